/* Neighbour lists copied out of a set-up particle set, for the search tests (t205-t208):
 * fetched, compared bit for bit and freed; and the jittered lattice those tests search.
 * Header-only; include after testutil.h (cmocka). */
#ifndef MFREE_TEST_NBR_LISTS_H
#define MFREE_TEST_NBR_LISTS_H

#include <stdint.h>
#include <stdlib.h>

typedef struct {
  int64_t *rowptr; /* rows + 1 offsets */
  int32_t *cols;
  int32_t rows; /* owned particles */
} lists_t;

/* A copy of the set's lists (mfree_particles_get_neighbors), one row per owned particle. */
static inline lists_t lists_fetch(mfree_context_t *ctx, mfree_particles_t *ps) {
  lists_t g;
  int32_t n = 0, ng = 0;
  int64_t nnz = 0;
  assert_ok(ctx, mfree_particles_get_size(ps, &n, &ng));
  assert_ok(ctx, mfree_particles_get_neighbor_nnz(ps, &nnz));
  g.rows = n - ng;
  g.rowptr = malloc(sizeof(int64_t) * ((size_t)g.rows + 1));
  g.cols = malloc(sizeof(int32_t) * (size_t)(nnz > 0 ? nnz : 1));
  assert_non_null(g.rowptr);
  assert_non_null(g.cols);
  assert_ok(ctx, mfree_particles_get_neighbors(ps, g.rowptr, g.cols));
  assert_int_equal(g.rowptr[g.rows], nnz);
  return g;
}

static inline void lists_free(lists_t *g) {
  free(g->rowptr);
  free(g->cols);
}

/* The same rows, entry for entry. */
static inline void assert_lists_equal(const lists_t *a, const lists_t *b) {
  assert_int_equal(a->rows, b->rows);
  assert_memory_equal(a->rowptr, b->rowptr, sizeof(int64_t) * ((size_t)a->rows + 1));
  assert_memory_equal(a->cols, b->cols, sizeof(int32_t) * (size_t)a->rowptr[a->rows]);
}

/* m^dim lattice points, spacing 1, each coordinate jittered by up to +-0.3, x fastest
 * (host order = lattice order: spatial order); AoS into x (dim m^dim values). */
static inline void jittered_lattice(double *x, int dim, int m, mfree_rng_t *r) {
  int32_t n = 1;
  for (int d = 0; d < dim; ++d) n *= m;
  for (int32_t p = 0; p < n; ++p) {
    int32_t q = p;
    for (int d = 0; d < dim; ++d) {
      x[(size_t)dim * p + d] = (q % m) + 0.3 * (2.0 * mfree_rng_uniform(r) - 1.0);
      q /= m;
    }
  }
}

#endif
