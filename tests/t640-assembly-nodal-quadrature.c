/* Assembler, nodal quadrature (paper 000 Sect. 5.2, eq 95; docs/papers.md, paper 000,
 * choices 3): the plane-stress stiffness of every nodal-quadrature scheme of 000 Sect. 6.2 equals
 * K_JK = sum_I dV_I B_test,J(x_I)^T D B_trial,K(x_I) built independently from the
 * approximants' gradient tables (mfree_approximant_assemble_csr), for Bubnov (SPH
 * symmetrised, JB, RL, MLS) and Petrov-Galerkin (KB Method 1 and 2 trial, Shepard test)
 * schemes; and with the finite-element layer (000 eqs 100-105, Fig. 2) the quadrature
 * points of the boundary nodes carry the bilinear elements' corner derivatives with the
 * node's volume split among its elements, the boundary rows being u_J = g(x_J).
 * Johnson-Beissel's shear strain keeps the symmetrised SPH derivatives (000 eqs 48-52:
 * only the normal strains are corrected). A layer given in several calls (symmetry lines
 * with different constrained components) is one layer with a mask per call.
 * Library only; dense comparisons. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"

static mfree_context_t *ctx;
static int setup(void **s) { (void)s; return mfree_context_create(&ctx) != MFREE_SUCCESS; }
static int teardown(void **s) { (void)s; return mfree_context_destroy(&ctx) != MFREE_SUCCESS; }

enum { NX = 9, NY = 6, N = NX * NY };
static const double E = 1000.0, NU = 0.3;
static double X[2 * N], V[N], H;

/* NX x NY nodes of spacing 1/8, interior ones jittered by up to 20 % (jitter = 1) or on
 * the grid (jitter = 0); volumes vary by +-10 % (the assembler must use each node's). */
static mfree_particles_t *cloud(int jitter) {
  mfree_rng_t r;
  mfree_rng_seed(&r, 640);
  const double dx = 0.125;
  for (int i = 0; i < NX; ++i)
    for (int j = 0; j < NY; ++j) {
      const int p = i * NY + j, b = i == 0 || j == 0 || i == NX - 1 || j == NY - 1;
      const double jx = jitter && !b ? 0.2 * (2 * mfree_rng_uniform(&r) - 1) : 0.0;
      const double jy = jitter && !b ? 0.2 * (2 * mfree_rng_uniform(&r) - 1) : 0.0;
      X[2 * p] = (i + jx) * dx;
      X[2 * p + 1] = (j + jy) * dx;
      V[p] = dx * dx * (0.9 + 0.2 * mfree_rng_uniform(&r));
    }
  H = sqrt(2.0) * dx; /* 000 eq 126 */
  mfree_particles_t *ps = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, 2, N, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, X, MFREE_LAYOUT_AOS, 2, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_support(ps, &H, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_volumes(ps, V, 1, MFREE_COPY));
  assert_ok(ctx, mfree_particles_setup(ps));
  return ps;
}

static mfree_approximant_t *approx(mfree_particles_t *ps, mfree_method_t m, int32_t order) {
  mfree_approximant_t *a = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, m, &a));
  if (order) assert_ok(ctx, mfree_approximant_set_order(a, order));
  return a;
}

/* Gradient tables at the particles, dense: G[(I * N + K) * 2 + d]. */
static double *gradients(mfree_approximant_t *a) {
  assert_ok(ctx, mfree_approximant_setup(a));
  int64_t nnz = 0;
  assert_ok(ctx, mfree_approximant_get_nnz(a, &nnz));
  int64_t *rp = malloc(sizeof(int64_t) * (N + 1));
  int32_t *ci = malloc(sizeof(int32_t) * (size_t)nnz);
  double *g = malloc(sizeof(double) * (size_t)nnz), *G = calloc((size_t)N * N * 2, sizeof(double));
  for (int d = 0; d < 2; ++d) {
    assert_ok(ctx, mfree_approximant_assemble_csr(a, MFREE_DERIV_GRADIENT, d, rp, ci, g));
    for (int32_t I = 0; I < N; ++I)
      for (int64_t k = rp[I]; k < rp[I + 1]; ++k) G[((size_t)I * N + ci[k]) * 2 + d] = g[k];
  }
  free(rp), free(ci), free(g);
  return G;
}

static void plane_stress(double D[3][3]) {
  const double q = E / (1 - NU * NU);
  const double d[3][3] = {{q, q * NU, 0}, {q * NU, q, 0}, {0, 0, q * (1 - NU) / 2}};
  memcpy(D, d, sizeof d);
}

/* Adds w B_J^T D B_K for test derivatives gt (of node J) and trial derivatives gr (of
 * node K) to the dense 2N x 2N matrix R; the shear rows of B use gts and grs. */
static void add_pair_s(double *R, int32_t J, const double *gt, const double *gts, int32_t K, const double *gr,
                       const double *grs, double w) {
  double D[3][3];
  plane_stress(D);
  const double BJ[3][2] = {{gt[0], 0}, {0, gt[1]}, {gts[1], gts[0]}};
  const double BK[3][2] = {{gr[0], 0}, {0, gr[1]}, {grs[1], grs[0]}};
  for (int c = 0; c < 2; ++c)
    for (int e = 0; e < 2; ++e) {
      double s = 0;
      for (int u = 0; u < 3; ++u)
        for (int v = 0; v < 3; ++v) s += BJ[u][c] * D[u][v] * BK[v][e];
      R[(size_t)(2 * J + c) * 2 * N + 2 * K + e] += w * s;
    }
}

static void add_pair(double *R, int32_t J, const double *gt, int32_t K, const double *gr, double w) {
  add_pair_s(R, J, gt, gt, K, gr, gr, w);
}

/* max |K - R| / max |R| for the assembled K (2N x 2N). */
static double compare(const mfree_matrix_t *K, const double *R) {
  const int64_t *rp;
  const int32_t *ci;
  const double *v;
  int32_t nr, nc;
  int64_t nnz;
  assert_ok(ctx, mfree_matrix_get_size(K, &nr, &nc, &nnz));
  assert_int_equal(nr, 2 * N);
  assert_ok(ctx, mfree_matrix_get_csr(K, &rp, &ci, &v));
  double *A = calloc((size_t)4 * N * N, sizeof(double)), dmax = 0, rmax = 0;
  for (int32_t i = 0; i < nr; ++i)
    for (int64_t k = rp[i]; k < rp[i + 1]; ++k) A[(size_t)i * 2 * N + ci[k]] = v[k];
  for (size_t k = 0; k < (size_t)4 * N * N; ++k) {
    dmax = fmax(dmax, fabs(A[k] - R[k]));
    rmax = fmax(rmax, fabs(R[k]));
  }
  free(A);
  return dmax / rmax;
}

static void zero_g(void *user, const double *x, double *g) {
  (void)user, (void)x;
  g[0] = g[1] = 0.0;
}

typedef struct {
  const char *name;
  mfree_method_t trial;
  int32_t order;
  mfree_method_t test; /* 0: Bubnov */
} scheme_t;

/* 000 Sect. 6.2 cases 1-6 (EFG, case 7, has background cells). */
static const scheme_t kSchemes[] = {
    {"SPH", MFREE_METHOD_SPH_SYMMETRIC, 0, (mfree_method_t)0},
    {"JB", MFREE_METHOD_JOHNSON_BEISSEL, 0, (mfree_method_t)0},
    {"RL", MFREE_METHOD_RANDLES_LIBERSKY, 0, (mfree_method_t)0},
    {"CD1", MFREE_METHOD_KB_METHOD1, 0, MFREE_METHOD_SHEPARD},
    {"CD2", MFREE_METHOD_KB_METHOD2, 1, MFREE_METHOD_SHEPARD},
    {"MLS", MFREE_METHOD_MLS, 1, (mfree_method_t)0},
};

/* Builds the assembled and the reference stiffness of one scheme; with layer = 1 the
 * finite-element layer along x = 0 (the first two columns of nodes, both components
 * prescribed); with layer = 2 a second call adds the layer along y = 0 and the masks are
 * u_x on x = 0, u_y on y = 0 (the corner element belongs to both calls). */
static void check_scheme(const scheme_t *sc, int jitter, int layer) {
  mfree_particles_t *ps = cloud(jitter);
  mfree_approximant_t *trial = approx(ps, sc->trial, sc->order);
  mfree_approximant_t *test = sc->test ? approx(ps, sc->test, 0) : NULL;
  mfree_assembler_t *as = NULL;
  assert_ok(ctx, mfree_assembler_create(ctx, trial, test, MFREE_FORM_ELASTICITY_PLANE_STRESS, &as));
  assert_ok(ctx, mfree_assembler_set_material(as, E, NU));
  assert_ok(ctx, mfree_assembler_set_quadrature_nodal(as));
  /* layer on x = 0: quads (0,j), (1,j), (1,j+1), (0,j+1) in column-major node numbering;
   * on y = 0: (i,0), (i+1,0), (i+1,1), (i,1) */
  enum { NE1 = NY - 1, NE = NY - 1 + NX - 1 };
  int32_t conn[4 * NE], gu[NY + NX], nel[N] = {0}, mask[N] = {0};
  for (int j = 0; j < NY - 1; ++j) {
    const int32_t q[4] = {j, NY + j, NY + j + 1, j + 1};
    memcpy(conn + 4 * j, q, sizeof q);
  }
  for (int i = 0; i < NX - 1; ++i) {
    const int32_t q[4] = {i * NY, (i + 1) * NY, (i + 1) * NY + 1, i * NY + 1};
    memcpy(conn + 4 * (NE1 + i), q, sizeof q);
  }
  for (int j = 0; j < NY; ++j) gu[j] = j;
  for (int i = 0; i < NX; ++i) gu[NY + i] = i * NY;
  const int ne = layer == 2 ? NE : NE1;
  if (layer == 1) assert_ok(ctx, mfree_assembler_set_fe_layer(as, NE1, 4, conn, NY, gu, 3, zero_g, NULL));
  if (layer == 2) {
    assert_ok(ctx, mfree_assembler_set_fe_layer(as, NE1, 4, conn, NY, gu, 1, zero_g, NULL));
    assert_ok(ctx, mfree_assembler_set_fe_layer(as, NX - 1, 4, conn + 4 * NE1, NX, gu + NY, 2, zero_g, NULL));
  }
  if (layer)
    for (int j = 0; j < NY; ++j) mask[gu[j]] |= layer == 2 ? 1 : 3;
  if (layer == 2)
    for (int i = 0; i < NX; ++i) mask[gu[NY + i]] |= 2;
  for (int k = 0; k < 4 * ne; ++k) nel[conn[k]] += mask[conn[k]] != 0;
  assert_ok(ctx, mfree_assembler_setup(as));
  mfree_matrix_t *K = NULL;
  assert_ok(ctx, mfree_assembler_assemble_matrix(as, &K));

  double *Gr = gradients(trial), *Gt = test ? gradients(test) : Gr;
  /* JB: symmetrised SPH derivatives in the shear rows (Bubnov: test = trial) */
  double *Gs = Gr;
  if (sc->trial == MFREE_METHOD_JOHNSON_BEISSEL) {
    mfree_approximant_t *sph = approx(ps, MFREE_METHOD_SPH_SYMMETRIC, 0);
    Gs = gradients(sph);
    mfree_approximant_destroy(&sph);
  }
  const double *Gts = test ? Gt : Gs;
  double *R = calloc((size_t)4 * N * N, sizeof(double));
  for (int32_t I = 0; I < N; ++I) {
    if (layer && nel[I]) { /* boundary node: the elements' corner derivatives */
      for (int e = 0; e < ne; ++e)
        for (int a = 0; a < 4; ++a) {
          if (conn[4 * e + a] != I) continue;
          /* bilinear corner = the linear triangle (I, next, previous) */
          const int32_t t[3] = {I, conn[4 * e + (a + 1) % 4], conn[4 * e + (a + 3) % 4]};
          const double *x0 = X + 2 * t[0], *x1 = X + 2 * t[1], *x2 = X + 2 * t[2];
          const double A2 = (x1[0] - x0[0]) * (x2[1] - x0[1]) - (x2[0] - x0[0]) * (x1[1] - x0[1]);
          const double g[3][2] = {{(x1[1] - x2[1]) / A2, (x2[0] - x1[0]) / A2},
                                  {(x2[1] - x0[1]) / A2, (x0[0] - x2[0]) / A2},
                                  {(x0[1] - x1[1]) / A2, (x1[0] - x0[0]) / A2}};
          for (int p = 0; p < 3; ++p)
            for (int q = 0; q < 3; ++q) add_pair(R, t[p], g[p], t[q], g[q], V[I] / nel[I]);
        }
      continue;
    }
    for (int32_t J = 0; J < N; ++J) {
      const size_t tj = ((size_t)I * N + J) * 2;
      const double *gt = Gt + tj, *gts = Gts + tj;
      if (gt[0] == 0.0 && gt[1] == 0.0 && gts[0] == 0.0 && gts[1] == 0.0) continue;
      for (int32_t Kn = 0; Kn < N; ++Kn) {
        const size_t rk = ((size_t)I * N + Kn) * 2;
        const double *gr = Gr + rk, *grs = Gs + rk;
        if (gr[0] != 0.0 || gr[1] != 0.0 || grs[0] != 0.0 || grs[1] != 0.0)
          add_pair_s(R, J, gt, gts, Kn, gr, grs, V[I]);
      }
    }
  }
  /* u_J,c = g_c(x_J) on the prescribed components of the boundary nodes */
  for (int32_t I = 0; I < N; ++I)
    for (int c = 0; c < 2; ++c) {
      if (!(mask[I] & (1 << c))) continue;
      double *row = R + (size_t)(2 * I + c) * 2 * N;
      memset(row, 0, sizeof(double) * 2 * N);
      row[2 * I + c] = 1.0;
    }
  const double err = compare(K, R);
  if (!(err < 1e-12))
    fail_msg("%s (jitter %d, layer %d): assembled stiffness differs from sum_I dV_I B^T D B by %.3e", sc->name,
             jitter, layer, err);
  free(R);
  if (Gt != Gr) free(Gt);
  if (Gs != Gr) free(Gs);
  free(Gr);
  mfree_matrix_destroy(&K);
  mfree_assembler_destroy(&as);
  mfree_approximant_destroy(&test);
  mfree_approximant_destroy(&trial);
  mfree_particles_destroy(&ps);
}

static void test_nodal_quadrature(void **s) {
  (void)s;
  for (size_t k = 0; k < sizeof kSchemes / sizeof kSchemes[0]; ++k) check_scheme(&kSchemes[k], 1, 0);
}

static void test_fe_layer_nodal(void **s) {
  (void)s;
  for (size_t k = 0; k < sizeof kSchemes / sizeof kSchemes[0]; ++k) check_scheme(&kSchemes[k], 1, 1);
}

/* Two symmetry lines, one call each with its own component mask. */
static void test_fe_layer_two_calls(void **s) {
  (void)s;
  for (size_t k = 0; k < sizeof kSchemes / sizeof kSchemes[0]; ++k) check_scheme(&kSchemes[k], 1, 2);
}

/* Every call of the layer must use the same element type. */
static void test_fe_layer_mixed_types(void **s) {
  (void)s;
  mfree_particles_t *ps = cloud(0);
  mfree_approximant_t *a = approx(ps, MFREE_METHOD_MLS, 1);
  mfree_assembler_t *as = NULL;
  assert_ok(ctx, mfree_assembler_create(ctx, a, NULL, MFREE_FORM_ELASTICITY_PLANE_STRESS, &as));
  const int32_t quad[4] = {0, NY, NY + 1, 1}, tri[3] = {NY + 1, 2 * NY + 1, NY + 2}, gu[2] = {0, 1};
  assert_ok(ctx, mfree_assembler_set_fe_layer(as, 1, 4, quad, 2, gu, 3, zero_g, NULL));
  assert_error(ctx, mfree_assembler_set_fe_layer(as, 1, 3, tri, 1, gu + 1, 1, zero_g, NULL), MFREE_ERR_ARG,
               "element type");
  mfree_assembler_destroy(&as);
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_nodal_quadrature),
      cmocka_unit_test(test_fe_layer_nodal),
      cmocka_unit_test(test_fe_layer_two_calls),
      cmocka_unit_test(test_fe_layer_mixed_types),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
