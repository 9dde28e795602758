// Particle set: borrowed or copied host arrays, validation, neighbour lists.
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/base/alloc.hpp"
#include "core/base/error.hpp"
#include "mfree.h"

namespace mfree {

// A strided view of n scalars, or of n items with ncomp components (AoS/SoA), that
// either points into host memory or into its own copy.
struct ScalarArray {
  const double *ptr = nullptr;
  int64_t stride = 1;  // 0: one value for all
  HVec<double> own;  // (from the context's hook, like every copy of host data)
  bool set() const { return ptr != nullptr; }
  double operator()(int64_t i) const { return ptr[i * stride]; }
};

struct VectorArray {
  const double *ptr = nullptr;
  int64_t ld = 0;
  int layout = MFREE_LAYOUT_AOS;
  HVec<double> own;
  bool set() const { return ptr != nullptr; }
  double operator()(int64_t i, int c) const {
    return layout == MFREE_LAYOUT_AOS ? ptr[i * ld + c] : ptr[c * ld + i];
  }
};

// MFREE_ERR_ARG when the last of n items (ncomp components each, layout and leading
// dimension ld) or of n scalars (stride) lies beyond what a 64-bit byte offset reaches:
// the index would wrap and read elsewhere. `what` names the array in the message.
void check_extent(int64_t n, int64_t ncomp, int layout, int64_t ld, const char *what);
void check_stride(int64_t n, int64_t stride, const char *what);

// CSR adjacency, 0-based, one row per owned particle.
struct Csr {
  HVec<int64_t> rowptr = HVec<int64_t>(1, 0);
  HVec<int32_t> cols;
  int64_t nnz() const { return rowptr.empty() ? 0 : rowptr.back(); }
};

// Grid and buffers of the cell-list search, kept between searches (neighbors.hpp).
struct NeighborScratch;
struct NeighborScratchDeleter {
  void operator()(NeighborScratch *s) const;
};

class ParticleSet {
 public:
  ParticleSet(int dim, int32_t n);

  int dim() const { return dim_; }
  int32_t size() const { return n_; }
  int32_t num_ghost() const { return n_ghost_; }
  int32_t num_owned() const { return n_ - n_ghost_; }

  void set_num_ghost(int32_t g);
  void set_positions(const double *x, int layout, int64_t ld, int mem);
  void set_volumes(const double *v, int64_t stride, int mem);
  void set_masses(const double *m, int64_t stride, int mem);
  void set_densities(const double *rho, int64_t stride, int mem);
  void set_support(const double *h, int64_t stride, int mem);
  void set_search(int convention, double kappa);
  // Verlet skin of the search (0, the default: none). With skin s > 0 a setup that
  // searches keeps candidate lists of radius kappa h + s, and later setups filter their
  // rows from them until some particle has moved (or grown its radius) by more than s / 2
  // since they were built (neighbors_verlet.inc): the rows are always a fresh search's.
  void set_search_skin(double skin);
  double search_skin() const { return skin_; }
  // Searches run by setups so far (with a skin: builds of the candidate lists).
  int64_t search_count() const;
  // The candidate lists the last setup filtered its rows from (rows of the owned
  // particles, sorted by index, each holding its row of neighbors(); the same lists
  // until search_count() changes); neighbors() itself after a setup without them.
  const Csr &search_candidates() const;
  // Rows left to the caller (off by default), for a host that filters the candidate lists
  // in its own pass over them (the fluid's fused rows of linear MLS): with a skin, a setup
  // whose rows would be filtered from the candidates in 2D (gather convention, no
  // periodic axis, every particle valid, positions (x, y) packed, no global ids, the AVX2
  // copy) then leaves them unfiltered, rows_left() is true and neighbors() has empty
  // rows; the caller keeps the candidates of search_candidates() by pair_test.hpp's test
  // (the same rows as the set's filter). Other setups filter as usual.
  void set_rows_left(bool on) { rows_left_ = on; }
  bool rows_left_wanted() const { return rows_left_ && !gid_; }
  bool rows_left() const;
  void set_periodic(const double *lo, const double *hi, const int32_t *periodic);
  void set_neighbors(const int64_t *rowptr, const int32_t *cols, int32_t base, int mem);
  // Global ids (NULL: none) and the host's halo width (0: none declared).
  void set_global_ids(const int64_t *ids, int mem);
  void set_halo_width(double w);
  // A host half pair list (each unordered pair once, any order; pairs.cpp): the rows
  // are built from it at setup, in O(npairs), without a search.
  void set_pairs(int64_t npairs, const int32_t *pi, const int32_t *pj, int32_t base, int mem);

  // Validate (and for a search, rebuild the lists). Negative failures throw.
  Report setup();
  Report update();

  bool is_setup() const { return setup_done_; }
  // Successful setups so far: objects built on the set tell whether their pattern is
  // from the current lists.
  int64_t setup_count() const { return setups_; }
  // The status particle i's data would get now (0, MFREE_FAIL_NONFINITE or
  // MFREE_FAIL_INVALID_DATA), re-read from the possibly borrowed arrays.
  int32_t data_status(int32_t i) const;
  const Csr &neighbors() const { return nbr_; }
  const std::vector<int32_t> &site_status() const { return site_status_; }

  double x(int32_t i, int c) const { return pos_(i, c); }
  double h(int32_t i) const { return h_(i); }
  // The same values for tight loops, without the layout test per access:
  // x(i, c) == pos_data()[i * pos_step_i() + c * pos_step_c()], h(i) == h_data()[i * h_step()].
  const double *pos_data() const { return pos_.ptr; }
  int64_t pos_step_i() const { return pos_.layout == MFREE_LAYOUT_AOS ? pos_.ld : 1; }
  int64_t pos_step_c() const { return pos_.layout == MFREE_LAYOUT_AOS ? 1 : pos_.ld; }
  const double *h_data() const { return h_.ptr; }
  int64_t h_step() const { return h_.stride; }
  bool has_support() const { return h_.set(); }
  bool has_volumes() const { return vol_.set() || (mass_.set() && rho_.set()); }
  double volume(int32_t i) const { return vol_.set() ? vol_(i) : mass_(i) / rho_(i); }

  int search_convention() const { return convention_; }
  double kappa() const { return kappa_; }
  bool periodic(int c) const { return periodic_[c]; }
  double box_lo(int c) const { return lo_[c]; }
  double box_hi(int c) const { return hi_[c]; }
  bool host_neighbors() const { return host_rowptr_ != nullptr || pairs_.set; }
  bool has_pairs() const { return pairs_.set; }
  int64_t num_pairs() const { return pairs_.n; }
  int32_t pair_base() const { return pairs_.base; }
  // Pair k joins particles pair_first()[k] - base and pair_second()[k] - base.
  const int32_t *pair_first() const { return pairs_.i; }
  const int32_t *pair_second() const { return pairs_.j; }
  // After setup, per pair k: where the second particle sits in the first one's row of
  // neighbors() (offset within the row, entry 2k), and the first in the second's row
  // (entry 2k + 1); -1 when that particle has no row (a ghost or an isolated particle).
  const std::vector<int32_t> &pair_offsets() const { return pair_off_; }
  bool has_global_ids() const { return gid_ != nullptr; }
  const int64_t *global_ids() const { return gid_; }
  double halo_width() const { return halo_; }
  // With global ids, each row of rows (columns are particle indices) reordered by
  // ascending global id, so that every sum over a row runs in one order whatever the
  // local numbering; without ids rows are left as they are (sorted by index). The const
  // form (rows of host points) works in scratch of its own.
  struct RowOrderScratch {
    std::vector<int64_t> start, fill;
    std::vector<int32_t> owner;
  };
  void order_rows_by_id(Csr &rows, RowOrderScratch &scratch) const;
  void order_rows_by_id(Csr &rows) const {
    RowOrderScratch scratch;
    order_rows_by_id(rows, scratch);
  }
  // Throws MFREE_ERR_HALO when a declared halo width is narrower than the radius r(s)
  // that site s of the valid owned particles reaches (what: the radius' name).
  template <class Radius>
  void check_halo(Radius r, const char *what) const;

  // Displacement x_i - x_j with the nearest image along periodic axes.
  void displacement(int32_t i, int32_t j, double *d) const {
    for (int c = 0; c < dim_; ++c) {
      double v = pos_(i, c) - pos_(j, c);
      if (periodic_[c]) {
        const double L = hi_[c] - lo_[c];
        v -= L * std::nearbyint(v / L);
      }
      d[c] = v;
    }
  }

 private:
  void set_scalar(ScalarArray &a, const double *v, int64_t stride, int mem, const char *what);
  // Mark particles whose borrowed data are invalid; returns the report.
  Report validate();
  void check_host_csr(const int64_t *rowptr, const int32_t *cols, int32_t base) const;
  // pairs.cpp: range and self-pair checks; the rows (and pair offsets) from the pairs,
  // duplicates rejected.
  void check_pairs(int64_t npairs, const int32_t *pi, const int32_t *pj, int32_t base) const;
  void rows_from_pairs(Csr &out, std::vector<int32_t> &offsets);

  int dim_;
  int32_t n_;
  int32_t n_ghost_ = 0;
  VectorArray pos_;
  ScalarArray vol_, mass_, rho_, h_;
  int convention_ = MFREE_SEARCH_GATHER;
  double kappa_ = 2.0;
  double skin_ = 0.0;
  bool rows_left_ = false;
  bool periodic_[3] = {false, false, false};
  double lo_[3] = {0, 0, 0}, hi_[3] = {0, 0, 0};

  const int64_t *host_rowptr_ = nullptr;
  const int32_t *host_cols_ = nullptr;
  int32_t host_base_ = 0;
  int32_t host_rows_ = 0;  // owned count when the host lists were set
  HVec<int64_t> host_rowptr_own_;
  HVec<int32_t> host_cols_own_;

  // global ids: n values, borrowed or in gid_own_. gid_perm_ lists the particles in
  // ascending id order (the duplicate check's sort, and the order rows are rebuilt in);
  // gid_perm_next_ is where a check sorts before it succeeds. Both, and the row-order
  // scratch, are kept so that a repeated setup allocates nothing.
  const int64_t *gid_ = nullptr;
  HVec<int64_t> gid_own_;
  HVec<int32_t> gid_perm_, gid_perm_next_;
  RowOrderScratch row_order_;
  void check_global_ids(const int64_t *ids);
  double halo_ = 0.0;
  struct PairList {
    bool set = false;
    const int32_t *i = nullptr, *j = nullptr;
    int64_t n = 0;
    int32_t base = 0;
    std::vector<int32_t> own_i, own_j;
  } pairs_;
  std::vector<int32_t> pair_off_, pair_off_next_;
  // rows_from_pairs' work arrays, kept so that a setup every step allocates nothing
  std::vector<int64_t> pair_start_, pair_fill_;
  std::vector<int32_t> pair_tmp_col_;
  std::vector<int64_t> pair_tmp_id_;
  std::vector<int32_t> pair_tmp_id32_;

  bool setup_done_ = false;
  int64_t setups_ = 0;
  Csr nbr_;
  Csr pair_rows_;  // the next rows built from pairs (storage reused, swapped with nbr_)
  std::vector<int32_t> site_status_;
  // The statuses before the running setup/update, kept as a member (sized at setup) so
  // that update allocates nothing.
  std::vector<int32_t> prev_status_;
  // The search's grid and buffers, created at the first search and reused by the next
  // ones (same sizes: no allocation, no page faults).
  std::unique_ptr<NeighborScratch, NeighborScratchDeleter> scratch_;
};

template <class Radius>
void ParticleSet::check_halo(Radius r, const char *what) const {
  if (halo_ <= 0.0) return;
  const int32_t no = num_owned();
  for (int32_t i = 0; i < no; ++i) {
    if (!site_status_.empty() && site_status_[i] != 0) continue;
    const double ri = r(i);
    if (ri > halo_)
      throw Error(MFREE_ERR_HALO, "owned particle " + std::to_string(i) +
                                      (gid_ ? " (global id " + std::to_string(gid_[i]) + ")" : std::string()) +
                                      ": its " + what + " " + std::to_string(ri) +
                                      " reaches past the declared halo width " + std::to_string(halo_) +
                                      " (mfree_particles_set_halo_width): rows would miss ghosts");
  }
}

}  // namespace mfree
