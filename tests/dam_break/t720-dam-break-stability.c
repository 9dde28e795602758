/* Stable time integration of paper 003's dam break at the paper's CFL number 0.5: the set-up
 * of examples/dam_break (a column a x 2a, nx particles across a, h = 1.5 d, kappa from eq
 * 125, mu = 0.5, hydrostatic densities, wall particles at d/3 set back by d/2, r0 = 0.7 h,
 * A = 10), in a tank 16a long, to T = t sqrt(2 g / a) = 8 (the surge is then about 4a short
 * of the far wall).
 *
 * Test 1 (everywhere): the predictor-corrector with the paper's settings holds the bottom
 * row on the floor. It decides the wall force's switch (003 eq 123) once per step with the
 * starting v_hat; decided at the predicted state, the bottom row sank through the floor (a
 * particle left the tank at T = 0.36, nx = 24).
 *
 * Tests 2-3 (argument "long", optimised builds): leap-frog and the predictor-corrector to T
 * = 8 at CFL 0.5, with the Shepard fallback above a moment-matrix condition estimate of 20
 * (mfree_system_set_shepard_condition; 003 Sect. 6 gives no tolerance). With the default 100
 * both schemes stop with a negative density between T = 2.7 and 6.4 (nx = 24, depending on
 * where the integration calls end): sites of estimate 20-100 (the surge tip, thin sheets,
 * particles crowding at the left wall) have shape-function gradients up to twice a lattice
 * corner's, which the CFL step h / max(c + |v|) does not see, and their velocities grow
 * in an odd-even (period-two) mode. At every output (T in steps of 0.25) no particle has
 * left the tank (the box), the densities lie within 10 % of rho0, the particle masses are
 * the initial ones and the Galerkin lumped masses sum to the total mass (003 eq 57); at T
 * = 8 the front lies between 10a and 13a (Martin & Moyce: 12.0a at T = 8.03). The
 * argument "long48" runs the same at nx = 48 (4,608 particles). nx = 96 is measured by
 * hand (README, CHANGELOG).
 *
 * The lumped-mass step (arguments "step", "lumped", "lumped48"; mfree_system_set_lumped_mass_step):
 * the cause of the failures with the default Shepard condition is the Galerkin lumped
 * mass m_i (003 eq 56), which falls to a third of the particle mass next to rows of
 * condition 50-100 (their N_i(x_k) < 0), so that the operator's largest frequency omega
 * grows as sqrt(M_i / m_i) and dt omega crosses leap-frog's limit 2 (docs/time-integration.md).
 * "step": the step with the option is cfl h / max_i c_i sqrt(max(1, M_i / m_i)) at rest, with m_i
 * from mfree_system_assemble_mass, and eq 120's without it or with the physical lumping.
 * "lumped": both schemes to T = 8 at nx = 24 with the library's default Shepard condition 100
 * and the option, with the checks of tests 2-3; "lumped48" ("lumped48 pc"): leap-frog (the
 * predictor-corrector) the same at nx = 48.
 *
 * The acoustic step (arguments "acoustic", "acoustic48" ["pc"]; mfree_system_set_acoustic_step):
 * the step also at most 1.5 / omega, omega the largest frequency of the linearised acoustic
 * operator (M_L^-1 B^T M C B, power iteration). With the lumped-mass step alone the
 * predictor-corrector stops at nx = 96 (T = 3.14): particles crowded against the left wall
 * (two columns within one spacing) have rows whose gradients put omega dt at 1.8-2.0 with
 * ordinary lumped masses, and a period-two mode grows there, the wall force's switch
 * toggling with it. "acoustic": both schemes to T = 8 at nx = 24 with the default
 * Shepard condition, the option alone, with the checks of tests 2-3; "acoustic48"
 * ("acoustic48 pc"): leap-frog (the predictor-corrector) the same at nx = 48. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"

static const double G = 9.81, RHO0 = 1000.0, GAMMA = 7.0, A = 0.05715, TANK = 16.0, CFL = 0.5;

typedef struct {
  int nx, n;
  double d, off, L;
  double *y, *m;
  mfree_context_t *ctx;
  mfree_system_t *sys;
} dam_t;

static int g_acoustic = 0; /* the acoustic step in every system dam_create makes */

static void dam_create(dam_t *s, int nx, double max_cond, int lumped_step) {
  memset(s, 0, sizeof *s);
  const int nz = 2 * nx, n = nx * nz;
  const double H = 2.0 * A, L = TANK * A, d = A / nx, h = 1.5 * d;
  const double kappa = 100.0 * RHO0 * 2.0 * G * H / GAMMA; /* 003 eq 125 */
  s->nx = nx, s->n = n, s->d = d, s->L = L, s->off = 0.5 * d;
  s->y = calloc(5 * (size_t)n, sizeof *s->y);
  s->m = malloc((size_t)n * sizeof *s->m);
  assert_non_null(s->y);
  assert_non_null(s->m);
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nx; ++i) {
      const int q = j * nx + i;
      const double z = (j + 0.5) * d;
      s->y[2 * q] = (i + 0.5) * d;
      s->y[2 * q + 1] = z;
      s->y[4 * (size_t)n + q] = RHO0 * pow(1.0 + RHO0 * G * (H - z) / kappa, 1.0 / GAMMA); /* 003 eq 65 */
      s->m[q] = s->y[4 * (size_t)n + q] * d * d;
    }
  /* walls as in the example: floor and both ends, spacing d/3, set back by d/2 */
  double *wx = NULL, *wn = NULL;
  const int nw = mfree_test_tank_walls(L, d, s->off, 1.5 * H, &wx, &wn);
  assert_ok(NULL, mfree_context_create(&s->ctx));
  mfree_context_t *ctx = s->ctx;
  s->sys = mfree_test_fluid_create(ctx, n, s->m, RHO0, kappa, GAMMA, 0.5, h);
  const double g[2] = {0.0, -G};
  assert_ok(ctx, mfree_system_set_gravity(s->sys, g));
  assert_ok(ctx, mfree_system_set_walls(s->sys, nw, wx, wn, 0.7 * h, 10.0));
  const double lo[2] = {-s->off, -s->off}, hi[2] = {L + s->off, 10.0 * H};
  assert_ok(ctx, mfree_system_set_box(s->sys, lo, hi)); /* crossing a wall fails the run */
  if (max_cond > 0) assert_ok(ctx, mfree_system_set_shepard_condition(s->sys, max_cond));
  if (lumped_step) assert_ok(ctx, mfree_system_set_lumped_mass_step(s->sys, 1));
  if (g_acoustic) assert_ok(ctx, mfree_system_set_acoustic_step(s->sys, 1));
  free(wx);
  free(wn);
}

static void dam_destroy(dam_t *s) {
  mfree_system_destroy(&s->sys);
  mfree_context_destroy(&s->ctx);
  free(s->y);
  free(s->m);
}

/* Integrate to T (units of sqrt(a / 2g)); fails the test with the library's message. */
static void dam_run(dam_t *s, mfree_integrator_t scheme, double *t, double T) {
  const double ts = sqrt(2.0 * G / A);
  int64_t ns = 0;
  const mfree_status_t st = mfree_system_integrate(s->sys, scheme, s->y, t, T / ts, CFL, 0.0, NULL, NULL, &ns);
  if (st != MFREE_SUCCESS) {
    char msg[512] = "";
    mfree_context_get_last_error(s->ctx, NULL, msg, sizeof msg);
    fail_msg("nx = %d, %s: stopped at T = %.3f: %s", s->nx,
             scheme == MFREE_INTEGRATOR_LEAPFROG ? "leap-frog" : "predictor-corrector", *t * ts, msg);
  }
}

/* The predictor-corrector with the paper's settings (Shepard tolerance 100) to T = 1: the
 * bottom row stays on the floor, about d above the wall particles. */
static void test_pc_bottom_row(void **state) {
  (void)state;
  dam_t s;
  dam_create(&s, 24, 0.0, 0);
  double t = 0.0, zmin = INFINITY;
  for (int k = 1; k <= 10; ++k) {
    dam_run(&s, MFREE_INTEGRATOR_PREDICTOR_CORRECTOR, &t, 0.1 * k);
    for (int q = 0; q < s.n; ++q) zmin = fmin(zmin, s.y[2 * q + 1] + s.off);
  }
  print_message("predictor-corrector, nx = 24, to T = 1: lowest particle %.3f d above the wall particles\n",
                zmin / s.d);
  assert_true(zmin > 0.8 * s.d); /* measured 0.98 d; the old switch: 0.17 d at T = 0.358, then out */
  dam_destroy(&s);
}

static void long_run(int nx, mfree_integrator_t scheme, double max_cond, int lumped_step) {
  dam_t s;
  dam_create(&s, nx, max_cond, lumped_step);
  double *m0 = malloc((size_t)s.n * sizeof *m0);
  assert_non_null(m0);
  memcpy(m0, s.m, (size_t)s.n * sizeof *m0);
  double t = 0.0, rmin = INFINITY, rmax = 0.0, mass_diff = 0.0;
  for (int k = 1; k <= 32; ++k) {
    dam_run(&s, scheme, &t, 0.25 * k);
    for (int q = 0; q < s.n; ++q) {
      const double r = s.y[4 * (size_t)s.n + q];
      rmin = fmin(rmin, r), rmax = fmax(rmax, r);
      assert_true(s.y[2 * q] > -s.off && s.y[2 * q] < s.L + s.off && s.y[2 * q + 1] > -s.off);
    }
    mass_diff = fmax(mass_diff, mfree_test_lumped_mass_rel_diff(s.ctx, s.sys, s.y, s.m, s.n));
  }
  double xmax = -INFINITY;
  for (int q = 0; q < s.n; ++q) xmax = fmax(xmax, s.y[2 * q]);
  const double front = (xmax + 0.5 * s.d) / A;
  print_message("%s, nx = %d, CFL 0.5, Shepard condition %g%s%s, to T = 8: densities %.1f-%.1f, front %.2f a, lumped mass sum %.1e\n",
                scheme == MFREE_INTEGRATOR_LEAPFROG ? "leap-frog" : "predictor-corrector", nx, max_cond,
                lumped_step ? ", lumped-mass step" : "", g_acoustic ? ", acoustic step" : "", rmin, rmax, front,
                mass_diff);
  assert_true(rmin > 0.9 * RHO0 && rmax < 1.1 * RHO0);
  assert_memory_equal(s.m, m0, (size_t)s.n * sizeof *m0);
  assert_true(mass_diff <= 1e-12);
  assert_true(front > 10.0 && front < 13.0);
  free(m0);
  dam_destroy(&s);
}

static int g_nx = 24, g_lumped = 0;
static void test_leapfrog_long(void **state) {
  (void)state;
  long_run(g_nx, MFREE_INTEGRATOR_LEAPFROG, g_lumped || g_acoustic ? 100.0 : 20.0, g_lumped);
}
static void test_pc_long(void **state) {
  (void)state;
  long_run(g_nx, MFREE_INTEGRATOR_PREDICTOR_CORRECTOR, g_lumped || g_acoustic ? 100.0 : 20.0, g_lumped);
}

static int stop_first(void *user, int64_t step, double t, double dt) {
  (void)step;
  (void)t;
  *(double *)user = dt;
  return 1;
}

/* The first step's length (the column at rest) with and without the lumped-mass step. */
static double first_step(dam_t *s, int lumped_step, mfree_lumping_t lump) {
  assert_ok(s->ctx, mfree_system_set_lumped_mass_step(s->sys, lumped_step));
  assert_ok(s->ctx, mfree_system_set_lumping(s->sys, lump));
  double *y = malloc(5 * (size_t)s->n * sizeof *y), t = 0.0, dt = 0.0;
  assert_non_null(y);
  memcpy(y, s->y, 5 * (size_t)s->n * sizeof *y);
  int64_t ns = 0;
  assert_ok(s->ctx, mfree_system_integrate(s->sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, 1.0, CFL, 0.0, stop_first, &dt, &ns));
  assert_int_equal(ns, 1);
  free(y);
  return dt;
}

static void test_lumped_step_formula(void **state) {
  (void)state;
  dam_t s;
  dam_create(&s, 12, 0.0, 0);
  const int n = s.n;
  const double h = 1.5 * s.d, H = 2.0 * A, kappa = 100.0 * RHO0 * 2.0 * G * H / GAMMA;
  double *Mi = malloc((size_t)n * sizeof *Mi), cmax = 0.0, smax = 0.0, rmin = INFINITY;
  assert_non_null(Mi);
  mfree_test_lumped_masses(s.ctx, s.sys, s.y, 2, n, Mi); /* Galerkin lumping (eq 56), the default */
  for (int q = 0; q < n; ++q) {
    const double c = sqrt(GAMMA * kappa / s.y[4 * (size_t)n + q]), r = Mi[q] / s.m[q]; /* 003 eq 121 */
    cmax = fmax(cmax, c);
    smax = fmax(smax, r < 1.0 ? c * sqrt(1.0 / r) : c);
    rmin = fmin(rmin, r);
  }
  const double dt120 = CFL * h / cmax, dtm = CFL * h / smax;
  const double off = first_step(&s, 0, MFREE_LUMP_GALERKIN), on = first_step(&s, 1, MFREE_LUMP_GALERKIN);
  const double phys = first_step(&s, 1, MFREE_LUMP_PHYSICAL);
  print_message("column at rest, nx = 12: smallest m_i / M_i %.3f; step %.4e (eq 120), %.4e (lumped-mass step), "
                "%.4e (lumped-mass step, physical lumping)\n", rmin, off, on, phys);
  assert_true(rmin < 0.9); /* the corners and edges: the option changes the step here */
  assert_true(fabs(off - dt120) <= 1e-12 * dt120);
  assert_true(fabs(on - dtm) <= 1e-12 * dtm);
  assert_true(on < 0.99 * off);
  assert_true(phys == off);
  free(Mi);
  dam_destroy(&s);
}

int main(int argc, char **argv) {
  const int longrun = argc > 1 && (!strncmp(argv[1], "long", 4) || !strncmp(argv[1], "lumped", 6) ||
                                   !strncmp(argv[1], "acoustic", 8));
  if (argc > 1 && (!strcmp(argv[1], "long48") || !strcmp(argv[1], "lumped48"))) g_nx = 48;
  g_lumped = argc > 1 && !strncmp(argv[1], "lumped", 6);
  g_acoustic = argc > 1 && !strncmp(argv[1], "acoustic", 8);
  const struct CMUnitTest short_tests[] = {cmocka_unit_test(test_pc_bottom_row)};
  const struct CMUnitTest step_tests[] = {cmocka_unit_test(test_lumped_step_formula)};
  const struct CMUnitTest long_tests[] = {cmocka_unit_test(test_leapfrog_long), cmocka_unit_test(test_pc_long)};
  if (argc > 1 && !strcmp(argv[1], "step")) return cmocka_run_group_tests(step_tests, NULL, NULL);
  if (argc > 1 && (!strcmp(argv[1], "lumped48") || !strcmp(argv[1], "acoustic48"))) {
    /* one scheme per run: each a few minutes of one core */
    g_nx = 48;
    const struct CMUnitTest lf[] = {cmocka_unit_test(test_leapfrog_long)}, pc[] = {cmocka_unit_test(test_pc_long)};
    return argc > 2 && !strcmp(argv[2], "pc") ? cmocka_run_group_tests(pc, NULL, NULL) : cmocka_run_group_tests(lf, NULL, NULL);
  }
  return longrun ? cmocka_run_group_tests(long_tests, NULL, NULL) : cmocka_run_group_tests(short_tests, NULL, NULL);
}
