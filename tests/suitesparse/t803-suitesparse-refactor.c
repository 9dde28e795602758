/* t803: numeric refactorisation through update (c): new values on the same pattern,
 * many times, from the same and from other matrix objects; a pattern change without
 * setup is MFREE_ERR_STATE and changes nothing; update before setup; update after a
 * singular setup; KLU's refactorisation falling back to fresh pivoting. */
#include <math.h>
#include <string.h>

#include "sstest.h"

enum { M = 16, N = M * M };

/* SPD for every t (diagonally dominant): for CHOLMOD. Nonsymmetric for t != 0 with
 * nonsym set: for UMFPACK and KLU. */
static mfree_matrix_t *family(mfree_context_t *ctx, int t, int nonsym) {
  const double d = 4.0 + 0.37 * t, c = nonsym ? 0.11 * t : 0.0;
  return ss_stencil(ctx, M, d, -1.0 - c, -1.0 + c, -1.0 + 0.5 * c, -1.0 - 0.5 * c);
}

static void repeated_updates(void **state) {
  (void)state;
  mfree_context_t *ctx = NULL;
  assert_ok(NULL, mfree_context_create(&ctx));
  for (int k = 0; k < 3; ++k) {
    const int nonsym = ss_kinds[k] != MFREE_SOLVER_CHOLMOD;
    mfree_suitesparse_t *s = NULL;
    assert_ok(ctx, mfree_suitesparse_create(ctx, ss_kinds[k], &s));
    mfree_matrix_t *A0 = family(ctx, 0, nonsym);
    assert_ok(ctx, mfree_suitesparse_setup(s, A0));
    int64_t nnz0 = 0;
    assert_ok(ctx, mfree_suitesparse_get_info(s, NULL, &nnz0, NULL));
    for (int t = 1; t <= 6; ++t) {
      mfree_matrix_t *A = family(ctx, t, nonsym); /* another object, same pattern */
      double xtrue[N], b[N], x[N];
      ss_make_rhs(A, 1, xtrue, b, N);
      assert_ok(ctx, mfree_suitesparse_update(s, A));
      assert_ok(ctx, mfree_suitesparse_solve(s, 1, b, N, x, N));
      const double err = ss_rel_error(N, 1, x, N, xtrue);
      if (!(err < 1e-12)) fail_msg("solver %d, update %d: relative error %.3e", (int)ss_kinds[k], t, err);
      /* the old values are really gone: A0's right-hand side gives another answer */
      double b0[N], x0[N], xt0[N];
      ss_make_rhs(A0, 1, xt0, b0, N);
      assert_ok(ctx, mfree_suitesparse_solve(s, 1, b0, N, x0, N));
      assert_true(ss_rel_error(N, 1, x0, N, xt0) > 1e-3);
      mfree_matrix_destroy(&A);
    }
    /* back to the first values */
    double xtrue[N], b[N], x[N];
    ss_make_rhs(A0, 1, xtrue, b, N);
    assert_ok(ctx, mfree_suitesparse_update(s, A0));
    assert_ok(ctx, mfree_suitesparse_solve(s, 1, b, N, x, N));
    assert_true(ss_rel_error(N, 1, x, N, xtrue) < 1e-12);
    mfree_matrix_destroy(&A0);
    mfree_suitesparse_destroy(&s);
  }
  mfree_context_destroy(&ctx);
}

static void pattern_change_needs_setup(void **state) {
  (void)state;
  mfree_context_t *ctx = NULL;
  assert_ok(NULL, mfree_context_create(&ctx));
  ss_errors_t errs;
  ss_capture_errors(ctx, &errs);
  /* 4 x 4 patterns: the same n and nnz, one entry moved (symmetric, SPD) */
  const double a[16] = {4, 1, 0, 0, 1, 4, 1, 0, 0, 1, 4, 1, 0, 0, 1, 4};
  const double c[16] = {4, 0, 1, 0, 0, 4, 1, 0, 1, 1, 4, 1, 0, 0, 1, 4};
  const double big[25] = {4, 1, 0, 0, 0, 1, 4, 1, 0, 0, 0, 1, 4, 1, 0, 0, 0, 1, 4, 1, 0, 0, 0, 1, 4};
  mfree_matrix_t *A = ss_dense(ctx, 4, a, NULL);
  mfree_matrix_t *C = ss_dense(ctx, 4, c, NULL);
  mfree_matrix_t *B = ss_dense(ctx, 5, big, NULL);
  /* Same n and nnz, and (two fresh objects) possibly the same pattern id: only the
   * contents tell A's pattern from C's. */
  int64_t nnz_a = 0, nnz_c = 0;
  assert_ok(ctx, mfree_matrix_get_size(A, NULL, NULL, &nnz_a));
  assert_ok(ctx, mfree_matrix_get_size(C, NULL, NULL, &nnz_c));
  assert_int_equal(nnz_a, nnz_c);
  const double xtrue[4] = {1, 2, 3, 4};
  double b[4], x[4];
  for (int i = 0; i < 4; ++i)
    b[i] = a[4 * i] * xtrue[0] + a[4 * i + 1] * xtrue[1] + a[4 * i + 2] * xtrue[2] + a[4 * i + 3] * xtrue[3];
  for (int k = 0; k < 3; ++k) {
    mfree_suitesparse_t *s = NULL;
    assert_ok(ctx, mfree_suitesparse_create(ctx, ss_kinds[k], &s));
    errs.calls = 0;
    assert_error(ctx, mfree_suitesparse_update(s, A), MFREE_ERR_STATE, "mfree_suitesparse_setup");
    assert_ok(ctx, mfree_suitesparse_setup(s, A));
    assert_error(ctx, mfree_suitesparse_update(s, C), MFREE_ERR_STATE, "mfree_suitesparse_setup");
    assert_error(ctx, mfree_suitesparse_update(s, B), MFREE_ERR_STATE, "pattern");
    assert_int_equal(errs.calls, 3);
    /* nothing changed: the factorisation of A still solves */
    assert_ok(ctx, mfree_suitesparse_solve(s, 1, b, 4, x, 4));
    for (int i = 0; i < 4; ++i) assert_true(fabs(x[i] - xtrue[i]) < 1e-13);
    /* setup with the new pattern, then update with it, works */
    assert_ok(ctx, mfree_suitesparse_setup(s, C));
    assert_ok(ctx, mfree_suitesparse_update(s, C));
    assert_error(ctx, mfree_suitesparse_update(s, A), MFREE_ERR_STATE, "pattern");
    mfree_suitesparse_destroy(&s);
  }
  mfree_matrix_destroy(&A);
  mfree_matrix_destroy(&B);
  mfree_matrix_destroy(&C);
  mfree_context_destroy(&ctx);
}

/* A singular setup keeps the analysis: update with good values of that pattern works.
 * Pattern: tridiagonal 3 x 3; singular values zero the last row and column (stored
 * zeros, symmetric, so CHOLMOD takes them too). */
static void update_after_singular_setup(void **state) {
  (void)state;
  mfree_context_t *ctx = NULL;
  assert_ok(NULL, mfree_context_create(&ctx));
  const int keep[9] = {1, 1, 0, 1, 1, 1, 0, 1, 1};
  const double good[9] = {2, 1, 0, 1, 2, 1, 0, 1, 2};
  const double sing[9] = {2, 1, 0, 1, 2, 0, 0, 0, 0};
  mfree_matrix_t *S = ss_dense(ctx, 3, sing, keep);
  mfree_matrix_t *G = ss_dense(ctx, 3, good, keep);
  for (int k = 0; k < 3; ++k) {
    mfree_suitesparse_t *s = NULL;
    assert_ok(ctx, mfree_suitesparse_create(ctx, ss_kinds[k], &s));
    assert_error(ctx, mfree_suitesparse_setup(s, S), MFREE_FAIL_SINGULAR, NULL);
    double b[3] = {3, 4, 3}, x[3];
    assert_error(ctx, mfree_suitesparse_solve(s, 1, b, 3, x, 3), MFREE_ERR_STATE, "failed");
    double rcond = 1.0;
    assert_ok(ctx, mfree_suitesparse_get_info(s, &rcond, NULL, NULL));
    assert_true(rcond == 0.0);
    assert_ok(ctx, mfree_suitesparse_update(s, G));
    assert_ok(ctx, mfree_suitesparse_solve(s, 1, b, 3, x, 3));
    for (int i = 0; i < 3; ++i) assert_true(fabs(x[i] - 1.0) < 1e-14 * 8);
    /* a singular update makes solve refuse again, until the next good update */
    assert_error(ctx, mfree_suitesparse_update(s, S), MFREE_FAIL_SINGULAR, NULL);
    assert_error(ctx, mfree_suitesparse_solve(s, 1, b, 3, x, 3), MFREE_ERR_STATE, NULL);
    assert_ok(ctx, mfree_suitesparse_update(s, G));
    assert_ok(ctx, mfree_suitesparse_solve(s, 1, b, 3, x, 3));
    for (int i = 0; i < 3; ++i) assert_true(fabs(x[i] - 1.0) < 1e-14 * 8);
    mfree_suitesparse_destroy(&s);
  }
  mfree_matrix_destroy(&S);
  mfree_matrix_destroy(&G);
  mfree_context_destroy(&ctx);
}

/* KLU's refactor reuses the old pivots; when the new values zero one of them (or make
 * it tiny) update must pivot afresh and still succeed. UMFPACK re-pivots anyway. */
static void refactor_with_bad_old_pivots(void **state) {
  (void)state;
  mfree_context_t *ctx = NULL;
  assert_ok(NULL, mfree_context_create(&ctx));
  const int keep[9] = {1, 1, 1, 1, 1, 1, 1, 1, 1};
  const double first[9] = {10, 1, 2, 1, 10, 3, 2, 1, 10}; /* diagonal pivots */
  const double zero_pivot[9] = {0, 1, 2, 1, 0, 3, 2, 1, 1};
  const double tiny_pivot[9] = {1e-15, 1, 2, 1, 1e-15, 3, 2, 1, 1};
  const double *next[2] = {zero_pivot, tiny_pivot};
  for (int k = 1; k < 3; ++k) {
    mfree_matrix_t *A = ss_dense(ctx, 3, first, keep);
    mfree_suitesparse_t *s = NULL;
    assert_ok(ctx, mfree_suitesparse_create(ctx, ss_kinds[k], &s));
    for (int v = 0; v < 2; ++v) {
      assert_ok(ctx, mfree_suitesparse_setup(s, A)); /* pivots chosen on `first` */
      mfree_matrix_t *B = ss_dense(ctx, 3, next[v], keep);
      double xtrue[3], b[3], x[3];
      ss_make_rhs(B, 1, xtrue, b, 3);
      assert_ok(ctx, mfree_suitesparse_update(s, B));
      assert_ok(ctx, mfree_suitesparse_solve(s, 1, b, 3, x, 3));
      const double err = ss_rel_error(3, 1, x, 3, xtrue);
      if (!(err < 1e-13)) fail_msg("solver %d, values %d: relative error %.3e", (int)ss_kinds[k], v, err);
      double rcond = 0.0;
      assert_ok(ctx, mfree_suitesparse_get_info(s, &rcond, NULL, NULL));
      assert_true(rcond > 1e-3); /* fresh pivots are good ones */
      mfree_matrix_destroy(&B);
    }
    mfree_suitesparse_destroy(&s);
    mfree_matrix_destroy(&A);
  }
  mfree_context_destroy(&ctx);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(repeated_updates),
      cmocka_unit_test(pattern_change_needs_setup),
      cmocka_unit_test(update_after_singular_setup),
      cmocka_unit_test(refactor_with_bad_old_pivots),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
