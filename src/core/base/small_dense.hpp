// Small dense solves of the local systems (moment matrices, correction matrices): the one
// condition threshold and condition rule of the library, the one pivoted LDL^T of
// symmetric positive definite matrices, Gauss-Jordan with partial pivoting of general
// ones, and the 2x2 and 3x3 closed forms.
//
// The condition rule: rc = min(1 / (||A||_1 ||A^-1||_1), ratio of the smallest to the
// largest |pivot| of the pivoted factorisation that solved A); the system is singular
// when rc < kMinRcond, and its condition number is reported as 1 / rc. The 1-norm
// product alone is blind to an exactly zero pivot (it is 1 for [[1,0],[0,0]] when the
// solve does not overflow), hence the pivot ratio. The fixed-size inverses below apply
// it with the 1-norm of their explicit inverse; the reference path (shape/local.cpp)
// applies it to Eigen's factorisations (see there why it keeps them).
//
// The fixed-size functions are always inlined so that every caller compiles them for its
// own target (the fast path's AVX2 + FMA copy included, simd.hpp): a caller that wants
// one out-of-line instance per copy wraps them in a function of its own region.
#pragma once

#include <algorithm>
#include <cmath>
#include <utility>

#include "core/base/simd.hpp"

// (the same definition as the fast path's: fully unrolled loops of compile-time length)
#ifndef MFREE_UNROLL
#define MFREE_UNROLL _Pragma("GCC unroll 64")
#endif

namespace mfree {
namespace dense {

// A local system whose reciprocal condition number is below this is singular.
constexpr double kMinRcond = 1e-12;

// 1 / (||A||_1 ||A^-1||_1) of an L x L matrix from the two norms; 0 for a zero matrix,
// 1 for L = 1 (a positive 1 x 1 system is perfectly conditioned).
MFREE_ALWAYS_INLINE double rcond_from_norms(double anorm, double xnorm, int L) {
  if (anorm == 0.0) return 0.0;
  if (L == 1) return 1.0;
  return xnorm == 0.0 ? 0.0 : (1.0 / xnorm) / anorm;
}

// The smallest over the largest |pivot| of L pivots (0 when all are zero).
MFREE_ALWAYS_INLINE double pivot_ratio(const double *piv, int L) {
  double big = 0.0, small = INFINITY;
  for (int k = 0; k < L; ++k) {
    big = std::max(big, std::fabs(piv[k]));
    small = std::min(small, std::fabs(piv[k]));
  }
  return big > 0.0 ? small / big : 0.0;
}

// The condition rule (top of this file): cond = 1 / rc, true when the system is regular.
MFREE_ALWAYS_INLINE bool condition_ok(double rc_norms, double pivots, double &cond) {
  double rc = std::isfinite(rc_norms) ? rc_norms : 0.0;
  rc = std::min(rc, pivots);
  cond = rc > 0.0 ? 1.0 / rc : INFINITY;
  return rc >= kMinRcond;
}

// ||A||_1, the largest column sum of |A|.
template <int L>
MFREE_ALWAYS_INLINE double norm1(const double (&A)[L][L]) {
  double big = 0.0;
  MFREE_UNROLL
  for (int b = 0; b < L; ++b) {
    double s = 0.0;
    MFREE_UNROLL
    for (int a = 0; a < L; ++a) s += std::fabs(A[a][b]);
    big = std::max(big, s);
  }
  return big;
}

// The condition rule for an explicit inverse X of A (matrix_norm = ||A||_1) and the
// pivots of the factorisation that gave it.
template <int L>
MFREE_ALWAYS_INLINE bool accept(double matrix_norm, const double (&X)[L][L], const double *piv,
                                double &cond) {
  // (||A^-1||_1 is exact here: one column sum of the explicit inverse)
  const double xnorm = (matrix_norm == 0.0 || L == 1) ? 0.0 : norm1<L>(X);
  return condition_ok(rcond_from_norms(matrix_norm, xnorm, L), pivot_ratio(piv, L), cond);
}

// Symmetric positive definite A (moment matrices of non-negative weights): LDL^T with
// Eigen's diagonal pivoting (largest remaining original diagonal first, so that the pivots
// and the condition number are those of Eigen::LDLT to round-off), X = A^-1. False when a
// pivot is not positive or the condition rule fails.
template <int L>
MFREE_ALWAYS_INLINE bool spd_inverse(const double (&A)[L][L], double (&X)[L][L], double &cond) {
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
// pivots of Eigen's PartialPivLU), X = A^-1.
template <int L>
MFREE_ALWAYS_INLINE bool gen_inverse(const double (&A)[L][L], double (&X)[L][L], double &cond) {
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

// The 2x2 inverse in closed form, with gen_inverse's singularity test and condition
// number: 1 / min(1 / (||A||_1 ||A^-1||_1), pivot ratio of partial pivoting), the pivots
// being big = max(|A00|, |A10|) and |det| / big, is |det|^-1 max(||A||_1 ||adj A||_1, big^2).
MFREE_ALWAYS_INLINE bool inverse2(const double (&A)[2][2], double (&X)[2][2], double &cond) {
  const double a = A[0][0], b = A[0][1], c = A[1][0], d = A[1][1];
  const double id = 1.0 / (a * d - b * c);
  X[0][0] = d * id;
  X[0][1] = -b * id;
  X[1][0] = -c * id;
  X[1][1] = a * id;
  const double fa = std::fabs(a), fb = std::fabs(b), fc = std::fabs(c), fd = std::fabs(d);
  const double big = std::max(fa, fc);
  const double an = std::max(fa + fc, fb + fd), adj = std::max(fd + fc, fb + fa);
  cond = std::fabs(id) * std::max(an * adj, big * big);
  return cond <= 1.0 / kMinRcond;  // false for inf and NaN (a zero determinant)
}

// The adjugate C of a 3x3 matrix (A C = det(A) I); returns det(A), expanded along the
// first row.
MFREE_ALWAYS_INLINE double adjugate3(const double (&A)[3][3], double (&C)[3][3]) {
  C[0][0] = A[1][1] * A[2][2] - A[1][2] * A[2][1];
  C[1][0] = A[1][2] * A[2][0] - A[1][0] * A[2][2];
  C[2][0] = A[1][0] * A[2][1] - A[1][1] * A[2][0];
  C[0][1] = A[0][2] * A[2][1] - A[0][1] * A[2][2];
  C[1][1] = A[0][0] * A[2][2] - A[0][2] * A[2][0];
  C[2][1] = A[0][1] * A[2][0] - A[0][0] * A[2][1];
  C[0][2] = A[0][1] * A[1][2] - A[0][2] * A[1][1];
  C[1][2] = A[0][2] * A[1][0] - A[0][0] * A[1][2];
  C[2][2] = A[0][0] * A[1][1] - A[0][1] * A[1][0];
  return A[0][0] * C[0][0] + A[0][1] * C[1][0] + A[0][2] * C[2][0];
}

// The 3x3 inverse of a symmetric A in closed form (adjugate over determinant), with
// spd_inverse's verdict and condition number: positive definite by the leading minors
// (Sylvester; the LDL^T pivots up to rounding), cond = ||A||_1 ||A^-1||_1 exactly. That is
// the whole condition rule here: for symmetric A the pivot ratio of LDL^T is at most the
// 2-norm condition number (the pivots lie between the extreme eigenvalues), which is at
// most the 1-norm one. False when A is not positive definite or the rule fails.
MFREE_ALWAYS_INLINE bool spd_inverse3(const double (&A)[3][3], double (&X)[3][3], double &cond) {
  double C[3][3];
  const double det = adjugate3(A, C);
  cond = 1.0;
  if (!(A[0][0] > 0.0 && C[2][2] > 0.0 && det > 0.0)) return false;
  const double id = 1.0 / det;
  cond = norm1<3>(A) * norm1<3>(C) * id;
  if (!(std::isfinite(cond) && cond > 0.0 && 1.0 / cond >= kMinRcond)) return false;
  MFREE_UNROLL
  for (int a = 0; a < 3; ++a) {
    MFREE_UNROLL
    for (int b = 0; b < 3; ++b) X[a][b] = C[a][b] * id;
  }
  return true;
}

// The 3x3 inverse in closed form (adjugate over determinant), with gen_inverse's
// singularity test and condition number: the pivots of partial pivoting (first largest
// |entry| of the column, in gen_inverse's row order after the swap) from the first
// column and the 2x2 Schur complement, branch-free; cond = max(||A||_1 ||A^-1||_1,
// largest / smallest pivot). A zero pivot or determinant gives inf or NaN: false.
MFREE_ALWAYS_INLINE bool inverse3(const double (&A)[3][3], double (&X)[3][3], double &cond) {
  double C[3][3];
  const double id = 1.0 / adjugate3(A, C);
  MFREE_UNROLL
  for (int a = 0; a < 3; ++a) {
    MFREE_UNROLL
    for (int b = 0; b < 3; ++b) X[a][b] = C[a][b] * id;
  }
  // first pivot: row p of the largest |A_i0| (the first on ties); the other two rows in
  // gen_inverse's order after swapping rows 0 and p: (1, 2), (0, 2) or (1, 0)
  const double a0 = std::fabs(A[0][0]), a1 = std::fabs(A[1][0]), a2 = std::fabs(A[2][0]);
  const int p = a2 > std::max(a0, a1) ? 2 : (a1 > a0 ? 1 : 0);
  const int ra = p == 0 ? 1 : (p == 1 ? 0 : 1), rb = p == 2 ? 0 : 2;
  const double u0 = A[p][0], ip = 1.0 / u0;
  const double n1 = A[p][1] * ip, n2 = A[p][2] * ip;  // the normalised pivot row
  const double sa1 = A[ra][1] - A[ra][0] * n1, sa2 = A[ra][2] - A[ra][0] * n2;
  const double sb1 = A[rb][1] - A[rb][0] * n1, sb2 = A[rb][2] - A[rb][0] * n2;
  // second pivot: the larger |Schur entry| of column 1 (row a on ties), third: the rest
  const bool swap = std::fabs(sb1) > std::fabs(sa1);
  const double u1 = swap ? sb1 : sa1, v1 = swap ? sa1 : sb1;
  const double w1 = swap ? sb2 : sa2, w2 = swap ? sa2 : sb2;
  const double u2 = w2 - v1 * (w1 / u1);
  const double f0 = std::fabs(u0), f1 = std::fabs(u1), f2 = std::fabs(u2);
  const double big = std::max(f0, std::max(f1, f2)), small = std::min(f0, std::min(f1, f2));
  cond = std::max(norm1<3>(A) * norm1<3>(X), big / small);
  return cond <= 1.0 / kMinRcond;  // false for inf and NaN
}

// The inverse of a D x D general matrix: the closed forms for D = 2, 3.
template <int D>
MFREE_ALWAYS_INLINE bool small_inverse(const double (&A)[D][D], double (&X)[D][D], double &cond) {
  if constexpr (D == 2) return inverse2(A, X, cond);
  else if constexpr (D == 3) return inverse3(A, X, cond);
  else return gen_inverse<D>(A, X, cond);
}

}  // namespace dense
}  // namespace mfree
