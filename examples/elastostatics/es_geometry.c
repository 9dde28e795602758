/* Problems, node clouds, nodal volumes and background quadrature for the static
 * convergence study of paper 000 Sect. 6.2 (see es.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "es.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* ------------------------------------------------------------------------------------ */
/* Exact solutions                                                                        */
/* ------------------------------------------------------------------------------------ */

/* Plane-stress compliance: the strains of a stress state. */
static void plane_stress_strain(const es_problem_t *p, const double *sig, double *eps) {
  eps[0] = (sig[0] - p->nu * sig[1]) / p->E;
  eps[1] = (sig[1] - p->nu * sig[0]) / p->E;
  eps[2] = 2.0 * (1.0 + p->nu) / p->E * sig[2];
}

void es_exact(const es_problem_t *p, const double *x, double *u, double *eps, double *sig) {
  double s[3], d[2];
  if (p->kind == ES_BEAM) {
    /* 000 eqs 120-125 (Timoshenko's cantilever, plane stress, y in [-D/2, D/2]) */
    const double P = p->P, L = p->L, D = p->D, E = p->E, nu = p->nu;
    const double I = D * D * D / 12.0, X = x[0], Y = x[1];
    d[0] = -P * Y / (6.0 * E * I) * ((6.0 * L - 3.0 * X) * X + (2.0 + nu) * (Y * Y - D * D / 4.0));
    d[1] = P / (6.0 * E * I) *
           (3.0 * nu * Y * Y * (L - X) + (4.0 + 5.0 * nu) * D * D * X / 4.0 + (3.0 * L - X) * X * X);
    s[0] = -P * (L - X) * Y / I;
    s[1] = 0.0;
    s[2] = P / (2.0 * I) * (D * D / 4.0 - Y * Y);
  } else if (p->kind == ES_HOLE) {
    /* Kirsch, 000 eqs 127-129 (unit traction in x at infinity); the classical
     * displacements with the plane-stress kappa = (3 - nu)/(1 + nu) (docs/papers.md,
     * paper 000, choices 2). */
    const double a = p->a, r = hypot(x[0], x[1]), t = atan2(x[1], x[0]);
    const double a2 = a * a / (r * r), a4 = a2 * a2;
    s[0] = 1.0 - a2 * (1.5 * cos(2 * t) + cos(4 * t)) + 1.5 * a4 * cos(4 * t);
    s[1] = -a2 * (0.5 * cos(2 * t) - cos(4 * t)) - 1.5 * a4 * cos(4 * t);
    s[2] = -a2 * (0.5 * sin(2 * t) + sin(4 * t)) + 1.5 * a4 * sin(4 * t);
    const double mu = p->E / (2.0 * (1.0 + p->nu)), kap = (3.0 - p->nu) / (1.0 + p->nu);
    const double f = a / (8.0 * mu), ra = r / a, ar = a / r, ar3 = ar * ar * ar;
    d[0] = f * (ra * (kap + 1.0) * cos(t) + 2.0 * ar * ((1.0 + kap) * cos(t) + cos(3 * t)) -
                2.0 * ar3 * cos(3 * t));
    d[1] = f * (ra * (kap - 3.0) * sin(t) + 2.0 * ar * ((1.0 - kap) * sin(t) + sin(3 * t)) -
                2.0 * ar3 * sin(3 * t));
  } else {
    const double *c = p->c;
    d[0] = c[0] + c[1] * x[0] + c[2] * x[1];
    d[1] = c[3] + c[4] * x[0] + c[5] * x[1];
    const double e0 = c[1], e1 = c[5], g = c[2] + c[4], q = p->E / (1.0 - p->nu * p->nu);
    s[0] = q * (e0 + p->nu * e1);
    s[1] = q * (e1 + p->nu * e0);
    s[2] = q * 0.5 * (1.0 - p->nu) * g;
  }
  if (u) u[0] = d[0], u[1] = d[1];
  if (sig) memcpy(sig, s, sizeof s);
  if (eps) plane_stress_strain(p, s, eps);
}

/* ------------------------------------------------------------------------------------ */
/* Gauss-Legendre rule on [-1, 1] (Newton on P_n)                                         */
/* ------------------------------------------------------------------------------------ */

static void gauss_rule(int n, double *g, double *w) {
  for (int i = 0; i < n; ++i) {
    double z = cos(M_PI * (i + 0.75) / (n + 0.5)), dp = 1.0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1.0, p1 = z;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      if (n == 1) p0 = 1.0;
      dp = n * (z * p1 - p0) / (z * z - 1.0);
      const double dz = p1 / dp;
      z -= dz;
      if (fabs(dz) < 1e-15) break;
    }
    g[i] = -z;
    w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
  }
}

/* ------------------------------------------------------------------------------------ */
/* Voronoi volumes: the cell of each node clipped to the domain                           */
/* ------------------------------------------------------------------------------------ */

enum { MAXV = 256 };

/* Keep the part of polygon (v, nv) where nx*x + ny*y <= c (Sutherland-Hodgman). */
static int clip(double *v, int nv, double nx, double ny, double c) {
  double out[2 * MAXV];
  int no = 0;
  for (int i = 0; i < nv; ++i) {
    const double *a = v + 2 * i, *b = v + 2 * ((i + 1) % nv);
    const double fa = nx * a[0] + ny * a[1] - c, fb = nx * b[0] + ny * b[1] - c;
    if (fa <= 0.0 && no < MAXV) out[2 * no] = a[0], out[2 * no + 1] = a[1], ++no;
    if ((fa < 0.0 && fb > 0.0) || (fa > 0.0 && fb < 0.0)) {
      const double t = fa / (fa - fb);
      if (no < MAXV) {
        out[2 * no] = a[0] + t * (b[0] - a[0]);
        out[2 * no + 1] = a[1] + t * (b[1] - a[1]);
        ++no;
      }
    }
  }
  memcpy(v, out, sizeof(double) * 2 * no);
  return no;
}

static double poly_area(const double *v, int nv) {
  double s = 0.0;
  for (int i = 0; i < nv; ++i) {
    const double *a = v + 2 * i, *b = v + 2 * ((i + 1) % nv);
    s += a[0] * b[1] - a[1] * b[0];
  }
  return 0.5 * s;
}

/* Signed area of triangle (0, A, B) intersected with the disc |x| < R. */
static double tri_disc(const double *A, const double *B, double R) {
  const double dx = B[0] - A[0], dy = B[1] - A[1];
  const double qa = dx * dx + dy * dy, qb = 2.0 * (A[0] * dx + A[1] * dy),
               qc = A[0] * A[0] + A[1] * A[1] - R * R;
  double ts[4] = {0.0, 0.0, 0.0, 1.0};
  int nt = 1;
  const double disc = qb * qb - 4.0 * qa * qc;
  if (qa > 0.0 && disc > 0.0) {
    const double sq = sqrt(disc), t1 = (-qb - sq) / (2.0 * qa), t2 = (-qb + sq) / (2.0 * qa);
    if (t1 > 0.0 && t1 < 1.0) ts[nt++] = t1;
    if (t2 > 0.0 && t2 < 1.0) ts[nt++] = t2;
  }
  ts[nt++] = 1.0;
  double area = 0.0;
  for (int k = 0; k + 1 < nt; ++k) {
    const double p0[2] = {A[0] + ts[k] * dx, A[1] + ts[k] * dy};
    const double p1[2] = {A[0] + ts[k + 1] * dx, A[1] + ts[k + 1] * dy};
    const double tm = 0.5 * (ts[k] + ts[k + 1]);
    const double mx = A[0] + tm * dx, my = A[1] + tm * dy;
    const double cr = p0[0] * p1[1] - p0[1] * p1[0];
    if (mx * mx + my * my < R * R) area += 0.5 * cr;
    else area += 0.5 * R * R * atan2(cr, p0[0] * p1[0] + p0[1] * p1[1]);
  }
  return area;
}

/* Volumes of all nodes: Voronoi cells within the box [lo, hi], minus the disc of radius
 * hole_r at the origin (0: none). Neighbours within rc are enough for a quasi-uniform
 * cloud of spacing rc / 4. Sum = the domain's area. */
static void voronoi_volumes(int32_t n, const double *x, const double *lo, const double *hi,
                            double rc, double hole_r, double *vol) {
  for (int32_t i = 0; i < n; ++i) {
    double v[2 * MAXV] = {lo[0], lo[1], hi[0], lo[1], hi[0], hi[1], lo[0], hi[1]};
    int nv = 4;
    const double xi = x[2 * i], yi = x[2 * i + 1];
    for (int32_t j = 0; j < n && nv > 0; ++j) {
      if (j == i) continue;
      const double ex = x[2 * j] - xi, ey = x[2 * j + 1] - yi;
      if (ex * ex + ey * ey > rc * rc) continue;
      /* half plane closer to i: e . x <= e . midpoint */
      nv = clip(v, nv, ex, ey, ex * (xi + 0.5 * ex) + ey * (yi + 0.5 * ey));
    }
    double area = fabs(poly_area(v, nv));
    if (hole_r > 0.0 && nv > 0) {
      double in = 0.0;
      for (int k = 0; k < nv; ++k) in += tri_disc(v + 2 * k, v + 2 * ((k + 1) % nv), hole_r);
      area -= fabs(in);
    }
    vol[i] = area;
  }
}

/* ------------------------------------------------------------------------------------ */
/* Levels                                                                                 */
/* ------------------------------------------------------------------------------------ */

typedef struct {
  double *p;
  int32_t n, cap, width;
} grow_t;

static int push(grow_t *g, const double *v) {
  if (g->n == g->cap) {
    const int32_t cap = g->cap ? 2 * g->cap : 64;
    double *q = realloc(g->p, sizeof(double) * (size_t)cap * (size_t)g->width);
    if (!q) return 1;
    g->p = q;
    g->cap = cap;
  }
  memcpy(g->p + (size_t)g->n * (size_t)g->width, v, sizeof(double) * (size_t)g->width);
  ++g->n;
  return 0;
}

/* Indices of the nodes on a line (coordinate `along` varying, the other fixed at `at`),
 * sorted along it. */
static int line_nodes(const es_level_t *lv, int along, double at, double tol, int32_t *out) {
  int np = 0;
  for (int32_t i = 0; i < lv->n; ++i)
    if (fabs(lv->x[2 * i + 1 - along] - at) < tol) out[np++] = i;
  for (int a = 1; a < np; ++a) /* insertion sort along the line */
    for (int b = a; b > 0 && lv->x[2 * out[b] + along] < lv->x[2 * out[b - 1] + along]; --b) {
      const int32_t t = out[b];
      out[b] = out[b - 1];
      out[b - 1] = t;
    }
  return np;
}

/* Segments between consecutive nodes of a sorted boundary line. */
static int add_chain(const es_level_t *lv, grow_t *seg, grow_t *nrm, grow_t *msk, const int32_t *idx,
                     int np, double nx, double ny, int mask) {
  for (int k = 0; k + 1 < np; ++k) {
    const double *a = lv->x + 2 * idx[k], *b = lv->x + 2 * idx[k + 1];
    const double s[4] = {a[0], a[1], b[0], b[1]};
    const double nn[2] = {nx, ny}, m = mask;
    if (push(seg, s) || push(nrm, nn) || (msk && push(msk, &m))) return 1;
  }
  return 0;
}

/* Records an essential boundary line as a chain of node indices (FE-layer emulation). */
static int add_dchain(es_level_t *lv, const int32_t *idx, int np, double nx, double ny, int mask) {
  if (lv->nchain >= ES_MAXCHAIN) return 1;
  const int c = lv->nchain++;
  int32_t *p = realloc(lv->chain_nodes, sizeof(int32_t) * (size_t)(lv->chain_start[c] + np));
  if (!p) return 1;
  lv->chain_nodes = p;
  memcpy(p + lv->chain_start[c], idx, sizeof(int32_t) * (size_t)np);
  lv->chain_start[c + 1] = lv->chain_start[c] + np;
  lv->chain_nrm[2 * c] = nx;
  lv->chain_nrm[2 * c + 1] = ny;
  lv->chain_mask[c] = mask;
  return 0;
}

/* Tensor Gauss points on a structured cell grid over [lo, hi]. */
static int cell_points(const double *lo, const double *hi, const int32_t *nc, int ng,
                       grow_t *xq, grow_t *wq) {
  double g[32], w[32];
  gauss_rule(ng, g, w);
  const double hx = (hi[0] - lo[0]) / nc[0], hy = (hi[1] - lo[1]) / nc[1];
  for (int32_t cx = 0; cx < nc[0]; ++cx)
    for (int32_t cy = 0; cy < nc[1]; ++cy)
      for (int a = 0; a < ng; ++a)
        for (int b = 0; b < ng; ++b) {
          const double p[2] = {lo[0] + hx * (cx + 0.5 * (1.0 + g[a])),
                               lo[1] + hy * (cy + 0.5 * (1.0 + g[b]))};
          const double wt = 0.25 * hx * hy * w[a] * w[b];
          if (push(xq, p) || push(wq, &wt)) return 1;
        }
  return 0;
}

/* Gauss points on the quarter plate [0, b]^2 minus the disc of radius a: two blocks
 * split by the diagonal, each the ruled map between the arc and the outer edge,
 * x(xi, eta) = (1 - eta) a (cos t, sin t) + eta (b, b tan t), t = xi pi/4 (block A,
 * next to x = b; block B is its mirror image in the diagonal). The arc is exact. */
static int hole_points(double a, double b, int32_t nxi, int32_t neta, const double *etas, int ng,
                       grow_t *xq, grow_t *wq) {
  double g[32], w[32];
  gauss_rule(ng, g, w);
  for (int32_t ci = 0; ci < nxi; ++ci)
    for (int32_t cj = 0; cj < neta; ++cj)
      for (int qa = 0; qa < ng; ++qa)
        for (int qb = 0; qb < ng; ++qb) {
          /* eta from the cell edges etas (NULL: uniform) */
          const double e0 = etas ? etas[cj] : (double)cj / neta, e1 = etas ? etas[cj + 1] : (cj + 1.0) / neta;
          const double xi = (ci + 0.5 * (1.0 + g[qa])) / nxi, eta = e0 + 0.5 * (1.0 + g[qb]) * (e1 - e0);
          const double t = xi * M_PI / 4.0, ct = cos(t), st = sin(t), tt = tan(t);
          const double X = (1.0 - eta) * a * ct + eta * b, Y = (1.0 - eta) * a * st + eta * b * tt;
          const double x_xi = M_PI / 4.0 * (-(1.0 - eta) * a * st);
          const double y_xi = M_PI / 4.0 * ((1.0 - eta) * a * ct + eta * b / (ct * ct));
          const double x_eta = b - a * ct, y_eta = b * tt - a * st;
          const double J = fabs(x_xi * y_eta - x_eta * y_xi);
          const double wt = J * 0.25 * w[qa] * w[qb] * (e1 - e0) / (double)nxi;
          const double pa[2] = {X, Y}, pb[2] = {Y, X};
          if (push(xq, pa) || push(wq, &wt) || push(xq, pb) || push(wq, &wt)) return 1;
        }
  return 0;
}

/* Gauss points (4 per interval) on the straight boundary line through the nodes of a
 * sorted line, with outward normal (nx, ny). */
static int boundary_line(const es_level_t *lv, const int32_t *idx, int np, double nx, double ny, grow_t *bx,
                         grow_t *bw, grow_t *bn) {
  double g[4], w[4];
  gauss_rule(4, g, w);
  const double nn[2] = {nx, ny};
  for (int k = 0; k + 1 < np; ++k) {
    const double *a = lv->x + 2 * idx[k], *b = lv->x + 2 * idx[k + 1];
    const double len = hypot(b[0] - a[0], b[1] - a[1]);
    for (int q = 0; q < 4; ++q) {
      const double t = 0.5 * (1.0 + g[q]), pt[2] = {a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])};
      const double wt = 0.5 * len * w[q];
      if (push(bx, pt) || push(bw, &wt) || push(bn, nn)) return 1;
    }
  }
  return 0;
}

/* Deterministic uniform numbers in [0, 1) for the irregular patch cloud. */
static double rnd(uint64_t *s) {
  *s ^= *s >> 12;
  *s ^= *s << 25;
  *s ^= *s >> 27;
  return (double)((*s * 2685821657736338717ULL) >> 11) / 9007199254740992.0;
}

const char *es_nodes_text(int kind) {
  switch (kind) {
    case ES_BEAM:
      return "regular grid, dx = dy";
    case ES_HOLE:
      return "regular grid of spacing dx on [0,5]^2 without the nodes at r < a + dx/2, plus "
             "nodes on the arc r = a at arc spacing <= dx (quasi-uniform, non-uniform next "
             "to the hole)";
    default:
      return "9 x 9 grid on [0,1]^2, every node moved by up to dx/4 (boundary nodes along "
             "their edge, corners fixed)";
  }
}

int32_t es_beam_ny(const es_problem_t *p, int k) {
  /* sqrt 2 steps: 2^j + 1 and 1.5 2^j + 1 alternate, so that dx / D = 1/2, 1/3, 1/4,
   * 1/6, 1/8, ... and L / dx stays an integer */
  static const int32_t kSqrt2[] = {3, 4, 5, 7, 9, 13, 17, 25, 33, 49, 65};
  if (k < 0) return 0;
  if (p->beam_dyadic) return k <= 8 ? (1 << (k + 1)) + 1 : 0;
  return k < (int)(sizeof kSqrt2 / sizeof kSqrt2[0]) ? kSqrt2[k] : 0;
}

int es_level_build(const es_problem_t *p, int k, int ngauss, es_level_t *lv) {
  memset(lv, 0, sizeof *lv);
  grow_t X = {NULL, 0, 0, 2}, DS = {NULL, 0, 0, 4}, DN = {NULL, 0, 0, 2}, DM = {NULL, 0, 0, 1};
  grow_t TS = {NULL, 0, 0, 4}, TN = {NULL, 0, 0, 2}, XQ = {NULL, 0, 0, 2}, WQ = {NULL, 0, 0, 1};
  grow_t BX = {NULL, 0, 0, 2}, BW = {NULL, 0, 0, 1}, BN = {NULL, 0, 0, 2};
  grow_t HN = {NULL, 0, 0, 1};
  double *etas = NULL;
  int32_t mblk = 0, nring = 0;
  double lo[2], hi[2];
  int fail = 0;
  if (p->kind == ES_BEAM) {
    const int32_t ny = es_beam_ny(p, k);
    if (ny < 2) return 1;
    const double dx = p->D / (ny - 1);
    const int32_t nx = (int32_t)lround(p->L / dx) + 1;
    lv->dx = dx;
    for (int32_t i = 0; i < nx; ++i)
      for (int32_t j = 0; j < ny; ++j) {
        const double q[2] = {i * dx, -0.5 * p->D + j * dx};
        fail |= push(&X, q);
      }
    lo[0] = 0.0, lo[1] = -0.5 * p->D, hi[0] = p->L, hi[1] = 0.5 * p->D;
    lv->cells = 1;
    lv->ncells[0] = nx - 1;
    lv->ncells[1] = ny - 1;
  } else if (p->kind == ES_HOLE) {
    /* m = 10, 14, 20, 28, 40, 56, 80, ... intervals along an edge: dx falls by about
     * sqrt(2) per level, so that more levels fit in the same time */
    const int32_t m = 2 * (int32_t)lround(5.0 * pow(sqrt(2.0), k));
    const double dx = p->b / m, a = p->a, b = p->b;
    lv->dx = dx;
    const int32_t narc = p->mapped ? 0 : (int32_t)ceil(0.5 * M_PI * a / dx);
    if (p->mapped == 2) {
      /* graded: mblk = m / 2 intervals along the hole per block (dtheta = pi / (4 mblk)),
       * rings growing geometrically from a dtheta on the axes so that the cells stay
       * about square (r_{k+1} ~ r_k (1 + dtheta)); supports s_I = sqrt(2) times the
       * larger local spacing (000 eq 130 read locally) */
      mblk = m / 2;
      const double dth = 0.25 * M_PI / mblk;
      nring = 1 + (int32_t)lround(log(b / a) / log(1.0 + dth));
      etas = malloc(sizeof(double) * (size_t)nring);
      if (!etas) goto oom;
      double lo_g = 1.0 + 1e-9, hi_g = 3.0;
      for (int it = 0; it < 200; ++it) { /* a dth (g^(nring-1) - 1) / (g - 1) = b - a */
        const double gg = 0.5 * (lo_g + hi_g);
        if (a * dth * (pow(gg, nring - 1) - 1.0) / (gg - 1.0) > b - a) hi_g = gg;
        else lo_g = gg;
      }
      const double gg = 0.5 * (lo_g + hi_g);
      etas[0] = 0.0;
      for (int32_t j = 1; j < nring; ++j) etas[j] = etas[j - 1] + a * dth * pow(gg, j - 1) / (b - a);
      for (int32_t j = 1; j < nring; ++j) etas[j] /= etas[nring - 1];
      etas[nring - 1] = 1.0;
      for (int blk = 0; blk < 2; ++blk)
        for (int32_t i = 0; i <= mblk - blk; ++i)
          for (int32_t j = 0; j < nring; ++j) {
            double q[2], r[2];
            for (int di = 0; di <= 1; ++di) { /* the node and its neighbour along the ring */
              const double t = 0.25 * M_PI * (i + di) / mblk, eta = etas[j];
              double *o = di ? r : q;
              o[0] = (1.0 - eta) * a * cos(t) + eta * b;
              o[1] = (1.0 - eta) * a * sin(t) + eta * b * tan(t);
            }
            double hh = hypot(r[0] - q[0], r[1] - q[1]);
            {
              const double t = 0.25 * M_PI * i / mblk, len = hypot(b - a * cos(t), b * tan(t) - a * sin(t));
              const double dr = len * (j == 0 ? etas[1] : j == nring - 1 ? 1.0 - etas[j - 1]
                                                                        : 0.5 * (etas[j + 1] - etas[j - 1]));
              hh = sqrt(2.0) * fmax(hh, dr);
            }
            if (i == 0) q[1] = 0.0;
            if (j == nring - 1) q[0] = b;
            if (i == mblk) q[1] = q[0];
            if (blk) {
              const double tmp = q[0];
              q[0] = q[1], q[1] = tmp;
            }
            fail |= push(&X, q) || push(&HN, &hh);
          }
    } else if (p->mapped) {
      /* the ruled map of hole_points with m intervals along each outer edge and
       * round(0.8 m) across: spacing dx at the outer edges, a pi / (4 m) along the hole */
      const int32_t neta = (int32_t)lround((b - a) / dx);
      for (int blk = 0; blk < 2; ++blk)
        for (int32_t i = 0; i <= m - blk; ++i)
          for (int32_t j = 0; j <= neta; ++j) {
            const double t = 0.25 * M_PI * i / m, eta = (double)j / neta;
            double q[2] = {(1.0 - eta) * a * cos(t) + eta * b, (1.0 - eta) * a * sin(t) + eta * b * tan(t)};
            if (i == 0) q[1] = 0.0;
            if (j == neta) q[0] = b;
            if (i == m) q[1] = q[0];
            if (blk) {
              const double tmp = q[0];
              q[0] = q[1], q[1] = tmp;
            }
            fail |= push(&X, q);
          }
    }
    for (int32_t q = 0; q <= narc && !p->mapped; ++q) {
      const double t = 0.5 * M_PI * q / narc;
      double pt[2] = {a * cos(t), a * sin(t)};
      if (q == 0) pt[1] = 0.0; /* exactly on the symmetry lines */
      if (q == narc) pt[0] = 0.0;
      fail |= push(&X, pt);
    }
    for (int32_t i = 0; i <= m && !p->mapped; ++i)
      for (int32_t j = 0; j <= m; ++j) {
        const double q[2] = {i * dx, j * dx};
        if (hypot(q[0], q[1]) >= a + 0.5 * dx) fail |= push(&X, q);
      }
    lo[0] = lo[1] = 0.0, hi[0] = hi[1] = b;
  } else {
    const int32_t m = 8;
    const double dx = 1.0 / m;
    uint64_t seed = 0x9e3779b97f4a7c15ULL;
    lv->dx = dx;
    for (int32_t i = 0; i <= m; ++i)
      for (int32_t j = 0; j <= m; ++j) {
        double q[2] = {i * dx, j * dx};
        const double rx = (rnd(&seed) - 0.5) * 0.5 * dx, ry = (rnd(&seed) - 0.5) * 0.5 * dx;
        if (i > 0 && i < m) q[0] += rx;
        if (j > 0 && j < m) q[1] += ry;
        fail |= push(&X, q);
      }
    lo[0] = lo[1] = 0.0, hi[0] = hi[1] = 1.0;
    lv->cells = 1;
    lv->ncells[0] = lv->ncells[1] = m;
  }
  if (fail) goto oom;
  lv->n = X.n;
  lv->x = X.p;
  X.p = NULL;
  lv->h = sqrt(2.0) * lv->dx; /* 000 eqs 126 and 130 */
  memcpy(lv->lo, lo, sizeof lo);
  memcpy(lv->hi, hi, sizeof hi);
  lv->vol = malloc(sizeof(double) * (size_t)lv->n);
  lv->dmask = calloc((size_t)lv->n, sizeof(int32_t));
  int32_t *line = malloc(sizeof(int32_t) * (size_t)lv->n);
  if (!lv->vol || !lv->dmask || !line) {
    free(line);
    goto oom;
  }
  voronoi_volumes(lv->n, lv->x, lo, hi, 4.0 * lv->dx, p->kind == ES_HOLE ? p->a : 0.0, lv->vol);

  const double tol = 1e-9 * (hi[0] - lo[0]);
  int np;
  if (p->kind == ES_BEAM) {
    /* x = 0: exact displacements, both components; x = L: traction from the exact stress */
    for (int32_t i = 0; i < lv->n; ++i)
      if (fabs(lv->x[2 * i]) < tol) lv->dmask[i] = 3;
    np = line_nodes(lv, 1, 0.0, tol, line);
    fail |= add_chain(lv, &DS, &DN, &DM, line, np, -1.0, 0.0, 3) | add_dchain(lv, line, np, -1.0, 0.0, 3);
    fail |= boundary_line(lv, line, np, -1.0, 0.0, &BX, &BW, &BN);
    np = line_nodes(lv, 1, p->L, tol, line);
    fail |= add_chain(lv, &TS, &TN, NULL, line, np, 1.0, 0.0, 0);
    fail |= boundary_line(lv, line, np, 1.0, 0.0, &BX, &BW, &BN);
    np = line_nodes(lv, 0, -0.5 * p->D, tol, line);
    fail |= boundary_line(lv, line, np, 0.0, -1.0, &BX, &BW, &BN);
    np = line_nodes(lv, 0, 0.5 * p->D, tol, line);
    fail |= boundary_line(lv, line, np, 0.0, 1.0, &BX, &BW, &BN);
    fail |= cell_points(lo, hi, lv->ncells, ngauss, &XQ, &WQ);
  } else if (p->kind == ES_HOLE) {
    /* symmetry: u_y = 0 on y = 0, u_x = 0 on x = 0; Kirsch tractions on x = b, y = b */
    for (int32_t i = 0; i < lv->n; ++i) {
      if (fabs(lv->x[2 * i + 1]) < tol) lv->dmask[i] |= 2;
      if (fabs(lv->x[2 * i]) < tol) lv->dmask[i] |= 1;
    }
    np = line_nodes(lv, 0, 0.0, tol, line);
    fail |= add_chain(lv, &DS, &DN, &DM, line, np, 0.0, -1.0, 2) | add_dchain(lv, line, np, 0.0, -1.0, 2);
    fail |= boundary_line(lv, line, np, 0.0, -1.0, &BX, &BW, &BN);
    np = line_nodes(lv, 1, 0.0, tol, line);
    fail |= add_chain(lv, &DS, &DN, &DM, line, np, -1.0, 0.0, 1) | add_dchain(lv, line, np, -1.0, 0.0, 1);
    fail |= boundary_line(lv, line, np, -1.0, 0.0, &BX, &BW, &BN);
    np = line_nodes(lv, 1, p->b, tol, line);
    fail |= add_chain(lv, &TS, &TN, NULL, line, np, 1.0, 0.0, 0);
    fail |= boundary_line(lv, line, np, 1.0, 0.0, &BX, &BW, &BN);
    np = line_nodes(lv, 0, p->b, tol, line);
    fail |= add_chain(lv, &TS, &TN, NULL, line, np, 0.0, 1.0, 0);
    fail |= boundary_line(lv, line, np, 0.0, 1.0, &BX, &BW, &BN);
    {
      /* the arc r = a, 4 Gauss points in the angle per arc interval of the nodes */
      const int32_t narc = (int32_t)ceil(0.5 * M_PI * p->a / lv->dx);
      double g[4], w[4];
      gauss_rule(4, g, w);
      for (int32_t q = 0; q < narc; ++q)
        for (int k = 0; k < 4; ++k) {
          const double t = 0.5 * M_PI * (q + 0.5 * (1.0 + g[k])) / narc;
          const double pt[2] = {p->a * cos(t), p->a * sin(t)}, nn[2] = {-cos(t), -sin(t)};
          const double wt = 0.5 * (0.5 * M_PI * p->a / narc) * w[k];
          fail |= push(&BX, pt) || push(&BW, &wt) || push(&BN, nn);
        }
    }
    const int32_t nxi = (int32_t)lround(p->b / lv->dx), neta = (int32_t)lround((p->b - p->a) / lv->dx);
    if (etas) /* graded: cells = the node grid of each block */
      fail |= hole_points(p->a, p->b, mblk, nring - 1, etas, ngauss, &XQ, &WQ);
    else
      fail |= hole_points(p->a, p->b, nxi, neta, NULL, ngauss, &XQ, &WQ);
  } else {
    /* the whole boundary is essential */
    for (int32_t i = 0; i < lv->n; ++i) {
      const double *q = lv->x + 2 * i;
      if (fabs(q[0]) < tol || fabs(q[1]) < tol || fabs(q[0] - 1.0) < tol || fabs(q[1] - 1.0) < tol)
        lv->dmask[i] = 3;
    }
    np = line_nodes(lv, 0, 0.0, tol, line);
    fail |= add_chain(lv, &DS, &DN, &DM, line, np, 0.0, -1.0, 3) | add_dchain(lv, line, np, 0.0, -1.0, 3);
    fail |= boundary_line(lv, line, np, 0.0, -1.0, &BX, &BW, &BN);
    np = line_nodes(lv, 0, 1.0, tol, line);
    fail |= add_chain(lv, &DS, &DN, &DM, line, np, 0.0, 1.0, 3) | add_dchain(lv, line, np, 0.0, 1.0, 3);
    fail |= boundary_line(lv, line, np, 0.0, 1.0, &BX, &BW, &BN);
    np = line_nodes(lv, 1, 0.0, tol, line);
    fail |= add_chain(lv, &DS, &DN, &DM, line, np, -1.0, 0.0, 3) | add_dchain(lv, line, np, -1.0, 0.0, 3);
    fail |= boundary_line(lv, line, np, -1.0, 0.0, &BX, &BW, &BN);
    np = line_nodes(lv, 1, 1.0, tol, line);
    fail |= add_chain(lv, &DS, &DN, &DM, line, np, 1.0, 0.0, 3) | add_dchain(lv, line, np, 1.0, 0.0, 3);
    fail |= boundary_line(lv, line, np, 1.0, 0.0, &BX, &BW, &BN);
    fail |= cell_points(lo, hi, lv->ncells, ngauss, &XQ, &WQ);
  }
  free(line);
  if (fail) goto oom;
  lv->nds = DS.n;
  lv->dseg = DS.p;
  lv->dnrm = DN.p;
  lv->dsmask = malloc(sizeof(int32_t) * (size_t)(DS.n ? DS.n : 1));
  if (!lv->dsmask) goto oom;
  for (int32_t s = 0; s < DS.n; ++s) lv->dsmask[s] = (int32_t)DM.p[s];
  free(DM.p);
  lv->nts = TS.n;
  lv->tseg = TS.p;
  lv->tnrm = TN.p;
  lv->nq = XQ.n;
  lv->xq = XQ.p;
  lv->wq = WQ.p;
  lv->nbp = BX.n;
  lv->bpx = BX.p;
  lv->bpw = BW.p;
  lv->bpn = BN.p;
  free(etas);
  if (HN.p) {
    /* per-node supports; each background point takes its nearest node's */
    lv->hn = HN.p;
    lv->hq = malloc(sizeof(double) * (size_t)(lv->nq ? lv->nq : 1));
    if (!lv->hq) {
      es_level_free(lv);
      return 1;
    }
    for (int32_t q = 0; q < lv->nq; ++q) {
      double best = HUGE_VAL;
      for (int32_t i = 0; i < lv->n; ++i) {
        const double d = hypot(lv->xq[2 * q] - lv->x[2 * i], lv->xq[2 * q + 1] - lv->x[2 * i + 1]);
        if (d < best) best = d, lv->hq[q] = lv->hn[i];
      }
    }
  }
  return 0;
oom:
  free(etas), free(HN.p);
  free(X.p), free(DM.p), free(TS.p), free(TN.p), free(XQ.p), free(WQ.p), free(BX.p), free(BW.p), free(BN.p);
  if (lv->dseg != DS.p) free(DS.p);
  if (lv->dnrm != DN.p) free(DN.p);
  es_level_free(lv);
  return 1;
}

void es_level_free(es_level_t *lv) {
  free(lv->x), free(lv->vol), free(lv->dmask), free(lv->dseg), free(lv->dnrm), free(lv->dsmask);
  free(lv->tseg), free(lv->tnrm), free(lv->xq), free(lv->wq), free(lv->chain_nodes);
  free(lv->bpx), free(lv->bpw), free(lv->bpn);
  free(lv->hn), free(lv->hq);
  memset(lv, 0, sizeof *lv);
}
