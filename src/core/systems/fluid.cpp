#include "core/systems/fluid.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <numeric>
#include <sstream>

#include "core/base/exact_sum.hpp"
#include "core/base/parallel.hpp"
#include "core/base/simd.hpp"

namespace mfree {

FluidSystem::FluidSystem(int dim, int32_t n) : dim_(dim), n_(n), ps_(dim, n) {
  if (dim != 2 && dim != 3) throw Error(MFREE_ERR_ARG, "the fluid system is 2D or 3D, not " + std::to_string(dim) + "D");
  rho0_.assign(n, 1000.0);
  vol_.assign(n > 0 ? n : 1, 1.0);
}

void FluidSystem::set_fluid(const double *rho0, int64_t stride, double kappa, double gamma, double mu) {
  if (!rho0) throw Error(MFREE_ERR_NULL, "rest density is NULL");
  if (stride < 0) throw Error(MFREE_ERR_ARG, "negative stride");
  check_stride(n_, stride, "rest density");
  if (!(std::isfinite(kappa) && kappa > 0.0) || !(std::isfinite(gamma) && gamma >= 1.0) ||
      !(std::isfinite(mu) && mu >= 0.0))
    throw Error(MFREE_ERR_ARG, "needs kappa > 0, gamma >= 1, mu >= 0");
  HVec<double> r(n_);
  for (int32_t i = 0; i < n_; ++i) {
    r[i] = rho0[i * stride];
    if (!(std::isfinite(r[i]) && r[i] > 0.0))
      throw Error(MFREE_ERR_INPUT, "rest density of particle " + std::to_string(i) + " must be finite and > 0");
  }
  to_nodes(r);
  rho0_.swap(r);
  kappa_ = kappa;
  gamma_ = gamma;
  mu_ = mu;
}

void FluidSystem::set_masses(const double *m, int64_t stride) {
  if (!m && n_ > 0) throw Error(MFREE_ERR_NULL, "masses are NULL");
  if (stride < 0) throw Error(MFREE_ERR_ARG, "negative stride");
  check_stride(n_, stride, "mass");
  HVec<double> v(n_);
  for (int32_t i = 0; i < n_; ++i) {
    v[i] = m[i * stride];
    if (!(std::isfinite(v[i]) && v[i] > 0.0))
      throw Error(MFREE_ERR_INPUT, "mass of particle " + std::to_string(i) + " must be finite and > 0");
  }
  to_nodes(v);
  mass_.swap(v);
}

void FluidSystem::set_smoothing(double h) {
  if (!(std::isfinite(h) && h > 0.0)) throw Error(MFREE_ERR_ARG, "h must be finite and > 0");
  ps_.set_support(&h, 0, MFREE_COPY);  // (first: the one step that may fail)
  h_ = h;
}

void FluidSystem::set_gravity(const double *g) {
  if (!g) throw Error(MFREE_ERR_NULL, "gravity is NULL");
  for (int c = 0; c < dim_; ++c) {
    if (!std::isfinite(g[c])) throw Error(MFREE_ERR_INPUT, "gravity must be finite");
    g_[c] = g[c];
  }
}

void FluidSystem::set_lumping(int lump) {
  if (lump != MFREE_LUMP_GALERKIN && lump != MFREE_LUMP_PHYSICAL) throw Error(MFREE_ERR_ARG, "unknown lumping");
  lump_ = lump;
}

void FluidSystem::set_walls(int32_t nwall, const double *x, const double *normals, double r0, double strength) {
  if (nwall < 0) throw Error(MFREE_ERR_ARG, "negative wall count");
  if (nwall > 0 && (!x || !normals)) throw Error(MFREE_ERR_NULL, "wall positions or normals are NULL");
  if (!(std::isfinite(r0) && r0 > 0.0) || !(std::isfinite(strength) && strength >= 0.0))
    throw Error(MFREE_ERR_ARG, "needs r0 > 0 and strength >= 0");
  for (int32_t k = 0; k < nwall; ++k) {
    double len = 0.0;
    for (int c = 0; c < dim_; ++c) len += normals[k * dim_ + c] * normals[k * dim_ + c];
    if (!(std::isfinite(len) && std::fabs(len - 1.0) < 1e-6))
      throw Error(MFREE_ERR_INPUT, "wall normal " + std::to_string(k) + " is not a unit vector");
  }
  auto w = std::make_unique<ParticleSet>(dim_, nwall);
  w->set_positions(x, MFREE_LAYOUT_AOS, dim_, MFREE_COPY);  // validates finiteness
  const double hw = 0.5 * r0;                               // gather radius kappa*h = r0
  w->set_support(&hw, 0, MFREE_COPY);
  w->setup();
  HVec<double> n(normals, normals + static_cast<size_t>(nwall) * dim_);
  walls_ = std::move(w);
  wall_n_.swap(n);
  r0_ = r0;
  strength_ = strength;
}

void FluidSystem::set_box(const double *lo, const double *hi) {
  if (!lo || !hi) throw Error(MFREE_ERR_NULL, "box bounds are NULL");
  for (int c = 0; c < dim_; ++c) {
    if (!(std::isfinite(lo[c]) && std::isfinite(hi[c]) && hi[c] > lo[c]))
      throw Error(MFREE_ERR_ARG, "box needs finite lo < hi");
    lo_[c] = lo[c];
    hi_[c] = hi[c];
  }
  box_ = true;
}

void FluidSystem::set_shepard_condition(double max_cond) {
  if (std::isnan(max_cond) || !(max_cond >= 1.0))
    throw Error(MFREE_ERR_ARG, "the Shepard condition threshold must be >= 1 (or +infinity), not " +
                                   std::to_string(max_cond));
  shepard_cond_ = max_cond;
}

void FluidSystem::set_lumped_mass_step(int on) {
  if (on != 0 && on != 1) throw Error(MFREE_ERR_ARG, "lumped-mass step: 0 or 1, not " + std::to_string(on));
  lumped_step_ = on != 0;
}

void FluidSystem::set_acoustic_step(int on) {
  if (on != 0 && on != 1) throw Error(MFREE_ERR_ARG, "acoustic step: 0 or 1, not " + std::to_string(on));
  acoustic_step_ = on != 0;
  pw_u_.clear();  // a fresh start of the power iteration
  pw_started_ = false;
}

void FluidSystem::check_ready() const {
  if (mass_.size() != static_cast<size_t>(n_)) throw Error(MFREE_ERR_STATE, "particle masses are not set");
  if (!(h_ > 0.0)) throw Error(MFREE_ERR_STATE, "the smoothing length is not set");
}

Report FluidSystem::check_state(const double *y, int64_t step) const {
  Report rep;
  const double *x = y, *v = y + static_cast<size_t>(dim_) * n_, *rho = y + 2 * static_cast<size_t>(dim_) * n_;
  // messages are formatted only on failure (this runs twice per step)
  auto fail = [&](mfree_status_t status, int32_t i, const char *what, double value, int c) {
    std::ostringstream s;
    if (step >= 0) s << "step " << step << ": ";
    s << "particle " << i << what;
    if (c >= 0) s << c << " = " << value << ")";
    else if (status == MFREE_FAIL_INVALID_DATA) s << value << " <= 0";
    rep.fail(status, s.str());
    return rep;
  };
  const int dim = dim_;
  auto valid = [&](int64_t i) {
    bool ok = rho[i] > 0.0 && rho[i] <= DBL_MAX;  // false for NaN
    for (int c = 0; c < dim; ++c) {
      const double xc = x[i * dim + c];
      ok = ok && std::isfinite(xc) && std::isfinite(v[i * dim + c]) && (!box_ || (xc >= lo_[c] && xc <= hi_[c]));
    }
    return ok;
  };
  // the first invalid particle: the lowest of the threads' first ones
  int32_t first[64];  // parallel_blocks runs at most 64 threads
  std::fill(first, first + 64, n_);
  parallel_blocks(n_, light_threads(n_), [&](int t, int64_t b, int64_t e) {
    // the common case first: branch-free over flat arrays (vectorisable), then the
    // particle-by-particle search only in a block that holds an invalid particle
    bool bad = false;
#if MFREE_VECTOR_EXTENSIONS
    if (dim == 2) {  // two particles (densities) and one particle (x, v) per operation
      // No lane masks: SSE2 has no blend, and GCC splits a masked accumulation into
      // scalar selects. A product with 0 is NaN exactly for a non-finite value, so a sum
      // of them is 0 exactly when every entry is finite; minima and maxima (minpd,
      // maxpd) of the finite values then decide the signs and the box.
      using simd::V2;
      V2 fin = {0.0, 0.0}, rmin = {DBL_MAX, DBL_MAX}, xmin = rmin, xmax = -rmin;
      int64_t i = b;
      for (; i + 2 <= e; i += 2) {
        V2 r;
        simd::load<2>(r, rho + i);
        fin += r * 0.0;
        rmin = rmin < r ? rmin : r;
      }
      for (; i < e; ++i) bad |= !(rho[i] > 0.0) | !(rho[i] <= DBL_MAX);
      for (i = b; i < e; ++i) {
        V2 xi, vi;
        simd::load<2>(xi, x + 2 * i);
        simd::load<2>(vi, v + 2 * i);
        fin += xi * 0.0 + vi * 0.0;
        xmin = xmin < xi ? xmin : xi;
        xmax = xmax > xi ? xmax : xi;
      }
      bad |= !(fin[0] == 0.0 && fin[1] == 0.0) || !(rmin[0] > 0.0 && rmin[1] > 0.0);
      if (box_) bad |= !(xmin[0] >= lo_[0] && xmin[1] >= lo_[1] && xmax[0] <= hi_[0] && xmax[1] <= hi_[1]);
      if (bad) {
        for (int64_t k = b; k < e; ++k)
          if (!valid(k)) {
            first[t] = static_cast<int32_t>(k);
            break;
          }
      }
      return;
    }
#endif
    for (int64_t i = b; i < e; ++i) bad |= !(rho[i] > 0.0) | !(rho[i] <= DBL_MAX);
    for (int64_t q = b * dim; q < e * dim; ++q) bad |= !(std::fabs(v[q]) <= DBL_MAX) | !(std::fabs(x[q]) <= DBL_MAX);
    if (box_)
      for (int64_t i = b; i < e; ++i)
        for (int c = 0; c < dim; ++c) bad |= !(x[i * dim + c] >= lo_[c]) | !(x[i * dim + c] <= hi_[c]);
    if (!bad) return;
    for (int64_t i = b; i < e; ++i)
      if (!valid(i)) {
        first[t] = static_cast<int32_t>(i);
        break;
      }
  });
  const int32_t i = *std::min_element(first, first + 64);
  if (i == n_) return rep;
  bool finite = std::isfinite(rho[i]);
  for (int c = 0; c < dim; ++c) finite = finite && std::isfinite(x[i * dim + c]) && std::isfinite(v[i * dim + c]);
  if (!finite) return fail(MFREE_FAIL_NONFINITE, i, " has a non-finite position, velocity or density", 0.0, -1);
  if (!(rho[i] > 0.0)) return fail(MFREE_FAIL_INVALID_DATA, i, " has density ", rho[i], -1);
  for (int c = 0; c < dim && box_; ++c)
    if (x[i * dim + c] < lo_[c] || x[i * dim + c] > hi_[c])
      return fail(MFREE_FAIL_DOMAIN, i, " left the box (coordinate ", x[i * dim + c], c);
  return rep;
}

double FluidSystem::tait(double rho, double rho0) const {
  const double r = rho / rho0;
  if (gamma_ == 7.0) {  // the usual exponent: no pow per particle
    const double r2 = r * r;
    return r2 * r2 * r2 * r;
  }
  return std::pow(r, gamma_);
}

Report FluidSystem::rhs(double t, const double *y, double *ydot) {
  (void)t;
  if (open_) return open_rhs(y, ydot);
  Report rep = prepare(y);
  if (!rep.ok()) return rep;
  const size_t nd = static_cast<size_t>(dim_) * n_;
  const double *v = y + nd, *rho = y + 2 * nd;
  rep = accel(v, rho, ydot + nd);
  kinematics(v, rho, ydot, ydot + 2 * nd);
  return rep;
}

Report FluidSystem::velocity(const double *y, double *vhat) {
  if (open_) return open_velocity(y, vhat);
  Report rep = prepare(y);
  if (!rep.ok()) return rep;
  const size_t nd = static_cast<size_t>(dim_) * n_;
  kinematics(y + nd, y + 2 * nd, vhat, nullptr);
  return rep;
}

void FluidSystem::pressure(const double *y, double *p) const {
  if (open_) return open_pressure(y, p);
  const double *rho = y + 2 * static_cast<size_t>(dim_) * n_;
  for (int32_t i = 0; i < n_; ++i) p[i] = pressure_at(rho[i], rho0_[i]);
}

Report FluidSystem::interpolation(const double *y, SparseMatrix &S) {
  if (open_) return open_interpolation(y, S);
  Report rep = prepare(y);
  if (!rep.ok()) return rep;
  std::vector<int32_t> id(n_);
  std::iota(id.begin(), id.end(), 0);
  interpolation_rows(n_, id.data(), id.data(), n_, S);
  return rep;
}

void FluidSystem::interpolation_rows(int32_t np, const int32_t *node, const int32_t *col, int32_t ncols,
                                     SparseMatrix &S) const {
  // rows are not guaranteed sorted by column: sort each row with its values
  // the fluid rows and columns only (dummies are not unknowns)
  const auto &acols = cols_;
  std::vector<int64_t> rp(static_cast<size_t>(np) + 1, 0);
  std::vector<int32_t> cols;
  std::vector<double> vals;
  std::vector<std::pair<int32_t, double>> row;
  for (int32_t r = 0; r < np; ++r) {
    const int32_t k = node[r];
    row.clear();
    for (int64_t e = rb(k); e < re(k); ++e)
      if (acols[e] < n_) row.push_back({col[acols[e]], N_[e]});
    std::sort(row.begin(), row.end());
    for (auto &q : row) {
      cols.push_back(q.first);
      vals.push_back(q.second);
    }
    rp[r + 1] = static_cast<int64_t>(cols.size());
  }
  S.set_pattern(np, ncols, rp, cols);
  std::copy(vals.begin(), vals.end(), S.values_mut().begin());
}

Report FluidSystem::mass(const double *y, bool consistent, SparseMatrix &M) {
  if (open_) return open_mass(y, consistent, M);
  Report rep = prepare(y);
  if (!rep.ok()) return rep;
  std::vector<int32_t> part(n_);
  std::iota(part.begin(), part.end(), 0);
  mass_matrix(n_, part.data(), part.data(), consistent, M);
  return rep;
}

bool FluidSystem::KeptMass::holds(const double *at, int32_t neq, bool c, int64_t g) const {
  return valid && consistent == c && gen == g && y.size() == static_cast<size_t>(neq) &&
         (neq == 0 || std::memcmp(y.data(), at, static_cast<size_t>(neq) * sizeof(double)) == 0);
}

void FluidSystem::KeptMass::keep(const double *at, int32_t neq, bool c, int64_t g) {
  y.assign(at, at + neq);
  consistent = c;
  gen = g;
  valid = true;
}

Report FluidSystem::apply_mass(const double *y, bool consistent, const double *v, double *Mv) {
  // (open boundaries change the particles' states without a setter: their generation
  // counts too; the sum of the two counters changes whenever either does)
  const int64_t gen = options_gen_ + (open_ ? open_->gen : 0);
  if (!kept_mass_.holds(y, neq(), consistent, gen)) {
    kept_mass_.valid = false;
    Report rep = mass(y, consistent, kept_mass_.M);
    if (!rep.ok()) return rep;
    kept_mass_.keep(y, neq(), consistent, gen);
  }
  kept_mass_.M.apply(v, Mv);
  return Report();
}

void FluidSystem::mass_matrix(int32_t np, const int32_t *node, const int32_t *part, bool consistent,
                              SparseMatrix &M) const {
  const int dim = dim_;
  const size_t nd = static_cast<size_t>(dim) * np;
  const auto &cols = cols_;
  const auto &N = N_;
  // node-level velocity block: consistent m_ij = sum_k N_i(x_k) N_j(x_k) M_k (003 eq 42),
  // or the lumped row sums; each entry sums its terms sorted by value, an order that
  // does not depend on the nodes' numbering
  std::vector<std::vector<std::pair<int32_t, double>>> rows(np);
  // with dummies: fluid rows and columns only, lumped masses as in accel (fluid_wall.hpp)
  for (int32_t k = 0; k < n_; ++k)
    for (int64_t a = rb(k); a < re(k); ++a) {
      const int32_t i = cols[a] < n_ ? part[cols[a]] : -1;
      if (i < 0) continue;
      for (int64_t b = rb(k); b < re(k); ++b) {
        const double m = N[a] * N[b] * mass_[k];
        if (consistent) {
          const int32_t j = cols[b] < n_ ? part[cols[b]] : -1;
          if (j >= 0) rows[i].push_back({j, m});
        } else {
          rows[i].push_back({i, m / share(k)});
        }
      }
    }
  const int32_t neq = (2 * dim + 1) * np;
  std::vector<int64_t> rowptr(static_cast<size_t>(neq) + 1, 0);
  std::vector<int32_t> ci;
  std::vector<double> vals;
  int32_t r = 0;
  auto identity_row = [&]() {
    ci.push_back(r);
    vals.push_back(1.0);
    rowptr[r + 1] = static_cast<int64_t>(ci.size());
    ++r;
  };
  for (size_t q = 0; q < nd; ++q) identity_row();
  for (int32_t i = 0; i < np; ++i) {
    auto &row = rows[i];
    std::sort(row.begin(), row.end());
    std::vector<std::pair<int32_t, double>> merged;
    for (auto &e : row) {
      if (!merged.empty() && merged.back().first == e.first) merged.back().second += e.second;
      else merged.push_back(e);
    }
    if (lump_ == MFREE_LUMP_PHYSICAL && !consistent) merged.assign(1, {i, mass_[node[i]]});
    for (int c = 0; c < dim; ++c) {
      for (auto &e : merged) {
        ci.push_back(static_cast<int32_t>(nd) + e.first * dim + c);
        vals.push_back(e.second);
      }
      rowptr[r + 1] = static_cast<int64_t>(ci.size());
      ++r;
    }
  }
  for (int32_t i = 0; i < np; ++i) identity_row();
  M.set_pattern(neq, neq, std::move(rowptr), std::move(ci));
  std::copy(vals.begin(), vals.end(), M.values_mut().begin());
}

// The Galerkin lumped masses m_i = sum_k N_i(x_k) M_k (eq 56) on the prepared tables, as
// accel sums them (dummies carry no fluid mass), in the order of the rows.
void FluidSystem::galerkin_lumped(std::vector<double> &m) const {
  m.assign(n_, 0.0);
  for (int32_t k = 0; k < nq(); ++k)
    for (int64_t q = rb(k); q < re(k); ++q)
      if (cols_[q] < n_) m[cols_[q]] += N_[q] * (k < n_ ? mass_[k] / share(k) : 0.0);
}

// The largest eigenvalue omega^2 of the linearised acoustic operator M_L^-1 B^T M C B on
// the prepared tables (B: nodal velocities to the divergence at the particles, as the
// density rate of eq 70 takes it; M the particle masses, C = gamma kappa / rho_k as in
// eq 121, M_L the lumped masses accel divides by), by `iters` steps of a power iteration
// whose vector is kept from the last call: the dominant mode moves slowly with the
// particles, so a few iterations a step follow it. A small fixed vector is added at every
// call so that a mode growing elsewhere (a cluster becoming ill-conditioned) always has a
// share to grow from. The Rayleigh quotient in the M_L inner product (the operator is
// self-adjoint in it) bounds omega^2 from below. Fluid particles only (no dummies); serial,
// so the result does not depend on the thread count. On ranks the same: each node's
// values are those of one rank (the ghosts' vector from their owners, the fixed vector
// indexed by global id, the products summed over the rows in node order), and the sums
// over the particles are exact (each particle's share rounded as on one rank, then added
// without rounding over every rank's owned particles), so omega does not depend on the
// partition.
double FluidSystem::acoustic_omega2(const double *y, int iters) {
  const int D = dim_;
  const size_t nd = static_cast<size_t>(D) * n_;
  const double *rho = y + 2 * nd;
  const bool galerkin = lump_ == MFREE_LUMP_GALERKIN;
  if (galerkin) galerkin_lumped(pw_m_);
  else pw_m_.assign(mass_.begin(), mass_.begin() + n_);
  const Collective *coll = collective();
  auto totals = [&](ExactSum *s, int ns, double *out) {
    if (coll) coll->exact_totals(s, ns, out);
    else
      for (int k = 0; k < ns; ++k) out[k] = s[k].value();
  };
  // |u|^2, the unknowns' count and the ranks without a vector: the first call (or the
  // particles changed) converges from scratch, on every rank alike
  double uu[3];
  {
    const bool fresh = !pw_started_ || pw_u_.size() != nd;
    ExactSum s[3];
    for (int32_t i = 0; i < n_ && !fresh; ++i) {
      if (!steps_by(i)) continue;
      double ui = 0.0;
      for (int c = 0; c < D; ++c) ui += pw_u_[static_cast<size_t>(i) * D + c] * pw_u_[static_cast<size_t>(i) * D + c];
      s[0].add(ui);
    }
    for (int32_t i = 0; i < n_; ++i)
      if (steps_by(i)) s[1].add(D);
    s[2].add(fresh ? 1.0 : 0.0);
    totals(s, 3, uu);
  }
  if (uu[2] > 0.0) {
    pw_u_.assign(nd, 0.0);
    uu[0] = 0.0;
    iters = std::max(iters, 30);
  }
  pw_started_ = true;
  const double seed = uu[0] > 0.0 ? 1e-3 * std::sqrt(uu[0] / uu[1]) : 1.0;  // relative to u
  for (int32_t i = 0; i < n_; ++i) {  // a fixed pseudo-random vector (Knuth's multiplicative hash)
    if (!steps_by(i)) continue;
    for (int c = 0; c < D; ++c) {
      const size_t g = static_cast<size_t>(global_id(i)) * D + c;
      pw_u_[static_cast<size_t>(i) * D + c] += seed * (static_cast<double>((g * 2654435761u) % 1000) / 1000.0 - 0.5);
    }
  }
  pw_w_.resize(nd);
  pw_div_.resize(n_);
  double lam = 0.0;
  for (int it = 0; it < iters; ++it) {
    to_ghosts(pw_u_.data(), D);
    for (int32_t k = 0; k < n_; ++k) {  // M C B u
      double dv = 0.0;
      for (int64_t q = rb(k); q < re(k); ++q)
        if (cols_[q] < n_)
          for (int c = 0; c < D; ++c) dv += pw_u_[static_cast<size_t>(cols_[q]) * D + c] * G_[q * D + c];
      pw_div_[k] = dv * mass_[k] * gamma_ * kappa_ / rho[k];
    }
    std::fill(pw_w_.begin(), pw_w_.end(), 0.0);
    for (int32_t k = 0; k < n_; ++k)  // B^T (M C B u)
      for (int64_t q = rb(k); q < re(k); ++q)
        if (cols_[q] < n_)
          for (int c = 0; c < D; ++c) pw_w_[static_cast<size_t>(cols_[q]) * D + c] += pw_div_[k] * G_[q * D + c];
    ExactSum s[3];  // u.w, u.u M_L, w.w M_L with w = M_L^-1 B^T M C B u
    for (int32_t i = 0; i < n_; ++i) {
      if (!steps_by(i)) continue;
      double num = 0.0, den = 0.0, nw = 0.0;
      for (int c = 0; c < D; ++c) {
        const size_t q = static_cast<size_t>(i) * D + c;
        num += pw_u_[q] * pw_w_[q];
        den += pw_u_[q] * pw_u_[q];
        pw_w_[q] /= pw_m_[i];
        nw += pw_w_[q] * pw_w_[q];
      }
      s[0].add(num);
      s[1].add(den * pw_m_[i]);
      s[2].add(nw * pw_m_[i]);
    }
    double tot[3];
    totals(s, 3, tot);
    const double den = tot[1], nw = tot[2];
    if (!(den > 0.0 && nw > 0.0 && std::isfinite(nw))) break;  // no fluid motion the rows see
    lam = tot[0] / den;
    const double sc = 1.0 / std::sqrt(nw);
    for (int32_t i = 0; i < n_; ++i)
      if (steps_by(i))
        for (int c = 0; c < D; ++c) pw_u_[static_cast<size_t>(i) * D + c] = pw_w_[static_cast<size_t>(i) * D + c] * sc;
  }
  return lam;
}

double FluidSystem::stable_dt(const double *y) {
  const size_t nd = static_cast<size_t>(dim_) * n_;
  const double *v = y + nd, *rho = y + 2 * nd;
  double tmax[64] = {};  // per thread (parallel_blocks runs at most 64): a maximum is exact in any order
  parallel_blocks(n_, light_threads(n_), [&](int t, int64_t b, int64_t e) {
    double cm = 0.0;
#if MFREE_VECTOR_EXTENSIONS
    if (dim_ == 2) {  // two particles at a time: the same correctly rounded roots, an exact maximum
      using simd::V2;
      const V2 gk = {gamma_ * kappa_, gamma_ * kappa_};
      V2 m2 = {0.0, 0.0};
      for (; b + 2 <= e; b += 2) {
        V2 v0, v1, r;
        simd::load<2>(v0, v + 2 * b);
        simd::load<2>(v1, v + 2 * b + 2);
        simd::load<2>(r, rho + b);
        const V2 vx = {v0[0], v1[0]}, vy = {v0[1], v1[1]};
        const V2 vv = vx * vx + vy * vy, q = gk / r;
        const V2 s = V2{std::sqrt(q[0]), std::sqrt(q[1])} + V2{std::sqrt(vv[0]), std::sqrt(vv[1])};
        m2 = m2 > s ? m2 : s;  // maxpd
      }
      cm = std::max(m2[0], m2[1]);
    }
#endif
    for (int64_t i = b; i < e; ++i) {
      double vv = 0.0;
      for (int c = 0; c < dim_; ++c) vv += v[i * dim_ + c] * v[i * dim_ + c];
      cm = std::max(cm, std::sqrt(gamma_ * kappa_ / rho[i]) + std::sqrt(vv));  // 003 eqs 120-121
    }
    tmax[t] = cm;
  });
  double cmax = *std::max_element(tmax, tmax + 64);
  if (lumped_step_ && lump_ == MFREE_LUMP_GALERKIN) {
    // Eq 120 takes a particle's inertia to be its mass M_i; the Galerkin lumped mass m_i
    // (eq 56, as accel sums it) is what the acceleration divides by, and next to rows
    // that extrapolate (ill-conditioned linear MLS at a wall or a sheet, whose N_i(x_k) < 0)
    // it falls to a third of M_i: the local acoustic frequency grows as sqrt(M_i / m_i)
    // and leap-frog's limit dt omega = 2 is crossed (docs/time-integration.md).
    galerkin_lumped(lumped_);
    for (int32_t i = 0; i < n_; ++i) {
      if (!(lumped_[i] < mass_[i]) || !steps_by(i)) continue;
      double vv = 0.0;
      for (int c = 0; c < dim_; ++c) vv += v[i * dim_ + c] * v[i * dim_ + c];
      const double s = std::sqrt(gamma_ * kappa_ / rho[i]) + std::sqrt(vv);
      // (a non-positive lumped mass stops accel with MFREE_FAIL_SINGULAR)
      if (lumped_[i] > 0.0) cmax = std::max(cmax, s * std::sqrt(mass_[i] / lumped_[i]));
    }
  }
  return cmax > 0.0 ? h_ / cmax : INFINITY;
}

double FluidSystem::acoustic_cap(const double *y) {
  if (!acoustic_step_) return INFINITY;
  // Eq 120 measures the frequencies against h / c; at crowded sites beside a wall the
  // rows' gradients (and the lumped masses) make the largest frequency omega of the
  // acoustic operator exceed what h / c assumes, and with omega dt near 2 both schemes
  // grow a period-2 mode there (docs/time-integration.md). 1.5 / omega leaves a quarter
  // of the limit 2 for what the linear acoustics leave out (viscosity, the wall force)
  // and for the power iteration's estimate from below.
  const double w2 = acoustic_omega2(y, 2);
  return w2 > 0.0 ? 1.5 / std::sqrt(w2) : INFINITY;
}

namespace {
// A failure inside integrate's step `step` (1 for the first): the message names it.
Report step_failed(Report r, int64_t step, const char *stage) {
  r.message = "step " + std::to_string(step) + stage + ": " + r.message;
  return r;
}
}  // namespace

std::string FluidSystem::fastest(const double *y) const {
  const size_t nd = static_cast<size_t>(dim_) * n_;
  const double *v = y + nd, *rho = y + 2 * nd;
  int32_t imax = 0;
  double smax = -1.0;
  for (int32_t i = 0; i < n_; ++i) {  // without overflow in |v|: hypot
    double vi = 0.0;
    for (int c = 0; c < dim_; ++c) vi = std::hypot(vi, v[static_cast<size_t>(i) * dim_ + c]);
    const double si = std::sqrt(gamma_ * kappa_ / rho[i]) + vi;
    if (si > smax) smax = si, imax = i;
  }
  std::ostringstream s;
  s << " (fastest: particle " << imax << ", c + |v| = " << smax << ")";
  return s.str();
}

Report FluidSystem::integrate(int scheme, double *y, double &t, double t_end, double cfl, double dt_max,
                              mfree_progress_fn progress, void *user, int64_t &nsteps) {
  if (open_) return open_integrate(scheme, y, t, t_end, cfl, dt_max, progress, user, nsteps);
  if (scheme != MFREE_INTEGRATOR_LEAPFROG && scheme != MFREE_INTEGRATOR_PREDICTOR_CORRECTOR)
    throw Error(MFREE_ERR_ARG, "unknown integrator");
  if (!(std::isfinite(t_end) && std::isfinite(t))) throw Error(MFREE_ERR_ARG, "times must be finite");
  if (!(std::isfinite(cfl) && cfl <= 1.0)) throw Error(MFREE_ERR_ARG, "cfl must be finite and <= 1");
  if (!(std::isfinite(dt_max) && dt_max >= 0.0)) throw Error(MFREE_ERR_ARG, "dt_max must be finite and >= 0");
  if (cfl <= 0.0 && dt_max <= 0.0) throw Error(MFREE_ERR_ARG, "give a CFL number or a fixed step dt_max");
  check_ready();
  nsteps = 0;
  Report rep;
  const int dim = dim_;
  const size_t nd = static_cast<size_t>(dim) * n_, ny = static_cast<size_t>(neq());
  work_state_.resize(ny);
  stage_.resize(ny);
  rate_.resize(ny);
  vh_.resize(nd);
  dr_.resize(n_);
  double *rate = rate_.data(), *vh = vh_.data(), *dr = dr_.data();
  while (t < t_end) {
    rep = prepare(y, nsteps > 0);  // after the first step y is the state check_state passed below
    if (!rep.ok()) {
      rep.message = "step " + std::to_string(nsteps) + ": " + rep.message;
      return rep;
    }
    double dt = 0.0;
    rep = step_size(stable_dt(y), cfl, dt_max, t, t_end, nsteps, y, dt, acoustic_cap(y));
    if (!rep.ok()) return rep;
    dt = std::min(dt, t_end - t);
    double *yn = work_state_.data();
    const double *x = y, *v = y + nd, *rho = y + 2 * nd;
    if (scheme == MFREE_INTEGRATOR_LEAPFROG) {
      // 003 Sect. 6.1: a from (x^k, rho^k, v^{k-1/2}); v^{k+1/2} = v + dt a; density rates
      // and interpolated velocities with v^{k+1/2} on the tables at x^k
      Report r = accel(v, rho, rate);
      if (!r.ok()) return step_failed(r, nsteps + 1, "");
      const int nt = light_threads(n_);
      parallel_blocks(static_cast<int64_t>(nd), nt, [&](int, int64_t b, int64_t e) {
        for (int64_t q = b; q < e; ++q) yn[nd + q] = v[q] + dt * rate[q];
      });
      kinematics(yn + nd, rho, vh, dr);
      parallel_blocks(n_, nt, [&](int, int64_t b, int64_t e) {
        for (int64_t q = b * dim; q < e * dim; ++q) yn[q] = x[q] + dt * vh[q];
        for (int64_t i = b; i < e; ++i) yn[2 * nd + i] = rho[i] + dt * dr[i];
      });
    } else {
      // 003 eqs 111-119; f(t, y) on the tables prepared above. The wall force's switch
      // f1 (eq 123) is decided once per step, with the starting v_hat^k, as leap-frog
      // decides it once with v^{k-1/2}: decided again at the predicted state, the half
      // kick of the predictor makes an approaching particle recede there, the corrector
      // stage (the only force of the final update) has no wall force, and a particle
      // resting on the wall sinks through it (003's dam break: the bottom row, T = 0.36).
      Report r = accel(v, rho, rate + nd);
      if (!r.ok()) return step_failed(r, nsteps + 1, "");
      kinematics(v, rho, rate, rate + 2 * nd);
      double *yp = stage_.data();
      for (size_t q = 0; q < ny; ++q) yp[q] = y[q] + 0.5 * dt * rate[q];
      r = prepare(yp);
      if (!r.ok()) return step_failed(r, nsteps + 1, " (predictor)");  // the step being taken, as below
      vh_start_.assign(rate, rate + nd);  // v_hat^k, before accel overwrites rate
      {
        struct Reset {  // also when accel throws
          const double *&p;
          ~Reset() { p = nullptr; }
        } reset{wall_switch_v_};
        wall_switch_v_ = vh_start_.data();
        r = accel(yp + nd, yp + 2 * nd, rate);
      }
      if (!r.ok()) return step_failed(r, nsteps + 1, " (predictor)");
      for (size_t q = 0; q < nd; ++q) yn[nd + q] = v[q] + 0.5 * dt * rate[q];  // v^C
      kinematics(yn + nd, yp + 2 * nd, vh, dr);
      for (int32_t i = 0; i < n_; ++i) yn[2 * nd + i] = rho[i] + 0.5 * dt * dr[i];  // rho^C
      for (size_t q = 0; q < nd; ++q) yn[q] = x[q] + 0.5 * dt * vh[q];              // x^C
      for (size_t q = 0; q < ny; ++q) yn[q] = 2.0 * yn[q] - y[q];                   // eqs 117-119
    }
    Report bad = check_state(yn, nsteps + 1);
    if (!bad.ok()) return bad;  // y keeps the last good state
    parallel_blocks(static_cast<int64_t>(ny), light_threads(n_), [&](int, int64_t b, int64_t e) {
      std::copy(yn + b, yn + e, y + b);
    });
    t = (t_end - t <= dt) ? t_end : t + dt;
    ++nsteps;
    if (progress && progress(user, nsteps, t, dt)) break;
  }
  return rep;
}

Report FluidSystem::step_size(double limit, double cfl, double dt_max, double t, double t_end, int64_t nsteps,
                              const double *y, double &dt, double cap) const {
  Report rep;
  dt = cfl > 0.0 ? cfl * limit : dt_max;
  if (cfl > 0.0 && dt_max > 0.0) dt = std::min(dt, dt_max);
  if (cfl <= 0.0 && dt > limit) {
    std::ostringstream s;
    s << "step " << nsteps + 1 << ": dt = " << dt << " exceeds the CFL limit " << limit << " (003 eq 120)";
    rep.fail(MFREE_FAIL_CFL, s.str());
    return rep;
  }
  dt = std::min(dt, cap);
  if (!(t + dt > t) && dt < t_end - t) {
    // speeds so large that h / max(c + |v|) is 0 (|v|^2 or gamma kappa / rho overflow)
    // or a step below t's resolution: the loop would never end
    std::ostringstream s;
    s << "step " << nsteps + 1 << ": the step dt = " << dt << " no longer advances t = " << t;
    if (cfl > 0.0) s << (y ? fastest(y) : std::string()) << " (003 eq 120)";
    rep.fail(MFREE_FAIL_CFL, s.str());
    return rep;
  }
  dt = std::min(dt, t_end - t);
  return rep;
}

}  // namespace mfree
