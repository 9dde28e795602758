/* The seven schemes of paper 000 Sect. 6.2 on mfree's assembler: one run = assemble,
 * impose the essential conditions, solve with UMFPACK (libmfree_suitesparse) and
 * measure the errors 000 eqs 114-119 (see es.h). */
#define _POSIX_C_SOURCE 200809L /* clock_gettime */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#ifdef ES_HAVE_SUITESPARSE
#include <mfree_suitesparse.h>
#endif

#include "es.h"

/* 000 Sect. 6.2, cases 1-7. Cases 1-3, 6, 7 are Bubnov-Galerkin; 4 and 5 Petrov-Galerkin
 * with Shepard test functions (000 Sect. 5.2.1); nodal quadrature except EFG. */
const es_scheme_t es_schemes[ES_NSCHEMES] = {
    {"SPH", MFREE_METHOD_SPH_SYMMETRIC, 0, (mfree_method_t)0, 0, 1},
    {"JB", MFREE_METHOD_JOHNSON_BEISSEL, 0, (mfree_method_t)0, 0, 1},
    {"RL", MFREE_METHOD_RANDLES_LIBERSKY, 0, (mfree_method_t)0, 0, 1},
    {"CD1", MFREE_METHOD_KB_METHOD1, 0, MFREE_METHOD_SHEPARD, 0, 0},
    {"CD2", MFREE_METHOD_KB_METHOD2, 1, MFREE_METHOD_SHEPARD, 0, 0},
    {"MLS", MFREE_METHOD_MLS, 1, (mfree_method_t)0, 0, 0},
    {"EFG", MFREE_METHOD_MLS, 1, (mfree_method_t)0, 1, 0},
};

static const char *const kBcNames[] = {"auto",     "direct",   "rows",     "nitsche", "penalty",  "lagrange",
                                       "fe-layer", "fe-nodal", "fe-gauss", "columns", "columns2"};

const char *es_bc_name(es_bc_t bc) {
  return (int)bc >= 0 && (int)bc <= ES_BC_COLUMNS2 ? kBcNames[bc] : "?";
}

int es_bc_parse(const char *s, es_bc_t *bc) {
  for (int k = 0; k <= ES_BC_COLUMNS2; ++k)
    if (strcmp(s, kBcNames[k]) == 0) {
      *bc = (es_bc_t)k;
      return 0;
    }
  return 1;
}

/* Essential conditions. The paper imposed u = g through a row of linear finite elements
 * blended into the meshfree functions (000 Sect. 5.2.4): mfree_assembler_set_fe_layer
 * (ES_BC_FE_LAYER), used for every scheme where it applies. It takes one component mask
 * for the whole layer, so the plate with a hole (u_y = 0 on y = 0, u_x = 0 on x = 0)
 * cannot use it; there the nodal-quadrature schemes get the example's own build of the
 * same layer as nodal quadrature sees it (ES_BC_FE_NODAL, equal to mfree's to round-off
 * on the beam) and EFG gets symmetric Nitsche, consistent like the layer.
 * The other options, measured for the report (--bc):
 *  - direct: u_J = g(x_J) on the parameters, meshfree derivatives everywhere. Natural for
 *    SPH, JB, RL, CD1 (their gradients act on nodal values) but the test functions of
 *    the inner nodes do not vanish on Gamma_u, which leaves an O(1/h) residual there.
 *  - rows (mfree_assembler_add_dirichlet_nodes): u^h(x_J) = g(x_J) with the trial values,
 *    which are Shepard functions for KB Method 1: not linearly complete, so even a linear
 *    field is not imposed exactly; for SPH, JB and RL mfree imposes u_J = g(x_J) on the
 *    particle values (the same as direct).
 *  - nitsche: not available for SPH, JB, RL (no functions between the particles); with
 *    Shepard test functions (CD1, CD2) it leaves a rigid rotation of the clamped end.
 *  - penalty, lagrange: on boundary Gauss points / at the boundary nodes. */
es_bc_t es_bc_resolve(const es_scheme_t *s, const es_level_t *lv, es_bc_t bc) {
  (void)s;
  if (bc != ES_BC_AUTO) return bc;
  return lv->nchain > 0 ? ES_BC_FE_LAYER : ES_BC_DIRECT;
}

double es_rate(int n, const double *dx, const double *e) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (int k = 0; k < n; ++k) {
    const double x = log(dx[k]), y = log(e[k]);
    sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

/* ------------------------------------------------------------------------------------ */
/* Boundary data                                                                          */
/* ------------------------------------------------------------------------------------ */

static void g_exact(void *user, const double *x, double *v) { es_exact(user, x, v, NULL, NULL); }

typedef struct {
  const es_problem_t *p;
  double n[2];
} traction_t;

static void t_exact(void *user, const double *x, double *v) {
  const traction_t *t = user;
  double s[3];
  es_exact(t->p, x, NULL, NULL, s);
  v[0] = s[0] * t->n[0] + s[2] * t->n[1];
  v[1] = s[2] * t->n[0] + s[1] * t->n[1];
}

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* ------------------------------------------------------------------------------------ */
/* Nodal-quadrature stiffness from the approximants' tables                               */
/* ------------------------------------------------------------------------------------ */

/* Gradient tables at the particles: row = quadrature particle I, columns = neighbours.
 * gn: derivatives for the normal strains, gs: for the shear strain (the same table except
 * for the paper's JB, whose shear keeps the symmetrised SPH derivatives). */
typedef struct {
  int64_t *rp;
  int32_t *ci;
  double *gn[2], *gs[2];
} tables_t;

static void tables_free(tables_t *t) {
  free(t->rp), free(t->ci);
  for (int c = 0; c < 2; ++c) {
    if (t->gs[c] != t->gn[c]) free(t->gs[c]);
    free(t->gn[c]);
  }
  memset(t, 0, sizeof *t);
}

static mfree_status_t table_read(mfree_approximant_t *a, int32_t n, int64_t **rp, int32_t **ci,
                                 double **g) {
  int64_t nnz = 0;
  mfree_status_t st = mfree_approximant_get_nnz(a, &nnz);
  if (st != MFREE_SUCCESS) return st;
  if (!*rp) {
    *rp = malloc(sizeof(int64_t) * (size_t)(n + 1));
    *ci = malloc(sizeof(int32_t) * (size_t)(nnz ? nnz : 1));
  }
  g[0] = malloc(sizeof(double) * (size_t)(nnz ? nnz : 1));
  g[1] = malloc(sizeof(double) * (size_t)(nnz ? nnz : 1));
  if (!*rp || !*ci || !g[0] || !g[1]) return MFREE_ERR_ALLOC;
  for (int c = 0; c < 2 && st == MFREE_SUCCESS; ++c)
    st = mfree_approximant_assemble_csr(a, MFREE_DERIV_GRADIENT, c, *rp, *ci, g[c]);
  return st;
}

/* Tables of approximant a (set up here); shear_a, when not NULL, provides the shear
 * derivatives (same neighbour pattern). */
static mfree_status_t tables_get(mfree_approximant_t *a, mfree_approximant_t *shear_a, int32_t n,
                                 tables_t *t) {
  memset(t, 0, sizeof *t);
  mfree_status_t st = mfree_approximant_setup(a);
  if (st < 0) return st;
  st = table_read(a, n, &t->rp, &t->ci, t->gn);
  if (st != MFREE_SUCCESS) return st;
  if (!shear_a) {
    t->gs[0] = t->gn[0], t->gs[1] = t->gn[1];
    return MFREE_SUCCESS;
  }
  st = mfree_approximant_setup(shear_a);
  if (st < 0) return st;
  int64_t *rp2 = NULL;
  int32_t *ci2 = NULL;
  st = table_read(shear_a, n, &rp2, &ci2, t->gs);
  if (st == MFREE_SUCCESS && memcmp(rp2, t->rp, sizeof(int64_t) * (size_t)(n + 1)) != 0) st = MFREE_ERR_MISMATCH;
  free(rp2), free(ci2);
  return st;
}

/* Position of column c in CSR row r, or -1. */
static int64_t find(const int64_t *rp, const int32_t *ci, int32_t r, int32_t c) {
  int64_t lo = rp[r], hi = rp[r + 1] - 1;
  while (lo <= hi) {
    const int64_t mid = lo + (hi - lo) / 2;
    if (ci[mid] == c) return mid;
    if (ci[mid] < c) lo = mid + 1;
    else hi = mid - 1;
  }
  return -1;
}

/* One side (test or trial) of a quadrature point: m functions with their node indices,
 * derivatives for the normal strains (nx, ny) and for the shear strain (sx, sy). */
typedef struct {
  int m;
  const int32_t *node;
  const double *nx, *ny, *sx, *sy;
} side_t;

/* Adds one quadrature point's w B_test^T D B_trial (Voigt xx, yy, xy; node-major dofs) to
 * the values v of a matrix with pattern (rp, ci), except in the rows of components that
 * skip marks (bit c of node J). Returns 1 if a non-zero falls outside the pattern. */
static int add_point(double *v, const int64_t *rp, const int32_t *ci, const double *D, const side_t *te,
                     const side_t *tr, double w, const int32_t *skip) {
  for (int a = 0; a < te->m; ++a) {
    const double BJ[3][2] = {{te->nx[a], 0.0}, {0.0, te->ny[a]}, {te->sy[a], te->sx[a]}};
    const int32_t J = te->node[a];
    for (int b = 0; b < tr->m; ++b) {
      const double BK[3][2] = {{tr->nx[b], 0.0}, {0.0, tr->ny[b]}, {tr->sy[b], tr->sx[b]}};
      const int32_t K = tr->node[b];
      for (int c = 0; c < 2; ++c)
        for (int e = 0; e < 2; ++e) {
          if (skip && (skip[J] & (1 << c))) continue;
          double s = 0.0;
          for (int u = 0; u < 3; ++u)
            for (int q = 0; q < 3; ++q) s += BJ[u][c] * D[3 * u + q] * BK[q][e];
          const int64_t pos = find(rp, ci, 2 * J + c, 2 * K + e);
          if (pos < 0) {
            if (s != 0.0) return 1;
            continue;
          }
          v[pos] += w * s;
        }
    }
  }
  return 0;
}

/* Side of quadrature particle I from tables t. */
static side_t table_side(const tables_t *t, int32_t I) {
  const int64_t o = t->rp[I];
  side_t s = {(int)(t->rp[I + 1] - o), t->ci + o, t->gn[0] + o, t->gn[1] + o, t->gs[0] + o, t->gs[1] + o};
  return s;
}

static void plane_stress_D(const es_problem_t *p, double *D) {
  const double q = p->E / (1.0 - p->nu * p->nu);
  const double d[9] = {q, q * p->nu, 0, q * p->nu, q, 0, 0, 0, q * 0.5 * (1.0 - p->nu)};
  memcpy(D, d, sizeof d);
}

/* The layer of the finite-element blending (000 Sect. 5.2.4): one quadrilateral between
 * each pair of consecutive boundary nodes P_k, P_k+1 of an essential boundary line and
 * their inner partners Q_k+1, Q_k (the nodes nearest to P - dx n), counter-clockwise.
 * conn: 4 per element; returns the element count, or -1 (message in err). */
static int32_t layer_elements(const es_level_t *lv, int chain, int32_t *conn, char *err, int errlen) {
  int32_t ne = 0;
  for (int c = 0; c < lv->nchain; ++c) {
    if (chain >= 0 && c != chain) continue;
    const int32_t a = lv->chain_start[c], b = lv->chain_start[c + 1];
    const double *nrm = lv->chain_nrm + 2 * c;
    for (int32_t k = a; k + 1 < b; ++k) {
      const int32_t P[2] = {lv->chain_nodes[k], lv->chain_nodes[k + 1]};
      int32_t Q[2];
      for (int e = 0; e < 2; ++e) {
        /* the inner node: the nearest one to P - d n, d the local spacing (graded hole:
         * the node's s / sqrt 2) */
        const double d = lv->hn ? lv->hn[P[e]] / sqrt(2.0) : lv->dx;
        const double tx = lv->x[2 * P[e]] - d * nrm[0], ty = lv->x[2 * P[e] + 1] - d * nrm[1];
        double best = 1e300;
        Q[e] = -1;
        for (int32_t j = 0; j < lv->n; ++j) {
          const double dd = hypot(lv->x[2 * j] - tx, lv->x[2 * j + 1] - ty);
          if (dd < best) best = dd, Q[e] = j;
        }
        if (best > 0.6 * d) {
          if (err) snprintf(err, (size_t)errlen, "FE layer: no inner node next to boundary node %d", (int)P[e]);
          return -1;
        }
      }
      int32_t *q = conn + 4 * ne++;
      q[0] = P[0], q[1] = P[1], q[2] = Q[1], q[3] = Q[0];
      double area = 0.0;
      for (int v = 0; v < 4; ++v) {
        const double *x0 = lv->x + 2 * q[v], *x1 = lv->x + 2 * q[(v + 1) % 4];
        area += x0[0] * x1[1] - x0[1] * x1[0];
      }
      if (area < 0.0) { /* make it counter-clockwise */
        const int32_t t = q[1];
        q[1] = q[3], q[3] = t;
      }
    }
  }
  return ne;
}

/* ES_BC_FE_NODAL: the finite-element layer of 000 Sect. 5.2.4 as nodal quadrature sees it.
 * The blended functions are only evaluated at the edges of the layer (000 eq 105): at a
 * node on Gamma_u they are the element functions, at the inner row the meshfree ones,
 * whose contributions the assembler already made. So at each Gamma_u node the meshfree
 * contribution is replaced by those of the elements that contain it, each with the
 * element's own corner derivatives and an equal share of the node's volume (000 Fig. 2);
 * direct_rows then imposes the prescribed values on the boundary nodes' parameters. The
 * corner derivatives of a bilinear element are those of the linear triangle (corner,
 * next, previous). This is what mfree_assembler_set_fe_layer does with nodal quadrature
 * (t640 checks that), but with a component mask per boundary line. */
static int fe_layer(const es_problem_t *p, const es_level_t *lv, const tables_t *te, const tables_t *tr,
                    double *v, const int64_t *rp, const int32_t *ci, char *err, int errlen) {
  double D[9];
  plane_stress_D(p, D);
  const int32_t n = lv->n;
  int32_t *nel = calloc((size_t)n, sizeof(int32_t)), *on_gu = calloc((size_t)n, sizeof(int32_t));
  int32_t *conn = malloc(sizeof(int32_t) * 4 * (size_t)(n ? n : 1));
  int32_t ne = -1;
  if (nel && on_gu && conn) ne = layer_elements(lv, -1, conn, err, errlen);
  int rc = ne < 0;
  for (int32_t k = 0; k < lv->chain_start[lv->nchain] && !rc; ++k) on_gu[lv->chain_nodes[k]] = 1;
  for (int32_t k = 0; k < 4 * ne; ++k) nel[conn[k]] += on_gu[conn[k]];
  for (int32_t I = 0; I < n && !rc; ++I) { /* remove the meshfree contributions */
    if (!on_gu[I]) continue;
    const side_t s = table_side(te, I), r = table_side(tr, I);
    rc = add_point(v, rp, ci, D, &s, &r, -lv->vol[I], NULL);
  }
  for (int32_t k = 0; k < 4 * ne && !rc; ++k) { /* element corners on Gamma_u */
    const int32_t *q = conn + 4 * (k / 4), a = k % 4, P = q[a];
    if (!on_gu[P]) continue;
    const int32_t tri[3] = {P, q[(a + 1) % 4], q[(a + 3) % 4]};
    const double *x0 = lv->x + 2 * tri[0], *x1 = lv->x + 2 * tri[1], *x2 = lv->x + 2 * tri[2];
    const double A2 = (x1[0] - x0[0]) * (x2[1] - x0[1]) - (x2[0] - x0[0]) * (x1[1] - x0[1]);
    const double gx[3] = {(x1[1] - x2[1]) / A2, (x2[1] - x0[1]) / A2, (x0[1] - x1[1]) / A2};
    const double gy[3] = {(x2[0] - x1[0]) / A2, (x0[0] - x2[0]) / A2, (x1[0] - x0[0]) / A2};
    const side_t s = {3, tri, gx, gy, gx, gy};
    rc = add_point(v, rp, ci, D, &s, &s, lv->vol[P] / nel[P], NULL);
  }
  if (rc && ne >= 0 && err) snprintf(err, (size_t)errlen, "FE layer: a coupling outside the assembled pattern");
  if (!nel || !on_gu || !conn) rc = 1;
  free(nel), free(on_gu), free(conn);
  return rc;
}

/* ES_BC_FE_GAUSS: quadrature points = the nodes off Gamma_u with their volumes, those of
 * the layer's interface nodes less a quarter of each adjacent element's area (the part of
 * their cells inside the layer), plus 2 x 2 Gauss points in every layer element (bilinear
 * map), where mfree blends the element and meshfree functions (000 eqs 100-104). */
static int fe_gauss_points(const es_level_t *lv, double **px, double **pw, int32_t *np, char *err, int errlen) {
  const int32_t n = lv->n;
  int32_t *conn = malloc(sizeof(int32_t) * 4 * (size_t)(n ? n : 1));
  char *gu = calloc((size_t)(n ? n : 1), 1);
  double *vol = malloc(sizeof(double) * (size_t)(n ? n : 1));
  int32_t ne = conn && gu && vol ? layer_elements(lv, -1, conn, err, errlen) : -1;
  double *x = ne >= 0 ? malloc(sizeof(double) * 2 * (size_t)(n + 4 * ne)) : NULL;
  double *w = ne >= 0 ? malloc(sizeof(double) * (size_t)(n + 4 * ne)) : NULL;
  int rc = !x || !w;
  if (!rc) {
    memcpy(vol, lv->vol, sizeof(double) * (size_t)n);
    for (int32_t k = 0; k < lv->chain_start[lv->nchain]; ++k) gu[lv->chain_nodes[k]] = 1;
    const double g = 1.0 / sqrt(3.0);
    int32_t m = 0;
    for (int32_t e = 0; e < ne; ++e) {
      const int32_t *q = conn + 4 * e;
      double X[4][2];
      for (int a = 0; a < 4; ++a) X[a][0] = lv->x[2 * q[a]], X[a][1] = lv->x[2 * q[a] + 1];
      double area = 0.0;
      for (int a = 0; a < 4; ++a) area += 0.5 * (X[a][0] * X[(a + 1) % 4][1] - X[(a + 1) % 4][0] * X[a][1]);
      for (int a = 0; a < 4; ++a)
        if (!gu[q[a]]) vol[q[a]] -= 0.25 * area;
      for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j, ++m) {
          const double u = i ? g : -g, v = j ? g : -g;
          const double N[4] = {0.25 * (1 - u) * (1 - v), 0.25 * (1 + u) * (1 - v), 0.25 * (1 + u) * (1 + v),
                               0.25 * (1 - u) * (1 + v)};
          double J[2][2] = {{0, 0}, {0, 0}};
          const double du[4] = {-0.25 * (1 - v), 0.25 * (1 - v), 0.25 * (1 + v), -0.25 * (1 + v)};
          const double dv[4] = {-0.25 * (1 - u), -0.25 * (1 + u), 0.25 * (1 + u), 0.25 * (1 - u)};
          x[2 * m] = x[2 * m + 1] = 0.0;
          for (int a = 0; a < 4; ++a)
            for (int d = 0; d < 2; ++d) {
              x[2 * m + d] += N[a] * X[a][d];
              J[d][0] += du[a] * X[a][d];
              J[d][1] += dv[a] * X[a][d];
            }
          w[m] = fabs(J[0][0] * J[1][1] - J[0][1] * J[1][0]);
        }
    }
    for (int32_t i = 0; i < n; ++i) {
      if (gu[i]) continue;
      x[2 * m] = lv->x[2 * i], x[2 * m + 1] = lv->x[2 * i + 1];
      w[m++] = vol[i];
    }
    *np = m;
  }
  free(conn), free(gu), free(vol);
  if (rc) {
    free(x), free(w);
    return 1;
  }
  *px = x, *pw = w;
  return 0;
}

/* Rows u_J = g_c(x_J) on the nodal parameters (ES_BC_DIRECT): the pattern of the
 * assembled matrix always holds the diagonal (every particle is its own neighbour). The
 * rows are scaled by E, the size of the stiffness rows. */
static void direct_rows(const es_problem_t *p, const es_level_t *lv, const int32_t *mask, const int64_t *rp,
                        const int32_t *ci, double *v, double *f) {
  for (int32_t i = 0; i < lv->n; ++i) {
    if (!mask[i]) continue;
    double g[2];
    es_exact(p, lv->x + 2 * i, g, NULL, NULL);
    for (int c = 0; c < 2; ++c) {
      if (!(mask[i] & (1 << c))) continue;
      const int32_t d = 2 * i + c;
      for (int64_t k = rp[d]; k < rp[d + 1]; ++k) v[k] = ci[k] == d ? p->E : 0.0;
      f[d] = p->E * g[c];
    }
  }
}

/* ------------------------------------------------------------------------------------ */
/* Linear solve                                                                           */
/* ------------------------------------------------------------------------------------ */

#ifndef ES_HAVE_SUITESPARSE
/* Fallback when libmfree_suitesparse is not built: reverse Cuthill-McKee ordering and a
 * banded LU with partial pivoting (the storage of LAPACK's dgbtrf). Fine for the patch
 * test and the coarser levels; the finest default levels want UMFPACK. */
static mfree_status_t band_solve(int32_t n, const int64_t *rp, const int32_t *ci, const double *v,
                                 const double *b, double *x, double *rcond, char *err, int errlen) {
  mfree_status_t st = MFREE_SUCCESS;
  int32_t *perm = malloc(sizeof(int32_t) * (size_t)n), *inv = malloc(sizeof(int32_t) * (size_t)n);
  int32_t *deg = malloc(sizeof(int32_t) * (size_t)n), *ipiv = malloc(sizeof(int32_t) * (size_t)n);
  double *ab = NULL, *y = malloc(sizeof(double) * (size_t)n);
  if (!perm || !inv || !deg || !ipiv || !y) {
    st = MFREE_ERR_ALLOC;
    goto out;
  }
  for (int32_t i = 0; i < n; ++i) deg[i] = (int32_t)(rp[i + 1] - rp[i]), inv[i] = -1;
  /* Cuthill-McKee from a node of least degree in every component, then reversed */
  int32_t head = 0, tail = 0;
  for (int32_t seed = 0; tail < n;) {
    int32_t best = -1;
    for (; seed < n && inv[seed] >= 0; ++seed) {
    }
    for (int32_t i = seed; i < n; ++i)
      if (inv[i] < 0 && (best < 0 || deg[i] < deg[best])) best = i;
    inv[best] = tail;
    perm[tail++] = best;
    while (head < tail) {
      const int32_t i = perm[head++], first = tail;
      for (int64_t k = rp[i]; k < rp[i + 1]; ++k)
        if (inv[ci[k]] < 0) inv[ci[k]] = tail, perm[tail++] = ci[k];
      for (int32_t a = first + 1; a < tail; ++a) /* by increasing degree */
        for (int32_t c = a; c > first && deg[perm[c]] < deg[perm[c - 1]]; --c) {
          const int32_t t = perm[c];
          perm[c] = perm[c - 1], perm[c - 1] = t;
        }
    }
  }
  for (int32_t a = 0; a < n / 2; ++a) {
    const int32_t t = perm[a];
    perm[a] = perm[n - 1 - a], perm[n - 1 - a] = t;
  }
  for (int32_t a = 0; a < n; ++a) inv[perm[a]] = a;
  int64_t kl = 0, ku = 0;
  for (int32_t i = 0; i < n; ++i)
    for (int64_t k = rp[i]; k < rp[i + 1]; ++k) {
      const int64_t d = (int64_t)inv[i] - inv[ci[k]];
      if (d > kl) kl = d;
      if (-d > ku) ku = -d;
    }
  const int64_t k2 = kl + ku, ld = 2 * kl + ku + 1;
  if ((double)ld * n * sizeof(double) > 1.5e9) {
    if (err) snprintf(err, (size_t)errlen, "built without libmfree_suitesparse: the banded fallback would need "
                                           "%.1f GB for %d unknowns (bandwidth %lld)", ld * (double)n * 8e-9, (int)n,
                      (long long)kl);
    st = MFREE_ERR_ALLOC;
    goto out;
  }
  ab = calloc((size_t)(ld * n), sizeof(double));
  if (!ab) {
    st = MFREE_ERR_ALLOC;
    goto out;
  }
#define AB(i, j) ab[(int64_t)(j) * ld + k2 + (i) - (j)]
  for (int32_t i = 0; i < n; ++i)
    for (int64_t k = rp[i]; k < rp[i + 1]; ++k) AB(inv[i], inv[ci[k]]) += v[k];
  double pmin = 1e300, pmax = 0.0;
  int64_t ju = 0;
  for (int64_t j = 0; j < n; ++j) {
    const int64_t km = kl < n - 1 - j ? kl : n - 1 - j;
    int64_t p = 0;
    for (int64_t r = 1; r <= km; ++r)
      if (fabs(AB(j + r, j)) > fabs(AB(j + p, j))) p = r;
    ipiv[j] = (int32_t)(j + p);
    const double piv = AB(j + p, j);
    if (piv == 0.0) {
      if (err) snprintf(err, (size_t)errlen, "banded LU: the matrix is singular (column %lld)", (long long)j);
      st = MFREE_FAIL_SINGULAR;
      goto out;
    }
    if (fabs(piv) < pmin) pmin = fabs(piv);
    if (fabs(piv) > pmax) pmax = fabs(piv);
    const int64_t last = j + ku + p < n - 1 ? j + ku + p : n - 1;
    if (last > ju) ju = last;
    if (p)
      for (int64_t c = j; c <= ju; ++c) {
        const double t = AB(j, c);
        AB(j, c) = AB(j + p, c), AB(j + p, c) = t;
      }
    for (int64_t r = 1; r <= km; ++r) AB(j + r, j) /= piv;
    for (int64_t c = j + 1; c <= ju; ++c) {
      const double t = AB(j, c);
      if (t != 0.0)
        for (int64_t r = 1; r <= km; ++r) AB(j + r, c) -= AB(j + r, j) * t;
    }
  }
  for (int32_t i = 0; i < n; ++i) y[inv[i]] = b[i];
  for (int64_t j = 0; j < n; ++j) {
    const int64_t km = kl < n - 1 - j ? kl : n - 1 - j;
    const double t = y[ipiv[j]];
    y[ipiv[j]] = y[j], y[j] = t;
    for (int64_t r = 1; r <= km; ++r) y[j + r] -= AB(j + r, j) * y[j];
  }
  for (int64_t j = n - 1; j >= 0; --j) {
    y[j] /= AB(j, j);
    for (int64_t i = j - k2 > 0 ? j - k2 : 0; i < j; ++i) y[i] -= AB(i, j) * y[j];
  }
#undef AB
  for (int32_t i = 0; i < n; ++i) x[i] = y[inv[i]];
  *rcond = pmax > 0 ? pmin / pmax : 0.0;
out:
  if (st == MFREE_ERR_ALLOC && err && !err[0]) snprintf(err, (size_t)errlen, "banded LU: out of memory");
  free(perm), free(inv), free(deg), free(ipiv), free(ab), free(y);
  return st;
}
#endif

/* K u = f: UMFPACK through libmfree_suitesparse, or the banded fallback. */
static mfree_status_t solve_system(mfree_context_t *ctx, const mfree_matrix_t *K, const double *f, double *u,
                                   double *rcond, char *err, int errlen) {
  int32_t n, nc;
  int64_t nnz;
  mfree_status_t st = mfree_matrix_get_size(K, &n, &nc, &nnz);
  if (st != MFREE_SUCCESS) return st;
#ifdef ES_HAVE_SUITESPARSE
  (void)nnz;
  mfree_suitesparse_t *solver = NULL;
  const char *what = "UMFPACK";
  st = mfree_suitesparse_create(ctx, MFREE_SOLVER_UMFPACK, &solver);
  if (st == MFREE_SUCCESS) {
    what = "UMFPACK factorisation";
    st = mfree_suitesparse_setup(solver, K);
  }
  if (st == MFREE_SUCCESS) st = mfree_suitesparse_get_info(solver, rcond, NULL, NULL);
  if (st == MFREE_SUCCESS) {
    what = "UMFPACK solve";
    st = mfree_suitesparse_solve(solver, 1, f, n, u, n);
  }
  mfree_suitesparse_destroy(&solver);
  if (st != MFREE_SUCCESS && err) {
    char msg[400] = "";
    mfree_context_get_last_error(ctx, NULL, msg, sizeof msg);
    snprintf(err, (size_t)errlen, "%s: %s (%s)", what, mfree_status_string(st), msg);
  }
  return st;
#else
  (void)ctx;
  const int64_t *rp;
  const int32_t *ci;
  const double *v;
  st = mfree_matrix_get_csr(K, &rp, &ci, &v);
  if (st != MFREE_SUCCESS) return st;
  return band_solve(n, rp, ci, v, f, u, rcond, err, errlen);
#endif
}

/* ------------------------------------------------------------------------------------ */
/* One run                                                                                */
/* ------------------------------------------------------------------------------------ */

enum { NGB = 4 }; /* Gauss points per boundary segment (essential conditions) */

typedef struct {
  mfree_context_t *ctx;
  char *err;
  int errlen;
  int *warn;
} chk_t;

/* Negative: fatal (returns 1); positive: a warning, the run goes on. */
static int chk(chk_t *c, mfree_status_t st, const char *what) {
  if (st == MFREE_SUCCESS) return 0;
  char msg[512] = "";
  mfree_context_get_last_error(c->ctx, NULL, msg, sizeof msg);
  if (st > 0) {
    if (!*c->warn) fprintf(stderr, "warning: %s: %s (%s)\n", what, mfree_status_string(st), msg);
    *c->warn = 1;
    return 0;
  }
  if (c->err) snprintf(c->err, (size_t)c->errlen, "%s: %s (%s)", what, mfree_status_string(st), msg);
  return 1;
}

#define CHECK(call, what)          \
  do {                             \
    st = (call);                   \
    if (chk(&ck, st, what)) goto done; \
  } while (0)

mfree_status_t es_run(mfree_context_t *ctx, const es_problem_t *p, const es_level_t *lv,
                      const es_scheme_t *s, es_bc_t bc, int efg_ngauss, es_result_t *r,
                      char *err, int errlen) {
  return es_run_vci(ctx, p, lv, s, bc, 0, efg_ngauss, r, err, errlen);
}

mfree_status_t es_run_vci(mfree_context_t *ctx, const es_problem_t *p, const es_level_t *lv,
                          const es_scheme_t *s, es_bc_t bc, int vci, int efg_ngauss,
                          es_result_t *r, char *err, int errlen) {
  const double t0 = now();
  memset(r, 0, sizeof *r);
  if (err && errlen > 0) err[0] = '\0';
  chk_t ck = {ctx, err, errlen, &r->warn};
  mfree_status_t st = MFREE_SUCCESS;
  mfree_particles_t *ps = NULL;
  mfree_approximant_t *trial = NULL, *test = NULL, *ev = NULL, *evn = NULL, *shear = NULL;
  tables_t ttr = {0}, tte = {0};
  double *kv = NULL;
  mfree_assembler_t *as = NULL;
  mfree_matrix_t *K = NULL;
  double *f = NULL, *u = NULL, *bx = NULL, *bw = NULL, *bn = NULL, *uq = NULL, *gq = NULL;
  double *un = NULL, *gx = NULL, *gw = NULL;
  int32_t ngp = 0;
  int32_t *nodes = NULL, *conn = NULL, *gu = NULL, *on_gu = NULL, *band = NULL;
  traction_t *tu = NULL;
  const int32_t n = lv->n;

  bc = es_bc_resolve(s, lv, bc);
  r->bc = bc;
  r->vci = vci != 0;
  if ((s->efg || s->particles_only) && bc == ES_BC_FE_GAUSS) {
    st = MFREE_ERR_UNSUPPORTED;
    if (err) snprintf(err, (size_t)errlen, "%s: fe-gauss is for nodal quadrature of functions defined between "
                                           "the particles", s->name);
    goto done;
  }
  if (s->efg && bc == ES_BC_FE_NODAL) {
    st = MFREE_ERR_UNSUPPORTED;
    if (err) snprintf(err, (size_t)errlen, "%s: the FE-layer emulation is for nodal quadrature", s->name);
    goto done;
  }
  if (s->particles_only && vci) {
    st = MFREE_ERR_UNSUPPORTED;
    if (err) snprintf(err, (size_t)errlen, "%s: consistent integration needs test-function values", s->name);
    goto done;
  }
  if ((bc == ES_BC_COLUMNS || bc == ES_BC_COLUMNS2) && p->kind != ES_BEAM) {
    st = MFREE_ERR_UNSUPPORTED;
    if (err) snprintf(err, (size_t)errlen, "%s: --bc %s is a diagnosis for the beam only", s->name, es_bc_name(bc));
    goto done;
  }
  if (s->particles_only && bc == ES_BC_NITSCHE) {
    st = MFREE_ERR_UNSUPPORTED;
    if (err) snprintf(err, (size_t)errlen, "%s: Nitsche needs functions between the particles", s->name);
    goto done;
  }

  CHECK(mfree_particles_create(ctx, 2, n, &ps), "particles");
  CHECK(mfree_particles_set_positions(ps, lv->x, MFREE_LAYOUT_AOS, 2, MFREE_COPY), "positions");
  CHECK(mfree_particles_set_volumes(ps, lv->vol, 1, MFREE_COPY), "volumes");
  CHECK(mfree_particles_set_support(ps, lv->hn ? lv->hn : &lv->h, lv->hn ? 1 : 0, MFREE_COPY), "support");
  CHECK(mfree_particles_setup(ps), "particle setup");
  CHECK(mfree_approximant_create(ctx, ps, s->trial, &trial), "trial approximant");
  if (s->order) CHECK(mfree_approximant_set_order(trial, s->order), "trial order");
  if (s->test) CHECK(mfree_approximant_create(ctx, ps, s->test, &test), "test approximant");

  CHECK(mfree_assembler_create(ctx, trial, test, MFREE_FORM_ELASTICITY_PLANE_STRESS, &as), "assembler");
  CHECK(mfree_assembler_set_material(as, p->E, p->nu), "material");
  if (s->efg) {
    const int ng = efg_ngauss > 0 ? efg_ngauss : 5;
    if (lv->cells)
      CHECK(mfree_assembler_set_quadrature_cells(as, lv->lo, lv->hi, lv->ncells, ng, NULL, NULL),
            "background cells");
    else
      CHECK(mfree_assembler_set_quadrature_points(as, lv->nq, lv->xq, MFREE_LAYOUT_AOS, 2, lv->wq),
            "background points");
  } else if (bc == ES_BC_FE_GAUSS) {
    if (fe_gauss_points(lv, &gx, &gw, &ngp, err, errlen)) {
      st = MFREE_ERR_INPUT;
      goto done;
    }
    CHECK(mfree_assembler_set_quadrature_points(as, ngp, gx, MFREE_LAYOUT_AOS, 2, gw), "layer Gauss points");
  } else {
    CHECK(mfree_assembler_set_quadrature_nodal(as), "nodal quadrature");
  }

  /* tractions from the exact stresses, one call per straight edge. Nodal quadrature
   * schemes: 000 eq 95's boundary term Psi_J(x_I) tau(x_I) dGamma_I, the nodes of each
   * segment with half its length (a node shared by two segments of an edge gets both
   * halves). EFG, consistent integration (its boundary rule must match the load's) and
   * --traction gauss: 4 Gauss points per segment. The choice matters on the coarse levels
   * only (beam 17x3: CD1 energy error 0.49 nodal, 0.33 Gauss; equal to 3 digits from
   * 129x17 on). */
  r->traction_nodal = !p->traction_gauss && !s->efg && !vci;
  tu = malloc(sizeof(traction_t) * (size_t)(lv->nts ? lv->nts : 1));
  bx = malloc(sizeof(double) * 4 * (size_t)(lv->nts ? lv->nts : 1));
  bw = malloc(sizeof(double) * 2 * (size_t)(lv->nts ? lv->nts : 1));
  if (!tu || !bx || !bw) {
    st = MFREE_ERR_ALLOC;
    goto done;
  }
  for (int32_t a = 0, b; a < lv->nts; a = b) {
    for (b = a + 1; b < lv->nts && lv->tnrm[2 * b] == lv->tnrm[2 * a] &&
                    lv->tnrm[2 * b + 1] == lv->tnrm[2 * a + 1];
         ++b) {
    }
    tu[a].p = p;
    tu[a].n[0] = lv->tnrm[2 * a];
    tu[a].n[1] = lv->tnrm[2 * a + 1];
    if (r->traction_nodal) {
      for (int32_t k = a; k < b; ++k) {
        const double *sg = lv->tseg + 4 * k;
        memcpy(bx + 4 * k, sg, sizeof(double) * 4);
        bw[2 * k] = bw[2 * k + 1] = 0.5 * hypot(sg[2] - sg[0], sg[3] - sg[1]);
      }
      CHECK(mfree_assembler_add_traction(as, 2 * (b - a), bx + 4 * a, MFREE_LAYOUT_AOS, 2, bw + 2 * a, t_exact,
                                         &tu[a]),
            "nodal tractions");
    } else {
      CHECK(mfree_assembler_add_traction_segments(as, b - a, lv->tseg + 4 * a, 4, t_exact, &tu[a]),
            "tractions");
    }
  }
  free(bx), free(bw);
  bx = bw = NULL;

  /* essential conditions */
  if (bc == ES_BC_NITSCHE || bc == ES_BC_PENALTY) {
    double g[NGB], gw[NGB];
    {
      /* the rule of es_geometry.c is static there; NGB = 4 points here */
      const double a = sqrt(3.0 / 7.0 - 2.0 / 7.0 * sqrt(6.0 / 5.0)),
                   b = sqrt(3.0 / 7.0 + 2.0 / 7.0 * sqrt(6.0 / 5.0));
      const double wa = (18.0 + sqrt(30.0)) / 36.0, wb = (18.0 - sqrt(30.0)) / 36.0;
      g[0] = -b, g[1] = -a, g[2] = a, g[3] = b;
      gw[0] = wb, gw[1] = wa, gw[2] = wa, gw[3] = wb;
    }
    const size_t np = (size_t)lv->nds * NGB;
    bx = malloc(sizeof(double) * 2 * (np ? np : 1));
    bw = malloc(sizeof(double) * (np ? np : 1));
    bn = malloc(sizeof(double) * 2 * (np ? np : 1));
    if (!bx || !bw || !bn) {
      st = MFREE_ERR_ALLOC;
      goto done;
    }
    for (int mask = 1; mask <= 3; ++mask) {
      int32_t m = 0;
      for (int32_t sg = 0; sg < lv->nds; ++sg) {
        if (lv->dsmask[sg] != mask) continue;
        const double *A = lv->dseg + 4 * sg, *B = A + 2;
        const double len = hypot(B[0] - A[0], B[1] - A[1]);
        for (int q = 0; q < NGB; ++q, ++m) {
          const double t = 0.5 * (1.0 + g[q]);
          bx[2 * m] = A[0] + t * (B[0] - A[0]);
          bx[2 * m + 1] = A[1] + t * (B[1] - A[1]);
          bw[m] = 0.5 * len * gw[q];
          bn[2 * m] = lv->dnrm[2 * sg];
          bn[2 * m + 1] = lv->dnrm[2 * sg + 1];
        }
      }
      if (m)
        CHECK(mfree_assembler_add_dirichlet(as, bc == ES_BC_NITSCHE ? MFREE_BC_NITSCHE : MFREE_BC_PENALTY,
                                            m, bx, MFREE_LAYOUT_AOS, 2, bw,
                                            bc == ES_BC_NITSCHE ? bn : NULL, mask, g_exact, (void *)p),
              "essential boundary");
    }
  } else if (bc == ES_BC_ROWS || bc == ES_BC_LAGRANGE) {
    nodes = malloc(sizeof(int32_t) * (size_t)(n ? n : 1));
    bx = malloc(sizeof(double) * 2 * (size_t)(n ? n : 1));
    if (!nodes || !bx) {
      st = MFREE_ERR_ALLOC;
      goto done;
    }
    for (int mask = 1; mask <= 3; ++mask) {
      int32_t m = 0;
      for (int32_t i = 0; i < n; ++i)
        if (lv->dmask[i] == mask) {
          nodes[m] = i;
          bx[2 * m] = lv->x[2 * i];
          bx[2 * m + 1] = lv->x[2 * i + 1];
          ++m;
        }
      if (!m) continue;
      if (bc == ES_BC_ROWS)
        CHECK(mfree_assembler_add_dirichlet_nodes(as, m, nodes, mask, g_exact, (void *)p), "Dirichlet rows");
      else
        CHECK(mfree_assembler_add_dirichlet(as, MFREE_BC_LAGRANGE, m, bx, MFREE_LAYOUT_AOS, 2, NULL, NULL, mask,
                                            g_exact, (void *)p),
              "Lagrange multipliers");
    }
  }

  if (bc == ES_BC_FE_LAYER || bc == ES_BC_FE_GAUSS) {
    /* one call per essential boundary line, each with its own component mask */
    conn = malloc(sizeof(int32_t) * 4 * (size_t)(n ? n : 1));
    gu = malloc(sizeof(int32_t) * (size_t)(n ? n : 1));
    on_gu = calloc((size_t)(n ? n : 1), sizeof(int32_t));
    if (!conn || !gu || !on_gu) {
      st = MFREE_ERR_ALLOC;
      goto done;
    }
    for (int c = 0; c < lv->nchain; ++c) {
      const int32_t ne = layer_elements(lv, c, conn, err, errlen);
      if (ne < 0) {
        st = MFREE_ERR_INPUT;
        goto done;
      }
      int32_t ngu = 0;
      for (int32_t k = lv->chain_start[c]; k < lv->chain_start[c + 1]; ++k) {
        const int32_t i = lv->chain_nodes[k];
        on_gu[i] = 1;
        gu[ngu++] = i;
      }
      CHECK(mfree_assembler_set_fe_layer(as, ne, 4, conn, ngu, gu, lv->chain_mask[c], g_exact, (void *)p),
            "FE layer");
    }
  }
  if (vci)
    CHECK(mfree_assembler_set_consistent_integration(as, lv->nbp, lv->bpx, MFREE_LAYOUT_AOS, 2, lv->bpw, lv->bpn),
          "consistent integration");
  CHECK(mfree_assembler_setup(as), "assembler setup");
  int32_t ndofs = 0, nquad = 0;
  CHECK(mfree_assembler_get_size(as, &ndofs, &nquad), "sizes");
  r->ndofs = ndofs;
  f = malloc(sizeof(double) * (size_t)ndofs);
  u = malloc(sizeof(double) * (size_t)ndofs);
  if (!f || !u) {
    st = MFREE_ERR_ALLOC;
    goto done;
  }
  CHECK(mfree_assembler_assemble_matrix(as, &K), "stiffness");
  CHECK(mfree_assembler_assemble_rhs(as, f), "load");
  if (bc == ES_BC_DIRECT || bc == ES_BC_FE_NODAL || bc == ES_BC_COLUMNS || bc == ES_BC_COLUMNS2) {
    /* the example's changes to the assembled stiffness, on a copy of its values */
    const int64_t *rp;
    const int32_t *ci;
    const double *va;
    int32_t nr, ncol;
    int64_t nnz;
    CHECK(mfree_matrix_get_size(K, &nr, &ncol, &nnz), "matrix size");
    CHECK(mfree_matrix_get_csr(K, &rp, &ci, &va), "matrix view");
    kv = malloc(sizeof(double) * (size_t)(nnz ? nnz : 1));
    if (!kv) {
      st = MFREE_ERR_ALLOC;
      goto done;
    }
    memcpy(kv, va, sizeof(double) * (size_t)nnz);
    if (bc == ES_BC_FE_NODAL) {
      /* JB: the shear rows of the removed meshfree contributions keep symmetrised SPH */
      if (s->trial == MFREE_METHOD_JOHNSON_BEISSEL)
        CHECK(mfree_approximant_create(ctx, ps, MFREE_METHOD_SPH_SYMMETRIC, &shear), "SPH shear");
      CHECK(tables_get(trial, shear, n, &ttr), "trial tables");
      if (test) CHECK(tables_get(test, NULL, n, &tte), "test tables");
      const tables_t *pte = test ? &tte : &ttr;
      if (fe_layer(p, lv, pte, &ttr, kv, rp, ci, err, errlen)) {
        st = MFREE_ERR_INTERNAL;
        goto done;
      }
    }
    if (bc == ES_BC_DIRECT || bc == ES_BC_FE_NODAL) direct_rows(p, lv, lv->dmask, rp, ci, kv, f);
    if (bc == ES_BC_COLUMNS || bc == ES_BC_COLUMNS2) {
      band = calloc((size_t)(n ? n : 1), sizeof(int32_t));
      if (!band) {
        st = MFREE_ERR_ALLOC;
        goto done;
      }
      for (int32_t i = 0; i < n; ++i) {
        const double x = lv->x[2 * i];
        if (x < 2.5 * lv->dx || (bc == ES_BC_COLUMNS2 && x > p->L - 2.5 * lv->dx)) band[i] = 3;
      }
      direct_rows(p, lv, band, rp, ci, kv, f);
    }
    mfree_matrix_t *K2 = NULL;
    CHECK(mfree_matrix_create_csr(ctx, nr, ncol, rp, ci, kv, &K2), "modified matrix");
    mfree_matrix_destroy(&K);
    K = K2;
  }

  st = solve_system(ctx, K, f, u, &r->rcond, err, errlen);
  if (st != MFREE_SUCCESS) goto done; /* a singular matrix (positive status) ends the run too */

  /* ---- errors ----
   * u^h at the nodes (000 eq 115): the values of the trial approximant at the particles
   * applied to the solution; for SPH, JB and RL (particles-only, their value tables are
   * kernel sums that are not even partitions of unity) the particle values u_I
   * themselves, which is what their gradients act on.
   * u^h and grad u^h at the Gauss points (000 eqs 116-119): the trial approximant at
   * the points; for SPH, JB and RL, whose functions are not defined between the
   * particles, an MLS (order 1, same kernel and h) interpolant of the particle values. */
  un = malloc(sizeof(double) * 2 * (size_t)n);
  uq = malloc(sizeof(double) * 2 * (size_t)lv->nq);
  gq = malloc(sizeof(double) * 4 * (size_t)lv->nq);
  if (!un || !uq || !gq) {
    st = MFREE_ERR_ALLOC;
    goto done;
  }
  if (s->particles_only) {
    memcpy(un, u, sizeof(double) * 2 * (size_t)n);
  } else {
    CHECK(mfree_approximant_create(ctx, ps, s->trial, &evn), "nodal values");
    if (s->order) CHECK(mfree_approximant_set_order(evn, s->order), "order");
    CHECK(mfree_approximant_set_derivatives(evn, MFREE_DERIV_VALUE), "tables");
    CHECK(mfree_approximant_setup(evn), "nodal values setup");
    CHECK(mfree_approximant_apply(evn, MFREE_OP_VALUE, 2, u, MFREE_LAYOUT_AOS, 2, un, MFREE_LAYOUT_AOS, 2),
          "nodal values apply");
  }
  {
    const mfree_method_t em = s->particles_only ? MFREE_METHOD_MLS : s->trial;
    CHECK(mfree_approximant_create(ctx, ps, em, &ev), "error approximant");
    if (s->particles_only || s->order) CHECK(mfree_approximant_set_order(ev, s->order ? s->order : 1), "order");
    CHECK(mfree_approximant_set_points(ev, lv->nq, lv->xq, MFREE_LAYOUT_AOS, 2, lv->hq ? lv->hq : &lv->h,
                                       lv->hq ? 1 : 0, MFREE_BORROW),
          "error points");
    CHECK(mfree_approximant_setup(ev), "error approximant setup");
    CHECK(mfree_approximant_apply(ev, MFREE_OP_VALUE, 2, u, MFREE_LAYOUT_AOS, 2, uq, MFREE_LAYOUT_AOS, 2),
          "values at Gauss points");
    CHECK(mfree_approximant_apply(ev, MFREE_OP_GRADIENT, 2, u, MFREE_LAYOUT_AOS, 2, gq, MFREE_LAYOUT_AOS, 4),
          "gradients at Gauss points");
  }
  {
    double num = 0, den = 0;
    for (int32_t i = 0; i < n; ++i) {
      double ue[2];
      es_exact(p, lv->x + 2 * i, ue, NULL, NULL);
      const double ex = un[2 * i] - ue[0], ey = un[2 * i + 1] - ue[1];
      num += lv->vol[i] * (ex * ex + ey * ey);
      den += lv->vol[i] * (ue[0] * ue[0] + ue[1] * ue[1]);
    }
    r->l2 = sqrt(num / den);
    const double q = p->E / (1.0 - p->nu * p->nu);
    double n0 = 0, d0 = 0, n1 = 0, d1 = 0;
    for (int32_t k = 0; k < lv->nq; ++k) {
      double ue[2], ee[3];
      es_exact(p, lv->xq + 2 * k, ue, ee, NULL);
      const double w = lv->wq[k], ex = uq[2 * k] - ue[0], ey = uq[2 * k + 1] - ue[1];
      n0 += w * (ex * ex + ey * ey);
      d0 += w * (ue[0] * ue[0] + ue[1] * ue[1]);
      const double *gg = gq + 4 * k; /* u_x,x u_x,y u_y,x u_y,y */
      const double e[3] = {gg[0] - ee[0], gg[3] - ee[1], gg[1] + gg[2] - ee[2]};
      /* eps : C : eps with the plane-stress C (000 eq 119 with the square root) */
      n1 += w * q * (e[0] * e[0] + e[1] * e[1] + 2 * p->nu * e[0] * e[1] + 0.5 * (1 - p->nu) * e[2] * e[2]);
      d1 += w * q * (ee[0] * ee[0] + ee[1] * ee[1] + 2 * p->nu * ee[0] * ee[1] + 0.5 * (1 - p->nu) * ee[2] * ee[2]);
    }
    r->L2 = sqrt(n0 / d0);
    r->energy = sqrt(n1 / d1);
  }
  {
    /* energy error at the nodes with the scheme's own derivatives there (JB: beta-corrected
     * normal strains, symmetrised SPH shear) */
    if (!ttr.rp) {
      if (s->trial == MFREE_METHOD_JOHNSON_BEISSEL)
        CHECK(mfree_approximant_create(ctx, ps, MFREE_METHOD_SPH_SYMMETRIC, &shear), "SPH shear");
      CHECK(tables_get(trial, shear, n, &ttr), "trial tables");
    }
    const double q = p->E / (1.0 - p->nu * p->nu);
    double num = 0, den = 0;
    for (int32_t I = 0; I < n; ++I) {
      double ee[3], e[3] = {0, 0, 0};
      es_exact(p, lv->x + 2 * I, NULL, ee, NULL);
      for (int64_t k = ttr.rp[I]; k < ttr.rp[I + 1]; ++k) {
        const int32_t K = ttr.ci[k];
        e[0] += ttr.gn[0][k] * u[2 * K];
        e[1] += ttr.gn[1][k] * u[2 * K + 1];
        e[2] += ttr.gs[1][k] * u[2 * K] + ttr.gs[0][k] * u[2 * K + 1];
      }
      for (int c = 0; c < 3; ++c) e[c] -= ee[c];
      num += lv->vol[I] * q * (e[0] * e[0] + e[1] * e[1] + 2 * p->nu * e[0] * e[1] + 0.5 * (1 - p->nu) * e[2] * e[2]);
      den += lv->vol[I] * q * (ee[0] * ee[0] + ee[1] * ee[1] + 2 * p->nu * ee[0] * ee[1] + 0.5 * (1 - p->nu) * ee[2] * ee[2]);
    }
    r->energy_nodal = sqrt(num / den);
  }
  st = MFREE_SUCCESS;

done:
  mfree_matrix_destroy(&K);
  mfree_assembler_destroy(&as);
  mfree_approximant_destroy(&ev);
  mfree_approximant_destroy(&shear);
  tables_free(&ttr);
  tables_free(&tte);
  free(kv);
  mfree_approximant_destroy(&evn);
  mfree_approximant_destroy(&test);
  mfree_approximant_destroy(&trial);
  mfree_particles_destroy(&ps);
  free(f), free(u), free(bx), free(bw), free(bn), free(uq), free(gq), free(un), free(nodes), free(tu);
  free(conn), free(gu), free(on_gu), free(gx), free(gw), free(band);
  r->seconds = now() - t0;
  return st;
}

