/* Corrected gradients on 1-4 ranks bitwise equal to one rank (label mpi).
 * Every rank builds the same cloud and computes the one-rank reference itself; then the
 * particles are split (slab along x, random by id, Zoltan RCB), each rank's owned share
 * in a random order of its own, the ghost layer built by libmfree_mpi (positions,
 * supports and volumes exchanged as one record), and for SPH, RL, KB Method 1, MLS 1,
 * MLS 2 and SSPH 2 every owned particle's gradient-table row (columns by global id) and
 * its apply(GRADIENT) of two exchanged fields must equal the reference bit for bit,
 * 2D and 3D. The ghosts' data must be their owners' (by id), the global numbering an
 * exclusive scan, and after the particles move and the plan is rebuilt the RL rows again
 * equal a one-rank run of the moved cloud. With a plan two support radii wide and the
 * first layer of ghosts counted as owned, the first layer's rows (RL, KB 1, MLS 2, whose
 * correction matrices and coefficients they hold) are their owners' bits too.
 * Pair gradients (a half pair list within kappa (h_i + h_j) / 2 on each rank, every pair
 * with an owned particle): for SPH, RL, KB Method 1, MLS 1 and MLS 2 both sides (gi, gj)
 * and the antisymmetrised form of every pair equal the one-rank pair's bit for bit, the
 * ghost side computed from the ghosts' correction records, which
 * mfree_halo_exchange_correction brings from their owners. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpitest.h"

typedef struct {
  int method, order;
  const char *name;
} method_t;
static const method_t kMethods[] = {
    {MFREE_METHOD_SPH, 0, "SPH"},        {MFREE_METHOD_RANDLES_LIBERSKY, 0, "RL"},
    {MFREE_METHOD_KB_METHOD1, 0, "KB1"}, {MFREE_METHOD_MLS, 1, "MLS1"},
    {MFREE_METHOD_MLS, 2, "MLS2"},       {MFREE_METHOD_SSPH, 2, "SSPH2"},
};
#define NMETHODS 6

/* One approximant's gradient rows and apply(GRADIENT) of two fields, columns as ids. */
typedef struct {
  int nsites, dim;
  int64_t *rp, *cid;
  double *g, *ap; /* g: nnz x dim; ap: nsites x 2 dim */
} rows_t;

static void field_at(int64_t id, double *u) {
  u[0] = sin(0.01 * (double)id + 0.3);
  u[1] = cos(0.013 * (double)id) * (double)(1 + id % 7);
}

static void compute_rows(mfree_context_t *ctx, mfree_particles_t *ps, const int64_t *ids, int n,
                         const method_t *m, rows_t *r) {
  mfree_approximant_t *a = NULL;
  int dim = 0;
  mfree_particles_get_dimension(ps, &dim);
  CHECK(mfree_approximant_create(ctx, ps, m->method, &a) == MFREE_SUCCESS, "create %s", m->name);
  if (m->order) mfree_approximant_set_order(a, m->order);
  mfree_approximant_set_derivatives(a, MFREE_DERIV_GRADIENT);
  const mfree_status_t st = mfree_approximant_setup(a);
  CHECK(st == MFREE_SUCCESS, "%s setup status %d", m->name, (int)st);
  int32_t ns = 0;
  int64_t nnz = 0;
  mfree_approximant_get_num_sites(a, &ns);
  mfree_approximant_get_nnz(a, &nnz);
  r->nsites = ns;
  r->dim = dim;
  r->rp = malloc(sizeof(int64_t) * (size_t)(ns + 1));
  r->cid = malloc(sizeof(int64_t) * (size_t)(nnz + 1));
  r->g = malloc(sizeof(double) * (size_t)(nnz * dim + 1));
  int32_t *cols = malloc(sizeof(int32_t) * (size_t)(nnz + 1));
  double *tmp = malloc(sizeof(double) * (size_t)(nnz + 1));
  for (int c = 0; c < dim; ++c) {
    mfree_approximant_assemble_csr(a, MFREE_DERIV_GRADIENT, c, r->rp, cols, tmp);
    for (int64_t k = 0; k < nnz; ++k) r->g[k * dim + c] = tmp[k];
  }
  for (int64_t k = 0; k < nnz; ++k) r->cid[k] = ids[cols[k]];
  double *u = malloc(sizeof(double) * (size_t)(2 * n + 1));
  for (int j = 0; j < n; ++j) field_at(ids[j], u + 2 * j);
  r->ap = malloc(sizeof(double) * (size_t)(2 * dim * ns + 1));
  CHECK(mfree_approximant_apply(a, MFREE_OP_GRADIENT, 2, u, MFREE_LAYOUT_AOS, 2, r->ap, MFREE_LAYOUT_AOS,
                                2 * dim) == MFREE_SUCCESS,
        "%s apply", m->name);
  free(u);
  free(cols);
  free(tmp);
  mfree_approximant_destroy(&a);
}

static void free_rows(rows_t *r) {
  free(r->rp);
  free(r->cid);
  free(r->g);
  free(r->ap);
}

static mfree_particles_t *reference_set(mfree_context_t *ctx, const cloud_t *c) {
  mfree_particles_t *ps = NULL;
  mfree_particles_create(ctx, c->dim, c->n, &ps);
  mfree_particles_set_positions(ps, c->x, MFREE_LAYOUT_AOS, c->dim, MFREE_BORROW);
  mfree_particles_set_support(ps, c->h, 1, MFREE_BORROW);
  mfree_particles_set_volumes(ps, c->v, 1, MFREE_BORROW);
  mfree_particles_set_global_ids(ps, c->id, MFREE_BORROW);
  CHECK(mfree_particles_setup(ps) == MFREE_SUCCESS, "reference setup");
  return ps;
}

/* Owned row k (global id ids[k]) of d against the reference row of the same id. */
static void compare_rows(const rows_t *ref, const rows_t *d, const int64_t *ids, int n_owned, const char *what) {
  const int dim = ref->dim;
  int bad = 0;
  for (int k = 0; k < n_owned && bad < 3; ++k) {
    const int s = (int)((ids[k] - 5) / 2);
    const int64_t a0 = ref->rp[s], a1 = ref->rp[s + 1], b0 = d->rp[k], b1 = d->rp[k + 1];
    int ok = a1 - a0 == b1 - b0;
    for (int64_t q = 0; ok && q < a1 - a0; ++q)
      ok = ref->cid[a0 + q] == d->cid[b0 + q] &&
           !memcmp(ref->g + (a0 + q) * dim, d->g + (b0 + q) * dim, sizeof(double) * dim);
    ok = ok && !memcmp(ref->ap + (size_t)s * 2 * dim, d->ap + (size_t)k * 2 * dim, sizeof(double) * 2 * dim);
    CHECK(ok, "%s: particle id %lld differs from one rank (row %lld / %lld entries)", what,
          (long long)ids[k], (long long)(a1 - a0), (long long)(b1 - b0));
    bad += !ok;
  }
}

/* ---- pair gradients ---------------------------------------------------------------- */

/* The methods whose pair gradients are checked: every one with a correction record
 * (SSPH has none: its ghost side stays 0) and SPH (from the kernel, no record). */
static const int kPairMethods[] = {0, 1, 2, 3, 4};
#define NPAIRMETHODS 5

/* A half pair list (cloud indices pi < pj, ascending) and its gradients per method. */
typedef struct {
  int64_t np;
  int32_t *pi, *pj;
  double *gi[NPAIRMETHODS], *gj[NPAIRMETHODS], *ga[NPAIRMETHODS];
} pairs_t;

/* a and b pair when closer than kappa (h_a + h_b) / 2 (SYMMETRIC_MEAN); computed in the
 * same order on every rank (the lower id first) so that the bits agree */
static int paired(const double *xa, double ha, const double *xb, double hb, int dim) {
  double r2 = 0;
  for (int d = 0; d < dim; ++d) r2 += (xa[d] - xb[d]) * (xa[d] - xb[d]);
  const double reach = KAPPA * 0.5 * (ha + hb);
  return r2 < reach * reach;
}

/* A set of n particles (positions every xld doubles, supports and volumes every hs; the
 * last n_ghost ghosts) with a pair list and global ids, set up. */
static mfree_particles_t *pair_set(mfree_context_t *ctx, int dim, int n, int n_ghost, const double *x,
                                   int64_t xld, const double *h, const double *v, int64_t hs,
                                   const int64_t *ids, int64_t np, const int32_t *pi, const int32_t *pj,
                                   double width) {
  mfree_particles_t *ps = NULL;
  mfree_particles_create(ctx, dim, n, &ps);
  mfree_particles_set_num_ghost(ps, n_ghost);
  mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, xld, MFREE_BORROW);
  mfree_particles_set_support(ps, h, hs, MFREE_BORROW);
  mfree_particles_set_volumes(ps, v, hs, MFREE_BORROW);
  mfree_particles_set_global_ids(ps, ids, MFREE_BORROW);
  mfree_particles_set_search(ps, MFREE_SEARCH_SYMMETRIC_MEAN, KAPPA);
  mfree_particles_set_pairs(ps, np, pi, pj, 0, MFREE_COPY);
  if (width > 0) mfree_particles_set_halo_width(ps, width);
  const mfree_status_t st = mfree_particles_setup(ps);
  CHECK(st == MFREE_SUCCESS, "pair set setup %d", (int)st);
  return ps;
}

/* Pair gradients of method m on ps: gi, gj and the antisymmetrised g, np * dim each. With
 * a halo, the ghosts' correction records come from their owners first (collective). */
static void pair_gradients(mfree_context_t *ctx, mfree_particles_t *ps, mfree_halo_t *halo, const method_t *m,
                           int dim, int64_t np, double **gi, double **gj, double **ga) {
  mfree_approximant_t *a = NULL;
  CHECK(mfree_approximant_create(ctx, ps, m->method, &a) == MFREE_SUCCESS, "pairs: create %s", m->name);
  if (m->order) mfree_approximant_set_order(a, m->order);
  mfree_approximant_set_derivatives(a, MFREE_DERIV_GRADIENT);
  mfree_status_t st = mfree_approximant_setup(a);
  CHECK(st == MFREE_SUCCESS, "pairs: %s setup %d", m->name, (int)st);
  if (halo && m->method != MFREE_METHOD_SPH) {
    st = mfree_halo_exchange_correction(halo, a);
    CHECK(st == MFREE_SUCCESS, "pairs: %s correction exchange %d", m->name, (int)st);
  }
  const int64_t cap = np * dim;
  *gi = malloc(sizeof(double) * (size_t)(cap + 1));
  *gj = malloc(sizeof(double) * (size_t)(cap + 1));
  *ga = malloc(sizeof(double) * (size_t)(cap + 1));
  CHECK(mfree_approximant_get_pair_gradients(a, *gi, *gj, dim, cap) == MFREE_SUCCESS, "pairs: %s gradients",
        m->name);
  CHECK(mfree_approximant_get_pair_gradients_antisymmetric(a, *ga, dim, cap) == MFREE_SUCCESS,
        "pairs: %s antisymmetric", m->name);
  mfree_approximant_destroy(&a);
}

static void reference_pairs(mfree_context_t *ctx, const cloud_t *c, pairs_t *p) {
  const int dim = c->dim;
  int64_t cap = 64, np = 0;
  p->pi = malloc(sizeof(int32_t) * (size_t)cap);
  p->pj = malloc(sizeof(int32_t) * (size_t)cap);
  for (int i = 0; i < c->n; ++i)
    for (int j = i + 1; j < c->n; ++j)
      if (paired(c->x + (size_t)i * dim, c->h[i], c->x + (size_t)j * dim, c->h[j], dim)) {
        if (np == cap) {
          cap *= 2;
          p->pi = realloc(p->pi, sizeof(int32_t) * (size_t)cap);
          p->pj = realloc(p->pj, sizeof(int32_t) * (size_t)cap);
        }
        p->pi[np] = i;
        p->pj[np++] = j;
      }
  p->np = np;
  mfree_particles_t *ps = pair_set(ctx, dim, c->n, 0, c->x, dim, c->h, c->v, 1, c->id, np, p->pi, p->pj, 0.0);
  for (int q = 0; q < NPAIRMETHODS; ++q)
    pair_gradients(ctx, ps, NULL, &kMethods[kPairMethods[q]], dim, np, &p->gi[q], &p->gj[q], &p->ga[q]);
  mfree_particles_destroy(&ps);
}

static void free_pairs(pairs_t *p) {
  free(p->pi);
  free(p->pj);
  for (int q = 0; q < NPAIRMETHODS; ++q) {
    free(p->gi[q]);
    free(p->gj[q]);
    free(p->ga[q]);
  }
}

/* The rank's pairs (every pair with an owned particle among its n = owned + ghost
 * particles, the lower id first) against the reference pairs of the same ids. */
static void check_pairs(mfree_context_t *ctx, mfree_halo_t *halo, const cloud_t *c, const pairs_t *ref,
                        const double *rec, int R, const int64_t *ids, int n_owned, int n, double width,
                        const char *label) {
  const int dim = c->dim;
  int64_t cap = 64, np = 0;
  int32_t *pi = malloc(sizeof(int32_t) * (size_t)cap), *pj = malloc(sizeof(int32_t) * (size_t)cap);
  int64_t *at = malloc(sizeof(int64_t) * (size_t)cap); /* the reference pair */
  int missing = 0;
  for (int a = 0; a < n_owned; ++a)
    for (int b = 0; b < n; ++b) {
      if (b == a || (b < n_owned && b < a)) continue; /* owned pairs once */
      const int lo = ids[a] < ids[b] ? a : b, hi = lo == a ? b : a;
      if (!paired(rec + (size_t)lo * R, rec[(size_t)lo * R + dim], rec + (size_t)hi * R, rec[(size_t)hi * R + dim],
                  dim))
        continue;
      if (np == cap) {
        cap *= 2;
        pi = realloc(pi, sizeof(int32_t) * (size_t)cap);
        pj = realloc(pj, sizeof(int32_t) * (size_t)cap);
        at = realloc(at, sizeof(int64_t) * (size_t)cap);
      }
      /* the reference pair of cloud indices (i, j), i < j, by bisection */
      const int32_t i = (int32_t)((ids[lo] - 5) / 2), j = (int32_t)((ids[hi] - 5) / 2);
      int64_t k0 = 0, k1 = ref->np;
      while (k0 < k1) {
        const int64_t mid = (k0 + k1) / 2;
        if (ref->pi[mid] < i || (ref->pi[mid] == i && ref->pj[mid] < j)) k0 = mid + 1;
        else k1 = mid;
      }
      if (k0 == ref->np || ref->pi[k0] != i || ref->pj[k0] != j) {
        ++missing;
        continue;
      }
      pi[np] = lo;
      pj[np] = hi;
      at[np++] = k0;
    }
  CHECK(missing == 0, "%s: %d pairs of this rank are not pairs of one rank", label, missing);
  /* every reference pair with an owned particle of this rank is here once */
  int64_t want = 0;
  for (int64_t k = 0; k < ref->np; ++k) {
    int own_i = 0, own_j = 0;
    for (int a = 0; a < n_owned && !(own_i && own_j); ++a) {
      own_i = own_i || ids[a] == c->id[ref->pi[k]];
      own_j = own_j || ids[a] == c->id[ref->pj[k]];
    }
    want += own_i || own_j;
  }
  CHECK(want == np, "%s: %lld pairs with an owned particle, one rank has %lld", label, (long long)np,
        (long long)want);
  mfree_particles_t *ps =
      pair_set(ctx, dim, n, n - n_owned, rec, R, rec + dim, rec + dim + 1, R, ids, np, pi, pj, width);
  for (int q = 0; q < NPAIRMETHODS; ++q) {
    const method_t *m = &kMethods[kPairMethods[q]];
    double *gi = NULL, *gj = NULL, *ga = NULL;
    pair_gradients(ctx, ps, halo, m, dim, np, &gi, &gj, &ga);
    int bad = 0;
    for (int64_t k = 0; k < np && bad < 3; ++k) {
      const size_t r = (size_t)at[k] * dim, o = (size_t)k * dim, sz = sizeof(double) * dim;
      const int ok_i = !memcmp(ref->gi[q] + r, gi + o, sz), ok_j = !memcmp(ref->gj[q] + r, gj + o, sz),
                ok_a = !memcmp(ref->ga[q] + r, ga + o, sz);
      CHECK(ok_i && ok_j && ok_a,
            "%s %s: pair of ids (%lld, %lld)%s differs from one rank:%s%s%s", label, m->name,
            (long long)ids[pi[k]], (long long)ids[pj[k]], pj[k] >= n_owned ? " (a ghost)" : "",
            ok_i ? "" : " gi", ok_j ? "" : " gj", ok_a ? "" : " antisymmetric");
      bad += !(ok_i && ok_j && ok_a);
    }
    free(gi);
    free(gj);
    free(ga);
  }
  mfree_particles_destroy(&ps);
  free(pi);
  free(pj);
  free(at);
}

/* The distributed run of one decomposition, compared with ref (one per method). */
/* layers = 2: the plan reaches two support radii and the ghosts within one radius of an
 * owned particle (the first layer) count as owned in the set, so that their rows, and
 * their correction data, are computed here too and must be their owners' bits. */
static void run(mfree_context_t *ctx, mfree_halo_t *halo, const cloud_t *c, const int *part, rows_t *ref,
                const method_t *methods, int nmethods, int layers, const pairs_t *pref, const char *label) {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const int dim = c->dim, R = dim + 2;
  int no = 0;
  int *own = malloc(sizeof(int) * (size_t)c->n);
  for (int i = 0; i < c->n; ++i)
    if (part[i] == rank) own[no++] = i;
  uint64_t s = 1234 + (uint64_t)rank;
  for (int i = no - 1; i > 0; --i) { /* this rank's own order */
    s = mpitest_hash(s);
    const int j = (int)(s % (uint64_t)(i + 1)), t = own[i];
    own[i] = own[j];
    own[j] = t;
  }
  double *xo = malloc(sizeof(double) * (size_t)(no * dim + 1));
  int64_t *io = malloc(sizeof(int64_t) * (size_t)(no + 1));
  for (int k = 0; k < no; ++k) {
    memcpy(xo + k * dim, c->x + (size_t)own[k] * dim, sizeof(double) * dim);
    io[k] = c->id[own[k]];
  }
  const double width = KAPPA * cloud_max_support(c) * (1 + 1e-12);
  mfree_status_t st = mfree_halo_setup(halo, no, xo, dim, io, layers * width);
  CHECK(st == MFREE_SUCCESS, "%s: halo setup %d", label, (int)st);
  int32_t n_owned = 0, n_ghost = 0;
  mfree_halo_get_size(halo, &n_owned, &n_ghost);
  CHECK(n_owned == no, "%s: n_owned", label);
  const int n = n_owned + n_ghost;
  int64_t *ids = malloc(sizeof(int64_t) * (size_t)(n + 1)), off = -1, total = -1;
  mfree_halo_get_global_ids(halo, ids);
  mfree_halo_get_global_offset(halo, &off, &total);
  int64_t scan = 0, nn = no;
  MPI_Exscan(&nn, &scan, 1, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
  CHECK(total == c->n && off == (rank ? scan : 0), "%s: offset %lld total %lld", label, (long long)off,
        (long long)total);
  /* one record per particle: x, h, V (owned filled, ghosts exchanged) */
  double *rec = malloc(sizeof(double) * (size_t)(n * R + 1));
  for (int k = 0; k < n; ++k)
    for (int q = 0; q < R; ++q) rec[k * R + q] = k < no ? NAN : -1.0;
  for (int k = 0; k < no; ++k) {
    memcpy(rec + k * R, xo + k * dim, sizeof(double) * dim);
    rec[k * R + dim] = c->h[own[k]];
    rec[k * R + dim + 1] = c->v[own[k]];
  }
  CHECK(mfree_halo_exchange(halo, R, rec, R) == MFREE_SUCCESS, "%s: exchange", label);
  for (int g = no; g < n; ++g) {
    const int i = (int)((ids[g] - 5) / 2);
    CHECK(ids[g] >= 5 && i < c->n && part[i] != rank, "%s: ghost id %lld", label, (long long)ids[g]);
    if (ids[g] < 5 || i >= c->n) continue;
    CHECK(!memcmp(rec + g * R, c->x + (size_t)i * dim, sizeof(double) * dim) && rec[g * R + dim] == c->h[i] &&
              rec[g * R + dim + 1] == c->v[i],
          "%s: ghost id %lld holds other data than its owner", label, (long long)ids[g]);
  }
  /* a strided field (ld > ncomp): the exchange writes components [0, ncomp) only */
  double *u = malloc(sizeof(double) * (size_t)(3 * n + 1));
  for (int k = 0; k < n; ++k) {
    if (k < no) field_at(ids[k], u + 3 * k);
    else u[3 * k] = u[3 * k + 1] = 0.0;
    u[3 * k + 2] = 42.0;
  }
  CHECK(mfree_halo_exchange(halo, 2, u, 3) == MFREE_SUCCESS, "%s: strided exchange", label);
  for (int g = no; g < n; ++g) {
    double w[2];
    field_at(ids[g], w);
    CHECK(u[3 * g] == w[0] && u[3 * g + 1] == w[1] && u[3 * g + 2] == 42.0, "%s: strided exchange at %d", label,
          g);
  }
  /* two layers: first-layer ghosts moved before the second layer and given rows */
  int nrows = no, set_ghosts = n_ghost;
  if (layers == 2) {
    double *rec2 = malloc(sizeof(double) * (size_t)(n * R + 1));
    int64_t *ids2 = malloc(sizeof(int64_t) * (size_t)(n + 1));
    int *second = malloc(sizeof(int) * (size_t)(n + 1)), ns = 0;
    memcpy(rec2, rec, sizeof(double) * (size_t)no * R);
    memcpy(ids2, ids, sizeof(int64_t) * (size_t)no);
    for (int g = no; g < n; ++g) {
      int first = 0;
      for (int k = 0; k < no && !first; ++k) {
        double r2 = 0;
        for (int d = 0; d < dim; ++d) r2 += pow(rec[g * R + d] - rec[k * R + d], 2);
        first = r2 <= width * width;
      }
      if (first) {
        memcpy(rec2 + (size_t)nrows * R, rec + (size_t)g * R, sizeof(double) * R);
        ids2[nrows++] = ids[g];
      } else {
        second[ns++] = g;
      }
    }
    for (int q = 0; q < ns; ++q) {
      memcpy(rec2 + (size_t)(nrows + q) * R, rec + (size_t)second[q] * R, sizeof(double) * R);
      ids2[nrows + q] = ids[second[q]];
    }
    int size = 1;
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    CHECK(size == 1 || (nrows > no && ns > 0), "%s: %d first-layer and %d second-layer ghosts", label, nrows - no, ns);
    set_ghosts = ns;
    memcpy(rec, rec2, sizeof(double) * (size_t)n * R);
    memcpy(ids, ids2, sizeof(int64_t) * (size_t)n);
    free(rec2);
    free(ids2);
    free(second);
  }
  /* the particle set on this rank, borrowing the records */
  mfree_particles_t *ps = NULL;
  mfree_particles_create(ctx, dim, n, &ps);
  mfree_particles_set_num_ghost(ps, set_ghosts);
  mfree_particles_set_positions(ps, rec, MFREE_LAYOUT_AOS, R, MFREE_BORROW);
  mfree_particles_set_support(ps, rec + dim, R, MFREE_BORROW);
  mfree_particles_set_volumes(ps, rec + dim + 1, R, MFREE_BORROW);
  mfree_particles_set_global_ids(ps, ids, MFREE_BORROW);
  mfree_particles_set_halo_width(ps, width);
  st = mfree_particles_setup(ps);
  CHECK(st == MFREE_SUCCESS, "%s: particle setup %d", label, (int)st);
  for (int m = 0; m < nmethods; ++m) {
    rows_t d;
    char what[128];
    snprintf(what, sizeof what, "%s %s", label, methods[m].name);
    compute_rows(ctx, ps, ids, n, &methods[m], &d);
    compare_rows(&ref[m], &d, ids, nrows, what);
    free_rows(&d);
  }
  mfree_particles_destroy(&ps);
  if (pref) check_pairs(ctx, halo, c, pref, rec, R, ids, no, n, width, label);
  free(u);
  free(rec);
  free(ids);
  free(xo);
  free(io);
  free(own);
}

int main(int argc, char **argv) {
  int rank = 0, size = 1;
  mfree_context_t *ctx = mpitest_start(&argc, &argv, &rank, &size);
  for (int dim = 2; dim <= 3; ++dim) {
    mfree_halo_t *halo = NULL;
    CHECK(mfree_halo_create(ctx, MPI_COMM_WORLD, dim, &halo) == MFREE_SUCCESS, "halo create");
    cloud_t c;
    cloud_make(&c, dim, dim == 2 ? 22 : 9, 77 + dim);
    mfree_particles_t *ps = reference_set(ctx, &c);
    rows_t ref[NMETHODS];
    for (int m = 0; m < NMETHODS; ++m) compute_rows(ctx, ps, c.id, c.n, &kMethods[m], &ref[m]);
    pairs_t pref;
    reference_pairs(ctx, &c, &pref);
    int *part = malloc(sizeof(int) * (size_t)c.n);
    const char *names[3] = {"slab", "random", "Zoltan RCB"};
    for (int how = 0; how < 3; ++how) {
      if (decompose(&c, how, MPI_COMM_WORLD, part) != 0) {
        if (rank == 0) printf("%dD %s: skipped (no Zoltan)\n", dim, names[how]);
        continue;
      }
      char label[64];
      snprintf(label, sizeof label, "%dD %s on %d ranks", dim, names[how], size);
      run(ctx, halo, &c, part, ref, kMethods, NMETHODS, 1, &pref, label);
      if (rank == 0) printf("%s: done\n", label);
    }
    /* two layers: the first layer's rows (RL, KB 1, MLS 2: their correction data) too */
    {
      const method_t two[3] = {kMethods[1], kMethods[2], kMethods[4]};
      rows_t ref2[3] = {ref[1], ref[2], ref[4]};
      char label[64];
      decompose(&c, DECOMP_SLAB, MPI_COMM_WORLD, part);
      snprintf(label, sizeof label, "%dD slab, two layers, on %d ranks", dim, size);
      run(ctx, halo, &c, part, ref2, two, 3, 2, NULL, label);
      if (rank == 0) printf("%s: done\n", label);
    }
    /* the particles move: every rank moves the same cloud, the plan is rebuilt */
    for (int i = 0; i < c.n; ++i)
      for (int d = 0; d < dim; ++d)
        c.x[i * dim + d] += 0.02 * sin(3.0 * c.x[i * dim + (d + 1) % dim] + d);
    rows_t moved;
    CHECK(mfree_particles_setup(ps) == MFREE_SUCCESS, "moved reference setup");
    compute_rows(ctx, ps, c.id, c.n, &kMethods[1], &moved);
    decompose(&c, DECOMP_SLAB, MPI_COMM_WORLD, part);
    char label[64];
    snprintf(label, sizeof label, "%dD moved, slab on %d ranks", dim, size);
    run(ctx, halo, &c, part, &moved, &kMethods[1], 1, 1, NULL, label);
    free_rows(&moved);
    for (int m = 0; m < NMETHODS; ++m) free_rows(&ref[m]);
    free_pairs(&pref);
    free(part);
    mfree_particles_destroy(&ps);
    cloud_free(&c);
    mfree_halo_destroy(&halo);
  }
  mfree_context_destroy(&ctx);
  const int rc = mpitest_finish("t160-mpi-gradients");
  MPI_Finalize();
  return rc;
}
