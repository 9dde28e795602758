/* The fluid's rows filtered inside the approximants' fused rows of linear MLS (2D, the
 * cubic spline): its particle set leaves the rows from its Verlet candidates to the row
 * kernel, which keeps a candidate by the search's own pair test while it computes the
 * offsets. The rows and the values must be those of the unfused path bit for bit: the
 * set of a plain particle set (no skin: a fresh search, its rows filtered by the search)
 * and the library's MLS approximant on it (order 1, cubic spline, the same support:
 * the same fused kernel without the filter). On a jittered patch in a shear flow that
 * moves neighbours relative to each other by more than the skin (0.25 h) over the run,
 * so that the candidates are reused and rebuilt, and on the lattice without jitter (pairs
 * at exactly the support radius), at every step, on one and two threads:
 * - the pattern of the interpolation matrix S_kj = N_j(x_k) is the approximant's, entry
 *   for entry (pairs at exactly 2h included: the closed support);
 * - S equals the approximant's value table bitwise at every site where both take the MLS
 *   rows (condition number at most 100, the fluid's Shepard threshold);
 * - the runs on one and two threads are bitwise the same. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static mfree_context_t *ctx;
static int setup(void **s) { (void)s; return mfree_context_create(&ctx) != MFREE_SUCCESS; }
static int teardown(void **s) { (void)s; return mfree_context_destroy(&ctx) != MFREE_SUCCESS; }

/* 48 x 48 particles: more than the 2048 sites below which loops run on one thread */
enum { L = 48, N = L * L, DIM = 2 };
static const double D = 0.005, RHO0 = 1000.0, G = 9.81, GAMMA = 7.0, U = 5.0;
static const double HS = 1.5 * 0.005; /* smoothing length h = 1.5 D, support 2h */

/* Lattice (jittered by up to jitter D), uniform density, shear flow v_0 = U sin(2 pi y /
 * (8 D)). */
static double *sheared_patch(double *m, double jitter) {
  double *y = calloc((2 * (size_t)DIM + 1) * N, sizeof(double));
  mfree_rng_t r;
  mfree_rng_seed(&r, 212);
  for (int p = 0; p < N; ++p) {
    y[DIM * p] = (p % L + 0.5) * D + jitter * D * (2 * mfree_rng_uniform(&r) - 1);
    y[DIM * p + 1] = (p / L + 0.5) * D + jitter * D * (2 * mfree_rng_uniform(&r) - 1);
    y[(size_t)DIM * N + DIM * p] = U * sin(2.0 * M_PI * y[DIM * p + 1] / (8.0 * D));
    y[2 * (size_t)DIM * N + p] = RHO0;
    m[p] = RHO0 * D * D;
  }
  return y;
}

static int one_step(void *user, int64_t step, double t, double dt) {
  (void)user;
  (void)t;
  (void)dt;
  return step >= 1;
}

/* The unfused reference at positions y: the approximant's rows, values and conditions. */
static void reference(const double *y, int64_t *rp, int32_t **cols, double **val, double *cond) {
  mfree_particles_t *ps = NULL;
  mfree_approximant_t *a = NULL;
  mfree_test_fluid_approximant(ctx, DIM, N, y, HS, NULL, &ps, &a);
  int64_t nnz = 0;
  assert_ok(ctx, mfree_approximant_get_nnz(a, &nnz));
  *cols = malloc((size_t)nnz * sizeof(int32_t));
  *val = malloc((size_t)nnz * sizeof(double));
  assert_ok(ctx, mfree_approximant_assemble_csr(a, MFREE_DERIV_VALUE, 0, rp, *cols, *val));
  assert_ok(ctx, mfree_approximant_get_condition(a, cond));
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
}

/* Runs the patch for `steps` leap-frog steps on `threads` threads, checking S against
 * the reference after every step; the final state to yout. Returns the rows compared. */
static int run(int threads, int steps, double jitter, double *yout) {
  assert_ok(ctx, mfree_context_set_num_threads(ctx, threads));
  double *m = malloc((size_t)N * sizeof(double));
  double *y = sheared_patch(m, jitter);
  const double kappa = 100.0 * RHO0 * 2.0 * G * (L * D) / GAMMA; /* 003 eq 125 */
  mfree_system_t *sys = mfree_test_fluid_create(ctx, N, m, RHO0, kappa, GAMMA, 1e-3, HS);
  int64_t *rp = malloc(((size_t)N + 1) * sizeof(int64_t));
  double *cond = malloc((size_t)N * sizeof(double));
  double t = 0.0;
  int compared = 0;
  for (int step = 0; step <= steps; ++step) {
    if (step > 0) {
      int64_t done = 0;
      assert_ok(ctx, mfree_system_integrate(sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, 1.0, 0.25, 0.0, one_step, NULL,
                                            &done));
      assert_int_equal(done, 1);
    }
    mfree_matrix_t *S = NULL;
    assert_ok(ctx, mfree_system_assemble_interpolation(sys, y, &S));
    const int64_t *sp;
    const int32_t *sc;
    const double *sv;
    assert_ok(ctx, mfree_matrix_get_csr(S, &sp, &sc, &sv));
    int32_t *cols;
    double *val;
    reference(y, rp, &cols, &val, cond);
    for (int k = 0; k <= N; ++k)
      if (sp[k] != rp[k])
        fail_msg("%d threads, step %d: row %d of S starts at %lld, the unfused rows at %lld", threads, step, k,
                 (long long)sp[k], (long long)rp[k]);
    for (int64_t e = 0; e < rp[N]; ++e)
      if (sc[e] != cols[e])
        fail_msg("%d threads, step %d: entry %lld of S is column %d, the unfused rows say %d", threads, step,
                 (long long)e, sc[e], cols[e]);
    for (int k = 0; k < N; ++k) {
      if (!(cond[k] <= 100.0)) continue;
      for (int64_t e = rp[k]; e < rp[k + 1]; ++e)
        if (memcmp(&sv[e], &val[e], sizeof(double)) != 0)
          fail_msg("%d threads, step %d: N_%d(x_%d) = %a, unfused %a", threads, step, cols[e], k, sv[e], val[e]);
      ++compared;
    }
    free(cols);
    free(val);
    mfree_matrix_destroy(&S);
  }
  memcpy(yout, y, (2 * (size_t)DIM + 1) * N * sizeof(double));
  free(rp);
  free(cond);
  free(y);
  free(m);
  mfree_system_destroy(&sys);
  return compared;
}

#ifdef __OPTIMIZE__
enum { STEPS = 12 };
#else
enum { STEPS = 6 };
#endif

static void fused_equals_unfused(double jitter) {
  const size_t ny = (2 * (size_t)DIM + 1) * N;
  double *y1 = malloc(ny * sizeof(double)), *y2 = malloc(ny * sizeof(double));
  const int c1 = run(1, STEPS, jitter, y1), c2 = run(2, STEPS, jitter, y2);
  assert_true(c1 > STEPS * N / 2);
  assert_int_equal(c1, c2);
  if (memcmp(y1, y2, ny * sizeof(double)) != 0) fail_msg("the states after %d steps differ on 1 and 2 threads", STEPS);
  free(y1);
  free(y2);
}

static void test_jittered(void **s) {
  (void)s;
  fused_equals_unfused(0.2);
}

/* pairs at exactly the support radius 2h = 3 D along the lattice's axes */
static void test_lattice(void **s) {
  (void)s;
  fused_equals_unfused(0.0);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_jittered),
      cmocka_unit_test(test_lattice),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
