/* Plate with a circular hole by SSPH/MSPH collocation (paper 001 Sect. 6.3); see plate.h.
 *
 * Particle arrangement (the paper's Figs. 10, 11 and 13 are not available,
 * docs/papers.md, paper 001, choices 5): rings refined towards the hole.
 *  - Rays: for t in [0, 1], the straight line from the hole point
 *    H(t) = a (cos(pi t/2), sin(pi t/2)) to the point P(t) of the outer edges (x = b,
 *    then y = b) at the fraction t of their length; P(1/2) is the corner (b, b).
 *  - Rings: ring k is the curve H + s_k (P - H), t in [0, 1]. The fractions s_k grow
 *    geometrically, the first radial spacing on the axes being radial_step times the
 *    spacing a dtheta = a pi / (2 (nt - 1)) of the nt particles on the quarter hole,
 *    with nr = plate_rings(a, b, nt) rings (with radial_step 1 they grow like
 *    r_{k+1} = r_k (1 + dtheta) on the axes: square cells there). The default
 *    radial_step 0.6 makes a radially refined layer at the hole, steeper grading
 *    outwards: the rings' first gap is 1.46 times larger at 45 degrees than on the
 *    axes, and with square cells on the axes the hole particles at 45 degrees
 *    (h_i = 1.5 Delta_i set by the hole spacing) reach only one ring inwards, so the
 *    normal curvature of the quadratic fits that their traction rows use comes from the
 *    hole's own curvature; with 0.6 they reach two rings (t650 has the measurements:
 *    SSPH below MSPH at every resolution only then).
 *  - Particles on ring k > 0: spaced along the ring like the rings are spaced across it
 *    (equal increments of the ring's arc length divided by the local ring spacing), with
 *    a particle on both ends and on t = 1/2, so the arrangement is symmetric about the
 *    diagonal and the corner (b, b) carries a particle. The number of particles per ring
 *    thus grows outwards ("coarser away from the hole" in the paper's words, yet with
 *    cells of aspect about 1 away from the hole). A plain nt x nr tensor arrangement was tried
 *    first: its cells get long and thin towards the outer edges, and with
 *    h_i = 1.5 Delta_i (Delta_i the nearest distance) some supports then hold only two
 *    lines of particles, on which a quadratic basis is singular (setup reports it).
 *  - With b = 10 a: nt = 11 gives 17 rings and 203 particles (the paper: 188 with 11 on
 *    the quarter hole), nt = 21 gives 31 rings and 679 particles (the paper: 686 with 21);
 *    with radial_step 1, 209 and 677.
 *
 * PLATE_LAYOUT_RAYS, the ruled arrangement that the paper's counts suggest (188 =
 * 11 x 17 + 1, 686 ~ 21 x 33; "coarser away from the hole"): nt straight rays from the
 * hole points H(t_j), t_j = j/(nt - 1), to the points P(t_j) of the outer edges above
 * (equally spaced along them, the middle ray ending at the corner (b, b)), nr particles
 * on each ray with geometric spacing whose first step is the spacing a dtheta on the
 * hole (square cells at the hole), so nt x nr particles. PLATE_LAYOUT_POLAR is the same
 * with radial rays theta_j = pi t_j / 2 ending where they meet x = b or y = b. Volumes: a
 * quarter of each adjacent quadrilateral (ray j, j + 1 by particle k, k + 1), so they
 * sum to the area of the polygonal model. On the standard plate of paper 000 (b = 5 a)
 * the rays' cells are long across the rays near the outer edges (spacing 2 b/(nt - 1)
 * there against (b - a)/(nr - 1) on average along them), so with h_i = 1.5 Delta_i some
 * supports reach only two rays and the quadratic fit is singular; no geometric grading
 * helps (a coarser end needs a finer start, and then the supports at the hole reach only
 * one ray). 11 x 17 first works from b = 9 a, 21 x 33 from b = 10 a; with square cells
 * along the whole axis the 17 particles of 11 rays reach (1 + pi/20)^16 a = 10.3 a.
 *
 * Volumes: spacing along the ring times the spacing across the rings, halved on the
 * boundary. Supports: h_i = hfac Delta_i, Delta_i the distance from particle i to its
 * nearest neighbour (001 Sect. 6.3 takes the smallest distance to the other particles of
 * the support; the nearest particle always lies in the support 2 h_i = 3 Delta_i, so the
 * two readings agree: docs/papers.md, paper 001, choices 6); gather search with
 * kappa = 2 (the kernel support is 2 h_i), W_ij = W(x_i - x_j, h_i) as in 001 eq 3.3
 * (cfg->search can make it
 * symmetric, a measurement only).
 *
 * Boundary rows (001 Sect. 6.3, boundaries 1-5; mixed conditions as in (6.24)/(6.25)):
 *  - hole r = a: traction rows sigma n = 0 for both components, n = -(x, y)/a (the
 *    outward normal of the body, pointing into the hole);
 *  - y = 0: u_2 = 0 (a Dirichlet row) and t_1 = 0 (the traction row with n = (0, -1)
 *    for component 1; the library lets the Dirichlet row win for component 2);
 *  - x = 0: u_1 = 0 and t_2 = 0 (n = (-1, 0));
 *  - x = b, y = b: exact Kirsch tractions sigma n with n = (1, 0), (0, 1), and at the
 *    corner (b, b) n = (1, 1)/sqrt 2 (the exact stress makes any normal consistent);
 *  - the four corners of the model: (a, 0) hole traction t_1 = 0 and u_2 = 0; (0, a)
 *    hole traction t_2 = 0 and u_1 = 0; (b, 0) exact t_1 on x = b and u_2 = 0; (0, b)
 *    exact t_2 on y = b and u_1 = 0: one rule at every corner on a symmetry line, its
 *    displacement condition and the other boundary's traction for the other component
 *    (PLATE_CORNER_DIRICHLET; the paper does not say, docs/papers.md, paper 001, choices 7). The alternatives at the
 *    hole corners, PLATE_CORNER_SYMMETRY (u_n = 0 and sigma_12 = 0 of the symmetry line)
 *    and PLATE_CORNER_HOLE (both hole tractions), are there to measure the choice.
 * Interior particles carry the two Navier equations (6.22). */
#define _POSIX_C_SOURCE 200809L
#include "plate.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <mfree_suitesparse.h>

static const double kPi = 3.14159265358979323846;

void plate_config_default(plate_config_t *cfg, int nt, int nr) {
  cfg->a = 1.0;
  cfg->b = 10.0;
  cfg->nt = nt;
  cfg->nr = nr > 0 ? nr : plate_rings(1.0, 10.0, nt);
  cfg->method = MFREE_METHOD_SSPH;
  cfg->young = 1.0;
  cfg->poisson = 0.25;
  cfg->sigma0 = 1.0;
  cfg->kernel_param = 1.6;
  cfg->hfac = 1.5;
  cfg->radial_step = 0.6;
  cfg->layout = PLATE_LAYOUT_RINGS;
  cfg->hole_corner = PLATE_CORNER_DIRICHLET;
  cfg->search = MFREE_SEARCH_GATHER;
  cfg->patch = 0;
}

int plate_ray_particles(int nt) { return 1 + 8 * (nt - 1) / 5; }

int plate_rings(double a, double b, int nt) {
  const double dtheta = 0.5 * kPi / (nt - 1);
  return 1 + (int)lround(log(b / a) / log(1.0 + dtheta));
}

/* ---- Kirsch solution ------------------------------------------------------------------ */

void plate_kirsch_stress(double a, double sigma0, double x, double y, double s[3]) {
  const double r2 = x * x + y * y, th = atan2(y, x);
  const double q2 = a * a / r2, q4 = q2 * q2;
  const double c2 = cos(2 * th), c4 = cos(4 * th), s2 = sin(2 * th), s4 = sin(4 * th);
  s[0] = sigma0 * (1.0 - q2 * (1.5 * c2 + c4) + 1.5 * q4 * c4);
  s[1] = sigma0 * (-q2 * (0.5 * c2 - c4) - 1.5 * q4 * c4);
  s[2] = sigma0 * (-q2 * (0.5 * s2 + s4) + 1.5 * q4 * s4);
}

void plate_kirsch_displacement(double a, double sigma0, double young, double poisson,
                               double x, double y, double u[2]) {
  const double mu = young / (2.0 * (1.0 + poisson)), kappa = 3.0 - 4.0 * poisson;
  const double r = sqrt(x * x + y * y), th = atan2(y, x);
  const double f = sigma0 * a / (8.0 * mu), ar = a / r, ar3 = ar * ar * ar;
  u[0] = f * (r / a * (kappa + 1.0) * cos(th) +
              2.0 * ar * ((1.0 + kappa) * cos(th) + cos(3 * th)) - 2.0 * ar3 * cos(3 * th));
  u[1] = f * (r / a * (kappa - 3.0) * sin(th) +
              2.0 * ar * ((1.0 - kappa) * sin(th) + sin(3 * th)) - 2.0 * ar3 * sin(3 * th));
}

/* ---- particles ------------------------------------------------------------------------ */

/* Geometric growth g of the radial spacing: d1 (g^m - 1)/(g - 1) = len. */
static double grading(double d1, int m, double len) {
  double lo = 0.05, hi = 20.0;
  for (int it = 0; it < 200; ++it) {
    const double g = 0.5 * (lo + hi);
    const double sum = fabs(g - 1.0) < 1e-12 ? d1 * m : d1 * (pow(g, m) - 1.0) / (g - 1.0);
    if (sum > len) hi = g;
    else lo = g;
  }
  return 0.5 * (lo + hi);
}

static double seconds(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Ring k is the curve C(s_k, t), t in [0, 1], between the hole (s = 0) and the outer
 * edges (s = 1); see the top of this file. */
static void ring_point(const plate_config_t *cfg, double s, double t, double p[2]) {
  const double a = cfg->a, b = cfg->b;
  double H[2] = {a * cos(0.5 * kPi * t), a * sin(0.5 * kPi * t)}, P[2];
  if (t <= 0.0) H[0] = a, H[1] = 0.0;
  if (t >= 1.0) H[0] = 0.0, H[1] = a;
  if (t < 0.5) P[0] = b, P[1] = 2.0 * t * b;
  else if (t == 0.5) P[0] = b, P[1] = b;
  else P[0] = 2.0 * (1.0 - t) * b, P[1] = b;
  if (s <= 0.0) p[0] = H[0], p[1] = H[1];
  else if (s >= 1.0) p[0] = P[0], p[1] = P[1];
  else p[0] = H[0] + s * (P[0] - H[0]), p[1] = H[1] + s * (P[1] - H[1]);
}

/* Length of the ray from the hole to the outer edges at parameter t. */
static double ray_length(const plate_config_t *cfg, double t) {
  double H[2], P[2];
  ring_point(cfg, 0.0, t, H);
  ring_point(cfg, 1.0, t, P);
  return hypot(P[0] - H[0], P[1] - H[1]);
}

/* h_i = hfac Delta_i, Delta_i the distance to the nearest other particle (O(n^2): the
 * example's sizes are small). */
static void nearest_supports(int n, const double *x, double hfac, double *h) {
  for (int i = 0; i < n; ++i) {
    double dmin = INFINITY;
    for (int j = 0; j < n; ++j) {
      if (j == i) continue;
      const double d = hypot(x[2 * j] - x[2 * i], x[2 * j + 1] - x[2 * i + 1]);
      if (d < dmin) dmin = d;
    }
    h[i] = hfac * dmin;
  }
}

/* Twice the signed area of the triangle (p, q, r). */
static double area2(const double *p, const double *q, const double *r) {
  return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]);
}

/* The ruled arrangement PLATE_LAYOUT_RAYS (see the top of this file): nt rays, nr
 * particles on each, stored ring by ring (index k nt + j, k along the ray, j the ray). */
static int rays_particles(const plate_config_t *cfg, int *nout, double **xout, double **vout,
                          double **hout, int32_t **tagout) {
  const int nt = cfg->nt, nr = cfg->nr, n = nt * nr;
  const double a = cfg->a;
  double *x = malloc(sizeof(double) * 2 * (size_t)n), *v = calloc((size_t)n, sizeof(double));
  double *h = malloc(sizeof(double) * (size_t)n);
  int32_t *tag = malloc(sizeof(int32_t) * (size_t)n);
  if (!x || !v || !h || !tag) {
    free(x), free(v), free(h), free(tag);
    return 1;
  }
  const double d1 = a * kPi / (2.0 * (nt - 1)); /* the particle spacing on the hole */
  for (int j = 0; j < nt; ++j) {
    const double t = (double)j / (nt - 1), th = 0.5 * kPi * t;
    const double c = j == nt - 1 ? 0.0 : cos(th), sn = j == 0 ? 0.0 : sin(th);
    const double len = cfg->layout == PLATE_LAYOUT_POLAR ? cfg->b / fmax(c, sn) - a : ray_length(cfg, t);
    /* geometric spacing along the ray from d1 at the hole: square cells at the hole */
    const double g = grading(d1, nr - 1, len);
    double s = 0.0;
    for (int k = 0; k < nr; ++k) {
      if (cfg->layout == PLATE_LAYOUT_POLAR) {
        const double r = k == nr - 1 ? a + len : a + s;
        x[2 * (k * nt + j)] = r * c, x[2 * (k * nt + j) + 1] = r * sn;
        if (k == nr - 1 && 2 * j <= nt - 1) x[2 * (k * nt + j)] = cfg->b;
        if (k == nr - 1 && 2 * j >= nt - 1) x[2 * (k * nt + j) + 1] = cfg->b;
      } else {
        ring_point(cfg, k == nr - 1 ? 1.0 : s / len, t, &x[2 * (k * nt + j)]);
      }
      s += d1 * pow(g, k);
      tag[k * nt + j] = (k == 0 ? PLATE_HOLE : 0) | (j == 0 ? PLATE_SYM_Y0 : 0) |
                        (j == nt - 1 ? PLATE_SYM_X0 : 0) |
                        (k == nr - 1 && 2 * j <= nt - 1 ? PLATE_EDGE_XB : 0) |
                        (k == nr - 1 && 2 * j >= nt - 1 ? PLATE_EDGE_YB : 0);
    }
  }
  /* volumes: a quarter of each adjacent quadrilateral cell (they sum to the area of the
   * polygonal model) */
  for (int k = 0; k + 1 < nr; ++k)
    for (int j = 0; j + 1 < nt; ++j) {
      const int c[4] = {k * nt + j, k * nt + j + 1, (k + 1) * nt + j + 1, (k + 1) * nt + j};
      const double area = 0.5 * fabs(area2(&x[2 * c[0]], &x[2 * c[1]], &x[2 * c[2]]) +
                                     area2(&x[2 * c[0]], &x[2 * c[2]], &x[2 * c[3]]));
      for (int q = 0; q < 4; ++q) v[c[q]] += 0.25 * area;
    }
  nearest_supports(n, x, cfg->hfac, h);
  *nout = n;
  *xout = x;
  *vout = v;
  *hout = h;
  *tagout = tag;
  return 0;
}

enum { NTAB = 2000 }; /* subintervals of the half ring for the particle count */

int plate_particles(const plate_config_t *cfg, int *nout, double **xout, double **vout,
                    double **hout, int32_t **tagout) {
  const int nt = cfg->nt, nr = cfg->nr, m0 = (nt - 1) / 2;
  const double a = cfg->a, b = cfg->b;
  if (nt < 3 || nt % 2 == 0 || nr < 3 || !(b > a && a > 0) || !(cfg->hfac > 0) ||
      !(cfg->radial_step > 0 && cfg->radial_step <= 2) ||
      cfg->hole_corner < PLATE_CORNER_DIRICHLET || cfg->hole_corner > PLATE_CORNER_HOLE ||
      cfg->search < MFREE_SEARCH_GATHER || cfg->search > MFREE_SEARCH_SYMMETRIC_MEAN)
    return 1;
  if (cfg->layout == PLATE_LAYOUT_RAYS || cfg->layout == PLATE_LAYOUT_POLAR)
    return rays_particles(cfg, nout, xout, vout, hout, tagout);
  if (cfg->layout != PLATE_LAYOUT_RINGS) return 1;
  double *s = malloc(sizeof(double) * (size_t)nr), *gap = malloc(sizeof(double) * (size_t)nr);
  int *m = malloc(sizeof(int) * (size_t)nr);
  double *tk = malloc(sizeof(double) * (size_t)nr * (NTAB + 1)); /* t of each ring's points */
  double *cum = malloc(sizeof(double) * (NTAB + 1));
  if (!s || !gap || !m || !tk || !cum) {
    free(s), free(gap), free(m), free(tk), free(cum);
    return 1;
  }
  /* ring fractions: geometric, the first radial spacing on the axes radial_step a dtheta */
  const double d1 = cfg->radial_step * a * kPi / (2.0 * (nt - 1));
  const double g = grading(d1, nr - 1, b - a);
  s[0] = 0.0;
  for (int k = 1; k < nr; ++k) s[k] = s[k - 1] + d1 * pow(g, k - 1) / (b - a);
  for (int k = 1; k < nr; ++k) s[k] /= s[nr - 1];
  s[nr - 1] = 1.0;
  for (int k = 0; k < nr; ++k) /* local radial spacing, as a fraction of the ray */
    gap[k] = k == 0 ? s[1] - s[0] : (k == nr - 1 ? s[k] - s[k - 1] : 0.5 * (s[k + 1] - s[k - 1]));
  /* points on each half ring (t in [0, 1/2], mirrored to [1/2, 1]) spaced like the
   * rings: equal increments of int |C'(t)| / (L(t) gap_k) dt */
  int n = 0;
  for (int k = 0; k < nr; ++k) {
    double *t = &tk[(size_t)k * (NTAB + 1)];
    if (k == 0) {
      m[k] = m0;
      for (int j = 0; j <= m0; ++j) t[j] = 0.5 * j / m0;
    } else {
      cum[0] = 0.0;
      double prev[2];
      ring_point(cfg, s[k], 0.0, prev);
      for (int q = 1; q <= NTAB; ++q) {
        const double tq = 0.5 * q / NTAB, tm = 0.5 * (q - 0.5) / NTAB;
        double p[2];
        ring_point(cfg, s[k], tq, p);
        cum[q] = cum[q - 1] + hypot(p[0] - prev[0], p[1] - prev[1]) / (ray_length(cfg, tm) * gap[k]);
        prev[0] = p[0], prev[1] = p[1];
      }
      m[k] = (int)lround(cum[NTAB]);
      if (m[k] < 1) m[k] = 1;
      int q = 0;
      for (int j = 0; j <= m[k]; ++j) {
        const double target = cum[NTAB] * j / m[k];
        while (q < NTAB - 1 && cum[q + 1] < target) ++q;
        const double f = (target - cum[q]) / (cum[q + 1] - cum[q]);
        t[j] = 0.5 * (q + (f < 0 ? 0 : f > 1 ? 1 : f)) / NTAB;
      }
      t[0] = 0.0, t[m[k]] = 0.5;
    }
    n += 2 * m[k] + 1;
  }
  double *x = malloc(sizeof(double) * 2 * (size_t)n), *v = malloc(sizeof(double) * (size_t)n);
  double *h = malloc(sizeof(double) * (size_t)n);
  int32_t *tag = malloc(sizeof(int32_t) * (size_t)n);
  if (!x || !v || !h || !tag) {
    free(s), free(gap), free(m), free(tk), free(cum), free(x), free(v), free(h), free(tag);
    return 1;
  }
  int p = 0;
  for (int k = 0; k < nr; ++k) {
    const double *t = &tk[(size_t)k * (NTAB + 1)];
    const int first = p, cnt = 2 * m[k] + 1;
    for (int j = 0; j < cnt; ++j, ++p) {
      const double tj = j <= m[k] ? t[j] : 1.0 - t[2 * m[k] - j];
      ring_point(cfg, s[k], tj, &x[2 * p]);
      tag[p] = (k == 0 ? PLATE_HOLE : 0) | (j == 0 ? PLATE_SYM_Y0 : 0) |
               (j == cnt - 1 ? PLATE_SYM_X0 : 0) |
               (k == nr - 1 && j <= m[k] ? PLATE_EDGE_XB : 0) |
               (k == nr - 1 && j >= m[k] ? PLATE_EDGE_YB : 0);
      /* volume: spacing along the ring times the radial spacing, halved on the edges */
      const double rad = ray_length(cfg, tj) * gap[k] * (k == 0 || k == nr - 1 ? 0.5 : 1.0);
      v[p] = rad;
    }
    for (int j = 0; j < cnt; ++j) {
      const double *c = &x[2 * (first + j)];
      double along = 0.0;
      if (j > 0) along += 0.5 * hypot(c[0] - c[-2], c[1] - c[-1]);
      if (j < cnt - 1) along += 0.5 * hypot(c[2] - c[0], c[3] - c[1]);
      v[first + j] *= along;
    }
  }
  nearest_supports(n, x, cfg->hfac, h);
  free(s), free(gap), free(m), free(tk), free(cum);
  *nout = n;
  *xout = x;
  *vout = v;
  *hout = h;
  *tagout = tag;
  return 0;
}

/* ---- boundary data -------------------------------------------------------------------- */

/* The exact solution of the configured problem: Kirsch, or uniform tension (patch). */
static void exact_stress(const plate_config_t *cfg, double x, double y, double s[3]) {
  if (cfg->patch) {
    s[0] = cfg->sigma0, s[1] = s[2] = 0.0;
    return;
  }
  plate_kirsch_stress(cfg->a, cfg->sigma0, x, y, s);
}

static void exact_displacement(const plate_config_t *cfg, double x, double y, double u[2]) {
  if (cfg->patch) { /* plane strain: eps11 = (1 - nu^2)/E s0, eps22 = -nu (1 + nu)/E s0 */
    const double nu = cfg->poisson;
    u[0] = cfg->sigma0 * (1.0 - nu * nu) / cfg->young * x;
    u[1] = -cfg->sigma0 * nu * (1.0 + nu) / cfg->young * y;
    return;
  }
  plate_kirsch_displacement(cfg->a, cfg->sigma0, cfg->young, cfg->poisson, x, y, u);
}

/* sigma n of the exact solution; a fixed normal, or the hole's (n = -x / |x|). */
typedef struct {
  const plate_config_t *cfg;
  double n[2];
  int hole;
} traction_t;

static void exact_traction(void *user, const double *x, double *t) {
  const traction_t *tr = user;
  double s[3], n[2] = {tr->n[0], tr->n[1]};
  if (tr->hole) {
    const double r = sqrt(x[0] * x[0] + x[1] * x[1]);
    n[0] = -x[0] / r, n[1] = -x[1] / r;
  }
  exact_stress(tr->cfg, x[0], x[1], s);
  t[0] = s[0] * n[0] + s[2] * n[1];
  t[1] = s[2] * n[0] + s[1] * n[1];
}

static void exact_u(void *user, const double *x, double *u) {
  exact_displacement(user, x[0], x[1], u);
}

/* ---- the solve ------------------------------------------------------------------------ */

#define CHECK(call)                                                                      \
  do {                                                                                   \
    st = (call);                                                                         \
    if (st != MFREE_SUCCESS) goto done;                                                  \
  } while (0)

void plate_result_free(plate_result_t *res) {
  plate_axis_t *ax = &res->axis;
  free(ax->x2), free(ax->u2), free(ax->u2_nodal), free(ax->u2_exact), free(ax->sxx),
      free(ax->sxx_exact);
  memset(ax, 0, sizeof *ax);
  free(res->x), free(res->u), free(res->uh), free(res->stress), free(res->tag);
  res->x = res->u = res->uh = res->stress = NULL;
  res->tag = NULL;
}

/* sqrt of the trapezoidal integral of e^2 over the abscissae x. */
static double trapz_norm(int n, const double *x, const double *e) {
  double s = 0.0;
  for (int k = 0; k + 1 < n; ++k) s += 0.5 * (x[k + 1] - x[k]) * (e[k] * e[k] + e[k + 1] * e[k + 1]);
  return sqrt(s);
}

mfree_status_t plate_solve(mfree_context_t *ctx, const plate_config_t *cfg,
                           plate_result_t *res) {
  mfree_status_t st = MFREE_SUCCESS;
  mfree_particles_t *ps = NULL;
  mfree_approximant_t *ap = NULL;
  mfree_assembler_t *as = NULL;
  mfree_matrix_t *K = NULL;
  mfree_suitesparse_t *solver = NULL;
  double *x = NULL, *vol = NULL, *h = NULL, *f = NULL, *u = NULL, *uh = NULL, *grad = NULL,
         *Ku = NULL, *nrm = NULL;
  int32_t *tag = NULL, *nodes = NULL, *cnt = NULL;
  int n = 0;
  memset(res, 0, sizeof *res);
  if (plate_particles(cfg, &n, &x, &vol, &h, &tag))
    return mfree_context_set_error(ctx, MFREE_ERR_ARG,
                                   "plate: needs odd nt >= 3, nr >= 3, b > a > 0, hfac > 0, "
                                   "0 < radial_step <= 2, a PLATE_LAYOUT_*, a PLATE_CORNER_* "
                                   "and an MFREE_SEARCH_* value");
  const int neq = 2 * n;
  res->n = n;
  res->neq = neq;
  int nax = 0;
  for (int p = 0; p < n; ++p) nax += (tag[p] & PLATE_SYM_X0) != 0;
  f = malloc(sizeof(double) * neq);
  u = malloc(sizeof(double) * neq);
  uh = malloc(sizeof(double) * neq);
  Ku = malloc(sizeof(double) * neq);
  grad = malloc(sizeof(double) * 4 * (size_t)n);
  nrm = malloc(sizeof(double) * 2 * (size_t)n);
  nodes = malloc(sizeof(int32_t) * (size_t)n);
  cnt = malloc(sizeof(int32_t) * (size_t)n);
  plate_axis_t *ax = &res->axis;
  ax->n = nax;
  ax->x2 = malloc(sizeof(double) * nax);
  ax->u2 = malloc(sizeof(double) * nax);
  ax->u2_nodal = malloc(sizeof(double) * nax);
  ax->u2_exact = malloc(sizeof(double) * nax);
  ax->sxx = malloc(sizeof(double) * nax);
  ax->sxx_exact = malloc(sizeof(double) * nax);
  if (!f || !u || !uh || !Ku || !grad || !nrm || !nodes || !cnt || !ax->x2 || !ax->u2 ||
      !ax->u2_nodal || !ax->u2_exact || !ax->sxx || !ax->sxx_exact) {
    st = mfree_context_set_error(ctx, MFREE_ERR_ALLOC, "plate: out of memory");
    goto done;
  }

  const double t0 = seconds();
  CHECK(mfree_particles_create(ctx, 2, n, &ps));
  CHECK(mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 2, MFREE_COPY));
  CHECK(mfree_particles_set_volumes(ps, vol, 1, MFREE_COPY));
  CHECK(mfree_particles_set_support(ps, h, 1, MFREE_COPY));
  CHECK(mfree_particles_set_search(ps, (mfree_search_t)cfg->search, 2.0));
  CHECK(mfree_particles_setup(ps));

  /* The approximant for the post-processing; the assembler copies its configuration
   * (and builds value, gradient and Hessian tables of its own). */
  CHECK(mfree_approximant_create(ctx, ps, cfg->method, &ap));
  CHECK(mfree_approximant_set_kernel(ap, MFREE_KERNEL_REVISED_SUPER_GAUSS, cfg->kernel_param));
  CHECK(mfree_approximant_set_order(ap, 2));
  CHECK(mfree_approximant_set_derivatives(
      ap, MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT | MFREE_DERIV_HESSIAN));
  st = mfree_approximant_setup(ap);
  if (st != MFREE_SUCCESS) {
    mfree_approximant_get_site_status(ap, cnt, &res->nfailed);
    goto done;
  }
  CHECK(mfree_approximant_get_neighbor_counts(ap, cnt));
  res->min_neighbors = cnt[0];
  for (int p = 1; p < n; ++p)
    if (cnt[p] < res->min_neighbors) res->min_neighbors = cnt[p];

  CHECK(mfree_assembler_create(ctx, ap, NULL, MFREE_FORM_COLLOCATION_PLANE_STRAIN, &as));
  CHECK(mfree_assembler_set_material(as, cfg->young, cfg->poisson));

  /* Traction rows: one set per normal (the traction function sees only the position);
   * every boundary node is in exactly one set. The Dirichlet rows of the symmetry lines
   * then replace the constrained component (the assembler lets Dirichlet rows win,
   * whatever the order of the calls). */
  const double r2 = sqrt(0.5);
  traction_t bc[6] = {{cfg, {0.0, 0.0}, 1},   /* hole, n = -x / a, with (a, 0), (0, a) */
                      {cfg, {0.0, -1.0}, 0},  /* y = 0: t_1 = -sigma_12 = 0 */
                      {cfg, {-1.0, 0.0}, 0},  /* x = 0: t_2 = -sigma_12 = 0 */
                      {cfg, {1.0, 0.0}, 0},   /* x = b, with the corner (b, 0) */
                      {cfg, {r2, r2}, 0},     /* the corner (b, b) */
                      {cfg, {0.0, 1.0}, 0}};  /* y = b, with the corner (0, b) */
  const int32_t edges = PLATE_EDGE_XB | PLATE_EDGE_YB;
  for (int e = 0; e < 6; ++e) {
    int nn = 0;
    for (int p = 0; p < n; ++p) {
      const int32_t t = tag[p];
      /* hole corners in the symmetry lines' sets (PLATE_CORNER_SYMMETRY) or the hole's */
      const int sym_corner = cfg->hole_corner == PLATE_CORNER_SYMMETRY;
      const int hole = (t & PLATE_HOLE) && !(sym_corner && (t & (PLATE_SYM_X0 | PLATE_SYM_Y0)));
      const int in = e == 0   ? hole
                     : e == 1 ? (t & PLATE_SYM_Y0) && !hole && !(t & edges)
                     : e == 2 ? (t & PLATE_SYM_X0) && !hole && !(t & edges)
                     : e == 3 ? (t & edges) == PLATE_EDGE_XB
                     : e == 4 ? (t & edges) == edges
                              : (t & edges) == PLATE_EDGE_YB;
      if (!in) continue;
      const double r = hypot(x[2 * p], x[2 * p + 1]);
      nodes[nn] = p;
      nrm[2 * nn] = bc[e].hole ? -x[2 * p] / r : bc[e].n[0];
      nrm[2 * nn + 1] = bc[e].hole ? -x[2 * p + 1] / r : bc[e].n[1];
      ++nn;
    }
    CHECK(mfree_assembler_add_traction_nodes(as, nn, nodes, nrm, exact_traction, &bc[e]));
  }
  for (int c = 0; c < 2; ++c) { /* u_2 = 0 on y = 0 (c = 0), u_1 = 0 on x = 0 (c = 1) */
    int nn = 0;
    for (int p = 0; p < n; ++p)
      if ((tag[p] & (c ? PLATE_SYM_X0 : PLATE_SYM_Y0)) &&
          !(cfg->hole_corner == PLATE_CORNER_HOLE && (tag[p] & PLATE_HOLE)))
        nodes[nn++] = p;
    CHECK(mfree_assembler_add_dirichlet_nodes(as, nn, nodes, c ? 1 : 2, exact_u, (void *)cfg));
  }

  CHECK(mfree_assembler_setup(as));
  int32_t ndofs = 0, nquad = 0;
  CHECK(mfree_assembler_get_size(as, &ndofs, &nquad));
  if (ndofs != neq) {
    st = mfree_context_set_error(ctx, MFREE_ERR_INTERNAL, "plate: unexpected number of unknowns");
    goto done;
  }
  CHECK(mfree_assembler_assemble_matrix(as, &K));
  CHECK(mfree_assembler_assemble_rhs(as, f));
  const double t1 = seconds();

  CHECK(mfree_suitesparse_create(ctx, MFREE_SOLVER_UMFPACK, &solver));
  CHECK(mfree_suitesparse_setup(solver, K));
  CHECK(mfree_suitesparse_solve(solver, 1, f, neq, u, neq));
  const double t2 = seconds();
  CHECK(mfree_suitesparse_get_info(solver, &res->rcond, NULL, NULL));
  res->t_setup = t1 - t0;
  res->t_solve = t2 - t1;

  CHECK(mfree_matrix_apply(K, u, Ku));
  double rmax = 0.0, fmax = 0.0;
  for (int d = 0; d < neq; ++d) {
    if (fabs(Ku[d] - f[d]) > rmax) rmax = fabs(Ku[d] - f[d]);
    if (fabs(f[d]) > fmax) fmax = fabs(f[d]);
  }
  res->residual = rmax / fmax;

  /* estimates of u and its gradient at the particles; grad[4p + 2c + d] = du_c/dx_d */
  CHECK(mfree_approximant_apply(ap, MFREE_OP_VALUE, 2, u, MFREE_LAYOUT_AOS, 2, uh,
                                MFREE_LAYOUT_AOS, 2));
  CHECK(mfree_approximant_apply(ap, MFREE_OP_GRADIENT, 2, u, MFREE_LAYOUT_AOS, 2, grad,
                                MFREE_LAYOUT_AOS, 4));
  const double E = cfg->young, nu = cfg->poisson;
  const double lam = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), mu = E / (2.0 * (1.0 + nu));
  res->stress = malloc(sizeof(double) * 3 * (size_t)n);
  if (!res->stress) {
    st = mfree_context_set_error(ctx, MFREE_ERR_ALLOC, "plate: out of memory");
    goto done;
  }
  for (int p = 0; p < n; ++p) {
    const double *g = &grad[4 * p];
    res->stress[3 * p] = (lam + 2.0 * mu) * g[0] + lam * g[3];
    res->stress[3 * p + 1] = lam * g[0] + (lam + 2.0 * mu) * g[3];
    res->stress[3 * p + 2] = mu * (g[1] + g[2]);
  }
  res->max_err_u = 0.0;
  for (int p = 0, k = 0; p < n; ++p) {
    double ue[2], se[3];
    exact_displacement(cfg, x[2 * p], x[2 * p + 1], ue);
    for (int c = 0; c < 2; ++c)
      if (fabs(uh[2 * p + c] - ue[c]) > res->max_err_u) res->max_err_u = fabs(uh[2 * p + c] - ue[c]);
    if (!(tag[p] & PLATE_SYM_X0)) continue;
    /* the particles on x = 0 come ring by ring, from the hole outwards */
    exact_stress(cfg, x[2 * p], x[2 * p + 1], se);
    ax->x2[k] = x[2 * p + 1];
    ax->u2[k] = uh[2 * p + 1];
    ax->u2_nodal[k] = u[2 * p + 1];
    ax->u2_exact[k] = ue[1];
    ax->sxx[k] = res->stress[3 * p];
    ax->sxx_exact[k] = se[0];
    if (k == 0) res->top = p;
    ++k;
  }
  res->scf = ax->sxx[0] / cfg->sigma0;
  double *e = Ku; /* scratch, nax <= n */
  for (int k = 0; k < nax; ++k) e[k] = ax->u2[k] - ax->u2_exact[k];
  res->err_u2 = trapz_norm(nax, ax->x2, e);
  for (int k = 0; k < nax; ++k) e[k] = ax->u2_nodal[k] - ax->u2_exact[k];
  res->err_u2_nodal = trapz_norm(nax, ax->x2, e);
  res->norm_u2 = trapz_norm(nax, ax->x2, ax->u2_exact);

  /* the same stress from the exact nodal displacements: the approximation error alone */
  res->u = malloc(sizeof(double) * neq);
  if (!res->u) {
    st = mfree_context_set_error(ctx, MFREE_ERR_ALLOC, "plate: out of memory");
    goto done;
  }
  memcpy(res->u, u, sizeof(double) * neq);
  for (int p = 0; p < n; ++p) exact_displacement(cfg, x[2 * p], x[2 * p + 1], &u[2 * p]);
  CHECK(mfree_approximant_apply(ap, MFREE_OP_GRADIENT, 2, u, MFREE_LAYOUT_AOS, 2, grad,
                                MFREE_LAYOUT_AOS, 4));
  res->scf_interp =
      ((lam + 2.0 * mu) * grad[4 * res->top] + lam * grad[4 * res->top + 3]) / cfg->sigma0;
  res->x = x, x = NULL;
  res->uh = uh, uh = NULL;
  res->tag = tag, tag = NULL;

done:
  mfree_suitesparse_destroy(&solver);
  mfree_matrix_destroy(&K);
  mfree_assembler_destroy(&as);
  mfree_approximant_destroy(&ap);
  mfree_particles_destroy(&ps);
  free(x), free(vol), free(h), free(f), free(u), free(uh), free(grad), free(Ku), free(nrm);
  free(tag), free(nodes), free(cnt);
  return st;
}
