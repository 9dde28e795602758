/* Approximants: every bad argument (documented status + message, object still usable),
 * degenerate neighbourhoods (positive status, failed sites reported, zero rows, never
 * NaN), the lower-order fallback, and reference counting. */
#include <math.h>
#include <string.h>

#include "testutil.h"

static mfree_context_t *ctx;
static int setup(void **s) { (void)s; return mfree_context_create(&ctx) != MFREE_SUCCESS; }
static int teardown(void **s) { (void)s; return mfree_context_destroy(&ctx) != MFREE_SUCCESS; }

enum { M = 8, N = M * M };
static double X[2 * N];
static const double H = 1.5 / M, VOL = 1.0 / N;

static mfree_particles_t *lattice(void) {
  mfree_rng_t r;
  mfree_rng_seed(&r, 7);
  for (int j = 0; j < M; ++j)
    for (int i = 0; i < M; ++i) {
      X[2 * (j * M + i)] = (i + 0.5 + 0.3 * (2 * mfree_rng_uniform(&r) - 1)) / M;
      X[2 * (j * M + i) + 1] = (j + 0.5 + 0.3 * (2 * mfree_rng_uniform(&r) - 1)) / M;
    }
  mfree_particles_t *ps = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, 2, N, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, X, MFREE_LAYOUT_AOS, 2, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_support(ps, &H, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_volumes(ps, &VOL, 0, MFREE_COPY));
  return ps;
}

static void test_create_and_setters(void **s) {
  (void)s;
  mfree_particles_t *ps = lattice();
  mfree_approximant_t *a = NULL;
  assert_int_equal(mfree_approximant_create(NULL, ps, MFREE_METHOD_MLS, &a), MFREE_ERR_NULL);
  assert_error(ctx, mfree_approximant_create(ctx, NULL, MFREE_METHOD_MLS, &a), MFREE_ERR_NULL,
               "particle set");
  assert_error(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, NULL), MFREE_ERR_NULL, "NULL");
  assert_error(ctx, mfree_approximant_create(ctx, ps, (mfree_method_t)0, &a), MFREE_ERR_ARG,
               "unknown method");
  assert_error(ctx, mfree_approximant_create(ctx, ps, (mfree_method_t)14, &a), MFREE_ERR_ARG,
               "unknown method");
  assert_null(a);
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, &a));

  /* kernel */
  assert_error(ctx, mfree_approximant_set_kernel(a, (mfree_kernel_t)0, 0.0), MFREE_ERR_ARG,
               "unknown kernel");
  assert_error(ctx, mfree_approximant_set_kernel(a, (mfree_kernel_t)77, 0.0), MFREE_ERR_ARG,
               "unknown kernel");
  assert_error(ctx, mfree_approximant_set_kernel(a, MFREE_KERNEL_REVISED_SUPER_GAUSS, -1.0),
               MFREE_ERR_ARG, "parameter");
  /* order: MLS 0..3 */
  assert_error(ctx, mfree_approximant_set_order(a, 4), MFREE_ERR_UNSUPPORTED, "orders 0..3");
  assert_error(ctx, mfree_approximant_set_order(a, -1), MFREE_ERR_UNSUPPORTED, "orders 0..3");
  /* derivative flags */
  assert_error(ctx, mfree_approximant_set_derivatives(a, 0), MFREE_ERR_ARG, "flags");
  assert_error(ctx, mfree_approximant_set_derivatives(a, 8), MFREE_ERR_ARG, "flags");
  assert_error(ctx, mfree_approximant_set_fallback(a, (mfree_fallback_t)3), MFREE_ERR_ARG,
               "fallback");

  /* per-method restrictions */
  struct { mfree_method_t m; int bad_order; } fixed[] = {
      {MFREE_METHOD_SPH, 1},          {MFREE_METHOD_SHEPARD, 1},
      {MFREE_METHOD_JOHNSON_BEISSEL, 2}, {MFREE_METHOD_RANDLES_LIBERSKY, 0},
      {MFREE_METHOD_KB_METHOD1, 2},   {MFREE_METHOD_KB_METHOD3, 0}};
  for (size_t k = 0; k < sizeof fixed / sizeof fixed[0]; ++k) {
    mfree_approximant_t *b = NULL;
    assert_ok(ctx, mfree_approximant_create(ctx, ps, fixed[k].m, &b));
    assert_error(ctx, mfree_approximant_set_order(b, fixed[k].bad_order), MFREE_ERR_UNSUPPORTED,
                 "fixed order");
    mfree_approximant_destroy(&b);
  }
  /* Hessians from methods that provide none (e.g. Johnson-Beissel) */
  const mfree_method_t no_hess[] = {MFREE_METHOD_SPH_SYMMETRIC, MFREE_METHOD_JOHNSON_BEISSEL,
                                    MFREE_METHOD_RANDLES_LIBERSKY, MFREE_METHOD_KB_METHOD1,
                                    MFREE_METHOD_KB_METHOD3};
  for (size_t k = 0; k < sizeof no_hess / sizeof no_hess[0]; ++k) {
    mfree_approximant_t *b = NULL;
    assert_ok(ctx, mfree_approximant_create(ctx, ps, no_hess[k], &b));
    assert_error(ctx, mfree_approximant_set_derivatives(b, MFREE_DERIV_VALUE | MFREE_DERIV_HESSIAN),
                 MFREE_ERR_UNSUPPORTED, "no second derivatives");
    mfree_approximant_destroy(&b);
  }
  /* SSPH of order 1 has no second-derivative shape functions: caught at setup */
  {
    mfree_approximant_t *b = NULL;
    assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_SSPH, &b));
    assert_ok(ctx, mfree_approximant_set_order(b, 1));
    assert_ok(ctx, mfree_approximant_set_derivatives(b, MFREE_DERIV_HESSIAN));
    assert_error(ctx, mfree_approximant_setup(b), MFREE_ERR_UNSUPPORTED, "order 1");
    assert_ok(ctx, mfree_approximant_set_order(b, 2));
    assert_ok(ctx, mfree_approximant_setup(b));
    mfree_approximant_destroy(&b);
  }
  /* kernels that cannot be differentiated (001 Sect. 6.2) */
  {
    mfree_approximant_t *b = NULL;
    assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_RANDLES_LIBERSKY, &b));
    assert_ok(ctx, mfree_approximant_set_kernel(b, MFREE_KERNEL_LINEAR, 0.0));
    assert_error(ctx, mfree_approximant_setup(b), MFREE_ERR_UNSUPPORTED, "linear kernel");
    mfree_approximant_destroy(&b);
    assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MSPH, &b));
    assert_ok(ctx, mfree_approximant_set_kernel(b, MFREE_KERNEL_QUADRATIC, 0.0));
    assert_error(ctx, mfree_approximant_setup(b), MFREE_ERR_UNSUPPORTED, "second derivative");
    mfree_approximant_destroy(&b);
    /* SSPH never differentiates the kernel: the linear kernel works */
    assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_SSPH, &b));
    assert_ok(ctx, mfree_approximant_set_kernel(b, MFREE_KERNEL_LINEAR, 0.0));
    assert_ok(ctx, mfree_approximant_set_derivatives(b, 7));
    assert_ok(ctx, mfree_approximant_setup(b));
    mfree_approximant_destroy(&b);
  }
  /* particles-only methods refuse host points */
  {
    mfree_approximant_t *b = NULL;
    const double p[2] = {0.5, 0.5};
    assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_JOHNSON_BEISSEL, &b));
    assert_error(ctx, mfree_approximant_set_points(b, 1, p, MFREE_LAYOUT_AOS, 2, &H, 0, MFREE_COPY),
                 MFREE_ERR_UNSUPPORTED, "particles only");
    mfree_approximant_destroy(&b);
  }
  /* kernel support larger than the search radius */
  {
    mfree_approximant_t *b = NULL;
    assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_SHEPARD, &b));
    assert_ok(ctx, mfree_approximant_set_kernel(b, MFREE_KERNEL_QUINTIC_SPLINE, 0.0));
    assert_error(ctx, mfree_approximant_setup(b), MFREE_ERR_MISMATCH, "search radius");
    assert_ok(ctx, mfree_particles_set_search(ps, MFREE_SEARCH_GATHER, 3.0));
    assert_ok(ctx, mfree_approximant_setup(b));
    assert_ok(ctx, mfree_particles_set_search(ps, MFREE_SEARCH_GATHER, 2.0));
    assert_ok(ctx, mfree_particles_setup(ps));
    mfree_approximant_destroy(&b);
  }
  /* after all the refusals, a still working approximant */
  assert_ok(ctx, mfree_approximant_setup(a));
  double fe = 1, de = 1;
  assert_ok(ctx, mfree_approximant_check_reproduction(a, 1, &fe, &de));
  assert_true(fe < 1e-12 && de < 1e-12);
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
}

static void test_state_and_apply_args(void **s) {
  (void)s;
  mfree_particles_t *ps = lattice();
  mfree_approximant_t *a = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, &a));
  double u[N], out[2 * N];
  for (int i = 0; i < N; ++i) u[i] = 1.0 + X[2 * i] - 2.0 * X[2 * i + 1];
  int32_t ns = -1;
  int64_t nnz = -1;
  double fe, de;
  /* before setup */
  assert_error(ctx, mfree_approximant_apply(a, MFREE_OP_VALUE, 1, u, MFREE_LAYOUT_AOS, 1, out,
                                            MFREE_LAYOUT_AOS, 1),
               MFREE_ERR_STATE, "not set up");
  assert_error(ctx, mfree_approximant_get_num_sites(a, &ns), MFREE_ERR_STATE, "not set up");
  assert_error(ctx, mfree_approximant_get_nnz(a, &nnz), MFREE_ERR_STATE, "not set up");
  assert_error(ctx, mfree_approximant_update(a), MFREE_ERR_STATE, "before setup");
  assert_error(ctx, mfree_approximant_check_reproduction(a, 1, &fe, &de), MFREE_ERR_STATE, "not set up");
  int32_t st[N];
  assert_error(ctx, mfree_approximant_get_site_status(a, st, NULL), MFREE_ERR_STATE, "not set up");

  assert_ok(ctx, mfree_approximant_setup(a));
  /* bad apply arguments */
  assert_error(ctx, mfree_approximant_apply(a, (mfree_op_t)9, 1, u, MFREE_LAYOUT_AOS, 1, out,
                                            MFREE_LAYOUT_AOS, 1),
               MFREE_ERR_ARG, "unknown operator");
  assert_error(ctx, mfree_approximant_apply(a, MFREE_OP_VALUE, 0, u, MFREE_LAYOUT_AOS, 1, out,
                                            MFREE_LAYOUT_AOS, 1),
               MFREE_ERR_ARG, "ncomp");
  assert_error(ctx, mfree_approximant_apply(a, MFREE_OP_VALUE, 1, NULL, MFREE_LAYOUT_AOS, 1, out,
                                            MFREE_LAYOUT_AOS, 1),
               MFREE_ERR_NULL, "u is NULL");
  assert_error(ctx, mfree_approximant_apply(a, MFREE_OP_VALUE, 1, u, MFREE_LAYOUT_AOS, 1, NULL,
                                            MFREE_LAYOUT_AOS, 1),
               MFREE_ERR_NULL, "output");
  assert_error(ctx, mfree_approximant_apply(a, MFREE_OP_VALUE, 2, u, MFREE_LAYOUT_AOS, 1, out,
                                            MFREE_LAYOUT_AOS, 2),
               MFREE_ERR_ARG, "leading dimension of u");
  assert_error(ctx, mfree_approximant_apply(a, MFREE_OP_VALUE, 1, u, MFREE_LAYOUT_SOA, N - 1, out,
                                            MFREE_LAYOUT_AOS, 1),
               MFREE_ERR_ARG, "leading dimension of u");
  assert_error(ctx, mfree_approximant_apply(a, MFREE_OP_GRADIENT, 1, u, MFREE_LAYOUT_AOS, 1, out,
                                            MFREE_LAYOUT_AOS, 1),
               MFREE_ERR_ARG, "leading dimension of out");
  assert_error(ctx, mfree_approximant_apply(a, MFREE_OP_VALUE, 1, u, (mfree_layout_t)5, 1, out,
                                            MFREE_LAYOUT_AOS, 1),
               MFREE_ERR_ARG, "layout");
  assert_error(ctx, mfree_approximant_apply(a, MFREE_OP_DIVERGENCE, 1, u, MFREE_LAYOUT_AOS, 1, out,
                                            MFREE_LAYOUT_AOS, 1),
               MFREE_ERR_MISMATCH, "divergence");
  assert_error(ctx, mfree_approximant_apply(a, MFREE_OP_HESSIAN, 1, u, MFREE_LAYOUT_AOS, 1, out,
                                            MFREE_LAYOUT_AOS, 3),
               MFREE_ERR_STATE, "Hessian table was not built");
  assert_int_equal(mfree_approximant_apply(NULL, MFREE_OP_VALUE, 1, u, MFREE_LAYOUT_AOS, 1, out,
                                           MFREE_LAYOUT_AOS, 1),
                   MFREE_ERR_NULL);
  /* exports */
  int64_t rp[N + 1];
  assert_error(ctx, mfree_approximant_assemble_csr(a, MFREE_DERIV_GRADIENT, 2, rp, NULL, NULL),
               MFREE_ERR_ARG, "component");
  assert_error(ctx, mfree_approximant_assemble_csr(a, MFREE_DERIV_HESSIAN, 0, rp, NULL, NULL),
               MFREE_ERR_STATE, "not built");
  assert_error(ctx, mfree_approximant_assemble_csr(a, (mfree_deriv_t)3, 0, rp, NULL, NULL),
               MFREE_ERR_ARG, "deriv");
  assert_error(ctx, mfree_approximant_assemble_csr(a, MFREE_DERIV_VALUE, 0, NULL, NULL, NULL),
               MFREE_ERR_NULL, "NULL");
  assert_error(ctx, mfree_approximant_check_reproduction(a, 4, &fe, &de), MFREE_ERR_ARG, "order");
  assert_error(ctx, mfree_approximant_check_reproduction(a, 1, NULL, &de), MFREE_ERR_NULL, "NULL");

  /* the failed calls changed nothing: a linear field is still reproduced */
  assert_ok(ctx, mfree_approximant_apply(a, MFREE_OP_GRADIENT, 1, u, MFREE_LAYOUT_AOS, 1, out,
                                         MFREE_LAYOUT_AOS, 2));
  for (int i = 0; i < N; ++i) {
    assert_true(fabs(out[2 * i] - 1.0) < 1e-12);
    assert_true(fabs(out[2 * i + 1] + 2.0) < 1e-12);
  }
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
}

/* The approximant keeps its particle set (and context) alive. */
static void test_refcount(void **s) {
  (void)s;
  mfree_context_t *c2 = NULL;
  assert_ok(NULL, mfree_context_create(&c2));
  mfree_particles_t *ps = NULL;
  const double h = 1.5 / M, v = 1.0 / N;
  mfree_particles_t *filler = lattice(); /* fills X */
  mfree_particles_destroy(&filler);
  assert_ok(c2, mfree_particles_create(c2, 2, N, &ps));
  assert_ok(c2, mfree_particles_set_positions(ps, X, MFREE_LAYOUT_AOS, 2, MFREE_COPY));
  assert_ok(c2, mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  assert_ok(c2, mfree_particles_set_volumes(ps, &v, 0, MFREE_COPY));
  mfree_approximant_t *a = NULL;
  assert_ok(c2, mfree_approximant_create(c2, ps, MFREE_METHOD_RKPM, &a));
  assert_ok(c2, mfree_particles_destroy(&ps));
  assert_ok(c2, mfree_context_destroy(&c2));
  assert_null(ps);
  /* both destroyed by the host: setup still works on the kept objects */
  assert_int_equal(mfree_approximant_setup(a), MFREE_SUCCESS);
  double fe = 1, de = 1;
  assert_int_equal(mfree_approximant_check_reproduction(a, 2, &fe, &de), MFREE_SUCCESS);
  assert_true(fe < 1e-12 && de < 1e-10);
  assert_int_equal(mfree_approximant_destroy(&a), MFREE_SUCCESS);
  assert_null(a);
  assert_int_equal(mfree_approximant_destroy(&a), MFREE_SUCCESS);
  assert_int_equal(mfree_approximant_destroy(NULL), MFREE_SUCCESS);
}

static int all_finite(const double *v, int64_t n) {
  for (int64_t i = 0; i < n; ++i)
    if (!isfinite(v[i])) return 0;
  return 1;
}

/* Particles on a line in 2D, coincident particles, an isolated particle: positive status,
 * failed sites reported, zero rows, no NaN; with the fallback every site is usable. */
static void test_degenerate(void **s) {
  (void)s;
  enum { K = 12 };
  double x[2 * K];
  for (int i = 0; i < 8; ++i) { /* 8 particles on the line y = x */
    x[2 * i] = 0.1 * i;
    x[2 * i + 1] = 0.1 * i;
  }
  x[16] = 2.0; x[17] = 2.0;     /* 8 and 9 coincident, far away */
  x[18] = 2.0; x[19] = 2.0;
  x[20] = 2.05; x[21] = 2.0;    /* 10 near them */
  x[22] = 9.0; x[23] = 9.0;     /* 11 isolated */
  const double h = 0.12, v = 0.01;
  mfree_particles_t *ps = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, 2, K, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 2, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_volumes(ps, &v, 0, MFREE_COPY));

  const mfree_method_t methods[] = {MFREE_METHOD_MLS,        MFREE_METHOD_RKPM,
                                    MFREE_METHOD_SSPH,       MFREE_METHOD_MSPH,
                                    MFREE_METHOD_KB_METHOD1, MFREE_METHOD_KB_METHOD2,
                                    MFREE_METHOD_KB_METHOD3, MFREE_METHOD_RANDLES_LIBERSKY,
                                    MFREE_METHOD_JOHNSON_BEISSEL};
  for (size_t m = 0; m < sizeof methods / sizeof methods[0]; ++m) {
    mfree_approximant_t *a = NULL;
    assert_ok(ctx, mfree_approximant_create(ctx, ps, methods[m], &a));
    mfree_status_t st = mfree_approximant_setup(a);
    if (st != MFREE_FAIL_SINGULAR && st != MFREE_FAIL_NEIGHBORS)
      fail_msg("method %d: setup returned %d, expected a positive failure", (int)methods[m], (int)st);
    char msg[512];
    mfree_context_get_last_error(ctx, NULL, msg, sizeof msg);
    assert_non_null(strstr(msg, "site"));
    int32_t status[K], nf = 0, order[K];
    assert_ok(ctx, mfree_approximant_get_site_status(a, status, &nf));
    assert_true(nf >= 2);
    /* the isolated particle 11 fails for every method with a linear basis or better */
    assert_true(status[11] != 0);
    /* failed rows are zero, every output finite */
    int64_t nnz = 0;
    assert_ok(ctx, mfree_approximant_get_nnz(a, &nnz));
    int64_t rp[K + 1];
    int32_t cols[K * K];
    double vals[K * K];
    assert_ok(ctx, mfree_approximant_assemble_csr(a, MFREE_DERIV_GRADIENT, 0, rp, cols, vals));
    assert_true(all_finite(vals, nnz));
    for (int i = 0; i < K; ++i)
      if (status[i])
        for (int64_t k = rp[i]; k < rp[i + 1]; ++k) assert_true(vals[k] == 0.0);
    assert_ok(ctx, mfree_approximant_get_site_order(a, order));
    for (int i = 0; i < K; ++i) assert_true((order[i] == -1) == (status[i] != 0));

    /* fallback: every site now has usable rows, reported by a lower order */
    assert_ok(ctx, mfree_approximant_set_fallback(a, MFREE_FALLBACK_LOWER_ORDER));
    assert_ok(ctx, mfree_approximant_setup(a));
    assert_ok(ctx, mfree_approximant_get_site_status(a, status, &nf));
    assert_int_equal(nf, 0);
    assert_ok(ctx, mfree_approximant_get_site_order(a, order));
    assert_int_equal(order[11], 0); /* Shepard */
    double u[K], g[2 * K], val[K];
    for (int i = 0; i < K; ++i) u[i] = 3.0;
    assert_ok(ctx, mfree_approximant_apply(a, MFREE_OP_GRADIENT, 1, u, MFREE_LAYOUT_AOS, 1, g,
                                           MFREE_LAYOUT_AOS, 2));
    assert_true(all_finite(g, 2 * K));
    for (int i = 0; i < 2 * K; ++i) assert_true(fabs(g[i]) < 1e-12); /* constants: 0 gradient */
    if (methods[m] != MFREE_METHOD_RANDLES_LIBERSKY && methods[m] != MFREE_METHOD_JOHNSON_BEISSEL) {
      assert_ok(ctx, mfree_approximant_apply(a, MFREE_OP_VALUE, 1, u, MFREE_LAYOUT_AOS, 1, val,
                                             MFREE_LAYOUT_AOS, 1));
      for (int i = 0; i < K; ++i) assert_true(fabs(val[i] - 3.0) < 1e-12);
    }
    mfree_approximant_destroy(&a);
  }
  mfree_particles_destroy(&ps);
}

/* Too few neighbours for the basis: 2D quadratic needs 6 (001 Sect. 2, the necessary condition); with h small
 * enough that sites see 3-5 particles, SSPH reports MFREE_FAIL_NEIGHBORS or
 * MFREE_FAIL_SINGULAR instead of garbage, and neighbour counts are reported. */
static void test_too_few_neighbors(void **s) {
  (void)s;
  mfree_particles_t *ps = lattice();
  const double hsmall = 0.55 / M;
  assert_ok(ctx, mfree_particles_set_support(ps, &hsmall, 0, MFREE_COPY));
  mfree_approximant_t *a = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_SSPH, &a));
  const mfree_status_t st = mfree_approximant_setup(a);
  assert_true(st == MFREE_FAIL_NEIGHBORS || st == MFREE_FAIL_SINGULAR);
  int32_t counts[N], status[N], nf = 0;
  double cond[N];
  assert_ok(ctx, mfree_approximant_get_neighbor_counts(a, counts));
  assert_ok(ctx, mfree_approximant_get_site_status(a, status, &nf));
  assert_ok(ctx, mfree_approximant_get_condition(a, cond));
  assert_true(nf > 0);
  for (int i = 0; i < N; ++i) {
    if (counts[i] < 6) assert_int_equal(status[i], MFREE_FAIL_NEIGHBORS);
    if (status[i] == 0) assert_true(cond[i] < 1e12);
  }
  /* the valid sites still reproduce quadratics exactly */
  double fe = 1, de = 1;
  assert_ok(ctx, mfree_approximant_check_reproduction(a, 2, &fe, &de));
  assert_true(fe < 1e-10 && de < 1e-8);
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
}

/* Borrowed particle data that became invalid isolate the site (positive status). */
static void test_invalid_particle(void **s) {
  (void)s;
  mfree_particles_t *ps = lattice();
  mfree_approximant_t *a = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, &a));
  assert_ok(ctx, mfree_approximant_setup(a));
  const double keep = X[2 * 20];
  X[2 * 20] = NAN;
  assert_error(ctx, mfree_particles_setup(ps), MFREE_FAIL_NONFINITE, "particle 20");
  assert_error(ctx, mfree_approximant_setup(a), MFREE_FAIL_NONFINITE, "site 20");
  int32_t status[N], nf = 0;
  assert_ok(ctx, mfree_approximant_get_site_status(a, status, &nf));
  assert_int_equal(status[20], MFREE_FAIL_NONFINITE);
  X[2 * 20] = keep;
  assert_ok(ctx, mfree_particles_setup(ps));
  assert_ok(ctx, mfree_approximant_setup(a));
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_create_and_setters), cmocka_unit_test(test_state_and_apply_args),
      cmocka_unit_test(test_refcount),           cmocka_unit_test(test_degenerate),
      cmocka_unit_test(test_too_few_neighbors),  cmocka_unit_test(test_invalid_particle),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
