/* Paper 000 Table IV: speed-up of the corrected-derivative formulation (Krongauz-
 * Belytschko Method 1) over MLS when building shape functions and their derivatives,
 * for domain-size multipliers d_m = 1.5, 2.5, 3.5 (support radius d_m * dx; cubic
 * spline, so h = d_m dx / 2). The paper reports 3.06, 3.12 and 2.43. Prints particles
 * per second for both and the ratio (one thread; best of 3 setups, each pattern +
 * tables; MFREE_BENCH_REPS changes the 3). Usage: bench_table4 [particles-per-side, 300]. */
#include "bench_util.h"

#include <mfree.h>

/* wall clock, or process CPU time with MFREE_BENCH_CLOCK=cpu (bench_util.h) */
static double now(void) { return bench_now(); }

static double time_setup(mfree_context_t *ctx, mfree_particles_t *ps, mfree_method_t m, int reps) {
  mfree_approximant_t *a = NULL;
  mfree_approximant_create(ctx, ps, m, &a);
  mfree_approximant_set_derivatives(a, MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT);
  double best = 1e300;
  for (int r = 0; r < reps; ++r) {
    const double t0 = now();
    if (mfree_approximant_setup(a) != MFREE_SUCCESS) {
      char msg[256];
      mfree_context_get_last_error(ctx, NULL, msg, sizeof msg);
      fprintf(stderr, "setup failed: %s\n", msg);
      exit(1);
    }
    const double t = now() - t0;
    if (t < best) best = t;
  }
  mfree_approximant_destroy(&a);
  return best;
}

int main(int argc, char **argv) {
  const int m = argc > 1 ? atoi(argv[1]) : 300;
  if (m < 4) return 2;
  const int n = m * m;
  const double dx = 1.0 / m;
  double *x = malloc(sizeof(double) * 2 * (size_t)n);
  srand(4);
  for (int p = 0; p < n; ++p) {
    x[2 * p] = (p % m + 0.5 + 0.2 * (2.0 * rand() / RAND_MAX - 1)) * dx;
    x[2 * p + 1] = (p / m + 0.5 + 0.2 * (2.0 * rand() / RAND_MAX - 1)) * dx;
  }
  const double vol = dx * dx, dms[3] = {1.5, 2.5, 3.5}, paper[3] = {3.06, 3.12, 2.43};
  mfree_context_t *ctx = NULL;
  mfree_context_create(&ctx);
  bench_page_hints(ctx);
  mfree_context_set_num_threads(ctx, 1);
  printf("paper 000 Table IV: Method 1 vs MLS (order 1) shape functions + gradients, %d particles\n", n);
  printf("%5s %14s %14s %10s %10s\n", "d_m", "Method1 p/s", "MLS p/s", "speed-up", "paper");
  for (int k = 0; k < 3; ++k) {
    const double h = 0.5 * dms[k] * dx;
    mfree_particles_t *ps = NULL;
    mfree_particles_create(ctx, 2, n, &ps);
    mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 2, MFREE_BORROW);
    mfree_particles_set_support(ps, &h, 0, MFREE_COPY);
    mfree_particles_set_volumes(ps, &vol, 0, MFREE_COPY);
    mfree_particles_setup(ps);
    const double t1 = time_setup(ctx, ps, MFREE_METHOD_KB_METHOD1, bench_reps(3));
    const double t2 = time_setup(ctx, ps, MFREE_METHOD_MLS, bench_reps(3));
    printf("%5.1f %14.3g %14.3g %10.2f %10.2f\n", dms[k], n / t1, n / t2, t2 / t1, paper[k]);
    bench_figure(t1, "s", "table4 %d d_m=%.1f KB Method 1 setup, 1 thread", n, dms[k]);
    bench_figure(t2, "s", "table4 %d d_m=%.1f MLS order 1 setup, 1 thread", n, dms[k]);
    mfree_particles_destroy(&ps);
  }
  mfree_context_destroy(&ctx);
  free(x);
  return 0;
}
