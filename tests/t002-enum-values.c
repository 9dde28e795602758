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
  assert_int_equal(MFREE_ERR_INTERNAL, -99);
  assert_int_equal(MFREE_FAIL_NONFINITE, 1);
  assert_int_equal(MFREE_FAIL_INVALID_DATA, 2);
  assert_int_equal(MFREE_FAIL_SINGULAR, 3);
  assert_int_equal(MFREE_FAIL_NEIGHBORS, 4);
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
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_status_values),
      cmocka_unit_test(test_option_values),
      cmocka_unit_test(test_kernel_values),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
