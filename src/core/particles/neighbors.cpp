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
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>
#include <type_traits>
#include <utility>

#include "core/shape/approximant.hpp"
#include "core/base/kernel.hpp"
#include "core/base/parallel.hpp"
#include "core/particles/particles.hpp"
#include "core/base/simd.hpp"

#if MFREE_SIMD_X86
#include <immintrin.h>
#endif

namespace mfree {

namespace {

// Row buffers are written before they are read: growing them need not zero the new
// entries (a value-initialising vector's memset was ~4 % of a 3D search). Storage comes
// from the context's allocator hook, like the lists themselves.
template <class T>
struct NoInitAlloc : HostAllocator<T> {
  template <class U>
  struct rebind {
    using other = NoInitAlloc<U>;
  };
  NoInitAlloc() = default;
  template <class U>
  NoInitAlloc(const NoInitAlloc<U> &) noexcept {}
  template <class U>
  void construct(U *p) noexcept {
    ::new (static_cast<void *>(p)) U;
  }
  template <class U, class... A>
  void construct(U *p, A &&...a) {
    ::new (static_cast<void *>(p)) U(std::forward<A>(a)...);
  }
};
template <class T>
using Buf = std::vector<T, NoInitAlloc<T>>;

// Resize a grid array (no initialisation); a new block is faulted in whole first
// (alloc.hpp, prefault: the first search of a set writes every page of it).
template <class T>
void resize_fresh(Buf<T> &v, size_t n) {
  if (n > v.capacity()) {
    v.clear();  // (the old contents need no copy)
    v.reserve(n);
    prefault(v.data(), n * sizeof(T));
  }
  v.resize(n);
}
// The per-thread row buffers are scratch written once front to back and read once per
// search: without a hook they take small pages (malloc) rather than alloc.hpp's huge
// pages. On the issue-8 VM a huge page costs 0.2 ms when the guest recycles it but 5-17
// ms when the host must back it anew (free-page reporting), a small page ~2 us either
// way; the lists and the grid keep the huge pages (read again by every approximant
// setup: fewer TLB misses). Measured on first 3D 10^5 searches in fresh processes: 93-155
// ms with small-page row buffers against 159-202 ms with huge ones when the pages came
// fresh from the host, 91-95 against 81-93 ms when recycled; repeated searches equal.
template <class T>
struct SmallPageAlloc : NoInitAlloc<T> {
  template <class U>
  struct rebind {
    using other = SmallPageAlloc<U>;
  };
  SmallPageAlloc() = default;
  template <class U>
  SmallPageAlloc(const SmallPageAlloc<U> &) noexcept {}
  T *allocate(std::size_t n) {
    if (current_alloc_hook()) return NoInitAlloc<T>::allocate(n);
    if (n > static_cast<std::size_t>(-1) / sizeof(T) / 2) throw std::bad_alloc();
    const std::size_t total = n * sizeof(T) + sizeof(detail::BlockHeader);
    void *raw = std::malloc(total);
    if (!raw) throw std::bad_alloc();
    auto *hdr = static_cast<detail::BlockHeader *>(raw);  // freed by hook_deallocate: std::free
    hdr->release = nullptr;
    hdr->user = nullptr;
    hdr->bytes = static_cast<int64_t>(total);
    return reinterpret_cast<T *>(hdr + 1);
  }
};
using RowBuf = std::vector<int32_t, SmallPageAlloc<int32_t>>;

// Query radius and pair limit of a site with search radius ri under the convention.
struct Rule {
  int conv;
  double rmax;
  double query(double ri) const {
    return conv == MFREE_SEARCH_GATHER ? ri : conv == MFREE_SEARCH_SYMMETRIC_MAX ? rmax : 0.5 * (ri + rmax);
  }
  double limit(double ri, double rj) const {
    return conv == MFREE_SEARCH_GATHER ? ri : conv == MFREE_SEARCH_SYMMETRIC_MAX ? std::max(ri, rj) : 0.5 * (ri + rj);
  }
};

// Work split into `nchunks` <= kMaxBlocks fixed chunks (chunk v: thread_block(count, v,
// nchunks)), run by however many threads the runtime grants (parallel_blocks keeps the
// block layout): passes that must see the same blocks (histogram, then scatter) agree
// even if a team comes out smaller than asked.
template <class Body>
void for_chunks(int nchunks, Body &&body) {
  parallel_blocks(nchunks, nchunks, [&](int, int64_t b, int64_t e) {
    for (int64_t v = b; v < e; ++v) body(static_cast<int>(v));
  });
}

class CellGrid {
 public:
  // (Re)build for the valid particles of ps; keeps the buffers' capacity.
  void build(const ParticleSet &ps, const std::vector<int32_t> &status);

  bool empty() const { return nvalid_ == 0; }
  double rmax() const { return rmax_; }
  bool uniform() const { return uniform_; }
  // Expected row length (particles per support ball at the mean density of the grid's
  // box): sizes the first search's row buffers.
  double expected_hits() const { return hits_; }
  int64_t num_cells() const { return ncells_; }

  // Wrap a coordinate into the periodic box along periodic axes.
  double wrap(double x, int c) const {
    if (!periodic_[c]) return x;
    return x - L_[c] * std::floor((x - lo_[c]) / L_[c]);
  }
  int64_t cell_of(const double *x) const {
    int64_t k[3] = {0, 0, 0};
    for (int c = 0; c < dim_; ++c) k[c] = coord(x[c], c);
    return index(k);
  }
  // Host indices of the valid particles in cell order.
  const int32_t *members() const { return id_.data(); }
  // Fraction of host-consecutive valid particles (i - 1, i) whose cells lie within one
  // cell row (2D) or cell plane (3D) of each other in cell order: ~1 for particles stored
  // in lattice or space-filling-curve order, ~0 for a random order.
  double host_locality(int32_t n) const;
  int32_t num_valid() const { return nvalid_; }

  // Write to row[cnt...] every valid particle j with squared distance to xq (wrapped)
  // within the rule's limit for a site of radius ri, growing row as needed; cnt is
  // advanced past them (row may hold junk beyond cnt).
  void query(const double *xq, double ri, const Rule &rule, RowBuf &row, size_t &cnt) const {
    if (nvalid_ == 0) return;
    const bool g = rule.conv == MFREE_SEARCH_GATHER;
    switch (dim_ * 4 + (any_periodic_ ? 2 : 0) + (g ? 1 : 0)) {
#define MFREE_QUERY(D, P, G) \
  case D * 4 + (P ? 2 : 0) + (G ? 1 : 0): query_t<D, P, G>(xq, ri, rule, row, cnt); break;
      MFREE_QUERY(1, false, false) MFREE_QUERY(1, false, true) MFREE_QUERY(1, true, false) MFREE_QUERY(1, true, true)
      MFREE_QUERY(2, false, false) MFREE_QUERY(2, false, true) MFREE_QUERY(2, true, false) MFREE_QUERY(2, true, true)
      MFREE_QUERY(3, false, false) MFREE_QUERY(3, false, true) MFREE_QUERY(3, true, false) MFREE_QUERY(3, true, true)
#undef MFREE_QUERY
      default: break;
    }
  }
#if MFREE_SIMD_X86
  // query() with the AVX2 scan (four candidates a step, hits packed by a table) where
  // it applies: 2D or 3D, no periodic axis, the gather convention; query() otherwise.
  // The same pair test lane by lane (no FMA), so the same rows. AVX2 only. 3D collects
  // the stencil's ranges and scans them in one call (query_avx2_t; 10^5 one-thread
  // host-order search 66 -> 48 ms, a loop per range inline was 23 % slower); 2D, five
  // ranges of ~7.5 candidates, scans each range inline (query2_avx2: 6 % faster than
  // query's two lanes, collecting was 7 % slower than them).
  // kind = avx2_kind(rule), asked once per search: 2 or 3 for the AVX2 queries, 0 for
  // query().
  int avx2_kind(const Rule &rule) const {
    return nvalid_ == 0 || any_periodic_ || rule.conv != MFREE_SEARCH_GATHER || dim_ < 2 ? 0 : dim_;
  }
  void query_avx2(int kind, const double *xq, double ri, const Rule &rule, RowBuf &row, size_t &cnt) const {
    if (kind == 2) query2_avx2(xq, ri, rule, row, cnt);
    else if (kind == 3) query_avx2_t<3>(xq, ri, rule, row, cnt);
    else query(xq, ri, rule, row, cnt);
  }
#endif

 private:
  // floor((x - lo) / cell), clamped or wrapped. (Without std::floor: baseline x86-64 has
  // no roundsd, and its branchy software floor was most of the cell pass of the build
  // and of a 2D query's set-up. Truncation is the floor for q > 0; where q may be
  // negative, one compare corrects it. The same cells as with floor.)
  int64_t coord(double x, int c) const {
    // (by the reciprocal: a division was most of the cell pass; monotone in x like the
    // quotient, and within an ulp or two of it, far inside margin_)
    const double q = inv_ok_ ? (x - lo_[c]) * inv_[c] : (x - lo_[c]) / cell_[c];
    int64_t k;
    if (periodic_[c]) {
      // (q lies within a cell or so of [0, nc]: x was wrapped)
      k = static_cast<int64_t>(q);
      k -= q < static_cast<double>(k) ? 1 : 0;
      k %= nc_[c];
      if (k < 0) k += nc_[c];
    } else {
      // clamp in double first: far-away host points must not overflow the cast
      k = q <= 0.0 ? 0 : (q >= static_cast<double>(nc_[c] - 1) ? nc_[c] - 1 : static_cast<int64_t>(q));
    }
    return k;
  }
  int64_t index(const int64_t *k) const {
    int64_t id = 0;
    for (int c = dim_ - 1; c >= 0; --c) id = id * nc_[c] + k[c];
    return id;
  }
  template <int D, bool Periodic, bool Gather>
  void query_t(const double *xq, double ri, const Rule &rule, RowBuf &row, size_t &cnt) const;
#if MFREE_SIMD_X86
  template <int D>
  void query_avx2_t(const double *xq, double ri, const Rule &rule, RowBuf &row, size_t &cnt) const;
  void query2_avx2(const double *xq, double ri, const Rule &rule, RowBuf &row, size_t &cnt) const;
  template <int D>
  size_t scan_avx2(const double *xq, double lim2, const int64_t *P0, const int64_t *P1, int nr, int32_t *out,
                   size_t k) const;
#endif
  // The counting sort's two particle passes for particles [b, e), with the dimension and
  // the periodicity as template parameters (no per-axis loops and branches; the same
  // arithmetic as wrap/cell_of, so the same cells): cell[i] of each valid particle
  // (-1: invalid) counted in cnt[cell], then the scatter by the fill positions pos.
  // The cells pass also counts, for host_locality, the host-consecutive valid pairs whose
  // cells lie within loc_w_ of each other (Loc: that count, the valid particles and the
  // first and last valid cell of [b, e); chunks join by their boundary pairs).
  // With Split, the pass also counts the valid particles whose cell lies below split_
  // (Loc::below; two chunks: the prefix sums' first cell block, no pass of its own).
  struct Loc {
    int64_t near = 0, valid = 0, first = -1, last = -1, below = 0;
  };
  template <int D, bool Periodic, bool Split, class Cnt>
  void cells_t(const ParticleSet &ps, const int32_t *status, int64_t b, int64_t e, int32_t *cell, Cnt *cnt,
               Loc &loc) const;
  void join_locality(const Loc *loc, int nch);
  template <int D, bool Periodic, class Pos>
  void scatter_t(const ParticleSet &ps, double kappa, int64_t b, int64_t e, const int32_t *cell, Pos *pos);
  template <bool Split, class Cnt>
  void cells_s(const ParticleSet &ps, const int32_t *status, int64_t b, int64_t e, int32_t *cell, Cnt *cnt,
               Loc &loc) const {
    switch (dim_ * 2 + (any_periodic_ ? 1 : 0)) {
      case 2: cells_t<1, false, Split>(ps, status, b, e, cell, cnt, loc); break;
      case 3: cells_t<1, true, Split>(ps, status, b, e, cell, cnt, loc); break;
      case 4: cells_t<2, false, Split>(ps, status, b, e, cell, cnt, loc); break;
      case 5: cells_t<2, true, Split>(ps, status, b, e, cell, cnt, loc); break;
      case 6: cells_t<3, false, Split>(ps, status, b, e, cell, cnt, loc); break;
      default: cells_t<3, true, Split>(ps, status, b, e, cell, cnt, loc); break;
    }
  }
  template <class Cnt>
  void cells(const ParticleSet &ps, const int32_t *status, int64_t b, int64_t e, int32_t *cell, Cnt *cnt, Loc &loc,
             bool split = false) const {
    if (split) cells_s<true>(ps, status, b, e, cell, cnt, loc);
    else cells_s<false>(ps, status, b, e, cell, cnt, loc);
  }
  template <class Pos>
  void scatter(const ParticleSet &ps, double kappa, int64_t b, int64_t e, const int32_t *cell, Pos *pos) {
    switch (dim_ * 2 + (any_periodic_ ? 1 : 0)) {
      case 2: scatter_t<1, false>(ps, kappa, b, e, cell, pos); break;
      case 3: scatter_t<1, true>(ps, kappa, b, e, cell, pos); break;
      case 4: scatter_t<2, false>(ps, kappa, b, e, cell, pos); break;
      case 5: scatter_t<2, true>(ps, kappa, b, e, cell, pos); break;
      case 6: scatter_t<3, false>(ps, kappa, b, e, cell, pos); break;
      default: scatter_t<3, true>(ps, kappa, b, e, cell, pos); break;
    }
  }
  template <int D, bool Periodic, bool Gather>
  size_t scan(const double *xq, double ri, const Rule &rule, int64_t p0, int64_t p1, int32_t *out,
              size_t k) const;

  int dim_ = 1;
  double lo_[3] = {0, 0, 0}, cell_[3] = {1, 1, 1}, L_[3] = {0, 0, 0};
  double inv_[3] = {1, 1, 1};  // 1 / cell_, used when all are finite and normal (inv_ok_)
  bool inv_ok_ = true;
  double margin_[3] = {0, 0, 0};  // slack of the geometric cell bounds (query)
  int64_t nc_[3] = {1, 1, 1};
  int64_t ncells_ = 1;
  bool periodic_[3] = {false, false, false};
  bool any_periodic_ = false;
  bool uniform_ = true;  // one search radius for every valid particle
  double rmax_ = 0.0;
  double hits_ = 0.0;
  int64_t split_ = 0;       // Loc::below counts cells below this one
  int64_t loc_w_ = 0;       // cells "near" in host_locality's sense: |difference| <= loc_w_
  double locality_ = 0.0;   // host_locality's fraction, found by the cells pass
  int32_t nvalid_ = 0;
  // (no radii by host index: a site's radius is kappa * h(i), recomputed where needed,
  // the same product; the sorted radii only for the symmetric conventions' pair limit:
  // 16 bytes per particle fewer to write, 390 fewer fresh pages in a first 2D search)
  bool need_srad_ = false;
  static constexpr int kPad = 4;  // padding entries after the members (the scans read them)
  Buf<double> sx_[3], srad_;     // by cell order, kPad padding entries at the end
  Buf<int32_t> id_;              // host index by cell order, kPad padding entries
  // (32-bit cell starts and indices: nvalid < 2^31 and at most 2^31 - 2 cells; half the
  // fresh pages and the memory traffic of 64-bit ones)
  Buf<int32_t> start_;           // cell c holds [start_[c], start_[c+1])
  Buf<int32_t> cell_idx_;        // cell of each host index (-1: invalid)
  Buf<int32_t> hist_;            // per-chunk cell counts, then fill positions
};

void CellGrid::build(const ParticleSet &ps, const std::vector<int32_t> &status) {
  dim_ = ps.dim();
  const int32_t n = ps.size();
  const double kappa = ps.kappa();
  any_periodic_ = false;
  for (int c = 0; c < 3; ++c) {
    periodic_[c] = c < dim_ && ps.periodic(c);
    any_periodic_ = any_periodic_ || periodic_[c];
    lo_[c] = periodic_[c] ? ps.box_lo(c) : 0.0;
    L_[c] = periodic_[c] ? ps.box_hi(c) - ps.box_lo(c) : 0.0;
    cell_[c] = 1.0;
    nc_[c] = 1;
    margin_[c] = 0.0;
  }
  rmax_ = 0.0;
  hits_ = 0.0;
  locality_ = 0.0;
  nvalid_ = 0;
  uniform_ = true;
  ncells_ = 1;
  need_srad_ = ps.search_convention() != MFREE_SEARCH_GATHER;

  // Pass 1 over fixed chunks: radii, bounding box, sum and maximum of the radii.
  const int nch = std::min(num_threads(n), 64);
  struct Part {
    double rsum = 0.0, rmin = 0.0, rmax = 0.0, bmin[3] = {0, 0, 0}, bmax[3] = {0, 0, 0};
    int32_t count = 0;
  };
  Part part[64];
  for_chunks(nch, [&](int v) {
    int64_t b, e;
    thread_block(n, v, nch, b, e);
    // accumulated in a local copy: the chunks' Part records share cache lines, and
    // updating them in place per particle made this pass slower on two threads than on
    // one (false sharing)
    // (strided loads, the dimension a template parameter and infinite starting bounds:
    // min and max without branches; the same values, the same sum)
    const double *X = ps.pos_data(), *H = ps.h_data();
    const int64_t si = ps.pos_step_i(), sc = ps.pos_step_c(), sh = ps.h_step();
    auto pass = [&](auto dc) {
      constexpr int D = decltype(dc)::value;
      const double inf = std::numeric_limits<double>::infinity();
      Part p;
      double rmin = inf, rmax = 0.0, rsum = 0.0, lo[3] = {inf, inf, inf}, hi[3] = {-inf, -inf, -inf};
      int32_t count = 0;
      const bool per = any_periodic_;
      for (int64_t i = b; i < e; ++i) {
        if (status[i] != 0) continue;
        const double r = kappa * H[i * sh];
        rmin = r < rmin ? r : rmin;
        rmax = r > rmax ? r : rmax;
        rsum += r;
#pragma GCC unroll 3
        for (int c = 0; c < D; ++c) {
          const double x = per ? wrap(X[i * si + c * sc], c) : X[i * si + c * sc];
          lo[c] = x < lo[c] ? x : lo[c];
          hi[c] = x > hi[c] ? x : hi[c];
        }
        ++count;
      }
      p.rmin = rmin;
      p.rmax = rmax;
      p.rsum = rsum;
      p.count = count;
      for (int c = 0; c < D; ++c) {
        p.bmin[c] = lo[c];
        p.bmax[c] = hi[c];
      }
      part[v] = p;
    };
    if (dim_ == 1) pass(std::integral_constant<int, 1>());
    else if (dim_ == 2) pass(std::integral_constant<int, 2>());
    else pass(std::integral_constant<int, 3>());
  });
  double rsum = 0.0, rmin = 0.0, bmin[3] = {0, 0, 0}, bmax[3] = {0, 0, 0};
  for (int v = 0; v < nch; ++v) {
    const Part &p = part[v];
    if (p.count == 0) continue;
    for (int c = 0; c < dim_; ++c) {
      if (nvalid_ == 0 || p.bmin[c] < bmin[c]) bmin[c] = p.bmin[c];
      if (nvalid_ == 0 || p.bmax[c] > bmax[c]) bmax[c] = p.bmax[c];
    }
    if (nvalid_ == 0 || p.rmin < rmin) rmin = p.rmin;
    rmax_ = std::max(rmax_, p.rmax);
    rsum += p.rsum;  // chunk sums: the cell edge may differ in the last bit between thread
                     // counts, the lists cannot (they are sets, sorted)
    nvalid_ += p.count;
  }
  uniform_ = rmin == rmax_;
  start_.assign(2, 0);
  id_.assign(1, 0);
  for (int c = 0; c < 3; ++c) sx_[c].assign(1, 0.0);
  srad_.assign(1, 0.0);
  if (nvalid_ == 0) return;

  for (int c = 0; c < dim_; ++c)
    if (periodic_[c] && 2.0 * rmax_ >= L_[c]) {
      std::ostringstream s;
      s << "support radius kappa*h = " << rmax_ << " is not below half the periodic box length "
        << L_[c] << " on axis " << c;
      nvalid_ = 0;
      throw Error(MFREE_ERR_INPUT, s.str());
    }

  // Cell edge: half the mean radius (a quarter along x), enlarged so that the grid has
  // at most ~2 cells per particle (clustered or far-flung particles would otherwise make
  // it huge). Enlarge until the grid fits (one particle at 1e15 needs more than 64
  // steps); an extent whose cell count is not a finite double gets one cell, which is
  // always correct because coordinates are clamped into the grid, and never reaches an
  // out-of-range cast.
  double edge = 0.5 * rsum / static_cast<double>(nvalid_);
  const double max_cells = std::min(2.0 * static_cast<double>(nvalid_) + 64.0, 2147483646.0);
  auto span = [](double ext, double e) {
    const double k = std::floor(ext / e);
    return std::isfinite(k) ? k : 0.0;
  };
  auto edge_of = [&edge](int c) { return c == 0 ? 0.5 * edge : edge; };
  for (;;) {
    double total = 1.0;
    for (int c = 0; c < dim_; ++c) {
      const double ext = periodic_[c] ? L_[c] : bmax[c] - bmin[c];
      total *= std::max(1.0, span(ext, edge_of(c)));
    }
    if (total <= max_cells) break;
    edge *= 1.5;
  }
  for (int c = 0; c < dim_; ++c) {
    if (periodic_[c]) {
      nc_[c] = std::max<int64_t>(1, static_cast<int64_t>(span(L_[c], edge_of(c))));
      cell_[c] = L_[c] / static_cast<double>(nc_[c]);
    } else {
      lo_[c] = bmin[c];
      nc_[c] = static_cast<int64_t>(span(bmax[c] - bmin[c], edge_of(c))) + 1;
      cell_[c] = edge_of(c);
    }
  }
  ncells_ = 1;
  for (int c = 0; c < dim_; ++c) ncells_ *= nc_[c];
  inv_ok_ = true;
  for (int c = 0; c < 3; ++c) {
    inv_[c] = 1.0 / cell_[c];
    inv_ok_ = inv_ok_ && std::isnormal(inv_[c]) && std::isnormal(cell_[c]);
  }
  {
    // expected row length if the particles filled the grid's box evenly
    const double r = rsum / static_cast<double>(nvalid_);
    double box = 1.0;
    for (int c = 0; c < dim_; ++c) box *= static_cast<double>(nc_[c]) * cell_[c];
    const double pi = 3.141592653589793;
    const double ball = dim_ == 1 ? 2.0 * r : (dim_ == 2 ? pi * r * r : 4.0 / 3.0 * pi * r * r * r);
    const double est = static_cast<double>(nvalid_) * ball / box;
    hits_ = std::isfinite(est) ? std::min(est, static_cast<double>(nvalid_)) : 0.0;
  }
  // A particle's cell index floor((x - lo) / cell) may be off by one for x within a few
  // ulps of a cell face; 1e-10 of the grid's scale covers that with room to spare.
  for (int c = 0; c < dim_; ++c)
    margin_[c] = 1e-10 * (std::fabs(lo_[c]) + static_cast<double>(nc_[c]) * cell_[c]);
  loc_w_ = dim_ == 1 ? 4 : (dim_ == 2 ? 2 * nc_[0] + 4 : nc_[0] * nc_[1] + 2 * nc_[0] + 4);

  // Counting sort of the valid particles by cell, stable (ascending host index in a
  // cell) for any chunk count: chunk v's particles follow chunk v-1's in every cell.
  const int64_t nc = ncells_;
  resize_fresh(cell_idx_, static_cast<size_t>(n));
  resize_fresh(start_, static_cast<size_t>(nc) + 2);
  // (kPad padding entries: read, never counted, by the two- and four-lane scans)
  const size_t padded = static_cast<size_t>(nvalid_) + kPad;
  resize_fresh(id_, padded);
  if (need_srad_) {
    resize_fresh(srad_, padded);
    std::fill(srad_.begin() + nvalid_, srad_.end(), 0.0);
  }
  for (int c = 0; c < dim_; ++c) resize_fresh(sx_[c], padded);
  std::fill(id_.begin() + nvalid_, id_.end(), 0);
  for (int c = 0; c < dim_; ++c) std::fill(sx_[c].begin() + nvalid_, sx_[c].end(), 0.0);
  int32_t *cell = cell_idx_.data();
  // (per-chunk histograms only while they stay small against the particle count)
  if (nch == 1 || static_cast<double>(nch) * static_cast<double>(nc) > 8.0 * (static_cast<double>(n) + 4096.0)) {
    // counts in start_[c + 2], their prefix sums make start_[c + 1] the start of cell c,
    // the scatter's fill positions, which it leaves at the start of cell c + 1 (one
    // entry more than the cells need: no pass shifting them back)
    int32_t *s2 = start_.data();
    std::fill(s2, s2 + nc + 2, 0);
    Loc loc;
    cells(ps, status.data(), 0, n, cell, s2 + 2, loc);
    join_locality(&loc, 1);
    for (int64_t c = 2; c <= nc + 1; ++c) s2[c] += s2[c - 1];
    scatter(ps, kappa, 0, n, cell, s2 + 1);
    return;
  }
  // chunk counts (nvalid < 2^31, so every count and position fits 32 bits)
  hist_.resize(static_cast<size_t>(nch) * static_cast<size_t>(nc));
  int32_t *hist = hist_.data();
  Loc loc[64];
  const bool two = nch == 2;
  if (two) {
    int64_t b, e;
    thread_block(nc, 1, 2, b, e);
    split_ = b;  // (the second cell block of the prefix sums below starts here)
  }
  for_chunks(nch, [&](int v) {
    int32_t *h = hist + static_cast<int64_t>(v) * nc;
    std::fill(h, h + nc, 0);
    int64_t b, e;
    thread_block(n, v, nch, b, e);
    Loc l;  // (a local copy: the chunks' records share cache lines)
    cells(ps, status.data(), b, e, cell, h, l, two);
    loc[v] = l;
  });
  join_locality(loc, nch);
  // prefix sums over (cell, chunk), two passes over cell blocks
  int64_t block_total[64];
  if (two) {  // (counted by the cells pass)
    block_total[0] = loc[0].below + loc[1].below;
    block_total[1] = nvalid_;
  } else {
    for_chunks(nch, [&](int v) {
      int64_t b, e, s = 0;
      thread_block(nc, v, nch, b, e);
      for (int64_t c = b; c < e; ++c)
        for (int u = 0; u < nch; ++u) s += hist[static_cast<int64_t>(u) * nc + c];
      block_total[v] = s;
    });
    for (int v = 1; v < nch; ++v) block_total[v] += block_total[v - 1];
  }
  for_chunks(nch, [&](int v) {
    int64_t b, e, s = v > 0 ? block_total[v - 1] : 0;
    thread_block(nc, v, nch, b, e);
    for (int64_t c = b; c < e; ++c) {
      start_[c] = static_cast<int32_t>(s);
      for (int u = 0; u < nch; ++u) {
        int32_t &h = hist[static_cast<int64_t>(u) * nc + c];
        const int32_t cnt = h;
        h = static_cast<int32_t>(s);
        s += cnt;
      }
    }
  });
  start_[nc] = nvalid_;
  for_chunks(nch, [&](int v) {
    int32_t *f = hist + static_cast<int64_t>(v) * nc;
    int64_t b, e;
    thread_block(n, v, nch, b, e);
    scatter(ps, kappa, b, e, cell, f);
  });
}

// (was a pass of its own over the cells after the build: 1.0-1.5 ms of a 10^6 search,
// serial)
double CellGrid::host_locality(int32_t n) const {
  if (nvalid_ < 2 || static_cast<int64_t>(cell_idx_.size()) < n) return 0.0;
  return locality_;
}

void CellGrid::join_locality(const Loc *loc, int nch) {
  int64_t near = 0, valid = 0, prev = -1;
  for (int v = 0; v < nch; ++v) {
    const Loc &l = loc[v];
    if (l.valid == 0) continue;
    near += l.near;
    if (prev >= 0 && l.first - prev <= loc_w_ && prev - l.first <= loc_w_) ++near;
    valid += l.valid;
    prev = l.last;
  }
  locality_ = valid > 1 ? static_cast<double>(near) / static_cast<double>(valid - 1) : 0.0;
}

template <int D, bool Periodic, bool Split, class Cnt>
void CellGrid::cells_t(const ParticleSet &ps, const int32_t *status, int64_t b, int64_t e, int32_t *cell,
                       Cnt *cnt, Loc &loc) const {
  const double *X = ps.pos_data();
  const int64_t si = ps.pos_step_i(), sc = ps.pos_step_c();
  // (prev starts far from every cell: the first valid particle counts no pair; near
  // without a branch: |id - prev| <= w as one unsigned comparison)
  const uint64_t w = static_cast<uint64_t>(loc_w_);
  int64_t prev = -(int64_t{1} << 62), near = 0, valid = 0, below = 0;
  const int64_t split = split_;
  for (int64_t i = b; i < e; ++i) {
    if (status[i] != 0) {
      cell[i] = -1;
      continue;
    }
    // index() order: id = (k2 * nc1 + k1) * nc0 + k0
    int64_t id = 0;
    for (int c = D - 1; c >= 0; --c) {
      const double x = X[i * si + c * sc];
      id = id * nc_[c] + coord(Periodic ? wrap(x, c) : x, c);
    }
    cell[i] = static_cast<int32_t>(id);
    ++cnt[id];
    near += static_cast<uint64_t>(id - prev) + w <= 2 * w ? 1 : 0;
    if (Split) below += id < split ? 1 : 0;
    prev = id;
    ++valid;
  }
  loc.below = below;
  loc.near = near;
  loc.valid = valid;
  loc.last = valid > 0 ? prev : -1;
  loc.first = -1;
  for (int64_t i = b; i < e && valid > 0; ++i)
    if (cell[i] >= 0) {
      loc.first = cell[i];
      break;
    }
}

template <int D, bool Periodic, class Pos>
void CellGrid::scatter_t(const ParticleSet &ps, double kappa, int64_t b, int64_t e, const int32_t *cell, Pos *pos) {
  double *x[3] = {sx_[0].data(), sx_[D > 1 ? 1 : 0].data(), sx_[D > 2 ? 2 : 0].data()};
  int32_t *id = id_.data();
  const double *X = ps.pos_data(), *H = ps.h_data();
  const int64_t si = ps.pos_step_i(), sc = ps.pos_step_c(), sh = ps.h_step();
  for (int64_t i = b; i < e; ++i) {
    if (cell[i] < 0) continue;
    const int64_t q = pos[cell[i]]++;
    id[q] = static_cast<int32_t>(i);
    for (int c = 0; c < D; ++c) {
      const double xc = X[i * si + c * sc];
      x[c][q] = Periodic ? wrap(xc, c) : xc;
    }
    if (need_srad_) srad_[q] = kappa * H[i * sh];
  }
}

// Members [p0, p1) within the limit of xq, written from out[k]; returns the new count.
// out must have room for p1 - p0 + 1 entries from k.
template <int D, bool Periodic, bool Gather>
size_t CellGrid::scan(const double *xq, double ri, const Rule &rule, int64_t p0, int64_t p1,
                      int32_t *out, size_t k) const {
  const double lim2 = ri * ri * (1.0 + kEdgeTol2);
  const double *x0 = sx_[0].data(), *x1 = sx_[D > 1 ? 1 : 0].data(), *x2 = sx_[D > 2 ? 2 : 0].data();
  const int32_t *id = id_.data();
  int64_t p = p0;
#if defined(__GNUC__)
  if (!Periodic && Gather) {
    // Two candidates per step (GCC/Clang vector extensions: SSE2 on x86-64, NEON on
    // arm64); an odd range reads one member past its end (the next cell's, or the
    // padding entry) and takes it back, so that every pair goes through the same
    // instructions (the symmetric transposition in run_queries needs the test to give
    // the same answer for (i, j) and (j, i), also under FMA contraction). Lane
    // arithmetic: ((d0^2 + d1^2) + d2^2) <= lim2.
    typedef double v2d __attribute__((vector_size(16)));
    typedef long long v2l __attribute__((vector_size(16)));
    const v2d q0 = {xq[0], xq[0]}, q1 = {D > 1 ? xq[1] : 0.0, D > 1 ? xq[1] : 0.0},
              q2 = {D > 2 ? xq[2] : 0.0, D > 2 ? xq[2] : 0.0}, lv = {lim2, lim2};
    v2l m = {0, 0};
    for (; p < p1; p += 2) {
      v2d a0, a1, a2;
      std::memcpy(&a0, x0 + p, sizeof a0);
      const v2d e0 = q0 - a0;
      v2d d2 = e0 * e0;
      if (D > 1) {
        std::memcpy(&a1, x1 + p, sizeof a1);
        const v2d e1 = q1 - a1;
        d2 = d2 + e1 * e1;
      }
      if (D > 2) {
        std::memcpy(&a2, x2 + p, sizeof a2);
        const v2d e2 = q2 - a2;
        d2 = d2 + e2 * e2;
      }
      m = static_cast<v2l>(d2 <= lv);  // lanes: -1 hit, 0 miss
      out[k] = id[p];
      k -= static_cast<size_t>(m[0]);
      out[k] = id[p + 1];
      k -= static_cast<size_t>(m[1]);
    }
    if (p > p1) k += static_cast<size_t>(m[1]);  // the member past the range
    return k;
  }
#endif
  // every candidate is written, the count advances only for a hit (no branch)
  for (; p < p1; ++p) {
    double d[3] = {xq[0] - x0[p], D > 1 ? xq[1] - x1[p] : 0.0, D > 2 ? xq[2] - x2[p] : 0.0};
    if (Periodic)
      for (int c = 0; c < D; ++c)
        if (periodic_[c]) d[c] -= L_[c] * std::nearbyint(d[c] / L_[c]);
    const double d2 = d[0] * d[0] + (D > 1 ? d[1] * d[1] : 0.0) + (D > 2 ? d[2] * d[2] : 0.0);
    out[k] = id[p];
    if (Gather) {
      k += d2 <= lim2;
    } else {
      const double l = rule.limit(ri, srad_[p]);
      k += d2 <= l * l * (1.0 + kEdgeTol2);
    }
  }
  return k;
}

template <int D, bool Periodic, bool Gather>
void CellGrid::query_t(const double *xq, double ri, const Rule &rule, RowBuf &row, size_t &cnt) const {
  const double R = rule.query(ri) * (1.0 + 1e-12);  // closed supports (kEdgeTol)
  const double R2 = R * R;
  // Cell ranges per axis: [k(x - R), k(x + R)] clamped, [k - m, k + m] on a periodic
  // axis, or all cells once where that stencil would wrap onto itself (`full`: no
  // geometric pruning along that axis, the pair test takes the nearest image).
  int64_t kmin[3] = {0, 0, 0}, kmax[3] = {0, 0, 0};
  bool full[3] = {false, false, false};
  for (int c = 0; c < D; ++c) {
    if (Periodic && periodic_[c]) {
      const int64_t kc = coord(xq[c], c);
      const int64_t m = static_cast<int64_t>(std::ceil(R / cell_[c]));
      if (2 * m + 1 >= nc_[c]) {
        kmin[c] = 0;
        kmax[c] = nc_[c] - 1;
        full[c] = true;
      } else {
        kmin[c] = kc - m;
        kmax[c] = kc + m;
      }
    } else {
      kmin[c] = coord(xq[c] - R, c);
      kmax[c] = coord(xq[c] + R, c);
    }
  }
  // Squared distance from xq to the slab of (image) cell k along axis c, a lower bound
  // for every particle stored in it: shrunk by a margin far above the rounding of the
  // cell index, so that no pair at the closed edge is lost.
  auto gap2 = [&](int c, int64_t k) {
    if (Periodic && full[c]) return 0.0;
    const double a = lo_[c] + static_cast<double>(k) * cell_[c], b = a + cell_[c];
    double g = std::max(a - xq[c], xq[c] - b) - margin_[c];
    g = g > 0.0 ? g : 0.0;
    return g * g;
  };
  // Along axis 0 the stencil's cells are one member range per row of cells, or two
  // where a periodic range wraps. (Trimming them to the sphere's chord per row costs a
  // square root and two divisions, more than the few candidates it saves.)
  int64_t seg[2][2] = {{kmin[0], kmax[0]}, {0, -1}};
  if (Periodic && periodic_[0]) {
    if (kmin[0] < 0) {
      seg[0][0] = 0;
      seg[1][0] = kmin[0] + nc_[0];
      seg[1][1] = nc_[0] - 1;
    } else if (kmax[0] >= nc_[0]) {
      seg[0][1] = nc_[0] - 1;
      seg[1][0] = 0;
      seg[1][1] = kmax[0] - nc_[0];
    }
  }
  const int nseg = Periodic && seg[1][1] >= seg[1][0] ? 2 : 1;
  // Room for every member the rows can hold (+1 for the two-lane scan's overrun). Without
  // periodic axes the scanned rows lie between the stencil's first and last cell in cell
  // order, so one check per query suffices.
  const int32_t *st = start_.data();
  bool checked = false;
  if (!Periodic) {
    const int64_t need = static_cast<int64_t>(cnt) + st[index(kmax) + 1] - st[index(kmin)] + 1;
    if (static_cast<int64_t>(row.size()) < need) row.resize(2 * static_cast<size_t>(need));
    checked = true;
  }
  int32_t *out = row.data();
  size_t k = cnt;
  // rows of cells whose slab misses the query's sphere are skipped (the corners of the
  // stencil)
  for (int64_t k2 = kmin[2]; k2 <= kmax[2]; ++k2) {
    const double gz = D > 2 ? gap2(2, k2) : 0.0;
    if (gz > R2) continue;
    const int64_t w2 = Periodic && periodic_[2] ? ((k2 % nc_[2]) + nc_[2]) % nc_[2] : k2;
    for (int64_t k1 = kmin[1]; k1 <= kmax[1]; ++k1) {
      // (only the corners of a 3D stencil can miss the sphere: along one axis the
      // extreme rows hold xq - R and xq + R, or lie within R of xq's cell when periodic;
      // the test cost 9 % of a 2D search and never skipped a row there)
      if (D > 2 && gz + gap2(1, k1) > R2) continue;
      const int64_t w1 = Periodic && periodic_[1] ? ((k1 % nc_[1]) + nc_[1]) % nc_[1] : k1;
      const int64_t base = (w2 * nc_[1] + w1) * nc_[0];
      for (int sg = 0; sg < nseg; ++sg) {
        const int64_t p0 = st[base + seg[sg][0]], p1 = st[base + seg[sg][1] + 1];
        if (!checked && row.size() < k + static_cast<size_t>(p1 - p0) + 1) {
          row.resize(2 * (k + static_cast<size_t>(p1 - p0) + 1));
          out = row.data();
        }
        k = scan<D, Periodic, Gather>(xq, ri, rule, p0, p1, out, k);
      }
    }
  }
  cnt = k;
}

#if MFREE_SIMD_X86
// Packing the hits of four candidates: byte shuffle (pshufb) of four int32 lanes moving
// the lanes set in the 4-bit mask to the front, and the number of those lanes.
struct PackTable {
  alignas(16) int8_t shuf[16][16];
  int8_t count[16];
  constexpr PackTable() : shuf(), count() {
    for (int m = 0; m < 16; ++m) {
      int k = 0;
      for (int l = 0; l < 4; ++l)
        if (m & (1 << l)) {
          for (int b = 0; b < 4; ++b) shuf[m][4 * k + b] = static_cast<int8_t>(4 * l + b);
          ++k;
        }
      count[m] = static_cast<int8_t>(k);
      for (int b = 4 * k; b < 16; ++b) shuf[m][b] = static_cast<int8_t>(0x80);  // zero
    }
  }
};
constexpr PackTable kPack{};

// AVX2 without FMA (target "avx2" alone): the pair test must round like the two-lane
// scan's, ((d0^2 + d1^2) + d2^2) <= lim2 with every product rounded, so that the rows
// are the same sets whichever scan found them.
#define MFREE_TARGET_AVX2_NOFMA __attribute__((target("avx2")))

// The members of the nr non-empty ranges [P0[r], P1[r]) within lim2 of xq, four a
// step: every candidate's id is stored and the hits packed to the front; the lanes past
// a range's end (the next cell's members or the padding, kPad entries) are masked off.
// All ranges in one loop (one call per query: the steps of consecutive ranges overlap).
// Writes up to out[k + sum of the lengths + 3].
template <int D>
MFREE_TARGET_AVX2_NOFMA size_t CellGrid::scan_avx2(const double *xq, double lim2, const int64_t *P0,
                                                   const int64_t *P1, int nr, int32_t *out, size_t k) const {
  const double *x0 = sx_[0].data(), *x1 = sx_[D > 1 ? 1 : 0].data(), *x2 = sx_[D > 2 ? 2 : 0].data();
  const int32_t *id = id_.data();
  const __m256d q0 = _mm256_set1_pd(xq[0]), q1 = _mm256_set1_pd(D > 1 ? xq[1] : 0.0),
                q2 = _mm256_set1_pd(D > 2 ? xq[2] : 0.0), lv = _mm256_set1_pd(lim2);
  for (int r = 0; r < nr; ++r) {
    const int64_t e = P1[r];
    for (int64_t p = P0[r]; p < e; p += 4) {
      const __m256d e0 = _mm256_sub_pd(q0, _mm256_loadu_pd(x0 + p));
      __m256d d2 = _mm256_mul_pd(e0, e0);
      if (D > 1) {
        const __m256d e1 = _mm256_sub_pd(q1, _mm256_loadu_pd(x1 + p));
        d2 = _mm256_add_pd(d2, _mm256_mul_pd(e1, e1));
      }
      if (D > 2) {
        const __m256d e2 = _mm256_sub_pd(q2, _mm256_loadu_pd(x2 + p));
        d2 = _mm256_add_pd(d2, _mm256_mul_pd(e2, e2));
      }
      const int64_t left = e - p;  // >= 1
      const int m = _mm256_movemask_pd(_mm256_cmp_pd(d2, lv, _CMP_LE_OQ)) & ((1 << (left < 4 ? left : 4)) - 1);
      const __m128i ids = _mm_loadu_si128(reinterpret_cast<const __m128i *>(id + p));
      const __m128i sh = _mm_load_si128(reinterpret_cast<const __m128i *>(kPack.shuf[m]));
      _mm_storeu_si128(reinterpret_cast<__m128i *>(out + k), _mm_shuffle_epi8(ids, sh));
      k += static_cast<size_t>(kPack.count[m]);
    }
  }
  return k;
}

// query_t<2, false, true> with four candidates a step, each row of cells' range scanned
// inline (as scan_avx2). Writes up to row[cnt + members + 3].
MFREE_TARGET_AVX2_NOFMA void CellGrid::query2_avx2(const double *xq, double ri, const Rule &rule, RowBuf &row,
                                                   size_t &cnt) const {
  const double R = rule.query(ri) * (1.0 + 1e-12);
  const double lim2 = ri * ri * (1.0 + kEdgeTol2);
  const int64_t a0 = coord(xq[0] - R, 0), b0 = coord(xq[0] + R, 0), a1 = coord(xq[1] - R, 1),
                b1 = coord(xq[1] + R, 1);
  const int32_t *st = start_.data();
  const int64_t need = static_cast<int64_t>(cnt) + st[b1 * nc_[0] + b0 + 1] - st[a1 * nc_[0] + a0] + 4;
  if (static_cast<int64_t>(row.size()) < need) row.resize(2 * static_cast<size_t>(need));
  int32_t *out = row.data();
  size_t k = cnt;
  const double *x0 = sx_[0].data(), *x1 = sx_[1].data();
  const int32_t *id = id_.data();
  const __m256d q0 = _mm256_set1_pd(xq[0]), q1 = _mm256_set1_pd(xq[1]), lv = _mm256_set1_pd(lim2);
  // (no gap test: along one axis every row of the stencil reaches the query's circle)
  for (int64_t k1 = a1; k1 <= b1; ++k1) {
    const int64_t base = k1 * nc_[0];
    const int64_t e = st[base + b0 + 1];
    for (int64_t p = st[base + a0]; p < e; p += 4) {
      const __m256d e0 = _mm256_sub_pd(q0, _mm256_loadu_pd(x0 + p));
      const __m256d e1 = _mm256_sub_pd(q1, _mm256_loadu_pd(x1 + p));
      const __m256d d2 = _mm256_add_pd(_mm256_mul_pd(e0, e0), _mm256_mul_pd(e1, e1));  // (d0^2 + d1^2)
      const int64_t left = e - p;  // >= 1; lanes past the range masked off
      const int m = _mm256_movemask_pd(_mm256_cmp_pd(d2, lv, _CMP_LE_OQ)) & ((1 << (left < 4 ? left : 4)) - 1);
      const __m128i ids = _mm_loadu_si128(reinterpret_cast<const __m128i *>(id + p));
      const __m128i sh = _mm_load_si128(reinterpret_cast<const __m128i *>(kPack.shuf[m]));
      _mm_storeu_si128(reinterpret_cast<__m128i *>(out + k), _mm_shuffle_epi8(ids, sh));
      k += static_cast<size_t>(kPack.count[m]);
    }
  }
  cnt = k;
}

// query_t<D, false, true> with scan_avx2: the member ranges of the stencil's rows of
// cells collected first (kRows at a time), then scanned in one call. (Per range a call
// of a four-lane loop was no faster than query_t's two lanes: the short loops' exits
// were mispredicted and their latency not overlapped; collected, 3D 10^5 66 -> 48 ms.)
template <int D>
MFREE_TARGET_AVX2_NOFMA void CellGrid::query_avx2_t(const double *xq, double ri, const Rule &rule, RowBuf &row,
                                                    size_t &cnt) const {
  const double R = rule.query(ri) * (1.0 + 1e-12);  // as query_t
  const double R2 = R * R;
  const double lim2 = ri * ri * (1.0 + kEdgeTol2);  // as scan
  int64_t kmin[3] = {0, 0, 0}, kmax[3] = {0, 0, 0};
  for (int c = 0; c < D; ++c) {
    kmin[c] = coord(xq[c] - R, c);
    kmax[c] = coord(xq[c] + R, c);
  }
  auto gap2 = [&](int c, int64_t k) {
    const double a = lo_[c] + static_cast<double>(k) * cell_[c], b = a + cell_[c];
    double g = std::max(a - xq[c], xq[c] - b) - margin_[c];
    g = g > 0.0 ? g : 0.0;
    return g * g;
  };
  const int32_t *st = start_.data();
  // room: every member between the stencil's first and last cell, and a step's overrun
  const int64_t need = static_cast<int64_t>(cnt) + st[index(kmax) + 1] - st[index(kmin)] + 4;
  if (static_cast<int64_t>(row.size()) < need) row.resize(2 * static_cast<size_t>(need));
  int32_t *out = row.data();
  size_t k = cnt;
  constexpr int kRows = 32;
  int64_t P0[kRows], P1[kRows];
  int nr = 0;
  // Rows of cells are never skipped along one axis (the extreme ones hold xq - R and xq
  // + R), only the corners of a 3D stencil: gy[k1 - kmin1] is the squared gap of row k1.
  double gy[kRows];
  const int64_t ny = kmax[1] - kmin[1] + 1;
  const bool corners = D > 2 && ny <= kRows;
  if (corners)
    for (int64_t k1 = kmin[1]; k1 <= kmax[1]; ++k1) gy[k1 - kmin[1]] = gap2(1, k1);
  for (int64_t k2 = kmin[2]; k2 <= kmax[2]; ++k2) {
    const double gz = D > 2 ? gap2(2, k2) : 0.0;
    for (int64_t k1 = kmin[1]; k1 <= kmax[1]; ++k1) {
      const int64_t base = (k2 * nc_[1] + k1) * nc_[0];
      const int64_t p0 = st[base + kmin[0]], p1 = st[base + kmax[0] + 1];
      // (kept by a select: which corner rows of a 3D stencil miss the sphere varies
      // from query to query, a branch there was mispredicted)
      const double gyk = corners ? gy[k1 - kmin[1]] : 0.0;
      const int keep = static_cast<int>(p1 > p0) & static_cast<int>(gz + gyk <= R2);  // (& not &&: no branch)
      P0[nr] = p0;
      P1[nr] = p1;
      nr += keep;
      if (nr == kRows) {
        k = scan_avx2<D>(xq, lim2, P0, P1, nr, out, k);
        nr = 0;
      }
    }
  }
  cnt = scan_avx2<D>(xq, lim2, P0, P1, nr, out, k);
}
#endif

// Rows are short (tens) and, for particles stored in lattice or cell order, nearly
// sorted already: insertion sort beats std::sort's set-up there.
void sort_row(int32_t *b, int32_t *e) {
  for (int32_t *p = b + 1; p < e; ++p) {
    const int32_t v = *p;
    int32_t *q = p;
    while (q > b && q[-1] > v) {
      *q = q[-1];
      --q;
    }
    *q = v;
  }
}

// mm[0] = min(init_min, [b, e)), mm[1] = max(-1, [b, e)). Four lanes at a time where
// GCC/Clang vector extensions exist (a compare and a select per lane: SSE2 has no
// 32-bit min/max); scalar cmovs were ~10 % of a threaded 2D search.
inline void row_min_max(const int32_t *b, const int32_t *e, int32_t init_min, int32_t *mm) {
  int32_t a = init_min, z = -1;
#if defined(__GNUC__)
  typedef int32_t v4i __attribute__((vector_size(16)));
  if (e - b >= 8) {
    v4i va = {init_min, init_min, init_min, init_min}, vz = {-1, -1, -1, -1};
    for (; e - b >= 4; b += 4) {
      v4i v;
      std::memcpy(&v, b, sizeof v);
      va = v < va ? v : va;
      vz = v > vz ? v : vz;
    }
    for (int l = 0; l < 4; ++l) {
      a = va[l] < a ? va[l] : a;
      z = vz[l] > z ? vz[l] : z;
    }
  }
#endif
  for (; b < e; ++b) {
    a = *b < a ? *b : a;
    z = *b > z ? *b : z;
  }
  mm[0] = a;
  mm[1] = z;
}

#if MFREE_SIMD_X86
// The same with AVX2's 32-bit min/max, eight lanes (the last eight entries reloaded for
// the tail: min and max do not mind an entry counted twice). The baseline copy above
// was ~6 % of a 2-thread 2D search's work (the tracking only the threaded transposition
// needs), this one about a third of that. Same values, so the same lists.
// The smallest of the eight lanes of mn and the largest of mx.
MFREE_TARGET_AVX2 inline void hmin_hmax_avx2(__m256i mn, __m256i mx, int32_t &lo, int32_t &hi) {
  __m128i a4 = _mm_min_epi32(_mm256_castsi256_si128(mn), _mm256_extracti128_si256(mn, 1));
  __m128i z4 = _mm_max_epi32(_mm256_castsi256_si128(mx), _mm256_extracti128_si256(mx, 1));
  a4 = _mm_min_epi32(a4, _mm_shuffle_epi32(a4, 0x4e));
  z4 = _mm_max_epi32(z4, _mm_shuffle_epi32(z4, 0x4e));
  a4 = _mm_min_epi32(a4, _mm_shuffle_epi32(a4, 0xb1));
  z4 = _mm_max_epi32(z4, _mm_shuffle_epi32(z4, 0xb1));
  lo = _mm_cvtsi128_si32(a4);
  hi = _mm_cvtsi128_si32(z4);
}

MFREE_TARGET_AVX2 void row_min_max_avx2(const int32_t *b, const int32_t *e, int32_t init_min, int32_t *mm) {
  if (e - b < 8) {
    int32_t a = init_min, z = -1;
    for (; b < e; ++b) {
      a = *b < a ? *b : a;
      z = *b > z ? *b : z;
    }
    mm[0] = a;
    mm[1] = z;
    return;
  }
  __m256i va = _mm256_set1_epi32(init_min), vz = _mm256_set1_epi32(-1);
  const int32_t *p = b;
  for (; e - p >= 8; p += 8) {
    const __m256i v = _mm256_loadu_si256(reinterpret_cast<const __m256i *>(p));
    va = _mm256_min_epi32(va, v);
    vz = _mm256_max_epi32(vz, v);
  }
  if (p < e) {
    const __m256i v = _mm256_loadu_si256(reinterpret_cast<const __m256i *>(e - 8));
    va = _mm256_min_epi32(va, v);
    vz = _mm256_max_epi32(vz, v);
  }
  hmin_hmax_avx2(va, vz, mm[0], mm[1]);
  _mm256_zeroupper();
}
#endif

// Sorting by rank: the n <= 64 distinct values a[0..n) go to out[#{a_m < a_k}], n times
// n/8 (16-bit: n/16) AVX2 compares, no data-dependent branch. The rows of a host-order
// search (below) come in cell-scan order, ~21 (2D) or ~55 (3D) values interleaved from
// a few runs: an insertion sort mispredicted on most of its moves (a 3D search 15 %
// slower than with the transposition of run_queries; by rank, faster). Without AVX2
// (SSE2's four lanes, MFREE_SIMD=baseline) the rank sort made a repeated 3D search
// 15-35 % slower than the transposition, so the host-order search is AVX2-only.
#if MFREE_SIMD_X86
// NV vectors of eight (n <= 8 NV), padded with INT32_MAX (ranked last, never stored).
template <int NV>
MFREE_TARGET_AVX2 inline void rank_sort_avx2_t(const int32_t *a, int n, int32_t *out) {
  alignas(32) int32_t buf[8 * NV], rank[8 * NV];
  const __m256i iota = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7), vn = _mm256_set1_epi32(n),
                pad = _mm256_set1_epi32(INT32_MAX);
  __m256i r[NV];
#pragma GCC unroll 8
  for (int q = 0; q < NV; ++q) {
    // lanes below n from a (masked lanes are not read), the others INT32_MAX
    const __m256i in = _mm256_cmpgt_epi32(vn, _mm256_add_epi32(iota, _mm256_set1_epi32(8 * q)));
    const __m256i v = _mm256_blendv_epi8(pad, _mm256_maskload_epi32(a + 8 * q, in), in);
    _mm256_store_si256(reinterpret_cast<__m256i *>(buf + 8 * q), v);
    r[q] = _mm256_setzero_si256();
  }
  for (int m = 0; m < n; ++m) {
    const __m256i b = _mm256_set1_epi32(buf[m]);
#pragma GCC unroll 8
    for (int q = 0; q < NV; ++q)
      r[q] = _mm256_sub_epi32(
          r[q], _mm256_cmpgt_epi32(_mm256_load_si256(reinterpret_cast<const __m256i *>(buf + 8 * q)), b));
  }
#pragma GCC unroll 8
  for (int q = 0; q < NV; ++q) _mm256_store_si256(reinterpret_cast<__m256i *>(rank + 8 * q), r[q]);
  for (int k = 0; k < n; ++k) out[rank[k]] = buf[k];
}
// The same on 16-bit offsets from the row's minimum when the row spans fewer than 32767
// host indices (particles in spatial order), sixteen lanes per vector (NV <= 4): half the
// compares. Returns false (nothing written) when the span is wider. Loading, range and
// conversion in vectors (as scalar loops they cost as much as the compares).
template <int NV>
MFREE_TARGET_AVX2 inline bool rank_sort16_avx2_t(const int32_t *a, int n, int32_t *out) {
  const __m256i first = _mm256_set1_epi32(a[0]);  // neutral padding for the range
  const __m256i iota8 = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7), vn8 = _mm256_set1_epi32(n);
  __m256i v32[2 * NV];
#pragma GCC unroll 8
  for (int q = 0; q < 2 * NV; ++q) {
    const __m256i in = _mm256_cmpgt_epi32(vn8, _mm256_add_epi32(iota8, _mm256_set1_epi32(8 * q)));
    v32[q] = _mm256_blendv_epi8(first, _mm256_maskload_epi32(a + 8 * q, in), in);
  }
  __m256i mn = v32[0], mx = v32[0];
#pragma GCC unroll 8
  for (int q = 1; q < 2 * NV; ++q) {
    mn = _mm256_min_epi32(mn, v32[q]);
    mx = _mm256_max_epi32(mx, v32[q]);
  }
  int32_t lo, hi;
  hmin_hmax_avx2(mn, mx, lo, hi);
  if (static_cast<int64_t>(hi) - lo >= INT16_MAX) return false;
  const __m256i vlo = _mm256_set1_epi32(lo), cap = _mm256_set1_epi16(INT16_MAX), vn = _mm256_set1_epi16(
                                                                                    static_cast<int16_t>(n));
  const __m256i iota = _mm256_setr_epi16(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  alignas(32) int16_t buf[16 * NV], rank[16 * NV];
  __m256i v[NV], r[NV];
#pragma GCC unroll 4
  for (int q = 0; q < NV; ++q) {
    // packs works within 128-bit halves: (a0-3 b0-3 a4-7 b4-7), put back in order
    const __m256i p = _mm256_permute4x64_epi64(
        _mm256_packs_epi32(_mm256_sub_epi32(v32[2 * q], vlo), _mm256_sub_epi32(v32[2 * q + 1], vlo)), 0xd8);
    const __m256i idx = _mm256_add_epi16(iota, _mm256_set1_epi16(static_cast<int16_t>(16 * q)));
    v[q] = _mm256_blendv_epi8(cap, p, _mm256_cmpgt_epi16(vn, idx));  // lanes >= n: INT16_MAX
    _mm256_store_si256(reinterpret_cast<__m256i *>(buf + 16 * q), v[q]);
    r[q] = _mm256_setzero_si256();
  }
  for (int m = 0; m < n; ++m) {
    const __m256i b = _mm256_set1_epi16(buf[m]);
#pragma GCC unroll 4
    for (int q = 0; q < NV; ++q) r[q] = _mm256_sub_epi16(r[q], _mm256_cmpgt_epi16(v[q], b));
  }
#pragma GCC unroll 4
  for (int q = 0; q < NV; ++q) _mm256_store_si256(reinterpret_cast<__m256i *>(rank + 16 * q), r[q]);
  for (int k = 0; k < n; ++k) out[rank[k]] = a[k];
  return true;
}
// (Rows of up to 32 take the 32-bit kernel: there the range and the conversion cost more
// than the compares they save.)
MFREE_TARGET_AVX2 void rank_sort_avx2(const int32_t *a, int n, int32_t *out) {
  if (n > 48 && rank_sort16_avx2_t<4>(a, n, out)) {
  } else if (n > 32 && n <= 48 && rank_sort16_avx2_t<3>(a, n, out)) {
  } else if (n <= 16) {
    rank_sort_avx2_t<2>(a, n, out);
  } else if (n <= 24) {  // (2D rows, ~21: 3 % of a 2D search against four vectors)
    rank_sort_avx2_t<3>(a, n, out);
  } else if (n <= 32) {
    rank_sort_avx2_t<4>(a, n, out);
  } else if (n <= 48) {
    rank_sort_avx2_t<6>(a, n, out);
  } else {
    rank_sort_avx2_t<8>(a, n, out);
  }
  _mm256_zeroupper();
}
#endif

}  // namespace

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
};

NeighborScratch *new_neighbor_scratch() { return new NeighborScratch; }
void NeighborScratchDeleter::operator()(NeighborScratch *s) const { delete s; }

namespace {

// Rows for nsites sites visited in `order`: site(s, x) writes the wrapped position of
// site s and returns its search radius, or a negative value for a site without a row.
// Each thread searches a static block of `order` into its own buffer; the rows are
// then placed by site index, so the result does not depend on the thread count.
//
// Sorting: rows arrive in cell order. For a symmetric relation (j in row i iff i in row
// j: uniform radii under gather, or a symmetric convention, every valid particle owning
// a row) the sorted rows are the transpose of the unsorted ones: visiting the sources i
// in ascending order and appending i to the row of each of its neighbours j writes
// every row in ascending order without a comparison (the pair test is bitwise
// symmetric: x_i - x_j = -(x_j - x_i) in IEEE arithmetic, also after the periodic
// shift). Each thread fills a static block of rows, visiting the sources that can reach
// it. Otherwise each row is sorted where it was found.
//
// out is written only after every buffer is in place (its capacity reserved first), so
// an exception (no memory) leaves it unchanged.
template <class Site>
void run_queries(NeighborScratch &sc, const Rule &rule, int32_t nsites, bool symmetric, Site &&site, Csr &out) {
  const CellGrid &grid = sc.grid;
  const int64_t nq = static_cast<int64_t>(sc.order.size());
  if (grid.empty() || nq == 0) {
    out.rowptr.reserve(static_cast<size_t>(nsites) + 1);
    out.rowptr.assign(static_cast<size_t>(nsites) + 1, 0);
    out.cols.clear();
    return;
  }
  const int32_t *order = sc.order.data();
  const int nt = std::min(num_threads(nq), 64);
  Buf<int64_t> &first = sc.first;  // offsets into the buffers
  first.resize(static_cast<size_t>(nq) + 1);
  // smallest and largest member of each row, for the threads of the transposition
  const bool track = symmetric && num_threads(nsites) > 1 && nt > 1;
  if (track) sc.lo_hi.resize(2 * static_cast<size_t>(nsites));
  int32_t *lo_hi = sc.lo_hi.data();
#if MFREE_SIMD_X86
  const bool avx2 = track && simd::use_avx2();
#endif
  auto min_max = [&](const int32_t *b, const int32_t *e, int32_t s) {
    int32_t *mm = lo_hi + 2 * static_cast<size_t>(s);
#if MFREE_SIMD_X86
    if (avx2) {
      row_min_max_avx2(b, e, nsites, mm);
      return;
    }
#endif
    row_min_max(b, e, nsites, mm);
  };
  size_t used[64];
  for_chunks(nt, [&](int t) {
    int64_t b, e;
    thread_block(nq, t, nt, b, e);
    // Room for the expected rows with a margin (growing it copies what was found so far
    // and touches twice the pages: a first search in 3D grew it once). Untouched
    // capacity costs no memory traffic.
    RowBuf &cols = sc.buf[t];
    const size_t room = static_cast<size_t>(e - b) * static_cast<size_t>(1.25 * grid.expected_hits() + 8.0) + 64;
    if (cols.size() < room) {
      cols.clear();  // (the old contents need no copy)
      cols.resize(room);
    }
    size_t cnt = 0;
    // The minimum and maximum of a row are taken one query later: the row was just
    // written entry by entry, and reading it back in 16-byte loads at once would stall
    // on store forwarding (measured: most of the tracking's cost).
    int32_t prev = -1;
    size_t p0 = 0, p1 = 0;
    for (int64_t q = b; q < e; ++q) {
      const int32_t s = order[q];
      double x[3] = {0, 0, 0};
      const double r = site(s, x);
      first[q] = static_cast<int64_t>(cnt);
      if (r < 0.0) continue;
      const size_t r0 = cnt;
      grid.query(x, r, rule, cols, cnt);
      if (!symmetric) {
        sort_row(cols.data() + r0, cols.data() + cnt);
      } else if (track) {
        if (prev >= 0) min_max(cols.data() + p0, cols.data() + p1, prev);
        prev = s;
        p0 = r0;
        p1 = cnt;
      }
    }
    if (prev >= 0) min_max(cols.data() + p0, cols.data() + p1, prev);
    used[t] = cnt;
  });
  // row lengths by site, then prefix sums; each block knows its own buffer's end
  sc.rowptr.resize(static_cast<size_t>(nsites) + 1);
  int64_t *rp = sc.rowptr.data();
  if (symmetric) sc.src.resize(static_cast<size_t>(nsites));
  const int32_t **src = sc.src.data();
  // (every pass over the sites runs on the threads: serial ones bounded the speed-up)
  for_chunks(nt, [&](int t) {
    int64_t b, e;
    thread_block(static_cast<int64_t>(nsites) + 1, t, nt, b, e);
    std::fill(rp + b, rp + e, 0);  // sites without a row (invalid, ghosts) keep 0
  });
  for_chunks(nt, [&](int t) {
    int64_t b, e;
    thread_block(nq, t, nt, b, e);
    for (int64_t q = b; q < e; ++q) {
      const int64_t end = q + 1 < e ? first[q + 1] : static_cast<int64_t>(used[t]);
      rp[order[q] + 1] = end - first[q];
      if (symmetric) src[order[q]] = sc.buf[t].data() + first[q];
    }
  });
  // prefix sums: block totals, their offsets, then each block's running sum
  int64_t part[64];
  for_chunks(nt, [&](int t) {
    int64_t b, e, sum = 0;
    thread_block(nsites, t, nt, b, e);
    for (int64_t s = b; s < e; ++s) sum += rp[s + 1];
    part[t] = sum;
  });
  for (int t = 1; t < nt; ++t) part[t] += part[t - 1];
  for_chunks(nt, [&](int t) {
    int64_t b, e, acc = t > 0 ? part[t - 1] : 0;
    thread_block(nsites, t, nt, b, e);
    for (int64_t s = b; s < e; ++s) rp[s + 1] = acc += rp[s + 1];
  });
  const int64_t nnz = rp[nsites];
  if (request_too_large(static_cast<double>(nnz) * sizeof(int32_t)))
    throw Error(MFREE_ERR_ALLOC, "the neighbour lists would hold " + std::to_string(nnz) +
                                     " pairs, more than the machine's memory: supports too large "
                                     "for the particle spacing?");
  out.rowptr.reserve(static_cast<size_t>(nsites) + 1);
  // (a new block gets room for moves: particles drawing closer add a few pairs)
  if (out.cols.capacity() < static_cast<size_t>(nnz)) out.cols.reserve(static_cast<size_t>(nnz + nnz / 16));
  // nothing below allocates
  if (!symmetric) out.rowptr.assign(rp, rp + nsites + 1);
  else out.rowptr.resize(static_cast<size_t>(nsites) + 1);
  out.cols.resize(static_cast<size_t>(nnz));
  auto place = [&]() {
    for_chunks(nt, [&](int t) {
      int64_t b, e;
      thread_block(nq, t, nt, b, e);
      for (int64_t q = b; q < e; ++q) {
        const int64_t end = q + 1 < e ? first[q + 1] : static_cast<int64_t>(used[t]);
        int32_t *o = out.cols.data() + rp[order[q]];
        std::copy(sc.buf[t].begin() + first[q], sc.buf[t].begin() + end, o);
        if (symmetric) sort_row(o, o + (end - first[q]));
      }
    });
  };
  if (!symmetric) {
    place();
    return;
  }
  // Transpose. cur[j] = out.rowptr[j + 1] is the next free position of row j, from rp[j]
  // on; a complete row leaves it at its end rp[j + 1], which is what out.rowptr must
  // hold (the CSR transposition's shifted row pointers: no separate cursor array, no
  // copy). A source that would overfill a row or leave one short (an asymmetric pair,
  // which the conditions above exclude: a safety net, not a proof) leaves some cursor
  // off its end; the rows are then placed and sorted instead. Writes stay inside the
  // thread's own rows [rp[jb], rp[je]) whatever happens.
  int64_t *cur = out.rowptr.data() + 1;
  out.rowptr[0] = 0;
  const int ntt = num_threads(nsites) < nt ? num_threads(nsites) : nt;
  char bad[64] = {0};
  for_chunks(ntt, [&](int t) {
    int64_t jb, je;
    thread_block(nsites, t, ntt, jb, je);
    if (jb >= je) return;
    for (int64_t j = jb; j < je; ++j) cur[j] = rp[j];
    // sources that reach rows [jb, je): by symmetry, the members of those rows
    int64_t imin = 0, imax = nsites - 1;
    if (ntt > 1) {
      imin = nsites;
      imax = -1;
      for (int64_t j = jb; j < je; ++j)
        if (rp[j + 1] > rp[j]) {
          imin = std::min<int64_t>(imin, lo_hi[2 * j]);
          imax = std::max<int64_t>(imax, lo_hi[2 * j + 1]);
        }
    }
    int32_t *cols = out.cols.data();
    const uint64_t span = static_cast<uint64_t>(je - jb);
    const bool all = jb == 0 && je == nsites;
    const int64_t lim = rp[je];
    for (int64_t i = imin; i <= imax; ++i) {
      const int32_t *r = src[i];
      const int64_t len = rp[i + 1] - rp[i];
      for (int64_t k = 0; k < len; ++k) {
        const int64_t j = r[k];
        if (!all && static_cast<uint64_t>(j - jb) >= span) continue;
        const int64_t c = cur[j]++;
        if (c < lim) cols[c] = static_cast<int32_t>(i);
      }
    }
    bool over = false;
    for (int64_t j = jb; j < je; ++j) over = over || cur[j] != rp[j + 1];
    bad[t] = over;
  });
  for (int t = 0; t < ntt; ++t)
    if (bad[t]) {
      out.rowptr.assign(rp, rp + nsites + 1);  // same size: no allocation
      place();
      return;
    }
}

#if MFREE_SIMD_X86
// One row of the host-order search: find(j, tmp) queries the grid for particle j into
// tmp and returns the count; sort_into writes such a row sorted to o.
struct HostRow {
  const CellGrid &grid;
  const ParticleSet &ps;
  const Rule &rule;
  // (asked once: strided access, the query's kind)
  const double *X = ps.pos_data(), *H = ps.h_data();
  const int64_t si = ps.pos_step_i(), sc = ps.pos_step_c(), sh = ps.h_step();
  const int dim = ps.dim(), kind = grid.avx2_kind(rule);
  const double kappa = ps.kappa();
  size_t find(int32_t j, RowBuf &tmp) const {
    double x[3] = {0, 0, 0};
    for (int c = 0; c < dim; ++c) x[c] = grid.wrap(X[j * si + c * sc], c);
    size_t cnt = 0;
    grid.query_avx2(kind, x, kappa * H[j * sh], rule, tmp, cnt);  // (the radius the grid was built from)
    return cnt;
  }
  static void sort_into(int32_t *t, size_t cnt, int32_t *o) {
    if (cnt > 64) {
      std::sort(t, t + cnt);
      std::copy(t, t + cnt, o);
    } else {
      rank_sort_avx2(t, static_cast<int>(cnt), o);
    }
  }
};

// Lists built in host order straight into out, on one thread: row j is the query of
// particle j, sorted, appended at rp[j] (every earlier row's length is known by then).
// No row buffers, no cell-order permutation, no transposition: a first search of a new
// set touches the lists, the grid and nothing else (the buffers, offsets and row
// pointers of run_queries were more than half of the fresh memory a first search
// faulted: 2D 10^5 246 -> 134 bytes per particle, 3D 525 -> 278). The price is that the
// queries run in host order: as fast as in cell order when host-consecutive particles
// are spatial neighbours (lattice or curve order; the caller checks), not otherwise
// once the grid outgrows the caches. Rows are sorted by rank (rank_sort_avx2: no
// data-dependent branch; an insertion sort mispredicted on most moves of a 3D row).
//
// A set's first lists get the expected rows with a margin as capacity before anything
// is written (a failure there leaves out unchanged); a later search allocates only when
// its rows outgrow the storage. Growing copies (doubling); if that allocation fails, out
// is left with no rows ({0}) and the exception propagates (ParticleSet::setup then
// marks the set not set up). The new lists take
// small pages: on the issue-8 VM a huge page first touched by the search costs more than
// its small pages when the host must back it anew (alloc.hpp, SmallPages), and the
// lists are read front to back afterwards (the TLB reach of huge pages buys little).
void host_order_rows(const CellGrid &grid, const ParticleSet &ps, const std::vector<int32_t> &status,
                     const Rule &rule, RowBuf &tmp, Csr &out) {
  const int32_t rows = ps.num_owned();
  const HostRow row{grid, ps, rule};
  const size_t est = static_cast<size_t>(rows) * static_cast<size_t>(1.25 * grid.expected_hits() + 8.0);
  if (out.rowptr.capacity() < static_cast<size_t>(rows) + 1) {
    out.rowptr.reserve(static_cast<size_t>(rows) + 1);
    prefault(out.rowptr.data(), (static_cast<size_t>(rows) + 1) * sizeof(int64_t));
  }
  if (out.cols.capacity() == 0) {  // (later searches grow only when the rows outgrow it)
    SmallPages small;
    out.cols.reserve(est);
  }
  out.rowptr.resize(static_cast<size_t>(rows) + 1);
  int64_t *rp = out.rowptr.data();
  rp[0] = 0;
  // Entries below cols.size() exist (a repeated search: the old lists) and are simply
  // overwritten; new ones are added in chunks (the value-initialising resize zero-fills
  // them first, in cache, right after their first touch).
  size_t have = out.cols.size();
  int32_t *cols = out.cols.data();
  const size_t chunk = std::min<size_t>(65536, std::max<size_t>(4096, est / 32));
  // Any exception from here on (the row buffer or the lists growing) leaves out with no
  // rows: its row pointers are already being rewritten. (The row buffer's growth was
  // outside this guard: a repeated search whose rows outgrew it and ran out of memory
  // left half-written lists that still counted as set up.)
  try {
    for (int32_t j = 0; j < rows; ++j) {
      const int64_t base = rp[j];
      if (status[j] != 0) {
        rp[j + 1] = base;  // no row
        continue;
      }
      const size_t cnt = row.find(j, tmp);
      const int64_t end = base + static_cast<int64_t>(cnt);
      rp[j + 1] = end;
      if (static_cast<size_t>(end) > have) {
        size_t want = std::max(static_cast<size_t>(end), have + chunk);
        if (want > out.cols.capacity()) {
          size_t grow = std::max(want, 2 * out.cols.capacity());
          if (request_too_large(static_cast<double>(grow) * sizeof(int32_t))) grow = want;
          if (request_too_large(static_cast<double>(grow) * sizeof(int32_t)))
            throw Error(MFREE_ERR_ALLOC, "the neighbour lists outgrow the machine's memory after " +
                                             std::to_string(end) + " pairs: supports too large for "
                                             "the particle spacing?");
          SmallPages small;
          out.cols.reserve(grow);
        }
        want = std::min(want, out.cols.capacity());
        prefault(out.cols.data() + have, (want - have) * sizeof(int32_t));
        out.cols.resize(want);
        have = want;
        cols = out.cols.data();
      }
      HostRow::sort_into(tmp.data(), cnt, cols + base);
    }
  } catch (...) {
    out.rowptr.assign(1, 0);  // (shrinks: no allocation)
    out.cols.clear();
    throw;
  }
  out.cols.resize(static_cast<size_t>(rp[rows]));
}

// host_order_rows on several threads: static blocks of rows in host order, each thread
// writing its block's sorted rows straight into the spare lists sc.next from a guessed
// offset g[t] (the block's offset in the current lists when the set was set up before
// with as many rows: exact for particles that did not move; otherwise a share of the
// storage), as far as the room up to the next block's guess allows, the rest of the
// block into its own buffer sc.buf[t]. When every guess was right and nothing spilled,
// the lists are done; otherwise the blocks are moved into place (memmove: right-moving
// blocks last to first, then the others first to last, so that no block overwrites one
// not yet moved) and the row ends of the moved blocks shifted. Then the spare lists and
// out swap storage. (Before: every block into its buffer, then all copied into place,
// 9 ms of 80 (2D) and 20 of 330 (3D) at 10^6 on two threads; a repeated search of a
// set at rest now moves nothing.) The same lists as on one thread: the same rows,
// sorted. out changes only by the final swap, so running out of memory leaves it
// unchanged.
void host_order_blocks(const CellGrid &grid, const ParticleSet &ps, const std::vector<int32_t> &status,
                       const Rule &rule, NeighborScratch &sc, Csr &out, int nt) {
  const int32_t rows = ps.num_owned();
  const HostRow row{grid, ps, rule};
  const int nb = block_count(nt);
  int64_t first[kMaxBlocks + 1];
  for (int t = 0; t < nb; ++t) {
    int64_t b, e;
    thread_block(rows, t, nb, b, e);
    first[t] = b;
  }
  first[nb] = rows;
  const bool again = out.rowptr.size() == static_cast<size_t>(rows) + 1;
  const double per_row = 1.25 * grid.expected_hits() + 8.0;
  Csr &nx = sc.next;
  if (nx.cols.capacity() == 0) {
    SmallPages small;
    nx.cols.reserve(static_cast<size_t>(static_cast<double>(rows) * per_row));
  }
  nx.rowptr.resize(static_cast<size_t>(rows) + 1);
  const int64_t cap = static_cast<int64_t>(nx.cols.capacity());
  int64_t g[kMaxBlocks + 1];
  for (int t = 0; t < nb; ++t)
    g[t] = again ? std::min(out.rowptr[static_cast<size_t>(first[t])], cap)
                 : (rows > 0 ? static_cast<int64_t>(static_cast<double>(cap) * static_cast<double>(first[t]) /
                                                    static_cast<double>(rows))
                             : 0);
  g[0] = 0;
  g[nb] = cap;
  for (int t = 1; t <= nb; ++t) g[t] = std::max(g[t], g[t - 1]);
  int64_t used[kMaxBlocks] = {}, inpl[kMaxBlocks] = {};
  {
    nx.cols.resize(static_cast<size_t>(cap));  // (zero-fills only storage never used before)
    int64_t *rp = nx.rowptr.data();
    int32_t *cols = nx.cols.data();
    rp[0] = 0;
    parallel_blocks(rows, nt, [&](int t, int64_t b, int64_t e) {
      RowBuf &spill = sc.buf[t], &tmp = sc.row[t];
      // (room for rows that outgrow the guess, so that the small changes of a moving
      // set allocate nothing after its first search)
      if (spill.capacity() == 0) spill.reserve(static_cast<size_t>(static_cast<double>(e - b) * per_row / 16.0) + 64);
      const int64_t off = g[t], room = g[t + 1] - g[t];
      int32_t *dst = cols + off;
      int64_t end = 0, in = -1;  // in >= 0: rows from end = in on go to spill
      for (int64_t j = b; j < e; ++j) {
        if (status[j] == 0) {
          const size_t cnt = row.find(static_cast<int32_t>(j), tmp);
          const int64_t c = static_cast<int64_t>(cnt);
          if (in < 0 && end + c > room) in = end;
          if (in < 0) {
            HostRow::sort_into(tmp.data(), cnt, dst + end);
          } else {
            const size_t o = static_cast<size_t>(end - in);
            if (o + cnt > spill.size()) spill.resize(std::max(2 * spill.size(), o + cnt));
            HostRow::sort_into(tmp.data(), cnt, spill.data() + o);
          }
          end += c;
        }
        rp[j + 1] = off + end;
      }
      used[t] = end;
      inpl[t] = in < 0 ? end : in;
    });
    int64_t base[kMaxBlocks + 1];
    base[0] = 0;
    bool moved = false;
    for (int t = 0; t < nb; ++t) {
      base[t + 1] = base[t] + used[t];
      moved = moved || base[t] != g[t] || inpl[t] != used[t];
    }
    if (moved) {
      if (base[nb] > cap) {  // (keeps the entries where they are)
        nx.cols.reserve(static_cast<size_t>(base[nb] + base[nb] / 16));
        nx.cols.resize(static_cast<size_t>(base[nb]));
        cols = nx.cols.data();
      }
      auto place = [&](int t) {
        if (base[t] != g[t] && inpl[t] > 0)
          std::memmove(cols + base[t], cols + g[t], static_cast<size_t>(inpl[t]) * sizeof(int32_t));
        if (used[t] > inpl[t])
          std::memcpy(cols + base[t] + inpl[t], sc.buf[t].data(), static_cast<size_t>(used[t] - inpl[t]) * sizeof(int32_t));
      };
      for (int t = nb - 1; t >= 0; --t)
        if (base[t] > g[t]) place(t);
      for (int t = 0; t < nb; ++t)
        if (base[t] <= g[t]) place(t);
      parallel_blocks(rows, nt, [&](int t, int64_t b, int64_t e) {
        const int64_t d = base[t] - g[t];
        if (d != 0)
          for (int64_t j = b; j < e; ++j) rp[j + 1] += d;
      });
    }
    nx.cols.resize(static_cast<size_t>(base[nb]));  // (shrinks: no allocation)
  }
  std::swap(out.rowptr, nx.rowptr);
  std::swap(out.cols, nx.cols);
}
#endif

}  // namespace

void find_neighbors(const ParticleSet &ps, const std::vector<int32_t> &status, NeighborScratch &sc, Csr &out) {
  const int32_t rows = ps.num_owned();
  sc.grid.build(ps, status);
  const CellGrid &grid = sc.grid;
  const Rule rule{ps.search_convention(), grid.rmax()};
  // AVX2, particles stored in spatial order: in host order, on one thread straight into
  // out, on more through one buffer per thread.
#if MFREE_SIMD_X86
  if (!grid.empty() && simd::use_avx2() && grid.host_locality(ps.size()) >= 0.75) {
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
                return ps.kappa() * ps.h(i);  // (what the grid's radii were built from)
              },
              out);
}

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
