/* The fluid on ranks with ranks that own nothing (label mpi): the dam break of paper 003
 * (12 x 24 particles, leap-frog at CFL 0.5) in three windows of 100 steps on 1-4 ranks:
 * first every particle on rank 0 (the others own none and hold no ghosts), then all of
 * them moved to the last rank by the host's own choice (mfree_migration_set_owners and
 * mfree_system_move_particles with a move callback over the migration plan: rank 0 loses
 * every particle, the last rank receives them all), then spread by Zoltan's RCB
 * (mfree_halo_migrate_fluid). After every window every particle's position, velocity and
 * density are bitwise those of the one-rank run, matched by global id. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpimove.h"
#include "mpitest.h"

enum { WINDOWS = 3 };
static const int64_t kWindow = 100;

/* The host's move (mfree_particles_move_fn): the records as one field of the plan. */
static mfree_status_t move(void *user, int32_t nrec, int32_t n_owned, double *records, int32_t n_new) {
  mfree_migration_t *m = user;
  const int64_t bytes = (int64_t)nrec * (int64_t)sizeof(double);
  mfree_migration_clear_fields(m);
  mfree_status_t st = mfree_migration_add_field(m, records, bytes, bytes);
  if (st == MFREE_SUCCESS) st = mfree_migration_execute(m, n_owned > n_new ? n_owned : n_new);
  mfree_migration_clear_fields(m);
  return st;
}

int main(int argc, char **argv) {
  int rank = 0, size = 1;
  mfree_context_t *ctx = mpitest_start(&argc, &argv, &rank, &size);
  damb_t b;
  damb_make(&b, 12, 24);
  const int n = b.n;
  int *owner = calloc((size_t)n, sizeof *owner);

  rankfluid_t ref;
  mfree_status_t st = rankfluid_make(&ref, ctx, MPI_COMM_SELF, &b, owner, 4.0 * b.h + 4.0 * b.d, 0);
  CHECK(st == MFREE_SUCCESS, "one-rank system: status %d: %s", (int)st, mpifluid_error(ctx));
  double *ref_y[WINDOWS], t = 0.0, t_ref[WINDOWS];
  for (int w = 0; w < WINDOWS && st == MFREE_SUCCESS; ++w) {
    int64_t steps = 0;
    st = mfree_system_integrate(ref.sys, MFREE_INTEGRATOR_LEAPFROG, ref.y, &t, 1.0, 0.5, 0.0, mpifluid_stop_at,
                                (void *)&kWindow, &steps);
    CHECK(st == MFREE_SUCCESS && steps == kWindow, "one rank, window %d: status %d: %s", w, (int)st,
          mpifluid_error(ctx));
    t_ref[w] = t;
    ref_y[w] = malloc(5 * (size_t)n * sizeof(double));
    memcpy(ref_y[w], ref.y, 5 * (size_t)n * sizeof(double));
  }

  /* every particle on rank 0 (owner is all zeros) */
  const double width = 4.0 * b.h + 0.5 * b.d;
  rankfluid_t r;
  counted_t cw;
  st = rankfluid_make(&r, ctx, MPI_COMM_WORLD, &b, owner, width, 0);
  if (st == MFREE_SUCCESS) st = mpimove_counted(&r, ctx, &b, width, &cw);
  CHECK(st == MFREE_SUCCESS, "system on the ranks: status %d: %s", (int)st, mpifluid_error(ctx));
  double *y = malloc(5 * (size_t)n * sizeof *y);
  memcpy(y, r.y, 5 * (size_t)r.n_owned * sizeof *y);
  mfree_migration_t *mig = NULL;
  if (st == MFREE_SUCCESS) st = mfree_migration_create(ctx, MPI_COMM_WORLD, 2, &mig);
  int32_t *to = malloc(((size_t)n + 1) * sizeof *to);
  t = 0.0;
  for (int w = 0; w < WINDOWS && st == MFREE_SUCCESS; ++w) {
    int64_t steps = 0;
    st = mfree_system_integrate(r.sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, 1.0, 0.5, 0.0, mpifluid_stop_at,
                                (void *)&kWindow, &steps);
    CHECK(st == MFREE_SUCCESS && steps == kWindow && t == t_ref[w], "window %d: status %d, %lld steps to %.17g: %s",
          w, (int)st, (long long)steps, t, mpifluid_error(ctx));
    int first = -1;
    const int bad = mpimove_differs(&r, y, ref_y[w], n, &first);
    CHECK(bad == 0, "window %d: %d owned particles differ from one rank's (first: id %d)", w, bad, first);
    int32_t no = 0, n_new = 0;
    mfree_halo_get_size(r.halo, &no, NULL);
    CHECK(no == (w == 0 ? (rank == 0 ? n : 0) : w == 1 ? (rank == size - 1 ? n : 0) : no),
          "window %d: rank %d owns %d particles", w, rank, (int)no);
    if (w == 0) { /* everything to the last rank */
      for (int k = 0; k < no; ++k) to[k] = size - 1;
      st = mfree_migration_set_owners(mig, no, to, &n_new);
      if (st == MFREE_SUCCESS) st = mfree_system_move_particles(r.sys, n_new, move, mig, y, 5 * (int64_t)n);
      CHECK(st == MFREE_SUCCESS, "move to the last rank: status %d: %s", (int)st, mpifluid_error(ctx));
    } else if (w == 1) {
      int64_t neq = 0;
      st = mfree_halo_migrate_fluid(r.halo, mig, r.sys, 1, y, 5 * (int64_t)n, &neq);
      CHECK(st == MFREE_SUCCESS, "RCB migration: status %d: %s", (int)st, mpifluid_error(ctx));
      mfree_halo_get_size(r.halo, &no, NULL);
      CHECK(size == 1 || (no > 0 && no < n), "after RCB rank %d owns %d of %d", rank, (int)no, n);
    }
  }
  if (rank == 0) printf("t191: %d ranks: %lld steps, %d ghost rebuilds on rank 0\n", size,
                        (long long)(WINDOWS * kWindow), cw.rebuilds);
  free(to);
  mfree_migration_destroy(&mig);
  rankfluid_free(&r);
  rankfluid_free(&ref);
  for (int w = 0; w < WINDOWS; ++w) free(ref_y[w]);
  free(y), free(owner);
  damb_free(&b);
  mfree_context_destroy(&ctx);
  const int rc = mpitest_finish("t191-mpifluid-empty-ranks");
  MPI_Finalize();
  return rc;
}
