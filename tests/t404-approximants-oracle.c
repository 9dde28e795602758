/* Approximants against an O(N^2) brute-force oracle written here: dense loops over ALL
 * particles (no neighbour lists), weights from mfree_kernel_eval, the textbook formulas
 * in long double with a small Gaussian elimination of our own:
 *  - SPH: Phi_j = W_j V_j, grad Phi_j = grad W_j V_j (000 eqs 21, 29), and the Hessian
 *    of the radial W, W'' n n^T + W'/r (I - n n^T);
 *  - Shepard: w_j / sum w and its quotient-rule derivative (000 eqs 38-39, Sect. 4.2);
 *  - MLS order 1 and 2: shifted, h-scaled basis, M gamma = p(0), derivatives with the
 *    shift point frozen, M gamma_,i = e_i / h - M_,i gamma (000 Sect. 4.3;
 *    docs/papers.md, paper 000, choices 1);
 *  - SSPH order 2: K = sum p p^T W V, Phi_alpha,j = (K^-1 p_j)_alpha W_j V_j, value
 *    alpha = 0, derivatives alpha! Q_alpha / h^|alpha| (001 Sect. 3 in lambda dimensions,
 *    the factor 2 of docs/papers.md, paper 001, errata 1);
 *  - KB Method 1: G_j = A^-T grad w^S_j with A_ab = sum_j (x_j - x)_a (grad w^S_j)_b
 *    (000 eqs 55-61 with alpha = A^-T, docs/papers.md, paper 000, errata 4);
 *  - Randles-Libersky: K_ab = sum_j (x_j - x)_a (grad W_j)_b V_j, corrected kernel
 *    gradient K^-T grad W_j V_j, difference form (000 eqs 68-69 in index form).
 * The library's tables (assemble_csr, compared as dense rows) must agree to 1e-12
 * relative to each row's largest entry, on a 2D cloud of 196 and a 3D cloud of 150
 * random particles with variable supports and volumes, for the gather and the
 * symmetric-max conventions. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"

static mfree_context_t *ctx;
static int32_t backend = MFREE_BACKEND_OPT; /* argument "ref": the reference backend */
static int setup(void **s) {
  (void)s;
  return mfree_context_create(&ctx) != MFREE_SUCCESS || mfree_context_set_backend(ctx, backend) != MFREE_SUCCESS;
}
static int teardown(void **s) { (void)s; return mfree_context_destroy(&ctx) != MFREE_SUCCESS; }

typedef long double real;

#define NMAX 200
#define TOL 1e-12

typedef struct {
  int dim, n;
  double x[NMAX * 3], h[NMAX], v[NMAX];
  mfree_search_t conv;
  mfree_kernel_t kernel;
} cloud_t;

/* Random points in [0,1]^dim at least 0.35 mean spacings apart, supports
 * hf * spacing * (1 .. 1.3), volumes spacing^dim * (0.7 .. 1.3). */
static void make_cloud(cloud_t *c, int dim, int n, double hf, uint64_t seed) {
  mfree_rng_t r;
  mfree_rng_seed(&r, seed);
  c->dim = dim;
  c->n = n;
  const double dx = pow(1.0 / n, 1.0 / dim), sep = 0.35 * dx;
  for (int i = 0; i < n;) {
    for (int d = 0; d < dim; ++d) c->x[i * dim + d] = mfree_rng_uniform(&r);
    int ok = 1;
    for (int j = 0; j < i && ok; ++j) {
      double d2 = 0.0;
      for (int d = 0; d < dim; ++d) d2 += (c->x[i * dim + d] - c->x[j * dim + d]) * (c->x[i * dim + d] - c->x[j * dim + d]);
      ok = d2 >= sep * sep;
    }
    if (ok) ++i;
  }
  for (int i = 0; i < n; ++i) {
    c->h[i] = hf * dx * (1.0 + 0.3 * mfree_rng_uniform(&r));
    c->v[i] = pow(dx, dim) * (0.7 + 0.6 * mfree_rng_uniform(&r));
  }
}

/* ------------------------------------------------------------------------------------ */
/* Oracle                                                                                  */
/* ------------------------------------------------------------------------------------ */

/* Solve A x = b (n x n, row-major, copied) by Gaussian elimination with partial
 * pivoting; b is overwritten with x. */
static void gauss_solve(int n, const real *A0, real *b) {
  real A[20 * 20];
  memcpy(A, A0, sizeof(real) * (size_t)(n * n));
  for (int k = 0; k < n; ++k) {
    int p = k;
    for (int i = k + 1; i < n; ++i)
      if (fabsl(A[i * n + k]) > fabsl(A[p * n + k])) p = i;
    assert_true(A[p * n + k] != 0.0L);
    if (p != k) {
      for (int j = 0; j < n; ++j) {
        const real t = A[k * n + j];
        A[k * n + j] = A[p * n + j];
        A[p * n + j] = t;
      }
      const real t = b[k];
      b[k] = b[p];
      b[p] = t;
    }
    for (int i = k + 1; i < n; ++i) {
      const real f = A[i * n + k] / A[k * n + k];
      for (int j = k; j < n; ++j) A[i * n + j] -= f * A[k * n + j];
      b[i] -= f * b[k];
    }
  }
  for (int i = n - 1; i >= 0; --i) {
    real s = b[i];
    for (int j = i + 1; j < n; ++j) s -= A[i * n + j] * b[j];
    b[i] = s / A[i * n + i];
  }
}

/* Complete monomial basis of degree <= k in dim variables (our own ordering). */
typedef struct {
  int dim, L;
  int e[20][3];
} basis_t;

static void basis_make(basis_t *B, int dim, int k) {
  B->dim = dim;
  B->L = 0;
  for (int deg = 0; deg <= k; ++deg)
    for (int a = 0; a <= deg; ++a)
      for (int b = 0; b <= deg - a; ++b) {
        const int c = deg - a - b;
        if ((dim < 2 && b) || (dim < 3 && c)) continue;
        B->e[B->L][0] = a;
        B->e[B->L][1] = b;
        B->e[B->L][2] = c;
        ++B->L;
      }
}
static void basis_eval(const basis_t *B, const real *z, real *p) {
  for (int m = 0; m < B->L; ++m) {
    real t = 1.0L;
    for (int d = 0; d < B->dim; ++d)
      for (int q = 0; q < B->e[m][d]; ++q) t *= z[d];
    p[m] = t;
  }
}
/* index of the monomial with exponents (i) + (k) (k < 0: just (i)) */
static int basis_find(const basis_t *B, int i, int k) {
  int want[3] = {0, 0, 0};
  ++want[i];
  if (k >= 0) ++want[k];
  for (int m = 0; m < B->L; ++m)
    if (B->e[m][0] == want[0] && B->e[m][1] == want[1] && B->e[m][2] == want[2]) return m;
  fail_msg("monomial not in the basis");
  return -1;
}

/* Per-site data of the oracle: weights and their x-gradients for ALL particles. */
typedef struct {
  real d[NMAX][3], w[NMAX], gw[NMAX][3], hw[NMAX][6];
} site_t;

static void site_weights(const cloud_t *c, int s, site_t *st) {
  const int dim = c->dim;
  for (int j = 0; j < c->n; ++j) {
    double r2 = 0.0, dd[3] = {0, 0, 0};
    for (int a = 0; a < dim; ++a) {
      dd[a] = c->x[j * dim + a] - c->x[s * dim + a];
      r2 += dd[a] * dd[a];
    }
    const double r = sqrt(r2);
    const double hp = c->conv == MFREE_SEARCH_GATHER ? c->h[s] : fmax(c->h[s], c->h[j]);
    double w = 0.0, dw = 0.0, d2w = 0.0;
    assert_ok(ctx, mfree_kernel_eval(ctx, c->kernel, dim, 0.0, hp, 1, &r, &w, &dw, &d2w));
    st->w[j] = w;
    for (int a = 0; a < 3; ++a) {
      st->d[j][a] = a < dim ? dd[a] : 0.0;
      /* grad_x W(|x - x_j|) = W'(r) (x - x_j) / r = -W'(r) d / r */
      st->gw[j][a] = (a < dim && r > 0.0) ? -(real)dw * dd[a] / r : 0.0L;
    }
    /* Hessian of a radial function: W'' n n^T + W'/r (I - n n^T), n = d / r; the limit
     * W''(0) I at r = 0 */
    for (int a = 0; a < dim; ++a)
      for (int b = a; b < dim; ++b) {
        const int e = a * dim - a * (a - 1) / 2 + (b - a);
        if (r > 0.0) {
          const real nn = (real)dd[a] * dd[b] / ((real)r * r);
          st->hw[j][e] = (real)d2w * nn + (real)dw / r * ((a == b ? 1.0L : 0.0L) - nn);
        } else {
          st->hw[j][e] = a == b ? (real)d2w : 0.0L;
        }
      }
  }
}

/* Oracle rows of one method at site s: val[n], grad[dim][n], hess[nh][n]. */
static void oracle_rows(const cloud_t *c, int s, const site_t *st, mfree_method_t m, int order,
                        real *val, real (*grad)[NMAX], real (*hess)[NMAX]) {
  const int dim = c->dim, n = c->n;
  const real hs = c->h[s];
  switch (m) {
    case MFREE_METHOD_SPH:
      for (int j = 0; j < n; ++j) {
        val[j] = st->w[j] * c->v[j];
        for (int a = 0; a < dim; ++a) grad[a][j] = st->gw[j][a] * c->v[j];
        for (int e = 0; e < dim * (dim + 1) / 2; ++e) hess[e][j] = st->hw[j][e] * c->v[j];
      }
      return;
    case MFREE_METHOD_SHEPARD:
    case MFREE_METHOD_KB_METHOD1: {
      real S = 0.0L, gS[3] = {0, 0, 0};
      for (int j = 0; j < n; ++j) {
        S += st->w[j];
        for (int a = 0; a < dim; ++a) gS[a] += st->gw[j][a];
      }
      for (int j = 0; j < n; ++j) {
        val[j] = st->w[j] / S;
        for (int a = 0; a < dim; ++a) grad[a][j] = st->gw[j][a] / S - st->w[j] * gS[a] / (S * S);
      }
      if (m == MFREE_METHOD_SHEPARD) return;
      /* A_ab = sum_j d_ja dphi_jb; G_j = A^-T dphi_j, i.e. A^T G_j = dphi_j */
      real A[9] = {0}, AT[9];
      for (int j = 0; j < n; ++j)
        for (int a = 0; a < dim; ++a)
          for (int b = 0; b < dim; ++b) A[a * dim + b] += st->d[j][a] * grad[b][j];
      for (int a = 0; a < dim; ++a)
        for (int b = 0; b < dim; ++b) AT[a * dim + b] = A[b * dim + a];
      for (int j = 0; j < n; ++j) {
        real g[3];
        for (int a = 0; a < dim; ++a) g[a] = grad[a][j];
        gauss_solve(dim, AT, g);
        for (int a = 0; a < dim; ++a) grad[a][j] = g[a];
      }
      return;
    }
    case MFREE_METHOD_RANDLES_LIBERSKY: {
      real K[9] = {0}, KT[9];
      for (int j = 0; j < n; ++j)
        for (int a = 0; a < dim; ++a)
          for (int b = 0; b < dim; ++b) K[a * dim + b] += st->d[j][a] * st->gw[j][b] * c->v[j];
      for (int a = 0; a < dim; ++a)
        for (int b = 0; b < dim; ++b) KT[a * dim + b] = K[b * dim + a];
      real sum[3] = {0, 0, 0};
      for (int j = 0; j < n; ++j) {
        val[j] = st->w[j] * c->v[j];
        real g[3];
        for (int a = 0; a < dim; ++a) g[a] = st->gw[j][a] * c->v[j];
        gauss_solve(dim, KT, g);
        for (int a = 0; a < dim; ++a) {
          grad[a][j] = j == s ? 0.0L : g[a];
          if (j != s) sum[a] += g[a];
        }
      }
      for (int a = 0; a < dim; ++a) grad[a][s] = -sum[a];
      return;
    }
    case MFREE_METHOD_MLS: {
      basis_t B;
      basis_make(&B, dim, order);
      const int L = B.L;
      static real P[NMAX][20];
      real M[400] = {0}, Mi[3][400];
      memset(Mi, 0, sizeof Mi);
      for (int j = 0; j < n; ++j) {
        real z[3];
        for (int a = 0; a < dim; ++a) z[a] = st->d[j][a] / hs;
        basis_eval(&B, z, P[j]);
        for (int p = 0; p < L; ++p)
          for (int q = 0; q < L; ++q) {
            M[p * L + q] += st->w[j] * P[j][p] * P[j][q];
            for (int a = 0; a < dim; ++a) Mi[a][p * L + q] += st->gw[j][a] * P[j][p] * P[j][q];
          }
      }
      real g[20] = {0}, gi[3][20];
      g[0] = 1.0L;
      gauss_solve(L, M, g);
      for (int a = 0; a < dim; ++a) {
        for (int p = 0; p < L; ++p) {
          real t = 0.0L;
          for (int q = 0; q < L; ++q) t -= Mi[a][p * L + q] * g[q];
          gi[a][p] = t;
        }
        gi[a][basis_find(&B, a, -1)] += 1.0L / hs;
        gauss_solve(L, M, gi[a]);
      }
      for (int j = 0; j < n; ++j) {
        real gp = 0.0L;
        for (int p = 0; p < L; ++p) gp += g[p] * P[j][p];
        val[j] = st->w[j] * gp;
        for (int a = 0; a < dim; ++a) {
          real t = 0.0L;
          for (int p = 0; p < L; ++p) t += gi[a][p] * P[j][p];
          grad[a][j] = st->w[j] * t + st->gw[j][a] * gp;
        }
      }
      return;
    }
    case MFREE_METHOD_SSPH: {
      basis_t B;
      basis_make(&B, dim, order);
      const int L = B.L;
      static real P[NMAX][20];
      real K[400] = {0};
      for (int j = 0; j < n; ++j) {
        real z[3];
        for (int a = 0; a < dim; ++a) z[a] = st->d[j][a] / hs;
        basis_eval(&B, z, P[j]);
        for (int p = 0; p < L; ++p)
          for (int q = 0; q < L; ++q) K[p * L + q] += P[j][p] * P[j][q] * st->w[j] * c->v[j];
      }
      real Ki[20][20]; /* columns of K^-1 */
      for (int p = 0; p < L; ++p) {
        for (int q = 0; q < L; ++q) Ki[p][q] = p == q ? 1.0L : 0.0L;
        gauss_solve(L, K, Ki[p]);
      }
      for (int j = 0; j < n; ++j) {
        real Q[20]; /* K^-1 p_j (K symmetric) */
        for (int p = 0; p < L; ++p) {
          Q[p] = 0.0L;
          for (int q = 0; q < L; ++q) Q[p] += Ki[q][p] * P[j][q];
        }
        const real wv = st->w[j] * c->v[j];
        val[j] = Q[0] * wv;
        for (int a = 0; a < dim; ++a) grad[a][j] = Q[basis_find(&B, a, -1)] * wv / hs;
        for (int a = 0; a < dim; ++a)
          for (int b = a; b < dim; ++b) {
            const int e = a * dim - a * (a - 1) / 2 + (b - a);
            hess[e][j] = (a == b ? 2.0L : 1.0L) * Q[basis_find(&B, a, b)] * wv / (hs * hs);
          }
      }
      return;
    }
    default:
      fail_msg("no oracle for method %d", (int)m);
  }
}

/* ------------------------------------------------------------------------------------ */

static double *dense_table(const mfree_approximant_t *a, mfree_deriv_t deriv, int comp, int n) {
  int32_t ns = 0;
  int64_t nnz = 0;
  assert_ok(ctx, mfree_approximant_get_num_sites(a, &ns));
  assert_ok(ctx, mfree_approximant_get_nnz(a, &nnz));
  assert_int_equal(ns, n);
  int64_t *rp = malloc(sizeof(int64_t) * (size_t)(n + 1));
  int32_t *cols = malloc(sizeof(int32_t) * (size_t)(nnz + 1));
  double *vals = malloc(sizeof(double) * (size_t)(nnz + 1));
  double *D = calloc((size_t)n * n, sizeof(double));
  assert_non_null(rp);
  assert_non_null(cols);
  assert_non_null(vals);
  assert_non_null(D);
  assert_ok(ctx, mfree_approximant_assemble_csr(a, deriv, comp, rp, cols, vals));
  for (int s = 0; s < n; ++s)
    for (int64_t k = rp[s]; k < rp[s + 1]; ++k) {
      assert_true(cols[k] >= 0 && cols[k] < n);
      D[(size_t)s * n + cols[k]] += vals[k];
    }
  free(rp);
  free(cols);
  free(vals);
  return D;
}

typedef struct {
  mfree_method_t m;
  int order;
  int flags;
  const char *name;
} ocase_t;

static const ocase_t kCases[] = {
    {MFREE_METHOD_SPH, 0, 7, "SPH"},
    {MFREE_METHOD_SHEPARD, 0, 3, "Shepard"},
    {MFREE_METHOD_MLS, 1, 3, "MLS 1"},
    {MFREE_METHOD_MLS, 2, 3, "MLS 2"},
    {MFREE_METHOD_SSPH, 2, 7, "SSPH 2"},
    {MFREE_METHOD_KB_METHOD1, 1, 3, "KB Method 1"},
    {MFREE_METHOD_RANDLES_LIBERSKY, 1, 3, "Randles-Libersky"},
};
#define NCASES ((int)(sizeof kCases / sizeof kCases[0]))

static void compare_with_oracle(const cloud_t *c) {
  const int n = c->n, dim = c->dim, nh = dim * (dim + 1) / 2;
  double R = 0.0;
  assert_ok(ctx, mfree_kernel_get_support_radius(ctx, c->kernel, 0.0, &R));
  mfree_particles_t *ps = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, dim, n, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, c->x, MFREE_LAYOUT_AOS, dim, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_support(ps, c->h, 1, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_volumes(ps, c->v, 1, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_search(ps, c->conv, R));

  /* the weights of every site, once (mfree_kernel_eval per pair is the slow part) */
  site_t *st = malloc(sizeof(site_t) * (size_t)n);
  assert_non_null(st);
  for (int s = 0; s < n; ++s) site_weights(c, s, &st[s]);
  static real val[NMAX], grad[3][NMAX], hess[6][NMAX];
  for (int ci = 0; ci < NCASES; ++ci) {
    const ocase_t *oc = &kCases[ci];
    mfree_approximant_t *a = NULL;
    assert_ok(ctx, mfree_approximant_create(ctx, ps, oc->m, &a));
    assert_ok(ctx, mfree_approximant_set_kernel(a, c->kernel, 0.0));
    assert_ok(ctx, mfree_approximant_set_order(a, oc->order));
    assert_ok(ctx, mfree_approximant_set_derivatives(a, oc->flags));
    assert_ok(ctx, mfree_approximant_setup(a));
    double *T[1 + 3 + 6] = {NULL};
    T[0] = dense_table(a, MFREE_DERIV_VALUE, 0, n);
    for (int d = 0; d < dim; ++d) T[1 + d] = dense_table(a, MFREE_DERIV_GRADIENT, d, n);
    if (oc->flags & MFREE_DERIV_HESSIAN)
      for (int e = 0; e < nh; ++e) T[4 + e] = dense_table(a, MFREE_DERIV_HESSIAN, e, n);
    double worst = 0.0;
    int worst_site = -1, worst_table = -1;
    for (int s = 0; s < n; ++s) {
      oracle_rows(c, s, &st[s], oc->m, oc->order, val, grad, hess);
      for (int t = 0; t < 10; ++t) {
        if (!T[t]) continue;
        const real *o = t == 0 ? val : (t < 4 ? grad[t - 1] : hess[t - 4]);
        real big = 0.0L;
        for (int j = 0; j < n; ++j) big = fmaxl(big, fabsl(o[j]));
        for (int j = 0; j < n; ++j) {
          const double e = (double)(fabsl((real)T[t][(size_t)s * n + j] - o[j]) / big);
          if (e > worst) {
            worst = e;
            worst_site = s;
            worst_table = t;
          }
        }
      }
    }
    if (getenv("MFREE_TEST_VERBOSE"))
      fprintf(stderr, "%-18s dim %d kernel %d convention %d: worst relative difference %.3g\n",
              oc->name, dim, (int)c->kernel, (int)c->conv, worst);
    if (worst > TOL)
      fail_msg("%s, dim %d, kernel %d, convention %d: table %d (0 value, 1-3 gradient, 4-9 "
               "Hessian) of site %d differs from the oracle by %.3g relative",
               oc->name, dim, (int)c->kernel, (int)c->conv, worst_table, worst_site, worst);
    for (int t = 0; t < 10; ++t) free(T[t]);
    assert_ok(ctx, mfree_approximant_destroy(&a));
  }
  free(st);
  assert_ok(ctx, mfree_particles_destroy(&ps));
}

static void test_oracle_2d(void **s) {
  (void)s;
  static cloud_t c;
  make_cloud(&c, 2, 196, 1.7, 2024);
  c.conv = MFREE_SEARCH_GATHER;
  c.kernel = MFREE_KERNEL_CUBIC_SPLINE;
  compare_with_oracle(&c);
  c.conv = MFREE_SEARCH_SYMMETRIC_MAX;
  c.kernel = MFREE_KERNEL_QUARTIC_SPLINE;
  compare_with_oracle(&c);
}

static void test_oracle_3d(void **s) {
  (void)s;
  static cloud_t c;
  make_cloud(&c, 3, 150, 1.6, 31337);
  c.conv = MFREE_SEARCH_GATHER;
  c.kernel = MFREE_KERNEL_WENDLAND_C4;
  compare_with_oracle(&c);
  c.conv = MFREE_SEARCH_SYMMETRIC_MAX;
  c.kernel = MFREE_KERNEL_CUBIC_SPLINE;
  compare_with_oracle(&c);
}

int main(int argc, char **argv) {
  backend = mfree_test_backend(argc, argv);
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_oracle_2d),
      cmocka_unit_test(test_oracle_3d),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
