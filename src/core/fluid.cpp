#include "fluid.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "kernel.hpp"

namespace mfree {

FluidSystem::FluidSystem(int dim, int32_t n) : dim_(dim), n_(n), ps_(dim, n) {
  if (dim != 2 && dim != 3) throw Error(MFREE_ERR_ARG, "the fluid system is 2D or 3D, not " + std::to_string(dim) + "D");
  rho0_.assign(n, 1000.0);
  vol_.assign(n > 0 ? n : 1, 1.0);
}

void FluidSystem::set_fluid(const double *rho0, int64_t stride, double kappa, double gamma, double mu) {
  if (!rho0) throw Error(MFREE_ERR_NULL, "rest density is NULL");
  if (stride < 0) throw Error(MFREE_ERR_ARG, "negative stride");
  if (!(std::isfinite(kappa) && kappa > 0.0) || !(std::isfinite(gamma) && gamma >= 1.0) ||
      !(std::isfinite(mu) && mu >= 0.0))
    throw Error(MFREE_ERR_ARG, "needs kappa > 0, gamma >= 1, mu >= 0");
  std::vector<double> r(n_);
  for (int32_t i = 0; i < n_; ++i) {
    r[i] = rho0[i * stride];
    if (!(std::isfinite(r[i]) && r[i] > 0.0))
      throw Error(MFREE_ERR_INPUT, "rest density of particle " + std::to_string(i) + " must be finite and > 0");
  }
  rho0_.swap(r);
  kappa_ = kappa;
  gamma_ = gamma;
  mu_ = mu;
}

void FluidSystem::set_masses(const double *m, int64_t stride) {
  if (!m && n_ > 0) throw Error(MFREE_ERR_NULL, "masses are NULL");
  if (stride < 0) throw Error(MFREE_ERR_ARG, "negative stride");
  std::vector<double> v(n_);
  for (int32_t i = 0; i < n_; ++i) {
    v[i] = m[i * stride];
    if (!(std::isfinite(v[i]) && v[i] > 0.0))
      throw Error(MFREE_ERR_INPUT, "mass of particle " + std::to_string(i) + " must be finite and > 0");
  }
  mass_.swap(v);
}

void FluidSystem::set_smoothing(double h) {
  if (!(std::isfinite(h) && h > 0.0)) throw Error(MFREE_ERR_ARG, "h must be finite and > 0");
  h_ = h;
  ps_.set_support(&h_, 0, MFREE_COPY);
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
  walls_ = std::move(w);
  wall_n_.assign(normals, normals + static_cast<size_t>(nwall) * dim_);
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

void FluidSystem::check_ready() const {
  if (mass_.size() != static_cast<size_t>(n_)) throw Error(MFREE_ERR_STATE, "particle masses are not set");
  if (!(h_ > 0.0)) throw Error(MFREE_ERR_STATE, "the smoothing length is not set");
}

Report FluidSystem::check_state(const double *y, const char *when) const {
  Report rep;
  const double *x = y, *v = y + static_cast<size_t>(dim_) * n_, *rho = y + 2 * static_cast<size_t>(dim_) * n_;
  for (int32_t i = 0; i < n_; ++i) {
    bool finite = std::isfinite(rho[i]);
    for (int c = 0; c < dim_; ++c) finite = finite && std::isfinite(x[i * dim_ + c]) && std::isfinite(v[i * dim_ + c]);
    std::ostringstream s;
    if (!finite) {
      s << when << "particle " << i << " has a non-finite position, velocity or density";
      rep.fail(MFREE_FAIL_NONFINITE, s.str());
      return rep;
    }
    if (!(rho[i] > 0.0)) {
      s << when << "particle " << i << " has density " << rho[i] << " <= 0";
      rep.fail(MFREE_FAIL_INVALID_DATA, s.str());
      return rep;
    }
    if (box_)
      for (int c = 0; c < dim_; ++c)
        if (x[i * dim_ + c] < lo_[c] || x[i * dim_ + c] > hi_[c]) {
          s << when << "particle " << i << " left the box (coordinate " << c << " = " << x[i * dim_ + c] << ")";
          rep.fail(MFREE_FAIL_DOMAIN, s.str());
          return rep;
        }
  }
  return rep;
}

Report FluidSystem::prepare(const double *y) {
  check_ready();
  Report rep = check_state(y, "");
  if (!rep.ok()) return rep;
  const double *rho = y + 2 * static_cast<size_t>(dim_) * n_;
  for (int32_t i = 0; i < n_; ++i) vol_[i] = mass_[i] / rho[i];
  ps_.set_positions(y, MFREE_LAYOUT_AOS, dim_, MFREE_BORROW);
  ps_.set_volumes(vol_.data(), 1, MFREE_BORROW);
  Report r = ps_.setup();
  if (!r.ok()) return r;
  if (!approx_) {
    ApproxConfig cfg;
    cfg.method = MFREE_METHOD_MLS;
    cfg.kernel = MFREE_KERNEL_CUBIC_SPLINE;
    cfg.order = 1;
    cfg.flags = MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT;
    cfg.fallback = MFREE_FALLBACK_LOWER_ORDER;  // Shepard at degenerate sites (003 Sect. 2.2)
    approx_ = std::make_unique<Approximant>(&ps_, cfg);
  }
  r = approx_->setup();
  if (!r.ok()) return r;
  shepard_ill_conditioned();
  if (walls_) {
    VectorArray xa;
    xa.ptr = y;
    xa.ld = dim_;
    xa.layout = MFREE_LAYOUT_AOS;
    ScalarArray ha;
    const double hw = 0.5 * r0_;
    ha.ptr = &hw;
    ha.stride = 0;
    find_point_neighbors(*walls_, walls_->site_status(), n_, xa, ha, wall_nbr_);
  }
  return rep;
}

void FluidSystem::shepard_ill_conditioned() {
  // 003 Sect. 6: where the linear-basis moment matrix is ill-conditioned, not only
  // singular, the constant basis is used: Shepard functions N_j = W_j V_j / sum W V. The
  // paper gives no tolerance. A lattice site has a condition estimate of 10-15, a free
  // edge or corner 30-60; a particle left in a thin sheet or strand climbs past 1e3 within
  // a few steps, and its gradients then drive the density negative in one step (dam
  // break along the wall, T ~ 2.2, at every resolution and CFL number tried). Hence the
  // default threshold 100 (mfree_system_set_shepard_condition).
  N_.assign(approx_->values().begin(), approx_->values().end());  // reuses N_'s storage
  G_.assign(approx_->gradients().begin(), approx_->gradients().end());
  const auto &cond = approx_->site_cond();
  const auto &rp = approx_->rowptr();
  const auto &cols = approx_->cols();
  const double tol = shepard_cond_;
  const Kernel kern(MFREE_KERNEL_CUBIC_SPLINE, dim_, 0.0);
  for (int32_t k = 0; k < n_; ++k) {
    if (!(cond[k] > tol)) continue;
    double S = 0.0, dS[3] = {0, 0, 0};
    for (int64_t e = rp[k]; e < rp[k + 1]; ++e) {
      const int32_t j = cols[e];
      double r2 = 0.0, dx[3] = {0, 0, 0};
      for (int c = 0; c < dim_; ++c) {
        dx[c] = ps_.x(k, c) - ps_.x(j, c);
        r2 += dx[c] * dx[c];
      }
      const double r = std::sqrt(r2);
      double w, dw, d2w;
      kern.eval(r, h_, w, dw, d2w);
      N_[e] = w * vol_[j];
      S += N_[e];
      for (int c = 0; c < dim_; ++c) {
        G_[e * dim_ + c] = r > 0.0 ? dw * dx[c] / r * vol_[j] : 0.0;
        dS[c] += G_[e * dim_ + c];
      }
    }
    for (int64_t e = rp[k]; e < rp[k + 1]; ++e) {
      N_[e] /= S;
      for (int c = 0; c < dim_; ++c) G_[e * dim_ + c] = (G_[e * dim_ + c] - N_[e] * dS[c]) / S;
    }
  }
}

void FluidSystem::kinematics(const double *v, const double *rho, double *vhat, double *drho) const {
  const auto &rp = approx_->rowptr();
  const auto &cols = approx_->cols();
  const auto &N = N_;
  const auto &G = G_;
  for (int32_t k = 0; k < n_; ++k) {
    double vh[3] = {0, 0, 0}, div = 0.0;
    for (int64_t e = rp[k]; e < rp[k + 1]; ++e) {
      const int32_t j = cols[e];
      for (int c = 0; c < dim_; ++c) {
        vh[c] += N[e] * v[j * dim_ + c];
        div += v[j * dim_ + c] * G[e * dim_ + c];
      }
    }
    if (vhat)
      for (int c = 0; c < dim_; ++c) vhat[k * dim_ + c] = vh[c];
    if (drho) drho[k] = -rho[k] * div;  // 003 eq 70, nodal parameters v_j
  }
}

Report FluidSystem::accel(const double *v, const double *rho, double *a) {
  Report rep;
  const int dim = dim_;
  const auto &rp = approx_->rowptr();
  const auto &cols = approx_->cols();
  const auto &N = N_;
  const auto &G = G_;
  force_.assign(static_cast<size_t>(n_) * dim, 0.0);
  lumped_.assign(n_, 0.0);
  fb_.assign(static_cast<size_t>(n_) * dim, 0.0);
  vhat_.resize(static_cast<size_t>(n_) * dim);
  kinematics(v, rho, vhat_.data(), nullptr);
  for (int32_t k = 0; k < n_; ++k) {
    // velocity gradient L_ab = sum_j v_j,a dN_j/dx_b at the quadrature point x_k
    double L[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    for (int64_t e = rp[k]; e < rp[k + 1]; ++e) {
      const int32_t j = cols[e];
      for (int aa = 0; aa < dim; ++aa)
        for (int b = 0; b < dim; ++b) L[aa][b] += v[j * dim + aa] * G[e * dim + b];
    }
    double tr = 0.0;
    for (int c = 0; c < dim; ++c) tr += L[c][c];
    const double p = kappa_ * (std::pow(rho[k] / rho0_[k], gamma_) - 1.0);
    double sig[3][3];
    for (int aa = 0; aa < dim; ++aa)
      for (int b = 0; b < dim; ++b) {
        const double d = 0.5 * (L[aa][b] + L[b][aa]) - (aa == b ? tr / 3.0 : 0.0);  // d' (003 eq 61)
        sig[aa][b] = (aa == b ? -p : 0.0) + 2.0 * mu_ * d;
      }
    const double Vk = vol_[k], Mk = mass_[k];
    for (int64_t e = rp[k]; e < rp[k + 1]; ++e) {
      const int32_t i = cols[e];
      for (int aa = 0; aa < dim; ++aa) {
        double s = 0.0;
        for (int b = 0; b < dim; ++b) s += sig[aa][b] * G[e * dim + b];
        force_[i * dim + aa] += -s * Vk + N[e] * Mk * g_[aa];  // 003 eqs 67-68
      }
      lumped_[i] += N[e] * Mk;  // 003 eq 56
    }
  }
  // wall forces (003 eqs 122-124), spread to the neighbours through N_i(x_j)
  if (walls_) {
    for (int32_t j = 0; j < n_; ++j) {
      double F[3] = {0, 0, 0};
      bool any = false;
      for (int64_t e = wall_nbr_.rowptr[j]; e < wall_nbr_.rowptr[j + 1]; ++e) {
        const int32_t k = wall_nbr_.cols[e];
        const double *nk = &wall_n_[static_cast<size_t>(k) * dim];
        double r2 = 0.0, approach = 0.0;
        for (int c = 0; c < dim; ++c) {
          const double d = ps_.x(j, c) - walls_->x(k, c);
          r2 += d * d;
          approach += vhat_[j * dim + c] * nk[c];
        }
        const double r = std::sqrt(r2);
        if (approach >= 0.0 || !(r > 0.0) || r >= r0_) continue;  // f1 = 0: moving away
        const double q = r0_ / r, f2 = strength_ / r * (q * q * q * q - q * q);
        for (int c = 0; c < dim; ++c) F[c] += f2 * nk[c];
        any = true;
      }
      if (!any) continue;
      for (int64_t e = rp[j]; e < rp[j + 1]; ++e)
        for (int c = 0; c < dim; ++c) fb_[cols[e] * dim + c] += N[e] * F[c];
    }
  }
  for (int32_t i = 0; i < n_; ++i) {
    const double m = lump_ == MFREE_LUMP_GALERKIN ? lumped_[i] : mass_[i];
    if (!(m > 0.0)) {
      rep.fail(MFREE_FAIL_SINGULAR, "particle " + std::to_string(i) + " has a non-positive lumped mass " +
                                        std::to_string(m));
      for (int c = 0; c < dim; ++c) a[i * dim + c] = 0.0;
      continue;
    }
    // the boundary force acts as an acceleration (003 Sect. 6.1 step 7)
    for (int c = 0; c < dim; ++c) a[i * dim + c] = force_[i * dim + c] / m + fb_[i * dim + c];
  }
  return rep;
}

Report FluidSystem::rhs(double t, const double *y, double *ydot) {
  (void)t;
  Report rep = prepare(y);
  if (!rep.ok()) return rep;
  const size_t nd = static_cast<size_t>(dim_) * n_;
  const double *v = y + nd, *rho = y + 2 * nd;
  rep = accel(v, rho, ydot + nd);
  kinematics(v, rho, ydot, ydot + 2 * nd);
  return rep;
}

Report FluidSystem::velocity(const double *y, double *vhat) {
  Report rep = prepare(y);
  if (!rep.ok()) return rep;
  const size_t nd = static_cast<size_t>(dim_) * n_;
  kinematics(y + nd, y + 2 * nd, vhat, nullptr);
  return rep;
}

void FluidSystem::pressure(const double *y, double *p) const {
  const double *rho = y + 2 * static_cast<size_t>(dim_) * n_;
  for (int32_t i = 0; i < n_; ++i) p[i] = kappa_ * (std::pow(rho[i] / rho0_[i], gamma_) - 1.0);
}

Report FluidSystem::interpolation(const double *y, SparseMatrix &S) {
  Report rep = prepare(y);
  if (!rep.ok()) return rep;
  // rows are not guaranteed sorted by column: sort each row with its values
  std::vector<int64_t> rp = approx_->rowptr();
  std::vector<int32_t> cols = approx_->cols();
  std::vector<double> vals = N_;
  for (int32_t k = 0; k < n_; ++k) {
    std::vector<std::pair<int32_t, double>> row;
    for (int64_t e = rp[k]; e < rp[k + 1]; ++e) row.push_back({cols[e], vals[e]});
    std::sort(row.begin(), row.end());
    for (size_t q = 0; q < row.size(); ++q) {
      cols[rp[k] + q] = row[q].first;
      vals[rp[k] + q] = row[q].second;
    }
  }
  S.set_pattern(n_, n_, rp, cols);
  std::copy(vals.begin(), vals.end(), S.values_mut().begin());
  return rep;
}

Report FluidSystem::mass(const double *y, bool consistent, SparseMatrix &M) {
  Report rep = prepare(y);
  if (!rep.ok()) return rep;
  const int dim = dim_;
  const size_t nd = static_cast<size_t>(dim) * n_;
  const auto &rp = approx_->rowptr();
  const auto &cols = approx_->cols();
  const auto &N = N_;
  // node-level velocity block: consistent m_ij = sum_k N_i(x_k) N_j(x_k) M_k (003 eq 42),
  // or the lumped row sums
  std::vector<std::vector<std::pair<int32_t, double>>> rows(n_);
  for (int32_t k = 0; k < n_; ++k)
    for (int64_t a = rp[k]; a < rp[k + 1]; ++a)
      for (int64_t b = rp[k]; b < rp[k + 1]; ++b) {
        const double m = N[a] * N[b] * mass_[k];
        if (consistent) rows[cols[a]].push_back({cols[b], m});
        else rows[cols[a]].push_back({cols[a], m});
      }
  std::vector<int64_t> rowptr(static_cast<size_t>(neq()) + 1, 0);
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
  for (int32_t i = 0; i < n_; ++i) {
    auto &row = rows[i];
    std::sort(row.begin(), row.end());
    std::vector<std::pair<int32_t, double>> merged;
    for (auto &e : row) {
      if (!merged.empty() && merged.back().first == e.first) merged.back().second += e.second;
      else merged.push_back(e);
    }
    if (lump_ == MFREE_LUMP_PHYSICAL && !consistent) merged.assign(1, {i, mass_[i]});
    for (int c = 0; c < dim; ++c) {
      for (auto &e : merged) {
        ci.push_back(static_cast<int32_t>(nd) + e.first * dim + c);
        vals.push_back(e.second);
      }
      rowptr[r + 1] = static_cast<int64_t>(ci.size());
      ++r;
    }
  }
  for (int32_t i = 0; i < n_; ++i) identity_row();
  M.set_pattern(neq(), neq(), std::move(rowptr), std::move(ci));
  std::copy(vals.begin(), vals.end(), M.values_mut().begin());
  return rep;
}

double FluidSystem::stable_dt(const double *y) const {
  const size_t nd = static_cast<size_t>(dim_) * n_;
  const double *v = y + nd, *rho = y + 2 * nd;
  double cmax = 0.0;
  for (int32_t i = 0; i < n_; ++i) {
    double vv = 0.0;
    for (int c = 0; c < dim_; ++c) vv += v[i * dim_ + c] * v[i * dim_ + c];
    cmax = std::max(cmax, std::sqrt(gamma_ * kappa_ / rho[i]) + std::sqrt(vv));  // 003 eqs 120-121
  }
  return cmax > 0.0 ? h_ / cmax : INFINITY;
}

Report FluidSystem::integrate(int scheme, double *y, double &t, double t_end, double cfl, double dt_max,
                              mfree_progress_fn progress, void *user, int64_t &nsteps) {
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
  std::vector<double> rate(ny), vh(nd), dr(n_);
  while (t < t_end) {
    rep = prepare(y);
    if (!rep.ok()) {
      rep.message = "step " + std::to_string(nsteps) + ": " + rep.message;
      return rep;
    }
    const double limit = stable_dt(y);
    double dt = cfl > 0.0 ? cfl * limit : dt_max;
    if (cfl > 0.0 && dt_max > 0.0) dt = std::min(dt, dt_max);
    if (cfl <= 0.0 && dt > limit) {
      std::ostringstream s;
      s << "step " << nsteps << ": dt = " << dt << " exceeds the CFL limit " << limit << " (003 eq 120)";
      rep.fail(MFREE_FAIL_CFL, s.str());
      return rep;
    }
    dt = std::min(dt, t_end - t);
    double *yn = work_state_.data();
    const double *x = y, *v = y + nd, *rho = y + 2 * nd;
    if (scheme == MFREE_INTEGRATOR_LEAPFROG) {
      // 003 Sect. 6.1: a from (x^k, rho^k, v^{k-1/2}); v^{k+1/2} = v + dt a; density rates
      // and interpolated velocities with v^{k+1/2} on the tables at x^k
      Report r = accel(v, rho, rate.data());
      if (!r.ok()) return r;
      for (size_t q = 0; q < nd; ++q) yn[nd + q] = v[q] + dt * rate[q];
      kinematics(yn + nd, rho, vh.data(), dr.data());
      for (size_t q = 0; q < nd; ++q) yn[q] = x[q] + dt * vh[q];
      for (int32_t i = 0; i < n_; ++i) yn[2 * nd + i] = rho[i] + dt * dr[i];
    } else {
      // 003 eqs 111-119
      Report r = rhs(t, y, rate.data());
      if (!r.ok()) return r;
      double *yp = stage_.data();
      for (size_t q = 0; q < ny; ++q) yp[q] = y[q] + 0.5 * dt * rate[q];
      r = prepare(yp);
      if (!r.ok()) {
        r.message = "step " + std::to_string(nsteps) + " (predictor): " + r.message;
        return r;
      }
      r = accel(yp + nd, yp + 2 * nd, rate.data());
      if (!r.ok()) return r;
      for (size_t q = 0; q < nd; ++q) yn[nd + q] = v[q] + 0.5 * dt * rate[q];  // v^C
      kinematics(yn + nd, yp + 2 * nd, vh.data(), dr.data());
      for (int32_t i = 0; i < n_; ++i) yn[2 * nd + i] = rho[i] + 0.5 * dt * dr[i];  // rho^C
      for (size_t q = 0; q < nd; ++q) yn[q] = x[q] + 0.5 * dt * vh[q];              // x^C
      for (size_t q = 0; q < ny; ++q) yn[q] = 2.0 * yn[q] - y[q];                   // eqs 117-119
    }
    Report bad = check_state(yn, ("step " + std::to_string(nsteps + 1) + ": ").c_str());
    if (!bad.ok()) return bad;  // y keeps the last good state
    std::copy(yn, yn + ny, y);
    t = (t_end - t <= dt) ? t_end : t + dt;
    ++nsteps;
    if (progress && progress(user, nsteps, t, dt)) break;
  }
  return rep;
}

}  // namespace mfree
