// libmfree_mpi: ghost layers and forward halo exchange over MPI neighbourhood
// collectives. Collective calls agree on their status (one MPI_Allreduce of the worst
// status and its rank, then that rank's message broadcast) before any step that would
// make the others wait, so that a failure on one rank never leaves another blocked.
#include "mfree_mpi.h"

#include "collective.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <limits>
#include <new>
#include <string>
#include <vector>

struct mfree_halo {
  mfree_context_t *ctx = nullptr;
  mfree_matrix_t *ctx_ref = nullptr;  // a 0 x 0 matrix: holds a reference on ctx
  MPI_Comm comm = MPI_COMM_NULL;      // the host's communicator, duplicated
  MPI_Comm graph = MPI_COMM_NULL;     // neighbour graph of the current plan
  int rank = 0, size = 1, dim = 0;
  bool ready = false;
  bool ids_checked = false;  // the owned ids in ids[0, n_owned) passed the global check
  mfree_mpi_detail::Pending pending;  // mfree_halo_set_pending_error: the next collective
                                      // call's outcome on this rank
  int32_t n_owned = 0, n_ghost = 0;
  int64_t offset = 0, total = 0;
  std::vector<int> nbrs;                          // neighbour ranks, ascending
  std::vector<int> scount, sdispl, rcount, rdispl;  // particles per neighbour
  std::vector<int> sc, sd, rc, rd;                // the same times ncomp (per exchange)
  std::vector<int32_t> send_idx;                  // owned particles sent, by neighbour
  std::vector<int64_t> ids;                       // owned then ghost global ids
  std::vector<double> sbuf, rbuf, boxes;
  std::vector<double> corr;  // correction records, owned then ghost (exchange_correction)
};

namespace {

using namespace mfree_mpi_detail;

// The agreement of collective.hpp over the plan's communicator.
mfree_status_t agree(mfree_halo_t *h, const char *fn, const Local &l, Loc *vals = nullptr, int nv = 0) noexcept {
  return mfree_mpi_detail::agree(h->ctx, h->comm, h->rank, fn, l, vals, nv);
}

mfree_status_t same_everywhere(mfree_halo_t *h, const char *fn, const char *what, const Loc &lo,
                               const Loc &neg_hi) noexcept {
  return mfree_mpi_detail::same_everywhere(h->ctx, fn, what, lo, neg_hi);
}

// A collective call's local step: the failure a binding handed over with
// mfree_halo_set_pending_error, else body's outcome.
template <class Body>
Local first_step(mfree_halo_t *h, Body &&body) noexcept {
  return h->pending.first_step(body);
}

// The rank that checks global id g for duplicates (ids spread by a 64-bit mix).
int id_owner(int64_t g, int size) {
  uint64_t z = static_cast<uint64_t>(g) + 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  z ^= z >> 31;
  return static_cast<int>(z % static_cast<uint64_t>(size));
}

bool overlaps(const double *a, const double *b, int dim, double w) {
  for (int c = 0; c < dim; ++c)
    if (a[c] - w > b[dim + c] || b[c] > a[dim + c] + w) return false;
  return true;
}

void free_graph(mfree_halo_t *h) {
  if (h->graph != MPI_COMM_NULL) MPI_Comm_free(&h->graph);
  h->graph = MPI_COMM_NULL;
}

}  // namespace

extern "C" {

mfree_status_t mfree_halo_create(mfree_context_t *ctx, MPI_Comm comm, int32_t dim, mfree_halo_t **halo) {
  const char *fn = "mfree_halo_create";
  if (!ctx) return MFREE_ERR_NULL;
  if (!halo) return record(ctx, MFREE_ERR_NULL, fn, "output pointer is NULL");
  *halo = nullptr;
  if (comm == MPI_COMM_NULL) return record(ctx, MFREE_ERR_ARG, fn, "communicator is MPI_COMM_NULL");
  mfree_halo_t *h = new (std::nothrow) mfree_halo_t;
  if (!h) return record(ctx, MFREE_ERR_ALLOC, fn, "out of memory");
  h->ctx = ctx;
  h->dim = dim;
  if (MPI_Comm_dup(comm, &h->comm) != MPI_SUCCESS) {
    delete h;
    return record(ctx, MFREE_ERR_INTERNAL, fn, "MPI_Comm_dup failed");
  }
  MPI_Comm_set_errhandler(h->comm, MPI_ERRORS_RETURN);
  MPI_Comm_rank(h->comm, &h->rank);
  MPI_Comm_size(h->comm, &h->size);
  Local l = run_local([&](Local &r) {
    if (dim < 1 || dim > 3) r.fail(MFREE_ERR_ARG, "dimension " + std::to_string(dim) + " is not 1, 2 or 3");
  });
  if (l.st == MFREE_SUCCESS) {
    // The ABI has no context retain: an empty matrix on ctx keeps it alive for us.
    int64_t zero = 0;
    const mfree_status_t st = mfree_matrix_create_csr(ctx, 0, 0, &zero, nullptr, nullptr, &h->ctx_ref);
    if (st != MFREE_SUCCESS) l.fail(st, "cannot hold the context");
  }
  Loc dims[2] = {{static_cast<double>(dim), 0}, {-static_cast<double>(dim), 0}};
  mfree_status_t st = agree(h, fn, l, dims, 2);
  if (st == MFREE_SUCCESS) st = same_everywhere(h, fn, "the dimension", dims[0], dims[1]);
  if (st != MFREE_SUCCESS) {
    mfree_halo_destroy(&h);
    return st;
  }
  *halo = h;
  return MFREE_SUCCESS;
}

mfree_status_t mfree_halo_create_f(mfree_context_t *ctx, int32_t fcomm, int32_t dim, mfree_halo_t **halo) {
  return mfree_halo_create(ctx, MPI_Comm_f2c(static_cast<MPI_Fint>(fcomm)), dim, halo);
}

mfree_status_t mfree_halo_destroy(mfree_halo_t **halo) {
  if (!halo || !*halo) return MFREE_SUCCESS;
  mfree_halo_t *h = *halo;
  // MPI_Comm_free after MPI_Finalize is erroneous (Open MPI aborts); MPI released the
  // plan's communicators at MPI_Finalize, so only the memory is left to free.
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (!finalized) {
    free_graph(h);
    if (h->comm != MPI_COMM_NULL) MPI_Comm_free(&h->comm);
  }
  mfree_matrix_t *ref = h->ctx_ref;
  delete h;
  mfree_matrix_destroy(&ref);
  *halo = nullptr;
  return MFREE_SUCCESS;
}

mfree_status_t mfree_halo_setup(mfree_halo_t *h, int32_t n_owned, const double *x, int64_t ld,
                                const int64_t *ids, double width) {
  const char *fn = "mfree_halo_setup";
  if (!h) return MFREE_ERR_NULL;
  h->ready = false;
  const int dim = h->dim;
  // 1. arguments and this rank's bounding box (empty: lo = +inf, hi = -inf)
  double box[6] = {0, 0, 0, 0, 0, 0};  // (dim <= 3: checked at create)
  Local l = first_step(h, [&](Local &r) {
    if (n_owned < 0) return r.fail(MFREE_ERR_ARG, "n_owned " + std::to_string(n_owned) + " is negative");
    if (ld < dim) return r.fail(MFREE_ERR_ARG, "leading dimension " + std::to_string(ld) + " is below dim");
    if (!std::isfinite(width) || width <= 0.0)
      return r.fail(MFREE_ERR_ARG, "halo width must be finite and > 0, got " + std::to_string(width));
    if (n_owned > 0 && !x) return r.fail(MFREE_ERR_NULL, "positions pointer is NULL");
    for (int c = 0; c < dim; ++c) {
      box[c] = std::numeric_limits<double>::infinity();
      box[dim + c] = -std::numeric_limits<double>::infinity();
    }
    for (int32_t i = 0; i < n_owned; ++i)
      for (int c = 0; c < dim; ++c) {
        const double v = x[i * ld + c];
        if (!std::isfinite(v))
          return r.fail(MFREE_ERR_INPUT, "position of particle " + std::to_string(i) + ", component " +
                                             std::to_string(c) + " is not finite");
        box[c] = std::min(box[c], v);
        box[dim + c] = std::max(box[dim + c], v);
      }
    if (ids)
      for (int32_t i = 0; i < n_owned; ++i)
        if (ids[i] < 0)
          return r.fail(MFREE_ERR_INPUT, "global id of particle " + std::to_string(i) + " is " +
                                             std::to_string(ids[i]) + " (must be >= 0)");
  });
  // The duplicate check (an all-to-all of every id) is skipped when no rank's owned ids
  // changed since the last one passed: a rebuild after motion without migration.
  const bool same = h->ids_checked && ids && n_owned == h->n_owned &&
                    static_cast<int64_t>(h->ids.size()) >= n_owned &&
                    std::equal(ids, ids + n_owned, h->ids.begin());
  h->ids_checked = false;
  // Agreed with the status, in the same all-reduce: the width (common to all ranks: the
  // neighbour relation must be symmetric), ids from every rank with particles or from
  // none (the duplicate check below is collective; a rank without particles may pass
  // NULL), and whether any rank's ids changed.
  const double has_ids = ids ? 1.0 : 0.0;
  Loc v[5] = {{width, 0},
              {-width, 0},
              {n_owned > 0 ? has_ids : 1.0, 0},    // min: 0 when a rank with particles has none
              {n_owned > 0 ? -has_ids : 0.0, 0},   // -max: -1 when a rank gives ids
              {same ? 0.0 : -1.0, 0}};             // -1 when some rank's ids changed
  mfree_status_t st = agree(h, fn, l, v, 5);
  if (st == MFREE_SUCCESS) st = same_everywhere(h, fn, "the halo width", v[0], v[1]);
  if (st == MFREE_SUCCESS && v[2].v == 0.0 && v[3].v == -1.0) {
    char text[160];
    std::snprintf(text, sizeof text,
                  "rank %d gives no global ids while rank %d gives its own (all ranks with particles or none)",
                  v[2].r, v[3].r);
    st = record(h->ctx, MFREE_ERR_ARG, fn, text);
  }
  if (st != MFREE_SUCCESS) return st;
  const bool any_changed = v[4].v == -1.0;
  const bool host_ids = v[3].v == -1.0;

  // 2. global numbering, every rank's box, and the duplicate-id check: each id is sent to
  // the rank id_owner(id), which finds repeats among what it receives
  l = run_local([&](Local &r) {
    int64_t n = n_owned, off = 0, tot = 0;
    mpi_ok(r, MPI_Exscan(&n, &off, 1, MPI_INT64_T, MPI_SUM, h->comm), "MPI_Exscan");
    if (h->rank == 0) off = 0;  // (undefined on rank 0)
    mpi_ok(r, MPI_Allreduce(&n, &tot, 1, MPI_INT64_T, MPI_SUM, h->comm), "MPI_Allreduce");
    h->offset = off;
    h->total = tot;
    h->boxes.resize(2 * static_cast<size_t>(dim) * h->size);
    mpi_ok(r, MPI_Allgather(box, 2 * dim, MPI_DOUBLE, h->boxes.data(), 2 * dim, MPI_DOUBLE, h->comm),
           "MPI_Allgather");
    h->ids.resize(static_cast<size_t>(n_owned));
    for (int32_t i = 0; i < n_owned; ++i) h->ids[i] = host_ids ? ids[i] : off + i;
    if (!host_ids || !any_changed) return;  // numbered here, or unchanged since checked
    std::vector<int> cnt(h->size, 0), rcnt(h->size, 0), sdis(h->size, 0), rdis(h->size, 0);
    for (int32_t i = 0; i < n_owned; ++i) ++cnt[id_owner(ids[i], h->size)];  // (n_owned = 0 if ids is NULL)
    mpi_ok(r, MPI_Alltoall(cnt.data(), 1, MPI_INT, rcnt.data(), 1, MPI_INT, h->comm), "MPI_Alltoall");
    for (int p = 1; p < h->size; ++p) {
      sdis[p] = sdis[p - 1] + cnt[p - 1];
      rdis[p] = rdis[p - 1] + rcnt[p - 1];
    }
    const size_t nr = static_cast<size_t>(rdis[h->size - 1]) + rcnt[h->size - 1];
    std::vector<int64_t> out(static_cast<size_t>(n_owned)), in(nr);
    std::vector<int> pos(sdis);
    for (int32_t i = 0; i < n_owned; ++i) out[pos[id_owner(ids[i], h->size)]++] = ids[i];
    mpi_ok(r, MPI_Alltoallv(out.data(), cnt.data(), sdis.data(), MPI_INT64_T, in.data(), rcnt.data(),
                            rdis.data(), MPI_INT64_T, h->comm),
           "MPI_Alltoallv");
    if (r.st) return;
    // (id, sending rank) pairs sorted: a repeat is two neighbours with one id
    std::vector<std::pair<int64_t, int>> all(nr);
    for (int p = 0; p < h->size; ++p)
      for (int k = 0; k < rcnt[p]; ++k) all[rdis[p] + k] = {in[rdis[p] + k], p};
    std::sort(all.begin(), all.end());
    for (size_t k = 1; k < nr; ++k)
      if (all[k].first == all[k - 1].first)
        return r.fail(MFREE_ERR_INPUT, "global id " + std::to_string(all[k].first) +
                                           " is given to particles of ranks " + std::to_string(all[k - 1].second) +
                                           " and " + std::to_string(all[k].second) +
                                           " (ids must be unique over all ranks)");
  });
  st = agree(h, fn, l);
  if (st != MFREE_SUCCESS) return st;

  // 3. neighbours (ranks whose boxes lie within the width: a symmetric relation, so both
  // sides list each other) and what to send them: the owned particles within the width
  // of their box
  l = run_local([&](Local &r) {
    free_graph(h);
    h->nbrs.clear();
    const double *me = box;
    for (int p = 0; p < h->size; ++p)
      if (p != h->rank && overlaps(me, &h->boxes[2 * static_cast<size_t>(dim) * p], dim, width))
        h->nbrs.push_back(p);
    const int k = static_cast<int>(h->nbrs.size());
    h->scount.assign(k, 0);
    h->sdispl.assign(k, 0);
    h->rcount.assign(k, 0);
    h->rdispl.assign(k, 0);
    h->send_idx.clear();
    for (int q = 0; q < k; ++q) {
      const double *b = &h->boxes[2 * static_cast<size_t>(dim) * h->nbrs[q]];
      h->sdispl[q] = static_cast<int>(h->send_idx.size());
      for (int32_t i = 0; i < n_owned; ++i) {
        bool in = true;
        for (int c = 0; c < dim && in; ++c) {
          const double v = x[i * ld + c];
          in = v >= b[c] - width && v <= b[dim + c] + width;
        }
        if (in) h->send_idx.push_back(i);
      }
      if (h->send_idx.size() > static_cast<size_t>(std::numeric_limits<int>::max()))
        return r.fail(MFREE_ERR_ARG, "more than 2^31 particle copies to send");
      h->scount[q] = static_cast<int>(h->send_idx.size()) - h->sdispl[q];
    }
    const int *nb = k ? h->nbrs.data() : MPI_UNWEIGHTED;  // (any non-NULL pointer when k = 0)
    mpi_ok(r, MPI_Dist_graph_create_adjacent(h->comm, k, nb, MPI_UNWEIGHTED, k, nb, MPI_UNWEIGHTED,
                                             MPI_INFO_NULL, 0, &h->graph),
           "MPI_Dist_graph_create_adjacent");
  });
  st = agree(h, fn, l);
  if (st != MFREE_SUCCESS) return st;

  // 4. counts and the ghosts' ids through the graph
  l = run_local([&](Local &r) {
    MPI_Comm_set_errhandler(h->graph, MPI_ERRORS_RETURN);
    const int k = static_cast<int>(h->nbrs.size());
    mpi_ok(r, MPI_Neighbor_alltoall(h->scount.data(), 1, MPI_INT, h->rcount.data(), 1, MPI_INT, h->graph),
           "MPI_Neighbor_alltoall");
    if (r.st) return;
    int64_t ng = 0;
    for (int q = 0; q < k; ++q) {
      h->rdispl[q] = static_cast<int>(ng);
      ng += h->rcount[q];
    }
    if (static_cast<int64_t>(n_owned) + ng > std::numeric_limits<int32_t>::max())
      return r.fail(MFREE_ERR_ARG, "owned plus ghost particles exceed 2^31 - 1");
    h->n_owned = n_owned;
    h->n_ghost = static_cast<int32_t>(ng);
    std::vector<int64_t> sid(h->send_idx.size());
    for (size_t s = 0; s < sid.size(); ++s) sid[s] = h->ids[h->send_idx[s]];
    h->ids.resize(static_cast<size_t>(n_owned) + static_cast<size_t>(ng));
    mpi_ok(r, MPI_Neighbor_alltoallv(sid.data(), h->scount.data(), h->sdispl.data(), MPI_INT64_T,
                                     h->ids.data() + n_owned, h->rcount.data(), h->rdispl.data(),
                                     MPI_INT64_T, h->graph),
           "MPI_Neighbor_alltoallv");
  });
  st = agree(h, fn, l);
  if (st != MFREE_SUCCESS) return st;
  h->ready = true;
  h->ids_checked = host_ids;
  return MFREE_SUCCESS;
}

mfree_status_t mfree_halo_get_context(const mfree_halo_t *h, mfree_context_t **ctx) {
  if (!h || !ctx) return MFREE_ERR_NULL;
  *ctx = h->ctx;
  return MFREE_SUCCESS;
}

mfree_status_t mfree_halo_set_pending_error(mfree_halo_t *h) {
  if (!h) return MFREE_ERR_NULL;
  return h->pending.take_from(h->ctx, "mfree_halo_set_pending_error");
}

mfree_status_t mfree_halo_get_size(const mfree_halo_t *h, int32_t *n_owned, int32_t *n_ghost) {
  if (!h) return MFREE_ERR_NULL;
  if (!h->ready) return record(h->ctx, MFREE_ERR_STATE, "mfree_halo_get_size", "the plan is not set up");
  if (n_owned) *n_owned = h->n_owned;
  if (n_ghost) *n_ghost = h->n_ghost;
  return MFREE_SUCCESS;
}

mfree_status_t mfree_halo_get_global_ids(const mfree_halo_t *h, int64_t *ids) {
  const char *fn = "mfree_halo_get_global_ids";
  if (!h) return MFREE_ERR_NULL;
  if (!h->ready) return record(h->ctx, MFREE_ERR_STATE, fn, "the plan is not set up");
  if (!ids && !h->ids.empty()) return record(h->ctx, MFREE_ERR_NULL, fn, "output pointer is NULL");
  std::copy(h->ids.begin(), h->ids.end(), ids);
  return MFREE_SUCCESS;
}

mfree_status_t mfree_halo_get_global_offset(const mfree_halo_t *h, int64_t *offset, int64_t *total) {
  if (!h) return MFREE_ERR_NULL;
  if (!h->ready) return record(h->ctx, MFREE_ERR_STATE, "mfree_halo_get_global_offset", "the plan is not set up");
  if (offset) *offset = h->offset;
  if (total) *total = h->total;
  return MFREE_SUCCESS;
}

mfree_status_t mfree_halo_get_plan(const mfree_halo_t *h, int32_t *n_neighbors, int64_t *n_send,
                                   int64_t *n_recv) {
  if (!h) return MFREE_ERR_NULL;
  if (!h->ready) return record(h->ctx, MFREE_ERR_STATE, "mfree_halo_get_plan", "the plan is not set up");
  if (n_neighbors) *n_neighbors = static_cast<int32_t>(h->nbrs.size());
  if (n_send) *n_send = static_cast<int64_t>(h->send_idx.size());
  if (n_recv) *n_recv = h->n_ghost;
  return MFREE_SUCCESS;
}

mfree_status_t mfree_halo_exchange(mfree_halo_t *h, int32_t ncomp, double *field, int64_t ld) {
  const char *fn = "mfree_halo_exchange";
  if (!h) return MFREE_ERR_NULL;
  // Local checks and the packing of the send buffer, then one small all-reduce that
  // agrees on the status and on ncomp before the neighbourhood collective: a rank that
  // fails, or passes another ncomp (another message size), makes every rank return
  // instead of leaving its neighbours waiting for its message.
  Local l = first_step(h, [&](Local &r) {
    if (!h->ready) return r.fail(MFREE_ERR_STATE, "the plan is not set up");
    if (ncomp < 1) return r.fail(MFREE_ERR_ARG, "ncomp must be >= 1, got " + std::to_string(ncomp));
    if (ld < ncomp)
      return r.fail(MFREE_ERR_ARG, "leading dimension " + std::to_string(ld) + " is below ncomp " +
                                       std::to_string(ncomp));
    if (!field && h->n_owned + h->n_ghost > 0) return r.fail(MFREE_ERR_NULL, "field is NULL");
    const size_t k = h->nbrs.size();
    const int64_t biggest = std::max<int64_t>(static_cast<int64_t>(h->send_idx.size()), h->n_ghost) * ncomp;
    if (biggest > std::numeric_limits<int>::max())
      return r.fail(MFREE_ERR_ARG, "more than 2^31 doubles in one exchange");
    h->sc.resize(k);
    h->sd.resize(k);
    h->rc.resize(k);
    h->rd.resize(k);
    for (size_t q = 0; q < k; ++q) {
      h->sc[q] = h->scount[q] * ncomp;
      h->sd[q] = h->sdispl[q] * ncomp;
      h->rc[q] = h->rcount[q] * ncomp;
      h->rd[q] = h->rdispl[q] * ncomp;
    }
    const size_t ns = h->send_idx.size();
    h->sbuf.resize(ns * ncomp);
    for (size_t s = 0; s < ns; ++s)
      std::memcpy(&h->sbuf[s * ncomp], field + h->send_idx[s] * ld, sizeof(double) * ncomp);
    if (ld != ncomp) h->rbuf.resize(static_cast<size_t>(h->n_ghost) * ncomp);
  });
  Loc v[2] = {{static_cast<double>(ncomp), 0}, {-static_cast<double>(ncomp), 0}};
  mfree_status_t st = agree(h, fn, l, v, 2);
  if (st == MFREE_SUCCESS) st = same_everywhere(h, fn, "ncomp (the message size)", v[0], v[1]);
  if (st != MFREE_SUCCESS) return st;
  // contiguous ghost items are received in place
  const bool direct = ld == ncomp;
  double *dst = field ? field + static_cast<int64_t>(h->n_owned) * ld : nullptr;
  double *recv = direct ? dst : h->rbuf.data();
  if (MPI_Neighbor_alltoallv(h->sbuf.data(), h->sc.data(), h->sd.data(), MPI_DOUBLE, recv, h->rc.data(),
                             h->rd.data(), MPI_DOUBLE, h->graph) != MPI_SUCCESS)
    return record(h->ctx, MFREE_ERR_INTERNAL, fn, "MPI_Neighbor_alltoallv failed");
  if (!direct)
    for (int32_t g = 0; g < h->n_ghost; ++g)
      std::memcpy(dst + g * ld, &h->rbuf[static_cast<size_t>(g) * ncomp], sizeof(double) * ncomp);
  return MFREE_SUCCESS;
}

mfree_status_t mfree_halo_exchange_correction(mfree_halo_t *h, mfree_approximant_t *a) {
  const char *fn = "mfree_halo_exchange_correction";
  if (!h) return MFREE_ERR_NULL;
  // 1. this rank's records, after checking that a's set is laid out as the plan
  mfree_context_t *actx = nullptr;
  int32_t ncoef = 0;
  Local l = first_step(h, [&](Local &r) {
    if (!h->ready) return r.fail(MFREE_ERR_STATE, "the plan is not set up");
    if (!a) return r.fail(MFREE_ERR_NULL, "approximant is NULL");
    mfree_particles_t *ps = nullptr;
    int32_t n = 0, ng = 0;
    mfree_approximant_get_context(a, &actx);
    mfree_status_t st = mfree_approximant_get_particles(a, &ps);
    if (st == MFREE_SUCCESS) st = mfree_particles_get_size(ps, &n, &ng);
    if (st != MFREE_SUCCESS) return core_fail(r, st, actx);
    if (ng != h->n_ghost || n - ng != h->n_owned)
      return r.fail(MFREE_ERR_ARG, "the approximant's particle set holds " + std::to_string(n - ng) +
                                       " owned particles and " + std::to_string(ng) + " ghosts, the plan " +
                                       std::to_string(h->n_owned) + " and " + std::to_string(h->n_ghost) +
                                       " (the set must be the plan's particles in its order)");
    st = mfree_approximant_get_correction_size(a, &ncoef);
    if (st != MFREE_SUCCESS) return core_fail(r, st, actx);
    h->corr.resize(static_cast<size_t>(n) * static_cast<size_t>(ncoef));
    if (h->n_owned == 0) return;  // (a rank without particles still takes part)
    st = mfree_approximant_get_correction(a, h->corr.data(), ncoef, static_cast<int64_t>(h->n_owned) * ncoef);
    if (st != MFREE_SUCCESS) return core_fail(r, st, actx);
  });
  mfree_status_t st = agree(h, fn, l);
  if (st != MFREE_SUCCESS) return st;
  // 2. the ghosts' records from their owners (agrees on ncoef: one method everywhere)
  st = mfree_halo_exchange(h, ncoef, h->corr.data(), ncoef);
  if (st != MFREE_SUCCESS) return st;
  // 3. handed to the approximant; agreed, so that every rank returns alike
  l = run_local([&](Local &r) {
    const int64_t off = static_cast<int64_t>(h->n_owned) * ncoef;
    const mfree_status_t s = mfree_approximant_set_ghost_correction(
        a, h->n_ghost ? h->corr.data() + off : nullptr, ncoef, static_cast<int64_t>(h->n_ghost) * ncoef);
    if (s != MFREE_SUCCESS) core_fail(r, s, actx);
  });
  return agree(h, fn, l);
}

}  // extern "C"

// The failure a binding handed over with mfree_halo_set_pending_error, taken (reported
// once), for the collective calls of halo_system.cpp.
mfree_status_t mfree_mpi_detail::take_pending(mfree_halo_t *h, std::string &msg) noexcept {
  const Local l = h->pending.first_step([](Local &) {});
  try {
    msg = l.msg;
  } catch (...) {
  }
  return l.st;
}

const int64_t *mfree_mpi_detail::halo_ids(const mfree_halo_t *h) noexcept { return h->ids.data(); }

extern "C" mfree_status_t mfree_halo_get_communicator(const mfree_halo_t *h, MPI_Comm *comm) {
  if (!h || !comm) return MFREE_ERR_NULL;
  *comm = h->comm;
  return MFREE_SUCCESS;
}
