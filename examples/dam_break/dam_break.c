/* Collapse of a water column (2D dam break) by the Galerkin-SPH fluid of paper 003
 * (Cueto-Felgueroso et al. 2004), surge front against Martin & Moyce (1952).
 *
 * Set-up. A column of width a and height 2a (Martin & Moyce's n^2 = 2; default
 * a = 0.05715 m = 2.25 in, their column) stands at the left end of a tank of length L =
 * --tank a (default 5a) and is released at t = 0. Everything else is paper 003 Sect. 7.1
 * (docs/papers.md, paper 003, choices 1): particles on the cell-centred lattice of spacing d = a / nx,
 * h = 1.5 d, rho0 = 1000, gamma = 7, kappa = 100 rho0 (2 g H) / gamma with H = 2a (eq 125),
 * mu = 0.5, hydrostatic initial densities (eq 65), masses rho_i d^2, MLS with a linear
 * basis, nodal integration, Galerkin lumped mass (eq 56), leap-frog (eqs 108-110) with
 * the CFL step (eq 120), wall particles at spacing d/3 with normals into the fluid,
 * r0 = 0.7 h, A = 10 (eqs 122-124).
 *
 * Wall position. The walls are set back by d/2 from the fluid's edge (first particle
 * layer at d from the wall particles, r0 / r = 1.05): with the walls on the fluid's edge
 * the first layer starts at r0 / r = 2.1, where the Lennard-Jones term is 15 A / r and
 * the first kick throws the layer off (see tests/t702). The fluid's edge x = 0 is the
 * column's far face (Martin & Moyce's origin) and z = 0 the floor.
 *
 * Options beyond the paper. --no-slip 1: the experiment's tank has no-slip walls; four
 * layers of dummy particles at spacing d past the floor and both end walls
 * (mfree_system_set_dummy_particles: zero velocity parameters, so the interpolated velocity
 * vanishes at the walls), the wall force kept. --diffusion D: density diffusion (delta-SPH),
 * which a run with water's viscosity (--mu 0.001) needs to reach T = 3. --lumped-step 1: the
 * CFL step with the lumped masses (mfree_system_set_lumped_mass_step), which holds the 16a
 * tank to T = 8 at CFL 0.5 with the library's Shepard condition. docs/fluid.md gives the
 * fronts each setting measures against the experiment: with --no-slip 1, the experiment's
 * walls, the front lies within 7.5 % of Martin & Moyce's points over 0.5 <= T <= 3 at the
 * default nx = 24 (7.4 % at 48, 6.7 % at 96); with the paper's free-slip walls, the
 * default, within 10.1 % at nx = 24, growing to 13.5 % at 96.
 *
 * Front. Z = (max_i x_i + d/2) / a over all fluid particles (a particle stands for the
 * cell of width d around it, so Z = 1 at t = 0), against T = t sqrt(2 g / a). The front
 * of the particles touching the floor (z_i < 1.5 d) is written to the CSV too.
 *
 * Output in DIR (--out, default dam_break_out): front.csv, front.gp and front.png (gnuplot
 * on PATH, not --no-plot) and the JSON summary dam_break.json (--json: on stdout too):
 * {"front":[[T,Z],...],"front_floor":[[T,Z_floor],...],"time_digest":..,"front_digest":..,
 * "front_floor_digest":.. (fc_digest of the T, Z and Z_floor samples: equal digests, equal
 * bits),"max_rel_dev":..,"compared":..,
 * "particles":..,"steps":..,"wall_seconds":..,"mass_rel_error":..,"status":..,"error":..,
 * "t_end":..,"density_range":[min,max],"head_speed":..,"head_speed_experiment":..,
 * "head_fit_points":..}, head_speed the surge front's speed dZ/dT (the least-squares slope
 * of the samples with 1 <= T <= 3; times sqrt(2 g a) in m/s), head_speed_experiment the
 * same fit through Martin & Moyce's points there, and max_rel_dev the largest
 * |Z - Z_exp| / Z_exp over the data points with 1 <= T <= 3 (Z linearly interpolated in
 * T; -1 when no data file), t_end the T reached and density_range the densities' extremes
 * at the output times (every 0.05 in T); "density_range_steps":[min,max] the extremes over
 * every accepted step (t = 0 included), which also see what happens between two outputs,
 * and "density_lowest":[T,particle,x,z] where that minimum was (docs/fluid.md: the no-slip
 * run's low density); "max_rel_dev_wide" and "compared_wide" the same over 0.5 <= T <= 3,
 * and "time_offset":[mean,min,max] the lag of the experiment there: T_exp minus the T at
 * which the simulated front reaches Z_exp, point by point; the
 * settings as "a", "nx", "cfl", "mu", "shepard_condition", "lumped_mass_step", "no_slip",
 * "diffusion", "scheme".
 * With --vtu DIR (or --vtu-every T): dam_break.pvd indexing dam_break_NNNN.vtu
 * (position, velocity = interpolated v_hat, pressure, density) every 0.25 in T. A run that
 * stops on an error (a particle leaving the tank, a non-finite state) says so on stderr
 * and exits with status 3. */
#define _XOPEN_SOURCE 700
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <mfree.h>

#include "fluid_common.h"
#include "util.h"

typedef struct {
  double a, tank, t_end, cfl, mu, strength, offset, out_dt, shepard, diffusion;
  int nx, scheme, lumping, lumped_step, no_slip, acoustic_step;
  const char *data;
  fc_run_t run;
} options_t;

static void usage(FILE *f) {
  fprintf(f, "usage: mfree_dam_break [options]\n");
  fc_dam_usage(f);
  fprintf(f, "  --lumped-step 0|1  CFL step with the lumped masses (mfree_system_set_lumped_mass_step;\n"
             "                  default 0, eq 120 as in the paper; 1 runs the 16a tank to T = 8 at CFL 0.5)\n"
             "  --acoustic-step 0|1  the step also at most 1.5 / omega, omega the acoustic operator's largest\n"
             "                  frequency (mfree_system_set_acoustic_step; default 0)\n"
             "  --no-slip 0|1   no-slip floor and end walls: dummy particles past them (default 0)\n"
             "  --diffusion D   density diffusion delta (mfree_system_set_density_diffusion; default 0)\n");
  fc_run_usage(f);
}

/* Returns 0 to go on, -1 after --help, 2 for bad options. */
static int parse(int argc, char **argv, options_t *o) {
  const char *scheme = "leapfrog", *lumping = "galerkin";
  const fc_option_t opts[] = {{"--nx", 'i', &o->nx},           {"--a", 'd', &o->a},
                              {"--tank", 'd', &o->tank},       {"--tend", 'd', &o->t_end},
                              {"--cfl", 'd', &o->cfl},         {"--mu", 'd', &o->mu},
                              {"--strength", 'd', &o->strength}, {"--offset", 'd', &o->offset},
                              {"--data", 's', &o->data},       {"--scheme", 's', &scheme},
                              {"--lumping", 's', &lumping},    {"--shepard-cond", 'd', &o->shepard},
                              {"--lumped-step", 'i', &o->lumped_step}, {"--no-slip", 'i', &o->no_slip},
                              {"--diffusion", 'd', &o->diffusion}, {"--acoustic-step", 'i', &o->acoustic_step},
                              {NULL, 0, NULL}};
  const int parsed = fc_parse(argc, argv, &o->run, opts, usage);
  if (parsed) return parsed;
  if (!strcmp(scheme, "leapfrog")) o->scheme = MFREE_INTEGRATOR_LEAPFROG;
  else if (!strcmp(scheme, "pc")) o->scheme = MFREE_INTEGRATOR_PREDICTOR_CORRECTOR;
  else o->scheme = -1;
  if (!strcmp(lumping, "galerkin")) o->lumping = MFREE_LUMP_GALERKIN;
  else if (!strcmp(lumping, "physical")) o->lumping = MFREE_LUMP_PHYSICAL;
  else o->lumping = -1;
  const int ok = o->scheme >= 0 && o->lumping >= 0 && o->nx >= 2 && o->a > 0 && o->tank > 1 && o->t_end > 0 &&
                 o->cfl > 0 && o->cfl <= 1 && o->mu >= 0 && o->strength >= 0 && o->offset >= 0 &&
                 o->shepard >= 1 && (o->lumped_step == 0 || o->lumped_step == 1) &&
                 (o->no_slip == 0 || o->no_slip == 1) && o->diffusion >= 0 &&
                 (o->acoustic_step == 0 || o->acoustic_step == 1);
  if (!ok) usage(stderr);
  return ok ? 0 : 2;
}

#define CHECK(call)                                                               \
  do {                                                                            \
    const mfree_status_t st_ = (call);                                            \
    if (st_ != MFREE_SUCCESS) return ex_fail(ctx, "mfree_dam_break", st_, #call); \
  } while (0)

int main(int argc, char **argv) {
  options_t o = {0.05715, 5.0, 3.2, 0.5, 0.5, 10.0, 0.5, 0.05, 100.0, 0.0, 24, MFREE_INTEGRATOR_LEAPFROG,
                 MFREE_LUMP_GALERKIN, 0, 0, 0, MFREE_DATA_DIR "/martin_moyce_1952.csv", {0}};
  fc_run_init(&o.run, "dam_break", 0.25);
  const int parsed = parse(argc, argv, &o);
  if (parsed) return parsed < 0 ? 0 : parsed;
  if (fc_run_prepare(&o.run)) return 1;
  const char *out_dir = o.run.out;

  /* ---- geometry and initial state (003 Sect. 7.1; docs/papers.md, paper 003, choices 1) */
  fc_dam_t dam;
  if (fc_dam_init(&dam, o.a, o.nx, o.tank, o.offset)) return 1;
  const double a = dam.a, L = dam.L, d = dam.d, tscale = dam.tscale;
  const int nx = dam.nx, n = dam.n;
  double *y = calloc(5 * (size_t)n, sizeof *y), *m = malloc((size_t)n * sizeof *m);
  if (!y || !m) return 1;
  fc_water_block(y, m, n, 0, 0.0, nx, dam.nz, d, dam.H, dam.rho0, dam.kappa, dam.gamma, dam.g);

  mfree_context_t *ctx = NULL;
  if (mfree_context_create(&ctx) != MFREE_SUCCESS) return 1;
  mfree_system_t *sys = NULL;
  CHECK(mfree_system_create_fluid(ctx, 2, n, &sys));
  CHECK(fc_dam_configure(&dam, sys, m, o.mu, o.strength, (mfree_lumping_t)o.lumping, o.shepard));
  CHECK(mfree_system_set_lumped_mass_step(sys, o.lumped_step));
  CHECK(mfree_system_set_acoustic_step(sys, o.acoustic_step));
  CHECK(mfree_system_set_density_diffusion(sys, o.diffusion));
  if (o.no_slip) CHECK(fc_dummy_tank(sys, (int)lround(L / d), 1.5 * dam.H, d));
  double mass0 = 0.0;
  for (int q = 0; q < n; ++q) mass0 += m[q];

  /* ---- run ---- */
  double dT[64], dZ[64];
  const int ndata = fc_read_pairs(o.data, dT, dZ, 64);
  if (!ndata && !o.run.quiet)
    fprintf(stderr, "mfree_dam_break: no Martin & Moyce data at %s; the comparison is skipped\n", o.data);
  FILE *csv = fc_dam_csv(&o.run, &dam);
  if (!csv) return 1;
  fc_vtu_t vtu;
  if (fc_vtu_open(&vtu, fc_run_vtu_dir(&o.run), "dam_break", o.run.vtu_every)) return 1;
  const int nout = (int)floor(o.t_end / o.out_dt + 1e-9);
  double *fT = malloc((size_t)(nout + 1) * sizeof *fT), *fZ = malloc((size_t)(nout + 1) * sizeof *fZ);
  double *fZf = malloc((size_t)(nout + 1) * sizeof *fZf);
  int nf = 0;
  double t = 0.0, rho_lo = INFINITY, rho_hi = -INFINITY; /* densities at the output times */
  int64_t steps = 0;
  mfree_status_t run = MFREE_SUCCESS;
  ex_progress_t prog;
  ex_progress_init(&prog, o.run.quiet, 0.0, o.t_end / tscale);
  fc_density_watch_t watch;
  fc_density_watch_init(&watch, y, n, 2, t, &prog);
  const double clock0 = fc_seconds();
  for (int io = 0; io <= nout; ++io) {
    const double T_target = io * o.out_dt;
    if (io > 0) {
      run = fc_integrate_watched(sys, (mfree_integrator_t)o.scheme, y, &t, T_target / tscale, o.cfl, &watch, &steps);
      if (run != MFREE_SUCCESS) break;
    }
    double xmax = -1e300, xfloor = -1e300;
    for (int q = 0; q < n; ++q) {
      if (y[2 * q] > xmax) xmax = y[2 * q];
      if (y[2 * q + 1] < 1.5 * d && y[2 * q] > xfloor) xfloor = y[2 * q];
      rho_lo = fmin(rho_lo, y[4 * (size_t)n + q]);
      rho_hi = fmax(rho_hi, y[4 * (size_t)n + q]);
    }
    const double T = t * tscale, Z = (xmax + 0.5 * d) / a, Zf = (xfloor + 0.5 * d) / a;
    fT[nf] = T;
    fZf[nf] = Zf;
    fZ[nf++] = Z;
    fprintf(csv, "%.4f,%.5f,%.5f,%.6f,%lld\n", T, Z, Zf, t, (long long)steps);
    if (fc_vtu_maybe(&vtu, sys, T, t, n, y, NULL)) return 1;
    if (L - xmax < 2.0 * d) break; /* the front reached the far wall */
  }
  const double wall = fc_seconds() - clock0;
  ex_progress_done(&prog, "mfree_dam_break", t);
  fclose(csv);
  if (fc_vtu_close(&vtu)) return 1;
  char msg[1024] = "";
  const int exit_status = run == MFREE_SUCCESS ? 0 : fc_run_error(ctx, &o.run, run, "T", t * tscale, msg, sizeof msg);

  /* ---- mass: constant particle masses, none lost (the box), and the Galerkin lumped
   * masses summing to the total (003 eq 57) ---- */
  double mass_err = 0.0;
  CHECK(fc_mass_error(sys, y, n, m, mass0, &mass_err));

  /* ---- comparison with Martin & Moyce, plot ---- */
  fc_front_cmp_t cmp;
  fc_front_compare(nf, fT, fZ, ndata, dT, dZ, &cmp);
  fc_dam_plot(&o.run, &dam, o.data, ndata, o.t_end);

  fc_json_t js;
  fc_json_init(&js);
  const fc_dam_run_t info = {steps, wall, o.cfl, o.shepard, o.mu, t * tscale, o.scheme, run, msg};
  fc_dam_json(&js, &dam, nf, fT, fZ, fZf, &cmp, &info);
  fc_json_num(&js, "mass_rel_error", mass_err);
  const double rho_range[2] = {rho_lo, rho_hi};
  fc_json_table(&js, "density_range", 2, 1, rho_range);
  const double rho_steps[2] = {watch.lo, watch.hi};
  fc_json_table(&js, "density_range_steps", 2, 1, rho_steps);
  const double lowest[4] = {watch.t_lo * tscale, watch.q_lo, watch.x_lo[0], watch.x_lo[1]};
  fc_json_table(&js, "density_lowest", 4, 1, lowest);
  fc_json_int(&js, "lumped_mass_step", o.lumped_step);
  fc_json_int(&js, "acoustic_step", o.acoustic_step);
  fc_json_int(&js, "no_slip", o.no_slip);
  fc_json_num(&js, "diffusion", o.diffusion);
  if (fc_json_finish(&js, &o.run)) return 1;
  if (!o.run.json_stdout) {
    printf("dam break: a = %g m, %d particles, %lld steps, %.1f s\n", a, n, (long long)steps, wall);
    fc_dam_print(nf, fT, fZ, &cmp);
    printf("mass: relative error %.2e; densities %.1f to %.1f at the output times, %.1f to %.1f over every step\n"
           "(the lowest: particle %d at T = %.4f, x = %.5f m, z = %.5f m); output in %s\n",
           mass_err, rho_lo, rho_hi, watch.lo, watch.hi, watch.q_lo, watch.t_lo * tscale, watch.x_lo[0],
           watch.x_lo[1], out_dir);
  }
  mfree_system_destroy(&sys);
  mfree_context_destroy(&ctx);
  free(y);
  free(m);
  fc_dam_free(&dam);
  free(fT);
  free(fZ);
  free(fZf);
  return exit_status;
}
