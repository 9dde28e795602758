/* Degenerate geometry for every method: particles on a line in 2D, on a
 * (tilted) plane in 3D, coincident particles, an isolated particle, clouds of 1, 2 and 3
 * particles in 1D, 2D and 3D, and supports smaller than the spacing. For every method
 * (and the orders its basis allows), without and with the lower-order fallback:
 *  - setup never returns a negative status (the input is valid) and never crashes;
 *  - a positive status if and only if sites failed, with a message on the context, and
 *    the failed sites listed by mfree_approximant_get_site_status (count = nfailed);
 *  - every entry of every table built is finite, and the rows of failed sites are zero;
 *  - the order used is -1 exactly at failed sites and never above the set order;
 *  - with MFREE_FALLBACK_LOWER_ORDER no site fails (Shepard always has the site itself),
 *    and a site that succeeded without the fallback keeps its order;
 *  - apply to a finite field gives finite values at every site. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"

enum { MAXN = 32 };

typedef struct {
  const char *name;
  int dim;
  int n;
  double x[3 * MAXN];
  double h;
} config_t;

static int add(config_t *c, double x, double y, double z) {
  c->x[3 * c->n] = x, c->x[3 * c->n + 1] = y, c->x[3 * c->n + 2] = z;
  return c->n++;
}

static int make_configs(config_t *cfg) {
  int k = 0;
  const double d = 0.1;
  config_t *c;
  c = &cfg[k++], *c = (config_t){"line in 2D", 2, 0, {0}, 1.5 * d};
  for (int i = 0; i < 8; ++i) add(c, d * i, 0.1 + 0.5 * d * i, 0);
  c = &cfg[k++], *c = (config_t){"tilted plane in 3D", 3, 0, {0}, 1.5 * d};
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) add(c, d * i, d * j, 0.2 + 0.05 * i + 0.05 * j);
  c = &cfg[k++], *c = (config_t){"line in 3D", 3, 0, {0}, 1.5 * d};
  for (int i = 0; i < 6; ++i) add(c, d * i, 0.5 * d * i, 0.25 * d * i);
  c = &cfg[k++], *c = (config_t){"coincident pairs in a 2D lattice", 2, 0, {0}, 1.5 * d};
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) add(c, d * i, d * j, 0);
  memcpy(&c->x[3 * 6], &c->x[3 * 5], 3 * sizeof(double));
  memcpy(&c->x[3 * 15], &c->x[3 * 14], 3 * sizeof(double));
  c = &cfg[k++], *c = (config_t){"all coincident in 2D", 2, 0, {0}, 1.5 * d};
  for (int i = 0; i < 5; ++i) add(c, 0.3, 0.3, 0);
  c = &cfg[k++], *c = (config_t){"coincident in 1D", 1, 0, {0}, 1.5 * d};
  add(c, 0.0, 0, 0), add(c, 0.1, 0, 0), add(c, 0.1, 0, 0), add(c, 0.2, 0, 0);
  c = &cfg[k++], *c = (config_t){"isolated particle beside a 2D lattice", 2, 0, {0}, 1.5 * d};
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) add(c, d * i, d * j, 0);
  add(c, 5.0, 5.0, 0);
  for (int dim = 1; dim <= 3; ++dim)
    for (int n = 1; n <= 3; ++n) {
      static char names[9][40];
      snprintf(names[3 * (dim - 1) + n - 1], 40, "cloud of %d in %dD", n, dim);
      c = &cfg[k++], *c = (config_t){names[3 * (dim - 1) + n - 1], dim, 0, {0}, 1.5 * d};
      add(c, 0.0, 0.0, 0.0);
      if (n > 1) add(c, d, 0.3 * d * (dim > 1), 0.2 * d * (dim > 2));
      if (n > 2) add(c, 0.4 * d, d * (dim > 1), 0.7 * d * (dim > 2));
    }
  c = &cfg[k++], *c = (config_t){"support below the spacing, 2D lattice", 2, 0, {0}, 0.2 * d};
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) add(c, d * i, d * j, 0);
  c = &cfg[k++], *c = (config_t){"support below the spacing, 3D lattice", 3, 0, {0}, 0.3 * d};
  for (int p = 0; p < 27; ++p) add(c, d * (p % 3), d * (p / 3 % 3), d * (p / 9));
  return k;
}

typedef struct {
  mfree_method_t method;
  int order; /* -1: the method's default */
  const char *name;
} method_t;

static const method_t METHODS[] = {
    {MFREE_METHOD_SPH, -1, "SPH"},
    {MFREE_METHOD_SPH_SYMMETRIC, -1, "SPH symmetric"},
    {MFREE_METHOD_SHEPARD, -1, "Shepard"},
    {MFREE_METHOD_MLS, 0, "MLS 0"},
    {MFREE_METHOD_MLS, 1, "MLS 1"},
    {MFREE_METHOD_MLS, 2, "MLS 2"},
    {MFREE_METHOD_MLS, 3, "MLS 3"},
    {MFREE_METHOD_RKPM, 1, "RKPM 1"},
    {MFREE_METHOD_RKPM, 2, "RKPM 2"},
    {MFREE_METHOD_JOHNSON_BEISSEL, -1, "Johnson-Beissel"},
    {MFREE_METHOD_RANDLES_LIBERSKY, -1, "Randles-Libersky"},
    {MFREE_METHOD_KB_METHOD1, -1, "KB 1"},
    {MFREE_METHOD_KB_METHOD2, 1, "KB 2 order 1"},
    {MFREE_METHOD_KB_METHOD2, 2, "KB 2 order 2"},
    {MFREE_METHOD_KB_METHOD3, -1, "KB 3"},
    {MFREE_METHOD_MSPH, 1, "MSPH 1"},
    {MFREE_METHOD_MSPH, 2, "MSPH 2"},
    {MFREE_METHOD_SSPH, 1, "SSPH 1"},
    {MFREE_METHOD_SSPH, 2, "SSPH 2"},
    {MFREE_METHOD_SSPH, 3, "SSPH 3"},
};

static mfree_context_t *ctx;
static int findings, positive, failed_sites, rescued_sites;

#define CHECK(cond, ...)                                                                 \
  do {                                                                                   \
    if (!(cond)) {                                                                       \
      if (findings < 60) {                                                               \
        print_message("%s / %s%s: ", c->name, m->name, fb ? " + fallback" : "");         \
        print_message(__VA_ARGS__);                                                      \
        print_message("\n");                                                             \
      }                                                                                  \
      findings++;                                                                        \
    }                                                                                    \
  } while (0)

static int all_finite(const double *v, int64_t n) {
  for (int64_t i = 0; i < n; ++i)
    if (!isfinite(v[i])) return 0;
  return 1;
}

/* One method on one configuration; returns the per-site status array in st_out. */
static void run_one(const config_t *c, const method_t *m, int fb, mfree_particles_t *ps,
                    const int32_t *st_nofb, const int32_t *order_nofb, int32_t *st_out,
                    int32_t *order_out) {
  mfree_approximant_t *a = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, m->method, &a));
  if (m->order >= 0) assert_ok(ctx, mfree_approximant_set_order(a, m->order));
  int flags = MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT | MFREE_DERIV_HESSIAN;
  if (mfree_approximant_set_derivatives(a, flags) != MFREE_SUCCESS) {
    flags = MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT;
    if (mfree_approximant_set_derivatives(a, flags) != MFREE_SUCCESS) {
      flags = MFREE_DERIV_GRADIENT;
      assert_ok(ctx, mfree_approximant_set_derivatives(a, flags));
    }
  }
  if (fb) assert_ok(ctx, mfree_approximant_set_fallback(a, MFREE_FALLBACK_LOWER_ORDER));
  mfree_context_set_error(ctx, MFREE_SUCCESS, "");
  mfree_status_t st = mfree_approximant_setup(a);
  if (st == MFREE_ERR_UNSUPPORTED && (flags & MFREE_DERIV_HESSIAN)) {
    /* order-1 bases of MSPH, SSPH and KB 2 have no second derivatives (setup says so) */
    flags &= ~MFREE_DERIV_HESSIAN;
    assert_ok(ctx, mfree_approximant_set_derivatives(a, flags));
    mfree_context_set_error(ctx, MFREE_SUCCESS, "");
    st = mfree_approximant_setup(a);
  }
  char msg[512] = "";
  mfree_context_get_last_error(ctx, NULL, msg, sizeof msg);
  CHECK(st >= 0, "setup returned %d (%s): %s", (int)st, mfree_status_string(st), msg);
  if (st < 0) {
    mfree_approximant_destroy(&a);
    for (int i = 0; i < c->n; ++i) st_out[i] = -1, order_out[i] = -1;
    return;
  }
  const int n = c->n;
  int32_t nsites = 0, nfailed = -1;
  assert_ok(ctx, mfree_approximant_get_num_sites(a, &nsites));
  assert_int_equal(nsites, n);
  assert_ok(ctx, mfree_approximant_get_site_status(a, st_out, &nfailed));
  int count = 0;
  for (int i = 0; i < n; ++i) count += st_out[i] != 0;
  CHECK(count == nfailed, "nfailed %d but %d nonzero site statuses", (int)nfailed, count);
  CHECK((st > 0) == (nfailed > 0), "status %d with %d failed sites", (int)st, (int)nfailed);
  if (st > 0) CHECK(msg[0] != '\0', "positive status without a message");
  for (int i = 0; i < n; ++i)
    CHECK(st_out[i] >= 0, "site %d has the negative status %d", i, (int)st_out[i]);
  if (!fb) positive += st > 0, failed_sites += nfailed;
  if (fb)
    for (int i = 0; i < n; ++i) rescued_sites += st_nofb[i] != 0 && st_out[i] == 0;

  assert_ok(ctx, mfree_approximant_get_site_order(a, order_out));
  const int set_order = m->order;
  for (int i = 0; i < n; ++i) {
    CHECK((order_out[i] == -1) == (st_out[i] != 0), "site %d: order %d, status %d", i,
          (int)order_out[i], (int)st_out[i]);
    if (set_order >= 0 && st_out[i] == 0)
      CHECK(order_out[i] <= set_order, "site %d uses order %d above %d", i, (int)order_out[i],
            set_order);
  }
  if (fb) {
    const int has_fallback_target = m->method != MFREE_METHOD_SPH &&
                                    m->method != MFREE_METHOD_SPH_SYMMETRIC;
    if (has_fallback_target) CHECK(nfailed == 0, "%d sites fail despite the fallback", (int)nfailed);
    for (int i = 0; i < n; ++i)
      if (st_nofb[i] == 0 && st_out[i] == 0)
        CHECK(order_out[i] == order_nofb[i], "site %d changed order %d -> %d with the fallback",
              i, (int)order_nofb[i], (int)order_out[i]);
  }

  /* every table: finite, zero rows at failed sites */
  int64_t nnz = 0;
  assert_ok(ctx, mfree_approximant_get_nnz(a, &nnz));
  int64_t *rp = malloc((size_t)(n + 1) * sizeof *rp);
  int32_t *cols = malloc((size_t)(nnz + 1) * sizeof *cols);
  double *vals = malloc((size_t)(nnz + 1) * sizeof *vals);
  const int nh = c->dim == 1 ? 1 : c->dim == 2 ? 3 : 6;
  struct { int flag; mfree_deriv_t d; int ncomp; } tabs[3] = {
      {MFREE_DERIV_VALUE, MFREE_DERIV_VALUE, 1},
      {MFREE_DERIV_GRADIENT, MFREE_DERIV_GRADIENT, c->dim},
      {MFREE_DERIV_HESSIAN, MFREE_DERIV_HESSIAN, nh}};
  for (int t = 0; t < 3; ++t) {
    if (!(flags & tabs[t].flag)) continue;
    for (int comp = 0; comp < tabs[t].ncomp; ++comp) {
      assert_ok(ctx, mfree_approximant_assemble_csr(a, tabs[t].d, comp, rp, cols, vals));
      CHECK(all_finite(vals, nnz), "table %d component %d has a non-finite entry", t, comp);
      for (int i = 0; i < n; ++i)
        if (st_out[i])
          for (int64_t k = rp[i]; k < rp[i + 1]; ++k)
            CHECK(vals[k] == 0.0, "failed site %d: table %d entry %g", i, t, vals[k]);
    }
  }
  free(rp), free(cols), free(vals);

  /* apply to a linear field */
  double u[MAXN], out[6 * MAXN];
  for (int i = 0; i < n; ++i)
    u[i] = 1.0 + c->x[3 * i] - 2.0 * c->x[3 * i + 1] + 0.5 * c->x[3 * i + 2];
  if (flags & MFREE_DERIV_VALUE) {
    assert_ok(ctx, mfree_approximant_apply(a, MFREE_OP_VALUE, 1, u, MFREE_LAYOUT_AOS, 1, out,
                                           MFREE_LAYOUT_AOS, 1));
    CHECK(all_finite(out, n), "apply VALUE gives a non-finite value");
  }
  assert_ok(ctx, mfree_approximant_apply(a, MFREE_OP_GRADIENT, 1, u, MFREE_LAYOUT_AOS, 1, out,
                                         MFREE_LAYOUT_AOS, c->dim));
  CHECK(all_finite(out, (int64_t)n * c->dim), "apply GRADIENT gives a non-finite value");
  mfree_approximant_destroy(&a);
}

static void test_degenerate_matrix(void **state) {
  (void)state;
  assert_ok(NULL, mfree_context_create(&ctx));
  static config_t cfg[32];
  const int ncfg = make_configs(cfg);
  int runs = 0;
  for (int k = 0; k < ncfg; ++k) {
    const config_t *c = &cfg[k];
    mfree_particles_t *ps = NULL;
    const double vol = pow(0.1, c->dim);
    assert_ok(ctx, mfree_particles_create(ctx, c->dim, c->n, &ps));
    assert_ok(ctx, mfree_particles_set_positions(ps, c->x, MFREE_LAYOUT_AOS, 3, MFREE_COPY));
    assert_ok(ctx, mfree_particles_set_volumes(ps, &vol, 0, MFREE_COPY));
    assert_ok(ctx, mfree_particles_set_support(ps, &c->h, 0, MFREE_COPY));
    /* valid (if degenerate) data: the particle set itself sets up cleanly */
    assert_ok(ctx, mfree_particles_setup(ps));
    for (size_t mi = 0; mi < sizeof METHODS / sizeof METHODS[0]; ++mi) {
      const method_t *m = &METHODS[mi];
      int32_t st0[MAXN], ord0[MAXN], st1[MAXN], ord1[MAXN];
      run_one(c, m, 0, ps, NULL, NULL, st0, ord0);
      run_one(c, m, 1, ps, st0, ord0, st1, ord1);
      runs += 2;
    }
    mfree_particles_destroy(&ps);
  }
  print_message("%d configurations x %d methods, %d setups; without the fallback %d setups "
                "reported %d failed sites, the fallback rescued %d; %d findings\n", ncfg,
                (int)(sizeof METHODS / sizeof METHODS[0]), runs, positive, failed_sites,
                rescued_sites, findings);
  /* the configurations are degenerate indeed: many setups fail without the fallback */
  assert_true(positive > 100);
  assert_int_equal(rescued_sites, failed_sites);
  mfree_context_destroy(&ctx);
  if (findings) fail_msg("%d findings (listed above)", findings);
}

/* Host points (sites that are not particles) at degenerate places: far from every
 * particle (no neighbour at all: it fails even with the fallback, and is reported), on top
 * of a particle, and with a support below the spacing. Every method that takes points. */
static void test_degenerate_points(void **state) {
  (void)state;
  assert_ok(NULL, mfree_context_create(&ctx));
  enum { K = 16, P = 4 };
  double x[2 * K];
  for (int p = 0; p < K; ++p) x[2 * p] = 0.1 * (p % 4), x[2 * p + 1] = 0.1 * (p / 4);
  const double h = 0.15, vol = 0.01;
  const double px[2 * P] = {7.0, 7.0, 0.1, 0.1, 0.15, 0.15, 0.305, 0.005};
  const double ph[P] = {0.15, 0.15, 0.15, 0.01};
  mfree_particles_t *ps = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, 2, K, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 2, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_volumes(ps, &vol, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  int tried = 0;
  for (size_t mi = 0; mi < sizeof METHODS / sizeof METHODS[0]; ++mi)
    for (int fb = 0; fb < 2; ++fb) {
      const method_t *m = &METHODS[mi];
      const config_t cc = {"host points", 2, K, {0}, h}, *c = &cc;
      mfree_approximant_t *a = NULL;
      assert_ok(ctx, mfree_approximant_create(ctx, ps, m->method, &a));
      if (m->order >= 0) assert_ok(ctx, mfree_approximant_set_order(a, m->order));
      if (fb) assert_ok(ctx, mfree_approximant_set_fallback(a, MFREE_FALLBACK_LOWER_ORDER));
      if (mfree_approximant_set_points(a, P, px, MFREE_LAYOUT_AOS, 2, ph, 1, MFREE_COPY) !=
          MFREE_SUCCESS) { /* particles-only methods */
        mfree_approximant_destroy(&a);
        continue;
      }
      ++tried;
      const mfree_status_t st = mfree_approximant_setup(a);
      CHECK(st > 0, "setup returned %d, expected a positive status (point 0 sees nothing)", (int)st);
      int32_t sst[P], nf = 0;
      assert_ok(ctx, mfree_approximant_get_site_status(a, sst, &nf));
      CHECK(sst[0] != 0, "the isolated point is not reported");
      int64_t nnz = 0, rp[P + 1];
      assert_ok(ctx, mfree_approximant_get_nnz(a, &nnz));
      int32_t *cols = malloc((size_t)(nnz + 1) * sizeof *cols);
      double *vals = malloc((size_t)(nnz + 1) * sizeof *vals);
      assert_ok(ctx, mfree_approximant_assemble_csr(a, MFREE_DERIV_GRADIENT, 0, rp, cols, vals));
      CHECK(all_finite(vals, nnz), "non-finite gradient entry");
      for (int i = 0; i < P; ++i)
        if (sst[i])
          for (int64_t k = rp[i]; k < rp[i + 1]; ++k) CHECK(vals[k] == 0.0, "failed point %d: %g", i, vals[k]);
      if (fb)
        for (int i = 1; i < P; ++i) CHECK(sst[i] == 0, "point %d fails despite the fallback", i);
      free(cols), free(vals);
      double u[K], out[2 * P];
      for (int p = 0; p < K; ++p) u[p] = 1.0 + x[2 * p] - x[2 * p + 1];
      assert_ok(ctx, mfree_approximant_apply(a, MFREE_OP_GRADIENT, 1, u, MFREE_LAYOUT_AOS, 1, out,
                                             MFREE_LAYOUT_AOS, 2));
      CHECK(all_finite(out, 2 * P), "apply GRADIENT at the points gives a non-finite value");
      mfree_approximant_destroy(&a);
    }
  assert_true(tried >= 20);
  mfree_particles_destroy(&ps);
  mfree_context_destroy(&ctx);
  if (findings) fail_msg("%d findings (listed above)", findings);
}

#if MFREE_T060_MESH
/* MPFEM (needs a mesh): a single element (cloud of 2, 3, 4 particles in 1D/2D), supports
 * below the spacing and above the element size (MFREE_FAIL_SUPPORT, tables still built),
 * and a host point outside the mesh (MFREE_FAIL_NEIGHBORS, zero row). */
static int mpfem_case(const char *name, int dim, int n, const double *x, double h,
                      mfree_element_t type, int nel, const int32_t *conn, int with_far_point) {
  int bad = 0;
  mfree_particles_t *ps = NULL;
  mfree_mesh_t *mesh = NULL;
  mfree_approximant_t *a = NULL;
  const double vol = 0.01;
  assert_ok(ctx, mfree_particles_create(ctx, dim, n, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, dim, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_volumes(ps, &vol, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  assert_ok(ctx, mfree_mesh_create(ctx, ps, &mesh));
  assert_ok(ctx, mfree_mesh_add_elements(mesh, type, nel, conn, 0, MFREE_COPY));
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MPFEM, &a));
  assert_ok(ctx, mfree_approximant_set_mesh(a, mesh));
  int nsites = n;
  if (with_far_point) {
    const double far[3] = {9.0, 9.0, 9.0};
    assert_ok(ctx, mfree_approximant_set_points(a, 1, far, MFREE_LAYOUT_AOS, dim, &h, 0, MFREE_COPY));
    nsites = 1;
  }
  const mfree_status_t st = mfree_approximant_setup(a);
  int32_t sst[8], nf = -1;
  if (st < 0) {
    print_message("MPFEM %s: setup returned %d\n", name, (int)st);
    bad++;
  } else {
    assert_ok(ctx, mfree_approximant_get_site_status(a, sst, &nf));
    int count = 0;
    for (int i = 0; i < nsites; ++i) count += sst[i] != 0;
    if (count != nf) print_message("MPFEM %s: nfailed %d, %d statuses\n", name, nf, count), bad++;
    if (with_far_point && (st != MFREE_FAIL_NEIGHBORS || sst[0] == 0))
      print_message("MPFEM %s: status %d for a point outside the mesh\n", name, (int)st), bad++;
    int64_t nnz = 0, rp[9];
    assert_ok(ctx, mfree_approximant_get_nnz(a, &nnz));
    int32_t cols[64];
    double vals[64], u[8], out[3 * 8];
    assert_true(nnz <= 64);
    for (int c = 0; c < dim; ++c) {
      assert_ok(ctx, mfree_approximant_assemble_csr(a, MFREE_DERIV_GRADIENT, c, rp, cols, vals));
      if (!all_finite(vals, nnz)) print_message("MPFEM %s: non-finite gradient\n", name), bad++;
      for (int i = 0; i < nsites; ++i)
        if (sst[i])
          for (int64_t k = rp[i]; k < rp[i + 1]; ++k)
            if (vals[k] != 0.0) print_message("MPFEM %s: failed site %d row not zero\n", name, i), bad++;
    }
    for (int i = 0; i < n; ++i) u[i] = 1.0 + x[dim * i];
    assert_ok(ctx, mfree_approximant_apply(a, MFREE_OP_VALUE, 1, u, MFREE_LAYOUT_AOS, 1, out,
                                           MFREE_LAYOUT_AOS, 1));
    if (!all_finite(out, nsites)) print_message("MPFEM %s: non-finite value\n", name), bad++;
  }
  mfree_approximant_destroy(&a);
  mfree_mesh_destroy(&mesh);
  mfree_particles_destroy(&ps);
  return bad;
}

static void test_degenerate_mpfem(void **state) {
  (void)state;
  assert_ok(NULL, mfree_context_create(&ctx));
  const double x1[4] = {0.0, 0.1, 0.2, 0.3};
  const int32_t c1[6] = {0, 1, 1, 2, 2, 3};
  const double x2[8] = {0, 0, 0.1, 0, 0.1, 0.1, 0, 0.1};
  const int32_t q[4] = {0, 1, 2, 3}, t[3] = {0, 1, 2};
  int bad = 0;
  bad += mpfem_case("cloud of 2 in 1D", 1, 2, x1, 0.04, MFREE_ELEMENT_LINE2, 1, c1, 0);
  bad += mpfem_case("1D, support below the spacing", 1, 4, x1, 0.01, MFREE_ELEMENT_LINE2, 3, c1, 0);
  bad += mpfem_case("1D, support above the element", 1, 4, x1, 0.5, MFREE_ELEMENT_LINE2, 3, c1, 0);
  bad += mpfem_case("1D, point outside the mesh", 1, 4, x1, 0.04, MFREE_ELEMENT_LINE2, 3, c1, 1);
  bad += mpfem_case("cloud of 3 in 2D (one triangle)", 2, 3, x2, 0.04, MFREE_ELEMENT_TRI3, 1, t, 0);
  bad += mpfem_case("cloud of 4 in 2D (one quad)", 2, 4, x2, 0.04, MFREE_ELEMENT_QUAD4, 1, q, 0);
  bad += mpfem_case("one quad, large support", 2, 4, x2, 0.5, MFREE_ELEMENT_QUAD4, 1, q, 0);
  bad += mpfem_case("one quad, point outside", 2, 4, x2, 0.04, MFREE_ELEMENT_QUAD4, 1, q, 1);
  mfree_context_destroy(&ctx);
  assert_int_equal(bad, 0);
}
#endif

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_degenerate_matrix),
      cmocka_unit_test(test_degenerate_points),
#if MFREE_T060_MESH
      cmocka_unit_test(test_degenerate_mpfem),
#endif
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
