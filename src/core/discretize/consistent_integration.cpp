#include "core/discretize/consistent_integration.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace mfree {

// Chen, Hillman and Rueter (IJNME 93, 2013): with the corrected gradients
// grad Psi_J + C_J p(x) at the quadrature points of J's support, p = (1, (x - x_J) / h_J),
// the quadrature satisfies the divergence theorem for Psi_J times every p_k,
//   sum_q (grad Psi_J p_k + Psi_J grad p_k)(x_q) w_q = sum_b (Psi_J p_k n)(x_b) w_b,
// so that trial functions that reproduce linear fields pass the linear patch test
// whatever the quadrature (nodal, or the layer's strip sampled at its two edges), and
// the integration error of linear stress fields is removed too. A support whose moment
// matrix is singular (too few points) gets the constant correction only.
void correct_test_gradients(const ParticleSet &ps, QTable &t, const QTable &b, const HVec<double> &normals) {
  const int dim = ps.dim(), np = 1 + dim;
  const int32_t n = ps.size();
  std::vector<double> M(static_cast<size_t>(n) * np * np, 0.0), R(static_cast<size_t>(n) * np * dim, 0.0);
  auto basis = [&](int32_t J, const double *x, double *P) {
    const double h = ps.h(J);
    P[0] = 1.0;
    for (int d = 0; d < dim; ++d) P[1 + d] = (x[d] - ps.x(J, d)) / h;
  };
  double P[4];
  for (int32_t p = 0; p < b.size(); ++p)
    for (int64_t a = b.rowptr[p]; a < b.rowptr[p + 1]; ++a) {
      const int32_t J = b.cols[a];
      basis(J, &b.x[static_cast<size_t>(p) * dim], P);
      for (int k = 0; k < np; ++k)
        for (int i = 0; i < dim; ++i)
          R[(static_cast<size_t>(J) * np + k) * dim + i] +=
              b.w[p] * b.val[a] * P[k] * normals[static_cast<size_t>(p) * dim + i];
    }
  for (int32_t q = 0; q < t.size(); ++q)
    for (int64_t a = t.rowptr[q]; a < t.rowptr[q + 1]; ++a) {
      const int32_t J = t.cols[a];
      const double w = t.w[q], hinv = 1.0 / ps.h(J);
      basis(J, &t.x[static_cast<size_t>(q) * dim], P);
      double *m = &M[static_cast<size_t>(J) * np * np];
      for (int k = 0; k < np; ++k)
        for (int l = 0; l < np; ++l) m[k * np + l] += w * P[k] * P[l];
      for (int k = 0; k < np; ++k)
        for (int i = 0; i < dim; ++i)
          R[(static_cast<size_t>(J) * np + k) * dim + i] -=
              w * (t.grad[a * dim + i] * P[k] + (k == 1 + i ? t.val[a] * hinv : 0.0));
    }
  // C_J (np x dim) = M_J^-1 R_J by Gaussian elimination with partial pivoting
  std::vector<double> Cc(static_cast<size_t>(n) * np * dim, 0.0);
  for (int32_t J = 0; J < n; ++J) {
    double A[4][4], B[4][3];
    const double *m = &M[static_cast<size_t>(J) * np * np], *r = &R[static_cast<size_t>(J) * np * dim];
    if (!(m[0] > 0.0)) continue;
    int use = np;
    for (int k = 0; k < np; ++k)
      for (int l = 0; l < np; ++l) A[k][l] = m[k * np + l];
    for (int k = 0; k < np; ++k)
      for (int i = 0; i < dim; ++i) B[k][i] = r[k * dim + i];
    for (int c = 0; c < use; ++c) {
      int piv = c;
      for (int k = c + 1; k < use; ++k)
        if (std::fabs(A[k][c]) > std::fabs(A[piv][c])) piv = k;
      if (std::fabs(A[piv][c]) < 1e-8 * m[0]) {  // singular: the constant correction only
        use = 1;
        A[0][0] = m[0];
        for (int i = 0; i < dim; ++i) B[0][i] = r[i];
        break;
      }
      std::swap(A[c], A[piv]);
      std::swap(B[c], B[piv]);
      for (int k = c + 1; k < use; ++k) {
        const double f = A[k][c] / A[c][c];
        for (int l = c; l < use; ++l) A[k][l] -= f * A[c][l];
        for (int i = 0; i < dim; ++i) B[k][i] -= f * B[c][i];
      }
    }
    double *cj = &Cc[static_cast<size_t>(J) * np * dim];
    for (int k = use - 1; k >= 0; --k)
      for (int i = 0; i < dim; ++i) {
        double v = B[k][i];
        for (int l = k + 1; l < use; ++l) v -= A[k][l] * cj[l * dim + i];
        cj[k * dim + i] = v / A[k][k];
      }
  }
  for (int32_t q = 0; q < t.size(); ++q)
    for (int64_t a = t.rowptr[q]; a < t.rowptr[q + 1]; ++a) {
      const int32_t J = t.cols[a];
      basis(J, &t.x[static_cast<size_t>(q) * dim], P);
      const double *cj = &Cc[static_cast<size_t>(J) * np * dim];
      for (int i = 0; i < dim; ++i)
        for (int k = 0; k < np; ++k) t.grad[a * dim + i] += cj[k * dim + i] * P[k];
    }
  t.sgrad.clear();  // particles-only test functions are rejected by set_consistent_integration
}

}  // namespace mfree
