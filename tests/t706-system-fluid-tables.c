/* The Galerkin-SPH fluid's shape-function tables (src/core/systems/fluid_tables.cpp: linear
 * MLS with the cubic spline by the approximants' row kernels, rebuilt at every evaluation on
 * the rows of the particle set's search with a Verlet skin, whose candidate lists are
 * reused while no particle has moved more than half the skin) against independent
 * references, on a jittered patch in a shear flow that moves the particles by about
 * 0.05 h per step and neighbours relative to each other by up to about 0.1 h per step
 * (more than the skin, 0.25 h, within the test), so that the candidate lists are both
 * reused and rebuilt and a missed rebuild would lose pairs:
 * - the pattern of the interpolation matrix S_kj = N_j(x_k) is exactly the O(N^2) set
 *   of pairs at most 2h apart (the closed support of every approximant), after every step;
 * - S and the density rates -rho_k sum_j v_j . grad N_j(x_k) equal the tables of the
 *   library's MLS approximant (order 1, cubic spline, same support) to round-off at
 *   every well-conditioned site (condition number < 50; the fluid switches to Shepard
 *   functions above 100, 003 Sect. 6);
 * - the state after several steps is bitwise the same with 1, 2 and 3 threads;
 * - in a random particle order the run is the lattice-ordered one up to the permutation
 *   and round-off, and bitwise the same with 1 and 2 threads. */
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

/* 2D: 48 x 48 = 2304 particles, 3D: 14^3 = 2744, more than the 2048 sites below which
 * loops run on one thread; the state is (x, v, rho) with dim components for x and v. */
static int DIM = 2, N = 48 * 48;
static const double D = 0.005, RHO0 = 1000.0, G = 9.81, GAMMA = 7.0, U = 5.0;
static const double HS = 1.5 * 0.005; /* smoothing length h = 1.5 D, support 2h */
static int side(void) { return DIM == 2 ? 48 : 14; }
static double kappa(void) { return 100.0 * RHO0 * 2.0 * G * (side() * D) / GAMMA; } /* 003 eq 125 */
static void set_dim(int dim) {
  DIM = dim;
  N = dim == 2 ? 48 * 48 : 14 * 14 * 14;
}

/* Jittered lattice, uniform density, shear flow v_0 = U sin(2 pi z / (8 D)), z the last
 * coordinate. */
static double *sheared_patch(double *m) {
  const int dim = DIM, n = N, L = side();
  double *y = calloc((2 * (size_t)dim + 1) * n, sizeof(double));
  mfree_rng_t r;
  mfree_rng_seed(&r, 706);
  for (int p = 0; p < n; ++p) {
    int q = p;
    for (int c = 0; c < dim; ++c, q /= L)
      y[dim * p + c] = (q % L + 0.5) * D + 0.2 * D * (2 * mfree_rng_uniform(&r) - 1);
    y[(size_t)dim * n + dim * p] = U * sin(2.0 * M_PI * y[dim * p + dim - 1] / (8.0 * D));
    y[2 * (size_t)dim * n + p] = RHO0;
    m[p] = RHO0 * pow(D, dim);
  }
  return y;
}

static mfree_system_t *fluid(const double *m) {
  mfree_system_t *s = NULL;
  assert_ok(ctx, mfree_system_create_fluid(ctx, DIM, N, &s));
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

static double dist2(const double *y, int a, int b) {
  double r2 = 0.0;
  for (int c = 0; c < DIM; ++c) r2 += (y[DIM * a + c] - y[DIM * b + c]) * (y[DIM * a + c] - y[DIM * b + c]);
  return r2;
}

/* Neighbours of every particle at most 2h away (closed support), by brute force, in column order (cols
 * holds MAXROW per particle: ~30 neighbours in 2D and ~115 in 3D). */
enum { MAXROW = 256 };
static int64_t brute_pairs(const double *y, int64_t *rp, int32_t *cols) {
  int64_t nnz = 0;
  const double R2 = 4.0 * HS * HS;
  for (int k = 0; k < N; ++k) {
    rp[k] = nnz;
    for (int j = 0; j < N; ++j)
      if (dist2(y, j, k) <= R2) cols[nnz++] = j;
    assert_true(nnz - rp[k] <= MAXROW);
  }
  rp[N] = nnz;
  return nnz;
}

/* The approximant reference at state y: values and gradients (CSR) and conditions. */
typedef struct {
  int64_t *rp;
  int32_t *cols;
  double *val, *grad[3], *cond;
} reference_t;

static void reference(const double *y, const double *m, reference_t *ref) {
  mfree_particles_t *ps = NULL;
  mfree_approximant_t *a = NULL;
  double *vol = malloc((size_t)N * sizeof(double));
  for (int i = 0; i < N; ++i) vol[i] = m[i] / y[2 * (size_t)DIM * N + i];
  mfree_test_fluid_approximant(ctx, DIM, N, y, HS, vol, &ps, &a);
  int64_t nnz = 0;
  assert_ok(ctx, mfree_approximant_get_nnz(a, &nnz));
  ref->rp = malloc(((size_t)N + 1) * sizeof(int64_t));
  ref->cols = malloc((size_t)nnz * sizeof(int32_t));
  ref->val = malloc((size_t)nnz * sizeof(double));
  ref->cond = malloc((size_t)N * sizeof(double));
  assert_ok(ctx, mfree_approximant_assemble_csr(a, MFREE_DERIV_VALUE, 0, ref->rp, ref->cols, ref->val));
  for (int c = 0; c < DIM; ++c) {
    ref->grad[c] = malloc((size_t)nnz * sizeof(double));
    assert_ok(ctx, mfree_approximant_assemble_csr(a, MFREE_DERIV_GRADIENT, c, ref->rp, ref->cols, ref->grad[c]));
  }
  assert_ok(ctx, mfree_approximant_get_condition(a, ref->cond));
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
  free(vol);
}

static void free_reference(reference_t *ref) {
  free(ref->rp);
  free(ref->cols);
  free(ref->val);
  free(ref->cond);
  for (int c = 0; c < DIM; ++c) free(ref->grad[c]);
}

static void tables_against_references(int dim, int steps) {
  set_dim(dim);
  const size_t ny = (2 * (size_t)DIM + 1) * N, nd = (size_t)DIM * N;
  double *m = malloc((size_t)N * sizeof(double));
  double *y = sheared_patch(m);
  mfree_system_t *sys = fluid(m);
  int64_t *brp = malloc(((size_t)N + 1) * sizeof(int64_t));
  double *yd = calloc(ny, sizeof(double));
  reference_t ref;
  double t = 0.0;
  int checked_rows = 0;
  double *y0 = malloc(nd * sizeof(double));
  memcpy(y0, y, nd * sizeof(double));
  int64_t *rp0 = malloc(((size_t)N + 1) * sizeof(int64_t));
  int32_t *cols0 = malloc((size_t)N * MAXROW * sizeof(int32_t)), *bcols = malloc((size_t)N * MAXROW * sizeof(int32_t));
  brute_pairs(y, rp0, cols0);
  for (int step = 0; step <= steps; ++step) {
    if (step > 0) {
      int64_t done = 0;
      assert_ok(ctx, mfree_system_integrate(sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, 1.0, 0.25, 0.0, one_step,
                                            NULL, &done));
      assert_int_equal(done, 1);
    }
    /* pattern: exactly the pairs at most 2h apart (Verlet lists reused or rebuilt) */
    mfree_matrix_t *S = NULL;
    assert_ok(ctx, mfree_system_assemble_interpolation(sys, y, &S));
    const int64_t *rp;
    const int32_t *ci;
    const double *sv;
    assert_ok(ctx, mfree_matrix_get_csr(S, &rp, &ci, &sv));
    const int64_t nnz = brute_pairs(y, brp, bcols);
    for (int k = 0; k <= N; ++k)
      if (rp[k] != brp[k]) fail_msg("%dD step %d: row %d of S starts at %lld, the O(N^2) pairs at %lld", dim, step,
                                    k, (long long)rp[k], (long long)brp[k]);
    for (int64_t e = 0; e < nnz; ++e)
      if (ci[e] != bcols[e]) fail_msg("%dD step %d: entry %lld of S is column %d, the O(N^2) pairs say %d", dim,
                                      step, (long long)e, ci[e], bcols[e]);
    /* values and density rates against the MLS approximant where it is well conditioned */
    reference(y, m, &ref);
    assert_ok(ctx, mfree_system_rhs(sys, t, y, yd));
    for (int k = 0; k < N; ++k) {
      if (!(ref.cond[k] < 50.0)) continue;
      /* merge the two rows by column: a row may hold pairs at exactly 2h (zero
       * weight) that the other lacks */
      double div = 0.0, scale = 0.0;
      int64_t e = rp[k], f = ref.rp[k];
      while (e < rp[k + 1] || f < ref.rp[k + 1]) {
        const int32_t ce = e < rp[k + 1] ? ci[e] : N, cf = f < ref.rp[k + 1] ? ref.cols[f] : N;
        const double mine = ce <= cf ? sv[e] : 0.0, theirs = cf <= ce ? ref.val[f] : 0.0;
        if (fabs(mine - theirs) > 1e-12)
          fail_msg("%dD step %d: N_%d(x_%d) = %.17g, approximant %.17g", dim, step, ce < cf ? ce : cf, k, mine,
                   theirs);
        if (cf <= ce) {
          const double *vj = y + nd + (size_t)DIM * cf;
          for (int c = 0; c < DIM; ++c) {
            div += vj[c] * ref.grad[c][f];
            scale += fabs(vj[c] * ref.grad[c][f]);
          }
        }
        e += ce <= cf;
        f += cf <= ce;
      }
      const double rho = y[2 * nd + k], want = -rho * div, tol = 1e-11 * rho * scale;
      if (fabs(yd[2 * nd + k] - want) > tol)
        fail_msg("%dD step %d: drho/dt at %d = %.17g, approximant gradients %.17g", dim, step, k, yd[2 * nd + k], want);
      ++checked_rows;
    }
    free_reference(&ref);
    mfree_matrix_destroy(&S);
  }
  /* the flow moved neighbours relative to each other by more than the skin (0.25 h),
   * so that lists that were never rebuilt would miss pairs (checked by mutation) */
  double rel = 0.0;
  for (int k = 0; k < N; ++k)
    for (int64_t e = rp0[k]; e < rp0[k + 1]; ++e) {
      const int j = cols0[e];
      double r2 = 0.0;
      for (int c = 0; c < DIM; ++c) {
        const double d = (y[DIM * j + c] - y0[DIM * j + c]) - (y[DIM * k + c] - y0[DIM * k + c]);
        r2 += d * d;
      }
      rel = fmax(rel, sqrt(r2));
    }
  if (!(rel > 0.3 * HS)) fail_msg("%dD: largest relative displacement of neighbours %g h: too small a test", dim, rel / HS);
  assert_true(checked_rows > steps * N / 2);
  free(y0);
  free(rp0);
  free(cols0);
  free(bcols);
  free(yd);
  free(brp);
  free(y);
  free(m);
  mfree_system_destroy(&sys);
}

/* Fewer steps in unoptimised (sanitizer) builds, where the O(N^2) pairs dominate: 2D
 * steps move neighbours relative to each other by ~0.07 h, 3D steps (smaller c, longer
 * steps) by ~0.15 h. */
#ifdef __OPTIMIZE__
enum { STEPS_2D = 12, STEPS_3D = 6 };
#else
enum { STEPS_2D = 8, STEPS_3D = 4 };
#endif

static void test_tables_2d(void **s) {
  (void)s;
  tables_against_references(2, STEPS_2D);
}

static void test_tables_3d(void **s) {
  (void)s;
  tables_against_references(3, STEPS_3D);
}

static void test_threads_bitwise(void **s) {
  (void)s;
  for (int dim = 2; dim <= 3; ++dim) {
    set_dim(dim);
    const size_t ny = (2 * (size_t)DIM + 1) * N;
    double *m = malloc((size_t)N * sizeof(double));
    double *want = NULL;
    for (int threads = 1; threads <= 3; ++threads) {
      double *y = sheared_patch(m);
      mfree_system_t *sys = fluid(m);
      double g[3] = {0.0, 0.0, 0.0};
      g[DIM - 1] = -G;
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
        if (memcmp(want, y, ny * sizeof(double)) != 0) fail_msg("%dD, %d threads: state differs from 1 thread", dim, threads);
        free(y);
      }
      mfree_system_destroy(&sys);
    }
    assert_ok(ctx, mfree_context_set_num_threads(ctx, 1));
    free(want);
    free(m);
  }
}

/* The force assembly scatters rows in chunks coloured so that a colour's chunks touch
 * disjoint nodes (fluid.cpp). With the particles in a random order every chunk touches
 * every other, so each chunk gets its own colour: the run must be the lattice-ordered
 * run up to the permutation and round-off (sums taken in another order), and bitwise the
 * same for 1 and 2 threads. 8 leap-frog steps, 2D. */
static void test_shuffled_order(void **s) {
  (void)s;
  set_dim(2);
  const int n = N, dim = DIM;
  const size_t nd = (size_t)dim * n, ny = (2 * nd + (size_t)n);
  double *m = malloc((size_t)n * sizeof(double)), *ms = malloc((size_t)n * sizeof(double));
  int *perm = malloc((size_t)n * sizeof(int));
  mfree_rng_t r;
  mfree_rng_seed(&r, 7061);
  for (int p = 0; p < n; ++p) perm[p] = p;
  for (int p = n - 1; p > 0; --p) { /* Fisher-Yates: shuffled particle p is lattice particle perm[p] */
    const int q = (int)(mfree_rng_uniform(&r) * (p + 1)) % (p + 1), t = perm[p];
    perm[p] = perm[q];
    perm[q] = t;
  }
  double *runs[3] = {NULL, NULL, NULL}; /* lattice order 1 thread, shuffled 1 and 2 threads */
  for (int run = 0; run < 3; ++run) {
    double *y0 = sheared_patch(m), *y = y0;
    if (run > 0) {
      y = malloc(ny * sizeof(double));
      for (int p = 0; p < n; ++p) {
        for (int c = 0; c < dim; ++c) {
          y[dim * p + c] = y0[dim * perm[p] + c];
          y[nd + dim * p + c] = y0[nd + dim * perm[p] + c];
        }
        y[2 * nd + p] = y0[2 * nd + perm[p]];
        ms[p] = m[perm[p]];
      }
      free(y0);
    }
    mfree_system_t *sys = fluid(run > 0 ? ms : m);
    const double g[2] = {0.0, -G};
    assert_ok(ctx, mfree_system_set_gravity(sys, g));
    assert_ok(ctx, mfree_context_set_num_threads(ctx, run == 2 ? 2 : 1));
    double t = 0.0;
    int64_t done = 0;
    for (int step = 0; step < 8; ++step)
      assert_ok(ctx, mfree_system_integrate(sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, 1.0, 0.25, 0.0, one_step, NULL, &done));
    mfree_system_destroy(&sys);
    runs[run] = y;
  }
  assert_ok(ctx, mfree_context_set_num_threads(ctx, 1));
  if (memcmp(runs[1], runs[2], ny * sizeof(double)) != 0) fail_msg("shuffled order: 2 threads differ from 1");
  double ex = 0.0, ev = 0.0, er = 0.0;
  for (int p = 0; p < n; ++p) {
    const int q = perm[p];
    for (int c = 0; c < dim; ++c) {
      ex = fmax(ex, fabs(runs[1][dim * p + c] - runs[0][dim * q + c]));
      ev = fmax(ev, fabs(runs[1][nd + dim * p + c] - runs[0][nd + dim * q + c]));
    }
    er = fmax(er, fabs(runs[1][2 * nd + p] - runs[0][2 * nd + q]));
  }
  /* round-off of sums of ~25 terms over 8 steps (measured: |dx| 2.8e-17 m, |dv| 3.6e-15
   * m/s, |drho| 3.4e-13 kg/m^3, i.e. ~1e-16 relative); bounds 1e-13 relative */
  if (!(ex <= 1e-14 && ev <= 1e-13 * U && er <= 1e-13 * RHO0))
    fail_msg("shuffled order differs from lattice order beyond round-off: |dx| %g, |dv| %g, |drho| %g", ex, ev, er);
  for (int k = 0; k < 3; ++k) free(runs[k]);
  free(perm);
  free(ms);
  free(m);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_tables_2d),
      cmocka_unit_test(test_tables_3d),
      cmocka_unit_test(test_threads_bitwise),
      cmocka_unit_test(test_shuffled_order),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
