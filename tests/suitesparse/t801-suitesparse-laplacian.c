/* t801: each solver on the SPD 2D 5-point Laplacian (a), several right-hand sides with
 * padded leading dimensions (d), an in-place solve, factor statistics, and the empty
 * matrix. Exact solutions: b = A x_true through mfree_matrix_apply. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sstest.h"

enum { M = 24, N = M * M };

static void laplacian_single_rhs(void **state) {
  (void)state;
  mfree_context_t *ctx = NULL;
  assert_ok(NULL, mfree_context_create(&ctx));
  mfree_matrix_t *A = ss_laplacian(ctx, M);
  double xtrue[N], b[N], x[N];
  ss_make_rhs(A, 1, xtrue, b, N);
  for (int k = 0; k < 3; ++k) {
    mfree_suitesparse_t *s = NULL;
    assert_ok(ctx, mfree_suitesparse_create(ctx, ss_kinds[k], &s));
    assert_ok(ctx, mfree_suitesparse_setup(s, A));
    memset(x, 0, sizeof x);
    assert_ok(ctx, mfree_suitesparse_solve(s, 1, b, N, x, N));
    const double err = ss_rel_error(N, 1, x, N, xtrue);
    if (!(err < 1e-12)) fail_msg("solver %d: relative error %.3e", (int)ss_kinds[k], err);

    double rcond = -1.0;
    int64_t fnnz = -1;
    int32_t width = -1;
    assert_ok(ctx, mfree_suitesparse_get_info(s, &rcond, &fnnz, &width));
    assert_int_equal(width, 32); /* automatic: nnz fits int */
    assert_true(rcond > 0.0 && rcond <= 1.0);
    int64_t annz = 0;
    assert_ok(ctx, mfree_matrix_get_size(A, NULL, NULL, &annz));
    /* the factors hold at least one triangle of A (CHOLMOD: L only) */
    assert_true(fnnz >= (annz + N) / 2);
    assert_ok(ctx, mfree_suitesparse_get_info(s, NULL, NULL, NULL));
    assert_ok(ctx, mfree_suitesparse_destroy(&s));
    assert_null(s);
  }
  mfree_matrix_destroy(&A);
  mfree_context_destroy(&ctx);
}

/* nrhs = 3 with ldb = N + 2 and ldx = N + 5: every column right, padding untouched. */
static void laplacian_multiple_rhs(void **state) {
  (void)state;
  enum { NRHS = 3, LDB = N + 2, LDX = N + 5 };
  mfree_context_t *ctx = NULL;
  assert_ok(NULL, mfree_context_create(&ctx));
  mfree_matrix_t *A = ss_laplacian(ctx, M);
  double *xtrue = malloc(sizeof(double) * N * NRHS);
  double *b = malloc(sizeof(double) * LDB * NRHS);
  double *bcopy = malloc(sizeof(double) * LDB * NRHS);
  double *x = malloc(sizeof(double) * LDX * NRHS);
  assert_non_null(xtrue);
  assert_non_null(b);
  assert_non_null(bcopy);
  assert_non_null(x);
  for (int i = 0; i < LDB * NRHS; ++i) b[i] = -7.0; /* padding sentinel */
  ss_make_rhs(A, NRHS, xtrue, b, LDB);
  memcpy(bcopy, b, sizeof(double) * LDB * NRHS);
  for (int k = 0; k < 3; ++k) {
    mfree_suitesparse_t *s = NULL;
    assert_ok(ctx, mfree_suitesparse_create(ctx, ss_kinds[k], &s));
    assert_ok(ctx, mfree_suitesparse_setup(s, A));
    for (int i = 0; i < LDX * NRHS; ++i) x[i] = 99.0;
    assert_ok(ctx, mfree_suitesparse_solve(s, NRHS, b, LDB, x, LDX));
    const double err = ss_rel_error(N, NRHS, x, LDX, xtrue);
    if (!(err < 1e-12)) fail_msg("solver %d: relative error %.3e", (int)ss_kinds[k], err);
    for (int j = 0; j < NRHS; ++j)
      for (int i = N; i < LDX; ++i) assert_true(x[j * LDX + i] == 99.0);
    assert_memory_equal(b, bcopy, sizeof(double) * LDB * NRHS); /* b is not modified */

    /* each column solved alone gives the same numbers */
    double single[N];
    for (int j = 0; j < NRHS; ++j) {
      assert_ok(ctx, mfree_suitesparse_solve(s, 1, b + j * LDB, N, single, N));
      for (int i = 0; i < N; ++i) assert_true(fabs(single[i] - x[j * LDX + i]) <= 1e-13);
    }

    /* in place: b == x with ldb == ldx */
    double *inplace = malloc(sizeof(double) * LDB * NRHS);
    assert_non_null(inplace);
    memcpy(inplace, b, sizeof(double) * LDB * NRHS);
    assert_ok(ctx, mfree_suitesparse_solve(s, NRHS, inplace, LDB, inplace, LDB));
    const double err2 = ss_rel_error(N, NRHS, inplace, LDB, xtrue);
    if (!(err2 < 1e-12)) fail_msg("solver %d in place: relative error %.3e", (int)ss_kinds[k], err2);
    free(inplace);

    /* nrhs = 0 does nothing, with or without arrays */
    assert_ok(ctx, mfree_suitesparse_solve(s, 0, NULL, N, NULL, N));
    mfree_suitesparse_destroy(&s);
  }
  free(xtrue);
  free(b);
  free(bcopy);
  free(x);
  mfree_matrix_destroy(&A);
  mfree_context_destroy(&ctx);
}

/* The solver keeps no pointer into A: destroy the matrix, then solve. And the solver
 * keeps its context alive: destroy the context first, then use and destroy the solver. */
static void lifetimes(void **state) {
  (void)state;
  for (int k = 0; k < 3; ++k) {
    mfree_context_t *ctx = NULL;
    assert_ok(NULL, mfree_context_create(&ctx));
    mfree_matrix_t *A = ss_laplacian(ctx, 8);
    double xtrue[64], b[64], x[64];
    ss_make_rhs(A, 1, xtrue, b, 64);
    mfree_suitesparse_t *s = NULL;
    assert_ok(ctx, mfree_suitesparse_create(ctx, ss_kinds[k], &s));
    assert_ok(ctx, mfree_suitesparse_setup(s, A));
    mfree_matrix_destroy(&A);
    mfree_context_destroy(&ctx);
    assert_int_equal(mfree_suitesparse_solve(s, 1, b, 64, x, 64), MFREE_SUCCESS);
    assert_true(ss_rel_error(64, 1, x, 64, xtrue) < 1e-12);
    /* an error is still recorded on the (kept) context without a crash */
    assert_int_equal(mfree_suitesparse_solve(s, 1, b, 3, x, 64), MFREE_ERR_ARG);
    mfree_suitesparse_destroy(&s);
  }
}

/* A 0 x 0 matrix: setup succeeds, solve does nothing. */
static void empty_matrix(void **state) {
  (void)state;
  mfree_context_t *ctx = NULL;
  assert_ok(NULL, mfree_context_create(&ctx));
  const int64_t rowptr[1] = {0};
  mfree_matrix_t *A = NULL;
  assert_ok(ctx, mfree_matrix_create_csr(ctx, 0, 0, rowptr, NULL, NULL, &A));
  for (int k = 0; k < 3; ++k) {
    mfree_suitesparse_t *s = NULL;
    assert_ok(ctx, mfree_suitesparse_create(ctx, ss_kinds[k], &s));
    assert_ok(ctx, mfree_suitesparse_setup(s, A));
    double b = 1.0, x = 2.0;
    assert_ok(ctx, mfree_suitesparse_solve(s, 1, &b, 1, &x, 1));
    assert_true(x == 2.0);
    assert_ok(ctx, mfree_suitesparse_update(s, A));
    int64_t fnnz = -1;
    assert_ok(ctx, mfree_suitesparse_get_info(s, NULL, &fnnz, NULL));
    assert_int_equal(fnnz, 0);
    mfree_suitesparse_destroy(&s);
  }
  mfree_matrix_destroy(&A);
  mfree_context_destroy(&ctx);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(laplacian_single_rhs),
      cmocka_unit_test(laplacian_multiple_rhs),
      cmocka_unit_test(lifetimes),
      cmocka_unit_test(empty_matrix),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
