// Approximant: its configuration and checks, setup and update, the state of the particle
// set it was set up on, the CSR export and the reproduction check. The pattern is built
// in approximant_pattern.cpp, the tables in approximant_compute.cpp.
#include "core/shape/approximant.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "core/base/basis.hpp"
#include "core/base/parallel.hpp"

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

const char *method_name(int m) {
  static const char *names[] = {"?", "SPH", "SPH symmetric", "Shepard", "MLS", "RKPM",
                                "Johnson-Beissel", "Randles-Libersky", "KB Method 1",
                                "KB Method 2", "KB Method 3", "MSPH", "SSPH", "MPFEM"};
  return (m >= 1 && m <= 13) ? names[m] : names[0];
}

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

void Approximant::set_shepard_condition(double max_cond) {
  if (!(max_cond >= 1.0)) throw Error(MFREE_ERR_ARG, "the Shepard condition threshold must be >= 1");
  shepard_cond_ = max_cond;
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
  check_kernel_use(m, k, order_, flags_);
}

void Approximant::check_kernel_use(int m, int k, int order, int flags) {
  auto mn = [m] { return std::string(method_name(m)); };
  const bool grad = flags & MFREE_DERIV_GRADIENT, hess = flags & MFREE_DERIV_HESSIAN;
  const bool uses_dw = (grad && gradient_needs_dw(m)) || m == MFREE_METHOD_MSPH ||
                       m == MFREE_METHOD_JOHNSON_BEISSEL || m == MFREE_METHOD_RANDLES_LIBERSKY ||
                       m == MFREE_METHOD_KB_METHOD1 || m == MFREE_METHOD_KB_METHOD3;
  if (k == MFREE_KERNEL_LINEAR && uses_dw)
    throw Error(MFREE_ERR_UNSUPPORTED,
                mn() + " differentiates the kernel; the linear kernel's derivative is constant "
                     "(paper 001 Sect. 6.2): use SSPH or another kernel");
  const bool uses_d2w = (hess && hessian_needs_d2w(m)) || (m == MFREE_METHOD_MSPH && order >= 2);
  if ((k == MFREE_KERNEL_LINEAR || k == MFREE_KERNEL_QUADRATIC) && uses_d2w)
    throw Error(MFREE_ERR_UNSUPPORTED,
                mn() + " needs the kernel's second derivative, constant for the linear and "
                     "quadratic kernels (paper 001 Sect. 6.2)");
  if (hess && !provides_hessian(m, order))
    throw Error(MFREE_ERR_UNSUPPORTED, mn() + " of order " + std::to_string(order) +
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
uint64_t rows_hash(const int64_t *rp, const int32_t *cl, int64_t rows) {
  auto mix = [](uint64_t v) {
    v ^= v >> 33;
    v *= 0xff51afd7ed558ccdULL;
    v ^= v >> 33;
    v *= 0xc4ceb9fe1a85ec53ULL;
    return v ^ (v >> 33);
  };
  const int nt = std::min(num_threads(rp[rows]), 64);
  uint64_t part[64] = {0};
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
uint64_t rows_hash(const Csr &g) {
  return rows_hash(g.rowptr.data(), g.cols.data(), static_cast<int64_t>(g.rowptr.size()) - 1);
}
}  // namespace

void Approximant::record_set_state() {
  set_setups_ = ps_->setup_count();
  set_owned_ = ps_->num_owned();
  // points: their pattern comes from their own search, not from the set's rows
  // (a pattern that is a copy of the set's rows is their digest's source later: a setup
  // every step, as a moving-particle code does, then pays for no digest)
  set_rows_hash_ = points_ || rows_shared_ ? 0 : rows_hash(ps_->neighbors());
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
  const uint64_t then = rows_shared_ ? rows_hash(rowptr_.data(), cols_.data(), nsites_) : set_rows_hash_;
  if (!points_ && rows_hash(ps_->neighbors()) != then)
    throw Error(MFREE_ERR_STATE, "the particle set was set up again with other neighbour lists "
                                 "since this approximant's setup (its pattern would be stale): "
                                 "call mfree_approximant_setup, not update");
  set_setups_ = ps_->setup_count();  // set up again with the same rows: still good
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
