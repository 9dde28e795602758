// The fluid's shape-function tables at the nodes (fluid particles, then dummies): the
// candidate (Verlet) lists and the chunk colouring of the scatter on them, and the rows
// filtered from the candidates at every prepare and computed by the approximants (the
// fast path where it applies, the general path with its fallbacks and Shepard rule).
#include <algorithm>
#include <cmath>
#include <type_traits>

#include "core/base/basis.hpp"
#include "core/base/parallel.hpp"
#include "core/base/simd.hpp"
#include "core/particles/neighbors.hpp"
#include "core/systems/fluid.hpp"

#if MFREE_SIMD_X86
#include <immintrin.h>
#endif

namespace mfree {

Report FluidSystem::candidates(const double *xn) {
  const int dim = dim_;
  const int32_t nall = nq();
  const size_t nx = static_cast<size_t>(nall) * dim;
  bool rebuild = !lists_valid_ || xref_.size() != nx || href_ != h_;
  if (!rebuild) {
    // 2 max |x - x_ref| < skin: pairs now closer than 2h were closer than 2h + skin at
    // the build (a tenth of the skin kept back for rounding)
    const double lim = 0.45 * skin_ * h_, lim2 = lim * lim;
    bool moved[64] = {};  // per thread (parallel_blocks runs at most 64)
    const double *xr = xref_.data();
    parallel_blocks(nall, light_threads(nall), [&](int t, int64_t b, int64_t e) {
      bool far = false;
      for (int64_t i = b; i < e; ++i) {
        double d2 = 0.0;
        for (int c = 0; c < dim; ++c) d2 += (xn[i * dim + c] - xr[i * dim + c]) * (xn[i * dim + c] - xr[i * dim + c]);
        far = far || !(d2 <= lim2);
      }
      moved[t] = far;
    });
    rebuild = std::any_of(moved, moved + 64, [](bool f) { return f; });
  }
  if (!rebuild) {
    if (xn != xbound_) {  // same lists, positions from another buffer (ps_ is read by fluid_wall)
      ps_.set_positions(xn, MFREE_LAYOUT_AOS, dim, MFREE_BORROW);
      xbound_ = xn;
    }
    return Report();
  }
  lists_valid_ = false;
  // gather radius 2 hs = R h + skin (the set's search multiplier is 2)
  const double hs = h_ * 0.5 * (kernel_->radius() + skin_);
  ps_.set_positions(xn, MFREE_LAYOUT_AOS, dim, MFREE_BORROW);
  xbound_ = xn;
  ps_.set_volumes(vol_.data(), 1, MFREE_BORROW);
  ps_.set_support(&hs, 0, MFREE_COPY);
  Report r = ps_.setup();
  if (!r.ok()) return r;
  const Csr &nb = ps_.neighbors();
  cand_.rowptr.assign(nb.rowptr.begin(), nb.rowptr.end());
  cand_.cols.assign(nb.cols.begin(), nb.cols.end());
  const int64_t cnnz = cand_.nnz();
  ctrans_valid_ = false;
  // the tables' rows lie in their candidate rows: no allocation until the next rebuild
  cols_.resize(cnnz);
  N_.resize(cnnz);
  G_.resize(cnnz * dim);
  rb_.resize(nall);
  re_.resize(nall);
  cond_.resize(nall);
  maxrow_ = 0;
  for (int32_t i = 0; i < nall; ++i)
    maxrow_ = std::max<int64_t>(maxrow_, cand_.rowptr[i + 1] - cand_.rowptr[i]);
  xref_.assign(xn, xn + nx);
  href_ = h_;
  ++rebuilds_;
  color_chunks();
  if (walls_) {
    VectorArray xa;
    xa.ptr = xn;
    xa.ld = dim;
    xa.layout = MFREE_LAYOUT_AOS;
    ScalarArray ha;
    const double hw = 0.5 * (r0_ + 0.5 * skin_ * h_);  // walls stand still: skin / 2 is enough
    ha.ptr = &hw;
    ha.stride = 0;
    find_point_neighbors(*walls_, walls_->site_status(), n_, xa, ha, wall_nbr_);
  }
  lists_valid_ = true;
  return Report();
}

void FluidSystem::transposed_candidates() {
  const int32_t nall = nq();
  // transposed entries: rows are sorted, so the rows i < j that hold j are met in the
  // order of row j (next[j] walks it); a missing partner (an asymmetric pair at the
  // edge of the lists) is -1 and may not become a pair of the tables
  ctrans_.assign(cand_.nnz(), -1);
  std::vector<int64_t> next(cand_.rowptr.begin(), cand_.rowptr.end() - 1);
  for (int32_t i = 0; i < nall; ++i)
    for (int64_t e = cand_.rowptr[i]; e < cand_.rowptr[i + 1]; ++e) {
      const int32_t j = cand_.cols[e];
      int64_t &p = next[j];
      while (p < cand_.rowptr[j + 1] && cand_.cols[p] < i) ++p;
      if (p < cand_.rowptr[j + 1] && cand_.cols[p] == i) ctrans_[e] = p;
    }
  cpos_.resize(cand_.nnz());
  NT_.resize(cand_.nnz() * (dim_ + 1));
  ctrans_valid_ = true;
}

// Greedy colouring of the row chunks in chunk order: color_mask_[j] holds the colours
// of the chunks so far that touch node j (write to it in the scatter: the candidates of
// their rows, a superset of the table rows until the next rebuild). The chunks and their
// colours depend on the lists only, not on the thread count. A node ordering so scattered
// that 64 colours do not suffice runs all chunks in one colour, in order, on one thread.
void FluidSystem::color_chunks() {
  const int32_t nall = nq();
  const int32_t nch = (nall + kChunk - 1) / kChunk;
  const int64_t *crp = cand_.rowptr.data();
  const int32_t *ccols = cand_.cols.data();
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

#if defined(__GNUC__) || defined(__clang__)
#define FLUID_NOINLINE __attribute__((noinline))
#else
#define FLUID_NOINLINE
#endif

namespace {

// The candidates cc[0 .. nc) of node k closer than the support (r2 < R2: a symmetric
// test, |x_j - x_k| is computed alike from both ends) written to js; returns their count.
// Candidates out of range are written and then overwritten (no branch: a quarter of them
// fall out). Not inlined into AVX2 code, where FMA contraction of r2 would move pairs at
// exactly the support's edge in or out of the rows depending on the CPU.
template <int D>
FLUID_NOINLINE int kept_columns(const double *xn, int64_t k, const int32_t *cc, int64_t nc, double R2, int32_t *js) {
  const double *xk = xn + k * D;
  int q = 0;
  for (int64_t e = 0; e < nc; ++e) {
    const int32_t j = cc[e];
    const double *xj = xn + static_cast<size_t>(j) * D;
    double r2 = 0.0;
    for (int c = 0; c < D; ++c) {
      const double d = xj[c] - xk[c];
      r2 += d * d;
    }
    js[q] = j;
    q += r2 < R2;
  }
  return q;
}

#if MFREE_SIMD_X86
struct PackTable {
  int32_t i[16][8];  // mask -> lane indices moving the kept 32-bit columns to the front
};
constexpr PackTable make_pack_table() {
  PackTable t{};
  for (int m = 0; m < 16; ++m) {
    int q = 0;
    for (int l = 0; l < 4; ++l)
      if (m >> l & 1) t.i[m][q++] = l;
  }
  return t;
}
constexpr PackTable kPack = make_pack_table();

// kept_columns<2> four candidates at a time with two 128-bit loads per pair of lanes, the
// kept columns left-packed through a permutation table; the products are kept from FMA
// contraction by an empty asm (the same test as the scalar loop, on any CPU).
MFREE_TARGET_AVX2 FLUID_NOINLINE int kept_columns2_avx2(const double *xn, int64_t k, const int32_t *cc, int64_t nc,
                                                       double R2, int32_t *js) {

  const __m256d xk = _mm256_set1_pd(xn[2 * k]), yk = _mm256_set1_pd(xn[2 * k + 1]), r2v = _mm256_set1_pd(R2);
  int q = 0;
  int64_t e = 0;
  for (; e + 4 <= nc; e += 4) {
    const int32_t *j = cc + e;
    const __m128d p0 = _mm_loadu_pd(xn + 2 * static_cast<size_t>(j[0])), p1 = _mm_loadu_pd(xn + 2 * static_cast<size_t>(j[1]));
    const __m128d p2 = _mm_loadu_pd(xn + 2 * static_cast<size_t>(j[2])), p3 = _mm_loadu_pd(xn + 2 * static_cast<size_t>(j[3]));
    const __m256d lo = _mm256_insertf128_pd(_mm256_castpd128_pd256(p0), p2, 1);  // x0 y0 x2 y2
    const __m256d hi = _mm256_insertf128_pd(_mm256_castpd128_pd256(p1), p3, 1);  // x1 y1 x3 y3
    const __m256d dx = _mm256_sub_pd(_mm256_unpacklo_pd(lo, hi), xk), dy = _mm256_sub_pd(_mm256_unpackhi_pd(lo, hi), yk);
    __m256d px = _mm256_mul_pd(dx, dx), py = _mm256_mul_pd(dy, dy);
    __asm__("" : "+x"(px), "+x"(py));  // r2 = d0 d0 + d1 d1, rounded as kept_columns
    const int mask = _mm256_movemask_pd(_mm256_cmp_pd(_mm256_add_pd(px, py), r2v, _CMP_LT_OQ));
    const __m256i pi = _mm256_loadu_si256(reinterpret_cast<const __m256i *>(kPack.i[mask]));
    const __m128i j4 = _mm_loadu_si128(reinterpret_cast<const __m128i *>(j));
    const __m256i jp = _mm256_permutevar8x32_epi32(_mm256_zextsi128_si256(j4), pi);
    _mm_storeu_si128(reinterpret_cast<__m128i *>(js + q), _mm256_castsi256_si128(jp));
    q += __builtin_popcount(static_cast<unsigned>(mask));
  }
  for (; e < nc; ++e) {
    const int32_t j = cc[e];
    const double *xj = xn + static_cast<size_t>(j) * 2;
    const double d0 = xj[0] - xn[2 * k], d1 = xj[1] - xn[2 * k + 1];
    double p0 = d0 * d0, p1 = d1 * d1;
    __asm__("" : "+x"(p0), "+x"(p1));
    js[q] = j;
    q += p0 + p1 < R2;
  }
  _mm256_zeroupper();
  return q;
}
#endif

// The methods whose rows read the particles' volumes (the others get the positions).
bool weights_volumes(int method) { return method != MFREE_METHOD_MLS; }

}  // namespace

bool FluidSystem::table_rows(int t, int32_t k0, int32_t k1, const double *xn, const double *pack, bool transpose) {
  const int dim = dim_;
  const double R = kernel_->radius() * h_, R2 = R * R;
  const int64_t *crp = cand_.rowptr.data();
  const int32_t *ccols = cand_.cols.data();
  const int32_t *cpos = cpos_.data();
  int64_t *rbeg = rb_.data(), *rend = re_.data();
  RowsScratch &w = rows_scratch_[t];
  int64_t *rp = w.rp.data();
  FastTables ft;
  ft.rowptr = rp;
  ft.cols = cols_.data();
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
  FastSites fs;
  fs.status = site_status_.data();
  fs.support = site_support_.data();
  fs.order = site_order_.data();
  fs.cond = cond_.data();
  fs.order_used = order_;
  const bool fast = fast_->ok();
#if MFREE_SIMD_X86
  const bool avx2 = dim == 2 && simd::use_avx2();
#endif
  for (int32_t c0 = k0; c0 < k1; c0 += kChunk) {
    const int32_t c1 = std::min(k1, c0 + kChunk);
    for (int32_t k = c0; k < c1; ++k) {
      if (transpose) {  // the rows' places come from prepare's filter
        for (int64_t e = crp[k]; e < crp[k + 1]; ++e)
          if (cpos[e] >= 0) cols_[rbeg[k] + cpos[e]] = ccols[e];
      } else {
        const int64_t o = k == c0 ? crp[k] : rend[k - 1];
        const int32_t *cc = ccols + crp[k];
        const int64_t nc = crp[k + 1] - crp[k];
        int32_t *js = cols_.data() + o;
        int n;
#if MFREE_SIMD_X86
        if (avx2) n = kept_columns2_avx2(xn, k, cc, nc, R2, js);
        else n = dim == 2 ? kept_columns<2>(xn, k, cc, nc, R2, js) : kept_columns<3>(xn, k, cc, nc, R2, js);
#else
        n = dim == 2 ? kept_columns<2>(xn, k, cc, nc, R2, js) : kept_columns<3>(xn, k, cc, nc, R2, js);
#endif
        rbeg[k] = o;
        rend[k] = o + n;
      }
      rp[k] = rbeg[k];  // the chunk's rows lie one after another
      // the node's place in its row (sorted; it is its own neighbour at distance 0)
      const int32_t *row = cols_.data() + rbeg[k];
      self_[k] = static_cast<int32_t>(std::lower_bound(row, row + (rend[k] - rbeg[k]), k) - row);
    }
    rp[c1] = rend[c1 - 1];
    if (fast) fast_->run(ft, c0, c1, w.fast, fs);
    for (int32_t k = c0; k < c1; ++k) {
      const bool done = fast && site_status_[k] != kFastPending;
      if (!done || cond_[k] > shepard_cond_) general_row(k, xn, w, done);
    }
  }
  if (!transpose) return false;
  bool one_way = false;
  const int64_t *ctr = ctrans_.data();
  for (int32_t k = k0; k < k1; ++k) {  // N_k(x_j) is entry (j, k) of the transpose
    int m = 0;
    for (int64_t e = crp[k]; e < crp[k + 1]; ++e) {
      if (cpos[e] < 0) continue;
      const int64_t q = rbeg[k] + m++, tr = ctr[e];
      if (tr < 0 || cpos[tr] < 0) {
        one_way = true;
        continue;
      }
      const int32_t j = ccols[e];
      double *nt = NT_.data() + (rbeg[j] + cpos[tr]) * (dim + 1);  // one cache line per entry
      nt[0] = N_[q];
      for (int c = 0; c < dim; ++c) nt[1 + c] = G_[q * dim + c];
    }
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
  const int32_t *js = cols_.data() + o;
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
  in.self = self_[k];
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
  const double *xn = node_positions(y);  // + dummies (fluid_wall.cpp)
  Report r = candidates(xn);
  if (!r.ok()) return r;
  const int nt = num_threads(nall);
  const int64_t *crp = cand_.rowptr.data();
  const int32_t *ccols = cand_.cols.data();
  const int64_t nchunk = (nall + kChunk - 1) / kChunk;  // the tables are written by chunks
  const bool transpose = vci_;  // only consistent integration reads NT_ (fluid_wall.cpp)
  if (transpose) {
    // the transposed writes need every row's kept positions first: a filter pass (the
    // rows filter on the fly otherwise), the same symmetric test as kept_columns
    if (!ctrans_valid_) transposed_candidates();
    const double R = kernel_->radius() * h_, R2 = R * R;
    auto filter = [&](auto dimc) {
      constexpr int D = decltype(dimc)::value;
      int32_t *cpos = cpos_.data();
      int64_t *rbeg = rb_.data(), *rend = re_.data();
      parallel_blocks(nchunk, nt, [&](int, int64_t cb, int64_t ce) {
        for (int64_t k = cb * kChunk; k < std::min<int64_t>(nall, ce * kChunk); ++k) {
          const double *xk = xn + k * D;
          int32_t cnt = 0;
          for (int64_t q = crp[k]; q < crp[k + 1]; ++q) {
            const double *xj = xn + static_cast<size_t>(ccols[q]) * D;
            double r2 = 0.0;
            for (int c = 0; c < D; ++c) {
              const double d = xj[c] - xk[c];
              r2 += d * d;
            }
            const int32_t keep = r2 < R2;
            cpos[q] = keep ? cnt : -1;
            cnt += keep;
          }
          rbeg[k] = k % kChunk == 0 ? crp[k] : rend[k - 1];
          rend[k] = rbeg[k] + cnt;
        }
      });
    };
    if (dim == 2) filter(std::integral_constant<int, 2>());
    else filter(std::integral_constant<int, 3>());
  }
  if (!fast_) fast_ = std::make_unique<FastPath>(dim, method_, order_, *kernel_, MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT);
  if (rows_scratch_.size() < static_cast<size_t>(nt)) rows_scratch_.resize(nt);
  const int maxrow = static_cast<int>(maxrow_);
  for (int t = 0; t < nt; ++t) {  // sized for the longest row: no allocation in the rows
    RowsScratch &w = rows_scratch_[t];
    w.fast.reserve(maxrow);
    if (w.d.size() < 3 * static_cast<size_t>(maxrow)) w.d.resize(3 * static_cast<size_t>(maxrow));
    if (w.v.size() < static_cast<size_t>(maxrow)) w.v.resize(maxrow);
    if (w.h.size() < static_cast<size_t>(maxrow)) w.h.resize(maxrow);
    w.work.reserve(maxrow, dim, basis_size(dim, std::max(order_, 1)));
    w.rp.resize(static_cast<size_t>(nall) + 1);
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
