/* The elastodynamic bar of paper 001 Sect. 6.4 on 1-4 ranks (label mpi), native central
 * differences: the displacements, velocities and stresses of every particle (matched by
 * global id) are bitwise those of the one-rank run (the same system on MPI_COMM_SELF),
 * for contiguous slabs, slabs in reverse rank order, scattered owners (a hash of the id)
 * and everything on the last rank (the others hold no particle and still take part);
 * the one-rank run is bitwise the serial system's (t703: the paper's wave speed and
 * amplitude), so the same holds for it. The step count and the time agree too. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpibar.h"
#include "mpitest.h"

enum { N = 400 };
static const double T_END = 8e-6; /* before the reflection (transit time 19.8 us) */

/* y (displacements, velocities) and stresses by global id after T_END; the step count. */
static int64_t run(mfree_context_t *ctx, MPI_Comm comm, int how, double *u, double *v, double *sig) {
  mpibar_t b;
  CHECK(mpibar_make(&b, ctx, comm, N, how) == MFREE_SUCCESS, "bar on ranks, decomposition %d", how);
  int32_t neq = -1, n = -1, dim = -1;
  CHECK(mfree_system_get_size(b.sys, &neq) == MFREE_SUCCESS && neq == 2 * b.n_owned, "neq %d", (int)neq);
  CHECK(mfree_system_get_dimension(b.sys, &dim, &n) == MFREE_SUCCESS && n == b.n_owned && dim == 1, "n %d", (int)n);
  double *y = calloc((size_t)neq + 1, sizeof(double)), *s = calloc((size_t)b.n_owned + 1, sizeof(double));
  double t = 0.0;
  int64_t steps = 0;
  const mfree_status_t st =
      mfree_system_integrate(b.sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, T_END, 0.5, 0.0, NULL, NULL, &steps);
  char msg[400] = "";
  mfree_context_get_last_error(ctx, NULL, msg, sizeof msg);
  CHECK(st == MFREE_SUCCESS, "integrate: %d %s", (int)st, msg);
  CHECK(t == T_END, "t %.17g", t);
  CHECK(mfree_system_get_stress(b.sys, t, y, s) == MFREE_SUCCESS, "stress");
  mpibar_collect(&b, y, 1, u);
  mpibar_collect(&b, y + b.n_owned, 1, v);
  mpibar_collect(&b, s, 1, sig);
  free(y);
  free(s);
  mpibar_free(&b);
  return steps;
}

static int same_bits(const double *a, const double *b, int n, const char *what, int how) {
  for (int i = 0; i < n; ++i)
    if (memcmp(&a[i], &b[i], sizeof(double)) != 0) {
      CHECK(0, "decomposition %d: %s of particle %d: %.17g, one rank %.17g", how, what, i, a[i], b[i]);
      return 0;
    }
  return 1;
}

int main(int argc, char **argv) {
  int rank = 0, size = 1;
  mfree_context_t *ctx = mpitest_start(&argc, &argv, &rank, &size);
  static double u1[N], v1[N], s1[N], u[N], v[N], s[N];

  /* the one-rank run: the same system on this rank alone */
  const int64_t steps1 = run(ctx, MPI_COMM_SELF, BAR_SLAB, u1, v1, s1);

  /* ... is the serial system's, bit for bit (t703 checks its physics) */
  serialbar_t sb;
  CHECK(serialbar_make(&sb, ctx, N) == MFREE_SUCCESS, "serial bar");
  double *y = calloc(2 * N, sizeof(double)), t = 0.0, sig[N];
  int64_t steps = 0;
  CHECK(mfree_system_integrate(sb.sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, T_END, 0.5, 0.0, NULL, NULL, &steps) ==
            MFREE_SUCCESS,
        "serial integrate");
  CHECK(mfree_system_get_stress(sb.sys, t, y, sig) == MFREE_SUCCESS, "serial stress");
  CHECK(steps == steps1, "serial steps %lld, one rank %lld", (long long)steps, (long long)steps1);
  same_bits(y, u1, N, "serial displacement", -1);
  same_bits(y + N, v1, N, "serial velocity", -1);
  same_bits(sig, s1, N, "serial stress", -1);
  /* the pulse is there: the loaded end moved, the free end not yet */
  CHECK(u1[N - 1] < -1e-6 && fabs(u1[0]) < 1e-12, "end displacements %g %g", u1[N - 1], u1[0]);
  free(y);
  serialbar_free(&sb);

  /* the decompositions of MPI_COMM_WORLD */
  for (int how = BAR_SLAB; how <= BAR_LAST; ++how) {
    const int64_t st = run(ctx, MPI_COMM_WORLD, how, u, v, s);
    CHECK(st == steps1, "decomposition %d: %lld steps, one rank %lld", how, (long long)st, (long long)steps1);
    same_bits(u, u1, N, "displacement", how);
    same_bits(v, v1, N, "velocity", how);
    same_bits(s, s1, N, "stress", how);
  }
  if (rank == 0) printf("t162: %lld steps, end displacement %.6e m, compared on %d ranks\n", (long long)steps1, u1[N - 1], size);
  mfree_context_destroy(&ctx);
  const int rc = mpitest_finish("t162-mpi-elastodynamic-bar");
  MPI_Finalize();
  return rc;
}
