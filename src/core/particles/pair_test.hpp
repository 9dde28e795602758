// The neighbour search's pair test under the gather convention, for code that filters a
// particle set's candidate lists itself (ParticleSet::set_rows_left): particle j is in
// the row of site i when |x_j - x_i|^2 <= (kappa h_i)^2 (1 + kEdgeTol2), the closed
// support, with the squared distance summed as the scans sum it ((d0^2 + d1^2) + d2^2,
// every product rounded: neighbors_cell_grid_scan.inc), so that a row filtered here is a
// fresh search's row bit for bit. The set's own filter of the candidates
// (neighbors_verlet.inc) takes its four-lane test from here too.
#pragma once

#include "core/base/kernel.hpp"
#include "core/base/simd.hpp"

namespace mfree {
namespace pair_test {

// The limit on the squared distance of the site with search radius ri = kappa h_i.
inline double limit2(double ri) { return ri * ri * (1.0 + kEdgeTol2); }

#if MFREE_SIMD_X86 && MFREE_VECTOR_EXTENSIONS
MFREE_AVX2_BEGIN
// Bit l set when the candidate with offsets (e0[l], e1[l]) from the site (2D; either
// sign: the squares are the same) is within lim2 = limit2(ri). The empty asm keeps the
// two products rounded in a file compiled with contraction (the approximants' fast
// path), where the sum would become a fused multiply-add.
MFREE_ALWAYS_INLINE int within4(const simd::V4 &e0, const simd::V4 &e1, const simd::V4 &lim2) {
  simd::V4 p0 = e0 * e0, p1 = e1 * e1;
  __asm__("" : "+x"(p0), "+x"(p1));
  return simd::x86::movemask(p0 + p1 <= lim2);
}
MFREE_AVX2_END
#endif

}  // namespace pair_test
}  // namespace mfree
