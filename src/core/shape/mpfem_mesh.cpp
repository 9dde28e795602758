// MPFEM's meshes: element connectivity over a particle set (copied or borrowed blocks)
// and its geometry at the current positions (paper 004 eqs 1-2).
#include "core/shape/mpfem.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/base/quadrature.hpp"

namespace mfree {

// ---------------------------------------------------------------------------------------
// Mesh

void Mesh::check_block(const Block &b, int32_t first) const {
  const int nn = element_nodes(b.type);
  const int32_t n = ps_->size();
  for (int32_t e = 0; e < b.n; ++e) {
    for (int k = 0; k < nn; ++k) {
      const int64_t v = static_cast<int64_t>(b.ptr[static_cast<int64_t>(e) * nn + k]) - b.base;
      if (v < 0 || v >= n) {
        std::ostringstream s;
        s << "element " << first + e << " (" << element_name(b.type) << ") node " << k
          << " is particle " << v + b.base << ", outside [" << b.base << ", " << n + b.base
          << ")";
        throw Error(MFREE_ERR_INPUT, s.str());
      }
      for (int l = 0; l < k; ++l)
        if (b.ptr[static_cast<int64_t>(e) * nn + l] == b.ptr[static_cast<int64_t>(e) * nn + k])
          throw Error(MFREE_ERR_INPUT, "element " + std::to_string(first + e) + " lists particle " +
                                           std::to_string(v + b.base) +
                                           " twice (degenerate element)");
    }
  }
}

void Mesh::add_elements(int type, int32_t n, const int32_t *conn, int base, int mem) {
  const int d = element_dim(type);
  if (d == 0) throw Error(MFREE_ERR_ARG, "unknown element type " + std::to_string(type));
  if (d != dim())
    throw Error(MFREE_ERR_MISMATCH, std::string(element_name(type)) + " elements are " +
                                        std::to_string(d) + "D but the mesh's particles are " +
                                        std::to_string(dim()) + "D (a mesh of mixed dimension)");
  if (n < 0) throw Error(MFREE_ERR_ARG, "element count " + std::to_string(n) + " is negative");
  if (base != 0 && base != 1)
    throw Error(MFREE_ERR_ARG, "index_base must be 0 or 1, got " + std::to_string(base));
  if (mem != MFREE_COPY && mem != MFREE_BORROW)
    throw Error(MFREE_ERR_ARG, "mem must be MFREE_COPY or MFREE_BORROW, got " + std::to_string(mem));
  if (!conn && n > 0) throw Error(MFREE_ERR_NULL, "connectivity pointer is NULL");
  Block b;
  b.type = type;
  b.n = n;
  b.base = base;
  b.ptr = conn;
  if (mem == MFREE_COPY) {
    check_block(b, num_elements());
    b.own.assign(conn, conn + static_cast<int64_t>(n) * element_nodes(type));
    b.ptr = b.own.data();
  }
  blocks_.push_back(std::move(b));
}

int32_t Mesh::num_elements() const {
  int64_t n = 0;
  for (const auto &b : blocks_) n += b.n;
  return static_cast<int32_t>(n);
}

void Mesh::connectivity(std::vector<int32_t> &type, std::vector<int32_t> &ptr,
                        std::vector<int32_t> &nodes) const {
  type.clear();
  ptr.assign(1, 0);
  nodes.clear();
  int32_t first = 0;
  for (const auto &b : blocks_) {
    if (b.own.empty()) check_block(b, first);
    const int nn = element_nodes(b.type);
    for (int32_t e = 0; e < b.n; ++e) {
      type.push_back(b.type);
      for (int k = 0; k < nn; ++k) nodes.push_back(b.ptr[static_cast<int64_t>(e) * nn + k] - b.base);
      ptr.push_back(static_cast<int32_t>(nodes.size()));
    }
    first += b.n;
  }
}

// ---------------------------------------------------------------------------------------
// Geometry and general shape functions

namespace {

// Whether every node of an element (n nodes X, 3 numbers each) lies on a face of its
// bounding box [L, H] of size `size`: an axis-aligned rectangle or brick.
bool is_box(const double *X, int n, int dim, const double *L, const double *H, double size) {
  for (int k = 0; k < n; ++k)
    for (int c = 0; c < dim; ++c) {
      const double v = X[3 * k + c];
      if (std::fabs(v - L[c]) > 1e-13 * size && std::fabs(v - H[c]) > 1e-13 * size) return false;
    }
  return true;
}

}  // namespace

void MeshGeometry::build(const Mesh &m) {
  const ParticleSet &ps = m.particles();
  // (a mesh may be set up before its particle set, which checks this at its own setup)
  if (!ps.pos_data()) throw Error(MFREE_ERR_STATE, "the mesh's particle set has no positions");
  dim = m.dim();
  m.connectivity(type, ptr, nodes);
  const int32_t ne = size();
  rel.assign(nodes.size() * 3, 0.0);
  lo.assign(static_cast<size_t>(ne) * 3, 0.0);
  hi.assign(static_cast<size_t>(ne) * 3, 0.0);
  center.assign(static_cast<size_t>(ne) * 3, 0.0);
  scale.assign(ne, 1.0);
  measure.assign(ne, 0.0);
  coef.assign(static_cast<size_t>(ne) * kMaxNodes * kMaxNodes, 0.0);
  box.assign(ne, 0);
  for (int32_t e = 0; e < ne; ++e) {
    const int n = nn(e), t = type[e];
    double *r = &rel[static_cast<size_t>(ptr[e]) * 3];
    for (int k = 0; k < n; ++k) {
      double d[3] = {0, 0, 0};
      for (int c = 0; c < dim; ++c)
        if (!std::isfinite(ps.x(nodes[ptr[e] + k], c)))
          throw Error(MFREE_ERR_INPUT, "element " + std::to_string(e) + ": node " +
                                           std::to_string(nodes[ptr[e] + k]) +
                                           " has a non-finite coordinate");
      if (k > 0) ps.displacement(nodes[ptr[e] + k], nodes[ptr[e]], d);
      for (int c = 0; c < 3; ++c) r[3 * k + c] = d[c];
    }
    double *L = &lo[3 * static_cast<size_t>(e)], *H = &hi[3 * static_cast<size_t>(e)],
           *C = &center[3 * static_cast<size_t>(e)];
    for (int c = 0; c < 3; ++c) {
      L[c] = H[c] = 0.0;
      for (int k = 0; k < n; ++k) {
        L[c] = std::min(L[c], r[3 * k + c]);
        H[c] = std::max(H[c], r[3 * k + c]);
      }
      C[c] = 0.5 * (L[c] + H[c]);
    }
    double size = 0.0;
    for (int c = 0; c < dim; ++c) size = std::max(size, H[c] - L[c]);
    scale[e] = size > 0.0 ? 0.5 * size : 1.0;
    // Jacobian checks: positive orientation and no degenerate corner.
    auto bad = [&](const std::string &why) {
      std::ostringstream s;
      s << "element " << e << " (" << element_name(t) << ", particles";
      for (int k = 0; k < n; ++k) s << " " << nodes[ptr[e] + k];
      s << ") " << why;
      throw Error(MFREE_ERR_INPUT, s.str());
    };
    const double tol = 1e-12;
    if (t == MFREE_ELEMENT_LINE2) {
      measure[e] = r[3];
      if (!(r[3] > tol * std::fabs(ps.x(nodes[ptr[e]], 0))) || r[3] <= 0.0)
        bad("has length " + std::to_string(r[3]) + " <= 0 (inverted or degenerate: x_1 < x_2 required)");
      box[e] = 1;
    } else if (t == MFREE_ELEMENT_TRI3) {
      const double a = 0.5 * (r[3] * r[7] - r[4] * r[6]);
      measure[e] = a;
      if (!(a > tol * size * size))
        bad("has signed area " + std::to_string(a) + " <= 0 (inverted, clockwise or degenerate)");
    } else if (t == MFREE_ELEMENT_QUAD4) {
      for (int k = 0; k < 4; ++k) {
        if (!(corner_cross(r, 4, k) > tol * size * size))
          bad("has Jacobian <= 0 at corner " + std::to_string(k) +
              " (inverted, clockwise, non-convex or degenerate)");
      }
      double a = 0.0;
      for (int k = 0; k < 4; ++k) {
        const double *p = r + 3 * k, *pn = r + 3 * ((k + 1) % 4);
        a += 0.5 * (p[0] * pn[1] - p[1] * pn[0]);
      }
      measure[e] = a;
      box[e] = is_box(r, 4, 2, L, H, size);
    } else {  // HEX8
      for (int k = 0; k < 8; ++k) {
        double x[3], det;
        iso_map(t, r, reference_corner(t, k), x, det);
        if (!(det > tol * size * size * size))
          bad("has Jacobian <= 0 at corner " + std::to_string(k) + " (inverted or degenerate)");
      }
      std::vector<double> xg, wg;
      gauss_legendre(2, xg, wg);
      double v = 0.0;
      for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j)
          for (int k = 0; k < 2; ++k) {
            const double rr[3] = {xg[i], xg[j], xg[k]};
            double x[3], det;
            iso_map(t, r, rr, x, det);
            v += wg[i] * wg[j] * wg[k] * det;
          }
      measure[e] = v;
      box[e] = is_box(r, 8, 3, L, H, size);
    }
    // General shape functions (004 eq 1).
    if (!general_shape_coefficients(t, r, C, scale[e], &coef[static_cast<size_t>(e) * kMaxNodes * kMaxNodes]))
      bad("has singular general shape functions (its nodes do not determine the "
          "interpolant in physical coordinates, e.g. a diamond-shaped QUAD4)");
  }
  // node -> elements
  const int32_t np = ps.size();
  node_ptr.assign(static_cast<size_t>(np) + 1, 0);
  for (int32_t v : nodes) ++node_ptr[v + 1];
  for (int32_t i = 0; i < np; ++i) node_ptr[i + 1] += node_ptr[i];
  node_elems.assign(nodes.size(), 0);
  std::vector<int64_t> fill(node_ptr.begin(), node_ptr.end() - 1);
  for (int32_t e = 0; e < ne; ++e)
    for (int32_t k = ptr[e]; k < ptr[e + 1]; ++k) node_elems[fill[nodes[k]]++] = e;
}

void MeshGeometry::shape(int32_t e, const double *xr, double *N, double *dN, double *d2N) const {
  general_shape(type[e], dim, &coef[static_cast<size_t>(e) * kMaxNodes * kMaxNodes],
                &center[3 * static_cast<size_t>(e)], scale[e], xr, N, dN, d2N);
}

void MeshGeometry::quadrature(const ParticleSet &ps, int ngauss, std::vector<double> &x,
                              std::vector<double> &w) const {
  std::vector<double> xg, wg;
  gauss_legendre(ngauss, xg, wg);
  x.clear();
  w.clear();
  for (int32_t e = 0; e < size(); ++e) {
    const double *r = &rel[static_cast<size_t>(ptr[e]) * 3];
    double x0[3] = {0, 0, 0};
    for (int c = 0; c < dim; ++c) x0[c] = ps.x(nodes[ptr[e]], c);
    auto push = [&](const double *p, double wt) {
      for (int c = 0; c < dim; ++c) x.push_back(x0[c] + p[c]);
      w.push_back(wt);
    };
    const int t = type[e];
    if (t == MFREE_ELEMENT_LINE2) {
      for (int i = 0; i < ngauss; ++i) {
        const double p[3] = {0.5 * (1 + xg[i]) * r[3], 0, 0};
        push(p, 0.5 * wg[i] * r[3]);
      }
    } else if (t == MFREE_ELEMENT_TRI3) {
      const double a2 = 2.0 * measure[e];
      for (int i = 0; i < ngauss; ++i)
        for (int j = 0; j < ngauss; ++j) {
          const double u = 0.5 * (1 + xg[i]), v = 0.5 * (1 + xg[j]) * (1 - u);
          const double p[3] = {u * r[3] + v * r[6], u * r[4] + v * r[7], 0};
          push(p, 0.25 * wg[i] * wg[j] * (1 - u) * a2);
        }
    } else if (t == MFREE_ELEMENT_QUAD4) {
      for (int i = 0; i < ngauss; ++i)
        for (int j = 0; j < ngauss; ++j) {
          const double rr[2] = {xg[i], xg[j]};
          double p[3], det;
          iso_map(t, r, rr, p, det);
          push(p, wg[i] * wg[j] * det);
        }
    } else {
      for (int i = 0; i < ngauss; ++i)
        for (int j = 0; j < ngauss; ++j)
          for (int k = 0; k < ngauss; ++k) {
            const double rr[3] = {xg[i], xg[j], xg[k]};
            double p[3], det;
            iso_map(t, r, rr, p, det);
            push(p, wg[i] * wg[j] * wg[k] * det);
          }
    }
  }
}

}  // namespace mfree
