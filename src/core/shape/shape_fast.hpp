// Specialised per-site shape functions for the common value + gradient tables:
// one template per (dimension, kernel shape, method family, basis order), SoA neighbour
// data gathered once per site, the kernel shape inlined for the cubic spline, moments
// accumulated as sums of monomials in one neighbour pass, fixed-size factorisations that
// repeat the general path's pivoting and condition estimate (so statuses and reported
// condition numbers agree to round-off; test t432). Everything it does not cover (Hessians, MSPH, KB
// Methods 2 and 3, order 3, sign-changing kernels) stays on the general path of
// local.cpp, and a site it cannot finish (any non-zero status) is recomputed there from
// scratch, so that statuses, fallbacks and failure rows are those of the general path.
#pragma once

#include <cstdint>

#include "core/base/alloc.hpp"
#include "core/base/kernel.hpp"

namespace mfree {

// Borrowed views of one approximant's data for the fast path.
struct FastTables {
  const int64_t *rowptr = nullptr;
  const int32_t *cols = nullptr;
  const int32_t *self = nullptr;  // position of the site in its row, -1 at host points
  // particles, one record of `stride` doubles each: coordinate c of particle j at
  // x[c][j * stride] with x[c] == x[0] + c, volume (1 when the set has none)
  // vol[j * stride]; support h[j * hstride] (in the record or after the records)
  const double *x[3] = {nullptr, nullptr, nullptr};
  const double *vol = nullptr;
  const double *h = nullptr;
  int64_t stride = 1, hstride = 1;
  // sites (the particles themselves or host points), likewise with sstride, shstride
  const double *sx[3] = {nullptr, nullptr, nullptr};
  const double *sh = nullptr;
  int64_t sstride = 1, shstride = 1;
  int convention = MFREE_SEARCH_GATHER;
  bool periodic[3] = {false, false, false};
  double period[3] = {0, 0, 0};
  double *val = nullptr;   // nullptr when the value table is not built
  double *grad = nullptr;  // nullptr when the gradient table is not built
  // When set, the sites' correction records (ncoef doubles each, the layout of
  // mfree_approximant_get_correction) of Shepard, MLS/RKPM, Johnson-Beissel,
  // Randles-Libersky and KB Method 1, written by the sites the fast path finishes outside the fused rows;
  // the others' are left as they were.
  double *coef = nullptr;
  int64_t ncoef = 0;
  // Rows to filter (kept != nullptr; only where FastPath::filters_rows()): rowptr and
  // cols are a particle set's candidate lists that it left to the caller
  // (ParticleSet::set_rows_left), the sites its particles, kappa its search radius factor.
  // Site s keeps the candidates within kappa sh[s] by the search's pair test
  // (pair_test.hpp), in their order, at kept[rowbeg[s] .. rowend[s]), and its values and
  // gradients at the same entries: the rows of a call's sites [b, e) one after the other
  // from rowptr[b] (compacted: the tables' entries in use stay together). The same rows
  // and tables as from the set's own filter.
  int32_t *kept = nullptr;
  int64_t *rowbeg = nullptr, *rowend = nullptr;
  double kappa = 0.0;
};

// Per-thread scratch, sized for the longest row before the sites are computed: fourteen
// arrays of SoA neighbour data, d(0) .. d(13) (cap >= the longest row rounded up to
// whole groups of four; the corrected rows: two sets of six, of seven for KB 1 in 3D), and a
// staging area for one row of values and up to three gradients.
struct FastScratch {
  HVec<double> buf, sval, sgrad;
  int cap = 0;
  void reserve(int maxrow);
  double *d(int c) { return buf.data() + static_cast<size_t>(c) * cap; }
  double *w() { return d(3); }
  double *gf() { return d(4); }
  double *v() { return d(5); }
  double *a() { return d(6); }  // method-specific (Shepard values)
  double *b(int c) { return d(7 + c); }  // method-specific (Shepard gradients)
};

// Per-site results of a block of sites. A site whose particle failed in the set gets
// that status (support 0, cond 1, order -1); a site the fast path cannot finish gets
// kFastPending (its rows are garbage) for the general path to recompute.
constexpr int32_t kFastPending = -0x7fffffff;
struct FastSites {
  int32_t *status = nullptr, *support = nullptr, *order = nullptr;
  double *cond = nullptr;
  const int32_t *pst = nullptr;  // particle status per site (nullptr at host points)
  int order_used = 0;            // reported for the sites done here
};

class FastPath {
 public:
  // Selects the specialised code for this configuration; ok() is false when the general
  // path must be used for every site.
  FastPath(int dim, int method, int order, const Kernel &kernel, int flags);
  bool ok() const { return fn_ != nullptr; }
  // Whether run() filters rows (FastTables::kept) for value + gradient tables without
  // correction records under the gather convention without a periodic axis: the fused
  // rows of linear MLS in 2D with the cubic spline (shape_fast_mls1.hpp).
  bool filters_rows() const { return filters_; }

  // Rows of the sites [b, e) and their entries of out (see FastSites); the scratch is
  // reserved for the longest row. support: neighbours with non-zero weight; cond:
  // condition estimate of the local system as the general path reports it (1 when none).
  // The rows of every site are written (garbage for pending ones) and visible to other
  // threads once the call returns.
  void run(const FastTables &t, int64_t b, int64_t e, FastScratch &w, const FastSites &out) const {
    fn_(*this, t, b, e, w, out);
  }

  int method() const { return method_; }
  int order() const { return order_; }
  const Kernel &kernel() const { return *kernel_; }

 private:
  using Fn = void (*)(const FastPath &, const FastTables &, int64_t, int64_t, FastScratch &,
                     const FastSites &);
  Fn fn_ = nullptr;
  bool filters_ = false;
  int method_;
  int order_;
  const Kernel *kernel_;
};

}  // namespace mfree
