/**
 * @file mfree_mpi.h
 * @brief Ghost layers and halo exchange over MPI for mfree particle sets (libmfree_mpi,
 * pkg-config mfree-mpi, CMake mfree::mfree_mpi).
 *
 * For hosts without halo code of their own. Each rank gives its owned particles
 * (positions, optional global ids) and a halo width; the plan finds the ghosts (every
 * particle of another rank within the width of this rank's owned particles' bounding
 * box, a superset of what the halo contract asks), numbers the owned particles globally
 * when the host has no ids (offsets by an exclusive scan), and exchanges any per-particle
 * field from owners to ghosts with one MPI neighbourhood collective
 * (MPI_Neighbor_alltoallv over a graph of the ranks whose boxes are within the width).
 * Memory per rank is O(owned + ghosts) plus one bounding box per rank.
 *
 * Arrays on a rank hold n_owned + n_ghost items: the owned particles first, in the host's
 * order, then the ghosts in the plan's order (mfree_halo_get_global_ids names them).
 * Give them to mfree_particles_* with mfree_particles_set_num_ghost(ps, n_ghost) and
 * mfree_particles_set_global_ids: the owned particles' results are then bitwise those of
 * a one-rank run.
 *
 * Collective calls (create, setup, exchange) must be called by every rank of the
 * communicator. Their errors are agreed: when one rank fails (bad argument, duplicate
 * global id anywhere, out of memory) or the ranks pass different values of an argument
 * that must be common (dim, width, ncomp), every rank returns the same status and its
 * context holds a message naming the failing rank and its reason; no rank is left waiting. Only
 * a NULL handle or context is reported locally (MFREE_ERR_NULL), as it has no
 * communicator. The core library never calls MPI; this one does. docs/mpi.md shows how
 * a host runs on ranks and which ghosts each method needs.
 */
#ifndef MFREE_MPI_H
#define MFREE_MPI_H

#include <mpi.h>
#include <stdint.h>

#include "mfree.h"

#ifdef __cplusplus
extern "C" {
#endif

#if defined(_WIN32)
#if defined(MFREE_MPI_BUILDING)
#define MFREE_MPI_API __declspec(dllexport)
#else
#define MFREE_MPI_API
#endif
#elif defined(__GNUC__) && __GNUC__ >= 4
#define MFREE_MPI_API __attribute__((visibility("default")))
#else
#define MFREE_MPI_API
#endif

/** A halo plan: the ghost layer of one rank and its exchange pattern. */
typedef struct mfree_halo mfree_halo_t;

/**
 * Create a halo plan on comm (duplicated, so that the plan's messages never meet the
 * host's). Collective over comm.
 * @param[in]  ctx   context for errors (kept alive by the plan)
 * @param[in]  comm  the ranks sharing the particles
 * @param[in]  dim   1, 2 or 3, the same on every rank (else MFREE_ERR_ARG on every rank)
 * @param[out] halo  the new plan; NULL on failure
 * @return MFREE_SUCCESS; MFREE_ERR_NULL (local) for a NULL ctx or halo; MFREE_ERR_ARG,
 *         MFREE_ERR_ALLOC or MFREE_ERR_INTERNAL on every rank when one rank fails or the
 *         ranks pass different dimensions
 */
MFREE_MPI_API mfree_status_t mfree_halo_create(mfree_context_t *ctx, MPI_Comm comm, int32_t dim,
                                               mfree_halo_t **halo);

/**
 * mfree_halo_create with a Fortran communicator handle (converted by MPI_Comm_f2c), for
 * hosts that hold communicators as Fortran integers.
 * @param[in]  ctx    context for errors
 * @param[in]  fcomm  the Fortran handle (e.g. MPI_COMM_WORLD of `use mpi`)
 * @param[in]  dim    1, 2 or 3
 * @param[out] halo   the new plan
 * @return as mfree_halo_create
 */
MFREE_MPI_API mfree_status_t mfree_halo_create_f(mfree_context_t *ctx, int32_t fcomm, int32_t dim,
                                                 mfree_halo_t **halo);

/**
 * Free a plan. Collective over the plan's communicator: the plan holds a duplicate of
 * comm and, once set up, a neighbourhood graph, which it frees with MPI_Comm_free, a
 * collective call in the MPI standard. Every rank of comm destroys the plan (a rank
 * must not skip it, nor destroy a plan that others keep), and a host with several plans
 * destroys them in the same order on every rank, like any collective call. After
 * MPI_Finalize (MPI_Finalized) only the plan's memory is freed, on each rank alone: its
 * communicators went with MPI, so a host whose clean-up runs after MPI_Finalize (C++
 * destructors, Fortran finalization at program end) may still call it.
 * @param[in,out] halo  may be NULL or point to NULL (nothing to do); set to NULL
 * @return MFREE_SUCCESS
 */
MFREE_MPI_API mfree_status_t mfree_halo_destroy(mfree_halo_t **halo);

/**
 * Build (or rebuild, after particles moved) the ghost layer and the exchange plan.
 * Collective. On failure the previous plan is gone: the getters and exchange return
 * MFREE_ERR_STATE until a setup succeeds.
 * @param[in] halo     the plan
 * @param[in] n_owned  owned particles on this rank (>= 0)
 * @param[in] x        positions, AoS: particle i, component c at x[i*ld + c], finite;
 *                     read during the call only
 * @param[in] ld       leading dimension (>= dim)
 * @param[in] ids      n_owned global ids (>= 0, unique over all ranks; copied), or NULL:
 *                     the owned particles are numbered offset + i, offset the exclusive
 *                     scan of n_owned (mfree_halo_get_global_offset); every rank with
 *                     particles gives ids, or none does (else MFREE_ERR_ARG)
 * @param[in] width    halo width (finite, > 0), the same on every rank (else MFREE_ERR_ARG
 *                     on every rank, naming two ranks and their widths): at least the
 *                     largest distance at which a particle of another rank can be a
 *                     neighbour (kappa times the largest support over all ranks), plus
 *                     twice the largest displacement before the next setup for plans
 *                     kept while particles move
 * @return MFREE_SUCCESS; on every rank alike: MFREE_ERR_ARG, MFREE_ERR_NULL,
 *         MFREE_ERR_INPUT (non-finite position, negative id, an id repeated anywhere:
 *         the message names it and the ranks), MFREE_ERR_ALLOC, MFREE_ERR_INTERNAL (an
 *         MPI failure); the message starts with the failing rank
 */
MFREE_MPI_API mfree_status_t mfree_halo_setup(mfree_halo_t *halo, int32_t n_owned,
                                              const double *x, int64_t ld, const int64_t *ids,
                                              double width);

/**
 * Owned and ghost counts of this rank.
 * @param[in]  halo     a set-up plan
 * @param[out] n_owned  owned particles (may be NULL)
 * @param[out] n_ghost  ghosts (may be NULL)
 * @return MFREE_SUCCESS; MFREE_ERR_STATE before a successful setup
 */
MFREE_MPI_API mfree_status_t mfree_halo_get_size(const mfree_halo_t *halo, int32_t *n_owned,
                                                 int32_t *n_ghost);

/**
 * Global ids of this rank's particles: the owned ones in the host's order, then the
 * ghosts in the plan's order.
 * @param[in]  halo  a set-up plan
 * @param[out] ids   n_owned + n_ghost values
 * @return MFREE_SUCCESS; MFREE_ERR_STATE before a successful setup; MFREE_ERR_NULL
 */
MFREE_MPI_API mfree_status_t mfree_halo_get_global_ids(const mfree_halo_t *halo, int64_t *ids);

/**
 * The exclusive scan of the owned counts (this rank's first number when the plan
 * numbered the particles) and their sum over all ranks.
 * @param[in]  halo    a set-up plan
 * @param[out] offset  the owned particles of the lower ranks (may be NULL)
 * @param[out] total   all owned particles (may be NULL)
 * @return MFREE_SUCCESS; MFREE_ERR_STATE before a successful setup
 */
MFREE_MPI_API mfree_status_t mfree_halo_get_global_offset(const mfree_halo_t *halo,
                                                          int64_t *offset, int64_t *total);

/**
 * The plan's size: one exchange of ncomp doubles sends 8 ncomp n_send bytes from this
 * rank to its neighbours and receives 8 ncomp n_recv.
 * @param[in]  halo         a set-up plan
 * @param[out] n_neighbors  ranks this one exchanges with (may be NULL)
 * @param[out] n_send       particle copies sent per exchange (may be NULL)
 * @param[out] n_recv       particle copies received (the ghosts; may be NULL)
 * @return MFREE_SUCCESS; MFREE_ERR_STATE before a successful setup
 */
MFREE_MPI_API mfree_status_t mfree_halo_get_plan(const mfree_halo_t *halo, int32_t *n_neighbors,
                                                 int64_t *n_send, int64_t *n_recv);

/**
 * The context a plan was created on, for bindings that check arguments themselves.
 * @param[in]  halo  the plan
 * @param[out] ctx   its context, borrowed: the plan keeps it alive; never destroy it
 * @return MFREE_SUCCESS; MFREE_ERR_NULL (without a message) for a NULL handle or output
 */
MFREE_MPI_API mfree_status_t mfree_halo_get_context(const mfree_halo_t *halo, mfree_context_t **ctx);

/**
 * Hand a failure found on this rank before a collective call to that call, for bindings
 * that check what the C API cannot see (the Fortran module: an array too short): the
 * last failure recorded on the plan's context (its status and message, e.g. by
 * mfree_context_set_error) becomes this rank's outcome of the next mfree_halo_setup or
 * mfree_halo_exchange on the plan. That call reads and writes none of its arrays, takes
 * part in the agreement, and returns the status on every rank with this rank's message
 * ("rank R: <message>", a leading "mfree_...: " of the message dropped), so that no
 * rank waits for one that gave up. Not collective.
 * @param[in] halo  the plan
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL handle; MFREE_ERR_STATE when the
 *         context holds no failure (nothing is handed over)
 */
MFREE_MPI_API mfree_status_t mfree_halo_set_pending_error(mfree_halo_t *halo);

/**
 * Forward exchange: the owners' values of a per-particle field written into the ghost
 * items. Collective: one MPI_Allreduce of three (value, rank) pairs that agrees on the
 * status and on ncomp, then one MPI_Neighbor_alltoallv; no allocation once the buffers
 * have grown to the largest ncomp used. A rank that fails its checks, or passes another
 * ncomp than the others (another message size), makes every rank return the same status
 * and message before any data moves; ld is local (it sets the layout in memory, not the
 * message).
 * @param[in]     halo   a set-up plan
 * @param[in]     ncomp  components per particle (>= 1), the same on every rank
 * @param[in,out] field  AoS, n_owned + n_ghost items of ld doubles: items [0, n_owned)
 *                       are read, components [0, ncomp) of the ghost items written
 * @param[in]     ld     leading dimension (>= ncomp); may differ between ranks
 * @return MFREE_SUCCESS; on every rank alike: MFREE_ERR_STATE before a successful
 *         setup; MFREE_ERR_ARG (a bad argument, or ranks that disagree on ncomp: "ranks
 *         disagree on ncomp", naming two ranks and their values), MFREE_ERR_NULL,
 *         MFREE_ERR_ALLOC; the message starts with the failing rank. MFREE_ERR_INTERNAL
 *         for an MPI failure (of the data exchange: on the ranks where it failed)
 */
MFREE_MPI_API mfree_status_t mfree_halo_exchange(mfree_halo_t *halo, int32_t ncomp, double *field,
                                                 int64_t ld);

/**
 * The ghosts' correction records from their owners, for the ghost side of pair gradients
 * (mfree_approximant_get_pair_gradients and _antisymmetric) bitwise equal to one rank's:
 * each rank's mfree_approximant_get_correction of its owned particles, exchanged like a
 * field, given to mfree_approximant_set_ghost_correction. Collective. Call it after every
 * mfree_approximant_setup or _update of a (they drop the ghosts' records). The records
 * are kept in a buffer of the plan (n_owned + n_ghost records), reused.
 * @param[in]     halo  a set-up plan
 * @param[in,out] a     a set-up approximant at a particle set that holds the plan's
 *                      particles in its order (n_owned owned, then the n_ghost ghosts:
 *                      else MFREE_ERR_ARG), of one method on every rank, with correction
 *                      data (MFREE_ERR_UNSUPPORTED for SPH, which needs none, SSPH, MLS and
 *                      RKPM of order 3, ...)
 * @return MFREE_SUCCESS; on every rank alike: the failures of mfree_approximant_get_correction
 *         and _set_ghost_correction on any rank, MFREE_ERR_STATE before a successful setup
 *         of the plan, MFREE_ERR_ARG, MFREE_ERR_NULL, MFREE_ERR_ALLOC, MFREE_ERR_INTERNAL;
 *         the message starts with the failing rank
 */
MFREE_MPI_API mfree_status_t mfree_halo_exchange_correction(mfree_halo_t *halo, mfree_approximant_t *a);

#ifdef __cplusplus
}
#endif

#endif /* MFREE_MPI_H */
