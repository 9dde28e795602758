// Variationally consistent integration (Chen, Hillman, Rueter, IJNME 93, 2013), second
// order: constant and linear corrections of the test gradients at the quadrature points.
#pragma once

#include "core/base/alloc.hpp"
#include "core/discretize/qtable.hpp"
#include "core/particles/particles.hpp"

namespace mfree {

// Corrects the gradients of the test functions in t (at the quadrature points) from their
// values in b at the boundary points, whose outward unit normals are `normals` (dim per
// point); the particles give each function's centre and support. Clears t.sgrad.
void correct_test_gradients(const ParticleSet &ps, QTable &t, const QTable &b, const HVec<double> &normals);

}  // namespace mfree
