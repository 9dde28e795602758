/* Assembler size limit (bad input "a matrix too large for int32 indices"): the
 * unknowns of an assembled system (particles x components + Lagrange multipliers) are
 * int32_t indices of mfree_matrix_t, so mfree_assembler_setup refuses more than
 * INT32_MAX of them with MFREE_ERR_ARG and a message. Reaching that through the API
 * would take about 7e8 particles, so this test checks the rule the assembler calls,
 * mfree_core_count_unknowns (src/core/discretize/unknowns.h), at and beyond the limit, and that a
 * real assembly's size is the count the rule gives (and, found on the way, that nodal
 * quadrature on a particle set without volumes is MFREE_ERR_STATE with a message; it
 * dereferenced the missing arrays before). The SuiteSparse adapter's own limit
 * (nnz above INT32_MAX moves to the 64-bit variants) is t806's. */
#include <stdint.h>

#include "testutil.h"
#include "core/discretize/unknowns.h"

static void test_limit(void **state) {
  (void)state;
  int32_t n = -1;
  /* 3D elasticity: 715827882 particles x 3 = 2147483646, plus one multiplier = INT32_MAX */
  assert_int_equal(mfree_core_count_unknowns(715827882, 3, 1, &n), MFREE_SUCCESS);
  assert_int_equal(n, INT32_MAX);
  n = -1;
  assert_int_equal(mfree_core_count_unknowns(715827882, 3, 2, &n), MFREE_ERR_ARG);
  assert_int_equal(n, -1); /* untouched on failure */
  assert_int_equal(mfree_core_count_unknowns(715827883, 3, 0, &n), MFREE_ERR_ARG);
  /* 2D and scalar forms */
  assert_int_equal(mfree_core_count_unknowns(1073741823, 2, 1, &n), MFREE_SUCCESS);
  assert_int_equal(n, INT32_MAX);
  assert_int_equal(mfree_core_count_unknowns(1073741824, 2, 0, &n), MFREE_ERR_ARG);
  assert_int_equal(mfree_core_count_unknowns(INT32_MAX, 1, 0, &n), MFREE_SUCCESS);
  assert_int_equal(n, INT32_MAX);
  assert_int_equal(mfree_core_count_unknowns(INT32_MAX, 1, 1, &n), MFREE_ERR_ARG);
  /* counts far beyond int32 (no int64 overflow in the product) */
  assert_int_equal(mfree_core_count_unknowns(INT64_MAX, 3, 0, &n), MFREE_ERR_ARG);
  assert_int_equal(mfree_core_count_unknowns(0, 3, INT64_MAX, &n), MFREE_ERR_ARG);
  /* empty systems are fine */
  assert_int_equal(mfree_core_count_unknowns(0, 2, 0, &n), MFREE_SUCCESS);
  assert_int_equal(n, 0);
}

static void test_bad_counts(void **state) {
  (void)state;
  int32_t n = 7;
  assert_int_equal(mfree_core_count_unknowns(-1, 2, 0, &n), MFREE_ERR_INPUT);
  assert_int_equal(mfree_core_count_unknowns(4, 2, -1, &n), MFREE_ERR_INPUT);
  assert_int_equal(mfree_core_count_unknowns(4, 0, 0, &n), MFREE_ERR_INPUT);
  assert_int_equal(mfree_core_count_unknowns(4, 4, 0, &n), MFREE_ERR_INPUT);
  assert_int_equal(n, 7);
}

static void zero(void *user, const double *x, double *v) {
  (void)user, (void)x;
  v[0] = v[1] = 0.0;
}

/* A 4 x 4 grid, plane-stress elasticity with Lagrange multipliers on u_x at the four
 * nodes of x = 0: 16 x 2 + 4 unknowns, the count the rule gives. */
static void test_assembler_size(void **state) {
  (void)state;
  mfree_context_t *ctx = NULL;
  assert_int_equal(mfree_context_create(&ctx), MFREE_SUCCESS);
  double x[32], bx[8];
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) x[2 * (4 * i + j)] = 0.25 * i, x[2 * (4 * i + j) + 1] = 0.25 * j;
  for (int j = 0; j < 4; ++j) bx[2 * j] = 0.0, bx[2 * j + 1] = 0.25 * j;
  const double h = 0.25 * 1.5;
  mfree_particles_t *ps = NULL;
  mfree_approximant_t *a = NULL;
  mfree_assembler_t *as = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, 2, 16, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 2, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_setup(ps));
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, &a));
  assert_ok(ctx, mfree_approximant_set_order(a, 1));
  assert_ok(ctx, mfree_assembler_create(ctx, a, NULL, MFREE_FORM_ELASTICITY_PLANE_STRESS, &as));
  assert_ok(ctx, mfree_assembler_set_material(as, 1000.0, 0.3));
  assert_ok(ctx, mfree_assembler_set_quadrature_nodal(as));
  /* nodal quadrature without particle volumes: a status and a message, not a crash */
  assert_error(ctx, mfree_assembler_setup(as), MFREE_ERR_STATE, "needs particle volumes");
  double vol[16];
  for (int i = 0; i < 16; ++i) vol[i] = 0.25 * 0.25 * ((i / 4 == 0 || i / 4 == 3) ? 0.5 : 1.0) *
                                        ((i % 4 == 0 || i % 4 == 3) ? 0.5 : 1.0);
  assert_ok(ctx, mfree_particles_set_volumes(ps, vol, 1, MFREE_COPY));
  assert_ok(ctx, mfree_particles_setup(ps));
  assert_ok(ctx, mfree_assembler_add_dirichlet(as, MFREE_BC_LAGRANGE, 4, bx, MFREE_LAYOUT_AOS, 2, NULL, NULL, 1,
                                               zero, NULL));
  assert_ok(ctx, mfree_assembler_setup(as));
  int32_t ndofs = 0, nq = 0, expect = -1;
  assert_ok(ctx, mfree_assembler_get_size(as, &ndofs, &nq));
  assert_int_equal(mfree_core_count_unknowns(16, 2, 4, &expect), MFREE_SUCCESS);
  assert_int_equal(ndofs, expect);
  assert_int_equal(ndofs, 36);
  mfree_assembler_destroy(&as);
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
  mfree_context_destroy(&ctx);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_limit),
      cmocka_unit_test(test_bad_counts),
      cmocka_unit_test(test_assembler_size),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
