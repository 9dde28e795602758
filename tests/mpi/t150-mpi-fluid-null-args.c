/* The fluid on ranks, a NULL argument on one rank only (label mpi, 1-4 ranks, under a
 * timeout that fails a hang): every collective call (mfree_system_rhs,
 * mfree_system_integrate, mfree_system_assemble_mass, mfree_system_assemble_interpolation,
 * mfree_system_get_velocity,
 * mfree_system_get_wall_force, mfree_system_create_fluid_ranks) returns MFREE_ERR_NULL on
 * every rank with the faulty rank's message ("rank R: y or ydot is NULL"), changes nothing
 * (y, t, the step count, an existing matrix), and the system still works: each good call
 * after the bad ones gives bit for bit what the same good call gives on a twin system that
 * never saw a bad call. The faulty rank is the last, then rank 0. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpifluid.h"
#include "mpitest.h"

static int rank = 0, size = 1;

int main(int argc, char **argv) {
  damb_t b;
  int *owner = NULL;
  double width = 0.0;
  rankfluid_t s, twin; /* s: sees the bad calls; twin: the good calls only */
  mfree_context_t *ctx = mpifluid_pair(&argc, &argv, &rank, &size, &b, &owner, &width, &s, &twin);
  const size_t neq = 5 * (size_t)s.n_owned, nd = 2 * (size_t)s.n_owned;
  double *d1 = malloc((neq + 1) * sizeof *d1), *d2 = malloc((neq + 1) * sizeof *d2);
  int64_t five = 5, steps = -1;

  /* creation with a NULL output on one rank: no system anywhere */
  for (int turn = 0; turn < 2; ++turn) {
    const int bad = turn == 0 ? size - 1 : 0;
    const int nl = s.n_owned + s.n_ghost;
    int64_t *ids = malloc(((size_t)nl + 1) * sizeof *ids);
    CHECK(mfree_halo_get_global_ids(s.halo, ids) == MFREE_SUCCESS, "ids");
    mfree_system_t *sys = NULL;
    expect_agreed(ctx,
                mfree_system_create_fluid_ranks(ctx, 2, s.n_owned, s.n_ghost, ids, width, mfree_halo_exchange_callback,
                                                mfree_halo_allgather, s.halo, rank == bad ? NULL : &sys),
                MFREE_ERR_NULL, bad, "output pointer is NULL", "create, NULL output");
    CHECK(sys == NULL, "no system after a failed creation");
    free(ids);
  }
  for (int turn = 0; turn < 2; ++turn) {
    const int bad = turn == 0 ? size - 1 : 0, me = rank == bad;
    /* the right-hand side */
    expect_agreed(ctx, mfree_system_rhs(s.sys, 0.0, me ? NULL : s.y, d1), MFREE_ERR_NULL, bad, "y or ydot is NULL",
                  "rhs, y NULL");
    expect_agreed(ctx, mfree_system_rhs(s.sys, 0.0, s.y, me ? NULL : d1), MFREE_ERR_NULL, bad, "y or ydot is NULL",
                  "rhs, ydot NULL");
    CHECK(mfree_system_rhs(s.sys, 0.0, s.y, d1) == MFREE_SUCCESS, "rhs");
    CHECK(mfree_system_rhs(twin.sys, 0.0, twin.y, d2) == MFREE_SUCCESS, "rhs, twin");
    mpitest_same_bits(d1, d2, neq, "rhs");

    /* the lumped mass: a NULL output pointer, a NULL state; an existing matrix unchanged */
    mfree_matrix_t *M = NULL, *Mt = NULL;
    expect_agreed(ctx, mfree_system_assemble_mass(s.sys, s.y, 0, me ? NULL : &M), MFREE_ERR_NULL, bad,
                  "output pointer is NULL", "mass, M NULL");
    CHECK(M == NULL, "no matrix made by a failed call");
    CHECK(mfree_system_assemble_mass(s.sys, s.y, 0, &M) == MFREE_SUCCESS, "mass");
    CHECK(mfree_system_assemble_mass(twin.sys, twin.y, 0, &Mt) == MFREE_SUCCESS, "mass, twin");
    expect_agreed(ctx, mfree_system_assemble_mass(s.sys, me ? NULL : s.y, 0, &M), MFREE_ERR_NULL, bad, "y is NULL",
                  "mass, y NULL");
    mfree_matrix_apply(M, s.y, d1);
    mfree_matrix_apply(Mt, twin.y, d2);
    mpitest_same_bits(d1, d2, neq, "mass times the state");
    mfree_matrix_destroy(&M);
    mfree_matrix_destroy(&Mt);

    /* the interpolation matrix: a NULL output pointer, a NULL state */
    mfree_matrix_t *S = NULL, *St = NULL;
    expect_agreed(ctx, mfree_system_assemble_interpolation(s.sys, s.y, me ? NULL : &S), MFREE_ERR_NULL, bad,
                  "output pointer is NULL", "interpolation, S NULL");
    CHECK(S == NULL, "no interpolation matrix made by a failed call");
    expect_agreed(ctx, mfree_system_assemble_interpolation(s.sys, me ? NULL : s.y, &S), MFREE_ERR_NULL, bad,
                  "y is NULL", "interpolation, y NULL");
    CHECK(S == NULL, "no interpolation matrix made by a failed call (y NULL)");
    CHECK(mfree_system_assemble_interpolation(s.sys, s.y, &S) == MFREE_SUCCESS, "interpolation");
    CHECK(mfree_system_assemble_interpolation(twin.sys, twin.y, &St) == MFREE_SUCCESS, "interpolation, twin");
    {
      int32_t nr = 0, nc = 0, nrt = 0, nct = 0;
      int64_t nz = 0, nzt = 0;
      CHECK(mfree_matrix_get_size(S, &nr, &nc, &nz) == MFREE_SUCCESS &&
                mfree_matrix_get_size(St, &nrt, &nct, &nzt) == MFREE_SUCCESS && nr == nrt && nc == nct && nz == nzt,
            "interpolation sizes %d x %d (%lld), twin %d x %d (%lld)", nr, nc, (long long)nz, nrt, nct, (long long)nzt);
      const int64_t *rp, *rpt;
      const int32_t *ci, *cit;
      const double *v, *vt;
      CHECK(mfree_matrix_get_csr(S, &rp, &ci, &v) == MFREE_SUCCESS &&
                mfree_matrix_get_csr(St, &rpt, &cit, &vt) == MFREE_SUCCESS,
            "interpolation CSR");
      if (nz == nzt) {
        CHECK(memcmp(ci, cit, (size_t)nz * sizeof *ci) == 0, "interpolation columns, twin");
        mpitest_same_bits(v, vt, (size_t)nz, "interpolation values");
      }
    }
    mfree_matrix_destroy(&S);
    mfree_matrix_destroy(&St);

    /* the interpolated velocity */
    expect_agreed(ctx, mfree_system_get_velocity(s.sys, me ? NULL : s.y, d1), MFREE_ERR_NULL, bad, "y or vhat is NULL",
                  "velocity, y NULL");
    expect_agreed(ctx, mfree_system_get_velocity(s.sys, s.y, me ? NULL : d1), MFREE_ERR_NULL, bad, "y or vhat is NULL",
                  "velocity, vhat NULL");
    CHECK(mfree_system_get_velocity(s.sys, s.y, d1) == MFREE_SUCCESS, "velocity");
    CHECK(mfree_system_get_velocity(twin.sys, twin.y, d2) == MFREE_SUCCESS, "velocity, twin");
    mpitest_same_bits(d1, d2, nd, "velocity");

    /* the wall force */
    double f1[2] = {0, 0}, f2[2] = {0, 0};
    expect_agreed(ctx, mfree_system_get_wall_force(s.sys, me ? NULL : s.y, f1, 0, NULL), MFREE_ERR_NULL, bad,
                  "y is NULL", "wall force, y NULL");
    expect_agreed(ctx, mfree_system_get_wall_force(s.sys, s.y, me ? NULL : f1, 0, NULL), MFREE_ERR_NULL, bad,
                  "total and per_wall are both NULL", "wall force, no output");
    CHECK(mfree_system_get_wall_force(s.sys, s.y, f1, 0, NULL) == MFREE_SUCCESS, "wall force");
    CHECK(mfree_system_get_wall_force(twin.sys, twin.y, f2, 0, NULL) == MFREE_SUCCESS, "wall force, twin");
    mpitest_same_bits(f1, f2, 2, "wall force");

    /* five leap-frog steps (then five of the predictor-corrector): y and t untouched by a
       failed call, no step taken */
    const mfree_integrator_t scheme = turn == 0 ? MFREE_INTEGRATOR_LEAPFROG : MFREE_INTEGRATOR_PREDICTOR_CORRECTOR;
    double t = 0.25 * turn, tt = 0.25 * turn;
    memcpy(d1, s.y, neq * sizeof *d1);
    expect_agreed(
        ctx, mfree_system_integrate(s.sys, scheme, me ? NULL : s.y, &t, 1.0, 0.5, 0.0, mpifluid_stop_at, &five, &steps),
        MFREE_ERR_NULL, bad, "y or t is NULL", "integrate, y NULL");
    CHECK(steps == 0, "integrate, y NULL: %lld steps", (long long)steps);
    expect_agreed(
        ctx, mfree_system_integrate(s.sys, scheme, s.y, me ? NULL : &t, 1.0, 0.5, 0.0, mpifluid_stop_at, &five, &steps),
        MFREE_ERR_NULL, bad, "y or t is NULL", "integrate, t NULL");
    CHECK(steps == 0 && t == 0.25 * turn, "integrate, t NULL: %lld steps, t = %g", (long long)steps, t);
    mpitest_same_bits(s.y, d1, neq, "the state after the failed integrations");
    CHECK(mfree_system_integrate(s.sys, scheme, s.y, &t, 1.0, 0.5, 0.0, mpifluid_stop_at, &five, &steps) ==
                  MFREE_SUCCESS &&
              steps == 5,
          "integrate: %lld steps (%s)", (long long)steps, mpifluid_error(ctx));
    CHECK(mfree_system_integrate(twin.sys, scheme, twin.y, &tt, 1.0, 0.5, 0.0, mpifluid_stop_at, &five, &steps) ==
                  MFREE_SUCCESS &&
              steps == 5,
          "integrate, twin");
    CHECK(t == tt, "time %.17g, twin %.17g", t, tt);
    mpitest_same_bits(s.y, twin.y, neq, "the state after five steps");
  }

  free(d1), free(d2);
  mpifluid_pair_free(&b, owner, &s, &twin);
  mfree_context_destroy(&ctx);
  const int rc = mpitest_finish("t150-mpi-fluid-null-args");
  MPI_Finalize();
  return rc;
}
