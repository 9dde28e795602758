/* The specialised value + gradient path (src/core/shape/shape_fast.cpp) against the
 * general per-site path of local.cpp. Asking also for the Hessian table routes every
 * site of an approximant through the general path, so the same configuration set up
 * with MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT (fast) and with | MFREE_DERIV_HESSIAN
 * (general) must give:
 *  - the same pattern, site statuses, neighbour counts and orders used;
 *  - value and gradient tables equal to round-off: per row, within 1e-13 x the
 *    condition number x the row's largest entry (both paths solve the same moment
 *    system, in a different arithmetic order);
 *  - the same condition numbers (both paths report the exact 1-norm condition number
 *    ||A||_1 ||A^-1||_1, or the pivot ratio of their factorisation when larger) to 1e-8;
 * for SPH, Shepard, MLS orders 0-2, RKPM orders 1-2 and SSPH order 2, in 2D and 3D,
 * with the inlined cubic spline and a kernel evaluated through Kernel::shape (Wendland
 * C2), the gather and symmetric-max conventions, at the particles and at host points,
 * with a periodic axis, for the value table or the gradient table alone, and for sites that fail (too few neighbours) with and without
 * the lower-order fallback, which the fast path hands to the general path.
 * Randles-Libersky and KB Method 1 have no Hessian; t404 checks them against an O(N^2)
 * oracle. The fast path's row kernels exist twice (baseline and AVX2 + FMA, chosen from
 * the CPU, src/core/base/simd.hpp): the whole group runs again with MFREE_SIMD=baseline, so
 * that both copies are checked on a machine with AVX2. The pattern copied from the set's
 * rows (kernel support = search radius) equals the filtered one (test_shared_pattern). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"

static mfree_context_t *ctx;
static int setup(void **s) { (void)s; return mfree_context_create(&ctx) != MFREE_SUCCESS; }
static int teardown(void **s) { (void)s; return mfree_context_destroy(&ctx) != MFREE_SUCCESS; }

/* Instrumented builds (the asan preset compiles the tests without __OPTIMIZE__) check
 * the inlined cubic spline only; the Kernel::shape route is the same code around it. */
#ifdef __OPTIMIZE__
#define NKERNELS 2
#else
#define NKERNELS 1
#endif

#define NMAX 400
#define NNZMAX 60000

typedef struct {
  int dim, n;
  double x[NMAX * 3], h[NMAX], v[NMAX];
} cloud_t;

/* Jittered lattice in [0, 1)^dim, m points a side, supports hf * dx * (1 .. 1.25),
 * volumes dx^dim * (0.8 .. 1.2). */
static void make_cloud(cloud_t *c, int dim, int m, double hf, uint64_t seed) {
  mfree_rng_t r;
  mfree_rng_seed(&r, seed);
  c->dim = dim;
  c->n = 1;
  for (int d = 0; d < dim; ++d) c->n *= m;
  assert_true(c->n <= NMAX);
  const double dx = 1.0 / m;
  for (int i = 0; i < c->n; ++i) {
    int q = i;
    for (int d = 0; d < dim; ++d) {
      c->x[i * dim + d] = (q % m + 0.5 + 0.3 * (2.0 * mfree_rng_uniform(&r) - 1.0)) * dx;
      q /= m;
    }
    c->h[i] = hf * dx * (1.0 + 0.25 * mfree_rng_uniform(&r));
    c->v[i] = pow(dx, dim) * (0.8 + 0.4 * mfree_rng_uniform(&r));
  }
}

typedef struct {
  mfree_method_t method;
  int order;
  const char *name;
} method_t;

static const method_t kMethods[] = {
    {MFREE_METHOD_SPH, 0, "SPH"},       {MFREE_METHOD_SHEPARD, 0, "Shepard"},
    {MFREE_METHOD_MLS, 0, "MLS 0"},     {MFREE_METHOD_MLS, 1, "MLS 1"},
    {MFREE_METHOD_MLS, 2, "MLS 2"},     {MFREE_METHOD_RKPM, 1, "RKPM 1"},
    {MFREE_METHOD_RKPM, 2, "RKPM 2"},   {MFREE_METHOD_SSPH, 2, "SSPH 2"},
};

typedef struct {
  int64_t nnz;
  int32_t nsites, nfailed;
  int64_t rowptr[NMAX + 1];
  int32_t cols[NNZMAX];
  double val[NNZMAX], grad[3][NNZMAX];
  int32_t status[NMAX], counts[NMAX], order[NMAX];
  double cond[NMAX];
} tables_t;

static tables_t ta, tb;

static void build(mfree_particles_t *ps, const method_t *m, mfree_kernel_t kernel, int flags,
                  int fallback, const double *pts, int npts, const double *ph, tables_t *t) {
  int dim = 0;
  mfree_approximant_t *a = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, m->method, &a));
  assert_ok(ctx, mfree_approximant_set_kernel(a, kernel, 0.0));
  if (m->order) assert_ok(ctx, mfree_approximant_set_order(a, m->order));
  assert_ok(ctx, mfree_approximant_set_derivatives(a, flags));
  if (fallback) assert_ok(ctx, mfree_approximant_set_fallback(a, MFREE_FALLBACK_LOWER_ORDER));
  if (pts) {
    dim = 0;
    assert_ok(ctx, mfree_particles_get_dimension(ps, &dim));
    assert_ok(ctx, mfree_approximant_set_points(a, npts, pts, MFREE_LAYOUT_AOS, dim, ph, 1, MFREE_COPY));
  }
  const mfree_status_t st = mfree_approximant_setup(a);
  assert_true(st == MFREE_SUCCESS || st > 0);
  assert_ok(ctx, mfree_approximant_get_num_sites(a, &t->nsites));
  assert_ok(ctx, mfree_approximant_get_nnz(a, &t->nnz));
  assert_true(t->nnz <= (int64_t)(NNZMAX));
  assert_ok(ctx, mfree_particles_get_dimension(ps, &dim));
  memset(t->val, 0, sizeof t->val);
  memset(t->grad, 0, sizeof t->grad);
  if (flags & MFREE_DERIV_VALUE)
    assert_ok(ctx, mfree_approximant_assemble_csr(a, MFREE_DERIV_VALUE, 0, t->rowptr, t->cols, t->val));
  if (flags & MFREE_DERIV_GRADIENT)
    for (int c = 0; c < dim; ++c)
      assert_ok(ctx, mfree_approximant_assemble_csr(a, MFREE_DERIV_GRADIENT, c, t->rowptr, t->cols, t->grad[c]));
  assert_ok(ctx, mfree_approximant_get_site_status(a, t->status, &t->nfailed));
  assert_ok(ctx, mfree_approximant_get_neighbor_counts(a, t->counts));
  assert_ok(ctx, mfree_approximant_get_site_order(a, t->order));
  assert_ok(ctx, mfree_approximant_get_condition(a, t->cond));
  mfree_approximant_destroy(&a);
}

/* Fast (value + gradient) against general (+ Hessian) for one configuration; returns
 * the largest table difference relative to tolerance (<= 1 passes). */
static double compare_flags(mfree_particles_t *ps, int dim, const method_t *m, mfree_kernel_t kernel,
                            int fallback, const double *pts, int npts, const double *ph, const char *what,
                            int vg) {
  build(ps, m, kernel, vg, fallback, pts, npts, ph, &ta);
  build(ps, m, kernel, vg | MFREE_DERIV_HESSIAN, fallback, pts, npts, ph, &tb);
  assert_int_equal(ta.nsites, tb.nsites);
  assert_int_equal(ta.nnz, tb.nnz);
  assert_int_equal(ta.nfailed, tb.nfailed);
  assert_memory_equal(ta.rowptr, tb.rowptr, sizeof(int64_t) * (size_t)(ta.nsites + 1));
  assert_memory_equal(ta.cols, tb.cols, sizeof(int32_t) * (size_t)ta.nnz);
  double worst = 0.0;
  for (int s = 0; s < ta.nsites; ++s) {
    if (ta.status[s] != tb.status[s] || ta.counts[s] != tb.counts[s] || ta.order[s] != tb.order[s])
      fail_msg("%s %s: site %d status %d/%d count %d/%d order %d/%d", what, m->name, s, ta.status[s],
               tb.status[s], ta.counts[s], tb.counts[s], ta.order[s], tb.order[s]);
    if (!(fabs(ta.cond[s] - tb.cond[s]) <= 1e-8 * tb.cond[s]) && !(isinf(ta.cond[s]) && isinf(tb.cond[s])))
      fail_msg("%s %s: site %d condition %.17g (fast) vs %.17g (general)", what, m->name, s,
               ta.cond[s], tb.cond[s]);
    double big = 0.0, diff = 0.0;
    for (int64_t k = ta.rowptr[s]; k < ta.rowptr[s + 1]; ++k) {
      big = fmax(big, fabs(tb.val[k]));
      diff = fmax(diff, fabs(ta.val[k] - tb.val[k]));
      for (int c = 0; c < dim; ++c) {
        big = fmax(big, fabs(tb.grad[c][k]));
        diff = fmax(diff, fabs(ta.grad[c][k] - tb.grad[c][k]));
      }
    }
    const double tol = 1e-13 * fmax(ta.cond[s], 1.0) * big;
    if (ta.status[s] == 0 && big == 0.0) fail_msg("%s %s: site %d has an empty row", what, m->name, s);
    if (diff > 0.0) worst = fmax(worst, diff / tol);
    if (diff > tol)
      fail_msg("%s %s: site %d tables differ by %.3g (row max %.3g, cond %.3g)", what, m->name, s, diff,
               big, ta.cond[s]);
  }
  return worst;
}

static double compare(mfree_particles_t *ps, int dim, const method_t *m, mfree_kernel_t kernel,
                      int fallback, const double *pts, int npts, const double *ph, const char *what) {
  return compare_flags(ps, dim, m, kernel, fallback, pts, npts, ph, what,
                       MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT);
}

static mfree_particles_t *particles(const cloud_t *c, mfree_search_t conv, int periodic) {
  mfree_particles_t *ps = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, c->dim, c->n, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, c->x, MFREE_LAYOUT_AOS, c->dim, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_support(ps, c->h, 1, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_volumes(ps, c->v, 1, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_search(ps, conv, 2.0));
  if (periodic) {
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    const int32_t per[3] = {1, 0, 0};
    assert_ok(ctx, mfree_particles_set_periodic(ps, lo, hi, per));
  }
  assert_ok(ctx, mfree_particles_setup(ps));
  return ps;
}

static void run_dim(int dim, int m) {
  cloud_t c;
  make_cloud(&c, dim, m, dim == 2 ? 1.6 : 1.3, 7 + (uint64_t)dim);
  const mfree_kernel_t kernels[2] = {MFREE_KERNEL_CUBIC_SPLINE, MFREE_KERNEL_WENDLAND_C2};
  /* host points: a coarser jittered lattice with supports like the particles' */
  cloud_t p;
  make_cloud(&p, dim, m - 3, dim == 2 ? 2.0 : 1.6, 99);
  double worst = 0.0;
  for (int conv = 0; conv < 2; ++conv)
    for (int per = 0; per < 2; ++per) {
      if (per && conv) continue;
      mfree_particles_t *ps = particles(&c, conv ? MFREE_SEARCH_SYMMETRIC_MAX : MFREE_SEARCH_GATHER, per);
      for (size_t k = 0; k < sizeof kMethods / sizeof kMethods[0]; ++k)
        for (int kk = 0; kk < NKERNELS; ++kk) {
          char what[96];
          snprintf(what, sizeof what, "%dD %s%s kernel %d", dim, conv ? "sym-max" : "gather",
                   per ? " periodic" : "", (int)kernels[kk]);
          worst = fmax(worst, compare(ps, dim, &kMethods[k], kernels[kk], 0, NULL, 0, NULL, what));
          if (kMethods[k].method != MFREE_METHOD_SPH && !per) {
            strncat(what, " points", sizeof what - strlen(what) - 1);
            worst = fmax(worst, compare(ps, dim, &kMethods[k], kernels[kk], 0, p.x, p.n, p.h, what));
          }
        }
      mfree_particles_destroy(&ps);
    }
  printf("%dD: largest table difference / tolerance %.3g\n", dim, worst);
}

static void test_fast_vs_general_2d(void **s) {
  (void)s;
  run_dim(2, 14);
}
static void test_fast_vs_general_3d(void **s) {
  (void)s;
  run_dim(3, 7);
}

/* Value table only and gradient table only (the fast path skips the derivative moments
 * for values alone). */
static void test_one_table(void **s) {
  (void)s;
  cloud_t c;
  make_cloud(&c, 2, 12, 1.6, 5);
  mfree_particles_t *ps = particles(&c, MFREE_SEARCH_GATHER, 0);
  for (size_t k = 0; k < sizeof kMethods / sizeof kMethods[0]; ++k) {
    compare_flags(ps, 2, &kMethods[k], MFREE_KERNEL_CUBIC_SPLINE, 0, NULL, 0, NULL, "value only",
                  MFREE_DERIV_VALUE);
    compare_flags(ps, 2, &kMethods[k], MFREE_KERNEL_CUBIC_SPLINE, 0, NULL, 0, NULL, "gradient only",
                  MFREE_DERIV_GRADIENT);
  }
  mfree_particles_destroy(&ps);
}

/* Sites with too few neighbours: the fast path gives them to the general path, with
 * the same statuses, and with MFREE_FALLBACK_LOWER_ORDER the same lower-order rows. */
static void test_failing_sites(void **s) {
  (void)s;
  cloud_t c;
  make_cloud(&c, 2, 12, 1.6, 3);
  for (int i = 0; i < c.n; i += 7) c.h[i] *= 0.3; /* about one neighbour within 2h */
  mfree_particles_t *ps = particles(&c, MFREE_SEARCH_GATHER, 0);
  const method_t mls2 = {MFREE_METHOD_MLS, 2, "MLS 2"}, mls1 = {MFREE_METHOD_MLS, 1, "MLS 1"};
  for (int fb = 0; fb < 2; ++fb) {
    compare(ps, 2, &mls2, MFREE_KERNEL_CUBIC_SPLINE, fb, NULL, 0, NULL, fb ? "fallback" : "no fallback");
    assert_true(ta.nfailed > 0 || fb);
    int lowered = 0;
    for (int i = 0; i < ta.nsites; ++i) lowered += ta.status[i] == 0 && ta.order[i] < 2;
    if (fb) assert_true(lowered > 0);
    compare(ps, 2, &mls1, MFREE_KERNEL_CUBIC_SPLINE, fb, NULL, 0, NULL, fb ? "fallback" : "no fallback");
  }
  mfree_particles_destroy(&ps);
}

/* The pattern: where the kernel's support equals the set's search radius (kappa = 2 for
 * the cubic spline, gather, no periodic axis) setup copies the set's rows; with a larger
 * kappa it filters them by distance. Both must give the same pattern, and so bitwise the
 * same tables and condition numbers, in 2D and 3D with variable supports. */
static void test_shared_pattern(void **state) {
  (void)state;
  const method_t *mls1 = &kMethods[3], *sph = &kMethods[0];
  for (int dim = 2; dim <= 3; ++dim) {
    cloud_t c;
    make_cloud(&c, dim, dim == 2 ? 14 : 6, 1.4, 11);
    mfree_particles_t *ps = particles(&c, MFREE_SEARCH_GATHER, 0);
    for (int k = 0; k < 2; ++k) {
      const method_t *m = k ? sph : mls1;
      build(ps, m, MFREE_KERNEL_CUBIC_SPLINE, MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT, 0, NULL, 0, NULL, &ta);
      assert_ok(ctx, mfree_particles_set_search(ps, MFREE_SEARCH_GATHER, 2.6));
      assert_ok(ctx, mfree_particles_setup(ps));
      build(ps, m, MFREE_KERNEL_CUBIC_SPLINE, MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT, 0, NULL, 0, NULL, &tb);
      assert_ok(ctx, mfree_particles_set_search(ps, MFREE_SEARCH_GATHER, 2.0));
      assert_ok(ctx, mfree_particles_setup(ps));
      assert_int_equal(ta.nnz, tb.nnz);
      assert_true(ta.nnz > 10 * c.n); /* real rows, not a degenerate cloud */
      assert_memory_equal(ta.rowptr, tb.rowptr, sizeof(int64_t) * (size_t)(ta.nsites + 1));
      assert_memory_equal(ta.cols, tb.cols, sizeof(int32_t) * (size_t)ta.nnz);
      assert_memory_equal(ta.val, tb.val, sizeof(double) * (size_t)ta.nnz);
      for (int d = 0; d < dim; ++d) assert_memory_equal(ta.grad[d], tb.grad[d], sizeof(double) * (size_t)ta.nnz);
      assert_memory_equal(ta.cond, tb.cond, sizeof(double) * (size_t)ta.nsites);
      assert_memory_equal(ta.status, tb.status, sizeof(int32_t) * (size_t)ta.nsites);
    }
    mfree_particles_destroy(&ps);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_shared_pattern),
      cmocka_unit_test(test_fast_vs_general_2d),
      cmocka_unit_test(test_fast_vs_general_3d),
      cmocka_unit_test(test_one_table),
      cmocka_unit_test(test_failing_sites),
  };
  const int failed = cmocka_run_group_tests(tests, setup, teardown);
  setenv("MFREE_SIMD", "baseline", 1); /* the baseline copy of the fast path */
  return failed + cmocka_run_group_tests(tests, setup, teardown);
}
