// The finite-element layer along the essential boundary (paper 000 eqs 100-105).
#include "core/discretize/assembler.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace mfree {

void Assembler::set_fe_layer(int32_t nelem, int32_t npe, const int32_t *conn, int32_t ngu, const int32_t *gu,
                             int32_t mask, mfree_field_fn g, void *user) {
  if (dim_ != 2) throw Error(MFREE_ERR_UNSUPPORTED, "the finite-element layer is implemented in 2D");
  if (collocation() || mass()) throw Error(MFREE_ERR_UNSUPPORTED, "the finite-element layer is for Galerkin forms");
  if (npe != 3 && npe != 4) throw Error(MFREE_ERR_ARG, "elements must have 3 (triangle) or 4 (quadrilateral) nodes");
  if (nelem < 1 || ngu < 1) throw Error(MFREE_ERR_ARG, "the layer needs elements and essential-boundary nodes");
  if (!conn || !gu) throw Error(MFREE_ERR_NULL, "connectivity or boundary nodes are NULL");
  if (!g) throw Error(MFREE_ERR_NULL, "boundary value function is NULL");
  if (mask <= 0 || mask >= (1 << ncomp_)) throw Error(MFREE_ERR_ARG, "component mask selects no valid component");
  if (fe_.npe && fe_.npe != npe)
    throw Error(MFREE_ERR_ARG, "the layer already has elements with " + std::to_string(fe_.npe) +
                                   " nodes; every call must use the same element type");
  // (the orientation check below reads the positions)
  if (!ps_->pos_data()) throw Error(MFREE_ERR_STATE, "the particle set has no positions");
  const int32_t n = ps_->num_owned();
  // Calls accumulate: elements of every call form one layer (the blending sees all of
  // them) and each call's boundary nodes get its own component mask, so symmetry lines
  // with different constrained components are one layer.
  FeLayer fe = fe_;
  fe.npe = npe;
  const size_t first = fe.conn.size();
  fe.conn.insert(fe.conn.end(), conn, conn + static_cast<size_t>(nelem) * npe);
  fe.on_gu.resize(ps_->size(), 0);
  fe.in_layer.resize(ps_->size(), 0);
  for (int32_t k = 0; k < nelem * npe; ++k) {
    if (conn[k] < 0 || conn[k] >= n)
      throw Error(MFREE_ERR_INPUT, "element " + std::to_string(k / npe) + " refers to particle " +
                                       std::to_string(conn[k]) + ", not an owned particle");
    fe.in_layer[conn[k]] = 1;
  }
  for (int32_t k = 0; k < ngu; ++k) {
    if (gu[k] < 0 || gu[k] >= n || !fe.in_layer[gu[k]])
      throw Error(MFREE_ERR_INPUT, "essential-boundary node " + std::to_string(gu[k]) + " is not a layer node");
    fe.on_gu[gu[k]] = 1;
  }
  // orientation: positive Jacobian at every corner (counter-clockwise, not degenerate)
  for (int32_t e = 0; e < nelem; ++e) {
    const int32_t *c = &fe.conn[first + static_cast<size_t>(e) * npe];
    double xmin[2] = {1e300, 1e300}, xmax[2] = {-1e300, -1e300};
    for (int a = 0; a < npe; ++a) {
      const int32_t i = c[a], j = c[(a + 1) % npe], k = c[(a + npe - 1) % npe];
      const double ax = ps_->x(j, 0) - ps_->x(i, 0), ay = ps_->x(j, 1) - ps_->x(i, 1);
      const double bx = ps_->x(k, 0) - ps_->x(i, 0), by = ps_->x(k, 1) - ps_->x(i, 1);
      if (!(ax * by - ay * bx > 0.0))
        throw Error(MFREE_ERR_INPUT, "layer element " + std::to_string(e) + " of this call" +
                                         " is inverted or degenerate (nodes must run counter-clockwise)");
      for (int d = 0; d < 2; ++d) {
        xmin[d] = std::min(xmin[d], ps_->x(i, d));
        xmax[d] = std::max(xmax[d], ps_->x(i, d));
      }
    }
    for (int d = 0; d < 2; ++d) {
      const double pad = 1e-10 * (xmax[d] - xmin[d] + 1.0);
      fe.bmin.push_back(xmin[d] - pad);
      fe.bmax.push_back(xmax[d] + pad);
    }
  }
  NodeSet ns;
  ns.kind = 3;
  ns.nodes.assign(gu, gu + ngu);
  ns.mask = mask;
  ns.fn = g;
  ns.user = user;
  nsets_.reserve(nsets_.size() + 1);  // the last allocation: nothing below may fail
  fe_ = std::move(fe);
  nsets_.push_back(std::move(ns));
  setup_done_ = false;
}

bool Assembler::fe_shape(int32_t e, const double *x, double *N, double *dN) const {
  const int npe = fe_.npe;
  const int32_t *c = &fe_.conn[static_cast<size_t>(e) * npe];
  if (x[0] < fe_.bmin[2 * e] || x[0] > fe_.bmax[2 * e] || x[1] < fe_.bmin[2 * e + 1] || x[1] > fe_.bmax[2 * e + 1])
    return false;
  double X[4][2];
  for (int a = 0; a < npe; ++a)
    for (int d = 0; d < 2; ++d) X[a][d] = ps_->x(c[a], d);
  const double tol = 1e-10;
  if (npe == 3) {
    const double j00 = X[1][0] - X[0][0], j01 = X[2][0] - X[0][0], j10 = X[1][1] - X[0][1], j11 = X[2][1] - X[0][1];
    const double det = j00 * j11 - j01 * j10;
    const double rx = x[0] - X[0][0], ry = x[1] - X[0][1];
    const double l1 = (j11 * rx - j01 * ry) / det, l2 = (-j10 * rx + j00 * ry) / det;
    if (l1 < -tol || l2 < -tol || l1 + l2 > 1.0 + tol) return false;
    N[0] = 1.0 - l1 - l2;
    N[1] = l1;
    N[2] = l2;
    // dl1/dx = (j11, -j01)/det, dl2/dx = (-j10, j00)/det
    dN[2] = j11 / det;
    dN[3] = -j01 / det;
    dN[4] = -j10 / det;
    dN[5] = j00 / det;
    dN[0] = -dN[2] - dN[4];
    dN[1] = -dN[3] - dN[5];
    return true;
  }
  static const double xi[4] = {-1, 1, 1, -1}, eta[4] = {-1, -1, 1, 1};
  double u = 0.0, v = 0.0, J[2][2] = {{0, 0}, {0, 0}};
  for (int it = 0; it < 30; ++it) {
    double f[2] = {-x[0], -x[1]};
    J[0][0] = J[0][1] = J[1][0] = J[1][1] = 0.0;
    for (int a = 0; a < 4; ++a) {
      const double Na = 0.25 * (1 + xi[a] * u) * (1 + eta[a] * v);
      const double du = 0.25 * xi[a] * (1 + eta[a] * v), dv = 0.25 * eta[a] * (1 + xi[a] * u);
      for (int d = 0; d < 2; ++d) {
        f[d] += Na * X[a][d];
        J[d][0] += du * X[a][d];
        J[d][1] += dv * X[a][d];
      }
    }
    const double det = J[0][0] * J[1][1] - J[0][1] * J[1][0];
    const double su = (J[1][1] * f[0] - J[0][1] * f[1]) / det, sv = (-J[1][0] * f[0] + J[0][0] * f[1]) / det;
    u -= su;
    v -= sv;
    if (std::fabs(su) + std::fabs(sv) < 1e-15) break;
  }
  if (std::fabs(u) > 1.0 + tol || std::fabs(v) > 1.0 + tol) return false;
  J[0][0] = J[0][1] = J[1][0] = J[1][1] = 0.0;
  double dNu[4], dNv[4];
  for (int a = 0; a < 4; ++a) {
    N[a] = 0.25 * (1 + xi[a] * u) * (1 + eta[a] * v);
    dNu[a] = 0.25 * xi[a] * (1 + eta[a] * v);
    dNv[a] = 0.25 * eta[a] * (1 + xi[a] * u);
    for (int d = 0; d < 2; ++d) {
      J[d][0] += dNu[a] * X[a][d];
      J[d][1] += dNv[a] * X[a][d];
    }
  }
  const double det = J[0][0] * J[1][1] - J[0][1] * J[1][0];
  for (int a = 0; a < 4; ++a) {  // grad N = J^-T (dN/du, dN/dv)
    dN[2 * a] = (J[1][1] * dNu[a] - J[1][0] * dNv[a]) / det;
    dN[2 * a + 1] = (-J[0][1] * dNu[a] + J[0][0] * dNv[a]) / det;
  }
  return true;
}

// Paper 000 eqs 100-105: in the layer, Phi0_I = (1 - r) N_I + r Phi_I with r = 3R^2 - 2R^3,
// R = sum of the FE functions of the interface nodes; at nodal quadrature points on the
// essential boundary the functions are the FE ones, the node's volume split among its
// elements (the Figure 2 procedure).
void Assembler::blend_qtable(QTable &t, const HVec<double> *pts) const {
  const int npe = fe_.npe;
  const int32_t nelem = static_cast<int32_t>(fe_.conn.size() / npe);
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
      if (!fe_.on_gu[q]) {
        push(t.w[q]);
        continue;
      }
      std::vector<int32_t> elems;
      for (int32_t e = 0; e < nelem; ++e)
        for (int a = 0; a < npe; ++a)
          if (fe_.conn[static_cast<size_t>(e) * npe + a] == q) elems.push_back(e);
      const double x[2] = {ps_->x(q, 0), ps_->x(q, 1)};
      for (int32_t e : elems) {
        fe_shape(e, x, N, dN);
        cols.clear();
        val.clear();
        grad.clear();
        for (int a = 0; a < npe; ++a) {
          cols.push_back(fe_.conn[static_cast<size_t>(e) * npe + a]);
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
      if (fe_shape(e, x, N, dN)) break;
    if (e == nelem) {
      push(t.w[q]);
      continue;
    }
    const int32_t *c = &fe_.conn[static_cast<size_t>(e) * npe];
    double R = 0.0, gR[2] = {0, 0};
    for (int a = 0; a < npe; ++a)
      if (!fe_.on_gu[c[a]]) {
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
