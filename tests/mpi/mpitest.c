#include "mpitest.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int mpitest_failures = 0;

void expect(mfree_context_t *ctx, mfree_status_t got, mfree_status_t want, const char *needle, const char *what) {
  char msg[600] = "";
  mfree_context_get_last_error(ctx, NULL, msg, sizeof msg);
  CHECK(got == want, "%s: status %d, expected %d (%s)", what, (int)got, (int)want, msg);
  CHECK(!needle || strstr(msg, needle), "%s: message '%s' lacks '%s'", what, msg, needle);
}

mfree_status_t mpitest_same_status(mfree_status_t st, const char *what) {
  int mine = (int)st, lo = 0, hi = 0;
  MPI_Allreduce(&mine, &lo, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  MPI_Allreduce(&mine, &hi, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  CHECK(lo == hi, "%s: the ranks return statuses %d to %d", what, lo, hi);
  return st;
}

void expect_agreed(mfree_context_t *ctx, mfree_status_t got, mfree_status_t want, int bad, const char *why,
                   const char *what) {
  mpitest_same_status(got, what);
  char needle[200];
  snprintf(needle, sizeof needle, "rank %d: %s", bad, why);
  expect(ctx, got, want, needle, what);
}

int mpitest_same_bits(const double *a, const double *b, int64_t n, const char *what) {
  for (int64_t i = 0; i < n; ++i)
    if (memcmp(&a[i], &b[i], sizeof(double)) != 0) {
      CHECK(0, "%s: item %lld differs: %.17g, reference %.17g", what, (long long)i, a[i], b[i]);
      return 0;
    }
  return 1;
}

char *slurp(const char *path) {
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  fseek(f, 0, SEEK_END);
  const long n = ftell(f);
  fseek(f, 0, SEEK_SET);
  char *s = n >= 0 ? malloc((size_t)n + 1) : NULL;
  if (s && fread(s, 1, (size_t)n, f) != (size_t)n) {
    free(s);
    s = NULL;
  }
  if (s) s[n] = 0;
  fclose(f);
  return s;
}

mfree_context_t *mpitest_start(int *argc, char ***argv, int *rank, int *size) {
  MPI_Init(argc, argv);
  MPI_Comm_rank(MPI_COMM_WORLD, rank);
  MPI_Comm_size(MPI_COMM_WORLD, size);
  mfree_context_t *ctx = NULL;
  mfree_context_create(&ctx);
  return ctx;
}

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
  /* Zoltan RCB through libmfree_mpi's migration, from a starting share of particles i with
   * i % size == rank; every rank learns every particle's part */
  const int mine_n = (c->n - rank + size - 1) / size;
  double *xs = malloc(sizeof(double) * (size_t)(mine_n + 1) * (size_t)c->dim);
  int32_t *dest = malloc(sizeof(int32_t) * (size_t)(mine_n + 1));
  int *mine = malloc(sizeof(int) * (size_t)c->n);
  for (int i = rank, k = 0; i < c->n; i += size, ++k)
    memcpy(xs + (size_t)k * c->dim, c->x + (size_t)i * c->dim, sizeof(double) * (size_t)c->dim);
  mfree_context_t *ctx = NULL;
  mfree_migration_t *mig = NULL;
  mfree_context_create(&ctx);
  int32_t n_new = 0;
  mfree_status_t st = mfree_migration_create(ctx, comm, c->dim, &mig);
  if (st == MFREE_SUCCESS) st = mfree_migration_partition(mig, mine_n, xs, c->dim, 1, &n_new);
  if (st == MFREE_SUCCESS) st = mfree_migration_get_owners(mig, dest, mine_n);
  for (int i = 0; i < c->n; ++i) mine[i] = -1;
  if (st == MFREE_SUCCESS)
    for (int i = rank, k = 0; i < c->n; i += size, ++k) mine[i] = dest[k];
  MPI_Allreduce(mine, part, c->n, MPI_INT, MPI_MAX, comm);
  mfree_migration_destroy(&mig);
  mfree_context_destroy(&ctx);
  free(xs);
  free(dest);
  free(mine);
  return st == MFREE_SUCCESS ? 0 : -1;
#else
  (void)part;
  return -1;
#endif
}
