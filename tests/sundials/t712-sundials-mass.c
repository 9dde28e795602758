/* The mass-matrix pieces of the adapter against mfree's own assembly: the SUNSparseMatrix
 * of mfree_sundials_create_mass_matrix and mfree_sundials_mass (CSR and CSC, lumped and
 * consistent, enlarged when too small), the force form F = M_L f, the residual, the
 * state prediction of the mass function, and a KLU mass solver that follows a change of
 * the consistent mass's sparsity pattern. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <sunlinsol/sunlinsol_klu.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include "suntest.h"

static mfree_context_t *ctx;
static SUNContext sunctx;
static double ystart[SUN_NEQ];

static int setup(void **s) { (void)s; return sun_fixture_setup(&ctx, &sunctx, ystart); }
static int teardown(void **s) { (void)s; return sun_fixture_teardown(&ctx, &sunctx); }

static N_Vector vector_of(const double *y) {
  N_Vector v = N_VNew_Serial(SUN_NEQ, sunctx);
  assert_non_null(v);
  memcpy(N_VGetArrayPointer(v), y, sizeof(double) * SUN_NEQ);
  return v;
}

/* M holds exactly mfree's mass of (sys, y, consistent), in its own format. */
static void assert_same_matrix(mfree_system_t *sys, const double *y, int consistent, SUNMatrix M) {
  mfree_matrix_t *A = NULL;
  assert_ok(ctx, mfree_system_assemble_mass(sys, y, consistent, &A));
  const int64_t *p;
  const int32_t *i;
  const double *x;
  if (SUNSparseMatrix_SparseType(M) == CSR_MAT) assert_ok(ctx, mfree_matrix_get_csr(A, &p, &i, &x));
  else assert_ok(ctx, mfree_matrix_get_csc(A, &p, &i, &x));
  assert_int_equal(SUNSparseMatrix_Rows(M), SUN_NEQ);
  assert_int_equal(SUNSparseMatrix_Columns(M), SUN_NEQ);
  assert_true(SUNSparseMatrix_NNZ(M) >= p[SUN_NEQ]);
  const sunindextype *mp = SUNSparseMatrix_IndexPointers(M), *mi = SUNSparseMatrix_IndexValues(M);
  const double *mx = SUNSparseMatrix_Data(M);
  for (int k = 0; k <= SUN_NEQ; ++k) assert_int_equal(mp[k], p[k]);
  for (int64_t e = 0; e < p[SUN_NEQ]; ++e) {
    assert_int_equal(mi[e], i[e]);
    assert_true(mx[e] == x[e]);
  }
  mfree_matrix_destroy(&A);
}

static void test_matrices(void **s) {
  (void)s;
  mfree_system_t *sys = sun_fluid(ctx);
  mfree_sundials_t *ad = NULL;
  assert_ok(ctx, mfree_sundials_create(ctx, sys, &ad));
  N_Vector y = vector_of(ystart);
  for (int consistent = 0; consistent < 2; ++consistent) {
    assert_ok(ctx, mfree_sundials_set_consistent_mass(ad, consistent));
    SUNMatrix M = NULL;
    assert_ok(ctx, mfree_sundials_create_mass_matrix(ad, sunctx, y, &M));
    assert_int_equal(SUNSparseMatrix_SparseType(M), CSR_MAT);
    assert_same_matrix(sys, ystart, consistent, M);
    /* the mass function refills it at the state create_mass_matrix recorded */
    assert_int_equal(mfree_sundials_mass(0.0, M, ad, NULL, NULL, NULL), 0);
    assert_same_matrix(sys, ystart, consistent, M);
    SUNMatDestroy(M);
    /* host matrices: CSC, and too small (one entry): enlarged */
    for (int type = CSC_MAT; type <= CSR_MAT; ++type) {
      SUNMatrix H = SUNSparseMatrix(SUN_NEQ, SUN_NEQ, 1, type, sunctx);
      assert_int_equal(mfree_sundials_mass(0.0, H, ad, NULL, NULL, NULL), 0);
      assert_same_matrix(sys, ystart, consistent, H);
      SUNMatDestroy(H);
    }
  }
  N_VDestroy(y);
  mfree_sundials_destroy(&ad);
  mfree_system_destroy(&sys);
}

/* F = M_L f: forces in the velocity rows, rates elsewhere; and the residuals */
static void test_forms(void **s) {
  (void)s;
  mfree_system_t *sys = sun_fluid(ctx);
  mfree_sundials_t *ad = NULL;
  assert_ok(ctx, mfree_sundials_create(ctx, sys, &ad));
  N_Vector y = vector_of(ystart), f = N_VClone(y), F = N_VClone(y), r = N_VClone(y);
  assert_int_equal(mfree_sundials_rhs(0.0, y, f, ad), 0);
  assert_int_equal(mfree_sundials_rhs_mass_form(0.0, y, F, ad), 0);
  const double *pf = N_VGetArrayPointer(f), *pF = N_VGetArrayPointer(F);
  mfree_matrix_t *ML = NULL, *MC = NULL;
  assert_ok(ctx, mfree_system_assemble_mass(sys, ystart, 0, &ML));
  double expect[SUN_NEQ];
  assert_ok(ctx, mfree_matrix_apply(ML, pf, expect));
  double fscale = 0.0;
  for (int q = 0; q < SUN_NEQ; ++q) fscale = fmax(fscale, fabs(expect[q]));
  for (int q = 0; q < SUN_NEQ; ++q) {
    assert_true(fabs(pF[q] - expect[q]) <= 1e-15 * fscale);
    if (q < 2 * SUN_N || q >= 4 * SUN_N) assert_true(pF[q] == pf[q]); /* identity rows */
  }
  /* lumped residual at y' = f is zero; the consistent one is M_C f - M_L f */
  assert_int_equal(mfree_sundials_residual(0.0, y, f, r, ad), 0);
  for (int q = 0; q < SUN_NEQ; ++q) assert_true(N_VGetArrayPointer(r)[q] == 0.0);
  assert_ok(ctx, mfree_sundials_set_consistent_mass(ad, 1));
  assert_int_equal(mfree_sundials_residual(0.0, y, f, r, ad), 0);
  assert_ok(ctx, mfree_system_assemble_mass(sys, ystart, 1, &MC));
  double mcf[SUN_NEQ];
  assert_ok(ctx, mfree_matrix_apply(MC, pf, mcf));
  double rmax = 0.0;
  for (int q = 0; q < SUN_NEQ; ++q) {
    assert_true(fabs(N_VGetArrayPointer(r)[q] - (mcf[q] - expect[q])) <= 1e-14 * fscale);
    rmax = fmax(rmax, fabs(N_VGetArrayPointer(r)[q]));
  }
  assert_true(rmax > 1e-6 * fscale); /* the two masses do differ */
  int64_t nrhs = 0, nres = 0;
  assert_ok(ctx, mfree_sundials_get_stats(ad, &nrhs, &nres, NULL, NULL, NULL));
  assert_int_equal(nrhs, 2);
  assert_int_equal(nres, 2);
  mfree_matrix_destroy(&MC);
  mfree_matrix_destroy(&ML);
  N_VDestroy(r);
  N_VDestroy(F);
  N_VDestroy(f);
  N_VDestroy(y);
  mfree_sundials_destroy(&ad);
  mfree_system_destroy(&sys);
}

/* Asked for another time than its state's, the mass function assembles at the state
 * predicted with the rate of the last right-hand side: y + (t - t_y) f(t_y, y) */
static void test_prediction(void **s) {
  (void)s;
  mfree_system_t *sys = sun_fluid(ctx);
  mfree_sundials_t *ad = NULL;
  assert_ok(ctx, mfree_sundials_create(ctx, sys, &ad));
  assert_ok(ctx, mfree_sundials_set_consistent_mass(ad, 1));
  N_Vector y = vector_of(ystart), f = N_VClone(y);
  const double t0 = 0.25, dt = 2e-3;
  assert_int_equal(mfree_sundials_rhs(t0, y, f, ad), 0);
  SUNMatrix M = SUNSparseMatrix(SUN_NEQ, SUN_NEQ, 1, CSR_MAT, sunctx);
  assert_int_equal(mfree_sundials_mass(t0, M, ad, NULL, NULL, NULL), 0);
  assert_same_matrix(sys, ystart, 1, M); /* same time: the state itself */
  assert_int_equal(mfree_sundials_mass(t0 + dt, M, ad, NULL, NULL, NULL), 0);
  double ypred[SUN_NEQ];
  const double step = (t0 + dt) - t0; /* as the adapter computes it */
  for (int q = 0; q < SUN_NEQ; ++q) ypred[q] = ystart[q] + step * N_VGetArrayPointer(f)[q];
  assert_same_matrix(sys, ypred, 1, M);
  int64_t nmass = 0, npred = 0;
  assert_ok(ctx, mfree_sundials_get_stats(ad, NULL, NULL, &nmass, &npred, NULL));
  assert_int_equal(nmass, 2);
  assert_int_equal(npred, 1);
  /* a state set by the host has no rate: used as it is, whatever the time */
  assert_ok(ctx, mfree_sundials_set_state(ad, y));
  assert_int_equal(mfree_sundials_mass(t0 + dt, M, ad, NULL, NULL, NULL), 0);
  assert_same_matrix(sys, ystart, 1, M);
  SUNMatDestroy(M);
  N_VDestroy(f);
  N_VDestroy(y);
  mfree_sundials_destroy(&ad);
  mfree_system_destroy(&sys);
}

/* The consistent mass's pattern changes when a particle moves to new neighbours; the
 * registered KLU solver is re-initialised and solves with the new matrix. */
static double solve_error(SUNLinearSolver LS, SUNMatrix M, mfree_system_t *sys, const double *y) {
  mfree_matrix_t *A = NULL;
  assert_ok(ctx, mfree_system_assemble_mass(sys, y, 1, &A));
  double xtrue[SUN_NEQ], b[SUN_NEQ];
  for (int q = 0; q < SUN_NEQ; ++q) xtrue[q] = 1.0 + 0.01 * q;
  assert_ok(ctx, mfree_matrix_apply(A, xtrue, b));
  N_Vector vb = vector_of(b), vx = N_VClone(vb);
  assert_int_equal(SUNLinSolSetup(LS, M), 0);
  assert_int_equal(SUNLinSolSolve(LS, M, vx, vb, 0.0), 0);
  double err = 0.0;
  for (int q = 0; q < SUN_NEQ; ++q) err = fmax(err, fabs(N_VGetArrayPointer(vx)[q] - xtrue[q]));
  N_VDestroy(vx);
  N_VDestroy(vb);
  mfree_matrix_destroy(&A);
  return err;
}

static void test_pattern_change(void **s) {
  (void)s;
  mfree_system_t *sys = sun_fluid(ctx);
  mfree_sundials_t *ad = NULL;
  assert_ok(ctx, mfree_sundials_create(ctx, sys, &ad));
  assert_ok(ctx, mfree_sundials_set_consistent_mass(ad, 1));
  N_Vector ya = vector_of(ystart);
  SUNMatrix M = NULL;
  assert_ok(ctx, mfree_sundials_create_mass_matrix(ad, sunctx, ya, &M));
  const sunindextype nnz_a = SUNSparseMatrix_IndexPointers(M)[SUN_NEQ];
  SUNLinearSolver LS = SUNLinSol_KLU(ya, M, sunctx);
  assert_ok(ctx, mfree_sundials_set_mass_solver(ad, LS));
  assert_int_equal(SUNLinSolInitialize(LS), 0);
  /* the condition number is ~1e6 (nodal integration): 1e-7 is round-off */
  assert_true(solve_error(LS, M, sys, ystart) < 1e-7);

  /* state b: the corner particle 0 moved half a spacing inwards, its neighbours change */
  double yb[SUN_NEQ];
  memcpy(yb, ystart, sizeof yb);
  yb[0] += 0.5 * SUN_D;
  yb[1] += 0.5 * SUN_D;
  N_Vector vb = vector_of(yb);
  assert_ok(ctx, mfree_sundials_set_state(ad, vb));
  assert_int_equal(mfree_sundials_mass(0.0, M, ad, NULL, NULL, NULL), 0);
  const sunindextype nnz_b = SUNSparseMatrix_IndexPointers(M)[SUN_NEQ];
  printf("[ t712 ] consistent mass nnz %ld -> %ld\n", (long)nnz_a, (long)nnz_b);
  assert_true(nnz_b != nnz_a);
  assert_same_matrix(sys, yb, 1, M);
  int64_t npattern = 0;
  assert_ok(ctx, mfree_sundials_get_stats(ad, NULL, NULL, NULL, NULL, &npattern));
  assert_int_equal(npattern, 1);
  assert_true(solve_error(LS, M, sys, yb) < 1e-7); /* analysed afresh */
  /* the same pattern again: no re-initialisation */
  assert_int_equal(mfree_sundials_mass(0.0, M, ad, NULL, NULL, NULL), 0);
  assert_ok(ctx, mfree_sundials_get_stats(ad, NULL, NULL, NULL, NULL, &npattern));
  assert_int_equal(npattern, 1);
  SUNLinSolFree(LS);
  SUNMatDestroy(M);
  N_VDestroy(vb);
  N_VDestroy(ya);
  mfree_sundials_destroy(&ad);
  mfree_system_destroy(&sys);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_matrices),
      cmocka_unit_test(test_forms),
      cmocka_unit_test(test_prediction),
      cmocka_unit_test(test_pattern_change),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
