// The fluid's shape-function tables at the nodes (fluid particles, then dummies): the rows
// from the nodes' particle set (its search with a Verlet skin), the chunk colouring of the
// scatter on the set's candidate lists, and the rows' values computed by the approximants
// at every prepare (the fast path where it applies, the general path with its fallbacks
// and Shepard rule).
#include <algorithm>
#include <cmath>

#include "core/base/basis.hpp"
#include "core/base/parallel.hpp"
#include "core/particles/neighbors.hpp"
#include "core/systems/fluid.hpp"

namespace mfree {

Report FluidSystem::candidates(const double *xn) {
  const int dim = dim_;
  const int32_t nall = nq();
  // the set's search: gather radius R h (support h, kappa the kernel's radius R) and its
  // skin, in units of length
  const double R = kernel_->radius(), skin = skin_ * h_;
  if (ps_.kappa() != R || ps_.search_convention() != MFREE_SEARCH_GATHER) ps_.set_search(MFREE_SEARCH_GATHER, R);
  if (ps_.search_skin() != skin) ps_.set_search_skin(skin);
  ps_.set_positions(xn, MFREE_LAYOUT_AOS, dim, MFREE_BORROW);
  xbound_ = xn;
  ps_.set_rows_left(fast_->filters_rows() && !vci_);
  Report r = ps_.setup();
  if (!r.ok()) {
    lists_valid_ = false;
    return r;
  }
  const Csr &cand = ps_.search_candidates();
  const int64_t cnnz = cand.nnz();
  if (ps_.rows_left()) {  // (sized for the candidates: no allocation until they grow)
    if (kept_.size() < static_cast<size_t>(cnnz)) kept_.resize(cnnz);
    if (rowend_.size() < static_cast<size_t>(nall)) {
      rowbeg_.resize(nall);
      rowend_.resize(nall);
    }
    rb_ = rowbeg_.data();
    re_ = rowend_.data();
    cols_ = kept_.data();
  } else {
    const Csr &nb = ps_.neighbors();
    rb_ = nb.rowptr.data();
    re_ = rb_ + 1;
    cols_ = nb.cols.data();
  }
  if (lists_valid_ && ps_.search_count() == cand_search_) return Report();
  // new candidate lists: the tables' rows lie in them until the next build
  N_.resize(cnnz);
  G_.resize(cnnz * dim);
  cond_.resize(nall);
  maxrow_ = 0;
  for (int32_t i = 0; i < nall; ++i) maxrow_ = std::max<int64_t>(maxrow_, cand.rowptr[i + 1] - cand.rowptr[i]);
  color_chunks(cand);
  if (walls_) {
    // walls stand still: a wall within r0 of a node now was within r0 + skin / 2 of it
    // when the candidates were built, as long as the set keeps them
    VectorArray xa;
    xa.ptr = xn;
    xa.ld = dim;
    xa.layout = MFREE_LAYOUT_AOS;
    ScalarArray ha;
    const double hw = 0.5 * (r0_ + 0.5 * skin);
    ha.ptr = &hw;
    ha.stride = 0;
    find_point_neighbors(*walls_, walls_->site_status(), n_, xa, ha, wall_nbr_);
  }
  cand_search_ = ps_.search_count();
  lists_valid_ = true;
  return Report();
}

// Greedy colouring of the row chunks in chunk order: color_mask_[j] holds the colours
// of the chunks so far that touch node j (write to it in the scatter: the candidates of
// their rows, a superset of the table rows until the next rebuild). The chunks and their
// colours depend on the lists only, not on the thread count. A node ordering so scattered
// that 64 colours do not suffice runs all chunks in one colour, in order, on one thread.
void FluidSystem::color_chunks(const Csr &cand) {
  const int32_t nall = nq();
  const int32_t nch = (nall + kChunk - 1) / kChunk;
  const int64_t *crp = cand.rowptr.data();
  const int32_t *ccols = cand.cols.data();
  color_mask_.assign(nall, 0);
  std::vector<int32_t> &color = chunk_color_;  // members: a rebuild allocates only when the set grows
  color.assign(nch, 0);
  int ncolor = 0;
  bool serial = false;
  for (int32_t c = 0; c < nch && !serial; ++c) {
    const int64_t e0 = crp[static_cast<int64_t>(c) * kChunk], e1 = crp[std::min<int64_t>(nall, (c + 1) * int64_t{kChunk})];
    uint64_t used = 0;
    for (int64_t e = e0; e < e1; ++e) used |= color_mask_[ccols[e]];
    if (used == ~uint64_t{0}) {
      serial = true;
      break;
    }
    int col = 0;
    while (used >> col & 1u) ++col;
    color[c] = col;
    ncolor = std::max(ncolor, col + 1);
    for (int64_t e = e0; e < e1; ++e) color_mask_[ccols[e]] |= uint64_t{1} << col;
  }
  if (serial) {
    ncolor = 1;
    std::fill(color.begin(), color.end(), 0);
  }
  color_ptr_.assign(static_cast<size_t>(ncolor) + 1, 0);
  for (int32_t c = 0; c < nch; ++c) ++color_ptr_[color[c] + 1];
  for (int col = 0; col < ncolor; ++col) color_ptr_[col + 1] += color_ptr_[col];
  chunk_order_.resize(nch);
  std::vector<int32_t> &fill = chunk_fill_;
  fill.assign(color_ptr_.begin(), color_ptr_.end() - 1);
  for (int32_t c = 0; c < nch; ++c) chunk_order_[fill[color[c]]++] = c;
  scatter_threads_ = !serial;
}

void FluidSystem::set_approximation(int method, int order, int kernel, double param) {
  if (method == MFREE_METHOD_MPFEM)
    throw Error(MFREE_ERR_UNSUPPORTED, "MPFEM needs a mesh: not a method for the fluid's moving particles");
  // the approximants' own checks of the method, the kernel and the order
  Approximant probe(&ps_, method);
  probe.set_kernel(kernel, param);
  probe.set_order(order);
  Approximant::check_kernel_use(method, kernel, order, MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT);
  method_ = method;
  order_ = has_order(method) ? order : fixed_order(method);
  kernel_id_ = kernel;
  kernel_param_ = param;
  kernel_ = std::make_unique<Kernel>(kernel, dim_, param);
  fast_.reset();
  lists_valid_ = false;  // the search radius follows the kernel's support
}

namespace {

// The methods whose rows read the particles' volumes (the others get the positions).
bool weights_volumes(int method) { return method != MFREE_METHOD_MLS; }

// Node k's place in its row of len sorted columns (it is its own neighbour at distance
// 0): the lower bound by halving without a branch (selects, no mispredicted jumps).
int32_t row_place(const int32_t *row, int64_t len, int32_t k) {
  const int32_t *at = row;
  if (len > 0) {
    for (; len > 1; len -= len / 2) at = at[len / 2] < k ? at + len / 2 : at;
    at += *at < k;
  }
  return static_cast<int32_t>(at - row);
}

}  // namespace

bool FluidSystem::table_rows(int t, int32_t k0, int32_t k1, const double *xn, const double *pack, bool transpose) {
  const int dim = dim_;
  RowsScratch &w = rows_scratch_[t];
  FastTables ft;
  ft.rowptr = rb_;
  ft.cols = cols_;
  ft.self = self_.data();
  const int64_t stride = pack ? dim + 1 : dim;
  const double *xs = pack ? pack : xn;
  for (int c = 0; c < dim; ++c) ft.x[c] = ft.sx[c] = xs + c;
  ft.vol = pack ? pack + dim : xn;  // (without pack read by no method: MLS does not weight by volume)
  ft.stride = ft.sstride = stride;
  ft.h = ft.sh = &h_;
  ft.hstride = ft.shstride = 0;
  ft.val = N_.data();
  ft.grad = G_.data();
  const bool left = ps_.rows_left();
  if (left) {  // the fast path filters the candidates (FastPath::filters_rows)
    const Csr &cand = ps_.search_candidates();
    ft.rowptr = cand.rowptr.data();
    ft.cols = cand.cols.data();
    ft.kept = kept_.data();
    ft.rowbeg = rowbeg_.data();
    ft.rowend = rowend_.data();
    ft.kappa = ps_.kappa();
  }
  FastSites fs;
  fs.status = site_status_.data();
  fs.support = site_support_.data();
  fs.order = site_order_.data();
  fs.cond = cond_.data();
  fs.order_used = order_;
  const bool fast = fast_->ok();
  for (int32_t c0 = k0; c0 < k1; c0 += kChunk) {
    const int32_t c1 = std::min(k1, c0 + kChunk);
    // (the filtering rows do not read the places; general_row finds its own)
    if (!left)
      for (int32_t k = c0; k < c1; ++k) self_[k] = row_place(cols_ + rb_[k], re_[k] - rb_[k], k);
    if (fast) fast_->run(ft, c0, c1, w.fast, fs);
    for (int32_t k = c0; k < c1; ++k) {
      const bool done = fast && site_status_[k] != kFastPending;
      if (!done || cond_[k] > shepard_cond_) general_row(k, xn, w, done);
    }
  }
  if (!transpose) return false;
  bool one_way = false;
  for (int32_t k = k0; k < k1; ++k)  // N_k(x_j) is entry (j, k) of the transpose
    for (int64_t q = rb_[k]; q < re_[k]; ++q) {
      const int32_t j = cols_[q];
      const int32_t *rj = cols_ + rb_[j], *ej = cols_ + re_[j], *p = std::lower_bound(rj, ej, k);
      if (p == ej || *p != k) {
        one_way = true;
        continue;
      }
      double *nt = NT_.data() + (p - cols_) * (dim + 1);  // one cache line per entry
      nt[0] = N_[q];
      for (int c = 0; c < dim; ++c) nt[1 + c] = G_[q * dim + c];
    }
  return one_way;
}

// Shepard functions replace the rows where the local system is ill-conditioned, not only
// singular (of w V: the approximants' Shepard method; 003 Sect. 6: a lattice node has a
// condition number of 10-15, a free edge or corner 30-60; a particle left in a thin sheet
// or strand climbs past 1e3 within a few steps, and its gradients then drive the density
// negative in one step (dam break along the wall, T ~ 2.2, at every resolution and CFL
// number tried). Hence the default threshold 100 (mfree_system_set_shepard_condition).
// Where the local system is singular or the row too short, the lower orders (for linear
// MLS: MLS of order 0, Shepard functions of w), then Shepard functions.
void FluidSystem::general_row(int32_t k, const double *xn, RowsScratch &w, bool fast_done) {
  const int dim = dim_;
  const int64_t o = rb_[k];
  const int n = static_cast<int>(re_[k] - o);
  const int32_t *js = cols_ + o;
  double *d = w.d.data();
  const double *xk = xn + static_cast<size_t>(k) * dim;
  for (int m = 0; m < n; ++m) {
    const double *xj = xn + static_cast<size_t>(js[m]) * dim;
    for (int c = 0; c < 3; ++c) d[3 * m + c] = c < dim ? xj[c] - xk[c] : 0.0;
    w.v[m] = vol_[js[m]];
    w.h[m] = h_;
  }
  LocalInput in;
  in.n = n;
  in.self = row_place(js, n, k);
  in.hs = h_;
  in.d = d;
  in.vol = w.v.data();
  in.h = w.h.data();
  LocalOutput out;
  out.phi = N_.data() + o;
  out.grad = G_.data() + o * dim;
  if (fast_done) {
    out.status = 0;
    out.cond = cond_[k];
  }
  LocalConfig cfg;
  cfg.method = method_;
  cfg.dim = dim;
  cfg.order = order_;
  cfg.kernel = kernel_.get();
  compute_site_rules(cfg, in, w.work, out, MFREE_FALLBACK_LOWER_ORDER, shepard_cond_, fast_done, 0);
  site_status_[k] = out.status;
  cond_[k] = out.cond;
}


Report FluidSystem::prepare(const double *y, bool checked) {
  check_ready();
  Report rep = checked ? Report() : check_state(y, -1);
  if (!rep.ok()) return rep;
  const int dim = dim_;
  const int32_t nall = nq();
  const size_t nd = static_cast<size_t>(dim) * n_;
  const double *rho = y + 2 * nd;
  parallel_blocks(n_, light_threads(n_), [&](int, int64_t b, int64_t e) {
    for (int64_t i = b; i < e; ++i) vol_[i] = mass_[i] / rho[i];
  });
  if (!kernel_) kernel_ = std::make_unique<Kernel>(kernel_id_, dim, kernel_param_);
  if (!fast_) fast_ = std::make_unique<FastPath>(dim, method_, order_, *kernel_, MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT);
  const double *xn = node_positions(y);  // + dummies (fluid_wall.cpp)
  Report r = candidates(xn);
  if (!r.ok()) return r;
  const int nt = num_threads(nall);
  const int64_t nchunk = (nall + kChunk - 1) / kChunk;  // the tables are written by chunks
  const bool transpose = vci_;  // only consistent integration reads NT_ (fluid_wall.cpp)
  if (transpose && NT_.size() < N_.size() * (dim + 1)) NT_.resize(N_.size() * (dim + 1));
  if (rows_scratch_.size() < static_cast<size_t>(nt)) rows_scratch_.resize(nt);
  const int maxrow = static_cast<int>(maxrow_);
  for (int t = 0; t < nt; ++t) {  // sized for the longest row: no allocation in the rows
    RowsScratch &w = rows_scratch_[t];
    w.fast.reserve(maxrow);
    if (w.d.size() < 3 * static_cast<size_t>(maxrow)) w.d.resize(3 * static_cast<size_t>(maxrow));
    if (w.v.size() < static_cast<size_t>(maxrow)) w.v.resize(maxrow);
    if (w.h.size() < static_cast<size_t>(maxrow)) w.h.resize(maxrow);
    w.work.reserve(maxrow, dim, basis_size(dim, std::max(order_, 1)));
  }
  site_status_.resize(nall);
  site_support_.resize(nall);
  site_order_.resize(nall);
  self_.resize(nall);
  const double *pack = nullptr;
  if (weights_volumes(method_)) {  // positions and volumes in one record per node
    const int rec = dim + 1;
    node_pack_.resize(static_cast<size_t>(nall) * rec);
    double *np = node_pack_.data();
    parallel_blocks(nall, light_threads(nall), [&](int, int64_t b, int64_t e) {
      for (int64_t i = b; i < e; ++i) {
        for (int c = 0; c < dim; ++c) np[i * rec + c] = xn[i * dim + c];
        np[i * rec + dim] = vol_[i];
      }
    });
    pack = np;
  }
  bool one_way[64] = {};  // parallel_blocks runs at most 64 threads
  parallel_blocks(nchunk, nt, [&](int t, int64_t b, int64_t e) {
    one_way[t] = table_rows(t, static_cast<int32_t>(b * kChunk), static_cast<int32_t>(std::min<int64_t>(nall, e * kChunk)),
                            xn, pack, transpose);
  });
  if (std::any_of(one_way, one_way + 64, [](bool f) { return f; })) {
    // cannot happen with lists from one search radius; a failure rather than a wrong sum
    rep.fail(MFREE_FAIL_NEIGHBORS, "the neighbour lists of the fluid are not symmetric");
    lists_valid_ = false;
    return rep;
  }
  rows_done();  // (on ranks: drops the rows it does not need)
  for (int32_t k = 0; k < nall; ++k)
    if (site_status_[k] != 0) {  // every fallback failed (Shepard functions need one neighbour)
      rep.fail(static_cast<mfree_status_t>(site_status_[k]),
               "node " + std::to_string(k) + " of the fluid has no shape functions (" + method_name(method_) + ")");
      return rep;
    }
  fluid_share();
  vci_setup();  // optional, fluid_wall.cpp
  return rep;
}

}  // namespace mfree
