#include "mpfem_util.h"

#include <stdlib.h>
#include <string.h>

mfree_particles_t *mp_particles(mfree_context_t *ctx, int32_t dim, int32_t n, const double *x,
                                double h) {
  mfree_particles_t *ps = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, dim, n, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, dim, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  return ps;
}

mfree_mesh_t *mp_mesh(mfree_context_t *ctx, mfree_particles_t *ps, mfree_element_t type,
                      int32_t nelem, const int32_t *conn) {
  mfree_mesh_t *m = NULL;
  assert_ok(ctx, mfree_mesh_create(ctx, ps, &m));
  assert_ok(ctx, mfree_mesh_add_elements(m, type, nelem, conn, 0, MFREE_COPY));
  return m;
}

mfree_approximant_t *mp_approx(mfree_context_t *ctx, mfree_particles_t *ps, mfree_mesh_t *mesh,
                               mfree_kernel_t kernel, mfree_mpfem_deriv_t deriv, int32_t flags,
                               int32_t npts, const double *pts, double hp,
                               mfree_status_t *status) {
  mfree_approximant_t *a = NULL;
  int32_t dim = 0;
  assert_ok(ctx, mfree_particles_get_dimension(ps, &dim));
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MPFEM, &a));
  assert_ok(ctx, mfree_approximant_set_mesh(a, mesh));
  assert_ok(ctx, mfree_approximant_set_kernel(a, kernel, 0.0));
  assert_ok(ctx, mfree_approximant_set_mpfem(a, deriv, 8));
  assert_ok(ctx, mfree_approximant_set_derivatives(a, flags));
  if (npts > 0)
    assert_ok(ctx, mfree_approximant_set_points(a, npts, pts, MFREE_LAYOUT_AOS, dim, &hp, 0,
                                                MFREE_COPY));
  mfree_status_t st = mfree_approximant_setup(a);
  if (status)
    *status = st;
  else
    assert_status(ctx, st, MFREE_SUCCESS);
  return a;
}

void mp_table_get(mfree_context_t *ctx, const mfree_approximant_t *a, int32_t flags, mp_table_t *t) {
  memset(t, 0, sizeof *t);
  int64_t nnz = 0;
  assert_ok(ctx, mfree_approximant_get_num_sites(a, &t->nsites));
  assert_ok(ctx, mfree_approximant_get_nnz(a, &nnz));
  t->rowptr = malloc(sizeof(int64_t) * (size_t)(t->nsites + 1));
  t->cols = malloc(sizeof(int32_t) * (size_t)(nnz + 1));
  t->dim = 0;
  const mfree_deriv_t first = (flags & MFREE_DERIV_VALUE) ? MFREE_DERIV_VALUE
                              : (flags & MFREE_DERIV_GRADIENT) ? MFREE_DERIV_GRADIENT
                                                               : MFREE_DERIV_HESSIAN;
  assert_ok(ctx, mfree_approximant_assemble_csr(a, first, 0, t->rowptr, t->cols, NULL));
  if (flags & MFREE_DERIV_VALUE) {
    t->val = malloc(sizeof(double) * (size_t)(nnz + 1));
    assert_ok(ctx, mfree_approximant_assemble_csr(a, MFREE_DERIV_VALUE, 0, NULL, NULL, t->val));
  }
  if (flags & MFREE_DERIV_GRADIENT) {
    for (int c = 0; c < 3; ++c) {
      double *v = malloc(sizeof(double) * (size_t)(nnz + 1));
      mfree_status_t st = mfree_approximant_assemble_csr(a, MFREE_DERIV_GRADIENT, c, NULL, NULL, v);
      if (st != MFREE_SUCCESS) {
        free(v);
        break;
      }
      t->grad[c] = v;
      t->dim = c + 1;
    }
  }
  if (flags & MFREE_DERIV_HESSIAN) {
    for (int c = 0; c < 6; ++c) {
      double *v = malloc(sizeof(double) * (size_t)(nnz + 1));
      mfree_status_t st = mfree_approximant_assemble_csr(a, MFREE_DERIV_HESSIAN, c, NULL, NULL, v);
      if (st != MFREE_SUCCESS) {
        free(v);
        break;
      }
      t->hess[c] = v;
    }
  }
}

void mp_table_free(mp_table_t *t) {
  free(t->rowptr);
  free(t->cols);
  free(t->val);
  for (int c = 0; c < 3; ++c) free(t->grad[c]);
  for (int c = 0; c < 6; ++c) free(t->hess[c]);
  memset(t, 0, sizeof *t);
}

double mp_at(const mp_table_t *t, const double *vals, int32_t site, int32_t j) {
  for (int64_t k = t->rowptr[site]; k < t->rowptr[site + 1]; ++k)
    if (t->cols[k] == j) return vals[k];
  return 0.0;
}

void mp_line_conn(int32_t n, int32_t *conn) {
  for (int32_t e = 0; e + 1 < n; ++e) {
    conn[2 * e] = e;
    conn[2 * e + 1] = e + 1;
  }
}

void mp_grid_nodes(int32_t nx, int32_t ny, const double *xs, const double *ys, double *x) {
  for (int32_t j = 0; j <= ny; ++j)
    for (int32_t i = 0; i <= nx; ++i) {
      x[2 * (j * (nx + 1) + i)] = xs[i];
      x[2 * (j * (nx + 1) + i) + 1] = ys[j];
    }
}

void mp_grid_quads(int32_t nx, int32_t ny, int32_t *conn) {
  for (int32_t j = 0; j < ny; ++j)
    for (int32_t i = 0; i < nx; ++i) {
      const int32_t n0 = j * (nx + 1) + i, e = j * nx + i;
      conn[4 * e] = n0;
      conn[4 * e + 1] = n0 + 1;
      conn[4 * e + 2] = n0 + nx + 2;
      conn[4 * e + 3] = n0 + nx + 1;
    }
}

void mp_grid_tris(int32_t nx, int32_t ny, int32_t *conn) {
  for (int32_t j = 0; j < ny; ++j)
    for (int32_t i = 0; i < nx; ++i) {
      const int32_t n0 = j * (nx + 1) + i, e = 2 * (j * nx + i);
      conn[3 * e] = n0;
      conn[3 * e + 1] = n0 + 1;
      conn[3 * e + 2] = n0 + nx + 2;
      conn[3 * (e + 1)] = n0;
      conn[3 * (e + 1) + 1] = n0 + nx + 2;
      conn[3 * (e + 1) + 2] = n0 + nx + 1;
    }
}
