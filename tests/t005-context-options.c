/* The context's backend and page hints (mfree_context_set_backend, _set_page_hints):
 *  - defaults: MFREE_BACKEND_OPT, MFREE_PAGES_DEFAULT; setters and getters round-trip;
 *  - bad input: an unknown backend or unknown page flags give MFREE_ERR_ARG with a message
 *    naming the function, and leave the setting as it was; a NULL context or output gives
 *    MFREE_ERR_NULL;
 *  - the two backends compute the same thing: MLS order 1 and 2, RKPM, SPH and Randles-
 *    Libersky value and gradient tables, and the applies of every operator to one and
 *    three fields, agree to round-off between MFREE_BACKEND_REF and MFREE_BACKEND_OPT, in
 *    2D and 3D (the set-up tables are kept: switching the backend of a set-up approximant
 *    changes only how the next apply computes). Page hints change no result: t204. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"

static void test_defaults_and_errors(void **s) {
  (void)s;
  mfree_context_t *ctx = NULL;
  assert_ok(NULL, mfree_context_create(&ctx));
  int32_t v = -7;
  assert_ok(ctx, mfree_context_get_backend(ctx, &v));
  assert_int_equal(v, MFREE_BACKEND_OPT);
  assert_ok(ctx, mfree_context_get_page_hints(ctx, &v));
  assert_int_equal(v, MFREE_PAGES_DEFAULT);

  assert_ok(ctx, mfree_context_set_backend(ctx, MFREE_BACKEND_REF));
  assert_ok(ctx, mfree_context_get_backend(ctx, &v));
  assert_int_equal(v, MFREE_BACKEND_REF);
  const int32_t bad[] = {0, 3, -1, MFREE_BACKEND_REF | MFREE_BACKEND_OPT};
  for (int i = 0; i < 4; ++i) {
    assert_error(ctx, mfree_context_set_backend(ctx, bad[i]), MFREE_ERR_ARG, "mfree_context_set_backend");
    assert_ok(ctx, mfree_context_get_backend(ctx, &v));
    assert_int_equal(v, MFREE_BACKEND_REF); /* unchanged */
  }
  assert_ok(ctx, mfree_context_set_backend(ctx, MFREE_BACKEND_OPT));
  assert_ok(ctx, mfree_context_get_backend(ctx, &v));
  assert_int_equal(v, MFREE_BACKEND_OPT);

  assert_ok(ctx, mfree_context_set_page_hints(ctx, MFREE_PAGES_HUGE | MFREE_PAGES_PREFAULT));
  assert_ok(ctx, mfree_context_get_page_hints(ctx, &v));
  assert_int_equal(v, MFREE_PAGES_HUGE | MFREE_PAGES_PREFAULT);
  assert_error(ctx, mfree_context_set_page_hints(ctx, 4), MFREE_ERR_ARG, "mfree_context_set_page_hints");
  assert_error(ctx, mfree_context_set_page_hints(ctx, -1), MFREE_ERR_ARG, "unknown flags");
  assert_ok(ctx, mfree_context_get_page_hints(ctx, &v));
  assert_int_equal(v, MFREE_PAGES_HUGE | MFREE_PAGES_PREFAULT); /* unchanged */
  assert_ok(ctx, mfree_context_set_page_hints(ctx, MFREE_PAGES_DEFAULT));
  assert_ok(ctx, mfree_context_get_page_hints(ctx, &v));
  assert_int_equal(v, MFREE_PAGES_DEFAULT);

  assert_int_equal(mfree_context_set_backend(NULL, MFREE_BACKEND_REF), MFREE_ERR_NULL);
  assert_int_equal(mfree_context_get_backend(NULL, &v), MFREE_ERR_NULL);
  assert_int_equal(mfree_context_get_backend(ctx, NULL), MFREE_ERR_NULL);
  assert_int_equal(mfree_context_set_page_hints(NULL, 0), MFREE_ERR_NULL);
  assert_int_equal(mfree_context_get_page_hints(NULL, &v), MFREE_ERR_NULL);
  assert_int_equal(mfree_context_get_page_hints(ctx, NULL), MFREE_ERR_NULL);
  assert_ok(NULL, mfree_context_destroy(&ctx));
}

/* Jittered lattice of m^dim points on [0,1]^dim, AoS with ld = dim. */
static double *cloud(int dim, int m, int *n) {
  *n = 1;
  for (int d = 0; d < dim; ++d) *n *= m;
  double *x = malloc(sizeof(double) * (size_t)dim * (size_t)*n);
  assert_non_null(x);
  mfree_rng_t r;
  mfree_rng_seed(&r, 5);
  for (int i = 0; i < *n; ++i) {
    int q = i;
    for (int d = 0; d < dim; ++d) {
      x[i * dim + d] = ((q % m) + 0.3 * (mfree_rng_uniform(&r) - 0.5)) / (m - 1);
      q /= m;
    }
  }
  return x;
}

static double max_abs(const double *a, int64_t n) {
  double s = 0.0;
  for (int64_t i = 0; i < n; ++i) s = fmax(s, fabs(a[i]));
  return s;
}

/* |a - b| <= tol * (max |b| + 1e-300), element-wise; names the first failure. */
static void expect_close(const double *a, const double *b, int64_t n, double tol, const char *what) {
  const double scale = max_abs(b, n) + 1e-300;
  for (int64_t i = 0; i < n; ++i)
    if (!(fabs(a[i] - b[i]) <= tol * scale)) fail_msg("%s [%lld]: opt %.17g, ref %.17g", what, (long long)i, a[i], b[i]);
}

typedef struct {
  int method, order;
} config_t;

static void test_ref_equals_opt(void **s) {
  (void)s;
  const config_t configs[] = {{MFREE_METHOD_MLS, 1}, {MFREE_METHOD_MLS, 2}, {MFREE_METHOD_RKPM, 1},
                              {MFREE_METHOD_SPH, 0}, {MFREE_METHOD_RANDLES_LIBERSKY, 0}};
  const int ops[5] = {MFREE_OP_VALUE, MFREE_OP_GRADIENT, MFREE_OP_DIVERGENCE, MFREE_OP_LAPLACIAN, MFREE_OP_HESSIAN};
  for (int dim = 2; dim <= 3; ++dim) {
    int n = 0;
    const int m = dim == 2 ? 14 : 7;
    double *x = cloud(dim, m, &n);
    const double h = 1.3 / (m - 1), vol = pow(1.0 / (m - 1), dim);
    double *u = malloc(sizeof(double) * 3 * (size_t)n);
    assert_non_null(u);
    for (int i = 0; i < 3 * n; ++i) u[i] = sin(1.0 + 0.37 * i) + x[(i / 3) * dim] * (1 + i % 3);
    for (size_t c = 0; c < sizeof configs / sizeof configs[0]; ++c) {
      const int hess = configs[c].method == MFREE_METHOD_MLS && configs[c].order == 2;
      mfree_context_t *ctx[2] = {NULL, NULL}; /* 0: opt, 1: ref */
      mfree_approximant_t *a[2] = {NULL, NULL};
      mfree_particles_t *ps[2] = {NULL, NULL};
      for (int b = 0; b < 2; ++b) {
        assert_ok(NULL, mfree_context_create(&ctx[b]));
        assert_ok(ctx[b], mfree_context_set_backend(ctx[b], b ? MFREE_BACKEND_REF : MFREE_BACKEND_OPT));
        assert_ok(ctx[b], mfree_particles_create(ctx[b], dim, n, &ps[b]));
        assert_ok(ctx[b], mfree_particles_set_positions(ps[b], x, MFREE_LAYOUT_AOS, dim, MFREE_COPY));
        assert_ok(ctx[b], mfree_particles_set_support(ps[b], &h, 0, MFREE_COPY));
        assert_ok(ctx[b], mfree_particles_set_volumes(ps[b], &vol, 0, MFREE_COPY));
        assert_ok(ctx[b], mfree_approximant_create(ctx[b], ps[b], configs[c].method, &a[b]));
        if (configs[c].order > 0) assert_ok(ctx[b], mfree_approximant_set_order(a[b], configs[c].order));
        assert_ok(ctx[b], mfree_approximant_set_derivatives(
                              a[b], MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT | (hess ? MFREE_DERIV_HESSIAN : 0)));
        assert_ok(ctx[b], mfree_approximant_setup(a[b]));
      }
      int64_t nnz[2];
      for (int b = 0; b < 2; ++b) assert_ok(ctx[b], mfree_approximant_get_nnz(a[b], &nnz[b]));
      assert_int_equal(nnz[0], nnz[1]);
      /* the tables, through the exported CSR of the values and each gradient direction */
      for (int op = 0; op < 5; ++op) {
        if (!hess && (ops[op] == MFREE_OP_LAPLACIAN || ops[op] == MFREE_OP_HESSIAN)) continue;
        for (int nc = 1; nc <= 3; nc += 2) {
          const int ncomp = ops[op] == MFREE_OP_DIVERGENCE ? dim : nc;
          if (ops[op] == MFREE_OP_DIVERGENCE && nc == 3) continue;
          const int per = ops[op] == MFREE_OP_GRADIENT ? ncomp * dim
                          : ops[op] == MFREE_OP_HESSIAN ? ncomp * dim * (dim + 1) / 2
                          : ops[op] == MFREE_OP_DIVERGENCE ? 1 : ncomp;
          double *out[2];
          for (int b = 0; b < 2; ++b) {
            out[b] = malloc(sizeof(double) * (size_t)per * (size_t)n);
            assert_non_null(out[b]);
            assert_ok(ctx[b], mfree_approximant_apply(a[b], ops[op], ncomp, u, MFREE_LAYOUT_AOS, 3, out[b],
                                                      MFREE_LAYOUT_AOS, per));
          }
          char what[96];
          snprintf(what, sizeof what, "%dD method %d order %d op %d ncomp %d", dim, configs[c].method,
                   configs[c].order, ops[op], ncomp);
          expect_close(out[0], out[1], (int64_t)per * n, 1e-10, what);
          /* the opt-built tables applied by the reference loop: only round-off apart */
          assert_ok(ctx[0], mfree_context_set_backend(ctx[0], MFREE_BACKEND_REF));
          assert_ok(ctx[0], mfree_approximant_apply(a[0], ops[op], ncomp, u, MFREE_LAYOUT_AOS, 3, out[1],
                                                    MFREE_LAYOUT_AOS, per));
          assert_ok(ctx[0], mfree_context_set_backend(ctx[0], MFREE_BACKEND_OPT));
          expect_close(out[0], out[1], (int64_t)per * n, 1e-13, what);
          free(out[0]);
          free(out[1]);
        }
      }
      for (int b = 0; b < 2; ++b) {
        assert_ok(ctx[b], mfree_approximant_destroy(&a[b]));
        assert_ok(ctx[b], mfree_particles_destroy(&ps[b]));
        assert_ok(NULL, mfree_context_destroy(&ctx[b]));
      }
    }
    free(u);
    free(x);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_defaults_and_errors),
      cmocka_unit_test(test_ref_equals_opt),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
