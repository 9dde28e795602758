// The fluid's shape-function tables at the nodes (fluid particles, then dummies): the
// candidate (Verlet) lists and the chunk colouring of the scatter on them, and the rows
// filtered from the candidates at every prepare.
#include <algorithm>
#include <cmath>
#include <type_traits>

#include "core/base/kernel.hpp"
#include "core/base/parallel.hpp"
#include "core/base/simd.hpp"
#include "core/particles/neighbors.hpp"
#include "core/shape/shape_fast_mls1.hpp"
#include "core/systems/fluid.hpp"

#ifdef __SSE2__
#include <emmintrin.h>
#endif
#if MFREE_SIMD_X86
#include <immintrin.h>
#endif

// Loops over a row's neighbours written for the vectoriser (any OpenMP: omp simd).
#define FLUID_PRAGMA(x) _Pragma(#x)
#ifdef _OPENMP
#define FLUID_SIMD(...) FLUID_PRAGMA(omp simd __VA_ARGS__)
#else
#define FLUID_SIMD(...)
#endif

namespace mfree {

namespace {

// a[m] = sqrt(a[m]), m < n, two at a time where SSE2 is there (compilers vectorise sqrt
// only without errno, which the library does not switch off); correctly rounded either way.
inline void sqrt_n(double *a, int n) {
  int m = 0;
#ifdef __SSE2__
  for (; m + 2 <= n; m += 2) _mm_storeu_pd(a + m, _mm_sqrt_pd(_mm_loadu_pd(a + m)));
#endif
  for (; m < n; ++m) a[m] = std::sqrt(a[m]);
}

#if MFREE_SIMD_X86
// sqrt_n four at a time, for the AVX2 copy of the row kernel (same correctly rounded values)
MFREE_TARGET_AVX2 void sqrt_n_avx2(double *a, int n) {
  int m = 0;
  for (; m + 4 <= n; m += 4) _mm256_storeu_pd(a + m, _mm256_sqrt_pd(_mm256_loadu_pd(a + m)));
  for (; m + 2 <= n; m += 2) _mm_storeu_pd(a + m, _mm_sqrt_pd(_mm_loadu_pd(a + m)));
  for (; m < n; ++m) a[m] = std::sqrt(a[m]);
}
#endif

// The approximants' singularity threshold on 1 / cond (local.cpp, shape_fast.cpp).
constexpr double kMinRcond = 1e-12;

// X = A^-1 for a symmetric positive definite A by A = U^T D U (unit upper U, built
// column by column) and its exact 1-norm condition number ||A||_1 ||X||_1; false when a
// pivot is not positive or the system is singular to kMinRcond.
template <int L>
MFREE_ALWAYS_INLINE bool spd_inverse(const double (&A)[L][L], double (&X)[L][L], double &cond) {
  double U[L][L] = {}, D[L];
  for (int j = 0; j < L; ++j) {
    for (int i = 0; i < j; ++i) {
      double v = A[i][j];
      for (int m = 0; m < i; ++m) v -= U[m][i] * D[m] * U[m][j];
      U[i][j] = v / D[i];
    }
    double dj = A[j][j];
    for (int m = 0; m < j; ++m) dj -= U[m][j] * D[m] * U[m][j];
    if (!(dj > 0.0)) return false;
    D[j] = dj;
  }
  // X = U^-1 D^-1 U^-T with V = U^-1 (unit upper)
  double V[L][L] = {};
  for (int i = L - 1; i >= 0; --i) {
    V[i][i] = 1.0;
    for (int j = i + 1; j < L; ++j) {
      double v = 0.0;
      for (int m = i + 1; m <= j; ++m) v -= U[i][m] * V[m][j];
      V[i][j] = v;
    }
  }
  for (int a = 0; a < L; ++a)
    for (int b = a; b < L; ++b) {
      double v = 0.0;
      for (int m = b; m < L; ++m) v += V[a][m] * V[b][m] / D[m];
      X[a][b] = X[b][a] = v;
    }
  double na = 0.0, nx = 0.0;
  for (int b = 0; b < L; ++b) {
    double sa = 0.0, sx = 0.0;
    for (int a = 0; a < L; ++a) {
      sa += std::fabs(A[a][b]);
      sx += std::fabs(X[a][b]);
    }
    na = std::max(na, sa);
    nx = std::max(nx, sx);
  }
  cond = na * nx;
  return std::isfinite(cond) && cond > 0.0 && 1.0 / cond >= kMinRcond;
}

}  // namespace

Report FluidSystem::candidates(const double *xn) {
  const int dim = dim_;
  const int32_t nall = nq();
  const size_t nx = static_cast<size_t>(nall) * dim;
  bool rebuild = !lists_valid_ || xref_.size() != nx || href_ != h_;
  if (!rebuild) {
    // 2 max |x - x_ref| < skin: pairs now closer than 2h were closer than 2h + skin at
    // the build (a tenth of the skin kept back for rounding)
    const double lim = 0.45 * skin_ * h_, lim2 = lim * lim;
    bool moved[64] = {};  // per thread (parallel_blocks runs at most 64)
    const double *xr = xref_.data();
    parallel_blocks(nall, light_threads(nall), [&](int t, int64_t b, int64_t e) {
      bool far = false;
      for (int64_t i = b; i < e; ++i) {
        double d2 = 0.0;
        for (int c = 0; c < dim; ++c) d2 += (xn[i * dim + c] - xr[i * dim + c]) * (xn[i * dim + c] - xr[i * dim + c]);
        far = far || !(d2 <= lim2);
      }
      moved[t] = far;
    });
    rebuild = std::any_of(moved, moved + 64, [](bool f) { return f; });
  }
  if (!rebuild) {
    if (xn != xbound_) {  // same lists, positions from another buffer (ps_ is read by fluid_wall)
      ps_.set_positions(xn, MFREE_LAYOUT_AOS, dim, MFREE_BORROW);
      xbound_ = xn;
    }
    return Report();
  }
  lists_valid_ = false;
  const double hs = h_ * (1.0 + 0.5 * skin_);  // gather radius 2 hs = 2h + skin
  ps_.set_positions(xn, MFREE_LAYOUT_AOS, dim, MFREE_BORROW);
  xbound_ = xn;
  ps_.set_volumes(vol_.data(), 1, MFREE_BORROW);
  ps_.set_support(&hs, 0, MFREE_COPY);
  Report r = ps_.setup();
  if (!r.ok()) return r;
  const Csr &nb = ps_.neighbors();
  cand_.rowptr.assign(nb.rowptr.begin(), nb.rowptr.end());
  cand_.cols.assign(nb.cols.begin(), nb.cols.end());
  const int64_t cnnz = cand_.nnz();
  ctrans_valid_ = false;
  // the tables' rows lie in their candidate rows: no allocation until the next rebuild
  cols_.resize(cnnz);
  N_.resize(cnnz);
  G_.resize(cnnz * dim);
  rb_.resize(nall);
  re_.resize(nall);
  cond_.resize(nall);
  maxrow_ = 0;
  for (int32_t i = 0; i < nall; ++i)
    maxrow_ = std::max<int64_t>(maxrow_, cand_.rowptr[i + 1] - cand_.rowptr[i]);
  xref_.assign(xn, xn + nx);
  href_ = h_;
  ++rebuilds_;
  color_chunks();
  if (walls_) {
    VectorArray xa;
    xa.ptr = xn;
    xa.ld = dim;
    xa.layout = MFREE_LAYOUT_AOS;
    ScalarArray ha;
    const double hw = 0.5 * (r0_ + 0.5 * skin_ * h_);  // walls stand still: skin / 2 is enough
    ha.ptr = &hw;
    ha.stride = 0;
    find_point_neighbors(*walls_, walls_->site_status(), n_, xa, ha, wall_nbr_);
  }
  lists_valid_ = true;
  return Report();
}

void FluidSystem::transposed_candidates() {
  const int32_t nall = nq();
  // transposed entries: rows are sorted, so the rows i < j that hold j are met in the
  // order of row j (next[j] walks it); a missing partner (an asymmetric pair at the
  // edge of the lists) is -1 and may not become a pair of the tables
  ctrans_.assign(cand_.nnz(), -1);
  std::vector<int64_t> next(cand_.rowptr.begin(), cand_.rowptr.end() - 1);
  for (int32_t i = 0; i < nall; ++i)
    for (int64_t e = cand_.rowptr[i]; e < cand_.rowptr[i + 1]; ++e) {
      const int32_t j = cand_.cols[e];
      int64_t &p = next[j];
      while (p < cand_.rowptr[j + 1] && cand_.cols[p] < i) ++p;
      if (p < cand_.rowptr[j + 1] && cand_.cols[p] == i) ctrans_[e] = p;
    }
  cpos_.resize(cand_.nnz());
  NT_.resize(cand_.nnz() * (dim_ + 1));
  ctrans_valid_ = true;
}

// Greedy colouring of the row chunks in chunk order: color_mask_[j] holds the colours
// of the chunks so far that touch node j (write to it in the scatter: the candidates of
// their rows, a superset of the table rows until the next rebuild). The chunks and their
// colours depend on the lists only, not on the thread count. A node ordering so scattered
// that 64 colours do not suffice runs all chunks in one colour, in order, on one thread.
void FluidSystem::color_chunks() {
  const int32_t nall = nq();
  const int32_t nch = (nall + kChunk - 1) / kChunk;
  const int64_t *crp = cand_.rowptr.data();
  const int32_t *ccols = cand_.cols.data();
  color_mask_.assign(nall, 0);
  std::vector<int32_t> &color = chunk_color_;  // members: a rebuild allocates only when the set grows
  color.assign(nch, 0);
  int ncolor = 0;
  bool serial = false;
  for (int32_t c = 0; c < nch && !serial; ++c) {
    const int64_t e0 = crp[static_cast<int64_t>(c) * kChunk], e1 = crp[std::min<int64_t>(nall, (c + 1) * int64_t{kChunk})];
    uint64_t used = 0;
    for (int64_t e = e0; e < e1; ++e) used |= color_mask_[ccols[e]];
    if (used == ~uint64_t{0}) {
      serial = true;
      break;
    }
    int col = 0;
    while (used >> col & 1u) ++col;
    color[c] = col;
    ncolor = std::max(ncolor, col + 1);
    for (int64_t e = e0; e < e1; ++e) color_mask_[ccols[e]] |= uint64_t{1} << col;
  }
  if (serial) {
    ncolor = 1;
    std::fill(color.begin(), color.end(), 0);
  }
  color_ptr_.assign(static_cast<size_t>(ncolor) + 1, 0);
  for (int32_t c = 0; c < nch; ++c) ++color_ptr_[color[c] + 1];
  for (int col = 0; col < ncolor; ++col) color_ptr_[col + 1] += color_ptr_[col];
  chunk_order_.resize(nch);
  std::vector<int32_t> &fill = chunk_fill_;
  fill.assign(color_ptr_.begin(), color_ptr_.end() - 1);
  for (int32_t c = 0; c < nch; ++c) chunk_order_[fill[color[c]]++] = c;
  scatter_threads_ = !serial;
}

// Shepard functions N_j = o_j / S, S = sum o, of the weights o = w (the approximants'
// fallback where the moment matrix is singular or the row too short), or of o = w V_j
// where it is ill-conditioned, not only singular (003 Sect. 6: a lattice node has a
// condition number of 10-15, a free edge or corner 30-60; a particle left in a thin sheet
// or strand climbs past 1e3 within a few steps, and its gradients then drive the density
// negative in one step (dam break along the wall, T ~ 2.2, at every resolution and CFL
// number tried). Hence the default threshold 100 (mfree_system_set_shepard_condition).
template <int D>
void FluidSystem::shepard_row(int n, const double *w, const double *gf, double *const *s, double ih,
                              bool volumes, const int32_t *js, double *Nk, double *Gk) const {
  double S = 0.0, dS[D] = {};
  for (int m = 0; m < n; ++m) {
    const double V = volumes ? vol_[js[m]] : 1.0;
    Nk[m] = w[m] * V;
    S += Nk[m];
    for (int c = 0; c < D; ++c) {
      Gk[m * D + c] = gf[m] * s[c][m] * ih * V;
      dS[c] += Gk[m * D + c];
    }
  }
  for (int m = 0; m < n; ++m) {
    Nk[m] /= S;
    for (int c = 0; c < D; ++c) Gk[m * D + c] = (Gk[m * D + c] - Nk[m] * dS[c]) / S;
  }
}

#if defined(__GNUC__) || defined(__clang__)
#define FLUID_NOINLINE __attribute__((noinline))
#else
#define FLUID_NOINLINE
#endif

namespace {

// The candidates of row k closer than 2h (r2 < R2, in the search's units: a symmetric
// test, |x_j - x_k| is computed alike from both ends) in structure-of-arrays scratch:
// scaled offsets s = (x_j - x_k) / h and columns js; returns their count. Candidates out
// of range are written and then overwritten (no branch: a quarter of them fall out).
// Not inlined into the AVX2 copy of the row kernel, where FMA contraction of r2 would
// move pairs at exactly 2h in or out of the rows depending on the CPU.
template <int D>
FLUID_NOINLINE int kept_candidates(const double *xn, int64_t k, const int32_t *cc, int64_t nc, double R2, double ih,
                                   double *const *s, int32_t *js) {
  const double *xk = xn + k * D;
  int q = 0;
  for (int64_t e = 0; e < nc; ++e) {
    const int32_t j = cc[e];
    const double *xj = xn + static_cast<size_t>(j) * D;
    double r2 = 0.0;
    for (int c = 0; c < D; ++c) {
      const double d = xj[c] - xk[c];
      r2 += d * d;
      s[c][q] = d * ih;
    }
    js[q] = j;
    q += r2 < R2;
  }
  return q;
}

#if MFREE_SIMD_X86
// kept_candidates four candidates at a time (AVX2 gathers, left-packed stores through a
// permutation table): the same differences, products and sums, so the same rows and
// offsets; the products are kept from FMA contraction by an empty asm.
struct PackTable {
  int32_t d[16][8];  // mask -> 32-bit lane indices moving the kept doubles to the front
  int32_t i[16][8];  // mask -> lane indices moving the kept 32-bit columns to the front
};
constexpr PackTable make_pack_table() {
  PackTable t{};
  for (int m = 0; m < 16; ++m) {
    int q = 0;
    for (int l = 0; l < 4; ++l)
      if (m >> l & 1) {
        t.d[m][2 * q] = 2 * l;
        t.d[m][2 * q + 1] = 2 * l + 1;
        t.i[m][q] = l;
        ++q;
      }
  }
  return t;
}
constexpr PackTable kPack = make_pack_table();

template <int D>
MFREE_TARGET_AVX2 FLUID_NOINLINE int kept_candidates_avx2(const double *xn, int64_t k, const int32_t *cc, int64_t nc,
                                                          double R2, double ih, double *const *s, int32_t *js) {
  const double *xk = xn + k * D;
  __m256d xkv[D];
  for (int c = 0; c < D; ++c) xkv[c] = _mm256_set1_pd(xk[c]);
  const __m256d r2v = _mm256_set1_pd(R2), ihv = _mm256_set1_pd(ih);
  const __m256d all = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
  int q = 0;
  int64_t e = 0;
  for (; e + 4 <= nc; e += 4) {
    const __m128i j4 = _mm_loadu_si128(reinterpret_cast<const __m128i *>(cc + e));
    const __m128i idx = D == 2 ? _mm_slli_epi32(j4, 1) : _mm_add_epi32(_mm_slli_epi32(j4, 1), j4);  // j * D
    __m256d d[D], p[D];
    for (int c = 0; c < D; ++c) {
      // the masked form: the plain one trips GCC 12's -Wmaybe-uninitialized
      const __m256d xj = _mm256_mask_i32gather_pd(_mm256_setzero_pd(), xn + c, idx, all, 8);
      d[c] = _mm256_sub_pd(xj, xkv[c]);
      p[c] = _mm256_mul_pd(d[c], d[c]);
      __asm__("" : "+x"(p[c]));  // r2 = (d0 d0 + d1 d1) + d2 d2, rounded as the scalar loop
    }
    __m256d r2 = p[0];
    for (int c = 1; c < D; ++c) r2 = _mm256_add_pd(r2, p[c]);
    const int mask = _mm256_movemask_pd(_mm256_cmp_pd(r2, r2v, _CMP_LT_OQ));
    const __m256i pd = _mm256_loadu_si256(reinterpret_cast<const __m256i *>(kPack.d[mask]));
    for (int c = 0; c < D; ++c) {
      const __m256d sc = _mm256_mul_pd(d[c], ihv);
      _mm256_storeu_pd(s[c] + q, _mm256_castps_pd(_mm256_permutevar8x32_ps(_mm256_castpd_ps(sc), pd)));
    }
    const __m256i pi = _mm256_loadu_si256(reinterpret_cast<const __m256i *>(kPack.i[mask]));
    const __m256i jp = _mm256_permutevar8x32_epi32(_mm256_zextsi128_si256(j4), pi);
    _mm_storeu_si128(reinterpret_cast<__m128i *>(js + q), _mm256_castsi256_si128(jp));
    q += __builtin_popcount(static_cast<unsigned>(mask));
  }
  for (; e < nc; ++e) {
    const int32_t j = cc[e];
    const double *xj = xn + static_cast<size_t>(j) * D;
    double r2 = 0.0;
    for (int c = 0; c < D; ++c) {
      const double dc = xj[c] - xk[c];
      double pc = dc * dc;
      __asm__("" : "+x"(pc));
      r2 += pc;
      s[c][q] = dc * ih;
    }
    js[q] = j;
    q += r2 < R2;
  }
  _mm256_zeroupper();
  return q;
}
#endif

}  // namespace

template <int D>
MFREE_ALWAYS_INLINE bool FluidSystem::table_rows_body(int32_t k0, int32_t k1, const double *xn, double *scratch,
                                                     int64_t *iscratch, bool transpose, bool wide) {
  (void)wide;
  constexpr int L = D + 1;
  const double ih = 1.0 / h_, tol = shepard_cond_, R2 = 4.0 * h_ * h_;
  const int64_t *crp = cand_.rowptr.data();
  const int32_t *ccols = cand_.cols.data();
  const int32_t *cpos = cpos_.data();
  const int64_t *ctr = transpose ? ctrans_.data() : nullptr;
  int64_t *rbeg = rb_.data(), *rend = re_.data();
  bool one_way = false;
  for (int32_t k = k0; k < k1; ++k) {  // k0 starts a chunk
    const double *xk = xn + static_cast<size_t>(k) * D;
    const int64_t o = transpose ? rbeg[k] : k % kChunk == 0 ? crp[k] : rend[k - 1];
    double *Nk = N_.data() + o, *Gk = G_.data() + o * D;
    // the row's neighbours in structure-of-arrays scratch: scaled offsets s = (x_j - x) / h,
    // weights w = f(|s|) and gf = -f'(|s|) / |s|, so that grad_x w_j = gf s / h; the
    // transposed candidates; the columns go straight to the row's place in cols_ (the
    // candidates out of range land on entries of later rows of the chunk, or unused ones).
    double *s[D], *w = scratch + D * static_cast<size_t>(maxrow_), *gf = w + maxrow_;
    for (int c = 0; c < D; ++c) s[c] = scratch + c * static_cast<size_t>(maxrow_);
    int32_t *js = cols_.data() + o;
    int64_t *ts = iscratch;
    int n = 0;
    if (transpose) {  // the rows' ends and positions come from prepare's filter
      for (int64_t e = crp[k]; e < crp[k + 1]; ++e) {
        const int32_t j = ccols[e];
        js[n] = j;
        ts[n] = ctr[e];
        for (int c = 0; c < D; ++c) s[c][n] = (xn[static_cast<size_t>(j) * D + c] - xk[c]) * ih;
        n += cpos[e] >= 0;
      }
    } else {
#if MFREE_SIMD_X86
      if (wide) n = kept_candidates_avx2<D>(xn, k, ccols + crp[k], crp[k + 1] - crp[k], R2, ih, s, js);
      else n = kept_candidates<D>(xn, k, ccols + crp[k], crp[k + 1] - crp[k], R2, ih, s, js);
#else
      n = kept_candidates<D>(xn, k, ccols + crp[k], crp[k + 1] - crp[k], R2, ih, s, js);
#endif
      rbeg[k] = o;
      rend[k] = o + n;
    }
    const double *s0 = s[0], *s1 = s[1], *s2 = s[D - 1];
    FLUID_SIMD()
    for (int m = 0; m < n; ++m) w[m] = s0[m] * s0[m] + s1[m] * s1[m] + (D == 3 ? s2[m] * s2[m] : 0.0);
#if MFREE_SIMD_X86
    if (wide) sqrt_n_avx2(w, n);  // |x_j - x| / h < 2
    else sqrt_n(w, n);
#else
    sqrt_n(w, n);
#endif
    FLUID_SIMD()
    for (int m = 0; m < n; ++m) {
      // the cubic spline as B-spline pieces, f = (2 - r)_+^3 / 4 - (1 - r)_+^3, with
      // (x)_+ = (x + |x|) / 2 (exact): no comparison, which the vectoriser would not
      // if-convert under trapping math
      const double r = w[m], a0 = 1.0 - r, b0 = 2.0 - r;
      const double a = 0.5 * (a0 + std::fabs(a0)), b = 0.5 * (b0 + std::fabs(b0));
      w[m] = 0.25 * b * b * b - a * a * a;
      const double df = 3.0 * a * a - 0.75 * b * b;  // exactly 0 at r = 0
      gf[m] = -df / (r + 1e-300);                    // r + 1e-300 = r unless r < 1e-284
    }
    // moments: M = sum w p p^T and M_,c = sum w_,c p p^T, p = (1, s), w_,c = gf s_c / h
    // (the 1/h is applied after the sums)
    double m0[L][L], mc[D][L][L];  // every entry is set below
    if (D == 2) {
      double a0 = 0, a1 = 0, a2 = 0, a11 = 0, a12 = 0, a22 = 0;
      double b1 = 0, b2 = 0, b11 = 0, b12 = 0, b22 = 0, b111 = 0, b112 = 0, b122 = 0, b222 = 0;
      FLUID_SIMD(reduction(+ : a0, a1, a2, a11, a12, a22, b1, b2, b11, b12, b22, b111, b112, b122, b222))
      for (int m = 0; m < n; ++m) {
        const double x1 = s0[m], x2 = s1[m], wm = w[m], gm = gf[m];
        a0 += wm;
        a1 += wm * x1;
        a2 += wm * x2;
        a11 += wm * x1 * x1;
        a12 += wm * x1 * x2;
        a22 += wm * x2 * x2;
        const double g1 = gm * x1, g2 = gm * x2;
        b1 += g1;
        b2 += g2;
        b11 += g1 * x1;
        b12 += g1 * x2;
        b22 += g2 * x2;
        b111 += g1 * x1 * x1;
        b112 += g1 * x1 * x2;
        b122 += g1 * x2 * x2;
        b222 += g2 * x2 * x2;
      }
      const double M[3][3] = {{a0, a1, a2}, {a1, a11, a12}, {a2, a12, a22}};
      // w_,1 p p^T: gf s1 (1, s1, s2)(1, s1, s2)^T, likewise for s2
      const double M1[3][3] = {{b1, b11, b12}, {b11, b111, b112}, {b12, b112, b122}};
      const double M2[3][3] = {{b2, b12, b22}, {b12, b112, b122}, {b22, b122, b222}};
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) {
          m0[a][b] = M[a][b];
          mc[0][a][b] = M1[a][b] * ih;
          mc[D - 1][a][b] = M2[a][b] * ih;
        }
    } else {
      double acc[L][L] = {}, accc[D][L][L] = {};
      for (int m = 0; m < n; ++m) {
        double p[L];
        p[0] = 1.0;
        for (int c = 0; c < D; ++c) p[1 + c] = s[c][m];
        for (int a = 0; a < L; ++a)
          for (int b = 0; b <= a; ++b) {
            const double pp = p[a] * p[b];
            acc[a][b] += w[m] * pp;
            for (int c = 0; c < D; ++c) accc[c][a][b] += gf[m] * s[c][m] * pp;
          }
      }
      for (int a = 0; a < L; ++a)
        for (int b = 0; b <= a; ++b) {
          m0[a][b] = m0[b][a] = acc[a][b];
          for (int c = 0; c < D; ++c) mc[c][a][b] = mc[c][b][a] = accc[c][a][b] * ih;
        }
    }
    double X[L][L], cond = 1.0;
    // too few neighbours or a singular moment matrix: Shepard functions of the weights
    // (the approximants' lower-order fallback, whose condition number is 1)
    const bool mls = n >= L && spd_inverse<L>(m0, X, cond);
    if (!mls) cond = 1.0;
    cond_[k] = cond;
    if (mls && !(cond > tol)) {
      // 003 eqs 27-31 (MLS, basis shifted to the node and scaled by h): M g = p(0),
      // M g_,c = e_c / h - M_,c g; N_j = w_j g.p_j, N_j,c = w_j g_,c.p_j + w_j,c g.p_j
      double g[L], gc[D][L];
      for (int a = 0; a < L; ++a) g[a] = X[a][0];
      for (int c = 0; c < D; ++c) {
        double rhs[L];
        for (int a = 0; a < L; ++a) {
          double t = 0.0;
          for (int b = 0; b < L; ++b) t += mc[c][a][b] * g[b];
          rhs[a] = -t;
        }
        rhs[1 + c] += ih;
        for (int a = 0; a < L; ++a) {
          double t = 0.0;
          for (int b = 0; b < L; ++b) t += X[a][b] * rhs[b];
          gc[c][a] = t;
        }
      }
      // g.p_j and g_,c.p_j with the coefficients in scalars, for the vectoriser
      const double g0 = g[0], g1 = g[1], g2 = g[2], g3 = g[L - 1];
      const double c00 = gc[0][0], c01 = gc[0][1], c02 = gc[0][2], c03 = gc[0][L - 1];
      const double c10 = gc[1][0], c11 = gc[1][1], c12 = gc[1][2], c13 = gc[1][L - 1];
      const double c20 = gc[D - 1][0], c21 = gc[D - 1][1], c22 = gc[D - 1][2], c23 = gc[D - 1][L - 1];
      FLUID_SIMD()
      for (int m = 0; m < n; ++m) {
        const double x1 = s0[m], x2 = s1[m], x3 = D == 3 ? s2[m] : 0.0;
        const double gp = g0 + g1 * x1 + g2 * x2 + (D == 3 ? g3 * x3 : 0.0);
        const double wm = w[m], gq = gf[m] * ih * gp;
        Nk[m] = wm * gp;
        Gk[m * D] = wm * (c00 + c01 * x1 + c02 * x2 + (D == 3 ? c03 * x3 : 0.0)) + gq * x1;
        Gk[m * D + 1] = wm * (c10 + c11 * x1 + c12 * x2 + (D == 3 ? c13 * x3 : 0.0)) + gq * x2;
        if (D == 3) Gk[m * D + D - 1] = wm * (c20 + c21 * x1 + c22 * x2 + c23 * x3) + gq * x3;
      }
    } else {
      shepard_row<D>(n, w, gf, s, ih, mls, js, Nk, Gk);
    }
    // the transposed copy: N_k(x_j) is entry (j, k) of the transpose
    if (!transpose) continue;
    for (int m = 0; m < n; ++m) {
      const int32_t j = js[m];
      const int64_t t = ts[m];
      if (t < 0 || cpos[t] < 0) {
        one_way = true;
        continue;
      }
      double *nt = NT_.data() + (rbeg[j] + cpos[t]) * (D + 1);  // one cache line per entry
      nt[0] = Nk[m];
      for (int c = 0; c < D; ++c) nt[1 + c] = Gk[m * D + c];
    }
  }
  return one_way;
}

template <int D>
bool FluidSystem::table_rows(int32_t k0, int32_t k1, const double *xn, double *scratch, int64_t *iscratch,
                             bool transpose) {
  return table_rows_body<D>(k0, k1, xn, scratch, iscratch, transpose, false);
}

#if MFREE_SIMD_X86
template <int D>
MFREE_TARGET_AVX2 bool FluidSystem::table_rows_avx2(int32_t k0, int32_t k1, const double *xn, double *scratch,
                                                    int64_t *iscratch, bool transpose) {
  return table_rows_body<D>(k0, k1, xn, scratch, iscratch, transpose, true);
}
#endif

#if MFREE_SIMD_X86
// The columns of kept_candidates<2> alone, four candidates at a time with two 128-bit loads
// per pair of lanes (cheaper than gathers here), the test r2 < R2 rounded as there (no
// FMA), the kept columns left-packed into js; returns their count.
MFREE_TARGET_AVX2 FLUID_NOINLINE int kept_columns2_avx2(const double *xn, int64_t k, const int32_t *cc, int64_t nc,
                                                       double R2, int32_t *js) {
  const __m256d xk = _mm256_set1_pd(xn[2 * k]), yk = _mm256_set1_pd(xn[2 * k + 1]), r2v = _mm256_set1_pd(R2);
  int q = 0;
  int64_t e = 0;
  for (; e + 4 <= nc; e += 4) {
    const int32_t *j = cc + e;
    const __m128d p0 = _mm_loadu_pd(xn + 2 * static_cast<size_t>(j[0])), p1 = _mm_loadu_pd(xn + 2 * static_cast<size_t>(j[1]));
    const __m128d p2 = _mm_loadu_pd(xn + 2 * static_cast<size_t>(j[2])), p3 = _mm_loadu_pd(xn + 2 * static_cast<size_t>(j[3]));
    const __m256d lo = _mm256_insertf128_pd(_mm256_castpd128_pd256(p0), p2, 1);  // x0 y0 x2 y2
    const __m256d hi = _mm256_insertf128_pd(_mm256_castpd128_pd256(p1), p3, 1);  // x1 y1 x3 y3
    const __m256d dx = _mm256_sub_pd(_mm256_unpacklo_pd(lo, hi), xk), dy = _mm256_sub_pd(_mm256_unpackhi_pd(lo, hi), yk);
    __m256d px = _mm256_mul_pd(dx, dx), py = _mm256_mul_pd(dy, dy);
    __asm__("" : "+x"(px), "+x"(py));  // r2 = d0 d0 + d1 d1, rounded as kept_candidates
    const int mask = _mm256_movemask_pd(_mm256_cmp_pd(_mm256_add_pd(px, py), r2v, _CMP_LT_OQ));
    const __m256i pi = _mm256_loadu_si256(reinterpret_cast<const __m256i *>(kPack.i[mask]));
    const __m128i j4 = _mm_loadu_si128(reinterpret_cast<const __m128i *>(j));
    const __m256i jp = _mm256_permutevar8x32_epi32(_mm256_zextsi128_si256(j4), pi);
    _mm_storeu_si128(reinterpret_cast<__m128i *>(js + q), _mm256_castsi256_si128(jp));
    q += __builtin_popcount(static_cast<unsigned>(mask));
  }
  for (; e < nc; ++e) {
    const int32_t j = cc[e];
    const double *xj = xn + static_cast<size_t>(j) * 2;
    const double d0 = xj[0] - xn[2 * k], d1 = xj[1] - xn[2 * k + 1];
    double p0 = d0 * d0, p1 = d1 * d1;
    __asm__("" : "+x"(p0), "+x"(p1));
    js[q] = j;
    q += p0 + p1 < R2;
  }
  _mm256_zeroupper();
  return q;
}

// Rows [k0, k1) in chunks: the candidates closer than 2h filtered into the chunk's rows
// (kept_candidates_avx2), then the approximants' fused linear-MLS rows on them
// (shape_fast_mls1.hpp); the rows they leave (a moment matrix not positive definite or
// singular) and those worse conditioned than shepard_cond_ are computed again by
// table_rows_avx2, which writes their Shepard functions.
void FluidSystem::table_rows2_avx2(int32_t k0, int32_t k1, const double *xn, double *scratch, int64_t *iscratch,
                                   FastScratch &fast, int64_t *rp) {
  const double R2 = 4.0 * h_ * h_;
  const int64_t *crp = cand_.rowptr.data();
  const int32_t *ccols = cand_.cols.data();
  int64_t *rbeg = rb_.data(), *rend = re_.data();
  FastTables ft;
  ft.rowptr = rp;
  ft.cols = cols_.data();
  ft.x[0] = ft.sx[0] = xn;
  ft.x[1] = ft.sx[1] = xn + 1;
  ft.stride = ft.sstride = 2;
  ft.h = ft.sh = &h_;
  ft.hstride = ft.shstride = 0;
  ft.val = N_.data();
  ft.grad = G_.data();
  FastSites fs;
  fs.status = site_status_.data();
  fs.support = site_support_.data();
  fs.order = site_order_.data();
  fs.cond = cond_.data();
  fs.order_used = 1;
  for (int32_t c0 = k0; c0 < k1; c0 += kChunk) {
    const int32_t c1 = std::min(k1, c0 + kChunk);
    for (int32_t k = c0; k < c1; ++k) {
      const int64_t o = k == c0 ? crp[k] : rend[k - 1];
      const int n = kept_columns2_avx2(xn, k, ccols + crp[k], crp[k + 1] - crp[k], R2, cols_.data() + o);
      rbeg[k] = o;
      rend[k] = o + n;
      rp[k] = o;  // the chunk's rows lie one after another
    }
    rp[c1] = rend[c1 - 1];
    mls1_rows2_avx2(ft, c0, c1, kMinRcond, fast, fs);
    for (int32_t k = c0; k < c1; ++k)
      if (site_status_[k] != 0 || cond_[k] > shepard_cond_) table_rows_avx2<2>(k, k + 1, xn, scratch, iscratch, false);
  }
}
#endif

Report FluidSystem::prepare(const double *y, bool checked) {
  check_ready();
  Report rep = checked ? Report() : check_state(y, -1);
  if (!rep.ok()) return rep;
  const int dim = dim_;
  const int32_t nall = nq();
  const size_t nd = static_cast<size_t>(dim) * n_;
  const double *rho = y + 2 * nd;
  parallel_blocks(n_, light_threads(n_), [&](int, int64_t b, int64_t e) {
    for (int64_t i = b; i < e; ++i) vol_[i] = mass_[i] / rho[i];
  });
  const double *xn = node_positions(y);  // + dummies (fluid_wall.cpp)
  Report r = candidates(xn);
  if (!r.ok()) return r;
  const int nt = num_threads(nall);
  const int64_t *crp = cand_.rowptr.data();
  const int32_t *ccols = cand_.cols.data();
  const int64_t nchunk = (nall + kChunk - 1) / kChunk;  // the tables are written by chunks
  const bool transpose = vci_;  // only consistent integration reads NT_ (fluid_wall.cpp)
  if (transpose) {
    // the transposed writes need every row's kept positions first: a filter pass (the
    // row kernel filters on the fly otherwise), the same symmetric test as kept_candidates
    if (!ctrans_valid_) transposed_candidates();
    const double R2 = 4.0 * h_ * h_;
    auto filter = [&](auto dimc) {
      constexpr int D = decltype(dimc)::value;
      int32_t *cpos = cpos_.data();
      int64_t *rbeg = rb_.data(), *rend = re_.data();
      parallel_blocks(nchunk, nt, [&](int, int64_t cb, int64_t ce) {
        for (int64_t k = cb * kChunk; k < std::min<int64_t>(nall, ce * kChunk); ++k) {
          const double *xk = xn + k * D;
          int32_t cnt = 0;
          for (int64_t q = crp[k]; q < crp[k + 1]; ++q) {
            const double *xj = xn + static_cast<size_t>(ccols[q]) * D;
            double r2 = 0.0;
            for (int c = 0; c < D; ++c) {
              const double d = xj[c] - xk[c];
              r2 += d * d;
            }
            const int32_t keep = r2 < R2;
            cpos[q] = keep ? cnt : -1;
            cnt += keep;
          }
          rbeg[k] = k % kChunk == 0 ? crp[k] : rend[k - 1];
          rend[k] = rbeg[k] + cnt;
        }
      });
    };
    if (dim == 2) filter(std::integral_constant<int, 2>());
    else filter(std::integral_constant<int, 3>());
  }
  const size_t per_thread = static_cast<size_t>(dim + 2) * (maxrow_ + 8), iper_thread = static_cast<size_t>(maxrow_);
  if (rows_scratch_.size() < per_thread * nt) rows_scratch_.resize(per_thread * nt);
  if (rows_iscratch_.size() < iper_thread * nt) rows_iscratch_.resize(iper_thread * nt);
#if MFREE_SIMD_X86
  if (dim == 2 && !transpose && simd::use_avx2()) {  // table_rows2_avx2's per-thread scratch
    if (fast_scratch_.size() < static_cast<size_t>(nt)) fast_scratch_.resize(nt);
    for (int t = 0; t < nt; ++t) fast_scratch_[t].reserve(static_cast<int>(maxrow_));
    rows_ptr_.resize(static_cast<size_t>(nt) * (nall + 1));
    site_status_.resize(nall);
    site_support_.resize(nall);
    site_order_.resize(nall);
  }
#endif
  bool one_way[64] = {};  // parallel_blocks runs at most 64 threads
  const bool avx2 = simd::use_avx2();  // once per step: every thread runs the same copy
  (void)avx2;
  auto rows = [&](int t, int32_t k0, int32_t k1) {
    double *scratch = rows_scratch_.data() + per_thread * t;
    int64_t *iscratch = rows_iscratch_.data() + iper_thread * t;
#if MFREE_SIMD_X86
    if (avx2 && dim == 2 && !transpose) {
      table_rows2_avx2(k0, k1, xn, scratch, iscratch, fast_scratch_[t], rows_ptr_.data() + static_cast<size_t>(t) * (nall + 1));
      return false;
    }
    if (avx2)
      return dim == 2 ? table_rows_avx2<2>(k0, k1, xn, scratch, iscratch, transpose)
                      : table_rows_avx2<3>(k0, k1, xn, scratch, iscratch, transpose);
#endif
    return dim == 2 ? table_rows<2>(k0, k1, xn, scratch, iscratch, transpose)
                    : table_rows<3>(k0, k1, xn, scratch, iscratch, transpose);
  };
  parallel_blocks(nchunk, nt, [&](int t, int64_t b, int64_t e) {
    one_way[t] = rows(t, static_cast<int32_t>(b * kChunk), static_cast<int32_t>(std::min<int64_t>(nall, e * kChunk)));
  });
  if (std::any_of(one_way, one_way + 64, [](bool f) { return f; })) {
    // cannot happen with lists from one search radius; a failure rather than a wrong sum
    rep.fail(MFREE_FAIL_NEIGHBORS, "the neighbour lists of the fluid are not symmetric");
    lists_valid_ = false;
    return rep;
  }
  fluid_share();
  vci_setup();  // optional, fluid_wall.cpp
  return rep;
}

}  // namespace mfree
