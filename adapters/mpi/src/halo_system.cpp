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
  return mfree_system_create_fluid_ranks(ctx, dim, n_owned, n_ghost, ids.data(), width, mfree_halo_exchange_callback,
                                         mfree_halo_allgather, halo, sys);
}

}  // extern "C"
