/* libFuzzer harness (issue 9): bytes -> a particle set (dimension, count, positions with
 * NaN/Inf/duplicates, supports and volumes with zero/negative/NaN values, ghosts,
 * search convention, periodic box, host neighbour lists), a method, kernel, order,
 * derivative flags, fallback, optional host points, and a field; then particles setup,
 * approximant setup, update and every apply operator in both layouts.
 *
 * Oracles besides the sanitizers: no call may return a status outside the documented
 * set, and when setup succeeded on finite data, apply of a finite field must give finite
 * values at every site whose status is 0 (mfree never reports NaN as valid).
 *
 * Built with clang -fsanitize=fuzzer,address,undefined when MFREE_FUZZ=ON (preset
 * "fuzz"); in every other build the same function is linked with replay.c, which runs
 * the seed corpus and the regression inputs as a plain test. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <mfree.h>

typedef struct {
  const uint8_t *p;
  size_t n;
} bytes_t;

static unsigned take(bytes_t *b) {
  if (b->n == 0) return 0;
  b->n--;
  return *b->p++;
}

static unsigned take16(bytes_t *b) { return take(b) | (take(b) << 8); }

/* A coordinate in [0, 1) with rare special values. */
static double coord(bytes_t *b, double prev) {
  const unsigned v = take16(b);
  switch (v) {
    case 0xFFFF: return NAN;
    case 0xFFFE: return INFINITY;
    case 0xFFFD: return prev; /* coincident with the previous particle */
    case 0xFFFC: return 1e300;
    default: return v / 65536.0;
  }
}

/* A positive quantity around `scale`, sometimes invalid. */
static double positive(bytes_t *b, double scale) {
  const unsigned v = take(b);
  switch (v) {
    case 0: return 0.0;
    case 255: return NAN;
    case 254: return -scale;
    case 253: return 1e-300;
    default: return scale * (0.05 + v / 64.0);
  }
}

/* The documented statuses: success, misuse -1..-7, data-dependent failures 1..7.
 * MFREE_ERR_INTERNAL (-99) is a bug in mfree. */
static int valid_status(mfree_status_t st) { return st >= -7 && st <= 7; }

#define CHECK_STATUS(call)                                    \
  do {                                                        \
    mfree_status_t st_ = (call);                              \
    if (!valid_status(st_)) __builtin_trap();                 \
  } while (0)

enum { MAXN = 48, MAXP = 8 };

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  bytes_t b = {data, size};
  const int dim = 1 + (int)(take(&b) % 3);
  const int n = (int)(take(&b) % (MAXN + 1));
  const int method = 1 + (int)(take(&b) % 14);       /* 14: unknown */
  const int kernel = 1 + (int)(take(&b) % 16);       /* 16: unknown */
  const int order = (int)(take(&b) % 5) - 1;         /* -1 = keep the default */
  const int flags = 1 + (int)(take(&b) % 7);
  const int opts = (int)take(&b);
  const int conv = 1 + (int)(take(&b) % 3);
  const double kappa = 1.0 + (take(&b) % 8) * 0.25;
  const double scale = 1.0 / (1.0 + (take(&b) % 16));

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
  if ((opts & 64) && n > 0) {
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
    }
    mfree_approximant_destroy(&a);
  }
  mfree_particles_destroy(&ps);
done:
  mfree_context_destroy(&ctx);
  return 0;
}
