/* The reference backend runs the baseline copies of the kernels that have no reference
 * path of their own (the fluid's force assembly, the neighbour search): a fluid's
 * right-hand side on a context with MFREE_BACKEND_REF is bitwise the same whether or not
 * MFREE_SIMD=baseline holds the optimised kernels on their baseline copies. On a CPU with
 * AVX2 + FMA the AVX2 copies round differently (fused multiply-adds), so a reference
 * backend that took them without the override would fail the comparison. (The fluid's
 * rows come from the approximants, whose reference path differs from the optimised one
 * at round-off: the optimised backend is compared to round-off only.) */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"

enum { NX = 16, NZ = 12, N = NX * NZ };
static const double D = 0.005, RHO0 = 1000.0, G = 9.81, GAMMA = 7.0;

/* A jittered lattice with random velocities and densities: state y (x, v, rho), masses m. */
static void patch(double *y, double *m) {
  mfree_rng_t r;
  mfree_rng_seed(&r, 7);
  for (int j = 0; j < NZ; ++j)
    for (int i = 0; i < NX; ++i) {
      const int p = j * NX + i;
      y[2 * p] = (i + 0.5) * D + 0.2 * D * (2 * mfree_rng_uniform(&r) - 1);
      y[2 * p + 1] = (j + 0.5) * D + 0.2 * D * (2 * mfree_rng_uniform(&r) - 1);
      y[2 * N + 2 * p] = 0.3 * (2 * mfree_rng_uniform(&r) - 1);
      y[2 * N + 2 * p + 1] = 0.3 * (2 * mfree_rng_uniform(&r) - 1);
      y[4 * N + p] = RHO0 * (1 + 0.01 * (2 * mfree_rng_uniform(&r) - 1));
      m[p] = y[4 * N + p] * D * D;
    }
}

/* The right-hand side of the fluid on a fresh context with the given backend. */
static void rhs(mfree_backend_t backend, const double *y, const double *m, double *yd) {
  mfree_context_t *ctx = NULL;
  assert_int_equal(mfree_context_create(&ctx), MFREE_SUCCESS);
  assert_ok(ctx, mfree_context_set_backend(ctx, backend));
  mfree_system_t *s = NULL;
  const double kappa = 100.0 * RHO0 * 2.0 * G * (NZ * D) / GAMMA, g[2] = {0.0, -G};
  assert_ok(ctx, mfree_system_create_fluid(ctx, 2, N, &s));
  assert_ok(ctx, mfree_system_set_fluid(s, &RHO0, 0, kappa, GAMMA, 1e-3));
  assert_ok(ctx, mfree_system_set_masses(s, m, 1));
  assert_ok(ctx, mfree_system_set_smoothing(s, 1.5 * D));
  assert_ok(ctx, mfree_system_set_gravity(s, g));
  assert_ok(ctx, mfree_system_rhs(s, 0.0, y, yd));
  assert_ok(ctx, mfree_system_destroy(&s));
  assert_int_equal(mfree_context_destroy(&ctx), MFREE_SUCCESS);
}

static void test_reference_is_baseline(void **st) {
  (void)st;
  double *y = calloc(5 * (size_t)N, sizeof(double)), m[N];
  double *ref = calloc(5 * (size_t)N, sizeof(double)), *base = calloc(5 * (size_t)N, sizeof(double));
  patch(y, m);
  double *opt = calloc(5 * (size_t)N, sizeof(double));
  unsetenv("MFREE_SIMD");
  rhs(MFREE_BACKEND_REF, y, m, ref);
  rhs(MFREE_BACKEND_OPT, y, m, opt);
  setenv("MFREE_SIMD", "baseline", 1);
  rhs(MFREE_BACKEND_REF, y, m, base);
  unsetenv("MFREE_SIMD");
  double big = 0.0;
  for (int i = 0; i < 5 * N; ++i) {
    assert_true(isfinite(ref[i]));
    big = fmax(big, fabs(ref[i]));
  }
  assert_true(big > 0.0); /* a right-hand side that moves something */
  assert_memory_equal(ref, base, 5 * (size_t)N * sizeof(double));
  /* the two backends: the same right-hand side up to round-off of the rows */
  for (int i = 0; i < 5 * N; ++i) assert_true(fabs(opt[i] - ref[i]) <= 1e-12 * big);
  free(opt);
  free(y);
  free(ref);
  free(base);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_reference_is_baseline)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
