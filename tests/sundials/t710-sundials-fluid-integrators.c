/* One Galerkin-SPH fluid patch (paper 003; 8 x 8 particles, spacing 0.005, h = 1.5 d,
 * rest density 1000, kappa of 003 eq 125 with H = 0.04, mu = 0.5, no gravity, no walls,
 * a divergence-free initial velocity of amplitude 0.1 m/s; suntest.c) integrated by
 *  (a) mfree_system_integrate, predictor-corrector (003 eqs 111-119), CFL 0.2 and 0.1,
 *      to T = 0.03 s (179 and 358 steps);
 *  (b) ERKStep with mfree_sundials_rhs (identity mass), to T1 = 0.0015 s and T;
 *  (c) ARKStep, explicit, with the lumped mass through the mass-matrix interface
 *      (mfree_sundials_rhs_mass_form + mfree_sundials_mass, SUNLinSol_KLU), to T1;
 *  (d) IDA with mfree_sundials_residual, lumped mass, to T1 and T; linear solver
 *      SPGMR without preconditioner (IDA's difference-quotient Jacobian-vector
 *      products: 2 to 3 residuals per Newton iteration instead of the 320 of a dense
 *      difference-quotient Jacobian, 15 times faster here);
 *  (e) the consistent mass (003 eq 42), another semi-discrete model whose mass matrix
 *      is nearly singular under nodal integration (condition ~1e6 for this patch:
 *      explicit steps ~3e-7 s), to TC = 5e-5 s: ARKStep + KLU against IDA + SPGMR
 *      preconditioned by c_j M_C (KLU, refilled through mfree_sundials_set_state +
 *      mfree_sundials_mass), y'(0) from M_C y' = F(0, y0) solved with KLU.
 * ERKStep and ARKStep use rtol 1e-10, IDA 1e-11 (against an ERKStep reference at
 * 1e-12, BDF's global error is the larger: 7e-7 at rtol 1e-10, 4e-7 at 3e-11, where
 * ERKStep's is 2e-8 at 1e-10); atol 1e-12. Agreement is measured block by block:
 * positions and densities relative to the largest displacement and density change of
 * the reference, velocities relative to the largest velocity (suntest.c). Tolerances:
 *  - (d) vs (b): the same ODE by independent methods (explicit RK 4(3) vs BDF 1-5):
 *    1e-6 (the densities set it: rtol * rho ~ 1e-8 kg/m^3 per step, over ~1300 BDF
 *    steps, against a change of 0.5 kg/m^3).
 *  - (c) vs (b): ARKODE asks for the mass at a stage time before it computes that
 *    stage, and the adapter assembles at a first-order prediction of the stage state
 *    (error O(h^2) in M, seen and controlled by ARKODE's error estimate): 1e-6 too.
 *  - (e): the same, 1e-6.
 *  - (a): second order: its distance to (b) must shrink by 4 +- 1.2 when the CFL
 *    number halves (observed: 4.3), and be below 3e-2 at CFL 0.1 (observed: 1.4e-2,
 *    in the densities, i.e. 7e-3 kg/m^3 of a 0.5 kg/m^3 change; positions 5e-6,
 *    velocities 5e-4): the observed second-order error sets the tolerance.
 * Run times and counters are printed. */
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

static const double T_END = 0.03, T1 = 0.0015, TC = 5e-5;
static const double RTOL = 1e-10, RTOL_IDA = 1e-11, ATOL = 1e-12;

static mfree_context_t *ctx;
static SUNContext sunctx;
static double ystart[SUN_NEQ];
enum { PC2, PC1, ERK1, ERK, ARK1, IDA1, IDA, ARKC, IDAC, NRUNS };
static double result[NRUNS][SUN_NEQ];
static int done[NRUNS];

static int setup(void **s) { (void)s; return sun_fixture_setup(&ctx, &sunctx, ystart); }
static int teardown(void **s) { (void)s; return sun_fixture_teardown(&ctx, &sunctx); }

static void report(const char *what, double secs, long nst, const mfree_sundials_t *ad) {
  int64_t nrhs = 0, nres = 0, nmass = 0, npred = 0, npat = 0;
  if (ad) mfree_sundials_get_stats(ad, &nrhs, &nres, &nmass, &npred, &npat);
  printf("[ t710 ] %-36s %6.2f s %5ld steps %6lld rhs %6lld res %5lld mass (%lld predicted, "
         "%lld new patterns)\n",
         what, secs, nst, (long long)nrhs, (long long)nres, (long long)nmass, (long long)npred,
         (long long)npat);
  fflush(stdout);
}

static void check_flag(const char *call, int flag) {
  if (flag < 0) {
    char msg[512];
    mfree_context_get_last_error(ctx, NULL, msg, sizeof msg);
    fail_msg("%s returned %d; last mfree error: %s", call, flag, msg);
  }
}

static N_Vector initial_vector(void) {
  N_Vector y = N_VNew_Serial(SUN_NEQ, sunctx);
  assert_non_null(y);
  memcpy(N_VGetArrayPointer(y), ystart, sizeof ystart);
  return y;
}

/* (a) the native predictor-corrector at two CFL numbers */
static void test_native(void **s) {
  (void)s;
  for (int k = 0; k < 2; ++k) {
    const double cfl = k == 0 ? 0.2 : 0.1;
    mfree_system_t *sys = sun_fluid(ctx);
    double *y = result[k == 0 ? PC2 : PC1], t = 0.0;
    int64_t ns = 0;
    memcpy(y, ystart, sizeof ystart);
    const double t0 = sun_seconds();
    assert_ok(ctx, mfree_system_integrate(sys, MFREE_INTEGRATOR_PREDICTOR_CORRECTOR, y, &t, T_END,
                                          cfl, 0.0, NULL, NULL, &ns));
    char what[64];
    snprintf(what, sizeof what, "(a) native PC, CFL %.1f, to T", cfl);
    report(what, sun_seconds() - t0, (long)ns, NULL);
    assert_true(t == T_END);
    assert_true(ns > 150);
    done[k == 0 ? PC2 : PC1] = 1;
    mfree_system_destroy(&sys);
  }
}

/* (b) ERKStep, y' = f(t, y), output at T1 and T */
static void test_erkstep(void **s) {
  (void)s;
  mfree_system_t *sys = sun_fluid(ctx);
  mfree_sundials_t *ad = NULL;
  assert_ok(ctx, mfree_sundials_create(ctx, sys, &ad));
  N_Vector y = initial_vector();
  void *mem = ERKStepCreate(mfree_sundials_rhs, 0.0, y, sunctx);
  assert_non_null(mem);
  assert_int_equal(ERKStepSStolerances(mem, RTOL, ATOL), ARK_SUCCESS);
  assert_int_equal(ERKStepSetUserData(mem, ad), ARK_SUCCESS);
  assert_int_equal(ERKStepSetMaxNumSteps(mem, 100000), ARK_SUCCESS);
  const double t0 = sun_seconds();
  double t = 0.0;
  for (int k = 0; k < 2; ++k) {
    const double tout = k == 0 ? T1 : T_END;
    assert_int_equal(ERKStepSetStopTime(mem, tout), ARK_SUCCESS);
    check_flag("ERKStepEvolve", ERKStepEvolve(mem, tout, y, &t, ARK_NORMAL));
    assert_true(t == tout);
    memcpy(result[k == 0 ? ERK1 : ERK], N_VGetArrayPointer(y), sizeof ystart);
  }
  long nst = 0;
  ERKStepGetNumSteps(mem, &nst);
  report("(b) ERKStep, rhs, to T", sun_seconds() - t0, nst, ad);
  done[ERK1] = done[ERK] = 1;
  ERKStepFree(&mem);
  N_VDestroy(y);
  mfree_sundials_destroy(&ad);
  mfree_system_destroy(&sys);
}

/* (c), (e) ARKStep, explicit, M y' = F(t, y) with a KLU mass solver */
static void run_arkstep(int consistent, double tend, double *out) {
  mfree_system_t *sys = sun_fluid(ctx);
  mfree_sundials_t *ad = NULL;
  assert_ok(ctx, mfree_sundials_create(ctx, sys, &ad));
  assert_ok(ctx, mfree_sundials_set_consistent_mass(ad, consistent));
  N_Vector y = initial_vector();
  SUNMatrix M = NULL;
  assert_ok(ctx, mfree_sundials_create_mass_matrix(ad, sunctx, y, &M)); /* state = y0 */
  SUNLinearSolver LS = SUNLinSol_KLU(y, M, sunctx);
  assert_non_null(LS);
  assert_ok(ctx, mfree_sundials_set_mass_solver(ad, LS));
  void *mem = ARKStepCreate(mfree_sundials_rhs_mass_form, NULL, 0.0, y, sunctx);
  assert_non_null(mem);
  assert_int_equal(ARKStepSetMassLinearSolver(mem, LS, M, SUNTRUE), ARK_SUCCESS);
  assert_int_equal(ARKStepSetMassFn(mem, mfree_sundials_mass), ARK_SUCCESS);
  assert_int_equal(ARKStepSStolerances(mem, RTOL, ATOL), ARK_SUCCESS);
  assert_int_equal(ARKStepSetUserData(mem, ad), ARK_SUCCESS);
  assert_int_equal(ARKStepSetMaxNumSteps(mem, 100000), ARK_SUCCESS);
  assert_int_equal(ARKStepSetStopTime(mem, tend), ARK_SUCCESS);
  double t = 0.0;
  const double t0 = sun_seconds();
  check_flag("ARKStepEvolve", ARKStepEvolve(mem, tend, y, &t, ARK_NORMAL));
  long nst = 0;
  ARKStepGetNumSteps(mem, &nst);
  report(consistent ? "(e) ARKStep + KLU, consistent, to TC" : "(c) ARKStep + KLU, lumped, to T1",
         sun_seconds() - t0, nst, ad);
  assert_true(t == tend);
  /* ARKStep asked for the mass at stage times the adapter had no state for */
  int64_t nmass = 0, npred = 0;
  assert_ok(ctx, mfree_sundials_get_stats(ad, NULL, NULL, &nmass, &npred, NULL));
  assert_true(nmass > nst && npred > 0);
  memcpy(out, N_VGetArrayPointer(y), sizeof ystart);
  ARKStepFree(&mem);
  SUNLinSolFree(LS);
  SUNMatDestroy(M);
  N_VDestroy(y);
  mfree_sundials_destroy(&ad);
  mfree_system_destroy(&sys);
}

static void test_arkstep_lumped(void **s) {
  (void)s;
  run_arkstep(0, T1, result[ARK1]);
  done[ARK1] = 1;
}

/* (d) IDA, lumped mass: r = y' - f(t, y) */
static void test_ida_lumped(void **s) {
  (void)s;
  mfree_system_t *sys = sun_fluid(ctx);
  mfree_sundials_t *ad = NULL;
  assert_ok(ctx, mfree_sundials_create(ctx, sys, &ad));
  N_Vector yy = initial_vector(), yp = N_VClone(yy);
  assert_int_equal(mfree_sundials_rhs(0.0, yy, yp, ad), 0); /* consistent y'(0) = f */
  void *mem = IDACreate(sunctx);
  assert_non_null(mem);
  assert_int_equal(IDAInit(mem, mfree_sundials_residual, 0.0, yy, yp), IDA_SUCCESS);
  assert_int_equal(IDASStolerances(mem, RTOL_IDA, ATOL), IDA_SUCCESS);
  assert_int_equal(IDASetUserData(mem, ad), IDA_SUCCESS);
  SUNLinearSolver LS = SUNLinSol_SPGMR(yy, SUN_PREC_NONE, 0, sunctx);
  assert_int_equal(IDASetLinearSolver(mem, LS, NULL), IDA_SUCCESS);
  assert_int_equal(IDASetMaxNumSteps(mem, 100000), IDA_SUCCESS);
  const double t0 = sun_seconds();
  double t = 0.0;
  for (int k = 0; k < 2; ++k) {
    const double tout = k == 0 ? T1 : T_END;
    assert_int_equal(IDASetStopTime(mem, tout), IDA_SUCCESS);
    check_flag("IDASolve", IDASolve(mem, tout, &t, yy, yp, IDA_NORMAL));
    assert_true(t == tout);
    memcpy(result[k == 0 ? IDA1 : IDA], N_VGetArrayPointer(yy), sizeof ystart);
  }
  long nst = 0;
  IDAGetNumSteps(mem, &nst);
  report("(d) IDA + SPGMR, lumped, to T", sun_seconds() - t0, nst, ad);
  done[IDA1] = done[IDA] = 1;
  IDAFree(&mem);
  SUNLinSolFree(LS);
  N_VDestroy(yp);
  N_VDestroy(yy);
  mfree_sundials_destroy(&ad);
  mfree_system_destroy(&sys);
}

/* (e) IDA, consistent mass: r = M_C(y) y' - M_L(y) f(t, y); the Newton matrix
 * c_j M_C + dr/dy is dominated by c_j M_C for small steps, which preconditions GMRES */
static struct {
  mfree_sundials_t *ad;
  SUNMatrix M;
  SUNLinearSolver LS;
} prec;

static int prec_setup(sunrealtype t, N_Vector yy, N_Vector yp, N_Vector rr, sunrealtype cj,
                      void *user_data) {
  (void)yp;
  (void)rr;
  (void)cj;
  (void)user_data;
  if (mfree_sundials_set_state(prec.ad, yy) != MFREE_SUCCESS) return -1;
  const int r = mfree_sundials_mass(t, prec.M, prec.ad, NULL, NULL, NULL); /* M_C(y) */
  if (r != 0) return r;
  return SUNLinSolSetup(prec.LS, prec.M) == 0 ? 0 : 1;
}

static int prec_solve(sunrealtype t, N_Vector yy, N_Vector yp, N_Vector rr, N_Vector rvec,
                      N_Vector zvec, sunrealtype cj, sunrealtype delta, void *user_data) {
  (void)t;
  (void)yy;
  (void)yp;
  (void)rr;
  (void)delta;
  (void)user_data;
  if (SUNLinSolSolve(prec.LS, prec.M, zvec, rvec, 0.0) != 0) return 1;
  N_VScale(1.0 / cj, zvec, zvec);
  return 0;
}

static void run_ida_consistent(double *out) {
  mfree_system_t *sys = sun_fluid(ctx);
  mfree_sundials_t *ad = NULL;
  assert_ok(ctx, mfree_sundials_create(ctx, sys, &ad));
  assert_ok(ctx, mfree_sundials_set_consistent_mass(ad, 1));
  N_Vector yy = initial_vector(), yp = N_VClone(yy), F = N_VClone(yy);
  prec.ad = ad;
  assert_ok(ctx, mfree_sundials_create_mass_matrix(ad, sunctx, yy, &prec.M));
  prec.LS = SUNLinSol_KLU(yy, prec.M, sunctx);
  assert_non_null(prec.LS);
  assert_ok(ctx, mfree_sundials_set_mass_solver(ad, prec.LS)); /* new patterns: re-analyse */
  /* y'(0) from M_C y' = F(0, y0) */
  assert_int_equal(SUNLinSolInitialize(prec.LS), 0);
  assert_int_equal(SUNLinSolSetup(prec.LS, prec.M), 0);
  assert_int_equal(mfree_sundials_rhs_mass_form(0.0, yy, F, ad), 0);
  assert_int_equal(SUNLinSolSolve(prec.LS, prec.M, yp, F, 0.0), 0);
  void *mem = IDACreate(sunctx);
  assert_non_null(mem);
  assert_int_equal(IDAInit(mem, mfree_sundials_residual, 0.0, yy, yp), IDA_SUCCESS);
  assert_int_equal(IDASStolerances(mem, RTOL_IDA, ATOL), IDA_SUCCESS);
  assert_int_equal(IDASetUserData(mem, ad), IDA_SUCCESS);
  SUNLinearSolver LS = SUNLinSol_SPGMR(yy, SUN_PREC_LEFT, 0, sunctx);
  assert_int_equal(IDASetLinearSolver(mem, LS, NULL), IDA_SUCCESS);
  assert_int_equal(IDASetPreconditioner(mem, prec_setup, prec_solve), IDA_SUCCESS);
  assert_int_equal(IDASetMaxNumSteps(mem, 100000), IDA_SUCCESS);
  assert_int_equal(IDASetStopTime(mem, TC), IDA_SUCCESS);
  const double t0 = sun_seconds();
  double t = 0.0;
  check_flag("IDASolve", IDASolve(mem, TC, &t, yy, yp, IDA_NORMAL));
  long nst = 0;
  IDAGetNumSteps(mem, &nst);
  report("(e) IDA + SPGMR/KLU, consistent, to TC", sun_seconds() - t0, nst, ad);
  assert_true(t == TC);
  memcpy(out, N_VGetArrayPointer(yy), sizeof ystart);
  IDAFree(&mem);
  SUNLinSolFree(LS);
  SUNLinSolFree(prec.LS);
  SUNMatDestroy(prec.M);
  N_VDestroy(F);
  N_VDestroy(yp);
  N_VDestroy(yy);
  mfree_sundials_destroy(&ad);
  mfree_system_destroy(&sys);
}

static void test_consistent(void **s) {
  (void)s;
  run_arkstep(1, TC, result[ARKC]);
  done[ARKC] = 1;
  run_ida_consistent(result[IDAC]);
  done[IDAC] = 1;
}

static sun_diff_t compare(const char *what, int a, int b) {
  const sun_diff_t d = sun_compare(result[a], result[b], ystart);
  printf("[ t710 ] %-36s x %.2e  v %.2e  rho %.2e\n", what, d.x, d.v, d.rho);
  fflush(stdout);
  return d;
}

static void test_agreement(void **s) {
  (void)s;
  for (int k = 0; k < NRUNS; ++k)
    if (!done[k]) fail_msg("run %d did not complete", k);
  double dx = 0.0, vmax = 0.0, drho = 0.0;
  for (int q = 0; q < SUN_NEQ; ++q) {
    const double d = fabs(result[ERK][q] - ystart[q]);
    if (q < 2 * SUN_N) dx = fmax(dx, d);
    else if (q < 4 * SUN_N) vmax = fmax(vmax, fabs(result[ERK][q]));
    else drho = fmax(drho, d);
  }
  printf("[ t710 ] motion at T: max |x - x0| %.2e m, max |v| %.2e m/s, max |rho - rho0| %.2e "
         "kg/m^3\n", dx, vmax, drho);
  assert_true(dx > 0.05 * SUN_D && drho > 0.01); /* not a trivial motion */
  const double ida = sun_diff_max(compare("(d) IDA vs (b) ERKStep at T", IDA, ERK));
  const double ida1 = sun_diff_max(compare("(d) IDA vs (b) ERKStep at T1", IDA1, ERK1));
  const double ark1 = sun_diff_max(compare("(c) ARKStep vs (b) ERKStep at T1", ARK1, ERK1));
  const double cons = sun_diff_max(compare("(e) ARKStep vs IDA, consistent, TC", ARKC, IDAC));
  const double pc2 = sun_diff_max(compare("(a) native CFL 0.2 vs (b) at T", PC2, ERK));
  const double pc1 = sun_diff_max(compare("(a) native CFL 0.1 vs (b) at T", PC1, ERK));
  printf("[ t710 ] native error ratio CFL 0.2 / CFL 0.1: %.2f\n", pc2 / pc1);
  fflush(stdout);
  assert_true(ida < 1e-6);
  assert_true(ida1 < 1e-6);
  assert_true(ark1 < 1e-6);
  assert_true(cons < 1e-6);
  assert_true(pc1 < 3e-2);
  assert_true(fabs(pc2 / pc1 - 4.0) < 1.2);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_native),         cmocka_unit_test(test_erkstep),
      cmocka_unit_test(test_arkstep_lumped), cmocka_unit_test(test_ida_lumped),
      cmocka_unit_test(test_consistent),     cmocka_unit_test(test_agreement),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
