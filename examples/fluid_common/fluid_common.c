#define _XOPEN_SOURCE 700
#include "fluid_common.h"

#include <math.h>
#include <stdlib.h>

int fc_walls_segment(fc_walls_t *w, double x0, double z0, double x1, double z1, double ds, double nx,
                     double nz, int skip_first) {
  const double len = hypot(x1 - x0, z1 - z0), nn = hypot(nx, nz);
  const int m = len > 0 ? (int)ceil(len / ds) : 0;
  if (w->n + m + 1 > w->cap) {
    const int cap = 2 * (w->n + m + 1);
    double *x = realloc(w->x, 2 * (size_t)cap * sizeof *x);
    if (!x) return 1;
    w->x = x;
    double *v = realloc(w->nrm, 2 * (size_t)cap * sizeof *v);
    if (!v) return 1;
    w->nrm = v;
    w->cap = cap;
  }
  for (int q = skip_first ? 1 : 0; q <= m; ++q) {
    const double s = m > 0 ? (double)q / m : 0.0;
    w->x[2 * w->n] = x0 + s * (x1 - x0);
    w->x[2 * w->n + 1] = z0 + s * (z1 - z0);
    w->nrm[2 * w->n] = nx / nn;
    w->nrm[2 * w->n + 1] = nz / nn;
    ++w->n;
  }
  return 0;
}

void fc_walls_free(fc_walls_t *w) {
  free(w->x);
  free(w->nrm);
  w->x = w->nrm = NULL;
  w->n = w->cap = 0;
}

int fc_write_vtu(const char *path, int n, const double *y, const double *vhat, const double *p,
                 const int *tag) {
  FILE *f = fopen(path, "w");
  if (!f) return 1;
  fprintf(f, "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" "
             "byte_order=\"LittleEndian\">\n<UnstructuredGrid>\n<Piece NumberOfPoints=\"%d\" "
             "NumberOfCells=\"%d\">\n<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" "
             "format=\"ascii\">\n",
          n, n);
  for (int i = 0; i < n; ++i) fprintf(f, "%.9g %.9g 0\n", y[2 * i], y[2 * i + 1]);
  fprintf(f, "</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int32\" Name=\"connectivity\" "
             "format=\"ascii\">\n");
  for (int i = 0; i < n; ++i) fprintf(f, "%d\n", i);
  fprintf(f, "</DataArray>\n<DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">\n");
  for (int i = 0; i < n; ++i) fprintf(f, "%d\n", i + 1);
  fprintf(f, "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
  for (int i = 0; i < n; ++i) fprintf(f, "1\n");
  fprintf(f, "</DataArray>\n</Cells>\n<PointData Scalars=\"pressure\" Vectors=\"velocity\">\n"
             "<DataArray type=\"Float64\" Name=\"velocity\" NumberOfComponents=\"3\" format=\"ascii\">\n");
  for (int i = 0; i < n; ++i) fprintf(f, "%.6g %.6g 0\n", vhat[2 * i], vhat[2 * i + 1]);
  fprintf(f, "</DataArray>\n<DataArray type=\"Float64\" Name=\"pressure\" format=\"ascii\">\n");
  for (int i = 0; i < n; ++i) fprintf(f, "%.6g\n", p[i]);
  fprintf(f, "</DataArray>\n<DataArray type=\"Float64\" Name=\"density\" format=\"ascii\">\n");
  for (int i = 0; i < n; ++i) fprintf(f, "%.8g\n", y[4 * n + i]);
  if (tag) {
    fprintf(f, "</DataArray>\n<DataArray type=\"Int32\" Name=\"fluid\" format=\"ascii\">\n");
    for (int i = 0; i < n; ++i) fprintf(f, "%d\n", tag[i]);
  }
  fprintf(f, "</DataArray>\n</PointData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
  return fclose(f) != 0;
}

int fc_snapshot(mfree_system_t *sys, const char *dir, const char *prefix, int index, double t, int n,
                const double *y, const int *tag, FILE *pvd) {
  double *vhat = malloc(2 * (size_t)n * sizeof *vhat), *p = malloc((size_t)n * sizeof *p);
  int rc = !vhat || !p;
  if (!rc) rc = mfree_system_get_velocity(sys, y, vhat) != MFREE_SUCCESS;
  if (!rc) rc = mfree_system_get_pressure(sys, y, p) != MFREE_SUCCESS;
  char path[4096];
  if (!rc) {
    snprintf(path, sizeof path, "%s/%s_%04d.vtu", dir, prefix, index);
    rc = fc_write_vtu(path, n, y, vhat, p, tag);
  }
  if (!rc && pvd)
    fprintf(pvd, "<DataSet timestep=\"%.6f\" group=\"\" part=\"0\" file=\"%s_%04d.vtu\"/>\n", t, prefix, index);
  free(vhat);
  free(p);
  return rc;
}
