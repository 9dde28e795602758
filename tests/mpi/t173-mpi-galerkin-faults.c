/* Galerkin elastodynamics on ranks (mfree_system_create_elastodynamic_ranks with a
 * Galerkin stiffness assembler), faults and bad input on 1-4 ranks (label mpi): every rank
 * returns the documented status with the failing rank's message, and no rank waits for
 * ever (the CTest timeout bounds it):
 *  - a non-finite displacement or velocity on the last rank: mfree_system_rhs and
 *    mfree_system_integrate return MFREE_FAIL_NONFINITE on every rank ("rank R: particle
 *    i (global id g) has a non-finite ..."), the integration before any step;
 *  - a load history that turns NaN on the last rank only, during the run: every rank
 *    stops at the same step and time with MFREE_FAIL_NONFINITE, y the last good state
 *    (these two: mpibar_check_faults, as for collocation in t164);
 *  - a fixed step above the step limit 2 / omega_max (a minimum over the ranks):
 *    MFREE_FAIL_CFL on every rank;
 *  - at creation, on the last rank only: an assembler on nodal quadrature, one with
 *    Lagrange multipliers, one with consistent integration (MFREE_ERR_UNSUPPORTED, each
 *    naming its reason), a mass assembler (MFREE_ERR_UNSUPPORTED), another density
 *    (MFREE_ERR_ARG: the ranks disagree): that status on every rank, no system. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpibar.h"
#include "mpitest.h"

enum { N = 120 };
static int rank = 0, size = 1;

static void zero(void *u, const double *x, double *v) {
  (void)u;
  (void)x;
  v[0] = 0.0;
}

/* A Galerkin Laplace assembler on the bar's approximant: what makes it unfit (1 nodal
 * quadrature, 2 Lagrange multipliers, 3 consistent integration, 4 a lumped mass form). */
static mfree_assembler_t *unfit(mfree_context_t *ctx, const mpibar_t *b, int what) {
  mfree_assembler_t *as = NULL;
  const double dx = BAR_L / (N - 1), x0 = 0.0, w0 = 1.0, n0 = -1.0;
  const double qx[2] = {0.5 * dx, 1.5 * dx}, qw[2] = {dx, dx};
  mfree_assembler_create(ctx, b->a, NULL, what == 4 ? MFREE_FORM_MASS_LUMPED : MFREE_FORM_LAPLACE, &as);
  mfree_assembler_set_coefficient(as, BAR_E);
  if (what != 1) mfree_assembler_set_quadrature_points(as, 2, qx, MFREE_LAYOUT_AOS, 1, qw);
  if (what == 2)
    mfree_assembler_add_dirichlet(as, MFREE_BC_LAGRANGE, 1, &x0, MFREE_LAYOUT_AOS, 1, &w0, NULL, 1, zero, NULL);
  if (what == 3) mfree_assembler_set_consistent_integration(as, 1, &x0, MFREE_LAYOUT_AOS, 1, &w0, &n0);
  mfree_assembler_setup(as);
  return as;
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const int last = size - 1;
  char who[32];
  snprintf(who, sizeof who, "rank %d:", last);
  mfree_context_t *ctx = NULL;
  mfree_context_create(&ctx);

  mpibar_t b;
  CHECK(mpibar_make_kind(&b, ctx, MPI_COMM_WORLD, N, BAR_SLAB, BAR_GALERKIN_FIXED) == MFREE_SUCCESS, "bar");
  const int neq = 2 * b.n_owned;
  double *y = calloc((size_t)neq + 1, sizeof(double)), *yd = calloc((size_t)neq + 1, sizeof(double));

  /* a non-finite state, a load history turning NaN during the run, on the last rank
   * (the loaded end's) */
  mpibar_check_faults(&b, ctx, y, yd);

  /* a fixed step beyond 2 / omega_max */
  double t = 0.0;
  int64_t steps = -1;
  expect(ctx, mfree_system_integrate(b.sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, 1e-5, 0.0, 1e-6, NULL, NULL, &steps),
         MFREE_FAIL_CFL, "2/omega_max", "a fixed step above the limit");
  CHECK(t == 0.0, "t unchanged");

  /* creation: one rank's unfit assembler, or another density, fails every rank */
  static const struct {
    int what;
    mfree_status_t st;
    const char *needle;
  } cases[] = {{1, MFREE_ERR_UNSUPPORTED, "nodal quadrature"},
               {2, MFREE_ERR_UNSUPPORTED, "Lagrange"},
               {3, MFREE_ERR_UNSUPPORTED, "consistent integration"},
               {4, MFREE_ERR_UNSUPPORTED, "Galerkin stiffness"}};
  mfree_system_t *s = NULL;
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
    mfree_assembler_t *as = rank == last ? unfit(ctx, &b, cases[k].what) : NULL;
    expect(ctx, mfree_halo_create_elastodynamic(b.halo, rank == last ? as : b.as, BAR_RHO, &s), cases[k].st, who,
           cases[k].needle);
    expect(ctx, cases[k].st, cases[k].st, cases[k].needle, "the reason");
    CHECK(s == NULL, "no system");
    mfree_assembler_destroy(&as);
  }
  if (size > 1)
    expect(ctx, mfree_halo_create_elastodynamic(b.halo, b.as, rank == last ? 2 * BAR_RHO : BAR_RHO, &s),
           MFREE_ERR_ARG, "ranks disagree on the density", "density differs on the last rank");
  CHECK(s == NULL, "no system");

  free(y);
  free(yd);
  mpibar_free(&b);
  mfree_context_destroy(&ctx);
  const int rc = mpitest_finish("t173-mpi-galerkin-faults");
  MPI_Finalize();
  return rc;
}
