/* One case of scripts/bench-ab.sh, compiled against one library's header and linked to it;
 * the driver (driver.c) loads the copies built against two libraries into one process.
 * Cases (the workloads of bench/, 10^5 particles; each call of ab_iter is one timed
 * iteration, returning its seconds by bench_now, so MFREE_BENCH_CLOCK=cpu applies):
 *   pairs DIM METHOD THREADS              bench_pairs' step: set_pairs, particle setup,
 *                                         approximant setup, pair gradients (i and j)
 *   shape DIM METHOD ORDER setup|update THREADS GRADONLY
 *                                         bench_shape's approximant setup or update, value
 *                                         and gradient tables (GRADONLY 0) or gradient only (1)
 *   apply DIM NCOMP THREADS               bench_apply's gradient of an NCOMP-vector (MLS 1)
 *   neighbors DIM first|repeat THREADS    bench_neighbors' setup of a new set (first: created
 *                                         and destroyed each time) or a repeated setup
 * METHOD: SPH, RL, KB1, MLS, SSPH (ORDER 0 for the methods without one). The context opts
 * in to the page hints as every bench/ program does (bench_page_hints). */
#include "bench_util.h"

#include <mfree.h>

#define CK(call)                                                                         \
  do {                                                                                   \
    const mfree_status_t s_ = (call);                                                    \
    if (s_ != MFREE_SUCCESS) {                                                           \
      char m_[512];                                                                      \
      mfree_context_get_last_error(ctx, NULL, m_, sizeof m_);                            \
      fprintf(stderr, "bench-ab: %s:%d: %s: %s\n", __FILE__, __LINE__, #call, m_);      \
      exit(1);                                                                           \
    }                                                                                    \
  } while (0)

static mfree_context_t *ctx;
static mfree_particles_t *ps;
static mfree_approximant_t *ap;
static int kind, dim, n, update, ncomp;
static int64_t npairs;
static int32_t *pi, *pj;
static double *x, *h, *mass, *rho, *gi, *gj, *u, *out, hconst;
static double parts[3];

static void usage(void) {
  fprintf(stderr,
          "bench-ab: a case is one of\n"
          "  pairs DIM METHOD THREADS\n"
          "  shape DIM METHOD ORDER setup|update THREADS GRADONLY\n"
          "  apply DIM NCOMP THREADS\n"
          "  neighbors DIM first|repeat THREADS\n");
  exit(2);
}

static mfree_method_t method_of(const char *s) {
  if (!strcmp(s, "SPH")) return MFREE_METHOD_SPH;
  if (!strcmp(s, "RL")) return MFREE_METHOD_RANDLES_LIBERSKY;
  if (!strcmp(s, "KB1")) return MFREE_METHOD_KB_METHOD1;
  if (!strcmp(s, "MLS")) return MFREE_METHOD_MLS;
  if (!strcmp(s, "SSPH")) return MFREE_METHOD_SSPH;
  fprintf(stderr, "bench-ab: unknown method %s (SPH, RL, KB1, MLS, SSPH)\n", s);
  exit(2);
}

/* bench_pairs' particles and pair list (bench_util.h) */
static void init_pairs(mfree_method_t method, int threads) {
  h = malloc(sizeof(double) * n);
  mass = malloc(sizeof(double) * n);
  rho = malloc(sizeof(double) * n);
  bench_pair_supports(n, bench_radius(dim) / 2.0, h);
  for (int i = 0; i < n; ++i) {
    rho[i] = 1000.0;
    mass[i] = 1000.0;
  }
  npairs = bench_half_pairs(ctx, dim, n, x, h, &pi, &pj);
  if (npairs < 0) exit(1);
  gi = malloc(sizeof(double) * dim * npairs);
  gj = malloc(sizeof(double) * dim * npairs);
  CK(mfree_context_set_num_threads(ctx, threads));
  CK(bench_pair_set(ctx, dim, n, x, h, mass, rho, method, &ps, &ap));
}

/* bench_shape's and bench_apply's particles (one support, unit volumes) and approximant */
static void init_tables(mfree_method_t method, int order, int flags, int threads) {
  const double vol = 1.0;
  CK(mfree_particles_create(ctx, dim, n, &ps));
  CK(mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, dim, MFREE_BORROW));
  CK(mfree_particles_set_support(ps, &hconst, 0, MFREE_COPY));
  CK(mfree_particles_set_volumes(ps, &vol, 0, MFREE_COPY));
  CK(mfree_particles_setup(ps));
  CK(mfree_approximant_create(ctx, ps, method, &ap));
  if (order) CK(mfree_approximant_set_order(ap, order));
  CK(mfree_approximant_set_derivatives(ap, flags));
  CK(mfree_approximant_setup(ap));
  CK(mfree_context_set_num_threads(ctx, threads));
}

int ab_init(int argc, char **argv) {
  if (argc < 2) usage();
  CK(mfree_context_create(&ctx));
  bench_page_hints(ctx);
  const char *k = argv[0];
  dim = atoi(argv[1]);
  if (dim != 2 && dim != 3) usage();
  x = bench_lattice(dim, bench_side(dim, 1e5), 0.3, &n);
  hconst = 0.5 * bench_radius(dim);
  if (!strcmp(k, "pairs") && argc == 4) {
    kind = 0;
    init_pairs(method_of(argv[2]), atoi(argv[3]));
  } else if (!strcmp(k, "shape") && argc == 7) {
    kind = 1;
    update = !strcmp(argv[4], "update");
    const int flags = atoi(argv[6]) ? MFREE_DERIV_GRADIENT : (MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT);
    init_tables(method_of(argv[2]), atoi(argv[3]), flags, atoi(argv[5]));
  } else if (!strcmp(k, "apply") && argc == 4) {
    kind = 2;
    ncomp = atoi(argv[2]);
    if (ncomp < 1) usage();
    init_tables(MFREE_METHOD_MLS, 1, MFREE_DERIV_GRADIENT, atoi(argv[3]));
    u = malloc(sizeof(double) * n * ncomp);
    out = malloc(sizeof(double) * n * ncomp * dim);
    for (int i = 0; i < n * ncomp; ++i) u[i] = sin(0.01 * i);
  } else if (!strcmp(k, "neighbors") && argc == 4) {
    kind = 3;
    update = !strcmp(argv[2], "repeat");
    CK(mfree_context_set_num_threads(ctx, atoi(argv[3])));
  } else {
    usage();
  }
  return 0;
}

static void new_set(void) {
  if (ps) mfree_particles_destroy(&ps);
  CK(mfree_particles_create(ctx, dim, n, &ps));
  CK(mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, dim, MFREE_BORROW));
  CK(mfree_particles_set_support(ps, &hconst, 0, MFREE_COPY));
}

double ab_iter(void) {
  double t0 = 0, t1 = 0;
  if (kind == 0) {
    t0 = bench_now();
    CK(mfree_particles_set_pairs(ps, npairs, pi, pj, 0, MFREE_BORROW));
    CK(mfree_particles_setup(ps));
    const double ta = bench_now();
    CK(mfree_approximant_setup(ap));
    const double tb = bench_now();
    CK(mfree_approximant_get_pair_gradients(ap, gi, gj, dim, dim * npairs));
    t1 = bench_now();
    parts[0] = ta - t0;
    parts[1] = tb - ta;
    parts[2] = t1 - tb;
  } else if (kind == 1) {
    t0 = bench_now();
    if (update) CK(mfree_approximant_update(ap));
    else CK(mfree_approximant_setup(ap));
    t1 = bench_now();
  } else if (kind == 2) {
    t0 = bench_now();
    CK(mfree_approximant_apply(ap, MFREE_OP_GRADIENT, ncomp, u, MFREE_LAYOUT_AOS, ncomp, out,
                               MFREE_LAYOUT_AOS, (int64_t)ncomp * dim));
    t1 = bench_now();
  } else {
    if (!update || !ps) {
      new_set();
      if (update) CK(mfree_particles_setup(ps));  /* a repeated setup's first, untimed */
    }
    t0 = bench_now();
    CK(mfree_particles_setup(ps));
    t1 = bench_now();
  }
  return t1 - t0;
}

/* The pairs case's parts of the last iteration: rows, tables, pair gradients. */
const double *ab_parts(void) { return parts; }
