/* Shared pieces of the free-surface flow examples of paper 003 (ramp, gravity_current):
 * wall particles (003 Sect. 6.2: spacing d/3, normals into the fluid) and VTU/PVD output
 * for ParaView (the progress bar is examples/util's). */
#ifndef MFREE_EXAMPLES_FLUID_COMMON_H
#define MFREE_EXAMPLES_FLUID_COMMON_H

#include <stdio.h>

#include <mfree.h>

/* A growing list of 2D wall particles with unit normals. */
typedef struct {
  int n, cap;
  double *x, *nrm;
} fc_walls_t;

/* Append wall particles from (x0, z0) to (x1, z1) (both ends included unless skip_first)
 * at spacing <= ds, with the unit normal (nx, nz) (normalised here). Returns 0, or 1 when
 * out of memory. */
int fc_walls_segment(fc_walls_t *w, double x0, double z0, double x1, double z1, double ds, double nx,
                     double nz, int skip_first);
void fc_walls_free(fc_walls_t *w);

/* VTU of the particles (position, interpolated velocity, pressure, density, and an
 * optional integer tag such as the fluid). Returns 0 on success. */
int fc_write_vtu(const char *path, int n, const double *y, const double *vhat, const double *p,
                 const int *tag);

/* Write the state at time t as dir/prefix_NNNN.vtu and add it to the open PVD file. */
int fc_snapshot(mfree_system_t *sys, const char *dir, const char *prefix, int index, double t, int n,
                const double *y, const int *tag, FILE *pvd);

#endif
