/* libmfree_sundials' callbacks with an N_Vector of the wrong length on one rank of a fluid
 * on ranks (label mpi, 2-4 ranks, under a timeout that fails a hang): the dam break of
 * paper 003 on NVECTOR_PARALLEL vectors; on the faulty rank one vector of a callback
 * (mfree_sundials_rhs's y or ydot, mfree_sundials_rhs_mass_form's F,
 * mfree_sundials_residual's r, mfree_sundials_mass_times' v with the consistent mass and,
 * at a new point, with the lumped mass) holds one value more than the system's equations
 * on that rank. Every rank's callback returns -1 with MFREE_ERR_MISMATCH on its context
 * and the faulty rank's message ("rank R: y has length 46, the system has 45 equations"),
 * no output is written on any rank (they keep a sentinel), and the adapter keeps its
 * state: the next good call gives bit for bit what the same call gives through a twin
 * adapter on a twin system that never saw a fault. The faulty rank is the last, then
 * rank 0. */
#include <nvector/nvector_parallel.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mfree_sundials.h"
#include "mfree_sundials_mpi.h"
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

int main(int argc, char **argv) {
  damb_t b;
  int *owner = NULL;
  mfree_context_t *ctx = mpifluid_start(&argc, &argv, &rank, &size, &b, 12, 24, &owner);
  MPI_Comm world = MPI_COMM_WORLD;
  SUNContext sunctx = NULL;
  SUNContext_Create(&world, &sunctx);
  const double width = 4.0 * b.h + 2.0 * b.d;
  /* s: sees the faults (through ad); twin: the good calls only (through adt) */
  rankfluid_t s, twin;
  CHECK(rankfluid_make(&s, ctx, MPI_COMM_WORLD, &b, owner, width, 0) == MFREE_SUCCESS, "system");
  CHECK(rankfluid_make(&twin, ctx, MPI_COMM_WORLD, &b, owner, width, 0) == MFREE_SUCCESS, "twin");
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

    /* the mass products: the consistent mass (the system's collective product), then the
       lumped mass at a new point (assembled: collective) */
    for (int consistent = 1; consistent >= 0; --consistent) {
      CHECK(mfree_sundials_set_consistent_mass(ad, consistent) == MFREE_SUCCESS &&
                mfree_sundials_set_consistent_mass(adt, consistent) == MFREE_SUCCESS,
            "consistent %d", consistent);
      const double tm = t + (consistent ? 1e-6 : 2e-6);
      fill(o1);
      if (rank == bad) memcpy(NV_DATA_P(longer), NV_DATA_P(v), (size_t)neq * sizeof(double));
      failed(ctx, mfree_sundials_mass_times(longer, o1, tm, ad), bad, "v", neq,
             consistent ? "consistent mass product" : "lumped mass product");
      untouched(o1, "mass product");
      CHECK(mfree_sundials_mass_times(v, o1, tm, ad) == 0 && mfree_sundials_mass_times(v, o2, tm, adt) == 0,
            "mass product: %s", mpifluid_error(ctx));
      mpitest_same_bits(NV_DATA_P(o1), NV_DATA_P(o2), neq, consistent ? "consistent product" : "lumped product");
    }
    N_VDestroy(longer);
  }

  N_VDestroy(y), N_VDestroy(o1), N_VDestroy(o2), N_VDestroy(v);
  mfree_sundials_destroy(&ad);
  mfree_sundials_destroy(&adt);
  free(owner);
  rankfluid_free(&s);
  rankfluid_free(&twin);
  damb_free(&b);
  SUNContext_Free(&sunctx);
  mfree_context_destroy(&ctx);
  const int rc = mpitest_finish("t153-mpisun-vector-length");
  MPI_Finalize();
  return rc;
}
