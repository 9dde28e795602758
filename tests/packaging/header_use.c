/* Compiled with -fsyntax-only as strict C99 (t003) and as C++11 (t004): the public
 * header must be clean in both, with every warning an error. It also touches a few of
 * the header's declarations so that a broken macro or typedef is noticed, not just a
 * missing include. */
#include <mfree.h>

#if !MFREE_VERSION_GE(0, 0, 0) || MFREE_VERSION_GE(MFREE_VERSION_MAJOR + 1, 0, 0)
#error "MFREE_VERSION_GE is inconsistent with MFREE_VERSION_MAJOR"
#endif
#if !MFREE_VERSION_GE(MFREE_VERSION_MAJOR, MFREE_VERSION_MINOR, MFREE_VERSION_PATCH)
#error "MFREE_VERSION_GE rejects the headers' own version"
#endif

/* A negative array size fails to compile in both languages (C99 has no static_assert). */
typedef char mfree_check_status_values[(MFREE_SUCCESS == 0 && MFREE_ERR_ARG < 0 &&
                                        MFREE_FAIL_SINGULAR > 0) ? 1 : -1];
typedef char mfree_check_index_width[(sizeof(int32_t) == 4) ? 1 : -1];

static void on_error(void *user, mfree_status_t code, const char *message) {
  (void)user;
  (void)code;
  (void)message;
}

int header_use(void);
int header_use(void) {
  mfree_context_t *ctx = 0;
  mfree_particles_t *ps = 0;
  mfree_error_handler_t handler = on_error;
  mfree_status_t st = mfree_context_create(&ctx);
  if (st == MFREE_SUCCESS) st = mfree_context_set_error_handler(ctx, handler, 0);
  if (st == MFREE_SUCCESS) st = mfree_particles_create(ctx, 2, 0, &ps);
  mfree_particles_destroy(&ps);
  mfree_context_destroy(&ctx);
  return st < 0 ? 1 : (int)st;
}
