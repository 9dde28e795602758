/* Helpers of the migration tests (migstate.h). */
#include "migstate.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static double bits(uint64_t id, int k) {
  uint64_t z = mpitest_hash(id * 8 + (uint64_t)k);
  if (k == 1) z &= 0x800fffffffffffffULL; /* a subnormal or a signed zero */
  double d;
  memcpy(&d, &z, sizeof d);
  return d;
}

void mig_position(const cloud_t *c, int i, double t, double *p) {
  const double *x = c->x + (size_t)i * c->dim;
  for (int d = 0; d < c->dim; ++d) p[d] = x[d];
  /* the column spreads along x as it sinks (dam-break-like), and drifts */
  if (c->dim >= 2) {
    p[0] = x[0] * (1.0 + t * x[c->dim - 1]) + 0.1 * t;
    p[c->dim - 1] = x[c->dim - 1] / (1.0 + 0.5 * t);
  } else {
    p[0] = x[0] * (1.0 + t) * (1.0 + t) + 0.1 * t;
  }
}

static int index_of(int64_t id) { return (int)((id - 5) / 2); } /* ids are 5 + 2 i */

void mig_state_init(mig_state_t *s, const cloud_t *c, const int *part, int rank, int cap, double t) {
  s->dim = c->dim;
  s->cap = cap;
  size_t n1 = (size_t)cap + 1;
  s->x = calloc(3 * n1, sizeof(double));
  s->v = calloc(2 * n1, sizeof(double));
  s->rho = calloc(n1, sizeof(double));
  s->h = calloc(n1, sizeof(double));
  s->id = calloc(n1, sizeof(int64_t));
  s->flags = calloc(n1, sizeof(mig_flags_t));
  s->n = 0;
  for (int i = 0; i < c->n; ++i) {
    if (part ? part[i] != rank : rank != 0) continue;
    const int k = s->n++;
    const uint64_t id = (uint64_t)c->id[i];
    mig_position(c, i, t, s->x + 3 * k);
    s->x[3 * k + 2] = -1.0; /* not registered (dim < 3): never read */
    s->v[2 * k] = bits(id, 0);
    s->v[2 * k + 1] = bits(id, 1);
    s->rho[k] = bits(id, 2);
    s->h[k] = c->h[i];
    s->id[k] = c->id[i];
    s->flags[k].other = bits(id, 3);
    s->flags[k].tag = (int32_t)mpitest_hash(id + 99);
  }
}

void mig_state_free(mig_state_t *s) {
  free(s->x);
  free(s->v);
  free(s->rho);
  free(s->h);
  free(s->id);
  free(s->flags);
}

mfree_status_t mig_state_register(const mig_state_t *s, mfree_migration_t *m) {
  mfree_status_t st = mfree_migration_clear_fields(m);
  if (!st) st = mfree_migration_add_field(m, s->x, 8 * (int64_t)s->dim, 3 * 8);
  if (!st) st = mfree_migration_add_field(m, s->v, 16, 16);
  if (!st) st = mfree_migration_add_field(m, s->rho, 8, 8);
  if (!st) st = mfree_migration_add_field(m, s->h, 8, 8);
  if (!st) st = mfree_migration_add_field(m, s->id, 8, 8);
  if (!st) st = mfree_migration_add_field(m, &s->flags[0].tag, 4, (int64_t)sizeof(mig_flags_t));
  return st;
}

void mig_state_move(mig_state_t *s, const cloud_t *c, double t) {
  for (int k = 0; k < s->n; ++k) mig_position(c, index_of(s->id[k]), t, s->x + 3 * k);
}

static int cmp64(const void *a, const void *b) {
  const int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
  return x < y ? -1 : x > y;
}

int mig_state_check(const mig_state_t *s, const cloud_t *c, double t, const char *what) {
  const int before = mpitest_failures;
  for (int k = 0; k < s->n; ++k) {
    const int64_t id = s->id[k];
    CHECK(id >= 5 && (id - 5) % 2 == 0 && (id - 5) / 2 < c->n, "%s: particle %d has a foreign id %lld", what, k,
          (long long)id);
    if (!(id >= 5 && (id - 5) % 2 == 0 && (id - 5) / 2 < c->n)) continue;
    const int i = index_of(id);
    double p[3] = {0, 0, 0}, want[2] = {bits((uint64_t)id, 0), bits((uint64_t)id, 1)}, rho = bits((uint64_t)id, 2);
    const int32_t tag = (int32_t)mpitest_hash((uint64_t)id + 99);
    mig_position(c, i, t, p);
    CHECK(!memcmp(s->x + 3 * k, p, sizeof(double) * (size_t)s->dim), "%s: position of id %lld", what, (long long)id);
    CHECK(!memcmp(s->v + 2 * k, want, sizeof want), "%s: velocity bits of id %lld", what, (long long)id);
    CHECK(!memcmp(s->rho + k, &rho, sizeof rho), "%s: density bits of id %lld", what, (long long)id);
    CHECK(!memcmp(s->h + k, c->h + i, sizeof(double)), "%s: support of id %lld", what, (long long)id);
    CHECK(s->flags[k].tag == tag, "%s: tag of id %lld", what, (long long)id);
  }
  /* every id exactly once over the ranks */
  int size = 1, rank = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  int *cnt = malloc(sizeof(int) * (size_t)size), *dis = malloc(sizeof(int) * (size_t)size);
  MPI_Allgather(&s->n, 1, MPI_INT, cnt, 1, MPI_INT, MPI_COMM_WORLD);
  int tot = 0;
  for (int p = 0; p < size; ++p) {
    dis[p] = tot;
    tot += cnt[p];
  }
  int64_t *all = malloc(sizeof(int64_t) * (size_t)(tot + 1));
  MPI_Allgatherv(s->id, s->n, MPI_INT64_T, all, cnt, dis, MPI_INT64_T, MPI_COMM_WORLD);
  CHECK(tot == c->n, "%s: %d particles over the ranks, expected %d", what, tot, c->n);
  qsort(all, (size_t)tot, sizeof(int64_t), cmp64);
  for (int k = 0; k < tot && k < c->n; ++k)
    if (all[k] != c->id[k]) {
      CHECK(all[k] == c->id[k], "%s: the ids over the ranks are not those of the cloud (at %d: %lld)", what, k,
            (long long)all[k]);
      break;
    }
  free(all);
  free(cnt);
  free(dis);
  int mine = mpitest_failures - before, any = 0;
  MPI_Allreduce(&mine, &any, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  return any;
}

double mig_imbalance(const mig_state_t *s) {
  int size = 1, mx = 0, sum = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  MPI_Allreduce(&s->n, &mx, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  MPI_Allreduce(&s->n, &sum, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  return sum ? (double)mx * size / sum : 1.0;
}
