// Monomial bases s^alpha, |alpha| <= k, in shifted and scaled local coordinates
// s = (x_j - x) / h, ordered by degree; the paper-001 order inside degrees 0..2
// (1; s1, s2, s3; s1^2, s2^2, s3^2, s1 s2, s2 s3, s3 s1).
#pragma once

#include <array>

namespace mfree {

constexpr int kMaxBasis = 20;  // order 3 in 3D

class Basis {
 public:
  Basis() = default;
  Basis(int dim, int order);

  int dim() const { return dim_; }
  int order() const { return order_; }
  int size() const { return size_; }
  const std::array<int, 3> &alpha(int m) const { return alpha_[m]; }
  int degree(int m) const { return alpha_[m][0] + alpha_[m][1] + alpha_[m][2]; }
  // alpha! = prod alpha_i!
  double factorial(int m) const;

  // Index of the monomial s_i (degree 1) and s_i s_k (degree 2); -1 if absent.
  int linear(int i) const { return order_ >= 1 ? 1 + i : -1; }
  int quadratic(int i, int k) const;

  void eval(const double *s, double *p) const;

 private:
  int dim_ = 1, order_ = 0, size_ = 1;
  std::array<std::array<int, 3>, kMaxBasis> alpha_{};
};

// Number of packed Hessian entries and the packed index of (i, k).
inline int hessian_size(int dim) { return dim * (dim + 1) / 2; }
inline int hessian_index(int dim, int i, int k) {
  if (i > k) {
    const int t = i;
    i = k;
    k = t;
  }
  // rows of the upper triangle: row i starts at i*dim - i(i-1)/2
  return i * dim - i * (i - 1) / 2 + (k - i);
}

// Binomial(order + dim, dim): size of the complete basis.
int basis_size(int dim, int order);

}  // namespace mfree
