/* The elastodynamic bar of paper 001 Sect. 6.4 by Galerkin on 1-4 ranks (label mpi),
 * native central differences through the reflection at the left end: t704's
 * discretisation (MLS, linear basis, cubic spline, 2-point Gauss cells, point traction
 * at the loaded end, lumped mass) given to mfree_system_create_elastodynamic_ranks,
 * with the left end free and held by a node row (an essential condition: a boundary
 * unknown solved from its neighbours at every evaluation). For contiguous slabs, slabs
 * in reverse rank order, scattered owners (a hash of the id) and everything on the last
 * rank, every particle's displacement and velocity (matched by global id), the step
 * count and the time are bitwise those of the one-rank run (the same system on
 * MPI_COMM_SELF), which is bitwise the serial mfree_system_create_elastodynamic_galerkin
 * with a lumped mass assembler on the same points (t704 checks its physics). Also
 * checked: the right-hand side at a state with every entry nonzero, bitwise; the
 * essential condition (the approximation vanishes at the held end, to round-off); the
 * loaded end moved, and the free left end after the wave reached it. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpibar.h"
#include "mpitest.h"

enum { N = 240 };
static const double T_END = 25e-6; /* past the reflection at the left end (19.8 us) */

static double state(int64_t id) { return 1e-7 * sin(0.37 * (double)id + 1.0); }

/* u, v by global id after T_END, the right-hand side at state() (both halves); the step
 * count */
static int64_t run(mfree_context_t *ctx, MPI_Comm comm, int how, int kind, double *u, double *v, double *f) {
  mpibar_t b;
  CHECK(mpibar_make_kind(&b, ctx, comm, N, how, kind) == MFREE_SUCCESS, "Galerkin bar on ranks, decomposition %d",
        how);
  int32_t neq = -1;
  CHECK(mfree_system_get_size(b.sys, &neq) == MFREE_SUCCESS && neq == 2 * b.n_owned, "neq %d", (int)neq);
  double *y = calloc((size_t)neq + 1, sizeof(double)), *yd = calloc((size_t)neq + 1, sizeof(double));
  for (int i = 0; i < b.n_owned; ++i) {
    y[i] = state(b.id[i]);
    y[b.n_owned + i] = 1e3 * state(b.id[i] + 7);
  }
  CHECK(mfree_system_rhs(b.sys, 2e-6, y, yd) == MFREE_SUCCESS, "rhs");
  mpibar_collect(&b, yd, 1, f);
  mpibar_collect(&b, yd + b.n_owned, 1, f + N);
  memset(y, 0, sizeof(double) * (size_t)neq);
  double t = 0.0;
  int64_t steps = 0;
  const mfree_status_t st =
      mfree_system_integrate(b.sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, T_END, 0.5, 0.0, NULL, NULL, &steps);
  char msg[400] = "";
  mfree_context_get_last_error(ctx, NULL, msg, sizeof msg);
  CHECK(st == MFREE_SUCCESS, "integrate: %d %s", (int)st, msg);
  CHECK(t == T_END, "t %.17g", t);
  mpibar_collect(&b, y, 1, u);
  mpibar_collect(&b, y + b.n_owned, 1, v);
  free(y);
  free(yd);
  mpibar_free(&b);
  return steps;
}

static void same_bits(const double *a, const double *b, int n, const char *what, int how, int kind) {
  for (int i = 0; i < n; ++i)
    if (memcmp(&a[i], &b[i], sizeof(double)) != 0) {
      CHECK(0, "bar %d, decomposition %d: %s %d: %.17g, one rank %.17g", kind, how, what, i, a[i], b[i]);
      return;
    }
}

int main(int argc, char **argv) {
  int rank = 0, size = 1;
  mfree_context_t *ctx = mpitest_start(&argc, &argv, &rank, &size);
  static double u1[N], v1[N], f1[2 * N], u[N], v[N], f[2 * N];

  for (int kind = BAR_GALERKIN; kind <= BAR_GALERKIN_FIXED; ++kind) {
    /* the one-rank run: the same system on this rank alone */
    const int64_t steps1 = run(ctx, MPI_COMM_SELF, BAR_SLAB, kind, u1, v1, f1);

    /* ... is the serial Galerkin system's, bit for bit */
    serialbar_t sb;
    CHECK(serialbar_make_kind(&sb, ctx, N, kind) == MFREE_SUCCESS, "serial Galerkin bar %d", kind);
    double *y = calloc(2 * N, sizeof(double)), *yd = calloc(2 * N, sizeof(double)), t = 0.0, uh[N];
    for (int i = 0; i < N; ++i) {
      y[i] = state(i);
      y[N + i] = 1e3 * state(i + 7);
    }
    CHECK(mfree_system_rhs(sb.sys, 2e-6, y, yd) == MFREE_SUCCESS, "serial rhs");
    same_bits(yd, f1, 2 * N, "serial right-hand side entry", -1, kind);
    memset(y, 0, sizeof(double) * 2 * N);
    int64_t steps = 0;
    CHECK(mfree_system_integrate(sb.sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, T_END, 0.5, 0.0, NULL, NULL, &steps) ==
              MFREE_SUCCESS,
          "serial integrate");
    CHECK(steps == steps1, "serial steps %lld, one rank %lld", (long long)steps, (long long)steps1);
    same_bits(y, u1, N, "serial displacement", -1, kind);
    same_bits(y + N, v1, N, "serial velocity", -1, kind);
    /* the approximation at the particles: the held end stays at 0 (its row holds
     * sum_K N_K(0) u_K = 0); the free end moved with the reflected wave */
    CHECK(mfree_approximant_apply(sb.a, MFREE_OP_VALUE, 1, y, MFREE_LAYOUT_AOS, 1, uh, MFREE_LAYOUT_AOS, 1) ==
              MFREE_SUCCESS,
          "apply");
    if (kind == BAR_GALERKIN_FIXED)
      CHECK(fabs(uh[0]) <= 1e-12 * fabs(uh[N - 1]), "held end: u(0) = %g, u(L) = %g", uh[0], uh[N - 1]);
    else
      CHECK(uh[0] < -1e-7, "free end: u(0) = %g", uh[0]);
    CHECK(uh[N - 1] < -1e-6, "the loaded end moved: u(L) = %g", uh[N - 1]);
    free(y);
    free(yd);
    serialbar_free(&sb);

    /* the decompositions of MPI_COMM_WORLD */
    for (int how = BAR_SLAB; how <= BAR_LAST; ++how) {
      const int64_t st = run(ctx, MPI_COMM_WORLD, how, kind, u, v, f);
      CHECK(st == steps1, "bar %d, decomposition %d: %lld steps, one rank %lld", kind, how, (long long)st,
            (long long)steps1);
      same_bits(u, u1, N, "displacement", how, kind);
      same_bits(v, v1, N, "velocity", how, kind);
      same_bits(f, f1, 2 * N, "right-hand side entry", how, kind);
    }
    if (rank == 0)
      printf("t169: %s left end: %lld steps, loaded end %.6e m, left end %.6e m, compared on %d ranks\n",
             kind == BAR_GALERKIN ? "free" : "held", (long long)steps1, u1[N - 1], u1[0], size);
  }
  mfree_context_destroy(&ctx);
  const int rc = mpitest_finish("t169-mpi-galerkin-bar");
  MPI_Finalize();
  return rc;
}
