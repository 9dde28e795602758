#include "mpibar.h"

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

int mpibar_make(mpibar_t *b, mfree_context_t *ctx, MPI_Comm comm, int n, int how) {
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
  st |= bar_operator(ctx, b->ps, n_owned, b->id, n, &b->a, &b->as);
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

int serialbar_make(serialbar_t *b, mfree_context_t *ctx, int n) {
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
  st |= bar_operator(ctx, b->ps, n, id, n, &b->a, &b->as);
  free(id);
  if (st) return st;
  st = mfree_system_create_elastodynamic(ctx, b->as, BAR_RHO, &b->sys);
  if (st == MFREE_SUCCESS) mfree_system_set_load_history(b->sys, mpibar_pulse, NULL);
  return st;
}

void serialbar_free(serialbar_t *b) {
  mfree_system_destroy(&b->sys);
  mfree_assembler_destroy(&b->as);
  mfree_approximant_destroy(&b->a);
  mfree_particles_destroy(&b->ps);
  free(b->x);
}
