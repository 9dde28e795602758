// The forms: material matrix, the form's part of the matrix (collocation, mass,
// stiffness) and the body loads; assemble_matrix and assemble_rhs add the boundary terms
// and the replaced rows of assembler_essential.cpp and assembler_tractions.cpp.
#include "core/discretize/assembler.hpp"

#include <algorithm>

#include "core/base/basis.hpp"
#include "core/discretize/strain.hpp"

namespace mfree {

void Assembler::material_matrix(double *D, int &nv) const {
  const double E = young_, nu = poisson_;
  nv = dim_ == 2 ? 3 : 6;
  std::fill(D, D + 36, 0.0);
  if (dim_ == 2) {
    const bool stress = form_ == MFREE_FORM_ELASTICITY_PLANE_STRESS || form_ == MFREE_FORM_COLLOCATION_PLANE_STRESS;
    if (stress) {
      const double f = E / (1.0 - nu * nu);
      D[0] = f; D[1] = f * nu; D[3] = f * nu; D[4] = f; D[8] = f * (1.0 - nu) / 2.0;
    } else {
      const double f = E / ((1.0 + nu) * (1.0 - 2.0 * nu));
      D[0] = f * (1.0 - nu); D[1] = f * nu; D[3] = f * nu; D[4] = f * (1.0 - nu);
      D[8] = f * (1.0 - 2.0 * nu) / 2.0;
    }
    // row-major 3x3 stored with stride 3
    return;
  }
  const double lam = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), mu = E / (2.0 * (1.0 + nu));
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) D[a * 6 + b] = lam + (a == b ? 2.0 * mu : 0.0);
  for (int a = 3; a < 6; ++a) D[a * 6 + a] = mu;
}

void Assembler::assemble_matrix(SparseMatrix &K) const {
  if (!setup_done_) throw Error(MFREE_ERR_STATE, "the assembler is not set up");
  if (K.rows() != ndofs_ || K.rowptr() != rowptr_ || K.colidx() != cols_)
    K.set_pattern(ndofs_, ndofs_, rowptr_, cols_);
  std::vector<double> &v = K.values_mut();
  std::fill(v.begin(), v.end(), 0.0);
  const Entries at{K, v};
  if (collocation()) {
    assemble_collocation(at);
  } else if (mass()) {
    assemble_mass(at);
  } else {
    assemble_stiffness(v);
    assemble_boundary_terms(at);
  }
  assemble_replaced_rows(at);
}

void Assembler::assemble_collocation(const Entries &at) const {
  const int nc = ncomp_, dim = dim_;
  const Approximant &trial = *trial_q_;
  const double E = young_, nu = poisson_;
  double lam = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  const double mu = E / (2.0 * (1.0 + nu));
  if (form_ == MFREE_FORM_COLLOCATION_PLANE_STRESS) lam = 2.0 * lam * mu / (lam + 2.0 * mu);
  const int nh = hessian_size(dim);
  const auto &H = trial.hessians();
  for (int32_t J = 0; J < trial.num_sites(); ++J)
    for (int64_t k = trial.rowptr()[J]; k < trial.rowptr()[J + 1]; ++k) {
      const int32_t K2 = trial.cols()[k];
      double lap = 0.0;
      for (int d = 0; d < dim; ++d) lap += H[k * nh + hessian_index(dim, d, d)];
      if (form_ == MFREE_FORM_COLLOCATION_LAPLACE) {
        if (row_kind_[J] == 0) at(J, K2) += -coef_ * lap;
        continue;
      }
      for (int a = 0; a < nc; ++a) {
        if (row_kind_[J * nc + a] != 0) continue;
        for (int b = 0; b < nc; ++b)
          at(J * nc + a, K2 * nc + b) +=
              -(mu * lap * (a == b ? 1.0 : 0.0) + (lam + mu) * H[k * nh + hessian_index(dim, a, b)]);
      }
    }
}

void Assembler::assemble_mass(const Entries &at) const {
  const QTable &qa = qtrial_, &qb = test_table();
  const auto &Pv = qa.val, &Tv = qb.val;
  for (int32_t q : qorder_) {
    const double w = qa.w[q];
    for (int64_t a = qb.rowptr[q]; a < qb.rowptr[q + 1]; ++a)
      for (int64_t b = qa.rowptr[q]; b < qa.rowptr[q + 1]; ++b) {
        const int32_t J = qb.cols[a], K2 = qa.cols[b];
        if (row_kind_[J] != 0) continue;
        const double m = w * coef_ * Tv[a] * Pv[b];
        if (form_ == MFREE_FORM_MASS) at(J, K2) += m;
        else at(J, J) += m;
      }
  }
}

void Assembler::assemble_stiffness(std::vector<double> &v) const {
  const int nc = ncomp_, dim = dim_;
  double D[36];
  int nv = 0;
  if (elasticity()) material_matrix(D, nv);
  const int dstride = dim == 2 ? 3 : 6;
  // Row by row (gather): for each test node J, the quadrature points its test
  // function sees (the transpose of the test table), with the positions of J's
  // columns in a scatter array, so that no entry is searched for.
  const QTable &qa = qtrial_, &qb = test_table();
  const auto &Pg = qa.grad, &Tg = qb.grad;
  const auto &Ps = qa.sgrad.empty() ? qa.grad : qa.sgrad, &Ts = qb.sgrad.empty() ? qb.grad : qb.sgrad;
  const int32_t nn = ps_->size();
  std::vector<int64_t> tp(static_cast<size_t>(nn) + 1, 0), ta(qb.cols.size());
  std::vector<int32_t> tq(qb.cols.size());
  for (int32_t J : qb.cols) ++tp[static_cast<size_t>(J) + 1];
  for (int32_t J = 0; J < nn; ++J) tp[J + 1] += tp[J];
  {
    // each row's quadrature points in the canonical order, so that every entry is
    // summed in the same order whatever the local numbering
    std::vector<int64_t> next(tp.begin(), tp.end() - 1);
    for (int32_t q : qorder_)
      for (int64_t a = qb.rowptr[q]; a < qb.rowptr[q + 1]; ++a) {
        const int64_t k = next[qb.cols[a]]++;
        tq[k] = q;
        ta[k] = a;
      }
  }
  std::vector<int64_t> pos(nn, -1);
  auto offset = [&](int32_t K2) {
    if (pos[K2] < 0) throw Error(MFREE_ERR_INTERNAL, "assembly entry outside the pattern");
    return pos[K2];
  };
  for (int32_t J = 0; J < nn; ++J) {
    if (tp[J] == tp[J + 1]) continue;
    const int64_t base = rowptr_[static_cast<size_t>(J) * nc];
    for (int32_t i = 0; i < node_deg_[J]; ++i) pos[cols_[base + static_cast<int64_t>(i) * nc] / nc] = int64_t{i} * nc;
    for (int64_t t = tp[J]; t < tp[J + 1]; ++t) {
      const int32_t q = tq[t];
      const int64_t a = ta[t], b0 = qa.rowptr[q], b1 = qa.rowptr[q + 1];
      const double w = qa.w[q];
      if (form_ == MFREE_FORM_LAPLACE) {
        if (row_kind_[J] != 0) continue;
        for (int64_t b = b0; b < b1; ++b) {
          double dot = 0.0;
          for (int d = 0; d < dim; ++d) dot += Tg[a * dim + d] * Pg[b * dim + d];
          v[base + offset(qa.cols[b])] += w * coef_ * dot;
        }
        continue;
      }
      double BJ[6][3], BJD[3][6];  // BJD = B_J^T D
      strain_rows(dim, &Tg[a * dim], &Ts[a * dim], BJ);
      for (int c = 0; c < nc; ++c)
        for (int t2 = 0; t2 < nv; ++t2) {
          double s = 0.0;
          for (int u = 0; u < nv; ++u) s += BJ[u][c] * D[u * dstride + t2];
          BJD[c][t2] = s;
        }
      for (int64_t b = b0; b < b1; ++b) {
        double BK[6][3];
        strain_rows(dim, &Pg[b * dim], &Ps[b * dim], BK);
        const int64_t o = offset(qa.cols[b]);
        for (int c = 0; c < nc; ++c) {
          if (row_kind_[J * nc + c] != 0) continue;
          double *row = &v[rowptr_[J * nc + c] + o];
          for (int e = 0; e < nc; ++e) {
            double s = 0.0;
            for (int t2 = 0; t2 < nv; ++t2) s += BJD[c][t2] * BK[t2][e];
            row[e] += w * s;
          }
        }
      }
    }
    for (int32_t i = 0; i < node_deg_[J]; ++i) pos[cols_[base + static_cast<int64_t>(i) * nc] / nc] = -1;
  }
}

void Assembler::assemble_rhs(double *f) const {
  if (!setup_done_) throw Error(MFREE_ERR_STATE, "the assembler is not set up");
  std::fill(f, f + ndofs_, 0.0);
  if (collocation()) {
    body_loads(f);
  } else if (!mass()) {
    body_loads(f);
    boundary_loads(f);
  }
  replaced_row_loads(f);
  // rows replaced in the form part were zeroed in the matrix; their loads must be too
}

void Assembler::body_loads(double *f) const {
  if (!body_) return;
  const int nc = ncomp_, dim = dim_;
  double val[3], x[3] = {0, 0, 0};
  if (collocation()) {
    for (int32_t J = 0; J < ps_->num_owned(); ++J) {
      for (int d = 0; d < dim; ++d) x[d] = ps_->x(J, d);
      body_(body_user_, x, val);
      for (int c = 0; c < nc; ++c)
        if (row_kind_[J * nc + c] == 0) f[J * nc + c] = val[c];
    }
    return;
  }
  if (!load_q_) return;
  const Approximant &L = *load_q_;
  for (int32_t q : qorder_) {
    const double w = quad_kind_ == 0 ? ps_->volume(q) : qw_[q];
    for (int d = 0; d < dim; ++d) x[d] = quad_kind_ == 0 ? ps_->x(q, d) : qx_[static_cast<size_t>(q) * dim + d];
    body_(body_user_, x, val);
    for (int64_t a = L.rowptr()[q]; a < L.rowptr()[q + 1]; ++a)
      for (int c = 0; c < nc; ++c) f[L.cols()[a] * nc + c] += w * L.values()[a] * val[c];
  }
}

}  // namespace mfree
