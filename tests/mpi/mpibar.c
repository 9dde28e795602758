#include "mpibar.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpitest.h"

static void traction(void *u, const double *x, double *v) {
  (void)u;
  v[0] = x[0] > 0.5 * BAR_L ? -1e9 : 0.0; /* right end: compressive; left end: free */
}

double mpibar_pulse(void *u, double t) {
  (void)u;
  return t <= BAR_T0 ? 1.0 : 0.0;
}

static int nan_rank = -1; /* the rank whose load history turns NaN after 1 us */
static double nan_history(void *u, double t) {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank == nan_rank && t > 1e-6) return NAN;
  return mpibar_pulse(u, t);
}

void mpibar_check_faults(mpibar_t *b, mfree_context_t *ctx, double *y, double *yd) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const int last = size - 1, neq = 2 * b->n_owned;
  char who[32], gid[64];
  snprintf(who, sizeof who, "rank %d:", last);
  snprintf(gid, sizeof gid, "(global id %lld)", (long long)(b->n * (int64_t)last / size));
  for (int half = 0; half < 2; ++half) {
    if (rank == last) y[half * b->n_owned] = NAN;
    expect(ctx, mfree_system_rhs(b->sys, 0.0, y, yd), MFREE_FAIL_NONFINITE, who, "rhs, NaN on the last rank");
    expect(ctx, MFREE_FAIL_NONFINITE, MFREE_FAIL_NONFINITE,
           half ? "has a non-finite velocity" : "has a non-finite displacement", "rhs message");
    expect(ctx, MFREE_FAIL_NONFINITE, MFREE_FAIL_NONFINITE, gid, "rhs message names the global id");
    double t = 0.0;
    int64_t steps = -1;
    expect(ctx, mfree_system_integrate(b->sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, 1e-6, 0.5, 0.0, NULL, NULL, &steps),
           MFREE_FAIL_NONFINITE, who, "integrate, NaN on the last rank");
    CHECK(t == 0.0 && steps == 0, "no step: t %g, %lld steps", t, (long long)steps);
    if (rank == last) y[half * b->n_owned] = 0.0;
  }
  CHECK(mfree_system_rhs(b->sys, 0.0, y, yd) == MFREE_SUCCESS, "rhs recovers");

  /* the history turns NaN on the last rank during the run */
  nan_rank = last;
  mfree_system_set_load_history(b->sys, nan_history, NULL);
  double t = 0.0;
  int64_t steps = -1;
  expect(ctx, mfree_system_integrate(b->sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, 3e-6, 0.5, 0.0, NULL, NULL, &steps),
         MFREE_FAIL_NONFINITE, "rank ", "integrate, NaN history on the last rank");
  double tt[2] = {t, (double)steps}, tmin[2], tmax[2];
  MPI_Allreduce(tt, tmin, 2, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
  MPI_Allreduce(tt, tmax, 2, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  CHECK(tmin[0] == tmax[0] && tmin[1] == tmax[1] && t > 0.0 && t <= 1e-6 + 1e-7,
        "every rank stops at the same step: t %g-%g, steps %g-%g", tmin[0], tmax[0], tmin[1], tmax[1]);
  for (int q = 0; q < neq; ++q) CHECK(isfinite(y[q]), "y holds the last good state (entry %d)", q);
  nan_rank = -1;
  mfree_system_set_load_history(b->sys, mpibar_pulse, NULL);
}

static int owner(int i, int n, int size, int how) {
  const int slab = (int)((int64_t)i * size / n);
  switch (how) {
    case BAR_REVERSED: return size - 1 - slab;
    case BAR_HASHED: return (int)(mpitest_hash((uint64_t)i) % (uint64_t)size);
    case BAR_LAST: return size - 1;
    default: return slab;
  }
}

/* The approximant and collocation assembler of the bar on a set-up particle set; the
 * ends among its first n_owned particles (ids 0 and n - 1) carry the tractions. */
static int bar_operator(mfree_context_t *ctx, mfree_particles_t *ps, int n_owned, const int64_t *id, int n,
                    mfree_approximant_t **a, mfree_assembler_t **as) {
  int st = mfree_approximant_create(ctx, ps, MFREE_METHOD_SSPH, a);
  st |= mfree_approximant_set_kernel(*a, MFREE_KERNEL_REVISED_SUPER_GAUSS, 1.6);
  st |= mfree_approximant_set_order(*a, 2);
  st |= mfree_approximant_set_derivatives(*a, 7);
  st |= mfree_assembler_create(ctx, *a, NULL, MFREE_FORM_COLLOCATION_LAPLACE, as);
  st |= mfree_assembler_set_coefficient(*as, BAR_E); /* 1D bar: rho u'' = E u'' */
  int32_t ends[2];
  double normals[2];
  int ne = 0;
  for (int i = 0; i < n_owned; ++i)
    if (id[i] == 0 || id[i] == n - 1) {
      ends[ne] = i;
      normals[ne++] = id[i] == 0 ? -1.0 : 1.0;
    }
  if (ne) st |= mfree_assembler_add_traction_nodes(*as, ne, ends, normals, traction, NULL);
  st |= mfree_assembler_setup(*as);
  return st;
}

static void zero(void *u, const double *x, double *v) {
  (void)u;
  (void)x;
  v[0] = 0.0;
}

/* Gauss point g (0, 1) of cell c (between particles c and c + 1): its position and weight,
 * as set_quadrature_cells computes them on one rank. */
static void gauss_point(int c, int g, double dx, double *x, double *w) {
  const double r = (g ? 1.0 : -1.0) / sqrt(3.0);
  *x = 0.0 + dx * (c + 0.5 * (1.0 + r));
  *w = 0.5 * dx * 1.0;
}

/* The Galerkin bar's stiffness on a set-up particle set of nn particles (the first n_owned
 * owned, ids id): the quadrature points of the cells within 4 dx of an owned particle and
 * the traction point x = L when an owned particle is within 4 dx of it (all of them on one
 * rank); the left end held when kind is BAR_GALERKIN_FIXED and id 0 is owned. */
static int bar_galerkin(mfree_context_t *ctx, mfree_particles_t *ps, int n_owned, const int64_t *id, int n, int kind,
                        mfree_approximant_t **a, mfree_assembler_t **as) {
  const double dx = BAR_L / (n - 1);
  int st = mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, a);
  st |= mfree_approximant_set_kernel(*a, MFREE_KERNEL_CUBIC_SPLINE, 0.0);
  st |= mfree_approximant_set_order(*a, 1);
  st |= mfree_approximant_set_derivatives(*a, MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT);
  st |= mfree_approximant_setup(*a);
  st |= mfree_assembler_create(ctx, *a, NULL, MFREE_FORM_LAPLACE, as);
  st |= mfree_assembler_set_coefficient(*as, BAR_E); /* 1D bar: int E u' v' */
  char *cell = calloc((size_t)n, 1);
  int near_end = 0, left = -1;
  for (int i = 0; i < n_owned; ++i) {
    for (int64_t c = id[i] - 4; c <= id[i] + 3; ++c)
      if (c >= 0 && c < n - 1) cell[c] = 1;
    near_end |= id[i] >= n - 5;
    if (id[i] == 0) left = i;
  }
  if (kind != BAR_GALERKIN_NODAL) {
    double *qx = malloc(sizeof(double) * 2 * (size_t)n), *qw = malloc(sizeof(double) * 2 * (size_t)n);
    int nq = 0;
    for (int c = 0; c < n - 1; ++c)
      for (int g = 0; g < 2 && cell[c]; ++g, ++nq) gauss_point(c, g, dx, &qx[nq], &qw[nq]);
    st |= mfree_assembler_set_quadrature_points(*as, nq, nq ? qx : NULL, MFREE_LAYOUT_AOS, 1, nq ? qw : NULL);
    free(qx);
    free(qw);
  }
  free(cell);
  const double xe = BAR_L, we = 1.0; /* unit cross-section */
  if (near_end) st |= mfree_assembler_add_traction(*as, 1, &xe, MFREE_LAYOUT_AOS, 1, &we, traction, NULL);
  if (kind == BAR_GALERKIN_FIXED && left >= 0)
    st |= mfree_assembler_add_dirichlet_nodes(*as, 1, (const int32_t[]){left}, 1, zero, NULL);
  st |= mfree_assembler_setup(*as);
  return st;
}

int mpibar_make(mpibar_t *b, mfree_context_t *ctx, MPI_Comm comm, int n, int how) {
  return mpibar_make_kind(b, ctx, comm, n, how, BAR_COLLOCATION);
}

int mpibar_make_kind(mpibar_t *b, mfree_context_t *ctx, MPI_Comm comm, int n, int how, int kind) {
  memset(b, 0, sizeof *b);
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  b->comm = comm;
  b->n = n;
  const double dx = BAR_L / (n - 1), h = 1.5 * dx, vol = dx;
  double *xo = malloc(sizeof(double) * (size_t)n);
  int64_t *io = malloc(sizeof(int64_t) * (size_t)n);
  int no = 0;
  for (int i = 0; i < n; ++i)
    if (owner(i, n, size, how) == rank) {
      xo[no] = i * dx;
      io[no++] = i;
    }
  int st = mfree_halo_create(ctx, comm, 1, &b->halo);
  if (st == MFREE_SUCCESS) st = mfree_halo_setup(b->halo, no, xo, 1, io, 6.0 * h);
  if (st != MFREE_SUCCESS) {
    free(xo);
    free(io);
    return st;
  }
  int32_t n_owned = 0, n_ghost = 0;
  mfree_halo_get_size(b->halo, &n_owned, &n_ghost);
  b->n_owned = n_owned;
  b->n_ghost = n_ghost;
  const int nn = n_owned + n_ghost;
  b->x = malloc(sizeof(double) * (size_t)(nn + 1));
  b->id = malloc(sizeof(int64_t) * (size_t)(nn + 1));
  memcpy(b->x, xo, sizeof(double) * (size_t)no);
  mfree_halo_exchange(b->halo, 1, b->x, 1);
  mfree_halo_get_global_ids(b->halo, b->id);
  free(xo);
  free(io);
  st = mfree_particles_create(ctx, 1, nn, &b->ps);
  st |= mfree_particles_set_num_ghost(b->ps, n_ghost);
  st |= mfree_particles_set_positions(b->ps, b->x, MFREE_LAYOUT_AOS, 1, MFREE_BORROW);
  st |= mfree_particles_set_support(b->ps, &h, 0, MFREE_COPY);
  st |= mfree_particles_set_volumes(b->ps, &vol, 0, MFREE_COPY);
  st |= mfree_particles_set_global_ids(b->ps, b->id, MFREE_BORROW);
  st |= kind == BAR_COLLOCATION ? bar_operator(ctx, b->ps, n_owned, b->id, n, &b->a, &b->as)
                                : bar_galerkin(ctx, b->ps, n_owned, b->id, n, kind, &b->a, &b->as);
  /* (every rank creates the system, a failed one too: the creation is collective) */
  const int st2 = mfree_halo_create_elastodynamic(b->halo, st ? NULL : b->as, BAR_RHO, &b->sys);
  if (st2 == MFREE_SUCCESS) mfree_system_set_load_history(b->sys, mpibar_pulse, NULL);
  return st ? st : st2;
}

void mpibar_free(mpibar_t *b) {
  mfree_system_destroy(&b->sys);
  mfree_assembler_destroy(&b->as);
  mfree_approximant_destroy(&b->a);
  mfree_particles_destroy(&b->ps);
  mfree_halo_destroy(&b->halo);
  free(b->x);
  free(b->id);
  b->x = NULL;
  b->id = NULL;
}

void mpibar_collect(const mpibar_t *b, const double *vals, int ncomp, double *out) {
  int size = 1;
  MPI_Comm_size(b->comm, &size);
  int *cnt = malloc(sizeof(int) * (size_t)size), *dis = malloc(sizeof(int) * (size_t)size);
  const int mine = b->n_owned * (ncomp + 1);
  MPI_Allgather(&mine, 1, MPI_INT, cnt, 1, MPI_INT, b->comm);
  int total = 0;
  for (int p = 0; p < size; ++p) {
    dis[p] = total;
    total += cnt[p];
  }
  /* (id, values) records; the id as a double (exact below 2^53) */
  double *send = malloc(sizeof(double) * (size_t)(mine + 1)), *all = malloc(sizeof(double) * (size_t)(total + 1));
  for (int i = 0; i < b->n_owned; ++i) {
    send[i * (ncomp + 1)] = (double)b->id[i];
    memcpy(&send[i * (ncomp + 1) + 1], &vals[i * ncomp], sizeof(double) * (size_t)ncomp);
  }
  MPI_Allgatherv(send, mine, MPI_DOUBLE, all, cnt, dis, MPI_DOUBLE, b->comm);
  for (int k = 0; k < total; k += ncomp + 1) memcpy(&out[(int64_t)all[k] * ncomp], &all[k + 1], sizeof(double) * (size_t)ncomp);
  free(send);
  free(all);
  free(cnt);
  free(dis);
}

int serialbar_make(serialbar_t *b, mfree_context_t *ctx, int n) { return serialbar_make_kind(b, ctx, n, BAR_COLLOCATION); }

int serialbar_make_kind(serialbar_t *b, mfree_context_t *ctx, int n, int kind) {
  return serialbar_make_mass(b, ctx, n, kind, MFREE_FORM_MASS_LUMPED);
}

int serialbar_make_mass(serialbar_t *b, mfree_context_t *ctx, int n, int kind, mfree_form_t mass_form) {
  memset(b, 0, sizeof *b);
  const double dx = BAR_L / (n - 1), h = 1.5 * dx, vol = dx;
  b->x = malloc(sizeof(double) * (size_t)n);
  int64_t *id = malloc(sizeof(int64_t) * (size_t)n);
  for (int i = 0; i < n; ++i) {
    b->x[i] = i * dx;
    id[i] = i;
  }
  int st = mfree_particles_create(ctx, 1, n, &b->ps);
  st |= mfree_particles_set_positions(b->ps, b->x, MFREE_LAYOUT_AOS, 1, MFREE_BORROW);
  st |= mfree_particles_set_support(b->ps, &h, 0, MFREE_COPY);
  st |= mfree_particles_set_volumes(b->ps, &vol, 0, MFREE_COPY);
  if (kind == BAR_COLLOCATION) {
    st |= bar_operator(ctx, b->ps, n, id, n, &b->a, &b->as);
  } else {
    st |= bar_galerkin(ctx, b->ps, n, id, n, kind, &b->a, &b->as);
    /* the mass on the same points: the gauss points of every cell */
    double *qx = malloc(sizeof(double) * 2 * (size_t)n), *qw = malloc(sizeof(double) * 2 * (size_t)n);
    for (int c = 0; c < n - 1; ++c)
      for (int g = 0; g < 2; ++g) gauss_point(c, g, dx, &qx[2 * c + g], &qw[2 * c + g]);
    st |= mfree_assembler_create(ctx, b->a, NULL, mass_form, &b->mass);
    st |= mfree_assembler_set_coefficient(b->mass, BAR_RHO);
    if (kind != BAR_GALERKIN_NODAL)
      st |= mfree_assembler_set_quadrature_points(b->mass, 2 * (n - 1), qx, MFREE_LAYOUT_AOS, 1, qw);
    st |= mfree_assembler_setup(b->mass);
    free(qx);
    free(qw);
  }
  free(id);
  if (st) return st;
  st = kind == BAR_COLLOCATION ? mfree_system_create_elastodynamic(ctx, b->as, BAR_RHO, &b->sys)
                               : mfree_system_create_elastodynamic_galerkin(ctx, b->as, b->mass, &b->sys);
  if (st == MFREE_SUCCESS) mfree_system_set_load_history(b->sys, mpibar_pulse, NULL);
  return st;
}

void serialbar_free(serialbar_t *b) {
  mfree_system_destroy(&b->sys);
  mfree_assembler_destroy(&b->as);
  mfree_assembler_destroy(&b->mass);
  mfree_approximant_destroy(&b->a);
  mfree_particles_destroy(&b->ps);
  free(b->x);
}
