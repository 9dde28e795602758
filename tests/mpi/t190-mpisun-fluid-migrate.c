/* The fluid on ranks with ARKODE across migrations (label mpi): the dam break of paper
 * 003 (12 x 24 particles) by ERKStep (adaptive steps) on libmfree_sundials_mpi's
 * reproducible parallel vectors, in four windows of 10 ms (at least 500 steps in all), on 1, 2
 * and 4 ranks: a ghost layer a
 * fiftieth of a spacing deeper than the rows need (rebuilt inside the windows, during the
 * right-hand sides), and between windows a migration by Zoltan (RCB with new regions,
 * HSFC with new regions, HSFC in the last regions), after which the host re-creates its
 * vector with the new length and the integrator (the one-rank run re-creates them at
 * the same times). Every particle's position, velocity and density, matched by global
 * id, and the steps of every window are bitwise those of the one-rank run.
 *
 * Built with FLUID_DUMMIES (t177), both systems have no-slip walls (four layers of dummy
 * particles past the floor and both end walls, examples/fluid_common's tank) and density
 * diffusion (delta 0.1), the ghost layer is four support radii and a quarter spacing
 * deep, as the dummies' extrapolated densities with density diffusion need, and the
 * windows are 25 ms (ERKStep's steps are longer there: still at least 500 in all). */
#include <arkode/arkode_erkstep.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mfree_sundials.h"
#include "mfree_sundials_mpi.h"
#include "mpimove.h"
#include "mpitest.h"
#ifdef FLUID_DUMMIES
#include "fluid_common.h"
#endif

#ifndef TEST_NAME
#define TEST_NAME "t190-mpisun-fluid-migrate"
#endif

enum { WINDOWS = 4 };
#ifdef FLUID_DUMMIES
static const double T_WINDOW = 25e-3, RTOL = 1e-3; /* (the walls' dummies allow longer steps) */
#else
static const double T_WINDOW = 10e-3, RTOL = 1e-3;
#endif

static void flag(int f, const char *what) { CHECK(f >= 0, "%s returned %d", what, f); }

/* The ghost layer's depth in support radii (2 h each) and its margin in spacings, and the
   options beyond 003 on sys. */
#ifdef FLUID_DUMMIES
static const double kRadii = 4.0, kMargin = 0.25;
static mfree_status_t options(mfree_system_t *sys, const damb_t *b) {
  mfree_status_t st = mfree_system_set_density_diffusion(sys, 0.1);
  /* the tank is 5 a long, its end walls 1.5 times the column high */
  if (st == MFREE_SUCCESS) st = fc_dummy_tank(sys, (int)lround(5.0 * b->a / b->d), 3.0 * b->a, b->d);
  return st;
}
#else
static const double kRadii = 2.0, kMargin = 0.02;
static mfree_status_t options(mfree_system_t *sys, const damb_t *b) {
  (void)sys, (void)b;
  return MFREE_SUCCESS;
}
#endif

/* One window of ERKStep from t0 on a fresh vector and integrator: y (the rank's state,
   5 n_owned) advanced to t0 + T_WINDOW; the steps. */
static long window(mfree_context_t *ctx, SUNContext sunctx, MPI_Comm comm, const damb_t *b, rankfluid_t *r,
                   double *ystate, double t0) {
  int32_t no = 0;
  mfree_halo_get_size(r->halo, &no, NULL);
  mfree_sundials_t *ad = NULL;
  CHECK(mfree_sundials_create(ctx, r->sys, &ad) == MFREE_SUCCESS, "adapter: %s", mpifluid_error(ctx));
  N_Vector y = NULL;
  CHECK(mfree_sundials_mpi_create_vector(ctx, r->sys, comm, sunctx, &y) == MFREE_SUCCESS, "vector: %s",
        mpifluid_error(ctx));
  CHECK(N_VGetLocalLength_Parallel(y) == 5 * no, "local length %ld, %d owned", (long)N_VGetLocalLength_Parallel(y),
        (int)no);
  memcpy(N_VGetArrayPointer(y), ystate, 5 * (size_t)no * sizeof(double));
  void *mem = ERKStepCreate(mfree_sundials_rhs, t0, y, sunctx);
  N_Vector atol = N_VClone(y);
  double *pa = N_VGetArrayPointer(atol);
  for (int k = 0; k < no; ++k) {
    pa[2 * k] = pa[2 * k + 1] = 1e-2 * b->d;
    pa[2 * no + 2 * k] = pa[2 * no + 2 * k + 1] = 1e-2;
    pa[4 * no + k] = 1.0;
  }
  flag(ERKStepSVtolerances(mem, RTOL, atol), "tolerances");
  flag(ERKStepSetUserData(mem, ad), "user data");
  flag(ERKStepSetMaxNumSteps(mem, 100000), "max steps");
  flag(ERKStepSetStopTime(mem, t0 + T_WINDOW), "stop time");
  double t = t0;
  flag(ERKStepEvolve(mem, t0 + T_WINDOW, y, &t, ARK_NORMAL), "ERKStepEvolve");
  long steps = -1;
  ERKStepGetNumSteps(mem, &steps);
  CHECK(t == t0 + T_WINDOW, "t %.17g", t);
  memcpy(ystate, N_VGetArrayPointer(y), 5 * (size_t)no * sizeof(double));
  ERKStepFree(&mem);
  N_VDestroy(atol);
  N_VDestroy(y);
  mfree_sundials_destroy(&ad);
  return steps;
}

int main(int argc, char **argv) {
  int rank = 0, size = 1;
  mfree_context_t *ctx = mpitest_start(&argc, &argv, &rank, &size);
  SUNContext sunctx = NULL, self_ctx = NULL;
  MPI_Comm world = MPI_COMM_WORLD, self = MPI_COMM_SELF;
  SUNContext_Create(&world, &sunctx);
  SUNContext_Create(&self, &self_ctx);
  damb_t b;
  damb_make(&b, 12, 24);
  const int n = b.n;
  int *owner = calloc((size_t)n, sizeof *owner);

  /* the reference: one rank, the same windows */
  rankfluid_t ref;
  mfree_status_t st = rankfluid_make(&ref, ctx, MPI_COMM_SELF, &b, owner, 2.0 * kRadii * b.h + 4.0 * b.d, 0);
  if (st == MFREE_SUCCESS) st = options(ref.sys, &b);
  CHECK(st == MFREE_SUCCESS, "one-rank system: status %d: %s", (int)st, mpifluid_error(ctx));
  double *ref_y[WINDOWS];
  long ref_steps[WINDOWS];
  for (int w = 0; w < WINDOWS; ++w) {
    ref_steps[w] = window(ctx, self_ctx, MPI_COMM_SELF, &b, &ref, ref.y, w * T_WINDOW);
    ref_y[w] = malloc(5 * (size_t)n * sizeof(double));
    memcpy(ref_y[w], ref.y, 5 * (size_t)n * sizeof(double));
  }

  /* on the ranks: horizontal layers first */
  for (int i = 0; i < n; ++i) {
    int p = (int)(b.y[2 * i + 1] / (2.0 * b.a) * size);
    owner[i] = p < 0 ? 0 : p >= size ? size - 1 : p;
  }
  const double width = 2.0 * kRadii * b.h + kMargin * b.d;
  rankfluid_t r;
  counted_t cw;
  st = rankfluid_make(&r, ctx, MPI_COMM_WORLD, &b, owner, width, 0);
  if (st == MFREE_SUCCESS) st = mpimove_counted(&r, ctx, &b, width, &cw);
  if (st == MFREE_SUCCESS) st = options(r.sys, &b);
  CHECK(st == MFREE_SUCCESS, "system on the ranks: status %d: %s", (int)st, mpifluid_error(ctx));
  double *y = malloc(5 * (size_t)n * sizeof *y);
  memcpy(y, r.y, 5 * (size_t)r.n_owned * sizeof *y);
  mfree_migration_t *mig = NULL;
  if (st == MFREE_SUCCESS) st = mfree_migration_create(ctx, MPI_COMM_WORLD, 2, &mig);
  const int32_t method[WINDOWS - 1] = {MFREE_PARTITIONER_RCB, MFREE_PARTITIONER_HSFC, MFREE_PARTITIONER_HSFC};
  const int32_t rebalance[WINDOWS - 1] = {1, 1, 0};
  long total_steps = 0;
  for (int w = 0; w < WINDOWS && st == MFREE_SUCCESS; ++w) {
    const long s = window(ctx, sunctx, MPI_COMM_WORLD, &b, &r, y, w * T_WINDOW);
    total_steps += s;
    CHECK(s == ref_steps[w], "window %d: %ld steps, one rank %ld", w, s, ref_steps[w]);
    int first = -1;
    const int bad = mpimove_differs(&r, y, ref_y[w], n, &first);
    CHECK(bad == 0, "window %d: %d owned particles differ from one rank's (first: id %d)", w, bad, first);
    if (w == WINDOWS - 1) break;
    int64_t neq = -1;
    st = mfree_migration_set_partitioner(mig, method[w], 1.05);
    if (st == MFREE_SUCCESS) st = mfree_halo_migrate_fluid(r.halo, mig, r.sys, rebalance[w], y, 5 * (int64_t)n, &neq);
    CHECK(st == MFREE_SUCCESS, "migration %d: status %d: %s", w, (int)st, mpifluid_error(ctx));
  }
  int rebuilds = cw.rebuilds, fewest = 0;
  MPI_Allreduce(&rebuilds, &fewest, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  CHECK(fewest > WINDOWS, "the ghosts were rebuilt %d times", fewest);
  CHECK(total_steps >= 500, "%ld steps in all: too short a run", total_steps);
  if (rank == 0)
    printf("%s: ERKStep on %d ranks: %ld steps in %d windows, %d ghost rebuilds\n", TEST_NAME, size, total_steps,
           WINDOWS, cw.rebuilds);
  mfree_migration_destroy(&mig);
  rankfluid_free(&r);
  rankfluid_free(&ref);
  for (int w = 0; w < WINDOWS; ++w) free(ref_y[w]);
  free(y), free(owner);
  damb_free(&b);
  SUNContext_Free(&self_ctx);
  SUNContext_Free(&sunctx);
  mfree_context_destroy(&ctx);
  const int rc = mpitest_finish(TEST_NAME);
  MPI_Finalize();
  return rc;
}
