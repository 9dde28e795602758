// Fast path of the value + gradient tables (see shape_fast.hpp). The formulas are those
// of local.cpp (same notation: d_j = x_j - x, s_j = d_j / hs, w_j = W(|d_j|, h_j),
// grad_x w_j = gf_j d_j with the radial factor gf_j = -W'(r_j) / r_j); only the
// arithmetic is arranged differently, so that tables agree with the general path to
// round-off (tests t404 against an O(N^2) oracle, t432 against the general path).
//
// Moments: for a monomial basis p of order K, the entries of M = sum w p p^T and of its
// derivatives M_,i = sum gf d_i p p^T are sums of single monomials, M_ab = sum w s^(a+b)
// and (M_,i)_ab = hs sum gf s^(a+b+e_i). So one neighbour pass accumulates the
// binom(2K+D, D) moments of w and the binom(2K+1+D, D) moments of gf (for 2D order 2:
// 15 + 21 sums instead of 3 x 21 matrix entries), in loops of fixed even length that the
// compiler vectorises.
#include "shape_fast.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "local.hpp"
#include "simd.hpp"

#if MFREE_SIMD_X86
#include <immintrin.h>
#endif

// Loops over the neighbours of a site: vectorised even at -O2 when OpenMP is on (the
// simd loops carry no dependence between neighbours); loops of compile-time length over
// monomials and small matrices: unrolled, so that their indices fold and the
// accumulators stay in registers.
#ifdef _OPENMP
#define MFREE_SIMD _Pragma("omp simd")
#define MFREE_SIMD_SUM(v) _Pragma(MFREE_STR(omp simd reduction(+ : v)))
#else
#define MFREE_SIMD
#define MFREE_SIMD_SUM(v)
#endif
#define MFREE_STR(x) #x
#define MFREE_UNROLL _Pragma("GCC unroll 64")

// Four neighbours at a time in GCC/Clang vector extensions: AVX2 registers in the AVX2
// copy, pairs of SSE2 (or NEON) registers in the baseline one. Only in locals, never
// passed by value (whose ABI would differ between the copies).
#if defined(__GNUC__) || defined(__clang__)
#define MFREE_VEC4 1
typedef double V4 __attribute__((vector_size(32)));
#else
#define MFREE_VEC4 0
#endif

namespace mfree {

namespace {

// The row kernels, compiled for the baseline target and, on x86-64 with GCC or Clang,
// once more for AVX2 + FMA; FastPath picks one copy per call from the CPU (simd.hpp),
// so every thread of a call runs the same code.
namespace base {
#include "shape_fast_rows.inc"
}  // namespace base

#if MFREE_SIMD_X86
MFREE_AVX2_BEGIN
namespace avx2 {
#include "shape_fast_rows.inc"

// The caller (baseline code) goes on with SSE instructions: return with the upper
// halves of the vector registers zeroed.
template <int D, class Kern>
int site_fn_ret(const FastPath &fp, const FastTables &t, int32_t s, FastScratch &w, int &support,
                double &cond) {
  const int r = site_fn<D, Kern>(fp, t, s, w, support, cond);
  _mm256_zeroupper();
  return r;
}
}  // namespace avx2
MFREE_AVX2_END
#endif

}  // namespace

void FastScratch::reserve(int maxrow) {
  if (maxrow <= cap) return;
  cap = maxrow;
  buf.assign(static_cast<size_t>(cap) * 10, 0.0);
}

FastPath::FastPath(int dim, int method, int order, const Kernel &kernel, int flags)
    : method_(method), order_(order), kernel_(&kernel) {
  if (flags & MFREE_DERIV_HESSIAN) return;
  if (dim < 1 || dim > 3) return;
  // LDL^T without pivoting needs non-negative weights
  const int k = kernel.id();
  if (k == MFREE_KERNEL_SUPER_GAUSS || k == MFREE_KERNEL_REVISED_SUPER_GAUSS) return;
  switch (method) {
    case MFREE_METHOD_SPH:
    case MFREE_METHOD_SPH_SYMMETRIC:
    case MFREE_METHOD_SHEPARD:
    case MFREE_METHOD_JOHNSON_BEISSEL:
    case MFREE_METHOD_RANDLES_LIBERSKY:
    case MFREE_METHOD_KB_METHOD1:
      break;
    case MFREE_METHOD_MLS:
    case MFREE_METHOD_RKPM:
      if (order < 0 || order > 2) return;
      break;
    case MFREE_METHOD_SSPH:
      if (order < 1 || order > 2) return;
      break;
    default:
      return;
  }
  const bool cubic = k == MFREE_KERNEL_CUBIC_SPLINE;
#if MFREE_SIMD_X86
  if (simd::use_avx2()) {
    using namespace avx2;
    switch (dim) {
      case 1: fn_ = cubic ? &site_fn_ret<1, CubicSpline> : &site_fn_ret<1, AnyShape>; break;
      case 2: fn_ = cubic ? &site_fn_ret<2, CubicSpline> : &site_fn_ret<2, AnyShape>; break;
      default: fn_ = cubic ? &site_fn_ret<3, CubicSpline> : &site_fn_ret<3, AnyShape>; break;
    }
    return;
  }
#endif
  using namespace base;
  switch (dim) {
    case 1: fn_ = cubic ? &site_fn<1, CubicSpline> : &site_fn<1, AnyShape>; break;
    case 2: fn_ = cubic ? &site_fn<2, CubicSpline> : &site_fn<2, AnyShape>; break;
    default: fn_ = cubic ? &site_fn<3, CubicSpline> : &site_fn<3, AnyShape>; break;
  }
}

}  // namespace mfree
