/* Shared helpers of the libmfree_petsc tests: see pktest.h. */
#include "pktest.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static void *xmalloc(size_t n) {
  void *p = malloc(n ? n : 1);
  assert_non_null(p);
  return p;
}

/* Gauss-Legendre points and weights on [-1, 1] for n = 2, 3. */
static void gauss(int n, double *g, double *w) {
  if (n == 2) {
    g[0] = -1.0 / sqrt(3.0), g[1] = -g[0];
    w[0] = w[1] = 1.0;
  } else {
    g[0] = -sqrt(0.6), g[1] = 0.0, g[2] = sqrt(0.6);
    w[0] = w[2] = 5.0 / 9.0, w[1] = 8.0 / 9.0;
  }
}

void pk_beam_exact(const pk_problem_t *p, const double *x, double *u) {
  /* 000 eqs 120-121 (Timoshenko's cantilever, plane stress, y in [-D/2, D/2]) */
  const double P = p->P, L = p->L, D = p->D, E = p->E, nu = p->nu;
  const double inertia = D * D * D / 12.0, X = x[0], Y = x[1];
  u[0] = -P * Y / (6.0 * E * inertia) * ((6.0 * L - 3.0 * X) * X + (2.0 + nu) * (Y * Y - D * D / 4.0));
  u[1] = P / (6.0 * E * inertia) * (3.0 * nu * Y * Y * (L - X) + (4.0 + 5.0 * nu) * D * D * X / 4.0 + (3.0 * L - X) * X * X);
}

/* Traction sigma n at x = L (n = (1, 0)): (sigma_xx, sigma_xy), 000 eqs 122-124. */
static void beam_traction(void *user, const double *x, double *t) {
  const pk_problem_t *p = (const pk_problem_t *)user;
  const double inertia = p->D * p->D * p->D / 12.0;
  t[0] = -p->P * (p->L - x[0]) * x[1] / inertia;
  t[1] = p->P / (2.0 * inertia) * (p->D * p->D / 4.0 - x[1] * x[1]);
}

static void beam_dirichlet(void *user, const double *x, double *g) { pk_beam_exact((const pk_problem_t *)user, x, g); }

static void block_gravity(void *user, const double *x, double *b) {
  (void)user;
  b[0] = 0.0, b[1] = 0.1 * x[0], b[2] = -1.0;
}

/* Background Gauss points of a box divided into cells of the node spacing. */
static void cells(pk_problem_t *p, const double *lo, const double *hi, const int32_t *nc, int ng) {
  double g[3], w[3];
  gauss(ng, g, w);
  int32_t tot = 1;
  for (int d = 0; d < p->dim; ++d) tot *= nc[d] * ng;
  p->nq = tot;
  p->qx = xmalloc(sizeof(double) * (size_t)tot * (size_t)p->dim);
  p->qw = xmalloc(sizeof(double) * (size_t)tot);
  for (int32_t t = 0; t < tot; ++t) {
    int32_t r = t;
    double wt = 1.0;
    for (int d = 0; d < p->dim; ++d) {
      const int32_t per = nc[d] * ng, i = r % per, cell = i / ng, q = i % ng;
      r /= per;
      const double hc = (hi[d] - lo[d]) / nc[d];
      p->qx[(size_t)t * p->dim + d] = lo[d] + hc * (cell + 0.5 * (1.0 + g[q]));
      wt *= 0.5 * hc * w[q];
    }
    p->qw[t] = wt;
  }
}

void pk_problem_beam(pk_problem_t *p, int32_t nx, int32_t ny, int quad) {
  memset(p, 0, sizeof *p);
  p->kind = PK_BEAM, p->dim = 2, p->quad = quad;
  p->P = 1000.0, p->L = 48.0, p->D = 12.0, p->E = 3e7, p->nu = 0.3;
  const double dx = p->L / (nx - 1), dy = p->D / (ny - 1);
  p->n = nx * ny;
  p->x = xmalloc(sizeof(double) * 2 * (size_t)p->n);
  p->vol = xmalloc(sizeof(double) * (size_t)p->n);
  for (int32_t j = 0; j < ny; ++j)
    for (int32_t i = 0; i < nx; ++i) {
      const int32_t k = j * nx + i;
      p->x[2 * k] = i * dx;
      p->x[2 * k + 1] = -0.5 * p->D + j * dy;
      p->vol[k] = dx * dy * ((i == 0 || i == nx - 1) ? 0.5 : 1.0) * ((j == 0 || j == ny - 1) ? 0.5 : 1.0);
    }
  p->h = 1.01 * (dx > dy ? dx : dy);
  p->R = 2.0 * p->h;
  /* tractions at x = L: two Gauss points per segment */
  double g[3], w[3];
  gauss(2, g, w);
  p->nt = 2 * (ny - 1);
  p->tx = xmalloc(sizeof(double) * 2 * (size_t)p->nt);
  p->tw = xmalloc(sizeof(double) * (size_t)p->nt);
  for (int32_t s = 0; s < ny - 1; ++s)
    for (int q = 0; q < 2; ++q) {
      const int32_t m = 2 * s + q;
      p->tx[2 * m] = p->L;
      p->tx[2 * m + 1] = -0.5 * p->D + dy * (s + 0.5 * (1.0 + g[q]));
      p->tw[m] = 0.5 * dy * w[q];
    }
  if (quad == PK_GAUSS) {
    /* penalty points at x = 0 (the same rule) and background cells */
    p->np = p->nt;
    p->px = xmalloc(sizeof(double) * 2 * (size_t)p->np);
    p->pw = xmalloc(sizeof(double) * (size_t)p->np);
    for (int32_t m = 0; m < p->np; ++m) {
      p->px[2 * m] = 0.0;
      p->px[2 * m + 1] = p->tx[2 * m + 1];
      p->pw[m] = p->tw[m];
    }
    const double lo[2] = {0.0, -0.5 * p->D}, hi[2] = {p->L, 0.5 * p->D};
    const int32_t nc[2] = {nx - 1, ny - 1};
    cells(p, lo, hi, nc, 3);
  }
}

void pk_problem_block(pk_problem_t *p, int32_t nx, int32_t ny, int32_t nz) {
  memset(p, 0, sizeof *p);
  p->kind = PK_BLOCK, p->dim = 3, p->quad = PK_GAUSS;
  p->E = 1000.0, p->nu = 0.3;
  const double ext[3] = {2.0, 1.0, 1.0};
  const double d[3] = {ext[0] / (nx - 1), ext[1] / (ny - 1), ext[2] / (nz - 1)};
  p->n = nx * ny * nz;
  p->x = xmalloc(sizeof(double) * 3 * (size_t)p->n);
  p->vol = xmalloc(sizeof(double) * (size_t)p->n);
  for (int32_t k = 0; k < nz; ++k)
    for (int32_t j = 0; j < ny; ++j)
      for (int32_t i = 0; i < nx; ++i) {
        const int32_t m = (k * ny + j) * nx + i;
        p->x[3 * m] = i * d[0], p->x[3 * m + 1] = j * d[1], p->x[3 * m + 2] = k * d[2];
        p->vol[m] = d[0] * d[1] * d[2];
      }
  p->h = 1.01 * fmax(d[0], fmax(d[1], d[2]));
  p->R = 2.0 * p->h;
  const double lo[3] = {0, 0, 0};
  const int32_t nc[3] = {nx - 1, ny - 1, nz - 1};
  cells(p, lo, ext, nc, 2);
}

void pk_problem_free(pk_problem_t *p) {
  free(p->x), free(p->vol), free(p->qx), free(p->qw), free(p->tx), free(p->tw), free(p->px), free(p->pw);
  memset(p, 0, sizeof *p);
}

static uint64_t mix(uint64_t z) {
  z += 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

/* Recursive coordinate bisection of the nodes idx[0..n) into parts [p0, p0 + np). */
static int cmp_axis;
static const double *cmp_x;
static int cmp_dim;
static int by_axis(const void *a, const void *b) {
  const double u = cmp_x[(size_t)*(const int32_t *)a * cmp_dim + cmp_axis];
  const double v = cmp_x[(size_t)*(const int32_t *)b * cmp_dim + cmp_axis];
  return u < v ? -1 : u > v ? 1 : (*(const int32_t *)a - *(const int32_t *)b);
}
static void bisect(const pk_problem_t *p, int32_t *idx, int32_t n, int p0, int np, int *part) {
  if (np == 1) {
    for (int32_t k = 0; k < n; ++k) part[idx[k]] = p0;
    return;
  }
  double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (int32_t k = 0; k < n; ++k)
    for (int d = 0; d < p->dim; ++d) {
      lo[d] = fmin(lo[d], p->x[(size_t)idx[k] * p->dim + d]);
      hi[d] = fmax(hi[d], p->x[(size_t)idx[k] * p->dim + d]);
    }
  int axis = 0;
  for (int d = 1; d < p->dim; ++d)
    if (hi[d] - lo[d] > hi[axis] - lo[axis]) axis = d;
  cmp_axis = axis, cmp_x = p->x, cmp_dim = p->dim;
  qsort(idx, (size_t)n, sizeof *idx, by_axis);
  const int nl = np / 2;
  const int32_t cut = (int32_t)((int64_t)n * nl / np);
  bisect(p, idx, cut, p0, nl, part);
  bisect(p, idx + cut, n - cut, p0 + nl, np - nl, part);
}

void pk_partition(const pk_problem_t *p, int how, int size, uint64_t seed, int *part) {
  if (how == PK_BISECT) {
    int32_t *idx = xmalloc(sizeof(int32_t) * (size_t)p->n);
    for (int32_t i = 0; i < p->n; ++i) idx[i] = i;
    bisect(p, idx, p->n, 0, size, part);
    free(idx);
    return;
  }
  double lo = HUGE_VAL, hi = -HUGE_VAL;
  for (int32_t i = 0; i < p->n; ++i) lo = fmin(lo, p->x[(size_t)i * p->dim]), hi = fmax(hi, p->x[(size_t)i * p->dim]);
  for (int32_t i = 0; i < p->n; ++i) {
    if (how == PK_SLAB) {
      int r = (int)((p->x[(size_t)i * p->dim] - lo) / (hi - lo) * size);
      part[i] = r >= size ? size - 1 : r;
    } else {
      part[i] = (int)(mix(seed * 1000003u + (uint64_t)i) % (uint64_t)size);
    }
  }
}

static double dist2(const pk_problem_t *p, const double *a, const double *b) {
  double s = 0.0;
  for (int d = 0; d < p->dim; ++d) s += (a[d] - b[d]) * (a[d] - b[d]);
  return s;
}

static void shuffle(int32_t *v, int32_t n, uint64_t seed) {
  if (!seed) return;
  for (int32_t i = n - 1; i > 0; --i) {
    const int32_t j = (int32_t)(mix(seed + (uint64_t)i) % (uint64_t)(i + 1));
    const int32_t t = v[i];
    v[i] = v[j], v[j] = t;
  }
}

void pk_local(const pk_problem_t *p, const int *part, int rank, uint64_t seed, pk_local_t *l) {
  memset(l, 0, sizeof *l);
  const int32_t n = p->n;
  /* distance class of each node: 0 owned, 1 within R, 2 within 2R, 3 beyond */
  int *cls = xmalloc(sizeof(int) * (size_t)n);
  for (int32_t i = 0; i < n; ++i) cls[i] = part[i] == rank ? 0 : 3;
  const double r1 = p->R * (1.0 + 1e-9), r2 = 2.0 * p->R * (1.0 + 1e-9);
  for (int32_t i = 0; i < n; ++i) {
    if (cls[i] != 0) continue;
    for (int32_t j = 0; j < n; ++j) {
      if (cls[j] <= 1) continue;
      const double d2 = dist2(p, p->x + (size_t)i * p->dim, p->x + (size_t)j * p->dim);
      if (d2 < r1 * r1) cls[j] = 1;
      else if (d2 < r2 * r2) cls[j] = 2;
    }
  }
  l->idx = xmalloc(sizeof(int32_t) * (size_t)n);
  for (int c = 0; c < 3; ++c) {
    const int32_t start = l->nlocal;
    for (int32_t i = 0; i < n; ++i)
      if (cls[i] == c) l->idx[l->nlocal++] = i;
    shuffle(l->idx + start, l->nlocal - start, seed ? seed + (uint64_t)c : 0);
    if (c == 0) l->nowned = l->nlocal;
    if (c == 1) l->ninner = l->nlocal - start;
  }
  l->nghost = l->nlocal - l->nowned - l->ninner;
  l->gid = xmalloc(sizeof(int64_t) * (size_t)(l->nlocal ? l->nlocal : 1));
  for (int32_t k = 0; k < l->nlocal; ++k) l->gid[k] = l->idx[k];
  free(cls);
}

void pk_local_all(const pk_problem_t *p, pk_local_t *l) {
  int *part = xmalloc(sizeof(int) * (size_t)p->n);
  for (int32_t i = 0; i < p->n; ++i) part[i] = 0;
  pk_local(p, part, 0, 0, l);
  free(part);
}

void pk_local_free(pk_local_t *l) {
  free(l->idx), free(l->gid);
  memset(l, 0, sizeof *l);
}

/* Points (AoS) within R of an owned node, in their global order. */
static int32_t near_owned(const pk_problem_t *p, const pk_local_t *l, int32_t m, const double *x, const double *w,
                          double *ox, double *ow) {
  const double r1 = p->R * (1.0 + 1e-9);
  int32_t k = 0;
  for (int32_t q = 0; q < m; ++q) {
    int keep = 0;
    for (int32_t a = 0; a < l->nowned && !keep; ++a)
      keep = dist2(p, x + (size_t)q * p->dim, p->x + (size_t)l->idx[a] * p->dim) < r1 * r1;
    if (!keep) continue;
    memcpy(ox + (size_t)k * p->dim, x + (size_t)q * p->dim, sizeof(double) * (size_t)p->dim);
    ow[k++] = w[q];
  }
  return k;
}

#define TRY(call)                        \
  do {                                   \
    st = (call);                         \
    if (st != MFREE_SUCCESS) goto done;  \
  } while (0)

mfree_status_t pk_system(mfree_context_t *ctx, const pk_problem_t *p, const pk_local_t *l, pk_system_t *s) {
  memset(s, 0, sizeof *s);
  mfree_status_t st = MFREE_SUCCESS;
  const int dim = p->dim;
  const int32_t n = l->nlocal;
  s->x = xmalloc(sizeof(double) * (size_t)dim * (size_t)(n ? n : 1));
  double *vol = xmalloc(sizeof(double) * (size_t)(n ? n : 1));
  const int32_t mbuf = p->nq > p->nt ? (p->nq > p->np ? p->nq : p->np) : (p->nt > p->np ? p->nt : p->np);
  double *bx = xmalloc(sizeof(double) * (size_t)dim * (size_t)(mbuf ? mbuf : 1));
  double *bw = xmalloc(sizeof(double) * (size_t)(mbuf ? mbuf : 1));
  for (int32_t k = 0; k < n; ++k) {
    memcpy(s->x + (size_t)k * dim, p->x + (size_t)l->idx[k] * dim, sizeof(double) * (size_t)dim);
    vol[k] = p->vol[l->idx[k]];
  }
  TRY(mfree_particles_create(ctx, dim, n, &s->ps));
  TRY(mfree_particles_set_positions(s->ps, s->x, MFREE_LAYOUT_AOS, dim, MFREE_COPY));
  TRY(mfree_particles_set_volumes(s->ps, vol, 1, MFREE_COPY));
  TRY(mfree_particles_set_support(s->ps, &p->h, 0, MFREE_COPY));
  TRY(mfree_particles_set_num_ghost(s->ps, l->nghost));
  TRY(mfree_particles_set_global_ids(s->ps, l->gid, MFREE_COPY));
  TRY(mfree_particles_setup(s->ps));
  TRY(mfree_approximant_create(ctx, s->ps, MFREE_METHOD_MLS, &s->ap));
  TRY(mfree_approximant_set_order(s->ap, 1));
  TRY(mfree_assembler_create(ctx, s->ap, NULL,
                             dim == 2 ? MFREE_FORM_ELASTICITY_PLANE_STRESS : MFREE_FORM_ELASTICITY_3D, &s->as));
  TRY(mfree_assembler_set_material(s->as, p->E, p->nu));
  if (p->quad == PK_GAUSS) {
    const int32_t m = near_owned(p, l, p->nq, p->qx, p->qw, bx, bw);
    TRY(mfree_assembler_set_quadrature_points(s->as, m, bx, MFREE_LAYOUT_AOS, dim, bw));
  } else {
    TRY(mfree_assembler_set_quadrature_nodal(s->as));
  }
  if (p->kind == PK_BEAM) {
    int32_t m = near_owned(p, l, p->nt, p->tx, p->tw, bx, bw);
    if (m) TRY(mfree_assembler_add_traction(s->as, m, bx, MFREE_LAYOUT_AOS, 2, bw, beam_traction, (void *)p));
    m = near_owned(p, l, p->np, p->px, p->pw, bx, bw);
    if (m)
      TRY(mfree_assembler_add_dirichlet(s->as, MFREE_BC_PENALTY, m, bx, MFREE_LAYOUT_AOS, 2, bw, NULL, 3,
                                        beam_dirichlet, (void *)p));
  } else {
    TRY(mfree_assembler_set_body_force(s->as, block_gravity, NULL));
  }
  TRY(mfree_assembler_setup(s->as));
done:
  free(vol), free(bx), free(bw);
  return st;
}

void pk_system_free(pk_system_t *s) {
  mfree_assembler_destroy(&s->as);
  mfree_approximant_destroy(&s->ap);
  mfree_particles_destroy(&s->ps);
  free(s->x), free(s->buf);
  memset(s, 0, sizeof *s);
}

void pk_dirichlet(const pk_problem_t *p, const pk_local_t *l, int32_t *n, int32_t **dofs, double **vals) {
  const int dim = p->dim;
  *dofs = xmalloc(sizeof(int32_t) * (size_t)dim * (size_t)(l->nowned ? l->nowned : 1));
  *vals = xmalloc(sizeof(double) * (size_t)dim * (size_t)(l->nowned ? l->nowned : 1));
  int32_t m = 0;
  /* the beam's nodal clamp only with nodal quadrature (the Gauss variant uses penalty) */
  if (p->kind == PK_BEAM && p->quad != PK_NODAL) {
    *n = 0;
    return;
  }
  for (int32_t a = 0; a < l->nowned; ++a) {
    const double *x = p->x + (size_t)l->idx[a] * dim;
    if (x[0] != 0.0) continue;
    double u[3] = {0, 0, 0};
    if (p->kind == PK_BEAM) pk_beam_exact(p, x, u);
    for (int c = 0; c < dim; ++c) {
      (*dofs)[m] = a * dim + c;
      (*vals)[m++] = u[c];
    }
  }
  *n = m;
}

int pk_main(int *argc, char ***argv, const struct CMUnitTest *tests, size_t n, int *rank, int *size) {
  if (PetscInitialize(argc, argv, NULL, NULL)) return 1;
  MPI_Comm_rank(PETSC_COMM_WORLD, rank);
  MPI_Comm_size(PETSC_COMM_WORLD, size);
  const int rc = _cmocka_run_group_tests("tests", tests, n, NULL, NULL);
  PetscFinalize();
  return rc;
}
