/* 2D Poisson problem -lap u = f on the unit square, u = g on the boundary, exact
 * solution u = sin(pi x) sin(pi y) + x y / 2, on structured QUAD4 or TRI3 meshes of
 * n x n cells, by MPFEM through mfree's assembler (cosine kernel, eq 21 derivatives,
 * nodal values imposed on the boundary nodes, Gauss quadrature of the mesh with a given
 * number of points per direction) and UMFPACK.
 * FEM is the same code with a kernel support far inside the elements (1e-6 of the
 * spacing): at the Gauss points the MPFEM functions are then exactly the FE functions
 * (reduction to FEM, checked against hand-written FE functions in t471). Errors in L2
 * and in the H1 semi-norm with a 5-point (per direction) Gauss rule of the mesh. */
#ifndef MPFEM_POISSON2D_H
#define MPFEM_POISSON2D_H

#include <math.h>
#include <stdlib.h>

#include <mfree_suitesparse.h>

#include "mpfem_util.h"

static const double P2_PI = 3.14159265358979323846;

static double p2_u(const double *x) { return sin(P2_PI * x[0]) * sin(P2_PI * x[1]) + 0.5 * x[0] * x[1]; }
static void p2_du(const double *x, double *g) {
  g[0] = P2_PI * cos(P2_PI * x[0]) * sin(P2_PI * x[1]) + 0.5 * x[1];
  g[1] = P2_PI * sin(P2_PI * x[0]) * cos(P2_PI * x[1]) + 0.5 * x[0];
}
static void p2_f_fn(void *user, const double *x, double *v) {
  (void)user;
  v[0] = 2.0 * P2_PI * P2_PI * sin(P2_PI * x[0]) * sin(P2_PI * x[1]);
}
static void p2_g_fn(void *user, const double *x, double *v) { (void)user; v[0] = p2_u(x); }

typedef struct {
  double L2, H1, H1_22; /* H1 semi-norm with eq 21 (Galerkin) and eq 22 derivatives */
} p2_err_t;

/* Solve on an n x n grid; tri != 0: TRI3 (two per cell, one diagonal). hk_rel: kernel
 * support half width in units of the spacing; ngauss: points per direction of the
 * assembly's Gauss rule (mfree_mesh_get_quadrature). Returns the setup status of the
 * assembler (positive statuses are failures here). */
static mfree_status_t p2_solve(mfree_context_t *ctx, int32_t n, int tri, double hk_rel, int32_t ngauss,
                               p2_err_t *err) {
  const int32_t nn = (n + 1) * (n + 1), ne = tri ? 2 * n * n : n * n;
  const double h = 1.0 / n, hk = hk_rel * h;
  double *gs = malloc(sizeof(double) * (size_t)(n + 1)), *x = malloc(sizeof(double) * 2 * (size_t)nn);
  for (int32_t i = 0; i <= n; ++i) gs[i] = i * h;
  gs[n] = 1.0;
  mp_grid_nodes(n, n, gs, gs, x);
  int32_t *conn = malloc(sizeof(int32_t) * 6 * (size_t)n * (size_t)n);
  if (tri)
    mp_grid_tris(n, n, conn);
  else
    mp_grid_quads(n, n, conn);
  mfree_particles_t *ps = mp_particles(ctx, 2, nn, x, hk);
  mfree_mesh_t *m = mp_mesh(ctx, ps, tri ? MFREE_ELEMENT_TRI3 : MFREE_ELEMENT_QUAD4, ne, conn);
  mfree_approximant_t *a = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MPFEM, &a));
  assert_ok(ctx, mfree_approximant_set_mesh(a, m));
  mfree_assembler_t *as = NULL;
  assert_ok(ctx, mfree_assembler_create(ctx, a, NULL, MFREE_FORM_LAPLACE, &as));
  int32_t nq = 0;
  assert_ok(ctx, mfree_mesh_get_quadrature(m, ngauss, &nq, NULL, NULL));
  double *qx = malloc(sizeof(double) * 2 * (size_t)nq), *qw = malloc(sizeof(double) * (size_t)nq);
  assert_ok(ctx, mfree_mesh_get_quadrature(m, ngauss, &nq, qx, qw));
  assert_ok(ctx, mfree_assembler_set_quadrature_points(as, nq, qx, MFREE_LAYOUT_AOS, 2, qw));
  assert_ok(ctx, mfree_assembler_set_body_force(as, p2_f_fn, NULL));
  int32_t *bn = malloc(sizeof(int32_t) * 4 * (size_t)(n + 1)), nb = 0;
  for (int32_t j = 0; j <= n; ++j)
    for (int32_t i = 0; i <= n; ++i)
      if (i == 0 || j == 0 || i == n || j == n) bn[nb++] = j * (n + 1) + i;
  assert_ok(ctx, mfree_assembler_add_dirichlet_nodes(as, nb, bn, 1, p2_g_fn, NULL));
  const mfree_status_t st = mfree_assembler_setup(as);
  if (st != MFREE_SUCCESS) goto done;
  mfree_matrix_t *K = NULL;
  assert_ok(ctx, mfree_assembler_assemble_matrix(as, &K));
  double *f = malloc(sizeof(double) * (size_t)nn), *u = malloc(sizeof(double) * (size_t)nn);
  assert_ok(ctx, mfree_assembler_assemble_rhs(as, f));
  mfree_suitesparse_t *s = NULL;
  assert_ok(ctx, mfree_suitesparse_create(ctx, MFREE_SOLVER_UMFPACK, &s));
  assert_ok(ctx, mfree_suitesparse_setup(s, K));
  assert_ok(ctx, mfree_suitesparse_solve(s, 1, f, nn, u, nn));
  for (int32_t k = 0; k < nb; ++k) /* the boundary values are the nodal values */
    assert_true(fabs(u[bn[k]] - p2_u(&x[2 * bn[k]])) < 1e-14);
  int32_t ne5 = 0;
  assert_ok(ctx, mfree_mesh_get_quadrature(m, 5, &ne5, NULL, NULL));
  double *ex = malloc(sizeof(double) * 2 * (size_t)ne5), *ew = malloc(sizeof(double) * (size_t)ne5);
  assert_ok(ctx, mfree_mesh_get_quadrature(m, 5, &ne5, ex, ew));
  mfree_approximant_t *ae = mp_approx(ctx, ps, m, MFREE_KERNEL_COSINE, MFREE_MPFEM_DERIV_FULL,
                                      MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT, ne5, ex, hk, NULL);
  double *v = malloc(sizeof(double) * (size_t)ne5), *g = malloc(sizeof(double) * 2 * (size_t)ne5);
  assert_ok(ctx, mfree_approximant_apply(ae, MFREE_OP_VALUE, 1, u, MFREE_LAYOUT_AOS, 1, v, MFREE_LAYOUT_AOS, 1));
  assert_ok(ctx, mfree_approximant_apply(ae, MFREE_OP_GRADIENT, 1, u, MFREE_LAYOUT_AOS, 1, g, MFREE_LAYOUT_AOS, 2));
  mfree_approximant_t *a22 = mp_approx(ctx, ps, m, MFREE_KERNEL_COSINE, MFREE_MPFEM_DERIV_ASSUMED_STRAIN,
                                       MFREE_DERIV_GRADIENT, ne5, ex, hk, NULL);
  double *g22 = malloc(sizeof(double) * 2 * (size_t)ne5);
  assert_ok(ctx, mfree_approximant_apply(a22, MFREE_OP_GRADIENT, 1, u, MFREE_LAYOUT_AOS, 1, g22, MFREE_LAYOUT_AOS, 2));
  double l2 = 0, h1 = 0, h22 = 0;
  for (int32_t p = 0; p < ne5; ++p) {
    double gx[2];
    p2_du(&ex[2 * p], gx);
    const double dv = v[p] - p2_u(&ex[2 * p]);
    l2 += ew[p] * dv * dv;
    h1 += ew[p] * ((g[2 * p] - gx[0]) * (g[2 * p] - gx[0]) + (g[2 * p + 1] - gx[1]) * (g[2 * p + 1] - gx[1]));
    h22 += ew[p] * ((g22[2 * p] - gx[0]) * (g22[2 * p] - gx[0]) +
                    (g22[2 * p + 1] - gx[1]) * (g22[2 * p + 1] - gx[1]));
  }
  err->L2 = sqrt(l2);
  err->H1 = sqrt(h1);
  err->H1_22 = sqrt(h22);
  mfree_approximant_destroy(&a22);
  free(g22);
  mfree_approximant_destroy(&ae);
  mfree_suitesparse_destroy(&s);
  mfree_matrix_destroy(&K);
  free(f), free(u), free(ex), free(ew), free(v), free(g);
done:
  mfree_assembler_destroy(&as);
  mfree_approximant_destroy(&a);
  mfree_mesh_destroy(&m);
  mfree_particles_destroy(&ps);
  free(gs), free(x), free(conn), free(qx), free(qw), free(bn);
  return st;
}

#endif
