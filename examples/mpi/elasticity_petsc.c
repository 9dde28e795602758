/* mfree_elasticity_petsc: paper 000's cantilever beam (Timoshenko's solution, 000 eqs
 * 120-125; plane stress, L = 48, D = 12, E = 3e7, nu = 0.3, P = 1000) solved on MPI
 * ranks through libmfree_petsc, written as a parallel VTU file.
 *
 *   mpirun -np 4 mfree_elasticity_petsc [--nx 97] [--ny 25] [--out beam] [PETSc options]
 *
 * Each rank owns a slab of node columns and builds its own particle set: its owned nodes,
 * then the halo the assembler needs (docs/mpi.md): the nodes within one support radius
 * R of an owned node (nodal quadrature points, so not ghosts of the set), then those
 * within 2R (ghosts). MLS with a linear basis, nodal quadrature, the exact traction at
 * x = L, the x = 0 nodes clamped to the exact displacement. The system goes to PETSc
 * (one MATMPIAIJ, rows of the owned nodes) and is solved by CG with GAMG; any PETSc
 * option applies with the prefix "beam_" (e.g. -beam_ksp_monitor, -beam_pc_type hypre).
 * Writes <out>.pvtu and <out>_<rank>.vtu (owned nodes as vertices, with displacement,
 * exact displacement and owner rank), and prints the tip deflection against the exact
 * one; exits non-zero when the solve failed or the tip error exceeds 5 %. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <mfree_petsc.h>

#include "pvtu.h"

typedef struct {
  double P, L, D, E, nu;
} beam_t;

static void exact(const beam_t *b, const double *x, double *u) {
  const double inertia = b->D * b->D * b->D / 12.0, X = x[0], Y = x[1];
  u[0] = -b->P * Y / (6.0 * b->E * inertia) * ((6.0 * b->L - 3.0 * X) * X + (2.0 + b->nu) * (Y * Y - b->D * b->D / 4.0));
  u[1] = b->P / (6.0 * b->E * inertia) *
         (3.0 * b->nu * Y * Y * (b->L - X) + (4.0 + 5.0 * b->nu) * b->D * b->D * X / 4.0 + (3.0 * b->L - X) * X * X);
}

static void traction(void *user, const double *x, double *t) {
  const beam_t *b = (const beam_t *)user;
  const double inertia = b->D * b->D * b->D / 12.0;
  t[0] = -b->P * (b->L - x[0]) * x[1] / inertia;
  t[1] = b->P / (2.0 * inertia) * (b->D * b->D / 4.0 - x[1] * x[1]);
}

/* Owned nodes as vertices with displacement, exact displacement and rank (pvtu.h). */
static int write_vtu(const char *out, int rank, int32_t n, const double *x, const double *u, const double *ue) {
  int32_t *owner = malloc(sizeof(int32_t) * ((size_t)n + 1));
  if (!owner) return 1;
  for (int32_t i = 0; i < n; ++i) owner[i] = rank;
  const ex_vtu_array_t arrays[3] = {{"displacement", EX_VTU_FLOAT64, 2, u, 2},
                                    {"exact", EX_VTU_FLOAT64, 2, ue, 2},
                                    {"rank", EX_VTU_INT32, 1, owner, 1}};
  const int bad = ex_pvtu_write(PETSC_COMM_WORLD, out, n, 2, x, 2, 3, arrays);
  free(owner);
  return bad;
}

#define CHECK(call)                                                                            \
  do {                                                                                         \
    st = (call);                                                                               \
    if (st != MFREE_SUCCESS) {                                                                 \
      char msg_[512] = "";                                                                     \
      mfree_context_get_last_error(ctx, NULL, msg_, sizeof msg_);                              \
      fprintf(stderr, "rank %d: %s: %s (%s)\n", rank, #call, mfree_status_string(st), msg_);   \
      goto done;                                                                               \
    }                                                                                          \
  } while (0)

int main(int argc, char **argv) {
  if (PetscInitialize(&argc, &argv, NULL, NULL)) return 1;
  int rank = 0, size = 1, rc = 1;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  MPI_Comm_size(PETSC_COMM_WORLD, &size);
  int32_t nx = 97, ny = 25;
  const char *out = "beam";
  for (int a = 1; a < argc; ++a) {
    if (!strcmp(argv[a], "--nx") && a + 1 < argc) nx = atoi(argv[++a]);
    else if (!strcmp(argv[a], "--ny") && a + 1 < argc) ny = atoi(argv[++a]);
    else if (!strcmp(argv[a], "--out") && a + 1 < argc) out = argv[++a];
  }
  const beam_t b = {1000.0, 48.0, 12.0, 3e7, 0.3};
  mfree_context_t *ctx = NULL;
  mfree_particles_t *ps = NULL;
  mfree_approximant_t *ap = NULL;
  mfree_assembler_t *as = NULL;
  mfree_petsc_t *pk = NULL;
  mfree_status_t st = MFREE_SUCCESS;
  double *x = NULL, *vol = NULL, *u = NULL, *ue = NULL, *tx = NULL, *tw = NULL, *dv = NULL;
  int64_t *gid = NULL;
  int32_t *dofs = NULL;
  if (nx < 3 || ny < 2 || nx < size) {
    if (rank == 0) fprintf(stderr, "need --nx >= max(3, ranks) and --ny >= 2\n");
    goto done;
  }
  const double dx = b.L / (nx - 1), dy = b.D / (ny - 1), h = 1.01 * (dx > dy ? dx : dy), R = 2.0 * h;
  /* slab of columns [i0, i1); the halo: columns within R (inner) and 2R (outer) */
  const int32_t i0 = (int32_t)((int64_t)nx * rank / size), i1 = (int32_t)((int64_t)nx * (rank + 1) / size);
  const int32_t w1 = (int32_t)floor(R / dx * (1.0 + 1e-12)), w2 = (int32_t)floor(2.0 * R / dx * (1.0 + 1e-12));
  const int32_t nmax = nx * ny;
  x = malloc(sizeof(double) * 2 * (size_t)nmax);
  vol = malloc(sizeof(double) * (size_t)nmax);
  gid = malloc(sizeof(int64_t) * (size_t)nmax);
  if (!x || !vol || !gid) goto done;
  int32_t n = 0, nowned = 0, ninner = 0;
  for (int layer = 0; layer < 3; ++layer) {
    for (int32_t i = 0; i < nx; ++i) {
      const int32_t dist = i < i0 ? i0 - i : (i >= i1 ? i - i1 + 1 : 0);
      const int in = layer == 0 ? dist == 0 : layer == 1 ? dist > 0 && dist <= w1 : dist > w1 && dist <= w2;
      if (!in) continue;
      for (int32_t j = 0; j < ny; ++j) {
        x[2 * n] = i * dx;
        x[2 * n + 1] = -0.5 * b.D + j * dy;
        vol[n] = dx * dy * ((i == 0 || i == nx - 1) ? 0.5 : 1.0) * ((j == 0 || j == ny - 1) ? 0.5 : 1.0);
        gid[n++] = (int64_t)j * nx + i;
      }
    }
    if (layer == 0) nowned = n;
    if (layer == 1) ninner = n - nowned;
  }
  CHECK(mfree_context_create(&ctx));
  CHECK(mfree_particles_create(ctx, 2, n, &ps));
  CHECK(mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 2, MFREE_BORROW));
  CHECK(mfree_particles_set_volumes(ps, vol, 1, MFREE_BORROW));
  CHECK(mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  CHECK(mfree_particles_set_num_ghost(ps, n - nowned - ninner));
  /* global ids: every row and sum in one order, so that the owned rows are those of a
   * one-rank run bit for bit. Every particle within R of a non-ghost of the set (owned
   * nodes and the inner layer) is present: the halo width the set can check is R. */
  CHECK(mfree_particles_set_global_ids(ps, gid, MFREE_BORROW));
  CHECK(mfree_particles_set_halo_width(ps, R));
  CHECK(mfree_particles_setup(ps));
  CHECK(mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, &ap));
  CHECK(mfree_approximant_set_order(ap, 1));
  CHECK(mfree_assembler_create(ctx, ap, NULL, MFREE_FORM_ELASTICITY_PLANE_STRESS, &as));
  CHECK(mfree_assembler_set_material(as, b.E, b.nu));
  CHECK(mfree_assembler_set_quadrature_nodal(as));
  /* nodal traction points at x = L within R of an owned node (000 eq 95's boundary term) */
  int32_t nt = 0;
  tx = malloc(sizeof(double) * 2 * (size_t)ny);
  tw = malloc(sizeof(double) * (size_t)ny);
  if (!tx || !tw) goto done;
  if (nx - 1 - (i1 - 1) <= w1)
    for (int32_t j = 0; j < ny; ++j) {
      tx[2 * nt] = b.L;
      tx[2 * nt + 1] = -0.5 * b.D + j * dy;
      tw[nt++] = (j == 0 || j == ny - 1) ? 0.5 * dy : dy;
    }
  if (nt) CHECK(mfree_assembler_add_traction(as, nt, tx, MFREE_LAYOUT_AOS, 2, tw, traction, (void *)&b));
  CHECK(mfree_assembler_setup(as));

  CHECK(mfree_petsc_create(ctx, PETSC_COMM_WORLD, &pk));
  CHECK(mfree_petsc_set_options_prefix(pk, "beam_"));
  CHECK(mfree_petsc_set_coordinates(pk, 2, nowned, x));
  CHECK(mfree_petsc_setup(pk, as, 2, n, nowned, gid));
  /* clamp the x = 0 nodes to the exact displacement */
  dofs = malloc(sizeof(int32_t) * 2 * (size_t)(nowned ? nowned : 1));
  dv = malloc(sizeof(double) * 2 * (size_t)(nowned ? nowned : 1));
  u = malloc(sizeof(double) * 2 * (size_t)(nowned ? nowned : 1));
  ue = malloc(sizeof(double) * 2 * (size_t)(nowned ? nowned : 1));
  if (!dofs || !dv || !u || !ue) goto done;
  int32_t nd = 0;
  for (int32_t a = 0; a < nowned; ++a) {
    exact(&b, x + 2 * a, ue + 2 * a);
    if (x[2 * a] != 0.0) continue;
    for (int c = 0; c < 2; ++c) dofs[nd] = 2 * a + c, dv[nd++] = ue[2 * a + c];
  }
  CHECK(mfree_petsc_set_dirichlet(pk, nd, dofs, dv));
  CHECK(mfree_petsc_solve(pk, u));
  int32_t its = 0;
  double rnorm = 0.0;
  CHECK(mfree_petsc_get_info(pk, &its, &rnorm, NULL));
  /* tip deflection at (L, 0) and the relative displacement error over all nodes */
  double tip[2] = {0.0, 0.0}, e2[2] = {0.0, 0.0}, g[2];
  for (int32_t a = 0; a < nowned; ++a) {
    if (x[2 * a] == b.L && x[2 * a + 1] == 0.0) tip[0] = u[2 * a + 1], tip[1] = 1.0;
    for (int c = 0; c < 2; ++c) e2[0] += (u[2 * a + c] - ue[2 * a + c]) * (u[2 * a + c] - ue[2 * a + c]);
    for (int c = 0; c < 2; ++c) e2[1] += ue[2 * a + c] * ue[2 * a + c];
  }
  MPI_Allreduce(tip, g, 2, MPI_DOUBLE, MPI_SUM, PETSC_COMM_WORLD);
  tip[0] = g[0];
  MPI_Allreduce(e2, g, 2, MPI_DOUBLE, MPI_SUM, PETSC_COMM_WORLD);
  const double xt[2] = {b.L, 0.0};
  double ut[2];
  exact(&b, xt, ut);
  const double tip_err = fabs(tip[0] - ut[1]) / fabs(ut[1]), l2 = sqrt(g[0] / g[1]);
  const int anybad = write_vtu(out, rank, nowned, x, u, ue); /* (the same on every rank) */
  if (rank == 0) {
    printf("beam %dx%d nodes on %d ranks: %d unknowns, %d Krylov iterations (residual %.2e)\n", (int)nx, (int)ny, size,
           (int)(2 * nx * ny), (int)its, rnorm);
    printf("tip deflection %.6e, exact %.6e: relative error %.3e; nodal displacement error %.3e\n", tip[0], ut[1],
           tip_err, l2);
    printf("wrote %s.pvtu and %d pieces\n", out, size);
  }
  rc = anybad || !(tip_err < 0.05);
done:
  free(x), free(vol), free(gid), free(u), free(ue), free(tx), free(tw), free(dv), free(dofs);
  mfree_petsc_destroy(&pk);
  mfree_assembler_destroy(&as);
  mfree_approximant_destroy(&ap);
  mfree_particles_destroy(&ps);
  mfree_context_destroy(&ctx);
  PetscFinalize();
  return rc;
}
