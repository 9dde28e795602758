/* Shared by the fuzz harnesses: reading values from the input bytes, and the oracles of
 * the rule of docs/robustness.md besides the sanitizers:
 *  - every status is one of the documented ones (MFREE_ERR_INTERNAL is a bug);
 *  - after a negative status the object is unchanged (the harnesses compare a snapshot);
 *  - every site reported valid holds finite values (fz_check_sites).
 * A broken oracle is __builtin_trap(): libFuzzer saves the input as a crash. */
#ifndef MFREE_FUZZ_UTIL_H
#define MFREE_FUZZ_UTIL_H

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <mfree.h>

typedef struct {
  const uint8_t *p;
  size_t n;
} fz_bytes_t;

static inline unsigned fz_u8(fz_bytes_t *b) {
  if (b->n == 0) return 0;
  b->n--;
  return *b->p++;
}

static inline unsigned fz_u16(fz_bytes_t *b) { return fz_u8(b) | (fz_u8(b) << 8); }

/* A coordinate in [0, 1) with rare special values. */
static inline double fz_coord(fz_bytes_t *b, double prev) {
  const unsigned v = fz_u16(b);
  switch (v) {
    case 0xFFFF: return NAN;
    case 0xFFFE: return INFINITY;
    case 0xFFFD: return prev; /* coincident with the previous particle */
    case 0xFFFC: return 1e300;
    case 0xFFFB: return -1e-300;
    default: return v / 65536.0;
  }
}

/* A positive quantity around `scale`, sometimes invalid or extreme. */
static inline double fz_positive(fz_bytes_t *b, double scale) {
  const unsigned v = fz_u8(b);
  switch (v) {
    case 0: return 0.0;
    case 255: return NAN;
    case 254: return -scale;
    case 253: return 1e-300;
    case 252: return INFINITY;
    case 251: return 1e300;
    default: return scale * (0.05 + v / 64.0);
  }
}

/* The documented statuses: success, misuse -1..-8, data-dependent failures 1..7. */
static inline int fz_valid_status(mfree_status_t st) { return st >= MFREE_ERR_HALO && st <= 7; }

#define FZ_TRAP_IF(cond)          \
  do {                            \
    if (cond) __builtin_trap();   \
  } while (0)

#define FZ_CHECK(call)                                \
  do {                                                \
    mfree_status_t st_ = (call);                      \
    FZ_TRAP_IF(!fz_valid_status(st_));                \
  } while (0)

/* The tables of a set-up approximant: sites, statuses, and every table it built as CSR
 * (value; gradient components; Hessian components). */
typedef struct {
  int32_t nsites;
  int64_t nnz;
  int32_t *status;
  int64_t *rowptr;
  int32_t *cols;
  double *vals; /* ntab tables of nnz values */
  int ntab;
} fz_tables_t;

static inline void fz_tables_free(fz_tables_t *t) {
  free(t->status), free(t->rowptr), free(t->cols), free(t->vals);
  memset(t, 0, sizeof *t);
}

/* Reads the tables of a (0 when it is not set up). */
static inline int fz_tables_get(const mfree_approximant_t *a, int dim, fz_tables_t *t) {
  memset(t, 0, sizeof *t);
  if (mfree_approximant_get_num_sites(a, &t->nsites) != MFREE_SUCCESS) return 0;
  FZ_TRAP_IF(mfree_approximant_get_nnz(a, &t->nnz) != MFREE_SUCCESS);
  t->status = calloc((size_t)t->nsites + 1, sizeof *t->status);
  t->rowptr = calloc((size_t)t->nsites + 1, sizeof *t->rowptr);
  t->cols = calloc((size_t)t->nnz + 1, sizeof *t->cols);
  const int nh = dim == 1 ? 1 : dim == 2 ? 3 : 6;
  t->vals = calloc(((size_t)t->nnz + 1) * (size_t)(1 + dim + nh), sizeof *t->vals);
  FZ_TRAP_IF(mfree_approximant_get_site_status(a, t->status, NULL) != MFREE_SUCCESS);
  const struct {
    mfree_deriv_t d;
    int ncomp;
  } tabs[3] = {{MFREE_DERIV_VALUE, 1}, {MFREE_DERIV_GRADIENT, dim}, {MFREE_DERIV_HESSIAN, nh}};
  for (int k = 0; k < 3; ++k)
    for (int c = 0; c < tabs[k].ncomp; ++c) {
      double *v = t->vals + (size_t)t->ntab * ((size_t)t->nnz + 1);
      const mfree_status_t st = mfree_approximant_assemble_csr(a, tabs[k].d, c, t->rowptr, t->cols, v);
      FZ_TRAP_IF(!fz_valid_status(st));
      if (st != MFREE_SUCCESS) break; /* that table was not built */
      t->ntab++;
    }
  return 1;
}

/* Every site reported valid holds finite values in every table. */
static inline void fz_check_sites(const fz_tables_t *t) {
  for (int k = 0; k < t->ntab; ++k) {
    const double *v = t->vals + (size_t)k * ((size_t)t->nnz + 1);
    for (int32_t s = 0; s < t->nsites; ++s) {
      if (t->status[s] != 0) continue;
      for (int64_t q = t->rowptr[s]; q < t->rowptr[s + 1]; ++q) FZ_TRAP_IF(!isfinite(v[q]));
    }
  }
}

/* Two snapshots of the same approximant are bitwise equal. */
static inline void fz_tables_same(const fz_tables_t *a, const fz_tables_t *b) {
  FZ_TRAP_IF(a->nsites != b->nsites || a->nnz != b->nnz || a->ntab != b->ntab);
  FZ_TRAP_IF(memcmp(a->status, b->status, sizeof(int32_t) * (size_t)a->nsites) != 0);
  FZ_TRAP_IF(memcmp(a->rowptr, b->rowptr, sizeof(int64_t) * ((size_t)a->nsites + 1)) != 0);
  FZ_TRAP_IF(memcmp(a->cols, b->cols, sizeof(int32_t) * (size_t)a->nnz) != 0);
  FZ_TRAP_IF(memcmp(a->vals, b->vals, sizeof(double) * (size_t)a->ntab * ((size_t)a->nnz + 1)) != 0);
}

/* The neighbour lists and statuses of a particle set (empty when not set up). */
typedef struct {
  int setup;
  int32_t n;
  int64_t nnz;
  int64_t *rowptr;
  int32_t *cols, *status;
} fz_lists_t;

static inline void fz_lists_get(const mfree_particles_t *ps, fz_lists_t *l) {
  memset(l, 0, sizeof *l);
  int32_t ng = 0;
  FZ_TRAP_IF(mfree_particles_get_size(ps, &l->n, &ng) != MFREE_SUCCESS);
  if (mfree_particles_get_neighbor_nnz(ps, &l->nnz) != MFREE_SUCCESS) return;
  l->setup = 1;
  l->rowptr = calloc((size_t)(l->n - ng) + 1, sizeof *l->rowptr);
  l->cols = calloc((size_t)l->nnz + 1, sizeof *l->cols);
  l->status = calloc((size_t)l->n + 1, sizeof *l->status);
  FZ_TRAP_IF(mfree_particles_get_neighbors(ps, l->rowptr, l->cols) != MFREE_SUCCESS);
  FZ_TRAP_IF(mfree_particles_get_site_status(ps, l->status, NULL) != MFREE_SUCCESS);
  /* rows sorted (by global id when the set has ids), in range, no column twice; failed
   * particles listed nowhere */
  int64_t *ids = calloc((size_t)l->n + 1, sizeof *ids);
  const int by_id = mfree_particles_get_global_ids(ps, ids) == MFREE_SUCCESS;
  for (int32_t i = 0; i < l->n - ng; ++i)
    for (int64_t k = l->rowptr[i]; k < l->rowptr[i + 1]; ++k) {
      const int32_t j = l->cols[k];
      FZ_TRAP_IF(j < 0 || j >= l->n);
      if (k > l->rowptr[i]) {
        const int32_t q = l->cols[k - 1];
        FZ_TRAP_IF(by_id ? ids[q] >= ids[j] : q >= j);
      }
      FZ_TRAP_IF(l->status[j] != 0 || l->status[i] != 0);
    }
  free(ids);
}

static inline void fz_lists_same(const fz_lists_t *a, const fz_lists_t *b) {
  FZ_TRAP_IF(a->setup != b->setup || a->nnz != b->nnz);
  if (!a->setup) return;
  FZ_TRAP_IF(memcmp(a->cols, b->cols, sizeof(int32_t) * (size_t)a->nnz) != 0);
  FZ_TRAP_IF(memcmp(a->status, b->status, sizeof(int32_t) * (size_t)a->n) != 0);
}

static inline void fz_lists_free(fz_lists_t *l) {
  free(l->rowptr), free(l->cols), free(l->status);
  memset(l, 0, sizeof *l);
}

#endif
