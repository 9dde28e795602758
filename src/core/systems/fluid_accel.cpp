// The fluid's right-hand side from the tables: the interpolated velocities and density
// rates (kinematics) and the accelerations (the force assembly, 003 eqs 56-68).
#include <algorithm>
#include <cmath>

#include "core/base/parallel.hpp"
#include "core/base/simd.hpp"
#include "core/systems/fluid.hpp"

namespace mfree {

#if MFREE_VECTOR_EXTENSIONS
using simd::V2;
using simd::V4;
#endif

void FluidSystem::kinematics(const double *v, const double *rho, double *vhat, double *drho) const {
  v = node_velocities(v);
  const int dim = dim_;
  const int64_t *rb = rb_, *re = re_;
  const int32_t *cols = cols_;
  const double *N = N_.data(), *G = G_.data();
  const bool avx2 = dim == 2 && simd::use_avx2();  // once per call: every thread runs the same copy
  parallel_blocks(n_, num_threads(n_), [&](int, int64_t b, int64_t e) {
#if MFREE_SIMD_X86
    if (avx2) {
      kinematics2_avx2(b, e, v, rho, vhat, drho);
      return;
    }
#endif
    for (int64_t k = b; k < e; ++k) {
      double vh[3] = {0, 0, 0}, div = 0.0;
      if (dim == 2) {
        // independent sums (one chain through div was the bottleneck): v0 += N a0,
        // v1 += N a1, d0 += a0 G0, d1 += a1 G1, in pairs where there (same operations)
        double v0 = 0, v1 = 0, d0 = 0, d1 = 0;
#if MFREE_VECTOR_EXTENSIONS
        V2 vv = {}, dd = {};
        for (int64_t q = rb[k]; q < re[k]; ++q) {
          V2 a, g;
          simd::load<2>(a, v + static_cast<size_t>(cols[q]) * 2);
          simd::load<2>(g, G + 2 * q);
          vv += N[q] * a;
          dd += a * g;
        }
        v0 = vv[0];
        v1 = vv[1];
        d0 = dd[0];
        d1 = dd[1];
#else
        for (int64_t q = rb[k]; q < re[k]; ++q) {
          const double *vj = v + static_cast<size_t>(cols[q]) * 2;
          const double a0 = vj[0], a1 = vj[1], nq = N[q];
          v0 += nq * a0;
          v1 += nq * a1;
          d0 += a0 * G[2 * q];
          d1 += a1 * G[2 * q + 1];
        }
#endif
        vh[0] = v0;
        vh[1] = v1;
        div = d0 + d1;
      } else {
        double d[3] = {0, 0, 0};
        for (int64_t q = rb[k]; q < re[k]; ++q) {
          const double *vj = v + static_cast<size_t>(cols[q]) * dim;
          for (int c = 0; c < dim; ++c) {
            vh[c] += N[q] * vj[c];
            d[c] += vj[c] * G[q * dim + c];
          }
        }
        div = d[0] + d[1] + d[2];
      }
      if (vhat)
        for (int c = 0; c < dim; ++c) vhat[k * dim + c] = vh[c];
      if (drho) drho[k] = -rho[k] * div;  // 003 eq 70, nodal parameters v_j
    }
  });
  if (drho) density_diffusion(rho, drho);  // optional, fluid_wall.cpp
}

FluidSystem::AccelArgs FluidSystem::accel_args(const double *v, const double *rho) {
  const int dim = dim_;
  const int32_t nall = nq();
  AccelArgs aa;
  aa.v = node_velocities(v);
  aa.rho = node_densities(rho);
  aa.rho0 = dummy_.n ? dummy_.rho0.data() : rho0_.data();
  aa.mass = dummy_.n ? dummy_.mass.data() : mass_.data();
  aa.keep_pack = vci_;  // vci_correct reads the points' stresses
  if (aa.keep_pack) pack_.resize(static_cast<size_t>(nall) * (dim * dim + 2 + dim));
  const int64_t na = static_cast<int64_t>(nall) * (2 * dim + 2);
  acc_.resize(na);
  double *acc = acc_.data();
  parallel_blocks(na, light_threads(nall), [&](int, int64_t b, int64_t e) { std::fill(acc + b, acc + e, 0.0); });
  return aa;
}

template <int D>
MFREE_ALWAYS_INLINE void FluidSystem::point_terms(int64_t k, const AccelArgs &arg, const double (&vh)[D],
                                                  const double (&L)[D][D], PointTerms<D> &pt) {
  constexpr int P = D * D + 2 + D;  // pack_ per point: sigma V (D x D), M, lumping mass, wall force
  const double *rho = arg.rho, *rho0 = arg.rho0, *mass = arg.mass;
  double tr3 = 0.0;
  for (int c = 0; c < D; ++c) tr3 += L[c][c];
  tr3 /= 3.0;
  const double p = kappa_ * (tait(rho[k], rho0[k]) - 1.0), Vk = vol_[k];
  double(&S)[D][D] = pt.S;
  for (int aa = 0; aa < D; ++aa)
    for (int bb = 0; bb < D; ++bb) {
      const double d = 0.5 * (L[aa][bb] + L[bb][aa]) - (aa == bb ? tr3 : 0.0);  // d' (003 eq 61)
      S[aa][bb] = ((aa == bb ? -p : 0.0) + 2.0 * mu_ * d) * Vk;
    }
  const double Mk = mass[k];
  // dummies carry no fluid mass; without dummies share() is 1 (no division on the row's path)
  const double Lk = k < n_ ? (dummy_.n ? mass[k] / dummy_.share[k] : mass[k]) : 0.0;
  pt.Mk = Mk;
  pt.Lk = Lk;
  double(&F)[D] = pt.F;
  for (int c = 0; c < D; ++c) F[c] = 0.0;
  bool wall = false;
  if (walls_ && k < n_) {
    // wall force (003 eqs 122-124) on approaching particles, spread through N_i(x_k);
    // "approaching" by wall_switch_v_ when integrate sets it (see fluid.hpp)
    const double *sv = wall_switch_v_ ? wall_switch_v_ + k * D : vh;
    for (int64_t q = wall_nbr_.rowptr[k]; q < wall_nbr_.rowptr[k + 1]; ++q) {
      const int32_t w = wall_nbr_.cols[q];
      const double *nw = &wall_n_[static_cast<size_t>(w) * D];
      double r2 = 0.0, approach = 0.0;
      for (int c = 0; c < D; ++c) {
        const double d = xbound_[k * D + c] - walls_->x(w, c);
        r2 += d * d;
        approach += sv[c] * nw[c];
      }
      const double r = std::sqrt(r2);
      if (approach >= 0.0 || !(r > 0.0) || r >= r0_) continue;  // f1 = 0: moving away
      const double qq = r0_ / r, f2 = strength_ / r * (qq * qq * qq * qq - qq * qq);
      for (int c = 0; c < D; ++c) F[c] += f2 * nw[c];
      wall = true;
    }
  }
  if (arg.keep_pack) {
    double *pk = &pack_[static_cast<size_t>(k) * P];
    for (int aa = 0; aa < D; ++aa)
      for (int bb = 0; bb < D; ++bb) pk[aa * D + bb] = S[aa][bb];
    pk[D * D] = Mk;
    pk[D * D + 1] = Lk;
    for (int c = 0; c < D; ++c) pk[D * D + 2 + c] = F[c];
  }
  pt.wall = wall;
}

// Point k of accel: the stress (times V_k), interpolated velocity and wall force at x_k,
// and the row's terms scattered to its nodes.
template <int D>
void FluidSystem::accel_point(int64_t k, const AccelArgs &arg) {
  constexpr int A = 2 * D + 2;  // acc_ per node: force, mass sum_k N M, lumped mass, wall force
  const double *v = arg.v;
  const int64_t q0 = rb_[k], q1 = re_[k];
  const int32_t *cols = cols_;
  const double *N = N_.data(), *G = G_.data();
  double *acc = acc_.data();
  // interpolated velocity and velocity gradient L_ab = sum_j v_j,a dN_j/dx_b at x_k
  double vh[D] = {}, L[D][D] = {};
  if constexpr (D == 2) {
    // six independent sums (the vectoriser's pairing made one dependent chain), in
    // pairs where there: (v0, v1) += N a, (l00, l10) += a g0, (l01, l11) += a g1
    double v0 = 0, v1 = 0, l00 = 0, l01 = 0, l10 = 0, l11 = 0;
#if MFREE_VECTOR_EXTENSIONS
    V2 vv = {}, c0 = {}, c1 = {};
    for (int64_t q = q0; q < q1; ++q) {
      V2 a;
      simd::load<2>(a, v + static_cast<size_t>(cols[q]) * 2);
      vv += N[q] * a;
      c0 += a * G[2 * q];
      c1 += a * G[2 * q + 1];
    }
    v0 = vv[0];
    v1 = vv[1];
    l00 = c0[0];
    l10 = c0[1];
    l01 = c1[0];
    l11 = c1[1];
#else
    for (int64_t q = q0; q < q1; ++q) {
      const double *vj = v + static_cast<size_t>(cols[q]) * 2;
      const double a0 = vj[0], a1 = vj[1], nq = N[q], g0 = G[2 * q], g1 = G[2 * q + 1];
      v0 += nq * a0;
      v1 += nq * a1;
      l00 += a0 * g0;
      l01 += a0 * g1;
      l10 += a1 * g0;
      l11 += a1 * g1;
    }
#endif
    vh[0] = v0;
    vh[1] = v1;
    L[0][0] = l00;
    L[0][1] = l01;
    L[1][0] = l10;
    L[1][1] = l11;
  } else {
    for (int64_t q = q0; q < q1; ++q) {
      const double *vj = v + static_cast<size_t>(cols[q]) * D;
      const double *gq = G + q * D;
      for (int c = 0; c < D; ++c) {
        vh[c] += N[q] * vj[c];
        for (int bb = 0; bb < D; ++bb) L[c][bb] += vj[c] * gq[bb];
      }
    }
  }
  PointTerms<D> pt;
  point_terms<D>(k, arg, vh, L, pt);
  const double(&S)[D][D] = pt.S;
  const double Mk = pt.Mk, Lk = pt.Lk, *F = pt.F;
  // the row's terms to its nodes i: -sigma_k V_k grad N_i(x_k), N_i(x_k) M_k (003 eq 56)
#if MFREE_VECTOR_EXTENSIONS
  if constexpr (D == 2) {  // the same operations in the same order, two lanes at a time
    const V2 s0 = {S[0][0], S[1][0]}, s1 = {S[0][1], S[1][1]}, ml = {Mk, Lk};
    for (int64_t q = q0; q < q1; ++q) {
      double *ai = acc + static_cast<size_t>(cols[q]) * A;
      V2 f, m;
      simd::load<2>(f, ai);
      simd::load<2>(m, ai + 2);
      const V2 sg = s0 * G[2 * q] + s1 * G[2 * q + 1];
      simd::store<2>(ai, f - sg);
      simd::store<2>(ai + 2, m + N[q] * ml);
    }
  } else
#endif
  for (int64_t q = q0; q < q1; ++q) {
    double *ai = acc + static_cast<size_t>(cols[q]) * A;
    const double *gi = G + q * D, Ni = N[q];
    for (int aa = 0; aa < D; ++aa) {
      double sg = 0.0;
      for (int bb = 0; bb < D; ++bb) sg += S[aa][bb] * gi[bb];
      ai[aa] -= sg;
    }
    ai[D] += Ni * Mk;
    ai[D + 1] += Ni * Lk;
  }
  if (pt.wall)
    for (int64_t q = q0; q < q1; ++q) {
      double *ai = acc + static_cast<size_t>(cols[q]) * A;
      for (int c = 0; c < D; ++c) ai[D + 2 + c] += N[q] * F[c];
    }
}

template <int D>
Report FluidSystem::accel_end(const AccelArgs &aa, double *a) {
  Report rep;
  constexpr int P = D * D + 2 + D;
  constexpr int A = 2 * D + 2;
  const double *acc = acc_.data();
  const bool galerkin = lump_ == MFREE_LUMP_GALERKIN;
  int32_t bad = n_;  // the first node without a positive mass
  int32_t first_bad[64];  // parallel_blocks runs at most 64 threads
  std::fill(first_bad, first_bad + 64, n_);
  parallel_blocks(n_, num_threads(n_), [&](int t, int64_t b, int64_t e) {
    for (int64_t i = b; i < e; ++i) {
      const double *ai = acc + static_cast<size_t>(i) * A;
      const double m = galerkin ? ai[D + 1] : mass_[i];
      if (!(m > 0.0)) {
        if (first_bad[t] == n_) first_bad[t] = static_cast<int32_t>(i);
        for (int c = 0; c < D; ++c) a[i * D + c] = 0.0;
        continue;
      }
      // the boundary force acts as an acceleration (003 Sect. 6.1 step 7)
#if MFREE_VECTOR_EXTENSIONS
      if constexpr (D == 2) {  // both components in one division (the same operations)
        V2 f, g, w;
        simd::load<2>(f, ai);
        simd::load<2>(g, g_);
        simd::load<2>(w, ai + D + 2);
        simd::store<2>(a + i * D, (f + ai[D] * g) / m + w);
        continue;
      }
#endif
      for (int c = 0; c < D; ++c) a[i * D + c] = (ai[c] + ai[D] * g_[c]) / m + ai[D + 2 + c];
    }
  });
  vci_correct(pack_.data(), P, a);  // optional, fluid_wall.cpp
  velocity_smoothing(aa.v, galerkin ? acc + D + 1 : mass_.data(), galerkin ? A : 1, a);  // optional, fluid_wall.cpp
  for (int32_t fbad : first_bad) bad = std::min(bad, fbad);
  if (bad < n_) {
    const double m = galerkin ? acc[static_cast<size_t>(bad) * A + D + 1] : mass_[bad];
    rep.fail(MFREE_FAIL_SINGULAR, "particle " + std::to_string(bad) + " has a non-positive lumped mass " +
                                      std::to_string(m));
  }
  return rep;
}

#if MFREE_SIMD_X86
MFREE_AVX2_BEGIN
namespace {

// p[0..3] += u.
MFREE_ALWAYS_INLINE void add4(double *p, const V4 &u) {
  V4 r;
  simd::load<4>(r, p);
  simd::store<4>(p, r + u);
}

// Table entries q .. q + 3 of a 2D row in registers, lanes in the order (q, q + 2, q + 1,
// q + 3) that the in-lane unpacks of interleaved pairs give: velocities (vx, vy) of the
// columns, values N and gradients (gx, gy).
struct Entries4 {
  V4 vx, vy, n, gx, gy;
};
MFREE_ALWAYS_INLINE void entries4(const double *v, const int32_t *cols, const double *N, const double *G, int64_t q,
                                  Entries4 &e) {
  const int32_t *c = cols + q;
  V2 v0, v1, v2, v3;
  simd::load<2>(v0, v + 2 * static_cast<size_t>(c[0]));
  simd::load<2>(v1, v + 2 * static_cast<size_t>(c[1]));
  simd::load<2>(v2, v + 2 * static_cast<size_t>(c[2]));
  simd::load<2>(v3, v + 2 * static_cast<size_t>(c[3]));
  V4 lo, hi, n, g01, g23;
  simd::concat(lo, v0, v1);  // v0 | v1
  simd::concat(hi, v2, v3);  // v2 | v3
  e.vx = MFREE_SHUF(lo, hi, 0, 4, 2, 6);  // (v0x, v2x, v1x, v3x)
  e.vy = MFREE_SHUF(lo, hi, 1, 5, 3, 7);
  simd::load<4>(n, N + q);
  e.n = MFREE_SHUF(n, n, 0, 2, 1, 3);  // (N0, N2, N1, N3)
  simd::load<4>(g01, G + 2 * q);
  simd::load<4>(g23, G + 2 * q + 4);
  e.gx = MFREE_SHUF(g01, g23, 0, 4, 2, 6);  // (g0x, g2x, g1x, g3x)
  e.gy = MFREE_SHUF(g01, g23, 1, 5, 3, 7);
}

}  // namespace

// accel_point<2> for rows [k0, k1): the gather of v_j and grad N_j four entries at a time
// (six sums in registers), the point's terms, and the scatter of four entries at a time:
// (fx, fy, N M_k, N L_k) in structure-of-arrays form, transposed by unpacks and lane
// permutes into one 4-double update per node (acc_ holds them contiguously).
void FluidSystem::accel_rows2_avx2(int64_t k0, int64_t k1, const AccelArgs &arg) {
  constexpr int A = 6;
  const double *v = arg.v;
  const int32_t *cols = cols_;
  const double *N = N_.data(), *G = G_.data();
  double *acc = acc_.data();
  const V4 zero = {};
  for (int64_t k = k0; k < k1; ++k) {
    const int64_t q0 = rb_[k], q1 = re_[k];
    V4 sv0 = {}, sv1 = {}, s00 = {}, s01 = {}, s10 = {}, s11 = {};
    int64_t q = q0;
    for (; q + 4 <= q1; q += 4) {
      Entries4 e;
      entries4(v, cols, N, G, q, e);
      sv0 += e.n * e.vx;
      sv1 += e.n * e.vy;
      s00 += e.vx * e.gx;
      s01 += e.vx * e.gy;
      s10 += e.vy * e.gx;
      s11 += e.vy * e.gy;
    }
    double t[8];
    simd::hsum4(sv0, sv1, s00, s01, t);
    simd::hsum4(s10, s11, zero, zero, t + 4);
    double vh[2] = {t[0], t[1]}, L[2][2] = {{t[2], t[3]}, {t[4], t[5]}};
    for (; q < q1; ++q) {
      const double *vj = v + static_cast<size_t>(cols[q]) * 2;
      const double a0 = vj[0], a1 = vj[1], nq = N[q], g0 = G[2 * q], g1 = G[2 * q + 1];
      vh[0] += nq * a0;
      vh[1] += nq * a1;
      L[0][0] += a0 * g0;
      L[0][1] += a0 * g1;
      L[1][0] += a1 * g0;
      L[1][1] += a1 * g1;
    }
    PointTerms<2> pt;
    point_terms<2>(k, arg, vh, L, pt);
    // the row's terms to its nodes i: -sigma_k V_k grad N_i(x_k), N_i(x_k) M_k (003 eq 56)
    const double n00 = -pt.S[0][0], n01 = -pt.S[0][1], n10 = -pt.S[1][0], n11 = -pt.S[1][1];
    const double mk = pt.Mk, lk = pt.Lk;
    q = q0;
    for (; q + 4 <= q1; q += 4) {
      const int32_t *c = cols + q;
      V4 nq, g01, g23;
      simd::load<4>(nq, N + q);
      nq = MFREE_SHUF(nq, nq, 0, 2, 1, 3);  // (N0, N2, N1, N3)
      simd::load<4>(g01, G + 2 * q);
      simd::load<4>(g23, G + 2 * q + 4);
      const V4 gx = MFREE_SHUF(g01, g23, 0, 4, 2, 6), gy = MFREE_SHUF(g01, g23, 1, 5, 3, 7);
      const V4 fx = n00 * gx + n01 * gy, fy = n10 * gx + n11 * gy;
      const V4 cm = nq * mk, cl = nq * lk;
      // entries 0 | 1 and 2 | 3 of (fx, fy) and of (cm, cl), then one 4-double row each
      const V4 t0 = MFREE_SHUF(fx, fy, 0, 4, 2, 6), t1 = MFREE_SHUF(fx, fy, 1, 5, 3, 7);
      const V4 t2 = MFREE_SHUF(cm, cl, 0, 4, 2, 6), t3 = MFREE_SHUF(cm, cl, 1, 5, 3, 7);
      double *a0 = acc + static_cast<size_t>(c[0]) * A, *a1 = acc + static_cast<size_t>(c[1]) * A;
      double *a2 = acc + static_cast<size_t>(c[2]) * A, *a3 = acc + static_cast<size_t>(c[3]) * A;
      // one node after the other (a node may appear twice in a group: each update reads
      // the one before)
      add4(a0, MFREE_SHUF(t0, t2, 0, 1, 4, 5));
      add4(a1, MFREE_SHUF(t0, t2, 2, 3, 6, 7));
      add4(a2, MFREE_SHUF(t1, t3, 0, 1, 4, 5));
      add4(a3, MFREE_SHUF(t1, t3, 2, 3, 6, 7));
    }
    for (; q < q1; ++q) {
      double *ai = acc + static_cast<size_t>(cols[q]) * A;
      const double gx = G[2 * q], gy = G[2 * q + 1];
      ai[0] += -pt.S[0][0] * gx + -pt.S[0][1] * gy;
      ai[1] += -pt.S[1][0] * gx + -pt.S[1][1] * gy;
      ai[2] += N[q] * pt.Mk;
      ai[3] += N[q] * pt.Lk;
    }
    if (pt.wall)
      for (q = q0; q < q1; ++q) {
        double *ai = acc + static_cast<size_t>(cols[q]) * A;
        for (int c = 0; c < 2; ++c) ai[4 + c] += N[q] * pt.F[c];
      }
  }
}

// The 2D kinematics of nodes [k0, k1) four entries at a time: vhat_k = sum N_j v_j and
// div_k = sum v_j . grad N_j in four sums of registers.
void FluidSystem::kinematics2_avx2(int64_t k0, int64_t k1, const double *v, const double *rho, double *vhat,
                                   double *drho) const {
  const int32_t *cols = cols_;
  const double *N = N_.data(), *G = G_.data();
  for (int64_t k = k0; k < k1; ++k) {
    const int64_t q0 = rb_[k], q1 = re_[k];
    V4 sv0 = {}, sv1 = {}, d0 = {}, d1 = {};
    int64_t q = q0;
    for (; q + 4 <= q1; q += 4) {
      Entries4 e;
      entries4(v, cols, N, G, q, e);
      sv0 += e.n * e.vx;
      sv1 += e.n * e.vy;
      d0 += e.vx * e.gx;
      d1 += e.vy * e.gy;
    }
    double t[4];
    simd::hsum4(sv0, sv1, d0, d1, t);
    for (; q < q1; ++q) {
      const double *vj = v + static_cast<size_t>(cols[q]) * 2;
      t[0] += N[q] * vj[0];
      t[1] += N[q] * vj[1];
      t[2] += vj[0] * G[2 * q];
      t[3] += vj[1] * G[2 * q + 1];
    }
    if (vhat) {
      vhat[2 * k] = t[0];
      vhat[2 * k + 1] = t[1];
    }
    if (drho) drho[k] = -rho[k] * (t[2] + t[3]);  // 003 eq 70, nodal parameters v_j
  }
}
MFREE_AVX2_END
#endif

// 003 eqs 56, 61, 67-68 with nodal quadrature: the force on node i is
//   f_i = sum_k [-sigma_k grad N_i(x_k) V_k + N_i(x_k) M_k g],  m_i = sum_k N_i(x_k) M_k,
// over the quadrature points k whose row holds i. One pass over the rows computes per
// point k the stress (times V_k), the interpolated velocity and the wall force and
// scatters the row's terms to the nodes i of the row (acc_); the chunks of rows of one
// colour touch disjoint nodes and run in parallel, the colours one after another, so that
// every node sums its terms in the same order whatever the number of threads.
Report FluidSystem::accel(const double *v, const double *rho, double *a) {
  const AccelArgs aa = accel_args(v, rho);
  const int32_t nall = nq();
  const int nt = scatter_threads_ ? num_threads(nall) : 1;
  const bool avx2 = dim_ == 2 && simd::use_avx2();  // once per call: every thread runs the same copy
  for (size_t col = 0; col + 1 < color_ptr_.size(); ++col) {
    const int32_t *chunks = chunk_order_.data() + color_ptr_[col];
    parallel_blocks(color_ptr_[col + 1] - color_ptr_[col], nt, [&](int, int64_t b, int64_t e) {
      for (int64_t c = b; c < e; ++c) {
        const int64_t k0 = static_cast<int64_t>(chunks[c]) * kChunk, k1 = std::min<int64_t>(nall, k0 + kChunk);
#if MFREE_SIMD_X86
        if (avx2) {
          accel_rows2_avx2(k0, k1, aa);
          continue;
        }
#endif
        for (int64_t k = k0; k < k1; ++k) {
          if (dim_ == 2) accel_point<2>(k, aa);
          else accel_point<3>(k, aa);
        }
      }
    });
  }
  return dim_ == 2 ? accel_end<2>(aa, a) : accel_end<3>(aa, a);
}

}  // namespace mfree
