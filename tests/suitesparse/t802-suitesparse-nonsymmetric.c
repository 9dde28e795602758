/* t802: a nonsymmetric convection-diffusion matrix (b). UMFPACK and KLU solve it (the
 * CSR arrays are factored as A^T and solved transposed, so a wrong transpose would show
 * here and not on symmetric matrices); CHOLMOD refuses it with MFREE_ERR_MISMATCH and a
 * message, and stays usable. Also an indefinite symmetric matrix, which the LU solvers
 * handle and CHOLMOD reports as not positive definite. */
#include <math.h>
#include <string.h>

#include "sstest.h"

enum { M = 20, N = M * M };

static void lu_solvers_solve_convection(void **state) {
  (void)state;
  mfree_context_t *ctx = NULL;
  assert_ok(NULL, mfree_context_create(&ctx));
  const double peclet[3][2] = {{0.3, 0.1}, {0.9, -0.6}, {2.5, 1.5}};
  for (int p = 0; p < 3; ++p) {
    mfree_matrix_t *A = ss_convection(ctx, M, peclet[p][0], peclet[p][1]);
    int32_t sym = 1;
    assert_ok(ctx, mfree_matrix_get_symmetric(A, &sym));
    assert_int_equal(sym, 0);
    double xtrue[2 * N], b[2 * N], x[2 * N];
    ss_make_rhs(A, 2, xtrue, b, N);
    for (int k = 1; k < 3; ++k) { /* UMFPACK, KLU */
      mfree_suitesparse_t *s = NULL;
      assert_ok(ctx, mfree_suitesparse_create(ctx, ss_kinds[k], &s));
      assert_ok(ctx, mfree_suitesparse_setup(s, A));
      assert_ok(ctx, mfree_suitesparse_solve(s, 2, b, N, x, N));
      const double err = ss_rel_error(N, 2, x, N, xtrue);
      if (!(err < 1e-12))
        fail_msg("solver %d, Peclet (%g, %g): relative error %.3e", (int)ss_kinds[k],
                 peclet[p][0], peclet[p][1], err);
      mfree_suitesparse_destroy(&s);
    }
    mfree_matrix_destroy(&A);
  }
  mfree_context_destroy(&ctx);
}

/* A^T x = b differs from A x = b: a solver that forgot the transpose fails this. */
static void transpose_is_handled(void **state) {
  (void)state;
  mfree_context_t *ctx = NULL;
  assert_ok(NULL, mfree_context_create(&ctx));
  const double a[9] = {4, 1, 0,  /* strongly nonsymmetric 3 x 3 */
                       -3, 5, 2,
                       0, -7, 6};
  mfree_matrix_t *A = ss_dense(ctx, 3, a, NULL);
  const double xtrue[3] = {1, -2, 3};
  double b[3];
  for (int i = 0; i < 3; ++i) b[i] = a[3 * i] * xtrue[0] + a[3 * i + 1] * xtrue[1] + a[3 * i + 2] * xtrue[2];
  for (int k = 1; k < 3; ++k) {
    mfree_suitesparse_t *s = NULL;
    double x[3] = {0, 0, 0};
    assert_ok(ctx, mfree_suitesparse_create(ctx, ss_kinds[k], &s));
    assert_ok(ctx, mfree_suitesparse_setup(s, A));
    assert_ok(ctx, mfree_suitesparse_solve(s, 1, b, 3, x, 3));
    for (int i = 0; i < 3; ++i) assert_true(fabs(x[i] - xtrue[i]) < 1e-14 * 8);
    mfree_suitesparse_destroy(&s);
  }
  mfree_matrix_destroy(&A);
  mfree_context_destroy(&ctx);
}

static void cholmod_refuses_nonsymmetric(void **state) {
  (void)state;
  mfree_context_t *ctx = NULL;
  assert_ok(NULL, mfree_context_create(&ctx));
  ss_errors_t errs;
  ss_capture_errors(ctx, &errs);
  mfree_matrix_t *C = ss_convection(ctx, M, 0.5, 0.25);
  mfree_matrix_t *L = ss_laplacian(ctx, M);
  mfree_suitesparse_t *s = NULL;
  assert_ok(ctx, mfree_suitesparse_create(ctx, MFREE_SOLVER_CHOLMOD, &s));
  ss_quiet_t q;
  ss_quiet_begin(&q);
  const mfree_status_t st = mfree_suitesparse_setup(s, C);
  const long printed = ss_quiet_end(&q);
  assert_error(ctx, st, MFREE_ERR_MISMATCH, "symmetric");
  assert_int_equal(printed, 0);
  assert_int_equal(errs.calls, 1);
  assert_non_null(strstr(errs.last_message, "CHOLMOD"));
  double b[N], x[N];
  memset(b, 0, sizeof b);
  assert_error(ctx, mfree_suitesparse_solve(s, 1, b, N, x, N), MFREE_ERR_STATE, "setup");

  /* still usable: the Laplacian works afterwards */
  double xtrue[N];
  ss_make_rhs(L, 1, xtrue, b, N);
  assert_ok(ctx, mfree_suitesparse_setup(s, L));
  assert_ok(ctx, mfree_suitesparse_solve(s, 1, b, N, x, N));
  assert_true(ss_rel_error(N, 1, x, N, xtrue) < 1e-12);
  /* a MISMATCH changes nothing: the Laplacian factorisation survives a refused setup */
  assert_error(ctx, mfree_suitesparse_setup(s, C), MFREE_ERR_MISMATCH, "UMFPACK");
  assert_ok(ctx, mfree_suitesparse_solve(s, 1, b, N, x, N));
  assert_true(ss_rel_error(N, 1, x, N, xtrue) < 1e-12);
  /* and update refuses the nonsymmetric values of a symmetric pattern */
  assert_error(ctx, mfree_suitesparse_update(s, C), MFREE_ERR_MISMATCH, "symmetric");

  mfree_suitesparse_destroy(&s);
  mfree_matrix_destroy(&C);
  mfree_matrix_destroy(&L);
  mfree_context_destroy(&ctx);
}

/* Symmetric indefinite (diagonal 2 instead of 4: eigenvalues from -2 to 6, none zero for
 * m = 10): UMFPACK and KLU solve it, CHOLMOD says not positive definite. */
static void indefinite_symmetric(void **state) {
  (void)state;
  enum { m = 10, n = m * m };
  mfree_context_t *ctx = NULL;
  assert_ok(NULL, mfree_context_create(&ctx));
  mfree_matrix_t *A = ss_stencil(ctx, m, 2.0, -1.0, -1.0, -1.0, -1.0);
  double xtrue[n], b[n], x[n];
  ss_make_rhs(A, 1, xtrue, b, n);
  for (int k = 0; k < 3; ++k) {
    mfree_suitesparse_t *s = NULL;
    assert_ok(ctx, mfree_suitesparse_create(ctx, ss_kinds[k], &s));
    if (ss_kinds[k] == MFREE_SOLVER_CHOLMOD) {
      assert_error(ctx, mfree_suitesparse_setup(s, A), MFREE_FAIL_SINGULAR, "CHOLMOD");
    } else {
      assert_ok(ctx, mfree_suitesparse_setup(s, A));
      assert_ok(ctx, mfree_suitesparse_solve(s, 1, b, n, x, n));
      assert_true(ss_rel_error(n, 1, x, n, xtrue) < 1e-12);
    }
    mfree_suitesparse_destroy(&s);
  }
  mfree_matrix_destroy(&A);
  mfree_context_destroy(&ctx);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(lu_solvers_solve_convection),
      cmocka_unit_test(transpose_is_handled),
      cmocka_unit_test(cholmod_refuses_nonsymmetric),
      cmocka_unit_test(indefinite_symmetric),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
