/* Failing calls on several threads that share one context (mfree.h: apply is reentrant;
 * every failure records its status and message on the context).
 *
 * Four threads apply ONE set-up approximant, whose context they all share, each cycling
 * through four calls out of step with the others: arguments that fail (a leading
 * dimension below its minimum: MFREE_ERR_ARG; a NULL field: MFREE_ERR_NULL), good
 * arguments, good arguments followed by a read of the context's last error. Checks:
 *  - every call returns its own documented status, every good call gives bitwise the
 *    result of one thread;
 *  - a last error read while the others write is one whole message of the two failing
 *    calls, with its matching code (never a torn or freed string);
 *  - an error handler installed on the context is called once per failing call, with a
 *    whole message.
 * The error recording used to write the context's message without a lock: glibc aborted
 * ("free(): unaligned chunk") or ASan reported a heap-use-after-free in it. Run under
 * ThreadSanitizer by the tsan preset, under ASan+UBSan by the asan preset. */
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"

enum { M = 8, N = M * M, NTHREADS = 4, ITER = 3000 };

static mfree_context_t *ctx;
static mfree_approximant_t *ap;
static double X[2 * N], U[N], REF[2 * N];
static atomic_int bad_reads, handler_calls, handler_bad;
static const char *MSG_LD = "mfree_approximant_apply: leading dimension of u is 0, below 1";
static const char *MSG_NULL = "mfree_approximant_apply: field pointer u is NULL";

static int whole(const char *msg, mfree_status_t code) {
  if (code == MFREE_ERR_ARG) return strcmp(msg, MSG_LD) == 0;
  if (code == MFREE_ERR_NULL) return strcmp(msg, MSG_NULL) == 0;
  return 0;
}

static void handler(void *user, mfree_status_t code, const char *message) {
  (void)user;
  atomic_fetch_add(&handler_calls, 1);
  if (!whole(message, code)) atomic_fetch_add(&handler_bad, 1);
}

typedef struct {
  int role, wrong;
} job_t;

static void *worker(void *arg) {
  job_t *j = arg;
  double out[2 * N];
  for (int it = 0; it < ITER; ++it) {
    mfree_status_t st;
    switch ((j->role + it) % 4) {
      case 0: /* ld 0 < 1 */
        st = mfree_approximant_apply(ap, MFREE_OP_GRADIENT, 1, U, MFREE_LAYOUT_AOS, 0, out,
                                     MFREE_LAYOUT_AOS, 2);
        j->wrong += st != MFREE_ERR_ARG;
        break;
      case 1: /* NULL field */
        st = mfree_approximant_apply(ap, MFREE_OP_GRADIENT, 1, NULL, MFREE_LAYOUT_AOS, 1, out,
                                     MFREE_LAYOUT_AOS, 2);
        j->wrong += st != MFREE_ERR_NULL;
        break;
      default: {
        st = mfree_approximant_apply(ap, MFREE_OP_GRADIENT, 1, U, MFREE_LAYOUT_AOS, 1, out,
                                     MFREE_LAYOUT_AOS, 2);
        j->wrong += st != MFREE_SUCCESS || memcmp(out, REF, sizeof out) != 0;
        if ((j->role + it) % 4 == 3) {
          char msg[256];
          mfree_status_t code = MFREE_SUCCESS;
          if (mfree_context_get_last_error(ctx, &code, msg, sizeof msg) != MFREE_SUCCESS)
            ++j->wrong;
          /* before the first failure the context holds no error */
          else if (code != MFREE_SUCCESS && !whole(msg, code))
            atomic_fetch_add(&bad_reads, 1);
        }
      }
    }
  }
  return NULL;
}

static void test_failing_calls_share_a_context(void **state) {
  (void)state;
  assert_ok(NULL, mfree_context_create(&ctx));
  mfree_particles_t *ps = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, 2, N, &ps));
  mfree_rng_t r;
  mfree_rng_seed(&r, 64);
  for (int p = 0; p < N; ++p) {
    X[2 * p] = (p % M + 0.2 * mfree_rng_uniform(&r)) / M;
    X[2 * p + 1] = (p / M + 0.2 * mfree_rng_uniform(&r)) / M;
    U[p] = X[2 * p] * X[2 * p] - 3.0 * X[2 * p + 1];
  }
  const double h = 1.6 / M, vol = 1.0 / N;
  assert_ok(ctx, mfree_particles_set_positions(ps, X, MFREE_LAYOUT_AOS, 2, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_volumes(ps, &vol, 0, MFREE_COPY));
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, &ap));
  assert_ok(ctx, mfree_approximant_setup(ap));
  assert_ok(ctx, mfree_approximant_apply(ap, MFREE_OP_GRADIENT, 1, U, MFREE_LAYOUT_AOS, 1, REF,
                                         MFREE_LAYOUT_AOS, 2));
  assert_ok(ctx, mfree_context_set_error_handler(ctx, handler, NULL));

  pthread_t th[NTHREADS];
  job_t job[NTHREADS];
  for (int t = 0; t < NTHREADS; ++t) {
    job[t].role = t;
    job[t].wrong = 0;
    assert_int_equal(pthread_create(&th[t], NULL, worker, &job[t]), 0);
  }
  for (int t = 0; t < NTHREADS; ++t) assert_int_equal(pthread_join(th[t], NULL), 0);
  for (int t = 0; t < NTHREADS; ++t) assert_int_equal(job[t].wrong, 0);
  assert_int_equal(atomic_load(&bad_reads), 0);
  assert_int_equal(atomic_load(&handler_calls), NTHREADS * ITER / 2);
  assert_int_equal(atomic_load(&handler_bad), 0);

  /* afterwards the context holds one whole message of the two */
  char msg[256];
  mfree_status_t code = MFREE_SUCCESS;
  assert_ok(NULL, mfree_context_get_last_error(ctx, &code, msg, sizeof msg));
  assert_true(whole(msg, code));

  mfree_approximant_destroy(&ap);
  mfree_particles_destroy(&ps);
  mfree_context_destroy(&ctx);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_failing_calls_share_a_context)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
