/* The elastodynamic bar on ranks (collocation, and Galerkin with a held end), a NULL
 * argument on one rank only (label mpi, 1-4 ranks, under a timeout that fails a hang):
 * mfree_system_rhs, mfree_system_integrate, mfree_system_get_stress (collocation) and
 * mfree_system_create_elastodynamic_ranks return MFREE_ERR_NULL on every rank with the
 * faulty rank's message, change nothing (y, t, the step count), and the system still
 * works: each good call after the bad ones gives bit for bit what the same good call
 * gives on a twin bar that never saw a bad call. The faulty rank is the last, then 0. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpibar.h"
#include "mpitest.h"

enum { N = 60 };
static int rank = 0, size = 1;

static void run(mfree_context_t *ctx, int kind) {
  mpibar_t s, twin;
  CHECK(mpibar_make_kind(&s, ctx, MPI_COMM_WORLD, N, BAR_SLAB, kind) == MFREE_SUCCESS, "bar %d", kind);
  CHECK(mpibar_make_kind(&twin, ctx, MPI_COMM_WORLD, N, BAR_SLAB, kind) == MFREE_SUCCESS, "twin %d", kind);
  mfree_system_set_load_history(s.sys, mpibar_pulse, NULL);
  mfree_system_set_load_history(twin.sys, mpibar_pulse, NULL);
  const size_t neq = 2 * (size_t)s.n_owned;
  double *y = calloc(neq + 1, sizeof *y), *yt = calloc(neq + 1, sizeof *yt);
  double *d1 = calloc(neq + 1, sizeof *d1), *d2 = calloc(neq + 1, sizeof *d2);
  int64_t steps = -1, st2 = -1;
  double t = 0.0, tt = 0.0;
  for (int turn = 0; turn < 2; ++turn) {
    const int bad = turn == 0 ? size - 1 : 0, me = rank == bad;
    /* the right-hand side at the current state and time */
    expect_agreed(ctx, mfree_system_rhs(s.sys, t, me ? NULL : y, d1), MFREE_ERR_NULL, bad, "y or ydot is NULL",
                  "rhs, y NULL");
    expect_agreed(ctx, mfree_system_rhs(s.sys, t, y, me ? NULL : d1), MFREE_ERR_NULL, bad, "y or ydot is NULL",
                  "rhs, ydot NULL");
    CHECK(mfree_system_rhs(s.sys, t, y, d1) == MFREE_SUCCESS, "rhs");
    CHECK(mfree_system_rhs(twin.sys, tt, yt, d2) == MFREE_SUCCESS, "rhs, twin");
    mpitest_same_bits(d1, d2, neq, "rhs");
    /* the stress (collocation only) */
    if (kind == BAR_COLLOCATION) {
      expect_agreed(ctx, mfree_system_get_stress(s.sys, t, me ? NULL : y, d1), MFREE_ERR_NULL, bad,
                    "y or sigma is NULL", "stress, y NULL");
      expect_agreed(ctx, mfree_system_get_stress(s.sys, t, y, me ? NULL : d1), MFREE_ERR_NULL, bad,
                    "y or sigma is NULL", "stress, sigma NULL");
      CHECK(mfree_system_get_stress(s.sys, t, y, d1) == MFREE_SUCCESS, "stress");
      CHECK(mfree_system_get_stress(twin.sys, tt, yt, d2) == MFREE_SUCCESS, "stress, twin");
      mpitest_same_bits(d1, d2, s.n_owned, "stress");
    }
    /* 1 us of central differences: y and t untouched by a failed call, no step taken */
    memcpy(d1, y, neq * sizeof *d1);
    const double t0 = t, t_end = t + 1e-6;
    expect_agreed(ctx,
                mfree_system_integrate(s.sys, MFREE_INTEGRATOR_LEAPFROG, me ? NULL : y, &t, t_end, 0.5, 0.0, NULL, NULL,
                                       &steps),
                MFREE_ERR_NULL, bad, "y or t is NULL", "integrate, y NULL");
    CHECK(steps == 0, "integrate, y NULL: %lld steps", (long long)steps);
    expect_agreed(ctx,
                mfree_system_integrate(s.sys, MFREE_INTEGRATOR_LEAPFROG, y, me ? NULL : &t, t_end, 0.5, 0.0, NULL, NULL,
                                       &steps),
                MFREE_ERR_NULL, bad, "y or t is NULL", "integrate, t NULL");
    CHECK(steps == 0 && t == t0, "integrate, t NULL: %lld steps, t = %g", (long long)steps, t);
    mpitest_same_bits(y, d1, neq, "the state after the failed integrations");
    CHECK(mfree_system_integrate(s.sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, t_end, 0.5, 0.0, NULL, NULL, &steps) ==
                  MFREE_SUCCESS &&
              steps > 0,
          "integrate");
    CHECK(mfree_system_integrate(twin.sys, MFREE_INTEGRATOR_LEAPFROG, yt, &tt, t_end, 0.5, 0.0, NULL, NULL, &st2) ==
                  MFREE_SUCCESS &&
              st2 == steps,
          "integrate, twin: %lld and %lld steps", (long long)steps, (long long)st2);
    CHECK(t == tt, "time %.17g, twin %.17g", t, tt);
    mpitest_same_bits(y, yt, neq, "the state after the integration");
    double norm = 0.0;
    for (size_t q = 0; q < neq; ++q) norm += fabs(y[q]);
    double all = 0.0;
    MPI_Allreduce(&norm, &all, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
    CHECK(all > 0.0, "the pulse moved the bar");
  }
  /* creation with a NULL output on one rank: no system anywhere */
  for (int turn = 0; turn < 2; ++turn) {
    const int bad = turn == 0 ? size - 1 : 0;
    mfree_system_t *sys = NULL;
    expect_agreed(ctx,
                mfree_system_create_elastodynamic_ranks(ctx, s.as, BAR_RHO, mfree_halo_exchange_callback,
                                                        mfree_halo_allgather, s.halo, rank == bad ? NULL : &sys),
                MFREE_ERR_NULL, bad, "output pointer is NULL", "create, NULL output");
    CHECK(sys == NULL, "no system after a failed creation");
  }
  free(y), free(yt), free(d1), free(d2);
  mpibar_free(&s);
  mpibar_free(&twin);
}

int main(int argc, char **argv) {
  mfree_context_t *ctx = mpitest_start(&argc, &argv, &rank, &size);
  run(ctx, BAR_COLLOCATION);
  run(ctx, BAR_GALERKIN_FIXED);
  mfree_context_destroy(&ctx);
  const int rc = mpitest_finish("t151-mpi-elastodynamic-null-args");
  MPI_Finalize();
  return rc;
}
