/* Faults of the dummy walls on ranks (label mpi), on 1-4 ranks under a timeout: every rank
 * returns the same status and none waits alone. The dam break with the examples' dummy
 * tank and a ghost layer two support radii deep (and two spacings): with density
 * diffusion too the layer must reach four radii, so a leap-frog run, a right-hand side and
 * an output return MFREE_ERR_HALO on every rank, naming the four radii, with nothing
 * changed; without the diffusion the same system runs. Then a non-finite density at the
 * last rank's first particle: MFREE_FAIL_NONFINITE on every rank with that rank's message
 * and the particle's global id from both integrators and a right-hand side, the state as
 * it was.
 * Bad dummy input is the setter's own (local) failure: t060. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fluid_common.h"
#include "mpifluid.h"
#include "mpitest.h"

int main(int argc, char **argv) {
  int rank = 0, size = 1;
  damb_t b;
  int *owner = NULL;
  mfree_context_t *ctx = mpifluid_start(&argc, &argv, &rank, &size, &b, 12, 24, &owner);
  const int last = size - 1;
  int64_t five = 5;
  char msg[512];
  rankfluid_t r;
  mfree_status_t st = rankfluid_make(&r, ctx, MPI_COMM_WORLD, &b, owner, 4.0 * b.h + 2.0 * b.d, 0);
  /* the tank is 5 a long, its end walls 1.5 times the column high */
  if (st == MFREE_SUCCESS) st = fc_dummy_tank(r.sys, 5 * 12, 3.0 * b.a, b.d);
  CHECK(mpitest_same_status(st, "creation") == MFREE_SUCCESS, "creation with the dummies: status %d", (int)st);
  if (st != MFREE_SUCCESS) MPI_Abort(MPI_COMM_WORLD, 1);
  const size_t ns = 5 * (size_t)r.n_owned;
  double *y0 = malloc((ns + 1) * sizeof *y0), *dot = malloc((ns + 1) * sizeof *dot);
  double *vhat = malloc((ns + 1) * sizeof *vhat);

  /* ---- dummies and density diffusion on a layer of two radii ---- */
  expect(ctx, mfree_system_set_density_diffusion(r.sys, 0.1), MFREE_SUCCESS, NULL, "density diffusion");
  memcpy(y0, r.y, ns * sizeof *y0);
  double t = 0.0;
  int64_t steps = 0;
  st = mfree_system_integrate(r.sys, MFREE_INTEGRATOR_LEAPFROG, r.y, &t, 1.0, 0.5, 0.0, mpifluid_stop_at, &five,
                              &steps);
  CHECK(mpitest_same_status(st, "run, two radii") == MFREE_ERR_HALO && steps == 0 && t == 0.0, "run: status %d, %lld steps",
        (int)st, (long long)steps);
  CHECK(strstr(mpifluid_error(ctx), "four support radii (dummy particles with density diffusion)"),
        "run: message \"%s\"", mpifluid_error(ctx));
  CHECK(!memcmp(y0, r.y, ns * sizeof *y0), "the refused run changed the state");
  st = mfree_system_rhs(r.sys, 0.0, r.y, dot);
  CHECK(mpitest_same_status(st, "rhs, two radii") == MFREE_ERR_HALO, "rhs: status %d", (int)st);
  CHECK(strstr(mpifluid_error(ctx), "four support radii"), "rhs: message \"%s\"", mpifluid_error(ctx));
  st = mfree_system_get_velocity(r.sys, r.y, vhat);
  CHECK(mpitest_same_status(st, "velocity, two radii") == MFREE_ERR_HALO, "velocity: status %d", (int)st);

  /* ---- without the diffusion, two radii are enough ---- */
  expect(ctx, mfree_system_set_density_diffusion(r.sys, 0.0), MFREE_SUCCESS, NULL, "no density diffusion");
  st = mfree_system_integrate(r.sys, MFREE_INTEGRATOR_LEAPFROG, r.y, &t, 1.0, 0.5, 0.0, mpifluid_stop_at, &five,
                              &steps);
  CHECK(mpitest_same_status(st, "run, no diffusion") == MFREE_SUCCESS && steps == 5, "run: status %d, %lld steps: %s",
        (int)st, (long long)steps, mpifluid_error(ctx));

  /* ---- a non-finite density on the last rank after the five steps: leap-frog, then the
     predictor-corrector ---- */
  for (int when = 0; when < 2; ++when) {
    if (rank == last && r.n_owned > 0) r.y[4 * (size_t)r.n_owned] = NAN;
    const double t0 = t;
    memcpy(y0, r.y, ns * sizeof *y0);
    st = mfree_system_integrate(r.sys, when ? MFREE_INTEGRATOR_PREDICTOR_CORRECTOR : MFREE_INTEGRATOR_LEAPFROG, r.y,
                                &t, 1.0, 0.5, 0.0, mpifluid_stop_at, &five, &steps);
    CHECK(mpitest_same_status(st, "non-finite") == MFREE_FAIL_NONFINITE, "non-finite density (%d): status %d", when, (int)st);
    snprintf(msg, sizeof msg, "%s", mpifluid_error(ctx));
    char want[32];
    snprintf(want, sizeof want, "rank %d: ", last);
    CHECK(strstr(msg, want) && strstr(msg, "global id"), "non-finite density: message \"%s\"", msg);
    CHECK(steps == 0 && t == t0 && !memcmp(y0, r.y, ns * sizeof *y0),
          "non-finite density: %lld steps taken, or the state changed", (long long)steps);
    st = mfree_system_rhs(r.sys, 0.0, r.y, dot);
    CHECK(mpitest_same_status(st, "rhs") == MFREE_FAIL_NONFINITE, "rhs of a non-finite state: status %d", (int)st);
  }

  free(y0), free(dot), free(vhat);
  rankfluid_free(&r);
  free(owner);
  damb_free(&b);
  mfree_context_destroy(&ctx);
  const int rc = mpitest_finish("t178-mpifluid-dummies-faults");
  MPI_Finalize();
  return rc;
}
