// Function multiversioning for the hot row kernels. The library is built for
// the baseline of its target (x86-64: SSE2, no -march) so that it runs on every machine;
// row kernels that profit from wider vectors and fused multiply-adds are compiled a
// second time for AVX2 + FMA, and the copy to run is chosen at run time from the CPU.
//
// Two ways to write the second copy (GCC and Clang on x86-64; elsewhere both macros
// are empty and MFREE_SIMD_X86 is 0, so the code compiles once, for the baseline):
//
//   1. A whole region of code (templates included) in its own namespace:
//        namespace base { <kernels> }
//        #if MFREE_SIMD_X86
//        MFREE_AVX2_BEGIN
//        namespace avx2 { <the same kernels, e.g. an #include of a .inc file> }
//        MFREE_AVX2_END
//        #endif
//      Every function *defined* between the two macros is compiled for AVX2 + FMA;
//      functions defined elsewhere (std::, Eigen) and inlined into them are too,
//      functions called out of line stay baseline. Keep the region's code in an
//      anonymous or ISA-named namespace: an inline function or template with external
//      linkage defined twice with different targets breaks the one-definition rule
//      (the linker may keep the AVX2 copy for baseline callers).
//   2. One function: MFREE_TARGET_AVX2 on its definition, with the body an
//      MFREE_ALWAYS_INLINE template shared with the baseline copy.
//
// Leave AVX2 code for baseline code with the upper halves of the vector registers zeroed
// (_mm256_zeroupper() before returning to a baseline caller, as shape_fast.cpp does):
// the compiler does this inside the AVX2 copy, but not at an indirect return to
// baseline SSE code, and on this project's machines the dirty state made the baseline
// code after it markedly slower (seen in the Randles-Libersky setup).
//
// Choose with simd::use_avx2() once per call (not per site): the answer depends only on
// the CPU and the environment, so every thread of a call runs the same copy and results
// stay bitwise identical for any thread count. The two copies may differ at round-off
// (FMA contracts a * b + c), so a host that needs bitwise reproducibility across
// machines sets MFREE_SIMD=baseline in the environment.
#pragma once

#include <cstdlib>
#include <cstring>

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
#define MFREE_TARGET_AVX2 __attribute__((target("avx2,fma")))
#if defined(__clang__)
#define MFREE_AVX2_BEGIN \
  _Pragma("clang attribute push(__attribute__((target(\"avx2,fma\"))), apply_to = function)")
#define MFREE_AVX2_END _Pragma("clang attribute pop")
#else
#define MFREE_AVX2_BEGIN _Pragma("GCC push_options") _Pragma("GCC target(\"avx2,fma\")")
#define MFREE_AVX2_END _Pragma("GCC pop_options")
#endif
#else
#define MFREE_TARGET_AVX2
#define MFREE_AVX2_BEGIN
#define MFREE_AVX2_END
#endif

namespace mfree {
namespace simd {

// True when the AVX2 + FMA copies may run: the CPU has both (and the OS saves the YMM
// state, which __builtin_cpu_supports checks) and MFREE_SIMD is not "baseline".
// Cheap enough to ask once per setup/update/step (the CPU model is read once by the
// compiler runtime; getenv is a scan of the environment).
inline bool use_avx2() {
#if MFREE_SIMD_X86
  const char *env = std::getenv("MFREE_SIMD");
  if (env && std::strcmp(env, "baseline") == 0) return false;
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
#else
  return false;
#endif
}

}  // namespace simd
}  // namespace mfree
