/* A host program of the installed libmfree_petsc (one MPI process): the 1D Poisson
 * problem -u'' = 1 on [0, 1] with u(0) = u(1) = 0, MLS 1 with nodal quadrature,
 * assembled into PETSc and solved by CG with GAMG; prints "petsc: ok" when the solver
 * converged and the midpoint value is within 2 % of the exact 1/8. */
#include <math.h>
#include <stdio.h>

#include <mfree_petsc.h>

enum { N = 41 };

static void one(void *user, const double *x, double *f) {
  (void)user, (void)x;
  f[0] = 1.0;
}

int main(int argc, char **argv) {
  if (PetscInitialize(&argc, &argv, NULL, NULL)) return 1;
  double x[N], vol[N], h = 1.5 / (N - 1), u[N];
  int64_t gid[N];
  for (int i = 0; i < N; ++i) {
    x[i] = (double)i / (N - 1);
    vol[i] = (i == 0 || i == N - 1 ? 0.5 : 1.0) / (N - 1);
    gid[i] = i;
  }
  mfree_context_t *ctx = NULL;
  mfree_particles_t *ps = NULL;
  mfree_approximant_t *ap = NULL;
  mfree_assembler_t *as = NULL;
  mfree_petsc_t *pk = NULL;
  const int32_t dofs[2] = {0, N - 1};
  const double zero[2] = {0.0, 0.0};
  mfree_status_t st = mfree_context_create(&ctx);
  if (!st) st = mfree_particles_create(ctx, 1, N, &ps);
  if (!st) st = mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 1, MFREE_BORROW);
  if (!st) st = mfree_particles_set_volumes(ps, vol, 1, MFREE_BORROW);
  if (!st) st = mfree_particles_set_support(ps, &h, 0, MFREE_COPY);
  if (!st) st = mfree_particles_setup(ps);
  if (!st) st = mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, &ap);
  if (!st) st = mfree_approximant_set_order(ap, 1);
  if (!st) st = mfree_assembler_create(ctx, ap, NULL, MFREE_FORM_LAPLACE, &as);
  if (!st) st = mfree_assembler_set_quadrature_nodal(as);
  if (!st) st = mfree_assembler_set_body_force(as, one, NULL);
  if (!st) st = mfree_assembler_setup(as);
  if (!st) st = mfree_petsc_create(ctx, PETSC_COMM_WORLD, &pk);
  if (!st) st = mfree_petsc_setup(pk, as, 1, N, N, gid);
  if (!st) st = mfree_petsc_set_dirichlet(pk, 2, dofs, zero);
  if (!st) st = mfree_petsc_solve(pk, u);
  int failed = 1;
  if (st) {
    char msg[256] = "";
    mfree_context_get_last_error(ctx, NULL, msg, sizeof msg);
    fprintf(stderr, "status %d: %s\n", (int)st, msg);
  } else if (fabs(u[N / 2] - 0.125) < 0.02 * 0.125) {
    printf("petsc: ok\n");
    failed = 0;
  } else {
    fprintf(stderr, "u(1/2) = %g, expected 0.125\n", u[N / 2]);
  }
  mfree_petsc_destroy(&pk);
  mfree_assembler_destroy(&as);
  mfree_approximant_destroy(&ap);
  mfree_particles_destroy(&ps);
  mfree_context_destroy(&ctx);
  PetscFinalize();
  return failed;
}
