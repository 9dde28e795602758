/* Ghost correction data (mfree_approximant_set_ghost_correction): a two-slab
 * decomposition of one cloud, in one process. Each slab is a particle set of its owned
 * particles (listed in another order than the whole cloud's) and, as ghosts, every
 * particle of the other slab paired with one of them, all with the cloud's global ids;
 * its pair list is the cloud's pairs that touch the slab, in reverse order. With the
 * ghosts' records taken from the other slab's mfree_approximant_get_correction, every
 * pair gradient (both sides) and the antisymmetrised form of every slab pair equal those
 * of the whole cloud as one set bit for bit, for each method with correction data, in
 * 2D and 3D. Then the error cases: each leaves the data set before in place. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"
#include "nbr_lists.h"

enum { NSLAB = 2 };

typedef struct {
  int dim, n;
  double *x, *h, *v, cut; /* cut: the slabs' boundary along x */
  int64_t *id;
  int64_t np;
  int32_t *pi, *pj;
} cloud_t;

/* m^dim jittered lattice points (spacing 1), supports 1.3 +-10 %, volumes 1 +-10 %, ids
 * 100 + 3 p; the pairs within 2 h_ij (SYMMETRIC_MEAN), shuffled. */
static void make_cloud(cloud_t *c, int dim, int m, uint64_t seed) {
  mfree_rng_t r;
  mfree_rng_seed(&r, seed);
  int n = 1;
  for (int d = 0; d < dim; ++d) n *= m;
  c->dim = dim;
  c->n = n;
  c->cut = 0.5 * (m - 1);
  c->x = malloc(sizeof(double) * (size_t)n * dim);
  c->h = malloc(sizeof(double) * (size_t)n);
  c->v = malloc(sizeof(double) * (size_t)n);
  c->id = malloc(sizeof(int64_t) * (size_t)n);
  jittered_lattice(c->x, dim, m, &r);
  for (int p = 0; p < n; ++p) {
    c->h[p] = 1.3 * (0.9 + 0.2 * mfree_rng_uniform(&r));
    c->v[p] = 0.9 + 0.2 * mfree_rng_uniform(&r);
    c->id[p] = 100 + 3 * (int64_t)p;
  }
  c->pi = malloc(sizeof(int32_t) * (size_t)n * n / 2);
  c->pj = malloc(sizeof(int32_t) * (size_t)n * n / 2);
  int64_t np = 0;
  for (int a = 0; a < n; ++a)
    for (int b = a + 1; b < n; ++b) {
      double r2 = 0.0;
      for (int d = 0; d < dim; ++d) {
        const double t = c->x[a * dim + d] - c->x[b * dim + d];
        r2 += t * t;
      }
      const double hij = 0.5 * (c->h[a] + c->h[b]);
      if (r2 < 4.0 * hij * hij) {
        c->pi[np] = a;
        c->pj[np] = b;
        ++np;
      }
    }
  for (int64_t k = np - 1; k > 0; --k) {
    const int64_t q = (int64_t)(mfree_rng_uniform(&r) * (double)(k + 1));
    const int32_t ti = c->pi[k], tj = c->pj[k];
    c->pi[k] = c->pi[q];
    c->pj[k] = c->pj[q];
    c->pi[q] = ti;
    c->pj[q] = tj;
  }
  c->np = np;
}

static void free_cloud(cloud_t *c) {
  free(c->x);
  free(c->h);
  free(c->v);
  free(c->id);
  free(c->pi);
  free(c->pj);
}

/* One slab: particle p of the set is particle glob[p] of the cloud (owned, then ghosts);
 * its pair k is the cloud's pair gk[k]. */
typedef struct {
  int n, nghost;
  int32_t *glob, *loc; /* loc: cloud particle -> set particle, or -1 */
  double *x, *h, *v;
  int64_t *id;
  int64_t np;
  int32_t *pi, *pj;
  int64_t *gk;
} slab_t;

static int in_slab(const cloud_t *c, int p, int s) { return (c->x[p * c->dim] < c->cut) == (s == 0); }

static void make_slab(const cloud_t *c, int s, slab_t *b) {
  const int dim = c->dim;
  b->glob = malloc(sizeof(int32_t) * (size_t)c->n);
  b->loc = malloc(sizeof(int32_t) * (size_t)c->n);
  for (int p = 0; p < c->n; ++p) b->loc[p] = -1;
  int n = 0;
  for (int p = c->n - 1; p >= 0; --p) /* owned, in reverse cloud order */
    if (in_slab(c, p, s)) {
      b->loc[p] = n;
      b->glob[n++] = p;
    }
  const int nown = n;
  for (int64_t k = 0; k < c->np; ++k) /* ghosts: the other slab's partners */
    for (int e = 0; e < 2; ++e) {
      const int a = e ? c->pj[k] : c->pi[k], g = e ? c->pi[k] : c->pj[k];
      if (b->loc[a] >= 0 && b->loc[a] < nown && b->loc[g] < 0) {
        b->loc[g] = n;
        b->glob[n++] = g;
      }
    }
  b->n = n;
  b->nghost = n - nown;
  b->x = malloc(sizeof(double) * (size_t)n * dim);
  b->h = malloc(sizeof(double) * (size_t)n);
  b->v = malloc(sizeof(double) * (size_t)n);
  b->id = malloc(sizeof(int64_t) * (size_t)n);
  for (int q = 0; q < n; ++q) {
    const int p = b->glob[q];
    memcpy(b->x + (size_t)q * dim, c->x + (size_t)p * dim, sizeof(double) * dim);
    b->h[q] = c->h[p];
    b->v[q] = c->v[p];
    b->id[q] = c->id[p];
  }
  /* the cloud's pairs with both particles in the set (ghost-ghost pairs included), in
   * reverse order */
  b->pi = malloc(sizeof(int32_t) * (size_t)c->np);
  b->pj = malloc(sizeof(int32_t) * (size_t)c->np);
  b->gk = malloc(sizeof(int64_t) * (size_t)c->np);
  int64_t np = 0;
  for (int64_t k = c->np - 1; k >= 0; --k)
    if (b->loc[c->pi[k]] >= 0 && b->loc[c->pj[k]] >= 0) {
      b->pi[np] = b->loc[c->pi[k]];
      b->pj[np] = b->loc[c->pj[k]];
      b->gk[np++] = k;
    }
  b->np = np;
}

static void free_slab(slab_t *b) {
  free(b->glob);
  free(b->loc);
  free(b->x);
  free(b->h);
  free(b->v);
  free(b->id);
  free(b->pi);
  free(b->pj);
  free(b->gk);
}

static mfree_particles_t *make_set(mfree_context_t *ctx, int dim, int n, int nghost, double *x, double *h,
                                   double *v, const int64_t *id, int64_t np, const int32_t *pi,
                                   const int32_t *pj) {
  mfree_particles_t *ps = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, dim, n, &ps));
  assert_ok(ctx, mfree_particles_set_num_ghost(ps, nghost));
  assert_ok(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, dim, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_support(ps, h, 1, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_volumes(ps, v, 1, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_global_ids(ps, id, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_search(ps, MFREE_SEARCH_SYMMETRIC_MEAN, 2.0));
  assert_ok(ctx, mfree_particles_set_pairs(ps, np, pi, pj, 0, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_setup(ps));
  return ps;
}

static mfree_approximant_t *make_approx(mfree_context_t *ctx, mfree_particles_t *ps, int method) {
  mfree_approximant_t *a = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, (mfree_method_t)method, &a));
  assert_ok(ctx, mfree_approximant_set_derivatives(a, MFREE_DERIV_GRADIENT));
  if (method == MFREE_METHOD_MLS) assert_ok(ctx, mfree_approximant_set_order(a, 1));
  assert_ok(ctx, mfree_approximant_setup(a));
  return a;
}

/* Pair gradients of a: gi, gj (dim every dim doubles) and the antisymmetrised g. */
static void pair_data(mfree_context_t *ctx, mfree_approximant_t *a, int dim, int64_t np, double *gi,
                      double *gj, double *g) {
  const int64_t cap = dim * (np > 0 ? np : 1);
  assert_ok(ctx, mfree_approximant_get_pair_gradients(a, gi, gj, dim, cap));
  assert_ok(ctx, mfree_approximant_get_pair_gradients_antisymmetric(a, g, dim, cap));
}

static const int kMethods[] = {MFREE_METHOD_RANDLES_LIBERSKY, MFREE_METHOD_KB_METHOD1, MFREE_METHOD_MLS,
                               MFREE_METHOD_SHEPARD, MFREE_METHOD_JOHNSON_BEISSEL};

static void run_dim(int dim, int m) {
  cloud_t c;
  make_cloud(&c, dim, m, 443 + (uint64_t)dim);
  slab_t sl[NSLAB];
  for (int s = 0; s < NSLAB; ++s) {
    make_slab(&c, s, &sl[s]);
    assert_true(sl[s].nghost > 0);
  }
  mfree_context_t *ctx = NULL;
  assert_ok(ctx, mfree_context_create(&ctx));
  mfree_particles_t *pw = make_set(ctx, dim, c.n, 0, c.x, c.h, c.v, c.id, c.np, c.pi, c.pj);
  mfree_particles_t *ps[NSLAB];
  for (int s = 0; s < NSLAB; ++s)
    ps[s] = make_set(ctx, dim, sl[s].n, sl[s].nghost, sl[s].x, sl[s].h, sl[s].v, sl[s].id, sl[s].np,
                     sl[s].pi, sl[s].pj);
  const size_t big = (size_t)dim * (size_t)c.np;
  double *wi = malloc(sizeof(double) * big), *wj = malloc(sizeof(double) * big),
         *wa = malloc(sizeof(double) * big);
  double *gi = malloc(sizeof(double) * big), *gj = malloc(sizeof(double) * big),
         *ga = malloc(sizeof(double) * big);
  for (size_t q = 0; q < sizeof kMethods / sizeof kMethods[0]; ++q) {
    const int method = kMethods[q];
    mfree_approximant_t *aw = make_approx(ctx, pw, method), *as[NSLAB];
    for (int s = 0; s < NSLAB; ++s) as[s] = make_approx(ctx, ps[s], method);
    int32_t nc = 0;
    assert_ok(ctx, mfree_approximant_get_correction_size(aw, &nc));
    const int64_t ld = nc + 2; /* a leading dimension larger than a record */
    /* the records of the whole cloud and of each slab's owned particles */
    double *rw = malloc(sizeof(double) * (size_t)(ld * c.n)), *rs[NSLAB];
    assert_ok(ctx, mfree_approximant_get_correction(aw, rw, ld, ld * c.n));
    for (int s = 0; s < NSLAB; ++s) {
      const int nown = sl[s].n - sl[s].nghost;
      rs[s] = malloc(sizeof(double) * (size_t)(ld * nown));
      assert_ok(ctx, mfree_approximant_get_correction(as[s], rs[s], ld, ld * nown));
      for (int p = 0; p < nown; ++p) /* an owned particle's record is the cloud's */
        assert_memory_equal(rs[s] + ld * p, rw + ld * sl[s].glob[p], sizeof(double) * nc);
    }
    pair_data(ctx, aw, dim, c.np, wi, wj, wa);
    for (int s = 0; s < NSLAB; ++s) {
      slab_t *b = &sl[s];
      const slab_t *o = &sl[1 - s];
      const int nown = b->n - b->nghost, oown = o->n - o->nghost;
      /* the ghosts' records from their owner, the other slab */
      double *rg = malloc(sizeof(double) * (size_t)(ld * b->nghost));
      for (int g = 0; g < b->nghost; ++g) {
        const int at = o->loc[b->glob[nown + g]];
        assert_true(at >= 0 && at < oown);
        memcpy(rg + ld * g, rs[1 - s] + ld * at, sizeof(double) * nc);
      }
      assert_ok(ctx, mfree_approximant_set_ghost_correction(as[s], rg, ld, (b->nghost - 1) * ld + nc));
      pair_data(ctx, as[s], dim, b->np, gi, gj, ga);
      int64_t ghost_sides = 0;
      for (int64_t k = 0; k < b->np; ++k) {
        const int64_t K = b->gk[k];
        assert_memory_equal(gi + dim * k, wi + dim * K, sizeof(double) * dim);
        assert_memory_equal(gj + dim * k, wj + dim * K, sizeof(double) * dim);
        assert_memory_equal(ga + dim * k, wa + dim * K, sizeof(double) * dim);
        ghost_sides += (b->pi[k] >= nown) + (b->pj[k] >= nown);
      }
      assert_true(ghost_sides > 0);
      print_message("%dD method %d slab %d: %lld pairs, %lld ghost sides, %d ghosts: bitwise equal\n", dim,
                    method, s, (long long)b->np, (long long)ghost_sides, b->nghost);

      /* Errors: each changes nothing (the pair gradients stay those above). */
      double *bad = malloc(sizeof(double) * (size_t)(ld * b->nghost));
      memcpy(bad, rg, sizeof(double) * (size_t)(ld * b->nghost));
      bad[ld * (b->nghost - 1) + nc - 1] = NAN;
      assert_error(ctx, mfree_approximant_set_ghost_correction(as[s], bad, ld, ld * b->nghost),
                   MFREE_ERR_INPUT, "not finite");
      bad[ld * (b->nghost - 1) + nc - 1] = INFINITY;
      assert_error(ctx, mfree_approximant_set_ghost_correction(as[s], bad, ld, ld * b->nghost),
                   MFREE_ERR_INPUT, "not finite");
      assert_error(ctx, mfree_approximant_set_ghost_correction(as[s], rg, nc - 1, ld * b->nghost),
                   MFREE_ERR_ARG, "leading dimension");
      assert_error(ctx, mfree_approximant_set_ghost_correction(as[s], rg, ld, (b->nghost - 1) * ld + nc - 1),
                   MFREE_ERR_ARG, "are needed");
      assert_error(ctx, mfree_approximant_set_ghost_correction(as[s], NULL, ld, ld * b->nghost),
                   MFREE_ERR_NULL, "NULL");
      assert_error(NULL, mfree_approximant_set_ghost_correction(NULL, rg, ld, ld * b->nghost), MFREE_ERR_NULL,
                   NULL);
      pair_data(ctx, as[s], dim, b->np, gi, gj, ga);
      for (int64_t k = 0; k < b->np; ++k) {
        assert_memory_equal(gi + dim * k, wi + dim * b->gk[k], sizeof(double) * dim);
        assert_memory_equal(gj + dim * k, wj + dim * b->gk[k], sizeof(double) * dim);
      }
      /* a new setup drops the data: the ghost sides are 0 again */
      assert_ok(ctx, mfree_approximant_setup(as[s]));
      pair_data(ctx, as[s], dim, b->np, gi, gj, ga);
      for (int64_t k = 0; k < b->np; ++k)
        for (int d = 0; d < dim; ++d) {
          if (b->pi[k] >= nown) assert_true(gi[dim * k + d] == 0.0);
          if (b->pj[k] >= nown) assert_true(gj[dim * k + d] == 0.0);
        }
      /* a particle set set up again after the approximant: the approximant is stale */
      assert_ok(ctx, mfree_particles_setup(ps[s]));
      assert_error(ctx, mfree_approximant_set_ghost_correction(as[s], rg, ld, ld * b->nghost), MFREE_ERR_STATE,
                   NULL);
      free(bad);
      free(rg);
    }
    for (int s = 0; s < NSLAB; ++s) {
      free(rs[s]);
      mfree_approximant_destroy(&as[s]);
    }
    free(rw);
    mfree_approximant_destroy(&aw);
  }
  /* methods without correction data; an approximant not set up */
  double rec[64] = {0};
  const int without[] = {MFREE_METHOD_SPH, MFREE_METHOD_KB_METHOD3};
  for (int q = 0; q < 2; ++q) {
    mfree_approximant_t *a = make_approx(ctx, ps[0], without[q]);
    assert_error(ctx, mfree_approximant_set_ghost_correction(a, rec, 1, 64), MFREE_ERR_UNSUPPORTED, NULL);
    mfree_approximant_destroy(&a);
  }
  mfree_approximant_t *a = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps[0], MFREE_METHOD_RANDLES_LIBERSKY, &a));
  assert_error(ctx, mfree_approximant_set_ghost_correction(a, rec, dim * dim, 64), MFREE_ERR_STATE, "not set up");
  mfree_approximant_destroy(&a);

  free(wi);
  free(wj);
  free(wa);
  free(gi);
  free(gj);
  free(ga);
  for (int s = 0; s < NSLAB; ++s) {
    mfree_particles_destroy(&ps[s]);
    free_slab(&sl[s]);
  }
  mfree_particles_destroy(&pw);
  mfree_context_destroy(&ctx);
  free_cloud(&c);
}

static void test_slabs_2d(void **state) {
  (void)state;
  run_dim(2, 12);
}

static void test_slabs_3d(void **state) {
  (void)state;
  run_dim(3, 8);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_slabs_2d),
      cmocka_unit_test(test_slabs_3d),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
