#include "core/discretize/fe_layer.hpp"

#include <algorithm>
#include <string>
#include <vector>

#include "core/base/error.hpp"
#include "core/shape/fe_shape.hpp"
#include "mfree.h"

namespace mfree {

void FeLayer::check_arguments(int32_t nelem, int32_t npe, const int32_t *conn, int32_t ngu, const int32_t *gu) {
  if (npe != 3 && npe != 4) throw Error(MFREE_ERR_ARG, "elements must have 3 (triangle) or 4 (quadrilateral) nodes");
  if (nelem < 1 || ngu < 1) throw Error(MFREE_ERR_ARG, "the layer needs elements and essential-boundary nodes");
  if (!conn || !gu) throw Error(MFREE_ERR_NULL, "connectivity or boundary nodes are NULL");
}

void FeLayer::add(int32_t nelem, int32_t npe, const int32_t *conn, int32_t ngu, const int32_t *gu) {
  check_arguments(nelem, npe, conn, ngu, gu);
  if (npe_ && npe_ != npe)
    throw Error(MFREE_ERR_ARG, "the layer already has elements with " + std::to_string(npe_) +
                                   " nodes; every call must use the same element type");
  // (the orientation check below reads the positions)
  if (!ps_->pos_data()) throw Error(MFREE_ERR_STATE, "the particle set has no positions");
  const int32_t n = ps_->num_owned();
  // Calls accumulate: elements of every call form one layer (the blending sees all of
  // them) and each call's boundary nodes get its own component mask, so symmetry lines
  // with different constrained components are one layer.
  FeLayer fe = *this;
  fe.npe_ = npe;
  const size_t first = fe.conn_.size();
  fe.conn_.insert(fe.conn_.end(), conn, conn + static_cast<size_t>(nelem) * npe);
  fe.on_gu_.resize(ps_->size(), 0);
  fe.in_layer_.resize(ps_->size(), 0);
  for (int32_t k = 0; k < nelem * npe; ++k) {
    if (conn[k] < 0 || conn[k] >= n)
      throw Error(MFREE_ERR_INPUT, "element " + std::to_string(k / npe) + " refers to particle " +
                                       std::to_string(conn[k]) + ", not an owned particle");
    fe.in_layer_[conn[k]] = 1;
  }
  for (int32_t k = 0; k < ngu; ++k) {
    if (gu[k] < 0 || gu[k] >= n || !fe.in_layer_[gu[k]])
      throw Error(MFREE_ERR_INPUT, "essential-boundary node " + std::to_string(gu[k]) + " is not a layer node");
    fe.on_gu_[gu[k]] = 1;
  }
  // orientation: positive Jacobian at every corner (counter-clockwise, not degenerate)
  for (int32_t e = 0; e < nelem; ++e) {
    const int32_t *c = &fe.conn_[first + static_cast<size_t>(e) * npe];
    double xmin[2] = {1e300, 1e300}, xmax[2] = {-1e300, -1e300}, X[4 * 3] = {0};
    for (int a = 0; a < npe; ++a)
      for (int d = 0; d < 2; ++d) X[3 * a + d] = ps_->x(c[a], d);
    for (int a = 0; a < npe; ++a) {
      if (!(corner_cross(X, npe, a) > 0.0))
        throw Error(MFREE_ERR_INPUT, "layer element " + std::to_string(e) + " of this call" +
                                         " is inverted or degenerate (nodes must run counter-clockwise)");
      for (int d = 0; d < 2; ++d) {
        xmin[d] = std::min(xmin[d], X[3 * a + d]);
        xmax[d] = std::max(xmax[d], X[3 * a + d]);
      }
    }
    for (int d = 0; d < 2; ++d) {
      const double pad = 1e-10 * (xmax[d] - xmin[d] + 1.0);
      fe.bmin_.push_back(xmin[d] - pad);
      fe.bmax_.push_back(xmax[d] + pad);
    }
  }
  *this = std::move(fe);
}

bool FeLayer::shape(int32_t e, const double *x, double *N, double *dN) const {
  const int npe = npe_;
  const int32_t *c = &conn_[static_cast<size_t>(e) * npe];
  if (x[0] < bmin_[2 * e] || x[0] > bmax_[2 * e] || x[1] < bmin_[2 * e + 1] || x[1] > bmax_[2 * e + 1])
    return false;
  double X[4 * 3] = {0};
  for (int a = 0; a < npe; ++a)
    for (int d = 0; d < 2; ++d) X[3 * a + d] = ps_->x(c[a], d);
  return element_shape_at(npe == 3 ? MFREE_ELEMENT_TRI3 : MFREE_ELEMENT_QUAD4, X, x, N, dN);
}

// Paper 000 eqs 100-105: in the layer, Phi0_I = (1 - r) N_I + r Phi_I with r = 3R^2 - 2R^3,
// R = sum of the FE functions of the interface nodes; at nodal quadrature points on the
// essential boundary the functions are the FE ones, the node's volume split among its
// elements (the Figure 2 procedure).
void FeLayer::blend(QTable &t, const HVec<double> *pts) const {
  const int npe = npe_;
  const int32_t nelem = static_cast<int32_t>(conn_.size() / npe);
  QTable out;
  out.rowptr.assign(1, 0);
  double N[4], dN[8];
  std::vector<int32_t> cols;
  std::vector<double> val, grad, sgrad;
  const bool has_s = !t.sgrad.empty();
  int32_t cur = 0;  // the input point being pushed
  auto push = [&](double w) {
    out.w.push_back(w);
    out.x.insert(out.x.end(), t.x.begin() + 2 * static_cast<size_t>(cur), t.x.begin() + 2 * static_cast<size_t>(cur) + 2);
    out.cols.insert(out.cols.end(), cols.begin(), cols.end());
    out.val.insert(out.val.end(), val.begin(), val.end());
    out.grad.insert(out.grad.end(), grad.begin(), grad.end());
    if (has_s) out.sgrad.insert(out.sgrad.end(), sgrad.begin(), sgrad.end());
    out.rowptr.push_back(static_cast<int64_t>(out.cols.size()));
  };
  for (int32_t q = 0; q < t.size(); ++q) {
    cur = q;
    const int64_t k0 = t.rowptr[q], k1 = t.rowptr[q + 1];
    cols.assign(t.cols.begin() + k0, t.cols.begin() + k1);
    val.assign(t.val.begin() + k0, t.val.begin() + k1);
    grad.assign(t.grad.begin() + 2 * k0, t.grad.begin() + 2 * k1);
    if (has_s) sgrad.assign(t.sgrad.begin() + 2 * k0, t.sgrad.begin() + 2 * k1);
    if (!pts) {
      if (!on_gu_[q]) {
        push(t.w[q]);
        continue;
      }
      std::vector<int32_t> elems;
      for (int32_t e = 0; e < nelem; ++e)
        for (int a = 0; a < npe; ++a)
          if (conn_[static_cast<size_t>(e) * npe + a] == q) elems.push_back(e);
      const double x[2] = {ps_->x(q, 0), ps_->x(q, 1)};
      for (int32_t e : elems) {
        shape(e, x, N, dN);
        cols.clear();
        val.clear();
        grad.clear();
        for (int a = 0; a < npe; ++a) {
          cols.push_back(conn_[static_cast<size_t>(e) * npe + a]);
          val.push_back(N[a]);
          grad.push_back(dN[2 * a]);
          grad.push_back(dN[2 * a + 1]);
        }
        if (has_s) sgrad = grad;
        push(t.w[q] / static_cast<double>(elems.size()));
      }
      continue;
    }
    const double x[2] = {(*pts)[2 * static_cast<size_t>(q)], (*pts)[2 * static_cast<size_t>(q) + 1]};
    int32_t e = 0;
    for (; e < nelem; ++e)
      if (shape(e, x, N, dN)) break;
    if (e == nelem) {
      push(t.w[q]);
      continue;
    }
    const int32_t *c = &conn_[static_cast<size_t>(e) * npe];
    double R = 0.0, gR[2] = {0, 0};
    for (int a = 0; a < npe; ++a)
      if (!on_gu_[c[a]]) {
        R += N[a];
        gR[0] += dN[2 * a];
        gR[1] += dN[2 * a + 1];
      }
    const double r = 3 * R * R - 2 * R * R * R, dr = 6 * R - 6 * R * R;
    const double gr[2] = {dr * gR[0], dr * gR[1]};
    for (size_t k = 0; k < cols.size(); ++k) {  // r Phi
      const double phi = val[k];
      for (int d = 0; d < 2; ++d) grad[2 * k + d] = gr[d] * phi + r * grad[2 * k + d];
      if (has_s)
        for (int d = 0; d < 2; ++d) sgrad[2 * k + d] = gr[d] * phi + r * sgrad[2 * k + d];
      val[k] = r * phi;
    }
    for (int a = 0; a < npe; ++a) {  // + (1 - r) N
      size_t k = 0;
      while (k < cols.size() && cols[k] != c[a]) ++k;
      if (k == cols.size()) {
        cols.push_back(c[a]);
        val.push_back(0.0);
        grad.push_back(0.0);
        grad.push_back(0.0);
        if (has_s) sgrad.push_back(0.0), sgrad.push_back(0.0);
      }
      val[k] += (1 - r) * N[a];
      for (int d = 0; d < 2; ++d) grad[2 * k + d] += -gr[d] * N[a] + (1 - r) * dN[2 * a + d];
      if (has_s)
        for (int d = 0; d < 2; ++d) sgrad[2 * k + d] += -gr[d] * N[a] + (1 - r) * dN[2 * a + d];
    }
    push(t.w[q]);
  }
  t = std::move(out);
}

}  // namespace mfree
