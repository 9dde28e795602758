// Dummy wall particles and density diffusion for the Galerkin-SPH fluid (see
// fluid_wall.hpp). Neither is in paper 003; both are off by default.
//
// Why (t702, 003 B5): the paper's wall force (eqs 122-124) acts only on approaching
// particles, so it cannot carry the bottom pressure of a still column, and the dropped
// traction term of eq 87 leaves the near-wall rows of the nodal-integration force
// unbalanced; a hydrostatic column then never settles. Dummy particles that extend the
// fluid past the walls with hydrostatically extrapolated pressure make the wall rows
// interior rows: the Galerkin force of a fluid node whose support crosses the wall picks
// up int_dummies (p grad N_i + N_i rho g) = the wall traction int_wall N_i p n.
// Nodal integration also leaves odd-even density modes that no force sees (t702 test 1);
// the density-diffusion term damps them.
#include <algorithm>
#include <cmath>
#include <string>

#include "fluid.hpp"
#include "kernel.hpp"

namespace mfree {

void FluidSystem::set_dummy_particles(int32_t n, const double *x, const double *vol, int64_t stride) {
  if (n < 0) throw Error(MFREE_ERR_ARG, "negative dummy particle count " + std::to_string(n));
  if (n > 0 && (!x || !vol)) throw Error(MFREE_ERR_NULL, "dummy positions or volumes are NULL");
  if (stride < 0) throw Error(MFREE_ERR_ARG, "negative stride");
  if (static_cast<int64_t>(n_) + n > INT32_MAX) throw Error(MFREE_ERR_ARG, "too many particles with the dummies");
  std::vector<double> xd(static_cast<size_t>(n) * dim_), vd(n);
  for (int32_t w = 0; w < n; ++w) {
    for (int c = 0; c < dim_; ++c) {
      xd[static_cast<size_t>(w) * dim_ + c] = x[static_cast<size_t>(w) * dim_ + c];
      if (!std::isfinite(xd[static_cast<size_t>(w) * dim_ + c]))
        throw Error(MFREE_ERR_INPUT, "dummy particle " + std::to_string(w) + " has a non-finite position");
    }
    vd[w] = vol[w * stride];
    if (!(std::isfinite(vd[w]) && vd[w] > 0.0))
      throw Error(MFREE_ERR_INPUT, "volume of dummy particle " + std::to_string(w) + " must be finite and > 0");
  }
  // a particle set of the new size; the approximant is rebuilt on it at the next prepare
  lists_valid_ = false;
  ps_ = ParticleSet(dim_, n_ + n);
  if (h_ > 0.0) ps_.set_support(&h_, 0, MFREE_COPY);
  vol_.assign(std::max<size_t>(static_cast<size_t>(n_) + n, 1), 1.0);
  std::copy(vd.begin(), vd.end(), vol_.begin() + n_);
  dummy_ = DummyWall();
  dummy_.n = n;
  dummy_.xd.swap(xd);
}

void FluidSystem::set_density_diffusion(double delta) {
  if (!(std::isfinite(delta) && delta >= 0.0))
    throw Error(MFREE_ERR_ARG, "the density-diffusion coefficient must be finite and >= 0, not " + std::to_string(delta));
  delta_ = delta;
}

const double *FluidSystem::node_positions(const double *y) {
  if (!dummy_.n) return y;
  const size_t nd = static_cast<size_t>(dim_) * n_;
  dummy_.x.resize(static_cast<size_t>(dim_) * nq());
  std::copy(y, y + nd, dummy_.x.begin());
  std::copy(dummy_.xd.begin(), dummy_.xd.end(), dummy_.x.begin() + nd);
  return dummy_.x.data();
}

const double *FluidSystem::node_velocities(const double *v) const {
  if (!dummy_.n || v == dummy_.v.data()) return v;
  const size_t nd = static_cast<size_t>(dim_) * n_;
  dummy_.v.assign(static_cast<size_t>(dim_) * nq(), 0.0);
  std::copy(v, v + nd, dummy_.v.begin());
  return dummy_.v.data();
}

// Adami, Hu & Adams (2012) eq 27 for walls at rest: p_w = sum_f W_wf (p_f + rho_f g.r_wf)
// / sum_f W_wf with r_wf = x_w - x_f, over the fluid neighbours within the support. The
// deeper dummies, which no fluid particle reaches but which are nodes of the MLS
// functions at the shallower ones, are filled the same way from the dummies already
// filled, layer by layer, so that the extended density field stays smooth (the density
// diffusion differentiates it).
const double *FluidSystem::node_densities(const double *rho) const {
  if (!dummy_.n || rho == dummy_.rho.data()) return rho;
  const int dim = dim_;
  const int32_t nall = nq();
  dummy_.rho.resize(nall);
  dummy_.rho0.resize(nall);
  dummy_.mass.resize(nall);
  dummy_.p.assign(nall, 0.0);
  dummy_.level.assign(nall, 0);  // 0 unknown, >0 filled in pass level (fluid: 1)
  std::copy(rho, rho + n_, dummy_.rho.begin());
  std::copy(rho0_.begin(), rho0_.end(), dummy_.rho0.begin());
  std::copy(mass_.begin(), mass_.end(), dummy_.mass.begin());
  for (int32_t f = 0; f < n_; ++f) {
    dummy_.p[f] = kappa_ * (std::pow(rho[f] / rho0_[f], gamma_) - 1.0);
    dummy_.level[f] = 1;
  }
  const Kernel kern(MFREE_KERNEL_CUBIC_SPLINE, dim, 0.0);
  const Csr &nb = ps_.neighbors();
  const double fallback_rho0 = rho0_.empty() ? 1000.0 : rho0_[0];
  bool progress = true;
  // pass 2: dummies with fluid neighbours; passes 3, 4 reach 4h into the wall, as deep as
  // the MLS functions of the quadrature points that fluid nodes see look
  for (int pass = 2; progress && pass <= 4; ++pass) {
    progress = false;
    for (int32_t w = n_; w < nall; ++w) {
      if (dummy_.level[w]) continue;
      double sw = 0.0, sp = 0.0, sr0 = 0.0;
      for (int64_t e = nb.rowptr[w]; e < nb.rowptr[w + 1]; ++e) {
        const int32_t f = nb.cols[e];
        const int lf = dummy_.level[f];
        if (lf == 0 || lf == pass) continue;  // only values of earlier passes
        double r2 = 0.0, gr = 0.0;
        for (int c = 0; c < dim; ++c) {
          const double d = ps_.x(w, c) - ps_.x(f, c);
          r2 += d * d;
          gr += g_[c] * d;
        }
        double W, dW, d2W;
        kern.eval(std::sqrt(r2), h_, W, dW, d2W);
        if (!(W > 0.0)) continue;
        sw += W;
        sp += W * (dummy_.p[f] + dummy_.rho[f] * gr);
        sr0 += W * dummy_.rho0[f];
      }
      if (!(sw > 0.0)) continue;
      // a wall does not pull: no suction (dummies beside the free surface)
      double p = std::max(sp / sw, 0.0);
      const double r0 = sr0 / sw;
      const double rw = r0 * std::pow(1.0 + p / kappa_, 1.0 / gamma_);  // inverse Tait
      dummy_.p[w] = p;
      dummy_.rho[w] = rw;
      dummy_.rho0[w] = r0;
      dummy_.level[w] = pass;
      progress = true;
    }
  }
  for (int32_t w = n_; w < nall; ++w) {
    if (!dummy_.level[w]) {  // out of reach of the fluid: at rest density, no pressure
      dummy_.rho[w] = fallback_rho0;
      dummy_.rho0[w] = fallback_rho0;
    }
    dummy_.mass[w] = dummy_.rho[w] * vol_[w];
  }
  return dummy_.rho.data();
}

void FluidSystem::fluid_share() {
  if (!dummy_.n) return;
  const auto &rp = rp_;
  const auto &cols = cols_;
  dummy_.share.assign(nq(), 0.0);
  for (int32_t k = 0; k < n_; ++k) {
    double s = 0.0;
    for (int64_t e = rp[k]; e < rp[k + 1]; ++e)
      if (cols[e] < n_) s += N_[e];
    // a fluid particle surrounded by dummies only (cannot happen for walls 2h thick and
    // a particle inside the fluid) keeps its mass on its own row's fluid part
    dummy_.share[k] = s > 1e-3 ? s : 1.0;
  }
}

// delta-SPH density diffusion (Molteni & Colagrossi 2009; Antuono et al. 2010):
// D_i = delta h c0_i sum_j psi_ji . grad_i W_ij V_j, psi_ji = 2 (rho_j - rho_i) x_ji / r^2
// - (<grad rho>_i + <grad rho>_j), with the MLS density gradients of the model (exact for
// linear fields, so a hydrostatic column is left alone, free surface included). With
// grad_i W_ij = W'(r) x_ij / r this is delta h c0_i sum_j (-W'/r) [2 (rho_j - rho_i) -
// (<grad rho>_i + <grad rho>_j) . x_ji] V_j. Dummies take part with their extrapolated
// densities.
void FluidSystem::density_diffusion(const double *rho, double *drho) const {
  if (!(delta_ > 0.0)) return;
  const int dim = dim_;
  const int32_t nall = nq();
  const double *r = node_densities(rho);
  const auto &rp = rp_;
  const auto &cols = cols_;
  dummy_.grad_rho.assign(static_cast<size_t>(nall) * dim, 0.0);
  for (int32_t k = 0; k < nall; ++k)
    for (int64_t e = rp[k]; e < rp[k + 1]; ++e)
      for (int c = 0; c < dim; ++c) dummy_.grad_rho[static_cast<size_t>(k) * dim + c] += G_[e * dim + c] * r[cols[e]];
  const double *gr = dummy_.grad_rho.data();
  const Kernel kern(MFREE_KERNEL_CUBIC_SPLINE, dim, 0.0);
  const Csr &nb = ps_.neighbors();
  for (int32_t i = 0; i < n_; ++i) {
    const double c0 = std::sqrt(gamma_ * kappa_ / rho0_[i]);
    double s = 0.0;
    for (int64_t e = nb.rowptr[i]; e < nb.rowptr[i + 1]; ++e) {
      const int32_t j = nb.cols[e];
      if (j == i) continue;
      double r2 = 0.0, gx = 0.0;
      for (int c = 0; c < dim; ++c) {
        const double xji = ps_.x(j, c) - ps_.x(i, c);
        r2 += xji * xji;
        gx += (gr[static_cast<size_t>(i) * dim + c] + gr[static_cast<size_t>(j) * dim + c]) * xji;
      }
      const double rr = std::sqrt(r2);
      if (!(rr > 0.0)) continue;
      double W, dW, d2W;
      kern.eval(rr, h_, W, dW, d2W);
      s += -dW / rr * (2.0 * (r[j] - r[i]) - gx) * vol_[j];
    }
    drho[i] += delta_ * h_ * c0 * s;
  }
}

}  // namespace mfree
