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
#include "core/shape/shape_fast.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <type_traits>

#include "core/base/kernel_eval.hpp"
#include "core/base/simd.hpp"
#include "core/base/small_dense.hpp"
#include "core/shape/local.hpp"
#include "core/shape/shape_fast_mls1.hpp"

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
#if defined(__GNUC__) || defined(__clang__)
#define MFREE_LAMBDA_INLINE __attribute__((always_inline))
#else
#define MFREE_LAMBDA_INLINE
#endif
#define MFREE_UNROLL _Pragma("GCC unroll 64")

// Four neighbours at a time in GCC/Clang vector extensions (simd.hpp): AVX2 registers in
// the AVX2 copy, pairs of SSE2 (or NEON) registers in the baseline one.
#define MFREE_VEC4 MFREE_VECTOR_EXTENSIONS

namespace mfree {

namespace {

#if MFREE_VEC4
using simd::I4;
using simd::V4;
#endif

// The row kernels, compiled for the baseline target and, on x86-64 with GCC or Clang,
// once more for AVX2 + FMA; FastPath picks one copy per call from the CPU (simd.hpp),
// so every thread of a call runs the same code.
#define MFREE_ROWS_AVX2 0
namespace base {
#include "core/shape/shape_fast_rows.inc"
}  // namespace base
#undef MFREE_ROWS_AVX2

#if MFREE_SIMD_X86
#define MFREE_ROWS_AVX2 1
MFREE_AVX2_BEGIN
namespace avx2 {
#include "core/shape/shape_fast_rows.inc"

// The caller (baseline code) goes on with SSE instructions: return with the upper
// halves of the vector registers zeroed.
template <int D, class Kern>
void block_fn_ret(const FastPath &fp, const FastTables &t, int64_t b, int64_t e, FastScratch &w,
                  const FastSites &out) {
  block_fn<D, Kern>(fp, t, b, e, w, out);
  MFREE_ZERO_UPPER();
}
}  // namespace avx2
MFREE_AVX2_END
#undef MFREE_ROWS_AVX2
#endif

}  // namespace

void FastScratch::reserve(int maxrow) {
  // whole groups of four neighbours (the fused rows write the padded group)
  const int need = (maxrow + 4) / 4 * 4;
  if (need <= cap) return;
  cap = need;
  buf.assign(static_cast<size_t>(cap) * 14, 0.0);
  sval.assign(static_cast<size_t>(cap), 0.0);
  sgrad.assign(static_cast<size_t>(cap) * 3, 0.0);
}

FastPath::FastPath(int dim, int method, int order, const Kernel &kernel, int flags)
    : method_(method), order_(order), kernel_(&kernel) {
  if (!optimised()) return;  // the reference backend (config.hpp) runs the general path
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
    filters_ = dim == 2 && cubic && method == MFREE_METHOD_MLS && order == 1 && mls1_rows2_available() &&
               (flags & MFREE_DERIV_VALUE) && (flags & MFREE_DERIV_GRADIENT);
    switch (dim) {
      case 1: fn_ = cubic ? &block_fn_ret<1, CubicSpline> : &block_fn_ret<1, AnyShape>; break;
      case 2: fn_ = cubic ? &block_fn_ret<2, CubicSpline> : &block_fn_ret<2, AnyShape>; break;
      default: fn_ = cubic ? &block_fn_ret<3, CubicSpline> : &block_fn_ret<3, AnyShape>; break;
    }
    return;
  }
#endif
  using namespace base;
  switch (dim) {
    case 1: fn_ = cubic ? &block_fn<1, CubicSpline> : &block_fn<1, AnyShape>; break;
    case 2: fn_ = cubic ? &block_fn<2, CubicSpline> : &block_fn<2, AnyShape>; break;
    default: fn_ = cubic ? &block_fn<3, CubicSpline> : &block_fn<3, AnyShape>; break;
  }
}

}  // namespace mfree
