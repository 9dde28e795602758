/* Assembler: exact identities (collocation reproduces quadratic elasticity fields to
 * round-off; partition-of-unity mass sums; Bubnov symmetry; Nitsche EFG patch test
 * improving with the quadrature order) and every bad input. Small systems are solved
 * densely here, so the test needs no solver library. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"

static mfree_context_t *ctx;
static int setup(void **s) { (void)s; return mfree_context_create(&ctx) != MFREE_SUCCESS; }
static int teardown(void **s) { (void)s; return mfree_context_destroy(&ctx) != MFREE_SUCCESS; }

enum { M = 9, N = M * M };
static double X[2 * N];
static int32_t BND[N], NB;

/* M x M nodes on the unit square, interior ones jittered by 25 % of the spacing. */
static mfree_particles_t *cloud(double hfac) {
  mfree_rng_t r;
  mfree_rng_seed(&r, 11);
  NB = 0;
  for (int j = 0; j < M; ++j)
    for (int i = 0; i < M; ++i) {
      const int p = j * M + i, b = i == 0 || j == 0 || i == M - 1 || j == M - 1;
      const double jx = b ? 0 : 0.25 * (2 * mfree_rng_uniform(&r) - 1);
      const double jy = b ? 0 : 0.25 * (2 * mfree_rng_uniform(&r) - 1);
      X[2 * p] = (i + jx) / (M - 1);
      X[2 * p + 1] = (j + jy) / (M - 1);
      if (b) BND[NB++] = p;
    }
  static double h, v;
  h = hfac / (M - 1);
  v = 1.0 / ((M - 1) * (M - 1));
  mfree_particles_t *ps = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, 2, N, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, X, MFREE_LAYOUT_AOS, 2, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_volumes(ps, &v, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_setup(ps));
  return ps;
}

/* Dense copy of a matrix and Gaussian elimination with partial pivoting. */
static double *dense(const mfree_matrix_t *K, int32_t *n) {
  int32_t nr, nc;
  int64_t nnz;
  assert_ok(ctx, mfree_matrix_get_size(K, &nr, &nc, &nnz));
  assert_int_equal(nr, nc);
  const int64_t *rp;
  const int32_t *ci;
  const double *v;
  assert_ok(ctx, mfree_matrix_get_csr(K, &rp, &ci, &v));
  double *A = calloc((size_t)nr * nr, sizeof(double));
  for (int32_t i = 0; i < nr; ++i)
    for (int64_t k = rp[i]; k < rp[i + 1]; ++k) A[(size_t)i * nr + ci[k]] = v[k];
  *n = nr;
  return A;
}
static void solve(int n, double *A, double *b) {
  for (int k = 0; k < n; ++k) {
    int p = k;
    for (int i = k + 1; i < n; ++i)
      if (fabs(A[(size_t)i * n + k]) > fabs(A[(size_t)p * n + k])) p = i;
    assert_true(fabs(A[(size_t)p * n + k]) > 1e-300);
    if (p != k) {
      for (int j = 0; j < n; ++j) {
        const double t = A[(size_t)k * n + j];
        A[(size_t)k * n + j] = A[(size_t)p * n + j];
        A[(size_t)p * n + j] = t;
      }
      const double t = b[k];
      b[k] = b[p];
      b[p] = t;
    }
    for (int i = k + 1; i < n; ++i) {
      const double f = A[(size_t)i * n + k] / A[(size_t)k * n + k];
      if (f == 0.0) continue;
      for (int j = k; j < n; ++j) A[(size_t)i * n + j] -= f * A[(size_t)k * n + j];
      b[i] -= f * b[k];
    }
  }
  for (int i = n - 1; i >= 0; --i) {
    double s = b[i];
    for (int j = i + 1; j < n; ++j) s -= A[(size_t)i * n + j] * b[j];
    b[i] = s / A[(size_t)i * n + i];
  }
}

/* Quadratic displacement field and the body force that balances it (plane strain,
 * E = 1, nu = 0.25): b = -(mu Lap u + (lam + mu) grad div u). */
static const double E = 1.0, NU = 0.25;
static void quad_u(void *u, const double *x, double *v) {
  (void)u;
  v[0] = 0.1 + 0.2 * x[0] - 0.3 * x[1] + 0.5 * x[0] * x[0] - 0.4 * x[0] * x[1] + 0.2 * x[1] * x[1];
  v[1] = -0.2 + 0.1 * x[0] + 0.4 * x[1] - 0.3 * x[0] * x[0] + 0.6 * x[0] * x[1] - 0.1 * x[1] * x[1];
}
static void quad_b(void *u, const double *x, double *v) {
  (void)u;
  (void)x;
  const double lam = E * NU / ((1 + NU) * (1 - 2 * NU)), mu = E / (2 * (1 + NU));
  /* u_x,xx = 1.0, u_x,xy = -0.4, u_x,yy = 0.4; u_y,xx = -0.6, u_y,xy = 0.6, u_y,yy = -0.2 */
  const double lap0 = 1.0 + 0.4, lap1 = -0.6 - 0.2;
  const double gd0 = 1.0 + 0.6, gd1 = -0.4 - 0.2; /* d/dx div u, d/dy div u */
  v[0] = -(mu * lap0 + (lam + mu) * gd0);
  v[1] = -(mu * lap1 + (lam + mu) * gd1);
}

/* SSPH and MSPH collocation reproduce a quadratic elasticity field exactly (001 Sect.
 * 6.3 form; SSPH is exact for degree <= 2 in value and both derivatives, 001 Sect. 3
 * consistency), so the nodal solution equals u(x_J) to round-off. */
static void test_collocation_exact(void **s) {
  (void)s;
  const mfree_method_t methods[2] = {MFREE_METHOD_SSPH, MFREE_METHOD_MSPH};
  for (int m = 0; m < 2; ++m) {
    mfree_particles_t *ps = cloud(1.6);
    mfree_approximant_t *a = NULL;
    assert_ok(ctx, mfree_approximant_create(ctx, ps, methods[m], &a));
    assert_ok(ctx, mfree_approximant_set_kernel(a, MFREE_KERNEL_REVISED_SUPER_GAUSS, 1.6));
    assert_ok(ctx, mfree_approximant_set_order(a, 2));
    assert_ok(ctx, mfree_approximant_set_derivatives(a, 7));
    mfree_assembler_t *as = NULL;
    assert_ok(ctx, mfree_assembler_create(ctx, a, NULL, MFREE_FORM_COLLOCATION_PLANE_STRAIN, &as));
    assert_ok(ctx, mfree_assembler_set_material(as, E, NU));
    assert_ok(ctx, mfree_assembler_set_body_force(as, quad_b, NULL));
    assert_ok(ctx, mfree_assembler_add_dirichlet_nodes(as, NB, BND, 3, quad_u, NULL));
    assert_ok(ctx, mfree_assembler_setup(as));
    mfree_matrix_t *K = NULL;
    assert_ok(ctx, mfree_assembler_assemble_matrix(as, &K));
    int32_t n = 0;
    double *A = dense(K, &n);
    assert_int_equal(n, 2 * N);
    double *f = calloc((size_t)n, sizeof(double));
    assert_ok(ctx, mfree_assembler_assemble_rhs(as, f));
    solve(n, A, f);
    double err = 0.0;
    for (int i = 0; i < N; ++i) {
      double u[2];
      quad_u(NULL, &X[2 * i], u);
      err = fmax(err, fmax(fabs(f[2 * i] - u[0]), fabs(f[2 * i + 1] - u[1])));
    }
    if (err > 1e-9) fail_msg("method %d: nodal error %g", (int)methods[m], err);
    free(A);
    free(f);
    mfree_matrix_destroy(&K);
    mfree_assembler_destroy(&as);
    mfree_approximant_destroy(&a);
    mfree_particles_destroy(&ps);
  }
}

/* Consistent mass with partition-of-unity functions (Shepard, MLS) on background cells
 * covering the unit square: the sum of all entries is rho * area exactly; the lumped
 * mass has the same diagonal sums; Bubnov matrices are symmetric. */
static void test_mass_sums(void **s) {
  (void)s;
  mfree_particles_t *ps = cloud(1.6);
  const mfree_method_t methods[2] = {MFREE_METHOD_SHEPARD, MFREE_METHOD_MLS};
  for (int m = 0; m < 2; ++m)
    for (int lumped = 0; lumped < 2; ++lumped) {
      mfree_approximant_t *a = NULL;
      assert_ok(ctx, mfree_approximant_create(ctx, ps, methods[m], &a));
      mfree_assembler_t *as = NULL;
      assert_ok(ctx, mfree_assembler_create(ctx, a, NULL, lumped ? MFREE_FORM_MASS_LUMPED : MFREE_FORM_MASS, &as));
      assert_ok(ctx, mfree_assembler_set_coefficient(as, 2.5));
      const double lo[2] = {0, 0}, hi[2] = {1, 1};
      const int32_t nc[2] = {M - 1, M - 1};
      assert_ok(ctx, mfree_assembler_set_quadrature_cells(as, lo, hi, nc, 4, NULL, NULL));
      assert_ok(ctx, mfree_assembler_setup(as));
      mfree_matrix_t *K = NULL;
      assert_ok(ctx, mfree_assembler_assemble_matrix(as, &K));
      const int64_t *rp;
      const int32_t *ci;
      const double *v;
      int32_t nr;
      assert_ok(ctx, mfree_matrix_get_csr(K, &rp, &ci, &v));
      assert_ok(ctx, mfree_matrix_get_size(K, &nr, NULL, NULL));
      double sum = 0.0;
      for (int32_t i = 0; i < nr; ++i)
        for (int64_t k = rp[i]; k < rp[i + 1]; ++k) {
          sum += v[k];
          if (lumped) assert_int_equal(ci[k], i);
        }
      if (fabs(sum - 2.5) > 1e-12) fail_msg("method %d lumped %d: mass sum %.15f", (int)methods[m], lumped, sum);
      int32_t sym = 0;
      assert_ok(ctx, mfree_matrix_get_symmetric(K, &sym));
      assert_int_equal(sym, 1);
      mfree_matrix_destroy(&K);
      mfree_assembler_destroy(&as);
      mfree_approximant_destroy(&a);
    }
  mfree_particles_destroy(&ps);
}

/* Graded cloud (particle supports h_i = 1.5 times the local spacing: 0.15 on [0,1]^2,
 * 0.75 on (1,3] x [0,1]) with background cells over [0,3] x [0,1]: each quadrature point
 * takes the support of its nearest particle. With one mean support (about 0.2) the
 * points of the coarse part would see a single particle and MLS could not be built;
 * with the local supports setup succeeds and the consistent mass matrix of MLS sums to
 * the area to round-off (partition of unity at every point, weights summing to 3). */
static void test_graded_supports(void **s) {
  (void)s;
  enum { NF = 11, NC = 4, NG = NF * NF + NC * 3 };
  double x[2 * NG], h[NG], v[NG];
  int k = 0;
  for (int i = 0; i < NF; ++i)
    for (int j = 0; j < NF; ++j, ++k) x[2 * k] = 0.1 * i, x[2 * k + 1] = 0.1 * j, h[k] = 0.15, v[k] = 0.01;
  for (int i = 0; i < NC; ++i)
    for (int j = 0; j < 3; ++j, ++k) x[2 * k] = 1.5 + 0.5 * i, x[2 * k + 1] = 0.5 * j, h[k] = 0.75, v[k] = 0.25;
  mfree_particles_t *ps = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, 2, NG, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 2, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_support(ps, h, 1, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_volumes(ps, v, 1, MFREE_COPY));
  assert_ok(ctx, mfree_particles_setup(ps));
  mfree_approximant_t *a = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, &a));
  assert_ok(ctx, mfree_approximant_set_order(a, 1));
  mfree_assembler_t *as = NULL;
  assert_ok(ctx, mfree_assembler_create(ctx, a, NULL, MFREE_FORM_MASS, &as));
  const double lo[2] = {0, 0}, hi[2] = {3, 1};
  const int32_t nc[2] = {12, 4};
  assert_ok(ctx, mfree_assembler_set_quadrature_cells(as, lo, hi, nc, 3, NULL, NULL));
  assert_ok(ctx, mfree_assembler_setup(as));
  mfree_matrix_t *K = NULL;
  assert_ok(ctx, mfree_assembler_assemble_matrix(as, &K));
  const int64_t *rp;
  const int32_t *ci;
  const double *val;
  int32_t nr;
  assert_ok(ctx, mfree_matrix_get_csr(K, &rp, &ci, &val));
  assert_ok(ctx, mfree_matrix_get_size(K, &nr, NULL, NULL));
  double sum = 0.0;
  for (int64_t q = 0; q < rp[nr]; ++q) sum += val[q];
  if (fabs(sum - 3.0) > 1e-12) fail_msg("graded cloud: MLS mass sum %.15f, area 3", sum);
  mfree_matrix_destroy(&K);
  mfree_assembler_destroy(&as);
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
}

static void lin_u(void *u, const double *x, double *v) {
  (void)u;
  v[0] = 0.01 + 0.02 * x[0] - 0.015 * x[1];
  v[1] = -0.01 + 0.005 * x[0] + 0.03 * x[1];
}

/* Boundary Gauss points (2 per segment, 4 segments per node interval) with normals. */
static int boundary_points(double *bx, double *bw, double *bn) {
  const double g[2] = {-0.5773502691896257, 0.5773502691896257};
  int nb = 0;
  for (int e = 0; e < 4; ++e)
    for (int c = 0; c < 4 * (M - 1); ++c)
      for (int q = 0; q < 2; ++q) {
        const double t = (c + 0.5 + 0.5 * g[q]) / (4 * (M - 1));
        const double px[4] = {t, 1, t, 0}, py[4] = {0, t, 1, t}, nx[4] = {0, 1, 0, -1}, ny[4] = {-1, 0, 1, 0};
        bx[2 * nb] = px[e];
        bx[2 * nb + 1] = py[e];
        bn[2 * nb] = nx[e];
        bn[2 * nb + 1] = ny[e];
        bw[nb] = 0.5 / (4 * (M - 1));
        ++nb;
      }
  return nb;
}

/* Elasticity patch test with EFG (MLS, background cells) and Nitsche: the error in a
 * linear displacement field falls as the background quadrature order rises
 * (Nitsche is consistent, so only quadrature error remains) and the matrix is
 * symmetric (Bubnov). */
static void test_efg_patch_nitsche(void **s) {
  (void)s;
  mfree_particles_t *ps = cloud(1.6);
  static double bx[2 * 1024], bw[1024], bn[2 * 1024];
  const int nb = boundary_points(bx, bw, bn);
  const int orders[4] = {2, 3, 5, 8};
  double errs[4];
  for (int t = 0; t < 4; ++t) {
    mfree_approximant_t *a = NULL;
    assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, &a));
    mfree_assembler_t *as = NULL;
    assert_ok(ctx, mfree_assembler_create(ctx, a, NULL, MFREE_FORM_ELASTICITY_PLANE_STRESS, &as));
    assert_ok(ctx, mfree_assembler_set_material(as, 1000.0, 0.3));
    const double lo[2] = {0, 0}, hi[2] = {1, 1};
    const int32_t nc[2] = {M - 1, M - 1};
    assert_ok(ctx, mfree_assembler_set_quadrature_cells(as, lo, hi, nc, orders[t], NULL, NULL));
    assert_ok(ctx, mfree_assembler_add_dirichlet(as, MFREE_BC_NITSCHE, nb, bx, MFREE_LAYOUT_AOS, 2, bw, bn, 3,
                                                 lin_u, NULL));
    assert_ok(ctx, mfree_assembler_setup(as));
    mfree_matrix_t *K = NULL;
    assert_ok(ctx, mfree_assembler_assemble_matrix(as, &K));
    int32_t sym = 0;
    assert_ok(ctx, mfree_matrix_get_symmetric(K, &sym));
    assert_int_equal(sym, 1);
    int32_t n = 0;
    double *A = dense(K, &n);
    double *f = calloc((size_t)n, sizeof(double));
    assert_ok(ctx, mfree_assembler_assemble_rhs(as, f));
    solve(n, A, f);
    /* u^h at the particles */
    assert_ok(ctx, mfree_approximant_setup(a));
    double uh[2 * N];
    assert_ok(ctx, mfree_approximant_apply(a, MFREE_OP_VALUE, 2, f, MFREE_LAYOUT_AOS, 2, uh, MFREE_LAYOUT_AOS, 2));
    double err = 0.0;
    for (int i = 0; i < N; ++i) {
      double u[2];
      lin_u(NULL, &X[2 * i], u);
      err = fmax(err, fmax(fabs(uh[2 * i] - u[0]), fabs(uh[2 * i + 1] - u[1])) / 0.05);
    }
    errs[t] = err;
    free(A);
    free(f);
    mfree_matrix_destroy(&K);
    mfree_assembler_destroy(&as);
    mfree_approximant_destroy(&a);
  }
  for (int t = 1; t < 4; ++t)
    if (!(errs[t] < errs[t - 1])) fail_msg("EFG patch error did not fall: %g -> %g", errs[t - 1], errs[t]);
  assert_true(errs[3] < 1e-3 * errs[0] || errs[3] < 1e-4);
  mfree_particles_destroy(&ps);
}


static void lin_scalar(void *u, const double *x, double *v) {
  (void)u;
  v[0] = 1.0 + 2.0 * x[0] + 3.0 * x[1];
}

/* The finite-element blending layer of paper 000 eqs 100-105 (one column of bilinear
 * elements along x = 0, u imposed on its boundary nodes): blended functions keep linear
 * completeness, so a Laplace patch test with EFG quadrature converges as the quadrature
 * order rises, and the boundary nodes carry the prescribed values exactly. Nitsche on
 * the other three edges. Regular lattice (the layer is a structured column). */
static void test_fe_layer_patch(void **s) {
  (void)s;
  static double xl[2 * N];
  for (int j = 0; j < M; ++j)
    for (int i = 0; i < M; ++i) {
      xl[2 * (j * M + i)] = (double)i / (M - 1);
      xl[2 * (j * M + i) + 1] = (double)j / (M - 1);
    }
  const double h = 1.6 / (M - 1), v = 1.0 / ((M - 1) * (M - 1));
  mfree_particles_t *ps = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, 2, N, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, xl, MFREE_LAYOUT_AOS, 2, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_volumes(ps, &v, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_setup(ps));
  int32_t conn[4 * (M - 1)], gu[M];
  for (int j = 0; j < M - 1; ++j) {
    conn[4 * j] = j * M;
    conn[4 * j + 1] = j * M + 1;
    conn[4 * j + 2] = (j + 1) * M + 1;
    conn[4 * j + 3] = (j + 1) * M;
  }
  for (int j = 0; j < M; ++j) gu[j] = j * M;
  static double bx[2 * 1024], bw[1024], bn[2 * 1024];
  const int nb4 = boundary_points(bx, bw, bn), nb = 3 * nb4 / 4; /* edges y=0, x=1, y=1 */
  const int orders[3] = {2, 3, 5};
  double errs[3];
  for (int t = 0; t < 3; ++t) {
    mfree_approximant_t *a = NULL;
    assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, &a));
    mfree_assembler_t *as = NULL;
    assert_ok(ctx, mfree_assembler_create(ctx, a, NULL, MFREE_FORM_LAPLACE, &as));
    const double lo[2] = {0, 0}, hi[2] = {1, 1};
    const int32_t nc[2] = {M - 1, M - 1};
    assert_ok(ctx, mfree_assembler_set_quadrature_cells(as, lo, hi, nc, orders[t], NULL, NULL));
    assert_ok(ctx, mfree_assembler_set_fe_layer(as, M - 1, 4, conn, M, gu, 1, lin_scalar, NULL));
    assert_ok(ctx, mfree_assembler_add_dirichlet(as, MFREE_BC_NITSCHE, nb, bx, MFREE_LAYOUT_AOS, 2, bw, bn, 1,
                                                 lin_scalar, NULL));
    assert_ok(ctx, mfree_assembler_setup(as));
    mfree_matrix_t *K = NULL;
    assert_ok(ctx, mfree_assembler_assemble_matrix(as, &K));
    int32_t n = 0;
    double *A = dense(K, &n);
    double *f = calloc((size_t)n, sizeof(double));
    assert_ok(ctx, mfree_assembler_assemble_rhs(as, f));
    solve(n, A, f);
    assert_ok(ctx, mfree_approximant_setup(a));
    double uh[N];
    assert_ok(ctx, mfree_approximant_apply(a, MFREE_OP_VALUE, 1, f, MFREE_LAYOUT_AOS, 1, uh, MFREE_LAYOUT_AOS, 1));
    double err = 0.0;
    for (int i = 0; i < N; ++i) {
      double u;
      lin_scalar(NULL, &xl[2 * i], &u);
      if (i % M == 0) assert_true(fabs(f[i] - u) < 1e-12); /* imposed on the layer's boundary nodes */
      else err = fmax(err, fabs(uh[i] - u));                /* meshfree nodes: u^h by MLS */
    }
    errs[t] = err;
    free(A);
    free(f);
    mfree_matrix_destroy(&K);
    mfree_assembler_destroy(&as);
    mfree_approximant_destroy(&a);
  }
  assert_true(errs[1] < errs[0] && errs[2] < errs[1]);
  assert_true(errs[2] < 1e-4);
  /* bad layers */
  mfree_approximant_t *a = NULL;
  mfree_assembler_t *as = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, &a));
  assert_ok(ctx, mfree_assembler_create(ctx, a, NULL, MFREE_FORM_LAPLACE, &as));
  int32_t bad[4] = {0, M, M + 1, 1}; /* clockwise: inverted */
  assert_error(ctx, mfree_assembler_set_fe_layer(as, 1, 4, bad, 1, gu, 1, lin_scalar, NULL), MFREE_ERR_INPUT,
               "inverted");
  int32_t far[4] = {0, 1, M + 1, N + 5};
  assert_error(ctx, mfree_assembler_set_fe_layer(as, 1, 4, far, 1, gu, 1, lin_scalar, NULL), MFREE_ERR_INPUT,
               "not an owned particle");
  const int32_t notlayer = N - 1;
  assert_error(ctx, mfree_assembler_set_fe_layer(as, 1, 4, conn, 1, &notlayer, 1, lin_scalar, NULL),
               MFREE_ERR_INPUT, "not a layer node");
  assert_error(ctx, mfree_assembler_set_fe_layer(as, 1, 5, conn, 1, gu, 1, lin_scalar, NULL), MFREE_ERR_ARG,
               "3 (triangle) or 4");
  mfree_assembler_destroy(&as);
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
}


/* Particles moved a little (same neighbours): update refills the values into the same
 * matrix, its pattern (pattern id) is kept, and the values equal a fresh assembly on the
 * moved particles (symbolic and numeric parts are separate). */
static void test_refill_after_move(void **s) {
  (void)s;
  mfree_particles_t *ps = cloud(1.6); /* borrows X */
  mfree_approximant_t *a = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, &a));
  mfree_assembler_t *as = NULL;
  assert_ok(ctx, mfree_assembler_create(ctx, a, NULL, MFREE_FORM_ELASTICITY_PLANE_STRAIN, &as));
  assert_ok(ctx, mfree_assembler_set_material(as, 10.0, 0.3));
  assert_ok(ctx, mfree_assembler_setup(as));
  mfree_matrix_t *K = NULL;
  assert_ok(ctx, mfree_assembler_assemble_matrix(as, &K));
  int64_t id0 = -1, id1 = -1, nnz0 = 0, nnz1 = 0;
  assert_ok(ctx, mfree_matrix_get_pattern_id(K, &id0));
  assert_ok(ctx, mfree_matrix_get_size(K, NULL, NULL, &nnz0));
  const int64_t *rp;
  const int32_t *ci;
  const double *v;
  assert_ok(ctx, mfree_matrix_get_csr(K, &rp, &ci, &v));
  double *before = malloc(sizeof(double) * (size_t)nnz0);
  memcpy(before, v, sizeof(double) * (size_t)nnz0);

  for (int i = 0; i < N; ++i) X[2 * i] += 1e-3 / (M - 1) * sin(7.0 * i); /* small move */
  assert_ok(ctx, mfree_particles_update(ps));
  assert_ok(ctx, mfree_assembler_update(as));
  assert_ok(ctx, mfree_assembler_assemble_matrix(as, &K));
  assert_ok(ctx, mfree_matrix_get_pattern_id(K, &id1));
  assert_ok(ctx, mfree_matrix_get_size(K, NULL, NULL, &nnz1));
  assert_true(id1 == id0);
  assert_true(nnz1 == nnz0);
  assert_ok(ctx, mfree_matrix_get_csr(K, &rp, &ci, &v));
  double change = 0.0, scale = 0.0;
  for (int64_t k = 0; k < nnz0; ++k) {
    change = fmax(change, fabs(v[k] - before[k]));
    scale = fmax(scale, fabs(before[k]));
  }
  assert_true(change > 1e-8 * scale); /* the values did change */

  /* a fresh assembler on the moved particles gives the same matrix */
  mfree_assembler_t *fresh = NULL;
  mfree_matrix_t *K2 = NULL;
  assert_ok(ctx, mfree_particles_setup(ps));
  assert_ok(ctx, mfree_assembler_create(ctx, a, NULL, MFREE_FORM_ELASTICITY_PLANE_STRAIN, &fresh));
  assert_ok(ctx, mfree_assembler_set_material(fresh, 10.0, 0.3));
  assert_ok(ctx, mfree_assembler_setup(fresh));
  assert_ok(ctx, mfree_assembler_assemble_matrix(fresh, &K2));
  const int64_t *rp2;
  const int32_t *ci2;
  const double *v2;
  int64_t nnz2 = 0;
  assert_ok(ctx, mfree_matrix_get_size(K2, NULL, NULL, &nnz2));
  assert_true(nnz2 == nnz0);
  assert_ok(ctx, mfree_matrix_get_csr(K2, &rp2, &ci2, &v2));
  for (int64_t k = 0; k < nnz0; ++k) {
    assert_int_equal(ci2[k], ci[k]);
    assert_true(fabs(v2[k] - v[k]) <= 1e-12 * scale);
  }
  free(before);
  mfree_matrix_destroy(&K);
  mfree_matrix_destroy(&K2);
  mfree_assembler_destroy(&as);
  mfree_assembler_destroy(&fresh);
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
}

static void g_zero(void *u, const double *x, double *v) {
  (void)u;
  (void)x;
  v[0] = v[1] = 0.0;
}

static void lin_scalar2(void *u, const double *x, double *v) {
  (void)u;
  v[0] = 0.3 + 1.5 * x[0] - 0.7 * x[1];
}

/* Dirichlet rows for particles-only methods (symmetrised SPH, Johnson-Beissel,
 * Randles-Libersky) impose u_J = g(x_J) on the particle value itself: the replaced rows
 * are identity rows with g on the right-hand side (for the other methods they hold the
 * trial values at the node). */
static void test_particles_only_dirichlet(void **s) {
  (void)s;
  mfree_particles_t *ps = cloud(1.6);
  const mfree_method_t methods[3] = {MFREE_METHOD_SPH_SYMMETRIC, MFREE_METHOD_JOHNSON_BEISSEL,
                                     MFREE_METHOD_RANDLES_LIBERSKY};
  for (int m = 0; m < 3; ++m) {
    mfree_approximant_t *a = NULL;
    assert_ok(ctx, mfree_approximant_create(ctx, ps, methods[m], &a));
    mfree_assembler_t *as = NULL;
    assert_ok(ctx, mfree_assembler_create(ctx, a, NULL, MFREE_FORM_LAPLACE, &as));
    assert_ok(ctx, mfree_assembler_set_quadrature_nodal(as));
    assert_ok(ctx, mfree_assembler_add_dirichlet_nodes(as, NB, BND, 1, lin_scalar2, NULL));
    assert_ok(ctx, mfree_assembler_setup(as));
    mfree_matrix_t *K = NULL;
    assert_ok(ctx, mfree_assembler_assemble_matrix(as, &K));
    double f[N];
    assert_ok(ctx, mfree_assembler_assemble_rhs(as, f));
    const int64_t *rp;
    const int32_t *ci;
    const double *v;
    assert_ok(ctx, mfree_matrix_get_csr(K, &rp, &ci, &v));
    for (int b = 0; b < NB; ++b) {
      const int32_t J = BND[b];
      for (int64_t k = rp[J]; k < rp[J + 1]; ++k)
        if (v[k] != (ci[k] == J ? 1.0 : 0.0))
          fail_msg("method %d: row %d has %g in column %d", (int)methods[m], (int)J, v[k], (int)ci[k]);
      double g;
      lin_scalar2(NULL, X + 2 * J, &g);
      assert_true(f[J] == g);
    }
    mfree_matrix_destroy(&K);
    mfree_assembler_destroy(&as);
    mfree_approximant_destroy(&a);
  }
  mfree_particles_destroy(&ps);
}

static void test_bad_input(void **s) {
  (void)s;
  mfree_particles_t *ps = cloud(1.6), *other = cloud(1.6);
  mfree_approximant_t *a = NULL, *b = NULL, *c = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, &a));
  assert_ok(ctx, mfree_approximant_create(ctx, other, MFREE_METHOD_SHEPARD, &b));
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_RANDLES_LIBERSKY, &c));
  mfree_assembler_t *as = NULL;
  assert_int_equal(mfree_assembler_create(NULL, a, NULL, MFREE_FORM_LAPLACE, &as), MFREE_ERR_NULL);
  assert_error(ctx, mfree_assembler_create(ctx, NULL, NULL, MFREE_FORM_LAPLACE, &as), MFREE_ERR_NULL, "trial");
  assert_error(ctx, mfree_assembler_create(ctx, a, b, MFREE_FORM_LAPLACE, &as), MFREE_ERR_MISMATCH,
               "different particle sets");
  assert_error(ctx, mfree_assembler_create(ctx, a, NULL, (mfree_form_t)0, &as), MFREE_ERR_ARG, "unknown form");
  assert_error(ctx, mfree_assembler_create(ctx, a, NULL, MFREE_FORM_ELASTICITY_3D, &as), MFREE_ERR_MISMATCH, "3D");
  assert_null(as);
  assert_ok(ctx, mfree_assembler_create(ctx, a, NULL, MFREE_FORM_ELASTICITY_PLANE_STRESS, &as));
  assert_error(ctx, mfree_assembler_set_material(as, -1.0, 0.3), MFREE_ERR_ARG, "E > 0");
  assert_error(ctx, mfree_assembler_set_material(as, 1.0, 0.5), MFREE_ERR_ARG, "nu");
  assert_error(ctx, mfree_assembler_set_coefficient(as, NAN), MFREE_ERR_ARG, "coefficient");
  double qx[4] = {0.5, 0.5, 0.2, 0.2}, qw[2] = {0.1, -0.1};
  assert_error(ctx, mfree_assembler_set_quadrature_points(as, 2, qx, MFREE_LAYOUT_AOS, 2, qw), MFREE_ERR_INPUT,
               "weight 1");
  qw[1] = NAN;
  assert_error(ctx, mfree_assembler_set_quadrature_points(as, 2, qx, MFREE_LAYOUT_AOS, 2, qw), MFREE_ERR_INPUT,
               "weight 1");
  qx[0] = INFINITY;
  qw[1] = 0.1;
  assert_error(ctx, mfree_assembler_set_quadrature_points(as, 2, qx, MFREE_LAYOUT_AOS, 2, qw), MFREE_ERR_INPUT,
               "not finite");
  const double seg[8] = {0, 0, 1, 0, 0.5, 0.5, 0.5, 0.5};
  assert_error(ctx, mfree_assembler_add_traction_segments(as, 2, seg, 2, g_zero, NULL), MFREE_ERR_INPUT,
               "segment 1 has zero length");
  assert_error(ctx, mfree_assembler_add_traction_segments(as, 1, seg, 0, g_zero, NULL), MFREE_ERR_ARG, "ngauss");
  const double bp[2] = {0.0, 0.5}, bw = 0.1, bad_n[2] = {2.0, 0.0};
  assert_error(ctx, mfree_assembler_add_dirichlet(as, MFREE_BC_NITSCHE, 1, bp, MFREE_LAYOUT_AOS, 2, &bw, NULL, 3,
                                                  g_zero, NULL),
               MFREE_ERR_NULL, "normals");
  assert_error(ctx, mfree_assembler_add_dirichlet(as, MFREE_BC_NITSCHE, 1, bp, MFREE_LAYOUT_AOS, 2, &bw, bad_n, 3,
                                                  g_zero, NULL),
               MFREE_ERR_INPUT, "unit vector");
  assert_error(ctx, mfree_assembler_add_dirichlet(as, MFREE_BC_PENALTY, 1, bp, MFREE_LAYOUT_AOS, 2, &bw, NULL, 4,
                                                  g_zero, NULL),
               MFREE_ERR_ARG, "mask");
  assert_error(ctx, mfree_assembler_add_dirichlet(as, MFREE_BC_COLLOCATION, 1, bp, MFREE_LAYOUT_AOS, 2, &bw, NULL,
                                                  3, g_zero, NULL),
               MFREE_ERR_ARG, "add_dirichlet_nodes");
  const int32_t badnode = N + 3;
  assert_error(ctx, mfree_assembler_add_dirichlet_nodes(as, 1, &badnode, 1, g_zero, NULL), MFREE_ERR_INPUT,
               "not an owned particle");
  const int32_t node0 = 0;
  const double nrm[2] = {1, 0};
  assert_error(ctx, mfree_assembler_add_traction_nodes(as, 1, &node0, nrm, g_zero, NULL), MFREE_ERR_UNSUPPORTED,
               "collocation");
  int32_t nd;
  mfree_matrix_t *K = NULL;
  double f[1];
  assert_error(ctx, mfree_assembler_get_size(as, &nd, NULL), MFREE_ERR_STATE, "not set up");
  assert_error(ctx, mfree_assembler_assemble_matrix(as, &K), MFREE_ERR_STATE, "not set up");
  assert_error(ctx, mfree_assembler_assemble_rhs(as, f), MFREE_ERR_STATE, "not set up");
  assert_error(ctx, mfree_assembler_update(as), MFREE_ERR_STATE, "before setup");
  /* quadrature points outside every support: a positive status, not a silent zero row */
  const double far[4] = {5.0, 5.0, 0.5, 0.5}, fw[2] = {1.0, 1.0};
  assert_ok(ctx, mfree_assembler_set_quadrature_points(as, 2, far, MFREE_LAYOUT_AOS, 2, fw));
  assert_error(ctx, mfree_assembler_setup(as), MFREE_FAIL_NEIGHBORS, "quadrature point");
  /* every point inside some support, but particles far from them are seen by none: their
   * rows would be zero (a singular matrix); reported with the particle */
  const double near[2] = {0.05, 0.05}, nw[1] = {1.0};
  assert_ok(ctx, mfree_assembler_set_quadrature_points(as, 1, near, MFREE_LAYOUT_AOS, 2, nw));
  assert_error(ctx, mfree_assembler_setup(as), MFREE_FAIL_NEIGHBORS, "seen by no quadrature point");
  /* nodal quadrature again: a clean setup after the failures */
  assert_ok(ctx, mfree_assembler_set_quadrature_nodal(as));
  assert_ok(ctx, mfree_assembler_setup(as));
  assert_ok(ctx, mfree_assembler_assemble_matrix(as, &K));
  assert_int_equal(mfree_assembler_assemble_matrix(NULL, &K), MFREE_ERR_NULL);
  mfree_matrix_destroy(&K);
  mfree_assembler_destroy(&as);
  /* particles-only methods refuse background quadrature */
  assert_ok(ctx, mfree_assembler_create(ctx, c, NULL, MFREE_FORM_LAPLACE, &as));
  const double lo[2] = {0, 0}, hi[2] = {1, 1};
  const int32_t ncell[2] = {4, 4};
  assert_ok(ctx, mfree_assembler_set_quadrature_cells(as, lo, hi, ncell, 2, NULL, NULL));
  assert_error(ctx, mfree_assembler_setup(as), MFREE_ERR_UNSUPPORTED, "nodal quadrature");
  mfree_assembler_destroy(&as);
  mfree_assembler_destroy(&as);
  mfree_approximant_destroy(&a);
  mfree_approximant_destroy(&b);
  mfree_approximant_destroy(&c);
  mfree_particles_destroy(&ps);
  mfree_particles_destroy(&other);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_collocation_exact),
      cmocka_unit_test(test_mass_sums),
      cmocka_unit_test(test_graded_supports),
      cmocka_unit_test(test_efg_patch_nitsche),
      cmocka_unit_test(test_fe_layer_patch),
      cmocka_unit_test(test_refill_after_move),
      cmocka_unit_test(test_particles_only_dirichlet),
      cmocka_unit_test(test_bad_input),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
