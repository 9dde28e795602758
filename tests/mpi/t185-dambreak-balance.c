/* Load balance during a dam break on 1-4 ranks (label mpi): every rank integrates the
 * same one-process Martin & Moyce dam break (paper 003, the example's set-up, 12 x 24
 * particles, leap-frog) and, at every window of T = 0.25 up to T = 3, takes the state of
 * the particles it owns: positions, velocities, densities, masses and global ids
 * migrate by Zoltan (RCB at odd windows, HSFC at even ones, rebalancing; the kept regions
 * at every third window). After each execute every owned particle's fields equal the
 * one-process state of its id bit for bit, every id is owned once, and after each
 * rebalance the per-rank counts are within 10 % of the mean while the column collapses
 * and its front runs along the floor. The first window starts with every particle on
 * rank 0. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fluid_common.h"
#include "mpitest.h"

static const double kG = 9.81, kRho0 = 1000.0, kGamma = 7.0;

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);

  /* ---- the example's dam break, one process ---- */
  const int nx = 12, nz = 24, n = nx * nz;
  const double a = 0.05715, H = 2.0 * a, L = 5.0 * a, d = a / nx, h = 1.5 * d;
  const double kappa = 100.0 * kRho0 * 2.0 * kG * H / kGamma, tscale = sqrt(2.0 * kG / a);
  double *y = calloc(5 * (size_t)n, sizeof *y), *m = malloc((size_t)n * sizeof *m);
  fc_water_block(y, m, n, 0, 0.0, nx, nz, d, H, kRho0, kappa, kGamma, kG);
  fc_walls_t walls = {0, 0, NULL, NULL};
  CHECK(fc_walls_tank(&walls, 0.0, L, 1.5 * H, 0.5 * d, d / 3.0) == 0, "walls");
  mfree_context_t *ctx = NULL;
  mfree_system_t *sys = NULL;
  mfree_context_create(&ctx);
  CHECK(fc_fluid_create(ctx, n, m, &kRho0, 0, kappa, kGamma, 0.5, h, kG, &walls, 10.0, &sys) == MFREE_SUCCESS,
        "fluid");
  const double lo[2] = {-d, -d}, hi[2] = {L + d, 10.0 * H};
  mfree_system_set_box(sys, lo, hi);

  /* ---- the ranks' owned particles: x (ld 2), v, rho, mass, id; all on rank 0 first ---- */
  const int cap = n;
  double *x = malloc(2 * sizeof(double) * (size_t)cap), *v = malloc(2 * sizeof(double) * (size_t)cap);
  double *rho = malloc(sizeof(double) * (size_t)cap), *mass = malloc(sizeof(double) * (size_t)cap);
  int64_t *id = malloc(sizeof(int64_t) * (size_t)cap);
  int no = 0;
  if (rank == 0)
    for (int q = 0; q < n; ++q) id[no++] = q;
  mfree_migration_t *mig = NULL;
  CHECK(mfree_migration_create(ctx, MPI_COMM_WORLD, 2, &mig) == MFREE_SUCCESS, "migration");
  mfree_migration_add_field(mig, x, 16, 16);
  mfree_migration_add_field(mig, v, 16, 16);
  mfree_migration_add_field(mig, rho, 8, 8);
  mfree_migration_add_field(mig, mass, 8, 8);
  mfree_migration_add_field(mig, id, 8, 8);

  double t = 0.0, worst = 1.0, worst_kept = 1.0, front = 0.0;
  int64_t steps = 0;
  ex_progress_t prog;
  ex_progress_init(&prog, 1, 0.0, 3.0 / tscale);
  for (int w = 0; w <= 12; ++w) {
    if (w > 0) {
      const mfree_status_t st =
          fc_integrate(sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, 0.25 * w / tscale, 0.5, &prog, &steps);
      CHECK(st == MFREE_SUCCESS, "window %d: integration status %d", w, (int)st);
      if (st != MFREE_SUCCESS) break;
    }
    /* the owned particles' state at this window, from the one-process run */
    for (int k = 0; k < no; ++k) {
      const int64_t q = id[k];
      memcpy(x + 2 * k, y + 2 * q, 2 * sizeof(double));
      memcpy(v + 2 * k, y + 2 * (size_t)n + 2 * q, 2 * sizeof(double));
      rho[k] = y[4 * (size_t)n + q];
      mass[k] = m[q];
    }
    int32_t n_new = -1;
    const int rebalance = w % 3 != 2;
    /* (the kept regions are those of the last rebalance: its partitioner stays) */
    if (rebalance)
      mfree_migration_set_partitioner(mig, w % 2 ? MFREE_PARTITIONER_RCB : MFREE_PARTITIONER_HSFC, 1.05);
    mfree_status_t st = mfree_migration_partition(mig, no, no ? x : NULL, 2, rebalance, &n_new);
    if (st == MFREE_SUCCESS) st = mfree_migration_execute(mig, cap);
    CHECK(st == MFREE_SUCCESS, "window %d: migration status %d", w, (int)st);
    if (st != MFREE_SUCCESS) break;
    no = n_new;
    /* every field is its id's, every id once */
    int bad = 0;
    for (int k = 0; k < no; ++k) {
      const int64_t q = id[k];
      bad += q < 0 || q >= n || memcmp(x + 2 * k, y + 2 * q, 2 * sizeof(double)) ||
             memcmp(v + 2 * k, y + 2 * (size_t)n + 2 * q, 2 * sizeof(double)) ||
             memcmp(rho + k, y + 4 * (size_t)n + q, sizeof(double)) || memcmp(mass + k, m + q, sizeof(double));
    }
    CHECK(bad == 0, "window %d: %d particles whose fields are not their id's", w, bad);
    int64_t idsum = 0, idsum_all = 0, want = (int64_t)n * (n - 1) / 2;
    int total = 0, mn = 0, mx = 0;
    for (int k = 0; k < no; ++k) idsum += id[k];
    MPI_Allreduce(&idsum, &idsum_all, 1, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
    MPI_Allreduce(&no, &total, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
    MPI_Allreduce(&no, &mn, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    MPI_Allreduce(&no, &mx, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    CHECK(total == n && idsum_all == want, "window %d: %d particles, id sum %lld", w, total, (long long)idsum_all);
    const double mean = (double)n / size;
    if (rebalance) {
      CHECK(mx <= 1.10 * mean && mn >= 0.90 * mean, "window %d (T = %.2f): counts %d to %d, mean %.1f", w,
            t * tscale, mn, mx, mean);
      worst = fmax(worst, mx / mean);
    } else {
      worst_kept = fmax(worst_kept, mx / mean);
    }
    front = 0.0;
    for (int q = 0; q < n; ++q) front = fmax(front, y[2 * q] / a);
  }
  CHECK(front > 2.5, "the front reached Z = %.2f (the column collapsed)", front);
  if (rank == 0)
    printf("t185: %d particles, %lld steps, front Z = %.2f, largest count %.3f x the mean after rebalancing, "
           "%.3f in the kept regions\n",
           n, (long long)steps, front, worst, worst_kept);

  mfree_migration_destroy(&mig);
  mfree_system_destroy(&sys);
  mfree_context_destroy(&ctx);
  fc_walls_free(&walls);
  free(y), free(m), free(x), free(v), free(rho), free(mass), free(id);
  const int rc = mpitest_finish("t185-dambreak-balance");
  MPI_Finalize();
  return rc;
}
