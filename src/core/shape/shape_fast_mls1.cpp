// Fused rows of linear MLS in 2D with the cubic spline (shape_fast_mls1.hpp), four
// neighbours at a time in vector extensions compiled for AVX2 + FMA (simd.hpp): the fast
// path's general MLS rows (shape_fast_rows.inc) gather a row's neighbours into scratch,
// accumulate the moments and factorise in separate passes; here the whole row stays in
// registers, and the 3x3 moment matrix is inverted in closed form (small_dense.hpp).
// Same functions as the general path to round-off (tests t404, t432). There is no
// baseline copy: the baseline fast path takes the general rows. Rows left to the caller
// by a particle set (FastTables::kept) are filtered from its candidates in the pass that
// computes the offsets, by the search's pair test: the kept offsets are packed as they
// are computed, so the candidates' positions are read once.
#include "core/shape/shape_fast_mls1.hpp"

#include "core/base/kernel_eval.hpp"
#include "core/base/simd.hpp"
#include "core/base/small_dense.hpp"
#include "core/particles/pair_test.hpp"

namespace mfree {

#if MFREE_SIMD_X86

bool mls1_rows2_available() { return true; }

MFREE_AVX2_BEGIN
namespace {
namespace avx2 {

using simd::V2;
using simd::V4;

// One row: the site, the row's columns and the scratch rows of 2 cap doubles each (room
// for a whole padded group past any row): scaled offsets sx, sy, weights wv and the
// radial factors gv.
struct Row {
  const double *P;
  int64_t ps;
  const int32_t *cc;
  int n;
  double xk, yk, ih;
  double *sx, *sy, *wv, *gv;
};

// The 15 moment sums of a row and its support: M = [[A00 A01 A02] [A01 A11 A12] [A02 A12
// A22]] = sum w p p^T and h M_,c = sum gf s_c p p^T, whose entries are the B sums.
struct Moments {
  double A00, A01, A02, A11, A12, A22;
  double B1, B2, B11, B12, B22, B111, B112, B122, B222;
  int support;
};

// (A) the scaled offsets s_j = (x_j - x_s) / h_s of the neighbours j[0..3] to sx, sy at m
// (positions by two 128-bit loads per pair of lanes, cheaper than gathers here).
MFREE_ALWAYS_INLINE void offsets4(const Row &r, const int32_t *j, int m) {
  V2 p0, p1, p2, p3;
  simd::load<2>(p0, r.P + r.ps * j[0]);
  simd::load<2>(p1, r.P + r.ps * j[1]);
  simd::load<2>(p2, r.P + r.ps * j[2]);
  simd::load<2>(p3, r.P + r.ps * j[3]);
  V4 lo, hi;
  simd::concat(lo, p0, p2);  // x0 y0 x2 y2
  simd::concat(hi, p1, p3);  // x1 y1 x3 y3
  const V4 dx = MFREE_SHUF(lo, hi, 0, 4, 2, 6) - r.xk, dy = MFREE_SHUF(lo, hi, 1, 5, 3, 7) - r.yk;
  simd::store<4>(r.sx + m, dx * r.ih);
  simd::store<4>(r.sy + m, dy * r.ih);
}

// The offsets of a row; the last group padded with the row's first neighbour.
MFREE_ALWAYS_INLINE void offsets(const Row &r) {
  const int n = r.n;
  int m = 0;
  for (; m + 4 <= n; m += 4) offsets4(r, r.cc + m, m);
  if (m < n) {
    const int rest = n - m;  // 1, 2 or 3 (a loop here became a call of memcpy)
    const int32_t jt[4] = {r.cc[m], rest > 1 ? r.cc[m + 1] : r.cc[0], rest > 2 ? r.cc[m + 2] : r.cc[0],
                           r.cc[0]};
    offsets4(r, jt, m);
  }
}

// Left-packing by a 4-bit mask k of kept lanes, entry e[k] (64 bytes: one index
// computation per group): d, the 32-bit lane indices that move the kept doubles of a V4
// to its front; b, the byte indices that move the kept ids of four to the front (the
// others zero); n, their count.
struct alignas(64) LeftPackEntry {
  int32_t d[8];
  char b[16];
  int n;
};
struct LeftPack {
  LeftPackEntry e[16];
};
constexpr LeftPack left_pack() {
  LeftPack t{};
  for (int k = 0; k < 16; ++k) {
    int c = 0;
    for (int l = 0; l < 4; ++l)
      if (k >> l & 1) {
        t.e[k].d[2 * c] = 2 * l;
        t.e[k].d[2 * c + 1] = 2 * l + 1;
        for (int q = 0; q < 4; ++q) t.e[k].b[4 * c + q] = static_cast<char>(4 * l + q);
        ++c;
      }
    for (int q = 4 * c; q < 16; ++q) t.e[k].b[q] = static_cast<char>(0x80);
    t.e[k].n = c;
  }
  return t;
}
constexpr LeftPack kLeft = left_pack();

// (A) of rows to filter: the candidates j[0..3] kept by the search's pair test on their
// offsets x_j - x_s, their scaled offsets (offsets4's values) packed to sx, sy at m and
// their ids (four stored) to out; returns the count kept. Lanes: the valid ones
// (the last group repeats a candidate); S: the particles' stride when known (0: r.ps).
template <int S>
MFREE_ALWAYS_INLINE int filter4(const Row &r, const int32_t *j, int lanes, const V4 &lim2, int32_t *out, int m) {
  const int64_t ps = S > 0 ? S : r.ps;
  V2 p0, p1, p2, p3;
  simd::load<2>(p0, r.P + ps * j[0]);
  simd::load<2>(p1, r.P + ps * j[1]);
  simd::load<2>(p2, r.P + ps * j[2]);
  simd::load<2>(p3, r.P + ps * j[3]);
  V4 lo, hi;
  simd::concat(lo, p0, p2);
  simd::concat(hi, p1, p3);
  const V4 dx = MFREE_SHUF(lo, hi, 0, 4, 2, 6) - r.xk, dy = MFREE_SHUF(lo, hi, 1, 5, 3, 7) - r.yk;
  const int k = lanes == 15 ? pair_test::within4(dx, dy, lim2) : pair_test::within4(dx, dy, lim2) & lanes;
  const LeftPackEntry &pk = kLeft.e[k];
  simd::x86::I8 idx;
  std::memcpy(&idx, pk.d, sizeof idx);
  simd::store<4>(r.sx + m, simd::x86::permute32(dx * r.ih, idx));
  simd::store<4>(r.sy + m, simd::x86::permute32(dy * r.ih, idx));
  simd::x86::B16 ids, sh;
  std::memcpy(&ids, j, sizeof ids);
  std::memcpy(&sh, pk.b, sizeof sh);
  const simd::x86::B16 packed = simd::x86::shuffle_bytes(ids, sh);
  std::memcpy(out, &packed, sizeof packed);
  return pk.n;
}

// The row of the nc candidates cc within lim2 of the site, in their order: the ids to
// kept, the offsets as offsets() writes them for those ids (the last group padded with
// the first's); returns the count. Room: the block's candidates go on for three past the
// row, whose last group then reads them (masked off) and stores four ids, at most three
// past the row (into the next rows of the block, written after this one).
template <int S>
MFREE_ALWAYS_INLINE int filtered_offsets(const Row &r, const int32_t *cc, int nc, double lim2, int32_t *kept,
                                         bool room) {
  const V4 lv = {lim2, lim2, lim2, lim2};
  int n = 0, p = 0;
  for (; p + 4 <= nc; p += 4) n += filter4<S>(r, cc + p, 15, lv, kept + n, n);  // (n <= p: within the row)
  if (p < nc) {
    const int rest = nc - p;  // 1, 2 or 3
    if (room) {  // (the lanes past the row: the next rows' candidates, masked off)
      n += filter4<S>(r, cc + p, (1 << rest) - 1, lv, kept + n, n);
    } else {
      const int32_t jt[4] = {cc[p], rest > 1 ? cc[p + 1] : cc[p], rest > 2 ? cc[p + 2] : cc[p], cc[p]};
      int32_t tail[4];
      const int kn = filter4<S>(r, jt, (1 << rest) - 1, lv, tail, n);
      for (int l = 0; l < kn; ++l) kept[n + l] = tail[l];
      n += kn;
    }
  }
  const V4 x0 = {r.sx[0], r.sx[0], r.sx[0], r.sx[0]}, y0 = {r.sy[0], r.sy[0], r.sy[0], r.sy[0]};
  simd::store<4>(r.sx + n, x0);
  simd::store<4>(r.sy + n, y0);
  return n;
}

// (B) r = |s_j|, the cubic spline's shape f = 1 - 3/2 r^2 + 3/4 r^3 (r < 1), (2 - r)^3 / 4
// (1 <= r < 2) and gf = -f'(r) / r = 3 - 9/4 r, 3/4 (2 - r)^2 / r in Horner form with a
// blend, the padded lanes' weights zero; then the moment sums. The weights lack the
// kernel's factor c0 / h^2 (the rows do not depend on it); the 1 / h of the derivatives is
// applied after the sums. The weights and the 6 sums of M first, then the 9 of M_,c from
// the stored gf: two short loops keep their sums in registers (one loop spilled 9 of 15)
// and let the out-of-order core overlap the square roots and divisions of successive
// groups.
// The weights of the group at m and its terms of the 6 sums of M (Last: the row's last
// group, whose lanes past n get zero weights; the others have none).
struct SumsM {
  V4 a0, a1, a2, a11, a12, a22, cnt;
};
template <bool Last>
MFREE_ALWAYS_INLINE void weights4(const Row &r, int m, SumsM &a) {
  using S = CubicSplineShape;
  static_assert(S::a0 == 1.0, "win adds one for a0");
  const V4 lanes = {0.0, 1.0, 2.0, 3.0}, zero = {}, one = zero + 1.0;
  V4 x1, x2;
  simd::load<4>(x1, r.sx + m);
  simd::load<4>(x2, r.sy + m);
  const V4 r2 = x1 * x1 + x2 * x2;
  const V4 q = simd::x86::sqrt(r2);
  const V4 win = r2 * (S::a3 * q + S::a2) + 1.0;
  const V4 gin = -2.0 * S::a2 - 3.0 * S::a3 * q;
  V4 bq = 2.0 - q;
  bq = bq > 0.0 ? bq : zero;
  const V4 bb = bq * bq;
  const V4 wout = S::b3 * bb * bq;
  const V4 gout = 3.0 * S::b3 * bb / q;  // q >= 1 where taken
  const auto inner = q < 1.0;
  V4 w = inner ? win : wout, g = inner ? gin : gout;
  if (Last) {
    const auto valid = lanes + static_cast<double>(m) < static_cast<double>(r.n);
    w = valid ? w : zero;
    g = valid ? g : zero;
  }
  simd::store<4>(r.wv + m, w);
  simd::store<4>(r.gv + m, g);
  a.cnt += w > 0.0 ? one : zero;
  const V4 wx = w * x1, wy = w * x2;
  a.a0 += w;
  a.a1 += wx;
  a.a2 += wy;
  a.a11 += wx * x1;
  a.a12 += wx * x2;
  a.a22 += wy * x2;
}

MFREE_ALWAYS_INLINE void moments(const Row &r, Moments &mo) {
  const int n = r.n;
  SumsM sa = {};
  int m = 0;
  for (; m + 4 <= n; m += 4) weights4<false>(r, m, sa);
  if (m < n) weights4<true>(r, m, sa);
  V4 &a0 = sa.a0, &a1 = sa.a1, &a2 = sa.a2, &a11 = sa.a11, &a12 = sa.a12, &a22 = sa.a22, &cnt = sa.cnt;
  V4 b1 = {}, b2 = {}, b11 = {}, b12 = {}, b22 = {}, b111 = {}, b112 = {}, b122 = {}, b222 = {};
  for (int m = 0; m < n; m += 4) {
    V4 x1, x2, g;
    simd::load<4>(x1, r.sx + m);
    simd::load<4>(x2, r.sy + m);
    simd::load<4>(g, r.gv + m);
    const V4 g1 = g * x1;
    b1 += g1;
    const V4 g11 = g1 * x1;
    b11 += g11;
    b111 += g11 * x1;
    b112 += g11 * x2;
    const V4 g12 = g1 * x2;
    b12 += g12;
    b122 += g12 * x2;
    const V4 g2 = g * x2;
    b2 += g2;
    const V4 g22 = g2 * x2;
    b22 += g22;
    b222 += g22 * x2;
  }
  double sm[16];
  simd::hsum4(a0, a1, a2, a11, sm);
  simd::hsum4(a12, a22, b1, b2, sm + 4);
  simd::hsum4(b11, b12, b22, b111, sm + 8);
  simd::hsum4(b112, b122, b222, cnt, sm + 12);
  mo = Moments{sm[0], sm[1], sm[2], sm[3], sm[4], sm[5], sm[6], sm[7], sm[8], sm[9], sm[10],
               sm[11], sm[12], sm[13], sm[14], static_cast<int>(sm[15])};
}

// (C) g = M^-1 p(0) and g_,c = M^-1 (e_c / h - M_,c g) (003 eqs 27-31), with M inverted by
// small_dense.hpp's closed form (its verdict: positive definite, the condition rule).
// False when the general path decides (fallback, failure).
struct Coefs {
  double g0, g1, g2, c00, c01, c02, c10, c11, c12;
};
MFREE_ALWAYS_INLINE bool solve(const Moments &mo, double ih, double min_rcond, Coefs &k, double &cond) {
  const double A[3][3] = {{mo.A00, mo.A01, mo.A02}, {mo.A01, mo.A11, mo.A12}, {mo.A02, mo.A12, mo.A22}};
  double X[3][3];
  if (mo.support < 3 || !dense::spd_inverse3(A, X, cond) || !(1.0 / cond >= min_rcond)) return false;
  const double g0 = X[0][0], g1 = X[0][1], g2 = X[0][2];
  // M_,1 = [[B1 B11 B12] [B11 B111 B112] [B12 B112 B122]] / h,
  // M_,2 = [[B2 B12 B22] [B12 B112 B122] [B22 B122 B222]] / h
  const double r10 = -(mo.B1 * g0 + mo.B11 * g1 + mo.B12 * g2) * ih,
               r11 = -(mo.B11 * g0 + mo.B111 * g1 + mo.B112 * g2) * ih + ih,
               r12 = -(mo.B12 * g0 + mo.B112 * g1 + mo.B122 * g2) * ih;
  const double r20 = -(mo.B2 * g0 + mo.B12 * g1 + mo.B22 * g2) * ih,
               r21 = -(mo.B12 * g0 + mo.B112 * g1 + mo.B122 * g2) * ih,
               r22 = -(mo.B22 * g0 + mo.B122 * g1 + mo.B222 * g2) * ih + ih;
  k.g0 = g0;
  k.g1 = g1;
  k.g2 = g2;
  k.c00 = X[0][0] * r10 + X[0][1] * r11 + X[0][2] * r12;
  k.c01 = X[0][1] * r10 + X[1][1] * r11 + X[1][2] * r12;
  k.c02 = X[0][2] * r10 + X[1][2] * r11 + X[2][2] * r12;
  k.c10 = X[0][0] * r20 + X[0][1] * r21 + X[0][2] * r22;
  k.c11 = X[0][1] * r20 + X[1][1] * r21 + X[1][2] * r22;
  k.c12 = X[0][2] * r20 + X[1][2] * r21 + X[2][2] * r22;
  return true;
}

// (D) N_j = w_j g.p_j, N_j,c = w_j g_,c.p_j + gf_j s_c / h g.p_j, four at a time, the
// gradients interleaved (x, y). The padded last group is stored lane by lane: the next
// row, or the next block (another thread), starts right after it.
// The group at q, of which rest (1-4) lanes are the row's.
MFREE_ALWAYS_INLINE void outputs4(const Row &r, const Coefs &k, int q, int rest, double *Nk, double *Gk) {
  V4 x1, x2, w, gf;
  simd::load<4>(x1, r.sx + q);
  simd::load<4>(x2, r.sy + q);
  simd::load<4>(w, r.wv + q);
  simd::load<4>(gf, r.gv + q);
  const V4 gp = k.g2 * x2 + (k.g1 * x1 + k.g0);
  const V4 gq = gf * r.ih * gp;
  const V4 Nv = w * gp;
  const V4 gx = w * (k.c02 * x2 + (k.c01 * x1 + k.c00)) + gq * x1;
  const V4 gy = w * (k.c12 * x2 + (k.c11 * x1 + k.c10)) + gq * x2;
  const V4 o0 = MFREE_SHUF(gx, gy, 0, 4, 1, 5), o1 = MFREE_SHUF(gx, gy, 2, 6, 3, 7);
  double *N = Nk + q, *G = Gk + 2 * q;
  switch (rest) {
    case 1:
      simd::store<1>(N, Nv);
      simd::store<2>(G, o0);
      break;
    case 2:
      simd::store<2>(N, Nv);
      simd::store<4>(G, o0);
      break;
    case 3:
      simd::store<3>(N, Nv);
      simd::store<4>(G, o0);
      simd::store<2>(G + 4, o1);
      break;
    default:
      simd::store<4>(N, Nv);
      simd::store<4>(G, o0);
      simd::store<4>(G + 4, o1);
  }
}

MFREE_ALWAYS_INLINE void outputs(const Row &r, const Coefs &k, double *Nk, double *Gk) {
  const int n = r.n;
  int q = 0;
  for (; q + 4 <= n; q += 4) outputs4(r, k, q, 4, Nk, Gk);
  if (q < n) outputs4(r, k, q, n - q, Nk, Gk);
}

}  // namespace avx2
}  // namespace

// Row by row: (A) offsets (of the kept candidates for Filter), (B) weights and moments,
// (C) the 3x3 solve, its condition number the general path's (see spd_inverse3), (D) the
// values and gradients.
namespace {
template <bool Filter>
void mls1_rows2(const FastTables &t, int64_t b, int64_t e, double min_rcond, FastScratch &ws,
                const FastSites &out) {
  avx2::Row r;
  r.P = t.x[0];
  r.ps = t.stride;
  r.sx = ws.d(0);
  r.sy = ws.d(2);
  r.wv = ws.d(4);
  r.gv = ws.d(6);
  const int64_t kend = t.rowptr[e];
  int64_t o = t.rowptr[b];  // (Filter: where the next row goes)
  for (int64_t s = b; s < e; ++s) {
    if (out.pst && out.pst[s] != 0) {  // failed in the set: an empty row
      out.status[s] = out.pst[s];
      out.support[s] = 0;
      out.cond[s] = 1.0;
      out.order[s] = -1;
      if (Filter) t.rowbeg[s] = t.rowend[s] = o;
      continue;
    }
    const int64_t k0 = t.rowptr[s];
    const double hs = t.sh[s * t.shstride];
    r.ih = 1.0 / hs;
    r.xk = t.sx[0][s * t.sstride];
    r.yk = t.sx[1][s * t.sstride];
    if (Filter) {
      const int nc = static_cast<int>(t.rowptr[s + 1] - k0);
      const double lim2 = pair_test::limit2(t.kappa * hs);
      const bool room = t.rowptr[s + 1] + 3 <= kend;
      r.n = t.stride == 2 ? avx2::filtered_offsets<2>(r, t.cols + k0, nc, lim2, t.kept + o, room)
                          : avx2::filtered_offsets<0>(r, t.cols + k0, nc, lim2, t.kept + o, room);
      t.rowbeg[s] = o;
      t.rowend[s] = o + r.n;
    } else {
      r.n = static_cast<int>(t.rowptr[s + 1] - k0);
      r.cc = t.cols + k0;
      avx2::offsets(r);
    }
    const int64_t w0 = Filter ? o : k0;  // the row's first entry
    if (Filter) o += r.n;
    avx2::Moments mo;
    avx2::moments(r, mo);
    avx2::Coefs k;
    double cond;
    if (!avx2::solve(mo, r.ih, min_rcond, k, cond)) {
      out.status[s] = kFastPending;
      continue;
    }
    out.status[s] = 0;
    out.support[s] = mo.support;
    out.cond[s] = cond;
    out.order[s] = out.order_used;
    avx2::outputs(r, k, t.val + w0, t.grad + 2 * w0);
  }
}
}  // namespace

void mls1_rows2_avx2(const FastTables &t, int64_t b, int64_t e, double min_rcond, FastScratch &ws,
                     const FastSites &out) {
  if (t.kept) mls1_rows2<true>(t, b, e, min_rcond, ws, out);
  else mls1_rows2<false>(t, b, e, min_rcond, ws, out);
  MFREE_ZERO_UPPER();
}
MFREE_AVX2_END

#else

bool mls1_rows2_available() { return false; }
void mls1_rows2_avx2(const FastTables &, int64_t, int64_t, double, FastScratch &, const FastSites &) {}

#endif

}  // namespace mfree
