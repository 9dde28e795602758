/* t805: every NULL or bad argument (g) (the rcond threshold's too), the frozen
 * enumerator values, and the states
 * in which each call is refused. Each failure returns its status, leaves a message on
 * the context (when there is one to leave it on) and calls the handler once. */
#include <float.h>
#include <math.h>
#include <string.h>

#include "sstest.h"

static void enum_values(void **state) {
  (void)state;
  assert_int_equal(MFREE_SOLVER_CHOLMOD, 1);
  assert_int_equal(MFREE_SOLVER_UMFPACK, 2);
  assert_int_equal(MFREE_SOLVER_KLU, 3);
  assert_int_equal(sizeof(mfree_solver_kind_t), sizeof(int));
}

static void create_destroy(void **state) {
  (void)state;
  mfree_context_t *ctx = NULL;
  assert_ok(NULL, mfree_context_create(&ctx));
  ss_errors_t errs;
  ss_capture_errors(ctx, &errs);
  mfree_suitesparse_t *s = (mfree_suitesparse_t *)&errs; /* must be overwritten */

  assert_int_equal(mfree_suitesparse_create(NULL, MFREE_SOLVER_KLU, &s), MFREE_ERR_NULL);
  assert_error(ctx, mfree_suitesparse_create(ctx, MFREE_SOLVER_KLU, NULL), MFREE_ERR_NULL, "NULL");
  assert_error(ctx, mfree_suitesparse_create(ctx, (mfree_solver_kind_t)0, &s), MFREE_ERR_ARG, "kind");
  assert_null(s);
  s = (mfree_suitesparse_t *)&errs;
  assert_error(ctx, mfree_suitesparse_create(ctx, (mfree_solver_kind_t)4, &s), MFREE_ERR_ARG, "4");
  assert_null(s);
  assert_error(ctx, mfree_suitesparse_create(ctx, (mfree_solver_kind_t)-1, &s), MFREE_ERR_ARG, "kind");
  assert_int_equal(errs.calls, 4);

  assert_int_equal(mfree_suitesparse_destroy(NULL), MFREE_SUCCESS);
  s = NULL;
  assert_int_equal(mfree_suitesparse_destroy(&s), MFREE_SUCCESS);
  for (int k = 0; k < 3; ++k) {
    assert_ok(ctx, mfree_suitesparse_create(ctx, ss_kinds[k], &s));
    assert_non_null(s);
    assert_ok(ctx, mfree_suitesparse_destroy(&s));
    assert_null(s);
  }
  mfree_context_destroy(&ctx);
}

static void bad_arguments(void **state) {
  (void)state;
  enum { m = 5, n = m * m };
  mfree_context_t *ctx = NULL;
  assert_ok(NULL, mfree_context_create(&ctx));
  ss_errors_t errs;
  ss_capture_errors(ctx, &errs);
  mfree_matrix_t *A = ss_laplacian(ctx, m);
  /* a 2 x 3 matrix */
  const int64_t rp[3] = {0, 2, 3};
  const int32_t ci[3] = {0, 2, 1};
  const double cv[3] = {1, 2, 3};
  mfree_matrix_t *R = NULL;
  assert_ok(ctx, mfree_matrix_create_csr(ctx, 2, 3, rp, ci, cv, &R));
  double b[2 * n], x[2 * n];
  memset(b, 0, sizeof b);

  for (int k = 0; k < 3; ++k) {
    mfree_suitesparse_t *s = NULL;
    assert_ok(ctx, mfree_suitesparse_create(ctx, ss_kinds[k], &s));
    errs.calls = 0;

    /* NULL handle: nothing to record on */
    assert_int_equal(mfree_suitesparse_set_index_width(NULL, 0), MFREE_ERR_NULL);
    assert_int_equal(mfree_suitesparse_setup(NULL, A), MFREE_ERR_NULL);
    assert_int_equal(mfree_suitesparse_update(NULL, A), MFREE_ERR_NULL);
    assert_int_equal(mfree_suitesparse_solve(NULL, 1, b, n, x, n), MFREE_ERR_NULL);
    assert_int_equal(mfree_suitesparse_get_info(NULL, NULL, NULL, NULL), MFREE_ERR_NULL);
    assert_int_equal(mfree_suitesparse_set_rcond_threshold(NULL, 0.0), MFREE_ERR_NULL);
    assert_int_equal(errs.calls, 0);

    /* singularity threshold: [0, 1) */
    assert_error(ctx, mfree_suitesparse_set_rcond_threshold(s, -1e-12), MFREE_ERR_ARG, "threshold");
    assert_error(ctx, mfree_suitesparse_set_rcond_threshold(s, 1.0), MFREE_ERR_ARG, "[0, 1)");
    assert_error(ctx, mfree_suitesparse_set_rcond_threshold(s, NAN), MFREE_ERR_ARG, "threshold");
    assert_error(ctx, mfree_suitesparse_set_rcond_threshold(s, INFINITY), MFREE_ERR_ARG, "threshold");
    assert_ok(ctx, mfree_suitesparse_set_rcond_threshold(s, 0.0));
    assert_ok(ctx, mfree_suitesparse_set_rcond_threshold(s, 1e3 * DBL_EPSILON));

    /* index width */
    assert_error(ctx, mfree_suitesparse_set_index_width(s, 16), MFREE_ERR_ARG, "16");
    assert_error(ctx, mfree_suitesparse_set_index_width(s, -1), MFREE_ERR_ARG, "width");
    assert_error(ctx, mfree_suitesparse_set_index_width(s, 128), MFREE_ERR_ARG, "width");

    /* before setup */
    assert_error(ctx, mfree_suitesparse_solve(s, 1, b, n, x, n), MFREE_ERR_STATE, "setup");
    assert_error(ctx, mfree_suitesparse_update(s, A), MFREE_ERR_STATE, "setup");
    assert_error(ctx, mfree_suitesparse_get_info(s, NULL, NULL, NULL), MFREE_ERR_STATE, "setup");

    /* setup / update arguments */
    assert_error(ctx, mfree_suitesparse_setup(s, NULL), MFREE_ERR_NULL, "NULL");
    assert_error(ctx, mfree_suitesparse_setup(s, R), MFREE_ERR_MISMATCH, "square");
    assert_error(ctx, mfree_suitesparse_solve(s, 1, b, n, x, n), MFREE_ERR_STATE, NULL);
    assert_ok(ctx, mfree_suitesparse_setup(s, A));
    assert_error(ctx, mfree_suitesparse_update(s, NULL), MFREE_ERR_NULL, "NULL");
    assert_error(ctx, mfree_suitesparse_update(s, R), MFREE_ERR_STATE, "setup");
    assert_error(ctx, mfree_suitesparse_setup(s, R), MFREE_ERR_MISMATCH, "2 x 3");

    /* solve arguments (the factorisation of A is intact after all the above) */
    assert_error(ctx, mfree_suitesparse_solve(s, -1, b, n, x, n), MFREE_ERR_ARG, "nrhs");
    assert_error(ctx, mfree_suitesparse_solve(s, 1, NULL, n, x, n), MFREE_ERR_NULL, "b is NULL");
    assert_error(ctx, mfree_suitesparse_solve(s, 1, b, n, NULL, n), MFREE_ERR_NULL, "x is NULL");
    assert_error(ctx, mfree_suitesparse_solve(s, 1, b, n - 1, x, n), MFREE_ERR_ARG, "ldb");
    assert_error(ctx, mfree_suitesparse_solve(s, 1, b, n, x, n - 1), MFREE_ERR_ARG, "ldx");
    assert_error(ctx, mfree_suitesparse_solve(s, 1, b, 0, x, n), MFREE_ERR_ARG, "ldb");
    assert_error(ctx, mfree_suitesparse_solve(s, 2, b, -5, x, n), MFREE_ERR_ARG, "ldb");
    assert_error(ctx, mfree_suitesparse_solve(s, 2, x, n, x, n + 1), MFREE_ERR_ARG, "in-place");
    assert_ok(ctx, mfree_suitesparse_solve(s, 2, b, n, x, n));
    assert_ok(ctx, mfree_suitesparse_solve(s, 0, NULL, n, NULL, n)); /* nothing to do */

    /* get_info outputs are optional */
    int32_t w = 0;
    assert_ok(ctx, mfree_suitesparse_get_info(s, NULL, NULL, &w));
    assert_int_equal(w, 32);
    assert_int_equal(errs.calls, 24);
    mfree_suitesparse_destroy(&s);
  }
  mfree_matrix_destroy(&A);
  mfree_matrix_destroy(&R);
  mfree_context_destroy(&ctx);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(enum_values),
      cmocka_unit_test(create_destroy),
      cmocka_unit_test(bad_arguments),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
