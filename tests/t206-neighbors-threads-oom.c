/*
 * t206: running out of memory in a neighbour search with two threads (the
 * one-thread case is t205's test_allocation_failure).
 *
 * The context's allocator hook is called from both threads at once here, so the hook
 * below counts with atomics and fails every allocation from a given count on. Cases, on
 * clustered 3D points stored in spatial order (the two-thread host-order search: one
 * buffer per thread, the blocks then moved into place) and on the same points in random
 * order (the buffered cell-order search):
 *  - the first setup of a new set, with every allocation failing in turn: the call
 *    returns MFREE_ERR_ALLOC with a message, the set is not set up, a retry without
 *    failures gives the lists of a one-thread set up without a hook, entry for entry;
 *  - a set already set up, its particles then drawn together (rows grow past the lists'
 *    capacity, so the search must allocate): every allocation of that setup failing in
 *    turn leaves the previous lists in place, unchanged (mfree.h: a failed setup changes
 *    nothing, but for the one-thread search that writes over its lists as it goes);
 * and every block allocated through the hook is returned once the set is destroyed.
 * No timing.
 */
#include "testutil.h"
#include "nbr_lists.h"

#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* A hook safe to call from several threads: allocations counted, bytes held tracked,
 * every allocation from g_fail_from on refused (g_fail_from < 0: none). */
static atomic_llong g_calls, g_frees, g_held, g_fail_from;

static void *oom_alloc(void *user, int64_t bytes) {
  (void)user;
  const long long k = atomic_fetch_add(&g_calls, 1);
  const long long from = atomic_load(&g_fail_from);
  if (from >= 0 && k >= from) {
    atomic_fetch_sub(&g_calls, 1);  /* a refused call allocates nothing */
    return NULL;
  }
  void *p = malloc((size_t)bytes);
  if (p) atomic_fetch_add(&g_held, bytes);
  return p;
}

static void oom_free(void *user, void *p, int64_t bytes) {
  (void)user;
  if (!p) return;
  atomic_fetch_add(&g_frees, 1);
  atomic_fetch_sub(&g_held, bytes);
  free(p);
}

typedef struct {
  int32_t n;
  double *x; /* AoS, 3 per point */
  double h;
} cloud_t;

static int cmp_key(const void *pa, const void *pb) {
  const double *a = pa, *b = pb;
  return a[0] < b[0] ? -1 : (a[0] > b[0] ? 1 : 0);
}

/* n clustered points (four blobs, sigma ~ 0.6, in a box of side 20) sorted by
 * (z slab, y slab, x) with slabs of about a grid cell: spatial order; ~40 neighbours
 * in the blobs. */
static cloud_t clustered(int32_t n, mfree_rng_t *r) {
  cloud_t c = {n, malloc(sizeof(double) * 3 * (size_t)n), 0.0};
  double *key = malloc(sizeof(double) * 4 * (size_t)n);
  assert_non_null(c.x);
  assert_non_null(key);
  double centre[4][3];
  for (int q = 0; q < 4; ++q)
    for (int d = 0; d < 3; ++d) centre[q][d] = 20.0 * mfree_rng_uniform(r);
  for (int32_t p = 0; p < n; ++p) {
    double *k = key + 4 * (size_t)p;
    for (int d = 0; d < 3; ++d) {
      double g = 0.0;
      for (int s = 0; s < 4; ++s) g += mfree_rng_uniform(r) - 0.5;
      k[1 + d] = centre[p % 4][d] + 1.2 * g;
    }
    k[0] = floor((k[3] + 10.0) / 0.15) * 1e6 + floor((k[2] + 10.0) / 0.15) * 1e3 + (k[1] + 10.0);
  }
  qsort(key, (size_t)n, 4 * sizeof(double), cmp_key);
  for (int32_t p = 0; p < n; ++p)
    for (int d = 0; d < 3; ++d) c.x[3 * (size_t)p + d] = key[4 * (size_t)p + 1 + d];
  free(key);
  const double rho = 0.25 * n / pow(2.0 * M_PI * 0.36, 1.5);
  c.h = 0.5 * cbrt(40.0 * 3.0 / (4.0 * M_PI * rho));
  return c;
}

/* The same points in a random order. */
static cloud_t shuffled(const cloud_t *c, mfree_rng_t *r) {
  cloud_t p = {c->n, malloc(sizeof(double) * 3 * (size_t)c->n), c->h};
  assert_non_null(p.x);
  memcpy(p.x, c->x, sizeof(double) * 3 * (size_t)c->n);
  for (int32_t k = c->n - 1; k > 0; --k) {
    int32_t j = (int32_t)(mfree_rng_uniform(r) * (k + 1));
    if (j > k) j = k;
    for (int d = 0; d < 3; ++d) {
      const double t = p.x[3 * (size_t)k + d];
      p.x[3 * (size_t)k + d] = p.x[3 * (size_t)j + d];
      p.x[3 * (size_t)j + d] = t;
    }
  }
  return p;
}

static mfree_particles_t *make_set(mfree_context_t *ctx, const cloud_t *c) {
  mfree_particles_t *ps = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, 3, c->n, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, c->x, MFREE_LAYOUT_AOS, 3, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_support(ps, &c->h, 0, MFREE_COPY));
  return ps;
}

/* The lists of c from a one-thread setup without a hook. */
static lists_t reference(const cloud_t *c) {
  mfree_context_t *ctx = NULL;
  assert_ok(NULL, mfree_context_create(&ctx));
  assert_ok(ctx, mfree_context_set_num_threads(ctx, 1));
  mfree_particles_t *ps = make_set(ctx, c);
  assert_ok(ctx, mfree_particles_setup(ps));
  lists_t g = lists_fetch(ctx, ps);
  mfree_particles_destroy(&ps);
  mfree_context_destroy(&ctx);
  return g;
}

static mfree_context_t *two_thread_context(void) {
  mfree_context_t *ctx = NULL;
  assert_ok(NULL, mfree_context_create(&ctx));
  assert_ok(ctx, mfree_context_set_num_threads(ctx, 2));
  assert_ok(ctx, mfree_context_set_allocator(ctx, oom_alloc, oom_free, NULL));
  return ctx;
}

/* First setup of a new set on two threads, every allocation failing in turn. */
static void first_setup_failing(const cloud_t *c) {
  lists_t ref = reference(c);
  mfree_context_t *ctx = two_thread_context();
  atomic_store(&g_fail_from, -1);
  mfree_particles_t *ps = make_set(ctx, c);
  const long long before = atomic_load(&g_calls);
  assert_ok(ctx, mfree_particles_setup(ps));
  const long long calls = atomic_load(&g_calls) - before;
  assert_true(calls > 0);
  lists_t g = lists_fetch(ctx, ps);
  assert_lists_equal(&g, &ref);
  lists_free(&g);
  mfree_particles_destroy(&ps);
  for (long long allow = 0; allow < calls; ++allow) {
    ps = make_set(ctx, c);
    atomic_store(&g_fail_from, atomic_load(&g_calls) + allow);
    assert_error(ctx, mfree_particles_setup(ps), MFREE_ERR_ALLOC, "memory");
    atomic_store(&g_fail_from, -1);
    int64_t nnz = 0;
    assert_error(ctx, mfree_particles_get_neighbor_nnz(ps, &nnz), MFREE_ERR_STATE, "not set up");
    assert_ok(ctx, mfree_particles_setup(ps));
    g = lists_fetch(ctx, ps);
    assert_lists_equal(&g, &ref);
    lists_free(&g);
    mfree_particles_destroy(&ps);
  }
  mfree_context_destroy(&ctx);
  assert_int_equal(atomic_load(&g_held), 0);
  assert_int_equal(atomic_load(&g_frees), atomic_load(&g_calls));
  lists_free(&ref);
}

/* A set up set whose particles draw together (x -> centre + 0.8 (x - centre): rows
 * grow by about 1 / 0.8^3 ~ 2x), set up again on two threads with every allocation
 * of that setup failing in turn: the old lists stay, unchanged. */
static void resetup_failing(const cloud_t *c) {
  cloud_t moved = {c->n, malloc(sizeof(double) * 3 * (size_t)c->n), c->h};
  assert_non_null(moved.x);
  double *x = moved.x; /* the set borrows x: the host moves its particles here */
  memcpy(x, c->x, sizeof(double) * 3 * (size_t)c->n);
  lists_t before_ref = reference(&moved);
  for (int64_t k = 0; k < 3 * (int64_t)c->n; ++k) x[k] = 10.0 + 0.8 * (c->x[k] - 10.0);
  lists_t after_ref = reference(&moved);
  assert_true(after_ref.rowptr[c->n] > before_ref.rowptr[c->n]);
  mfree_context_t *ctx = two_thread_context();
  atomic_store(&g_fail_from, -1);
  /* the number of allocations of the growing setup, from a clean run */
  memcpy(x, c->x, sizeof(double) * 3 * (size_t)c->n);
  mfree_particles_t *ps = make_set(ctx, &moved);
  assert_ok(ctx, mfree_particles_setup(ps));
  for (int64_t k = 0; k < 3 * (int64_t)c->n; ++k) x[k] = 10.0 + 0.8 * (c->x[k] - 10.0);
  long long calls = atomic_load(&g_calls);
  assert_ok(ctx, mfree_particles_setup(ps));
  calls = atomic_load(&g_calls) - calls;
  assert_true(calls > 0); /* the rows outgrew the lists */
  lists_t g = lists_fetch(ctx, ps);
  assert_lists_equal(&g, &after_ref);
  lists_free(&g);
  mfree_particles_destroy(&ps);
  for (long long allow = 0; allow < calls; ++allow) {
    memcpy(x, c->x, sizeof(double) * 3 * (size_t)c->n);
    ps = make_set(ctx, &moved);
    assert_ok(ctx, mfree_particles_setup(ps));
    for (int64_t k = 0; k < 3 * (int64_t)c->n; ++k) x[k] = 10.0 + 0.8 * (c->x[k] - 10.0);
    atomic_store(&g_fail_from, atomic_load(&g_calls) + allow);
    assert_error(ctx, mfree_particles_setup(ps), MFREE_ERR_ALLOC, "memory");
    atomic_store(&g_fail_from, -1);
    g = lists_fetch(ctx, ps);
    assert_lists_equal(&g, &before_ref);
    lists_free(&g);
    /* and a retry finds the new lists */
    assert_ok(ctx, mfree_particles_setup(ps));
    g = lists_fetch(ctx, ps);
    assert_lists_equal(&g, &after_ref);
    lists_free(&g);
    mfree_particles_destroy(&ps);
  }
  mfree_context_destroy(&ctx);
  assert_int_equal(atomic_load(&g_held), 0);
  assert_int_equal(atomic_load(&g_frees), atomic_load(&g_calls));
  lists_free(&before_ref);
  lists_free(&after_ref);
  free(moved.x);
}

/* Clustered points from the seed, in spatial order or shuffled, through one case. */
static void run_case(uint64_t seed, int shuffle, void (*body)(const cloud_t *)) {
  mfree_rng_t r;
  mfree_rng_seed(&r, seed);
  cloud_t c = clustered(4000, &r);
  if (shuffle) {
    cloud_t p = shuffled(&c, &r);
    body(&p);
    free(p.x);
  } else {
    body(&c);
  }
  free(c.x);
}

static void test_first_setup_spatial_order(void **state) {
  (void)state;
  run_case(2061, 0, first_setup_failing);
}

static void test_first_setup_random_order(void **state) {
  (void)state;
  run_case(2062, 1, first_setup_failing);
}

static void test_resetup_spatial_order(void **state) {
  (void)state;
  run_case(2063, 0, resetup_failing);
}

static void test_resetup_random_order(void **state) {
  (void)state;
  run_case(2064, 1, resetup_failing);
}

int main(void) {
  atomic_store(&g_fail_from, -1);
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_first_setup_spatial_order),
      cmocka_unit_test(test_first_setup_random_order),
      cmocka_unit_test(test_resetup_spatial_order),
      cmocka_unit_test(test_resetup_random_order),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
