/* An inflow gate with a SUNDIALS integrator (docs/fluid.md, "Inflow and outflow"): the host
 * integrates with ERKStep on mfree_sundials_rhs in windows of d / (2U), calls
 * mfree_system_update_open_boundaries between them and reinitialises ERKStep there (the
 * state changed). A gate 0.06 m wide (6 points, d = 0.01 m) injects water at U = 1 m/s into
 * 300 particles, all dormant at first, with no gravity and no walls (the jet translates at
 * U). After 0.2 s: the same particles were released as by the native leap-frog
 * (mfree_system_integrate), 20 rows; their mass is rho U W t; every released particle moves
 * at U and is at its row's place U t - (k + 1/2) d to 1e-6 (rtol 1e-8), the buffer holds
 * 3 rows upstream of the gate, and the dormant particles have not moved. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <arkode/arkode_erkstep.h>

#include "suntest.h"

static mfree_context_t *ctx;
static SUNContext sunctx;
static int setup(void **s) {
  (void)s;
  return mfree_context_create(&ctx) != MFREE_SUCCESS || SUNContext_Create(NULL, &sunctx) != 0;
}
static int teardown(void **s) {
  (void)s;
  SUNContext_Free(&sunctx);
  return mfree_context_destroy(&ctx) != MFREE_SUCCESS;
}

enum { N = 300 };
static const double RHO = 1000.0, U = 1.0, D = 0.01, W = 0.06, GAMMA = 7.0, T_END = 0.2;

static mfree_system_t *channel(double *y) {
  mfree_system_t *sys = NULL;
  assert_ok(ctx, mfree_system_create_fluid(ctx, 2, N, &sys));
  const double kappa = RHO * 100.0 / GAMMA, m = RHO * D * D;
  assert_ok(ctx, mfree_system_set_fluid(sys, &RHO, 0, kappa, GAMMA, 0.01));
  assert_ok(ctx, mfree_system_set_masses(sys, &m, 0));
  assert_ok(ctx, mfree_system_set_smoothing(sys, 1.5 * D));
  assert_ok(ctx, mfree_system_set_active(sys, 0));
  const double o[2] = {0.0, 0.0}, e[2] = {0.0, W}, nrm[2] = {1.0, 0.0};
  assert_ok(ctx, mfree_system_set_inflow(sys, 0, o, e, nrm, U, RHO, D));
  memset(y, 0, sizeof(double) * 5 * N);
  for (int i = 0; i < N; ++i) {
    y[2 * i] = -1.0 - i; /* dormant: anywhere */
    y[4 * N + i] = RHO;
  }
  return sys;
}

static void test_erkstep_windows(void **s) {
  (void)s;
  double yn[5 * N];
  mfree_system_t *ref = channel(yn);
  double t = 0.0;
  assert_ok(ctx, mfree_system_integrate(ref, MFREE_INTEGRATOR_LEAPFROG, yn, &t, T_END, 0.5, 0.0, NULL, NULL, NULL));
  int32_t sref[N], na_ref = 0;
  assert_ok(ctx, mfree_system_get_active(ref, &na_ref, N, sref));

  N_Vector y = N_VNew_Serial(5 * N, sunctx);
  double *py = N_VGetArrayPointer(y);
  mfree_system_t *sys = channel(py);
  double y0[5 * N];
  memcpy(y0, py, sizeof y0);
  mfree_sundials_t *ad = NULL;
  assert_ok(ctx, mfree_sundials_create(ctx, sys, &ad));
  t = 0.0;
  assert_ok(ctx, mfree_system_update_open_boundaries(sys, t, py));
  void *mem = ERKStepCreate(mfree_sundials_rhs, t, y, sunctx);
  assert_non_null(mem);
  assert_int_equal(ERKStepSStolerances(mem, 1e-8, 1e-12), ARK_SUCCESS);
  assert_int_equal(ERKStepSetUserData(mem, ad), ARK_SUCCESS);
  assert_int_equal(ERKStepSetMaxNumSteps(mem, 100000), ARK_SUCCESS);
  const int windows = (int)lround(T_END / (0.5 * D / U));
  for (int w = 1; w <= windows; ++w) {
    const double tout = w * T_END / windows;
    assert_int_equal(ERKStepSetStopTime(mem, tout), ARK_SUCCESS);
    assert_int_equal(ERKStepEvolve(mem, tout, y, &t, ARK_NORMAL), ARK_SUCCESS);
    assert_ok(ctx, mfree_system_update_open_boundaries(sys, t, py));
    assert_int_equal(ERKStepReInit(mem, mfree_sundials_rhs, t, y), ARK_SUCCESS);
  }
  assert_true(fabs(t - T_END) < 1e-15);
  int64_t count = 0, count_ref = 0;
  double min = 0.0, min_ref = 0.0;
  assert_ok(ctx, mfree_system_get_inflow(sys, 0, &count, &min));
  assert_ok(ctx, mfree_system_get_inflow(ref, 0, &count_ref, &min_ref));
  assert_int_equal(count, 20 * 6);
  assert_int_equal(count, count_ref);
  assert_true(fabs(min - RHO * U * W * T_END) <= 1e-12 * min);
  int32_t st[N], na = 0;
  assert_ok(ctx, mfree_system_get_active(sys, &na, N, st));
  assert_int_equal(na, na_ref);
  int nbuf = 0;
  for (int i = 0; i < N; ++i) {
    assert_int_equal(st[i], sref[i]); /* the same particles, from the same pool */
    if (st[i] == MFREE_PARTICLE_DORMANT) {
      assert_true(py[2 * i] == y0[2 * i] && py[2 * i + 1] == y0[2 * i + 1]);
      continue;
    }
    const int k = i / 6; /* row k: particles 6k .. 6k + 5 */
    const double place = U * T_END - (k + 0.5) * D;
    assert_true(fabs(py[2 * i] - place) < 1e-6);
    assert_true(fabs(py[2 * N + 2 * i] - U) < 1e-6 && fabs(py[2 * N + 2 * i + 1]) < 1e-6);
    if (st[i] == MFREE_PARTICLE_INFLOW) {
      ++nbuf;
      assert_true(py[2 * i] < 0.0);
    }
  }
  assert_int_equal(nbuf, 3 * 6);
  ERKStepFree(&mem);
  N_VDestroy(y);
  mfree_sundials_destroy(&ad);
  mfree_system_destroy(&sys);
  mfree_system_destroy(&ref);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_erkstep_windows)};
  return cmocka_run_group_tests(tests, setup, teardown);
}
