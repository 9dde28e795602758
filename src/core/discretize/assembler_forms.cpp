// The forms: material matrix, assembly of the matrix and of the right-hand side.
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
  const int nc = ncomp_, dim = dim_;
  const int32_t nbase = ps_->size() * nc;
  auto at = [&](int32_t r, int32_t c) -> double & {
    const int64_t k = K.find(r, c);
    if (k < 0) throw Error(MFREE_ERR_INTERNAL, "assembly entry outside the pattern");
    return v[k];
  };
  const Approximant &trial = *trial_q_;
  double D[36];
  int nv = 0;
  if (elasticity()) material_matrix(D, nv);
  const int dstride = dim == 2 ? 3 : 6;

  if (collocation()) {
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
  } else if (form_ == MFREE_FORM_MASS || form_ == MFREE_FORM_MASS_LUMPED) {
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
  } else {
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
    // penalty, Nitsche and Lagrange terms
    for (size_t si = 0; si < psets_.size(); ++si) {
      auto &s = psets_[si];
      const QView ts{ps_test_[si]}, tr{ps_trial_[si]};
      if (s->kind == 2) {
        for (int32_t p = 0; p < tr.num_sites(); ++p)
          for (int64_t a = ts.rowptr()[p]; a < ts.rowptr()[p + 1]; ++a)
            for (int64_t b = tr.rowptr()[p]; b < tr.rowptr()[p + 1]; ++b)
              for (int c = 0; c < nc; ++c) {
                const int32_t J = ts.cols()[a];
                if (!(s->mask & (1 << c)) || row_kind_[J * nc + c] != 0) continue;
                at(J * nc + c, tr.cols()[b] * nc + c) +=
                    penalty_ * s->w[p] * ts.values()[a] * tr.values()[b];
              }
      } else if (s->kind == 4) {
        for (int32_t p = 0; p < tr.num_sites(); ++p) {
          const double w = s->w[p], *n = &s->normals[static_cast<size_t>(p) * dim];
          for (int64_t a = ts.rowptr()[p]; a < ts.rowptr()[p + 1]; ++a) {
            const int32_t J = ts.cols()[a];
            const double psi = ts.values()[a];
            double TJ[3][3];
            traction_row(&ts.gradients()[a * dim], n, TJ);
            for (int64_t b = tr.rowptr()[p]; b < tr.rowptr()[p + 1]; ++b) {
              const int32_t K2 = tr.cols()[b];
              const double phi = tr.values()[b];
              double TK[3][3];
              traction_row(&tr.gradients()[b * dim], n, TK);
              for (int c = 0; c < nc; ++c) {
                if (!(s->mask & (1 << c))) continue;
                // consistency: -psi (sigma(u) n)_c in row (J, c)
                if (row_kind_[J * nc + c] == 0)
                  for (int e = 0; e < nc; ++e) at(J * nc + c, K2 * nc + e) += -w * psi * TK[c][e];
                // symmetry: -(sigma(psi e_a) n)_c u_c in rows (J, a)
                for (int aa = 0; aa < nc; ++aa)
                  if (row_kind_[J * nc + aa] == 0) at(J * nc + aa, K2 * nc + c) += -w * TJ[c][aa] * phi;
                // stabilisation
                if (row_kind_[J * nc + c] == 0) at(J * nc + c, K2 * nc + c) += w * nitsche_ * psi * phi;
              }
            }
          }
        }
      } else if (s->kind == 3) {
        int32_t m = nbase + s->first_multiplier;
        for (int32_t p = 0; p < tr.num_sites(); ++p)
          for (int c = 0; c < nc; ++c) {
            if (!(s->mask & (1 << c))) continue;
            for (int64_t b = tr.rowptr()[p]; b < tr.rowptr()[p + 1]; ++b) {
              const int32_t d = tr.cols()[b] * nc + c;
              at(m, d) += tr.values()[b];
              if (row_kind_[d] == 0) at(d, m) += tr.values()[b];
            }
            ++m;
          }
      }
    }
  }
  // replaced rows at nodes
  const Approximant *tn = collocation() ? trial_q_.get() : trial_nodes_.get();
  for (int32_t dof = 0; dof < nbase; ++dof) {
    if (row_kind_[dof] == 0) continue;
    const int32_t J = dof / nc;
    const int c = dof % nc;
    const NodeSet &ns = nsets_[row_set_[dof]];
    if (row_kind_[dof] == 3) {
      at(dof, dof) += 1.0;
    } else if (row_kind_[dof] == 1 && tn->interpolating()) {
      at(dof, dof) += 1.0;  // Kronecker delta (MPFEM, 004 Sect. 2.4): u_J = g(x_J) exactly
    } else if (row_kind_[dof] == 1) {
      for (int64_t b = tn->rowptr()[J]; b < tn->rowptr()[J + 1]; ++b)
        at(dof, tn->cols()[b] * nc + c) += tn->values()[b];
    } else {
      const double *nrm = &ns.normals[static_cast<size_t>(row_node_[dof]) * dim];
      const auto &G = trial_q_->gradients();
      for (int64_t b = trial_q_->rowptr()[J]; b < trial_q_->rowptr()[J + 1]; ++b) {
        const int32_t K2 = trial_q_->cols()[b];
        if (!elasticity()) {
          double s = 0.0;
          for (int d = 0; d < dim; ++d) s += nrm[d] * G[b * dim + d];
          at(dof, K2) += coef_ * s;
          continue;
        }
        double B[6][3];
        strain_rows(dim, &G[b * dim], B);
        for (int e = 0; e < nc; ++e) {
          double s = 0.0;  // (sigma n)_c = sum_d sigma_cd n_d, sigma = D B u
          for (int d = 0; d < dim; ++d) {
            const int vr = voigt(dim, c, d);
            for (int t = 0; t < nv; ++t) s += nrm[d] * D[vr * dstride + t] * B[t][e];
          }
          at(dof, K2 * nc + e) += s;
        }
      }
    }
  }
}

void Assembler::assemble_rhs(double *f) const {
  if (!setup_done_) throw Error(MFREE_ERR_STATE, "the assembler is not set up");
  std::fill(f, f + ndofs_, 0.0);
  const int nc = ncomp_, dim = dim_;
  const int32_t nbase = ps_->size() * nc;
  double val[3], x[3] = {0, 0, 0};
  if (collocation()) {
    if (body_)
      for (int32_t J = 0; J < ps_->num_owned(); ++J) {
        for (int d = 0; d < dim; ++d) x[d] = ps_->x(J, d);
        body_(body_user_, x, val);
        for (int c = 0; c < nc; ++c)
          if (row_kind_[J * nc + c] == 0) f[J * nc + c] = val[c];
      }
  } else if (!mass()) {
    if (body_ && load_q_) {
      const Approximant &L = *load_q_;
      for (int32_t q : qorder_) {
        const double w = quad_kind_ == 0 ? ps_->volume(q) : qw_[q];
        for (int d = 0; d < dim; ++d) x[d] = quad_kind_ == 0 ? ps_->x(q, d) : qx_[static_cast<size_t>(q) * dim + d];
        body_(body_user_, x, val);
        for (int64_t a = L.rowptr()[q]; a < L.rowptr()[q + 1]; ++a)
          for (int c = 0; c < nc; ++c) f[L.cols()[a] * nc + c] += w * L.values()[a] * val[c];
      }
    }
    for (size_t si = 0; si < psets_.size(); ++si) {
      auto &s = psets_[si];
      if (s->kind == 5) continue;  // boundary of the consistent integration: no load
      const QView ts{ps_test_[si]};
      const int32_t np = static_cast<int32_t>(s->w.size());
      int32_t m = nbase + s->first_multiplier;
      for (int32_t p = 0; p < np; ++p) {
        for (int d = 0; d < dim; ++d) x[d] = s->x[static_cast<size_t>(p) * dim + d];
        s->fn(s->user, x, val);
        if (s->kind == 4) {
          const double *n = &s->normals[static_cast<size_t>(p) * dim];
          for (int64_t a = ts.rowptr()[p]; a < ts.rowptr()[p + 1]; ++a) {
            const int32_t J = ts.cols()[a];
            double TJ[3][3];
            traction_row(&ts.gradients()[a * dim], n, TJ);
            for (int c = 0; c < nc; ++c) {
              if (!(s->mask & (1 << c))) continue;
              for (int aa = 0; aa < nc; ++aa) f[J * nc + aa] += -s->w[p] * TJ[c][aa] * val[c];
              f[J * nc + c] += s->w[p] * nitsche_ * ts.values()[a] * val[c];
            }
          }
        } else if (s->kind == 1 || s->kind == 2) {
          const double fac = s->kind == 1 ? s->w[p] : penalty_ * s->w[p];
          for (int64_t a = ts.rowptr()[p]; a < ts.rowptr()[p + 1]; ++a)
            for (int c = 0; c < nc; ++c) {
              if (s->kind == 2 && !(s->mask & (1 << c))) continue;
              f[ts.cols()[a] * nc + c] += fac * ts.values()[a] * val[c];
            }
        } else if (s->kind == 3) {
          for (int c = 0; c < nc; ++c)
            if (s->mask & (1 << c)) f[m++] = val[c];
        }
      }
    }
  }
  // replaced rows
  for (int32_t dof = 0; dof < nbase; ++dof) {
    if (row_kind_[dof] == 0) continue;
    const int32_t J = dof / nc;
    const int c = dof % nc;
    const NodeSet &ns = nsets_[row_set_[dof]];
    for (int d = 0; d < dim; ++d) x[d] = ps_->x(J, d);
    ns.fn(ns.user, x, val);
    f[dof] = val[c];
  }
  // rows replaced in the form part were zeroed in the matrix; their loads must be too
}

}  // namespace mfree
