/*
 * t201: the cell-list neighbour search against an O(N^2) brute-force oracle.
 *
 * Exact set equality, row by row, in 1D/2D/3D for uniform random points, jittered
 * lattices and strongly clustered points; uniform and variable supports; the three
 * conventions; periodic, open and mixed boxes; ghosts; borrowed SoA/AoS positions with
 * a leading dimension above the minimum; 10^5-particle sets (sampled rows); and the
 * edge cases of the particle-set contract (n = 0, all-to-all, coincident particles,
 * invalid borrowed data, update, periodic box too small, particles outside the box).
 *
 * The oracle computes the criterion the way the library states it (squared distance
 * d2 < lim^2, nearest image d -= L*nearbyint(d/L), lim from kappa*h), and every
 * comparison also asserts that no pair lies within a relative 1e-10 of the threshold,
 * so a mismatch is a bug and never a rounding tie.
 */
#include "testutil.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* ---------------------------------------------------------------------------------- */
/* Point clouds and the oracle                                                         */
/* ---------------------------------------------------------------------------------- */

/* The test's own copy of a particle set: x is AoS with stride 3 (unused components 0). */
typedef struct {
  int dim;
  int32_t n;
  double *x;
  double *h;
} cloud_t;

typedef struct {
  int conv;
  double kappa;
  int32_t periodic[3];
  double lo[3], hi[3];
} search_t;

static const int conventions[3] = {MFREE_SEARCH_GATHER, MFREE_SEARCH_SYMMETRIC_MAX,
                                   MFREE_SEARCH_SYMMETRIC_MEAN};

static void *xmalloc(size_t bytes) {
  void *p = malloc(bytes > 0 ? bytes : 1);
  assert_non_null(p);
  return p;
}

static cloud_t cloud_new(int dim, int32_t n) {
  cloud_t c;
  c.dim = dim;
  c.n = n;
  c.x = xmalloc(sizeof(double) * 3 * (size_t)n);
  c.h = xmalloc(sizeof(double) * (size_t)n);
  memset(c.x, 0, sizeof(double) * 3 * (size_t)n);
  for (int32_t i = 0; i < n; ++i) c.h[i] = 1.0;
  return c;
}

static void cloud_free(cloud_t *c) {
  free(c->x);
  free(c->h);
  c->x = c->h = NULL;
}

static search_t search_make(int conv, double kappa, int pmode) {
  /* pmode 0: open box; 1: periodic on every axis; 2: periodic along x only */
  search_t s;
  s.conv = conv;
  s.kappa = kappa;
  for (int c = 0; c < 3; ++c) {
    s.lo[c] = 0.0;
    s.hi[c] = 1.0;
    s.periodic[c] = pmode == 1 || (pmode == 2 && c == 0);
  }
  return s;
}

static int any_periodic(const search_t *s) { return s->periodic[0] || s->periodic[1] || s->periodic[2]; }

static double pair_d2(const cloud_t *c, const search_t *s, int32_t i, int32_t j) {
  double d2 = 0.0;
  for (int k = 0; k < c->dim; ++k) {
    double d = c->x[3 * (size_t)i + k] - c->x[3 * (size_t)j + k];
    if (s->periodic[k]) {
      const double L = s->hi[k] - s->lo[k];
      d -= L * nearbyint(d / L);
    }
    d2 += d * d;
  }
  return d2;
}

static double pair_lim(const search_t *s, double hi_, double hj) {
  const double ri = s->kappa * hi_, rj = s->kappa * hj;
  switch (s->conv) {
    case MFREE_SEARCH_GATHER: return ri;
    case MFREE_SEARCH_SYMMETRIC_MAX: return ri > rj ? ri : rj;
    default: return 0.5 * (ri + rj);
  }
}

/* Rows rows[0..nb) of the oracle (ascending j) into out[b*n ...], counts in cnt[b];
 * bad[j] != 0 excludes particle j (may be NULL). Same arithmetic as pair_d2/pair_lim
 * (rint equals nearbyint in the default rounding mode and is much cheaper in glibc);
 * several rows share one pass over the particles, which is memory-bound at 10^5.
 * Tracks the smallest relative distance of any pair to its threshold in *gap. */
enum { OB = 8 };
static void oracle_block(const cloud_t *c, const search_t *s, const int32_t *bad,
                         const int32_t *rows, int nb, int32_t *out, int64_t *cnt, double *gap) {
  const int dim = c->dim, conv = s->conv;
  const int32_t n = c->n;
  const double *x = c->x, *h = c->h, kappa = s->kappa;
  double xi[OB][3], ri[OB], L[3];
  int per[3], live[OB];
  for (int k = 0; k < 3; ++k) {
    per[k] = k < dim && s->periodic[k];
    L[k] = s->hi[k] - s->lo[k];
  }
  for (int b = 0; b < nb; ++b) {
    for (int k = 0; k < 3; ++k) xi[b][k] = x[3 * (size_t)rows[b] + k];
    ri[b] = kappa * h[rows[b]];
    live[b] = !(bad && bad[rows[b]]);
    cnt[b] = 0;
  }
  double g = *gap;
  for (int32_t j = 0; j < n; ++j) {
    if (bad && bad[j]) continue;
    const double *xj = x + 3 * (size_t)j;
    const double rj = kappa * h[j];
    for (int b = 0; b < nb; ++b) {
      if (!live[b]) continue;
      double d2 = 0.0;
      for (int k = 0; k < dim; ++k) {
        double d = xi[b][k] - xj[k];
        if (per[k]) d -= L[k] * rint(d / L[k]);
        d2 += d * d;
      }
      const double lim = conv == MFREE_SEARCH_GATHER ? ri[b]
                         : conv == MFREE_SEARCH_SYMMETRIC_MAX ? (ri[b] > rj ? ri[b] : rj)
                                                              : 0.5 * (ri[b] + rj);
      const double lim2 = lim * lim, diff = fabs(d2 - lim2);
      if (diff < 1e-6 * lim2 && diff / lim2 < g) g = diff / lim2;
      if (d2 < lim2) out[(size_t)b * n + cnt[b]++] = j;
    }
  }
  *gap = g;
}

static int64_t oracle_row(const cloud_t *c, const search_t *s, const int32_t *bad, int32_t i,
                          int32_t *out, double *gap) {
  int64_t cnt = 0;
  oracle_block(c, s, bad, &i, 1, out, &cnt, gap);
  return cnt;
}

typedef struct {
  int64_t *rowptr;
  int32_t *cols;
  int64_t nnz;
  int32_t rows;
} csr_t;

static void csr_free(csr_t *g) {
  free(g->rowptr);
  free(g->cols);
  g->rowptr = NULL;
  g->cols = NULL;
}

/* Fetch the library's lists and check the CSR structure itself. */
static csr_t fetch(mfree_context_t *ctx, mfree_particles_t *ps) {
  csr_t g;
  int32_t n = 0, ng = 0;
  assert_ok(ctx, mfree_particles_get_size(ps, &n, &ng));
  g.rows = n - ng;
  assert_ok(ctx, mfree_particles_get_neighbor_nnz(ps, &g.nnz));
  assert_true(g.nnz >= 0);
  g.rowptr = xmalloc(sizeof(int64_t) * ((size_t)g.rows + 1));
  g.cols = xmalloc(sizeof(int32_t) * (size_t)g.nnz);
  for (int32_t i = 0; i <= g.rows; ++i) g.rowptr[i] = -7;
  assert_ok(ctx, mfree_particles_get_neighbors(ps, g.rowptr, g.cols));
  assert_int_equal(g.rowptr[0], 0);
  for (int32_t i = 0; i < g.rows; ++i) assert_true(g.rowptr[i + 1] >= g.rowptr[i]);
  assert_int_equal(g.rowptr[g.rows], g.nnz);
  for (int64_t k = 0; k < g.nnz; ++k) assert_true(g.cols[k] >= 0 && g.cols[k] < n);
  return g;
}

static void report_mismatch(const cloud_t *c, const search_t *s, const char *label, int32_t i,
                            const int32_t *got, int64_t ngot, const int32_t *want, int64_t nwant) {
  int64_t a = 0, b = 0;
  while (a < ngot && b < nwant && got[a] == want[b]) ++a, ++b;
  int32_t j;
  const char *what;
  if (b < nwant && (a >= ngot || want[b] < got[a])) {
    j = want[b];
    what = "missing";
  } else {
    j = got[a];
    what = "spurious";
  }
  const double lim = pair_lim(s, c->h[i], c->h[j]);
  fail_msg("%s: row %d has %lld entries, oracle %lld; %s neighbour %d "
           "(d2 = %.17g, lim2 = %.17g, h_i = %g, h_j = %g)",
           label, (int)i, (long long)ngot, (long long)nwant, what, (int)j,
           pair_d2(c, s, i, j < c->n ? j : i), lim * lim, c->h[i], c->h[j < c->n ? j : i]);
}

/* Compare rows (all owned rows when rows == NULL) with the oracle, exact sequences. */
static void check_rows(mfree_context_t *ctx, mfree_particles_t *ps, const cloud_t *c,
                       const search_t *s, const int32_t *bad, const int32_t *rows,
                       int32_t nrows, const char *label) {
  csr_t g = fetch(ctx, ps);
  int32_t *want = xmalloc(sizeof(int32_t) * (size_t)c->n * OB);
  double gap = 1e-6;
  const int32_t count = rows ? nrows : g.rows;
  int64_t total = 0;
  for (int32_t r0 = 0; r0 < count; r0 += OB) {
    int32_t blk[OB];
    int64_t cnt[OB];
    const int nb = count - r0 < OB ? (int)(count - r0) : OB;
    for (int b = 0; b < nb; ++b) blk[b] = rows ? rows[r0 + b] : r0 + b;
    oracle_block(c, s, bad, blk, nb, want, cnt, &gap);
    for (int b = 0; b < nb; ++b) {
      const int32_t i = blk[b];
      const int64_t nw = cnt[b];
      const int32_t *w = want + (size_t)b * c->n;
      const int32_t *got = g.cols + g.rowptr[i];
      const int64_t ng = g.rowptr[i + 1] - g.rowptr[i];
      total += nw;
      if (ng != nw || (nw > 0 && memcmp(got, w, sizeof(int32_t) * (size_t)nw) != 0))
        report_mismatch(c, s, label, i, got, ng, w, nw);
    }
  }
  if (!rows) assert_int_equal(total, g.nnz);
  /* Data too close to a threshold would make the comparison depend on rounding. */
  if (!(gap > 1e-10)) fail_msg("%s: test data has a near tie (relative gap %g)", label, gap);
  free(want);
  csr_free(&g);
}

/* A particle set holding a copy of the cloud. */
static mfree_particles_t *make_set(mfree_context_t *ctx, const cloud_t *c, const search_t *s,
                                   int32_t n_ghost, int uniform_h) {
  mfree_particles_t *ps = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, c->dim, c->n, &ps));
  assert_ok(ctx, mfree_particles_set_num_ghost(ps, n_ghost));
  /* AoS with ld 3 is above the minimum in 1D and 2D. */
  assert_ok(ctx, mfree_particles_set_positions(ps, c->x, MFREE_LAYOUT_AOS, 3, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_support(ps, c->h, uniform_h ? 0 : 1, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_search(ps, (mfree_search_t)s->conv, s->kappa));
  if (any_periodic(s)) assert_ok(ctx, mfree_particles_set_periodic(ps, s->lo, s->hi, s->periodic));
  assert_ok(ctx, mfree_particles_setup(ps));
  return ps;
}

static mfree_context_t *new_ctx(void) {
  mfree_context_t *ctx = NULL;
  assert_int_equal(mfree_context_create(&ctx), MFREE_SUCCESS);
  assert_non_null(ctx);
  return ctx;
}

/* ---------------------------------------------------------------------------------- */
/* Generators                                                                          */
/* ---------------------------------------------------------------------------------- */

static double ball_volume(int dim) { return dim == 1 ? 2.0 : dim == 2 ? M_PI : 4.0 * M_PI / 3.0; }

/* Support giving about k neighbours at n points per unit volume. */
static double support_for(int dim, double n, double k, double kappa) {
  return pow(k / (n * ball_volume(dim)), 1.0 / dim) / kappa;
}

static double gauss(mfree_rng_t *r) {
  double u = mfree_rng_uniform(r);
  while (u <= 0.0) u = mfree_rng_uniform(r);
  return sqrt(-2.0 * log(u)) * cos(2.0 * M_PI * mfree_rng_uniform(r));
}

static void gen_uniform(cloud_t *c, mfree_rng_t *r) {
  for (int32_t i = 0; i < c->n; ++i)
    for (int k = 0; k < c->dim; ++k) c->x[3 * (size_t)i + k] = mfree_rng_uniform(r);
}

/* m^dim lattice points in the unit box, each displaced by up to 30% of the spacing. */
static cloud_t gen_lattice(int dim, int32_t m, mfree_rng_t *r) {
  int32_t n = 1;
  for (int k = 0; k < dim; ++k) n *= m;
  cloud_t c = cloud_new(dim, n);
  const double dx = 1.0 / m;
  for (int32_t i = 0; i < n; ++i) {
    int32_t rest = i;
    for (int k = 0; k < dim; ++k) {
      const int32_t q = rest % m;
      rest /= m;
      c.x[3 * (size_t)i + k] = (q + 0.5) * dx + 0.3 * dx * (2.0 * mfree_rng_uniform(r) - 1.0);
    }
  }
  return c;
}

/* ncl tight Gaussian clusters (sigma between smin and 10 smin) of npc points each plus nbg
 * uniform background points; h_i = eta * rho(x_i)^(-1/dim) from the generating density,
 * capped at hcap, which spans more than two orders of magnitude. */
static cloud_t gen_clustered(int dim, int ncl, int32_t npc, int32_t nbg, double smin, double eta,
                             double hcap, mfree_rng_t *r) {
  cloud_t c = cloud_new(dim, ncl * npc + nbg);
  double centre[8][3], sigma[8];
  assert_true(ncl <= 8);
  for (int q = 0; q < ncl; ++q) {
    for (int k = 0; k < dim; ++k) centre[q][k] = 0.15 + 0.7 * mfree_rng_uniform(r);
    sigma[q] = smin * pow(10.0, mfree_rng_uniform(r));
  }
  int32_t p = 0;
  for (int q = 0; q < ncl; ++q)
    for (int32_t i = 0; i < npc; ++i, ++p)
      for (int k = 0; k < dim; ++k) c.x[3 * (size_t)p + k] = centre[q][k] + sigma[q] * gauss(r);
  for (int32_t i = 0; i < nbg; ++i, ++p)
    for (int k = 0; k < dim; ++k) c.x[3 * (size_t)p + k] = mfree_rng_uniform(r);
  double hmin = INFINITY, hmax = 0.0;
  for (int32_t i = 0; i < c.n; ++i) {
    double rho = (double)nbg;
    for (int q = 0; q < ncl; ++q) {
      double r2 = 0.0;
      for (int k = 0; k < dim; ++k) {
        const double d = c.x[3 * (size_t)i + k] - centre[q][k];
        r2 += d * d;
      }
      const double s2 = sigma[q] * sigma[q];
      rho += npc * exp(-0.5 * r2 / s2) / pow(2.0 * M_PI * s2, 0.5 * dim);
    }
    double h = eta * pow(rho, -1.0 / dim);
    if (h > hcap) h = hcap;
    c.h[i] = h;
    if (h < hmin) hmin = h;
    if (h > hmax) hmax = h;
  }
  /* The set is meant to stress variable supports: insist on the spread. */
  if (!(hmax / hmin >= 100.0)) fail_msg("clustered set: h spans only %g", hmax / hmin);
  return c;
}

static void set_uniform_h(cloud_t *c, double h) {
  for (int32_t i = 0; i < c->n; ++i) c->h[i] = h;
}

static void set_variable_h(cloud_t *c, double h0, mfree_rng_t *r) {
  for (int32_t i = 0; i < c->n; ++i) c->h[i] = h0 * (0.4 + 1.2 * mfree_rng_uniform(r));
}

/* ---------------------------------------------------------------------------------- */
/* Oracle matrix: points x conventions x supports x boxes x ghosts                     */
/* ---------------------------------------------------------------------------------- */

static const double kappas[3] = {2.0, 1.3, 2.5};

/* Run every convention, uniform and variable h, open/periodic/mixed box on cloud c.
 * h0 is a reference support for kappa = 1 (divided by kappa below). When vary_h is 0 the
 * cloud's own h is used as given (clustered sets). */
static void run_matrix(cloud_t *c, double h0, int vary_h, const char *name, mfree_rng_t *r) {
  mfree_context_t *ctx = new_ctx();
  char label[160];
  int cfg = 0;
  for (int ci = 0; ci < 3; ++ci)
    for (int hv = 0; hv < (vary_h ? 2 : 1); ++hv)
      for (int pm = 0; pm < 3; ++pm, ++cfg) {
        const double kappa = kappas[cfg % 3];
        search_t s = search_make(conventions[ci], kappa, pm);
        const int uniform = vary_h && hv == 0;
        if (vary_h) {
          if (uniform) set_uniform_h(c, h0 / kappa);
          else set_variable_h(c, h0 / kappa, r);
        }
        const int32_t ng = (cfg % 2) ? c->n / 7 : 0;
        snprintf(label, sizeof label, "%s %dD conv %d kappa %g %s h, box mode %d, %d ghosts",
                 name, c->dim, s.conv, kappa, vary_h ? (uniform ? "uniform" : "variable") : "given",
                 pm, (int)ng);
        mfree_particles_t *ps = make_set(ctx, c, &s, ng, uniform);
        check_rows(ctx, ps, c, &s, NULL, NULL, 0, label);
        assert_ok(ctx, mfree_particles_destroy(&ps));
        assert_null(ps);
      }
  mfree_context_destroy(&ctx);
}

static void test_uniform_random(void **state) {
  (void)state;
  static const int32_t sizes[3] = {1500, 1500, 1400};
  mfree_rng_t r;
  mfree_rng_seed(&r, 201);
  for (int dim = 1; dim <= 3; ++dim) {
    cloud_t c = cloud_new(dim, sizes[dim - 1]);
    gen_uniform(&c, &r);
    run_matrix(&c, support_for(dim, c.n, 25.0, 1.0), 1, "uniform random", &r);
    cloud_free(&c);
  }
}

static void test_jittered_lattice(void **state) {
  (void)state;
  static const int32_t m[3] = {1200, 36, 11};
  mfree_rng_t r;
  mfree_rng_seed(&r, 202);
  for (int dim = 1; dim <= 3; ++dim) {
    cloud_t c = gen_lattice(dim, m[dim - 1], &r);
    /* h = 1.3 spacings for kappa = 2, as an SPH code would choose */
    run_matrix(&c, 2.6 / m[dim - 1], 1, "jittered lattice", &r);
    cloud_free(&c);
  }
}

static void test_clustered(void **state) {
  (void)state;
  mfree_rng_t r;
  mfree_rng_seed(&r, 203);
  for (int dim = 1; dim <= 3; ++dim) {
    /* hcap keeps kappa*h below a fifth of the periodic box for every kappa used */
    cloud_t c = gen_clustered(dim, 5, 250, 300, 1e-4, 1.3, 0.08, &r);
    run_matrix(&c, 0.0, 0, "clustered", &r);
    cloud_free(&c);
  }
}

/* ---------------------------------------------------------------------------------- */
/* Ghosts                                                                              */
/* ---------------------------------------------------------------------------------- */

static void test_ghosts(void **state) {
  (void)state;
  mfree_context_t *ctx = new_ctx();
  mfree_rng_t r;
  mfree_rng_seed(&r, 204);
  for (int dim = 1; dim <= 3; ++dim) {
    cloud_t c = cloud_new(dim, 600);
    gen_uniform(&c, &r);
    set_variable_h(&c, support_for(dim, c.n, 20.0, 2.0), &r);
    for (int ci = 0; ci < 3; ++ci) {
      search_t s = search_make(conventions[ci], 2.0, ci == 1 ? 2 : 0);
      for (int32_t ng = 0; ng <= c.n; ng += c.n / 3) {
        mfree_particles_t *ps = make_set(ctx, &c, &s, ng, 0);
        csr_t g = fetch(ctx, ps);
        assert_int_equal(g.rows, c.n - ng);
        /* Ghosts must turn up as neighbours of owned particles whenever some exist. */
        int ghost_seen = 0;
        for (int64_t k = 0; k < g.nnz; ++k) ghost_seen |= g.cols[k] >= c.n - ng;
        assert_int_equal(ghost_seen, ng > 0 && ng < c.n);
        csr_free(&g);
        check_rows(ctx, ps, &c, &s, NULL, NULL, 0, "ghosts");
        mfree_particles_destroy(&ps);
      }
    }
    cloud_free(&c);
  }
  mfree_context_destroy(&ctx);
}

/* ---------------------------------------------------------------------------------- */
/* Borrowed and copied layouts with ld above the minimum                               */
/* ---------------------------------------------------------------------------------- */

/* A host code's particle record: position, smoothing length, velocity (ld = 7). */
typedef struct {
  double x[3];
  double h;
  double v[3];
} host_particle_t;

static void move_points(cloud_t *c, mfree_rng_t *r, double amp) {
  for (int32_t i = 0; i < c->n; ++i)
    for (int k = 0; k < c->dim; ++k) c->x[3 * (size_t)i + k] += amp * (2.0 * mfree_rng_uniform(r) - 1.0);
}

static void test_borrowed_layouts(void **state) {
  (void)state;
  assert_int_equal(sizeof(host_particle_t), 7 * sizeof(double));
  mfree_context_t *ctx = new_ctx();
  mfree_rng_t r;
  mfree_rng_seed(&r, 205);
  for (int dim = 1; dim <= 3; ++dim)
    for (int ci = 0; ci < 3; ++ci) {
      const int32_t n = 700;
      cloud_t c = cloud_new(dim, n);
      gen_uniform(&c, &r);
      set_variable_h(&c, support_for(dim, n, 20.0, 2.0), &r);
      search_t s = search_make(conventions[ci], 2.0, ci);

      /* AoS struct array: positions at offset 0 and supports at offset 3, ld = 7. */
      host_particle_t *hp = xmalloc(sizeof(host_particle_t) * n);
      /* SoA with ld = n + 13, copied and borrowed. */
      const int64_t ld = n + 13;
      double *soa = xmalloc(sizeof(double) * (size_t)ld * dim);
      double *hsoa = xmalloc(sizeof(double) * n);
      for (int32_t i = 0; i < n; ++i) {
        for (int k = 0; k < 3; ++k) hp[i].x[k] = k < dim ? c.x[3 * i + k] : -1e300;
        for (int k = 0; k < 3; ++k) hp[i].v[k] = 1e300;  /* never read as a position */
        hp[i].h = c.h[i];
        for (int k = 0; k < dim; ++k) soa[k * ld + i] = c.x[3 * i + k];
        hsoa[i] = c.h[i];
      }
      for (int64_t i = n; i < ld; ++i)
        for (int k = 0; k < dim; ++k) soa[k * ld + i] = NAN;  /* padding is never read */

      mfree_particles_t *pa = NULL, *pb = NULL, *pc = NULL;
      assert_ok(ctx, mfree_particles_create(ctx, dim, n, &pa));
      assert_ok(ctx, mfree_particles_set_positions(pa, hp[0].x, MFREE_LAYOUT_AOS, 7, MFREE_BORROW));
      assert_ok(ctx, mfree_particles_set_support(pa, &hp[0].h, 7, MFREE_BORROW));
      assert_ok(ctx, mfree_particles_create(ctx, dim, n, &pb));
      assert_ok(ctx, mfree_particles_set_positions(pb, soa, MFREE_LAYOUT_SOA, ld, MFREE_BORROW));
      assert_ok(ctx, mfree_particles_set_support(pb, hsoa, 1, MFREE_BORROW));
      assert_ok(ctx, mfree_particles_create(ctx, dim, n, &pc));
      assert_ok(ctx, mfree_particles_set_positions(pc, soa, MFREE_LAYOUT_SOA, ld, MFREE_COPY));
      assert_ok(ctx, mfree_particles_set_support(pc, hsoa, 1, MFREE_COPY));
      mfree_particles_t *all[3] = {pa, pb, pc};
      for (int q = 0; q < 3; ++q) {
        assert_ok(ctx, mfree_particles_set_search(all[q], (mfree_search_t)s.conv, s.kappa));
        if (any_periodic(&s)) assert_ok(ctx, mfree_particles_set_periodic(all[q], s.lo, s.hi, s.periodic));
        assert_ok(ctx, mfree_particles_setup(all[q]));
      }
      check_rows(ctx, pa, &c, &s, NULL, NULL, 0, "borrowed AoS ld 7");
      check_rows(ctx, pb, &c, &s, NULL, NULL, 0, "borrowed SoA ld n+13");
      check_rows(ctx, pc, &c, &s, NULL, NULL, 0, "copied SoA ld n+13");

      /* Move the host's particles and change their supports: borrowed arrays are
       * re-read by setup, the copy is not. */
      cloud_t old = cloud_new(dim, n);
      memcpy(old.x, c.x, sizeof(double) * 3 * n);
      memcpy(old.h, c.h, sizeof(double) * n);
      move_points(&c, &r, 0.2 * support_for(dim, n, 20.0, 2.0));
      for (int32_t i = 0; i < n; ++i) {
        if (any_periodic(&s))
          for (int k = 0; k < dim; ++k)
            if (s.periodic[k]) c.x[3 * i + k] -= floor(c.x[3 * i + k]);
        c.h[i] *= 0.8 + 0.4 * mfree_rng_uniform(&r);
        for (int k = 0; k < dim; ++k) hp[i].x[k] = soa[k * ld + i] = c.x[3 * i + k];
        hp[i].h = hsoa[i] = c.h[i];
      }
      for (int q = 0; q < 3; ++q) assert_ok(ctx, mfree_particles_setup(all[q]));
      check_rows(ctx, pa, &c, &s, NULL, NULL, 0, "borrowed AoS ld 7, moved");
      check_rows(ctx, pb, &c, &s, NULL, NULL, 0, "borrowed SoA ld n+13, moved");
      check_rows(ctx, pc, &old, &s, NULL, NULL, 0, "copied SoA after the host moved");
      for (int q = 0; q < 3; ++q) mfree_particles_destroy(&all[q]);
      cloud_free(&old);
      cloud_free(&c);
      free(hp);
      free(soa);
      free(hsoa);
    }
  mfree_context_destroy(&ctx);
}

/* ---------------------------------------------------------------------------------- */
/* 10^5 particles: sampled rows against the O(N) per-row oracle                         */
/* ---------------------------------------------------------------------------------- */

static void sample_rows(mfree_rng_t *r, int32_t n_owned, int32_t *rows, int32_t k) {
  for (int32_t q = 0; q < k; ++q) rows[q] = (int32_t)(mfree_rng_uniform(r) * n_owned);
  rows[0] = 0;
  rows[k - 1] = n_owned - 1;
}

static void large_case(mfree_context_t *ctx, cloud_t *c, const search_t *s, int32_t ng,
                       int uniform, mfree_rng_t *r, const char *label) {
  enum { K = 1000 };
  int32_t rows[K];
  mfree_particles_t *ps = make_set(ctx, c, s, ng, uniform);
  sample_rows(r, c->n - ng, rows, K);
  check_rows(ctx, ps, c, s, NULL, rows, K, label);
  mfree_particles_destroy(&ps);
}

static void test_large(void **state) {
  (void)state;
  mfree_context_t *ctx = new_ctx();
  mfree_rng_t r;
  mfree_rng_seed(&r, 206);
  const int32_t n = 100000;
  char label[96];
  for (int dim = 2; dim <= 3; ++dim) {
    cloud_t c = cloud_new(dim, n);
    gen_uniform(&c, &r);
    const double h0 = support_for(dim, n, 30.0, 1.0);
    if (dim == 2) {
      /* gather, one support, open box */
      search_t s = search_make(MFREE_SEARCH_GATHER, 2.0, 0);
      set_uniform_h(&c, h0 / s.kappa);
      snprintf(label, sizeof label, "10^5 uniform random 2D gather");
      large_case(ctx, &c, &s, 0, 1, &r, label);
    }
    /* symmetric conventions, variable supports, periodic boxes and ghosts */
    search_t s = search_make(dim == 2 ? MFREE_SEARCH_SYMMETRIC_MAX : MFREE_SEARCH_SYMMETRIC_MEAN,
                             1.3, dim == 2 ? 2 : 1);
    set_variable_h(&c, h0 / s.kappa, &r);
    snprintf(label, sizeof label, "10^5 uniform random %dD conv %d, periodic, ghosts", dim, s.conv);
    large_case(ctx, &c, &s, 5000, 0, &r, label);
    cloud_free(&c);
  }
  /* Clustered sets at 2*10^4 (the cell list spends O(cluster size^2) on a dense cluster,
   * so 10^5 clustered particles would take tens of seconds). */
  for (int dim = 2; dim <= 3; ++dim) {
    cloud_t q = gen_clustered(dim, 6, 3000, 2000, 1e-3, 1.3, 0.05, &r);
    search_t s = search_make(dim == 2 ? MFREE_SEARCH_SYMMETRIC_MAX : MFREE_SEARCH_SYMMETRIC_MEAN,
                             2.0, dim == 2 ? 0 : 1);
    snprintf(label, sizeof label, "2*10^4 clustered %dD conv %d", dim, s.conv);
    large_case(ctx, &q, &s, dim == 2 ? 1000 : 0, 0, &r, label);
    cloud_free(&q);
  }
  mfree_context_destroy(&ctx);
}

/* ---------------------------------------------------------------------------------- */
/* Edge cases                                                                          */
/* ---------------------------------------------------------------------------------- */

static void test_empty(void **state) {
  (void)state;
  mfree_context_t *ctx = new_ctx();
  for (int dim = 1; dim <= 3; ++dim)
    for (int layout = MFREE_LAYOUT_AOS; layout <= MFREE_LAYOUT_SOA; ++layout) {
      mfree_particles_t *ps = NULL;
      const double h = 0.1;
      assert_ok(ctx, mfree_particles_create(ctx, dim, 0, &ps));
      assert_ok(ctx, mfree_particles_set_positions(ps, NULL, (mfree_layout_t)layout,
                                                   layout == MFREE_LAYOUT_AOS ? dim : 0, MFREE_BORROW));
      assert_ok(ctx, mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
      assert_ok(ctx, mfree_particles_set_search(ps, (mfree_search_t)conventions[dim - 1], 2.0));
      assert_ok(ctx, mfree_particles_setup(ps));
      int64_t nnz = -1, rowptr[1] = {-1};
      int32_t nf = -1;
      assert_ok(ctx, mfree_particles_get_neighbor_nnz(ps, &nnz));
      assert_int_equal(nnz, 0);
      assert_ok(ctx, mfree_particles_get_neighbors(ps, rowptr, NULL));
      assert_int_equal(rowptr[0], 0);
      assert_ok(ctx, mfree_particles_get_site_status(ps, NULL, &nf));
      assert_int_equal(nf, 0);
      assert_ok(ctx, mfree_particles_update(ps));
      mfree_particles_destroy(&ps);
    }
  mfree_context_destroy(&ctx);
}

static void test_all_to_all(void **state) {
  (void)state;
  mfree_context_t *ctx = new_ctx();
  mfree_rng_t r;
  mfree_rng_seed(&r, 207);
  for (int dim = 1; dim <= 3; ++dim)
    for (int ci = 0; ci < 3; ++ci)
      for (int pm = 0; pm < 2; ++pm) {
        const int32_t n = 90, ng = 10;
        cloud_t c = cloud_new(dim, n);
        gen_uniform(&c, &r);
        search_t s = search_make(conventions[ci], 2.0, 0);
        if (pm == 0) {
          /* every distance in the unit box is below 2*1 */
          set_uniform_h(&c, 1.0);
        } else {
          /* one particle with a huge support, the rest tiny: symmetric-max must link it
           * to everybody, gather only from its own row */
          set_uniform_h(&c, 1e-6);
          c.h[37] = 1e3;
        }
        mfree_particles_t *ps = make_set(ctx, &c, &s, ng, 0);
        csr_t g = fetch(ctx, ps);
        if (pm == 0) {
          assert_int_equal(g.nnz, (int64_t)(n - ng) * n);
          for (int32_t i = 0; i < n - ng; ++i)
            for (int32_t j = 0; j < n; ++j) assert_int_equal(g.cols[g.rowptr[i] + j], j);
        } else {
          assert_int_equal(g.rowptr[38] - g.rowptr[37], n);
          for (int32_t i = 0; i < n - ng; ++i) {
            int found = 0;
            for (int64_t k = g.rowptr[i]; k < g.rowptr[i + 1]; ++k) found |= g.cols[k] == 37;
            /* mean: 0.5*(2e3 + 2e-6) reaches every particle in the unit box, too */
            assert_int_equal(found, i == 37 || ci != 0);
          }
        }
        csr_free(&g);
        check_rows(ctx, ps, &c, &s, NULL, NULL, 0, "all to all");
        mfree_particles_destroy(&ps);
        cloud_free(&c);
      }
  mfree_context_destroy(&ctx);
}

static void test_coincident(void **state) {
  (void)state;
  mfree_context_t *ctx = new_ctx();
  mfree_rng_t r;
  mfree_rng_seed(&r, 208);
  for (int dim = 1; dim <= 3; ++dim)
    for (int ci = 0; ci < 3; ++ci) {
      /* 100 distinct points, each present three times at non-adjacent indices */
      const int32_t m = 100, n = 3 * m;
      cloud_t c = cloud_new(dim, n);
      for (int32_t i = 0; i < m; ++i)
        for (int k = 0; k < dim; ++k)
          c.x[3 * i + k] = c.x[3 * (i + m) + k] = c.x[3 * (i + 2 * m) + k] = mfree_rng_uniform(&r);
      set_variable_h(&c, support_for(dim, m, 8.0, 2.0), &r);
      search_t s = search_make(conventions[ci], 2.0, ci == 1 ? 1 : 0);
      mfree_particles_t *ps = make_set(ctx, &c, &s, 0, 0);
      csr_t g = fetch(ctx, ps);
      for (int32_t i = 0; i < n; ++i)
        for (int t = 1; t <= 2; ++t) {
          const int32_t j = (i + t * m) % n;
          int found = 0;
          for (int64_t k = g.rowptr[i]; k < g.rowptr[i + 1]; ++k) found |= g.cols[k] == j;
          if (!found) fail_msg("%dD: coincident particle %d missing from row %d", dim, (int)j, (int)i);
        }
      csr_free(&g);
      check_rows(ctx, ps, &c, &s, NULL, NULL, 0, "coincident");
      mfree_particles_destroy(&ps);

      /* Every particle at one point: a degenerate (zero-extent) grid. */
      for (int32_t i = 0; i < n; ++i)
        for (int k = 0; k < dim; ++k) c.x[3 * i + k] = 0.25;
      ps = make_set(ctx, &c, &s, 7, 0);
      g = fetch(ctx, ps);
      assert_int_equal(g.nnz, (int64_t)(n - 7) * n);
      csr_free(&g);
      mfree_particles_destroy(&ps);
      cloud_free(&c);
    }
  mfree_context_destroy(&ctx);
}

/* A far outlier must not blow up the cell grid and finds only itself. */
static void test_far_outlier(void **state) {
  (void)state;
  mfree_context_t *ctx = new_ctx();
  mfree_rng_t r;
  mfree_rng_seed(&r, 209);
  static const double far[3] = {1e6, 1e15, 1e300};
  for (int dim = 1; dim <= 3; ++dim)
    for (int f = 0; f < 3; ++f) {
      cloud_t c = cloud_new(dim, 400);
      gen_uniform(&c, &r);
      set_uniform_h(&c, support_for(dim, c.n, 15.0, 2.0));
      for (int k = 0; k < dim; ++k) c.x[3 * 5 + k] = far[f] * (k + 1);
      search_t s = search_make(conventions[f], 2.0, dim == 2 ? 2 : 0);
      if (s.periodic[0]) c.x[3 * 5] = 0.5;
      mfree_particles_t *ps = make_set(ctx, &c, &s, 0, 1);
      check_rows(ctx, ps, &c, &s, NULL, NULL, 0, "far outlier");
      mfree_particles_destroy(&ps);
      cloud_free(&c);
    }
  mfree_context_destroy(&ctx);
}

static void check_status(mfree_context_t *ctx, mfree_particles_t *ps, int32_t n,
                         const int32_t *bad, const char *label) {
  int32_t *st = xmalloc(sizeof(int32_t) * (size_t)n);
  int32_t nf = -1, nbad = 0;
  assert_ok(ctx, mfree_particles_get_site_status(ps, st, &nf));
  for (int32_t i = 0; i < n; ++i) {
    if (st[i] != bad[i]) fail_msg("%s: site status[%d] = %d, expected %d", label, (int)i, (int)st[i], (int)bad[i]);
    nbad += bad[i] != 0;
  }
  assert_int_equal(nf, nbad);
  free(st);
}

/* Check statuses, isolation and the remaining rows after an invalid borrowed value. */
static void check_isolated(mfree_context_t *ctx, mfree_particles_t *ps, const cloud_t *c,
                           const search_t *s, const int32_t *bad, const char *label) {
  check_status(ctx, ps, c->n, bad, label);
  csr_t g = fetch(ctx, ps);
  for (int32_t i = 0; i < g.rows; ++i) {
    if (bad[i]) assert_int_equal(g.rowptr[i + 1], g.rowptr[i]);
  }
  for (int64_t k = 0; k < g.nnz; ++k)
    if (bad[g.cols[k]]) fail_msg("%s: isolated particle %d is listed", label, (int)g.cols[k]);
  csr_free(&g);
  check_rows(ctx, ps, c, s, bad, NULL, 0, label);
}

static void test_invalid_borrowed(void **state) {
  (void)state;
  mfree_context_t *ctx = new_ctx();
  mfree_rng_t r;
  mfree_rng_seed(&r, 210);
  for (int dim = 1; dim <= 3; ++dim)
    for (int ci = 0; ci < 3; ++ci) {
      const int32_t n = 500, ng = 50, a = 17, b = 480; /* b is a ghost */
      cloud_t c = cloud_new(dim, n);
      gen_uniform(&c, &r);
      set_variable_h(&c, support_for(dim, n, 20.0, 2.0), &r);
      search_t s = search_make(conventions[ci], 2.0, ci);
      double *x = xmalloc(sizeof(double) * 3 * n), *h = xmalloc(sizeof(double) * n);
      memcpy(x, c.x, sizeof(double) * 3 * n);
      memcpy(h, c.h, sizeof(double) * n);
      int32_t *bad = xmalloc(sizeof(int32_t) * n);
      memset(bad, 0, sizeof(int32_t) * n);

      mfree_particles_t *ps = NULL;
      assert_ok(ctx, mfree_particles_create(ctx, dim, n, &ps));
      assert_ok(ctx, mfree_particles_set_num_ghost(ps, ng));
      assert_ok(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 3, MFREE_BORROW));
      assert_ok(ctx, mfree_particles_set_support(ps, h, 1, MFREE_BORROW));
      assert_ok(ctx, mfree_particles_set_search(ps, (mfree_search_t)s.conv, s.kappa));
      if (any_periodic(&s)) assert_ok(ctx, mfree_particles_set_periodic(ps, s.lo, s.hi, s.periodic));
      assert_ok(ctx, mfree_particles_setup(ps));
      check_isolated(ctx, ps, &c, &s, bad, "valid");

      /* Non-finite positions: an owned particle and a ghost. */
      x[3 * a + dim - 1] = NAN;
      x[3 * b] = -INFINITY;
      bad[a] = bad[b] = MFREE_FAIL_NONFINITE;
      assert_error(ctx, mfree_particles_setup(ps), MFREE_FAIL_NONFINITE, "particle 17:");
      check_isolated(ctx, ps, &c, &s, bad, "NaN position");

      /* Restored: everything valid again. */
      memcpy(x, c.x, sizeof(double) * 3 * n);
      memset(bad, 0, sizeof(int32_t) * n);
      assert_ok(ctx, mfree_particles_setup(ps));
      check_isolated(ctx, ps, &c, &s, bad, "restored");

      /* Supports that became zero, negative or NaN. */
      h[a] = 0.0;
      h[b] = -c.h[b];
      h[3] = NAN;
      bad[a] = bad[b] = MFREE_FAIL_INVALID_DATA;
      bad[3] = MFREE_FAIL_NONFINITE;
      /* the first failing particle's status is the call's */
      assert_error(ctx, mfree_particles_setup(ps), MFREE_FAIL_NONFINITE, "particle 3:");
      check_isolated(ctx, ps, &c, &s, bad, "bad support");
      h[3] = c.h[3];
      bad[3] = 0;
      assert_error(ctx, mfree_particles_setup(ps), MFREE_FAIL_INVALID_DATA, "particle 17:");
      check_isolated(ctx, ps, &c, &s, bad, "zero/negative support");
      mfree_particles_destroy(&ps);

      /* A borrowed uniform support (stride 0) that turns negative isolates everybody. */
      double hu = support_for(dim, n, 20.0, 2.0);
      set_uniform_h(&c, hu);
      assert_ok(ctx, mfree_particles_create(ctx, dim, n, &ps));
      assert_ok(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 3, MFREE_BORROW));
      assert_ok(ctx, mfree_particles_set_support(ps, &hu, 0, MFREE_BORROW));
      assert_ok(ctx, mfree_particles_set_search(ps, (mfree_search_t)s.conv, s.kappa));
      assert_ok(ctx, mfree_particles_setup(ps));
      s = search_make(s.conv, s.kappa, 0);
      memset(bad, 0, sizeof(int32_t) * n);
      check_isolated(ctx, ps, &c, &s, bad, "uniform borrowed support");
      hu = -1.0;
      for (int32_t i = 0; i < n; ++i) bad[i] = MFREE_FAIL_INVALID_DATA;
      assert_error(ctx, mfree_particles_setup(ps), MFREE_FAIL_INVALID_DATA, "particle 0:");
      check_isolated(ctx, ps, &c, &s, bad, "uniform support negative");
      mfree_particles_destroy(&ps);

      free(x);
      free(h);
      free(bad);
      cloud_free(&c);
    }
  mfree_context_destroy(&ctx);
}

static int csr_equal(const csr_t *a, const csr_t *b) {
  return a->rows == b->rows && a->nnz == b->nnz &&
         memcmp(a->rowptr, b->rowptr, sizeof(int64_t) * ((size_t)a->rows + 1)) == 0 &&
         memcmp(a->cols, b->cols, sizeof(int32_t) * (size_t)a->nnz) == 0;
}

static void test_update(void **state) {
  (void)state;
  mfree_context_t *ctx = new_ctx();
  mfree_rng_t r;
  mfree_rng_seed(&r, 211);
  for (int dim = 1; dim <= 3; ++dim)
    for (int ci = 0; ci < 3; ++ci) {
      const int32_t n = 500, a = 123;
      cloud_t c = cloud_new(dim, n);
      gen_uniform(&c, &r);
      const double h0 = support_for(dim, n, 20.0, 2.0);
      set_variable_h(&c, h0, &r);
      search_t s = search_make(conventions[ci], 2.0, 0);
      double *x = xmalloc(sizeof(double) * 3 * n);
      memcpy(x, c.x, sizeof(double) * 3 * n);
      int32_t *bad = xmalloc(sizeof(int32_t) * n);
      memset(bad, 0, sizeof(int32_t) * n);

      mfree_particles_t *ps = NULL;
      assert_ok(ctx, mfree_particles_create(ctx, dim, n, &ps));
      assert_status(ctx, mfree_particles_update(ps), MFREE_ERR_STATE);
      assert_ok(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 3, MFREE_BORROW));
      assert_ok(ctx, mfree_particles_set_support(ps, c.h, 1, MFREE_COPY));
      assert_ok(ctx, mfree_particles_set_search(ps, (mfree_search_t)s.conv, s.kappa));
      assert_ok(ctx, mfree_particles_setup(ps));
      csr_t before = fetch(ctx, ps);

      /* Move every particle: update keeps the lists. */
      move_points(&c, &r, 0.5 * h0);
      memcpy(x, c.x, sizeof(double) * 3 * n);
      assert_ok(ctx, mfree_particles_update(ps));
      csr_t kept = fetch(ctx, ps);
      assert_true(csr_equal(&before, &kept));
      check_status(ctx, ps, n, bad, "update");
      csr_free(&kept);
      /* ... which must differ from a fresh search, or the check above proves nothing. */
      {
        int32_t *want = xmalloc(sizeof(int32_t) * n);
        double gap = INFINITY;
        int differs = 0;
        for (int32_t i = 0; i < n && !differs; ++i) {
          const int64_t nw = oracle_row(&c, &s, NULL, i, want, &gap);
          differs = nw != before.rowptr[i + 1] - before.rowptr[i] ||
                    memcmp(want, before.cols + before.rowptr[i], sizeof(int32_t) * (size_t)nw) != 0;
        }
        assert_true(differs);
        free(want);
      }

      /* A particle turning non-finite is re-validated and isolated by update. */
      x[3 * a] = NAN;
      assert_error(ctx, mfree_particles_update(ps), MFREE_FAIL_NONFINITE, "particle 123:");
      bad[a] = MFREE_FAIL_NONFINITE;
      csr_t iso = fetch(ctx, ps);
      /* expected: the old lists with a removed */
      for (int32_t i = 0, p = 0; i < n; ++i) {
        assert_int_equal(iso.rowptr[i], p);
        if (i != a)
          for (int64_t k = before.rowptr[i]; k < before.rowptr[i + 1]; ++k)
            if (before.cols[k] != a) assert_int_equal(iso.cols[p++], before.cols[k]);
        assert_int_equal(iso.rowptr[i + 1], p);
      }
      csr_free(&iso);
      check_status(ctx, ps, n, bad, "update with a NaN");

      /* Repaired and searched again: the moved positions. */
      x[3 * a] = c.x[3 * a];
      bad[a] = 0;
      assert_ok(ctx, mfree_particles_setup(ps));
      check_isolated(ctx, ps, &c, &s, bad, "setup after update");
      csr_free(&before);
      mfree_particles_destroy(&ps);
      free(x);
      free(bad);
      cloud_free(&c);
    }
  mfree_context_destroy(&ctx);
}

static void test_periodic_too_small(void **state) {
  (void)state;
  mfree_context_t *ctx = new_ctx();
  mfree_rng_t r;
  mfree_rng_seed(&r, 212);
  for (int dim = 1; dim <= 3; ++dim)
    for (int ci = 0; ci < 3; ++ci) {
      const int32_t n = 200;
      cloud_t c = cloud_new(dim, n);
      gen_uniform(&c, &r);
      mfree_particles_t *ps = NULL;
      const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
      const int32_t per_all[3] = {1, 1, 1}, per_x[3] = {1, 0, 0};
      double h = 0.25; /* kappa*h = L/2 exactly */
      assert_ok(ctx, mfree_particles_create(ctx, dim, n, &ps));
      assert_ok(ctx, mfree_particles_set_positions(ps, c.x, MFREE_LAYOUT_AOS, 3, MFREE_COPY));
      assert_ok(ctx, mfree_particles_set_support(ps, &h, 0, MFREE_BORROW));
      assert_ok(ctx, mfree_particles_set_search(ps, (mfree_search_t)conventions[ci], 2.0));
      assert_ok(ctx, mfree_particles_set_periodic(ps, lo, hi, per_all));
      assert_error(ctx, mfree_particles_setup(ps), MFREE_ERR_INPUT, "half the periodic box");
      assert_status(ctx, mfree_particles_get_neighbor_nnz(ps, &(int64_t){0}), MFREE_ERR_STATE);

      /* Just below the limit, fine (every pair is then a neighbour in 1D). */
      h = 0.2499;
      assert_ok(ctx, mfree_particles_setup(ps));
      search_t s = search_make(conventions[ci], 2.0, 1);
      set_uniform_h(&c, h);
      check_rows(ctx, ps, &c, &s, NULL, NULL, 0, "just below L/2");
      csr_t prev = fetch(ctx, ps);

      /* A borrowed support that grows too large: the call fails, nothing changes. */
      h = 0.3;
      assert_error(ctx, mfree_particles_setup(ps), MFREE_ERR_INPUT, "half the periodic box");
      csr_t now = fetch(ctx, ps);
      assert_true(csr_equal(&prev, &now));
      csr_free(&now);
      h = -0.3; /* invalid support makes no particle valid: nothing to check */
      assert_error(ctx, mfree_particles_setup(ps), MFREE_FAIL_INVALID_DATA, "support");
      h = 0.2499;

      /* Along a non-periodic axis any support is fine; along x it is still checked. */
      if (dim > 1) {
        h = 0.3;
        const double lo2[3] = {0, 0, 0}, hi2[3] = {1.5, 1e-3, 1e-3};
        assert_ok(ctx, mfree_particles_set_periodic(ps, lo2, hi2, per_x));
        s = search_make(conventions[ci], 2.0, 2);
        s.hi[0] = 1.5;
        set_uniform_h(&c, h);
        assert_ok(ctx, mfree_particles_setup(ps));
        check_rows(ctx, ps, &c, &s, NULL, NULL, 0, "periodic x only, large h");
        assert_ok(ctx, mfree_particles_set_periodic(ps, lo, hi, per_x));
        assert_error(ctx, mfree_particles_setup(ps), MFREE_ERR_INPUT, "axis 0");
      }

      /* One particle's variable support too large is enough. */
      for (int32_t i = 0; i < n; ++i) c.h[i] = 0.05;
      c.h[n / 2] = 0.26;
      assert_ok(ctx, mfree_particles_set_support(ps, c.h, 1, MFREE_COPY));
      assert_ok(ctx, mfree_particles_set_periodic(ps, lo, hi, per_all));
      assert_error(ctx, mfree_particles_setup(ps), MFREE_ERR_INPUT, "half the periodic box");
      csr_free(&prev);
      mfree_particles_destroy(&ps);
      cloud_free(&c);
    }
  mfree_context_destroy(&ctx);
}

/* An invalid particle must not change what a failed (negative) setup leaves behind. */
static void test_failed_setup_changes_nothing(void **state) {
  (void)state;
  mfree_context_t *ctx = new_ctx();
  mfree_rng_t r;
  mfree_rng_seed(&r, 213);
  const int32_t n = 100;
  cloud_t c = cloud_new(2, n);
  gen_uniform(&c, &r);
  double *h = xmalloc(sizeof(double) * n);
  for (int32_t i = 0; i < n; ++i) h[i] = 0.05;
  const double lo[2] = {0, 0}, hi[2] = {1, 1};
  const int32_t per[2] = {1, 1};
  mfree_particles_t *ps = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, 2, n, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, c.x, MFREE_LAYOUT_AOS, 3, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_support(ps, h, 1, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_periodic(ps, lo, hi, per));
  assert_ok(ctx, mfree_particles_setup(ps));
  csr_t prev = fetch(ctx, ps);
  h[3] = NAN;  /* would isolate particle 3 ... */
  h[9] = 0.3;  /* ... but the box is now too small: the whole call fails */
  assert_error(ctx, mfree_particles_setup(ps), MFREE_ERR_INPUT, "half the periodic box");
  int32_t st[100], nf = -1;
  assert_ok(ctx, mfree_particles_get_site_status(ps, st, &nf));
  assert_int_equal(nf, 0);
  assert_int_equal(st[3], 0);
  csr_t now = fetch(ctx, ps);
  assert_true(csr_equal(&prev, &now));
  csr_free(&now);
  csr_free(&prev);
  mfree_particles_destroy(&ps);
  free(h);
  cloud_free(&c);
  mfree_context_destroy(&ctx);
}

static void test_outside_box(void **state) {
  (void)state;
  mfree_context_t *ctx = new_ctx();
  mfree_rng_t r;
  mfree_rng_seed(&r, 214);
  static const double shifts[6] = {1.0, -1.0, 2.0, -3.0, 17.0, 0.0};
  for (int dim = 1; dim <= 3; ++dim)
    for (int ci = 0; ci < 3; ++ci)
      for (int pm = 1; pm <= 2; ++pm) {
        const int32_t n = 600;
        cloud_t c = cloud_new(dim, n);
        gen_uniform(&c, &r);
        search_t s = search_make(conventions[ci], 2.0, pm);
        /* a box away from the origin: [-0.5, 2) on every axis */
        for (int k = 0; k < 3; ++k) {
          s.lo[k] = -0.5;
          s.hi[k] = 2.0;
        }
        for (int32_t i = 0; i < n; ++i)
          for (int k = 0; k < dim; ++k) c.x[3 * i + k] = -0.5 + 2.5 * c.x[3 * i + k];
        set_variable_h(&c, support_for(dim, n / pow(2.5, dim), 20.0, 2.0), &r);
        mfree_particles_t *ps = make_set(ctx, &c, &s, 0, 0);
        check_rows(ctx, ps, &c, &s, NULL, NULL, 0, "inside the periodic box");
        csr_t inside = fetch(ctx, ps);
        mfree_particles_destroy(&ps);

        /* Whole box lengths along periodic axes change no distance: same lists. */
        for (int32_t i = 0; i < n; i += 3)
          for (int k = 0; k < dim; ++k)
            if (s.periodic[k]) c.x[3 * i + k] += 2.5 * shifts[(i / 3 + k) % 6];
        ps = make_set(ctx, &c, &s, 0, 0);
        csr_t shifted = fetch(ctx, ps);
        assert_true(csr_equal(&inside, &shifted));
        check_rows(ctx, ps, &c, &s, NULL, NULL, 0, "shifted by box lengths");
        csr_free(&shifted);
        mfree_particles_destroy(&ps);

        /* Particles just beyond hi, just below lo and exactly at hi must find the
         * particles near the opposite face. */
        const int32_t special[3] = {1, 4, 7};
        for (int k = 0; k < dim; ++k)
          if (s.periodic[k]) {
            c.x[3 * 1 + k] = 2.0 + 0.01;
            c.x[3 * 4 + k] = -0.5 - 0.013;
            c.x[3 * 7 + k] = 2.0;
          }
        for (int q = 0; q < 3; ++q) c.h[special[q]] = 1.6 * support_for(dim, n / pow(2.5, dim), 20.0, 2.0);
        ps = make_set(ctx, &c, &s, 0, 0);
        check_rows(ctx, ps, &c, &s, NULL, NULL, 0, "beyond the periodic box");
        csr_t g = fetch(ctx, ps);
        for (int q = 0; q < 3; ++q) {
          /* the data must make the point: some neighbours are across the box */
          const int32_t i = special[q];
          int across = 0;
          for (int64_t p = g.rowptr[i]; p < g.rowptr[i + 1]; ++p)
            for (int k = 0; k < dim; ++k)
              across += s.periodic[k] && fabs(c.x[3 * i + k] - c.x[3 * (size_t)g.cols[p] + k]) > 1.25;
          assert_true(across > 0);
        }
        csr_free(&g);
        csr_free(&inside);
        mfree_particles_destroy(&ps);
        cloud_free(&c);
      }
  mfree_context_destroy(&ctx);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_uniform_random),
      cmocka_unit_test(test_jittered_lattice),
      cmocka_unit_test(test_clustered),
      cmocka_unit_test(test_ghosts),
      cmocka_unit_test(test_borrowed_layouts),
      cmocka_unit_test(test_large),
      cmocka_unit_test(test_empty),
      cmocka_unit_test(test_all_to_all),
      cmocka_unit_test(test_coincident),
      cmocka_unit_test(test_far_outlier),
      cmocka_unit_test(test_invalid_borrowed),
      cmocka_unit_test(test_update),
      cmocka_unit_test(test_periodic_too_small),
      cmocka_unit_test(test_failed_setup_changes_nothing),
      cmocka_unit_test(test_outside_box),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
