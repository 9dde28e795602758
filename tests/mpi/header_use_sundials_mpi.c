/* Compiled with -fsyntax-only as strict C99 (t170): the header of libmfree_sundials_mpi
 * must be clean, every warning an error, and its declarations usable. */
#include <mfree_sundials_mpi.h>

int header_use(MPI_Comm comm, mfree_system_t *sys, SUNContext sunctx);
int header_use(MPI_Comm comm, mfree_system_t *sys, SUNContext sunctx) {
  mfree_context_t *ctx = 0;
  N_Vector v = 0;
  double x[2] = {1.0, 2.0}, s = 0.0;
  mfree_status_t st = mfree_context_create(&ctx);
  if (st == MFREE_SUCCESS) st = mfree_sundials_mpi_create_vector(ctx, sys, comm, sunctx, &v);
  if (st == MFREE_SUCCESS) st = mfree_sundials_mpi_set_reproducible(ctx, v);
  if (st == MFREE_SUCCESS) st = mfree_sundials_mpi_sum(ctx, comm, x, 2, &s);
  if (v) N_VDestroy(v);
  mfree_context_destroy(&ctx);
  return (int)st;
}
