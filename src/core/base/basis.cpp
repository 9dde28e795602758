#include "core/base/basis.hpp"

namespace mfree {

int basis_size(int dim, int order) {
  int num = 1, den = 1;
  for (int i = 1; i <= dim; ++i) {
    num *= order + i;
    den *= i;
  }
  return num / den;
}

Basis::Basis(int dim, int order) : dim_(dim), order_(order), size_(0) {
  auto push = [&](int a, int b, int c) { alpha_[size_++] = {a, b, c}; };
  push(0, 0, 0);
  if (order >= 1)
    for (int i = 0; i < dim; ++i) push(i == 0, i == 1, i == 2);
  if (order >= 2) {
    for (int i = 0; i < dim; ++i) push(2 * (i == 0), 2 * (i == 1), 2 * (i == 2));
    if (dim >= 2) push(1, 1, 0);
    if (dim >= 3) {
      push(0, 1, 1);
      push(1, 0, 1);
    }
  }
  for (int deg = 3; deg <= order; ++deg)
    for (int a = deg; a >= 0; --a)
      for (int b = (dim >= 2 ? deg - a : 0); b >= 0; --b) {
        const int c = deg - a - b;
        if (dim == 1 && (b || c)) continue;
        if (dim == 2 && c) continue;
        push(a, b, c);
      }
}

double Basis::factorial(int m) const {
  double f = 1.0;
  for (int c = 0; c < 3; ++c)
    for (int i = 2; i <= alpha_[m][c]; ++i) f *= i;
  return f;
}

int Basis::quadratic(int i, int k) const {
  if (order_ < 2) return -1;
  for (int m = 1 + dim_; m < size_; ++m) {
    const auto &a = alpha_[m];
    std::array<int, 3> want{0, 0, 0};
    ++want[i];
    ++want[k];
    if (a == want) return m;
  }
  return -1;
}

void Basis::eval(const double *s, double *p) const {
  // powers up to the order, then products
  double pw[3][4];
  for (int c = 0; c < 3; ++c) {
    pw[c][0] = 1.0;
    const double v = c < dim_ ? s[c] : 0.0;
    for (int e = 1; e <= 3; ++e) pw[c][e] = pw[c][e - 1] * v;
  }
  for (int m = 0; m < size_; ++m)
    p[m] = pw[0][alpha_[m][0]] * pw[1][alpha_[m][1]] * pw[2][alpha_[m][2]];
}

}  // namespace mfree
