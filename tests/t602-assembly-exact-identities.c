/* Assembler: exact identities of the elasticity forms, the CSC view and Lagrange
 * multipliers.
 *  - Material matrices: with Bubnov MLS of order 1 (which reproduces linear fields and
 *    their gradients to round-off at every quadrature point) and background Gauss cells
 *    whose weights sum to the volume V, the stiffness of the linear fields u_a = e_a x
 *    (e_a a unit Voigt strain) is u_a^T K u_b = V D_ab exactly, for every pair a, b:
 *    plane stress, plane strain and 3D, against the textbook D (Lame constants);
 *    rigid-body modes give K u = 0 and K is symmetric.
 *  - Quadratures: host points and weights equal to the background cells' Gauss points
 *    give the cells' matrix to round-off, also with an inside-test that drops two
 *    thirds of the cells (particles seen by no point are then reported,
 *    MFREE_FAIL_NEIGHBORS).
 *  - The CSC view (mfree_matrix_get_csc) holds the same entries as the CSR view, also
 *    after a refill on moved particles (same pattern id, new values); the 32- and
 *    64-bit CSR views share the CSR view's values (zero-copy).
 *  - Loads: tractions on segments equal the same Gauss points given as host points,
 *    and with partition-of-unity test functions the load's resultant and moment are the
 *    Gauss rule's, exact for the quadratic traction here.
 *  - MFREE_BC_PENALTY adds alpha sum_p w_p Phi_J(x_p) Phi_K(x_p) to the matrix and
 *    alpha sum_p w_p Phi_J(x_p) g(x_p) to the load (independent approximant at x_p).
 *  - MFREE_BC_LAGRANGE: the multiplier rows are the trial values Phi_J(x_p) at the
 *    points (an independent approximant evaluated there), the system is symmetric, and
 *    the solved u^h satisfies u^h(x_p) = g(x_p) at every point to round-off.
 * Small systems, solved densely; library only. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"

static mfree_context_t *ctx;
static int setup(void **s) { (void)s; return mfree_context_create(&ctx) != MFREE_SUCCESS; }
static int teardown(void **s) { (void)s; return mfree_context_destroy(&ctx) != MFREE_SUCCESS; }

static const double YOUNG = 7.0, NU = 0.3;

/* m^dim nodes on the unit square / cube, interior ones jittered by 20 % of the spacing.
 * Positions are borrowed from xs (the caller keeps them alive). */
static mfree_particles_t *cloud(int dim, int m, double hfac, double *xs, uint64_t seed) {
  mfree_rng_t r;
  mfree_rng_seed(&r, seed);
  const int n = dim == 2 ? m * m : m * m * m;
  for (int p = 0; p < n; ++p) {
    int idx[3] = {p % m, (p / m) % m, p / (m * m)}, b = 0;
    for (int d = 0; d < dim; ++d) b |= idx[d] == 0 || idx[d] == m - 1;
    for (int d = 0; d < dim; ++d)
      xs[dim * p + d] = (idx[d] + (b ? 0.0 : 0.2 * (2 * mfree_rng_uniform(&r) - 1))) / (m - 1);
  }
  static double h, v;
  h = hfac / (m - 1);
  v = pow(1.0 / (m - 1), dim);
  mfree_particles_t *ps = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, dim, n, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, xs, MFREE_LAYOUT_AOS, dim, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_volumes(ps, &v, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_setup(ps));
  return ps;
}

/* Voigt material matrix: 2D (xx, yy, gamma_xy), 3D (xx, yy, zz, gamma_yz, gamma_xz,
 * gamma_xy); engineering shear strains. */
static int material(mfree_form_t form, double D[6][6]) {
  memset(D, 0, sizeof(double) * 36);
  const double mu = YOUNG / (2 * (1 + NU));
  if (form == MFREE_FORM_ELASTICITY_PLANE_STRESS) {
    const double q = YOUNG / (1 - NU * NU);
    D[0][0] = D[1][1] = q;
    D[0][1] = D[1][0] = q * NU;
    D[2][2] = mu;
    return 3;
  }
  const double lam = YOUNG * NU / ((1 + NU) * (1 - 2 * NU));
  const int nn = form == MFREE_FORM_ELASTICITY_3D ? 3 : 2;
  for (int i = 0; i < nn; ++i)
    for (int j = 0; j < nn; ++j) D[i][j] = lam + (i == j ? 2 * mu : 0.0);
  const int nv = nn == 3 ? 6 : 3;
  for (int i = nn; i < nv; ++i) D[i][i] = mu;
  return nv;
}

/* u = grad-u-matrix G applied to x: G (dim x dim, row-major) for Voigt strain a. */
static void voigt_gradient(int dim, int a, double G[3][3]) {
  memset(G, 0, sizeof(double) * 9);
  if (a < dim) {
    G[a][a] = 1.0;
    return;
  }
  /* shear pairs: 2D a = 2 -> (0,1); 3D a = 3 -> (1,2), 4 -> (0,2), 5 -> (0,1) */
  int i = 0, j = 1;
  if (dim == 3 && a == 3) i = 1, j = 2;
  if (dim == 3 && a == 4) i = 0, j = 2;
  G[i][j] = G[j][i] = 0.5; /* engineering shear strain 1 */
}

static void spmv(const mfree_matrix_t *K, const double *x, double *y) { assert_ok(ctx, mfree_matrix_apply(K, x, y)); }

static void check_material(mfree_form_t form) {
  const int dim = form == MFREE_FORM_ELASTICITY_3D ? 3 : 2, m = dim == 3 ? 5 : 8;
  const int n = dim == 2 ? m * m : m * m * m;
  double *xs = malloc(sizeof(double) * (size_t)(dim * n));
  mfree_particles_t *ps = cloud(dim, m, 1.5, xs, 5 + (uint64_t)form);
  mfree_approximant_t *a = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, &a));
  assert_ok(ctx, mfree_approximant_set_order(a, 1));
  mfree_assembler_t *as = NULL;
  assert_ok(ctx, mfree_assembler_create(ctx, a, NULL, form, &as));
  assert_ok(ctx, mfree_assembler_set_material(as, YOUNG, NU));
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  const int32_t nc[3] = {m - 1, m - 1, m - 1};
  assert_ok(ctx, mfree_assembler_set_quadrature_cells(as, lo, hi, nc, 2, NULL, NULL));
  assert_ok(ctx, mfree_assembler_setup(as));
  mfree_matrix_t *K = NULL;
  assert_ok(ctx, mfree_assembler_assemble_matrix(as, &K));
  int32_t nd = 0, sym = 0;
  assert_ok(ctx, mfree_matrix_get_size(K, &nd, NULL, NULL));
  assert_int_equal(nd, dim * n);
  assert_ok(ctx, mfree_matrix_get_symmetric(K, &sym));
  assert_int_equal(sym, 1);

  double D[6][6];
  const int nv = material(form, D);
  double *u[6], *Ku = malloc(sizeof(double) * (size_t)nd);
  for (int s = 0; s < nv; ++s) {
    double G[3][3];
    voigt_gradient(dim, s, G);
    u[s] = malloc(sizeof(double) * (size_t)nd);
    for (int p = 0; p < n; ++p)
      for (int i = 0; i < dim; ++i) {
        double v = 0.0;
        for (int j = 0; j < dim; ++j) v += G[i][j] * xs[dim * p + j];
        u[s][dim * p + i] = v;
      }
  }
  const double V = 1.0; /* the unit square / cube */
  for (int s = 0; s < nv; ++s) {
    spmv(K, u[s], Ku);
    for (int t = 0; t < nv; ++t) {
      double e = 0.0;
      for (int k = 0; k < nd; ++k) e += u[t][k] * Ku[k];
      if (fabs(e - V * D[t][s]) > 1e-11 * YOUNG) fail_msg("form %d: u_%d^T K u_%d = %.15g, V D = %.15g", (int)form, t, s, e, V * D[t][s]);
    }
  }
  /* rigid-body modes: translations and infinitesimal rotations */
  const int nr = dim == 3 ? 6 : 3;
  double kmax = 0.0;
  {
    const int64_t *rp;
    const int32_t *ci;
    const double *kv;
    assert_ok(ctx, mfree_matrix_get_csr(K, &rp, &ci, &kv));
    for (int64_t k = 0; k < rp[nd]; ++k) kmax = fmax(kmax, fabs(kv[k]));
  }
  double *r = malloc(sizeof(double) * (size_t)nd);
  for (int mode = 0; mode < nr; ++mode) {
    for (int p = 0; p < n; ++p) {
      const double *x = xs + dim * p;
      double *v = r + dim * p;
      for (int i = 0; i < dim; ++i) v[i] = mode == i ? 1.0 : 0.0;
      if (mode >= dim) {
        int i = 0, j = 1; /* rotation in the (i, j) plane */
        if (mode == 4) i = 1, j = 2;
        if (mode == 5) i = 0, j = 2;
        v[i] = -x[j];
        v[j] = x[i];
      }
    }
    spmv(K, r, Ku);
    for (int k = 0; k < nd; ++k)
      if (fabs(Ku[k]) > 1e-11 * kmax) fail_msg("form %d: rigid mode %d, (K u)_%d = %g", (int)form, mode, k, Ku[k]);
  }
  for (int s = 0; s < nv; ++s) free(u[s]);
  free(r);
  free(Ku);
  mfree_matrix_destroy(&K);
  mfree_assembler_destroy(&as);
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
  free(xs);
}

static void test_material_plane_stress(void **s) { (void)s; check_material(MFREE_FORM_ELASTICITY_PLANE_STRESS); }
static void test_material_plane_strain(void **s) { (void)s; check_material(MFREE_FORM_ELASTICITY_PLANE_STRAIN); }
static void test_material_3d(void **s) { (void)s; check_material(MFREE_FORM_ELASTICITY_3D); }

/* CSC and CSR views hold the same entries (each CSC column sorted by row). */
static void compare_views(const mfree_matrix_t *K) {
  int32_t nr, nc;
  int64_t nnz;
  assert_ok(ctx, mfree_matrix_get_size(K, &nr, &nc, &nnz));
  const int64_t *rp, *cp;
  const int32_t *ci, *ri;
  const double *v, *w;
  assert_ok(ctx, mfree_matrix_get_csr(K, &rp, &ci, &v));
  assert_ok(ctx, mfree_matrix_get_csc(K, &cp, &ri, &w));
  assert_true(cp[0] == 0 && cp[nc] == nnz);
  int64_t *pos = calloc((size_t)nc, sizeof(int64_t));
  for (int32_t j = 0; j < nc; ++j) pos[j] = cp[j];
  for (int32_t i = 0; i < nr; ++i) /* rows in order: each column's rows come sorted */
    for (int64_t k = rp[i]; k < rp[i + 1]; ++k) {
      const int32_t j = ci[k];
      assert_true(pos[j] < cp[j + 1]);
      assert_int_equal(ri[pos[j]], i);
      assert_true(w[pos[j]] == v[k]);
      ++pos[j];
    }
  for (int32_t j = 0; j < nc; ++j) assert_true(pos[j] == cp[j + 1]);
  free(pos);
}

static void test_csc_view_and_refill(void **s) {
  (void)s;
  enum { m = 7, n = m * m };
  double xs[2 * n];
  mfree_particles_t *ps = cloud(2, m, 1.6, xs, 3);
  mfree_approximant_t *trial = NULL, *test = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_KB_METHOD1, &trial));
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_SHEPARD, &test));
  mfree_assembler_t *as = NULL; /* Petrov-Galerkin: an unsymmetric matrix */
  assert_ok(ctx, mfree_assembler_create(ctx, trial, test, MFREE_FORM_ELASTICITY_PLANE_STRESS, &as));
  assert_ok(ctx, mfree_assembler_set_material(as, YOUNG, NU));
  assert_ok(ctx, mfree_assembler_setup(as));
  mfree_matrix_t *K = NULL;
  assert_ok(ctx, mfree_assembler_assemble_matrix(as, &K));
  int32_t sym = 1;
  assert_ok(ctx, mfree_matrix_get_symmetric(K, &sym));
  assert_int_equal(sym, 0);
  compare_views(K);
  int64_t id0, id1;
  assert_ok(ctx, mfree_matrix_get_pattern_id(K, &id0));
  const int64_t *cp;
  const int32_t *ri;
  const double *w;
  assert_ok(ctx, mfree_matrix_get_csc(K, &cp, &ri, &w));
  const double w0 = w[0];
  for (int i = 0; i < n; ++i) xs[2 * i + 1] += 2e-3 * cos(3.0 * i) / (m - 1); /* small move */
  assert_ok(ctx, mfree_particles_update(ps));
  assert_ok(ctx, mfree_assembler_update(as));
  assert_ok(ctx, mfree_assembler_assemble_matrix(as, &K));
  assert_ok(ctx, mfree_matrix_get_pattern_id(K, &id1));
  assert_true(id1 == id0);
  compare_views(K); /* the cached CSC follows the refill */
  { /* zero-copy: the 32- and 64-bit views share the values array of the CSR view, and
       their index arrays hold the same indices */
    int32_t nr;
    int64_t nnz;
    assert_ok(ctx, mfree_matrix_get_size(K, &nr, NULL, &nnz));
    const int64_t *rp, *rp64, *ci64;
    const int32_t *ci, *rp32, *ci32;
    const double *v, *v32, *v64;
    assert_ok(ctx, mfree_matrix_get_csr(K, &rp, &ci, &v));
    assert_ok(ctx, mfree_matrix_get_csr_i32(K, &rp32, &ci32, &v32));
    assert_ok(ctx, mfree_matrix_get_csr_i64(K, &rp64, &ci64, &v64));
    assert_ptr_equal(v32, v);
    assert_ptr_equal(v64, v);
    for (int32_t i = 0; i <= nr; ++i) assert_true(rp32[i] == rp[i] && rp64[i] == rp[i]);
    for (int64_t k = 0; k < nnz; ++k) assert_true(ci32[k] == ci[k] && ci64[k] == ci[k]);
  }
  assert_ok(ctx, mfree_matrix_get_csc(K, &cp, &ri, &w));
  assert_true(w[0] != w0);
  mfree_matrix_destroy(&K);
  mfree_assembler_destroy(&as);
  mfree_approximant_destroy(&trial);
  mfree_approximant_destroy(&test);
  mfree_particles_destroy(&ps);
}

static int32_t left_half(void *u, const double *x) {
  (void)u;
  return x[0] < 1.0 / 3.0;
}

/* K as a dense matrix (n x n). */
static double *dense_of(const mfree_matrix_t *K, int32_t n) {
  const int64_t *rp;
  const int32_t *ci;
  const double *v;
  assert_ok(ctx, mfree_matrix_get_csr(K, &rp, &ci, &v));
  double *A = calloc((size_t)n * n, sizeof(double));
  for (int32_t i = 0; i < n; ++i)
    for (int64_t k = rp[i]; k < rp[i + 1]; ++k) A[(size_t)i * n + ci[k]] = v[k];
  return A;
}

/* The three domain quadratures agree where they must: host points and weights equal to
 * the background cells' Gauss points give the same matrix to round-off, also when the
 * cells' inside-test keeps only x < 1/3 (host points filtered the same way). */
static void test_quadrature_equivalence(void **s) {
  (void)s;
  enum { m = 7, n = m * m, nc1 = m - 1, ng = 3 };
  double xs[2 * n];
  mfree_particles_t *ps = cloud(2, m, 1.6, xs, 21);
  mfree_approximant_t *a = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, &a));
  const double gp[ng] = {-sqrt(0.6), 0.0, sqrt(0.6)}, gw[ng] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
  static double qx[2 * nc1 * nc1 * ng * ng], qw[nc1 * nc1 * ng * ng];
  const double hc = 1.0 / nc1;
  for (int half = 0; half < 2; ++half) {
    int32_t nq = 0;
    for (int cj = 0; cj < nc1; ++cj)
      for (int ci = 0; ci < nc1; ++ci)
        for (int b = 0; b < ng; ++b)
          for (int c = 0; c < ng; ++c) {
            const double x = (ci + 0.5 + 0.5 * gp[c]) * hc, y = (cj + 0.5 + 0.5 * gp[b]) * hc;
            if (half && !(x < 1.0 / 3.0)) continue;
            qx[2 * nq] = x, qx[2 * nq + 1] = y;
            qw[nq++] = 0.25 * hc * hc * gw[b] * gw[c];
          }
    mfree_assembler_t *ac = NULL, *ap = NULL;
    mfree_matrix_t *Kc = NULL, *Kp = NULL;
    const double lo[2] = {0, 0}, hi[2] = {1, 1};
    const int32_t nc[2] = {nc1, nc1};
    assert_ok(ctx, mfree_assembler_create(ctx, a, NULL, MFREE_FORM_ELASTICITY_PLANE_STRESS, &ac));
    assert_ok(ctx, mfree_assembler_create(ctx, a, NULL, MFREE_FORM_ELASTICITY_PLANE_STRESS, &ap));
    assert_ok(ctx, mfree_assembler_set_material(ac, YOUNG, NU));
    assert_ok(ctx, mfree_assembler_set_material(ap, YOUNG, NU));
    assert_ok(ctx, mfree_assembler_set_quadrature_cells(ac, lo, hi, nc, ng, half ? left_half : NULL, NULL));
    assert_ok(ctx, mfree_assembler_set_quadrature_points(ap, nq, qx, MFREE_LAYOUT_AOS, 2, qw));
    /* with x > 1/3 dropped, the particles near x = 1 are seen by no point: reported */
    const mfree_status_t expect = half ? MFREE_FAIL_NEIGHBORS : MFREE_SUCCESS;
    assert_int_equal(mfree_assembler_setup(ac), expect);
    assert_int_equal(mfree_assembler_setup(ap), expect);
    int32_t nqc = 0, nqp = 0;
    assert_ok(ctx, mfree_assembler_get_size(ac, NULL, &nqc));
    assert_ok(ctx, mfree_assembler_get_size(ap, NULL, &nqp));
    assert_int_equal(nqc, nq);
    assert_int_equal(nqp, nq);
    assert_ok(ctx, mfree_assembler_assemble_matrix(ac, &Kc));
    assert_ok(ctx, mfree_assembler_assemble_matrix(ap, &Kp));
    double *A = dense_of(Kc, 2 * n), *B = dense_of(Kp, 2 * n), amax = 0.0, diff = 0.0;
    for (size_t k = 0; k < (size_t)4 * n * n; ++k) {
      amax = fmax(amax, fabs(A[k]));
      diff = fmax(diff, fabs(A[k] - B[k]));
    }
    if (!(diff <= 1e-13 * amax)) fail_msg("half %d: cells and host points differ by %g (max %g)", half, diff, amax);
    free(A), free(B);
    mfree_matrix_destroy(&Kc);
    mfree_matrix_destroy(&Kp);
    mfree_assembler_destroy(&ac);
    mfree_assembler_destroy(&ap);
  }
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
}

/* Resultant sum_J f_J and moment sum_J x_J cross f_J about the origin of nodal loads
 * (dim per node); in 2D the moment is M[2] (about z) and M[0] = M[1] = 0. */
static void resultant_moment(int dim, int n, const double *xs, const double *f, double R[3], double M[3]) {
  for (int c = 0; c < 3; ++c) R[c] = M[c] = 0.0;
  for (int J = 0; J < n; ++J) {
    const double *x = xs + dim * J, *fj = f + dim * J;
    const double X[3] = {x[0], x[1], dim == 3 ? x[2] : 0.0}, F[3] = {fj[0], fj[1], dim == 3 ? fj[2] : 0.0};
    for (int c = 0; c < 3; ++c) R[c] += F[c];
    M[0] += X[1] * F[2] - X[2] * F[1];
    M[1] += X[2] * F[0] - X[0] * F[2];
    M[2] += X[0] * F[1] - X[1] * F[0];
  }
}

static void t_quad(void *u, const double *x, double *v) {
  (void)u;
  v[0] = 1.0 + 0.5 * x[1] - 2.0 * x[1] * x[1];
  v[1] = 0.3 - x[1] * x[1];
}

static void test_traction_loads(void **s) {
  (void)s;
  enum { m = 7, n = m * m, nseg = m - 1, ng = 3 };
  double xs[2 * n];
  mfree_particles_t *ps = cloud(2, m, 1.6, xs, 13);
  mfree_approximant_t *a = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, &a));
  double seg[4 * nseg], px[2 * nseg * ng], pw[nseg * ng];
  const double gp[ng] = {-sqrt(0.6), 0.0, sqrt(0.6)}, gw[ng] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
  for (int k = 0; k < nseg; ++k) { /* the edge x = 1, bottom to top */
    const double y0 = (double)k / nseg, y1 = (double)(k + 1) / nseg;
    seg[4 * k] = 1.0, seg[4 * k + 1] = y0, seg[4 * k + 2] = 1.0, seg[4 * k + 3] = y1;
    for (int g = 0; g < ng; ++g) {
      px[2 * (ng * k + g)] = 1.0;
      px[2 * (ng * k + g) + 1] = 0.5 * (y0 + y1) + 0.5 * (y1 - y0) * gp[g];
      pw[ng * k + g] = 0.5 * (y1 - y0) * gw[g];
    }
  }
  mfree_assembler_t *as = NULL, *ap = NULL;
  assert_ok(ctx, mfree_assembler_create(ctx, a, NULL, MFREE_FORM_ELASTICITY_PLANE_STRESS, &as));
  assert_ok(ctx, mfree_assembler_create(ctx, a, NULL, MFREE_FORM_ELASTICITY_PLANE_STRESS, &ap));
  assert_ok(ctx, mfree_assembler_add_traction_segments(as, nseg, seg, ng, t_quad, NULL));
  assert_ok(ctx, mfree_assembler_add_traction(ap, nseg * ng, px, MFREE_LAYOUT_AOS, 2, pw, t_quad, NULL));
  assert_ok(ctx, mfree_assembler_setup(as));
  assert_ok(ctx, mfree_assembler_setup(ap));
  double fs[2 * n], fp[2 * n];
  assert_ok(ctx, mfree_assembler_assemble_rhs(as, fs));
  assert_ok(ctx, mfree_assembler_assemble_rhs(ap, fp));
  for (int k = 0; k < 2 * n; ++k) assert_true(fabs(fs[k] - fp[k]) <= 1e-15);
  /* resultant and moment about the origin: int t ds and int (x t_y - y t_x) ds over
   * x = 1, y in [0, 1] (MLS values sum to 1 and reproduce x, y) */
  double R[3], M[3];
  resultant_moment(2, n, xs, fs, R, M);
  const double Mz = M[2];
  const double Rx = 1.0 + 0.25 - 2.0 / 3.0, Ry = 0.3 - 1.0 / 3.0;
  const double Mexact = Ry - (0.5 + 0.5 / 3.0 - 2.0 / 4.0); /* x t_y - y t_x with x = 1 */
  if (fabs(R[0] - Rx) > 1e-13 || fabs(R[1] - Ry) > 1e-13 || fabs(Mz - Mexact) > 1e-13)
    fail_msg("resultant (%.15g, %.15g) vs (%.15g, %.15g), moment %.15g vs %.15g", R[0], R[1], Rx, Ry, Mz, Mexact);
  mfree_assembler_destroy(&as);
  mfree_assembler_destroy(&ap);
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
}

static void t_quad3(void *u, const double *x, double *v) {
  (void)u;
  v[0] = 1.0 + 0.5 * x[1] - 2.0 * x[2] * x[2];
  v[1] = 0.3 - x[1] * x[2];
  v[2] = 0.2 * x[1] * x[1] + 0.7 * x[2];
}

/* 3D facets: the face x = 1 of the unit cube as 2 k^2 triangles (diagonals alternating),
 * 3 x 3 points each (exact to degree 4). With MLS test functions (a partition of unity
 * that reproduces x, y, z) the loads' resultant and moment about the origin equal the
 * integrals of t and x cross t over the face, computed here by a 4 x 4 Gauss product
 * rule on the square (exact to degree 7 in each variable). */
static void test_traction_facets(void **s) {
  (void)s;
  enum { m = 5, n = m * m * m, k = 3, nf = 2 * k * k, ng = 3 };
  double xs[3 * n], tri[9 * nf];
  mfree_particles_t *ps = cloud(3, m, 1.8, xs, 21);
  mfree_approximant_t *a = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, &a));
  for (int i = 0, f = 0; i < k; ++i)
    for (int j = 0; j < k; ++j) {
      const double y0 = (double)i / k, y1 = (double)(i + 1) / k, z0 = (double)j / k, z1 = (double)(j + 1) / k;
      const double c[4][3] = {{1, y0, z0}, {1, y1, z0}, {1, y1, z1}, {1, y0, z1}};
      const int split = (i + j) % 2; /* diagonal 0-2 or 1-3 */
      const int t0[3] = {0, 1, split ? 2 : 3}, t1[3] = {split ? 0 : 1, 2, 3};
      for (int v = 0; v < 3; ++v)
        for (int d = 0; d < 3; ++d) tri[9 * f + 3 * v + d] = c[t0[v]][d], tri[9 * (f + 1) + 3 * v + d] = c[t1[v]][d];
      f += 2;
    }
  mfree_assembler_t *as = NULL;
  assert_ok(ctx, mfree_assembler_create(ctx, a, NULL, MFREE_FORM_ELASTICITY_3D, &as));
  assert_ok(ctx, mfree_assembler_add_traction_facets(as, nf, tri, ng, t_quad3, NULL));
  assert_ok(ctx, mfree_assembler_setup(as));
  double f[3 * n];
  assert_ok(ctx, mfree_assembler_assemble_rhs(as, f));
  double R[3], M[3];
  resultant_moment(3, n, xs, f, R, M);
  const double gp[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526};
  const double gw[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538};
  double Re[3] = {0, 0, 0}, Me[3] = {0, 0, 0};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      const double x[3] = {1.0, 0.5 * (1 + gp[i]), 0.5 * (1 + gp[j])}, w = 0.25 * gw[i] * gw[j];
      double t[3];
      t_quad3(NULL, x, t);
      for (int c = 0; c < 3; ++c) Re[c] += w * t[c];
      Me[0] += w * (x[1] * t[2] - x[2] * t[1]);
      Me[1] += w * (x[2] * t[0] - x[0] * t[2]);
      Me[2] += w * (x[0] * t[1] - x[1] * t[0]);
    }
  for (int c = 0; c < 3; ++c)
    if (fabs(R[c] - Re[c]) > 1e-12 || fabs(M[c] - Me[c]) > 1e-12)
      fail_msg("component %d: resultant %.15g vs %.15g, moment %.15g vs %.15g", c, R[c], Re[c], M[c], Me[c]);
  mfree_assembler_destroy(&as);
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
}

static void g_lin(void *u, const double *x, double *v) {
  (void)u;
  v[0] = 0.3 + 1.5 * x[0] - 0.7 * x[1] + 0.4 * x[0] * x[0];
}
static void b_const(void *u, const double *x, double *v) {
  (void)u;
  (void)x;
  v[0] = 0.8; /* -Lap g */
}

static void test_lagrange(void **s) {
  (void)s;
  enum { m = 7, n = m * m, per = 6, np = 4 * per };
  double xs[2 * n], bp[2 * np], bw[np];
  mfree_particles_t *ps = cloud(2, m, 1.6, xs, 9);
  for (int e = 0; e < 4; ++e) /* points inside each edge (corners excluded) */
    for (int k = 0; k < per; ++k) {
      const double t = (k + 0.5) / per;
      double *x = bp + 2 * (e * per + k);
      x[0] = e == 0 ? t : e == 1 ? 1.0 : e == 2 ? 1.0 - t : 0.0;
      x[1] = e == 0 ? 0.0 : e == 1 ? t : e == 2 ? 1.0 : 1.0 - t;
      bw[e * per + k] = 1.0 / per;
    }
  mfree_approximant_t *a = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, &a));
  assert_ok(ctx, mfree_approximant_set_order(a, 1));
  mfree_assembler_t *as = NULL;
  assert_ok(ctx, mfree_assembler_create(ctx, a, NULL, MFREE_FORM_LAPLACE, &as));
  const double lo[2] = {0, 0}, hi[2] = {1, 1};
  const int32_t nc[2] = {m - 1, m - 1};
  assert_ok(ctx, mfree_assembler_set_quadrature_cells(as, lo, hi, nc, 3, NULL, NULL));
  assert_ok(ctx, mfree_assembler_set_body_force(as, b_const, NULL));
  assert_ok(ctx, mfree_assembler_add_dirichlet(as, MFREE_BC_LAGRANGE, np, bp, MFREE_LAYOUT_AOS, 2, bw, NULL, 1,
                                               g_lin, NULL));
  assert_ok(ctx, mfree_assembler_setup(as));
  int32_t nd = 0;
  assert_ok(ctx, mfree_assembler_get_size(as, &nd, NULL));
  assert_int_equal(nd, n + np);
  mfree_matrix_t *K = NULL;
  assert_ok(ctx, mfree_assembler_assemble_matrix(as, &K));
  int32_t sym = 0;
  assert_ok(ctx, mfree_matrix_get_symmetric(K, &sym));
  assert_int_equal(sym, 1);

  /* the multiplier rows hold the trial values at the points (up to one sign) */
  mfree_approximant_t *ev = NULL;
  const double h = 1.6 / (m - 1);
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, &ev));
  assert_ok(ctx, mfree_approximant_set_order(ev, 1));
  assert_ok(ctx, mfree_approximant_set_points(ev, np, bp, MFREE_LAYOUT_AOS, 2, &h, 0, MFREE_BORROW));
  assert_ok(ctx, mfree_approximant_setup(ev));
  double *Phi = calloc((size_t)np * n, sizeof(double));
  {
    int64_t nnz;
    assert_ok(ctx, mfree_approximant_get_nnz(ev, &nnz));
    int64_t *rp = malloc(sizeof(int64_t) * (np + 1));
    int32_t *ci = malloc(sizeof(int32_t) * (size_t)nnz);
    double *v = malloc(sizeof(double) * (size_t)nnz);
    assert_ok(ctx, mfree_approximant_assemble_csr(ev, MFREE_DERIV_VALUE, 0, rp, ci, v));
    for (int p = 0; p < np; ++p)
      for (int64_t k = rp[p]; k < rp[p + 1]; ++k) Phi[(size_t)p * n + ci[k]] = v[k];
    free(rp), free(ci), free(v);
  }
  double *A = calloc((size_t)nd * nd, sizeof(double));
  {
    const int64_t *rp;
    const int32_t *ci;
    const double *v;
    assert_ok(ctx, mfree_matrix_get_csr(K, &rp, &ci, &v));
    for (int32_t i = 0; i < nd; ++i)
      for (int64_t k = rp[i]; k < rp[i + 1]; ++k) A[(size_t)i * nd + ci[k]] = v[k];
  }
  double sign = 0.0;
  for (int p = 0; p < np; ++p) {
    for (int J = 0; J < n; ++J) {
      const double kij = A[(size_t)(n + p) * nd + J];
      if (sign == 0.0 && fabs(Phi[(size_t)p * n + J]) > 0.1) sign = kij / Phi[(size_t)p * n + J] > 0 ? 1.0 : -1.0;
      assert_true(fabs(kij - sign * Phi[(size_t)p * n + J]) < 1e-13);
    }
    for (int q = 0; q < np; ++q) assert_true(A[(size_t)(n + p) * nd + n + q] == 0.0);
  }
  assert_true(sign != 0.0);

  /* solve densely; the constraint holds at every point */
  double *f = malloc(sizeof(double) * (size_t)nd);
  assert_ok(ctx, mfree_assembler_assemble_rhs(as, f));
  for (int k = 0; k < nd; ++k) { /* Gaussian elimination with partial pivoting */
    int piv = k;
    for (int i = k + 1; i < nd; ++i)
      if (fabs(A[(size_t)i * nd + k]) > fabs(A[(size_t)piv * nd + k])) piv = i;
    assert_true(fabs(A[(size_t)piv * nd + k]) > 1e-300);
    if (piv != k) {
      for (int j = 0; j < nd; ++j) {
        const double t = A[(size_t)k * nd + j];
        A[(size_t)k * nd + j] = A[(size_t)piv * nd + j];
        A[(size_t)piv * nd + j] = t;
      }
      const double t = f[k];
      f[k] = f[piv];
      f[piv] = t;
    }
    for (int i = k + 1; i < nd; ++i) {
      const double c = A[(size_t)i * nd + k] / A[(size_t)k * nd + k];
      if (c == 0.0) continue;
      for (int j = k; j < nd; ++j) A[(size_t)i * nd + j] -= c * A[(size_t)k * nd + j];
      f[i] -= c * f[k];
    }
  }
  for (int i = nd - 1; i >= 0; --i) {
    double t = f[i];
    for (int j = i + 1; j < nd; ++j) t -= A[(size_t)i * nd + j] * f[j];
    f[i] = t / A[(size_t)i * nd + i];
  }
  double uq[np];
  assert_ok(ctx, mfree_approximant_apply(ev, MFREE_OP_VALUE, 1, f, MFREE_LAYOUT_AOS, 1, uq, MFREE_LAYOUT_AOS, 1));
  for (int p = 0; p < np; ++p) {
    double g;
    g_lin(NULL, bp + 2 * p, &g);
    if (fabs(uq[p] - g) > 1e-11) fail_msg("Lagrange point %d: u^h = %.15g, g = %.15g", p, uq[p], g);
  }
  free(f);
  free(A);
  free(Phi);
  mfree_matrix_destroy(&K);
  mfree_assembler_destroy(&as);
  mfree_approximant_destroy(&ev);
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
}

/* Penalty: K_pen - K_0 = alpha sum_p w_p Phi_J(x_p) Phi_K(x_p), f_pen - f_0 = alpha
 * sum_p w_p Phi_J(x_p) g(x_p), with Phi from an independent approximant at the points. */
static void test_penalty(void **s) {
  (void)s;
  enum { m = 6, n = m * m, np = 10 };
  double xs[2 * n], bp[2 * np], bw[np];
  mfree_particles_t *ps = cloud(2, m, 1.6, xs, 17);
  for (int p = 0; p < np; ++p) {
    bp[2 * p] = (p + 0.5) / np;
    bp[2 * p + 1] = 0.0;
    bw[p] = 1.0 / np;
  }
  mfree_approximant_t *a = NULL, *ev = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, &a));
  const double alpha = 250.0, h = 1.6 / (m - 1);
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, &ev));
  assert_ok(ctx, mfree_approximant_set_points(ev, np, bp, MFREE_LAYOUT_AOS, 2, &h, 0, MFREE_BORROW));
  assert_ok(ctx, mfree_approximant_setup(ev));
  double Phi[np][n];
  memset(Phi, 0, sizeof Phi);
  {
    int64_t nnz;
    assert_ok(ctx, mfree_approximant_get_nnz(ev, &nnz));
    int64_t rp[np + 1];
    int32_t *ci = malloc(sizeof(int32_t) * (size_t)nnz);
    double *v = malloc(sizeof(double) * (size_t)nnz);
    assert_ok(ctx, mfree_approximant_assemble_csr(ev, MFREE_DERIV_VALUE, 0, rp, ci, v));
    for (int p = 0; p < np; ++p)
      for (int64_t k = rp[p]; k < rp[p + 1]; ++k) Phi[p][ci[k]] = v[k];
    free(ci), free(v);
  }
  double *A[2], f[2][n];
  for (int with = 0; with < 2; ++with) {
    mfree_assembler_t *as = NULL;
    mfree_matrix_t *K = NULL;
    assert_ok(ctx, mfree_assembler_create(ctx, a, NULL, MFREE_FORM_LAPLACE, &as));
    assert_ok(ctx, mfree_assembler_set_coefficient(as, 2.0));
    if (with) {
      assert_ok(ctx, mfree_assembler_set_penalty(as, alpha));
      assert_ok(ctx, mfree_assembler_add_dirichlet(as, MFREE_BC_PENALTY, np, bp, MFREE_LAYOUT_AOS, 2, bw, NULL, 1,
                                                   g_lin, NULL));
    }
    assert_ok(ctx, mfree_assembler_setup(as));
    assert_ok(ctx, mfree_assembler_assemble_matrix(as, &K));
    assert_ok(ctx, mfree_assembler_assemble_rhs(as, f[with]));
    A[with] = dense_of(K, n);
    mfree_matrix_destroy(&K);
    mfree_assembler_destroy(&as);
  }
  for (int J = 0; J < n; ++J) {
    double fe = 0.0;
    for (int p = 0; p < np; ++p) {
      double g;
      g_lin(NULL, bp + 2 * p, &g);
      fe += alpha * bw[p] * Phi[p][J] * g;
    }
    if (fabs(f[1][J] - f[0][J] - fe) > 1e-12 * alpha) fail_msg("penalty load %d: %.15g vs %.15g", J, f[1][J] - f[0][J], fe);
    for (int K = 0; K < n; ++K) {
      double ke = 0.0;
      for (int p = 0; p < np; ++p) ke += alpha * bw[p] * Phi[p][J] * Phi[p][K];
      const double d = A[1][(size_t)J * n + K] - A[0][(size_t)J * n + K];
      if (fabs(d - ke) > 1e-12 * alpha) fail_msg("penalty K[%d][%d]: %.15g vs %.15g", J, K, d, ke);
    }
  }
  free(A[0]), free(A[1]);
  mfree_approximant_destroy(&ev);
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_material_plane_stress),
      cmocka_unit_test(test_material_plane_strain),
      cmocka_unit_test(test_material_3d),
      cmocka_unit_test(test_csc_view_and_refill),
      cmocka_unit_test(test_quadrature_equivalence),
      cmocka_unit_test(test_traction_loads),
      cmocka_unit_test(test_traction_facets),
      cmocka_unit_test(test_lagrange),
      cmocka_unit_test(test_penalty),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
