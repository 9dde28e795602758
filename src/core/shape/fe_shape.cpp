#include "core/shape/fe_shape.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "core/base/basis.hpp"
#include "mfree.h"

namespace mfree {

namespace {

// Reference corners of the isoparametric QUAD4 and HEX8 (VTK order).
const double kQuadRef[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
const double kHexRef[8][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                              {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};

// Monomials of the general shape functions: bit c of a mask is the factor xi_c, so
// {1, x}, {1, x, y}, {1, x, y, xy} and {1, x, y, z, xy, yz, zx, xyz} are multilinear.
const int kMasks[4][8] = {{0, 1, 0, 0, 0, 0, 0, 0},
                          {0, 1, 2, 0, 0, 0, 0, 0},
                          {0, 1, 2, 3, 0, 0, 0, 0},
                          {0, 1, 2, 4, 3, 6, 5, 7}};

const int *monomials(int type) {
  switch (type) {
    case MFREE_ELEMENT_LINE2: return kMasks[0];
    case MFREE_ELEMENT_TRI3: return kMasks[1];
    case MFREE_ELEMENT_QUAD4: return kMasks[2];
    default: return kMasks[3];
  }
}

// Inside tolerance of element_shape_at, in reference coordinates.
constexpr double kInsideTol = 1e-10;

bool tri3_shape_at(const double *X, const double *x, double *N, double *dN) {
  const double j00 = X[3] - X[0], j01 = X[6] - X[0], j10 = X[4] - X[1], j11 = X[7] - X[1];
  const double det = j00 * j11 - j01 * j10;
  const double rx = x[0] - X[0], ry = x[1] - X[1];
  const double l1 = (j11 * rx - j01 * ry) / det, l2 = (-j10 * rx + j00 * ry) / det;
  if (l1 < -kInsideTol || l2 < -kInsideTol || l1 + l2 > 1.0 + kInsideTol) return false;
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

// Reference functions and the Jacobian J[d][k] = dx_d / dr_k of a QUAD4 at r.
void quad4_jacobian(const double *X, const double *r, double *N, double *dNr, double J[2][2]) {
  iso_shape(MFREE_ELEMENT_QUAD4, r, N, dNr);
  J[0][0] = J[0][1] = J[1][0] = J[1][1] = 0.0;
  for (int a = 0; a < 4; ++a)
    for (int d = 0; d < 2; ++d) {
      J[d][0] += dNr[3 * a] * X[3 * a + d];
      J[d][1] += dNr[3 * a + 1] * X[3 * a + d];
    }
}

bool quad4_shape_at(const double *X, const double *x, double *N, double *dN) {
  double r[2] = {0.0, 0.0}, J[2][2], dNr[12];
  for (int it = 0; it < 30; ++it) {
    quad4_jacobian(X, r, N, dNr, J);
    double f[2] = {-x[0], -x[1]};  // the residual x(r) - x
    for (int a = 0; a < 4; ++a)
      for (int d = 0; d < 2; ++d) f[d] += N[a] * X[3 * a + d];
    const double det = J[0][0] * J[1][1] - J[0][1] * J[1][0];
    const double su = (J[1][1] * f[0] - J[0][1] * f[1]) / det, sv = (-J[1][0] * f[0] + J[0][0] * f[1]) / det;
    r[0] -= su;
    r[1] -= sv;
    if (std::fabs(su) + std::fabs(sv) < 1e-15) break;
  }
  if (std::fabs(r[0]) > 1.0 + kInsideTol || std::fabs(r[1]) > 1.0 + kInsideTol) return false;
  quad4_jacobian(X, r, N, dNr, J);
  const double det = J[0][0] * J[1][1] - J[0][1] * J[1][0];
  for (int a = 0; a < 4; ++a) {  // grad N = J^-T (dN/du, dN/dv)
    dN[2 * a] = (J[1][1] * dNr[3 * a] - J[1][0] * dNr[3 * a + 1]) / det;
    dN[2 * a + 1] = (-J[0][1] * dNr[3 * a] + J[0][0] * dNr[3 * a + 1]) / det;
  }
  return true;
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

const char *element_name(int t) {
  switch (t) {
    case MFREE_ELEMENT_LINE2: return "LINE2";
    case MFREE_ELEMENT_TRI3: return "TRI3";
    case MFREE_ELEMENT_QUAD4: return "QUAD4";
    case MFREE_ELEMENT_HEX8: return "HEX8";
    default: return "?";
  }
}

const double *reference_corner(int type, int k) {
  return type == MFREE_ELEMENT_QUAD4 ? kQuadRef[k] : kHexRef[k];
}

void iso_shape(int type, const double *r, double *N, double *dNr) {
  if (type == MFREE_ELEMENT_QUAD4) {
    for (int I = 0; I < 4; ++I) {
      const double a = kQuadRef[I][0], b = kQuadRef[I][1];
      N[I] = 0.25 * (1 + a * r[0]) * (1 + b * r[1]);
      dNr[3 * I] = 0.25 * a * (1 + b * r[1]);
      dNr[3 * I + 1] = 0.25 * b * (1 + a * r[0]);
      dNr[3 * I + 2] = 0.0;
    }
    return;
  }
  for (int I = 0; I < 8; ++I) {
    const double a = kHexRef[I][0], b = kHexRef[I][1], c3 = kHexRef[I][2];
    const double fa = 1 + a * r[0], fb = 1 + b * r[1], fc = 1 + c3 * r[2];
    N[I] = 0.125 * fa * fb * fc;
    dNr[3 * I] = 0.125 * a * fb * fc;
    dNr[3 * I + 1] = 0.125 * b * fa * fc;
    dNr[3 * I + 2] = 0.125 * c3 * fa * fb;
  }
}

void iso_map(int type, const double *X, const double *r, double *x, double &det) {
  double J[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}}, N[8], dNr[24];
  x[0] = x[1] = x[2] = 0.0;
  iso_shape(type, r, N, dNr);
  if (type == MFREE_ELEMENT_QUAD4) {
    for (int I = 0; I < 4; ++I)
      for (int c = 0; c < 2; ++c) {
        x[c] += N[I] * X[3 * I + c];
        J[c][0] += dNr[3 * I] * X[3 * I + c];
        J[c][1] += dNr[3 * I + 1] * X[3 * I + c];
      }
    det = J[0][0] * J[1][1] - J[0][1] * J[1][0];
    return;
  }
  for (int I = 0; I < 8; ++I)
    for (int c = 0; c < 3; ++c) {
      x[c] += N[I] * X[3 * I + c];
      for (int k = 0; k < 3; ++k) J[c][k] += dNr[3 * I + k] * X[3 * I + c];
    }
  det = J[0][0] * (J[1][1] * J[2][2] - J[1][2] * J[2][1]) -
        J[0][1] * (J[1][0] * J[2][2] - J[1][2] * J[2][0]) +
        J[0][2] * (J[1][0] * J[2][1] - J[1][1] * J[2][0]);
}

double corner_cross(const double *X, int n, int k) {
  const double *p = X + 3 * k, *pn = X + 3 * ((k + 1) % n), *pp = X + 3 * ((k + n - 1) % n);
  return (pn[0] - p[0]) * (pp[1] - p[1]) - (pn[1] - p[1]) * (pp[0] - p[0]);
}

bool element_shape_at(int type, const double *X, const double *x, double *N, double *dN) {
  return type == MFREE_ELEMENT_TRI3 ? tri3_shape_at(X, x, N, dN) : quad4_shape_at(X, x, N, dN);
}

bool general_shape_coefficients(int type, const double *X, const double *center, double scale,
                                double *coef) {
  // V[I][m] = p_m(xi_I), C = V^-1 (004 eq 1).
  const int n = element_nodes(type);
  const int *mask = monomials(type);
  Eigen::MatrixXd V(n, n);
  for (int I = 0; I < n; ++I) {
    double xi[3];
    for (int c = 0; c < 3; ++c) xi[c] = (X[3 * I + c] - center[c]) / scale;
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
  if (!(minp > 1e-10 * maxp)) return false;
  const Eigen::MatrixXd Ci = lu.inverse();
  for (int mm = 0; mm < n; ++mm)
    for (int I = 0; I < n; ++I) coef[mm * kMaxElementNodes + I] = Ci(mm, I);
  return true;
}

void general_shape(int type, int dim, const double *coef, const double *center, double scale,
                   const double *xr, double *N, double *dN, double *d2N) {
  const int n = element_nodes(type);
  const int *mask = monomials(type);
  const double is = 1.0 / scale;
  double xi[3] = {0, 0, 0};
  for (int c = 0; c < dim; ++c) xi[c] = (xr[c] - center[c]) * is;
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
  const double *K = coef;
  for (int I = 0; I < n; ++I) {
    if (N) {
      double v = 0.0;
      for (int mm = 0; mm < n; ++mm) v += K[mm * kMaxElementNodes + I] * p[mm];
      N[I] = v;
    }
    if (dN)
      for (int a = 0; a < dim; ++a) {
        double v = 0.0;
        for (int mm = 0; mm < n; ++mm) v += K[mm * kMaxElementNodes + I] * dp[mm][a];
        dN[I * 3 + a] = v;
      }
    if (d2N)
      for (int k = 0; k < nh; ++k) {
        double v = 0.0;
        for (int mm = 0; mm < n; ++mm) v += K[mm * kMaxElementNodes + I] * d2p[mm][k];
        d2N[I * 6 + k] = v;
      }
  }
}

}  // namespace mfree
