// The assembler's construction, the tables of test and trial functions it builds at setup,
// the sparsity pattern and update.
#include "core/discretize/assembler.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/base/kernel.hpp"
#include "core/discretize/unknowns.h"
#include "core/particles/neighbors.hpp"

namespace mfree {

Assembler::Assembler(const ParticleSet *ps, const ApproxConfig &trial, const ApproxConfig &test,
                     bool bubnov, int form)
    : ps_(ps), trial_cfg_(trial), test_cfg_(bubnov ? trial : test), bubnov_(bubnov), form_(form),
      dim_(ps->dim()), fe_(ps) {
  if (form < MFREE_FORM_LAPLACE || form > MFREE_FORM_COLLOCATION_PLANE_STRAIN)
    throw Error(MFREE_ERR_ARG, "unknown form " + std::to_string(form));
  const bool plane = form == MFREE_FORM_ELASTICITY_PLANE_STRESS || form == MFREE_FORM_ELASTICITY_PLANE_STRAIN ||
                     form == MFREE_FORM_COLLOCATION_PLANE_STRESS || form == MFREE_FORM_COLLOCATION_PLANE_STRAIN;
  if (plane && dim_ != 2)
    throw Error(MFREE_ERR_MISMATCH, "plane elasticity needs a 2D particle set, got dimension " + std::to_string(dim_));
  if (form == MFREE_FORM_ELASTICITY_3D && dim_ != 3)
    throw Error(MFREE_ERR_MISMATCH, "3D elasticity needs a 3D particle set");
  if (collocation() && !bubnov)
    throw Error(MFREE_ERR_ARG, "collocation forms take no test approximant");
  ncomp_ = elasticity() ? dim_ : 1;
}

bool Assembler::elasticity() const {
  return form_ == MFREE_FORM_ELASTICITY_PLANE_STRESS || form_ == MFREE_FORM_ELASTICITY_PLANE_STRAIN ||
         form_ == MFREE_FORM_ELASTICITY_3D || form_ == MFREE_FORM_COLLOCATION_PLANE_STRESS ||
         form_ == MFREE_FORM_COLLOCATION_PLANE_STRAIN;
}

void Assembler::set_material(double young, double poisson) {
  if (!(std::isfinite(young) && young > 0.0) || !(std::isfinite(poisson) && poisson > -1.0 && poisson < 0.5))
    throw Error(MFREE_ERR_ARG, "material needs E > 0 and -1 < nu < 1/2");
  young_ = young;
  poisson_ = poisson;
}

void Assembler::set_coefficient(double c) {
  if (!(std::isfinite(c) && c > 0.0)) throw Error(MFREE_ERR_ARG, "coefficient must be finite and > 0");
  coef_ = c;
}


double Assembler::mean_h() const {
  double s = 0.0;
  const int32_t n = ps_->size();
  for (int32_t i = 0; i < n; ++i) s += ps_->h(i);
  return n ? s / n : 1.0;
}

ApproxConfig Assembler::values_config(const ApproxConfig &c) const {
  // Particles-only methods correct derivatives, not values: loads and boundary values
  // use the method's own function approximation (paper 000 leaves this open,
  // docs/papers.md, paper 000, choices 4). Symmetrised SPH and Johnson-Beissel keep SPH's kernel
  // estimate sum_I W(x - x_I) u_I dV_I (000 eq 21; JB corrects the normal strains only),
  // which is not a partition of unity next to the boundary; Randles-Libersky's
  // normalised SPH uses Shepard functions (000 eq 70). With Shepard values for all three
  // the tractions' resultant would be exact and symmetrised SPH would converge slowly on
  // the plate with a hole, unlike 000 Table III (see tests/assembly/check_table3.cmake).
  ApproxConfig v = c;
  if (is_particles_only(c.method)) {
    v.method = c.method == MFREE_METHOD_RANDLES_LIBERSKY ? MFREE_METHOD_SHEPARD : MFREE_METHOD_SPH;
    v.order = 0;
  }
  v.flags = MFREE_DERIV_VALUE;
  return v;
}

std::vector<double> Assembler::point_supports(const HVec<double> &pts) const {
  const int32_t n = ps_->size(), m = static_cast<int32_t>(pts.size() / dim_);
  if (!ps_->has_support() || n == 0) return {mean_h()};
  double hmin = ps_->h(0), hmax = hmin;
  for (int32_t i = 1; i < n; ++i) {
    hmin = std::min(hmin, ps_->h(i));
    hmax = std::max(hmax, ps_->h(i));
  }
  if (hmin == hmax || m == 0) return {hmax};
  // h(x) = sum_j w_j(x) h_j / sum_j w_j(x), the particles' supports averaged with their
  // own (scatter) cubic-spline weights w_j = f(2 r / (kappa h_j)) / h_j^dim: it follows
  // the local h inside a uniform region and grows smoothly across a transition, where a
  // point next to fine particles still reaches the coarse ones beyond them. A point that
  // no support covers takes its nearest particle's h.
  const double kappa = ps_->kappa();
  VectorArray X;
  X.ptr = pts.data();
  X.ld = dim_;
  X.layout = MFREE_LAYOUT_AOS;
  ScalarArray H;
  H.ptr = &hmax;
  H.stride = 0;
  Csr nb;
  find_point_neighbors(*ps_, ps_->site_status(), m, X, H, nb);
  const Kernel spline(MFREE_KERNEL_CUBIC_SPLINE, dim_, 0.0);
  std::vector<double> h(m, hmax);
  for (int32_t q = 0; q < m; ++q) {
    double best = HUGE_VAL, sw = 0.0, swh = 0.0;
    for (int64_t k = nb.rowptr[q]; k < nb.rowptr[q + 1]; ++k) {
      const int32_t j = nb.cols[k];
      double d2 = 0.0;
      for (int c = 0; c < dim_; ++c) {
        const double d = pts[static_cast<size_t>(q) * dim_ + c] - ps_->x(j, c);
        d2 += d * d;
      }
      const double hj = ps_->h(j), u = 2.0 * std::sqrt(d2) / (kappa * hj);
      if (d2 < best) best = d2, h[q] = hj;
      if (u >= 2.0) continue;
      const double w = spline.shape(u) / std::pow(hj, dim_);
      sw += w;
      swh += w * hj;
    }
    if (sw > 0.0) h[q] = swh / sw;
  }
  return h;
}

std::unique_ptr<Approximant> Assembler::make(const ApproxConfig &cfg, const HVec<double> *pts) const {
  auto a = std::make_unique<Approximant>(ps_, cfg);
  if (pts) {
    // Supports of quadrature and boundary points: the particles' supports averaged around
    // the point (point_supports), so that on graded clouds a point sees what the
    // particles around it see, not a mean over the whole set.
    const std::vector<double> h = point_supports(*pts);
    const int32_t n = static_cast<int32_t>(pts->size() / dim_);
    a->set_points(n, n ? pts->data() : nullptr, MFREE_LAYOUT_AOS, dim_, h.data(), h.size() == 1 ? 0 : 1,
                  MFREE_COPY);
  }
  return a;
}

Report Assembler::build_tables() {
  Report rep;
  auto merge = [&](const Report &r, const char *where) {
    if (!r.ok()) rep.fail(r.status, std::string(where) + ": " + r.message);
  };
  const bool nodal = quad_kind_ == 0;
  if (!nodal && (is_particles_only(trial_cfg_.method) || is_particles_only(test_cfg_.method)))
    throw Error(MFREE_ERR_UNSUPPORTED, "symmetric SPH, Johnson-Beissel and Randles-Libersky are defined at the "
                                       "particles: use nodal quadrature");
  ApproxConfig tc = trial_cfg_, sc = test_cfg_;
  if (collocation()) {
    tc.flags = MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT | MFREE_DERIV_HESSIAN;
    trial_q_ = make(tc, nullptr);
    merge(trial_q_->setup(), "collocation tables");
    test_q_.reset();
    load_q_.reset();
    trial_nodes_.reset();
  } else {
    const bool m = mass();
    tc.flags = m ? MFREE_DERIV_VALUE : (MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT);
    sc.flags = tc.flags;
    if (is_particles_only(tc.method)) tc.flags = MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT;
    trial_q_ = make(tc, nodal ? nullptr : &qx_);
    merge(trial_q_->setup(), "trial functions at the quadrature points");
    if (!bubnov_) {
      test_q_ = make(sc, nodal ? nullptr : &qx_);
      merge(test_q_->setup(), "test functions at the quadrature points");
    } else {
      test_q_.reset();
    }
    // Johnson-Beissel (paper 000 eqs 48-52) corrects the normal strains; the shear strain
    // keeps the symmetrised SPH derivatives of eq 47.
    auto shear = [&](const ApproxConfig &c, std::unique_ptr<Approximant> &out, const char *where) {
      out.reset();
      if (!elasticity() || c.method != MFREE_METHOD_JOHNSON_BEISSEL) return;
      ApproxConfig sh = c;
      sh.method = MFREE_METHOD_SPH_SYMMETRIC;
      sh.flags = MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT;
      out = make(sh, nullptr);
      merge(out->setup(), where);
    };
    shear(tc, trial_shear_, "symmetrised SPH shear derivatives of the trial functions");
    if (!bubnov_) shear(sc, test_shear_, "symmetrised SPH shear derivatives of the test functions");
    else test_shear_.reset();
    load_q_.reset();
    if (body_ && !m) {
      load_q_ = make(values_config(test_cfg_), nodal ? nullptr : &qx_);
      merge(load_q_->setup(), "test values at the quadrature points");
    }
    trial_nodes_.reset();
    if (std::any_of(nsets_.begin(), nsets_.end(), [](const NodeSet &n) { return n.kind != 3; })) {
      trial_nodes_ = make(values_config(trial_cfg_), nullptr);
      merge(trial_nodes_->setup(), "trial values at the particles");
    }
  }
  for (auto &s : psets_) {
    s->test.reset();
    s->trial.reset();
    if (s->kind == 4) {
      ApproxConfig t = test_cfg_, r = trial_cfg_;
      t.flags = r.flags = MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT;
      s->test = make(t, &s->x);
      merge(s->test->setup(), "test functions at Nitsche points");
      s->trial = make(r, &s->x);
      merge(s->trial->setup(), "trial functions at Nitsche points");
      continue;
    }
    if (s->kind == 1 || s->kind == 2 || s->kind == 5) {
      s->test = make(values_config(test_cfg_), &s->x);
      merge(s->test->setup(), "test values at boundary points");
    }
    if (s->kind == 2 || s->kind == 3) {
      s->trial = make(values_config(trial_cfg_), &s->x);
      merge(s->trial->setup(), "trial values at boundary points");
    }
  }
  return rep;
}

void Assembler::build_pattern() {
  const int32_t n = ps_->size(), nc = ncomp_;
  std::vector<std::vector<int32_t>> rows(n);  // node-level columns per test node
  const Approximant &trial = *trial_q_;
  if (form_ == MFREE_FORM_MASS_LUMPED) {
    for (int32_t i = 0; i < n; ++i) rows[i].push_back(i);
  } else if (collocation()) {
    for (int32_t s = 0; s < trial.num_sites(); ++s)
      for (int64_t b = trial.rowptr()[s]; b < trial.rowptr()[s + 1]; ++b) rows[s].push_back(trial.cols()[b]);
  } else {
    // Row J = the trial neighbours of every quadrature point that J's test function
    // sees: through the transpose of the test table, with a marker per node, so that
    // each row is collected without duplicates (background quadrature has many points
    // per node pair).
    const QTable &qa = qtrial_, &qb = test_table();
    std::vector<int64_t> tp(static_cast<size_t>(n) + 1, 0);
    for (int32_t J : qb.cols) ++tp[static_cast<size_t>(J) + 1];
    for (int32_t J = 0; J < n; ++J) tp[J + 1] += tp[J];
    std::vector<int32_t> tq(qb.cols.size());
    {
      std::vector<int64_t> next(tp.begin(), tp.end() - 1);
      for (int32_t q = 0; q < qb.size(); ++q)
        for (int64_t a = qb.rowptr[q]; a < qb.rowptr[q + 1]; ++a) tq[next[qb.cols[a]]++] = q;
    }
    std::vector<int32_t> mark(n, -1);
    for (int32_t J = 0; J < n; ++J)
      for (int64_t t = tp[J]; t < tp[J + 1]; ++t) {
        const int32_t q = tq[t];
        for (int64_t b = qa.rowptr[q]; b < qa.rowptr[q + 1]; ++b) {
          const int32_t K = qa.cols[b];
          if (mark[K] != J) mark[K] = J, rows[J].push_back(K);
        }
      }
    for (size_t si = 0; si < psets_.size(); ++si)
      if (psets_[si]->kind == 2 || psets_[si]->kind == 4) {
        const QTable &ts = ps_test_[si], &tr = ps_trial_[si];
        for (int32_t p = 0; p < tr.size(); ++p)
          for (int64_t a = ts.rowptr[p]; a < ts.rowptr[p + 1]; ++a) {
            auto &row = rows[ts.cols[a]];
            for (int64_t b = tr.rowptr[p]; b < tr.rowptr[p + 1]; ++b) row.push_back(tr.cols[b]);
          }
      }
  }
  // Dirichlet/traction rows at nodes: the trial row at the node
  const Approximant *tn = collocation() ? trial_q_.get() : trial_nodes_.get();
  for (auto &ns : nsets_)
    for (int32_t J : ns.nodes) {
      if (ns.kind == 3) {
        rows[J].push_back(J);
        continue;
      }
      for (int64_t b = tn->rowptr()[J]; b < tn->rowptr()[J + 1]; ++b) rows[J].push_back(tn->cols()[b]);
    }
  for (auto &r : rows) {
    std::sort(r.begin(), r.end());
    r.erase(std::unique(r.begin(), r.end()), r.end());
  }
  // multipliers: one per Lagrange point and constrained component
  nmult_ = 0;
  std::vector<std::vector<int32_t>> mcols;  // dof columns of each multiplier row
  for (size_t si = 0; si < psets_.size(); ++si) {
    auto &s = psets_[si];
    if (s->kind != 3) continue;
    s->first_multiplier = nmult_;
    const QView a{ps_trial_[si]};
    for (int32_t p = 0; p < a.num_sites(); ++p)
      for (int c = 0; c < nc; ++c) {
        if (!(s->mask & (1 << c))) continue;
        std::vector<int32_t> mc;
        for (int64_t b = a.rowptr()[p]; b < a.rowptr()[p + 1]; ++b) mc.push_back(a.cols()[b] * nc + c);
        std::sort(mc.begin(), mc.end());
        mcols.push_back(std::move(mc));
        ++nmult_;
      }
  }
  // unknowns are int32 indices in the ABI (mfree_matrix_t columns): unknowns.h, t690
  int32_t nunknowns = 0;
  const mfree_status_t size_status =
      mfree_core_count_unknowns(n, nc, static_cast<int64_t>(mcols.size()), &nunknowns);
  if (size_status != MFREE_SUCCESS)
    throw Error(size_status, "too many unknowns (" +
                                   std::to_string(static_cast<int64_t>(n) * nc + static_cast<int64_t>(mcols.size())) +
                                   ") for int32 indices");
  const int32_t nbase = n * nc;
  ndofs_ = nunknowns;  // = nbase + nmult_, counted once by the size rule above
  // transpose of the multiplier columns: for each dof, the multipliers touching it
  std::vector<std::vector<int32_t>> dof_mult(nbase);
  for (int32_t m = 0; m < nmult_; ++m)
    for (int32_t d : mcols[m]) dof_mult[d].push_back(nbase + m);
  rowptr_.assign(static_cast<size_t>(ndofs_) + 1, 0);
  cols_.clear();
  node_deg_.assign(n, 0);
  for (int32_t J = 0; J < n; ++J) node_deg_[J] = static_cast<int32_t>(rows[J].size());
  for (int32_t J = 0; J < n; ++J)
    for (int a = 0; a < nc; ++a) {
      const int32_t dof = J * nc + a;
      for (int32_t K : rows[J])
        for (int b = 0; b < nc; ++b) cols_.push_back(K * nc + b);
      for (int32_t m : dof_mult[dof]) cols_.push_back(m);
      rowptr_[dof + 1] = static_cast<int64_t>(cols_.size());
    }
  for (int32_t m = 0; m < nmult_; ++m) {
    for (int32_t d : mcols[m]) cols_.push_back(d);
    rowptr_[nbase + m + 1] = static_cast<int64_t>(cols_.size());
  }
  // replaced rows: Dirichlet rows win over traction rows, both over the form's rows
  row_kind_.assign(nbase, 0);
  row_set_.assign(nbase, -1);
  row_node_.assign(nbase, -1);
  const int passes[3] = {2, 1, 3};  // later passes win: identity > Dirichlet > traction rows
  for (int pass : passes)
    for (size_t si = 0; si < nsets_.size(); ++si) {
      const NodeSet &ns = nsets_[si];
      if (ns.kind != pass) continue;
      for (size_t k = 0; k < ns.nodes.size(); ++k)
        for (int c = 0; c < nc; ++c) {
          if (ns.kind != 2 && !(ns.mask & (1 << c))) continue;
          const int32_t dof = ns.nodes[k] * nc + c;
          // Particles-only methods (symmetrised SPH, JB, RL) have no values between or at
          // the particles beyond the particle values their derivatives act on: their
          // Dirichlet rows hold u_J = g(x_J) on the parameter itself (identity rows).
          row_kind_[dof] = ns.kind == 1 && is_particles_only(trial_cfg_.method) ? 3 : ns.kind;
          row_set_[dof] = static_cast<int32_t>(si);
          row_node_[dof] = static_cast<int32_t>(k);
        }
    }
}

Report Assembler::setup() {
  if (!ps_->is_setup()) throw Error(MFREE_ERR_STATE, "the particle set is not set up");
  // nodal quadrature weighs every particle with its volume (000 eq 95)
  if (!collocation() && quad_kind_ == 0 && !ps_->has_volumes())
    throw Error(MFREE_ERR_STATE,
                "nodal quadrature needs particle volumes (mfree_particles_set_volumes, or masses and densities)");
  const double modulus = elasticity() ? young_ : coef_;
  if (!penalty_set_) penalty_ = 1e6 * modulus;
  nitsche_ = penalty_set_ ? penalty_ : 100.0 * modulus / mean_h();
  Report rep = build_tables();
  build_qtables();
  build_pattern();
  quadrature_order();
  // diagnostics: quadrature points outside every support; particles no point sees
  const Approximant &trial = *trial_q_;
  int64_t bad_q = 0;
  for (int32_t s = 0; s < trial.num_sites(); ++s)
    if (trial.site_status()[s] != 0 || trial.rowptr()[s + 1] == trial.rowptr()[s]) ++bad_q;
  if (bad_q && rep.ok())
    rep.fail(MFREE_FAIL_NEIGHBORS, std::to_string(bad_q) + " quadrature points are outside every support or failed");
  // Only owned rows: a ghost beyond the quadrature points' reach has an empty row, which
  // is no fault (its rows belong to the rank that owns it).
  for (int32_t d = 0; d < ps_->num_owned() * ncomp_; ++d)
    if (rowptr_[d + 1] == rowptr_[d] && row_kind_[d] == 0) {
      rep.fail(MFREE_FAIL_NEIGHBORS, "particle " + std::to_string(d / ncomp_) +
                                         " is seen by no quadrature point: its row of the matrix is zero");
      break;
    }
  setup_done_ = true;
  return rep;
}

Report Assembler::update() {
  if (!setup_done_) throw Error(MFREE_ERR_STATE, "update called before setup");
  Report rep;
  auto upd = [&](Approximant *a) {
    if (a) {
      Report r = a->update();
      if (!r.ok()) rep.fail(r.status, r.message);
    }
  };
  upd(trial_q_.get());
  upd(test_q_.get());
  upd(load_q_.get());
  upd(trial_nodes_.get());
  upd(trial_shear_.get());
  upd(test_shear_.get());
  for (auto &s : psets_) {
    upd(s->test.get());
    upd(s->trial.get());
  }
  build_qtables();
  return rep;
}

}  // namespace mfree
