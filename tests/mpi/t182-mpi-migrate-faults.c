/* Faults of the migration calls on 1-4 ranks (label mpi): every rank returns the
 * documented status with a message naming the failing rank, nothing moves, and no rank
 * waits for ever (the CTest timeout bounds it):
 *  - a NULL handle or output on every function (MFREE_ERR_NULL, local);
 *  - create: a NULL context, MPI_COMM_NULL, a dimension of 4 on one rank, ranks that
 *    disagree on the dimension;
 *  - set_partitioner and add_field: an unknown method, a tolerance outside [1, 10] or NaN,
 *    item or stride bytes out of range (nothing changed or registered);
 *  - partition: a negative count, NULL positions, ld below dim, a NaN position on one rank,
 *    rebalance 2, ranks that disagree on rebalance or on the partitioner;
 *  - set_owners: an owner out of range on one rank (above and below), NULL owners;
 *  - execute: without a plan, twice, a capacity one short on one rank (the message gives
 *    the size needed), a field without data, ranks that registered different fields (one
 *    more field; the same sizes in another order): the same status on every rank, the
 *    plan kept, and a correct execute afterwards moves everything;
 *  - get_counts / get_owners without a plan, get_owners with a short array;
 *  - set_pending_error: nothing to hand over, then a failure of one rank handed to the
 *    next collective call, which every rank returns;
 *  - a plan destroyed after MPI_Finalize: only its memory freed (no abort).
 * A last check reads mfree_mpi.h and fails when a mfree_migration_* function has no row
 * here, so that a new function comes with its bad-input rows. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "migstate.h"

static int rank = 0, size = 1;

#if !defined(MFREE_MPI_HEADER) || !defined(MFREE_TEST_SOURCE)
#error "MFREE_MPI_HEADER and MFREE_TEST_SOURCE (mfree_mpi.h and this file) must be defined by the build"
#endif

/* Every mfree_migration_* function declared in the header is called in this file with a
 * bad argument (a row above names it followed by "(NULL" or "(m"); returns the missing. */
static int missing_rows(void) {
  char *h = slurp(MFREE_MPI_HEADER), *me = slurp(MFREE_TEST_SOURCE);
  int missing = 0, found = 0;
  CHECK(h && me, "cannot read %s or %s", MFREE_MPI_HEADER, MFREE_TEST_SOURCE);
  for (const char *p = h; h && me && (p = strstr(p, "MFREE_MPI_API mfree_status_t mfree_migration_")); ++p) {
    char name[96] = "", call[112];
    sscanf(p + strlen("MFREE_MPI_API mfree_status_t "), "%95[a-z_]", name);
    ++found;
    snprintf(call, sizeof call, "%s(NULL", name);
    if (!strstr(me, call)) {
      CHECK(0, "%s has no bad-input row (no call %s...) in this test", name, call);
      ++missing;
    }
  }
  CHECK(found >= 13, "only %d mfree_migration_* functions found in %s", found, MFREE_MPI_HEADER);
  free(h);
  free(me);
  return missing;
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const int last = size - 1;
  char who[32];
  snprintf(who, sizeof who, "rank %d:", last);
  mfree_context_t *ctx = NULL;
  mfree_context_create(&ctx);

  /* ---- NULL handles and outputs ---- */
  mfree_migration_t *m = NULL;
  int32_t n32 = 0;
  int64_t n64 = 0;
  mfree_context_t *got_ctx = NULL;
  double xd[2] = {0, 0};
  CHECK(mfree_migration_create(NULL, MPI_COMM_WORLD, 2, &m) == MFREE_ERR_NULL, "create, NULL context");
  expect(ctx, mfree_migration_create(ctx, MPI_COMM_WORLD, 2, NULL), MFREE_ERR_NULL, "output", "create, NULL out");
  expect(ctx, mfree_migration_create(ctx, MPI_COMM_NULL, 2, &m), MFREE_ERR_ARG, "MPI_COMM_NULL", "MPI_COMM_NULL");
  CHECK(mfree_migration_create_f(NULL, (int32_t)MPI_Comm_c2f(MPI_COMM_WORLD), 2, &m) == MFREE_ERR_NULL, "create_f");
  CHECK(mfree_migration_destroy(NULL) == MFREE_SUCCESS && mfree_migration_destroy(&m) == MFREE_SUCCESS,
        "destroy of NULL");
  CHECK(mfree_migration_set_partitioner(NULL, MFREE_PARTITIONER_RCB, 1.05) == MFREE_ERR_NULL, "NULL handle");
  CHECK(mfree_migration_add_field(NULL, xd, 8, 8) == MFREE_ERR_NULL, "NULL handle");
  CHECK(mfree_migration_clear_fields(NULL) == MFREE_ERR_NULL, "NULL handle");
  CHECK(mfree_migration_partition(NULL, 1, xd, 2, 1, &n32) == MFREE_ERR_NULL, "NULL handle");
  CHECK(mfree_migration_set_owners(NULL, 0, NULL, &n32) == MFREE_ERR_NULL, "NULL handle");
  CHECK(mfree_migration_execute(NULL, 0) == MFREE_ERR_NULL, "NULL handle");
  CHECK(mfree_migration_get_counts(NULL, &n32, &n32, &n64, &n64) == MFREE_ERR_NULL, "NULL handle");
  CHECK(mfree_migration_get_owners(NULL, &n32, 1) == MFREE_ERR_NULL, "NULL handle");
  CHECK(mfree_migration_get_context(NULL, &got_ctx) == MFREE_ERR_NULL, "NULL handle");
  CHECK(mfree_migration_set_pending_error(NULL) == MFREE_ERR_NULL, "NULL handle");

  /* ---- create: a bad or disagreeing dimension ---- */
  expect(ctx, mfree_migration_create(ctx, MPI_COMM_WORLD, rank == last ? 4 : 2, &m), MFREE_ERR_ARG, who,
         "create, dim 4 on the last rank");
  CHECK(m == NULL, "no plan after a failed create");
  if (size > 1) {
    expect(ctx, mfree_migration_create(ctx, MPI_COMM_WORLD, rank == last ? 3 : 2, &m), MFREE_ERR_ARG,
           "ranks disagree on the dimension", "create, dim 3 on the last rank only");
    CHECK(m == NULL, "no plan after a disagreement");
  }
  CHECK(mfree_migration_create(ctx, MPI_COMM_WORLD, 2, &m) == MFREE_SUCCESS, "create");
  CHECK(mfree_migration_get_context(m, NULL) == MFREE_ERR_NULL, "get_context, NULL out");
  CHECK(mfree_migration_get_context(m, &got_ctx) == MFREE_SUCCESS && got_ctx == ctx, "get_context");

  /* ---- local setters ---- */
  expect(ctx, mfree_migration_set_partitioner(m, 7, 1.05), MFREE_ERR_ARG, "unknown partitioner", "method 7");
  expect(ctx, mfree_migration_set_partitioner(m, MFREE_PARTITIONER_HSFC, 0.5), MFREE_ERR_ARG, "[1, 10]", "tol 0.5");
  expect(ctx, mfree_migration_set_partitioner(m, MFREE_PARTITIONER_HSFC, NAN), MFREE_ERR_ARG, "[1, 10]", "tol NaN");
  expect(ctx, mfree_migration_add_field(m, xd, 0, 8), MFREE_ERR_ARG, "item_bytes", "item 0");
  expect(ctx, mfree_migration_add_field(m, xd, 16, 8), MFREE_ERR_ARG, "stride_bytes", "stride below item");

  cloud_t c;
  cloud_make(&c, 2, 12, 182);
  int *part = malloc(sizeof(int) * (size_t)c.n), *owners = malloc(sizeof(int) * (size_t)(c.n + 1));
  decompose(&c, DECOMP_RANDOM, MPI_COMM_WORLD, part);
  mig_state_t s;
  mig_state_init(&s, &c, part, rank, c.n, 0.0);
  CHECK(mig_state_register(&s, m) == MFREE_SUCCESS, "register");
  int32_t n_new = -1;

  /* ---- execute and getters without a plan ---- */
  expect(ctx, mfree_migration_execute(m, s.cap), MFREE_ERR_STATE, "no plan", "execute without a plan");
  expect(ctx, mfree_migration_get_counts(m, &n32, NULL, NULL, NULL), MFREE_ERR_STATE, "no plan", "counts");
  expect(ctx, mfree_migration_get_owners(m, owners, c.n), MFREE_ERR_STATE, "no plan", "owners");

  /* ---- partition ---- */
  const int pn = s.n > 0; /* (a random share can be empty on a rank) */
  expect(ctx, mfree_migration_partition(m, rank == last ? -1 : s.n, s.x, 3, 1, &n_new), MFREE_ERR_ARG, who,
         "negative count on the last rank");
  if (s.n > 0 || size == 1) {
    int bad = rank == 0 && pn, any = 0;
    MPI_Allreduce(&bad, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    if (any) {
      expect(ctx, mfree_migration_partition(m, s.n, bad ? NULL : s.x, 3, 1, &n_new), MFREE_ERR_NULL,
             "rank 0: positions pointer is NULL", "NULL positions on rank 0");
      const double keep = s.x[1];
      if (bad) s.x[1] = NAN;
      expect(ctx, mfree_migration_partition(m, s.n, s.x, 3, 1, &n_new), MFREE_ERR_INPUT,
             "rank 0: position of particle 0, component 1", "NaN position on rank 0");
      if (bad) s.x[1] = keep;
    }
  }
  expect(ctx, mfree_migration_partition(m, s.n, s.x, rank == last ? 1 : 3, 1, &n_new), MFREE_ERR_ARG,
         "leading dimension", "ld below dim on the last rank");
  expect(ctx, mfree_migration_partition(m, s.n, s.x, 3, 2, &n_new), MFREE_ERR_ARG, "rebalance must be 0 or 1",
         "rebalance 2");
  expect(ctx, mfree_migration_execute(m, s.cap), MFREE_ERR_STATE, "no plan", "execute after a failed plan");
  if (size > 1) {
    expect(ctx, mfree_migration_partition(m, s.n, s.x, 3, rank == last ? 0 : 1, &n_new), MFREE_ERR_ARG,
           "ranks disagree on rebalance", "rebalance on all but the last rank");
    mfree_migration_set_partitioner(m, rank == last ? MFREE_PARTITIONER_HSFC : MFREE_PARTITIONER_RCB, 1.05);
    expect(ctx, mfree_migration_partition(m, s.n, s.x, 3, 1, &n_new), MFREE_ERR_ARG,
           "ranks disagree on the partitioner", "HSFC on the last rank only");
    mfree_migration_set_partitioner(m, MFREE_PARTITIONER_RCB, rank == last ? 1.2 : 1.05);
    expect(ctx, mfree_migration_partition(m, s.n, s.x, 3, 1, &n_new), MFREE_ERR_ARG,
           "ranks disagree on the imbalance tolerance", "tolerance on the last rank only");
    mfree_migration_set_partitioner(m, MFREE_PARTITIONER_RCB, 1.05);
  }
  mig_state_check(&s, &c, 0.0, "after the refused partitions (nothing moved)");

  /* ---- set_owners ---- */
  for (int k = 0; k < s.n; ++k) owners[k] = (rank + 1) % size;
  if (s.n > 0 || size == 1) {
    int bad = rank == 0 && pn, any = 0;
    MPI_Allreduce(&bad, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    if (any) {
      if (bad) owners[0] = size;
      expect(ctx, mfree_migration_set_owners(m, s.n, owners, &n_new), MFREE_ERR_INPUT,
             "rank 0: owner of particle 0 is rank", "owner = size on rank 0");
      if (bad) owners[0] = -1;
      expect(ctx, mfree_migration_set_owners(m, s.n, owners, &n_new), MFREE_ERR_INPUT, "not in [0, ",
             "owner -1 on rank 0");
      owners[0] = (rank + 1) % size;
      expect(ctx, mfree_migration_set_owners(m, s.n, bad ? NULL : owners, &n_new), MFREE_ERR_NULL,
             "rank 0: owners pointer is NULL", "NULL owners on rank 0");
    }
  }
  expect(ctx, mfree_migration_set_owners(m, rank == last ? -3 : s.n, owners, &n_new), MFREE_ERR_ARG, who,
         "negative count on the last rank");
  expect(ctx, mfree_migration_execute(m, s.cap), MFREE_ERR_STATE, "no plan", "execute after a failed set_owners");

  /* ---- execute: refused on one rank, agreed on all, the plan kept ---- */
  CHECK(mfree_migration_set_owners(m, s.n, owners, &n_new) == MFREE_SUCCESS, "set_owners");
  if (s.n > 0) {
    expect(ctx, mfree_migration_get_owners(m, owners, s.n - 1), MFREE_ERR_ARG, "owned particles",
           "get_owners, short");
    expect(ctx, mfree_migration_get_owners(m, NULL, s.n), MFREE_ERR_NULL, "NULL", "get_owners, NULL");
  }
  {
    int gives = n_new > 0 && rank == last, any = 0;
    MPI_Allreduce(&gives, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    if (any) {
      char needle[96];
      snprintf(needle, sizeof needle, "%s capacity", who);
      expect(ctx, mfree_migration_execute(m, gives ? n_new - 1 : s.cap), MFREE_ERR_ARG, needle,
             "capacity one short on the last rank");
      mig_state_check(&s, &c, 0.0, "after the refused execute (nothing moved)");
    }
  }
  if (size > 1) {
    /* one more field on the last rank */
    double *extra = calloc((size_t)c.n + 1, sizeof(double));
    if (rank == last) mfree_migration_add_field(m, extra, 8, 8);
    expect(ctx, mfree_migration_execute(m, s.cap), MFREE_ERR_ARG, "ranks disagree on the registered fields",
           "one more field on the last rank");
    /* the same sizes in another order on the last rank */
    mfree_migration_clear_fields(m);
    if (rank == last) {
      mfree_migration_add_field(m, s.v, 16, 16);
      mfree_migration_add_field(m, s.x, 16, 24);
    } else {
      mfree_migration_add_field(m, s.x, 16, 24);
      mfree_migration_add_field(m, s.v, 16, 16);
    }
    mfree_migration_add_field(m, s.rho, 8, 8);
    mfree_migration_add_field(m, &s.flags[0].tag, rank == last ? 4 : 8, (int64_t)sizeof(mig_flags_t));
    mfree_migration_add_field(m, s.id, rank == last ? 8 : 4, 8);
    expect(ctx, mfree_migration_execute(m, s.cap), MFREE_ERR_ARG, "ranks disagree on the registered fields",
           "the same record size, other item sizes on the last rank");
    free(extra);
    mig_state_check(&s, &c, 0.0, "after the refused layouts (nothing moved)");
  }
  /* a capacity below the owned particles the arrays hold (but not below n_new) */
  {
    int32_t n_owned_plan = 0;
    mfree_migration_get_counts(m, &n_owned_plan, NULL, NULL, NULL);
    int gives = n_owned_plan > n_new, any = 0;
    MPI_Allreduce(&gives, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    if (any) {
      expect(ctx, mfree_migration_execute(m, gives ? n_new : s.cap), MFREE_ERR_ARG, "owned particles the plan moves",
             "capacity below n_owned on the ranks that lose particles");
      mig_state_check(&s, &c, 0.0, "after the refused execute (nothing moved)");
    }
    CHECK(any || size == 1, "no rank loses particles: the row above did not run");
  }
  /* a field without data */
  mfree_migration_clear_fields(m);
  mfree_migration_add_field(m, rank == 0 ? NULL : s.rho, 8, 8);
  expect(ctx, mfree_migration_execute(m, s.cap), MFREE_ERR_NULL, "rank 0: field 0 has no data", "NULL field data");
  /* the plan was kept through every refusal: the right fields and capacity move it */
  CHECK(mig_state_register(&s, m) == MFREE_SUCCESS, "register again");
  CHECK(mfree_migration_execute(m, s.cap) == MFREE_SUCCESS, "execute after the refusals");
  s.n = n_new;
  mig_state_check(&s, &c, 0.0, "after the execute");
  expect(ctx, mfree_migration_execute(m, s.cap), MFREE_ERR_STATE, "no plan", "a second execute");

  /* ---- a failure handed over by one rank ---- */
  mfree_context_t *ctx2 = NULL;
  mfree_context_create(&ctx2);
  mfree_migration_t *m2 = NULL;
  CHECK(mfree_migration_create(ctx2, MPI_COMM_WORLD, 2, &m2) == MFREE_SUCCESS, "create on ctx2");
  expect(ctx2, mfree_migration_set_pending_error(m2), MFREE_ERR_STATE, "no failure", "nothing to hand over");
  mfree_migration_clear_fields(m2);
  if (rank == last) mfree_context_set_error(ctx2, MFREE_ERR_ARG, "mfree_host_check: array q holds 3 elements");
  if (rank == last) CHECK(mfree_migration_set_pending_error(m2) == MFREE_SUCCESS, "hand over");
  expect(ctx2, mfree_migration_set_owners(m2, 0, NULL, &n_new), MFREE_ERR_ARG, "array q holds 3 elements",
         "the handed-over failure on every rank");
  CHECK(mfree_migration_set_owners(m2, 0, NULL, &n_new) == MFREE_SUCCESS && n_new == 0, "handed over once");
  mfree_migration_destroy(&m2);
  mfree_context_destroy(&ctx2);

  mfree_migration_destroy(&m);
  mig_state_free(&s);
  free(part);
  free(owners);
  cloud_free(&c);

  /* a plan with a Zoltan structure destroyed after MPI_Finalize: memory only */
  mfree_migration_t *late = NULL;
  const double xl[2] = {(double)rank, 0.0};
  CHECK(mfree_migration_create(ctx, MPI_COMM_WORLD, 2, &late) == MFREE_SUCCESS, "the late plan");
#ifdef MFREE_TEST_ZOLTAN
  CHECK(mfree_migration_partition(late, 1, xl, 2, 1, &n_new) == MFREE_SUCCESS, "the late plan's partition");
#else
  (void)xl;
#endif
  mfree_context_destroy(&ctx); /* the plan keeps the context alive */
  if (rank == 0) missing_rows();
  int rc = mpitest_finish("t182-mpi-migrate-faults");
  MPI_Finalize();
  if (mfree_migration_destroy(&late) != MFREE_SUCCESS || late) {
    fprintf(stderr, "t182-mpi-migrate-faults: rank %d: mfree_migration_destroy after MPI_Finalize failed\n", rank);
    rc = 1;
  }
  return rc;
}
