/* libFuzzer harness: MPFEM with meshes. Bytes -> a structured grid of nodes (1D lines,
 * 2D quadrilaterals or triangles, 3D bricks) jittered and sometimes corrupted (NaN,
 * coincident nodes), the mesh's connectivity with corrupted entries (an index out of
 * range or repeated, a flipped element), copied or borrowed, 0- or 1-based; supports
 * (kernel half width) around half a spacing; the derivative scheme, the edge-rule order,
 * a kernel, derivative flags, host points; then mesh setup, quadrature, approximant
 * setup, a node moved (borrowed) and update, apply. Oracles: fuzz_util.h. */
#include "fuzz_util.h"

enum { MAXM = 5, MAXN = MAXM * MAXM * MAXM, MAXE = 2 * (MAXM - 1) * (MAXM - 1) * (MAXM - 1), MAXP = 6 };

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  fz_bytes_t b = {data, size};
  const int dim = 1 + (int)(fz_u8(&b) % 3);
  const int m = 2 + (int)(fz_u8(&b) % (MAXM - 1)); /* nodes per axis */
  const unsigned opts = fz_u8(&b);
  const int tri = dim == 2 && (opts & 1);
  const mfree_mem_t mem = (opts & 2) ? MFREE_BORROW : MFREE_COPY;
  const int base = (int)((opts >> 2) & 1);
  const mfree_mpfem_deriv_t deriv = (mfree_mpfem_deriv_t)(fz_u8(&b) % 5); /* 0, 4: unknown */
  const int ngauss = (int)(fz_u8(&b) % 22);
  const int flags = 1 + (int)(fz_u8(&b) % 7);
  const int kernel = (opts & 8) ? 1 + (int)(fz_u8(&b) % 16) : 0;
  const double hfac = 0.1 + (fz_u8(&b) % 16) * 0.08;
  const double sp = 1.0 / (m - 1);
  const int n = dim == 1 ? m : dim == 2 ? m * m : m * m * m;

  static double x[3 * MAXN], h[MAXN], v[MAXN], u[MAXN], px[3 * MAXP], ph[MAXP];
  static int32_t conn[8 * MAXE];
  for (int p = 0; p < n; ++p) {
    const int idx[3] = {p % m, (p / m) % m, p / (m * m)};
    for (int c = 0; c < dim; ++c) {
      const unsigned j = fz_u8(&b);
      x[dim * p + c] = (idx[c] + (j == 255 ? NAN : j == 254 ? 0.0 : (j / 255.0 - 0.5) * 0.3)) * sp;
    }
    h[p] = fz_u8(&b) == 255 ? fz_positive(&b, sp) : hfac * sp;
    v[p] = 1.0;
    u[p] = (double)fz_u8(&b) - 128.0;
  }
  /* elements of the structured grid */
  int ne = 0, nn = 0;
  mfree_element_t type = MFREE_ELEMENT_LINE2;
  if (dim == 1) {
    type = MFREE_ELEMENT_LINE2, nn = 2;
    for (int i = 0; i + 1 < m; ++i, ++ne) conn[2 * ne] = i, conn[2 * ne + 1] = i + 1;
  } else if (dim == 2) {
    type = tri ? MFREE_ELEMENT_TRI3 : MFREE_ELEMENT_QUAD4, nn = tri ? 3 : 4;
    for (int j = 0; j + 1 < m; ++j)
      for (int i = 0; i + 1 < m; ++i) {
        const int a = j * m + i, b1 = a + 1, c = a + m + 1, d = a + m;
        int32_t *e = conn + nn * ne;
        if (tri) {
          e[0] = a, e[1] = b1, e[2] = c, e += 3, ++ne;
          e[0] = a, e[1] = c, e[2] = d, ++ne;
        } else {
          e[0] = a, e[1] = b1, e[2] = c, e[3] = d, ++ne;
        }
      }
  } else {
    type = MFREE_ELEMENT_HEX8, nn = 8;
    for (int k = 0; k + 1 < m; ++k)
      for (int j = 0; j + 1 < m; ++j)
        for (int i = 0; i + 1 < m; ++i, ++ne) {
          const int a = (k * m + j) * m + i;
          int32_t *e = conn + 8 * ne;
          e[0] = a, e[1] = a + 1, e[2] = a + m + 1, e[3] = a + m;
          for (int q = 0; q < 4; ++q) e[4 + q] = e[q] + m * m;
        }
  }
  /* corruptions: an index out of range, repeated, or two nodes swapped (flipped) */
  const int ncorrupt = (int)(fz_u8(&b) % 3);
  for (int q = 0; q < ncorrupt; ++q) {
    const int at = (int)(fz_u16(&b) % (unsigned)(ne * nn));
    const unsigned kind = fz_u8(&b) % 3;
    if (kind == 0) { /* n or n + 1, or negative */
      const unsigned w = fz_u8(&b);
      conn[at] = (int32_t)n + (int32_t)(w % 2) - 2 * (int32_t)(n + 1) * (int32_t)((w >> 1) & 1);
    }
    else if (kind == 1) conn[at] = conn[at - at % nn];
    else {
      const int first = at - at % nn;
      const int32_t t = conn[first];
      conn[first] = conn[first + 1], conn[first + 1] = t;
    }
  }
  if (base)
    for (int k = 0; k < ne * nn; ++k) conn[k] += 1;
  const int npts = (opts & 16) ? (int)(fz_u8(&b) % (MAXP + 1)) : -1;
  for (int i = 0; i < (npts > 0 ? npts : 0); ++i) {
    for (int c = 0; c < dim; ++c) px[dim * i + c] = fz_coord(&b, 0.0);
    ph[i] = fz_positive(&b, hfac * sp);
  }

  mfree_context_t *ctx = NULL;
  if (mfree_context_create(&ctx) != MFREE_SUCCESS) return 0;
  mfree_particles_t *ps = NULL;
  mfree_mesh_t *mesh = NULL;
  mfree_approximant_t *a = NULL;
  if (mfree_particles_create(ctx, dim, n, &ps) != MFREE_SUCCESS) goto done;
  FZ_CHECK(mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, dim, MFREE_BORROW));
  FZ_CHECK(mfree_particles_set_support(ps, h, 1, MFREE_BORROW));
  FZ_CHECK(mfree_particles_set_volumes(ps, v, 1, MFREE_BORROW));
  FZ_CHECK(mfree_mesh_create(ctx, ps, &mesh));
  if (!mesh) goto done;
  FZ_CHECK(mfree_mesh_add_elements(mesh, type, ne, conn, base, mem));
  FZ_CHECK(mfree_mesh_setup(mesh));
  int32_t nel = 0;
  FZ_CHECK(mfree_mesh_get_size(mesh, &nel));
  {
    int32_t nq = 0;
    const int32_t ng = 1 + (int32_t)(fz_u8(&b) % 4);
    const mfree_status_t st = mfree_mesh_get_quadrature(mesh, ng, &nq, NULL, NULL);
    FZ_TRAP_IF(!fz_valid_status(st));
    if (st == MFREE_SUCCESS && nq > 0 && nq < 100000) {
      double *qx = malloc(sizeof(double) * (size_t)nq * (size_t)dim), *qw = malloc(sizeof(double) * (size_t)nq);
      FZ_CHECK(mfree_mesh_get_quadrature(mesh, ng, &nq, qx, qw));
      free(qx), free(qw);
    }
  }
  FZ_CHECK(mfree_approximant_create(ctx, ps, MFREE_METHOD_MPFEM, &a));
  if (!a) goto done;
  if (kernel) FZ_CHECK(mfree_approximant_set_kernel(a, (mfree_kernel_t)kernel, 0.0));
  FZ_CHECK(mfree_approximant_set_mpfem(a, deriv, ngauss));
  FZ_CHECK(mfree_approximant_set_derivatives(a, flags));
  FZ_CHECK(mfree_approximant_set_mesh(a, (opts & 32) ? NULL : mesh));
  if (npts >= 0) FZ_CHECK(mfree_approximant_set_points(a, npts, px, MFREE_LAYOUT_AOS, dim, ph, 1, MFREE_COPY));
  mfree_status_t st = mfree_approximant_setup(a);
  FZ_TRAP_IF(!fz_valid_status(st));
  for (int round = 0; round < 3 && st >= 0; ++round) {
    fz_tables_t t;
    const int had = fz_tables_get(a, dim, &t);
    if (had) {
      fz_check_sites(&t);
      double *out = calloc((size_t)t.nsites * 6 + 1, sizeof *out);
      const mfree_status_t sa = mfree_approximant_apply(a, MFREE_OP_GRADIENT, 1, u, MFREE_LAYOUT_AOS, 1, out,
                                                        MFREE_LAYOUT_AOS, dim);
      FZ_TRAP_IF(!fz_valid_status(sa));
      free(out);
    }
    /* a node moves (borrowed), or its support changes; then update */
    const int p = (int)(fz_u8(&b) % (unsigned)n);
    const unsigned w = fz_u8(&b);
    if (w & 1) x[dim * p + (int)((w >> 1) % (unsigned)dim)] += ((w >> 3) == 31 ? NAN : ((int)(w >> 3) - 16) * 0.02 * sp);
    else h[p] = fz_positive(&b, hfac * sp);
    if (fz_u8(&b) & 1) FZ_CHECK(mfree_particles_update(ps));
    fz_tables_t after;
    const mfree_status_t su = mfree_approximant_update(a);
    FZ_TRAP_IF(!fz_valid_status(su));
    if (fz_tables_get(a, dim, &after)) {
      fz_check_sites(&after);
      if (su < 0 && had) fz_tables_same(&t, &after);
    }
    fz_tables_free(&t);
    fz_tables_free(&after);
  }
done:
  mfree_approximant_destroy(&a);
  mfree_mesh_destroy(&mesh);
  mfree_particles_destroy(&ps);
  mfree_context_destroy(&ctx);
  return 0;
}
