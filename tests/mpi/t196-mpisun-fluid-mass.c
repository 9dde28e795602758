/* The fluid on ranks by ARKStep with its mass matrix (label mpi): the dam break of paper
 * 003 (8 x 16 particles) in the mass form M_L y' = M_L f (mfree_sundials_rhs_mass_form,
 * the lumped mass of 003 eq 56 in the velocity rows) with a matrix-free PCG mass solver
 * (mfree_sundials_mass_times, the mass at the stage times) on NVECTOR_PARALLEL vectors
 * with reproducible reductions (mfree_sundials_mpi_create_vector), on 1-4 ranks, for
 * horizontal layers and owners by a hash of the id. Every particle's position, velocity
 * and density, matched by global id, the numbers of steps and of mass products are
 * bitwise those of the same code on one rank (MPI_COMM_SELF), and those of the
 * one-process fluid (mfree_system_create_fluid) through the serial adapter on the same
 * kind of vectors over MPI_COMM_SELF: the lumped masses sum their terms in an order of
 * their values, not of the numbering. The PCG's dot products read every rank's entries:
 * any rounding difference of a mass product or a reduction would change the iterates.
 * Built with MASS_CONSISTENT=1 (t156) the same program runs the consistent mass (003
 * eq 42: mfree_sundials_set_consistent_mass, whose products on ranks couple owned
 * particles to ghosts, mfree_system_apply_mass) with h = d (below) to T = 1 ms, with a
 * ghost layer a thousandth of a spacing deeper than two support radii, so that the ranks
 * rebuild their ghosts every few steps (counted through the rebuild callback), with the
 * same checks. */
#include <arkode/arkode_arkstep.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sunlinsol/sunlinsol_pcg.h>

#include "mfree_sundials.h"
#include "mfree_sundials_mpi.h"
#include "mpifluid.h"
#include "mpitest.h"

#ifndef MASS_CONSISTENT
#define MASS_CONSISTENT 0
#define TEST_NAME "t196-mpisun-fluid-mass"
static const double T_END = 1e-4, RTOL = 1e-3, MARGIN = 4.0; /* the layer beyond 4 h, in spacings */
#else
static const double T_END = 2e-3, RTOL = 1e-3, MARGIN = 1e-3;
#endif

static void flag(int f, const char *what) { CHECK(f >= 0, "%s returned %d", what, f); }

typedef struct {
  long steps, nmass;
  int flag;    /* ARKStepEvolve's */
  int rebuilt; /* ghost rebuilds during the run */
} outcome_t;

/* libmfree_mpi's rebuild, counted */
static int rebuilds = 0;
static mfree_status_t counted_rebuild(void *halo, int32_t n_owned, const double *x, int64_t ld, const int64_t *ids,
                                      double width, int32_t *n_ghost, const int64_t **all_ids) {
  ++rebuilds;
  return mfree_halo_rebuild_callback(halo, n_owned, x, ld, ids, width, n_ghost, all_ids);
}

/* The state of every particle (5 n, by global id, on every rank) after T_END. owner:
   the ranks' owners, or NULL for the one-process fluid on MPI_COMM_SELF. */
static outcome_t run(mfree_context_t *ctx, SUNContext sunctx, MPI_Comm comm, const damb_t *b, const int *owner,
                     int consistent, double *out) {
  outcome_t o = {-1, -1, 0, 0};
  rankfluid_t r;
  memset(&r, 0, sizeof r);
  mfree_system_t *sys = NULL;
  const int n = b->n;
  if (owner) {
    const mfree_status_t st = rankfluid_make(&r, ctx, comm, b, owner, 4.0 * b->h + MARGIN * b->d, 0);
    CHECK(st == MFREE_SUCCESS, "system: status %d: %s", (int)st, mpifluid_error(ctx));
    sys = r.sys;
    rebuilds = 0;
    CHECK(mfree_system_set_halo_rebuild(sys, counted_rebuild) == MFREE_SUCCESS, "rebuild: %s", mpifluid_error(ctx));
  } else {
    CHECK(mfree_system_create_fluid(ctx, 2, n, &sys) == MFREE_SUCCESS && damb_configure(b, sys) == MFREE_SUCCESS &&
              mfree_system_set_masses(sys, b->m, 1) == MFREE_SUCCESS,
          "one-process fluid: %s", mpifluid_error(ctx));
  }
  mfree_sundials_t *ad = NULL;
  CHECK(mfree_sundials_create(ctx, sys, &ad) == MFREE_SUCCESS, "adapter: %s", mpifluid_error(ctx));
  CHECK(mfree_sundials_set_consistent_mass(ad, consistent) == MFREE_SUCCESS, "consistent %d", consistent);
  N_Vector y = NULL;
  CHECK(mfree_sundials_mpi_create_vector(ctx, sys, comm, sunctx, &y) == MFREE_SUCCESS, "vector: %s",
        mpifluid_error(ctx));
  CHECK(N_VGetLength(y) == 5 * n, "global length %ld", (long)N_VGetLength(y));
  const int no = owner ? r.n_owned : n;
  memcpy(N_VGetArrayPointer(y), owner ? r.y : b->y, 5 * (size_t)no * sizeof(double));
  void *mem = ARKStepCreate(mfree_sundials_rhs_mass_form, NULL, 0.0, y, sunctx);
  SUNLinearSolver LS = SUNLinSol_PCG(y, SUN_PREC_NONE, MASS_CONSISTENT ? 200 : 50, sunctx);
  flag(ARKStepSetMassLinearSolver(mem, LS, NULL, SUNTRUE), "ARKStepSetMassLinearSolver");
  flag(ARKStepSetMassTimes(mem, NULL, mfree_sundials_mass_times, ad), "ARKStepSetMassTimes");
  CHECK(mfree_sundials_set_state(ad, y) == MFREE_SUCCESS, "state: %s", mpifluid_error(ctx));
  N_Vector atol = N_VClone(y);
  mpifluid_tolerances(b, no, N_VGetArrayPointer(atol));
  flag(ARKStepSVtolerances(mem, RTOL, atol), "tolerances");
  flag(ARKStepSetUserData(mem, ad), "user data");
  flag(ARKStepSetMaxNumSteps(mem, 100000), "max steps");
  flag(ARKStepSetStopTime(mem, T_END), "stop time");
  double t = 0.0;
  o.flag = ARKStepEvolve(mem, T_END, y, &t, ARK_NORMAL);
  ARKStepGetNumSteps(mem, &o.steps);
  int64_t nmass = 0;
  mfree_sundials_get_stats(ad, NULL, NULL, &nmass, NULL, NULL);
  o.nmass = (long)nmass;
  o.rebuilt = rebuilds;
  if (o.flag >= 0) {
    CHECK(t == T_END, "t %.17g", t);
    if (owner)
      mpifluid_state(comm, &r, N_VGetArrayPointer(y), n, out);
    else
      memcpy(out, N_VGetArrayPointer(y), 5 * (size_t)n * sizeof(double));
  }
  ARKStepFree(&mem);
  SUNLinSolFree(LS);
  N_VDestroy(atol);
  N_VDestroy(y);
  mfree_sundials_destroy(&ad);
  if (owner)
    rankfluid_free(&r);
  else
    mfree_system_destroy(&sys);
  return o;
}

int main(int argc, char **argv) {
  int rank = 0, size = 1;
  mfree_context_t *ctx = mpitest_start(&argc, &argv, &rank, &size);
  SUNContext sunctx = NULL, self_ctx = NULL;
  MPI_Comm world = MPI_COMM_WORLD, self = MPI_COMM_SELF;
  SUNContext_Create(&world, &sunctx);
  SUNContext_Create(&self, &self_ctx);
  damb_t b;
  damb_make(&b, 8, 16);
#if MASS_CONSISTENT
  /* At h = 1.5 d the consistent mass of the linear MLS functions has a condition number
     near 1e5 (unpreconditioned CG takes some 1,100 iterations, Jacobi or lumped-mass
     preconditioning barely fewer); at h = d some 70 */
  b.h = b.d;
#endif
  const int n = b.n;
  int *owner = calloc((size_t)n, sizeof *owner);
  double *y0 = malloc(5 * (size_t)n * sizeof *y0), *y1 = malloc(5 * (size_t)n * sizeof *y1),
         *y = malloc(5 * (size_t)n * sizeof *y);
  /* the one-process fluid and the system on one rank, by rank 0 for every rank */
  outcome_t o0 = {0, 0, 0, 0}, o1 = {0, 0, 0, 0};
  if (rank == 0) {
    o0 = run(ctx, self_ctx, MPI_COMM_SELF, &b, NULL, MASS_CONSISTENT, y0);
    o1 = run(ctx, self_ctx, MPI_COMM_SELF, &b, owner, MASS_CONSISTENT, y1);
    CHECK(o0.flag >= 0 && o1.flag >= 0, "ARKStepEvolve: %d (one process), %d (one rank): %s", o0.flag, o1.flag,
          mpifluid_error(ctx));
    CHECK(o0.steps == o1.steps && o0.nmass == o1.nmass, "one process: %ld steps, %ld mass products; one rank %ld, %ld",
          o0.steps, o0.nmass, o1.steps, o1.nmass);
    CHECK(memcmp(y0, y1, 5 * (size_t)n * sizeof *y0) == 0, "the one-rank state differs from the one-process fluid's");
  }
  long counts[2] = {o1.steps, o1.nmass};
  MPI_Bcast(counts, 2, MPI_LONG, 0, MPI_COMM_WORLD);
  MPI_Bcast(y1, 5 * n, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  o1.steps = counts[0], o1.nmass = counts[1];
  double front = 0.0, vmax = 0.0;
  for (int q = 0; q < n; ++q) front = fmax(front, y1[2 * q]), vmax = fmax(vmax, hypot(y1[2 * (size_t)n + 2 * q], y1[2 * (size_t)n + 2 * q + 1]));
  /* the column has started to fall: speeds of g t at the top, the front not yet moved far */
  CHECK(o1.steps > 10 && vmax > 0.5 * 9.81 * T_END && front > b.a - 0.5 * b.d, "%ld steps, front %.5f m, column %.5f m, speed %.3g m/s",
        o1.steps, front, b.a, vmax);
  CHECK(o1.nmass > 2 * o1.steps, "%ld mass products in %ld steps", o1.nmass, o1.steps);
  for (int how = 0; how < 2; ++how) {
    for (int i = 0; i < n; ++i) {
      int p = (int)(b.y[2 * i + 1] / (2.0 * b.a) * size);
      p = p < 0 ? 0 : p >= size ? size - 1 : p;
      owner[i] = how ? (int)(mpitest_hash((uint64_t)i) % (uint64_t)size) : p;
    }
    const outcome_t o = run(ctx, sunctx, MPI_COMM_WORLD, &b, owner, MASS_CONSISTENT, y);
    const char *name = how ? "hashed" : "layers";
    CHECK(o.flag >= 0, "%s: ARKStepEvolve %d: %s", name, o.flag, mpifluid_error(ctx));
    CHECK(o.steps == o1.steps && o.nmass == o1.nmass, "%s: %ld steps, %ld mass products; one rank %ld, %ld", name,
          o.steps, o.nmass, o1.steps, o1.nmass);
    int bad = 0;
    for (int q = 0; q < n; ++q)
      bad += memcmp(y + 2 * q, y1 + 2 * q, 16) || memcmp(y + 2 * (size_t)n + 2 * q, y1 + 2 * (size_t)n + 2 * q, 16) ||
             memcmp(y + 4 * (size_t)n + q, y1 + 4 * (size_t)n + q, 8);
    CHECK(bad == 0, "%s: %d of %d particles differ from one rank's", name, bad, n);
    CHECK(!MASS_CONSISTENT || o.rebuilt >= 3, "%s: %d ghost rebuilds", name, o.rebuilt);
  }
  if (rank == 0)
    printf("%s: ARKStep + PCG %s mass, %ld steps, %ld mass products, %d ghost rebuilds to T = %g s on %d ranks, "
           "front %.5f m\n",
           TEST_NAME, MASS_CONSISTENT ? "consistent" : "lumped", o1.steps, o1.nmass, o1.rebuilt, T_END, size, front);
  free(owner), free(y0), free(y1), free(y);
  damb_free(&b);
  SUNContext_Free(&self_ctx);
  SUNContext_Free(&sunctx);
  mfree_context_destroy(&ctx);
  const int rc = mpitest_finish(TEST_NAME);
  MPI_Finalize();
  return rc;
}
