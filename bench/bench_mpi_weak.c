/* Weak scaling of a distributed gradient step with libmfree_mpi (run by hand):
 *   mpirun --oversubscribe -np P ./bench/bench_mpi_weak [--side=500] [--steps=20]
 * Each rank owns a side x side block of a perturbed 2D lattice (2.5e5 particles at the
 * default), the blocks in a row along x, so inner ranks have two neighbours. A step:
 * owned particles drift, the halo exchange sends positions (2 doubles) and one field,
 * the particle set and a Randles-Libersky approximant update on the kept pattern, and
 * the gradient of the field is applied. Rank 0 prints the time per step (slowest rank),
 * the time in the step's two exchanges (which includes waiting for slower ranks) and in
 * the same two exchanges repeated after a barrier (the transfer alone); their fractions
 * of the step are the reference measured in the same run. Then the bytes each rank sends
 * per step, the ghosts, and the cost of the first plan and of a rebuild.
 * On a machine with fewer cores than ranks (--oversubscribe) the ranks share cores:
 * those times are not speed-ups. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <mfree_mpi.h>

#include "bench_util.h"

static void ok(mfree_context_t *ctx, mfree_status_t st, const char *what) {
  if (st == MFREE_SUCCESS) return;
  char msg[512] = "";
  mfree_context_get_last_error(ctx, NULL, msg, sizeof msg);
  fprintf(stderr, "bench_mpi_weak: %s: %s\n", what, msg);
  MPI_Abort(MPI_COMM_WORLD, 2);
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  int rank, size, side = 500, steps = 20;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  for (int a = 1; a < argc; ++a) {
    if (!strncmp(argv[a], "--side=", 7)) side = atoi(argv[a] + 7);
    if (!strncmp(argv[a], "--steps=", 8)) steps = atoi(argv[a] + 8);
  }
  const int32_t no = side * side;
  const double dx = 1.0 / side, hs = 1.3 * dx, vol = dx * dx, width = 2.0 * hs * 1.05;
  double *xo = malloc(sizeof(double) * 2 * (size_t)no);
  int64_t *io = malloc(sizeof(int64_t) * (size_t)no);
  for (int32_t k = 0; k < no; ++k) {
    xo[2 * k] = rank + ((k % side) + 0.5 + 0.1 * sin(12.9898 * k)) * dx;
    xo[2 * k + 1] = ((k / side) + 0.5 + 0.1 * cos(78.233 * k)) * dx;
    io[k] = (int64_t)rank * no + k;
  }
  mfree_context_t *ctx = NULL;
  mfree_halo_t *halo = NULL;
  ok(ctx, mfree_context_create(&ctx), "context");
  bench_page_hints(ctx);
  ok(ctx, mfree_halo_create(ctx, MPI_COMM_WORLD, 2, &halo), "halo");
  MPI_Barrier(MPI_COMM_WORLD);
  double t0 = MPI_Wtime();
  ok(ctx, mfree_halo_setup(halo, no, xo, 2, io, width), "halo setup");
  const double t_plan = MPI_Wtime() - t0;
  int32_t n_owned, ng, nnb;
  int64_t nsend;
  ok(ctx, mfree_halo_get_size(halo, &n_owned, &ng), "size");
  ok(ctx, mfree_halo_get_plan(halo, &nnb, &nsend, NULL), "plan");
  const int32_t n = no + ng;
  double *x = malloc(sizeof(double) * 2 * (size_t)n), *u = malloc(sizeof(double) * (size_t)n);
  double *g = malloc(sizeof(double) * 2 * (size_t)no);
  int64_t *ids = malloc(sizeof(int64_t) * (size_t)n);
  memcpy(x, xo, sizeof(double) * 2 * (size_t)no);
  ok(ctx, mfree_halo_get_global_ids(halo, ids), "ids");
  mfree_particles_t *ps = NULL;
  mfree_approximant_t *ap = NULL;
  ok(ctx, mfree_particles_create(ctx, 2, n, &ps), "particles");
  mfree_particles_set_num_ghost(ps, ng);
  mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 2, MFREE_BORROW);
  mfree_particles_set_support(ps, &hs, 0, MFREE_COPY);
  mfree_particles_set_volumes(ps, &vol, 0, MFREE_COPY);
  mfree_particles_set_global_ids(ps, ids, MFREE_BORROW);
  ok(ctx, mfree_halo_exchange(halo, 2, x, 2), "exchange");
  ok(ctx, mfree_particles_setup(ps), "particle setup");
  ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_RANDLES_LIBERSKY, &ap), "approximant");
  ok(ctx, mfree_approximant_set_derivatives(ap, MFREE_DERIV_GRADIENT), "derivatives");
  ok(ctx, mfree_approximant_setup(ap), "approximant setup");
  double t_step = 0, t_comm = 0, t_bare = 0;
  for (int s = 0; s < steps; ++s) {
    MPI_Barrier(MPI_COMM_WORLD);
    t0 = MPI_Wtime();
    for (int32_t i = 0; i < no; ++i) {
      x[2 * i] += 1e-4 * dx * cos(x[2 * i + 1] + s);
      u[i] = sin(3.0 * x[2 * i]) * x[2 * i + 1];
    }
    const double c0 = MPI_Wtime();
    ok(ctx, mfree_halo_exchange(halo, 2, x, 2), "exchange x");
    ok(ctx, mfree_halo_exchange(halo, 1, u, 1), "exchange u");
    const double c1 = MPI_Wtime();
    ok(ctx, mfree_particles_update(ps), "update");
    ok(ctx, mfree_approximant_update(ap), "approximant update");
    ok(ctx, mfree_approximant_apply(ap, MFREE_OP_GRADIENT, 1, u, MFREE_LAYOUT_AOS, 1, g, MFREE_LAYOUT_AOS, 2),
       "apply");
    const double t1 = MPI_Wtime();
    /* the same two exchanges again after a barrier: the transfer alone, without the
     * wait for slower ranks that the step's exchanges include */
    MPI_Barrier(MPI_COMM_WORLD);
    const double e0 = MPI_Wtime();
    ok(ctx, mfree_halo_exchange(halo, 2, x, 2), "exchange x");
    ok(ctx, mfree_halo_exchange(halo, 1, u, 1), "exchange u");
    const double e1 = MPI_Wtime();
    /* the slowest rank's step, its exchanges, the bare exchanges */
    double loc[3] = {t1 - t0, c1 - c0, e1 - e0}, mx[3];
    MPI_Allreduce(loc, mx, 3, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    t_step += mx[0];
    t_comm += mx[1];
    t_bare += mx[2];
  }
  MPI_Barrier(MPI_COMM_WORLD);
  t0 = MPI_Wtime();
  ok(ctx, mfree_halo_setup(halo, no, x, 2, io, width), "rebuild");
  double t_rebuild = MPI_Wtime() - t0, tp[2] = {t_plan, t_rebuild}, tpm[2];
  MPI_Reduce(tp, tpm, 2, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
  int64_t bytes = nsend * 3 * (int64_t)sizeof(double), bmax = 0;
  MPI_Reduce(&bytes, &bmax, 1, MPI_INT64_T, MPI_MAX, 0, MPI_COMM_WORLD);
  int32_t ngmax = 0;
  MPI_Reduce(&ng, &ngmax, 1, MPI_INT32_T, MPI_MAX, 0, MPI_COMM_WORLD);
  if (rank == 0)
    printf("bench_mpi_weak: %d ranks x %d particles: %.4f s/step, exchanges %.4f s/step (%.1f %%; "
           "after a barrier %.5f s, %.2f %%), %.3f MB sent per rank per step (max), ghosts %d (max), "
           "plan %.4f s, rebuild %.4f s\n",
           size, no, t_step / steps, t_comm / steps, 100.0 * t_comm / t_step, t_bare / steps,
           100.0 * t_bare / t_step, bmax / 1e6, ngmax, tpm[0], tpm[1]);
  if (rank == 0) {
    bench_figure(t_step / steps, "s", "mpi_weak %d ranks x %d step", size, no);
    bench_figure(t_comm / steps, "s", "mpi_weak %d ranks x %d exchanges in the step", size, no);
  }
  mfree_approximant_destroy(&ap);
  mfree_particles_destroy(&ps);
  mfree_halo_destroy(&halo);
  mfree_context_destroy(&ctx);
  free(xo);
  free(io);
  free(x);
  free(u);
  free(g);
  free(ids);
  MPI_Finalize();
  return 0;
}
