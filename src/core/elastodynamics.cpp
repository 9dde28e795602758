#include "elastodynamics.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "basis.hpp"

namespace mfree {

ElasticSystem::ElasticSystem(const Assembler *as, double density) : as_(as), rho_(density) {
  if (!as->is_setup()) throw Error(MFREE_ERR_STATE, "the assembler is not set up");
  const int form = as->form();
  if (form != MFREE_FORM_COLLOCATION_LAPLACE && form != MFREE_FORM_COLLOCATION_PLANE_STRESS &&
      form != MFREE_FORM_COLLOCATION_PLANE_STRAIN)
    throw Error(MFREE_ERR_UNSUPPORTED, "elastodynamics needs a collocation assembler (Laplace form for the 1D bar "
                                       "rho u'' = E u'', or a plane collocation form)");
  if (!(std::isfinite(density) && density > 0.0)) throw Error(MFREE_ERR_ARG, "density must be finite and > 0");
  const ParticleSet &ps = as->particles();
  dim_ = ps.dim();
  nc_ = as->ncomp();
  nd_ = ps.size() * nc_;
  if (ps.num_ghost() != 0) throw Error(MFREE_ERR_UNSUPPORTED, "elastodynamics runs on particle sets without ghosts");
  as->assemble_matrix(K_);
  f0_.assign(static_cast<size_t>(nd_), 0.0);
  as->assemble_rhs(f0_.data());
  const auto &kinds = as->row_kinds();
  bpos_.assign(nd_, -1);
  for (int32_t d = 0; d < nd_; ++d)
    if (kinds[d] != 0) {
      bpos_[d] = static_cast<int32_t>(bdofs_.size());
      bdofs_.push_back(d);
    }
  // K_bb u_B = g(t) f0_B - K_bi u_I, factorised once (the particles do not move)
  const int32_t nb = static_cast<int32_t>(bdofs_.size());
  if (nb > 0) {
    std::vector<Eigen::Triplet<double>> trip;
    for (int32_t q = 0; q < nb; ++q) {
      const int32_t d = bdofs_[q];
      for (int64_t k = K_.rowptr()[d]; k < K_.rowptr()[d + 1]; ++k) {
        const int32_t c = K_.colidx()[k];
        if (bpos_[c] >= 0 && K_.values()[k] != 0.0) trip.emplace_back(q, bpos_[c], K_.values()[k]);
      }
    }
    Eigen::SparseMatrix<double> Kbb(nb, nb);
    Kbb.setFromTriplets(trip.begin(), trip.end());
    lu_ = std::make_unique<Eigen::SparseLU<Eigen::SparseMatrix<double>>>();
    lu_->compute(Kbb);
    if (lu_->info() != Eigen::Success)
      throw Error(MFREE_ERR_INPUT, "the boundary rows do not determine the boundary unknowns (singular block)");
  }
  // wave speed and the smallest particle spacing for the CFL limit
  const double E = as->young(), nu = as->poisson();
  if (form == MFREE_FORM_COLLOCATION_LAPLACE) {
    c_ = std::sqrt(as->coefficient() / rho_);
  } else {
    const double lam = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
    const double lam_eff = form == MFREE_FORM_COLLOCATION_PLANE_STRESS ? 2 * lam * mu / (lam + 2 * mu) : lam;
    c_ = std::sqrt((lam_eff + 2 * mu) / rho_);
  }
  dx_min_ = INFINITY;
  const Approximant *tab = as->collocation_tables();
  for (int32_t i = 0; i < ps.size(); ++i)
    for (int64_t k = tab->rowptr()[i]; k < tab->rowptr()[i + 1]; ++k) {
      const int32_t j = tab->cols()[k];
      if (j == i) continue;
      double d[3] = {0, 0, 0}, r2 = 0.0;
      ps.displacement(i, j, d);
      for (int c = 0; c < dim_; ++c) r2 += d[c] * d[c];
      if (r2 > 0.0) dx_min_ = std::min(dx_min_, std::sqrt(r2));
    }
  rb_.resize(nb);
  work_.resize(nd_);
}

void ElasticSystem::set_load_history(double (*fn)(void *, double), void *user) {
  hist_ = fn;
  hist_user_ = user;
}

void ElasticSystem::enforce_boundary(double t, double *u) const {
  const int32_t nb = static_cast<int32_t>(bdofs_.size());
  if (nb == 0) return;
  const double g = history(t);
  Eigen::VectorXd r(nb);
  for (int32_t q = 0; q < nb; ++q) {
    const int32_t d = bdofs_[q];
    double s = g * f0_[d];
    for (int64_t k = K_.rowptr()[d]; k < K_.rowptr()[d + 1]; ++k) {
      const int32_t c = K_.colidx()[k];
      if (bpos_[c] < 0) s -= K_.values()[k] * u[c];
    }
    r(q) = s;
  }
  const Eigen::VectorXd ub = lu_->solve(r);
  for (int32_t q = 0; q < nb; ++q) u[bdofs_[q]] = ub(q);
}

void ElasticSystem::accel(const double *u, double *a) const {
  for (int32_t d = 0; d < nd_; ++d) {
    if (bpos_[d] >= 0) {
      a[d] = 0.0;
      continue;
    }
    double s = f0_[d];  // body force (constant)
    for (int64_t k = K_.rowptr()[d]; k < K_.rowptr()[d + 1]; ++k) s -= K_.values()[k] * u[K_.colidx()[k]];
    a[d] = s / rho_;
  }
}

Report ElasticSystem::check(const double *y, const std::string &when) const {
  Report rep;
  for (int32_t q = 0; q < 2 * nd_; ++q)
    if (!std::isfinite(y[q])) {
      std::ostringstream s;
      s << when << "particle " << (q % nd_) / nc_ << " has a non-finite " << (q < nd_ ? "displacement" : "velocity");
      rep.fail(MFREE_FAIL_NONFINITE, s.str());
      break;
    }
  return rep;
}

Report ElasticSystem::rhs(double t, const double *y, double *ydot) {
  Report rep = check(y, "");
  if (!rep.ok()) return rep;
  std::copy(y, y + nd_, work_.begin());
  enforce_boundary(t, work_.data());
  // boundary unknowns follow the constraints: their entries of y are not used
  for (int32_t d = 0; d < nd_; ++d) ydot[d] = bpos_[d] >= 0 ? 0.0 : y[nd_ + d];
  accel(work_.data(), ydot + nd_);
  return rep;
}

Report ElasticSystem::mass(const double *y, bool consistent, SparseMatrix &M) {
  (void)y;
  (void)consistent;
  std::vector<int64_t> rp(static_cast<size_t>(neq()) + 1);
  std::vector<int32_t> ci(static_cast<size_t>(neq()));
  for (int32_t q = 0; q < neq(); ++q) {
    rp[q + 1] = q + 1;
    ci[q] = q;
  }
  M.set_pattern(neq(), neq(), std::move(rp), std::move(ci));
  std::fill(M.values_mut().begin(), M.values_mut().end(), 1.0);  // y' = f is already explicit
  return Report();
}

void ElasticSystem::stress(double t, const double *y, double *sigma) const {
  std::copy(y, y + nd_, work_.begin());
  enforce_boundary(t, work_.data());
  const Approximant *tab = as_->collocation_tables();
  const auto &G = tab->gradients();
  const int32_t n = as_->particles().size();
  const int sc = stress_components();
  const double E = as_->young(), nu = as_->poisson();
  double lam = E * nu / ((1 + nu) * (1 - 2 * nu));
  const double mu = E / (2 * (1 + nu));
  if (as_->form() == MFREE_FORM_COLLOCATION_PLANE_STRESS) lam = 2 * lam * mu / (lam + 2 * mu);
  for (int32_t i = 0; i < n; ++i) {
    double L[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};  // du_a/dx_b
    for (int64_t k = tab->rowptr()[i]; k < tab->rowptr()[i + 1]; ++k) {
      const int32_t j = tab->cols()[k];
      for (int a = 0; a < nc_; ++a)
        for (int b = 0; b < dim_; ++b) L[a][b] += work_[j * nc_ + a] * G[k * dim_ + b];
    }
    if (as_->form() == MFREE_FORM_COLLOCATION_LAPLACE) {
      sigma[i * sc] = as_->coefficient() * L[0][0];  // 1D bar: sigma = E u'
      continue;
    }
    const double div = L[0][0] + L[1][1];
    sigma[i * sc + 0] = lam * div + 2 * mu * L[0][0];
    sigma[i * sc + 1] = lam * div + 2 * mu * L[1][1];
    sigma[i * sc + 2] = mu * (L[0][1] + L[1][0]);
  }
}

Report ElasticSystem::integrate(int scheme, double *y, double &t, double t_end, double cfl, double dt_max,
                                mfree_progress_fn progress, void *user, int64_t &nsteps) {
  if (scheme != MFREE_INTEGRATOR_LEAPFROG)
    throw Error(MFREE_ERR_UNSUPPORTED, "elastodynamics integrates with the central-difference (leap-frog) scheme");
  if (!(std::isfinite(t_end) && std::isfinite(t))) throw Error(MFREE_ERR_ARG, "times must be finite");
  if (!(std::isfinite(cfl) && cfl <= 1.0)) throw Error(MFREE_ERR_ARG, "cfl must be finite and <= 1");
  if (!(std::isfinite(dt_max) && dt_max >= 0.0)) throw Error(MFREE_ERR_ARG, "dt_max must be finite and >= 0");
  if (cfl <= 0.0 && dt_max <= 0.0) throw Error(MFREE_ERR_ARG, "give a CFL number or a fixed step dt_max");
  nsteps = 0;
  Report rep = check(y, "initial state: ");
  if (!rep.ok()) return rep;
  const double limit = dx_min_ / c_;
  double dt = cfl > 0.0 ? cfl * limit : dt_max;
  if (cfl > 0.0 && dt_max > 0.0) dt = std::min(dt, dt_max);
  if (dt > limit * (1.0 + 1e-12)) {
    std::ostringstream s;
    s << "dt = " << dt << " exceeds the CFL limit dx/c = " << limit;
    rep.fail(MFREE_FAIL_CFL, s.str());
    return rep;
  }
  std::vector<double> yn(y, y + 2 * static_cast<size_t>(nd_)), a(nd_), u(nd_);
  double *un = yn.data(), *vn = yn.data() + nd_;
  enforce_boundary(t, un);
  accel(un, a.data());
  while (t < t_end) {
    const double h = std::min(dt, t_end - t);
    // velocity Verlet = central difference for the displacements
    for (int32_t d = 0; d < nd_; ++d) {
      vn[d] += 0.5 * h * a[d];
      un[d] += h * vn[d];
    }
    const double tn = (t_end - t <= h) ? t_end : t + h;
    enforce_boundary(tn, un);
    accel(un, a.data());
    for (int32_t d = 0; d < nd_; ++d) vn[d] += 0.5 * h * a[d];
    Report bad = check(yn.data(), "step " + std::to_string(nsteps + 1) + ": ");
    if (!bad.ok()) return bad;
    std::copy(yn.begin(), yn.end(), y);
    t = tn;
    ++nsteps;
    if (progress && progress(user, nsteps, t, h)) break;
  }
  return rep;
}

}  // namespace mfree
