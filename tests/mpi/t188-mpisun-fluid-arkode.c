/* The fluid on ranks with ARKODE (label mpi): the dam break of paper 003 (12 x 24
 * particles) by ERKStep (explicit, adaptive steps) on NVECTOR_PARALLEL vectors with
 * reproducible reductions (mfree_sundials_mpi_create_vector) over each rank's owned
 * particles, on 1-4 ranks: every particle's position, velocity and density, matched by
 * global id, and the number of steps are bitwise those of the one-rank run (the same
 * code on MPI_COMM_SELF), for horizontal layers and owners by a hash of the id. The
 * adaptive steps read every rank's error through the WRMS norm. */
#include <arkode/arkode_erkstep.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mfree_sundials.h"
#include "mfree_sundials_mpi.h"
#include "mpifluid.h"
#include "mpitest.h"

static const double T_END = 2e-3, RTOL = 1e-3;

static void flag(int f, const char *what) { CHECK(f >= 0, "%s returned %d", what, f); }

/* The state of every particle (5 n, by global id, on every rank) after T_END; the steps. */
static long run(mfree_context_t *ctx, SUNContext sunctx, MPI_Comm comm, const damb_t *b, const int *owner,
                double *out) {
  rankfluid_t r;
  const double width = 4.0 * b->h + 4.0 * b->d;
  mfree_status_t st = rankfluid_make(&r, ctx, comm, b, owner, width, 0);
  CHECK(st == MFREE_SUCCESS, "system: status %d: %s", (int)st, mpifluid_error(ctx));
  mfree_sundials_t *ad = NULL;
  CHECK(mfree_sundials_create(ctx, r.sys, &ad) == MFREE_SUCCESS, "adapter: %s", mpifluid_error(ctx));
  N_Vector y = NULL;
  CHECK(mfree_sundials_mpi_create_vector(ctx, r.sys, comm, sunctx, &y) == MFREE_SUCCESS, "vector: %s",
        mpifluid_error(ctx));
  CHECK(N_VGetLength(y) == 5 * b->n, "global length %ld", (long)N_VGetLength(y));
  const int no = r.n_owned;
  memcpy(N_VGetArrayPointer(y), r.y, 5 * (size_t)no * sizeof(double));
  void *mem = ERKStepCreate(mfree_sundials_rhs, 0.0, y, sunctx);
  N_Vector atol = N_VClone(y);
  mpifluid_tolerances(b, no, N_VGetArrayPointer(atol));
  flag(ERKStepSVtolerances(mem, RTOL, atol), "tolerances");
  flag(ERKStepSetUserData(mem, ad), "user data");
  flag(ERKStepSetMaxNumSteps(mem, 100000), "max steps");
  flag(ERKStepSetStopTime(mem, T_END), "stop time");
  double t = 0.0;
  flag(ERKStepEvolve(mem, T_END, y, &t, ARK_NORMAL), "ERKStepEvolve");
  long steps = -1;
  ERKStepGetNumSteps(mem, &steps);
  CHECK(t == T_END, "t %.17g", t);
  mpifluid_state(comm, &r, N_VGetArrayPointer(y), b->n, out); /* every rank's owned states, by global id */
  ERKStepFree(&mem);
  N_VDestroy(atol);
  N_VDestroy(y);
  mfree_sundials_destroy(&ad);
  rankfluid_free(&r);
  return steps;
}

int main(int argc, char **argv) {
  int rank = 0, size = 1;
  mfree_context_t *ctx = mpitest_start(&argc, &argv, &rank, &size);
  SUNContext sunctx = NULL, self_ctx = NULL;
  MPI_Comm world = MPI_COMM_WORLD, self = MPI_COMM_SELF;
  SUNContext_Create(&world, &sunctx);
  SUNContext_Create(&self, &self_ctx);
  damb_t b;
  damb_make(&b, 12, 24);
  const int n = b.n;
  int *owner = calloc((size_t)n, sizeof *owner);
  double *y1 = malloc(5 * (size_t)n * sizeof *y1), *y = malloc(5 * (size_t)n * sizeof *y);
  const long s1 = run(ctx, self_ctx, MPI_COMM_SELF, &b, owner, y1);
  double front = 0.0;
  for (int q = 0; q < n; ++q) front = fmax(front, y1[2 * q]);
  CHECK(s1 > 10 && front > b.a - 0.5 * b.d, "%ld steps, front %.5f m, column %.5f m", s1, front, b.a);
  for (int how = 0; how < 2; ++how) {
    for (int i = 0; i < n; ++i) {
      int p = (int)(b.y[2 * i + 1] / (2.0 * b.a) * size);
      p = p < 0 ? 0 : p >= size ? size - 1 : p;
      owner[i] = how ? (int)(mpitest_hash((uint64_t)i) % (uint64_t)size) : p;
    }
    const long s = run(ctx, sunctx, MPI_COMM_WORLD, &b, owner, y);
    CHECK(s == s1, "%s: %ld steps, one rank %ld", how ? "hashed" : "layers", s, s1);
    int bad = 0;
    for (int q = 0; q < n; ++q)
      bad += memcmp(y + 2 * q, y1 + 2 * q, 16) || memcmp(y + 2 * (size_t)n + 2 * q, y1 + 2 * (size_t)n + 2 * q, 16) ||
             memcmp(y + 4 * (size_t)n + q, y1 + 4 * (size_t)n + q, 8);
    CHECK(bad == 0, "%s: %d of %d particles differ from one rank's", how ? "hashed" : "layers", bad, n);
  }
  if (rank == 0) printf("t188: ERKStep %ld steps to T = %g s on %d ranks, front %.5f m\n", s1, T_END, size, front);
  free(owner), free(y1), free(y);
  damb_free(&b);
  SUNContext_Free(&self_ctx);
  SUNContext_Free(&sunctx);
  mfree_context_destroy(&ctx);
  const int rc = mpitest_finish("t188-mpisun-fluid-arkode");
  MPI_Finalize();
  return rc;
}
