/* t807: the singularity threshold on the reciprocal condition estimate
 * (mfree_suitesparse_set_rcond_threshold). UMFPACK and KLU stop only at exactly zero
 * pivots, so without it a singular matrix whose zero pivot round-off made tiny is
 * factorised and solved silently.
 *  - A 2 x 2 block [[1, 1], [1, 1 + delta]] (plus an identity block): its estimate is
 *    about delta for all three solvers (row scaling of UMFPACK / KLU leaves it at that
 *    order; CHOLMOD's squared ratio of L's diagonal is delta exactly in exact
 *    arithmetic). delta = 1e-8 passes the default (1e-10), fails a threshold of 1e-6
 *    with MFREE_FAIL_SINGULAR and a message that gives the estimate, and passes again
 *    after the threshold is lowered (update, same pattern); delta = 1e-12 fails the
 *    default and passes with the check disabled (threshold 0).
 *  - The Laplacian of a grid graph with pure Neumann rows (every row sums to zero, so it
 *    is singular with the null vector 1; weights 0.1 .. 0.7 are not dyadic, so the last
 *    pivot is a round-off residue rather than an exact zero, or for CHOLMOD possibly
 *    negative), n = 25 .. 10000: MFREE_FAIL_SINGULAR under the default threshold for
 *    every solver; with the check disabled (threshold 0) CHOLMOD usually still stops
 *    (a non-positive pivot) but UMFPACK and KLU "succeed" with estimates of
 *    1e-15 .. 5e-13 (growing about like n eps): what the default catches. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sstest.h"

enum { K = 6, N2 = K + 2 };

static mfree_matrix_t *near_singular(mfree_context_t *ctx, double delta) {
  double a[N2 * N2];
  memset(a, 0, sizeof a);
  a[0] = 1.0, a[1] = 1.0, a[N2] = 1.0, a[N2 + 1] = 1.0 + delta;
  for (int i = 2; i < N2; ++i) a[i * N2 + i] = 1.0 + 0.1 * i;
  return ss_dense(ctx, N2, a, NULL);
}

static const char *name_of(mfree_solver_kind_t k) {
  return k == MFREE_SOLVER_CHOLMOD ? "CHOLMOD" : k == MFREE_SOLVER_UMFPACK ? "UMFPACK" : "KLU";
}

static void threshold_moves(void **state) {
  (void)state;
  mfree_context_t *ctx = NULL;
  assert_ok(NULL, mfree_context_create(&ctx));
  mfree_matrix_t *A = near_singular(ctx, 1e-8);
  double b[N2], x[N2], xtrue[N2];
  ss_make_rhs(A, 1, xtrue, b, N2);
  for (int k = 0; k < 3; ++k)
    for (int width = 32; width <= 64; width += 32) {
      mfree_suitesparse_t *s = NULL;
      assert_ok(ctx, mfree_suitesparse_create(ctx, ss_kinds[k], &s));
      assert_ok(ctx, mfree_suitesparse_set_index_width(s, width));
      /* default: passes */
      assert_ok(ctx, mfree_suitesparse_setup(s, A));
      double rc = 0.0;
      assert_ok(ctx, mfree_suitesparse_get_info(s, &rc, NULL, NULL));
      print_message("%s (%d-bit): rcond %.3e\n", name_of(ss_kinds[k]), width, rc);
      assert_true(rc > 1e-10 && rc < 1e-6);
      assert_ok(ctx, mfree_suitesparse_solve(s, 1, b, N2, x, N2));
      assert_true(ss_rel_error(N2, 1, x, N2, xtrue) < 1e-6);
      /* a threshold above the estimate: reported, not solved */
      assert_ok(ctx, mfree_suitesparse_set_rcond_threshold(s, 1e-6));
      assert_error(ctx, mfree_suitesparse_setup(s, A), MFREE_FAIL_SINGULAR, "reciprocal condition estimate");
      char msg[512] = "";
      mfree_context_get_last_error(ctx, NULL, msg, sizeof msg);
      assert_non_null(strstr(msg, name_of(ss_kinds[k])));
      assert_non_null(strstr(msg, "threshold 1e-06"));
      assert_error(ctx, mfree_suitesparse_solve(s, 1, b, N2, x, N2), MFREE_ERR_STATE, "factorisation failed");
      double rej = 0.0;
      assert_ok(ctx, mfree_suitesparse_get_info(s, &rej, NULL, NULL));
      assert_true(rej > 1e-10 && rej < 1e-6); /* the rejected estimate stays readable */
      assert_error(ctx, mfree_suitesparse_update(s, A), MFREE_FAIL_SINGULAR, "below the threshold");
      /* lowered: the same pattern factorises again */
      assert_ok(ctx, mfree_suitesparse_set_rcond_threshold(s, 1e-9));
      assert_ok(ctx, mfree_suitesparse_update(s, A));
      assert_ok(ctx, mfree_suitesparse_solve(s, 1, b, N2, x, N2));
      assert_true(ss_rel_error(N2, 1, x, N2, xtrue) < 1e-6);
      mfree_suitesparse_destroy(&s);
    }
  mfree_matrix_destroy(&A);
  /* below the default: reported; with the check off it is factorised (and solved
   * as well as an estimate of 1e-12 allows) */
  A = near_singular(ctx, 1e-12);
  ss_make_rhs(A, 1, xtrue, b, N2);
  for (int k = 0; k < 3; ++k) {
    mfree_suitesparse_t *s = NULL;
    assert_ok(ctx, mfree_suitesparse_create(ctx, ss_kinds[k], &s));
    assert_error(ctx, mfree_suitesparse_setup(s, A), MFREE_FAIL_SINGULAR, "threshold 1e-10");
    assert_ok(ctx, mfree_suitesparse_set_rcond_threshold(s, 0.0));
    assert_ok(ctx, mfree_suitesparse_setup(s, A));
    assert_ok(ctx, mfree_suitesparse_solve(s, 1, b, N2, x, N2));
    assert_true(ss_rel_error(N2, 1, x, N2, xtrue) < 1e-2);
    mfree_suitesparse_destroy(&s);
  }
  mfree_matrix_destroy(&A);
  mfree_context_destroy(&ctx);
}

/* Graph Laplacian of an m x m grid with edge weights 0.1 (1 + (i + 2 j) % 7). */
static mfree_matrix_t *neumann(mfree_context_t *ctx, int32_t m) {
  const int32_t n = m * m;
  int64_t *rp = malloc(sizeof(int64_t) * (size_t)(n + 1));
  int32_t *ci = malloc(sizeof(int32_t) * 5 * (size_t)n);
  double *v = malloc(sizeof(double) * 5 * (size_t)n);
  int64_t nz = 0;
  rp[0] = 0;
  for (int32_t j = 0; j < m; ++j)
    for (int32_t i = 0; i < m; ++i) {
      const int32_t r = i + m * j;
      /* neighbours in column order: south, west, (self), east, north */
      const int32_t nb[4] = {j > 0 ? r - m : -1, i > 0 ? r - 1 : -1, i < m - 1 ? r + 1 : -1, j < m - 1 ? r + m : -1};
      double w[4], d = 0.0;
      for (int q = 0; q < 4; ++q) {
        const int32_t c = nb[q];
        if (c < 0) continue;
        const int32_t lo = r < c ? r : c, hi = r < c ? c : r; /* symmetric weight of edge (lo, hi) */
        w[q] = 0.1 * (1 + (lo + 2 * hi) % 7);
        d += w[q];
      }
      for (int q = 0; q < 2; ++q)
        if (nb[q] >= 0) ci[nz] = nb[q], v[nz++] = -w[q];
      ci[nz] = r, v[nz++] = d;
      for (int q = 2; q < 4; ++q)
        if (nb[q] >= 0) ci[nz] = nb[q], v[nz++] = -w[q];
      rp[r + 1] = nz;
    }
  mfree_matrix_t *A = NULL;
  assert_ok(ctx, mfree_matrix_create_csr(ctx, n, n, rp, ci, v, &A));
  free(rp), free(ci), free(v);
  return A;
}

static void singular_reported(void **state) {
  (void)state;
  mfree_context_t *ctx = NULL;
  assert_ok(NULL, mfree_context_create(&ctx));
  static const int32_t ms[5] = {5, 10, 20, 50, 100};
  for (int im = 0; im < 5; ++im) {
    const int32_t m = ms[im];
    mfree_matrix_t *A = neumann(ctx, m);
    int32_t sym = 0;
    assert_ok(ctx, mfree_matrix_get_symmetric(A, &sym));
    assert_int_equal(sym, 1);
    for (int k = 0; k < 3; ++k) {
      mfree_suitesparse_t *s = NULL;
      assert_ok(ctx, mfree_suitesparse_create(ctx, ss_kinds[k], &s));
      assert_error(ctx, mfree_suitesparse_setup(s, A), MFREE_FAIL_SINGULAR, name_of(ss_kinds[k]));
      assert_ok(ctx, mfree_suitesparse_set_rcond_threshold(s, 0.0));
      const mfree_status_t st = mfree_suitesparse_setup(s, A);
      double rc = -1.0;
      assert_ok(ctx, mfree_suitesparse_get_info(s, &rc, NULL, NULL));
      print_message("m = %2d %-7s: without the check status %d, rcond %.2e\n", m, name_of(ss_kinds[k]), (int)st, rc);
      if (st == MFREE_SUCCESS)
        assert_true(rc < 1e-12);
      else
        assert_int_equal(st, MFREE_FAIL_SINGULAR);
      mfree_suitesparse_destroy(&s);
    }
    mfree_matrix_destroy(&A);
  }
  mfree_context_destroy(&ctx);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(threshold_moves),
      cmocka_unit_test(singular_reported),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
