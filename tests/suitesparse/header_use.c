/* Compiled with -fsyntax-only as strict C99 (t890) and as C++11 (t891): the adapter's
 * header must be clean in both, every warning an error, and its declarations usable. */
#include <mfree_suitesparse.h>

typedef char mfree_ss_check_kinds[(MFREE_SOLVER_CHOLMOD == 1 && MFREE_SOLVER_UMFPACK == 2 &&
                                   MFREE_SOLVER_KLU == 3) ? 1 : -1];

int header_use(const mfree_matrix_t *A);
int header_use(const mfree_matrix_t *A) {
  mfree_context_t *ctx = 0;
  mfree_suitesparse_t *s = 0;
  double b[1] = {1.0}, x[1], rcond = 0.0;
  int64_t fnnz = 0;
  int32_t width = 0;
  mfree_status_t st = mfree_context_create(&ctx);
  if (st == MFREE_SUCCESS) st = mfree_suitesparse_create(ctx, MFREE_SOLVER_KLU, &s);
  if (st == MFREE_SUCCESS) st = mfree_suitesparse_set_index_width(s, 0);
  if (st == MFREE_SUCCESS) st = mfree_suitesparse_setup(s, A);
  if (st == MFREE_SUCCESS) st = mfree_suitesparse_update(s, A);
  if (st == MFREE_SUCCESS) st = mfree_suitesparse_solve(s, 1, b, 1, x, 1);
  if (st == MFREE_SUCCESS) st = mfree_suitesparse_get_info(s, &rcond, &fnnz, &width);
  mfree_suitesparse_destroy(&s);
  mfree_context_destroy(&ctx);
  return (int)st;
}
