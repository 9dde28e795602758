/* The Galerkin-SPH fluid's own shape-function tables (src/core/fluid.cpp: linear MLS
 * with the cubic spline, rebuilt at every evaluation on Verlet candidate lists that are
 * reused while no particle has moved more than half the skin) against independent
 * references, on a jittered patch in a shear flow that moves the particles by about
 * 0.05 h per step and neighbours relative to each other by up to about 0.1 h per step
 * (more than the skin, 0.25 h, within the test), so that the candidate lists are both
 * reused and rebuilt and a missed rebuild would lose pairs:
 * - the pattern of the interpolation matrix S_kj = N_j(x_k) is exactly the O(N^2) set
 *   of pairs closer than 2h, after every step;
 * - S and the density rates -rho_k sum_j v_j . grad N_j(x_k) equal the tables of the
 *   library's MLS approximant (order 1, cubic spline, same support) to round-off at
 *   every well-conditioned site (condition number < 50; the fluid switches to Shepard
 *   functions above 100, 003 Sect. 6);
 * - the state after several steps is bitwise the same with 1, 2 and 3 threads. */
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

/* 48 x 48 = 2304 particles: more than the 2048 sites below which loops run on one thread */
enum { NX = 48, NZ = 48, N = NX * NZ };
static const double D = 0.005, RHO0 = 1000.0, G = 9.81, GAMMA = 7.0, U = 5.0;
static const double HS = 1.5 * 0.005; /* smoothing length h = 1.5 D, support 2h */
static double kappa(void) { return 100.0 * RHO0 * 2.0 * G * (NZ * D) / GAMMA; } /* 003 eq 125 */

/* Jittered lattice, uniform density, shear flow v_x = U sin(2 pi z / (8 D)). */
static double *sheared_patch(double *m) {
  double *y = calloc(5 * (size_t)N, sizeof(double));
  mfree_rng_t r;
  mfree_rng_seed(&r, 706);
  for (int j = 0; j < NZ; ++j)
    for (int i = 0; i < NX; ++i) {
      const int p = j * NX + i;
      y[2 * p] = (i + 0.5) * D + 0.2 * D * (2 * mfree_rng_uniform(&r) - 1);
      y[2 * p + 1] = (j + 0.5) * D + 0.2 * D * (2 * mfree_rng_uniform(&r) - 1);
      y[2 * N + 2 * p] = U * sin(2.0 * M_PI * y[2 * p + 1] / (8.0 * D));
      y[4 * N + p] = RHO0;
      m[p] = RHO0 * D * D;
    }
  return y;
}

static mfree_system_t *fluid(const double *m) {
  mfree_system_t *s = NULL;
  assert_ok(ctx, mfree_system_create_fluid(ctx, 2, N, &s));
  assert_ok(ctx, mfree_system_set_fluid(s, &RHO0, 0, kappa(), GAMMA, 1e-3));
  assert_ok(ctx, mfree_system_set_masses(s, m, 1));
  assert_ok(ctx, mfree_system_set_smoothing(s, HS));
  return s;
}

static int one_step(void *user, int64_t step, double t, double dt) {
  (void)user;
  (void)t;
  (void)dt;
  return step >= 1;
}

/* Neighbours of every particle closer than 2h, by brute force, in column order. */
static int64_t brute_pairs(const double *y, int64_t *rp, int32_t *cols) {
  int64_t nnz = 0;
  const double R2 = 4.0 * HS * HS;
  for (int k = 0; k < N; ++k) {
    rp[k] = nnz;
    for (int j = 0; j < N; ++j) {
      const double dx = y[2 * j] - y[2 * k], dz = y[2 * j + 1] - y[2 * k + 1];
      if (dx * dx + dz * dz < R2) {
        if (cols) cols[nnz] = j;
        ++nnz;
      }
    }
  }
  rp[N] = nnz;
  return nnz;
}

/* The approximant reference at state y: values and gradients (CSR) and conditions. */
typedef struct {
  int64_t rp[N + 1];
  int32_t *cols;
  double *val, *gx, *gz, cond[N];
} reference_t;

static void reference(const double *y, const double *m, reference_t *ref) {
  mfree_particles_t *ps = NULL;
  mfree_approximant_t *a = NULL;
  double vol[N];
  for (int i = 0; i < N; ++i) vol[i] = m[i] / y[4 * N + i];
  assert_ok(ctx, mfree_particles_create(ctx, 2, N, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, y, MFREE_LAYOUT_AOS, 2, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_volumes(ps, vol, 1, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_support(ps, &HS, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_setup(ps));
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, &a));
  assert_ok(ctx, mfree_approximant_set_kernel(a, MFREE_KERNEL_CUBIC_SPLINE, 0.0));
  assert_ok(ctx, mfree_approximant_set_order(a, 1));
  assert_ok(ctx, mfree_approximant_set_fallback(a, MFREE_FALLBACK_LOWER_ORDER));
  assert_ok(ctx, mfree_approximant_setup(a));
  int64_t nnz = 0;
  assert_ok(ctx, mfree_approximant_get_nnz(a, &nnz));
  ref->cols = malloc((size_t)nnz * sizeof(int32_t));
  ref->val = malloc((size_t)nnz * sizeof(double));
  ref->gx = malloc((size_t)nnz * sizeof(double));
  ref->gz = malloc((size_t)nnz * sizeof(double));
  assert_ok(ctx, mfree_approximant_assemble_csr(a, MFREE_DERIV_VALUE, 0, ref->rp, ref->cols, ref->val));
  assert_ok(ctx, mfree_approximant_assemble_csr(a, MFREE_DERIV_GRADIENT, 0, ref->rp, ref->cols, ref->gx));
  assert_ok(ctx, mfree_approximant_assemble_csr(a, MFREE_DERIV_GRADIENT, 1, ref->rp, ref->cols, ref->gz));
  assert_ok(ctx, mfree_approximant_get_condition(a, ref->cond));
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
}

static void free_reference(reference_t *ref) {
  free(ref->cols);
  free(ref->val);
  free(ref->gx);
  free(ref->gz);
}

static void test_tables_against_references(void **s) {
  (void)s;
  double m[N];
  double *y = sheared_patch(m);
  mfree_system_t *sys = fluid(m);
  int64_t *brp = malloc((N + 1) * sizeof(int64_t));
  double *yd = calloc(5 * (size_t)N, sizeof(double));
  reference_t *ref = malloc(sizeof *ref);
  double t = 0.0;
  int checked_rows = 0;
  double *y0 = malloc(2 * (size_t)N * sizeof(double));
  memcpy(y0, y, 2 * (size_t)N * sizeof(double));
  int64_t *rp0 = malloc((N + 1) * sizeof(int64_t));
  int32_t *cols0 = malloc((size_t)brute_pairs(y, rp0, NULL) * sizeof(int32_t));
  brute_pairs(y, rp0, cols0);
  for (int step = 0; step <= 12; ++step) {
    if (step > 0) {
      int64_t done = 0;
      assert_ok(ctx, mfree_system_integrate(sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, 1.0, 0.25, 0.0, one_step,
                                            NULL, &done));
      assert_int_equal(done, 1);
    }
    /* pattern: exactly the pairs closer than 2h (Verlet lists reused or rebuilt) */
    mfree_matrix_t *S = NULL;
    assert_ok(ctx, mfree_system_assemble_interpolation(sys, y, &S));
    const int64_t *rp;
    const int32_t *ci;
    const double *sv;
    assert_ok(ctx, mfree_matrix_get_csr(S, &rp, &ci, &sv));
    const int64_t nnz = brute_pairs(y, brp, NULL);
    int32_t *bcols = malloc((size_t)nnz * sizeof(int32_t));
    brute_pairs(y, brp, bcols);
    for (int k = 0; k <= N; ++k)
      if (rp[k] != brp[k]) fail_msg("step %d: row %d of S starts at %lld, the O(N^2) pairs at %lld", step, k,
                                    (long long)rp[k], (long long)brp[k]);
    for (int64_t e = 0; e < nnz; ++e)
      if (ci[e] != bcols[e]) fail_msg("step %d: entry %lld of S is column %d, the O(N^2) pairs say %d", step,
                                      (long long)e, ci[e], bcols[e]);
    /* values and density rates against the MLS approximant where it is well conditioned */
    reference(y, m, ref);
    assert_ok(ctx, mfree_system_rhs(sys, t, y, yd));
    for (int k = 0; k < N; ++k) {
      if (!(ref->cond[k] < 50.0)) continue;
      /* merge the two rows by column: the search may hand the approximant pairs at
       * exactly 2h (zero weight), which the fluid leaves out */
      double div = 0.0, scale = 0.0;
      int64_t e = rp[k], f = ref->rp[k];
      while (e < rp[k + 1] || f < ref->rp[k + 1]) {
        const int32_t ce = e < rp[k + 1] ? ci[e] : N, cf = f < ref->rp[k + 1] ? ref->cols[f] : N;
        const double mine = ce <= cf ? sv[e] : 0.0, theirs = cf <= ce ? ref->val[f] : 0.0;
        if (fabs(mine - theirs) > 1e-12)
          fail_msg("step %d: N_%d(x_%d) = %.17g, approximant %.17g", step, ce < cf ? ce : cf, k, mine, theirs);
        if (cf <= ce) {
          const double *vj = y + 2 * N + 2 * cf;
          div += vj[0] * ref->gx[f] + vj[1] * ref->gz[f];
          scale += fabs(vj[0] * ref->gx[f]) + fabs(vj[1] * ref->gz[f]);
        }
        e += ce <= cf;
        f += cf <= ce;
      }
      const double want = -y[4 * N + k] * div, tol = 1e-11 * y[4 * N + k] * scale;
      if (fabs(yd[4 * N + k] - want) > tol) fail_msg("step %d: drho/dt at %d = %.17g, approximant gradients %.17g", step,
                                                     k, yd[4 * N + k], want);
      ++checked_rows;
    }
    free_reference(ref);
    free(bcols);
    mfree_matrix_destroy(&S);
  }
  /* the flow moved neighbours relative to each other by more than the skin (0.25 h) */
  double rel = 0.0;
  for (int k = 0; k < N; ++k)
    for (int64_t e = rp0[k]; e < rp0[k + 1]; ++e) {
      const int j = cols0[e];
      const double dx = (y[2 * j] - y0[2 * j]) - (y[2 * k] - y0[2 * k]);
      const double dz = (y[2 * j + 1] - y0[2 * j + 1]) - (y[2 * k + 1] - y0[2 * k + 1]);
      rel = fmax(rel, sqrt(dx * dx + dz * dz));
    }
  if (!(rel > 0.5 * HS)) fail_msg("largest relative displacement of neighbours %g h: too small a test", rel / HS);
  assert_true(checked_rows > 12 * N / 2);
  free(y0);
  free(rp0);
  free(cols0);
  free(ref);
  free(yd);
  free(brp);
  free(y);
  mfree_system_destroy(&sys);
}

static void test_threads_bitwise(void **s) {
  (void)s;
  double m[N];
  double *want = NULL;
  for (int threads = 1; threads <= 3; ++threads) {
    double *y = sheared_patch(m);
    mfree_system_t *sys = fluid(m);
    const double g[2] = {0.0, -G};
    assert_ok(ctx, mfree_system_set_gravity(sys, g));
    assert_ok(ctx, mfree_context_set_num_threads(ctx, threads));
    double t = 0.0;
    int64_t done = 0;
    for (int step = 0; step < 8; ++step)
      assert_ok(ctx, mfree_system_integrate(sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, 1.0, 0.25, 0.0, one_step, NULL,
                                            &done));
    if (!want) {
      want = y;
    } else {
      if (memcmp(want, y, 5 * (size_t)N * sizeof(double)) != 0) fail_msg("%d threads: state differs from 1 thread", threads);
      free(y);
    }
    mfree_system_destroy(&sys);
  }
  assert_ok(ctx, mfree_context_set_num_threads(ctx, 1));
  free(want);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_tables_against_references),
      cmocka_unit_test(test_threads_bitwise),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
