/* Bore between two water levels (paper 003 Sect. 7.2, Figs. 8-9; docs/papers.md, paper
 * 003, choices 2) by the Galerkin-SPH fluid of paper 003, its speed against the
 * shallow-water bore.
 *
 * Set-up (the paper gives no dimensions; these are ours). A tank of length --tank L
 * (default 1.5 m) holds water at rest at depth h1 = 0.1 m over x < --deep Ld (default
 * 0.5 m) and at depth h0 = --ratio r times h1 (default 0.5) beyond. The gate between them
 * is gone at t = 0: a bore runs into the shallow water and a rarefaction into the deep
 * water. --nz particles over h1 (default 20: 4,000 particles, the paper's 3,980), d = h1 /
 * nz, h = 1.5 d; the paper's constants: rho0 = 1000, mu = 0.5, gamma = 7, kappa = 100
 * rho0 (2 g h1) / gamma (eq 125), hydrostatic initial densities in each part (eq 65), MLS
 * linear, nodal integration, Galerkin lumped mass, leap-frog with CFL --cfl (default the
 * paper's 0.5) and the acoustic step (--acoustic-step, default 1: without it the run at CFL
 * 0.5 stops at t = 0.34-0.40 s with a negative density at the end wall's corner), wall
 * particles at spacing d/3 set back by d/2, r0 = 0.7 h, A = 10.
 *
 * Reference. The shallow-water (Stoker) solution of the Riemann problem on a wet bed: the
 * middle state (h_m, u_m) joins the rarefaction, u_m = 2 (sqrt(g h1) - sqrt(g h_m)), to
 * the bore, whose speed S satisfies S^2 = g h_m (h_m + h0) / (2 h0) and mass S (h_m -
 * h0) = h_m u_m. For r = 0.5: h_m = 0.7269 h1, S = 0.9354 m/s.
 *
 * Measurement. The free surface is the highest particle (+ d/2) within columns of width 3d;
 * the bore is the last point where it is above the mid height (h0 + h_m)/2, scanning from
 * one depth before the end wall back towards the gate (linear between columns), every
 * 0.01 s. Its speed is the
 * least-squares slope of its position while it has travelled between 2 h1 (formed) and
 * L - Ld - 2 h1 (two depths before the end wall), where the run stops. The depth behind
 * the bore is the mean surface height over the middle half of the plateau the
 * shallow-water solution predicts, when the rarefaction reaches the left wall (Ld /
 * sqrt(g h1), 0.50 s; its reflection then lowers the plateau).
 *
 * Output in --out DIR (default bore_out): bore.csv (t, position), profile.csv (surface at
 * that time against the shallow-water solution), bore.png and profile.png (gnuplot), the
 * JSON summary bore.json (--json: on stdout too): {"status":..,"error":..,"t":..,
 * "steps":..,"particles":..,"bore_speed":..,"reference":..,"rel_dev":..,"fit_points":..,
 * "fit_window":[..],"depth_ratio":..,"h_m":..,"h_m_reference":..,"h_m_rel_dev":..,"h_m_time":..,
 * "bore":[[t,x],...],"mass_rel_error":..,"cfl":..,"lumped_mass_step":..,"acoustic_step":..,
 * "wall_seconds":..}. --lumped-step 1, --acoustic-step 1: the step controls beyond the paper
 * (mfree_system_set_lumped_mass_step, mfree_system_set_acoustic_step; --acoustic-step 0 runs
 * the paper's scheme as it stands) with which the run holds at the paper's CFL 0.5
 * (docs/fluid.md). --vtu DIR: the VTU
 * series every 0.05 s. A run that stops on an error says so and exits with status 3. */
#define _XOPEN_SOURCE 700
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "fluid_common.h"
#include "util.h"

static const double kG = 9.81, kRho0 = 1000.0, kGamma = 7.0, kH1 = 0.1;

/* Shallow-water middle state of the wet-bed Riemann problem: h_m, u_m and the bore speed. */
static void sw_bore(double h1, double h0, double *hm, double *um, double *S) {
  double a = h0, b = h1;
  for (int it = 0; it < 200; ++it) {
    const double m = 0.5 * (a + b);
    const double f = 2.0 * (sqrt(kG * h1) - sqrt(kG * m)) - (m - h0) * sqrt(kG * (m + h0) / (2.0 * h0 * m));
    if (f > 0) a = m;
    else b = m;
  }
  *hm = 0.5 * (a + b);
  *um = 2.0 * (sqrt(kG * h1) - sqrt(kG * *hm));
  *S = sqrt(kG * *hm * (*hm + h0) / (2.0 * h0));
}

/* Shallow-water surface at x (gate at xg) at time t > 0. */
static double sw_height(double x, double t, double xg, double h1, double h0, double hm, double um, double S) {
  const double c1 = sqrt(kG * h1), cm = sqrt(kG * hm), xi = (x - xg) / t;
  if (xi <= -c1) return h1;
  if (xi <= um - cm) return pow(2.0 * c1 - xi, 2) / (9.0 * kG);
  if (xi <= S) return hm;
  return h0;
}

/* Surface heights at the centres of columns of width d over [0, L): the highest particle
 * (+ d/2) within the column and its two neighbours, so that a column the disordered
 * particles happen to leave empty does not open a hole in the surface. */
static void surface(int n, const double *y, double d, int ncol, double *col, double *height) {
  for (int b = 0; b < ncol; ++b) col[b] = 0.0;
  for (int q = 0; q < n; ++q) {
    int b = (int)floor(y[2 * q] / d);
    if (b < 0) b = 0;
    if (b >= ncol) b = ncol - 1;
    col[b] = fmax(col[b], y[2 * q + 1] + 0.5 * d);
  }
  for (int b = 0; b < ncol; ++b)
    height[b] = fmax(col[b], fmax(b > 0 ? col[b - 1] : 0.0, b + 1 < ncol ? col[b + 1] : 0.0));
}

/* The bore: scanning from column b1 back towards the gate, the first column above thr;
 * the position where the surface falls through thr, linear between column centres. */
static double bore_position(const double *height, int b0, int b1, double d, double thr) {
  for (int b = b1; b > b0; --b)
    if (height[b - 1] >= thr) {
      const double hl = height[b - 1], hr = height[b];
      const double w = hl > hr ? (hl - thr) / (hl - hr) : 0.0;
      return (b - 0.5 + fmin(w, 1.0)) * d;
    }
  return (b0 + 0.5) * d;
}

typedef struct {
  double h1, h0, xg, hm, um, S, d;
  int ncol;
} bore_t;

/* Write DIR/profile.csv, the surface at time t (> 0) against the shallow-water solution,
 * and return the mean surface height over the middle half of the plateau the
 * shallow-water solution predicts (the depth behind the bore; NaN if empty), or -1 when
 * the file cannot be written. */
static double profile(const fc_run_t *r, const bore_t *b, const double *height, double t) {
  FILE *f = fc_open_csv(r, "profile.csv");
  if (!f) return -1.0;
  fprintf(f, "# free surface at t = %.4f s: mfree (highest particle + d/2 within 3 columns) and shallow water\n"
             "x,height,height_sw\n", t);
  const double pa = b->xg + (b->um - sqrt(kG * b->hm)) * t, pb = b->xg + b->S * t;
  double sum = 0.0;
  int count = 0;
  for (int k = 0; k < b->ncol; ++k) {
    const double x = (k + 0.5) * b->d;
    fprintf(f, "%.5f,%.6f,%.6f\n", x, height[k], sw_height(x, t, b->xg, b->h1, b->h0, b->hm, b->um, b->S));
    if (x >= pa + 0.25 * (pb - pa) && x <= pb - 0.25 * (pb - pa)) sum += height[k], ++count;
  }
  fclose(f);
  return count ? sum / count : NAN;
}

static void usage(FILE *f) {
  fprintf(f, "usage: mfree_bore [--nz N (20)] [--ratio R (0.5)] [--deep LD (0.5 m)] [--tank L (1.5 m)]\n"
             "                  [--tend T (2 s; the run stops earlier, two depths before the end wall)]\n"
             "                  [--cfl C (0.5)] [--mu MU (0.5)] [--lumped-step 0|1 (0)] [--acoustic-step 0|1 (1)]\n"
             "                  [run options; --vtu-every in s, default 0.05]\n");
  fc_run_usage(f);
}

int main(int argc, char **argv) {
  int nz = 20, lumped_step = 0, acoustic_step = 1;
  double ratio = 0.5, deep = 0.5, tank = 1.5, t_end = 2.0, cfl = 0.5, mu = 0.5;
  fc_run_t ro;
  fc_run_init(&ro, "bore", 0.05);
  const fc_option_t opts[] = {{"--nz", 'i', &nz},     {"--ratio", 'd', &ratio}, {"--deep", 'd', &deep},
                              {"--tank", 'd', &tank}, {"--tend", 'd', &t_end},  {"--cfl", 'd', &cfl},
                              {"--mu", 'd', &mu},     {"--lumped-step", 'i', &lumped_step},
                              {"--acoustic-step", 'i', &acoustic_step}, {NULL, 0, NULL}};
  const int parsed = fc_parse(argc, argv, &ro, opts, usage);
  if (parsed) return parsed < 0 ? 0 : parsed;
  const double d = kH1 / (nz > 0 ? nz : 1);
  const int nz0 = (int)lround(ratio * nz), nd = (int)lround(deep / d), ns = (int)lround((tank - deep) / d);
  if (nz < 4 || !(ratio > 0 && ratio < 1) || nz0 < 2 || nz0 >= nz || nd < 4 || !(tank - deep >= 6 * kH1) ||
      !(t_end > 0) || !(cfl > 0 && cfl <= 1) || !(mu >= 0) || (lumped_step != 0 && lumped_step != 1) ||
      (acoustic_step != 0 && acoustic_step != 1)) {
    usage(stderr);
    return 2;
  }
  if (fc_run_prepare(&ro)) return 1;
  const double h = 1.5 * d, off = 0.5 * d, ds = d / 3.0, h1 = kH1, h0 = nz0 * d, xg = nd * d,
               L = (nd + ns) * d;
  const int n = nd * nz + ns * nz0;
  const double kappa = 100.0 * kRho0 * 2.0 * kG * h1 / kGamma; /* 003 eq 125 */
  double *y = calloc(5 * (size_t)n, sizeof *y), *m = malloc((size_t)n * sizeof *m);
  const int ncol = nd + ns;
  double *height = malloc((size_t)ncol * sizeof *height), *col = malloc((size_t)ncol * sizeof *col);
  if (!y || !m || !height || !col) return 1;
  const int q = fc_water_block(y, m, n, 0, 0.0, nd, nz, d, h1, kRho0, kappa, kGamma, kG);
  fc_water_block(y, m, n, q, xg, ns, nz0, d, h0, kRho0, kappa, kGamma, kG);
  fc_walls_t w = {0, 0, NULL, NULL};
  if (fc_walls_tank(&w, 0.0, L, 2.0 * h1, off, ds)) return 1;

  mfree_context_t *ctx = NULL;
  if (mfree_context_create(&ctx) != MFREE_SUCCESS) return 1;
  mfree_system_t *sys = NULL;
  mfree_status_t st;
#define CHECK(call) \
  if ((st = (call)) != MFREE_SUCCESS) return ex_fail(ctx, "mfree_bore", st, #call)
  CHECK(fc_fluid_create(ctx, n, m, &kRho0, 0, kappa, kGamma, mu, h, kG, &w, 10.0, &sys));
  const double lo[2] = {-off, -off}, hi[2] = {L + off, 10.0 * h1};
  CHECK(mfree_system_set_box(sys, lo, hi));
  CHECK(mfree_system_set_lumped_mass_step(sys, lumped_step));
  CHECK(mfree_system_set_acoustic_step(sys, acoustic_step));
  double mass0 = 0.0;
  for (int k = 0; k < n; ++k) mass0 += m[k];

  double hm, um, S;
  sw_bore(h1, h0, &hm, &um, &S);
  const double thr = 0.5 * (h0 + hm), win_lo = 2.0 * h1, win_hi = (L - xg) - 2.0 * h1;
  const int bend = (int)floor((L - h1) / d); /* the scan starts one depth before the end wall */

  FILE *csv = fc_open_csv(&ro, "bore.csv");
  if (!csv) return 1;
  fprintf(csv, "# bore between depths %g and %g m (gate at x = %g m), %d particles; shallow-water bore "
               "speed %.4f m/s\nt,x_bore,travel\n", h1, h0, xg, n, S);
  fc_vtu_t vtu;
  if (fc_vtu_open(&vtu, fc_run_vtu_dir(&ro), "bore", ro.vtu_every)) return 1;
  fc_series_t series = {NULL, 0, 0};
  fc_fit_t fit = {0, 0, 0, 0, 0};
  ex_progress_t prog;
  ex_progress_init(&prog, ro.quiet, 0.0, t_end);
  const double out_dt = 0.01;
  /* the profile when the rarefaction reaches the left wall: later its reflection lowers
   * the plateau, which the Riemann solution does not describe */
  const bore_t bore = {h1, h0, xg, hm, um, S, d, ncol};
  const double t_prof = xg / sqrt(kG * h1);
  double t = 0.0, tf0 = 0.0, tf1 = 0.0, hm_meas = NAN, t_hm = NAN;
  int64_t steps = 0;
  mfree_status_t run = MFREE_SUCCESS;
  const double clock0 = fc_seconds();
  for (int io = 0; t < t_end - 1e-12; ++io) {
    if (io > 0) {
      run = fc_integrate(sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, fmin(t_end, io * out_dt), cfl, &prog, &steps);
      if (run != MFREE_SUCCESS) break;
    }
    surface(n, y, d, ncol, col, height);
    const double xb = bore_position(height, nd - 1, bend, d, thr), travel = xb - xg;
    fprintf(csv, "%.4f,%.6f,%.6f\n", t, xb, travel);
    const double row[2] = {t, xb};
    if (fc_series_push(&series, 2, row)) return 1;
    if (travel >= win_lo && travel <= win_hi) {
      if (!fit.n) tf0 = t;
      tf1 = t;
      fc_fit_add(&fit, t, xb);
    }
    if (t > 0 && isnan(t_hm) && t >= t_prof - 1e-9) {
      t_hm = t;
      if ((hm_meas = profile(&ro, &bore, height, t)) < 0) return 1;
    }
    if (fc_vtu_maybe(&vtu, sys, t, t, n, y, NULL)) return 1;
    if (travel > win_hi) break;
  }
  const double wall = fc_seconds() - clock0;
  ex_progress_done(&prog, "mfree_bore", t);
  fclose(csv);
  if (fc_vtu_close(&vtu)) return 1;
  char msg[1024] = "";
  const int exit_status = run == MFREE_SUCCESS ? 0 : fc_run_error(ctx, &ro, run, "t", t, msg, sizeof msg);
  double mass_err = 0.0;
  CHECK(fc_mass_error(sys, y, n, m, mass0, &mass_err));
  double speed, icpt;
  fc_fit_line(&fit, &speed, &icpt);
  if (isnan(t_hm) && t > 0) { /* the run ended before t_prof */
    t_hm = t;
    if ((hm_meas = profile(&ro, &bore, height, t)) < 0) return 1;
  }


  /* plots: the bore's position against the shallow-water speed; the surface profile */
  char data[4096];
  FILE *f = fc_plot_begin(&ro, "bore", 800, 560, "t (s)", "bore position x - x_{gate} (m)", data, sizeof data);
  if (f) {
    fprintf(f, "set key top left\nset title 'Bore, depths %g and %g m, %d particles: Galerkin SPH vs shallow water'\n"
               "plot '%s' using 1:3 with linespoints pt 7 ps 0.5 title 'mfree (Galerkin SPH)', "
               "%.6f * x with lines lw 2 dt 2 title 'shallow-water bore, S = %.3f m/s'",
            h1, h0, n, data, S, S);
    if (fit.n >= 3)
      fprintf(f, ", (x >= %g && x <= %g) ? %.6f + %.6f * x : 1/0 with lines lw 2 title 'fit, %.3f m/s'", tf0, tf1,
              icpt - xg, speed, speed);
    fprintf(f, "\n");
    fc_plot_end(f, &ro, "bore");
  }
  f = fc_plot_begin(&ro, "profile", 900, 400, "x (m)", "free surface (m)", data, sizeof data);
  if (f) {
    fprintf(f, "set key top right\nset yrange [0:%g]\nset title 'Bore at t = %.3f s: free surface'\n"
               "plot '%s' using 1:2 with lines lw 2 title 'mfree (Galerkin SPH, %d particles)', "
               "'%s' using 1:3 with lines dt 2 lw 2 title 'shallow water'\n",
            1.3 * h1, t_hm, data, n, data);
    fc_plot_end(f, &ro, "profile");
  }

  fc_json_t js;
  fc_json_init(&js);
  fc_json_run(&js, run, msg, t, steps, n);
  fc_json_num(&js, "bore_speed", speed);
  fc_json_num(&js, "reference", S);
  fc_json_num(&js, "rel_dev", (speed - S) / S);
  fc_json_int(&js, "fit_points", fit.n);
  const double window[2] = {win_lo, win_hi};
  fc_json_table(&js, "fit_window", 2, 1, window);
  fc_json_num(&js, "depth_ratio", h0 / h1);
  fc_json_num(&js, "h_m", hm_meas);
  fc_json_num(&js, "h_m_reference", hm);
  fc_json_num(&js, "h_m_rel_dev", (hm_meas - hm) / hm);
  fc_json_num(&js, "h_m_time", t_hm);
  fc_json_table(&js, "bore", series.n / 2, 2, series.v);
  fc_json_num(&js, "mass_rel_error", mass_err);
  fc_json_num(&js, "cfl", cfl);
  fc_json_int(&js, "lumped_mass_step", lumped_step);
  fc_json_int(&js, "acoustic_step", acoustic_step);
  fc_json_num(&js, "wall_seconds", wall);
  if (fc_json_finish(&js, &ro)) return 1;
  if (!ro.json_stdout) {
    printf("bore: depths %g / %g m, %d particles, t = %.3f s, %lld steps, %.1f s\n", h1, h0, n, t,
           (long long)steps, wall);
    printf("bore speed %.4f m/s over %d samples; shallow water %.4f m/s (%+.1f %%)\n", speed, fit.n, S,
           100.0 * (speed - S) / S);
    printf("depth behind the bore at t = %.3f s %.4f m; shallow water %.4f m (%+.1f %%); mass error %.2e\n", t_hm,
           hm_meas, hm, 100.0 * (hm_meas - hm) / hm, mass_err);
  }
  mfree_system_destroy(&sys);
  mfree_context_destroy(&ctx);
  fc_walls_free(&w);
  fc_series_free(&series);
  free(y);
  free(m);
  free(height);
  free(col);
  return exit_status;
}
