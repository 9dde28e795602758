/* Compiled with -fsyntax-only as strict C99 (t790) and as C++14 (t791): the adapter's
 * header, with the SUNDIALS headers it includes, must be clean in both, every warning
 * an error, and its declarations usable as SUNDIALS callbacks. */
#include <mfree_sundials.h>

#include <arkode/arkode.h>
#include <arkode/arkode_ls.h>
#include <ida/ida.h>

/* the callbacks have exactly SUNDIALS' callback types */
static ARKRhsFn rhs_fn = mfree_sundials_rhs;
static ARKRhsFn mass_form_fn = mfree_sundials_rhs_mass_form;
static ARKLsMassFn mass_fn = mfree_sundials_mass;
static IDAResFn res_fn = mfree_sundials_residual;

int header_use(mfree_system_t *sys, N_Vector y, N_Vector ydot);
int header_use(mfree_system_t *sys, N_Vector y, N_Vector ydot) {
  mfree_context_t *ctx = 0;
  mfree_sundials_t *ad = 0;
  SUNContext sunctx = 0;
  SUNMatrix M = 0;
  int64_t nrhs = 0, nres = 0, nmass = 0, npred = 0, npat = 0;
  mfree_sundials_errcode_t sunerr = 0;
  int r = 0;
  mfree_status_t st = mfree_context_create(&ctx);
  if (SUNContext_Create(MFREE_SUNDIALS_COMM_NULL, &sunctx) != 0) return -1;
  if (st == MFREE_SUCCESS) st = mfree_sundials_create(ctx, sys, &ad);
  if (st == MFREE_SUCCESS) st = mfree_sundials_set_consistent_mass(ad, 1);
  if (st == MFREE_SUCCESS) st = mfree_sundials_set_state(ad, y);
  if (st == MFREE_SUCCESS) st = mfree_sundials_set_mass_solver(ad, 0);
  if (st == MFREE_SUCCESS) st = mfree_sundials_create_mass_matrix(ad, sunctx, y, &M);
  if (st == MFREE_SUCCESS) r = rhs_fn(0.0, y, ydot, ad) + mass_form_fn(0.0, y, ydot, ad) +
                               mass_fn(0.0, M, ad, y, y, y) + res_fn(0.0, y, ydot, ydot, ad);
  if (st == MFREE_SUCCESS) st = mfree_sundials_get_stats(ad, &nrhs, &nres, &nmass, &npred, &npat);
  if (M) SUNMatDestroy(M);
  mfree_sundials_destroy(&ad);
  sunerr = SUNContext_Free(&sunctx);
  mfree_context_destroy(&ctx);
  return (int)st + r + (int)sunerr;
}
