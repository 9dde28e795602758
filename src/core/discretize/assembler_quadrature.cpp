// Quadrature of the assembler: nodal, background cells or host points, the tables of
// functions at the quadrature points, and their consistent-integration correction.
#include "core/discretize/assembler.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/base/quadrature.hpp"
#include "core/discretize/consistent_integration.hpp"

namespace mfree {

namespace {

// Gauss-Legendre product rule (ngauss per axis) on the cells of the box [lo, hi] cut into
// ncells per axis: the points (dim per point) for which inside(user, x) holds (every
// point without inside) and their weights.
void cell_rule(int dim, const double *lo, const double *hi, const int32_t *ncells, int ngauss,
               mfree_inside_fn inside, void *user, HVec<double> &x, HVec<double> &w) {
  std::vector<double> g, gw;
  gauss_legendre(ngauss, g, gw);
  int64_t total = 1;
  for (int c = 0; c < dim; ++c) total *= static_cast<int64_t>(ncells[c]) * ngauss;
  if (total > (int64_t(1) << 31) - 1) throw Error(MFREE_ERR_ARG, "too many quadrature points");
  double h[3] = {0, 0, 0};
  for (int c = 0; c < dim; ++c) h[c] = (hi[c] - lo[c]) / ncells[c];
  int64_t idx[3] = {0, 0, 0}, per[3] = {1, 1, 1};
  for (int c = 0; c < dim; ++c) per[c] = static_cast<int64_t>(ncells[c]) * ngauss;
  for (int64_t t = 0; t < total; ++t) {
    int64_t r = t;
    double p[3] = {0, 0, 0}, wt = 1.0;
    for (int c = 0; c < dim; ++c) {
      idx[c] = r % per[c];
      r /= per[c];
      const int64_t cell = idx[c] / ngauss, q = idx[c] % ngauss;
      p[c] = lo[c] + h[c] * (cell + 0.5 * (1.0 + g[q]));
      wt *= 0.5 * h[c] * gw[q];
    }
    if (inside && !inside(user, p)) continue;
    for (int c = 0; c < dim; ++c) x.push_back(p[c]);
    w.push_back(wt);
  }
}

}  // namespace

void Assembler::set_quadrature_nodal() {
  quad_kind_ = 0;
  qx_.clear();
  qw_.clear();
  setup_done_ = false;
}

void Assembler::check_points(int32_t npts, const double *x, const double *w, const char *what) const {
  if (npts < 0) throw Error(MFREE_ERR_ARG, std::string(what) + ": negative point count");
  if (npts > 0 && !x) throw Error(MFREE_ERR_NULL, std::string(what) + ": points are NULL");
  if (w)
    for (int32_t p = 0; p < npts; ++p)
      if (!(std::isfinite(w[p]) && w[p] >= 0.0))
        throw Error(MFREE_ERR_INPUT, std::string(what) + ": weight " + std::to_string(p) + " = " +
                                         std::to_string(w[p]) + " is negative or not finite");
}

void Assembler::check_unit_normals(int32_t npts, const double *normals, const char *what) const {
  for (int32_t p = 0; p < npts; ++p) {
    double len = 0.0;
    for (int c = 0; c < dim_; ++c) len += normals[p * dim_ + c] * normals[p * dim_ + c];
    if (!(std::isfinite(len) && std::fabs(len - 1.0) < 1e-6))
      throw Error(MFREE_ERR_INPUT, std::string(what) + "normal " + std::to_string(p) + " is not a finite unit vector");
  }
}

void Assembler::read_points(int32_t npts, const double *x, int layout, int64_t ld,
                            HVec<double> &out) const {
  if (layout != MFREE_LAYOUT_AOS && layout != MFREE_LAYOUT_SOA) throw Error(MFREE_ERR_ARG, "unknown layout");
  if (ld < (layout == MFREE_LAYOUT_AOS ? dim_ : npts)) throw Error(MFREE_ERR_ARG, "leading dimension too small");
  check_extent(npts, dim_, layout, ld, "the points");
  VectorArray v;
  v.ptr = x;
  v.ld = ld;
  v.layout = layout;
  out.assign(static_cast<size_t>(npts) * dim_, 0.0);
  for (int32_t p = 0; p < npts; ++p)
    for (int c = 0; c < dim_; ++c) {
      const double val = v(p, c);
      if (!std::isfinite(val)) throw Error(MFREE_ERR_INPUT, "point " + std::to_string(p) + " is not finite");
      out[static_cast<size_t>(p) * dim_ + c] = val;
    }
}

void Assembler::set_quadrature_cells(const double *lo, const double *hi, const int32_t *ncells, int ngauss,
                                     mfree_inside_fn inside, void *user) {
  if (!lo || !hi || !ncells) throw Error(MFREE_ERR_NULL, "lo, hi or ncells is NULL");
  if (ngauss < 1 || ngauss > 20) throw Error(MFREE_ERR_ARG, "ngauss must be 1..20");
  for (int c = 0; c < dim_; ++c) {
    if (!(std::isfinite(lo[c]) && std::isfinite(hi[c]) && hi[c] > lo[c]))
      throw Error(MFREE_ERR_INPUT, "cell box axis " + std::to_string(c) + " needs finite lo < hi");
    if (ncells[c] < 1) throw Error(MFREE_ERR_ARG, "ncells must be >= 1");
  }
  HVec<double> x, w;
  cell_rule(dim_, lo, hi, ncells, ngauss, inside, user, x, w);
  qx_ = std::move(x);
  qw_ = std::move(w);
  quad_kind_ = 1;
  setup_done_ = false;
}

void Assembler::set_quadrature_points(int32_t npts, const double *x, int layout, int64_t ld, const double *w) {
  check_points(npts, x, w, "quadrature");
  if (npts > 0 && !w) throw Error(MFREE_ERR_NULL, "quadrature weights are NULL");
  // both copies made before either is replaced: running out of memory leaves the old pair
  HVec<double> pts, wts;
  read_points(npts, x, layout, ld, pts);
  wts.assign(w, w + npts);
  qx_.swap(pts);
  qw_.swap(wts);
  quad_kind_ = 1;
  setup_done_ = false;
}

void Assembler::set_body_force(mfree_field_fn f, void *user) {
  body_ = f;
  body_user_ = user;
}

void Assembler::fill_qtable(const Approximant &a, QTable &t, const HVec<double> *w,
                            const HVec<double> *pts) const {
  const int dim = dim_;
  const int32_t nq = a.num_sites();
  t.w.resize(nq);
  for (int32_t q = 0; q < nq; ++q) t.w[q] = w ? (*w)[q] : ps_->volume(q);
  if (pts) {
    t.x.assign(pts->begin(), pts->end());
  } else {
    t.x.resize(static_cast<size_t>(nq) * dim);
    for (int32_t q = 0; q < nq; ++q)
      for (int d = 0; d < dim; ++d) t.x[static_cast<size_t>(q) * dim + d] = ps_->x(q, d);
  }
  t.rowptr = a.rowptr();
  t.cols = a.cols();
  const size_t nnz = t.cols.size();
  t.val = a.values().empty() ? std::vector<double>(nnz, 0.0) : a.values();
  t.grad = a.gradients().empty() ? std::vector<double>(nnz * dim, 0.0) : a.gradients();
}

void Assembler::build_qtables() {
  if (collocation()) return;
  const bool nodal = quad_kind_ == 0;
  fill_qtable(*trial_q_, qtrial_, nodal ? nullptr : &qw_, nodal ? nullptr : &qx_);
  if (test_q_) fill_qtable(*test_q_, qtest_, nodal ? nullptr : &qw_, nodal ? nullptr : &qx_);
  else qtest_ = QTable();
  auto shear = [&](const Approximant *a, QTable &t) {
    if (!a) return;
    if (a->rowptr() != t.rowptr || a->cols() != t.cols)
      throw Error(MFREE_ERR_INTERNAL, "symmetrised SPH and Johnson-Beissel tables differ in their neighbours");
    t.sgrad = a->gradients();
  };
  shear(trial_shear_.get(), qtrial_);
  if (test_q_) shear(test_shear_.get(), qtest_);
  if (fe_.npe()) {
    fe_.blend(qtrial_, nodal ? nullptr : &qx_);
    if (test_q_) fe_.blend(qtest_, nodal ? nullptr : &qx_);
  }
  // boundary point sets: the same blending, so that boundary terms inside the layer use
  // the layer's functions
  ps_test_.assign(psets_.size(), QTable());
  ps_trial_.assign(psets_.size(), QTable());
  for (size_t i = 0; i < psets_.size(); ++i) {
    PointSet &s = *psets_[i];
    if (s.test) {
      fill_qtable(*s.test, ps_test_[i], &s.w, &s.x);
      if (fe_.npe()) fe_.blend(ps_test_[i], &s.x);
    }
    if (s.trial) {
      fill_qtable(*s.trial, ps_trial_[i], &s.w, &s.x);
      if (fe_.npe()) fe_.blend(ps_trial_[i], &s.x);
    }
  }
  // variationally consistent integration: the test gradients of the assembly corrected
  own_test_table_ = test_q_ != nullptr;
  for (size_t i = 0; i < psets_.size(); ++i) {
    if (psets_[i]->kind != 5) continue;
    if (!own_test_table_) {
      qtest_ = qtrial_;
      own_test_table_ = true;
    }
    correct_test_gradients(*ps_, qtest_, ps_test_[i], psets_[i]->normals);
  }
}

void Assembler::quadrature_order() {
  // Background and host points keep the host's order; nodal quadrature points are
  // particles, taken in the set's canonical order.
  const int32_t nq = collocation() ? 0 : qtrial_.size();
  qorder_.resize(static_cast<size_t>(nq));
  for (int32_t q = 0; q < nq; ++q) qorder_[q] = q;
  if (quad_kind_ == 0 && ps_->has_global_ids()) {
    const int64_t *gid = ps_->global_ids();
    std::sort(qorder_.begin(), qorder_.end(), [gid](int32_t a, int32_t b) { return gid[a] < gid[b]; });
  }
}

const char *Assembler::ranks_obstacle() const {
  if (quad_kind_ == 0)
    return "nodal quadrature: its points are the particle set's non-ghosts, and on ranks those must include the "
           "ghosts within one support radius of the owned particles, which the system's state (the owned "
           "particles) cannot tell apart; give the quadrature points within one support radius of the owned "
           "particles, in the global order of the points (mfree_assembler_set_quadrature_points)";
  if (fe_.npe()) return "an FE layer (its elements are not distributed)";
  for (const auto &s : psets_)
    if (s->kind == 5) return "consistent integration (its boundary correction is not distributed)";
  return nullptr;
}

std::unique_ptr<Assembler> Assembler::mass_on_same_points(int form, double coef) const {
  auto m = std::make_unique<Assembler>(ps_, trial_cfg_, test_cfg_, bubnov_, form);
  m->set_coefficient(coef);
  m->quad_kind_ = quad_kind_;
  m->qx_ = qx_;
  m->qw_ = qw_;
  const Report rep = m->setup();
  if (!rep.ok()) throw Error(MFREE_ERR_INPUT, "the mass on the stiffness's quadrature points: " + rep.message);
  return m;
}

void Assembler::set_consistent_integration(int32_t npts, const double *x, int layout, int64_t ld,
                                           const double *w, const double *normals) {
  if (collocation() || mass())
    throw Error(MFREE_ERR_UNSUPPORTED, "consistent integration corrects test gradients of Galerkin stiffness forms");
  if (is_particles_only(test_cfg_.method))
    throw Error(MFREE_ERR_UNSUPPORTED, "consistent integration needs test-function values at boundary points, which "
                                       "symmetrised SPH, Johnson-Beissel and Randles-Libersky do not define");
  check_points(npts, x, w, "consistent integration");
  if (npts > 0 && !w) throw Error(MFREE_ERR_NULL, "consistent integration: weights are NULL");
  if (npts > 0 && !normals) throw Error(MFREE_ERR_NULL, "consistent integration: normals are NULL");
  check_unit_normals(npts, normals, "consistent integration: ");
  std::unique_ptr<PointSet> s;
  if (npts > 0) {
    s = std::make_unique<PointSet>();
    s->kind = 5;
    read_points(npts, x, layout, ld, s->x);
    s->w.assign(w, w + npts);
    s->normals.assign(normals, normals + static_cast<size_t>(npts) * dim_);
  }
  psets_.reserve(psets_.size() + 1);  // the last allocation: nothing below may fail
  psets_.erase(std::remove_if(psets_.begin(), psets_.end(), [](const std::unique_ptr<PointSet> &q) { return q->kind == 5; }),
               psets_.end());
  if (s) psets_.push_back(std::move(s));
  setup_done_ = false;
}

}  // namespace mfree
