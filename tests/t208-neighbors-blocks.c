/*
 * t208: the host-order search on several threads (src/core/particles/neighbors.cpp,
 * host_order_blocks) gives the one-thread lists bit for bit while the particles move
 * so that some blocks of rows grow and others shrink.
 *
 * Each block writes its rows at a guessed offset (its offset in the previous lists) into
 * spare lists, spills what outgrows the room into a buffer of its own, and the blocks
 * are moved into place afterwards (right-moving ones last to first, the others first to
 * last). A jittered lattice in host order (x fastest, so block t holds a slab of the
 * slowest axis) is squeezed on one side and stretched on the other, then the other way
 * round, then drawn together as a whole (rows ~2x: the spare lists grow), then spread
 * again; every setup on 2, 3, 5 and 8 threads (blocks; the runtime may grant fewer
 * threads, the blocks stay) must equal a one-thread setup of the same points. Gather
 * (variable supports) and symmetric-mean conventions, 2D and 3D; a 2D case with ghosts.
 * Holds without AVX2 too (general path on both sides). No timing.
 */
#include "testutil.h"
#include "nbr_lists.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Scale the slowest axis about its middle: by a below the middle, by b above. */
static void warp(double *x, const double *x0, int dim, int32_t n, double mid, double a, double b) {
  for (int32_t p = 0; p < n; ++p) {
    for (int d = 0; d < dim; ++d) x[(size_t)dim * p + d] = x0[(size_t)dim * p + d];
    double *s = &x[(size_t)dim * p + dim - 1];
    *s = mid + (*s < mid ? a : b) * (*s - mid);
  }
}

static void run_case(int dim, int m, int conv, int32_t ng) {
  mfree_rng_t r;
  mfree_rng_seed(&r, (uint64_t)(208 + 10 * dim + conv + ng));
  int32_t n = 1;
  for (int d = 0; d < dim; ++d) n *= m;
  double *x0 = malloc(sizeof(double) * (size_t)dim * (size_t)n);
  double *x = malloc(sizeof(double) * (size_t)dim * (size_t)n);
  double *h = malloc(sizeof(double) * (size_t)n);
  assert_non_null(x0);
  assert_non_null(x);
  assert_non_null(h);
  jittered_lattice(x0, dim, m, &r);
  for (int32_t p = 0; p < n; ++p) h[p] = (dim == 2 ? 1.3 : 1.1) * (1.0 + 0.4 * mfree_rng_uniform(&r));
  memcpy(x, x0, sizeof(double) * (size_t)dim * (size_t)n);
  const int threads[5] = {1, 2, 3, 5, 8};
  mfree_context_t *ctx[5];
  mfree_particles_t *ps[5];
  for (int k = 0; k < 5; ++k) {
    assert_ok(NULL, mfree_context_create(&ctx[k]));
    assert_ok(ctx[k], mfree_context_set_num_threads(ctx[k], threads[k]));
    assert_ok(ctx[k], mfree_particles_create(ctx[k], dim, n, &ps[k]));
    assert_ok(ctx[k], mfree_particles_set_positions(ps[k], x, MFREE_LAYOUT_AOS, dim, MFREE_BORROW));
    assert_ok(ctx[k], mfree_particles_set_support(ps[k], h, 1, MFREE_BORROW));
    assert_ok(ctx[k], mfree_particles_set_search(ps[k], (mfree_search_t)conv, 2.0));
    if (ng) assert_ok(ctx[k], mfree_particles_set_num_ghost(ps[k], ng));
  }
  const double mid = 0.5 * (m - 1);
  /* (below-middle factor, above-middle factor) of each step */
  const double steps[][2] = {{1.0, 1.0}, {0.9, 1.1}, {0.85, 1.2}, {1.15, 0.9}, {1.0, 1.0},
                             {0.7, 0.7}, {0.72, 0.75}, {1.1, 1.1}, {1.0, 1.0}};
  const int nsteps = (int)(sizeof(steps) / sizeof(steps[0]));
  for (int s = 0; s < nsteps; ++s) {
    warp(x, x0, dim, n, mid, steps[s][0], steps[s][1]);
    for (int k = 0; k < 5; ++k) assert_ok(ctx[k], mfree_particles_setup(ps[k]));
    lists_t ref = lists_fetch(ctx[0], ps[0]);
    assert_true(ref.rowptr[ref.rows] > 10 * (int64_t)ref.rows);
    for (int k = 1; k < 5; ++k) {
      lists_t g = lists_fetch(ctx[k], ps[k]);
      assert_int_equal(g.rows, ref.rows);
      if (memcmp(g.rowptr, ref.rowptr, sizeof(int64_t) * ((size_t)ref.rows + 1)) != 0 ||
          memcmp(g.cols, ref.cols, sizeof(int32_t) * (size_t)ref.rowptr[ref.rows]) != 0)
        fail_msg("%dD conv %d step %d: %d threads differ from one", dim, conv, s, threads[k]);
      lists_free(&g);
    }
    lists_free(&ref);
  }
  for (int k = 0; k < 5; ++k) {
    mfree_particles_destroy(&ps[k]);
    mfree_context_destroy(&ctx[k]);
  }
  free(x0);
  free(x);
  free(h);
}

static void test_3d_gather(void **state) {
  (void)state;
  run_case(3, 16, MFREE_SEARCH_GATHER, 0);
}

static void test_3d_symmetric_mean(void **state) {
  (void)state;
  run_case(3, 14, MFREE_SEARCH_SYMMETRIC_MEAN, 0);
}

static void test_2d_gather_ghosts(void **state) {
  (void)state;
  run_case(2, 70, MFREE_SEARCH_GATHER, 300);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_3d_gather),
      cmocka_unit_test(test_3d_symmetric_mean),
      cmocka_unit_test(test_2d_gather_ghosts),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
