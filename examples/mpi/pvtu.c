/* Parallel VTU output of the MPI examples (pvtu.h). */
#include "pvtu.h"

#include <string.h>

/* 1 on every rank when any rank's bad is nonzero. */
static int any(MPI_Comm comm, int bad) {
  int out = 1;
  if (MPI_Allreduce(&bad, &out, 1, MPI_INT, MPI_MAX, comm) != MPI_SUCCESS) return 1;
  return out != 0;
}

int ex_pvtu_write(MPI_Comm comm, const char *prefix, int64_t n, int dim, const double *x, int64_t ldx,
                  int narrays, const ex_vtu_array_t *arrays) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  char path[4096];
  int bad = snprintf(path, sizeof path, "%s_%d.vtu", prefix, rank) >= (int)sizeof path;
  if (!bad) bad = ex_vtu_write(path, n, dim, x, ldx, narrays, arrays);
  if (any(comm, bad)) return 1;
  if (rank == 0) {
    const char *base = strrchr(prefix, '/');
    base = base ? base + 1 : prefix;
    FILE *f = NULL;
    bad = snprintf(path, sizeof path, "%s.pvtu", prefix) >= (int)sizeof path;
    if (!bad) bad = !(f = fopen(path, "w"));
    if (!bad) {
      fprintf(f, "<?xml version=\"1.0\"?>\n<VTKFile type=\"PUnstructuredGrid\" version=\"0.1\" "
                 "byte_order=\"LittleEndian\" header_type=\"UInt64\">\n<PUnstructuredGrid GhostLevel=\"0\">\n"
                 "<PPoints>\n<PDataArray type=\"Float64\" NumberOfComponents=\"3\"/>\n</PPoints>\n<PPointData>\n");
      for (int a = 0; a < narrays; ++a)
        fprintf(f, "<PDataArray type=\"%s\" Name=\"%s\" NumberOfComponents=\"%d\"/>\n",
                ex_vtu_type_name(arrays[a].type), arrays[a].name, ex_vtu_file_components(arrays[a].ncomp));
      fputs("</PPointData>\n", f);
      for (int r = 0; r < size; ++r) fprintf(f, "<Piece Source=\"%s_%d.vtu\"/>\n", base, r);
      fputs("</PUnstructuredGrid>\n</VTKFile>\n", f);
      bad = ferror(f);
      bad = (fclose(f) != 0) || bad;
    }
  }
  return any(comm, bad);
}

int ex_pvtu_series_open(ex_pvtu_series_t *s, MPI_Comm comm, const char *dir, const char *name) {
  int rank = 0;
  memset(s, 0, sizeof *s);
  s->comm = comm;
  MPI_Comm_rank(comm, &rank);
  int bad = snprintf(s->dir, sizeof s->dir, "%s", dir) >= (int)sizeof s->dir ||
            snprintf(s->name, sizeof s->name, "%s", name) >= (int)sizeof s->name;
  if (rank == 0 && !bad) {
    char path[4096];
    bad = snprintf(path, sizeof path, "%s/%s.pvd", dir, name) >= (int)sizeof path;
    if (!bad) bad = !(s->pvd = fopen(path, "w"));
    if (!bad) fputs("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n", s->pvd);
  }
  if (any(comm, bad)) {
    if (s->pvd) fclose(s->pvd);
    s->pvd = NULL;
    return 1;
  }
  return 0;
}

int ex_pvtu_series_write(ex_pvtu_series_t *s, double t, int64_t n, int dim, const double *x, int64_t ldx,
                         int narrays, const ex_vtu_array_t *arrays) {
  char prefix[4096];
  snprintf(prefix, sizeof prefix, "%s/%s_%04d", s->dir, s->name, s->count);
  if (ex_pvtu_write(s->comm, prefix, n, dim, x, ldx, narrays, arrays)) return 1;
  if (s->pvd)
    fprintf(s->pvd, "<DataSet timestep=\"%.17g\" group=\"\" part=\"0\" file=\"%s_%04d.pvtu\"/>\n", t, s->name,
            s->count);
  ++s->count;
  return 0;
}

int ex_pvtu_series_close(ex_pvtu_series_t *s) {
  int bad = 0;
  if (s->pvd) {
    fputs("</Collection>\n</VTKFile>\n", s->pvd);
    bad = ferror(s->pvd);
    bad = (fclose(s->pvd) != 0) || bad;
    s->pvd = NULL;
  }
  return any(s->comm, bad);
}
