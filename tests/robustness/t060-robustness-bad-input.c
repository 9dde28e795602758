/* Bad-input matrix of the core C ABI: every public function of mfree.h
 * against every class of bad argument that applies to it -- NULL handle, NULL array or
 * output, wrong dimension, negative or too small count / leading dimension / stride,
 * NaN or Inf in an array, zero or negative volume or support, unknown enumerator, wrong
 * object state, mismatched objects. For each row:
 *  - the documented status (mfree.h: negative = misuse, nothing changed);
 *  - when a handle carries a context, that context holds the same code and a fresh,
 *    non-empty message;
 *  - every object of the fixture is still usable and unchanged: the same sizes, and
 *    bitwise the same apply / matrix-vector / right-hand-side results as before;
 *  - every site an approximant of the fixture reports valid holds finite values (the
 *    rule of mfree.h: negative status, nothing changed; positive, valid sites finite);
 *  - nothing was written to stdout or stderr (both are redirected to a file while the
 *    rows run, and the file must stay empty).
 * A last check reads mfree.h and fails when a public function has no row here, so that
 * a new function comes with its bad-input rows. */
#define _POSIX_C_SOURCE 200809L /* dup, dup2, fileno */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "testutil.h"

#ifndef MFREE_PUBLIC_HEADER
#error "MFREE_PUBLIC_HEADER (path of include/mfree.h) must be defined by the build"
#endif

enum { M = 6, N = M * M, NE = (M - 1) * (M - 1), MAXLOG = 1 << 16, MAXFN = 512 };
static const double SP = 0.2;            /* lattice spacing */
static const char SENTINEL[] = "(sentinel: no message recorded)";

typedef struct {
  mfree_context_t *ctx;
  mfree_particles_t *ps;     /* 2D lattice, set up */
  mfree_particles_t *fresh;  /* data set, never set up */
  mfree_particles_t *ps3;    /* a 3D set (mismatched dimension) */
  mfree_context_t *ctx2;     /* another context, which must stay clean */
  mfree_approximant_t *a;    /* MLS order 1, values + gradients + Hessians, set up */
  mfree_approximant_t *a_new;/* MLS on ps, not set up */
  mfree_approximant_t *a3;   /* MLS on ps3, set up */
  mfree_particles_t *psm;    /* the lattice with supports of half a spacing, for MPFEM */
#if MFREE_T060_MESH
  mfree_mesh_t *mesh;        /* quad4 mesh over psm, set up */
#endif
  mfree_approximant_t *am;   /* MPFEM on mesh (else a second MLS), set up */
  mfree_matrix_t *A;         /* 3 x 3 */
  mfree_assembler_t *as;     /* Laplace, Galerkin, nodal quadrature, set up */
  mfree_assembler_t *as_new; /* not set up */
  mfree_system_t *sys;       /* fluid 2D, N particles */
  double x[2 * N], y[5 * N], m[N], u[N], h;
  /* reference results */
  double ref_grad[2 * N], ref_mp[N], ref_Ax[3], ref_rhs[N], ref_ydot[5 * N], ref_vol[N];
  int64_t ref_nnz;
  /* report */
  int rows, failures;
  char log[MAXLOG];
  const char *covered[MAXFN];
  int ncovered;
} fx_t;

static fx_t F;

static void logf_(const char *fmt, const char *a, const char *b, int c, int d) {
  size_t used = strlen(F.log);
  if (used + 512 < sizeof F.log) snprintf(F.log + used, sizeof F.log - used, fmt, a, b, c, d);
  F.failures++;
}

static void cover(const char *call) {
  static char names[MAXFN][96];
  char name[96];
  size_t k = 0;
  while (call[k] && call[k] != '(' && k + 1 < sizeof name) name[k] = call[k], ++k;
  name[k] = '\0';
  for (int i = 0; i < F.ncovered; ++i)
    if (strcmp(F.covered[i], name) == 0) return;
  if (F.ncovered < MAXFN) {
    strcpy(names[F.ncovered], name);
    F.covered[F.ncovered] = names[F.ncovered];
    F.ncovered++;
  }
}

static double field(double x, double y) { return 1.0 + 2.0 * x - 3.0 * y + x * y; }

/* --- the fixture ---------------------------------------------------------------- */

static mfree_status_t make_fixture(void) {
  mfree_status_t st = MFREE_SUCCESS;
#define TRY(call) do { if ((st = (call)) != MFREE_SUCCESS) return st; } while (0)
  TRY(mfree_context_create(&F.ctx));
  TRY(mfree_context_create(&F.ctx2));
  F.h = 1.5 * SP;
  const double vol = SP * SP;
  for (int j = 0; j < M; ++j)
    for (int i = 0; i < M; ++i) {
      const int p = j * M + i;
      F.x[2 * p] = i * SP;
      F.x[2 * p + 1] = j * SP;
      F.u[p] = field(F.x[2 * p], F.x[2 * p + 1]);
    }
  TRY(mfree_particles_create(F.ctx, 2, N, &F.ps));
  TRY(mfree_particles_set_positions(F.ps, F.x, MFREE_LAYOUT_AOS, 2, MFREE_COPY));
  TRY(mfree_particles_set_volumes(F.ps, &vol, 0, MFREE_COPY));
  TRY(mfree_particles_set_support(F.ps, &F.h, 0, MFREE_COPY));
  TRY(mfree_particles_setup(F.ps));
  TRY(mfree_particles_create(F.ctx, 2, N, &F.fresh));
  TRY(mfree_particles_set_positions(F.fresh, F.x, MFREE_LAYOUT_AOS, 2, MFREE_COPY));
  TRY(mfree_particles_set_volumes(F.fresh, &vol, 0, MFREE_COPY));
  TRY(mfree_particles_set_support(F.fresh, &F.h, 0, MFREE_COPY));

  static double x3[3 * 27];
  for (int p = 0; p < 27; ++p) {
    x3[3 * p] = (p % 3) * SP;
    x3[3 * p + 1] = (p / 3 % 3) * SP;
    x3[3 * p + 2] = (p / 9) * SP;
  }
  const double vol3 = SP * SP * SP;
  TRY(mfree_particles_create(F.ctx, 3, 27, &F.ps3));
  TRY(mfree_particles_set_positions(F.ps3, x3, MFREE_LAYOUT_AOS, 3, MFREE_COPY));
  TRY(mfree_particles_set_volumes(F.ps3, &vol3, 0, MFREE_COPY));
  TRY(mfree_particles_set_support(F.ps3, &F.h, 0, MFREE_COPY));
  TRY(mfree_approximant_create(F.ctx, F.ps3, MFREE_METHOD_MLS, &F.a3));
  TRY(mfree_approximant_setup(F.a3));

  TRY(mfree_approximant_create(F.ctx, F.ps, MFREE_METHOD_MLS, &F.a));
  TRY(mfree_approximant_set_derivatives(F.a, MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT |
                                                 MFREE_DERIV_HESSIAN));
  TRY(mfree_approximant_setup(F.a));
  TRY(mfree_approximant_create(F.ctx, F.ps, MFREE_METHOD_MLS, &F.a_new));

#if MFREE_T060_MESH
  static int32_t conn[4 * NE];
  for (int j = 0; j + 1 < M; ++j)
    for (int i = 0; i + 1 < M; ++i) {
      int32_t *c = conn + 4 * (j * (M - 1) + i);
      c[0] = j * M + i, c[1] = j * M + i + 1, c[2] = (j + 1) * M + i + 1, c[3] = (j + 1) * M + i;
    }
  const double hm = 0.5 * SP;
  TRY(mfree_particles_create(F.ctx, 2, N, &F.psm));
  TRY(mfree_particles_set_positions(F.psm, F.x, MFREE_LAYOUT_AOS, 2, MFREE_COPY));
  TRY(mfree_particles_set_volumes(F.psm, &vol, 0, MFREE_COPY));
  TRY(mfree_particles_set_support(F.psm, &hm, 0, MFREE_COPY));
  TRY(mfree_mesh_create(F.ctx, F.psm, &F.mesh));
  TRY(mfree_mesh_add_elements(F.mesh, MFREE_ELEMENT_QUAD4, NE, conn, 0, MFREE_COPY));
  TRY(mfree_mesh_setup(F.mesh));
  TRY(mfree_approximant_create(F.ctx, F.psm, MFREE_METHOD_MPFEM, &F.am));
  TRY(mfree_approximant_set_mesh(F.am, F.mesh));
#else
  const double hm = 0.5 * SP;
  TRY(mfree_particles_create(F.ctx, 2, N, &F.psm));
  TRY(mfree_particles_set_positions(F.psm, F.x, MFREE_LAYOUT_AOS, 2, MFREE_COPY));
  TRY(mfree_particles_set_volumes(F.psm, &vol, 0, MFREE_COPY));
  TRY(mfree_particles_set_support(F.psm, &hm, 0, MFREE_COPY));
  TRY(mfree_approximant_create(F.ctx, F.ps, MFREE_METHOD_MLS, &F.am));
  TRY(mfree_approximant_set_derivatives(F.am, MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT));
#endif
  TRY(mfree_approximant_setup(F.am));

  static const int64_t rp[4] = {0, 2, 4, 5};
  static const int32_t ci[5] = {0, 1, 0, 1, 2};
  static const double va[5] = {2.0, -1.0, -1.0, 2.0, 3.0};
  TRY(mfree_matrix_create_csr(F.ctx, 3, 3, rp, ci, va, &F.A));

  TRY(mfree_assembler_create(F.ctx, F.a, NULL, MFREE_FORM_LAPLACE, &F.as));
  TRY(mfree_assembler_setup(F.as));
  TRY(mfree_assembler_create(F.ctx, F.a, NULL, MFREE_FORM_LAPLACE, &F.as_new));

  const double rho0 = 1000.0;
  for (int p = 0; p < N; ++p) {
    F.y[2 * p] = F.x[2 * p];
    F.y[2 * p + 1] = F.x[2 * p + 1];
    F.y[2 * N + 2 * p] = 0.01 * sin(p);
    F.y[2 * N + 2 * p + 1] = 0.01 * cos(p);
    F.y[4 * N + p] = rho0 * (1.0 + 0.001 * sin(3.0 * p));
    F.m[p] = rho0 * vol;
  }
  TRY(mfree_system_create_fluid(F.ctx, 2, N, &F.sys));
  TRY(mfree_system_set_fluid(F.sys, &rho0, 0, 1.0e4, 7.0, 1.0e-3));
  TRY(mfree_system_set_masses(F.sys, F.m, 1));
  TRY(mfree_system_set_smoothing(F.sys, F.h));
#undef TRY
  return MFREE_SUCCESS;
}

/* The positive half of the rule (mfree.h, docs/robustness.md): every site an approximant
 * reports valid holds finite values in every table it built. NULL when it holds. */
static const char *valid_sites_finite(const mfree_approximant_t *a, int dim) {
  int32_t ns = 0, st[4 * N];
  int64_t nnz = 0, rp[4 * N + 1];
  static int32_t cl[16 * N * N];
  static double v[16 * N * N];
  if (mfree_approximant_get_num_sites(a, &ns) || ns > 4 * N) return NULL; /* not set up */
  if (mfree_approximant_get_nnz(a, &nnz) || nnz > 16 * N * N) return "approximant nnz";
  if (mfree_approximant_get_site_status(a, st, NULL)) return "approximant site status";
  const int nh = dim == 2 ? 3 : 6;
  for (int d = 0; d < 3; ++d)
    for (int c = 0; c < (d == 0 ? 1 : d == 1 ? dim : nh); ++c) {
      const mfree_deriv_t deriv = d == 0 ? MFREE_DERIV_VALUE : d == 1 ? MFREE_DERIV_GRADIENT : MFREE_DERIV_HESSIAN;
      if (mfree_approximant_assemble_csr(a, deriv, c, rp, cl, v) != MFREE_SUCCESS) break; /* not built */
      for (int32_t s = 0; s < ns; ++s)
        if (st[s] == 0)
          for (int64_t k = rp[s]; k < rp[s + 1]; ++k)
            if (!isfinite(v[k])) return "a site reported valid holds a non-finite value";
    }
  return NULL;
}

/* Results of every object; reference on the first call (ref != 0), else compared
 * bitwise. Returns a description of the first difference, or NULL. */
static const char *health(int ref) {
  int32_t n = -1, ng = -1, dim = -1, nel = -1, nt = -1;
  int64_t nnz = -1;
  double grad[2 * N], mp[N], Ax[3], rhs[N], ydot[5 * N], vol[N];
  const double xin[3] = {1.0, 2.0, 3.0};
  if (mfree_particles_get_size(F.ps, &n, &ng) || n != N || ng != 0) return "particle count";
  if (mfree_particles_get_dimension(F.ps, &dim) || dim != 2) return "particle dimension";
  if (mfree_particles_get_neighbor_nnz(F.ps, &nnz)) return "neighbour count";
  if (mfree_particles_get_volumes(F.ps, vol)) return "volumes";
  if (mfree_approximant_update(F.a)) return "approximant update";
  if (mfree_approximant_apply(F.a, MFREE_OP_GRADIENT, 1, F.u, MFREE_LAYOUT_AOS, 1, grad,
                              MFREE_LAYOUT_AOS, 2))
    return "approximant apply";
  if (mfree_approximant_apply(F.am, MFREE_OP_VALUE, 1, F.u, MFREE_LAYOUT_AOS, 1, mp,
                              MFREE_LAYOUT_AOS, 1))
    return "MPFEM apply";
#if MFREE_T060_MESH
  if (mfree_mesh_get_size(F.mesh, &nel) || nel != NE) return "mesh size";
#else
  (void)nel;
#endif
  if (mfree_matrix_apply(F.A, xin, Ax)) return "matrix apply";
  if (mfree_assembler_assemble_rhs(F.as, rhs)) return "assembler rhs";
  if (mfree_system_rhs(F.sys, 0.0, F.y, ydot)) return "system rhs";
  if (mfree_context_get_num_threads(F.ctx, &nt) || nt != 1) return "context threads";
  int32_t backend = 0, hints = -1;
  if (mfree_context_get_backend(F.ctx, &backend) || backend != MFREE_BACKEND_OPT)
    return "context backend";
  if (mfree_context_get_page_hints(F.ctx, &hints) || hints != MFREE_PAGES_DEFAULT)
    return "context page hints";
  if (ref) {
    F.ref_nnz = nnz;
    memcpy(F.ref_grad, grad, sizeof grad);
    memcpy(F.ref_mp, mp, sizeof mp);
    memcpy(F.ref_Ax, Ax, sizeof Ax);
    memcpy(F.ref_rhs, rhs, sizeof rhs);
    memcpy(F.ref_ydot, ydot, sizeof ydot);
    memcpy(F.ref_vol, vol, sizeof vol);
    return NULL;
  }
  if (nnz != F.ref_nnz) return "neighbour count changed";
  if (memcmp(vol, F.ref_vol, sizeof vol)) return "volumes changed";
  if (memcmp(grad, F.ref_grad, sizeof grad)) return "approximant gradient changed";
  if (memcmp(mp, F.ref_mp, sizeof mp)) return "MPFEM values changed";
  if (memcmp(Ax, F.ref_Ax, sizeof Ax)) return "matrix product changed";
  if (memcmp(rhs, F.ref_rhs, sizeof rhs)) return "assembled rhs changed";
  if (memcmp(ydot, F.ref_ydot, sizeof ydot)) return "system rhs changed";
  return NULL;
}

/* Arm the context before a row: a fresh message must replace the sentinel. */
static void arm(mfree_context_t *c) {
  if (c) mfree_context_set_error(c, MFREE_ERR_INTERNAL, SENTINEL);
}

static void row(const char *call, mfree_status_t got, mfree_status_t want, mfree_context_t *c) {
  F.rows++;
  cover(call);
  char msg[512] = "";
  mfree_status_t code = MFREE_SUCCESS;
  if (got != want) {
    if (c) mfree_context_get_last_error(c, NULL, msg, sizeof msg);
    logf_("  %s\n    returned %s, expected %d, got %d\n", call, mfree_status_string(got), (int)want,
          (int)got);
    if (msg[0]) logf_("    message: %s%s\n", msg, "", 0, 0), F.failures--; /* same finding */
  } else if (c && want != MFREE_SUCCESS) {
    mfree_context_get_last_error(c, &code, msg, sizeof msg);
    if (code != got) logf_("  %s\n    context code %s, call returned %d (%d)\n", call,
                           mfree_status_string(code), (int)got, 0);
    if (msg[0] == '\0' || strcmp(msg, SENTINEL) == 0)
      logf_("  %s\n    no message recorded on the context%s\n", call, "", 0, 0);
  }
  const char *bad = health(0);
  if (!bad) bad = valid_sites_finite(F.a, 2);
  if (!bad) bad = valid_sites_finite(F.am, 2);
  if (!bad) bad = valid_sites_finite(F.a3, 3);
  if (bad) logf_("  %s\n    afterwards: %s\n", call, bad, 0, 0);
}

/* A row with a context to check (c), or none (NULL: a NULL handle carries no context). */
#define ROWC(c, want, call)                                                              \
  do {                                                                                   \
    arm(c);                                                                              \
    mfree_status_t st_ = (call);                                                         \
    row(#call, st_, (want), (c));                                                        \
  } while (0)
#define ROW(want, call) ROWC(F.ctx, want, call)
#define ROW0(want, call) ROWC(NULL, want, call)

static void host_field(void *user, const double *x, double *v) { (void)user; v[0] = x[0]; }
static double history(void *user, double t) { (void)user; return t; }
static int32_t inside(void *user, const double *x) { (void)user; return x[0] >= 0.0; }
/* the collective callbacks of one rank: no ghosts to fill; the gather copies */
static mfree_status_t one_exchange(void *user, int32_t ncomp, double *field, int64_t ld) {
  (void)user, (void)ncomp, (void)field, (void)ld;
  return MFREE_SUCCESS;
}
static mfree_status_t one_allgather(void *user, const double *in, int64_t n, double *out, int64_t cap,
                                    int64_t *total) {
  (void)user;
  *total = n;
  if (cap >= n && n > 0) memcpy(out, in, sizeof(double) * (size_t)n);
  return MFREE_SUCCESS;
}
/* The halo rebuild and particle move of one rank: nothing moves, no ghosts. */
static mfree_status_t one_rebuild(void *user, int32_t n_owned, const double *x, int64_t ld, const int64_t *ids,
                                  double width, int32_t *n_ghost, const int64_t **all_ids) {
  (void)user, (void)n_owned, (void)x, (void)ld, (void)width;
  *n_ghost = 0;
  *all_ids = ids;
  return MFREE_SUCCESS;
}
static mfree_status_t bad_rebuild(void *user, int32_t n_owned, const double *x, int64_t ld, const int64_t *ids,
                                  double width, int32_t *n_ghost, const int64_t **all_ids) {
  (void)user, (void)n_owned, (void)x, (void)ld, (void)ids, (void)width, (void)n_ghost, (void)all_ids;
  return MFREE_ERR_INTERNAL;
}
static mfree_status_t one_move(void *user, int32_t nrec, int32_t n_owned, double *records, int32_t n_new) {
  (void)user, (void)nrec, (void)records;
  return n_new == n_owned ? MFREE_SUCCESS : MFREE_ERR_ARG;
}
static mfree_status_t bad_move(void *user, int32_t nrec, int32_t n_owned, double *records, int32_t n_new) {
  (void)user, (void)nrec, (void)n_owned, (void)records, (void)n_new;
  return MFREE_ERR_INTERNAL;
}
static void handler(void *user, mfree_status_t code, const char *message) {
  (void)code, (void)message;
  ++*(int *)user;
}
#if MFREE_T060_ALLOCATOR
static void *my_alloc(void *user, int64_t bytes) { (void)user; return malloc((size_t)bytes); }
static void my_free(void *user, void *p, int64_t bytes) { (void)user, (void)bytes; free(p); }
#endif

/* --- the rows ------------------------------------------------------------------ */

/* Pair lists, pair gradients, correction data, and the relations wrappers use. */
static void rows_pairs(void) {
  mfree_context_t *c = NULL;
  mfree_particles_t *pp = NULL;
  int64_t n64 = 0;
  int32_t i32 = 0, d32 = 0;
  int32_t pi[3] = {0, 1, 2}, pj[3] = {1, 2, 3}, self_i[1] = {4}, self_j[1] = {4}, far[1] = {N};
  double g[2 * 8], cor[9 * N];
  ROW0(MFREE_ERR_NULL, mfree_particles_get_context(NULL, &c));
  ROW0(MFREE_ERR_NULL, mfree_particles_get_context(F.ps, NULL));
  ROW0(MFREE_SUCCESS, mfree_particles_get_context(F.ps, &c));
  ROW0(MFREE_ERR_NULL, mfree_approximant_get_context(NULL, &c));
  ROW0(MFREE_ERR_NULL, mfree_approximant_get_context(F.a, NULL));
  ROW0(MFREE_ERR_NULL, mfree_mesh_get_context(NULL, &c));
  ROW0(MFREE_ERR_NULL, mfree_matrix_get_context(NULL, &c));
  ROW0(MFREE_ERR_NULL, mfree_matrix_get_context(F.A, NULL));
  ROW0(MFREE_ERR_NULL, mfree_assembler_get_context(NULL, &c));
  ROW0(MFREE_ERR_NULL, mfree_assembler_get_context(F.as, NULL));
  ROW0(MFREE_ERR_NULL, mfree_system_get_context(NULL, &c));
  ROW0(MFREE_ERR_NULL, mfree_system_get_context(F.sys, NULL));
  ROW0(MFREE_ERR_NULL, mfree_approximant_get_particles(NULL, &pp));
  ROW0(MFREE_ERR_NULL, mfree_approximant_get_particles(F.a, NULL));
  ROW0(MFREE_ERR_NULL, mfree_mesh_get_particles(NULL, &pp));
  ROW0(MFREE_ERR_NULL, mfree_system_get_dimension(NULL, &d32, &i32));
  ROW(MFREE_ERR_NULL, mfree_system_get_dimension(F.sys, NULL, NULL));
  ROW(MFREE_SUCCESS, mfree_system_get_dimension(F.sys, &d32, &i32));
  /* set_pairs on the set-up lattice: every failure leaves it as it was */
  ROW0(MFREE_ERR_NULL, mfree_particles_set_pairs(NULL, 3, pi, pj, 0, MFREE_COPY));
  ROW(MFREE_ERR_ARG, mfree_particles_set_pairs(F.ps, -1, pi, pj, 0, MFREE_COPY));
  ROW(MFREE_ERR_NULL, mfree_particles_set_pairs(F.ps, 3, NULL, pj, 0, MFREE_COPY));
  ROW(MFREE_ERR_NULL, mfree_particles_set_pairs(F.ps, 3, pi, NULL, 0, MFREE_COPY));
  ROW(MFREE_ERR_ARG, mfree_particles_set_pairs(F.ps, 3, pi, pj, 2, MFREE_COPY));
  ROW(MFREE_ERR_ARG, mfree_particles_set_pairs(F.ps, 3, pi, pj, 0, (mfree_mem_t)7));
  ROW(MFREE_ERR_INPUT, mfree_particles_set_pairs(F.ps, 1, far, pj, 0, MFREE_COPY));
  ROW(MFREE_ERR_INPUT, mfree_particles_set_pairs(F.ps, 3, pi, pj, 1, MFREE_COPY)); /* 0, 1-based */
  ROW(MFREE_ERR_INPUT, mfree_particles_set_pairs(F.ps, 1, self_i, self_j, 0, MFREE_BORROW));
  /* global ids and halo width: failures leave the lattice without ids */
  int64_t gid[N], gid_neg[N], gid_dup[N];
  for (int p = 0; p < N; ++p) gid[p] = gid_neg[p] = gid_dup[p] = 10 + p;
  gid_neg[3] = -1;
  gid_dup[5] = gid_dup[4];
  ROW0(MFREE_ERR_NULL, mfree_particles_set_global_ids(NULL, gid, MFREE_COPY));
  ROW(MFREE_ERR_ARG, mfree_particles_set_global_ids(F.ps, gid, (mfree_mem_t)7));
  ROW(MFREE_ERR_INPUT, mfree_particles_set_global_ids(F.ps, gid_neg, MFREE_COPY));
  ROW(MFREE_ERR_INPUT, mfree_particles_set_global_ids(F.ps, gid_dup, MFREE_COPY));
  ROW0(MFREE_ERR_NULL, mfree_particles_get_global_ids(NULL, gid));
  ROW(MFREE_ERR_STATE, mfree_particles_get_global_ids(F.ps, gid));
  ROW0(MFREE_ERR_NULL, mfree_particles_set_halo_width(NULL, 1.0));
  ROW(MFREE_ERR_ARG, mfree_particles_set_halo_width(F.ps, -1.0));
  ROW(MFREE_ERR_ARG, mfree_particles_set_halo_width(F.ps, NAN));
  ROW0(MFREE_ERR_NULL, mfree_particles_set_search_skin(NULL, 0.1));
  ROW(MFREE_ERR_ARG, mfree_particles_set_search_skin(F.ps, -0.1));
  ROW(MFREE_ERR_ARG, mfree_particles_set_search_skin(F.ps, NAN));
  ROW(MFREE_ERR_ARG, mfree_particles_set_search_skin(F.ps, INFINITY));
  ROW0(MFREE_ERR_NULL, mfree_particles_get_search_count(NULL, &n64));
  ROW(MFREE_ERR_NULL, mfree_particles_get_search_count(F.ps, NULL));
  ROW0(MFREE_ERR_NULL, mfree_particles_get_num_pairs(NULL, &n64));
  ROW(MFREE_ERR_NULL, mfree_particles_get_num_pairs(F.ps, NULL));
  ROW(MFREE_ERR_STATE, mfree_particles_get_num_pairs(F.ps, &n64));
  /* pair gradients: no pair list, not set up, NULL */
  ROW0(MFREE_ERR_NULL, mfree_approximant_get_pair_gradients(NULL, g, g, 2, 16));
  ROW(MFREE_ERR_STATE, mfree_approximant_get_pair_gradients(F.a, g, NULL, 2, 16));
  ROW(MFREE_ERR_STATE, mfree_approximant_get_pair_gradients(F.a_new, g, NULL, 2, 16));
  ROW0(MFREE_ERR_NULL, mfree_approximant_get_pair_gradients_antisymmetric(NULL, g, 2, 16));
  ROW(MFREE_ERR_STATE, mfree_approximant_get_pair_gradients_antisymmetric(F.a, g, 2, 16));
  /* correction data of the set-up MLS (9 doubles per particle in 2D) */
  ROW0(MFREE_ERR_NULL, mfree_approximant_get_correction_size(NULL, &i32));
  ROW(MFREE_ERR_NULL, mfree_approximant_get_correction_size(F.a, NULL));
  ROW0(MFREE_ERR_NULL, mfree_approximant_get_correction(NULL, cor, 9, 9 * N));
  ROW(MFREE_ERR_NULL, mfree_approximant_get_correction(F.a, NULL, 9, 9 * N));
  ROW(MFREE_ERR_ARG, mfree_approximant_get_correction(F.a, cor, 8, 9 * N));
  ROW(MFREE_ERR_ARG, mfree_approximant_get_correction(F.a, cor, 9, 9 * N - 1));
  ROW(MFREE_ERR_ARG, mfree_approximant_get_correction(F.a, cor, 9, -1));
  ROW(MFREE_ERR_STATE, mfree_approximant_get_correction(F.a_new, cor, 9, 9 * N));
  ROW(MFREE_SUCCESS, mfree_approximant_get_correction(F.a, cor, 9, 9 * N));
  ROW0(MFREE_ERR_NULL, mfree_approximant_set_ghost_correction(NULL, cor, 9, 9 * N));
  ROW(MFREE_ERR_ARG, mfree_approximant_set_ghost_correction(F.a, cor, 8, 9 * N));
  ROW(MFREE_ERR_ARG, mfree_approximant_set_ghost_correction(F.a, cor, 9, -1));
  ROW(MFREE_ERR_STATE, mfree_approximant_set_ghost_correction(F.a_new, cor, 9, 9 * N));
  ROW(MFREE_SUCCESS, mfree_approximant_set_ghost_correction(F.a, cor, 9, 9 * N));
  /* a pair-list set of its own, for the buffer checks of the pair gradients */
  mfree_particles_t *ps = NULL;
  mfree_approximant_t *ap = NULL, *sph = NULL;
  if (mfree_particles_create(F.ctx, 2, N, &ps) == MFREE_SUCCESS &&
      mfree_particles_set_positions(ps, F.x, MFREE_LAYOUT_AOS, 2, MFREE_BORROW) == MFREE_SUCCESS &&
      mfree_particles_set_support(ps, &F.h, 0, MFREE_COPY) == MFREE_SUCCESS &&
      mfree_particles_set_pairs(ps, 3, pi, pj, 0, MFREE_COPY) == MFREE_SUCCESS &&
      mfree_approximant_create(F.ctx, ps, MFREE_METHOD_SPH, &sph) == MFREE_SUCCESS &&
      mfree_approximant_create(F.ctx, ps, MFREE_METHOD_SHEPARD, &ap) == MFREE_SUCCESS &&
      mfree_particles_setup(ps) >= MFREE_SUCCESS && mfree_approximant_setup(ap) >= MFREE_SUCCESS) {
    ROW(MFREE_ERR_ARG, mfree_approximant_get_pair_gradients(ap, g, g + 8, 2, 5));
    ROW(MFREE_ERR_ARG, mfree_approximant_get_pair_gradients(ap, g, NULL, 1, 16));
    ROW(MFREE_ERR_ARG, mfree_approximant_get_pair_gradients(ap, g, NULL, 2, -3));
    ROW(MFREE_ERR_NULL, mfree_approximant_get_pair_gradients(ap, NULL, NULL, 2, 16));
    ROW(MFREE_ERR_ARG, mfree_approximant_get_pair_gradients_antisymmetric(ap, g, 2, 5));
    ROW(MFREE_SUCCESS, mfree_approximant_get_pair_gradients(ap, g, g + 8, 2, 6));
    ROW(MFREE_ERR_UNSUPPORTED, mfree_approximant_get_correction_size(sph, &i32));
  } else {
    logf_("  rows_pairs: could not build the pair-list set%s\n", "", 0, 0, 0);
  }
  mfree_approximant_destroy(&sph);
  mfree_approximant_destroy(&ap);
  mfree_particles_destroy(&ps);
}


static void rows_version_context(void) {
  int32_t i32 = 0;
  char buf[8];
  mfree_status_t code;
  mfree_context_t *null_ctx = NULL;
  /* each output may be NULL (documented) */
  ROW0(MFREE_SUCCESS, mfree_version_get(NULL, NULL, NULL));
  cover("mfree_version_string"); /* no argument; checked for a non-empty string below */
  cover("mfree_status_string");  /* any value, checked below */

  ROW0(MFREE_ERR_NULL, mfree_context_create(NULL));
  ROW0(MFREE_SUCCESS, mfree_context_destroy(NULL));
  ROW0(MFREE_SUCCESS, mfree_context_destroy(&null_ctx));
  ROW0(MFREE_ERR_NULL, mfree_context_get_last_error(NULL, &code, buf, sizeof buf));
  /* The getters of the context itself record nothing: get_last_error must not overwrite
   * the error it is asked for, and get_num_threads takes a const context. */
  ROW0(MFREE_ERR_ARG, mfree_context_get_last_error(F.ctx, &code, buf, 0));
  ROW0(MFREE_ERR_ARG, mfree_context_get_last_error(F.ctx, &code, buf, -5));
  ROW0(MFREE_ERR_NULL, mfree_context_set_error(NULL, MFREE_ERR_ARG, "x"));
  ROW0(MFREE_ERR_NULL, mfree_context_set_error_handler(NULL, handler, NULL));
  ROW0(MFREE_ERR_NULL, mfree_context_set_num_threads(NULL, 1));
  ROW(MFREE_ERR_ARG, mfree_context_set_num_threads(F.ctx, -1));
  ROW0(MFREE_ERR_NULL, mfree_context_get_num_threads(NULL, &i32));
  ROW0(MFREE_ERR_NULL, mfree_context_get_num_threads(F.ctx, NULL));
  ROW0(MFREE_ERR_NULL, mfree_context_set_backend(NULL, MFREE_BACKEND_REF));
  ROW(MFREE_ERR_ARG, mfree_context_set_backend(F.ctx, 0));
  ROW(MFREE_ERR_ARG, mfree_context_set_backend(F.ctx, 3));
  ROW0(MFREE_ERR_NULL, mfree_context_get_backend(NULL, &i32));
  ROW0(MFREE_ERR_NULL, mfree_context_get_backend(F.ctx, NULL));
  ROW0(MFREE_ERR_NULL, mfree_context_set_page_hints(NULL, MFREE_PAGES_HUGE));
  ROW(MFREE_ERR_ARG, mfree_context_set_page_hints(F.ctx, -1));
  ROW(MFREE_ERR_ARG, mfree_context_set_page_hints(F.ctx, 4));
  ROW0(MFREE_ERR_NULL, mfree_context_get_page_hints(NULL, &i32));
  ROW0(MFREE_ERR_NULL, mfree_context_get_page_hints(F.ctx, NULL));
#if MFREE_T060_ALLOCATOR
  ROW0(MFREE_ERR_NULL, mfree_context_set_allocator(NULL, my_alloc, my_free, NULL));
  ROW(MFREE_ERR_ARG, mfree_context_set_allocator(F.ctx, my_alloc, NULL, NULL));
  ROW(MFREE_ERR_ARG, mfree_context_set_allocator(F.ctx, NULL, my_free, NULL));
#endif
}

static void rows_kernels(void) {
  const double r[3] = {0.0, 0.1, 0.2}, rnan[2] = {0.1, NAN}, rneg[2] = {0.1, -0.1};
  double w[3], rad, c;
  ROW0(MFREE_ERR_NULL, mfree_kernel_eval(NULL, MFREE_KERNEL_CUBIC_SPLINE, 2, 0, 1, 3, r, w, NULL, NULL));
  ROW(MFREE_ERR_ARG, mfree_kernel_eval(F.ctx, (mfree_kernel_t)0, 2, 0, 1, 3, r, w, NULL, NULL));
  ROW(MFREE_ERR_ARG, mfree_kernel_eval(F.ctx, (mfree_kernel_t)999, 2, 0, 1, 3, r, w, NULL, NULL));
  ROW(MFREE_ERR_ARG, mfree_kernel_eval(F.ctx, MFREE_KERNEL_CUBIC_SPLINE, 0, 0, 1, 3, r, w, NULL, NULL));
  ROW(MFREE_ERR_ARG, mfree_kernel_eval(F.ctx, MFREE_KERNEL_CUBIC_SPLINE, 4, 0, 1, 3, r, w, NULL, NULL));
  ROW(MFREE_ERR_ARG, mfree_kernel_eval(F.ctx, MFREE_KERNEL_CUBIC_SPLINE, 2, 0, 1, -1, r, w, NULL, NULL));
  ROW(MFREE_ERR_ARG, mfree_kernel_eval(F.ctx, MFREE_KERNEL_CUBIC_SPLINE, 2, 0, 0.0, 3, r, w, NULL, NULL));
  ROW(MFREE_ERR_ARG, mfree_kernel_eval(F.ctx, MFREE_KERNEL_CUBIC_SPLINE, 2, 0, -1.0, 3, r, w, NULL, NULL));
  ROW(MFREE_ERR_ARG, mfree_kernel_eval(F.ctx, MFREE_KERNEL_CUBIC_SPLINE, 2, 0, NAN, 3, r, w, NULL, NULL));
  ROW(MFREE_ERR_ARG, mfree_kernel_eval(F.ctx, MFREE_KERNEL_CUBIC_SPLINE, 2, 0, INFINITY, 3, r, w, NULL, NULL));
  ROW(MFREE_ERR_ARG, mfree_kernel_eval(F.ctx, MFREE_KERNEL_REVISED_SUPER_GAUSS, 2, -1.0, 1, 3, r, w, NULL, NULL));
  ROW(MFREE_ERR_ARG, mfree_kernel_eval(F.ctx, MFREE_KERNEL_REVISED_SUPER_GAUSS, 2, NAN, 1, 3, r, w, NULL, NULL));
  ROW(MFREE_ERR_NULL, mfree_kernel_eval(F.ctx, MFREE_KERNEL_CUBIC_SPLINE, 2, 0, 1, 3, NULL, w, NULL, NULL));
  ROW(MFREE_ERR_INPUT, mfree_kernel_eval(F.ctx, MFREE_KERNEL_CUBIC_SPLINE, 2, 0, 1, 2, rnan, w, NULL, NULL));
  ROW(MFREE_ERR_INPUT, mfree_kernel_eval(F.ctx, MFREE_KERNEL_CUBIC_SPLINE, 2, 0, 1, 2, rneg, w, NULL, NULL));

  ROW0(MFREE_ERR_NULL, mfree_kernel_get_support_radius(NULL, MFREE_KERNEL_CUBIC_SPLINE, 0, &rad));
  ROW(MFREE_ERR_ARG, mfree_kernel_get_support_radius(F.ctx, (mfree_kernel_t)0, 0, &rad));
  ROW(MFREE_ERR_ARG, mfree_kernel_get_support_radius(F.ctx, MFREE_KERNEL_REVISED_SUPER_GAUSS, -2.0, &rad));
  ROW(MFREE_ERR_NULL, mfree_kernel_get_support_radius(F.ctx, MFREE_KERNEL_CUBIC_SPLINE, 0, NULL));
  ROW0(MFREE_ERR_NULL, mfree_kernel_get_normalization(NULL, MFREE_KERNEL_CUBIC_SPLINE, 2, 0, &c));
  ROW(MFREE_ERR_ARG, mfree_kernel_get_normalization(F.ctx, (mfree_kernel_t)16, 2, 0, &c));
  ROW(MFREE_ERR_ARG, mfree_kernel_get_normalization(F.ctx, MFREE_KERNEL_CUBIC_SPLINE, 5, 0, &c));
  ROW(MFREE_ERR_ARG, mfree_kernel_get_normalization(F.ctx, MFREE_KERNEL_REVISED_SUPER_GAUSS, 2, INFINITY, &c));
  ROW(MFREE_ERR_NULL, mfree_kernel_get_normalization(F.ctx, MFREE_KERNEL_CUBIC_SPLINE, 2, 0, NULL));
}

static void rows_particles(void) {
  mfree_particles_t *p = NULL, *null_ps = NULL;
  double xbad[2 * N], v[N];
  const double one = 1.0, zero = 0.0, neg = -1.0, nan_ = NAN, inf_ = INFINITY;
  const double lo[2] = {0, 0}, hi[2] = {1, 1}, hiflip[2] = {-1, 1}, lonan[2] = {NAN, 0};
  const int32_t per[2] = {1, 0};
  const double lohuge[2] = {-DBL_MAX, 0}, hihuge[2] = {DBL_MAX, 1};
  int32_t i32, st[N];
  int64_t i64, rowptr[N + 1];
  int32_t cols[4 * N];
  memcpy(xbad, F.x, sizeof xbad);
  xbad[7] = NAN;

  ROW0(MFREE_ERR_NULL, mfree_particles_create(NULL, 2, N, &p));
  ROW(MFREE_ERR_ARG, mfree_particles_create(F.ctx, 0, N, &p));
  ROW(MFREE_ERR_ARG, mfree_particles_create(F.ctx, 4, N, &p));
  ROW(MFREE_ERR_ARG, mfree_particles_create(F.ctx, 2, -1, &p));
  ROW(MFREE_ERR_NULL, mfree_particles_create(F.ctx, 2, N, NULL));
  ROW0(MFREE_SUCCESS, mfree_particles_destroy(NULL));
  ROW0(MFREE_SUCCESS, mfree_particles_destroy(&null_ps));

  ROW0(MFREE_ERR_NULL, mfree_particles_set_num_ghost(NULL, 0));
  ROW(MFREE_ERR_ARG, mfree_particles_set_num_ghost(F.fresh, -1));
  ROW(MFREE_ERR_ARG, mfree_particles_set_num_ghost(F.fresh, N + 1));

  ROW0(MFREE_ERR_NULL, mfree_particles_set_positions(NULL, F.x, MFREE_LAYOUT_AOS, 2, MFREE_COPY));
  ROW(MFREE_ERR_NULL, mfree_particles_set_positions(F.fresh, NULL, MFREE_LAYOUT_AOS, 2, MFREE_COPY));
  ROW(MFREE_ERR_ARG, mfree_particles_set_positions(F.fresh, F.x, (mfree_layout_t)0, 2, MFREE_COPY));
  ROW(MFREE_ERR_ARG, mfree_particles_set_positions(F.fresh, F.x, (mfree_layout_t)3, 2, MFREE_COPY));
  ROW(MFREE_ERR_ARG, mfree_particles_set_positions(F.fresh, F.x, MFREE_LAYOUT_AOS, 1, MFREE_COPY));
  ROW(MFREE_ERR_ARG, mfree_particles_set_positions(F.fresh, F.x, MFREE_LAYOUT_AOS, -2, MFREE_COPY));
  ROW(MFREE_ERR_ARG, mfree_particles_set_positions(F.fresh, F.x, MFREE_LAYOUT_SOA, N - 1, MFREE_COPY));
  /* a leading dimension whose last entry's offset wraps a 64-bit index */
  ROW(MFREE_ERR_ARG, mfree_particles_set_positions(F.ps, F.x, MFREE_LAYOUT_AOS, INT64_MAX, MFREE_BORROW));
  ROW(MFREE_ERR_ARG, mfree_particles_set_positions(F.ps, F.x, MFREE_LAYOUT_SOA, INT64_MAX / 2, MFREE_COPY));
  ROW(MFREE_ERR_ARG, mfree_particles_set_positions(F.fresh, F.x, MFREE_LAYOUT_AOS, 2, (mfree_mem_t)0));
  ROW(MFREE_ERR_ARG, mfree_particles_set_positions(F.fresh, F.x, MFREE_LAYOUT_AOS, 2, (mfree_mem_t)7));
  ROW(MFREE_ERR_INPUT, mfree_particles_set_positions(F.ps, xbad, MFREE_LAYOUT_AOS, 2, MFREE_COPY));

  ROW0(MFREE_ERR_NULL, mfree_particles_set_volumes(NULL, &one, 0, MFREE_COPY));
  ROW(MFREE_ERR_NULL, mfree_particles_set_volumes(F.ps, NULL, 0, MFREE_COPY));
  ROW(MFREE_ERR_ARG, mfree_particles_set_volumes(F.ps, &one, -1, MFREE_COPY));
  ROW(MFREE_ERR_ARG, mfree_particles_set_volumes(F.ps, &one, 0, (mfree_mem_t)0));
  ROW(MFREE_ERR_INPUT, mfree_particles_set_volumes(F.ps, &zero, 0, MFREE_COPY));
  ROW(MFREE_ERR_INPUT, mfree_particles_set_volumes(F.ps, &neg, 0, MFREE_COPY));
  ROW(MFREE_ERR_INPUT, mfree_particles_set_volumes(F.ps, &nan_, 0, MFREE_COPY));
  ROW(MFREE_ERR_INPUT, mfree_particles_set_volumes(F.ps, &inf_, 0, MFREE_COPY));
  ROW0(MFREE_ERR_NULL, mfree_particles_set_masses(NULL, &one, 0, MFREE_COPY));
  ROW(MFREE_ERR_NULL, mfree_particles_set_masses(F.fresh, NULL, 0, MFREE_COPY));
  ROW(MFREE_ERR_ARG, mfree_particles_set_masses(F.fresh, &one, -3, MFREE_COPY));
  ROW(MFREE_ERR_INPUT, mfree_particles_set_masses(F.fresh, &zero, 0, MFREE_COPY));
  ROW(MFREE_ERR_INPUT, mfree_particles_set_masses(F.fresh, &nan_, 0, MFREE_COPY));
  ROW0(MFREE_ERR_NULL, mfree_particles_set_densities(NULL, &one, 0, MFREE_COPY));
  ROW(MFREE_ERR_NULL, mfree_particles_set_densities(F.fresh, NULL, 0, MFREE_COPY));
  ROW(MFREE_ERR_ARG, mfree_particles_set_densities(F.fresh, &one, -1, MFREE_COPY));
  ROW(MFREE_ERR_INPUT, mfree_particles_set_densities(F.fresh, &neg, 0, MFREE_COPY));
  ROW(MFREE_ERR_INPUT, mfree_particles_set_densities(F.fresh, &inf_, 0, MFREE_COPY));
  ROW0(MFREE_ERR_NULL, mfree_particles_set_support(NULL, &one, 0, MFREE_COPY));
  ROW(MFREE_ERR_NULL, mfree_particles_set_support(F.ps, NULL, 0, MFREE_COPY));
  ROW(MFREE_ERR_ARG, mfree_particles_set_support(F.ps, &one, -1, MFREE_COPY));
  ROW(MFREE_ERR_ARG, mfree_particles_set_support(F.ps, &one, INT64_MAX, MFREE_COPY));
  ROW(MFREE_ERR_ARG, mfree_particles_set_volumes(F.ps, &one, INT64_MAX / 4, MFREE_BORROW));
  ROW(MFREE_ERR_INPUT, mfree_particles_set_support(F.ps, &zero, 0, MFREE_COPY));
  ROW(MFREE_ERR_INPUT, mfree_particles_set_support(F.ps, &neg, 0, MFREE_COPY));
  ROW(MFREE_ERR_INPUT, mfree_particles_set_support(F.ps, &nan_, 0, MFREE_COPY));

  ROW0(MFREE_ERR_NULL, mfree_particles_set_search(NULL, MFREE_SEARCH_GATHER, 2.0));
  ROW(MFREE_ERR_ARG, mfree_particles_set_search(F.fresh, (mfree_search_t)0, 2.0));
  ROW(MFREE_ERR_ARG, mfree_particles_set_search(F.fresh, (mfree_search_t)4, 2.0));
  ROW(MFREE_ERR_ARG, mfree_particles_set_search(F.fresh, MFREE_SEARCH_GATHER, 0.0));
  ROW(MFREE_ERR_ARG, mfree_particles_set_search(F.fresh, MFREE_SEARCH_GATHER, -2.0));
  ROW(MFREE_ERR_ARG, mfree_particles_set_search(F.fresh, MFREE_SEARCH_GATHER, NAN));

  ROW0(MFREE_ERR_NULL, mfree_particles_set_periodic(NULL, lo, hi, per));
  ROW(MFREE_ERR_NULL, mfree_particles_set_periodic(F.fresh, NULL, hi, per));
  ROW(MFREE_ERR_NULL, mfree_particles_set_periodic(F.fresh, lo, NULL, per));
  ROW(MFREE_ERR_NULL, mfree_particles_set_periodic(F.fresh, lo, hi, NULL));
  /* a box is an argument (MFREE_ERR_ARG), not data */
  ROW(MFREE_ERR_ARG, mfree_particles_set_periodic(F.fresh, lo, hiflip, per));
  ROW(MFREE_ERR_INPUT, mfree_particles_set_periodic(F.fresh, lonan, hi, per)); /* NaN: data */
  /* a period hi - lo that overflows to infinity */
  ROW(MFREE_ERR_INPUT, mfree_particles_set_periodic(F.ps, lohuge, hihuge, per));

  /* host neighbour lists: row i = {i}, malformed variants */
  for (int i = 0; i <= N; ++i) rowptr[i] = i;
  for (int i = 0; i < N; ++i) cols[i] = i;
  ROW0(MFREE_ERR_NULL, mfree_particles_set_neighbors(NULL, rowptr, cols, 0, MFREE_COPY));
  ROW(MFREE_ERR_NULL, mfree_particles_set_neighbors(F.fresh, NULL, cols, 0, MFREE_COPY));
  ROW(MFREE_ERR_NULL, mfree_particles_set_neighbors(F.fresh, rowptr, NULL, 0, MFREE_COPY));
  ROW(MFREE_ERR_ARG, mfree_particles_set_neighbors(F.fresh, rowptr, cols, 2, MFREE_COPY));
  ROW(MFREE_ERR_ARG, mfree_particles_set_neighbors(F.fresh, rowptr, cols, 0, (mfree_mem_t)3));
  cols[3] = N; /* out of range */
  ROW(MFREE_ERR_INPUT, mfree_particles_set_neighbors(F.fresh, rowptr, cols, 0, MFREE_COPY));
  cols[3] = -1;
  ROW(MFREE_ERR_INPUT, mfree_particles_set_neighbors(F.fresh, rowptr, cols, 0, MFREE_COPY));
  cols[3] = 3;
  rowptr[5] = 3; /* not monotone */
  ROW(MFREE_ERR_INPUT, mfree_particles_set_neighbors(F.fresh, rowptr, cols, 0, MFREE_COPY));
  rowptr[5] = 5;
  rowptr[0] = 1; /* rowptr[0] != base */
  ROW(MFREE_ERR_INPUT, mfree_particles_set_neighbors(F.fresh, rowptr, cols, 0, MFREE_COPY));
  rowptr[0] = 0;
  for (int i = 1; i <= N; ++i) rowptr[i] = i + 1; /* row 0 = {0, 0}: a column twice */
  for (int i = 0; i <= N; ++i) cols[i] = i > 0 ? i - 1 : 0;
  ROW(MFREE_ERR_INPUT, mfree_particles_set_neighbors(F.fresh, rowptr, cols, 0, MFREE_COPY));
  ROW(MFREE_ERR_INPUT, mfree_particles_set_neighbors(F.fresh, rowptr, cols, 0, MFREE_BORROW));
  for (int i = 0; i <= N; ++i) rowptr[i] = i;
  for (int i = 0; i < N; ++i) cols[i] = i;

  ROW0(MFREE_ERR_NULL, mfree_particles_setup(NULL));
  ROW0(MFREE_ERR_NULL, mfree_particles_update(NULL));
  ROW(MFREE_ERR_STATE, mfree_particles_update(F.fresh));
  ROW0(MFREE_ERR_NULL, mfree_particles_get_dimension(NULL, &i32));
  ROW(MFREE_ERR_NULL, mfree_particles_get_dimension(F.ps, NULL));
  ROW0(MFREE_ERR_NULL, mfree_particles_get_size(NULL, &i32, &i32));
  ROW0(MFREE_ERR_NULL, mfree_particles_get_neighbor_nnz(NULL, &i64));
  ROW(MFREE_ERR_NULL, mfree_particles_get_neighbor_nnz(F.ps, NULL));
  ROW(MFREE_ERR_STATE, mfree_particles_get_neighbor_nnz(F.fresh, &i64));
  ROW0(MFREE_ERR_NULL, mfree_particles_get_neighbors(NULL, rowptr, cols));
  ROW(MFREE_ERR_NULL, mfree_particles_get_neighbors(F.ps, NULL, NULL));
  ROW(MFREE_ERR_STATE, mfree_particles_get_neighbors(F.fresh, rowptr, cols));
  ROW0(MFREE_ERR_NULL, mfree_particles_get_volumes(NULL, v));
  ROW(MFREE_ERR_NULL, mfree_particles_get_volumes(F.ps, NULL));
  ROW0(MFREE_ERR_NULL, mfree_particles_get_site_status(NULL, st, &i32));
  ROW(MFREE_ERR_NULL, mfree_particles_get_site_status(F.ps, NULL, NULL));
  ROW(MFREE_ERR_STATE, mfree_particles_get_site_status(F.fresh, st, &i32));
}

#if MFREE_T060_MESH
static void rows_mesh(void) {
  mfree_mesh_t *mh = NULL, *null_mesh = NULL;
  int32_t conn[4] = {0, 1, M + 1, M}, rep[4] = {0, 1, 1, M}, oob[4] = {0, 1, N, M};
  int32_t npts;
  double qx[2 * 64], qw[64];
  ROW0(MFREE_ERR_NULL, mfree_mesh_create(NULL, F.ps, &mh));
  ROW(MFREE_ERR_NULL, mfree_mesh_create(F.ctx, NULL, &mh));
  ROW(MFREE_ERR_NULL, mfree_mesh_create(F.ctx, F.ps, NULL));
  ROW0(MFREE_SUCCESS, mfree_mesh_destroy(NULL));
  ROW0(MFREE_SUCCESS, mfree_mesh_destroy(&null_mesh));

  assert_ok(F.ctx, mfree_mesh_create(F.ctx, F.ps, &mh));
  ROW0(MFREE_ERR_NULL, mfree_mesh_add_elements(NULL, MFREE_ELEMENT_QUAD4, 1, conn, 0, MFREE_COPY));
  ROW(MFREE_ERR_NULL, mfree_mesh_add_elements(mh, MFREE_ELEMENT_QUAD4, 1, NULL, 0, MFREE_COPY));
  ROW(MFREE_ERR_ARG, mfree_mesh_add_elements(mh, (mfree_element_t)0, 1, conn, 0, MFREE_COPY));
  ROW(MFREE_ERR_ARG, mfree_mesh_add_elements(mh, (mfree_element_t)5, 1, conn, 0, MFREE_COPY));
  ROW(MFREE_ERR_MISMATCH, mfree_mesh_add_elements(mh, MFREE_ELEMENT_HEX8, 1, conn, 0, MFREE_COPY));
  ROW(MFREE_ERR_ARG, mfree_mesh_add_elements(mh, MFREE_ELEMENT_QUAD4, -1, conn, 0, MFREE_COPY));
  ROW(MFREE_ERR_ARG, mfree_mesh_add_elements(mh, MFREE_ELEMENT_QUAD4, 1, conn, 2, MFREE_COPY));
  ROW(MFREE_ERR_ARG, mfree_mesh_add_elements(mh, MFREE_ELEMENT_QUAD4, 1, conn, 0, (mfree_mem_t)0));
  ROW(MFREE_ERR_INPUT, mfree_mesh_add_elements(mh, MFREE_ELEMENT_QUAD4, 1, oob, 0, MFREE_COPY));
  ROW(MFREE_ERR_INPUT, mfree_mesh_add_elements(mh, MFREE_ELEMENT_QUAD4, 1, rep, 0, MFREE_COPY));
  /* clockwise element: rejected at setup, the mesh stays usable */
  int32_t cw[4] = {0, M, M + 1, 1};
  assert_ok(F.ctx, mfree_mesh_add_elements(mh, MFREE_ELEMENT_QUAD4, 1, cw, 0, MFREE_COPY));
  ROW0(MFREE_ERR_NULL, mfree_mesh_setup(NULL));
  ROW(MFREE_ERR_INPUT, mfree_mesh_setup(mh));
  mfree_mesh_destroy(&mh);

  ROW0(MFREE_ERR_NULL, mfree_mesh_get_size(NULL, &npts));
  ROW(MFREE_ERR_NULL, mfree_mesh_get_size(F.mesh, NULL));
  ROW0(MFREE_ERR_NULL, mfree_mesh_get_quadrature(NULL, 2, &npts, qx, qw));
  ROW(MFREE_ERR_NULL, mfree_mesh_get_quadrature(F.mesh, 2, NULL, qx, qw));
  ROW(MFREE_ERR_ARG, mfree_mesh_get_quadrature(F.mesh, 0, &npts, NULL, NULL));
  ROW(MFREE_ERR_ARG, mfree_mesh_get_quadrature(F.mesh, 11, &npts, NULL, NULL));
}
#endif

static void rows_approximant(void) {
  mfree_approximant_t *b = NULL, *null_a = NULL;
  double out[6 * N], pts[4] = {0.5, 0.5, 0.3, NAN}, ph = 0.3, err1, err2;
  const double zero = 0.0;
  int32_t i32, st[N];
  int64_t i64, rowptr[N + 1];
  int32_t cols[N * N];
  double vals[N * N];
  double ubad[N];
  memcpy(ubad, F.u, sizeof ubad);
  ubad[4] = NAN;

  ROW0(MFREE_ERR_NULL, mfree_approximant_create(NULL, F.ps, MFREE_METHOD_MLS, &b));
  ROW(MFREE_ERR_NULL, mfree_approximant_create(F.ctx, NULL, MFREE_METHOD_MLS, &b));
  ROW(MFREE_ERR_NULL, mfree_approximant_create(F.ctx, F.ps, MFREE_METHOD_MLS, NULL));
  ROW(MFREE_ERR_ARG, mfree_approximant_create(F.ctx, F.ps, (mfree_method_t)0, &b));
  ROW(MFREE_ERR_ARG, mfree_approximant_create(F.ctx, F.ps, (mfree_method_t)14, &b));
  ROW0(MFREE_SUCCESS, mfree_approximant_destroy(NULL));
  ROW0(MFREE_SUCCESS, mfree_approximant_destroy(&null_a));

  ROW0(MFREE_ERR_NULL, mfree_approximant_set_kernel(NULL, MFREE_KERNEL_CUBIC_SPLINE, 0));
  ROW(MFREE_ERR_ARG, mfree_approximant_set_kernel(F.a_new, (mfree_kernel_t)0, 0));
  ROW(MFREE_ERR_ARG, mfree_approximant_set_kernel(F.a_new, (mfree_kernel_t)16, 0));
  ROW(MFREE_ERR_ARG, mfree_approximant_set_kernel(F.a_new, MFREE_KERNEL_REVISED_SUPER_GAUSS, NAN));
  ROW0(MFREE_ERR_NULL, mfree_approximant_set_order(NULL, 1));
  ROW(MFREE_ERR_UNSUPPORTED, mfree_approximant_set_order(F.a_new, -1));
  ROW(MFREE_ERR_UNSUPPORTED, mfree_approximant_set_order(F.a_new, 4));
  ROW0(MFREE_ERR_NULL, mfree_approximant_set_derivatives(NULL, MFREE_DERIV_VALUE));
  ROW(MFREE_ERR_ARG, mfree_approximant_set_derivatives(F.a_new, 0));
  ROW(MFREE_ERR_ARG, mfree_approximant_set_derivatives(F.a_new, 8));
  ROW(MFREE_ERR_ARG, mfree_approximant_set_derivatives(F.a_new, -1));
  ROW0(MFREE_ERR_NULL, mfree_approximant_set_fallback(NULL, MFREE_FALLBACK_NONE));
  ROW(MFREE_ERR_ARG, mfree_approximant_set_fallback(F.a_new, (mfree_fallback_t)0));
  ROW(MFREE_ERR_ARG, mfree_approximant_set_fallback(F.a_new, (mfree_fallback_t)3));
#if MFREE_T060_MESH
  ROW0(MFREE_ERR_NULL, mfree_approximant_set_mesh(NULL, F.mesh));
  {
    mfree_approximant_t *mls = NULL; /* not MPFEM, on the mesh's particles */
    assert_ok(F.ctx, mfree_approximant_create(F.ctx, F.psm, MFREE_METHOD_MLS, &mls));
    ROW(MFREE_ERR_UNSUPPORTED, mfree_approximant_set_mesh(mls, F.mesh));
    mfree_approximant_destroy(&mls);
  }
  ROW(MFREE_ERR_MISMATCH, mfree_approximant_set_mesh(F.a_new, F.mesh)); /* other particles */
  ROW(MFREE_ERR_NULL, mfree_approximant_set_mesh(F.am, NULL));
  {
    mfree_approximant_t *m3 = NULL;
    assert_ok(F.ctx, mfree_approximant_create(F.ctx, F.ps3, MFREE_METHOD_MPFEM, &m3));
    ROW(MFREE_ERR_MISMATCH, mfree_approximant_set_mesh(m3, F.mesh));
    mfree_approximant_destroy(&m3);
  }
  ROW0(MFREE_ERR_NULL, mfree_approximant_set_mpfem(NULL, MFREE_MPFEM_DERIV_FULL, 8));
  ROW(MFREE_ERR_UNSUPPORTED, mfree_approximant_set_mpfem(F.a_new, MFREE_MPFEM_DERIV_FULL, 8));
  ROW(MFREE_ERR_ARG, mfree_approximant_set_mpfem(F.am, (mfree_mpfem_deriv_t)0, 8));
  ROW(MFREE_ERR_ARG, mfree_approximant_set_mpfem(F.am, (mfree_mpfem_deriv_t)4, 8));
  ROW(MFREE_ERR_ARG, mfree_approximant_set_mpfem(F.am, MFREE_MPFEM_DERIV_FULL, 0));
  ROW(MFREE_ERR_ARG, mfree_approximant_set_mpfem(F.am, MFREE_MPFEM_DERIV_FULL, 21));
#endif

  ROW0(MFREE_ERR_NULL, mfree_approximant_set_points(NULL, 1, pts, MFREE_LAYOUT_AOS, 2, &ph, 0, MFREE_COPY));
  ROW(MFREE_ERR_ARG, mfree_approximant_set_points(F.a_new, -1, pts, MFREE_LAYOUT_AOS, 2, &ph, 0, MFREE_COPY));
  ROW(MFREE_ERR_NULL, mfree_approximant_set_points(F.a_new, 1, NULL, MFREE_LAYOUT_AOS, 2, &ph, 0, MFREE_COPY));
  ROW(MFREE_ERR_NULL, mfree_approximant_set_points(F.a_new, 1, pts, MFREE_LAYOUT_AOS, 2, NULL, 0, MFREE_COPY));
  ROW(MFREE_ERR_ARG, mfree_approximant_set_points(F.a_new, 1, pts, MFREE_LAYOUT_AOS, 1, &ph, 0, MFREE_COPY));
  ROW(MFREE_ERR_ARG, mfree_approximant_set_points(F.a_new, 1, pts, (mfree_layout_t)9, 2, &ph, 0, MFREE_COPY));
  ROW(MFREE_ERR_ARG, mfree_approximant_set_points(F.a_new, 1, pts, MFREE_LAYOUT_AOS, 2, &ph, -1, MFREE_COPY));
  ROW(MFREE_ERR_ARG, mfree_approximant_set_points(F.a_new, 1, pts, MFREE_LAYOUT_AOS, 2, &ph, 0, (mfree_mem_t)0));
  ROW(MFREE_ERR_INPUT, mfree_approximant_set_points(F.a_new, 2, pts, MFREE_LAYOUT_AOS, 2, &ph, 0, MFREE_COPY));
  ROW(MFREE_ERR_ARG, mfree_approximant_set_points(F.a, 2, pts, MFREE_LAYOUT_AOS, INT64_MAX, &ph, 0, MFREE_COPY));
  ROW(MFREE_ERR_INPUT, mfree_approximant_set_points(F.a_new, 1, pts, MFREE_LAYOUT_AOS, 2, &zero, 0, MFREE_COPY));
  {
    mfree_approximant_t *rl = NULL;
    assert_ok(F.ctx, mfree_approximant_create(F.ctx, F.ps, MFREE_METHOD_RANDLES_LIBERSKY, &rl));
    ROW(MFREE_ERR_UNSUPPORTED, mfree_approximant_set_points(rl, 1, pts, MFREE_LAYOUT_AOS, 2, &ph, 0, MFREE_COPY));
    mfree_approximant_destroy(&rl);
  }

  ROW0(MFREE_ERR_NULL, mfree_approximant_setup(NULL));
#if MFREE_T060_MESH
  {
    mfree_approximant_t *mp = NULL; /* MPFEM without a mesh */
    assert_ok(F.ctx, mfree_approximant_create(F.ctx, F.ps, MFREE_METHOD_MPFEM, &mp));
    ROW(MFREE_ERR_STATE, mfree_approximant_setup(mp));
    mfree_approximant_destroy(&mp);
  }
#endif
  ROW0(MFREE_ERR_NULL, mfree_approximant_update(NULL));
  ROW(MFREE_ERR_STATE, mfree_approximant_update(F.a_new));

  ROW0(MFREE_ERR_NULL, mfree_approximant_apply(NULL, MFREE_OP_VALUE, 1, F.u, MFREE_LAYOUT_AOS, 1, out, MFREE_LAYOUT_AOS, 1));
  ROW(MFREE_ERR_STATE, mfree_approximant_apply(F.a_new, MFREE_OP_VALUE, 1, F.u, MFREE_LAYOUT_AOS, 1, out, MFREE_LAYOUT_AOS, 1));
  ROW(MFREE_ERR_ARG, mfree_approximant_apply(F.a, (mfree_op_t)0, 1, F.u, MFREE_LAYOUT_AOS, 1, out, MFREE_LAYOUT_AOS, 1));
  ROW(MFREE_ERR_ARG, mfree_approximant_apply(F.a, (mfree_op_t)6, 1, F.u, MFREE_LAYOUT_AOS, 1, out, MFREE_LAYOUT_AOS, 1));
  ROW(MFREE_ERR_ARG, mfree_approximant_apply(F.a, MFREE_OP_VALUE, 0, F.u, MFREE_LAYOUT_AOS, 1, out, MFREE_LAYOUT_AOS, 1));
  ROW(MFREE_ERR_ARG, mfree_approximant_apply(F.a, MFREE_OP_VALUE, -2, F.u, MFREE_LAYOUT_AOS, 1, out, MFREE_LAYOUT_AOS, 1));
  ROW(MFREE_ERR_NULL, mfree_approximant_apply(F.a, MFREE_OP_VALUE, 1, NULL, MFREE_LAYOUT_AOS, 1, out, MFREE_LAYOUT_AOS, 1));
  ROW(MFREE_ERR_NULL, mfree_approximant_apply(F.a, MFREE_OP_VALUE, 1, F.u, MFREE_LAYOUT_AOS, 1, NULL, MFREE_LAYOUT_AOS, 1));
  ROW(MFREE_ERR_ARG, mfree_approximant_apply(F.a, MFREE_OP_VALUE, 1, F.u, (mfree_layout_t)0, 1, out, MFREE_LAYOUT_AOS, 1));
  ROW(MFREE_ERR_ARG, mfree_approximant_apply(F.a, MFREE_OP_VALUE, 1, F.u, MFREE_LAYOUT_AOS, 1, out, (mfree_layout_t)5, 1));
  ROW(MFREE_ERR_ARG, mfree_approximant_apply(F.a, MFREE_OP_VALUE, 1, F.u, MFREE_LAYOUT_AOS, 0, out, MFREE_LAYOUT_AOS, 1));
  ROW(MFREE_ERR_ARG, mfree_approximant_apply(F.a, MFREE_OP_VALUE, 1, F.u, MFREE_LAYOUT_AOS, INT64_MAX, out, MFREE_LAYOUT_AOS, 1));
  ROW(MFREE_ERR_ARG, mfree_approximant_apply(F.a, MFREE_OP_VALUE, 1, F.u, MFREE_LAYOUT_AOS, 1, out, MFREE_LAYOUT_AOS, INT64_MAX / 8));
  ROW(MFREE_ERR_ARG, mfree_approximant_apply_add(F.a, MFREE_OP_GRADIENT, 1, F.u, MFREE_LAYOUT_SOA, N, out, MFREE_LAYOUT_SOA, INT64_MAX / 2));
  ROW(MFREE_ERR_ARG, mfree_approximant_apply(F.a, MFREE_OP_VALUE, 1, F.u, MFREE_LAYOUT_SOA, N - 1, out, MFREE_LAYOUT_AOS, 1));
  ROW(MFREE_ERR_ARG, mfree_approximant_apply(F.a, MFREE_OP_GRADIENT, 1, F.u, MFREE_LAYOUT_AOS, 1, out, MFREE_LAYOUT_AOS, 1));
  ROW(MFREE_ERR_ARG, mfree_approximant_apply(F.a, MFREE_OP_GRADIENT, 1, F.u, MFREE_LAYOUT_AOS, 1, out, MFREE_LAYOUT_SOA, N - 1));
  ROW(MFREE_ERR_MISMATCH, mfree_approximant_apply(F.a, MFREE_OP_DIVERGENCE, 1, F.u, MFREE_LAYOUT_AOS, 1, out, MFREE_LAYOUT_AOS, 1));
  /* a table that was not built */
  ROW(MFREE_ERR_STATE, mfree_approximant_apply(F.am, MFREE_OP_HESSIAN, 1, F.u, MFREE_LAYOUT_AOS, 1, out, MFREE_LAYOUT_AOS, 3));
  /* A NaN in the field is the host's data: apply does not scan it (hot path, documented
   * as allocation-free); it propagates to exactly the rows that read that particle. */
  ROW(MFREE_SUCCESS, mfree_approximant_apply(F.a, MFREE_OP_VALUE, 1, ubad, MFREE_LAYOUT_AOS, 1, out, MFREE_LAYOUT_AOS, 1));
  {
    int64_t rp[N + 1];
    static int32_t cc[N * N];
    assert_ok(F.ctx, mfree_approximant_assemble_csr(F.a, MFREE_DERIV_VALUE, 0, rp, cc, NULL));
    for (int i = 0; i < N; ++i) {
      int reads = 0;
      for (int64_t k = rp[i]; k < rp[i + 1]; ++k) reads |= cc[k] == 4;
      if (reads != (isnan(out[i]) != 0)) logf_("  apply with u[4] = NaN: row %s%s%d NaN %d\n", "", "", i, !reads);
    }
  }
  ROW0(MFREE_ERR_NULL, mfree_approximant_apply_add(NULL, MFREE_OP_VALUE, 1, F.u, MFREE_LAYOUT_AOS, 1, out, MFREE_LAYOUT_AOS, 1));
  ROW(MFREE_ERR_STATE, mfree_approximant_apply_add(F.a_new, MFREE_OP_VALUE, 1, F.u, MFREE_LAYOUT_AOS, 1, out, MFREE_LAYOUT_AOS, 1));
  ROW(MFREE_ERR_ARG, mfree_approximant_apply_add(F.a, (mfree_op_t)-3, 1, F.u, MFREE_LAYOUT_AOS, 1, out, MFREE_LAYOUT_AOS, 1));
  ROW(MFREE_ERR_ARG, mfree_approximant_apply_add(F.a, MFREE_OP_VALUE, 1, F.u, MFREE_LAYOUT_AOS, -1, out, MFREE_LAYOUT_AOS, 1));
  ROW(MFREE_ERR_NULL, mfree_approximant_apply_add(F.a, MFREE_OP_VALUE, 1, F.u, MFREE_LAYOUT_AOS, 1, NULL, MFREE_LAYOUT_AOS, 1));

  ROW0(MFREE_ERR_NULL, mfree_approximant_get_num_sites(NULL, &i32));
  ROW(MFREE_ERR_NULL, mfree_approximant_get_num_sites(F.a, NULL));
  ROW(MFREE_ERR_STATE, mfree_approximant_get_num_sites(F.a_new, &i32));
  ROW0(MFREE_ERR_NULL, mfree_approximant_get_nnz(NULL, &i64));
  ROW(MFREE_ERR_NULL, mfree_approximant_get_nnz(F.a, NULL));
  ROW(MFREE_ERR_STATE, mfree_approximant_get_nnz(F.a_new, &i64));
  ROW0(MFREE_ERR_NULL, mfree_approximant_assemble_csr(NULL, MFREE_DERIV_VALUE, 0, rowptr, cols, vals));
  ROW(MFREE_ERR_STATE, mfree_approximant_assemble_csr(F.a_new, MFREE_DERIV_VALUE, 0, rowptr, cols, vals));
  ROW(MFREE_ERR_NULL, mfree_approximant_assemble_csr(F.a, MFREE_DERIV_VALUE, 0, NULL, NULL, NULL));
  ROW(MFREE_ERR_ARG, mfree_approximant_assemble_csr(F.a, (mfree_deriv_t)3, 0, rowptr, cols, vals));
  ROW(MFREE_ERR_ARG, mfree_approximant_assemble_csr(F.a, MFREE_DERIV_GRADIENT, 2, rowptr, cols, vals));
  ROW(MFREE_ERR_ARG, mfree_approximant_assemble_csr(F.a, MFREE_DERIV_GRADIENT, -1, rowptr, cols, vals));
  ROW(MFREE_ERR_ARG, mfree_approximant_assemble_csr(F.a, MFREE_DERIV_HESSIAN, 3, rowptr, cols, vals));
  ROW(MFREE_ERR_ARG, mfree_approximant_assemble_csr(F.a, MFREE_DERIV_VALUE, 1, rowptr, cols, vals));
  ROW(MFREE_ERR_STATE, mfree_approximant_assemble_csr(F.am, MFREE_DERIV_HESSIAN, 0, rowptr, cols, vals));
  ROW0(MFREE_ERR_NULL, mfree_approximant_check_reproduction(NULL, 1, &err1, &err2));
  ROW(MFREE_ERR_STATE, mfree_approximant_check_reproduction(F.a_new, 1, &err1, &err2));
  ROW(MFREE_ERR_NULL, mfree_approximant_check_reproduction(F.a, 1, NULL, &err2));
  ROW(MFREE_ERR_ARG, mfree_approximant_check_reproduction(F.a, -1, &err1, &err2));
  ROW0(MFREE_ERR_NULL, mfree_approximant_get_site_status(NULL, st, &i32));
  ROW(MFREE_ERR_NULL, mfree_approximant_get_site_status(F.a, NULL, NULL));
  ROW(MFREE_ERR_STATE, mfree_approximant_get_site_status(F.a_new, st, &i32));
  ROW0(MFREE_ERR_NULL, mfree_approximant_get_neighbor_counts(NULL, st));
  ROW(MFREE_ERR_NULL, mfree_approximant_get_neighbor_counts(F.a, NULL));
  ROW(MFREE_ERR_STATE, mfree_approximant_get_neighbor_counts(F.a_new, st));
  ROW0(MFREE_ERR_NULL, mfree_approximant_get_condition(NULL, out));
  ROW(MFREE_ERR_NULL, mfree_approximant_get_condition(F.a, NULL));
  ROW(MFREE_ERR_STATE, mfree_approximant_get_condition(F.a_new, out));
  ROW0(MFREE_ERR_NULL, mfree_approximant_get_site_order(NULL, st));
  ROW(MFREE_ERR_NULL, mfree_approximant_get_site_order(F.a, NULL));
  ROW(MFREE_ERR_STATE, mfree_approximant_get_site_order(F.a_new, st));
}

static void rows_matrix(void) {
  mfree_matrix_t *B = NULL, *null_m = NULL;
  int64_t rp[3] = {0, 1, 2}, rpbad[3] = {0, 2, 1};
  int32_t ci[2] = {0, 1}, cibad[2] = {0, 5};
  double va[2] = {1, 1}, vanan[2] = {1, NAN}, x[3] = {1, 2, 3}, y[3];
  int32_t i32, i32b;
  int64_t i64;
  const int64_t *p64;
  const int32_t *p32;
  const int64_t *q64;
  const double *pv;
  ROW0(MFREE_ERR_NULL, mfree_matrix_create_csr(NULL, 2, 2, rp, ci, va, &B));
  ROW(MFREE_ERR_ARG, mfree_matrix_create_csr(F.ctx, -1, 2, rp, ci, va, &B));
  ROW(MFREE_ERR_ARG, mfree_matrix_create_csr(F.ctx, 2, -1, rp, ci, va, &B));
  ROW(MFREE_ERR_NULL, mfree_matrix_create_csr(F.ctx, 2, 2, NULL, ci, va, &B));
  ROW(MFREE_ERR_NULL, mfree_matrix_create_csr(F.ctx, 2, 2, rp, NULL, va, &B));
  ROW(MFREE_ERR_NULL, mfree_matrix_create_csr(F.ctx, 2, 2, rp, ci, NULL, &B));
  ROW(MFREE_ERR_NULL, mfree_matrix_create_csr(F.ctx, 2, 2, rp, ci, va, NULL));
  ROW(MFREE_ERR_INPUT, mfree_matrix_create_csr(F.ctx, 2, 2, rpbad, ci, va, &B));
  ROW(MFREE_ERR_INPUT, mfree_matrix_create_csr(F.ctx, 2, 2, rp, cibad, va, &B));
  ROW(MFREE_ERR_INPUT, mfree_matrix_create_csr(F.ctx, 2, 2, rp, ci, vanan, &B));
  ROW0(MFREE_SUCCESS, mfree_matrix_destroy(NULL));
  ROW0(MFREE_SUCCESS, mfree_matrix_destroy(&null_m));
  ROW0(MFREE_ERR_NULL, mfree_matrix_get_size(NULL, &i32, &i32b, &i64));
  ROW0(MFREE_ERR_NULL, mfree_matrix_get_csr(NULL, &p64, &p32, &pv));
  ROW(MFREE_ERR_NULL, mfree_matrix_get_csr(F.A, NULL, NULL, NULL));
  ROW0(MFREE_ERR_NULL, mfree_matrix_get_csr_i32(NULL, &p32, &p32, &pv));
  ROW(MFREE_ERR_NULL, mfree_matrix_get_csr_i32(F.A, NULL, NULL, NULL));
  ROW0(MFREE_ERR_NULL, mfree_matrix_get_csr_i64(NULL, &p64, &q64, &pv));
  ROW(MFREE_ERR_NULL, mfree_matrix_get_csr_i64(F.A, NULL, NULL, NULL));
  ROW0(MFREE_ERR_NULL, mfree_matrix_get_csc(NULL, &p64, &p32, &pv));
  ROW(MFREE_ERR_NULL, mfree_matrix_get_csc(F.A, NULL, NULL, NULL));
  ROW0(MFREE_ERR_NULL, mfree_matrix_get_pattern_id(NULL, &i64));
  ROW(MFREE_ERR_NULL, mfree_matrix_get_pattern_id(F.A, NULL));
  ROW0(MFREE_ERR_NULL, mfree_matrix_get_symmetric(NULL, &i32));
  ROW(MFREE_ERR_NULL, mfree_matrix_get_symmetric(F.A, NULL));
  ROW0(MFREE_ERR_NULL, mfree_matrix_apply(NULL, x, y));
  ROW(MFREE_ERR_NULL, mfree_matrix_apply(F.A, NULL, y));
  ROW(MFREE_ERR_NULL, mfree_matrix_apply(F.A, x, NULL));
}

static void rows_assembler(void) {
  mfree_assembler_t *b = NULL, *null_as = NULL;
  mfree_matrix_t *K = NULL;
  const double lo[2] = {0, 0}, hi[2] = {1, 1}, hibad[2] = {0, 1};
  const int32_t nc[2] = {4, 4}, ncbad[2] = {0, 4};
  double px[4] = {0.5, 0.5, 0.4, 0.4}, pw[2] = {0.1, 0.1}, pwbad[2] = {0.1, -1.0};
  double nrm[4] = {1, 0, 1, 0}, seg[4] = {0, 0, 0, 1}, segzero[4] = {0, 0, 0, 0};
  double rhs[N];
  int32_t nodes[2] = {0, 1}, nodesbad[2] = {0, N}, i32, i32b;
  int32_t tri[3] = {0, 1, M};

  ROW0(MFREE_ERR_NULL, mfree_assembler_create(NULL, F.a, NULL, MFREE_FORM_LAPLACE, &b));
  ROW(MFREE_ERR_NULL, mfree_assembler_create(F.ctx, NULL, NULL, MFREE_FORM_LAPLACE, &b));
  ROW(MFREE_ERR_NULL, mfree_assembler_create(F.ctx, F.a, NULL, MFREE_FORM_LAPLACE, NULL));
  ROW(MFREE_ERR_ARG, mfree_assembler_create(F.ctx, F.a, NULL, (mfree_form_t)0, &b));
  ROW(MFREE_ERR_ARG, mfree_assembler_create(F.ctx, F.a, NULL, (mfree_form_t)10, &b));
  ROW(MFREE_ERR_MISMATCH, mfree_assembler_create(F.ctx, F.a, F.a3, MFREE_FORM_LAPLACE, &b));
  ROW(MFREE_ERR_MISMATCH, mfree_assembler_create(F.ctx, F.a, NULL, MFREE_FORM_ELASTICITY_3D, &b));
  ROW0(MFREE_SUCCESS, mfree_assembler_destroy(NULL));
  ROW0(MFREE_SUCCESS, mfree_assembler_destroy(&null_as));

  ROW0(MFREE_ERR_NULL, mfree_assembler_set_material(NULL, 1, 0.3));
  ROW(MFREE_ERR_ARG, mfree_assembler_set_material(F.as_new, 0.0, 0.3));
  ROW(MFREE_ERR_ARG, mfree_assembler_set_material(F.as_new, NAN, 0.3));
  ROW(MFREE_ERR_ARG, mfree_assembler_set_material(F.as_new, 1.0, 0.5));
  ROW(MFREE_ERR_ARG, mfree_assembler_set_material(F.as_new, 1.0, -1.0));
  ROW0(MFREE_ERR_NULL, mfree_assembler_set_coefficient(NULL, 1.0));
  ROW(MFREE_ERR_ARG, mfree_assembler_set_coefficient(F.as_new, NAN));
  ROW(MFREE_ERR_ARG, mfree_assembler_set_coefficient(F.as_new, INFINITY));
  ROW0(MFREE_ERR_NULL, mfree_assembler_set_quadrature_nodal(NULL));
  ROW0(MFREE_ERR_NULL, mfree_assembler_set_quadrature_cells(NULL, lo, hi, nc, 2, inside, NULL));
  ROW(MFREE_ERR_NULL, mfree_assembler_set_quadrature_cells(F.as_new, NULL, hi, nc, 2, inside, NULL));
  ROW(MFREE_ERR_NULL, mfree_assembler_set_quadrature_cells(F.as_new, lo, NULL, nc, 2, inside, NULL));
  ROW(MFREE_ERR_NULL, mfree_assembler_set_quadrature_cells(F.as_new, lo, hi, NULL, 2, inside, NULL));
  ROW(MFREE_ERR_ARG, mfree_assembler_set_quadrature_cells(F.as_new, lo, hi, ncbad, 2, inside, NULL));
  ROW(MFREE_ERR_ARG, mfree_assembler_set_quadrature_cells(F.as_new, lo, hi, nc, 0, inside, NULL));
  ROW(MFREE_ERR_INPUT, mfree_assembler_set_quadrature_cells(F.as_new, lo, hibad, nc, 2, inside, NULL));
  ROW0(MFREE_ERR_NULL, mfree_assembler_set_quadrature_points(NULL, 2, px, MFREE_LAYOUT_AOS, 2, pw));
  ROW(MFREE_ERR_ARG, mfree_assembler_set_quadrature_points(F.as_new, -2, px, MFREE_LAYOUT_AOS, 2, pw));
  ROW(MFREE_ERR_NULL, mfree_assembler_set_quadrature_points(F.as_new, 2, NULL, MFREE_LAYOUT_AOS, 2, pw));
  ROW(MFREE_ERR_NULL, mfree_assembler_set_quadrature_points(F.as_new, 2, px, MFREE_LAYOUT_AOS, 2, NULL));
  ROW(MFREE_ERR_ARG, mfree_assembler_set_quadrature_points(F.as_new, 2, px, MFREE_LAYOUT_AOS, 1, pw));
  ROW(MFREE_ERR_ARG, mfree_assembler_set_quadrature_points(F.as_new, 2, px, (mfree_layout_t)0, 2, pw));
  ROW(MFREE_ERR_INPUT, mfree_assembler_set_quadrature_points(F.as_new, 2, px, MFREE_LAYOUT_AOS, 2, pwbad));
  px[1] = NAN;
  ROW(MFREE_ERR_INPUT, mfree_assembler_set_quadrature_points(F.as_new, 2, px, MFREE_LAYOUT_AOS, 2, pw));
  px[1] = 0.5;
  ROW0(MFREE_ERR_NULL, mfree_assembler_set_body_force(NULL, host_field, NULL));

  ROW0(MFREE_ERR_NULL, mfree_assembler_add_traction(NULL, 2, px, MFREE_LAYOUT_AOS, 2, pw, host_field, NULL));
  ROW(MFREE_ERR_ARG, mfree_assembler_add_traction(F.as_new, -1, px, MFREE_LAYOUT_AOS, 2, pw, host_field, NULL));
  ROW(MFREE_ERR_NULL, mfree_assembler_add_traction(F.as_new, 2, NULL, MFREE_LAYOUT_AOS, 2, pw, host_field, NULL));
  ROW(MFREE_ERR_NULL, mfree_assembler_add_traction(F.as_new, 2, px, MFREE_LAYOUT_AOS, 2, NULL, host_field, NULL));
  ROW(MFREE_ERR_NULL, mfree_assembler_add_traction(F.as_new, 2, px, MFREE_LAYOUT_AOS, 2, pw, NULL, NULL));
  ROW(MFREE_ERR_ARG, mfree_assembler_add_traction(F.as_new, 2, px, MFREE_LAYOUT_SOA, 1, pw, host_field, NULL));
  ROW(MFREE_ERR_INPUT, mfree_assembler_add_traction(F.as_new, 2, px, MFREE_LAYOUT_AOS, 2, pwbad, host_field, NULL));
  ROW0(MFREE_ERR_NULL, mfree_assembler_add_traction_segments(NULL, 1, seg, 2, host_field, NULL));
  ROW(MFREE_ERR_ARG, mfree_assembler_add_traction_segments(F.as_new, -1, seg, 2, host_field, NULL));
  ROW(MFREE_ERR_NULL, mfree_assembler_add_traction_segments(F.as_new, 1, NULL, 2, host_field, NULL));
  ROW(MFREE_ERR_NULL, mfree_assembler_add_traction_segments(F.as_new, 1, seg, 2, NULL, NULL));
  ROW(MFREE_ERR_ARG, mfree_assembler_add_traction_segments(F.as_new, 1, seg, 0, host_field, NULL));
  ROW(MFREE_ERR_INPUT, mfree_assembler_add_traction_segments(F.as_new, 1, segzero, 2, host_field, NULL));
  { /* 3D facets: a 3D elasticity assembler on the 3D set */
    const double tri[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    const double trizero[9] = {0, 0, 0, 1, 1, 1, 2, 2, 2}, trinan[9] = {0, 0, 0, 1, 0, 0, 0, NAN, 0};
    mfree_assembler_t *as3 = NULL;
    ROW(MFREE_SUCCESS, mfree_assembler_create(F.ctx, F.a3, NULL, MFREE_FORM_ELASTICITY_3D, &as3));
    ROW0(MFREE_ERR_NULL, mfree_assembler_add_traction_facets(NULL, 1, tri, 2, host_field, NULL));
    ROW(MFREE_ERR_UNSUPPORTED, mfree_assembler_add_traction_facets(F.as_new, 1, tri, 2, host_field, NULL));
    ROW(MFREE_ERR_ARG, mfree_assembler_add_traction_facets(as3, -1, tri, 2, host_field, NULL));
    ROW(MFREE_ERR_NULL, mfree_assembler_add_traction_facets(as3, 1, NULL, 2, host_field, NULL));
    ROW(MFREE_ERR_NULL, mfree_assembler_add_traction_facets(as3, 1, tri, 2, NULL, NULL));
    ROW(MFREE_ERR_ARG, mfree_assembler_add_traction_facets(as3, 1, tri, 0, host_field, NULL));
    ROW(MFREE_ERR_ARG, mfree_assembler_add_traction_facets(as3, 1, tri, 21, host_field, NULL));
    ROW(MFREE_ERR_INPUT, mfree_assembler_add_traction_facets(as3, 1, trizero, 2, host_field, NULL));
    ROW(MFREE_ERR_INPUT, mfree_assembler_add_traction_facets(as3, 1, trinan, 2, host_field, NULL));
    mfree_assembler_destroy(&as3);
  }

  ROW0(MFREE_ERR_NULL, mfree_assembler_add_dirichlet(NULL, MFREE_BC_PENALTY, 2, px, MFREE_LAYOUT_AOS, 2, pw, NULL, 1, host_field, NULL));
  ROW(MFREE_ERR_ARG, mfree_assembler_add_dirichlet(F.as_new, (mfree_bc_t)0, 2, px, MFREE_LAYOUT_AOS, 2, pw, NULL, 1, host_field, NULL));
  ROW(MFREE_ERR_ARG, mfree_assembler_add_dirichlet(F.as_new, (mfree_bc_t)5, 2, px, MFREE_LAYOUT_AOS, 2, pw, NULL, 1, host_field, NULL));
  ROW(MFREE_ERR_ARG, mfree_assembler_add_dirichlet(F.as_new, MFREE_BC_PENALTY, -2, px, MFREE_LAYOUT_AOS, 2, pw, NULL, 1, host_field, NULL));
  ROW(MFREE_ERR_NULL, mfree_assembler_add_dirichlet(F.as_new, MFREE_BC_PENALTY, 2, NULL, MFREE_LAYOUT_AOS, 2, pw, NULL, 1, host_field, NULL));
  ROW(MFREE_ERR_NULL, mfree_assembler_add_dirichlet(F.as_new, MFREE_BC_PENALTY, 2, px, MFREE_LAYOUT_AOS, 2, NULL, NULL, 1, host_field, NULL));
  ROW(MFREE_ERR_NULL, mfree_assembler_add_dirichlet(F.as_new, MFREE_BC_NITSCHE, 2, px, MFREE_LAYOUT_AOS, 2, pw, NULL, 1, host_field, NULL));
  ROW(MFREE_ERR_ARG, mfree_assembler_add_dirichlet(F.as_new, MFREE_BC_PENALTY, 2, px, MFREE_LAYOUT_AOS, 0, pw, NULL, 1, host_field, NULL));
  ROW(MFREE_ERR_ARG, mfree_assembler_add_dirichlet(F.as_new, MFREE_BC_PENALTY, 2, px, MFREE_LAYOUT_AOS, 2, pw, NULL, 0, host_field, NULL));
  ROW(MFREE_ERR_ARG, mfree_assembler_add_dirichlet(F.as_new, MFREE_BC_PENALTY, 2, px, MFREE_LAYOUT_AOS, 2, pw, NULL, 4, host_field, NULL));
  ROW(MFREE_ERR_INPUT, mfree_assembler_add_dirichlet(F.as_new, MFREE_BC_PENALTY, 2, px, MFREE_LAYOUT_AOS, 2, pwbad, NULL, 1, host_field, NULL));
  ROW0(MFREE_ERR_NULL, mfree_assembler_add_dirichlet_nodes(NULL, 2, nodes, 1, host_field, NULL));
  ROW(MFREE_ERR_ARG, mfree_assembler_add_dirichlet_nodes(F.as_new, -1, nodes, 1, host_field, NULL));
  ROW(MFREE_ERR_NULL, mfree_assembler_add_dirichlet_nodes(F.as_new, 2, NULL, 1, host_field, NULL));
  ROW(MFREE_ERR_INPUT, mfree_assembler_add_dirichlet_nodes(F.as_new, 2, nodesbad, 1, host_field, NULL));
  ROW(MFREE_ERR_ARG, mfree_assembler_add_dirichlet_nodes(F.as_new, 2, nodes, 0, host_field, NULL));
  ROW0(MFREE_ERR_NULL, mfree_assembler_add_traction_nodes(NULL, 2, nodes, nrm, host_field, NULL));
  ROW(MFREE_ERR_UNSUPPORTED, mfree_assembler_add_traction_nodes(F.as_new, 2, nodes, nrm, host_field, NULL));
  {
    mfree_assembler_t *col = NULL; /* traction rows belong to collocation forms */
    assert_ok(F.ctx, mfree_assembler_create(F.ctx, F.a, NULL, MFREE_FORM_COLLOCATION_LAPLACE, &col));
    ROW(MFREE_ERR_ARG, mfree_assembler_add_traction_nodes(col, -1, nodes, nrm, host_field, NULL));
    ROW(MFREE_ERR_NULL, mfree_assembler_add_traction_nodes(col, 2, NULL, nrm, host_field, NULL));
    ROW(MFREE_ERR_NULL, mfree_assembler_add_traction_nodes(col, 2, nodes, NULL, host_field, NULL));
    ROW(MFREE_ERR_INPUT, mfree_assembler_add_traction_nodes(col, 2, nodesbad, nrm, host_field, NULL));
    mfree_assembler_destroy(&col);
  }
  ROW0(MFREE_ERR_NULL, mfree_assembler_set_fe_layer(NULL, 1, 3, tri, 1, nodes, 1, host_field, NULL));
  ROW(MFREE_ERR_ARG, mfree_assembler_set_fe_layer(F.as_new, -1, 3, tri, 1, nodes, 1, host_field, NULL));
  ROW(MFREE_ERR_ARG, mfree_assembler_set_fe_layer(F.as_new, 1, 5, tri, 1, nodes, 1, host_field, NULL));
  ROW(MFREE_ERR_NULL, mfree_assembler_set_fe_layer(F.as_new, 1, 3, NULL, 1, nodes, 1, host_field, NULL));
  ROW(MFREE_ERR_NULL, mfree_assembler_set_fe_layer(F.as_new, 1, 3, tri, 1, NULL, 1, host_field, NULL));
  ROW(MFREE_ERR_INPUT, mfree_assembler_set_fe_layer(F.as_new, 1, 3, tri, 1, nodesbad + 1, 1, host_field, NULL));
  {
    /* a set without positions: the layer's orientation check cannot read them */
    mfree_particles_t *bare = NULL;
    mfree_approximant_t *ab = NULL;
    mfree_assembler_t *asb = NULL;
    assert_ok(F.ctx, mfree_particles_create(F.ctx, 2, N, &bare));
    assert_ok(F.ctx, mfree_approximant_create(F.ctx, bare, MFREE_METHOD_RKPM, &ab));
    assert_ok(F.ctx, mfree_assembler_create(F.ctx, ab, NULL, MFREE_FORM_LAPLACE, &asb));
    ROWC(F.ctx, MFREE_ERR_STATE, mfree_assembler_set_fe_layer(asb, 1, 3, tri, 1, nodes, 1, host_field, NULL));
    mfree_assembler_destroy(&asb);
    mfree_approximant_destroy(&ab);
    mfree_particles_destroy(&bare);
  }
  ROW0(MFREE_ERR_NULL, mfree_assembler_set_penalty(NULL, 1e6));
  ROW(MFREE_ERR_ARG, mfree_assembler_set_penalty(F.as_new, -1.0));
  ROW(MFREE_ERR_ARG, mfree_assembler_set_penalty(F.as_new, NAN));
  {
    double nrmbad[4] = {1, 0, 0.5, 0}, pwnan[2] = {0.1, NAN};
    ROW0(MFREE_ERR_NULL, mfree_assembler_set_consistent_integration(NULL, 2, px, MFREE_LAYOUT_AOS, 2, pw, nrm));
    ROW(MFREE_ERR_ARG, mfree_assembler_set_consistent_integration(F.as_new, -1, px, MFREE_LAYOUT_AOS, 2, pw, nrm));
    ROW(MFREE_ERR_NULL, mfree_assembler_set_consistent_integration(F.as_new, 2, NULL, MFREE_LAYOUT_AOS, 2, pw, nrm));
    ROW(MFREE_ERR_NULL, mfree_assembler_set_consistent_integration(F.as_new, 2, px, MFREE_LAYOUT_AOS, 2, NULL, nrm));
    ROW(MFREE_ERR_NULL, mfree_assembler_set_consistent_integration(F.as_new, 2, px, MFREE_LAYOUT_AOS, 2, pw, NULL));
    ROW(MFREE_ERR_INPUT, mfree_assembler_set_consistent_integration(F.as_new, 2, px, MFREE_LAYOUT_AOS, 2, pwbad, nrm));
    ROW(MFREE_ERR_INPUT, mfree_assembler_set_consistent_integration(F.as_new, 2, px, MFREE_LAYOUT_AOS, 2, pwnan, nrm));
    ROW(MFREE_ERR_INPUT, mfree_assembler_set_consistent_integration(F.as_new, 2, px, MFREE_LAYOUT_AOS, 2, pw, nrmbad));
    ROW(MFREE_ERR_ARG, mfree_assembler_set_consistent_integration(F.as_new, 2, px, MFREE_LAYOUT_AOS, 1, pw, nrm));
    ROW(MFREE_ERR_ARG, mfree_assembler_set_consistent_integration(F.as_new, 2, px, (mfree_layout_t)7, 2, pw, nrm));
    mfree_assembler_t *mass = NULL; /* the correction is for stiffness forms only */
    assert_ok(F.ctx, mfree_assembler_create(F.ctx, F.a, NULL, MFREE_FORM_MASS, &mass));
    ROW(MFREE_ERR_UNSUPPORTED,
        mfree_assembler_set_consistent_integration(mass, 2, px, MFREE_LAYOUT_AOS, 2, pw, nrm));
    mfree_assembler_destroy(&mass);
  }

  ROW0(MFREE_ERR_NULL, mfree_assembler_setup(NULL));
  ROW0(MFREE_ERR_NULL, mfree_assembler_update(NULL));
  ROW(MFREE_ERR_STATE, mfree_assembler_update(F.as_new));
  ROW0(MFREE_ERR_NULL, mfree_assembler_get_size(NULL, &i32, &i32b));
  ROW(MFREE_ERR_STATE, mfree_assembler_get_size(F.as_new, &i32, &i32b));
  ROW0(MFREE_ERR_NULL, mfree_assembler_assemble_matrix(NULL, &K));
  ROW(MFREE_ERR_NULL, mfree_assembler_assemble_matrix(F.as, NULL));
  ROW(MFREE_ERR_STATE, mfree_assembler_assemble_matrix(F.as_new, &K));
  ROW0(MFREE_ERR_NULL, mfree_assembler_assemble_rhs(NULL, rhs));
  ROW(MFREE_ERR_NULL, mfree_assembler_assemble_rhs(F.as, NULL));
  ROW(MFREE_ERR_STATE, mfree_assembler_assemble_rhs(F.as_new, rhs));
  mfree_matrix_destroy(&K);
}

static void rows_system(void) {
  mfree_system_t *s = NULL, *null_sys = NULL;
  const double one = 1.0, zero = 0.0, g[2] = {0, -9.81}, gnan[2] = {0, NAN};
  const double lo[2] = {-1, -1}, hi[2] = {2, 2}, hibad[2] = {-2, 2};
  double wx[4] = {0, -0.1, 0.2, -0.1}, wn[4] = {0, 1, 0, 1}, wnbad[4] = {0, 0, 0, 1};
  double ydot[5 * N], p[N], yb[5 * N], t = 0.0, sig[3 * N];
  int32_t i32;
  int64_t steps;
  mfree_matrix_t *Mm = NULL;
  memcpy(yb, F.y, sizeof yb);
  yb[3] = NAN;

  ROW0(MFREE_ERR_NULL, mfree_system_create_fluid(NULL, 2, N, &s));
  ROW(MFREE_ERR_ARG, mfree_system_create_fluid(F.ctx, 0, N, &s));
  ROW(MFREE_ERR_ARG, mfree_system_create_fluid(F.ctx, 4, N, &s));
  ROW(MFREE_ERR_ARG, mfree_system_create_fluid(F.ctx, 2, -1, &s));
  ROW(MFREE_ERR_NULL, mfree_system_create_fluid(F.ctx, 2, N, NULL));
  ROW0(MFREE_SUCCESS, mfree_system_destroy(NULL));
  ROW0(MFREE_SUCCESS, mfree_system_destroy(&null_sys));

  ROW0(MFREE_ERR_NULL, mfree_system_set_fluid(NULL, &one, 0, 1, 7, 0));
  ROW(MFREE_ERR_NULL, mfree_system_set_fluid(F.sys, NULL, 0, 1, 7, 0));
  ROW(MFREE_ERR_ARG, mfree_system_set_fluid(F.sys, &one, -1, 1, 7, 0));
  ROW(MFREE_ERR_INPUT, mfree_system_set_fluid(F.sys, &zero, 0, 1, 7, 0));
  ROW(MFREE_ERR_ARG, mfree_system_set_fluid(F.sys, &one, 0, -1, 7, 0));
  ROW(MFREE_ERR_ARG, mfree_system_set_fluid(F.sys, &one, 0, 1, NAN, 0));
  ROW(MFREE_ERR_ARG, mfree_system_set_fluid(F.sys, &one, 0, 1, 7, -1));
  ROW0(MFREE_ERR_NULL, mfree_system_set_masses(NULL, &one, 0));
  ROW(MFREE_ERR_NULL, mfree_system_set_masses(F.sys, NULL, 0));
  ROW(MFREE_ERR_ARG, mfree_system_set_masses(F.sys, &one, -1));
  ROW(MFREE_ERR_INPUT, mfree_system_set_masses(F.sys, &zero, 0));
  ROW0(MFREE_ERR_NULL, mfree_system_set_smoothing(NULL, 1.0));
  ROW(MFREE_ERR_ARG, mfree_system_set_smoothing(F.sys, 0.0));
  ROW(MFREE_ERR_ARG, mfree_system_set_smoothing(F.sys, NAN));
  ROW0(MFREE_ERR_NULL, mfree_system_set_gravity(NULL, g));
  ROW(MFREE_ERR_NULL, mfree_system_set_gravity(F.sys, NULL));
  ROW(MFREE_ERR_INPUT, mfree_system_set_gravity(F.sys, gnan));
  ROW0(MFREE_ERR_NULL, mfree_system_set_lumping(NULL, MFREE_LUMP_GALERKIN));
  ROW(MFREE_ERR_ARG, mfree_system_set_lumping(F.sys, (mfree_lumping_t)0));
  ROW(MFREE_ERR_ARG, mfree_system_set_lumping(F.sys, (mfree_lumping_t)3));
  ROW0(MFREE_ERR_NULL, mfree_system_set_walls(NULL, 2, wx, wn, 0.1, 10));
  ROW(MFREE_ERR_ARG, mfree_system_set_walls(F.sys, -1, wx, wn, 0.1, 10));
  ROW(MFREE_ERR_NULL, mfree_system_set_walls(F.sys, 2, NULL, wn, 0.1, 10));
  ROW(MFREE_ERR_NULL, mfree_system_set_walls(F.sys, 2, wx, NULL, 0.1, 10));
  ROW(MFREE_ERR_INPUT, mfree_system_set_walls(F.sys, 2, wx, wnbad, 0.1, 10));
  ROW(MFREE_ERR_ARG, mfree_system_set_walls(F.sys, 2, wx, wn, -0.1, 10));
  ROW(MFREE_ERR_ARG, mfree_system_set_walls(F.sys, 2, wx, wn, 0.1, NAN));
#if MFREE_T060_SHEPARD_CONDITION
  ROW0(MFREE_ERR_NULL, mfree_system_set_shepard_condition(NULL, 100.0));
  ROW(MFREE_ERR_ARG, mfree_system_set_shepard_condition(F.sys, 0.5));
  ROW(MFREE_ERR_ARG, mfree_system_set_shepard_condition(F.sys, NAN));
#endif
  ROW0(MFREE_ERR_NULL, mfree_system_set_approximation(NULL, MFREE_METHOD_MLS, 1, MFREE_KERNEL_CUBIC_SPLINE, 0.0));
  ROW(MFREE_ERR_ARG, mfree_system_set_approximation(F.sys, (mfree_method_t)0, 1, MFREE_KERNEL_CUBIC_SPLINE, 0.0));
  ROW(MFREE_ERR_ARG, mfree_system_set_approximation(F.sys, (mfree_method_t)99, 1, MFREE_KERNEL_CUBIC_SPLINE, 0.0));
  ROW(MFREE_ERR_ARG, mfree_system_set_approximation(F.sys, MFREE_METHOD_MLS, 1, (mfree_kernel_t)0, 0.0));
  ROW(MFREE_ERR_ARG, mfree_system_set_approximation(F.sys, MFREE_METHOD_MLS, 1, (mfree_kernel_t)99, 0.0));
  ROW(MFREE_ERR_UNSUPPORTED, mfree_system_set_approximation(F.sys, MFREE_METHOD_MLS, 4, MFREE_KERNEL_CUBIC_SPLINE, 0.0));
  ROW(MFREE_ERR_UNSUPPORTED, mfree_system_set_approximation(F.sys, MFREE_METHOD_MLS, -1, MFREE_KERNEL_CUBIC_SPLINE, 0.0));
  ROW(MFREE_ERR_UNSUPPORTED, mfree_system_set_approximation(F.sys, MFREE_METHOD_RANDLES_LIBERSKY, 2, MFREE_KERNEL_CUBIC_SPLINE, 0.0));
  ROW(MFREE_ERR_UNSUPPORTED, mfree_system_set_approximation(F.sys, MFREE_METHOD_MPFEM, 1, MFREE_KERNEL_COSINE, 0.0));
  ROW(MFREE_ERR_UNSUPPORTED, mfree_system_set_approximation(F.sys, MFREE_METHOD_MLS, 1, MFREE_KERNEL_LINEAR, 0.0));
  /* dummy wall particles and density diffusion (failures change nothing) */
  ROW0(MFREE_ERR_NULL, mfree_system_set_dummy_particles(NULL, 2, wx, &one, 0));
  ROW(MFREE_ERR_ARG, mfree_system_set_dummy_particles(F.sys, -1, wx, &one, 0));
  ROW(MFREE_ERR_NULL, mfree_system_set_dummy_particles(F.sys, 2, NULL, &one, 0));
  ROW(MFREE_ERR_NULL, mfree_system_set_dummy_particles(F.sys, 2, wx, NULL, 0));
  ROW(MFREE_ERR_ARG, mfree_system_set_dummy_particles(F.sys, 2, wx, &one, -1));
  ROW(MFREE_ERR_INPUT, mfree_system_set_dummy_particles(F.sys, 2, wx, &zero, 0));
  ROW(MFREE_ERR_INPUT, mfree_system_set_dummy_particles(F.sys, 1, gnan, &one, 0));
  ROW0(MFREE_ERR_NULL, mfree_system_set_density_diffusion(NULL, 0.1));
  ROW(MFREE_ERR_ARG, mfree_system_set_density_diffusion(F.sys, -0.1));
  ROW(MFREE_ERR_ARG, mfree_system_set_density_diffusion(F.sys, NAN));
  ROW0(MFREE_ERR_NULL, mfree_system_set_consistent_integration(NULL, 1));
  ROW(MFREE_ERR_ARG, mfree_system_set_consistent_integration(F.sys, -1));
  ROW(MFREE_ERR_ARG, mfree_system_set_consistent_integration(F.sys, 2));
  ROW0(MFREE_ERR_NULL, mfree_system_set_velocity_smoothing(NULL, 0.1));
  ROW(MFREE_ERR_ARG, mfree_system_set_velocity_smoothing(F.sys, -0.1));
  ROW(MFREE_ERR_ARG, mfree_system_set_velocity_smoothing(F.sys, NAN));
  ROW(MFREE_ERR_ARG, mfree_system_set_velocity_smoothing(F.sys, INFINITY));
  ROW0(MFREE_ERR_NULL, mfree_system_set_lumped_mass_step(NULL, 1));
  ROW(MFREE_ERR_ARG, mfree_system_set_lumped_mass_step(F.sys, -1));
  ROW(MFREE_ERR_ARG, mfree_system_set_lumped_mass_step(F.sys, 2));
  ROW0(MFREE_ERR_NULL, mfree_system_set_acoustic_step(NULL, 1));
  ROW(MFREE_ERR_ARG, mfree_system_set_acoustic_step(F.sys, -1));
  ROW(MFREE_ERR_ARG, mfree_system_set_acoustic_step(F.sys, 2));
  ROW0(MFREE_ERR_NULL, mfree_system_set_box(NULL, lo, hi));
  ROW(MFREE_ERR_NULL, mfree_system_set_box(F.sys, NULL, hi));
  ROW(MFREE_ERR_NULL, mfree_system_set_box(F.sys, lo, NULL));
  ROW(MFREE_ERR_ARG, mfree_system_set_box(F.sys, lo, hibad));

  ROW0(MFREE_ERR_NULL, mfree_system_get_size(NULL, &i32));
  ROW(MFREE_ERR_NULL, mfree_system_get_size(F.sys, NULL));
  ROW0(MFREE_ERR_NULL, mfree_system_rhs(NULL, 0, F.y, ydot));
  ROW(MFREE_ERR_NULL, mfree_system_rhs(F.sys, 0, NULL, ydot));
  ROW(MFREE_ERR_NULL, mfree_system_rhs(F.sys, 0, F.y, NULL));
  ROW(MFREE_FAIL_NONFINITE, mfree_system_rhs(F.sys, 0, yb, ydot));
  ROW0(MFREE_ERR_NULL, mfree_system_assemble_mass(NULL, F.y, 0, &Mm));
  ROW(MFREE_ERR_NULL, mfree_system_assemble_mass(F.sys, NULL, 0, &Mm));
  ROW(MFREE_ERR_NULL, mfree_system_assemble_mass(F.sys, F.y, 0, NULL));
  ROW0(MFREE_ERR_NULL, mfree_system_assemble_interpolation(NULL, F.y, &Mm));
  ROW(MFREE_ERR_NULL, mfree_system_assemble_interpolation(F.sys, NULL, &Mm));
  ROW(MFREE_ERR_NULL, mfree_system_assemble_interpolation(F.sys, F.y, NULL));
  ROW0(MFREE_ERR_NULL, mfree_system_apply_mass(NULL, F.y, 1, F.y, ydot));
  ROW(MFREE_ERR_NULL, mfree_system_apply_mass(F.sys, NULL, 1, F.y, ydot));
  ROW(MFREE_ERR_NULL, mfree_system_apply_mass(F.sys, F.y, 1, NULL, ydot));
  ROW(MFREE_ERR_NULL, mfree_system_apply_mass(F.sys, F.y, 0, F.y, NULL));
  ROW(MFREE_FAIL_NONFINITE, mfree_system_apply_mass(F.sys, yb, 1, F.y, ydot));
  ROW0(MFREE_ERR_NULL, mfree_system_get_pressure(NULL, F.y, p));
  ROW(MFREE_ERR_NULL, mfree_system_get_pressure(F.sys, NULL, p));
  ROW(MFREE_ERR_NULL, mfree_system_get_pressure(F.sys, F.y, NULL));
  ROW0(MFREE_ERR_NULL, mfree_system_get_velocity(NULL, F.y, p));
  ROW(MFREE_ERR_NULL, mfree_system_get_velocity(F.sys, NULL, p));
  ROW(MFREE_ERR_NULL, mfree_system_get_velocity(F.sys, F.y, NULL));
  /* the fixture's fluid has no wall particles: per_wall must say 0 */
  ROW0(MFREE_ERR_NULL, mfree_system_get_wall_force(NULL, F.y, p, 0, NULL));
  ROW(MFREE_ERR_NULL, mfree_system_get_wall_force(F.sys, NULL, p, 0, NULL));
  ROW(MFREE_ERR_NULL, mfree_system_get_wall_force(F.sys, F.y, NULL, 0, NULL));
  ROW(MFREE_ERR_ARG, mfree_system_get_wall_force(F.sys, F.y, p, 2, sig));
  ROW(MFREE_ERR_ARG, mfree_system_get_wall_force(F.sys, F.y, NULL, -1, sig));
  ROW(MFREE_FAIL_NONFINITE, mfree_system_get_wall_force(F.sys, yb, p, 0, NULL));
  ROW0(MFREE_ERR_NULL, mfree_system_integrate(NULL, MFREE_INTEGRATOR_LEAPFROG, yb, &t, 1e-3, 0.2, 0, NULL, NULL, &steps));
  ROW(MFREE_ERR_ARG, mfree_system_integrate(F.sys, (mfree_integrator_t)0, yb, &t, 1e-3, 0.2, 0, NULL, NULL, &steps));
  ROW(MFREE_ERR_NULL, mfree_system_integrate(F.sys, MFREE_INTEGRATOR_LEAPFROG, NULL, &t, 1e-3, 0.2, 0, NULL, NULL, &steps));
  ROW(MFREE_ERR_NULL, mfree_system_integrate(F.sys, MFREE_INTEGRATOR_LEAPFROG, yb, NULL, 1e-3, 0.2, 0, NULL, NULL, &steps));
  ROW(MFREE_ERR_ARG, mfree_system_integrate(F.sys, MFREE_INTEGRATOR_LEAPFROG, yb, &t, NAN, 0.2, 0, NULL, NULL, &steps));
  ROW(MFREE_ERR_ARG, mfree_system_integrate(F.sys, MFREE_INTEGRATOR_LEAPFROG, yb, &t, 1e-3, 0.0, 0.0, NULL, NULL, &steps));
  ROW(MFREE_ERR_ARG, mfree_system_integrate(F.sys, MFREE_INTEGRATOR_LEAPFROG, yb, &t, 1e-3, 0.2, -1.0, NULL, NULL, &steps));
  ROW(MFREE_FAIL_NONFINITE, mfree_system_integrate(F.sys, MFREE_INTEGRATOR_LEAPFROG, yb, &t, 1e-3, 0.2, 0, NULL, NULL, &steps));
  /* open boundaries: the fixture's fluid has no gate or outflow (failures create none) */
  {
    const double go[2] = {0.0, 0.0}, ge[2] = {0.0, 1.0}, gn[2] = {1.0, 0.0}, gbad[2] = {0.6, 0.6};
    const double gnan[2] = {NAN, 0.0};
    int32_t states[N + 1];
    int64_t cnt = 0;
    double gm = 0.0;
    ROW0(MFREE_ERR_NULL, mfree_system_set_active(NULL, 1));
    ROW(MFREE_ERR_ARG, mfree_system_set_active(F.sys, -1));
    ROW(MFREE_ERR_ARG, mfree_system_set_active(F.sys, N + 1));
    ROW0(MFREE_ERR_NULL, mfree_system_set_inflow(NULL, 0, go, ge, gn, 1.0, 1000.0, 0.1));
    ROW(MFREE_ERR_NULL, mfree_system_set_inflow(F.sys, 0, NULL, ge, gn, 1.0, 1000.0, 0.1));
    ROW(MFREE_ERR_NULL, mfree_system_set_inflow(F.sys, 0, go, NULL, gn, 1.0, 1000.0, 0.1));
    ROW(MFREE_ERR_NULL, mfree_system_set_inflow(F.sys, 0, go, ge, NULL, 1.0, 1000.0, 0.1));
    ROW(MFREE_ERR_ARG, mfree_system_set_inflow(F.sys, 1, go, ge, gn, 1.0, 1000.0, 0.1));
    ROW(MFREE_ERR_ARG, mfree_system_set_inflow(F.sys, -1, go, ge, gn, 1.0, 1000.0, 0.1));
    ROW(MFREE_ERR_ARG, mfree_system_set_inflow(F.sys, 0, go, ge, gbad, 1.0, 1000.0, 0.1));
    ROW(MFREE_ERR_ARG, mfree_system_set_inflow(F.sys, 0, go, gn, gn, 1.0, 1000.0, 0.1));
    ROW(MFREE_ERR_ARG, mfree_system_set_inflow(F.sys, 0, go, ge, gn, 1.0, 1000.0, 3.0));
    ROW(MFREE_ERR_ARG, mfree_system_set_inflow(F.sys, 0, go, ge, gn, 0.0, 1000.0, 0.1));
    ROW(MFREE_ERR_ARG, mfree_system_set_inflow(F.sys, 0, go, ge, gn, 1.0, NAN, 0.1));
    ROW(MFREE_ERR_ARG, mfree_system_set_inflow(F.sys, 0, go, ge, gn, 1.0, 1000.0, INFINITY));
    ROW(MFREE_ERR_INPUT, mfree_system_set_inflow(F.sys, 0, gnan, ge, gn, 1.0, 1000.0, 0.1));
    ROW0(MFREE_ERR_NULL, mfree_system_set_outflow(NULL, 0, go, gn));
    ROW(MFREE_ERR_NULL, mfree_system_set_outflow(F.sys, 0, NULL, gn));
    ROW(MFREE_ERR_NULL, mfree_system_set_outflow(F.sys, 0, go, NULL));
    ROW(MFREE_ERR_ARG, mfree_system_set_outflow(F.sys, 1, go, gn));
    ROW(MFREE_ERR_ARG, mfree_system_set_outflow(F.sys, 0, go, gbad));
    ROW(MFREE_ERR_INPUT, mfree_system_set_outflow(F.sys, 0, gnan, gn));
    ROW0(MFREE_ERR_NULL, mfree_system_update_open_boundaries(NULL, 0.0, yb));
    ROW(MFREE_ERR_NULL, mfree_system_update_open_boundaries(F.sys, 0.0, NULL));
    ROW(MFREE_ERR_ARG, mfree_system_update_open_boundaries(F.sys, NAN, yb));
    ROW0(MFREE_ERR_NULL, mfree_system_get_active(NULL, &i32, N, states));
    ROW(MFREE_ERR_NULL, mfree_system_get_active(F.sys, NULL, N, states));
    ROW(MFREE_ERR_ARG, mfree_system_get_active(F.sys, &i32, N + 1, states));
    ROW0(MFREE_ERR_NULL, mfree_system_get_inflow(NULL, 0, &cnt, &gm));
    ROW(MFREE_ERR_ARG, mfree_system_get_inflow(F.sys, 0, &cnt, &gm));
    ROW0(MFREE_ERR_NULL, mfree_system_get_outflow(NULL, 0, &cnt, &gm));
    ROW(MFREE_ERR_ARG, mfree_system_get_outflow(F.sys, 0, &cnt, &gm));
  }

  ROW0(MFREE_ERR_NULL, mfree_system_create_elastodynamic(NULL, F.as, 1.0, &s));
  ROW(MFREE_ERR_NULL, mfree_system_create_elastodynamic(F.ctx, NULL, 1.0, &s));
  ROW(MFREE_ERR_NULL, mfree_system_create_elastodynamic(F.ctx, F.as, 1.0, NULL));
  ROW(MFREE_ERR_UNSUPPORTED, mfree_system_create_elastodynamic(F.ctx, F.as, 1.0, &s));
  ROW0(MFREE_ERR_NULL, mfree_system_create_elastodynamic_ranks(NULL, F.as, 1.0, one_exchange, one_allgather, NULL, &s));
  ROW(MFREE_ERR_NULL, mfree_system_create_elastodynamic_ranks(F.ctx, NULL, 1.0, one_exchange, one_allgather, NULL, &s));
  ROW(MFREE_ERR_NULL, mfree_system_create_elastodynamic_ranks(F.ctx, F.as, 1.0, one_exchange, one_allgather, NULL, NULL));
  ROW(MFREE_ERR_NULL, mfree_system_create_elastodynamic_ranks(F.ctx, F.as, 1.0, NULL, one_allgather, NULL, &s));
  ROW(MFREE_ERR_NULL, mfree_system_create_elastodynamic_ranks(F.ctx, F.as, 1.0, one_exchange, NULL, NULL, &s));
  /* a Galerkin assembler on nodal quadrature */
  ROW(MFREE_ERR_UNSUPPORTED, mfree_system_create_elastodynamic_ranks(F.ctx, F.as, 1.0, one_exchange, one_allgather, NULL, &s));
  {
    /* the fluid on ranks (one rank: the callbacks of one process) */
    const int64_t ids[3] = {4, 2, 9}, twice[3] = {4, 2, 4}, negative[3] = {4, -1, 9};
    double ys[10] = {0.0, 0.0, 0.1, 0.0, 0, 0, 0, 0, 1000, 1000}, yd[10], tf = 0.0;
    mfree_system_t *fr = NULL;
    mfree_matrix_t *fm = NULL;
    ROW0(MFREE_ERR_NULL, mfree_system_create_fluid_ranks(NULL, 2, 2, 1, ids, 1.0, one_exchange, one_allgather, NULL, &s));
    ROW(MFREE_ERR_NULL, mfree_system_create_fluid_ranks(F.ctx, 2, 2, 1, ids, 1.0, one_exchange, one_allgather, NULL, NULL));
    ROW(MFREE_ERR_NULL, mfree_system_create_fluid_ranks(F.ctx, 2, 2, 1, ids, 1.0, NULL, one_allgather, NULL, &s));
    ROW(MFREE_ERR_NULL, mfree_system_create_fluid_ranks(F.ctx, 2, 2, 1, ids, 1.0, one_exchange, NULL, NULL, &s));
    ROW(MFREE_ERR_NULL, mfree_system_create_fluid_ranks(F.ctx, 2, 2, 1, NULL, 1.0, one_exchange, one_allgather, NULL, &s));
    ROW(MFREE_ERR_ARG, mfree_system_create_fluid_ranks(F.ctx, 4, 2, 1, ids, 1.0, one_exchange, one_allgather, NULL, &s));
    ROW(MFREE_ERR_ARG, mfree_system_create_fluid_ranks(F.ctx, 2, -1, 1, ids, 1.0, one_exchange, one_allgather, NULL, &s));
    ROW(MFREE_ERR_ARG, mfree_system_create_fluid_ranks(F.ctx, 2, 2, -1, ids, 1.0, one_exchange, one_allgather, NULL, &s));
    ROW(MFREE_ERR_ARG, mfree_system_create_fluid_ranks(F.ctx, 2, 2, 1, ids, 0.0, one_exchange, one_allgather, NULL, &s));
    ROW(MFREE_ERR_ARG, mfree_system_create_fluid_ranks(F.ctx, 2, 2, 1, ids, NAN, one_exchange, one_allgather, NULL, &s));
    ROW(MFREE_ERR_INPUT, mfree_system_create_fluid_ranks(F.ctx, 2, 2, 1, twice, 1.0, one_exchange, one_allgather, NULL, &s));
    ROW(MFREE_ERR_INPUT, mfree_system_create_fluid_ranks(F.ctx, 2, 2, 1, negative, 1.0, one_exchange, one_allgather, NULL, &s));
    ROW(MFREE_SUCCESS, mfree_system_create_fluid_ranks(F.ctx, 2, 2, 0, ids, 1.0, one_exchange, one_allgather, NULL, &fr));
    if (fr) {
      const double m2[2] = {10.0, 10.0};
      ROW(MFREE_SUCCESS, mfree_system_set_masses(fr, m2, 1));
      ROW(MFREE_SUCCESS, mfree_system_set_smoothing(fr, 0.1));
      /* the outputs on ranks: NULL arguments agreed by the ranks; the consistent mass as products only */
      ROW(MFREE_ERR_NULL, mfree_system_get_pressure(fr, ys, NULL));
      ROW(MFREE_ERR_NULL, mfree_system_get_velocity(fr, NULL, yd));
      ROW(MFREE_ERR_NULL, mfree_system_get_velocity(fr, ys, NULL));
      ROW(MFREE_ERR_NULL, mfree_system_get_wall_force(fr, NULL, yd, 0, NULL));
      ROW(MFREE_ERR_NULL, mfree_system_get_wall_force(fr, ys, NULL, 0, NULL));
      ROW(MFREE_ERR_NULL, mfree_system_assemble_mass(fr, NULL, 0, &fm));
      ROW(MFREE_ERR_ARG, mfree_system_get_wall_force(fr, ys, yd, 1, yd));
      ROW(MFREE_ERR_UNSUPPORTED, mfree_system_assemble_mass(fr, ys, 1, &fm));
      /* ghosts rebuilt and particles moved */
      ROW0(MFREE_ERR_NULL, mfree_system_set_halo_rebuild(NULL, one_rebuild));
      ROW(MFREE_ERR_UNSUPPORTED, mfree_system_set_halo_rebuild(F.sys, one_rebuild));
      ROW0(MFREE_ERR_NULL, mfree_system_move_particles(NULL, 2, one_move, NULL, ys, 10));
      ROW(MFREE_ERR_UNSUPPORTED, mfree_system_move_particles(F.sys, 2, one_move, NULL, ys, 10));
      ROW(MFREE_ERR_STATE, mfree_system_move_particles(fr, 2, one_move, NULL, ys, 10)); /* no rebuild callback */
      ROW(MFREE_SUCCESS, mfree_system_set_halo_rebuild(fr, one_rebuild));
      ROW(MFREE_ERR_ARG, mfree_system_move_particles(fr, -1, one_move, NULL, ys, 10));
      ROW(MFREE_ERR_ARG, mfree_system_move_particles(fr, 2, one_move, NULL, ys, 9));
      ROW(MFREE_ERR_NULL, mfree_system_move_particles(fr, 2, NULL, NULL, ys, 10));
      ROW(MFREE_ERR_NULL, mfree_system_move_particles(fr, 2, one_move, NULL, NULL, 10));
      ROW(MFREE_ERR_INTERNAL, mfree_system_move_particles(fr, 2, bad_move, NULL, ys, 10));
      ROW(MFREE_SUCCESS, mfree_system_move_particles(fr, 2, one_move, NULL, ys, 10));
      ROW(MFREE_SUCCESS, mfree_system_rhs(fr, 0.0, ys, yd));
      ROW(MFREE_ERR_NULL, mfree_system_assemble_interpolation(fr, NULL, &fm));
      ROW(MFREE_SUCCESS, mfree_system_assemble_interpolation(fr, ys, &fm));
      ROW(MFREE_ERR_NULL, mfree_system_apply_mass(fr, NULL, 1, ys, yd));
      ROW(MFREE_ERR_NULL, mfree_system_apply_mass(fr, ys, 1, NULL, yd));
      ROW(MFREE_ERR_NULL, mfree_system_apply_mass(fr, ys, 0, ys, NULL));
      ROW(MFREE_SUCCESS, mfree_system_apply_mass(fr, ys, 1, ys, yd));
      /* a fault made pending (as the Fortran wrappers' size checks do): the next collective call
         returns it, its arrays unread (NULL here), once */
      ROW0(MFREE_ERR_NULL, mfree_system_set_pending_error(NULL, MFREE_ERR_ARG, "x"));
      ROW(MFREE_ERR_ARG, mfree_system_set_pending_error(fr, MFREE_FAIL_NONFINITE, "x"));
      ROW(MFREE_ERR_ARG, mfree_system_set_pending_error(fr, (mfree_status_t)-50, "x"));
      ROW(MFREE_SUCCESS, mfree_system_set_pending_error(fr, MFREE_ERR_ARG, "mfree_host: ydot holds 3 elements"));
      ROW(MFREE_ERR_ARG, mfree_system_rhs(fr, 0.0, NULL, NULL));
      ROW(MFREE_SUCCESS, mfree_system_rhs(fr, 0.0, ys, yd));
      ROW(MFREE_SUCCESS, mfree_system_set_pending_error(fr, MFREE_ERR_MISMATCH, NULL));
      ROW(MFREE_ERR_MISMATCH, mfree_system_integrate(fr, MFREE_INTEGRATOR_LEAPFROG, NULL, NULL, 1e-3, 0.2, 0, NULL,
                                                     NULL, &steps));
      ROW(MFREE_SUCCESS, mfree_system_set_pending_error(fr, MFREE_ERR_ARG, NULL));
      ROW(MFREE_SUCCESS, mfree_system_set_pending_error(fr, MFREE_SUCCESS, NULL));
      ROW(MFREE_SUCCESS, mfree_system_rhs(fr, 0.0, ys, yd));
      ROW(MFREE_ERR_ARG, mfree_system_integrate(fr, (mfree_integrator_t)0, ys, &tf, 1e-3, 0.2, 0, NULL, NULL, &steps));
      ROW(MFREE_ERR_ARG, mfree_system_integrate(fr, MFREE_INTEGRATOR_LEAPFROG, ys, &tf, NAN, 0.2, 0, NULL, NULL, &steps));
      ys[7] = NAN;
      ROW(MFREE_FAIL_NONFINITE, mfree_system_rhs(fr, 0.0, ys, yd));
      ROW(MFREE_FAIL_NONFINITE, mfree_system_apply_mass(fr, ys, 1, ys, yd));
      ROW(MFREE_FAIL_NONFINITE, mfree_system_integrate(fr, MFREE_INTEGRATOR_LEAPFROG, ys, &tf, 1e-3, 0.2, 0, NULL, NULL, &steps));
      ROW(MFREE_FAIL_NONFINITE, mfree_system_integrate(fr, MFREE_INTEGRATOR_PREDICTOR_CORRECTOR, ys, &tf, 1e-3, 0.2, 0, NULL, NULL, &steps));
      /* a failed rebuild leaves the system unusable */
      ROW(MFREE_SUCCESS, mfree_system_set_halo_rebuild(fr, bad_rebuild));
      ROW(MFREE_ERR_INTERNAL, mfree_system_move_particles(fr, 2, one_move, NULL, ys, 10));
      ROW(MFREE_ERR_STATE, mfree_system_rhs(fr, 0.0, ys, yd));
      ROW(MFREE_ERR_STATE, mfree_system_move_particles(fr, 2, one_move, NULL, ys, 10));
      mfree_system_destroy(&fr);
    }
    mfree_matrix_destroy(&fm);
  }
#if MFREE_T060_GALERKIN_ELASTODYNAMICS
  {
    mfree_assembler_t *mass = NULL;
    assert_ok(F.ctx, mfree_assembler_create(F.ctx, F.a, NULL, MFREE_FORM_MASS_LUMPED, &mass));
    ROW0(MFREE_ERR_NULL, mfree_system_create_elastodynamic_galerkin(NULL, F.as, mass, &s));
    ROW(MFREE_ERR_NULL, mfree_system_create_elastodynamic_galerkin(F.ctx, NULL, mass, &s));
    ROW(MFREE_ERR_NULL, mfree_system_create_elastodynamic_galerkin(F.ctx, F.as, NULL, &s));
    ROW(MFREE_ERR_NULL, mfree_system_create_elastodynamic_galerkin(F.ctx, F.as, mass, NULL));
    /* the mass assembler is not set up */
    ROW(MFREE_ERR_STATE, mfree_system_create_elastodynamic_galerkin(F.ctx, F.as, mass, &s));
    mfree_assembler_destroy(&mass);
  }
#endif
  ROW0(MFREE_ERR_NULL, mfree_system_set_load_history(NULL, history, NULL));
  ROW(MFREE_ERR_UNSUPPORTED, mfree_system_set_load_history(F.sys, history, NULL));
  ROW0(MFREE_ERR_NULL, mfree_system_get_stress(NULL, 0.0, F.y, sig));
  ROW(MFREE_ERR_UNSUPPORTED, mfree_system_get_stress(F.sys, 0.0, F.y, sig));
  mfree_matrix_destroy(&Mm);
}

/* Names of the MFREE_API functions declared in the header. */
static int header_functions(const char *path, char names[][96], int max) {
  FILE *f = fopen(path, "r");
  if (!f) return -1;
  static char text[1 << 20];
  size_t len = fread(text, 1, sizeof text - 1, f);
  fclose(f);
  text[len] = '\0';
  int count = 0;
  for (char *p = strstr(text, "MFREE_API "); p && count < max; p = strstr(p + 1, "MFREE_API ")) {
    if (p > text && p[-1] != '\n') continue; /* the macro's own definition */
    char *paren = strchr(p, '(');
    if (!paren) break;
    char *e = paren;
    while (e > p && e[-1] == ' ') --e;
    char *b = e;
    while (b > p && (b[-1] == '_' || (b[-1] >= 'a' && b[-1] <= 'z') || (b[-1] >= '0' && b[-1] <= '9')))
      --b;
    size_t n = (size_t)(e - b);
    if (n == 0 || n >= 96) continue;
    memcpy(names[count], b, n);
    names[count][n] = '\0';
    ++count;
  }
  return count;
}

static void test_bad_input_matrix(void **state) {
  (void)state;
  memset(&F, 0, sizeof F);
  assert_int_equal(make_fixture(), MFREE_SUCCESS);
  assert_null(health(1));

  /* Everything the library might print goes to a file while the rows run. */
  fflush(stdout);
  fflush(stderr);
  FILE *sink = tmpfile();
  assert_non_null(sink);
  const int out_fd = dup(1), err_fd = dup(2);
  assert_true(out_fd >= 0 && err_fd >= 0);
  dup2(fileno(sink), 1);
  dup2(fileno(sink), 2);

  rows_version_context();
  rows_kernels();
  rows_particles();
#if MFREE_T060_MESH
  rows_mesh();
#endif
  rows_approximant();
  rows_matrix();
  rows_assembler();
  rows_system();
  rows_pairs();

  fflush(stdout);
  fflush(stderr);
  dup2(out_fd, 1);
  dup2(err_fd, 2);
  close(out_fd);
  close(err_fd);
  fseek(sink, 0, SEEK_END);
  const long printed = ftell(sink);
  char head[512] = "";
  if (printed > 0) {
    rewind(sink);
    size_t k = fread(head, 1, sizeof head - 1, sink);
    head[k] = '\0';
  }
  fclose(sink);

  /* the failures recorded on ctx never reached the other context */
  mfree_status_t code2 = MFREE_ERR_INTERNAL;
  assert_ok(F.ctx2, mfree_context_get_last_error(F.ctx2, &code2, NULL, 0));
  assert_int_equal(code2, MFREE_SUCCESS);

  /* the two functions without a bad argument */
  const char *v = mfree_version_string();
  assert_true(v && v[0]);
  assert_true(mfree_status_string((mfree_status_t)12345) != NULL);
  assert_true(mfree_status_string((mfree_status_t)-12345) != NULL);

  print_message("%d rows, %d findings\n", F.rows, F.failures);
  if (F.failures) {
    print_message("bad-input matrix findings:\n");
    for (const char *p = F.log; *p;) { /* line by line: cmocka truncates long messages */
      const char *e = strchr(p, '\n');
      const int len = e ? (int)(e - p) : (int)strlen(p);
      print_message("%.*s\n", len, p);
      p += len + (e != NULL);
    }
    fail_msg("%d findings in the bad-input matrix (listed above)", F.failures);
  }
  if (printed > 0) fail_msg("mfree printed %ld bytes while the rows ran:\n%s", printed, head);

  /* every public function has rows */
  static char names[MAXFN][96];
  const int n = header_functions(MFREE_PUBLIC_HEADER, names, MAXFN);
  assert_true(n > 50);
  char missing[4096] = "";
  for (int i = 0; i < n; ++i) {
    int found = 0;
    for (int k = 0; k < F.ncovered && !found; ++k) found = strcmp(names[i], F.covered[k]) == 0;
    if (!found && strlen(missing) + strlen(names[i]) + 4 < sizeof missing) {
      strcat(missing, "\n  ");
      strcat(missing, names[i]);
    }
  }
  if (missing[0]) fail_msg("public functions without bad-input rows in %s:%s", __FILE__, missing);

  mfree_system_destroy(&F.sys);
  mfree_assembler_destroy(&F.as_new);
  mfree_assembler_destroy(&F.as);
  mfree_matrix_destroy(&F.A);
  mfree_approximant_destroy(&F.am);
#if MFREE_T060_MESH
  mfree_mesh_destroy(&F.mesh);
#endif
  mfree_approximant_destroy(&F.a_new);
  mfree_approximant_destroy(&F.a);
  mfree_approximant_destroy(&F.a3);
  mfree_particles_destroy(&F.ps3);
  mfree_particles_destroy(&F.psm);
  mfree_particles_destroy(&F.fresh);
  mfree_particles_destroy(&F.ps);
  mfree_context_destroy(&F.ctx2);
  mfree_context_destroy(&F.ctx);
}

/* The error handler sees every recorded failure, and a failure of one context leaves
 * another untouched. */
static void test_handler_and_isolation(void **state) {
  (void)state;
  mfree_context_t *c1 = NULL, *c2 = NULL;
  int calls = 0;
  assert_ok(NULL, mfree_context_create(&c1));
  assert_ok(NULL, mfree_context_create(&c2));
  assert_ok(c1, mfree_context_set_error_handler(c1, handler, &calls));
  mfree_particles_t *p = NULL;
  assert_error(c1, mfree_particles_create(c1, 7, 3, &p), MFREE_ERR_ARG, NULL);
  assert_int_equal(calls, 1);
  mfree_status_t code = MFREE_ERR_INTERNAL;
  char msg[64] = "x";
  assert_ok(c2, mfree_context_get_last_error(c2, &code, msg, sizeof msg));
  assert_int_equal(code, MFREE_SUCCESS);
  assert_string_equal(msg, "");
  /* a one-byte buffer gets the terminator only */
  assert_ok(c1, mfree_context_get_last_error(c1, &code, msg, 1));
  assert_string_equal(msg, "");
  mfree_context_destroy(&c1);
  mfree_context_destroy(&c2);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_bad_input_matrix),
      cmocka_unit_test(test_handler_and_isolation),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
