/* Operator application: gradient of a scalar and of a 3-vector by mfree_approximant_apply
 * with a set-up MLS (order 1) gradient table, against a STREAM-style triad
 * a[i] = b[i] + s c[i] measured in the same binary on arrays far larger than the caches.
 * Reported as the bandwidth the apply reaches (bytes of the table, column indices, row
 * pointers, input and output counted once) as a fraction of the triad's (24 bytes per
 * element, the STREAM convention). Target >= 50 %. Usage: bench_apply [n] (100000). */
#include "bench_util.h"

#include <mfree.h>
#ifdef _OPENMP
#include <omp.h>
#endif
#include <string.h>
#if defined(__linux__)
#include <sys/mman.h>
#endif

/* The triad's arrays on transparent huge pages where the kernel offers them (madvise), like
 * mfree's own tables with the page hints this program asks for (bench_page_hints,
 * src/core/base/alloc.hpp), so that the ratio is not skewed by the triad's TLB misses; the
 * library's debugging override MFREE_HUGEPAGES=0 turns both off. */
static double *triad_array(size_t len) {
  void *p = NULL;
  if (posix_memalign(&p, (size_t)2 << 20, len * sizeof(double)) != 0) return NULL;
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  const char *e = getenv("MFREE_HUGEPAGES");
  if (!(e && strcmp(e, "0") == 0)) (void)madvise(p, len * sizeof(double), MADV_HUGEPAGE);
#endif
  return p;
}

/* Best triad time on one thread (*t1, *g1 GB/s) and on `threads` (*tn, *gn), the two
 * alternated, so that a busy moment of the VM spoils runs of both counts alike. */
static void triad(int threads, double *t1, double *g1, double *tn, double *gn) {
  const size_t len = (size_t)1 << 24; /* 3 x 128 MiB */
  double *a = triad_array(len), *b = triad_array(len), *c = triad_array(len);
  if (!a || !b || !c) {
    fprintf(stderr, "bench_apply: no memory for the triad\n");
    exit(1);
  }
  for (size_t i = 0; i < len; ++i) {
    a[i] = 0.0;
    b[i] = 1.0 + (double)(i & 7);
    c[i] = 2.0;
  }
  double best[2] = {1e300, 1e300};
  const double s = 3.0;
  for (int r = 0; r < 20; ++r) {
    const int k = r & 1;
    const int nt = k ? threads : 1;
    (void)nt;
    const double t0 = bench_now();
#ifdef _OPENMP
#pragma omp parallel for schedule(static) num_threads(nt > 0 ? nt : omp_get_max_threads())
#endif
    for (long i = 0; i < (long)len; ++i) a[i] = b[i] + s * c[i];
    const double t = bench_now() - t0;
    if (t < best[k]) best[k] = t;
  }
  double sum = 0;
  for (size_t i = 0; i < len; i += 4096) sum += a[i];
  if (sum < 0) printf("%g\n", sum); /* keep the loop */
  *t1 = best[0];
  *tn = best[1];
  *g1 = 24.0 * (double)len / best[0] / 1e9;
  *gn = 24.0 * (double)len / best[1] / 1e9;
  free(a);
  free(b);
  free(c);
}

/* One approximant; for each operator the one-thread and the all-thread applies are
 * alternated on it (the context's thread count changed between calls), best of 30 each. */
static void run(int dim, double n_target, int threads, double g1, double gn) {
  int n = 0;
  double *x = bench_lattice(dim, bench_side(dim, n_target), 0.3, &n);
  const double h = 0.5 * bench_radius(dim);
  mfree_context_t *ctx = NULL;
  mfree_context_create(&ctx);
  bench_page_hints(ctx);
  mfree_particles_t *ps = NULL;
  mfree_particles_create(ctx, dim, n, &ps);
  mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, dim, MFREE_BORROW);
  mfree_particles_set_support(ps, &h, 0, MFREE_COPY);
  mfree_approximant_t *a = NULL;
  mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, &a);
  mfree_approximant_set_derivatives(a, MFREE_DERIV_GRADIENT);
  if (mfree_approximant_setup(a) != MFREE_SUCCESS) {
    fprintf(stderr, "setup failed\n");
    exit(1);
  }
  int64_t nnz = 0;
  mfree_approximant_get_nnz(a, &nnz);
  double *u = malloc(sizeof(double) * 3 * (size_t)n), *out = malloc(sizeof(double) * 9 * (size_t)n);
  for (int i = 0; i < 3 * n; ++i) u[i] = x[(size_t)(i / 3) * dim + (i % 3) % dim] * (1 + i % 3);
  for (int nc = 1; nc <= 3; nc += 2) {
    double best[2] = {1e300, 1e300};
    for (int r = 0; r < 60; ++r) { /* best of 30 each: memory-bound, so other jobs' traffic scatters single runs */
      const int k = r & 1;
      mfree_context_set_num_threads(ctx, k ? threads : 1);
      const double t0 = bench_now();
      mfree_approximant_apply(a, MFREE_OP_GRADIENT, nc, u, MFREE_LAYOUT_AOS, nc, out, MFREE_LAYOUT_AOS,
                              (int64_t)nc * dim);
      const double t = bench_now() - t0;
      if (t < best[k]) best[k] = t;
    }
    /* table (dim doubles per entry) + 32-bit columns + row pointers + input + output */
    const double bytes = (double)nnz * (8.0 * dim + 4.0) + 8.0 * (n + 1) + 8.0 * n * nc + 8.0 * n * nc * dim;
    char lb[32];
    for (int k = 0; k < 2; ++k) {
      bench_figure(best[k], "s", "apply %dD %d gradient of %d-vector, %s", dim, n, nc,
                   k ? bench_threads_label(threads, lb, sizeof lb) : "1 thread");
      const double gbs = bytes / best[k] / 1e9;
      printf("%dD n=%8d threads %-3s grad of %d-vector %9.5f s %10.3g p/s %7.2f GB/s = %5.1f %% of triad", dim, n,
             k ? "all" : "1", nc, best[k], n / best[k], gbs, 100.0 * gbs / (k ? gn : g1));
      if (k)
        printf("  speed-up x%.2f (bandwidth ceiling x%.2f: the all-thread triad over this apply's one-thread rate)",
               best[0] / best[1], gn / (bytes / best[0] / 1e9));
      printf("\n");
    }
  }
  free(u);
  free(out);
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
  mfree_context_destroy(&ctx);
  free(x);
}

int main(int argc, char **argv) {
  const double n = argc > 1 ? atof(argv[1]) : 1e5;
  for (int dim = 2; dim <= 3; ++dim) {
    /* the triad of the same minutes as this dimension's applies */
    double t1 = 0, tn = 0, g1 = 0, gn = 0;
    triad(bench_threads(), &t1, &g1, &tn, &gn);
    printf("STREAM-style triad, 2^24 doubles: 1 thread %.4f s %.2f GB/s; all threads %.4f s %.2f GB/s "
           "(x%.2f: a bandwidth-bound apply cannot gain more from threads)\n",
           t1, g1, tn, gn, t1 / tn);
    char lb[32];
    bench_figure(t1, "s", "reference triad before %dD, 1 thread", dim);
    bench_figure(tn, "s", "reference triad before %dD, %s", dim, bench_threads_label(bench_threads(), lb, sizeof lb));
    run(dim, n, bench_threads(), g1, gn);
  }
  return 0;
}
