// Half pair lists (each unordered pair once, as legacy SPH hydrocodes keep them): the
// particle set's rows built from the pairs (per-pair gradients and correction data:
// shape/pair_gradients.cpp).
#include <algorithm>
#include <climits>
#include <cmath>
#include <sstream>
#include <type_traits>

#include "core/particles/particles.hpp"

namespace mfree {

namespace {

// Particle p (0-based) and pair k in the host's numbering.
std::string host_particle(int32_t p, int32_t base) { return std::to_string(int64_t{p} + base); }
std::string host_pair(int64_t k, int32_t base) { return std::to_string(k + base); }

}  // namespace

void ParticleSet::check_pairs(int64_t npairs, const int32_t *pi, const int32_t *pj,
                              int32_t base) const {
  if (npairs > 0 && (!pi || !pj)) throw Error(MFREE_ERR_NULL, "pair_i or pair_j is NULL");
  // the common case in one branch-free pass; the failing pair is named by a second one
  const int64_t lo = base, hi = int64_t{base} + n_;
  bool bad = false;
  for (int64_t k = 0; k < npairs; ++k) {
    const int64_t a = pi[k], b = pj[k];
    bad |= (a < lo) | (a >= hi) | (b < lo) | (b >= hi) | (a == b);
  }
  if (!bad) return;
  const std::string range = "[" + std::to_string(lo) + ", " + std::to_string(hi - 1) + "]";
  for (int64_t k = 0; k < npairs; ++k) {
    const int64_t a = pi[k], b = pj[k];
    const std::string at = "pair " + host_pair(k, base) + (base ? " (1-based)" : "");
    if (a < lo || a >= hi)
      throw Error(MFREE_ERR_INPUT, at + ": pair_i = " + std::to_string(a) + " is outside " + range);
    if (b < lo || b >= hi)
      throw Error(MFREE_ERR_INPUT, at + ": pair_j = " + std::to_string(b) + " is outside " + range);
    if (a == b)
      throw Error(MFREE_ERR_INPUT,
                  at + " joins particle " + std::to_string(a) + " with itself (self pair)");
  }
}

void ParticleSet::set_pairs(int64_t npairs, const int32_t *pi, const int32_t *pj, int32_t base,
                            int mem) {
  if (mem != MFREE_COPY && mem != MFREE_BORROW)
    throw Error(MFREE_ERR_ARG, "mem must be MFREE_COPY or MFREE_BORROW, got " + std::to_string(mem));
  if (base != 0 && base != 1)
    throw Error(MFREE_ERR_ARG, "index base must be 0 or 1, got " + std::to_string(base));
  if (npairs < 0)
    throw Error(MFREE_ERR_ARG, "pair count " + std::to_string(npairs) + " is negative");
  check_pairs(npairs, pi, pj, base);
  PairList p;
  p.set = true;
  p.n = npairs;
  p.base = base;
  if (mem == MFREE_COPY) {
    p.own_i.assign(pi, pi + npairs);
    p.own_j.assign(pj, pj + npairs);
    p.i = p.own_i.data();
    p.j = p.own_j.data();
  } else {
    p.i = pi;
    p.j = pj;
  }
  pairs_ = std::move(p);
  host_rowptr_ = nullptr;  // a pair list replaces CSR lists
  host_cols_ = nullptr;
  host_rowptr_own_.clear();
  host_cols_own_.clear();
  setup_done_ = false;
}

// Two counting passes, O(npairs + n), no search and no sort: the first puts each pair
// in both particles' rows in pair order; the second reads those rows particle by
// particle and appends the particle to the rows of its neighbours, so every row comes
// out in ascending order (the lists are symmetric: the transpose of the first pass is
// the neighbour lists again). Pairs with an isolated particle (nonzero status) are left
// out; the rows are those of the owned particles.
void ParticleSet::rows_from_pairs(Csr &out, std::vector<int32_t> &offsets) {
  const int64_t P = pairs_.n;
  const int32_t *pi = pairs_.i, *pj = pairs_.j, base = pairs_.base;
  check_pairs(P, pi, pj, base);  // borrowed lists may have changed since set_pairs
  const int32_t n = n_, owned = num_owned();
  const int32_t *st = site_status_.data();
  // start[p]: where row p of the first pass begins (start[n] = all entries)
  pair_start_.assign(static_cast<size_t>(n) + 1, 0);
  int64_t *start = pair_start_.data();
  for (int64_t k = 0; k < P; ++k) {
    const int32_t a = pi[k] - base, b = pj[k] - base;
    if (st[a] | st[b]) continue;
    ++start[a + 1];
    ++start[b + 1];
  }
  for (int32_t p = 0; p < n; ++p) start[p + 1] += start[p];
  const int64_t total = start[n];
  pair_fill_.assign(start, start + n);
  int64_t *fill = pair_fill_.data();
  // Rows come out sorted: a repeated pair shows as two equal neighbours c, r.
  auto duplicate = [&](int32_t c, int32_t r) {
    int64_t first = -1, second = -1;
    for (int64_t k = 0; k < P && second < 0; ++k) {
      const int32_t a = pi[k] - base, b = pj[k] - base;
      if ((a == c && b == r) || (a == r && b == c)) (first < 0 ? first : second) = k;
    }
    throw Error(MFREE_ERR_INPUT, "pairs " + host_pair(first, base) + " and " + host_pair(second, base) +
                                     (base ? " (1-based)" : "") + " both join particles " +
                                     host_particle(std::min(c, r), base) + " and " +
                                     host_particle(std::max(c, r), base) + " (duplicate pair)");
  };
  pair_tmp_col_.resize(static_cast<size_t>(total));
  int32_t *tc = pair_tmp_col_.data();
  // The final rows have the sizes of the first pass's; only owned particles get one.
  out.rowptr.resize(static_cast<size_t>(owned) + 1);
  std::copy(start, start + owned + 1, out.rowptr.data());
  const int64_t nnz = start[owned];
  out.cols.resize(static_cast<size_t>(nnz));
  offsets.assign(static_cast<size_t>(2 * P), -1);
  int32_t *cl = out.cols.data();
  // Entry ids 2k (pair k in its first particle's row) and 2k + 1, 32-bit when they fit.
  // (Both passes scatter: the rows they write to are fetched a few entries ahead.)
  constexpr int64_t ahead = 16;
  auto passes = [&](auto *tid) {
    for (int64_t k = 0; k < P; ++k) {
      if (k + ahead < P) {
        __builtin_prefetch(tc + fill[pi[k + ahead] - base], 1);
        __builtin_prefetch(tc + fill[pj[k + ahead] - base], 1);
      }
      const int32_t a = pi[k] - base, b = pj[k] - base;
      if (st[a] | st[b]) continue;
      const int64_t u = fill[a]++, v = fill[b]++;
      tc[u] = b;
      tid[u] = static_cast<std::remove_pointer_t<decltype(tid)>>(2 * k);
      tc[v] = a;
      tid[v] = static_cast<std::remove_pointer_t<decltype(tid)>>(2 * k + 1);
    }
    std::copy(start, start + owned, fill);
    for (int32_t r = 0; r < n; ++r)
      for (int64_t u = start[r]; u < start[r + 1]; ++u) {
        if (u + ahead < total) {
          const int32_t ca = tc[u + ahead];
          if (ca < owned) __builtin_prefetch(cl + fill[ca], 1);
          __builtin_prefetch(offsets.data() + (tid[u + ahead] ^ 1), 1);
        }
        const int32_t c = tc[u];
        if (c >= owned) continue;  // a ghost has no row
        const int64_t q = fill[c]++;
        if (q > start[c] && cl[q - 1] == r) duplicate(c, r);
        cl[q] = r;
        offsets[static_cast<size_t>(tid[u] ^ 1)] = static_cast<int32_t>(q - start[c]);
      }
  };
  if (2 * P <= INT32_MAX) {
    pair_tmp_id32_.resize(static_cast<size_t>(total));
    passes(pair_tmp_id32_.data());
  } else {
    pair_tmp_id_.resize(static_cast<size_t>(total));
    passes(pair_tmp_id_.data());
  }
}

}  // namespace mfree
