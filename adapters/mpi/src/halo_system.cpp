// Systems on ranks through a halo plan: the two collective callbacks of the core's
// systems on ranks (mfree_exchange_fn, mfree_allgather_fn) over the plan, from the
// plan's public API and its communicator.
#include <cstdio>
#include <limits>
#include <vector>

#include "collective.hpp"
#include "mfree_mpi.h"

namespace {

mfree_status_t fail(mfree_context_t *ctx, mfree_status_t st, const char *msg) {
  char text[400];
  std::snprintf(text, sizeof text, "mfree_halo_allgather: %s", msg);
  return mfree_context_set_error(ctx, st, text);
}

// mfree_particles_move_fn over a migration plan that has partitioned: the records
// travel as one registered field.
mfree_status_t move_records(void *migration, int32_t nrec, int32_t n_owned, double *records, int32_t n_new) {
  mfree_migration_t *m = static_cast<mfree_migration_t *>(migration);
  const int64_t bytes = static_cast<int64_t>(nrec) * static_cast<int64_t>(sizeof(double));
  mfree_migration_clear_fields(m);
  mfree_status_t st = mfree_migration_add_field(m, records, bytes, bytes);
  if (st == MFREE_SUCCESS) st = mfree_migration_execute(m, n_owned > n_new ? n_owned : n_new);
  mfree_migration_clear_fields(m);
  return st;
}

}  // namespace

extern "C" {

mfree_status_t mfree_halo_exchange_callback(void *halo, int32_t ncomp, double *field, int64_t ld) {
  return mfree_halo_exchange(static_cast<mfree_halo_t *>(halo), ncomp, field, ld);
}

mfree_status_t mfree_halo_allgather(void *halo, const double *in, int64_t n, double *out, int64_t cap,
                                    int64_t *total) {
  const mfree_halo_t *h = static_cast<const mfree_halo_t *>(halo);
  mfree_context_t *ctx = nullptr;
  MPI_Comm comm = MPI_COMM_NULL;
  if (mfree_halo_get_context(h, &ctx) != MFREE_SUCCESS || mfree_halo_get_communicator(h, &comm) != MFREE_SUCCESS)
    return MFREE_ERR_NULL;
  int size = 1, rank = 0;
  MPI_Comm_size(comm, &size);
  MPI_Comm_rank(comm, &rank);
  // this rank's count, capacity and argument fault (or the failure a binding handed
  // over, flagged), seen by every rank: one outcome
  std::string pending;
  const mfree_status_t handed = mfree_mpi_detail::take_pending(static_cast<mfree_halo_t *>(halo), pending);
  const int64_t bad = handed != MFREE_SUCCESS ? handed
                      : !total                ? MFREE_ERR_NULL
                      : n < 0                 ? MFREE_ERR_ARG
                      : (n > 0 && !in)        ? MFREE_ERR_NULL
                                              : 0;
  int64_t mine[4] = {n, cap, bad, handed != MFREE_SUCCESS};
  std::vector<int64_t> all;
  try {
    all.resize(4 * static_cast<size_t>(size));
  } catch (...) {
    return fail(ctx, MFREE_ERR_ALLOC, "out of memory");  // (before any rank waits: none can go on)
  }
  if (MPI_Allgather(mine, 4, MPI_INT64_T, all.data(), 4, MPI_INT64_T, comm) != MPI_SUCCESS)
    return fail(ctx, MFREE_ERR_INTERNAL, "MPI_Allgather failed");
  for (int p = 0; p < size; ++p)
    if (all[4 * p + 2] != 0) {
      char msg[360];
      if (all[4 * p + 3])
        std::snprintf(msg, sizeof msg, "rank %d: %s", p,
                      p == rank ? pending.c_str() : "a binding's check of its arrays failed there");
      else
        std::snprintf(msg, sizeof msg, "rank %d: %s", p,
                      all[4 * p + 2] == MFREE_ERR_ARG ? "a negative count" : "a NULL total, or NULL values with n > 0");
      return fail(ctx, static_cast<mfree_status_t>(all[4 * p + 2]), msg);
    }
  int64_t sum = 0;
  bool room = true;
  for (int p = 0; p < size; ++p) sum += all[4 * p];
  for (int p = 0; p < size; ++p) room = room && all[4 * p + 1] >= sum;
  *total = sum;
  if (!room) return MFREE_SUCCESS;  // the total only
  if (sum > std::numeric_limits<int>::max()) return fail(ctx, MFREE_ERR_ARG, "more than 2^31 - 1 values");
  std::vector<int> counts(size), displs(size);
  for (int p = 0, off = 0; p < size; ++p) {
    counts[p] = static_cast<int>(all[4 * p]);
    displs[p] = off;
    off += counts[p];
  }
  if (MPI_Allgatherv(in, static_cast<int>(n), MPI_DOUBLE, out, counts.data(), displs.data(), MPI_DOUBLE, comm) !=
      MPI_SUCCESS)
    return fail(ctx, MFREE_ERR_INTERNAL, "MPI_Allgatherv failed");
  return MFREE_SUCCESS;
}

mfree_status_t mfree_halo_create_elastodynamic(mfree_halo_t *halo, mfree_assembler_t *as, double density,
                                               mfree_system_t **sys) {
  mfree_context_t *ctx = nullptr;
  if (mfree_halo_get_context(halo, &ctx) != MFREE_SUCCESS) return MFREE_ERR_NULL;
  return mfree_system_create_elastodynamic_ranks(ctx, as, density, mfree_halo_exchange_callback,
                                                 mfree_halo_allgather, halo, sys);
}

mfree_status_t mfree_halo_create_fluid(mfree_halo_t *halo, int32_t dim, double width, mfree_system_t **sys) {
  mfree_context_t *ctx = nullptr;
  if (mfree_halo_get_context(halo, &ctx) != MFREE_SUCCESS || !sys) return MFREE_ERR_NULL;
  int32_t n_owned = 0, n_ghost = 0;
  mfree_status_t st = mfree_halo_get_size(halo, &n_owned, &n_ghost);
  std::vector<int64_t> ids;
  if (st == MFREE_SUCCESS) {
    // (a plan that is not set up fails alike on every rank: the ids come from its setup)
    ids.resize(static_cast<size_t>(n_owned) + n_ghost + 1);
    st = mfree_halo_get_global_ids(halo, ids.data());
  }
  if (st != MFREE_SUCCESS) return st;
  st = mfree_system_create_fluid_ranks(ctx, dim, n_owned, n_ghost, ids.data(), width, mfree_halo_exchange_callback,
                                       mfree_halo_allgather, halo, sys);
  // (on every rank alike: creation is agreed)
  if (st == MFREE_SUCCESS) st = mfree_system_set_halo_rebuild(*sys, mfree_halo_rebuild_callback);
  return st;
}

mfree_status_t mfree_halo_rebuild_callback(void *halo, int32_t n_owned, const double *x, int64_t ld,
                                           const int64_t *global_ids, double width, int32_t *n_ghost,
                                           const int64_t **all_ids) {
  mfree_halo_t *h = static_cast<mfree_halo_t *>(halo);
  const mfree_status_t st = mfree_halo_setup(h, n_owned, x, ld, global_ids, width);
  if (st != MFREE_SUCCESS) return st;
  if (!n_ghost || !all_ids) return MFREE_ERR_NULL;
  mfree_halo_get_size(h, nullptr, n_ghost);
  *all_ids = mfree_mpi_detail::halo_ids(h);
  return MFREE_SUCCESS;
}

mfree_status_t mfree_halo_migrate_fluid(mfree_halo_t *halo, mfree_migration_t *migration, mfree_system_t *sys,
                                        int32_t rebalance, double *y, int64_t capacity, int64_t *neq) {
  mfree_context_t *ctx = nullptr, *mctx = nullptr;
  if (mfree_halo_get_context(halo, &ctx) != MFREE_SUCCESS ||
      mfree_migration_get_context(migration, &mctx) != MFREE_SUCCESS)
    return MFREE_ERR_NULL;
  // this rank's checks, handed to the partition so that every rank returns their outcome
  int32_t dim = 0, n_owned = 0, sys_neq = 0;
  char msg[300] = "";
  mfree_status_t bad = MFREE_SUCCESS;
  if (!sys || !neq) {
    bad = MFREE_ERR_NULL;
    std::snprintf(msg, sizeof msg, "mfree_halo_migrate_fluid: %s is NULL", !sys ? "the system" : "neq");
  } else if (mfree_halo_get_size(halo, &n_owned, nullptr) != MFREE_SUCCESS) {
    bad = MFREE_ERR_STATE;
    std::snprintf(msg, sizeof msg, "mfree_halo_migrate_fluid: the halo plan is not set up");
  } else if (mfree_system_get_dimension(sys, &dim, nullptr) != MFREE_SUCCESS ||
             mfree_system_get_size(sys, &sys_neq) != MFREE_SUCCESS ||
             static_cast<int64_t>(sys_neq) != static_cast<int64_t>(2 * dim + 1) * n_owned) {
    bad = MFREE_ERR_ARG;
    std::snprintf(msg, sizeof msg,
                  "mfree_halo_migrate_fluid: the system is not a fluid over this plan's %d owned particles",
                  static_cast<int>(n_owned));
  } else if (!y && n_owned > 0) {
    bad = MFREE_ERR_NULL;
    std::snprintf(msg, sizeof msg, "mfree_halo_migrate_fluid: y is NULL");
  } else if (capacity < sys_neq) {
    bad = MFREE_ERR_ARG;
    std::snprintf(msg, sizeof msg, "mfree_halo_migrate_fluid: capacity %lld is below the %d doubles of this rank's state",
                  static_cast<long long>(capacity), static_cast<int>(sys_neq));
  }
  if (bad != MFREE_SUCCESS) {
    mfree_context_set_error(mctx, bad, msg);
    mfree_migration_set_pending_error(migration);
    n_owned = 0;  // (the partition reads nothing then)
  }
  int32_t n_new = 0;
  mfree_status_t st = mfree_migration_partition(migration, n_owned, y, dim > 0 ? dim : 1, rebalance, &n_new);
  if (st != MFREE_SUCCESS) {
    // (the partition's message is on the plan's context; the host reads the halo's)
    char m[600] = "";
    mfree_context_get_last_error(mctx, nullptr, m, sizeof m);
    if (mctx != ctx) mfree_context_set_error(ctx, st, m);
    return st;
  }
  *neq = static_cast<int64_t>(2 * dim + 1) * n_new;
  return mfree_system_move_particles(sys, n_new, move_records, migration, y, capacity);
}

}  // extern "C"
