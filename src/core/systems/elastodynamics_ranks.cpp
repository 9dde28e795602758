// Elastodynamics on ranks: each rank holds its owned particles and their
// ghosts; the interior rows of its owned particles need the ghosts' displacements (one
// halo exchange per evaluation), and the boundary rows determine the boundary unknowns
// through a block that may couple particles of several ranks. That block is gathered
// once, in (global id, component) order, and solved on every rank at each evaluation
// from all ranks' boundary data (one all-gather, which also carries each rank's status):
// every rank then holds every boundary unknown, computed by the same operations in the
// same order whatever the partition, so the owned particles' results are bitwise those
// of one rank. The boundary is a lower-dimensional set: the gather and the solve grow
// with it, not with the particles.
// Galerkin on ranks is the same system with K, f and the lumped mass from the assembler,
// whose owned rows are bitwise the one-rank rows when its quadrature points are the
// host's, given in the global order (nodal quadrature is refused: its points are the
// set's non-ghosts). The lumped mass keeps every unknown's acceleration local: the
// right-hand side divides by it. The consistent mass is applied, never inverted (its
// inverse would couple every unknown): ARKStep's mass form M_C y' = M_L f solves for
// g f - K u = M_L f on its velocity rows, the equation of the one-process system with a
// consistent mass (M_C y' = M_C f there), with the products of apply_mass.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/systems/elastodynamics.hpp"

namespace mfree {

Report ElasticSystem::settle(const Report &agreed) {
  if (agreed.status < 0) throw Error(agreed.status, agreed.message);
  return agreed;
}

ElasticSystem::ElasticSystem(const Assembler *as, double density, const Collective &coll)
    : as_(as), rho_(density), coll_(coll) {
  if (!as->is_setup()) throw Error(MFREE_ERR_STATE, "the assembler is not set up");
  const int form = as->form();
  galerkin_ = form == MFREE_FORM_LAPLACE || form == MFREE_FORM_ELASTICITY_PLANE_STRESS ||
              form == MFREE_FORM_ELASTICITY_PLANE_STRAIN || form == MFREE_FORM_ELASTICITY_3D;
  if (!galerkin_ && form != MFREE_FORM_COLLOCATION_LAPLACE && form != MFREE_FORM_COLLOCATION_PLANE_STRESS &&
      form != MFREE_FORM_COLLOCATION_PLANE_STRAIN)
    throw Error(MFREE_ERR_UNSUPPORTED, "elastodynamics on ranks needs a collocation assembler (Laplace form for the "
                                       "1D bar, or a plane collocation form) or a Galerkin stiffness assembler "
                                       "(Laplace or elasticity form)");
  if (galerkin_) {
    if (as->ndofs() != as->particles().size() * as->ncomp())
      throw Error(MFREE_ERR_UNSUPPORTED, "Lagrange multipliers are not supported in elastodynamics: impose "
                                         "essential conditions by penalty, Nitsche or node rows");
    if (const char *why = as->ranks_obstacle())
      throw Error(MFREE_ERR_UNSUPPORTED, std::string("Galerkin elastodynamics on ranks does not take ") + why);
  }
  if (!(std::isfinite(density) && density > 0.0)) throw Error(MFREE_ERR_ARG, "density must be finite and > 0");
  if (!as->particles().has_global_ids())
    throw Error(MFREE_ERR_STATE, "on ranks the particle set needs global ids (mfree_particles_set_global_ids): "
                                 "they order the boundary unknowns");
  ranks_ = true;
  init_operator();
  sort_rows();
  if (!galerkin_) {
    dx_min_ = local_spacing(as->particles().num_owned());
    return;
  }
  // The lumped mass (rows summed: the mass is local to each unknown) of the stiffness's
  // approximants on its quadrature points. A consistent mass couples every unknown through
  // its inverse at each evaluation, a solve over all ranks whose sums would follow the
  // partition: the right-hand side divides by the lumped mass, and the consistent one is
  // applied only (apply_mass).
  init_galerkin_mass(as->mass_on_same_points(MFREE_FORM_MASS_LUMPED, density).get());
}

// Each row's entries in global-id order of their columns (the assembler's are in local
// order, which depends on the partition): every sum over a row then runs in one order.
// (K_ is used through its arrays only; its rows are not sorted by local column.)
int64_t ElasticSystem::key(int32_t d) const {
  return as_->particles().global_ids()[d / nc_] * nc_ + d % nc_;
}

void ElasticSystem::sort_rows() {
  std::vector<int64_t> rp(K_.rowptr());
  std::vector<int32_t> ci(K_.colidx());
  std::vector<double> va(K_.values());
  std::vector<std::pair<int64_t, int64_t>> row;
  for (int32_t d = 0; d < K_.rows(); ++d) {
    row.clear();
    for (int64_t k = rp[d]; k < rp[d + 1]; ++k) row.emplace_back(key(K_.colidx()[k]), k);
    std::sort(row.begin(), row.end());
    for (size_t q = 0; q < row.size(); ++q) {
      ci[rp[d] + q] = K_.colidx()[row[q].second];
      va[rp[d] + q] = K_.values()[row[q].second];
    }
  }
  K_.set_pattern(K_.rows(), K_.cols(), std::move(rp), std::move(ci));
  K_.values_mut() = std::move(va);
}

std::unique_ptr<ElasticSystem> ElasticSystem::on_ranks(const Assembler *as, double density, const Collective &coll) {
  // 1. the local part, its outcome and the values every rank must share, agreed
  std::unique_ptr<ElasticSystem> sys;
  const Report mine = coll.local([&] {
    if (!as) throw Error(MFREE_ERR_NULL, "assembler is NULL");
    sys.reset(new ElasticSystem(as, density, coll));
    return Report();
  });
  enum { kStatus, kDensity, kForm, kCoef, kYoung, kPoisson, kComp, kDim, kSpacing, kN };
  double v[kN] = {static_cast<double>(mine.status), density, 0, 0, 0, 0, 0, 0, INFINITY};
  if (sys) {
    v[kForm] = as->form();
    v[kCoef] = as->coefficient();
    v[kYoung] = as->young();
    v[kPoisson] = as->poisson();
    v[kComp] = as->ncomp();
    v[kDim] = as->particles().dim();
    v[kSpacing] = sys->galerkin_ ? sys->limit_ : sys->dx_min_;
  }
  const std::vector<double> all = coll.allgather(v, kN);
  const size_t np = all.size() / kN;
  std::vector<double> st(np);
  for (size_t p = 0; p < np; ++p) st[p] = all[kN * p];
  settle(coll.agree_from(st, mine));
  static const char *names[kN] = {"", "the density", "the assembler's form", "the form's coefficient",
                                  "Young's modulus", "Poisson's ratio", "the components", "the dimension", ""};
  double spacing = INFINITY;
  for (size_t p = 0; p < np; ++p) {
    for (int k = kDensity; k < kSpacing; ++k)
      if (!(all[kN * p + k] == all[k]) && !(std::isnan(all[kN * p + k]) && std::isnan(all[k]))) {
        std::ostringstream s;
        s.precision(17);
        s << "ranks disagree on " << names[k] << ": rank 0 passes " << all[k] << ", rank " << p << " passes "
          << all[kN * p + k] << " (every rank must pass the same)";
        throw Error(MFREE_ERR_ARG, s.str());
      }
    spacing = std::min(spacing, all[kN * p + kSpacing]);  // a minimum: exact in any order
  }
  // 2. the boundary block of all ranks (identical data on every rank: a failure here is
  // every rank's). Galerkin: the step limit 2 / omega_max is a minimum over ranks too
  // (2 / sqrt of the largest Gershgorin bound: a monotone function of one rank's bound).
  if (sys->galerkin_) {
    sys->limit_ = spacing;
    sys->dx_min_ = spacing * sys->c_;
  } else {
    sys->dx_min_ = spacing;
    sys->limit_ = spacing / sys->c_;
  }
  sys->init_ranks();
  return sys;
}

void ElasticSystem::init_ranks() {
  const auto &kinds = as_->row_kinds();
  own_b_.clear();
  for (int32_t d = 0; d < nd_; ++d)
    if (kinds[d] != 0) own_b_.push_back(d);
  // every rank's count and keys (global id, component) of its owned boundary unknowns
  const double nb_own = static_cast<double>(own_b_.size());
  const std::vector<double> counts = coll_.allgather(&nb_own, 1);
  const int np = static_cast<int>(counts.size());
  cnt_.assign(np, 0);
  seg_.assign(np + 1, 0);
  int64_t nb = 0;
  for (int p = 0; p < np; ++p) {
    cnt_[p] = static_cast<int64_t>(counts[p]);
    seg_[p] = p + nb;
    nb += cnt_[p];
  }
  seg_[np] = np + nb;
  std::vector<double> mine(own_b_.size());
  for (size_t k = 0; k < own_b_.size(); ++k) mine[k] = Collective::pack(key(own_b_[k]));
  std::vector<double> keys_in(static_cast<size_t>(nb));
  coll_.allgather(mine.data(), static_cast<int64_t>(mine.size()), keys_in.data(), nb);
  std::vector<int64_t> keys(static_cast<size_t>(nb));
  for (int64_t k = 0; k < nb; ++k) keys[k] = Collective::unpack(keys_in[k]);
  std::vector<int64_t> sorted(keys);
  std::sort(sorted.begin(), sorted.end());
  for (int64_t k = 1; k < nb; ++k)
    if (sorted[k] == sorted[k - 1])
      throw Error(MFREE_ERR_INPUT, "global id " + std::to_string(sorted[k] / nc_) +
                                       " is the id of boundary particles of two ranks (ids must be unique)");
  auto pos = [&](int64_t k) -> int32_t {
    auto it = std::lower_bound(sorted.begin(), sorted.end(), k);
    return it != sorted.end() && *it == k ? static_cast<int32_t>(it - sorted.begin()) : -1;
  };
  perm_.resize(static_cast<size_t>(nb));
  for (int64_t k = 0; k < nb; ++k) perm_[k] = pos(keys[k]);
  // where the boundary unknowns are here (owned or ghost)
  bpos_.assign(nl_, -1);
  gb_local_.assign(static_cast<size_t>(nb), -1);
  for (int32_t d = 0; d < nl_; ++d) {
    bpos_[d] = pos(key(d));
    if (bpos_[d] >= 0) gb_local_[bpos_[d]] = d;
  }
  // the block K_bb: each rank's owned boundary rows, as (row, column, value)
  std::vector<double> trip_in;
  for (int32_t d : own_b_)
    for (int64_t k = K_.rowptr()[d]; k < K_.rowptr()[d + 1]; ++k) {
      const int32_t c = K_.colidx()[k];
      if (bpos_[c] >= 0 && K_.values()[k] != 0.0) {
        trip_in.push_back(bpos_[d]);
        trip_in.push_back(bpos_[c]);
        trip_in.push_back(K_.values()[k]);
      }
    }
  const std::vector<double> trip_all = coll_.allgather(trip_in.data(), static_cast<int64_t>(trip_in.size()));
  std::vector<Eigen::Triplet<double>> trip;
  for (size_t k = 0; k + 2 < trip_all.size(); k += 3)
    trip.emplace_back(static_cast<int>(trip_all[k]), static_cast<int>(trip_all[k + 1]), trip_all[k + 2]);
  // (sorted: the matrix must not depend on the ranks' order of sending)
  std::sort(trip.begin(), trip.end(), [](const Eigen::Triplet<double> &x, const Eigen::Triplet<double> &y) {
    return x.col() != y.col() ? x.col() < y.col() : x.row() < y.row();
  });
  if (nb > 0) factor_boundary(static_cast<int32_t>(nb), trip);
  rbe_.resize(nb);
  send_.resize(own_b_.size() + 1);
  gathered_.resize(static_cast<size_t>(seg_[np]));
}

Report ElasticSystem::fill_state(double t, const double *u, const Report &mine) const {
  std::copy(u, u + nd_, work_.begin());
  coll_.exchange(nc_, work_.data(), nc_);
  // this rank's boundary rows' data (g f0 - K_bI u_I), with its status, to every rank
  const double g = history(t);
  send_[0] = static_cast<double>(mine.status);
  for (size_t q = 0; q < own_b_.size(); ++q) {
    const int32_t d = own_b_[q];
    double s = g * f0_[d];
    for (int64_t k = K_.rowptr()[d]; k < K_.rowptr()[d + 1]; ++k) {
      const int32_t c = K_.colidx()[k];
      if (bpos_[c] < 0) s -= K_.values()[k] * work_[c];
    }
    send_[q + 1] = s;
  }
  const int np = static_cast<int>(cnt_.size());
  coll_.allgather(send_.data(), static_cast<int64_t>(send_.size()), gathered_.data(), seg_[np]);
  std::vector<double> st(np);
  for (int p = 0; p < np; ++p) st[p] = gathered_[seg_[p]];
  Report agreed = coll_.agree_from(st, mine);
  if (!agreed.ok()) return agreed;
  if (rbe_.size() == 0) return agreed;
  int64_t k = 0;
  for (int p = 0; p < np; ++p)
    for (int64_t j = 0; j < cnt_[p]; ++j) rbe_(perm_[k++]) = gathered_[seg_[p] + 1 + j];
  const Eigen::VectorXd ub = lu_->solve(rbe_);
  for (Eigen::Index q = 0; q < ub.size(); ++q)
    if (gb_local_[q] >= 0) work_[gb_local_[q]] = ub(q);
  return agreed;
}

// The velocity rows of the one-process system's mass (mass(): column d of M_ff, i.e. the
// entries m_JK of every J for unknown K, in the order of J) from the consistent mass on
// the stiffness's points: an owned K's column is complete here (every quadrature point
// in its support is the rank's, every particle whose support reaches them one of its
// particles), and each entry sums the points in the global order, so the rows are one
// rank's bit for bit, listed in global-id order. Columns: the local unknowns'
// displacements (nl_), then their velocities (nl_); constrained unknowns (here or on
// their owner: bpos_) keep identity rows and are no column of a free row.
void ElasticSystem::init_consistent_ranks() {
  SparseMatrix Ms;
  as_->mass_on_same_points(MFREE_FORM_MASS, rho_)->assemble_matrix(Ms);
  const int32_t n = as_->particles().num_owned(), np = as_->particles().size();
  std::vector<std::vector<std::pair<int64_t, std::pair<int32_t, double>>>> col(n);
  for (int32_t J = 0; J < np; ++J)
    for (int64_t k = Ms.rowptr()[J]; k < Ms.rowptr()[J + 1]; ++k) {
      const int32_t K = Ms.colidx()[k];
      if (K < n && Ms.values()[k] != 0.0) col[K].push_back({key(J * nc_), {J, Ms.values()[k]}});
    }
  std::vector<int64_t> rp(static_cast<size_t>(neq()) + 1, 0);
  std::vector<int32_t> ci;
  std::vector<double> va;
  for (int32_t q = 0; q < neq(); ++q) {
    const int32_t d = q - nd_;
    if (d >= 0 && bpos_[d] < 0) {
      auto &c = col[d / nc_];
      std::sort(c.begin(), c.end());
      const int a = d % nc_;
      for (const auto &e : c) {
        const int32_t u = e.second.first * nc_ + a;
        if (bpos_[u] >= 0) continue;
        ci.push_back(nl_ + u);
        va.push_back(e.second.second);
      }
    } else {
      ci.push_back(d >= 0 ? nl_ + d : q);
      va.push_back(1.0);
    }
    rp[q + 1] = static_cast<int64_t>(ci.size());
  }
  cmass_.set_pattern(neq(), 2 * nl_, std::move(rp), std::move(ci));
  cmass_.values_mut() = std::move(va);
  cmass_done_ = true;
}

Report ElasticSystem::apply_mass(const double *y, bool consistent, const double *v, double *Mv) {
  if (!ranks_) return System::apply_mass(y, consistent, v, Mv);
  // one outcome for the arguments and the first product's set-up (the product is
  // collective: no rank may leave before the exchange)
  const bool cm = consistent && galerkin_;
  Report rep = settle(coll_.agree(coll_.local([&] {
    if ((!y || !v || !Mv) && nd_ > 0) throw Error(MFREE_ERR_NULL, "y, v or Mv is NULL");
    if (cm && !cmass_done_) init_consistent_ranks();
    return Report();
  })));
  if (!cm) {
    SparseMatrix M;
    mass(y, false, M);
    M.apply(v, Mv);
    return rep;
  }
  cw_.assign(2 * static_cast<size_t>(nl_), 0.0);
  std::copy(v, v + nd_, cw_.begin());
  std::copy(v + nd_, v + 2 * nd_, cw_.begin() + nl_);
  coll_.exchange(nc_, cw_.data() + nl_, nc_);
  cmass_.apply(cw_.data(), Mv);
  return rep;
}

}  // namespace mfree
