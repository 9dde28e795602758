/* Compiled with -fsyntax-only as strict C99 (t960) and as C++11 (t961): the adapter's
 * header must be clean in both, every warning an error, and its declarations usable. */
#include <mfree_mpi.h>

int header_use(MPI_Comm comm);
int header_use(MPI_Comm comm) {
  mfree_context_t *ctx = 0;
  mfree_halo_t *h = 0;
  double x[2] = {0.0, 0.0};
  int64_t ids[1] = {0}, off = 0, total = 0, ns = 0, nr = 0;
  int32_t no = 0, ng = 0, nn = 0;
  mfree_status_t st = mfree_context_create(&ctx);
  if (st == MFREE_SUCCESS) st = mfree_halo_create(ctx, comm, 2, &h);
  if (st == MFREE_SUCCESS) st = mfree_halo_setup(h, 1, x, 2, ids, 0.5);
  if (st == MFREE_SUCCESS) st = mfree_halo_get_size(h, &no, &ng);
  if (st == MFREE_SUCCESS) st = mfree_halo_get_global_ids(h, ids);
  if (st == MFREE_SUCCESS) st = mfree_halo_get_global_offset(h, &off, &total);
  if (st == MFREE_SUCCESS) st = mfree_halo_get_plan(h, &nn, &ns, &nr);
  if (st == MFREE_SUCCESS) st = mfree_halo_exchange(h, 2, x, 2);
  mfree_halo_destroy(&h);
  if (st == MFREE_SUCCESS) st = mfree_halo_create_f(ctx, 0, 2, &h);
  mfree_halo_destroy(&h);
  mfree_context_destroy(&ctx);
  return (int)st;
}
