#include "core/shape/mpfem_weights.hpp"

#include <algorithm>
#include <cmath>

#include "core/base/basis.hpp"
#include "core/base/quadrature.hpp"

namespace mfree {

namespace {

constexpr double kPi = 3.14159265358979323846;

}  // namespace

// ---------------------------------------------------------------------------------------
// Kernel profile

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
// Element weights

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

// Polygon (TRI3, QUAD4): divergence theorem with F = (G(t1) g(t2), 0), div F = phi, so
// W = sum over edges of int G(t1) g(t2) n1 ds, dW_i = -int phi n_i ds and
// d2W_ij = int (d_j phi) n_i ds; each edge is split where t1 or t2 crosses a knot of
// the kernel, so Gauss rules see smooth integrands only.
void polygon_weight(const MeshGeometry &geo, const KernelProfile &K, int32_t e, const double *d0,
                    double h, bool d1, bool d2, const std::vector<double> &xg,
                    const std::vector<double> &wg, ElemWeight &out) {
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

}  // namespace

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
  polygon_weight(geo, K, e, d0, h, d1, d2, xg, wg, out);
}

bool box_overlaps(const MeshGeometry &geo, int32_t e, const double *d0, double Rh) {
  for (int c = 0; c < geo.dim; ++c)
    if (!(d0[c] + geo.lo[3 * e + c] < Rh && d0[c] + geo.hi[3 * e + c] > -Rh)) return false;
  return true;
}

// ---------------------------------------------------------------------------------------
// Element grid

ElementGrid::ElementGrid(const MeshGeometry &geo, const ParticleSet &ps) : dim_(geo.dim) {
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

void ElementGrid::query(const double *x, double r, int32_t tag, std::vector<int32_t> &out) {
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


void ElementGrid::range(const double *lo, const double *hi, int32_t *a, int32_t *b) const {
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

}  // namespace mfree
