/* t303: a table entry that overflows from valid data fails its site with
 * MFREE_FAIL_NONFINITE, on both backends: SPH on a 20 x 20 lattice (spacing 1e-3,
 * h = 1.1e-3, so no neighbour lies on a support's edge) where one particle's volume is
 * 1e308, so V_j W_ij overflows in the row of every site within 2h of it (at places all
 * along the rows: the screen's vector lanes and its tail) and nowhere else. The other
 * sites keep status 0 and finite entries; a site that failed has its rows zeroed. */
#include <math.h>
#include <string.h>

#include "testutil.h"

enum { M = 20, N = M * M, BIG = 7 * M + 9 };
static mfree_context_t *ctx;
static int setup(void **s) { (void)s; return mfree_context_create(&ctx) != MFREE_SUCCESS; }
static int teardown(void **s) { (void)s; return mfree_context_destroy(&ctx) != MFREE_SUCCESS; }

static void run(int32_t backend) {
  const double d = 1e-3, h = 1.1e-3;
  double x[2 * N], vol[N];
  for (int i = 0; i < N; ++i) {
    x[2 * i] = d * (i % M);
    x[2 * i + 1] = d * (i / M);
    vol[i] = d * d;
  }
  vol[BIG] = 1e308;
  assert_ok(ctx, mfree_context_set_backend(ctx, backend));
  mfree_particles_t *ps = NULL;
  mfree_approximant_t *a = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, 2, N, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 2, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_volumes(ps, vol, 1, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_setup(ps));
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_SPH, &a));
  assert_ok(ctx, mfree_approximant_set_derivatives(a, MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT));
  assert_error(ctx, mfree_approximant_setup(a), MFREE_FAIL_NONFINITE, "site");
  int32_t status[N], nf = 0, expect = 0;
  assert_ok(ctx, mfree_approximant_get_site_status(a, status, &nf));
  for (int i = 0; i < N; ++i) {
    const double dx = x[2 * i] - x[2 * BIG], dy = x[2 * i + 1] - x[2 * BIG + 1];
    const int near = sqrt(dx * dx + dy * dy) < 2.0 * h;
    expect += near;
    assert_int_equal(status[i], near ? MFREE_FAIL_NONFINITE : 0);
  }
  assert_int_equal(nf, expect);
  assert_true(expect >= 13); /* rows long enough for the vector loop and its tail */
  /* every entry of the tables finite: the failed rows zeroed, the others computed */
  int64_t nnz = 0;
  assert_ok(ctx, mfree_approximant_get_nnz(a, &nnz));
  int64_t *rp = test_malloc(sizeof(int64_t) * (N + 1));
  int32_t *cols = test_malloc(sizeof(int32_t) * nnz);
  double *val = test_malloc(sizeof(double) * nnz);
  assert_ok(ctx, mfree_approximant_assemble_csr(a, MFREE_DERIV_VALUE, 0, rp, cols, val));
  for (int i = 0; i < N; ++i)
    for (int64_t k = rp[i]; k < rp[i + 1]; ++k) {
      assert_true(isfinite(val[k]));
      if (status[i]) assert_true(val[k] == 0.0);
    }
  test_free(rp);
  test_free(cols);
  test_free(val);
  /* with the volume back to normal every site is valid again */
  vol[BIG] = d * d;
  assert_ok(ctx, mfree_particles_setup(ps));
  assert_ok(ctx, mfree_approximant_setup(a));
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
}

static void test_opt(void **s) {
  (void)s;
  run(MFREE_BACKEND_OPT);
}
static void test_ref(void **s) {
  (void)s;
  run(MFREE_BACKEND_REF);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_opt), cmocka_unit_test(test_ref)};
  return cmocka_run_group_tests(tests, setup, teardown);
}
