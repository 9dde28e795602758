// Gauss–Legendre rules on [-1, 1].
#pragma once

#include <vector>

namespace mfree {

// n-point Gauss–Legendre nodes and weights on [-1, 1] (exact for degree 2n - 1).
void gauss_legendre(int n, std::vector<double> &nodes, std::vector<double> &weights);

}  // namespace mfree
