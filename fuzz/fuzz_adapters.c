/* libFuzzer harness: the SuiteSparse and SUNDIALS adapters (built when both adapters
 * are). Bytes -> (a) a matrix from host CSR (square or not, symmetric or not, unsorted,
 * repeated or out-of-range columns, NaN/Inf, empty rows: a singular matrix), a solver
 * kind (CHOLMOD, UMFPACK, KLU, unknown), the index width and rcond threshold, setup,
 * solve with several right-hand sides and leading dimensions (in place too), update with
 * new values, info; (b) a small fluid system behind the SUNDIALS adapter: the right-hand
 * side in both forms, the residual, the mass matrix into SUNDIALS matrices of the right
 * and the wrong size or format, a state vector of the wrong length, NaN states.
 * Oracles: documented statuses (the SUNDIALS callbacks return 0, > 0 recoverable or < 0
 * fatal); a successful solve of a finite system gives finite values. */
#include "fuzz_util.h"

#include <mfree_suitesparse.h>
#include <mfree_sundials.h>
#include <nvector/nvector_serial.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunmatrix/sunmatrix_sparse.h>

enum { MAXR = 12, MAXNNZ = 8 * MAXR };

static void suitesparse(fz_bytes_t *b, mfree_context_t *ctx) {
  const unsigned opts = fz_u8(b);
  const int32_t nr = (int32_t)(fz_u8(b) % (MAXR + 1));
  const int32_t nc = (opts & 1) ? nr : (int32_t)(fz_u8(b) % (MAXR + 1));
  int64_t rp[MAXR + 1];
  int32_t cl[MAXNNZ];
  double v[MAXNNZ];
  int finite = 1;
  rp[0] = 0;
  for (int32_t i = 0; i < nr; ++i) {
    int64_t k = rp[i];
    /* a diagonal entry first (mostly), then a few others */
    if (i < nc && (opts & 2)) cl[k] = i, v[k++] = 4.0 + fz_u8(b) % 4;
    const int len = (int)(fz_u8(b) % 4);
    for (int q = 0; q < len && k < MAXNNZ; ++q, ++k) {
      const unsigned w = fz_u8(b);
      cl[k] = nc > 0 ? (int32_t)(w % (unsigned)nc) : 0;
      v[k] = w == 255 ? NAN : w == 254 ? INFINITY : ((int)w - 128) / 128.0;
      finite &= w < 254;
    }
    rp[i + 1] = k;
  }
  mfree_matrix_t *A = NULL;
  FZ_CHECK(mfree_matrix_create_csr(ctx, nr, nc, rp, cl, v, &A));
  if (!A) return;
  mfree_suitesparse_t *s = NULL;
  FZ_CHECK(mfree_suitesparse_create(ctx, (mfree_solver_kind_t)((opts >> 3) % 4 + (opts & 128 ? 1 : 0)), &s));
  if (s) {
    if (opts & 32) FZ_CHECK(mfree_suitesparse_set_index_width(s, (opts & 64) ? 64 : 32));
    if (opts & 64) FZ_CHECK(mfree_suitesparse_set_rcond_threshold(s, fz_positive(b, 1e-12)));
    const mfree_status_t st = mfree_suitesparse_setup(s, A);
    FZ_TRAP_IF(!fz_valid_status(st));
    const int32_t nrhs = (int32_t)(fz_u8(b) % 4) - (opts & 16 ? 1 : 0);
    const unsigned wl = fz_u8(b);
    const int64_t ld = (wl & 1) ? (nr > 0 ? nr : 1) + (int64_t)(wl >> 1) % 3 : INT64_MAX / (1 + (wl >> 1) % 4);
    double *bb = calloc((size_t)4 * (MAXR + 3), sizeof *bb), *xx = calloc((size_t)4 * (MAXR + 3), sizeof *xx);
    for (int k = 0; k < 4 * (MAXR + 3); ++k) bb[k] = 1.0 + k % 5;
    const int64_t ldx = ld <= MAXR + 3 ? ld : (nr > 0 ? nr : 1);
    const mfree_status_t ss = ld <= MAXR + 3 ? mfree_suitesparse_solve(s, nrhs, bb, ld, (wl & 2) ? bb : xx, ld)
                                             : mfree_suitesparse_solve(s, nrhs, bb, ld, xx, ldx);
    FZ_TRAP_IF(!fz_valid_status(ss));
    FZ_TRAP_IF(ld > MAXR + 3 && nrhs > 1 && nr > 0 && ss == MFREE_SUCCESS); /* a wrapping ld is refused */
    if (ss == MFREE_SUCCESS && finite && st == MFREE_SUCCESS && ld <= MAXR + 3 && !(wl & 2))
      for (int32_t r = 0; r < nrhs; ++r)
        for (int32_t i = 0; i < nr; ++i) FZ_TRAP_IF(isnan(xx[r * ld + i]));
    for (int64_t k = 0; k < rp[nr]; ++k) v[k] *= 1.5;
    mfree_matrix_t *A2 = NULL;
    FZ_CHECK(mfree_matrix_create_csr(ctx, nr, nc, rp, cl, v, &A2));
    if (A2) FZ_CHECK(mfree_suitesparse_update(s, A2));
    double rc = 0.0;
    int64_t fnnz = 0;
    int32_t width = 0;
    FZ_CHECK(mfree_suitesparse_get_info(s, &rc, &fnnz, &width));
    mfree_matrix_destroy(&A2);
    free(bb), free(xx);
  }
  mfree_suitesparse_destroy(&s);
  mfree_matrix_destroy(&A);
}

static int valid_callback(int r) { return r >= -1000 && r <= 1000; }

static void sundials(fz_bytes_t *b, mfree_context_t *ctx) {
  SUNContext sunctx = NULL;
  if (SUNContext_Create(MFREE_SUNDIALS_COMM_NULL, &sunctx) != 0) return;
  const int m = 2 + (int)(fz_u8(b) % 3), n = m * m, dim = 2;
  const unsigned opts = fz_u8(b);
  const double sp = 1.0 / m;
  mfree_system_t *sys = NULL;
  FZ_CHECK(mfree_system_create_fluid(ctx, dim, n, &sys));
  const double mass = 1000.0 * sp * sp;
  if (sys) {
    FZ_CHECK(mfree_system_set_masses(sys, &mass, 0));
    FZ_CHECK(mfree_system_set_smoothing(sys, 1.5 * sp));
  }
  int32_t neq = 0;
  if (!sys || mfree_system_get_size(sys, &neq) != MFREE_SUCCESS) {
    mfree_system_destroy(&sys);
    SUNContext_Free(&sunctx);
    return;
  }
  N_Vector y = N_VNew_Serial(neq, sunctx), yd = N_VNew_Serial(neq, sunctx), r = N_VNew_Serial(neq, sunctx);
  N_Vector wrong = N_VNew_Serial(neq + 1, sunctx);
  double *Y = N_VGetArrayPointer(y), *YD = N_VGetArrayPointer(yd);
  for (int q = 0; q < n; ++q) {
    for (int c = 0; c < dim; ++c) {
      const unsigned w = fz_u8(b);
      Y[dim * q + c] = ((c ? q / m : q % m) + 0.5 + (w == 255 ? NAN : (w / 255.0 - 0.5) * 0.4)) * sp;
      Y[dim * n + dim * q + c] = 0.0;
      YD[dim * q + c] = YD[dim * n + dim * q + c] = 0.0;
    }
    Y[2 * dim * n + q] = 1000.0, YD[2 * dim * n + q] = 0.0;
  }
  mfree_sundials_t *ad = NULL;
  FZ_CHECK(mfree_sundials_create(ctx, sys, &ad));
  if (ad) {
    FZ_CHECK(mfree_sundials_set_consistent_mass(ad, (int32_t)(opts & 1)));
    FZ_CHECK(mfree_sundials_set_state(ad, (opts & 2) ? wrong : y));
    FZ_TRAP_IF(!valid_callback(mfree_sundials_rhs(0.0, y, yd, ad)));
    FZ_TRAP_IF(!valid_callback(mfree_sundials_rhs_mass_form(0.0, y, r, ad)));
    FZ_TRAP_IF(!valid_callback(mfree_sundials_residual(0.0, y, yd, r, ad)));
    FZ_TRAP_IF(!valid_callback(mfree_sundials_rhs(0.0, wrong, yd, ad)));
    SUNMatrix M = NULL;
    FZ_CHECK(mfree_sundials_create_mass_matrix(ad, sunctx, y, &M));
    if (M) {
      FZ_TRAP_IF(!valid_callback(mfree_sundials_mass(0.0, M, ad, y, yd, r)));
      SUNMatDestroy(M);
    }
    const unsigned w = fz_u8(b);
    SUNMatrix S = (w & 1) ? SUNSparseMatrix(neq - (int)((w >> 1) & 1), neq, 1 + (w >> 2), (w & 8) ? CSC_MAT : CSR_MAT, sunctx)
                          : SUNDenseMatrix(neq, neq, sunctx);
    if (S) {
      FZ_TRAP_IF(!valid_callback(mfree_sundials_mass(0.0, S, ad, y, yd, r)));
      SUNMatDestroy(S);
    }
    int64_t c1 = 0, c2 = 0, c3 = 0, c4 = 0;
    mfree_sundials_get_stats(ad, &c1, &c2, &c3, &c4, NULL);
  }
  mfree_sundials_destroy(&ad);
  N_VDestroy(y), N_VDestroy(yd), N_VDestroy(r), N_VDestroy(wrong);
  mfree_system_destroy(&sys);
  SUNContext_Free(&sunctx);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  fz_bytes_t b = {data, size};
  mfree_context_t *ctx = NULL;
  if (mfree_context_create(&ctx) != MFREE_SUCCESS) return 0;
  if (fz_u8(&b) & 1) suitesparse(&b, ctx);
  else sundials(&b, ctx);
  mfree_context_destroy(&ctx);
  return 0;
}
