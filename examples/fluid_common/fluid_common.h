/* Shared pieces of the free-surface flow examples of paper 003 (dam_break, ramp,
 * gravity_current, bore, drop): wall particles (003 Sect. 6.2: spacing d/3, normals into
 * the fluid), the run options every one of them takes, a VTU/PVD series for ParaView, the
 * JSON summary and the report of a run that stopped on an error (the progress bar is
 * examples/util's).
 *
 * Run options (fc_run_option):
 *   --out DIR        CSV data, gnuplot scripts, PNGs and the JSON summary (default: the
 *                    example's <name>_out)
 *   --vtu DIR        write a VTU series (DIR/<name>.pvd indexing DIR/<name>_NNNN.vtu);
 *                    off by default
 *   --vtu-every T    its interval in the example's time unit; T > 0 without --vtu writes
 *                    the series into the --out directory, 0 turns it off
 *   --json-file F    the JSON summary's path (default DIR/<name>.json, always written)
 *   --json           print the summary on stdout as well (one line)
 *   --no-plot        no gnuplot; --quiet: no progress bar */
#ifndef MFREE_EXAMPLES_FLUID_COMMON_H
#define MFREE_EXAMPLES_FLUID_COMMON_H

#include <stddef.h>
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

/* ---- run options ---- */
typedef struct {
  const char *name;      /* the example's short name: file names and messages */
  const char *out;       /* --out */
  const char *vtu_dir;   /* --vtu, or NULL */
  double vtu_every;      /* --vtu-every (the example sets its default) */
  int vtu_every_set;     /* --vtu-every was given */
  const char *json_path; /* --json-file, or NULL for <out>/<name>.json */
  int json_stdout, quiet, plot;
} fc_run_t;

/* Defaults: out = "<name>_out", no VTU, summary in the out directory, plots on. */
void fc_run_init(fc_run_t *r, const char *name, double vtu_every);
/* 1 when argv[*i] is one of the run options (advancing *i past a value), 0 otherwise;
 * -1 for an option missing its value or with a bad one. */
int fc_run_option(int argc, char **argv, int *i, fc_run_t *r);
/* Usage lines of the run options. */
void fc_run_usage(FILE *f);
/* Create the out directory (and the VTU directory). Returns 0, or 1 with a message. */
int fc_run_prepare(fc_run_t *r);
/* The directory of the VTU series, NULL when there is none. */
const char *fc_run_vtu_dir(const fc_run_t *r);

/* ---- VTU series for ParaView ---- */

/* VTU of the particles (position, interpolated velocity, pressure, density, and an
 * optional integer tag such as the fluid). Returns 0 on success. */
int fc_write_vtu(const char *path, int n, const double *y, const double *vhat, const double *p,
                 const int *tag);

typedef struct {
  FILE *pvd;
  char dir[2048], prefix[64];
  int count;
  double every, next;
} fc_vtu_t;

/* Open dir/prefix.pvd (dir NULL: a series that writes nothing). Returns 0, or 1 with a
 * message. */
int fc_vtu_open(fc_vtu_t *v, const char *dir, const char *prefix, double every);
/* Write the state when T (the example's time unit) has reached the next output time;
 * t is the physical time recorded in the PVD. Returns 0, or 1 with a message. */
int fc_vtu_maybe(fc_vtu_t *v, mfree_system_t *sys, double T, double t, int n, const double *y,
                 const int *tag);
/* Close the PVD. Returns 0, or 1 when it could not be written. */
int fc_vtu_close(fc_vtu_t *v);

/* ---- JSON summary: one object on one line ---- */
typedef struct {
  char *s;
  size_t len, cap;
  int items, err;
} fc_json_t;

void fc_json_init(fc_json_t *j);
/* A number (null when not finite: JSON has no NaN). */
void fc_json_num(fc_json_t *j, const char *key, double v);
void fc_json_int(fc_json_t *j, const char *key, long long v);
/* A string (NULL: null), escaped. */
void fc_json_str(fc_json_t *j, const char *key, const char *v);
/* rows x width numbers, row-major, as an array of arrays (width 1: a flat array). */
void fc_json_table(fc_json_t *j, const char *key, int rows, int width, const double *v);
/* Close the object, write it to r's summary path and, with --json, to stdout; free it.
 * Returns 0, or 1 with a message when the file could not be written. */
int fc_json_finish(fc_json_t *j, const fc_run_t *r);

/* ---- errors ---- */

/* After mfree_system_integrate returned st != MFREE_SUCCESS at time t (in the example's
 * unit, named by unit, e.g. "t" or "T"): the context's message into msg, and on stderr
 * "<name>: error: the run stopped at <unit> = <t>: <message>". Returns the examples'
 * exit status of a stopped run, 3. */
int fc_run_error(mfree_context_t *ctx, const fc_run_t *r, mfree_status_t st, const char *unit, double t,
                 char *msg, size_t size);

/* ---- mass ---- */

/* The Galerkin lumped masses (003 eq 56; the diagonal of the velocity block of
 * mfree_system_assemble_mass) of the n particles of a 2D fluid at state y. */
mfree_status_t fc_lumped_masses(mfree_system_t *sys, const double *y, int n, double *lumped);
/* Relative mass error of a run: the larger of |sum m - mass0| (constant particle masses,
 * none lost) and |sum of the lumped masses - mass0| (003 eq 57), over mass0. */
mfree_status_t fc_mass_error(mfree_system_t *sys, const double *y, int n, const double *m, double mass0,
                             double *err);

/* A growable array of doubles for measured series. Returns 0, 1 when out of memory. */
typedef struct {
  double *v;
  int n, cap;
} fc_series_t;
int fc_series_push(fc_series_t *s, int width, const double *row);
void fc_series_free(fc_series_t *s);

#endif
