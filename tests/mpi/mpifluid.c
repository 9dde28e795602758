#include "mpifluid.h"

#include "mpitest.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const double kRho0 = 1000.0, kGamma = 7.0, kG = 9.81;

static void wall_segment(damb_t *b, double x0, double z0, double x1, double z1, double ds, double nx, double nz,
                         int skip_first) {
  const int k = (int)ceil(hypot(x1 - x0, z1 - z0) / ds);
  for (int i = skip_first; i <= k; ++i) {
    const double s = (double)i / k;
    b->wx[2 * b->nwall] = x0 + s * (x1 - x0);
    b->wx[2 * b->nwall + 1] = z0 + s * (z1 - z0);
    b->wn[2 * b->nwall] = nx;
    b->wn[2 * b->nwall + 1] = nz;
    ++b->nwall;
  }
}

void damb_make(damb_t *b, int nx, int nz) {
  b->n = nx * nz;
  b->a = 0.05715;
  b->d = b->a / nx;
  b->h = 1.5 * b->d;
  const double H = 2.0 * b->a, L = 5.0 * b->a, d = b->d, top = 1.5 * H, off = 0.5 * d, ds = d / 3.0;
  b->kappa = 100.0 * kRho0 * 2.0 * kG * H / kGamma;
  const int n = b->n;
  b->y = calloc(5 * (size_t)n, sizeof *b->y);
  b->m = malloc((size_t)n * sizeof *b->m);
  for (int j = 0, q = 0; j < nz; ++j)
    for (int i = 0; i < nx; ++i, ++q) {
      const double z = (j + 0.5) * d;
      b->y[2 * q] = (i + 0.5) * d;
      b->y[2 * q + 1] = z;
      b->y[4 * (size_t)n + q] = kRho0 * pow(1.0 + kRho0 * kG * (H - z) / b->kappa, 1.0 / kGamma); /* 003 eq 65 */
      b->m[q] = b->y[4 * (size_t)n + q] * d * d;
    }
  const int cap = 2 * (int)ceil((top + off) / ds) + (int)ceil((L + 2 * off) / ds) + 8;
  b->wx = malloc(2 * sizeof(double) * (size_t)cap);
  b->wn = malloc(2 * sizeof(double) * (size_t)cap);
  b->nwall = 0;
  wall_segment(b, -off, top, -off, -off, ds, 1, 0, 0);         /* left wall */
  wall_segment(b, -off, -off, L + off, -off, ds, 0, 1, 1);     /* floor */
  wall_segment(b, L + off, -off, L + off, top, ds, -1, 0, 1);  /* right wall */
}

void damb_free(damb_t *b) {
  free(b->y), free(b->m), free(b->wx), free(b->wn);
  memset(b, 0, sizeof *b);
}

mfree_status_t damb_configure(const damb_t *b, mfree_system_t *sys) {
  const double g[2] = {0.0, -kG};
  mfree_status_t st = mfree_system_set_fluid(sys, &kRho0, 0, b->kappa, kGamma, 0.5);
  if (st == MFREE_SUCCESS) st = mfree_system_set_smoothing(sys, b->h);
  if (st == MFREE_SUCCESS) st = mfree_system_set_gravity(sys, g);
  if (st == MFREE_SUCCESS) st = mfree_system_set_walls(sys, b->nwall, b->wx, b->wn, 0.7 * b->h, 10.0);
  return st;
}

/* The open channel (mpifluid_channel, mpifluid_open). */
static const double kChanU = 1.0, kChanD = 0.01, kChanW = 0.06, kChanC0 = 10.0, kChanOut = 0.155;

void mpifluid_channel(damb_t *b, int n) {
  memset(b, 0, sizeof *b);
  b->n = n;
  b->a = 1.0;
  b->d = kChanD;
  b->h = 1.5 * kChanD;
  b->kappa = kRho0 * kChanC0 * kChanC0 / kGamma;
  b->y = calloc(5 * (size_t)n, sizeof *b->y);
  b->m = malloc((size_t)n * sizeof *b->m);
  for (int i = 0; i < n; ++i) {
    b->y[2 * i] = -1.0 - i * kChanD; /* dormant: anywhere, here upstream */
    b->y[2 * i + 1] = 0.5 * kChanW;
    b->y[4 * (size_t)n + i] = kRho0;
    b->m[i] = kRho0 * kChanD * kChanD;
  }
  const double ds = kChanD / 3.0;
  const int per = (int)ceil(0.4 / ds) + 1;
  b->wx = malloc(4 * sizeof(double) * (size_t)per);
  b->wn = malloc(4 * sizeof(double) * (size_t)per);
  for (int side = 0; side < 2; ++side)
    for (int k = 0; k < per; ++k, ++b->nwall) {
      b->wx[2 * b->nwall] = -0.1 + k * ds;
      b->wx[2 * b->nwall + 1] = side ? kChanW + 0.5 * kChanD : -0.5 * kChanD;
      b->wn[2 * b->nwall] = 0.0;
      b->wn[2 * b->nwall + 1] = side ? -1.0 : 1.0;
    }
}

mfree_status_t mpifluid_open(mfree_system_t *sys, double speed) {
  const double o[2] = {0.0, 0.0}, e[2] = {0.0, kChanW}, nrm[2] = {1.0, 0.0}, p[2] = {kChanOut, 0.0};
  mfree_status_t st = mfree_system_set_active(sys, 0);
  if (st == MFREE_SUCCESS) st = mfree_system_set_inflow(sys, 0, o, e, nrm, speed > 0.0 ? speed : kChanU, kRho0, kChanD);
  if (st == MFREE_SUCCESS) st = mfree_system_set_outflow(sys, 0, p, nrm);
  return st;
}

void mpifluid_slabs(const damb_t *b, int size, int *owner) {
  for (int i = 0; i < b->n; ++i) {
    const int p = (int)(b->y[2 * i] / b->a * size);
    owner[i] = p < 0 ? 0 : p >= size ? size - 1 : p;
  }
}

mfree_context_t *mpifluid_start(int *argc, char ***argv, int *rank, int *size, damb_t *b, int nx, int nz,
                                int **owner) {
  mfree_context_t *ctx = mpitest_start(argc, argv, rank, size);
  damb_make(b, nx, nz);
  *owner = malloc(((size_t)b->n + 1) * sizeof **owner);
  mpifluid_slabs(b, *size, *owner);
  return ctx;
}

mfree_status_t rankfluid_make(rankfluid_t *r, mfree_context_t *ctx, MPI_Comm comm, const damb_t *b,
                              const int *owner, double width, int reverse) {
  memset(r, 0, sizeof *r);
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  const int n = b->n;
  int no = 0;
  for (int i = 0; i < n; ++i) no += owner[i] == rank;
  int64_t *own = malloc(((size_t)no + 1) * sizeof *own);
  double *x = malloc(2 * ((size_t)no + 1) * sizeof *x);
  for (int i = 0, k = 0; i < n; ++i)
    if (owner[i] == rank) own[reverse ? no - 1 - k++ : k++] = i;
  for (int k = 0; k < no; ++k) memcpy(x + 2 * k, b->y + 2 * own[k], 2 * sizeof(double));
  mfree_status_t st = mfree_halo_create(ctx, comm, 2, &r->halo);
  if (st == MFREE_SUCCESS) st = mfree_halo_setup(r->halo, no, x, 2, own, width);
  int32_t n_owned = 0, n_ghost = 0;
  if (st == MFREE_SUCCESS) st = mfree_halo_get_size(r->halo, &n_owned, &n_ghost);
  double *m = NULL;
  if (st == MFREE_SUCCESS) {
    r->n_owned = n_owned;
    r->n_ghost = n_ghost;
    r->id = malloc(((size_t)n_owned + n_ghost + 1) * sizeof *r->id);
    m = malloc(((size_t)n_owned + n_ghost + 1) * sizeof *m);
    st = mfree_halo_get_global_ids(r->halo, r->id);
  }
  if (st == MFREE_SUCCESS) {
    for (int k = 0; k < n_owned; ++k) m[k] = b->m[r->id[k]];
    st = mfree_halo_exchange(r->halo, 1, m, 1); /* the ghosts' masses from their owners */
  }
  if (st == MFREE_SUCCESS) st = mfree_halo_create_fluid(r->halo, 2, width, &r->sys);
  if (st == MFREE_SUCCESS) st = damb_configure(b, r->sys);
  if (st == MFREE_SUCCESS) st = mfree_system_set_masses(r->sys, m, 1);
  if (st == MFREE_SUCCESS) {
    r->y = malloc(5 * ((size_t)n_owned + 1) * sizeof *r->y);
    const size_t no2 = 2 * (size_t)n_owned;
    for (int k = 0; k < n_owned; ++k) {
      const int64_t q = r->id[k];
      memcpy(r->y + 2 * k, b->y + 2 * q, 2 * sizeof(double));
      memcpy(r->y + no2 + 2 * k, b->y + 2 * (size_t)n + 2 * q, 2 * sizeof(double));
      r->y[2 * no2 + k] = b->y[4 * (size_t)n + q];
    }
  }
  free(own), free(x), free(m);
  return st;
}

void rankfluid_free(rankfluid_t *r) {
  mfree_system_destroy(&r->sys);
  if (r->halo) mfree_halo_destroy(&r->halo);
  free(r->id), free(r->y);
  memset(r, 0, sizeof *r);
}

mfree_context_t *mpifluid_pair(int *argc, char ***argv, int *rank, int *size, damb_t *b, int **owner,
                               double *width, rankfluid_t *s, rankfluid_t *twin) {
  mfree_context_t *ctx = mpifluid_start(argc, argv, rank, size, b, 12, 24, owner);
  const double w = 4.0 * b->h + 2.0 * b->d;
  if (width) *width = w;
  CHECK(rankfluid_make(s, ctx, MPI_COMM_WORLD, b, *owner, w, 0) == MFREE_SUCCESS, "system");
  CHECK(rankfluid_make(twin, ctx, MPI_COMM_WORLD, b, *owner, w, 0) == MFREE_SUCCESS, "twin");
  return ctx;
}

void mpifluid_pair_free(damb_t *b, int *owner, rankfluid_t *s, rankfluid_t *twin) {
  free(owner);
  rankfluid_free(s);
  rankfluid_free(twin);
  damb_free(b);
}

void mpifluid_collect(MPI_Comm comm, int n_owned, const int64_t *id, const double *vals, int per, double *out) {
  int size = 1;
  MPI_Comm_size(comm, &size);
  int *counts = malloc(sizeof(int) * (size_t)size), *displs = malloc(sizeof(int) * (size_t)size);
  MPI_Allgather(&n_owned, 1, MPI_INT, counts, 1, MPI_INT, comm);
  int total = 0;
  for (int p = 0; p < size; ++p) displs[p] = total, total += counts[p];
  int64_t *ids = malloc(((size_t)total + 1) * sizeof *ids);
  MPI_Allgatherv(id, n_owned, MPI_INT64_T, ids, counts, displs, MPI_INT64_T, comm);
  for (int p = 0; p < size; ++p) counts[p] *= per, displs[p] *= per;
  double *all = malloc(((size_t)total * per + 1) * sizeof *all);
  MPI_Allgatherv(vals, n_owned * per, MPI_DOUBLE, all, counts, displs, MPI_DOUBLE, comm);
  for (int k = 0; k < total; ++k) memcpy(out + (size_t)per * ids[k], all + (size_t)per * k, (size_t)per * sizeof(double));
  free(counts), free(displs), free(ids), free(all);
}

void mpifluid_state(MPI_Comm comm, const rankfluid_t *r, const double *y, int n, double *out) {
  const size_t no = (size_t)r->n_owned;
  mpifluid_collect(comm, r->n_owned, r->id, y, 2, out);
  mpifluid_collect(comm, r->n_owned, r->id, y + 2 * no, 2, out + 2 * (size_t)n);
  mpifluid_collect(comm, r->n_owned, r->id, y + 4 * no, 1, out + 4 * (size_t)n);
}

void mpifluid_tolerances(const damb_t *b, int no, double *atol) {
  for (int k = 0; k < no; ++k) {
    atol[2 * k] = atol[2 * k + 1] = 1e-2 * b->d;              /* positions */
    atol[2 * no + 2 * k] = atol[2 * no + 2 * k + 1] = 1e-2; /* velocities (m/s) */
    atol[4 * no + k] = 1.0;                                 /* densities (kg/m3) */
  }
}

int32_t mpifluid_stop_at(void *user, int64_t step, double t, double dt) {
  (void)t, (void)dt;
  return step >= *(const int64_t *)user;
}

const char *mpifluid_error(const mfree_context_t *ctx) {
  static char msg[1024];
  msg[0] = 0;
  mfree_context_get_last_error(ctx, NULL, msg, sizeof msg);
  return msg;
}
