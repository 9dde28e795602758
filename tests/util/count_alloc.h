/* A counting allocator for the context's allocator hook (mfree_context_set_allocator),
 * shared by the C tests that check where mfree's blocks come from: calls, frees and bytes
 * held, and an optional failure after a number of allocations (fail_after < 0: never).
 * Header-only; include after <stdlib.h>. */
#ifndef MFREE_TEST_COUNT_ALLOC_H
#define MFREE_TEST_COUNT_ALLOC_H

#include <stdint.h>
#include <stdlib.h>

typedef struct {
  int64_t calls, frees, held;
  int64_t fail_after; /* allocations allowed before failing; < 0: never fail */
} counter_t;

static inline void *count_alloc(void *user, int64_t bytes) {
  counter_t *c = (counter_t *)user;
  if (c->fail_after >= 0 && c->calls >= c->fail_after) return NULL;
  ++c->calls;
  c->held += bytes;
  return malloc((size_t)bytes);
}

static inline void count_free(void *user, void *p, int64_t bytes) {
  counter_t *c = (counter_t *)user;
  ++c->frees;
  c->held -= bytes;
  free(p);
}

#endif
