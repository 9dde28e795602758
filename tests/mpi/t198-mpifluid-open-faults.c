/* Faults of the open boundaries on ranks (label mpi), on 1, 2 and 4 ranks, t195's channel
 * (mpifluid_channel): every case returns the same status on every rank, and none hangs.
 * - open boundaries set on the last rank only: the integration returns MFREE_ERR_ARG
 *   ("ranks disagree on open boundaries") and takes no step; the update too ("ranks
 *   disagree on the open boundaries");
 * - a gate at another speed on the last rank: the update, MFREE_ERR_ARG;
 * - a non-finite time or a NULL state on the last rank only: MFREE_ERR_ARG / MFREE_ERR_NULL,
 *   "rank R: ..." naming it;
 * - an active count above the capacity (every rank's items): MFREE_ERR_ARG; a negative one
 *   at the setter;
 * - global ids that are not 0 .. N - 1 (the middle particle owned by no rank): MFREE_ERR_INPUT;
 * - no halo rebuild callback: MFREE_ERR_STATE;
 * - a capacity of 60 particles: the integration stops with MFREE_FAIL_CAPACITY on every rank
 *   with the one-process message, at the same time and with the same counts;
 * - a fault pending on the last rank (mfree_system_set_pending_error): the right-hand side
 *   returns it on every rank, and the next one runs. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpifluid.h"
#include "mpitest.h"

enum { N = 120 };

/* The channel of n particles on the ranks (owners by id modulo the ranks; owner -1 for the
 * middle particle with orphan); its open boundaries unless none. */
static mfree_status_t make(rankfluid_t *r, mfree_context_t *ctx, int n, int orphan, int none, double speed) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  damb_t b;
  mpifluid_channel(&b, n);
  int *owner = malloc((size_t)n * sizeof *owner);
  for (int i = 0; i < n; ++i) owner[i] = i % size;
  if (orphan) owner[n / 2] = -1;
  mfree_status_t st = rankfluid_make(r, ctx, MPI_COMM_WORLD, &b, owner, 4.0 * b.h + 0.25 * b.d, 0);
  if (st == MFREE_SUCCESS && !none) st = mpifluid_open(r->sys, speed);
  free(owner);
  damb_free(&b);
  return st;
}

int main(int argc, char **argv) {
  int rank = 0, size = 1;
  mfree_context_t *ctx = mpitest_start(&argc, &argv, &rank, &size);
  const int last = size - 1;
  rankfluid_t r;
  double t = 0.0;
  int64_t steps = -1;

  if (size > 1) { /* set on the last rank only */
    CHECK(make(&r, ctx, N, 0, rank != last, 0.0) == MFREE_SUCCESS, "set-up: %s", mpifluid_error(ctx));
    expect(ctx, mfree_system_integrate(r.sys, MFREE_INTEGRATOR_LEAPFROG, r.y, &t, 0.01, 0.5, 0.0, NULL, NULL, &steps),
           MFREE_ERR_ARG, "ranks disagree on open boundaries", "open boundaries on one rank, integrate");
    CHECK(steps == 0 && t == 0.0, "the refused integration took %lld steps", (long long)steps);
    expect(ctx, mfree_system_update_open_boundaries(r.sys, 0.0, r.y), MFREE_ERR_ARG, "ranks disagree",
           "open boundaries on one rank, update");
    rankfluid_free(&r);
    CHECK(make(&r, ctx, N, 0, 0, rank == last ? 2.0 : 0.0) == MFREE_SUCCESS, "set-up: %s", mpifluid_error(ctx));
    expect(ctx, mfree_system_update_open_boundaries(r.sys, 0.0, r.y), MFREE_ERR_ARG, "ranks disagree",
           "another gate speed on one rank");
    rankfluid_free(&r);
  }

  CHECK(make(&r, ctx, N, 0, 0, 0.0) == MFREE_SUCCESS, "set-up: %s", mpifluid_error(ctx));
  expect_agreed(ctx, mfree_system_update_open_boundaries(r.sys, rank == last ? NAN : 0.0, r.y), MFREE_ERR_ARG, last,
                "time must be finite", "a non-finite time on one rank");
  expect_agreed(ctx, mfree_system_update_open_boundaries(r.sys, 0.0, rank == last ? NULL : r.y), MFREE_ERR_NULL,
                last, "y is NULL", "a NULL state on one rank");
  expect(ctx, mfree_system_set_active(r.sys, -1), MFREE_ERR_ARG, "negative", "a negative active count");
  expect(ctx, mfree_system_set_active(r.sys, N + 1), MFREE_SUCCESS, NULL, "an active count (checked later)");
  expect(ctx, mfree_system_update_open_boundaries(r.sys, 0.0, r.y), MFREE_ERR_ARG, "active count",
         "an active count above the capacity");
  rankfluid_free(&r);

  CHECK(make(&r, ctx, N, 1, 0, 0.0) == MFREE_SUCCESS, "set-up: %s", mpifluid_error(ctx));
  expect(ctx, mfree_system_update_open_boundaries(r.sys, 0.0, r.y), MFREE_ERR_INPUT, "global ids 0 ..",
         "a particle owned by no rank");
  rankfluid_free(&r);

  CHECK(make(&r, ctx, N, 0, 0, 0.0) == MFREE_SUCCESS, "set-up: %s", mpifluid_error(ctx));
  mfree_system_set_halo_rebuild(r.sys, NULL);
  expect(ctx, mfree_system_update_open_boundaries(r.sys, 0.0, r.y), MFREE_ERR_STATE, "rebuild callback",
         "no rebuild callback");
  rankfluid_free(&r);

  /* the pool exhausted, on the ranks as in one process */
  damb_t b;
  mpifluid_channel(&b, 60);
  mfree_system_t *one = NULL;
  double t1 = 0.0;
  int64_t in1 = -1, in = -2;
  mfree_status_t st1 = mfree_system_create_fluid(ctx, 2, 60, &one);
  if (st1 == MFREE_SUCCESS) st1 = damb_configure(&b, one);
  if (st1 == MFREE_SUCCESS) st1 = mfree_system_set_masses(one, b.m, 1);
  if (st1 == MFREE_SUCCESS) st1 = mpifluid_open(one, 0.0);
  if (st1 == MFREE_SUCCESS) st1 = mfree_system_integrate(one, MFREE_INTEGRATOR_LEAPFROG, b.y, &t1, 1.0, 0.5, 0.0, NULL,
                                                         NULL, NULL);
  CHECK(st1 == MFREE_FAIL_CAPACITY, "one process: status %d: %s", (int)st1, mpifluid_error(ctx));
  char msg1[1024] = {0};
  mfree_context_get_last_error(ctx, NULL, msg1, sizeof msg1);
  mfree_system_get_inflow(one, 0, &in1, NULL);
  mfree_system_destroy(&one);
  damb_free(&b);
  CHECK(make(&r, ctx, 60, 0, 0, 0.0) == MFREE_SUCCESS, "set-up: %s", mpifluid_error(ctx));
  t = 0.0;
  expect(ctx, mfree_system_integrate(r.sys, MFREE_INTEGRATOR_LEAPFROG, r.y, &t, 1.0, 0.5, 0.0, NULL, NULL, NULL),
         MFREE_FAIL_CAPACITY, strstr(msg1, "the pool"), "the pool exhausted");
  mfree_system_get_inflow(r.sys, 0, &in, NULL);
  CHECK(t == t1 && in == in1 && in > 0, "exhausted at t = %.17g with %lld in; one process %.17g, %lld", t,
        (long long)in, t1, (long long)in1);

  double *Mv = calloc(5 * ((size_t)r.n_owned + 1), sizeof *Mv);
  /* a fault pending on one rank (a host's check): the right-hand side returns it on every
     rank, and the next one runs */
  if (rank == last) mfree_system_set_pending_error(r.sys, MFREE_ERR_INPUT, "a host's fault");
  expect_agreed(ctx, mfree_system_rhs(r.sys, t, r.y, Mv), MFREE_ERR_INPUT, last, "a host's fault",
                "a fault pending in the right-hand side");
  expect(ctx, mfree_system_rhs(r.sys, t, r.y, Mv), MFREE_SUCCESS, NULL, "the right-hand side after the fault");
  free(Mv);
  rankfluid_free(&r);
  mfree_context_destroy(&ctx);
  const int rc = mpitest_finish("t198-mpifluid-open-faults");
  MPI_Finalize();
  return rc;
}
