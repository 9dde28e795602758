/* Helpers of the SuiteSparse adapter tests (8xx): model matrices on an m x m grid,
 * error capture, and a check that a call prints nothing. */
#ifndef MFREE_SSTEST_H
#define MFREE_SSTEST_H

#include "testutil.h"

#include <mfree_suitesparse.h>

/* The three solvers, for loops over kinds. */
extern const mfree_solver_kind_t ss_kinds[3];

/* 5-point stencil on an m x m grid with Dirichlet boundaries (row r = i + m*j):
 * diagonal d, west/east/south/north neighbours w, e, s, nn. Rows sorted by column. */
mfree_matrix_t *ss_stencil(mfree_context_t *ctx, int32_t m, double d, double w, double e,
                           double s, double nn);
/* The SPD 2D Laplacian: 4 on the diagonal, -1 to each neighbour. */
mfree_matrix_t *ss_laplacian(mfree_context_t *ctx, int32_t m);
/* Convection-diffusion -lap u + beta . grad u, central differences, mesh Peclet
 * numbers px = beta_x h / 2, py = beta_y h / 2: nonsymmetric and nonsingular. */
mfree_matrix_t *ss_convection(mfree_context_t *ctx, int32_t m, double px, double py);
/* A matrix from a dense row-major n x n array, keeping only entries with keep != 0
 * (keep may be NULL: keep the nonzeros). */
mfree_matrix_t *ss_dense(mfree_context_t *ctx, int32_t n, const double *a, const int *keep);

/* Exact-solution check: x_true[i] = 1 + sin(i + 7 j); b = A x_true (through
 * mfree_matrix_apply) in column j of b (leading dimension ldb). */
void ss_make_rhs(const mfree_matrix_t *A, int32_t nrhs, double *xtrue, double *b, int64_t ldb);
/* max_j ||x_j - xtrue_j||_2 / ||xtrue_j||_2. */
double ss_rel_error(int32_t n, int32_t nrhs, const double *x, int64_t ldx, const double *xtrue);

/* Counts what the context's error handler receives. */
typedef struct {
  int calls;
  mfree_status_t last_code;
  char last_message[1024];
} ss_errors_t;
void ss_capture_errors(mfree_context_t *ctx, ss_errors_t *e);

/* Run fd 1 and 2 into a temporary file between begin and end; end returns the number
 * of bytes written meanwhile. */
typedef struct {
  int saved_out, saved_err, fd;
} ss_quiet_t;
void ss_quiet_begin(ss_quiet_t *q);
long ss_quiet_end(ss_quiet_t *q);

#endif
