/* Helpers shared by the examples: plots and progress.
 *
 * Plots. An example writes its data (CSV or .dat) and a gnuplot script next to it, then
 * calls ex_plot, which runs gnuplot when it is on PATH and says where the PNG is, or says
 * that there is no plot and where the data are. Plotting is optional: without gnuplot (or
 * with MFREE_NO_PLOT=1 in the environment) the example still succeeds.
 *
 * Failures. ex_fail prints the context's message of a failed call.
 *
 * Progress. ex_progress is an mfree_progress_fn that draws a bar on stderr when stderr is
 * a terminal; otherwise (a log, a pipe, a test) it stays silent and ex_progress_done
 * prints one summary line. */
#ifndef MFREE_EXAMPLES_UTIL_H
#define MFREE_EXAMPLES_UTIL_H

#include <stdint.h>
#include <stdio.h>

#include <mfree.h>

/* 1 when gnuplot is on PATH and MFREE_NO_PLOT is not set to a nonzero value. */
int ex_plot_available(void);

/* Run gnuplot on the script, which writes png. Reports on msg (stdout, or stderr when
 * stdout carries JSON): "plot: <png>" on success; else why there is no plot and that the
 * data are in data. Returns 1 when the PNG was written, 0 otherwise (never fatal). */
int ex_plot(const char *script, const char *png, const char *data, FILE *msg);

/* dir/file into dst (size bytes), with one slash between them. */
void ex_join(char *dst, size_t size, const char *dir, const char *file);

/* 1 when the path can be quoted in a gnuplot script (no quote characters). */
int ex_plot_path_ok(const char *path);

/* Print ctx's last error for a failed call `what` of program prog; returns 1. */
int ex_fail(mfree_context_t *ctx, const char *prog, mfree_status_t st, const char *what);
/* For programs that stop at the first failure: exit(1) after ex_fail's message unless st
 * is MFREE_SUCCESS; ex_xmalloc: malloc (n = 0: one byte), or exit(1) after "<prog>: out of
 * memory". */
void ex_check_exit(mfree_context_t *ctx, const char *prog, mfree_status_t st, const char *what);
void *ex_xmalloc(const char *prog, size_t n);

/* The plot options every plotting example takes: --out DIR (sets *out) and --no-plot
 * (clears *plot). Returns 1 when argv[*i] was one of them (advancing *i past a value). */
int ex_plot_option(int argc, char **argv, int *i, const char **out, int *plot);

typedef struct {
  int quiet;     /* nothing at all */
  int tty;       /* stderr is a terminal: draw the bar */
  int last;      /* last percentage drawn */
  double t0, t1; /* the time span of the whole run */
  int64_t base;  /* steps of earlier mfree_system_integrate calls */
  FILE *f;       /* where the bar is drawn: stderr */
} ex_progress_t;

/* Start a run over [t0, t1]. */
void ex_progress_init(ex_progress_t *p, int quiet, double t0, double t1);
/* Draw the bar on the terminal f instead (e.g. /dev/tty for an MPI rank, whose stderr
 * mpirun turns into a pipe); unless quiet. */
void ex_progress_to(ex_progress_t *p, FILE *f);
/* mfree_progress_fn; user = ex_progress_t *. Never stops the integration. */
int32_t ex_progress(void *user, int64_t step, double t, double dt);
/* After each mfree_system_integrate call: add the steps it took. */
void ex_progress_steps(ex_progress_t *p, int64_t steps);
/* End of the run: ends the bar's line on a terminal, else prints one summary line. */
void ex_progress_done(ex_progress_t *p, const char *what, double t);

/* ---- VTU files for ParaView (a VTK XML unstructured grid of vertices) ---- */

/* Element types of a point-data array. */
typedef enum { EX_VTU_FLOAT64 = 0, EX_VTU_INT64 = 1, EX_VTU_INT32 = 2 } ex_vtu_type_t;

/* A point-data array: item i, component c at ((const T *)data)[i * ld + c], T the C type
 * of type (double, int64_t, int32_t). ncomp 1 to 3; 2 is written as a 3-vector with a zero
 * third component (ParaView's vectors have three). */
typedef struct {
  const char *name;
  ex_vtu_type_t type;
  int ncomp;
  const void *data;
  int64_t ld;
} ex_vtu_array_t;

/* One VTU piece: n points x (dim 1 to 3 components, leading dimension ldx; missing
 * components written as 0), one vertex cell each, and the narrays point-data arrays.
 * ASCII; doubles with 17 significant digits, so that they read back bit for bit. Returns 0,
 * or 1 when the file could not be written. */
int ex_vtu_write(const char *path, int64_t n, int dim, const double *x, int64_t ldx, int narrays,
                 const ex_vtu_array_t *arrays);
/* The VTK type name of an array type ("Float64", "Int64", "Int32"). */
const char *ex_vtu_type_name(ex_vtu_type_t type);
/* Components an array has in the file (ncomp 2 is written as 3). */
int ex_vtu_file_components(int ncomp);

#endif
