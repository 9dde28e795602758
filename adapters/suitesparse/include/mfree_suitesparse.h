/**
 * @file mfree_suitesparse.h
 * @brief Sparse direct solvers (SuiteSparse CHOLMOD, UMFPACK, KLU) for mfree's sparse
 * matrices (mfree_matrix_t).
 *
 * A separate library, libmfree_suitesparse, linking libmfree and SuiteSparse; this
 * header includes no SuiteSparse header. C99-clean; the conventions of mfree.h apply.
 * docs/sparse-solves.md shows how to use it.
 *
 * Zero copy: the solver reads the matrix through its CSR views and never copies the
 * values (the CSR arrays of A are the CSC arrays of A^T, which SuiteSparse factors:
 * UMFPACK and KLU solve the transposed system, CHOLMOD needs a symmetric A anyway).
 * After setup or update returns, the solver holds no pointer into A: the matrix may be
 * refilled or destroyed and solve keeps using the factors.
 *
 * Lifecycle: create, [set_index_width], setup(A), solve (many times), update(A') (same
 * pattern, new values), solve, ..., setup(B) (new pattern), destroy. After any failure
 * the object stays usable: a later setup with a good matrix works.
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
 * Create a solver of the given kind. A solver is used from one thread at a time;
 * different solvers are independent. Defaults: automatic index width, singularity
 * threshold 1e-10.
 * @param[in]  ctx   context for error messages (kept alive by the solver)
 * @param[in]  kind  an mfree_solver_kind_t (anything else: MFREE_ERR_ARG)
 * @param[out] s     the new solver (NULL on failure)
 * @return MFREE_SUCCESS; MFREE_ERR_NULL; MFREE_ERR_ARG; MFREE_ERR_ALLOC
 */
MFREE_SUITESPARSE_API mfree_status_t mfree_suitesparse_create(mfree_context_t *ctx,
                                                              mfree_solver_kind_t kind,
                                                              mfree_suitesparse_t **s);

/**
 * Release a solver and its factors.
 * @param[in,out] s  may be NULL or point to NULL; set to NULL
 * @return MFREE_SUCCESS
 */
MFREE_SUITESPARSE_API mfree_status_t mfree_suitesparse_destroy(mfree_suitesparse_t **s);

/**
 * Integer width of the SuiteSparse variant used by the next setup (update keeps the
 * width of its setup). Automatic: the 32-bit variants (cholmod, umfpack_di, klu) when
 * nnz(A) fits, else the 64-bit ones, with one retry in 64 bits when a 32-bit
 * factorisation overflows. Both widths give the same factorisation.
 * @param[in] s     the solver
 * @param[in] bits  0 (automatic, default), 32 or 64 (anything else: MFREE_ERR_ARG);
 *                  forcing 32 on a matrix whose nnz does not fit makes setup fail with
 *                  MFREE_ERR_UNSUPPORTED
 * @return MFREE_SUCCESS; MFREE_ERR_NULL; MFREE_ERR_ARG
 */
MFREE_SUITESPARSE_API mfree_status_t mfree_suitesparse_set_index_width(mfree_suitesparse_t *s,
                                                                       int32_t bits);

/**
 * Singularity threshold on the reciprocal condition estimate (the rcond of
 * mfree_suitesparse_get_info). UMFPACK and KLU call a matrix singular only at an exactly
 * zero pivot, which round-off rarely leaves, so without this check a singular system
 * would be solved silently. An estimate below the threshold after a numeric
 * factorisation makes setup or update return MFREE_FAIL_SINGULAR; solve then refuses
 * until a factorisation passes. docs/sparse-solves.md explains the default, 1e-10.
 * Takes effect at the next setup or update.
 * @param[in] s          the solver
 * @param[in] threshold  in [0, 1); 0 disables the check (anything else, NaN included:
 *                       MFREE_ERR_ARG, nothing changed)
 * @return MFREE_SUCCESS; MFREE_ERR_NULL; MFREE_ERR_ARG
 */
MFREE_SUITESPARSE_API mfree_status_t mfree_suitesparse_set_rcond_threshold(mfree_suitesparse_t *s,
                                                                           double threshold);

/**
 * Symbolic analysis (fill-reducing ordering) and numeric factorisation of A, replacing
 * any previous factorisation. A is read through its views during the call only.
 * @param[in] s  the solver
 * @param[in] A  square matrix (else MFREE_ERR_MISMATCH); for MFREE_SOLVER_CHOLMOD also
 *               symmetric (mfree_matrix_get_symmetric == 1, else MFREE_ERR_MISMATCH)
 * @return MFREE_SUCCESS; MFREE_FAIL_SINGULAR when A is singular (a zero pivot or an
 *         estimate below the threshold) or, for CHOLMOD, not positive definite: the
 *         symbolic analysis is kept for an update, solve refuses until a factorisation
 *         succeeds; MFREE_FAIL_NONFINITE for a NaN or Inf in A (the previous
 *         factorisation is released); MFREE_ERR_UNSUPPORTED for forced 32-bit indices
 *         too narrow for nnz; MFREE_ERR_ALLOC (the previous factorisation is then
 *         already released). Argument errors change nothing.
 */
MFREE_SUITESPARSE_API mfree_status_t mfree_suitesparse_setup(mfree_suitesparse_t *s,
                                                             const mfree_matrix_t *A);

/**
 * Numeric refactorisation with new values on the pattern of the last setup, reusing
 * its ordering and symbolic analysis. The pattern is compared by content (size, nnz
 * and a 128-bit fingerprint of the indices), so A may be another matrix with the same
 * pattern. KLU first tries klu_refactor and factorises afresh when its pivots degrade;
 * UMFPACK re-pivots always; CHOLMOD does not pivot.
 * @param[in] s  the solver
 * @param[in] A  matrix with the pattern of the last setup
 * @return as setup; MFREE_ERR_STATE when there was no successful symbolic analysis or
 *         the pattern differs (call mfree_suitesparse_setup)
 */
MFREE_SUITESPARSE_API mfree_status_t mfree_suitesparse_update(mfree_suitesparse_t *s,
                                                              const mfree_matrix_t *A);

/**
 * Solve A X = B for nrhs right-hand sides, column-major. b == x with ldb == ldx solves
 * in place; any other overlap is undefined. No allocation after the first solve with a
 * given nrhs.
 * @param[in]  s     a solver with a successful factorisation
 * @param[in]  nrhs  number of right-hand sides (>= 0; 0 does nothing)
 * @param[in]  b     right-hand sides, column j at b[j*ldb]; ldb * nrhs doubles, not
 *                   modified unless it is x (may be NULL if nrhs == 0)
 * @param[in]  ldb   leading dimension of b, >= max(1, n) (else MFREE_ERR_ARG)
 * @param[out] x     solutions, ldx * nrhs doubles; rows n..ldx-1 are left untouched
 * @param[in]  ldx   leading dimension of x, >= max(1, n) (else MFREE_ERR_ARG)
 * @return MFREE_SUCCESS; MFREE_ERR_NULL; MFREE_ERR_ARG; MFREE_ERR_STATE before a
 *         successful setup or update
 */
MFREE_SUITESPARSE_API mfree_status_t mfree_suitesparse_solve(mfree_suitesparse_t *s,
                                                             int32_t nrhs, const double *b,
                                                             int64_t ldb, double *x,
                                                             int64_t ldx);

/**
 * Facts about the current factorisation, after a setup that got at least through the
 * symbolic analysis.
 * @param[in]  s            the solver
 * @param[out] rcond        cheap reciprocal condition estimate of the last numeric
 *                          factorisation, min/max |pivot| (UMFPACK, KLU: diagonal of U
 *                          of the row-scaled matrix; CHOLMOD: diagonal of L, squared);
 *                          0 when it failed, the rejected estimate when it was below
 *                          the threshold; a warning sign, not a bound; or NULL
 * @param[out] factor_nnz   entries in the factors, nnz(L) + nnz(U) (KLU: plus the
 *                          off-diagonal blocks; CHOLMOD: nnz(L)), or NULL
 * @param[out] index_width  32 or 64: the SuiteSparse variant in use, or NULL
 * @return MFREE_SUCCESS; MFREE_ERR_NULL; MFREE_ERR_STATE before a symbolic analysis
 */
MFREE_SUITESPARSE_API mfree_status_t mfree_suitesparse_get_info(const mfree_suitesparse_t *s,
                                                                double *rcond,
                                                                int64_t *factor_nnz,
                                                                int32_t *index_width);

/**
 * The context a solver was created on, for bindings that check arguments themselves
 * (the Fortran module does) and record their failures with mfree_context_set_error.
 * @param[in]  s    the solver
 * @param[out] ctx  its context, borrowed: the solver keeps it alive; never destroy it
 * @return MFREE_SUCCESS; MFREE_ERR_NULL (without a message) for a NULL handle or output
 */
MFREE_SUITESPARSE_API mfree_status_t mfree_suitesparse_get_context(const mfree_suitesparse_t *s,
                                                                   mfree_context_t **ctx);

#ifdef __cplusplus
}
#endif

#endif /* MFREE_SUITESPARSE_H */
