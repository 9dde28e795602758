/* Paper 001 (Zhang & Batra, "Symmetric smoothed particle hydrodynamics (SSPH) method and
 * its application to elastic problems", Comput Mech 43 (2009) 321-340), Sect. 6.1 and
 * Sect. 6.2 closed forms, through the public API:
 *  - Table 1 (sine test, 10 particles, revised Gauss, h = 1.5 Delta, quadratic basis);
 *  - Table 2 / Fig. 3 (rates over N = 10 ... 500) and the reproduced per-N values
 *    ("reproduced": docs/papers.md, paper 001, derived results 4);
 *  - MSPH and RKPM derivative norms (orderings; the support edge: docs/papers.md,
 *    paper 001, choices 3);
 *  - the interior closed forms 6.13-6.16 and the f_xx form that they imply
 *    (docs/papers.md, paper 001, derived results 1).
 * Setup (docs/papers.md, paper 001, choices 1, 2): particles at the cell centres
 * x_i = (i - 1/2)/N, volumes Delta = 1/N, gather support 2h, norms
 * sqrt(Delta sum_i e_i^2). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"

static mfree_context_t *ctx;
static int setup(void **s) { (void)s; return mfree_context_create(&ctx) != MFREE_SUCCESS; }
static int teardown(void **s) { (void)s; return mfree_context_destroy(&ctx) != MFREE_SUCCESS; }

/* ---- checks that name their source (and expect_near of testutil.h) ------------------ */

#define expect_less(a, b, src)                                                             \
  do {                                                                                     \
    const double a_ = (a), b_ = (b);                                                       \
    if (!(a_ < b_)) fail_msg("%s: expected %.6g < %.6g", (src), a_, b_);                   \
  } while (0)

/* got equals the value printed with sig significant digits (half a unit of the last). */
static void expect_printed(double got, double printed, int sig, const char *src) {
  const double unit = pow(10.0, floor(log10(fabs(printed))) - (sig - 1));
  if (!(fabs(got - printed) <= 0.5 * unit * (1.0 + 1e-9)))
    fail_msg("%s: got %.8g, the source prints %.*g", src, got, sig, printed);
}

/* ---- the 1D experiment ---------------------------------------------------------------- */

enum { NMAX = 500 };
static const int kN[7] = {10, 20, 30, 50, 100, 250, 500};

typedef struct {
  double f[NMAX], fx[NMAX], fxx[NMAX];
} est_t;

/* Estimates of f, f_x (and f_xx when hess) at the particles from nodal values u; setup
 * must return expect_setup, and *nfailed (if not NULL) receives the failed sites. */
static void estimate_status(mfree_method_t method, mfree_kernel_t kernel, double kparam, int n,
                            double hfac, int hess, const double *u, est_t *out,
                            mfree_status_t expect_setup, int32_t *failed) {
  mfree_particles_t *ps = NULL;
  mfree_approximant_t *a = NULL;
  double x[NMAX];
  const double delta = 1.0 / n, h = hfac * delta;
  for (int i = 0; i < n; ++i) x[i] = (i + 0.5) * delta;
  assert_ok(ctx, mfree_particles_create(ctx, 1, n, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 1, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_volumes(ps, &delta, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_search(ps, MFREE_SEARCH_GATHER, 2.0));
  assert_ok(ctx, mfree_approximant_create(ctx, ps, method, &a));
  assert_ok(ctx, mfree_approximant_set_kernel(a, kernel, kparam));
  assert_ok(ctx, mfree_approximant_set_order(a, 2));
  assert_ok(ctx, mfree_approximant_set_derivatives(
                     a, MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT | (hess ? MFREE_DERIV_HESSIAN : 0)));
  assert_status(ctx, mfree_approximant_setup(a), expect_setup);
  if (failed) {
    int32_t st[NMAX];
    assert_ok(ctx, mfree_approximant_get_site_status(a, st, NULL));
    for (int i = 0; i < n; ++i) failed[i] = st[i];
  }
  assert_ok(ctx, mfree_approximant_apply(a, MFREE_OP_VALUE, 1, u, MFREE_LAYOUT_AOS, 1, out->f,
                                         MFREE_LAYOUT_AOS, 1));
  assert_ok(ctx, mfree_approximant_apply(a, MFREE_OP_GRADIENT, 1, u, MFREE_LAYOUT_AOS, 1, out->fx,
                                         MFREE_LAYOUT_AOS, 1));
  if (hess)
    assert_ok(ctx, mfree_approximant_apply(a, MFREE_OP_HESSIAN, 1, u, MFREE_LAYOUT_AOS, 1,
                                           out->fxx, MFREE_LAYOUT_AOS, 1));
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
}
static void estimate(mfree_method_t method, mfree_kernel_t kernel, double kparam, int n,
                     double hfac, int hess, const double *u, est_t *out) {
  estimate_status(method, kernel, kparam, n, hfac, hess, u, out, MFREE_SUCCESS, NULL);
}

/* 001 eq 6.1 and its derivatives. */
static void sine(double x, double *f, double *fx, double *fxx) {
  const double s8 = sin(8.0);
  *f = sin(8.0 * (1.0 - x)) / s8;
  *fx = -8.0 * cos(8.0 * (1.0 - x)) / s8;
  *fxx = -64.0 * sin(8.0 * (1.0 - x)) / s8;
}

/* ||e||_0, ||e||_1, ||e||_2 of the sine test (001 eq 6.3 by the midpoint rule:
 * docs/papers.md, paper 001, choices 2). */
static void sine_norms(mfree_method_t method, int n, double hfac, double e[3]) {
  double u[NMAX], ex[3][NMAX];
  est_t est;
  for (int i = 0; i < n; ++i) {
    sine((i + 0.5) / n, &ex[0][i], &ex[1][i], &ex[2][i]);
    u[i] = ex[0][i];
  }
  estimate(method, MFREE_KERNEL_REVISED_GAUSS, 0.0, n, hfac, 1, u, &est);
  const double *got[3] = {est.f, est.fx, est.fxx};
  for (int k = 0; k < 3; ++k) {
    double s = 0.0;
    for (int i = 0; i < n; ++i) s += (got[k][i] - ex[k][i]) * (got[k][i] - ex[k][i]);
    e[k] = sqrt(s / n);
  }
}

/* Least-squares slope of ln e against ln Delta (001 Sect. 6.1: "convergence rate means
 * the slope of the least-squares fitted line"). */
static double rate(const double e[7]) {
  double mx = 0, my = 0, sxy = 0, sxx = 0;
  for (int k = 0; k < 7; ++k) {
    mx += log(1.0 / kN[k]) / 7;
    my += log(e[k]) / 7;
  }
  for (int k = 0; k < 7; ++k) {
    const double dx = log(1.0 / kN[k]) - mx;
    sxy += dx * (log(e[k]) - my);
    sxx += dx * dx;
  }
  return sxy / sxx;
}

/* all N for MSPH, SSPH, RKPM: e[method][N][norm] */
enum { MSPH, SSPH, RKPM };
static const mfree_method_t kMethods[3] = {MFREE_METHOD_MSPH, MFREE_METHOD_SSPH, MFREE_METHOD_RKPM};
static void all_norms(double hfac, double e[3][7][3]) {
  for (int m = 0; m < 3; ++m)
    for (int k = 0; k < 7; ++k) sine_norms(kMethods[m], kN[k], hfac, e[m][k]);
}
static void rates(double e[3][7][3], double r[3][3]) {
  for (int m = 0; m < 3; ++m)
    for (int c = 0; c < 3; ++c) {
      double v[7];
      for (int k = 0; k < 7; ++k) v[k] = e[m][k][c];
      r[m][c] = rate(v);
    }
}

/* h = 1.5 Delta puts the neighbours i +- 3 at exactly 2h. A relative shift of 1e-12 puts
 * all of them inside (the paper's d <= 2) or outside; SSPH values move by ~1e-12. */
#define H_AS_IS 1.5
#define H_EDGE_IN (1.5 * (1.0 + 1e-12))
#define H_EDGE_OUT (1.5 * (1.0 - 1e-12))

/* ---- Table 1, SSPH -------------------------------------------------------------------- */

static void test_table1_ssph(void **state) {
  (void)state;
  double e[3];
  sine_norms(MFREE_METHOD_SSPH, 10, H_AS_IS, e);
  expect_printed(e[0], 1.88e-2, 3, "001 Table 1, SSPH column, ||e||_0 (1.88E-2)");
  expect_printed(e[1], 1.21, 3, "001 Table 1, SSPH column, ||e||_1 (1.21)");
  expect_printed(e[2], 17.2, 3, "001 Table 1, SSPH column, ||e||_2 (17.2)");
  expect_printed(e[0], 1.8790e-2, 5, "001 Sect. 6.1, reproduced, SSPH N = 10, ||e||_0 1.8790e-2");
  expect_printed(e[1], 1.2148, 5, "001 Sect. 6.1, reproduced, SSPH N = 10, ||e||_1 1.2148");
  expect_printed(e[2], 17.179, 5, "001 Sect. 6.1, reproduced, SSPH N = 10, ||e||_2 1.7179e+1");
  /* SSPH never differentiates W, so the support-edge convention does not matter */
  double in[3], out[3];
  sine_norms(MFREE_METHOD_SSPH, 10, H_EDGE_IN, in);
  sine_norms(MFREE_METHOD_SSPH, 10, H_EDGE_OUT, out);
  for (int k = 0; k < 3; ++k) {
    expect_near(in[k], e[k], 1e-9 * e[k], "001 Sect. 3: SSPH uses W only (W(2h) = 0), edge in");
    expect_near(out[k], e[k], 1e-9 * e[k], "001 Sect. 3: SSPH uses W only (W(2h) = 0), edge out");
  }
}

/* 001 Sect. 4 / Table 1: RKPM and SSPH function estimates are identical,
 * at the particles for every N and at arbitrary points. */
static void test_rkpm_value_equals_ssph(void **state) {
  (void)state;
  for (int k = 0; k < 7; ++k) {
    const int n = kN[k];
    double u[NMAX], d1, d2;
    for (int i = 0; i < n; ++i) sine((i + 0.5) / n, &u[i], &d1, &d2);
    static est_t s, r;
    estimate(MFREE_METHOD_SSPH, MFREE_KERNEL_REVISED_GAUSS, 0.0, n, H_AS_IS, 0, u, &s);
    estimate(MFREE_METHOD_RKPM, MFREE_KERNEL_REVISED_GAUSS, 0.0, n, H_AS_IS, 0, u, &r);
    for (int i = 0; i < n; ++i)
      expect_near(r.f[i], s.f[i], 1e-12, "001 Sect. 4: RKPM f_i = SSPH f_i (P^T(0) = {1,0,0})");
  }
  double es[3], er[3];
  sine_norms(MFREE_METHOD_SSPH, 10, H_AS_IS, es);
  sine_norms(MFREE_METHOD_RKPM, 10, H_AS_IS, er);
  expect_near(er[0], es[0], 1e-12 * es[0], "001 Table 1, RKPM ||e||_0 = SSPH ||e||_0 (1.88E-2)");

  /* at host points (quadrature-like sites), 20 particles, random points in [0, 1] */
  enum { NP = 20, NQ = 37 };
  double x[NP], u[NP], q[NQ], vs[NQ], vr[NQ], d1, d2;
  const double delta = 1.0 / NP, h = 1.5 * delta;
  mfree_rng_t rng;
  mfree_rng_seed(&rng, 410);
  for (int i = 0; i < NP; ++i) {
    x[i] = (i + 0.5) * delta;
    sine(x[i], &u[i], &d1, &d2);
  }
  for (int i = 0; i < NQ; ++i) q[i] = mfree_rng_uniform(&rng);
  mfree_particles_t *ps = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, 1, NP, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 1, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_volumes(ps, &delta, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  for (int m = 0; m < 2; ++m) {
    mfree_approximant_t *a = NULL;
    assert_ok(ctx, mfree_approximant_create(ctx, ps, m ? MFREE_METHOD_RKPM : MFREE_METHOD_SSPH, &a));
    assert_ok(ctx, mfree_approximant_set_kernel(a, MFREE_KERNEL_REVISED_GAUSS, 0.0));
    assert_ok(ctx, mfree_approximant_set_order(a, 2));
    assert_ok(ctx, mfree_approximant_set_derivatives(a, MFREE_DERIV_VALUE));
    assert_ok(ctx, mfree_approximant_set_points(a, NQ, q, MFREE_LAYOUT_AOS, 1, &h, 0, MFREE_COPY));
    assert_ok(ctx, mfree_approximant_setup(a));
    assert_ok(ctx, mfree_approximant_apply(a, MFREE_OP_VALUE, 1, u, MFREE_LAYOUT_AOS, 1,
                                           m ? vr : vs, MFREE_LAYOUT_AOS, 1));
    mfree_approximant_destroy(&a);
  }
  mfree_particles_destroy(&ps);
  for (int i = 0; i < NQ; ++i)
    expect_near(vr[i], vs[i], 1e-12, "001 Sect. 4 eqs 4.10-4.15: RKPM f(x) = SSPH f(x) anywhere");
}

/* ---- Table 2 and the per-N reference values, SSPH ------------------------------------ */

static void test_table2_ssph(void **state) {
  (void)state;
  /* 001 Sect. 6.1, reproduced SSPH reference values, N = 10 ... 500 */
  static const double ref[7][3] = {
      {1.8790e-2, 1.2148, 1.7179e+1}, {1.5839e-3, 3.4510e-1, 6.1998},
      {3.7231e-4, 1.5840e-1, 3.3987},  {6.0488e-5, 5.8289e-2, 1.5866},
      {5.1987e-6, 1.4780e-2, 5.6200e-1}, {2.0620e-7, 2.3827e-3, 1.4221e-1},
      {1.8089e-8, 5.9708e-4, 5.0274e-2}};
  double e[7][3], v[3][7];
  char src[160];
  for (int k = 0; k < 7; ++k) {
    sine_norms(MFREE_METHOD_SSPH, kN[k], H_AS_IS, e[k]);
    for (int c = 0; c < 3; ++c) {
      snprintf(src, sizeof src, "001 Sect. 6.1, reproduced SSPH table, N = %d, ||e||_%d", kN[k], c);
      expect_printed(e[k][c], ref[k][c], 5, src);
      v[c][k] = e[k][c];
    }
  }
  const double paper[3] = {3.54, 1.96, 1.49}, repro[3] = {3.541, 1.957, 1.493};
  for (int c = 0; c < 3; ++c) {
    const double r = rate(v[c]);
    snprintf(src, sizeof src, "001 Table 2, SSPH column, rate of ||e||_%d (%.2f)", c, paper[c]);
    expect_near(r, paper[c], 0.03, src);
    snprintf(src, sizeof src, "001 Sect. 6.1, reproduced SSPH slope of ||e||_%d (%.3f)", c, repro[c]);
    expect_printed(r, repro[c], 4, src);
  }
}

/* ---- MSPH and RKPM: Table 1 / Table 2 / Fig. 3 statements ----------------------------- */

/* The paper's orderings (001 Sect. 6.1 text under Table 1 and Fig. 3),
 * checked for a set of norms e[method][N][norm]. */
static void check_orderings(double e[3][7][3], const char *conv) {
  char src[200];
  for (int c = 0; c < 3; ++c) {
    snprintf(src, sizeof src, "001 Sect. 6.1 (Table 1): all SSPH norms below MSPH's, ||e||_%d, %s", c, conv);
    expect_less(e[SSPH][0][c], e[MSPH][0][c], src);
  }
  snprintf(src, sizeof src, "001 Sect. 6.1 (Table 1): RKPM has the smallest H1 norm, %s", conv);
  expect_less(e[RKPM][0][1], e[SSPH][0][1], src);
  expect_less(e[RKPM][0][1], e[MSPH][0][1], src);
  snprintf(src, sizeof src, "001 Sect. 6.1 (Table 1): RKPM has the largest H2 norm, %s", conv);
  expect_less(e[SSPH][0][2], e[RKPM][0][2], src);
  expect_less(e[MSPH][0][2], e[RKPM][0][2], src);
  for (int k = 0; k < 7; ++k) {
    snprintf(src, sizeof src,
             "001 Sect. 6.1 (Fig. 3): for every N the L2 error of SSPH and RKPM is below MSPH's, N = %d, %s",
             kN[k], conv);
    expect_less(e[SSPH][k][0], e[MSPH][k][0], src);
    expect_less(e[RKPM][k][0], e[MSPH][k][0], src);
    snprintf(src, sizeof src,
             "001 Sect. 6.1 (Fig. 3): RKPM gives the smallest H1 and the largest H2, N = %d, %s",
             kN[k], conv);
    expect_less(e[RKPM][k][1], e[SSPH][k][1], src);
    expect_less(e[RKPM][k][1], e[MSPH][k][1], src);
    expect_less(e[SSPH][k][2], e[RKPM][k][2], src);
    expect_less(e[MSPH][k][2], e[RKPM][k][2], src);
  }
}

/* h = 1.5 Delta exactly, as the paper states it. Which of the pairs at exactly 2h count as
 * neighbours is then decided by the rounding of x_j - x_i (8 of the 14 at N = 10, 12 of
 * 34 at N = 20, 132 of 994 at N = 500), so MSPH and RKPM mix the two conventions
 * (docs/papers.md, paper 001, choices 3). mfree gives, N = 10 (paper in brackets):
 *   MSPH ||e||_0 3.54e-2 [2.86e-2, +24%], ||e||_1 1.28 [1.40, -8%], ||e||_2 19.4 [20.1, -4%]
 *   RKPM ||e||_0 1.88e-2 [1.88e-2],       ||e||_1 0.688 [0.59, +17%], ||e||_2 25.1 [32.8, -23%]
 * and rates MSPH 3.21 / 1.97 / 1.41 [3.52 / 1.92 / 1.47], RKPM 3.54 / 2.05 / 1.18
 * [3.54 / 1.80 / 1.54]. These numbers depend on round-off in the pair test, so only the
 * paper's orderings are asserted here; the digits are checked below, per convention. */
static void test_msph_rkpm_orderings_as_stated(void **state) {
  (void)state;
  static double e[3][7][3];
  all_norms(H_AS_IS, e);
  check_orderings(e, "h = 1.5 Delta");
}

/* The two support-edge conventions (docs/papers.md, paper 001, choices 3; derived results 4):
 * mfree reproduces both to the printed digits, which pins its MSPH (eqs 2.9-2.15) and
 * RKPM (eqs 4.12-4.13) derivatives. */
static void test_edge_conventions_repro(void **state) {
  (void)state;
  static double in[3][7][3], out[3][7][3];
  double rin[3][3];
  all_norms(H_EDGE_IN, in);
  all_norms(H_EDGE_OUT, out);
  rates(in, rin);
  /* the reproduced N = 10 values of both conventions */
  expect_printed(in[MSPH][0][0], 3.67e-2, 3, "001 Sect. 6.1, reproduced MSPH edge included, ||e||_0 3.67e-2");
  expect_printed(in[MSPH][0][1], 1.47, 3, "001 Sect. 6.1, reproduced MSPH edge included, ||e||_1 1.47");
  expect_printed(in[MSPH][0][2], 21.3, 3, "001 Sect. 6.1, reproduced MSPH edge included, ||e||_2 21.3");
  expect_printed(rin[MSPH][0], 3.547, 4, "001 Sect. 6.1, reproduced MSPH edge included, rates 3.547");
  expect_printed(rin[MSPH][1], 1.941, 4, "001 Sect. 6.1, reproduced MSPH edge included, rates 1.941");
  expect_printed(rin[MSPH][2], 1.493, 4, "001 Sect. 6.1, reproduced MSPH edge included, rates 1.493");
  expect_printed(out[MSPH][0][0], 1.93e-2, 3, "001 Sect. 6.1, reproduced MSPH edge excluded, ||e||_0 1.93e-2");
  expect_printed(out[MSPH][0][1], 1.24, 3, "001 Sect. 6.1, reproduced MSPH edge excluded, ||e||_1 1.24");
  expect_printed(out[MSPH][0][2], 17.2, 3, "001 Sect. 6.1, reproduced MSPH edge excluded, ||e||_2 17.2");
  expect_printed(in[RKPM][0][0], 1.879e-2, 4, "001 Sect. 6.1, reproduced RKPM edge included, ||e||_0 1.879e-2");
  expect_printed(in[RKPM][0][1], 0.721, 3, "001 Sect. 6.1, reproduced RKPM edge included, ||e||_1 0.721");
  expect_printed(in[RKPM][0][2], 33.4, 3, "001 Sect. 6.1, reproduced RKPM edge included, ||e||_2 33.4");
  expect_printed(rin[RKPM][0], 3.541, 4, "001 Sect. 6.1, reproduced RKPM edge included, rates 3.541");
  expect_printed(rin[RKPM][1], 1.877, 4, "001 Sect. 6.1, reproduced RKPM edge included, rates 1.877");
  expect_printed(rin[RKPM][2], 1.510, 4, "001 Sect. 6.1, reproduced RKPM edge included, rates 1.510");
  expect_printed(out[RKPM][0][0], 1.879e-2, 4, "001 Sect. 6.1, reproduced RKPM edge excluded, ||e||_0 1.879e-2");
  expect_printed(out[RKPM][0][1], 0.730, 3, "001 Sect. 6.1, reproduced RKPM edge excluded, ||e||_1 0.730");
  expect_printed(out[RKPM][0][2], 16.4, 3, "001 Sect. 6.1, reproduced RKPM edge excluded, ||e||_2 16.4");
  /* the L2 ordering holds in both conventions at every N */
  for (int k = 0; k < 7; ++k) {
    expect_less(out[SSPH][k][0], out[MSPH][k][0],
                "001 Sect. 6.1 (Fig. 3): L2 of SSPH below MSPH at every N, edge excluded");
    expect_less(in[SSPH][k][0], in[MSPH][k][0],
                "001 Sect. 6.1 (Fig. 3): L2 of SSPH below MSPH at every N, edge included");
  }
}

/* The paper against the edge-included ("d <= 2") convention, the one
 * closest to it. mfree (paper): MSPH 3.67e-2 (2.86e-2, +28%), 1.47 (1.40, +5%),
 * 21.3 (20.1, +6%); RKPM 0.721 (0.59, +22%), 33.4 (32.8, +2%). The paper's MSPH ||e||_0 is
 * not within 25% of either convention; it lies between them (1.93e-2 and 3.67e-2), which
 * is what is asserted for it. The paper's code evidently differs in an undocumented
 * detail at the support edge (docs/papers.md, paper 001, choices 3). */
static void test_msph_rkpm_vs_paper(void **state) {
  (void)state;
  static double in[3][7][3], out[3][7][3];
  double r[3][3];
  all_norms(H_EDGE_IN, in);
  all_norms(H_EDGE_OUT, out);
  rates(in, r);
  check_orderings(in, "edge included");
  expect_near(in[MSPH][0][1], 1.40, 0.25 * 1.40, "001 Table 1, MSPH ||e||_1 1.40 (within 25%)");
  expect_near(in[MSPH][0][2], 20.1, 0.25 * 20.1, "001 Table 1, MSPH ||e||_2 20.1 (within 25%)");
  expect_near(in[RKPM][0][1], 0.59, 0.25 * 0.59, "001 Table 1, RKPM ||e||_1 0.59 (within 25%)");
  expect_near(in[RKPM][0][2], 32.8, 0.25 * 32.8, "001 Table 1, RKPM ||e||_2 32.8 (within 25%)");
  expect_printed(in[RKPM][0][0], 1.88e-2, 3, "001 Table 1, RKPM ||e||_0 1.88E-2");
  expect_less(out[MSPH][0][0], 2.86e-2, "001 Table 1, MSPH ||e||_0 2.86E-2 above the edge-excluded value");
  expect_less(2.86e-2, in[MSPH][0][0], "001 Table 1, MSPH ||e||_0 2.86E-2 below the edge-included value");
  /* 001 Table 2: MSPH 3.52 / 1.92 / 1.47, RKPM 3.54 / 1.80 / 1.54 (RKPM H1 within
   * +-0.15: mfree 1.877) */
  expect_near(r[MSPH][0], 3.52, 0.03, "001 Table 2, MSPH column, rate of ||e||_0 3.52");
  expect_near(r[MSPH][1], 1.92, 0.03, "001 Table 2, MSPH column, rate of ||e||_1 1.92");
  expect_near(r[MSPH][2], 1.47, 0.03, "001 Table 2, MSPH column, rate of ||e||_2 1.47");
  expect_near(r[RKPM][0], 3.54, 0.03, "001 Table 2, RKPM column, rate of ||e||_0 3.54");
  expect_near(r[RKPM][1], 1.80, 0.15, "001 Table 2, RKPM column, rate of ||e||_1 1.80 (+-0.15)");
  expect_near(r[RKPM][2], 1.54, 0.03, "001 Table 2, RKPM column, rate of ||e||_2 1.54");
}

/* ---- closed forms (001 eqs 6.13-6.16; f_xx: docs/papers.md, paper 001, derived results 1) */

/* The six kernels of 001 Sect. 6.2 (shape only: G cancels in SSPH), written from the
 * paper's equations, not from mfree; the revised super Gauss at a = 1 and 1.6. */
enum { NKER = 7 };
static const mfree_kernel_t kKer[NKER] = {
    MFREE_KERNEL_LINEAR,  MFREE_KERNEL_QUADRATIC,      MFREE_KERNEL_CUBIC_SPLINE,
    MFREE_KERNEL_QUARTIC, MFREE_KERNEL_REVISED_GAUSS, MFREE_KERNEL_REVISED_SUPER_GAUSS,
    MFREE_KERNEL_REVISED_SUPER_GAUSS};
static const double kKerA[NKER] = {0, 0, 0, 0, 0, 1.0, 1.6};
static const char *const kKerName[NKER] = {"linear (6.4)", "quadratic (6.5)", "cubic (6.6)",
                                           "quartic (6.7)", "revised Gauss (6.8)",
                                           "revised super Gauss a=1 (6.10)",
                                           "revised super Gauss a=1.6 (6.17)"};
static double shape(int k, double d) {
  if (d >= 2.0) return 0.0;
  switch (k) {
    case 0: return (2.0 - d) / 4.0;
    case 1: return 1.0 - d + d * d / 4.0;
    case 2: return d < 1.0 ? 1.0 - 1.5 * d * d + 0.75 * d * d * d : pow(2.0 - d, 3) / 4.0;
    case 3: return 1.0 - 1.5 * d * d + d * d * d - 3.0 / 16.0 * pow(d, 4);
    case 4: return exp(-d * d) - exp(-4.0);
    default: return (4.0 - d * d) * exp(-kKerA[k] * d * d);
  }
}

static void test_closed_forms_interior(void **state) {
  (void)state;
  enum { N = 20 };
  const double delta = 1.0 / N;
  double u[N];
  mfree_rng_t rng;
  mfree_rng_seed(&rng, 6130);
  for (int i = 0; i < N; ++i) u[i] = 2.0 * mfree_rng_uniform(&rng) - 1.0; /* any nodal data */
  static const double ratios[5] = {1.1, 1.2, 1.3, 1.4, 1.5};
  char src[200];
  for (int k = 0; k < NKER; ++k)
    for (int r = 0; r < 5; ++r) {
      est_t est;
      estimate(MFREE_METHOD_SSPH, kKer[k], kKerA[k], N, ratios[r], 1, u, &est);
      const double w0 = shape(k, 0.0), w1 = shape(k, 1.0 / ratios[r]), w2 = shape(k, 2.0 / ratios[r]);
      const double c1 = (w2 / w0) / (1.0 + 16.0 * w2 / w1 + 18.0 * w2 / w0);
      const double c2 = (w2 / w1) / (w2 / w1 + 0.25);
      for (int i = 2; i < N - 2; ++i) {
        const double S1 = u[i + 1] + u[i - 1], S2 = u[i + 2] + u[i - 2];
        const double f = u[i] + c1 * (12.0 * S1 - 3.0 * S2 - 18.0 * u[i]);
        const double cd1 = (u[i + 1] - u[i - 1]) / (2 * delta), cd2 = (u[i + 2] - u[i - 2]) / (4 * delta);
        const double fx = cd1 + c2 * (cd2 - cd1);
        const double fxx = ((S1 - 2 * u[i]) + 4 * w2 / w1 * (S2 - 2 * u[i]) + 6 * w2 / w0 * (S2 - S1)) /
                           (delta * delta * (1.0 + 16.0 * w2 / w1 + 18.0 * w2 / w0));
        snprintf(src, sizeof src, "001 eq 6.13 (f_i with c1), %s, h = %.1f Delta, i = %d", kKerName[k], ratios[r], i);
        expect_near(est.f[i], f, 1e-12, src);
        snprintf(src, sizeof src, "001 eq 6.14 (f_x with c2), %s, h = %.1f Delta, i = %d", kKerName[k], ratios[r], i);
        expect_near(est.fx[i], fx, 1e-12 / delta, src);
        snprintf(src, sizeof src, "f_xx closed form (docs/papers.md, paper 001, derived results 1), %s, h = %.1f Delta, i = %d", kKerName[k], ratios[r], i);
        expect_near(est.fxx[i], fxx, 1e-11 / (delta * delta), src);
      }
    }
}

static void test_closed_forms_nearest(void **state) {
  (void)state;
  enum { N = 20 };
  const double delta = 1.0 / N;
  double u[N];
  mfree_rng_t rng;
  mfree_rng_seed(&rng, 6150);
  for (int i = 0; i < N; ++i) u[i] = 2.0 * mfree_rng_uniform(&rng) - 1.0;
  static const double ratios[3] = {0.6, 0.8, 1.0}; /* Delta/2 < h <= Delta */
  char src[200];
  for (int k = 0; k < NKER; ++k)
    for (int r = 0; r < 3; ++r) {
      est_t est;
      int32_t failed[N];
      /* the end particles see one neighbour: K is singular there (001 eq 3.5),
       * reported as too few neighbours, rows zero */
      estimate_status(MFREE_METHOD_SSPH, kKer[k], kKerA[k], N, ratios[r], 1, u, &est,
                      MFREE_FAIL_NEIGHBORS, failed);
      for (int i = 0; i < N; ++i) {
        snprintf(src, sizeof src, "001 Sect. 3 (eq 3.5): K singular iff < 2 other particles, %s, h = %.1f Delta, i = %d",
                 kKerName[k], ratios[r], i);
        if ((failed[i] != 0) != (i == 0 || i == N - 1)) fail_msg("%s: site status %d", src, (int)failed[i]);
      }
      for (int i = 1; i < N - 1; ++i) {
        snprintf(src, sizeof src, "001 eq 6.15 (f_i exact), %s, h = %.1f Delta, i = %d", kKerName[k], ratios[r], i);
        expect_near(est.f[i], u[i], 1e-12, src);
        snprintf(src, sizeof src, "001 eq 6.16 (central difference), %s, h = %.1f Delta, i = %d", kKerName[k], ratios[r], i);
        expect_near(est.fx[i], (u[i + 1] - u[i - 1]) / (2 * delta), 1e-12 / delta, src);
        snprintf(src, sizeof src, "f_xx closed form with w2 = 0 (second difference), %s, h = %.1f Delta, i = %d", kKerName[k], ratios[r], i);
        expect_near(est.fxx[i], (u[i + 1] - 2 * u[i] + u[i - 1]) / (delta * delta), 1e-11 / (delta * delta), src);
      }
    }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_table1_ssph),
      cmocka_unit_test(test_rkpm_value_equals_ssph),
      cmocka_unit_test(test_table2_ssph),
      cmocka_unit_test(test_msph_rkpm_orderings_as_stated),
      cmocka_unit_test(test_edge_conventions_repro),
      cmocka_unit_test(test_msph_rkpm_vs_paper),
      cmocka_unit_test(test_closed_forms_interior),
      cmocka_unit_test(test_closed_forms_nearest),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
