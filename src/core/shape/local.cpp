// Per-site shape functions for every method of papers 000 and 001.
//
// Notation: d_j = x_j - x (neighbour minus site), s_j = d_j / hs (scaled), weights
// w_j = W(|d_j|, h_j) with gradient gw_j = grad_x w_j = -W'(r) d_j / r and Hessian
// hw_j = grad_x grad_x w_j. Volumes V_j enter where the method says so (SPH, RKPM, SSPH,
// MSPH, Randles-Libersky, Johnson-Beissel); MLS, Shepard and the Krongauz-Belytschko
// corrections use plain weights as in paper 000.
#include "core/shape/local.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "core/base/small_dense.hpp"

namespace mfree {

using Mat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxBasis, kMaxBasis>;
using Vec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxBasis, 1>;

namespace {

struct Site {
  const LocalConfig &cfg;
  const LocalInput &in;
  LocalWork &w;
  LocalOutput &out;
  int dim, nh, n;
  const double *d(int j) const { return in.d + 3 * j; }
  double *gw(int j) { return &w.gw[3 * j]; }
  double *hw(int j) { return &w.hw[6 * j]; }
};

void zero_rows(Site &s) {
  if (s.cfg.want_value && s.out.phi) std::fill(s.out.phi, s.out.phi + s.n, 0.0);
  if (s.cfg.want_grad && s.out.grad) std::fill(s.out.grad, s.out.grad + s.n * s.dim, 0.0);
  if (s.cfg.want_hess && s.out.hess) std::fill(s.out.hess, s.out.hess + s.n * s.nh, 0.0);
}

// Kernel weights and their x-derivatives; returns the number of non-zero weights.
int weights(Site &s, bool need_grad, bool need_hess) {
  const Kernel &k = *s.cfg.kernel;
  int support = 0;
  for (int j = 0; j < s.n; ++j) {
    const double *dj = s.d(j);
    double r, wv, dw, d2w;
    double *g = s.gw(j);
    double *H = s.hw(j);
    kernel_at(k, s.dim, dj, s.in.h[j], r, wv, dw, d2w, g);
    s.w.r[j] = r;
    s.w.w[j] = wv;
    if (wv != 0.0) ++support;
    if (!need_grad && !need_hess) g[0] = g[1] = g[2] = 0.0;
    if (!need_hess) {
      for (int e = 0; e < 6; ++e) H[e] = 0.0;
    } else {
      double r2 = 0.0;
      for (int c = 0; c < s.dim; ++c) r2 += dj[c] * dj[c];
      // W'' n n + W'/r (I - n n), n = d / r; at r = 0 the limit W''(0) I
      for (int a = 0; a < s.dim; ++a)
        for (int b = a; b < s.dim; ++b) {
          double v;
          if (r > 0.0) {
            const double nn = dj[a] * dj[b] / r2;
            v = d2w * nn + dw / r * ((a == b ? 1.0 : 0.0) - nn);
          } else {
            v = a == b ? d2w : 0.0;
          }
          H[hessian_index(s.dim, a, b)] = v;
        }
    }
  }
  return support;
}

// Shepard functions phi = w / S and derivatives into work.q (value), work.sh (grad
// then Hessian); optionally written to the output rows.
int shepard(Site &s, bool write) {
  const int dim = s.dim, nh = s.nh, n = s.n;
  double S = 0.0, gS[3] = {0, 0, 0}, hS[6] = {0, 0, 0, 0, 0, 0};
  for (int j = 0; j < n; ++j) {
    S += s.w.w[j];
    for (int c = 0; c < dim; ++c) gS[c] += s.gw(j)[c];
    for (int e = 0; e < nh; ++e) hS[e] += s.hw(j)[e];
  }
  if (!(S > 0.0)) return MFREE_FAIL_NEIGHBORS;
  const double iS = 1.0 / S;
  if (s.out.coef) {  // the sum and its gradient, after what precedes them in the record
    double *c = s.out.coef + (s.cfg.method == MFREE_METHOD_KB_METHOD1 ? dim * dim : 0);
    c[0] = S;
    for (int a = 0; a < dim; ++a) c[1 + a] = gS[a];
  }
  double *phi = s.w.q.data();
  double *gphi = s.w.sh.data();
  double *hphi = s.w.sh.data() + 3 * n;
  for (int j = 0; j < n; ++j) {
    const double wj = s.w.w[j];
    phi[j] = wj * iS;
    const double *g = s.gw(j);
    for (int c = 0; c < dim; ++c) gphi[3 * j + c] = g[c] * iS - wj * gS[c] * iS * iS;
    if (!s.cfg.want_hess) continue;  // only the Hessian row reads hphi
    const double *H = s.hw(j);
    for (int a = 0; a < dim; ++a)
      for (int b = a; b < dim; ++b) {
        const int e = hessian_index(dim, a, b);
        hphi[6 * j + e] = H[e] * iS - (g[a] * gS[b] + g[b] * gS[a]) * iS * iS -
                          wj * hS[e] * iS * iS + 2.0 * wj * gS[a] * gS[b] * iS * iS * iS;
      }
  }
  if (write) {
    for (int j = 0; j < n; ++j) {
      if (s.cfg.want_value) s.out.phi[j] = phi[j];
      if (s.cfg.want_grad)
        for (int c = 0; c < dim; ++c) s.out.grad[j * dim + c] = gphi[3 * j + c];
      if (s.cfg.want_hess)
        for (int e = 0; e < nh; ++e) s.out.hess[j * nh + e] = hphi[6 * j + e];
    }
  }
  return 0;
}

// The pivots of a factorisation, for the condition rule (base/small_dense.hpp).
template <class M>
Vec pivots(const Eigen::LDLT<M> &f) { return f.vectorD(); }
template <class M>
Vec pivots(const Eigen::PartialPivLU<M> &f) { return f.matrixLU().diagonal(); }

// The condition rule of base/small_dense.hpp with ||A^-1||_1 exact: the systems are small
// (L <= 20), so the inverse costs a few solves, and the fast path, which has the inverse
// anyway, gets the same number from one column sum (Eigen's rcond() estimate, a lower
// bound of ||A^-1||_1, would make the two paths disagree).
//
// The reference path factorises with Eigen (LDLT, PartialPivLU), not with the fixed-size
// factorisations of small_dense.hpp that the fast path uses: it is the oracle the fast
// path is checked against (statuses, condition numbers and tables to round-off), and an
// independent factorisation keeps a fault in the hand-written one visible there. What the
// two paths must share, the threshold and the rule, is defined once, in small_dense.hpp.
template <class MatA, class Solver>
bool check_rcond(Site &s, const MatA &A, const Solver &solver) {
  const Eigen::Index L = A.rows();
  const double anorm = A.cwiseAbs().colwise().sum().maxCoeff();
  double xnorm = 0.0;
  if (anorm != 0.0 && L > 1) {
    const MatA X = solver.solve(MatA::Identity(L, L));
    xnorm = X.cwiseAbs().colwise().sum().maxCoeff();
  }
  const Vec piv = pivots(solver);
  return dense::condition_ok(dense::rcond_from_norms(anorm, xnorm, static_cast<int>(L)),
                             dense::pivot_ratio(piv.data(), static_cast<int>(L)), s.out.cond);
}

// Moving least squares (MLS, weights w) and RKPM (weights w V), order k, with true
// derivatives: Phi_j = omega_j gamma . p_j, M gamma = p(0), differentiated with the
// shift point frozen at the site (paper 000 Sect. 4.3; docs/papers.md, paper 000, choices 1).
//
// L (basis size) is a template parameter, so that the moment matrices are fixed-size
// and live in registers and on the stack; M and its first derivatives M_,i (symmetric,
// like M) are accumulated in one pass over the neighbours from the lower triangle of
// p p^T, computed once per neighbour.
// The complete basis of order <= 2 in the order of Basis (1; s_i; s_i^2; s1 s2, s2 s3,
// s3 s1) written out for a compile-time dimension; higher orders use Basis::eval.
template <int D, int L>
inline void eval_basis(const Basis &B, const double *sj, double *p) {
  if (L == 1) {
    p[0] = 1.0;
  } else if (L == D + 1) {
    p[0] = 1.0;
    for (int c = 0; c < D; ++c) p[1 + c] = sj[c];
  } else if (L == (D + 1) * (D + 2) / 2) {
    p[0] = 1.0;
    for (int c = 0; c < D; ++c) {
      p[1 + c] = sj[c];
      p[1 + D + c] = sj[c] * sj[c];
    }
    if (D >= 2) p[1 + 2 * D] = sj[0] * sj[1];
    if (D >= 3) {
      p[2 + 2 * D] = sj[1] * sj[2];
      p[3 + 2 * D] = sj[2] * sj[0];
    }
  } else {
    B.eval(sj, p);
  }
}

template <int D, int L>
int mls_fixed(Site &s, const Basis &B, bool rkpm) {
  using MatL = Eigen::Matrix<double, L, L>;
  using VecL = Eigen::Matrix<double, L, 1>;
  constexpr int dim = D;
  const int n = s.n;
  const double ih = 1.0 / s.in.hs;
  const bool deriv = s.cfg.want_grad || s.cfg.want_hess;
  double *P = s.w.p.data();
  auto omega = [&](int j) { return rkpm ? s.w.w[j] * s.in.vol[j] : s.w.w[j]; };
  auto domega = [&](int j, int c) { return rkpm ? s.gw(j)[c] * s.in.vol[j] : s.gw(j)[c]; };
  auto ddomega = [&](int j, int e) { return rkpm ? s.hw(j)[e] * s.in.vol[j] : s.hw(j)[e]; };

  // lower triangles of M and M_,i in local accumulators (no aliasing with the
  // neighbour arrays, so that they can stay in registers for small L)
  constexpr int T = L * (L + 1) / 2;
  double m0[T] = {0}, mi[D][T] = {{0}};
  for (int j = 0; j < n; ++j) {
    double sj[3] = {0, 0, 0};
    for (int c = 0; c < dim; ++c) sj[c] = s.d(j)[c] * ih;
    double pl[L];
    eval_basis<D, L>(B, sj, pl);
    std::copy(pl, pl + L, P + j * L);
    const double o = omega(j);
    if (deriv) {
      double od[D];
      for (int c = 0; c < D; ++c) od[c] = domega(j, c);
      for (int a = 0, t = 0; a < L; ++a)
        for (int b = 0; b <= a; ++b, ++t) {
          const double pp = pl[a] * pl[b];
          m0[t] += o * pp;
          for (int c = 0; c < D; ++c) mi[c][t] += od[c] * pp;
        }
    } else if (o != 0.0) {
      for (int a = 0, t = 0; a < L; ++a)
        for (int b = 0; b <= a; ++b, ++t) m0[t] += o * (pl[a] * pl[b]);
    }
  }
  MatL M, Mi[D];
  for (int a = 0, t = 0; a < L; ++a)
    for (int b = 0; b <= a; ++b, ++t) {
      M(a, b) = M(b, a) = m0[t];
      for (int c = 0; c < D; ++c) Mi[c](a, b) = Mi[c](b, a) = mi[c][t];
    }
  Eigen::LDLT<MatL> ldlt(M);
  if (ldlt.info() != Eigen::Success || !check_rcond(s, M, ldlt)) return MFREE_FAIL_SINGULAR;

  VecL e = VecL::Zero();
  e(0) = 1.0;
  const VecL g = ldlt.solve(e);
  auto dot = [&](const VecL &v, int j) {
    const double *p = P + j * L;
    double t = 0.0;
    for (int a = 0; a < L; ++a) t += v(a) * p[a];
    return t;
  };
  if (!deriv) {
    if (s.cfg.want_value)
      for (int j = 0; j < n; ++j) s.out.phi[j] = omega(j) * dot(g, j);
    return 0;
  }
  // the D derivative systems share the factorisation: one solve with D right-hand sides
  Eigen::Matrix<double, L, D> rhs;
  for (int i = 0; i < dim; ++i) {
    rhs.col(i) = -(Mi[i] * g);
    const int li = B.linear(i);
    if (li >= 0 && li < L) rhs(li, i) += ih;
  }
  const Eigen::Matrix<double, L, D> gsol = ldlt.solve(rhs);
  VecL gi[D];
  for (int i = 0; i < dim; ++i) gi[i] = gsol.col(i);
  if (s.out.coef)  // gamma, then its derivatives along each axis
    for (int a = 0; a < L; ++a) {
      s.out.coef[a] = g(a);
      for (int i = 0; i < dim; ++i) s.out.coef[(1 + i) * L + a] = gi[i](a);
    }
  for (int j = 0; j < n; ++j) {
    const double gp = dot(g, j), o = omega(j);
    if (s.cfg.want_value) s.out.phi[j] = o * gp;
    if (s.cfg.want_grad)
      for (int i = 0; i < dim; ++i) s.out.grad[j * dim + i] = o * dot(gi[i], j) + domega(j, i) * gp;
  }
  if (!s.cfg.want_hess) return 0;
  for (int i = 0; i < dim; ++i)
    for (int k = i; k < dim; ++k) {
      const int e2 = hessian_index(dim, i, k);
      MatL Mik = MatL::Zero();
      for (int j = 0; j < n; ++j) {
        const double o = ddomega(j, e2);
        if (o == 0.0) continue;
        const double *p = P + j * L;
        for (int a = 0; a < L; ++a)
          for (int b = 0; b < L; ++b) Mik(a, b) += o * p[a] * p[b];
      }
      VecL rhs = -(Mi[i] * gi[k]) - Mi[k] * gi[i] - Mik * g;
      const int qd = B.quadratic(i, k);
      if (qd >= 0 && qd < L) rhs(qd) += (i == k ? 2.0 : 1.0) * ih * ih;
      const VecL gik = ldlt.solve(rhs);
      for (int j = 0; j < n; ++j)
        s.out.hess[j * s.nh + e2] = omega(j) * dot(gik, j) + domega(j, k) * dot(gi[i], j) +
                                    domega(j, i) * dot(gi[k], j) + ddomega(j, e2) * dot(g, j);
    }
  return 0;
}

int mls(Site &s, int order, bool rkpm) {
  const Basis B(s.dim, order);
  if (s.out.support < B.size()) return MFREE_FAIL_NEIGHBORS;
  switch (s.dim * 100 + B.size()) {  // basis_size(dim, order) for dim 1..3, order 0..3
    case 101: return mls_fixed<1, 1>(s, B, rkpm);
    case 102: return mls_fixed<1, 2>(s, B, rkpm);
    case 103: return mls_fixed<1, 3>(s, B, rkpm);
    case 104: return mls_fixed<1, 4>(s, B, rkpm);
    case 201: return mls_fixed<2, 1>(s, B, rkpm);
    case 203: return mls_fixed<2, 3>(s, B, rkpm);
    case 206: return mls_fixed<2, 6>(s, B, rkpm);
    case 210: return mls_fixed<2, 10>(s, B, rkpm);
    case 301: return mls_fixed<3, 1>(s, B, rkpm);
    case 304: return mls_fixed<3, 4>(s, B, rkpm);
    case 310: return mls_fixed<3, 10>(s, B, rkpm);
    case 320: return mls_fixed<3, 20>(s, B, rkpm);
    default: return MFREE_FAIL_SINGULAR;
  }
}

// Methods that estimate Taylor coefficients Q_alpha (SSPH, KB Method 2, MSPH) read the
// value, gradient and Hessian rows off the same coefficients: f = Q_0,
// df/dx_i = Q_{e_i} / hs, d2f/dx_i dx_k = alpha! Q_{e_i + e_k} / hs^2. row(m, scale,
// dst, stride) writes the shape functions of coefficient m.
template <class Row>
void write_coefficient_rows(Site &s, const Basis &B, double ih, Row &&row) {
  const int dim = s.dim;
  if (s.cfg.want_value) row(0, 1.0, s.out.phi, 1);
  if (s.cfg.want_grad)
    for (int i = 0; i < dim; ++i) row(B.linear(i), ih, s.out.grad + i, dim);
  if (s.cfg.want_hess)
    for (int i = 0; i < dim; ++i)
      for (int k = i; k < dim; ++k) {
        const int m = B.quadratic(i, k);
        row(m, B.factorial(m) * ih * ih, s.out.hess + hessian_index(dim, i, k), s.nh);
      }
}

// Weighted Taylor fit (SSPH, 001 eqs 3.3-3.10, weights W V; KB Method 2, 000 eqs 63-64,
// weights phi^S): K = sum omega p p^T, Q = K^-1 sum omega p f. Value Q_0, derivatives
// alpha! Q_alpha / hs^|alpha|; the kernel is never differentiated.
int taylor_fit(Site &s, int order, const double *omega) {
  const Basis B(s.dim, order);
  const int L = B.size(), dim = s.dim, n = s.n;
  if (s.out.support < L) return MFREE_FAIL_NEIGHBORS;
  const double ih = 1.0 / s.in.hs;
  double *P = s.w.p.data();
  Mat K = Mat::Zero(L, L);
  for (int j = 0; j < n; ++j) {
    double sj[3] = {0, 0, 0};
    for (int c = 0; c < dim; ++c) sj[c] = s.d(j)[c] * ih;
    double *p = P + j * L;
    B.eval(sj, p);
    if (omega[j] == 0.0) continue;
    for (int a = 0; a < L; ++a)
      for (int b = 0; b <= a; ++b) K(a, b) += omega[j] * p[a] * p[b];
  }
  K.triangularView<Eigen::StrictlyUpper>() = K.transpose().triangularView<Eigen::StrictlyUpper>();
  Eigen::LDLT<Mat> ldlt(K);
  if (ldlt.info() != Eigen::Success || !check_rcond(s, K, ldlt)) return MFREE_FAIL_SINGULAR;
  auto row = [&](int m, double scale, double *dst, int stride) {
    Vec e = Vec::Zero(L);
    e(m) = 1.0;
    const Vec c = ldlt.solve(e);
    for (int j = 0; j < n; ++j) {
      double t = 0.0;
      const double *p = P + j * L;
      for (int a = 0; a < L; ++a) t += c(a) * p[a];
      dst[j * stride] = scale * omega[j] * t;
    }
  };
  write_coefficient_rows(s, B, ih, row);
  return 0;
}

// MSPH (001 eqs 2.9-2.15): moments of W and its xi-derivatives against the shifted
// basis; K is not symmetric. N_alpha,j = sum_c (K^-1)_{alpha c} M_c^(j) V_j.
int msph(Site &s, int order) {
  const Basis B(s.dim, order);
  const int L = B.size(), dim = s.dim, n = s.n;
  if (s.out.support < L) return MFREE_FAIL_NEIGHBORS;
  const double ih = 1.0 / s.in.hs, hs = s.in.hs;
  double *P = s.w.p.data();
  double *Mv = s.w.q.data();  // n x L moments M_c^(j), scaled by hs^|c|
  Mat K = Mat::Zero(L, L);
  for (int j = 0; j < n; ++j) {
    double sj[3] = {0, 0, 0};
    for (int c = 0; c < dim; ++c) sj[c] = s.d(j)[c] * ih;
    double *p = P + j * L;
    B.eval(sj, p);
    double *m = Mv + j * L;
    for (int a = 0; a < L; ++a) {
      const auto &al = B.alpha(a);
      const int deg = B.degree(a);
      if (deg == 0) {
        m[a] = s.w.w[j];
      } else if (deg == 1) {
        const int i = al[0] ? 0 : (al[1] ? 1 : 2);
        m[a] = -s.gw(j)[i] * hs;  // d/dxi W(x - xi) = -grad_x w
      } else {
        int ii[2], c = 0;
        for (int q = 0; q < 3; ++q)
          for (int t = 0; t < al[q]; ++t) ii[c++] = q;
        m[a] = s.hw(j)[hessian_index(dim, ii[0], ii[1])] * hs * hs;
      }
    }
    const double V = s.in.vol[j];
    for (int a = 0; a < L; ++a)
      for (int b = 0; b < L; ++b) K(a, b) += m[a] * p[b] * V;
  }
  Eigen::PartialPivLU<Mat> lu(K);
  if (!check_rcond(s, K, lu)) return MFREE_FAIL_SINGULAR;
  const Mat Ki = lu.inverse();
  auto row = [&](int a, double scale, double *dst, int stride) {
    for (int j = 0; j < n; ++j) {
      double t = 0.0;
      const double *m = Mv + j * L;
      for (int c = 0; c < L; ++c) t += Ki(a, c) * m[c];
      dst[j * stride] = scale * t * s.in.vol[j];
    }
  };
  write_coefficient_rows(s, B, ih, row);
  return 0;
}

// Derivative corrections with alpha = A^-T (paper 000 Sects. 4.4.3, 4.4.5, 4.4.6; the
// transpose: docs/papers.md, paper 000, errata 4):
// A_ab = sum_j p_a(j) q_b(j); the corrected functions are (A^-T q_j)_k. p and q are
// n x m arrays; writes C = A^-T into coef (m x m, row-major).
// (m is 1..4: a compile-time size keeps A and its LU in registers.)
template <int M>
int correction_fixed(Site &s, const double *p, const double *q, double *coef) {
  using MatM = Eigen::Matrix<double, M, M>;
  double acc[M][M] = {{0}};
  for (int j = 0; j < s.n; ++j)
    for (int a = 0; a < M; ++a)
      for (int b = 0; b < M; ++b) acc[a][b] += p[j * M + a] * q[j * M + b];
  MatM A;
  for (int a = 0; a < M; ++a)
    for (int b = 0; b < M; ++b) A(a, b) = acc[a][b];
  Eigen::PartialPivLU<MatM> lu(A);
  if (!check_rcond(s, A, lu)) return MFREE_FAIL_SINGULAR;
  const MatM C = lu.inverse().transpose();
  for (int a = 0; a < M; ++a)
    for (int b = 0; b < M; ++b) coef[a * M + b] = C(a, b);
  return 0;
}

int correction(Site &s, int m, const double *p, const double *q, double *coef) {
  switch (m) {
    case 1: return correction_fixed<1>(s, p, q, coef);
    case 2: return correction_fixed<2>(s, p, q, coef);
    case 3: return correction_fixed<3>(s, p, q, coef);
    case 4: return correction_fixed<4>(s, p, q, coef);
    default: return MFREE_FAIL_SINGULAR;
  }
}

void sph_values(Site &s) {
  if (s.cfg.want_value)
    for (int j = 0; j < s.n; ++j) s.out.phi[j] = s.w.w[j] * s.in.vol[j];
}

// Difference form G_self = -sum_{j != self} G_j, so that constants have zero gradient.
void close_difference(Site &s) {
  const int dim = s.dim;
  double sum[3] = {0, 0, 0};
  for (int j = 0; j < s.n; ++j)
    if (j != s.in.self)
      for (int c = 0; c < dim; ++c) sum[c] += s.out.grad[j * dim + c];
  for (int c = 0; c < dim; ++c) s.out.grad[s.in.self * dim + c] = -sum[c];
}

int run(Site &s, int order) {
  const LocalConfig &cfg = s.cfg;
  const int dim = s.dim, n = s.n;
  switch (cfg.method) {
    case MFREE_METHOD_SPH:
      if (s.out.support < 1) return MFREE_FAIL_NEIGHBORS;
      sph_values(s);
      if (cfg.want_grad)
        for (int j = 0; j < n; ++j)
          for (int c = 0; c < dim; ++c) s.out.grad[j * dim + c] = s.gw(j)[c] * s.in.vol[j];
      if (cfg.want_hess)
        for (int j = 0; j < n; ++j)
          for (int e = 0; e < s.nh; ++e) s.out.hess[j * s.nh + e] = s.hw(j)[e] * s.in.vol[j];
      return 0;
    case MFREE_METHOD_SPH_SYMMETRIC:
      if (s.out.support < 1) return MFREE_FAIL_NEIGHBORS;
      sph_values(s);
      if (cfg.want_grad) {
        for (int j = 0; j < n; ++j)
          for (int c = 0; c < dim; ++c) s.out.grad[j * dim + c] = s.gw(j)[c] * s.in.vol[j];
        close_difference(s);
      }
      return 0;
    case MFREE_METHOD_SHEPARD:
      return shepard(s, true);
    case MFREE_METHOD_MLS:
      return mls(s, order, false);
    case MFREE_METHOD_RKPM:
      return mls(s, order, true);
    case MFREE_METHOD_SSPH: {
      double *om = s.w.r.data() + n;  // r has room for 2n
      for (int j = 0; j < n; ++j) om[j] = s.w.w[j] * s.in.vol[j];
      return taylor_fit(s, order, om);
    }
    case MFREE_METHOD_KB_METHOD2: {
      const int st = shepard(s, false);
      if (st) return st;
      double *om = s.w.r.data() + n;
      std::copy(s.w.q.begin(), s.w.q.begin() + n, om);
      return taylor_fit(s, order, om);
    }
    case MFREE_METHOD_MSPH:
      return msph(s, order);
    case MFREE_METHOD_JOHNSON_BEISSEL: {
      if (s.out.support < 2) return MFREE_FAIL_NEIGHBORS;
      sph_values(s);
      if (!cfg.want_grad) return 0;
      for (int c = 0; c < dim; ++c) {
        double den = 0.0;  // sum_j (grad w_j)_c V_j (x_j - x)_c, > 0 for a monotone kernel
        for (int j = 0; j < n; ++j) den += s.gw(j)[c] * s.in.vol[j] * s.d(j)[c];
        if (!(std::fabs(den) > 0.0)) return MFREE_FAIL_SINGULAR;
        const double beta = 1.0 / den;
        if (s.out.coef) s.out.coef[c] = beta;
        for (int j = 0; j < n; ++j) s.out.grad[j * dim + c] = beta * s.gw(j)[c] * s.in.vol[j];
      }
      close_difference(s);
      return 0;
    }
    case MFREE_METHOD_RANDLES_LIBERSKY:
    case MFREE_METHOD_KB_METHOD1:
    case MFREE_METHOD_KB_METHOD3: {
      const bool rl = cfg.method == MFREE_METHOD_RANDLES_LIBERSKY;
      const bool m3 = cfg.method == MFREE_METHOD_KB_METHOD3;
      if (s.out.support < dim + 1) return MFREE_FAIL_NEIGHBORS;
      if (rl) {
        sph_values(s);
      } else {
        const int st = shepard(s, false);
        if (st) return st;
      }
      const int m = m3 ? dim + 1 : dim, off = m3 ? 1 : 0;
      const double hs = s.in.hs, ih = 1.0 / hs;
      double *p = s.w.p.data();
      double *q = s.w.p.data() + static_cast<size_t>(n) * m;
      const double *sphi = s.w.q.data(), *sgrad = s.w.sh.data();
      for (int j = 0; j < n; ++j) {
        if (m3) {
          p[j * m] = 1.0;
          q[j * m] = sphi[j];
        }
        for (int c = 0; c < dim; ++c) {
          p[j * m + off + c] = s.d(j)[c] * ih;
          q[j * m + off + c] = rl ? s.gw(j)[c] * s.in.vol[j] * hs : sgrad[3 * j + c] * hs;
        }
      }
      double C[16];
      const int st = correction(s, m, p, q, C);
      if (st) return st;
      if (s.out.coef && !m3)  // C column by column: corrected gradient = C grad
        for (int a = 0; a < dim; ++a)
          for (int b = 0; b < dim; ++b) s.out.coef[a + b * dim] = C[a * m + b];
      for (int j = 0; j < n; ++j) {
        double f[4];
        for (int a = 0; a < m; ++a) {
          f[a] = 0.0;
          for (int b = 0; b < m; ++b) f[a] += C[a * m + b] * q[j * m + b];
        }
        if (cfg.want_value) {
          if (m3) s.out.phi[j] = f[0];
          else if (!rl) s.out.phi[j] = sphi[j];
        }
        if (cfg.want_grad)
          for (int c = 0; c < dim; ++c) s.out.grad[j * dim + c] = f[off + c] * ih;
      }
      if (rl && cfg.want_grad) close_difference(s);
      return 0;
    }
    default:
      return MFREE_FAIL_SINGULAR;
  }
}

}  // namespace

RecordGradient::RecordGradient(const LocalConfig &cfg)
    : cfg_(cfg),
      basis_(cfg.dim, cfg.method == MFREE_METHOD_MLS || cfg.method == MFREE_METHOD_RKPM ? cfg.order : 0) {}

void RecordGradient::operator()(const double *rec, double hs, const double *d, double w,
                                const double *gw, double vol, double *g) const {
  const int dim = cfg_.dim;
  switch (cfg_.method) {
    case MFREE_METHOD_SHEPARD: {  // grad (w / S) / V
      const double iS = 1.0 / rec[0], iv = 1.0 / vol;
      for (int c = 0; c < dim; ++c) g[c] = (gw[c] * iS - w * rec[1 + c] * iS * iS) * iv;
      return;
    }
    case MFREE_METHOD_JOHNSON_BEISSEL:  // beta_c grad_c w
      for (int c = 0; c < dim; ++c) g[c] = rec[c] * gw[c];
      return;
    case MFREE_METHOD_RANDLES_LIBERSKY:  // M grad w
      for (int a = 0; a < dim; ++a) {
        double f = 0.0;
        for (int b = 0; b < dim; ++b) f += rec[a + b * dim] * gw[b];
        g[a] = f;
      }
      return;
    case MFREE_METHOD_KB_METHOD1: {  // M grad (w / S) / V, S and grad S after M
      const double *S = rec + dim * dim, iS = 1.0 / S[0], iv = 1.0 / vol;
      double q[3];
      for (int c = 0; c < dim; ++c) q[c] = gw[c] * iS - w * S[1 + c] * iS * iS;
      for (int a = 0; a < dim; ++a) {
        double f = 0.0;
        for (int b = 0; b < dim; ++b) f += rec[a + b * dim] * q[b];
        g[a] = f * iv;
      }
      return;
    }
    default: {  // MLS, RKPM: gamma, then d gamma / dx_c
      const bool rkpm = cfg_.method == MFREE_METHOD_RKPM;
      const int L = basis_.size();
      const double ih = 1.0 / hs, iv = 1.0 / vol;
      double sj[3] = {0, 0, 0}, p[kMaxBasis];
      for (int c = 0; c < dim; ++c) sj[c] = d[c] * ih;
      basis_.eval(sj, p);
      auto dot = [&](const double *v) {
        double t = 0.0;
        for (int a = 0; a < L; ++a) t += v[a] * p[a];
        return t;
      };
      const double gp = dot(rec);
      if (rkpm)  // o = w V: the volume cancels
        for (int i = 0; i < dim; ++i) g[i] = w * dot(rec + (1 + i) * L) + gw[i] * gp;
      else
        for (int i = 0; i < dim; ++i) g[i] = (w * dot(rec + (1 + i) * L) + gw[i] * gp) * iv;
      return;
    }
  }
}

void LocalWork::reserve(int n, int dim, int L) {
  (void)dim;
  const size_t nn = static_cast<size_t>(n);
  if (r.size() < 2 * nn) r.resize(2 * nn);
  if (w.size() < nn) w.resize(nn);
  if (gw.size() < 3 * nn) gw.resize(3 * nn);
  if (hw.size() < 6 * nn) hw.resize(6 * nn);
  const size_t pl = nn * static_cast<size_t>(std::max(L, 8));
  if (p.size() < pl) p.resize(pl);
  if (q.size() < pl) q.resize(pl);
  if (sh.size() < 9 * nn) sh.resize(9 * nn);
}

void compute_site(const LocalConfig &cfg, const LocalInput &in, LocalWork &work,
                  LocalOutput &out) {
  Site s{cfg, in, work, out, cfg.dim, hessian_size(cfg.dim), in.n};
  work.reserve(in.n, cfg.dim, basis_size(cfg.dim, std::max(cfg.order, 1)));
  const int m = cfg.method;
  const bool need_hess = cfg.want_hess || m == MFREE_METHOD_MSPH;
  const bool need_grad = need_hess || cfg.want_grad || m == MFREE_METHOD_KB_METHOD1 ||
                         m == MFREE_METHOD_KB_METHOD3 || m == MFREE_METHOD_RANDLES_LIBERSKY ||
                         m == MFREE_METHOD_JOHNSON_BEISSEL;
  out.cond = 1.0;
  out.support = weights(s, need_grad, need_hess);
  zero_rows(s);
  out.status = run(s, cfg.order);
  out.order_used = out.status ? -1 : (has_order(m) ? cfg.order : fixed_order(m));
  if (out.status) zero_rows(s);
}

void compute_site_rules(LocalConfig cfg, const LocalInput &in, LocalWork &work, LocalOutput &out,
                        int fallback, double shepard_cond, bool done, int ncoef) {
  const int method = cfg.method, order = cfg.order;
  if (!done) compute_site(cfg, in, work, out);
  if (out.status && fallback == MFREE_FALLBACK_LOWER_ORDER) {
    const int first_status = out.status;
    const double first_cond = out.cond;
    // A site that falls back gets a record of zeros (mfree.h): a lower order's or
    // Shepard's record has another layout, and Shepard's (1 + dim values) is longer
    // than Johnson-Beissel's or Randles-Libersky's, so it would run into the next one.
    if (out.coef) std::fill_n(out.coef, ncoef, 0.0);
    out.coef = nullptr;
    if (has_order(method))
      for (int o = order - 1; o >= min_order(method) && out.status; --o) {
        cfg.order = o;
        if (cfg.want_hess && !provides_hessian(method, o)) break;
        compute_site(cfg, in, work, out);
      }
    if (out.status) {  // last resort: Shepard functions (constant complete)
      cfg.method = MFREE_METHOD_SHEPARD;
      cfg.order = 0;
      compute_site(cfg, in, work, out);
    }
    if (out.status) {
      out.status = first_status;
      out.cond = first_cond;
    }
  }
  if (!out.status && out.cond > shepard_cond) {
    const double cond = out.cond;
    if (out.coef) std::fill_n(out.coef, ncoef, 0.0);  // as a fallback's (above)
    out.coef = nullptr;
    // Shepard functions of w V, RKPM of order 0 (MFREE_METHOD_SHEPARD's are of w)
    cfg.method = MFREE_METHOD_RKPM;
    cfg.order = 0;
    compute_site(cfg, in, work, out);
    out.cond = cond;
  }
}

bool has_order(int m) {
  return m == MFREE_METHOD_MLS || m == MFREE_METHOD_RKPM || m == MFREE_METHOD_SSPH ||
         m == MFREE_METHOD_MSPH || m == MFREE_METHOD_KB_METHOD2;
}
int fixed_order(int m) {
  switch (m) {
    case MFREE_METHOD_JOHNSON_BEISSEL:
    case MFREE_METHOD_RANDLES_LIBERSKY:
    case MFREE_METHOD_KB_METHOD1:
    case MFREE_METHOD_KB_METHOD3:
      return 1;
    default:
      return 0;
  }
}
int min_order(int m) {
  switch (m) {
    case MFREE_METHOD_MLS:
    case MFREE_METHOD_RKPM:
      return 0;
    case MFREE_METHOD_SSPH:
    case MFREE_METHOD_MSPH:
    case MFREE_METHOD_KB_METHOD2:
      return 1;
    default:
      return fixed_order(m);
  }
}
int max_order(int m) {
  switch (m) {
    case MFREE_METHOD_MLS:
    case MFREE_METHOD_RKPM:
    case MFREE_METHOD_SSPH:
      return 3;
    case MFREE_METHOD_MSPH:
    case MFREE_METHOD_KB_METHOD2:
      return 2;
    default:
      return fixed_order(m);
  }
}
bool particles_only(int m) {
  return m == MFREE_METHOD_SPH_SYMMETRIC || m == MFREE_METHOD_JOHNSON_BEISSEL ||
         m == MFREE_METHOD_RANDLES_LIBERSKY;
}
bool provides_hessian(int m, int order) {
  switch (m) {
    case MFREE_METHOD_SPH:
    case MFREE_METHOD_SHEPARD:
    case MFREE_METHOD_MLS:
    case MFREE_METHOD_RKPM:
      return true;
    case MFREE_METHOD_SSPH:
    case MFREE_METHOD_MSPH:
    case MFREE_METHOD_KB_METHOD2:
      return order >= 2;
    default:
      return false;
  }
}

}  // namespace mfree
