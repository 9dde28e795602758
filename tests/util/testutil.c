#include "testutil.h"

#include <math.h>
#include <stdlib.h>
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

void mfree_test_lumped_masses(mfree_context_t *ctx, mfree_system_t *sys, const double *y, int dim, int n,
                              double *Mi) {
  mfree_matrix_t *M = NULL;
  assert_ok(ctx, mfree_system_assemble_mass(sys, y, 0, &M));
  const int64_t *rp;
  const int32_t *ci;
  const double *mv;
  assert_ok(ctx, mfree_matrix_get_csr(M, &rp, &ci, &mv));
  const int64_t vel = (int64_t)dim * n, rho = 2 * vel;
  for (int64_t row = 0; row < rho + n; ++row) { /* state: x (dim n), v (dim n), rho (n) */
    assert_int_equal(rp[row + 1] - rp[row], 1);
    assert_int_equal(ci[rp[row]], row);
    if (row < vel || row >= rho) assert_true(mv[rp[row]] == 1.0);
  }
  for (int q = 0; q < n; ++q) {
    Mi[q] = mv[rp[vel + (int64_t)dim * q]];
    for (int c = 1; c < dim; ++c) assert_true(mv[rp[vel + (int64_t)dim * q + c]] == Mi[q]);
  }
  mfree_matrix_destroy(&M);
}

double mfree_test_lumped_mass_rel_diff(mfree_context_t *ctx, mfree_system_t *sys, const double *y,
                                       const double *m, int n) {
  double *Mi = malloc(sizeof(double) * (size_t)n), total = 0.0, lumped = 0.0;
  assert_non_null(Mi);
  mfree_test_lumped_masses(ctx, sys, y, 2, n, Mi);
  for (int q = 0; q < n; ++q) {
    total += m[q];
    lumped += Mi[q];
  }
  free(Mi);
  return fabs(lumped - total) / total;
}

int32_t mfree_test_backend(int argc, char **argv) {
  return argc > 1 && strcmp(argv[1], "ref") == 0 ? MFREE_BACKEND_REF : MFREE_BACKEND_OPT;
}
