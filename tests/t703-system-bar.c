/* Paper 001 Sect. 6.4, wave in a bar (E = 200 GPa, rho = 7865 kg/m3, L = 0.1 m,
 * -1 GPa for 3 us at the right end, left end free, 800 particles), by SSPH collocation
 * (revised super Gauss a = 1.6, h = 1.5 dx, quadratic basis) and central differences:
 * wave speed within 2 % of sqrt(E/rho) = 5.04 mm/us (the paper's "5 mm/us"), pulse
 * amplitude within 5 % of 1 GPa, and the stress-free left end reflects the compressive
 * pulse as a tensile one (paper Fig. 16). Also the elastodynamic system's bad input. */
#include <math.h>
#include <stdlib.h>

#include "testutil.h"

static mfree_context_t *ctx;
static int setup(void **s) { (void)s; return mfree_context_create(&ctx) != MFREE_SUCCESS; }
static int teardown(void **s) { (void)s; return mfree_context_destroy(&ctx) != MFREE_SUCCESS; }

enum { N = 800 };
static const double L = 0.1, E = 200e9, RHO = 7865.0, T0 = 3e-6;
static double X[N];

static void traction(void *u, const double *x, double *v) {
  (void)u;
  v[0] = x[0] > 0.5 * L ? -1e9 : 0.0; /* right end: compressive; left end: free */
}
static double pulse(void *u, double t) {
  (void)u;
  return t <= T0 ? 1.0 : 0.0;
}

static void test_wave(void **s) {
  (void)s;
  mfree_test_bar_t b = mfree_test_bar_create(ctx, N, L, E, RHO, X, traction, pulse);
  int32_t neq = 0;
  assert_ok(ctx, mfree_system_get_size(b.sys, &neq));
  assert_int_equal(neq, 2 * N);
  double *y = calloc((size_t)neq, sizeof(double)), sig[N];
  double t = 0.0;
  int64_t ns = 0;
  const double c = sqrt(E / RHO);
  /* before the reflection (transit time L/c = 19.8 us) */
  assert_ok(ctx, mfree_system_integrate(b.sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, 10e-6, 0.5, 0.0, NULL, NULL, &ns));
  assert_true(fabs(t - 10e-6) < 1e-15);
  assert_ok(ctx, mfree_system_get_stress(b.sys, t, y, sig));
  int front = -1;
  for (int i = 0; i < N && front < 0; ++i)
    if (sig[i] < -0.5e9) front = i; /* leftmost point past half the amplitude */
  assert_true(front > 0);
  const double speed = (L - X[front]) / t;
  if (fabs(speed - c) > 0.02 * c) fail_msg("wave speed %.4f mm/us, exact %.4f", speed * 1e-3, c * 1e-3);
  /* plateau behind the front: the analytic -1 GPa on L - c t < x < L - c (t - 3 us),
   * 3 mm away from both fronts (their oscillations) */
  double sum = 0.0;
  int cnt = 0;
  for (int i = 0; i < N; ++i)
    if (X[i] > L - c * t + 3e-3 && X[i] < L - c * (t - T0) - 3e-3) {
      sum += sig[i];
      ++cnt;
    }
  assert_true(cnt > 20);
  if (fabs(sum / cnt + 1e9) > 0.05e9) fail_msg("pulse amplitude %.4f GPa", sum / cnt * 1e-9);
  /* ahead of the pulse the bar is at rest */
  for (int i = 0; i < N; ++i)
    if (X[i] < L - c * t - 5e-3) assert_true(fabs(sig[i]) < 0.02e9);
  /* after the reflection at the free end the pulse is tensile and travels right */
  assert_ok(ctx, mfree_system_integrate(b.sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, 30e-6, 0.5, 0.0, NULL, NULL, &ns));
  assert_ok(ctx, mfree_system_get_stress(b.sys, t, y, sig));
  double smax = -1e300, smin = 1e300, xmax = 0.0;
  for (int i = 0; i < N; ++i) {
    if (sig[i] > smax) {
      smax = sig[i];
      xmax = X[i];
    }
    smin = fmin(smin, sig[i]);
  }
  assert_true(smax > 0.9e9);   /* tensile */
  assert_true(smin > -0.35e9); /* no compressive pulse left */
  const double expect = c * (t - L / c) - 0.5 * c * T0; /* centre of the reflected pulse */
  assert_true(fabs(xmax - expect) < 0.6 * c * T0);
  free(y);
  mfree_test_bar_destroy(&b);
}

static void test_bad_input(void **s) {
  (void)s;
  mfree_test_bar_t b = mfree_test_bar_create(ctx, N, L, E, RHO, X, traction, pulse);
  mfree_system_t *sys = NULL;
  assert_error(ctx, mfree_system_create_elastodynamic(ctx, NULL, RHO, &sys), MFREE_ERR_NULL, "assembler");
  assert_error(ctx, mfree_system_create_elastodynamic(ctx, b.as, -1.0, &sys), MFREE_ERR_ARG, "density");
  /* a Galerkin assembler is not a collocation operator */
  mfree_assembler_t *gal = NULL;
  assert_ok(ctx, mfree_assembler_create(ctx, b.a, NULL, MFREE_FORM_LAPLACE, &gal));
  assert_ok(ctx, mfree_assembler_setup(gal));
  assert_error(ctx, mfree_system_create_elastodynamic(ctx, gal, RHO, &sys), MFREE_ERR_UNSUPPORTED, "collocation");
  mfree_assembler_destroy(&gal);
  /* fluid-only calls on an elastic system, elastic-only calls on a fluid */
  const double one = 1.0;
  assert_error(ctx, mfree_system_set_masses(b.sys, &one, 0), MFREE_ERR_UNSUPPORTED, "not a fluid");
  mfree_system_t *fl = NULL;
  assert_ok(ctx, mfree_system_create_fluid(ctx, 2, 4, &fl));
  assert_error(ctx, mfree_system_set_load_history(fl, pulse, NULL), MFREE_ERR_UNSUPPORTED, "not elastodynamic");
  mfree_system_destroy(&fl);
  /* a fixed step above the CFL limit dx/c */
  double *y = calloc(2 * N, sizeof(double)), t = 0.0;
  int64_t ns;
  assert_error(ctx, mfree_system_integrate(b.sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, 1e-6, 0.0, 1e-6, NULL, NULL, &ns),
               MFREE_FAIL_CFL, "CFL");
  assert_true(t == 0.0);
  assert_error(ctx, mfree_system_integrate(b.sys, MFREE_INTEGRATOR_PREDICTOR_CORRECTOR, y, &t, 1e-6, 0.5, 0.0, NULL,
                                           NULL, &ns),
               MFREE_ERR_UNSUPPORTED, "central-difference");
  y[5] = NAN;
  assert_error(ctx, mfree_system_integrate(b.sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, 1e-6, 0.5, 0.0, NULL, NULL, &ns),
               MFREE_FAIL_NONFINITE, "particle 5");
  free(y);
  /* the system keeps its assembler alive */
  mfree_assembler_destroy(&b.as);
  double *y2 = calloc(2 * N, sizeof(double)), yd[2 * N];
  assert_ok(ctx, mfree_system_rhs(b.sys, 0.0, y2, yd));
  free(y2);
  mfree_test_bar_destroy(&b);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_wave),
      cmocka_unit_test(test_bad_input),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
