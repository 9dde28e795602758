/* Completeness of every method on an irregular 2D cloud, computed with
 * mfree_approximant_check_reproduction and compared with the statements of paper 000
 * (Belytschko, Krongauz, Dolbow, Gerlach, "On the completeness of meshfree particle
 * methods", IJNME 43 (1998) 785-819, Sect. 4, eqs 21-70) and, for MSPH and
 * SSPH, with paper 001 (Zhang & Batra, Comput Mech 43 (2009) 321-340, Sects. 2-3).
 *  - function order: largest k <= 3 with every reproducing condition of degree <= k
 *    (000 eqs 5-7) met to 1e-10 at every particle, -1 when constants fail;
 *  - derivative order: the same for the gradient table (000 eqs 8-9);
 *  - the Johnson-Beissel counterexample v = a(x + y) (000 eqs 53-54);
 *  - integrability (000 eq 18) of Shepard and MLS against KB Methods 1-3.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"

static mfree_context_t *ctx;
static int setup(void **s) { (void)s; return mfree_context_create(&ctx) != MFREE_SUCCESS; }
static int teardown(void **s) { (void)s; return mfree_context_destroy(&ctx) != MFREE_SUCCESS; }

#define TOL 1e-10

/* An M x M lattice in the unit square; jitter (fraction of dx) moves each particle by up
 * to +-jitter dx per axis. Support h = hr dx, volumes dx^2, cubic spline, gather. */
enum { MMAX = 16 };
typedef struct {
  int m, n;
  double dx, h;
  double x[2 * MMAX * MMAX];
} cloud_t;

static mfree_particles_t *make_cloud(cloud_t *c, int m, double jitter, double hr, uint64_t seed) {
  mfree_rng_t rng;
  mfree_rng_seed(&rng, seed);
  c->m = m;
  c->n = m * m;
  c->dx = 1.0 / m;
  c->h = hr * c->dx;
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < m; ++i) {
      c->x[2 * (j * m + i) + 0] = (i + 0.5 + jitter * (2.0 * mfree_rng_uniform(&rng) - 1.0)) * c->dx;
      c->x[2 * (j * m + i) + 1] = (j + 0.5 + jitter * (2.0 * mfree_rng_uniform(&rng) - 1.0)) * c->dx;
    }
  const double vol = c->dx * c->dx;
  mfree_particles_t *ps = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, 2, c->n, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, c->x, MFREE_LAYOUT_AOS, 2, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_volumes(ps, &vol, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_support(ps, &c->h, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_search(ps, MFREE_SEARCH_GATHER, 2.0));
  return ps;
}

static mfree_approximant_t *make(mfree_particles_t *ps, mfree_method_t method, int order,
                                 int flags) {
  mfree_approximant_t *a = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, method, &a));
  assert_ok(ctx, mfree_approximant_set_order(a, order));
  assert_ok(ctx, mfree_approximant_set_derivatives(a, flags));
  assert_ok(ctx, mfree_approximant_setup(a));
  return a;
}

/* Orders reached, as defined above. */
static void orders(mfree_approximant_t *a, int *fn, int *deriv) {
  int fok = 1, dok = 1;
  *fn = *deriv = -1;
  for (int k = 0; k <= 3; ++k) {
    double fe = 0.0, de = 0.0;
    assert_ok(ctx, mfree_approximant_check_reproduction(a, k, &fe, &de));
    fok = fok && fe < TOL;
    dok = dok && de < TOL;
    if (fok) *fn = k;
    if (dok) *deriv = k;
  }
}

typedef struct {
  mfree_method_t method;
  int order;
  int fn, deriv; /* expected */
  const char *source;
} row_t;

/* Paper 000 Sect. 4 (docs/papers.md, paper 000, derived results 2) and paper 001 for
 * MSPH/SSPH. 3 means ">= 3" (check_reproduction covers degrees up to 3). */
static const row_t kRows[] = {
    {MFREE_METHOD_SPH, 0, -1, -1, "000 Sect. 3 (eqs 21, 29; eq 37): SPH reproduces nothing, not even constants"},
    {MFREE_METHOD_SPH_SYMMETRIC, 0, -1, 0, "000 Sect. 4.4.1 (eq 47): symmetrised SPH, derivatives of constants only; function not corrected"},
    {MFREE_METHOD_SHEPARD, 0, 0, 0, "000 Sect. 4.2 (eqs 38-42): Shepard constant / constant"},
    {MFREE_METHOD_MLS, 1, 1, 1, "000 Sect. 4.3 (eqs 43-46): MLS linear / linear"},
    {MFREE_METHOD_MLS, 2, 2, 2, "000 Sect. 2 (eqs 3-4): MLS of order k is complete to k (k = 2)"},
    {MFREE_METHOD_MLS, 3, 3, 3, "000 Sect. 2 (eqs 3-4): MLS of order k is complete to k (k = 3)"},
    {MFREE_METHOD_RKPM, 1, 1, 1, "000 Sect. 4.3 / 001 eqs 4.5-4.13: RKPM = MLS by kernel correction, linear"},
    {MFREE_METHOD_RKPM, 2, 2, 2, "001 Sect. 4 (eq 4.5): RKPM reproducing conditions to order n = 2"},
    {MFREE_METHOD_JOHNSON_BEISSEL, 1, -1, 0, "000 Sect. 4.4.2 (eqs 49-54): JB derivatives of constants only (fails v = a(x+y)); function not corrected"},
    {MFREE_METHOD_RANDLES_LIBERSKY, 1, -1, 1, "000 Sect. 4.4.6 (eqs 68-69): RL linear derivatives; function not corrected"},
    {MFREE_METHOD_KB_METHOD1, 1, 0, 1, "000 Sect. 4.4.3 (eqs 55-61): KB Method 1 constant (Shepard) / linear"},
    {MFREE_METHOD_KB_METHOD2, 1, 1, 1, "000 Sect. 4.4.4 (eqs 63-64): KB Method 2 linear / linear"},
    {MFREE_METHOD_KB_METHOD3, 1, 1, 1, "000 Sect. 4.4.5 (eqs 65-66): KB Method 3 linear / linear"},
    /* 001 states consistency m, m-1 (m-2 for second derivatives); at the particles both
     * fits reproduce degree m exactly in the value and gradient tables (K Q = T is solved
     * exactly when f is a polynomial of degree <= m), which implies the paper's orders. */
    {MFREE_METHOD_MSPH, 1, 1, 1, "001 Sect. 2 (eq 2.15 consistency m, m-1), m = 1: exact reproduction of degree 1"},
    {MFREE_METHOD_MSPH, 2, 2, 2, "001 Sect. 2 (eq 2.15 consistency m, m-1), m = 2: exact reproduction of degree 2"},
    {MFREE_METHOD_SSPH, 1, 1, 1, "001 Sect. 3 (consistency m, m-1), m = 1: exact reproduction of degree 1"},
    {MFREE_METHOD_SSPH, 2, 2, 2, "001 Sect. 3 (consistency m, m-1), m = 2: exact reproduction of degree 2"},
    {MFREE_METHOD_SSPH, 3, 3, 3, "001 Sect. 3 (consistency m, m-1), m = 3: exact reproduction of degree 3"},
};

static void test_summary_table(void **state) {
  (void)state;
  static cloud_t c;
  mfree_particles_t *ps = make_cloud(&c, 10, 0.35, 1.9, 412);
  for (size_t r = 0; r < sizeof kRows / sizeof kRows[0]; ++r) {
    const row_t *row = &kRows[r];
    mfree_approximant_t *a = make(ps, row->method, row->order, MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT);
    int fn, deriv;
    orders(a, &fn, &deriv);
    if (fn != row->fn || deriv != row->deriv)
      fail_msg("%s: function/derivative order %d/%d, the paper's table says %d/%d", row->source,
               fn, deriv, row->fn, row->deriv);
    mfree_approximant_destroy(&a);
  }
  mfree_particles_destroy(&ps);
}

/* 001 Sect. 3 ("consistent to orders m, m-1 and m-2"): SSPH (and,
 * by the same argument, MSPH) reproduces degree m exactly in the second-derivative table
 * as well, boundary particles included, and not degree m + 1. */
static void test_second_derivatives(void **state) {
  (void)state;
  static cloud_t c;
  mfree_particles_t *ps = make_cloud(&c, 10, 0.35, 1.9, 4122);
  static const struct {
    mfree_method_t method;
    int order;
    const char *source;
  } rows[] = {
      {MFREE_METHOD_SSPH, 2, "001 Sect. 3: SSPH m = 2, f, grad f, Hessian exact for degree 2"},
      {MFREE_METHOD_MSPH, 2, "001 Sect. 2 (eq 2.15): MSPH m = 2, f, grad f, Hessian exact for degree 2"},
      {MFREE_METHOD_SSPH, 3, "001 Sect. 3 (general m): SSPH m = 3, Hessian exact for degree 3"},
  };
  for (size_t r = 0; r < sizeof rows / sizeof rows[0]; ++r) {
    mfree_approximant_t *a =
        make(ps, rows[r].method, rows[r].order, MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT | MFREE_DERIV_HESSIAN);
    double fe, de;
    assert_ok(ctx, mfree_approximant_check_reproduction(a, rows[r].order, &fe, &de));
    if (!(fe < TOL && de < TOL)) fail_msg("%s: violations %.3g (f), %.3g (derivatives)", rows[r].source, fe, de);
    if (rows[r].order < 3) {
      assert_ok(ctx, mfree_approximant_check_reproduction(a, rows[r].order + 1, &fe, &de));
      if (!(fe > 1e-6 && de > 1e-6))
        fail_msg("%s, and not degree %d: violations %.3g (f), %.3g (derivatives)", rows[r].source,
                 rows[r].order + 1, fe, de);
    }
    mfree_approximant_destroy(&a);
  }
  mfree_particles_destroy(&ps);
}

/* 000 eqs 53-54: JB gives D_x = a (1 + rho_J) for v_x = a (x + y), with
 * rho_J = sum_I dW_JI/dx V_I (y_I - y_J) / sum_I dW_JI/dx V_I (x_I - x_J), non-zero on
 * irregular particles, while v_x = a x is differentiated exactly (000 Sect. 4.4.2).
 * rho_J is computed here from the neighbour lists and mfree_kernel_eval. */
static void test_johnson_beissel_counterexample(void **state) {
  (void)state;
  static cloud_t c;
  mfree_particles_t *ps = make_cloud(&c, 10, 0.35, 1.5, 4123);
  mfree_approximant_t *a = make(ps, MFREE_METHOD_JOHNSON_BEISSEL, 1, MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT);
  const int n = c.n;
  static double vx[MMAX * MMAX], vxy[MMAX * MMAX], gx[2 * MMAX * MMAX], gxy[2 * MMAX * MMAX];
  const double alpha = 0.7;
  for (int i = 0; i < n; ++i) {
    vx[i] = alpha * c.x[2 * i];
    vxy[i] = alpha * (c.x[2 * i] + c.x[2 * i + 1]);
  }
  assert_ok(ctx, mfree_approximant_apply(a, MFREE_OP_GRADIENT, 1, vx, MFREE_LAYOUT_AOS, 1, gx, MFREE_LAYOUT_AOS, 2));
  assert_ok(ctx, mfree_approximant_apply(a, MFREE_OP_GRADIENT, 1, vxy, MFREE_LAYOUT_AOS, 1, gxy, MFREE_LAYOUT_AOS, 2));
  int64_t nnz = 0;
  assert_ok(ctx, mfree_particles_get_neighbor_nnz(ps, &nnz));
  int64_t *rowptr = malloc(sizeof(int64_t) * (size_t)(n + 1));
  int32_t *cols = malloc(sizeof(int32_t) * (size_t)nnz);
  assert_non_null(rowptr);
  assert_non_null(cols);
  assert_ok(ctx, mfree_particles_get_neighbors(ps, rowptr, cols));
  double max_rho = 0.0;
  for (int J = 0; J < n; ++J) {
    if (!(fabs(gx[2 * J] - alpha) < 1e-12))
      fail_msg("000 eq 52a: JB reproduces D_x of v_x = a x exactly; particle %d gives %.15g", J, gx[2 * J]);
    double num = 0.0, den = 0.0;
    for (int64_t k = rowptr[J]; k < rowptr[J + 1]; ++k) {
      const int I = cols[k];
      if (I == J) continue;
      const double dx = c.x[2 * I] - c.x[2 * J], dy = c.x[2 * I + 1] - c.x[2 * J + 1];
      const double r = sqrt(dx * dx + dy * dy);
      double dw = 0.0;
      assert_ok(ctx, mfree_kernel_eval(ctx, MFREE_KERNEL_CUBIC_SPLINE, 2, 0.0, c.h, 1, &r, NULL, &dw, NULL));
      const double dWdx = dw * (-dx) / r; /* d/dx_J W(|x_J - x_I|) */
      num += dWdx * (dy);
      den += dWdx * (dx);
    }
    const double rho = num / den;
    if (!(fabs(gxy[2 * J] - alpha * (1.0 + rho)) < 1e-12))
      fail_msg("000 eq 54: JB D_x of a(x+y) is a(1 + rho_J); particle %d: %.15g vs %.15g", J,
               gxy[2 * J], alpha * (1.0 + rho));
    if (fabs(rho) > max_rho) max_rho = fabs(rho);
  }
  if (!(max_rho > 1e-3))
    fail_msg("000 Sect. 4.4.2: JB fails v = a(x+y) on irregular particles (max |rho_J| = %.3g)", max_rho);
  free(rowptr);
  free(cols);
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);

  /* on a regular lattice rho_J = 0 at interior nodes, JB exact (docs/papers.md, paper 000,
   * derived results 1) */
  static cloud_t g;
  ps = make_cloud(&g, 12, 0.0, 1.5, 1);
  a = make(ps, MFREE_METHOD_JOHNSON_BEISSEL, 1, MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT);
  for (int i = 0; i < g.n; ++i) vxy[i] = alpha * (g.x[2 * i] + g.x[2 * i + 1]);
  assert_ok(ctx, mfree_approximant_apply(a, MFREE_OP_GRADIENT, 1, vxy, MFREE_LAYOUT_AOS, 1, gxy, MFREE_LAYOUT_AOS, 2));
  int interior = 0;
  for (int i = 0; i < g.n; ++i) {
    const double px = g.x[2 * i], py = g.x[2 * i + 1], edge = 2.0 * g.h;
    if (px < edge || px > 1 - edge || py < edge || py > 1 - edge) continue;
    ++interior;
    if (!(fabs(gxy[2 * i] - alpha) < 1e-12 && fabs(gxy[2 * i + 1] - alpha) < 1e-12))
      fail_msg("000 Sect. 4.4.2, lattice: JB exact for a(x+y) at interior lattice node %d: %.15g, %.15g", i,
               gxy[2 * i], gxy[2 * i + 1]);
  }
  assert_true(interior > 0);
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
}

/* Max over particles I of |d/dy G_xI - d/dx G_yI| h^2 at (x0, y0), central differences
 * of the gradient shape functions evaluated at host points (000 eq 18). */
static double curl(mfree_particles_t *ps, const cloud_t *c, mfree_method_t method, int order,
                   double x0, double y0) {
  const double e = 1e-5 * c->h;
  const double p[8] = {x0 + e, y0, x0 - e, y0, x0, y0 + e, x0, y0 - e};
  mfree_approximant_t *a = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, method, &a));
  assert_ok(ctx, mfree_approximant_set_order(a, order));
  assert_ok(ctx, mfree_approximant_set_derivatives(a, MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT));
  assert_ok(ctx, mfree_approximant_set_points(a, 4, p, MFREE_LAYOUT_AOS, 2, &c->h, 0, MFREE_COPY));
  assert_ok(ctx, mfree_approximant_setup(a));
  /* G[point][direction][particle] through apply on unit vectors would be O(n^2); the
   * CSR export gives the rows directly */
  int64_t nnz = 0, rowptr[5];
  assert_ok(ctx, mfree_approximant_get_nnz(a, &nnz));
  int32_t *cols = malloc(sizeof(int32_t) * (size_t)nnz);
  double *vx = malloc(sizeof(double) * (size_t)nnz), *vy = malloc(sizeof(double) * (size_t)nnz);
  double *G = calloc((size_t)8 * (size_t)c->n, sizeof(double));
  assert_non_null(cols);
  assert_non_null(vx);
  assert_non_null(vy);
  assert_non_null(G);
  assert_ok(ctx, mfree_approximant_assemble_csr(a, MFREE_DERIV_GRADIENT, 0, rowptr, cols, vx));
  assert_ok(ctx, mfree_approximant_assemble_csr(a, MFREE_DERIV_GRADIENT, 1, rowptr, cols, vy));
  for (int q = 0; q < 4; ++q)
    for (int64_t k = rowptr[q]; k < rowptr[q + 1]; ++k) {
      G[(size_t)(2 * q) * c->n + cols[k]] = vx[k];
      G[(size_t)(2 * q + 1) * c->n + cols[k]] = vy[k];
    }
  double worst = 0.0;
  for (int I = 0; I < c->n; ++I) {
    const double dGy_dx = (G[(size_t)1 * c->n + I] - G[(size_t)3 * c->n + I]) / (2 * e);
    const double dGx_dy = (G[(size_t)4 * c->n + I] - G[(size_t)6 * c->n + I]) / (2 * e);
    worst = fmax(worst, fabs(dGy_dx - dGx_dy) * c->h * c->h);
  }
  free(cols);
  free(vx);
  free(vy);
  free(G);
  mfree_approximant_destroy(&a);
  return worst;
}

/* 000 Sects. 2.3, 4 (eq 18; docs/papers.md, paper 000, derived results 3): Shepard and
 * MLS derivatives are true derivatives, hence integrable; KB Methods 1, 2, 3 corrected derivatives are not. The
 * curl of a true gradient is zero up to the O(e^2) difference error (~1e-10 here); the
 * corrected ones give ~1e-2. */
static void test_integrability(void **state) {
  (void)state;
  static cloud_t c;
  mfree_particles_t *ps = make_cloud(&c, 10, 0.35, 1.9, 4124);
  static const double probe[2][2] = {{0.487, 0.531}, {0.362, 0.618}};
  static const struct {
    mfree_method_t method;
    int order, integrable;
    const char *source;
  } rows[] = {
      {MFREE_METHOD_SHEPARD, 0, 1, "000 Sect. 4.2: Shepard derivatives are integrable"},
      {MFREE_METHOD_MLS, 1, 1, "000 Sect. 4.3: MLS derivatives are integrable"},
      {MFREE_METHOD_KB_METHOD1, 1, 0, "000 Sect. 4.4.3: KB Method 1 derivatives are not integrable"},
      {MFREE_METHOD_KB_METHOD2, 1, 0, "000 Sect. 4.4.4: Method 2 derivatives are not integrable"},
      {MFREE_METHOD_KB_METHOD3, 1, 0, "000 Sect. 4.4.5: Method 3 derivatives are not integrable"},
  };
  for (size_t r = 0; r < sizeof rows / sizeof rows[0]; ++r) {
    double worst = 0.0;
    for (int p = 0; p < 2; ++p)
      worst = fmax(worst, curl(ps, &c, rows[r].method, rows[r].order, probe[p][0], probe[p][1]));
    if (rows[r].integrable ? !(worst < 1e-7) : !(worst > 1e-4))
      fail_msg("%s: max |curl| h^2 = %.3g", rows[r].source, worst);
  }
  mfree_particles_destroy(&ps);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_summary_table),
      cmocka_unit_test(test_second_derivatives),
      cmocka_unit_test(test_johnson_beissel_counterexample),
      cmocka_unit_test(test_integrability),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
