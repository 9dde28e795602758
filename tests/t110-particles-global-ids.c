/* Particle sets with global ids: one canonical order.
 *  - a random permutation of a cloud (owned and, in the sub-domain case, ghost particles
 *    in another random order, on another thread count) gives every owned particle the
 *    bits of the reference set: neighbour rows by global id, every table row (values,
 *    gradients, Hessians where provided) and apply, for every method of particles
 *    (SPH, symmetric SPH, Shepard, MLS 1-2, RKPM 1-2, JB, RL, KB 1-3, MSPH 1-2, SSPH 1-2),
 *    2D and 3D;
 *  - the same with a rank-like sub-domain: owned particles on one side of a cut, ghosts
 *    within one support radius of them (the halo contract of docs/mpi.md);
 *  - the same with host-supplied neighbour lists (shuffled rows that omit the particle
 *    itself) and with the symmetric-mean search convention;
 *  - rows of host points (MLS 2) over a permuted set: the same ids, order and bits;
 *  - pair gradients of a host pair list (SPH, RL, KB 1, MLS 1), the set permuted and the
 *    pairs reordered and flipped: both sides of every pair the same bits;
 *  - bad input: negative or repeated ids (copied, and borrowed ids changed before setup:
 *    nothing changes), get without ids, a negative or NaN halo width, and a declared halo
 *    width narrower than the search radius or the kernel support: MFREE_ERR_HALO. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"

static mfree_context_t *ctx, *ctx2;
static int setup(void **s) {
  (void)s;
  if (mfree_context_create(&ctx) || mfree_context_create(&ctx2)) return 1;
  return mfree_context_set_num_threads(ctx2, 2) != MFREE_SUCCESS;
}
static int teardown(void **s) {
  (void)s;
  mfree_context_destroy(&ctx2);
  return mfree_context_destroy(&ctx) != MFREE_SUCCESS;
}

#define NMAX 400
#define KAPPA 2.0

typedef struct {
  int dim, n, n_ghost;
  double x[NMAX * 3], h[NMAX], v[NMAX];
  int64_t id[NMAX];
  int orig[NMAX]; /* index of each particle in the reference cloud */
} cloud_t;

/* Jittered lattice, m per axis on [0,1]^dim, supports varying by +-10 %, ids 7 + 3 i. */
static void make_cloud(cloud_t *c, int dim, int m, uint64_t seed) {
  mfree_rng_t r;
  mfree_rng_seed(&r, seed);
  const double dx = 1.0 / (m - 1);
  int total = 1;
  for (int d = 0; d < dim; ++d) total *= m;
  assert_true(total <= NMAX);
  c->dim = dim;
  c->n = total;
  c->n_ghost = 0;
  for (int i = 0; i < total; ++i) {
    int rest = i;
    for (int d = 0; d < dim; ++d) {
      c->x[i * dim + d] = (rest % m) * dx + 0.25 * dx * (2.0 * mfree_rng_uniform(&r) - 1.0);
      rest /= m;
    }
    c->h[i] = 1.3 * dx * (0.9 + 0.2 * mfree_rng_uniform(&r));
    c->v[i] = pow(dx, dim) * (0.9 + 0.2 * mfree_rng_uniform(&r));
    c->id[i] = 7 + 3 * (int64_t)i;
    c->orig[i] = i;
  }
}

static void shuffle(int *a, int n, mfree_rng_t *r) {
  for (int i = n - 1; i > 0; --i) {
    const int j = (int)(mfree_rng_uniform(r) * (i + 1));
    const int t = a[i];
    a[i] = a[j];
    a[j] = t;
  }
}

/* A sub-domain of ref: the particles with x_0 < cut owned, those with x_0 in
 * [cut, cut + halo) ghosts, each group in random order (cut = INFINITY: a permutation),
 * or in id order for seed 0. */
static void make_subdomain(cloud_t *out, const cloud_t *ref, double cut, double halo, uint64_t seed) {
  mfree_rng_t r;
  mfree_rng_seed(&r, seed);
  int own[NMAX], gh[NMAX], no = 0, ng = 0;
  const int dim = ref->dim;
  for (int i = 0; i < ref->n; ++i) {
    const double x0 = ref->x[i * dim];
    if (x0 < cut) own[no++] = i;
    else if (x0 < cut + halo) gh[ng++] = i;
  }
  if (seed) { /* seed 0: owned and ghosts in id order, ghosts last (few rows out of id order) */
    shuffle(own, no, &r);
    shuffle(gh, ng, &r);
  }
  out->dim = dim;
  out->n = no + ng;
  out->n_ghost = ng;
  for (int k = 0; k < no + ng; ++k) {
    const int i = k < no ? own[k] : gh[k - no];
    memcpy(out->x + k * dim, ref->x + i * dim, sizeof(double) * dim);
    out->h[k] = ref->h[i];
    out->v[k] = ref->v[i];
    out->id[k] = ref->id[i];
    out->orig[k] = i;
  }
}

static mfree_particles_t *make_set(mfree_context_t *c, const cloud_t *cl, int conv, int ids) {
  mfree_particles_t *ps = NULL;
  assert_ok(c, mfree_particles_create(c, cl->dim, cl->n, &ps));
  assert_ok(c, mfree_particles_set_num_ghost(ps, cl->n_ghost));
  assert_ok(c, mfree_particles_set_positions(ps, cl->x, MFREE_LAYOUT_AOS, cl->dim, MFREE_COPY));
  assert_ok(c, mfree_particles_set_support(ps, cl->h, 1, MFREE_COPY));
  assert_ok(c, mfree_particles_set_volumes(ps, cl->v, 1, MFREE_COPY));
  assert_ok(c, mfree_particles_set_search(ps, conv, KAPPA));
  if (ids) assert_ok(c, mfree_particles_set_global_ids(ps, cl->id, MFREE_COPY));
  return ps;
}

/* Host lists for sub: each owned particle's neighbours within KAPPA h_i (gather),
 * shuffled, without the particle itself (1-based, the Fortran way). */
static void host_lists(const cloud_t *sub, int64_t *rp, int32_t *cols, uint64_t seed) {
  mfree_rng_t r;
  mfree_rng_seed(&r, seed);
  const int dim = sub->dim, no = sub->n - sub->n_ghost;
  int64_t k = 0;
  rp[0] = 1;
  for (int i = 0; i < no; ++i) {
    int row[NMAX], cnt = 0;
    const double lim = KAPPA * sub->h[i];
    for (int j = 0; j < sub->n; ++j) {
      double r2 = 0;
      for (int d = 0; d < dim; ++d) {
        const double t = sub->x[j * dim + d] - sub->x[i * dim + d];
        r2 += t * t;
      }
      if (j != i && r2 < lim * lim) row[cnt++] = j;
    }
    shuffle(row, cnt, &r);
    for (int q = 0; q < cnt; ++q) cols[k++] = row[q] + 1;
    rp[i + 1] = k + 1;
  }
}

typedef struct {
  int method, order;
} method_t;

static const method_t kMethods[] = {
    {MFREE_METHOD_SPH, 0},  {MFREE_METHOD_SPH_SYMMETRIC, 0}, {MFREE_METHOD_SHEPARD, 0},
    {MFREE_METHOD_MLS, 1},  {MFREE_METHOD_MLS, 2},           {MFREE_METHOD_RKPM, 1},
    {MFREE_METHOD_RKPM, 2}, {MFREE_METHOD_JOHNSON_BEISSEL, 0}, {MFREE_METHOD_RANDLES_LIBERSKY, 0},
    {MFREE_METHOD_KB_METHOD1, 0}, {MFREE_METHOD_KB_METHOD2, 1}, {MFREE_METHOD_KB_METHOD3, 0},
    {MFREE_METHOD_MSPH, 1}, {MFREE_METHOD_MSPH, 2},          {MFREE_METHOD_SSPH, 1},
    {MFREE_METHOD_SSPH, 2},
};
#define NMETHODS ((int)(sizeof kMethods / sizeof kMethods[0]))

typedef struct {
  int nsites, nh;
  int64_t rp[NMAX + 1];
  int32_t *cols;
  double *tab[1 + 3 + 6]; /* value, gradient components, Hessian components (or NULL) */
  double *grad;           /* apply: gradient of two fields, nsites x 2 dim */
  int32_t status[NMAX];
} tables_t;

static int make_approximant(mfree_context_t *c, mfree_particles_t *ps, const method_t *m,
                            mfree_approximant_t **a) {
  assert_ok(c, mfree_approximant_create(c, ps, m->method, a));
  if (m->order) assert_ok(c, mfree_approximant_set_order(*a, m->order));
  int flags = MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT | MFREE_DERIV_HESSIAN;
  if (mfree_approximant_set_derivatives(*a, flags) != MFREE_SUCCESS) {
    flags = MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT;
    assert_ok(c, mfree_approximant_set_derivatives(*a, flags));
  }
  return flags;
}

static void fetch(mfree_context_t *c, mfree_particles_t *ps, const cloud_t *cl, const method_t *m,
                  tables_t *t) {
  mfree_approximant_t *a = NULL;
  int flags = make_approximant(c, ps, m, &a);
  mfree_status_t st = mfree_approximant_setup(a);
  if (st == MFREE_ERR_UNSUPPORTED && (flags & MFREE_DERIV_HESSIAN)) { /* not at this order */
    flags = MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT;
    assert_ok(c, mfree_approximant_set_derivatives(a, flags));
    st = mfree_approximant_setup(a);
  }
  if (st < 0) {
    char msg[512] = "";
    mfree_context_get_last_error(c, NULL, msg, sizeof msg);
    fail_msg("method %d order %d: setup returned %d: %s", m->method, m->order, (int)st, msg);
  }
  const int dim = cl->dim;
  int64_t nnz = 0;
  int32_t ns = 0;
  assert_ok(c, mfree_approximant_get_num_sites(a, &ns));
  assert_ok(c, mfree_approximant_get_nnz(a, &nnz));
  t->nsites = ns;
  t->nh = (flags & MFREE_DERIV_HESSIAN) ? dim * (dim + 1) / 2 : 0;
  t->cols = malloc(sizeof(int32_t) * (size_t)(nnz + 1));
  memset(t->tab, 0, sizeof t->tab);
  for (int k = 0; k < 1 + dim + t->nh; ++k) {
    const int deriv = k == 0 ? MFREE_DERIV_VALUE : k <= dim ? MFREE_DERIV_GRADIENT : MFREE_DERIV_HESSIAN;
    const int comp = k == 0 ? 0 : k <= dim ? k - 1 : k - 1 - dim;
    t->tab[k] = malloc(sizeof(double) * (size_t)(nnz + 1));
    assert_ok(c, mfree_approximant_assemble_csr(a, deriv, comp, t->rp, t->cols, t->tab[k]));
  }
  /* two fields known at the reference particles, carried by id */
  double u[NMAX * 2];
  for (int j = 0; j < cl->n; ++j) {
    const int o = cl->orig[j];
    u[2 * j] = sin(1.0 + 0.37 * o);
    u[2 * j + 1] = cos(0.5 * o) * (1 + o % 5);
  }
  t->grad = malloc(sizeof(double) * (size_t)(ns * 2 * dim + 1));
  assert_ok(c, mfree_approximant_apply(a, MFREE_OP_GRADIENT, 2, u, MFREE_LAYOUT_AOS, 2, t->grad,
                                       MFREE_LAYOUT_AOS, 2 * dim));
  assert_ok(c, mfree_approximant_get_site_status(a, t->status, NULL));
  mfree_approximant_destroy(&a);
}

static void free_tables(tables_t *t) {
  free(t->cols);
  for (int k = 0; k < 10; ++k) free(t->tab[k]);
  free(t->grad);
}

/* Row s of A (reference numbering) against row k of B: the same ids in the same
 * order, the same bits in every table and in apply. */
static void compare(const tables_t *A, const cloud_t *ca, const tables_t *B, const cloud_t *cb,
                    const char *what) {
  const int dim = ca->dim, nb = cb->n - cb->n_ghost;
  for (int k = 0; k < nb; ++k) {
    const int s = cb->orig[k];
    const int64_t a0 = A->rp[s], a1 = A->rp[s + 1], b0 = B->rp[k], b1 = B->rp[k + 1];
    if (a1 - a0 != b1 - b0 || A->status[s] != B->status[k])
      fail_msg("%s: particle id %lld: row lengths %lld / %lld, status %d / %d", what,
               (long long)ca->id[s], (long long)(a1 - a0), (long long)(b1 - b0), A->status[s],
               B->status[k]);
    for (int64_t q = 0; q < a1 - a0; ++q) {
      if (ca->id[A->cols[a0 + q]] != cb->id[B->cols[b0 + q]])
        fail_msg("%s: particle id %lld: entry %lld is id %lld / %lld", what, (long long)ca->id[s],
                 (long long)q, (long long)ca->id[A->cols[a0 + q]], (long long)cb->id[B->cols[b0 + q]]);
      for (int t = 0; t < 1 + dim + A->nh; ++t)
        if (memcmp(&A->tab[t][a0 + q], &B->tab[t][b0 + q], sizeof(double)))
          fail_msg("%s: particle id %lld: table %d entry %lld: %.17g / %.17g", what,
                   (long long)ca->id[s], t, (long long)q, A->tab[t][a0 + q], B->tab[t][b0 + q]);
    }
    if (memcmp(A->grad + (size_t)s * 2 * dim, B->grad + (size_t)k * 2 * dim, sizeof(double) * 2 * dim))
      fail_msg("%s: particle id %lld: apply differs (%.17g / %.17g)", what, (long long)ca->id[s],
               A->grad[(size_t)s * 2 * dim], B->grad[(size_t)k * 2 * dim]);
  }
}

/* Neighbour rows of B equal those of A by id (in the same id order). */
static void compare_neighbors(mfree_particles_t *pa, const cloud_t *ca, mfree_particles_t *pb,
                              const cloud_t *cb) {
  int64_t na = 0, nb = 0;
  assert_ok(ctx, mfree_particles_get_neighbor_nnz(pa, &na));
  assert_ok(ctx2, mfree_particles_get_neighbor_nnz(pb, &nb));
  int64_t *ra = malloc(sizeof(int64_t) * (size_t)(ca->n + 1)), *rb = malloc(sizeof(int64_t) * (size_t)(cb->n + 1));
  int32_t *ka = malloc(sizeof(int32_t) * (size_t)(na + 1)), *kb = malloc(sizeof(int32_t) * (size_t)(nb + 1));
  assert_ok(ctx, mfree_particles_get_neighbors(pa, ra, ka));
  assert_ok(ctx2, mfree_particles_get_neighbors(pb, rb, kb));
  for (int k = 0; k < cb->n - cb->n_ghost; ++k) {
    const int s = cb->orig[k];
    assert_int_equal(ra[s + 1] - ra[s], rb[k + 1] - rb[k]);
    for (int64_t q = 0; q < ra[s + 1] - ra[s]; ++q) {
      assert_int_equal(ca->id[ka[ra[s] + q]], cb->id[kb[rb[k] + q]]);
      if (q) assert_true(cb->id[kb[rb[k] + q - 1]] < cb->id[kb[rb[k] + q]]);
    }
  }
  free(ra);
  free(rb);
  free(ka);
  free(kb);
}

static double max_support(const cloud_t *c) {
  double m = 0;
  for (int i = 0; i < c->n; ++i) m = c->h[i] > m ? c->h[i] : m;
  return m;
}

/* variant: 0 permutation, 1 sub-domain with ghosts, 2 sub-domain with host lists,
 * 3 sub-domain, symmetric-mean convention, 4 sub-domain in id order (the rows are put in
 * id order by insertion; in the others, where the numbering is unrelated to the ids,
 * they are rebuilt) */
static void run(int dim, int variant) {
  static cloud_t ref, sub;
  make_cloud(&ref, dim, dim == 2 ? 17 : 7, 11 + dim);
  const int conv = variant == 3 ? MFREE_SEARCH_SYMMETRIC_MEAN : MFREE_SEARCH_GATHER;
  const double halo = KAPPA * max_support(&ref) * 1.0000001;
  make_subdomain(&sub, &ref, variant == 0 ? INFINITY : 0.45, halo, variant == 4 ? 0 : 100 + variant);
  assert_true(variant == 0 || sub.n_ghost > 0);
  mfree_particles_t *pa = make_set(ctx, &ref, conv, 1), *pb = make_set(ctx2, &sub, conv, 1);
  int64_t *hrp = NULL;
  int32_t *hcols = NULL;
  if (variant == 2) {
    hrp = malloc(sizeof(int64_t) * (size_t)(sub.n + 1));
    hcols = malloc(sizeof(int32_t) * (size_t)sub.n * (size_t)sub.n);
    host_lists(&sub, hrp, hcols, 5);
    assert_ok(ctx2, mfree_particles_set_neighbors(pb, hrp, hcols, 1, MFREE_COPY));
  }
  if (variant) assert_ok(ctx2, mfree_particles_set_halo_width(pb, halo));
  assert_ok(ctx, mfree_particles_setup(pa));
  assert_ok(ctx2, mfree_particles_setup(pb));
  if (variant != 2) compare_neighbors(pa, &ref, pb, &sub);
  char what[96];
  for (int m = 0; m < NMETHODS; ++m) {
    tables_t A, B;
    fetch(ctx, pa, &ref, &kMethods[m], &A);
    fetch(ctx2, pb, &sub, &kMethods[m], &B);
    snprintf(what, sizeof what, "%dD variant %d method %d order %d", dim, variant,
             kMethods[m].method, kMethods[m].order);
    compare(&A, &ref, &B, &sub, what);
    free_tables(&A);
    free_tables(&B);
  }
  free(hrp);
  free(hcols);
  mfree_particles_destroy(&pa);
  mfree_particles_destroy(&pb);
}

/* Host points (MLS 2 values and gradients at 40 points): the rows of the points over a
 * permuted set hold the same ids in the same order and the same bits. */
static void test_points(void **s) {
  (void)s;
  static cloud_t ref, sub;
  for (int dim = 2; dim <= 3; ++dim) {
    make_cloud(&ref, dim, dim == 2 ? 17 : 7, 21 + dim);
    make_subdomain(&sub, &ref, INFINITY, 0, 9);
    double px[40 * 3], ph = 1.3 / (dim == 2 ? 16 : 6);
    mfree_rng_t r;
    mfree_rng_seed(&r, 77);
    for (int k = 0; k < 40 * dim; ++k) px[k] = 0.1 + 0.8 * mfree_rng_uniform(&r);
    tables_t T[2];
    for (int side = 0; side < 2; ++side) {
      const cloud_t *c = side ? &sub : &ref;
      mfree_context_t *cx = side ? ctx2 : ctx;
      mfree_particles_t *ps = make_set(cx, c, MFREE_SEARCH_GATHER, 1);
      mfree_approximant_t *a = NULL;
      assert_ok(cx, mfree_approximant_create(cx, ps, MFREE_METHOD_MLS, &a));
      assert_ok(cx, mfree_approximant_set_order(a, 2));
      assert_ok(cx, mfree_approximant_set_points(a, 40, px, MFREE_LAYOUT_AOS, dim, &ph, 0, MFREE_COPY));
      assert_ok(cx, mfree_approximant_setup(a));
      int64_t nnz = 0;
      assert_ok(cx, mfree_approximant_get_nnz(a, &nnz));
      T[side].cols = malloc(sizeof(int32_t) * (size_t)(nnz + 1));
      for (int k = 0; k <= dim; ++k) {
        T[side].tab[k] = malloc(sizeof(double) * (size_t)(nnz + 1));
        assert_ok(cx, mfree_approximant_assemble_csr(a, k ? MFREE_DERIV_GRADIENT : MFREE_DERIV_VALUE, k ? k - 1 : 0,
                                                     T[side].rp, T[side].cols, T[side].tab[k]));
      }
      mfree_approximant_destroy(&a);
      mfree_particles_destroy(&ps);
    }
    for (int p = 0; p < 40; ++p) {
      assert_int_equal(T[0].rp[p + 1] - T[0].rp[p], T[1].rp[p + 1] - T[1].rp[p]);
      for (int64_t q = 0; q < T[0].rp[p + 1] - T[0].rp[p]; ++q) {
        const int64_t a0 = T[0].rp[p] + q, b0 = T[1].rp[p] + q;
        assert_int_equal(ref.id[T[0].cols[a0]], sub.id[T[1].cols[b0]]);
        for (int k = 0; k <= dim; ++k) assert_memory_equal(&T[0].tab[k][a0], &T[1].tab[k][b0], sizeof(double));
      }
    }
    for (int side = 0; side < 2; ++side) {
      free(T[side].cols);
      for (int k = 0; k <= dim; ++k) free(T[side].tab[k]);
    }
  }
}

/* Pair gradients (a host's half pair list): the set permuted, its pairs listed in
 * another order and orientation, every pair's i and j sides the same bits, for SPH, RL,
 * KB 1, MLS 1, 2D and 3D. */
static void test_pair_gradients(void **s) {
  (void)s;
  static cloud_t ref, sub;
  static int32_t pi[2][NMAX * 40], pj[2][NMAX * 40];
  static int64_t where[NMAX * 40];
  static int flip[NMAX * 40];
  const int methods[4] = {MFREE_METHOD_SPH, MFREE_METHOD_RANDLES_LIBERSKY, MFREE_METHOD_KB_METHOD1,
                          MFREE_METHOD_MLS};
  for (int dim = 2; dim <= 3; ++dim) {
    make_cloud(&ref, dim, dim == 2 ? 15 : 7, 31 + dim);
    make_subdomain(&sub, &ref, INFINITY, 0, 12);
    int inv[NMAX];
    for (int k = 0; k < sub.n; ++k) inv[sub.orig[k]] = k;
    int64_t np = 0;
    for (int i = 0; i < ref.n; ++i)
      for (int j = i + 1; j < ref.n; ++j) {
        double r2 = 0, hm = ref.h[i] > ref.h[j] ? ref.h[i] : ref.h[j];
        for (int d = 0; d < dim; ++d) r2 += pow(ref.x[i * dim + d] - ref.x[j * dim + d], 2);
        if (r2 < KAPPA * KAPPA * hm * hm) {
          assert_true(np < NMAX * 40);
          pi[0][np] = i;
          pj[0][np] = j;
          ++np;
        }
      }
    /* the permuted list: pair k of the reference at where[k], flipped or not */
    mfree_rng_t r;
    mfree_rng_seed(&r, 5);
    for (int64_t k = 0; k < np; ++k) where[k] = k;
    for (int64_t k = np - 1; k > 0; --k) {
      const int64_t j = (int64_t)(mfree_rng_uniform(&r) * (double)(k + 1)), t = where[k];
      where[k] = where[j];
      where[j] = t;
    }
    for (int64_t k = 0; k < np; ++k) {
      flip[k] = mfree_rng_uniform(&r) < 0.5;
      const int a = inv[pi[0][k]], b = inv[pj[0][k]];
      pi[1][where[k]] = flip[k] ? b : a;
      pj[1][where[k]] = flip[k] ? a : b;
    }
    for (int m = 0; m < 4; ++m) {
      double *g[2][2];
      for (int side = 0; side < 2; ++side) {
        const cloud_t *c = side ? &sub : &ref;
        mfree_context_t *cx = side ? ctx2 : ctx;
        mfree_particles_t *ps = make_set(cx, c, MFREE_SEARCH_GATHER, 1);
        assert_ok(cx, mfree_particles_set_pairs(ps, np, pi[side], pj[side], 0, MFREE_COPY));
        assert_ok(cx, mfree_particles_setup(ps));
        mfree_approximant_t *a = NULL;
        assert_ok(cx, mfree_approximant_create(cx, ps, methods[m], &a));
        assert_ok(cx, mfree_approximant_setup(a));
        for (int q = 0; q < 2; ++q) g[side][q] = malloc(sizeof(double) * (size_t)(np * dim + 1));
        assert_ok(cx, mfree_approximant_get_pair_gradients(a, g[side][0], g[side][1], dim, np * dim));
        mfree_approximant_destroy(&a);
        mfree_particles_destroy(&ps);
      }
      for (int64_t k = 0; k < np; ++k) {
        const double *ai = g[0][0] + k * dim, *aj = g[0][1] + k * dim;
        const double *bi = g[1][flip[k]] + where[k] * dim, *bj = g[1][!flip[k]] + where[k] * dim;
        if (memcmp(ai, bi, sizeof(double) * dim) || memcmp(aj, bj, sizeof(double) * dim))
          fail_msg("%dD method %d: pair %lld (ids %lld, %lld) differs: %.17g / %.17g", dim, methods[m],
                   (long long)k, (long long)ref.id[pi[0][k]], (long long)ref.id[pj[0][k]], ai[0], bi[0]);
      }
      for (int side = 0; side < 2; ++side)
        for (int q = 0; q < 2; ++q) free(g[side][q]);
    }
  }
}

static void test_permutation_2d(void **s) { (void)s; run(2, 0); }
static void test_permutation_3d(void **s) { (void)s; run(3, 0); }
static void test_subdomain_2d(void **s) { (void)s; run(2, 1); }
static void test_subdomain_3d(void **s) { (void)s; run(3, 1); }
static void test_host_lists_2d(void **s) { (void)s; run(2, 2); }
static void test_host_lists_3d(void **s) { (void)s; run(3, 2); }
static void test_symmetric_mean_2d(void **s) { (void)s; run(2, 3); }
static void test_symmetric_mean_3d(void **s) { (void)s; run(3, 3); }
static void test_id_order_2d(void **s) { (void)s; run(2, 4); }
static void test_id_order_3d(void **s) { (void)s; run(3, 4); }

/* Without ids the rows stay sorted by local index; the ids order them by id. */
static void test_row_order(void **s) {
  (void)s;
  static cloud_t c;
  make_cloud(&c, 2, 9, 3);
  for (int i = 0; i < c.n; ++i) c.id[i] = (int64_t)((i * 37) % c.n) * 1000000007LL;  /* scrambled */
  mfree_particles_t *ps = make_set(ctx, &c, MFREE_SEARCH_GATHER, 0);
  int64_t rp[NMAX + 1], nnz = 0;
  static int32_t cols[NMAX * NMAX];
  assert_ok(ctx, mfree_particles_setup(ps));
  assert_ok(ctx, mfree_particles_get_neighbors(ps, rp, cols));
  for (int i = 0; i < c.n; ++i)
    for (int64_t k = rp[i] + 1; k < rp[i + 1]; ++k) assert_true(cols[k - 1] < cols[k]);
  assert_ok(ctx, mfree_particles_get_neighbor_nnz(ps, &nnz));
  const int64_t nnz0 = nnz;
  assert_ok(ctx, mfree_particles_set_global_ids(ps, c.id, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_setup(ps));
  assert_ok(ctx, mfree_particles_get_neighbors(ps, rp, cols));
  assert_ok(ctx, mfree_particles_get_neighbor_nnz(ps, &nnz));
  assert_int_equal(nnz, nnz0);
  int unsorted = 0;
  for (int i = 0; i < c.n; ++i)
    for (int64_t k = rp[i] + 1; k < rp[i + 1]; ++k) {
      assert_true(c.id[cols[k - 1]] < c.id[cols[k]]);
      unsorted += cols[k - 1] > cols[k];
    }
  assert_true(unsorted > 0); /* the ids did reorder the rows */
  int64_t got[NMAX];
  assert_ok(ctx, mfree_particles_get_global_ids(ps, got));
  assert_memory_equal(got, c.id, sizeof(int64_t) * (size_t)c.n);
  /* removing the ids restores index order */
  assert_ok(ctx, mfree_particles_set_global_ids(ps, NULL, MFREE_COPY));
  assert_error(ctx, mfree_particles_get_global_ids(ps, got), MFREE_ERR_STATE, "no global ids");
  assert_ok(ctx, mfree_particles_setup(ps));
  assert_ok(ctx, mfree_particles_get_neighbors(ps, rp, cols));
  for (int i = 0; i < c.n; ++i)
    for (int64_t k = rp[i] + 1; k < rp[i + 1]; ++k) assert_true(cols[k - 1] < cols[k]);
  mfree_particles_destroy(&ps);
}

static void test_bad_ids(void **s) {
  (void)s;
  static cloud_t c;
  make_cloud(&c, 2, 6, 4);
  mfree_particles_t *ps = make_set(ctx, &c, MFREE_SEARCH_GATHER, 0);
  int64_t ids[NMAX], got[NMAX];
  memcpy(ids, c.id, sizeof(int64_t) * (size_t)c.n);
  ids[9] = ids[4];
  assert_error(ctx, mfree_particles_set_global_ids(ps, ids, MFREE_COPY), MFREE_ERR_INPUT,
               "particles 4 and 9");
  assert_error(ctx, mfree_particles_get_global_ids(ps, got), MFREE_ERR_STATE, "no global ids");
  ids[9] = -3;
  assert_error(ctx, mfree_particles_set_global_ids(ps, ids, MFREE_BORROW), MFREE_ERR_INPUT, ">= 0");
  assert_error(ctx, mfree_particles_set_global_ids(ps, c.id, 3), MFREE_ERR_ARG, "mem");
  assert_int_equal(mfree_particles_set_global_ids(NULL, c.id, MFREE_COPY), MFREE_ERR_NULL);
  /* borrowed ids that turn repeated before setup: MFREE_ERR_INPUT, the set as it was */
  memcpy(ids, c.id, sizeof(int64_t) * (size_t)c.n);
  assert_ok(ctx, mfree_particles_set_global_ids(ps, ids, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_setup(ps));
  int64_t rp0[NMAX + 1], rp1[NMAX + 1];
  static int32_t k0[NMAX * NMAX], k1[NMAX * NMAX];
  assert_ok(ctx, mfree_particles_get_neighbors(ps, rp0, k0));
  ids[c.n - 1] = ids[0];
  assert_error(ctx, mfree_particles_setup(ps), MFREE_ERR_INPUT, "unique");
  assert_ok(ctx, mfree_particles_get_neighbors(ps, rp1, k1));
  assert_memory_equal(rp0, rp1, sizeof(int64_t) * (size_t)(c.n + 1));
  assert_memory_equal(k0, k1, sizeof(int32_t) * (size_t)rp0[c.n]);
  mfree_particles_destroy(&ps);
}

static void test_halo_width(void **s) {
  (void)s;
  static cloud_t ref, sub;
  make_cloud(&ref, 2, 12, 5);
  const double hmax = max_support(&ref);
  make_subdomain(&sub, &ref, 0.5, KAPPA * hmax, 6);
  mfree_particles_t *ps = make_set(ctx, &sub, MFREE_SEARCH_GATHER, 1);
  double hown = 0, hsub = max_support(&sub);
  for (int i = 0; i < sub.n - sub.n_ghost; ++i) hown = sub.h[i] > hown ? sub.h[i] : hown;
  assert_error(ctx, mfree_particles_set_halo_width(ps, -1.0), MFREE_ERR_ARG, "halo width");
  assert_error(ctx, mfree_particles_set_halo_width(ps, NAN), MFREE_ERR_ARG, "halo width");
  assert_error(ctx, mfree_particles_set_halo_width(ps, INFINITY), MFREE_ERR_ARG, "halo width");
  /* narrower than the search radius kappa h of some owned particle */
  assert_ok(ctx, mfree_particles_set_halo_width(ps, 0.999 * KAPPA * hown));
  assert_error(ctx, mfree_particles_setup(ps), MFREE_ERR_HALO, "reaches past the declared halo width");
  char msg[512];
  mfree_context_get_last_error(ctx, NULL, msg, sizeof msg);
  assert_non_null(strstr(msg, "global id"));
  assert_ok(ctx, mfree_particles_set_halo_width(ps, KAPPA * hmax));
  assert_ok(ctx, mfree_particles_setup(ps));
  /* symmetric convention: the largest support present counts */
  assert_ok(ctx, mfree_particles_set_search(ps, MFREE_SEARCH_SYMMETRIC_MAX, KAPPA));
  assert_ok(ctx, mfree_particles_set_halo_width(ps, KAPPA * hsub * 0.999));
  assert_error(ctx, mfree_particles_setup(ps), MFREE_ERR_HALO, "search radius");
  assert_ok(ctx, mfree_particles_set_search(ps, MFREE_SEARCH_GATHER, KAPPA));
  /* host lists: the set does not search, the approximant checks the kernel's support */
  int64_t rp[NMAX + 1];
  static int32_t cols[NMAX * NMAX];
  host_lists(&sub, rp, cols, 2);
  assert_ok(ctx, mfree_particles_set_neighbors(ps, rp, cols, 1, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_halo_width(ps, 0.5 * KAPPA * hmax));
  assert_ok(ctx, mfree_particles_setup(ps));
  mfree_approximant_t *a = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_RANDLES_LIBERSKY, &a));
  assert_error(ctx, mfree_approximant_setup(a), MFREE_ERR_HALO, "kernel support");
  assert_ok(ctx, mfree_particles_set_halo_width(ps, 0.0));  /* none declared */
  assert_ok(ctx, mfree_particles_setup(ps));
  assert_ok(ctx, mfree_approximant_setup(a));
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_permutation_2d),    cmocka_unit_test(test_permutation_3d),
      cmocka_unit_test(test_subdomain_2d),      cmocka_unit_test(test_subdomain_3d),
      cmocka_unit_test(test_host_lists_2d),     cmocka_unit_test(test_host_lists_3d),
      cmocka_unit_test(test_symmetric_mean_2d), cmocka_unit_test(test_symmetric_mean_3d),
      cmocka_unit_test(test_id_order_2d),       cmocka_unit_test(test_id_order_3d),
      cmocka_unit_test(test_points),            cmocka_unit_test(test_pair_gradients),
      cmocka_unit_test(test_row_order),         cmocka_unit_test(test_bad_ids),
      cmocka_unit_test(test_halo_width),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
