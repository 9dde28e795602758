/**
 * @file mfree_sundials.h
 * @brief An mfree particle system (mfree_system_t) as the callbacks of SUNDIALS
 * integrators: ARKODE (ERKStep, ARKStep, also with a mass matrix) and IDA.
 *
 * A separate library, libmfree_sundials, linking libmfree and SUNDIALS; the mfree core
 * never includes a SUNDIALS header. docs/time-integration.md shows how to use it.
 *
 * Requirements: SUNDIALS 6.x built with double precision (sunrealtype == double);
 * tested with 6.4. The declarations use only names SUNDIALS 6.x and 7.x both define;
 * the macros below hide what differs. This header includes the SUNDIALS headers of the
 * types it uses, so a host needs the SUNDIALS include directory. C99-clean; the
 * conventions of mfree.h apply to the functions returning mfree_status_t.
 *
 * Vectors: every N_Vector passed to a callback must expose one contiguous host array
 * of N = mfree_system_get_size values through N_VGetArrayPointer (NVECTOR_SERIAL,
 * NVECTOR_OPENMP, NVECTOR_PTHREADS or a custom vector with nvgetarraypointer and
 * nvgetlength); values are read and written in place, never copied, except the state
 * kept for the mass function. A vector that fails these checks (NULL, another length, no
 * array) on one rank of a system on ranks does not leave the other ranks waiting: the
 * fault is made pending on the system (mfree_system_set_pending_error) and the callback
 * still makes its system call, which returns the fault's status on every rank with this
 * rank's message ("rank R: y has length ..."), nothing read or written. The same holds
 * for the other arguments of mfree_sundials_create_mass_matrix (a NULL SUNContext or
 * output pointer). Where the system call is local on ranks (an elastodynamic system's
 * mfree_system_assemble_mass), the fault is this rank's alone, as the call's would be.
 *
 * Callback returns (int): 0 on success; a positive mfree status as it is (SUNDIALS'
 * "recoverable": IDA, CVODE and ARKStep's implicit stages retry with a smaller step;
 * the explicit stages of SUNDIALS 6.4 treat it as unrecoverable); -1 for a negative
 * mfree status or an adapter failure (unrecoverable), the reason on the context.
 *
 * Threads: an adapter serves one integrator at a time; different adapters are
 * independent.
 */
#ifndef MFREE_SUNDIALS_H
#define MFREE_SUNDIALS_H

#include <stdint.h>

#include <sundials/sundials_config.h>
#include <sundials/sundials_context.h>
#include <sundials/sundials_linearsolver.h>
#include <sundials/sundials_matrix.h>
#include <sundials/sundials_nvector.h>
#include <sundials/sundials_types.h>

#include "mfree.h"

#if defined(_WIN32)
#if defined(MFREE_SUNDIALS_BUILDING)
#define MFREE_SUNDIALS_API __declspec(dllexport)
#else
#define MFREE_SUNDIALS_API
#endif
#elif defined(__GNUC__) && __GNUC__ >= 4
#define MFREE_SUNDIALS_API __attribute__((visibility("default")))
#else
#define MFREE_SUNDIALS_API
#endif

/* ------------------------------------------------------------------------------------ */
/* SUNDIALS version differences                                                           */
/* ------------------------------------------------------------------------------------ */

#if !defined(SUNDIALS_VERSION_MAJOR) || SUNDIALS_VERSION_MAJOR < 6
#error "mfree_sundials needs SUNDIALS 6.x (tested: 6.4); SUNContext appeared in 6.0"
#endif
#if !defined(SUNDIALS_DOUBLE_PRECISION)
#error "mfree_sundials needs SUNDIALS built with double precision (sunrealtype == double)"
#endif

/** The "no communicator" argument of SUNContext_Create, whose type changed:
 * 6.x takes a void * (NULL), 7.x a SUNComm (SUN_COMM_NULL). Use
 * `SUNContext_Create(MFREE_SUNDIALS_COMM_NULL, &sunctx)` in code meant for both. */
#if SUNDIALS_VERSION_MAJOR >= 7
#define MFREE_SUNDIALS_COMM_NULL SUN_COMM_NULL
#else
#define MFREE_SUNDIALS_COMM_NULL NULL
#endif

/** SUNDIALS' own status type, for hosts that check SUNDIALS calls in code meant for both
 * versions: 7.x returns SUNErrCode from its vector, matrix and linear-solver functions
 * where 6.x returns int (0 is success in both). */
#if SUNDIALS_VERSION_MAJOR >= 7
typedef SUNErrCode mfree_sundials_errcode_t;
#else
typedef int mfree_sundials_errcode_t;
#endif

#ifdef __cplusplus
extern "C" {
#endif

/** An adapter: an mfree system, the context its failures are recorded on, the last
 * state seen by its right-hand sides, and work space. Pass it as SUNDIALS' user_data. */
typedef struct mfree_sundials mfree_sundials_t;

/* ------------------------------------------------------------------------------------ */
/* Lifecycle and settings                                                                 */
/* ------------------------------------------------------------------------------------ */

/**
 * Create an adapter for a system. Defaults: lumped mass, no state, no mass solver.
 * @param[in]  ctx  context for the adapter's messages (kept alive); pass the system's
 *                  context so that all messages of a failing callback are on one
 * @param[in]  sys  the system, borrowed: the host keeps it alive until the adapter is
 *                  destroyed; its size must be known (mfree_system_get_size succeeds)
 * @param[out] ad   the new adapter (NULL on failure)
 * @return MFREE_SUCCESS; MFREE_ERR_NULL; the status of mfree_system_get_size when the
 *         system's size is unknown; MFREE_ERR_ALLOC
 */
MFREE_SUNDIALS_API mfree_status_t mfree_sundials_create(mfree_context_t *ctx,
                                                        mfree_system_t *sys,
                                                        mfree_sundials_t **ad);

/**
 * Release an adapter (not its system, nor SUNDIALS objects registered with it).
 * @param[in,out] ad  may be NULL or point to NULL; set to NULL
 * @return MFREE_SUCCESS
 */
MFREE_SUNDIALS_API mfree_status_t mfree_sundials_destroy(mfree_sundials_t **ad);

/**
 * Which mass matrix multiplies y' in mfree_sundials_mass, mfree_sundials_residual and
 * mfree_sundials_create_mass_matrix: the lumped mass the system's right-hand side
 * divides by, or the consistent Galerkin mass ([CuetoFelgueroso2004] eq 42). The
 * right-hand side F of the mass-matrix form is the same for both.
 * @param[in] ad          the adapter
 * @param[in] consistent  0 lumped (default), nonzero consistent
 * @return MFREE_SUCCESS; MFREE_ERR_NULL
 */
MFREE_SUNDIALS_API mfree_status_t mfree_sundials_set_consistent_mass(mfree_sundials_t *ad,
                                                                     int32_t consistent);

/**
 * Set the state at which mfree_sundials_mass assembles, used whatever the time asked
 * until a right-hand side or residual of this adapter next succeeds: before
 * ARKStepEvolve (whose first mass evaluation comes before any right-hand side), to
 * freeze the mass at a state, or to refill a mass matrix in a preconditioner setup.
 * @param[in] ad  the adapter
 * @param[in] y   state vector (N values; copied)
 * @return MFREE_SUCCESS; MFREE_ERR_NULL; MFREE_ERR_MISMATCH for a vector of another
 *         length; MFREE_ERR_UNSUPPORTED for a vector without a host array
 */
MFREE_SUNDIALS_API mfree_status_t mfree_sundials_set_state(mfree_sundials_t *ad, N_Vector y);

/**
 * Register the linear solver that factorises the mass matrix filled by
 * mfree_sundials_mass. Whenever a fill changes the matrix's sparsity pattern (the
 * consistent mass of moving particles), the adapter calls SUNLinSolInitialize(LS) so
 * that sparse direct solvers such as SUNLinSol_KLU analyse the new pattern instead of
 * solving wrongly with the old one. Not needed for the lumped mass.
 * @param[in] ad  the adapter
 * @param[in] LS  the mass solver (borrowed: the adapter does not own it), or NULL to
 *                unregister; one without an initialize operation is
 *                MFREE_ERR_UNSUPPORTED
 * @return MFREE_SUCCESS; MFREE_ERR_NULL; MFREE_ERR_UNSUPPORTED
 */
MFREE_SUNDIALS_API mfree_status_t mfree_sundials_set_mass_solver(mfree_sundials_t *ad,
                                                                 SUNLinearSolver LS);

/**
 * Create a SUNDIALS sparse matrix (SUNSparseMatrix, CSR_MAT, N x N) holding the mass
 * matrix at state y, for ARKStepSetMassLinearSolver and SUNLinSol_KLU; y also becomes
 * the adapter's state, as with mfree_sundials_set_state. Later patterns with more
 * entries are handled by mfree_sundials_mass.
 * @param[in]  ad      the adapter
 * @param[in]  sunctx  the SUNDIALS context of the matrix
 * @param[in]  y       state (N values; copied as the adapter's state)
 * @param[out] M       the new matrix, owned by the host (SUNMatDestroy); NULL on failure
 * @return MFREE_SUCCESS; a positive status when the system fails at y;
 *         MFREE_ERR_NULL for a NULL sunctx or M, MFREE_ERR_MISMATCH or
 *         MFREE_ERR_UNSUPPORTED for a y as the callbacks refuse it (on ranks, where the
 *         assembly is collective: on every rank, with the faulty rank's message, no
 *         matrix made); MFREE_ERR_UNSUPPORTED when nnz does not fit sunindextype
 */
MFREE_SUNDIALS_API mfree_status_t mfree_sundials_create_mass_matrix(mfree_sundials_t *ad,
                                                                    SUNContext sunctx,
                                                                    N_Vector y,
                                                                    SUNMatrix *M);

/**
 * Counters since creation, for tuning and tests.
 * @param[in]  ad               the adapter
 * @param[out] nrhs             right-hand side evaluations (both forms, failed ones
 *                              included), or NULL
 * @param[out] nres             residual evaluations, or NULL
 * @param[out] nmass            mass-matrix evaluations, or NULL
 * @param[out] nmass_predicted  of those, the ones assembled at a predicted state, or
 *                              NULL
 * @param[out] npattern         mass fills whose pattern differed from the previous fill
 *                              of the same matrix, or NULL
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL adapter
 */
MFREE_SUNDIALS_API mfree_status_t mfree_sundials_get_stats(const mfree_sundials_t *ad,
                                                           int64_t *nrhs, int64_t *nres,
                                                           int64_t *nmass,
                                                           int64_t *nmass_predicted,
                                                           int64_t *npattern);

/* ------------------------------------------------------------------------------------ */
/* SUNDIALS callbacks (user_data is the mfree_sundials_t *)                              */
/* ------------------------------------------------------------------------------------ */

/**
 * ydot = f(t, y), the system's right-hand side: an ARKRhsFn for ERKStep or either part
 * of ARKStep with the identity mass, or a CVRhsFn. On success y becomes the adapter's
 * state (copied), at time t with rate ydot.
 * @param[in]  t          time
 * @param[in]  y          state, N values
 * @param[out] ydot       derivative, N values
 * @param[in]  user_data  the adapter
 * @return 0; a positive mfree status (recoverable: non-finite or out-of-range state,
 *         particle outside the box, singular local system, ...); -1 (no adapter,
 *         vector without array pointer, wrong length, any negative mfree status)
 */
MFREE_SUNDIALS_API int mfree_sundials_rhs(sunrealtype t, N_Vector y, N_Vector ydot,
                                          void *user_data);

/**
 * F = M_L(y) f(t, y), the right-hand side of the mass-matrix form M y' = F(t, y) (M_L
 * the lumped mass; positions and densities have identity rows), for ARKStep together
 * with mfree_sundials_mass. On success y becomes the adapter's state, at time t with
 * rate f(t, y). Cost: one right-hand side and one lumped-mass assembly.
 * @param[in]  t          time
 * @param[in]  y          state, N values
 * @param[out] F          right-hand side, N values
 * @param[in]  user_data  the adapter
 * @return as mfree_sundials_rhs
 */
MFREE_SUNDIALS_API int mfree_sundials_rhs_mass_form(sunrealtype t, N_Vector y, N_Vector F,
                                                    void *user_data);

/**
 * The mass matrix as an ARKLsMassFn (ARKStepSetMassFn): fills the host's sparse matrix
 * M (CSR_MAT or CSC_MAT, N x N; enlarged with SUNSparseMatrix_Reallocate when too
 * small). ARKODE asks for M(t) only, so the adapter assembles it at the first-order
 * prediction y_r + (t - t_r) y'_r from its last successful right-hand side, or at a
 * state set by mfree_sundials_set_state; docs/time-integration.md explains why. For
 * the exact state-dependent mass use IDA (mfree_sundials_residual).
 * @param[in]     t          time ARKODE asks for (used only for the prediction)
 * @param[in,out] M          SUNSparseMatrix N x N (other kinds or sizes: -1)
 * @param[in]     user_data  the adapter
 * @param         tmp1       unused
 * @param         tmp2       unused
 * @param         tmp3       unused
 * @return 0; a positive mfree status when the system fails at the state (e.g. a
 *         non-finite prediction); -1 with no state yet, a matrix of the wrong kind or
 *         size, a failed reallocation or re-initialisation, or an nnz that does not fit
 *         sunindextype
 */
MFREE_SUNDIALS_API int mfree_sundials_mass(sunrealtype t, SUNMatrix M, void *user_data,
                                           N_Vector tmp1, N_Vector tmp2, N_Vector tmp3);

/**
 * The residual of the mass-matrix form M(y) y' = F(t, y) as an IDAResFn: with the
 * lumped mass r = y' - f(t, y) (the same roots without assembling M_L), with the
 * consistent mass r = M_C(y) y' - F(t, y). The mass is evaluated at the y given, so
 * IDA integrates the state-dependent mass exactly. No Jacobian is provided: use IDA's
 * difference quotients or a Krylov solver (docs/time-integration.md). On success y and
 * y' become the adapter's state and rate.
 * @param[in]  t          time
 * @param[in]  y          state, N values
 * @param[in]  yp         its derivative, N values
 * @param[out] r          residual, N values
 * @param[in]  user_data  the adapter
 * @return as mfree_sundials_rhs
 */
MFREE_SUNDIALS_API int mfree_sundials_residual(sunrealtype t, N_Vector y, N_Vector yp,
                                               N_Vector r, void *user_data);

/**
 * ARKLsMassTimesFn: Mv = M v with M the mass of mfree_sundials_mass (at the same state,
 * predicted to time t), for matrix-free mass solvers such as SUNLinSol_PCG
 * (ARKStepSetMassLinearSolver(mem, LS, NULL, ...), ARKStepSetMassTimes(mem, NULL,
 * mfree_sundials_mass_times, ad)), and for vectors over ranks (NVECTOR_PARALLEL: the
 * lumped mass of a system on ranks is block-diagonal by rank; collocation: the identity;
 * the fluid: its lumped mass, diagonal). The product is the system's own,
 * mfree_system_apply_mass at that state, lumped or consistent
 * (mfree_sundials_set_consistent_mass): the system keeps the mass of one state (except a
 * fluid with open boundaries), so that products at the same t with no right-hand side (no
 * new state) in between reuse it, as the iterations of one mass solve do. On ranks it is
 * collective at every product (a vector's fault on one rank reaches every rank); the
 * consistent mass couples owned particles to ghosts and exchanges v there.
 * @param[in]  v            the vector to multiply (the system's length on this rank)
 * @param[out] Mv           M v
 * @param[in]  t            time
 * @param[in]  mtimes_data  the adapter (ARKStepSetMassTimes' data)
 * @return 0; -1 (reason on the context) for a NULL adapter, no state yet, or vectors of
 *         another length or without data; the system's positive status as it is
 */
MFREE_SUNDIALS_API int mfree_sundials_mass_times(N_Vector v, N_Vector Mv, sunrealtype t,
                                                 void *mtimes_data);

#ifdef __cplusplus
}
#endif

#endif /* MFREE_SUNDIALS_H */
