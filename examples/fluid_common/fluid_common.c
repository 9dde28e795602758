#define _XOPEN_SOURCE 700
#include "fluid_common.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

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

int fc_walls_tank(fc_walls_t *w, double x0, double x1, double top, double off, double ds) {
  int bad = fc_walls_segment(w, x0 - off, top, x0 - off, -off, ds, 1, 0, 0);
  bad |= fc_walls_segment(w, x0 - off, -off, x1 + off, -off, ds, 0, 1, 1);
  bad |= fc_walls_segment(w, x1 + off, -off, x1 + off, top, ds, -1, 0, 1);
  return bad;
}

mfree_status_t fc_dummy_tank(mfree_system_t *sys, int ncol, double top, double d) {
  const int nl = 4, nrow = (int)ceil(top / d), ndum = nl * (ncol + 2 * nl) + 2 * nl * nrow;
  const double L = ncol * d;
  double *xd = malloc(2 * (size_t)ndum * sizeof *xd);
  if (!xd) return MFREE_ERR_ALLOC;
  int k = 0;
  for (int l = 0; l < nl; ++l)
    for (int i = -nl; i < ncol + nl; ++i, ++k) xd[2 * k] = (i + 0.5) * d, xd[2 * k + 1] = -(l + 0.5) * d;
  for (int l = 0; l < nl; ++l)
    for (int j = 0; j < nrow; ++j)
      for (int side = 0; side < 2; ++side, ++k) {
        xd[2 * k] = side ? L + (l + 0.5) * d : -(l + 0.5) * d;
        xd[2 * k + 1] = (j + 0.5) * d;
      }
  const double vol = d * d;
  const mfree_status_t st = mfree_system_set_dummy_particles(sys, ndum, xd, &vol, 0);
  free(xd);
  return st;
}

int fc_water_block(double *y, double *m, int n, int q0, double x0, int ni, int nj, double d, double H,
                   double rho0, double kappa, double gamma, double g) {
  int q = q0;
  for (int j = 0; j < nj; ++j)
    for (int i = 0; i < ni; ++i, ++q)
      fc_water_cell(x0, i, j, d, H, rho0, kappa, gamma, g, y + 2 * q, y + 4 * (size_t)n + q, m + q);
  return q;
}

void fc_water_cell(double x0, int i, int j, double d, double H, double rho0, double kappa, double gamma, double g,
                   double *x, double *rho, double *m) {
  const double z = (j + 0.5) * d;
  x[0] = x0 + (i + 0.5) * d;
  x[1] = z;
  *rho = rho0 * pow(1.0 + rho0 * g * (H - z) / kappa, 1.0 / gamma); /* 003 eq 65 */
  *m = *rho * d * d;
}

int fc_water_drop(double *y, double *m, int n, int q0, double xc, double zc, double R, double d, double rho0,
                  double v0) {
  const int ir = (int)floor(R / d + 1e-9);
  const double rr = (R / d) * (R / d) * (1.0 + 1e-9);
  int q = q0;
  for (int j = -ir; j <= ir; ++j)
    for (int i = -ir; i <= ir; ++i) {
      if (i * i + j * j > rr) continue;
      if (y) {
        y[2 * q] = xc + i * d;
        y[2 * q + 1] = zc + j * d;
        y[2 * (size_t)n + 2 * q + 1] = -v0;
        y[4 * (size_t)n + q] = rho0;
        m[q] = rho0 * d * d;
      }
      ++q;
    }
  return q;
}

void fc_walls_free(fc_walls_t *w) {
  free(w->x);
  free(w->nrm);
  w->x = w->nrm = NULL;
  w->n = w->cap = 0;
}

/* ---- run options ---- */

void fc_run_init(fc_run_t *r, const char *name, double vtu_every) {
  static char out[128];
  snprintf(out, sizeof out, "%s_out", name);
  r->name = name;
  r->out = out;
  r->vtu_dir = NULL;
  r->vtu_every = vtu_every;
  r->vtu_every_set = 0;
  r->json_path = NULL;
  r->json_stdout = 0;
  r->quiet = 0;
  r->plot = 1;
}

int fc_run_option(int argc, char **argv, int *i, fc_run_t *r) {
  const char *s = argv[*i];
  const int has = *i + 1 < argc;
  if (ex_plot_option(argc, argv, i, &r->out, &r->plot)) return 1;
  if (!strcmp(s, "--json")) r->json_stdout = 1;
  else if (!strcmp(s, "--quiet")) r->quiet = 1;
  else if (!strcmp(s, "--vtu") || !strcmp(s, "--json-file") || !strcmp(s, "--vtu-every")) {
    if (!has) return -1;
    const char *v = argv[*i + 1];
    if (!strcmp(s, "--vtu")) r->vtu_dir = v;
    else if (!strcmp(s, "--json-file")) r->json_path = v;
    else {
      char *end = NULL;
      r->vtu_every = strtod(v, &end);
      r->vtu_every_set = 1;
      if (end == v || *end || !(r->vtu_every >= 0)) return -1;
    }
    ++*i;
  } else return 0;
  return 1;
}

static int parse_value(const fc_option_t *o, const char *v) {
  char *end = NULL;
  if (o->kind == 's') {
    *(const char **)o->value = v;
    return 1;
  }
  if (o->kind == 'i') {
    const long x = strtol(v, &end, 10);
    if (end == v || *end || x < -2147483647L || x > 2147483647L) return 0;
    *(int *)o->value = (int)x;
    return 1;
  }
  const double x = strtod(v, &end);
  if (end == v || *end) return 0;
  *(double *)o->value = x;
  return 1;
}

int fc_parse(int argc, char **argv, fc_run_t *r, const fc_option_t *opts, void (*usage)(FILE *)) {
  for (int i = 1; i < argc; ++i) {
    const int k = fc_run_option(argc, argv, &i, r);
    if (k > 0) continue;
    if (k == 0 && !strcmp(argv[i], "--help")) {
      usage(stdout);
      return -1;
    }
    const fc_option_t *o = opts;
    if (k == 0)
      while (o->name && strcmp(o->name, argv[i])) ++o;
    if (k < 0 || !o->name || i + 1 >= argc || !parse_value(o, argv[i + 1])) {
      fprintf(stderr, "mfree_%s: error: bad or unknown option %s%s%s\n", r->name, argv[i], i + 1 < argc ? " " : "",
              i + 1 < argc ? argv[i + 1] : "");
      usage(stderr);
      return 2;
    }
    ++i;
  }
  return 0;
}

void fc_run_usage(FILE *f) {
  fprintf(f, "  --out DIR       data, plots and the JSON summary (default <example>_out)\n"
             "  --vtu DIR       write a VTU series for ParaView into DIR (default: none)\n"
             "  --vtu-every T   its interval (without --vtu: into the --out directory; 0 = none)\n"
             "  --json-file F   the JSON summary (default DIR/<example>.json of --out)\n"
             "  --json          print the JSON summary on stdout as well\n"
             "  --no-plot       do not run gnuplot\n"
             "  --quiet         no progress bar (it is drawn only on a terminal)\n");
}

const char *fc_run_vtu_dir(const fc_run_t *r) {
  if (!(r->vtu_every > 0)) return NULL;
  if (r->vtu_dir) return r->vtu_dir;
  return r->vtu_every_set ? r->out : NULL;
}

static int make_dir(const char *name, const char *dir) {
  if (mkdir(dir, 0777) != 0 && errno != EEXIST) {
    fprintf(stderr, "mfree_%s: error: cannot create %s: %s\n", name, dir, strerror(errno));
    return 1;
  }
  if (access(dir, W_OK) != 0) {
    fprintf(stderr, "mfree_%s: error: cannot write in %s\n", name, dir);
    return 1;
  }
  return 0;
}

int fc_run_prepare(fc_run_t *r) {
  if (make_dir(r->name, r->out)) return 1;
  const char *v = fc_run_vtu_dir(r);
  return v ? make_dir(r->name, v) : 0;
}

/* path opened for writing, or NULL after "mfree_<name>: error: cannot write <path>". */
static FILE *create_file(const char *name, const char *path) {
  FILE *f = fopen(path, "w");
  if (!f) fprintf(stderr, "mfree_%s: error: cannot write %s\n", name, path);
  return f;
}

FILE *fc_open_csv(const fc_run_t *r, const char *file) {
  char path[4096];
  ex_join(path, sizeof path, r->out, file);
  return create_file(r->name, path);
}

/* ---- VTU ---- */

int fc_vtu_open(fc_vtu_t *v, const char *dir, const char *prefix, double every) {
  memset(v, 0, sizeof *v);
  if (!dir) return 0;
  snprintf(v->dir, sizeof v->dir, "%s", dir);
  snprintf(v->prefix, sizeof v->prefix, "%s", prefix);
  v->every = every;
  char path[4096];
  snprintf(path, sizeof path, "%s/%s.pvd", dir, prefix);
  v->pvd = create_file(prefix, path);
  if (!v->pvd) return 1;
  fprintf(v->pvd, "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n");
  return 0;
}

int fc_vtu_maybe(fc_vtu_t *v, mfree_system_t *sys, double T, double t, int n, const double *y,
                 const int32_t *tag) {
  if (!v->pvd || T < v->next - 1e-9 * (1.0 + fabs(T))) return 0;
  double *vhat = malloc(2 * (size_t)n * sizeof *vhat + 1), *p = malloc((size_t)n * sizeof *p + 1);
  char path[4096];
  snprintf(path, sizeof path, "%s/%s_%04d.vtu", v->dir, v->prefix, v->count);
  int rc = !vhat || !p;
  if (!rc) rc = mfree_system_get_velocity(sys, y, vhat) != MFREE_SUCCESS;
  if (!rc) rc = mfree_system_get_pressure(sys, y, p) != MFREE_SUCCESS;
  if (!rc) {
    const ex_vtu_array_t arrays[4] = {{"velocity", EX_VTU_FLOAT64, 2, vhat, 2},
                                      {"pressure", EX_VTU_FLOAT64, 1, p, 1},
                                      {"density", EX_VTU_FLOAT64, 1, y + 4 * (size_t)n, 1},
                                      {"fluid", EX_VTU_INT32, 1, tag, 1}};
    rc = ex_vtu_write(path, n, 2, y, 2, tag ? 4 : 3, arrays);
  }
  free(vhat);
  free(p);
  if (rc) {
    fprintf(stderr, "mfree_%s: error: cannot write %s\n", v->prefix, path);
    return 1;
  }
  fprintf(v->pvd, "<DataSet timestep=\"%.9g\" group=\"\" part=\"0\" file=\"%s_%04d.vtu\"/>\n", t, v->prefix,
          v->count);
  ++v->count;
  while (v->next <= T + 1e-9 * (1.0 + fabs(T))) v->next += v->every;
  return 0;
}

int fc_vtu_close(fc_vtu_t *v) {
  if (!v->pvd) return 0;
  fprintf(v->pvd, "</Collection>\n</VTKFile>\n");
  const int bad = ferror(v->pvd);
  const int rc = (fclose(v->pvd) != 0) || bad;
  v->pvd = NULL;
  if (rc) fprintf(stderr, "mfree_%s: error: cannot write %s/%s.pvd\n", v->prefix, v->dir, v->prefix);
  return rc;
}

/* ---- JSON ---- */

static void json_raw(fc_json_t *j, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

static void json_raw(fc_json_t *j, const char *fmt, ...) {
  if (j->err) return;
  for (;;) {
    va_list ap;
    va_start(ap, fmt);
    const int k = vsnprintf(j->s ? j->s + j->len : NULL, j->s ? j->cap - j->len : 0, fmt, ap);
    va_end(ap);
    if (k < 0) {
      j->err = 1;
      return;
    }
    if (j->s && j->len + (size_t)k < j->cap) {
      j->len += (size_t)k;
      return;
    }
    const size_t cap = 2 * (j->cap + (size_t)k + 64);
    char *s = realloc(j->s, cap);
    if (!s) {
      j->err = 1;
      return;
    }
    j->s = s;
    j->cap = cap;
  }
}

static void json_key(fc_json_t *j, const char *key) { json_raw(j, "%s\"%s\":", j->items++ ? "," : "", key); }

static void json_number(fc_json_t *j, double v) {
  if (isfinite(v)) json_raw(j, "%.10g", v);
  else json_raw(j, "null");
}

void fc_json_init(fc_json_t *j) {
  memset(j, 0, sizeof *j);
  json_raw(j, "{");
}

void fc_json_num(fc_json_t *j, const char *key, double v) {
  json_key(j, key);
  json_number(j, v);
}

void fc_json_int(fc_json_t *j, const char *key, long long v) {
  json_key(j, key);
  json_raw(j, "%lld", v);
}

void fc_json_str(fc_json_t *j, const char *key, const char *v) {
  json_key(j, key);
  if (!v) {
    json_raw(j, "null");
    return;
  }
  json_raw(j, "\"");
  for (const unsigned char *c = (const unsigned char *)v; *c; ++c) {
    if (*c == '"' || *c == '\\') json_raw(j, "\\%c", *c);
    else if (*c < 0x20) json_raw(j, "\\u%04x", *c);
    else json_raw(j, "%c", *c);
  }
  json_raw(j, "\"");
}

void fc_json_table(fc_json_t *j, const char *key, int rows, int width, const double *v) {
  json_key(j, key);
  json_raw(j, "[");
  for (int r = 0; r < rows; ++r) {
    json_raw(j, "%s%s", r ? "," : "", width > 1 ? "[" : "");
    for (int c = 0; c < width; ++c) {
      if (c) json_raw(j, ",");
      json_number(j, v[(size_t)r * width + c]);
    }
    if (width > 1) json_raw(j, "]");
  }
  json_raw(j, "]");
}

int fc_json_finish(fc_json_t *j, const fc_run_t *r) {
  json_raw(j, "}");
  char path[4096];
  if (r->json_path) snprintf(path, sizeof path, "%s", r->json_path);
  else {
    char file[128];
    snprintf(file, sizeof file, "%s.json", r->name);
    ex_join(path, sizeof path, r->out, file);
  }
  int rc = j->err;
  if (rc) fprintf(stderr, "mfree_%s: error: out of memory for the JSON summary\n", r->name);
  else {
    FILE *f = fopen(path, "w");
    rc = !f;
    if (f) {
      fprintf(f, "%s\n", j->s);
      rc = ferror(f) | (fclose(f) != 0);
    }
    if (rc) fprintf(stderr, "mfree_%s: error: cannot write %s\n", r->name, path);
    if (r->json_stdout) printf("%s\n", j->s);
  }
  free(j->s);
  memset(j, 0, sizeof *j);
  return rc;
}

/* ---- errors and series ---- */

int fc_run_error(mfree_context_t *ctx, const fc_run_t *r, mfree_status_t st, const char *unit, double t,
                 char *msg, size_t size) {
  msg[0] = '\0';
  mfree_context_get_last_error(ctx, NULL, msg, size);
  fprintf(stderr, "mfree_%s: error: the run stopped at %s = %.4g (%s): %s\n", r->name, unit, t,
          mfree_status_string(st), msg);
  return 3;
}

mfree_status_t fc_fluid_create(mfree_context_t *ctx, int n, const double *m, const double *rho0, int64_t stride,
                               double kappa, double gamma, double mu, double h, double g, const fc_walls_t *walls,
                               double strength, mfree_system_t **sys) {
  mfree_status_t st = mfree_system_create_fluid(ctx, 2, n, sys);
  if (st == MFREE_SUCCESS) st = fc_fluid_configure(*sys, m, rho0, stride, kappa, gamma, mu, h, g, walls, strength);
  if (st != MFREE_SUCCESS) mfree_system_destroy(sys);
  return st;
}

mfree_status_t fc_fluid_configure(mfree_system_t *sys, const double *m, const double *rho0, int64_t stride,
                                  double kappa, double gamma, double mu, double h, double g, const fc_walls_t *walls,
                                  double strength) {
  const double gv[2] = {0.0, -g};
  mfree_status_t st = mfree_system_set_fluid(sys, rho0, stride, kappa, gamma, mu);
  if (st == MFREE_SUCCESS) st = mfree_system_set_masses(sys, m, 1);
  if (st == MFREE_SUCCESS) st = mfree_system_set_smoothing(sys, h);
  if (st == MFREE_SUCCESS) st = mfree_system_set_gravity(sys, gv);
  if (st == MFREE_SUCCESS && walls)
    st = mfree_system_set_walls(sys, walls->n, walls->x, walls->nrm, 0.7 * h, strength); /* 003 Sect. 6.2 */
  return st;
}

void fc_json_run(fc_json_t *j, mfree_status_t run, const char *msg, double t, long long steps, int n) {
  fc_json_int(j, "status", (int)run);
  fc_json_str(j, "error", run == MFREE_SUCCESS ? NULL : msg);
  fc_json_num(j, "t", t);
  fc_json_int(j, "steps", steps);
  fc_json_int(j, "particles", n);
}

static mfree_status_t integrate(mfree_system_t *sys, mfree_integrator_t scheme, double *y, double *t, double t_end,
                                double cfl, mfree_progress_fn fn, void *user, ex_progress_t *p, int64_t *steps) {
  int64_t k = 0;
  const mfree_status_t st = mfree_system_integrate(sys, scheme, y, t, t_end, cfl, 0.0, fn, user, &k);
  *steps += k;
  ex_progress_steps(p, k);
  return st;
}

mfree_status_t fc_integrate(mfree_system_t *sys, mfree_integrator_t scheme, double *y, double *t, double t_end,
                            double cfl, ex_progress_t *p, int64_t *steps) {
  return integrate(sys, scheme, y, t, t_end, cfl, ex_progress, p, p, steps);
}

static void density_scan(fc_density_watch_t *w, double t) {
  const double *rho = w->y + 2 * (size_t)w->dim * w->n;
  for (int q = 0; q < w->n; ++q) {
    if (rho[q] > w->hi) w->hi = rho[q];
    if (rho[q] < w->lo) {
      w->lo = rho[q];
      w->t_lo = t;
      w->q_lo = q;
      for (int c = 0; c < w->dim; ++c) w->x_lo[c] = w->y[(size_t)w->dim * q + c];
    }
  }
}

void fc_density_watch_init(fc_density_watch_t *w, const double *y, int n, int dim, double t, ex_progress_t *p) {
  *w = (fc_density_watch_t){y, n, dim, INFINITY, -INFINITY, t, {0.0, 0.0, 0.0}, -1, p};
  density_scan(w, t);
}

/* mfree_progress_fn: reads the state only, as the integrator allows. */
static int32_t density_progress(void *user, int64_t step, double t, double dt) {
  fc_density_watch_t *w = user;
  density_scan(w, t);
  return ex_progress(w->progress, step, t, dt);
}

mfree_status_t fc_integrate_watched(mfree_system_t *sys, mfree_integrator_t scheme, double *y, double *t,
                                    double t_end, double cfl, fc_density_watch_t *w, int64_t *steps) {
  return integrate(sys, scheme, y, t, t_end, cfl, density_progress, w, w->progress, steps);
}

double fc_seconds(void) {
  struct timespec c;
  clock_gettime(CLOCK_MONOTONIC, &c);
  return (double)c.tv_sec + 1e-9 * (double)c.tv_nsec;
}

static void stem_path(char *dst, size_t size, const fc_run_t *r, const char *stem, const char *ext) {
  char file[256];
  snprintf(file, sizeof file, "%s.%s", stem, ext);
  ex_join(dst, size, r->out, file);
}

FILE *fc_plot_begin(const fc_run_t *r, const char *stem, int width, int height, const char *xlabel,
                    const char *ylabel, char *csv, size_t size) {
  char gp[4096], png[4096];
  stem_path(gp, sizeof gp, r, stem, "gp");
  stem_path(png, sizeof png, r, stem, "png");
  stem_path(csv, size, r, stem, "csv");
  if (!r->plot || !ex_plot_path_ok(png) || !ex_plot_path_ok(csv)) return NULL;
  FILE *f = fopen(gp, "w");
  if (f)
    fprintf(f, "set terminal pngcairo size %d,%d\nset output '%s'\nset datafile separator ','\nset grid\n"
               "set xlabel '%s'\nset ylabel '%s'\n",
            width, height, png, xlabel, ylabel);
  return f;
}

void fc_plot_end(FILE *f, const fc_run_t *r, const char *stem) {
  if (!f) return;
  fclose(f);
  char gp[4096], png[4096], csv[4096];
  stem_path(gp, sizeof gp, r, stem, "gp");
  stem_path(png, sizeof png, r, stem, "png");
  stem_path(csv, sizeof csv, r, stem, "csv");
  ex_plot(gp, png, csv, r->json_stdout ? stderr : stdout);
}

mfree_status_t fc_lumped_masses(mfree_system_t *sys, const double *y, int n, double *lumped) {
  mfree_matrix_t *M = NULL;
  mfree_status_t st = mfree_system_assemble_mass(sys, y, 0, &M);
  const int64_t *rp;
  const int32_t *ci;
  const double *mv;
  if (st == MFREE_SUCCESS) st = mfree_matrix_get_csr(M, &rp, &ci, &mv);
  if (st == MFREE_SUCCESS)
    for (int q = 0; q < n; ++q) lumped[q] = mv[rp[2 * n + 2 * q]];
  mfree_matrix_destroy(&M);
  return st;
}

mfree_status_t fc_mass_error(mfree_system_t *sys, const double *y, int n, const double *m, double mass0,
                             double *err) {
  double *lumped = malloc((size_t)n * sizeof *lumped + 1);
  if (!lumped) return MFREE_ERR_ALLOC;
  const mfree_status_t st = fc_lumped_masses(sys, y, n, lumped);
  double sum_m = 0.0, sum_l = 0.0;
  for (int q = 0; q < n; ++q) sum_m += m[q], sum_l += lumped[q];
  free(lumped);
  *err = fmax(fabs(sum_m - mass0), fabs(sum_l - mass0)) / mass0;
  return st;
}

/* ---- the dam break ---- */

void fc_dam_usage(FILE *f) {
  fprintf(f, "  --nx N          particles across the column width a (default 24; 2N up its height)\n"
             "  --a A           column width in m (default 0.05715, Martin & Moyce's 2.25 in)\n"
             "  --tank L        tank length in units of a (default 5)\n"
             "  --tend T        end time in units of sqrt(a / (2 g)) (default 3.2)\n"
             "  --cfl C         CFL number of 003 eq 120 (default 0.5)\n"
             "  --mu MU         dynamic viscosity (default 0.5, paper 003)\n"
             "  --strength A    wall-force constant A (default 10, paper 003)\n"
             "  --offset F      walls set back by F d from the fluid's edge (default 0.5)\n"
             "  --shepard-cond C  Shepard functions where the MLS moment matrix's condition exceeds C\n"
             "                  (default 100, the library's; 20 runs the 16a tank to T = 8 at CFL 0.5)\n"
             "  --scheme S      leapfrog (default) | pc (predictor-corrector)\n"
             "  --lumping L     galerkin (default, 003 eq 56) | physical (eq 58)\n"
             "  --data PATH     Martin & Moyce CSV (default: the repository's data/martin_moyce_1952.csv)\n"
             "  (--vtu-every in units of T, default 0.25)\n");
}

int fc_dam_init(fc_dam_t *b, double a, int nx, double tank, double offset) {
  memset(b, 0, sizeof *b);
  b->a = a;
  b->nx = nx;
  b->nz = 2 * nx;
  b->n = b->nx * b->nz;
  b->H = 2.0 * a;
  b->L = tank * a;
  b->d = a / nx;
  b->h = 1.5 * b->d;
  b->rho0 = 1000.0;
  b->gamma = 7.0;
  b->g = 9.81;
  b->kappa = 100.0 * b->rho0 * 2.0 * b->g * b->H / b->gamma; /* 003 eq 125 */
  b->tscale = sqrt(2.0 * b->g / a);                          /* T = t sqrt(2 g / a) */
  /* walls: the floor, then both ends pairwise upwards, spacing d/3, up to 1.5 H */
  const double off = offset * b->d, ws = b->d / 3.0, top = 1.5 * b->H, L = b->L;
  const int nb = (int)ceil((L + 2 * off) / ws) + 1, ns = (int)ceil((top + off) / ws);
  const int nw = nb + 2 * ns;
  fc_walls_t *w = &b->walls;
  w->x = malloc(2 * (size_t)nw * sizeof *w->x);
  w->nrm = malloc(2 * (size_t)nw * sizeof *w->nrm);
  if (!w->x || !w->nrm) {
    fc_walls_free(w);
    return 1;
  }
  w->n = w->cap = nw;
  int k = 0;
  for (int q = 0; q < nb; ++q, ++k) {
    w->x[2 * k] = -off + q * (L + 2 * off) / (nb - 1);
    w->x[2 * k + 1] = -off;
    w->nrm[2 * k] = 0.0;
    w->nrm[2 * k + 1] = 1.0;
  }
  for (int q = 1; q <= ns; ++q)
    for (int side = 0; side < 2; ++side, ++k) {
      w->x[2 * k] = side ? L + off : -off;
      w->x[2 * k + 1] = -off + q * (top + off) / ns;
      w->nrm[2 * k] = side ? -1.0 : 1.0;
      w->nrm[2 * k + 1] = 0.0;
    }
  b->off = off;
  b->lo[0] = b->lo[1] = -off;
  b->hi[0] = L + off;
  b->hi[1] = 10.0 * b->H;
  return 0;
}

void fc_dam_free(fc_dam_t *b) { fc_walls_free(&b->walls); }

void fc_dam_particle(const fc_dam_t *b, int64_t q, double *x, double *rho, double *m) {
  fc_water_cell(0.0, (int)(q % b->nx), (int)(q / b->nx), b->d, b->H, b->rho0, b->kappa, b->gamma, b->g, x, rho, m);
}

mfree_status_t fc_dam_configure(const fc_dam_t *b, mfree_system_t *sys, const double *m, double mu,
                                double strength, mfree_lumping_t lumping, double shepard) {
  mfree_status_t st =
      fc_fluid_configure(sys, m, &b->rho0, 0, b->kappa, b->gamma, mu, b->h, b->g, &b->walls, strength);
  if (st == MFREE_SUCCESS) st = mfree_system_set_lumping(sys, lumping);
  if (st == MFREE_SUCCESS) st = mfree_system_set_shepard_condition(sys, shepard);
  if (st == MFREE_SUCCESS) st = mfree_system_set_box(sys, b->lo, b->hi);
  return st;
}

int fc_read_pairs(const char *path, double *T, double *Z, int cap) {
  FILE *f = path ? fopen(path, "r") : NULL;
  if (!f) return 0;
  char line[512];
  int n = 0;
  while (fgets(line, sizeof line, f) && n < cap) {
    double t, z;
    if (line[0] == '#') continue;
    if (sscanf(line, "%lf,%lf", &t, &z) == 2) {
      T[n] = t;
      Z[n] = z;
      ++n;
    }
  }
  fclose(f);
  return n;
}

/* The front at time T, linear in T between the samples; 0 when T is outside them. */
static int front_at(int nf, const double *fT, const double *fZ, double T, double *Z) {
  for (int r = 0; r + 1 < nf; ++r)
    if (fT[r] <= T && fT[r + 1] >= T) {
      const double w = (T - fT[r]) / (fT[r + 1] - fT[r]);
      *Z = (1 - w) * fZ[r] + w * fZ[r + 1];
      return 1;
    }
  return 0;
}

/* The head speed's window in T: the comparison's (the surge after its start, before the far wall). */
static const double kHead0 = 1.0, kHead1 = 3.0;

void fc_front_compare(int nf, const double *fT, const double *fZ, int ndata, const double *dT, const double *dZ,
                      fc_front_cmp_t *c) {
  double maxdev = -1.0, maxdev_wide = -1.0, off_sum = 0.0, off_min = INFINITY, off_max = -INFINITY, Zs = 0.0;
  int compared = 0, compared_wide = 0, noff = 0;
  for (int q = 0; q < ndata; ++q) {
    if (dT[q] < 0.5 || dT[q] > 3.0) continue;
    if (front_at(nf, fT, fZ, dT[q], &Zs)) {
      const double dev = fabs(Zs - dZ[q]) / dZ[q];
      maxdev_wide = fmax(maxdev_wide, dev);
      ++compared_wide;
      if (dT[q] >= 1.0) {
        maxdev = fmax(maxdev, dev);
        ++compared;
      }
    }
    /* the lag: the front only advances until it hits the far wall, so the first
       crossing of Z_exp is taken */
    for (int r = 0; r + 1 < nf; ++r)
      if (fZ[r] <= dZ[q] && fZ[r + 1] >= dZ[q] && fZ[r + 1] > fZ[r]) {
        const double lag = dT[q] - (fT[r] + (dZ[q] - fZ[r]) / (fZ[r + 1] - fZ[r]) * (fT[r + 1] - fT[r]));
        off_sum += lag;
        off_min = fmin(off_min, lag);
        off_max = fmax(off_max, lag);
        ++noff;
        break;
      }
  }
  c->max_rel_dev = compared ? maxdev : -1.0;
  c->compared = compared;
  c->max_rel_dev_wide = compared_wide ? maxdev_wide : NAN;
  c->compared_wide = compared_wide;
  c->offset[0] = noff ? off_sum / noff : NAN;
  c->offset[1] = noff ? off_min : NAN;
  c->offset[2] = noff ? off_max : NAN;
  fc_fit_t fit = {0, 0, 0, 0, 0}, fit_exp = {0, 0, 0, 0, 0};
  for (int r = 0; r < nf; ++r)
    if (fT[r] >= kHead0 && fT[r] <= kHead1) fc_fit_add(&fit, fT[r], fZ[r]);
  for (int q = 0; q < ndata; ++q)
    if (dT[q] >= kHead0 && dT[q] <= kHead1) fc_fit_add(&fit_exp, dT[q], dZ[q]);
  fc_fit_line(&fit, &c->head_speed, NULL);
  fc_fit_line(&fit_exp, &c->head_speed_exp, NULL);
  c->head_points = fit.n;
}

FILE *fc_dam_csv(const fc_run_t *r, const fc_dam_t *b) {
  FILE *csv = fc_open_csv(r, "front.csv");
  if (csv)
    fprintf(csv, "# Martin & Moyce dam break, a = %g m, nx = %d, %d particles\n"
                 "# T = t sqrt(2 g / a), Z = (max x + d/2) / a, Z_floor: particles with z < 1.5 d\n"
                 "T,Z,Z_floor,t,steps\n", b->a, b->nx, b->n);
  return csv;
}

void fc_dam_plot(const fc_run_t *r, const fc_dam_t *b, const char *data, int ndata, double t_end) {
  char csv_path[4096];
  FILE *gp = ex_plot_path_ok(data) ? fc_plot_begin(r, "front", 800, 560, "T = t (2g/a)^{1/2}", "Z = z/a", csv_path,
                                                   sizeof csv_path)
                                   : NULL;
  if (!gp) return;
  fprintf(gp, "set key top left\n"
              "set title 'Dam break, n^2 = 2: Galerkin SPH (Cueto-Felgueroso et al. 2004) vs Martin and Moyce (1952)'\n"
              "set xrange [0:%g]\n"
              "plot '%s' using 1:2 with lines lw 2 title 'front, all particles (%d)', "
              "'%s' using 1:3 with lines dt 2 title 'front, particles on the floor'",
          t_end + 0.5, csv_path, b->n, csv_path);
  if (ndata) fprintf(gp, ", '%s' using 1:2 with points pt 7 title 'Martin and Moyce (1952), n^2 = 2'", data);
  fprintf(gp, "\n");
  fc_plot_end(gp, r, "front");
}

void fc_dam_json(fc_json_t *j, const fc_dam_t *b, int nf, const double *fT, const double *fZ, const double *fZf,
                 const fc_front_cmp_t *c, const fc_dam_run_t *r) {
  double *rows = calloc(2 * (size_t)(nf + 1), sizeof *rows);
  if (!rows) {
    j->err = 1;
    return;
  }
  for (int q = 0; q < nf; ++q) rows[2 * q] = fT[q], rows[2 * q + 1] = fZ[q];
  fc_json_table(j, "front", nf, 2, rows);
  for (int q = 0; q < nf; ++q) rows[2 * q + 1] = fZf[q];
  fc_json_table(j, "front_floor", nf, 2, rows);
  free(rows);
  char digest[17];
  fc_digest(fT, (size_t)nf, digest);
  fc_json_str(j, "time_digest", digest);
  fc_digest(fZ, (size_t)nf, digest);
  fc_json_str(j, "front_digest", digest);
  fc_digest(fZf, (size_t)nf, digest);
  fc_json_str(j, "front_floor_digest", digest);
  fc_json_num(j, "max_rel_dev", c->max_rel_dev);
  fc_json_int(j, "compared", c->compared);
  fc_json_num(j, "max_rel_dev_wide", c->max_rel_dev_wide);
  fc_json_int(j, "compared_wide", c->compared_wide);
  fc_json_table(j, "time_offset", 3, 1, c->offset);
  fc_json_int(j, "particles", b->n);
  fc_json_int(j, "steps", r->steps);
  fc_json_num(j, "wall_seconds", r->wall_seconds);
  fc_json_num(j, "a", b->a);
  fc_json_int(j, "nx", b->nx);
  fc_json_num(j, "cfl", r->cfl);
  fc_json_num(j, "shepard_condition", r->shepard);
  fc_json_num(j, "mu", r->mu);
  fc_json_str(j, "scheme", r->scheme == MFREE_INTEGRATOR_LEAPFROG ? "leapfrog" : "pc");
  fc_json_int(j, "status", (int)r->status);
  fc_json_str(j, "error", r->status == MFREE_SUCCESS ? NULL : r->error);
  fc_json_num(j, "t_end", r->T_end);
  fc_json_num(j, "head_speed", c->head_speed);
  fc_json_num(j, "head_speed_experiment", c->head_speed_exp);
  fc_json_int(j, "head_fit_points", c->head_points);
}

void fc_dam_print(int nf, const double *fT, const double *fZ, const fc_front_cmp_t *c) {
  for (int q = 0; q < nf; q += 4) printf("  T = %5.2f  Z = %6.3f\n", fT[q], fZ[q]);
  if (c->max_rel_dev >= 0)
    printf("max |Z - Z_exp| / Z_exp over 1 <= T <= 3: %.3f (%d points)\n", c->max_rel_dev, c->compared);
  if (c->compared_wide)
    printf("over 0.5 <= T <= 3: %.3f (%d points); the experiment lags by T = %.3f (%.3f to %.3f)\n",
           c->max_rel_dev_wide, c->compared_wide, c->offset[0], c->offset[1], c->offset[2]);
  if (c->head_points >= 3)
    printf("head speed dZ/dT over 1 <= T <= 3: %.4f (%d samples); the experiment %.4f\n", c->head_speed,
           c->head_points, c->head_speed_exp);
}

void fc_digest(const double *v, size_t n, char *hex) {
  uint64_t h = 0xcbf29ce484222325ULL; /* FNV-1a over the bytes */
  const unsigned char *p = (const unsigned char *)v;
  for (size_t k = 0; k < n * sizeof *v; ++k) h = (h ^ p[k]) * 0x100000001b3ULL;
  snprintf(hex, 17, "%016llx", (unsigned long long)h);
}

void fc_fit_add(fc_fit_t *f, double x, double y) {
  f->sx += x;
  f->sy += y;
  f->sxx += x * x;
  f->sxy += x * y;
  ++f->n;
}

void fc_fit_line(const fc_fit_t *f, double *slope, double *intercept) {
  double b = NAN, a = NAN;
  if (f->n >= 3) {
    b = (f->n * f->sxy - f->sx * f->sy) / (f->n * f->sxx - f->sx * f->sx);
    a = (f->sy - b * f->sx) / f->n;
  }
  if (slope) *slope = b;
  if (intercept) *intercept = a;
}

int fc_series_push(fc_series_t *s, int width, const double *row) {
  if (s->n + width > s->cap) {
    const int cap = 2 * (s->n + width) + 64;
    double *v = realloc(s->v, (size_t)cap * sizeof *v);
    if (!v) return 1;
    s->v = v;
    s->cap = cap;
  }
  memcpy(s->v + s->n, row, (size_t)width * sizeof *row);
  s->n += width;
  return 0;
}

void fc_series_free(fc_series_t *s) {
  free(s->v);
  memset(s, 0, sizeof *s);
}
