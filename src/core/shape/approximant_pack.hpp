// The particle records of an approximant (Approximant::pack): shared by the pattern,
// the general path's site input and the fast path's tables.
#pragma once

#include <cstdint>

namespace mfree {

// Doubles per particle record of pack(): coordinates, volume and support, except in 3D:
// x y z vol (32 bytes, one aligned load per neighbour in the fast path, never split
// across cache lines), the supports in an array after the records.
constexpr int record_length(int dim) { return dim == 3 ? 4 : dim + 2; }
// Where pack() puts the n particles' supports in its block P: the support of particle
// i is h[i * stride] (after the records in 3D, inside them otherwise).
struct PackedSupports {
  double *h;
  int64_t stride;
};
inline PackedSupports packed_supports(double *P, int dim, int64_t n) {
  const int64_t S = record_length(dim);
  return S < dim + 2 ? PackedSupports{P + S * n, 1} : PackedSupports{P + dim + 1, S};
}

}  // namespace mfree
