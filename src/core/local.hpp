// Per-site shape functions: given the neighbours of one evaluation site, compute the
// rows of the value, gradient and Hessian tables for one method.
#pragma once

#include <cstdint>
#include <vector>

#include "alloc.hpp"
#include "basis.hpp"
#include "kernel.hpp"
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

// Natural order reported for a method without a polynomial order.
int fixed_order(int method);
// Smallest order a polynomial method accepts (fallback stops there, then Shepard).
int min_order(int method);
int max_order(int method);
bool has_order(int method);
bool particles_only(int method);
bool provides_hessian(int method, int order);

}  // namespace mfree
