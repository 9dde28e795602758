/*
 * t205: the one-thread host-order neighbour search against the general cell-order one
 * on the same points (src/core/particles/neighbors.cpp).
 *
 * A one-thread search of particles stored in spatial order (on x86 with AVX2; elsewhere,
 * or with MFREE_SIMD=baseline, both sides below take the general path and the test
 * checks only that) finds the rows in host order and writes each one, sorted by rank
 * (32-bit lanes; 16-bit offsets for rows of more
 * than 32 entries spanning fewer than 32767 indices; std::sort beyond 64), straight into
 * the lists, growing them when the estimate from the mean density falls short. The same
 * particles in random order take the general path (cell-order queries into buffers, a
 * transposition or per-row sorts). Both must give the same relation, exactly: every
 * case sets up the points in spatial order and under a random permutation and compares
 * the rows entry by entry after mapping the indices back (the permuted rows sorted again
 * by the test). A spatially ordered set with two threads (host order too: each block
 * of rows written into spare lists at a guessed offset, spills moved into place; t208
 * tests moving blocks) must give the same bits as with one.
 * Cases:
 *  - 3D jittered lattice, ~45 neighbours (16-bit ranks), gather and symmetric-max;
 *  - 2D, ~21 neighbours (32-bit ranks), with ghosts;
 *  - variable supports (rows beyond 64: std::sort), symmetric-mean;
 *  - a lattice with particles near its start swapped with ones near its end (rows
 *    spanning more than 32767 host indices: the 32-bit fallback);
 *  - clustered points sorted along z, y, x (the estimate falls short: the lists grow);
 * and, through a failing allocator hook, every allocation of a clustered setup failing
 * in turn: MFREE_ERR_ALLOC with a message, the set then not set up, a retry equal to the
 * reference, every block returned. No timing.
 */
#include "count_alloc.h"
#include "testutil.h"
#include "nbr_lists.h"

#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

typedef struct {
  int dim;
  int32_t n;
  double *x; /* AoS, dim per point */
  double *h;
} cloud_t;

static cloud_t cloud_new(int dim, int32_t n) {
  cloud_t c = {dim, n, calloc((size_t)n * dim, sizeof(double)), calloc((size_t)n, sizeof(double))};
  assert_non_null(c.x);
  assert_non_null(c.h);
  return c;
}

static void cloud_free(cloud_t *c) {
  free(c->x);
  free(c->h);
}

/* m^dim lattice points, spacing 1, jitter 0.3, x fastest (host order = lattice order). */
static cloud_t lattice(int dim, int m, mfree_rng_t *r) {
  int32_t n = 1;
  for (int d = 0; d < dim; ++d) n *= m;
  cloud_t c = cloud_new(dim, n);
  jittered_lattice(c.x, dim, m, r);
  return c;
}

static void swap_points(cloud_t *c, int32_t a, int32_t b) {
  for (int d = 0; d < c->dim; ++d) {
    const double t = c->x[(size_t)c->dim * a + d];
    c->x[(size_t)c->dim * a + d] = c->x[(size_t)c->dim * b + d];
    c->x[(size_t)c->dim * b + d] = t;
  }
  const double t = c->h[a];
  c->h[a] = c->h[b];
  c->h[b] = t;
}

static int cmp_key(const void *pa, const void *pb) {
  const double *a = pa, *b = pb;
  return a[0] < b[0] ? -1 : (a[0] > b[0] ? 1 : 0);
}

/* Clustered 3D points (Gaussian blobs in a box of side 20), stored along z, y, x in
 * slabs of 0.15 (about a grid cell: spatial order), and a support giving ~40 neighbours
 * in the blobs. */
static cloud_t clustered(int32_t n, mfree_rng_t *r) {
  cloud_t c = cloud_new(3, n);
  double centre[4][3];
  for (int q = 0; q < 4; ++q)
    for (int d = 0; d < 3; ++d) centre[q][d] = 20.0 * mfree_rng_uniform(r);
  for (int32_t p = 0; p < n; ++p) {
    const int q = p % 4;
    for (int d = 0; d < 3; ++d) {
      /* sum of uniforms: roughly Gaussian, sigma ~ 0.6 */
      double g = 0.0;
      for (int k = 0; k < 4; ++k) g += mfree_rng_uniform(r) - 0.5;
      c.x[3 * (size_t)p + d] = centre[q][d] + 1.2 * g;
    }
  }
  /* sort by (z slab, y slab, x) */
  double *key = malloc(sizeof(double) * 4 * (size_t)n);
  assert_non_null(key);
  for (int32_t p = 0; p < n; ++p) {
    const double *x = c.x + 3 * (size_t)p;
    key[4 * (size_t)p] = floor((x[2] + 10.0) / 0.15) * 1e6 + floor((x[1] + 10.0) / 0.15) * 1e3 + (x[0] + 10.0);
    for (int d = 0; d < 3; ++d) key[4 * (size_t)p + 1 + d] = x[d];
  }
  qsort(key, (size_t)n, 4 * sizeof(double), cmp_key);
  for (int32_t p = 0; p < n; ++p)
    for (int d = 0; d < 3; ++d) c.x[3 * (size_t)p + d] = key[4 * (size_t)p + 1 + d];
  free(key);
  /* density in a blob ~ (n/4) / (2 pi sigma^2)^(3/2): ~40 neighbours there */
  const double rho = 0.25 * n / pow(2.0 * M_PI * 0.36, 1.5);
  for (int32_t p = 0; p < n; ++p) c.h[p] = 0.5 * cbrt(40.0 * 3.0 / (4.0 * M_PI * rho));
  return c;
}

static mfree_particles_t *make_set(mfree_context_t *ctx, const cloud_t *c, int conv, double kappa, int32_t ng) {
  mfree_particles_t *ps = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, c->dim, c->n, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, c->x, MFREE_LAYOUT_AOS, c->dim, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_support(ps, c->h, 1, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_search(ps, (mfree_search_t)conv, kappa));
  if (ng) assert_ok(ctx, mfree_particles_set_num_ghost(ps, ng));
  return ps;
}

static int cmp_i32(const void *a, const void *b) {
  const int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
  return (x > y) - (x < y);
}

/* The lists of c in its own order (one thread, and two) equal those of c under a random
 * permutation that keeps the ghosts last. Returns the longest row seen. */
static int64_t compare_orders(const cloud_t *c, int conv, double kappa, int32_t ng, mfree_rng_t *r) {
  const int32_t n = c->n, no = n - ng;
  /* perm[q] = the particle of c stored at q in the permuted copy */
  int32_t *perm = malloc(sizeof(int32_t) * (size_t)n), *inv = malloc(sizeof(int32_t) * (size_t)n);
  assert_non_null(perm);
  assert_non_null(inv);
  for (int32_t q = 0; q < n; ++q) perm[q] = q;
  for (int part = 0; part < 2; ++part) {
    const int32_t lo = part ? no : 0, len = part ? ng : no;
    for (int32_t k = len - 1; k > 0; --k) {
      int32_t j = (int32_t)(mfree_rng_uniform(r) * (k + 1));
      if (j > k) j = k;
      const int32_t t = perm[lo + k];
      perm[lo + k] = perm[lo + j];
      perm[lo + j] = t;
    }
  }
  for (int32_t q = 0; q < n; ++q) inv[perm[q]] = q;
  cloud_t p = cloud_new(c->dim, n);
  for (int32_t q = 0; q < n; ++q) {
    for (int d = 0; d < c->dim; ++d) p.x[(size_t)c->dim * q + d] = c->x[(size_t)c->dim * perm[q] + d];
    p.h[q] = c->h[perm[q]];
  }
  lists_t ref = {NULL, NULL, 0};
  for (int threads = 1; threads <= 2; ++threads) {
    mfree_context_t *ctx = NULL;
    assert_ok(NULL, mfree_context_create(&ctx));
    assert_ok(ctx, mfree_context_set_num_threads(ctx, threads));
    mfree_particles_t *ps = make_set(ctx, c, conv, kappa, ng);
    assert_ok(ctx, mfree_particles_setup(ps));
    lists_t g = lists_fetch(ctx, ps);
    mfree_particles_destroy(&ps);
    if (threads == 1) {
      ref = g;
      /* the permuted copy, one thread (random order: the general path) */
      ps = make_set(ctx, &p, conv, kappa, ng);
      assert_ok(ctx, mfree_particles_setup(ps));
      lists_t gp = lists_fetch(ctx, ps);
      mfree_particles_destroy(&ps);
      assert_int_equal(gp.rowptr[no], ref.rowptr[no]);
      int32_t *row = malloc(sizeof(int32_t) * (size_t)(n > 0 ? n : 1));
      assert_non_null(row);
      for (int32_t i = 0; i < no; ++i) {
        const int32_t q = inv[i];
        const int64_t len = gp.rowptr[q + 1] - gp.rowptr[q];
        if (len != ref.rowptr[i + 1] - ref.rowptr[i])
          fail_msg("row %d: %lld entries in spatial order, %lld permuted", i,
                   (long long)(ref.rowptr[i + 1] - ref.rowptr[i]), (long long)len);
        for (int64_t k = 0; k < len; ++k) row[k] = perm[gp.cols[gp.rowptr[q] + k]];
        qsort(row, (size_t)len, sizeof(int32_t), cmp_i32);
        for (int64_t k = 0; k < len; ++k)
          if (row[k] != ref.cols[ref.rowptr[i] + k]) fail_msg("row %d differs at entry %lld", i, (long long)k);
      }
      free(row);
      lists_free(&gp);
    } else {
      assert_lists_equal(&g, &ref);
      lists_free(&g);
    }
    mfree_context_destroy(&ctx);
  }
  int64_t longest = 0;
  for (int32_t i = 0; i < no; ++i)
    if (ref.rowptr[i + 1] - ref.rowptr[i] > longest) longest = ref.rowptr[i + 1] - ref.rowptr[i];
  /* rows strictly ascending, every owned particle its own neighbour */
  for (int32_t i = 0; i < no; ++i) {
    int self = 0;
    for (int64_t k = ref.rowptr[i]; k < ref.rowptr[i + 1]; ++k) {
      if (k > ref.rowptr[i]) assert_true(ref.cols[k - 1] < ref.cols[k]);
      self |= ref.cols[k] == i;
    }
    assert_true(self);
  }
  lists_free(&ref);
  cloud_free(&p);
  free(perm);
  free(inv);
  return longest;
}

static void test_lattices(void **state) {
  (void)state;
  mfree_rng_t r;
  mfree_rng_seed(&r, 205);
  /* 3D, ~45 neighbours (rows of 33 to 64: the 16-bit ranks), r = (45 * 3 / (4 pi))^(1/3) */
  cloud_t c3 = lattice(3, 16, &r);
  const double r3 = cbrt(45.0 * 3.0 / (4.0 * M_PI));
  for (int32_t i = 0; i < c3.n; ++i) c3.h[i] = 0.5 * r3;
  int64_t longest = compare_orders(&c3, MFREE_SEARCH_GATHER, 2.0, 0, &r);
  if (!(longest > 32 && longest <= 64)) fail_msg("longest row %lld: not the 16-bit ranks", (long long)longest);
  compare_orders(&c3, MFREE_SEARCH_SYMMETRIC_MAX, 2.0, 0, &r);
  /* variable supports: rows beyond 64 */
  for (int32_t i = 0; i < c3.n; ++i) c3.h[i] = 0.5 * r3 * (0.7 + 0.9 * mfree_rng_uniform(&r));
  longest = compare_orders(&c3, MFREE_SEARCH_SYMMETRIC_MEAN, 2.0, 0, &r);
  assert_true(longest > 64);
  compare_orders(&c3, MFREE_SEARCH_GATHER, 2.0, c3.n / 5, &r);
  cloud_free(&c3);
  /* 2D, ~21 neighbours, with and without ghosts */
  cloud_t c2 = lattice(2, 70, &r);
  for (int32_t i = 0; i < c2.n; ++i) c2.h[i] = 0.5 * sqrt(21.0 / M_PI);
  longest = compare_orders(&c2, MFREE_SEARCH_GATHER, 2.0, 0, &r);
  assert_true(longest <= 32);
  compare_orders(&c2, MFREE_SEARCH_GATHER, 2.0, 700, &r);
  cloud_free(&c2);
}

static void test_far_swaps(void **state) {
  (void)state;
  mfree_rng_t r;
  mfree_rng_seed(&r, 2051);
  /* 34^3 = 39304 points; particles among the first 2000 swapped with their mirror
   * n - 1 - i: rows near either end then span more than 32767 host indices (while 98 %
   * of host-consecutive pairs stay spatial neighbours) */
  cloud_t c = lattice(3, 34, &r);
  const double r3 = cbrt(57.0 * 3.0 / (4.0 * M_PI));
  for (int32_t i = 0; i < c.n; ++i) c.h[i] = 0.5 * r3;
  for (int32_t i = 0; i < 2000; i += 5) swap_points(&c, i, c.n - 1 - i);
  compare_orders(&c, MFREE_SEARCH_GATHER, 2.0, 0, &r);
  cloud_free(&c);
}

static void test_clustered_growth(void **state) {
  (void)state;
  mfree_rng_t r;
  mfree_rng_seed(&r, 2052);
  cloud_t c = clustered(6000, &r);
  const int64_t longest = compare_orders(&c, MFREE_SEARCH_GATHER, 2.0, 0, &r);
  assert_true(longest > 20);
  cloud_free(&c);
}

/* Every allocation of a clustered one-thread setup failing in turn. */
static void test_allocation_failure(void **state) {
  (void)state;
  mfree_rng_t r;
  mfree_rng_seed(&r, 2053);
  cloud_t c = clustered(3000, &r);
  counter_t cnt = {0, 0, 0, -1};
  mfree_context_t *ctx = NULL;
  assert_ok(NULL, mfree_context_create(&ctx));
  assert_ok(ctx, mfree_context_set_num_threads(ctx, 1));
  assert_ok(ctx, mfree_context_set_allocator(ctx, count_alloc, count_free, &cnt));
  mfree_particles_t *ps = make_set(ctx, &c, MFREE_SEARCH_GATHER, 2.0, 0);
  const int64_t before = cnt.calls;
  assert_ok(ctx, mfree_particles_setup(ps));
  const int64_t calls = cnt.calls - before;
  assert_true(calls > 0);
  lists_t ref = lists_fetch(ctx, ps);
  mfree_particles_destroy(&ps);
  for (int64_t allow = 0; allow < calls; ++allow) {
    ps = make_set(ctx, &c, MFREE_SEARCH_GATHER, 2.0, 0);
    cnt.fail_after = cnt.calls + allow;
    assert_error(ctx, mfree_particles_setup(ps), MFREE_ERR_ALLOC, "memory");
    int64_t nnz = 0;
    assert_error(ctx, mfree_particles_get_neighbor_nnz(ps, &nnz), MFREE_ERR_STATE, "not set up");
    cnt.fail_after = -1;
    assert_ok(ctx, mfree_particles_setup(ps));
    lists_t g = lists_fetch(ctx, ps);
    assert_lists_equal(&g, &ref);
    lists_free(&g);
    mfree_particles_destroy(&ps);
  }
  lists_free(&ref);
  mfree_context_destroy(&ctx);
  assert_int_equal(cnt.held, 0);
  assert_int_equal(cnt.frees, cnt.calls);
  cloud_free(&c);
}

/* Allocations counted from any thread (the hook may be called by both at once). */
static atomic_llong g_calls;
static void *atomic_alloc(void *user, int64_t bytes) {
  (void)user;
  atomic_fetch_add(&g_calls, 1);
  return malloc((size_t)bytes);
}
static void atomic_free(void *user, void *p, int64_t bytes) {
  (void)user;
  (void)bytes;
  free(p);
}

/* Two threads, host order: repeated setups of a moving set allocate nothing once the
 * sizes have settled, and give the one-thread lists bit for bit. */
static void test_two_threads_repeated(void **state) {
  (void)state;
  mfree_rng_t r;
  mfree_rng_seed(&r, 2205);
  cloud_t c = lattice(3, 16, &r);
  for (int32_t i = 0; i < c.n; ++i) c.h[i] = 0.5 * cbrt(45.0 * 3.0 / (4.0 * M_PI));
  mfree_context_t *ctx = NULL, *ctx1 = NULL;
  assert_ok(NULL, mfree_context_create(&ctx));
  assert_ok(NULL, mfree_context_create(&ctx1));
  assert_ok(ctx, mfree_context_set_num_threads(ctx, 2));
  assert_ok(ctx, mfree_context_set_allocator(ctx, atomic_alloc, atomic_free, NULL));
  mfree_particles_t *ps = make_set(ctx, &c, MFREE_SEARCH_GATHER, 2.0, 0);
  mfree_particles_t *ps1 = make_set(ctx1, &c, MFREE_SEARCH_GATHER, 2.0, 0);
  assert_ok(ctx, mfree_particles_setup(ps));
  assert_true(atomic_load(&g_calls) > 0);
  /* a second setup settles the sizes (it keeps the previous statuses aside once) */
  assert_ok(ctx, mfree_particles_setup(ps));
  const long long calls = atomic_load(&g_calls);
  for (int step = 0; step < 4; ++step) {
    /* a slight contraction (the bounding box, hence the grid, does not grow) and jitter */
    for (int64_t k = 0; k < 3 * (int64_t)c.n; ++k)
      c.x[k] = 7.5 + (c.x[k] - 7.5) * 0.999 + 1e-4 * (mfree_rng_uniform(&r) - 0.5);
    assert_ok(ctx, mfree_particles_setup(ps));
    assert_ok(ctx1, mfree_particles_setup(ps1));
    if (atomic_load(&g_calls) != calls)
      fail_msg("step %d: %lld allocations in a repeated 2-thread setup", step, atomic_load(&g_calls) - calls);
    lists_t g = lists_fetch(ctx, ps), g1 = lists_fetch(ctx1, ps1);
    assert_lists_equal(&g, &g1);
    lists_free(&g);
    lists_free(&g1);
  }
  mfree_particles_destroy(&ps);
  mfree_particles_destroy(&ps1);
  mfree_context_destroy(&ctx);
  mfree_context_destroy(&ctx1);
  cloud_free(&c);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_lattices),
      cmocka_unit_test(test_far_swaps),
      cmocka_unit_test(test_clustered_growth),
      cmocka_unit_test(test_allocation_failure),
      cmocka_unit_test(test_two_threads_repeated),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
