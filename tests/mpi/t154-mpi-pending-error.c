/* A fault made pending on a system by the host (mfree_system_set_pending_error, as the
 * Fortran module's size checks and libmfree_sundials' vector checks do) on one rank only
 * (label mpi, 1-4 ranks, under a timeout that fails a hang): the next collective call of
 * the fluid on ranks (mfree_system_rhs, _integrate, _assemble_mass,
 * _assemble_interpolation, _apply_mass lumped and consistent, _get_velocity,
 * _get_wall_force, _move_particles) and of the elastodynamic bar on ranks (_rhs,
 * _get_stress, _integrate) returns the pending status on every rank with the faulty
 * rank's message ("rank R: ..."), writes no output on any rank (the outputs keep a
 * sentinel; y, t and the step count are unchanged; no matrix is made), and the fault is
 * reported once: the call after it gives bit for bit what the same call gives on a twin
 * system that never saw a fault (the elastic bar: what the same call gave before). A
 * fault cleared with MFREE_SUCCESS is not reported. In one process (mfree_system_create_fluid)
 * the next call returns the fault at once, its message without a rank. The faulty rank
 * is the last, then rank 0. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpibar.h"
#include "mpifluid.h"
#include "mpitest.h"

static int rank = 0, size = 1;
static const double SENTINEL = -12345.5;

/* The fault on rank bad: a status the callers' checks return and a message naming the
 * array ("mfree_..." prefix dropped by the setter). */
static void pend(mfree_context_t *ctx, mfree_system_t *sys, int bad, mfree_status_t st) {
  if (rank == bad)
    CHECK(mfree_system_set_pending_error(sys, st, "mfree_host_check: out holds 3 values, more are needed") ==
              MFREE_SUCCESS,
          "set_pending_error: %s", mpifluid_error(ctx));
}

static void fill(double *a, size_t n) {
  for (size_t i = 0; i < n; ++i) a[i] = SENTINEL;
}

/* a holds the sentinel in all n values */
static void untouched(const double *a, size_t n, const char *what) {
  for (size_t i = 0; i < n; ++i)
    if (a[i] != SENTINEL) {
      CHECK(0, "%s: output %zu written (%.17g) by a failed call", what, i, a[i]);
      return;
    }
}

/* The identity move: every rank keeps its particles. */
static mfree_status_t keep_all(void *user, int32_t nrec, int32_t n_owned, double *records, int32_t n_new) {
  (void)user, (void)nrec, (void)records;
  return n_new == n_owned ? MFREE_SUCCESS : MFREE_ERR_ARG;
}

static void same_matrix(const mfree_matrix_t *A, const mfree_matrix_t *B, const char *what) {
  int32_t nr = 0, nc = 0, nrb = 0, ncb = 0;
  int64_t nz = 0, nzb = 0;
  CHECK(mfree_matrix_get_size(A, &nr, &nc, &nz) == MFREE_SUCCESS &&
            mfree_matrix_get_size(B, &nrb, &ncb, &nzb) == MFREE_SUCCESS && nr == nrb && nc == ncb && nz == nzb,
        "%s: sizes %d x %d (%lld), twin %d x %d (%lld)", what, nr, nc, (long long)nz, nrb, ncb, (long long)nzb);
  const int64_t *rp, *rpb;
  const int32_t *ci, *cib;
  const double *v, *vb;
  if (nz != nzb || mfree_matrix_get_csr(A, &rp, &ci, &v) != MFREE_SUCCESS ||
      mfree_matrix_get_csr(B, &rpb, &cib, &vb) != MFREE_SUCCESS)
    return;
  CHECK(memcmp(rp, rpb, ((size_t)nr + 1) * sizeof *rp) == 0 && memcmp(ci, cib, (size_t)nz * sizeof *ci) == 0,
        "%s: pattern differs from the twin's", what);
  mpitest_same_bits(v, vb, nz, what);
}

static void fluid_calls(mfree_context_t *ctx, rankfluid_t *s, rankfluid_t *twin, int turn) {
  const int bad = turn == 0 ? size - 1 : 0;
  const mfree_status_t st = turn == 0 ? MFREE_ERR_ARG : MFREE_ERR_MISMATCH;
  const char *why = "out holds 3 values, more are needed";
  const size_t neq = 5 * (size_t)s->n_owned, nd = 2 * (size_t)s->n_owned;
  double *d1 = malloc((neq + 1) * sizeof *d1), *d2 = malloc((neq + 1) * sizeof *d2);
  double *y0 = malloc((neq + 1) * sizeof *y0), *v = malloc((neq + 1) * sizeof *v);
  for (size_t i = 0; i < neq; ++i) v[i] = 1.0 + 0.25 * (double)(i % 7);
  memcpy(y0, s->y, neq * sizeof *y0);

  /* the right-hand side: the faulty rank passes no output at all (NULL is allowed then) */
  fill(d1, neq);
  pend(ctx, s->sys, bad, st);
  expect_agreed(ctx, mfree_system_rhs(s->sys, 0.0, s->y, rank == bad ? NULL : d1), st, bad, why, "rhs");
  untouched(d1, neq, "rhs");
  CHECK(mfree_system_rhs(s->sys, 0.0, s->y, d1) == MFREE_SUCCESS, "rhs after the fault: %s", mpifluid_error(ctx));
  CHECK(mfree_system_rhs(twin->sys, 0.0, twin->y, d2) == MFREE_SUCCESS, "rhs, twin");
  mpitest_same_bits(d1, d2, (int64_t)neq, "rhs after the fault");

  /* a fault cleared before the call is not reported */
  pend(ctx, s->sys, bad, st);
  if (rank == bad) CHECK(mfree_system_set_pending_error(s->sys, MFREE_SUCCESS, NULL) == MFREE_SUCCESS, "clear");
  CHECK(mfree_system_rhs(s->sys, 0.0, s->y, d1) == MFREE_SUCCESS, "rhs after a cleared fault: %s",
        mpifluid_error(ctx));
  mpitest_same_bits(d1, d2, (int64_t)neq, "rhs after a cleared fault");

  /* the lumped mass: no matrix made; the next one the twin's */
  mfree_matrix_t *M = NULL, *Mt = NULL;
  pend(ctx, s->sys, bad, st);
  expect_agreed(ctx, mfree_system_assemble_mass(s->sys, s->y, 0, &M), st, bad, why, "mass");
  CHECK(M == NULL, "a matrix made by a failed call");
  CHECK(mfree_system_assemble_mass(s->sys, s->y, 0, &M) == MFREE_SUCCESS, "mass: %s", mpifluid_error(ctx));
  CHECK(mfree_system_assemble_mass(twin->sys, twin->y, 0, &Mt) == MFREE_SUCCESS, "mass, twin");
  if (M && Mt) same_matrix(M, Mt, "mass after the fault");
  mfree_matrix_destroy(&M);
  mfree_matrix_destroy(&Mt);

  /* the interpolation matrix */
  pend(ctx, s->sys, bad, st);
  expect_agreed(ctx, mfree_system_assemble_interpolation(s->sys, s->y, &M), st, bad, why, "interpolation");
  CHECK(M == NULL, "an interpolation matrix made by a failed call");
  CHECK(mfree_system_assemble_interpolation(s->sys, s->y, &M) == MFREE_SUCCESS, "interpolation: %s",
        mpifluid_error(ctx));
  CHECK(mfree_system_assemble_interpolation(twin->sys, twin->y, &Mt) == MFREE_SUCCESS, "interpolation, twin");
  if (M && Mt) same_matrix(M, Mt, "interpolation after the fault");
  mfree_matrix_destroy(&M);
  mfree_matrix_destroy(&Mt);

  /* the mass products, lumped and consistent */
  for (int consistent = 0; consistent < 2; ++consistent) {
    fill(d1, neq);
    pend(ctx, s->sys, bad, st);
    expect_agreed(ctx, mfree_system_apply_mass(s->sys, s->y, consistent, v, rank == bad ? NULL : d1), st, bad, why,
                  consistent ? "consistent mass product" : "lumped mass product");
    untouched(d1, neq, "mass product");
    CHECK(mfree_system_apply_mass(s->sys, s->y, consistent, v, d1) == MFREE_SUCCESS, "mass product: %s",
          mpifluid_error(ctx));
    CHECK(mfree_system_apply_mass(twin->sys, twin->y, consistent, v, d2) == MFREE_SUCCESS, "mass product, twin");
    mpitest_same_bits(d1, d2, (int64_t)neq, consistent ? "consistent product after the fault" : "lumped product");
  }

  /* the interpolated velocity */
  fill(d1, nd);
  pend(ctx, s->sys, bad, st);
  expect_agreed(ctx, mfree_system_get_velocity(s->sys, s->y, d1), st, bad, why, "velocity");
  untouched(d1, nd, "velocity");
  CHECK(mfree_system_get_velocity(s->sys, s->y, d1) == MFREE_SUCCESS, "velocity: %s", mpifluid_error(ctx));
  CHECK(mfree_system_get_velocity(twin->sys, twin->y, d2) == MFREE_SUCCESS, "velocity, twin");
  mpitest_same_bits(d1, d2, (int64_t)nd, "velocity after the fault");

  /* the wall force */
  double f1[2], f2[2] = {0, 0};
  fill(f1, 2);
  pend(ctx, s->sys, bad, st);
  expect_agreed(ctx, mfree_system_get_wall_force(s->sys, s->y, f1, 0, NULL), st, bad, why, "wall force");
  untouched(f1, 2, "wall force");
  CHECK(mfree_system_get_wall_force(s->sys, s->y, f1, 0, NULL) == MFREE_SUCCESS, "wall force: %s",
        mpifluid_error(ctx));
  CHECK(mfree_system_get_wall_force(twin->sys, twin->y, f2, 0, NULL) == MFREE_SUCCESS, "wall force, twin");
  mpitest_same_bits(f1, f2, 2, "wall force after the fault");

  /* five steps: y, t and the step count untouched by the failed call */
  int64_t five = 5, steps = -1;
  double t = 0.25 * turn, tt = 0.25 * turn;
  pend(ctx, s->sys, bad, st);
  expect_agreed(ctx,
                mfree_system_integrate(s->sys, MFREE_INTEGRATOR_LEAPFROG, s->y, &t, 1.0, 0.5, 0.0, mpifluid_stop_at,
                                       &five, &steps),
                st, bad, why, "integrate");
  CHECK(steps == 0 && t == 0.25 * turn, "integrate: %lld steps, t = %g", (long long)steps, t);
  mpitest_same_bits(s->y, y0, (int64_t)neq, "the state after the failed integration");
  CHECK(mfree_system_integrate(s->sys, MFREE_INTEGRATOR_LEAPFROG, s->y, &t, 1.0, 0.5, 0.0, mpifluid_stop_at, &five,
                               &steps) == MFREE_SUCCESS &&
            steps == 5,
        "integrate: %lld steps (%s)", (long long)steps, mpifluid_error(ctx));
  CHECK(mfree_system_integrate(twin->sys, MFREE_INTEGRATOR_LEAPFROG, twin->y, &tt, 1.0, 0.5, 0.0, mpifluid_stop_at,
                               &five, &steps) == MFREE_SUCCESS,
        "integrate, twin");
  CHECK(t == tt, "time %.17g, twin %.17g", t, tt);
  mpitest_same_bits(s->y, twin->y, (int64_t)neq, "the state after five steps");

  /* a particle move that keeps every particle: nothing moved by the failed one */
  memcpy(y0, s->y, neq * sizeof *y0);
  pend(ctx, s->sys, bad, st);
  expect_agreed(ctx, mfree_system_move_particles(s->sys, s->n_owned, keep_all, NULL, s->y, (int64_t)neq), st, bad,
                why, "move");
  mpitest_same_bits(s->y, y0, (int64_t)neq, "the state after the failed move");
  int32_t neq_now = -1;
  CHECK(mfree_system_get_size(s->sys, &neq_now) == MFREE_SUCCESS && neq_now == (int32_t)neq, "neq %d after the move",
        (int)neq_now);
  CHECK(mfree_system_move_particles(s->sys, s->n_owned, keep_all, NULL, s->y, (int64_t)neq) == MFREE_SUCCESS,
        "move: %s", mpifluid_error(ctx));
  CHECK(mfree_system_move_particles(twin->sys, twin->n_owned, keep_all, NULL, twin->y, (int64_t)neq) ==
            MFREE_SUCCESS,
        "move, twin");
  mpitest_same_bits(s->y, twin->y, (int64_t)neq, "the state after the move");
  CHECK(mfree_system_rhs(s->sys, 0.0, s->y, d1) == MFREE_SUCCESS &&
            mfree_system_rhs(twin->sys, 0.0, twin->y, d2) == MFREE_SUCCESS,
        "rhs after the move: %s", mpifluid_error(ctx));
  mpitest_same_bits(d1, d2, (int64_t)neq, "rhs after the move");
  free(d1), free(d2), free(y0), free(v);
}

/* The bar's right-hand side at t = 1 us (stress 0) or its stress (stress 1). */
static mfree_status_t bar_output(mfree_system_t *sys, int stress, const double *y, double *out) {
  return stress ? mfree_system_get_stress(sys, 1e-6, y, out) : mfree_system_rhs(sys, 1e-6, y, out);
}

/* The elastodynamic bar on ranks: rhs, stress and integrate fail alike, then give what
 * they gave before the fault. */
static void bar_calls(mfree_context_t *ctx, int turn) {
  const int bad = turn == 0 ? size - 1 : 0;
  const mfree_status_t st = turn == 0 ? MFREE_ERR_ARG : MFREE_ERR_MISMATCH;
  const char *why = "out holds 3 values, more are needed";
  mpibar_t b;
  CHECK(mpibar_make(&b, ctx, MPI_COMM_WORLD, 40, BAR_SLAB) == 0, "bar");
  const size_t neq = 2 * (size_t)b.n_owned, no = (size_t)b.n_owned;
  double *y = calloc(neq + 1, sizeof *y), *ref = malloc((neq + 1) * sizeof *ref), *d = malloc((neq + 1) * sizeof *d);
  for (size_t i = 0; i < no; ++i) y[i] = 1e-6 * sin(0.3 * (double)b.id[i]);
  for (int stress = 0; stress < 2; ++stress) { /* the right-hand side, then the stress */
    const char *what = stress ? "bar stress" : "bar rhs";
    const size_t nout = stress ? no : neq;
    CHECK(bar_output(b.sys, stress, y, ref) == MFREE_SUCCESS, "%s: %s", what, mpifluid_error(ctx));
    fill(d, nout);
    pend(ctx, b.sys, bad, st);
    expect_agreed(ctx, bar_output(b.sys, stress, y, d), st, bad, why, what);
    untouched(d, nout, what);
    CHECK(bar_output(b.sys, stress, y, d) == MFREE_SUCCESS, "%s after the fault: %s", what, mpifluid_error(ctx));
    mpitest_same_bits(d, ref, (int64_t)nout, stress ? "bar stress after the fault" : "bar rhs after the fault");
  }

  double t = 0.0;
  int64_t steps = -1;
  memcpy(ref, y, neq * sizeof *ref);
  pend(ctx, b.sys, bad, st);
  expect_agreed(ctx, mfree_system_integrate(b.sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, 1e-6, 0.5, 0.0, NULL, NULL, &steps),
                st, bad, why, "bar integrate");
  CHECK(steps == 0 && t == 0.0, "bar integrate: %lld steps, t = %g", (long long)steps, t);
  mpitest_same_bits(y, ref, (int64_t)neq, "the bar's state after the failed integration");
  CHECK(mfree_system_integrate(b.sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, 1e-6, 0.5, 0.0, NULL, NULL, &steps) ==
                MFREE_SUCCESS &&
            steps > 0 && t == 1e-6,
        "bar integrate after the fault: %lld steps, t = %g (%s)", (long long)steps, t, mpifluid_error(ctx));
  free(y), free(ref), free(d);
  mpibar_free(&b);
}

/* One process: the next call returns the fault at once, its message without a rank;
 * nothing written; then the call works; bad statuses refused. */
static void one_process(mfree_context_t *ctx, const damb_t *b) {
  mfree_system_t *one = NULL;
  CHECK(mfree_system_create_fluid(ctx, 2, b->n, &one) == MFREE_SUCCESS && damb_configure(b, one) == MFREE_SUCCESS &&
            mfree_system_set_masses(one, b->m, 1) == MFREE_SUCCESS,
        "one-process fluid: %s", mpifluid_error(ctx));
  const size_t neq = 5 * (size_t)b->n;
  double *ref = malloc(neq * sizeof *ref), *d = malloc(neq * sizeof *d);
  CHECK(mfree_system_rhs(one, 0.0, b->y, ref) == MFREE_SUCCESS, "one-process rhs");
  CHECK(mfree_system_set_pending_error(one, MFREE_ERR_ARG, "mfree_system_rhs: ydot holds 3 elements, 1440 are needed") ==
            MFREE_SUCCESS,
        "set_pending_error, one process");
  fill(d, neq);
  expect(ctx, mfree_system_rhs(one, 0.0, b->y, d), MFREE_ERR_ARG, "mfree_system_rhs: ydot holds 3 elements",
         "one-process rhs after the fault");
  CHECK(strstr(mpifluid_error(ctx), "rank") == NULL, "a rank in the one-process message: %s", mpifluid_error(ctx));
  untouched(d, neq, "one-process rhs");
  CHECK(mfree_system_rhs(one, 0.0, b->y, d) == MFREE_SUCCESS, "one-process rhs after the fault");
  mpitest_same_bits(d, ref, (int64_t)neq, "one-process rhs after the fault");
  /* no message: the status's description */
  CHECK(mfree_system_set_pending_error(one, MFREE_ERR_MISMATCH, NULL) == MFREE_SUCCESS, "set, no message");
  expect(ctx, mfree_system_apply_mass(one, b->y, 0, b->y, d), MFREE_ERR_MISMATCH,
         mfree_status_string(MFREE_ERR_MISMATCH), "one-process product after a fault without message");
  /* not an error status: refused, nothing pending */
  expect(ctx, mfree_system_set_pending_error(one, MFREE_FAIL_NONFINITE, "x"), MFREE_ERR_ARG, "not an error status",
         "a positive status");
  expect(ctx, mfree_system_set_pending_error(one, (mfree_status_t)-50, "x"), MFREE_ERR_ARG, "not an error status",
         "an unknown status");
  CHECK(mfree_system_set_pending_error(NULL, MFREE_ERR_ARG, "x") == MFREE_ERR_NULL, "a NULL system");
  CHECK(mfree_system_rhs(one, 0.0, b->y, d) == MFREE_SUCCESS, "one-process rhs after refused settings");
  mpitest_same_bits(d, ref, (int64_t)neq, "one-process rhs after refused settings");
  free(ref), free(d);
  mfree_system_destroy(&one);
}

int main(int argc, char **argv) {
  damb_t b;
  int *owner = NULL;
  rankfluid_t s, twin; /* s: sees the faults; twin: the good calls only */
  mfree_context_t *ctx = mpifluid_pair(&argc, &argv, &rank, &size, &b, &owner, NULL, &s, &twin);
  for (int turn = 0; turn < 2; ++turn) {
    fluid_calls(ctx, &s, &twin, turn);
    bar_calls(ctx, turn);
  }
  if (rank == 0) one_process(ctx, &b);
  mpifluid_pair_free(&b, owner, &s, &twin);
  mfree_context_destroy(&ctx);
  const int rc = mpitest_finish("t154-mpi-pending-error");
  MPI_Finalize();
  return rc;
}
