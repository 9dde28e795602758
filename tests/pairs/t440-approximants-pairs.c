/* Half pair lists (mfree_particles_set_pairs) and per-pair gradients
 * (mfree_approximant_get_pair_gradients, _antisymmetric), per-particle correction data
 * (mfree_approximant_get_correction).
 *
 * The cloud: a jittered m x m lattice of real particles in [0, 1]^2 (spacing dx), with
 * two layers of virtual boundary particles around it stored after the real ones as
 * ghosts; h per particle varies by +-10 %, pairs are the unordered pairs within
 * 2 (h_i + h_j) / 2 (the search convention SYMMETRIC_MEAN), shuffled, each in a random
 * orientation. Oracles: exact identities (linear fields, antisymmetry, momentum sums,
 * bitwise equality with CSR lists) and the cubic spline written out here. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"

enum { M = 14, NREAL = M * M, LAYERS = 2, NMAX = (M + 2 * LAYERS) * (M + 2 * LAYERS) };

typedef struct {
  int n, nghost;
  double x[2 * NMAX], h[NMAX], m[NMAX], rho[NMAX];
  int64_t np;
  int32_t *pi, *pj; /* 0-based */
} cloud_t;

static double dist2(const cloud_t *c, int a, int b) {
  const double dx = c->x[2 * a] - c->x[2 * b], dy = c->x[2 * a + 1] - c->x[2 * b + 1];
  return dx * dx + dy * dy;
}

static void make_cloud(cloud_t *c, uint64_t seed) {
  mfree_rng_t r;
  mfree_rng_seed(&r, seed);
  const double dx = 1.0 / (M - 1);
  int n = 0;
  for (int pass = 0; pass < 2; ++pass) /* real particles first, then the virtual ones */
    for (int b = -LAYERS; b < M + LAYERS; ++b)
      for (int a = -LAYERS; a < M + LAYERS; ++a) {
        const int inside = a >= 0 && a < M && b >= 0 && b < M;
        if (inside != (pass == 0)) continue;
        const double jit = inside ? 0.25 : 0.0;
        c->x[2 * n] = dx * (a + jit * (2.0 * mfree_rng_uniform(&r) - 1.0));
        c->x[2 * n + 1] = dx * (b + jit * (2.0 * mfree_rng_uniform(&r) - 1.0));
        c->h[n] = 1.2 * dx * (1.0 + 0.1 * (2.0 * mfree_rng_uniform(&r) - 1.0));
        c->rho[n] = 1000.0 * (1.0 + 0.05 * mfree_rng_uniform(&r));
        c->m[n] = c->rho[n] * dx * dx * (1.0 + 0.2 * mfree_rng_uniform(&r));
        ++n;
      }
  c->n = n;
  c->nghost = n - NREAL;
  /* pairs within 2 h_ij, then shuffled and randomly oriented */
  c->pi = malloc(sizeof(int32_t) * (size_t)n * n / 2);
  c->pj = malloc(sizeof(int32_t) * (size_t)n * n / 2);
  int64_t np = 0;
  for (int a = 0; a < n; ++a)
    for (int b = a + 1; b < n; ++b) {
      const double hij = 0.5 * (c->h[a] + c->h[b]);
      if (dist2(c, a, b) < 4.0 * hij * hij) {
        c->pi[np] = a;
        c->pj[np] = b;
        ++np;
      }
    }
  for (int64_t k = np - 1; k > 0; --k) {
    const int64_t q = (int64_t)(mfree_rng_uniform(&r) * (double)(k + 1));
    int32_t t = c->pi[k];
    c->pi[k] = c->pi[q];
    c->pi[q] = t;
    t = c->pj[k];
    c->pj[k] = c->pj[q];
    c->pj[q] = t;
  }
  for (int64_t k = 0; k < np; ++k)
    if (mfree_rng_uniform(&r) < 0.5) {
      const int32_t t = c->pi[k];
      c->pi[k] = c->pj[k];
      c->pj[k] = t;
    }
  c->np = np;
}

static void free_cloud(cloud_t *c) {
  free(c->pi);
  free(c->pj);
}

/* A particle set on the cloud (borrowed arrays, SYMMETRIC_MEAN, ghosts); lists set by
 * the caller. */
static mfree_particles_t *cloud_set(mfree_context_t *ctx, cloud_t *c) {
  mfree_particles_t *ps = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, 2, c->n, &ps));
  assert_ok(ctx, mfree_particles_set_num_ghost(ps, c->nghost));
  assert_ok(ctx, mfree_particles_set_positions(ps, c->x, MFREE_LAYOUT_AOS, 2, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_support(ps, c->h, 1, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_masses(ps, c->m, 1, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_densities(ps, c->rho, 1, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_search(ps, MFREE_SEARCH_SYMMETRIC_MEAN, 2.0));
  return ps;
}

static mfree_approximant_t *make_approx(mfree_context_t *ctx, mfree_particles_t *ps, int method) {
  mfree_approximant_t *a = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, (mfree_method_t)method, &a));
  assert_ok(ctx, mfree_approximant_set_derivatives(a, MFREE_DERIV_GRADIENT));
  assert_ok(ctx, mfree_approximant_setup(a));
  return a;
}

static const int corrected[] = {MFREE_METHOD_RANDLES_LIBERSKY, MFREE_METHOD_KB_METHOD1,
                                MFREE_METHOD_MLS, MFREE_METHOD_RKPM, MFREE_METHOD_KB_METHOD3};

/* grad_i W(x_i - x_j, h) of the 2D cubic spline (000 eq 26, C = 10 / (7 pi h^2)),
 * written as mfree's kernel evaluates it. */
static void cubic_dwdx(const double *xi, const double *xj, double h, double *g) {
  const double d0 = xj[0] - xi[0], d1 = xj[1] - xi[1];
  const double r = sqrt(d0 * d0 + d1 * d1), ih = 1.0 / h, q = r * ih;
  double df = 0.0;
  if (q < 1.0) df = -3.0 * q + 2.25 * q * q;
  else if (q < 2.0) df = -0.75 * (2.0 - q) * (2.0 - q);
  const double dw = 10.0 / (7.0 * M_PI) * ih * ih * ih * df;
  g[0] = -dw * d0 / r;
  g[1] = -dw * d1 / r;
}

/* Plain SPH: gi is the host's dwdx, gj exactly -gi; the antisymmetric form is gi. */
static void test_sph_is_dwdx(void **state) {
  (void)state;
  cloud_t c;
  make_cloud(&c, 1);
  mfree_context_t *ctx = NULL;
  assert_ok(ctx, mfree_context_create(&ctx));
  mfree_particles_t *ps = cloud_set(ctx, &c);
  assert_ok(ctx, mfree_particles_set_pairs(ps, c.np, c.pi, c.pj, 0, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_setup(ps));
  int64_t np = -1;
  assert_ok(ctx, mfree_particles_get_num_pairs(ps, &np));
  assert_int_equal(np, c.np);
  mfree_approximant_t *a = make_approx(ctx, ps, MFREE_METHOD_SPH);
  double *gi = malloc(sizeof(double) * 3 * c.np), *gj = malloc(sizeof(double) * 3 * c.np);
  double *ga = malloc(sizeof(double) * 2 * c.np);
  assert_ok(ctx, mfree_approximant_get_pair_gradients(a, gi, gj, 3, 3 * c.np));
  assert_ok(ctx, mfree_approximant_get_pair_gradients_antisymmetric(a, ga, 2, 2 * c.np));
  double worst = 0.0;
  for (int64_t k = 0; k < c.np; ++k) {
    const int i = c.pi[k], j = c.pj[k];
    double g[2];
    cubic_dwdx(c.x + 2 * i, c.x + 2 * j, 0.5 * (c.h[i] + c.h[j]), g);
    for (int d = 0; d < 2; ++d) {
      const double e = fabs(gi[3 * k + d] - g[d]) / (fabs(g[0]) + fabs(g[1]));
      if (e > worst) worst = e;
      assert_true(gj[3 * k + d] == -gi[3 * k + d]);
      assert_true(ga[2 * k + d] == gi[3 * k + d]);
    }
  }
  print_message("SPH pair gradients vs the cubic spline's dwdx: %.2e relative\n", worst);
  assert_true(worst <= 1e-14);
  free(gi);
  free(gj);
  free(ga);
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
  mfree_context_destroy(&ctx);
  free_cloud(&c);
}

/* The corrected methods in a host pair loop: the gradient of a linear field is exact at
 * every real particle (those next to the virtual particles included). */
static void test_linear_fields(void **state) {
  (void)state;
  cloud_t c;
  make_cloud(&c, 2);
  mfree_context_t *ctx = NULL;
  assert_ok(ctx, mfree_context_create(&ctx));
  mfree_particles_t *ps = cloud_set(ctx, &c);
  assert_ok(ctx, mfree_particles_set_pairs(ps, c.np, c.pi, c.pj, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_setup(ps));
  double *gi = malloc(sizeof(double) * 2 * c.np), *gj = malloc(sizeof(double) * 2 * c.np);
  double u[NMAX], du[2 * NMAX];
  const double b0 = 3.0, b1 = -5.0;
  for (int p = 0; p < c.n; ++p) u[p] = 2.0 + b0 * c.x[2 * p] + b1 * c.x[2 * p + 1];
  for (size_t q = 0; q < sizeof corrected / sizeof corrected[0]; ++q) {
    mfree_approximant_t *a = make_approx(ctx, ps, corrected[q]);
    assert_ok(ctx, mfree_approximant_get_pair_gradients(a, gi, gj, 2, 2 * c.np));
    memset(du, 0, sizeof du);
    for (int64_t k = 0; k < c.np; ++k) { /* the host's loop: V_j (u_j - u_i) g */
      const int i = c.pi[k], j = c.pj[k];
      const double vi = c.m[i] / c.rho[i], vj = c.m[j] / c.rho[j];
      for (int d = 0; d < 2; ++d) {
        du[2 * i + d] += vj * (u[j] - u[i]) * gi[2 * k + d];
        du[2 * j + d] += vi * (u[i] - u[j]) * gj[2 * k + d];
      }
    }
    double worst = 0.0;
    for (int p = 0; p < NREAL; ++p) {
      const double e = fmax(fabs(du[2 * p] - b0), fabs(du[2 * p + 1] - b1)) / fabs(b1);
      if (e > worst) worst = e;
    }
    print_message("method %d: linear field gradient error %.2e\n", corrected[q], worst);
    assert_true(worst <= 1e-12);
    /* corrected gradients are not antisymmetric */
    double asym = 0.0;
    for (int64_t k = 0; k < c.np; ++k) asym = fmax(asym, fabs(gi[2 * k] + gj[2 * k]));
    assert_true(asym > 1e-6);
    mfree_approximant_destroy(&a);
  }
  free(gi);
  free(gj);
  mfree_particles_destroy(&ps);
  mfree_context_destroy(&ctx);
  free_cloud(&c);
}

/* Pair lists and CSR lists (each row unsorted, without the particle itself, as a host
 * builds them) of the same neighbourhoods: the same rows and tables, bit for bit, for
 * one and for two threads. */
static void test_pairs_equal_csr(void **state) {
  (void)state;
  cloud_t c;
  make_cloud(&c, 3);
  const int nown = NREAL;
  int64_t *rowptr = calloc((size_t)nown + 1, sizeof(int64_t));
  int32_t *cols = malloc(sizeof(int32_t) * 2 * c.np);
  for (int64_t k = 0; k < c.np; ++k) {
    if (c.pi[k] < nown) ++rowptr[c.pi[k] + 1];
    if (c.pj[k] < nown) ++rowptr[c.pj[k] + 1];
  }
  for (int p = 0; p < nown; ++p) rowptr[p + 1] += rowptr[p];
  int64_t *fill = malloc(sizeof(int64_t) * nown);
  memcpy(fill, rowptr, sizeof(int64_t) * nown);
  for (int64_t k = 0; k < c.np; ++k) {
    if (c.pi[k] < nown) cols[fill[c.pi[k]]++] = c.pj[k];
    if (c.pj[k] < nown) cols[fill[c.pj[k]]++] = c.pi[k];
  }
  for (int threads = 1; threads <= 2; ++threads) {
    mfree_context_t *ctx = NULL;
    assert_ok(ctx, mfree_context_create(&ctx));
    assert_ok(ctx, mfree_context_set_num_threads(ctx, threads));
    mfree_particles_t *pp = cloud_set(ctx, &c), *pc = cloud_set(ctx, &c);
    assert_ok(ctx, mfree_particles_set_pairs(pp, c.np, c.pi, c.pj, 0, MFREE_BORROW));
    assert_ok(ctx, mfree_particles_set_neighbors(pc, rowptr, cols, 0, MFREE_BORROW));
    assert_ok(ctx, mfree_particles_setup(pp));
    assert_ok(ctx, mfree_particles_setup(pc));
    int64_t nnz_p = 0, nnz_c = 0;
    assert_ok(ctx, mfree_particles_get_neighbor_nnz(pp, &nnz_p));
    assert_ok(ctx, mfree_particles_get_neighbor_nnz(pc, &nnz_c));
    assert_int_equal(nnz_p, nnz_c);
    int64_t *rp1 = malloc(sizeof(int64_t) * (nown + 1)), *rp2 = malloc(sizeof(int64_t) * (nown + 1));
    int32_t *c1 = malloc(sizeof(int32_t) * nnz_p), *c2 = malloc(sizeof(int32_t) * nnz_p);
    assert_ok(ctx, mfree_particles_get_neighbors(pp, rp1, c1));
    assert_ok(ctx, mfree_particles_get_neighbors(pc, rp2, c2));
    assert_memory_equal(rp1, rp2, sizeof(int64_t) * (nown + 1));
    assert_memory_equal(c1, c2, sizeof(int32_t) * nnz_p);
    free(rp1);
    free(rp2);
    free(c1);
    free(c2);
    const int methods[] = {MFREE_METHOD_SPH, MFREE_METHOD_RANDLES_LIBERSKY, MFREE_METHOD_KB_METHOD1,
                           MFREE_METHOD_MLS};
    for (int q = 0; q < 4; ++q) {
      mfree_approximant_t *ap = make_approx(ctx, pp, methods[q]), *ac = make_approx(ctx, pc, methods[q]);
      int64_t n1 = 0, n2 = 0;
      assert_ok(ctx, mfree_approximant_get_nnz(ap, &n1));
      assert_ok(ctx, mfree_approximant_get_nnz(ac, &n2));
      assert_int_equal(n1, n2);
      int64_t *r1 = malloc(sizeof(int64_t) * (nown + 1)), *r2 = malloc(sizeof(int64_t) * (nown + 1));
      int32_t *k1 = malloc(sizeof(int32_t) * n1), *k2 = malloc(sizeof(int32_t) * n1);
      double *v1 = malloc(sizeof(double) * n1), *v2 = malloc(sizeof(double) * n1);
      for (int d = 0; d < 2; ++d) {
        assert_ok(ctx, mfree_approximant_assemble_csr(ap, MFREE_DERIV_GRADIENT, d, r1, k1, v1));
        assert_ok(ctx, mfree_approximant_assemble_csr(ac, MFREE_DERIV_GRADIENT, d, r2, k2, v2));
        assert_memory_equal(r1, r2, sizeof(int64_t) * (nown + 1));
        assert_memory_equal(k1, k2, sizeof(int32_t) * n1);
        assert_memory_equal(v1, v2, sizeof(double) * n1);
      }
      free(r1);
      free(r2);
      free(k1);
      free(k2);
      free(v1);
      free(v2);
      mfree_approximant_destroy(&ap);
      mfree_approximant_destroy(&ac);
    }
    mfree_particles_destroy(&pp);
    mfree_particles_destroy(&pc);
    mfree_context_destroy(&ctx);
  }
  free(fill);
  free(rowptr);
  free(cols);
  free_cloud(&c);
}

/* 1,000 steps of a weakly compressible pair-loop code (pressure from a linear equation
 * of state, continuity density): with the antisymmetrised RL gradient the total
 * momentum stays at its initial zero to round-off; with the one-sided RL gradient the
 * run stays finite. Pairs are rebuilt every step (from mfree's own search). */
static void run_steps(int antisym, double *pmax, double *vmax) {
  cloud_t c;
  make_cloud(&c, 4);
  free(c.pi);
  free(c.pj);
  const int n = c.n;
  double v[2 * NMAX] = {0}, dv[2 * NMAX], drho[NMAX], rho0[NMAX];
  for (int p = 0; p < n; ++p) rho0[p] = 1000.0; /* the densities start 0-5 % above it */
  mfree_context_t *ctx = NULL;
  assert_ok(ctx, mfree_context_create(&ctx));
  /* ghosts move and carry momentum too here: every particle is owned, so that the
   * momentum sum runs over all of them */
  mfree_particles_t *search = NULL, *ps = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, 2, n, &search));
  assert_ok(ctx, mfree_particles_set_positions(search, c.x, MFREE_LAYOUT_AOS, 2, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_support(search, c.h, 1, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_search(search, MFREE_SEARCH_SYMMETRIC_MEAN, 2.0));
  assert_ok(ctx, mfree_particles_create(ctx, 2, n, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, c.x, MFREE_LAYOUT_AOS, 2, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_support(ps, c.h, 1, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_masses(ps, c.m, 1, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_densities(ps, c.rho, 1, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_search(ps, MFREE_SEARCH_SYMMETRIC_MEAN, 2.0));
  mfree_approximant_t *a = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_RANDLES_LIBERSKY, &a));
  assert_ok(ctx, mfree_approximant_set_derivatives(a, MFREE_DERIV_GRADIENT));
  int64_t cap = 0;
  int32_t *pi = NULL, *pj = NULL;
  double *gi = NULL, *gj = NULL;
  int64_t *rowptr = malloc(sizeof(int64_t) * (n + 1));
  const double c0 = 10.0, dt = 1e-4;
  double mom0[2] = {0, 0}, scale = 0.0; /* mom0: the largest |total momentum| seen */
  *pmax = 0.0;
  for (int step = 0; step < 1000; ++step) {
    /* the host's pair search: mfree's rows, j > i */
    assert_ok(ctx, mfree_particles_setup(search));
    int64_t nnz = 0;
    assert_ok(ctx, mfree_particles_get_neighbor_nnz(search, &nnz));
    int32_t *cols = malloc(sizeof(int32_t) * nnz);
    assert_ok(ctx, mfree_particles_get_neighbors(search, rowptr, cols));
    if (nnz > cap) {
      cap = nnz;
      pi = realloc(pi, sizeof(int32_t) * cap);
      pj = realloc(pj, sizeof(int32_t) * cap);
      gi = realloc(gi, sizeof(double) * 2 * cap);
      gj = realloc(gj, sizeof(double) * 2 * cap);
    }
    int64_t np = 0;
    for (int i = 0; i < n; ++i)
      for (int64_t q = rowptr[i]; q < rowptr[i + 1]; ++q)
        if (cols[q] > i) {
          pi[np] = i;
          pj[np] = cols[q];
          ++np;
        }
    free(cols);
    assert_ok(ctx, mfree_particles_set_pairs(ps, np, pi, pj, 0, MFREE_BORROW));
    assert_ok(ctx, mfree_particles_setup(ps));
    assert_ok(ctx, mfree_approximant_setup(a));
    if (antisym) {
      assert_ok(ctx, mfree_approximant_get_pair_gradients_antisymmetric(a, gi, 2, 2 * cap));
    } else {
      assert_ok(ctx, mfree_approximant_get_pair_gradients(a, gi, gj, 2, 2 * cap));
    }
    memset(dv, 0, sizeof dv);
    memset(drho, 0, sizeof drho);
    for (int64_t k = 0; k < np; ++k) {
      const int i = pi[k], j = pj[k];
      const double *g1 = gi + 2 * k;
      double g2[2] = {-g1[0], -g1[1]};
      if (!antisym) {
        g2[0] = gj[2 * k];
        g2[1] = gj[2 * k + 1];
      }
      const double p_i = c0 * c0 * (c.rho[i] - rho0[i]), p_j = c0 * c0 * (c.rho[j] - rho0[j]);
      const double f = p_i / (c.rho[i] * c.rho[i]) + p_j / (c.rho[j] * c.rho[j]);
      for (int d = 0; d < 2; ++d) {
        dv[2 * i + d] -= c.m[j] * f * g1[d];
        dv[2 * j + d] -= c.m[i] * f * g2[d];
        drho[i] += c.m[j] * (v[2 * i + d] - v[2 * j + d]) * g1[d];
        drho[j] += c.m[i] * (v[2 * j + d] - v[2 * i + d]) * g2[d];
      }
    }
    for (int p = 0; p < n; ++p) {
      c.rho[p] += dt * drho[p];
      for (int d = 0; d < 2; ++d) {
        v[2 * p + d] += dt * dv[2 * p + d];
        c.x[2 * p + d] += dt * v[2 * p + d];
      }
      const double pr = fabs(c0 * c0 * (c.rho[p] - rho0[p]));
      if (pr > *pmax) *pmax = pr;
    }
    double mom[2] = {0, 0};
    for (int p = 0; p < n; ++p)
      for (int d = 0; d < 2; ++d) mom[d] += c.m[p] * v[2 * p + d];
    if (antisym)
      for (int d = 0; d < 2; ++d) mom0[d] = fmax(mom0[d], fabs(mom[d]));
  }
  *vmax = 0.0;
  for (int p = 0; p < n; ++p) /* the momentum moved about: sum m |v| at the end */
    scale += c.m[p] * (fabs(v[2 * p]) + fabs(v[2 * p + 1]));
  for (int p = 0; p < 2 * n; ++p) {
    assert_true(isfinite(v[p]));
    *vmax = fmax(*vmax, fabs(v[p]));
  }
  if (antisym) {
    print_message("antisymmetrised RL: |total momentum| <= %.2e over 1000 steps (scale %.2e)\n",
                  fmax(mom0[0], mom0[1]), scale);
    assert_true(scale > 0.0);
    assert_true(fmax(mom0[0], mom0[1]) <= 1e-12 * scale);
  }
  free(rowptr);
  free(pi);
  free(pj);
  free(gi);
  free(gj);
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
  mfree_particles_destroy(&search);
  mfree_context_destroy(&ctx);
}

static void test_momentum(void **state) {
  (void)state;
  double pmax = 0.0, vmax = 0.0;
  run_steps(1, &pmax, &vmax);
  print_message("antisymmetrised: max |p| %.3g, max |v| %.3g\n", pmax, vmax);
  run_steps(0, &pmax, &vmax);
  print_message("one-sided RL: max |p| %.3g, max |v| %.3g\n", pmax, vmax);
}

/* The correction data reproduce the pair gradients by the documented formulas. */
static void test_correction_layout(void **state) {
  (void)state;
  cloud_t c;
  make_cloud(&c, 5);
  mfree_context_t *ctx = NULL;
  assert_ok(ctx, mfree_context_create(&ctx));
  mfree_particles_t *ps = cloud_set(ctx, &c);
  assert_ok(ctx, mfree_particles_set_pairs(ps, c.np, c.pi, c.pj, 0, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_setup(ps));
  const int methods[] = {MFREE_METHOD_RANDLES_LIBERSKY, MFREE_METHOD_KB_METHOD1, MFREE_METHOD_MLS,
                         MFREE_METHOD_RKPM};
  const int sizes[] = {4, 7, 9, 9};
  double *gi = malloc(sizeof(double) * 2 * c.np), *gj = malloc(sizeof(double) * 2 * c.np);
  for (int q = 0; q < 4; ++q) {
    mfree_approximant_t *a = make_approx(ctx, ps, methods[q]);
    if (methods[q] == MFREE_METHOD_RKPM) { /* order 1 */
      assert_ok(ctx, mfree_approximant_set_order(a, 1));
      assert_ok(ctx, mfree_approximant_setup(a));
    }
    int32_t nc = 0;
    assert_ok(ctx, mfree_approximant_get_correction_size(a, &nc));
    assert_int_equal(nc, sizes[q]);
    const int64_t ld = nc + 1;
    double *cor = malloc(sizeof(double) * ld * NREAL);
    assert_ok(ctx, mfree_approximant_get_correction(a, cor, ld, ld * NREAL));
    assert_ok(ctx, mfree_approximant_get_pair_gradients(a, gi, gj, 2, 2 * c.np));
    double worst = 0.0;
    for (int64_t k = 0; k < c.np; ++k)
      for (int side = 0; side < 2; ++side) {
        const int i = side ? c.pj[k] : c.pi[k], j = side ? c.pi[k] : c.pj[k];
        if (i >= NREAL) continue;
        const double *C = cor + ld * i, *g = (side ? gj : gi) + 2 * k;
        const double hij = 0.5 * (c.h[i] + c.h[j]), vj = c.m[j] / c.rho[j];
        const double d[2] = {c.x[2 * j] - c.x[2 * i], c.x[2 * j + 1] - c.x[2 * i + 1]};
        const double r = sqrt(d[0] * d[0] + d[1] * d[1]);
        double w = 0.0, dwdr = 0.0;
        assert_ok(ctx, mfree_kernel_eval(ctx, MFREE_KERNEL_CUBIC_SPLINE, 2, 0.0, hij, 1, &r, &w, &dwdr, NULL));
        const double gw[2] = {-dwdr * d[0] / r, -dwdr * d[1] / r}; /* grad_i w_j */
        double want[2];
        if (methods[q] == MFREE_METHOD_RANDLES_LIBERSKY) {
          for (int a2 = 0; a2 < 2; ++a2) want[a2] = C[a2] * gw[0] + C[a2 + 2] * gw[1];
        } else if (methods[q] == MFREE_METHOD_KB_METHOD1) {
          const double S = C[4], gS[2] = {C[5], C[6]};
          double gs[2];
          for (int a2 = 0; a2 < 2; ++a2) gs[a2] = gw[a2] / S - w * gS[a2] / (S * S);
          for (int a2 = 0; a2 < 2; ++a2) want[a2] = (C[a2] * gs[0] + C[a2 + 2] * gs[1]) / vj;
        } else {
          const double o = methods[q] == MFREE_METHOD_RKPM ? w * vj : w;
          const double go[2] = {methods[q] == MFREE_METHOD_RKPM ? gw[0] * vj : gw[0],
                                methods[q] == MFREE_METHOD_RKPM ? gw[1] * vj : gw[1]};
          const double p[3] = {1.0, d[0] / c.h[i], d[1] / c.h[i]};
          const double gp = C[0] * p[0] + C[1] * p[1] + C[2] * p[2];
          for (int a2 = 0; a2 < 2; ++a2) {
            const double *Gc = C + 3 * (1 + a2);
            want[a2] = (o * (Gc[0] * p[0] + Gc[1] * p[1] + Gc[2] * p[2]) + go[a2] * gp) / vj;
          }
        }
        const double s = fabs(g[0]) + fabs(g[1]) + 1e-300;
        for (int a2 = 0; a2 < 2; ++a2) worst = fmax(worst, fabs(g[a2] - want[a2]) / s);
      }
    print_message("method %d: correction data reproduce the pair gradients to %.2e\n", methods[q], worst);
    assert_true(worst <= 1e-10);
    free(cor);
    mfree_approximant_destroy(&a);
  }
  free(gi);
  free(gj);
  mfree_particles_destroy(&ps);
  mfree_context_destroy(&ctx);
  free_cloud(&c);
}

/* With global ids the rows run in id order, not in the order of the pair offsets: the
 * pair gradients are looked up, and equal those without ids up to the summation order. */
static void test_global_ids(void **state) {
  (void)state;
  cloud_t c;
  make_cloud(&c, 6);
  mfree_context_t *ctx = NULL;
  assert_ok(ctx, mfree_context_create(&ctx));
  int64_t ids[NMAX];
  for (int p = 0; p < c.n; ++p) ids[p] = 1000 + (int64_t)(c.n - p) * 7; /* reversed */
  double *g0 = malloc(sizeof(double) * 4 * c.np), *g1 = malloc(sizeof(double) * 4 * c.np);
  for (int with_ids = 0; with_ids < 2; ++with_ids) {
    mfree_particles_t *ps = cloud_set(ctx, &c);
    if (with_ids) assert_ok(ctx, mfree_particles_set_global_ids(ps, ids, MFREE_COPY));
    assert_ok(ctx, mfree_particles_set_pairs(ps, c.np, c.pi, c.pj, 0, MFREE_BORROW));
    assert_ok(ctx, mfree_particles_setup(ps));
    mfree_approximant_t *a = make_approx(ctx, ps, MFREE_METHOD_RANDLES_LIBERSKY);
    double *g = with_ids ? g1 : g0;
    assert_ok(ctx, mfree_approximant_get_pair_gradients(a, g, g + 2 * c.np, 2, 2 * c.np));
    mfree_approximant_destroy(&a);
    mfree_particles_destroy(&ps);
  }
  double worst = 0.0, big = 0.0;
  for (int64_t k = 0; k < 4 * c.np; ++k) {
    worst = fmax(worst, fabs(g1[k] - g0[k]));
    big = fmax(big, fabs(g0[k]));
  }
  print_message("RL pair gradients with and without global ids: %.2e relative\n", worst / big);
  assert_true(worst <= 1e-12 * big);
  free(g0);
  free(g1);
  mfree_context_destroy(&ctx);
  free_cloud(&c);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_sph_is_dwdx),       cmocka_unit_test(test_linear_fields),
      cmocka_unit_test(test_pairs_equal_csr),   cmocka_unit_test(test_correction_layout),
      cmocka_unit_test(test_momentum),          cmocka_unit_test(test_global_ids),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
