#include "core/particles/particles.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "core/base/parallel.hpp"
#include "core/base/simd.hpp"
#include "core/particles/neighbors.hpp"

namespace mfree {

namespace {

std::string fmt_index(const char *what, int64_t i, double v) {
  std::ostringstream s;
  s << what << "[" << i << "] = " << v;
  return s.str();
}

void check_mem(int mem) {
  if (mem != MFREE_COPY && mem != MFREE_BORROW)
    throw Error(MFREE_ERR_ARG, "mem must be MFREE_COPY or MFREE_BORROW, got " + std::to_string(mem));
}

}  // namespace

ParticleSet::ParticleSet(int dim, int32_t n) : dim_(dim), n_(n) {
  if (dim < 1 || dim > 3)
    throw Error(MFREE_ERR_ARG, "dimension " + std::to_string(dim) + " is not 1, 2 or 3");
  if (n < 0) throw Error(MFREE_ERR_ARG, "particle count " + std::to_string(n) + " is negative");
  nbr_.rowptr.assign(1, 0);
}

void ParticleSet::set_num_ghost(int32_t g) {
  if (g < 0 || g > n_)
    throw Error(MFREE_ERR_ARG, "ghost count " + std::to_string(g) + " is outside [0, n = " +
                                   std::to_string(n_) + "]");
  n_ghost_ = g;
  setup_done_ = false;
}

void check_extent(int64_t n, int64_t ncomp, int layout, int64_t ld, const char *what) {
  // Largest element index an int64 byte offset can reach: beyond it, i * ld wraps.
  const int64_t lim = INT64_MAX / static_cast<int64_t>(sizeof(double));
  const int64_t items = layout == MFREE_LAYOUT_AOS ? n : ncomp;  // how many times ld is stepped
  const int64_t inner = layout == MFREE_LAYOUT_AOS ? ncomp : n;  // entries within one step
  if (items <= 1 || inner <= 0) return;
  if (ld > (lim - (inner - 1)) / (items - 1))
    throw Error(MFREE_ERR_ARG, std::string("leading dimension ") + std::to_string(ld) + " of " + what +
                                   " is too large: the last entry's offset overflows a 64-bit index");
}

void check_stride(int64_t n, int64_t stride, const char *what) {
  const int64_t lim = INT64_MAX / static_cast<int64_t>(sizeof(double));
  if (n > 1 && stride > lim / (n - 1))
    throw Error(MFREE_ERR_ARG, std::string(what) + " stride " + std::to_string(stride) +
                                   " is too large: the last entry's offset overflows a 64-bit index");
}

void ParticleSet::set_positions(const double *x, int layout, int64_t ld, int mem) {
  check_mem(mem);
  if (layout != MFREE_LAYOUT_AOS && layout != MFREE_LAYOUT_SOA)
    throw Error(MFREE_ERR_ARG, "unknown layout " + std::to_string(layout));
  const int64_t need = layout == MFREE_LAYOUT_AOS ? dim_ : n_;
  if (ld < need)
    throw Error(MFREE_ERR_ARG, "leading dimension " + std::to_string(ld) + " is below " +
                                   std::to_string(need) +
                                   (layout == MFREE_LAYOUT_AOS ? " (dim)" : " (n)"));
  check_extent(n_, dim_, layout, ld, "the positions");
  if (x == nullptr && n_ > 0) throw Error(MFREE_ERR_NULL, "positions pointer is NULL");
  VectorArray v;
  v.ptr = x;
  v.ld = ld;
  v.layout = layout;
  // (one pass without a branch over a packed array, the common case of a time loop that
  // hands its state each step; the culprit is looked for only when it fails)
  const bool packed = ld == need && x != nullptr;
  if (!packed || !simd::all_finite(x, static_cast<int64_t>(n_) * dim_))
    for (int32_t i = 0; i < n_; ++i)
      for (int c = 0; c < dim_; ++c)
        if (!std::isfinite(v(i, c))) {
          std::ostringstream s;
          s << "position of particle " << i << ", component " << c << " is " << v(i, c);
          throw Error(MFREE_ERR_INPUT, s.str());
        }
  // The new array is made aside and swapped in (no exception after the first change):
  // running out of memory leaves the set as it was.
  HVec<double> own;
  if (mem == MFREE_COPY) {
    own.resize(std::max<size_t>(static_cast<size_t>(n_) * dim_, 1));
    for (int32_t i = 0; i < n_; ++i)
      for (int c = 0; c < dim_; ++c) own[static_cast<size_t>(i) * dim_ + c] = v(i, c);
    v.ptr = own.data();
    v.ld = dim_;
    v.layout = MFREE_LAYOUT_AOS;
  } else if (x == nullptr) {
    own.assign(1, 0.0);  // a zero-particle set still needs a non-NULL marker that positions were given
    v.ptr = own.data();
  }
  pos_.own.swap(own);
  pos_.ptr = v.ptr;
  pos_.ld = v.ld;
  pos_.layout = v.layout;
  setup_done_ = false;
}

void ParticleSet::set_scalar(ScalarArray &a, const double *v, int64_t stride, int mem,
                             const char *what) {
  check_mem(mem);
  if (stride < 0)
    throw Error(MFREE_ERR_ARG, std::string(what) + " stride " + std::to_string(stride) + " is negative");
  check_stride(n_, stride, what);
  if (v == nullptr && (n_ > 0 || stride == 0))
    throw Error(MFREE_ERR_NULL, std::string(what) + " pointer is NULL");
  const int32_t count = stride == 0 ? 1 : n_;
  for (int32_t i = 0; i < count; ++i) {
    const double val = v[i * stride];
    if (!std::isfinite(val) || val <= 0.0)
      throw Error(MFREE_ERR_INPUT, fmt_index(what, i, val) + " must be finite and > 0");
  }
  // made aside and swapped in, as set_positions
  HVec<double> own;
  const double *ptr = v;
  int64_t st = stride;
  if (mem == MFREE_COPY) {
    own.assign(count > 0 ? count : 1, 1.0);
    for (int32_t i = 0; i < count; ++i) own[i] = v[i * stride];
    ptr = own.data();
    st = stride == 0 ? 0 : 1;
  } else if (v == nullptr) {  // n = 0 with a NULL array: still counts as set
    own.assign(1, 1.0);
    ptr = own.data();
  }
  a.own.swap(own);
  a.ptr = ptr;
  a.stride = st;
  setup_done_ = false;
}

void ParticleSet::set_volumes(const double *v, int64_t stride, int mem) {
  set_scalar(vol_, v, stride, mem, "volume");
}
void ParticleSet::set_masses(const double *m, int64_t stride, int mem) {
  set_scalar(mass_, m, stride, mem, "mass");
}
void ParticleSet::set_densities(const double *rho, int64_t stride, int mem) {
  set_scalar(rho_, rho, stride, mem, "density");
}
void ParticleSet::set_support(const double *h, int64_t stride, int mem) {
  set_scalar(h_, h, stride, mem, "support");
}

void ParticleSet::set_search(int convention, double kappa) {
  if (convention < MFREE_SEARCH_GATHER || convention > MFREE_SEARCH_SYMMETRIC_MEAN)
    throw Error(MFREE_ERR_ARG, "unknown search convention " + std::to_string(convention));
  if (!std::isfinite(kappa) || kappa <= 0.0)
    throw Error(MFREE_ERR_ARG, "kappa must be finite and > 0");
  convention_ = convention;
  kappa_ = kappa;
  setup_done_ = false;
}

void ParticleSet::set_search_skin(double skin) {
  if (!std::isfinite(skin) || skin < 0.0)
    throw Error(MFREE_ERR_ARG, "search skin must be finite and >= 0, got " + std::to_string(skin));
  skin_ = skin;
  setup_done_ = false;
}

int64_t ParticleSet::search_count() const { return scratch_ ? neighbor_searches(*scratch_) : 0; }

bool ParticleSet::rows_left() const { return scratch_ && !host_neighbors() && neighbor_rows_left(*scratch_); }

const Csr &ParticleSet::search_candidates() const {
  const Csr *c = scratch_ ? neighbor_candidates(*scratch_) : nullptr;
  return c && !host_neighbors() ? *c : nbr_;
}

void ParticleSet::set_periodic(const double *lo, const double *hi, const int32_t *periodic) {
  if (!lo || !hi || !periodic) throw Error(MFREE_ERR_NULL, "lo, hi and periodic must not be NULL");
  for (int c = 0; c < dim_; ++c) {
    if (!std::isfinite(lo[c]) || !std::isfinite(hi[c]))
      throw Error(MFREE_ERR_INPUT, "box bounds must be finite");
    if (periodic[c] && !(hi[c] > lo[c]))
      throw Error(MFREE_ERR_ARG, "box axis " + std::to_string(c) + " has hi <= lo");
    if (periodic[c] && !std::isfinite(hi[c] - lo[c]))
      throw Error(MFREE_ERR_INPUT, "box axis " + std::to_string(c) +
                                       ": the period hi - lo overflows to infinity");
  }
  for (int c = 0; c < dim_; ++c) {
    lo_[c] = lo[c];
    hi_[c] = hi[c];
    periodic_[c] = periodic[c] != 0;
  }
  setup_done_ = false;
}

void ParticleSet::check_host_csr(const int64_t *rowptr, const int32_t *cols, int32_t base) const {
  const int32_t rows = num_owned();
  if (rowptr[0] != base)
    throw Error(MFREE_ERR_INPUT, "neighbour rowptr[0] = " + std::to_string(rowptr[0]) +
                                     ", expected the index base " + std::to_string(base));
  for (int32_t i = 0; i < rows; ++i)
    if (rowptr[i + 1] < rowptr[i])
      throw Error(MFREE_ERR_INPUT, "neighbour rowptr is not monotone at row " + std::to_string(i));
  const int64_t nnz = rowptr[rows] - base;
  if (nnz > 0 && cols == nullptr) throw Error(MFREE_ERR_NULL, "neighbour column array is NULL");
  for (int64_t k = 0; k < nnz; ++k)
    if (cols[k] < base || cols[k] - base >= n_)
      throw Error(MFREE_ERR_INPUT, "neighbour column " + std::to_string(cols[k]) + " at position " +
                                       std::to_string(k) + " is outside [" + std::to_string(base) +
                                       ", " + std::to_string(base + n_) + ")");
  // A column twice in a row would count that neighbour twice in every sum over the row
  // (rows need not be sorted: last row seen per column).
  std::vector<int32_t> seen(static_cast<size_t>(n_), -1);
  for (int32_t i = 0; i < rows; ++i)
    for (int64_t k = rowptr[i] - base; k < rowptr[i + 1] - base; ++k) {
      int32_t &last = seen[static_cast<size_t>(cols[k] - base)];
      if (last == i)
        throw Error(MFREE_ERR_INPUT, "neighbour column " + std::to_string(cols[k]) +
                                         " appears twice in row " + std::to_string(i));
      last = i;
    }
}

void ParticleSet::set_neighbors(const int64_t *rowptr, const int32_t *cols, int32_t base, int mem) {
  check_mem(mem);
  if (base != 0 && base != 1) throw Error(MFREE_ERR_ARG, "index base must be 0 or 1");
  if (!rowptr) throw Error(MFREE_ERR_NULL, "neighbour rowptr is NULL");
  check_host_csr(rowptr, cols, base);
  const int32_t rows = num_owned();
  // The copies are made aside and swapped in: running out of memory half way must leave
  // the previous lists (and the pointers into them) as they were.
  HVec<int64_t> rp_own;
  HVec<int32_t> cols_own;
  if (mem == MFREE_COPY) {
    const int64_t nnz = rowptr[rows] - base;
    rp_own.assign(rowptr, rowptr + rows + 1);
    cols_own.assign(cols, cols + nnz);
    if (cols_own.empty()) cols_own.push_back(base);  // keep data() non-NULL
  }
  host_rowptr_own_.swap(rp_own);
  host_cols_own_.swap(cols_own);
  host_rowptr_ = mem == MFREE_COPY ? host_rowptr_own_.data() : rowptr;
  host_cols_ = mem == MFREE_COPY ? host_cols_own_.data() : cols;
  host_base_ = base;
  host_rows_ = rows;
  pairs_ = PairList();  // the CSR lists replace a pair list
  pair_off_.clear();
  setup_done_ = false;
}

void ParticleSet::check_global_ids(const int64_t *ids) {
  for (int32_t i = 0; i < n_; ++i)
    if (ids[i] < 0)
      throw Error(MFREE_ERR_INPUT, "global id of particle " + std::to_string(i) + " is " +
                                       std::to_string(ids[i]) + " (must be >= 0)");
  // the particles in id order (ties by index); a repeat is two neighbours with one id
  HVec<int32_t> &perm = gid_perm_next_;
  perm.resize(static_cast<size_t>(n_));
  for (int32_t i = 0; i < n_; ++i) perm[i] = i;
  std::sort(perm.begin(), perm.end(),
            [ids](int32_t a, int32_t b) { return ids[a] < ids[b] || (ids[a] == ids[b] && a < b); });
  for (int32_t q = 1; q < n_; ++q)
    if (ids[perm[q]] == ids[perm[q - 1]])
      throw Error(MFREE_ERR_INPUT, "global id " + std::to_string(ids[perm[q]]) + " is given to particles " +
                                       std::to_string(perm[q - 1]) + " and " + std::to_string(perm[q]) +
                                       " (ids must be unique in the set)");
  gid_perm_.swap(gid_perm_next_);
}

void ParticleSet::set_global_ids(const int64_t *ids, int mem) {
  check_mem(mem);
  if (!ids) {
    gid_ = nullptr;
    gid_own_.clear();
    setup_done_ = false;
    return;
  }
  // (the copy first: after the check, which replaces the id order, nothing may fail)
  HVec<int64_t> own;
  if (mem == MFREE_COPY) {
    own.assign(ids, ids + n_);
    if (own.empty()) own.push_back(0);  // keep data() non-NULL: the set has ids
  }
  check_global_ids(ids);
  if (mem == MFREE_COPY) {
    gid_own_.swap(own);
    gid_ = gid_own_.data();
  } else {
    gid_own_.clear();
    gid_ = ids;
  }
  setup_done_ = false;
}

void ParticleSet::set_halo_width(double w) {
  if (!std::isfinite(w) || w < 0.0)
    throw Error(MFREE_ERR_ARG, "halo width must be finite and >= 0, got " + std::to_string(w));
  halo_ = w;
  setup_done_ = false;
}

void ParticleSet::order_rows_by_id(Csr &rows, RowOrderScratch &sc) const {
  if (!gid_) return;
  const int64_t *g = gid_;
  const int64_t nrows = static_cast<int64_t>(rows.rowptr.size()) - 1, nnz = rows.nnz();
  const int64_t *rp = rows.rowptr.data();
  int32_t *cl = rows.cols.data();
  // Rows come sorted by index. Where the local numbering follows the ids (a host's own
  // particles in id order, ghosts appended) few entries are out of id order: insertion
  // sort, in place. Otherwise (numbering unrelated to the ids) the rows are rebuilt in
  // O(nnz): each particle's rows listed, then the particles visited in id order, each
  // appended to its rows.
  const int nt = block_count(num_threads(nnz));
  int64_t per_block[kMaxBlocks] = {0};
  parallel_blocks(nrows, nt, [&](int t, int64_t b, int64_t e) {
    int64_t d = 0;
    for (int64_t r = b; r < e; ++r)
      for (int64_t k = rp[r] + 1; k < rp[r + 1]; ++k) d += g[cl[k - 1]] > g[cl[k]];
    per_block[t] = d;
  });
  int64_t descents = 0;
  for (int t = 0; t < nt; ++t) descents += per_block[t];
  if (descents == 0) return;
  if (descents * 8 < nnz) {
    parallel_blocks(nrows, num_threads(nnz), [&](int, int64_t b, int64_t e) {
      for (int64_t r = b; r < e; ++r)
        for (int64_t k = rp[r] + 1; k < rp[r + 1]; ++k) {
          const int32_t v = cl[k];
          const int64_t gv = g[v];
          int64_t q = k;
          for (; q > rp[r] && g[cl[q - 1]] > gv; --q) cl[q] = cl[q - 1];
          cl[q] = v;
        }
    });
    return;
  }
  const int32_t n = n_;
  sc.start.assign(static_cast<size_t>(n) + 1, 0);
  int64_t *start = sc.start.data();
  for (int64_t k = 0; k < nnz; ++k) ++start[cl[k] + 1];
  for (int32_t j = 0; j < n; ++j) start[j + 1] += start[j];
  sc.fill.assign(start, start + n);
  sc.owner.resize(static_cast<size_t>(nnz));
  int64_t *fill = sc.fill.data();
  int32_t *owner = sc.owner.data();
  for (int64_t r = 0; r < nrows; ++r)
    for (int64_t k = rp[r]; k < rp[r + 1]; ++k) owner[fill[cl[k]]++] = static_cast<int32_t>(r);
  sc.fill.assign(rp, rp + nrows);
  fill = sc.fill.data();
  for (int32_t q = 0; q < n; ++q) {
    const int32_t j = gid_perm_[q];
    for (int64_t t = start[j]; t < start[j + 1]; ++t) cl[fill[owner[t]]++] = j;
  }
}

int32_t ParticleSet::data_status(int32_t i) const {
  for (int c = 0; c < dim_; ++c)
    if (!std::isfinite(pos_(i, c))) return MFREE_FAIL_NONFINITE;
  for (const ScalarArray *a : {&h_, &vol_, &mass_, &rho_}) {
    if (!a->set()) continue;
    const double v = (*a)(i);
    if (!std::isfinite(v)) return MFREE_FAIL_NONFINITE;
    if (v <= 0.0) return MFREE_FAIL_INVALID_DATA;
  }
  return 0;
}

Report ParticleSet::validate() {
  Report rep;
  // (zeroed below by the threads, each its block: a serial assign was a pass of its own)
  site_status_.resize(static_cast<size_t>(n_));
  int32_t *status = site_status_.data();
  // Common case first, over the context's threads: every particle valid (a search is
  // otherwise parallel, and this pass would bound its speed-up); the messages below are
  // built only when some particle fails.
  {
    const int nt = std::min(num_threads(n_), 64);
    char fail[64] = {0};
    // (one array at a time with strided loads and no early exit: loops without branches;
    // a value shared by all, stride 0, checked once)
    parallel_blocks(n_, nt, [&](int t, int64_t b, int64_t e) {
      std::fill(status + b, status + e, 0);
      const double big = std::numeric_limits<double>::max();
      bool ok = true;
      const double *X = pos_data();
      const int64_t si = pos_step_i(), sc = pos_step_c();
      if (sc == 1 && si == dim_) {  // packed (x, y, z) per particle: one run of doubles
        ok = simd::all_finite(X + b * si, (e - b) * si);
      } else {
        for (int c = 0; c < dim_; ++c) {
          bool okc = true;
          if (si == 1) okc = simd::all_finite(X + c * sc + b, e - b);
          else
            for (int64_t i = b; i < e; ++i) okc &= std::fabs(X[i * si + c * sc]) <= big;  // finite
          ok = ok && okc;
        }
      }
      for (const ScalarArray *a : {&h_, &vol_, &mass_, &rho_}) {
        if (!a->set()) continue;
        const double *v = a->ptr;
        const int64_t st = a->stride;
        const int64_t e1 = st == 0 ? std::min<int64_t>(e, b + 1) : e;
        bool oka = true;
        for (int64_t i = b; i < e1; ++i) oka &= v[i * st] > 0.0 && v[i * st] <= big;  // finite, > 0
        ok = ok && oka;
      }
      fail[t] = !ok;
    });
    bool any = false;
    for (int t = 0; t < nt; ++t) any = any || fail[t];
    if (!any) return rep;
  }
  int64_t bad = 0;
  for (int32_t i = 0; i < n_; ++i) {
    int32_t st = 0;
    std::string why;
    for (int c = 0; c < dim_ && !st; ++c)
      if (!std::isfinite(pos_(i, c))) {
        st = MFREE_FAIL_NONFINITE;
        why = "position component " + std::to_string(c) + " is " + std::to_string(pos_(i, c));
      }
    auto check = [&](const ScalarArray &a, const char *what) {
      if (st || !a.set()) return;
      const double v = a(i);
      if (!std::isfinite(v)) {
        st = MFREE_FAIL_NONFINITE;
        why = std::string(what) + " is " + std::to_string(v);
      } else if (v <= 0.0) {
        st = MFREE_FAIL_INVALID_DATA;
        why = std::string(what) + " is " + std::to_string(v) + " (must be > 0)";
      }
    };
    check(h_, "support");
    check(vol_, "volume");
    check(mass_, "mass");
    check(rho_, "density");
    if (st) {
      site_status_[i] = st;
      if (bad == 0)
        rep.fail(static_cast<mfree_status_t>(st), "particle " + std::to_string(i) + ": " + why);
      ++bad;
    }
  }
  if (bad > 1) rep.message += " (" + std::to_string(bad) + " particles isolated)";
  else if (bad == 1) rep.message += " (particle isolated)";
  return rep;
}

Report ParticleSet::setup() {
  if (!pos_.set()) throw Error(MFREE_ERR_STATE, "positions are not set");
  if (!host_neighbors() && !h_.set())
    throw Error(MFREE_ERR_STATE, "support sizes are not set (needed by the neighbour search)");
  if (host_neighbors() && !has_pairs()) {
    // The host's rowptr has the owned count of set_neighbors time; a later
    // set_num_ghost would make us read past it.
    if (host_rows_ != num_owned())
      throw Error(MFREE_ERR_MISMATCH, "the host neighbour lists have " + std::to_string(host_rows_) +
                                          " rows but the set now has " + std::to_string(num_owned()) +
                                          " owned particles (set_num_ghost after set_neighbors)");
    check_host_csr(host_rowptr_, host_cols_, host_base_);
  }
  // A negative failure (periodic box too small, no memory) changes nothing: the old
  // statuses go back with the old lists.
  // (the old statuses change places with the spare array rather than being copied to it)
  prev_status_.reserve(static_cast<size_t>(n_));  // update swaps the two arrays: both
  site_status_.reserve(static_cast<size_t>(n_));  // hold n entries without allocating
  prev_status_.swap(site_status_);
  Report rep = validate();
  Csr out{{}, {}};  // (empty: a search allocates nothing here; host lists fill it below)
  try {
    // borrowed ids may have changed since they were set
    if (gid_ && gid_own_.empty()) check_global_ids(gid_);
    if (!host_neighbors()) {
      const bool gather = convention_ == MFREE_SEARCH_GATHER;
      double hmax = 0.0;
      if (!gather && halo_ > 0.0)
        for (int32_t j = 0; j < n_; ++j)
          if (site_status_[j] == 0) hmax = std::max(hmax, h_(j));
      check_halo([&](int32_t i) { return kappa_ * (gather ? h_(i) : std::max(h_(i), hmax)); },
                 "search radius");
    }
    if (has_pairs()) {
      rows_from_pairs(pair_rows_, pair_off_next_);
    } else if (host_neighbors()) {
      const int32_t rows = num_owned();
      out.rowptr.assign(static_cast<size_t>(rows) + 1, 0);
      out.cols.reserve(static_cast<size_t>(host_rowptr_[rows] - host_base_));
      for (int32_t i = 0; i < rows; ++i) {
        if (site_status_[i] == 0)
          for (int64_t k = host_rowptr_[i] - host_base_; k < host_rowptr_[i + 1] - host_base_; ++k) {
            const int32_t j = host_cols_[k] - host_base_;
            if (site_status_[j] == 0) out.cols.push_back(j);
          }
        // get_neighbors promises sorted rows; host rows need not be.
        std::sort(out.cols.begin() + out.rowptr[i], out.cols.end());
        out.rowptr[i + 1] = static_cast<int64_t>(out.cols.size());
      }
    } else {
      // in place: the search reuses the lists' storage and leaves them unchanged when
      // it throws
      if (!scratch_) scratch_.reset(new_neighbor_scratch());
      find_neighbors(*this, site_status_, *scratch_, nbr_);
    }
  } catch (...) {
    site_status_.swap(prev_status_);
    // (a search that ran out of memory after it began to overwrite the lists leaves them
    // with no rows: the old lists are gone, so the set is no longer set up)
    if (nbr_.rowptr.size() != static_cast<size_t>(num_owned()) + 1) setup_done_ = false;
    throw;
  }
  if (has_pairs()) {
    std::swap(nbr_, pair_rows_);
    pair_off_.swap(pair_off_next_);
  } else if (host_neighbors()) {
    nbr_ = std::move(out);
  }
  order_rows_by_id(nbr_, row_order_);
  setup_done_ = true;
  ++setups_;
  return rep;
}

Report ParticleSet::update() {
  if (!setup_done_) throw Error(MFREE_ERR_STATE, "update called before setup");
  // No allocation here (t430): both status arrays have n entries since setup, and a
  // particle that turned invalid is dropped from the rows in place.
  prev_status_.swap(site_status_);
  Report rep = validate();
  bool changed = false;
  for (int32_t i = 0; i < n_; ++i)
    if (site_status_[i] != 0 && prev_status_[i] == 0) changed = true;
  if (changed) {
    // A particle that turned invalid since setup must not stay in anybody's row.
    int64_t w = 0, r0 = 0;
    for (int32_t i = 0; i < num_owned(); ++i) {
      const int64_t r1 = nbr_.rowptr[i + 1];
      if (site_status_[i] == 0)
        for (int64_t k = r0; k < r1; ++k)
          if (site_status_[nbr_.cols[k]] == 0) nbr_.cols[w++] = nbr_.cols[k];
      r0 = r1;
      nbr_.rowptr[i + 1] = w;
    }
    nbr_.cols.resize(static_cast<size_t>(w));
  }
  return rep;
}

}  // namespace mfree
