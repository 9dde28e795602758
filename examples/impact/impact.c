/* Impact of a drop on a rigid structure (paper 003 Sect. 7.4, Figs. 15-17, the
 * fluid-structure example; docs/papers.md, paper 003, choices 2) by the Galerkin-SPH
 * fluid of paper 003: the force history on the structure and its impulse against the
 * fluid's momentum.
 *
 * Structure model (the paper does not specify one; this is ours): a rigid, fixed,
 * horizontal plate, infinitely stiff and massive, whose top face is a row of wall
 * particles at spacing d/3 with upward normals exerting the force of 003 eqs 122-124 (r0 =
 * 0.7 h, A = 10) on approaching fluid particles. The plate spans --plate P drop diameters
 * (default 6) centred under the drop; it is the only wall.
 *
 * Set-up (the paper gives 4,470 fluid particles and no dimensions; these are ours, after
 * its drop example): a circular drop of diameter --diameter D (default 0.05 m), particles
 * at the lattice points of spacing d = D / --nd (default 40: 1,257 particles; 75 gives
 * 4,421, the paper's count) inside the circle, at rest density, velocity parameters
 * (0, -2) m/s (a constant field is reproduced exactly, 003 eq 100), its lowest particle
 * 2 d above the plate's face. rho0 = 1000, mu = 0.5 (the paper's drop), gamma = 7, sound
 * speed ten times the impact speed (kappa = rho0 c^2 / gamma), h = 1.5 d, MLS linear,
 * nodal integration, Galerkin lumped mass (eq 56), leap-frog with CFL --cfl (default the
 * paper's 0.5) and the acoustic step (--acoustic-step, default 1; without it the run at
 * CFL 0.5 and nd = 40 stops at t = 0.0076 s with a negative density after the impact, at
 * CFL 0.25 it holds; --lumped-step 1 also holds it: mfree_system_set_acoustic_step,
 * mfree_system_set_lumped_mass_step),
 * gravity 9.81 m/s^2, to --tend (default 0.04 s: the drop has spread into a sheet and
 * its vertical momentum is gone).
 *
 * Measured (CFL 0.5, acoustic step): the impulse within 0.52 %, 0.28 % and 0.24 % of the
 * momentum change at nd = 20, 30 and 40 (317, 709 and 1,257 particles; 651, 1,231 and
 * 1,641 steps), 0.951, 0.963 and 0.958 of M (2 + g t); at CFL 0.25 without it 0.30 % at
 * nd = 40 (2,232 steps). The mean force peaks about 2 ms after the first contact, then decays
 * to the drop's weight as the drop spreads.
 *
 * Force and impulse. At every step the force the structure exerts on the fluid, F(t), is
 * read with mfree_system_get_wall_force (the sum of the plate's wall particles' shares)
 * before the step, and the impulse I(t) = sum F dt accumulates over the steps. The fluid's
 * momentum P = sum_i M_i v_i (M_i the Galerkin lumped masses, assembled separately)
 * changes by I + M g t when nothing else acts on it: the check is the relative
 * difference |P(t_end) - P(0) - M g t_end - I(t_end)| / |I(t_end)| in the vertical
 * (impulse_dev; tested to 2 %), and the impulse against M (2 + g t_end), the impulse
 * that brings the drop to rest vertically by t_end (stopping_impulse;
 * impulse_over_momentum: 1 for a drop at rest, less when part of it still falls, more for
 * a rebound).
 *
 * Output in --out DIR (default impact_out): force.csv (t, F_x, F_z, I_z at every step),
 * force_mean.csv (the mean force over every 0.5 ms), impulse.csv (t, I_z, dP_z = P_z(t) -
 * P_z(0) + M g t every 0.5 ms), force.png (the force history), impulse.png (I_z(t) beside
 * the fluid's momentum change dP_z(t) and M (2 + g t), the impulse that stops the drop
 * by t), and the JSON summary
 * impact.json (--json: on stdout too): {"status","error","t","steps","particles",
 * "mass_rel_error","peak_force","peak_time","impulse":[I_x,I_z],"momentum_change":[..],
 * "impulse_dev","impulse_over_momentum","stopping_impulse","impact_time","force":[[t,F_x,
 * F_z],...] (means over every 0.0005 s),"momentum":[[t,I_z,dP_z],...],"sound_speed","cfl",
 * "wall_seconds"}. --vtu DIR: the VTU series every
 * 0.002 s. A run that stops on an error says so on stderr and exits with status 3. */
#define _XOPEN_SOURCE 700
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fluid_common.h"
#include "util.h"

static const double kG = 9.81, kRho0 = 1000.0, kGamma = 7.0, kV0 = 2.0;

static void usage(FILE *f) {
  fprintf(f, "usage: mfree_impact [--nd N (40)] [--diameter D (0.05 m)] [--plate P (6 diameters)]\n"
             "                    [--tend T (0.04 s)] [--cfl C (0.5)] [--mu MU (0.5)]\n"
             "                    [--lumped-step 0|1 (0)] [--acoustic-step 0|1 (1)]\n"
             "                    [run options; --vtu-every in s, default 0.002]\n");
  fc_run_usage(f);
}

/* progress callback of a one-step integration */
static int32_t stop_after_one(void *user, int64_t step, double t, double dt) {
  (void)user;
  (void)step;
  (void)t;
  (void)dt;
  return 1;
}

/* the fluid's momentum sum_i M_i v_i with the lumped masses at y */
static mfree_status_t momentum(mfree_system_t *sys, const double *y, int n, double *lumped, double P[2]) {
  const mfree_status_t st = fc_lumped_masses(sys, y, n, lumped);
  P[0] = P[1] = 0.0;
  for (int q = 0; q < n && st == MFREE_SUCCESS; ++q)
    for (int c = 0; c < 2; ++c) P[c] += lumped[q] * y[2 * n + 2 * q + c];
  return st;
}

/* A CSV of rows of three numbers (the plots read it; a failure leaves the plot empty). */
static void write_rows(const char *path, const char *header, const fc_series_t *rows) {
  FILE *f = fopen(path, "w");
  if (!f) return;
  fprintf(f, "%s\n", header);
  for (int k = 0; k < rows->n / 3; ++k)
    fprintf(f, "%.6f,%.8g,%.8g\n", rows->v[3 * k], rows->v[3 * k + 1], rows->v[3 * k + 2]);
  fclose(f);
}

int main(int argc, char **argv) {
  int nd = 40, lumped_step = 0, acoustic_step = 1;
  double diameter = 0.05, plate = 6.0, t_end = 0.04, cfl = 0.5, mu = 0.5;
  fc_run_t ro;
  fc_run_init(&ro, "impact", 0.002);
  const fc_option_t opts[] = {{"--nd", 'i', &nd},     {"--diameter", 'd', &diameter}, {"--plate", 'd', &plate},
                              {"--tend", 'd', &t_end}, {"--cfl", 'd', &cfl},          {"--mu", 'd', &mu},
                              {"--lumped-step", 'i', &lumped_step}, {"--acoustic-step", 'i', &acoustic_step},
                              {NULL, 0, NULL}};
  const int parsed = fc_parse(argc, argv, &ro, opts, usage);
  if (parsed) return parsed < 0 ? 0 : parsed;
  if (nd < 6 || !(diameter > 0) || !(plate >= 2) || !(t_end > 0) || !(cfl > 0 && cfl <= 1) || !(mu >= 0) ||
      (lumped_step != 0 && lumped_step != 1) || (acoustic_step != 0 && acoustic_step != 1)) {
    usage(stderr);
    return 2;
  }
  if (fc_run_prepare(&ro)) return 1;
  const double d = diameter / nd, R = 0.5 * diameter, h = 1.5 * d, ds = d / 3.0;
  const int ir = (int)floor(R / d + 1e-9);
  const double zc0 = ir * d + 2.0 * d; /* the lowest particle 2 d above the plate's face z = 0 */
  const int n = fc_water_drop(NULL, NULL, 0, 0, 0.0, zc0, R, d, kRho0, kV0);
  const double c0 = 10.0 * kV0, kappa = kRho0 * c0 * c0 / kGamma;
  double *y = calloc(5 * (size_t)n, sizeof *y), *m = malloc((size_t)n * sizeof *m),
         *lumped = malloc((size_t)n * sizeof *lumped);
  if (!y || !m || !lumped) return 1;
  fc_water_drop(y, m, n, 0, 0.0, zc0, R, d, kRho0, kV0);
  double mass = 0.0;
  for (int k = 0; k < n; ++k) mass += m[k];
  const double half = 0.5 * plate * diameter;
  fc_walls_t w = {0, 0, NULL, NULL};
  if (fc_walls_segment(&w, -half, 0.0, half, 0.0, ds, 0.0, 1.0, 0)) return 1;
  double *pw = malloc(2 * (size_t)w.n * sizeof *pw);
  if (!pw) return 1;

  mfree_context_t *ctx = NULL;
  if (mfree_context_create(&ctx) != MFREE_SUCCESS) return 1;
  mfree_system_t *sys = NULL;
  mfree_status_t st;
#define CHECK(call) \
  if ((st = (call)) != MFREE_SUCCESS) return ex_fail(ctx, "mfree_impact", st, #call)
  CHECK(fc_fluid_create(ctx, n, m, &kRho0, 0, kappa, kGamma, mu, h, kG, &w, 10.0, &sys));
  /* the particles stay above the plate's face and within reach of it */
  const double lo[2] = {-2.0 * half, -0.5 * d}, hi[2] = {2.0 * half, zc0 + 10.0 * diameter};
  CHECK(mfree_system_set_box(sys, lo, hi));
  CHECK(mfree_system_set_lumped_mass_step(sys, lumped_step));
  CHECK(mfree_system_set_acoustic_step(sys, acoustic_step));

  FILE *csv = fc_open_csv(&ro, "force.csv");
  if (!csv) return 1;
  fprintf(csv, "# drop of diameter %g m at 2 m/s onto a rigid plate; %d particles\n"
               "t,F_x,F_z,I_z\n", diameter, n);
  fc_vtu_t vtu;
  if (fc_vtu_open(&vtu, fc_run_vtu_dir(&ro), "impact", ro.vtu_every)) return 1;
  fc_series_t hist = {NULL, 0, 0}, mom = {NULL, 0, 0};
  ex_progress_t prog;
  ex_progress_init(&prog, ro.quiet, 0.0, t_end);
  double t = 0.0, P0[2], P[2], I[2] = {0, 0}, F[2] = {0, 0}, peak = 0.0, t_peak = NAN, t_impact = NAN;
  double next_hist = 0.0005, t_hist = 0.0, I_hist[2] = {0, 0};
  int64_t steps = 0;
  mfree_status_t run = MFREE_SUCCESS;
  const double clock0 = fc_seconds();
  CHECK(momentum(sys, y, n, lumped, P0));
  if (fc_vtu_maybe(&vtu, sys, t, t, n, y, NULL)) return 1;
  while (t < t_end - 1e-12) {
    run = mfree_system_get_wall_force(sys, y, NULL, w.n, pw);
    if (run != MFREE_SUCCESS) break;
    F[0] = F[1] = 0.0;
    for (int k = 0; k < w.n; ++k) F[0] += pw[2 * k], F[1] += pw[2 * k + 1];
    if (F[1] > peak) peak = F[1], t_peak = t;
    if (isnan(t_impact) && F[1] > 0.0) t_impact = t;
    const double t0 = t;
    int64_t k = 0;
    run = mfree_system_integrate(sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, t_end, cfl, 0.0, stop_after_one, NULL, &k);
    steps += k;
    ex_progress(&prog, k, t, t - t0);
    ex_progress_steps(&prog, k);
    if (run != MFREE_SUCCESS) break;
    for (int c = 0; c < 2; ++c) I[c] += (t - t0) * F[c];
    fprintf(csv, "%.7f,%.8g,%.8g,%.8g\n", t0, F[0], F[1], I[1]);
    if (t >= next_hist - 1e-12) { /* the mean force over the last interval, the momentum */
      CHECK(momentum(sys, y, n, lumped, P));
      const double mrow[3] = {t, I[1], P[1] - P0[1] + mass * kG * t};
      if (fc_series_push(&mom, 3, mrow)) return 1;
      const double row[3] = {0.5 * (t + t_hist), (I[0] - I_hist[0]) / (t - t_hist), (I[1] - I_hist[1]) / (t - t_hist)};
      if (fc_series_push(&hist, 3, row)) return 1;
      next_hist += 0.0005;
      t_hist = t;
      I_hist[0] = I[0];
      I_hist[1] = I[1];
    }
    if (fc_vtu_maybe(&vtu, sys, t, t, n, y, NULL)) return 1;
  }
  const double wall = fc_seconds() - clock0;
  ex_progress_done(&prog, "mfree_impact", t);
  fclose(csv);
  if (fc_vtu_close(&vtu)) return 1;
  char msg[1024] = "";
  const int exit_status = run == MFREE_SUCCESS ? 0 : fc_run_error(ctx, &ro, run, "t", t, msg, sizeof msg);
  double mass_err = 0.0;
  CHECK(fc_mass_error(sys, y, n, m, mass, &mass_err));
  CHECK(momentum(sys, y, n, lumped, P));
  const double dP[2] = {P[0] - P0[0], P[1] - P0[1] + mass * kG * t};
  const double dev = fabs(dP[1] - I[1]) / fabs(I[1]);
  const double p_rest = mass * (kV0 + kG * t); /* the impulse that brings the drop to rest by t */

  char hpath[4096];
  ex_join(hpath, sizeof hpath, ro.out, "force_mean.csv");
  write_rows(hpath, "t,F_x_mean,F_z_mean", &hist);
  char ipath[4096];
  ex_join(ipath, sizeof ipath, ro.out, "impulse.csv");
  write_rows(ipath, "t,I_z,dP_z", &mom);
  char data[4096];
  FILE *f = fc_plot_begin(&ro, "force", 800, 560, "t (s)", "vertical force on the plate (N/m)", data, sizeof data);
  if (f) {
    fprintf(f, "set key top right\nset title 'Drop of %g m at 2 m/s on a rigid plate, %d particles: force history'\n"
               "plot '%s' every ::1 using 1:3 with lines lw 1 lc rgb '#b0b0b0' title 'mfree: force at every step', "
               "'%s' using 1:3 with linespoints lw 2 pt 7 ps 0.5 title 'mfree: mean over 0.5 ms', "
               "%g with lines dt 2 title 'rho_0 V^2 D = %.0f N/m (stagnation pressure x diameter)', "
               "%g with lines dt 3 title 'drop weight M g = %.1f N/m'\n",
            diameter, n, data, hpath, kRho0 * kV0 * kV0 * diameter, kRho0 * kV0 * kV0 * diameter, mass * kG,
            mass * kG);
    fc_plot_end(f, &ro, "force");
  }
  f = fc_plot_begin(&ro, "impulse", 800, 560, "t (s)", "vertical impulse (N s/m)", data, sizeof data);
  if (f) {
    fprintf(f, "set key bottom right\nset title 'Impulse of the plate against the fluid''s momentum change'\n"
               "plot '%s' using 1:2 with lines lw 2 title 'mfree: impulse sum F dt', "
               "'%s' using 1:3 with points pt 7 ps 0.5 title 'fluid: P_z(t) - P_z(0) + M g t', "
               "%g * (2 + 9.81 * x) with lines dt 2 title 'the impulse that stops the drop by t: M (2 + g t)'\n",
            data, data, mass);
    fc_plot_end(f, &ro, "impulse");
  }

  fc_json_t js;
  fc_json_init(&js);
  fc_json_run(&js, run, msg, t, steps, n);
  fc_json_num(&js, "mass_rel_error", mass_err);
  fc_json_num(&js, "peak_force", peak);
  fc_json_num(&js, "peak_time", t_peak);
  fc_json_table(&js, "impulse", 2, 1, I);
  fc_json_table(&js, "momentum_change", 2, 1, dP);
  fc_json_num(&js, "impulse_dev", dev);
  fc_json_num(&js, "impulse_over_momentum", I[1] / p_rest);
  fc_json_num(&js, "stopping_impulse", p_rest);
  fc_json_num(&js, "impact_time", t_impact);
  fc_json_table(&js, "force", hist.n / 3, 3, hist.v);
  fc_json_table(&js, "momentum", mom.n / 3, 3, mom.v);
  fc_json_num(&js, "sound_speed", c0);
  fc_json_num(&js, "cfl", cfl);
  fc_json_int(&js, "lumped_mass_step", lumped_step);
  fc_json_int(&js, "acoustic_step", acoustic_step);
  fc_json_num(&js, "wall_seconds", wall);
  if (fc_json_finish(&js, &ro)) return 1;
  if (!ro.json_stdout) {
    printf("impact: %d particles, t = %.4f s, %lld steps, %.1f s\n", n, t, (long long)steps, wall);
    printf("peak force %.4g N/m at t = %.4f s (first contact %.4f s)\n", peak, t_peak, t_impact);
    printf("impulse (%.5g, %.5g) N s/m; fluid momentum change less gravity's (%.5g, %.5g): %.2e apart\n", I[0],
           I[1], dP[0], dP[1], dev);
    printf("impulse / M (2 + g t) %.4f; mass error %.2e\n", I[1] / p_rest, mass_err);
  }
  mfree_system_destroy(&sys);
  mfree_context_destroy(&ctx);
  fc_walls_free(&w);
  fc_series_free(&hist);
  fc_series_free(&mom);
  free(pw);
  free(lumped);
  free(y);
  free(m);
  return exit_status;
}
