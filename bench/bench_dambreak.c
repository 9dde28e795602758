/* One full step of the Galerkin-SPH dam break of paper 003 through the public system API
 * (mfree_system_integrate, leap-frog, CFL 0.25): state checks, MLS shape functions
 * rebuilt every step at all particles (on Verlet candidate lists, which the first steps
 * from rest do not need to rebuild), forces, wall forces, kinematics, update. The column is nx x 2nx
 * particles (default nx = 112: 25,088 particles, close to PySPH's 25,153-particle WCSPH
 * dam break, the peer of BENCHMARKS.md's dam-break row). Usage: bench_dambreak [nx] [steps] [threads]: without
 * a thread count, one thread and then all. */
#include "bench_util.h"

#include <mfree.h>

static int stop_after(void *user, int64_t step, double t, double dt) {
  (void)t;
  (void)dt;
  return step >= *(const int64_t *)user;
}

static double run(int nx, int64_t steps, int threads, int *n_out) {
  const double a = 0.05715, rho0 = 1000.0, gam = 7.0, grav = 9.81, H = 2.0 * a, L = 5.0 * a;
  const double d = a / nx, h = 1.5 * d, kappa = 100.0 * rho0 * 2.0 * grav * H / gam;
  const int nz = 2 * nx, n = nx * nz;
  double *y = calloc(5 * (size_t)n, sizeof *y), *m = malloc((size_t)n * sizeof *m);
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nx; ++i) {
      const int q = j * nx + i;
      const double z = (j + 0.5) * d;
      y[2 * q] = (i + 0.5) * d;
      y[2 * q + 1] = z;
      y[4 * (size_t)n + q] = rho0 * pow(1.0 + rho0 * grav * (H - z) / kappa, 1.0 / gam);
      m[q] = y[4 * (size_t)n + q] * d * d;
    }
  const double off = 0.5 * d, ws = d / 3.0, top = 1.5 * H;
  const int nb = (int)ceil((L + 2 * off) / ws) + 1, ns = (int)ceil((top + off) / ws), nw = nb + 2 * ns;
  double *wx = malloc(2 * (size_t)nw * sizeof *wx), *wn = malloc(2 * (size_t)nw * sizeof *wn);
  int k = 0;
  for (int q = 0; q < nb; ++q, ++k) {
    wx[2 * k] = -off + q * (L + 2 * off) / (nb - 1);
    wx[2 * k + 1] = -off;
    wn[2 * k] = 0.0;
    wn[2 * k + 1] = 1.0;
  }
  for (int q = 1; q <= ns; ++q)
    for (int side = 0; side < 2; ++side, ++k) {
      wx[2 * k] = side ? L + off : -off;
      wx[2 * k + 1] = -off + q * (top + off) / ns;
      wn[2 * k] = side ? -1.0 : 1.0;
      wn[2 * k + 1] = 0.0;
    }
  mfree_context_t *ctx = NULL;
  mfree_system_t *sys = NULL;
  mfree_context_create(&ctx);
  bench_page_hints(ctx);
  mfree_context_set_num_threads(ctx, threads);
  mfree_system_create_fluid(ctx, 2, n, &sys);
  mfree_system_set_fluid(sys, &rho0, 0, kappa, gam, 1e-3);
  mfree_system_set_masses(sys, m, 1);
  mfree_system_set_smoothing(sys, h);
  const double g[2] = {0.0, -grav};
  mfree_system_set_gravity(sys, g);
  mfree_system_set_walls(sys, nw, wx, wn, 0.7 * h, 10.0);
  const double lo[2] = {-off, -off}, hi[2] = {L + off, 10.0 * H};
  mfree_system_set_box(sys, lo, hi);
  double t = 0.0;
  int64_t done = 0, one = 1;
  /* one warm-up step (first setup allocates), then the timed ones */
  mfree_system_integrate(sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, 1.0, 0.25, 0.0, stop_after, &one, &done);
  const double t0 = bench_now();
  const mfree_status_t st =
      mfree_system_integrate(sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, 1.0, 0.25, 0.0, stop_after, &steps, &done);
  const double el = bench_now() - t0;
  if (st != MFREE_SUCCESS || done != steps) {
    char msg[512];
    mfree_context_get_last_error(ctx, NULL, msg, sizeof msg);
    fprintf(stderr, "integrate failed after %lld steps: %s\n", (long long)done, msg);
    exit(1);
  }
  mfree_system_destroy(&sys);
  mfree_context_destroy(&ctx);
  free(y);
  free(m);
  free(wx);
  free(wn);
  *n_out = n;
  return el / (double)steps;
}

int main(int argc, char **argv) {
  const int nx = argc > 1 ? atoi(argv[1]) : 112;
  const int64_t steps = argc > 2 ? atoll(argv[2]) : 20;
  int n = 0;
  const double pysph = 21e-3 / 25153.0; /* seconds per particle-step */
  const int only = argc > 3 ? atoi(argv[3]) : 0;
  for (int pass = only > 0 ? 1 : 0; pass < 2; ++pass) {
    const int threads = only > 0 ? only : pass == 0 ? 1 : bench_threads();
    const double ts = run(nx, steps, threads, &n);
    char label[16];
    snprintf(label, sizeof label, threads > 0 ? "%d" : "all", threads);
    printf("dam break, %d particles, threads %-3s: %8.3f ms per step, %9.3g particle-steps/s, "
           "%.2fx PySPH WCSPH (target >= 2 on 1 thread)\n",
           n, label, 1e3 * ts, n / ts, pysph * n / ts);
    char lb[32];
    bench_figure(ts, "s", "dambreak %d step, %s", n, pass == 0 || only == 1 ? "1 thread" : bench_threads_label(threads, lb, sizeof lb));
  }
  return 0;
}
