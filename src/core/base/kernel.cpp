#include "core/base/kernel.hpp"

#include <cmath>
#include <string>
#include <vector>

#include "core/base/error.hpp"
#include "core/base/kernel_eval.hpp"
#include "core/base/quadrature.hpp"

namespace mfree {

namespace {

constexpr double kPi = 3.14159265358979323846;
const double kExpM4 = std::exp(-4.0);

// p^k for small integer k, p clipped at zero (truncated power).
inline double tp(double p, int k) {
  if (p <= 0.0) return 0.0;
  double r = 1.0;
  for (int i = 0; i < k; ++i) r *= p;
  return r;
}

}  // namespace

bool Kernel::valid_id(int k) {
  return k >= MFREE_KERNEL_CUBIC_SPLINE && k <= MFREE_KERNEL_HAAR;
}

double Kernel::support_radius(int k, double param) {
  (void)param;
  switch (k) {
    case MFREE_KERNEL_QUINTIC_SPLINE:
    case MFREE_KERNEL_GAUSSIAN:
    case MFREE_KERNEL_SUPER_GAUSS:
      return 3.0;
    case MFREE_KERNEL_QUARTIC_SPLINE:
      return 2.5;
    case MFREE_KERNEL_COSINE:  // the MPFEM kernels of paper 004: width d = 2h
    case MFREE_KERNEL_COSINE_SQUARED:
    case MFREE_KERNEL_HAAR:
      return 1.0;
    default:
      if (!valid_id(k)) throw Error(MFREE_ERR_ARG, "unknown kernel " + std::to_string(k));
      return 2.0;
  }
}

Kernel::Kernel(int kernel, int dim, double param) : id_(kernel), dim_(dim), a_(1.0) {
  if (!valid_id(kernel)) throw Error(MFREE_ERR_ARG, "unknown kernel " + std::to_string(kernel));
  if (dim < 1 || dim > 3)
    throw Error(MFREE_ERR_ARG, "dimension " + std::to_string(dim) + " is not 1, 2 or 3");
  if (!std::isfinite(param) || param < 0.0)
    throw Error(MFREE_ERR_ARG, "kernel parameter must be finite and >= 0");
  if (kernel == MFREE_KERNEL_REVISED_SUPER_GAUSS && param > 0.0) a_ = param;
  radius_ = support_radius(kernel, param);

  // c = 1 / (S_dim * int_0^R f(q) q^(dim-1) dq), S = 2, 2 pi, 4 pi. Panels of width 1/2
  // put every spline knot on a panel edge, so 20-point Gauss–Legendre is exact for the
  // piecewise polynomials and accurate to round-off for the Gaussians.
  std::vector<double> xg, wg;
  gauss_legendre(20, xg, wg);
  double integral = 0.0;
  const int panels = static_cast<int>(std::lround(radius_ / 0.5));
  for (int p = 0; p < panels; ++p) {
    const double a = 0.5 * p, b = 0.5 * (p + 1);
    for (std::size_t g = 0; g < xg.size(); ++g) {
      const double q = 0.5 * (a + b) + 0.5 * (b - a) * xg[g];
      double qd = 1.0;
      for (int d = 1; d < dim; ++d) qd *= q;
      integral += 0.5 * (b - a) * wg[g] * shape(q) * qd;
    }
  }
  const double surface = dim == 1 ? 2.0 : (dim == 2 ? 2.0 * kPi : 4.0 * kPi);
  c_ = 1.0 / (surface * integral);
}

double Kernel::shape(double q) const {
  double f, df, d2f;
  shape(q, f, df, d2f);
  return f;
}

void Kernel::shape(double q, double &f, double &df, double &d2f) const {
  f = df = d2f = 0.0;
  if (q > radius_ * (1.0 + kEdgeTol)) return;
  if (q > radius_) q = radius_;  // on the edge: the value from inside (closed support)
  switch (id_) {
    case MFREE_KERNEL_CUBIC_SPLINE: {  // inlined by the fast paths too (kernel_eval.hpp)
      using S = CubicSplineShape;
      if (q < 1.0) {
        f = S::inner(q);
        df = S::inner_d(q);
        d2f = S::inner_d2(q);
      } else {
        const double t = S::kRadius - q;
        f = S::outer(t);
        df = S::outer_d(t);
        d2f = S::outer_d2(t);
      }
      return;
    }
    case MFREE_KERNEL_QUARTIC:
      f = 1.0 - 1.5 * q * q + q * q * q - 0.1875 * q * q * q * q;
      df = -3.0 * q + 3.0 * q * q - 0.75 * q * q * q;
      d2f = -3.0 + 6.0 * q - 2.25 * q * q;
      return;
    case MFREE_KERNEL_QUINTIC_SPLINE: {
      const double t3 = 3.0 - q, t2 = 2.0 - q, t1 = 1.0 - q;
      f = tp(t3, 5) - 6.0 * tp(t2, 5) + 15.0 * tp(t1, 5);
      df = -5.0 * (tp(t3, 4) - 6.0 * tp(t2, 4) + 15.0 * tp(t1, 4));
      d2f = 20.0 * (tp(t3, 3) - 6.0 * tp(t2, 3) + 15.0 * tp(t1, 3));
      return;
    }
    case MFREE_KERNEL_QUARTIC_SPLINE: {
      const double t3 = 2.5 - q, t2 = 1.5 - q, t1 = 0.5 - q;
      f = tp(t3, 4) - 5.0 * tp(t2, 4) + 10.0 * tp(t1, 4);
      df = -4.0 * (tp(t3, 3) - 5.0 * tp(t2, 3) + 10.0 * tp(t1, 3));
      d2f = 12.0 * (tp(t3, 2) - 5.0 * tp(t2, 2) + 10.0 * tp(t1, 2));
      return;
    }
    case MFREE_KERNEL_GAUSSIAN: {
      const double e = std::exp(-q * q);
      f = e;
      df = -2.0 * q * e;
      d2f = (4.0 * q * q - 2.0) * e;
      return;
    }
    case MFREE_KERNEL_SUPER_GAUSS: {
      // (5/2 - q^2) e^{-q^2}
      const double e = std::exp(-q * q), q2 = q * q;
      f = (2.5 - q2) * e;
      df = q * (2.0 * q2 - 7.0) * e;
      d2f = (-4.0 * q2 * q2 + 20.0 * q2 - 7.0) * e;
      return;
    }
    case MFREE_KERNEL_REVISED_GAUSS: {
      const double e = std::exp(-q * q);
      f = e - kExpM4;
      df = -2.0 * q * e;
      d2f = (4.0 * q * q - 2.0) * e;
      return;
    }
    case MFREE_KERNEL_REVISED_SUPER_GAUSS: {
      // (4 - q^2) e^{-a q^2}
      const double a = a_, q2 = q * q, e = std::exp(-a * q2);
      f = (4.0 - q2) * e;
      df = (-2.0 * q - 2.0 * a * q * (4.0 - q2)) * e;
      // d/dq [(-2q - 8aq + 2a q^3) e] = (-2 - 8a + 6a q^2) e - 2aq (-2q - 8aq + 2aq^3) e
      d2f = ((-2.0 - 8.0 * a + 6.0 * a * q2) -
             2.0 * a * q * (-2.0 * q - 8.0 * a * q + 2.0 * a * q * q2)) * e;
      return;
    }
    case MFREE_KERNEL_WENDLAND_C2: {
      const double t = 1.0 - 0.5 * q;
      if (dim_ == 1) {  // (1 - q/2)^3 (1 + 3q/2)
        f = t * t * t * (1.0 + 1.5 * q);
        df = -1.5 * t * t * (1.0 + 1.5 * q) + 1.5 * t * t * t;  // = -3 q t^2 ... kept explicit
        d2f = 1.5 * t * (1.0 + 1.5 * q) - 2.25 * t * t - 2.25 * t * t;
      } else {  // (1 - q/2)^4 (1 + 2q)
        f = t * t * t * t * (1.0 + 2.0 * q);
        df = -2.0 * t * t * t * (1.0 + 2.0 * q) + 2.0 * t * t * t * t;
        d2f = 3.0 * t * t * (1.0 + 2.0 * q) - 4.0 * t * t * t - 4.0 * t * t * t;
      }
      return;
    }
    case MFREE_KERNEL_WENDLAND_C4: {
      const double t = 1.0 - 0.5 * q;
      if (dim_ == 1) {  // (1 - q/2)^5 (1 + 5q/2 + 2q^2)
        const double p = 1.0 + 2.5 * q + 2.0 * q * q, dp = 2.5 + 4.0 * q, d2p = 4.0;
        const double t4 = t * t * t * t, t5 = t4 * t;
        f = t5 * p;
        df = -2.5 * t4 * p + t5 * dp;
        d2f = 5.0 * t * t * t * p - 5.0 * t4 * dp + t5 * d2p;
      } else {  // (1 - q/2)^6 (1 + 3q + 35/12 q^2)
        const double p = 1.0 + 3.0 * q + 35.0 / 12.0 * q * q, dp = 3.0 + 35.0 / 6.0 * q,
                     d2p = 35.0 / 6.0;
        const double t4 = t * t * t * t, t5 = t4 * t, t6 = t5 * t;
        f = t6 * p;
        df = -3.0 * t5 * p + t6 * dp;
        d2f = 7.5 * t4 * p - 6.0 * t5 * dp + t6 * d2p;
      }
      return;
    }
    case MFREE_KERNEL_LINEAR:
      f = 0.25 * (2.0 - q);
      df = -0.25;
      d2f = 0.0;
      return;
    case MFREE_KERNEL_QUADRATIC: {
      const double t = 1.0 - 0.5 * q;
      f = t * t;
      df = -t;
      d2f = 0.5;
      return;
    }
    case MFREE_KERNEL_COSINE: {  // 004 eq 28: cos(pi t / d), docs/papers.md, 004 errata 1
      const double a = 0.5 * kPi;
      f = std::cos(a * q);
      df = -a * std::sin(a * q);
      d2f = -a * a * f;
      return;
    }
    case MFREE_KERNEL_COSINE_SQUARED: {  // (1 + cos(pi q)) / 2
      f = 0.5 * (1.0 + std::cos(kPi * q));
      df = -0.5 * kPi * std::sin(kPi * q);
      d2f = -0.5 * kPi * kPi * std::cos(kPi * q);
      return;
    }
    case MFREE_KERNEL_HAAR:  // closed box: 1 up to and including q = 1
      f = 1.0;
      return;
    default:
      return;
  }
}

}  // namespace mfree
