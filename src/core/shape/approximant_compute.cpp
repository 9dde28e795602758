// Approximant: the tables of every site (compute), by the fast path where it applies and
// the general path (local.cpp) elsewhere, and the screening of sites with invalid data.
#include "core/shape/approximant.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <sstream>

#include "core/base/basis.hpp"
#include "core/base/parallel.hpp"
#include "core/base/simd.hpp"
#include "core/shape/approximant_pack.hpp"

namespace mfree {

namespace {
// Sites computed before their rows are screened (screen_sites): rows of a few hundred
// sites stay in the L2 cache
constexpr int64_t kScreenBlock = 256;

}  // namespace

Report Approximant::compute(const char *what) {
  (void)what;
  const int dim = ps_->dim(), nh = hessian_size(dim);
  const size_t nnz = cols_.size();
  const bool fv = flags_ & MFREE_DERIV_VALUE, fg = flags_ & MFREE_DERIV_GRADIENT,
             fh = flags_ & MFREE_DERIV_HESSIAN;
  // same sizes on update: nothing is allocated; every row is written below (by the fast
  // path or by general_site, which zeroes failed rows), so no fill is needed
  val_.resize(fv ? nnz : 0);
  grad_.resize(fg ? nnz * dim : 0);
  hess_.resize(fh ? nnz * nh : 0);
  // per-site results: every site's entries are written in the parallel loop below
  support_.resize(nsites_);
  cond_.resize(nsites_);
  order_used_.resize(nsites_);
  find_bad_particles();

  const LocalConfig base = local_config(fv, fg, fh);
  const int nt = num_threads(nsites_);
  reserve_scratch(nt);
  // The specialised path for the common configurations (shape_fast.hpp); a site it
  // cannot finish is recomputed below by the general path with its fallbacks.
  const FastPath fast(dim, method_, order_, *kernel_, flags_);
  FastTables ft;
  if (fast.ok()) ft = fast_tables();
  // The sites' correction records for the pair gradients (pair-list sets): written by
  // the fast path or general_site alongside the rows where they can, the rest after
  // the rows (a NaN marks a record not written).
  const bool recs = keeps_records();
  const int ncoef = recs ? correction_size() : 0;
  if (recs) {
    records_.assign(static_cast<size_t>(nsites_) * ncoef, std::numeric_limits<double>::quiet_NaN());
    ft.coef = records_.data();
    ft.ncoef = ncoef;
  } else {
    records_.clear();
  }
  const auto &pst = ps_->site_status();
  FastSites fs;
  fs.status = status_.data();
  fs.support = support_.data();
  fs.cond = cond_.data();
  fs.order = order_used_.data();
  fs.pst = points_ ? nullptr : pst.data();
  fs.order_used = has_order(method_) ? order_ : fixed_order(method_);
  std::atomic<int64_t> nfailed{0};
  // the sites of a block, then their screening while their rows are still in cache
  auto sites = [&](int t, int64_t b, int64_t e) {
    SiteScratch &w = scratch_[t];
    if (fast.ok()) fast.run(ft, b, e, w.fast, fs);
    for (int32_t s = static_cast<int32_t>(b); s < e; ++s) {
      // a site done by the fast path goes on only when ill-conditioned (set_shepard_condition)
      const bool fast_done = fast.ok() && status_[s] != kFastPending;
      if (fast_done && !(status_[s] == 0 && cond_[s] > shepard_cond_)) continue;
      const int32_t me = site_particle(s);
      if (me >= 0 && pst[me] != 0) {
        status_[s] = pst[me];
        support_[s] = 0;
        cond_[s] = 1.0;
        order_used_[s] = -1;
        continue;
      }
      general_site(s, base, fast_done, w, recs ? records_.data() + int64_t{s} * ncoef : nullptr, ncoef);
    }
    return screen_sites(b, e);
  };
  parallel_blocks(nsites_, nt, [&](int t, int64_t b, int64_t e) {
    int64_t bad = 0;
    for (int64_t c = b; c < e; c += kScreenBlock) bad += sites(t, c, std::min<int64_t>(e, c + kScreenBlock));
    if (bad) nfailed += bad;
  });
  if (recs) {
    compute_records(records_.data(), ncoef, true);
    const int want = has_order(method_) ? order_ : fixed_order(method_);
    rec_ok_.assign(static_cast<size_t>(ps_->size()), 0);
    for (int32_t s = 0; s < nsites_; ++s)
      rec_ok_[s] = pst[s] == 0 && status_[s] == 0 && order_used_[s] == want;
  }
  Report rep;
  if (nfailed) report_failures(nfailed, rep);
  return rep;
}

void Approximant::reserve_scratch(int nt) {
  // Per-thread scratch sized for the longest row before the threads start, so that no
  // site allocates; sites are split statically and are independent, so the tables do
  // not depend on the thread count.
  const int dim = ps_->dim();
  if (scratch_.size() < static_cast<size_t>(nt)) scratch_.resize(nt);
  const int maxrow = maxrow_;
  const int maxL = basis_size(dim, std::max(has_order(method_) ? order_ : 1, 1));
  for (int t = 0; t < nt; ++t) {
    SiteScratch &w = scratch_[t];
    const size_t need = static_cast<size_t>(maxrow);
    if (w.d.size() < 3 * need) w.d.resize(3 * need);
    if (w.v.size() < need) w.v.resize(need);
    if (w.h.size() < need) w.h.resize(need);
    w.work.reserve(maxrow, dim, maxL);
    w.fast.reserve(maxrow);
  }
}

FastTables Approximant::fast_tables() {
  const int dim = ps_->dim();
  FastTables ft;
  ft.rowptr = rowptr_.data();
  ft.cols = cols_.data();
  ft.self = self_.data();
  for (int c = 0; c < dim; ++c) {
    ft.x[c] = pack_.data() + c;
    ft.sx[c] = points_ ? spack_.data() + c : ft.x[c];
    ft.periodic[c] = ps_->periodic(c);
    ft.period[c] = ps_->box_hi(c) - ps_->box_lo(c);
  }
  const int64_t PS = record_length(dim);
  const PackedSupports ph = packed_supports(pack_.data(), dim, ps_->size());
  ft.vol = pack_.data() + dim;
  ft.h = ph.h;
  ft.hstride = ph.stride;
  ft.sh = points_ ? spack_.data() + dim : ft.h;
  ft.shstride = points_ ? dim + 1 : ft.hstride;
  ft.stride = PS;
  ft.sstride = points_ ? dim + 1 : PS;
  ft.convention = ps_->search_convention();
  ft.val = (flags_ & MFREE_DERIV_VALUE) ? val_.data() : nullptr;
  ft.grad = (flags_ & MFREE_DERIV_GRADIENT) ? grad_.data() : nullptr;
  return ft;
}

void Approximant::general_site(int32_t s, const LocalConfig &base, bool fast_done, SiteScratch &w,
                               double *coef, int ncoef) {
  const int dim = ps_->dim(), nh = hessian_size(dim);
  const bool fv = flags_ & MFREE_DERIV_VALUE, fg = flags_ & MFREE_DERIV_GRADIENT,
             fh = flags_ & MFREE_DERIV_HESSIAN;
  const int64_t k0 = rowptr_[s];
  const int n = static_cast<int>(rowptr_[s + 1] - k0);
  site_input(s, w.d.data(), w.v.data(), w.h.data());
  LocalInput in;
  in.n = n;
  in.self = self_[s];
  in.hs = site_h(s);
  in.d = w.d.data();
  in.vol = w.v.data();
  in.h = w.h.data();
  LocalOutput out;
  // data() + offset, not &v[k]: the tables are empty when no site has a neighbour
  out.phi = fv ? val_.data() + k0 : nullptr;
  out.grad = fg ? grad_.data() + k0 * dim : nullptr;
  out.hess = fh ? hess_.data() + k0 * nh : nullptr;
  out.coef = coef;
  LocalConfig cfg = base;
  cfg.method = method_;
  cfg.order = order_;
  if (fast_done) {  // the fast path's result stands but for the rows
    out.status = 0;
    out.cond = cond_[s];
  }
  compute_site_rules(cfg, in, w.work, out, fallback_, shepard_cond_, fast_done, ncoef);
  status_[s] = out.status;
  support_[s] = out.support;
  cond_[s] = out.cond;
  order_used_[s] = out.order_used;
}

void Approximant::report_failures(int64_t nfailed, Report &rep) const {
  int32_t s = 0;
  while (!status_[s]) ++s;  // the first failed site
  std::ostringstream msg;
  msg << method_name(method_) << ": site " << s;
  if (status_[s] == MFREE_FAIL_NEIGHBORS)
    msg << " has " << support_[s] << " neighbours with non-zero weight, too few for the basis";
  else if (status_[s] == MFREE_FAIL_SINGULAR)
    msg << " has a singular local system (condition estimate " << cond_[s]
        << "; collinear, coincident or too few neighbours)";
  else if (status_[s] == MFREE_FAIL_NONFINITE)
    msg << " has a non-finite value in its data, a neighbour's, or its shape functions "
           "(a support too small for the coordinates' range?)";
  else
    msg << " has invalid particle data (a support or volume <= 0)";
  msg << " (" << nfailed << (nfailed == 1 ? " site" : " sites") << " failed; their rows are zero)";
  rep.fail(static_cast<mfree_status_t>(status_[s]), msg.str());
}

void Approximant::site_input(int32_t s, double *dd, double *v, double *h) const {
  const int dim = ps_->dim();
  bool periodic = false;
  for (int c = 0; c < dim; ++c) periodic = periodic || ps_->periodic(c);
  const bool gather = ps_->search_convention() == MFREE_SEARCH_GATHER;
  const bool have_vol = ps_->has_volumes();
  const int64_t k0 = rowptr_[s];
  const int n = static_cast<int>(rowptr_[s + 1] - k0);
  // x_j - x_s as site_displacement computes it, with the site's data hoisted
  double xs[3] = {0, 0, 0};
  for (int c = 0; c < dim; ++c) xs[c] = site_x(s, c);
  const double hs = site_h(s);
  for (int q = 0; q < n; ++q) {
    const int32_t j = cols_[k0 + q];
    double *d = dd + 3 * static_cast<size_t>(q);
    d[0] = d[1] = d[2] = 0.0;
    if (periodic) site_displacement(s, j, d);
    else
      for (int c = 0; c < dim; ++c) d[c] = ps_->x(j, c) - xs[c];
    v[q] = have_vol ? ps_->volume(j) : 1.0;
    h[q] = gather ? hs : pair_h(s, j);
  }
}

void Approximant::find_bad_particles() {
  const int32_t n = ps_->size();
  pbad_.resize(static_cast<size_t>(n));  // (same size on update: no allocation)
  int32_t *bad = pbad_.data();
  bool any[64] = {};  // per thread (parallel_blocks runs at most 64)
  parallel_blocks(n, num_threads(n), [&](int t, int64_t b, int64_t e) {
    int32_t all = 0;
    for (int64_t i = b; i < e; ++i) all |= bad[i] = ps_->data_status(static_cast<int32_t>(i));
    any[t] = all != 0;
  });
  any_bad_ = std::any_of(any, any + 64, [](bool a) { return a; });
}

int64_t Approximant::screen_sites(int64_t b, int64_t e) {
  const int dim = ps_->dim(), nh = hessian_size(dim);
  const int32_t *bad = pbad_.data();
  int64_t failed = 0;
  for (int64_t s = b; s < e; ++s) {
    int32_t cls = 0;
    const int32_t me = site_particle(static_cast<int32_t>(s));
    if (me >= 0) {
      cls = bad[me];
    } else {
      for (int c = 0; c < dim && !cls; ++c)
        if (!std::isfinite(px_(static_cast<int32_t>(s), c))) cls = MFREE_FAIL_NONFINITE;
      const double hs = ph_(static_cast<int32_t>(s));
      if (!cls && !std::isfinite(hs)) cls = MFREE_FAIL_NONFINITE;
      if (!cls && !(hs > 0.0)) cls = MFREE_FAIL_INVALID_DATA;
    }
    const int64_t k0 = rowptr_[s], k1 = rowptr_[s + 1];
    if (any_bad_)
      for (int64_t k = k0; k < k1 && !cls; ++k) cls = bad[cols_[k]];
    if (!cls && status_[s] == 0) {
      bool finite = true;
      if (!val_.empty()) finite &= simd::all_finite(val_.data() + k0, k1 - k0);
      if (!grad_.empty()) finite &= simd::all_finite(grad_.data() + k0 * dim, (k1 - k0) * dim);
      if (!hess_.empty()) finite &= simd::all_finite(hess_.data() + k0 * nh, (k1 - k0) * nh);
      if (!finite) cls = MFREE_FAIL_NONFINITE;
    }
    if (cls) {
      status_[s] = cls;
      order_used_[s] = -1;
      if (!val_.empty()) std::fill(val_.begin() + k0, val_.begin() + k1, 0.0);
      if (!grad_.empty()) std::fill(grad_.begin() + k0 * dim, grad_.begin() + k1 * dim, 0.0);
      if (!hess_.empty()) std::fill(hess_.begin() + k0 * nh, hess_.begin() + k1 * nh, 0.0);
    }
    failed += status_[s] != 0;
  }
  return failed;
}

}  // namespace mfree
