// Neighbour search: the rows of a particle set's owned particles, and of host points,
// among its valid particles (neighbors.cpp: one cell grid, general and host-order
// queries).
#pragma once

#include <cstdint>
#include <vector>

#include "core/particles/particles.hpp"

namespace mfree {

// Cell-list search over the valid particles of ps (site_status[i] == 0); fills rows for
// the owned particles, sorted. Throws Error on a periodic box too small for the supports;
// on any exception out is unchanged, except when memory ran out after the one-thread
// search began to write it in place: out then has no rows (rowptr {0}). scratch holds
// the grid and buffers between calls.
NeighborScratch *new_neighbor_scratch();
void find_neighbors(const ParticleSet &ps, const std::vector<int32_t> &site_status, NeighborScratch &scratch,
                    Csr &out);

// Neighbours among the particles of ps for each host point (site support hp, the set's
// convention and kappa), skipping particles with a nonzero status.
void find_point_neighbors(const ParticleSet &ps, const std::vector<int32_t> &status,
                          int32_t npts, const VectorArray &x, const ScalarArray &h, Csr &out);

}  // namespace mfree
