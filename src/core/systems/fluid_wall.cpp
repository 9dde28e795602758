// Dummy wall particles, density diffusion and consistent nodal integration for the
// Galerkin-SPH fluid (see fluid_wall.hpp). None is in paper 003; all are off by default.
//
// Why (t702, still water: docs/papers.md, paper 003, choices 3): the paper's wall
// force (eqs 122-124) acts only on approaching
// particles, so it cannot carry the bottom pressure of a still column, and the dropped
// traction term of eq 87 leaves the near-wall rows of the nodal-integration force
// unbalanced; a hydrostatic column then never settles. Dummy particles that extend the
// fluid past the walls with hydrostatically extrapolated pressure make the wall rows
// interior rows: the Galerkin force of a fluid node whose support crosses the wall picks
// up int_dummies (p grad N_i + N_i rho g) = the wall traction int_wall N_i p n.
// Nodal integration also leaves odd-even density modes that no force sees (t702 test 1);
// the density-diffusion term damps them. And it lets a pressure push disordered particles
// (integration-constraint error), which destabilises their positions: see vci_setup.
#include <algorithm>
#include <cmath>
#include <string>

#include "core/systems/fluid.hpp"
#include "core/base/kernel.hpp"
#include "core/base/parallel.hpp"

namespace mfree {

namespace {

// The nodes' kernel at distance r for the smoothing length h: W and dW/dr.
struct NodeKernel {
  Kernel k;
  double h;
  void eval(double r, double &w, double &dw) const {
    double d2w;
    k.eval(r, h, w, dw, d2w);
  }
  double value(double r) const { return k.value(r, h); }
};

}  // namespace

void FluidSystem::set_dummy_particles(int32_t n, const double *x, const double *vol, int64_t stride) {
  if (n < 0) throw Error(MFREE_ERR_ARG, "negative dummy particle count " + std::to_string(n));
  if (n > 0 && (!x || !vol)) throw Error(MFREE_ERR_NULL, "dummy positions or volumes are NULL");
  if (stride < 0) throw Error(MFREE_ERR_ARG, "negative stride");
  check_stride(n, stride, "dummy volume");
  if (static_cast<int64_t>(n_) + n > INT32_MAX) throw Error(MFREE_ERR_ARG, "too many particles with the dummies");
  // Everything is built aside and swapped in when complete: running out of memory half
  // way leaves the system as it was.
  HVec<double> xd(static_cast<size_t>(n) * dim_);
  HVec<double> vols(std::max<int32_t>(n, 1));
  for (int32_t w = 0; w < n; ++w) {
    for (int c = 0; c < dim_; ++c) {
      xd[static_cast<size_t>(w) * dim_ + c] = x[static_cast<size_t>(w) * dim_ + c];
      if (!std::isfinite(xd[static_cast<size_t>(w) * dim_ + c]))
        throw Error(MFREE_ERR_INPUT, "dummy particle " + std::to_string(w) + " has a non-finite position");
    }
    const double v = vol[w * stride];
    if (!(std::isfinite(v) && v > 0.0))
      throw Error(MFREE_ERR_INPUT, "volume of dummy particle " + std::to_string(w) + " must be finite and > 0");
    vols[w] = v;
  }
  DummyWall dummy;
  dummy.n = n;
  dummy.xd.swap(xd);
  seat_nodes(n, vols.data());
  dummy_ = std::move(dummy);
}

void FluidSystem::seat_nodes(int32_t ndummy, const double *dvol) {
  const size_t nall = static_cast<size_t>(n_) + ndummy;
  HVec<double> vols(std::max<size_t>(nall, 1), 1.0);
  if (ndummy > 0) std::copy(dvol, dvol + ndummy, vols.begin() + n_);
  // a particle set of the new size; the approximant is rebuilt on it at the next prepare
  ParticleSet nodes(dim_, static_cast<int32_t>(nall));
  if (h_ > 0.0) nodes.set_support(&h_, 0, MFREE_COPY);
  ps_ = std::move(nodes);
  vol_.swap(vols);
  lists_valid_ = false;
  cand_search_ = -1;
  xbound_ = nullptr;
  rb_ = re_ = nullptr;
  cols_ = nullptr;
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
  const NodeKernel kern{Kernel(MFREE_KERNEL_CUBIC_SPLINE, dim, 0.0), h_};
  const double fallback_rho0 = rho0_.empty() ? 1000.0 : rho0_[0];
  bool progress = true;
  // pass 2: dummies with fluid neighbours; passes 3, 4 reach 4h into the wall, as deep as
  // the MLS functions of the quadrature points that fluid nodes see look
  for (int pass = 2; progress && pass <= 4; ++pass) {
    progress = false;
    for (int32_t w = n_; w < nall; ++w) {
      if (dummy_.level[w]) continue;
      double sw = 0.0, sp = 0.0, sr0 = 0.0;
      for (int64_t e = rb(w); e < re(w); ++e) {  // the pairs closer than 2h
        const int32_t f = cols_[e];
        const int lf = dummy_.level[f];
        if (lf == 0 || lf == pass) continue;  // only values of earlier passes
        double r2 = 0.0, gr = 0.0;
        for (int c = 0; c < dim; ++c) {
          const double d = ps_.x(w, c) - ps_.x(f, c);
          r2 += d * d;
          gr += g_[c] * d;
        }
        double W, dW;
        kern.eval(std::sqrt(r2), W, dW);
        if (!(W > 0.0)) continue;
        sw += W;
        sp += W * (dummy_.p[f] + dummy_.rho[f] * gr);

        sr0 += W * dummy_.rho0[f];
      }
      if (!(sw > 0.0)) continue;
      // a wall does not pull: no suction (dummies beside the free surface)
      const double p = std::max(sp / sw, 0.0);
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
  const auto &cols = cols_;
  dummy_.share.assign(nq(), 0.0);
  for (int32_t k = 0; k < n_; ++k) {
    double s = 0.0;
    for (int64_t e = rb(k); e < re(k); ++e)
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
  const auto &cols = cols_;
  dummy_.grad_rho.assign(static_cast<size_t>(nall) * dim, 0.0);
  for (int32_t k = 0; k < nall; ++k)
    for (int64_t e = rb(k); e < re(k); ++e)
      for (int c = 0; c < dim; ++c) dummy_.grad_rho[static_cast<size_t>(k) * dim + c] += G_[e * dim + c] * r[cols[e]];
  const double *gr = dummy_.grad_rho.data();
  const NodeKernel kern{Kernel(MFREE_KERNEL_CUBIC_SPLINE, dim, 0.0), h_};
  for (int32_t i = 0; i < n_; ++i) {
    const double c0 = std::sqrt(gamma_ * kappa_ / rho0_[i]);
    double s = 0.0;
    for (int64_t e = rb(i); e < re(i); ++e) {
      const int32_t j = cols[e];
      if (j == i) continue;
      double r2 = 0.0, gx = 0.0;
      for (int c = 0; c < dim; ++c) {
        const double xji = ps_.x(j, c) - ps_.x(i, c);
        r2 += xji * xji;
        gx += (gr[static_cast<size_t>(i) * dim + c] + gr[static_cast<size_t>(j) * dim + c]) * xji;
      }
      const double rr = std::sqrt(r2);
      if (!(rr > 0.0)) continue;
      double W, dW;
      kern.eval(rr, W, dW);
      s += -dW / rr * (2.0 * (r[j] - r[i]) - gx) * vol_[j];
    }
    drho[i] += delta_ * h_ * c0 * s;
  }
}

// Variationally consistent nodal integration with the constant correction (Chen, Hillman
// & Rueter 2013) of the fluid's test-function gradients: grad N~_i(x_k) = grad N_i(x_k) +
// xi_i N_i(x_k), xi_i = -sum_k V_k grad N_i(x_k) / sum_k V_k N_i(x_k), so that
// sum_k V_k grad N~_i(x_k) = 0 (the integration constraint of a node whose support lies in
// the fluid, dummies included). Without it a uniform pressure p pushes the particles of a
// disordered lattice by p sum_k V_k grad N_i(x_k), and that geometric force has negative
// stiffness: a closed box of fluid at rest under 1000 Pa, lattice jittered by 1e-3 d,
// blows up at a rate ~24/s growing as sqrt(p) (at p = 0 nothing moves), the instability
// that ends every still column after ~0.5 s. Nodes near a free surface, where the true
// constraint has a boundary term the fluid does not know, are left out. Surface particles
// are those with a kernel volume sum K_j = sum_k V_k W(x_j - x_k) below 0.8 (a lattice
// with h = 1.5 d: 1.003 inside, 0.975 one row below the surface, 0.73 on it), blend
// b_j = min(1, max(0, (K_j - 0.8) / 0.05)); node i is corrected by the factor
// min_j [1 - (1 - b_j) min(1, W_ij / W(1.5 h))] over itself and its fluid neighbours j, so
// that no node within about 2h of the surface is (its N_i reaches across it), and the
// factor varies continuously as particles move.
void FluidSystem::vci_setup() {
  if (!vci_) return;
  const int dim = dim_;
  const NodeKernel kern{Kernel(MFREE_KERNEL_CUBIC_SPLINE, dim, 0.0), h_};
  dummy_.xi.assign(static_cast<size_t>(n_) * dim, 0.0);
  dummy_.blend.assign(n_, 0.0);
  for (int32_t i = 0; i < n_; ++i) {
    double K = 0.0;
    for (int64_t q = rb(i); q < re(i); ++q) {
      const int32_t k = cols_[q];
      double r2 = 0.0;
      for (int c = 0; c < dim; ++c) r2 += (ps_.x(i, c) - ps_.x(k, c)) * (ps_.x(i, c) - ps_.x(k, c));
      double W, dW;
      kern.eval(std::sqrt(r2), W, dW);
      K += vol_[k] * W;
    }
    dummy_.blend[i] = std::min(1.0, std::max(0.0, (K - 0.8) / 0.05));
  }
  double W15, dW;
  kern.eval(1.5 * h_, W15, dW);
  for (int32_t i = 0; i < n_; ++i) {
    double blend = 1.0, S = 0.0, b[3] = {0, 0, 0};
    for (int64_t q = rb(i); q < re(i); ++q) {
      const int32_t k = cols_[q];
      if (k < n_ && dummy_.blend[k] < 1.0) {  // dummies count as complete
        double r2 = 0.0, W;
        for (int c = 0; c < dim; ++c) r2 += (ps_.x(i, c) - ps_.x(k, c)) * (ps_.x(i, c) - ps_.x(k, c));
        kern.eval(std::sqrt(r2), W, dW);
        blend = std::min(blend, 1.0 - (1.0 - dummy_.blend[k]) * std::min(1.0, W / W15));
      }
      const double Vk = vol_[k], *nt = &NT_[static_cast<size_t>(q) * (dim + 1)];
      S += Vk * nt[0];
      for (int c = 0; c < dim; ++c) b[c] += Vk * nt[1 + c];
    }
    if (!(blend > 0.0) || !(S > 0.0)) continue;
    for (int c = 0; c < dim; ++c) dummy_.xi[static_cast<size_t>(i) * dim + c] = -blend * b[c] / S;
  }
}

// a_i += -(sum_k N_i(x_k) sigma_k V_k) xi_i / m_i, from accel's per-point pack (sigma V in
// the first dim^2 entries, the lumping mass at dim^2 + 1; see accel_dim).
void FluidSystem::vci_correct(const double *pack, int per_point, double *a) const {
  if (!vci_) return;
  const int dim = dim_;
  const bool galerkin = lump_ == MFREE_LUMP_GALERKIN;
  for (int32_t i = 0; i < n_; ++i) {
    const double *xi = &dummy_.xi[static_cast<size_t>(i) * dim];
    double f[3] = {0, 0, 0}, lm = 0.0;
    for (int64_t q = rb(i); q < re(i); ++q) {
      const double *pk = pack + static_cast<size_t>(cols_[q]) * per_point;
      const double Ni = NT_[static_cast<size_t>(q) * (dim + 1)];
      for (int aa = 0; aa < dim; ++aa) {
        double s = 0.0;
        for (int bb = 0; bb < dim; ++bb) s += pk[aa * dim + bb] * xi[bb];
        f[aa] -= Ni * s;
      }
      lm += Ni * pk[dim * dim + 1];
    }
    const double m = galerkin ? lm : mass_[i];
    if (!(m > 0.0)) continue;  // reported by accel
    for (int c = 0; c < dim; ++c) a[static_cast<size_t>(i) * dim + c] += f[c] / m;
  }
}

void FluidSystem::set_consistent_integration(int on) {
  if (on != 0 && on != 1) throw Error(MFREE_ERR_ARG, "consistent integration is 0 (off) or 1 (constant correction), not " + std::to_string(on));
  vci_ = on != 0;
}

void FluidSystem::set_velocity_smoothing(double beta) {
  if (!(std::isfinite(beta) && beta >= 0.0))
    throw Error(MFREE_ERR_ARG, "the velocity-smoothing coefficient must be finite and >= 0, not " + std::to_string(beta));
  vsmooth_ = beta;
}

// Conservative smoothing of the velocity parameters (Randles & Libersky; paper 000 Sect.
// 6.3 stabilises nodal quadrature with it, coefficient 0.1), as a rate: node i gains the
// force sum_j c_ij (v_j - v_i), c_ij = beta cbar_ij / h (m_i V_j + m_j V_i) / 2 W_ij, which
// is equal and opposite for a fluid pair (linear momentum exact; not central, so angular
// momentum is not: a rigid rotation is braked where a node's neighbourhood is one-sided,
// sum_j c_ij x_ji != 0, i.e. near a free surface). Dummies enter with v = 0 (a wall at
// rest, no-slip). Why (t702 test 3): checkerboard velocity parameters have no velocity
// gradient at the nodes, hence no density response, yet v_hat = S v moves the particles
// (t702 test 1); nothing in the paper's scheme damps them, so particle positions and
// densities of a still column drift apart (the column rises while its pressure grows,
// with a row-alternating pressure pattern) until it fails near 1 s. This term damps them
// at a rate ~ beta c / h. Gather per node: threaded and deterministic.
void FluidSystem::velocity_smoothing(const double *v, const double *lumped, int stride, double *a) const {
  if (!(vsmooth_ > 0.0)) return;
  const int dim = dim_;
  const NodeKernel kern{Kernel(MFREE_KERNEL_CUBIC_SPLINE, dim, 0.0), h_};
  const double *mass = dummy_.n ? dummy_.mass.data() : mass_.data();
  const double *rho0 = dummy_.n ? dummy_.rho0.data() : rho0_.data();
  const double gk = gamma_ * kappa_;
  parallel_blocks(n_, num_threads(n_), [&](int, int64_t b, int64_t e) {
    for (int64_t i = b; i < e; ++i) {
      double f[3] = {0, 0, 0};
      const double ci = std::sqrt(gk / rho0[i]);
      for (int64_t q = rb(i); q < re(i); ++q) {
        const int32_t j = cols_[q];
        if (j == i) continue;
        double r2 = 0.0;
        for (int c = 0; c < dim; ++c) r2 += (ps_.x(j, c) - ps_.x(i, c)) * (ps_.x(j, c) - ps_.x(i, c));
        const double W = kern.value(std::sqrt(r2));  // rows hold the pairs closer than 2h
        const double cbar = j < n_ && rho0[j] == rho0[i] ? ci : 0.5 * (ci + std::sqrt(gk / rho0[j]));
        const double cij = vsmooth_ * cbar / h_ * 0.5 * (mass[i] * vol_[j] + mass[j] * vol_[i]) * W;
        for (int c = 0; c < dim; ++c) f[c] += cij * (v[static_cast<size_t>(j) * dim + c] - v[i * dim + c]);
      }
      const double m = lumped[i * stride];
      if (!(m > 0.0)) continue;  // reported by accel
      for (int c = 0; c < dim; ++c) a[i * dim + c] += f[c] / m;
    }
  });
}

}  // namespace mfree

namespace mfree {

// The walls' force on the fluid at state y, from the accelerations accel computes. The
// shape functions are a partition of unity, so the fluid's internal forces cancel in
// sum_i m_i a_i (m_i the masses accel divides by: the lumped masses of eq 56, or the
// particle masses with physical lumping), and sum_i m_i a_i - M g, M the fluid's mass,
// is what acts on the fluid from outside: the wall particles' force of eqs 122-124 and,
// with dummy particles, their share of the Galerkin force (the wall traction) and of the
// velocity smoothing (no-slip). With consistent integration, whose correction does not
// conserve momentum, it also holds that correction's sum. Per wall particle w: its force
// on point k, f1 f2 n_w (eqs 122-124), acts as an acceleration on the nodes i of row k
// through N_i(x_k), hence on the fluid as (sum_i m_i N_i(x_k)) f1 f2 n_w; the same
// test of approach as accel, with the interpolated velocity summed here.
Report FluidSystem::wall_force(const double *y, double *total, int32_t nwall, double *per_wall) {
  if (open_) return open_wall_force(y, total, nwall, per_wall);
  const int32_t nw = walls_ ? walls_->size() : 0;
  if (per_wall && nwall != nw)
    throw Error(MFREE_ERR_ARG, "per_wall holds " + std::to_string(nwall) + " wall particles, the system has " +
                                   std::to_string(nw));
  check_ready();
  Report rep = prepare(y);
  if (!rep.ok()) return rep;
  const int dim = dim_;
  const size_t nd = static_cast<size_t>(dim) * n_;
  const double *v = y + nd, *rho = y + 2 * nd;
  std::vector<double> a(nd), m(n_);
  rep = accel(v, rho, a.data());
  if (!rep.ok()) return rep;
  const int A = 2 * dim + 2;  // acc_ per node: force, mass sum, lumped mass, wall force
  const bool galerkin = lump_ == MFREE_LUMP_GALERKIN;
  for (int32_t i = 0; i < n_; ++i) m[i] = galerkin ? acc_[static_cast<size_t>(i) * A + dim + 1] : mass_[i];
  if (total) {
    double f[3] = {0, 0, 0}, M = 0.0;
    for (int32_t i = 0; i < n_; ++i) {
      for (int c = 0; c < dim; ++c) f[c] += m[i] * a[static_cast<size_t>(i) * dim + c];
      M += mass_[i];
    }
    for (int c = 0; c < dim; ++c) total[c] = f[c] - M * g_[c];
  }
  if (per_wall) {
    std::fill(per_wall, per_wall + static_cast<size_t>(nw) * dim, 0.0);
    const double *vn = node_velocities(v);
    std::vector<std::pair<int32_t, double>> terms;
    for (int32_t k = 0; k < n_ && nw > 0; ++k) {
      wall_row(k, vn, m.data(), terms);
      for (const auto &e : terms)
        for (int c = 0; c < dim; ++c)
          per_wall[static_cast<size_t>(e.first) * dim + c] += e.second * wall_n_[static_cast<size_t>(e.first) * dim + c];
    }
  }
  return rep;
}

void FluidSystem::wall_row(int32_t k, const double *vn, const double *m,
                           std::vector<std::pair<int32_t, double>> &terms) const {
  terms.clear();
  if (wall_nbr_.rowptr[k] == wall_nbr_.rowptr[k + 1]) return;
  const int dim = dim_;
  double vh[3] = {0, 0, 0}, mk = 0.0;
  for (int64_t q = rb(k); q < re(k); ++q) {
    const int32_t i = cols_[q];
    for (int c = 0; c < dim; ++c) vh[c] += N_[q] * vn[static_cast<size_t>(i) * dim + c];
    if (i < n_) mk += N_[q] * m[i];
  }
  for (int64_t q = wall_nbr_.rowptr[k]; q < wall_nbr_.rowptr[k + 1]; ++q) {
    const int32_t w = wall_nbr_.cols[q];
    const double *nrm = &wall_n_[static_cast<size_t>(w) * dim];
    double r2 = 0.0, approach = 0.0;
    for (int c = 0; c < dim; ++c) {
      const double d = xbound_[static_cast<size_t>(k) * dim + c] - walls_->x(w, c);
      r2 += d * d;
      approach += vh[c] * nrm[c];
    }
    const double r = std::sqrt(r2);
    if (approach >= 0.0 || !(r > 0.0) || r >= r0_) continue;  // as in accel
    const double qq = r0_ / r, f2 = strength_ / r * (qq * qq * qq * qq - qq * qq);
    terms.push_back({w, mk * f2});
  }
}

}  // namespace mfree
