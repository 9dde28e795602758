/* A fluid run that blows up inside mfree_system_integrate (include/mfree.h, above its
 * declaration: "a non-finite state or a particle outside the box stops the run with a
 * positive status naming the step and particle; y and *t then hold the last good
 * state"), the state turning non-finite during a step, not given non-finite on entry.
 *
 * The run: a water block falls at twice the sound speed onto a resting block of the same
 * size (jittered lattice, 96 x 96 = 9216 particles, more than the 8192 from which even the
 * state check runs on two threads), Tait gamma = 7, no gravity, no viscosity, with an
 * absurd bulk modulus kappa = 1e307 Pa (finite, so set_fluid takes it; 003 eq 125 would
 * give ~4e4 Pa here). Without gravity and viscosity the equations and the CFL step are
 * invariant under v -> s v, t -> t / s, kappa -> s^2 kappa, so until the overflow this is
 * the ordinary Mach-2 impact in time units of ~1e-154 s; but the impact compresses the
 * layer at the interface to rho / rho0 > (1 + DBL_MAX / kappa)^(1/7) ~ 1.52 within a few
 * steps, where the Tait pressure kappa ((rho / rho0)^7 - 1) overflows to +inf: the
 * accelerations of the next step, and with them the new velocities, positions and
 * densities around that layer, are non-finite. Checked, for the leap-frog and the
 * predictor-corrector schemes, with 1 and 2 threads:
 * - MFREE_FAIL_NONFINITE, the message naming the failing step (nsteps + 1) and the first
 *   invalid particle, the latter from an independent oracle: the right-hand side of the
 *   last good state (mfree_system_rhs) gives the accelerations, non-finite at particles A;
 *   the leap-frog's new velocities are then non-finite exactly at A, and the interpolated
 *   velocities and density rates (hence positions and densities) at every particle whose
 *   row of the interpolation matrix (mfree_system_assemble_interpolation) reaches A; the
 *   predictor state (003 eq 111) is non-finite exactly at A;
 * - y and t bitwise equal to a reference run on a fresh system that stops itself after
 *   nsteps steps (progress callback), nsteps = the number of accepted steps (callbacks),
 *   and the last good state holds an infinite pressure (the cause above);
 * - the system is usable afterwards: the same system integrates the same start again to
 *   that state (MFREE_SUCCESS), and from there fails again at once ("step 1"), state kept;
 * - 2 threads: the same status, message, nsteps, y and t bitwise.
 * Also the stalls that made integrate loop forever before (found here): speeds so large
 * that the CFL step h / max(c + |v|) is 0 (|v|^2 or gamma kappa / rho overflow), and a
 * fixed step below the resolution of t, now MFREE_FAIL_CFL naming the step (and the
 * fastest particle), the state kept. No leak: the ASan build runs this test too. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"

static mfree_context_t *ctx;
static int setup(void **s) { (void)s; return mfree_context_create(&ctx) != MFREE_SUCCESS; }
static int teardown(void **s) { (void)s; return mfree_context_destroy(&ctx) != MFREE_SUCCESS; }

enum { L = 96, N = L * L, NY = 5 * N };
static const double D = 0.005, RHO0 = 1000.0, GAMMA = 7.0, KAPPA = 1e307, CFL = 0.25;

/* Jittered lattice at rest density; the upper half (rows L/2 ..) moves down at 2 c0,
 * c0 = sqrt(gamma kappa / rho0) (003 eq 121). */
static double *impact(double *m) {
  double *y = calloc(NY, sizeof(double));
  mfree_rng_t r;
  mfree_rng_seed(&r, 708);
  const double U = 2.0 * sqrt(GAMMA * KAPPA / RHO0);
  for (int j = 0; j < L; ++j)
    for (int i = 0; i < L; ++i) {
      const int p = j * L + i;
      y[2 * p] = (i + 0.5) * D + 0.2 * D * (2 * mfree_rng_uniform(&r) - 1);
      y[2 * p + 1] = (j + 0.5) * D + 0.2 * D * (2 * mfree_rng_uniform(&r) - 1);
      y[2 * N + 2 * p + 1] = j >= L / 2 ? -U : 0.0;
      y[4 * N + p] = RHO0;
      m[p] = RHO0 * D * D;
    }
  return y;
}

static mfree_system_t *fluid(const double *m, double kappa) {
  mfree_system_t *s = NULL;
  assert_ok(ctx, mfree_system_create_fluid(ctx, 2, N, &s));
  assert_ok(ctx, mfree_system_set_fluid(s, &RHO0, 0, kappa, GAMMA, 0.0));
  assert_ok(ctx, mfree_system_set_masses(s, m, 1));
  assert_ok(ctx, mfree_system_set_smoothing(s, 1.5 * D));
  return s;
}

/* Progress: counts the accepted steps, checks that they come in order and stops after
 * `stop` of them (0: never; a run that never ends is stopped at `cap` and fails). */
typedef struct {
  int64_t calls, last, stop, cap;
  double t;
} progress_t;
static int32_t progress(void *user, int64_t step, double t, double dt) {
  progress_t *p = user;
  ++p->calls;
  if (step != p->last + 1 || !(dt > 0.0) || !(t > p->t)) p->cap = -1; /* checked by the caller */
  p->last = step;
  p->t = t;
  return (p->stop > 0 && step >= p->stop) || (p->cap != 0 && step >= p->cap);
}

typedef struct {
  mfree_status_t status;
  char msg[512];
  int64_t nsteps;
  double t, *y;
} outcome_t;

/* Integrates y0 from t = 0 on sys with the CFL step; stop > 0 stops after stop steps. */
static void run(mfree_system_t *sys, int scheme, const double *y0, int64_t stop, outcome_t *o) {
  o->y = malloc(NY * sizeof(double));
  memcpy(o->y, y0, NY * sizeof(double));
  o->t = 0.0;
  o->nsteps = -1;
  progress_t p = {0, 0, stop, 100000, 0.0};
  o->status = mfree_system_integrate(sys, (mfree_integrator_t)scheme, o->y, &o->t, 1.0, CFL, 0.0, progress, &p,
                                     &o->nsteps);
  o->msg[0] = '\0';
  if (o->status != MFREE_SUCCESS) mfree_context_get_last_error(ctx, NULL, o->msg, sizeof o->msg);
  if (p.cap < 0) fail_msg("progress: steps out of order or not advancing");
  assert_int_equal(o->nsteps, p.calls); /* nsteps = accepted steps, one callback each */
  assert_int_equal(o->nsteps, p.last);
  if (p.calls > 0) assert_true(o->t == p.t);
}

/* From the last good state o (failed run on sys) the next step fails at once, state kept. */
static void fails_again(mfree_system_t *sys, int scheme, const outcome_t *o) {
  double *y = malloc(NY * sizeof(double));
  memcpy(y, o->y, NY * sizeof(double));
  double t = o->t;
  int64_t ns = -1;
  char expect[64];
  snprintf(expect, sizeof expect, "step 1%s: particle", scheme == MFREE_INTEGRATOR_LEAPFROG ? "" : " (predictor)");
  assert_error(ctx, mfree_system_integrate(sys, (mfree_integrator_t)scheme, y, &t, 1.0, CFL, 0.0, NULL, NULL, &ns),
               MFREE_FAIL_NONFINITE, expect);
  assert_int_equal(ns, 0);
  assert_memory_equal(&t, &o->t, sizeof(double));
  assert_memory_equal(y, o->y, NY * sizeof(double));
  free(y);
}

static void blowup(int scheme) {
  assert_ok(ctx, mfree_context_set_num_threads(ctx, 1));
  double *m = malloc(N * sizeof(double));
  double *y0 = impact(m);
  mfree_system_t *sys = fluid(m, KAPPA);
  outcome_t one, *o = &one;
  run(sys, scheme, y0, 0, o);
  printf("[ t708 ] scheme %d: status %d after %lld steps, t = %.6g: %s\n", scheme, (int)o->status,
         (long long)o->nsteps, o->t, o->msg);
  if (o->status != MFREE_FAIL_NONFINITE)
    fail_msg("expected MFREE_FAIL_NONFINITE, got %d (%s)", (int)o->status, o->msg);
  assert_true(o->nsteps >= 3); /* a blow-up after some good steps, not on entry */
  for (int q = 0; q < NY; ++q) assert_true(isfinite(o->y[q]));

  /* reference: a fresh system, same start, stopped after nsteps steps */
  mfree_system_t *ref = fluid(m, KAPPA);
  outcome_t r;
  run(ref, scheme, y0, o->nsteps, &r);
  assert_int_equal(r.status, MFREE_SUCCESS);
  assert_int_equal(r.nsteps, o->nsteps);
  assert_memory_equal(&r.t, &o->t, sizeof(double));
  assert_memory_equal(r.y, o->y, NY * sizeof(double));

  /* the cause: the last good state holds an infinite Tait pressure */
  double *pr = malloc(N * sizeof(double));
  assert_ok(ctx, mfree_system_get_pressure(ref, r.y, pr));
  int inf_p = 0;
  for (int i = 0; i < N; ++i) inf_p += isinf(pr[i]) && pr[i] > 0;
  assert_true(inf_p > 0);

  /* oracle for the named particle: accelerations of the last good state */
  double *yd = malloc(NY * sizeof(double));
  assert_ok(ctx, mfree_system_rhs(ref, r.t, r.y, yd));
  char *bad_a = calloc(N, 1);
  int first_a = N;
  for (int i = 0; i < N; ++i)
    if (!isfinite(yd[2 * N + 2 * i]) || !isfinite(yd[2 * N + 2 * i + 1])) {
      bad_a[i] = 1;
      if (first_a == N) first_a = i;
    }
  assert_true(first_a < N);
  char expect[128];
  if (scheme == MFREE_INTEGRATOR_LEAPFROG) {
    mfree_matrix_t *S = NULL;
    assert_ok(ctx, mfree_system_assemble_interpolation(ref, r.y, &S));
    const int64_t *rp;
    const int32_t *ci;
    const double *sv;
    assert_ok(ctx, mfree_matrix_get_csr(S, &rp, &ci, &sv));
    int first = first_a;
    for (int k = 0; k < first; ++k)
      for (int64_t e = rp[k]; e < rp[k + 1]; ++e)
        if (bad_a[ci[e]]) {
          first = k;
          break;
        }
    mfree_matrix_destroy(&S);
    snprintf(expect, sizeof expect, "step %lld: particle %d has a non-finite", (long long)o->nsteps + 1, first);
  } else {
    /* the predictor state y + dt/2 f(y) is non-finite exactly where f's accelerations are */
    snprintf(expect, sizeof expect, "step %lld (predictor): particle %d has a non-finite", (long long)o->nsteps + 1,
             first_a);
  }
  if (!strstr(o->msg, expect)) fail_msg("message \"%s\" does not contain \"%s\"", o->msg, expect);

  /* the failed system is still usable: the same start again to the same state ... */
  outcome_t again;
  run(sys, scheme, y0, o->nsteps, &again);
  assert_int_equal(again.status, MFREE_SUCCESS);
  assert_memory_equal(again.y, o->y, NY * sizeof(double));
  assert_memory_equal(&again.t, &o->t, sizeof(double));
  /* ... and from there the next step fails again at once, state kept */
  fails_again(sys, scheme, &again);
  free(again.y);
  free(bad_a);
  free(yd);
  free(pr);
  free(r.y);
  mfree_system_destroy(&ref);
  mfree_system_destroy(&sys);

  /* two threads (the state check too: N / 4 > 2048): the same outcome bitwise */
  assert_ok(ctx, mfree_context_set_num_threads(ctx, 2));
  sys = fluid(m, KAPPA);
  outcome_t two;
  run(sys, scheme, y0, 0, &two);
  assert_int_equal(two.status, one.status);
  assert_string_equal(two.msg, one.msg);
  assert_int_equal(two.nsteps, one.nsteps);
  assert_memory_equal(&two.t, &one.t, sizeof(double));
  assert_memory_equal(two.y, one.y, NY * sizeof(double));
  fails_again(sys, scheme, &two);
  mfree_system_destroy(&sys);
  assert_ok(ctx, mfree_context_set_num_threads(ctx, 1));
  free(one.y);
  free(two.y);
  free(y0);
  free(m);
}

static void test_blowup_leapfrog(void **s) {
  (void)s;
  blowup(MFREE_INTEGRATOR_LEAPFROG);
}

static void test_blowup_predictor_corrector(void **s) {
  (void)s;
  blowup(MFREE_INTEGRATOR_PREDICTOR_CORRECTOR);
}

/* Steps that no longer advance t. Before the fix each of these looped for ever (here:
 * until the progress callback's cap, with MFREE_SUCCESS). */
static void test_stalls(void **s) {
  (void)s;
  assert_ok(ctx, mfree_context_set_num_threads(ctx, 1));
  double *m = malloc(N * sizeof(double));
  double *y0 = impact(m), *y = malloc(NY * sizeof(double));
  for (int p = 0; p < N; ++p) y0[2 * N + 2 * p + 1] = 0.0; /* at rest */
  mfree_system_t *sys = fluid(m, 4e4);
  for (int scheme = MFREE_INTEGRATOR_LEAPFROG; scheme <= MFREE_INTEGRATOR_PREDICTOR_CORRECTOR; ++scheme) {
    /* |v|^2 overflows at one particle (|v| = 1e160 is finite: the state is valid), so
     * the CFL step is h / inf = 0 */
    memcpy(y, y0, NY * sizeof(double));
    y[2 * N + 2 * 77] = 1e160;
    double t = 0.0;
    int64_t ns = -1;
    progress_t p = {0, 0, 0, 1000, 0.0};
    assert_error(ctx,
                 mfree_system_integrate(sys, (mfree_integrator_t)scheme, y, &t, 1.0, CFL, 0.0, progress, &p, &ns),
                 MFREE_FAIL_CFL, "step 1: the step dt = 0 no longer advances t = 0 (fastest: particle 77");
    assert_int_equal(ns, 0);
    assert_true(t == 0.0);
    y[2 * N + 2 * 77] = 0.0;
    assert_memory_equal(y, y0, NY * sizeof(double));

    /* a fixed step below half an ulp of t */
    t = 1.0;
    assert_error(ctx,
                 mfree_system_integrate(sys, (mfree_integrator_t)scheme, y, &t, 2.0, 0.0, 1e-17, progress, &p, &ns),
                 MFREE_FAIL_CFL, "step 1: the step dt = 1e-17 no longer advances t = 1");
    assert_int_equal(ns, 0);
    assert_true(t == 1.0);
    assert_memory_equal(y, y0, NY * sizeof(double));
    /* the same step from t = 0 advances t: a few steps, then stopped by the callback */
    t = 0.0;
    p = (progress_t){0, 0, 3, 0, 0.0};
    assert_ok(ctx, mfree_system_integrate(sys, (mfree_integrator_t)scheme, y, &t, 2.0, 0.0, 1e-17, progress, &p, &ns));
    assert_int_equal(ns, 3);
    assert_true(t > 2.5e-17 && t < 3.5e-17);
    memcpy(y, y0, NY * sizeof(double));
  }
  mfree_system_destroy(&sys);
  /* gamma kappa / rho overflows: every sound speed is infinite */
  sys = fluid(m, DBL_MAX / 2);
  double t = 0.0;
  int64_t ns = -1;
  assert_error(ctx, mfree_system_integrate(sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, 1.0, CFL, 0.0, NULL, NULL, &ns),
               MFREE_FAIL_CFL, "(fastest: particle 0, c + |v| = inf)");
  assert_int_equal(ns, 0);
  assert_memory_equal(y, y0, NY * sizeof(double));
  mfree_system_destroy(&sys);
  free(y);
  free(y0);
  free(m);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_blowup_leapfrog),
      cmocka_unit_test(test_blowup_predictor_corrector),
      cmocka_unit_test(test_stalls),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
