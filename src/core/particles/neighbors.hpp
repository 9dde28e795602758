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
// the grid and buffers between calls. With a search skin (ps.search_skin() > 0) scratch
// also keeps candidate lists of radius kappa h + skin and the rows are filtered from
// them while they still hold every pair (neighbors_verlet.inc): the same rows as a
// fresh search.
NeighborScratch *new_neighbor_scratch();
void find_neighbors(const ParticleSet &ps, const std::vector<int32_t> &site_status, NeighborScratch &scratch,
                    Csr &out);
// The candidate lists the last find_neighbors filtered its rows from, or NULL when it
// searched without a skin.
const Csr *neighbor_candidates(const NeighborScratch &scratch);
// Searches find_neighbors completed with scratch (with a skin: builds of the candidates).
int64_t neighbor_searches(const NeighborScratch &scratch);
// Whether the last find_neighbors left its rows to the caller (out has empty rows; see
// ParticleSet::set_rows_left).
bool neighbor_rows_left(const NeighborScratch &scratch);

// Neighbours among the particles of ps for each host point (site support hp, the set's
// convention and kappa), skipping particles with a nonzero status.
void find_point_neighbors(const ParticleSet &ps, const std::vector<int32_t> &status,
                          int32_t npts, const VectorArray &x, const ScalarArray &h, Csr &out);

}  // namespace mfree
