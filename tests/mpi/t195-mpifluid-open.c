/* Open boundaries of the fluid on ranks (label mpi): a channel between two walls (gravity
 * on), an inflow gate of six points at x = 0 injecting water at U = 1 m/s into a capacity
 * of 300 particles, all dormant at first (spread far upstream), and an outflow plane at
 * x = 0.155 m, run for 0.3 s in three windows of 0.1 s with leap-frog (or the
 * predictor-corrector: argument "pc"). The one-process fluid (mfree_system_create_fluid)
 * is the reference. On 1, 2 and 4 ranks, owners by id modulo the ranks (so that each
 * injected row is spread over them), a ghost layer a quarter spacing deeper than two
 * support radii, and a migration between windows (Zoltan RCB, then HSFC): after every
 * window the steps and the time are the reference's, every particle's state (dormant,
 * fluid, buffer: mfree_system_get_active on its owner) is the reference's for the same
 * global id, every owned particle's position, velocity and density the reference's bit
 * for bit, and the gate's and the plane's counts and masses the reference's bit for bit.
 * So the injected particles' global ids are the one-process capacity indices on any
 * number of ranks. At the end the right-hand side (mfree_system_rhs) of every owned
 * particle is the reference's bit for bit, and so are the pressures, the interpolated
 * velocities, the walls' force on each wall particle, the lumped and consistent mass
 * products (mfree_system_apply_mass), the lumped mass matrix's product and every row of
 * the interpolation matrix (its entries by column id); the walls' total
 * force agrees to rounding (4e-12 of the fluid's weight: exact sums on ranks) and is not
 * zero. A host's own integration (the midpoint rule on the right-hand side, the boundaries
 * updated between windows, as a SUNDIALS host integrates) is bitwise the one-process
 * host's too (in the leap-frog run). The run is not trivial: rows went in and out
 * (180 in, 91 out by 0.3 s on one process) and particles moved between ranks. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpimove.h"
#include "mpitest.h"

enum { N = 300, WINDOWS = 3 };
/* the mass of an injected particle, rho d W / 6 (mpifluid_channel, mpifluid_open) */
static const double RHO_D2_6 = 1000.0 * 0.01 * 0.06 / 6.0;

typedef struct {
  int64_t steps, in, out;
  double t, min, mout;
  double *y;     /* 5 N */
  int32_t *state; /* N */
} snap_t;

static mfree_status_t totals(mfree_system_t *sys, snap_t *s) {
  mfree_status_t st = mfree_system_get_inflow(sys, 0, &s->in, &s->min);
  if (st == MFREE_SUCCESS) st = mfree_system_get_outflow(sys, 0, &s->out, &s->mout);
  return st;
}

/* A host's own integration, as a SUNDIALS host's: the midpoint rule on mfree_system_rhs, the
 * open boundaries updated between windows of d / (4 U) (eight steps each), to 0.05 s, on
 * the one-process fluid and on the ranks (owners owner): every owned particle's state and
 * the gate's count and mass bitwise the one-process run's. */
static void host_windows(mfree_context_t *ctx, const damb_t *b, const int *owner) {
  enum { STEPS = 8, WINS = 20 };
  const double dt = b->d / 4.0 / STEPS;
  mfree_system_t *one = NULL;
  rankfluid_t r;
  double *y1 = malloc(5 * (size_t)N * sizeof *y1), *f1 = malloc(5 * (size_t)N * sizeof *f1), t = 0.0;
  memcpy(y1, b->y, 5 * (size_t)N * sizeof *y1);
  mfree_status_t st = mfree_system_create_fluid(ctx, 2, N, &one);
  if (st == MFREE_SUCCESS) st = damb_configure(b, one);
  if (st == MFREE_SUCCESS) st = mfree_system_set_masses(one, b->m, 1);
  if (st == MFREE_SUCCESS) st = mpifluid_open(one, 0.0);
  if (st == MFREE_SUCCESS) st = rankfluid_make(&r, ctx, MPI_COMM_WORLD, b, owner, 4.0 * b->h + 0.25 * b->d, 0);
  if (st == MFREE_SUCCESS) st = mpifluid_open(r.sys, 0.0);
  const size_t ny = 5 * (size_t)r.n_owned;
  double *f = malloc((ny + 1) * sizeof *f), *h = malloc((ny + 1) * sizeof *h);
  double *h1 = malloc(5 * (size_t)N * sizeof *h1);
  if (st == MFREE_SUCCESS) st = mfree_system_update_open_boundaries(one, t, y1);
  if (st == MFREE_SUCCESS) st = mfree_system_update_open_boundaries(r.sys, t, r.y);
  for (int w = 0; w < WINS && st == MFREE_SUCCESS; ++w) {
    for (int k = 0; k < STEPS && st == MFREE_SUCCESS; ++k) { /* the midpoint rule */
      st = mfree_system_rhs(one, t, y1, f1);
      if (st == MFREE_SUCCESS) st = mfree_system_rhs(r.sys, t, r.y, f);
      for (size_t q = 0; q < 5 * (size_t)N; ++q) h1[q] = y1[q] + 0.5 * dt * f1[q];
      for (size_t q = 0; q < ny; ++q) h[q] = r.y[q] + 0.5 * dt * f[q];
      if (st == MFREE_SUCCESS) st = mfree_system_rhs(one, t + 0.5 * dt, h1, f1);
      if (st == MFREE_SUCCESS) st = mfree_system_rhs(r.sys, t + 0.5 * dt, h, f);
      for (size_t q = 0; q < 5 * (size_t)N; ++q) y1[q] += dt * f1[q];
      for (size_t q = 0; q < ny; ++q) r.y[q] += dt * f[q];
      t = (w * STEPS + k + 1) * dt;
    }
    if (st == MFREE_SUCCESS) st = mfree_system_update_open_boundaries(one, t, y1);
    if (st == MFREE_SUCCESS) st = mfree_system_update_open_boundaries(r.sys, t, r.y);
  }
  CHECK(st == MFREE_SUCCESS, "host windows: status %d: %s", (int)st, mpifluid_error(ctx));
  int first = -1;
  CHECK(mpimove_differs(&r, r.y, y1, N, &first) == 0, "host windows: id %d differs from the one-process run", first);
  snap_t s1, s;
  if (st == MFREE_SUCCESS) st = totals(one, &s1);
  if (st == MFREE_SUCCESS) st = totals(r.sys, &s);
  CHECK(st == MFREE_SUCCESS && s.in == s1.in && s.min == s1.min && s.in >= 6 * 4,
        "host windows: %lld in (%.17g kg), one process %lld (%.17g)", (long long)s.in, s.min, (long long)s1.in, s1.min);
  free(y1), free(f1), free(f), free(h), free(h1);
  rankfluid_free(&r);
  mfree_system_destroy(&one);
}

int main(int argc, char **argv) {
  int rank = 0, size = 1;
  mfree_context_t *ctx = mpitest_start(&argc, &argv, &rank, &size);
  const mfree_integrator_t scheme =
      argc > 1 && !strcmp(argv[1], "pc") ? MFREE_INTEGRATOR_PREDICTOR_CORRECTOR : MFREE_INTEGRATOR_LEAPFROG;
  damb_t b;
  mpifluid_channel(&b, N);

  /* the reference: the one-process fluid with the capacity */
  snap_t ref[WINDOWS];
  mfree_system_t *one = NULL;
  double *y1 = malloc(5 * (size_t)N * sizeof *y1), t = 0.0;
  memcpy(y1, b.y, 5 * (size_t)N * sizeof *y1);
  mfree_status_t st = mfree_system_create_fluid(ctx, 2, N, &one);
  if (st == MFREE_SUCCESS) st = damb_configure(&b, one);
  if (st == MFREE_SUCCESS) st = mfree_system_set_masses(one, b.m, 1);
  if (st == MFREE_SUCCESS) st = mpifluid_open(one, 0.0);
  for (int w = 0; w < WINDOWS; ++w) {
    ref[w].y = malloc(5 * (size_t)N * sizeof(double));
    ref[w].state = malloc((size_t)N * sizeof(int32_t));
    int32_t na = 0;
    if (st == MFREE_SUCCESS)
      st = mfree_system_integrate(one, scheme, y1, &t, 0.1 * (w + 1), 0.5, 0.0, NULL, NULL, &ref[w].steps);
    if (st == MFREE_SUCCESS) st = mfree_system_get_active(one, &na, N, ref[w].state);
    if (st == MFREE_SUCCESS) st = totals(one, &ref[w]);
    ref[w].t = t;
    memcpy(ref[w].y, y1, 5 * (size_t)N * sizeof(double));
  }
  CHECK(st == MFREE_SUCCESS, "one process: status %d: %s", (int)st, mpifluid_error(ctx));
  /* 30 rows in; about 15 out (15 in the free jet of t740, the walls and gravity here) */
  CHECK(ref[WINDOWS - 1].in == 180 && ref[WINDOWS - 1].out >= 84 && ref[WINDOWS - 1].out <= 96,
        "one process: %lld in, %lld out",
        (long long)ref[WINDOWS - 1].in, (long long)ref[WINDOWS - 1].out);
  double *rate1 = malloc(5 * (size_t)N * sizeof *rate1), *p1 = malloc((size_t)N * sizeof *p1);
  if (st == MFREE_SUCCESS) st = mfree_system_rhs(one, t, y1, rate1);
  if (st == MFREE_SUCCESS) st = mfree_system_get_pressure(one, y1, p1);
  /* a vector for the mass products: particle g's unknowns 1 + g / 1000 + c / 10 */
  double *u1 = malloc(5 * (size_t)N * sizeof *u1), *Mu1 = malloc(10 * (size_t)N * sizeof *Mu1);
  for (int g = 0; g < N; ++g) {
    for (int c = 0; c < 2; ++c) {
      u1[2 * g + c] = 1.0 + g / 1000.0 + c / 10.0;
      u1[2 * N + 2 * g + c] = 1.0 + g / 1000.0 + (c + 2) / 10.0;
    }
    u1[4 * N + g] = 1.0 + g / 1000.0 + 0.4;
  }
  if (st == MFREE_SUCCESS) st = mfree_system_apply_mass(one, y1, 0, u1, Mu1);
  if (st == MFREE_SUCCESS) st = mfree_system_apply_mass(one, y1, 1, u1, Mu1 + 5 * (size_t)N);
  mfree_matrix_t *S1 = NULL;
  if (st == MFREE_SUCCESS) st = mfree_system_assemble_interpolation(one, y1, &S1);
  double *v1 = malloc(2 * (size_t)N * sizeof *v1), *pw1 = malloc(2 * ((size_t)b.nwall + 1) * sizeof *pw1), f1[2];
  if (st == MFREE_SUCCESS) st = mfree_system_get_velocity(one, y1, v1);
  if (st == MFREE_SUCCESS) st = mfree_system_get_wall_force(one, y1, f1, b.nwall, pw1);

  /* on the ranks */
  int *owner = malloc((size_t)N * sizeof *owner);
  for (int i = 0; i < N; ++i) owner[i] = i % size;
  const double width = 4.0 * b.h + 0.25 * b.d;
  rankfluid_t r;
  if (st == MFREE_SUCCESS) st = rankfluid_make(&r, ctx, MPI_COMM_WORLD, &b, owner, width, 0);
  if (st == MFREE_SUCCESS) st = mpifluid_open(r.sys, 0.0);
  CHECK(st == MFREE_SUCCESS, "system on the ranks: status %d: %s", (int)st, mpifluid_error(ctx));
  double *y = malloc(5 * (size_t)N * sizeof *y);
  if (st == MFREE_SUCCESS) memcpy(y, r.y, 5 * (size_t)r.n_owned * sizeof *y);
  mfree_migration_t *mig = NULL;
  if (st == MFREE_SUCCESS) st = mfree_migration_create(ctx, MPI_COMM_WORLD, 2, &mig);
  const int32_t method[WINDOWS - 1] = {MFREE_PARTITIONER_RCB, MFREE_PARTITIONER_HSFC};
  int64_t moved = 0;
  int32_t no = 0;
  int64_t *id = malloc(((size_t)N + 1) * sizeof *id);
  int32_t *state = malloc(((size_t)N + 1) * sizeof *state);
  t = 0.0;
  for (int w = 0; w < WINDOWS && st == MFREE_SUCCESS; ++w) {
    int64_t steps = 0;
    st = mfree_system_integrate(r.sys, scheme, y, &t, 0.1 * (w + 1), 0.5, 0.0, NULL, NULL, &steps);
    CHECK(st == MFREE_SUCCESS, "window %d: integrate status %d: %s", w, (int)st, mpifluid_error(ctx));
    CHECK(steps == ref[w].steps && t == ref[w].t, "window %d: %lld steps to t = %.17g, one process %lld to %.17g", w,
          (long long)steps, t, (long long)ref[w].steps, ref[w].t);
    int first = -1;
    const int bad = mpimove_differs(&r, y, ref[w].y, N, &first);
    CHECK(bad == 0, "window %d: %d owned particles differ from the one-process fluid's (first: id %d)", w, bad, first);
    mfree_halo_get_size(r.halo, &no, NULL);
    mfree_halo_get_global_ids(r.halo, id);
    int32_t na = 0, na_ref = 0, na_all = 0, wrong = 0;
    if (st == MFREE_SUCCESS) st = mfree_system_get_active(r.sys, &na, no, state);
    for (int k = 0; k < no; ++k) {
      wrong += state[k] != ref[w].state[id[k]];
      na_ref += ref[w].state[id[k]] != MFREE_PARTICLE_DORMANT;
    }
    MPI_Allreduce(&na, &na_all, 1, MPI_INT32_T, MPI_SUM, MPI_COMM_WORLD);
    CHECK(wrong == 0 && na == na_ref, "window %d: %d owned states differ, %d active (one process %d)", w, (int)wrong,
          (int)na, (int)na_ref);
    snap_t s;
    if (st == MFREE_SUCCESS) st = totals(r.sys, &s);
    CHECK(s.in == ref[w].in && s.out == ref[w].out && s.min == ref[w].min && s.mout == ref[w].mout,
          "window %d: %lld in (%.17g kg), %lld out (%.17g kg); one process %lld (%.17g), %lld (%.17g)", w,
          (long long)s.in, s.min, (long long)s.out, s.mout, (long long)ref[w].in, ref[w].min, (long long)ref[w].out,
          ref[w].mout);
    if (w == WINDOWS - 1 || st != MFREE_SUCCESS) break;
    /* the particles to the owners of a Zoltan partition */
    char *was = calloc((size_t)N, 1);
    for (int k = 0; k < no; ++k) was[id[k]] = 1;
    int64_t neq = -1, received = 0, all = 0;
    st = mfree_migration_set_partitioner(mig, method[w], 1.05);
    if (st == MFREE_SUCCESS) st = mfree_halo_migrate_fluid(r.halo, mig, r.sys, 1, y, 5 * (int64_t)N, &neq);
    CHECK(st == MFREE_SUCCESS, "migration %d: status %d: %s", w, (int)st, mpifluid_error(ctx));
    mfree_halo_get_size(r.halo, &no, NULL);
    mfree_halo_get_global_ids(r.halo, id);
    for (int k = 0; k < no; ++k) received += !was[id[k]];
    MPI_Allreduce(&received, &all, 1, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
    moved += all;
    free(was);
  }
  CHECK(size == 1 || moved > 0, "no particle moved between ranks");
  /* the rates and pressures at the end */
  double *rate = malloc(5 * ((size_t)no + 1) * sizeof *rate), *p = malloc(((size_t)no + 1) * sizeof *p);
  if (st == MFREE_SUCCESS) st = mfree_system_rhs(r.sys, t, y, rate);
  CHECK(st == MFREE_SUCCESS, "rhs: status %d: %s", (int)st, mpifluid_error(ctx));
  int first = -1;
  CHECK(mpimove_differs(&r, rate, rate1, N, &first) == 0, "rates differ from the one-process fluid's (first: id %d)",
        first);
  if (st == MFREE_SUCCESS) st = mfree_system_get_pressure(r.sys, y, p);
  int wrong = 0;
  for (int k = 0; k < no; ++k) wrong += memcmp(&p[k], &p1[id[k]], sizeof *p) != 0;
  CHECK(st == MFREE_SUCCESS && wrong == 0, "pressures: status %d, %d differ", (int)st, wrong);
  /* the interpolated velocities bitwise; the walls' force per wall particle bitwise, its
     total to rounding (exact sums on ranks: docs/fluid-ranks.md) */
  double *vel = malloc(2 * ((size_t)no + 1) * sizeof *vel), *pw = malloc(2 * ((size_t)b.nwall + 1) * sizeof *pw), f[2];
  if (st == MFREE_SUCCESS) st = mfree_system_get_velocity(r.sys, y, vel);
  wrong = 0;
  for (int k = 0; k < no; ++k) wrong += memcmp(&vel[2 * k], &v1[2 * id[k]], 2 * sizeof *vel) != 0;
  CHECK(st == MFREE_SUCCESS && wrong == 0, "velocities: status %d, %d differ: %s", (int)st, wrong, mpifluid_error(ctx));
  if (st == MFREE_SUCCESS) st = mfree_system_get_wall_force(r.sys, y, f, b.nwall, pw);
  CHECK(st == MFREE_SUCCESS && mpitest_same_bits(pw, pw1, 2 * (int64_t)b.nwall, "force per wall particle"),
        "wall force: status %d: %s", (int)st, mpifluid_error(ctx));
  const double weight = ref[WINDOWS - 1].min - ref[WINDOWS - 1].mout + 18 * RHO_D2_6 * 9.81;
  CHECK(fabs(f[0] - f1[0]) <= 4e-12 * weight && fabs(f[1] - f1[1]) <= 4e-12 * weight && fabs(f1[1]) > 1e-3 * weight,
        "the walls' force (%.17g, %.17g), one process (%.17g, %.17g)", f[0], f[1], f1[0], f1[1]);
  /* the lumped and consistent mass products, and the lumped mass matrix's, bitwise */
  double *u = malloc(5 * ((size_t)no + 1) * sizeof *u), *Mu = malloc(5 * ((size_t)no + 1) * sizeof *Mu);
  for (int k = 0; k < no; ++k) {
    for (int c = 0; c < 2; ++c) {
      u[2 * k + c] = u1[2 * id[k] + c];
      u[2 * no + 2 * k + c] = u1[2 * N + 2 * id[k] + c];
    }
    u[4 * no + k] = u1[4 * N + id[k]];
  }
  for (int consistent = 0; consistent < 2 && st == MFREE_SUCCESS; ++consistent) {
    st = mfree_system_apply_mass(r.sys, y, consistent, u, Mu);
    CHECK(st == MFREE_SUCCESS && mpimove_differs(&r, Mu, Mu1 + 5 * (size_t)N * consistent, N, &first) == 0,
          "mass products (consistent %d): status %d, first id %d differs: %s", consistent, (int)st, first,
          mpifluid_error(ctx));
  }
  mfree_matrix_t *M = NULL;
  if (st == MFREE_SUCCESS) st = mfree_system_assemble_mass(r.sys, y, 0, &M);
  const int64_t *rp = NULL;
  const int32_t *col = NULL;
  const double *val = NULL;
  if (st == MFREE_SUCCESS) st = mfree_matrix_get_csr(M, &rp, &col, &val);
  CHECK(st == MFREE_SUCCESS, "lumped mass matrix: status %d: %s", (int)st, mpifluid_error(ctx));
  for (int q = 0; q < 5 * no && st == MFREE_SUCCESS; ++q) {
    double sum = 0.0;
    for (int64_t e = rp[q]; e < rp[q + 1]; ++e) sum += val[e] * u[col[e]];
    Mu[q] = sum;
  }
  CHECK(st != MFREE_SUCCESS || mpimove_differs(&r, Mu, Mu1, N, &first) == 0,
        "the lumped mass matrix's product: id %d differs", first);
  mfree_matrix_destroy(&M);
  free(u), free(Mu), free(u1), free(Mu1);
  /* the interpolation matrix: every owned row's entries (column id, value) bitwise the
     one-process row's (its columns the host's items: owned, then ghosts) */
  const int64_t *rp1 = NULL;
  const int32_t *col1 = NULL;
  const double *val1 = NULL;
  mfree_matrix_t *S = NULL;
  if (st == MFREE_SUCCESS) st = mfree_matrix_get_csr(S1, &rp1, &col1, &val1);
  if (st == MFREE_SUCCESS) st = mfree_system_assemble_interpolation(r.sys, y, &S);
  int32_t ng = 0; /* the host's items after the call (it may rebuild the ghosts) */
  mfree_halo_get_size(r.halo, &no, &ng);
  int64_t *items = malloc(((size_t)no + ng + 1) * sizeof *items);
  mfree_halo_get_global_ids(r.halo, items);
  if (st == MFREE_SUCCESS) st = mfree_matrix_get_csr(S, &rp, &col, &val);
  CHECK(st == MFREE_SUCCESS, "interpolation: status %d: %s", (int)st, mpifluid_error(ctx));
  wrong = 0;
  for (int k = 0; k < no && st == MFREE_SUCCESS; ++k) {
    const int64_t g = items[k], len = rp[k + 1] - rp[k];
    int same = len == rp1[g + 1] - rp1[g];
    for (int64_t e = 0; e < len && same; ++e) { /* the one-process row's entry of the same column id */
      int64_t f = rp1[g];
      while (f < rp1[g + 1] && col1[f] != items[col[rp[k] + e]]) ++f;
      same = f < rp1[g + 1] && !memcmp(&val[rp[k] + e], &val1[f], sizeof *val);
    }
    wrong += !same;
  }
  CHECK(wrong == 0, "interpolation: %d owned rows differ from the one-process fluid's", wrong);
  mfree_matrix_destroy(&S);
  mfree_matrix_destroy(&S1);
  free(items);
  if (scheme == MFREE_INTEGRATOR_LEAPFROG) host_windows(ctx, &b, owner); /* (no scheme of ours) */
  free(vel), free(pw), free(v1), free(pw1), free(rate), free(p), free(rate1), free(p1);
  free(y), free(y1), free(id), free(state), free(owner);
  for (int w = 0; w < WINDOWS; ++w) free(ref[w].y), free(ref[w].state);
  mfree_migration_destroy(&mig);
  rankfluid_free(&r);
  mfree_system_destroy(&one);
  damb_free(&b);
  mfree_context_destroy(&ctx);
  const int rc = mpitest_finish("t195-mpifluid-open");
  MPI_Finalize();
  return rc;
}
