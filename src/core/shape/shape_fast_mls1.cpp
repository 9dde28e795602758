// Fused rows of linear MLS in 2D with the cubic spline (shape_fast_mls1.hpp), in AVX2 +
// FMA intrinsics: the fast path's general MLS rows (shape_fast_rows.inc) gather a row's
// neighbours into scratch, accumulate the moments and factorise in separate passes; here
// the whole row stays in registers, and the 3x3 moment matrix is inverted in closed form.
// Same functions as the general path to round-off (tests t404, t432).
#include "core/shape/shape_fast_mls1.hpp"

#include <algorithm>
#include <cmath>

#include "core/base/kernel_eval.hpp"
#include "core/base/simd.hpp"

#if MFREE_SIMD_X86
#include <immintrin.h>
#endif

namespace mfree {

#if MFREE_SIMD_X86

bool mls1_rows2_available() { return true; }

#if defined(__GNUC__) || defined(__clang__)
#define MLS1_INLINE_LAMBDA __attribute__((always_inline))
#else
#define MLS1_INLINE_LAMBDA
#endif

// (the region's lambdas are compiled for AVX2 + FMA too, which a target attribute on the
// enclosing function alone would not give them)
MFREE_AVX2_BEGIN
namespace {

// sum of the four lanes of each of a, b, c, d: (sum a, sum b, sum c, sum d)
MFREE_TARGET_AVX2 MFREE_ALWAYS_INLINE __m256d hsum4(__m256d a, __m256d b, __m256d c, __m256d d) {
  const __m256d ab = _mm256_hadd_pd(a, b), cd = _mm256_hadd_pd(c, d);  // (a01, b01, a23, b23), ...
  return _mm256_add_pd(_mm256_permute2f128_pd(ab, cd, 0x20), _mm256_permute2f128_pd(ab, cd, 0x31));
}

}  // namespace

// One row s: (A) the scaled offsets s_j = (x_j - x_s) / h_s four neighbours at a time
// (positions by two 128-bit loads per pair of lanes, cheaper than gathers here); (B) r =
// |s_j|, the cubic spline's shape f = 1 - 3/2 r^2 + 3/4 r^3 (r < 1), (2 - r)^3 / 4
// (1 <= r < 2) and gf = -f'(r) / r = 3 - 9/4 r, 3/4 (2 - r)^2 / r in Horner form with a
// blend, and the 15 moment sums in registers (6 with the weights, 9 in a second loop
// over the stored gf); (C) the 3x3 moment matrix inverted by its adjugate, positive
// definiteness by its leading minors (Sylvester; the LDL^T pivots up to rounding), its
// exact 1-norm condition number (which bounds the pivot ratio the general path also
// takes, so both report the same number); (D) the values and gradients four at a time,
// the gradients interleaved (x, y) by two unpacks and two lane permutes. The last group
// of a row is padded with the row's first neighbour, its weights masked to zero, and
// stored through masks: the next row, or the next block (another thread), starts right
// after it. The weights lack the kernel's factor c0 / h^2 (the rows do not depend on it);
// the 1 / h of the derivatives is applied after the sums.
MFREE_TARGET_AVX2 void mls1_rows2_avx2(const FastTables &t, int64_t b, int64_t e, double min_rcond,
                                       FastScratch &ws, const FastSites &out) {
  const __m256i lane = _mm256_setr_epi64x(0, 1, 2, 3), lane2 = _mm256_setr_epi64x(4, 5, 6, 7);
  const __m256d one = _mm256_set1_pd(1.0), two = _mm256_set1_pd(2.0), zero = _mm256_setzero_pd();
  // scratch rows of 2 cap doubles each: room for a whole padded group past any row
  double *sx = ws.d(0), *sy = ws.d(2), *wv = ws.d(4), *gv = ws.d(6);
  const double *P = t.x[0];
  const int64_t ps = t.stride;
  for (int64_t s = b; s < e; ++s) {
    if (out.pst && out.pst[s] != 0) {  // failed in the set: an empty row
      out.status[s] = out.pst[s];
      out.support[s] = 0;
      out.cond[s] = 1.0;
      out.order[s] = -1;
      continue;
    }
    const int64_t k0 = t.rowptr[s];
    const int n = static_cast<int>(t.rowptr[s + 1] - k0);
    const int32_t *cc = t.cols + k0;
    double *Nk = t.val + k0, *Gk = t.grad + 2 * k0;
    const double hs = t.sh[s * t.shstride], ih = 1.0 / hs;
    const __m256d ihv = _mm256_set1_pd(ih);
    const __m256d xk = _mm256_set1_pd(t.sx[0][s * t.sstride]), yk = _mm256_set1_pd(t.sx[1][s * t.sstride]);
    // (A) offsets
    auto offsets4 = [&](const int32_t *j, int m) MLS1_INLINE_LAMBDA {
      const __m128d p0 = _mm_loadu_pd(P + ps * j[0]), p1 = _mm_loadu_pd(P + ps * j[1]);
      const __m128d p2 = _mm_loadu_pd(P + ps * j[2]), p3 = _mm_loadu_pd(P + ps * j[3]);
      const __m256d lo = _mm256_insertf128_pd(_mm256_castpd128_pd256(p0), p2, 1);  // x0 y0 x2 y2
      const __m256d hi = _mm256_insertf128_pd(_mm256_castpd128_pd256(p1), p3, 1);  // x1 y1 x3 y3
      const __m256d dx = _mm256_sub_pd(_mm256_unpacklo_pd(lo, hi), xk), dy = _mm256_sub_pd(_mm256_unpackhi_pd(lo, hi), yk);
      _mm256_storeu_pd(sx + m, _mm256_mul_pd(dx, ihv));
      _mm256_storeu_pd(sy + m, _mm256_mul_pd(dy, ihv));
    };
    int m = 0;
    for (; m + 4 <= n; m += 4) offsets4(cc + m, m);
    if (m < n) {
      const int rest = n - m;  // 1, 2 or 3 (a loop here became a call of memcpy)
      const int32_t jt[4] = {cc[m], rest > 1 ? cc[m + 1] : cc[0], rest > 2 ? cc[m + 2] : cc[0], cc[0]};
      offsets4(jt, m);
    }
    // (B) weights and moments
    __m256d a0 = zero, a1 = zero, a2 = zero, a11 = zero, a12 = zero, a22 = zero;
    __m256d b1 = zero, b2 = zero, b11 = zero, b12 = zero, b22 = zero, b111 = zero, b112 = zero, b122 = zero, b222 = zero;
    __m256d cnt = zero;
    const __m256i nv = _mm256_set1_epi64x(n);
    // weights and the 6 sums of M first, then the 9 of M_,c from the stored gf: two short
    // loops keep their sums in registers (one loop spilled 9 of 15) and let the
    // out-of-order core overlap the square roots and divisions of successive groups
    // the cubic spline's pieces (kernel_eval.hpp): f = 1 + a2 r^2 + a3 r^3 and -f'/r =
    // -2 a2 - 3 a3 r (r < 1); b3 t^3 and 3 b3 t^2 / r (t = 2 - r)
    using S = CubicSplineShape;
    static_assert(S::a0 == 1.0, "win adds one for a0");
    const __m256d ca3 = _mm256_set1_pd(S::a3), ca2 = _mm256_set1_pd(S::a2);
    const __m256d cg1 = _mm256_set1_pd(3.0 * S::a3), cg0 = _mm256_set1_pd(-2.0 * S::a2);
    const __m256d cb3 = _mm256_set1_pd(S::b3), cgb = _mm256_set1_pd(3.0 * S::b3);
    for (m = 0; m < n; m += 4) {
      const __m256d valid = _mm256_castsi256_pd(_mm256_cmpgt_epi64(nv, _mm256_add_epi64(lane, _mm256_set1_epi64x(m))));
      const __m256d x1 = _mm256_loadu_pd(sx + m), x2 = _mm256_loadu_pd(sy + m);
      const __m256d r2 = _mm256_fmadd_pd(x1, x1, _mm256_mul_pd(x2, x2));
      const __m256d r = _mm256_sqrt_pd(r2);
      const __m256d inner = _mm256_cmp_pd(r, one, _CMP_LT_OQ);
      const __m256d win = _mm256_fmadd_pd(r2, _mm256_fmadd_pd(ca3, r, ca2), one);
      const __m256d gin = _mm256_fnmadd_pd(cg1, r, cg0);
      const __m256d bq = _mm256_max_pd(_mm256_sub_pd(two, r), zero), bb = _mm256_mul_pd(bq, bq);
      const __m256d wout = _mm256_mul_pd(_mm256_mul_pd(cb3, bb), bq);
      const __m256d gout = _mm256_div_pd(_mm256_mul_pd(cgb, bb), r);  // r >= 1 where taken
      const __m256d w = _mm256_and_pd(_mm256_blendv_pd(wout, win, inner), valid);
      const __m256d g = _mm256_and_pd(_mm256_blendv_pd(gout, gin, inner), valid);
      _mm256_storeu_pd(wv + m, w);
      _mm256_storeu_pd(gv + m, g);
      cnt = _mm256_add_pd(cnt, _mm256_and_pd(_mm256_cmp_pd(w, zero, _CMP_GT_OQ), one));
      const __m256d wx = _mm256_mul_pd(w, x1), wy = _mm256_mul_pd(w, x2);
      a0 = _mm256_add_pd(a0, w);
      a1 = _mm256_add_pd(a1, wx);
      a2 = _mm256_add_pd(a2, wy);
      a11 = _mm256_fmadd_pd(wx, x1, a11);
      a12 = _mm256_fmadd_pd(wx, x2, a12);
      a22 = _mm256_fmadd_pd(wy, x2, a22);
    }
    for (m = 0; m < n; m += 4) {
      const __m256d x1 = _mm256_loadu_pd(sx + m), x2 = _mm256_loadu_pd(sy + m), g = _mm256_loadu_pd(gv + m);
      const __m256d g1 = _mm256_mul_pd(g, x1);
      b1 = _mm256_add_pd(b1, g1);
      const __m256d g11 = _mm256_mul_pd(g1, x1);
      b11 = _mm256_add_pd(b11, g11);
      b111 = _mm256_fmadd_pd(g11, x1, b111);
      b112 = _mm256_fmadd_pd(g11, x2, b112);
      const __m256d g12 = _mm256_mul_pd(g1, x2);
      b12 = _mm256_add_pd(b12, g12);
      b122 = _mm256_fmadd_pd(g12, x2, b122);
      const __m256d g2 = _mm256_mul_pd(g, x2);
      b2 = _mm256_add_pd(b2, g2);
      const __m256d g22 = _mm256_mul_pd(g2, x2);
      b22 = _mm256_add_pd(b22, g22);
      b222 = _mm256_fmadd_pd(g22, x2, b222);
    }
    double sm[20];
    _mm256_storeu_pd(sm, hsum4(a0, a1, a2, a11));
    _mm256_storeu_pd(sm + 4, hsum4(a12, a22, b1, b2));
    _mm256_storeu_pd(sm + 8, hsum4(b11, b12, b22, b111));
    _mm256_storeu_pd(sm + 12, hsum4(b112, b122, b222, cnt));
    const int support = static_cast<int>(sm[15]);
    // (C) M = [[A00 A01 A02] [A01 A11 A12] [A02 A12 A22]], M_,c = w_,c p p^T (times h above)
    const double A00 = sm[0], A01 = sm[1], A02 = sm[2], A11 = sm[3], A12 = sm[4], A22 = sm[5];
    const double B1 = sm[6], B2 = sm[7], B11 = sm[8], B12 = sm[9], B22 = sm[10], B111 = sm[11], B112 = sm[12],
                 B122 = sm[13], B222 = sm[14];
    const double C00 = A11 * A22 - A12 * A12, C01 = A02 * A12 - A01 * A22, C02 = A01 * A12 - A02 * A11;
    const double C11 = A00 * A22 - A02 * A02, C12 = A01 * A02 - A00 * A12, C22 = A00 * A11 - A01 * A01;
    const double det = A00 * C00 + A01 * C01 + A02 * C02;
    bool ok = support >= 3 && A00 > 0.0 && C22 > 0.0 && det > 0.0;
    double cond = 1.0;
    if (ok) {
      const double na = std::max(std::max(std::fabs(A00) + std::fabs(A01) + std::fabs(A02),
                                          std::fabs(A01) + std::fabs(A11) + std::fabs(A12)),
                                 std::fabs(A02) + std::fabs(A12) + std::fabs(A22));
      const double nc = std::max(std::max(std::fabs(C00) + std::fabs(C01) + std::fabs(C02),
                                          std::fabs(C01) + std::fabs(C11) + std::fabs(C12)),
                                 std::fabs(C02) + std::fabs(C12) + std::fabs(C22));
      cond = na * nc * (1.0 / det);
      ok = std::isfinite(cond) && cond > 0.0 && 1.0 / cond >= min_rcond;
    }
    if (!ok) {  // the general path decides (fallback, failure)
      out.status[s] = kFastPending;
      continue;
    }
    out.status[s] = 0;
    out.support[s] = support;
    out.cond[s] = cond;
    out.order[s] = out.order_used;
    // 003 eqs 27-31: g = M^-1 p(0), g_,c = M^-1 (e_c / h - M_,c g)
    const double id = 1.0 / det;  // the same division as above (the compiler keeps one)
    const double X00 = C00 * id, X01 = C01 * id, X02 = C02 * id, X11 = C11 * id, X12 = C12 * id, X22 = C22 * id;
    const double g0 = X00, g1 = X01, g2 = X02;
    // M_,1 = [[B1 B11 B12] [B11 B111 B112] [B12 B112 B122]] / h, M_,2 = [[B2 B12 B22] [B12 B112 B122] [B22 B122 B222]] / h
    const double r10 = -(B1 * g0 + B11 * g1 + B12 * g2) * ih, r11 = -(B11 * g0 + B111 * g1 + B112 * g2) * ih + ih,
                 r12 = -(B12 * g0 + B112 * g1 + B122 * g2) * ih;
    const double r20 = -(B2 * g0 + B12 * g1 + B22 * g2) * ih, r21 = -(B12 * g0 + B112 * g1 + B122 * g2) * ih,
                 r22 = -(B22 * g0 + B122 * g1 + B222 * g2) * ih + ih;
    const double c00 = X00 * r10 + X01 * r11 + X02 * r12, c01 = X01 * r10 + X11 * r11 + X12 * r12,
                 c02 = X02 * r10 + X12 * r11 + X22 * r12;
    const double c10 = X00 * r20 + X01 * r21 + X02 * r22, c11 = X01 * r20 + X11 * r21 + X12 * r22,
                 c12 = X02 * r20 + X12 * r21 + X22 * r22;
    // (D) N_j = w_j g.p_j, N_j,c = w_j g_,c.p_j + gf_j s_c / h g.p_j
    const __m256d G0 = _mm256_set1_pd(g0), G1 = _mm256_set1_pd(g1), G2 = _mm256_set1_pd(g2);
    const __m256d Q00 = _mm256_set1_pd(c00), Q01 = _mm256_set1_pd(c01), Q02 = _mm256_set1_pd(c02);
    const __m256d Q10 = _mm256_set1_pd(c10), Q11 = _mm256_set1_pd(c11), Q12 = _mm256_set1_pd(c12);
    auto out4 = [&](int q, bool tail) MLS1_INLINE_LAMBDA {
      const __m256d x1 = _mm256_loadu_pd(sx + q), x2 = _mm256_loadu_pd(sy + q), w = _mm256_loadu_pd(wv + q);
      const __m256d gp = _mm256_fmadd_pd(G2, x2, _mm256_fmadd_pd(G1, x1, G0));
      const __m256d gq = _mm256_mul_pd(_mm256_mul_pd(_mm256_loadu_pd(gv + q), ihv), gp);
      const __m256d Nv = _mm256_mul_pd(w, gp);
      const __m256d gx = _mm256_fmadd_pd(w, _mm256_fmadd_pd(Q02, x2, _mm256_fmadd_pd(Q01, x1, Q00)), _mm256_mul_pd(gq, x1));
      const __m256d gy = _mm256_fmadd_pd(w, _mm256_fmadd_pd(Q12, x2, _mm256_fmadd_pd(Q11, x1, Q10)), _mm256_mul_pd(gq, x2));
      const __m256d t0 = _mm256_unpacklo_pd(gx, gy), t1 = _mm256_unpackhi_pd(gx, gy);  // (x0 y0 x2 y2), (x1 y1 x3 y3)
      const __m256d o0 = _mm256_permute2f128_pd(t0, t1, 0x20), o1 = _mm256_permute2f128_pd(t0, t1, 0x31);
      if (!tail) {
        _mm256_storeu_pd(Nk + q, Nv);
        _mm256_storeu_pd(Gk + 2 * q, o0);
        _mm256_storeu_pd(Gk + 2 * q + 4, o1);
      } else {
        const __m256i rem = _mm256_set1_epi64x(n - q), rem2 = _mm256_set1_epi64x(2 * (n - q));
        _mm256_maskstore_pd(Nk + q, _mm256_cmpgt_epi64(rem, lane), Nv);
        _mm256_maskstore_pd(Gk + 2 * q, _mm256_cmpgt_epi64(rem2, lane), o0);
        _mm256_maskstore_pd(Gk + 2 * q + 4, _mm256_cmpgt_epi64(rem2, lane2), o1);
      }
    };
    m = 0;
    for (; m + 4 <= n; m += 4) out4(m, false);
    if (m < n) out4(m, true);
  }
  _mm256_zeroupper();
}
MFREE_AVX2_END

#else

bool mls1_rows2_available() { return false; }
void mls1_rows2_avx2(const FastTables &, int64_t, int64_t, double, FastScratch &, const FastSites &) {}

#endif

}  // namespace mfree
