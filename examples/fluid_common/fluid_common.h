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
#include <stdint.h>
#include <stdio.h>

#include <mfree.h>

#include "util.h"

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
/* The walls of a rectangular tank whose fluid fills x0 <= x <= x1 above z = 0: left wall,
 * floor and right wall set back by off, up to height top, at spacing <= ds. Returns 0, or
 * 1 when out of memory. */
int fc_walls_tank(fc_walls_t *w, double x0, double x1, double top, double off, double ds);
void fc_walls_free(fc_walls_t *w);
/* No-slip walls for the tank whose fluid fills 0 <= x <= ncol d above z = 0: four layers
 * of dummy particles (mfree_system_set_dummy_particles, volume d^2) at spacing d continuing
 * the fluid's lattice past the floor and both side walls, the side layers up to height
 * top. Returns the library's status (MFREE_ERR_ALLOC when out of memory). */
mfree_status_t fc_dummy_tank(mfree_system_t *sys, int ncol, double top, double d);

/* Particles q0, q0 + 1, ... of a block of water at rest: nj rows of ni particles at the
 * centres of lattice cells of spacing d, the lower-left cell's corner at (x0, 0), row by
 * row; densities hydrostatic below a free surface at height H (003 eq 65, Tait with rho0,
 * kappa, gamma, gravity g), masses rho d^2. y is the state of n particles. Returns the
 * next index, q0 + ni nj. */
int fc_water_block(double *y, double *m, int n, int q0, double x0, int ni, int nj, double d, double H,
                   double rho0, double kappa, double gamma, double g);
/* Cell (i, j) of such a block alone: its particle's position x (2), hydrostatic density
 * *rho and mass *m, the bits fc_water_block writes (hosts that hold a share of the
 * particles, e.g. on MPI ranks). */
void fc_water_cell(double x0, int i, int j, double d, double H, double rho0, double kappa, double gamma, double g,
                   double *x, double *rho, double *m);

/* Particles q0, q0 + 1, ... of a circular drop of radius R at rest density rho0, falling
 * at speed v0: the points (xc + i d, zc + j d) of the lattice of spacing d inside the
 * circle (those on it included whatever the rounding), velocity parameters (0, -v0) (a
 * constant field is reproduced exactly, 003 eq 100), masses rho0 d^2. y is the state of n
 * particles; with y NULL nothing is written (m may be NULL too), to count the drop's
 * particles first. Returns the next index, q0 + the drop's particles. */
int fc_water_drop(double *y, double *m, int n, int q0, double xc, double zc, double R, double d, double rho0,
                  double v0);

/* ---- run options ---- */

/* An example's own option: name, kind 'i' (int), 'd' (double) or 's' (string), and where
 * its value goes. A list ends with a NULL name. */
typedef struct {
  const char *name;
  char kind;
  void *value;
} fc_option_t;
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
/* Parse the command line: the run options, the example's own (opts) and --help (usage on
 * stdout). Returns 0 to go on, -1 after --help (exit with 0), 2 after a bad or unknown
 * option (usage on stderr; exit with 2). */
int fc_parse(int argc, char **argv, fc_run_t *r, const fc_option_t *opts, void (*usage)(FILE *));
/* Usage lines of the run options. */
void fc_run_usage(FILE *f);
/* Create the out directory (and the VTU directory). Returns 0, or 1 with a message. */
int fc_run_prepare(fc_run_t *r);
/* The directory of the VTU series, NULL when there is none. */
const char *fc_run_vtu_dir(const fc_run_t *r);
/* Open the CSV file (any name) in the out directory for writing; NULL after
 * "mfree_<name>: error: cannot write <path>" on stderr. */
FILE *fc_open_csv(const fc_run_t *r, const char *file);

/* ---- VTU series for ParaView ---- */

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
 * t is the physical time recorded in the PVD: a VTU of the particles (examples/util's
 * ex_vtu_write) with their interpolated velocity, pressure, density and, unless tag is
 * NULL, the integer tag "fluid". Returns 0, or 1 with a message. */
int fc_vtu_maybe(fc_vtu_t *v, mfree_system_t *sys, double T, double t, int n, const double *y,
                 const int32_t *tag);
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

/* ---- running ---- */

/* A 2D fluid of the paper 003 examples: n particles with masses m, rest densities rho0
 * (stride 0: one for all), Tait kappa and gamma, viscosity mu, smoothing length h,
 * gravity g downwards, and, unless walls is NULL, the wall force of 003 Sect. 6.2 at
 * r0 = 0.7 h with the given strength A. On failure *sys is NULL and the context holds
 * the message. */
mfree_status_t fc_fluid_create(mfree_context_t *ctx, int n, const double *m, const double *rho0, int64_t stride,
                               double kappa, double gamma, double mu, double h, double g, const fc_walls_t *walls,
                               double strength, mfree_system_t **sys);
/* The same settings on a fluid system created otherwise (e.g. on MPI ranks, where m holds
 * the owned particles' and the ghosts' masses). */
mfree_status_t fc_fluid_configure(mfree_system_t *sys, const double *m, const double *rho0, int64_t stride,
                                  double kappa, double gamma, double mu, double h, double g, const fc_walls_t *walls,
                                  double strength);
/* The head of every summary: "status", "error" (the message, null without a failure),
 * "t", "steps", "particles". */
void fc_json_run(fc_json_t *j, mfree_status_t run, const char *msg, double t, long long steps, int n);

/* mfree_system_integrate to t_end with the progress bar p, adding the steps taken to
 * *steps. */
mfree_status_t fc_integrate(mfree_system_t *sys, mfree_integrator_t scheme, double *y, double *t, double t_end,
                            double cfl, ex_progress_t *p, int64_t *steps);
/* The densities over every accepted step of a run, the initial state included: the
 * output times alone can miss a short excursion (a period-two mode of the explicit step
 * growing and dying between two outputs, docs/fluid.md). y is the state integrated, of
 * n particles in dim dimensions; lo and hi the extremes, and at the lowest: the time t_lo,
 * the particle q_lo and its position x_lo. */
typedef struct {
  const double *y;
  int n, dim;
  double lo, hi, t_lo, x_lo[3];
  int q_lo;
  ex_progress_t *progress; /* drawn after each scan */
} fc_density_watch_t;
/* Start the watch at the state y at time t (scanned now). */
void fc_density_watch_init(fc_density_watch_t *w, const double *y, int n, int dim, double t, ex_progress_t *p);
/* fc_integrate with the densities scanned after every accepted step. */
mfree_status_t fc_integrate_watched(mfree_system_t *sys, mfree_integrator_t scheme, double *y, double *t,
                                    double t_end, double cfl, fc_density_watch_t *w, int64_t *steps);
/* Seconds of a monotonic clock, for the summaries' wall_seconds. */
double fc_seconds(void);

/* ---- plots (examples/util's ex_plot runs gnuplot) ---- */

/* Begin the gnuplot script DIR/<stem>.gp that draws DIR/<stem>.png (width x height) from
 * the CSV DIR/<stem>.csv, whose path goes to csv: terminal, output, separator, grid and
 * axis labels; the caller adds key, title and plot. NULL when plots are off (--no-plot)
 * or a path cannot be quoted in the script. */
FILE *fc_plot_begin(const fc_run_t *r, const char *stem, int width, int height, const char *xlabel,
                    const char *ylabel, char *csv, size_t size);
/* Close the script and run gnuplot: "plot: <png>", or why there is no plot. */
void fc_plot_end(FILE *f, const fc_run_t *r, const char *stem);

/* ---- mass ---- */

/* The Galerkin lumped masses (003 eq 56; the diagonal of the velocity block of
 * mfree_system_assemble_mass) of the n particles of a 2D fluid at state y. */
mfree_status_t fc_lumped_masses(mfree_system_t *sys, const double *y, int n, double *lumped);
/* Relative mass error of a run: the larger of |sum m - mass0| (constant particle masses,
 * none lost) and |sum of the lumped masses - mass0| (003 eq 57), over mass0. */
mfree_status_t fc_mass_error(mfree_system_t *sys, const double *y, int n, const double *m, double mass0,
                             double *err);

/* ---- the dam break of paper 003 against Martin & Moyce (1952): examples/dam_break and
 * examples/mpi/dam_break ---- */

/* A column of width a and height H = 2a (n^2 = 2) of nx x nz = 2 nx particles (particle
 * q = j nx + i: cell (i, j) of a water block at x0 = 0, spacing d = a / nx, h = 1.5 d,
 * rho0 1000, gamma 7, g 9.81, kappa = 100 rho0 (2 g H) / gamma, 003 eq 125) at the left
 * end of a tank of length L = tank a; walls (floor and both ends, spacing d/3) set back
 * by off = offset d from the fluid's edge up to 1.5 H; the box a particle must stay in
 * (crossing a wall fails); T = t tscale, tscale = sqrt(2 g / a). */
typedef struct {
  double a, H, L, d, h, off, rho0, gamma, g, kappa, tscale;
  int nx, nz, n;
  fc_walls_t walls;
  double lo[2], hi[2];
} fc_dam_t;
/* The usage lines of the options both dam-break examples take: --nx, --a, --tank,
 * --tend, --cfl, --mu, --strength, --offset, --shepard-cond, --scheme, --lumping, --data. */
void fc_dam_usage(FILE *f);
/* Returns 0, or 1 when out of memory. */
int fc_dam_init(fc_dam_t *b, double a, int nx, double tank, double offset);
void fc_dam_free(fc_dam_t *b);
/* Particle q's position x (2), density and mass at rest (fc_water_cell). */
void fc_dam_particle(const fc_dam_t *b, int64_t q, double *x, double *rho, double *m);
/* fc_fluid_configure with the dam break's fluid (m: the system's per-particle masses),
 * viscosity mu, wall strength A, lumping, Shepard condition and box. */
mfree_status_t fc_dam_configure(const fc_dam_t *b, mfree_system_t *sys, const double *m, double mu,
                                double strength, mfree_lumping_t lumping, double shepard);

/* The Martin & Moyce points (T, Z) of a CSV file ("T,Z" lines, # comments): the count
 * (at most cap), 0 when path is NULL or the file cannot be read. */
int fc_read_pairs(const char *path, double *T, double *Z, int cap);

/* A front history Z(T) (nf samples, T ascending) against the experiment's ndata points:
 * max_rel_dev the largest |Z - Z_exp| / Z_exp over the points with 1 <= T <= 3 (Z
 * linearly interpolated in T; -1 without a compared point), max_rel_dev_wide the same
 * over 0.5 <= T <= 3 (NaN without one), and offset[3] = mean, min, max of T_exp minus the
 * T at which the front first reaches Z_exp over 0.5 <= T <= 3 (NaN without one).
 * head_speed: the surge front's speed dZ/dT, the least-squares slope of the samples with
 * 1 <= T <= 3 (head_points of them; NaN with fewer than 3), before the front reaches the
 * tank's far wall at Z = 5 (times sqrt(2 g a) in m/s); head_speed_exp the same fit
 * through the experiment's points in that window. */
typedef struct {
  double max_rel_dev, max_rel_dev_wide, offset[3];
  int compared, compared_wide;
  double head_speed, head_speed_exp;
  int head_points;
} fc_front_cmp_t;
void fc_front_compare(int nf, const double *fT, const double *fZ, int ndata, const double *dT, const double *dZ,
                      fc_front_cmp_t *c);

/* front.csv in r's out directory with its header (the columns T, Z, Z_floor, t, steps);
 * NULL after a message when it cannot be written. */
FILE *fc_dam_csv(const fc_run_t *r, const fc_dam_t *b);
/* The gnuplot script and PNG "front" of the CSV against the experiment's points in data
 * (ndata of them), over 0 <= T <= t_end + 0.5 (nothing with --no-plot). */
void fc_dam_plot(const fc_run_t *r, const fc_dam_t *b, const char *data, int ndata, double t_end);
/* What a dam-break run reports besides its front. */
typedef struct {
  long long steps;
  double wall_seconds, cfl, shepard, mu, T_end; /* T_end: the T reached */
  int scheme;                               /* an mfree_integrator_t */
  mfree_status_t status;
  const char *error; /* the message of a failed run */
} fc_dam_run_t;
/* The summary's keys of both dam-break examples: "front" and "front_floor" ([T, Z] rows),
 * their digests "time_digest", "front_digest", "front_floor_digest" (fc_digest),
 * "max_rel_dev", "compared", "max_rel_dev_wide", "compared_wide", "time_offset",
 * "particles", "steps", "wall_seconds", "a", "nx", "cfl", "shepard_condition", "mu",
 * "scheme", "status", "error" (null after a success), "t_end", "head_speed",
 * "head_speed_experiment", "head_fit_points" (fc_front_compare). */
void fc_dam_json(fc_json_t *j, const fc_dam_t *b, int nf, const double *fT, const double *fZ, const double *fZf,
                 const fc_front_cmp_t *c, const fc_dam_run_t *r);
/* Z every fourth sample and the comparison, on stdout. */
void fc_dam_print(int nf, const double *fT, const double *fZ, const fc_front_cmp_t *c);

/* A digest of n doubles' bits (16 hex digits and a NUL in hex[17]): equal digests of
 * two runs' histories say that they agree bit for bit, which the JSON's 10 digits do
 * not. */
void fc_digest(const double *v, size_t n, char *hex);

/* ---- least-squares line y = a + b x through samples added one at a time ---- */
typedef struct {
  double sx, sy, sxx, sxy;
  int n;
} fc_fit_t;
void fc_fit_add(fc_fit_t *f, double x, double y);
/* Slope and intercept (NaN with fewer than 3 samples); either output may be NULL. */
void fc_fit_line(const fc_fit_t *f, double *slope, double *intercept);

/* A growable array of doubles for measured series. Returns 0, 1 when out of memory. */
typedef struct {
  double *v;
  int n, cap;
} fc_series_t;
int fc_series_push(fc_series_t *s, int width, const double *row);
void fc_series_free(fc_series_t *s);

#endif
