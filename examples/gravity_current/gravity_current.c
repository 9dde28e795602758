/* Gravity current / lock exchange (paper 003 Sect. 7.3, Figs. 10-11; docs/papers.md,
 * paper 003, choices 2) by the Galerkin-SPH fluid of paper 003 with two fluids.
 *
 * Set-up. A tank of depth D = 0.06 m holds fluid 1 (rho0 = 1000 kg/m3) on the left over a
 * length --light (default 0.06 m) and fluid 2 (rho0 = 1500 kg/m3) on the right over
 * 0.06 m (the paper's Fig. 10 labels "0.06 m", "0.06 m", read as two compartments), both
 * filled to D. The lock between them is gone at t = 0 and fluid 2 runs under fluid 1.
 * --nz particles over the depth (default 51: 5,202 particles, the paper's 5,100), h = 1.5 d,
 * MLS linear, nodal integration, Galerkin lumped mass, leap-frog with CFL --cfl (default
 * 0.5, the paper's), wall particles at d/3 set back by d/2, r0 = 0.7 h, A = 10.
 * Per-particle rest densities (mfree_system_set_fluid with stride 1) and hydrostatic
 * initial densities in each compartment (003 eq 65). The paper gives neither kappa nor mu
 * for this example: kappa = 100 rho2 (2 g D) / gamma (eq 125 with the heavier fluid, so
 * both stay within 1 % of their rest densities), and mu = --mu (default 0.5 Pa s, the
 * viscosity of the paper's other viscous flows, Sects. 7.1, 7.2 and 7.4 a; the current's
 * Reynolds number U D / nu is then about 30).
 *
 * Head. The head is the leading edge of the heavy layer: the leftmost x where fluid 2
 * fills at least 0.2 D of the depth over a width of 0.1 D (at least 0.02 D^2 of its
 * particles' area d^2 lie in [x, x + 0.1 D); minus d/2, the particle's half cell). A
 * single particle thrown ahead does not count; where the nose is one piece (all
 * resolutions here) this is the leftmost particle to within a particle spacing.
 *
 * Head speed. The least-squares slope of the head's position, sampled every 0.005 s, over
 * the window 0.05 <= t <= 0.2 s (--fit-from, --fit-to; t (g'/D)^(1/2) from 0.45 to 1.8,
 * g' = g drho / rho1: from the end of the lock's first acceleration to the head 0.4 D from
 * the end wall; other densities scale the default by (D / g')^(1/2)), the run stopping at
 * its end (or at --tend). Compared with Rottman & Simpson's v_h = 0.4 (g D drho /
 * rho0)^(1/2) = 0.217 m/s (003 eq 126, rho0 = rho1; the paper reports about 0.2 m/s) and
 * with Benjamin's (1968) energy-conserving half-depth current under a lid, 0.5 (g D drho /
 * rho1)^(1/2) = 0.271 m/s. The default run gives 0.2199 m/s, +1.3 % of eq 126; the
 * speed converges with resolution, 0.222-0.223 m/s at nz = 26 to 41 and 0.218-0.221 m/s
 * at nz = 51 to 100 (docs/fluid.md has the table, and the shorter window 0.1-0.2 s, over
 * which the nose's unsteadiness gives 0.231-0.240 m/s).
 *
 * The long-tank set-up (fluid 1 2 D long, mu = 0.01: --light 0.12 --mu 0.01 --fit-from 0.1
 * --fit-to 0.3 --cfl 0.25): over 0.1 <= t <= 0.3 s, the lock's collapse, the head runs at
 * 0.30-0.32 m/s over 0.10 <= t <= 0.15 s and at 0.17-0.23 m/s over 0.25 <= t <= 0.30 s
 * (nz = 26 to 41); with --lumped-step 1 the speed over the window converges to 0.28 m/s
 * (0.280, 0.282, 0.281, 0.282 m/s at nz = 34, 41, 58, 82), 30 % above eq 126. Later the
 * particle arrangement disintegrates (the nodal-integration instability of
 * docs/fluid.md), so a longer tank and a later window give no convergent speed either. At
 * CFL 0.5 this set-up stops with a negative density (t = 0.12 s at nz = 34) unless
 * --acoustic-step 1 (mfree_system_set_acoustic_step).
 *
 * Diagnostics (not in the paper): --heavy RHO2 (a smaller density difference, towards the
 * Boussinesq lock exchange whose inviscid current is Benjamin's), --lid 1 (a free-slip
 * lid of wall particles at z = D + d/2 in place of the free surface), --consistent 1
 * (mfree_system_set_consistent_integration), --shepard-cond C and --lumped-step 1 (the
 * fluid's options of the same names; in the long-tank set-up from nz = 58 the paper's step
 * stops with a non-positive lumped mass, as the dam break did, and --lumped-step 1 runs).
 * Density diffusion is not offered: it diffuses rho itself and so mixes the two rest
 * densities at the interface.
 *
 * No-slip walls (--no-slip 1; not in the paper): four layers of dummy particles at spacing
 * d past the floor and the side walls (mfree_system_set_dummy_particles: zero velocity
 * parameters, so the interpolated velocity vanishes at the wall), the wall force kept.
 * Measured in the long-tank set-up: 0.200, 0.230, 0.243, 0.265 m/s at nz = 12, 20, 26, 34,
 * below the free-slip values and not converged: the floor's boundary layer, (nu t)^(1/2) =
 * 1.4 mm at t = 0.2 s, is thinner than the particle spacing (1.8 mm at nz = 34), so its
 * drag falls as d does.
 *
 * Output in --out DIR (default gravity_current_out): head.csv and head.png (the head's
 * travel against Rottman & Simpson's speed; gnuplot on PATH, not --no-plot), and the JSON
 * summary gravity_current.json (--json: on stdout too): {"status":..,"error":..,"t":..,
 * "steps":..,"particles":..,"head_speed":..,"reference":0.217,"rel_dev":..,
 * "inviscid_reference":0.271,"rel_dev_inviscid":..,"fit_points":..,"fit_window":[t0,t1]
 * (s),"head":[[t,x_head,x_leftmost],...],"mass_rel_error":..,"cfl":..,"mu":..,"no_slip":..,
 * "heavy_density":..,"light_length":..,"lid":..,"consistent_integration":..,
 * "shepard_condition":..,"lumped_mass_step":..,"wall_seconds":..}
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

static const double kG = 9.81, kGamma = 7.0, kD = 0.06, kRho1 = 1000.0;
/* the default fit window (s) at the paper's densities; other densities scale it by
 * (D / g')^(1/2), g' = g (rho2 - rho1) / rho1 */
static const double kFit0 = 0.05, kFit1 = 0.2;

static int cmp_double(const void *a, const void *b) {
  const double x = *(const double *)a, z = *(const double *)b;
  return (x > z) - (x < z);
}

/* The heavy layer's leading edge from the sorted x of its particles (spacing d): the
 * first x_j with at least 0.02 D^2 / d^2 particles in [x_j, x_j + 0.1 D), minus d / 2. */
static double head_edge(const double *xs, int nh, double d) {
  const double need = 0.02 * kD * kD / (d * d), width = 0.1 * kD;
  for (int j = 0, k = 0; j < nh; ++j) {
    if (k < j) k = j;
    while (k < nh && xs[k] < xs[j] + width) ++k;
    if (k - j >= need) return xs[j] - 0.5 * d;
  }
  return nh ? xs[0] - 0.5 * d : NAN;
}

static void usage(FILE *f) {
  fprintf(f, "usage: mfree_gravity_current [--nz N (51)] [--light L1 (0.06 m)] [--tend T (s; default: the end\n"
             "       of the fit window)] [--fit-from T0 (0.05 s)] [--fit-to T1 (0.2 s)] [--mu MU (0.5 Pa s)]\n"
             "       [--cfl C (0.5)] [--no-slip 0|1 (0)] [--heavy RHO2 (1500 kg/m3)] [--lid 0|1 (0)]\n"
             "       [--consistent 0|1 (0)] [--shepard-cond C (100)] [--lumped-step 0|1 (0)]\n"
             "       [--acoustic-step 0|1 (0)]\n"
             "       [run options; --vtu-every in s, default 0.05]\n");
  fc_run_usage(f);
}

int main(int argc, char **argv) {
  int nz = 51;
  double light = kD, t_end = -1.0, fit0 = -1.0, fit1 = -1.0, mu = 0.5, cfl = 0.5;
  int noslip = 0, lid = 0, consistent = 0, lumped_step = 0, acoustic_step = 0;
  double rho2 = 1500.0, shepard = 100.0;
  fc_run_t ro;
  fc_run_init(&ro, "gravity_current", 0.05);
  const fc_option_t opts[] = {{"--nz", 'i', &nz}, {"--light", 'd', &light}, {"--tend", 'd', &t_end},
                              {"--mu", 'd', &mu}, {"--cfl", 'd', &cfl},     {"--no-slip", 'i', &noslip},
                              {"--heavy", 'd', &rho2}, {"--lid", 'i', &lid},
                              {"--consistent", 'i', &consistent}, {"--shepard-cond", 'd', &shepard},
                              {"--lumped-step", 'i', &lumped_step}, {"--acoustic-step", 'i', &acoustic_step},
                              {"--fit-from", 'd', &fit0}, {"--fit-to", 'd', &fit1},
                              {NULL, 0, NULL}};
  const int parsed = fc_parse(argc, argv, &ro, opts, usage);
  if (parsed) return parsed < 0 ? 0 : parsed;
  if (nz < 4 || !(light >= kD) || !(t_end > 0 || t_end == -1.0) || !(mu >= 0) || !(cfl > 0 && cfl <= 1) ||
      (noslip != 0 && noslip != 1) || !(rho2 > kRho1 && rho2 <= 10.0 * kRho1) || (lid != 0 && lid != 1) ||
      (consistent != 0 && consistent != 1) || (lumped_step != 0 && lumped_step != 1) || (acoustic_step != 0 && acoustic_step != 1) || !(shepard >= 1) ||
      !(fit0 >= 0 || fit0 == -1.0) || !(fit1 > 0 || fit1 == -1.0)) {
    usage(stderr);
    return 2;
  }
  if (fc_run_prepare(&ro)) return 1;
  const double tscale = sqrt(500.0 / (rho2 - kRho1));
  if (fit0 < 0) fit0 = kFit0 * tscale;
  if (fit1 < 0) fit1 = kFit1 * tscale;
  if (!(fit1 > fit0)) {
    usage(stderr);
    return 2;
  }
  if (t_end < 0) t_end = fit1;
  const char *out = ro.out;
  const double d = kD / nz, h = 1.5 * d, off = 0.5 * d, ds = d / 3.0;
  const int n1 = (int)lround(light / d), n2 = nz, nx = n1 + n2, n = nx * nz;
  const double L = nx * d, xlock = n1 * d;
  const double kappa = 100.0 * rho2 * 2.0 * kG * kD / kGamma; /* 003 eq 125, heavier fluid */
  double *y = calloc(5 * (size_t)n, sizeof *y), *m = malloc((size_t)n * sizeof *m),
         *rho0 = malloc((size_t)n * sizeof *rho0);
  int32_t *tag = malloc((size_t)n * sizeof *tag);
  double *xs = malloc((size_t)n * sizeof *xs);
  if (!y || !m || !rho0 || !tag || !xs) return 1;
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nx; ++i) {
      const int q = j * nx + i;
      const double z = (j + 0.5) * d;
      tag[q] = i < n1 ? 1 : 2;
      rho0[q] = i < n1 ? kRho1 : rho2;
      y[2 * q] = (i + 0.5) * d;
      y[2 * q + 1] = z;
      y[4 * n + q] = rho0[q] * pow(1.0 + rho0[q] * kG * (kD - z) / kappa, 1.0 / kGamma); /* eq 65 */
      m[q] = y[4 * n + q] * d * d;
    }
  const double top = lid ? kD + off : 2.0 * kD;
  fc_walls_t w = {0, 0, NULL, NULL};
  if (fc_walls_tank(&w, 0.0, L, top, off, ds)) return 1;
  if (lid && fc_walls_segment(&w, -off + ds, top, L + off - ds, top, ds, 0, -1, 0)) return 1;

  mfree_context_t *ctx = NULL;
  if (mfree_context_create(&ctx) != MFREE_SUCCESS) return 1;
  mfree_system_t *sys = NULL;
  mfree_status_t st;
#define CHECK(call) \
  if ((st = (call)) != MFREE_SUCCESS) return ex_fail(ctx, "mfree_gravity_current", st, #call)
  CHECK(fc_fluid_create(ctx, n, m, rho0, 1, kappa, kGamma, mu, h, kG, &w, 10.0, &sys));
  const double lo[2] = {-off, -off}, hi[2] = {L + off, 10.0 * kD};
  CHECK(mfree_system_set_box(sys, lo, hi));
  CHECK(mfree_system_set_consistent_integration(sys, consistent));
  CHECK(mfree_system_set_shepard_condition(sys, shepard));
  CHECK(mfree_system_set_lumped_mass_step(sys, lumped_step));
  CHECK(mfree_system_set_acoustic_step(sys, acoustic_step));
  if (noslip) CHECK(fc_dummy_tank(sys, nx, top, d)); /* four layers past the floor and the side walls */
  double mass0 = 0.0;
  for (int q = 0; q < n; ++q) mass0 += m[q];

  FILE *csv = fc_open_csv(&ro, "head.csv");
  if (!csv) return 1;
  fprintf(csv, "t,x_head,travel,x_leftmost\n");
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
    int nh = 0;
    for (int q = 0; q < n; ++q)
      if (tag[q] == 2) xs[nh++] = y[2 * q];
    qsort(xs, (size_t)nh, sizeof *xs, cmp_double);
    const double xh = head_edge(xs, nh, d), xl = xs[0] - 0.5 * d;
    fprintf(csv, "%.4f,%.6f,%.6f,%.6f\n", t, xh, xlock - xh, xl);
    const double row[3] = {t, xh, xl};
    if (fc_series_push(&head, 3, row)) return 1;
    if (t >= fit0 - 1e-9 && t <= fit1 + 1e-9) fc_fit_add(&fit, t, xh);
    if (fc_vtu_maybe(&vtu, sys, t, t, n, y, tag)) return 1;
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
  const double ref = 0.4 * sqrt(kG * kD * (rho2 - kRho1) / kRho1); /* 003 eq 126 */
  const double ref_inviscid = 0.5 * sqrt(kG * kD * (rho2 - kRho1) / kRho1); /* Benjamin (1968) */
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
      fprintf(gp, ", %.6f + %.6f * (x - %.6f) with lines lw 2 dt 2 title 'Rottman and Simpson: v_h = 0.4 (g D drho/rho_0)^{1/2} = %.3f m/s'"
                  ", %.6f + %.6f * (x - %.6f) with lines lw 2 dt 3 title 'inviscid (Benjamin 1968): 0.5 (g D drho/rho_0)^{1/2} = %.3f m/s'",
              xlock - fit.sy / nfit, ref, fit.sx / nfit, ref, xlock - fit.sy / nfit, ref_inviscid, fit.sx / nfit,
              ref_inviscid);
    fprintf(gp, "\n");
    fc_plot_end(gp, &ro, "head");
  }
  fc_json_t js;
  fc_json_init(&js);
  fc_json_run(&js, run, msg, t, steps, n);
  fc_json_num(&js, "head_speed", nfit >= 3 ? speed : NAN);
  fc_json_num(&js, "reference", ref);
  fc_json_num(&js, "rel_dev", nfit >= 3 ? (speed - ref) / ref : NAN);
  fc_json_num(&js, "inviscid_reference", ref_inviscid);
  fc_json_num(&js, "rel_dev_inviscid", nfit >= 3 ? (speed - ref_inviscid) / ref_inviscid : NAN);
  fc_json_int(&js, "fit_points", nfit);
  const double window[2] = {fit0, fit1};
  fc_json_table(&js, "fit_window", 2, 1, window);
  fc_json_table(&js, "head", head.n / 3, 3, head.v);
  fc_json_num(&js, "mass_rel_error", merr);
  fc_json_num(&js, "cfl", cfl);
  fc_json_num(&js, "mu", mu);
  fc_json_int(&js, "no_slip", noslip);
  fc_json_num(&js, "heavy_density", rho2);
  fc_json_num(&js, "light_length", light);
  fc_json_int(&js, "lid", lid);
  fc_json_int(&js, "consistent_integration", consistent);
  fc_json_num(&js, "shepard_condition", shepard);
  fc_json_int(&js, "lumped_mass_step", lumped_step);
  fc_json_int(&js, "acoustic_step", acoustic_step);
  fc_json_num(&js, "wall_seconds", wall);
  if (fc_json_finish(&js, &ro)) return 1;
  if (!ro.json_stdout) {
    printf("gravity current: %d particles, t = %.3f s, %lld steps, %.1f s\n", n, t, (long long)steps, wall);
    printf("head speed %.4f m/s over %d samples; Rottman & Simpson 0.4 (g D drho/rho0)^1/2 = %.4f m/s (%+.1f %%); "
           "inviscid 0.5 (g D drho/rho0)^1/2 = %.4f m/s (%+.1f %%)\n",
           speed, nfit, ref, 100.0 * (speed - ref) / ref, ref_inviscid, 100.0 * (speed - ref_inviscid) / ref_inviscid);
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
  free(xs);
  fc_series_free(&head);
  return exit_status;
}
