// Kernel shapes that a fast path evaluates inline: the one definition of each, used by
// Kernel::shape (kernel.cpp) and by the fast paths that specialise on the kernel (the
// shape functions' fused rows). W(r, h) = c / h^dim f(r / h); the normalisation c is
// Kernel::norm(), computed once in kernel.cpp. Every other kernel is defined in
// Kernel::shape only; one that a fast path specialises moves here.
#pragma once

#include "core/base/simd.hpp"

namespace mfree {

// The cubic spline (M4): f = a0 + a2 q^2 + a3 q^3 on [0, 1), b3 t^3 on [1, 2], t = 2 - q.
// The fast paths fold the coefficients, named here, into their own constants.
struct CubicSplineShape {
  static constexpr double kRadius = 2.0;
  static constexpr double a0 = 1.0, a2 = -1.5, a3 = 0.75;
  static constexpr double b3 = 0.25;

  // the inner piece (q < 1): f, f', f''
  MFREE_ALWAYS_INLINE static double inner(double q) { return a0 + a2 * q * q + a3 * q * q * q; }
  MFREE_ALWAYS_INLINE static double inner_d(double q) { return 2.0 * a2 * q + 3.0 * a3 * q * q; }
  MFREE_ALWAYS_INLINE static double inner_d2(double q) { return 2.0 * a2 + 6.0 * a3 * q; }
  // the outer piece (1 <= q <= 2) in t = 2 - q: f, f' (d/dq), f''
  MFREE_ALWAYS_INLINE static double outer(double t) { return b3 * t * t * t; }
  MFREE_ALWAYS_INLINE static double outer_d(double t) { return -3.0 * b3 * t * t; }
  MFREE_ALWAYS_INLINE static double outer_d2(double t) { return 6.0 * b3 * t; }
};

}  // namespace mfree
