// Fused rows of linear MLS in 2D with the cubic spline, for AVX2 + FMA: the fast path's
// (shape_fast.hpp) specialisation of the most common configuration of a moving-particle
// code (paper 003's Galerkin SPH), taken for value + gradient tables under the gather
// convention without a periodic axis and without correction records.
#pragma once

#include <cstdint>

#include "core/shape/shape_fast.hpp"

namespace mfree {

// Whether the fused rows exist in this build (x86-64 with GCC or Clang).
bool mls1_rows2_available();

// The rows of sites [b, e) as FastPath::run writes them (FastSites): status 0 with the
// support and the condition number of the moment matrix where the MLS rows are done,
// kFastPending where the moment matrix is not positive definite or is singular to the
// general path's threshold min_rcond on the reciprocal condition number (the general
// path decides). With t.kept, the rows are filtered from candidate lists as
// FastTables says. Call only when simd::use_avx2() and mls1_rows2_available().
void mls1_rows2_avx2(const FastTables &t, int64_t b, int64_t e, double min_rcond,
                     FastScratch &w, const FastSites &out);

}  // namespace mfree
