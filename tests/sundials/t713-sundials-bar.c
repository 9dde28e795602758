/* SUNDIALS on the elastodynamic system: paper 001 Sect. 6.4, wave in a bar (E = 200 GPa,
 * rho = 7865 kg/m3, L = 0.1 m, -1 GPa for 3 us at the right end, left end free, 800
 * particles; SSPH collocation with the revised super Gauss a = 1.6, h = 1.5 dx, quadratic
 * basis, as t703) integrated by
 *  (a) mfree_system_integrate, central differences, CFL 0.5, 0.25, 0.125, to T = 10 us;
 *  (b) ERKStep with mfree_sundials_rhs, rtol 1e-7, to T0 = 3 us and T;
 *  (c) ARKStep, explicit, through the mass-matrix interface (the collocation system's
 *      mass is the identity: mfree_sundials_rhs_mass_form + mfree_sundials_mass + KLU),
 *      rtol 1e-7, to T;
 *  (d) IDA with mfree_sundials_residual (r = y' - f), SPGMR, rtol 1e-5, to T0 only (BDF
 *      on an undamped step front needs ~40000 steps to T at rtol 1e-7: a minute).
 * Absolute tolerances are 1e-7 of the displacement (7.6e-5 m) and velocity (25 m/s)
 * scales, times rtol / 1e-7 for IDA. The load switches off at T0; every integrator stops
 * there exactly and restarts (the history reads a phase flag), so all integrate the same
 * piecewise-smooth problem.
 * Checks (largest interior displacement difference relative to the largest displacement):
 *  - (c) vs (b) at T: 1e-6 (observed 6e-8); (d) vs (b) at T0: 1e-4 (observed 8e-6, set by
 *    IDA's rtol);
 *  - (a) is second order: its distance to (b) shrinks by 4 +- 1 from CFL 0.25 to 0.125
 *    (observed 3.9; from 0.5 to 0.25 only 3.1: the step front's shortest waves are not yet
 *    asymptotic) and is below 2e-4 at CFL 0.125 (observed 1.1e-4);
 *  - each result at T shows the paper's wave: front speed within 2 % of sqrt(E/rho) =
 *    5.04 mm/us (observed 5.006) and plateau stress within 5 % of -1 GPa (observed
 *    -1.003 to -1.005) (paper 001 Sect. 6.4, Fig. 16).
 * (e) the Galerkin system with its consistent mass: ARKStep through the mass interface
 * (KLU) against ERKStep, to 1 us: 1e-6 (observed 1e-7).
 * Optimised builds only (tests/sundials/CMakeLists.txt). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <arkode/arkode_arkstep.h>
#include <arkode/arkode_erkstep.h>
#include <ida/ida.h>
#include <sunlinsol/sunlinsol_klu.h>
#include <sunlinsol/sunlinsol_spgmr.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include "suntest.h"

enum { N = 800, NEQ = 2 * N };
static const double L = 0.1, E = 200e9, RHO = 7865.0, T0 = 3e-6, T_END = 10e-6;

static mfree_context_t *ctx;
static SUNContext sunctx;
static double X[N];
enum { PC05, PC025, PC0125, ERK, ARK, IDAR, NRUNS };
static double result[NRUNS][NEQ], erk_t0[NEQ], ida_t0[NEQ];
static int done[NRUNS];
static int loaded; /* phase of the load history: 1 while the pulse acts */
/* Displacements reach 7.6e-5 m (strain 0.005 over the 15 mm pulse), velocities 25 m/s
 * (sigma / rho c): absolute tolerances 1e-7 of those scales. */
static const double RTOL = 1e-7, RTOL_IDA = 1e-5, ATOL_U = 7.6e-12, ATOL_V = 2.5e-6;
static N_Vector atol_vector(double scale) {
  N_Vector a = N_VNew_Serial(NEQ, sunctx);
  double *p = N_VGetArrayPointer(a);
  for (int q = 0; q < NEQ; ++q) p[q] = scale * (q < N ? ATOL_U : ATOL_V);
  return a;
}

static int setup(void **s) {
  (void)s;
  if (mfree_context_create(&ctx) != MFREE_SUCCESS) return 1;
  return SUNContext_Create(MFREE_SUNDIALS_COMM_NULL, &sunctx) != 0;
}
static int teardown(void **s) {
  (void)s;
  SUNContext_Free(&sunctx);
  return mfree_context_destroy(&ctx) != MFREE_SUCCESS;
}

static void traction(void *u, const double *x, double *v) {
  (void)u;
  v[0] = x[0] > 0.5 * L ? -1e9 : 0.0;
}
static double history(void *u, double t) {
  (void)u;
  (void)t;
  return loaded ? 1.0 : 0.0;
}

static void check_flag(const char *call, int flag) {
  if (flag < 0) {
    char msg[512];
    mfree_context_get_last_error(ctx, NULL, msg, sizeof msg);
    fail_msg("%s returned %d; last mfree error: %s", call, flag, msg);
  }
}

/* The paper's wave in a state at T_END (the phase is off: the stress-free right end). */
static void check_wave(mfree_system_t *sys, const double *y, const char *what) {
  double sig[N];
  loaded = 0;
  assert_ok(ctx, mfree_system_get_stress(sys, T_END, y, sig));
  int front = -1;
  for (int i = 0; i < N && front < 0; ++i)
    if (sig[i] < -0.5e9) front = i;
  assert_true(front > 0);
  const double c = sqrt(E / RHO), speed = (L - X[front]) / T_END;
  double sum = 0.0;
  int cnt = 0;
  for (int i = 0; i < N; ++i)
    if (X[i] > L - c * T_END + 3e-3 && X[i] < L - c * (T_END - T0) - 3e-3) {
      sum += sig[i];
      ++cnt;
    }
  assert_true(cnt > 20);
  printf("[ t713 ] %-28s front %.4f mm/us (exact %.4f), plateau %.4f GPa\n", what, speed * 1e-3,
         c * 1e-3, sum / cnt * 1e-9);
  if (fabs(speed - c) > 0.02 * c) fail_msg("%s: wave speed %.4f mm/us", what, speed * 1e-3);
  if (fabs(sum / cnt + 1e9) > 0.05e9) fail_msg("%s: amplitude %.4f GPa", what, sum / cnt * 1e-9);
}

/* Largest difference of interior displacements, relative to the largest of b's. */
static double distance(const double *a, const double *b) {
  double d = 0.0, s = 0.0;
  for (int i = 1; i < N - 1; ++i) {
    d = fmax(d, fabs(a[i] - b[i]));
    s = fmax(s, fabs(b[i]));
  }
  return d / s;
}

/* (a) native central differences */
static void test_native(void **s) {
  (void)s;
  for (int k = 0; k < 3; ++k) {
    mfree_test_bar_t b = mfree_test_bar_create(ctx, N, L, E, RHO, X, traction, history);
    double *y = result[PC05 + k], t = 0.0;
    int64_t ns = 0, ns2 = 0;
    memset(y, 0, sizeof result[0]);
    loaded = 1;
    const double cfl = 0.5 / (1 << k);
    assert_ok(ctx, mfree_system_integrate(b.sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, T0, cfl, 0.0, NULL, NULL, &ns));
    assert_true(t == T0);
    loaded = 0;
    assert_ok(ctx,
              mfree_system_integrate(b.sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, T_END, cfl, 0.0, NULL, NULL, &ns2));
    assert_true(t == T_END);
    char what[64];
    snprintf(what, sizeof what, "(a) native, CFL %g", cfl);
    check_wave(b.sys, y, what);
    done[PC05 + k] = 1;
    mfree_test_bar_destroy(&b);
  }
}

/* (b) ERKStep, y' = f(t, y) */
static void test_erkstep(void **s) {
  (void)s;
  mfree_test_bar_t b = mfree_test_bar_create(ctx, N, L, E, RHO, X, traction, history);
  mfree_sundials_t *ad = NULL;
  assert_ok(ctx, mfree_sundials_create(ctx, b.sys, &ad));
  N_Vector y = N_VNew_Serial(NEQ, sunctx);
  N_VConst(0.0, y);
  loaded = 1;
  void *mem = ERKStepCreate(mfree_sundials_rhs, 0.0, y, sunctx);
  assert_non_null(mem);
  N_Vector atol = atol_vector(1.0);
  assert_int_equal(ERKStepSVtolerances(mem, RTOL, atol), ARK_SUCCESS);
  assert_int_equal(ERKStepSetUserData(mem, ad), ARK_SUCCESS);
  assert_int_equal(ERKStepSetMaxNumSteps(mem, 100000), ARK_SUCCESS);
  double t = 0.0;
  assert_int_equal(ERKStepSetStopTime(mem, T0), ARK_SUCCESS);
  check_flag("ERKStepEvolve", ERKStepEvolve(mem, T0, y, &t, ARK_NORMAL));
  assert_true(t == T0);
  memcpy(erk_t0, N_VGetArrayPointer(y), sizeof erk_t0);
  loaded = 0;
  assert_int_equal(ERKStepReset(mem, T0, y), ARK_SUCCESS);
  assert_int_equal(ERKStepSetStopTime(mem, T_END), ARK_SUCCESS);
  check_flag("ERKStepEvolve", ERKStepEvolve(mem, T_END, y, &t, ARK_NORMAL));
  assert_true(t == T_END);
  memcpy(result[ERK], N_VGetArrayPointer(y), sizeof result[0]);
  check_wave(b.sys, result[ERK], "(b) ERKStep");
  done[ERK] = 1;
  ERKStepFree(&mem);
  N_VDestroy(y);
  N_VDestroy(atol);
  mfree_sundials_destroy(&ad);
  mfree_test_bar_destroy(&b);
}

/* (c) ARKStep with the (identity) mass through KLU */
static void test_arkstep_mass(void **s) {
  (void)s;
  mfree_test_bar_t b = mfree_test_bar_create(ctx, N, L, E, RHO, X, traction, history);
  mfree_sundials_t *ad = NULL;
  assert_ok(ctx, mfree_sundials_create(ctx, b.sys, &ad));
  N_Vector y = N_VNew_Serial(NEQ, sunctx);
  N_VConst(0.0, y);
  loaded = 1;
  SUNMatrix M = NULL;
  assert_ok(ctx, mfree_sundials_create_mass_matrix(ad, sunctx, y, &M));
  assert_int_equal(SUNSparseMatrix_NNZ(M), NEQ); /* the identity */
  SUNLinearSolver LS = SUNLinSol_KLU(y, M, sunctx);
  assert_non_null(LS);
  assert_ok(ctx, mfree_sundials_set_mass_solver(ad, LS));
  void *mem = ARKStepCreate(mfree_sundials_rhs_mass_form, NULL, 0.0, y, sunctx);
  assert_non_null(mem);
  assert_int_equal(ARKStepSetMassLinearSolver(mem, LS, M, SUNFALSE), ARK_SUCCESS);
  assert_int_equal(ARKStepSetMassFn(mem, mfree_sundials_mass), ARK_SUCCESS);
  N_Vector atol = atol_vector(1.0);
  assert_int_equal(ARKStepSVtolerances(mem, RTOL, atol), ARK_SUCCESS);
  assert_int_equal(ARKStepSetUserData(mem, ad), ARK_SUCCESS);
  assert_int_equal(ARKStepSetMaxNumSteps(mem, 100000), ARK_SUCCESS);
  double t = 0.0;
  assert_int_equal(ARKStepSetStopTime(mem, T0), ARK_SUCCESS);
  check_flag("ARKStepEvolve", ARKStepEvolve(mem, T0, y, &t, ARK_NORMAL));
  assert_true(t == T0);
  loaded = 0;
  assert_int_equal(ARKStepReset(mem, T0, y), ARK_SUCCESS);
  assert_int_equal(ARKStepSetStopTime(mem, T_END), ARK_SUCCESS);
  check_flag("ARKStepEvolve", ARKStepEvolve(mem, T_END, y, &t, ARK_NORMAL));
  assert_true(t == T_END);
  memcpy(result[ARK], N_VGetArrayPointer(y), sizeof result[0]);
  check_wave(b.sys, result[ARK], "(c) ARKStep + KLU mass");
  done[ARK] = 1;
  ARKStepFree(&mem);
  SUNLinSolFree(LS);
  SUNMatDestroy(M);
  N_VDestroy(y);
  N_VDestroy(atol);
  mfree_sundials_destroy(&ad);
  mfree_test_bar_destroy(&b);
}

/* (d) IDA, r = y' - f(t, y), to T0: BDF on an undamped wave front needs ~40000 steps to
 * T_END at rtol 1e-7 (a minute); at rtol 1e-5 to T0 it takes seconds */
static void test_ida(void **s) {
  (void)s;
  mfree_test_bar_t b = mfree_test_bar_create(ctx, N, L, E, RHO, X, traction, history);
  mfree_sundials_t *ad = NULL;
  assert_ok(ctx, mfree_sundials_create(ctx, b.sys, &ad));
  N_Vector yy = N_VNew_Serial(NEQ, sunctx), yp = N_VClone(yy);
  N_VConst(0.0, yy);
  loaded = 1;
  assert_int_equal(mfree_sundials_rhs(0.0, yy, yp, ad), 0);
  void *mem = IDACreate(sunctx);
  assert_non_null(mem);
  assert_int_equal(IDAInit(mem, mfree_sundials_residual, 0.0, yy, yp), IDA_SUCCESS);
  N_Vector atol = atol_vector(RTOL_IDA / RTOL);
  assert_int_equal(IDASVtolerances(mem, RTOL_IDA, atol), IDA_SUCCESS);
  assert_int_equal(IDASetUserData(mem, ad), IDA_SUCCESS);
  SUNLinearSolver LS = SUNLinSol_SPGMR(yy, SUN_PREC_NONE, 0, sunctx);
  assert_int_equal(IDASetLinearSolver(mem, LS, NULL), IDA_SUCCESS);
  assert_int_equal(IDASetMaxNumSteps(mem, 100000), IDA_SUCCESS);
  double t = 0.0;
  assert_int_equal(IDASetStopTime(mem, T0), IDA_SUCCESS);
  check_flag("IDASolve", IDASolve(mem, T0, &t, yy, yp, IDA_NORMAL));
  assert_true(t == T0);
  memcpy(ida_t0, N_VGetArrayPointer(yy), sizeof ida_t0);
  done[IDAR] = 1;
  IDAFree(&mem);
  SUNLinSolFree(LS);
  N_VDestroy(yp);
  N_VDestroy(yy);
  N_VDestroy(atol);
  mfree_sundials_destroy(&ad);
  mfree_test_bar_destroy(&b);
}

static const double TG = 1e-6; /* the stiffer consistent-mass system: 5 mm of travel */

/* (e) The Galerkin system (mfree_system_create_elastodynamic_galerkin: MLS, cubic spline,
 * h = 1.5 dx, 2-point Gauss cells, consistent mass, the end load as a point traction;
 * as t704) to TG = 1 us: ARKStep with its consistent mass through the mass interface
 * (mfree_sundials_rhs_mass_form gives g f - K u, mfree_sundials_mass the mass, KLU
 * solves) against ERKStep on y' = f (the system solves with the mass itself). The same
 * ODE by two routes: 1e-6. */
static void end_load(void *u, const double *x, double *v) {
  (void)u;
  (void)x;
  v[0] = -1e9;
}

static mfree_assembler_t *cells(mfree_approximant_t *a, mfree_form_t form, double coef) {
  mfree_assembler_t *as = NULL;
  const double lo = 0.0, hi = L;
  const int32_t nc = N - 1;
  assert_ok(ctx, mfree_assembler_create(ctx, a, NULL, form, &as));
  assert_ok(ctx, mfree_assembler_set_coefficient(as, coef));
  assert_ok(ctx, mfree_assembler_set_quadrature_cells(as, &lo, &hi, &nc, 2, NULL, NULL));
  return as;
}

static void run_galerkin(int mass_form, double *out) {
  const double dx = L / (N - 1), h = 1.5 * dx, vol = dx;
  for (int i = 0; i < N; ++i) X[i] = i * dx;
  mfree_particles_t *ps = NULL;
  mfree_approximant_t *a = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, 1, N, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, X, MFREE_LAYOUT_AOS, 1, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_volumes(ps, &vol, 0, MFREE_COPY));
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, &a));
  mfree_assembler_t *K = cells(a, MFREE_FORM_LAPLACE, E), *M = cells(a, MFREE_FORM_MASS, RHO);
  const double xe = L, we = 1.0;
  assert_ok(ctx, mfree_assembler_add_traction(K, 1, &xe, MFREE_LAYOUT_AOS, 1, &we, end_load, NULL));
  assert_ok(ctx, mfree_assembler_setup(K));
  assert_ok(ctx, mfree_assembler_setup(M));
  mfree_system_t *sys = NULL;
  assert_ok(ctx, mfree_system_create_elastodynamic_galerkin(ctx, K, M, &sys));
  assert_ok(ctx, mfree_system_set_load_history(sys, history, NULL));
  loaded = 1;
  mfree_sundials_t *ad = NULL;
  assert_ok(ctx, mfree_sundials_create(ctx, sys, &ad));
  N_Vector y = N_VNew_Serial(NEQ, sunctx), atol = atol_vector(1.0);
  N_VConst(0.0, y);
  void *mem = NULL;
  SUNMatrix Mm = NULL;
  SUNLinearSolver LS = NULL;
  double t = 0.0;
  if (mass_form) {
    assert_ok(ctx, mfree_sundials_set_consistent_mass(ad, 1));
    assert_ok(ctx, mfree_sundials_create_mass_matrix(ad, sunctx, y, &Mm));
    assert_true(SUNSparseMatrix_NNZ(Mm) > NEQ); /* not the identity */
    LS = SUNLinSol_KLU(y, Mm, sunctx);
    assert_non_null(LS);
    assert_ok(ctx, mfree_sundials_set_mass_solver(ad, LS));
    mem = ARKStepCreate(mfree_sundials_rhs_mass_form, NULL, 0.0, y, sunctx);
    assert_non_null(mem);
    assert_int_equal(ARKStepSetMassLinearSolver(mem, LS, Mm, SUNFALSE), ARK_SUCCESS);
    assert_int_equal(ARKStepSetMassFn(mem, mfree_sundials_mass), ARK_SUCCESS);
    assert_int_equal(ARKStepSVtolerances(mem, RTOL, atol), ARK_SUCCESS);
    assert_int_equal(ARKStepSetUserData(mem, ad), ARK_SUCCESS);
    assert_int_equal(ARKStepSetMaxNumSteps(mem, 100000), ARK_SUCCESS);
    assert_int_equal(ARKStepSetStopTime(mem, TG), ARK_SUCCESS);
    check_flag("ARKStepEvolve", ARKStepEvolve(mem, TG, y, &t, ARK_NORMAL));
    ARKStepFree(&mem);
  } else {
    mem = ERKStepCreate(mfree_sundials_rhs, 0.0, y, sunctx);
    assert_non_null(mem);
    assert_int_equal(ERKStepSVtolerances(mem, RTOL, atol), ARK_SUCCESS);
    assert_int_equal(ERKStepSetUserData(mem, ad), ARK_SUCCESS);
    assert_int_equal(ERKStepSetMaxNumSteps(mem, 100000), ARK_SUCCESS);
    assert_int_equal(ERKStepSetStopTime(mem, TG), ARK_SUCCESS);
    check_flag("ERKStepEvolve", ERKStepEvolve(mem, TG, y, &t, ARK_NORMAL));
    ERKStepFree(&mem);
  }
  assert_true(t == TG);
  memcpy(out, N_VGetArrayPointer(y), sizeof result[0]);
  if (LS) SUNLinSolFree(LS);
  if (Mm) SUNMatDestroy(Mm);
  N_VDestroy(y);
  N_VDestroy(atol);
  mfree_sundials_destroy(&ad);
  mfree_system_destroy(&sys);
  mfree_assembler_destroy(&K);
  mfree_assembler_destroy(&M);
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
}

static void test_galerkin_mass(void **s) {
  (void)s;
  static double ark[NEQ], erk[NEQ];
  run_galerkin(1, ark);
  run_galerkin(0, erk);
  double dmax = 0.0, umax = 0.0;
  for (int i = 0; i < N; ++i) {
    dmax = fmax(dmax, fabs(ark[i] - erk[i]));
    umax = fmax(umax, fabs(erk[i]));
  }
  printf("[ t713 ] Galerkin, consistent mass, to 1 us: ARKStep + KLU mass vs ERKStep %.2e (end displacement %.3e m)\n",
         dmax / umax, erk[N - 1]);
  assert_true(umax > 1e-6);
  assert_true(dmax < 1e-6 * umax);
}

static void test_agreement(void **s) {
  (void)s;
  for (int k = 0; k < NRUNS; ++k)
    if (!done[k]) skip();
  const double ark = distance(result[ARK], result[ERK]), ida = distance(ida_t0, erk_t0);
  const double d05 = distance(result[PC05], result[ERK]), d025 = distance(result[PC025], result[ERK]);
  const double d0125 = distance(result[PC0125], result[ERK]);
  printf("[ t713 ] vs ERKStep: ARKStep %.2e, IDA %.2e, native CFL 0.5 %.2e, 0.25 %.2e, 0.125 %.2e (ratios %.2f %.2f)\n",
         ark, ida, d05, d025, d0125, d05 / d025, d025 / d0125);
  assert_true(ark < 1e-6);
  assert_true(ida < 1e-4);
  assert_true(fabs(d025 / d0125 - 4.0) < 1.0);
  assert_true(d0125 < 2e-4);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_native),       cmocka_unit_test(test_erkstep), cmocka_unit_test(test_arkstep_mass),
      cmocka_unit_test(test_ida),          cmocka_unit_test(test_agreement), cmocka_unit_test(test_galerkin_mass),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
