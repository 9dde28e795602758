/* Paper 001 (Zhang & Batra, Comput Mech 43 (2009) 321-340), Sect. 6.2: SSPH with six
 * kernels on f = exp(-x^2), through the public API.
 *  - Tables 3 (h = 1.2 Delta), 4 (h = 1.4 Delta) and 5 (cubic, quartic, revised super
 *    Gauss a = 1.0 ... 1.6): every entry to the printed digits and every rank in
 *    parentheses (all reproduced: docs/papers.md, paper 001, derived results 4);
 *  - the rankings equal those of the decay coefficients c1 (L2) and c2 (H1) of eqs
 *    6.13/6.14;
 *  - Table 6: H1 convergence rates per kernel, RSG a = 1.6;
 *  - the recommendation of RSG a = 1.6: smallest errors of all.
 * Setup (docs/papers.md, paper 001, choices 1, 2): 20 particles at the cell centres of [0, 1], Delta = 0.05, volumes
 * Delta, quadratic basis, norms sqrt(Delta sum e_i^2) of the errors in f and f_x. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "testutil.h"

static mfree_context_t *ctx;
static int setup(void **s) { (void)s; return mfree_context_create(&ctx) != MFREE_SUCCESS; }
static int teardown(void **s) { (void)s; return mfree_context_destroy(&ctx) != MFREE_SUCCESS; }

/* The nine kernel variants of Tables 3-5, in the paper's column order. */
enum { LIN, QUAD, CUB, QUART, RGAUSS, RSG10, RSG12, RSG14, RSG16, NK };
static const mfree_kernel_t kKernel[NK] = {
    MFREE_KERNEL_LINEAR,  MFREE_KERNEL_QUADRATIC,      MFREE_KERNEL_CUBIC_SPLINE,
    MFREE_KERNEL_QUARTIC, MFREE_KERNEL_REVISED_GAUSS, MFREE_KERNEL_REVISED_SUPER_GAUSS,
    MFREE_KERNEL_REVISED_SUPER_GAUSS, MFREE_KERNEL_REVISED_SUPER_GAUSS,
    MFREE_KERNEL_REVISED_SUPER_GAUSS};
static const double kParam[NK] = {0, 0, 0, 0, 0, 1.0, 1.2, 1.4, 1.6};
static const char *const kName[NK] = {"Linear", "Quadratic", "Cubic", "Quartic", "Revised Gauss",
                                      "Revised super Gauss a=1.0", "a=1.2", "a=1.4", "a=1.6"};

/* ||e||_0 and ||e||_1 of exp(-x^2) for kernel k, N particles, h = hr Delta. */
static void norms(int k, int n, double hr, double e[2]) {
  enum { NMAX = 500 };
  double x[NMAX], u[NMAX], f[NMAX], fx[NMAX];
  const double delta = 1.0 / n, h = hr * delta;
  for (int i = 0; i < n; ++i) {
    x[i] = (i + 0.5) * delta;
    u[i] = exp(-x[i] * x[i]);
  }
  mfree_particles_t *ps = NULL;
  mfree_approximant_t *a = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, 1, n, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 1, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_volumes(ps, &delta, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_search(ps, MFREE_SEARCH_GATHER, 2.0));
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_SSPH, &a));
  assert_ok(ctx, mfree_approximant_set_kernel(a, kKernel[k], kParam[k]));
  assert_ok(ctx, mfree_approximant_set_order(a, 2));
  assert_ok(ctx, mfree_approximant_set_derivatives(a, MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT));
  assert_ok(ctx, mfree_approximant_setup(a));
  assert_ok(ctx, mfree_approximant_apply(a, MFREE_OP_VALUE, 1, u, MFREE_LAYOUT_AOS, 1, f, MFREE_LAYOUT_AOS, 1));
  assert_ok(ctx, mfree_approximant_apply(a, MFREE_OP_GRADIENT, 1, u, MFREE_LAYOUT_AOS, 1, fx, MFREE_LAYOUT_AOS, 1));
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
  double s0 = 0.0, s1 = 0.0;
  for (int i = 0; i < n; ++i) {
    const double d0 = f[i] - u[i], d1 = fx[i] - (-2.0 * x[i] * u[i]);
    s0 += d0 * d0;
    s1 += d1 * d1;
  }
  e[0] = sqrt(delta * s0);
  e[1] = sqrt(delta * s1);
}

/* 1-based rank of v[i] among v[0..n-1], 1 = smallest. */
static int rank_of(const double *v, int n, int i) {
  int r = 1;
  for (int j = 0; j < n; ++j)
    if (v[j] < v[i]) ++r;
  return r;
}

/* A printed table: columns, values (||e||_0 / 1e-6, ||e||_1 / 1e-3), ranks. */
typedef struct {
  const char *name;
  double hr;
  int col[6];
  double value[2][6];
  int rank[2][6];
} table_t;

static const table_t kTables[4] = {
    {"001 Table 3 (h = 1.2 Delta)", 1.2, {LIN, QUAD, CUB, QUART, RGAUSS, RSG10},
     {{6.84, 3.01, 1.60, 2.43, 4.30, 2.63}, {3.12, 2.12, 1.56, 1.70, 2.19, 1.80}},
     {{6, 4, 1, 2, 5, 3}, {6, 4, 1, 2, 5, 3}}},
    {"001 Table 4 (h = 1.4 Delta)", 1.4, {LIN, QUAD, CUB, QUART, RGAUSS, RSG10},
     {{7.82, 4.86, 4.44, 5.43, 6.36, 5.06}, {3.50, 2.80, 2.20, 2.47, 2.78, 2.40}},
     {{6, 2, 1, 4, 5, 3}, {6, 5, 1, 3, 4, 2}}},
    {"001 Table 5 (h = 1.2 Delta)", 1.2, {CUB, QUART, RSG10, RSG12, RSG14, RSG16},
     {{1.60, 2.43, 2.63, 1.77, 1.14, 0.71}, {1.56, 1.70, 1.80, 1.64, 1.52, 1.44}},
     {{3, 5, 6, 4, 2, 1}, {3, 5, 6, 4, 2, 1}}},
    {"001 Table 5 (h = 1.4 Delta)", 1.4, {CUB, QUART, RSG10, RSG12, RSG14, RSG16},
     {{4.44, 5.43, 5.06, 4.14, 3.30, 2.55}, {2.20, 2.47, 2.40, 2.18, 1.99, 1.83}},
     {{4, 6, 5, 3, 2, 1}, {4, 6, 5, 3, 2, 1}}},
};

/* 001 Sect. 6.2, reproduced, four significant digits, same layout (h = 1.2, 1.4; nine kernels) */
static const double kRepro[2][2][NK] = {
    {{6.842e-6, 3.008e-6, 1.603e-6, 2.431e-6, 4.301e-6, 2.627e-6, 1.769e-6, 1.141e-6, 7.115e-7},
     {3.125e-3, 2.119e-3, 1.564e-3, 1.703e-3, 2.192e-3, 1.803e-3, 1.640e-3, 1.522e-3, 1.440e-3}},
    {{7.817e-6, 4.864e-6, 4.442e-6, 5.427e-6, 6.363e-6, 5.063e-6, 4.144e-6, 3.298e-6, 2.551e-6},
     {3.501e-3, 2.802e-3, 2.197e-3, 2.473e-3, 2.776e-3, 2.401e-3, 2.179e-3, 1.987e-3, 1.827e-3}}};

static void test_tables_3_4_5(void **state) {
  (void)state;
  char src[200];
  for (int t = 0; t < 4; ++t) {
    const table_t *T = &kTables[t];
    double v[2][6];
    for (int c = 0; c < 6; ++c) {
      double e[2];
      norms(T->col[c], 20, T->hr, e);
      v[0][c] = e[0] / 1e-6;
      v[1][c] = e[1] / 1e-3;
    }
    for (int q = 0; q < 2; ++q)
      for (int c = 0; c < 6; ++c) {
        const char *norm = q ? "||e||_1 (E-3)" : "||e||_0 (E-6)";
        snprintf(src, sizeof src, "%s, row %s, column %s, printed %.2f", T->name, norm,
                 kName[T->col[c]], T->value[q][c]);
        if (t == 0 && q == 1 && T->col[c] == LIN) {
          /* printed 3.12 although the value is 3.1253 (reproduced 3.125e-3):
           * the paper truncated this one entry, docs/papers.md, paper 001, errata 7 */
          if (!(floor(v[q][c] * 100.0) == 312.0)) fail_msg("%s (truncated): got %.5f", src, v[q][c]);
          expect_near(v[q][c], 3.125, 0.0005, "001 Sect. 6.2, reproduced, Table 3 linear ||e||_1 3.125e-3");
        } else {
          expect_near(v[q][c], T->value[q][c], 0.005 + 1e-9, src);
        }
        snprintf(src, sizeof src, "%s, row %s, column %s, rank (%d)", T->name, norm,
                 kName[T->col[c]], T->rank[q][c]);
        const int r = rank_of(v[q], 6, c);
        if (r != T->rank[q][c]) fail_msg("%s: got rank %d", src, r);
      }
  }
  /* four digits: the reproduced table, all nine kernels at both h */
  for (int h = 0; h < 2; ++h)
    for (int k = 0; k < NK; ++k) {
      double e[2];
      norms(k, 20, h ? 1.4 : 1.2, e);
      for (int q = 0; q < 2; ++q) {
        const double ref = kRepro[h][q][k];
        const double unit = pow(10.0, floor(log10(ref)) - 3);
        snprintf(src, sizeof src, "001 Sect. 6.2, reproduced, h = %.1f Delta, %s, ||e||_%d = %.4g",
                 h ? 1.4 : 1.2, kName[k], q, ref);
        expect_near(e[q], ref, 0.5 * unit * (1 + 1e-9), src);
      }
    }
}

/* 001 Sect. 6.2: "The error norms follow the ranking predicted by values of coefficients
 * c1 and c2" (eqs 6.13, 6.14), for the six kernels of Tables 3 and 4.
 * c1, c2 are computed from mfree's kernels at 0, Delta, 2 Delta. */
static void test_rankings_follow_c1_c2(void **state) {
  (void)state;
  char src[200];
  for (int t = 0; t < 4; ++t) {
    const table_t *T = &kTables[t];
    double c[2][6], v[2][6];
    for (int col = 0; col < 6; ++col) {
      const int k = T->col[col];
      const double delta = 0.05, h = T->hr * delta, r[3] = {0.0, delta, 2.0 * delta};
      double w[3];
      assert_ok(ctx, mfree_kernel_eval(ctx, kKernel[k], 1, kParam[k], h, 3, r, w, NULL, NULL));
      c[0][col] = (w[2] / w[0]) / (1.0 + 16.0 * w[2] / w[1] + 18.0 * w[2] / w[0]);
      c[1][col] = (w[2] / w[1]) / (w[2] / w[1] + 0.25);
      double e[2];
      norms(k, 20, T->hr, e);
      v[0][col] = e[0];
      v[1][col] = e[1];
    }
    for (int q = 0; q < 2; ++q)
      for (int col = 0; col < 6; ++col) {
        snprintf(src, sizeof src, "001 Sect. 6.2 / Fig. 6: %s rank of ||e||_%d equals rank of c%d, %s",
                 T->name, q, q + 1, kName[T->col[col]]);
        const int re = rank_of(v[q], 6, col), rc = rank_of(c[q], 6, col);
        if (re != rc) fail_msg("%s: error rank %d, c rank %d", src, re, rc);
      }
  }
}

/* 001 Table 6: H1 rates (slope of ln ||e||_1 against ln Delta), N = 10 ... 500 (the
 * paper's N are not stated: docs/papers.md, paper 001, choices 4). */
static void test_table6_rates(void **state) {
  (void)state;
  static const int N[7] = {10, 20, 30, 50, 100, 250, 500};
  static const int cols[6] = {LIN, QUAD, CUB, QUART, RGAUSS, RSG16};
  static const double paper[2][6] = {{1.9902, 2.0006, 2.0140, 2.0096, 1.9993, 2.0189},
                                     {1.9882, 1.9926, 1.9993, 1.9956, 1.9927, 2.0064}};
  static const double repro[2][6] = {{1.9907, 2.0006, 2.0134, 2.0091, 1.9993, 2.0180},
                                    {1.9888, 1.9930, 1.9993, 1.9958, 1.9930, 2.0061}};
  char src[200];
  double rate[2][6];
  for (int h = 0; h < 2; ++h)
    for (int c = 0; c < 6; ++c) {
      double lx[7], ly[7], mx = 0, my = 0, sxy = 0, sxx = 0;
      for (int n = 0; n < 7; ++n) {
        double e[2];
        norms(cols[c], N[n], h ? 1.4 : 1.2, e);
        lx[n] = log(1.0 / N[n]);
        ly[n] = log(e[1]);
        mx += lx[n] / 7;
        my += ly[n] / 7;
      }
      for (int n = 0; n < 7; ++n) {
        sxy += (lx[n] - mx) * (ly[n] - my);
        sxx += (lx[n] - mx) * (lx[n] - mx);
      }
      rate[h][c] = sxy / sxx;
      snprintf(src, sizeof src, "001 Table 6, h = %.1f Delta, %s (%.4f)", h ? 1.4 : 1.2,
               kName[cols[c]], paper[h][c]);
      expect_near(rate[h][c], paper[h][c], 0.01, src);
      snprintf(src, sizeof src, "001 Sect. 6.2, reproduced Table 6 rates, h = %.1f Delta, %s (%.4f)",
               h ? 1.4 : 1.2, kName[cols[c]], repro[h][c]);
      expect_near(rate[h][c], repro[h][c], 0.002, src);
      snprintf(src, sizeof src, "001 Sect. 6.2: \"convergence rates are not affected by the choice of the kernel\" (2.00 +- 0.02), %s",
               kName[cols[c]]);
      expect_near(rate[h][c], 2.0, 0.02, src);
    }
  for (int c = 0; c < 6; ++c) {
    snprintf(src, sizeof src, "001 Sect. 6.2: \"A larger smoothing length will give smaller convergence rate\", %s",
             kName[cols[c]]);
    if (!(rate[1][c] <= rate[0][c])) fail_msg("%s: %.5f (1.4) > %.5f (1.2)", src, rate[1][c], rate[0][c]);
  }
}

/* 001 Sect. 6.2 / Sect. 7 conclusion 7: the revised super Gauss with a = 1.6 "has the
 * least error and is recommended": smallest ||e||_0 and ||e||_1 of all nine variants, at
 * both smoothing lengths; and the errors decrease with a (Table 5). */
static void test_rsg16_recommended(void **state) {
  (void)state;
  char src[200];
  for (int h = 0; h < 2; ++h) {
    double v[2][NK];
    for (int k = 0; k < NK; ++k) {
      double e[2];
      norms(k, 20, h ? 1.4 : 1.2, e);
      v[0][k] = e[0];
      v[1][k] = e[1];
    }
    for (int q = 0; q < 2; ++q) {
      for (int k = 0; k < NK; ++k) {
        if (k == RSG16) continue;
        snprintf(src, sizeof src, "001 Table 5 / conclusion 7: RSG a=1.6 below %s, ||e||_%d, h = %.1f Delta",
                 kName[k], q, h ? 1.4 : 1.2);
        if (!(v[q][RSG16] < v[q][k])) fail_msg("%s: %.4g >= %.4g", src, v[q][RSG16], v[q][k]);
      }
      for (int k = RSG10; k < RSG16; ++k) {
        snprintf(src, sizeof src, "001 Table 5: errors decrease as a grows (%s -> next), ||e||_%d, h = %.1f Delta",
                 kName[k], q, h ? 1.4 : 1.2);
        if (!(v[q][k + 1] < v[q][k])) fail_msg("%s: %.4g >= %.4g", src, v[q][k + 1], v[q][k]);
      }
    }
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_tables_3_4_5),
      cmocka_unit_test(test_rankings_follow_c1_c2),
      cmocka_unit_test(test_table6_rates),
      cmocka_unit_test(test_rsg16_recommended),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
