#include "core/discretize/assembler.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/base/basis.hpp"
#include "core/base/quadrature.hpp"
#include "core/discretize/unknowns.h"
#include "core/particles/neighbors.hpp"

namespace mfree {

namespace {

bool is_particles_only(int m) {
  return m == MFREE_METHOD_SPH_SYMMETRIC || m == MFREE_METHOD_JOHNSON_BEISSEL ||
         m == MFREE_METHOD_RANDLES_LIBERSKY;
}

// Rows of the strain-displacement matrix B(g) for gradient g (Voigt: xx, yy, [zz,] xy
// [, yz, zx]); B[v][a] is the factor of u_a in strain component v.
int strain_rows(int dim, const double *g, double B[6][3]) {
  for (int v = 0; v < 6; ++v) B[v][0] = B[v][1] = B[v][2] = 0.0;
  if (dim == 2) {
    B[0][0] = g[0];
    B[1][1] = g[1];
    B[2][0] = g[1];
    B[2][1] = g[0];
    return 3;
  }
  B[0][0] = g[0];
  B[1][1] = g[1];
  B[2][2] = g[2];
  B[3][0] = g[1];
  B[3][1] = g[0];
  B[4][1] = g[2];
  B[4][2] = g[1];
  B[5][0] = g[2];
  B[5][2] = g[0];
  return 6;
}

// The same with the shear rows from gradient gs (Johnson-Beissel: paper 000 eqs 48-52
// correct the normal strains only).
int strain_rows(int dim, const double *g, const double *gs, double B[6][3]) {
  double Bs[6][3];
  const int nv = strain_rows(dim, g, B);
  if (gs == g) return nv;
  strain_rows(dim, gs, Bs);
  for (int v = dim; v < nv; ++v)
    for (int a = 0; a < 3; ++a) B[v][a] = Bs[v][a];
  return nv;
}

// Voigt index of the stress component (a, b).
int voigt(int dim, int a, int b) {
  if (a == b) return a;
  if (dim == 2) return 2;
  const int lo = std::min(a, b), hi = std::max(a, b);
  return lo == 0 ? (hi == 1 ? 3 : 5) : 4;
}

}  // namespace

Assembler::Assembler(const ParticleSet *ps, const ApproxConfig &trial, const ApproxConfig &test,
                     bool bubnov, int form)
    : ps_(ps), trial_cfg_(trial), test_cfg_(bubnov ? trial : test), bubnov_(bubnov), form_(form),
      dim_(ps->dim()) {
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

void Assembler::set_penalty(double alpha) {
  if (!(std::isfinite(alpha) && alpha > 0.0)) throw Error(MFREE_ERR_ARG, "penalty must be finite and > 0");
  penalty_ = alpha;
  penalty_set_ = true;
}

void Assembler::traction_row(const double *g, const double *n, double T[3][3]) const {
  for (int a = 0; a < 3; ++a) T[a][0] = T[a][1] = T[a][2] = 0.0;
  if (!elasticity()) {
    double s = 0.0;
    for (int d = 0; d < dim_; ++d) s += n[d] * g[d];
    T[0][0] = coef_ * s;
    return;
  }
  double D[36], B[6][3];
  int nv = 0;
  material_matrix(D, nv);
  const int dstride = dim_ == 2 ? 3 : 6;
  strain_rows(dim_, g, B);
  for (int c = 0; c < dim_; ++c)
    for (int e = 0; e < dim_; ++e) {
      double s = 0.0;
      for (int d = 0; d < dim_; ++d) {
        const int vr = voigt(dim_, c, d);
        for (int t = 0; t < nv; ++t) s += n[d] * D[vr * dstride + t] * B[t][e];
      }
      T[c][e] = s;
    }
}

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
  std::vector<double> g, gw;
  gauss_legendre(ngauss, g, gw);
  HVec<double> x, w;
  int64_t total = 1;
  for (int c = 0; c < dim_; ++c) total *= static_cast<int64_t>(ncells[c]) * ngauss;
  if (total > (int64_t(1) << 31) - 1) throw Error(MFREE_ERR_ARG, "too many quadrature points");
  double h[3] = {0, 0, 0};
  for (int c = 0; c < dim_; ++c) h[c] = (hi[c] - lo[c]) / ncells[c];
  int64_t idx[3] = {0, 0, 0}, per[3] = {1, 1, 1};
  for (int c = 0; c < dim_; ++c) per[c] = static_cast<int64_t>(ncells[c]) * ngauss;
  for (int64_t t = 0; t < total; ++t) {
    int64_t r = t;
    double p[3] = {0, 0, 0}, wt = 1.0;
    for (int c = 0; c < dim_; ++c) {
      idx[c] = r % per[c];
      r /= per[c];
      const int64_t cell = idx[c] / ngauss, q = idx[c] % ngauss;
      p[c] = lo[c] + h[c] * (cell + 0.5 * (1.0 + g[q]));
      wt *= 0.5 * h[c] * gw[q];
    }
    if (inside && !inside(user, p)) continue;
    for (int c = 0; c < dim_; ++c) x.push_back(p[c]);
    w.push_back(wt);
  }
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

void Assembler::add_traction(int32_t npts, const double *x, int layout, int64_t ld, const double *w,
                             mfree_field_fn t, void *user) {
  if (collocation()) throw Error(MFREE_ERR_UNSUPPORTED, "collocation forms take tractions at nodes (add_traction_nodes)");
  if (mass()) throw Error(MFREE_ERR_UNSUPPORTED, "mass forms take no loads");
  check_points(npts, x, w, "traction");
  if (!t) throw Error(MFREE_ERR_NULL, "traction function is NULL");
  if (npts > 0 && !w) throw Error(MFREE_ERR_NULL, "traction weights are NULL");
  auto s = std::make_unique<PointSet>();
  s->kind = 1;
  read_points(npts, x, layout, ld, s->x);
  s->w.assign(w, w + npts);
  s->fn = t;
  s->user = user;
  psets_.push_back(std::move(s));
  setup_done_ = false;
}

// Checks shared by the boundary pieces (2D segments, 3D facets): dimension, count,
// pointer, rule order, and that every coordinate of every piece is finite.
static void check_boundary_pieces(int dim, int want_dim, int32_t count, const double *x, int ncoord,
                                  int ngauss, const char *what, const char *other) {
  if (dim != want_dim)
    throw Error(MFREE_ERR_UNSUPPORTED, std::string("boundary ") + what + "s are " + std::to_string(want_dim) +
                                           "D; give " + std::to_string(5 - want_dim) + "D boundaries as " + other);
  if (count < 0) throw Error(MFREE_ERR_ARG, std::string("negative ") + what + " count");
  if (count > 0 && !x) throw Error(MFREE_ERR_NULL, std::string(what) + "s are NULL");
  if (ngauss < 1 || ngauss > 20) throw Error(MFREE_ERR_ARG, "ngauss must be 1..20");
  for (int64_t k = 0; k < int64_t(count) * ncoord; ++k)
    if (!std::isfinite(x[k]))
      throw Error(MFREE_ERR_INPUT, std::string(what) + " " + std::to_string(k / ncoord) + " is not finite");
}

void Assembler::add_traction_segments(int32_t nseg, const double *x, int ngauss, mfree_field_fn t, void *user) {
  check_boundary_pieces(dim_, 2, nseg, x, 4, ngauss, "segment", "facets");
  std::vector<double> g, gw, pts, w;
  gauss_legendre(ngauss, g, gw);
  for (int32_t s = 0; s < nseg; ++s) {
    const double *a = x + 4 * s, *b = a + 2;
    const double len = std::hypot(b[0] - a[0], b[1] - a[1]);
    if (!(len > 0.0)) throw Error(MFREE_ERR_INPUT, "segment " + std::to_string(s) + " has zero length");
    for (int q = 0; q < ngauss; ++q) {
      const double tq = 0.5 * (1.0 + g[q]);
      pts.push_back(a[0] + tq * (b[0] - a[0]));
      pts.push_back(a[1] + tq * (b[1] - a[1]));
      w.push_back(0.5 * len * gw[q]);
    }
  }
  add_traction(static_cast<int32_t>(w.size()), pts.data(), MFREE_LAYOUT_AOS, 2, w.data(), t, user);
}

void Assembler::add_traction_facets(int32_t nfacet, const double *x, int ngauss, mfree_field_fn t, void *user) {
  check_boundary_pieces(dim_, 3, nfacet, x, 9, ngauss, "facet", "segments");
  // Collapsed (Duffy) product rule: (xi, eta) = (u, v (1 - u)) with Gauss-Legendre in u
  // and v on [0, 1]; dA = |(b - a) x (c - a)| (1 - u) du dv.
  std::vector<double> g, gw, pts, w;
  gauss_legendre(ngauss, g, gw);
  for (int32_t f = 0; f < nfacet; ++f) {
    const double *a = x + 9 * f, *b = a + 3, *c = a + 6;
    const double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double nx = e1[1] * e2[2] - e1[2] * e2[1], ny = e1[2] * e2[0] - e1[0] * e2[2],
                 nz = e1[0] * e2[1] - e1[1] * e2[0];
    const double jac = std::sqrt(nx * nx + ny * ny + nz * nz);
    const double scale = std::max(std::hypot(e1[0], e1[1], e1[2]), std::hypot(e2[0], e2[1], e2[2]));
    if (!(jac > 1e-14 * scale * scale))
      throw Error(MFREE_ERR_INPUT, "facet " + std::to_string(f) + " has zero area");
    for (int i = 0; i < ngauss; ++i) {
      const double u = 0.5 * (1.0 + g[i]);
      for (int j = 0; j < ngauss; ++j) {
        const double v = 0.5 * (1.0 + g[j]), xi = u, eta = v * (1.0 - u);
        for (int d = 0; d < 3; ++d) pts.push_back(a[d] + xi * e1[d] + eta * e2[d]);
        w.push_back(0.25 * gw[i] * gw[j] * (1.0 - u) * jac);
      }
    }
  }
  add_traction(static_cast<int32_t>(w.size()), pts.data(), MFREE_LAYOUT_AOS, 3, w.data(), t, user);
}

void Assembler::add_dirichlet(int method, int32_t npts, const double *x, int layout, int64_t ld,
                              const double *w, const double *normals, int32_t mask, mfree_field_fn g,
                              void *user) {
  if (method != MFREE_BC_PENALTY && method != MFREE_BC_LAGRANGE && method != MFREE_BC_NITSCHE)
    throw Error(MFREE_ERR_ARG, "add_dirichlet takes MFREE_BC_PENALTY, MFREE_BC_LAGRANGE or MFREE_BC_NITSCHE "
                               "(row replacement: add_dirichlet_nodes)");
  if (mass()) throw Error(MFREE_ERR_UNSUPPORTED, "mass forms take no boundary conditions");
  if (method == MFREE_BC_NITSCHE) {
    if (npts > 0 && !normals) throw Error(MFREE_ERR_NULL, "Nitsche needs the boundary normals");
    if (npts > 0 && !w) throw Error(MFREE_ERR_NULL, "Nitsche weights are NULL");
    if (is_particles_only(trial_cfg_.method) || is_particles_only(test_cfg_.method))
      throw Error(MFREE_ERR_UNSUPPORTED, "Nitsche needs derivatives at boundary points, which particles-only "
                                         "methods do not define");
    for (int32_t p = 0; p < npts; ++p) {
      double len = 0.0;
      for (int c = 0; c < dim_; ++c) len += normals[p * dim_ + c] * normals[p * dim_ + c];
      if (!(std::isfinite(len) && std::fabs(len - 1.0) < 1e-6))
        throw Error(MFREE_ERR_INPUT, "normal " + std::to_string(p) + " is not a finite unit vector");
    }
  }
  if (collocation()) throw Error(MFREE_ERR_UNSUPPORTED, "collocation forms take Dirichlet nodes");
  if (mask <= 0 || mask >= (1 << ncomp_)) throw Error(MFREE_ERR_ARG, "component mask selects no valid component");
  if (!g) throw Error(MFREE_ERR_NULL, "boundary value function is NULL");
  check_points(npts, x, w, "dirichlet");
  if (method == MFREE_BC_PENALTY && npts > 0 && !w) throw Error(MFREE_ERR_NULL, "penalty weights are NULL");
  auto s = std::make_unique<PointSet>();
  s->kind = method == MFREE_BC_PENALTY ? 2 : method == MFREE_BC_LAGRANGE ? 3 : 4;
  read_points(npts, x, layout, ld, s->x);
  if (method == MFREE_BC_NITSCHE) s->normals.assign(normals, normals + static_cast<size_t>(npts) * dim_);
  if (w) s->w.assign(w, w + npts);
  else s->w.assign(npts, 1.0);
  s->mask = mask;
  s->fn = g;
  s->user = user;
  psets_.push_back(std::move(s));
  setup_done_ = false;
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
  for (int32_t p = 0; p < npts; ++p) {
    double len = 0.0;
    for (int c = 0; c < dim_; ++c) len += normals[p * dim_ + c] * normals[p * dim_ + c];
    if (!(std::isfinite(len) && std::fabs(len - 1.0) < 1e-6))
      throw Error(MFREE_ERR_INPUT, "consistent integration: normal " + std::to_string(p) +
                                       " is not a finite unit vector");
  }
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

void Assembler::add_dirichlet_nodes(int32_t n, const int32_t *nodes, int32_t mask, mfree_field_fn g, void *user) {
  if (n < 0) throw Error(MFREE_ERR_ARG, "negative node count");
  if (n > 0 && !nodes) throw Error(MFREE_ERR_NULL, "nodes are NULL");
  if (!g) throw Error(MFREE_ERR_NULL, "boundary value function is NULL");
  if (mask <= 0 || mask >= (1 << ncomp_)) throw Error(MFREE_ERR_ARG, "component mask selects no valid component");
  for (int32_t k = 0; k < n; ++k)
    if (nodes[k] < 0 || nodes[k] >= ps_->num_owned())
      throw Error(MFREE_ERR_INPUT, "node " + std::to_string(nodes[k]) + " is not an owned particle");
  NodeSet s;
  s.kind = 1;
  s.nodes.assign(nodes, nodes + n);
  s.mask = mask;
  s.fn = g;
  s.user = user;
  nsets_.push_back(std::move(s));
  setup_done_ = false;
}

void Assembler::add_traction_nodes(int32_t n, const int32_t *nodes, const double *normals, mfree_field_fn t,
                                   void *user) {
  if (!collocation()) throw Error(MFREE_ERR_UNSUPPORTED, "traction rows at nodes are for collocation forms");
  if (n < 0) throw Error(MFREE_ERR_ARG, "negative node count");
  if (n > 0 && (!nodes || !normals)) throw Error(MFREE_ERR_NULL, "nodes or normals are NULL");
  if (!t) throw Error(MFREE_ERR_NULL, "traction function is NULL");
  for (int32_t k = 0; k < n; ++k) {
    if (nodes[k] < 0 || nodes[k] >= ps_->num_owned())
      throw Error(MFREE_ERR_INPUT, "node " + std::to_string(nodes[k]) + " is not an owned particle");
    double len = 0.0;
    for (int c = 0; c < dim_; ++c) len += normals[k * dim_ + c] * normals[k * dim_ + c];
    if (!(std::isfinite(len) && len > 0.0))
      throw Error(MFREE_ERR_INPUT, "normal of node " + std::to_string(nodes[k]) + " is zero or not finite");
  }
  NodeSet s;
  s.kind = 2;
  s.nodes.assign(nodes, nodes + n);
  s.normals.assign(normals, normals + static_cast<size_t>(n) * dim_);
  s.fn = t;
  s.user = user;
  nsets_.push_back(std::move(s));
  setup_done_ = false;
}

void Assembler::set_fe_layer(int32_t nelem, int32_t npe, const int32_t *conn, int32_t ngu, const int32_t *gu,
                             int32_t mask, mfree_field_fn g, void *user) {
  if (dim_ != 2) throw Error(MFREE_ERR_UNSUPPORTED, "the finite-element layer is implemented in 2D");
  if (collocation() || mass()) throw Error(MFREE_ERR_UNSUPPORTED, "the finite-element layer is for Galerkin forms");
  if (npe != 3 && npe != 4) throw Error(MFREE_ERR_ARG, "elements must have 3 (triangle) or 4 (quadrilateral) nodes");
  if (nelem < 1 || ngu < 1) throw Error(MFREE_ERR_ARG, "the layer needs elements and essential-boundary nodes");
  if (!conn || !gu) throw Error(MFREE_ERR_NULL, "connectivity or boundary nodes are NULL");
  if (!g) throw Error(MFREE_ERR_NULL, "boundary value function is NULL");
  if (mask <= 0 || mask >= (1 << ncomp_)) throw Error(MFREE_ERR_ARG, "component mask selects no valid component");
  if (fe_.npe && fe_.npe != npe)
    throw Error(MFREE_ERR_ARG, "the layer already has elements with " + std::to_string(fe_.npe) +
                                   " nodes; every call must use the same element type");
  // (the orientation check below reads the positions)
  if (!ps_->pos_data()) throw Error(MFREE_ERR_STATE, "the particle set has no positions");
  const int32_t n = ps_->num_owned();
  // Calls accumulate: elements of every call form one layer (the blending sees all of
  // them) and each call's boundary nodes get its own component mask, so symmetry lines
  // with different constrained components are one layer.
  FeLayer fe = fe_;
  fe.npe = npe;
  const size_t first = fe.conn.size();
  fe.conn.insert(fe.conn.end(), conn, conn + static_cast<size_t>(nelem) * npe);
  fe.on_gu.resize(ps_->size(), 0);
  fe.in_layer.resize(ps_->size(), 0);
  for (int32_t k = 0; k < nelem * npe; ++k) {
    if (conn[k] < 0 || conn[k] >= n)
      throw Error(MFREE_ERR_INPUT, "element " + std::to_string(k / npe) + " refers to particle " +
                                       std::to_string(conn[k]) + ", not an owned particle");
    fe.in_layer[conn[k]] = 1;
  }
  for (int32_t k = 0; k < ngu; ++k) {
    if (gu[k] < 0 || gu[k] >= n || !fe.in_layer[gu[k]])
      throw Error(MFREE_ERR_INPUT, "essential-boundary node " + std::to_string(gu[k]) + " is not a layer node");
    fe.on_gu[gu[k]] = 1;
  }
  // orientation: positive Jacobian at every corner (counter-clockwise, not degenerate)
  for (int32_t e = 0; e < nelem; ++e) {
    const int32_t *c = &fe.conn[first + static_cast<size_t>(e) * npe];
    double xmin[2] = {1e300, 1e300}, xmax[2] = {-1e300, -1e300};
    for (int a = 0; a < npe; ++a) {
      const int32_t i = c[a], j = c[(a + 1) % npe], k = c[(a + npe - 1) % npe];
      const double ax = ps_->x(j, 0) - ps_->x(i, 0), ay = ps_->x(j, 1) - ps_->x(i, 1);
      const double bx = ps_->x(k, 0) - ps_->x(i, 0), by = ps_->x(k, 1) - ps_->x(i, 1);
      if (!(ax * by - ay * bx > 0.0))
        throw Error(MFREE_ERR_INPUT, "layer element " + std::to_string(e) + " of this call" +
                                         " is inverted or degenerate (nodes must run counter-clockwise)");
      for (int d = 0; d < 2; ++d) {
        xmin[d] = std::min(xmin[d], ps_->x(i, d));
        xmax[d] = std::max(xmax[d], ps_->x(i, d));
      }
    }
    for (int d = 0; d < 2; ++d) {
      const double pad = 1e-10 * (xmax[d] - xmin[d] + 1.0);
      fe.bmin.push_back(xmin[d] - pad);
      fe.bmax.push_back(xmax[d] + pad);
    }
  }
  NodeSet ns;
  ns.kind = 3;
  ns.nodes.assign(gu, gu + ngu);
  ns.mask = mask;
  ns.fn = g;
  ns.user = user;
  nsets_.reserve(nsets_.size() + 1);  // the last allocation: nothing below may fail
  fe_ = std::move(fe);
  nsets_.push_back(std::move(ns));
  setup_done_ = false;
}

bool Assembler::fe_shape(int32_t e, const double *x, double *N, double *dN) const {
  const int npe = fe_.npe;
  const int32_t *c = &fe_.conn[static_cast<size_t>(e) * npe];
  if (x[0] < fe_.bmin[2 * e] || x[0] > fe_.bmax[2 * e] || x[1] < fe_.bmin[2 * e + 1] || x[1] > fe_.bmax[2 * e + 1])
    return false;
  double X[4][2];
  for (int a = 0; a < npe; ++a)
    for (int d = 0; d < 2; ++d) X[a][d] = ps_->x(c[a], d);
  const double tol = 1e-10;
  if (npe == 3) {
    const double j00 = X[1][0] - X[0][0], j01 = X[2][0] - X[0][0], j10 = X[1][1] - X[0][1], j11 = X[2][1] - X[0][1];
    const double det = j00 * j11 - j01 * j10;
    const double rx = x[0] - X[0][0], ry = x[1] - X[0][1];
    const double l1 = (j11 * rx - j01 * ry) / det, l2 = (-j10 * rx + j00 * ry) / det;
    if (l1 < -tol || l2 < -tol || l1 + l2 > 1.0 + tol) return false;
    N[0] = 1.0 - l1 - l2;
    N[1] = l1;
    N[2] = l2;
    // dl1/dx = (j11, -j01)/det, dl2/dx = (-j10, j00)/det
    dN[2] = j11 / det;
    dN[3] = -j01 / det;
    dN[4] = -j10 / det;
    dN[5] = j00 / det;
    dN[0] = -dN[2] - dN[4];
    dN[1] = -dN[3] - dN[5];
    return true;
  }
  static const double xi[4] = {-1, 1, 1, -1}, eta[4] = {-1, -1, 1, 1};
  double u = 0.0, v = 0.0, J[2][2] = {{0, 0}, {0, 0}};
  for (int it = 0; it < 30; ++it) {
    double f[2] = {-x[0], -x[1]};
    J[0][0] = J[0][1] = J[1][0] = J[1][1] = 0.0;
    for (int a = 0; a < 4; ++a) {
      const double Na = 0.25 * (1 + xi[a] * u) * (1 + eta[a] * v);
      const double du = 0.25 * xi[a] * (1 + eta[a] * v), dv = 0.25 * eta[a] * (1 + xi[a] * u);
      for (int d = 0; d < 2; ++d) {
        f[d] += Na * X[a][d];
        J[d][0] += du * X[a][d];
        J[d][1] += dv * X[a][d];
      }
    }
    const double det = J[0][0] * J[1][1] - J[0][1] * J[1][0];
    const double su = (J[1][1] * f[0] - J[0][1] * f[1]) / det, sv = (-J[1][0] * f[0] + J[0][0] * f[1]) / det;
    u -= su;
    v -= sv;
    if (std::fabs(su) + std::fabs(sv) < 1e-15) break;
  }
  if (std::fabs(u) > 1.0 + tol || std::fabs(v) > 1.0 + tol) return false;
  J[0][0] = J[0][1] = J[1][0] = J[1][1] = 0.0;
  double dNu[4], dNv[4];
  for (int a = 0; a < 4; ++a) {
    N[a] = 0.25 * (1 + xi[a] * u) * (1 + eta[a] * v);
    dNu[a] = 0.25 * xi[a] * (1 + eta[a] * v);
    dNv[a] = 0.25 * eta[a] * (1 + xi[a] * u);
    for (int d = 0; d < 2; ++d) {
      J[d][0] += dNu[a] * X[a][d];
      J[d][1] += dNv[a] * X[a][d];
    }
  }
  const double det = J[0][0] * J[1][1] - J[0][1] * J[1][0];
  for (int a = 0; a < 4; ++a) {  // grad N = J^-T (dN/du, dN/dv)
    dN[2 * a] = (J[1][1] * dNu[a] - J[1][0] * dNv[a]) / det;
    dN[2 * a + 1] = (-J[0][1] * dNu[a] + J[0][0] * dNv[a]) / det;
  }
  return true;
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

// Paper 000 eqs 100-105: in the layer, Phi0_I = (1 - r) N_I + r Phi_I with r = 3R^2 - 2R^3,
// R = sum of the FE functions of the interface nodes; at nodal quadrature points on the
// essential boundary the functions are the FE ones, the node's volume split among its
// elements (the Figure 2 procedure).
void Assembler::blend_qtable(QTable &t, const HVec<double> *pts) const {
  const int npe = fe_.npe;
  const int32_t nelem = static_cast<int32_t>(fe_.conn.size() / npe);
  QTable out;
  out.rowptr.assign(1, 0);
  double N[4], dN[8];
  std::vector<int32_t> cols;
  std::vector<double> val, grad, sgrad;
  const bool has_s = !t.sgrad.empty();
  int32_t cur = 0;  // the input point being pushed
  auto push = [&](double w) {
    out.w.push_back(w);
    out.x.insert(out.x.end(), t.x.begin() + 2 * static_cast<size_t>(cur), t.x.begin() + 2 * static_cast<size_t>(cur) + 2);
    out.cols.insert(out.cols.end(), cols.begin(), cols.end());
    out.val.insert(out.val.end(), val.begin(), val.end());
    out.grad.insert(out.grad.end(), grad.begin(), grad.end());
    if (has_s) out.sgrad.insert(out.sgrad.end(), sgrad.begin(), sgrad.end());
    out.rowptr.push_back(static_cast<int64_t>(out.cols.size()));
  };
  for (int32_t q = 0; q < t.size(); ++q) {
    cur = q;
    const int64_t k0 = t.rowptr[q], k1 = t.rowptr[q + 1];
    cols.assign(t.cols.begin() + k0, t.cols.begin() + k1);
    val.assign(t.val.begin() + k0, t.val.begin() + k1);
    grad.assign(t.grad.begin() + 2 * k0, t.grad.begin() + 2 * k1);
    if (has_s) sgrad.assign(t.sgrad.begin() + 2 * k0, t.sgrad.begin() + 2 * k1);
    if (!pts) {
      if (!fe_.on_gu[q]) {
        push(t.w[q]);
        continue;
      }
      std::vector<int32_t> elems;
      for (int32_t e = 0; e < nelem; ++e)
        for (int a = 0; a < npe; ++a)
          if (fe_.conn[static_cast<size_t>(e) * npe + a] == q) elems.push_back(e);
      const double x[2] = {ps_->x(q, 0), ps_->x(q, 1)};
      for (int32_t e : elems) {
        fe_shape(e, x, N, dN);
        cols.clear();
        val.clear();
        grad.clear();
        for (int a = 0; a < npe; ++a) {
          cols.push_back(fe_.conn[static_cast<size_t>(e) * npe + a]);
          val.push_back(N[a]);
          grad.push_back(dN[2 * a]);
          grad.push_back(dN[2 * a + 1]);
        }
        if (has_s) sgrad = grad;
        push(t.w[q] / static_cast<double>(elems.size()));
      }
      continue;
    }
    const double x[2] = {(*pts)[2 * static_cast<size_t>(q)], (*pts)[2 * static_cast<size_t>(q) + 1]};
    int32_t e = 0;
    for (; e < nelem; ++e)
      if (fe_shape(e, x, N, dN)) break;
    if (e == nelem) {
      push(t.w[q]);
      continue;
    }
    const int32_t *c = &fe_.conn[static_cast<size_t>(e) * npe];
    double R = 0.0, gR[2] = {0, 0};
    for (int a = 0; a < npe; ++a)
      if (!fe_.on_gu[c[a]]) {
        R += N[a];
        gR[0] += dN[2 * a];
        gR[1] += dN[2 * a + 1];
      }
    const double r = 3 * R * R - 2 * R * R * R, dr = 6 * R - 6 * R * R;
    const double gr[2] = {dr * gR[0], dr * gR[1]};
    for (size_t k = 0; k < cols.size(); ++k) {  // r Phi
      const double phi = val[k];
      for (int d = 0; d < 2; ++d) grad[2 * k + d] = gr[d] * phi + r * grad[2 * k + d];
      if (has_s)
        for (int d = 0; d < 2; ++d) sgrad[2 * k + d] = gr[d] * phi + r * sgrad[2 * k + d];
      val[k] = r * phi;
    }
    for (int a = 0; a < npe; ++a) {  // + (1 - r) N
      size_t k = 0;
      while (k < cols.size() && cols[k] != c[a]) ++k;
      if (k == cols.size()) {
        cols.push_back(c[a]);
        val.push_back(0.0);
        grad.push_back(0.0);
        grad.push_back(0.0);
        if (has_s) sgrad.push_back(0.0), sgrad.push_back(0.0);
      }
      val[k] += (1 - r) * N[a];
      for (int d = 0; d < 2; ++d) grad[2 * k + d] += -gr[d] * N[a] + (1 - r) * dN[2 * a + d];
      if (has_s)
        for (int d = 0; d < 2; ++d) sgrad[2 * k + d] += -gr[d] * N[a] + (1 - r) * dN[2 * a + d];
    }
    push(t.w[q]);
  }
  t = std::move(out);
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
  if (fe_.npe) {
    blend_qtable(qtrial_, nodal ? nullptr : &qx_);
    if (test_q_) blend_qtable(qtest_, nodal ? nullptr : &qx_);
  }
  // boundary point sets: the same blending, so that boundary terms inside the layer use
  // the layer's functions
  ps_test_.assign(psets_.size(), QTable());
  ps_trial_.assign(psets_.size(), QTable());
  for (size_t i = 0; i < psets_.size(); ++i) {
    PointSet &s = *psets_[i];
    if (s.test) {
      fill_qtable(*s.test, ps_test_[i], &s.w, &s.x);
      if (fe_.npe) blend_qtable(ps_test_[i], &s.x);
    }
    if (s.trial) {
      fill_qtable(*s.trial, ps_trial_[i], &s.w, &s.x);
      if (fe_.npe) blend_qtable(ps_trial_[i], &s.x);
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
    correct_test_gradients(qtest_, ps_test_[i], psets_[i]->normals);
  }
}

// Chen, Hillman and Rueter (IJNME 93, 2013): with the corrected gradients
// grad Psi_J + C_J p(x) at the quadrature points of J's support, p = (1, (x - x_J) / h_J),
// the quadrature satisfies the divergence theorem for Psi_J times every p_k,
//   sum_q (grad Psi_J p_k + Psi_J grad p_k)(x_q) w_q = sum_b (Psi_J p_k n)(x_b) w_b,
// so that trial functions that reproduce linear fields pass the linear patch test
// whatever the quadrature (nodal, or the layer's strip sampled at its two edges), and
// the integration error of linear stress fields is removed too. A support whose moment
// matrix is singular (too few points) gets the constant correction only.
void Assembler::correct_test_gradients(QTable &t, const QTable &b, const HVec<double> &normals) const {
  const int dim = dim_, np = 1 + dim;
  const int32_t n = ps_->size();
  std::vector<double> M(static_cast<size_t>(n) * np * np, 0.0), R(static_cast<size_t>(n) * np * dim, 0.0);
  auto basis = [&](int32_t J, const double *x, double *P) {
    const double h = ps_->h(J);
    P[0] = 1.0;
    for (int d = 0; d < dim; ++d) P[1 + d] = (x[d] - ps_->x(J, d)) / h;
  };
  double P[4];
  for (int32_t p = 0; p < b.size(); ++p)
    for (int64_t a = b.rowptr[p]; a < b.rowptr[p + 1]; ++a) {
      const int32_t J = b.cols[a];
      basis(J, &b.x[static_cast<size_t>(p) * dim], P);
      for (int k = 0; k < np; ++k)
        for (int i = 0; i < dim; ++i)
          R[(static_cast<size_t>(J) * np + k) * dim + i] +=
              b.w[p] * b.val[a] * P[k] * normals[static_cast<size_t>(p) * dim + i];
    }
  for (int32_t q = 0; q < t.size(); ++q)
    for (int64_t a = t.rowptr[q]; a < t.rowptr[q + 1]; ++a) {
      const int32_t J = t.cols[a];
      const double w = t.w[q], hinv = 1.0 / ps_->h(J);
      basis(J, &t.x[static_cast<size_t>(q) * dim], P);
      double *m = &M[static_cast<size_t>(J) * np * np];
      for (int k = 0; k < np; ++k)
        for (int l = 0; l < np; ++l) m[k * np + l] += w * P[k] * P[l];
      for (int k = 0; k < np; ++k)
        for (int i = 0; i < dim; ++i)
          R[(static_cast<size_t>(J) * np + k) * dim + i] -=
              w * (t.grad[a * dim + i] * P[k] + (k == 1 + i ? t.val[a] * hinv : 0.0));
    }
  // C_J (np x dim) = M_J^-1 R_J by Gaussian elimination with partial pivoting
  std::vector<double> Cc(static_cast<size_t>(n) * np * dim, 0.0);
  for (int32_t J = 0; J < n; ++J) {
    double A[4][4], B[4][3];
    const double *m = &M[static_cast<size_t>(J) * np * np], *r = &R[static_cast<size_t>(J) * np * dim];
    if (!(m[0] > 0.0)) continue;
    int use = np;
    for (int k = 0; k < np; ++k)
      for (int l = 0; l < np; ++l) A[k][l] = m[k * np + l];
    for (int k = 0; k < np; ++k)
      for (int i = 0; i < dim; ++i) B[k][i] = r[k * dim + i];
    for (int c = 0; c < use; ++c) {
      int piv = c;
      for (int k = c + 1; k < use; ++k)
        if (std::fabs(A[k][c]) > std::fabs(A[piv][c])) piv = k;
      if (std::fabs(A[piv][c]) < 1e-8 * m[0]) {  // singular: the constant correction only
        use = 1;
        A[0][0] = m[0];
        for (int i = 0; i < dim; ++i) B[0][i] = r[i];
        break;
      }
      std::swap(A[c], A[piv]);
      std::swap(B[c], B[piv]);
      for (int k = c + 1; k < use; ++k) {
        const double f = A[k][c] / A[c][c];
        for (int l = c; l < use; ++l) A[k][l] -= f * A[c][l];
        for (int i = 0; i < dim; ++i) B[k][i] -= f * B[c][i];
      }
    }
    double *cj = &Cc[static_cast<size_t>(J) * np * dim];
    for (int k = use - 1; k >= 0; --k)
      for (int i = 0; i < dim; ++i) {
        double v = B[k][i];
        for (int l = k + 1; l < use; ++l) v -= A[k][l] * cj[l * dim + i];
        cj[k * dim + i] = v / A[k][k];
      }
  }
  for (int32_t q = 0; q < t.size(); ++q)
    for (int64_t a = t.rowptr[q]; a < t.rowptr[q + 1]; ++a) {
      const int32_t J = t.cols[a];
      basis(J, &t.x[static_cast<size_t>(q) * dim], P);
      const double *cj = &Cc[static_cast<size_t>(J) * np * dim];
      for (int i = 0; i < dim; ++i)
        for (int k = 0; k < np; ++k) t.grad[a * dim + i] += cj[k * dim + i] * P[k];
    }
  t.sgrad.clear();  // particles-only test functions are rejected by set_consistent_integration
}

double Assembler::mean_h() const {
  double s = 0.0;
  const int32_t n = ps_->size();
  for (int32_t i = 0; i < n; ++i) s += ps_->h(i);
  return n ? s / n : 1.0;
}

ApproxConfig Assembler::values_config(const ApproxConfig &c) const {
  // Particles-only methods correct derivatives, not values: loads and boundary values
  // use the method's own function approximation (paper 000 leaves this open, section
  // 5.5 of the spec note). Symmetrised SPH and Johnson-Beissel keep SPH's kernel
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
      const double f = u < 1.0 ? 1.0 - 1.5 * u * u + 0.75 * u * u * u : 0.25 * (2.0 - u) * (2.0 - u) * (2.0 - u);
      const double w = f / std::pow(hj, dim_);
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

void Assembler::material_matrix(double *D, int &nv) const {
  const double E = young_, nu = poisson_;
  nv = dim_ == 2 ? 3 : 6;
  std::fill(D, D + 36, 0.0);
  if (dim_ == 2) {
    const bool stress = form_ == MFREE_FORM_ELASTICITY_PLANE_STRESS || form_ == MFREE_FORM_COLLOCATION_PLANE_STRESS;
    if (stress) {
      const double f = E / (1.0 - nu * nu);
      D[0] = f; D[1] = f * nu; D[3] = f * nu; D[4] = f; D[8] = f * (1.0 - nu) / 2.0;
    } else {
      const double f = E / ((1.0 + nu) * (1.0 - 2.0 * nu));
      D[0] = f * (1.0 - nu); D[1] = f * nu; D[3] = f * nu; D[4] = f * (1.0 - nu);
      D[8] = f * (1.0 - 2.0 * nu) / 2.0;
    }
    // row-major 3x3 stored with stride 3
    return;
  }
  const double lam = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), mu = E / (2.0 * (1.0 + nu));
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) D[a * 6 + b] = lam + (a == b ? 2.0 * mu : 0.0);
  for (int a = 3; a < 6; ++a) D[a * 6 + a] = mu;
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

void Assembler::assemble_matrix(SparseMatrix &K) const {
  if (!setup_done_) throw Error(MFREE_ERR_STATE, "the assembler is not set up");
  if (K.rows() != ndofs_ || K.rowptr() != rowptr_ || K.colidx() != cols_)
    K.set_pattern(ndofs_, ndofs_, rowptr_, cols_);
  std::vector<double> &v = K.values_mut();
  std::fill(v.begin(), v.end(), 0.0);
  const int nc = ncomp_, dim = dim_;
  const int32_t nbase = ps_->size() * nc;
  auto at = [&](int32_t r, int32_t c) -> double & {
    const int64_t k = K.find(r, c);
    if (k < 0) throw Error(MFREE_ERR_INTERNAL, "assembly entry outside the pattern");
    return v[k];
  };
  const Approximant &trial = *trial_q_;
  double D[36];
  int nv = 0;
  if (elasticity()) material_matrix(D, nv);
  const int dstride = dim == 2 ? 3 : 6;

  if (collocation()) {
    const double E = young_, nu = poisson_;
    double lam = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    const double mu = E / (2.0 * (1.0 + nu));
    if (form_ == MFREE_FORM_COLLOCATION_PLANE_STRESS) lam = 2.0 * lam * mu / (lam + 2.0 * mu);
    const int nh = hessian_size(dim);
    const auto &H = trial.hessians();
    for (int32_t J = 0; J < trial.num_sites(); ++J)
      for (int64_t k = trial.rowptr()[J]; k < trial.rowptr()[J + 1]; ++k) {
        const int32_t K2 = trial.cols()[k];
        double lap = 0.0;
        for (int d = 0; d < dim; ++d) lap += H[k * nh + hessian_index(dim, d, d)];
        if (form_ == MFREE_FORM_COLLOCATION_LAPLACE) {
          if (row_kind_[J] == 0) at(J, K2) += -coef_ * lap;
          continue;
        }
        for (int a = 0; a < nc; ++a) {
          if (row_kind_[J * nc + a] != 0) continue;
          for (int b = 0; b < nc; ++b)
            at(J * nc + a, K2 * nc + b) +=
                -(mu * lap * (a == b ? 1.0 : 0.0) + (lam + mu) * H[k * nh + hessian_index(dim, a, b)]);
        }
      }
  } else if (form_ == MFREE_FORM_MASS || form_ == MFREE_FORM_MASS_LUMPED) {
    const QTable &qa = qtrial_, &qb = test_table();
    const auto &Pv = qa.val, &Tv = qb.val;
    for (int32_t q : qorder_) {
      const double w = qa.w[q];
      for (int64_t a = qb.rowptr[q]; a < qb.rowptr[q + 1]; ++a)
        for (int64_t b = qa.rowptr[q]; b < qa.rowptr[q + 1]; ++b) {
          const int32_t J = qb.cols[a], K2 = qa.cols[b];
          if (row_kind_[J] != 0) continue;
          const double m = w * coef_ * Tv[a] * Pv[b];
          if (form_ == MFREE_FORM_MASS) at(J, K2) += m;
          else at(J, J) += m;
        }
    }
  } else {
    // Row by row (gather): for each test node J, the quadrature points its test
    // function sees (the transpose of the test table), with the positions of J's
    // columns in a scatter array, so that no entry is searched for.
    const QTable &qa = qtrial_, &qb = test_table();
    const auto &Pg = qa.grad, &Tg = qb.grad;
    const auto &Ps = qa.sgrad.empty() ? qa.grad : qa.sgrad, &Ts = qb.sgrad.empty() ? qb.grad : qb.sgrad;
    const int32_t nn = ps_->size();
    std::vector<int64_t> tp(static_cast<size_t>(nn) + 1, 0), ta(qb.cols.size());
    std::vector<int32_t> tq(qb.cols.size());
    for (int32_t J : qb.cols) ++tp[static_cast<size_t>(J) + 1];
    for (int32_t J = 0; J < nn; ++J) tp[J + 1] += tp[J];
    {
      // each row's quadrature points in the canonical order, so that every entry is
      // summed in the same order whatever the local numbering
      std::vector<int64_t> next(tp.begin(), tp.end() - 1);
      for (int32_t q : qorder_)
        for (int64_t a = qb.rowptr[q]; a < qb.rowptr[q + 1]; ++a) {
          const int64_t k = next[qb.cols[a]]++;
          tq[k] = q;
          ta[k] = a;
        }
    }
    std::vector<int64_t> pos(nn, -1);
    auto offset = [&](int32_t K2) {
      if (pos[K2] < 0) throw Error(MFREE_ERR_INTERNAL, "assembly entry outside the pattern");
      return pos[K2];
    };
    for (int32_t J = 0; J < nn; ++J) {
      if (tp[J] == tp[J + 1]) continue;
      const int64_t base = rowptr_[static_cast<size_t>(J) * nc];
      for (int32_t i = 0; i < node_deg_[J]; ++i) pos[cols_[base + static_cast<int64_t>(i) * nc] / nc] = int64_t{i} * nc;
      for (int64_t t = tp[J]; t < tp[J + 1]; ++t) {
        const int32_t q = tq[t];
        const int64_t a = ta[t], b0 = qa.rowptr[q], b1 = qa.rowptr[q + 1];
        const double w = qa.w[q];
        if (form_ == MFREE_FORM_LAPLACE) {
          if (row_kind_[J] != 0) continue;
          for (int64_t b = b0; b < b1; ++b) {
            double dot = 0.0;
            for (int d = 0; d < dim; ++d) dot += Tg[a * dim + d] * Pg[b * dim + d];
            v[base + offset(qa.cols[b])] += w * coef_ * dot;
          }
          continue;
        }
        double BJ[6][3], BJD[3][6];  // BJD = B_J^T D
        strain_rows(dim, &Tg[a * dim], &Ts[a * dim], BJ);
        for (int c = 0; c < nc; ++c)
          for (int t2 = 0; t2 < nv; ++t2) {
            double s = 0.0;
            for (int u = 0; u < nv; ++u) s += BJ[u][c] * D[u * dstride + t2];
            BJD[c][t2] = s;
          }
        for (int64_t b = b0; b < b1; ++b) {
          double BK[6][3];
          strain_rows(dim, &Pg[b * dim], &Ps[b * dim], BK);
          const int64_t o = offset(qa.cols[b]);
          for (int c = 0; c < nc; ++c) {
            if (row_kind_[J * nc + c] != 0) continue;
            double *row = &v[rowptr_[J * nc + c] + o];
            for (int e = 0; e < nc; ++e) {
              double s = 0.0;
              for (int t2 = 0; t2 < nv; ++t2) s += BJD[c][t2] * BK[t2][e];
              row[e] += w * s;
            }
          }
        }
      }
      for (int32_t i = 0; i < node_deg_[J]; ++i) pos[cols_[base + static_cast<int64_t>(i) * nc] / nc] = -1;
    }
    // penalty, Nitsche and Lagrange terms
    for (size_t si = 0; si < psets_.size(); ++si) {
      auto &s = psets_[si];
      const QView ts{ps_test_[si]}, tr{ps_trial_[si]};
      if (s->kind == 2) {
        for (int32_t p = 0; p < tr.num_sites(); ++p)
          for (int64_t a = ts.rowptr()[p]; a < ts.rowptr()[p + 1]; ++a)
            for (int64_t b = tr.rowptr()[p]; b < tr.rowptr()[p + 1]; ++b)
              for (int c = 0; c < nc; ++c) {
                const int32_t J = ts.cols()[a];
                if (!(s->mask & (1 << c)) || row_kind_[J * nc + c] != 0) continue;
                at(J * nc + c, tr.cols()[b] * nc + c) +=
                    penalty_ * s->w[p] * ts.values()[a] * tr.values()[b];
              }
      } else if (s->kind == 4) {
        for (int32_t p = 0; p < tr.num_sites(); ++p) {
          const double w = s->w[p], *n = &s->normals[static_cast<size_t>(p) * dim];
          for (int64_t a = ts.rowptr()[p]; a < ts.rowptr()[p + 1]; ++a) {
            const int32_t J = ts.cols()[a];
            const double psi = ts.values()[a];
            double TJ[3][3];
            traction_row(&ts.gradients()[a * dim], n, TJ);
            for (int64_t b = tr.rowptr()[p]; b < tr.rowptr()[p + 1]; ++b) {
              const int32_t K2 = tr.cols()[b];
              const double phi = tr.values()[b];
              double TK[3][3];
              traction_row(&tr.gradients()[b * dim], n, TK);
              for (int c = 0; c < nc; ++c) {
                if (!(s->mask & (1 << c))) continue;
                // consistency: -psi (sigma(u) n)_c in row (J, c)
                if (row_kind_[J * nc + c] == 0)
                  for (int e = 0; e < nc; ++e) at(J * nc + c, K2 * nc + e) += -w * psi * TK[c][e];
                // symmetry: -(sigma(psi e_a) n)_c u_c in rows (J, a)
                for (int aa = 0; aa < nc; ++aa)
                  if (row_kind_[J * nc + aa] == 0) at(J * nc + aa, K2 * nc + c) += -w * TJ[c][aa] * phi;
                // stabilisation
                if (row_kind_[J * nc + c] == 0) at(J * nc + c, K2 * nc + c) += w * nitsche_ * psi * phi;
              }
            }
          }
        }
      } else if (s->kind == 3) {
        int32_t m = nbase + s->first_multiplier;
        for (int32_t p = 0; p < tr.num_sites(); ++p)
          for (int c = 0; c < nc; ++c) {
            if (!(s->mask & (1 << c))) continue;
            for (int64_t b = tr.rowptr()[p]; b < tr.rowptr()[p + 1]; ++b) {
              const int32_t d = tr.cols()[b] * nc + c;
              at(m, d) += tr.values()[b];
              if (row_kind_[d] == 0) at(d, m) += tr.values()[b];
            }
            ++m;
          }
      }
    }
  }
  // replaced rows at nodes
  const Approximant *tn = collocation() ? trial_q_.get() : trial_nodes_.get();
  for (int32_t dof = 0; dof < nbase; ++dof) {
    if (row_kind_[dof] == 0) continue;
    const int32_t J = dof / nc;
    const int c = dof % nc;
    const NodeSet &ns = nsets_[row_set_[dof]];
    if (row_kind_[dof] == 3) {
      at(dof, dof) += 1.0;
    } else if (row_kind_[dof] == 1 && tn->interpolating()) {
      at(dof, dof) += 1.0;  // Kronecker delta (MPFEM, 004 Sect. 2.4): u_J = g(x_J) exactly
    } else if (row_kind_[dof] == 1) {
      for (int64_t b = tn->rowptr()[J]; b < tn->rowptr()[J + 1]; ++b)
        at(dof, tn->cols()[b] * nc + c) += tn->values()[b];
    } else {
      const double *nrm = &ns.normals[static_cast<size_t>(row_node_[dof]) * dim];
      const auto &G = trial_q_->gradients();
      for (int64_t b = trial_q_->rowptr()[J]; b < trial_q_->rowptr()[J + 1]; ++b) {
        const int32_t K2 = trial_q_->cols()[b];
        if (!elasticity()) {
          double s = 0.0;
          for (int d = 0; d < dim; ++d) s += nrm[d] * G[b * dim + d];
          at(dof, K2) += coef_ * s;
          continue;
        }
        double B[6][3];
        strain_rows(dim, &G[b * dim], B);
        for (int e = 0; e < nc; ++e) {
          double s = 0.0;  // (sigma n)_c = sum_d sigma_cd n_d, sigma = D B u
          for (int d = 0; d < dim; ++d) {
            const int vr = voigt(dim, c, d);
            for (int t = 0; t < nv; ++t) s += nrm[d] * D[vr * dstride + t] * B[t][e];
          }
          at(dof, K2 * nc + e) += s;
        }
      }
    }
  }
}

void Assembler::assemble_rhs(double *f) const {
  if (!setup_done_) throw Error(MFREE_ERR_STATE, "the assembler is not set up");
  std::fill(f, f + ndofs_, 0.0);
  const int nc = ncomp_, dim = dim_;
  const int32_t nbase = ps_->size() * nc;
  double val[3], x[3] = {0, 0, 0};
  if (collocation()) {
    if (body_)
      for (int32_t J = 0; J < ps_->num_owned(); ++J) {
        for (int d = 0; d < dim; ++d) x[d] = ps_->x(J, d);
        body_(body_user_, x, val);
        for (int c = 0; c < nc; ++c)
          if (row_kind_[J * nc + c] == 0) f[J * nc + c] = val[c];
      }
  } else if (!mass()) {
    if (body_ && load_q_) {
      const Approximant &L = *load_q_;
      for (int32_t q : qorder_) {
        const double w = quad_kind_ == 0 ? ps_->volume(q) : qw_[q];
        for (int d = 0; d < dim; ++d) x[d] = quad_kind_ == 0 ? ps_->x(q, d) : qx_[static_cast<size_t>(q) * dim + d];
        body_(body_user_, x, val);
        for (int64_t a = L.rowptr()[q]; a < L.rowptr()[q + 1]; ++a)
          for (int c = 0; c < nc; ++c) f[L.cols()[a] * nc + c] += w * L.values()[a] * val[c];
      }
    }
    for (size_t si = 0; si < psets_.size(); ++si) {
      auto &s = psets_[si];
      if (s->kind == 5) continue;  // boundary of the consistent integration: no load
      const QView ts{ps_test_[si]};
      const int32_t np = static_cast<int32_t>(s->w.size());
      int32_t m = nbase + s->first_multiplier;
      for (int32_t p = 0; p < np; ++p) {
        for (int d = 0; d < dim; ++d) x[d] = s->x[static_cast<size_t>(p) * dim + d];
        s->fn(s->user, x, val);
        if (s->kind == 4) {
          const double *n = &s->normals[static_cast<size_t>(p) * dim];
          for (int64_t a = ts.rowptr()[p]; a < ts.rowptr()[p + 1]; ++a) {
            const int32_t J = ts.cols()[a];
            double TJ[3][3];
            traction_row(&ts.gradients()[a * dim], n, TJ);
            for (int c = 0; c < nc; ++c) {
              if (!(s->mask & (1 << c))) continue;
              for (int aa = 0; aa < nc; ++aa) f[J * nc + aa] += -s->w[p] * TJ[c][aa] * val[c];
              f[J * nc + c] += s->w[p] * nitsche_ * ts.values()[a] * val[c];
            }
          }
        } else if (s->kind == 1 || s->kind == 2) {
          const double fac = s->kind == 1 ? s->w[p] : penalty_ * s->w[p];
          for (int64_t a = ts.rowptr()[p]; a < ts.rowptr()[p + 1]; ++a)
            for (int c = 0; c < nc; ++c) {
              if (s->kind == 2 && !(s->mask & (1 << c))) continue;
              f[ts.cols()[a] * nc + c] += fac * ts.values()[a] * val[c];
            }
        } else if (s->kind == 3) {
          for (int c = 0; c < nc; ++c)
            if (s->mask & (1 << c)) f[m++] = val[c];
        }
      }
    }
  }
  // replaced rows
  for (int32_t dof = 0; dof < nbase; ++dof) {
    if (row_kind_[dof] == 0) continue;
    const int32_t J = dof / nc;
    const int c = dof % nc;
    const NodeSet &ns = nsets_[row_set_[dof]];
    for (int d = 0; d < dim; ++d) x[d] = ps_->x(J, d);
    ns.fn(ns.user, x, val);
    f[dof] = val[c];
  }
  // rows replaced in the form part were zeroed in the matrix; their loads must be too
}

}  // namespace mfree
