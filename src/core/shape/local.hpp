// Per-site shape functions: given the neighbours of one evaluation site, compute the
// rows of the value, gradient and Hessian tables for one method.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "core/base/alloc.hpp"
#include "core/base/basis.hpp"
#include "core/base/kernel.hpp"
#include "mfree.h"

namespace mfree {

struct LocalConfig {
  int method = MFREE_METHOD_MLS;
  int dim = 1;
  int order = 1;
  bool want_value = true, want_grad = true, want_hess = false;
  const Kernel *kernel = nullptr;
};

// Inputs of one site: n neighbours j with displacement d_j = x_j - x (3 per j),
// volume V_j and pair support h_j; `self` is the position of the site itself in the
// list (-1 at a host point); hs is the site's own length scale.
struct LocalInput {
  int n = 0;
  int self = -1;
  double hs = 1.0;
  const double *d = nullptr;
  const double *vol = nullptr;
  const double *h = nullptr;
};

// Outputs: rows phi[n], grad[n*dim], hess[n*nh] (only the wanted ones are written).
struct LocalOutput {
  double *phi = nullptr, *grad = nullptr, *hess = nullptr;
  // When set, the site's correction data (the layout of mfree_approximant_get_correction)
  // for Shepard, MLS/RKPM, Johnson-Beissel, Randles-Libersky and KB Method 1.
  double *coef = nullptr;
  int status = 0;       // 0 or MFREE_FAIL_*
  double cond = 1.0;    // condition estimate of the local system
  int order_used = 0;   // order actually built (after fallback), -1 failed
  int support = 0;      // neighbours with non-zero weight
};

// Scratch space reused between sites (no allocation once large enough).
struct LocalWork {
  HVec<double> r, w, gw, hw, p, q, sh;
  void reserve(int n, int dim, int L);
};

// Compute one site with the configured method and order (no fallback).
void compute_site(const LocalConfig &cfg, const LocalInput &in, LocalWork &work,
                  LocalOutput &out);

// One site with the approximants' rules (Approximant::set_fallback, set_shepard_condition):
// compute_site unless done (a fast path's result stands but for the rows: out.status 0 and
// out.cond set by the caller); with fallback MFREE_FALLBACK_LOWER_ORDER, where that failed,
// the lower orders down to the method's least, then Shepard functions (the first failure
// kept when all fail); where the site succeeded with a condition estimate above
// shepard_cond, Shepard functions of the volume-weighted kernel with that estimate kept.
// A site that falls back or goes to Shepard gets a record (out.coef, ncoef doubles) of zeros.
void compute_site_rules(LocalConfig cfg, const LocalInput &in, LocalWork &work, LocalOutput &out,
                        int fallback, double shepard_cond, bool done, int ncoef);

// The kernel at d = x_j - x (dim values) with support h: r = |d|, the value w and its
// gradient with respect to x, gw = -W'(r) d / r (0 at r = 0), as every table computes
// them; dw = W'(r), d2w = W''(r).
inline void kernel_at(const Kernel &k, int dim, const double *d, double h, double &r, double &w,
                      double &dw, double &d2w, double *gw) {
  double r2 = 0.0;
  for (int c = 0; c < dim; ++c) r2 += d[c] * d[c];
  r = std::sqrt(r2);
  k.eval(r, h, w, dw, d2w);
  for (int c = 0; c < dim; ++c) gw[c] = r > 0.0 ? -dw * d[c] / r : 0.0;
}

// The gradient of one neighbour j's shape function at a site per unit volume (the row's
// entry divided by V_j) from the site's correction record (LocalOutput::coef, the
// layout of mfree_approximant_get_correction) and the kernel at the pair: what a
// process that holds the record but not the site's row (a ghost's owner sent it)
// computes as well as the owner. Equal to the rows' entries / V_j to round-off. For
// Shepard, MLS/RKPM of order <= 2, Johnson-Beissel, Randles-Libersky and KB Method 1
// (cfg.method, cfg.order, cfg.dim).
class RecordGradient {
 public:
  explicit RecordGradient(const LocalConfig &cfg);
  // d = x_j - x (3 values), w and gw the kernel and its gradient there (kernel_at), vol
  // V_j, hs the site's length scale; writes dim values to g.
  void operator()(const double *rec, double hs, const double *d, double w, const double *gw,
                  double vol, double *g) const;

 private:
  LocalConfig cfg_;
  Basis basis_;
};

// Natural order reported for a method without a polynomial order.
int fixed_order(int method);
// Smallest order a polynomial method accepts (fallback stops there, then Shepard).
int min_order(int method);
int max_order(int method);
bool has_order(int method);
bool particles_only(int method);
bool provides_hessian(int method, int order);

}  // namespace mfree
