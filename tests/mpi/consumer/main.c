/* A host of the installed libmfree_mpi: one rank (an MPI singleton), three particles
 * numbered by the plan, an RL gradient of a linear field on the set the plan describes.
 * Prints "halo: ok" when the numbering is 0, 1, 2 and the gradient exact. */
#include <math.h>
#include <stdio.h>

#include <mfree_mpi.h>

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  mfree_context_t *ctx = NULL;
  mfree_halo_t *h = NULL;
  double x[9 * 2], u[9];
  int64_t ids[9], off = -1, total = -1;
  int32_t no = 0, ng = -1;
  int k = 0;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i, ++k) {
      x[2 * k] = 0.5 * i;
      x[2 * k + 1] = 0.5 * j;
      u[k] = 1.0 + 2.0 * x[2 * k] - x[2 * k + 1];
    }
  int ok = mfree_context_create(&ctx) == MFREE_SUCCESS &&
           mfree_halo_create(ctx, MPI_COMM_WORLD, 2, &h) == MFREE_SUCCESS &&
           mfree_halo_setup(h, 9, x, 2, NULL, 1.5) == MFREE_SUCCESS &&
           mfree_halo_get_size(h, &no, &ng) == MFREE_SUCCESS &&
           mfree_halo_get_global_ids(h, ids) == MFREE_SUCCESS &&
           mfree_halo_get_global_offset(h, &off, &total) == MFREE_SUCCESS &&
           mfree_halo_exchange(h, 1, u, 1) == MFREE_SUCCESS;
  ok = ok && no == 9 && ng == 0 && off == 0 && total == 9 && ids[0] == 0 && ids[8] == 8;
  mfree_particles_t *ps = NULL;
  mfree_approximant_t *a = NULL;
  double h0 = 0.6, v = 0.25, g[9 * 2];
  ok = ok && mfree_particles_create(ctx, 2, 9, &ps) == MFREE_SUCCESS &&
       mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 2, MFREE_COPY) == MFREE_SUCCESS &&
       mfree_particles_set_support(ps, &h0, 0, MFREE_COPY) == MFREE_SUCCESS &&
       mfree_particles_set_volumes(ps, &v, 0, MFREE_COPY) == MFREE_SUCCESS &&
       mfree_particles_set_global_ids(ps, ids, MFREE_COPY) == MFREE_SUCCESS &&
       mfree_approximant_create(ctx, ps, MFREE_METHOD_RANDLES_LIBERSKY, &a) == MFREE_SUCCESS &&
       mfree_approximant_setup(a) == MFREE_SUCCESS &&
       mfree_approximant_apply(a, MFREE_OP_GRADIENT, 1, u, MFREE_LAYOUT_AOS, 1, g, MFREE_LAYOUT_AOS, 2) ==
           MFREE_SUCCESS;
  ok = ok && fabs(g[8] - 2.0) < 1e-12 && fabs(g[9] + 1.0) < 1e-12;
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
  mfree_halo_destroy(&h);
  mfree_context_destroy(&ctx);
  printf(ok ? "halo: ok\n" : "halo: FAILED\n");
  MPI_Finalize();
  return ok ? 0 : 1;
}
