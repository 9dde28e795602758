#include "testutil.h"

#include <math.h>
#include <string.h>

void mfree_test_expect_error(mfree_context_t *ctx, mfree_status_t got, mfree_status_t expected,
                             const char *needle, const char *what) {
  char msg[1024] = "";
  mfree_status_t code = MFREE_SUCCESS;
  if (ctx) mfree_context_get_last_error(ctx, &code, msg, sizeof msg);
  if (got != expected)
    fail_msg("%s returned %d (%s), expected %d; last error: %s", what, (int)got,
             mfree_status_string(got), (int)expected, msg);
  if (ctx) {
    if (code != expected) fail_msg("%s: context code %d, expected %d", what, (int)code, (int)expected);
    if (msg[0] == '\0') fail_msg("%s: empty message on the context", what);
    if (needle && !strstr(msg, needle))
      fail_msg("%s: message \"%s\" does not mention \"%s\"", what, msg, needle);
  }
}

void mfree_rng_seed(mfree_rng_t *r, uint64_t seed) { r->s = seed * 2654435761u + 88172645463325252ull; }

double mfree_rng_uniform(mfree_rng_t *r) {
  r->s ^= r->s >> 12;
  r->s ^= r->s << 25;
  r->s ^= r->s >> 27;
  return (double)((r->s * 2685821657736338717ull) >> 11) * (1.0 / 9007199254740992.0);
}

double mfree_test_lumped_mass_rel_diff(mfree_context_t *ctx, mfree_system_t *sys, const double *y,
                                       const double *m, int n) {
  mfree_matrix_t *M = NULL;
  assert_ok(ctx, mfree_system_assemble_mass(sys, y, 0, &M));
  const int64_t *rp;
  const int32_t *ci;
  const double *mv;
  assert_ok(ctx, mfree_matrix_get_csr(M, &rp, &ci, &mv));
  double total = 0.0, lumped = 0.0;
  for (int q = 0; q < n; ++q) {
    total += m[q];
    lumped += mv[rp[2 * n + 2 * q]];
  }
  mfree_matrix_destroy(&M);
  return fabs(lumped - total) / total;
}
