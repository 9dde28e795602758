/* Shape-function setup per method (SPH, Randles-Libersky, Krongauz-Belytschko Method 1,
 * MLS order 1 and 2, SSPH order 2) on jittered lattices with ~21 (2D) / ~57 (3D)
 * neighbours: value + gradient tables built by mfree_approximant_setup (pattern and
 * tables) and rebuilt by mfree_approximant_update (tables only, the per-step cost of a
 * moving-particle code), serial and on all cores. Reference: Compadre 1.7.5 GMLS
 * gradient weights at 100,489 points (BENCHMARKS.md gives its figures beside ours).
 * The like-for-like rows (2D) build the gradient
 * table only, as Compadre's figure does. Also the bytes per particle held by the set-up
 * approximant, counted through the context's allocator hook.
 * MFREE_BENCH_ALL_METHODS=1 adds every method's one-thread setup relative to SPH;
 * MFREE_BENCH_REPS sets the timed repetitions (default 5, 1 above 2e5 particles).
 * Usage: bench_shape [n ...]  (default 100000). */
#include "bench_util.h"

#include <mfree.h>

typedef struct {
  const char *name;
  mfree_method_t method;
  int order;
  double compadre; /* seconds per 100,489 points, or 0 */
} method_t;

static const method_t kMethods[] = {
    {"SPH", MFREE_METHOD_SPH, 0, 0.0},
    {"Randles-Libersky", MFREE_METHOD_RANDLES_LIBERSKY, 0, 0.0},
    {"KB Method 1", MFREE_METHOD_KB_METHOD1, 0, 0.0},
    {"MLS order 1", MFREE_METHOD_MLS, 1, 0.33},
    {"MLS order 2", MFREE_METHOD_MLS, 2, 0.65},
    {"SSPH order 2", MFREE_METHOD_SSPH, 2, 0.0},
};

/* Every method at its default order (and the orders the guide's table names), for the
 * cost of each relative to plain SPH in the same run: MFREE_BENCH_ALL_METHODS=1. */
static const method_t kEvery[] = {
    {"SPH", MFREE_METHOD_SPH, 0, 0.0},
    {"SPH symmetrised", MFREE_METHOD_SPH_SYMMETRIC, 0, 0.0},
    {"Shepard", MFREE_METHOD_SHEPARD, 0, 0.0},
    {"Randles-Libersky", MFREE_METHOD_RANDLES_LIBERSKY, 0, 0.0},
    {"Johnson-Beissel", MFREE_METHOD_JOHNSON_BEISSEL, 0, 0.0},
    {"KB Method 1", MFREE_METHOD_KB_METHOD1, 0, 0.0},
    {"KB Method 2", MFREE_METHOD_KB_METHOD2, 1, 0.0},
    {"KB Method 3", MFREE_METHOD_KB_METHOD3, 0, 0.0},
    {"MLS order 1", MFREE_METHOD_MLS, 1, 0.0},
    {"MLS order 2", MFREE_METHOD_MLS, 2, 0.0},
    {"RKPM order 1", MFREE_METHOD_RKPM, 1, 0.0},
    {"RKPM order 2", MFREE_METHOD_RKPM, 2, 0.0},
    {"MSPH order 1", MFREE_METHOD_MSPH, 1, 0.0},
    {"MSPH order 2", MFREE_METHOD_MSPH, 2, 0.0},
    {"SSPH order 1", MFREE_METHOD_SSPH, 1, 0.0},
    {"SSPH order 2", MFREE_METHOD_SSPH, 2, 0.0},
};

/* Counting allocator installed on the context: bytes currently held. */
typedef struct {
  int64_t held, peak, calls;
} counter_t;

static void *count_alloc(void *user, int64_t bytes) {
  counter_t *c = (counter_t *)user;
  c->held += bytes;
  if (c->held > c->peak) c->peak = c->held;
  ++c->calls;
  return malloc((size_t)bytes);
}
static void count_free(void *user, void *p, int64_t bytes) {
  counter_t *c = (counter_t *)user;
  c->held -= bytes;
  free(p);
}

static void check(mfree_context_t *ctx, mfree_status_t st, const char *what) {
  if (st == MFREE_SUCCESS) return;
  char msg[512];
  mfree_context_get_last_error(ctx, NULL, msg, sizeof msg);
  fprintf(stderr, "%s failed (%d): %s\n", what, (int)st, msg);
  exit(1);
}

/* Best setup and best update on one thread (t_setup[0], t_update[0]) and on `threads`
 * ([1]), the two alternated on the same approximant (the context's thread count changed
 * between calls), so that a moment in which another job holds a core spoils runs of both
 * counts alike, not the whole of one; the speed-up is best over best. The first setup
 * (allocating the tables) is not timed. Bytes held by the approximant after setup. */
static void time_method(int dim, int n, const double *x, double h, const method_t *m, int flags,
                        int threads, double *t_setup, double *t_update, double *bytes) {
  counter_t cnt = {0, 0, 0};
  mfree_context_t *ctx = NULL;
  mfree_context_create(&ctx);
  bench_page_hints(ctx);
  mfree_particles_t *ps = NULL;
  const double vol = 1.0;
  check(ctx, mfree_particles_create(ctx, dim, n, &ps), "particles_create");
  mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, dim, MFREE_BORROW);
  mfree_particles_set_support(ps, &h, 0, MFREE_COPY);
  mfree_particles_set_volumes(ps, &vol, 0, MFREE_COPY);
  check(ctx, mfree_particles_setup(ps), "particles_setup");
  /* bytes: an approximant set up under the counting hook, then destroyed */
  check(ctx, mfree_context_set_allocator(ctx, count_alloc, count_free, &cnt), "set_allocator");
  mfree_approximant_t *a = NULL;
  const int64_t before = cnt.held;
  check(ctx, mfree_approximant_create(ctx, ps, m->method, &a), "approximant_create");
  if (m->order) check(ctx, mfree_approximant_set_order(a, m->order), "set_order");
  check(ctx, mfree_approximant_set_derivatives(a, flags), "set_derivatives");
  check(ctx, mfree_approximant_setup(a), "approximant_setup");
  *bytes = (double)(cnt.held - before) / n;
  mfree_approximant_destroy(&a);
  /* times: a second one on the default allocator (what a host gets without a hook: huge
   * pages for the big tables where the system has them), its first setup untimed */
  check(ctx, mfree_context_set_allocator(ctx, NULL, NULL, NULL), "set_allocator");
  check(ctx, mfree_approximant_create(ctx, ps, m->method, &a), "approximant_create");
  if (m->order) check(ctx, mfree_approximant_set_order(a, m->order), "set_order");
  check(ctx, mfree_approximant_set_derivatives(a, flags), "set_derivatives");
  check(ctx, mfree_approximant_setup(a), "approximant_setup");
  const int reps = bench_reps(n <= 200000 ? 5 : 1);
  t_setup[0] = t_setup[1] = t_update[0] = t_update[1] = 1e300;
  for (int r = 0; r < 2 * reps; ++r) {
    const int k = r & 1;
    mfree_context_set_num_threads(ctx, k ? threads : 1);
    double t0 = bench_now();
    check(ctx, mfree_approximant_setup(a), "approximant_setup");
    double t = bench_now() - t0;
    if (t < t_setup[k]) t_setup[k] = t;
    t0 = bench_now();
    check(ctx, mfree_approximant_update(a), "approximant_update");
    t = bench_now() - t0;
    if (t < t_update[k]) t_update[k] = t;
  }
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
  mfree_context_destroy(&ctx);
}

static void run(int dim, double n_target) {
  int n = 0;
  double *x = bench_lattice(dim, bench_side(dim, n_target), 0.3, &n);
  const double h = 0.5 * bench_radius(dim);
  const int vg = MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT;
  printf("\n%dD, %d particles, ~%d neighbours, value + gradient tables\n", dim, n, dim == 2 ? 21 : 57);
  printf("%-18s %10s %10s %10s %10s %10s %10s %8s %9s\n", "method", "setup s", "p/s", "update s",
         "p/s", "pattern s", "all thr s", "speedup", "B/part");
  double t_mls1 = 0, t_cheap[2] = {0, 0};
  char lb[32];
  const char *tl = bench_threads_label(bench_threads(), lb, sizeof lb);
  for (size_t k = 0; k < sizeof kMethods / sizeof kMethods[0]; ++k) {
    const method_t *m = &kMethods[k];
    double tsv[2], tuv[2], bytes;
    time_method(dim, n, x, h, m, vg, bench_threads(), tsv, tuv, &bytes);
    const double ts = tsv[0], tu = tuv[0], tsn = tsv[1];
    if (m->method == MFREE_METHOD_MLS && m->order == 1) t_mls1 = ts;
    if (m->method == MFREE_METHOD_RANDLES_LIBERSKY) t_cheap[0] = ts;
    if (m->method == MFREE_METHOD_KB_METHOD1) t_cheap[1] = ts;
    printf("%-18s %10.4f %10.3g %10.4f %10.3g %10.4f %10.4f %8.2f %9.0f\n", m->name, ts, n / ts, tu,
           n / tu, ts - tu, tsn, ts / tsn, bytes);
    bench_figure(ts, "s", "shape %dD %d %s setup, 1 thread", dim, n, m->name);
    bench_figure(tu, "s", "shape %dD %d %s update, 1 thread", dim, n, m->name);
    bench_figure(tsn, "s", "shape %dD %d %s setup, %s", dim, n, m->name, tl);
    bench_figure(tuv[1], "s", "shape %dD %d %s update, %s", dim, n, m->name, tl);
    bench_figure(bytes, "B/particle", "shape %dD %d %s memory", dim, n, m->name);
  }
  printf("setup MLS order 1 / Randles-Libersky %.2f, / KB Method 1 %.2f (paper 000 Table IV: >= 2.4)\n",
         t_mls1 / t_cheap[0], t_mls1 / t_cheap[1]);
  const char *every = getenv("MFREE_BENCH_ALL_METHODS");
  if (every && atoi(every)) {
    printf("every method, one thread, value + gradient setup relative to SPH in this run\n");
    printf("%-18s %10s %10s %9s\n", "method", "setup s", "update s", "x SPH");
    double t_sph = 0;
    for (size_t k = 0; k < sizeof kEvery / sizeof kEvery[0]; ++k) {
      double tsv[2], tuv[2], bytes;
      time_method(dim, n, x, h, &kEvery[k], vg, 1, tsv, tuv, &bytes);
      if (k == 0) t_sph = tsv[0];
      printf("%-18s %10.4f %10.4f %9.2f\n", kEvery[k].name, tsv[0], tuv[0], tsv[0] / t_sph);
      bench_figure(tsv[0], "s", "shape %dD %d every method: %s setup, 1 thread", dim, n, kEvery[k].name);
      bench_figure(tuv[0], "s", "shape %dD %d every method: %s update, 1 thread", dim, n, kEvery[k].name);
    }
  }
  if (dim == 2) {
    /* Like for like with Compadre's figure: GMLS gradient weights only (no value table)
     * at points whose neighbour lists are given (the search is not timed, here as there):
     * setup = pattern (rows of the particle set's lists within the support) + tables,
     * update = tables only. */
    printf("like for like with Compadre 1.7.5 (gradient table only; Compadre scaled to %d points)\n", n);
    printf("%-18s %10s %10s %10s %10s %12s %12s\n", "method", "setup s", "update s", "all thr s",
           "speedup", "vs Compadre", "(tables)");
    for (size_t k = 0; k < sizeof kMethods / sizeof kMethods[0]; ++k) {
      const method_t *m = &kMethods[k];
      if (m->compadre <= 0) continue;
      double tsv[2], tuv[2], bytes;
      time_method(dim, n, x, h, m, MFREE_DERIV_GRADIENT, bench_threads(), tsv, tuv, &bytes);
      const double ts = tsv[0], tu = tuv[0], tsn = tsv[1];
      const double ref = m->compadre * (n / 100489.0);
      printf("%-18s %10.4f %10.4f %10.4f %10.2f %11.1fx %11.1fx\n", m->name, ts, tu, tsn, ts / tsn,
             ref / ts, ref / tu);
      bench_figure(ts, "s", "shape %dD %d %s gradient only setup, 1 thread", dim, n, m->name);
      bench_figure(tu, "s", "shape %dD %d %s gradient only update, 1 thread", dim, n, m->name);
      bench_figure(tsn, "s", "shape %dD %d %s gradient only setup, %s", dim, n, m->name, tl);
    }
  }
  free(x);
}

int main(int argc, char **argv) {
  int ran = 0;
  for (int a = 1; a < argc; ++a, ran = 1) {
    run(2, atof(argv[a]));
    run(3, atof(argv[a]));
  }
  if (!ran) {
    run(2, 100489);
    run(3, 1e5);
  }
  printf("\npattern = setup - update; vs Compadre: Compadre's time scaled to the same particle "
         "count / mfree setup time (target >= 10), (tables): / update time\n");
  return 0;
}
