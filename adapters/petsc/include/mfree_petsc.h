/*
 * mfree_petsc — distributed Galerkin systems of mfree assemblers in PETSc: a parallel
 * sparse matrix (MATAIJ: MATMPIAIJ on more than one rank), its right-hand side and a
 * Krylov solve (KSP, conjugate gradients with algebraic multigrid, PCGAMG, by default).
 * A separate library, libmfree_petsc, that links libmfree, PETSc and MPI; the core
 * libmfree never includes a PETSc or MPI header. C99-clean; the conventions of mfree.h
 * apply (every function returns an mfree_status_t; the message of a failure is kept on
 * the context given to mfree_petsc_create; nothing prints, aborts or exits: PETSc's
 * error printing is switched off around every call).
 *
 * The distributed setting. Each rank holds one mfree particle set of nlocal particles:
 * first its nowned owned nodes, then ghost copies of other ranks' nodes, each with its
 * 64-bit global id (the same ids as mfree_particles_set_global_ids). Every rank sets up
 * an assembler on its set as on one machine; mfree_petsc_setup takes the rows of the
 * owned nodes of that assembler's matrix, with their columns renumbered from global ids
 * to PETSc's, into a matrix whose row block on each rank is its owned nodes (in local
 * order, ncomp rows per node). For the rows of the owned nodes to be those of a run on
 * one rank, the particle set must hold every particle within two support radii of an
 * owned node (the quadrature points that see an owned node, and their neighbours), and
 * with nodal quadrature the particles within one support radius of an owned node must
 * be non-ghosts of the set (they are the quadrature points): see the halo rule in
 * docs/petsc.md. With global ids on the set, those rows are then bitwise equal to the
 * one-rank rows.
 *
 * Collective calls. mfree_petsc_setup, _assemble, _set_dirichlet and _solve are
 * collective over the communicator. Each checks its arguments on every rank and the
 * ranks agree on the outcome before any PETSc collective operation: when any rank fails,
 * every rank returns the same status (the most negative status of the failing ranks),
 * the failing rank's message on that rank and "rank R failed: ..." on the others, and
 * nothing is changed on any rank. A NULL handle returns MFREE_ERR_NULL at once, without
 * communication.
 *
 * PETSc options. PetscInitialize must have been called by the host (mfree_petsc_create
 * returns MFREE_ERR_STATE otherwise); the host also calls PetscFinalize after destroying
 * its objects. The matrix, the vectors and the solver take their options from PETSc's
 * options database under the prefix of mfree_petsc_set_options_prefix (MatSetFromOptions
 * and KSPSetFromOptions at setup), so any PETSc option applies: -ksp_type, -pc_type
 * hypre -pc_hypre_type boomeramg, -ksp_rtol, -ksp_monitor, -mat_type, and so on.
 * Defaults before the options: KSPCG, PCGAMG, relative tolerance 1e-10, absolute 1e-50,
 * at most 10000 iterations, the rigid-body modes of mfree_petsc_set_coordinates as
 * near null space of elasticity matrices.
 *
 * Lifecycle: create -> [set_options_prefix, set_coordinates] -> setup(as) (pattern,
 * preallocation and a first assembly) -> [set_dirichlet] -> solve -> after
 * mfree_assembler_update (particles moved, same pattern) or new material or loads:
 * assemble (values only, no reallocation) -> solve ... -> setup again when the
 * assembler was set up again (new pattern) -> destroy.
 */
#ifndef MFREE_PETSC_H
#define MFREE_PETSC_H

#include <stdint.h>

#include <petscksp.h>

#include "mfree.h"

#if defined(_WIN32)
#if defined(MFREE_PETSC_BUILDING)
#define MFREE_PETSC_API __declspec(dllexport)
#else
#define MFREE_PETSC_API
#endif
#elif defined(__GNUC__) && __GNUC__ >= 4
#define MFREE_PETSC_API __attribute__((visibility("default")))
#else
#define MFREE_PETSC_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

/** A distributed system: matrix, right-hand side, solution vector and solver. */
typedef struct mfree_petsc mfree_petsc_t;

/**
 * Create an empty distributed system on a communicator. Not collective. The context
 * records the failures and is kept alive until the system is destroyed; comm is
 * borrowed (it must stay valid until destroy) and must be the same on every rank that
 * takes part in the collective calls.
 * @param[in]  ctx   context for error messages
 * @param[in]  comm  MPI communicator (MPI_COMM_NULL: MFREE_ERR_ARG)
 * @param[out] pk    the new system (NULL on failure)
 * @return MFREE_SUCCESS; MFREE_ERR_NULL (ctx or pk NULL); MFREE_ERR_ARG; MFREE_ERR_STATE
 *         when PETSc is not initialised (PetscInitialize); MFREE_ERR_ALLOC
 */
MFREE_PETSC_API mfree_status_t mfree_petsc_create(mfree_context_t *ctx, MPI_Comm comm,
                                                  mfree_petsc_t **pk);

/**
 * Destroy the system and its PETSc objects (collective, as PETSc's destroys are).
 * @param[in,out] pk  may be NULL or point to NULL; set to NULL
 * @return MFREE_SUCCESS
 */
MFREE_PETSC_API mfree_status_t mfree_petsc_destroy(mfree_petsc_t **pk);

/**
 * Options prefix of the matrix, the vectors and the solver in PETSc's options database
 * (e.g. "elast_" reads -elast_ksp_type). Copied. Takes effect at the next setup.
 * Not collective.
 * @param[in] pk      the system
 * @param[in] prefix  letters, digits and '_', not starting with a digit, at most 63
 *                    characters; NULL or "" for none
 * @return MFREE_SUCCESS; MFREE_ERR_NULL; MFREE_ERR_ARG for another prefix
 */
MFREE_PETSC_API mfree_status_t mfree_petsc_set_options_prefix(mfree_petsc_t *pk,
                                                              const char *prefix);

/**
 * Coordinates of the owned nodes, for the near null space of elasticity (the rigid-body
 * modes, MatNullSpaceCreateRigidBody) that algebraic multigrid uses. Copied; takes
 * effect at the next setup, and only when the number of components per node equals dim.
 * Not collective, but every rank with owned nodes gives them or none does (else the
 * next setup returns MFREE_ERR_ARG on every rank, naming a rank without them).
 * @param[in] pk      the system
 * @param[in] dim     2 or 3 (else MFREE_ERR_ARG)
 * @param[in] nowned  number of owned nodes (must match setup's, else setup returns
 *                    MFREE_ERR_MISMATCH)
 * @param[in] x       nowned * dim values, node after node (NULL with nowned > 0:
 *                    MFREE_ERR_NULL; a non-finite value: MFREE_ERR_INPUT)
 * @return MFREE_SUCCESS; MFREE_ERR_NULL; MFREE_ERR_ARG; MFREE_ERR_INPUT (nothing changed)
 */
MFREE_PETSC_API mfree_status_t mfree_petsc_set_coordinates(mfree_petsc_t *pk, int32_t dim,
                                                           int32_t nowned, const double *x);

/**
 * Build the distributed system of a set-up assembler (collective): the PETSc numbering
 * (the owned nodes of rank r follow those of ranks 0..r-1, ncomp rows per node), the
 * matrix preallocated exactly from the pattern of the owned rows (diagonal and
 * off-diagonal blocks counted per row; a later assembly that needed a new entry would
 * fail rather than reallocate), the vectors, the solver with its options, and a first
 * assembly (as mfree_petsc_assemble). Replaces a previous setup (Dirichlet rows are
 * cleared). The assembler is borrowed: it must stay alive and set up while the system
 * assembles from it.
 * @param[in] pk      the system
 * @param[in] as      a set-up Galerkin assembler on this rank's particle set of nlocal
 *                    particles, without Lagrange multipliers (its unknowns must be
 *                    nlocal * ncomp, else MFREE_ERR_MISMATCH)
 * @param[in] ncomp   components per node: 1 (Laplace, mass) or the dimension
 *                    (elasticity), the same on every rank; else MFREE_ERR_ARG on every
 *                    rank
 * @param[in] nlocal  particles of the set (owned first, then ghosts), >= nowned
 * @param[in] nowned  the owned nodes: particles 0 .. nowned - 1 (>= 0)
 * @param[in] gids    nlocal global ids (borrowed for the call), each in [0, 2^31 / ncomp)
 *                    for PETSc's 32-bit indices; the owned ids of all ranks distinct,
 *                    and every ghost's id owned by some rank (else MFREE_ERR_INPUT on
 *                    every rank)
 * @return MFREE_SUCCESS; MFREE_ERR_NULL; MFREE_ERR_ARG; MFREE_ERR_MISMATCH (unknowns, or
 *         coordinates of another node count); MFREE_ERR_STATE when the assembler is
 *         not set up (the assembler's own failure otherwise); MFREE_ERR_INPUT for
 *         repeated or out-of-range ids, a ghost id that no rank owns, or a non-finite
 *         matrix or load entry of an owned row (naming the node and its id);
 *         MFREE_ERR_ALLOC; MFREE_ERR_INTERNAL with PETSc's message for a PETSc failure
 *         (MFREE_ERR_ARG for a bad option value). On failure on any rank nothing changes on
 *         any rank: a previous setup stays in use.
 */
MFREE_PETSC_API mfree_status_t mfree_petsc_setup(mfree_petsc_t *pk, mfree_assembler_t *as,
                                                 int32_t ncomp, int32_t nlocal,
                                                 int32_t nowned, const int64_t *gids);

/**
 * Assemble again from the assembler of the setup (collective): the matrix values of the
 * owned rows (inserted into the preallocated pattern: no reallocation) and the
 * right-hand side, then the Dirichlet rows of mfree_petsc_set_dirichlet. Call it after
 * mfree_assembler_update, or after changing the assembler's material, coefficient or
 * loads. An assembler set up again with another pattern gives MFREE_ERR_STATE (call
 * mfree_petsc_setup).
 * @param[in] pk  the system
 * @return MFREE_SUCCESS; MFREE_ERR_NULL; MFREE_ERR_STATE before setup or after a new
 *         pattern; MFREE_ERR_INPUT for a non-finite entry; the assembler's failure
 */
MFREE_PETSC_API mfree_status_t mfree_petsc_assemble(mfree_petsc_t *pk);

/**
 * Essential conditions on unknowns of owned nodes (collective), u_d = value_d: after
 * every assembly the rows and columns of these unknowns are zeroed with a unit diagonal
 * (MatZeroRowsColumns), and the right-hand side becomes b - A u_D off them and value_d
 * on them, so a symmetric matrix stays symmetric for conjugate gradients. These fix the
 * nodal parameters: the values at the nodes for interpolating approximants (MPFEM, the
 * particles-only methods), an approximation of the boundary values otherwise (where the
 * assembler's penalty or Nitsche conditions are exact to the quadrature). Copied;
 * replaces the previous set and is applied at once to the assembled system.
 * @param[in] pk      the system
 * @param[in] n       number of constrained unknowns on this rank (>= 0; 0 clears)
 * @param[in] dofs    n local unknowns node * ncomp + component, node < nowned, distinct
 *                    (else MFREE_ERR_INPUT)
 * @param[in] values  n finite values (else MFREE_ERR_INPUT)
 * @return MFREE_SUCCESS; MFREE_ERR_NULL; MFREE_ERR_ARG (n < 0); MFREE_ERR_INPUT;
 *         MFREE_ERR_STATE before setup (nothing changed on failure)
 */
MFREE_PETSC_API mfree_status_t mfree_petsc_set_dirichlet(mfree_petsc_t *pk, int32_t n,
                                                         const int32_t *dofs,
                                                         const double *values);

/**
 * Solve the system with the KSP (collective) from a zero initial guess, and copy the
 * owned part of the solution to u.
 * @param[in]  pk the system
 * @param[out] u  nowned * ncomp values, node * ncomp + component; may be NULL (the
 *                solution stays in the vector of mfree_petsc_get_vectors)
 * @return MFREE_SUCCESS; MFREE_ERR_NULL; MFREE_ERR_STATE before setup;
 *         MFREE_ERR_INTERNAL for a PETSc failure; MFREE_FAIL_SINGULAR (positive) when the
 *         solver diverged or stopped at its iteration limit (the reason in the message
 *         and from mfree_petsc_get_info; u holds the last iterate)
 */
MFREE_PETSC_API mfree_status_t mfree_petsc_solve(mfree_petsc_t *pk, double *u);

/**
 * Facts about the last solve (not collective). Each output may be NULL.
 * @param[in]  pk          the system
 * @param[out] iterations  Krylov iterations
 * @param[out] residual    the solver's last residual norm
 * @param[out] reason      KSPConvergedReason (> 0 converged, < 0 diverged, 0 none yet)
 * @return MFREE_SUCCESS; MFREE_ERR_NULL
 */
MFREE_PETSC_API mfree_status_t mfree_petsc_get_info(const mfree_petsc_t *pk,
                                                    int32_t *iterations, double *residual,
                                                    int32_t *reason);

/**
 * Global numbering (not collective): the first PETSc row of this rank (its owned
 * unknowns are rows first .. first + nowned * ncomp - 1, in local order) and the global
 * number of rows; and, when node_rows is not NULL, the PETSc number of each of the
 * nlocal particles' nodes (its rows are node * ncomp + component).
 * @param[in]  pk         the system
 * @param[out] first      may be NULL
 * @param[out] nglobal    may be NULL
 * @param[out] node_rows  nlocal values, or NULL
 * @return MFREE_SUCCESS; MFREE_ERR_NULL; MFREE_ERR_STATE before setup
 */
MFREE_PETSC_API mfree_status_t mfree_petsc_get_numbering(const mfree_petsc_t *pk,
                                                         int64_t *first, int64_t *nglobal,
                                                         int64_t *node_rows);

/**
 * The PETSc objects, borrowed (valid until the next setup or destroy; do not destroy
 * them): the matrix, the solver, the right-hand side and solution vectors. Hosts may
 * change them (KSPSetType, extra options, MatView); mfree_petsc_assemble overwrites the
 * matrix values of the owned rows and the right-hand side. Not collective. Each output
 * may be NULL.
 * @param[in]  pk   the system
 * @param[out] A    the matrix
 * @param[out] ksp  the Krylov solver
 * @param[out] b    the right-hand side
 * @param[out] x    the solution
 * @return MFREE_SUCCESS; MFREE_ERR_NULL; MFREE_ERR_STATE before setup
 */
MFREE_PETSC_API mfree_status_t mfree_petsc_get_objects(const mfree_petsc_t *pk, Mat *A,
                                                       KSP *ksp, Vec *b, Vec *x);

#ifdef __cplusplus
}
#endif

#endif /* MFREE_PETSC_H */
