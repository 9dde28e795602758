/**
 * @file mfree_mpi.h
 * @brief mfree over MPI (libmfree_mpi, pkg-config mfree-mpi, CMake mfree::mfree_mpi): ghost
 * layers and halo exchange for particle sets, migration of particles between ranks with
 * Zoltan partitions (mfree_migration_*), and the elastodynamic and fluid systems on ranks
 * (mfree_halo_create_elastodynamic, mfree_halo_create_fluid).
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

/* ------------------------------------------------------------------------------------ */
/* Migration: owned particles and their fields moved to new owners, partitioned by       */
/* Zoltan (RCB or HSFC) or by the host. docs/mpi.md, "Migration and load balance".       */
/* ------------------------------------------------------------------------------------ */

/** A migration plan: where each owned particle goes, and the fields that travel with it. */
typedef struct mfree_migration mfree_migration_t;

/** Partitioners of mfree_migration_partition (Zoltan's geometric methods). */
typedef MFREE_ENUM(mfree_partitioner) {
  MFREE_PARTITIONER_RCB = 1, /**< recursive coordinate bisection (Zoltan LB_METHOD RCB): box
                                  regions, the default */
  MFREE_PARTITIONER_HSFC = 2 /**< Hilbert space-filling curve (Zoltan LB_METHOD HSFC) */
} mfree_partitioner_t;

/**
 * Create a migration plan on comm (duplicated). Collective over comm. Migration is the
 * host's choice of moment (between integration windows): mfree_migration_partition or
 * _set_owners decides where each owned particle goes, mfree_migration_execute moves it with
 * every registered field; the host then rebuilds its halo (mfree_halo_setup) and particle set.
 * @param[in]  ctx        context for errors (kept alive by the plan)
 * @param[in]  comm       the ranks sharing the particles
 * @param[in]  dim        1, 2 or 3, the same on every rank (else MFREE_ERR_ARG on every rank)
 * @param[out] migration  the new plan; NULL on failure
 * @return MFREE_SUCCESS; MFREE_ERR_NULL (local) for a NULL ctx or migration; MFREE_ERR_ARG,
 *         MFREE_ERR_ALLOC or MFREE_ERR_INTERNAL on every rank when one rank fails or the
 *         ranks pass different dimensions
 */
MFREE_MPI_API mfree_status_t mfree_migration_create(mfree_context_t *ctx, MPI_Comm comm, int32_t dim,
                                                    mfree_migration_t **migration);

/**
 * mfree_migration_create with a Fortran communicator handle (converted by MPI_Comm_f2c).
 * @param[in]  ctx        context for errors
 * @param[in]  fcomm      the Fortran handle (e.g. MPI_COMM_WORLD of `use mpi`)
 * @param[in]  dim        1, 2 or 3
 * @param[out] migration  the new plan
 * @return as mfree_migration_create
 */
MFREE_MPI_API mfree_status_t mfree_migration_create_f(mfree_context_t *ctx, int32_t fcomm, int32_t dim,
                                                      mfree_migration_t **migration);

/**
 * Free a plan. Collective over the plan's communicator, like mfree_halo_destroy (it frees
 * its duplicate communicator and Zoltan's); after MPI_Finalize only the memory is freed.
 * @param[in,out] migration  may be NULL or point to NULL (nothing to do); set to NULL
 * @return MFREE_SUCCESS
 */
MFREE_MPI_API mfree_status_t mfree_migration_destroy(mfree_migration_t **migration);

/**
 * Choose the partitioner of the next mfree_migration_partition. Not collective; every rank
 * must choose the same (checked by the partition call: MFREE_ERR_ARG on every rank).
 * @param[in] migration      the plan
 * @param[in] method         MFREE_PARTITIONER_RCB (the default) or MFREE_PARTITIONER_HSFC
 * @param[in] imbalance_tol  the largest allowed ratio of a rank's count to the mean
 *                           (Zoltan IMBALANCE_TOL), in [1, 10]; the default 1.05
 * @return MFREE_SUCCESS; MFREE_ERR_NULL; MFREE_ERR_ARG for an unknown method or a
 *         tolerance outside [1, 10] (nothing changed)
 */
MFREE_MPI_API mfree_status_t mfree_migration_set_partitioner(mfree_migration_t *migration, int32_t method,
                                                             double imbalance_tol);

/**
 * Register a per-particle field that travels with its particle: positions, velocities,
 * densities, masses, global ids, flags, any strided array. Particle i's item is the
 * item_bytes bytes at (char *)data + i * stride_bytes, copied bit for bit. The array is
 * the caller's; it must hold the capacity given to mfree_migration_execute (the items
 * past the owned ones, ghosts, are not read and are overwritten by arrivals). Not
 * collective; every rank registers the same fields in the same order (item sizes; checked
 * by mfree_migration_execute). After the host reallocates an array, it clears the fields
 * and registers them again.
 * @param[in] migration     the plan
 * @param[in] data          the array (may be NULL only while capacity 0 is passed)
 * @param[in] item_bytes    bytes per particle copied (>= 1), e.g. 3 * sizeof(double)
 * @param[in] stride_bytes  bytes from one particle to the next (>= item_bytes)
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL plan; MFREE_ERR_ARG for item_bytes < 1
 *         or stride_bytes < item_bytes (nothing registered)
 */
MFREE_MPI_API mfree_status_t mfree_migration_add_field(mfree_migration_t *migration, void *data,
                                                       int64_t item_bytes, int64_t stride_bytes);

/**
 * Forget every registered field. Not collective.
 * @param[in] migration  the plan
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL plan
 */
MFREE_MPI_API mfree_status_t mfree_migration_clear_fields(mfree_migration_t *migration);

/**
 * Decide where each owned particle goes by Zoltan's geometric partition of all ranks'
 * positions, and how many particles this rank owns after mfree_migration_execute.
 * Collective. With rebalance = 1 (and on the first call) Zoltan computes new regions,
 * one per rank, balancing the counts to the tolerance of mfree_migration_set_partitioner;
 * with rebalance = 0 the regions of the last rebalance are kept and only the particles
 * that left this rank's region move to the rank whose region holds them (cheaper, no
 * balancing). Positions are read during the call only. Moves nothing.
 * @param[in]  migration  the plan
 * @param[in]  n_owned    owned particles on this rank (>= 0)
 * @param[in]  x          positions, AoS: particle i, component c at x[i*ld + c], finite
 * @param[in]  ld         leading dimension (>= dim)
 * @param[in]  rebalance  1: new regions; 0: the last regions (taken as 1 when there are
 *                        none: the first call, or the partitioner changed since)
 * @param[out] n_new      the particles this rank owns after the migration (may be NULL)
 * @return MFREE_SUCCESS; on every rank alike: MFREE_ERR_ARG (a bad argument, rebalance not
 *         0 or 1, ranks that disagree on the partitioner, its tolerance or rebalance, more
 *         than 2^31 - 1 particles on a rank afterwards), MFREE_ERR_NULL, MFREE_ERR_INPUT (a
 *         non-finite position), MFREE_ERR_UNSUPPORTED (libmfree_mpi built without Zoltan),
 *         MFREE_ERR_ALLOC, MFREE_ERR_INTERNAL (an MPI or Zoltan failure); the message
 *         starts with the failing rank. On failure the previous plan is gone
 */
MFREE_MPI_API mfree_status_t mfree_migration_partition(mfree_migration_t *migration, int32_t n_owned,
                                                       const double *x, int64_t ld, int32_t rebalance,
                                                       int32_t *n_new);

/**
 * Decide where each owned particle goes by the host's choice (its own partitioner), and
 * how many particles this rank owns after mfree_migration_execute. Collective. Moves
 * nothing.
 * @param[in]  migration  the plan
 * @param[in]  n_owned    owned particles on this rank (>= 0)
 * @param[in]  owners     n_owned ranks of the plan's communicator, in [0, size)
 *                        (may be NULL when n_owned is 0); read during the call only
 * @param[out] n_new      the particles this rank owns after the migration (may be NULL)
 * @return MFREE_SUCCESS; on every rank alike: MFREE_ERR_ARG (n_owned < 0, more than
 *         2^31 - 1 particles on a rank afterwards), MFREE_ERR_NULL, MFREE_ERR_INPUT (an
 *         owner out of range: the message names the particle), MFREE_ERR_ALLOC,
 *         MFREE_ERR_INTERNAL; the message starts with the failing rank. On failure the
 *         previous plan is gone
 */
MFREE_MPI_API mfree_status_t mfree_migration_set_owners(mfree_migration_t *migration, int32_t n_owned,
                                                        const int32_t *owners, int32_t *n_new);

/**
 * Move the owned particles as planned, with every registered field, in place: afterwards
 * items [0, n_new) of each field hold this rank's particles, first those it kept (in their
 * order), then those it received (by sending rank, each in its order); every particle's
 * bytes are those it left with. Collective. The checks come first and are agreed: when a
 * rank's capacity is below its n_new, or the ranks registered different fields, every rank
 * returns the same status with nothing moved, and the plan is kept (grow the arrays,
 * register them again, call again). Then one MPI_Alltoallv of packed records.
 * @param[in] migration  a plan from mfree_migration_partition or _set_owners, not yet executed
 * @param[in] capacity   particles each registered array holds (>= n_new, the size needed,
 *                       from the plan call or mfree_migration_get_counts; and >= the
 *                       plan's n_owned, which the arrays hold)
 * @return MFREE_SUCCESS; on every rank alike: MFREE_ERR_STATE (no plan, or executed
 *         already), MFREE_ERR_ARG (a capacity below n_new: "capacity C is below the N
 *         particles this rank owns after the migration", or below n_owned; ranks whose registered fields
 *         differ in number or item sizes: "ranks disagree on the registered fields"),
 *         MFREE_ERR_NULL (a field without data and capacity > 0), MFREE_ERR_ALLOC,
 *         MFREE_ERR_INTERNAL; the message starts with the failing rank
 */
MFREE_MPI_API mfree_status_t mfree_migration_execute(mfree_migration_t *migration, int32_t capacity);

/**
 * The current plan's counts on this rank.
 * @param[in]  migration  a plan from mfree_migration_partition or _set_owners
 * @param[out] n_owned    owned particles before the migration (may be NULL)
 * @param[out] n_new      owned particles after it (may be NULL)
 * @param[out] n_send     particles this rank sends away (may be NULL)
 * @param[out] n_recv     particles it receives (may be NULL)
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL plan; MFREE_ERR_STATE without a plan
 */
MFREE_MPI_API mfree_status_t mfree_migration_get_counts(const mfree_migration_t *migration, int32_t *n_owned,
                                                        int32_t *n_new, int64_t *n_send, int64_t *n_recv);

/**
 * The destination rank of each owned particle of the current plan (this rank for those it
 * keeps), for hosts that move data of their own along.
 * @param[in]  migration  a plan from mfree_migration_partition or _set_owners
 * @param[out] owners     n_owned values (may be NULL when n_owned is 0)
 * @param[in]  capacity   values owners holds (>= n_owned, else MFREE_ERR_ARG with nothing
 *                        written and the message giving n_owned)
 * @return MFREE_SUCCESS; MFREE_ERR_NULL; MFREE_ERR_STATE without a plan; MFREE_ERR_ARG
 */
MFREE_MPI_API mfree_status_t mfree_migration_get_owners(const mfree_migration_t *migration, int32_t *owners,
                                                        int64_t capacity);

/**
 * The context of a plan, for bindings that check arguments themselves.
 * @param[in]  migration  the plan
 * @param[out] ctx        its context, borrowed
 * @return MFREE_SUCCESS; MFREE_ERR_NULL (without a message) for a NULL handle or output
 */
MFREE_MPI_API mfree_status_t mfree_migration_get_context(const mfree_migration_t *migration,
                                                         mfree_context_t **ctx);

/**
 * Hand a failure found on this rank before a collective call to that call, as
 * mfree_halo_set_pending_error does for a halo plan: the last failure on the plan's
 * context becomes this rank's outcome of the next mfree_migration_partition, _set_owners
 * or _execute, which reads and writes none of its arrays and returns it on every rank.
 * Not collective.
 * @param[in] migration  the plan
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL handle; MFREE_ERR_STATE when the
 *         context holds no failure
 */
MFREE_MPI_API mfree_status_t mfree_migration_set_pending_error(mfree_migration_t *migration);

/* ------------------------------------------------------------------------------------ */
/* Systems on ranks: the collective callbacks of mfree_system_create_elastodynamic_ranks  */
/* over a halo plan. docs/mpi.md, "Systems on ranks".                                      */
/* ------------------------------------------------------------------------------------ */

/**
 * The plan's communicator (a duplicate of the one given at creation), for collective
 * calls of the host that must meet the plan's ranks.
 * @param[in]  halo  the plan
 * @param[out] comm  its communicator, borrowed: the plan frees it
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL handle or output
 */
MFREE_MPI_API mfree_status_t mfree_halo_get_communicator(const mfree_halo_t *halo, MPI_Comm *comm);

/**
 * mfree_halo_exchange as an mfree_exchange_fn, for systems on ranks
 * (mfree_system_create_elastodynamic_ranks with user = the plan). Collective.
 * @param[in]     halo   the plan (an mfree_halo_t *)
 * @param[in]     ncomp  components per particle, the same on every rank
 * @param[in,out] field  owned then ghost items of ld doubles
 * @param[in]     ld     leading dimension (>= ncomp)
 * @return as mfree_halo_exchange: the same status on every rank
 */
MFREE_MPI_API mfree_status_t mfree_halo_exchange_callback(void *halo, int32_t ncomp, double *field,
                                                          int64_t ld);

/**
 * An all-gather over the plan's communicator as an mfree_allgather_fn: every rank's n
 * doubles concatenated in rank order (MPI_Allgather of the counts and capacities, then
 * MPI_Allgatherv; the values' bits are moved, never combined). Collective.
 * @param[in]  halo   the plan (an mfree_halo_t *)
 * @param[in]  in     this rank's n values (may be NULL when n is 0)
 * @param[in]  n      this rank's count (>= 0)
 * @param[out] out    cap doubles, written when every rank's cap is at least *total
 * @param[in]  cap    capacity of out (0: ask for the total only)
 * @param[out] total  the sum of the ranks' n
 * @return MFREE_SUCCESS; on every rank alike: MFREE_ERR_NULL (a NULL plan: locally; a
 *         NULL total or NULL in with n > 0), MFREE_ERR_ARG (a negative n, more than
 *         2^31 - 1 values), MFREE_ERR_INTERNAL (an MPI failure); the message starts with
 *         the failing rank
 */
MFREE_MPI_API mfree_status_t mfree_halo_allgather(void *halo, const double *in, int64_t n,
                                                  double *out, int64_t cap, int64_t *total);

/**
 * mfree_system_create_elastodynamic_ranks through this plan: the ghosts' displacements
 * by mfree_halo_exchange, the boundary rows' data by mfree_halo_allgather; the system is
 * created on the plan's context and keeps a pointer to the plan, which must outlive it
 * (destroy the system first). Collective; the assembler's particle set holds the plan's
 * particles in its order (n_owned owned, then the n_ghost ghosts, with the plan's global
 * ids: mfree_halo_get_global_ids).
 * @param[in]  halo     a set-up plan
 * @param[in]  as       a set-up collocation or Galerkin stiffness assembler over the
 *                      plan's particles (kept alive), or NULL (every rank then fails)
 * @param[in]  density  rho > 0, the same on every rank
 * @param[out] sys      the new system
 * @return as mfree_system_create_elastodynamic_ranks; MFREE_ERR_NULL (local) for a NULL
 *         plan or output
 */
MFREE_MPI_API mfree_status_t mfree_halo_create_elastodynamic(mfree_halo_t *halo, mfree_assembler_t *as,
                                                             double density, mfree_system_t **sys);

/**
 * mfree_system_create_fluid_ranks through this plan: the plan's owned particles and
 * ghosts, in its order and with its global ids, the ghosts' states by
 * mfree_halo_exchange, the reductions by mfree_halo_allgather; created on the plan's
 * context, keeping a pointer to the plan, which must outlive it (destroy the system
 * first). Collective. The per-particle setters of the system take the plan's
 * n_owned + n_ghost items (fill the ghosts' masses with mfree_halo_exchange). The system
 * rebuilds its ghosts through the plan when particles move too far
 * (mfree_halo_rebuild_callback, set with mfree_system_set_halo_rebuild: the plan is set
 * up again inside the run), and migrates with mfree_halo_migrate_fluid.
 * @param[in]  halo   a set-up plan
 * @param[in]  dim    2 or 3 (the plan's dimension)
 * @param[in]  width  the width the plan was set up with (at least two support radii; four with dummies and density diffusion)
 * @param[out] sys    the new system
 * @return as mfree_system_create_fluid_ranks; MFREE_ERR_NULL (local) for a NULL plan or
 *         output
 */
MFREE_MPI_API mfree_status_t mfree_halo_create_fluid(mfree_halo_t *halo, int32_t dim, double width,
                                                     mfree_system_t **sys);

/**
 * mfree_halo_setup as an mfree_halo_rebuild_fn (mfree_system_set_halo_rebuild), for a
 * fluid on ranks created over this plan with mfree_system_create_fluid_ranks
 * (mfree_halo_create_fluid registers it itself): the plan set up again around the given
 * owned particles and ids with the system's width. Collective.
 * @param[in]  halo        the plan (an mfree_halo_t *)
 * @param[in]  n_owned     owned particles
 * @param[in]  x           their positions, AoS
 * @param[in]  ld          leading dimension
 * @param[in]  global_ids  their global ids
 * @param[in]  width       the halo width
 * @param[out] n_ghost     the plan's new ghost count
 * @param[out] all_ids     the plan's global ids (owned, then ghosts), borrowed until its
 *                         next setup
 * @return as mfree_halo_setup: the same status on every rank
 */
MFREE_MPI_API mfree_status_t mfree_halo_rebuild_callback(void *halo, int32_t n_owned, const double *x,
                                                         int64_t ld, const int64_t *global_ids, double width,
                                                         int32_t *n_ghost, const int64_t **all_ids);

/**
 * Migrate a fluid on ranks between integration windows: Zoltan's partition of the owned
 * particles' positions (migration's partitioner; rebalance as in mfree_migration_partition)
 * chooses their owners, and the particles move there with their state (from y), rest
 * densities, masses and global ids (mfree_system_move_particles); the plan is set up again
 * around the new owned particles with the system's width, and the system re-seated on
 * them, every option kept. Ghosts are also rebuilt during an integration when particles
 * move too far (mfree_system_set_halo_rebuild), so migration is needed only for the
 * balance of the counts and the size of the halo. Afterwards y holds this rank's new state
 * ((2 dim + 1) n_new doubles: *neq), the owned particles in the order of
 * mfree_migration_execute (those kept, then those received), the plan's global ids
 * (mfree_halo_get_global_ids) name them; the results of the run stay bitwise those of
 * one rank. A host integrating with its own vectors re-creates them with the new length
 * (SUNDIALS: mfree_sundials_mpi_create_vector and ERKStepReInit, or a new integrator).
 * The plan's registered fields are cleared. Collective.
 * @param[in]     halo       the plan the system was created over (mfree_halo_create_fluid)
 * @param[in]     migration  a migration plan on the same ranks
 * @param[in]     sys        the fluid on ranks
 * @param[in]     rebalance  1: new regions; 0: the last regions (as mfree_migration_partition)
 * @param[in,out] y          this rank's state in ((2 dim + 1) n_owned doubles), the new one out
 * @param[in]     capacity   doubles y holds (at least the current state's)
 * @param[out]    neq        the new state's length (set also when capacity is too small)
 * @return MFREE_SUCCESS; on every rank alike: MFREE_ERR_ARG ("capacity C is below the N
 *         doubles of this rank's state after the move": nothing moved, grow y to *neq and
 *         call again; a system that is not a fluid over this plan; the partition's
 *         argument failures), MFREE_ERR_NULL (a NULL system, neq, or y with owned
 *         particles), MFREE_ERR_STATE (a plan that is not set up), the partition's,
 *         the migration's and the halo setup's failures (after a failed halo setup the
 *         system returns MFREE_ERR_STATE: create it again); MFREE_ERR_NULL (local) for a
 *         NULL plan
 */
MFREE_MPI_API mfree_status_t mfree_halo_migrate_fluid(mfree_halo_t *halo, mfree_migration_t *migration,
                                                      mfree_system_t *sys, int32_t rebalance, double *y,
                                                      int64_t capacity, int64_t *neq);

#ifdef __cplusplus
}
#endif

#endif /* MFREE_MPI_H */
