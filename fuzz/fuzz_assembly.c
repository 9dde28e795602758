/* libFuzzer harness: assembly and matrices. Bytes -> a jittered 1D/2D/3D lattice (some
 * data invalid), trial and test approximants (any method, kernel, order), a form (every
 * mfree_form_t and unknown ones), a quadrature (nodal, background cells with an
 * inside-test, host points with weights), material and coefficient, a body force,
 * essential conditions (penalty, Lagrange, collocation, Nitsche on boundary points;
 * conditions at nodes), tractions (points, 2D segments, 3D facets, collocation rows at
 * nodes), consistent integration, a finite-element layer over lattice cells, back to
 * nodal quadrature, setup, update after a move, the matrix (CSR, 32/64-bit views,
 * CSC, symmetric flag, product) and the right-hand side. Then a matrix from host CSR
 * (unsorted, repeated or out-of-range columns, non-finite values) and its product.
 * Oracles: documented statuses; a negative status leaves the matrix as it was; no NaN in
 * a matrix or right-hand side assembled with a success status from finite data. */
#include "fuzz_util.h"

enum { MAXM = 5, MAXN = MAXM * MAXM * MAXM, MAXQ = 16 };

static void body(void *user, const double *x, double *f) {
  const double s = *(const double *)user;
  for (int c = 0; c < 3; ++c) f[c] = s * (x[0] + c);
}
static void gfun(void *user, const double *x, double *g) {
  (void)user;
  for (int c = 0; c < 3; ++c) g[c] = sin(x[0]) - c; /* finite at any finite point */
}
static int32_t inside(void *user, const double *x) {
  (void)user;
  return x[0] < 0.8;
}

/* The matrix is finite, and the product works. */
static void check_matrix(const mfree_matrix_t *K, int finite) {
  int32_t nr = 0, nc = 0;
  int64_t nnz = 0;
  FZ_TRAP_IF(mfree_matrix_get_size(K, &nr, &nc, &nnz) != MFREE_SUCCESS);
  const int64_t *rp = NULL, *rp64 = NULL, *cp = NULL, *c64 = NULL;
  const int32_t *cl = NULL, *rp32 = NULL, *c32 = NULL, *ri = NULL;
  const double *v = NULL, *v32 = NULL, *v64 = NULL, *vc = NULL;
  FZ_TRAP_IF(mfree_matrix_get_csr(K, &rp, &cl, &v) != MFREE_SUCCESS);
  FZ_CHECK(mfree_matrix_get_csr_i32(K, &rp32, &c32, &v32));
  FZ_CHECK(mfree_matrix_get_csr_i64(K, &rp64, &c64, &v64));
  FZ_CHECK(mfree_matrix_get_csc(K, &cp, &ri, &vc));
  int32_t sym = -1;
  FZ_CHECK(mfree_matrix_get_symmetric(K, &sym));
  for (int64_t k = 0; k < nnz && finite; ++k) FZ_TRAP_IF(isnan(v[k]));
  double *x = calloc((size_t)nc + 1, sizeof *x), *y = calloc((size_t)nr + 1, sizeof *y);
  for (int32_t j = 0; j < nc; ++j) x[j] = 1.0 / (1.0 + j);
  FZ_CHECK(mfree_matrix_apply(K, x, y));
  free(x), free(y);
}

static void host_matrix(fz_bytes_t *b, mfree_context_t *ctx) {
  const int32_t nr = (int32_t)(fz_u8(b) % 9);
  const unsigned wc = fz_u8(b); /* (one read per statement: argument order is unspecified) */
  const int32_t nc = (int32_t)(wc % 9) - (wc == 3);
  int64_t rp[10];
  int32_t cl[80];
  double v[80];
  rp[0] = (int64_t)(fz_u8(b) == 9);
  for (int32_t i = 0; i < nr; ++i) {
    const int len = (int)(fz_u8(b) % 9);
    int64_t k = rp[i];
    for (int q = 0; q < len && k < 80; ++q, ++k) {
      const unsigned w = fz_u8(b);
      cl[k] = (int32_t)(w % (unsigned)(nc + 2)) - 1;
      v[k] = w == 255 ? NAN : w == 254 ? INFINITY : (double)w - 100.0;
    }
    rp[i + 1] = k;
  }
  mfree_matrix_t *A = NULL;
  const mfree_status_t st = mfree_matrix_create_csr(ctx, nr, nc, rp, cl, v, &A);
  FZ_TRAP_IF(!fz_valid_status(st));
  FZ_TRAP_IF(st == MFREE_SUCCESS && !A);
  FZ_TRAP_IF(st != MFREE_SUCCESS && A);
  if (A) check_matrix(A, 0);
  mfree_matrix_destroy(&A);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  fz_bytes_t b = {data, size};
  const int dim = 1 + (int)(fz_u8(&b) % 3);
  const int m = 2 + (int)(fz_u8(&b) % (MAXM - 1));
  const int n = dim == 1 ? m : dim == 2 ? m * m : m * m * m;
  const unsigned opts = fz_u8(&b), opts2 = fz_u8(&b);
  const int trial_method = 1 + (int)(fz_u8(&b) % 13);
  const int test_method = (opts & 1) ? 1 + (int)(fz_u8(&b) % 13) : 0;
  const int kernel = (opts & 2) ? 1 + (int)(fz_u8(&b) % 15) : 0;
  const int order = (opts & 4) ? (int)(fz_u8(&b) % 4) : -1;
  const mfree_form_t form = (mfree_form_t)(fz_u8(&b) % 11); /* 0, 10: unknown */
  const int quad = (int)(fz_u8(&b) % 3);
  const double sp = 1.0 / (m - 1), hfac = 1.0 + (fz_u8(&b) % 8) * 0.25;
  double scale = 1.0;

  static double x[3 * MAXN], h[MAXN], v[MAXN], qx[3 * MAXQ], qw[MAXQ], f[4 * MAXN + 64];
  static int32_t nodes[MAXN], conn[4 * MAXN];
  double nrm[3 * MAXQ];
  for (int k = 0; k < 3 * MAXQ; ++k) nrm[k] = (k % dim) == 0 ? 1.0 : 0.0;
  int finite = 1;
  for (int p = 0; p < n; ++p) {
    const int idx[3] = {p % m, (p / m) % m, p / (m * m)};
    for (int c = 0; c < dim; ++c) {
      const unsigned j = fz_u8(&b);
      x[dim * p + c] = (idx[c] + (j == 255 ? NAN : (j / 255.0 - 0.5) * 0.4)) * sp;
      finite &= j != 255;
    }
    const unsigned j = fz_u8(&b);
    h[p] = j == 255 ? fz_positive(&b, sp) : hfac * sp;
    v[p] = pow(sp, dim);
    finite &= isfinite(h[p]) && h[p] > 1e-100;
  }
  const int nq = (int)(fz_u8(&b) % (MAXQ + 1));
  for (int q = 0; q < nq; ++q) {
    for (int c = 0; c < dim; ++c) qx[dim * q + c] = fz_coord(&b, 0.0);
    qw[q] = fz_positive(&b, 0.1);
  }

  mfree_context_t *ctx = NULL;
  if (mfree_context_create(&ctx) != MFREE_SUCCESS) return 0;
  mfree_particles_t *ps = NULL;
  mfree_approximant_t *tr = NULL, *te = NULL;
  mfree_assembler_t *as = NULL;
  mfree_matrix_t *K = NULL;
  if (mfree_particles_create(ctx, dim, n, &ps) != MFREE_SUCCESS) goto done;
  FZ_CHECK(mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, dim, MFREE_BORROW));
  FZ_CHECK(mfree_particles_set_support(ps, h, 1, MFREE_BORROW));
  FZ_CHECK(mfree_particles_set_volumes(ps, v, 1, MFREE_BORROW));
  FZ_CHECK(mfree_particles_set_search(ps, MFREE_SEARCH_GATHER, 3.0));
  FZ_CHECK(mfree_approximant_create(ctx, ps, (mfree_method_t)trial_method, &tr));
  if (!tr) goto done;
  if (kernel) FZ_CHECK(mfree_approximant_set_kernel(tr, (mfree_kernel_t)kernel, 0.0));
  if (order >= 0) FZ_CHECK(mfree_approximant_set_order(tr, order));
  if (test_method) FZ_CHECK(mfree_approximant_create(ctx, ps, (mfree_method_t)test_method, &te));
  FZ_CHECK(mfree_assembler_create(ctx, tr, te, form, &as));
  if (!as) goto done;
  if (opts & 8) {
    const double young = (opts2 & 1) ? -1.0 : 1.0 + (fz_u8(&b) % 4), nu = ((int)(fz_u8(&b) % 12) - 2) * 0.05;
    FZ_CHECK(mfree_assembler_set_material(as, young, nu));
  }
  if (opts & 16) FZ_CHECK(mfree_assembler_set_coefficient(as, fz_positive(&b, 1.0)));
  if (quad == 1) {
    const double lo[3] = {-0.1, -0.1, -0.1}, hi[3] = {1.1, 1.1, 1.1};
    int32_t nc[3];
    for (int c = 0; c < 3; ++c) nc[c] = (int32_t)(fz_u8(&b) % 5) - (opts2 & 2 ? 1 : 0);
    const int32_t ng = (int32_t)(fz_u8(&b) % 6);
    FZ_CHECK(mfree_assembler_set_quadrature_cells(as, lo, hi, nc, ng, (opts2 & 4) ? inside : NULL, NULL));
  } else if (quad == 2) {
    FZ_CHECK(mfree_assembler_set_quadrature_points(as, nq, qx, MFREE_LAYOUT_AOS, dim, qw));
  }
  if (opts & 32) FZ_CHECK(mfree_assembler_set_body_force(as, body, &scale));
  if (opts & 64) {
    const mfree_bc_t bc = (mfree_bc_t)(fz_u8(&b) % 6);
    const int32_t mask = (int32_t)(fz_u8(&b) % 9);
    FZ_CHECK(mfree_assembler_add_dirichlet(as, bc, nq, qx, MFREE_LAYOUT_AOS, dim, qw, nrm, mask, gfun, NULL));
  }
  if (opts & 128) {
    const int nn = (int)(fz_u8(&b) % 6);
    for (int k = 0; k < nn; ++k) nodes[k] = (int32_t)(fz_u8(&b) % (unsigned)(n + 1)) - (opts2 & 8 ? 1 : 0);
    FZ_CHECK(mfree_assembler_add_dirichlet_nodes(as, nn, nodes, (int32_t)(1 + fz_u8(&b) % 7), gfun, NULL));
  }
  const unsigned opts3 = fz_u8(&b);
  if (opts3 & 1) FZ_CHECK(mfree_assembler_add_traction(as, nq, qx, MFREE_LAYOUT_AOS, dim, qw, gfun, NULL));
  if (opts3 & 2) { /* segments (2D) and triangles (3D) from the points' coordinates */
    const int32_t ng = (int32_t)(fz_u8(&b) % 5);
    FZ_CHECK(mfree_assembler_add_traction_segments(as, nq / 4, qx, ng, gfun, NULL));
    FZ_CHECK(mfree_assembler_add_traction_facets(as, nq / 3, qx, ng, gfun, NULL));
  }
  if (opts3 & 4) { /* collocation traction rows at nodes */
    const int nn = (int)(fz_u8(&b) % 6);
    for (int k = 0; k < nn; ++k) nodes[k] = (int32_t)(fz_u8(&b) % (unsigned)(n + 1)) - (opts2 & 8 ? 1 : 0);
    FZ_CHECK(mfree_assembler_add_traction_nodes(as, nn, nodes, nrm, gfun, NULL));
  }
  if (opts3 & 8) FZ_CHECK(mfree_assembler_set_consistent_integration(as, nq, qx, MFREE_LAYOUT_AOS, dim, qw, nrm));
  if (opts3 & 16) { /* a finite-element layer over lattice cells (2D), maybe flipped or repeated */
    const int npe = (opts3 & 32) ? 3 : 4, ne = 1 + (int)(fz_u8(&b) % 4);
    for (int e = 0; e < ne; ++e) {
      const unsigned w = fz_u8(&b);
      const int32_t c0 = (int32_t)(w % (unsigned)n), c[4] = {c0, c0 + 1, c0 + m + 1, c0 + m};
      for (int a = 0; a < npe; ++a) conn[npe * e + a] = (w & 128) ? c[npe - 1 - a] : c[a];
    }
    const int32_t ngu = (int32_t)(fz_u8(&b) % 3);
    FZ_CHECK(mfree_assembler_set_fe_layer(as, ne, npe, conn, ngu, conn, (int32_t)(1 + fz_u8(&b) % 3), gfun, NULL));
  }
  if (opts3 & 64) FZ_CHECK(mfree_assembler_set_quadrature_nodal(as));
  if (opts2 & 16) FZ_CHECK(mfree_assembler_set_penalty(as, fz_positive(&b, 1e3)));
  /* an extreme (valid) coefficient or penalty may overflow the entries: no NaN oracle */
  finite &= !(opts & 16) && !(opts2 & 16);
  mfree_status_t st = mfree_assembler_setup(as);
  FZ_TRAP_IF(!fz_valid_status(st));
  for (int round = 0; round < 2 && st >= 0; ++round) {
    int32_t ndofs = 0, nquad = 0;
    FZ_TRAP_IF(mfree_assembler_get_size(as, &ndofs, &nquad) != MFREE_SUCCESS);
    const mfree_status_t sk = mfree_assembler_assemble_matrix(as, &K);
    FZ_TRAP_IF(!fz_valid_status(sk));
    if (K) check_matrix(K, finite && sk == MFREE_SUCCESS && st == MFREE_SUCCESS);
    if (ndofs <= (int32_t)(sizeof f / sizeof f[0])) {
      const mfree_status_t sr = mfree_assembler_assemble_rhs(as, f);
      FZ_TRAP_IF(!fz_valid_status(sr));
      if (sr == MFREE_SUCCESS && finite && st == MFREE_SUCCESS)
        for (int32_t i = 0; i < ndofs; ++i) FZ_TRAP_IF(isnan(f[i]));
    }
    /* a particle moves (borrowed) or turns invalid, then update */
    const int p = (int)(fz_u8(&b) % (unsigned)n);
    const unsigned w = fz_u8(&b);
    x[dim * p] += w == 255 ? NAN : ((int)w - 128) * 0.001 * sp;
    finite &= w != 255;
    if (w & 1) FZ_CHECK(mfree_particles_update(ps));
    st = mfree_assembler_update(as);
    FZ_TRAP_IF(!fz_valid_status(st));
  }
  host_matrix(&b, ctx);
done:
  mfree_matrix_destroy(&K);
  mfree_assembler_destroy(&as);
  mfree_approximant_destroy(&te);
  mfree_approximant_destroy(&tr);
  mfree_particles_destroy(&ps);
  mfree_context_destroy(&ctx);
  return 0;
}
