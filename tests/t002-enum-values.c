/* Every public enumerator's value is frozen: a change here is an ABI break. */
#include "testutil.h"

static void test_status_values(void **s) {
  (void)s;
  assert_int_equal(MFREE_SUCCESS, 0);
  assert_int_equal(MFREE_ERR_NULL, -1);
  assert_int_equal(MFREE_ERR_ARG, -2);
  assert_int_equal(MFREE_ERR_STATE, -3);
  assert_int_equal(MFREE_ERR_ALLOC, -4);
  assert_int_equal(MFREE_ERR_MISMATCH, -5);
  assert_int_equal(MFREE_ERR_UNSUPPORTED, -6);
  assert_int_equal(MFREE_ERR_INPUT, -7);
  assert_int_equal(MFREE_ERR_HALO, -8);
  assert_int_equal(MFREE_ERR_INTERNAL, -99);
  assert_int_equal(MFREE_FAIL_NONFINITE, 1);
  assert_int_equal(MFREE_FAIL_INVALID_DATA, 2);
  assert_int_equal(MFREE_FAIL_SINGULAR, 3);
  assert_int_equal(MFREE_FAIL_NEIGHBORS, 4);
  assert_int_equal(MFREE_FAIL_DOMAIN, 5);
  assert_int_equal(MFREE_FAIL_CFL, 6);
  assert_int_equal(MFREE_FAIL_SUPPORT, 7);
  assert_int_equal(MFREE_FAIL_CAPACITY, 8);
  assert_int_equal(sizeof(mfree_status_t), sizeof(int));
}

static void test_option_values(void **s) {
  (void)s;
  assert_int_equal(MFREE_COPY, 1);
  assert_int_equal(MFREE_BORROW, 2);
  assert_int_equal(MFREE_LAYOUT_AOS, 1);
  assert_int_equal(MFREE_LAYOUT_SOA, 2);
  assert_int_equal(MFREE_SEARCH_GATHER, 1);
  assert_int_equal(MFREE_SEARCH_SYMMETRIC_MAX, 2);
  assert_int_equal(MFREE_SEARCH_SYMMETRIC_MEAN, 3);
}

static void test_kernel_values(void **s) {
  (void)s;
  assert_int_equal(MFREE_KERNEL_CUBIC_SPLINE, 1);
  assert_int_equal(MFREE_KERNEL_QUARTIC, 2);
  assert_int_equal(MFREE_KERNEL_QUINTIC_SPLINE, 3);
  assert_int_equal(MFREE_KERNEL_GAUSSIAN, 4);
  assert_int_equal(MFREE_KERNEL_SUPER_GAUSS, 5);
  assert_int_equal(MFREE_KERNEL_REVISED_GAUSS, 6);
  assert_int_equal(MFREE_KERNEL_REVISED_SUPER_GAUSS, 7);
  assert_int_equal(MFREE_KERNEL_WENDLAND_C2, 8);
  assert_int_equal(MFREE_KERNEL_WENDLAND_C4, 9);
  assert_int_equal(MFREE_KERNEL_LINEAR, 10);
  assert_int_equal(MFREE_KERNEL_QUADRATIC, 11);
  assert_int_equal(MFREE_KERNEL_QUARTIC_SPLINE, 12);
  assert_int_equal(MFREE_KERNEL_COSINE, 13);
  assert_int_equal(MFREE_KERNEL_COSINE_SQUARED, 14);
  assert_int_equal(MFREE_KERNEL_HAAR, 15);
}

static void test_method_values(void **s) {
  (void)s;
  assert_int_equal(MFREE_METHOD_SPH, 1);
  assert_int_equal(MFREE_METHOD_SPH_SYMMETRIC, 2);
  assert_int_equal(MFREE_METHOD_SHEPARD, 3);
  assert_int_equal(MFREE_METHOD_MLS, 4);
  assert_int_equal(MFREE_METHOD_RKPM, 5);
  assert_int_equal(MFREE_METHOD_JOHNSON_BEISSEL, 6);
  assert_int_equal(MFREE_METHOD_RANDLES_LIBERSKY, 7);
  assert_int_equal(MFREE_METHOD_KB_METHOD1, 8);
  assert_int_equal(MFREE_METHOD_KB_METHOD2, 9);
  assert_int_equal(MFREE_METHOD_KB_METHOD3, 10);
  assert_int_equal(MFREE_METHOD_MSPH, 11);
  assert_int_equal(MFREE_METHOD_SSPH, 12);
  assert_int_equal(MFREE_METHOD_MPFEM, 13);
  assert_int_equal(MFREE_DERIV_VALUE, 1);
  assert_int_equal(MFREE_DERIV_GRADIENT, 2);
  assert_int_equal(MFREE_DERIV_HESSIAN, 4);
  assert_int_equal(MFREE_OP_VALUE, 1);
  assert_int_equal(MFREE_OP_GRADIENT, 2);
  assert_int_equal(MFREE_OP_DIVERGENCE, 3);
  assert_int_equal(MFREE_OP_LAPLACIAN, 4);
  assert_int_equal(MFREE_OP_HESSIAN, 5);
  assert_int_equal(MFREE_FALLBACK_NONE, 1);
  assert_int_equal(MFREE_FALLBACK_LOWER_ORDER, 2);
}

static void test_assembly_values(void **s) {
  (void)s;
  assert_int_equal(MFREE_FORM_LAPLACE, 1);
  assert_int_equal(MFREE_FORM_ELASTICITY_PLANE_STRESS, 2);
  assert_int_equal(MFREE_FORM_ELASTICITY_PLANE_STRAIN, 3);
  assert_int_equal(MFREE_FORM_ELASTICITY_3D, 4);
  assert_int_equal(MFREE_FORM_MASS, 5);
  assert_int_equal(MFREE_FORM_MASS_LUMPED, 6);
  assert_int_equal(MFREE_FORM_COLLOCATION_LAPLACE, 7);
  assert_int_equal(MFREE_FORM_COLLOCATION_PLANE_STRESS, 8);
  assert_int_equal(MFREE_FORM_COLLOCATION_PLANE_STRAIN, 9);
  assert_int_equal(MFREE_BC_PENALTY, 1);
  assert_int_equal(MFREE_BC_LAGRANGE, 2);
  assert_int_equal(MFREE_BC_COLLOCATION, 3);
  assert_int_equal(MFREE_BC_NITSCHE, 4);
  assert_int_equal(MFREE_INTEGRATOR_LEAPFROG, 1);
  assert_int_equal(MFREE_INTEGRATOR_PREDICTOR_CORRECTOR, 2);
  assert_int_equal(MFREE_LUMP_GALERKIN, 1);
  assert_int_equal(MFREE_LUMP_PHYSICAL, 2);
  assert_int_equal(MFREE_PARTICLE_DORMANT, 0);
  assert_int_equal(MFREE_PARTICLE_FLUID, 1);
  assert_int_equal(MFREE_PARTICLE_INFLOW, 2);
  assert_int_equal(MFREE_ELEMENT_LINE2, 1);
  assert_int_equal(MFREE_ELEMENT_TRI3, 2);
  assert_int_equal(MFREE_ELEMENT_QUAD4, 3);
  assert_int_equal(MFREE_ELEMENT_HEX8, 4);
  assert_int_equal(MFREE_MPFEM_DERIV_FULL, 1);
  assert_int_equal(MFREE_MPFEM_DERIV_ASSUMED_STRAIN, 2);
  assert_int_equal(MFREE_MPFEM_DERIV_NODAL, 3);
}

static void test_context_option_values(void **s) {
  (void)s;
  assert_int_equal(MFREE_BACKEND_REF, 1);
  assert_int_equal(MFREE_BACKEND_OPT, 2);
  assert_int_equal(MFREE_PAGES_DEFAULT, 0);
  assert_int_equal(MFREE_PAGES_HUGE, 1);
  assert_int_equal(MFREE_PAGES_PREFAULT, 2);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_status_values),
      cmocka_unit_test(test_option_values),
      cmocka_unit_test(test_kernel_values),
      cmocka_unit_test(test_method_values),
      cmocka_unit_test(test_assembly_values),
      cmocka_unit_test(test_context_option_values),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
