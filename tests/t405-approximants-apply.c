/* Approximants: applying the tables to host fields.
 *  - apply_add adds exactly what apply writes (out += op(u));
 *  - AoS and SoA inputs and outputs with leading dimensions above the minimum (a host
 *    struct array with ld = 7, SoA with padding) give the same results and write
 *    nothing outside their slots;
 *  - ncomp = 3 fields equal three scalar applications, component c / direction d at
 *    c*dim + d (mfree_op_t);
 *  - DIVERGENCE = trace of the GRADIENT of a dim-component field, LAPLACIAN = trace of
 *    the HESSIAN;
 *  - ghosts: sites are the owned particles only, columns include the ghosts, and the
 *    owned rows equal those of the same particles without ghosts;
 *  - the exported CSR, as a dense mat-vec, reproduces what apply computes;
 *  - apply never modifies u. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"

static mfree_context_t *ctx;
static int32_t backend = MFREE_BACKEND_OPT; /* argument "ref": the reference backend */
static int setup(void **s) {
  (void)s;
  return mfree_context_create(&ctx) != MFREE_SUCCESS || mfree_context_set_backend(ctx, backend) != MFREE_SUCCESS;
}
static int teardown(void **s) { (void)s; return mfree_context_destroy(&ctx) != MFREE_SUCCESS; }

#define NMAX 256
#define NC 3 /* field components */

static const int kOps[5] = {MFREE_OP_VALUE, MFREE_OP_GRADIENT, MFREE_OP_DIVERGENCE,
                            MFREE_OP_LAPLACIAN, MFREE_OP_HESSIAN};

typedef struct {
  int dim, n, n_ghost;
  double x[NMAX * 3], h[NMAX], v[NMAX];
} cloud_t;

/* Jittered lattice with m per axis on [0,1]^dim; with ghosts, the particles of the
 * outer layer are moved to the end of the arrays and become ghosts. */
static void make_cloud(cloud_t *c, int dim, int m, int ghost_layer, uint64_t seed) {
  mfree_rng_t r;
  mfree_rng_seed(&r, seed);
  const double dx = 1.0 / (m - 1);
  int total = 1;
  for (int d = 0; d < dim; ++d) total *= m;
  assert_true(total <= NMAX);
  c->dim = dim;
  c->n = total;
  c->n_ghost = 0;
  int owned = 0, ghost = 0;
  static double gx[NMAX * 3];
  for (int i = 0; i < total; ++i) {
    int rest = i, outer = 0;
    double p[3];
    for (int d = 0; d < dim; ++d) {
      const int k = rest % m;
      rest /= m;
      outer |= k == 0 || k == m - 1;
      p[d] = k * dx + 0.3 * dx * (2.0 * mfree_rng_uniform(&r) - 1.0);
    }
    if (ghost_layer && outer) {
      for (int d = 0; d < dim; ++d) gx[ghost * dim + d] = p[d];
      ++ghost;
    } else {
      for (int d = 0; d < dim; ++d) c->x[owned * dim + d] = p[d];
      ++owned;
    }
  }
  memcpy(&c->x[owned * dim], gx, sizeof(double) * (size_t)(ghost * dim));
  c->n_ghost = ghost;
  for (int i = 0; i < total; ++i) {
    c->h[i] = 1.6 * dx * (1.0 + 0.2 * mfree_rng_uniform(&r));
    c->v[i] = pow(dx, dim) * (0.9 + 0.2 * mfree_rng_uniform(&r));
  }
}

static mfree_particles_t *make_set(const cloud_t *c, int with_ghosts) {
  mfree_particles_t *ps = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, c->dim, c->n, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, c->x, MFREE_LAYOUT_AOS, c->dim, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_support(ps, c->h, 1, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_volumes(ps, c->v, 1, MFREE_COPY));
  if (with_ghosts) assert_ok(ctx, mfree_particles_set_num_ghost(ps, c->n_ghost));
  return ps;
}

static mfree_approximant_t *make_approx(mfree_particles_t *ps, mfree_method_t m, int order) {
  mfree_approximant_t *a = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, m, &a));
  assert_ok(ctx, mfree_approximant_set_order(a, order));
  assert_ok(ctx, mfree_approximant_set_derivatives(
                     a, MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT | MFREE_DERIV_HESSIAN));
  assert_ok(ctx, mfree_approximant_setup(a));
  int32_t nfailed = -1;
  assert_ok(ctx, mfree_approximant_get_site_status(a, NULL, &nfailed));
  assert_int_equal(nfailed, 0);
  return a;
}

/* input components and output components of an operator */
static int op_in(int op, int dim) { return op == MFREE_OP_DIVERGENCE ? dim : NC; }
static int op_out(int op, int dim) {
  const int nh = dim * (dim + 1) / 2;
  switch (op) {
    case MFREE_OP_GRADIENT:
      return NC * dim;
    case MFREE_OP_DIVERGENCE:
      return 1;
    case MFREE_OP_HESSIAN:
      return NC * nh;
    default:
      return NC;
  }
}

static void random_field(int n, int nc, double *u /* AoS, ld nc */, uint64_t seed) {
  mfree_rng_t r;
  mfree_rng_seed(&r, seed);
  for (int i = 0; i < n * nc; ++i) u[i] = 2.0 * mfree_rng_uniform(&r) - 1.0;
}

static double maxabs(const double *a, int n) {
  double m = 0.0;
  for (int i = 0; i < n; ++i) m = fmax(m, fabs(a[i]));
  return m;
}

/* Reference: AoS in, AoS out, minimal leading dimensions. */
static void apply_ref(const mfree_approximant_t *a, int op, int dim, int nc, const double *u, double *out) {
  assert_ok(ctx, mfree_approximant_apply(a, (mfree_op_t)op, nc, u, MFREE_LAYOUT_AOS, nc, out,
                                         MFREE_LAYOUT_AOS, op_out(op, dim)));
}

/* apply_add adds exactly what apply writes. */
static void test_apply_add(void **s) {
  (void)s;
  static cloud_t c;
  static double u[NMAX * NC], base[NMAX * 18], got[NMAX * 18], ref[NMAX * 18];
  for (int dim = 1; dim <= 3; ++dim) {
    make_cloud(&c, dim, dim == 1 ? 30 : (dim == 2 ? 12 : 6), 0, 10u + (uint64_t)dim);
    mfree_particles_t *ps = make_set(&c, 0);
    mfree_approximant_t *a = make_approx(ps, MFREE_METHOD_MLS, 2);
    for (int oi = 0; oi < 5; ++oi) {
      const int op = kOps[oi], nc = op_in(op, dim), oc = op_out(op, dim);
      random_field(c.n, nc, u, 3u + (uint64_t)oi);
      random_field(c.n, oc, base, 4u + (uint64_t)oi);
      apply_ref(a, op, dim, nc, u, ref);
      memcpy(got, base, sizeof(double) * (size_t)(c.n * oc));
      assert_ok(ctx, mfree_approximant_apply_add(a, (mfree_op_t)op, nc, u, MFREE_LAYOUT_AOS, nc, got,
                                                 MFREE_LAYOUT_AOS, oc));
      const double scale = maxabs(ref, c.n * oc) + 1.0;
      for (int i = 0; i < c.n * oc; ++i)
        if (fabs(got[i] - (base[i] + ref[i])) > 1e-15 * scale)
          fail_msg("dim %d op %d: apply_add %.17g vs %.17g + %.17g", dim, op, got[i], base[i], ref[i]);
      /* twice: out = base + 2 op(u) */
      assert_ok(ctx, mfree_approximant_apply_add(a, (mfree_op_t)op, nc, u, MFREE_LAYOUT_AOS, nc, got,
                                                 MFREE_LAYOUT_AOS, oc));
      for (int i = 0; i < c.n * oc; ++i)
        if (fabs(got[i] - (base[i] + 2.0 * ref[i])) > 4e-15 * scale)
          fail_msg("dim %d op %d: second apply_add", dim, op);
    }
    assert_ok(ctx, mfree_approximant_destroy(&a));
    assert_ok(ctx, mfree_particles_destroy(&ps));
  }
}

/* AoS/SoA with padded leading dimensions: same numbers, padding untouched, u unchanged. */
static void test_layouts(void **s) {
  (void)s;
  static cloud_t c;
  static double u[NMAX * NC], ref[NMAX * 18], uin[NMAX * 8 + 64], ucopy[NMAX * 8 + 64],
      out[NMAX * 24 + 64];
  const double sentinel = -12345.678;
  for (int dim = 1; dim <= 3; ++dim) {
    make_cloud(&c, dim, dim == 1 ? 30 : (dim == 2 ? 12 : 6), 0, 20u + (uint64_t)dim);
    mfree_particles_t *ps = make_set(&c, 0);
    mfree_approximant_t *a = make_approx(ps, MFREE_METHOD_SSPH, 2);
    const int n = c.n;
    for (int oi = 0; oi < 5; ++oi) {
      const int op = kOps[oi], nc = op_in(op, dim), oc = op_out(op, dim);
      random_field(n, nc, u, 30u + (uint64_t)oi);
      apply_ref(a, op, dim, nc, u, ref);
      const double scale = maxabs(ref, n * oc);
      for (int ul = 0; ul < 3; ++ul)   /* AoS minimal, host structs (ld 7, offset 2), SoA padded */
        for (int ol = 0; ol < 2; ++ol) { /* AoS padded, SoA padded */
          mfree_layout_t ulayout = ul == 2 ? MFREE_LAYOUT_SOA : MFREE_LAYOUT_AOS;
          const int64_t uld = ul == 0 ? nc : (ul == 1 ? 7 : n + 5);
          const double *up = ul == 1 ? uin + 2 : uin;
          for (int i = 0; i < NMAX * 8 + 64; ++i) uin[i] = sentinel;
          for (int i = 0; i < n; ++i)
            for (int k = 0; k < nc; ++k) {
              if (ulayout == MFREE_LAYOUT_AOS) uin[(ul == 1 ? 2 : 0) + i * uld + k] = u[i * nc + k];
              else uin[k * uld + i] = u[i * nc + k];
            }
          memcpy(ucopy, uin, sizeof uin);
          const mfree_layout_t olayout = ol == 0 ? MFREE_LAYOUT_AOS : MFREE_LAYOUT_SOA;
          const int64_t old = ol == 0 ? oc + 4 : n + 3;
          for (int i = 0; i < NMAX * 24 + 64; ++i) out[i] = sentinel;
          assert_ok(ctx, mfree_approximant_apply(a, (mfree_op_t)op, nc, up, ulayout, uld, out, olayout, old));
          if (memcmp(uin, ucopy, sizeof uin) != 0) fail_msg("dim %d op %d: apply modified u", dim, op);
          for (int i = 0; i < NMAX * 24 + 64; ++i) {
            /* which slot is i? */
            int site, comp, inside;
            if (olayout == MFREE_LAYOUT_AOS) {
              site = i / (int)old;
              comp = i % (int)old;
              inside = site < n && comp < oc;
            } else {
              comp = i / (int)old;
              site = i % (int)old;
              inside = comp < oc && site < n;
            }
            if (!inside) {
              if (out[i] != sentinel) fail_msg("dim %d op %d layout %d/%d: wrote padding slot %d", dim, op, ul, ol, i);
            } else if (fabs(out[i] - ref[site * oc + comp]) > 1e-15 * scale) {
              fail_msg("dim %d op %d layout %d/%d: site %d comp %d %.17g vs %.17g", dim, op, ul, ol,
                       site, comp, out[i], ref[site * oc + comp]);
            }
          }
        }
    }
    /* leading dimensions below the minimum are refused */
    assert_error(ctx, mfree_approximant_apply(a, MFREE_OP_VALUE, NC, u, MFREE_LAYOUT_AOS, NC - 1, out, MFREE_LAYOUT_AOS, NC),
                 MFREE_ERR_ARG, "leading dimension");
    assert_error(ctx, mfree_approximant_apply(a, MFREE_OP_VALUE, NC, u, MFREE_LAYOUT_SOA, n - 1, out, MFREE_LAYOUT_AOS, NC),
                 MFREE_ERR_ARG, "leading dimension");
    assert_error(ctx, mfree_approximant_apply(a, MFREE_OP_GRADIENT, NC, u, MFREE_LAYOUT_AOS, NC, out, MFREE_LAYOUT_AOS, NC * dim - 1),
                 MFREE_ERR_ARG, "leading dimension");
    assert_error(ctx, mfree_approximant_apply(a, MFREE_OP_VALUE, NC, u, MFREE_LAYOUT_AOS, NC, out, MFREE_LAYOUT_SOA, n - 1),
                 MFREE_ERR_ARG, "leading dimension");
    assert_ok(ctx, mfree_approximant_destroy(&a));
    assert_ok(ctx, mfree_particles_destroy(&ps));
  }
}

/* ncomp = 3 equals three scalar applications; DIVERGENCE = trace GRADIENT, LAPLACIAN =
 * trace HESSIAN. */
static void test_components_and_traces(void **s) {
  (void)s;
  static cloud_t c;
  static double u[NMAX * NC], u1[NMAX], vec[NMAX * 18], sc[NMAX * 6], g[NMAX * 9], tr[NMAX * 6];
  for (int dim = 1; dim <= 3; ++dim) {
    const int nh = dim * (dim + 1) / 2;
    make_cloud(&c, dim, dim == 1 ? 30 : (dim == 2 ? 12 : 6), 0, 40u + (uint64_t)dim);
    mfree_particles_t *ps = make_set(&c, 0);
    mfree_approximant_t *a = make_approx(ps, MFREE_METHOD_RKPM, 2);
    const int n = c.n;
    random_field(n, NC, u, 41u);
    const int ops[3] = {MFREE_OP_VALUE, MFREE_OP_GRADIENT, MFREE_OP_HESSIAN};
    for (int oi = 0; oi < 3; ++oi) {
      const int op = ops[oi], per = op == MFREE_OP_VALUE ? 1 : (op == MFREE_OP_GRADIENT ? dim : nh);
      apply_ref(a, op, dim, NC, u, vec);
      for (int k = 0; k < NC; ++k) {
        for (int i = 0; i < n; ++i) u1[i] = u[i * NC + k];
        assert_ok(ctx, mfree_approximant_apply(a, (mfree_op_t)op, 1, u1, MFREE_LAYOUT_AOS, 1, sc,
                                               MFREE_LAYOUT_AOS, per));
        for (int i = 0; i < n; ++i)
          for (int q = 0; q < per; ++q)
            if (fabs(vec[i * NC * per + k * per + q] - sc[i * per + q]) > 1e-15 * (fabs(sc[i * per + q]) + 1.0))
              fail_msg("dim %d op %d: component %d entry %d differs from the scalar apply", dim, op, k, q);
      }
    }
    /* divergence of the first dim components */
    static double ud[NMAX * 3], div[NMAX];
    for (int i = 0; i < n; ++i)
      for (int d = 0; d < dim; ++d) ud[i * dim + d] = u[i * NC + d];
    assert_ok(ctx, mfree_approximant_apply(a, MFREE_OP_DIVERGENCE, dim, ud, MFREE_LAYOUT_AOS, dim, div, MFREE_LAYOUT_AOS, 1));
    assert_ok(ctx, mfree_approximant_apply(a, MFREE_OP_GRADIENT, dim, ud, MFREE_LAYOUT_AOS, dim, g, MFREE_LAYOUT_AOS, dim * dim));
    const double gs = maxabs(g, n * dim * dim);
    for (int i = 0; i < n; ++i) {
      double t = 0.0;
      for (int d = 0; d < dim; ++d) t += g[i * dim * dim + d * dim + d];
      if (fabs(div[i] - t) > 1e-13 * gs) fail_msg("dim %d site %d: divergence %.17g, trace of gradient %.17g", dim, i, div[i], t);
    }
    /* Laplacian of each component */
    assert_ok(ctx, mfree_approximant_apply(a, MFREE_OP_LAPLACIAN, NC, u, MFREE_LAYOUT_AOS, NC, tr, MFREE_LAYOUT_AOS, NC));
    apply_ref(a, MFREE_OP_HESSIAN, dim, NC, u, vec);
    const double hsc = maxabs(vec, n * NC * nh);
    for (int i = 0; i < n; ++i)
      for (int k = 0; k < NC; ++k) {
        double t = 0.0;
        for (int d = 0; d < dim; ++d) t += vec[i * NC * nh + k * nh + d * dim - d * (d - 1) / 2];
        if (fabs(tr[i * NC + k] - t) > 1e-13 * hsc)
          fail_msg("dim %d site %d comp %d: Laplacian %.17g, trace of Hessian %.17g", dim, i, k, tr[i * NC + k], t);
      }
    /* misuse: divergence needs ncomp = dim; tables not built */
    assert_error(ctx, mfree_approximant_apply(a, MFREE_OP_DIVERGENCE, dim + 1, u, MFREE_LAYOUT_AOS, dim + 1, div, MFREE_LAYOUT_AOS, 1),
                 MFREE_ERR_MISMATCH, "divergence");
    assert_ok(ctx, mfree_approximant_destroy(&a));
    mfree_approximant_t *b = NULL;
    assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, &b));
    assert_ok(ctx, mfree_approximant_setup(b)); /* default tables: value and gradient */
    assert_error(ctx, mfree_approximant_apply(b, MFREE_OP_LAPLACIAN, 1, u, MFREE_LAYOUT_AOS, 1, tr, MFREE_LAYOUT_AOS, 1),
                 MFREE_ERR_STATE, "Hessian");
    assert_ok(ctx, mfree_approximant_destroy(&b));
    assert_ok(ctx, mfree_particles_destroy(&ps));
  }
}

/* Dense mat-vec with the exported tables equals apply, for every operator. */
static void check_csr_matches_apply(const mfree_approximant_t *a, int dim, int n, int nsites, const char *what) {
  const int nh = dim * (dim + 1) / 2;
  int64_t nnz = 0;
  assert_ok(ctx, mfree_approximant_get_nnz(a, &nnz));
  int64_t *rp = malloc(sizeof(int64_t) * (size_t)(nsites + 1));
  int32_t *cols = malloc(sizeof(int32_t) * (size_t)nnz);
  double *vals = malloc(sizeof(double) * (size_t)nnz * (size_t)(1 + dim + nh));
  assert_non_null(rp);
  assert_non_null(cols);
  assert_non_null(vals);
  /* tables: 0 value, 1..dim gradient, then Hessian */
  assert_ok(ctx, mfree_approximant_assemble_csr(a, MFREE_DERIV_VALUE, 0, rp, cols, vals));
  for (int d = 0; d < dim; ++d)
    assert_ok(ctx, mfree_approximant_assemble_csr(a, MFREE_DERIV_GRADIENT, d, NULL, NULL, vals + (size_t)(1 + d) * nnz));
  for (int e = 0; e < nh; ++e)
    assert_ok(ctx, mfree_approximant_assemble_csr(a, MFREE_DERIV_HESSIAN, e, NULL, NULL, vals + (size_t)(1 + dim + e) * nnz));
  assert_int_equal(rp[0], 0);
  assert_int_equal(rp[nsites], nnz);
  static double u[NMAX * NC], out[NMAX * 18];
  random_field(NMAX, NC, u, 99u); /* read as SoA with ld = NMAX */
  for (int oi = 0; oi < 5; ++oi) {
    const int op = kOps[oi], nc = op_in(op, dim), oc = op_out(op, dim);
    assert_ok(ctx, mfree_approximant_apply(a, (mfree_op_t)op, nc, u, MFREE_LAYOUT_SOA, NMAX, out, MFREE_LAYOUT_AOS, oc));
    double big = 0.0, err = 0.0;
    for (int s = 0; s < nsites; ++s)
      for (int q = 0; q < oc; ++q) {
        double acc = 0.0, absacc = 0.0;
        for (int64_t k = rp[s]; k < rp[s + 1]; ++k) {
          const int j = cols[k];
          assert_true(j >= 0 && j < n);
          double t = 0.0;
          switch (op) {
            case MFREE_OP_VALUE:
              t = vals[k] * u[q * NMAX + j];
              break;
            case MFREE_OP_GRADIENT:
              t = vals[(size_t)(1 + q % dim) * nnz + k] * u[(q / dim) * NMAX + j];
              break;
            case MFREE_OP_DIVERGENCE:
              for (int d = 0; d < dim; ++d) t += vals[(size_t)(1 + d) * nnz + k] * u[d * NMAX + j];
              break;
            case MFREE_OP_LAPLACIAN:
              for (int d = 0; d < dim; ++d) t += vals[(size_t)(1 + dim + d * dim - d * (d - 1) / 2) * nnz + k] * u[q * NMAX + j];
              break;
            case MFREE_OP_HESSIAN:
              t = vals[(size_t)(1 + dim + q % nh) * nnz + k] * u[(q / nh) * NMAX + j];
              break;
          }
          acc += t;
          absacc += fabs(t);
        }
        big = fmax(big, absacc);
        err = fmax(err, fabs(out[s * oc + q] - acc));
      }
    if (err > 1e-14 * big) fail_msg("%s, op %d: apply differs from the CSR mat-vec by %.3g (scale %.3g)", what, op, err, big);
  }
  free(rp);
  free(cols);
  free(vals);
}

static void test_csr_equals_apply(void **s) {
  (void)s;
  static cloud_t c;
  const mfree_method_t methods[4] = {MFREE_METHOD_MLS, MFREE_METHOD_SSPH, MFREE_METHOD_SHEPARD, MFREE_METHOD_KB_METHOD2};
  for (int dim = 1; dim <= 3; ++dim)
    for (int mi = 0; mi < 4; ++mi) {
      make_cloud(&c, dim, dim == 1 ? 30 : (dim == 2 ? 12 : 6), 0, 50u + (uint64_t)dim);
      mfree_particles_t *ps = make_set(&c, 0);
      mfree_approximant_t *a = make_approx(ps, methods[mi], methods[mi] == MFREE_METHOD_SHEPARD ? 0 : 2);
      check_csr_matches_apply(a, dim, c.n, c.n, "no ghosts");
      assert_ok(ctx, mfree_approximant_destroy(&a));
      assert_ok(ctx, mfree_particles_destroy(&ps));
    }
}

/* Ghosts: owned sites only, ghost columns, owned rows unchanged by the ghost flag. */
static void test_ghosts(void **s) {
  (void)s;
  static cloud_t c;
  static double u[NMAX], out[NMAX * 3], ref[NMAX * 3];
  for (int dim = 1; dim <= 3; ++dim) {
    make_cloud(&c, dim, dim == 1 ? 30 : (dim == 2 ? 14 : 6), 1, 60u + (uint64_t)dim);
    const int n = c.n, nown = c.n - c.n_ghost;
    assert_true(c.n_ghost > 0);
    mfree_particles_t *pg = make_set(&c, 1), *pa = make_set(&c, 0);
    int32_t gsize = 0, gng = 0;
    assert_ok(ctx, mfree_particles_get_size(pg, &gsize, &gng));
    assert_int_equal(gsize, n);
    assert_int_equal(gng, c.n_ghost);
    mfree_approximant_t *ag = make_approx(pg, MFREE_METHOD_MLS, 1);
    mfree_approximant_t *aa = make_approx(pa, MFREE_METHOD_MLS, 1);
    int32_t ns = 0;
    assert_ok(ctx, mfree_approximant_get_num_sites(ag, &ns));
    assert_int_equal(ns, nown);
    assert_ok(ctx, mfree_approximant_get_num_sites(aa, &ns));
    assert_int_equal(ns, n);

    /* rows of the owned particles: same columns (ghosts among them) and values */
    int64_t nnzg = 0, nnza = 0;
    assert_ok(ctx, mfree_approximant_get_nnz(ag, &nnzg));
    assert_ok(ctx, mfree_approximant_get_nnz(aa, &nnza));
    int64_t *rg = malloc(sizeof(int64_t) * (size_t)(nown + 1)), *ra = malloc(sizeof(int64_t) * (size_t)(n + 1));
    int32_t *cg = malloc(sizeof(int32_t) * (size_t)nnzg), *ca = malloc(sizeof(int32_t) * (size_t)nnza);
    double *vg = malloc(sizeof(double) * (size_t)nnzg), *va = malloc(sizeof(double) * (size_t)nnza);
    assert_true(rg && ra && cg && ca && vg && va);
    const int nh = dim * (dim + 1) / 2;
    int ghost_cols = 0;
    for (int t = 0; t < 1 + dim + nh; ++t) {
      const mfree_deriv_t deriv = t == 0 ? MFREE_DERIV_VALUE : (t <= dim ? MFREE_DERIV_GRADIENT : MFREE_DERIV_HESSIAN);
      const int comp = t == 0 ? 0 : (t <= dim ? t - 1 : t - 1 - dim);
      assert_ok(ctx, mfree_approximant_assemble_csr(ag, deriv, comp, rg, cg, vg));
      assert_ok(ctx, mfree_approximant_assemble_csr(aa, deriv, comp, ra, ca, va));
      assert_int_equal(rg[nown], nnzg);
      for (int si = 0; si < nown; ++si) {
        assert_int_equal(rg[si + 1] - rg[si], ra[si + 1] - ra[si]);
        for (int64_t k = rg[si]; k < rg[si + 1]; ++k) {
          /* match by column (rows need not be ordered alike) */
          const int32_t j = cg[k];
          assert_true(j >= 0 && j < n);
          if (t == 0 && j >= nown) ++ghost_cols;
          int found = 0;
          for (int64_t q = ra[si]; q < ra[si + 1] && !found; ++q)
            if (ca[q] == j) {
              found = 1;
              if (fabs(va[q] - vg[k]) > 1e-14 * (fabs(va[q]) + 1e-300) && va[q] != vg[k])
                fail_msg("dim %d table %d site %d col %d: %.17g with ghosts, %.17g without", dim, t, si, j, vg[k], va[q]);
            }
          if (!found) fail_msg("dim %d site %d: column %d only with ghosts", dim, si, j);
        }
      }
    }
    assert_true(ghost_cols > 0);

    /* apply: u over all n particles, out over the owned sites; SoA ld checks use n and
     * the number of sites */
    for (int i = 0; i < n; ++i) u[i] = 0.3 - 1.1 * c.x[i * dim] + (dim > 1 ? 0.7 * c.x[i * dim + 1] : 0.0);
    assert_ok(ctx, mfree_approximant_apply(ag, MFREE_OP_GRADIENT, 1, u, MFREE_LAYOUT_SOA, n, out, MFREE_LAYOUT_SOA, nown));
    for (int i = 0; i < nown; ++i) {
      /* linear field: exact gradient at every owned site (MLS order 1), the boundary
       * owned particles leaning on the ghosts */
      if (fabs(out[i] + 1.1) > 1e-10 / c.h[i]) fail_msg("dim %d site %d: d/dx %.17g", dim, i, out[i]);
      if (dim > 1 && fabs(out[nown + i] - 0.7) > 1e-10 / c.h[i]) fail_msg("dim %d site %d: d/dy %.17g", dim, i, out[nown + i]);
    }
    assert_ok(ctx, mfree_approximant_apply(aa, MFREE_OP_GRADIENT, 1, u, MFREE_LAYOUT_SOA, n, ref, MFREE_LAYOUT_SOA, n));
    for (int i = 0; i < nown; ++i)
      for (int d = 0; d < dim; ++d)
        if (fabs(out[d * nown + i] - ref[d * n + i]) > 1e-13 * (fabs(ref[d * n + i]) + 1.0))
          fail_msg("dim %d site %d: gradient with ghosts differs from without", dim, i);
    assert_error(ctx, mfree_approximant_apply(ag, MFREE_OP_VALUE, 1, u, MFREE_LAYOUT_SOA, n - 1, out, MFREE_LAYOUT_SOA, nown),
                 MFREE_ERR_ARG, "leading dimension");
    assert_error(ctx, mfree_approximant_apply(ag, MFREE_OP_VALUE, 1, u, MFREE_LAYOUT_SOA, n, out, MFREE_LAYOUT_SOA, nown - 1),
                 MFREE_ERR_ARG, "leading dimension");
    check_csr_matches_apply(ag, dim, n, nown, "ghosts");

    free(rg);
    free(ra);
    free(cg);
    free(ca);
    free(vg);
    free(va);
    assert_ok(ctx, mfree_approximant_destroy(&ag));
    assert_ok(ctx, mfree_approximant_destroy(&aa));
    assert_ok(ctx, mfree_particles_destroy(&pg));
    assert_ok(ctx, mfree_particles_destroy(&pa));
  }
}

int main(int argc, char **argv) {
  backend = mfree_test_backend(argc, argv);
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_apply_add),
      cmocka_unit_test(test_layouts),
      cmocka_unit_test(test_components_and_traces),
      cmocka_unit_test(test_csr_equals_apply),
      cmocka_unit_test(test_ghosts),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
