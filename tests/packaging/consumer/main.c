/* Installed-tree consumer: 4 particles on a unit square plus one far away, h = 0.6,
 * gather search with kappa 2 (radius 1.2). Each corner sees itself and its two edge
 * neighbours (distance 1) but not the diagonal one (1.41); the far particle sees only
 * itself: 4 * 3 + 1 = 13 neighbour pairs. */
#include <stdio.h>

#include <mfree.h>

int main(void) {
  const double x[] = {0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 1.0, 5.0, 5.0};
  const double h = 0.6;
  mfree_context_t *ctx = NULL;
  mfree_particles_t *ps = NULL;
  int64_t nnz = -1;
  int ok = mfree_context_create(&ctx) == MFREE_SUCCESS &&
           mfree_particles_create(ctx, 2, 5, &ps) == MFREE_SUCCESS &&
           mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 2, MFREE_COPY) == 0 &&
           mfree_particles_set_support(ps, &h, 0, MFREE_COPY) == MFREE_SUCCESS &&
           mfree_particles_setup(ps) == MFREE_SUCCESS &&
           mfree_particles_get_neighbor_nnz(ps, &nnz) == MFREE_SUCCESS && nnz == 13;
  printf("mfree %s consumer: %lld neighbour pairs (expected 13): %s\n",
         mfree_version_string(), (long long)nnz, ok ? "ok" : "FAILED");
  mfree_particles_destroy(&ps);
  mfree_context_destroy(&ctx);
  return ok ? 0 : 1;
}
