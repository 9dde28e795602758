/*
 * t203: repeated searches on one particle set with 1 and 2 threads.
 *
 * A particle set keeps the search's grid and buffers between setups, builds the grid
 * with per-thread histograms and searches in place into the lists' storage. Here one
 * set is set up again and again while the borrowed positions and supports change (the
 * lists grow, shrink and change pattern), with enough particles (2,197 in 3D, 2,304 in
 * 2D) that two threads split every pass. Each setup must equal the O(N^2) oracle row by
 * row, and the 1- and 2-thread lists must be bitwise identical. Also: a non-finite
 * support in a threaded search (the particle is isolated, the others searched), and a
 * failing setup (periodic box too small) that must leave the previous lists unchanged.
 */
#include "testutil.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Jittered lattice of m^dim points (spacing 1, AoS with dim components). */
static double *lattice(int dim, int m, uint64_t seed, int32_t *n_out) {
  int32_t n = 1;
  for (int d = 0; d < dim; ++d) n *= m;
  double *x = malloc(sizeof(double) * (size_t)dim * (size_t)n);
  assert_non_null(x);
  for (int32_t p = 0; p < n; ++p) {
    int32_t q = p;
    for (int c = 0; c < dim; ++c) {
      seed ^= seed >> 12;
      seed ^= seed << 25;
      seed ^= seed >> 27;
      const double u = (double)((seed * 2685821657736338717ULL) >> 11) / 9007199254740992.0;
      x[(size_t)dim * p + c] = (q % m) + 0.6 * (u - 0.5);
      q /= m;
    }
  }
  *n_out = n;
  return x;
}

/* The gather criterion as the library states it: |x_i - x_j|^2 <= (kappa h_i)^2; counts
 * pairs within a relative 1e-9 of the threshold (a tie would make the test ambiguous). */
static int64_t oracle_rows(int dim, int32_t n, const double *x, const double *h, int64_t hs, double kappa,
                           int64_t *rp, int32_t *cl, int64_t cap, int64_t *ties) {
  int64_t k = 0;
  rp[0] = 0;
  for (int32_t i = 0; i < n; ++i) {
    const double r = kappa * h[i * hs], lim2 = r * r;
    for (int32_t j = 0; j < n; ++j) {
      double d2 = 0.0;
      for (int c = 0; c < dim; ++c) {
        const double d = x[(size_t)dim * i + c] - x[(size_t)dim * j + c];
        d2 += d * d;
      }
      if (fabs(d2 - lim2) <= 1e-9 * lim2) ++*ties;
      if (d2 <= lim2) {
        assert_true(k < cap);
        cl[k++] = j;
      }
    }
    rp[i + 1] = k;
  }
  return k;
}

typedef struct {
  int64_t *rp;
  int32_t *cl;
  int64_t nnz;
} lists_t;

static lists_t get_lists(mfree_context_t *ctx, mfree_particles_t *ps, int32_t n) {
  lists_t l;
  assert_ok(ctx, mfree_particles_get_neighbor_nnz(ps, &l.nnz));
  l.rp = malloc(sizeof(int64_t) * (size_t)(n + 1));
  l.cl = malloc(sizeof(int32_t) * (size_t)(l.nnz > 0 ? l.nnz : 1));
  assert_non_null(l.rp);
  assert_non_null(l.cl);
  assert_ok(ctx, mfree_particles_get_neighbors(ps, l.rp, l.cl));
  return l;
}

static void lists_free(lists_t *l) {
  free(l->rp);
  free(l->cl);
}

static void assert_lists_equal(const lists_t *a, const lists_t *b, int32_t n) {
  assert_int_equal(a->nnz, b->nnz);
  assert_memory_equal(a->rp, b->rp, sizeof(int64_t) * (size_t)(n + 1));
  assert_memory_equal(a->cl, b->cl, sizeof(int32_t) * (size_t)a->nnz);
}

/* Five setups of one set per thread count: uniform h (rows sorted by transposition) and
 * variable h (rows sorted one by one), positions and supports changed in between. */
static void check_dim(int dim, int m) {
  int32_t n = 0;
  double *x0 = lattice(dim, m, 0x2030 + (uint64_t)dim, &n);
  double *x = malloc(sizeof(double) * (size_t)dim * (size_t)n), *h = malloc(sizeof(double) * (size_t)n);
  const int64_t cap = (int64_t)n * 200;
  int64_t *orp = malloc(sizeof(int64_t) * (size_t)(n + 1));
  int32_t *ocl = malloc(sizeof(int32_t) * (size_t)cap);
  assert_non_null(x);
  assert_non_null(h);
  assert_non_null(orp);
  assert_non_null(ocl);
  /* step s: lattice scaled by 1 + 0.05 s, support growing then shrinking, variable from
   * step 2 on (the sorted path), uniform otherwise (the transposed path) */
  const double hs[5] = {1.0, 1.4, 0.8, 1.2, 0.7};
  lists_t got[2][5];
  for (int t = 0; t < 2; ++t) {
    mfree_context_t *ctx = NULL;
    assert_ok(ctx, mfree_context_create(&ctx));
    assert_ok(ctx, mfree_context_set_num_threads(ctx, t + 1));
    memcpy(x, x0, sizeof(double) * (size_t)dim * (size_t)n); /* validated when set */
    for (int32_t i = 0; i < n; ++i) h[i] = 1.0;
    mfree_particles_t *ps = NULL;
    assert_ok(ctx, mfree_particles_create(ctx, dim, n, &ps));
    assert_ok(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, dim, MFREE_BORROW));
    assert_ok(ctx, mfree_particles_set_support(ps, h, 1, MFREE_BORROW));
    for (int s = 0; s < 5; ++s) {
      for (int64_t k = 0; k < (int64_t)dim * n; ++k) x[k] = x0[k] * (1.0 + 0.05 * s) + 0.01 * s;
      for (int32_t i = 0; i < n; ++i) h[i] = hs[s] * ((s % 2 == 0 && s > 0) ? 1.0 + 0.3 * ((i * 7) % 5) / 4.0 : 1.0);
      assert_ok(ctx, mfree_particles_setup(ps));
      got[t][s] = get_lists(ctx, ps, n);
      if (t == 0) {
        int64_t ties = 0;
        const int64_t nnz = oracle_rows(dim, n, x, h, 1, 2.0, orp, ocl, cap, &ties);
        assert_int_equal(ties, 0);
        assert_int_equal(nnz, got[0][s].nnz);
        assert_memory_equal(orp, got[0][s].rp, sizeof(int64_t) * (size_t)(n + 1));
        assert_memory_equal(ocl, got[0][s].cl, sizeof(int32_t) * (size_t)nnz);
      } else {
        assert_lists_equal(&got[0][s], &got[1][s], n);
      }
    }

    /* A non-finite support in a threaded search: that particle is isolated, the rest
     * equal the oracle over the valid particles. */
    const int32_t bad = n / 2 + 3;
    h[bad] = NAN;
    assert_error(ctx, mfree_particles_setup(ps), MFREE_FAIL_NONFINITE, "support");
    lists_t l = get_lists(ctx, ps, n);
    assert_int_equal(l.rp[bad + 1], l.rp[bad]);
    for (int64_t k = 0; k < l.nnz; ++k) assert_int_not_equal(l.cl[k], bad);
    h[bad] = h[0];
    assert_ok(ctx, mfree_particles_setup(ps));
    lists_t full = get_lists(ctx, ps, n);
    for (int32_t i = 0; i < n; ++i) {
      if (i == bad) continue;
      /* row i of the failed search is row i of the full one without `bad` */
      int64_t a = l.rp[i];
      for (int64_t k = full.rp[i]; k < full.rp[i + 1]; ++k) {
        if (full.cl[k] == bad) continue;
        assert_true(a < l.rp[i + 1]);
        assert_int_equal(l.cl[a++], full.cl[k]);
      }
      assert_int_equal(a, l.rp[i + 1]);
    }

    /* A failing setup (a borrowed support grew past half the periodic box) leaves the
     * previous lists unchanged. */
    const double lo[3] = {-1.0, -1.0, -1.0}, hi[3] = {1.3 * m + 1.0, 1.3 * m + 1.0, 1.3 * m + 1.0};
    const int32_t per[3] = {1, 1, 1};
    assert_ok(ctx, mfree_particles_set_periodic(ps, lo, hi, per));
    assert_ok(ctx, mfree_particles_setup(ps));
    lists_t before = get_lists(ctx, ps, n);
    const double h0 = h[0];
    h[0] = 0.5 * hi[0];
    assert_error(ctx, mfree_particles_setup(ps), MFREE_ERR_INPUT, "periodic box");
    lists_t after = get_lists(ctx, ps, n);
    assert_lists_equal(&before, &after, n);
    h[0] = h0;
    lists_free(&before);
    lists_free(&after);
    lists_free(&full);
    lists_free(&l);
    mfree_particles_destroy(&ps);
    mfree_context_destroy(&ctx);
  }
  for (int t = 0; t < 2; ++t)
    for (int s = 0; s < 5; ++s) lists_free(&got[t][s]);
  free(orp);
  free(ocl);
  free(x);
  free(h);
  free(x0);
}

static void test_reuse_2d(void **state) {
  (void)state;
  check_dim(2, 48); /* 2,304 particles */
}

static void test_reuse_3d(void **state) {
  (void)state;
  check_dim(3, 13); /* 2,197 particles */
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_reuse_2d),
      cmocka_unit_test(test_reuse_3d),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
