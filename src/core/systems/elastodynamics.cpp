#include "core/systems/elastodynamics.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/base/basis.hpp"

namespace mfree {

ElasticSystem::ElasticSystem(const Assembler *as, double density) : as_(as), rho_(density) {
  if (!as->is_setup()) throw Error(MFREE_ERR_STATE, "the assembler is not set up");
  const int form = as->form();
  if (form != MFREE_FORM_COLLOCATION_LAPLACE && form != MFREE_FORM_COLLOCATION_PLANE_STRESS &&
      form != MFREE_FORM_COLLOCATION_PLANE_STRAIN)
    throw Error(MFREE_ERR_UNSUPPORTED, "elastodynamics needs a collocation assembler (Laplace form for the 1D bar "
                                       "rho u'' = E u'', or a plane collocation form); Galerkin assemblers go to "
                                       "mfree_system_create_elastodynamic_galerkin");
  if (!(std::isfinite(density) && density > 0.0)) throw Error(MFREE_ERR_ARG, "density must be finite and > 0");
  init_common();
  dx_min_ = local_spacing(as->particles().size());
  limit_ = dx_min_ / c_;
}

// The smallest distance between a particle of the first nrows and a neighbour of its
// collocation row: the CFL limit's spacing.
double ElasticSystem::local_spacing(int32_t nrows) const {
  const ParticleSet &ps = as_->particles();
  double dx = INFINITY;
  const Approximant *tab = as_->collocation_tables();
  for (int32_t i = 0; i < nrows; ++i)
    for (int64_t k = tab->rowptr()[i]; k < tab->rowptr()[i + 1]; ++k) {
      const int32_t j = tab->cols()[k];
      if (j == i) continue;
      double d[3] = {0, 0, 0}, r2 = 0.0;
      ps.displacement(i, j, d);
      for (int c = 0; c < dim_; ++c) r2 += d[c] * d[c];
      if (r2 > 0.0) dx = std::min(dx, std::sqrt(r2));
    }
  return dx;
}

ElasticSystem::ElasticSystem(const Assembler *stiffness, const Assembler *mass) : as_(stiffness), rho_(0.0) {
  if (!stiffness->is_setup() || !mass->is_setup()) throw Error(MFREE_ERR_STATE, "an assembler is not set up");
  const int form = stiffness->form();
  if (form != MFREE_FORM_LAPLACE && form != MFREE_FORM_ELASTICITY_PLANE_STRESS &&
      form != MFREE_FORM_ELASTICITY_PLANE_STRAIN && form != MFREE_FORM_ELASTICITY_3D)
    throw Error(MFREE_ERR_UNSUPPORTED, "the stiffness assembler needs a Galerkin Laplace or elasticity form");
  if (mass->form() != MFREE_FORM_MASS && mass->form() != MFREE_FORM_MASS_LUMPED)
    throw Error(MFREE_ERR_UNSUPPORTED, "the mass assembler needs MFREE_FORM_MASS or MFREE_FORM_MASS_LUMPED");
  if (&mass->particles() != &stiffness->particles())
    throw Error(MFREE_ERR_MISMATCH, "the mass and stiffness assemblers are built on different particle sets");
  if (stiffness->ndofs() != stiffness->particles().size() * stiffness->ncomp())
    throw Error(MFREE_ERR_UNSUPPORTED, "Lagrange multipliers are not supported in elastodynamics: impose essential "
                                       "conditions by penalty, Nitsche or node rows");
  if (mass->ndofs() != mass->particles().size())
    throw Error(MFREE_ERR_UNSUPPORTED, "the mass assembler has extra unknowns (multipliers)");
  galerkin_ = true;
  rho_ = mass->coefficient();
  init_common();
  init_galerkin_mass(mass);
}

void ElasticSystem::init_common() {
  if (as_->particles().num_ghost() != 0)
    throw Error(MFREE_ERR_UNSUPPORTED, "elastodynamics runs on particle sets without ghosts (on ranks: "
                                       "mfree_system_create_elastodynamic_ranks)");
  init_operator();
  init_boundary();
}

// The operator's rows, its load and the wave speed; nd_ counts the owned unknowns, nl_
// the local ones (owned and ghost particles).
void ElasticSystem::init_operator() {
  const Assembler *as = as_;
  const ParticleSet &ps = as->particles();
  dim_ = ps.dim();
  nc_ = as->ncomp();
  nd_ = ps.num_owned() * nc_;
  nl_ = ps.size() * nc_;
  as->assemble_matrix(K_);
  f0_.assign(static_cast<size_t>(nl_), 0.0);
  as->assemble_rhs(f0_.data());
  // wave speed: bar (Laplace, c = coefficient = E) or P wave
  const int form = as->form();
  if (form == MFREE_FORM_COLLOCATION_LAPLACE || form == MFREE_FORM_LAPLACE) {
    c_ = std::sqrt(as->coefficient() / rho_);
  } else {
    const double E = as->young(), nu = as->poisson();
    const double lam = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
    const bool pstress = form == MFREE_FORM_COLLOCATION_PLANE_STRESS || form == MFREE_FORM_ELASTICITY_PLANE_STRESS;
    const double lam_eff = pstress ? 2 * lam * mu / (lam + 2 * mu) : lam;
    c_ = std::sqrt((lam_eff + 2 * mu) / rho_);
  }
  work_.resize(nl_);
}

// The boundary unknowns of one process and the factorised block that determines them.
void ElasticSystem::init_boundary() {
  const auto &kinds = as_->row_kinds();
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
    factor_boundary(nb, trip);
  }
  rb_.resize(nb);
}

void ElasticSystem::factor_boundary(int32_t nb, const std::vector<Eigen::Triplet<double>> &trip) {
  Eigen::SparseMatrix<double> Kbb(nb, nb);
  Kbb.setFromTriplets(trip.begin(), trip.end());
  lu_ = std::make_unique<Eigen::SparseLU<Eigen::SparseMatrix<double>>>();
  lu_->compute(Kbb);
  if (lu_->info() != Eigen::Success)
    throw Error(MFREE_ERR_INPUT, "the boundary rows do not determine the boundary unknowns (singular block)");
}

void ElasticSystem::init_galerkin_mass(const Assembler *mass) {
  SparseMatrix Ms;
  mass->assemble_matrix(Ms);
  // the free unknowns: the owned ones whose rows the essential conditions did not replace
  const auto &kinds = as_->row_kinds();
  fpos_.assign(nd_, -1);
  for (int32_t d = 0; d < nd_; ++d)
    if (kinds[d] == 0) {
      fpos_[d] = static_cast<int32_t>(fdofs_.size());
      fdofs_.push_back(d);
    }
  const int32_t nf = static_cast<int32_t>(fdofs_.size());
  // M_ff: the scalar mass m_JK on every component, couplings to constrained unknowns
  // dropped (exact when the constrained values do not accelerate, or the mass is lumped);
  // the owned rows (on ranks the mass is lumped: no column leaves them)
  std::vector<Eigen::Triplet<double>> trip;
  lumped_ = mass->form() == MFREE_FORM_MASS_LUMPED;
  const int32_t n = as_->particles().num_owned();
  for (int32_t J = 0; J < n; ++J)
    for (int64_t k = Ms.rowptr()[J]; k < Ms.rowptr()[J + 1]; ++k) {
      const int32_t K = Ms.colidx()[k];
      const double m = Ms.values()[k];
      if (m == 0.0) continue;
      if (K != J) lumped_ = false;
      if (K >= n) continue;
      for (int a = 0; a < nc_; ++a) {
        const int32_t p = fpos_[J * nc_ + a], q = fpos_[K * nc_ + a];
        if (p >= 0 && q >= 0) trip.emplace_back(p, q, m);
      }
    }
  Mff_.resize(nf, nf);
  Mff_.setFromTriplets(trip.begin(), trip.end());
  // (a rank may own no free unknown: Eigen's norm wants a non-empty matrix)
  const Eigen::SparseMatrix<double> asym = Mff_ - Eigen::SparseMatrix<double>(Mff_.transpose());
  if (nf > 0 && asym.norm() > 1e-12 * Mff_.norm())
    throw Error(MFREE_ERR_UNSUPPORTED, "the mass matrix is not symmetric (Petrov-Galerkin): use a Bubnov mass");
  if (lumped_) {
    minv_.assign(nf, 0.0);
    for (int32_t p = 0; p < nf; ++p) {
      const double m = Mff_.coeff(p, p);
      if (!(m > 0.0)) throw Error(MFREE_ERR_INPUT, "the lumped mass of unknown " + std::to_string(fdofs_[p]) +
                                                       " is " + std::to_string(m) + ", not positive");
      minv_[p] = 1.0 / m;
    }
  } else {
    mfac_ = std::make_unique<Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>>();
    mfac_->compute(Mff_);
    bool spd = mfac_->info() == Eigen::Success;
    if (spd)
      for (int32_t p = 0; p < nf; ++p) spd = spd && mfac_->vectorD()(p) > 0.0;
    if (!spd) throw Error(MFREE_ERR_INPUT, "the consistent mass is not positive definite");
  }
  // Step limit of central differences, 2 / omega_max, omega^2 the eigenvalues of
  // M^-1 K on the free unknowns. Lumped: Gershgorin's bound max_p sum_q |K_pq| / m_p
  // (rigorous). Consistent: power iteration, 200 steps from a fixed start, plus 5 %.
  double w2 = 0.0;
  if (lumped_) {
    for (int32_t p = 0; p < nf; ++p) {
      const int32_t d = fdofs_[p];
      double s = 0.0;
      for (int64_t k = K_.rowptr()[d]; k < K_.rowptr()[d + 1]; ++k) s += std::fabs(K_.values()[k]);
      w2 = std::max(w2, s * minv_[p]);
    }
  } else {
    Eigen::VectorXd x(nf), Kx(nf);
    for (int32_t p = 0; p < nf; ++p) x(p) = 1.0 + 0.37 * std::sin(1.0 + 7.3 * p);  // not an eigenvector
    std::vector<double> u(nd_), a(nd_);
    for (int it = 0; it < 200 && nf > 0; ++it) {
      x /= x.norm();
      std::fill(u.begin(), u.end(), 0.0);
      for (int32_t p = 0; p < nf; ++p) u[fdofs_[p]] = x(p);
      for (int32_t p = 0; p < nf; ++p) {
        const int32_t d = fdofs_[p];
        double s = 0.0;
        for (int64_t k = K_.rowptr()[d]; k < K_.rowptr()[d + 1]; ++k) s += K_.values()[k] * u[K_.colidx()[k]];
        Kx(p) = s;
      }
      const Eigen::VectorXd y = mfac_->solve(Kx);
      w2 = std::max(w2, x.dot(Mff_ * y) / x.dot(Mff_ * x));  // Rayleigh quotient in the M inner product
      x = y;
    }
    w2 *= 1.05 * 1.05;
  }
  limit_ = w2 > 0.0 ? 2.0 / std::sqrt(w2) : INFINITY;
  dx_min_ = limit_ * c_;
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

void ElasticSystem::accel(double t, const double *u, double *a) const {
  if (galerkin_) {
    // M_ff a_f = g(t) f_f - K_f u: the history scales the whole load vector
    const int32_t nf = static_cast<int32_t>(fdofs_.size());
    const double g = history(t);
    Eigen::VectorXd r(nf);
    for (int32_t p = 0; p < nf; ++p) {
      const int32_t d = fdofs_[p];
      double s = g * f0_[d];
      for (int64_t k = K_.rowptr()[d]; k < K_.rowptr()[d + 1]; ++k) s -= K_.values()[k] * u[K_.colidx()[k]];
      r(p) = s;
    }
    if (lumped_) {
      for (int32_t p = 0; p < nf; ++p) r(p) *= minv_[p];
    } else if (nf > 0) {
      r = mfac_->solve(r).eval();
    }
    for (int32_t d = 0; d < nd_; ++d) a[d] = fpos_[d] >= 0 ? r(fpos_[d]) : 0.0;
    return;
  }
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
      const int32_t i = (q % nd_) / nc_;
      s << when << "particle " << i;
      if (ranks_) s << " (global id " << as_->particles().global_ids()[i] << ")";
      s << " has a non-finite " << (q < nd_ ? "displacement" : "velocity");
      rep.fail(MFREE_FAIL_NONFINITE, s.str());
      break;
    }
  return rep;
}

Report ElasticSystem::rhs(double t, const double *y, double *ydot) {
  Report rep = ranks_ ? coll_.local([&] { return check(y, ""); }) : check(y, "");
  if (ranks_) {
    rep = fill_state(t, y, rep);  // every rank takes part, a failing one too
    if (!rep.ok()) return settle(rep);
  } else {
    if (!rep.ok()) return rep;
    std::copy(y, y + nd_, work_.begin());
    enforce_boundary(t, work_.data());
  }
  // boundary unknowns follow the constraints: their entries of y are not used
  for (int32_t d = 0; d < nd_; ++d) ydot[d] = bpos_[d] >= 0 ? 0.0 : y[nd_ + d];
  accel(t, work_.data(), ydot + nd_);
  return rep;
}

Report ElasticSystem::mass(const double *y, bool consistent, SparseMatrix &M) {
  (void)y;
  if (ranks_ && galerkin_ && consistent)
    throw Error(MFREE_ERR_UNSUPPORTED, "no consistent mass matrix for elastodynamics on ranks (its rows couple owned "
                                       "particles to ghosts): use its products (mfree_system_apply_mass) or the "
                                       "lumped mass");
  // y' = f is explicit for collocation: the identity. Galerkin: the velocity block holds
  // the mass the right-hand side divides by (lumped or consistent, as assembled) on the
  // free unknowns, the identity on the constrained ones. Constant: built once.
  if (mrp_.empty()) {
    mrp_.assign(static_cast<size_t>(neq()) + 1, 0);
    for (int32_t q = 0; q < neq(); ++q) {
      const int32_t d = q - nd_;
      if (galerkin_ && d >= 0 && fpos_[d] >= 0) {
        std::vector<std::pair<int32_t, double>> row;
        // Mff_ is column-major and symmetric: column p is row p
        for (Eigen::SparseMatrix<double>::InnerIterator it(Mff_, fpos_[d]); it; ++it)
          row.push_back({nd_ + fdofs_[it.row()], it.value()});
        std::sort(row.begin(), row.end());
        for (auto &e : row) {
          mci_.push_back(e.first);
          mval_.push_back(e.second);
        }
      } else {
        mci_.push_back(q);
        mval_.push_back(1.0);
      }
      mrp_[q + 1] = static_cast<int64_t>(mci_.size());
    }
  }
  M.set_pattern(neq(), neq(), mrp_, mci_);
  std::copy(mval_.begin(), mval_.end(), M.values_mut().begin());
  return Report();
}

void ElasticSystem::stress(double t, const double *y, double *sigma) const {
  if (ranks_) {
    settle(fill_state(t, y, coll_.local([] { return Report(); })));
  } else {
    std::copy(y, y + nd_, work_.begin());
    enforce_boundary(t, work_.data());
  }
  const Approximant *tab = as_->collocation_tables();
  const auto &G = tab->gradients();
  const int32_t n = num_particles();
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
  nsteps = 0;
  // The argument checks and the first state's: on ranks one outcome for all (and the
  // same arguments everywhere), so that no rank steps on alone.
  Report rep;
  double dt = 0.0;
  try {
    if (ranks_ && coll_.take_pending(rep)) throw Error(rep.status, rep.message);
    if (scheme != MFREE_INTEGRATOR_LEAPFROG)
      throw Error(MFREE_ERR_UNSUPPORTED, "elastodynamics integrates with the central-difference (leap-frog) scheme");
    if (!(std::isfinite(t_end) && std::isfinite(t))) throw Error(MFREE_ERR_ARG, "times must be finite");
    if (!(std::isfinite(cfl) && cfl <= 1.0)) throw Error(MFREE_ERR_ARG, "cfl must be finite and <= 1");
    if (!(std::isfinite(dt_max) && dt_max >= 0.0)) throw Error(MFREE_ERR_ARG, "dt_max must be finite and >= 0");
    if (cfl <= 0.0 && dt_max <= 0.0) throw Error(MFREE_ERR_ARG, "give a CFL number or a fixed step dt_max");
    rep = check(y, "initial state: ");
    dt = cfl > 0.0 ? cfl * limit_ : dt_max;
    if (cfl > 0.0 && dt_max > 0.0) dt = std::min(dt, dt_max);
    if (rep.ok() && dt > limit_ * (1.0 + 1e-12)) {
      std::ostringstream s;
      s << "dt = " << dt << " exceeds the CFL limit " << (galerkin_ ? "2/omega_max = " : "dx/c = ") << limit_;
      rep.fail(MFREE_FAIL_CFL, s.str());
    }
  } catch (const Error &e) {
    if (!ranks_) throw;
    rep.status = e.status();
    rep.message = e.what();
  }
  if (ranks_) {
    const double mine[5] = {static_cast<double>(rep.status), t, t_end, cfl, dt_max};
    const std::vector<double> all = coll_.allgather(mine, 5);
    std::vector<double> st(all.size() / 5);
    for (size_t p = 0; p < st.size(); ++p) st[p] = all[5 * p];
    rep = settle(coll_.agree_from(st, rep));
    static const char *names[5] = {"", "t", "t_end", "cfl", "dt_max"};
    for (size_t p = 1; rep.ok() && p < st.size(); ++p)
      for (int k = 1; k < 5; ++k)
        if (all[5 * p + k] != all[k]) {
          std::ostringstream s;
          s << "ranks disagree on " << names[k] << ": rank 0 passes " << all[k] << ", rank " << p << " passes "
            << all[5 * p + k] << " (every rank must pass the same)";
          throw Error(MFREE_ERR_ARG, s.str());
        }
  }
  if (!rep.ok()) return rep;
  std::vector<double> yn(y, y + 2 * static_cast<size_t>(nd_)), a(nd_), u(nd_);
  double *un = yn.data(), *vn = yn.data() + nd_;
  // a = the acceleration at displacements un (boundary unknowns enforced in un)
  auto eval = [&](double tt) {
    if (!ranks_) {
      enforce_boundary(tt, un);
      accel(tt, un, a.data());
      return Report();
    }
    Report r = settle(fill_state(tt, un, Report()));
    for (int32_t d = 0; d < nd_; ++d)
      if (bpos_[d] >= 0) un[d] = work_[d];
    accel(tt, work_.data(), a.data());
    return r;
  };
  eval(t);
  while (t < t_end) {
    const double h = std::min(dt, t_end - t);
    // velocity Verlet = central difference for the displacements
    for (int32_t d = 0; d < nd_; ++d) {
      vn[d] += 0.5 * h * a[d];
      un[d] += h * vn[d];
    }
    const double tn = (t_end - t <= h) ? t_end : t + h;
    eval(tn);
    for (int32_t d = 0; d < nd_; ++d) vn[d] += 0.5 * h * a[d];
    Report bad = check(yn.data(), "step " + std::to_string(nsteps + 1) + ": ");
    if (ranks_) bad = settle(coll_.agree(bad));
    if (!bad.ok()) return bad;
    std::copy(yn.begin(), yn.end(), y);
    t = tn;
    ++nsteps;
    if (progress && progress(user, nsteps, t, h)) break;
  }
  return rep;
}

}  // namespace mfree
