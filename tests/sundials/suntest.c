#include "suntest.h"

#include <math.h>
#include <time.h>

double sun_kappa(void) { return 100.0 * SUN_RHO0 * 2.0 * 9.81 * SUN_H / SUN_GAMMA; }

mfree_system_t *sun_fluid(mfree_context_t *ctx) {
  mfree_system_t *s = NULL;
  const double rho0 = SUN_RHO0, m = SUN_RHO0 * SUN_D * SUN_D;
  assert_ok(ctx, mfree_system_create_fluid(ctx, 2, SUN_N, &s));
  assert_ok(ctx, mfree_system_set_fluid(s, &rho0, 0, sun_kappa(), SUN_GAMMA, SUN_MU));
  assert_ok(ctx, mfree_system_set_masses(s, &m, 0));
  assert_ok(ctx, mfree_system_set_smoothing(s, 1.5 * SUN_D));
  return s;
}

int sun_fixture_setup(mfree_context_t **ctx, SUNContext *sunctx, double *ystart) {
  if (mfree_context_create(ctx) != MFREE_SUCCESS) return 1;
  if (SUNContext_Create(MFREE_SUNDIALS_COMM_NULL, sunctx) != 0) return 1;
  sun_initial_state(ystart);
  return 0;
}

int sun_fixture_teardown(mfree_context_t **ctx, SUNContext *sunctx) {
  SUNContext_Free(sunctx);
  return mfree_context_destroy(ctx) != MFREE_SUCCESS;
}

void sun_initial_state(double *y) {
  const double L = SUN_NX * SUN_D, k = 3.14159265358979323846 / L;
  for (int j = 0; j < SUN_NX; ++j)
    for (int i = 0; i < SUN_NX; ++i) {
      const int p = j * SUN_NX + i;
      const double x = (i + 0.5) * SUN_D, z = (j + 0.5) * SUN_D;
      y[2 * p] = x;
      y[2 * p + 1] = z;
      y[2 * SUN_N + 2 * p] = SUN_U * sin(k * x) * cos(k * z);
      y[2 * SUN_N + 2 * p + 1] = -SUN_U * cos(k * x) * sin(k * z);
      y[4 * SUN_N + p] = SUN_RHO0;
    }
}

static double block(const double *a, const double *b, const double *y0, int lo, int hi) {
  double diff = 0.0, scale = 0.0;
  for (int q = lo; q < hi; ++q) {
    diff = fmax(diff, fabs(a[q] - b[q]));
    scale = fmax(scale, fabs(y0 ? b[q] - y0[q] : b[q]));
  }
  return scale > 0.0 ? diff / scale : diff;
}

sun_diff_t sun_compare(const double *a, const double *b, const double *y0) {
  sun_diff_t d;
  d.x = block(a, b, y0, 0, 2 * SUN_N);
  d.v = block(a, b, NULL, 2 * SUN_N, 4 * SUN_N);
  d.rho = block(a, b, y0, 4 * SUN_N, 5 * SUN_N);
  return d;
}

double sun_diff_max(sun_diff_t d) { return fmax(d.x, fmax(d.v, d.rho)); }

double sun_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
