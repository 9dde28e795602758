#include "core/shape/approximant.hpp"

#include <algorithm>
#include <atomic>
#include <cfloat>
#include <cmath>
#include <limits>
#include <sstream>
#include <type_traits>

#include "core/base/basis.hpp"
#include "core/base/parallel.hpp"
#include "core/particles/neighbors.hpp"

namespace mfree {

namespace {

bool needs_volumes(int m) {
  return m == MFREE_METHOD_SPH || m == MFREE_METHOD_SPH_SYMMETRIC || m == MFREE_METHOD_RKPM ||
         m == MFREE_METHOD_SSPH || m == MFREE_METHOD_MSPH || m == MFREE_METHOD_JOHNSON_BEISSEL ||
         m == MFREE_METHOD_RANDLES_LIBERSKY;
}
// Methods that differentiate the kernel for their gradient table (all but SSPH and KB
// Method 2, which fit derivatives without W').
bool gradient_needs_dw(int m) { return m != MFREE_METHOD_SSPH && m != MFREE_METHOD_KB_METHOD2; }
bool hessian_needs_d2w(int m) {
  return m == MFREE_METHOD_SPH || m == MFREE_METHOD_SHEPARD || m == MFREE_METHOD_MLS ||
         m == MFREE_METHOD_RKPM || m == MFREE_METHOD_MSPH;
}
// Doubles per particle record of pack(): coordinates, volume and support, except in 3D:
// x y z vol (32 bytes, one aligned load per neighbour in the fast path, never split
// across cache lines), the supports in an array after the records.
constexpr int record_length(int dim) { return dim == 3 ? 4 : dim + 2; }
// Where pack() puts the n particles' supports in its block P: the support of particle
// i is h[i * stride] (after the records in 3D, inside them otherwise).
struct PackedSupports {
  double *h;
  int64_t stride;
};
PackedSupports packed_supports(double *P, int dim, int64_t n) {
  const int64_t S = record_length(dim);
  return S < dim + 2 ? PackedSupports{P + S * n, 1} : PackedSupports{P + dim + 1, S};
}
const char *method_name(int m) {
  static const char *names[] = {"?", "SPH", "SPH symmetric", "Shepard", "MLS", "RKPM",
                                "Johnson-Beissel", "Randles-Libersky", "KB Method 1",
                                "KB Method 2", "KB Method 3", "MSPH", "SSPH", "MPFEM"};
  return (m >= 1 && m <= 13) ? names[m] : names[0];
}
int default_order(int m) {
  switch (m) {
    case MFREE_METHOD_RKPM:
    case MFREE_METHOD_SSPH:
    case MFREE_METHOD_MSPH:
      return 2;
    case MFREE_METHOD_MLS:
    case MFREE_METHOD_KB_METHOD2:
      return 1;
    default:
      return fixed_order(m);
  }
}

}  // namespace

Approximant::Approximant(const ParticleSet *ps, int method) : ps_(ps), method_(method) {
  if (method < MFREE_METHOD_SPH || method > MFREE_METHOD_MPFEM)
    throw Error(MFREE_ERR_ARG, "unknown method " + std::to_string(method));
  order_ = default_order(method);
  if (method == MFREE_METHOD_MPFEM) {  // linear general shape functions, cosine kernel
    order_ = 1;
    kernel_id_ = MFREE_KERNEL_COSINE;
  }
  kernel_ = std::make_unique<Kernel>(kernel_id_, ps->dim(), kernel_param_);
}

Approximant::Approximant(const ParticleSet *ps, const ApproxConfig &cfg) : Approximant(ps, cfg.method) {
  set_kernel(cfg.kernel, cfg.param);
  if (has_order(method_)) set_order(cfg.order);
  set_derivatives(cfg.flags);
  set_fallback(cfg.fallback);
  if (method_ == MFREE_METHOD_MPFEM) {
    set_mesh(cfg.mesh);
    set_mpfem(cfg.mpfem_deriv, cfg.mpfem_ngauss);
  }
}

ApproxConfig Approximant::config() const {
  ApproxConfig c;
  c.method = method_;
  c.kernel = kernel_id_;
  c.param = kernel_param_;
  c.order = order_;
  c.flags = flags_;
  c.fallback = fallback_;
  c.mesh = mesh_;
  c.mpfem_deriv = mpfem_deriv_;
  c.mpfem_ngauss = mpfem_ngauss_;
  return c;
}

void Approximant::set_kernel(int kernel, double param) {
  auto k = std::make_unique<Kernel>(kernel, ps_->dim(), param);  // validates
  kernel_ = std::move(k);
  kernel_id_ = kernel;
  kernel_param_ = param;
  setup_done_ = false;
}

void Approximant::set_order(int order) {
  if (method_ == MFREE_METHOD_MPFEM) {
    if (order != 1)
      throw Error(MFREE_ERR_UNSUPPORTED, "MPFEM has fixed order 1 (linear general shape functions)");
    return;
  }
  if (!has_order(method_)) {
    if (order != fixed_order(method_))
      throw Error(MFREE_ERR_UNSUPPORTED, std::string(method_name(method_)) + " has fixed order " +
                                             std::to_string(fixed_order(method_)));
    return;
  }
  if (order < min_order(method_) || order > max_order(method_))
    throw Error(MFREE_ERR_UNSUPPORTED, std::string(method_name(method_)) + " supports orders " +
                                           std::to_string(min_order(method_)) + ".." +
                                           std::to_string(max_order(method_)) + ", not " +
                                           std::to_string(order));
  order_ = order;
  setup_done_ = false;
}

void Approximant::set_derivatives(int flags) {
  if (flags <= 0 || flags > 7)
    throw Error(MFREE_ERR_ARG, "derivative flags " + std::to_string(flags) +
                                   " are not an or of MFREE_DERIV_VALUE/GRADIENT/HESSIAN");
  if ((flags & MFREE_DERIV_HESSIAN) && method_ != MFREE_METHOD_MPFEM &&
      !provides_hessian(method_, max_order(method_)))
    throw Error(MFREE_ERR_UNSUPPORTED,
                std::string(method_name(method_)) + " provides no second derivatives");
  flags_ = flags;
  setup_done_ = false;
}

void Approximant::set_fallback(int policy) {
  if (policy != MFREE_FALLBACK_NONE && policy != MFREE_FALLBACK_LOWER_ORDER)
    throw Error(MFREE_ERR_ARG, "unknown fallback policy " + std::to_string(policy));
  fallback_ = policy;
}

void Approximant::set_points(int32_t npts, const double *x, int layout, int64_t ld,
                             const double *h, int64_t h_stride, int mem) {
  if (particles_only(method_))
    throw Error(MFREE_ERR_UNSUPPORTED, std::string(method_name(method_)) +
                                           " is defined at the particles only");
  if (mem != MFREE_COPY && mem != MFREE_BORROW)
    throw Error(MFREE_ERR_ARG, "mem must be MFREE_COPY or MFREE_BORROW, got " + std::to_string(mem));
  // Reuse the particle-set validation on a scratch set of the points, borrowing them
  // (a copy there would hold the points' memory twice).
  {
    ParticleSet tmp(ps_->dim(), npts);
    tmp.set_positions(x, layout, ld, MFREE_BORROW);
    tmp.set_support(h, h_stride, MFREE_BORROW);
  }
  // The new arrays are made aside and swapped in (nothing throws after the first
  // change): running out of memory leaves the approximant as it was.
  VectorArray px;
  ScalarArray ph;
  px.ptr = x;
  px.ld = ld;
  px.layout = layout;
  ph.ptr = h;
  ph.stride = h_stride;
  if (mem == MFREE_COPY) {
    const int d = dim();
    px.own.assign(static_cast<size_t>(npts) * d + 1, 0.0);
    const int32_t nh = h_stride == 0 ? 1 : npts;
    ph.own.assign(static_cast<size_t>(std::max(nh, 1)), 1.0);
    for (int32_t i = 0; i < npts; ++i)
      for (int c = 0; c < d; ++c) px.own[static_cast<size_t>(i) * d + c] = px(i, c);
    for (int32_t i = 0; i < nh; ++i) ph.own[i] = h[i * h_stride];
    px.ptr = px.own.data();
    px.ld = d;
    px.layout = MFREE_LAYOUT_AOS;
    ph.ptr = ph.own.data();
    ph.stride = h_stride == 0 ? 0 : 1;
  } else {
    if (!px.ptr) {
      px.own.assign(1, 0.0);
      px.ptr = px.own.data();
    }
    if (!ph.ptr) {
      ph.own.assign(1, 1.0);
      ph.ptr = ph.own.data();
    }
  }
  px_.own.swap(px.own);
  px_.ptr = px.ptr;
  px_.ld = px.ld;
  px_.layout = px.layout;
  ph_.own.swap(ph.own);
  ph_.ptr = ph.ptr;
  ph_.stride = ph.stride;
  npts_ = npts;
  points_ = true;
  setup_done_ = false;
}

void Approximant::validate_config() const {
  const int k = kernel_id_, m = method_;
  // the name is built on failure only (update allocates nothing; "Randles-Libersky" outgrows SSO)
  auto mn = [m] { return std::string(method_name(m)); };
  if (!ps_->has_support())
    throw Error(MFREE_ERR_STATE, "the particle set has no support sizes (the kernel needs h)");
  if (needs_volumes(m) && !ps_->has_volumes())
    throw Error(MFREE_ERR_STATE, mn() + " needs particle volumes (or masses and densities)");
  if (!ps_->host_neighbors() && kernel_->radius() > ps_->kappa() * (1.0 + 1e-12)) {
    std::ostringstream s;
    s << "kernel support radius " << kernel_->radius() << " h exceeds the search radius kappa = "
      << ps_->kappa() << " h of the particle set (mfree_particles_set_search)";
    throw Error(MFREE_ERR_MISMATCH, s.str());
  }
  if (points_ && particles_only(m))
    throw Error(MFREE_ERR_UNSUPPORTED, mn() + " is defined at the particles only");
  const bool grad = flags_ & MFREE_DERIV_GRADIENT, hess = flags_ & MFREE_DERIV_HESSIAN;
  const bool uses_dw = (grad && gradient_needs_dw(m)) || m == MFREE_METHOD_MSPH ||
                       m == MFREE_METHOD_JOHNSON_BEISSEL || m == MFREE_METHOD_RANDLES_LIBERSKY ||
                       m == MFREE_METHOD_KB_METHOD1 || m == MFREE_METHOD_KB_METHOD3;
  if (k == MFREE_KERNEL_LINEAR && uses_dw)
    throw Error(MFREE_ERR_UNSUPPORTED,
                mn() + " differentiates the kernel; the linear kernel's derivative is constant "
                     "(paper 001 Sect. 6.2): use SSPH or another kernel");
  const bool uses_d2w = (hess && hessian_needs_d2w(m)) || (m == MFREE_METHOD_MSPH && order_ >= 2);
  if ((k == MFREE_KERNEL_LINEAR || k == MFREE_KERNEL_QUADRATIC) && uses_d2w)
    throw Error(MFREE_ERR_UNSUPPORTED,
                mn() + " needs the kernel's second derivative, constant for the linear and "
                     "quadratic kernels (paper 001 Sect. 6.2)");
  if (hess && !provides_hessian(m, order_))
    throw Error(MFREE_ERR_UNSUPPORTED, mn() + " of order " + std::to_string(order_) +
                                           " provides no second derivatives");
}

double Approximant::site_x(int32_t s, int c) const { return points_ ? px_(s, c) : ps_->x(s, c); }
double Approximant::site_h(int32_t s) const { return points_ ? ph_(s) : ps_->h(s); }

void Approximant::site_displacement(int32_t s, int32_t j, double *d) const {
  if (!points_) {
    ps_->displacement(j, s, d);
    return;
  }
  for (int c = 0; c < dim(); ++c) {
    double v = ps_->x(j, c) - px_(s, c);
    if (ps_->periodic(c)) {
      const double L = ps_->box_hi(c) - ps_->box_lo(c);
      v -= L * std::nearbyint(v / L);
    }
    d[c] = v;
  }
}

double Approximant::pair_h(int32_t s, int32_t j) const {
  return pair_support(ps_->search_convention(), site_h(s), ps_->h(j));
}

LocalConfig Approximant::local_config(bool value, bool grad, bool hess) const {
  LocalConfig cfg;
  cfg.method = method_;
  cfg.dim = ps_->dim();
  cfg.order = order_;
  cfg.want_value = value;
  cfg.want_grad = grad;
  cfg.want_hess = hess;
  cfg.kernel = kernel_.get();
  return cfg;
}

void Approximant::pack() {
  const int dim = ps_->dim();
  const int32_t np = ps_->size();
  const bool have_vol = ps_->has_volumes();
  const size_t N = static_cast<size_t>(np);
  // AoS, one record per particle (coordinates, volume, support; record_length): the data
  // of a neighbour come in one cache line
  const size_t S = static_cast<size_t>(record_length(dim));
  // (+ supports after the records; + one spare record, so that data() + offset, for the
  // fields of record 0, stays inside the block when there are no particles)
  pack_.resize(S * N + (S < static_cast<size_t>(dim) + 2 ? N : 0) + S);
  double *P = pack_.data();
  const PackedSupports ph = packed_supports(P, dim, np);
  double *H = ph.h;
  const size_t HS = static_cast<size_t>(ph.stride);
  parallel_blocks(np, num_threads(np), [&](int, int64_t b, int64_t e) {
    for (int64_t i = b; i < e; ++i) {
      const int32_t j = static_cast<int32_t>(i);
      double *r = P + S * static_cast<size_t>(i);
      for (int c = 0; c < dim; ++c) r[c] = ps_->x(j, c);
      r[dim] = have_vol ? ps_->volume(j) : 1.0;
      H[HS * static_cast<size_t>(i)] = ps_->h(j);
    }
  });
  if (!points_) {
    spack_.clear();
    return;
  }
  const size_t M = static_cast<size_t>(npts_);
  const size_t T = static_cast<size_t>(dim) + 1;
  spack_.resize(T * M + T);  // (+ one spare record, as pack_)
  for (int32_t s = 0; s < npts_; ++s) {
    for (int c = 0; c < dim; ++c) spack_[T * s + c] = px_(s, c);
    spack_[T * s + dim] = ph_(s);
  }
}

void Approximant::build_pattern() {
  const int dim = ps_->dim();
  const double R = kernel_->radius();
  const Csr *src = &ps_->neighbors();
  if (points_) {
    // validate the points' borrowed data like particle data
    for (int32_t s = 0; s < npts_; ++s) {
      for (int c = 0; c < dim; ++c)
        if (!std::isfinite(px_(s, c)))
          throw Error(MFREE_ERR_INPUT, "point " + std::to_string(s) + " has a non-finite coordinate");
      if (!(std::isfinite(ph_(s)) && ph_(s) > 0.0))
        throw Error(MFREE_ERR_INPUT, "point " + std::to_string(s) + " has support <= 0 or non-finite");
    }
    find_point_neighbors(*ps_, ps_->site_status(), npts_, px_, ph_, point_nbr_);
    src = &point_nbr_;
    nsites_ = npts_;
  } else {
    nsites_ = ps_->num_owned();
  }
  // every entry is written below (and status_ by compute), in parallel blocks
  rowptr_.resize(static_cast<size_t>(nsites_) + 1);
  rowptr_[0] = 0;
  self_.resize(nsites_);
  status_.resize(nsites_);
  const auto &pst = ps_->site_status();
  // The row of site s: its neighbours within the kernel's support (closed, kEdgeTol) in
  // the order of the neighbour list, the particle itself always (appended when a host
  // list omits it). Counted in a first pass and written in a second, both over static
  // blocks of sites, so that the pattern is the same for any thread count.
  // records of pack() (particles: coordinates, volume, support; record_length) and of the
  // sites; the supports PH (particles) and SH (sites) with their strides
  const int64_t PS = record_length(dim), SS = points_ ? dim + 1 : PS;
  const double *P = pack_.data(), *SP = points_ ? spack_.data() : P;
  const PackedSupports ph = packed_supports(pack_.data(), dim, ps_->size());
  const double *PH = ph.h;
  const int64_t PHS = ph.stride;
  const double *SH = points_ ? SP + dim : PH;
  const int64_t SHS = points_ ? SS : PHS;
  bool per[3] = {false, false, false};
  double period[3] = {0, 0, 0};
  for (int c = 0; c < dim; ++c) {
    per[c] = ps_->periodic(c);
    period[c] = ps_->box_hi(c) - ps_->box_lo(c);
  }
  const int conv = ps_->search_convention();
  const bool any_periodic = per[0] || per[1] || per[2];
  const double tol = 1.0 + kEdgeTol2;
  // The common case: the kernel's support is the set's search radius (R h_s = kappa h_s,
  // gather, no periodic axis, lists found by the set's own search), so the filter below
  // would keep every entry (same closed-edge test d^2 <= (R h_s)^2 (1 + kEdgeTol2)) and
  // the pattern is the set's rows: copied, not rebuilt.
  if (!points_ && !ps_->host_neighbors() && conv == MFREE_SEARCH_GATHER && !any_periodic &&
      R == ps_->kappa() && share_rows(*src))
    return;
  // One pass over static blocks of sites (the pattern is the same for any thread count):
  // row s is written at src->rowptr[s] + s (room for every candidate and an appended
  // self), then the rows are moved down to their final offsets.
  const int64_t *srp = src->rowptr.data();
  const int32_t *scl = src->cols.data();
  check_table_size(src->nnz() + nsites_);
  cols_.resize(static_cast<size_t>(src->nnz()) + static_cast<size_t>(nsites_));
  int32_t *cl = cols_.data();
  int32_t *self = self_.data();
  int64_t *rp = rowptr_.data();
  const int64_t *gid = ps_->global_ids();
  const int nt = num_threads(src->nnz());
  parallel_blocks(nsites_, nt, [&](int, int64_t b, int64_t e) {
    for (int64_t s = b; s < e; ++s) {
      const int32_t me = site_particle(static_cast<int32_t>(s));
      const int64_t base = srp[s] + s;
      int64_t k = base;
      if (me >= 0 && pst[me] != 0) {
        rp[s + 1] = 0;
        continue;
      }
      const double *sr = SP + s * SS;
      const double hs = SH[s * SHS];
      const double xs[3] = {sr[0], dim > 1 ? sr[1] : 0.0, dim > 2 ? sr[2] : 0.0};
      int64_t at_self = -1;
      if (conv == MFREE_SEARCH_GATHER && !any_periodic) {
        // the common case, branch-free: keep j when within R hs (or j is the site)
        const double lim = R * hs, lim2 = lim * lim * tol;
        // the record length as a compile-time constant for 2D and 3D
        auto scan = [&](auto dimc) {
          constexpr int D = decltype(dimc)::value;
          const int pd = D > 0 ? D : dim;
          const int64_t ps = D > 0 ? record_length(D) : PS;
          for (int64_t q = srp[s]; q < srp[s + 1]; ++q) {
            const int32_t j = scl[q];
            const double *pj = P + j * ps;
            double r2 = 0.0;
            for (int c = 0; c < pd; ++c) {
              const double v = pj[c] - xs[c];
              r2 += v * v;
            }
            if (j == me) at_self = k;
            cl[k] = j;
            k += (r2 <= lim2) | (j == me);
          }
        };
        if (dim == 2) scan(std::integral_constant<int, 2>());
        else if (dim == 3) scan(std::integral_constant<int, 3>());
        else scan(std::integral_constant<int, 0>());
      } else {
        for (int64_t q = srp[s]; q < srp[s + 1]; ++q) {
          const int32_t j = scl[q];
          if (j == me) {
            at_self = k;
            cl[k++] = j;
            continue;
          }
          double r2 = 0.0;
          for (int c = 0; c < dim; ++c) {
            double v = P[j * PS + c] - xs[c];
            if (per[c]) v -= period[c] * std::nearbyint(v / period[c]);
            r2 += v * v;
          }
          const double hj = PH[j * PHS];
          const double hp = conv == MFREE_SEARCH_SYMMETRIC_MAX    ? std::max(hs, hj)
                            : conv == MFREE_SEARCH_SYMMETRIC_MEAN ? 0.5 * (hs + hj)
                                                                  : hs;
          const double rad = R * hp;
          if (r2 <= rad * rad * tol) cl[k++] = j;
        }
      }
      if (me >= 0 && at_self < 0) {  // host lists may omit the particle itself
        at_self = k;
        cl[k++] = me;
        if (gid)  // in its place by global id
          for (; at_self > base && gid[cl[at_self - 1]] > gid[me]; --at_self)
            std::swap(cl[at_self - 1], cl[at_self]);
      }
      self[s] = at_self < 0 ? -1 : static_cast<int32_t>(at_self - base);
      rp[s + 1] = k - base;
    }
  });
  maxrow_ = 0;
  for (int32_t s = 0; s < nsites_; ++s) {
    const int64_t base = srp[s] + s, cnt = rp[s + 1];
    maxrow_ = std::max(maxrow_, static_cast<int>(cnt));
    rp[s + 1] = rp[s] + cnt;
    if (rp[s] != base) std::copy(cl + base, cl + base + cnt, cl + rp[s]);  // moves down
  }
  cols_.resize(static_cast<size_t>(rp[nsites_]));
}

void Approximant::check_table_size(int64_t nnz) const {
  // the pattern and every table it will hold, before any of them is allocated
  const int dim = ps_->dim();
  const double per = sizeof(int32_t) + sizeof(double) * (((flags_ & MFREE_DERIV_VALUE) ? 1 : 0) +
                                                         ((flags_ & MFREE_DERIV_GRADIENT) ? dim : 0) +
                                                         ((flags_ & MFREE_DERIV_HESSIAN) ? hessian_size(dim) : 0));
  const double bytes = per * static_cast<double>(nnz);
  if (request_too_large(bytes)) {
    std::ostringstream s;
    s << "the shape-function tables of " << nnz << " neighbour pairs would take " << bytes / 1e9
      << " GB, more than the machine's memory (" << physical_memory() / 1e9
      << " GB): supports too large for the particle spacing?";
    throw Error(MFREE_ERR_ALLOC, s.str());
  }
}

bool Approximant::share_rows(const Csr &src) {
  const auto &pst = ps_->site_status();
  for (int32_t s = 0; s < nsites_; ++s)
    if (pst[s] != 0) return false;  // failed particles get empty rows: filter
  const int64_t nnz = src.nnz();
  if (static_cast<int64_t>(src.rowptr.size()) != static_cast<int64_t>(nsites_) + 1) return false;
  check_table_size(nnz);
  cols_.resize(static_cast<size_t>(nnz));
  const int64_t *srp = src.rowptr.data();
  const int32_t *scl = src.cols.data();
  int32_t *cl = cols_.data(), *self = self_.data();
  int64_t *rp = rowptr_.data();
  const int64_t *gid = ps_->global_ids();
  // static blocks of sites, each copying its rows and finding the site in them (rows
  // are sorted: a binary search)
  const int nt = num_threads(nnz);
  std::atomic<int64_t> missing{0};
  std::atomic<int> longest{0};
  parallel_blocks(nsites_, nt, [&](int, int64_t b, int64_t e) {
    if (b >= e) return;
    std::copy(srp + b + 1, srp + e + 1, rp + b + 1);
    int miss = 0;
    int64_t big = 0;
    for (int64_t s = b; s < e; ++s) {
      // the row copied, and the site's place in it (sorted) found as the count of smaller
      // entries in the same pass (no branch to mispredict, unlike a binary search)
      const int32_t *r0 = scl + srp[s];
      int32_t *out = cl + srp[s];
      const int n = static_cast<int>(srp[s + 1] - srp[s]);
      const int32_t me = static_cast<int32_t>(s);
      int at = 0;
      if (gid) {  // rows in global-id order
        const int64_t gme = gid[me];
        for (int q = 0; q < n; ++q) {
          const int32_t v = r0[q];
          out[q] = v;
          at += gid[v] < gme;
        }
      } else {
#ifdef _OPENMP
#pragma omp simd reduction(+ : at)
#endif
        for (int q = 0; q < n; ++q) {
          const int32_t v = r0[q];
          out[q] = v;
          at += v < me;
        }
      }
      const bool found = at < n && r0[at] == me;
      self[s] = found ? at : -1;
      miss += !found;
      big = std::max<int64_t>(big, n);
    }
    if (miss) missing += miss;
    int cur = longest.load();
    while (big > cur && !longest.compare_exchange_weak(cur, static_cast<int>(big))) {
    }
  });
  maxrow_ = longest;
  return missing == 0;  // else a row lacks its site (never from the set's search): filter
}

Report Approximant::compute(const char *what) {
  (void)what;
  const int dim = ps_->dim(), nh = hessian_size(dim);
  const size_t nnz = cols_.size();
  const bool fv = flags_ & MFREE_DERIV_VALUE, fg = flags_ & MFREE_DERIV_GRADIENT,
             fh = flags_ & MFREE_DERIV_HESSIAN;
  // same sizes on update: nothing is allocated; every row is written below (by the fast
  // path or by compute_site, which zeroes failed rows), so no fill is needed
  val_.resize(fv ? nnz : 0);
  grad_.resize(fg ? nnz * dim : 0);
  hess_.resize(fh ? nnz * nh : 0);
  // per-site results: every site's entries are written in the parallel loop below
  support_.resize(nsites_);
  cond_.resize(nsites_);
  order_used_.resize(nsites_);
  find_bad_particles();

  const LocalConfig base = local_config(fv, fg, fh);

  // Per-thread scratch sized for the longest row before the threads start, so that no
  // site allocates; sites are split statically and are independent, so the tables do
  // not depend on the thread count.
  const int nt = num_threads(nsites_);
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
  // The specialised path for the common configurations (shape_fast.hpp); a site it
  // cannot finish is recomputed below by the general path with its fallbacks.
  const FastPath fast(dim, method_, order_, *kernel_, flags_);
  FastTables ft;
  if (fast.ok()) {
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
    ft.val = fv ? val_.data() : nullptr;
    ft.grad = fg ? grad_.data() : nullptr;
  }
  // The sites' correction records for the pair gradients (pair-list sets): written by
  // the fast path or compute_site alongside the rows where they can, the rest after
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
  parallel_blocks(nsites_, nt, [&](int t, int64_t b, int64_t e) {
    SiteScratch &w = scratch_[t];
    LocalConfig cfg = base;
    if (fast.ok()) fast.run(ft, b, e, w.fast, fs);
    int64_t bad = 0;
    for (int32_t s = static_cast<int32_t>(b); s < e; ++s) {
      if (fast.ok() && status_[s] != kFastPending) continue;
      const int32_t me = site_particle(s);
      if (me >= 0 && pst[me] != 0) {
        status_[s] = pst[me];
        support_[s] = 0;
        cond_[s] = 1.0;
        order_used_[s] = -1;
        continue;
      }
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
      out.coef = recs ? records_.data() + int64_t{s} * ncoef : nullptr;
      cfg.method = method_;
      cfg.order = order_;
      compute_site(cfg, in, w.work, out);
      if (out.status && fallback_ == MFREE_FALLBACK_LOWER_ORDER) {
        const int first_status = out.status;
        const double first_cond = out.cond;
        // A site that falls back gets a record of zeros (mfree.h): a lower order's or
        // Shepard's record has another layout, and Shepard's (1 + dim values) is longer
        // than Johnson-Beissel's or Randles-Libersky's, so it would run into the next one.
        if (out.coef) std::fill_n(out.coef, ncoef, 0.0);
        out.coef = nullptr;
        if (has_order(method_))
          for (int o = order_ - 1; o >= min_order(method_) && out.status; --o) {
            cfg.order = o;
            if (fh && !provides_hessian(method_, o)) break;
            compute_site(cfg, in, w.work, out);
          }
        if (out.status) {  // last resort: Shepard functions (constant complete)
          cfg.method = MFREE_METHOD_SHEPARD;
          cfg.order = 0;
          compute_site(cfg, in, w.work, out);
        }
        if (out.status) {
          out.status = first_status;
          out.cond = first_cond;
        }
      }
      status_[s] = out.status;
      support_[s] = out.support;
      cond_[s] = out.cond;
      order_used_[s] = out.order_used;
    }
    bad = screen_sites(b, e);
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
  if (nfailed) {
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
    const int64_t nf = nfailed;
    msg << " (" << nf << (nf == 1 ? " site" : " sites") << " failed; their rows are zero)";
    rep.fail(static_cast<mfree_status_t>(status_[s]), msg.str());
  }
  return rep;
}

const double *Approximant::packed_volumes(int64_t &stride) const {
  stride = record_length(ps_->dim());
  return pack_.data() + ps_->dim();
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

Report Approximant::setup() {
  if (method_ == MFREE_METHOD_MPFEM) {
    Report rep = compute_mpfem();
    record_set_state();
    setup_done_ = true;
    return rep;
  }
  validate_config();
  if (!points_) {
    const double R = kernel_->radius();
    const int conv = ps_->search_convention();
    double hmax = 0.0;
    if (conv != MFREE_SEARCH_GATHER && ps_->halo_width() > 0.0)
      for (int32_t j = 0; j < ps_->size(); ++j)
        if (ps_->site_status()[j] == 0) hmax = std::max(hmax, ps_->h(j));
    ps_->check_halo(
        [&](int32_t i) { return R * (conv == MFREE_SEARCH_GATHER ? ps_->h(i) : std::max(ps_->h(i), hmax)); },
        "kernel support");
  }
  pack();
  build_pattern();
  Report rep = compute("setup");
  record_set_state();
  setup_done_ = true;
  ghost_set_ = false;
  return rep;
}

Report Approximant::update() {
  if (!setup_done_) throw Error(MFREE_ERR_STATE, "update called before setup");
  check_set_unchanged();
  if (method_ == MFREE_METHOD_MPFEM) return compute_mpfem();
  validate_config();
  pack();
  Report rep = compute("update");
  ghost_set_ = false;
  return rep;
}

namespace {
// A 64-bit digest of the rows (order-sensitive; entries mixed independently so that the
// pass runs at memory speed, in blocks for the threads, combined in block order).
uint64_t rows_hash(const Csr &g) {
  auto mix = [](uint64_t v) {
    v ^= v >> 33;
    v *= 0xff51afd7ed558ccdULL;
    v ^= v >> 33;
    v *= 0xc4ceb9fe1a85ec53ULL;
    return v ^ (v >> 33);
  };
  const int64_t rows = static_cast<int64_t>(g.rowptr.size()) - 1;
  const int nt = std::min(num_threads(g.nnz()), 64);
  uint64_t part[64] = {0};
  const int64_t *rp = g.rowptr.data();
  const int32_t *cl = g.cols.data();
  parallel_blocks(rows, nt, [&](int t, int64_t b, int64_t e) {
    uint64_t h = 0;
    for (int64_t i = b; i < e; ++i) {
      h += mix(static_cast<uint64_t>(rp[i + 1]) * 0x9e3779b97f4a7c15ULL + static_cast<uint64_t>(i));
      for (int64_t k = rp[i]; k < rp[i + 1]; ++k)
        h += mix((static_cast<uint64_t>(k) << 32) ^ static_cast<uint32_t>(cl[k]));
    }
    part[t] = h;
  });
  uint64_t h = mix(static_cast<uint64_t>(rows));
  for (int t = 0; t < nt; ++t) h = mix(h ^ part[t]);
  return h;
}
}  // namespace

void Approximant::record_set_state() {
  set_setups_ = ps_->setup_count();
  set_owned_ = ps_->num_owned();
  // points: their pattern comes from their own search, not from the set's rows
  set_rows_hash_ = points_ ? 0 : rows_hash(ps_->neighbors());
}

void Approximant::check_set_unchanged() {
  if (!ps_->is_setup())
    throw Error(MFREE_ERR_STATE, "the particle set was changed (a set_* call) and is not set up: "
                                 "set it up, then call mfree_approximant_setup, not update");
  if (ps_->setup_count() == set_setups_) return;
  if (ps_->num_owned() != set_owned_)
    throw Error(MFREE_ERR_STATE, "the particle set now has " + std::to_string(ps_->num_owned()) +
                                     " owned particles, " + std::to_string(set_owned_) +
                                     " at this approximant's setup (ghost count changed): call "
                                     "mfree_approximant_setup, not update");
  if (!points_ && rows_hash(ps_->neighbors()) != set_rows_hash_)
    throw Error(MFREE_ERR_STATE, "the particle set was set up again with other neighbour lists "
                                 "since this approximant's setup (its pattern would be stale): "
                                 "call mfree_approximant_setup, not update");
  set_setups_ = ps_->setup_count();  // set up again with the same rows: still good
}

void Approximant::find_bad_particles() {
  const int32_t n = ps_->size();
  pbad_.resize(static_cast<size_t>(n));  // (same size on update: no allocation)
  int32_t *bad = pbad_.data();
  parallel_blocks(n, num_threads(n), [&](int, int64_t b, int64_t e) {
    for (int64_t i = b; i < e; ++i) bad[i] = ps_->data_status(static_cast<int32_t>(i));
  });
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
    for (int64_t k = k0; k < k1 && !cls; ++k) cls = bad[cols_[k]];
    if (!cls && status_[s] == 0) {
      bool finite = true;
      if (!val_.empty())
        for (int64_t k = k0; k < k1; ++k) finite &= std::fabs(val_[k]) <= DBL_MAX;
      if (!grad_.empty())
        for (int64_t k = k0 * dim; k < k1 * dim; ++k) finite &= std::fabs(grad_[k]) <= DBL_MAX;
      if (!hess_.empty())
        for (int64_t k = k0 * nh; k < k1 * nh; ++k) finite &= std::fabs(hess_[k]) <= DBL_MAX;
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

void Approximant::export_csr(int deriv, int component, int64_t *rowptr, int32_t *cols,
                             double *vals) const {
  const int dim = ps_->dim(), nh = hessian_size(dim);
  const HVec<double> *tab = nullptr;
  int stride = 1;
  if (deriv == MFREE_DERIV_VALUE) {
    tab = &val_;
    if (component != 0) throw Error(MFREE_ERR_ARG, "the value table has one component (0)");
  } else if (deriv == MFREE_DERIV_GRADIENT) {
    tab = &grad_;
    stride = dim;
  } else if (deriv == MFREE_DERIV_HESSIAN) {
    tab = &hess_;
    stride = nh;
  } else {
    throw Error(MFREE_ERR_ARG, "deriv must be one of MFREE_DERIV_VALUE, _GRADIENT, _HESSIAN");
  }
  if (component < 0 || component >= stride)
    throw Error(MFREE_ERR_ARG, "component " + std::to_string(component) + " is outside [0, " +
                                   std::to_string(stride) + ")");
  if (!(flags_ & deriv)) throw Error(MFREE_ERR_STATE, "that table was not built (set_derivatives)");
  if (rowptr) std::copy(rowptr_.begin(), rowptr_.end(), rowptr);
  if (cols) std::copy(cols_.begin(), cols_.end(), cols);
  if (vals)
    for (size_t k = 0; k < cols_.size(); ++k) vals[k] = (*tab)[k * stride + component];
}

void Approximant::check_reproduction(int order, double &fn_err, double &deriv_err) const {
  if (order < 0 || order > 3) throw Error(MFREE_ERR_ARG, "order must be 0..3");
  const int dim = ps_->dim(), nh = hessian_size(dim);
  const Basis B(dim, order);
  const int L = B.size();
  fn_err = deriv_err = 0.0;
  double p[kMaxBasis];
  for (int32_t s = 0; s < nsites_; ++s) {
    if (status_[s]) continue;
    const double hs = site_h(s), ih = 1.0 / hs;
    double sv[kMaxBasis] = {0}, sg[kMaxBasis][3] = {{0}}, sh[kMaxBasis][6] = {{0}};
    for (int64_t k = rowptr_[s]; k < rowptr_[s + 1]; ++k) {
      double d[3] = {0, 0, 0};
      site_displacement(s, cols_[k], d);
      for (int c = 0; c < dim; ++c) d[c] *= ih;
      B.eval(d, p);
      for (int m = 0; m < L; ++m) {
        if (!val_.empty()) sv[m] += val_[k] * p[m];
        if (!grad_.empty())
          for (int c = 0; c < dim; ++c) sg[m][c] += grad_[k * dim + c] * p[m];
        if (!hess_.empty())
          for (int e = 0; e < nh; ++e) sh[m][e] += hess_[k * nh + e] * p[m];
      }
    }
    for (int m = 0; m < L; ++m) {
      const auto &al = B.alpha(m);
      const int deg = B.degree(m);
      if (!val_.empty()) fn_err = std::max(fn_err, std::fabs(sv[m] - (deg == 0 ? 1.0 : 0.0)));
      if (!grad_.empty())
        for (int c = 0; c < dim; ++c) {
          const double exact = (deg == 1 && al[c] == 1) ? 1.0 : 0.0;
          deriv_err = std::max(deriv_err, std::fabs(sg[m][c] * hs - exact));
        }
      if (!hess_.empty())
        for (int a = 0; a < dim; ++a)
          for (int b = a; b < dim; ++b) {
            std::array<int, 3> want{0, 0, 0};
            ++want[a];
            ++want[b];
            const double exact = (al == want) ? (a == b ? 2.0 : 1.0) : 0.0;
            deriv_err = std::max(deriv_err, std::fabs(sh[m][hessian_index(dim, a, b)] * hs * hs - exact));
          }
    }
  }
}

}  // namespace mfree
