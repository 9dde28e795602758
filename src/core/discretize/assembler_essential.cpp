// Essential conditions: penalty, Lagrange multipliers, Nitsche (boundary points) and
// replaced rows (Dirichlet nodes, the FE layer's nodes, collocation traction rows): their
// setters, their matrix terms and their loads.
#include "core/discretize/assembler.hpp"

#include <cmath>
#include <string>

namespace mfree {

void Assembler::set_penalty(double alpha) {
  if (!(std::isfinite(alpha) && alpha > 0.0)) throw Error(MFREE_ERR_ARG, "penalty must be finite and > 0");
  penalty_ = alpha;
  penalty_set_ = true;
}

void Assembler::add_dirichlet(int method, int32_t npts, const double *x, int layout, int64_t ld,
                              const double *w, const double *normals, int32_t mask, mfree_field_fn g,
                              void *user) {
  if (method != MFREE_BC_PENALTY && method != MFREE_BC_LAGRANGE && method != MFREE_BC_NITSCHE)
    throw Error(MFREE_ERR_ARG, "add_dirichlet takes MFREE_BC_PENALTY, MFREE_BC_LAGRANGE or MFREE_BC_NITSCHE "
                               "(row replacement: add_dirichlet_nodes)");
  if (mass()) throw Error(MFREE_ERR_UNSUPPORTED, "mass forms take no boundary conditions");
  if (method == MFREE_BC_NITSCHE) {
    if (npts > 0 && !normals) throw Error(MFREE_ERR_NULL, "Nitsche needs the boundary normals");
    if (npts > 0 && !w) throw Error(MFREE_ERR_NULL, "Nitsche weights are NULL");
    if (is_particles_only(trial_cfg_.method) || is_particles_only(test_cfg_.method))
      throw Error(MFREE_ERR_UNSUPPORTED, "Nitsche needs derivatives at boundary points, which particles-only "
                                         "methods do not define");
    check_unit_normals(npts, normals, "");
  }
  if (collocation()) throw Error(MFREE_ERR_UNSUPPORTED, "collocation forms take Dirichlet nodes");
  if (mask <= 0 || mask >= (1 << ncomp_)) throw Error(MFREE_ERR_ARG, "component mask selects no valid component");
  if (!g) throw Error(MFREE_ERR_NULL, "boundary value function is NULL");
  check_points(npts, x, w, "dirichlet");
  if (method == MFREE_BC_PENALTY && npts > 0 && !w) throw Error(MFREE_ERR_NULL, "penalty weights are NULL");
  auto s = std::make_unique<PointSet>();
  s->kind = method == MFREE_BC_PENALTY ? 2 : method == MFREE_BC_LAGRANGE ? 3 : 4;
  read_points(npts, x, layout, ld, s->x);
  if (method == MFREE_BC_NITSCHE) s->normals.assign(normals, normals + static_cast<size_t>(npts) * dim_);
  if (w) s->w.assign(w, w + npts);
  else s->w.assign(npts, 1.0);
  s->mask = mask;
  s->fn = g;
  s->user = user;
  psets_.push_back(std::move(s));
  setup_done_ = false;
}

void Assembler::check_values(mfree_field_fn g, int32_t mask) const {
  if (!g) throw Error(MFREE_ERR_NULL, "boundary value function is NULL");
  if (mask <= 0 || mask >= (1 << ncomp_)) throw Error(MFREE_ERR_ARG, "component mask selects no valid component");
}

Assembler::NodeSet Assembler::node_set(int kind, int32_t n, const int32_t *nodes, int32_t mask, mfree_field_fn fn,
                                       void *user) {
  NodeSet s;
  s.kind = kind;
  s.nodes.assign(nodes, nodes + n);
  s.mask = mask;
  s.fn = fn;
  s.user = user;
  return s;
}

void Assembler::add_dirichlet_nodes(int32_t n, const int32_t *nodes, int32_t mask, mfree_field_fn g, void *user) {
  if (n < 0) throw Error(MFREE_ERR_ARG, "negative node count");
  if (n > 0 && !nodes) throw Error(MFREE_ERR_NULL, "nodes are NULL");
  check_values(g, mask);
  for (int32_t k = 0; k < n; ++k)
    if (nodes[k] < 0 || nodes[k] >= ps_->num_owned())
      throw Error(MFREE_ERR_INPUT, "node " + std::to_string(nodes[k]) + " is not an owned particle");
  nsets_.push_back(node_set(1, n, nodes, mask, g, user));
  setup_done_ = false;
}

void Assembler::set_fe_layer(int32_t nelem, int32_t npe, const int32_t *conn, int32_t ngu, const int32_t *gu,
                             int32_t mask, mfree_field_fn g, void *user) {
  if (dim_ != 2) throw Error(MFREE_ERR_UNSUPPORTED, "the finite-element layer is implemented in 2D");
  if (collocation() || mass()) throw Error(MFREE_ERR_UNSUPPORTED, "the finite-element layer is for Galerkin forms");
  FeLayer::check_arguments(nelem, npe, conn, ngu, gu);
  check_values(g, mask);
  NodeSet ns = node_set(3, ngu, gu, mask, g, user);
  nsets_.reserve(nsets_.size() + 1);  // the last allocation before the layer: nothing after it may fail
  fe_.add(nelem, npe, conn, ngu, gu);
  nsets_.push_back(std::move(ns));
  setup_done_ = false;
}

// Boundary terms at points: penalty (kind 2), Nitsche (kind 4: consistency, symmetry and
// stabilisation) and the Lagrange multipliers' rows and columns (kind 3).
void Assembler::assemble_boundary_terms(const Entries &at) const {
  const int nc = ncomp_, dim = dim_;
  const int32_t nbase = ps_->size() * nc;
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

// Rows replaced at nodes: identity rows (the FE layer's nodes, particles-only methods,
// interpolating trial functions), Dirichlet rows u(x_J) = g, and the collocation forms'
// traction rows (sigma(u) n)(x_J) = t.
void Assembler::assemble_replaced_rows(const Entries &at) const {
  const int nc = ncomp_, dim = dim_;
  const int32_t nbase = ps_->size() * nc;
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
        double T[3][3];
        traction_row(&G[b * dim], nrm, T);
        for (int e = 0; e < nc; ++e) at(dof, trial_q_->cols()[b] * nc + e) += T[c][e];
      }
    }
  }
}

// Loads of the boundary points: tractions (kind 1), penalty (2), Lagrange (3: the
// multipliers' right-hand sides) and Nitsche (4).
void Assembler::boundary_loads(double *f) const {
  const int nc = ncomp_, dim = dim_;
  const int32_t nbase = ps_->size() * nc;
  double val[3], x[3] = {0, 0, 0};
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

void Assembler::replaced_row_loads(double *f) const {
  const int nc = ncomp_, dim = dim_;
  const int32_t nbase = ps_->size() * nc;
  double val[3], x[3] = {0, 0, 0};
  for (int32_t dof = 0; dof < nbase; ++dof) {
    if (row_kind_[dof] == 0) continue;
    const int32_t J = dof / nc;
    const int c = dof % nc;
    const NodeSet &ns = nsets_[row_set_[dof]];
    for (int d = 0; d < dim; ++d) x[d] = ps_->x(J, d);
    ns.fn(ns.user, x, val);
    f[dof] = val[c];
  }
}

}  // namespace mfree
