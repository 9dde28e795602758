// Tractions: at boundary points, on segments (2D), on facets (3D), and traction rows at
// collocation nodes.
#include "core/discretize/assembler.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/base/quadrature.hpp"
#include "core/discretize/strain.hpp"

namespace mfree {

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

namespace {

// Gauss-Legendre rule (ngauss points) on each segment (a, b) of x (4 numbers each): points
// (2 per point) and weights.
void segment_rule(int32_t nseg, const double *x, int ngauss, std::vector<double> &pts, std::vector<double> &w) {
  std::vector<double> g, gw;
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
}

// Rule with ngauss^2 points on each triangle (a, b, c) of x (9 numbers each): points (3 per
// point) and weights.
void facet_rule(int32_t nfacet, const double *x, int ngauss, std::vector<double> &pts, std::vector<double> &w) {
  // Collapsed (Duffy) product rule: (xi, eta) = (u, v (1 - u)) with Gauss-Legendre in u
  // and v on [0, 1]; dA = |(b - a) x (c - a)| (1 - u) du dv.
  std::vector<double> g, gw;
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
}

}  // namespace

void Assembler::add_traction_segments(int32_t nseg, const double *x, int ngauss, mfree_field_fn t, void *user) {
  check_boundary_pieces(dim_, 2, nseg, x, 4, ngauss, "segment", "facets");
  std::vector<double> pts, w;
  segment_rule(nseg, x, ngauss, pts, w);
  add_traction(static_cast<int32_t>(w.size()), pts.data(), MFREE_LAYOUT_AOS, 2, w.data(), t, user);
}

void Assembler::add_traction_facets(int32_t nfacet, const double *x, int ngauss, mfree_field_fn t, void *user) {
  check_boundary_pieces(dim_, 3, nfacet, x, 9, ngauss, "facet", "segments");
  std::vector<double> pts, w;
  facet_rule(nfacet, x, ngauss, pts, w);
  add_traction(static_cast<int32_t>(w.size()), pts.data(), MFREE_LAYOUT_AOS, 3, w.data(), t, user);
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

}  // namespace mfree
