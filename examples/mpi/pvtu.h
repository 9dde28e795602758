/* Parallel VTU output of the MPI examples: every rank writes its owned particles as one
 * piece, <prefix>_<rank>.vtu (ex_vtu_write of examples/util), and rank 0 the index
 * <prefix>.pvtu that ParaView opens, listing every rank's piece and declaring its arrays.
 * A series adds <dir>/<name>.pvd, which indexes the .pvtu files of a run by time. The
 * calls are collective and return the same value on every rank (0, or 1 when any rank
 * failed to write), so that no rank goes on alone after a failed write. */
#ifndef MFREE_EXAMPLES_PVTU_H
#define MFREE_EXAMPLES_PVTU_H

#include <mpi.h>
#include <stdint.h>
#include <stdio.h>

#include "util.h"

/* Write <prefix>.pvtu and this rank's <prefix>_<rank>.vtu (prefix may hold a directory;
 * the index names the pieces relative to itself): n owned points x (dim components,
 * leading dimension ldx) and narrays point-data arrays, the same names, types and
 * component counts on every rank. Collective over comm. */
int ex_pvtu_write(MPI_Comm comm, const char *prefix, int64_t n, int dim, const double *x, int64_t ldx,
                  int narrays, const ex_vtu_array_t *arrays);

typedef struct {
  MPI_Comm comm;
  FILE *pvd; /* rank 0 only */
  char dir[2048], name[128];
  int count;
} ex_pvtu_series_t;

/* Start a series <dir>/<name>.pvd (the directory must exist). Collective. */
int ex_pvtu_series_open(ex_pvtu_series_t *s, MPI_Comm comm, const char *dir, const char *name);
/* Write snapshot <dir>/<name>_NNNN.pvtu (and its pieces) at time t and index it.
 * Collective; arguments as ex_pvtu_write. */
int ex_pvtu_series_write(ex_pvtu_series_t *s, double t, int64_t n, int dim, const double *x, int64_t ldx,
                         int narrays, const ex_vtu_array_t *arrays);
/* Close the .pvd. Collective. */
int ex_pvtu_series_close(ex_pvtu_series_t *s);

#endif
