/* libFuzzer harness: particle sets and the neighbour search. Bytes -> a set (dimension,
 * count, ghosts, borrowed or copied positions, supports and volumes with special values,
 * search convention and kappa, a periodic box, host neighbour lists with arbitrary rows:
 * unsorted, repeated or out-of-range columns), then a program of calls: setup, update,
 * a change of ghost count, of a borrowed value, of the lists, of the box, of the search;
 * global ids (repeated, negative), masses and densities, a half pair list (repeated,
 * self or out-of-range pairs), the halo width.
 * After every call: a documented status; after a negative one the lists and statuses are
 * those of before; after a setup or update the lists are sorted, in range, free of
 * repeated columns and of failed particles. */
#include "fuzz_util.h"

enum { MAXN = 64, MAXNNZ = 8 * MAXN, NOPS = 24 };

typedef struct {
  int dim, n;
  double x[3 * MAXN], h[MAXN], v[MAXN];
  int64_t rp[MAXN + 1], gid[2][MAXN];
  int gcur; /* gid[gcur] is the set's (maybe borrowed) ids: new ones go to the other */
  int32_t cols[MAXNNZ], pi[MAXNNZ], pj[MAXNNZ];
} data_t;

/* Host lists from the bytes: row lengths 0..7, columns anywhere in [-1, n]. */
static void host_lists(fz_bytes_t *b, data_t *d, int rows, int base) {
  d->rp[0] = base;
  int64_t k = 0;
  for (int i = 0; i < rows; ++i) {
    const int len = (int)(fz_u8(b) % 8);
    for (int q = 0; q < len && k < MAXNNZ; ++q) {
      const unsigned c = fz_u8(b);
      /* mostly valid, sometimes repeated (c % 4 == 1: the previous column), rarely out of range */
      int32_t j = (int32_t)(c % (unsigned)(d->n + 2)) - 1;
      if (c % 4 == 1 && k > d->rp[i] - base) j = d->cols[k - 1] - base;
      d->cols[k++] = j + base;
    }
    d->rp[i + 1] = k + base;
  }
}

static mfree_status_t call(mfree_particles_t *ps, fz_bytes_t *b, data_t *d, int op, mfree_mem_t mem) {
  switch (op) {
    case 0: return mfree_particles_setup(ps);
    case 1: return mfree_particles_update(ps);
    case 2: { /* (one byte per argument, read in order: argument evaluation order is unspecified) */
      const int32_t g = (int32_t)(fz_u8(b) % (unsigned)(d->n + 2)) - 1;
      return mfree_particles_set_num_ghost(ps, g);
    }
    case 3: { /* a borrowed position or support changes (moved, NaN, ...) */
      const int i = d->n ? (int)(fz_u8(b) % (unsigned)d->n) : 0;
      if (d->n) {
        if (fz_u8(b) & 1) {
          const int c = (int)(fz_u8(b) % (unsigned)d->dim);
          const double val = fz_coord(b, d->x[0]);
          d->x[d->dim * i + c] = val;
        } else {
          d->h[i] = fz_positive(b, 0.1);
        }
      }
      return MFREE_SUCCESS;
    }
    case 4: {
      int32_t ng = 0, n = 0;
      mfree_particles_get_size(ps, &n, &ng);
      const int base = (int)(fz_u8(b) & 1);
      host_lists(b, d, n - ng, base);
      return mfree_particles_set_neighbors(ps, d->rp, d->cols, base, (fz_u8(b) & 1) ? MFREE_BORROW : MFREE_COPY);
    }
    case 5: {
      double lo[3], hi[3];
      int32_t per[3];
      for (int c = 0; c < 3; ++c) {
        const unsigned k = fz_u8(b);
        lo[c] = k == 250 ? -1.7e308 : k == 251 ? NAN : -(k % 4) * 0.25;
        hi[c] = k == 250 ? 1.7e308 : 1.0 + (k % 3) * 0.5;
        per[c] = (int32_t)((k >> 2) & 1);
      }
      return mfree_particles_set_periodic(ps, lo, hi, per);
    }
    case 6: {
      const mfree_search_t conv = (mfree_search_t)(fz_u8(b) % 5);
      const double kappa = 0.5 + (fz_u8(b) % 8) * 0.5;
      return mfree_particles_set_search(ps, conv, kappa);
    }
    case 7: {
      const unsigned k = fz_u8(b);
      const mfree_layout_t layout = (k & 1) ? MFREE_LAYOUT_SOA : MFREE_LAYOUT_AOS;
      /* (a huge ld must be one whose offsets wrap, which mfree refuses: a large one that does
       * not wrap is a valid request for an array larger than ours) */
      const int64_t ld = (k & 2) ? INT64_MAX / (1 + (k >> 2) % 4) : (k & 1) ? d->n : d->dim;
      return mfree_particles_set_positions(ps, d->x, layout, ld, mem);
    }
    case 8: return mfree_particles_set_support(ps, d->h, (int64_t)(fz_u8(b) % 3), mem);
    case 9: return mfree_particles_set_volumes(ps, d->v, (int64_t)(fz_u8(b) % 2), mem);
    case 10: { /* global ids: mostly distinct, sometimes repeated or negative; or none */
      const unsigned k = fz_u8(b);
      int64_t *ids = d->gid[1 - d->gcur];
      for (int i = 0; i < d->n; ++i) ids[i] = (k & 1) ? (int64_t)(fz_u8(b) % 8) - 1 : 7 * (d->n - i);
      const mfree_status_t st = mfree_particles_set_global_ids(ps, (k & 2) ? NULL : ids, mem);
      if (st == MFREE_SUCCESS) d->gcur = 1 - d->gcur;
      return st;
    }
    case 11: { /* masses or densities (volumes from them when both are set) */
      const unsigned k = fz_u8(b);
      return (k & 2) ? mfree_particles_set_masses(ps, d->v, (int64_t)(k % 2), mem)
                     : mfree_particles_set_densities(ps, d->h, (int64_t)(k % 2), mem);
    }
    case 12: { /* a half pair list (0- or 1-based): pairs anywhere in [-1, n] */
      const int base = (int)(fz_u8(b) & 1);
      const int64_t np = fz_u8(b) % 32;
      for (int64_t k = 0; k < np; ++k) {
        const unsigned w = fz_u8(b);
        d->pi[k] = (int32_t)(w % (unsigned)(d->n + 2)) - 1 + base;
        d->pj[k] = (int32_t)((w >> 3) % (unsigned)(d->n + 2)) - 1 + base;
      }
      const mfree_status_t st = mfree_particles_set_pairs(ps, np, d->pi, d->pj, base, mem);
      int64_t got = -1;
      FZ_CHECK(mfree_particles_get_num_pairs(ps, &got));
      return st;
    }
    default: {
      double vol[MAXN + 1];
      FZ_CHECK(mfree_particles_get_volumes(ps, vol));
      return mfree_particles_set_halo_width(ps, fz_positive(b, 0.1));
    }
  }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  fz_bytes_t b = {data, size};
  static data_t d;
  memset(&d, 0, sizeof d);
  d.dim = 1 + (int)(fz_u8(&b) % 3);
  d.n = (int)(fz_u8(&b) % (MAXN + 1));
  const unsigned opts = fz_u8(&b);
  const mfree_mem_t mem = (opts & 1) ? MFREE_BORROW : MFREE_COPY;
  const double scale = 1.0 / (1.0 + (fz_u8(&b) % 16));
  for (int i = 0; i < d.dim * d.n; ++i) d.x[i] = fz_coord(&b, i >= d.dim ? d.x[i - d.dim] : 0.0);
  for (int i = 0; i < d.n; ++i) d.h[i] = fz_positive(&b, scale), d.v[i] = fz_positive(&b, scale);

  mfree_context_t *ctx = NULL;
  if (mfree_context_create(&ctx) != MFREE_SUCCESS) return 0;
  if (opts & 2) mfree_context_set_num_threads(ctx, 2);
  mfree_particles_t *ps = NULL;
  if (mfree_particles_create(ctx, d.dim, d.n, &ps) != MFREE_SUCCESS) goto done;
  FZ_CHECK(mfree_particles_set_positions(ps, d.x, MFREE_LAYOUT_AOS, d.dim, mem));
  FZ_CHECK(mfree_particles_set_support(ps, d.h, 1, mem));
  FZ_CHECK(mfree_particles_set_volumes(ps, d.v, 1, mem));
  for (int k = 0; k < NOPS && b.n > 0; ++k) {
    const int op = (int)(fz_u8(&b) % 14);
    fz_lists_t before, after;
    fz_lists_get(ps, &before);
    const mfree_status_t st = call(ps, &b, &d, op, mem);
    FZ_TRAP_IF(!fz_valid_status(st));
    fz_lists_get(ps, &after);
    if (st < 0) fz_lists_same(&before, &after);
    fz_lists_free(&before);
    fz_lists_free(&after);
  }
  mfree_particles_destroy(&ps);
done:
  mfree_context_destroy(&ctx);
  return 0;
}
