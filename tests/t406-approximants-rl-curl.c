/* Integrability of particle-only gradients (paper 000 Sect. 4.4.6: Randles-
 * Libersky derivatives "are not integrable"). For SPH and RL the row of particle i uses
 * x_i only as the evaluation point for the columns j != i, so moving particle i by
 * +-eps gives central differences of G_j(x) in x, and the curl
 * d/dy G^x_j - d/dx G^y_j follows. The SPH kernel gradient is a true gradient (curl at
 * finite-difference level), RL's renormalised gradient is not (clearly non-zero). */
#include <math.h>
#include <string.h>

#include "testutil.h"

enum { M = 10, N = M * M };

static mfree_context_t *ctx;
static int setup(void **s) { (void)s; return mfree_context_create(&ctx) != MFREE_SUCCESS; }
static int teardown(void **s) { (void)s; return mfree_context_destroy(&ctx) != MFREE_SUCCESS; }

/* Gradient component c of row i, as a dense row over all particles. */
static void grad_row(mfree_approximant_t *a, int i, int c, double *row) {
  static int64_t rp[N + 1];
  static int32_t cols[N * N];
  static double vals[N * N];
  assert_ok(ctx, mfree_approximant_assemble_csr(a, MFREE_DERIV_GRADIENT, c, rp, cols, vals));
  memset(row, 0, sizeof(double) * N);
  for (int64_t k = rp[i]; k < rp[i + 1]; ++k) row[cols[k]] = vals[k];
}

/* Max over j != i of |curl G_j| h^2, relative to max |G_j| h. */
static double relative_curl(mfree_method_t method, double *x, int i, double h) {
  mfree_particles_t *ps = NULL;
  const double vol = 1.0 / N;
  assert_ok(ctx, mfree_particles_create(ctx, 2, N, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 2, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_volumes(ps, &vol, 0, MFREE_COPY));
  mfree_approximant_t *a = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, method, &a));
  const double eps = 1e-5 * h, x0 = x[2 * i], y0 = x[2 * i + 1];
  double gxp[N], gxm[N], gyp[N], gym[N], g0[N];
  assert_ok(ctx, mfree_particles_setup(ps));
  assert_ok(ctx, mfree_approximant_setup(a));
  grad_row(a, i, 0, g0);
  /* d/dy of G^x: move i along y */
  x[2 * i + 1] = y0 + eps;
  assert_ok(ctx, mfree_approximant_update(a));
  grad_row(a, i, 0, gxp);
  x[2 * i + 1] = y0 - eps;
  assert_ok(ctx, mfree_approximant_update(a));
  grad_row(a, i, 0, gxm);
  x[2 * i + 1] = y0;
  /* d/dx of G^y: move i along x */
  x[2 * i] = x0 + eps;
  assert_ok(ctx, mfree_approximant_update(a));
  grad_row(a, i, 1, gyp);
  x[2 * i] = x0 - eps;
  assert_ok(ctx, mfree_approximant_update(a));
  grad_row(a, i, 1, gym);
  x[2 * i] = x0;
  double cmax = 0.0, gmax = 0.0;
  for (int j = 0; j < N; ++j) {
    if (j == i) continue;
    const double cu = (gxp[j] - gxm[j]) / (2 * eps) - (gyp[j] - gym[j]) / (2 * eps);
    cmax = fmax(cmax, fabs(cu) * h * h);
    gmax = fmax(gmax, fabs(g0[j]) * h);
  }
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
  return cmax / gmax;
}

static void test_curl(void **s) {
  (void)s;
  double x[2 * N];
  mfree_rng_t r;
  mfree_rng_seed(&r, 5);
  for (int j = 0; j < M; ++j)
    for (int i = 0; i < M; ++i) {
      x[2 * (j * M + i)] = (i + 0.5 + 0.3 * (2 * mfree_rng_uniform(&r) - 1)) / M;
      x[2 * (j * M + i) + 1] = (j + 0.5 + 0.3 * (2 * mfree_rng_uniform(&r) - 1)) / M;
    }
  const double h = 1.6 / M;
  const int sites[3] = {44, 45, 55}; /* interior particles */
  for (int k = 0; k < 3; ++k) {
    const double sph = relative_curl(MFREE_METHOD_SPH, x, sites[k], h);
    const double rl = relative_curl(MFREE_METHOD_RANDLES_LIBERSKY, x, sites[k], h);
    if (!(sph < 1e-6)) fail_msg("site %d: SPH kernel-gradient curl %g (should vanish)", sites[k], sph);
    if (!(rl > 1e-3)) fail_msg("site %d: RL curl %g (should be clearly non-zero)", sites[k], rl);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_curl)};
  return cmocka_run_group_tests(tests, setup, teardown);
}
