/* Approximants at host points:
 *  - evaluating at points placed on the particles, with the particles' supports, gives
 *    the particle tables (same pattern, values to 1e-13) for every method defined away
 *    from the particles; the particles-only methods (symmetrised SPH 000 eq 47,
 *    Johnson-Beissel 000 eq 49, Randles-Libersky 000 eq 68, all "evaluated at nodes
 *    only", 000 Sects. 4.4.1, 4.4.2, 4.4.6) refuse points with MFREE_ERR_UNSUPPORTED;
 *  - borrowed points (and borrowed particle positions) that moved, followed by
 *    mfree_approximant_update, give the tables of a fresh setup;
 *  - in a periodic box MLS reproduces linear and quadratic fields across the boundary
 *    in nearest-image local coordinates (check_reproduction and an independent check on
 *    the exported CSR), and the tables are invariant under a periodic translation of
 *    all particles. */
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

#define NMAX 512

/* (mfree_test_full_matrix: unoptimised builds check a reduced matrix, noted at each loop) */

typedef struct {
  int dim, n;
  double x[NMAX * 3], h[NMAX], v[NMAX];
} cloud_t;

/* Jittered lattice, m per axis, cell-centred in [0,1)^dim (offsets +-30 % of the
 * spacing), supports hf * spacing * (1 .. 1 + hvar), volumes spacing^dim (0.8 .. 1.2). */
static void make_cloud(cloud_t *c, int dim, int m, double hf, double hvar, uint64_t seed) {
  mfree_rng_t r;
  mfree_rng_seed(&r, seed);
  const double dx = 1.0 / m;
  c->dim = dim;
  c->n = 1;
  for (int d = 0; d < dim; ++d) c->n *= m;
  assert_true(c->n <= NMAX);
  for (int i = 0; i < c->n; ++i) {
    int rest = i;
    for (int d = 0; d < dim; ++d) {
      c->x[i * dim + d] = ((rest % m) + 0.5 + 0.3 * (2.0 * mfree_rng_uniform(&r) - 1.0)) * dx;
      rest /= m;
    }
    c->h[i] = hf * dx * (1.0 + hvar * mfree_rng_uniform(&r));
    c->v[i] = pow(dx, dim) * (0.8 + 0.4 * mfree_rng_uniform(&r));
  }
}

static double radius_of(mfree_kernel_t k) {
  double R = 0.0;
  assert_ok(ctx, mfree_kernel_get_support_radius(ctx, k, 0.0, &R));
  return R;
}

static mfree_particles_t *make_set(const cloud_t *c, mfree_kernel_t k, mfree_search_t conv,
                                   mfree_mem_t mem) {
  mfree_particles_t *ps = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, c->dim, c->n, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, c->x, MFREE_LAYOUT_AOS, c->dim, mem));
  assert_ok(ctx, mfree_particles_set_support(ps, c->h, 1, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_volumes(ps, c->v, 1, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_search(ps, conv, radius_of(k)));
  return ps;
}

static mfree_approximant_t *make_approx(mfree_particles_t *ps, mfree_method_t m, int order,
                                        mfree_kernel_t k, int flags) {
  mfree_approximant_t *a = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, m, &a));
  assert_ok(ctx, mfree_approximant_set_kernel(a, k, 0.0));
  assert_ok(ctx, mfree_approximant_set_order(a, order));
  assert_ok(ctx, mfree_approximant_set_derivatives(a, flags));
  return a;
}

static void assert_no_failed_site(const mfree_approximant_t *a) {
  int32_t nfailed = -1;
  assert_ok(ctx, mfree_approximant_get_site_status(a, NULL, &nfailed));
  assert_int_equal(nfailed, 0);
}

/* A table exported as CSR, rows sorted by column (the export need not sort them). */
typedef struct {
  int32_t ns;
  int64_t nnz;
  int64_t *rp;
  int32_t *cols;
  double *vals;
} csr_t;

static void csr_get(const mfree_approximant_t *a, mfree_deriv_t deriv, int comp, csr_t *t) {
  assert_ok(ctx, mfree_approximant_get_num_sites(a, &t->ns));
  assert_ok(ctx, mfree_approximant_get_nnz(a, &t->nnz));
  t->rp = malloc(sizeof(int64_t) * (size_t)(t->ns + 1));
  t->cols = malloc(sizeof(int32_t) * (size_t)(t->nnz + 1));
  t->vals = malloc(sizeof(double) * (size_t)(t->nnz + 1));
  assert_non_null(t->rp);
  assert_non_null(t->cols);
  assert_non_null(t->vals);
  assert_ok(ctx, mfree_approximant_assemble_csr(a, deriv, comp, t->rp, t->cols, t->vals));
  assert_int_equal(t->rp[0], 0);
  assert_int_equal(t->rp[t->ns], t->nnz);
  for (int s = 0; s < t->ns; ++s) /* insertion sort of each row by column */
    for (int64_t k = t->rp[s] + 1; k < t->rp[s + 1]; ++k)
      for (int64_t q = k; q > t->rp[s] && t->cols[q - 1] > t->cols[q]; --q) {
        const int32_t c = t->cols[q];
        const double v = t->vals[q];
        t->cols[q] = t->cols[q - 1];
        t->vals[q] = t->vals[q - 1];
        t->cols[q - 1] = c;
        t->vals[q - 1] = v;
      }
}
static void csr_free(csr_t *t) {
  free(t->rp);
  free(t->cols);
  free(t->vals);
}

/* Same pattern, values equal to tol relative to the largest magnitude; returns the
 * relative difference. */
static double csr_compare(const csr_t *a, const csr_t *b, const char *what) {
  assert_int_equal(a->ns, b->ns);
  if (a->nnz != b->nnz) fail_msg("%s: nnz %ld vs %ld", what, (long)a->nnz, (long)b->nnz);
  assert_memory_equal(a->rp, b->rp, sizeof(int64_t) * (size_t)(a->ns + 1));
  assert_memory_equal(a->cols, b->cols, sizeof(int32_t) * (size_t)a->nnz);
  double diff = 0.0, big = 0.0;
  for (int64_t k = 0; k < a->nnz; ++k) {
    diff = fmax(diff, fabs(a->vals[k] - b->vals[k]));
    big = fmax(big, fabs(a->vals[k]));
  }
  return big > 0.0 ? diff / big : diff;
}

/* Compare every table the approximants built (value, gradient and Hessian components). */
static double compare_all(const mfree_approximant_t *a, const mfree_approximant_t *b, int dim,
                          int flags, const char *what) {
  double worst = 0.0;
  const int nh = dim * (dim + 1) / 2;
  for (int t = 0; t < 3; ++t) {
    const mfree_deriv_t deriv = t == 0 ? MFREE_DERIV_VALUE : (t == 1 ? MFREE_DERIV_GRADIENT : MFREE_DERIV_HESSIAN);
    if (!(flags & deriv)) continue;
    const int ncomp = t == 0 ? 1 : (t == 1 ? dim : nh);
    for (int comp = 0; comp < ncomp; ++comp) {
      csr_t ta, tb;
      csr_get(a, deriv, comp, &ta);
      csr_get(b, deriv, comp, &tb);
      worst = fmax(worst, csr_compare(&ta, &tb, what));
      csr_free(&ta);
      csr_free(&tb);
    }
  }
  return worst;
}

typedef struct {
  mfree_method_t m;
  int order;
  int hessian;
} mcase_t;

static const mcase_t kPointMethods[] = {
    {MFREE_METHOD_SPH, 0, 1},        {MFREE_METHOD_SHEPARD, 0, 1},    {MFREE_METHOD_MLS, 0, 1},
    {MFREE_METHOD_MLS, 1, 1},        {MFREE_METHOD_MLS, 2, 1},        {MFREE_METHOD_MLS, 3, 1},
    {MFREE_METHOD_RKPM, 0, 1},       {MFREE_METHOD_RKPM, 1, 1},       {MFREE_METHOD_RKPM, 2, 1},
    {MFREE_METHOD_RKPM, 3, 1},       {MFREE_METHOD_KB_METHOD1, 1, 0}, {MFREE_METHOD_KB_METHOD2, 1, 0},
    {MFREE_METHOD_KB_METHOD2, 2, 1}, {MFREE_METHOD_KB_METHOD3, 1, 0}, {MFREE_METHOD_MSPH, 1, 0},
    {MFREE_METHOD_MSPH, 2, 1},       {MFREE_METHOD_SSPH, 1, 0},       {MFREE_METHOD_SSPH, 2, 1},
    {MFREE_METHOD_SSPH, 3, 1},
};
#define NPOINTMETHODS ((int)(sizeof kPointMethods / sizeof kPointMethods[0]))

static const mfree_kernel_t kSmooth[5] = {MFREE_KERNEL_CUBIC_SPLINE, MFREE_KERNEL_QUINTIC_SPLINE,
                                          MFREE_KERNEL_WENDLAND_C4, MFREE_KERNEL_GAUSSIAN,
                                          MFREE_KERNEL_QUARTIC_SPLINE};

/* Points on the particles, same supports: same rows to 1e-13, for each convention. */
static void test_points_on_particles(void **s) {
  (void)s;
  static cloud_t c;
  static const mfree_search_t conv[3] = {MFREE_SEARCH_GATHER, MFREE_SEARCH_SYMMETRIC_MAX,
                                         MFREE_SEARCH_SYMMETRIC_MEAN};
  for (int dim = 1; dim <= 3; ++dim)
    for (int cv = 0; cv < 3; ++cv)
      for (int mi = 0; mi < NPOINTMETHODS; ++mi) {
        const mcase_t *mc = &kPointMethods[mi];
        /* reduced matrix: one convention per method and dimension, in rotation; no
         * order 3 in 3D */
        if (!mfree_test_full_matrix() && (cv != (mi + dim) % 3 || (dim == 3 && mc->order == 3))) continue;
        const mfree_kernel_t k = kSmooth[(mi + cv) % 5];
        const int m = dim == 1 ? 30 : (dim == 2 ? 12 : (mfree_test_full_matrix() ? 6 : 5)); /* reduced: 5^3 */
        const double hf = 1.5 + (dim == 2 ? 0.4 : 0.3) * (mc->order > 1 ? mc->order - 1 : 0);
        make_cloud(&c, dim, m, hf, 0.3, 40u + (uint64_t)(dim * 3 + cv));
        const int flags = MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT | (mc->hessian ? MFREE_DERIV_HESSIAN : 0);
        mfree_particles_t *ps = make_set(&c, k, conv[cv], MFREE_COPY);
        mfree_approximant_t *ap = make_approx(ps, mc->m, mc->order, k, flags);
        mfree_approximant_t *aq = make_approx(ps, mc->m, mc->order, k, flags);
        assert_ok(ctx, mfree_approximant_setup(ap));
        /* SoA point array with a larger leading dimension, to vary the layout */
        static double xs[3 * (NMAX + 3)];
        for (int i = 0; i < c.n; ++i)
          for (int d = 0; d < dim; ++d) xs[d * (c.n + 3) + i] = c.x[i * dim + d];
        assert_ok(ctx, mfree_approximant_set_points(aq, c.n, xs, MFREE_LAYOUT_SOA, c.n + 3, c.h, 1,
                                                    MFREE_COPY));
        assert_ok(ctx, mfree_approximant_setup(aq));
        assert_no_failed_site(ap);
        assert_no_failed_site(aq);
        const double e = compare_all(ap, aq, dim, flags, "points vs particles");
        if (e > 1e-13)
          fail_msg("method %d order %d kernel %d dim %d convention %d: points differ from "
                   "particles by %.3g", (int)mc->m, mc->order, (int)k, dim, (int)conv[cv], e);
        assert_ok(ctx, mfree_approximant_destroy(&ap));
        assert_ok(ctx, mfree_approximant_destroy(&aq));
        assert_ok(ctx, mfree_particles_destroy(&ps));
      }
}

/* One support for all points (h_stride 0) equals the same value repeated. */
static void test_point_support_stride_zero(void **s) {
  (void)s;
  static cloud_t c;
  make_cloud(&c, 2, 12, 1.7, 0.0, 21);
  mfree_particles_t *ps = make_set(&c, MFREE_KERNEL_CUBIC_SPLINE, MFREE_SEARCH_SYMMETRIC_MEAN, MFREE_COPY);
  const int flags = MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT | MFREE_DERIV_HESSIAN;
  static double h[NMAX];
  for (int i = 0; i < c.n; ++i) h[i] = c.h[0];
  for (int mem = 0; mem < 2; ++mem) {
    const mfree_mem_t mm = mem ? MFREE_BORROW : MFREE_COPY;
    mfree_approximant_t *a1 = make_approx(ps, MFREE_METHOD_MLS, 2, MFREE_KERNEL_CUBIC_SPLINE, flags);
    mfree_approximant_t *a0 = make_approx(ps, MFREE_METHOD_MLS, 2, MFREE_KERNEL_CUBIC_SPLINE, flags);
    mfree_approximant_t *ap = make_approx(ps, MFREE_METHOD_MLS, 2, MFREE_KERNEL_CUBIC_SPLINE, flags);
    assert_ok(ctx, mfree_approximant_set_points(a1, c.n, c.x, MFREE_LAYOUT_AOS, 2, h, 1, mm));
    assert_ok(ctx, mfree_approximant_set_points(a0, c.n, c.x, MFREE_LAYOUT_AOS, 2, &c.h[0], 0, mm));
    assert_ok(ctx, mfree_approximant_setup(a1));
    assert_ok(ctx, mfree_approximant_setup(a0));
    assert_ok(ctx, mfree_approximant_setup(ap)); /* the particles (uniform h) */
    assert_no_failed_site(a0);
    const double e = compare_all(a1, a0, 2, flags, "stride 0 vs 1");
    if (e > 0.0) fail_msg("mem %d: h_stride 0 differs from a repeated h by %.3g", mem, e);
    const double ep = compare_all(ap, a0, 2, flags, "stride 0 vs particles");
    if (ep > 1e-13) fail_msg("mem %d: h_stride 0 points differ from the particles by %.3g", mem, ep);
    assert_ok(ctx, mfree_approximant_destroy(&a1));
    assert_ok(ctx, mfree_approximant_destroy(&a0));
    assert_ok(ctx, mfree_approximant_destroy(&ap));
  }
  assert_ok(ctx, mfree_particles_destroy(&ps));
}

/* Particles-only methods refuse points (and nothing is changed: setup still works). */
static void test_particles_only_methods(void **s) {
  (void)s;
  static cloud_t c;
  make_cloud(&c, 2, 8, 1.5, 0.0, 3);
  const mfree_method_t only[3] = {MFREE_METHOD_SPH_SYMMETRIC, MFREE_METHOD_JOHNSON_BEISSEL,
                                  MFREE_METHOD_RANDLES_LIBERSKY};
  mfree_particles_t *ps = make_set(&c, MFREE_KERNEL_CUBIC_SPLINE, MFREE_SEARCH_GATHER, MFREE_COPY);
  for (int i = 0; i < 3; ++i) {
    mfree_approximant_t *a = NULL;
    assert_ok(ctx, mfree_approximant_create(ctx, ps, only[i], &a));
    assert_error(ctx, mfree_approximant_set_points(a, c.n, c.x, MFREE_LAYOUT_AOS, 2, c.h, 1, MFREE_COPY),
                 MFREE_ERR_UNSUPPORTED, "particles");
    assert_ok(ctx, mfree_approximant_setup(a));
    int32_t ns = 0;
    assert_ok(ctx, mfree_approximant_get_num_sites(a, &ns));
    assert_int_equal(ns, c.n);
    assert_ok(ctx, mfree_approximant_destroy(&a));
  }
  assert_ok(ctx, mfree_particles_destroy(&ps));
}

/* Borrowed points moved, then update: the tables of a fresh setup at the new points
 * (the move is small enough that no particle enters or leaves a support, which the
 * equal patterns confirm); and the update really re-read the points. */
static void test_borrowed_points_update(void **s) {
  (void)s;
  static cloud_t c;
  static const mcase_t cases[] = {{MFREE_METHOD_MLS, 2, 1},
                                  {MFREE_METHOD_SSPH, 2, 1},
                                  {MFREE_METHOD_KB_METHOD1, 1, 0},
                                  {MFREE_METHOD_SHEPARD, 0, 1}};
  for (int dim = 1; dim <= 3; ++dim)
    for (size_t ci = 0; ci < sizeof cases / sizeof cases[0]; ++ci) {
      const mcase_t *mc = &cases[ci];
      const int m = dim == 1 ? 30 : (dim == 2 ? 12 : 6), npts = 20;
      make_cloud(&c, dim, m, 1.8, 0.3, 9u + (uint64_t)dim);
      mfree_rng_t r;
      mfree_rng_seed(&r, 123u + (uint64_t)dim);
      double px[20 * 3], ph[20], moved[20 * 3];
      for (int i = 0; i < npts; ++i) {
        for (int d = 0; d < dim; ++d) px[i * dim + d] = 0.1 + 0.8 * mfree_rng_uniform(&r);
        ph[i] = (1.8 / m) * (1.0 + 0.2 * mfree_rng_uniform(&r));
      }
      const int flags = MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT | (mc->hessian ? MFREE_DERIV_HESSIAN : 0);
      mfree_particles_t *ps = make_set(&c, MFREE_KERNEL_WENDLAND_C4, MFREE_SEARCH_GATHER, MFREE_COPY);
      mfree_approximant_t *ab = make_approx(ps, mc->m, mc->order, MFREE_KERNEL_WENDLAND_C4, flags);
      assert_ok(ctx, mfree_approximant_set_points(ab, npts, px, MFREE_LAYOUT_AOS, dim, ph, 1, MFREE_BORROW));
      assert_ok(ctx, mfree_approximant_setup(ab));
      csr_t t0;
      csr_get(ab, MFREE_DERIV_VALUE, 0, &t0);
      for (int i = 0; i < npts * dim; ++i) px[i] += 2e-4 * (2.0 * mfree_rng_uniform(&r) - 1.0) / m;
      memcpy(moved, px, sizeof(double) * (size_t)npts * dim);
      assert_ok(ctx, mfree_approximant_update(ab));
      assert_no_failed_site(ab);
      mfree_approximant_t *af = make_approx(ps, mc->m, mc->order, MFREE_KERNEL_WENDLAND_C4, flags);
      assert_ok(ctx, mfree_approximant_set_points(af, npts, moved, MFREE_LAYOUT_AOS, dim, ph, 1, MFREE_COPY));
      assert_ok(ctx, mfree_approximant_setup(af));
      const double e = compare_all(ab, af, dim, flags, "update vs fresh setup");
      if (e > 1e-13)
        fail_msg("method %d dim %d: updated tables differ from a fresh setup by %.3g", (int)mc->m, dim, e);
      csr_t t1;
      csr_get(ab, MFREE_DERIV_VALUE, 0, &t1);
      const double moved_by = csr_compare(&t0, &t1, "before vs after the move");
      if (!(moved_by > 1e-8))
        fail_msg("method %d dim %d: update did not see the moved points (%.3g)", (int)mc->m, dim, moved_by);
      csr_free(&t0);
      csr_free(&t1);
      assert_ok(ctx, mfree_approximant_destroy(&ab));
      assert_ok(ctx, mfree_approximant_destroy(&af));
      assert_ok(ctx, mfree_particles_destroy(&ps));
    }
}

/* Borrowed particle positions moved: particles_update + approximant_update equal a fresh
 * particle set and approximant at the new positions. */
static void test_borrowed_particles_update(void **s) {
  (void)s;
  static cloud_t c, c2;
  for (int dim = 1; dim <= 3; ++dim) {
    const int m = dim == 1 ? 30 : (dim == 2 ? 12 : (mfree_test_full_matrix() ? 6 : 5)); /* reduced: 5^3 */
    make_cloud(&c, dim, m, 1.8, 0.3, 77u + (uint64_t)dim);
    mfree_particles_t *ps = make_set(&c, MFREE_KERNEL_CUBIC_SPLINE, MFREE_SEARCH_SYMMETRIC_MAX, MFREE_BORROW);
    const int flags = MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT | MFREE_DERIV_HESSIAN;
    mfree_approximant_t *a = make_approx(ps, MFREE_METHOD_RKPM, 2, MFREE_KERNEL_CUBIC_SPLINE, flags);
    assert_ok(ctx, mfree_approximant_setup(a));
    mfree_rng_t r;
    mfree_rng_seed(&r, 5);
    for (int i = 0; i < c.n * dim; ++i) c.x[i] += 2e-4 * (2.0 * mfree_rng_uniform(&r) - 1.0) / m;
    assert_ok(ctx, mfree_particles_update(ps));
    assert_ok(ctx, mfree_approximant_update(a));
    assert_no_failed_site(a);
    c2 = c;
    mfree_particles_t *ps2 = make_set(&c2, MFREE_KERNEL_CUBIC_SPLINE, MFREE_SEARCH_SYMMETRIC_MAX, MFREE_COPY);
    mfree_approximant_t *a2 = make_approx(ps2, MFREE_METHOD_RKPM, 2, MFREE_KERNEL_CUBIC_SPLINE, flags);
    assert_ok(ctx, mfree_approximant_setup(a2));
    const double e = compare_all(a, a2, dim, flags, "moved particles");
    if (e > 1e-13) fail_msg("dim %d: updated tables differ from a fresh setup by %.3g", dim, e);
    assert_ok(ctx, mfree_approximant_destroy(&a));
    assert_ok(ctx, mfree_approximant_destroy(&a2));
    assert_ok(ctx, mfree_particles_destroy(&ps));
    assert_ok(ctx, mfree_particles_destroy(&ps2));
  }
}

/* Nearest-image displacement in the unit box. */
static double wrap(double d) { return d - floor(d + 0.5); }

static int hidx(int dim, int i, int k) {
  if (i > k) {
    const int t = i;
    i = k;
    k = t;
  }
  return i * dim - i * (i - 1) / 2 + (k - i);
}

/* Reproduction in a periodic unit box, independently of check_reproduction: for every
 * site and every monomial p of degree <= order in nearest-image displacements
 * z_j = wrap(x_j - x), sum_j Phi_j p(z_j) = p(0), sum_j G_j p(z_j) = grad p(0), sum_j H_j
 * p(z_j) = Hessian of p at 0. Returns the worst violation scaled by h^|derivative|;
 * counts pairs that straddle the boundary. */
static double periodic_violation(const mfree_approximant_t *a, int dim, int order, const double *sx,
                                 const double *sh, const double *px, int *wrapped) {
  const int nh = dim * (dim + 1) / 2;
  csr_t V, G[3], H[6];
  csr_get(a, MFREE_DERIV_VALUE, 0, &V);
  for (int d = 0; d < dim; ++d) csr_get(a, MFREE_DERIV_GRADIENT, d, &G[d]);
  for (int e = 0; e < nh; ++e) csr_get(a, MFREE_DERIV_HESSIAN, e, &H[e]);
  double worst = 0.0;
  for (int s = 0; s < V.ns; ++s) {
    /* monomials z^alpha, |alpha| <= order, as exponent triples */
    for (int ea = 0; ea <= order; ++ea)
      for (int eb = 0; eb <= (dim >= 2 ? order - ea : 0); ++eb)
        for (int ec = 0; ec <= (dim >= 3 ? order - ea - eb : 0); ++ec) {
          const int ex[3] = {ea, eb, ec};
          double sv = 0.0, sg[3] = {0, 0, 0}, shh[6] = {0, 0, 0, 0, 0, 0};
          for (int64_t k = V.rp[s]; k < V.rp[s + 1]; ++k) {
            const int j = V.cols[k];
            double p = 1.0;
            for (int d = 0; d < dim; ++d) {
              const double raw = px[j * dim + d] - sx[s * dim + d];
              const double z = wrap(raw);
              if (fabs(raw) > 0.5) ++*wrapped;
              for (int q = 0; q < ex[d]; ++q) p *= z;
            }
            sv += V.vals[k] * p;
            for (int d = 0; d < dim; ++d) sg[d] += G[d].vals[k] * p;
            for (int e = 0; e < nh; ++e) shh[e] += H[e].vals[k] * p;
          }
          const int deg = ea + eb + ec;
          const double h = sh[s];
          double hp = 1.0; /* the monomial's natural size h^deg */
          for (int q = 0; q < deg; ++q) hp *= h;
          worst = fmax(worst, fabs(sv - (deg == 0 ? 1.0 : 0.0)) / (deg == 0 ? 1.0 : hp));
          for (int d = 0; d < dim; ++d) {
            const double exact = (deg == 1 && ex[d] == 1) ? 1.0 : 0.0;
            worst = fmax(worst, fabs(sg[d] - exact) * h / (deg == 0 ? 1.0 : hp));
          }
          for (int i = 0; i < dim; ++i)
            for (int k2 = i; k2 < dim; ++k2) {
              int want[3] = {0, 0, 0};
              ++want[i];
              ++want[k2];
              const double exact =
                  (deg == 2 && ex[0] == want[0] && ex[1] == want[1] && ex[2] == want[2]) ? (i == k2 ? 2.0 : 1.0) : 0.0;
              worst = fmax(worst, fabs(shh[hidx(dim, i, k2)] - exact) * h * h / (deg == 0 ? 1.0 : hp));
            }
        }
  }
  csr_free(&V);
  for (int d = 0; d < dim; ++d) csr_free(&G[d]);
  for (int e = 0; e < nh; ++e) csr_free(&H[e]);
  return worst;
}

static void test_periodic_mls(void **s) {
  (void)s;
  static cloud_t c, ct;
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  const int32_t per[3] = {1, 1, 1};
  for (int dim = 1; dim <= 3; ++dim)
    for (int order = 1; order <= (dim == 3 ? 1 : 2); ++order) {
      const int m = dim == 1 ? 30 : (dim == 2 ? 12 : 8);
      const double hf = order == 1 ? 1.5 : 1.8;
      make_cloud(&c, dim, m, hf, 0.0, 600u + (uint64_t)(dim * 3 + order));
      const int flags = MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT | MFREE_DERIV_HESSIAN;
      mfree_particles_t *ps = make_set(&c, MFREE_KERNEL_CUBIC_SPLINE, MFREE_SEARCH_GATHER, MFREE_COPY);
      assert_ok(ctx, mfree_particles_set_periodic(ps, lo, hi, per));
      mfree_approximant_t *a = make_approx(ps, MFREE_METHOD_MLS, order, MFREE_KERNEL_CUBIC_SPLINE, flags);
      assert_ok(ctx, mfree_approximant_setup(a));
      assert_no_failed_site(a);
      double fn = 1, de = 1;
      assert_ok(ctx, mfree_approximant_check_reproduction(a, order, &fn, &de));
      if (fn > 1e-10 || de > 1e-10)
        fail_msg("dim %d order %d: periodic reproduction violated (%.3g, %.3g)", dim, order, fn, de);
      int wrapped = 0;
      const double v = periodic_violation(a, dim, order, c.x, c.h, c.x, &wrapped);
      if (v > 1e-10) fail_msg("dim %d order %d: independent periodic check %.3g", dim, order, v);
      assert_true(wrapped > 0); /* rows really reach across the boundary */

      /* host points near the boundary, reproduction across it */
      double px[16 * 3], ph[16];
      mfree_rng_t r;
      mfree_rng_seed(&r, 8);
      for (int i = 0; i < 16; ++i) {
        for (int d = 0; d < dim; ++d) {
          const double u = 0.04 * mfree_rng_uniform(&r);
          px[i * dim + d] = (i + d) % 2 ? u : 1.0 - u - 1e-9;
        }
        ph[i] = hf / m;
      }
      mfree_approximant_t *ap = make_approx(ps, MFREE_METHOD_MLS, order, MFREE_KERNEL_CUBIC_SPLINE, flags);
      assert_ok(ctx, mfree_approximant_set_points(ap, 16, px, MFREE_LAYOUT_AOS, dim, ph, 1, MFREE_COPY));
      assert_ok(ctx, mfree_approximant_setup(ap));
      assert_no_failed_site(ap);
      assert_ok(ctx, mfree_approximant_check_reproduction(ap, order, &fn, &de));
      if (fn > 1e-10 || de > 1e-10)
        fail_msg("dim %d order %d: periodic reproduction at points (%.3g, %.3g)", dim, order, fn, de);
      wrapped = 0;
      const double vp = periodic_violation(ap, dim, order, px, ph, c.x, &wrapped);
      if (vp > 1e-10) fail_msg("dim %d order %d: independent check at points %.3g", dim, order, vp);
      assert_true(wrapped > 0);

      /* translation by t (wrapped into the box) leaves every table unchanged */
      ct = c;
      const double t[3] = {0.37, 0.61, 0.23};
      for (int i = 0; i < c.n; ++i)
        for (int d = 0; d < dim; ++d) {
          double y = c.x[i * dim + d] + t[d];
          ct.x[i * dim + d] = y - floor(y);
        }
      mfree_particles_t *pt = make_set(&ct, MFREE_KERNEL_CUBIC_SPLINE, MFREE_SEARCH_GATHER, MFREE_COPY);
      assert_ok(ctx, mfree_particles_set_periodic(pt, lo, hi, per));
      mfree_approximant_t *at = make_approx(pt, MFREE_METHOD_MLS, order, MFREE_KERNEL_CUBIC_SPLINE, flags);
      assert_ok(ctx, mfree_approximant_setup(at));
      const double e = compare_all(a, at, dim, flags, "translated box");
      if (e > 1e-11) fail_msg("dim %d order %d: translated tables differ by %.3g", dim, order, e);

      assert_ok(ctx, mfree_approximant_destroy(&a));
      assert_ok(ctx, mfree_approximant_destroy(&ap));
      assert_ok(ctx, mfree_approximant_destroy(&at));
      assert_ok(ctx, mfree_particles_destroy(&ps));
      assert_ok(ctx, mfree_particles_destroy(&pt));
    }
}

int main(int argc, char **argv) {
  backend = mfree_test_backend(argc, argv);
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_points_on_particles),
      cmocka_unit_test(test_point_support_stride_zero),
      cmocka_unit_test(test_particles_only_methods),
      cmocka_unit_test(test_borrowed_points_update),
      cmocka_unit_test(test_borrowed_particles_update),
      cmocka_unit_test(test_periodic_mls),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
