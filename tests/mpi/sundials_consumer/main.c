/* A host of the installed libmfree_sundials_mpi: one rank (an MPI singleton). A parallel
 * vector of SUNDIALS with the adapter's exact reductions, whose dot product must be the
 * exact value where a left-to-right floating-point sum loses it (also through a clone);
 * and the adapter's exact sum of the host's own values. Prints "vector: ok" and
 * "sum: ok". */
#include <stdio.h>

#include <mfree_sundials_mpi.h>

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  MPI_Comm comm = MPI_COMM_WORLD;
  mfree_context_t *ctx = NULL;
  SUNContext sunctx = NULL;
  /* 1e16 + 1 - 1e16 + 1: the plain sum is 1 (the first 1 is lost), the exact one 2 */
  double x[4] = {1e16, 1.0, -1e16, 1.0}, s = 0.0;
  int ok_ctx = mfree_context_create(&ctx) == MFREE_SUCCESS && SUNContext_Create(&comm, &sunctx) == 0;
  N_Vector v = ok_ctx ? N_VNew_Parallel(comm, 4, 4, sunctx) : NULL;
  int ok = v != NULL && mfree_sundials_mpi_set_reproducible(ctx, v) == MFREE_SUCCESS;
  /* a clone made after the change has it too (SUNDIALS 6 dispatches N_VDotProd(x, y)
   * through y's operations) */
  N_Vector one = ok ? N_VClone(v) : NULL;
  ok = ok && one != NULL;
  if (ok) {
    double *d = N_VGetArrayPointer(v);
    for (int i = 0; i < 4; ++i) d[i] = x[i];
    N_VConst(1.0, one);
    ok = N_VDotProd(v, one) == 2.0 && N_VDotProd(one, v) == 2.0;
  }
  printf(ok ? "vector: ok\n" : "vector: FAILED\n");
  int ok_sum = ok_ctx && mfree_sundials_mpi_sum(ctx, comm, x, 4, &s) == MFREE_SUCCESS && s == 2.0;
  printf(ok_sum ? "sum: ok\n" : "sum: FAILED\n");
  if (one) N_VDestroy(one);
  if (v) N_VDestroy(v);
  SUNContext_Free(&sunctx);
  mfree_context_destroy(&ctx);
  MPI_Finalize();
  return ok && ok_sum ? 0 : 1;
}
