// The finite-element layer along the essential boundary (paper 000 eqs 100-105): 2D
// elements (TRI3 or QUAD4, from shape/fe_shape.hpp) over the particles next to the
// boundary, whose functions replace the meshfree ones on the boundary and blend into
// them across the layer, so that essential conditions hold at the boundary nodes.
#pragma once

#include <cstdint>

#include "core/base/alloc.hpp"
#include "core/discretize/qtable.hpp"
#include "core/particles/particles.hpp"

namespace mfree {

class FeLayer {
 public:
  explicit FeLayer(const ParticleSet *ps) : ps_(ps) {}
  // Nodes per element: 3 (triangles) or 4 (quadrilaterals); 0: no layer.
  int npe() const { return npe_; }
  // The checks of add's arguments that need no particle data, for callers that order
  // them among their own.
  static void check_arguments(int32_t nelem, int32_t npe, const int32_t *conn, int32_t ngu, const int32_t *gu);
  // Adds nelem elements (conn: npe owned particles each, counter-clockwise) and the
  // essential-boundary nodes gu (layer nodes) to the layer; calls accumulate into one
  // layer. Throws, leaving the layer as it was, on invalid input.
  void add(int32_t nelem, int32_t npe, const int32_t *conn, int32_t ngu, const int32_t *gu);
  // Functions of element e at x: N[npe], gradients dN[2 npe]; false if x is outside.
  bool shape(int32_t e, const double *x, double *N, double *dN) const;
  // Blends the rows of t at the points pts (NULL: the particles, nodal quadrature) with
  // the layer's functions.
  void blend(QTable &t, const HVec<double> *pts) const;

 private:
  const ParticleSet *ps_;
  int npe_ = 0;
  HVec<int32_t> conn_;       // nelem * npe particle indices
  HVec<char> on_gu_;         // per particle: node on the essential boundary
  HVec<char> in_layer_;      // per particle: node of some layer element
  HVec<double> bmin_, bmax_;  // element bounding boxes
};

}  // namespace mfree
