/*
 * mfree_sundials — an mfree semi-discrete particle system (mfree_system_t) as the
 * callbacks of SUNDIALS time integrators: the right-hand side of y' = f(t, y) for
 * ARKODE (ERKStep, ARKStep), the right-hand side and mass matrix of the mass-matrix
 * form M y' = F(t, y) for ARKStep with a sparse direct mass solver (SUNLinSol_KLU), and
 * the residual of M(y) y' = F(t, y) for IDA.
 *
 * A separate library, libmfree_sundials, that links libmfree and SUNDIALS; the mfree
 * core never includes a SUNDIALS header. This header includes the SUNDIALS headers of
 * the types it uses (N_Vector, SUNMatrix, SUNLinearSolver, SUNContext, sunrealtype), so
 * a host needs the SUNDIALS include directory. C99-clean; the conventions of mfree.h
 * apply to the functions returning mfree_status_t (0 success, negative misuse, positive
 * data-dependent failure; the message of a failure is kept on the adapter's context;
 * nothing prints, aborts or exits).
 *
 * SUNDIALS versions. Built and tested with SUNDIALS 6.4 (Debian 12's 6.4.1) only. The
 * declarations below use only names that SUNDIALS 6.x and 7.x both define (sunrealtype,
 * N_Vector, SUNMatrix, SUNLinearSolver, SUNContext); what differs between the two is
 * isolated in the macros of the "SUNDIALS version differences" block (guarded by
 * SUNDIALS_VERSION_MAJOR), so that 7.x needs no change of this header. 7.x is not tested.
 * SUNDIALS must be configured with double precision (sunrealtype == double): the state
 * is handed to mfree without conversion. From C++, SUNDIALS 6.4's own headers need
 * C++14 (sundials_context.h includes sundials_context.hpp, which uses
 * std::make_unique); this header adds nothing beyond C99 / C++11.
 *
 * Vectors. Every N_Vector passed to the callbacks must expose one contiguous host array
 * of N = mfree_system_get_size values through N_VGetArrayPointer (NVECTOR_SERIAL,
 * NVECTOR_OPENMP, NVECTOR_PTHREADS, or a custom vector that implements
 * nvgetarraypointer and nvgetlength). A vector without an array (N_VGetArrayPointer
 * returns NULL, e.g. N_VNewEmpty_Serial) or of another length makes the callback
 * return -1 (unrecoverable) with the reason on the context. Values are read and written
 * in place, never copied, except the state kept for the mass function (below).
 *
 * Return values of the SUNDIALS callbacks (int): 0 on success; the mfree status itself
 * when it is positive (a data-dependent failure such as MFREE_FAIL_NONFINITE or
 * MFREE_FAIL_DOMAIN: SUNDIALS' "recoverable", on which IDA, CVODE and the implicit
 * stages of ARKStep retry with a smaller step); -1 for every negative mfree status and
 * for every adapter-level failure (SUNDIALS' "unrecoverable"). SUNDIALS 6.4 quirk: the
 * explicit stages of ERKStep and ARKStep treat any positive return as unrecoverable
 * (ERKStepEvolve returns ARK_UNREC_RHSFUNC_ERR, "no recovery is possible"); IDA cuts
 * the step and retries (test t711).
 *
 * Threads. An adapter is used by one integrator at a time (it keeps the last state and
 * work arrays); different adapters are independent.
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
 * Create an adapter for a system. The system is borrowed: it is not reference counted
 * from outside, so the host keeps it alive (and does not destroy it) until the adapter
 * is destroyed. ctx is kept alive by the adapter.
 * mfree records the failures of the system's own functions (mfree_system_rhs, ...) on
 * the context the system was created on, and the adapter's failures go to ctx: pass
 * the system's context as ctx so that every message of a failing callback is on one
 * context (mfree's API has no way to ask a system for its context, so this cannot be
 * checked).
 * Defaults: lumped mass (mfree_sundials_set_consistent_mass), no state, no mass solver.
 * @param[in]  ctx  context for the adapter's messages (the system's context)
 * @param[in]  sys  the system (borrowed; its size must be known: set up enough that
 *                  mfree_system_get_size succeeds)
 * @param[out] ad   the new adapter (NULL on failure)
 */
MFREE_SUNDIALS_API mfree_status_t mfree_sundials_create(mfree_context_t *ctx,
                                                        mfree_system_t *sys,
                                                        mfree_sundials_t **ad);

/**
 * Release an adapter (not its system, not SUNDIALS objects registered with it).
 * @param[in,out] ad  may be NULL or point to NULL; set to NULL
 */
MFREE_SUNDIALS_API mfree_status_t mfree_sundials_destroy(mfree_sundials_t **ad);

/**
 * Which mass matrix M multiplies y' in mfree_sundials_mass, mfree_sundials_residual and
 * mfree_sundials_create_mass_matrix: 0 (default) the lumped mass the system's
 * right-hand side divides by (mfree_system_set_lumping), nonzero the consistent Galerkin
 * mass (mfree_system_assemble_mass with consistent != 0, 003 eq 42). The right-hand side
 * F of the mass-matrix form is the same in both cases (mfree_sundials_rhs_mass_form).
 * @param[in] consistent  0 lumped, nonzero consistent
 */
MFREE_SUNDIALS_API mfree_status_t mfree_sundials_set_consistent_mass(mfree_sundials_t *ad,
                                                                     int32_t consistent);

/**
 * Set the state at which mfree_sundials_mass assembles (copied; it has no rate, so it
 * is used as it is whatever the time asked), until a right-hand side or residual of
 * this adapter next succeeds. Use it before ARKStepEvolve, whose first mass evaluation
 * comes before any right-hand side; to freeze the mass matrix at a state (with
 * time_dep = SUNFALSE in ARKStepSetMassLinearSolver); or to refill a mass matrix at a
 * given state, e.g. in an IDA preconditioner setup.
 * @param[in] y  state vector (N values, read through N_VGetArrayPointer; copied)
 */
MFREE_SUNDIALS_API mfree_status_t mfree_sundials_set_state(mfree_sundials_t *ad, N_Vector y);

/**
 * Register the linear solver that factorises the mass matrix filled by
 * mfree_sundials_mass (NULL unregisters; the adapter does not own it). The consistent
 * mass of moving particles changes its sparsity pattern whenever neighbour lists
 * change; SUNLinSol_KLU (and SuperLU_MT) would then refactor the new values on the old
 * symbolic analysis and solve wrongly (test t712). When the pattern written into a
 * matrix differs from that of the previous fill of the same matrix, the adapter calls
 * SUNLinSolInitialize(LS), after which SUNDIALS' sparse direct solvers analyse the
 * pattern afresh at their next setup (what SUNLinSol_KLUReInit with
 * SUNKLU_REINIT_PARTIAL does, without tying the adapter to one solver library). The
 * first fill of a matrix needs none; a matrix destroyed and another created at the same
 * address may cost one needless re-analysis. Not needed for the lumped mass, whose
 * pattern is the diagonal, always.
 * @param[in] LS  the mass solver given to ARKStepSetMassLinearSolver (or used by the
 *                host with the matrix), or NULL; one without an initialize operation
 *                is MFREE_ERR_UNSUPPORTED
 */
MFREE_SUNDIALS_API mfree_status_t mfree_sundials_set_mass_solver(mfree_sundials_t *ad,
                                                                 SUNLinearSolver LS);

/**
 * Create a SUNDIALS sparse matrix (SUNSparseMatrix, CSR_MAT) of size N x N holding the
 * mass matrix (lumped or consistent, as set) at state y, for ARKStepSetMassLinearSolver
 * and SUNLinSol_KLU. Its nnz is that of the mass at y; a later pattern with more
 * entries is handled by mfree_sundials_mass (SUNSparseMatrix_Reallocate). y also
 * becomes the adapter's state, as with mfree_sundials_set_state.
 * sunindextype may be 32 or 64 bits; a mass whose nnz does not fit is
 * MFREE_ERR_UNSUPPORTED.
 * @param[in]  sunctx  the SUNDIALS context of the matrix
 * @param[in]  y       state (N values; copied as the adapter's state)
 * @param[out] M       the new matrix, owned by the host (SUNMatDestroy); NULL on failure
 * @return a positive status when the system fails at y (non-finite state, ...)
 */
MFREE_SUNDIALS_API mfree_status_t mfree_sundials_create_mass_matrix(mfree_sundials_t *ad,
                                                                    SUNContext sunctx,
                                                                    N_Vector y,
                                                                    SUNMatrix *M);

/**
 * Counters since creation, for tuning and tests. Each output may be NULL.
 * @param[out] nrhs             right-hand side evaluations (both forms), failed ones
 *                              included
 * @param[out] nres             residual evaluations
 * @param[out] nmass            mass-matrix evaluations (mfree_sundials_mass)
 * @param[out] nmass_predicted  of those, the ones assembled at a predicted state (asked
 *                              for a time other than that of the last right-hand side;
 *                              see mfree_sundials_mass)
 * @param[out] npattern         mass-matrix fills whose sparsity pattern differed from
 *                              the previous fill of the same matrix (each one
 *                              re-initialises the registered mass solver)
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
 * ydot = f(t, y), the system's right-hand side (mfree_system_rhs): usable directly as
 * an ARKRhsFn for ERKStepCreate, or as the explicit or implicit part of ARKStepCreate
 * with the identity mass, or as a CVRhsFn. On success y becomes the adapter's state
 * (copied), at time t with rate ydot (see mfree_sundials_mass).
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
 * F = M_L(y) f(t, y), the right-hand side of the mass-matrix form M y' = F(t, y): the
 * nodal forces in the velocity block (M_L the lumped mass the system's right-hand side
 * divides by, so that M_L y' = F is the system itself), and the rates of positions and
 * densities unchanged (their rows of M are the identity). Use it as ARKStep's
 * right-hand side together with mfree_sundials_mass. On success y becomes the adapter's
 * state, at time t with rate f(t, y).
 * Cost: one right-hand side and one lumped-mass assembly at y.
 * @return as mfree_sundials_rhs
 */
MFREE_SUNDIALS_API int mfree_sundials_rhs_mass_form(sunrealtype t, N_Vector y, N_Vector F,
                                                    void *user_data);

/**
 * The mass matrix M as an ARKLsMassFn (ARKStepSetMassFn): fills the host's sparse
 * matrix M (SUNSparseMatrix, CSR_MAT or CSC_MAT, N x N; entries beyond the mass's nnz
 * are left unused) with the lumped or consistent mass. When M holds fewer than nnz
 * entries it is enlarged with SUNSparseMatrix_Reallocate.
 *
 * At which state. The mass of the fluid depends on the state (positions, and densities
 * through the particle volumes), but ARKODE's mass function gets only a time: ARKODE
 * treats M as a function M(t). Worse, ARKStep (6.4) calls it at a stage time before it
 * has computed that stage's state, then evaluates the right-hand side at the stage and
 * solves with the matrix it got. The adapter therefore keeps the argument y_r, time t_r
 * and rate y'_r of its last successful right-hand side (either form, or the residual
 * with its y'), and assembles M at the first-order prediction y_r + (t - t_r) y'_r
 * (at y_r itself when t == t_r). Within an explicit Runge-Kutta step the prediction
 * misses the stage state by O(h^2), so the integrated system is M(y) y' = F(t, y) up to
 * an O(h^2) perturbation of M, which ARKODE's error estimate sees and controls (with
 * the last state alone, the O(h) perturbation forced steps 25 times smaller at rtol
 * 1e-10). A state set with mfree_sundials_set_state or mfree_sundials_create_mass_matrix
 * (later than the last right-hand side) has no rate and is used as it is, whatever t:
 * set the initial state this way before ARKStepEvolve, whose first mass evaluation
 * comes before any right-hand side; with time_dep = SUNFALSE in
 * ARKStepSetMassLinearSolver the mass is then frozen at that state.
 * For the exact state-dependent mass use IDA (mfree_sundials_residual); for the lumped
 * mass, ERKStep with mfree_sundials_rhs divides by the lumped mass of the current state
 * exactly and is cheaper.
 * @param[in]     t          time ARKODE asks for (used only for the prediction)
 * @param[in,out] M          SUNSparseMatrix N x N (other kinds or sizes: -1)
 * @param[in]     user_data  the adapter
 * @param         tmp1, tmp2, tmp3  unused
 * @return 0; a positive mfree status when the system fails at the state (e.g. a
 *         non-finite prediction); -1 with no state yet, a matrix of the wrong kind or
 *         size, a failed reallocation or re-initialisation, or an nnz that does not fit
 *         sunindextype
 */
MFREE_SUNDIALS_API int mfree_sundials_mass(sunrealtype t, SUNMatrix M, void *user_data,
                                           N_Vector tmp1, N_Vector tmp2, N_Vector tmp3);

/**
 * The residual of the mass-matrix form M(y) y' = F(t, y) as an IDAResFn (IDAInit),
 * F = M_L(y) f(t, y) as in mfree_sundials_rhs_mass_form:
 *  - lumped mass (default): r = y' - f(t, y), i.e. M_L^{-1} (M_L y' - F): the same
 *    roots, without assembling M_L (M_L is diagonal and positive; IDA's Newton
 *    convergence test measures corrections of y, not residuals);
 *  - consistent mass (mfree_sundials_set_consistent_mass): r = M_C(y) y' - F(t, y),
 *    whose velocity rows are the consistent-mass Galerkin equations M_C v' = F (003
 *    eq 42) and whose other rows are those of y' = f.
 * The mass is evaluated at the y given, so IDA integrates the state-dependent mass
 * exactly (unlike ARKStep's mass interface). No Jacobian is provided: use IDA's
 * difference quotients with a dense or band solver, or a Krylov solver (SPGMR with
 * difference-quotient Jacobian-vector products; for the consistent mass, preconditioned
 * by c_j M_C, which mfree_sundials_set_state + mfree_sundials_mass and SUNLinSol_KLU
 * provide: test t710). On success y and y' become the adapter's state and rate.
 * Cost: one right-hand side (lumped); one right-hand side and two mass assemblies
 * (consistent).
 * @param[in]  t          time
 * @param[in]  y          state, N values
 * @param[in]  yp         its derivative, N values
 * @param[out] r          residual, N values
 * @param[in]  user_data  the adapter
 * @return as mfree_sundials_rhs
 */
MFREE_SUNDIALS_API int mfree_sundials_residual(sunrealtype t, N_Vector y, N_Vector yp,
                                               N_Vector r, void *user_data);

#ifdef __cplusplus
}
#endif

#endif /* MFREE_SUNDIALS_H */
