#include "mpitest.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef MFREE_TEST_ZOLTAN
#include <zoltan.h>
#endif

int mpitest_failures = 0;

int mpitest_finish(const char *name) {
  int total = 0, rank = 0;
  MPI_Allreduce(&mpitest_failures, &total, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank == 0) printf("%s: %s (%d failed checks)\n", name, total ? "FAILED" : "ok", total);
  return total != 0;
}

uint64_t mpitest_hash(uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

static double uniform(uint64_t *s) {
  *s = mpitest_hash(*s);
  return (double)(*s >> 11) * 0x1.0p-53;
}

void cloud_make(cloud_t *c, int dim, int m, uint64_t seed) {
  int n = 1;
  for (int d = 0; d < dim; ++d) n *= m;
  c->dim = dim;
  c->n = n;
  c->x = malloc(sizeof(double) * (size_t)n * dim);
  c->h = malloc(sizeof(double) * (size_t)n);
  c->v = malloc(sizeof(double) * (size_t)n);
  c->id = malloc(sizeof(int64_t) * (size_t)n);
  const double dx = 1.0 / (m - 1);
  uint64_t s = seed;
  for (int i = 0; i < n; ++i) {
    int rest = i;
    for (int d = 0; d < dim; ++d) {
      c->x[i * dim + d] = (rest % m) * dx + 0.25 * dx * (2.0 * uniform(&s) - 1.0);
      rest /= m;
    }
    c->h[i] = 1.3 * dx * (0.9 + 0.2 * uniform(&s));
    c->v[i] = pow(dx, dim) * (0.9 + 0.2 * uniform(&s));
    c->id[i] = 5 + 2 * (int64_t)i;
  }
}

void cloud_free(cloud_t *c) {
  free(c->x);
  free(c->h);
  free(c->v);
  free(c->id);
}

double cloud_max_support(const cloud_t *c) {
  double m = 0;
  for (int i = 0; i < c->n; ++i) m = c->h[i] > m ? c->h[i] : m;
  return m;
}

#ifdef MFREE_TEST_ZOLTAN
/* Zoltan's view of this rank's starting share: particles i with i % size == rank. */
typedef struct {
  const cloud_t *c;
  int rank, size;
} zdata_t;

static int z_num_obj(void *data, int *ierr) {
  const zdata_t *z = data;
  *ierr = ZOLTAN_OK;
  return (z->c->n - z->rank + z->size - 1) / z->size;
}
static void z_obj_list(void *data, int ng, int nl, ZOLTAN_ID_PTR gids, ZOLTAN_ID_PTR lids, int wdim,
                       float *w, int *ierr) {
  const zdata_t *z = data;
  (void)ng, (void)nl, (void)wdim, (void)w;
  int k = 0;
  for (int i = z->rank; i < z->c->n; i += z->size, ++k) {
    gids[k] = (ZOLTAN_ID_TYPE)i;
    lids[k] = (ZOLTAN_ID_TYPE)k;
  }
  *ierr = ZOLTAN_OK;
}
static int z_num_geom(void *data, int *ierr) {
  *ierr = ZOLTAN_OK;
  return ((const zdata_t *)data)->c->dim;
}
static void z_geom(void *data, int ng, int nl, int nobj, ZOLTAN_ID_PTR gids, ZOLTAN_ID_PTR lids, int ndim,
                   double *g, int *ierr) {
  const zdata_t *z = data;
  (void)ng, (void)nl, (void)lids;
  for (int k = 0; k < nobj; ++k)
    for (int d = 0; d < ndim; ++d) g[k * ndim + d] = z->c->x[(size_t)gids[k] * z->c->dim + d];
  *ierr = ZOLTAN_OK;
}
#endif

int decompose(const cloud_t *c, int how, MPI_Comm comm, int *part) {
  int rank, size;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  if (how == DECOMP_SLAB) {
    for (int i = 0; i < c->n; ++i) {
      int p = (int)floor(c->x[i * c->dim] * size);
      part[i] = p < 0 ? 0 : p >= size ? size - 1 : p;
    }
    return 0;
  }
  if (how == DECOMP_RANDOM) {
    for (int i = 0; i < c->n; ++i) part[i] = (int)(mpitest_hash((uint64_t)c->id[i] * 31 + 7) % (uint64_t)size);
    return 0;
  }
#ifdef MFREE_TEST_ZOLTAN
  float ver = 0;
  if (Zoltan_Initialize(0, NULL, &ver) != ZOLTAN_OK) return -1;
  struct Zoltan_Struct *zz = Zoltan_Create(comm);
  zdata_t zd = {c, rank, size};
  Zoltan_Set_Param(zz, "DEBUG_LEVEL", "0");
  Zoltan_Set_Param(zz, "LB_METHOD", "RCB");
  Zoltan_Set_Param(zz, "NUM_GID_ENTRIES", "1");
  Zoltan_Set_Param(zz, "NUM_LID_ENTRIES", "1");
  Zoltan_Set_Param(zz, "RETURN_LISTS", "EXPORT");
  Zoltan_Set_Num_Obj_Fn(zz, z_num_obj, &zd);
  Zoltan_Set_Obj_List_Fn(zz, z_obj_list, &zd);
  Zoltan_Set_Num_Geom_Fn(zz, z_num_geom, &zd);
  Zoltan_Set_Geom_Multi_Fn(zz, z_geom, &zd);
  int changes, ngid, nlid, nimp, nexp, *iproc, *ipart, *eproc, *epart;
  ZOLTAN_ID_PTR igid, ilid, egid, elid;
  const int rc = Zoltan_LB_Partition(zz, &changes, &ngid, &nlid, &nimp, &igid, &ilid, &iproc, &ipart, &nexp,
                                     &egid, &elid, &eproc, &epart);
  /* every rank learns every particle's part: the starting share, then the exports */
  int *mine = malloc(sizeof(int) * (size_t)c->n);
  for (int i = 0; i < c->n; ++i) mine[i] = i % size == rank ? rank : -1;
  if (rc == ZOLTAN_OK)
    for (int k = 0; k < nexp; ++k) mine[egid[k]] = epart[k];
  MPI_Allreduce(mine, part, c->n, MPI_INT, MPI_MAX, comm);
  free(mine);
  Zoltan_LB_Free_Part(&igid, &ilid, &iproc, &ipart);
  Zoltan_LB_Free_Part(&egid, &elid, &eproc, &epart);
  Zoltan_Destroy(&zz);
  return rc == ZOLTAN_OK ? 0 : -1;
#else
  (void)part;
  return -1;
#endif
}
