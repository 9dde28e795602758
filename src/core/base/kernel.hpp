// Radial smoothing kernels W(r, h) = c / h^dim * f(r / h).
#pragma once

#include <cstdint>

#include "mfree.h"

namespace mfree {

// Supports are closed: a distance within this relative tolerance of the support radius
// counts as on the support (paper 001's d <= 2), so that pairs exactly on the edge are
// treated alike whatever the round-off of their coordinates. The neighbour search, the
// approximant's pattern and the kernel use the same rule.
constexpr double kEdgeTol = 1e-13;
// Squared-distance form: d^2 within lim^2 (1 + kEdgeTol)^2.
constexpr double kEdgeTol2 = 2.0 * kEdgeTol;

class Kernel {
 public:
  // Throws Error(MFREE_ERR_ARG) for an unknown kernel, a dimension outside 1..3 or a
  // bad shape parameter.
  Kernel(int kernel, int dim, double param);

  int id() const { return id_; }
  int dim() const { return dim_; }
  double param() const { return a_; }
  double radius() const { return radius_; }  // support radius in units of h
  double norm() const { return c_; }         // c in W = c / h^dim f(q)

  // Shape f(q) and its derivatives; zero for q >= radius().
  void shape(double q, double &f, double &df, double &d2f) const;
  double shape(double q) const;

  // W, dW/dr, d2W/dr2 at distance r for smoothing length h.
  void eval(double r, double h, double &w, double &dw, double &d2w) const {
    const double ih = 1.0 / h;
    double f, df, d2f;
    shape(r * ih, f, df, d2f);
    double s = c_;
    for (int d = 0; d < dim_; ++d) s *= ih;
    w = s * f;
    dw = s * ih * df;
    d2w = s * ih * ih * d2f;
  }
  double value(double r, double h) const {
    const double ih = 1.0 / h;
    double s = c_;
    for (int d = 0; d < dim_; ++d) s *= ih;
    return s * shape(r * ih);
  }

  // Support radius for a kernel id without building it (Error on unknown id).
  static double support_radius(int kernel, double param);
  static bool valid_id(int kernel);

 private:
  int id_;
  int dim_;
  double a_;
  double radius_;
  double c_;
};

}  // namespace mfree
