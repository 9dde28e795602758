#include "sstest.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

const mfree_solver_kind_t ss_kinds[3] = {MFREE_SOLVER_CHOLMOD, MFREE_SOLVER_UMFPACK,
                                         MFREE_SOLVER_KLU};

mfree_matrix_t *ss_stencil(mfree_context_t *ctx, int32_t m, double d, double w, double e,
                           double s, double nn) {
  const int32_t n = m * m;
  int64_t *rowptr = malloc(sizeof(int64_t) * (size_t)(n + 1));
  int32_t *cols = malloc(sizeof(int32_t) * (size_t)(5 * n));
  double *vals = malloc(sizeof(double) * (size_t)(5 * n));
  assert_non_null(rowptr);
  assert_non_null(cols);
  assert_non_null(vals);
  int64_t k = 0;
  rowptr[0] = 0;
  for (int32_t r = 0; r < n; ++r) {
    const int32_t i = r % m, j = r / m;
    if (j > 0) { cols[k] = r - m; vals[k++] = s; }
    if (i > 0) { cols[k] = r - 1; vals[k++] = w; }
    cols[k] = r; vals[k++] = d;
    if (i < m - 1) { cols[k] = r + 1; vals[k++] = e; }
    if (j < m - 1) { cols[k] = r + m; vals[k++] = nn; }
    rowptr[r + 1] = k;
  }
  mfree_matrix_t *A = NULL;
  assert_ok(ctx, mfree_matrix_create_csr(ctx, n, n, rowptr, cols, vals, &A));
  free(rowptr);
  free(cols);
  free(vals);
  return A;
}

mfree_matrix_t *ss_laplacian(mfree_context_t *ctx, int32_t m) {
  return ss_stencil(ctx, m, 4.0, -1.0, -1.0, -1.0, -1.0);
}

mfree_matrix_t *ss_convection(mfree_context_t *ctx, int32_t m, double px, double py) {
  return ss_stencil(ctx, m, 4.0, -1.0 - px, -1.0 + px, -1.0 - py, -1.0 + py);
}

mfree_matrix_t *ss_dense(mfree_context_t *ctx, int32_t n, const double *a, const int *keep) {
  int64_t *rowptr = malloc(sizeof(int64_t) * (size_t)(n + 1));
  int32_t *cols = malloc(sizeof(int32_t) * (size_t)(n * n + 1));
  double *vals = malloc(sizeof(double) * (size_t)(n * n + 1));
  assert_non_null(rowptr);
  assert_non_null(cols);
  assert_non_null(vals);
  int64_t k = 0;
  rowptr[0] = 0;
  for (int32_t i = 0; i < n; ++i) {
    for (int32_t j = 0; j < n; ++j) {
      const int32_t ij = i * n + j;
      if (keep ? keep[ij] != 0 : a[ij] != 0.0) {
        cols[k] = j;
        vals[k++] = a[ij];
      }
    }
    rowptr[i + 1] = k;
  }
  mfree_matrix_t *A = NULL;
  assert_ok(ctx, mfree_matrix_create_csr(ctx, n, n, rowptr, cols, vals, &A));
  free(rowptr);
  free(cols);
  free(vals);
  return A;
}

void ss_make_rhs(const mfree_matrix_t *A, int32_t nrhs, double *xtrue, double *b, int64_t ldb) {
  int32_t n = 0;
  assert_int_equal(mfree_matrix_get_size(A, &n, NULL, NULL), MFREE_SUCCESS);
  for (int32_t j = 0; j < nrhs; ++j) {
    for (int32_t i = 0; i < n; ++i) xtrue[(size_t)j * n + i] = 1.0 + sin(i + 7.0 * j);
    assert_int_equal(mfree_matrix_apply(A, xtrue + (size_t)j * n, b + j * ldb), MFREE_SUCCESS);
  }
}

double ss_rel_error(int32_t n, int32_t nrhs, const double *x, int64_t ldx, const double *xtrue) {
  double worst = 0.0;
  for (int32_t j = 0; j < nrhs; ++j) {
    double num = 0.0, den = 0.0;
    for (int32_t i = 0; i < n; ++i) {
      const double t = xtrue[(size_t)j * n + i], dlt = x[j * ldx + i] - t;
      num += dlt * dlt;
      den += t * t;
    }
    const double r = sqrt(num / den);
    if (!(r <= worst)) worst = r; /* NaN propagates */
  }
  return worst;
}

static void on_error(void *user, mfree_status_t code, const char *message) {
  ss_errors_t *e = user;
  e->calls++;
  e->last_code = code;
  snprintf(e->last_message, sizeof e->last_message, "%s", message ? message : "");
}

void ss_capture_errors(mfree_context_t *ctx, ss_errors_t *e) {
  memset(e, 0, sizeof *e);
  assert_int_equal(mfree_context_set_error_handler(ctx, on_error, e), MFREE_SUCCESS);
}

void ss_quiet_begin(ss_quiet_t *q) {
  char path[] = "/tmp/mfree-ss-quiet-XXXXXX";
  fflush(stdout);
  fflush(stderr);
  q->fd = mkstemp(path);
  assert_true(q->fd >= 0);
  unlink(path);
  q->saved_out = dup(1);
  q->saved_err = dup(2);
  assert_true(q->saved_out >= 0 && q->saved_err >= 0);
  assert_true(dup2(q->fd, 1) >= 0 && dup2(q->fd, 2) >= 0);
}

long ss_quiet_end(ss_quiet_t *q) {
  fflush(stdout);
  fflush(stderr);
  dup2(q->saved_out, 1);
  dup2(q->saved_err, 2);
  close(q->saved_out);
  close(q->saved_err);
  struct stat st;
  const long size = fstat(q->fd, &st) == 0 ? (long)st.st_size : -1;
  close(q->fd);
  return size;
}
