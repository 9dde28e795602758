/* The fluid on ranks across ghost rebuilds and migrations (label mpi): the dam break of
 * paper 003 (16 x 32 particles, leap-frog at CFL 0.5) for 500 steps in four windows of
 * 125 on 1-4 ranks, starting from vertical slabs, with a ghost layer only a quarter
 * spacing deeper than the two support radii the rows need (so that the ranks rebuild it
 * many times inside each window) and a migration between windows (Zoltan RCB with new
 * regions, HSFC with new regions, HSFC in the last regions: the particles that crossed
 * into another rank's region move there). After every window every owned particle's
 * position, velocity and density are bitwise those of the one-rank run (MPI_COMM_SELF,
 * the same windows), matched by global id, with the same steps and time.
 *
 * Built with FLUID_OPTIONS (t174), the program runs the same with one option of the
 * one-process fluid set on every system, named by its argument: density diffusion
 * (delta 0.1), velocity smoothing (beta 0.1), consistent integration or the lumped-mass
 * step, or all four ("all"), or the acoustic step ("acoustic-step", t179: its power
 * iteration's vector exchanged at the ghosts and carried through the rebuilds and
 * migrations by global id, its sums exact); further arguments: "pc" runs the
 * predictor-corrector in place of leap-frog, "cfl=<c>" the CFL number (0.5). Then also, on
 * every rank, the one-process fluid (mfree_system_create_fluid, 512 particles: one chunk
 * of rows, its scatter in the rank's order) with the option takes the same steps to the
 * same bits as the one-rank run after every window, and without the option it ends
 * elsewhere or stops (the option acts).
 *
 * Built with FLUID_DUMMIES too (t176), the option "dummies" puts four layers of dummy
 * particles past the floor and both end walls (no-slip walls, examples/fluid_common's
 * tank), and options joined by '+' are set together ("dummies+diffusion"). With dummies
 * and density diffusion the ghost layer is four support radii deep (a quarter spacing
 * more), as the extrapolated densities the density gradients read need. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpimove.h"
#include "mpitest.h"
#ifdef FLUID_DUMMIES
#include "fluid_common.h"
#endif

#ifndef TEST_NAME
#define TEST_NAME "t189-mpifluid-migrate"
#endif

enum { NX = 16, NZ = 32, WINDOWS = 4 };
static const int64_t kWindow = 125;
static mfree_integrator_t scheme = MFREE_INTEGRATOR_LEAPFROG;
static double cfl = 0.5;

#ifdef FLUID_OPTIONS
/* The option named opt set on sys, the dam break b's (NULL: none). */
static mfree_status_t set_option(mfree_system_t *sys, const damb_t *b, const char *opt) {
  if (!opt) return MFREE_SUCCESS;
  const char *plus = strchr(opt, '+');
  if (plus) {
    char first[32];
    const size_t len = (size_t)(plus - opt);
    if (len >= sizeof first) return MFREE_ERR_ARG;
    memcpy(first, opt, len);
    first[len] = '\0';
    const mfree_status_t st = set_option(sys, b, first);
    return st == MFREE_SUCCESS ? set_option(sys, b, plus + 1) : st;
  }
  if (!strcmp(opt, "all")) {
    static const char *each[4] = {"diffusion", "smoothing", "vci", "lumped-step"};
    mfree_status_t st = MFREE_SUCCESS;
    for (int k = 0; k < 4 && st == MFREE_SUCCESS; ++k) st = set_option(sys, b, each[k]);
    return st;
  }
#ifdef FLUID_DUMMIES
  /* the tank is 5 a long, its end walls 1.5 times the column high */
  if (!strcmp(opt, "dummies")) return fc_dummy_tank(sys, 5 * NX, 3.0 * b->a, b->d);
#endif
  if (!strcmp(opt, "diffusion")) return mfree_system_set_density_diffusion(sys, 0.1);
  if (!strcmp(opt, "smoothing")) return mfree_system_set_velocity_smoothing(sys, 0.1);
  if (!strcmp(opt, "vci")) return mfree_system_set_consistent_integration(sys, 1);
  if (!strcmp(opt, "lumped-step")) return mfree_system_set_lumped_mass_step(sys, 1);
  if (!strcmp(opt, "acoustic-step")) return mfree_system_set_acoustic_step(sys, 1);
  return MFREE_ERR_ARG;
}

/* The one-process fluid with option opt (or none) through the windows: 0 when it takes
   steps[w] steps to t[w] and the state ref[w] bit for bit after every window; without
   compare, 0 when its last state differs from ref's or it stops before. */
static int one_process_differs(mfree_context_t *ctx, const damb_t *b, const char *opt, double *const *ref,
                               const int64_t *steps_ref, const double *t_ref, int compare) {
  const int n = b->n;
  mfree_system_t *sys = NULL;
  double *y = malloc(5 * (size_t)n * sizeof *y), t = 0.0;
  memcpy(y, b->y, 5 * (size_t)n * sizeof *y);
  mfree_status_t st = mfree_system_create_fluid(ctx, 2, n, &sys);
  if (st == MFREE_SUCCESS) st = damb_configure(b, sys);
  if (st == MFREE_SUCCESS) st = mfree_system_set_masses(sys, b->m, 1);
  if (st == MFREE_SUCCESS) st = set_option(sys, b, opt);
  int differs = 0;
  for (int w = 0; w < WINDOWS && st == MFREE_SUCCESS; ++w) {
    int64_t steps = 0;
    st = mfree_system_integrate(sys, scheme, y, &t, 1.0, cfl, 0.0, mpifluid_stop_at,
                                (void *)&kWindow, &steps);
    if (compare) differs += steps != steps_ref[w] || t != t_ref[w] || memcmp(y, ref[w], 5 * (size_t)n * sizeof *y);
  }
  CHECK(st == MFREE_SUCCESS || !compare, "one process (%s): status %d: %s", opt ? opt : "no option", (int)st,
        mpifluid_error(ctx));
  /* (without compare, a run that stops ends elsewhere too) */
  if (!compare) differs = st == MFREE_SUCCESS && !memcmp(y, ref[WINDOWS - 1], 5 * (size_t)n * sizeof *y);
  mfree_system_destroy(&sys);
  free(y);
  return compare ? st != MFREE_SUCCESS || differs : differs;
}
#endif

int main(int argc, char **argv) {
  int rank = 0, size = 1;
  mfree_context_t *ctx = mpitest_start(&argc, &argv, &rank, &size);
  damb_t b;
  damb_make(&b, NX, NZ);
  const int n = b.n;
  int *owner = calloc((size_t)n, sizeof *owner);

  /* the ghost layer's depth the rows need: two support radii (2 h each), or four */
  double radii = 2.0;
#ifdef FLUID_OPTIONS
  const char *opt = argc > 1 ? argv[1] : "(none)";
  for (int k = 2; k < argc; ++k) {
    if (!strcmp(argv[k], "pc")) scheme = MFREE_INTEGRATOR_PREDICTOR_CORRECTOR;
    if (!strncmp(argv[k], "cfl=", 4)) cfl = atof(argv[k] + 4);
  }
  if (strstr(opt, "dummies") && (strstr(opt, "diffusion") || strstr(opt, "all"))) radii = 4.0;
#endif

  /* the reference: one rank, a deep layer, the same windows */
  rankfluid_t ref;
  mfree_status_t st = rankfluid_make(&ref, ctx, MPI_COMM_SELF, &b, owner, 2.0 * radii * b.h + 4.0 * b.d, 0);
#ifdef FLUID_OPTIONS
  if (st == MFREE_SUCCESS) st = set_option(ref.sys, &b, opt);
#endif
  CHECK(st == MFREE_SUCCESS, "one-rank system: status %d: %s", (int)st, mpifluid_error(ctx));
  double *ref_y[WINDOWS], t_ref[WINDOWS];
  int64_t steps_ref[WINDOWS];
  double t = 0.0;
  for (int w = 0; w < WINDOWS && st == MFREE_SUCCESS; ++w) {
    st = mfree_system_integrate(ref.sys, scheme, ref.y, &t, 1.0, cfl, 0.0, mpifluid_stop_at,
                                (void *)&kWindow, &steps_ref[w]);
    CHECK(st == MFREE_SUCCESS && steps_ref[w] == kWindow, "one rank, window %d: status %d: %s", w, (int)st,
          mpifluid_error(ctx));
    t_ref[w] = t;
    ref_y[w] = malloc(5 * (size_t)n * sizeof(double));
    memcpy(ref_y[w], ref.y, 5 * (size_t)n * sizeof(double));
  }

  /* on the ranks */
  mpifluid_slabs(&b, size, owner);
  const double width = 2.0 * radii * b.h + 0.25 * b.d;
  rankfluid_t r;
  counted_t cw;
  st = rankfluid_make(&r, ctx, MPI_COMM_WORLD, &b, owner, width, 0);
  if (st == MFREE_SUCCESS) st = mpimove_counted(&r, ctx, &b, width, &cw);
#ifdef FLUID_OPTIONS
  if (st == MFREE_SUCCESS) st = set_option(r.sys, &b, opt);
#endif
  CHECK(st == MFREE_SUCCESS, "system on the ranks: status %d: %s", (int)st, mpifluid_error(ctx));
  /* a state buffer for any owned count: no reallocation between windows */
  double *y = malloc(5 * (size_t)n * sizeof *y);
  memcpy(y, r.y, 5 * (size_t)r.n_owned * sizeof *y);
  mfree_migration_t *mig = NULL;
  if (st == MFREE_SUCCESS) st = mfree_migration_create(ctx, MPI_COMM_WORLD, 2, &mig);
  const int32_t method[WINDOWS - 1] = {MFREE_PARTITIONER_RCB, MFREE_PARTITIONER_HSFC, MFREE_PARTITIONER_HSFC};
  const int32_t rebalance[WINDOWS - 1] = {1, 1, 0};
  int64_t sent[WINDOWS - 1] = {0, 0, 0};
  t = 0.0;
  for (int w = 0; w < WINDOWS && st == MFREE_SUCCESS; ++w) {
    int64_t steps = 0;
    st = mfree_system_integrate(r.sys, scheme, y, &t, 1.0, cfl, 0.0, mpifluid_stop_at,
                                (void *)&kWindow, &steps);
    CHECK(st == MFREE_SUCCESS, "window %d: integrate status %d: %s", w, (int)st, mpifluid_error(ctx));
    CHECK(steps == steps_ref[w] && t == t_ref[w], "window %d: %lld steps to t = %.17g, one rank %lld to %.17g", w,
          (long long)steps, t, (long long)steps_ref[w], t_ref[w]);
    int first = -1;
    const int bad = mpimove_differs(&r, y, ref_y[w], n, &first);
    CHECK(bad == 0, "window %d: %d owned particles differ from one rank's (first: id %d)", w, bad, first);
    if (w == WINDOWS - 1 || st != MFREE_SUCCESS) break;
    int64_t neq = -1, received = 0;
    int32_t no = 0, sys_neq = 0;
    mfree_halo_get_size(r.halo, &no, NULL);
    char *was = calloc((size_t)n, 1); /* the owned particles before the migration */
    int64_t *id = malloc(((size_t)n + 1) * sizeof *id), *ids_before = malloc(((size_t)n + 1) * sizeof *id);
    mfree_halo_get_global_ids(r.halo, ids_before);
    for (int k = 0; k < no; ++k) was[ids_before[k]] = 1;
    st = mfree_migration_set_partitioner(mig, method[w], 1.05);
    if (st == MFREE_SUCCESS) st = mfree_halo_migrate_fluid(r.halo, mig, r.sys, rebalance[w], y, 5 * (int64_t)n, &neq);
    CHECK(st == MFREE_SUCCESS, "migration %d: status %d: %s", w, (int)st, mpifluid_error(ctx));
    mfree_halo_get_size(r.halo, &no, NULL);
    mfree_system_get_size(r.sys, &sys_neq);
    CHECK(neq == 5 * (int64_t)no && sys_neq == neq, "migration %d: neq %lld, system %d, %d owned", w, (long long)neq,
          (int)sys_neq, (int)no);
    if (st == MFREE_SUCCESS) mfree_halo_get_global_ids(r.halo, id);
    for (int k = 0; k < no && st == MFREE_SUCCESS; ++k) received += !was[id[k]];
    free(was), free(id), free(ids_before);
    MPI_Allreduce(&received, &sent[w], 1, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
    int total = 0, mine = no;
    MPI_Allreduce(&mine, &total, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
    CHECK(total == n, "migration %d: %d particles owned in all", w, total);
    /* new regions: the counts within Zoltan's tolerance of the mean */
    int most = 0;
    MPI_Allreduce(&mine, &most, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    CHECK(!rebalance[w] || most <= ceil(1.1 * n / size), "migration %d: a rank owns %d of %d particles", w, most, n);
  }
  int rebuilds = cw.rebuilds, all_rebuilds = 0;
  MPI_Allreduce(&rebuilds, &all_rebuilds, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  /* the layer was rebuilt inside the windows (the migrations' setups are three) */
  CHECK(all_rebuilds > WINDOWS, "the ghosts were rebuilt %d times", all_rebuilds);
  if (size > 1) {
    CHECK(sent[0] > 0 && sent[1] > 0, "the rebalances moved %lld and %lld particles", (long long)sent[0],
          (long long)sent[1]);
    CHECK(sent[2] > 0, "no particle crossed into another rank's region in the last window");
  }
  if (rank == 0)
    printf("%s: %d ranks: %lld steps to t = %.6f, %d ghost rebuilds, migrations moved %lld, %lld, %lld particles\n",
           TEST_NAME, size, (long long)(WINDOWS * kWindow), t, cw.rebuilds, (long long)sent[0], (long long)sent[1],
           (long long)sent[2]);
  /* the particles moved: the front left the column */
  double front = 0.0;
  for (int q = 0; q < n; ++q) front = fmax(front, ref_y[WINDOWS - 1][2 * q]);
  CHECK(front > 1.1 * b.a, "the front is at %.4f m, the column %.4f m wide", front, b.a);
#ifdef FLUID_OPTIONS
  CHECK(!one_process_differs(ctx, &b, opt, ref_y, steps_ref, t_ref, 1),
        "%s: the one-process fluid differs from the one-rank run", opt);
  CHECK(!one_process_differs(ctx, &b, NULL, ref_y, steps_ref, t_ref, 0), "%s: the run without it ends the same", opt);
  if (rank == 0) printf("%s: %s, %s\n", TEST_NAME, opt, scheme == MFREE_INTEGRATOR_LEAPFROG ? "leap-frog" : "pc");
#endif

  mfree_migration_destroy(&mig);
  rankfluid_free(&r);
  rankfluid_free(&ref);
  for (int w = 0; w < WINDOWS; ++w) free(ref_y[w]);
  free(y), free(owner);
  damb_free(&b);
  mfree_context_destroy(&ctx);
  const int rc = mpitest_finish(TEST_NAME);
  MPI_Finalize();
  return rc;
}
