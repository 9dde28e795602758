// Approximant: the particle records (pack) and the pattern of the tables (build_pattern,
// share_rows), with the size check made before anything is allocated.
#include "core/shape/approximant.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <sstream>
#include <type_traits>
#include <utility>

#include "core/base/basis.hpp"
#include "core/base/parallel.hpp"
#include "core/particles/neighbors.hpp"
#include "core/shape/approximant_pack.hpp"

namespace mfree {

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
  rows_shared_ = !points_ && !ps_->host_neighbors() && conv == MFREE_SEARCH_GATHER && !any_periodic &&
                 R == ps_->kappa() && share_rows(*src);
  if (rows_shared_) return;
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

const double *Approximant::packed_volumes(int64_t &stride) const {
  stride = record_length(ps_->dim());
  return pack_.data() + ps_->dim();
}

}  // namespace mfree
