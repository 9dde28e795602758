/* Completeness (reproducing conditions) of every mfree method on an irregular 2D cloud,
 * computed, next to the completeness paper 000 states for each method (Belytschko,
 * Krongauz, Dolbow, Gerlach, IJNME 43 (1998) 785-819, Sect. 4) and the consistency
 * statements of paper 001 (Zhang & Batra 2009, Sects. 2-3) for MSPH and SSPH.
 *
 * For each method the function order is the largest k in 0..3 for which every
 * reproducing condition of degree <= k (000 eqs 5-7) holds to 1e-10 at every particle
 * (mfree_approximant_check_reproduction), -1 when even constants fail; the derivative
 * order likewise for the gradient table (000 eqs 8-9, scaled by h). 3 is the largest
 * order the check covers, so "3" means "at least 3".
 *
 * Integrability (000 eq 18: d/dy of the x-derivative function equals d/dx of the
 * y-derivative function) is measured by central differences of the gradient shape
 * functions at host points, for the methods that can be evaluated away from the
 * particles; reported as max |curl| h^2 over all particles and a few interior points.
 *
 * Usage: mfree_completeness [--json] [--per-side M] [--seed S]
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "papers.h"

#define TOL 1e-10       /* reproduction threshold (round-off is ~1e-13 here) */
#define CURL_TOL 1e-6   /* |curl| h^2 below this counts as integrable */
#define MAXORDER 3

typedef struct {
  mfree_method_t method;
  int order;        /* set order (methods with a fixed order: their own) */
  const char *name;
  int paper_fn;     /* paper's function / derivative order (-1 none) */
  int paper_deriv;
  const char *paper_kind;  /* "reproduction" (000) or "consistency" (001: m, m-1) */
  int paper_integrable;    /* 1 yes, 0 no, -1 not stated */
  int particles_only;
} entry_t;

/* Paper 000 Sect. 4 (docs/papers.md, paper 000, derived results 2) and paper 001 Sects. 2-4. */
static const entry_t kEntries[] = {
    {MFREE_METHOD_SPH, 0, "SPH", -1, -1, "reproduction", 1, 0},
    {MFREE_METHOD_SPH_SYMMETRIC, 0, "SPH symmetric", -1, 0, "reproduction", 0, 1},
    {MFREE_METHOD_SHEPARD, 0, "Shepard", 0, 0, "reproduction", 1, 0},
    {MFREE_METHOD_MLS, 1, "MLS", 1, 1, "reproduction", 1, 0},
    {MFREE_METHOD_MLS, 2, "MLS", 2, 2, "reproduction", 1, 0},
    {MFREE_METHOD_RKPM, 1, "RKPM", 1, 1, "reproduction", 1, 0},
    {MFREE_METHOD_RKPM, 2, "RKPM", 2, 2, "reproduction", 1, 0},
    {MFREE_METHOD_JOHNSON_BEISSEL, 1, "Johnson-Beissel", -1, 0, "reproduction", 0, 1},
    {MFREE_METHOD_RANDLES_LIBERSKY, 1, "Randles-Libersky", -1, 1, "reproduction", 0, 1},
    {MFREE_METHOD_KB_METHOD1, 1, "KB Method 1", 0, 1, "reproduction", 0, 0},
    {MFREE_METHOD_KB_METHOD2, 1, "KB Method 2", 1, 1, "reproduction", 0, 0},
    {MFREE_METHOD_KB_METHOD3, 1, "KB Method 3", 1, 1, "reproduction", 0, 0},
    {MFREE_METHOD_MSPH, 1, "MSPH", 1, 0, "consistency", -1, 0},
    {MFREE_METHOD_MSPH, 2, "MSPH", 2, 1, "consistency", -1, 0},
    {MFREE_METHOD_SSPH, 1, "SSPH", 1, 0, "consistency", -1, 0},
    {MFREE_METHOD_SSPH, 2, "SSPH", 2, 1, "consistency", -1, 0},
};
#define NENTRIES ((int)(sizeof kEntries / sizeof kEntries[0]))

typedef struct {
  int fn_order, deriv_order;
  double fn_err[MAXORDER + 1], deriv_err[MAXORDER + 1];
  double curl;  /* max |curl| h^2, or -1 when not measured */
} result_t;

typedef struct {
  int per_side;
  uint64_t seed;
} options_t;

static uint64_t rng_state;
static double rng_uniform(void) { /* xorshift64*, deterministic across platforms */
  rng_state ^= rng_state >> 12;
  rng_state ^= rng_state << 25;
  rng_state ^= rng_state >> 27;
  return (double)((rng_state * 2685821657736338717ull) >> 11) * (1.0 / 9007199254740992.0);
}

#define TRY(what, call)                                     \
  do {                                                      \
    mfree_status_t st_ = (call);                            \
    if (st_ != MFREE_SUCCESS) {                             \
      papers_report(ctx, st_, what);                        \
      rc = 1;                                               \
      goto done;                                            \
    }                                                       \
  } while (0)

/* Central-difference curl of the gradient shape functions at (x0, y0). */
static int measure_curl(mfree_context_t *ctx, mfree_particles_t *ps, const entry_t *e,
                        int n, double x0, double y0, double h, double *curl) {
  int rc = 0;
  const double eps = 1e-5 * h;
  const double pts[8] = {x0 + eps, y0, x0 - eps, y0, x0, y0 + eps, x0, y0 - eps};
  mfree_approximant_t *a = NULL;
  int64_t rowptr[5], nnz = 0;
  int32_t *cols = NULL;
  double *gx = NULL, *gy = NULL, *dense = NULL;
  TRY("approximant_create", mfree_approximant_create(ctx, ps, e->method, &a));
  TRY("set_order", mfree_approximant_set_order(a, e->order));
  TRY("set_derivatives", mfree_approximant_set_derivatives(a, MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT));
  TRY("set_points", mfree_approximant_set_points(a, 4, pts, MFREE_LAYOUT_AOS, 2, &h, 0, MFREE_COPY));
  TRY("setup (points)", mfree_approximant_setup(a));
  TRY("get_nnz", mfree_approximant_get_nnz(a, &nnz));
  cols = malloc(sizeof(int32_t) * (size_t)(nnz + 1));
  gx = malloc(sizeof(double) * (size_t)(nnz + 1));
  gy = malloc(sizeof(double) * (size_t)(nnz + 1));
  dense = calloc((size_t)4 * 2 * (size_t)n, sizeof(double)); /* point, direction, particle */
  if (!cols || !gx || !gy || !dense) {
    fprintf(stderr, "error: out of memory\n");
    rc = 1;
    goto done;
  }
  TRY("assemble_csr", mfree_approximant_assemble_csr(a, MFREE_DERIV_GRADIENT, 0, rowptr, cols, gx));
  TRY("assemble_csr", mfree_approximant_assemble_csr(a, MFREE_DERIV_GRADIENT, 1, rowptr, cols, gy));
  for (int p = 0; p < 4; ++p)
    for (int64_t k = rowptr[p]; k < rowptr[p + 1]; ++k) {
      dense[(size_t)(p * 2 + 0) * n + cols[k]] = gx[k];
      dense[(size_t)(p * 2 + 1) * n + cols[k]] = gy[k];
    }
  *curl = 0.0;
  for (int j = 0; j < n; ++j) {
    const double dgy_dx = (dense[(size_t)(0 * 2 + 1) * n + j] - dense[(size_t)(1 * 2 + 1) * n + j]) / (2 * eps);
    const double dgx_dy = (dense[(size_t)(2 * 2 + 0) * n + j] - dense[(size_t)(3 * 2 + 0) * n + j]) / (2 * eps);
    const double c = fabs(dgy_dx - dgx_dy) * h * h;
    if (c > *curl) *curl = c;
  }
done:
  mfree_approximant_destroy(&a);
  free(cols);
  free(gx);
  free(gy);
  free(dense);
  return rc;
}

static int run(mfree_context_t *ctx, const options_t *opt, result_t *res) {
  int rc = 0;
  const int m = opt->per_side, n = m * m;
  const double dx = 1.0 / m, h = 1.8 * dx, vol = dx * dx;
  mfree_particles_t *ps = NULL;
  mfree_approximant_t *a = NULL;
  double *x = malloc(sizeof(double) * 2 * (size_t)n);
  if (!x) {
    fprintf(stderr, "error: out of memory\n");
    return 1;
  }
  /* jittered lattice: cell centres moved by up to +-0.3 dx in each direction */
  rng_state = opt->seed * 2654435761u + 88172645463325252ull;
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < m; ++i) {
      x[2 * (j * m + i) + 0] = (i + 0.5 + 0.6 * (rng_uniform() - 0.5)) * dx;
      x[2 * (j * m + i) + 1] = (j + 0.5 + 0.6 * (rng_uniform() - 0.5)) * dx;
    }
  TRY("particles_create", mfree_particles_create(ctx, 2, n, &ps));
  TRY("set_positions", mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 2, MFREE_COPY));
  TRY("set_volumes", mfree_particles_set_volumes(ps, &vol, 0, MFREE_COPY));
  TRY("set_support", mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  TRY("set_search", mfree_particles_set_search(ps, MFREE_SEARCH_GATHER, 2.0));
  for (int k = 0; k < NENTRIES; ++k) {
    const entry_t *e = &kEntries[k];
    result_t *r = &res[k];
    TRY("approximant_create", mfree_approximant_create(ctx, ps, e->method, &a));
    TRY("set_order", mfree_approximant_set_order(a, e->order));
    TRY("set_derivatives", mfree_approximant_set_derivatives(a, MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT));
    TRY(e->name, mfree_approximant_setup(a));
    r->fn_order = r->deriv_order = -1;
    int fn_ok = 1, deriv_ok = 1;
    for (int o = 0; o <= MAXORDER; ++o) {
      TRY("check_reproduction",
          mfree_approximant_check_reproduction(a, o, &r->fn_err[o], &r->deriv_err[o]));
      fn_ok = fn_ok && r->fn_err[o] < TOL;
      deriv_ok = deriv_ok && r->deriv_err[o] < TOL;
      if (fn_ok) r->fn_order = o;
      if (deriv_ok) r->deriv_order = o;
    }
    mfree_approximant_destroy(&a);
    r->curl = -1.0;
    if (!e->particles_only) {
      /* a few interior points away from the particles */
      static const double probe[3][2] = {{0.503, 0.497}, {0.371, 0.612}, {0.655, 0.288}};
      r->curl = 0.0;
      for (int p = 0; p < 3; ++p) {
        double c = 0.0;
        if (measure_curl(ctx, ps, e, n, probe[p][0], probe[p][1], h, &c)) {
          rc = 1;
          goto done;
        }
        if (c > r->curl) r->curl = c;
      }
    }
  }
done:
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
  free(x);
  return rc;
}

static double violation(const double *err, int order) {
  return err[order < 0 ? 0 : order];
}

static void print_json(const options_t *opt, const result_t *res) {
  printf("{\"cloud\":{\"dim\":2,\"per_side\":%d,\"seed\":%llu,\"jitter\":0.3,\"h_over_dx\":1.8,"
         "\"kernel\":\"cubic spline\"},\"tolerance\":%.1e,\"methods\":[",
         opt->per_side, (unsigned long long)opt->seed, TOL);
  for (int k = 0; k < NENTRIES; ++k) {
    const entry_t *e = &kEntries[k];
    const result_t *r = &res[k];
    printf("%s{\"method\":\"%s\",\"order\":%d,\"dim\":2,\"fn_order\":%d,\"deriv_order\":%d,"
           "\"fn_max_violation\":%.3e,\"deriv_max_violation\":%.3e,",
           k ? "," : "", e->name, e->order, r->fn_order, r->deriv_order,
           violation(r->fn_err, r->fn_order), violation(r->deriv_err, r->deriv_order));
    printf("\"fn_violation\":[%.3e,%.3e,%.3e,%.3e],\"deriv_violation\":[%.3e,%.3e,%.3e,%.3e],",
           r->fn_err[0], r->fn_err[1], r->fn_err[2], r->fn_err[3], r->deriv_err[0],
           r->deriv_err[1], r->deriv_err[2], r->deriv_err[3]);
    printf("\"paper_fn_order\":%d,\"paper_deriv_order\":%d,\"paper_kind\":\"%s\",",
           e->paper_fn, e->paper_deriv, e->paper_kind);
    if (r->curl >= 0.0)
      printf("\"curl\":%.3e,\"integrable\":%s,", r->curl, r->curl < CURL_TOL ? "true" : "false");
    else
      printf("\"curl\":null,\"integrable\":null,");
    printf("\"paper_integrable\":%s}",
           e->paper_integrable < 0 ? "null" : (e->paper_integrable ? "true" : "false"));
  }
  printf("]}\n");
}

static void order_text(int o, char *buf) {
  if (o < 0) strcpy(buf, "none");
  else if (o >= MAXORDER) snprintf(buf, 16, ">=%d", MAXORDER);
  else snprintf(buf, 16, "%d", o);
}

static void print_table(const options_t *opt, const result_t *res) {
  printf("Completeness on an irregular 2D cloud: %d x %d jittered lattice (+-0.3 dx, seed %llu),\n"
         "cubic spline, h = 1.8 dx, gather. Order k holds when every reproducing condition\n"
         "of degree <= k is met to %.0e at every particle (paper 000 eqs 5-9).\n\n",
         opt->per_side, opt->per_side, (unsigned long long)opt->seed, TOL);
  printf("%-17s %3s | %-6s %-6s %-9s %-9s | %-13s | %-10s %-10s\n", "method", "set", "fn",
         "deriv", "fn viol", "der viol", "paper fn/der", "|curl|h^2", "integrable");
  printf("%.*s\n", 100, "----------------------------------------------------------------------"
                        "------------------------------");
  int agree = 1;
  for (int k = 0; k < NENTRIES; ++k) {
    const entry_t *e = &kEntries[k];
    const result_t *r = &res[k];
    char fo[16], dor[16], pf[16], pd[16], paper[40], curl[16], integ[24];
    order_text(r->fn_order, fo);
    order_text(r->deriv_order, dor);
    order_text(e->paper_fn, pf);
    order_text(e->paper_deriv, pd);
    snprintf(paper, sizeof paper, "%s/%s%s", pf, pd, e->paper_kind[0] == 'c' ? " (c)" : "");
    if (r->curl >= 0) snprintf(curl, sizeof curl, "%.2e", r->curl);
    else strcpy(curl, "nodes only");
    if (r->curl < 0) strcpy(integ, "-");
    else
      snprintf(integ, sizeof integ, "%s (paper %s)", r->curl < CURL_TOL ? "yes" : "no",
               e->paper_integrable < 0 ? "-" : (e->paper_integrable ? "yes" : "no"));
    /* 000's table states reproduction exactly; 001 states consistency m, m-1, which the
     * exact reproduction of degree m (in values and derivatives) implies. */
    const int ok = e->paper_kind[0] == 'r'
                       ? (r->fn_order == e->paper_fn && r->deriv_order == e->paper_deriv)
                       : (r->fn_order >= e->paper_fn && r->deriv_order >= e->paper_deriv);
    agree = agree && ok;
    printf("%-17s %3d | %-6s %-6s %-9.2e %-9.2e | %-13s | %-10s %s%s\n", e->name, e->order, fo,
           dor, violation(r->fn_err, r->fn_order), violation(r->deriv_err, r->deriv_order),
           paper, curl, integ, ok ? "" : "  <-- differs from the paper");
  }
  printf("\nfn/deriv: orders reached by mfree; viol: largest violation at that order (at order 0\n"
         "when none holds). paper: 000 Sect. 4 (reproduction); (c) = paper 001's consistency\n"
         "orders m, m-1 for MSPH/SSPH, which reproduce degree m exactly in the value and\n"
         "derivative tables at the particles (a stronger property).\n");
  printf("%s\n", agree ? "All orders agree with the papers." : "Some orders differ from the papers.");
}

static int parse_extra(int argc, char **argv, int *i, void *user) {
  options_t *o = user;
  if (strcmp(argv[*i], "--per-side") == 0 && *i + 1 < argc) {
    o->per_side = atoi(argv[++*i]);
    return o->per_side >= 6 && o->per_side <= 200;
  }
  if (strcmp(argv[*i], "--seed") == 0 && *i + 1 < argc) {
    o->seed = strtoull(argv[++*i], NULL, 10);
    return 1;
  }
  return 0;
}

int main(int argc, char **argv) {
  static const char usage[] =
      "usage: mfree_completeness [--json] [--per-side M (6..200, default 12)] [--seed S]\n"
      "Reproduction order of every mfree method on an irregular 2D cloud, vs paper 000 Sect. 4.\n";
  options_t opt = {12, 7};
  int json = 0;
  if (papers_parse(argc, argv, usage, &json, parse_extra, &opt)) return 2;
  mfree_context_t *ctx = NULL;
  if (mfree_context_create(&ctx) != MFREE_SUCCESS) {
    fprintf(stderr, "error: cannot create an mfree context\n");
    return 1;
  }
  result_t res[NENTRIES];
  const int rc = run(ctx, &opt, res);
  if (rc == 0) {
    if (json) print_json(&opt, res);
    else print_table(&opt, res);
  }
  mfree_context_destroy(&ctx);
  return rc;
}
