// Fast path of the value + gradient tables (see shape_fast.hpp). The formulas are those
// of local.cpp (same notation: d_j = x_j - x, s_j = d_j / hs, w_j = W(|d_j|, h_j),
// grad_x w_j = gf_j d_j with the radial factor gf_j = -W'(r_j) / r_j); only the
// arithmetic is arranged differently, so that tables agree with the general path to
// round-off (tests t404 against an O(N^2) oracle, t432 against the general path).
//
// Moments: for a monomial basis p of order K, the entries of M = sum w p p^T and of its
// derivatives M_,i = sum gf d_i p p^T are sums of single monomials, M_ab = sum w s^(a+b)
// and (M_,i)_ab = hs sum gf s^(a+b+e_i). So one neighbour pass accumulates the
// binom(2K+D, D) moments of w and the binom(2K+1+D, D) moments of gf (for 2D order 2:
// 15 + 21 sums instead of 3 x 21 matrix entries), in loops of fixed even length that the
// compiler vectorises.
#include "shape_fast.hpp"

#include <algorithm>
#include <cmath>

#include "local.hpp"

// Loops over the neighbours of a site: vectorised even at -O2 when OpenMP is on (the
// simd loops carry no dependence between neighbours); loops of compile-time length over
// monomials and small matrices: unrolled, so that their indices fold and the
// accumulators stay in registers.
#ifdef _OPENMP
#define MFREE_SIMD _Pragma("omp simd")
#define MFREE_SIMD_SUM(v) _Pragma(MFREE_STR(omp simd reduction(+ : v)))
#else
#define MFREE_SIMD
#define MFREE_SIMD_SUM(v)
#endif
#define MFREE_STR(x) #x
#define MFREE_UNROLL _Pragma("GCC unroll 64")

namespace mfree {

namespace {

// As in local.cpp: a local system whose reciprocal condition number is below this is
// singular (the site then goes to the general path, which decides and reports).
constexpr double kMinRcond = 1e-12;

// ---------------------------------------------------------------------------------------
// Monomials s^e, |e| <= 2K+1, in D variables, ordered by degree (degree-1 monomials are
// s_1..s_D at positions 1..D), with each one's parent (one degree lower) and the
// variable that multiplies it, and the moment index of every p_a p_b and s_i p_a p_b.

constexpr int binom(int n, int k) {
  int r = 1;
  for (int i = 1; i <= k; ++i) r = r * (n - k + i) / i;
  return r;
}

template <int D, int K>
struct Tab {
  static constexpr int L = binom(K + D, D);
  static constexpr int NW = binom(2 * K + D, D);
  static constexpr int NM = binom(2 * K + 1 + D, D);
  static constexpr int PW = (NW + 1) / 2 * 2;  // padded to even lengths
  static constexpr int PM = (NM + 1) / 2 * 2;
  int e[NM][3] = {};
  int parent[NM] = {};
  int var[NM] = {};
  int mw[L][L] = {};
  int mg[D][L][L] = {};
};

template <int D, int K>
constexpr int find_mono(const Tab<D, K> &t, int a, int b, int c) {
  for (int m = 0; m < Tab<D, K>::NM; ++m)
    if (t.e[m][0] == a && t.e[m][1] == b && t.e[m][2] == c) return m;
  return -1;
}

template <int D, int K>
constexpr Tab<D, K> make_tab() {
  Tab<D, K> t{};
  int m = 0;
  // degrees 0..2 in the order of Basis (1; s_i; s_i^2; s1 s2, s2 s3, s3 s1), so that the
  // moment matrices are those of the general path entry for entry (pivoting and the
  // condition estimate depend on the order); higher degrees in any order
  auto push = [&](int a, int b, int c) {
    t.e[m][0] = a;
    t.e[m][1] = b;
    t.e[m][2] = c;
    ++m;
  };
  push(0, 0, 0);
  for (int i = 0; i < D; ++i) push(i == 0, i == 1, i == 2);
  if (K >= 1) {  // degree 2 is needed from order 1 on (2K + 1 >= 3)
    for (int i = 0; i < D; ++i) push(2 * (i == 0), 2 * (i == 1), 2 * (i == 2));
    if (D >= 2) push(1, 1, 0);
    if (D >= 3) {
      push(0, 1, 1);
      push(1, 0, 1);
    }
  }
  for (int deg = 3; deg <= 2 * K + 1; ++deg)
    for (int a = deg; a >= 0; --a)
      for (int b = deg - a; b >= 0; --b) {
        const int c = deg - a - b;
        if ((D < 2 && b) || (D < 3 && c)) continue;
        push(a, b, c);
      }
  for (int q = 1; q < Tab<D, K>::NM; ++q) {
    int v = 0;
    while (t.e[q][v] == 0) ++v;
    t.var[q] = v;
    t.parent[q] = find_mono(t, t.e[q][0] - (v == 0), t.e[q][1] - (v == 1), t.e[q][2] - (v == 2));
  }
  for (int a = 0; a < Tab<D, K>::L; ++a)
    for (int b = 0; b < Tab<D, K>::L; ++b) {
      const int e0 = t.e[a][0] + t.e[b][0], e1 = t.e[a][1] + t.e[b][1], e2 = t.e[a][2] + t.e[b][2];
      t.mw[a][b] = find_mono(t, e0, e1, e2);
      MFREE_UNROLL
      for (int i = 0; i < D; ++i) t.mg[i][a][b] = find_mono(t, e0 + (i == 0), e1 + (i == 1), e2 + (i == 2));
    }
  return t;
}

template <int D, int K>
constexpr Tab<D, K> kTab = make_tab<D, K>();

// Monomials 0..N-1 of s (N <= NM), zero up to P.
template <int D, int K, int N, int P>
inline void monomials(const double *s, double *mo) {
  constexpr const Tab<D, K> &T = kTab<D, K>;
  mo[0] = 1.0;
  MFREE_UNROLL
  for (int m = 1; m < N; ++m) mo[m] = mo[T.parent[m]] * s[T.var[m]];
  MFREE_UNROLL
  for (int m = N; m < P; ++m) mo[m] = 0.0;
}

// ---------------------------------------------------------------------------------------
// Small dense inverses, with the general path's singularity test and condition number
// (local.cpp check_rcond): rc = min(Eigen's rcond() estimate, ratio of the smallest to
// the largest pivot of the same pivoted factorisation), singular below kMinRcond,
// reported as 1 / rc. Both are reproduced here on the explicit inverse, so that the
// two paths report the same condition numbers and decide alike (up to round-off).

template <int L>
double norm1(const double (&A)[L][L]) {
  double big = 0.0;
  for (int b = 0; b < L; ++b) {
    double s = 0.0;
    for (int a = 0; a < L; ++a) s += std::fabs(A[a][b]);
    big = std::max(big, s);
  }
  return big;
}

// out = X b (T: X^T b)
template <int L, bool T>
void mul(const double (&X)[L][L], const double *b, double *out) {
  MFREE_UNROLL
  for (int a = 0; a < L; ++a) {
    double t = 0.0;
    MFREE_UNROLL
    for (int c = 0; c < L; ++c) t += (T ? X[c][a] : X[a][c]) * b[c];
    out[a] = t;
  }
}

template <int L>
double sum_abs(const double *v) {
  double t = 0.0;
  MFREE_UNROLL
  for (int a = 0; a < L; ++a) t += std::fabs(v[a]);
  return t;
}

// Eigen's rcond_invmatrix_L1_norm_estimate (Hager / Higham), step for step, with the
// solves done by the inverse X.
template <int L>
double inverse_norm_estimate(const double (&X)[L][L]) {
  double v[L], w[L], sign[L], old_sign[L];
  for (int a = 0; a < L; ++a) w[a] = 1.0 / L;
  mul<L, false>(X, w, v);
  double lower = sum_abs<L>(v);
  if (L == 1) return lower;
  double old_lower = lower;
  int idx = -1, old_idx = -1;
  for (int k = 0; k < 4; ++k) {
    bool same = k > 0;
    MFREE_UNROLL
    for (int a = 0; a < L; ++a) {
      sign[a] = v[a] < 0.0 ? -1.0 : 1.0;
      same = same && sign[a] == old_sign[a];
    }
    if (same) break;
    mul<L, true>(X, sign, v);
    idx = 0;
    double vmax = std::fabs(v[0]);
    MFREE_UNROLL
    for (int a = 1; a < L; ++a) {  // first largest, without branches
      const double va = std::fabs(v[a]);
      idx = va > vmax ? a : idx;
      vmax = va > vmax ? va : vmax;
    }
    if (idx == old_idx) break;
    for (int a = 0; a < L; ++a) v[a] = X[a][idx];
    lower = sum_abs<L>(v);
    if (lower <= old_lower) break;
    for (int a = 0; a < L; ++a) old_sign[a] = sign[a];
    old_idx = idx;
    old_lower = lower;
  }
  double alt = 1.0;
  for (int a = 0; a < L; ++a) {
    w[a] = alt * (1.0 + static_cast<double>(a) / static_cast<double>(L - 1));
    alt = -alt;
  }
  mul<L, false>(X, w, v);
  return std::max(lower, 2.0 * sum_abs<L>(v) / (3.0 * L));
}

// matrix_norm = ||A||_1, piv = the factorisation's pivots.
template <int L>
bool accept(double matrix_norm, const double (&X)[L][L], const double *piv, double &cond) {
  double rc;
  if (matrix_norm == 0.0) {
    rc = 0.0;
  } else if (L == 1) {
    rc = 1.0;
  } else {
    const double inv = inverse_norm_estimate<L>(X);
    rc = inv == 0.0 ? 0.0 : (1.0 / inv) / matrix_norm;
  }
  if (!std::isfinite(rc)) rc = 0.0;
  double big = 0.0, small = INFINITY;
  for (int k = 0; k < L; ++k) {
    big = std::max(big, std::fabs(piv[k]));
    small = std::min(small, std::fabs(piv[k]));
  }
  rc = std::min(rc, big > 0.0 ? small / big : 0.0);
  cond = rc > 0.0 ? 1.0 / rc : INFINITY;
  return rc >= kMinRcond;
}

// Symmetric positive definite A (moment matrices of non-negative weights): LDL^T with
// Eigen's diagonal pivoting (largest remaining original diagonal first), X = A^-1.
// False when a pivot is not positive (the general path then decides) or the test fails.
template <int L>
bool spd_inverse(const double (&A)[L][L], double (&X)[L][L], double &cond) {
  int p[L];
  double dg[L];
  MFREE_UNROLL
  for (int k = 0; k < L; ++k) {
    p[k] = k;
    dg[k] = std::fabs(A[k][k]);
  }
  MFREE_UNROLL
  for (int k = 0; k < L; ++k) {
    int big = k;
    double dmax = dg[k];
    MFREE_UNROLL
    for (int j = 0; j < L; ++j) {  // first largest of the rest, without branches
      if (j <= k) continue;
      big = dg[j] > dmax ? j : big;
      dmax = dg[j] > dmax ? dg[j] : dmax;
    }
    const int pk = p[k];
    p[k] = p[big];
    p[big] = pk;
    dg[big] = dg[k];
    dg[k] = dmax;
  }
  double B[L][L];
  MFREE_UNROLL
  for (int a = 0; a < L; ++a) {
    MFREE_UNROLL
    for (int b = 0; b < L; ++b) B[a][b] = A[p[a]][p[b]];
  }
  // fixed loop bounds with guards: fully unrolled, the guards fold away
  double Lw[L][L] = {}, Dg[L] = {}, iD[L] = {};
  MFREE_UNROLL
  for (int k = 0; k < L; ++k) {
    double dk = B[k][k];
    MFREE_UNROLL
    for (int m = 0; m < L; ++m)
      if (m < k) dk -= Lw[k][m] * Lw[k][m] * Dg[m];
    if (!(dk > 0.0)) return false;
    Dg[k] = dk;
    iD[k] = 1.0 / dk;
    MFREE_UNROLL
    for (int i = 0; i < L; ++i) {
      if (i <= k) continue;
      double v = B[i][k];
      MFREE_UNROLL
      for (int m = 0; m < L; ++m)
        if (m < k) v -= Lw[i][m] * Lw[k][m] * Dg[m];
      Lw[i][k] = v * iD[k];
    }
  }
  double Y[L][L] = {};  // L^-1, unit lower triangular
  MFREE_UNROLL
  for (int c = 0; c < L; ++c) {
    Y[c][c] = 1.0;
    MFREE_UNROLL
    for (int i = 0; i < L; ++i) {
      if (i <= c) continue;
      double v = 0.0;
      MFREE_UNROLL
      for (int m = 0; m < L; ++m)
        if (m >= c && m < i) v -= Lw[i][m] * Y[m][c];
      Y[i][c] = v;
    }
  }
  MFREE_UNROLL
  for (int a = 0; a < L; ++a) {
    MFREE_UNROLL
    for (int b = 0; b < L; ++b) {
      if (b < a) continue;
      double v = 0.0;
      MFREE_UNROLL
      for (int k = 0; k < L; ++k)
        if (k >= b) v += Y[k][a] * Y[k][b] * iD[k];
      X[p[a]][p[b]] = X[p[b]][p[a]] = v;
    }
  }
  return accept<L>(norm1(A), X, Dg, cond);
}

// General A (the corrected-derivative systems): Gauss-Jordan with partial pivoting (the
// pivots of Eigen's PartialPivLU).
template <int L>
bool gen_inverse(const double (&A)[L][L], double (&X)[L][L], double &cond) {
  double W[L][L], piv[L];
  for (int a = 0; a < L; ++a)
    for (int b = 0; b < L; ++b) {
      W[a][b] = A[a][b];
      X[a][b] = a == b ? 1.0 : 0.0;
    }
  for (int k = 0; k < L; ++k) {
    int p = k;
    for (int i = k + 1; i < L; ++i)
      if (std::fabs(W[i][k]) > std::fabs(W[p][k])) p = i;
    if (!(std::fabs(W[p][k]) > 0.0)) return false;
    if (p != k)
      for (int b = 0; b < L; ++b) {
        std::swap(W[p][b], W[k][b]);
        std::swap(X[p][b], X[k][b]);
      }
    piv[k] = W[k][k];
    const double ip = 1.0 / W[k][k];
    for (int b = 0; b < L; ++b) {
      W[k][b] *= ip;
      X[k][b] *= ip;
    }
    for (int i = 0; i < L; ++i) {
      if (i == k) continue;
      const double f = W[i][k];
      if (f == 0.0) continue;
      for (int b = 0; b < L; ++b) {
        W[i][b] -= f * W[k][b];
        X[i][b] -= f * X[k][b];
      }
    }
  }
  return accept<L>(norm1(A), X, piv, cond);
}

// ---------------------------------------------------------------------------------------
// Kernel shapes f(q), f'(q). The cubic spline is written out (the default kernel and the
// one of the papers' benchmarks), with Kernel::shape's expressions and closed support;
// every other non-negative kernel goes through Kernel::shape.

struct CubicSpline {
  explicit CubicSpline(const Kernel &) {}
  // both pieces and a select: neighbours fall on either side of q = 1 at random, and
  // a branch would be mispredicted half the time
  static constexpr bool kVector = true;
  // Both pieces blended with a 0/1 mask (equal to selecting one: the other is multiplied
  // by zero, t = max(2 - q, 0) written with fabs): neighbours fall on either side of
  // q = 1 at random, so a branch would be mispredicted half the time, and the blend
  // lets the neighbour loop vectorise.
  static double f(double q) {
    const double m = q < 1.0 ? 1.0 : 0.0, t0 = 2.0 - q, t = 0.5 * (t0 + std::fabs(t0));
    return m * (1.0 - 1.5 * q * q + 0.75 * q * q * q) + (1.0 - m) * (0.25 * t * t * t);
  }
  static double df(double q) {
    const double m = q < 1.0 ? 1.0 : 0.0, t0 = 2.0 - q, t = 0.5 * (t0 + std::fabs(t0));
    return m * (-3.0 * q + 2.25 * q * q) + (1.0 - m) * (-0.75 * t * t);
  }
  void operator()(double q, double &fv, double &dfv) const {
    fv = f(q);
    dfv = df(q);
  }
};

struct AnyShape {
  explicit AnyShape(const Kernel &k) : k_(&k) {}
  void operator()(double q, double &f, double &df) const {
    double d2f;
    k_->shape(q, f, df, d2f);
  }
  static constexpr bool kVector = false;
  const Kernel *k_;
};

// Displacements, volumes, weights and radial gradient factors of the row of site s into
// the scratch (SoA); returns the number of non-zero weights.
template <int D, class Kern, bool G>
int gather(const FastPath &fp, const FastTables &t, int32_t s, FastScratch &w, int n) {
  const int32_t *cl = t.cols + t.rowptr[s];
  const double hs = t.sh[s * t.sstride];
  const int64_t ps = t.stride;
  double *d[3] = {w.d(0), w.d(1), w.d(2)};
  // one pass over the neighbours' records (coordinates and volume in one cache line)
  double xs[D];
  MFREE_UNROLL
  for (int c = 0; c < D; ++c) xs[c] = t.sx[c][s * t.sstride];
  const double *P = t.x[0], *PV = t.vol;
  double *v = w.v();
  for (int j = 0; j < n; ++j) {
    const int64_t r = cl[j] * ps;
    MFREE_UNROLL
    for (int c = 0; c < D; ++c) d[c][j] = P[r + c] - xs[c];
    v[j] = PV[r];
  }
  MFREE_UNROLL
  for (int c = 0; c < D; ++c)
    if (t.periodic[c]) {
      const double L = t.period[c];
      double *dc = d[c];
      for (int j = 0; j < n; ++j) dc[j] -= L * std::nearbyint(dc[j] / L);
    }
  const Kern K(fp.kernel());
  const double c0 = fp.kernel().norm();
  double *wt = w.w(), *gf = w.gf();
  int support = 0;
  if constexpr (Kern::kVector) {
    if (t.convention == MFREE_SEARCH_GATHER) {
      const double ih = 1.0 / hs;
      double sw = c0;
      MFREE_UNROLL
      for (int c = 0; c < D; ++c) sw *= ih;
      const double swih = sw * ih;
      const double *d0 = d[0], *d1 = d[D > 1 ? 1 : 0], *d2 = d[D > 2 ? 2 : 0];
      double nz = 0.0;  // a double count, so that the loop has one lane width
      MFREE_SIMD_SUM(nz)
      for (int j = 0; j < n; ++j) {
        double r2 = d0[j] * d0[j];
        if (D > 1) r2 += d1[j] * d1[j];
        if (D > 2) r2 += d2[j] * d2[j];
        const double r = std::sqrt(r2), q = r * ih;
        const double wv = sw * Kern::f(q), df = Kern::df(q);
        wt[j] = wv;
        nz += wv != 0.0 ? 1.0 : 0.0;
        if (G) {
          const double rs = r > 0.0 ? r : 1.0, rm = r > 0.0 ? 1.0 : 0.0;
          gf[j] = rm * (-(swih * df) / rs);
        }
      }
      return static_cast<int>(nz);
    }
  }
  const int conv = t.convention;
  for (int j = 0; j < n; ++j) {
    const double hj = t.h[cl[j] * ps];
    const double h = conv == MFREE_SEARCH_SYMMETRIC_MAX    ? std::max(hs, hj)
                     : conv == MFREE_SEARCH_SYMMETRIC_MEAN ? 0.5 * (hs + hj)
                                                           : hs;
    const double ih = 1.0 / h;
    double sw = c0;
    MFREE_UNROLL
    for (int c = 0; c < D; ++c) sw *= ih;
    double r2 = 0.0;
    MFREE_UNROLL
    for (int c = 0; c < D; ++c) r2 += d[c][j] * d[c][j];
    const double r = std::sqrt(r2);
    double f, df;
    K(r * ih, f, df);
    const double wv = sw * f;
    wt[j] = wv;
    support += wv != 0.0;
    if (G) gf[j] = r > 0.0 ? -(sw * ih * df) / r : 0.0;
  }
  return support;
}

// Output rows of one site.
struct Rows {
  double *val, *grad;
};

// Difference form: the site's own gradient entry is minus the sum of the others.
template <int D>
void close_difference(double *grad, int n, int self) {
  double sum[D] = {};
  for (int j = 0; j < n; ++j)
    if (j != self)
      MFREE_UNROLL
      for (int c = 0; c < D; ++c) sum[c] += grad[j * D + c];
  MFREE_UNROLL
  for (int c = 0; c < D; ++c) grad[self * D + c] = -sum[c];
}

template <int D>
int sph(FastScratch &w, int n, Rows o, int self) {
  const double *wt = w.w(), *gf = w.gf(), *v = w.v();
  if (o.val)
    for (int j = 0; j < n; ++j) o.val[j] = wt[j] * v[j];
  if (o.grad) {
    for (int j = 0; j < n; ++j) {
      const double gv = gf[j] * v[j];
      MFREE_UNROLL
      for (int c = 0; c < D; ++c) o.grad[j * D + c] = gv * w.d(c)[j];
    }
    if (self >= 0) close_difference<D>(o.grad, n, self);
  }
  return 0;
}

// Shepard functions into scratch a (values) and b(c) (gradients).
template <int D>
int shepard(FastScratch &w, int n) {
  const double *wt = w.w(), *gf = w.gf();
  double S = 0.0, gS[D] = {};
  for (int j = 0; j < n; ++j) {
    S += wt[j];
    MFREE_UNROLL
    for (int c = 0; c < D; ++c) gS[c] += gf[j] * w.d(c)[j];
  }
  if (!(S > 0.0)) return MFREE_FAIL_NEIGHBORS;
  const double iS = 1.0 / S;
  double *phi = w.a();
  for (int j = 0; j < n; ++j) phi[j] = wt[j] * iS;
  MFREE_UNROLL
  for (int c = 0; c < D; ++c) {
    const double *dc = w.d(c);
    double *g = w.b(c);
    for (int j = 0; j < n; ++j) g[j] = gf[j] * dc[j] * iS - wt[j] * gS[c] * iS * iS;
  }
  return 0;
}

template <int D>
void write_shepard(FastScratch &w, int n, Rows o) {
  if (o.val) std::copy(w.a(), w.a() + n, o.val);
  if (o.grad)
    for (int j = 0; j < n; ++j)
      MFREE_UNROLL
      for (int c = 0; c < D; ++c) o.grad[j * D + c] = w.b(c)[j];
}

// Randles-Libersky (q_j = grad w_j V_j, difference form) and Krongauz-Belytschko
// Method 1 (q_j = grad phi^S_j): A_ab = sum_j d_ja q_jb, corrected gradient A^-T q_j.
template <int D>
int corrected(FastScratch &w, int n, Rows o, int self, bool rl, double &cond) {
  const double *d[3] = {w.d(0), w.d(1), w.d(2)};
  const double *gf = w.gf(), *v = w.v();
  double *gv = w.a();  // RL: q_j = gv_j d_j with gv = gf V
  const double *q[3] = {w.b(0), w.b(1), w.b(2)};
  double acc[D][D] = {};
  if (rl) {
    // A_ab = sum_j gv_j d_ja d_jb is symmetric
    double s[D * D] = {};
    for (int j = 0; j < n; ++j) {
      const double g = gf[j] * v[j];
      gv[j] = g;
      MFREE_UNROLL
      for (int a = 0; a < D; ++a) {
        const double ga = g * d[a][j];
        MFREE_UNROLL
        for (int b = 0; b < D; ++b)
          if (b <= a) s[a * D + b] += ga * d[b][j];
      }
    }
    MFREE_UNROLL
    for (int a = 0; a < D; ++a) {
      MFREE_UNROLL
      for (int b = 0; b < D; ++b) acc[a][b] = b <= a ? s[a * D + b] : s[b * D + a];
    }
  } else {
    const int st = shepard<D>(w, n);
    if (st) return st;
    double s[D * D] = {};
    for (int j = 0; j < n; ++j) {
      MFREE_UNROLL
      for (int a = 0; a < D; ++a) {
        MFREE_UNROLL
        for (int b = 0; b < D; ++b) s[a * D + b] += d[a][j] * q[b][j];
      }
    }
    MFREE_UNROLL
    for (int a = 0; a < D; ++a) {
      MFREE_UNROLL
      for (int b = 0; b < D; ++b) acc[a][b] = s[a * D + b];
    }
  }
  double X[D][D];
  if (!gen_inverse<D>(acc, X, cond)) return MFREE_FAIL_SINGULAR;
  if (o.val) {
    if (rl)
      for (int j = 0; j < n; ++j) o.val[j] = w.w()[j] * v[j];
    else
      std::copy(w.a(), w.a() + n, o.val);
  }
  if (o.grad) {
    double *g = o.grad;
    if (rl) {
      for (int j = 0; j < n; ++j) {
        MFREE_UNROLL
        for (int c = 0; c < D; ++c) {
          double t = 0.0;
          MFREE_UNROLL
          for (int b = 0; b < D; ++b) t += X[b][c] * d[b][j];
          g[j * D + c] = gv[j] * t;
        }
      }
      close_difference<D>(g, n, self);
    } else {
      for (int j = 0; j < n; ++j) {
        MFREE_UNROLL
        for (int c = 0; c < D; ++c) {
          double t = 0.0;
          MFREE_UNROLL
          for (int b = 0; b < D; ++b) t += X[b][c] * q[b][j];
          g[j * D + c] = t;
        }
      }
    }
  }
  return 0;
}

// Johnson-Beissel: grad_c = grad_c w_j V_j / sum_j grad_c w_j V_j d_jc, difference form.
template <int D>
int johnson_beissel(FastScratch &w, int n, Rows o, int self) {
  const double *wt = w.w(), *gf = w.gf(), *v = w.v();
  double beta[D];
  if (o.grad)
    MFREE_UNROLL
    for (int c = 0; c < D; ++c) {
      const double *dc = w.d(c);
      double den = 0.0;
      for (int j = 0; j < n; ++j) den += gf[j] * dc[j] * v[j] * dc[j];
      if (!(std::fabs(den) > 0.0)) return MFREE_FAIL_SINGULAR;
      beta[c] = 1.0 / den;
    }
  if (o.val)
    for (int j = 0; j < n; ++j) o.val[j] = wt[j] * v[j];
  if (o.grad) {
    for (int j = 0; j < n; ++j)
      MFREE_UNROLL
      for (int c = 0; c < D; ++c) o.grad[j * D + c] = beta[c] * gf[j] * w.d(c)[j] * v[j];
    close_difference<D>(o.grad, n, self);
  }
  return 0;
}

// MLS (weights w) and RKPM (weights w V) of order K with true derivatives (local.cpp
// mls_fixed): M gamma = p(0), M gamma_,i = e_i / hs - M_,i gamma,
// Phi_j = w_j gamma . p_j, Phi_j,i = w_j gamma_,i . p_j + w_j,i gamma . p_j.
template <int D, int K>
int mls(FastScratch &w, int n, int support, double hs, Rows o, bool rkpm, double &cond) {
  using T = Tab<D, K>;
  constexpr const T &tab = kTab<D, K>;
  constexpr int L = T::L;
  if (support < L) return MFREE_FAIL_NEIGHBORS;
  double *wt = w.w(), *gf = w.gf();
  const bool deriv = o.grad != nullptr;
  if (rkpm) {
    const double *v = w.v();
    for (int j = 0; j < n; ++j) wt[j] *= v[j];
    if (deriv)
      for (int j = 0; j < n; ++j) gf[j] *= v[j];
  }
  const double ih = 1.0 / hs;
  const double *d[3] = {w.d(0), w.d(1), w.d(2)};
  double aw[T::PM] = {}, ag[T::PM] = {};
  for (int j = 0; j < n; ++j) {
    double s[D];
    MFREE_UNROLL
    for (int c = 0; c < D; ++c) s[c] = d[c][j] * ih;
    double mo[T::PM];
    if (deriv) {
      monomials<D, K, T::NM, T::PM>(s, mo);
      const double wj = wt[j], gj = gf[j];
      MFREE_UNROLL
      for (int m = 0; m < T::PW; ++m) aw[m] += wj * mo[m];
      MFREE_UNROLL
      for (int m = 0; m < T::PM; ++m) ag[m] += gj * mo[m];
    } else {
      monomials<D, K, T::NW, T::PW>(s, mo);
      const double wj = wt[j];
      MFREE_UNROLL
      for (int m = 0; m < T::PW; ++m) aw[m] += wj * mo[m];
    }
  }
  double M[L][L], X[L][L];
  MFREE_UNROLL
  for (int a = 0; a < L; ++a)
    for (int b = 0; b < L; ++b) M[a][b] = aw[tab.mw[a][b]];
  if (!spd_inverse<L>(M, X, cond)) return MFREE_FAIL_SINGULAR;
  double g[L], gi[D][L];
  MFREE_UNROLL
  for (int a = 0; a < L; ++a) g[a] = X[a][0];
  if (deriv)
    MFREE_UNROLL
    for (int i = 0; i < D; ++i) {
      double rhs[L];
      MFREE_UNROLL
      for (int a = 0; a < L; ++a) {
        double t = 0.0;
        MFREE_UNROLL
        for (int b = 0; b < L; ++b) t += ag[tab.mg[i][a][b]] * g[b];
        rhs[a] = -hs * t;
      }
      if (1 + i < L) rhs[1 + i] += ih;
      MFREE_UNROLL
      for (int a = 0; a < L; ++a) {
        double t = 0.0;
        MFREE_UNROLL
        for (int b = 0; b < L; ++b) t += X[a][b] * rhs[b];
        gi[i][a] = t;
      }
    }
  for (int j = 0; j < n; ++j) {
    double s[D], p[L];
    MFREE_UNROLL
    for (int c = 0; c < D; ++c) s[c] = d[c][j] * ih;
    monomials<D, K, L, L>(s, p);
    double gp = 0.0;
    MFREE_UNROLL
    for (int a = 0; a < L; ++a) gp += g[a] * p[a];
    if (o.val) o.val[j] = wt[j] * gp;
    if (deriv)
      MFREE_UNROLL
      for (int i = 0; i < D; ++i) {
        double t = 0.0;
        MFREE_UNROLL
        for (int a = 0; a < L; ++a) t += gi[i][a] * p[a];
        o.grad[j * D + i] = wt[j] * t + gf[j] * d[i][j] * gp;
      }
  }
  return 0;
}

// SSPH of order K (001 eqs 3.3-3.10): K = sum W V p p^T, value (K^-1 p_j)_0 W_j V_j,
// gradient (K^-1 p_j)_{e_i} W_j V_j / hs; the kernel is not differentiated.
template <int D, int K>
int ssph(FastScratch &w, int n, int support, double hs, Rows o, double &cond) {
  using T = Tab<D, K>;
  constexpr const T &tab = kTab<D, K>;
  constexpr int L = T::L;
  if (support < L) return MFREE_FAIL_NEIGHBORS;
  double *om = w.w();
  const double *v = w.v();
  for (int j = 0; j < n; ++j) om[j] *= v[j];
  const double ih = 1.0 / hs;
  const double *d[3] = {w.d(0), w.d(1), w.d(2)};
  double aw[T::PW] = {};
  for (int j = 0; j < n; ++j) {
    double s[D], mo[T::PW];
    MFREE_UNROLL
    for (int c = 0; c < D; ++c) s[c] = d[c][j] * ih;
    monomials<D, K, T::NW, T::PW>(s, mo);
    const double oj = om[j];
    MFREE_UNROLL
    for (int m = 0; m < T::PW; ++m) aw[m] += oj * mo[m];
  }
  double M[L][L], X[L][L];
  MFREE_UNROLL
  for (int a = 0; a < L; ++a)
    for (int b = 0; b < L; ++b) M[a][b] = aw[tab.mw[a][b]];
  if (!spd_inverse<L>(M, X, cond)) return MFREE_FAIL_SINGULAR;
  for (int j = 0; j < n; ++j) {
    double s[D], p[L];
    MFREE_UNROLL
    for (int c = 0; c < D; ++c) s[c] = d[c][j] * ih;
    monomials<D, K, L, L>(s, p);
    if (o.val) {
      double t = 0.0;
      MFREE_UNROLL
      for (int a = 0; a < L; ++a) t += X[0][a] * p[a];
      o.val[j] = om[j] * t;
    }
    if (o.grad)
      MFREE_UNROLL
      for (int i = 0; i < D; ++i) {
        double t = 0.0;
        MFREE_UNROLL
        for (int a = 0; a < L; ++a) t += X[1 + i][a] * p[a];
        o.grad[j * D + i] = ih * om[j] * t;
      }
  }
  return 0;
}

template <int D>
int mls_order(int order, FastScratch &w, int n, int support, double hs, Rows o, bool rkpm, double &cond) {
  switch (order) {
    case 0: return mls<D, 0>(w, n, support, hs, o, rkpm, cond);
    case 1: return mls<D, 1>(w, n, support, hs, o, rkpm, cond);
    default: return mls<D, 2>(w, n, support, hs, o, rkpm, cond);
  }
}

template <int D, class Kern>
int site_fn(const FastPath &fp, const FastTables &t, int32_t s, FastScratch &w, int &support,
            double &cond) {
  const int64_t k0 = t.rowptr[s];
  const int n = static_cast<int>(t.rowptr[s + 1] - k0);
  const int m = fp.method();
  Rows o{t.val ? t.val + k0 : nullptr, t.grad ? t.grad + k0 * D : nullptr};
  const bool corr = m == MFREE_METHOD_RANDLES_LIBERSKY || m == MFREE_METHOD_KB_METHOD1;
  const bool need_grad = m != MFREE_METHOD_SSPH && (o.grad || corr);
  support = need_grad ? gather<D, Kern, true>(fp, t, s, w, n) : gather<D, Kern, false>(fp, t, s, w, n);
  cond = 1.0;
  const double hs = t.sh[s * t.sstride];
  const int self = t.self[s];
  switch (m) {
    case MFREE_METHOD_SPH:
      if (support < 1) return MFREE_FAIL_NEIGHBORS;
      return sph<D>(w, n, o, -1);
    case MFREE_METHOD_SPH_SYMMETRIC:
      if (support < 1) return MFREE_FAIL_NEIGHBORS;
      return sph<D>(w, n, o, self);
    case MFREE_METHOD_SHEPARD: {
      const int st = shepard<D>(w, n);
      if (!st) write_shepard<D>(w, n, o);
      return st;
    }
    case MFREE_METHOD_JOHNSON_BEISSEL:
      if (support < 2) return MFREE_FAIL_NEIGHBORS;
      return johnson_beissel<D>(w, n, o, self);
    case MFREE_METHOD_RANDLES_LIBERSKY:
    case MFREE_METHOD_KB_METHOD1:
      if (support < D + 1) return MFREE_FAIL_NEIGHBORS;
      return corrected<D>(w, n, o, self, m == MFREE_METHOD_RANDLES_LIBERSKY, cond);
    case MFREE_METHOD_MLS:
    case MFREE_METHOD_RKPM:
      return mls_order<D>(fp.order(), w, n, support, hs, o, m == MFREE_METHOD_RKPM, cond);
    case MFREE_METHOD_SSPH:
      if (fp.order() == 1) return ssph<D, 1>(w, n, support, hs, o, cond);
      return ssph<D, 2>(w, n, support, hs, o, cond);
    default:
      return MFREE_FAIL_SINGULAR;
  }
}

}  // namespace

void FastScratch::reserve(int maxrow) {
  if (maxrow <= cap) return;
  cap = maxrow;
  buf.assign(static_cast<size_t>(cap) * 10, 0.0);
}

FastPath::FastPath(int dim, int method, int order, const Kernel &kernel, int flags)
    : method_(method), order_(order), kernel_(&kernel) {
  if (flags & MFREE_DERIV_HESSIAN) return;
  if (dim < 1 || dim > 3) return;
  // LDL^T without pivoting needs non-negative weights
  const int k = kernel.id();
  if (k == MFREE_KERNEL_SUPER_GAUSS || k == MFREE_KERNEL_REVISED_SUPER_GAUSS) return;
  switch (method) {
    case MFREE_METHOD_SPH:
    case MFREE_METHOD_SPH_SYMMETRIC:
    case MFREE_METHOD_SHEPARD:
    case MFREE_METHOD_JOHNSON_BEISSEL:
    case MFREE_METHOD_RANDLES_LIBERSKY:
    case MFREE_METHOD_KB_METHOD1:
      break;
    case MFREE_METHOD_MLS:
    case MFREE_METHOD_RKPM:
      if (order < 0 || order > 2) return;
      break;
    case MFREE_METHOD_SSPH:
      if (order < 1 || order > 2) return;
      break;
    default:
      return;
  }
  const bool cubic = k == MFREE_KERNEL_CUBIC_SPLINE;
  switch (dim) {
    case 1: fn_ = cubic ? &site_fn<1, CubicSpline> : &site_fn<1, AnyShape>; break;
    case 2: fn_ = cubic ? &site_fn<2, CubicSpline> : &site_fn<2, AnyShape>; break;
    default: fn_ = cubic ? &site_fn<3, CubicSpline> : &site_fn<3, AnyShape>; break;
  }
}

}  // namespace mfree
