/* A circular drop falling onto water at rest (paper 003 Sect. 7.4, Figs. 12-14;
 * docs/papers.md, paper 003, choices 2) by the Galerkin-SPH fluid of paper 003: mass,
 * momentum and free fall before the impact.
 *
 * Set-up (the paper gives the drop's speed, 2 m/s, rho0 = 1000, mu = 0.5 and 5,539
 * particles, no dimensions; these are ours). A tank of width --width W (default 0.4 m)
 * holds water at rest to depth Hp = 0.1 m; a drop of diameter --diameter D (default
 * 0.05 m) starts with its lowest point --gap G (default 0.1 m) above the surface, falling
 * at 2 m/s. Particles on a lattice of spacing d = Hp / --nz (default 36: 5,184 in the pool
 * and 253 in the drop, 5,437 in all), those of the drop at the lattice points inside the
 * circle, at rest density (no pressure in free fall) with velocity parameters (0, -2)
 * (a constant field is reproduced exactly, 003 eq 100); the pool's densities hydrostatic
 * (eq 65). h = 1.5 d, MLS linear, nodal integration, Galerkin lumped mass (eq 56),
 * leap-frog with CFL --cfl (default the paper's 0.5), wall particles at spacing d/3 set
 * back by d/2, r0 = 0.7 h, A = 10. The paper does not give kappa: the sound speed is ten
 * times the larger of sqrt(2 g Hp) (003 eq 125) and the impact speed sqrt(4 + 2 g G).
 *
 * Checks, every 0.002 s before the impact (the drop and the pool farther apart than the
 * support radius 2h, so that no shape function couples them):
 *  - mass: particle masses constant and the lumped masses summing to the total (eq 57);
 *  - momentum, gravity: the drop's momentum P_d = sum_i M_i v_i over its nodes (M_i the
 *    lumped masses) against P_d(0) + M_d g t; nothing but gravity acts on it, so the two
 *    agree to round-off (drop_momentum_dev, relative to M_d |v|);
 *  - momentum, walls: the rate of the whole fluid's momentum, sum_i M_i a_i from
 *    mfree_system_rhs, with the walls removed (a twin system) equals M g to round-off
 *    (internal_force_dev, relative to sum_i M_i |a_i|): the internal forces carry no
 *    momentum, so walls and gravity are its only sources, and the momentum the walls gave
 *    is P(t) - P(0) - M g t (wall_impulse). Its vertical part is compared with the pool's
 *    weight times t (the floor carries the pool at rest: wall_impulse_ratio =
 *    wall_impulse_z / pool_weight_impulse), its horizontal part with zero (the side walls
 *    push equally: wall_impulse_x_rel = |x| / |z| part);
 *  - free fall: the drop's centre of mass against z_c(0) - 2 t - g t^2 / 2, relative to
 *    the distance fallen (free_fall_dev; by the impact gravity makes about 9 % of it).
 * The run goes on past the impact to --tend (default 0.08 s; the paper's Fig. 14 is at
 * 0.0396 s).
 *
 * Output in --out DIR (default drop_out): drop.csv, drop.png (the centre of mass against
 * the free-fall curve; gnuplot), the JSON summary drop.json (--json: on stdout too) with
 * the numbers above, "impact_time", "contact_time_reference" (the drop's lowest point
 * reaching the surface in free fall), "centroid":[[t,z_c,z_free_fall],...] and
 * "momentum":[[t,P_x,P_z],...]. --vtu DIR: the VTU series every 0.004 s (point data
 * "fluid": 1 pool, 2 drop). A run that stops on an error says so and exits with status 3. */
#define _XOPEN_SOURCE 700
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "fluid_common.h"
#include "util.h"

static const double kG = 9.81, kRho0 = 1000.0, kGamma = 7.0, kHp = 0.1, kV0 = 2.0;

static void usage(FILE *f) {
  fprintf(f, "usage: mfree_drop [--nz N (36)] [--width W (0.4 m)] [--diameter D (0.05 m)] [--gap G (0.1 m)]\n"
             "                  [--tend T (0.08 s)] [--cfl C (0.5)] [--mu MU (0.5)]\n"
             "                  [run options; --vtu-every in s, default 0.004]\n");
  fc_run_usage(f);
}

typedef struct {
  mfree_system_t *sys, *twin; /* the fluid, and the same fluid without walls */
  int n, nd;                  /* particles; the drop is the last nd */
  double *lumped, *rate_twin;
} probe_t;

/* Momentum of the whole fluid (P) and of the drop (Pd), and the momentum rate without the
 * walls (Ft) and its scale, at state y. */
static mfree_status_t probe(probe_t *p, double t, const double *y, double P[2], double Pd[2], double Ft[2],
                            double *scale) {
  const int n = p->n;
  mfree_status_t st = fc_lumped_masses(p->sys, y, n, p->lumped);
  if (st == MFREE_SUCCESS) st = mfree_system_rhs(p->twin, t, y, p->rate_twin);
  if (st != MFREE_SUCCESS) return st;
  *scale = 0.0;
  for (int c = 0; c < 2; ++c) P[c] = Pd[c] = Ft[c] = 0.0;
  for (int q = 0; q < n; ++q)
    for (int c = 0; c < 2; ++c) {
      const double M = p->lumped[q], v = y[2 * n + 2 * q + c];
      P[c] += M * v;
      if (q >= n - p->nd) Pd[c] += M * v;
      Ft[c] += M * p->rate_twin[2 * n + 2 * q + c];
      *scale += fabs(M * p->rate_twin[2 * n + 2 * q + c]);
    }
  return MFREE_SUCCESS;
}

int main(int argc, char **argv) {
  int nz = 36;
  double width = 0.4, diameter = 0.05, gap = 0.1, t_end = 0.08, cfl = 0.5, mu = 0.5;
  fc_run_t ro;
  fc_run_init(&ro, "drop", 0.004);
  const fc_option_t opts[] = {{"--nz", 'i', &nz},   {"--width", 'd', &width}, {"--diameter", 'd', &diameter},
                              {"--gap", 'd', &gap}, {"--tend", 'd', &t_end},  {"--cfl", 'd', &cfl},
                              {"--mu", 'd', &mu},   {NULL, 0, NULL}};
  const int parsed = fc_parse(argc, argv, &ro, opts, usage);
  if (parsed) return parsed < 0 ? 0 : parsed;
  const double d = kHp / (nz > 0 ? nz : 1), R = 0.5 * diameter;
  if (nz < 4 || !(diameter >= 4 * d) || !(width >= diameter + 8 * d) || !(gap >= 4 * d) || !(t_end > 0) ||
      !(cfl > 0 && cfl <= 1) || !(mu >= 0)) {
    usage(stderr);
    return 2;
  }
  if (fc_run_prepare(&ro)) return 1;
  const double h = 1.5 * d, off = 0.5 * d, ds = d / 3.0;
  const int nx = (int)lround(width / d), np = nx * nz;
  const double W = nx * d, xc = 0.5 * W, zc0 = kHp + gap + R;
  const int nd = fc_water_drop(NULL, NULL, 0, 0, xc, zc0, R, d, kRho0, kV0), n = np + nd;
  const double v_impact = sqrt(kV0 * kV0 + 2.0 * kG * gap);
  const double c0 = 10.0 * fmax(sqrt(2.0 * kG * kHp), v_impact), kappa = kRho0 * c0 * c0 / kGamma;
  double *y = calloc(5 * (size_t)n, sizeof *y), *m = malloc((size_t)n * sizeof *m);
  int32_t *tag = malloc((size_t)n * sizeof *tag);
  probe_t pr = {NULL, NULL, n, nd, malloc((size_t)n * sizeof(double)), malloc(5 * (size_t)n * sizeof(double))};
  if (!y || !m || !tag || !pr.lumped || !pr.rate_twin) return 1;
  const int q = fc_water_block(y, m, n, 0, 0.0, nx, nz, d, kHp, kRho0, kappa, kGamma, kG);
  fc_water_drop(y, m, n, q, xc, zc0, R, d, kRho0, kV0);
  for (int k = 0; k < n; ++k) tag[k] = k < np ? 1 : 2;
  double mass0 = 0.0, mass_d = 0.0, zd0 = 0.0;
  for (int k = 0; k < n; ++k) mass0 += m[k];
  for (int k = np; k < n; ++k) mass_d += m[k], zd0 += m[k] * y[2 * k + 1];
  zd0 /= mass_d;
  const double mass_p = mass0 - mass_d;
  fc_walls_t w = {0, 0, NULL, NULL};
  const double wtop = zc0 + R + 2 * d;
  if (fc_walls_tank(&w, 0.0, W, wtop, off, ds)) return 1;

  mfree_context_t *ctx = NULL;
  if (mfree_context_create(&ctx) != MFREE_SUCCESS) return 1;
  mfree_status_t st;
#define CHECK(call) \
  if ((st = (call)) != MFREE_SUCCESS) return ex_fail(ctx, "mfree_drop", st, #call)
  const double g[2] = {0.0, -kG};
  CHECK(fc_fluid_create(ctx, n, m, &kRho0, 0, kappa, kGamma, mu, h, kG, &w, 10.0, &pr.sys));
  CHECK(fc_fluid_create(ctx, n, m, &kRho0, 0, kappa, kGamma, mu, h, kG, NULL, 0.0, &pr.twin));
  mfree_system_t *sys = pr.sys;
  const double lo[2] = {-off, -off}, hi[2] = {W + off, 10.0 * wtop};
  CHECK(mfree_system_set_box(sys, lo, hi));

  FILE *csv = fc_open_csv(&ro, "drop.csv");
  if (!csv) return 1;
  fprintf(csv, "# drop of diameter %g m at 2 m/s onto water %g m deep; %d + %d particles\n"
               "t,z_c,z_free_fall,gap,P_x,P_z,P_drop_z\n", diameter, kHp, np, nd);
  fc_vtu_t vtu;
  if (fc_vtu_open(&vtu, fc_run_vtu_dir(&ro), "drop", ro.vtu_every)) return 1;
  fc_series_t cen = {NULL, 0, 0}, mom = {NULL, 0, 0};
  ex_progress_t prog;
  ex_progress_init(&prog, ro.quiet, 0.0, t_end);
  const double out_dt = 0.002;
  double t = 0.0, P0[2] = {0, 0}, Pd0[2] = {0, 0}, Ft[2], scale;
  double dev_pd = 0.0, dev_int = 0.0, dev_ff = 0.0, t_impact = NAN, Pw_at[2] = {NAN, NAN};
  int64_t steps = 0;
  int before = 1;
  mfree_status_t run = MFREE_SUCCESS;
  const double clock0 = fc_seconds();
  for (int io = 0; t < t_end - 1e-12; ++io) {
    if (io > 0) {
      run = fc_integrate(sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, fmin(t_end, io * out_dt), cfl, &prog, &steps);
      if (run != MFREE_SUCCESS) break;
    }
    /* the gap between drop and pool, and the drop's centre of mass */
    double gap_now = INFINITY, zc = 0.0;
    for (int a = np; a < n; ++a) {
      zc += m[a] * y[2 * a + 1];
      for (int b = 0; b < np; ++b) {
        const double dx = y[2 * a] - y[2 * b], dz = y[2 * a + 1] - y[2 * b + 1];
        if (fabs(dz) < gap_now) gap_now = fmin(gap_now, hypot(dx, dz));
      }
    }
    zc /= mass_d;
    const double zff = zd0 - kV0 * t - 0.5 * kG * t * t;
    double P[2], Pd[2];
    CHECK(probe(&pr, t, y, P, Pd, Ft, &scale));
    if (io == 0) P0[0] = P[0], P0[1] = P[1], Pd0[0] = Pd[0], Pd0[1] = Pd[1];
    if (before && gap_now <= 2.0 * h) {
      before = 0;
      t_impact = t;
    }
    if (before) {
      const double vd = mass_d * (kV0 + kG * t);
      dev_pd = fmax(dev_pd, fmax(fabs(Pd[0] - Pd0[0]), fabs(Pd[1] - Pd0[1] - mass_d * g[1] * t)) / vd);
      dev_int = fmax(dev_int, fmax(fabs(Ft[0] - mass0 * g[0]), fabs(Ft[1] - mass0 * g[1])) / scale);
      if (t > 0) dev_ff = fmax(dev_ff, fabs((zd0 - zc) - (zd0 - zff)) / (zd0 - zff));
      for (int c = 0; c < 2; ++c) Pw_at[c] = P[c] - P0[c] - mass0 * g[c] * t;
    }
    fprintf(csv, "%.4f,%.7f,%.7f,%.6f,%.8g,%.8g,%.8g\n", t, zc, zff, gap_now, P[0], P[1], Pd[1]);
    const double rc[3] = {t, zc, zff}, rm[3] = {t, P[0], P[1]};
    if (fc_series_push(&cen, 3, rc) || fc_series_push(&mom, 3, rm)) return 1;
    if (fc_vtu_maybe(&vtu, sys, t, t, n, y, tag)) return 1;
  }
  const double wall = fc_seconds() - clock0;
  ex_progress_done(&prog, "mfree_drop", t);
  fclose(csv);
  if (fc_vtu_close(&vtu)) return 1;
  char msg[1024] = "";
  const int exit_status = run == MFREE_SUCCESS ? 0 : fc_run_error(ctx, &ro, run, "t", t, msg, sizeof msg);
  double mass_err = 0.0;
  CHECK(fc_mass_error(sys, y, n, m, mass0, &mass_err));
  /* the pre-impact sample the wall numbers refer to: the last one before the impact */
  double t_last = 0.0;
  for (int k = 0; k < cen.n / 3; ++k)
    if (!(cen.v[3 * k] >= t_impact)) t_last = cen.v[3 * k];
  const double weight = mass_p * kG * t_last;
  /* contact in free fall: the lowest point reaches the surface */
  const double t_contact = (-kV0 + sqrt(kV0 * kV0 + 2.0 * kG * gap)) / kG;

  char data[4096];
  FILE *f = fc_plot_begin(&ro, "drop", 800, 560, "t (s)", "height of the drop''s centre of mass (m)", data,
                          sizeof data);
  if (f) {
    fprintf(f, "set key bottom left\nset title 'Drop at 2 m/s onto water at rest, %d particles'\n"
               "set arrow from %g, graph 0 to %g, graph 1 nohead dt 3\n"
               "set label 'impact' at %g, graph 0.95\n"
               "plot '%s' using 1:2 with points pt 7 ps 0.6 title 'mfree (Galerkin SPH)', "
               "'%s' using 1:3 with lines lw 2 dt 2 title 'free fall z_0 - 2t - g t^2/2', "
               "%g with lines dt 4 title 'pool surface + radius'\n",
            n, t_impact, t_impact, t_impact, data, data, kHp + R);
    fc_plot_end(f, &ro, "drop");
  }

  fc_json_t js;
  fc_json_init(&js);
  fc_json_run(&js, run, msg, t, steps, n);
  fc_json_int(&js, "drop_particles", nd);
  fc_json_int(&js, "pool_particles", np);
  fc_json_num(&js, "mass_rel_error", mass_err);
  fc_json_num(&js, "impact_time", t_impact);
  fc_json_num(&js, "contact_time_reference", t_contact);
  fc_json_num(&js, "last_sample_before_impact", t_last);
  fc_json_num(&js, "drop_momentum_dev", dev_pd);
  fc_json_num(&js, "internal_force_dev", dev_int);
  fc_json_num(&js, "free_fall_dev", dev_ff);
  const double Iw2[2] = {Pw_at[0], Pw_at[1]};
  fc_json_table(&js, "wall_impulse", 2, 1, Iw2);
  fc_json_num(&js, "wall_impulse_z", Pw_at[1]);
  fc_json_num(&js, "pool_weight_impulse", weight);
  fc_json_num(&js, "wall_impulse_ratio", Pw_at[1] / weight);
  fc_json_num(&js, "wall_impulse_x_rel", fabs(Pw_at[0] / Pw_at[1]));
  fc_json_table(&js, "centroid", cen.n / 3, 3, cen.v);
  fc_json_table(&js, "momentum", mom.n / 3, 3, mom.v);
  fc_json_num(&js, "sound_speed", c0);
  fc_json_num(&js, "cfl", cfl);
  fc_json_num(&js, "wall_seconds", wall);
  if (fc_json_finish(&js, &ro)) return 1;
  if (!ro.json_stdout) {
    printf("drop: %d particles (%d in the drop), t = %.4f s, %lld steps, %.1f s\n", n, nd, t, (long long)steps,
           wall);
    printf("impact at t = %.4f s (free-fall contact %.4f s); before it:\n", t_impact, t_contact);
    printf("  drop momentum vs P0 + M g t: %.2e; internal forces without walls vs M g: %.2e\n", dev_pd, dev_int);
    printf("  centre of mass vs free fall: %.2e of the distance fallen\n", dev_ff);
    printf("  walls' impulse to t = %.4f s: (%.4g, %.4g) N s/m; pool weight x t: %.4g N s/m\n", t_last, Pw_at[0],
           Pw_at[1], weight);
    printf("mass error %.2e\n", mass_err);
  }
  mfree_system_destroy(&pr.sys);
  mfree_system_destroy(&pr.twin);
  mfree_context_destroy(&ctx);
  fc_walls_free(&w);
  fc_series_free(&cen);
  fc_series_free(&mom);
  free(pr.lumped);
  free(pr.rate_twin);
  free(y);
  free(m);
  free(tag);
  return exit_status;
}
