/* The context's allocator hook (mfree_context_set_allocator): the neighbour lists and
 * shape-function tables come from it, every block goes back to the allocator that made
 * it, an allocation failure is MFREE_ERR_ALLOC with a message, and after the first
 * setup mfree_particles_update, mfree_approximant_update and mfree_approximant_apply
 * allocate nothing through the hook, for every method family, with one thread
 * and with two. Allocations through the C++ standard library, which the hook cannot see,
 * are counted by tests/heap/t433. */
#include <stdlib.h>
#include <string.h>

#include "count_alloc.h"
#include "testutil.h"


/* A jittered m^dim lattice, spacing 1, h = 1.3 (about 21 / 70 neighbours in 2D / 3D). */
static mfree_particles_t *lattice(mfree_context_t *ctx, int dim, int m, double **xout) {
  int n = 1;
  for (int d = 0; d < dim; ++d) n *= m;
  double *x = malloc(sizeof(double) * (size_t)(dim * n));
  mfree_rng_t r;
  mfree_rng_seed(&r, 11 + (uint64_t)dim);
  for (int p = 0; p < n; ++p) {
    int q = p;
    for (int c = 0; c < dim; ++c) {
      x[dim * p + c] = (q % m) + 0.3 * (2.0 * mfree_rng_uniform(&r) - 1.0);
      q /= m;
    }
  }
  const double h = 1.3, vol = 1.0;
  mfree_particles_t *ps = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, dim, n, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, dim, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_volumes(ps, &vol, 0, MFREE_COPY));
  *xout = x;
  return ps;
}

static void test_bad_arguments(void **state) {
  (void)state;
  counter_t c = {0, 0, 0, -1};
  assert_int_equal(mfree_context_set_allocator(NULL, count_alloc, count_free, &c), MFREE_ERR_NULL);
  mfree_context_t *ctx = NULL;
  assert_ok(ctx, mfree_context_create(&ctx));
  assert_error(ctx, mfree_context_set_allocator(ctx, count_alloc, NULL, &c), MFREE_ERR_ARG, "neither");
  assert_error(ctx, mfree_context_set_allocator(ctx, NULL, count_free, &c), MFREE_ERR_ARG, "neither");
  assert_ok(ctx, mfree_context_set_allocator(ctx, NULL, NULL, NULL));
  mfree_context_destroy(&ctx);
}

typedef struct {
  mfree_method_t method;
  int order; /* 0: the method's default */
  int flags;
} method_t;

static const method_t kMethods[] = {
    {MFREE_METHOD_SPH, 0, 7},
    {MFREE_METHOD_SHEPARD, 0, 7},
    {MFREE_METHOD_MLS, 1, 3},
    {MFREE_METHOD_MLS, 2, 7},
    {MFREE_METHOD_RKPM, 1, 3},
    {MFREE_METHOD_RANDLES_LIBERSKY, 0, 3},
    {MFREE_METHOD_KB_METHOD1, 0, 3},
    {MFREE_METHOD_KB_METHOD3, 0, 3},
    {MFREE_METHOD_SSPH, 2, 7},
    {MFREE_METHOD_MSPH, 2, 7},
    {MFREE_METHOD_JOHNSON_BEISSEL, 0, 3},
};

static void no_allocation_after_setup(int dim, int m, int threads) {
  counter_t c = {0, 0, 0, -1};
  mfree_context_t *ctx = NULL;
  assert_ok(ctx, mfree_context_create(&ctx));
  assert_ok(ctx, mfree_context_set_num_threads(ctx, threads));
  assert_ok(ctx, mfree_context_set_allocator(ctx, count_alloc, count_free, &c));
  double *x = NULL;
  mfree_particles_t *ps = lattice(ctx, dim, m, &x);
  assert_ok(ctx, mfree_particles_setup(ps));
  assert_true(c.calls > 0); /* the neighbour lists came from the hook */
  int32_t n = 0;
  assert_ok(ctx, mfree_particles_get_size(ps, &n, NULL));
  double *u = malloc(sizeof(double) * 3 * (size_t)n), *out = malloc(sizeof(double) * 18 * (size_t)n);
  for (int i = 0; i < 3 * n; ++i) u[i] = 0.01 * i;
  for (size_t k = 0; k < sizeof kMethods / sizeof kMethods[0]; ++k) {
    const method_t *me = &kMethods[k];
    mfree_approximant_t *a = NULL;
    assert_ok(ctx, mfree_approximant_create(ctx, ps, me->method, &a));
    if (me->order) assert_ok(ctx, mfree_approximant_set_order(a, me->order));
    assert_ok(ctx, mfree_approximant_set_derivatives(a, me->flags));
    const int64_t before = c.calls;
    assert_ok(ctx, mfree_approximant_setup(a));
    assert_true(c.calls > before); /* the tables came from the hook */
    const int64_t calls = c.calls, held = c.held;
    for (int rep = 0; rep < 2; ++rep) {
      assert_ok(ctx, mfree_particles_update(ps));
      assert_ok(ctx, mfree_approximant_update(a));
      assert_ok(ctx, mfree_approximant_apply(a, MFREE_OP_VALUE, 3, u, MFREE_LAYOUT_AOS, 3, out,
                                             MFREE_LAYOUT_AOS, 3));
      assert_ok(ctx, mfree_approximant_apply(a, MFREE_OP_GRADIENT, 3, u, MFREE_LAYOUT_SOA, n, out,
                                             MFREE_LAYOUT_AOS, 3 * dim));
      assert_ok(ctx, mfree_approximant_apply_add(a, MFREE_OP_DIVERGENCE, dim, u, MFREE_LAYOUT_AOS, 3,
                                                 out, MFREE_LAYOUT_AOS, 1));
      if (me->flags & MFREE_DERIV_HESSIAN) {
        assert_ok(ctx, mfree_approximant_apply(a, MFREE_OP_HESSIAN, 3, u, MFREE_LAYOUT_AOS, 3, out,
                                               MFREE_LAYOUT_AOS, 18));
        assert_ok(ctx, mfree_approximant_apply(a, MFREE_OP_LAPLACIAN, 1, u, MFREE_LAYOUT_AOS, 3, out,
                                               MFREE_LAYOUT_AOS, 1));
      }
    }
    if (c.calls != calls || c.held != held)
      fail_msg("method %d, dim %d, %d threads: %lld allocations (%lld bytes) in particle/approximant "
               "update or apply",
               (int)me->method, dim, threads, (long long)(c.calls - calls), (long long)(c.held - held));
    mfree_approximant_destroy(&a);
  }
  mfree_particles_destroy(&ps);
  mfree_context_destroy(&ctx);
  /* everything went back to the hook */
  assert_int_equal(c.held, 0);
  assert_int_equal(c.frees, c.calls);
  free(u);
  free(out);
  free(x);
}

static void test_no_allocation_2d(void **state) {
  (void)state;
  no_allocation_after_setup(2, 24, 1);
  no_allocation_after_setup(2, 60, 2); /* 3600 sites: above the threading threshold */
}

static void test_no_allocation_3d(void **state) {
  (void)state;
  no_allocation_after_setup(3, 9, 1);
#ifdef __OPTIMIZE__ /* 2744 sites, threaded: seconds unoptimised under sanitizers */
  no_allocation_after_setup(3, 14, 2);
#endif
}

/* Blocks go back to the allocator that made them, after the hook changed. */
static void test_blocks_return_home(void **state) {
  (void)state;
  counter_t a = {0, 0, 0, -1}, b = {0, 0, 0, -1};
  mfree_context_t *ctx = NULL;
  assert_ok(ctx, mfree_context_create(&ctx));
  assert_ok(ctx, mfree_context_set_allocator(ctx, count_alloc, count_free, &a));
  double *x = NULL;
  mfree_particles_t *ps = lattice(ctx, 2, 12, &x);
  mfree_approximant_t *ap = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, &ap));
  assert_ok(ctx, mfree_approximant_setup(ap));
  assert_true(a.held > 0);
  assert_ok(ctx, mfree_context_set_allocator(ctx, count_alloc, count_free, &b));
  assert_ok(ctx, mfree_approximant_update(ap)); /* same sizes: nothing from b */
  assert_int_equal(b.calls, 0);
  assert_ok(ctx, mfree_particles_setup(ps)); /* same sizes: the lists' storage is reused */
  assert_int_equal(b.calls, 0);
  mfree_approximant_t *ap2 = NULL; /* a new approximant: its tables from b */
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, &ap2));
  assert_ok(ctx, mfree_approximant_setup(ap2));
  assert_true(b.calls > 0);
  assert_ok(ctx, mfree_approximant_setup(ap));
  assert_ok(ctx, mfree_context_set_allocator(ctx, NULL, NULL, NULL));
  mfree_approximant_destroy(&ap2); /* b's blocks back to b, a's (ap, the lists) to a */
  mfree_approximant_destroy(&ap);
  mfree_particles_destroy(&ps);
  mfree_context_destroy(&ctx);
  assert_int_equal(a.held, 0);
  assert_int_equal(b.held, 0);
  assert_int_equal(a.frees, a.calls);
  assert_int_equal(b.frees, b.calls);
  free(x);
}

/* A failing allocator: MFREE_ERR_ALLOC with a message, nothing leaked, and the objects
 * work again with a working allocator. */
static void test_allocation_failure(void **state) {
  (void)state;
  counter_t c = {0, 0, 0, -1};
  mfree_context_t *ctx = NULL;
  assert_ok(ctx, mfree_context_create(&ctx));
  double *x = NULL;
  mfree_particles_t *ps = lattice(ctx, 2, 12, &x);
  assert_ok(ctx, mfree_particles_setup(ps));
  mfree_approximant_t *ap = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, &ap));
  for (int64_t allow = 0; allow < 4; ++allow) {
    c.calls = 0;
    c.fail_after = allow;
    assert_ok(ctx, mfree_context_set_allocator(ctx, count_alloc, count_free, &c));
    assert_error(ctx, mfree_approximant_setup(ap), MFREE_ERR_ALLOC, "memory");
  }
  c.fail_after = -1;
  assert_ok(ctx, mfree_approximant_setup(ap));
  mfree_approximant_destroy(&ap);
  mfree_particles_destroy(&ps);
  mfree_context_destroy(&ctx);
  assert_int_equal(c.held, 0);
  free(x);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_bad_arguments),
      cmocka_unit_test(test_no_allocation_2d),
      cmocka_unit_test(test_no_allocation_3d),
      cmocka_unit_test(test_blocks_return_home),
      cmocka_unit_test(test_allocation_failure),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
