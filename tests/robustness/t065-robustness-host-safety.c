/* Never corrupt the host (mfree.h, "Statuses"): a call with a negative status changes
 * nothing; after a positive status every site reported valid holds finite values.
 *  1. Every setter that copies host data (particle positions, volumes, masses,
 *     densities, supports, neighbour lists; approximant points; mesh elements) with each
 *     of its allocations failing in turn (the context's allocator hook): MFREE_ERR_ALLOC,
 *     and the object gives bitwise the results it gave before (a half-updated copy used to
 *     leave rows and columns of different lists: a heap-buffer-overflow at the next setup).
 *     At least one allocation of each copy must go through the hook.
 *  2. For every method, NaN / Inf / zero in borrowed
 *     positions, supports and volumes, through the documented per-step path
 *     (particles_update + approximant_update) and through approximant_update alone: a
 *     positive status, the particle's own site and every site whose row holds it fail
 *     with the data's class (MFREE_FAIL_NONFINITE, or MFREE_FAIL_INVALID_DATA for a
 *     support of 0), and every other site's rows are finite (MPFEM: a mesh node without a
 *     finite position makes the mesh invalid, MFREE_ERR_INPUT, tables unchanged). Tiny
 *     supports (1e-300) at a particle (at setup and at an update) and at a host point: no
 *     non-finite value at a valid site.
 *  3. approximant_update after the particle set changed under it (ghost count, a search
 *     that found other rows, a set_* without setup): MFREE_ERR_STATE and the approximant
 *     unchanged; after a setup of the set with the same rows it updates. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "count_alloc.h"
#include "testutil.h"

enum { M = 6, N = M * M };
static const double SP = 1.0 / M;

static void lattice(double *x, double scale, uint64_t seed) {
  mfree_rng_t r;
  mfree_rng_seed(&r, seed);
  for (int p = 0; p < N; ++p) {
    x[2 * p] = scale * (p % M + 0.5 + 0.3 * (mfree_rng_uniform(&r) - 0.5)) * SP;
    x[2 * p + 1] = scale * (p / M + 0.5 + 0.3 * (mfree_rng_uniform(&r) - 0.5)) * SP;
  }
}

/* ---- 1. failed copies ---------------------------------------------------------------- */

static counter_t C = {0, 0, 0, -1};

/* Gradient of a fixed field by approximant a after setting its set and a up again. */
static void results(mfree_context_t *ctx, mfree_particles_t *ps, mfree_approximant_t *a, int32_t n,
                    double *out, int64_t *nnz) {
  double u[N];
  for (int p = 0; p < n; ++p) u[p] = sin(1.0 + p);
  assert_ok(ctx, mfree_particles_setup(ps));
  assert_ok(ctx, mfree_approximant_setup(a));
  int32_t ns = 0;
  assert_ok(ctx, mfree_approximant_get_num_sites(a, &ns));
  memset(out, 0, sizeof(double) * 2 * (size_t)N);
  assert_ok(ctx, mfree_approximant_apply(a, MFREE_OP_GRADIENT, 1, u, MFREE_LAYOUT_AOS, 1, out,
                                         MFREE_LAYOUT_AOS, 2));
  assert_ok(ctx, mfree_approximant_get_nnz(a, nnz));
  *nnz = *nnz * 1000 + ns;
}

typedef mfree_status_t (*setter_fn)(void *obj, int variant);
static double Xa[2 * N], Xb[2 * N], Va[N], Vb[N], Ha[N], Hb[N], Pa[2 * 10], Pb[2 * 20];
static int64_t RPa[N + 1], RPb[N + 1];
static int32_t CLa[N * N], CLb[N * N];

static void host_lists(const double *x, double r, int64_t *rp, int32_t *cl) {
  rp[0] = 0;
  for (int i = 0; i < N; ++i) {
    int64_t k = rp[i];
    for (int j = N - 1; j >= 0; --j) { /* unsorted rows */
      const double dx = x[2 * i] - x[2 * j], dy = x[2 * i + 1] - x[2 * j + 1];
      if (dx * dx + dy * dy <= r * r) cl[k++] = j;
    }
    rp[i + 1] = k;
  }
}

typedef struct {
  const char *name;
  int kind; /* 0 positions, 1 volumes, 2 masses, 3 densities, 4 support, 5 lists, 6 points, 7 mesh */
} setter_t;

static mfree_status_t call_setter(int kind, int variant, mfree_particles_t *ps, mfree_approximant_t *a,
                                  mfree_mesh_t *mesh) {
  switch (kind) {
    case 0: return mfree_particles_set_positions(ps, variant ? Xb : Xa, MFREE_LAYOUT_AOS, 2, MFREE_COPY);
    case 1: return mfree_particles_set_volumes(ps, variant ? Vb : Va, 1, MFREE_COPY);
    case 2: return mfree_particles_set_masses(ps, variant ? Vb : Va, 1, MFREE_COPY);
    case 3: return mfree_particles_set_densities(ps, variant ? Vb : Va, 1, MFREE_COPY);
    case 4: return mfree_particles_set_support(ps, variant ? Hb : Ha, 1, MFREE_COPY);
    case 5: return mfree_particles_set_neighbors(ps, variant ? RPb : RPa, variant ? CLb : CLa, 0, MFREE_COPY);
    case 6: return mfree_approximant_set_points(a, variant ? 20 : 10, variant ? Pb : Pa, MFREE_LAYOUT_AOS, 2,
                                                variant ? Hb : Ha, 1, MFREE_COPY);
    default: {
      static const int32_t quad[4] = {0, 1, M + 1, M};
      static const int32_t quads[8] = {1, 2, M + 2, M + 1, 2, 3, M + 3, M + 2};
      return mfree_mesh_add_elements(mesh, MFREE_ELEMENT_QUAD4, variant ? 2 : 1, variant ? quads : quad, 0,
                                     MFREE_COPY);
    }
  }
}

static void test_failed_copy_changes_nothing(void **state) {
  (void)state;
  lattice(Xa, 1.0, 1);
  lattice(Xb, 0.9, 2);
  for (int p = 0; p < N; ++p) {
    Va[p] = SP * SP * (1.0 + 0.01 * (p % 3));
    Vb[p] = 2.0 * Va[p];
    Ha[p] = 1.5 * SP;
    Hb[p] = 1.7 * SP;
  }
  for (int s = 0; s < 20; ++s) {
    if (s < 10) Pa[2 * s] = Xa[2 * (s + 7)] + 0.01, Pa[2 * s + 1] = Xa[2 * (s + 7) + 1];
    Pb[2 * s] = Xa[2 * (s + 8)] - 0.01, Pb[2 * s + 1] = Xa[2 * (s + 8) + 1];
  }
  host_lists(Xa, 3.0 * SP, RPa, CLa);
  host_lists(Xa, 3.3 * SP, RPb, CLb);
  assert_true(RPb[N] > RPa[N]);

  static const char *names[] = {"positions", "volumes", "masses", "densities", "support",
                                "neighbour lists", "points", "mesh elements"};
  for (int kind = 0; kind < 8; ++kind) {
    mfree_context_t *ctx = NULL;
    assert_ok(NULL, mfree_context_create(&ctx));
    assert_ok(ctx, mfree_context_set_allocator(ctx, count_alloc, count_free, &C));
    mfree_particles_t *ps = NULL;
    mfree_approximant_t *a = NULL;
    mfree_mesh_t *mesh = NULL;
    assert_ok(ctx, mfree_particles_create(ctx, 2, N, &ps));
    assert_ok(ctx, call_setter(0, 0, ps, NULL, NULL));
    assert_ok(ctx, call_setter(4, 0, ps, NULL, NULL));
    assert_ok(ctx, call_setter(1, 0, ps, NULL, NULL));
    if (kind == 2 || kind == 3) { /* the set's volumes from masses and densities */
      mfree_particles_destroy(&ps);
      assert_ok(ctx, mfree_particles_create(ctx, 2, N, &ps));
      assert_ok(ctx, call_setter(0, 0, ps, NULL, NULL));
      assert_ok(ctx, call_setter(4, 0, ps, NULL, NULL));
      assert_ok(ctx, call_setter(2, 0, ps, NULL, NULL));
      assert_ok(ctx, call_setter(3, 0, ps, NULL, NULL));
    }
    if (kind == 5) assert_ok(ctx, call_setter(5, 0, ps, NULL, NULL));
    assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_RKPM, &a));
    if (kind == 6) assert_ok(ctx, call_setter(6, 0, ps, a, NULL));
    if (kind == 7) {
      assert_ok(ctx, mfree_mesh_create(ctx, ps, &mesh));
      assert_ok(ctx, call_setter(7, 0, ps, NULL, mesh));
    }
    double ref[2 * N], got[2 * N];
    int64_t ref_nnz = 0, got_nnz = 0;
    results(ctx, ps, a, N, ref, &ref_nnz);
    int32_t ref_nel = 0, nel = 0;
    if (mesh) assert_ok(ctx, mfree_mesh_get_size(mesh, &ref_nel));

    int failures = 0;
    for (int k = 0;; ++k) {
      C.fail_after = C.calls + k;
      const mfree_status_t st = call_setter(kind, 1, ps, a, mesh);
      C.fail_after = -1;
      if (st == MFREE_SUCCESS) break;
      if (st != MFREE_ERR_ALLOC) fail_msg("%s: status %d with %d allocations allowed", names[kind], st, k);
      ++failures;
      results(ctx, ps, a, N, got, &got_nnz);
      if (got_nnz != ref_nnz || memcmp(got, ref, sizeof got) != 0)
        fail_msg("%s: a failed copy (%d allocations allowed) changed the results", names[kind], k);
      if (mesh) {
        assert_ok(ctx, mfree_mesh_get_size(mesh, &nel));
        assert_int_equal(nel, ref_nel);
      }
      assert_true(k < 100);
    }
    if (failures == 0) fail_msg("%s: no allocation of the copy went through the hook", names[kind]);
    mfree_mesh_destroy(&mesh);
    mfree_approximant_destroy(&a);
    mfree_particles_destroy(&ps);
    mfree_context_destroy(&ctx);
    assert_int_equal(C.held, 0);
  }
}

/* ---- 2. non-finite and invalid data --------------------------------------------------- */

typedef struct {
  mfree_context_t *ctx;
  mfree_particles_t *ps;
  mfree_approximant_t *a;
  mfree_mesh_t *mesh; /* MPFEM: quadrilaterals over the lattice */
  double x[2 * N], h[N], v[N];
} fix_t;

static int flags_of(int method) { (void)method; return MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT; }

/* A borrowed 2D set and an approximant of `method` on it; status of the setup. */
static mfree_status_t build(fix_t *f, int method, double tiny_h_at) {
  memset(f, 0, sizeof *f);
  lattice(f->x, 1.0, 7);
  /* MPFEM: supports of half a spacing (004 eq 13: each node's support stays inside
   * its own elements) */
  const double h = method == MFREE_METHOD_MPFEM ? 0.5 * SP : 1.5 * SP;
  for (int p = 0; p < N; ++p) f->h[p] = h, f->v[p] = SP * SP;
  if (tiny_h_at >= 0) f->h[(int)tiny_h_at] = 1e-300;
  assert_ok(NULL, mfree_context_create(&f->ctx));
  assert_ok(f->ctx, mfree_particles_create(f->ctx, 2, N, &f->ps));
  assert_ok(f->ctx, mfree_particles_set_positions(f->ps, f->x, MFREE_LAYOUT_AOS, 2, MFREE_BORROW));
  assert_ok(f->ctx, mfree_particles_set_support(f->ps, f->h, 1, MFREE_BORROW));
  assert_ok(f->ctx, mfree_particles_set_volumes(f->ps, f->v, 1, MFREE_BORROW));
  assert_ok(f->ctx, mfree_approximant_create(f->ctx, f->ps, (mfree_method_t)method, &f->a));
  mfree_approximant_set_derivatives(f->a, flags_of(method));
  if (method == MFREE_METHOD_MPFEM) {
    int32_t conn[4 * (M - 1) * (M - 1)];
    for (int j = 0; j + 1 < M; ++j)
      for (int i = 0; i + 1 < M; ++i) {
        int32_t *c = conn + 4 * (j * (M - 1) + i);
        c[0] = j * M + i, c[1] = j * M + i + 1, c[2] = (j + 1) * M + i + 1, c[3] = (j + 1) * M + i;
      }
    assert_ok(f->ctx, mfree_mesh_create(f->ctx, f->ps, &f->mesh));
    assert_ok(f->ctx, mfree_mesh_add_elements(f->mesh, MFREE_ELEMENT_QUAD4, (M - 1) * (M - 1), conn, 0,
                                              MFREE_COPY));
    assert_ok(f->ctx, mfree_approximant_set_mesh(f->a, f->mesh));
  }
  return mfree_approximant_setup(f->a);
}

static void destroy(fix_t *f) {
  mfree_mesh_destroy(&f->mesh);
  mfree_approximant_destroy(&f->a);
  mfree_particles_destroy(&f->ps);
  mfree_context_destroy(&f->ctx);
}

/* Every valid site's rows finite; sites whose row (or own particle) holds `bad` have
 * status `cls` (bad < 0: no such check). Returns the number of failed sites. */
static int check_sites(fix_t *f, int method, int bad, int cls, const char *what) {
  int32_t ns = 0, nf = 0;
  int64_t nnz = 0;
  assert_ok(f->ctx, mfree_approximant_get_num_sites(f->a, &ns));
  assert_ok(f->ctx, mfree_approximant_get_nnz(f->a, &nnz));
  int32_t *st = malloc(sizeof(int32_t) * (size_t)(ns + 1));
  int64_t *rp = malloc(sizeof(int64_t) * (size_t)(ns + 1));
  int32_t *cl = malloc(sizeof(int32_t) * (size_t)(nnz + 1));
  double *val = malloc(sizeof(double) * (size_t)(nnz + 1));
  assert_ok(f->ctx, mfree_approximant_get_site_status(f->a, st, &nf));
  const int fl = flags_of(method);
  for (int d = 0; d < 3; ++d) {
    const mfree_deriv_t deriv = d == 0 ? MFREE_DERIV_VALUE : MFREE_DERIV_GRADIENT;
    if (!(fl & deriv)) continue;
    assert_ok(f->ctx, mfree_approximant_assemble_csr(f->a, deriv, d == 0 ? 0 : d - 1, rp, cl, val));
    for (int32_t s = 0; s < ns; ++s) {
      int holds = s == bad && ns == N;
      for (int64_t k = rp[s]; k < rp[s + 1]; ++k) holds |= cl[k] == bad;
      if (bad >= 0 && holds && st[s] != cls)
        fail_msg("method %d, %s: site %d holds particle %d but has status %d, not %d", method, what, s, bad,
                 st[s], cls);
      if (st[s] != 0) continue;
      for (int64_t k = rp[s]; k < rp[s + 1]; ++k)
        if (!isfinite(val[k]))
          fail_msg("method %d, %s: site %d is reported valid but holds %g", method, what, s, val[k]);
    }
  }
  free(st), free(rp), free(cl), free(val);
  return nf;
}

static void test_nonfinite_never_valid(void **state) {
  (void)state;
  enum { K = 14 }; /* an interior particle */
  typedef struct {
    int array; /* 0 x, 1 h, 2 v */
    double value;
    int cls;
    const char *name;
  } bad_t;
  const bad_t cases[] = {{0, NAN, MFREE_FAIL_NONFINITE, "position NaN"},
                         {0, INFINITY, MFREE_FAIL_NONFINITE, "position Inf"},
                         {1, NAN, MFREE_FAIL_NONFINITE, "support NaN"},
                         {1, 0.0, MFREE_FAIL_INVALID_DATA, "support 0"},
                         {2, NAN, MFREE_FAIL_NONFINITE, "volume NaN"},
                         {2, -1.0, MFREE_FAIL_INVALID_DATA, "volume < 0"}};
  for (int method = MFREE_METHOD_SPH; method <= MFREE_METHOD_MPFEM; ++method) {
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; ++c)
      for (int path = 0; path < 2; ++path) {
        fix_t f;
        const mfree_status_t st0 = build(&f, method, -1);
        assert_true(st0 >= 0);
        check_sites(&f, method, -1, 0, "setup");
        double *arr = cases[c].array == 0 ? f.x + 2 * K : cases[c].array == 1 ? f.h + K : f.v + K;
        *arr = cases[c].value;
        if (path == 0) {
          const mfree_status_t sp = mfree_particles_update(f.ps);
          assert_int_equal(sp, cases[c].cls);
        }
        const mfree_status_t st = mfree_approximant_update(f.a);
        char what[96];
        snprintf(what, sizeof what, "%s, %s", cases[c].name, path ? "update alone" : "particles_update + update");
        if (method == MFREE_METHOD_MPFEM && cases[c].array == 0) {
          /* a mesh node without a finite position: the mesh is invalid (mfree.h,
           * mfree_mesh_setup), a negative status, and the tables stay as they were */
          assert_int_equal(st, MFREE_ERR_INPUT);
          check_sites(&f, method, -1, 0, what);
        } else {
          if (st != cases[c].cls) fail_msg("method %d, %s: update returned %d, not %d", method, what, st, cases[c].cls);
          assert_true(check_sites(&f, method, K, cases[c].cls, what) > 0);
        }
        destroy(&f);
      }
    /* a tiny support turning up at the update */
    for (int path = 0; path < 2; ++path) {
      fix_t f;
      assert_true(build(&f, method, -1) >= 0);
      f.h[K] = 1e-300;
      if (path == 0) assert_ok(f.ctx, mfree_particles_update(f.ps));
      assert_true(mfree_approximant_update(f.a) >= 0);
      check_sites(&f, method, -1, 0, "support 1e-300 at an update");
      destroy(&f);
    }
    /* tiny supports at a particle (set up with it) */
    fix_t f;
    const mfree_status_t st = build(&f, method, K);
    assert_true(st >= 0);
    check_sites(&f, method, -1, 0, "support 1e-300 at a particle");
    /* and at a host point */
    double pts[4] = {0.5, 0.5, 0.3, 0.6}, ph[2] = {1.5 * SP, 1e-300};
    if (mfree_approximant_set_points(f.a, 2, pts, MFREE_LAYOUT_AOS, 2, ph, 1, MFREE_COPY) == MFREE_SUCCESS) {
      assert_true(mfree_approximant_setup(f.a) >= 0);
      check_sites(&f, method, -1, 0, "support 1e-300 at a host point");
    }
    destroy(&f);
  }
}

/* ---- 3. update after the set changed ----------------------------------------------------- */

static void test_update_notices_changed_set(void **state) {
  (void)state;
  fix_t f;
  assert_ok(f.ctx, build(&f, MFREE_METHOD_MLS, -1));
  int32_t ns = 0;
  assert_ok(f.ctx, mfree_approximant_update(f.a));
  /* a setup of the set that finds the same rows: update goes on */
  assert_ok(f.ctx, mfree_particles_setup(f.ps));
  assert_ok(f.ctx, mfree_approximant_update(f.a));

  /* ghost count 0 -> 18, the set set up again */
  assert_ok(f.ctx, mfree_particles_set_num_ghost(f.ps, N / 2));
  assert_error(f.ctx, mfree_approximant_update(f.a), MFREE_ERR_STATE, "not set up");
  assert_ok(f.ctx, mfree_particles_setup(f.ps));
  assert_error(f.ctx, mfree_approximant_update(f.a), MFREE_ERR_STATE, "owned particles");
  assert_ok(f.ctx, mfree_approximant_get_num_sites(f.a, &ns));
  assert_int_equal(ns, N); /* unchanged */
  assert_ok(f.ctx, mfree_approximant_setup(f.a));
  assert_ok(f.ctx, mfree_approximant_get_num_sites(f.a, &ns));
  assert_int_equal(ns, N / 2);
  assert_ok(f.ctx, mfree_approximant_update(f.a));

  /* the particles drawn together (borrowed), a new search: other rows */
  for (int k = 0; k < 2 * N; ++k) f.x[k] *= 0.8;
  assert_ok(f.ctx, mfree_particles_setup(f.ps));
  int64_t nnz0 = 0, nnz1 = 0;
  assert_ok(f.ctx, mfree_approximant_get_nnz(f.a, &nnz0));
  assert_error(f.ctx, mfree_approximant_update(f.a), MFREE_ERR_STATE, "neighbour lists");
  assert_ok(f.ctx, mfree_approximant_get_nnz(f.a, &nnz1));
  assert_int_equal(nnz0, nnz1);
  assert_ok(f.ctx, mfree_approximant_setup(f.a));
  assert_ok(f.ctx, mfree_approximant_get_nnz(f.a, &nnz1));
  assert_true(nnz1 > nnz0);
  assert_ok(f.ctx, mfree_approximant_update(f.a));
  destroy(&f);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_failed_copy_changes_nothing),
      cmocka_unit_test(test_nonfinite_never_valid),
      cmocka_unit_test(test_update_notices_changed_set),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
