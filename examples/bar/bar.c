/* Wave in a bar (paper 001, Zhang & Batra 2009, Sect. 6.4, Fig. 16) by SSPH collocation
 * and central differences: a steel bar (E = 200 GPa, rho = 7865 kg/m3, L = 0.1 m) at
 * rest, a compressive traction of 1 GPa on its right end for 3 us, its left end free.
 * The pulse runs left at c = sqrt(E / rho) = 5.04 mm/us (the paper's "5 mm/us"), reaches
 * the free end after L / c = 19.8 us and comes back tensile. 800 particles, SSPH of order
 * 2 with the revised super Gauss kernel (a = 1.6), h = 1.5 dx, as the test t703.
 *
 * Output in --out DIR (default bar_out): bar.csv, the stress sigma(x) at t = 6, 12, 18
 * and 30 us, and bar.png (the wave at those times; gnuplot on PATH, not --no-plot).
 * The wave speed is measured from the leftmost particle past half the amplitude at
 * t = 12 us. --json prints {"wave_speed":.. (m/s),"reference":..,"rel_dev":..,
 * "amplitude_GPa":..,"reflected_max_GPa":..,"particles":..,"steps":..}.
 * Usage: mfree_bar [--n N (800)] [--out DIR] [--no-plot] [--json] */
#define _XOPEN_SOURCE 700
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <mfree.h>

#include "util.h"

static const double kL = 0.1, kE = 200e9, kRho = 7865.0, kT0 = 3e-6;
#define NSNAP 4
static const double kSnap[NSNAP] = {6e-6, 12e-6, 18e-6, 30e-6};

static void traction(void *user, const double *x, double *v) {
  (void)user;
  v[0] = x[0] > 0.5 * kL ? -1e9 : 0.0; /* right end compressive, left end free */
}
static double pulse(void *user, double t) {
  (void)user;
  return t <= kT0 ? 1.0 : 0.0;
}

#define CHECK(call)                                                         \
  do {                                                                      \
    const mfree_status_t st_ = (call);                                      \
    if (st_ != MFREE_SUCCESS) return ex_fail(ctx, "mfree_bar", st_, #call); \
  } while (0)

static int run(mfree_context_t *ctx, int n, const char *out, int plot, int json) {
  const double dx = kL / (n - 1), h = 1.5 * dx, vol = dx, c = sqrt(kE / kRho);
  double *x = malloc((size_t)n * sizeof *x), *y = calloc(2 * (size_t)n, sizeof *y);
  double *sig = malloc((size_t)n * NSNAP * sizeof *sig);
  if (!x || !y || !sig) {
    fprintf(stderr, "mfree_bar: out of memory\n");
    return 1;
  }
  for (int i = 0; i < n; ++i) x[i] = i * dx;
  mfree_particles_t *ps = NULL;
  mfree_approximant_t *a = NULL;
  mfree_assembler_t *as = NULL;
  mfree_system_t *sys = NULL;
  CHECK(mfree_particles_create(ctx, 1, n, &ps));
  CHECK(mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 1, MFREE_BORROW));
  CHECK(mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  CHECK(mfree_particles_set_volumes(ps, &vol, 0, MFREE_COPY));
  CHECK(mfree_approximant_create(ctx, ps, MFREE_METHOD_SSPH, &a));
  CHECK(mfree_approximant_set_kernel(a, MFREE_KERNEL_REVISED_SUPER_GAUSS, 1.6));
  CHECK(mfree_approximant_set_order(a, 2));
  CHECK(mfree_approximant_set_derivatives(a, MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT | MFREE_DERIV_HESSIAN));
  CHECK(mfree_assembler_create(ctx, a, NULL, MFREE_FORM_COLLOCATION_LAPLACE, &as));
  CHECK(mfree_assembler_set_coefficient(as, kE)); /* 1D bar: rho u'' = E u'' */
  const int32_t ends[2] = {0, n - 1};
  const double normals[2] = {-1.0, 1.0};
  CHECK(mfree_assembler_add_traction_nodes(as, 2, ends, normals, traction, NULL));
  CHECK(mfree_assembler_setup(as));
  CHECK(mfree_system_create_elastodynamic(ctx, as, kRho, &sys));
  CHECK(mfree_system_set_load_history(sys, pulse, NULL));

  double t = 0.0;
  int64_t steps = 0;
  for (int k = 0; k < NSNAP; ++k) {
    int64_t ns = 0;
    CHECK(mfree_system_integrate(sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, kSnap[k], 0.5, 0.0, NULL, NULL, &ns));
    steps += ns;
    CHECK(mfree_system_get_stress(sys, t, y, sig + (size_t)k * n));
  }
  /* wave speed at t = 12 us: the leftmost particle past half the amplitude */
  const double *s12 = sig + (size_t)1 * n;
  int front = -1;
  for (int i = 0; i < n && front < 0; ++i)
    if (s12[i] < -0.5e9) front = i;
  const double speed = front > 0 ? (kL - x[front]) / kSnap[1] : NAN;
  /* amplitude: mean on the plateau behind the front at 12 us, 3 mm from both fronts */
  double sum = 0.0, smax = -1e300;
  int cnt = 0;
  for (int i = 0; i < n; ++i)
    if (x[i] > kL - c * kSnap[1] + 3e-3 && x[i] < kL - c * (kSnap[1] - kT0) - 3e-3) {
      sum += s12[i];
      ++cnt;
    }
  for (int i = 0; i < n; ++i) smax = fmax(smax, sig[(size_t)3 * n + i]);
  const double amp = cnt ? -sum / cnt : NAN;

  char csv[4200], gp[4200], png[4200];
  ex_join(csv, sizeof csv, out, "bar.csv");
  ex_join(gp, sizeof gp, out, "bar.gp");
  ex_join(png, sizeof png, out, "bar.png");
  FILE *f = fopen(csv, "w");
  if (!f) {
    fprintf(stderr, "mfree_bar: cannot write %s\n", csv);
    return 1;
  }
  fprintf(f, "# paper 001 Sect. 6.4: stress in the bar (GPa) at t = 6, 12, 18, 30 us\nx_mm");
  for (int k = 0; k < NSNAP; ++k) fprintf(f, ",sigma_%gus", kSnap[k] * 1e6);
  fprintf(f, "\n");
  for (int i = 0; i < n; ++i) {
    fprintf(f, "%.5f", x[i] * 1e3);
    for (int k = 0; k < NSNAP; ++k) fprintf(f, ",%.6f", sig[(size_t)k * n + i] * 1e-9);
    fprintf(f, "\n");
  }
  fclose(f);
  if (plot && ex_plot_path_ok(csv) && (f = fopen(gp, "w"))) {
    fprintf(f, "set terminal pngcairo size 900,500\nset output '%s'\nset datafile separator ','\n"
               "set title 'Wave in a bar, SSPH collocation (Zhang and Batra 2009, Sect. 6.4): c = %.3f mm/us'\n"
               "set xlabel 'x (mm)'\nset ylabel 'stress (GPa)'\nset key bottom right\nset grid\n"
               "set yrange [-1.6:1.6]\nplot",
            png, speed * 1e-3);
    for (int k = 0; k < NSNAP; ++k)
      fprintf(f, "%s '%s' every ::1 using 1:%d with lines lw 2 title 't = %g us%s'", k ? "," : "", csv, k + 2,
              kSnap[k] * 1e6, k == NSNAP - 1 ? " (reflected)" : "");
    fprintf(f, "\n");
    fclose(f);
    ex_plot(gp, png, csv, json ? stderr : stdout);
  }
  if (json) {
    printf("{\"wave_speed\":%.3f,\"reference\":%.3f,\"rel_dev\":%.5f,\"amplitude_GPa\":%.5f,"
           "\"reflected_max_GPa\":%.5f,\"particles\":%d,\"steps\":%lld}\n",
           speed, c, (speed - c) / c, amp * 1e-9, smax * 1e-9, n, (long long)steps);
  } else {
    printf("bar: %d particles, %lld steps to t = %g us\n", n, (long long)steps, t * 1e6);
    printf("wave speed %.4f mm/us (sqrt(E/rho) = %.4f, %+.2f %%); pulse amplitude %.4f GPa (1 GPa);\n"
           "after the reflection at the free end the peak is %+.4f GPa (tensile)\n",
           speed * 1e-3, c * 1e-3, 100.0 * (speed - c) / c, amp * 1e-9, smax * 1e-9);
    printf("stress profiles: %s\n", csv);
  }
  mfree_system_destroy(&sys);
  mfree_assembler_destroy(&as);
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
  free(x);
  free(y);
  free(sig);
  return 0;
}

int main(int argc, char **argv) {
  int n = 800, plot = 1, json = 0;
  const char *out = "bar_out";
  for (int i = 1; i < argc; ++i) {
    const char *s = argv[i];
    if (!strcmp(s, "--json")) json = 1;
    else if (!strcmp(s, "--no-plot")) plot = 0;
    else if (!strcmp(s, "--n") && i + 1 < argc) n = atoi(argv[++i]);
    else if (!strcmp(s, "--out") && i + 1 < argc) out = argv[++i];
    else if (!strcmp(s, "--help")) {
      printf("usage: mfree_bar [--n N (800)] [--out DIR (bar_out)] [--no-plot] [--json]\n");
      return 0;
    } else {
      fprintf(stderr, "usage: mfree_bar [--n N (800)] [--out DIR (bar_out)] [--no-plot] [--json]\n");
      return 2;
    }
  }
  if (n < 100) {
    fprintf(stderr, "mfree_bar: --n must be at least 100\n");
    return 2;
  }
  if (mkdir(out, 0777) != 0 && access(out, W_OK) != 0) {
    fprintf(stderr, "mfree_bar: cannot write in %s\n", out);
    return 1;
  }
  mfree_context_t *ctx = NULL;
  if (mfree_context_create(&ctx) != MFREE_SUCCESS) return 1;
  const int rc = run(ctx, n, out, plot, json);
  mfree_context_destroy(&ctx);
  return rc;
}
