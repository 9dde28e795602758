/* t806: index widths (e). Forced 32- and 64-bit SuiteSparse variants give identical
 * solutions for every solver (SPD and nonsymmetric matrices, setup and update), the
 * automatic choice takes 32 bits for a small matrix, and a width set after setup takes
 * effect at the next setup only.
 * A matrix with more than INT32_MAX entries cannot be allocated in a test, so the rule
 * that chooses the width is checked directly on its thresholds: the adapter's internal
 * mfree_ss_select_index_width (src/index_width.h), the function setup calls. */
#include <string.h>

#include "index_width.h"
#include "sstest.h"

enum { M = 18, N = M * M };

static void selection_rule(void **state) {
  (void)state;
  const int64_t fits = INT64_C(2147483647), too_big = fits + 1;
  int32_t bits = 0;
  assert_int_equal(mfree_ss_select_index_width(0, 0, &bits), MFREE_SUCCESS);
  assert_int_equal(bits, 32);
  assert_int_equal(mfree_ss_select_index_width(0, fits, &bits), MFREE_SUCCESS);
  assert_int_equal(bits, 32);
  assert_int_equal(mfree_ss_select_index_width(0, too_big, &bits), MFREE_SUCCESS);
  assert_int_equal(bits, 64);
  assert_int_equal(mfree_ss_select_index_width(0, INT64_MAX, &bits), MFREE_SUCCESS);
  assert_int_equal(bits, 64);
  assert_int_equal(mfree_ss_select_index_width(32, fits, &bits), MFREE_SUCCESS);
  assert_int_equal(bits, 32);
  bits = 0;
  assert_int_equal(mfree_ss_select_index_width(32, too_big, &bits), MFREE_ERR_UNSUPPORTED);
  assert_int_equal(bits, 0);
  assert_int_equal(mfree_ss_select_index_width(64, 5, &bits), MFREE_SUCCESS);
  assert_int_equal(bits, 64);
  assert_int_equal(mfree_ss_select_index_width(64, too_big, &bits), MFREE_SUCCESS);
  assert_int_equal(bits, 64);
  assert_int_equal(mfree_ss_select_index_width(16, 5, &bits), MFREE_ERR_ARG);
  assert_int_equal(mfree_ss_select_index_width(0, -1, &bits), MFREE_ERR_INPUT);
}

static void solve_with(mfree_context_t *ctx, mfree_solver_kind_t kind, int32_t width,
                       const mfree_matrix_t *A, const mfree_matrix_t *A2, const double *b,
                       double *x, double *x2) {
  mfree_suitesparse_t *s = NULL;
  assert_ok(ctx, mfree_suitesparse_create(ctx, kind, &s));
  assert_ok(ctx, mfree_suitesparse_set_index_width(s, width));
  assert_ok(ctx, mfree_suitesparse_setup(s, A));
  int32_t used = 0;
  assert_ok(ctx, mfree_suitesparse_get_info(s, NULL, NULL, &used));
  assert_int_equal(used, width == 0 ? 32 : width);
  assert_ok(ctx, mfree_suitesparse_solve(s, 2, b, N, x, N));
  assert_ok(ctx, mfree_suitesparse_update(s, A2));
  assert_ok(ctx, mfree_suitesparse_solve(s, 2, b, N, x2, N));
  mfree_suitesparse_destroy(&s);
}

static void forced_widths_agree(void **state) {
  (void)state;
  mfree_context_t *ctx = NULL;
  assert_ok(NULL, mfree_context_create(&ctx));
  for (int k = 0; k < 3; ++k) {
    const mfree_solver_kind_t kind = ss_kinds[k];
    const int sym = kind == MFREE_SOLVER_CHOLMOD;
    mfree_matrix_t *A = sym ? ss_laplacian(ctx, M) : ss_convection(ctx, M, 0.7, -0.4);
    mfree_matrix_t *A2 = sym ? ss_stencil(ctx, M, 5.0, -1.0, -1.0, -1.0, -1.0)
                             : ss_convection(ctx, M, -0.3, 0.9);
    double xtrue[2 * N], b[2 * N];
    ss_make_rhs(A, 2, xtrue, b, N);
    double x[3][2 * N], x2[3][2 * N];
    const int32_t widths[3] = {32, 64, 0};
    for (int w = 0; w < 3; ++w) solve_with(ctx, kind, widths[w], A, A2, b, x[w], x2[w]);
    assert_true(ss_rel_error(N, 2, x[0], N, xtrue) < 1e-12);
    /* identical: same orderings and pivots, only the integer type differs */
    assert_memory_equal(x[0], x[1], sizeof x[0]);
    assert_memory_equal(x[0], x[2], sizeof x[0]);
    assert_memory_equal(x2[0], x2[1], sizeof x2[0]);
    assert_memory_equal(x2[0], x2[2], sizeof x2[0]);
    mfree_matrix_destroy(&A);
    mfree_matrix_destroy(&A2);
  }
  mfree_context_destroy(&ctx);
}

/* set_index_width between setup and update does not touch the current factorisation;
 * the next setup switches. */
static void width_change_applies_at_setup(void **state) {
  (void)state;
  mfree_context_t *ctx = NULL;
  assert_ok(NULL, mfree_context_create(&ctx));
  mfree_matrix_t *A = ss_laplacian(ctx, 6);
  for (int k = 0; k < 3; ++k) {
    mfree_suitesparse_t *s = NULL;
    int32_t used = 0;
    assert_ok(ctx, mfree_suitesparse_create(ctx, ss_kinds[k], &s));
    assert_ok(ctx, mfree_suitesparse_setup(s, A));
    assert_ok(ctx, mfree_suitesparse_set_index_width(s, 64));
    assert_ok(ctx, mfree_suitesparse_update(s, A));
    assert_ok(ctx, mfree_suitesparse_get_info(s, NULL, NULL, &used));
    assert_int_equal(used, 32);
    assert_ok(ctx, mfree_suitesparse_setup(s, A));
    assert_ok(ctx, mfree_suitesparse_get_info(s, NULL, NULL, &used));
    assert_int_equal(used, 64);
    assert_ok(ctx, mfree_suitesparse_set_index_width(s, 32));
    assert_ok(ctx, mfree_suitesparse_setup(s, A));
    assert_ok(ctx, mfree_suitesparse_get_info(s, NULL, NULL, &used));
    assert_int_equal(used, 32);
    mfree_suitesparse_destroy(&s);
  }
  mfree_matrix_destroy(&A);
  mfree_context_destroy(&ctx);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(selection_rule),
      cmocka_unit_test(forced_widths_agree),
      cmocka_unit_test(width_change_applies_at_setup),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
