// The fluid on ranks, its ghosts rebuilt as particles move and its particles moved
// between ranks (the host's rebuild and move callbacks): FluidRanks' re-seat.
#include <algorithm>
#include <cstdint>
#include <string>

#include "core/systems/fluid_ranks.hpp"

namespace mfree {

// ---- Ghosts rebuilt and particles moved ----------------------------------------------
// The results never depend on which ghosts a rank holds, only on their being there: the
// nodes are numbered by global id, so a rebuilt layer (or a new set of owned particles)
// leaves every row, sum and scatter order as it was, and the results stay bitwise those
// of one rank. A re-seat keeps every option; the nodes' per-particle data (rest density,
// mass) travel with the owned particles and reach the new ghosts through one exchange.

void FluidRanks::check_usable() const {
  if (broken_)
    throw Error(MFREE_ERR_STATE, "a halo rebuild of this system failed: its ghosts no longer match the host's "
                                 "halo (create the system again)");
}

void FluidRanks::rebuild_halo(const double *y) {
  const int D = dim();
  // (one more item each: the host sees arrays, also on a rank without owned particles)
  mv_x_.resize(static_cast<size_t>(D) * n_own_ + 1);
  std::copy(y, y + static_cast<size_t>(D) * n_own_, mv_x_.begin());
  mv_id_.resize(static_cast<size_t>(n_own_) + 1);
  mv_data_.resize(2 * static_cast<size_t>(n_own_) + 1);
  mv_pw_.resize(pw_started_ ? static_cast<size_t>(D) * n_own_ + 1 : 0);
  for (int32_t p = 0; p < n_own_; ++p) {
    const int32_t k = owned_[p];
    mv_id_[p] = gid_[k];
    mv_data_[2 * p] = rho0_[k];
    mv_data_[2 * p + 1] = mass_[k];
    if (pw_started_) std::copy_n(&pw_u_[static_cast<size_t>(k) * D], D, &mv_pw_[static_cast<size_t>(p) * D]);
  }
  reseat(n_own_, mv_x_.data(), mv_id_.data(), mv_data_.data(), mv_pw_.data());
}

void FluidRanks::reseat(int32_t n_owned, const double *xo, const int64_t *oid, const double *data,
                        const double *pw) {
  const int D = dim();
  kept_mass_.valid = false;  // (apply_mass's columns are the nodes)
  int32_t ng = -1;
  const int64_t *ids = nullptr;
  // the host's rebuild (collective: its status is the same on every rank), then the local
  // checks of what it returned, agreed
  const Report mine = guarded([&] {
    const mfree_status_t st = rebuild_(coll_.user(), n_owned, xo, D, oid, width_, &ng, &ids);
    if (st != MFREE_SUCCESS)
      throw Error(st, "the host's halo rebuild callback failed with status " + std::to_string(st) + " (" +
                          mfree_status_string(st) + ")");
    if (ng < 0) throw Error(MFREE_ERR_INPUT, "the halo rebuild returned " + std::to_string(ng) + " ghosts");
    if (n_owned + static_cast<int64_t>(ng) > INT32_MAX)
      throw Error(MFREE_ERR_INPUT, "more than 2^31 - 1 particles on a rank after the halo rebuild");
    if (!ids && n_owned + ng > 0) throw Error(MFREE_ERR_INPUT, "the halo rebuild returned NULL global ids");
    for (int32_t p = 0; p < n_owned; ++p)
      if (ids[p] != oid[p])
        throw Error(MFREE_ERR_INPUT, "the halo rebuild changed owned item " + std::to_string(p) + "'s global id (" +
                                         std::to_string(oid[p]) + " -> " + std::to_string(ids[p]) + ")");
    return Report();
  });
  Report agreed = coll_.agree(mine);
  if (!agreed.ok()) {
    broken_ = true;
    throw Error(agreed.status, agreed.message);
  }
  const Report seated = guarded([&] {
    // (the dummies' volumes, after the fluid's, move to the new nodes)
    const std::vector<double> dvol(vol_.begin() + n_, vol_.begin() + nq());
    n_own_ = n_owned;
    n_ghost_ = ng;
    n_ = n_owned + ng;
    number(ids);
    // a new particle set of the nodes (its search lists and the tables follow at the
    // next prepare), with the system's support
    seat_nodes(dummy_.n, dvol.data());
    xfirst_.clear();
    // the rest densities and masses to the nodes, the ghosts' from their owners
    buf_.resize(2 * static_cast<size_t>(n_));
    std::copy(data, data + 2 * static_cast<size_t>(n_owned), buf_.begin());
    coll_.exchange(2, buf_.data(), 2);
    rho0_.resize(n_);
    mass_.resize(n_);
    for (int32_t p = 0; p < n_; ++p) {
      rho0_[node_[p]] = buf_[2 * static_cast<size_t>(p)];
      mass_[node_[p]] = buf_[2 * static_cast<size_t>(p) + 1];
    }
    // the power iteration goes on from the owned particles' vector, as on one rank (the
    // ghosts' values come from their owners before each product)
    if (pw_started_) {
      pw_u_.assign(static_cast<size_t>(D) * n_, 0.0);
      for (int32_t p = 0; p < n_owned; ++p)
        std::copy_n(pw + static_cast<size_t>(p) * D, D, &pw_u_[static_cast<size_t>(node_[p]) * D]);
    }
    return Report();
  });
  agreed = coll_.agree(seated);
  if (!agreed.ok()) {
    broken_ = true;
    throw Error(agreed.status, agreed.message);
  }
}

void FluidRanks::move_particles(int32_t n_new, mfree_particles_move_fn move, void *move_user, double *y,
                                int64_t capacity) {
  // records: x, v, rho, rest density, mass, the global id's bits, the power iteration's
  // vector (with the acoustic step)
  const int D = dim(), nrec = 2 * D + 4 + (pw_started_ ? D : 0);
  const Report args = coll_.local([&] {
    check_usable();
    if (!rebuild_) throw Error(MFREE_ERR_STATE, "no halo rebuild callback (mfree_system_set_halo_rebuild)");
    if (!move) throw Error(MFREE_ERR_NULL, "move callback is NULL");
    if (n_new < 0) throw Error(MFREE_ERR_ARG, "negative particle count n_new " + std::to_string(n_new));
    const int64_t need = static_cast<int64_t>(2 * D + 1) * n_new;
    if (capacity < need)
      throw Error(MFREE_ERR_ARG, "capacity " + std::to_string(capacity) + " is below the " + std::to_string(need) +
                                     " doubles of this rank's state after the move");
    if (capacity < neq())
      throw Error(MFREE_ERR_ARG, "capacity " + std::to_string(capacity) + " is below the " +
                                     std::to_string(neq()) + " doubles of this rank's state");
    if (!y && (n_own_ > 0 || n_new > 0)) throw Error(MFREE_ERR_NULL, "y is NULL");
    check_ready();
    return Report();
  });
  // the outcome, and whether the records carry the power iteration's vector: a record's
  // length must be the same on every rank
  const double mine[2] = {static_cast<double>(args.status), pw_started_ ? 1.0 : 0.0};
  const std::vector<double> all = coll_.allgather(mine, 2);
  std::vector<double> st(all.size() / 2);
  bool differ = false;
  for (size_t p = 0; p < st.size(); ++p) {
    st[p] = all[2 * p];
    differ = differ || all[2 * p + 1] != all[1];
  }
  Report agreed = coll_.agree_from(st, args);
  if (!agreed.ok()) throw Error(agreed.status, agreed.message);
  if (differ)
    throw Error(MFREE_ERR_ARG,
                "ranks disagree on the acoustic step (mfree_system_set_acoustic_step): every rank must set the same");
  const size_t no = static_cast<size_t>(D) * n_own_;
  mv_rec_.resize(static_cast<size_t>(std::max(n_own_, n_new)) * nrec + 1);
  for (int32_t p = 0; p < n_own_; ++p) {
    double *r = &mv_rec_[static_cast<size_t>(p) * nrec];
    const int32_t k = owned_[p];
    for (int c = 0; c < D; ++c) {
      r[c] = y[p * D + c];
      r[D + c] = y[no + p * D + c];
    }
    r[2 * D] = y[2 * no + p];
    r[2 * D + 1] = rho0_[k];
    r[2 * D + 2] = mass_[k];
    r[2 * D + 3] = Collective::pack(gid_[k]);
    if (pw_started_) std::copy_n(&pw_u_[static_cast<size_t>(k) * D], D, r + 2 * D + 4);
  }
  const Report moved = guarded([&] {
    const mfree_status_t st = move(move_user, nrec, n_own_, mv_rec_.data(), n_new);
    if (st != MFREE_SUCCESS)
      throw Error(st, "the host's move callback failed with status " + std::to_string(st) + " (" +
                          mfree_status_string(st) + ")");
    return Report();
  });
  agreed = coll_.agree(moved);
  if (!agreed.ok()) throw Error(agreed.status, agreed.message);  // the system as it was
  mv_x_.resize(static_cast<size_t>(D) * n_new + 1);
  mv_id_.resize(static_cast<size_t>(n_new) + 1);
  mv_data_.resize(2 * static_cast<size_t>(n_new) + 1);
  mv_pw_.resize(pw_started_ ? static_cast<size_t>(D) * n_new + 1 : 0);
  for (int32_t p = 0; p < n_new; ++p) {
    const double *r = &mv_rec_[static_cast<size_t>(p) * nrec];
    for (int c = 0; c < D; ++c) mv_x_[p * D + c] = r[c];
    mv_data_[2 * p] = r[2 * D + 1];
    mv_data_[2 * p + 1] = r[2 * D + 2];
    mv_id_[p] = Collective::unpack(r[2 * D + 3]);
    if (pw_started_) std::copy_n(r + 2 * D + 4, D, &mv_pw_[static_cast<size_t>(p) * D]);
  }
  reseat(n_new, mv_x_.data(), mv_id_.data(), mv_data_.data(), mv_pw_.data());
  if (open_) open_->dirty = true;  // (the inner system's items are the moved ones)
  const size_t nn = static_cast<size_t>(D) * n_new;
  for (int32_t p = 0; p < n_new; ++p) {
    const double *r = &mv_rec_[static_cast<size_t>(p) * nrec];
    for (int c = 0; c < D; ++c) {
      y[p * D + c] = r[c];
      y[nn + p * D + c] = r[D + c];
    }
    y[2 * nn + p] = r[2 * D];
  }
}

}  // namespace mfree
