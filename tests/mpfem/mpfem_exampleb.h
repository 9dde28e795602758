/* Paper 004 Example B (Sect. 3.2, eqs 29-35): u'' + g = 0 on [0, 1], u(0) given,
 * u'(1) given, exact solution u = -x^3 + exp(-((x - x0)/alpha)^2), alpha = 0.02,
 * x0 = 0.5, linear elements of spacing h. Solved by linear FEM (written out here: a
 * tridiagonal system) and by MPFEM through mfree's assembler (cosine kernel, support
 * half width R h_k = h, i.e. d = 2h; trial derivative eq 21; Bubnov-Galerkin; nodal
 * value imposed at x = 0) with UMFPACK. Errors: eq 34 (L2) and eq 35 (H1 semi-norm,
 * MPFEM derivative by eq 22 as in the paper, and by eq 21), with 10-point Gauss per
 * half element as in docs/papers.md, paper 004, reproduction. Header-only so that tests include it. */
#ifndef MPFEM_EXAMPLEB_H
#define MPFEM_EXAMPLEB_H

#include <math.h>
#include <stdlib.h>

#include <mfree_suitesparse.h>

#include "mpfem_util.h"

#define EB_ALPHA 0.02
#define EB_X0 0.5

static double eb_u(double x) {
  const double s = (x - EB_X0) / EB_ALPHA;
  return -x * x * x + exp(-s * s);
}
static double eb_du(double x) {
  const double s = (x - EB_X0) / EB_ALPHA;
  return -3.0 * x * x - 2.0 * (x - EB_X0) / (EB_ALPHA * EB_ALPHA) * exp(-s * s);
}
static double eb_g(double x) { /* 004 eq 30 */
  const double s = (x - EB_X0) / EB_ALPHA, a2 = EB_ALPHA * EB_ALPHA, q = (2 * x - 2 * EB_X0) / a2;
  return 6.0 * x + (2.0 / a2 - q * q) * exp(-s * s);
}
static void eb_g_fn(void *user, const double *x, double *v) { (void)user; v[0] = eb_g(x[0]); }
static void eb_u_fn(void *user, const double *x, double *v) { (void)user; v[0] = eb_u(x[0]); }
static void eb_t_fn(void *user, const double *x, double *v) { (void)user; v[0] = eb_du(x[0]); }

typedef struct {
  double L2, H1, H1_21; /* H1: FEM, or MPFEM by eq 22 */
} eb_err_t;

/* Gauss-Legendre rule on [-1, 1] through a one-element mesh's quadrature. */
static void eb_gauss(mfree_context_t *ctx, int n, double *xg, double *wg) {
  const double x[2] = {-1.0, 1.0};
  const int32_t conn[2] = {0, 1};
  mfree_particles_t *ps = mp_particles(ctx, 1, 2, x, 1.0);
  mfree_mesh_t *m = mp_mesh(ctx, ps, MFREE_ELEMENT_LINE2, 1, conn);
  int32_t np = 0;
  assert_ok(ctx, mfree_mesh_get_quadrature(m, n, &np, xg, wg));
  assert_int_equal(np, n);
  mfree_mesh_destroy(&m);
  mfree_particles_destroy(&ps);
}

/* Error points: 10-point Gauss on each half element of the uniform mesh of n nodes. */
static int32_t eb_error_points(mfree_context_t *ctx, int32_t n, double **xe, double **we) {
  double xg[10], wg[10];
  eb_gauss(ctx, 10, xg, wg);
  const int32_t ne = 2 * (n - 1), np = 10 * ne;
  *xe = malloc(sizeof(double) * (size_t)np);
  *we = malloc(sizeof(double) * (size_t)np);
  const double hh = 1.0 / ne;
  for (int32_t e = 0; e < ne; ++e)
    for (int g = 0; g < 10; ++g) {
      (*xe)[10 * e + g] = hh * (e + 0.5 * (1.0 + xg[g]));
      (*we)[10 * e + g] = 0.5 * hh * wg[g];
    }
  return np;
}

/* Linear FEM, ngauss points per element for the load. */
static void eb_fem(mfree_context_t *ctx, int32_t n, int ngauss, eb_err_t *err) {
  const double h = 1.0 / (n - 1);
  double xg[10], wg[10];
  eb_gauss(ctx, ngauss, xg, wg);
  double *f = calloc((size_t)n, sizeof(double)), *u = calloc((size_t)n, sizeof(double));
  double *d = malloc(sizeof(double) * (size_t)n), *o = malloc(sizeof(double) * (size_t)n);
  for (int32_t e = 0; e + 1 < n; ++e)
    for (int g = 0; g < ngauss; ++g) {
      const double s = 0.5 * (1 + xg[g]), x = (e + s) * h, w = 0.5 * h * wg[g] * eb_g(x);
      f[e] += w * (1 - s);
      f[e + 1] += w * s;
    }
  f[n - 1] += eb_du(1.0);
  u[0] = eb_u(0.0);
  /* unknowns 1..n-1: tridiagonal (2/h, -1/h), last diagonal 1/h; Thomas algorithm */
  for (int32_t i = 1; i < n; ++i) {
    d[i] = (i == n - 1 ? 1.0 : 2.0) / h;
    o[i] = -1.0 / h;
  }
  f[1] += u[0] / h;
  for (int32_t i = 2; i < n; ++i) {
    const double m = o[i - 1] / d[i - 1];
    d[i] -= m * o[i - 1];
    f[i] -= m * f[i - 1];
  }
  u[n - 1] = f[n - 1] / d[n - 1];
  for (int32_t i = n - 2; i >= 1; --i) u[i] = (f[i] - o[i] * u[i + 1]) / d[i];
  double *xe, *we;
  const int32_t np = eb_error_points(ctx, n, &xe, &we);
  double l2 = 0, h1 = 0;
  for (int32_t p = 0; p < np; ++p) {
    int32_t e = (int32_t)(xe[p] / h);
    if (e > n - 2) e = n - 2;
    const double s = xe[p] / h - e, uh = u[e] * (1 - s) + u[e + 1] * s, duh = (u[e + 1] - u[e]) / h;
    l2 += we[p] * (uh - eb_u(xe[p])) * (uh - eb_u(xe[p]));
    h1 += we[p] * (duh - eb_du(xe[p])) * (duh - eb_du(xe[p]));
  }
  err->L2 = sqrt(l2);
  err->H1 = sqrt(h1);
  err->H1_21 = err->H1;
  free(xe), free(we), free(f), free(u), free(d), free(o);
}

/* MPFEM through the assembler; kernel support half width R hk (cosine: hk = h gives
 * d = 2h); returns the solver's status (positive: singular). u (n values) may be NULL. */
static mfree_status_t eb_mpfem(mfree_context_t *ctx, int32_t n, int ngauss, mfree_kernel_t kernel,
                               double hk, mfree_mpfem_deriv_t stiffness, eb_err_t *err, double *uout) {
  const double h = 1.0 / (n - 1);
  double *x = malloc(sizeof(double) * (size_t)n);
  for (int32_t i = 0; i < n; ++i) x[i] = i * h;
  x[n - 1] = 1.0;
  int32_t *conn = malloc(sizeof(int32_t) * 2 * (size_t)n);
  mp_line_conn(n, conn);
  mfree_particles_t *ps = mp_particles(ctx, 1, n, x, hk);
  mfree_mesh_t *m = mp_mesh(ctx, ps, MFREE_ELEMENT_LINE2, n - 1, conn);
  mfree_approximant_t *a = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MPFEM, &a));
  assert_ok(ctx, mfree_approximant_set_mesh(a, m));
  assert_ok(ctx, mfree_approximant_set_kernel(a, kernel, 0.0));
  assert_ok(ctx, mfree_approximant_set_mpfem(a, stiffness, 8));
  mfree_assembler_t *as = NULL;
  assert_ok(ctx, mfree_assembler_create(ctx, a, NULL, MFREE_FORM_LAPLACE, &as));
  int32_t nq = 0;
  assert_ok(ctx, mfree_mesh_get_quadrature(m, ngauss, &nq, NULL, NULL));
  double *qx = malloc(sizeof(double) * (size_t)nq), *qw = malloc(sizeof(double) * (size_t)nq);
  assert_ok(ctx, mfree_mesh_get_quadrature(m, ngauss, &nq, qx, qw));
  assert_ok(ctx, mfree_assembler_set_quadrature_points(as, nq, qx, MFREE_LAYOUT_AOS, 1, qw));
  assert_ok(ctx, mfree_assembler_set_body_force(as, eb_g_fn, NULL));
  const double one = 1.0, w1 = 1.0;
  const int32_t node0 = 0;
  assert_ok(ctx, mfree_assembler_add_traction(as, 1, &one, MFREE_LAYOUT_AOS, 1, &w1, eb_t_fn, NULL));
  assert_ok(ctx, mfree_assembler_add_dirichlet_nodes(as, 1, &node0, 1, eb_u_fn, NULL));
  assert_ok(ctx, mfree_assembler_setup(as));
  mfree_matrix_t *K = NULL;
  assert_ok(ctx, mfree_assembler_assemble_matrix(as, &K));
  double *f = malloc(sizeof(double) * (size_t)n), *u = malloc(sizeof(double) * (size_t)n);
  assert_ok(ctx, mfree_assembler_assemble_rhs(as, f));
  mfree_suitesparse_t *s = NULL;
  assert_ok(ctx, mfree_suitesparse_create(ctx, MFREE_SOLVER_UMFPACK, &s));
  const mfree_status_t st = mfree_suitesparse_setup(s, K);
  if (st == MFREE_SUCCESS) {
    assert_ok(ctx, mfree_suitesparse_solve(s, 1, f, n, u, n));
    double *xe, *we;
    const int32_t np = eb_error_points(ctx, n, &xe, &we);
    double *v = malloc(sizeof(double) * (size_t)np), *g22 = malloc(sizeof(double) * (size_t)np),
           *g21 = malloc(sizeof(double) * (size_t)np);
    for (int form = 0; form < 2; ++form) {
      mfree_approximant_t *ae = mp_approx(ctx, ps, m, kernel,
                                          form ? MFREE_MPFEM_DERIV_FULL : MFREE_MPFEM_DERIV_ASSUMED_STRAIN,
                                          MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT, np, xe, hk, NULL);
      if (!form)
        assert_ok(ctx, mfree_approximant_apply(ae, MFREE_OP_VALUE, 1, u, MFREE_LAYOUT_AOS, 1, v, MFREE_LAYOUT_AOS, 1));
      assert_ok(ctx, mfree_approximant_apply(ae, MFREE_OP_GRADIENT, 1, u, MFREE_LAYOUT_AOS, 1, form ? g21 : g22,
                                             MFREE_LAYOUT_AOS, 1));
      mfree_approximant_destroy(&ae);
    }
    double l2 = 0, h22 = 0, h21 = 0;
    for (int32_t p = 0; p < np; ++p) {
      l2 += we[p] * (v[p] - eb_u(xe[p])) * (v[p] - eb_u(xe[p]));
      h22 += we[p] * (g22[p] - eb_du(xe[p])) * (g22[p] - eb_du(xe[p]));
      h21 += we[p] * (g21[p] - eb_du(xe[p])) * (g21[p] - eb_du(xe[p]));
    }
    err->L2 = sqrt(l2);
    err->H1 = sqrt(h22);
    err->H1_21 = sqrt(h21);
    if (uout)
      for (int32_t i = 0; i < n; ++i) uout[i] = u[i];
    free(xe), free(we), free(v), free(g22), free(g21);
  }
  mfree_suitesparse_destroy(&s);
  mfree_matrix_destroy(&K);
  mfree_assembler_destroy(&as);
  mfree_approximant_destroy(&a);
  mfree_mesh_destroy(&m);
  mfree_particles_destroy(&ps);
  free(x), free(conn), free(qx), free(qw), free(f), free(u);
  return st;
}

#endif
