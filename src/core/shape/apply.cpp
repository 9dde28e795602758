// Operator application: the set-up shape-function table applied to host fields.
#include <algorithm>
#include <cstring>
#include <string>

#include "core/shape/approximant.hpp"
#include "core/base/basis.hpp"
#include "core/base/parallel.hpp"
#include "core/base/simd.hpp"

#if MFREE_SIMD_X86
#include <immintrin.h>
#endif


namespace mfree {

int Approximant::op_components(int op, int ncomp) const {
  const int dim = ps_->dim();
  switch (op) {
    case MFREE_OP_VALUE:
    case MFREE_OP_LAPLACIAN:
      return ncomp;
    case MFREE_OP_GRADIENT:
      return ncomp * dim;
    case MFREE_OP_DIVERGENCE:
      if (ncomp != dim)
        throw Error(MFREE_ERR_MISMATCH, "divergence needs ncomp = dim = " + std::to_string(dim) +
                                            ", got " + std::to_string(ncomp));
      return 1;
    case MFREE_OP_HESSIAN:
      return ncomp * hessian_size(dim);
    default:
      throw Error(MFREE_ERR_ARG, "unknown operator " + std::to_string(op));
  }
}

namespace {

// Up to kBlock outputs of one site are accumulated together in one pass over its row;
// each output is still the sum over the row in row order, as a one-output loop would
// give, so the result does not depend on the blocking or on the thread count.
constexpr int kBlock = 24;

// out rows [b, e) of the gradient of ncomp fields (D compile-time: the inner loops
// unroll).
template <int D>
void gradient_rows(int64_t b, int64_t e, const int64_t *rowptr, const int32_t *cols, const double *grad,
                   int ncomp, const double *u, int64_t ju, int64_t cu, double *out, int64_t so, int64_t co,
                   bool add) {
  for (int64_t s = b; s < e; ++s) {
    for (int c0 = 0; c0 < ncomp; c0 += kBlock / D) {
      const int nc = std::min(kBlock / D, ncomp - c0);
      double acc[kBlock] = {0};
      for (int64_t k = rowptr[s]; k < rowptr[s + 1]; ++k) {
        const double *g = grad + k * D;
        const double *uj = u + cols[k] * ju + c0 * cu;
        for (int c = 0; c < nc; ++c) {
          const double v = uj[c * cu];
          for (int d = 0; d < D; ++d) acc[c * D + d] += g[d] * v;
        }
      }
      double *o = out + s * so + static_cast<int64_t>(c0) * D * co;
      for (int q = 0; q < nc * D; ++q) {
        if (add) o[q * co] += acc[q];
        else o[q * co] = acc[q];
      }
    }
  }
}

// The hot cases (D and NC <= 3 fields compile-time, apply or apply_add): the NC * D
// accumulators live in registers and the row is one branch-free streaming pass over
// the columns and the gradient table. Same operations in the same order as
// gradient_rows (each output summed over the row in row order, starting from 0), so the
// results are bitwise those of the general loop.
template <int D, int NC, bool Add>
void gradient_rows_fixed(int64_t b, int64_t e, const int64_t *rowptr, const int32_t *cols,
                         const double *grad, const double *u, int64_t ju, int64_t cu, double *out,
                         int64_t so, int64_t co) {
  int64_t k = rowptr[b];
  for (int64_t s = b; s < e; ++s) {
    const int64_t k1 = rowptr[s + 1];
    double acc[NC * D];
#pragma GCC unroll 9
    for (int q = 0; q < NC * D; ++q) acc[q] = 0.0;
    for (; k < k1; ++k) {
      const double *g = grad + k * D;
      const double *uj = u + cols[k] * ju;
#pragma GCC unroll 3
      for (int c = 0; c < NC; ++c) {
        const double v = uj[c * cu];
#pragma GCC unroll 3
        for (int d = 0; d < D; ++d) acc[c * D + d] += g[d] * v;
      }
    }
    double *o = out + s * so;
#pragma GCC unroll 9
    for (int q = 0; q < NC * D; ++q) {
      if (Add) o[q * co] += acc[q];
      else o[q * co] = acc[q];
    }
  }
}

#if defined(__GNUC__)
// The same kernel for D = 2, 3 with two-lane vectors (GCC/Clang vector extensions: SSE2
// on x86-64, NEON on arm64): gradient components 0 and 1 of a field are one lane pair,
// so a table entry costs NC vector multiply-adds (plus NC scalar ones in 3D) instead of
// NC * D scalar ones. Every lane does the scalar kernel's operations in its order (a
// product, then a sum; no fused multiply-add at the baseline target), so the results
// are bitwise those of gradient_rows_fixed.
typedef double v2d_t __attribute__((vector_size(16)));

template <int D, int NC, bool Add>
void gradient_rows_v2(int64_t b, int64_t e, const int64_t *rowptr, const int32_t *cols, const double *grad,
                      const double *u, int64_t ju, int64_t cu, double *out, int64_t so, int64_t co) {
  static_assert(D == 2 || D == 3, "two-lane kernel: D = 2 or 3");
  int64_t k = rowptr[b];
  for (int64_t s = b; s < e; ++s) {
    const int64_t k1 = rowptr[s + 1];
    v2d_t a01[NC];
    double a2[NC];
#pragma GCC unroll 3
    for (int c = 0; c < NC; ++c) {
      a01[c] = v2d_t{0.0, 0.0};
      a2[c] = 0.0;
    }
    for (; k < k1; ++k) {
      const double *g = grad + k * D;
      v2d_t g01;
      std::memcpy(&g01, g, sizeof g01);
      const double *uj = u + cols[k] * ju;
#pragma GCC unroll 3
      for (int c = 0; c < NC; ++c) {
        const double v = uj[c * cu];
        a01[c] += g01 * v;
        if (D == 3) a2[c] += g[2] * v;
      }
    }
    double *o = out + s * so;
#pragma GCC unroll 3
    for (int c = 0; c < NC; ++c) {
      double r[3] = {a01[c][0], a01[c][1], a2[c]};
#pragma GCC unroll 3
      for (int d = 0; d < D; ++d) {
        double &w = o[(c * D + d) * co];
        if (Add) w += r[d];
        else w = r[d];
      }
    }
  }
}
#endif

#if MFREE_SIMD_X86
// AVX2 + FMA copies for the 2D and 3D gradient of NC = 1 or 3 fields, chosen once per apply with
// simd::use_avx2() (MFREE_SIMD=baseline keeps the two-lane kernel above). The two-lane
// kernel needs ~15 (scalar) and ~32 (3-vector) instructions per table entry; here an
// entry costs one or three 4-lane FMAs. Every output is summed in ONE fixed order for
// both NC: two partial sums, fma(g_d, u_c, .) over the row's entries at even and at odd
// positions, in row order from 0, then even + odd. For NC = 1 the lanes are d (gradient
// components), for NC = 3 the lanes of accumulator d are the fields c: the same
// operations on each output, so a field's gradient is bitwise the same whether applied
// alone or as part of a 3-vector, and (a row is always done whole by one thread) for any
// thread count. Against the baseline kernel the results differ at round-off (fused
// multiply-add, two partial sums).
MFREE_AVX2_BEGIN
namespace avx2 {

// One row of the gradient of NC = 3 fields (D = 2 or 3), entries [k, k1): accumulator d
// holds d/dx_d of the three fields in lanes 0-2, with the even/odd partial sums of the rule
// above. Returns k1.
template <int D, bool Add>
MFREE_ALWAYS_INLINE int64_t fields3_row(int64_t k, int64_t k1, const int32_t *cols, const double *grad,
                                        const double *u, int64_t ju, int64_t cu, double *o, int64_t co) {
  const __m256i m3 = _mm256_set_epi64x(0, -1, -1, -1);  // lanes 0-2: never reads past a field
  auto field = [&](int64_t j) {
    const double *uj = u + j * ju;
    if (cu == 1) return _mm256_maskload_pd(uj, m3);
    return _mm256_set_pd(0.0, uj[2 * cu], uj[cu], uj[0]);
  };
  __m256d p[D], q[D];
#pragma GCC unroll 3
  for (int d = 0; d < D; ++d) p[d] = q[d] = _mm256_setzero_pd();
  for (; k + 1 < k1; k += 2) {
    const double *g = grad + k * D;
    const __m256d ua = field(cols[k]), ub = field(cols[k + 1]);
#pragma GCC unroll 3
    for (int d = 0; d < D; ++d) p[d] = _mm256_fmadd_pd(_mm256_broadcast_sd(g + d), ua, p[d]);
#pragma GCC unroll 3
    for (int d = 0; d < D; ++d) q[d] = _mm256_fmadd_pd(_mm256_broadcast_sd(g + D + d), ub, q[d]);
  }
  if (k < k1) {
    const double *g = grad + k * D;
    const __m256d ua = field(cols[k]);
#pragma GCC unroll 3
    for (int d = 0; d < D; ++d) p[d] = _mm256_fmadd_pd(_mm256_broadcast_sd(g + d), ua, p[d]);
    ++k;
  }
  alignas(32) double r[D][4];
#pragma GCC unroll 3
  for (int d = 0; d < D; ++d) _mm256_store_pd(r[d], _mm256_add_pd(p[d], q[d]));
  for (int c = 0; c < 3; ++c)
    for (int d = 0; d < D; ++d) {
      double &w = o[(c * D + d) * co];
      if (Add) w += r[d][c];
      else w = r[d][c];
    }
  return k;
}

template <int NC, bool Add>
void gradient_rows_3d(int64_t b, int64_t e, const int64_t *rowptr, const int32_t *cols, const double *grad,
                      const double *u, int64_t ju, int64_t cu, double *out, int64_t so, int64_t co) {
  static_assert(NC == 1 || NC == 3, "AVX2 3D kernel: NC = 1 or 3");
  const __m256i m3 = _mm256_set_epi64x(0, -1, -1, -1);  // lanes 0-2: never reads past an entry
  int64_t k = rowptr[b];
  for (int64_t s = b; s < e; ++s) {
    const int64_t k1 = rowptr[s + 1];
    double *o = out + s * so;
    if constexpr (NC == 1) {
      __m256d p = _mm256_setzero_pd(), q = _mm256_setzero_pd();
      for (; k + 1 < k1; k += 2) {
        const double *g = grad + k * 3;
        const __m256d ga = _mm256_loadu_pd(g);       // lane 3 = next entry's g0: unused lane
        const __m256d gb = _mm256_maskload_pd(g + 3, m3);
        p = _mm256_fmadd_pd(ga, _mm256_broadcast_sd(u + cols[k] * ju), p);
        q = _mm256_fmadd_pd(gb, _mm256_broadcast_sd(u + cols[k + 1] * ju), q);
      }
      if (k < k1) {
        p = _mm256_fmadd_pd(_mm256_maskload_pd(grad + k * 3, m3), _mm256_broadcast_sd(u + cols[k] * ju), p);
        ++k;
      }
      alignas(32) double r[4];
      _mm256_store_pd(r, _mm256_add_pd(p, q));
      for (int d = 0; d < 3; ++d) {
        if (Add) o[d * co] += r[d];
        else o[d * co] = r[d];
      }
    } else {
      k = fields3_row<3, Add>(k, k1, cols, grad, u, ju, cu, o, co);
    }
  }
}

// The 2D copy, same summation rule: two partial sums per output (entries at even and at
// odd positions of the row, fma in row order, then even + odd). NC = 1 takes two entries
// per vector (lanes 0-1: the even entry's g0, g1; lanes 2-3: the odd one's), NC = 3 one
// accumulator per gradient component with the fields in lanes 0-2, so that a field's
// gradient is bitwise the same alone or inside a 3-vector.
template <int NC, bool Add>
void gradient_rows_2d(int64_t b, int64_t e, const int64_t *rowptr, const int32_t *cols, const double *grad,
                      const double *u, int64_t ju, int64_t cu, double *out, int64_t so, int64_t co) {
  static_assert(NC == 1 || NC == 3, "AVX2 2D kernel: NC = 1 or 3");
  int64_t k = rowptr[b];
  for (int64_t s = b; s < e; ++s) {
    const int64_t k1 = rowptr[s + 1];
    double *o = out + s * so;
    if constexpr (NC == 1) {
      __m256d p = _mm256_setzero_pd();
      for (; k + 1 < k1; k += 2) {
        const __m256d g = _mm256_loadu_pd(grad + k * 2);
        const __m256d uu = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loaddup_pd(u + cols[k] * ju)),
                                                _mm_loaddup_pd(u + cols[k + 1] * ju), 1);
        p = _mm256_fmadd_pd(g, uu, p);
      }
      if (k < k1) {  // the last entry of an odd row is an even one: lanes 0-1 only
        const __m128d lo = _mm_fmadd_pd(_mm_loadu_pd(grad + k * 2), _mm_loaddup_pd(u + cols[k] * ju),
                                        _mm256_castpd256_pd128(p));
        p = _mm256_insertf128_pd(p, lo, 0);
        ++k;
      }
      alignas(32) double r[4];
      _mm256_store_pd(r, p);
      for (int d = 0; d < 2; ++d) {
        const double v = r[d] + r[d + 2];
        if (Add) o[d * co] += v;
        else o[d * co] = v;
      }
    } else {
      k = fields3_row<2, Add>(k, k1, cols, grad, u, ju, cu, o, co);
    }
  }
}

// The 2D or the 3D kernel.
template <int D, int NC, bool Add>
void gradient_rows_simd(int64_t b, int64_t e, const int64_t *rowptr, const int32_t *cols, const double *grad,
                        const double *u, int64_t ju, int64_t cu, double *out, int64_t so, int64_t co) {
  if constexpr (D == 2) gradient_rows_2d<NC, Add>(b, e, rowptr, cols, grad, u, ju, cu, out, so, co);
  else gradient_rows_3d<NC, Add>(b, e, rowptr, cols, grad, u, ju, cu, out, so, co);
}

}  // namespace avx2
MFREE_AVX2_END
#endif

template <int D, int NC, bool Add>
void gradient_rows_best(int64_t b, int64_t e, const int64_t *rowptr, const int32_t *cols, const double *grad,
                        const double *u, int64_t ju, int64_t cu, double *out, int64_t so, int64_t co) {
#if defined(__GNUC__)
  if constexpr (D >= 2) {
    gradient_rows_v2<D, NC, Add>(b, e, rowptr, cols, grad, u, ju, cu, out, so, co);
    return;
  }
#endif
  gradient_rows_fixed<D, NC, Add>(b, e, rowptr, cols, grad, u, ju, cu, out, so, co);
}

template <int D>
void gradient_block(int64_t b, int64_t e, const int64_t *rowptr, const int32_t *cols, const double *grad,
                    int ncomp, const double *u, int64_t ju, int64_t cu, double *out, int64_t so, int64_t co,
                    bool add, bool use_avx) {
#if MFREE_SIMD_X86
  if constexpr (D == 2 || D == 3) {
    if (use_avx && (ncomp == 1 || ncomp == 3)) {
      if (ncomp == 1) {
        if (add) avx2::gradient_rows_simd<D, 1, true>(b, e, rowptr, cols, grad, u, ju, cu, out, so, co);
        else avx2::gradient_rows_simd<D, 1, false>(b, e, rowptr, cols, grad, u, ju, cu, out, so, co);
      } else {
        if (add) avx2::gradient_rows_simd<D, 3, true>(b, e, rowptr, cols, grad, u, ju, cu, out, so, co);
        else avx2::gradient_rows_simd<D, 3, false>(b, e, rowptr, cols, grad, u, ju, cu, out, so, co);
      }
      return;
    }
  }
#endif
  (void)use_avx;
#define MFREE_GRAD_FIXED(NC)                                                                        \
  case NC:                                                                                          \
    if (add) gradient_rows_best<D, NC, true>(b, e, rowptr, cols, grad, u, ju, cu, out, so, co);  \
    else gradient_rows_best<D, NC, false>(b, e, rowptr, cols, grad, u, ju, cu, out, so, co); \
    return;
  switch (ncomp) {
    MFREE_GRAD_FIXED(1)
    MFREE_GRAD_FIXED(2)
    MFREE_GRAD_FIXED(3)
    default:
      gradient_rows<D>(b, e, rowptr, cols, grad, ncomp, u, ju, cu, out, so, co, add);
  }
#undef MFREE_GRAD_FIXED
}

}  // namespace

void Approximant::apply(int op, int ncomp, const double *u, int ulayout, int64_t uld, double *out,
                        int olayout, int64_t old, bool add) const {
  const int dim = ps_->dim(), nh = hessian_size(dim);
  const int ocomp = op_components(op, ncomp);
  // strides of a site / particle index and of a component in the two layouts
  const int64_t ju = ulayout == MFREE_LAYOUT_AOS ? uld : 1, cu = ulayout == MFREE_LAYOUT_AOS ? 1 : uld;
  const int64_t so = olayout == MFREE_LAYOUT_AOS ? old : 1, co = olayout == MFREE_LAYOUT_AOS ? 1 : old;
  const int64_t *rp = rowptr_.data();
  const int32_t *cl = cols_.data();
  const int nt = num_threads(static_cast<int64_t>(cols_.size()) / 8);
  // once per call: every thread runs the same copy
  const bool use_avx = op == MFREE_OP_GRADIENT && (dim == 2 || dim == 3) && simd::use_avx2();
  // output rows [b, e)
  auto rows = [&](int64_t b, int64_t e) {
    if (op == MFREE_OP_GRADIENT) {
      if (dim == 1) gradient_block<1>(b, e, rp, cl, grad_.data(), ncomp, u, ju, cu, out, so, co, add, false);
      else if (dim == 2) gradient_block<2>(b, e, rp, cl, grad_.data(), ncomp, u, ju, cu, out, so, co, add, use_avx);
      else gradient_block<3>(b, e, rp, cl, grad_.data(), ncomp, u, ju, cu, out, so, co, add, use_avx);
      return;
    }
    double acc[kBlock];
    for (int64_t s = b; s < e; ++s) {
      const int64_t k0 = rp[s], k1 = rp[s + 1];
      for (int oc0 = 0; oc0 < ocomp; oc0 += kBlock) {
        const int nb = std::min(kBlock, ocomp - oc0);
        for (int q = 0; q < nb; ++q) acc[q] = 0.0;
        switch (op) {
          case MFREE_OP_VALUE:
            for (int64_t k = k0; k < k1; ++k) {
              const double v = val_[k], *uj = u + cl[k] * ju;
              for (int q = 0; q < nb; ++q) acc[q] += v * uj[(oc0 + q) * cu];
            }
            break;
          case MFREE_OP_DIVERGENCE:
            for (int64_t k = k0; k < k1; ++k) {
              const double *uj = u + cl[k] * ju;
              for (int d = 0; d < dim; ++d) acc[0] += grad_[k * dim + d] * uj[d * cu];
            }
            break;
          case MFREE_OP_LAPLACIAN:
            for (int64_t k = k0; k < k1; ++k) {
              double tr = 0.0;
              for (int d = 0; d < dim; ++d) tr += hess_[k * nh + hessian_index(dim, d, d)];
              const double *uj = u + cl[k] * ju;
              for (int q = 0; q < nb; ++q) acc[q] += tr * uj[(oc0 + q) * cu];
            }
            break;
          case MFREE_OP_HESSIAN:
            for (int64_t k = k0; k < k1; ++k) {
              const double *H = &hess_[k * nh], *uj = u + cl[k] * ju;
              for (int q = 0; q < nb; ++q) {
                const int oc = oc0 + q;
                acc[q] += H[oc % nh] * uj[(oc / nh) * cu];
              }
            }
            break;
          default:
            break;
        }
        for (int q = 0; q < nb; ++q) {
          double &o = out[s * so + (oc0 + q) * co];
          if (add) o += acc[q];
          else o = acc[q];
        }
      }
    }
  };
  // Blocks of equal nonzero counts rather than equal site counts: the work of a row is
  // its length, and rows differ (boundaries, variable supports, host points). Block v
  // starts at the first row that starts at or after nnz v / nb; a row is computed the
  // same way in any block, so results stay bitwise identical for any thread count.
  const int nb = block_count(nt);
  const int64_t nnz = rp[nsites_];
  auto split = [&](int64_t v) {
    if (v >= nb) return static_cast<int64_t>(nsites_);
    const int64_t target = v * (nnz / nb) + (v * (nnz % nb)) / nb;
    return static_cast<int64_t>(std::lower_bound(rp, rp + nsites_, target) - rp);
  };
  parallel_blocks(nb, nt, [&](int, int64_t vb, int64_t ve) {
    for (int64_t v = vb; v < ve; ++v) rows(split(v), split(v + 1));
  });
}

}  // namespace mfree
