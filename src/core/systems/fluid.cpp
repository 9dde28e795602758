#include "core/systems/fluid.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <sstream>
#include <type_traits>

#include "core/base/kernel.hpp"
#include "core/base/parallel.hpp"
#include "core/base/simd.hpp"
#include "core/particles/neighbors.hpp"
#include "core/shape/shape_fast_mls1.hpp"

#ifdef __SSE2__
#include <emmintrin.h>
#endif
#if MFREE_SIMD_X86
#include <immintrin.h>
#endif

// Loops over a row's neighbours written for the vectoriser (any OpenMP: omp simd).
#define FLUID_PRAGMA(x) _Pragma(#x)
#ifdef _OPENMP
#define FLUID_SIMD(...) FLUID_PRAGMA(omp simd __VA_ARGS__)
#else
#define FLUID_SIMD(...)
#endif

namespace mfree {

namespace {
// Threads for a loop of a few operations per particle (checks, volumes, updates): a team
// and its barrier (a few microseconds on idle cores, far more on a loaded machine) pay
// off from ~8,000 particles.
inline int light_threads(int64_t n) { return num_threads(n / 4); }
}  // namespace

FluidSystem::FluidSystem(int dim, int32_t n) : dim_(dim), n_(n), ps_(dim, n) {
  if (dim != 2 && dim != 3) throw Error(MFREE_ERR_ARG, "the fluid system is 2D or 3D, not " + std::to_string(dim) + "D");
  rho0_.assign(n, 1000.0);
  vol_.assign(n > 0 ? n : 1, 1.0);
}

void FluidSystem::set_fluid(const double *rho0, int64_t stride, double kappa, double gamma, double mu) {
  if (!rho0) throw Error(MFREE_ERR_NULL, "rest density is NULL");
  if (stride < 0) throw Error(MFREE_ERR_ARG, "negative stride");
  check_stride(n_, stride, "rest density");
  if (!(std::isfinite(kappa) && kappa > 0.0) || !(std::isfinite(gamma) && gamma >= 1.0) ||
      !(std::isfinite(mu) && mu >= 0.0))
    throw Error(MFREE_ERR_ARG, "needs kappa > 0, gamma >= 1, mu >= 0");
  HVec<double> r(n_);
  for (int32_t i = 0; i < n_; ++i) {
    r[i] = rho0[i * stride];
    if (!(std::isfinite(r[i]) && r[i] > 0.0))
      throw Error(MFREE_ERR_INPUT, "rest density of particle " + std::to_string(i) + " must be finite and > 0");
  }
  rho0_.swap(r);
  kappa_ = kappa;
  gamma_ = gamma;
  mu_ = mu;
}

void FluidSystem::set_masses(const double *m, int64_t stride) {
  if (!m && n_ > 0) throw Error(MFREE_ERR_NULL, "masses are NULL");
  if (stride < 0) throw Error(MFREE_ERR_ARG, "negative stride");
  check_stride(n_, stride, "mass");
  HVec<double> v(n_);
  for (int32_t i = 0; i < n_; ++i) {
    v[i] = m[i * stride];
    if (!(std::isfinite(v[i]) && v[i] > 0.0))
      throw Error(MFREE_ERR_INPUT, "mass of particle " + std::to_string(i) + " must be finite and > 0");
  }
  mass_.swap(v);
}

void FluidSystem::set_smoothing(double h) {
  if (!(std::isfinite(h) && h > 0.0)) throw Error(MFREE_ERR_ARG, "h must be finite and > 0");
  ps_.set_support(&h, 0, MFREE_COPY);  // (first: the one step that may fail)
  h_ = h;
}

void FluidSystem::set_gravity(const double *g) {
  if (!g) throw Error(MFREE_ERR_NULL, "gravity is NULL");
  for (int c = 0; c < dim_; ++c) {
    if (!std::isfinite(g[c])) throw Error(MFREE_ERR_INPUT, "gravity must be finite");
    g_[c] = g[c];
  }
}

void FluidSystem::set_lumping(int lump) {
  if (lump != MFREE_LUMP_GALERKIN && lump != MFREE_LUMP_PHYSICAL) throw Error(MFREE_ERR_ARG, "unknown lumping");
  lump_ = lump;
}

void FluidSystem::set_walls(int32_t nwall, const double *x, const double *normals, double r0, double strength) {
  if (nwall < 0) throw Error(MFREE_ERR_ARG, "negative wall count");
  if (nwall > 0 && (!x || !normals)) throw Error(MFREE_ERR_NULL, "wall positions or normals are NULL");
  if (!(std::isfinite(r0) && r0 > 0.0) || !(std::isfinite(strength) && strength >= 0.0))
    throw Error(MFREE_ERR_ARG, "needs r0 > 0 and strength >= 0");
  for (int32_t k = 0; k < nwall; ++k) {
    double len = 0.0;
    for (int c = 0; c < dim_; ++c) len += normals[k * dim_ + c] * normals[k * dim_ + c];
    if (!(std::isfinite(len) && std::fabs(len - 1.0) < 1e-6))
      throw Error(MFREE_ERR_INPUT, "wall normal " + std::to_string(k) + " is not a unit vector");
  }
  auto w = std::make_unique<ParticleSet>(dim_, nwall);
  w->set_positions(x, MFREE_LAYOUT_AOS, dim_, MFREE_COPY);  // validates finiteness
  const double hw = 0.5 * r0;                               // gather radius kappa*h = r0
  w->set_support(&hw, 0, MFREE_COPY);
  w->setup();
  HVec<double> n(normals, normals + static_cast<size_t>(nwall) * dim_);
  walls_ = std::move(w);
  wall_n_.swap(n);
  r0_ = r0;
  strength_ = strength;
}

void FluidSystem::set_box(const double *lo, const double *hi) {
  if (!lo || !hi) throw Error(MFREE_ERR_NULL, "box bounds are NULL");
  for (int c = 0; c < dim_; ++c) {
    if (!(std::isfinite(lo[c]) && std::isfinite(hi[c]) && hi[c] > lo[c]))
      throw Error(MFREE_ERR_ARG, "box needs finite lo < hi");
    lo_[c] = lo[c];
    hi_[c] = hi[c];
  }
  box_ = true;
}

void FluidSystem::set_shepard_condition(double max_cond) {
  if (std::isnan(max_cond) || !(max_cond >= 1.0))
    throw Error(MFREE_ERR_ARG, "the Shepard condition threshold must be >= 1 (or +infinity), not " +
                                   std::to_string(max_cond));
  shepard_cond_ = max_cond;
}

void FluidSystem::check_ready() const {
  if (mass_.size() != static_cast<size_t>(n_)) throw Error(MFREE_ERR_STATE, "particle masses are not set");
  if (!(h_ > 0.0)) throw Error(MFREE_ERR_STATE, "the smoothing length is not set");
}

Report FluidSystem::check_state(const double *y, int64_t step) const {
  Report rep;
  const double *x = y, *v = y + static_cast<size_t>(dim_) * n_, *rho = y + 2 * static_cast<size_t>(dim_) * n_;
  // messages are formatted only on failure (this runs twice per step)
  auto fail = [&](mfree_status_t status, int32_t i, const char *what, double value, int c) {
    std::ostringstream s;
    if (step >= 0) s << "step " << step << ": ";
    s << "particle " << i << what;
    if (c >= 0) s << c << " = " << value << ")";
    else if (status == MFREE_FAIL_INVALID_DATA) s << value << " <= 0";
    rep.fail(status, s.str());
    return rep;
  };
  const int dim = dim_;
  auto valid = [&](int64_t i) {
    bool ok = rho[i] > 0.0 && rho[i] <= DBL_MAX;  // false for NaN
    for (int c = 0; c < dim; ++c) {
      const double xc = x[i * dim + c];
      ok = ok && std::isfinite(xc) && std::isfinite(v[i * dim + c]) && (!box_ || (xc >= lo_[c] && xc <= hi_[c]));
    }
    return ok;
  };
  // the first invalid particle: the lowest of the threads' first ones
  int32_t first[64];  // parallel_blocks runs at most 64 threads
  std::fill(first, first + 64, n_);
  parallel_blocks(n_, light_threads(n_), [&](int t, int64_t b, int64_t e) {
    // the common case first: branch-free over flat arrays (vectorisable), then the
    // particle-by-particle search only in a block that holds an invalid particle
    bool bad = false;
#ifdef __SSE2__
    if (dim == 2) {  // two particles (densities) and one particle (x, v) per operation
      const __m128d big = _mm_set1_pd(DBL_MAX), zero = _mm_setzero_pd();
      const __m128d absm = _mm_castsi128_pd(_mm_set1_epi64x(0x7fffffffffffffffLL));
      const __m128d lo = _mm_setr_pd(lo_[0], lo_[1]), hi = _mm_setr_pd(hi_[0], hi_[1]);
      __m128d ok = _mm_castsi128_pd(_mm_set1_epi64x(-1));
      int64_t i = b;
      for (; i + 2 <= e; i += 2) {
        const __m128d r = _mm_loadu_pd(rho + i);
        ok = _mm_and_pd(ok, _mm_and_pd(_mm_cmpgt_pd(r, zero), _mm_cmple_pd(r, big)));
      }
      for (; i < e; ++i) bad |= !(rho[i] > 0.0) | !(rho[i] <= DBL_MAX);
      for (i = b; i < e; ++i) {
        const __m128d xi = _mm_loadu_pd(x + 2 * i), vi = _mm_loadu_pd(v + 2 * i);
        ok = _mm_and_pd(ok, _mm_and_pd(_mm_cmple_pd(_mm_and_pd(xi, absm), big), _mm_cmple_pd(_mm_and_pd(vi, absm), big)));
        if (box_) ok = _mm_and_pd(ok, _mm_and_pd(_mm_cmpge_pd(xi, lo), _mm_cmple_pd(xi, hi)));
      }
      if (bad || _mm_movemask_pd(ok) != 3) {
        for (int64_t k = b; k < e; ++k)
          if (!valid(k)) {
            first[t] = static_cast<int32_t>(k);
            break;
          }
      }
      return;
    }
#endif
    for (int64_t i = b; i < e; ++i) bad |= !(rho[i] > 0.0) | !(rho[i] <= DBL_MAX);
    for (int64_t q = b * dim; q < e * dim; ++q) bad |= !(std::fabs(v[q]) <= DBL_MAX) | !(std::fabs(x[q]) <= DBL_MAX);
    if (box_)
      for (int64_t i = b; i < e; ++i)
        for (int c = 0; c < dim; ++c) bad |= !(x[i * dim + c] >= lo_[c]) | !(x[i * dim + c] <= hi_[c]);
    if (!bad) return;
    for (int64_t i = b; i < e; ++i)
      if (!valid(i)) {
        first[t] = static_cast<int32_t>(i);
        break;
      }
  });
  const int32_t i = *std::min_element(first, first + 64);
  if (i == n_) return rep;
  bool finite = std::isfinite(rho[i]);
  for (int c = 0; c < dim; ++c) finite = finite && std::isfinite(x[i * dim + c]) && std::isfinite(v[i * dim + c]);
  if (!finite) return fail(MFREE_FAIL_NONFINITE, i, " has a non-finite position, velocity or density", 0.0, -1);
  if (!(rho[i] > 0.0)) return fail(MFREE_FAIL_INVALID_DATA, i, " has density ", rho[i], -1);
  for (int c = 0; c < dim && box_; ++c)
    if (x[i * dim + c] < lo_[c] || x[i * dim + c] > hi_[c])
      return fail(MFREE_FAIL_DOMAIN, i, " left the box (coordinate ", x[i * dim + c], c);
  return rep;
}

double FluidSystem::tait(double rho, double rho0) const {
  const double r = rho / rho0;
  if (gamma_ == 7.0) {  // the usual exponent: no pow per particle
    const double r2 = r * r;
    return r2 * r2 * r2 * r;
  }
  return std::pow(r, gamma_);
}

namespace {

// a[m] = sqrt(a[m]), m < n, two at a time where SSE2 is there (compilers vectorise sqrt
// only without errno, which the library does not switch off); correctly rounded either way.
inline void sqrt_n(double *a, int n) {
  int m = 0;
#ifdef __SSE2__
  for (; m + 2 <= n; m += 2) _mm_storeu_pd(a + m, _mm_sqrt_pd(_mm_loadu_pd(a + m)));
#endif
  for (; m < n; ++m) a[m] = std::sqrt(a[m]);
}

#if MFREE_SIMD_X86
// sqrt_n four at a time, for the AVX2 copy of the row kernel (same correctly rounded values)
MFREE_TARGET_AVX2 void sqrt_n_avx2(double *a, int n) {
  int m = 0;
  for (; m + 4 <= n; m += 4) _mm256_storeu_pd(a + m, _mm256_sqrt_pd(_mm256_loadu_pd(a + m)));
  for (; m + 2 <= n; m += 2) _mm_storeu_pd(a + m, _mm_sqrt_pd(_mm_loadu_pd(a + m)));
  for (; m < n; ++m) a[m] = std::sqrt(a[m]);
}
#endif

// The approximants' singularity threshold on 1 / cond (local.cpp, shape_fast.cpp).
constexpr double kMinRcond = 1e-12;

// X = A^-1 for a symmetric positive definite A by A = U^T D U (unit upper U, built
// column by column) and its exact 1-norm condition number ||A||_1 ||X||_1; false when a
// pivot is not positive or the system is singular to kMinRcond.
template <int L>
MFREE_ALWAYS_INLINE bool spd_inverse(const double (&A)[L][L], double (&X)[L][L], double &cond) {
  double U[L][L] = {}, D[L];
  for (int j = 0; j < L; ++j) {
    for (int i = 0; i < j; ++i) {
      double v = A[i][j];
      for (int m = 0; m < i; ++m) v -= U[m][i] * D[m] * U[m][j];
      U[i][j] = v / D[i];
    }
    double dj = A[j][j];
    for (int m = 0; m < j; ++m) dj -= U[m][j] * D[m] * U[m][j];
    if (!(dj > 0.0)) return false;
    D[j] = dj;
  }
  // X = U^-1 D^-1 U^-T with V = U^-1 (unit upper)
  double V[L][L] = {};
  for (int i = L - 1; i >= 0; --i) {
    V[i][i] = 1.0;
    for (int j = i + 1; j < L; ++j) {
      double v = 0.0;
      for (int m = i + 1; m <= j; ++m) v -= U[i][m] * V[m][j];
      V[i][j] = v;
    }
  }
  for (int a = 0; a < L; ++a)
    for (int b = a; b < L; ++b) {
      double v = 0.0;
      for (int m = b; m < L; ++m) v += V[a][m] * V[b][m] / D[m];
      X[a][b] = X[b][a] = v;
    }
  double na = 0.0, nx = 0.0;
  for (int b = 0; b < L; ++b) {
    double sa = 0.0, sx = 0.0;
    for (int a = 0; a < L; ++a) {
      sa += std::fabs(A[a][b]);
      sx += std::fabs(X[a][b]);
    }
    na = std::max(na, sa);
    nx = std::max(nx, sx);
  }
  cond = na * nx;
  return std::isfinite(cond) && cond > 0.0 && 1.0 / cond >= kMinRcond;
}

}  // namespace

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
  const double hs = h_ * (1.0 + 0.5 * skin_);  // gather radius 2 hs = 2h + skin
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

// Shepard functions N_j = o_j / S, S = sum o, of the weights o = w (the approximants'
// fallback where the moment matrix is singular or the row too short), or of o = w V_j
// where it is ill-conditioned, not only singular (003 Sect. 6: a lattice node has a
// condition number of 10-15, a free edge or corner 30-60; a particle left in a thin sheet
// or strand climbs past 1e3 within a few steps, and its gradients then drive the density
// negative in one step (dam break along the wall, T ~ 2.2, at every resolution and CFL
// number tried). Hence the default threshold 100 (mfree_system_set_shepard_condition).
template <int D>
void FluidSystem::shepard_row(int n, const double *w, const double *gf, double *const *s, double ih,
                              bool volumes, const int32_t *js, double *Nk, double *Gk) const {
  double S = 0.0, dS[D] = {};
  for (int m = 0; m < n; ++m) {
    const double V = volumes ? vol_[js[m]] : 1.0;
    Nk[m] = w[m] * V;
    S += Nk[m];
    for (int c = 0; c < D; ++c) {
      Gk[m * D + c] = gf[m] * s[c][m] * ih * V;
      dS[c] += Gk[m * D + c];
    }
  }
  for (int m = 0; m < n; ++m) {
    Nk[m] /= S;
    for (int c = 0; c < D; ++c) Gk[m * D + c] = (Gk[m * D + c] - Nk[m] * dS[c]) / S;
  }
}

#if defined(__GNUC__) || defined(__clang__)
#define FLUID_NOINLINE __attribute__((noinline))
#else
#define FLUID_NOINLINE
#endif

namespace {

// The candidates of row k closer than 2h (r2 < R2, in the search's units: a symmetric
// test, |x_j - x_k| is computed alike from both ends) in structure-of-arrays scratch:
// scaled offsets s = (x_j - x_k) / h and columns js; returns their count. Candidates out
// of range are written and then overwritten (no branch: a quarter of them fall out).
// Not inlined into the AVX2 copy of the row kernel, where FMA contraction of r2 would
// move pairs at exactly 2h in or out of the rows depending on the CPU.
template <int D>
FLUID_NOINLINE int kept_candidates(const double *xn, int64_t k, const int32_t *cc, int64_t nc, double R2, double ih,
                                   double *const *s, int32_t *js) {
  const double *xk = xn + k * D;
  int q = 0;
  for (int64_t e = 0; e < nc; ++e) {
    const int32_t j = cc[e];
    const double *xj = xn + static_cast<size_t>(j) * D;
    double r2 = 0.0;
    for (int c = 0; c < D; ++c) {
      const double d = xj[c] - xk[c];
      r2 += d * d;
      s[c][q] = d * ih;
    }
    js[q] = j;
    q += r2 < R2;
  }
  return q;
}

#if MFREE_SIMD_X86
// kept_candidates four candidates at a time (AVX2 gathers, left-packed stores through a
// permutation table): the same differences, products and sums, so the same rows and
// offsets; the products are kept from FMA contraction by an empty asm.
struct PackTable {
  int32_t d[16][8];  // mask -> 32-bit lane indices moving the kept doubles to the front
  int32_t i[16][8];  // mask -> lane indices moving the kept 32-bit columns to the front
};
constexpr PackTable make_pack_table() {
  PackTable t{};
  for (int m = 0; m < 16; ++m) {
    int q = 0;
    for (int l = 0; l < 4; ++l)
      if (m >> l & 1) {
        t.d[m][2 * q] = 2 * l;
        t.d[m][2 * q + 1] = 2 * l + 1;
        t.i[m][q] = l;
        ++q;
      }
  }
  return t;
}
constexpr PackTable kPack = make_pack_table();

template <int D>
MFREE_TARGET_AVX2 FLUID_NOINLINE int kept_candidates_avx2(const double *xn, int64_t k, const int32_t *cc, int64_t nc,
                                                          double R2, double ih, double *const *s, int32_t *js) {
  const double *xk = xn + k * D;
  __m256d xkv[D];
  for (int c = 0; c < D; ++c) xkv[c] = _mm256_set1_pd(xk[c]);
  const __m256d r2v = _mm256_set1_pd(R2), ihv = _mm256_set1_pd(ih);
  const __m256d all = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
  int q = 0;
  int64_t e = 0;
  for (; e + 4 <= nc; e += 4) {
    const __m128i j4 = _mm_loadu_si128(reinterpret_cast<const __m128i *>(cc + e));
    const __m128i idx = D == 2 ? _mm_slli_epi32(j4, 1) : _mm_add_epi32(_mm_slli_epi32(j4, 1), j4);  // j * D
    __m256d d[D], p[D];
    for (int c = 0; c < D; ++c) {
      // the masked form: the plain one trips GCC 12's -Wmaybe-uninitialized
      const __m256d xj = _mm256_mask_i32gather_pd(_mm256_setzero_pd(), xn + c, idx, all, 8);
      d[c] = _mm256_sub_pd(xj, xkv[c]);
      p[c] = _mm256_mul_pd(d[c], d[c]);
      __asm__("" : "+x"(p[c]));  // r2 = (d0 d0 + d1 d1) + d2 d2, rounded as the scalar loop
    }
    __m256d r2 = p[0];
    for (int c = 1; c < D; ++c) r2 = _mm256_add_pd(r2, p[c]);
    const int mask = _mm256_movemask_pd(_mm256_cmp_pd(r2, r2v, _CMP_LT_OQ));
    const __m256i pd = _mm256_loadu_si256(reinterpret_cast<const __m256i *>(kPack.d[mask]));
    for (int c = 0; c < D; ++c) {
      const __m256d sc = _mm256_mul_pd(d[c], ihv);
      _mm256_storeu_pd(s[c] + q, _mm256_castps_pd(_mm256_permutevar8x32_ps(_mm256_castpd_ps(sc), pd)));
    }
    const __m256i pi = _mm256_loadu_si256(reinterpret_cast<const __m256i *>(kPack.i[mask]));
    const __m256i jp = _mm256_permutevar8x32_epi32(_mm256_zextsi128_si256(j4), pi);
    _mm_storeu_si128(reinterpret_cast<__m128i *>(js + q), _mm256_castsi256_si128(jp));
    q += __builtin_popcount(static_cast<unsigned>(mask));
  }
  for (; e < nc; ++e) {
    const int32_t j = cc[e];
    const double *xj = xn + static_cast<size_t>(j) * D;
    double r2 = 0.0;
    for (int c = 0; c < D; ++c) {
      const double dc = xj[c] - xk[c];
      double pc = dc * dc;
      __asm__("" : "+x"(pc));
      r2 += pc;
      s[c][q] = dc * ih;
    }
    js[q] = j;
    q += r2 < R2;
  }
  _mm256_zeroupper();
  return q;
}
#endif

}  // namespace

template <int D>
MFREE_ALWAYS_INLINE bool FluidSystem::table_rows_body(int32_t k0, int32_t k1, const double *xn, double *scratch,
                                                     int64_t *iscratch, bool transpose, bool wide) {
  (void)wide;
  constexpr int L = D + 1;
  const double ih = 1.0 / h_, tol = shepard_cond_, R2 = 4.0 * h_ * h_;
  const int64_t *crp = cand_.rowptr.data();
  const int32_t *ccols = cand_.cols.data();
  const int32_t *cpos = cpos_.data();
  const int64_t *ctr = transpose ? ctrans_.data() : nullptr;
  int64_t *rbeg = rb_.data(), *rend = re_.data();
  bool one_way = false;
  for (int32_t k = k0; k < k1; ++k) {  // k0 starts a chunk
    const double *xk = xn + static_cast<size_t>(k) * D;
    const int64_t o = transpose ? rbeg[k] : k % kChunk == 0 ? crp[k] : rend[k - 1];
    double *Nk = N_.data() + o, *Gk = G_.data() + o * D;
    // the row's neighbours in structure-of-arrays scratch: scaled offsets s = (x_j - x) / h,
    // weights w = f(|s|) and gf = -f'(|s|) / |s|, so that grad_x w_j = gf s / h; the
    // transposed candidates; the columns go straight to the row's place in cols_ (the
    // candidates out of range land on entries of later rows of the chunk, or unused ones).
    double *s[D], *w = scratch + D * static_cast<size_t>(maxrow_), *gf = w + maxrow_;
    for (int c = 0; c < D; ++c) s[c] = scratch + c * static_cast<size_t>(maxrow_);
    int32_t *js = cols_.data() + o;
    int64_t *ts = iscratch;
    int n = 0;
    if (transpose) {  // the rows' ends and positions come from prepare's filter
      for (int64_t e = crp[k]; e < crp[k + 1]; ++e) {
        const int32_t j = ccols[e];
        js[n] = j;
        ts[n] = ctr[e];
        for (int c = 0; c < D; ++c) s[c][n] = (xn[static_cast<size_t>(j) * D + c] - xk[c]) * ih;
        n += cpos[e] >= 0;
      }
    } else {
#if MFREE_SIMD_X86
      if (wide) n = kept_candidates_avx2<D>(xn, k, ccols + crp[k], crp[k + 1] - crp[k], R2, ih, s, js);
      else n = kept_candidates<D>(xn, k, ccols + crp[k], crp[k + 1] - crp[k], R2, ih, s, js);
#else
      n = kept_candidates<D>(xn, k, ccols + crp[k], crp[k + 1] - crp[k], R2, ih, s, js);
#endif
      rbeg[k] = o;
      rend[k] = o + n;
    }
    const double *s0 = s[0], *s1 = s[1], *s2 = s[D - 1];
    FLUID_SIMD()
    for (int m = 0; m < n; ++m) w[m] = s0[m] * s0[m] + s1[m] * s1[m] + (D == 3 ? s2[m] * s2[m] : 0.0);
#if MFREE_SIMD_X86
    if (wide) sqrt_n_avx2(w, n);  // |x_j - x| / h < 2
    else sqrt_n(w, n);
#else
    sqrt_n(w, n);
#endif
    FLUID_SIMD()
    for (int m = 0; m < n; ++m) {
      // the cubic spline as B-spline pieces, f = (2 - r)_+^3 / 4 - (1 - r)_+^3, with
      // (x)_+ = (x + |x|) / 2 (exact): no comparison, which the vectoriser would not
      // if-convert under trapping math
      const double r = w[m], a0 = 1.0 - r, b0 = 2.0 - r;
      const double a = 0.5 * (a0 + std::fabs(a0)), b = 0.5 * (b0 + std::fabs(b0));
      w[m] = 0.25 * b * b * b - a * a * a;
      const double df = 3.0 * a * a - 0.75 * b * b;  // exactly 0 at r = 0
      gf[m] = -df / (r + 1e-300);                    // r + 1e-300 = r unless r < 1e-284
    }
    // moments: M = sum w p p^T and M_,c = sum w_,c p p^T, p = (1, s), w_,c = gf s_c / h
    // (the 1/h is applied after the sums)
    double m0[L][L], mc[D][L][L];  // every entry is set below
    if (D == 2) {
      double a0 = 0, a1 = 0, a2 = 0, a11 = 0, a12 = 0, a22 = 0;
      double b1 = 0, b2 = 0, b11 = 0, b12 = 0, b22 = 0, b111 = 0, b112 = 0, b122 = 0, b222 = 0;
      FLUID_SIMD(reduction(+ : a0, a1, a2, a11, a12, a22, b1, b2, b11, b12, b22, b111, b112, b122, b222))
      for (int m = 0; m < n; ++m) {
        const double x1 = s0[m], x2 = s1[m], wm = w[m], gm = gf[m];
        a0 += wm;
        a1 += wm * x1;
        a2 += wm * x2;
        a11 += wm * x1 * x1;
        a12 += wm * x1 * x2;
        a22 += wm * x2 * x2;
        const double g1 = gm * x1, g2 = gm * x2;
        b1 += g1;
        b2 += g2;
        b11 += g1 * x1;
        b12 += g1 * x2;
        b22 += g2 * x2;
        b111 += g1 * x1 * x1;
        b112 += g1 * x1 * x2;
        b122 += g1 * x2 * x2;
        b222 += g2 * x2 * x2;
      }
      const double M[3][3] = {{a0, a1, a2}, {a1, a11, a12}, {a2, a12, a22}};
      // w_,1 p p^T: gf s1 (1, s1, s2)(1, s1, s2)^T, likewise for s2
      const double M1[3][3] = {{b1, b11, b12}, {b11, b111, b112}, {b12, b112, b122}};
      const double M2[3][3] = {{b2, b12, b22}, {b12, b112, b122}, {b22, b122, b222}};
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) {
          m0[a][b] = M[a][b];
          mc[0][a][b] = M1[a][b] * ih;
          mc[D - 1][a][b] = M2[a][b] * ih;
        }
    } else {
      double acc[L][L] = {}, accc[D][L][L] = {};
      for (int m = 0; m < n; ++m) {
        double p[L];
        p[0] = 1.0;
        for (int c = 0; c < D; ++c) p[1 + c] = s[c][m];
        for (int a = 0; a < L; ++a)
          for (int b = 0; b <= a; ++b) {
            const double pp = p[a] * p[b];
            acc[a][b] += w[m] * pp;
            for (int c = 0; c < D; ++c) accc[c][a][b] += gf[m] * s[c][m] * pp;
          }
      }
      for (int a = 0; a < L; ++a)
        for (int b = 0; b <= a; ++b) {
          m0[a][b] = m0[b][a] = acc[a][b];
          for (int c = 0; c < D; ++c) mc[c][a][b] = mc[c][b][a] = accc[c][a][b] * ih;
        }
    }
    double X[L][L], cond = 1.0;
    // too few neighbours or a singular moment matrix: Shepard functions of the weights
    // (the approximants' lower-order fallback, whose condition number is 1)
    const bool mls = n >= L && spd_inverse<L>(m0, X, cond);
    if (!mls) cond = 1.0;
    cond_[k] = cond;
    if (mls && !(cond > tol)) {
      // 003 eqs 27-31 (MLS, basis shifted to the node and scaled by h): M g = p(0),
      // M g_,c = e_c / h - M_,c g; N_j = w_j g.p_j, N_j,c = w_j g_,c.p_j + w_j,c g.p_j
      double g[L], gc[D][L];
      for (int a = 0; a < L; ++a) g[a] = X[a][0];
      for (int c = 0; c < D; ++c) {
        double rhs[L];
        for (int a = 0; a < L; ++a) {
          double t = 0.0;
          for (int b = 0; b < L; ++b) t += mc[c][a][b] * g[b];
          rhs[a] = -t;
        }
        rhs[1 + c] += ih;
        for (int a = 0; a < L; ++a) {
          double t = 0.0;
          for (int b = 0; b < L; ++b) t += X[a][b] * rhs[b];
          gc[c][a] = t;
        }
      }
      // g.p_j and g_,c.p_j with the coefficients in scalars, for the vectoriser
      const double g0 = g[0], g1 = g[1], g2 = g[2], g3 = g[L - 1];
      const double c00 = gc[0][0], c01 = gc[0][1], c02 = gc[0][2], c03 = gc[0][L - 1];
      const double c10 = gc[1][0], c11 = gc[1][1], c12 = gc[1][2], c13 = gc[1][L - 1];
      const double c20 = gc[D - 1][0], c21 = gc[D - 1][1], c22 = gc[D - 1][2], c23 = gc[D - 1][L - 1];
      FLUID_SIMD()
      for (int m = 0; m < n; ++m) {
        const double x1 = s0[m], x2 = s1[m], x3 = D == 3 ? s2[m] : 0.0;
        const double gp = g0 + g1 * x1 + g2 * x2 + (D == 3 ? g3 * x3 : 0.0);
        const double wm = w[m], gq = gf[m] * ih * gp;
        Nk[m] = wm * gp;
        Gk[m * D] = wm * (c00 + c01 * x1 + c02 * x2 + (D == 3 ? c03 * x3 : 0.0)) + gq * x1;
        Gk[m * D + 1] = wm * (c10 + c11 * x1 + c12 * x2 + (D == 3 ? c13 * x3 : 0.0)) + gq * x2;
        if (D == 3) Gk[m * D + D - 1] = wm * (c20 + c21 * x1 + c22 * x2 + c23 * x3) + gq * x3;
      }
    } else {
      shepard_row<D>(n, w, gf, s, ih, mls, js, Nk, Gk);
    }
    // the transposed copy: N_k(x_j) is entry (j, k) of the transpose
    if (!transpose) continue;
    for (int m = 0; m < n; ++m) {
      const int32_t j = js[m];
      const int64_t t = ts[m];
      if (t < 0 || cpos[t] < 0) {
        one_way = true;
        continue;
      }
      double *nt = NT_.data() + (rbeg[j] + cpos[t]) * (D + 1);  // one cache line per entry
      nt[0] = Nk[m];
      for (int c = 0; c < D; ++c) nt[1 + c] = Gk[m * D + c];
    }
  }
  return one_way;
}

template <int D>
bool FluidSystem::table_rows(int32_t k0, int32_t k1, const double *xn, double *scratch, int64_t *iscratch,
                             bool transpose) {
  return table_rows_body<D>(k0, k1, xn, scratch, iscratch, transpose, false);
}

#if MFREE_SIMD_X86
template <int D>
MFREE_TARGET_AVX2 bool FluidSystem::table_rows_avx2(int32_t k0, int32_t k1, const double *xn, double *scratch,
                                                    int64_t *iscratch, bool transpose) {
  return table_rows_body<D>(k0, k1, xn, scratch, iscratch, transpose, true);
}
#endif

#if MFREE_SIMD_X86
// The columns of kept_candidates<2> alone, four candidates at a time with two 128-bit loads
// per pair of lanes (cheaper than gathers here), the test r2 < R2 rounded as there (no
// FMA), the kept columns left-packed into js; returns their count.
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
    __asm__("" : "+x"(px), "+x"(py));  // r2 = d0 d0 + d1 d1, rounded as kept_candidates
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

// Rows [k0, k1) in chunks: the candidates closer than 2h filtered into the chunk's rows
// (kept_candidates_avx2), then the approximants' fused linear-MLS rows on them
// (shape_fast_mls1.hpp); the rows they leave (a moment matrix not positive definite or
// singular) and those worse conditioned than shepard_cond_ are computed again by
// table_rows_avx2, which writes their Shepard functions.
void FluidSystem::table_rows2_avx2(int32_t k0, int32_t k1, const double *xn, double *scratch, int64_t *iscratch,
                                   FastScratch &fast, int64_t *rp) {
  const double R2 = 4.0 * h_ * h_;
  const int64_t *crp = cand_.rowptr.data();
  const int32_t *ccols = cand_.cols.data();
  int64_t *rbeg = rb_.data(), *rend = re_.data();
  FastTables ft;
  ft.rowptr = rp;
  ft.cols = cols_.data();
  ft.x[0] = ft.sx[0] = xn;
  ft.x[1] = ft.sx[1] = xn + 1;
  ft.stride = ft.sstride = 2;
  ft.h = ft.sh = &h_;
  ft.hstride = ft.shstride = 0;
  ft.val = N_.data();
  ft.grad = G_.data();
  FastSites fs;
  fs.status = site_status_.data();
  fs.support = site_support_.data();
  fs.order = site_order_.data();
  fs.cond = cond_.data();
  fs.order_used = 1;
  for (int32_t c0 = k0; c0 < k1; c0 += kChunk) {
    const int32_t c1 = std::min(k1, c0 + kChunk);
    for (int32_t k = c0; k < c1; ++k) {
      const int64_t o = k == c0 ? crp[k] : rend[k - 1];
      const int n = kept_columns2_avx2(xn, k, ccols + crp[k], crp[k + 1] - crp[k], R2, cols_.data() + o);
      rbeg[k] = o;
      rend[k] = o + n;
      rp[k] = o;  // the chunk's rows lie one after another
    }
    rp[c1] = rend[c1 - 1];
    mls1_rows2_avx2(ft, c0, c1, kMinRcond, fast, fs);
    for (int32_t k = c0; k < c1; ++k)
      if (site_status_[k] != 0 || cond_[k] > shepard_cond_) table_rows_avx2<2>(k, k + 1, xn, scratch, iscratch, false);
  }
}
#endif

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
    // row kernel filters on the fly otherwise), the same symmetric test as kept_candidates
    if (!ctrans_valid_) transposed_candidates();
    const double R2 = 4.0 * h_ * h_;
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
  const size_t per_thread = static_cast<size_t>(dim + 2) * (maxrow_ + 8), iper_thread = static_cast<size_t>(maxrow_);
  if (rows_scratch_.size() < per_thread * nt) rows_scratch_.resize(per_thread * nt);
  if (rows_iscratch_.size() < iper_thread * nt) rows_iscratch_.resize(iper_thread * nt);
#if MFREE_SIMD_X86
  if (dim == 2 && !transpose && simd::use_avx2()) {  // table_rows2_avx2's per-thread scratch
    if (fast_scratch_.size() < static_cast<size_t>(nt)) fast_scratch_.resize(nt);
    for (int t = 0; t < nt; ++t) fast_scratch_[t].reserve(static_cast<int>(maxrow_));
    rows_ptr_.resize(static_cast<size_t>(nt) * (nall + 1));
    site_status_.resize(nall);
    site_support_.resize(nall);
    site_order_.resize(nall);
  }
#endif
  bool one_way[64] = {};  // parallel_blocks runs at most 64 threads
  const bool avx2 = simd::use_avx2();  // once per step: every thread runs the same copy
  (void)avx2;
  auto rows = [&](int t, int32_t k0, int32_t k1) {
    double *scratch = rows_scratch_.data() + per_thread * t;
    int64_t *iscratch = rows_iscratch_.data() + iper_thread * t;
#if MFREE_SIMD_X86
    if (avx2 && dim == 2 && !transpose) {
      table_rows2_avx2(k0, k1, xn, scratch, iscratch, fast_scratch_[t], rows_ptr_.data() + static_cast<size_t>(t) * (nall + 1));
      return false;
    }
    if (avx2)
      return dim == 2 ? table_rows_avx2<2>(k0, k1, xn, scratch, iscratch, transpose)
                      : table_rows_avx2<3>(k0, k1, xn, scratch, iscratch, transpose);
#endif
    return dim == 2 ? table_rows<2>(k0, k1, xn, scratch, iscratch, transpose)
                    : table_rows<3>(k0, k1, xn, scratch, iscratch, transpose);
  };
  parallel_blocks(nchunk, nt, [&](int t, int64_t b, int64_t e) {
    one_way[t] = rows(t, static_cast<int32_t>(b * kChunk), static_cast<int32_t>(std::min<int64_t>(nall, e * kChunk)));
  });
  if (std::any_of(one_way, one_way + 64, [](bool f) { return f; })) {
    // cannot happen with lists from one search radius; a failure rather than a wrong sum
    rep.fail(MFREE_FAIL_NEIGHBORS, "the neighbour lists of the fluid are not symmetric");
    lists_valid_ = false;
    return rep;
  }
  fluid_share();
  vci_setup();  // optional, fluid_wall.cpp
  return rep;
}

void FluidSystem::kinematics(const double *v, const double *rho, double *vhat, double *drho) const {
  v = node_velocities(v);
  const int dim = dim_;
  const int64_t *rb = rb_.data(), *re = re_.data();
  const int32_t *cols = cols_.data();
  const double *N = N_.data(), *G = G_.data();
  const bool avx2 = dim == 2 && simd::use_avx2();  // once per call: every thread runs the same copy
  parallel_blocks(n_, num_threads(n_), [&](int, int64_t b, int64_t e) {
#if MFREE_SIMD_X86
    if (avx2) {
      kinematics2_avx2(b, e, v, rho, vhat, drho);
      return;
    }
#endif
    for (int64_t k = b; k < e; ++k) {
      double vh[3] = {0, 0, 0}, div = 0.0;
      if (dim == 2) {
        // independent sums (one chain through div was the bottleneck): v0 += N a0,
        // v1 += N a1, d0 += a0 G0, d1 += a1 G1, in SSE2 pairs where there (same operations)
        double v0 = 0, v1 = 0, d0 = 0, d1 = 0;
#ifdef __SSE2__
        __m128d vv = _mm_setzero_pd(), dd = _mm_setzero_pd();
        for (int64_t q = rb[k]; q < re[k]; ++q) {
          const __m128d a = _mm_loadu_pd(v + static_cast<size_t>(cols[q]) * 2);
          vv = _mm_add_pd(vv, _mm_mul_pd(_mm_set1_pd(N[q]), a));
          dd = _mm_add_pd(dd, _mm_mul_pd(a, _mm_loadu_pd(G + 2 * q)));
        }
        double t[4];
        _mm_storeu_pd(t, vv);
        _mm_storeu_pd(t + 2, dd);
        v0 = t[0];
        v1 = t[1];
        d0 = t[2];
        d1 = t[3];
#else
        for (int64_t q = rb[k]; q < re[k]; ++q) {
          const double *vj = v + static_cast<size_t>(cols[q]) * 2;
          const double a0 = vj[0], a1 = vj[1], nq = N[q];
          v0 += nq * a0;
          v1 += nq * a1;
          d0 += a0 * G[2 * q];
          d1 += a1 * G[2 * q + 1];
        }
#endif
        vh[0] = v0;
        vh[1] = v1;
        div = d0 + d1;
      } else {
        double d[3] = {0, 0, 0};
        for (int64_t q = rb[k]; q < re[k]; ++q) {
          const double *vj = v + static_cast<size_t>(cols[q]) * dim;
          for (int c = 0; c < dim; ++c) {
            vh[c] += N[q] * vj[c];
            d[c] += vj[c] * G[q * dim + c];
          }
        }
        div = d[0] + d[1] + d[2];
      }
      if (vhat)
        for (int c = 0; c < dim; ++c) vhat[k * dim + c] = vh[c];
      if (drho) drho[k] = -rho[k] * div;  // 003 eq 70, nodal parameters v_j
    }
  });
  if (drho) density_diffusion(rho, drho);  // optional, fluid_wall.cpp
}

FluidSystem::AccelArgs FluidSystem::accel_args(const double *v, const double *rho) {
  const int dim = dim_;
  const int32_t nall = nq();
  AccelArgs aa;
  aa.v = node_velocities(v);
  aa.rho = node_densities(rho);
  aa.rho0 = dummy_.n ? dummy_.rho0.data() : rho0_.data();
  aa.mass = dummy_.n ? dummy_.mass.data() : mass_.data();
  aa.keep_pack = vci_;  // vci_correct reads the points' stresses
  if (aa.keep_pack) pack_.resize(static_cast<size_t>(nall) * (dim * dim + 2 + dim));
  const int64_t na = static_cast<int64_t>(nall) * (2 * dim + 2);
  acc_.resize(na);
  double *acc = acc_.data();
  parallel_blocks(na, light_threads(nall), [&](int, int64_t b, int64_t e) { std::fill(acc + b, acc + e, 0.0); });
  return aa;
}

template <int D>
MFREE_ALWAYS_INLINE void FluidSystem::point_terms(int64_t k, const AccelArgs &arg, const double (&vh)[D],
                                                  const double (&L)[D][D], PointTerms<D> &pt) {
  constexpr int P = D * D + 2 + D;  // pack_ per point: sigma V (D x D), M, lumping mass, wall force
  const double *rho = arg.rho, *rho0 = arg.rho0, *mass = arg.mass;
  double tr3 = 0.0;
  for (int c = 0; c < D; ++c) tr3 += L[c][c];
  tr3 /= 3.0;
  const double p = kappa_ * (tait(rho[k], rho0[k]) - 1.0), Vk = vol_[k];
  double(&S)[D][D] = pt.S;
  for (int aa = 0; aa < D; ++aa)
    for (int bb = 0; bb < D; ++bb) {
      const double d = 0.5 * (L[aa][bb] + L[bb][aa]) - (aa == bb ? tr3 : 0.0);  // d' (003 eq 61)
      S[aa][bb] = ((aa == bb ? -p : 0.0) + 2.0 * mu_ * d) * Vk;
    }
  const double Mk = mass[k];
  // dummies carry no fluid mass; without dummies share() is 1 (no division on the row's path)
  const double Lk = k < n_ ? (dummy_.n ? mass[k] / dummy_.share[k] : mass[k]) : 0.0;
  pt.Mk = Mk;
  pt.Lk = Lk;
  double(&F)[D] = pt.F;
  for (int c = 0; c < D; ++c) F[c] = 0.0;
  bool wall = false;
  if (walls_ && k < n_) {
    // wall force (003 eqs 122-124) on approaching particles, spread through N_i(x_k)
    for (int64_t q = wall_nbr_.rowptr[k]; q < wall_nbr_.rowptr[k + 1]; ++q) {
      const int32_t w = wall_nbr_.cols[q];
      const double *nw = &wall_n_[static_cast<size_t>(w) * D];
      double r2 = 0.0, approach = 0.0;
      for (int c = 0; c < D; ++c) {
        const double d = xbound_[k * D + c] - walls_->x(w, c);
        r2 += d * d;
        approach += vh[c] * nw[c];
      }
      const double r = std::sqrt(r2);
      if (approach >= 0.0 || !(r > 0.0) || r >= r0_) continue;  // f1 = 0: moving away
      const double qq = r0_ / r, f2 = strength_ / r * (qq * qq * qq * qq - qq * qq);
      for (int c = 0; c < D; ++c) F[c] += f2 * nw[c];
      wall = true;
    }
  }
  if (arg.keep_pack) {
    double *pk = &pack_[static_cast<size_t>(k) * P];
    for (int aa = 0; aa < D; ++aa)
      for (int bb = 0; bb < D; ++bb) pk[aa * D + bb] = S[aa][bb];
    pk[D * D] = Mk;
    pk[D * D + 1] = Lk;
    for (int c = 0; c < D; ++c) pk[D * D + 2 + c] = F[c];
  }
  pt.wall = wall;
}

// Point k of accel: the stress (times V_k), interpolated velocity and wall force at x_k,
// and the row's terms scattered to its nodes.
template <int D>
void FluidSystem::accel_point(int64_t k, const AccelArgs &arg) {
  constexpr int A = 2 * D + 2;  // acc_ per node: force, mass sum_k N M, lumped mass, wall force
  const double *v = arg.v;
  const int64_t q0 = rb_[k], q1 = re_[k];
  const int32_t *cols = cols_.data();
  const double *N = N_.data(), *G = G_.data();
  double *acc = acc_.data();
  // interpolated velocity and velocity gradient L_ab = sum_j v_j,a dN_j/dx_b at x_k
  double vh[D] = {}, L[D][D] = {};
  if constexpr (D == 2) {
    // six independent sums (the vectoriser's pairing made one dependent chain), in SSE2
    // pairs where there: (v0, v1) += N a, (l00, l10) += a g0, (l01, l11) += a g1
    double v0 = 0, v1 = 0, l00 = 0, l01 = 0, l10 = 0, l11 = 0;
#ifdef __SSE2__
    __m128d vv = _mm_setzero_pd(), c0 = _mm_setzero_pd(), c1 = _mm_setzero_pd();
    for (int64_t q = q0; q < q1; ++q) {
      const __m128d a = _mm_loadu_pd(v + static_cast<size_t>(cols[q]) * 2);
      vv = _mm_add_pd(vv, _mm_mul_pd(_mm_set1_pd(N[q]), a));
      c0 = _mm_add_pd(c0, _mm_mul_pd(a, _mm_set1_pd(G[2 * q])));
      c1 = _mm_add_pd(c1, _mm_mul_pd(a, _mm_set1_pd(G[2 * q + 1])));
    }
    double t[6];
    _mm_storeu_pd(t, vv);
    _mm_storeu_pd(t + 2, c0);
    _mm_storeu_pd(t + 4, c1);
    v0 = t[0];
    v1 = t[1];
    l00 = t[2];
    l10 = t[3];
    l01 = t[4];
    l11 = t[5];
#else
    for (int64_t q = q0; q < q1; ++q) {
      const double *vj = v + static_cast<size_t>(cols[q]) * 2;
      const double a0 = vj[0], a1 = vj[1], nq = N[q], g0 = G[2 * q], g1 = G[2 * q + 1];
      v0 += nq * a0;
      v1 += nq * a1;
      l00 += a0 * g0;
      l01 += a0 * g1;
      l10 += a1 * g0;
      l11 += a1 * g1;
    }
#endif
    vh[0] = v0;
    vh[1] = v1;
    L[0][0] = l00;
    L[0][1] = l01;
    L[1][0] = l10;
    L[1][1] = l11;
  } else {
    for (int64_t q = q0; q < q1; ++q) {
      const double *vj = v + static_cast<size_t>(cols[q]) * D;
      const double *gq = G + q * D;
      for (int c = 0; c < D; ++c) {
        vh[c] += N[q] * vj[c];
        for (int bb = 0; bb < D; ++bb) L[c][bb] += vj[c] * gq[bb];
      }
    }
  }
  PointTerms<D> pt;
  point_terms<D>(k, arg, vh, L, pt);
  const double(&S)[D][D] = pt.S;
  const double Mk = pt.Mk, Lk = pt.Lk, *F = pt.F;
  // the row's terms to its nodes i: -sigma_k V_k grad N_i(x_k), N_i(x_k) M_k (003 eq 56)
#ifdef __SSE2__
  if constexpr (D == 2) {  // the same operations in the same order, two lanes at a time
    const __m128d s0 = _mm_setr_pd(S[0][0], S[1][0]), s1 = _mm_setr_pd(S[0][1], S[1][1]);
    const __m128d ml = _mm_setr_pd(Mk, Lk);
    for (int64_t q = q0; q < q1; ++q) {
      double *ai = acc + static_cast<size_t>(cols[q]) * A;
      const __m128d sg = _mm_add_pd(_mm_mul_pd(s0, _mm_set1_pd(G[2 * q])), _mm_mul_pd(s1, _mm_set1_pd(G[2 * q + 1])));
      _mm_storeu_pd(ai, _mm_sub_pd(_mm_loadu_pd(ai), sg));
      _mm_storeu_pd(ai + 2, _mm_add_pd(_mm_loadu_pd(ai + 2), _mm_mul_pd(_mm_set1_pd(N[q]), ml)));
    }
  } else
#endif
  for (int64_t q = q0; q < q1; ++q) {
    double *ai = acc + static_cast<size_t>(cols[q]) * A;
    const double *gi = G + q * D, Ni = N[q];
    for (int aa = 0; aa < D; ++aa) {
      double sg = 0.0;
      for (int bb = 0; bb < D; ++bb) sg += S[aa][bb] * gi[bb];
      ai[aa] -= sg;
    }
    ai[D] += Ni * Mk;
    ai[D + 1] += Ni * Lk;
  }
  if (pt.wall)
    for (int64_t q = q0; q < q1; ++q) {
      double *ai = acc + static_cast<size_t>(cols[q]) * A;
      for (int c = 0; c < D; ++c) ai[D + 2 + c] += N[q] * F[c];
    }
}

template <int D>
Report FluidSystem::accel_end(const AccelArgs &aa, double *a) {
  Report rep;
  constexpr int P = D * D + 2 + D;
  constexpr int A = 2 * D + 2;
  const double *acc = acc_.data();
  const bool galerkin = lump_ == MFREE_LUMP_GALERKIN;
  int32_t bad = n_;  // the first node without a positive mass
  int32_t first_bad[64];  // parallel_blocks runs at most 64 threads
  std::fill(first_bad, first_bad + 64, n_);
  parallel_blocks(n_, num_threads(n_), [&](int t, int64_t b, int64_t e) {
    for (int64_t i = b; i < e; ++i) {
      const double *ai = acc + static_cast<size_t>(i) * A;
      const double m = galerkin ? ai[D + 1] : mass_[i];
      if (!(m > 0.0)) {
        if (first_bad[t] == n_) first_bad[t] = static_cast<int32_t>(i);
        for (int c = 0; c < D; ++c) a[i * D + c] = 0.0;
        continue;
      }
      // the boundary force acts as an acceleration (003 Sect. 6.1 step 7)
#ifdef __SSE2__
      if constexpr (D == 2) {  // both components in one division (the same operations)
        const __m128d f = _mm_add_pd(_mm_loadu_pd(ai), _mm_mul_pd(_mm_set1_pd(ai[D]), _mm_loadu_pd(g_)));
        _mm_storeu_pd(a + i * D, _mm_add_pd(_mm_div_pd(f, _mm_set1_pd(m)), _mm_loadu_pd(ai + D + 2)));
        continue;
      }
#endif
      for (int c = 0; c < D; ++c) a[i * D + c] = (ai[c] + ai[D] * g_[c]) / m + ai[D + 2 + c];
    }
  });
  vci_correct(pack_.data(), P, a);  // optional, fluid_wall.cpp
  velocity_smoothing(aa.v, galerkin ? acc + D + 1 : mass_.data(), galerkin ? A : 1, a);  // optional, fluid_wall.cpp
  for (int32_t fbad : first_bad) bad = std::min(bad, fbad);
  if (bad < n_) {
    const double m = galerkin ? acc[static_cast<size_t>(bad) * A + D + 1] : mass_[bad];
    rep.fail(MFREE_FAIL_SINGULAR, "particle " + std::to_string(bad) + " has a non-positive lumped mass " +
                                      std::to_string(m));
  }
  return rep;
}

#if MFREE_SIMD_X86
MFREE_AVX2_BEGIN
namespace {

// sum of the four lanes of each of a, b, c, d: (sum a, sum b, sum c, sum d)
MFREE_TARGET_AVX2 MFREE_ALWAYS_INLINE __m256d hsum4(__m256d a, __m256d b, __m256d c, __m256d d) {
  const __m256d ab = _mm256_hadd_pd(a, b), cd = _mm256_hadd_pd(c, d);  // (a01, b01, a23, b23), ...
  return _mm256_add_pd(_mm256_permute2f128_pd(ab, cd, 0x20), _mm256_permute2f128_pd(ab, cd, 0x31));
}

// Table entries q .. q + 3 of a 2D row in registers, lanes in the order (q, q + 2, q + 1,
// q + 3) that the in-lane unpacks of interleaved pairs give: velocities (vx, vy) of the
// columns, values N and gradients (gx, gy).
struct Entries4 {
  __m256d vx, vy, n, gx, gy;
};
MFREE_ALWAYS_INLINE Entries4 entries4(const double *v, const int32_t *cols, const double *N, const double *G, int64_t q) {
  Entries4 e;
  const int32_t *c = cols + q;
  const __m256d lo = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(v + 2 * static_cast<size_t>(c[0]))),
                                          _mm_loadu_pd(v + 2 * static_cast<size_t>(c[1])), 1);  // v0 | v1
  const __m256d hi = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(v + 2 * static_cast<size_t>(c[2]))),
                                          _mm_loadu_pd(v + 2 * static_cast<size_t>(c[3])), 1);  // v2 | v3
  e.vx = _mm256_unpacklo_pd(lo, hi);  // (v0x, v2x, v1x, v3x)
  e.vy = _mm256_unpackhi_pd(lo, hi);
  e.n = _mm256_permute4x64_pd(_mm256_loadu_pd(N + q), 0xD8);  // (N0, N2, N1, N3)
  const __m256d g01 = _mm256_loadu_pd(G + 2 * q), g23 = _mm256_loadu_pd(G + 2 * q + 4);
  e.gx = _mm256_unpacklo_pd(g01, g23);  // (g0x, g2x, g1x, g3x)
  e.gy = _mm256_unpackhi_pd(g01, g23);
  return e;
}

}  // namespace

// accel_point<2> for rows [k0, k1): the gather of v_j and grad N_j four entries at a time
// (six sums in registers), the point's terms, and the scatter of four entries at a time:
// (fx, fy, N M_k, N L_k) in structure-of-arrays form, transposed by unpacks and lane
// permutes into one 4-double update per node (acc_ holds them contiguously).
void FluidSystem::accel_rows2_avx2(int64_t k0, int64_t k1, const AccelArgs &arg) {
  constexpr int A = 6;
  const double *v = arg.v;
  const int32_t *cols = cols_.data();
  const double *N = N_.data(), *G = G_.data();
  double *acc = acc_.data();
  const __m256d zero = _mm256_setzero_pd();
  for (int64_t k = k0; k < k1; ++k) {
    const int64_t q0 = rb_[k], q1 = re_[k];
    __m256d sv0 = zero, sv1 = zero, s00 = zero, s01 = zero, s10 = zero, s11 = zero;
    int64_t q = q0;
    for (; q + 4 <= q1; q += 4) {
      const Entries4 e = entries4(v, cols, N, G, q);
      sv0 = _mm256_fmadd_pd(e.n, e.vx, sv0);
      sv1 = _mm256_fmadd_pd(e.n, e.vy, sv1);
      s00 = _mm256_fmadd_pd(e.vx, e.gx, s00);
      s01 = _mm256_fmadd_pd(e.vx, e.gy, s01);
      s10 = _mm256_fmadd_pd(e.vy, e.gx, s10);
      s11 = _mm256_fmadd_pd(e.vy, e.gy, s11);
    }
    double t[8];
    _mm256_storeu_pd(t, hsum4(sv0, sv1, s00, s01));
    _mm256_storeu_pd(t + 4, hsum4(s10, s11, zero, zero));
    double vh[2] = {t[0], t[1]}, L[2][2] = {{t[2], t[3]}, {t[4], t[5]}};
    for (; q < q1; ++q) {
      const double *vj = v + static_cast<size_t>(cols[q]) * 2;
      const double a0 = vj[0], a1 = vj[1], nq = N[q], g0 = G[2 * q], g1 = G[2 * q + 1];
      vh[0] += nq * a0;
      vh[1] += nq * a1;
      L[0][0] += a0 * g0;
      L[0][1] += a0 * g1;
      L[1][0] += a1 * g0;
      L[1][1] += a1 * g1;
    }
    PointTerms<2> pt;
    point_terms<2>(k, arg, vh, L, pt);
    // the row's terms to its nodes i: -sigma_k V_k grad N_i(x_k), N_i(x_k) M_k (003 eq 56)
    const __m256d n00 = _mm256_set1_pd(-pt.S[0][0]), n01 = _mm256_set1_pd(-pt.S[0][1]);
    const __m256d n10 = _mm256_set1_pd(-pt.S[1][0]), n11 = _mm256_set1_pd(-pt.S[1][1]);
    const __m256d mk = _mm256_set1_pd(pt.Mk), lk = _mm256_set1_pd(pt.Lk);
    q = q0;
    for (; q + 4 <= q1; q += 4) {
      const int32_t *c = cols + q;
      const __m256d nq = _mm256_permute4x64_pd(_mm256_loadu_pd(N + q), 0xD8);
      const __m256d g01 = _mm256_loadu_pd(G + 2 * q), g23 = _mm256_loadu_pd(G + 2 * q + 4);
      const __m256d gx = _mm256_unpacklo_pd(g01, g23), gy = _mm256_unpackhi_pd(g01, g23);
      const __m256d fx = _mm256_fmadd_pd(n00, gx, _mm256_mul_pd(n01, gy));
      const __m256d fy = _mm256_fmadd_pd(n10, gx, _mm256_mul_pd(n11, gy));
      const __m256d cm = _mm256_mul_pd(nq, mk), cl = _mm256_mul_pd(nq, lk);
      const __m256d t0 = _mm256_unpacklo_pd(fx, fy), t1 = _mm256_unpackhi_pd(fx, fy);  // entries 0 | 1, 2 | 3
      const __m256d t2 = _mm256_unpacklo_pd(cm, cl), t3 = _mm256_unpackhi_pd(cm, cl);
      double *a0 = acc + static_cast<size_t>(c[0]) * A, *a1 = acc + static_cast<size_t>(c[1]) * A;
      double *a2 = acc + static_cast<size_t>(c[2]) * A, *a3 = acc + static_cast<size_t>(c[3]) * A;
      _mm256_storeu_pd(a0, _mm256_add_pd(_mm256_loadu_pd(a0), _mm256_permute2f128_pd(t0, t2, 0x20)));
      _mm256_storeu_pd(a1, _mm256_add_pd(_mm256_loadu_pd(a1), _mm256_permute2f128_pd(t0, t2, 0x31)));
      _mm256_storeu_pd(a2, _mm256_add_pd(_mm256_loadu_pd(a2), _mm256_permute2f128_pd(t1, t3, 0x20)));
      _mm256_storeu_pd(a3, _mm256_add_pd(_mm256_loadu_pd(a3), _mm256_permute2f128_pd(t1, t3, 0x31)));
    }
    for (; q < q1; ++q) {
      double *ai = acc + static_cast<size_t>(cols[q]) * A;
      const double gx = G[2 * q], gy = G[2 * q + 1];
      ai[0] += -pt.S[0][0] * gx + -pt.S[0][1] * gy;
      ai[1] += -pt.S[1][0] * gx + -pt.S[1][1] * gy;
      ai[2] += N[q] * pt.Mk;
      ai[3] += N[q] * pt.Lk;
    }
    if (pt.wall)
      for (q = q0; q < q1; ++q) {
        double *ai = acc + static_cast<size_t>(cols[q]) * A;
        for (int c = 0; c < 2; ++c) ai[4 + c] += N[q] * pt.F[c];
      }
  }
}

// The 2D kinematics of nodes [k0, k1) four entries at a time: vhat_k = sum N_j v_j and
// div_k = sum v_j . grad N_j in four sums of registers.
void FluidSystem::kinematics2_avx2(int64_t k0, int64_t k1, const double *v, const double *rho, double *vhat,
                                   double *drho) const {
  const int32_t *cols = cols_.data();
  const double *N = N_.data(), *G = G_.data();
  const __m256d zero = _mm256_setzero_pd();
  for (int64_t k = k0; k < k1; ++k) {
    const int64_t q0 = rb_[k], q1 = re_[k];
    __m256d sv0 = zero, sv1 = zero, d0 = zero, d1 = zero;
    int64_t q = q0;
    for (; q + 4 <= q1; q += 4) {
      const Entries4 e = entries4(v, cols, N, G, q);
      sv0 = _mm256_fmadd_pd(e.n, e.vx, sv0);
      sv1 = _mm256_fmadd_pd(e.n, e.vy, sv1);
      d0 = _mm256_fmadd_pd(e.vx, e.gx, d0);
      d1 = _mm256_fmadd_pd(e.vy, e.gy, d1);
    }
    double t[4];
    _mm256_storeu_pd(t, hsum4(sv0, sv1, d0, d1));
    for (; q < q1; ++q) {
      const double *vj = v + static_cast<size_t>(cols[q]) * 2;
      t[0] += N[q] * vj[0];
      t[1] += N[q] * vj[1];
      t[2] += vj[0] * G[2 * q];
      t[3] += vj[1] * G[2 * q + 1];
    }
    if (vhat) {
      vhat[2 * k] = t[0];
      vhat[2 * k + 1] = t[1];
    }
    if (drho) drho[k] = -rho[k] * (t[2] + t[3]);  // 003 eq 70, nodal parameters v_j
  }
}
MFREE_AVX2_END
#endif

// 003 eqs 56, 61, 67-68 with nodal quadrature: the force on node i is
//   f_i = sum_k [-sigma_k grad N_i(x_k) V_k + N_i(x_k) M_k g],  m_i = sum_k N_i(x_k) M_k,
// over the quadrature points k whose row holds i. One pass over the rows computes per
// point k the stress (times V_k), the interpolated velocity and the wall force and
// scatters the row's terms to the nodes i of the row (acc_); the chunks of rows of one
// colour touch disjoint nodes and run in parallel, the colours one after another, so that
// every node sums its terms in the same order whatever the number of threads.
Report FluidSystem::accel(const double *v, const double *rho, double *a) {
  const AccelArgs aa = accel_args(v, rho);
  const int32_t nall = nq();
  const int nt = scatter_threads_ ? num_threads(nall) : 1;
  const bool avx2 = dim_ == 2 && simd::use_avx2();  // once per call: every thread runs the same copy
  for (size_t col = 0; col + 1 < color_ptr_.size(); ++col) {
    const int32_t *chunks = chunk_order_.data() + color_ptr_[col];
    parallel_blocks(color_ptr_[col + 1] - color_ptr_[col], nt, [&](int, int64_t b, int64_t e) {
      for (int64_t c = b; c < e; ++c) {
        const int64_t k0 = static_cast<int64_t>(chunks[c]) * kChunk, k1 = std::min<int64_t>(nall, k0 + kChunk);
#if MFREE_SIMD_X86
        if (avx2) {
          accel_rows2_avx2(k0, k1, aa);
          continue;
        }
#endif
        for (int64_t k = k0; k < k1; ++k) {
          if (dim_ == 2) accel_point<2>(k, aa);
          else accel_point<3>(k, aa);
        }
      }
    });
  }
  return dim_ == 2 ? accel_end<2>(aa, a) : accel_end<3>(aa, a);
}

Report FluidSystem::rhs(double t, const double *y, double *ydot) {
  (void)t;
  Report rep = prepare(y);
  if (!rep.ok()) return rep;
  const size_t nd = static_cast<size_t>(dim_) * n_;
  const double *v = y + nd, *rho = y + 2 * nd;
  rep = accel(v, rho, ydot + nd);
  kinematics(v, rho, ydot, ydot + 2 * nd);
  return rep;
}

Report FluidSystem::velocity(const double *y, double *vhat) {
  Report rep = prepare(y);
  if (!rep.ok()) return rep;
  const size_t nd = static_cast<size_t>(dim_) * n_;
  kinematics(y + nd, y + 2 * nd, vhat, nullptr);
  return rep;
}

void FluidSystem::pressure(const double *y, double *p) const {
  const double *rho = y + 2 * static_cast<size_t>(dim_) * n_;
  for (int32_t i = 0; i < n_; ++i) p[i] = kappa_ * (std::pow(rho[i] / rho0_[i], gamma_) - 1.0);
}

Report FluidSystem::interpolation(const double *y, SparseMatrix &S) {
  Report rep = prepare(y);
  if (!rep.ok()) return rep;
  // rows are not guaranteed sorted by column: sort each row with its values
  // the fluid rows and columns only (dummies are not unknowns)
  const auto &acols = cols_;
  std::vector<int64_t> rp(static_cast<size_t>(n_) + 1, 0);
  std::vector<int32_t> cols;
  std::vector<double> vals;
  for (int32_t k = 0; k < n_; ++k) {
    std::vector<std::pair<int32_t, double>> row;
    for (int64_t e = rb(k); e < re(k); ++e)
      if (acols[e] < n_) row.push_back({acols[e], N_[e]});
    std::sort(row.begin(), row.end());
    for (auto &q : row) {
      cols.push_back(q.first);
      vals.push_back(q.second);
    }
    rp[k + 1] = static_cast<int64_t>(cols.size());
  }
  S.set_pattern(n_, n_, rp, cols);
  std::copy(vals.begin(), vals.end(), S.values_mut().begin());
  return rep;
}

Report FluidSystem::mass(const double *y, bool consistent, SparseMatrix &M) {
  Report rep = prepare(y);
  if (!rep.ok()) return rep;
  const int dim = dim_;
  const size_t nd = static_cast<size_t>(dim) * n_;
  const auto &cols = cols_;
  const auto &N = N_;
  // node-level velocity block: consistent m_ij = sum_k N_i(x_k) N_j(x_k) M_k (003 eq 42),
  // or the lumped row sums
  std::vector<std::vector<std::pair<int32_t, double>>> rows(n_);
  // with dummies: fluid rows and columns only, lumped masses as in accel (fluid_wall.hpp)
  for (int32_t k = 0; k < n_; ++k)
    for (int64_t a = rb(k); a < re(k); ++a) {
      if (cols[a] >= n_) continue;
      for (int64_t b = rb(k); b < re(k); ++b) {
        const double m = N[a] * N[b] * mass_[k];
        if (consistent) {
          if (cols[b] < n_) rows[cols[a]].push_back({cols[b], m});
        } else {
          rows[cols[a]].push_back({cols[a], m / share(k)});
        }
      }
    }
  std::vector<int64_t> rowptr(static_cast<size_t>(neq()) + 1, 0);
  std::vector<int32_t> ci;
  std::vector<double> vals;
  int32_t r = 0;
  auto identity_row = [&]() {
    ci.push_back(r);
    vals.push_back(1.0);
    rowptr[r + 1] = static_cast<int64_t>(ci.size());
    ++r;
  };
  for (size_t q = 0; q < nd; ++q) identity_row();
  for (int32_t i = 0; i < n_; ++i) {
    auto &row = rows[i];
    std::sort(row.begin(), row.end());
    std::vector<std::pair<int32_t, double>> merged;
    for (auto &e : row) {
      if (!merged.empty() && merged.back().first == e.first) merged.back().second += e.second;
      else merged.push_back(e);
    }
    if (lump_ == MFREE_LUMP_PHYSICAL && !consistent) merged.assign(1, {i, mass_[i]});
    for (int c = 0; c < dim; ++c) {
      for (auto &e : merged) {
        ci.push_back(static_cast<int32_t>(nd) + e.first * dim + c);
        vals.push_back(e.second);
      }
      rowptr[r + 1] = static_cast<int64_t>(ci.size());
      ++r;
    }
  }
  for (int32_t i = 0; i < n_; ++i) identity_row();
  M.set_pattern(neq(), neq(), std::move(rowptr), std::move(ci));
  std::copy(vals.begin(), vals.end(), M.values_mut().begin());
  return rep;
}

double FluidSystem::stable_dt(const double *y) const {
  const size_t nd = static_cast<size_t>(dim_) * n_;
  const double *v = y + nd, *rho = y + 2 * nd;
  double tmax[64] = {};  // per thread (parallel_blocks runs at most 64): a maximum is exact in any order
  parallel_blocks(n_, light_threads(n_), [&](int t, int64_t b, int64_t e) {
    double cm = 0.0;
#ifdef __SSE2__
    if (dim_ == 2) {  // two particles at a time: the same correctly rounded roots, an exact maximum
      const __m128d gk = _mm_set1_pd(gamma_ * kappa_);
      __m128d m2 = _mm_setzero_pd();
      for (; b + 2 <= e; b += 2) {
        const __m128d v0 = _mm_loadu_pd(v + 2 * b), v1 = _mm_loadu_pd(v + 2 * b + 2);
        const __m128d vx = _mm_unpacklo_pd(v0, v1), vy = _mm_unpackhi_pd(v0, v1);
        const __m128d vv = _mm_add_pd(_mm_mul_pd(vx, vx), _mm_mul_pd(vy, vy));
        const __m128d c = _mm_sqrt_pd(_mm_div_pd(gk, _mm_loadu_pd(rho + b)));
        m2 = _mm_max_pd(m2, _mm_add_pd(c, _mm_sqrt_pd(vv)));
      }
      double t2[2];
      _mm_storeu_pd(t2, m2);
      cm = std::max(t2[0], t2[1]);
    }
#endif
    for (int64_t i = b; i < e; ++i) {
      double vv = 0.0;
      for (int c = 0; c < dim_; ++c) vv += v[i * dim_ + c] * v[i * dim_ + c];
      cm = std::max(cm, std::sqrt(gamma_ * kappa_ / rho[i]) + std::sqrt(vv));  // 003 eqs 120-121
    }
    tmax[t] = cm;
  });
  const double cmax = *std::max_element(tmax, tmax + 64);
  return cmax > 0.0 ? h_ / cmax : INFINITY;
}

namespace {
// A failure inside integrate's step `step` (1 for the first): the message names it.
Report step_failed(Report r, int64_t step, const char *stage) {
  r.message = "step " + std::to_string(step) + stage + ": " + r.message;
  return r;
}
}  // namespace

std::string FluidSystem::fastest(const double *y) const {
  const size_t nd = static_cast<size_t>(dim_) * n_;
  const double *v = y + nd, *rho = y + 2 * nd;
  int32_t imax = 0;
  double smax = -1.0;
  for (int32_t i = 0; i < n_; ++i) {  // without overflow in |v|: hypot
    double vi = 0.0;
    for (int c = 0; c < dim_; ++c) vi = std::hypot(vi, v[static_cast<size_t>(i) * dim_ + c]);
    const double si = std::sqrt(gamma_ * kappa_ / rho[i]) + vi;
    if (si > smax) smax = si, imax = i;
  }
  std::ostringstream s;
  s << " (fastest: particle " << imax << ", c + |v| = " << smax << ")";
  return s.str();
}

Report FluidSystem::integrate(int scheme, double *y, double &t, double t_end, double cfl, double dt_max,
                              mfree_progress_fn progress, void *user, int64_t &nsteps) {
  if (scheme != MFREE_INTEGRATOR_LEAPFROG && scheme != MFREE_INTEGRATOR_PREDICTOR_CORRECTOR)
    throw Error(MFREE_ERR_ARG, "unknown integrator");
  if (!(std::isfinite(t_end) && std::isfinite(t))) throw Error(MFREE_ERR_ARG, "times must be finite");
  if (!(std::isfinite(cfl) && cfl <= 1.0)) throw Error(MFREE_ERR_ARG, "cfl must be finite and <= 1");
  if (!(std::isfinite(dt_max) && dt_max >= 0.0)) throw Error(MFREE_ERR_ARG, "dt_max must be finite and >= 0");
  if (cfl <= 0.0 && dt_max <= 0.0) throw Error(MFREE_ERR_ARG, "give a CFL number or a fixed step dt_max");
  check_ready();
  nsteps = 0;
  Report rep;
  const int dim = dim_;
  const size_t nd = static_cast<size_t>(dim) * n_, ny = static_cast<size_t>(neq());
  work_state_.resize(ny);
  stage_.resize(ny);
  rate_.resize(ny);
  vh_.resize(nd);
  dr_.resize(n_);
  double *rate = rate_.data(), *vh = vh_.data(), *dr = dr_.data();
  while (t < t_end) {
    rep = prepare(y, nsteps > 0);  // after the first step y is the state check_state passed below
    if (!rep.ok()) {
      rep.message = "step " + std::to_string(nsteps) + ": " + rep.message;
      return rep;
    }
    const double limit = stable_dt(y);
    double dt = cfl > 0.0 ? cfl * limit : dt_max;
    if (cfl > 0.0 && dt_max > 0.0) dt = std::min(dt, dt_max);
    if (cfl <= 0.0 && dt > limit) {
      std::ostringstream s;
      s << "step " << nsteps + 1 << ": dt = " << dt << " exceeds the CFL limit " << limit << " (003 eq 120)";
      rep.fail(MFREE_FAIL_CFL, s.str());
      return rep;
    }
    if (!(t + dt > t) && dt < t_end - t) {
      // speeds so large that h / max(c + |v|) is 0 (|v|^2 or gamma kappa / rho overflow)
      // or a step below t's resolution: the loop would never end
      std::ostringstream s;
      s << "step " << nsteps + 1 << ": the step dt = " << dt << " no longer advances t = " << t;
      if (cfl > 0.0) s << fastest(y) << " (003 eq 120)";
      rep.fail(MFREE_FAIL_CFL, s.str());
      return rep;
    }
    dt = std::min(dt, t_end - t);
    double *yn = work_state_.data();
    const double *x = y, *v = y + nd, *rho = y + 2 * nd;
    if (scheme == MFREE_INTEGRATOR_LEAPFROG) {
      // 003 Sect. 6.1: a from (x^k, rho^k, v^{k-1/2}); v^{k+1/2} = v + dt a; density rates
      // and interpolated velocities with v^{k+1/2} on the tables at x^k
      Report r = accel(v, rho, rate);
      if (!r.ok()) return step_failed(r, nsteps + 1, "");
      const int nt = light_threads(n_);
      parallel_blocks(static_cast<int64_t>(nd), nt, [&](int, int64_t b, int64_t e) {
        for (int64_t q = b; q < e; ++q) yn[nd + q] = v[q] + dt * rate[q];
      });
      kinematics(yn + nd, rho, vh, dr);
      parallel_blocks(n_, nt, [&](int, int64_t b, int64_t e) {
        for (int64_t q = b * dim; q < e * dim; ++q) yn[q] = x[q] + dt * vh[q];
        for (int64_t i = b; i < e; ++i) yn[2 * nd + i] = rho[i] + dt * dr[i];
      });
    } else {
      // 003 eqs 111-119; f(t, y) on the tables prepared above
      Report r = accel(v, rho, rate + nd);
      if (!r.ok()) return step_failed(r, nsteps + 1, "");
      kinematics(v, rho, rate, rate + 2 * nd);
      double *yp = stage_.data();
      for (size_t q = 0; q < ny; ++q) yp[q] = y[q] + 0.5 * dt * rate[q];
      r = prepare(yp);
      if (!r.ok()) return step_failed(r, nsteps + 1, " (predictor)");  // the step being taken, as below
      r = accel(yp + nd, yp + 2 * nd, rate);
      if (!r.ok()) return step_failed(r, nsteps + 1, " (predictor)");
      for (size_t q = 0; q < nd; ++q) yn[nd + q] = v[q] + 0.5 * dt * rate[q];  // v^C
      kinematics(yn + nd, yp + 2 * nd, vh, dr);
      for (int32_t i = 0; i < n_; ++i) yn[2 * nd + i] = rho[i] + 0.5 * dt * dr[i];  // rho^C
      for (size_t q = 0; q < nd; ++q) yn[q] = x[q] + 0.5 * dt * vh[q];              // x^C
      for (size_t q = 0; q < ny; ++q) yn[q] = 2.0 * yn[q] - y[q];                   // eqs 117-119
    }
    Report bad = check_state(yn, nsteps + 1);
    if (!bad.ok()) return bad;  // y keeps the last good state
    parallel_blocks(static_cast<int64_t>(ny), light_threads(n_), [&](int, int64_t b, int64_t e) {
      std::copy(yn + b, yn + e, y + b);
    });
    t = (t_end - t <= dt) ? t_end : t + dt;
    ++nsteps;
    if (progress && progress(user, nsteps, t, dt)) break;
  }
  return rep;
}

}  // namespace mfree
