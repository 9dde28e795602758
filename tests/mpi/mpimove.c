#include "mpimove.h"

#include <stdlib.h>
#include <string.h>

static mfree_status_t cx(void *u, int32_t ncomp, double *f, int64_t ld) {
  return mfree_halo_exchange_callback(((counted_t *)u)->halo, ncomp, f, ld);
}

static mfree_status_t ca(void *u, const double *in, int64_t n, double *out, int64_t cap, int64_t *total) {
  return mfree_halo_allgather(((counted_t *)u)->halo, in, n, out, cap, total);
}

mfree_status_t mpimove_rebuild(void *u, int32_t n_owned, const double *x, int64_t ld, const int64_t *ids, double width,
                         int32_t *n_ghost, const int64_t **all_ids) {
  counted_t *w = u;
  ++w->rebuilds;
  /* (a host failing alike on every rank: the callbacks' contract) */
  if (w->fail_rebuild) return MFREE_ERR_INTERNAL;
  return mfree_halo_rebuild_callback(w->halo, n_owned, x, ld, ids, width, n_ghost, all_ids);
}

mfree_status_t mpimove_counted(rankfluid_t *r, mfree_context_t *ctx, const damb_t *b, double width, counted_t *w) {
  mfree_system_destroy(&r->sys);
  w->halo = r->halo;
  w->rebuilds = 0;
  w->fail_rebuild = 0;
  const int n = r->n_owned + r->n_ghost;
  double *m = malloc(((size_t)n + 1) * sizeof *m);
  for (int k = 0; k < n; ++k) m[k] = b->m[r->id[k]];
  mfree_status_t st =
      mfree_system_create_fluid_ranks(ctx, 2, r->n_owned, r->n_ghost, r->id, width, cx, ca, w, &r->sys);
  if (st == MFREE_SUCCESS) st = damb_configure(b, r->sys);
  if (st == MFREE_SUCCESS) st = mfree_system_set_masses(r->sys, m, 1);
  if (st == MFREE_SUCCESS) st = mfree_system_set_halo_rebuild(r->sys, mpimove_rebuild);
  free(m);
  return st;
}

int mpimove_differs(const rankfluid_t *r, const double *y, const double *ref, int n, int *first) {
  int32_t no = 0, ng = 0;
  mfree_halo_get_size(r->halo, &no, &ng);
  int64_t *id = malloc(((size_t)no + ng + 1) * sizeof *id);
  mfree_halo_get_global_ids(r->halo, id);
  const size_t no2 = 2 * (size_t)no, n2 = 2 * (size_t)n;
  int bad = 0;
  *first = -1;
  for (int k = 0; k < no; ++k) {
    const int64_t q = id[k];
    const int d = memcmp(y + 2 * k, ref + 2 * q, 16) || memcmp(y + no2 + 2 * k, ref + n2 + 2 * q, 16) ||
                  memcmp(y + 2 * no2 + k, ref + 2 * n2 + q, 8);
    if (d && *first < 0) *first = (int)q;
    bad += d;
  }
  free(id);
  return bad;
}
