/* Helpers shared by the MPFEM tests (paper 004). */
#ifndef MPFEM_UTIL_H
#define MPFEM_UTIL_H

#include <stdint.h>

#include "testutil.h"

/* A table exported from an approximant: rows = sites, columns = particles. */
typedef struct {
  int32_t nsites, dim;
  int64_t *rowptr;
  int32_t *cols;
  double *val, *grad[3], *hess[6];
} mp_table_t;

/* Particle set of n particles (positions AoS, copied) with one support h. */
mfree_particles_t *mp_particles(mfree_context_t *ctx, int32_t dim, int32_t n, const double *x,
                                double h);
/* Mesh of one element type (connectivity 0-based, copied). */
mfree_mesh_t *mp_mesh(mfree_context_t *ctx, mfree_particles_t *ps, mfree_element_t type,
                      int32_t nelem, const int32_t *conn);
/* MPFEM approximant on ps with the mesh, kernel, derivative form and tables; host
 * points (npts > 0: AoS coordinates, support hp) or the particles; *status gets the
 * setup status. */
mfree_approximant_t *mp_approx(mfree_context_t *ctx, mfree_particles_t *ps, mfree_mesh_t *mesh,
                               mfree_kernel_t kernel, mfree_mpfem_deriv_t deriv, int32_t flags,
                               int32_t npts, const double *pts, double hp,
                               mfree_status_t *status);
void mp_table_get(mfree_context_t *ctx, const mfree_approximant_t *a, int32_t flags, mp_table_t *t);
void mp_table_free(mp_table_t *t);
/* Entry (site, particle) of a table array (0 when absent). */
double mp_at(const mp_table_t *t, const double *vals, int32_t site, int32_t j);

/* Structured meshes: 1D nodes x (n), LINE2 connectivity; 2D grid of (nx+1)(ny+1) nodes
 * with spacing from xs (nx+1) and ys (ny+1), QUAD4 or TRI3 (two per cell). */
void mp_line_conn(int32_t n, int32_t *conn);
void mp_grid_nodes(int32_t nx, int32_t ny, const double *xs, const double *ys, double *x);
void mp_grid_quads(int32_t nx, int32_t ny, int32_t *conn);
void mp_grid_tris(int32_t nx, int32_t ny, int32_t *conn);

#endif
