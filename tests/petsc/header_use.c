/* Compiled with -fsyntax-only as strict C99 (t970) and as C++11 (t971): the adapter's
 * header (with PETSc's and MPI's) must be clean in both, every warning an error, and its
 * declarations usable. */
#include <mfree_petsc.h>

int header_use(mfree_assembler_t *as, MPI_Comm comm);
int header_use(mfree_assembler_t *as, MPI_Comm comm) {
  mfree_context_t *ctx = 0;
  mfree_petsc_t *pk = 0;
  const int64_t gid[1] = {0};
  const int32_t dof[1] = {0};
  const double val[1] = {0.0}, xy[2] = {0.0, 0.0};
  double u[1];
  int32_t its = 0, reason = 0;
  double res = 0.0;
  int64_t first = 0, n = 0, rows[1];
  Mat A = 0;
  KSP ksp = 0;
  Vec b = 0, x = 0;
  mfree_status_t st = mfree_context_create(&ctx);
  if (st == MFREE_SUCCESS) st = mfree_petsc_create(ctx, comm, &pk);
  if (st == MFREE_SUCCESS) st = mfree_petsc_set_options_prefix(pk, "host_");
  if (st == MFREE_SUCCESS) st = mfree_petsc_set_coordinates(pk, 2, 1, xy);
  if (st == MFREE_SUCCESS) st = mfree_petsc_setup(pk, as, 1, 1, 1, gid);
  if (st == MFREE_SUCCESS) st = mfree_petsc_assemble(pk);
  if (st == MFREE_SUCCESS) st = mfree_petsc_set_dirichlet(pk, 1, dof, val);
  if (st == MFREE_SUCCESS) st = mfree_petsc_solve(pk, u);
  if (st == MFREE_SUCCESS) st = mfree_petsc_get_info(pk, &its, &res, &reason);
  if (st == MFREE_SUCCESS) st = mfree_petsc_get_numbering(pk, &first, &n, rows);
  if (st == MFREE_SUCCESS) st = mfree_petsc_get_objects(pk, &A, &ksp, &b, &x);
  mfree_petsc_destroy(&pk);
  mfree_context_destroy(&ctx);
  return (int)st;
}
