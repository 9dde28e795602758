/* libmfree_sundials' callbacks with an N_Vector of the wrong length on one rank of a fluid
 * on ranks (label mpi, 2-4 ranks, under a timeout that fails a hang): the dam break of
 * paper 003 on NVECTOR_PARALLEL vectors; on the faulty rank one vector of a callback
 * (mfree_sundials_rhs's y or ydot, mfree_sundials_rhs_mass_form's F,
 * mfree_sundials_residual's r, mfree_sundials_mass_times' v with the consistent and the
 * lumped mass, at a new point and at a point whose mass is kept) holds one value more
 * than the system's equations on that rank. Every rank's callback returns -1 with
 * MFREE_ERR_MISMATCH on its context and the faulty rank's message ("rank R: y has length
 * 46, the system has 45 equations"), no output is written on any rank (they keep a
 * sentinel), and the adapter keeps its state: the next good call gives bit for bit what
 * the same call gives through a twin adapter on a twin system that never saw a fault.
 * mfree_sundials_create_mass_matrix with a NULL SUNContext, a NULL output or a y too long
 * on the faulty rank returns MFREE_ERR_NULL or MFREE_ERR_MISMATCH on every rank, no matrix
 * made; then the twin's matrix bit for bit. The mass products again on the elastodynamic
 * bar (collocation; Galerkin, lumped and consistent), whose lumped mass every rank
 * assembles alone. The faulty rank is the last, then rank 0. */
#include <nvector/nvector_parallel.h>
#include <sunmatrix/sunmatrix_sparse.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mfree_sundials.h"
#include "mfree_sundials_mpi.h"
#include "mpibar.h"
#include "mpifluid.h"
#include "mpitest.h"

static int rank = 0, size = 1;
static const double SENTINEL = -12345.5;

static void fill(N_Vector v) {
  double *a = NV_DATA_P(v);
  for (sunindextype i = 0; i < NV_LOCLENGTH_P(v); ++i) a[i] = SENTINEL;
}

static void untouched(N_Vector v, const char *what) {
  const double *a = NV_DATA_P(v);
  for (sunindextype i = 0; i < NV_LOCLENGTH_P(v); ++i)
    if (a[i] != SENTINEL) {
      CHECK(0, "%s: output %ld written (%.17g) by a failed call", what, (long)i, a[i]);
      return;
    }
}

/* A parallel vector of this rank's local length n (its global length the ranks' sum). */
static N_Vector vec(SUNContext sunctx, sunindextype n, mfree_context_t *ctx) {
  long local = (long)n, global = 0;
  MPI_Allreduce(&local, &global, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  N_Vector v = N_VNew_Parallel(MPI_COMM_WORLD, n, (sunindextype)global, sunctx);
  CHECK(v != NULL, "N_VNew_Parallel");
  if (v) CHECK(mfree_sundials_mpi_set_reproducible(ctx, v) == MFREE_SUCCESS, "reproducible");
  return v;
}

/* A callback's outcome on every rank: -1, MFREE_ERR_MISMATCH, the faulty rank's message
 * naming the vector; the faulty rank also sees its own lengths in it. */
static void failed(mfree_context_t *ctx, int ret, int bad, const char *name, int32_t neq, const char *what) {
  CHECK(ret == -1, "%s: the callback returned %d", what, ret);
  mfree_status_t code = MFREE_SUCCESS;
  char msg[512] = "";
  mfree_context_get_last_error(ctx, &code, msg, sizeof msg);
  char why[96];
  snprintf(why, sizeof why, "%s has length", name);
  expect_agreed(ctx, code, MFREE_ERR_MISMATCH, bad, why, what);
  if (rank == bad) {
    char exact[160];
    snprintf(exact, sizeof exact, "rank %d: %s has length %d, the system has %d equations", bad, name, (int)neq + 1,
             (int)neq);
    CHECK(strstr(msg, exact) != NULL, "%s: message \"%s\", expected \"%s\"", what, msg, exact);
  }
}

/* The mass products (mfree_sundials_mass_times) of ad (which sees the faults) and adt
 * (its twin: the good calls only), consistent (with consistent) and lumped: with longer as
 * v, on the faulty rank one value longer than the system's neq equations, at a new point,
 * then again at that point (its mass kept): every rank fails alike, nothing written; then
 * the good product is the twin's bit for bit. */
static void products(mfree_context_t *ctx, mfree_sundials_t *ad, mfree_sundials_t *adt, int consistent_too,
                     N_Vector longer, N_Vector v, N_Vector o1, N_Vector o2, int32_t neq, int bad, double t,
                     const char *sys) {
  for (int consistent = consistent_too; consistent >= 0; --consistent) {
    CHECK(mfree_sundials_set_consistent_mass(ad, consistent) == MFREE_SUCCESS &&
              mfree_sundials_set_consistent_mass(adt, consistent) == MFREE_SUCCESS,
          "consistent %d", consistent);
    const double tm = t + (consistent ? 1e-6 : 2e-6);
    for (int kept = 0; kept < 2; ++kept) {
      char what[96];
      snprintf(what, sizeof what, "%s, %s mass product%s", sys, consistent ? "consistent" : "lumped",
               kept ? ", kept" : "");
      fill(o1);
      if (rank == bad) memcpy(NV_DATA_P(longer), NV_DATA_P(v), (size_t)neq * sizeof(double));
      failed(ctx, mfree_sundials_mass_times(longer, o1, tm, ad), bad, "v", neq, what);
      untouched(o1, what);
      CHECK(mfree_sundials_mass_times(v, o1, tm, ad) == 0 && mfree_sundials_mass_times(v, o2, tm, adt) == 0,
            "%s: %s", what, mpifluid_error(ctx));
      mpitest_same_bits(NV_DATA_P(o1), NV_DATA_P(o2), neq, what);
    }
  }
}

/* The elastodynamic bar's mass products (BAR_COLLOCATION: the identity; BAR_GALERKIN: the
 * lumped and the consistent mass), whose lumped mass each rank assembles alone: the
 * products are still collective. 40 particles, a state of small displacements. */
static void bar_products(mfree_context_t *ctx, SUNContext sunctx, int kind) {
  mpibar_t bar, twin;
  const int made = mpibar_make_kind(&bar, ctx, MPI_COMM_WORLD, 40, BAR_SLAB, kind) == 0 &&
                   mpibar_make_kind(&twin, ctx, MPI_COMM_WORLD, 40, BAR_SLAB, kind) == 0;
  CHECK(made, "bar %d: %s", kind, mpifluid_error(ctx));
  mfree_sundials_t *ad = NULL, *adt = NULL;
  if (made)
    CHECK(mfree_sundials_create(ctx, bar.sys, &ad) == MFREE_SUCCESS &&
              mfree_sundials_create(ctx, twin.sys, &adt) == MFREE_SUCCESS,
          "bar adapters: %s", mpifluid_error(ctx));
  if (ad && adt) {
    const int32_t neq = 2 * bar.n_owned;
    N_Vector y = vec(sunctx, neq, ctx), v = vec(sunctx, neq, ctx), o1 = vec(sunctx, neq, ctx);
    N_Vector o2 = vec(sunctx, neq, ctx);
    for (int32_t i = 0; i < neq; ++i) {
      NV_DATA_P(y)[i] = 1e-6 * (i % 5);
      NV_DATA_P(v)[i] = 1.0 + 0.25 * (i % 7);
    }
    CHECK(mfree_sundials_set_state(ad, y) == MFREE_SUCCESS && mfree_sundials_set_state(adt, y) == MFREE_SUCCESS,
          "bar state");
    for (int turn = 0; turn < 2; ++turn) {
      const int bad = turn == 0 ? size - 1 : 0;
      N_Vector longer = vec(sunctx, neq + (rank == bad ? 1 : 0), ctx);
      products(ctx, ad, adt, kind == BAR_GALERKIN, longer, v, o1, o2, neq, bad, 1e-7 * (turn + 1),
               kind == BAR_GALERKIN ? "Galerkin bar" : "collocation bar");
      N_VDestroy(longer);
    }
    N_VDestroy(y), N_VDestroy(v), N_VDestroy(o1), N_VDestroy(o2);
  }
  mfree_sundials_destroy(&ad);
  mfree_sundials_destroy(&adt);
  mpibar_free(&bar);
  mpibar_free(&twin);
}

int main(int argc, char **argv) {
  damb_t b;
  int *owner = NULL;
  rankfluid_t s, twin; /* s: sees the faults (through ad); twin: the good calls only (through adt) */
  mfree_context_t *ctx = mpifluid_pair(&argc, &argv, &rank, &size, &b, &owner, NULL, &s, &twin);
  MPI_Comm world = MPI_COMM_WORLD;
  SUNContext sunctx = NULL;
  SUNContext_Create(&world, &sunctx);
  mfree_sundials_t *ad = NULL, *adt = NULL;
  CHECK(mfree_sundials_create(ctx, s.sys, &ad) == MFREE_SUCCESS &&
            mfree_sundials_create(ctx, twin.sys, &adt) == MFREE_SUCCESS,
        "adapters: %s", mpifluid_error(ctx));
  const int32_t neq = 5 * s.n_owned;
  N_Vector y = vec(sunctx, neq, ctx), o1 = vec(sunctx, neq, ctx), o2 = vec(sunctx, neq, ctx);
  N_Vector v = vec(sunctx, neq, ctx);
  memcpy(NV_DATA_P(y), s.y, (size_t)neq * sizeof(double));
  for (int32_t i = 0; i < neq; ++i) NV_DATA_P(v)[i] = 1.0 + 0.25 * (i % 7);

  for (int turn = 0; turn < 2; ++turn) {
    const int bad = turn == 0 ? size - 1 : 0;
    /* one value more on the faulty rank only */
    N_Vector longer = vec(sunctx, neq + (rank == bad ? 1 : 0), ctx);
    memcpy(NV_DATA_P(longer), s.y, (size_t)neq * sizeof(double));
    if (rank == bad) NV_DATA_P(longer)[neq] = 0.0;
    const double t = 1e-4 * (turn + 1);

    /* the right-hand side: y, then ydot too long on the faulty rank */
    fill(o1);
    failed(ctx, mfree_sundials_rhs(t, longer, o1, ad), bad, "y", neq, "rhs, y");
    untouched(o1, "rhs, y");
    fill(longer);
    failed(ctx, mfree_sundials_rhs(t, y, longer, ad), bad, "ydot", neq, "rhs, ydot");
    untouched(longer, "rhs, ydot");
    CHECK(mfree_sundials_rhs(t, y, o1, ad) == 0 && mfree_sundials_rhs(t, y, o2, adt) == 0, "rhs: %s",
          mpifluid_error(ctx));
    mpitest_same_bits(NV_DATA_P(o1), NV_DATA_P(o2), neq, "rhs after the faults");

    /* the mass form's right-hand side, the residual */
    fill(longer);
    failed(ctx, mfree_sundials_rhs_mass_form(t, y, longer, ad), bad, "F", neq, "mass form, F");
    untouched(longer, "mass form, F");
    CHECK(mfree_sundials_rhs_mass_form(t, y, o1, ad) == 0 && mfree_sundials_rhs_mass_form(t, y, o2, adt) == 0,
          "mass form: %s", mpifluid_error(ctx));
    mpitest_same_bits(NV_DATA_P(o1), NV_DATA_P(o2), neq, "mass form after the fault");
    fill(longer);
    failed(ctx, mfree_sundials_residual(t, y, v, longer, ad), bad, "r", neq, "residual, r");
    untouched(longer, "residual, r");
    CHECK(mfree_sundials_residual(t, y, v, o1, ad) == 0 && mfree_sundials_residual(t, y, v, o2, adt) == 0,
          "residual: %s", mpifluid_error(ctx));
    mpitest_same_bits(NV_DATA_P(o1), NV_DATA_P(o2), neq, "residual after the fault");

    products(ctx, ad, adt, 1, longer, v, o1, o2, neq, bad, t, "fluid");

    /* the lumped mass matrix's creation (collective): a NULL SUNContext, a NULL output, y
       too long on the faulty rank; every rank's M stays NULL */
    for (int arg = 0; arg < 3; ++arg) {
      static const char *const whats[3] = {"SUNContext is NULL", "output pointer is NULL", "y has length"};
      SUNMatrix M = NULL;
      if (rank == bad) memcpy(NV_DATA_P(longer), s.y, (size_t)neq * sizeof(double));
      const mfree_status_t st =
          mfree_sundials_create_mass_matrix(ad, arg == 0 && rank == bad ? NULL : sunctx, arg == 2 ? longer : y,
                                            arg == 1 && rank == bad ? NULL : &M);
      expect_agreed(ctx, st, arg == 2 ? MFREE_ERR_MISMATCH : MFREE_ERR_NULL, bad, whats[arg], "mass matrix");
      CHECK(M == NULL, "mass matrix: made after \"%s\"", whats[arg]);
      if (M) SUNMatDestroy(M);
    }
    SUNMatrix M = NULL, Mt = NULL;
    CHECK(mfree_sundials_create_mass_matrix(ad, sunctx, y, &M) == MFREE_SUCCESS &&
              mfree_sundials_create_mass_matrix(adt, sunctx, y, &Mt) == MFREE_SUCCESS,
          "mass matrix: %s", mpifluid_error(ctx));
    if (M && Mt) {
      const sunindextype nnz = SUNSparseMatrix_IndexPointers(M)[neq];
      CHECK(nnz == SUNSparseMatrix_IndexPointers(Mt)[neq], "mass matrix: nnz");
      mpitest_same_bits(SUNSparseMatrix_Data(M), SUNSparseMatrix_Data(Mt), nnz, "mass matrix");
    }
    if (M) SUNMatDestroy(M);
    if (Mt) SUNMatDestroy(Mt);
    N_VDestroy(longer);
  }

  N_VDestroy(y), N_VDestroy(o1), N_VDestroy(o2), N_VDestroy(v);
  bar_products(ctx, sunctx, BAR_COLLOCATION);
  bar_products(ctx, sunctx, BAR_GALERKIN);
  mfree_sundials_destroy(&ad);
  mfree_sundials_destroy(&adt);
  mpifluid_pair_free(&b, owner, &s, &twin);
  SUNContext_Free(&sunctx);
  mfree_context_destroy(&ctx);
  const int rc = mpitest_finish("t153-mpisun-vector-length");
  MPI_Finalize();
  return rc;
}
