/* The fluid on ranks (label mpi): the dam break of paper 003 (24 x 48 particles,
 * leap-frog and predictor-corrector at CFL 0.5, 150 steps) on 1-4 ranks, for horizontal layers (the ghost layer
 * is deeper than the rows need: the rows of the ghosts far out are incomplete and must
 * not count), a scattered partition (owners by a hash of the id: most neighbours are
 * ghosts) and vertical slabs whose owned items are listed in reverse order: every owned particle's position, velocity and density
 * after the run, and its right-hand side at the start, are bitwise those of the same
 * system on one rank (MPI_COMM_SELF), matched by global id, with the same steps and
 * time; and at 20 x 40 particles the one-rank run is bitwise the one-process fluid's
 * (mfree_system_create_fluid), whose force assembly takes the rows' order up to two
 * chunks of rows. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpifluid.h"
#include "mpitest.h"

enum { LAYERS = 0, HASHED = 1, SLAB_REVERSED = 2, NDECOMP = 3 };
static const char *kName[NDECOMP] = {"layers", "hashed", "slabs, reversed local order"};

/* The one-process fluid (mfree_system_create_fluid) and the system on one rank take the
   same steps to the same bits on nx x nz particles; 0 when they do. */
static int one_process_differs(mfree_context_t *ctx, int nx, int nz, int64_t steps_wanted, mfree_integrator_t scheme) {
  damb_t b;
  damb_make(&b, nx, nz);
  const int n = b.n;
  int *owner = calloc((size_t)n, sizeof *owner);
  rankfluid_t r;
  mfree_system_t *sys = NULL;
  double *y = malloc(5 * (size_t)n * sizeof *y), t = 0.0, tr = 0.0;
  memcpy(y, b.y, 5 * (size_t)n * sizeof *y);
  int64_t steps = 0, steps_r = 0;
  mfree_status_t st = rankfluid_make(&r, ctx, MPI_COMM_SELF, &b, owner, 4.0 * b.h + 4.0 * b.d, 0);
  if (st == MFREE_SUCCESS)
    st = mfree_system_integrate(r.sys, scheme, r.y, &tr, 1.0, 0.5, 0.0, mpifluid_stop_at,
                                &steps_wanted, &steps_r);
  if (st == MFREE_SUCCESS) st = mfree_system_create_fluid(ctx, 2, n, &sys);
  if (st == MFREE_SUCCESS) st = damb_configure(&b, sys);
  if (st == MFREE_SUCCESS) st = mfree_system_set_masses(sys, b.m, 1);
  if (st == MFREE_SUCCESS)
    st = mfree_system_integrate(sys, scheme, y, &t, 1.0, 0.5, 0.0, mpifluid_stop_at,
                                &steps_wanted, &steps);
  CHECK(st == MFREE_SUCCESS && steps == steps_r && t == tr, "one process vs one rank: status %d, %lld and %lld steps",
        (int)st, (long long)steps, (long long)steps_r);
  const int differs = st != MFREE_SUCCESS || memcmp(y, r.y, 5 * (size_t)n * sizeof *y) != 0;
  mfree_system_destroy(&sys);
  rankfluid_free(&r);
  free(y), free(owner);
  damb_free(&b);
  return differs;
}

int main(int argc, char **argv) {
  int rank = 0, size = 1;
  mfree_context_t *ctx = mpitest_start(&argc, &argv, &rank, &size);
  damb_t b;
  damb_make(&b, 24, 48); /* three chunks of rows: the one-process fluid's colours reorder its scatter */
  const int n = b.n;
  const double width = 4.0 * b.h + 4.0 * b.d; /* two support radii and a margin for the motion */
  int64_t steps_wanted = 150;
  const size_t n2 = 2 * (size_t)n;

  /* ---- the reference: the system on one rank, every particle owned ---- */
  int *owner = calloc((size_t)n, sizeof *owner);
  rankfluid_t ref;
  mfree_status_t st = rankfluid_make(&ref, ctx, MPI_COMM_SELF, &b, owner, width, 0);
  CHECK(st == MFREE_SUCCESS, "one-rank system: status %d: %s", (int)st, mpifluid_error(ctx));
  double *ref_dot = malloc(5 * (size_t)n * sizeof *ref_dot);
  st = mfree_system_rhs(ref.sys, 0.0, ref.y, ref_dot);
  CHECK(st == MFREE_SUCCESS, "one-rank rhs: status %d: %s", (int)st, mpifluid_error(ctx));
  /* leap-frog, then the predictor-corrector (ref's owned items are in id order: item q
     is particle q) */
  const mfree_integrator_t schemes[2] = {MFREE_INTEGRATOR_LEAPFROG, MFREE_INTEGRATOR_PREDICTOR_CORRECTOR};
  static const char *kScheme[2] = {"leap-frog", "predictor-corrector"};
  double t_refs[2] = {0.0, 0.0}, *ref_ys[2];
  int64_t steps_refs[2] = {0, 0};
  for (int sch = 0; sch < 2; ++sch) {
    rankfluid_t r1;
    st = rankfluid_make(&r1, ctx, MPI_COMM_SELF, &b, owner, width, 0);
    if (st == MFREE_SUCCESS)
      st = mfree_system_integrate(r1.sys, schemes[sch], r1.y, &t_refs[sch], 1.0, 0.5, 0.0, mpifluid_stop_at,
                                  &steps_wanted, &steps_refs[sch]);
    CHECK(st == MFREE_SUCCESS && steps_refs[sch] == steps_wanted, "one-rank %s: status %d after %lld steps: %s",
          kScheme[sch], (int)st, (long long)steps_refs[sch], mpifluid_error(ctx));
    ref_ys[sch] = malloc(5 * (size_t)n * sizeof(double));
    memcpy(ref_ys[sch], r1.y, 5 * (size_t)n * sizeof(double));
    rankfluid_free(&r1);
  }

  /* ---- on the ranks ---- */
  for (int sch = 0; sch < 2; ++sch)
  for (int how = 0; how < NDECOMP; ++how) {
    const double t_ref = t_refs[sch], *ref_y = ref_ys[sch];
    const int64_t steps_ref = steps_refs[sch];
    for (int i = 0; i < n; ++i) {
      /* horizontal layers (ghosts far above and below, whose rows are incomplete) or
         vertical slabs */
      int p = how == LAYERS ? (int)(b.y[2 * i + 1] / (2.0 * b.a) * size) : (int)(b.y[2 * i] / b.a * size);
      p = p < 0 ? 0 : p >= size ? size - 1 : p;
      owner[i] = how == HASHED ? (int)(mpitest_hash((uint64_t)i) % (uint64_t)size) : p;
    }
    rankfluid_t r;
    st = rankfluid_make(&r, ctx, MPI_COMM_WORLD, &b, owner, width, how == SLAB_REVERSED);
    CHECK(st == MFREE_SUCCESS, "%s: system: status %d: %s", kName[how], (int)st, mpifluid_error(ctx));
    if (st != MFREE_SUCCESS) {
      rankfluid_free(&r);
      continue;
    }
    const int no = r.n_owned;
    const size_t no2 = 2 * (size_t)no;
    double *dot = malloc(5 * ((size_t)no + 1) * sizeof *dot);
    st = mfree_system_rhs(r.sys, 0.0, r.y, dot);
    CHECK(st == MFREE_SUCCESS, "%s: rhs status %d: %s", kName[how], (int)st, mpifluid_error(ctx));
    int bad_rhs = 0;
    for (int k = 0; k < no; ++k) {
      const int64_t q = r.id[k];
      bad_rhs += memcmp(dot + 2 * k, ref_dot + 2 * q, 16) || memcmp(dot + no2 + 2 * k, ref_dot + n2 + 2 * q, 16) ||
                 memcmp(dot + 2 * no2 + k, ref_dot + 2 * n2 + q, 8);
    }
    CHECK(bad_rhs == 0, "%s: %d of %d owned particles' rates differ from one rank's", kName[how], bad_rhs, no);
    double t = 0.0;
    int64_t steps = 0;
    st = mfree_system_integrate(r.sys, schemes[sch], r.y, &t, 1.0, 0.5, 0.0, mpifluid_stop_at, &steps_wanted, &steps);
    CHECK(st == MFREE_SUCCESS, "%s, %s: integrate status %d: %s", kScheme[sch], kName[how], (int)st,
          mpifluid_error(ctx));
    CHECK(steps == steps_ref && t == t_ref, "%s, %s: %lld steps to t = %.17g, one rank %lld to %.17g", kScheme[sch],
          kName[how], (long long)steps, t, (long long)steps_ref, t_ref);
    int bad = 0, first = -1, total = 0;
    for (int k = 0; k < no; ++k) {
      const int64_t q = r.id[k];
      const int differs = memcmp(r.y + 2 * k, ref_y + 2 * q, 16) || memcmp(r.y + no2 + 2 * k, ref_y + n2 + 2 * q, 16) ||
                          memcmp(r.y + 2 * no2 + k, ref_y + 2 * n2 + q, 8);
      if (differs && first < 0) first = (int)q;
      bad += differs;
    }
    CHECK(bad == 0, "%s, %s: %d of %d owned particles differ from one rank's (first: id %d)", kScheme[sch], kName[how],
          bad, no, first);
    MPI_Allreduce(&no, &total, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
    CHECK(total == n, "%s: %d particles owned in all", kName[how], total);
    if (rank == 0)
      printf("t186: %s, %s on %d ranks: %lld steps, rank 0 owns %d particles and %d ghosts\n", kScheme[sch],
             kName[how], size, (long long)steps, no, r.n_ghost);
    free(dot);
    rankfluid_free(&r);
  }
  /* (at two chunks, 800 particles, the coloured scatter keeps the rows' order) */
  for (int sch = 0; sch < 2; ++sch)
    CHECK(!one_process_differs(ctx, 20, 40, steps_wanted, schemes[sch]), "%s: the one-process fluid differs from the "
          "one-rank run", kScheme[sch]);
  /* the particles moved: the front left the column */
  double front = 0.0;
  for (int q = 0; q < n; ++q) front = fmax(front, ref_ys[0][2 * q]);
  CHECK(front > 1.03 * b.a, "the front is at %.4f m, the column %.4f m wide", front, b.a);

  rankfluid_free(&ref);
  free(ref_dot), free(owner), free(ref_ys[0]), free(ref_ys[1]);
  damb_free(&b);
  mfree_context_destroy(&ctx);
  const int rc = mpitest_finish("t186-mpi-fluid-dambreak");
  MPI_Finalize();
  return rc;
}
