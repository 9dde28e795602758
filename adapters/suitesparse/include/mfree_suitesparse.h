/*
 * mfree_suitesparse — sparse direct solvers (SuiteSparse CHOLMOD, UMFPACK, KLU) for
 * mfree's sparse matrices (mfree_matrix_t). A separate library, libmfree_suitesparse,
 * that links libmfree and SuiteSparse; this header includes no SuiteSparse header, so
 * hosts need none. C99-clean; the conventions of mfree.h apply (every function returns
 * an mfree_status_t; the message of a failure is kept on the context given to
 * mfree_suitesparse_create; nothing prints, aborts or exits).
 *
 * Zero copy. The solver reads the matrix through its CSR views
 * (mfree_matrix_get_csr_i32 / mfree_matrix_get_csr_i64) and never copies the values.
 * The CSR arrays of A are the CSC arrays of A^T, which is what SuiteSparse takes:
 *  - UMFPACK factors A^T and solves with sys = UMFPACK_At ((A^T)^T x = A x = b);
 *  - KLU factors A^T and solves with klu_tsolve / klu_l_tsolve;
 *  - CHOLMOD needs a symmetric positive definite A, for which CSR = CSC: a
 *    cholmod_sparse header points at the CSR arrays (stype = 1, the upper triangle of
 *    the CSC view is used and the other triangle ignored; packed, sorted).
 * The index arrays come from the matrix's views: with 32-bit indices the row offsets
 * are the matrix's cached 32-bit copy and the columns are its own; with 64-bit indices
 * the offsets are its own and the columns its cached 64-bit copy. Values are never
 * converted. After setup / update return, the solver holds no pointer into A: the
 * matrix may be refilled or destroyed and mfree_suitesparse_solve keeps using the
 * factors (no iterative refinement, which would need A again).
 *
 * Lifecycle: create -> [set_index_width] -> setup(A) -> solve (many times) ->
 * update(A') (same pattern, new values) -> solve ... -> setup(B) (new pattern) ->
 * destroy. After any failure the object stays usable: a later setup with a good
 * matrix works.
 */
#ifndef MFREE_SUITESPARSE_H
#define MFREE_SUITESPARSE_H

#include <stdint.h>

#include "mfree.h"

#if defined(_WIN32)
#if defined(MFREE_SUITESPARSE_BUILDING)
#define MFREE_SUITESPARSE_API __declspec(dllexport)
#else
#define MFREE_SUITESPARSE_API
#endif
#elif defined(__GNUC__) && __GNUC__ >= 4
#define MFREE_SUITESPARSE_API __attribute__((visibility("default")))
#else
#define MFREE_SUITESPARSE_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

/** Which SuiteSparse solver factorises the matrix. Values are frozen. */
typedef MFREE_ENUM(mfree_solver_kind) {
  MFREE_SOLVER_CHOLMOD = 1, /**< sparse Cholesky A = L L^T; symmetric positive definite
                                 matrices only (mfree_matrix_get_symmetric must say 1) */
  MFREE_SOLVER_UMFPACK = 2, /**< multifrontal LU with partial pivoting; any square
                                 nonsingular matrix */
  MFREE_SOLVER_KLU = 3      /**< left-looking LU with BTF ordering, fast refactorisation
                                 (circuit- and Jacobian-like matrices); any square
                                 nonsingular matrix */
} mfree_solver_kind_t;

/** A direct solver: one factorisation of one matrix pattern at a time. */
typedef struct mfree_suitesparse mfree_suitesparse_t;

/**
 * Create a solver of the given kind. Its failures are recorded on ctx, which the
 * solver keeps alive until it is destroyed (so teardown order does not matter). A
 * solver is used from one thread at a time; different solvers are independent.
 * Defaults: automatic index width (see mfree_suitesparse_set_index_width), singularity
 * threshold 1e-10 on the reciprocal condition estimate (see
 * mfree_suitesparse_set_rcond_threshold).
 * @param[in]  ctx   context for error messages
 * @param[in]  kind  an mfree_solver_kind_t (anything else: MFREE_ERR_ARG)
 * @param[out] s     the new solver (NULL on failure)
 */
MFREE_SUITESPARSE_API mfree_status_t mfree_suitesparse_create(mfree_context_t *ctx,
                                                              mfree_solver_kind_t kind,
                                                              mfree_suitesparse_t **s);

/**
 * Release a solver and its factors.
 * @param[in,out] s  may be NULL or point to NULL; set to NULL
 */
MFREE_SUITESPARSE_API mfree_status_t mfree_suitesparse_destroy(mfree_suitesparse_t **s);

/**
 * Integer width of the SuiteSparse variant used by the next setup.
 * 0 (default, automatic): the 32-bit variants (cholmod_*, umfpack_di_*, klu_*) when
 * nnz(A) <= INT32_MAX, else the 64-bit ones (cholmod_l_*, umfpack_dl_*, klu_l_*);
 * moreover, if a 32-bit variant reports an integer overflow in its factors (CHOLMOD,
 * KLU: "too large"), setup retries once with the 64-bit variant.
 * 32 or 64 force one variant; forcing 32 on a matrix whose nnz does not fit makes
 * setup fail with MFREE_ERR_UNSUPPORTED. Both widths give the same factorisation (same
 * orderings and pivots), so solutions agree to the last bit in practice.
 * The width takes effect at the next setup; update keeps the width of its setup.
 * @param[in] bits  0, 32 or 64 (anything else: MFREE_ERR_ARG)
 */
MFREE_SUITESPARSE_API mfree_status_t mfree_suitesparse_set_index_width(mfree_suitesparse_t *s,
                                                                       int32_t bits);

/**
 * Singularity threshold on the reciprocal condition estimate (the rcond of
 * mfree_suitesparse_get_info). UMFPACK and KLU report a matrix as singular only when a
 * pivot is exactly zero, and round-off usually leaves a tiny nonzero pivot instead, so a
 * singular system (e.g. a stiffness with a zero-energy mode) would otherwise be solved
 * silently, with garbage amplified by 1/rcond. After every numeric factorisation (setup
 * and update, all three solvers) an estimate below the threshold makes the call return
 * MFREE_FAIL_SINGULAR with a message giving the estimate and the threshold; the solver
 * is then in the state documented for singular matrices (solve refuses until a
 * factorisation passes), and get_info still reports the rejected estimate.
 * Default 1e-10, chosen from measurements: singular matrices leave round-off estimates
 * that grow roughly like n * DBL_EPSILON (the MPFEM Haar ring of test t474, n = 40:
 * 1.7e-15; singular grid Laplacians of t807: 1.3e-13 at n = 2500, 6.8e-12 at
 * n = 160000, so singular systems of a few million unknowns may pass unnoticed), while
 * the smallest estimate of a legitimate system in mfree's tests and examples was 6.4e-8
 * (the penalty-constrained Table III systems; Lagrange multipliers 1.0e-7, Laplacians,
 * Nitsche, collocation and MPFEM systems 1e-5 and above). The estimate is min/max |pivot|
 * (CHOLMOD: squared), not a bound on the condition number: a host with badly scaled but
 * solvable systems (large penalty factors) may lower the threshold or disable the check.
 * Takes effect at the next setup / update.
 * @param[in] threshold  in [0, 1); 0 disables the check (anything else, NaN included:
 *                       MFREE_ERR_ARG, nothing changed)
 */
MFREE_SUITESPARSE_API mfree_status_t mfree_suitesparse_set_rcond_threshold(mfree_suitesparse_t *s,
                                                                           double threshold);

/**
 * Symbolic analysis (fill-reducing ordering) and numeric factorisation of A. Replaces
 * any previous factorisation. A is read through its views during the call only.
 * @param[in] A  square matrix (else MFREE_ERR_MISMATCH); for MFREE_SOLVER_CHOLMOD also
 *               symmetric (mfree_matrix_get_symmetric == 1, else MFREE_ERR_MISMATCH)
 * @return MFREE_SUCCESS; MFREE_FAIL_SINGULAR (positive) when A is singular (an exactly
 *         zero pivot, or a reciprocal condition estimate below the threshold of
 *         mfree_suitesparse_set_rcond_threshold) or, for
 *         CHOLMOD, not positive definite: the symbolic analysis is kept (update with
 *         better values of the same pattern works), but solve returns MFREE_ERR_STATE
 *         until a factorisation succeeds; MFREE_FAIL_NONFINITE (positive) when A holds
 *         a NaN or Inf (the previous factorisation is released, nothing is factorised);
 *         MFREE_ERR_UNSUPPORTED when 32-bit indices are forced and nnz(A) > INT32_MAX;
 *         MFREE_ERR_ALLOC when memory runs out (the previous factorisation is then
 *         already released: keeping both would double the peak memory).
 *         Argument errors (NULL, not square, not symmetric for CHOLMOD, forced 32-bit
 *         indices too narrow for nnz) change nothing: the previous factorisation stays.
 */
MFREE_SUITESPARSE_API mfree_status_t mfree_suitesparse_setup(mfree_suitesparse_t *s,
                                                             const mfree_matrix_t *A);

/**
 * Numeric refactorisation with new values on the pattern of the last setup (the
 * ordering and symbolic analysis are reused). A may be the matrix of the setup refilled
 * with new values, or another matrix with the same pattern.
 * The pattern is compared by content: size, nnz and a 128-bit fingerprint of the row
 * offsets and column indices (mfree_matrix_get_pattern_id alone cannot tell: it counts
 * the patterns of one matrix object, so two matrices created separately report the
 * same id). KLU first tries klu_refactor (the pivot order of the last factorisation);
 * when that fails or its pivot ratio drops below eps^(2/3), it factorises again with
 * fresh partial pivoting. UMFPACK re-pivots always; CHOLMOD does not pivot.
 * @param[in] A  matrix with the pattern of the last setup
 * @return as setup; MFREE_ERR_STATE when there was no successful symbolic analysis or
 *         the pattern differs (the message says to call mfree_suitesparse_setup)
 */
MFREE_SUITESPARSE_API mfree_status_t mfree_suitesparse_update(mfree_suitesparse_t *s,
                                                              const mfree_matrix_t *A);

/**
 * Solve A X = B for nrhs right-hand sides, column-major: column j of B is
 * b[j*ldb .. j*ldb + n - 1], of X is x[j*ldx .. j*ldx + n - 1]. B is borrowed for the
 * call and not modified unless it is X itself: b == x with ldb == ldx solves in place
 * (any other overlap of b and x is undefined). No allocation after the first solve with
 * a given nrhs (CHOLMOD keeps its workspace; UMFPACK and KLU need none beyond setup).
 * @param[in]  nrhs  number of right-hand sides (>= 0; 0 does nothing)
 * @param[in]  b     right-hand sides, ldb * nrhs doubles (may be NULL if nrhs == 0)
 * @param[in]  ldb   leading dimension of b, >= max(1, n) (else MFREE_ERR_ARG)
 * @param[out] x     solutions, ldx * nrhs doubles; rows n..ldx-1 are left untouched
 * @param[in]  ldx   leading dimension of x, >= max(1, n) (else MFREE_ERR_ARG)
 * @return MFREE_ERR_STATE before a successful setup / update
 */
MFREE_SUITESPARSE_API mfree_status_t mfree_suitesparse_solve(mfree_suitesparse_t *s,
                                                             int32_t nrhs, const double *b,
                                                             int64_t ldb, double *x,
                                                             int64_t ldx);

/**
 * Facts about the current factorisation (after a setup that got at least through the
 * symbolic analysis; else MFREE_ERR_STATE). Each output may be NULL.
 * @param[out] rcond        cheap reciprocal condition estimate of the last numeric
 *                          factorisation, min/max |pivot|: UMFPACK and KLU take the
 *                          diagonal of U of the row-scaled matrix they factor (their
 *                          default scaling), CHOLMOD the diagonal of L, squared (so
 *                          1/cond for a diagonal matrix); 0 when it failed, the
 *                          rejected estimate when it was below the singularity
 *                          threshold. A small value warns of ill-conditioning; it is
 *                          not a bound.
 * @param[out] factor_nnz   entries in the factors: nnz(L) + nnz(U) (+ the off-diagonal
 *                          blocks for KLU), diagonals included; nnz(L) for CHOLMOD
 * @param[out] index_width  32 or 64: the SuiteSparse variant in use
 */
MFREE_SUITESPARSE_API mfree_status_t mfree_suitesparse_get_info(const mfree_suitesparse_t *s,
                                                                double *rcond,
                                                                int64_t *factor_nnz,
                                                                int32_t *index_width);

#ifdef __cplusplus
}
#endif

#endif /* MFREE_SUITESPARSE_H */
