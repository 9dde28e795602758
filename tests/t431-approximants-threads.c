/* Results do not depend on the thread count: neighbour lists, shape-function
 * tables (at the particles and at host points), site data and applied operators are
 * bitwise identical with 1 and 2 threads (and with 0 = all cores), for every method
 * family, in 2D and 3D. Sets are above the size from which mfree starts threads. Without
 * OpenMP every count runs serially and the test still holds. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"

typedef struct {
  mfree_method_t method;
  int order;
  int flags;
  int points; /* also at host points */
} method_t;

static const method_t kMethods[] = {
    {MFREE_METHOD_SPH, 0, 7, 1},           {MFREE_METHOD_SHEPARD, 0, 3, 1},
    {MFREE_METHOD_MLS, 1, 3, 1},           {MFREE_METHOD_MLS, 2, 7, 1},
    {MFREE_METHOD_RKPM, 2, 3, 0},          {MFREE_METHOD_RANDLES_LIBERSKY, 0, 3, 0},
    {MFREE_METHOD_KB_METHOD1, 0, 3, 1},    {MFREE_METHOD_KB_METHOD2, 2, 7, 0},
    {MFREE_METHOD_SSPH, 2, 7, 1},          {MFREE_METHOD_MSPH, 2, 3, 0},
    {MFREE_METHOD_JOHNSON_BEISSEL, 0, 3, 0},
};

typedef struct {
  int64_t nnz;
  int64_t *rowptr;
  int32_t *cols;
  double *tab[3]; /* value, one gradient component, one Hessian component */
  int32_t *status;
  double *cond;
  double *grad3; /* gradient of a 3-vector */
} result_t;

static void result_free(result_t *r) {
  free(r->rowptr);
  free(r->cols);
  for (int k = 0; k < 3; ++k) free(r->tab[k]);
  free(r->status);
  free(r->cond);
  free(r->grad3);
  memset(r, 0, sizeof *r);
}

typedef struct {
  int dim, n, npts;
  double *x, *pts, *u;
} cloud_t;

static cloud_t make_cloud(int dim, int m) {
  cloud_t c = {dim, 1, 0, NULL, NULL, NULL};
  for (int d = 0; d < dim; ++d) c.n *= m;
  c.x = malloc(sizeof(double) * (size_t)(dim * c.n));
  mfree_rng_t r;
  mfree_rng_seed(&r, 5 + (uint64_t)dim);
  for (int p = 0; p < c.n; ++p) {
    int q = p;
    for (int k = 0; k < dim; ++k) {
      c.x[dim * p + k] = (q % m) + 0.35 * (2.0 * mfree_rng_uniform(&r) - 1.0);
      q /= m;
    }
  }
  /* host points inside the cloud, as many as the particles */
  c.npts = c.n;
  c.pts = malloc(sizeof(double) * (size_t)(dim * c.npts));
  for (int i = 0; i < dim * c.npts; ++i) c.pts[i] = 1.0 + (m - 3.0) * mfree_rng_uniform(&r);
  c.u = malloc(sizeof(double) * 3 * (size_t)c.n);
  for (int i = 0; i < 3 * c.n; ++i) c.u[i] = mfree_rng_uniform(&r);
  return c;
}

static void compute(const cloud_t *c, const method_t *me, int threads, int at_points, result_t *res) {
  mfree_context_t *ctx = NULL;
  assert_ok(ctx, mfree_context_create(&ctx));
  assert_ok(ctx, mfree_context_set_num_threads(ctx, threads));
  const double h = 1.3, vol = 1.0;
  mfree_particles_t *ps = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, c->dim, c->n, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, c->x, MFREE_LAYOUT_AOS, c->dim, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_volumes(ps, &vol, 0, MFREE_COPY));
  mfree_approximant_t *a = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, me->method, &a));
  if (me->order) assert_ok(ctx, mfree_approximant_set_order(a, me->order));
  assert_ok(ctx, mfree_approximant_set_derivatives(a, me->flags));
  if (at_points)
    assert_ok(ctx, mfree_approximant_set_points(a, c->npts, c->pts, MFREE_LAYOUT_AOS, c->dim, &h, 0,
                                                MFREE_BORROW));
  assert_ok(ctx, mfree_approximant_setup(a));
  assert_ok(ctx, mfree_approximant_update(a));
  int32_t ns = 0;
  assert_ok(ctx, mfree_approximant_get_num_sites(a, &ns));
  assert_ok(ctx, mfree_approximant_get_nnz(a, &res->nnz));
  res->rowptr = malloc(sizeof(int64_t) * (size_t)(ns + 1));
  res->cols = malloc(sizeof(int32_t) * (size_t)res->nnz + 4);
  const int derivs[3] = {MFREE_DERIV_VALUE, MFREE_DERIV_GRADIENT, MFREE_DERIV_HESSIAN};
  const int comps[3] = {0, c->dim - 1, c->dim == 2 ? 1 : 4};
  for (int k = 0; k < 3; ++k) {
    if (!(me->flags & derivs[k])) continue;
    res->tab[k] = malloc(sizeof(double) * (size_t)res->nnz + 8);
    assert_ok(ctx, mfree_approximant_assemble_csr(a, (mfree_deriv_t)derivs[k], comps[k], res->rowptr, res->cols, res->tab[k]));
  }
  res->status = malloc(sizeof(int32_t) * (size_t)ns);
  res->cond = malloc(sizeof(double) * (size_t)ns);
  assert_ok(ctx, mfree_approximant_get_site_status(a, res->status, NULL));
  assert_ok(ctx, mfree_approximant_get_condition(a, res->cond));
  res->grad3 = malloc(sizeof(double) * 9 * (size_t)ns);
  assert_ok(ctx, mfree_approximant_apply(a, MFREE_OP_GRADIENT, 3, c->u, MFREE_LAYOUT_AOS, 3, res->grad3,
                                         MFREE_LAYOUT_AOS, 3 * c->dim));
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
  mfree_context_destroy(&ctx);
}

static void same(const result_t *a, const result_t *b, int ns, int dim, const char *what) {
  if (a->nnz != b->nnz) fail_msg("%s: nnz %lld vs %lld", what, (long long)a->nnz, (long long)b->nnz);
  if (memcmp(a->rowptr, b->rowptr, sizeof(int64_t) * (size_t)(ns + 1)) ||
      memcmp(a->cols, b->cols, sizeof(int32_t) * (size_t)a->nnz))
    fail_msg("%s: patterns differ", what);
  for (int k = 0; k < 3; ++k)
    if (a->tab[k] && memcmp(a->tab[k], b->tab[k], sizeof(double) * (size_t)a->nnz))
      fail_msg("%s: table %d differs", what, k);
  if (memcmp(a->status, b->status, sizeof(int32_t) * (size_t)ns) ||
      memcmp(a->cond, b->cond, sizeof(double) * (size_t)ns))
    fail_msg("%s: site data differ", what);
  if (memcmp(a->grad3, b->grad3, sizeof(double) * 3 * (size_t)dim * (size_t)ns))
    fail_msg("%s: applied gradients differ", what);
}

/* Unoptimised (sanitizer) builds check every other method, so that the test stays a
 * few seconds there; optimised builds check all. */
#ifdef __OPTIMIZE__
static const size_t kStep = 1;
#else
static const size_t kStep = 2;
#endif

static void check_dim(int dim, int m) {
  cloud_t c = make_cloud(dim, m);
  for (size_t k = 0; k < sizeof kMethods / sizeof kMethods[0]; k += kStep)
    for (int at = 0; at <= kMethods[k].points; ++at) {
      result_t r1 = {0}, r2 = {0}, r0 = {0};
      compute(&c, &kMethods[k], 1, at, &r1);
      compute(&c, &kMethods[k], 2, at, &r2);
      const int all = k == 2; /* 0 = all cores, for one method */
      if (all) compute(&c, &kMethods[k], 0, at, &r0);
      char what[96];
      snprintf(what, sizeof what, "%dD method %d order %d%s", dim, (int)kMethods[k].method,
               kMethods[k].order, at ? " at points" : "");
      same(&r1, &r2, at ? c.npts : c.n, dim, what);
      if (all) same(&r1, &r0, at ? c.npts : c.n, dim, what);
      result_free(&r1);
      result_free(&r2);
      result_free(&r0);
    }
  free(c.x);
  free(c.pts);
  free(c.u);
}

/* The neighbour lists themselves, and under the symmetric conventions. */
static void test_neighbors(void **state) {
  (void)state;
  cloud_t c = make_cloud(2, 48);
  double *h = malloc(sizeof(double) * (size_t)c.n);
  for (int i = 0; i < c.n; ++i) h[i] = 0.9 + 0.6 * c.u[i];
  /* the fourth: gather with one h for all, sorted by transposition like the symmetric
   * conventions (the first is sorted row by row) */
  const int conv[4] = {MFREE_SEARCH_GATHER, MFREE_SEARCH_SYMMETRIC_MAX, MFREE_SEARCH_SYMMETRIC_MEAN,
                       MFREE_SEARCH_GATHER};
  for (int k = 0; k < 4; ++k) {
    int64_t *rp[2];
    int32_t *cl[2];
    int64_t nnz[2];
    for (int t = 0; t < 2; ++t) {
      mfree_context_t *ctx = NULL;
      assert_ok(ctx, mfree_context_create(&ctx));
      assert_ok(ctx, mfree_context_set_num_threads(ctx, t + 1));
      mfree_particles_t *ps = NULL;
      assert_ok(ctx, mfree_particles_create(ctx, 2, c.n, &ps));
      assert_ok(ctx, mfree_particles_set_positions(ps, c.x, MFREE_LAYOUT_AOS, 2, MFREE_BORROW));
      assert_ok(ctx, mfree_particles_set_support(ps, h, k == 3 ? 0 : 1, MFREE_BORROW));
      assert_ok(ctx, mfree_particles_set_search(ps, (mfree_search_t)conv[k], 2.0));
      assert_ok(ctx, mfree_particles_setup(ps));
      assert_ok(ctx, mfree_particles_get_neighbor_nnz(ps, &nnz[t]));
      rp[t] = malloc(sizeof(int64_t) * (size_t)(c.n + 1));
      cl[t] = malloc(sizeof(int32_t) * (size_t)nnz[t]);
      assert_ok(ctx, mfree_particles_get_neighbors(ps, rp[t], cl[t]));
      mfree_particles_destroy(&ps);
      mfree_context_destroy(&ctx);
    }
    assert_int_equal(nnz[0], nnz[1]);
    assert_memory_equal(rp[0], rp[1], sizeof(int64_t) * (size_t)(c.n + 1));
    assert_memory_equal(cl[0], cl[1], sizeof(int32_t) * (size_t)nnz[0]);
    for (int t = 0; t < 2; ++t) {
      free(rp[t]);
      free(cl[t]);
    }
  }
  free(h);
  free(c.x);
  free(c.pts);
  free(c.u);
}

static void test_tables_2d(void **state) {
  (void)state;
  check_dim(2, 48); /* 2304 sites */
}

static void test_tables_3d(void **state) {
  (void)state;
  check_dim(3, 13); /* 2197 sites */
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_neighbors),
      cmocka_unit_test(test_tables_2d),
      cmocka_unit_test(test_tables_3d),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
