/* A host program of the installed libmfree_sundials: a 4 x 4 Galerkin-SPH fluid patch
 * integrated with ERKStep and IDA through the adapter's callbacks; prints
 * "<integrator>: ok" lines when both agree with the native predictor-corrector to its
 * (second-order) accuracy. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <arkode/arkode_erkstep.h>
#include <ida/ida.h>
#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <mfree_sundials.h>

enum { NX = 4, N = NX * NX, NEQ = 5 * N };
static const double D = 0.005, RHO0 = 1000.0, T = 2e-3;

static mfree_system_t *fluid(mfree_context_t *ctx) {
  mfree_system_t *s = NULL;
  const double m = RHO0 * D * D, kappa = 100.0 * RHO0 * 2.0 * 9.81 * 0.04 / 7.0;
  if (mfree_system_create_fluid(ctx, 2, N, &s) || mfree_system_set_fluid(s, &RHO0, 0, kappa, 7.0, 0.5) ||
      mfree_system_set_masses(s, &m, 0) || mfree_system_set_smoothing(s, 1.5 * D))
    return NULL;
  return s;
}

int main(void) {
  mfree_context_t *ctx = NULL;
  SUNContext sunctx = NULL;
  if (mfree_context_create(&ctx) || SUNContext_Create(MFREE_SUNDIALS_COMM_NULL, &sunctx)) return 1;
  double y0[NEQ], ref[NEQ];
  for (int p = 0; p < N; ++p) {
    const double x = (p % NX + 0.5) * D, z = (p / NX + 0.5) * D;
    y0[2 * p] = x;
    y0[2 * p + 1] = z;
    y0[2 * N + 2 * p] = 0.1 * sin(3.14159 * x / (NX * D));
    y0[2 * N + 2 * p + 1] = 0.0;
    y0[4 * N + p] = RHO0;
  }
  mfree_system_t *sys = fluid(ctx);
  mfree_sundials_t *ad = NULL;
  if (!sys || mfree_sundials_create(ctx, sys, &ad)) return 1;
  double t = 0.0;
  memcpy(ref, y0, sizeof ref);
  if (mfree_system_integrate(sys, MFREE_INTEGRATOR_PREDICTOR_CORRECTOR, ref, &t, T, 0.05, 0.0, NULL, NULL,
                             NULL))
    return 1;
  int failures = 0;
  for (int which = 0; which < 2; ++which) {
    N_Vector y = N_VNew_Serial(NEQ, sunctx), yp = N_VClone(y);
    memcpy(N_VGetArrayPointer(y), y0, sizeof y0);
    int flag;
    t = 0.0;
    if (which == 0) {
      void *mem = ERKStepCreate(mfree_sundials_rhs, 0.0, y, sunctx);
      ERKStepSStolerances(mem, 1e-9, 1e-12);
      ERKStepSetUserData(mem, ad);
      ERKStepSetMaxNumSteps(mem, 100000);
      ERKStepSetStopTime(mem, T);
      flag = ERKStepEvolve(mem, T, y, &t, ARK_NORMAL);
      ERKStepFree(&mem);
    } else {
      SUNMatrix A = SUNDenseMatrix(NEQ, NEQ, sunctx);
      SUNLinearSolver LS = SUNLinSol_Dense(y, A, sunctx);
      mfree_sundials_rhs(0.0, y, yp, ad);
      void *mem = IDACreate(sunctx);
      IDAInit(mem, mfree_sundials_residual, 0.0, y, yp);
      IDASStolerances(mem, 1e-9, 1e-12);
      IDASetUserData(mem, ad);
      IDASetLinearSolver(mem, LS, A);
      IDASetMaxNumSteps(mem, 100000);
      IDASetStopTime(mem, T);
      flag = IDASolve(mem, T, &t, y, yp, IDA_NORMAL);
      IDAFree(&mem);
      SUNLinSolFree(LS);
      SUNMatDestroy(A);
    }
    double err = 0.0, scale = 0.0;
    for (int q = 2 * N; q < 4 * N; ++q) { /* velocities */
      err = fmax(err, fabs(N_VGetArrayPointer(y)[q] - ref[q]));
      scale = fmax(scale, fabs(ref[q]));
    }
    const char *name = which == 0 ? "erkstep" : "ida";
    if (flag < 0 || !(err < 1e-2 * scale)) { /* the native scheme's second-order error */
      char msg[256] = "";
      mfree_context_get_last_error(ctx, NULL, msg, sizeof msg);
      fprintf(stderr, "%s: flag %d, velocity difference %g of %g: %s\n", name, flag, err, scale, msg);
      ++failures;
    } else {
      printf("%s: ok\n", name);
    }
    N_VDestroy(yp);
    N_VDestroy(y);
  }
  mfree_sundials_destroy(&ad);
  mfree_system_destroy(&sys);
  SUNContext_Free(&sunctx);
  mfree_context_destroy(&ctx);
  return failures != 0;
}
