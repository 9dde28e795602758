/* Faults of the fluid on ranks across ghost rebuilds and migrations (label mpi), on 1-4
 * ranks: every rank returns the same documented status and none waits. Bad arguments of
 * mfree_halo_migrate_fluid on one rank (a NULL system or neq, a capacity below the
 * current state, a capacity below the new state: MFREE_ERR_ARG with *neq set and nothing
 * moved), ranks that disagree on rebalance, bad arguments of mfree_system_move_particles
 * on one rank, a move callback that fails (the system and the state stay as they were), the
 * acoustic step switched off on one rank after a run (MFREE_ERR_ARG before the move), a
 * system without a rebuild callback (MFREE_ERR_HALO when the layer is too shallow, as
 * before), and a rebuild callback that fails inside a run (its status, then
 * MFREE_ERR_STATE from every evaluation). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpimove.h"
#include "mpitest.h"

static int rank = 0, size = 1;

/* st on every rank is want */
static void same(mfree_status_t st, mfree_status_t want, const char *what, mfree_context_t *ctx) {
  int lo = (int)st, hi = (int)st, glo = 0, ghi = 0;
  MPI_Allreduce(&lo, &glo, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  MPI_Allreduce(&hi, &ghi, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  CHECK(glo == (int)want && ghi == (int)want, "%s: status %d here (%d..%d over the ranks), want %d: %s", what, (int)st,
        glo, ghi, (int)want, mpifluid_error(ctx));
}

static mfree_status_t failing_move(void *user, int32_t nrec, int32_t n_owned, double *records, int32_t n_new) {
  (void)user, (void)nrec, (void)n_owned, (void)records, (void)n_new;
  return MFREE_ERR_INTERNAL;
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  mfree_context_t *ctx = NULL;
  mfree_context_create(&ctx);
  damb_t b;
  damb_make(&b, 12, 24);
  const int n = b.n;
  int *owner = calloc((size_t)n, sizeof *owner);
  /* rank 0 owns nothing at first (with more than one rank), so that a partition gives it
     more than it has */
  for (int i = 0; i < n; ++i) owner[i] = size == 1 ? 0 : 1 + i % (size - 1);
  const double width = 4.0 * b.h + 0.25 * b.d;
  rankfluid_t r;
  counted_t cw;
  mfree_status_t st = rankfluid_make(&r, ctx, MPI_COMM_WORLD, &b, owner, width, 0);
  if (st == MFREE_SUCCESS) st = mpimove_counted(&r, ctx, &b, width, &cw);
  same(st, MFREE_SUCCESS, "system", ctx);
  mfree_migration_t *mig = NULL;
  same(mfree_migration_create(ctx, MPI_COMM_WORLD, 2, &mig), MFREE_SUCCESS, "migration plan", ctx);
  const int last = size - 1;
  const int64_t cap = 5 * (int64_t)n, mine = 5 * (int64_t)r.n_owned;
  double *y = malloc((size_t)cap * sizeof *y), *y0 = malloc((size_t)cap * sizeof *y0);
  memcpy(y, r.y, (size_t)mine * sizeof *y);
  memcpy(y0, y, (size_t)mine * sizeof *y);
  int64_t neq = -1;

  /* mfree_halo_migrate_fluid: bad arguments on the last rank only */
  same(mfree_halo_migrate_fluid(r.halo, mig, rank == last ? NULL : r.sys, 1, y, cap, &neq), MFREE_ERR_NULL,
       "NULL system on one rank", ctx);
  same(mfree_halo_migrate_fluid(r.halo, mig, r.sys, 1, y, cap, rank == last ? NULL : &neq), MFREE_ERR_NULL,
       "NULL neq on one rank", ctx);
  same(mfree_halo_migrate_fluid(r.halo, mig, r.sys, 1, y, rank == last ? mine - 1 : cap, &neq), MFREE_ERR_ARG,
       "capacity below the current state on one rank", ctx);
  same(mfree_halo_migrate_fluid(r.halo, mig, r.sys, rank == 0 ? 1 : 0, y, cap, &neq),
       size > 1 ? MFREE_ERR_ARG : MFREE_SUCCESS, "ranks disagree on rebalance", ctx);
  /* a capacity below the new state: every rank gives its current state's length, and
     rank 0, which owns nothing, gets particles */
  {
    st = mfree_halo_migrate_fluid(r.halo, mig, r.sys, 1, y, mine, &neq);
    same(st, size > 1 ? MFREE_ERR_ARG : MFREE_SUCCESS, "a capacity below the new state", ctx);
    int32_t no = 0;
    mfree_halo_get_size(r.halo, &no, NULL);
    if (st == MFREE_ERR_ARG) {
      CHECK((rank > 0 || neq > 0) && no == r.n_owned && memcmp(y, y0, (size_t)mine * sizeof *y) == 0,
            "after a refused migration: neq %lld, %d owned (%d before), the state %s", (long long)neq, (int)no,
            r.n_owned, memcmp(y, y0, (size_t)mine * sizeof *y) ? "changed" : "kept");
      /* grown: the same call goes through */
      st = mfree_halo_migrate_fluid(r.halo, mig, r.sys, 1, y, cap, &neq);
    }
    same(st, MFREE_SUCCESS, "a migration after growing y", ctx);
  }
  int32_t no = 0;
  mfree_halo_get_size(r.halo, &no, NULL);

  /* mfree_system_move_particles: bad arguments on one rank, a failing move */
  same(mfree_system_move_particles(r.sys, rank == last ? -1 : no, failing_move, mig, y, cap), MFREE_ERR_ARG,
       "negative n_new on one rank", ctx);
  same(mfree_system_move_particles(r.sys, no, rank == last ? NULL : failing_move, mig, y, cap), MFREE_ERR_NULL,
       "NULL move on one rank", ctx);
  memcpy(y0, y, 5 * (size_t)no * sizeof *y);
  same(mfree_system_move_particles(r.sys, no, failing_move, mig, y, cap), MFREE_ERR_INTERNAL, "a failing move", ctx);
  CHECK(memcmp(y0, y, 5 * (size_t)no * sizeof *y) == 0, "a failed move changed the state");
  double t = 0.0;
  int64_t steps = 0, want = 40;
  same(mfree_system_integrate(r.sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, 1.0, 0.5, 0.0, mpifluid_stop_at, &want, &steps),
       MFREE_SUCCESS, "a run after the failed move", ctx);
  CHECK(cw.rebuilds > 0 || size == 1, "no ghost rebuild in 40 steps");

  /* the acoustic step switched off on one rank after a run (its records would be shorter
     there): MFREE_ERR_ARG on every rank before the move */
  same(mfree_system_set_acoustic_step(r.sys, 1), MFREE_SUCCESS, "the acoustic step", ctx);
  want = 5;
  same(mfree_system_integrate(r.sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, 1.0, 0.5, 0.0, mpifluid_stop_at, &want, &steps),
       MFREE_SUCCESS, "a run with the acoustic step", ctx);
  same(rank == last ? mfree_system_set_acoustic_step(r.sys, 0) : MFREE_SUCCESS, MFREE_SUCCESS,
       "the acoustic step off on one rank", ctx);
  mfree_halo_get_size(r.halo, &no, NULL);
  memcpy(y0, y, 5 * (size_t)no * sizeof *y);
  same(mfree_system_move_particles(r.sys, no, failing_move, mig, y, cap), size > 1 ? MFREE_ERR_ARG : MFREE_ERR_INTERNAL,
       "a move with the acoustic step off on one rank", ctx);
  CHECK(size == 1 || strstr(mpifluid_error(ctx), "disagree on the acoustic step"), "the message: %s",
        mpifluid_error(ctx));
  CHECK(memcmp(y0, y, 5 * (size_t)no * sizeof *y) == 0, "a refused move changed the state");
  same(mfree_system_set_acoustic_step(r.sys, 0), MFREE_SUCCESS, "the acoustic step off", ctx);

  /* without a rebuild callback: MFREE_ERR_HALO, as before */
  same(mfree_system_set_halo_rebuild(r.sys, NULL), MFREE_SUCCESS, "no rebuild", ctx);
  want = 1000;
  same(mfree_system_integrate(r.sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, 1.0, 0.5, 0.0, mpifluid_stop_at, &want, &steps),
       MFREE_ERR_HALO, "a shallow layer without a rebuild callback", ctx);

  /* a rebuild callback that fails inside a run, then a broken system */
  cw.fail_rebuild = 1;
  same(mfree_system_set_halo_rebuild(r.sys, mpimove_rebuild), MFREE_SUCCESS, "the failing rebuild", ctx);
  same(mfree_system_integrate(r.sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, 1.0, 0.5, 0.0, mpifluid_stop_at, &want, &steps),
       MFREE_ERR_INTERNAL, "a failing rebuild inside a run", ctx);
  mfree_halo_get_size(r.halo, &no, NULL);
  double *dot = malloc(5 * ((size_t)no + 1) * sizeof *dot);
  same(mfree_system_rhs(r.sys, t, y, dot), MFREE_ERR_STATE, "the right-hand side after a failed rebuild", ctx);
  same(mfree_system_move_particles(r.sys, no, failing_move, mig, y, cap), MFREE_ERR_STATE,
       "a move after a failed rebuild", ctx);
  free(dot);
  /* a NULL plan: locally */
  int32_t ng = 0;
  const int64_t *all_ids = NULL;
  CHECK(mfree_halo_rebuild_callback(NULL, 0, y, 2, NULL, width, &ng, &all_ids) == MFREE_ERR_NULL,
        "mfree_halo_rebuild_callback of a NULL plan");
  CHECK(mfree_halo_migrate_fluid(NULL, mig, r.sys, 1, y, cap, &neq) == MFREE_ERR_NULL &&
            mfree_halo_migrate_fluid(r.halo, NULL, r.sys, 1, y, cap, &neq) == MFREE_ERR_NULL,
        "mfree_halo_migrate_fluid of a NULL plan");
  mfree_migration_destroy(&mig);
  rankfluid_free(&r);
  free(y), free(y0), free(owner);
  damb_free(&b);
  mfree_context_destroy(&ctx);
  const int rc = mpitest_finish("t192-mpifluid-migrate-faults");
  MPI_Finalize();
  return rc;
}
