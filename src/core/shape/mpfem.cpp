// The MPFEM approximant (paper 004): its options and the tables of its shape functions,
// element-weighted sums of the elements' general shape functions.
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <memory>
#include <sstream>
#include <string>

#include "core/base/basis.hpp"
#include "core/base/quadrature.hpp"
#include "core/shape/approximant.hpp"
#include "core/shape/mpfem.hpp"
#include "core/shape/mpfem_weights.hpp"

namespace mfree {

namespace {

// What a site's row holds: values always (the normalised weights need them), gradients and
// Hessians when asked for; full: the derivatives of the weights too (004 eq 21), else
// the assumed-strain or nodal forms (eqs 33-38), which differentiate N only.
struct RowOptions {
  RowOptions(int dim_, int mode, bool fg_, bool fh_)
      : dim(dim_), nh(hessian_size(dim_)), full(mode == MFREE_MPFEM_DERIV_FULL),
        nodal(mode == MFREE_MPFEM_DERIV_NODAL), d1(full && (fg_ || fh_)), d2(full && fh_), fg(fg_), fh(fh_) {}
  int dim, nh;
  bool full, nodal, d1, d2, fg, fh;
};

// Host points must be finite with positive finite supports.
void check_points(int32_t npts, int dim, const VectorArray &px, const ScalarArray &ph) {
  for (int32_t s = 0; s < npts; ++s) {
    for (int c = 0; c < dim; ++c)
      if (!std::isfinite(px(s, c)))
        throw Error(MFREE_ERR_INPUT, "point " + std::to_string(s) + " has a non-finite coordinate");
    if (!(std::isfinite(ph(s)) && ph(s) > 0.0))
      throw Error(MFREE_ERR_INPUT, "point " + std::to_string(s) + " has support <= 0 or non-finite");
  }
}

// A site's functions, one slot per node (3 gradient and 6 Hessian numbers per slot), in
// the order the elements reached them; ew is scratch for the element weights.
struct SiteRow {
  std::vector<int32_t> node;
  std::vector<double> v, g, h;
  std::vector<ElemWeight> ew;
};

// Shape functions of a site with support h from the elements cand (first nodes at
// dfirst[3 i] from the site): Phi_I = sum_e omega_e N_I^e with the normalised element
// weights omega_e = W_e / sum W (004 eqs 6, 11, 12) and, under the full scheme, their
// derivatives. False (row empty) when no element has positive weight.
bool site_row(const MeshGeometry &geo, const KernelProfile &K, const std::vector<int32_t> &cand,
              const std::vector<double> &dfirst, double h, const RowOptions &o,
              const std::vector<double> &xg, const std::vector<double> &wg, SiteRow &row) {
  const int dim = o.dim, nh = o.nh;
  const bool fg = o.fg, fh = o.fh, full = o.full;
  const size_t nc = cand.size();
  std::vector<ElemWeight> &ew = row.ew;
  ew.assign(nc, ElemWeight());
  double D = 0.0, dD[3] = {0, 0, 0}, d2D[6] = {0, 0, 0, 0, 0, 0};
  for (size_t i = 0; i < nc; ++i) {
    if (o.nodal) {
      ew[i].W = 1.0 / geo.measure[cand[i]];  // 004 eq 38
    } else {
      element_weight(geo, K, cand[i], &dfirst[3 * i], h, o.d1, o.d2, xg, wg, ew[i]);
    }
    D += ew[i].W;
    for (int a = 0; a < dim; ++a) dD[a] += ew[i].dW[a];
    for (int k = 0; k < nh; ++k) d2D[k] += ew[i].d2W[k];
  }
  std::vector<int32_t> &rnode = row.node;
  std::vector<double> &rv = row.v, &rg = row.g, &rh = row.h;
  rnode.clear();
  rv.clear();
  rg.clear();
  rh.clear();
  if (!(D > 0.0)) return false;
  for (size_t i = 0; i < nc; ++i) {
    const ElemWeight &w = ew[i];
    bool any = w.W != 0.0;
    for (int a = 0; a < dim; ++a) any = any || w.dW[a] != 0.0;
    if (!any) continue;
    // normalised weights (004 eqs 6, 11, 12) and their derivatives
    const double om = w.W / D;
    double dom[3] = {0, 0, 0}, d2om[6] = {0, 0, 0, 0, 0, 0};
    for (int a = 0; a < dim; ++a) dom[a] = (w.dW[a] - om * dD[a]) / D;
    for (int a = 0; a < dim; ++a)
      for (int b = a; b < dim; ++b) {
        const int k = hessian_index(dim, a, b);
        d2om[k] = (w.d2W[k] - dom[b] * dD[a] - dom[a] * dD[b] - om * d2D[k]) / D;
      }
    const int32_t e = cand[i];
    const int n = geo.nn(e);
    double xr[3] = {0, 0, 0}, N[8], dN[24], d2N[48];
    for (int c = 0; c < dim; ++c) xr[c] = -dfirst[3 * i + c];
    // only the derivatives asked for (the Hessians of the general shape functions
    // are needed for the Hessian table only)
    geo.shape(e, xr, N, (fg || fh) ? dN : nullptr, fh ? d2N : nullptr);
    for (int I = 0; I < n; ++I) {
      const int32_t node = geo.nodes[geo.ptr[e] + I];
      size_t slot = 0;
      while (slot < rnode.size() && rnode[slot] != node) ++slot;
      if (slot == rnode.size()) {
        rnode.push_back(node);
        rv.push_back(0.0);
        rg.insert(rg.end(), 3, 0.0);
        rh.insert(rh.end(), 6, 0.0);
      }
      rv[slot] += om * N[I];
      if (!(fg || fh)) continue;
      for (int a = 0; a < dim; ++a)
        rg[3 * slot + a] += (full ? dom[a] * N[I] : 0.0) + om * dN[3 * I + a];
      if (!fh) continue;
      for (int a = 0; a < dim; ++a)
        for (int b = a; b < dim; ++b) {
          const int k = hessian_index(dim, a, b);
          double v = om * d2N[6 * I + k];
          if (full) v += d2om[k] * N[I] + dom[a] * dN[3 * I + b] + dom[b] * dN[3 * I + a];
          rh[6 * slot + k] += v;
        }
    }
  }
  return true;
}

// 004 eq 13 at every node of the mesh: no node's support may reach, with positive weight,
// an element that does not contain the node. count: the nodes that violate it; node,
// elem, w: the first of them, the element and its unnormalised weight.
struct Violation {
  int64_t count = 0;
  int32_t node = -1, elem = -1;
  double w = 0.0;
};

Violation interpolation_violations(const ParticleSet &ps, const MeshGeometry &geo, const KernelProfile &K,
                                   ElementGrid *grid, int32_t tag0, const int32_t *pst, const int32_t *pbad,
                                   const std::vector<double> &xg, const std::vector<double> &wg) {
  const int dim = ps.dim();
  const int32_t ne = geo.size();
  std::vector<int32_t> near;
  Violation v;
  for (int32_t P = 0; P < ps.size(); ++P) {
    if (geo.node_ptr[P] == geo.node_ptr[P + 1] || pst[P] != 0 || pbad[P] != 0) continue;
    const double h = ps.h(P), Rh = K.radius() * h;
    bool bad = false;
    if (grid) {
      double xp[3] = {0, 0, 0};
      for (int c = 0; c < dim; ++c) xp[c] = ps.x(P, c);
      grid->query(xp, Rh, tag0 + P, near);
    }
    const int32_t nscan = grid ? static_cast<int32_t>(near.size()) : ne;
    for (int32_t i = 0; i < nscan && !bad; ++i) {
      const int32_t e = grid ? near[i] : i;
      bool mine = false;
      for (int32_t k = geo.ptr[e]; k < geo.ptr[e + 1]; ++k) mine = mine || geo.nodes[k] == P;
      if (mine) continue;
      double d[3] = {0, 0, 0};
      ps.displacement(geo.nodes[geo.ptr[e]], P, d);
      if (!box_overlaps(geo, e, d, Rh)) continue;
      ElemWeight w;
      element_weight(geo, K, e, d, h, false, false, xg, wg, w);
      // Positions relative to the node carry round-off of about eps |x|, which is
      // eps |x| / (R h) of the kernel's width: with a support far below the spacing
      // (the reduction to FEM) the edge integrals of an element the support only
      // touches at a vertex leave that much instead of 0.
      double xmag = 0.0;
      for (int c = 0; c < dim; ++c)
        xmag = std::max({xmag, std::fabs(ps.x(P, c)), std::fabs(d[c]) + geo.hi[3 * e + c] - geo.lo[3 * e + c]});
      if (w.W > 1e-12 + 100.0 * DBL_EPSILON * xmag / Rh) {
        bad = true;
        if (v.count == 0) {
          v.node = P;
          v.elem = e;
          v.w = w.W;
        }
      }
    }
    if (bad) ++v.count;
  }
  return v;
}

// The report of failed sites: the first one (with support half width Rh) and why.
std::string failed_sites_message(int32_t first_bad, int32_t status, double Rh, int64_t nfailed) {
  std::ostringstream msg;
  msg << "MPFEM: site " << first_bad;
  if (status == MFREE_FAIL_NEIGHBORS)
    msg << ": its kernel support (half width R h = " << Rh << ") reaches no element";
  else if (status == MFREE_FAIL_NONFINITE)
    msg << " has a non-finite value in its data or its shape functions";
  else
    msg << " has invalid particle data";
  msg << " (" << nfailed << (nfailed == 1 ? " site" : " sites") << " failed; their rows are zero)";
  return msg.str();
}

}  // namespace

void Approximant::set_mesh(std::shared_ptr<const Mesh> mesh) {
  if (method_ != MFREE_METHOD_MPFEM)
    throw Error(MFREE_ERR_UNSUPPORTED, "only MPFEM approximants take a mesh");
  if (mesh && &mesh->particles() != ps_)
    throw Error(MFREE_ERR_MISMATCH, "the mesh is built on another particle set than the approximant");
  mesh_ = std::move(mesh);
  setup_done_ = false;
}

void Approximant::set_mpfem(int deriv, int ngauss) {
  if (method_ != MFREE_METHOD_MPFEM)
    throw Error(MFREE_ERR_UNSUPPORTED, "MPFEM options on a non-MPFEM approximant");
  if (deriv < MFREE_MPFEM_DERIV_FULL || deriv > MFREE_MPFEM_DERIV_NODAL)
    throw Error(MFREE_ERR_ARG, "unknown MPFEM derivative form " + std::to_string(deriv));
  if (ngauss < 1 || ngauss > 20)
    throw Error(MFREE_ERR_ARG, "ngauss = " + std::to_string(ngauss) + " is outside 1..20");
  mpfem_deriv_ = deriv;
  mpfem_ngauss_ = ngauss;
  setup_done_ = false;
}

Report Approximant::compute_mpfem() {
  const int dim = ps_->dim(), nh = hessian_size(dim);
  if (!mesh_)
    throw Error(MFREE_ERR_STATE, "MPFEM needs a mesh: call mfree_approximant_set_mesh before setup");
  if (!ps_->has_support())
    throw Error(MFREE_ERR_STATE, "the particle set has no support sizes (the MPFEM kernel's half "
                                 "width is R h)");
  const bool fv = flags_ & MFREE_DERIV_VALUE, fg = flags_ & MFREE_DERIV_GRADIENT,
             fh = flags_ & MFREE_DERIV_HESSIAN;
  const int mode = mpfem_deriv_;
  if (mode == MFREE_MPFEM_DERIV_NODAL && points_)
    throw Error(MFREE_ERR_UNSUPPORTED, "the MPFEM nodal scheme (004 eqs 37-38) is defined at the "
                                       "nodes only, not at host points");
  const KernelProfile K(kernel_id_, kernel_param_);
  if (mode == MFREE_MPFEM_DERIV_FULL && fh && !K.continuous())
    throw Error(MFREE_ERR_UNSUPPORTED, "second derivatives by 004 eq 21 need a continuous kernel; "
                                       "with the Haar kernel use MFREE_MPFEM_DERIV_ASSUMED_STRAIN");
  MeshGeometry geo;
  geo.build(*mesh_);
  const int32_t ne = geo.size();
  if (dim == 3)
    for (int32_t e = 0; e < ne; ++e)
      if (!geo.box[e])
        throw Error(MFREE_ERR_UNSUPPORTED, "element " + std::to_string(e) +
                                               ": MPFEM weights on HEX8 elements need axis-aligned "
                                               "bricks");
  if (points_) check_points(npts_, dim, px_, ph_);
  nsites_ = points_ ? npts_ : ps_->num_owned();
  rowptr_.assign(1, 0);
  cols_.clear();
  val_.clear();
  grad_.clear();
  hess_.clear();
  self_.assign(nsites_, -1);
  status_.assign(nsites_, 0);
  support_.assign(nsites_, 0);
  cond_.assign(nsites_, 1.0);
  order_used_.assign(nsites_, 1);
  std::vector<double> xg, wg;
  gauss_legendre(mpfem_ngauss_, xg, wg);

  const RowOptions opt(dim, mode, fg, fh);
  std::vector<int32_t> cand, near;
  bool periodic = false;
  for (int c = 0; c < dim; ++c) periodic = periodic || ps_->periodic(c);
  std::unique_ptr<ElementGrid> grid;
  if (!periodic && ne > 0) grid = std::make_unique<ElementGrid>(geo, *ps_);
  std::vector<double> dfirst;
  SiteRow row;
  std::vector<int> order;
  const auto &pst = ps_->site_status();
  // borrowed data that turned invalid since the set's setup: such a site is not computed
  // (a NaN support would reach the element grid's index arithmetic)
  find_bad_particles();
  for (int32_t s = 0; s < nsites_; ++s) {
    const int32_t me = site_particle(s);
    auto close_row = [&]() { rowptr_.push_back(static_cast<int64_t>(cols_.size())); };
    if (me >= 0 && (pst[me] != 0 || pbad_[me] != 0)) {
      status_[s] = pst[me] != 0 ? pst[me] : pbad_[me];
      order_used_[s] = -1;
      close_row();
      continue;
    }
    const double h = site_h(s), Rh = K.radius() * h;
    cand.clear();
    dfirst.clear();
    if (opt.nodal) {
      for (int64_t k = geo.node_ptr[me]; k < geo.node_ptr[me + 1]; ++k) cand.push_back(geo.node_elems[k]);
      for (int32_t e : cand) {
        double d[3] = {0, 0, 0};
        site_displacement(s, geo.nodes[geo.ptr[e]], d);
        dfirst.insert(dfirst.end(), d, d + 3);
      }
    } else {
      if (grid) {
        double xs[3] = {0, 0, 0};
        for (int c = 0; c < dim; ++c) xs[c] = site_x(s, c);
        grid->query(xs, Rh, s, near);
      }
      const int32_t nscan = grid ? static_cast<int32_t>(near.size()) : ne;
      for (int32_t i = 0; i < nscan; ++i) {
        const int32_t e = grid ? near[i] : i;
        double d[3] = {0, 0, 0};
        site_displacement(s, geo.nodes[geo.ptr[e]], d);
        if (!box_overlaps(geo, e, d, Rh)) continue;
        cand.push_back(e);
        dfirst.insert(dfirst.end(), d, d + 3);
      }
    }
    if (!site_row(geo, K, cand, dfirst, h, opt, xg, wg, row)) {
      status_[s] = MFREE_FAIL_NEIGHBORS;
      order_used_[s] = -1;
      close_row();
      continue;
    }
    const std::vector<int32_t> &rnode = row.node;
    order.resize(rnode.size());
    for (size_t k = 0; k < order.size(); ++k) order[k] = static_cast<int>(k);
    std::sort(order.begin(), order.end(), [&](int a, int b) { return rnode[a] < rnode[b]; });
    for (int k : order) {
      if (rnode[k] == me) self_[s] = static_cast<int32_t>(cols_.size() - rowptr_.back());
      cols_.push_back(rnode[k]);
      if (fv) val_.push_back(row.v[k]);
      if (fg)
        for (int a = 0; a < dim; ++a) grad_.push_back(row.g[3 * k + a]);
      if (fh)
        for (int q = 0; q < nh; ++q) hess_.push_back(row.h[6 * k + q]);
    }
    support_[s] = static_cast<int32_t>(rnode.size());
    close_row();
  }
  const int64_t nfailed = screen_sites(0, nsites_);
  int32_t first_bad = -1;
  for (int32_t s = 0; s < nsites_ && first_bad < 0; ++s)
    if (status_[s]) first_bad = s;

  Report rep;
  if (nfailed)
    rep.fail(static_cast<mfree_status_t>(status_[first_bad]),
             failed_sites_message(first_bad, status_[first_bad], K.radius() * site_h(first_bad), nfailed));

  // Interpolation condition (004 eq 13), checked at the nodes.
  interpolating_ = true;
  if (opt.nodal) return rep;
  const Violation v = interpolation_violations(*ps_, geo, K, grid.get(), nsites_, pst.data(), pbad_.data(), xg, wg);
  if (v.count) {
    interpolating_ = false;
    std::ostringstream msg;
    msg << "MPFEM: the kernel support of node " << v.node << " (half width R h = "
        << K.radius() * ps_->h(v.node) << ") reaches element " << v.elem
        << ", which does not contain the node (unnormalised weight " << v.w << "): 004 eq 13 "
        << "is violated at " << v.count << (v.count == 1 ? " node" : " nodes")
        << ", the functions do not interpolate (004 Sect. 4.1); reduce the support";
    if (rep.ok()) rep.fail(MFREE_FAIL_SUPPORT, msg.str());
  }
  return rep;
}

}  // namespace mfree
