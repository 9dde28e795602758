/* A host program of the installed libmfree_suitesparse: solve the 1D Laplacian
 * tridiag(-1, 2, -1) x = b with each solver; prints "<solver>: ok" lines. */
#include <math.h>
#include <stdio.h>

#include <mfree_suitesparse.h>

enum { N = 50 };

int main(void) {
  int64_t rowptr[N + 1];
  int32_t cols[3 * N];
  double vals[3 * N], xtrue[N], b[N], x[N];
  int64_t k = 0;
  rowptr[0] = 0;
  for (int i = 0; i < N; ++i) {
    if (i > 0) { cols[k] = i - 1; vals[k++] = -1.0; }
    cols[k] = i; vals[k++] = 2.0;
    if (i < N - 1) { cols[k] = i + 1; vals[k++] = -1.0; }
    rowptr[i + 1] = k;
    xtrue[i] = 1.0 + 0.5 * i;
  }
  mfree_context_t *ctx = NULL;
  mfree_matrix_t *A = NULL;
  int failures = 0;
  if (mfree_context_create(&ctx) || mfree_matrix_create_csr(ctx, N, N, rowptr, cols, vals, &A) ||
      mfree_matrix_apply(A, xtrue, b))
    return 1;
  const mfree_solver_kind_t kinds[3] = {MFREE_SOLVER_CHOLMOD, MFREE_SOLVER_UMFPACK,
                                        MFREE_SOLVER_KLU};
  const char *names[3] = {"cholmod", "umfpack", "klu"};
  for (int s = 0; s < 3; ++s) {
    mfree_suitesparse_t *solver = NULL;
    mfree_status_t st = mfree_suitesparse_create(ctx, kinds[s], &solver);
    if (!st) st = mfree_suitesparse_setup(solver, A);
    if (!st) st = mfree_suitesparse_solve(solver, 1, b, N, x, N);
    double err = 0.0;
    for (int i = 0; !st && i < N; ++i) err = fmax(err, fabs(x[i] - xtrue[i]) / fabs(xtrue[i]));
    if (st || !(err < 1e-10)) {
      char msg[256] = "";
      mfree_context_get_last_error(ctx, NULL, msg, sizeof msg);
      fprintf(stderr, "%s: status %d, error %g: %s\n", names[s], (int)st, err, msg);
      ++failures;
    } else {
      printf("%s: ok\n", names[s]);
    }
    mfree_suitesparse_destroy(&solver);
  }
  mfree_matrix_destroy(&A);
  mfree_context_destroy(&ctx);
  return failures != 0;
}
