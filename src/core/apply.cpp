// Operator application: the set-up shape-function table applied to host fields.
#include <algorithm>
#include <string>

#include "approximant.hpp"
#include "basis.hpp"
#include "parallel.hpp"

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

template <int D>
void gradient_block(int64_t b, int64_t e, const int64_t *rowptr, const int32_t *cols, const double *grad,
                    int ncomp, const double *u, int64_t ju, int64_t cu, double *out, int64_t so, int64_t co,
                    bool add) {
#define MFREE_GRAD_FIXED(NC)                                                                        \
  case NC:                                                                                          \
    if (add) gradient_rows_fixed<D, NC, true>(b, e, rowptr, cols, grad, u, ju, cu, out, so, co);    \
    else gradient_rows_fixed<D, NC, false>(b, e, rowptr, cols, grad, u, ju, cu, out, so, co);       \
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
  parallel_blocks(nsites_, nt, [&](int, int64_t b, int64_t e) {
    if (op == MFREE_OP_GRADIENT) {
      if (dim == 1) gradient_block<1>(b, e, rp, cl, grad_.data(), ncomp, u, ju, cu, out, so, co, add);
      else if (dim == 2) gradient_block<2>(b, e, rp, cl, grad_.data(), ncomp, u, ju, cu, out, so, co, add);
      else gradient_block<3>(b, e, rp, cl, grad_.data(), ncomp, u, ju, cu, out, so, co, add);
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
  });
}

}  // namespace mfree
