/* The fluid's outputs on ranks (label mpi): for the dam break of paper 003 (12 x 24
 * particles) at rest and after 40 leap-frog steps with 0.5 m/s downwards added to every
 * velocity, on 1-4 ranks (horizontal layers,
 * owners by a hash of the id, vertical slabs listed in reverse order):
 * - pressures (mfree_system_get_pressure), interpolated velocities
 *   (mfree_system_get_velocity) and the lumped masses of 003 eq 56
 *   (mfree_system_assemble_mass: identity rows for positions and densities, one diagonal
 *   entry per velocity row) of every owned particle, matched by global id, bitwise those
 *   of the system on one rank and of the one-process fluid (mfree_system_create_fluid);
 *   the lumped masses positive and summing to the particles' masses;
 * - the walls' total force (mfree_system_get_wall_force) the same bits on every rank and
 *   those of one rank (exact sums over the ranks); against the one-process fluid's
 *   (summed in particle order, rounded at every term) within 1e-12 of the sum of the
 *   terms' magnitudes; none at rest (003 eq 65's densities: no particle approaches a
 *   wall, the internal forces cancel), and the floor holding the column up when moving;
 * - each wall particle's force bitwise one rank's and the one-process fluid's (the rows'
 *   terms gathered and summed in global-id order), summing to the total; asked on one
 *   rank only, the total on the others;
 * - what is not distributed fails alike on every rank: the consistent mass
 *   (MFREE_ERR_UNSUPPORTED); a NULL output (MFREE_ERR_NULL) or a per_wall of the wrong size
 *   (MFREE_ERR_ARG) on one rank only. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpifluid.h"
#include "mpitest.h"

enum { LAYERS = 0, HASHED = 1, SLAB_REVERSED = 2, NDECOMP = 3 };
static const char *kName[NDECOMP] = {"layers", "hashed", "slabs, reversed local order"};

typedef struct {
  double *p, *vh, *ml; /* per particle by global id: pressure, v_hat (2), lumped mass */
  double total[2];
  double *per_wall; /* 2 per wall particle */
} outputs_t;

static void outputs_alloc(outputs_t *o, int n, int nwall) {
  o->p = calloc((size_t)n, sizeof(double));
  o->vh = calloc(2 * (size_t)n, sizeof(double));
  o->ml = calloc((size_t)n, sizeof(double));
  o->per_wall = calloc(2 * (size_t)nwall, sizeof(double));
}
static void outputs_free(outputs_t *o) { free(o->p), free(o->vh), free(o->ml), free(o->per_wall); }

/* The lumped masses of the velocity rows of M (no particles), checking the identity rows
   and the diagonal pattern. */
static void lumped_masses(const mfree_matrix_t *M, int no, double *ml) {
  const int64_t *ptr = NULL;
  const int32_t *idx = NULL;
  const double *val = NULL;
  CHECK(mfree_matrix_get_csr(M, &ptr, &idx, &val) == MFREE_SUCCESS, "csr");
  int bad = 0;
  for (int r = 0; r < 5 * no; ++r) {
    bad += ptr[r + 1] - ptr[r] != 1 || idx[ptr[r]] != r;
    const int k = (r - 2 * no) / 2;
    if (r < 2 * no || r >= 4 * no)
      bad += val[ptr[r]] != 1.0;
    else if ((r - 2 * no) % 2 == 0)
      ml[k] = val[ptr[r]];
    else
      bad += memcmp(&ml[k], &val[ptr[r]], sizeof(double)) != 0; /* the same mass on both components */
  }
  CHECK(bad == 0, "%d rows of the mass are not identity rows or one lumped mass per particle", bad);
}

/* Every output of the dam break b's state, by global id. owner NULL: the one-process
   fluid; else the system on the ranks of comm. */
static void run(mfree_context_t *ctx, MPI_Comm comm, const damb_t *b, const int *owner, int reverse, outputs_t *o) {
  const int n = b->n;
  rankfluid_t r;
  memset(&r, 0, sizeof r);
  mfree_system_t *sys = NULL;
  const double *y = b->y;
  int no = n;
  if (owner) {
    const mfree_status_t st = rankfluid_make(&r, ctx, comm, b, owner, 4.0 * b->h + 4.0 * b->d, reverse);
    CHECK(st == MFREE_SUCCESS, "system: status %d: %s", (int)st, mpifluid_error(ctx));
    sys = r.sys, y = r.y, no = r.n_owned;
  } else {
    CHECK(mfree_system_create_fluid(ctx, 2, n, &sys) == MFREE_SUCCESS && damb_configure(b, sys) == MFREE_SUCCESS &&
              mfree_system_set_masses(sys, b->m, 1) == MFREE_SUCCESS,
          "one-process fluid: %s", mpifluid_error(ctx));
  }
  double *p = malloc(((size_t)no + 1) * sizeof *p), *vh = malloc((2 * (size_t)no + 1) * sizeof *vh),
         *ml = malloc(((size_t)no + 1) * sizeof *ml);
  mfree_matrix_t *M = NULL;
  mfree_status_t st = mfree_system_get_pressure(sys, y, p);
  CHECK(st == MFREE_SUCCESS, "pressure: %d: %s", (int)st, mpifluid_error(ctx));
  st = mfree_system_get_velocity(sys, y, vh);
  CHECK(st == MFREE_SUCCESS, "velocity: %d: %s", (int)st, mpifluid_error(ctx));
  st = mfree_system_assemble_mass(sys, y, 0, &M);
  CHECK(st == MFREE_SUCCESS, "mass: %d: %s", (int)st, mpifluid_error(ctx));
  if (st == MFREE_SUCCESS) lumped_masses(M, no, ml);
  st = mfree_system_get_wall_force(sys, y, o->total, b->nwall, o->per_wall);
  CHECK(st == MFREE_SUCCESS, "wall force: %d: %s", (int)st, mpifluid_error(ctx));
  double total_again[2] = {0.0, 0.0};
  st = mfree_system_get_wall_force(sys, y, total_again, 0, NULL); /* the total alone: the same */
  CHECK(st == MFREE_SUCCESS && memcmp(total_again, o->total, sizeof total_again) == 0, "wall force total alone: %d",
        (int)st);
  if (owner) {
    mpifluid_collect(comm, no, r.id, p, 1, o->p);
    mpifluid_collect(comm, no, r.id, vh, 2, o->vh);
    mpifluid_collect(comm, no, r.id, ml, 1, o->ml);
    /* not distributed: every rank fails alike */
    double f[2], *per_wall = malloc(2 * (size_t)b->nwall * sizeof *per_wall);
    expect(ctx, mfree_system_assemble_mass(sys, y, 1, &M), MFREE_ERR_UNSUPPORTED, "consistent", "consistent mass");
    int rank = 0;
    MPI_Comm_rank(comm, &rank);
    /* the force per wall particle on rank 0 only, the total on the others: each its part */
    st = mfree_system_get_wall_force(sys, y, rank == 0 ? NULL : f, b->nwall, rank == 0 ? per_wall : NULL);
    CHECK(st == MFREE_SUCCESS, "per_wall on rank 0 alone: %d: %s", (int)st, mpifluid_error(ctx));
    if (rank == 0)
      CHECK(memcmp(per_wall, o->per_wall, 2 * (size_t)b->nwall * sizeof *per_wall) == 0, "per_wall on rank 0 alone");
    else
      CHECK(memcmp(f, o->total, sizeof f) == 0, "total without rank 0's");
    expect(ctx, mfree_system_get_wall_force(sys, y, f, rank == 0 ? b->nwall - 1 : b->nwall, per_wall), MFREE_ERR_ARG,
           "wall particles", "per_wall of the wrong size on rank 0");
    expect(ctx, mfree_system_get_velocity(sys, y, rank == 0 ? NULL : vh), MFREE_ERR_NULL, "NULL",
           "velocity output NULL on rank 0");
    expect(ctx, mfree_system_get_wall_force(sys, rank == 0 ? NULL : y, f, 0, NULL), MFREE_ERR_NULL, "NULL",
           "wall force state NULL on rank 0");
    free(per_wall);
    rankfluid_free(&r);
  } else {
    memcpy(o->p, p, (size_t)n * sizeof *p);
    memcpy(o->vh, vh, 2 * (size_t)n * sizeof *vh);
    memcpy(o->ml, ml, (size_t)n * sizeof *ml);
    mfree_system_destroy(&sys);
  }
  mfree_matrix_destroy(&M);
  free(p), free(vh), free(ml);
}

static int differ(const double *a, const double *b, int n) {
  int bad = 0;
  for (int i = 0; i < n; ++i) bad += memcmp(a + i, b + i, sizeof(double)) != 0;
  return bad;
}

int main(int argc, char **argv) {
  int rank = 0, size = 1;
  mfree_context_t *ctx = mpitest_start(&argc, &argv, &rank, &size);
  damb_t b;
  damb_make(&b, 12, 24);
  const int n = b.n;
  int *owner = calloc((size_t)n, sizeof *owner);
  outputs_t o0, o1, o;
  outputs_alloc(&o0, n, b.nwall), outputs_alloc(&o1, n, b.nwall), outputs_alloc(&o, n, b.nwall);
  double weight = 0.0;
  for (int q = 0; q < n; ++q) weight += b.m[q] * 9.81;
  for (int moved = 0; moved <= 1; ++moved) {
    if (moved) { /* 40 leap-frog steps of the one-process fluid: every particle moves */
      mfree_system_t *sys = NULL;
      double t = 0.0;
      int64_t want = 40, steps = 0;
      mfree_status_t st = mfree_system_create_fluid(ctx, 2, n, &sys);
      if (st == MFREE_SUCCESS) st = damb_configure(&b, sys);
      if (st == MFREE_SUCCESS) st = mfree_system_set_masses(sys, b.m, 1);
      if (st == MFREE_SUCCESS)
        st = mfree_system_integrate(sys, MFREE_INTEGRATOR_LEAPFROG, b.y, &t, 1.0, 0.5, 0.0, mpifluid_stop_at, &want,
                                    &steps);
      CHECK(st == MFREE_SUCCESS && steps == 40, "40 steps: %d, %lld steps", (int)st, (long long)steps);
      mfree_system_destroy(&sys);
      for (int q = 0; q < n; ++q) b.y[2 * (size_t)n + 2 * q + 1] -= 0.5; /* and all moving down onto the floor */
    }
    const char *when = moved ? "after 40 steps, moving down" : "at rest";
    run(ctx, MPI_COMM_SELF, &b, NULL, 0, &o0);
    run(ctx, MPI_COMM_SELF, &b, owner, 0, &o1);
    /* one rank against the one-process fluid */
    CHECK(differ(o1.p, o0.p, n) == 0, "%s: one rank's pressures differ from the one-process fluid's", when);
    CHECK(differ(o1.vh, o0.vh, 2 * n) == 0, "%s: one rank's velocities differ from the one-process fluid's", when);
    CHECK(differ(o1.ml, o0.ml, n) == 0, "%s: one rank's lumped masses differ from the one-process fluid's", when);
    CHECK(differ(o1.per_wall, o0.per_wall, 2 * b.nwall) == 0, "%s: one rank's force per wall particle differs from the "
          "one-process fluid's", when);
    double sx = 0.0, sy = 0.0;
    for (int w = 0; w < b.nwall; ++w) sx += o1.per_wall[2 * w], sy += o1.per_wall[2 * w + 1];
    /* without dummies the shares sum to the total */
    CHECK(fabs(sx - o1.total[0]) <= 1e-10 * weight && fabs(sy - o1.total[1]) <= 1e-10 * weight,
          "%s: per-wall sum (%.17g, %.17g), total (%.17g, %.17g)", when, sx, sy, o1.total[0], o1.total[1]);
    double scale = 0.0, msum = 0.0, mmin = INFINITY;
    for (int q = 0; q < n; ++q) scale += b.m[q] * 9.81, msum += o1.ml[q], mmin = fmin(mmin, o1.ml[q]);
    /* the lumped masses sum to the particle masses (the rows' partition of unity) */
    double mtotal = 0.0;
    for (int q = 0; q < n; ++q) mtotal += b.m[q];
    CHECK(mmin > 0.0 && fabs(msum - mtotal) <= 1e-10 * mtotal, "%s: lumped masses: min %g, sum %.15g, masses %.15g",
          when, mmin, msum, mtotal);
    for (int c = 0; c < 2; ++c)
      CHECK(fabs(o1.total[c] - o0.total[c]) <= 1e-12 * 4.0 * scale, "%s: wall force %d: one rank %.17g, one process %.17g",
            when, c, o1.total[c], o0.total[c]);
    /* at rest no particle approaches a wall (eq 123's switch) and the internal forces
       cancel: no force; moving down, the floor holds the column up */
    if (!moved)
      CHECK(fabs(o1.total[0]) <= 1e-10 * weight && fabs(o1.total[1]) <= 1e-10 * weight,
            "at rest: wall force (%g, %g), weight %g", o1.total[0], o1.total[1], weight);
    else
      CHECK(o1.total[1] > 0.01 * weight, "moving down: wall force (%g, %g), weight %g", o1.total[0], o1.total[1],
            weight);
    for (int how = 0; how < NDECOMP; ++how) {
      for (int i = 0; i < n; ++i) {
        const int layer = (int)(b.y[2 * i + 1] / (2.0 * b.a) * size), slab = (int)(b.y[2 * i] / b.a * size);
        owner[i] = how == HASHED ? (int)(mpitest_hash((uint64_t)i) % (uint64_t)size)
                                 : how == LAYERS ? (layer < 0 ? 0 : layer >= size ? size - 1 : layer)
                                                 : (slab < 0 ? 0 : slab >= size ? size - 1 : slab);
      }
      run(ctx, MPI_COMM_WORLD, &b, owner, how == SLAB_REVERSED, &o);
      CHECK(differ(o.p, o1.p, n) == 0, "%s, %s: %d pressures differ from one rank's", when, kName[how], differ(o.p, o1.p, n));
      CHECK(differ(o.vh, o1.vh, 2 * n) == 0, "%s, %s: %d velocity components differ from one rank's", when, kName[how],
            differ(o.vh, o1.vh, 2 * n));
      CHECK(differ(o.ml, o1.ml, n) == 0, "%s, %s: %d lumped masses differ from one rank's", when, kName[how],
            differ(o.ml, o1.ml, n));
      CHECK(differ(o.per_wall, o1.per_wall, 2 * b.nwall) == 0, "%s, %s: %d per-wall forces differ from one rank's", when,
            kName[how], differ(o.per_wall, o1.per_wall, 2 * b.nwall));
      CHECK(differ(o.total, o1.total, 2) == 0, "%s, %s: wall force (%.17g, %.17g), one rank (%.17g, %.17g)", when,
            kName[how], o.total[0], o.total[1], o1.total[0], o1.total[1]);
      double *all = malloc(2 * (size_t)size * sizeof *all);
      MPI_Allgather(o.total, 2, MPI_DOUBLE, all, 2, MPI_DOUBLE, MPI_COMM_WORLD);
      int ranks_differ = 0;
      for (int p = 1; p < size; ++p) ranks_differ += differ(all, all + 2 * p, 2) != 0;
      CHECK(ranks_differ == 0, "%s, %s: %d ranks' wall forces differ from rank 0's", when, kName[how], ranks_differ);
      free(all);
    }
    if (rank == 0)
      printf("t197 %s: wall force (%.6f, %.6f) N/m (one process (%.6f, %.6f)), weight %.6f N/m, %d ranks\n", when,
             o1.total[0], o1.total[1], o0.total[0], o0.total[1], weight, size);
    for (int i = 0; i < n; ++i) owner[i] = 0;
  }
  outputs_free(&o0), outputs_free(&o1), outputs_free(&o);
  free(owner);
  damb_free(&b);
  mfree_context_destroy(&ctx);
  const int rc = mpitest_finish("t197-mpi-fluid-outputs");
  MPI_Finalize();
  return rc;
}
