#include "core/shape/mpfem.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cfloat>
#include <memory>
#include <cmath>
#include <sstream>

#include "core/shape/approximant.hpp"
#include "core/base/basis.hpp"
#include "core/base/quadrature.hpp"

namespace mfree {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Monomials of the general shape functions: bit c of a mask is the factor xi_c, so
// {1, x}, {1, x, y}, {1, x, y, xy} and {1, x, y, z, xy, yz, zx, xyz} are multilinear.
const int kMasks[4][8] = {{0, 1, 0, 0, 0, 0, 0, 0},
                          {0, 1, 2, 0, 0, 0, 0, 0},
                          {0, 1, 2, 3, 0, 0, 0, 0},
                          {0, 1, 2, 4, 3, 6, 5, 7}};

const char *element_name(int t) {
  switch (t) {
    case MFREE_ELEMENT_LINE2: return "LINE2";
    case MFREE_ELEMENT_TRI3: return "TRI3";
    case MFREE_ELEMENT_QUAD4: return "QUAD4";
    case MFREE_ELEMENT_HEX8: return "HEX8";
    default: return "?";
  }
}

// Reference corners of the isoparametric QUAD4 and HEX8 (VTK order).
const double kQuadRef[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
const double kHexRef[8][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                              {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};

// Isoparametric map of a QUAD4/HEX8 at reference point r: x (relative) and det J.
void iso_map(int type, const double *rel, const double *r, double *x, double &det) {
  double J[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  x[0] = x[1] = x[2] = 0.0;
  if (type == MFREE_ELEMENT_QUAD4) {
    for (int I = 0; I < 4; ++I) {
      const double a = kQuadRef[I][0], b = kQuadRef[I][1];
      const double N = 0.25 * (1 + a * r[0]) * (1 + b * r[1]);
      const double d0 = 0.25 * a * (1 + b * r[1]), d1 = 0.25 * b * (1 + a * r[0]);
      for (int c = 0; c < 2; ++c) {
        x[c] += N * rel[3 * I + c];
        J[c][0] += d0 * rel[3 * I + c];
        J[c][1] += d1 * rel[3 * I + c];
      }
    }
    det = J[0][0] * J[1][1] - J[0][1] * J[1][0];
    return;
  }
  for (int I = 0; I < 8; ++I) {
    const double a = kHexRef[I][0], b = kHexRef[I][1], c3 = kHexRef[I][2];
    const double fa = 1 + a * r[0], fb = 1 + b * r[1], fc = 1 + c3 * r[2];
    const double N = 0.125 * fa * fb * fc;
    const double d[3] = {0.125 * a * fb * fc, 0.125 * b * fa * fc, 0.125 * c3 * fa * fb};
    for (int c = 0; c < 3; ++c) {
      x[c] += N * rel[3 * I + c];
      for (int k = 0; k < 3; ++k) J[c][k] += d[k] * rel[3 * I + c];
    }
  }
  det = J[0][0] * (J[1][1] * J[2][2] - J[1][2] * J[2][1]) -
        J[0][1] * (J[1][0] * J[2][2] - J[1][2] * J[2][0]) +
        J[0][2] * (J[1][0] * J[2][1] - J[1][1] * J[2][0]);
}

}  // namespace

int element_dim(int t) {
  switch (t) {
    case MFREE_ELEMENT_LINE2: return 1;
    case MFREE_ELEMENT_TRI3:
    case MFREE_ELEMENT_QUAD4: return 2;
    case MFREE_ELEMENT_HEX8: return 3;
    default: return 0;
  }
}

int element_nodes(int t) {
  switch (t) {
    case MFREE_ELEMENT_LINE2: return 2;
    case MFREE_ELEMENT_TRI3: return 3;
    case MFREE_ELEMENT_QUAD4: return 4;
    case MFREE_ELEMENT_HEX8: return 8;
    default: return 0;
  }
}

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
        const double *p = r + 3 * k, *pn = r + 3 * ((k + 1) % 4), *pp = r + 3 * ((k + 3) % 4);
        const double cr = (pn[0] - p[0]) * (pp[1] - p[1]) - (pn[1] - p[1]) * (pp[0] - p[0]);
        if (!(cr > tol * size * size))
          bad("has Jacobian <= 0 at corner " + std::to_string(k) +
              " (inverted, clockwise, non-convex or degenerate)");
      }
      double a = 0.0;
      for (int k = 0; k < 4; ++k) {
        const double *p = r + 3 * k, *pn = r + 3 * ((k + 1) % 4);
        a += 0.5 * (p[0] * pn[1] - p[1] * pn[0]);
      }
      measure[e] = a;
      bool isbox = true;
      for (int k = 0; k < 4; ++k)
        for (int c = 0; c < 2; ++c) {
          const double v = r[3 * k + c];
          if (std::fabs(v - L[c]) > 1e-13 * size && std::fabs(v - H[c]) > 1e-13 * size) isbox = false;
        }
      box[e] = isbox;
    } else {  // HEX8
      for (int k = 0; k < 8; ++k) {
        double x[3], det;
        iso_map(t, r, kHexRef[k], x, det);
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
      bool isbox = true;
      for (int k = 0; k < 8; ++k)
        for (int c = 0; c < 3; ++c) {
          const double w = r[3 * k + c];
          if (std::fabs(w - L[c]) > 1e-13 * size && std::fabs(w - H[c]) > 1e-13 * size) isbox = false;
        }
      box[e] = isbox;
    }
    // General shape functions: V[I][m] = p_m(xi_I), C = V^-1 (004 eq 1).
    const int *mask = kMasks[dim == 1 ? 0 : (t == MFREE_ELEMENT_TRI3 ? 1 : (t == MFREE_ELEMENT_QUAD4 ? 2 : 3))];
    Eigen::MatrixXd V(n, n);
    for (int I = 0; I < n; ++I) {
      double xi[3];
      for (int c = 0; c < 3; ++c) xi[c] = (r[3 * I + c] - C[c]) / scale[e];
      for (int mm = 0; mm < n; ++mm) {
        double p = 1.0;
        for (int c = 0; c < 3; ++c)
          if (mask[mm] & (1 << c)) p *= xi[c];
        V(I, mm) = p;
      }
    }
    Eigen::FullPivLU<Eigen::MatrixXd> lu(V);
    const double maxp = lu.maxPivot();
    double minp = maxp;
    for (int k = 0; k < n; ++k) minp = std::min(minp, std::fabs(lu.matrixLU()(k, k)));
    if (!(minp > 1e-10 * maxp))
      bad("has singular general shape functions (its nodes do not determine the "
          "interpolant in physical coordinates, e.g. a diamond-shaped QUAD4)");
    const Eigen::MatrixXd Ci = lu.inverse();
    for (int mm = 0; mm < n; ++mm)
      for (int I = 0; I < n; ++I)
        coef[static_cast<size_t>(e) * kMaxNodes * kMaxNodes + mm * kMaxNodes + I] = Ci(mm, I);
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
  const int n = nn(e), t = type[e];
  const int *mask = kMasks[dim == 1 ? 0 : (t == MFREE_ELEMENT_TRI3 ? 1 : (t == MFREE_ELEMENT_QUAD4 ? 2 : 3))];
  const double s = scale[e], is = 1.0 / s;
  const double *C = &center[3 * static_cast<size_t>(e)];
  double xi[3] = {0, 0, 0};
  for (int c = 0; c < dim; ++c) xi[c] = (xr[c] - C[c]) * is;
  const int nh = hessian_size(dim);
  double p[8], dp[8][3], d2p[8][6];
  for (int mm = 0; mm < n; ++mm) {
    const int m = mask[mm];
    double v = 1.0;
    for (int c = 0; c < dim; ++c)
      if (m & (1 << c)) v *= xi[c];
    p[mm] = v;
    for (int a = 0; a < dim; ++a) {
      double g = 0.0;
      if (m & (1 << a)) {
        g = is;
        for (int c = 0; c < dim; ++c)
          if (c != a && (m & (1 << c))) g *= xi[c];
      }
      dp[mm][a] = g;
      for (int b = a; b < dim; ++b) {
        double h2 = 0.0;
        if (b != a && (m & (1 << a)) && (m & (1 << b))) {
          h2 = is * is;
          for (int c = 0; c < dim; ++c)
            if (c != a && c != b && (m & (1 << c))) h2 *= xi[c];
        }
        d2p[mm][hessian_index(dim, a, b)] = h2;
      }
    }
  }
  const double *K = &coef[static_cast<size_t>(e) * kMaxNodes * kMaxNodes];
  for (int I = 0; I < n; ++I) {
    if (N) {
      double v = 0.0;
      for (int mm = 0; mm < n; ++mm) v += K[mm * kMaxNodes + I] * p[mm];
      N[I] = v;
    }
    if (dN)
      for (int a = 0; a < dim; ++a) {
        double v = 0.0;
        for (int mm = 0; mm < n; ++mm) v += K[mm * kMaxNodes + I] * dp[mm][a];
        dN[I * 3 + a] = v;
      }
    if (d2N)
      for (int k = 0; k < nh; ++k) {
        double v = 0.0;
        for (int mm = 0; mm < n; ++mm) v += K[mm * kMaxNodes + I] * d2p[mm][k];
        d2N[I * 6 + k] = v;
      }
  }
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

// ---------------------------------------------------------------------------------------
// Kernel profile

KernelProfile::KernelProfile(int kernel, double param) : id_(kernel), k_(kernel, 1, param) {
  R_ = k_.radius();
  gauss_legendre(10, xg_, wg_);
  if (kernel == MFREE_KERNEL_COSINE || kernel == MFREE_KERNEL_COSINE_SQUARED ||
      kernel == MFREE_KERNEL_HAAR) {
    knots_ = {-R_, 0.0, R_};
    return;
  }
  // Panels of width 1/2 put every spline knot on a panel edge.
  const int np = static_cast<int>(std::lround(2.0 * R_ / 0.5));
  cum_.assign(np + 1, 0.0);
  for (int p = 0; p <= np; ++p) knots_.push_back(-R_ + 0.5 * p);
  for (int p = 0; p < np; ++p) {
    const double a = knots_[p], b = knots_[p + 1];
    double s = 0.0;
    for (size_t g = 0; g < xg_.size(); ++g) {
      const double q = 0.5 * (a + b) + 0.5 * (b - a) * xg_[g];
      s += 0.5 * (b - a) * wg_[g] * k_.norm() * k_.shape(std::fabs(q));
    }
    cum_[p + 1] = cum_[p] + s;
  }
}

void KernelProfile::g(double t, double h, double &v, double &dv) const {
  const double ih = 1.0 / h, q = std::fabs(t) * ih;
  double f, df, d2f;
  k_.shape(q, f, df, d2f);
  v = k_.norm() * ih * f;
  dv = k_.norm() * ih * ih * df * (t > 0 ? 1.0 : (t < 0 ? -1.0 : 0.0));
}

double KernelProfile::Gq(double q) const {
  if (q <= -R_) return 0.0;
  if (q >= R_) return 1.0;
  switch (id_) {
    case MFREE_KERNEL_COSINE:
      return 0.5 * (1.0 + std::sin(0.5 * kPi * q));
    case MFREE_KERNEL_COSINE_SQUARED:
      return 0.5 + 0.5 * q + std::sin(kPi * q) / (2.0 * kPi);
    case MFREE_KERNEL_HAAR:
      return 0.5 * (q + 1.0);
    default:
      break;
  }
  const int p = std::min(static_cast<int>((q + R_) / 0.5), static_cast<int>(cum_.size()) - 2);
  const double a = knots_[p];
  double s = 0.0;
  for (size_t g = 0; g < xg_.size(); ++g) {
    const double x = 0.5 * (a + q) + 0.5 * (q - a) * xg_[g];
    s += 0.5 * (q - a) * wg_[g] * k_.norm() * k_.shape(std::fabs(x));
  }
  return std::min(1.0, cum_[p] + s);
}

double KernelProfile::G(double t, double h) const { return Gq(t / h); }

// ---------------------------------------------------------------------------------------
// The MPFEM approximant

namespace {

// sin(x) / x, accurate also near 0.
double sinc(double x) {
  if (std::fabs(x) < 1e-4) return 1.0 - x * x / 6.0;
  return std::sin(x) / x;
}

// Exact integrals over s in [sa, sb] of cos(c0 + c1 s) and sin(c0 + c1 s).
void trig_integrals(double c0, double c1, double sa, double sb, double &ic, double &is) {
  const double L = sb - sa, ph = c0 + c1 * 0.5 * (sa + sb), f = L * sinc(0.5 * c1 * L);
  ic = f * std::cos(ph);
  is = f * std::sin(ph);
}

struct ElemWeight {
  double W = 0.0, dW[3] = {0, 0, 0}, d2W[6] = {0, 0, 0, 0, 0, 0};
};

// Interval [a, b] relative to the site: W = G(b) - G(a), W' = g(a) - g(b),
// W'' = g'(b) - g'(a) (the kernel is centred at x, so d/dx of G(b - x) is -g).
void interval_weight(const KernelProfile &K, double a, double b, double h, double &W, double &dW,
                     double &d2W) {
  double ga, dga, gb, dgb;
  K.g(a, h, ga, dga);
  K.g(b, h, gb, dgb);
  W = K.G(b, h) - K.G(a, h);
  dW = ga - gb;
  d2W = dgb - dga;
}

// Unnormalised weight int_e phi(y - x) dy and its x-derivatives (004 eq 11), for element
// e whose first node is at d0 = x_first - x.
void element_weight(const MeshGeometry &geo, const KernelProfile &K, int32_t e, const double *d0,
                    double h, bool d1, bool d2, const std::vector<double> &xg,
                    const std::vector<double> &wg, ElemWeight &out) {
  const int dim = geo.dim;
  out = ElemWeight();
  if (geo.box[e]) {  // tensor kernel over a rectangle or brick: a product of intervals
    double W[3], dW[3], d2W[3];
    for (int c = 0; c < dim; ++c)
      interval_weight(K, d0[c] + geo.lo[3 * e + c], d0[c] + geo.hi[3 * e + c], h, W[c], dW[c], d2W[c]);
    out.W = 1.0;
    for (int c = 0; c < dim; ++c) out.W *= W[c];
    if (!(d1 || d2)) return;
    for (int a = 0; a < dim; ++a) {
      double g = dW[a];
      for (int c = 0; c < dim; ++c)
        if (c != a) g *= W[c];
      out.dW[a] = g;
      if (d2)
        for (int b = a; b < dim; ++b) {
          double v = (a == b) ? d2W[a] : dW[a] * dW[b];
          for (int c = 0; c < dim; ++c)
            if (c != a && c != b) v *= W[c];
          out.d2W[hessian_index(dim, a, b)] = v;
        }
    }
    return;
  }
  // Polygon (TRI3, QUAD4): divergence theorem with F = (G(t1) g(t2), 0), div F = phi, so
  // W = sum over edges of int G(t1) g(t2) n1 ds, dW_i = -int phi n_i ds and
  // d2W_ij = int (d_j phi) n_i ds; each edge is split where t1 or t2 crosses a knot of
  // the kernel, so Gauss rules see smooth integrands only.
  const int n = geo.nn(e);
  const double *r = &geo.rel[static_cast<size_t>(geo.ptr[e]) * 3];
  const double Rh = K.radius() * h;
  double H[2][2] = {{0, 0}, {0, 0}};
  double sig[64];
  for (int k = 0; k < n; ++k) {
    const double P0[2] = {d0[0] + r[3 * k], d0[1] + r[3 * k + 1]};
    const int k1 = (k + 1) % n;
    const double dx[2] = {r[3 * k1] - r[3 * k], r[3 * k1 + 1] - r[3 * k + 1]};
    int ns = 0;
    sig[ns++] = 0.0;
    sig[ns++] = 1.0;
    for (int c = 0; c < 2; ++c) {
      if (dx[c] == 0.0) continue;
      for (double q : K.knots()) {
        const double s = (q * h - P0[c]) / dx[c];
        if (s > 0.0 && s < 1.0 && ns < 64) sig[ns++] = s;
      }
    }
    std::sort(sig, sig + ns);
    for (int p = 0; p + 1 < ns; ++p) {
      const double sa = sig[p], sb = sig[p + 1];
      if (!(sb > sa)) continue;
      const double sm = 0.5 * (sa + sb);
      const double m0 = P0[0] + sm * dx[0], m1 = P0[1] + sm * dx[1];
      if (std::fabs(m1) > Rh) continue;            // g(t2) = 0 on the whole piece
      const bool out1 = std::fabs(m0) > Rh;
      if (out1 && m0 < 0.0) continue;              // G(t1) = 0 and g(t1) = 0
      if (K.cosine()) {
        // alpha = k t1, beta = k t2 along the piece; with g = (k/2) cos, G = (1 + sin)/2,
        // g' = -(k^2/2) sin, every product below is a sum of sin / cos of alpha +- beta.
        const double k = 0.5 * kPi / Rh;
        double cb, sb_;
        trig_integrals(k * P0[1], k * dx[1], sa, sb, cb, sb_);
        if (out1) {
          out.W += 0.5 * k * cb * dx[1];
          continue;
        }
        double cp, sp, cm, sm_;
        trig_integrals(k * (P0[0] + P0[1]), k * (dx[0] + dx[1]), sa, sb, cp, sp);
        trig_integrals(k * (P0[0] - P0[1]), k * (dx[0] - dx[1]), sa, sb, cm, sm_);
        out.W += (0.25 * k * cb + 0.125 * k * (sp + sm_)) * dx[1];
        if (d1 || d2) {
          const double gg = 0.125 * k * k * (cp + cm);  // int g1 g2
          out.dW[0] -= gg * dx[1];
          out.dW[1] += gg * dx[0];
        }
        if (d2) {
          const double k3 = 0.125 * k * k * k;
          const double p1 = -k3 * (sp + sm_), p2 = -k3 * (sp - sm_);  // int g1' g2, int g1 g2'
          H[0][0] += p1 * dx[1];
          H[0][1] += p2 * dx[1];
          H[1][0] -= p1 * dx[0];
          H[1][1] -= p2 * dx[0];
        }
        continue;
      }
      for (size_t j = 0; j < xg.size(); ++j) {
        const double sj = sm + 0.5 * (sb - sa) * xg[j], wt = 0.5 * (sb - sa) * wg[j];
        const double t1 = P0[0] + sj * dx[0], t2 = P0[1] + sj * dx[1];
        double g1 = 0.0, dg1 = 0.0, g2, dg2;
        K.g(t2, h, g2, dg2);
        const double G1 = out1 ? 1.0 : K.G(t1, h);
        out.W += wt * G1 * g2 * dx[1];
        if (out1) continue;
        K.g(t1, h, g1, dg1);
        if (d1 || d2) {
          out.dW[0] -= wt * g1 * g2 * dx[1];
          out.dW[1] += wt * g1 * g2 * dx[0];
        }
        if (d2) {
          const double p1 = dg1 * g2, p2 = g1 * dg2;
          H[0][0] += wt * p1 * dx[1];
          H[0][1] += wt * p2 * dx[1];
          H[1][0] -= wt * p1 * dx[0];
          H[1][1] -= wt * p2 * dx[0];
        }
      }
    }
  }
  out.d2W[0] = H[0][0];
  out.d2W[1] = 0.5 * (H[0][1] + H[1][0]);
  out.d2W[2] = H[1][1];
}

bool box_overlaps(const MeshGeometry &geo, int32_t e, const double *d0, double Rh) {
  for (int c = 0; c < geo.dim; ++c)
    if (!(d0[c] + geo.lo[3 * e + c] < Rh && d0[c] + geo.hi[3 * e + c] > -Rh)) return false;
  return true;
}


// Uniform bucket grid over the elements' bounding boxes (absolute coordinates), so that
// a site finds the elements its support box may reach without a sweep over the mesh.
// Not used on periodic sets, whose elements are placed by nearest image.
class ElementGrid {
 public:
  ElementGrid(const MeshGeometry &geo, const ParticleSet &ps) : dim_(geo.dim) {
    const int32_t ne = geo.size();
    lo_.assign(static_cast<size_t>(ne) * 3, 0.0);
    hi_.assign(static_cast<size_t>(ne) * 3, 0.0);
    double glo[3] = {0, 0, 0}, ghi[3] = {0, 0, 0}, ext = 0.0;
    for (int32_t e = 0; e < ne; ++e)
      for (int c = 0; c < dim_; ++c) {
        const double x0 = ps.x(geo.nodes[geo.ptr[e]], c);
        lo_[3 * e + c] = x0 + geo.lo[3 * e + c];
        hi_[3 * e + c] = x0 + geo.hi[3 * e + c];
        glo[c] = e ? std::min(glo[c], lo_[3 * e + c]) : lo_[3 * e + c];
        ghi[c] = e ? std::max(ghi[c], hi_[3 * e + c]) : hi_[3 * e + c];
        ext += hi_[3 * e + c] - lo_[3 * e + c];
      }
    ext = ne ? ext / (static_cast<double>(ne) * dim_) : 1.0;
    int64_t cells = 1;
    for (int c = 0; c < dim_; ++c) {
      org_[c] = glo[c];
      const double span = ghi[c] - glo[c];
      n_[c] = static_cast<int32_t>(std::min(1024.0, std::max(1.0, std::floor(span / std::max(ext, 1e-300)))));
    }
    // at most a few cells per element (scattered elements must not make a huge grid)
    const int64_t cap = std::max<int64_t>(64, 4 * static_cast<int64_t>(ne));
    for (;;) {
      cells = 1;
      for (int c = 0; c < dim_; ++c) cells *= n_[c];
      if (cells <= cap) break;
      int big = 0;
      for (int c = 1; c < dim_; ++c)
        if (n_[c] > n_[big]) big = c;
      n_[big] = std::max(1, n_[big] / 2);
    }
    for (int c = 0; c < dim_; ++c) {
      const double span = ghi[c] - glo[c];
      cs_[c] = span > 0.0 ? span / n_[c] : 1.0;
    }
    start_.assign(static_cast<size_t>(cells) + 1, 0);
    for (int pass = 0; pass < 2; ++pass) {
      for (int32_t e = 0; e < ne; ++e) {
        int32_t a[3], b[3];
        range(&lo_[3 * e], &hi_[3 * e], a, b);
        for (int32_t k = a[2]; k <= b[2]; ++k)
          for (int32_t j = a[1]; j <= b[1]; ++j)
            for (int32_t i = a[0]; i <= b[0]; ++i) {
              const int64_t cell = (static_cast<int64_t>(k) * n_[1] + j) * n_[0] + i;
              if (pass == 0) ++start_[cell + 1];
              else elems_[fill_[cell]++] = e;
            }
      }
      if (pass == 0) {
        for (size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
        elems_.assign(static_cast<size_t>(start_.back()), 0);
        fill_.assign(start_.begin(), start_.end() - 1);
      }
    }
    stamp_.assign(ne, -1);
  }
  // Elements whose box may overlap [x - r, x + r], ascending, each once.
  void query(const double *x, double r, int32_t tag, std::vector<int32_t> &out) {
    out.clear();
    double qlo[3] = {0, 0, 0}, qhi[3] = {0, 0, 0};
    for (int c = 0; c < dim_; ++c) qlo[c] = x[c] - r, qhi[c] = x[c] + r;
    int32_t a[3], b[3];
    range(qlo, qhi, a, b);
    for (int32_t k = a[2]; k <= b[2]; ++k)
      for (int32_t j = a[1]; j <= b[1]; ++j)
        for (int32_t i = a[0]; i <= b[0]; ++i) {
          const int64_t cell = (static_cast<int64_t>(k) * n_[1] + j) * n_[0] + i;
          for (int64_t q = start_[cell]; q < start_[cell + 1]; ++q) {
            const int32_t e = elems_[q];
            if (stamp_[e] == tag) continue;
            stamp_[e] = tag;
            out.push_back(e);
          }
        }
    std::sort(out.begin(), out.end());
  }

 private:
  void range(const double *lo, const double *hi, int32_t *a, int32_t *b) const {
    for (int c = 0; c < 3; ++c) {
      if (c >= dim_) {
        a[c] = b[c] = 0;
        continue;
      }
      const double fa = std::floor((lo[c] - org_[c]) / cs_[c]), fb = std::floor((hi[c] - org_[c]) / cs_[c]);
      a[c] = static_cast<int32_t>(std::min<double>(n_[c] - 1, std::max(0.0, fa)));
      b[c] = static_cast<int32_t>(std::min<double>(n_[c] - 1, std::max(0.0, fb)));
    }
  }
  int dim_;
  double org_[3] = {0, 0, 0}, cs_[3] = {1, 1, 1};
  int32_t n_[3] = {1, 1, 1};
  std::vector<double> lo_, hi_;
  std::vector<int64_t> start_, fill_;
  std::vector<int32_t> elems_, stamp_;
};
}  // namespace

void Approximant::set_mesh(std::shared_ptr<const Mesh> mesh) {
  if (method_ != MFREE_METHOD_MPFEM)
    throw Error(MFREE_ERR_UNSUPPORTED, "only MPFEM approximants take a mesh");
  if (mesh && &mesh->particles() != ps_)
    throw Error(MFREE_ERR_MISMATCH, "the mesh is built on another particle set than the approximant");
  mesh_ = std::move(mesh);
  setup_done_ = false;
}

void Approximant::set_mpfem(int deriv, int ngauss) {
  if (method_ != MFREE_METHOD_MPFEM)
    throw Error(MFREE_ERR_UNSUPPORTED, "MPFEM options on a non-MPFEM approximant");
  if (deriv < MFREE_MPFEM_DERIV_FULL || deriv > MFREE_MPFEM_DERIV_NODAL)
    throw Error(MFREE_ERR_ARG, "unknown MPFEM derivative form " + std::to_string(deriv));
  if (ngauss < 1 || ngauss > 20)
    throw Error(MFREE_ERR_ARG, "ngauss = " + std::to_string(ngauss) + " is outside 1..20");
  mpfem_deriv_ = deriv;
  mpfem_ngauss_ = ngauss;
  setup_done_ = false;
}

Report Approximant::compute_mpfem() {
  const int dim = ps_->dim(), nh = hessian_size(dim);
  if (!mesh_)
    throw Error(MFREE_ERR_STATE, "MPFEM needs a mesh: call mfree_approximant_set_mesh before setup");
  if (!ps_->has_support())
    throw Error(MFREE_ERR_STATE, "the particle set has no support sizes (the MPFEM kernel's half "
                                 "width is R h)");
  const bool fv = flags_ & MFREE_DERIV_VALUE, fg = flags_ & MFREE_DERIV_GRADIENT,
             fh = flags_ & MFREE_DERIV_HESSIAN;
  const int mode = mpfem_deriv_;
  if (mode == MFREE_MPFEM_DERIV_NODAL && points_)
    throw Error(MFREE_ERR_UNSUPPORTED, "the MPFEM nodal scheme (004 eqs 37-38) is defined at the "
                                       "nodes only, not at host points");
  const KernelProfile K(kernel_id_, kernel_param_);
  if (mode == MFREE_MPFEM_DERIV_FULL && fh && !K.continuous())
    throw Error(MFREE_ERR_UNSUPPORTED, "second derivatives by 004 eq 21 need a continuous kernel; "
                                       "with the Haar kernel use MFREE_MPFEM_DERIV_ASSUMED_STRAIN");
  MeshGeometry geo;
  geo.build(*mesh_);
  const int32_t ne = geo.size();
  if (dim == 3)
    for (int32_t e = 0; e < ne; ++e)
      if (!geo.box[e])
        throw Error(MFREE_ERR_UNSUPPORTED, "element " + std::to_string(e) +
                                               ": MPFEM weights on HEX8 elements need axis-aligned "
                                               "bricks");
  if (points_)
    for (int32_t s = 0; s < npts_; ++s) {
      for (int c = 0; c < dim; ++c)
        if (!std::isfinite(px_(s, c)))
          throw Error(MFREE_ERR_INPUT, "point " + std::to_string(s) + " has a non-finite coordinate");
      if (!(std::isfinite(ph_(s)) && ph_(s) > 0.0))
        throw Error(MFREE_ERR_INPUT, "point " + std::to_string(s) + " has support <= 0 or non-finite");
    }
  nsites_ = points_ ? npts_ : ps_->num_owned();
  rowptr_.assign(1, 0);
  cols_.clear();
  val_.clear();
  grad_.clear();
  hess_.clear();
  self_.assign(nsites_, -1);
  status_.assign(nsites_, 0);
  support_.assign(nsites_, 0);
  cond_.assign(nsites_, 1.0);
  order_used_.assign(nsites_, 1);
  std::vector<double> xg, wg;
  gauss_legendre(mpfem_ngauss_, xg, wg);

  const bool full = mode == MFREE_MPFEM_DERIV_FULL;
  const bool d1 = full && (fg || fh), d2 = full && fh;
  std::vector<int32_t> cand, near;
  bool periodic = false;
  for (int c = 0; c < dim; ++c) periodic = periodic || ps_->periodic(c);
  std::unique_ptr<ElementGrid> grid;
  if (!periodic && ne > 0) grid = std::make_unique<ElementGrid>(geo, *ps_);
  std::vector<ElemWeight> ew;
  std::vector<double> dfirst;
  std::vector<int32_t> rnode;
  std::vector<double> rv, rg, rh;
  std::vector<int> order;
  int64_t nfailed = 0;
  int32_t first_bad = -1;
  const auto &pst = ps_->site_status();
  // borrowed data that turned invalid since the set's setup: such a site is not computed
  // (a NaN support would reach the element grid's index arithmetic)
  find_bad_particles();
  for (int32_t s = 0; s < nsites_; ++s) {
    const int32_t me = site_particle(s);
    auto close_row = [&]() { rowptr_.push_back(static_cast<int64_t>(cols_.size())); };
    if (me >= 0 && (pst[me] != 0 || pbad_[me] != 0)) {
      status_[s] = pst[me] != 0 ? pst[me] : pbad_[me];
      order_used_[s] = -1;
      ++nfailed;
      if (first_bad < 0) first_bad = s;
      close_row();
      continue;
    }
    const double h = site_h(s), Rh = K.radius() * h;
    cand.clear();
    dfirst.clear();
    if (mode == MFREE_MPFEM_DERIV_NODAL) {
      for (int64_t k = geo.node_ptr[me]; k < geo.node_ptr[me + 1]; ++k) cand.push_back(geo.node_elems[k]);
      for (int32_t e : cand) {
        double d[3] = {0, 0, 0};
        site_displacement(s, geo.nodes[geo.ptr[e]], d);
        dfirst.insert(dfirst.end(), d, d + 3);
      }
    } else {
      if (grid) {
        double xs[3] = {0, 0, 0};
        for (int c = 0; c < dim; ++c) xs[c] = site_x(s, c);
        grid->query(xs, Rh, s, near);
      }
      const int32_t nscan = grid ? static_cast<int32_t>(near.size()) : ne;
      for (int32_t i = 0; i < nscan; ++i) {
        const int32_t e = grid ? near[i] : i;
        double d[3] = {0, 0, 0};
        site_displacement(s, geo.nodes[geo.ptr[e]], d);
        if (!box_overlaps(geo, e, d, Rh)) continue;
        cand.push_back(e);
        dfirst.insert(dfirst.end(), d, d + 3);
      }
    }
    const size_t nc = cand.size();
    ew.assign(nc, ElemWeight());
    double D = 0.0, dD[3] = {0, 0, 0}, d2D[6] = {0, 0, 0, 0, 0, 0};
    for (size_t i = 0; i < nc; ++i) {
      if (mode == MFREE_MPFEM_DERIV_NODAL) {
        ew[i].W = 1.0 / geo.measure[cand[i]];  // 004 eq 38
      } else {
        element_weight(geo, K, cand[i], &dfirst[3 * i], h, d1, d2, xg, wg, ew[i]);
      }
      D += ew[i].W;
      for (int a = 0; a < dim; ++a) dD[a] += ew[i].dW[a];
      for (int k = 0; k < nh; ++k) d2D[k] += ew[i].d2W[k];
    }
    rnode.clear();
    rv.clear();
    rg.clear();
    rh.clear();
    if (!(D > 0.0)) {
      status_[s] = MFREE_FAIL_NEIGHBORS;
      order_used_[s] = -1;
      ++nfailed;
      if (first_bad < 0) first_bad = s;
      close_row();
      continue;
    }
    for (size_t i = 0; i < nc; ++i) {
      const ElemWeight &w = ew[i];
      bool any = w.W != 0.0;
      for (int a = 0; a < dim; ++a) any = any || w.dW[a] != 0.0;
      if (!any) continue;
      // normalised weights (004 eqs 6, 11, 12) and their derivatives
      const double om = w.W / D;
      double dom[3] = {0, 0, 0}, d2om[6] = {0, 0, 0, 0, 0, 0};
      for (int a = 0; a < dim; ++a) dom[a] = (w.dW[a] - om * dD[a]) / D;
      for (int a = 0; a < dim; ++a)
        for (int b = a; b < dim; ++b) {
          const int k = hessian_index(dim, a, b);
          d2om[k] = (w.d2W[k] - dom[b] * dD[a] - dom[a] * dD[b] - om * d2D[k]) / D;
        }
      const int32_t e = cand[i];
      const int n = geo.nn(e);
      double xr[3] = {0, 0, 0}, N[8], dN[24], d2N[48];
      for (int c = 0; c < dim; ++c) xr[c] = -dfirst[3 * i + c];
      // only the derivatives asked for (the Hessians of the general shape functions
      // are needed for the Hessian table only)
      geo.shape(e, xr, N, (fg || fh) ? dN : nullptr, fh ? d2N : nullptr);
      for (int I = 0; I < n; ++I) {
        const int32_t node = geo.nodes[geo.ptr[e] + I];
        size_t slot = 0;
        while (slot < rnode.size() && rnode[slot] != node) ++slot;
        if (slot == rnode.size()) {
          rnode.push_back(node);
          rv.push_back(0.0);
          rg.insert(rg.end(), 3, 0.0);
          rh.insert(rh.end(), 6, 0.0);
        }
        rv[slot] += om * N[I];
        if (!(fg || fh)) continue;
        for (int a = 0; a < dim; ++a)
          rg[3 * slot + a] += (full ? dom[a] * N[I] : 0.0) + om * dN[3 * I + a];
        if (!fh) continue;
        for (int a = 0; a < dim; ++a)
          for (int b = a; b < dim; ++b) {
            const int k = hessian_index(dim, a, b);
            double v = om * d2N[6 * I + k];
            if (full) v += d2om[k] * N[I] + dom[a] * dN[3 * I + b] + dom[b] * dN[3 * I + a];
            rh[6 * slot + k] += v;
          }
      }
    }
    order.resize(rnode.size());
    for (size_t k = 0; k < order.size(); ++k) order[k] = static_cast<int>(k);
    std::sort(order.begin(), order.end(), [&](int a, int b) { return rnode[a] < rnode[b]; });
    for (int k : order) {
      if (rnode[k] == me) self_[s] = static_cast<int32_t>(cols_.size() - rowptr_.back());
      cols_.push_back(rnode[k]);
      if (fv) val_.push_back(rv[k]);
      if (fg)
        for (int a = 0; a < dim; ++a) grad_.push_back(rg[3 * k + a]);
      if (fh)
        for (int q = 0; q < nh; ++q) hess_.push_back(rh[6 * k + q]);
    }
    support_[s] = static_cast<int32_t>(rnode.size());
    close_row();
  }
  nfailed = screen_sites(0, nsites_);
  first_bad = -1;
  for (int32_t s = 0; s < nsites_ && first_bad < 0; ++s)
    if (status_[s]) first_bad = s;

  Report rep;
  if (nfailed) {
    std::ostringstream msg;
    msg << "MPFEM: site " << first_bad;
    if (status_[first_bad] == MFREE_FAIL_NEIGHBORS)
      msg << ": its kernel support (half width R h = " << K.radius() * site_h(first_bad)
          << ") reaches no element";
    else if (status_[first_bad] == MFREE_FAIL_NONFINITE)
      msg << " has a non-finite value in its data or its shape functions";
    else
      msg << " has invalid particle data";
    msg << " (" << nfailed << (nfailed == 1 ? " site" : " sites") << " failed; their rows are zero)";
    rep.fail(static_cast<mfree_status_t>(status_[first_bad]), msg.str());
  }

  // Interpolation condition (004 eq 13): no node's support may reach, with positive
  // weight, an element that does not contain the node.
  interpolating_ = true;
  if (mode != MFREE_MPFEM_DERIV_NODAL) {
    int64_t nviol = 0;
    int32_t vnode = -1, velem = -1;
    double vw = 0.0;
    for (int32_t P = 0; P < ps_->size(); ++P) {
      if (geo.node_ptr[P] == geo.node_ptr[P + 1] || pst[P] != 0 || pbad_[P] != 0) continue;
      const double h = ps_->h(P), Rh = K.radius() * h;
      bool bad = false;
      if (grid) {
        double xp[3] = {0, 0, 0};
        for (int c = 0; c < dim; ++c) xp[c] = ps_->x(P, c);
        grid->query(xp, Rh, nsites_ + P, near);
      }
      const int32_t nscan = grid ? static_cast<int32_t>(near.size()) : ne;
      for (int32_t i = 0; i < nscan && !bad; ++i) {
        const int32_t e = grid ? near[i] : i;
        bool mine = false;
        for (int32_t k = geo.ptr[e]; k < geo.ptr[e + 1]; ++k) mine = mine || geo.nodes[k] == P;
        if (mine) continue;
        double d[3] = {0, 0, 0};
        ps_->displacement(geo.nodes[geo.ptr[e]], P, d);
        if (!box_overlaps(geo, e, d, Rh)) continue;
        ElemWeight w;
        element_weight(geo, K, e, d, h, false, false, xg, wg, w);
        // Positions relative to the node carry round-off of about eps |x|, which is
        // eps |x| / (R h) of the kernel's width: with a support far below the spacing
        // (the reduction to FEM) the edge integrals of an element the support only
        // touches at a vertex leave that much instead of 0.
        double xmag = 0.0;
        for (int c = 0; c < dim; ++c)
          xmag = std::max({xmag, std::fabs(ps_->x(P, c)), std::fabs(d[c]) + geo.hi[3 * e + c] - geo.lo[3 * e + c]});
        if (w.W > 1e-12 + 100.0 * DBL_EPSILON * xmag / Rh) {
          bad = true;
          if (nviol == 0) {
            vnode = P;
            velem = e;
            vw = w.W;
          }
        }
      }
      if (bad) ++nviol;
    }
    if (nviol) {
      interpolating_ = false;
      std::ostringstream msg;
      msg << "MPFEM: the kernel support of node " << vnode << " (half width R h = "
          << K.radius() * ps_->h(vnode) << ") reaches element " << velem
          << ", which does not contain the node (unnormalised weight " << vw << "): 004 eq 13 "
          << "is violated at " << nviol << (nviol == 1 ? " node" : " nodes")
          << ", the functions do not interpolate (004 Sect. 4.1); reduce the support";
      if (rep.ok()) rep.fail(MFREE_FAIL_SUPPORT, msg.str());
    }
  }
  return rep;
}

}  // namespace mfree
