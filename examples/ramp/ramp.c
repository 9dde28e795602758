/* Breaking dam down a ramp (paper 003 Sect. 7.1, Figs. 5-7; docs/papers.md, paper 003,
 * choices 1) by the Galerkin-SPH fluid of paper 003.
 *
 * Set-up. A square water column of side H = 0.1 m (--nx particles across, 50 = the
 * paper's 2500) stands on a short floor against the left wall; at t = 0 the gate on its
 * right is gone and the water runs down a ramp of slope 0.5 (rise/run, 26.57 deg; the
 * paper's "slope 0.5" is ambiguous) that starts at the column's right edge, drops 0.3 m
 * and meets a horizontal floor that ends at a wall at x = 1 m. Constants of 003: rho0 =
 * 1000, gamma = 7, kappa = 100 rho0 (2 g H) / gamma (eq 125), mu = 0.5 (Fig. 7),
 * hydrostatic initial densities (eq 65), h = 1.5 d, MLS linear, nodal integration,
 * Galerkin lumped mass, leap-frog with CFL 0.5 (eq 120), wall particles at spacing d/3
 * set back by d/2 from the fluid's edge, r0 = 0.7 h, A = 10 (eqs 122-124).
 *
 * The paper reports particle plots only (Fig. 7 at t = 0.152 s). This program checks
 * what can be checked: the run completes past 0.152 s with no non-finite state, no
 * particle crosses a wall (every particle stays above the floor and ramp and inside the
 * side walls), the mass is exact, and the front has run down the ramp.
 *
 * Output in --out DIR (default ramp_out): the JSON summary ramp.json (--json: on stdout
 * too) {"status":..,"error":..,"t":..,"steps":..,"particles":..,"mass_rel_error":..,
 * "front_x":..,"min_clearance":..,"wall_seconds":..}: min_clearance is the smallest
 * distance of a particle above the floor/ramp line (m; negative = a particle crossed a
 * wall). With --vtu DIR (or --vtu-every T): ramp.pvd and ramp_NNNN.vtu every 0.019 s. A
 * run that stops on an error says so on stderr and exits with status 3. */
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

static const double kG = 9.81, kRho0 = 1000.0, kGamma = 7.0, kH = 0.1, kSlope = 0.5, kDrop = 0.3,
                    kEnd = 1.0;

/* Height of the floor/ramp line (the fluid's bottom edge) at x. */
static double ground(double x) {
  if (x <= kH) return 0.0;
  if (x <= kH + kDrop / kSlope) return -kSlope * (x - kH);
  return -kDrop;
}

static void usage(FILE *f) {
  fprintf(f, "usage: mfree_ramp [--nx N (50)] [--tend T (0.2 s)] [--cfl C (0.5)] [--mu MU (0.5)]\n"
             "                  [run options; --vtu-every in s, default 0.019]\n");
  fc_run_usage(f);
}

int main(int argc, char **argv) {
  int nx = 50;
  double t_end = 0.2, cfl = 0.5, mu = 0.5;
  fc_run_t ro;
  fc_run_init(&ro, "ramp", 0.019);
  const fc_option_t opts[] = {
      {"--nx", 'i', &nx}, {"--tend", 'd', &t_end}, {"--cfl", 'd', &cfl}, {"--mu", 'd', &mu}, {NULL, 0, NULL}};
  const int parsed = fc_parse(argc, argv, &ro, opts, usage);
  if (parsed) return parsed < 0 ? 0 : parsed;
  if (nx < 2 || !(t_end > 0) || !(cfl > 0 && cfl <= 1) || !(mu >= 0)) {
    usage(stderr);
    return 2;
  }
  if (fc_run_prepare(&ro)) return 1;
  const double d = kH / nx, h = 1.5 * d, off = 0.5 * d, ds = d / 3.0;
  const double kappa = 100.0 * kRho0 * 2.0 * kG * kH / kGamma; /* 003 eq 125 */
  const int n = nx * nx;
  double *y = calloc(5 * (size_t)n, sizeof *y), *m = malloc((size_t)n * sizeof *m);
  if (!y || !m) return 1;
  fc_water_block(y, m, n, 0, 0.0, nx, nx, d, kH, kRho0, kappa, kGamma, kG);
  /* walls, set back by off along their normals: left wall, floor, ramp, lower floor, end wall */
  const double top = 3.0 * kH, nr = sqrt(1.0 + kSlope * kSlope), xr = kH + kDrop / kSlope;
  const double sx = off * kSlope / nr, sz = off / nr; /* ramp offset along -(slope, 1)/nr */
  fc_walls_t w = {0, 0, NULL, NULL};
  int bad = fc_walls_segment(&w, -off, top, -off, -off, ds, 1, 0, 0);
  bad |= fc_walls_segment(&w, -off, -off, kH - sx, -off, ds, 0, 1, 1);
  bad |= fc_walls_segment(&w, kH - sx, -off, xr - sx, -kDrop - sz, ds, kSlope, 1, 1);
  bad |= fc_walls_segment(&w, xr - sx, -kDrop - off, kEnd + off, -kDrop - off, ds, 0, 1, 0);
  bad |= fc_walls_segment(&w, kEnd + off, -kDrop - off, kEnd + off, top, ds, -1, 0, 1);
  if (bad) return 1;

  mfree_context_t *ctx = NULL;
  if (mfree_context_create(&ctx) != MFREE_SUCCESS) return 1;
  mfree_system_t *sys = NULL;
  mfree_status_t st;
#define CHECK(call) \
  if ((st = (call)) != MFREE_SUCCESS) return ex_fail(ctx, "mfree_ramp", st, #call)
  CHECK(fc_fluid_create(ctx, n, m, &kRho0, 0, kappa, kGamma, mu, h, kG, &w, 10.0, &sys));
  const double lo[2] = {-off, -kDrop - off}, hi[2] = {kEnd + off, 10.0 * kH};
  CHECK(mfree_system_set_box(sys, lo, hi));
  double mass0 = 0.0;
  for (int q = 0; q < n; ++q) mass0 += m[q];

  fc_vtu_t vtu;
  if (fc_vtu_open(&vtu, fc_run_vtu_dir(&ro), "ramp", ro.vtu_every)) return 1;
  ex_progress_t prog;
  ex_progress_init(&prog, ro.quiet, 0.0, t_end);
  double t = 0.0;
  int64_t steps = 0;
  mfree_status_t run = MFREE_SUCCESS;
  const double clock0 = fc_seconds();
  if (fc_vtu_maybe(&vtu, sys, t, t, n, y, NULL)) return 1;
  while (t < t_end && run == MFREE_SUCCESS) {
    const double target = vtu.pvd ? fmin(t_end, vtu.next) : t_end;
    run = fc_integrate(sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, target, cfl, &prog, &steps);
    if (fc_vtu_maybe(&vtu, sys, t, t, n, y, NULL)) return 1;
  }
  const double wall = fc_seconds() - clock0;
  ex_progress_done(&prog, "mfree_ramp", t);
  if (fc_vtu_close(&vtu)) return 1;
  char msg[1024] = "";
  const int exit_status = run == MFREE_SUCCESS ? 0 : fc_run_error(ctx, &ro, run, "t", t, msg, sizeof msg);

  double front = -1e300, clear = 1e300;
  for (int q = 0; q < n; ++q) {
    front = fmax(front, y[2 * q]);
    clear = fmin(clear, y[2 * q + 1] - ground(y[2 * q]));
    clear = fmin(clear, y[2 * q]);          /* left wall */
    clear = fmin(clear, kEnd - y[2 * q]);   /* end wall */
  }
  double merr = 0.0;
  CHECK(fc_mass_error(sys, y, n, m, mass0, &merr));
  fc_json_t js;
  fc_json_init(&js);
  fc_json_run(&js, run, msg, t, steps, n);
  fc_json_num(&js, "mass_rel_error", merr);
  fc_json_num(&js, "front_x", front);
  fc_json_num(&js, "min_clearance", clear);
  fc_json_num(&js, "cfl", cfl);
  fc_json_num(&js, "wall_seconds", wall);
  if (fc_json_finish(&js, &ro)) return 1;
  if (!ro.json_stdout) {
    printf("ramp: %d particles, t = %.4f s, %lld steps, %.1f s\n", n, t, (long long)steps, wall);
    printf("front at x = %.4f m; smallest clearance above floor/ramp/walls %.2e m; mass error %.2e\n", front, clear,
           merr);
    if (vtu.count) printf("VTU series: %s/ramp.pvd\n", vtu.dir);
  }
  mfree_system_destroy(&sys);
  mfree_context_destroy(&ctx);
  fc_walls_free(&w);
  free(y);
  free(m);
  return exit_status;
}
