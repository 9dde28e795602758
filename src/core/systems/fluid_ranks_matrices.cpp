// The fluid on ranks' matrices: the mass products (the consistent mass couples an owned
// particle to the ghosts within one support radius, columns the rank's state does not
// hold, so it is applied, never handed out) and the interpolation matrix's owned rows.
// Both read the tables output_prepare builds: every entry is summed as on one rank
// (FluidSystem::mass_matrix sorts each entry's terms by value; an interpolation entry is
// one table value), and every row lists its columns in node order, which is global-id
// order: the products and rows are one rank's, bit for bit, whatever the partition.
#include <numeric>

#include "core/systems/fluid_ranks.hpp"

namespace mfree {

// The rows of the rank's state (positions, velocities, densities of the owned particles,
// host order) of the consistent mass over every node, columns in the node state's layout
// (positions, velocities, densities of the nodes): the one-process matrix's rows with
// the nodes' numbers. FluidSystem::mass_matrix assembles them for every node; the rows
// of ghosts are dropped (only owned particles' rows are complete).
void FluidRanks::consistent_rows(SparseMatrix &M) const {
  const int D = dim();
  const int32_t n = size();
  std::vector<int32_t> id(n);
  std::iota(id.begin(), id.end(), 0);
  SparseMatrix full;
  mass_matrix(n, id.data(), id.data(), true, full);
  const size_t nd = static_cast<size_t>(D) * n;
  const auto &rp = full.rowptr();
  const auto &ci = full.colidx();
  const auto &va = full.values();
  const int32_t rows = neq();
  std::vector<int64_t> ptr(static_cast<size_t>(rows) + 1, 0);
  std::vector<int32_t> cols;
  std::vector<double> vals;
  int32_t r = 0;
  auto take = [&](size_t row) {
    for (int64_t e = rp[row]; e < rp[row + 1]; ++e) {
      cols.push_back(ci[e]);
      vals.push_back(va[e]);
    }
    ptr[++r] = static_cast<int64_t>(cols.size());
  };
  for (int b = 0; b < 2; ++b)  // positions, velocities
    for (int32_t p = 0; p < n_own_; ++p)
      for (int c = 0; c < D; ++c) take(b * nd + static_cast<size_t>(owned_[p]) * D + c);
  for (int32_t p = 0; p < n_own_; ++p) take(2 * nd + owned_[p]);
  M.set_pattern(rows, static_cast<int32_t>(full.cols()), ptr, cols);
  std::copy(vals.begin(), vals.end(), M.values_mut().begin());
}

// Every rank agrees on the outcome of its arguments (a fault pending on the collective
// operations: the C API's) and on whether its kept mass is M(y) (a rank that assembled
// alone would wait in the exchange of the state), assembles when any rank must, then
// applies: the lumped mass locally, the consistent mass to v's velocities with the
// ghosts' from their owners (one exchange of dim values per item).
Report FluidRanks::apply_mass(const double *y, bool consistent, const double *v, double *Mv) {
  check_usable();
  if (open_) return open_apply_mass_ranks(y, consistent, v, Mv);
  double same = 0.0;
  const Report mine = coll_.local([&] {
    same = kept_mass_.holds(y, neq(), consistent, options_gen_) ? 1.0 : 0.0;
    return Report();
  });
  Report agreed = agree_min(mine, &same, 1);
  if (!agreed.ok()) return agreed;
  if (same == 0.0) {
    kept_mass_.valid = false;
    agreed = output_prepare(y, nullptr, MFREE_SUCCESS, "");
    if (!agreed.ok()) return agreed;
    if (consistent)
      consistent_rows(kept_mass_.M);
    else
      lumped_rows(kept_mass_.M);
    kept_mass_.keep(y, neq(), consistent, options_gen_);
  }
  if (!consistent) {
    kept_mass_.M.apply(v, Mv);
    return agreed;
  }
  const int D = dim();
  const int32_t n = size();
  const size_t nd = static_cast<size_t>(D) * n, no = static_cast<size_t>(D) * n_own_;
  w_.assign(2 * nd + n, 0.0);
  for (int32_t p = 0; p < n_own_; ++p) {
    const size_t k = owned_[p];
    for (int c = 0; c < D; ++c) {
      w_[k * D + c] = v[p * D + c];
      w_[nd + k * D + c] = v[no + p * D + c];
    }
    w_[2 * nd + k] = v[2 * no + p];
  }
  sync(w_.data() + nd, D);
  kept_mass_.M.apply(w_.data(), Mv);
  return agreed;
}

// The owned rows in the host's order, the columns the host's items (owned, then ghosts,
// as the global ids given at creation or by the last rebuild list them).
Report FluidRanks::interpolation(const double *y, SparseMatrix &S) {
  if (open_) return open_interpolation_ranks(y, S);
  const Report agreed =
      output_prepare(y, nullptr, !y && n_own_ > 0 ? MFREE_ERR_NULL : MFREE_SUCCESS, "y is NULL");
  if (!agreed.ok()) return agreed;
  const int32_t n = size();
  std::vector<int32_t> item(n);
  for (int32_t p = 0; p < n; ++p) item[node_[p]] = p;
  interpolation_rows(n_own_, owned_.data(), item.data(), n, S);
  return agreed;
}

}  // namespace mfree
