/* The acoustic step (mfree_system_set_acoustic_step) against an independent largest
 * frequency: its step is 1.5 / omega, omega^2 the largest eigenvalue of the linearised
 * acoustic operator, which the test finds from the system's own right-hand side.
 *
 * A free patch of water (10 x 8 particles, spacing d = 1 cm, h = 1.5 d, rho0 = 1000,
 * gamma = 7, kappa for a sound speed of 10 m/s, mu = 0, no gravity, no walls) at rest at
 * density rho0: the velocity rates depend on the densities only and the density rates on
 * the velocities only, both linearly about this state, so the Jacobian blocks J_vr =
 * d(dv/dt)/d(rho) and J_rv = d(drho/dt)/d(v) (central differences of mfree_system_rhs;
 * drho/dt is linear in v, dv/dt is p(rho) V through the Tait law, whose derivative at rho0
 * is the gamma kappa / rho0 of eq 121) give the operator -J_vr J_rv = M_L^-1 B^T M C B.
 * Its largest eigenvalue comes from a dense power iteration run to convergence (its
 * eigenvalues are real and non-negative: it is similar to a symmetric matrix).
 *
 * The integrator at CFL 1 (eq 120's step is then above 1.5 / omega: omega h / c = 2.5 at
 * a free corner) takes steps of 1.5 / omega_lib, omega_lib the library's estimate from
 * below (power iteration from a fixed vector, then two iterations a step): dt omega must
 * lie in [1.5 (1 - 1e-9), 1.5 (1 + 1e-2)] at the first step and within 2e-4 of 1.5 after 40
 * steps at rest. Without the option the step is eq 120's (cfl h / c) exactly. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"

enum { NXP = 10, NZP = 8, N = NXP * NZP, NY = 5 * N };
static const double RHO0 = 1000.0, GAMMA = 7.0, D = 0.01, C0 = 10.0;

typedef struct {
  double dt[64];
  int n;
} steps_t;

static int record(void *user, int64_t step, double t, double dt) {
  (void)step;
  (void)t;
  steps_t *s = user;
  if (s->n < 64) s->dt[s->n++] = dt;
  return 0;
}

static mfree_system_t *patch(mfree_context_t *ctx, double *y) {
  double m[N];
  memset(y, 0, NY * sizeof *y);
  for (int j = 0; j < NZP; ++j)
    for (int i = 0; i < NXP; ++i) {
      const int q = j * NXP + i;
      y[2 * q] = (i + 0.5) * D, y[2 * q + 1] = (j + 0.5) * D;
      y[4 * N + q] = RHO0;
      m[q] = RHO0 * D * D;
    }
  return mfree_test_fluid_create(ctx, N, m, RHO0, RHO0 * C0 * C0 / GAMMA, GAMMA, 0.0, 1.5 * D);
}

/* omega^2 of -J_vr J_rv by central differences of the rhs and a dense power iteration. */
static double omega2_oracle(mfree_context_t *ctx, mfree_system_t *sys, const double *y0) {
  double *y = malloc(NY * sizeof *y), *fp = malloc(NY * sizeof *fp), *fm = malloc(NY * sizeof *fm);
  double *Jvr = malloc((size_t)2 * N * N * sizeof *Jvr), *Jrv = malloc((size_t)N * 2 * N * sizeof *Jrv);
  assert_true(y && fp && fm && Jvr && Jrv);
  const double ev = 1e-6, er = 1e-3; /* a velocity (m/s) and a density (kg/m^3) step */
  for (int c = 0; c < 2 * N; ++c) { /* column c of J_rv: drho/dt against v_c */
    memcpy(y, y0, NY * sizeof *y);
    y[2 * N + c] = ev;
    assert_ok(ctx, mfree_system_rhs(sys, 0.0, y, fp));
    y[2 * N + c] = -ev;
    assert_ok(ctx, mfree_system_rhs(sys, 0.0, y, fm));
    for (int k = 0; k < N; ++k) Jrv[(size_t)k * 2 * N + c] = (fp[4 * N + k] - fm[4 * N + k]) / (2 * ev);
  }
  for (int k = 0; k < N; ++k) { /* column k of J_vr: dv/dt against rho_k */
    memcpy(y, y0, NY * sizeof *y);
    y[4 * N + k] = RHO0 + er;
    assert_ok(ctx, mfree_system_rhs(sys, 0.0, y, fp));
    y[4 * N + k] = RHO0 - er;
    assert_ok(ctx, mfree_system_rhs(sys, 0.0, y, fm));
    for (int r = 0; r < 2 * N; ++r) Jvr[(size_t)r * N + k] = (fp[2 * N + r] - fm[2 * N + r]) / (2 * er);
  }
  /* power iteration on A u = -J_vr (J_rv u) */
  double u[2 * N], w[2 * N], div[N], lam = 0.0;
  for (int r = 0; r < 2 * N; ++r) u[r] = 1.0 + 0.1 * sin(1.0 + r);
  for (int it = 0; it < 20000; ++it) {
    for (int k = 0; k < N; ++k) {
      div[k] = 0.0;
      for (int c = 0; c < 2 * N; ++c) div[k] += Jrv[(size_t)k * 2 * N + c] * u[c];
    }
    double nw = 0.0, uw = 0.0, uu = 0.0;
    for (int r = 0; r < 2 * N; ++r) {
      w[r] = 0.0;
      for (int k = 0; k < N; ++k) w[r] -= Jvr[(size_t)r * N + k] * div[k];
      nw += w[r] * w[r], uw += u[r] * w[r], uu += u[r] * u[r];
    }
    const double prev = lam;
    lam = uw / uu;
    for (int r = 0; r < 2 * N; ++r) u[r] = w[r] / sqrt(nw);
    if (it > 100 && fabs(lam - prev) <= 1e-14 * lam) break;
  }
  free(y), free(fp), free(fm), free(Jvr), free(Jrv);
  return lam;
}

static void test_acoustic_step(void **state) {
  (void)state;
  mfree_context_t *ctx = NULL;
  assert_ok(NULL, mfree_context_create(&ctx));
  double y0[NY], y[NY];
  mfree_system_t *sys = patch(ctx, y0);
  const double w2 = omega2_oracle(ctx, sys, y0), omega = sqrt(w2), h = 1.5 * D;
  print_message("free patch %d x %d at rest: omega = %.1f 1/s (omega h / c = %.3f)\n", NXP, NZP, omega,
                omega * h / C0);
  assert_true(omega * h / C0 > 1.5); /* eq 120's step at CFL 1 is then above 1.5 / omega */

  steps_t off = {{0}, 0}, on = {{0}, 0};
  double t = 0.0;
  int64_t ns = 0;
  memcpy(y, y0, sizeof y);
  assert_ok(ctx, mfree_system_integrate(sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, 1.0, 1.0, 0.0, record, &off, &ns));
  print_message("eq 120 alone: dt omega = %.4f\n", off.dt[0] * omega);
  assert_true(fabs(off.dt[0] - h / C0) <= 1e-12 * h / C0);

  assert_ok(ctx, mfree_system_set_acoustic_step(sys, 1));
  memcpy(y, y0, sizeof y);
  t = 0.0;
  assert_ok(ctx, mfree_system_integrate(sys, MFREE_INTEGRATOR_PREDICTOR_CORRECTOR, y, &t, 40 * 1.5 / omega * 0.9999,
                                        1.0, 0.0, record, &on, &ns));
  const double first = on.dt[0] * omega, last = on.dt[on.n - 2] * omega; /* the last step is cut at t_end */
  print_message("acoustic step: dt omega = %.6f (first step), %.8f (step %d)\n", first, last, on.n - 1);
  assert_true(first >= 1.5 * (1.0 - 1e-9) && first <= 1.5 * 1.01);
  assert_true(fabs(last - 1.5) <= 3e-4);
  mfree_system_destroy(&sys);
  mfree_context_destroy(&ctx);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_acoustic_step)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
