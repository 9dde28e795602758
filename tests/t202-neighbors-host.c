/*
 * t202: host-supplied neighbour lists (mfree_particles_set_neighbors).
 *
 * Valid CSR lists, 0- or 1-based, copied or borrowed, are returned as given (0-based,
 * rows sorted as get_neighbors promises); every malformed list (a column out of range or
 * twice in a row, rowptr not monotone or not starting at the base) is refused with the
 * documented status and a message and leaves the previous lists in force; a borrowed
 * list that turns invalid is caught by setup; invalid particle data isolate particles in
 * host lists too; calls before setup are state errors.
 */
#include "testutil.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* 8 particles, the last 2 ghosts: 6 rows. Row 1 is empty, row 5 lacks the particle
 * itself, ghosts 6 and 7 appear as neighbours. */
enum { N = 8, NG = 2, ROWS = N - NG, NNZ = 12 };
static const int64_t ref_rowptr[ROWS + 1] = {0, 3, 3, 5, 9, 10, 12};
static const int32_t ref_cols[NNZ] = {0, 1, 7, /* */ 2, 6, /* */ 0, 3, 4, 5, /* */ 4, /* */ 1, 7};

static mfree_context_t *ctx;
static int grp_setup(void **s) {
  (void)s;
  return mfree_context_create(&ctx) != MFREE_SUCCESS;
}
static int grp_teardown(void **s) {
  (void)s;
  return mfree_context_destroy(&ctx) != MFREE_SUCCESS;
}

static double pos[N * 2];

/* A 2D set of N particles with NG ghosts and copied positions; no support (host lists
 * need none). */
static mfree_particles_t *new_set(void) {
  mfree_particles_t *ps = NULL;
  for (int i = 0; i < N * 2; ++i) pos[i] = 0.1 * i;
  assert_ok(ctx, mfree_particles_create(ctx, 2, N, &ps));
  assert_ok(ctx, mfree_particles_set_num_ghost(ps, NG));
  assert_ok(ctx, mfree_particles_set_positions(ps, pos, MFREE_LAYOUT_AOS, 2, MFREE_COPY));
  return ps;
}

typedef struct {
  int64_t rowptr[ROWS + 1];
  int32_t cols[N * N];
  int64_t nnz;
} lists_t;

static void get_lists(mfree_particles_t *ps, lists_t *l) {
  memset(l, 0xff, sizeof *l);
  assert_ok(ctx, mfree_particles_get_neighbor_nnz(ps, &l->nnz));
  assert_true(l->nnz >= 0 && l->nnz <= N * N);
  assert_ok(ctx, mfree_particles_get_neighbors(ps, l->rowptr, l->cols));
  assert_int_equal(l->rowptr[ROWS], l->nnz);
}

/* The lists equal (rowptr, cols) shifted down by base. */
static void assert_lists(mfree_particles_t *ps, const int64_t *rowptr, const int32_t *cols, int base) {
  lists_t l;
  get_lists(ps, &l);
  for (int i = 0; i <= ROWS; ++i) assert_int_equal(l.rowptr[i], rowptr[i] - base);
  for (int64_t k = 0; k < l.nnz; ++k) assert_int_equal(l.cols[k], cols[k] - base);
}

static void assert_ref(mfree_particles_t *ps) { assert_lists(ps, ref_rowptr, ref_cols, 0); }

static void shifted(int base, int64_t *rowptr, int32_t *cols) {
  for (int i = 0; i <= ROWS; ++i) rowptr[i] = ref_rowptr[i] + base;
  for (int k = 0; k < NNZ; ++k) cols[k] = ref_cols[k] + base;
}

/* ---------------------------------------------------------------------------------- */

static void test_copied_returned_as_given(void **s) {
  (void)s;
  for (int base = 0; base <= 1; ++base) {
    mfree_particles_t *ps = new_set();
    int64_t rowptr[ROWS + 1];
    int32_t cols[NNZ];
    shifted(base, rowptr, cols);
    assert_ok(ctx, mfree_particles_set_neighbors(ps, rowptr, cols, base, MFREE_COPY));
    assert_ok(ctx, mfree_particles_setup(ps));
    assert_ref(ps);
    int32_t st[N], nf = -1;
    assert_ok(ctx, mfree_particles_get_site_status(ps, st, &nf));
    assert_int_equal(nf, 0);
    /* A copy: the host may reuse its arrays, even with invalid values. */
    for (int i = 0; i <= ROWS; ++i) rowptr[i] = -5;
    for (int k = 0; k < NNZ; ++k) cols[k] = 1000;
    assert_ok(ctx, mfree_particles_setup(ps));
    assert_ref(ps);
    assert_ok(ctx, mfree_particles_update(ps));
    assert_ref(ps);
    mfree_particles_destroy(&ps);
  }
}

static void test_borrowed_reread(void **s) {
  (void)s;
  for (int base = 0; base <= 1; ++base) {
    mfree_particles_t *ps = new_set();
    int64_t rowptr[ROWS + 1];
    int32_t cols[NNZ];
    shifted(base, rowptr, cols);
    assert_ok(ctx, mfree_particles_set_neighbors(ps, rowptr, cols, base, MFREE_BORROW));
    assert_ok(ctx, mfree_particles_setup(ps));
    assert_ref(ps);
    /* Re-read at setup: row 0 becomes {2, 5, 6}, row 3 loses particle 4. */
    cols[0] = 2 + base;
    cols[1] = 5 + base;
    cols[2] = 6 + base;
    cols[7] = 5 + base;
    for (int i = 4; i <= ROWS; ++i) rowptr[i] = ref_rowptr[i] - 1 + base;
    for (int k = 8; k < NNZ - 1; ++k) cols[k] = ref_cols[k + 1] + base;
    assert_ok(ctx, mfree_particles_setup(ps));
    int64_t nnz = 0;
    assert_ok(ctx, mfree_particles_get_neighbor_nnz(ps, &nnz));
    assert_int_equal(nnz, NNZ - 1);
    assert_lists(ps, rowptr, cols, base);
    /* update keeps the lists: a further change is not seen until setup. */
    lists_t before;
    get_lists(ps, &before);
    cols[0] = 0 + base;
    assert_ok(ctx, mfree_particles_update(ps));
    lists_t after;
    get_lists(ps, &after);
    assert_memory_equal(before.rowptr, after.rowptr, sizeof before.rowptr);
    assert_memory_equal(before.cols, after.cols, sizeof(int32_t) * (size_t)before.nnz);
    assert_ok(ctx, mfree_particles_setup(ps));
    get_lists(ps, &after);
    assert_int_equal(after.cols[0], 0);
    mfree_particles_destroy(&ps);
  }
}

/* Rows need not be sorted nor contain the particle itself; get_neighbors returns each
 * row sorted ascending, with the same entries. */
static void test_unsorted_rows(void **s) {
  (void)s;
  static const int32_t unsorted[NNZ] = {7, 0, 1, /* */ 6, 2, /* */ 5, 3, 0, 4, /* */ 4, /* */ 7, 1};
  for (int mem = MFREE_COPY; mem <= MFREE_BORROW; ++mem) {
    mfree_particles_t *ps = new_set();
    assert_ok(ctx, mfree_particles_set_neighbors(ps, ref_rowptr, unsorted, 0, (mfree_mem_t)mem));
    assert_ok(ctx, mfree_particles_setup(ps));
    assert_ref(ps);
    mfree_particles_destroy(&ps);
  }
}

/* Host lists take precedence over the search, with or without supports set. */
static void test_host_lists_replace_search(void **s) {
  (void)s;
  mfree_particles_t *ps = new_set();
  const double h = 10.0; /* the search would link every pair */
  assert_ok(ctx, mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_setup(ps));
  int64_t nnz = 0;
  assert_ok(ctx, mfree_particles_get_neighbor_nnz(ps, &nnz));
  assert_int_equal(nnz, ROWS * N);
  assert_ok(ctx, mfree_particles_set_neighbors(ps, ref_rowptr, ref_cols, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_setup(ps));
  assert_ref(ps);
  mfree_particles_destroy(&ps);
}

/* The search's own lists fed back as 1-based borrowed host lists come back unchanged. */
static void test_roundtrip_search_lists(void **s) {
  (void)s;
  enum { M = 3000, MG = 300 };
  double *x = malloc(sizeof(double) * 2 * M);
  assert_non_null(x);
  mfree_rng_t r;
  mfree_rng_seed(&r, 202);
  for (int i = 0; i < 2 * M; ++i) x[i] = mfree_rng_uniform(&r);
  const double h = 0.02;
  mfree_particles_t *a = NULL, *b = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, 2, M, &a));
  assert_ok(ctx, mfree_particles_set_num_ghost(a, MG));
  assert_ok(ctx, mfree_particles_set_positions(a, x, MFREE_LAYOUT_AOS, 2, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_support(a, &h, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_setup(a));
  int64_t nnz = 0;
  assert_ok(ctx, mfree_particles_get_neighbor_nnz(a, &nnz));
  assert_true(nnz > 5 * (M - MG));
  int64_t *rowptr = malloc(sizeof(int64_t) * (M - MG + 1));
  int32_t *cols = malloc(sizeof(int32_t) * (size_t)nnz);
  int32_t *cols2 = malloc(sizeof(int32_t) * (size_t)nnz);
  int64_t *rowptr2 = malloc(sizeof(int64_t) * (M - MG + 1));
  assert_non_null(rowptr);
  assert_non_null(cols);
  assert_non_null(cols2);
  assert_non_null(rowptr2);
  assert_ok(ctx, mfree_particles_get_neighbors(a, rowptr, cols));
  for (int i = 0; i <= M - MG; ++i) ++rowptr[i];
  for (int64_t k = 0; k < nnz; ++k) ++cols[k];

  assert_ok(ctx, mfree_particles_create(ctx, 2, M, &b));
  assert_ok(ctx, mfree_particles_set_num_ghost(b, MG));
  assert_ok(ctx, mfree_particles_set_positions(b, x, MFREE_LAYOUT_AOS, 2, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_neighbors(b, rowptr, cols, 1, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_setup(b));
  int64_t nnz2 = 0;
  assert_ok(ctx, mfree_particles_get_neighbor_nnz(b, &nnz2));
  assert_int_equal(nnz2, nnz);
  assert_ok(ctx, mfree_particles_get_neighbors(b, rowptr2, cols2));
  for (int i = 0; i <= M - MG; ++i) assert_int_equal(rowptr2[i], rowptr[i] - 1);
  for (int64_t k = 0; k < nnz; ++k) assert_int_equal(cols2[k], cols[k] - 1);
  mfree_particles_destroy(&a);
  mfree_particles_destroy(&b);
  free(x);
  free(rowptr);
  free(cols);
  free(rowptr2);
  free(cols2);
}

/* Every malformed list: the status and message, and the previous lists stay in force
 * (for get_neighbors and for the next setup). */
static void test_invalid_lists(void **s) {
  (void)s;
  mfree_particles_t *ps = new_set();
  assert_ok(ctx, mfree_particles_set_neighbors(ps, ref_rowptr, ref_cols, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_setup(ps));
  assert_ref(ps);

  int64_t rp[ROWS + 1];
  int32_t cl[NNZ];
#define RESET(base) shifted((base), rp, cl)
#define REFUSED(call, status, needle)                   \
  do {                                                  \
    assert_error(ctx, (call), (status), (needle));      \
    assert_ref(ps);                                     \
    assert_ok(ctx, mfree_particles_setup(ps));          \
    assert_ref(ps);                                     \
  } while (0)

  /* rowptr[0] must be the base */
  RESET(0);
  rp[0] = 1;
  REFUSED(mfree_particles_set_neighbors(ps, rp, cl, 0, MFREE_COPY), MFREE_ERR_INPUT, "rowptr[0]");
  RESET(1);
  rp[0] = 0;
  REFUSED(mfree_particles_set_neighbors(ps, rp, cl, 1, MFREE_BORROW), MFREE_ERR_INPUT, "rowptr[0]");
  RESET(0);
  REFUSED(mfree_particles_set_neighbors(ps, rp, cl, 1, MFREE_COPY), MFREE_ERR_INPUT, "rowptr[0]");

  /* monotone rowptr */
  RESET(0);
  rp[3] = 2;
  REFUSED(mfree_particles_set_neighbors(ps, rp, cl, 0, MFREE_COPY), MFREE_ERR_INPUT, "monotone");
  RESET(1);
  rp[ROWS] = rp[ROWS - 1] - 1;
  REFUSED(mfree_particles_set_neighbors(ps, rp, cl, 1, MFREE_BORROW), MFREE_ERR_INPUT, "monotone");

  /* columns in [base, base + n) */
  RESET(0);
  cl[4] = -1;
  REFUSED(mfree_particles_set_neighbors(ps, rp, cl, 0, MFREE_COPY), MFREE_ERR_INPUT, "outside");
  RESET(0);
  cl[NNZ - 1] = N;
  REFUSED(mfree_particles_set_neighbors(ps, rp, cl, 0, MFREE_BORROW), MFREE_ERR_INPUT, "outside");
  RESET(1);
  cl[0] = 0;
  REFUSED(mfree_particles_set_neighbors(ps, rp, cl, 1, MFREE_COPY), MFREE_ERR_INPUT, "outside");
  RESET(1);
  cl[5] = N + 1;
  REFUSED(mfree_particles_set_neighbors(ps, rp, cl, 1, MFREE_COPY), MFREE_ERR_INPUT, "outside");
  RESET(0);
  cl[2] = INT32_MIN;
  REFUSED(mfree_particles_set_neighbors(ps, rp, cl, 0, MFREE_COPY), MFREE_ERR_INPUT, "outside");

  /* NULL pointers */
  RESET(0);
  REFUSED(mfree_particles_set_neighbors(ps, NULL, cl, 0, MFREE_COPY), MFREE_ERR_NULL, "rowptr");
  REFUSED(mfree_particles_set_neighbors(ps, rp, NULL, 0, MFREE_BORROW), MFREE_ERR_NULL, "column");
  assert_int_equal(mfree_particles_set_neighbors(NULL, rp, cl, 0, MFREE_COPY), MFREE_ERR_NULL);

  /* enumerators */
  REFUSED(mfree_particles_set_neighbors(ps, rp, cl, 2, MFREE_COPY), MFREE_ERR_ARG, "index base");
  REFUSED(mfree_particles_set_neighbors(ps, rp, cl, -1, MFREE_COPY), MFREE_ERR_ARG, "index base");
  REFUSED(mfree_particles_set_neighbors(ps, rp, cl, 0, (mfree_mem_t)0), MFREE_ERR_ARG, "mem");
  REFUSED(mfree_particles_set_neighbors(ps, rp, cl, 0, (mfree_mem_t)3), MFREE_ERR_ARG, "mem");

  /* a column twice in a row would count that neighbour twice in every sum: refused,
   * copied or borrowed (a borrowed list that turns so is caught by setup) */
  RESET(1);
  cl[1] = N; /* row 0 = {1, 8, 8} (1-based) */
  REFUSED(mfree_particles_set_neighbors(ps, rp, cl, 1, MFREE_COPY), MFREE_ERR_INPUT, "twice");
  RESET(0);
  cl[8] = 3; /* row 3 = {0, 3, 4, 3} */
  REFUSED(mfree_particles_set_neighbors(ps, rp, cl, 0, MFREE_BORROW), MFREE_ERR_INPUT, "twice");
  {
    mfree_particles_t *pb = new_set();
    RESET(0);
    assert_ok(ctx, mfree_particles_set_neighbors(pb, rp, cl, 0, MFREE_BORROW));
    assert_ok(ctx, mfree_particles_setup(pb));
    cl[10] = 7; /* row 5 = {7, 7} */
    assert_error(ctx, mfree_particles_setup(pb), MFREE_ERR_INPUT, "twice");
    mfree_particles_destroy(&pb);
  }

  /* The boundaries are valid: column base + n - 1, empty rows, NULL cols with nnz 0. */
  RESET(1);
  cl[1] = N, cl[2] = 2; /* row 0 = {1, 8, 2} (1-based): the largest index, unsorted */
  assert_ok(ctx, mfree_particles_set_neighbors(ps, rp, cl, 1, MFREE_COPY));
  assert_ok(ctx, mfree_particles_setup(ps));
  lists_t l;
  get_lists(ps, &l);
  assert_int_equal(l.cols[1], 1);
  assert_int_equal(l.cols[2], N - 1);
  const int64_t empty[ROWS + 1] = {1, 1, 1, 1, 1, 1, 1};
  assert_ok(ctx, mfree_particles_set_neighbors(ps, empty, NULL, 1, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_setup(ps));
  get_lists(ps, &l);
  assert_int_equal(l.nnz, 0);
  for (int i = 0; i <= ROWS; ++i) assert_int_equal(l.rowptr[i], 0);
#undef REFUSED
#undef RESET
  mfree_particles_destroy(&ps);
}

/* A borrowed list modified into an invalid one after it was set: setup refuses it and
 * the lists of the last successful setup stay; repaired, it works again. */
static void test_borrowed_turns_invalid(void **s) {
  (void)s;
  for (int base = 0; base <= 1; ++base) {
    mfree_particles_t *ps = new_set();
    int64_t rp[ROWS + 1];
    int32_t cl[NNZ];
    shifted(base, rp, cl);
    assert_ok(ctx, mfree_particles_set_neighbors(ps, rp, cl, base, MFREE_BORROW));
    assert_ok(ctx, mfree_particles_setup(ps));
    assert_ref(ps);

    rp[0] = base + 1;
    assert_error(ctx, mfree_particles_setup(ps), MFREE_ERR_INPUT, "rowptr[0]");
    assert_ref(ps);
    rp[0] = base;

    rp[2] = rp[3] + 1;
    assert_error(ctx, mfree_particles_setup(ps), MFREE_ERR_INPUT, "monotone");
    assert_ref(ps);
    rp[2] = ref_rowptr[2] + base;

    cl[6] = N + base;
    assert_error(ctx, mfree_particles_setup(ps), MFREE_ERR_INPUT, "outside");
    assert_ref(ps);
    cl[6] = base - 1;
    assert_error(ctx, mfree_particles_setup(ps), MFREE_ERR_INPUT, "outside");
    assert_ref(ps);
    cl[6] = ref_cols[6] + base;

    assert_ok(ctx, mfree_particles_setup(ps));
    assert_ref(ps);
    int32_t nf = -1;
    assert_ok(ctx, mfree_particles_get_site_status(ps, NULL, &nf));
    assert_int_equal(nf, 0);
    mfree_particles_destroy(&ps);
  }
}

static void test_calls_before_setup(void **s) {
  (void)s;
  mfree_particles_t *ps = NULL;
  int64_t nnz = -1, rowptr[ROWS + 1];
  int32_t cols[NNZ], st[N], nf = -1;
  assert_ok(ctx, mfree_particles_create(ctx, 2, N, &ps));
  assert_ok(ctx, mfree_particles_set_num_ghost(ps, NG));
  assert_ok(ctx, mfree_particles_set_neighbors(ps, ref_rowptr, ref_cols, 0, MFREE_COPY));
  assert_error(ctx, mfree_particles_get_neighbor_nnz(ps, &nnz), MFREE_ERR_STATE, "not set up");
  assert_int_equal(nnz, -1);
  assert_error(ctx, mfree_particles_get_neighbors(ps, rowptr, cols), MFREE_ERR_STATE, "not set up");
  assert_error(ctx, mfree_particles_get_site_status(ps, st, &nf), MFREE_ERR_STATE, "not set up");
  assert_error(ctx, mfree_particles_update(ps), MFREE_ERR_STATE, "before setup");
  /* positions are still needed (for validation) */
  assert_error(ctx, mfree_particles_setup(ps), MFREE_ERR_STATE, "positions");
  assert_error(ctx, mfree_particles_get_neighbor_nnz(ps, &nnz), MFREE_ERR_STATE, "not set up");
  assert_ok(ctx, mfree_particles_set_positions(ps, pos, MFREE_LAYOUT_AOS, 2, MFREE_COPY));
  assert_ok(ctx, mfree_particles_setup(ps));
  assert_ok(ctx, mfree_particles_get_neighbor_nnz(ps, &nnz));
  assert_int_equal(nnz, NNZ);
  /* New lists invalidate the set-up state until the next setup. */
  assert_ok(ctx, mfree_particles_set_neighbors(ps, ref_rowptr, ref_cols, 0, MFREE_COPY));
  assert_error(ctx, mfree_particles_get_neighbor_nnz(ps, &nnz), MFREE_ERR_STATE, "not set up");
  assert_ok(ctx, mfree_particles_setup(ps));
  assert_ref(ps);
  mfree_particles_destroy(&ps);
}

/* Changing the ghost count after set_neighbors changes the number of rows: setup must
 * refuse the lists rather than read past the host's rowptr. */
static void test_ghost_count_changed(void **s) {
  (void)s;
  for (int mem = MFREE_COPY; mem <= MFREE_BORROW; ++mem) {
    mfree_particles_t *ps = new_set();
    assert_ok(ctx, mfree_particles_set_neighbors(ps, ref_rowptr, ref_cols, 0, (mfree_mem_t)mem));
    assert_ok(ctx, mfree_particles_setup(ps));
    assert_ref(ps);
    assert_ok(ctx, mfree_particles_set_num_ghost(ps, 0));
    assert_error(ctx, mfree_particles_setup(ps), MFREE_ERR_MISMATCH, "rows");
    assert_ok(ctx, mfree_particles_set_num_ghost(ps, NG + 1));
    assert_error(ctx, mfree_particles_setup(ps), MFREE_ERR_MISMATCH, "rows");
    assert_ok(ctx, mfree_particles_set_num_ghost(ps, NG));
    assert_ok(ctx, mfree_particles_setup(ps));
    assert_ref(ps);
    mfree_particles_destroy(&ps);
  }
}

/* Invalid borrowed particle data isolate particles in host lists as in searched ones. */
static void test_invalid_particle_data(void **s) {
  (void)s;
  mfree_particles_t *ps = NULL;
  double x[N * 2], v[N];
  for (int i = 0; i < N * 2; ++i) x[i] = 0.1 * i;
  for (int i = 0; i < N; ++i) v[i] = 1.0;
  assert_ok(ctx, mfree_particles_create(ctx, 2, N, &ps));
  assert_ok(ctx, mfree_particles_set_num_ghost(ps, NG));
  assert_ok(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 2, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_volumes(ps, v, 1, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_neighbors(ps, ref_rowptr, ref_cols, 0, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_setup(ps));
  assert_ref(ps);

  x[2 * 3 + 1] = NAN; /* owned particle 3 */
  v[7] = -1.0;        /* ghost 7 */
  assert_error(ctx, mfree_particles_setup(ps), MFREE_FAIL_NONFINITE, "particle 3:");
  int32_t st[N], nf = -1;
  assert_ok(ctx, mfree_particles_get_site_status(ps, st, &nf));
  assert_int_equal(nf, 2);
  for (int i = 0; i < N; ++i)
    assert_int_equal(st[i], i == 3 ? MFREE_FAIL_NONFINITE : i == 7 ? MFREE_FAIL_INVALID_DATA : 0);
  /* the reference lists without 3 and 7, row 3 empty */
  static const int64_t want_rowptr[ROWS + 1] = {0, 2, 2, 4, 4, 5, 6};
  static const int32_t want_cols[6] = {0, 1, /* */ 2, 6, /* */ /* */ 4, /* */ 1};
  assert_lists(ps, want_rowptr, want_cols, 0);

  /* Repaired: the lists as given again. */
  x[2 * 3 + 1] = 0.7;
  v[7] = 1.0;
  assert_ok(ctx, mfree_particles_setup(ps));
  assert_ref(ps);
  mfree_particles_destroy(&ps);
}

/* No rows at all: every particle a ghost, or no particles. */
static void test_no_rows(void **s) {
  (void)s;
  for (int i = 0; i < N * 2; ++i) pos[i] = 0.1 * i;
  for (int base = 0; base <= 1; ++base)
    for (int32_t n = 0; n <= N; n += N) {
      mfree_particles_t *ps = NULL;
      const int64_t rowptr[1] = {base};
      int64_t out[1] = {-1}, nnz = -1;
      assert_ok(ctx, mfree_particles_create(ctx, 2, n, &ps));
      assert_ok(ctx, mfree_particles_set_num_ghost(ps, n));
      assert_ok(ctx, mfree_particles_set_positions(ps, n ? pos : NULL, MFREE_LAYOUT_AOS, 2, MFREE_COPY));
      assert_ok(ctx, mfree_particles_set_neighbors(ps, rowptr, NULL, base, MFREE_COPY));
      assert_ok(ctx, mfree_particles_setup(ps));
      assert_ok(ctx, mfree_particles_get_neighbor_nnz(ps, &nnz));
      assert_int_equal(nnz, 0);
      assert_ok(ctx, mfree_particles_get_neighbors(ps, out, NULL));
      assert_int_equal(out[0], 0);
      /* and rowptr[0] must still be the base */
      const int64_t wrong[1] = {1 - base};
      assert_error(ctx, mfree_particles_set_neighbors(ps, wrong, NULL, base, MFREE_COPY), MFREE_ERR_INPUT,
                   "rowptr[0]");
      mfree_particles_destroy(&ps);
    }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_copied_returned_as_given),
      cmocka_unit_test(test_borrowed_reread),
      cmocka_unit_test(test_unsorted_rows),
      cmocka_unit_test(test_host_lists_replace_search),
      cmocka_unit_test(test_roundtrip_search_lists),
      cmocka_unit_test(test_invalid_lists),
      cmocka_unit_test(test_borrowed_turns_invalid),
      cmocka_unit_test(test_calls_before_setup),
      cmocka_unit_test(test_ghost_count_changed),
      cmocka_unit_test(test_invalid_particle_data),
      cmocka_unit_test(test_no_rows),
  };
  return cmocka_run_group_tests(tests, grp_setup, grp_teardown);
}
