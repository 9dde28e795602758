/* Options of the one-process fluid on ranks (label mpi), on 1, 2 and 4 ranks: dummy wall
 * particles are taken (t176 runs them), and removed again (count 0) they leave nothing
 * behind: afterwards the system takes 40 leap-frog steps to the same bits as a system that
 * never saw any of these (open boundaries on ranks: t195, t198). The active-particle
 * query answers for the owned particles (all active), not for the ghosts. The acoustic
 * step is taken (t179 runs it); set on one rank only, the integration returns
 * MFREE_ERR_ARG on every rank (its power iteration is collective) and takes no step. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpifluid.h"
#include "mpitest.h"

int main(int argc, char **argv) {
  int rank = 0, size = 1;
  damb_t b;
  int *owner = NULL;
  mfree_context_t *ctx = mpifluid_start(&argc, &argv, &rank, &size, &b, 12, 24, &owner);
  const double width = 4.0 * b.h + 2.0 * b.d;
  rankfluid_t r, fresh;
  mfree_status_t st = rankfluid_make(&r, ctx, MPI_COMM_WORLD, &b, owner, width, 0);
  if (st == MFREE_SUCCESS) st = rankfluid_make(&fresh, ctx, MPI_COMM_WORLD, &b, owner, width, 0);
  CHECK(st == MFREE_SUCCESS, "systems on the ranks: status %d: %s", (int)st, mpifluid_error(ctx));
  if (st != MFREE_SUCCESS) MPI_Abort(MPI_COMM_WORLD, 1);

  /* a row of dummies under the floor, as the serial dam break's */
  enum { ND = 8 };
  double xd[2 * ND], vol = b.d * b.d;
  for (int k = 0; k < ND; ++k) xd[2 * k] = (k + 0.5) * b.d, xd[2 * k + 1] = -0.5 * b.d;
  expect(ctx, mfree_system_set_dummy_particles(r.sys, ND, xd, &vol, 0), MFREE_SUCCESS, NULL, "dummy particles");
  expect(ctx, mfree_system_set_dummy_particles(r.sys, 0, NULL, NULL, 0), MFREE_SUCCESS, NULL, "no dummy particles");
  expect(ctx, mfree_system_set_acoustic_step(r.sys, 1), MFREE_SUCCESS, NULL, "acoustic step");
  expect(ctx, mfree_system_set_acoustic_step(r.sys, 0), MFREE_SUCCESS, NULL, "acoustic step off");
  if (size > 1) {
    expect(ctx, mfree_system_set_acoustic_step(r.sys, rank == 0), MFREE_SUCCESS, NULL, "acoustic step on rank 0");
    int64_t one = 1, none = -1;
    double t0 = 0.0;
    const mfree_status_t got = mfree_system_integrate(r.sys, MFREE_INTEGRATOR_LEAPFROG, r.y, &t0, 1.0, 0.5, 0.0,
                                                      mpifluid_stop_at, &one, &none);
    expect(ctx, got, MFREE_ERR_ARG, "ranks disagree on the acoustic step", "the acoustic step on rank 0 only");
    CHECK(none == 0 && t0 == 0.0, "the refused integration took %lld steps to t = %g", (long long)none, t0);
    expect(ctx, mfree_system_set_acoustic_step(r.sys, 0), MFREE_SUCCESS, NULL, "acoustic step off again");
  }
  /* the query: the owned particles, every one active */
  int32_t nactive = -1;
  int32_t *state = malloc(((size_t)r.n_owned + 1) * sizeof *state);
  expect(ctx, mfree_system_get_active(r.sys, &nactive, r.n_owned, state), MFREE_SUCCESS, NULL, "active query");
  CHECK(nactive == r.n_owned, "%d active of %d owned", (int)nactive, r.n_owned);
  int fluid = 0;
  for (int k = 0; k < r.n_owned; ++k) fluid += state[k] == MFREE_PARTICLE_FLUID;
  CHECK(fluid == r.n_owned, "%d of %d owned particles in the fluid state", fluid, r.n_owned);
  if (r.n_ghost > 0)
    expect(ctx, mfree_system_get_active(r.sys, &nactive, r.n_owned + r.n_ghost, state), MFREE_ERR_ARG, "state holds",
           "a state sized for the ghosts too");

  /* nothing changed */
  int64_t forty = 40, steps = 0, steps_f = 0;
  double t = 0.0, tf = 0.0;
  st = mfree_system_integrate(r.sys, MFREE_INTEGRATOR_LEAPFROG, r.y, &t, 1.0, 0.5, 0.0, mpifluid_stop_at, &forty,
                              &steps);
  CHECK(st == MFREE_SUCCESS && steps == 40, "after the refusals: status %d, %lld steps: %s", (int)st,
        (long long)steps, mpifluid_error(ctx));
  st = mfree_system_integrate(fresh.sys, MFREE_INTEGRATOR_LEAPFROG, fresh.y, &tf, 1.0, 0.5, 0.0, mpifluid_stop_at,
                              &forty, &steps_f);
  CHECK(st == MFREE_SUCCESS && steps_f == 40 && t == tf, "the fresh system: status %d, t %.17g and %.17g", (int)st,
        t, tf);
  CHECK(!memcmp(r.y, fresh.y, 5 * (size_t)r.n_owned * sizeof *r.y), "the refusals changed the run");

  free(state);
  rankfluid_free(&fresh);
  rankfluid_free(&r);
  free(owner);
  damb_free(&b);
  mfree_context_destroy(&ctx);
  const int rc = mpitest_finish("t175-mpi-fluid-refused-options");
  MPI_Finalize();
  return rc;
}
