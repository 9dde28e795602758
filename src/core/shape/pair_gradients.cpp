// Pair-list hosts on the approximant side: per-pair gradients read back in the host's
// pair order, and the per-site correction data for hosts that apply the correction
// themselves (the rows come from the particle set's pairs, particles/pairs.cpp).
#include <algorithm>
#include <climits>
#include <cmath>
#include <sstream>
#include <type_traits>

#include "core/shape/approximant.hpp"
#include "core/shape/local.hpp"
#include "core/base/parallel.hpp"

namespace mfree {

void Approximant::check_pairs_ready(const char *what) const {
  if (!setup_done_) throw Error(MFREE_ERR_STATE, std::string(what) + ": the approximant is not set up");
  if (points_)
    throw Error(MFREE_ERR_UNSUPPORTED, std::string(what) + ": the sites are host points, not the particles");
  if (method_ == MFREE_METHOD_MPFEM)
    throw Error(MFREE_ERR_UNSUPPORTED, std::string(what) + ": not defined for MPFEM");
  if (!ps_->is_setup() || set_setups_ != ps_->setup_count())
    throw Error(MFREE_ERR_STATE, std::string(what) +
                                     ": the particle set changed since this approximant's setup "
                                     "(set it up, then the approximant)");
}

namespace {

// One pair's two sides to the caller's records: a and c are the gradients of the first
// and second particle's rows (ha, hc: whether the row exists).
inline void write_pair(int dim, bool antisym, const double *a, bool ha, const double *c, bool hc,
                       double *oi, double *oj) {
  if (!antisym) {
    for (int d = 0; d < dim; ++d) oi[d] = a[d];
    if (oj)
      for (int d = 0; d < dim; ++d) oj[d] = c[d];
  } else if (ha && hc) {
    for (int d = 0; d < dim; ++d) oi[d] = 0.5 * (a[d] - c[d]);
  } else {  // one side known: the pair takes it (the other is its negative)
    for (int d = 0; d < dim; ++d) oi[d] = ha ? a[d] : -c[d];
  }
}

}  // namespace

void Approximant::kernel_gradient(int32_t s, int32_t j, double *g) const {
  double d[3] = {0, 0, 0}, r, w, dw, d2w;
  ps_->displacement(j, s, d);  // x_j - x_s
  kernel_at(*kernel_, ps_->dim(), d, pair_h(s, j), r, w, dw, d2w, g);
}

void Approximant::pair_gradients(double *gi, double *gj, int64_t ld, bool antisym) const {
  check_pairs_ready("pair gradients");
  if (!ps_->has_pairs())
    throw Error(MFREE_ERR_STATE, "the particle set has no pair list (mfree_particles_set_pairs)");
  if (!(flags_ & MFREE_DERIV_GRADIENT))
    throw Error(MFREE_ERR_STATE, "the gradient table was not built (mfree_approximant_set_derivatives)");
  const bool sph = method_ == MFREE_METHOD_SPH || method_ == MFREE_METHOD_SPH_SYMMETRIC;
  // SPH's kernel gradient is antisymmetric when h_ij is: one side gives the other,
  // exactly, also for a pair whose particles have no rows (ghosts).
  const bool sym_h = ps_->search_convention() != MFREE_SEARCH_GATHER;
  // The common case: every row is the set's row (the pair offsets) plus the site itself
  // appended, i.e. the kernel's support dropped no pair and no site failed; then the
  // offset gives the table entry directly, and a particle without a row has offset -1.
  // (With global ids the rows are in id order, not the order the offsets refer to.)
  const bool direct = static_cast<int64_t>(cols_.size()) == ps_->neighbors().nnz() + nsites_ &&
                      !ps_->has_global_ids();
  // Methods with correction records take every side from a record, the sites' own or a
  // ghost's (set_ghost_correction), so that a side computed where the particle is a
  // ghost equals the one computed where it is owned, bit for bit. A site whose record
  // is missing (it fell back to another order) is looked up in its row.
  const bool by_record = !records_.empty();
  if (sph && sym_h)
    pair_gradients_sph(gi, gj, ld, antisym);
  else if (direct && !sph && !by_record)
    pair_gradients_direct(gi, gj, ld, antisym);
  else
    pair_gradients_general(gi, gj, ld, antisym);
}

// The kernel gradient, computed as the host computes its dwdx (the table's entries
// differ from it in the last bits near the support's edge), and exactly antisymmetric.
void Approximant::pair_gradients_sph(double *gi, double *gj, int64_t ld, bool antisym) const {
  const int dim = ps_->dim();
  const int64_t P = ps_->num_pairs();
  const int32_t *pi = ps_->pair_first(), *pj = ps_->pair_second(), base = ps_->pair_base();
  const auto &pst = ps_->site_status();
  parallel_blocks(P, num_threads(P), [&](int, int64_t b, int64_t e) {
    for (int64_t k = b; k < e; ++k) {
      const int32_t i = pi[k] - base, j = pj[k] - base;
      double a[3] = {0, 0, 0}, c[3] = {0, 0, 0};
      const bool ok = pst[i] == 0 && pst[j] == 0;
      if (ok) kernel_gradient(i, j, a);
      for (int d = 0; d < dim; ++d) c[d] = -a[d];
      write_pair(dim, antisym, a, ok, c, ok, gi + k * ld, gj ? gj + k * ld : nullptr);
    }
  });
}

// Both sides straight from the tables at the pair offsets.
void Approximant::pair_gradients_direct(double *gi, double *gj, int64_t ld, bool antisym) const {
  const int dim = ps_->dim();
  const int64_t P = ps_->num_pairs();
  const int32_t *pi = ps_->pair_first(), *pj = ps_->pair_second(), base = ps_->pair_base();
  const int32_t *off = ps_->pair_offsets().data();
  int64_t vstride = 0;
  const double *vol = packed_volumes(vstride);
  const int64_t *rp = rowptr_.data();
  const double *G = grad_.data();
  parallel_blocks(P, num_threads(P), [&](int, int64_t b, int64_t e) {
    // the j side's row is far from the i side's in the tables: its entry is fetched a
    // few pairs ahead (the i sides run through their rows in order)
    constexpr int64_t ahead = 16;
    for (int64_t k = b; k < e; ++k) {
      if (k + ahead < e) {
        const int64_t ka = k + ahead;
        const int32_t ja = pj[ka] - base, oca = off[2 * ka + 1];
        if (oca >= 0) __builtin_prefetch(G + (rp[ja] + oca) * dim);
      }
      const int32_t i = pi[k] - base, j = pj[k] - base;
      const int32_t oa = off[2 * k], oc = off[2 * k + 1];
      double a[3] = {0, 0, 0}, c[3] = {0, 0, 0};
      const bool ha = oa >= 0, hc = oc >= 0;
      // 1/V_j and 1/V_i from one division
      const double vi = vol[i * vstride], vj = vol[j * vstride], ivv = 1.0 / (vi * vj);
      if (ha) {
        const double *g = G + (rp[i] + oa) * dim, iv = vi * ivv;
        for (int d = 0; d < dim; ++d) a[d] = g[d] * iv;
      }
      if (hc) {
        const double *g = G + (rp[j] + oc) * dim, iv = vj * ivv;
        for (int d = 0; d < dim; ++d) c[d] = g[d] * iv;
      }
      write_pair(dim, antisym, a, ha, c, hc, gi + k * ld, gj ? gj + k * ld : nullptr);
    }
  });
}

// The general case: rows the kernel's support filtered, failed sites, records, or SPH
// with a support of the row's own particle (gather): each side looked up, computed from
// its record, or for SPH computed.
void Approximant::pair_gradients_general(double *gi, double *gj, int64_t ld, bool antisym) const {
  const bool sph = method_ == MFREE_METHOD_SPH || method_ == MFREE_METHOD_SPH_SYMMETRIC;
  const bool sym_h = ps_->search_convention() != MFREE_SEARCH_GATHER;
  const bool by_record = !records_.empty();
  const int dim = ps_->dim();
  const int64_t P = ps_->num_pairs();
  const int32_t *pi = ps_->pair_first(), *pj = ps_->pair_second(), base = ps_->pair_base();
  const int32_t *off = ps_->pair_offsets().data();
  int64_t vstride = 0;
  const double *vol = packed_volumes(vstride);
  const int64_t *rp = rowptr_.data();
  const int32_t *cl = cols_.data();
  const double *G = grad_.data();
  const int32_t owned = nsites_;
  const auto &pst = ps_->site_status();
  const int m = by_record ? correction_size() : 0;
  const uint8_t *rok = rec_ok_.data();
  auto record_of = [&](int32_t s) -> const double * {
    if (!by_record || !rok[s]) return nullptr;
    return s < owned ? records_.data() + int64_t{s} * m : ghost_records_.data() + int64_t{s - owned} * m;
  };
  const RecordGradient record_gradient(local_config(true, true, false));
  auto find = [&](int32_t s, int32_t j, int32_t hint) -> int64_t {
    const int64_t b = rp[s], e = rp[s + 1];
    if (hint >= 0 && b + hint < e && cl[b + hint] == j) return b + hint;
    for (int64_t q = b; q < e; ++q)
      if (cl[q] == j) return q;
    return -1;
  };
  auto side = [&](int32_t s, int32_t j, int32_t hint, double *g) -> bool {
    g[0] = g[1] = g[2] = 0.0;
    if (pst[s] != 0 || pst[j] != 0) return false;
    if (sph) {  // the kernel gradient itself, for ghosts too: nothing to correct
      kernel_gradient(s, j, g);
      return true;
    }
    if (s >= owned || status_[s] != 0) return false;
    const int64_t q = find(s, j, hint);
    if (q >= 0) {
      const double iv = 1.0 / vol[j * vstride];
      for (int c = 0; c < dim; ++c) g[c] = G[q * dim + c] * iv;
    }
    return true;
  };
  // Both sides from records, without periodic images: the packed particle data (the
  // same numbers as the set's), the dimension fixed; else the general case below.
  bool periodic = false;
  for (int q = 0; q < dim; ++q) periodic = periodic || ps_->periodic(q);
  const int conv = ps_->search_convention();
  const double *pk = pack_.data();
  const int64_t S = vstride;  // the packed record length
  const double *ph = pk + (dim == 3 ? S * ps_->size() : dim + 1);
  const int64_t hst = dim == 3 ? 1 : S;
  auto both = [&](auto dc, int32_t i, int32_t j, double *a, double *c) {
    constexpr int D = decltype(dc)::value;
    const double *xi = pk + i * S, *xj = pk + j * S, hi = ph[i * hst], hj = ph[j * hst];
    double d[3] = {0, 0, 0}, r, w, dw, d2w, gw[3] = {0, 0, 0};
    for (int q = 0; q < D; ++q) d[q] = xj[q] - xi[q];
    kernel_at(*kernel_, D, d, pair_support(conv, hi, hj), r, w, dw, d2w, gw);
    record_gradient(record_of(i), hi, d, w, gw, xj[D], a);
    for (int q = 0; q < D; ++q) d[q] = -d[q];
    if (sym_h)
      for (int q = 0; q < D; ++q) gw[q] = -gw[q];
    else
      kernel_at(*kernel_, D, d, pair_support(conv, hj, hi), r, w, dw, d2w, gw);
    record_gradient(record_of(j), hj, d, w, gw, xi[D], c);
  };
  parallel_blocks(P, num_threads(P), [&](int, int64_t b, int64_t e) {
    for (int64_t k = b; k < e; ++k) {
      const int32_t i = pi[k] - base, j = pj[k] - base;
      double a[3] = {0, 0, 0}, c[3] = {0, 0, 0};
      if (by_record && !periodic && rok[i] && rok[j] && dim >= 2) {
        if (dim == 2) both(std::integral_constant<int, 2>(), i, j, a, c);
        else both(std::integral_constant<int, 3>(), i, j, a, c);
        write_pair(dim, antisym, a, true, c, true, gi + k * ld, gj ? gj + k * ld : nullptr);
        continue;
      }
      const bool ok = pst[i] == 0 && pst[j] == 0;
      const double *ri = ok ? record_of(i) : nullptr, *rj = ok ? record_of(j) : nullptr;
      if (ri || rj) {  // the kernel once for both sides where h_ij is symmetric
        double d[3] = {0, 0, 0}, r, w, dw, d2w, gw[3] = {0, 0, 0};
        ps_->displacement(j, i, d);  // x_j - x_i
        kernel_at(*kernel_, dim, d, pair_h(i, j), r, w, dw, d2w, gw);
        if (ri) record_gradient(ri, site_h(i), d, w, gw, vol[j * vstride], a);
        if (rj) {  // x_i - x_j and its gradient are the negatives, exactly
          for (int q = 0; q < dim; ++q) d[q] = -d[q];
          if (sym_h)
            for (int q = 0; q < dim; ++q) gw[q] = -gw[q];
          else
            kernel_at(*kernel_, dim, d, pair_h(j, i), r, w, dw, d2w, gw);
          record_gradient(rj, site_h(j), d, w, gw, vol[i * vstride], c);
        }
      }
      const bool ha = ri ? true : side(i, j, off[2 * k], a);
      const bool hc = rj ? true : side(j, i, off[2 * k + 1], c);
      write_pair(dim, antisym, a, ha, c, hc, gi + k * ld, gj ? gj + k * ld : nullptr);
    }
  });
}

// Doubles of a record (the layouts of mfree_approximant_get_correction), 0 for none.
namespace {
int correction_length(int method, int dim, int order) {
  switch (method) {
    case MFREE_METHOD_SHEPARD:
      return 1 + dim;
    case MFREE_METHOD_JOHNSON_BEISSEL:
      return dim;
    case MFREE_METHOD_RANDLES_LIBERSKY:
      return dim * dim;
    case MFREE_METHOD_KB_METHOD1:
      return dim * dim + 1 + dim;
    case MFREE_METHOD_MLS:
    case MFREE_METHOD_RKPM:
      return order <= 2 ? (1 + dim) * basis_size(dim, order) : 0;
    default:
      return 0;
  }
}
}  // namespace

int Approximant::correction_size() const {
  const int m = correction_length(method_, ps_->dim(), order_);
  if (m > 0) return m;
  if (method_ == MFREE_METHOD_MLS || method_ == MFREE_METHOD_RKPM)
    throw Error(MFREE_ERR_UNSUPPORTED, "correction data of MLS/RKPM are defined up to order 2");
  throw Error(MFREE_ERR_UNSUPPORTED,
              "correction data are defined for Shepard, MLS/RKPM, Johnson-Beissel, "
              "Randles-Libersky and KB Method 1");
}

bool Approximant::has_correction() const {
  return correction_length(method_, ps_->dim(), order_) > 0;
}

void Approximant::correction(double *out, int64_t ld) const {
  check_pairs_ready("correction data");
  const int m = correction_size();
  if (records_.empty()) return compute_records(out, ld);
  for (int32_t s = 0; s < nsites_; ++s)
    std::copy_n(records_.data() + int64_t{s} * m, m, out + s * ld);
}

bool Approximant::keeps_records() const {
  return !points_ && method_ != MFREE_METHOD_MPFEM && ps_->has_pairs() &&
         (flags_ & MFREE_DERIV_GRADIENT) && has_correction();
}

void Approximant::set_ghost_correction(const double *c, int64_t ld) {
  check_pairs_ready("ghost correction data");
  const int m = correction_size();
  const int64_t ng = ps_->size() - ps_->num_owned();
  // checked in full before anything is kept: a failed call changes nothing
  for (int64_t g = 0; g < ng; ++g)
    for (int a = 0; a < m; ++a)
      if (!std::isfinite(c[g * ld + a]))
        throw Error(MFREE_ERR_INPUT, "ghost correction data: value " + std::to_string(a) +
                                         " of ghost " + std::to_string(g) + " (particle " +
                                         std::to_string(ps_->num_owned() + g) + ") is not finite");
  ghost_records_.resize(static_cast<size_t>(ng * m));
  ghost_valid_.resize(static_cast<size_t>(ng));
  for (int64_t g = 0; g < ng; ++g) {
    const double *src = c + g * ld;
    double *dst = ghost_records_.data() + g * m;
    bool any = false;
    for (int a = 0; a < m; ++a) any |= src[a] != 0.0;
    std::copy_n(src, m, dst);
    ghost_valid_[g] = any;  // zeros: a site that failed or fell back at its owner
  }
  if (!records_.empty())
    for (int64_t g = 0; g < ng; ++g)
      rec_ok_[ps_->num_owned() + g] = ghost_valid_[g] && ps_->site_status()[ps_->num_owned() + g] == 0;
  ghost_set_ = true;
}

void Approximant::compute_records(double *out, int64_t ld, bool missing_only) const {
  const int m = correction_size();
  const LocalConfig cfg = local_config(false, true, false);
  const int want_order = has_order(method_) ? order_ : fixed_order(method_);
  const int nt = num_threads(nnz());
  parallel_blocks(nsites_, nt, [&](int, int64_t b, int64_t e) {
    const size_t row = static_cast<size_t>(std::max(maxrow_, 1));
    std::vector<double> d, v, h, g;  // sized at the first site computed here
    LocalWork work;
    for (int64_t s = b; s < e; ++s) {
      double *c = out + s * ld;
      const bool keep = status_[s] == 0 && order_used_[s] == want_order;  // not failed, nor fell back
      if (keep && missing_only && !std::isnan(c[0])) continue;
      std::fill(c, c + m, 0.0);
      if (!keep) continue;
      if (d.empty()) {
        d.resize(3 * row);
        v.resize(row);
        h.resize(row);
        g.resize(3 * row);
      }
      const int32_t site = static_cast<int32_t>(s);
      site_input(site, d.data(), v.data(), h.data());
      LocalInput in;
      in.n = static_cast<int>(rowptr_[s + 1] - rowptr_[s]);
      in.self = self_[s];
      in.hs = site_h(site);
      in.d = d.data();
      in.vol = v.data();
      in.h = h.data();
      LocalOutput o;
      o.grad = g.data();
      o.coef = c;
      compute_site(cfg, in, work, o);
      if (o.status) std::fill(c, c + m, 0.0);
    }
  });
}

}  // namespace mfree
