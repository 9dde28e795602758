/* The per-step cost of a pair-list host (mfree_particles_set_pairs): set-up from a half
 * pair list plus the per-pair gradients (mfree_approximant_get_pair_gradients) for SPH,
 * Randles-Libersky, KB Method 1, MLS 1 and the antisymmetrised RL, against a plain C
 * loop that computes the cubic spline's dwdx for the same pairs (the host's own,
 * uncorrected cost), measured in the same run, alternately (reference, method,
 * reference, ...), best of the repeats. 10^5 particles (argument 1) on a jittered
 * lattice in 2D and 3D, about 21 / 57 neighbours per particle, h_ij = (h_i + h_j) / 2;
 * one thread and all threads (the reference loop then runs on all threads too).
 *
 *   bench_pairs [n] [repeats]      (defaults 1e5, 7)
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <mfree.h>

#include "bench_util.h"

#ifdef _OPENMP
#include <omp.h>
#endif

#define CHECK(call)                                                                  \
  do {                                                                               \
    mfree_status_t st_ = (call);                                                     \
    if (st_ != MFREE_SUCCESS) {                                                      \
      char m_[512] = "";                                                             \
      mfree_context_get_last_error(ctx, NULL, m_, sizeof m_);                        \
      fprintf(stderr, "%s:%d: %s: %s\n", __FILE__, __LINE__, #call, m_);             \
      exit(1);                                                                       \
    }                                                                                \
  } while (0)

/* The host's loop: dwdx(:, k) = grad_i W(x_i - x_j, h_ij), cubic spline. */
static double sink = 0.0;
static void host_dwdx(int dim, const double *x, const double *h, int64_t np, const int32_t *pi,
                      const int32_t *pj, double *dwdx, int threads) {
  const double pi_ = 3.14159265358979323846;
  const double cn = dim == 2 ? 10.0 / (7.0 * pi_) : 1.0 / pi_;
  (void)threads;
#ifdef _OPENMP
#pragma omp parallel for schedule(static) num_threads(threads > 0 ? threads : omp_get_num_procs())
#endif
  for (int64_t k = 0; k < np; ++k) {
    const int32_t i = pi[k], j = pj[k];
    double d[3] = {0, 0, 0}, r2 = 0.0;
    for (int c = 0; c < dim; ++c) {
      d[c] = x[dim * i + c] - x[dim * j + c];
      r2 += d[c] * d[c];
    }
    const double r = sqrt(r2), hij = 0.5 * (h[i] + h[j]), ih = 1.0 / hij, q = r * ih;
    double df = 0.0;
    if (q < 1.0) df = -3.0 * q + 2.25 * q * q;
    else if (q < 2.0) df = -0.75 * (2.0 - q) * (2.0 - q);
    double s = cn * ih * ih * (dim == 3 ? ih : 1.0) * ih * df;
    s = r > 0.0 ? s / r : 0.0;
    for (int c = 0; c < dim; ++c) dwdx[dim * k + c] = s * d[c];
  }
  sink += dwdx[0];
}

static void run(int dim, double ntarget, int reps) {
  const int m = bench_side(dim, ntarget);
  int n = 0;
  double *x = bench_lattice(dim, m, 0.3, &n);
  const double radius = bench_radius(dim), h0 = radius / 2.0;
  double *h = malloc(sizeof(double) * n), *mass = malloc(sizeof(double) * n);
  double *rho = malloc(sizeof(double) * n);
  bench_pair_supports(n, h0, h);
  for (int i = 0; i < n; ++i) {
    rho[i] = 1000.0;
    mass[i] = 1000.0;
  }
  mfree_context_t *ctx = NULL;
  CHECK(mfree_context_create(&ctx));
  bench_page_hints(ctx);
  int32_t *pi = NULL, *pj = NULL;
  const int64_t np = bench_half_pairs(ctx, dim, n, x, h, &pi, &pj);
  if (np < 0) exit(1);
  double *dwdx = malloc(sizeof(double) * dim * np);
  double *gi = malloc(sizeof(double) * dim * np), *gj = malloc(sizeof(double) * dim * np);
  printf("%dD: %d particles, %lld pairs (%.1f neighbours each)\n", dim, n, (long long)np,
         2.0 * (double)np / n);
  printf("  %-12s %7s %10s %10s %8s   %s\n", "method", "threads", "mfree ms", "host ms", "ratio",
         "(rows, tables, pair gradients ms)");

  const char *names[] = {"SPH", "RL", "KB1", "MLS1", "RL antisym"};
  const int methods[] = {MFREE_METHOD_SPH, MFREE_METHOD_RANDLES_LIBERSKY, MFREE_METHOD_KB_METHOD1,
                         MFREE_METHOD_MLS, MFREE_METHOD_RANDLES_LIBERSKY};
  const int nthreads[2] = {1, bench_threads()};
  for (int t = 0; t < 2; ++t) {
    CHECK(mfree_context_set_num_threads(ctx, nthreads[t]));
    int32_t used = 1;
    CHECK(mfree_context_get_num_threads(ctx, &used));
#ifdef _OPENMP
    const int shown = nthreads[t] > 0 ? nthreads[t] : omp_get_num_procs();
#else
    const int shown = 1;
#endif
    for (int q = 0; q < 5; ++q) {
      mfree_particles_t *ps = NULL;
      mfree_approximant_t *a = NULL;
      CHECK(bench_pair_set(ctx, dim, n, x, h, mass, rho, (mfree_method_t)methods[q], &ps, &a));
      double best_m = 1e30, best_h = 1e30, part[3] = {0, 0, 0};
      for (int r = 0; r < reps; ++r) {
        double t0 = bench_now();
        host_dwdx(dim, x, h, np, pi, pj, dwdx, nthreads[t]);
        double t1 = bench_now();
        if (t1 - t0 < best_h) best_h = t1 - t0;
        /* the per-step path: the new pair list, rows, tables, pair gradients */
        t0 = bench_now();
        CHECK(mfree_particles_set_pairs(ps, np, pi, pj, 0, MFREE_BORROW));
        CHECK(mfree_particles_setup(ps));
        const double ta = bench_now();
        CHECK(mfree_approximant_setup(a));
        const double tb = bench_now();
        if (q == 4) CHECK(mfree_approximant_get_pair_gradients_antisymmetric(a, gi, dim, dim * np));
        else CHECK(mfree_approximant_get_pair_gradients(a, gi, gj, dim, dim * np));
        t1 = bench_now();
        if (t1 - t0 < best_m) {
          best_m = t1 - t0;
          part[0] = ta - t0;
          part[1] = tb - ta;
          part[2] = t1 - tb;
        }
      }
      printf("  %-12s %7d %10.2f %10.2f %8.2f   %6.2f %6.2f %6.2f\n", names[q], shown, 1e3 * best_m,
             1e3 * best_h, best_m / best_h, 1e3 * part[0], 1e3 * part[1], 1e3 * part[2]);
      char lb[32];
      const char *tl = t ? bench_threads_label(nthreads[t], lb, sizeof lb) : "1 thread";
      bench_figure(best_m, "s", "pairs %dD %d %s step, %s", dim, n, names[q], tl);
      bench_figure(best_h, "s", "reference pairs %dD %d host dwdx loop (with %s), %s", dim, n, names[q], tl);
      fflush(stdout);
      mfree_approximant_destroy(&a);
      mfree_particles_destroy(&ps);
    }
  }
  mfree_context_destroy(&ctx);
  free(x);
  free(h);
  free(mass);
  free(rho);
  free(pi);
  free(pj);
  free(dwdx);
  free(gi);
  free(gj);
}

int main(int argc, char **argv) {
  const double n = argc > 1 ? atof(argv[1]) : 1e5;
  const int reps = argc > 2 ? atoi(argv[2]) : 7;
  run(2, n, reps);
  run(3, n, reps);
  printf("(best of %d alternating repeats; sink %g)\n", reps, sink);
  return 0;
}
