/* Load balance and extreme migrations on 1-4 ranks (label mpi):
 *  - a dam-break-like column (a 2D lattice 1 wide, 2 high) starts wholly on rank 0 (the
 *    others own nothing) and spreads over windows; at each window Zoltan repartitions it
 *    (RCB, then HSFC) and after each execute every rank's count is within 10 % of the mean;
 *    between rebalances the kept regions take the particles that crossed into them;
 *  - every particle sent to the last rank (the others lose all theirs), then the halo
 *    rebuilt and a field exchanged with ranks that own nothing, then a repartition from
 *    the one rank that holds all, balanced again;
 *  - a partition and an execute with no particles on any rank;
 * and after every move each particle's fields are bitwise those of its id and every id is
 * owned exactly once. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "migstate.h"

static int rank = 0, size = 1;

static void expect_ok(mfree_context_t *ctx, mfree_status_t st, const char *what) {
  char msg[600] = "";
  mfree_context_get_last_error(ctx, NULL, msg, sizeof msg);
  CHECK(st == MFREE_SUCCESS, "%s: status %d (%s)", what, (int)st, msg);
}

/* Every rank's count within 10 % of the mean. */
static void check_balance(const mig_state_t *s, const char *what) {
  int sum = 0, mn = 0, mx = 0;
  MPI_Allreduce(&s->n, &sum, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  MPI_Allreduce(&s->n, &mn, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  MPI_Allreduce(&s->n, &mx, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  const double mean = (double)sum / size;
  CHECK(mx <= 1.10 * mean && mn >= 0.90 * mean, "%s: counts from %d to %d, mean %.1f", what, mn, mx, mean);
}

/* One window: move to time t, partition (rebalance or kept regions), execute. */
static void window(mfree_context_t *ctx, mfree_migration_t *m, mig_state_t *s, const cloud_t *c, double t,
                   int rebalance, const char *what) {
  int32_t n_new = -1;
  mig_state_move(s, c, t);
  expect_ok(ctx, mfree_migration_partition(m, s->n, s->n ? s->x : NULL, 3, rebalance, &n_new), what);
  expect_ok(ctx, mfree_migration_execute(m, s->cap), what);
  s->n = n_new;
  mig_state_check(s, c, t, what);
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  cloud_t c;
  cloud_make(&c, 2, 30, 181);
  for (int i = 0; i < c.n; ++i) c.x[2 * i + 1] *= 2.0; /* the column: 1 wide, 2 high */
  mig_state_t s;
  mig_state_init(&s, &c, NULL, rank, c.n, 0.0); /* all on rank 0 */
  mig_state_check(&s, &c, 0.0, "start");

  mfree_context_t *ctx = NULL;
  mfree_migration_t *m = NULL;
  mfree_context_create(&ctx);
  expect_ok(ctx, mfree_migration_create(ctx, MPI_COMM_WORLD, 2, &m), "create");
  expect_ok(ctx, mig_state_register(&s, m), "register");
  int32_t n_new = -1;
  double t = 0.0; /* the time of the positions */

#ifdef MFREE_TEST_ZOLTAN
  /* 1. the column spreads; RCB, then HSFC, regions at every other window */
  const int methods[2] = {MFREE_PARTITIONER_RCB, MFREE_PARTITIONER_HSFC};
  for (int k = 0; k < 2; ++k) {
    expect_ok(ctx, mfree_migration_set_partitioner(m, methods[k], 1.05), "partitioner");
    for (int w = 0; w < 4; ++w) {
      char what[64];
      t += 0.25;
      snprintf(what, sizeof what, "%s window %d (t = %.2f)", k ? "HSFC" : "RCB", w, t);
      window(ctx, m, &s, &c, t, w % 2 == 0, what);
      if (w % 2 == 0) check_balance(&s, what);
    }
  }
#endif

  /* 2. all to the last rank, the others lose all theirs */
  int *owners = malloc(sizeof(int) * (size_t)(c.n + 1));
  for (int k = 0; k < s.n; ++k) owners[k] = size - 1;
  expect_ok(ctx, mfree_migration_set_owners(m, s.n, s.n ? owners : NULL, &n_new), "all to the last rank");
  CHECK(n_new == (rank == size - 1 ? c.n : 0), "n_new %d", n_new);
  expect_ok(ctx, mfree_migration_execute(m, s.cap), "execute: all to the last rank");
  s.n = n_new;
  mig_state_check(&s, &c, t, "all on the last rank");
  {
    /* the halo over ranks that own nothing: built, and a field exchanged */
    mfree_halo_t *halo = NULL;
    int32_t no = -1, ng = -1;
    expect_ok(ctx, mfree_halo_create(ctx, MPI_COMM_WORLD, 2, &halo), "halo");
    expect_ok(ctx, mfree_halo_setup(halo, s.n, s.n ? s.x : NULL, 3, s.n ? s.id : NULL, 0.1), "halo setup");
    expect_ok(ctx, mfree_halo_get_size(halo, &no, &ng), "halo size");
    CHECK(no == s.n && ng == 0, "owned %d ghosts %d", no, ng);
    expect_ok(ctx, mfree_halo_exchange(halo, 1, s.rho, 1), "exchange");
    mfree_halo_destroy(&halo);
  }
#ifdef MFREE_TEST_ZOLTAN
  /* 3. from the one rank holding all, balanced again (kept regions first: the last
   * rebalance's regions spread the particles without balancing them) */
  window(ctx, m, &s, &c, t, 0, "kept regions from one rank");
  window(ctx, m, &s, &c, t, 1, "rebalance from one rank");
  check_balance(&s, "rebalance from one rank");
#endif

#ifdef MFREE_TEST_ZOLTAN
  /* 4. no particles anywhere: a partition that has nothing to do */
  {
    mfree_migration_t *empty = NULL;
    expect_ok(ctx, mfree_migration_create(ctx, MPI_COMM_WORLD, 2, &empty), "create (empty)");
    for (int rebalance = 1; rebalance >= 0; --rebalance) {
      n_new = -1;
      expect_ok(ctx, mfree_migration_partition(empty, 0, NULL, 2, rebalance, &n_new), "partition of nothing");
      expect_ok(ctx, mfree_migration_execute(empty, 0), "execute of nothing");
      CHECK(n_new == 0, "n_new %d of nothing", n_new);
    }
    mfree_migration_destroy(&empty);
  }
#endif

  mfree_migration_destroy(&m);
  mfree_context_destroy(&ctx);
  mig_state_free(&s);
  free(owners);
  cloud_free(&c);
  const int rc = mpitest_finish("t181-mpi-migrate-balance");
  MPI_Finalize();
  return rc;
}
