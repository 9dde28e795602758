/* Particle sets: creation, borrowed/copied arrays in every layout, validation of every
 * input, state errors, and that a failed call changes nothing. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"

static mfree_context_t *ctx;
static int setup(void **s) { (void)s; return mfree_context_create(&ctx) != MFREE_SUCCESS; }
static int teardown(void **s) { (void)s; return mfree_context_destroy(&ctx) != MFREE_SUCCESS; }

#define N 40

/* Neighbour lists of a set after setup, as a flat signature for comparisons. */
typedef struct { int64_t rowptr[N + 1]; int32_t cols[N * N]; int64_t nnz; } lists_t;
static void get_lists(mfree_particles_t *ps, lists_t *l) {
  memset(l, 0, sizeof *l);
  assert_ok(ctx, mfree_particles_get_neighbor_nnz(ps, &l->nnz));
  assert_true(l->nnz <= N * N);
  assert_ok(ctx, mfree_particles_get_neighbors(ps, l->rowptr, l->cols));
}
static void assert_lists_equal(const lists_t *a, const lists_t *b) {
  assert_int_equal(a->nnz, b->nnz);
  assert_memory_equal(a->rowptr, b->rowptr, sizeof a->rowptr);
  assert_memory_equal(a->cols, b->cols, sizeof(int32_t) * (size_t)a->nnz);
}

static void make_points(int dim, double *x /* AoS, ld = dim */) {
  mfree_rng_t r;
  mfree_rng_seed(&r, 42);
  for (int i = 0; i < N * dim; ++i) x[i] = mfree_rng_uniform(&r);
}

/* Brute-force gather lists of a small AoS cloud: the oracle for the layout tests. */
static void brute(int dim, const double *x, double h, double kappa, lists_t *l) {
  memset(l, 0, sizeof *l);
  for (int i = 0; i < N; ++i) {
    for (int j = 0; j < N; ++j) {
      double d2 = 0;
      for (int c = 0; c < dim; ++c) d2 += (x[i * dim + c] - x[j * dim + c]) * (x[i * dim + c] - x[j * dim + c]);
      if (d2 < kappa * h * kappa * h) l->cols[l->nnz++] = j;
    }
    l->rowptr[i + 1] = l->nnz;
  }
}

/* Fortran x(3,n) (AoS, ld 3 in 2D), x(n,3) (SoA), a struct array (AoS, ld 7), borrowed
 * and copied, all give the brute-force lists. */
static void test_layouts(void **s) {
  (void)s;
  for (int dim = 1; dim <= 3; ++dim) {
    double x[N * 3];
    make_points(dim, x);
    const double h = 0.12;
    lists_t want, got;
    brute(dim, x, h, 2.0, &want);
    assert_true(want.nnz > N); /* not only self pairs */

    double aos3[N * 3], soa[3 * (N + 5)], structs[N * 7];
    for (int i = 0; i < N; ++i)
      for (int c = 0; c < dim; ++c) {
        aos3[i * 3 + c] = x[i * dim + c];
        soa[c * (N + 5) + i] = x[i * dim + c];
        structs[i * 7 + 2 + c] = x[i * dim + c];
      }
    struct { const double *p; mfree_layout_t lay; int64_t ld; } cases[] = {
        {x, MFREE_LAYOUT_AOS, dim},
        {aos3, MFREE_LAYOUT_AOS, 3},
        {soa, MFREE_LAYOUT_SOA, N + 5},
        {structs + 2, MFREE_LAYOUT_AOS, 7},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k)
      for (int mem = MFREE_COPY; mem <= MFREE_BORROW; ++mem) {
        mfree_particles_t *ps = NULL;
        assert_ok(ctx, mfree_particles_create(ctx, dim, N, &ps));
        assert_ok(ctx, mfree_particles_set_positions(ps, cases[k].p, cases[k].lay, cases[k].ld,
                                                     (mfree_mem_t)mem));
        assert_ok(ctx, mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
        assert_ok(ctx, mfree_particles_setup(ps));
        get_lists(ps, &got);
        assert_lists_equal(&got, &want);
        int32_t d = 0, n = 0, g = -1;
        assert_ok(ctx, mfree_particles_get_dimension(ps, &d));
        assert_ok(ctx, mfree_particles_get_size(ps, &n, &g));
        assert_int_equal(d, dim);
        assert_int_equal(n, N);
        assert_int_equal(g, 0);
        mfree_particles_destroy(&ps);
      }
  }
}

/* Copied arrays ignore later host changes; borrowed arrays are re-read at setup. */
static void test_copy_vs_borrow(void **s) {
  (void)s;
  double x[N * 2], h[N];
  make_points(2, x);
  for (int i = 0; i < N; ++i) h[i] = 0.1;
  mfree_particles_t *pc = NULL, *pb = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, 2, N, &pc));
  assert_ok(ctx, mfree_particles_create(ctx, 2, N, &pb));
  assert_ok(ctx, mfree_particles_set_positions(pc, x, MFREE_LAYOUT_AOS, 2, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_positions(pb, x, MFREE_LAYOUT_AOS, 2, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_support(pc, h, 1, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_support(pb, h, 1, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_setup(pc));
  assert_ok(ctx, mfree_particles_setup(pb));
  lists_t before, after_c, after_b, want;
  get_lists(pc, &before);
  /* move every particle onto one point and enlarge the supports: all pairs are neighbours */
  double xs[N * 2];
  memcpy(xs, x, sizeof x);
  for (int i = 0; i < N * 2; ++i) x[i] = 0.5;
  for (int i = 0; i < N; ++i) h[i] = 1.0;
  assert_ok(ctx, mfree_particles_setup(pc));
  assert_ok(ctx, mfree_particles_setup(pb));
  get_lists(pc, &after_c);
  get_lists(pb, &after_b);
  assert_lists_equal(&after_c, &before);
  assert_int_equal(after_b.nnz, (int64_t)N * N);
  brute(2, x, 1.0, 2.0, &want);
  assert_lists_equal(&after_b, &want);
  (void)xs;
  mfree_particles_destroy(&pc);
  mfree_particles_destroy(&pb);
}

/* Volumes directly, or masses / densities, one value (stride 0) or per particle,
 * borrowed with a stride (a field of a host struct array). */
static void test_volumes(void **s) {
  (void)s;
  double m[N], rho[2 * N], v[N];
  for (int i = 0; i < N; ++i) {
    m[i] = 1.0 + i;
    rho[2 * i] = 2.0;
    rho[2 * i + 1] = -1.0; /* another field of the host's struct: never read */
  }
  mfree_particles_t *ps = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, 1, N, &ps));
  assert_error(ctx, mfree_particles_get_volumes(ps, v), MFREE_ERR_STATE, "volumes");
  assert_ok(ctx, mfree_particles_set_masses(ps, m, 1, MFREE_BORROW));
  assert_error(ctx, mfree_particles_get_volumes(ps, v), MFREE_ERR_STATE, "densities");
  assert_ok(ctx, mfree_particles_set_densities(ps, rho, 2, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_get_volumes(ps, v));
  for (int i = 0; i < N; ++i) assert_true(v[i] == (1.0 + i) / 2.0);
  m[3] = 10.0; /* borrowed: re-read */
  assert_ok(ctx, mfree_particles_get_volumes(ps, v));
  assert_true(v[3] == 5.0);
  const double vol = 0.25;
  assert_ok(ctx, mfree_particles_set_volumes(ps, &vol, 0, MFREE_COPY)); /* volumes win */
  assert_ok(ctx, mfree_particles_get_volumes(ps, v));
  for (int i = 0; i < N; ++i) assert_true(v[i] == 0.25);
  mfree_particles_destroy(&ps);
}

/* Every bad argument: documented status, message, and the set still works after. */
static void test_bad_input(void **s) {
  (void)s;
  double x[N * 2], h = 0.1, bad[N];
  make_points(2, x);
  mfree_particles_t *ps = NULL;

  assert_int_equal(mfree_particles_create(NULL, 2, N, &ps), MFREE_ERR_NULL);
  assert_error(ctx, mfree_particles_create(ctx, 2, N, NULL), MFREE_ERR_NULL, "NULL");
  assert_error(ctx, mfree_particles_create(ctx, 0, N, &ps), MFREE_ERR_ARG, "dimension 0");
  assert_error(ctx, mfree_particles_create(ctx, 4, N, &ps), MFREE_ERR_ARG, "dimension 4");
  assert_error(ctx, mfree_particles_create(ctx, 2, -1, &ps), MFREE_ERR_ARG, "negative");
  assert_null(ps);
  assert_ok(ctx, mfree_particles_create(ctx, 2, N, &ps));

  /* state errors before any data */
  assert_error(ctx, mfree_particles_setup(ps), MFREE_ERR_STATE, "positions");
  assert_error(ctx, mfree_particles_update(ps), MFREE_ERR_STATE, "before setup");
  int64_t nnz = -1;
  assert_error(ctx, mfree_particles_get_neighbor_nnz(ps, &nnz), MFREE_ERR_STATE, "not set up");
  int64_t rp[N + 1];
  int32_t cols[N * N];
  assert_error(ctx, mfree_particles_get_neighbors(ps, rp, cols), MFREE_ERR_STATE, "not set up");
  int32_t st[N];
  assert_error(ctx, mfree_particles_get_site_status(ps, st, NULL), MFREE_ERR_STATE, "not set up");

  /* positions */
  assert_error(ctx, mfree_particles_set_positions(ps, NULL, MFREE_LAYOUT_AOS, 2, MFREE_COPY),
               MFREE_ERR_NULL, "NULL");
  assert_error(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 1, MFREE_COPY),
               MFREE_ERR_ARG, "leading dimension");
  assert_error(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_SOA, N - 1, MFREE_COPY),
               MFREE_ERR_ARG, "leading dimension");
  assert_error(ctx, mfree_particles_set_positions(ps, x, (mfree_layout_t)3, 2, MFREE_COPY),
               MFREE_ERR_ARG, "layout");
  assert_error(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 2, (mfree_mem_t)0),
               MFREE_ERR_ARG, "mem");
  const double saved = x[2 * 7 + 1];
  x[2 * 7 + 1] = NAN;
  assert_error(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 2, MFREE_COPY),
               MFREE_ERR_INPUT, "particle 7");
  x[2 * 7 + 1] = INFINITY;
  assert_error(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 2, MFREE_BORROW),
               MFREE_ERR_INPUT, "particle 7");
  x[2 * 7 + 1] = saved;
  assert_ok(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 2, MFREE_COPY));
  assert_error(ctx, mfree_particles_setup(ps), MFREE_ERR_STATE, "support");

  /* scalars: supports, volumes, masses, densities */
  typedef mfree_status_t (*setter)(mfree_particles_t *, const double *, int64_t, mfree_mem_t);
  const setter setters[4] = {mfree_particles_set_support, mfree_particles_set_volumes,
                             mfree_particles_set_masses, mfree_particles_set_densities};
  const char *names[4] = {"support", "volume", "mass", "density"};
  for (int k = 0; k < 4; ++k) {
    for (int i = 0; i < N; ++i) bad[i] = 1.0;
    assert_error(ctx, setters[k](ps, NULL, 1, MFREE_COPY), MFREE_ERR_NULL, names[k]);
    assert_error(ctx, setters[k](ps, bad, -1, MFREE_COPY), MFREE_ERR_ARG, "stride");
    assert_error(ctx, setters[k](ps, bad, 1, (mfree_mem_t)7), MFREE_ERR_ARG, "mem");
    const double vals[4] = {0.0, -1.0, NAN, -INFINITY};
    for (int v = 0; v < 4; ++v) {
      bad[5] = vals[v];
      assert_error(ctx, setters[k](ps, bad, 1, MFREE_COPY), MFREE_ERR_INPUT, "[5]");
      assert_error(ctx, setters[k](ps, bad + 5, 0, MFREE_BORROW), MFREE_ERR_INPUT, names[k]);
    }
  }
  assert_ok(ctx, mfree_particles_set_support(ps, &h, 0, MFREE_COPY));

  /* search options and box */
  assert_error(ctx, mfree_particles_set_search(ps, (mfree_search_t)0, 2.0), MFREE_ERR_ARG, "convention");
  assert_error(ctx, mfree_particles_set_search(ps, (mfree_search_t)4, 2.0), MFREE_ERR_ARG, "convention");
  assert_error(ctx, mfree_particles_set_search(ps, MFREE_SEARCH_GATHER, 0.0), MFREE_ERR_ARG, "kappa");
  assert_error(ctx, mfree_particles_set_search(ps, MFREE_SEARCH_GATHER, NAN), MFREE_ERR_ARG, "kappa");
  const double lo[2] = {0, 0}, hi[2] = {1, 1}, hibad[2] = {1, 0}, lonan[2] = {NAN, 0};
  const int32_t per[2] = {1, 1};
  assert_error(ctx, mfree_particles_set_periodic(ps, NULL, hi, per), MFREE_ERR_NULL, "NULL");
  assert_error(ctx, mfree_particles_set_periodic(ps, lo, hibad, per), MFREE_ERR_ARG, "hi <= lo");
  assert_error(ctx, mfree_particles_set_periodic(ps, lonan, hi, per), MFREE_ERR_INPUT, "finite");
  assert_error(ctx, mfree_particles_set_num_ghost(ps, -1), MFREE_ERR_ARG, "ghost");
  assert_error(ctx, mfree_particles_set_num_ghost(ps, N + 1), MFREE_ERR_ARG, "ghost");

  /* NULL handles: nothing to record on, just the status */
  assert_int_equal(mfree_particles_setup(NULL), MFREE_ERR_NULL);
  assert_int_equal(mfree_particles_update(NULL), MFREE_ERR_NULL);
  assert_int_equal(mfree_particles_set_support(NULL, &h, 0, MFREE_COPY), MFREE_ERR_NULL);
  assert_int_equal(mfree_particles_get_neighbor_nnz(NULL, &nnz), MFREE_ERR_NULL);
  assert_int_equal(mfree_particles_get_dimension(NULL, NULL), MFREE_ERR_NULL);
  assert_error(ctx, mfree_particles_get_dimension(ps, NULL), MFREE_ERR_NULL, "NULL");

  /* after all that, the set is intact: same lists as a fresh set */
  assert_ok(ctx, mfree_particles_setup(ps));
  lists_t got, want;
  get_lists(ps, &got);
  brute(2, x, h, 2.0, &want);
  assert_lists_equal(&got, &want);
  assert_error(ctx, mfree_particles_get_neighbors(ps, NULL, cols), MFREE_ERR_NULL, "rowptr");
  assert_error(ctx, mfree_particles_get_site_status(ps, NULL, NULL), MFREE_ERR_NULL, "NULL");
  int32_t nfailed = -1;
  assert_ok(ctx, mfree_particles_get_site_status(ps, st, &nfailed));
  assert_int_equal(nfailed, 0);
  mfree_particles_destroy(&ps);
}

/* Borrowed volumes or masses that turn invalid after they were set: setup completes,
 * returns the positive status and isolates exactly those particles. */
static void test_borrowed_turns_invalid(void **s) {
  (void)s;
  double x[N * 2], vol[N], h = 0.2;
  make_points(2, x);
  for (int i = 0; i < N; ++i) vol[i] = 0.01;
  mfree_particles_t *ps = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, 2, N, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 2, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_volumes(ps, vol, 1, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_setup(ps));
  lists_t good;
  get_lists(ps, &good);

  vol[11] = 0.0;
  vol[23] = -2.0;
  assert_error(ctx, mfree_particles_update(ps), MFREE_FAIL_INVALID_DATA, "particle 11");
  int32_t st[N], nf = 0;
  assert_ok(ctx, mfree_particles_get_site_status(ps, st, &nf));
  assert_int_equal(nf, 2);
  assert_int_equal(st[11], MFREE_FAIL_INVALID_DATA);
  assert_int_equal(st[23], MFREE_FAIL_INVALID_DATA);
  lists_t l;
  get_lists(ps, &l);
  /* rows of 11 and 23 are empty; no row lists them; the other pairs are kept */
  assert_int_equal(l.rowptr[12] - l.rowptr[11], 0);
  assert_int_equal(l.rowptr[24] - l.rowptr[23], 0);
  int64_t expect = 0;
  for (int i = 0; i < N; ++i)
    for (int64_t k = good.rowptr[i]; k < good.rowptr[i + 1]; ++k)
      if (i != 11 && i != 23 && good.cols[k] != 11 && good.cols[k] != 23) ++expect;
  assert_int_equal(l.nnz, expect);
  for (int64_t k = 0; k < l.nnz; ++k) assert_true(l.cols[k] != 11 && l.cols[k] != 23);

  vol[11] = NAN;
  assert_error(ctx, mfree_particles_setup(ps), MFREE_FAIL_NONFINITE, "particle 11");
  /* repaired data: back to the full lists */
  vol[11] = 0.01;
  vol[23] = 0.01;
  assert_ok(ctx, mfree_particles_setup(ps));
  get_lists(ps, &l);
  assert_lists_equal(&l, &good);
  mfree_particles_destroy(&ps);
}

/* n = 0 is valid: empty results. */
static void test_empty(void **s) {
  (void)s;
  mfree_particles_t *ps = NULL;
  const double h = 1.0;
  assert_ok(ctx, mfree_particles_create(ctx, 3, 0, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, NULL, MFREE_LAYOUT_SOA, 0, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_volumes(ps, NULL, 1, MFREE_COPY));
  assert_ok(ctx, mfree_particles_setup(ps));
  assert_ok(ctx, mfree_particles_update(ps));
  int64_t nnz = -1, rp[1] = {-1};
  assert_ok(ctx, mfree_particles_get_neighbor_nnz(ps, &nnz));
  assert_int_equal(nnz, 0);
  assert_ok(ctx, mfree_particles_get_neighbors(ps, rp, NULL));
  assert_int_equal(rp[0], 0);
  int32_t nf = -1;
  assert_ok(ctx, mfree_particles_get_site_status(ps, NULL, &nf));
  assert_int_equal(nf, 0);
  mfree_particles_destroy(&ps);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_layouts),    cmocka_unit_test(test_copy_vs_borrow),
      cmocka_unit_test(test_volumes),    cmocka_unit_test(test_bad_input),
      cmocka_unit_test(test_borrowed_turns_invalid), cmocka_unit_test(test_empty),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
