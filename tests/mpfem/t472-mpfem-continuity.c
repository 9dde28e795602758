/* MPFEM continuity (paper 004 Sects. 2.6, 2.7, 4.2; docs/papers.md, paper 004, derived
 * results 4). A field u^h = sum_J N_J u_J with random nodal values on a non-uniform
 * 1D mesh is probed on both sides of the points where smoothness could break: the
 * nodes (element boundaries) and the points where the support edge crosses a node
 * (node +- R h). A quantity f is continuous at p when the one-sided jump
 * |f(p + eps) - f(p - eps)| is O(eps): with eps = 1e-7 and derivatives that grow like
 * 1/h^k, "continuous" means a jump below 1e-3 of max |f| over the probes (expected
 * about 1e-5), "discontinuous" a jump above 1e-2 of it.
 *  - cosine kernel (C0): value and eq 21 derivative continuous, second derivative not;
 *  - cos^2 kernel (C1, zero slope at the edge, eq 36): second derivative continuous;
 *  - Haar kernel: the eq 21 derivative jumps, the eq 22 derivative does not.
 * In 2D, the eq 21 gradient with the cosine kernel is continuous across element edges
 * of QUAD4 and TRI3 meshes. */
#include <math.h>
#include <stdlib.h>

#include "mpfem_util.h"

#define EPS 1e-7
#define SMALL 1e-3
#define LARGE 1e-2

static mfree_context_t *ctx;

static int setup(void **state) {
  (void)state;
  assert_ok(NULL, mfree_context_create(&ctx));
  return 0;
}
static int teardown(void **state) {
  (void)state;
  mfree_context_destroy(&ctx);
  return 0;
}

enum { NN = 16 };
static double xn[NN], un[NN];

static void make_mesh(void) {
  mfree_rng_t r;
  mfree_rng_seed(&r, 41);
  xn[0] = 0.0;
  for (int i = 1; i < NN; ++i) xn[i] = xn[i - 1] + 0.1 * (1.0 + 0.4 * (2 * mfree_rng_uniform(&r) - 1));
  for (int i = 0; i < NN; ++i) un[i] = 2.0 * mfree_rng_uniform(&r) - 1.0;
}

/* Jumps of value, first and second derivative at the probe points p (both sides),
 * relative to the largest magnitude of each over the probes. */
static void jumps(mfree_kernel_t k, mfree_mpfem_deriv_t deriv, double h, int np, const double *p,
                  double *jv, double *jg, double *jh) {
  int32_t conn[2 * NN];
  mp_line_conn(NN, conn);
  mfree_particles_t *ps = mp_particles(ctx, 1, NN, xn, h);
  mfree_mesh_t *m = mp_mesh(ctx, ps, MFREE_ELEMENT_LINE2, NN - 1, conn);
  double *pts = malloc(sizeof(double) * 2 * (size_t)np);
  for (int i = 0; i < np; ++i) {
    pts[2 * i] = p[i] - EPS;
    pts[2 * i + 1] = p[i] + EPS;
  }
  const int hess = !(k == MFREE_KERNEL_HAAR && deriv == MFREE_MPFEM_DERIV_FULL);
  const int32_t flags = MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT | (hess ? MFREE_DERIV_HESSIAN : 0);
  mfree_status_t st;
  mfree_approximant_t *a = mp_approx(ctx, ps, m, k, deriv, flags, 2 * np, pts, h, &st);
  double *v = malloc(sizeof(double) * 2 * (size_t)np), *g = malloc(sizeof(double) * 2 * (size_t)np),
         *hh = malloc(sizeof(double) * 2 * (size_t)np);
  assert_ok(ctx, mfree_approximant_apply(a, MFREE_OP_VALUE, 1, un, MFREE_LAYOUT_AOS, 1, v, MFREE_LAYOUT_AOS, 1));
  assert_ok(ctx, mfree_approximant_apply(a, MFREE_OP_GRADIENT, 1, un, MFREE_LAYOUT_AOS, 1, g, MFREE_LAYOUT_AOS, 1));
  if (hess)
    assert_ok(ctx, mfree_approximant_apply(a, MFREE_OP_HESSIAN, 1, un, MFREE_LAYOUT_AOS, 1, hh, MFREE_LAYOUT_AOS, 1));
  double sv = 0, sg = 0, sh = 0; /* scales: max |f| over the probes */
  for (int i = 0; i < 2 * np; ++i) {
    sv = fmax(sv, fabs(v[i]));
    sg = fmax(sg, fabs(g[i]));
    if (hess) sh = fmax(sh, fabs(hh[i]));
  }
  for (int i = 0; i < np; ++i) {
    jv[i] = fabs(v[2 * i + 1] - v[2 * i]) / sv;
    jg[i] = fabs(g[2 * i + 1] - g[2 * i]) / sg;
    jh[i] = hess ? fabs(hh[2 * i + 1] - hh[2 * i]) / sh : 0.0;
  }
  free(v);
  free(g);
  free(hh);
  free(pts);
  mfree_approximant_destroy(&a);
  mfree_mesh_destroy(&m);
  mfree_particles_destroy(&ps);
}

/* Probe points: interior nodes, and interior nodes +- h (support edge on a node). */
static int probes(double h, double *p) {
  int n = 0;
  for (int i = 2; i < NN - 2; ++i) {
    p[n++] = xn[i];
    p[n++] = xn[i] - h;
    p[n++] = xn[i] + h;
  }
  return n;
}

static void test_cosine(void **state) {
  (void)state;
  make_mesh();
  const double h = 0.06; /* below the shortest element, so eq 13 holds */
  double p[64], jv[64], jg[64], jh[64];
  const int np = probes(h, p);
  jumps(MFREE_KERNEL_COSINE, MFREE_MPFEM_DERIV_FULL, h, np, p, jv, jg, jh);
  double mv = 0, mg = 0, minh = INFINITY;
  for (int i = 0; i < np; ++i) {
    mv = fmax(mv, jv[i]);
    mg = fmax(mg, jg[i]);
    /* the second derivative jumps where the support edge crosses a node (g' jumps at
     * the edge of the C0 kernel); at the nodes themselves the kernel is smooth */
    if (i % 3 != 0) minh = fmin(minh, jh[i]);
  }
  print_message("cosine: relative jumps: value %.2e, eq-21 derivative %.2e, second derivative at "
                "node +- h at least %.2e\n", mv, mg, minh);
  assert_true(mv < SMALL);
  assert_true(mg < SMALL);   /* C1 (004 Sect. 2.6) */
  assert_true(minh > LARGE); /* second derivative C^-1 (004 Sect. 2.7) */
}

static void test_cosine_squared(void **state) {
  (void)state;
  make_mesh();
  const double h = 0.06;
  double p[64], jv[64], jg[64], jh[64], jc[64];
  const int np = probes(h, p);
  jumps(MFREE_KERNEL_COSINE_SQUARED, MFREE_MPFEM_DERIV_FULL, h, np, p, jv, jg, jh);
  double mh = 0;
  for (int i = 0; i < np; ++i) mh = fmax(mh, jh[i]);
  /* the same probes with the cosine kernel: its second-derivative jumps are O(10^1..3) */
  jumps(MFREE_KERNEL_COSINE, MFREE_MPFEM_DERIV_FULL, h, np, p, jv, jg, jc);
  double mc = 0;
  for (int i = 0; i < np; ++i) mc = fmax(mc, jc[i]);
  print_message("cos^2: relative second-derivative jump %.2e (cosine kernel: %.2e)\n", mh, mc);
  assert_true(mh < SMALL); /* C2 with a C1 kernel satisfying eq 36 (004 Sect. 4.2) */
  assert_true(mc > 100 * mh);
}

static void test_haar(void **state) {
  (void)state;
  make_mesh();
  const double h = 0.06;
  double p[64], jv[64], jg21[64], jg22[64], jh[64];
  const int np = probes(h, p);
  jumps(MFREE_KERNEL_HAAR, MFREE_MPFEM_DERIV_FULL, h, np, p, jv, jg21, jh);
  double mv = 0, m21 = 0, m22 = 0;
  for (int i = 0; i < np; ++i) {
    mv = fmax(mv, jv[i]);
    m21 = fmax(m21, jg21[i]);
  }
  jumps(MFREE_KERNEL_HAAR, MFREE_MPFEM_DERIV_ASSUMED_STRAIN, h, np, p, jv, jg22, jh);
  for (int i = 0; i < np; ++i) m22 = fmax(m22, jg22[i]);
  print_message("Haar: relative jumps: value %.2e, eq 21 derivative %.2e, eq 22 derivative %.2e\n", mv,
                m21, m22);
  assert_true(mv < SMALL);   /* C0 */
  assert_true(m21 > LARGE);  /* eq 21 derivative discontinuous (docs/papers.md) */
  assert_true(m22 < SMALL);  /* eq 22 continuous for any L2 kernel (004 Sect. 2.7) */
}

/* 2D: gradient (eq 21, cosine kernel) on both sides of interior element edges. */
static void test_edges_2d(void **state) {
  (void)state;
  enum { NX = 4, NY = 3, N2 = (NX + 1) * (NY + 1), NP = 40 };
  double x2[2 * N2], u2[N2];
  int32_t cq[4 * NX * NY], ct[6 * NX * NY];
  mfree_rng_t r;
  mfree_rng_seed(&r, 43);
  for (int j = 0; j <= NY; ++j)
    for (int i = 0; i <= NX; ++i) {
      double *p = &x2[2 * (j * (NX + 1) + i)];
      p[0] = i + ((i > 0 && i < NX) ? 0.15 * (2 * mfree_rng_uniform(&r) - 1) : 0.0);
      p[1] = j + ((j > 0 && j < NY) ? 0.15 * (2 * mfree_rng_uniform(&r) - 1) : 0.0);
    }
  for (int i = 0; i < N2; ++i) u2[i] = 2 * mfree_rng_uniform(&r) - 1;
  mp_grid_quads(NX, NY, cq);
  mp_grid_tris(NX, NY, ct);
  for (int type = 0; type < 2; ++type) {
    /* probe points on interior edges (x_a + t (x_b - x_a)), offset +-eps along the normal */
    double pts[4 * NP];
    int np = 0;
    const int ne = type == 0 ? NX * NY : 2 * NX * NY, nv = type == 0 ? 4 : 3;
    const int32_t *c = type == 0 ? cq : ct;
    for (int e = 0; e < ne && np < NP; ++e)
      for (int k = 0; k < nv && np < NP; ++k) {
        const double *a = &x2[2 * c[nv * e + k]], *b = &x2[2 * c[nv * e + (k + 1) % nv]];
        const double mx = 0.5 * (a[0] + b[0]) + 0.1 * (b[0] - a[0]), my = 0.5 * (a[1] + b[1]) + 0.1 * (b[1] - a[1]);
        if (mx <= 0.2 || my <= 0.2 || mx >= NX - 0.2 || my >= NY - 0.2) continue; /* interior edges only */
        const double L = hypot(b[0] - a[0], b[1] - a[1]), nx = (b[1] - a[1]) / L, ny = -(b[0] - a[0]) / L;
        pts[4 * np] = mx - EPS * nx;
        pts[4 * np + 1] = my - EPS * ny;
        pts[4 * np + 2] = mx + EPS * nx;
        pts[4 * np + 3] = my + EPS * ny;
        ++np;
      }
    mfree_particles_t *ps = mp_particles(ctx, 2, N2, x2, 0.3);
    mfree_mesh_t *m = type == 0 ? mp_mesh(ctx, ps, MFREE_ELEMENT_QUAD4, ne, cq) : mp_mesh(ctx, ps, MFREE_ELEMENT_TRI3, ne, ct);
    mfree_approximant_t *a = mp_approx(ctx, ps, m, MFREE_KERNEL_COSINE, MFREE_MPFEM_DERIV_FULL,
                                       MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT, 2 * np, pts, 0.3, NULL);
    double g[4 * NP];
    assert_ok(ctx, mfree_approximant_apply(a, MFREE_OP_GRADIENT, 1, u2, MFREE_LAYOUT_AOS, 1, g, MFREE_LAYOUT_AOS, 2));
    double mj = 0.0, sg = 0.0;
    for (int i = 0; i < np; ++i) mj = fmax(mj, hypot(g[4 * i + 2] - g[4 * i], g[4 * i + 3] - g[4 * i + 1]));
    for (int i = 0; i < 2 * np; ++i) sg = fmax(sg, hypot(g[2 * i], g[2 * i + 1]));
    mj /= sg;
    print_message("%s: %d edge probes, relative gradient jump %.2e\n", type ? "TRI3" : "QUAD4", np, mj);
    assert_true(np >= 10);
    assert_true(mj < SMALL);
    mfree_approximant_destroy(&a);
    mfree_mesh_destroy(&m);
    mfree_particles_destroy(&ps);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_cosine),
      cmocka_unit_test(test_cosine_squared),
      cmocka_unit_test(test_haar),
      cmocka_unit_test(test_edges_2d),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
