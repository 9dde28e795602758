// Operator application: the set-up shape-function table applied to host fields.
//
// Every operator is one of two shapes of sparse product over a site's row:
//  - outer: out(s, c W + w) = sum_k T(k, w) u(j_k, c), a table of W values per entry
//    applied to NC fields: VALUE (the values, W = 1), GRADIENT (W = dim), HESSIAN
//    (W = nh), LAPLACIAN (the trace of the Hessian, W = 1);
//  - contraction: out(s) = sum_k sum_d T(k, d) u(j_k, d), the DIVERGENCE.
// The reference backend runs one loop for both shapes, any W and NC (each output the sum
// over the row in row order, from 0). The optimised backend runs the outer product with
// W up to 3 of a stored table (VALUE, GRADIENT, HESSIAN in 1D and 2D) in the kernel of
// apply_rows.inc (W and, up to 3, the fields compile-time; baseline and AVX2 + FMA
// copies), and the rest in the reference loop; the two agree to round-off.
#include <algorithm>
#include <string>
#include <type_traits>

#include "core/shape/approximant.hpp"
#include "core/base/basis.hpp"
#include "core/base/config.hpp"
#include "core/base/parallel.hpp"
#include "core/base/simd.hpp"

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

// One apply: the rows, a table of W values per entry, the fields u(j, c) = u[j ju + c cu]
// and the output out(s, q) = out[s so + q co].
struct OuterJob {
  const int64_t *rowptr;
  const int32_t *cols;
  const double *table;
  const double *u;
  int64_t ju, cu;
  int nc;         // fields
  double *out;
  int64_t so, co;
};
using OuterFn = void (*)(const OuterJob &, int64_t, int64_t);

// Up to kBlock outputs of one site are accumulated together in one pass over its row;
// each output is still summed over the row in one fixed order, so the result does not
// depend on the blocking or on the thread count.
constexpr int kBlock = 24;

namespace base {
constexpr int kChunk = MFREE_VECTOR_EXTENSIONS ? 2 : 1;
inline void leave() {}
#include "core/shape/apply_rows.inc"
}  // namespace base

#if MFREE_SIMD_X86
MFREE_AVX2_BEGIN
namespace avx2 {
constexpr int kChunk = 4;
inline void leave() { MFREE_ZERO_UPPER(); }
#include "core/shape/apply_rows.inc"
}  // namespace avx2
MFREE_AVX2_END
#endif

// The reference loop, rows [b, e). op is the operator, W the values per table entry
// (entry(k, t) writes them to t), nc the fields.
template <class Entry>
void reference_rows(int op, int W, int nc, Entry entry, int64_t b, int64_t e, const OuterJob &j, bool add) {
  double acc[kBlock], t[kBlock];
  if (op == MFREE_OP_DIVERGENCE) {
    for (int64_t s = b; s < e; ++s) {
      double sum = 0.0;
      for (int64_t k = j.rowptr[s]; k < j.rowptr[s + 1]; ++k) {
        entry(k, t);
        const double *uj = j.u + j.cols[k] * j.ju;
        for (int d = 0; d < W; ++d) sum += t[d] * uj[d * j.cu];
      }
      double &o = j.out[s * j.so];
      if (add) o += sum;
      else o = sum;
    }
    return;
  }
  const int cb = kBlock / W;  // fields per pass
  for (int64_t s = b; s < e; ++s) {
    for (int c0 = 0; c0 < nc; c0 += cb) {
      const int n = std::min(cb, nc - c0);
      std::fill(acc, acc + n * W, 0.0);
      for (int64_t k = j.rowptr[s]; k < j.rowptr[s + 1]; ++k) {
        entry(k, t);
        const double *uj = j.u + j.cols[k] * j.ju + c0 * j.cu;
        for (int c = 0; c < n; ++c) {
          const double v = uj[c * j.cu];
          for (int w = 0; w < W; ++w) acc[c * W + w] += t[w] * v;
        }
      }
      double *o = j.out + s * j.so + static_cast<int64_t>(c0) * W * j.co;
      for (int q = 0; q < n * W; ++q) {
        if (add) o[q * j.co] += acc[q];
        else o[q * j.co] = acc[q];
      }
    }
  }
}

}  // namespace

void Approximant::apply(int op, int ncomp, const double *u, int ulayout, int64_t uld, double *out,
                        int olayout, int64_t old, bool add) const {
  const int dim = ps_->dim(), nh = hessian_size(dim);
  op_components(op, ncomp);  // checks op and ncomp
  OuterJob job;
  job.rowptr = rowptr_.data();
  job.cols = cols_.data();
  job.u = u;
  job.nc = ncomp;
  // strides of a site / particle index and of a component in the two layouts
  job.ju = ulayout == MFREE_LAYOUT_AOS ? uld : 1;
  job.cu = ulayout == MFREE_LAYOUT_AOS ? 1 : uld;
  job.out = out;
  job.so = olayout == MFREE_LAYOUT_AOS ? old : 1;
  job.co = olayout == MFREE_LAYOUT_AOS ? 1 : old;
  int W = 1;  // values per table entry
  switch (op) {
    case MFREE_OP_VALUE: job.table = val_.data(); break;
    case MFREE_OP_GRADIENT:
    case MFREE_OP_DIVERGENCE: job.table = grad_.data(); W = dim; break;
    case MFREE_OP_HESSIAN: job.table = hess_.data(); W = nh; break;
    default: job.table = nullptr; break;  // LAPLACIAN: traces of the Hessians
  }
  // once per call: every thread runs the same code
  OuterFn fast = nullptr;
  if (optimised() && job.table && op != MFREE_OP_DIVERGENCE && W <= 3) {
#if MFREE_SIMD_X86
    if (simd::use_avx2()) fast = avx2::outer_fn(W, ncomp, add);
    else
#endif
      fast = base::outer_fn(W, ncomp, add);
  }
  const double *tab = job.table, *hs = hess_.data();
  auto rows = [&](int64_t b, int64_t e) {
    if (fast) fast(job, b, e);
    else if (tab)
      reference_rows(op, W, ncomp, [&](int64_t k, double *t) { std::copy(tab + k * W, tab + (k + 1) * W, t); },
                     b, e, job, add);
    else
      reference_rows(op, 1, ncomp, [&](int64_t k, double *t) {
        double tr = 0.0;
        for (int d = 0; d < dim; ++d) tr += hs[k * nh + hessian_index(dim, d, d)];
        t[0] = tr;
      }, b, e, job, add);
  };
  // Blocks of equal nonzero counts rather than equal site counts: the work of a row is
  // its length, and rows differ (boundaries, variable supports, host points). Block v
  // starts at the first row that starts at or after nnz v / nb; a row is computed the
  // same way in any block, so results stay bitwise identical for any thread count.
  const int64_t *rp = job.rowptr;
  const int nt = num_threads(static_cast<int64_t>(cols_.size()) / 8);
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
