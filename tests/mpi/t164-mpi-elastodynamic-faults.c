/* The elastodynamic system on ranks, faults and bad input on 1-4 ranks (label mpi): every
 * rank returns the documented status with the failing rank's message, and no rank waits
 * for ever (the CTest timeout bounds it):
 *  - a non-finite state on the last rank: mfree_system_rhs and mfree_system_integrate
 *    return MFREE_FAIL_NONFINITE on every rank ("rank R: particle i (global id g) has a
 *    non-finite displacement"), the integration before any step (t and y unchanged);
 *  - a load history that turns NaN on the last rank only, during the run: every rank
 *    stops at the same step and time with MFREE_FAIL_NONFINITE, y the last good state
 *    (these two: mpibar_check_faults);
 *  - ranks that disagree on t_end or cfl (integrate), on the density (create): MFREE_ERR_ARG
 *    on every rank, naming two ranks and their values;
 *  - at creation a NULL assembler, a negative density, a Galerkin assembler on nodal
 *    quadrature (t173 has the other Galerkin cases) or a particle
 *    set without global ids on one rank: that rank's status (MFREE_ERR_NULL,
 *    MFREE_ERR_ARG, MFREE_ERR_UNSUPPORTED, MFREE_ERR_STATE) on every rank, no system;
 *    NULL callbacks or output: MFREE_ERR_NULL (local);
 *  - the host-callback path (mfree_system_create_elastodynamic_ranks with the host's own
 *    callbacks, here wrapping the plan's) gives the plan's right-hand side bit for bit;
 *  - mfree_halo_allgather: a negative count or NULL values on one rank: the status on
 *    every rank; a capacity too small: the total only. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpibar.h"
#include "mpitest.h"

enum { N = 120 };
static int rank = 0, size = 1;

/* the host's own callbacks (counting), over the plan */
static int64_t host_calls = 0;
static mfree_status_t host_exchange(void *user, int32_t ncomp, double *field, int64_t ld) {
  ++host_calls;
  return mfree_halo_exchange((mfree_halo_t *)user, ncomp, field, ld);
}
static mfree_status_t host_allgather(void *user, const double *in, int64_t n, double *out, int64_t cap,
                                     int64_t *total) {
  ++host_calls;
  return mfree_halo_allgather(user, in, n, out, cap, total);
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
  CHECK(mpibar_make(&b, ctx, MPI_COMM_WORLD, N, BAR_SLAB) == MFREE_SUCCESS, "bar");
  const int neq = 2 * b.n_owned;
  double *y = calloc((size_t)neq + 1, sizeof(double)), *yd = calloc((size_t)neq + 1, sizeof(double));
  double *y2 = calloc((size_t)neq + 1, sizeof(double));

  /* a non-finite state, a load history turning NaN during the run, on the last rank */
  mpibar_check_faults(&b, ctx, y, yd);
  double t = 0.0;
  int64_t steps = -1;

  /* ranks that disagree on the integration's arguments */
  if (size > 1) {
    t = 0.0;
    expect(ctx,
           mfree_system_integrate(b.sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, rank == last ? 2e-6 : 1e-6, 0.5, 0.0, NULL,
                                  NULL, &steps),
           MFREE_ERR_ARG, "ranks disagree on t_end", "t_end differs on the last rank");
    expect(ctx,
           mfree_system_integrate(b.sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, 1e-6, rank == last ? 0.25 : 0.5, 0.0, NULL,
                                  NULL, &steps),
           MFREE_ERR_ARG, "ranks disagree on cfl", "cfl differs on the last rank");
    CHECK(t == 0.0, "t unchanged");
  }
  t = 0.0;
  expect(ctx,
         mfree_system_integrate(b.sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, 1e-6, rank == last ? 2.0 : 0.5, 0.0, NULL,
                                NULL, &steps),
         MFREE_ERR_ARG, who, "cfl > 1 on the last rank");
  expect(ctx,
         mfree_system_integrate(b.sys, rank == last ? MFREE_INTEGRATOR_PREDICTOR_CORRECTOR : MFREE_INTEGRATOR_LEAPFROG,
                                y, &t, 1e-6, 0.5, 0.0, NULL, NULL, &steps),
         MFREE_ERR_UNSUPPORTED, who, "another scheme on the last rank");

  /* creation: one rank's failure, or ranks that disagree, fail every rank */
  mfree_system_t *s = NULL;
  expect(ctx, mfree_halo_create_elastodynamic(b.halo, rank == last ? NULL : b.as, BAR_RHO, &s), MFREE_ERR_NULL,
         who, "NULL assembler on the last rank");
  CHECK(s == NULL, "no system");
  expect(ctx, mfree_halo_create_elastodynamic(b.halo, b.as, rank == last ? -1.0 : BAR_RHO, &s), MFREE_ERR_ARG, who,
         "negative density on the last rank");
  if (size > 1)
    expect(ctx, mfree_halo_create_elastodynamic(b.halo, b.as, rank == last ? 2 * BAR_RHO : BAR_RHO, &s),
           MFREE_ERR_ARG, "ranks disagree on the density", "density differs on the last rank");
  CHECK(s == NULL, "no system");
  mfree_assembler_t *gal = NULL;
  mfree_assembler_create(ctx, b.a, NULL, MFREE_FORM_LAPLACE, &gal);
  mfree_assembler_setup(gal);
  expect(ctx, mfree_halo_create_elastodynamic(b.halo, rank == last ? gal : b.as, BAR_RHO, &s), MFREE_ERR_UNSUPPORTED,
         who, "a Galerkin assembler on the last rank");
  mfree_assembler_destroy(&gal);
  /* a set without global ids on the last rank */
  {
    mfree_particles_t *ps = NULL;
    mfree_approximant_t *a = NULL;
    mfree_assembler_t *as = NULL;
    const double dx = BAR_L / (N - 1), h = 1.5 * dx;
    mfree_particles_create(ctx, 1, b.n_owned + b.n_ghost, &ps);
    mfree_particles_set_num_ghost(ps, b.n_ghost);
    mfree_particles_set_positions(ps, b.x, MFREE_LAYOUT_AOS, 1, MFREE_BORROW);
    mfree_particles_set_support(ps, &h, 0, MFREE_COPY);
    mfree_particles_set_volumes(ps, &dx, 0, MFREE_COPY);
    mfree_approximant_create(ctx, ps, MFREE_METHOD_SSPH, &a);
    mfree_approximant_set_kernel(a, MFREE_KERNEL_REVISED_SUPER_GAUSS, 1.6);
    mfree_approximant_set_order(a, 2);
    mfree_approximant_set_derivatives(a, 7);
    mfree_assembler_create(ctx, a, NULL, MFREE_FORM_COLLOCATION_LAPLACE, &as);
    mfree_assembler_set_coefficient(as, BAR_E);
    mfree_assembler_setup(as);
    expect(ctx, mfree_halo_create_elastodynamic(b.halo, rank == last ? as : b.as, BAR_RHO, &s), MFREE_ERR_STATE,
           "global ids", "no global ids on the last rank");
    CHECK(s == NULL, "no system");
    mfree_assembler_destroy(&as);
    mfree_approximant_destroy(&a);
    mfree_particles_destroy(&ps);
  }
  /* local failures: nothing to agree with */
  expect(ctx, mfree_halo_create_elastodynamic(b.halo, b.as, BAR_RHO, NULL), MFREE_ERR_NULL, "output", "NULL output");
  CHECK(mfree_halo_create_elastodynamic(NULL, b.as, BAR_RHO, &s) == MFREE_ERR_NULL, "NULL plan");
  expect(ctx, mfree_system_create_elastodynamic_ranks(ctx, b.as, BAR_RHO, NULL, host_allgather, b.halo, &s),
         MFREE_ERR_NULL, "callback", "NULL exchange");

  /* the host-callback path: the same right-hand side, bit for bit */
  CHECK(mfree_system_create_elastodynamic_ranks(ctx, b.as, BAR_RHO, host_exchange, host_allgather, b.halo, &s) ==
            MFREE_SUCCESS,
        "host callbacks");
  mfree_system_set_load_history(s, mpibar_pulse, NULL);
  for (int q = 0; q < neq; ++q) y[q] = 1e-9 * sin(0.37 * q + rank);
  const int64_t before = host_calls;
  CHECK(mfree_system_rhs(b.sys, 1e-6, y, yd) == MFREE_SUCCESS, "rhs, plan");
  CHECK(mfree_system_rhs(s, 1e-6, y, y2) == MFREE_SUCCESS, "rhs, host callbacks");
  CHECK(host_calls - before == 2, "one exchange and one gather per evaluation: %lld calls", (long long)(host_calls - before));
  CHECK(memcmp(yd, y2, sizeof(double) * (size_t)neq) == 0, "the same bits");
  mfree_system_destroy(&s);

  /* mfree_halo_allgather's bad input */
  double in[2] = {1.0, 2.0}, out[16];
  int64_t total = -1;
  expect(ctx, mfree_halo_allgather(b.halo, in, rank == last ? -1 : 1, out, 16, &total), MFREE_ERR_ARG, who,
         "allgather, negative count on the last rank");
  expect(ctx, mfree_halo_allgather(b.halo, rank == 0 ? NULL : in, 2, out, 16, &total), MFREE_ERR_NULL, "rank 0:",
         "allgather, NULL values on rank 0");
  out[0] = -7.0;
  CHECK(mfree_halo_allgather(b.halo, in, 2, out, rank == last ? 1 : 16, &total) == MFREE_SUCCESS && total == 2 * size &&
            out[0] == -7.0,
        "allgather, a capacity too small on the last rank: the total only (%lld)", (long long)total);
  CHECK(mfree_halo_allgather(b.halo, in, 2, out, 16, &total) == MFREE_SUCCESS && out[0] == 1.0 &&
            out[2 * size - 1] == 2.0,
        "allgather");
  CHECK(mfree_halo_allgather(NULL, in, 2, out, 16, &total) == MFREE_ERR_NULL, "allgather, NULL plan");
  MPI_Comm comm = MPI_COMM_NULL;
  CHECK(mfree_halo_get_communicator(b.halo, &comm) == MFREE_SUCCESS && comm != MPI_COMM_NULL, "communicator");
  CHECK(mfree_halo_get_communicator(b.halo, NULL) == MFREE_ERR_NULL, "communicator, NULL output");

  free(y);
  free(y2);
  free(yd);
  mpibar_free(&b);
  mfree_context_destroy(&ctx);
  const int rc = mpitest_finish("t164-mpi-elastodynamic-faults");
  MPI_Finalize();
  return rc;
}
