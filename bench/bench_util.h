/* Shared helpers of the benchmarks: wall clock, jittered lattices, thread count from the
 * environment. Header-only; the benchmarks are run by hand and never time a test. */
#ifndef MFREE_BENCH_UTIL_H
#define MFREE_BENCH_UTIL_H

#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <mfree.h>

/* Wall clock; with MFREE_BENCH_CLOCK=cpu the process CPU time instead, which keeps
 * one-thread figures meaningful on a machine shared with other jobs (threaded figures
 * then add the threads' times and mean nothing). */
static inline double bench_now(void) {
  static int cpu = -1;
  if (cpu < 0) {
    const char *s = getenv("MFREE_BENCH_CLOCK");
    cpu = s && s[0] == 'c';
  }
  struct timespec t;
  clock_gettime(cpu ? CLOCK_PROCESS_CPUTIME_ID : CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Huge pages and prefaulting for the library's big tables: a host that wants speed opts
 * in. A library from before the option did both by default (bench/CMakeLists.txt defines
 * MFREE_BENCH_HAVE_PAGE_HINTS when mfree.h declares it). */
static inline void bench_page_hints(mfree_context_t *ctx) {
#ifdef MFREE_BENCH_HAVE_PAGE_HINTS
  mfree_context_set_page_hints(ctx, MFREE_PAGES_HUGE | MFREE_PAGES_PREFAULT);
#else
  (void)ctx;
#endif
}

/* Deterministic uniform numbers in [-1, 1) (xorshift64*), the same on every libc. */
static inline double bench_rand(uint64_t *s) {
  *s ^= *s >> 12;
  *s ^= *s << 25;
  *s ^= *s >> 27;
  const uint64_t r = *s * 2685821657736338717ULL;
  return (double)(r >> 11) * (2.0 / 9007199254740992.0) - 1.0;
}

/* A jittered lattice of m^dim points with spacing 1, each coordinate moved by up to
 * +-jitter; AoS with dim per point. Returns malloc'ed memory (n = m^dim). */
static inline double *bench_lattice(int dim, int m, double jitter, int *n_out) {
  int n = 1;
  for (int d = 0; d < dim; ++d) n *= m;
  double *x = (double *)malloc(sizeof(double) * (size_t)dim * (size_t)n);
  uint64_t seed = 0x9e3779b97f4a7c15ULL + (uint64_t)dim;
  for (int p = 0; p < n; ++p) {
    int q = p;
    for (int c = 0; c < dim; ++c) {
      x[(size_t)dim * p + c] = (q % m) + jitter * bench_rand(&seed);
      q /= m;
    }
  }
  *n_out = n;
  return x;
}

/* Lattice side for about n_target points. */
static inline int bench_side(int dim, double n_target) {
  return (int)floor(pow(n_target, 1.0 / dim) + 0.5);
}

/* Search radius (lattice spacing 1) giving about 21 neighbours in 2D (pi r^2 = 21) and
 * 57 in 3D (4/3 pi r^3 = 57), the densities of every shape and pair benchmark. */
static inline double bench_radius(int dim) {
  const double pi = 3.14159265358979323846;
  return dim == 2 ? sqrt(21.0 / pi) : cbrt(57.0 * 3.0 / (4.0 * pi));
}

/* The pair-list workload (bench_pairs, scripts/bench-ab): supports h_i = h0 (1 + 0.02 u_i)
 * with u_i uniform in [-1, 1), and the host's half pair list (i, j > i), each pair once in
 * particle order, from the library's own search once (symmetric mean h_ij, kappa 2) as a
 * linked-list search would give it; *pi and *pj malloc'ed. Returns the pair count, or -1
 * with the context's message on stderr when a call failed. */
static inline void bench_pair_supports(int n, double h0, double *h) {
  uint64_t seed = 7;
  for (int i = 0; i < n; ++i) h[i] = h0 * (1.0 + 0.02 * bench_rand(&seed));
}
static inline int64_t bench_half_pairs(mfree_context_t *ctx, int dim, int n, const double *x,
                                       const double *h, int32_t **pi, int32_t **pj) {
  mfree_particles_t *search = NULL;
  int64_t nnz = 0, np = 0;
  if (mfree_particles_create(ctx, dim, n, &search) != MFREE_SUCCESS ||
      mfree_particles_set_positions(search, x, MFREE_LAYOUT_AOS, dim, MFREE_BORROW) != MFREE_SUCCESS ||
      mfree_particles_set_support(search, h, 1, MFREE_BORROW) != MFREE_SUCCESS ||
      mfree_particles_set_search(search, MFREE_SEARCH_SYMMETRIC_MEAN, 2.0) != MFREE_SUCCESS ||
      mfree_particles_setup(search) != MFREE_SUCCESS ||
      mfree_particles_get_neighbor_nnz(search, &nnz) != MFREE_SUCCESS) {
    char msg[512] = "";
    mfree_context_get_last_error(ctx, NULL, msg, sizeof msg);
    fprintf(stderr, "bench_half_pairs: %s\n", msg);
    mfree_particles_destroy(&search);
    return -1;
  }
  int64_t *rowptr = (int64_t *)malloc(sizeof(int64_t) * (size_t)(n + 1));
  int32_t *cols = (int32_t *)malloc(sizeof(int32_t) * (size_t)nnz);
  mfree_particles_get_neighbors(search, rowptr, cols);
  *pi = (int32_t *)malloc(sizeof(int32_t) * (size_t)(nnz / 2 + 8));
  *pj = (int32_t *)malloc(sizeof(int32_t) * (size_t)(nnz / 2 + 8));
  for (int i = 0; i < n; ++i)
    for (int64_t q = rowptr[i]; q < rowptr[i + 1]; ++q)
      if (cols[q] > i) {
        (*pi)[np] = i;
        (*pj)[np] = cols[q];
        ++np;
      }
  mfree_particles_destroy(&search);
  free(rowptr);
  free(cols);
  return np;
}

/* The pair-list workload's particle set (positions, supports, masses and densities
 * borrowed; symmetric-mean search, kappa 2) and its approximant of method m with the
 * gradient table; the first failing call's status. */
static inline mfree_status_t bench_pair_set(mfree_context_t *ctx, int dim, int n, const double *x,
                                            const double *h, const double *mass, const double *rho,
                                            mfree_method_t m, mfree_particles_t **ps,
                                            mfree_approximant_t **a) {
  mfree_status_t st;
  if ((st = mfree_particles_create(ctx, dim, n, ps)) != MFREE_SUCCESS ||
      (st = mfree_particles_set_positions(*ps, x, MFREE_LAYOUT_AOS, dim, MFREE_BORROW)) != MFREE_SUCCESS ||
      (st = mfree_particles_set_support(*ps, h, 1, MFREE_BORROW)) != MFREE_SUCCESS ||
      (st = mfree_particles_set_masses(*ps, mass, 1, MFREE_BORROW)) != MFREE_SUCCESS ||
      (st = mfree_particles_set_densities(*ps, rho, 1, MFREE_BORROW)) != MFREE_SUCCESS ||
      (st = mfree_particles_set_search(*ps, MFREE_SEARCH_SYMMETRIC_MEAN, 2.0)) != MFREE_SUCCESS ||
      (st = mfree_approximant_create(ctx, *ps, m, a)) != MFREE_SUCCESS)
    return st;
  return mfree_approximant_set_derivatives(*a, MFREE_DERIV_GRADIENT);
}

/* Threads for the "all cores" runs: MFREE_BENCH_THREADS, else 0 (all cores). */
static inline int bench_threads(void) {
  const char *s = getenv("MFREE_BENCH_THREADS");
  return s ? atoi(s) : 0;
}

/* The name of the second thread count in figures: "all threads" (count 0), "N threads",
 * or "1 thread (second count)", so that it never equals the one-thread figure's. */
static inline const char *bench_threads_label(int threads, char *buf, size_t len) {
  if (threads <= 0) return "all threads";
  if (threads == 1) return "1 thread (second count)";
  snprintf(buf, len, "%d threads", threads);
  return buf;
}

/* Repetitions of a program's timing loop: MFREE_BENCH_REPS overrides the program's
 * default `def` (fewer for a side-by-side run that repeats whole programs instead). */
static inline int bench_reps(int def) {
  const char *s = getenv("MFREE_BENCH_REPS");
  const int r = s ? atoi(s) : 0;
  return r > 0 ? r : def;
}

/* Machine-readable figures: with MFREE_BENCH_FORMAT=tsv each figure is also printed as
 * one line "name<TAB>value<TAB>unit" among the human lines (which carry no tab), for
 * scripts/bench-compare.sh. Times are in seconds (unit "s", lower is better), memory in
 * "B/particle"; the name of a figure of a reference that is not mfree (nanoflann, the
 * triad, a host loop) starts with "reference ". Names are stable: the script matches the
 * figures of two builds by them. */
#if defined(__GNUC__)
__attribute__((format(printf, 3, 4)))
#endif
static inline void bench_figure(double value, const char *unit, const char *name_fmt, ...) {
  static int tsv = -1;
  if (tsv < 0) {
    const char *s = getenv("MFREE_BENCH_FORMAT");
    tsv = s && strcmp(s, "tsv") == 0;
  }
  if (!tsv) return;
  char name[256];
  va_list ap;
  va_start(ap, name_fmt);
  vsnprintf(name, sizeof name, name_fmt, ap);
  va_end(ap);
  printf("%s\t%.6g\t%s\n", name, value, unit);
}

#endif
