/* The elastodynamic bar of paper 001 Sect. 6.4 on 1-4 ranks (label mpi) with ARKODE on
 * NVECTOR_PARALLEL vectors whose reductions are reproducible
 * (mfree_sundials_mpi_create_vector): ERKStep (explicit, adaptive steps) and ARKStep with
 * the mass through a matrix-free PCG mass solver (mfree_sundials_mass_times) give, for
 * every particle matched by global id, bitwise the displacements and velocities of the
 * one-rank run (the same code on MPI_COMM_SELF), with the same numbers of steps, for
 * contiguous slabs, scattered owners and everything on one rank. The adaptive steps
 * depend on every rank's error through the WRMS norm: any rounding difference of a
 * reduction would change them. Also: the exact sum (mfree_sundials_mpi_sum) of values
 * whose floating-point sum depends on the order is the same on every partition.
 * Built three times: with the collocation bar (t163), with t704's Galerkin bar with its
 * left end held by a node row and the lumped mass (t172, BAR_KIND = BAR_GALERKIN_FIXED),
 * and with that bar's consistent mass (t157, MASS_CONSISTENT = 1): ARKStep's mass form
 * M_C y' = M_L f (the system on ranks divides by its lumped mass, so M_L f = g f - K u,
 * the consistent system's own force) with the consistent mass's products
 * (mfree_sundials_set_consistent_mass; on ranks owned rows, v exchanged at the ghosts),
 * over the first 20 ns of the pulse (this consistent mass is ill-conditioned: PCG takes
 * hundreds of iterations a step, each dot product reading every rank's entries). There
 * the steps, PCG iterations (ARKStepGetNumMassIters) and states are one rank's bit for
 * bit, and against independent results: the one-process system with a consistent mass
 * assembler (mfree_system_create_elastodynamic_galerkin, MFREE_FORM_MASS: its right-hand
 * side solves with M_C by a Cholesky factorisation) through the same calls on one process
 * agrees within 1e-4 of the largest displacement, while the lumped-mass run is farther
 * from it than that. */
#include <arkode/arkode_arkstep.h>
#include <arkode/arkode_erkstep.h>
#include <math.h>
#include <nvector/nvector_serial.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sunlinsol/sunlinsol_pcg.h>

#include "mfree_sundials.h"
#include "mfree_sundials_mpi.h"
#include "mpibar.h"
#include "mpitest.h"

#ifndef BAR_KIND
#define BAR_KIND BAR_COLLOCATION
#define TEST_NAME "t163-mpisun-elastodynamic-arkode"
#endif
#ifndef MASS_CONSISTENT
#define MASS_CONSISTENT 0
#endif

/* (the Galerkin bar's PCG mass solves take several iterations, each with exact dot
 * products: fewer particles and the pulse's length keep its run as short as the
 * collocation bar's) */
enum { N = BAR_KIND == BAR_COLLOCATION ? 160 : MASS_CONSISTENT ? 50 : 100 };
static const double T_END = BAR_KIND == BAR_COLLOCATION ? 5e-6 : MASS_CONSISTENT ? 2e-8 : 3e-6, RTOL = 1e-6;

static void flag(int f, const char *what) { CHECK(f >= 0, "%s returned %d", what, f); }

/* The system sys (n_owned particles here) from rest to T_END on vectors over comm: y its
   final state; the step count, *iters the mass solver's iterations. mass: ARKStep with
   PCG on the mass (consistent: the consistent mass's products), else ERKStep */
static long evolve(mfree_context_t *ctx, SUNContext sunctx, MPI_Comm comm, mfree_system_t *sys, int n_owned,
                   int mass, int consistent, double *yout, long *iters) {
  mfree_sundials_t *ad = NULL;
  CHECK(mfree_sundials_create(ctx, sys, &ad) == MFREE_SUCCESS, "adapter");
  CHECK(mfree_sundials_set_consistent_mass(ad, consistent) == MFREE_SUCCESS, "consistent");
  N_Vector y = NULL;
  CHECK(mfree_sundials_mpi_create_vector(ctx, sys, comm, sunctx, &y) == MFREE_SUCCESS, "vector");
  CHECK(N_VGetLength(y) == 2 * N, "global length %ld", (long)N_VGetLength(y));
  N_Vector atol = N_VClone(y);
  N_VConst(1e-12, atol);
  double *pa = N_VGetArrayPointer(atol);
  for (int i = 0; i < n_owned; ++i) pa[n_owned + i] = 1e-5; /* velocities */
  void *mem = NULL;
  SUNLinearSolver LS = NULL;
  double t = 0.0;
  long steps = -1;
  *iters = 0;
  if (mass) {
    mem = ARKStepCreate(mfree_sundials_rhs_mass_form, NULL, 0.0, y, sunctx);
    LS = SUNLinSol_PCG(y, SUN_PREC_NONE, consistent ? 2000 : 10, sunctx);
    flag(ARKStepSetMassLinearSolver(mem, LS, NULL, SUNFALSE), "ARKStepSetMassLinearSolver");
    flag(ARKStepSetMassTimes(mem, NULL, mfree_sundials_mass_times, ad), "ARKStepSetMassTimes");
    CHECK(mfree_sundials_set_state(ad, y) == MFREE_SUCCESS, "state");
    flag(ARKStepSVtolerances(mem, RTOL, atol), "tolerances");
    flag(ARKStepSetUserData(mem, ad), "user data");
    flag(ARKStepSetMaxNumSteps(mem, 100000), "max steps");
    flag(ARKStepSetStopTime(mem, T_END), "stop time");
    flag(ARKStepEvolve(mem, T_END, y, &t, ARK_NORMAL), "ARKStepEvolve");
    ARKStepGetNumSteps(mem, &steps);
    ARKStepGetNumMassIters(mem, iters);
    ARKStepFree(&mem);
  } else {
    mem = ERKStepCreate(mfree_sundials_rhs, 0.0, y, sunctx);
    flag(ERKStepSVtolerances(mem, RTOL, atol), "tolerances");
    flag(ERKStepSetUserData(mem, ad), "user data");
    flag(ERKStepSetMaxNumSteps(mem, 100000), "max steps");
    flag(ERKStepSetStopTime(mem, T_END), "stop time");
    flag(ERKStepEvolve(mem, T_END, y, &t, ARK_NORMAL), "ERKStepEvolve");
    ERKStepGetNumSteps(mem, &steps);
    ERKStepFree(&mem);
  }
  CHECK(t == T_END, "t %.17g", t);
  if (n_owned > 0) memcpy(yout, N_VGetArrayPointer(y), sizeof(double) * 2 * (size_t)n_owned);
  if (LS) SUNLinSolFree(LS);
  N_VDestroy(atol);
  N_VDestroy(y);
  mfree_sundials_destroy(&ad);
  return steps;
}

/* u, v by global id after T_END; the step count (and *iters the mass solver's). */
static long run(mfree_context_t *ctx, SUNContext sunctx, MPI_Comm comm, int how, int mass, int consistent, double *u,
                double *v, long *iters) {
  mpibar_t b;
  CHECK(mpibar_make_kind(&b, ctx, comm, N, how, BAR_KIND) == MFREE_SUCCESS, "bar, decomposition %d", how);
  double *y = calloc(2 * (size_t)b.n_owned + 1, sizeof(double));
  const long steps = evolve(ctx, sunctx, comm, b.sys, b.n_owned, mass, consistent, y, iters);
  mpibar_collect(&b, y, 1, u);
  mpibar_collect(&b, y + b.n_owned, 1, v);
  free(y);
  mpibar_free(&b);
  return steps;
}

#if MASS_CONSISTENT
static double max_diff(const double *a, const double *b, int n) {
  double m = 0.0;
  for (int i = 0; i < n; ++i) m = fmax(m, fabs(a[i] - b[i]));
  return m;
}
#endif

static void same_bits(const double *a, const double *b, const char *what, int how, int mass) {
  for (int i = 0; i < N; ++i)
    if (memcmp(&a[i], &b[i], sizeof(double)) != 0) {
      CHECK(0, "%s, decomposition %d: %s of particle %d: %.17g, one rank %.17g", mass ? "ARKStep" : "ERKStep", how,
            what, i, a[i], b[i]);
      return;
    }
}

int main(int argc, char **argv) {
  int rank = 0, size = 1;
  mfree_context_t *ctx = mpitest_start(&argc, &argv, &rank, &size);
  SUNContext sunctx = NULL;
  MPI_Comm world = MPI_COMM_WORLD, self = MPI_COMM_SELF;
  SUNContext self_ctx = NULL;
  SUNContext_Create(&world, &sunctx);
  SUNContext_Create(&self, &self_ctx);
  static double u1[N], v1[N], u[N], v[N];

  for (int mass = MASS_CONSISTENT; mass <= 1; ++mass) {
    long it1 = 0, it = 0;
    const long s1 = run(ctx, self_ctx, MPI_COMM_SELF, BAR_SLAB, mass, MASS_CONSISTENT, u1, v1, &it1);
    /* (the ends are boundary unknowns: their entries of y stay 0) */
    CHECK(u1[N - 3] < -1e-7 || MASS_CONSISTENT, "the pulse moved the particles near the loaded end: %g", u1[N - 3]);
    const int hows[3] = {BAR_SLAB, BAR_HASHED, BAR_LAST};
    for (int k = 0; k < 3; ++k) {
      const long s = run(ctx, sunctx, MPI_COMM_WORLD, hows[k], mass, MASS_CONSISTENT, u, v, &it);
      CHECK(s == s1 && it == it1, "%s, decomposition %d: %ld steps, %ld mass iterations; one rank %ld, %ld",
            mass ? "ARKStep" : "ERKStep", hows[k], s, it, s1, it1);
      same_bits(u, u1, "displacement", hows[k], mass);
      same_bits(v, v1, "velocity", hows[k], mass);
    }
#if MASS_CONSISTENT
    /* the one-process consistent system; the lumped mass on one rank */
    serialbar_t sb;
    static double ys[2 * N], ul[N], vl[N];
    long its = 0, itl = 0;
    CHECK(serialbar_make_mass(&sb, ctx, N, BAR_KIND, MFREE_FORM_MASS) == MFREE_SUCCESS, "serial bar");
    const long ss = evolve(ctx, self_ctx, MPI_COMM_SELF, sb.sys, N, 1, 1, ys, &its);
    serialbar_free(&sb);
    run(ctx, self_ctx, MPI_COMM_SELF, BAR_SLAB, 1, 0, ul, vl, &itl);
    double scale = 0.0;
    for (int i = 0; i < N; ++i) scale = fmax(scale, fabs(ys[i]));
    const double dser = max_diff(u1, ys, N), dlum = max_diff(ul, ys, N);
    CHECK(ys[N - 1] < -1e-7, "the pulse moved the loaded end: %g", ys[N - 1]);
    CHECK(dser <= 1e-4 * scale, "one rank vs one process: %.3e of %.3e", dser, scale);
    CHECK(dlum > 1e-4 * scale, "the lumped run is as close to the consistent one: %.3e of %.3e", dlum, scale);
    CHECK(it1 > s1, "%ld mass-solver iterations in %ld steps", it1, s1);
    if (rank == 0)
      printf("%.4s: ARKStep + PCG consistent mass %ld steps, %ld PCG iterations; one process %ld steps, %ld "
             "iterations; |u - u_serial| %.2e, |u_lumped - u_serial| %.2e of %.3e m, compared on %d ranks\n",
             TEST_NAME, s1, it1, ss, its, dser, dlum, scale, size);
#else
    if (rank == 0)
      printf("%.4s: %s %ld steps, displacement near the loaded end %.6e m, compared on %d ranks\n", TEST_NAME, mass ? "ARKStep + PCG mass" : "ERKStep",
             s1, u1[N - 3], size);
#endif
  }

  /* the exact sum: 1e16 + 1 - 1e16 and friends, spread over the ranks in two ways */
  enum { M = 1000 };
  static double vals[M];
  for (int i = 0; i < M; ++i) vals[i] = (i % 3 == 0 ? 1e16 : 1.0) * (i % 2 ? -1.0 : 1.0) * (1.0 + i * 1e-3);
  double exact = 0.0, s0 = 0.0, s1 = 0.0;
  CHECK(mfree_sundials_mpi_sum(ctx, MPI_COMM_SELF, vals, M, &exact) == MFREE_SUCCESS, "sum on one rank");
  const int lo = M * rank / size, hi = M * (rank + 1) / size;
  CHECK(mfree_sundials_mpi_sum(ctx, MPI_COMM_WORLD, vals + lo, hi - lo, &s0) == MFREE_SUCCESS, "sum, slabs");
  double mine[M];
  int nm = 0;
  for (int i = M - 1; i >= 0; --i)
    if (i % size == (size - 1 - rank)) mine[nm++] = vals[i];
  CHECK(mfree_sundials_mpi_sum(ctx, MPI_COMM_WORLD, mine, nm, &s1) == MFREE_SUCCESS, "sum, scattered");
  CHECK(memcmp(&exact, &s0, sizeof exact) == 0 && memcmp(&exact, &s1, sizeof exact) == 0,
        "exact sums %.17g %.17g %.17g", exact, s0, s1);
  /* the exact value: the pairs cancel but for the 1 + i 1e-3 scale factors */
  long double ref = 0.0L;
  for (int i = 0; i < M; ++i) ref += (long double)vals[i];
  CHECK(fabs(exact - (double)ref) <= 1e-3 * fabs((double)ref) + 1.0, "sum %.17g, long double %.17Lg", exact, ref);
  /* bad input, on every rank alike */
  CHECK(mfree_sundials_mpi_sum(ctx, MPI_COMM_WORLD, vals, rank == size - 1 ? -1 : 1, &s0) == MFREE_ERR_ARG,
        "negative count on one rank");
  CHECK(mfree_sundials_mpi_sum(ctx, MPI_COMM_WORLD, rank == 0 ? NULL : vals, 1, &s0) == MFREE_ERR_NULL,
        "NULL values on rank 0");
  CHECK(mfree_sundials_mpi_sum(NULL, MPI_COMM_WORLD, vals, 1, &s0) == MFREE_ERR_NULL, "NULL context everywhere");
  /* a NULL context on one rank takes part in the reduction: every rank fails, none waits */
  CHECK(mfree_sundials_mpi_sum(rank == size - 1 ? NULL : ctx, MPI_COMM_WORLD, vals, 1, &s0) == MFREE_ERR_NULL,
        "NULL context on the last rank");
  N_Vector ser = N_VNew_Serial(4, sunctx);
  CHECK(mfree_sundials_mpi_set_reproducible(ctx, ser) == MFREE_ERR_UNSUPPORTED, "a serial vector");
  CHECK(mfree_sundials_mpi_set_reproducible(ctx, NULL) == MFREE_ERR_NULL, "NULL vector");
  N_VDestroy(ser);
  N_Vector y = NULL;
  CHECK(mfree_sundials_mpi_create_vector(ctx, NULL, MPI_COMM_WORLD, sunctx, &y) == MFREE_ERR_NULL && !y,
        "NULL system");
  /* (with the old early return the other ranks waited in the reduction) */
  CHECK(mfree_sundials_mpi_create_vector(rank == size - 1 ? NULL : ctx, NULL, MPI_COMM_WORLD, sunctx, &y) ==
                MFREE_ERR_NULL && !y,
        "NULL context on the last rank");

  SUNContext_Free(&self_ctx);
  SUNContext_Free(&sunctx);
  mfree_context_destroy(&ctx);
  const int rc = mpitest_finish(TEST_NAME);
  MPI_Finalize();
  return rc;
}
