/* MPFEM in 1D against reproduced reference values (docs/papers.md, paper 004, derived
 * results 10):
 * nodes 0..5, linear elements, cosine kernel (pi/(2d)) cos(pi t/d) with d = 2 and d = 1,
 * Haar kernel with d = 2; shape functions, derivatives by 004 eq 21 and eq 22. They are
 * rounded to 6 decimals, so the tolerance is 1.5e-6. The kernel's support radius is
 * R h = h (R = 1), so the width d is 2h. */
#include <math.h>
#include <stdlib.h>

#include "mpfem_util.h"

#define TOL 1.5e-6

typedef struct {
  double x;
  int32_t first, n; /* nodes first .. first + n - 1 */
  double N[4], d21[4], d22[4];
} ref_row_t;

static const ref_row_t kCosD2[] = {
    {0.00, 0, 2, {1, 0}, {-1, 1}, {-1, 1}},
    {0.25, 0, 3, {0.70871, 0.332579, -0.04129}, {-1.227671, 1.455343, -0.227671},
     {-0.944947, 0.889895, 0.055053}},
    {0.50, 0, 3, {0.414214, 0.671573, -0.085786}, {-1.097933, 1.195866, -0.097933},
     {-0.828427, 0.656854, 0.171573}},
    {1.00, 0, 3, {0, 1, 0}, {-0.5, 0, 0.5}, {-0.5, 0, 0.5}},
    {2.50, 1, 4, {-0.073223, 0.573223, 0.573223, -0.073223}, {0.131234, -1.393701, 1.393701, -0.131234},
     {-0.146447, -0.56066, 0.56066, 0.146447}},
    {2.75, 1, 4, {-0.028545, 0.229926, 0.875784, -0.077165}, {0.187359, -1.247463, 0.932849, 0.127255},
     {-0.03806, -0.615221, 0.344623, 0.308658}},
    {4.90, 3, 3, {-0.009582, 0.119163, 0.890418}, {0.167737, -1.335474, 1.167737},
     {-0.010646, -0.978708, 0.989354}},
};

static mfree_context_t *ctx;
static mfree_particles_t *ps;
static mfree_mesh_t *mesh;

static int setup(void **state) {
  (void)state;
  double x[6];
  int32_t conn[10];
  for (int i = 0; i < 6; ++i) x[i] = i;
  mp_line_conn(6, conn);
  assert_ok(NULL, mfree_context_create(&ctx));
  ps = mp_particles(ctx, 1, 6, x, 1.0);
  mesh = mp_mesh(ctx, ps, MFREE_ELEMENT_LINE2, 5, conn);
  return 0;
}

static int teardown(void **state) {
  (void)state;
  mfree_mesh_destroy(&mesh);
  mfree_particles_destroy(&ps);
  mfree_context_destroy(&ctx);
  return 0;
}

/* Evaluate at the given points with kernel support hp; check the rows. */
static void check_rows(mfree_kernel_t kernel, double hp, mfree_mpfem_deriv_t deriv, int npts,
                       const double *pts, const int32_t *first, const int32_t *n,
                       const double (*N)[4], const double (*dN)[4]) {
  mfree_approximant_t *a =
      mp_approx(ctx, ps, mesh, kernel, deriv, MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT, npts, pts, hp, NULL);
  mp_table_t t;
  mp_table_get(ctx, a, MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT, &t);
  for (int p = 0; p < npts; ++p) {
    double sum = 0.0;
    for (int32_t j = 0; j < 6; ++j) {
      const int in = j >= first[p] && j < first[p] + n[p];
      const double v = mp_at(&t, t.val, p, j), g = mp_at(&t, t.grad[0], p, j);
      sum += v;
      if (!in) {
        if (fabs(v) > 1e-15 || fabs(g) > 1e-13)
          fail_msg("x = %g: node %d outside the reference support has N = %g, dN = %g", pts[p], j, v, g);
        continue;
      }
      if (N && fabs(v - N[p][j - first[p]]) > TOL)
        fail_msg("x = %g kernel %d: N_%d = %.7f, reference %.6f", pts[p], kernel, j, v, N[p][j - first[p]]);
      if (dN && fabs(g - dN[p][j - first[p]]) > TOL)
        fail_msg("x = %g kernel %d deriv %d: dN_%d = %.7f, reference %.6f", pts[p], kernel, deriv, j, g,
                 dN[p][j - first[p]]);
    }
    assert_true(fabs(sum - 1.0) < 1e-14); /* partition of unity, 004 eq 12 */
  }
  mp_table_free(&t);
  mfree_approximant_destroy(&a);
}

/* The reference values, cosine kernel d = 2: N, eq 21 and eq 22 derivatives. */
static void test_cosine_d2(void **state) {
  (void)state;
  const int np = sizeof kCosD2 / sizeof kCosD2[0];
  double pts[16], N[16][4], d21[16][4], d22[16][4];
  int32_t first[16], n[16];
  for (int p = 0; p < np; ++p) {
    pts[p] = kCosD2[p].x;
    first[p] = kCosD2[p].first;
    n[p] = kCosD2[p].n;
    for (int k = 0; k < 4; ++k) {
      N[p][k] = kCosD2[p].N[k];
      d21[p][k] = kCosD2[p].d21[k];
      d22[p][k] = kCosD2[p].d22[k];
    }
  }
  check_rows(MFREE_KERNEL_COSINE, 1.0, MFREE_MPFEM_DERIV_FULL, np, pts, first, n,
             (const double(*)[4])N, (const double(*)[4])d21);
  check_rows(MFREE_KERNEL_COSINE, 1.0, MFREE_MPFEM_DERIV_ASSUMED_STRAIN, np, pts, first, n,
             (const double(*)[4])N, (const double(*)[4])d22);
}

/* The reference values: Haar kernel d = 2 and cosine kernel d = 1 (MPFEM = FEM at the element
 * centre when the support lies inside one element, 004 Sect. 2.2). */
static void test_haar_and_small_support(void **state) {
  (void)state;
  const double pts[2] = {2.5, 2.75};
  const int32_t first[2] = {1, 1}, n[2] = {4, 4};
  const double Nh[2][4] = {{-0.125, 0.625, 0.625, -0.125}, {-0.09375, 0.34375, 0.84375, -0.09375}};
  check_rows(MFREE_KERNEL_HAAR, 1.0, MFREE_MPFEM_DERIV_ASSUMED_STRAIN, 2, pts, first, n, Nh, NULL);
  const int32_t f1[2] = {2, 2}, n1[2] = {2, 3};
  const double Nc[2][4] = {{0.5, 0.5}, {0.213388, 0.823223, -0.036612}};
  check_rows(MFREE_KERNEL_COSINE, 0.5, MFREE_MPFEM_DERIV_FULL, 2, pts, f1, n1, Nc, NULL);
}

/* The MPFEM kernels as radial kernels (mfree_kernel_eval): support radius 1 and the
 * normalisation constants in closed form, 1D (004 eq 28 corrected: pi/(2d) with
 * d = 2h), 2D and 3D: cosine pi/4, 1/(4 - 8/pi), 1/(8 - 64/pi^2); cos^2 1,
 * 1/(pi/2 - 2/pi), 1/(2pi/3 - 4/pi); Haar 1/2, 1/pi, 3/(4pi). */
static void test_kernel_constants(void **state) {
  (void)state;
  const double pi = 3.14159265358979323846;
  const mfree_kernel_t ks[3] = {MFREE_KERNEL_COSINE, MFREE_KERNEL_COSINE_SQUARED, MFREE_KERNEL_HAAR};
  const double c[3][3] = {{pi / 4, 1 / (4 - 8 / pi), 1 / (8 - 64 / (pi * pi))},
                          {1.0, 1 / (pi / 2 - 2 / pi), 1 / (2 * pi / 3 - 4 / pi)},
                          {0.5, 1 / pi, 3 / (4 * pi)}};
  for (int k = 0; k < 3; ++k) {
    double R = 0.0;
    assert_ok(ctx, mfree_kernel_get_support_radius(ctx, ks[k], 0.0, &R));
    assert_true(R == 1.0);
    for (int d = 1; d <= 3; ++d) {
      double v = 0.0;
      assert_ok(ctx, mfree_kernel_get_normalization(ctx, ks[k], d, 0.0, &v));
      if (fabs(v - c[k][d - 1]) > 1e-14 * c[k][d - 1])
        fail_msg("kernel %d, %dD: normalisation %.17g, closed form %.17g", ks[k], d, v, c[k][d - 1]);
    }
  }
  /* 1D values: W(t) = (pi/(2d)) cos(pi t/d), d = 2h = 2 */
  const double r[3] = {0.0, 0.5, 1.0};
  double w[3], dw[3];
  assert_ok(ctx, mfree_kernel_eval(ctx, MFREE_KERNEL_COSINE, 1, 0.0, 1.0, 3, r, w, dw, NULL));
  for (int i = 0; i < 3; ++i) {
    assert_true(fabs(w[i] - pi / 4 * cos(pi * r[i] / 2)) < 1e-15);
    assert_true(fabs(dw[i] + pi * pi / 8 * sin(pi * r[i] / 2)) < 1e-15);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_kernel_constants),
      cmocka_unit_test(test_cosine_d2),
      cmocka_unit_test(test_haar_and_small_support),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
