/* Context, version and status strings. */
#include <stdio.h>
#include <string.h>

#include "testutil.h"

/* Version macros equal the run-time version; MFREE_VERSION_GE orders correctly. */
static void test_version(void **s) {
  (void)s;
  char expect[64];
  snprintf(expect, sizeof expect, "%d.%d.%d", MFREE_VERSION_MAJOR, MFREE_VERSION_MINOR,
           MFREE_VERSION_PATCH);
  assert_string_equal(mfree_version_string(), expect);
  assert_string_equal(mfree_version_string(), MFREE_VERSION_STRING);
  int32_t ma = -1, mi = -1, pa = -1;
  assert_int_equal(mfree_version_get(&ma, &mi, &pa), MFREE_SUCCESS);
  assert_int_equal(ma, MFREE_VERSION_MAJOR);
  assert_int_equal(mi, MFREE_VERSION_MINOR);
  assert_int_equal(pa, MFREE_VERSION_PATCH);
  assert_int_equal(mfree_version_get(NULL, NULL, NULL), MFREE_SUCCESS);
  assert_true(MFREE_VERSION_GE(MFREE_VERSION_MAJOR, MFREE_VERSION_MINOR, MFREE_VERSION_PATCH));
  assert_true(MFREE_VERSION_GE(0, 0, 0));
  assert_false(MFREE_VERSION_GE(MFREE_VERSION_MAJOR + 1, 0, 0));
  assert_false(MFREE_VERSION_GE(MFREE_VERSION_MAJOR, MFREE_VERSION_MINOR + 1, 0));
  assert_false(MFREE_VERSION_GE(MFREE_VERSION_MAJOR, MFREE_VERSION_MINOR, MFREE_VERSION_PATCH + 1));
}

static void test_status_strings(void **s) {
  (void)s;
  const mfree_status_t all[] = {MFREE_SUCCESS,       MFREE_ERR_NULL,     MFREE_ERR_ARG,
                                MFREE_ERR_STATE,     MFREE_ERR_ALLOC,    MFREE_ERR_MISMATCH,
                                MFREE_ERR_UNSUPPORTED, MFREE_ERR_INPUT,  MFREE_ERR_INTERNAL,
                                MFREE_FAIL_NONFINITE, MFREE_FAIL_INVALID_DATA,
                                MFREE_FAIL_SINGULAR, MFREE_FAIL_NEIGHBORS,
                                MFREE_FAIL_DOMAIN, MFREE_FAIL_CFL};
  const size_t n = sizeof all / sizeof all[0];
  for (size_t i = 0; i < n; ++i) {
    const char *a = mfree_status_string(all[i]);
    assert_non_null(a);
    assert_string_not_equal(a, "unknown status");
    for (size_t j = 0; j < i; ++j) assert_string_not_equal(a, mfree_status_string(all[j]));
  }
  assert_string_equal(mfree_status_string((mfree_status_t)12345), "unknown status");
}

static int handler_calls;
static mfree_status_t handler_code;
static char handler_msg[256];
static void handler(void *user, mfree_status_t code, const char *msg) {
  ++*(int *)user;
  handler_code = code;
  snprintf(handler_msg, sizeof handler_msg, "%s", msg);
}

static void test_context(void **s) {
  (void)s;
  mfree_context_t *ctx = NULL;
  assert_int_equal(mfree_context_create(NULL), MFREE_ERR_NULL);
  assert_int_equal(mfree_context_create(&ctx), MFREE_SUCCESS);
  assert_non_null(ctx);

  /* fresh context: no error */
  mfree_status_t code = MFREE_ERR_INTERNAL;
  char msg[64] = "x";
  assert_int_equal(mfree_context_get_last_error(ctx, &code, msg, sizeof msg), MFREE_SUCCESS);
  assert_int_equal(code, MFREE_SUCCESS);
  assert_string_equal(msg, "");

  /* a failure is recorded with the function name; the handler sees it */
  handler_calls = 0;
  assert_int_equal(mfree_context_set_error_handler(ctx, handler, &handler_calls), MFREE_SUCCESS);
  mfree_particles_t *ps = NULL;
  assert_error(ctx, mfree_particles_create(ctx, 4, 10, &ps), MFREE_ERR_ARG, "mfree_particles_create");
  assert_null(ps);
  assert_int_equal(handler_calls, 1);
  assert_int_equal(handler_code, MFREE_ERR_ARG);
  assert_non_null(strstr(handler_msg, "dimension"));

  /* truncation to a short buffer keeps it NUL-terminated */
  char tiny[8];
  assert_int_equal(mfree_context_get_last_error(ctx, NULL, tiny, sizeof tiny), MFREE_SUCCESS);
  assert_int_equal(strlen(tiny), 7);
  assert_int_equal(mfree_context_get_last_error(ctx, NULL, tiny, 0), MFREE_ERR_ARG);
  assert_int_equal(mfree_context_get_last_error(NULL, &code, NULL, 0), MFREE_ERR_NULL);

  /* a successful call leaves the last error in place */
  assert_int_equal(mfree_particles_create(ctx, 2, 3, &ps), MFREE_SUCCESS);
  assert_int_equal(mfree_context_get_last_error(ctx, &code, NULL, 0), MFREE_SUCCESS);
  assert_int_equal(code, MFREE_ERR_ARG);

  /* removing the handler */
  assert_int_equal(mfree_context_set_error_handler(ctx, NULL, NULL), MFREE_SUCCESS);
  assert_int_equal(mfree_particles_set_num_ghost(ps, 9), MFREE_ERR_ARG);
  assert_int_equal(handler_calls, 1);

  /* adapters record their own failures */
  assert_int_equal(mfree_context_set_error(ctx, MFREE_FAIL_SINGULAR, "adapter: singular"),
                   MFREE_FAIL_SINGULAR);
  assert_int_equal(mfree_context_get_last_error(ctx, &code, msg, sizeof msg), MFREE_SUCCESS);
  assert_int_equal(code, MFREE_FAIL_SINGULAR);
  assert_string_equal(msg, "adapter: singular");
  assert_int_equal(mfree_context_set_error(NULL, MFREE_ERR_ARG, "x"), MFREE_ERR_NULL);

  /* threads */
  int32_t nt = -1;
  assert_int_equal(mfree_context_get_num_threads(ctx, &nt), MFREE_SUCCESS);
  assert_int_equal(nt, 1);
  assert_int_equal(mfree_context_set_num_threads(ctx, 2), MFREE_SUCCESS);
  assert_int_equal(mfree_context_get_num_threads(ctx, &nt), MFREE_SUCCESS);
  assert_int_equal(nt, 2);
  assert_error(ctx, mfree_context_set_num_threads(ctx, -3), MFREE_ERR_ARG, "negative");
  assert_int_equal(mfree_context_get_num_threads(ctx, &nt), MFREE_SUCCESS);
  assert_int_equal(nt, 2);
  assert_int_equal(mfree_context_set_num_threads(NULL, 1), MFREE_ERR_NULL);
  assert_int_equal(mfree_context_get_num_threads(NULL, &nt), MFREE_ERR_NULL);
  assert_int_equal(mfree_context_get_num_threads(ctx, NULL), MFREE_ERR_NULL);
  assert_int_equal(mfree_context_set_error_handler(NULL, handler, NULL), MFREE_ERR_NULL);

  /* reference counting: the particle set keeps the context alive */
  assert_int_equal(mfree_context_destroy(&ctx), MFREE_SUCCESS);
  assert_null(ctx);
  assert_int_equal(mfree_particles_set_num_ghost(ps, 99), MFREE_ERR_ARG); /* records on the kept ctx */
  assert_int_equal(mfree_particles_destroy(&ps), MFREE_SUCCESS);
  assert_null(ps);

  /* destroy accepts NULL and pointer-to-NULL */
  assert_int_equal(mfree_context_destroy(NULL), MFREE_SUCCESS);
  assert_int_equal(mfree_context_destroy(&ctx), MFREE_SUCCESS);
  assert_int_equal(mfree_particles_destroy(NULL), MFREE_SUCCESS);
  assert_int_equal(mfree_particles_destroy(&ps), MFREE_SUCCESS);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_version),
      cmocka_unit_test(test_status_strings),
      cmocka_unit_test(test_context),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
