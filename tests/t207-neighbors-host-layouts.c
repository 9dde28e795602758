/*
 * t207: the host-order neighbour search's strided reads and four-lane scans
 * (src/core/particles/neighbors.cpp: query2_avx2 in 2D, query_avx2_t in 3D, on x86 with AVX2;
 * elsewhere, or with MFREE_SIMD=baseline, the general path, and the test checks that).
 *
 * Jittered lattices stored in lattice order (host order = spatial order), gather
 * convention, supports varying by a factor ~2 from particle to particle (query radii and
 * member ranges of every length, rows past the lanes' masks), given
 *  - as AoS positions with stride-1 supports, and
 *  - as SoA positions with a padded leading dimension (n + 5) and the supports read with
 *    stride 3 out of an interleaved array:
 * both must give the same lists bit for bit, with one thread and with two, and every row
 * must equal the O(N^2) oracle's: j in row i iff |x_i - x_j| <= kappa h_i, for every pair
 * farther than 1e-9 (relative) from that threshold (pairs closer to it are not judged: the
 * library's closed-support tolerance decides them); the test also asserts that at least
 * one row has more than 32 entries and one fewer than 16.
 * And a repeated one-thread setup whose rows outgrow the row buffer and the lists (the
 * supports doubled in the borrowed array) with every allocation failing in turn, through
 * a failing allocator hook: MFREE_ERR_ALLOC, and then either the set not set up (the
 * host-order search had begun to overwrite its lists) or still set up with its previous
 * lists unchanged (the general path, MFREE_SIMD=baseline) -- never half-written lists
 * that count as set up; a retry equal to a fresh set's lists, every block returned. No
 * timing.
 */
#include "count_alloc.h"
#include "testutil.h"
#include "nbr_lists.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static lists_t search(int dim, int32_t n, const double *x, int layout, int64_t ld, const double *h, int64_t hs,
                      int threads) {
  mfree_context_t *ctx = NULL;
  mfree_particles_t *ps = NULL;
  assert_ok(NULL, mfree_context_create(&ctx));
  assert_ok(ctx, mfree_context_set_num_threads(ctx, threads));
  assert_ok(ctx, mfree_particles_create(ctx, dim, n, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, x, (mfree_layout_t)layout, ld, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_support(ps, h, hs, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_search(ps, MFREE_SEARCH_GATHER, 2.0));
  assert_ok(ctx, mfree_particles_setup(ps));
  lists_t g = lists_fetch(ctx, ps);
  mfree_particles_destroy(&ps);
  mfree_context_destroy(&ctx);
  return g;
}

static void run(int dim, int m, double neighbours, uint64_t seed) {
  mfree_rng_t r;
  mfree_rng_seed(&r, seed);
  int32_t n = 1;
  for (int d = 0; d < dim; ++d) n *= m;
  const int64_t ld = (int64_t)n + 5;
  double *aos = malloc(sizeof(double) * (size_t)n * dim), *soa = malloc(sizeof(double) * (size_t)ld * dim);
  double *h = malloc(sizeof(double) * (size_t)n), *h3 = malloc(sizeof(double) * 3 * (size_t)n);
  assert_non_null(aos);
  assert_non_null(soa);
  assert_non_null(h);
  assert_non_null(h3);
  /* mean support radius 2 h for `neighbours` neighbours at unit density */
  const double rad = dim == 2 ? sqrt(neighbours / M_PI) : cbrt(neighbours * 3.0 / (4.0 * M_PI));
  jittered_lattice(aos, dim, m, &r);
  for (int32_t p = 0; p < n; ++p) {
    for (int d = 0; d < dim; ++d) soa[(size_t)d * ld + p] = aos[(size_t)dim * p + d];
    h[p] = 0.5 * rad * (0.6 + 0.8 * mfree_rng_uniform(&r));
    h3[3 * (size_t)p] = h[p];
    h3[3 * (size_t)p + 1] = -1.0; /* never read */
    h3[3 * (size_t)p + 2] = NAN;
  }
  for (int64_t p = n; p < ld; ++p)
    for (int d = 0; d < dim; ++d) soa[(size_t)d * ld + p] = NAN; /* padding, never read */

  lists_t ref = search(dim, n, aos, MFREE_LAYOUT_AOS, dim, h, 1, 1);
  for (int threads = 1; threads <= 2; ++threads) {
    lists_t g = search(dim, n, soa, MFREE_LAYOUT_SOA, ld, h3, 3, threads);
    assert_lists_equal(&g, &ref);
    lists_free(&g);
    if (threads == 2) {
      g = search(dim, n, aos, MFREE_LAYOUT_AOS, dim, h, 1, 2);
      assert_lists_equal(&g, &ref);
      lists_free(&g);
    }
  }

  /* the oracle, row by row: clear pairs only */
  int64_t longest = 0, shortest = n, judged = 0;
  for (int32_t i = 0; i < n; ++i) {
    const int64_t b = ref.rowptr[i], e = ref.rowptr[i + 1];
    if (e - b > longest) longest = e - b;
    if (e - b < shortest) shortest = e - b;
    for (int64_t k = b + 1; k < e; ++k) assert_true(ref.cols[k - 1] < ref.cols[k]);
    const double lim2 = (2.0 * h[i]) * (2.0 * h[i]);
    int64_t k = b;
    for (int32_t j = 0; j < n; ++j) {
      double d2 = 0.0;
      for (int d = 0; d < dim; ++d) {
        const double t = aos[(size_t)dim * i + d] - aos[(size_t)dim * j + d];
        d2 += t * t;
      }
      const int listed = k < e && ref.cols[k] == j;
      if (listed) ++k;
      if (fabs(d2 - lim2) <= 1e-9 * lim2) continue;
      ++judged;
      if ((d2 < lim2) != listed)
        fail_msg("%dD row %d, particle %d: distance^2 %.17g, limit^2 %.17g, %s", dim, i, j, d2, lim2,
                 listed ? "listed" : "missing");
    }
    if (k != e) fail_msg("%dD row %d: entries not in the oracle's order", dim, i);
  }
  assert_true(judged > 0);
  if (!(longest > 32 && shortest < 16))
    fail_msg("%dD rows of %lld to %lld entries: the range the test means to cover is missed", dim,
             (long long)shortest, (long long)longest);
  lists_free(&ref);
  free(aos);
  free(soa);
  free(h);
  free(h3);
}

static void test_2d(void **state) {
  (void)state;
  run(2, 60, 21.0, 2071);
}

static void test_3d(void **state) {
  (void)state;
  run(3, 15, 45.0, 2072);
}

static void test_growth_failure(void **state) {
  (void)state;
  mfree_rng_t r;
  mfree_rng_seed(&r, 2073);
  const int m = 12, dim = 3;
  const int32_t n = m * m * m;
  double *x = malloc(sizeof(double) * 3 * (size_t)n), *h = malloc(sizeof(double) * (size_t)n);
  assert_non_null(x);
  assert_non_null(h);
  jittered_lattice(x, dim, m, &r);
  const double small = 0.5 * cbrt(20.0 * 3.0 / (4.0 * M_PI)), big = 2.0 * small; /* ~20, ~160 neighbours */
  /* the references: fresh sets with the small and the big supports */
  for (int32_t p = 0; p < n; ++p) h[p] = small;
  lists_t old = search(dim, n, x, MFREE_LAYOUT_AOS, dim, h, 1, 1);
  for (int32_t p = 0; p < n; ++p) h[p] = big;
  lists_t ref = search(dim, n, x, MFREE_LAYOUT_AOS, dim, h, 1, 1);
  counter_t cnt = {0, 0, 0, -1};
  mfree_context_t *ctx = NULL;
  assert_ok(NULL, mfree_context_create(&ctx));
  assert_ok(ctx, mfree_context_set_num_threads(ctx, 1));
  assert_ok(ctx, mfree_context_set_allocator(ctx, count_alloc, count_free, &cnt));
  int64_t calls = -1;
  for (int64_t allow = -1; allow < calls || calls < 0; ++allow) {
    mfree_particles_t *ps = NULL;
    assert_ok(ctx, mfree_particles_create(ctx, dim, n, &ps));
    assert_ok(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, dim, MFREE_BORROW));
    assert_ok(ctx, mfree_particles_set_support(ps, h, 1, MFREE_BORROW));
    for (int32_t p = 0; p < n; ++p) h[p] = small;
    assert_ok(ctx, mfree_particles_setup(ps));
    for (int32_t p = 0; p < n; ++p) h[p] = big; /* borrowed: the next setup sees them */
    const int64_t before = cnt.calls;
    if (allow < 0) {
      /* count the repeated setup's allocations */
      assert_ok(ctx, mfree_particles_setup(ps));
      calls = cnt.calls - before;
      assert_true(calls >= 2); /* the row buffer and the lists grow */
    } else {
      cnt.fail_after = before + allow;
      assert_error(ctx, mfree_particles_setup(ps), MFREE_ERR_ALLOC, "memory");
      cnt.fail_after = -1;
      int64_t nnz = 0;
      if (mfree_particles_get_neighbor_nnz(ps, &nnz) == MFREE_SUCCESS) {
        /* still set up: the previous lists, unchanged */
        lists_t g = lists_fetch(ctx, ps);
        assert_lists_equal(&g, &old);
        lists_free(&g);
      } else {
        assert_error(ctx, mfree_particles_get_neighbor_nnz(ps, &nnz), MFREE_ERR_STATE, "not set up");
      }
      assert_ok(ctx, mfree_particles_setup(ps));
    }
    lists_t g = lists_fetch(ctx, ps);
    assert_lists_equal(&g, &ref);
    lists_free(&g);
    mfree_particles_destroy(&ps);
  }
  mfree_context_destroy(&ctx);
  assert_int_equal(cnt.held, 0);
  assert_int_equal(cnt.frees, cnt.calls);
  lists_free(&ref);
  lists_free(&old);
  free(x);
  free(h);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_2d),
      cmocka_unit_test(test_3d),
      cmocka_unit_test(test_growth_failure),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
