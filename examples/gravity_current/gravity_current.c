/* Gravity current / lock exchange (paper 003 Sect. 7.3, Figs. 10-11; spec 003 section
 * 3.3) by the Galerkin-SPH fluid of paper 003 with two fluids.
 *
 * Set-up. A tank of depth D = 0.06 m holds fluid 1 (rho0 = 1000 kg/m3) on the left over a
 * length --light (default 0.12 m = 2 D) and fluid 2 (rho0 = 1500 kg/m3) on the right over
 * 0.06 m (the paper's Fig. 10 labels "0.06 m", "0.06 m"), both filled to D. The lock
 * between them is gone at t = 0 and fluid 2 runs under fluid 1. --nz particles over the
 * depth (default 34: 3468 particles, near the paper's 5100), h = 1.5 d, MLS linear,
 * nodal integration, Galerkin lumped mass, leap-frog with CFL --cfl (default 0.25: at 0.5
 * the run stops at t ~ 0.2 s with a negative density where the free surface over the
 * draining heavy fluid sloshes against the right wall), wall particles at d/3
 * set back by d/2, r0 = 0.7 h, A = 10. Per-particle rest densities (mfree_system_set_fluid
 * with stride 1) and hydrostatic initial densities in each compartment (003 eq 65). The
 * paper gives neither kappa nor mu for this example: kappa = 100 rho2 (2 g D) / gamma
 * (eq 125 with the heavier fluid, so both stay within 1 % of their rest densities), and
 * mu = --mu (default 0.01 Pa s; with the 0.5 of the other examples the current's Reynolds
 * number U D / nu would be ~24 and viscosity would slow the head).
 *
 * Head speed. The head is the leftmost particle of fluid 2; its position is recorded
 * every 0.005 s and the speed is the least-squares slope of x_head(t) while the head
 * has travelled between D/2 (after the start-up acceleration) and L1 - D (one depth
 * before the far wall, which then blocks the light fluid's return flow and slows the
 * head: at nz = 12 the slope over [D/4, L1 - D/2] is 0.177 m/s, over [D/2, L1 - D]
 * 0.219 m/s), compared with Rottman & Simpson's v_h = 0.4 (g D drho / rho0)^(1/2) =
 * 0.217 m/s (003 eq 126; the paper reports about 0.2 m/s). The run stops when the head
 * has travelled L1 - D (or at --tend).
 *
 * Output in --out DIR (default gravity_current_out): head.csv and head.png (the head's
 * travel against Rottman & Simpson's speed; gnuplot on PATH, not --no-plot), and the JSON
 * summary gravity_current.json (--json: on stdout too): {"status":..,"error":..,"t":..,
 * "steps":..,"particles":..,"head_speed":..,"reference":0.217,"rel_dev":..,"fit_points":..,
 * "fit_window":[lo,hi],"head":[[t,x_head],...],"mass_rel_error":..,"wall_seconds":..}
 * (head_speed and rel_dev null when fewer than 3 head positions fell in the window). With
 * --vtu DIR (or --vtu-every T): gravity_current.pvd with VTU snapshots every 0.05 s (point
 * data "fluid" = 1 or 2). A run that stops on an error says so on stderr and exits with
 * status 3. */
#define _XOPEN_SOURCE 700
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "fluid_common.h"
#include "util.h"

static const double kG = 9.81, kGamma = 7.0, kD = 0.06, kRho1 = 1000.0, kRho2 = 1500.0;

static void usage(FILE *f) {
  fprintf(f, "usage: mfree_gravity_current [--nz N (34)] [--light L1 (0.12 m)] [--tend T (s; default: until\n"
             "       the head has travelled L1 - D, at most 1.5 s)] [--mu MU (0.01)] [--cfl C (0.25)]\n"
             "       [run options; --vtu-every in s, default 0.05]\n");
  fc_run_usage(f);
}

int main(int argc, char **argv) {
  int nz = 34;
  double light = 2.0 * kD, t_end = 1.5, mu = 0.01, cfl = 0.25;
  fc_run_t ro;
  fc_run_init(&ro, "gravity_current", 0.05);
  const fc_option_t opts[] = {{"--nz", 'i', &nz}, {"--light", 'd', &light}, {"--tend", 'd', &t_end},
                              {"--mu", 'd', &mu}, {"--cfl", 'd', &cfl},     {NULL, 0, NULL}};
  const int parsed = fc_parse(argc, argv, &ro, opts, usage);
  if (parsed) return parsed < 0 ? 0 : parsed;
  if (nz < 4 || !(light >= kD) || !(t_end > 0) || !(mu >= 0) || !(cfl > 0 && cfl <= 1)) {
    usage(stderr);
    return 2;
  }
  if (fc_run_prepare(&ro)) return 1;
  const char *out = ro.out;
  const double d = kD / nz, h = 1.5 * d, off = 0.5 * d, ds = d / 3.0;
  const int n1 = (int)lround(light / d), n2 = nz, nx = n1 + n2, n = nx * nz;
  const double L = nx * d, xlock = n1 * d;
  const double kappa = 100.0 * kRho2 * 2.0 * kG * kD / kGamma; /* 003 eq 125, heavier fluid */
  double *y = calloc(5 * (size_t)n, sizeof *y), *m = malloc((size_t)n * sizeof *m),
         *rho0 = malloc((size_t)n * sizeof *rho0);
  int *tag = malloc((size_t)n * sizeof *tag);
  if (!y || !m || !rho0 || !tag) return 1;
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nx; ++i) {
      const int q = j * nx + i;
      const double z = (j + 0.5) * d;
      tag[q] = i < n1 ? 1 : 2;
      rho0[q] = i < n1 ? kRho1 : kRho2;
      y[2 * q] = (i + 0.5) * d;
      y[2 * q + 1] = z;
      y[4 * n + q] = rho0[q] * pow(1.0 + rho0[q] * kG * (kD - z) / kappa, 1.0 / kGamma); /* eq 65 */
      m[q] = y[4 * n + q] * d * d;
    }
  const double top = 2.0 * kD;
  fc_walls_t w = {0, 0, NULL, NULL};
  if (fc_walls_tank(&w, 0.0, L, top, off, ds)) return 1;

  mfree_context_t *ctx = NULL;
  if (mfree_context_create(&ctx) != MFREE_SUCCESS) return 1;
  mfree_system_t *sys = NULL;
  mfree_status_t st;
#define CHECK(call) \
  if ((st = (call)) != MFREE_SUCCESS) return ex_fail(ctx, "mfree_gravity_current", st, #call)
  CHECK(fc_fluid_create(ctx, n, m, rho0, 1, kappa, kGamma, mu, h, kG, &w, 10.0, &sys));
  const double lo[2] = {-off, -off}, hi[2] = {L + off, 10.0 * kD};
  CHECK(mfree_system_set_box(sys, lo, hi));
  double mass0 = 0.0;
  for (int q = 0; q < n; ++q) mass0 += m[q];

  char path[4096];
  snprintf(path, sizeof path, "%s/head.csv", out);
  FILE *csv = fopen(path, "w");
  if (!csv) return 1;
  fprintf(csv, "t,x_head,travel\n");
  fc_vtu_t vtu;
  if (fc_vtu_open(&vtu, fc_run_vtu_dir(&ro), "gravity_current", ro.vtu_every)) return 1;
  fc_series_t head = {NULL, 0, 0};
  const double out_dt = 0.005;
  ex_progress_t prog;
  ex_progress_init(&prog, ro.quiet, 0.0, t_end);
  double t = 0.0;
  int64_t steps = 0;
  fc_fit_t fit = {0, 0, 0, 0, 0};
  mfree_status_t run = MFREE_SUCCESS;
  const double clock0 = fc_seconds();
  for (int io = 0; t < t_end - 1e-12; ++io) {
    if (io > 0) {
      run = fc_integrate(sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, fmin(t_end, io * out_dt), cfl, &prog, &steps);
      if (run != MFREE_SUCCESS) break;
    }
    double xh = 1e300;
    for (int q = 0; q < n; ++q)
      if (tag[q] == 2) xh = fmin(xh, y[2 * q] - 0.5 * d);
    const double travel = xlock - xh;
    fprintf(csv, "%.4f,%.6f,%.6f\n", t, xh, travel);
    const double row[2] = {t, xh};
    if (fc_series_push(&head, 2, row)) return 1;
    if (travel >= 0.5 * kD && travel <= light - kD) fc_fit_add(&fit, t, xh);
    if (fc_vtu_maybe(&vtu, sys, t, t, n, y, tag)) return 1;
    if (travel > light - kD) break; /* past the measuring window */
  }
  const double wall = fc_seconds() - clock0;
  ex_progress_done(&prog, "mfree_gravity_current", t);
  fclose(csv);
  if (fc_vtu_close(&vtu)) return 1;
  char msg[1024] = "";
  const int exit_status = run == MFREE_SUCCESS ? 0 : fc_run_error(ctx, &ro, run, "t", t, msg, sizeof msg);
  const int nfit = fit.n;
  double speed;
  fc_fit_line(&fit, &speed, NULL);
  speed = -speed;
  const double ref = 0.4 * sqrt(kG * kD * (kRho2 - kRho1) / kRho1); /* 003 eq 126 */
  double merr = 0.0;
  CHECK(fc_mass_error(sys, y, n, m, mass0, &merr));
  /* plot: the distance the head travelled against time, with the Rottman & Simpson speed
   * drawn through the middle of the fitted window */
  char csv_path[4096];
  FILE *gp = fc_plot_begin(&ro, "head", 800, 560, "t (s)", "distance travelled by the head (m)", csv_path,
                           sizeof csv_path);
  if (gp) {
    fprintf(gp, "set key top left\n"
                "set title 'Gravity current, %d particles: head against Rottman and Simpson (1983)'\n"
                "plot '%s' every ::1 using 1:3 with linespoints pt 7 ps 0.5 title 'mfree (Galerkin SPH)'",
            n, csv_path);
    if (nfit >= 3)
      fprintf(gp, ", %.6f + %.6f * (x - %.6f) with lines lw 2 dt 2 title 'v_h = 0.4 (g D drho/rho_0)^{1/2} = %.3f m/s'",
              xlock - fit.sy / nfit, ref, fit.sx / nfit, ref);
    fprintf(gp, "\n");
    fc_plot_end(gp, &ro, "head");
  }
  fc_json_t js;
  fc_json_init(&js);
  fc_json_run(&js, run, msg, t, steps, n);
  fc_json_num(&js, "head_speed", nfit >= 3 ? speed : NAN);
  fc_json_num(&js, "reference", ref);
  fc_json_num(&js, "rel_dev", nfit >= 3 ? (speed - ref) / ref : NAN);
  fc_json_int(&js, "fit_points", nfit);
  const double window[2] = {0.5 * kD, light - kD};
  fc_json_table(&js, "fit_window", 2, 1, window);
  fc_json_table(&js, "head", head.n / 2, 2, head.v);
  fc_json_num(&js, "mass_rel_error", merr);
  fc_json_num(&js, "cfl", cfl);
  fc_json_num(&js, "wall_seconds", wall);
  if (fc_json_finish(&js, &ro)) return 1;
  if (!ro.json_stdout) {
    printf("gravity current: %d particles, t = %.3f s, %lld steps, %.1f s\n", n, t, (long long)steps, wall);
    printf("head speed %.4f m/s over %d samples; Rottman & Simpson 0.4 (g D drho/rho0)^1/2 = %.4f m/s (%+.1f %%)\n",
           speed, nfit, ref, 100.0 * (speed - ref) / ref);
    printf("head history: %s/head.csv%s%s%s\n", out, vtu.count ? "; VTU series: " : "", vtu.count ? vtu.dir : "",
           vtu.count ? "/gravity_current.pvd" : "");
  }
  mfree_system_destroy(&sys);
  mfree_context_destroy(&ctx);
  fc_walls_free(&w);
  free(y);
  free(m);
  free(rho0);
  free(tag);
  fc_series_free(&head);
  return exit_status;
}
