/* Faults of the fluid on ranks (label mpi), on 1-4 ranks under a timeout: every rank
 * returns the same status (and the failing rank's message) and none waits alone: a
 * non-finite state on one rank, before the run and after a few steps; ranks that
 * disagree on the end time or on the halo width; a ghost layer shallower than two
 * support radii (MFREE_ERR_HALO); bad input to the creation on one rank; the consistent
 * mass as a matrix, which the ranks' states cannot hold (MFREE_ERR_UNSUPPORTED: its
 * products and the interpolation matrix are t155's). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpifluid.h"
#include "mpitest.h"

static mfree_status_t noop_exchange(void *user, int32_t ncomp, double *field, int64_t ld) {
  (void)user, (void)ncomp, (void)field, (void)ld;
  return MFREE_SUCCESS;
}

static mfree_status_t self_allgather(void *user, const double *in, int64_t n, double *out, int64_t cap,
                                     int64_t *total) {
  (void)user;
  *total = n;
  if (cap >= n && n > 0) memcpy(out, in, (size_t)n * sizeof *in);
  return MFREE_SUCCESS;
}

int main(int argc, char **argv) {
  int rank = 0, size = 1;
  damb_t b;
  int *owner = NULL;
  mfree_context_t *ctx = mpifluid_start(&argc, &argv, &rank, &size, &b, 12, 24, &owner);
  const int last = size - 1;
  const double width = 4.0 * b.h + 2.0 * b.d;
  int64_t five = 5;
  char msg[512];

  /* ---- a non-finite velocity on the last rank, before a leap-frog run and after five steps
     (then the predictor-corrector) ---- */
  for (int when = 0; when < 2; ++when) {
    rankfluid_t r;
    mfree_status_t st = rankfluid_make(&r, ctx, MPI_COMM_WORLD, &b, owner, width, 0);
    CHECK(mpitest_same_status(st, "creation") == MFREE_SUCCESS, "creation status %d", (int)st);
    double t = 0.0;
    int64_t steps = 0;
    if (when == 1) {
      st = mfree_system_integrate(r.sys, MFREE_INTEGRATOR_LEAPFROG, r.y, &t, 1.0, 0.5, 0.0, mpifluid_stop_at, &five,
                                  &steps);
      CHECK(mpitest_same_status(st, "five steps") == MFREE_SUCCESS && steps == 5, "five steps: status %d, %lld steps",
            (int)st, (long long)steps);
    }
    if (rank == last && r.n_owned > 0) r.y[2 * (size_t)r.n_owned + 1] = NAN; /* v_z of its first particle */
    const double t0 = t;
    double *y0 = malloc(5 * ((size_t)r.n_owned + 1) * sizeof *y0);
    memcpy(y0, r.y, 5 * (size_t)r.n_owned * sizeof *y0);
    st = mfree_system_integrate(r.sys, when ? MFREE_INTEGRATOR_PREDICTOR_CORRECTOR : MFREE_INTEGRATOR_LEAPFROG, r.y,
                                &t, 1.0, 0.5, 0.0, mpifluid_stop_at, &five, &steps);
    CHECK(mpitest_same_status(st, "non-finite") == MFREE_FAIL_NONFINITE, "non-finite velocity (%d): status %d", when,
          (int)st);
    snprintf(msg, sizeof msg, "%s", mpifluid_error(ctx));
    char want[32];
    snprintf(want, sizeof want, "rank %d: ", last);
    CHECK(strstr(msg, want) && strstr(msg, "global id"), "non-finite velocity: message \"%s\"", msg);
    CHECK(steps == 0 && t == t0 && memcmp(y0, r.y, 5 * (size_t)r.n_owned * sizeof *y0) == 0,
          "non-finite velocity: %lld steps taken, or the state changed", (long long)steps);
    /* the right-hand side as well */
    double *dot = malloc(5 * ((size_t)r.n_owned + 1) * sizeof *dot);
    st = mfree_system_rhs(r.sys, 0.0, r.y, dot);
    CHECK(mpitest_same_status(st, "rhs") == MFREE_FAIL_NONFINITE, "rhs of a non-finite state: status %d", (int)st);
    free(dot), free(y0);
    rankfluid_free(&r);
  }

  /* ---- disagreeing ranks, a shallow halo, the unsupported ---- */
  {
    rankfluid_t r;
    mfree_status_t st = rankfluid_make(&r, ctx, MPI_COMM_WORLD, &b, owner, width, 0);
    CHECK(mpitest_same_status(st, "creation") == MFREE_SUCCESS, "creation status %d", (int)st);
    double t = 0.0;
    int64_t steps = 0;
    if (size > 1) {
      st = mfree_system_integrate(r.sys, MFREE_INTEGRATOR_LEAPFROG, r.y, &t, rank == last ? 2.0 : 1.0, 0.5, 0.0,
                                  mpifluid_stop_at, &five, &steps);
      CHECK(mpitest_same_status(st, "t_end") == MFREE_ERR_ARG && steps == 0, "disagreeing t_end: status %d", (int)st);
      CHECK(strstr(mpifluid_error(ctx), "ranks disagree on t_end"), "message \"%s\"",
            mpifluid_error(ctx));
    }
    st = mfree_system_integrate(r.sys, (mfree_integrator_t)7, r.y, &t, 1.0, 0.5, 0.0, NULL, NULL, &steps);
    CHECK(mpitest_same_status(st, "scheme") == MFREE_ERR_ARG, "unknown integrator: status %d", (int)st);
    /* (the distributed outputs: t197) */
    mfree_matrix_t *M = NULL;
    CHECK(mfree_system_assemble_mass(r.sys, r.y, 1, &M) == MFREE_ERR_UNSUPPORTED && !M, "consistent mass on ranks");
    CHECK(strstr(mpifluid_error(ctx), "mfree_system_apply_mass"), "message \"%s\"", mpifluid_error(ctx));
    int32_t neq = 0;
    CHECK(mfree_system_get_size(r.sys, &neq) == MFREE_SUCCESS && neq == 5 * r.n_owned, "neq %d, %d owned",
          (int)neq, r.n_owned);
    rankfluid_free(&r);
  }
  {
    /* a ghost layer of one support radius: the rows of the ghosts next to the owned
       particles would miss their own neighbours */
    rankfluid_t r;
    mfree_status_t st = rankfluid_make(&r, ctx, MPI_COMM_WORLD, &b, owner, 2.0 * b.h + b.d, 0);
    CHECK(mpitest_same_status(st, "creation") == MFREE_SUCCESS, "creation status %d", (int)st);
    double t = 0.0;
    int64_t steps = 0;
    st = mfree_system_integrate(r.sys, MFREE_INTEGRATOR_LEAPFROG, r.y, &t, 1.0, 0.5, 0.0, mpifluid_stop_at, &five,
                                &steps);
    CHECK(mpitest_same_status(st, "shallow halo") == MFREE_ERR_HALO && steps == 0, "shallow halo: status %d", (int)st);
    rankfluid_free(&r);
  }

  /* ---- creation: bad input on one rank fails every rank ---- */
  {
    rankfluid_t r;
    mfree_status_t st = rankfluid_make(&r, ctx, MPI_COMM_WORLD, &b, owner, width, 0);
    CHECK(mpitest_same_status(st, "creation") == MFREE_SUCCESS, "creation status %d", (int)st);
    const int nl = r.n_owned + r.n_ghost;
    int64_t *ids = malloc(((size_t)nl + 2) * sizeof *ids);
    memcpy(ids, r.id, (size_t)nl * sizeof *ids);
    mfree_system_t *sys = NULL;
    /* a global id given twice on the last rank */
    if (rank == last && nl >= 2) ids[1] = ids[0];
    st = mfree_system_create_fluid_ranks(ctx, 2, r.n_owned, r.n_ghost, ids, width, mfree_halo_exchange_callback,
                                         mfree_halo_allgather, r.halo, &sys);
    CHECK(mpitest_same_status(st, "twice") == (nl >= 2 || rank != last ? MFREE_ERR_INPUT : MFREE_SUCCESS) && !sys,
          "an id twice: status %d", (int)st);
    mfree_system_destroy(&sys);
    memcpy(ids, r.id, (size_t)nl * sizeof *ids);
    /* a negative count, a dimension of its own, a width of its own on the last rank */
    st = mfree_system_create_fluid_ranks(ctx, 2, rank == last ? -1 : r.n_owned, r.n_ghost, ids, width,
                                         mfree_halo_exchange_callback, mfree_halo_allgather, r.halo, &sys);
    CHECK(mpitest_same_status(st, "count") == MFREE_ERR_ARG && !sys, "negative count: status %d", (int)st);
    st = mfree_system_create_fluid_ranks(ctx, rank == last ? 4 : 2, r.n_owned, r.n_ghost, ids, width,
                                         mfree_halo_exchange_callback, mfree_halo_allgather, r.halo, &sys);
    CHECK(mpitest_same_status(st, "dimension") == MFREE_ERR_ARG && !sys, "bad dimension: status %d", (int)st);
    if (size > 1) {
      st = mfree_system_create_fluid_ranks(ctx, rank == last ? 3 : 2, r.n_owned, r.n_ghost, ids, width,
                                           mfree_halo_exchange_callback, mfree_halo_allgather, r.halo, &sys);
      CHECK(mpitest_same_status(st, "dimensions") == MFREE_ERR_ARG && !sys, "disagreeing dimensions: status %d", (int)st);
      CHECK(strstr(mpifluid_error(ctx), "ranks disagree on the dimension"), "message \"%s\"",
            mpifluid_error(ctx));
      st = mfree_system_create_fluid_ranks(ctx, 2, r.n_owned, r.n_ghost, ids, rank == last ? 2 * width : width,
                                           mfree_halo_exchange_callback, mfree_halo_allgather, r.halo, &sys);
      CHECK(mpitest_same_status(st, "width") == MFREE_ERR_ARG && !sys, "disagreeing widths: status %d", (int)st);
    }
    st = mfree_system_create_fluid_ranks(ctx, 2, r.n_owned, r.n_ghost, ids, rank == last ? NAN : width,
                                         mfree_halo_exchange_callback, mfree_halo_allgather, r.halo, &sys);
    CHECK(mpitest_same_status(st, "NaN width") == MFREE_ERR_ARG && !sys, "NaN width: status %d", (int)st);
    /* local failures: no callbacks, no output (this rank alone; every rank here) */
    CHECK(mfree_system_create_fluid_ranks(ctx, 2, r.n_owned, r.n_ghost, ids, width, NULL, mfree_halo_allgather,
                                          r.halo, &sys) == MFREE_ERR_NULL,
          "NULL exchange");
    CHECK(mfree_system_create_fluid_ranks(ctx, 2, r.n_owned, r.n_ghost, ids, width, mfree_halo_exchange_callback,
                                          mfree_halo_allgather, r.halo, NULL) == MFREE_ERR_NULL,
          "NULL output");
    /* the host-callback path on one rank: a system of its own with trivial callbacks */
    st = mfree_system_create_fluid_ranks(ctx, 2, 3, 0, ids, width, noop_exchange, self_allgather, NULL, &sys);
    CHECK(st == MFREE_SUCCESS && sys, "host callbacks: status %d", (int)st);
    mfree_system_destroy(&sys);
    free(ids);
    rankfluid_free(&r);
  }

  free(owner);
  damb_free(&b);
  mfree_context_destroy(&ctx);
  const int rc = mpitest_finish("t187-mpi-fluid-faults");
  MPI_Finalize();
  return rc;
}
