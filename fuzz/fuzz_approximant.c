/* libFuzzer harness: bytes -> a particle set (dimension, count, positions with
 * NaN/Inf/duplicates, supports and volumes with zero/negative/NaN values, ghosts,
 * search convention, periodic box, host neighbour lists or a half pair list), a method,
 * kernel, order, derivative flags, fallback, optional host points, and a field; then
 * particles setup, approximant setup, update, every apply operator in both layouts and
 * the diagnostics (conditions, orders, neighbour counts, reproduction check, per-pair
 * gradients, correction data).
 *
 * Then a program of changes read from the rest of the bytes: particles update,
 * approximant update, a borrowed position or support changed, a new ghost count with the
 * set set up again, new host points, apply from two threads at once next to failing
 * calls on the same context, CSR export.
 *
 * Oracles besides the sanitizers (fuzz_util.h): no call may return a status outside the
 * documented set; after a negative status the tables are bitwise those of before; every
 * site reported valid holds finite values in every table and in every apply result of a
 * finite field; two threads applying at once get the result of one.
 *
 * Built with clang -fsanitize=fuzzer,address,undefined when MFREE_FUZZ=ON (preset
 * "fuzz"); in every other build the same function is linked with replay.c, which runs
 * the seed corpus and the regression inputs as a plain test. */
#include <pthread.h>

#include "fuzz_util.h"

#define take fz_u8
#define take16 fz_u16
#define coord fz_coord
#define positive fz_positive
#define valid_status fz_valid_status
#define CHECK_STATUS FZ_CHECK

enum { MAXN = 48, MAXP = 8, NOPS = 12 };

/* ---- two threads applying one approximant at once, next to failing calls ----------- */

typedef struct {
  const mfree_approximant_t *a;
  const double *u;
  double *out;
  int nsites, wrong;
} job_t;

static void *apply_job(void *arg) {
  job_t *j = arg;
  for (int r = 0; r < 4; ++r) {
    /* a failing call on the shared context (leading dimension 0) */
    j->wrong |= mfree_approximant_apply(j->a, MFREE_OP_VALUE, 1, j->u, MFREE_LAYOUT_AOS, 0, j->out,
                                        MFREE_LAYOUT_AOS, 1) != MFREE_ERR_ARG;
    j->wrong |= mfree_approximant_apply(j->a, MFREE_OP_VALUE, 1, j->u, MFREE_LAYOUT_AOS, 3, j->out,
                                        MFREE_LAYOUT_AOS, 1) != MFREE_SUCCESS;
  }
  return NULL;
}

static void threads(const mfree_approximant_t *a, const double *uu, int nsites) {
  if (nsites <= 0) return;
  double *ref = calloc((size_t)nsites, sizeof *ref);
  job_t job[2];
  pthread_t th[2];
  int started[2] = {0, 0};
  if (mfree_approximant_apply(a, MFREE_OP_VALUE, 1, uu, MFREE_LAYOUT_AOS, 3, ref, MFREE_LAYOUT_AOS, 1) != MFREE_SUCCESS) {
    free(ref);
    return; /* no value table */
  }
  for (int t = 0; t < 2; ++t) {
    job[t].a = a, job[t].u = uu, job[t].nsites = nsites, job[t].wrong = 0;
    job[t].out = calloc((size_t)nsites, sizeof(double));
    started[t] = pthread_create(&th[t], NULL, apply_job, &job[t]) == 0;
  }
  for (int t = 0; t < 2; ++t) {
    if (started[t]) pthread_join(th[t], NULL);
    FZ_TRAP_IF(job[t].wrong);
    /* bitwise the result of one thread (NaN compares by bits too) */
    FZ_TRAP_IF(started[t] && memcmp(job[t].out, ref, sizeof(double) * (size_t)nsites) != 0);
    free(job[t].out);
  }
  free(ref);
}

/* ---- the diagnostics of a set-up approximant ------------------------------------------ */

static void diagnostics(fz_bytes_t *b, const mfree_approximant_t *a, int dim, int nsites) {
  const size_t ns = (size_t)nsites + 1;
  double *cond = calloc(ns, sizeof *cond);
  int32_t *ord = calloc(ns, sizeof *ord), *cnt = calloc(ns, sizeof *cnt);
  CHECK_STATUS(mfree_approximant_get_condition(a, cond));
  CHECK_STATUS(mfree_approximant_get_site_order(a, ord));
  CHECK_STATUS(mfree_approximant_get_neighbor_counts(a, cnt));
  double fe = 0.0, de = 0.0;
  CHECK_STATUS(mfree_approximant_check_reproduction(a, (int32_t)(take(b) % 4) - 1, &fe, &de));
  free(cond), free(ord), free(cnt);
  /* per-pair gradients (a pair list set: one row per pair), with a capacity that may be short */
  int64_t np = 0;
  mfree_particles_t *ps = NULL;
  if (mfree_approximant_get_particles(a, &ps) == MFREE_SUCCESS && ps &&
      mfree_particles_get_num_pairs(ps, &np) == MFREE_SUCCESS && np > 0) {
    const int64_t cap = np * dim - (int64_t)(take(b) % 2);
    double *gi = calloc((size_t)(np * dim), sizeof *gi), *gj = calloc((size_t)(np * dim), sizeof *gj);
    CHECK_STATUS(mfree_approximant_get_pair_gradients(a, gi, gj, dim, cap));
    CHECK_STATUS(mfree_approximant_get_pair_gradients_antisymmetric(a, gi, dim, cap));
    free(gi), free(gj);
  }
  /* correction data: one row of ncoef per particle */
  int32_t ncoef = 0, n = 0;
  if (mfree_approximant_get_correction_size(a, &ncoef) == MFREE_SUCCESS && ncoef > 0 && ps &&
      mfree_particles_get_size(ps, &n, NULL) == MFREE_SUCCESS) {
    const int64_t cap = (int64_t)ncoef * n - (int64_t)(take(b) % 2);
    double *c = calloc((size_t)ncoef * (size_t)n + 1, sizeof *c);
    CHECK_STATUS(mfree_approximant_get_correction(a, c, ncoef, cap));
    free(c);
  }
}

/* ---- a program of changes after the first setup ------------------------------------ */

static void program(fz_bytes_t *b, mfree_context_t *ctx, mfree_particles_t *ps, mfree_approximant_t *a,
                    int dim, int n, int points, double *x, double *h, const double *uu) {
  (void)ctx;
  for (int k = 0; k < NOPS && b->n > 0; ++k) {
    const int op = (int)(take(b) % 8);
    fz_tables_t before, after;
    int32_t owned_before = 0, ng = 0, nn = 0;
    mfree_particles_get_size(ps, &nn, &ng);
    owned_before = nn - ng;
    const int had = fz_tables_get(a, dim, &before);
    mfree_status_t st = MFREE_SUCCESS;
    switch (op) {
      case 0: st = mfree_particles_update(ps); break;
      case 1: st = mfree_approximant_update(a); break;
      case 2: /* a borrowed value changes: moved, NaN, Inf, tiny or zero support */
        if (n > 0) {
          const int i = (int)(take(b) % (unsigned)n);
          const unsigned w = take(b);
          if (w & 1) x[dim * i + (int)((w >> 1) % (unsigned)dim)] = coord(b, x[0]);
          else h[i] = positive(b, 0.1);
        }
        break;
      case 3: { /* a new ghost count and a new setup of the set: update must notice */
        const int32_t g = (int32_t)(take(b) % (unsigned)(n + 1));
        st = mfree_particles_set_num_ghost(ps, g);
        if (st == MFREE_SUCCESS) st = mfree_particles_setup(ps);
        FZ_TRAP_IF(!valid_status(st));
        if (st >= 0 && g != ng) {
          st = mfree_approximant_update(a);
          /* never a stale result: an update that succeeds has the sites of the set as it is */
          int32_t ns = -1;
          if (st >= 0 && !points) FZ_TRAP_IF(mfree_approximant_get_num_sites(a, &ns) != MFREE_SUCCESS || ns != n - g);
        }
        break;
      }
      case 4: st = mfree_approximant_setup(a); break;
      case 5: threads(a, uu, had ? before.nsites : 0); break;
      case 6: { /* apply_add twice equals apply doubled, on valid sites */
        if (!had || before.nsites == 0) break;
        double *o1 = calloc((size_t)before.nsites, sizeof *o1), *o2 = calloc((size_t)before.nsites, sizeof *o2);
        const mfree_status_t s1 = mfree_approximant_apply(a, MFREE_OP_VALUE, 1, uu, MFREE_LAYOUT_AOS, 3, o1, MFREE_LAYOUT_AOS, 1);
        const mfree_status_t s2 = mfree_approximant_apply_add(a, MFREE_OP_VALUE, 1, uu, MFREE_LAYOUT_AOS, 3, o2, MFREE_LAYOUT_AOS, 1);
        FZ_TRAP_IF(!valid_status(s1) || s1 != s2);
        if (s1 == MFREE_SUCCESS)
          for (int s = 0; s < before.nsites; ++s) FZ_TRAP_IF(memcmp(&o1[s], &o2[s], sizeof(double)) != 0 && !isnan(o1[s]));
        free(o1), free(o2);
        break;
      }
      default: { /* a leading dimension that wraps: refused, nothing changed */
        double o[MAXN + MAXP + 1] = {0}; /* one value per site */
        st = mfree_approximant_apply(a, MFREE_OP_VALUE, 1, uu, MFREE_LAYOUT_AOS, INT64_MAX / (1 + take(b) % 4), o,
                                     MFREE_LAYOUT_AOS, 1);
        FZ_TRAP_IF(n > 1 && st == MFREE_SUCCESS);
      }
    }
    FZ_TRAP_IF(!valid_status(st));
    const int has = fz_tables_get(a, dim, &after);
    if (has) fz_check_sites(&after);
    if (st < 0 && had) {
      FZ_TRAP_IF(!has);
      fz_tables_same(&before, &after);
    }
    (void)owned_before;
    fz_tables_free(&before);
    fz_tables_free(&after);
  }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  fz_bytes_t b = {data, size};
  const int dim = 1 + (int)(take(&b) % 3);
  const int n = (int)(take(&b) % (MAXN + 1));
  const int method = 1 + (int)(take(&b) % 14);       /* 14: unknown */
  const int kernel = 1 + (int)(take(&b) % 16);       /* 16: unknown */
  const int order = (int)(take(&b) % 5) - 1;         /* -1 = keep the default */
  const int flags = 1 + (int)(take(&b) % 7);
  const int opts = (int)take(&b);
  const int conv = 1 + (int)(take(&b) % 3);
  const double kappa = 1.0 + (take(&b) % 8) * 0.25;
  const unsigned scale_byte = take(&b);
  const double scale = 1.0 / (1.0 + (scale_byte % 16));
  const int pairs = (int)(scale_byte & 16); /* a half pair list instead of CSR host lists */

  double x[3 * MAXN], h[MAXN], v[MAXN], u[MAXN], px[3 * MAXP], ph[MAXP];
  int finite_data = 1;
  for (int i = 0; i < dim * n; ++i) {
    x[i] = coord(&b, i >= dim ? x[i - dim] : 0.0);
    finite_data &= isfinite(x[i]) && fabs(x[i]) < 1e10;
  }
  const int one_h = opts & 1;
  for (int i = 0; i < (one_h ? 1 : n); ++i) {
    h[i] = positive(&b, scale);
    finite_data &= isfinite(h[i]) && h[i] > 1e-200;
  }
  for (int i = 0; i < n; ++i) {
    v[i] = positive(&b, scale * scale);
    u[i] = (double)(int)take(&b) - 128.0;
  }
  const int npts = (opts & 2) ? (int)(take(&b) % (MAXP + 1)) : -1;
  for (int i = 0; i < (npts > 0 ? npts : 0); ++i) {
    for (int d = 0; d < dim; ++d) px[dim * i + d] = coord(&b, 0.0);
    ph[i] = positive(&b, scale);
  }
  const int n_ghost = (opts & 4) ? (int)(take(&b) % (n + 1)) : 0;

  mfree_context_t *ctx = NULL;
  if (mfree_context_create(&ctx) != MFREE_SUCCESS) return 0;
  mfree_particles_t *ps = NULL;
  if (mfree_particles_create(ctx, dim, n, &ps) != MFREE_SUCCESS) goto done;
  CHECK_STATUS(mfree_particles_set_num_ghost(ps, n_ghost));
  /* borrowed data skip the setter's checks and reach setup's */
  const mfree_mem_t mem = (opts & 8) ? MFREE_BORROW : MFREE_COPY;
  CHECK_STATUS(mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, dim, mem));
  CHECK_STATUS(mfree_particles_set_support(ps, h, one_h ? 0 : 1, mem));
  CHECK_STATUS(mfree_particles_set_volumes(ps, v, 1, mem));
  CHECK_STATUS(mfree_particles_set_search(ps, (mfree_search_t)conv, kappa));
  if (opts & 16) {
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    const int32_t per[3] = {1, opts & 32 ? 1 : 0, 1};
    CHECK_STATUS(mfree_particles_set_periodic(ps, lo, hi, per));
  }
  if ((opts & 64) && n > 1 && pairs) {
    /* each particle with the next one; the last pair repeated when scale_byte & 32 */
    int32_t pi[MAXN], pj[MAXN];
    int64_t np = 0;
    for (int i = 0; i + 1 < n; ++i, ++np) pi[np] = i, pj[np] = i + 1;
    if (scale_byte & 32) pi[np] = pi[np - 1], pj[np] = pj[np - 1], ++np;
    CHECK_STATUS(mfree_particles_set_pairs(ps, np, pi, pj, 0, MFREE_COPY));
    int64_t got = -1;
    CHECK_STATUS(mfree_particles_get_num_pairs(ps, &got));
  } else if ((opts & 64) && n > 0) {
    /* host lists: each owned particle sees itself and the next two (mod n) */
    int64_t rp[MAXN + 1];
    int32_t cols[3 * MAXN];
    const int owned = n - n_ghost;
    for (int i = 0; i <= owned; ++i) rp[i] = 3 * i;
    for (int i = 0; i < owned; ++i)
      for (int k = 0; k < 3; ++k) cols[3 * i + k] = (i + k) % n;
    CHECK_STATUS(mfree_particles_set_neighbors(ps, rp, cols, 0, MFREE_COPY));
  }
  mfree_status_t st = mfree_particles_setup(ps);
  if (!valid_status(st)) __builtin_trap();

  mfree_approximant_t *a = NULL;
  if (mfree_approximant_create(ctx, ps, (mfree_method_t)method, &a) == MFREE_SUCCESS) {
    CHECK_STATUS(mfree_approximant_set_kernel(a, (mfree_kernel_t)kernel, 0.0));
    if (order >= 0) CHECK_STATUS(mfree_approximant_set_order(a, order));
    CHECK_STATUS(mfree_approximant_set_derivatives(a, flags));
    CHECK_STATUS(mfree_approximant_set_fallback(a, (opts & 128) ? MFREE_FALLBACK_LOWER_ORDER
                                                              : MFREE_FALLBACK_NONE));
    if (npts >= 0)
      CHECK_STATUS(mfree_approximant_set_points(a, npts, px, MFREE_LAYOUT_AOS, dim, ph, 1,
                                                MFREE_COPY));
    st = mfree_approximant_setup(a);
    if (!valid_status(st)) __builtin_trap();
    if (st >= 0) {
      if (n > 0 && (opts & 8)) CHECK_STATUS(mfree_approximant_update(a));
      int32_t nsites = 0;
      if (mfree_approximant_get_num_sites(a, &nsites) != MFREE_SUCCESS) __builtin_trap();
      int32_t *sst = calloc((size_t)nsites + 1, sizeof *sst);
      double *out = calloc(((size_t)nsites + 1) * 6 * 3, sizeof *out);
      double uu[3 * MAXN];
      for (int i = 0; i < n; ++i)
        for (int d = 0; d < 3; ++d) uu[3 * i + d] = u[i] * (d + 1);
      int32_t nfailed = 0;
      if (mfree_approximant_get_site_status(a, sst, &nfailed) != MFREE_SUCCESS) __builtin_trap();
      {
        fz_tables_t t;
        if (fz_tables_get(a, dim, &t)) fz_check_sites(&t);
        fz_tables_free(&t);
      }
      const int nh = dim == 1 ? 1 : dim == 2 ? 3 : 6;
      const struct { mfree_op_t op; int ncomp, ocomp; } ops[5] = {
          {MFREE_OP_VALUE, 2, 2}, {MFREE_OP_GRADIENT, 1, dim}, {MFREE_OP_DIVERGENCE, dim, 1},
          {MFREE_OP_LAPLACIAN, 1, 1}, {MFREE_OP_HESSIAN, 1, nh}};
      for (int k = 0; k < 5; ++k) {
        const int soa = (opts >> k) & 1;
        const mfree_layout_t ol = soa ? MFREE_LAYOUT_SOA : MFREE_LAYOUT_AOS;
        const int64_t old = soa ? (nsites > 0 ? nsites : 1) : ops[k].ocomp;
        st = mfree_approximant_apply(a, ops[k].op, ops[k].ncomp, uu, MFREE_LAYOUT_AOS, 3, out,
                                     ol, old);
        if (!valid_status(st)) __builtin_trap();
        if (st != MFREE_SUCCESS || !finite_data) continue;
        for (int s = 0; s < nsites; ++s) {
          if (sst[s] != 0) continue;
          for (int c = 0; c < ops[k].ocomp; ++c) {
            const double w = soa ? out[(int64_t)c * old + s] : out[(int64_t)s * old + c];
            if (isnan(w)) __builtin_trap(); /* NaN at a site reported valid */
          }
        }
      }
      free(sst);
      free(out);
      diagnostics(&b, a, dim, nsites);
      program(&b, ctx, ps, a, dim, n, npts >= 0, x, h, uu);
    }
    mfree_approximant_destroy(&a);
  }
  mfree_particles_destroy(&ps);
done:
  mfree_context_destroy(&ctx);
  return 0;
}
