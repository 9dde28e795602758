/* t804: singular matrices (f). A structurally empty row, a row of stored zeros, and a
 * symmetric matrix that looks SPD (positive diagonal, symmetric) but is indefinite:
 * MFREE_FAIL_SINGULAR, a message naming the solver, exactly one call of the context's
 * error handler, and nothing written to stdout or stderr. The solver stays usable. */
#include <math.h>
#include <string.h>

#include "sstest.h"

enum { M = 12, N = M * M };

static const char *name_of(mfree_solver_kind_t k) {
  return k == MFREE_SOLVER_CHOLMOD ? "CHOLMOD" : k == MFREE_SOLVER_UMFPACK ? "UMFPACK" : "KLU";
}

/* Laplacian with row `r` (and, if sym, column `r`) removed from the pattern
 * (stored = 0) or kept as stored zeros (stored = 1). */
static mfree_matrix_t *zero_row(mfree_context_t *ctx, int32_t r, int sym, int stored) {
  mfree_matrix_t *L = ss_laplacian(ctx, M);
  const int64_t *rp = NULL;
  const int32_t *ci = NULL;
  const double *v = NULL;
  assert_ok(ctx, mfree_matrix_get_csr(L, &rp, &ci, &v));
  int64_t rowptr[N + 1];
  int32_t cols[5 * N];
  double vals[5 * N];
  int64_t k = 0;
  rowptr[0] = 0;
  for (int32_t i = 0; i < N; ++i) {
    for (int64_t p = rp[i]; p < rp[i + 1]; ++p) {
      const int zero = i == r || (sym && ci[p] == r);
      if (zero && !stored) continue;
      cols[k] = ci[p];
      vals[k++] = zero ? 0.0 : v[p];
    }
    rowptr[i + 1] = k;
  }
  mfree_matrix_t *A = NULL;
  assert_ok(ctx, mfree_matrix_create_csr(ctx, N, N, rowptr, cols, vals, &A));
  mfree_matrix_destroy(&L);
  return A;
}

static void expect_singular_quietly(mfree_context_t *ctx, ss_errors_t *errs,
                                    mfree_suitesparse_t *s, const mfree_matrix_t *A,
                                    mfree_solver_kind_t kind, const char *what) {
  errs->calls = 0;
  ss_quiet_t q;
  ss_quiet_begin(&q);
  const mfree_status_t st = mfree_suitesparse_setup(s, A);
  const long printed = ss_quiet_end(&q);
  if (st != MFREE_FAIL_SINGULAR)
    fail_msg("%s, %s: setup returned %d, expected MFREE_FAIL_SINGULAR", name_of(kind), what, (int)st);
  if (printed != 0) fail_msg("%s, %s: %ld bytes printed", name_of(kind), what, printed);
  assert_int_equal(errs->calls, 1);
  assert_int_equal(errs->last_code, MFREE_FAIL_SINGULAR);
  if (!strstr(errs->last_message, name_of(kind)))
    fail_msg("%s, %s: message \"%s\" does not name the solver", name_of(kind), what, errs->last_message);
  assert_non_null(strstr(errs->last_message, "mfree_suitesparse_setup"));
  assert_error(ctx, st, MFREE_FAIL_SINGULAR, name_of(kind));
}

static void zero_rows(void **state) {
  (void)state;
  mfree_context_t *ctx = NULL;
  assert_ok(NULL, mfree_context_create(&ctx));
  ss_errors_t errs;
  ss_capture_errors(ctx, &errs);
  mfree_matrix_t *L = ss_laplacian(ctx, M);
  double xtrue[N], b[N], x[N];
  ss_make_rhs(L, 1, xtrue, b, N);
  for (int k = 0; k < 3; ++k) {
    const mfree_solver_kind_t kind = ss_kinds[k];
    const int sym = kind == MFREE_SOLVER_CHOLMOD; /* CHOLMOD takes symmetric input only */
    for (int stored = 0; stored < 2; ++stored) {
      for (int width = 32; width <= 64; width += 32) {
        mfree_suitesparse_t *s = NULL;
        assert_ok(ctx, mfree_suitesparse_create(ctx, kind, &s));
        assert_ok(ctx, mfree_suitesparse_set_index_width(s, width));
        mfree_matrix_t *A = zero_row(ctx, N / 2 + 3, sym, stored);
        expect_singular_quietly(ctx, &errs, s, A, kind,
                                stored ? "row of stored zeros" : "structurally empty row");
        /* solve refuses; the object stays usable */
        assert_error(ctx, mfree_suitesparse_solve(s, 1, b, N, x, N), MFREE_ERR_STATE, name_of(kind));
        assert_ok(ctx, mfree_suitesparse_setup(s, L));
        assert_ok(ctx, mfree_suitesparse_solve(s, 1, b, N, x, N));
        assert_true(ss_rel_error(N, 1, x, N, xtrue) < 1e-12);
        mfree_matrix_destroy(&A);
        mfree_suitesparse_destroy(&s);
      }
    }
  }
  mfree_matrix_destroy(&L);
  mfree_context_destroy(&ctx);
}

/* Symmetric, positive diagonal, diagonally "almost" dominant, yet indefinite. CHOLMOD
 * must say not positive definite; also a rank-one-deficient symmetric matrix with a
 * positive diagonal, which every solver must call singular. */
static void spd_looking(void **state) {
  (void)state;
  mfree_context_t *ctx = NULL;
  assert_ok(NULL, mfree_context_create(&ctx));
  ss_errors_t errs;
  ss_capture_errors(ctx, &errs);
  /* eigenvalues of [[1,2,0],[2,1,0],[0,0,3]]: -1, 3, 3 */
  const double indef[9] = {1, 2, 0, 2, 1, 0, 0, 0, 3};
  /* [[1,1,0],[1,1,0],[0,0,2]]: eigenvalues 0, 2, 2 (exactly singular, PSD) */
  const double psd[9] = {1, 1, 0, 1, 1, 0, 0, 0, 2};
  mfree_matrix_t *I3 = ss_dense(ctx, 3, indef, NULL);
  mfree_matrix_t *P3 = ss_dense(ctx, 3, psd, NULL);
  mfree_matrix_t *Big = ss_stencil(ctx, M, 3.0, -1.0, -1.0, -1.0, -1.0); /* min eig < 0 */
  for (int k = 0; k < 3; ++k) {
    mfree_suitesparse_t *s = NULL;
    assert_ok(ctx, mfree_suitesparse_create(ctx, ss_kinds[k], &s));
    if (ss_kinds[k] == MFREE_SOLVER_CHOLMOD) {
      expect_singular_quietly(ctx, &errs, s, I3, ss_kinds[k], "indefinite 3 x 3");
      assert_non_null(strstr(errs.last_message, "positive definite"));
      expect_singular_quietly(ctx, &errs, s, Big, ss_kinds[k], "indefinite stencil");
    } else {
      assert_ok(ctx, mfree_suitesparse_setup(s, I3));
    }
    expect_singular_quietly(ctx, &errs, s, P3, ss_kinds[k], "semidefinite 3 x 3");
    mfree_suitesparse_destroy(&s);
  }
  mfree_matrix_destroy(&I3);
  mfree_matrix_destroy(&P3);
  mfree_matrix_destroy(&Big);
  mfree_context_destroy(&ctx);
}

/* A matrix without a single stored entry (every row empty) is singular for all. */
static void no_entries(void **state) {
  (void)state;
  mfree_context_t *ctx = NULL;
  assert_ok(NULL, mfree_context_create(&ctx));
  ss_errors_t errs;
  ss_capture_errors(ctx, &errs);
  const int64_t rowptr[4] = {0, 0, 0, 0};
  mfree_matrix_t *Z = NULL;
  assert_ok(ctx, mfree_matrix_create_csr(ctx, 3, 3, rowptr, NULL, NULL, &Z));
  for (int k = 0; k < 3; ++k)
    for (int width = 32; width <= 64; width += 32) {
      mfree_suitesparse_t *s = NULL;
      assert_ok(ctx, mfree_suitesparse_create(ctx, ss_kinds[k], &s));
      assert_ok(ctx, mfree_suitesparse_set_index_width(s, width));
      expect_singular_quietly(ctx, &errs, s, Z, ss_kinds[k], "no entries");
      mfree_suitesparse_destroy(&s);
    }
  mfree_matrix_destroy(&Z);
  mfree_context_destroy(&ctx);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(zero_rows),
      cmocka_unit_test(spd_looking),
      cmocka_unit_test(no_entries),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
