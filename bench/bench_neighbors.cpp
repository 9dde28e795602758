// Neighbour search: mfree's cell list (mfree_particles_setup) on jittered lattices in 2D
// and 3D with ~21 / ~57 neighbours, serial and on all cores, against nanoflann's k-d
// tree (build + radius search of every point, when nanoflann was found at configure
// time) and, at 10^4 points, against the O(N^2) oracle (row-by-row identical sets).
// Usage: bench_neighbors [n ...]   sizes (default 10000 100000; add 1000000 by hand).
// Prints particles per second and the ratio to each reference. Never run by the tests.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include <sys/mman.h>
#include <sys/resource.h>

#include "bench_util.h"
#include <mfree.h>

#ifdef MFREE_BENCH_HAVE_NANOFLANN
#include <nanoflann.hpp>

namespace {
struct Cloud {
  const double *x;
  size_t n;
  int dim;
  size_t kdtree_get_point_count() const { return n; }
  double kdtree_get_pt(size_t i, size_t c) const { return x[i * dim + c]; }
  template <class B>
  bool kdtree_get_bbox(B &) const { return false; }
};

// Build + radius search of every point. With lists: the hits go to CSR lists (row
// pointers and 32-bit columns, in fresh vectors each call, rows unsorted), the output
// mfree's search produces; without: only counted, one hits vector reused.
template <int D, bool Lists = false>
double nanoflann_time(const double *x, int n, double r, long long *pairs) {
  using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, Cloud>, Cloud, D, unsigned>;
  Cloud cloud{x, static_cast<size_t>(n), D};
  const double t0 = bench_now();
  Tree tree(D, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  tree.buildIndex();
  std::vector<std::pair<unsigned, double>> hits;
  nanoflann::SearchParams params;
  params.sorted = false;
  long long total = 0;
  std::vector<int64_t> rowptr;
  std::vector<int32_t> cols;
  if (Lists) rowptr.resize(static_cast<size_t>(n) + 1);
  for (int i = 0; i < n; ++i) {
    hits.clear();
    total += static_cast<long long>(tree.radiusSearch(x + static_cast<size_t>(i) * D, r * r, hits, params));
    if (Lists) {
      for (const auto &hit : hits) cols.push_back(static_cast<int32_t>(hit.first));
      rowptr[static_cast<size_t>(i) + 1] = static_cast<int64_t>(cols.size());
    }
  }
  *pairs = total;
  const double t = bench_now() - t0;
  if (Lists && cols.size() != static_cast<size_t>(total)) std::printf("nanoflann lists: wrong size\n");
  return t;
}
}  // namespace
#endif

namespace {

// All pairs within r, row by row; returns the number of rows that differ from mfree's.
long long oracle_diff(int dim, int n, const double *x, double r, const int64_t *rowptr,
                      const int32_t *cols, double *seconds) {
  const double t0 = bench_now();
  long long bad = 0;
  std::vector<int32_t> row;
  for (int i = 0; i < n; ++i) {
    row.clear();
    for (int j = 0; j < n; ++j) {
      double d2 = 0;
      for (int c = 0; c < dim; ++c) {
        const double d = x[dim * i + c] - x[dim * j + c];
        d2 += d * d;
      }
      if (d2 <= r * r) row.push_back(j);
    }
    if (!std::equal(row.begin(), row.end(), cols + rowptr[i], cols + rowptr[i + 1])) ++bad;
  }
  *seconds = bench_now() - t0;
  return bad;
}

// Minor page faults of this process so far (a first touch of a fresh page is one).
long minor_faults() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_minflt;
}

// What a first touch of a fresh small page costs here: 16 MiB mapped, kept off huge
// pages, written one byte per page, best of three; seconds per fault. The first setup
// of a new set pays this for every page of its lists and buffers (on virtual machines
// several times bare metal's: the part of the first setup no search can save).
double fault_cost() {
  const size_t bytes = size_t{16} << 20;
  double best = 1e300;
  for (int r = 0; r < 3; ++r) {
    void *m = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (m == MAP_FAILED) return 0.0;
    char *p = static_cast<char *>(m);
#ifdef MADV_NOHUGEPAGE
    madvise(p, bytes, MADV_NOHUGEPAGE);
#endif
    const long f0 = minor_faults();
    const double t0 = bench_now();
    for (size_t k = 0; k < bytes; k += 4096) p[k] = 1;
    const double t = bench_now() - t0;
    const long nf = minor_faults() - f0;
    munmap(m, bytes);
    if (nf > 0) best = std::min(best, t / static_cast<double>(nf));
  }
  return best < 1e300 ? best : 0.0;
}

// Counting allocator on the context: bytes currently held through the hook.
struct Held {
  long long bytes = 0;
};
void *held_alloc(void *user, int64_t bytes) {
  static_cast<Held *>(user)->bytes += bytes;
  return std::malloc(static_cast<size_t>(bytes));
}
void held_free(void *user, void *p, int64_t bytes) {
  static_cast<Held *>(user)->bytes -= bytes;
  std::free(p);
}

// Best of reps setups of one particle set (the repeated search of a moving-particle
// code: from the second setup on the set reuses its grid and buffers); *held = bytes
// held by the set-up set (lists + search scratch + copied supports), per particle.
// With tn: the setups alternate one thread and `threads` (the context's count changed
// between calls, so that a busy moment of the VM spoils both alike), the best of reps
// each; the return value is the one-thread best, *tn the other. Without tn: `threads`.
double time_mfree(int dim, int n, const double *x, double h, int threads, int reps, int64_t *nnz,
                  mfree_particles_t **keep, double *held, double *first = nullptr, double *tn = nullptr,
                  long *first_faults = nullptr) {
  mfree_context_t *ctx = nullptr;
  mfree_particles_t *ps = nullptr;
  static Held count;  // outlives a kept set (destroyed after this context)
  count.bytes = 0;
  mfree_context_create(&ctx);
  bench_page_hints(ctx);
  if (held) mfree_context_set_allocator(ctx, held_alloc, held_free, &count);  // (not thread-safe: 1-thread run)
  mfree_context_set_num_threads(ctx, 1);
  mfree_particles_create(ctx, dim, n, &ps);
  mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, dim, MFREE_BORROW);
  mfree_particles_set_support(ps, &h, 0, MFREE_COPY);
  double best[2] = {1e300, 1e300};
  const int rounds = tn ? 2 * reps : reps;
  for (int r = 0; r < rounds; ++r) {
    const int k = tn ? (r & 1) : 0;
    mfree_context_set_num_threads(ctx, tn ? (k ? threads : 1) : threads);
    const long f0 = minor_faults();
    const double t0 = bench_now();
    if (mfree_particles_setup(ps) != MFREE_SUCCESS) {
      std::fprintf(stderr, "mfree_particles_setup failed\n");
      std::exit(1);
    }
    const double t = bench_now() - t0;
    if (r == 0 && first) *first = t;  // the set's first search: allocates its buffers
    if (r == 0 && first_faults) *first_faults = minor_faults() - f0;
    best[k] = std::min(best[k], t);
  }
  mfree_particles_get_neighbor_nnz(ps, nnz);
  if (held) *held = static_cast<double>(count.bytes) / n;
  if (tn) *tn = best[1];
  if (keep) *keep = ps;
  else mfree_particles_destroy(&ps);
  mfree_context_destroy(&ctx);
  return best[0];
}

void run(int dim, double n_target) {
  int n = 0;
  const int m = bench_side(dim, n_target);
  double *x = bench_lattice(dim, m, 0.3, &n);
  const double r = bench_radius(dim), h = 0.5 * r;  // cubic spline: support 2h
  const int reps = bench_reps(n <= 200000 ? 5 : 3);
  int64_t nnz = 0, nnz_t = 0;
  mfree_particles_t *ps = nullptr;
  double held = 0;
  // The one-thread set first: its first setup is the first search of this size in the
  // process (fresh pages from the kernel); the library's own allocator (no hook), as a
  // host without a hook gets it (big blocks then take huge pages, see alloc.hpp).
  // Its later setups alternate one and all threads.
  double t1_first = 0, t1_again = 0, tn = 0;
  long faults = 0;
  const double t1 =
      time_mfree(dim, n, x, h, bench_threads(), reps, &nnz, nullptr, nullptr, &t1_first, &tn, &faults);
  // the count of a fresh set set up on all threads only
  time_mfree(dim, n, x, h, bench_threads(), 1, &nnz_t, nullptr, nullptr, nullptr);
  // a new set again, right after another one was destroyed (memory just freed)
  int64_t nnz_a = 0;
  time_mfree(dim, n, x, h, 1, 1, &nnz_a, nullptr, nullptr, &t1_again);
  // the memory report (and the oracle's lists) through a counting hook
  int64_t nnz_h = 0;
  time_mfree(dim, n, x, h, 1, 1, &nnz_h, n <= 20000 ? &ps : nullptr, &held);
  std::printf("%dD n=%8d  neighbours %5.1f  mfree 1 thread %8.4f s %9.3g p/s | all threads %8.4f s"
              " %9.3g p/s (x%.2f)%s\n",
              dim, n, static_cast<double>(nnz) / n, t1, n / t1, tn, n / tn, t1 / tn,
              nnz_t == nnz && nnz_a == nnz && nnz_h == nnz ? "" : "  THREADED OR HOOKED COUNT DIFFERS");
  std::printf("      memory held by the set-up particle set: %.0f bytes per particle (lists %.0f)\n", held,
              4.0 * static_cast<double>(nnz) / n + 8.0);
  char lb[32];
  bench_figure(t1, "s", "neighbors %dD %d setup, 1 thread", dim, n);
  bench_figure(tn, "s", "neighbors %dD %d setup, %s", dim, n, bench_threads_label(bench_threads(), lb, sizeof lb));
  bench_figure(t1_first, "s", "neighbors %dD %d first setup of a new set, 1 thread", dim, n);
  bench_figure(t1_again, "s", "neighbors %dD %d first setup after a set was destroyed, 1 thread", dim, n);
  bench_figure(held, "B/particle", "neighbors %dD %d memory", dim, n);
#ifdef MFREE_BENCH_HAVE_NANOFLANN
  long long pairs = 0;
  double tk = 1e300, tk_first = 0;
  for (int k = 0; k < reps; ++k) {
    const double t = dim == 2 ? nanoflann_time<2>(x, n, r, &pairs) : nanoflann_time<3>(x, n, r, &pairs);
    if (k == 0) tk_first = t;  // its first run in this process at this size
    tk = std::min(tk, t);
  }
  bench_figure(tk, "s", "reference neighbors %dD %d nanoflann build + search, 1 thread", dim, n);
  std::printf("      nanoflann k-d tree build + radius search %8.4f s %9.3g p/s  pairs %s  "
              "mfree speed-up %.2fx (target >= 3)\n",
              tk, n / tk, pairs == nnz ? "equal" : "DIFFER", tk / t1);
  std::printf("      first setup of a new set (allocating its buffers): first of its size in the process "
              "%8.4f s: %.2fx nanoflann's best, %.2fx its first run (%.4f s); after another set was "
              "destroyed %8.4f s: %.2fx\n",
              t1_first, tk / t1_first, tk_first / t1_first, tk_first, t1_again, tk / t1_again);
  // like for like: nanoflann writing the same CSR lists into fresh vectors
  double tl = 1e300, tl_first = 0;
  for (int k = 0; k < reps; ++k) {
    const double t =
        dim == 2 ? nanoflann_time<2, true>(x, n, r, &pairs) : nanoflann_time<3, true>(x, n, r, &pairs);
    if (k == 0) tl_first = t;
    tl = std::min(tl, t);
  }
  std::printf("      nanoflann writing CSR lists too: first run %8.4f s (%.2fx mfree's first setup), best "
              "%8.4f s (%.2fx mfree's repeated setup)\n",
              tl_first, tl_first / t1_first, tl, tl / t1);
#else
  std::printf("      nanoflann: not found at configure time (Debian libnanoflann-dev), not measured\n");
#endif
  // The first setup's fresh pages, at what a first touch costs on this machine
  const double fc = fault_cost();
  std::printf("      first setup's page faults: %ld (%.0f bytes per particle), at %.2f us each "
              "(measured now) %.4f s; first setup without them %.4f s (repeated setups %.4f s)\n",
              faults, 4096.0 * static_cast<double>(faults) / n, 1e6 * fc, fc * static_cast<double>(faults),
              t1_first - fc * static_cast<double>(faults), t1);
  if (ps) {
    std::vector<int64_t> rowptr(static_cast<size_t>(n) + 1);
    std::vector<int32_t> cols(static_cast<size_t>(nnz));
    mfree_particles_get_neighbors(ps, rowptr.data(), cols.data());
    double tb = 0;
    const long long bad = oracle_diff(dim, n, x, r, rowptr.data(), cols.data(), &tb);
    std::printf("      O(N^2) oracle %8.3f s %9.3g p/s  rows differing %lld  mfree speed-up %.0fx\n",
                tb, n / tb, bad, tb / t1);
    mfree_particles_destroy(&ps);
  }
  std::free(x);
}

}  // namespace

int main(int argc, char **argv) {
  std::vector<double> sizes;
  for (int a = 1; a < argc; ++a) sizes.push_back(std::atof(argv[a]));
  if (sizes.empty()) sizes = {1e4, 1e5};
  std::printf("neighbour search, jittered lattices (jitter 0.3 spacing), cubic-spline support 2h\n");
  for (double s : sizes)
    for (int dim = 2; dim <= 3; ++dim) run(dim, s);
  return 0;
}
