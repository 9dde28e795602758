// Cell-list neighbour search with variable support, three conventions, periodic axes.
//
// Cells have edge >= half the mean search radius (a quarter along x, where a stencil
// row is one contiguous range and finer cells only trim it); a query with radius R
// scans the cells within R (gather: kappa h_i; symmetric-max: kappa max_j h_j, filtered
// by max(h_i, h_j); symmetric-mean: kappa (h_i + max h)/2, filtered by the mean), so
// uniform supports cost a 9 x 5^(dim-1) stencil and strongly variable ones stay correct.
// The same grid answers queries from the particles themselves and from host points.
//
// Speed: the particles are counting-sorted by cell (row-major cell order, x fastest;
// per-thread histograms, so the sort is parallel and its result does not depend on the
// thread count) and their coordinates and radii copied in that order (SoA), so that
// the cells of one stencil row are one contiguous range scanned by a branch-free loop.
// Queries run in cell order too (neighbouring queries share cache lines), in static
// blocks over the context's threads, each into its own buffer; the rows are then placed
// by host index. The permutation never leaves this file: rows hold host indices, sorted
// ascending -- for a symmetric relation by transposing the unsorted rows (no
// comparisons, see run_queries), otherwise by sorting each row. A particle set keeps
// the grid and the buffers between searches (NeighborScratch), so a repeated search
// allocates nothing and touches no new pages once the sizes have settled.
//
// On one thread with AVX2 and particles stored in spatial order (lattice, curve), the
// rows are instead found in host order and written sorted straight into the lists
// (host_order_rows): no buffers, the fewest fresh pages for the first search of a set.
// There, 2D and 3D gather searches without periodic axes scan four candidates a step
// (AVX2, query_avx2).
// Either way the lists are the same sets, sorted: the same bits.
//
// The search is one translation unit in five parts, by algorithm: the cell grid
// (neighbors_cell_grid.inc) and its queries (neighbors_cell_grid_scan.inc), the general
// queries (neighbors_general.inc), the host-order queries (neighbors_host_order.inc) and
// the Verlet skin's reuse of candidate lists (neighbors_verlet.inc); this file holds the
// search's buffers and its two entry points, which choose between them. One unit, because the parts share the grid's types and the compiler inlines the
// grid's queries into the query loops of both kinds; as separate units the grid would
// need external linkage and those decisions could change.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>
#include <type_traits>
#include <utility>

#include "core/particles/neighbors.hpp"
#include "core/base/kernel.hpp"
#include "core/base/parallel.hpp"
#include "core/particles/particles.hpp"
#include "core/particles/pair_test.hpp"
#include "core/base/simd.hpp"

#include "core/particles/neighbors_cell_grid.inc"
#include "core/particles/neighbors_cell_grid_scan.inc"

namespace mfree {

// The Verlet skin's candidate lists (neighbors_verlet.inc) and what they were built from.
struct VerletLists {
  Csr cand;            // rows of radius kappa h + skin at the build, sorted by index
  Buf<double> x0;      // positions at the build, dim per particle
  Buf<double> r0;      // search radii kappa h at the build
  Buf<int32_t> stat0;  // particle statuses at the build
  double x0abs = 0.0;  // largest |coordinate| in x0
  HVec<int32_t> tmp;   // filtered rows, block by block, before they are placed
  bool built = false;  // cand holds for the settings below
  bool used = false;   // the last search's rows came from cand
  bool left = false;   // ... and were left to the caller (ParticleSet::set_rows_left)
  // the settings cand was built under (another value rebuilds)
  int32_t n = -1, owned = -1;
  int conv = -1;
  double skin = 0.0;
  bool periodic[3] = {false, false, false};
  double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
};

// Buffers of a search, kept by a particle set between searches (sizes settle after the
// first; a repeated search then allocates nothing), or local to one host-point search.
struct NeighborScratch {
  CellGrid grid;
  Buf<int32_t> order;
  RowBuf buf[64];
  RowBuf row[64];  // one row at a time (host_order_blocks)
  Buf<int64_t> first, rowptr;
  Buf<int32_t> lo_hi;
  Buf<const int32_t *> src;
  Csr next;  // the lists host_order_blocks writes, then swaps with the set's
  VerletLists verlet;
  int64_t searches = 0;  // completed searches of the set's rows or candidates
};

NeighborScratch *new_neighbor_scratch() { return new NeighborScratch; }
void NeighborScratchDeleter::operator()(NeighborScratch *s) const { delete s; }

}  // namespace mfree

#include "core/particles/neighbors_general.inc"
#include "core/particles/neighbors_host_order.inc"

namespace mfree {

namespace {

// The rows of the owned particles with every search radius kappa h_i + pad.
void search_rows(const ParticleSet &ps, const std::vector<int32_t> &status, NeighborScratch &sc, Csr &out,
                 double pad) {
  const int32_t rows = ps.num_owned();
  sc.grid.build(ps, status, pad);
  const CellGrid &grid = sc.grid;
  const Rule rule{ps.search_convention(), grid.rmax()};
  // AVX2, particles stored in spatial order: in host order, on one thread straight into
  // out, on more through one buffer per thread. Not for Verlet candidates (pad > 0): their
  // longer rows (beyond the rank sort's 64 in 3D) sort faster by the cell-order queries'
  // transposition.
#if MFREE_SIMD_X86
  if (!grid.empty() && pad == 0.0 && simd::use_avx2() && grid.host_locality(ps.size()) >= 0.75) {
    const int nt = num_threads(ps.size());
    if (nt == 1) host_order_rows(grid, ps, status, rule, sc.buf[0], out);
    else host_order_blocks(grid, ps, status, rule, sc, out, nt);
    return;
  }
#endif
  // owned valid particles in cell order
  const int32_t *mem = grid.members();
  const int32_t nv = grid.num_valid();
  sc.order.resize(static_cast<size_t>(nv));
  if (rows == ps.size()) {  // no ghosts: every member owns a row
    const int nch = std::min(num_threads(nv), 64);
    int32_t *o = sc.order.data();
    for_chunks(nch, [&](int t) {
      int64_t b, e;
      thread_block(nv, t, nch, b, e);
      std::copy(mem + b, mem + e, o + b);
    });
  } else {
    int32_t no = 0;
    for (int32_t p = 0; p < nv; ++p)
      if (mem[p] < rows) sc.order[no++] = mem[p];
    sc.order.resize(static_cast<size_t>(no));
  }
  const int dim = ps.dim();
  // symmetric relation (see run_queries): every valid particle has a row (no ghosts), and
  // a symmetric convention or one radius for all
  const bool symmetric = rows == ps.size() && (rule.conv != MFREE_SEARCH_GATHER || grid.uniform());
  run_queries(sc, rule, rows, symmetric,
              [&](int32_t i, double *x) {
                for (int c = 0; c < dim; ++c) x[c] = grid.wrap(ps.x(i, c), c);
                return ps.kappa() * ps.h(i) + pad;  // (what the grid's radii were built from)
              },
              out);
}

}  // namespace
}  // namespace mfree

#include "core/particles/neighbors_verlet.inc"

namespace mfree {

void find_neighbors(const ParticleSet &ps, const std::vector<int32_t> &status, NeighborScratch &sc, Csr &out) {
  if (ps.search_skin() > 0.0) {
    verlet_rows(ps, status, sc, out);
    return;
  }
  sc.verlet.built = sc.verlet.used = sc.verlet.left = false;
  search_rows(ps, status, sc, out, 0.0);
  ++sc.searches;
}

const Csr *neighbor_candidates(const NeighborScratch &sc) { return sc.verlet.used ? &sc.verlet.cand : nullptr; }
int64_t neighbor_searches(const NeighborScratch &sc) { return sc.searches; }
bool neighbor_rows_left(const NeighborScratch &sc) { return sc.verlet.used && sc.verlet.left; }

void find_point_neighbors(const ParticleSet &ps, const std::vector<int32_t> &status, int32_t npts,
                          const VectorArray &x, const ScalarArray &h, Csr &out) {
  NeighborScratch sc;
  sc.grid.build(ps, status);
  const CellGrid &grid = sc.grid;
  const Rule rule{ps.search_convention(), grid.rmax()};
  const int dim = ps.dim();
  auto site = [&](int32_t s, double *xs) {
    for (int c = 0; c < dim; ++c) xs[c] = grid.wrap(x(s, c), c);
    return ps.kappa() * h(s);
  };
  // points in cell order (counting sort by the cell they fall in)
  sc.order.resize(static_cast<size_t>(npts));
  if (!grid.empty() && npts > 0) {
    const int64_t ncells = grid.num_cells();
    std::vector<int64_t> start(static_cast<size_t>(ncells) + 1, 0), cell(npts);
    for (int32_t s = 0; s < npts; ++s) {
      double xs[3] = {0, 0, 0};
      site(s, xs);
      cell[s] = grid.cell_of(xs);
      ++start[cell[s] + 1];
    }
    for (int64_t c = 0; c < ncells; ++c) start[c + 1] += start[c];
    for (int32_t s = 0; s < npts; ++s) sc.order[start[cell[s]]++] = s;
  }
  run_queries(sc, rule, npts, false, site, out);
  ps.order_rows_by_id(out);
}

}  // namespace mfree
