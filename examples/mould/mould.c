/* Filling a circular mould with a core through a gate (paper 003 Sect. 7.5, Figs. 18-21)
 * by the Galerkin-SPH fluid of paper 003 with an inflow gate (mfree_system_set_inflow).
 *
 * Set-up (the paper gives the jet's speed at the gate, 18 m/s, mu = 0.01, the wave
 * celerity 1000 m/s, A = 4 and 14,314 particles; its Fig. 18 with the dimensions is not
 * available, so these are ours). A circular mould of radius --radius Rm (default 0.05 m)
 * centred at the origin, with a circular core of radius --core Rc (default 0.015 m) at its
 * centre. The gate, --gate W wide (default 0.01 m), lies 5 spacings below the mould's
 * lowest point at the end of a vertical channel; the fluid (rho0 = 1000 kg/m^3) enters
 * upwards at 18 m/s, hits the core and splits into two jets that run round it. Spacing
 * d = W / --nw (default 10: d = 1 mm), h = 1.5 d, linear MLS, nodal integration,
 * leap-frog at CFL --cfl (default 0.5), kappa = rho0 c^2 / gamma with c = 1000 m/s,
 * gamma = 7; wall particles (003 Sect. 6.2: spacing d/3, r0 = 0.7 h, A = --strength,
 * default the paper's 4) on the mould's circle (normals inwards), the core's (normals
 * outwards) and the channel's sides; gravity -9.81 m/s^2 along z. The mould starts empty:
 * the system holds a capacity of particles, all dormant at first; the gate injects rows
 * of nw particles through its buffer (docs/fluid.md, "Inflow and outflow").
 *
 * Checks, every 0.1 ms:
 *  - mass entering through the gate (mfree_system_get_inflow) against rho0 U W t: equal
 *    to the released count times the particle mass to round-off, and to rho0 U W t within
 *    half a row (mass_in_dev: the largest relative deviation once 50 rows have entered);
 *  - total mass: the lumped masses of the active particles summing to the particle
 *    masses (003 eq 57) and those to the entered mass plus the buffer's;
 *  - symmetry of the two jets round the core: the gate's rows are mirror images about
 *    x = 0 (lattice points (j + 1/2) W / nw), so particle j of a row and particle
 *    nw - 1 - j are mirror twins; symmetry_dev is the largest distance between a particle
 *    and its twin's mirror image, over all particles and samples, in spacings; and the
 *    jets' fronts (the fluid particle farthest round the core on each side, angle from
 *    the core's lowest point) are compared (front_dev, in spacings).
 * Impact: the first sample at which a fluid particle is within 2h of the core.
 *
 * Output in --out DIR (default mould_out): mould.csv, mould.png (the entered mass against
 * rho0 U W t; gnuplot), mould_fronts.png (both jets' front angles), the JSON summary
 * mould.json (--json: on stdout too) with the numbers above and "mass_in":[[t,M,rho U W t],
 * ...], "fronts":[[t,left,right],...]. --vtu DIR: the VTU series every 0.5 ms (point data
 * "fluid": 0 dormant, 1 fluid, 2 in the gate's buffer). A run that stops on an error says
 * so and exits with status 3. */
#define _XOPEN_SOURCE 700
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fluid_common.h"
#include "util.h"

static const double kG = 9.81, kRho0 = 1000.0, kGamma = 7.0, kU = 18.0, kC = 1000.0;

static void usage(FILE *f) {
  fprintf(f, "usage: mfree_mould [--nw N (10)] [--radius R (0.05 m)] [--core R (0.015 m)] [--gate W (0.01 m)]\n"
             "                   [--tend T (0.008 s)] [--cfl C (0.5)] [--mu MU (0.01)] [--strength A (4)]\n"
             "                   [--shepard-cond K (20)] [--delta D (0)] [--smoothing B (0.1)]\n"
             "                   [--lumped-step 0|1 (0): mfree_system_set_lumped_mass_step]\n"
             "                   [run options; --vtu-every in s, default 0.0005]\n");
  fc_run_usage(f);
}

/* Wall particles on an arc of the circle of radius r about the origin, from angle a0 to
 * a1 (radians, counter-clockwise from +x; both ends included, or with full the whole
 * circle from a0 without repeating it), at spacing <= ds, normals inwards (sign -1) or
 * outwards (+1). */
static int arc(fc_walls_t *w, double r, double a0, double a1, int full, double ds, double sign) {
  const int k = (int)ceil(r * (a1 - a0) / ds);
  for (int q = 0; q <= k - full; ++q) {
    const double a = a0 + (a1 - a0) * q / k, c = cos(a), s = sin(a);
    if (fc_walls_segment(w, r * c, r * s, r * c, r * s, ds, sign * c, sign * s, 0)) return 1;
  }
  return 0;
}

int main(int argc, char **argv) {
  int nw = 10;
  double Rm = 0.05, Rc = 0.015, W = 0.01, t_end = 0.008, cfl = 0.5, mu = 0.01, strength = 4.0, shepard = 20.0;
  double delta = 0.0, beta = 0.1;
  int lumped_step = 0;
  fc_run_t ro;
  fc_run_init(&ro, "mould", 0.0005);
  const fc_option_t opts[] = {{"--nw", 'i', &nw},          {"--radius", 'd', &Rm}, {"--core", 'd', &Rc},
                              {"--gate", 'd', &W},         {"--tend", 'd', &t_end}, {"--cfl", 'd', &cfl},
                              {"--mu", 'd', &mu},          {"--strength", 'd', &strength},
                              {"--shepard-cond", 'd', &shepard}, {"--delta", 'd', &delta},
                              {"--smoothing", 'd', &beta}, {"--lumped-step", 'i', &lumped_step},
                              {NULL, 0, NULL}};
  const int parsed = fc_parse(argc, argv, &ro, opts, usage);
  if (parsed) return parsed < 0 ? 0 : parsed;
  const double d = W / (nw > 0 ? nw : 1);
  if (nw < 3 || !(Rc > 0) || !(Rm >= Rc + 10 * d) || !(W > 0 && W < Rc) || !(t_end > 0) ||
      !(cfl > 0 && cfl <= 1) || !(mu >= 0) || !(strength >= 0) || !(shepard >= 1) || !(delta >= 0) || !(beta >= 0) ||
      (lumped_step != 0 && lumped_step != 1)) {
    usage(stderr);
    return 2;
  }
  if (fc_run_prepare(&ro)) return 1;
  const double h = 1.5 * d, ds = d / 3.0, off = 0.5 * d;
  const double zb = -sqrt(Rm * Rm - 0.25 * W * W); /* where the channel meets the circle */
  const double zgate = -Rm - 5 * d;
  const int nb = (int)ceil(2.0 * h / d - 1e-9); /* the buffer's rows (support radius 2h) */
  const int rows = (int)ceil(kU * t_end / d) + nb + 2;
  const int n = rows * nw; /* the capacity */
  const double kappa = kRho0 * kC * kC / kGamma;
  const double pm = kRho0 * d * W / nw; /* the particles' mass (the gate's) */
  double *y = calloc(5 * (size_t)n, sizeof *y), *m = malloc((size_t)n * sizeof *m);
  double *lumped = malloc((size_t)n * sizeof *lumped);
  int32_t *state = malloc((size_t)n * sizeof *state);
  if (!y || !m || !lumped || !state) return 1;
  for (int i = 0; i < n; ++i) { /* dormant: parked below the buffer, at rest density */
    m[i] = pm;
    y[2 * i + 1] = zgate - (nb + 2) * d;
    y[4 * n + i] = kRho0;
  }
  fc_walls_t w = {0, 0, NULL, NULL};
  const double ag = asin(0.5 * W / Rm); /* the channel's half-angle on the circle */
  const double pi = acos(-1.0);
  /* both circles mirror images of themselves about x = 0, as the gate's lattice */
  if (arc(&w, Rm + off, -0.5 * pi + ag, 1.5 * pi - ag, 0, ds, -1.0) || arc(&w, Rc - off, -0.5 * pi, 1.5 * pi, 1, ds, 1.0) ||
      fc_walls_segment(&w, -0.5 * W - off, zgate, -0.5 * W - off, zb, ds, 1.0, 0.0, 0) ||
      fc_walls_segment(&w, 0.5 * W + off, zgate, 0.5 * W + off, zb, ds, -1.0, 0.0, 0))
    return 1;

  mfree_context_t *ctx = NULL;
  if (mfree_context_create(&ctx) != MFREE_SUCCESS) return 1;
  mfree_status_t st;
#define CHECK(call) \
  if ((st = (call)) != MFREE_SUCCESS) return ex_fail(ctx, "mfree_mould", st, #call)
  mfree_system_t *sys = NULL;
  CHECK(fc_fluid_create(ctx, n, m, &kRho0, 0, kappa, kGamma, mu, h, kG, &w, strength, &sys));
  const double lo[2] = {-Rm - 2 * d, zgate - (nb + 3) * d}, hi[2] = {Rm + 2 * d, Rm + 2 * d};
  CHECK(mfree_system_set_box(sys, lo, hi));
  CHECK(mfree_system_set_shepard_condition(sys, shepard));
  CHECK(mfree_system_set_density_diffusion(sys, delta));
  CHECK(mfree_system_set_velocity_smoothing(sys, beta));
  CHECK(mfree_system_set_lumped_mass_step(sys, lumped_step));
  CHECK(mfree_system_set_active(sys, 0));
  const double go[2] = {-0.5 * W, zgate}, ge[2] = {W, 0.0}, gn[2] = {0.0, 1.0};
  CHECK(mfree_system_set_inflow(sys, 0, go, ge, gn, kU, kRho0, d));

  FILE *csv = fc_open_csv(&ro, "mould.csv");
  if (!csv) return 1;
  fprintf(csv, "# mould of radius %g m with a core of radius %g m, gate %g m at 18 m/s; d = %g m\n"
               "t,mass_in,rho_U_W_t,active,front_left_deg,front_right_deg,symmetry_dev_d\n", Rm, Rc, W, d);
  fc_vtu_t vtu;
  if (fc_vtu_open(&vtu, fc_run_vtu_dir(&ro), "mould", ro.vtu_every)) return 1;
  fc_series_t min_s = {NULL, 0, 0}, fr_s = {NULL, 0, 0};
  ex_progress_t prog;
  ex_progress_init(&prog, ro.quiet, 0.0, t_end);
  const double out_dt = 1e-4, row_mass = pm * nw;
  double t = 0.0, dev_in = 0.0, dev_count = 0.0, dev_mass = 0.0, dev_sym = 0.0, dev_front = 0.0;
  double t_impact = NAN, mass_in = 0.0, dev_centroid = 0.0;
  int64_t steps = 0, count = 0;
  int32_t na = 0;
  mfree_status_t run = MFREE_SUCCESS;
  const double clock0 = fc_seconds();
  CHECK(mfree_system_update_open_boundaries(sys, t, y)); /* the gate's buffer at t = 0 */
  for (int io = 0; t < t_end - 1e-12; ++io) {
    if (io > 0) {
      run = fc_integrate(sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, fmin(t_end, io * out_dt), cfl, &prog, &steps);
      if (run != MFREE_SUCCESS) break;
    }
    CHECK(mfree_system_get_inflow(sys, 0, &count, &mass_in));
    CHECK(mfree_system_get_active(sys, &na, n, state));
    const double ref = kRho0 * kU * W * t;
    dev_count = fmax(dev_count, fabs(mass_in - (double)count * pm) / fmax(mass_in, pm));
    if (t >= 50 * d / kU) dev_in = fmax(dev_in, fabs(mass_in - ref) / ref);
    /* mass: the lumped masses of the active particles, the particle masses */
    CHECK(fc_lumped_masses(sys, y, n, lumped));
    double ml = 0.0, mp = 0.0;
    int nbuf = 0;
    for (int i = 0; i < n; ++i)
      if (state[i] != MFREE_PARTICLE_DORMANT) {
        ml += lumped[i];
        mp += m[i];
        nbuf += state[i] == MFREE_PARTICLE_INFLOW;
      }
    dev_mass = fmax(dev_mass, fmax(fabs(ml - mp), fabs(mp - (mass_in + nbuf * pm))) / mp);
    /* symmetry: twins j and nw - 1 - j of a row; the fronts round the core */
    double fl = 0.0, fr = 0.0, cl[3] = {0, 0, 0}, cr[3] = {0, 0, 0};
    for (int i = 0; i < n; ++i) {
      if (state[i] != MFREE_PARTICLE_FLUID) continue;
      const int twin = (i / nw) * nw + (nw - 1 - i % nw);
      const double ex = y[2 * i] + y[2 * twin], ez = y[2 * i + 1] - y[2 * twin + 1];
      dev_sym = fmax(dev_sym, hypot(ex, ez) / d);
      const double x = y[2 * i], z = y[2 * i + 1];
      if (isnan(t_impact) && hypot(x, z) <= Rc + 2 * h) t_impact = t;
      if (hypot(x, z) < Rc) continue;
      const double ang = atan2(fabs(x), -z) * 180.0 / pi; /* 0 at the core's lowest point */
      double *cs = x < -0.25 * d ? cl : x > 0.25 * d ? cr : NULL;
      if (cs) cs[0] += x, cs[1] += z, cs[2] += 1;
      if (x < -0.25 * d) fl = fmax(fl, ang);
      if (x > 0.25 * d) fr = fmax(fr, ang);
    }
    if (cl[2] > 0 && cr[2] > 0) /* the jets' centroids (outside the core's circle), mirrored */
      dev_centroid = fmax(dev_centroid, hypot(cl[0] / cl[2] + cr[0] / cr[2], cl[1] / cl[2] - cr[1] / cr[2]) / d);
    /* the fronts' arc lengths on the mean radius, in spacings */
    dev_front = fmax(dev_front, fabs(fl - fr) * pi / 180.0 * 0.5 * (Rm + Rc) / d);
    fprintf(csv, "%.5f,%.8g,%.8g,%d,%.3f,%.3f,%.3g\n", t, mass_in, ref, na, fl, fr, dev_sym);
    const double rm[3] = {t, mass_in, ref}, rf[3] = {t, fl, fr};
    if (fc_series_push(&min_s, 3, rm) || fc_series_push(&fr_s, 3, rf)) return 1;
    if (fc_vtu_maybe(&vtu, sys, t, t, n, y, state)) return 1;
  }
  const double wall = fc_seconds() - clock0;
  ex_progress_done(&prog, "mfree_mould", t);
  fclose(csv);
  if (fc_vtu_close(&vtu)) return 1;
  char msg[1024] = "";
  const int exit_status = run == MFREE_SUCCESS ? 0 : fc_run_error(ctx, &ro, run, "t", t, msg, sizeof msg);
  const double final_ref = kRho0 * kU * W * t, final_dev = fabs(mass_in - final_ref) / final_ref;

  char data[4096], data_fronts[4096];
  FILE *f = fc_plot_begin(&ro, "mould", 800, 560, "t (s)", "mass entered through the gate (kg/m)", data,
                          sizeof data);
  if (f) {
    fprintf(f, "set key top left\nset title 'Mould filling, gate at 18 m/s, d = %g mm'\n"
               "plot '%s' using 1:2 with points pt 7 ps 0.6 title 'mfree: particles released by the gate', "
               "'%s' using 1:3 with lines lw 2 dt 2 title 'rho U W t'\n",
            d * 1e3, data, data);
    fc_plot_end(f, &ro, "mould");
  }
  f = fc_plot_begin(&ro, "mould_fronts", 800, 560, "t (s)", "jet front round the core (degrees)", data_fronts,
                    sizeof data_fronts);
  if (f) {
    fprintf(f, "set key top left\nset title 'The two jets round the core'\n"
               "plot '%s' using 1:5 with lines lw 2 title 'left jet', "
               "'%s' using 1:6 with points pt 6 ps 0.8 title 'right jet (mirror image)'\n",
            data, data);
    fc_plot_end(f, &ro, "mould_fronts");
  }

  fc_json_t js;
  fc_json_init(&js);
  fc_json_run(&js, run, msg, t, steps, n); /* particles: the state's, dormant included */
  fc_json_int(&js, "active", na);
  fc_json_num(&js, "spacing", d);
  fc_json_int(&js, "released", count);
  fc_json_num(&js, "mass_in", mass_in);
  fc_json_num(&js, "mass_in_reference", final_ref);
  fc_json_num(&js, "mass_in_final_dev", final_dev);
  fc_json_num(&js, "mass_in_dev", dev_in);
  fc_json_num(&js, "mass_count_dev", dev_count);
  fc_json_num(&js, "mass_rel_error", dev_mass);
  fc_json_num(&js, "impact_time", t_impact);
  fc_json_num(&js, "symmetry_dev", dev_sym);
  fc_json_num(&js, "front_dev", dev_front);
  fc_json_num(&js, "centroid_dev", dev_centroid);
  fc_json_table(&js, "mass_in_series", min_s.n / 3, 3, min_s.v);
  fc_json_table(&js, "fronts", fr_s.n / 3, 3, fr_s.v);
  fc_json_num(&js, "sound_speed", kC);
  fc_json_num(&js, "cfl", cfl);
  fc_json_num(&js, "shepard_condition", shepard);
  fc_json_num(&js, "smoothing", beta);
  fc_json_int(&js, "lumped_mass_step", lumped_step);
  fc_json_num(&js, "wall_seconds", wall);
  if (fc_json_finish(&js, &ro)) return 1;
  if (!ro.json_stdout) {
    printf("mould: %d active of %d, t = %.5f s, %lld steps, %.1f s\n", (int)na, n, t, (long long)steps, wall);
    printf("mass in %.6g kg/m (%lld particles) vs rho U W t = %.6g: %.2e (at most %.2e after 50 rows)\n", mass_in,
           (long long)count, final_ref, final_dev, dev_in);
    printf("impact on the core at t = %.4f s; jets: fronts %.2e, centroids %.2e spacings from mirror images;"
           " particles %.2e\n", t_impact, dev_front, dev_centroid, dev_sym);
    printf("mass error %.2e\n", dev_mass);
  }
  (void)row_mass;
  mfree_system_destroy(&sys);
  mfree_context_destroy(&ctx);
  fc_walls_free(&w);
  fc_series_free(&min_s);
  fc_series_free(&fr_s);
  free(y);
  free(m);
  free(lumped);
  free(state);
  return exit_status;
}
