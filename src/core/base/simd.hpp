// SIMD in mfree: one style, one dispatch (docs/performance.md, "Vector instructions").
//
// The library is built for the baseline of its target (x86-64: SSE2, no -march) so that
// it runs on every machine; kernels that profit from wider vectors and fused
// multiply-adds are compiled a second time for AVX2 + FMA, and the copy to run is chosen
// at run time from the CPU. Every vector kernel is written the same way:
//
//   1. Once, as portable C++: templates with loops of compile-time length and, where the
//      lanes must be explicit, GCC/Clang vector extensions (V2, V4 below, loaded and
//      stored with simd::load / simd::store). Arithmetic is written as arithmetic
//      (acc += g * u); the AVX2 copy contracts it to fused multiply-adds.
//   2. Compiled twice by region, in an anonymous namespace of the .cpp:
//        namespace base { <kernels> }
//        #if MFREE_SIMD_X86
//        MFREE_AVX2_BEGIN
//        namespace avx2 { <the same kernels, e.g. an #include of a .inc file> }
//        MFREE_AVX2_END
//        #endif
//      Every function *defined* between the two macros is compiled for AVX2 + FMA;
//      functions defined elsewhere (std::, Eigen) and inlined into them are too,
//      functions called out of line stay baseline. Never give a region's code external
//      linkage: an inline function or template defined twice with different targets
//      breaks the one-definition rule (the linker may keep the AVX2 copy for baseline
//      callers). No per-function target attributes; an intrinsic only for what the
//      extensions cannot say (a masked load, a movemask), inside the region.
//   3. Chosen once per call with simd::use_avx2(), before any parallel region, so that
//      every thread of a call runs the same copy and results stay bitwise identical for
//      any thread count. The reference backend (config.hpp) takes no vector path.
//
// An AVX2 function called through a pointer from baseline code returns through
// MFREE_ZERO_UPPER(): the compiler clears the upper halves of the vector registers inside
// the AVX2 copy but not at an indirect return to baseline SSE code, and the dirty state
// made the baseline code after it markedly slower on this project's machines (seen in
// the Randles-Libersky setup).
//
// The two copies may differ at round-off (FMA contracts a * b + c), so a host that needs
// bitwise reproducibility across machines sets MFREE_SIMD=baseline in the environment
// (read in config.cpp) or runs the reference backend.
#pragma once

#include <cstdint>
#include <cstring>

#include "core/base/config.hpp"

#if (defined(__GNUC__) || defined(__clang__)) && (defined(__x86_64__) || defined(__i386__)) && \
    !defined(MFREE_NO_SIMD_DISPATCH)
#define MFREE_SIMD_X86 1
#else
#define MFREE_SIMD_X86 0
#endif

#if defined(__GNUC__) || defined(__clang__)
#define MFREE_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define MFREE_ALWAYS_INLINE inline
#endif

#if MFREE_SIMD_X86
#if defined(__clang__)
#define MFREE_AVX2_BEGIN \
  _Pragma("clang attribute push(__attribute__((target(\"avx2,fma\"))), apply_to = function)")
#define MFREE_AVX2_END _Pragma("clang attribute pop")
#else
#define MFREE_AVX2_BEGIN _Pragma("GCC push_options") _Pragma("GCC target(\"avx2,fma\")")
#define MFREE_AVX2_END _Pragma("GCC pop_options")
#endif
#else
#define MFREE_AVX2_BEGIN
#define MFREE_AVX2_END
#endif

namespace mfree {
namespace simd {

#if defined(__GNUC__) || defined(__clang__)
#define MFREE_VECTOR_EXTENSIONS 1
// Two and four doubles: SSE2 / AVX2 registers (NEON pairs on arm64). Only in locals of a
// region's functions, never passed by value across a call (whose ABI differs between
// the copies).
typedef double V2 __attribute__((vector_size(16)));
typedef double V4 __attribute__((vector_size(32)));
#else
#define MFREE_VECTOR_EXTENSIONS 0
#endif

// N consecutive doubles at p into the low lanes of v (the others 0); no alignment.
// Vectors go by reference (a 32-byte vector by value has another ABI in each copy).
// Lanes are set one by one below the full width: a memcpy into part of a vector goes
// through the stack and stalls the load that reads it back.
template <int N, class V>
MFREE_ALWAYS_INLINE void load(V &v, const double *p) {
  if constexpr (N * sizeof(double) == sizeof(V)) {
    std::memcpy(&v, p, sizeof(V));
  } else if constexpr (sizeof(V) == 2 * sizeof(double)) {
    v = V{p[0], 0.0};
  } else if constexpr (N == 1) {
    v = V{p[0], 0.0, 0.0, 0.0};
  } else if constexpr (N == 2) {
    v = V{p[0], p[1], 0.0, 0.0};
  } else {
    v = V{p[0], p[1], p[2], 0.0};
  }
}
template <int N>
MFREE_ALWAYS_INLINE void load(double &v, const double *p) { v = *p; }

#if MFREE_VECTOR_EXTENSIONS
typedef long long I4 __attribute__((vector_size(32)));
// Lanes of two V4 a, b (indices 0-3: a, 4-7: b), e.g. MFREE_SHUF(a, b, 0, 4, 2, 6).
#if defined(__clang__)
#define MFREE_SHUF(a, b, i, j, k, l) __builtin_shufflevector(a, b, i, j, k, l)
#else
#define MFREE_SHUF(a, b, i, j, k, l) __builtin_shuffle(a, b, ::mfree::simd::I4{i, j, k, l})
#endif

// {lo, hi}: two V2 into one V4 (in the AVX2 copy one vinsertf128, from memory when lo
// and hi were just loaded).
MFREE_ALWAYS_INLINE void concat(V4 &v, const V2 &lo, const V2 &hi) {
#if defined(__clang__) || __GNUC__ >= 12
  v = __builtin_shufflevector(lo, hi, 0, 1, 2, 3);
#else
  v = V4{lo[0], lo[1], hi[0], hi[1]};
#endif
}

// The sum of the lanes, in the one order of every horizontal sum: (v0 + v1) + (v2 + v3).
MFREE_ALWAYS_INLINE double hsum(const V4 &v) { return (v[0] + v[1]) + (v[2] + v[3]); }
// r[k] = hsum(v_k) for four vectors at once (bitwise the same sums as hsum).
MFREE_ALWAYS_INLINE void hsum4(const V4 &a, const V4 &b, const V4 &c, const V4 &d, double *r) {
  const V4 ab = MFREE_SHUF(a, b, 0, 4, 2, 6) + MFREE_SHUF(a, b, 1, 5, 3, 7);  // a01 b01 a23 b23
  const V4 cd = MFREE_SHUF(c, d, 0, 4, 2, 6) + MFREE_SHUF(c, d, 1, 5, 3, 7);
  const V4 s = MFREE_SHUF(ab, cd, 0, 1, 4, 5) + MFREE_SHUF(ab, cd, 2, 3, 6, 7);
  std::memcpy(r, &s, sizeof(V4));
}

// v = {v1, v2, v3, v0}: lanes 1-3 down to 0-2.
MFREE_ALWAYS_INLINE void rotate_down(V4 &v) {
#if defined(__clang__)
  v = __builtin_shufflevector(v, v, 1, 2, 3, 0);
#else
  typedef long long I4 __attribute__((vector_size(32)));
  v = __builtin_shuffle(v, I4{1, 2, 3, 0});
#endif
}
#endif

// The low N lanes of v to p.
template <int N, class V>
MFREE_ALWAYS_INLINE void store(double *p, const V &v) {
  std::memcpy(p, &v, N * sizeof(double));
}

// Lane i of v (v itself for a scalar).
template <class V>
MFREE_ALWAYS_INLINE double lane(const V &v, int i) { return v[i]; }
MFREE_ALWAYS_INLINE double lane(double v, int) { return v; }

#if MFREE_SIMD_X86
// Clears the upper halves of the vector registers (vzeroupper); call only in AVX2 code.
#define MFREE_ZERO_UPPER() __builtin_ia32_vzeroupper()

// What the vector extensions cannot say (or GCC does not compile to one instruction), for
// the AVX2 copies only (defined in the region: a call from baseline code does not
// compile): the square root and the minimum of a vector, a
// comparison's sign bits gathered into an int, a byte shuffle and a lane permutation by
// indices known only at run time (Clang's extensions have none) and a masked load (the lanes it skips are
// never read, so they may lie past the end of an array).
MFREE_AVX2_BEGIN
namespace x86 {
typedef char B16 __attribute__((vector_size(16)));
typedef int I8 __attribute__((vector_size(32)));
MFREE_ALWAYS_INLINE V4 sqrt(const V4 &x) { return __builtin_ia32_sqrtpd256(x); }
// a < b ? a : b lane by lane in one instruction (GCC compiles the select to a compare and
// a blend).
MFREE_ALWAYS_INLINE V4 min(const V4 &a, const V4 &b) { return __builtin_ia32_minpd256(a, b); }
// Bit k set when lane k of the comparison result m of two V4 is true.
template <class M>
MFREE_ALWAYS_INLINE int movemask(const M &m) {
  static_assert(sizeof(M) == sizeof(V4), "a comparison of two V4");
  return __builtin_ia32_movmskpd256((V4)m);
}
// r[i] = v[idx[i]], or 0 where idx[i] has its top bit set (pshufb).
MFREE_ALWAYS_INLINE B16 shuffle_bytes(const B16 &v, const B16 &idx) { return __builtin_ia32_pshufb128(v, idx); }
// r = the 32-bit lanes of v reordered by idx (vpermps, across the halves): four doubles
// left-packed by a table of index pairs.
MFREE_ALWAYS_INLINE V4 permute32(const V4 &v, const I8 &idx) {
  typedef float F8 __attribute__((vector_size(32)));
  return (V4)__builtin_ia32_permvarsf256((F8)v, idx);
}
// The lanes of p where mask has its top bit set, 0 elsewhere.
MFREE_ALWAYS_INLINE I8 maskload(const int32_t *p, const I8 &mask) {
  return __builtin_ia32_maskloadd256(reinterpret_cast<const I8 *>(p), mask);
}
}  // namespace x86
MFREE_AVX2_END
#endif

// Whether v[0 .. n) are all finite. x - x is 0 for a finite x and NaN for an infinite or
// NaN one, so sums of such differences stay 0 exactly when every x is finite: one pass
// without a branch, in two-lane vectors with two independent sums, because the compiler
// leaves a loop of comparisons (|x| <= DBL_MAX) scalar. For passes over every table
// entry or every coordinate of a call; the caller looks for the culprit only when false.
inline bool all_finite(const double *v, int64_t n) {
  double rest = 0.0;
  int64_t k = 0;
#if MFREE_VECTOR_EXTENSIONS
  V2 a = {0.0, 0.0}, b = {0.0, 0.0};
  for (; k + 4 <= n; k += 4) {
    V2 x, y;
    load<2>(x, v + k);
    load<2>(y, v + k + 2);
    a += x - x;
    b += y - y;
  }
  a += b;
  rest = a[0] + a[1];
#endif
  for (; k < n; ++k) rest += v[k] - v[k];
  return rest == 0.0;
}

// True when the AVX2 + FMA copies may run: the running call is on the optimised backend
// (the reference backend runs the baseline copies of every kernel that has no reference
// path of its own: the fluid, the neighbour search), the CPU has both (and the OS saves
// the YMM state, which __builtin_cpu_supports checks) and MFREE_SIMD is not "baseline".
// Cheap enough to ask once per setup/update/apply (the CPU model is read once by the
// compiler runtime; the override is one scan of the environment).
inline bool use_avx2() {
#if MFREE_SIMD_X86
  if (!optimised() || env::simd_baseline()) return false;
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
#else
  return false;
#endif
}

}  // namespace simd
}  // namespace mfree
