/* Never corrupt the host (mfree.h, "Statuses"): a call with a negative status changes
 * nothing; after a positive status every site reported valid holds finite values.
 *  1. Every setter that copies host data (particle positions, volumes, masses,
 *     densities, supports, neighbour lists, global ids; approximant points; mesh
 *     elements; the assemblers' quadratures, boundary conditions and finite-element
 *     layer; the fluid systems' properties, masses, smoothing, walls and dummy particles)
 *     with each of its allocations failing in turn (the context's allocator hook):
 *     MFREE_ERR_ALLOC, and the object gives bitwise the results it gave before (a
 *     half-updated copy used to leave rows and columns of different lists: a
 *     heap-buffer-overflow at the next setup). At least one allocation of each copy must
 *     go through the hook.
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

/* The objects of one case; the setters under test copy into one of them. */
typedef struct {
  mfree_context_t *ctx;
  mfree_particles_t *ps;
  mfree_approximant_t *a;
  mfree_mesh_t *mesh;
  mfree_assembler_t *as;
  mfree_system_t *sys;
  double y[5 * N]; /* the fluid's state */
} objs_t;

/* A setter under test: kind, variant 0 (the state before) or 1 (the failing copy). */
typedef mfree_status_t (*setter_fn)(objs_t *o, int kind, int variant);
/* The results the objects give (set up again), as a digest of their bytes. */
typedef uint64_t (*results_fn)(objs_t *o);

static uint64_t digest(uint64_t h, const void *p, size_t bytes) {
  const unsigned char *b = (const unsigned char *)p;
  for (size_t k = 0; k < bytes; ++k) h = (h ^ b[k]) * 1099511628211ull; /* FNV-1a */
  return h;
}
static const uint64_t DIGEST0 = 14695981039346656037ull;

/* Calls setter (kind, variant 1) with each of its allocations failing in turn until it
 * succeeds: every failure is MFREE_ERR_ALLOC and leaves the results as they were; at
 * least one allocation went through the hook. */
static void inject(objs_t *o, int kind, const char *name, setter_fn setter, results_fn results) {
  const uint64_t ref = results(o);
  int failures = 0;
  for (int k = 0;; ++k) {
    C.fail_after = C.calls + k;
    const mfree_status_t st = setter(o, kind, 1);
    C.fail_after = -1;
    if (st == MFREE_SUCCESS) break;
    if (st != MFREE_ERR_ALLOC) fail_msg("%s: status %d with %d allocations allowed", name, st, k);
    ++failures;
    if (results(o) != ref) fail_msg("%s: a failed copy (%d allocations allowed) changed the results", name, k);
    assert_true(k < 100);
  }
  if (failures == 0) fail_msg("%s: no allocation of the copy went through the hook", name);
}

static void destroy_objs(objs_t *o) {
  mfree_system_destroy(&o->sys);
  mfree_assembler_destroy(&o->as);
  mfree_mesh_destroy(&o->mesh);
  mfree_approximant_destroy(&o->a);
  mfree_particles_destroy(&o->ps);
  mfree_context_destroy(&o->ctx);
  assert_int_equal(C.held, 0);
}

static double Xa[2 * N], Xb[2 * N], Va[N], Vb[N], Ha[N], Hb[N], Pa[2 * 10], Pb[2 * 20];
static int64_t IDa[N], IDb[N];
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

static void fill_data(void) {
  lattice(Xa, 1.0, 1);
  lattice(Xb, 0.9, 2);
  for (int p = 0; p < N; ++p) {
    Va[p] = SP * SP * (1.0 + 0.01 * (p % 3));
    Vb[p] = 2.0 * Va[p];
    Ha[p] = 1.5 * SP;
    Hb[p] = 1.7 * SP;
    IDa[p] = 3 * p + 1;
    IDb[p] = 5 * (N - p);
  }
  for (int s = 0; s < 20; ++s) {
    if (s < 10) Pa[2 * s] = Xa[2 * (s + 7)] + 0.01, Pa[2 * s + 1] = Xa[2 * (s + 7) + 1];
    Pb[2 * s] = Xa[2 * (s + 8)] - 0.01, Pb[2 * s + 1] = Xa[2 * (s + 8) + 1];
  }
  host_lists(Xa, 3.0 * SP, RPa, CLa);
  host_lists(Xa, 3.3 * SP, RPb, CLb);
  assert_true(RPb[N] > RPa[N]);
}

/* A context with the counting hook, and a set of the lattice's particles (copied). */
static void new_objs(objs_t *o, int volumes) {
  memset(o, 0, sizeof *o);
  assert_ok(NULL, mfree_context_create(&o->ctx));
  assert_ok(o->ctx, mfree_context_set_allocator(o->ctx, count_alloc, count_free, &C));
  assert_ok(o->ctx, mfree_particles_create(o->ctx, 2, N, &o->ps));
  assert_ok(o->ctx, mfree_particles_set_positions(o->ps, Xa, MFREE_LAYOUT_AOS, 2, MFREE_COPY));
  assert_ok(o->ctx, mfree_particles_set_support(o->ps, Ha, 1, MFREE_COPY));
  if (volumes) assert_ok(o->ctx, mfree_particles_set_volumes(o->ps, Va, 1, MFREE_COPY));
}

/* 1a. particle sets, approximants, meshes: kind 0 positions, 1 volumes, 2 masses,
 * 3 densities, 4 support, 5 lists, 6 points, 7 mesh, 8 global ids */
static mfree_status_t particle_setter(objs_t *o, int kind, int variant) {
  switch (kind) {
    case 0: return mfree_particles_set_positions(o->ps, variant ? Xb : Xa, MFREE_LAYOUT_AOS, 2, MFREE_COPY);
    case 1: return mfree_particles_set_volumes(o->ps, variant ? Vb : Va, 1, MFREE_COPY);
    case 2: return mfree_particles_set_masses(o->ps, variant ? Vb : Va, 1, MFREE_COPY);
    case 3: return mfree_particles_set_densities(o->ps, variant ? Vb : Va, 1, MFREE_COPY);
    case 4: return mfree_particles_set_support(o->ps, variant ? Hb : Ha, 1, MFREE_COPY);
    case 5:
      return mfree_particles_set_neighbors(o->ps, variant ? RPb : RPa, variant ? CLb : CLa, 0, MFREE_COPY);
    case 6: return mfree_approximant_set_points(o->a, variant ? 20 : 10, variant ? Pb : Pa, MFREE_LAYOUT_AOS, 2,
                                                variant ? Hb : Ha, 1, MFREE_COPY);
    case 7: {
      static const int32_t quad[4] = {0, 1, M + 1, M};
      static const int32_t quads[8] = {1, 2, M + 2, M + 1, 2, 3, M + 3, M + 2};
      return mfree_mesh_add_elements(o->mesh, MFREE_ELEMENT_QUAD4, variant ? 2 : 1, variant ? quads : quad, 0,
                                     MFREE_COPY);
    }
    default: return mfree_particles_set_global_ids(o->ps, variant ? IDb : IDa, MFREE_COPY);
  }
}

/* Gradient of a fixed field by the approximant after setting the set and it up again,
 * its nnz and site count, and the mesh's element count. */
static uint64_t approximant_results(objs_t *o) {
  double u[N], out[2 * N];
  for (int p = 0; p < N; ++p) u[p] = sin(1.0 + p);
  assert_ok(o->ctx, mfree_particles_setup(o->ps));
  assert_ok(o->ctx, mfree_approximant_setup(o->a));
  int32_t ns = 0, nel = 0;
  int64_t nnz = 0;
  assert_ok(o->ctx, mfree_approximant_get_num_sites(o->a, &ns));
  memset(out, 0, sizeof out);
  assert_ok(o->ctx, mfree_approximant_apply(o->a, MFREE_OP_GRADIENT, 1, u, MFREE_LAYOUT_AOS, 1, out,
                                            MFREE_LAYOUT_AOS, 2));
  assert_ok(o->ctx, mfree_approximant_get_nnz(o->a, &nnz));
  if (o->mesh) assert_ok(o->ctx, mfree_mesh_get_size(o->mesh, &nel));
  uint64_t h = digest(DIGEST0, out, sizeof out);
  h = digest(h, &nnz, sizeof nnz);
  h = digest(h, &ns, sizeof ns);
  return digest(h, &nel, sizeof nel);
}

static void test_failed_copy_changes_nothing(void **state) {
  (void)state;
  fill_data();
  static const char *names[] = {"positions", "volumes", "masses", "densities", "support",
                                "neighbour lists", "points", "mesh elements", "global ids"};
  for (int kind = 0; kind < 9; ++kind) {
    objs_t o;
    /* masses and densities: the set's volumes from them */
    const int from_masses = kind == 2 || kind == 3;
    new_objs(&o, !from_masses);
    if (from_masses) {
      assert_ok(o.ctx, particle_setter(&o, 2, 0));
      assert_ok(o.ctx, particle_setter(&o, 3, 0));
    }
    if (kind == 5 || kind == 8) assert_ok(o.ctx, particle_setter(&o, kind, 0));
    assert_ok(o.ctx, mfree_approximant_create(o.ctx, o.ps, MFREE_METHOD_RKPM, &o.a));
    if (kind == 6) assert_ok(o.ctx, particle_setter(&o, 6, 0));
    if (kind == 7) {
      assert_ok(o.ctx, mfree_mesh_create(o.ctx, o.ps, &o.mesh));
      assert_ok(o.ctx, particle_setter(&o, 7, 0));
    }
    inject(&o, kind, names[kind], particle_setter, approximant_results);
    destroy_objs(&o);
  }
}

/* 1b. assemblers: kind 0 quadrature points, 1 quadrature cells, 2 traction points,
 * 3 traction segments, 4 penalty points, 5 Nitsche points, 6 Lagrange points,
 * 7 consistent integration, 8 Dirichlet nodes, 9 finite-element layer (Galerkin
 * Laplace); 10 traction nodes (collocation Laplace) */
enum { ASM_KINDS = 11, ASM_COLLOCATION = 10 };

static void boundary_value(void *user, const double *x, double *v) {
  (void)user;
  v[0] = 1.0 + x[0] - 0.5 * x[1];
}

/* npts points on the unit square's boundary (on its bottom side only when !whole), with
 * weights and outward normals. */
static void boundary_points(int npts, int whole, double *x, double *w, double *nrm) {
  const int sides = whole ? 4 : 1, per = npts / sides;
  for (int p = 0; p < npts; ++p) {
    const int side = p / per;
    const double t = (p % per + 0.5) / per;
    const double px[4] = {t, 1.0, 1.0 - t, 0.0}, py[4] = {0.0, t, 1.0, 1.0 - t};
    const double nx[4] = {0.0, 1.0, 0.0, -1.0}, ny[4] = {-1.0, 0.0, 1.0, 0.0};
    x[2 * p] = px[side], x[2 * p + 1] = py[side];
    nrm[2 * p] = nx[side], nrm[2 * p + 1] = ny[side];
    w[p] = 1.0 / per;
  }
}

static mfree_status_t assembler_setter(objs_t *o, int kind, int variant) {
  double x[2 * 25], w[25], nrm[2 * 25];
  const int npts = variant ? 24 : 16;
  boundary_points(npts, kind == 7, x, w, nrm);
  static const int32_t nodes[] = {0, 1, 2, 3, 4, 5, 6};
  switch (kind) {
    case 0: { /* a g x g grid over the square */
      const int g = variant ? 5 : 4;
      for (int p = 0; p < g * g; ++p) x[2 * p] = (p % g + 0.5) / g, x[2 * p + 1] = (p / g + 0.5) / g, w[p] = 1.0 / (g * g);
      return mfree_assembler_set_quadrature_points(o->as, g * g, x, MFREE_LAYOUT_AOS, 2, w);
    }
    case 1: {
      const double lo[2] = {0.0, 0.0}, hi[2] = {1.0, 1.0};
      const int32_t ncells[2] = {variant ? 4 : 3, variant ? 4 : 3};
      return mfree_assembler_set_quadrature_cells(o->as, lo, hi, ncells, 2, NULL, NULL);
    }
    case 2: return mfree_assembler_add_traction(o->as, npts, x, MFREE_LAYOUT_AOS, 2, w, boundary_value, NULL);
    case 3: {
      const double seg[8] = {0.0, 0.0, 0.5, 0.0, 0.5, 0.0, 1.0, 0.0};
      return mfree_assembler_add_traction_segments(o->as, variant ? 2 : 1, seg, 3, boundary_value, NULL);
    }
    case 4:
    case 5:
    case 6: {
      const mfree_bc_t bc = kind == 4 ? MFREE_BC_PENALTY : kind == 5 ? MFREE_BC_NITSCHE : MFREE_BC_LAGRANGE;
      return mfree_assembler_add_dirichlet(o->as, bc, npts / 4, x, MFREE_LAYOUT_AOS, 2, w, nrm, 1,
                                           boundary_value, NULL);
    }
    case 7: return mfree_assembler_set_consistent_integration(o->as, npts, x, MFREE_LAYOUT_AOS, 2, w, nrm);
    case 8: return mfree_assembler_add_dirichlet_nodes(o->as, variant ? 4 : 3, nodes + 3 * variant, 1,
                                                       boundary_value, NULL);
    case 9: {
      const int32_t quad[2][4] = {{0, 1, M + 1, M}, {1, 2, M + 2, M + 1}}, gu[2][2] = {{0, 1}, {2, 1}};
      return mfree_assembler_set_fe_layer(o->as, 1, 4, quad[variant], 2, gu[variant], 1, boundary_value, NULL);
    }
    default:
      return mfree_assembler_add_traction_nodes(o->as, variant ? 4 : 3, nodes + 3 * variant, nrm,
                                                boundary_value, NULL);
  }
}

/* The assembler set up again: its size, matrix and right-hand side. */
static uint64_t assembler_results(objs_t *o) {
  assert_ok(o->ctx, mfree_assembler_setup(o->as));
  int32_t size[2] = {0, 0}, nrows = 0;
  int64_t nnz = 0;
  assert_ok(o->ctx, mfree_assembler_get_size(o->as, &size[0], &size[1]));
  mfree_matrix_t *K = NULL;
  assert_ok(o->ctx, mfree_assembler_assemble_matrix(o->as, &K));
  const int64_t *rp = NULL;
  const int32_t *cl = NULL;
  const double *val = NULL;
  assert_ok(o->ctx, mfree_matrix_get_size(K, &nrows, NULL, &nnz));
  assert_ok(o->ctx, mfree_matrix_get_csr(K, &rp, &cl, &val));
  double *f = calloc((size_t)size[0] + 1, sizeof(double));
  assert_ok(o->ctx, mfree_assembler_assemble_rhs(o->as, f));
  uint64_t h = digest(DIGEST0, size, sizeof size);
  h = digest(h, rp, sizeof(int64_t) * ((size_t)nrows + 1));
  h = digest(h, cl, sizeof(int32_t) * (size_t)nnz);
  h = digest(h, val, sizeof(double) * (size_t)nnz);
  h = digest(h, f, sizeof(double) * (size_t)size[0]);
  free(f);
  mfree_matrix_destroy(&K);
  return h;
}

static void test_failed_assembler_copy_changes_nothing(void **state) {
  (void)state;
  fill_data();
  static const char *names[ASM_KINDS] = {"quadrature points", "quadrature cells", "traction points",
                                         "traction segments", "penalty points", "Nitsche points",
                                         "Lagrange points", "consistent integration", "Dirichlet nodes",
                                         "finite-element layer", "traction nodes"};
  for (int kind = 0; kind < ASM_KINDS; ++kind) {
    objs_t o;
    new_objs(&o, 1);
    assert_ok(o.ctx, mfree_approximant_create(o.ctx, o.ps, MFREE_METHOD_RKPM, &o.a));
    if (kind == ASM_COLLOCATION) {
      assert_ok(o.ctx, mfree_approximant_set_order(o.a, 2));
      assert_ok(o.ctx, mfree_approximant_set_derivatives(
                           o.a, MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT | MFREE_DERIV_HESSIAN));
    }
    assert_ok(o.ctx, mfree_assembler_create(o.ctx, o.a, NULL,
                                            kind == ASM_COLLOCATION ? MFREE_FORM_COLLOCATION_LAPLACE
                                                                    : MFREE_FORM_LAPLACE,
                                            &o.as));
    if (kind == 9 || kind == ASM_COLLOCATION) assert_ok(o.ctx, assembler_setter(&o, 8, 0));
    assert_ok(o.ctx, assembler_setter(&o, kind, 0));
    inject(&o, kind, names[kind], assembler_setter, assembler_results);
    destroy_objs(&o);
  }
}

/* 1c. fluid systems: kind 0 fluid properties, 1 masses, 2 smoothing, 3 walls, 4 dummy
 * particles */
static mfree_status_t system_setter(objs_t *o, int kind, int variant) {
  switch (kind) {
    case 0: {
      const double rho0 = variant ? 1010.0 : 1000.0;
      return mfree_system_set_fluid(o->sys, &rho0, 0, 100.0, 7.0, 0.01);
    }
    case 1: return mfree_system_set_masses(o->sys, variant ? Vb : Va, 1);
    case 2: return mfree_system_set_smoothing(o->sys, variant ? 1.7 * SP : 1.5 * SP);
    default: {
      double wx[2 * 8], wn[2 * 8];
      for (int k = 0; k < 8; ++k) wx[2 * k] = (k + 0.5) / 8, wx[2 * k + 1] = -0.25 * SP, wn[2 * k] = 0.0, wn[2 * k + 1] = 1.0;
      if (kind == 3) return mfree_system_set_walls(o->sys, variant ? 8 : 6, wx, wn, 2.0 * SP, 10.0);
      const double vol = SP * SP;
      return mfree_system_set_dummy_particles(o->sys, variant ? 8 : 6, wx, &vol, 0);
    }
  }
}

/* The fluid's right-hand side at a fixed state. */
static uint64_t system_results(objs_t *o) {
  int32_t neq = 0;
  double ydot[5 * N];
  assert_ok(o->ctx, mfree_system_get_size(o->sys, &neq));
  assert_int_equal(neq, 5 * N);
  assert_ok(o->ctx, mfree_system_rhs(o->sys, 0.0, o->y, ydot));
  return digest(DIGEST0, ydot, sizeof ydot);
}

static void test_failed_system_copy_changes_nothing(void **state) {
  (void)state;
  fill_data();
  static const char *names[] = {"fluid properties", "fluid masses", "smoothing", "walls", "dummy particles"};
  for (int kind = 0; kind < 5; ++kind) {
    objs_t o;
    memset(&o, 0, sizeof o);
    assert_ok(NULL, mfree_context_create(&o.ctx));
    assert_ok(o.ctx, mfree_context_set_allocator(o.ctx, count_alloc, count_free, &C));
    for (int p = 0; p < N; ++p) {
      o.y[2 * p] = Xa[2 * p], o.y[2 * p + 1] = Xa[2 * p + 1];
      o.y[2 * N + 2 * p] = 0.1 * sin(p), o.y[2 * N + 2 * p + 1] = 0.1 * cos(p);
      o.y[4 * N + p] = 1000.0 * (1.0 + 0.01 * sin(3.0 * p));
    }
    assert_ok(o.ctx, mfree_system_create_fluid(o.ctx, 2, N, &o.sys));
    for (int k = 0; k < 3; ++k) assert_ok(o.ctx, system_setter(&o, k, 0));
    if (kind >= 3) assert_ok(o.ctx, system_setter(&o, kind, 0));
    inject(&o, kind, names[kind], system_setter, system_results);
    destroy_objs(&o);
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
      cmocka_unit_test(test_failed_assembler_copy_changes_nothing),
      cmocka_unit_test(test_failed_system_copy_changes_nothing),
      cmocka_unit_test(test_nonfinite_never_valid),
      cmocka_unit_test(test_update_notices_changed_set),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
