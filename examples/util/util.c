/* Plots, failures and progress for the examples (util.h). */
#define _POSIX_C_SOURCE 200809L
#include "util.h"

#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

static int on_path(const char *name) {
  const char *path = getenv("PATH");
  if (!path) return 0;
  char buf[4096];
  for (const char *p = path; *p;) {
    const char *e = strchr(p, ':');
    const size_t len = e ? (size_t)(e - p) : strlen(p);
    if (len > 0 && len + strlen(name) + 2 < sizeof buf) {
      memcpy(buf, p, len);
      buf[len] = '/';
      strcpy(buf + len + 1, name);
      if (access(buf, X_OK) == 0) return 1;
    }
    if (!e) break;
    p = e + 1;
  }
  return 0;
}

static int plot_off(void) {
  const char *off = getenv("MFREE_NO_PLOT");
  return off && *off && strcmp(off, "0") != 0;
}

int ex_plot_available(void) { return !plot_off() && on_path("gnuplot"); }

int ex_plot_path_ok(const char *path) { return !strchr(path, '\'') && !strchr(path, '"'); }

void ex_join(char *dst, size_t size, const char *dir, const char *file) {
  const size_t n = strlen(dir);
  snprintf(dst, size, "%s%s%s", dir, (n && dir[n - 1] == '/') ? "" : "/", file);
}

int ex_plot(const char *script, const char *png, const char *data, FILE *msg) {
  if (plot_off()) {
    fprintf(msg, "no plot (MFREE_NO_PLOT is set); data in %s, script in %s\n", data, script);
    return 0;
  }
  if (!ex_plot_available()) {
    fprintf(msg, "no plot: gnuplot is not installed (scripts/deps.sh installs gnuplot-nox); "
                 "data in %s, script in %s\n", data, script);
    return 0;
  }
  if (!ex_plot_path_ok(script)) {
    fprintf(msg, "no plot: the path %s contains a quote\n", script);
    return 0;
  }
  char cmd[4200];
  snprintf(cmd, sizeof cmd, "gnuplot '%s' > /dev/null 2>&1", script);
  fflush(NULL);
  const int rc = system(cmd);
  if (rc != 0 || access(png, R_OK) != 0) {
    fprintf(msg, "no plot: gnuplot failed on %s; data in %s\n", script, data);
    return 0;
  }
  fprintf(msg, "plot: %s\n", png);
  return 1;
}

int ex_fail(mfree_context_t *ctx, const char *prog, mfree_status_t st, const char *what) {
  char msg[1024] = "";
  mfree_context_get_last_error(ctx, NULL, msg, sizeof msg);
  fprintf(stderr, "%s: %s failed (%s): %s\n", prog, what, mfree_status_string(st), msg);
  return 1;
}

void ex_check_exit(mfree_context_t *ctx, const char *prog, mfree_status_t st, const char *what) {
  if (st != MFREE_SUCCESS) exit(ex_fail(ctx, prog, st, what));
}

void *ex_xmalloc(const char *prog, size_t n) {
  void *p = malloc(n ? n : 1);
  if (!p) {
    fprintf(stderr, "%s: out of memory\n", prog);
    exit(1);
  }
  return p;
}

int ex_plot_option(int argc, char **argv, int *i, const char **out, int *plot) {
  if (strcmp(argv[*i], "--out") == 0 && *i + 1 < argc) {
    *out = argv[++*i];
    return 1;
  }
  if (strcmp(argv[*i], "--no-plot") == 0) {
    *plot = 0;
    return 1;
  }
  return 0;
}

void ex_progress_init(ex_progress_t *p, int quiet, double t0, double t1) {
  p->quiet = quiet;
  p->tty = isatty(fileno(stderr));
  p->last = -1;
  p->t0 = t0;
  p->t1 = t1;
  p->base = 0;
  p->f = stderr;
}

void ex_progress_to(ex_progress_t *p, FILE *f) {
  p->f = f;
  p->tty = 1;
}

int32_t ex_progress(void *user, int64_t step, double t, double dt) {
  ex_progress_t *p = user;
  (void)dt;
  if (p->quiet || !p->tty) return 0;
  int pct = p->t1 > p->t0 ? (int)(100.0 * (t - p->t0) / (p->t1 - p->t0)) : 100;
  if (pct > 100) pct = 100;
  if (pct != p->last) {
    p->last = pct;
    const int w = 40, fill = pct * w / 100;
    fprintf(p->f, "\r[%.*s%*s] %3d%%  t = %.4g s  step %lld", fill,
            "########################################", w - fill, "", pct, t,
            (long long)(p->base + step));
    fflush(p->f);
  }
  return 0;
}

void ex_progress_steps(ex_progress_t *p, int64_t steps) { p->base += steps; }

void ex_progress_done(ex_progress_t *p, const char *what, double t) {
  if (p->quiet) return;
  if (p->tty && p->last >= 0) fprintf(p->f, "\n");
  else fprintf(stderr, "%s: integrated to t = %.4g s in %lld steps\n", what, t, (long long)p->base);
}

/* ---- VTU ---- */

const char *ex_vtu_type_name(ex_vtu_type_t type) {
  return type == EX_VTU_INT64 ? "Int64" : type == EX_VTU_INT32 ? "Int32" : "Float64";
}

int ex_vtu_file_components(int ncomp) { return ncomp == 2 ? 3 : ncomp; }

/* Component c of item i of an array, printed; components past ncomp (a 2-vector's third)
 * are 0. */
static void vtu_value(FILE *f, const ex_vtu_array_t *a, int64_t i, int c) {
  if (c >= a->ncomp) {
    fputs("0", f);
    return;
  }
  const int64_t k = i * a->ld + c;
  if (a->type == EX_VTU_INT64) fprintf(f, "%lld", (long long)((const int64_t *)a->data)[k]);
  else if (a->type == EX_VTU_INT32) fprintf(f, "%d", (int)((const int32_t *)a->data)[k]);
  else fprintf(f, "%.17g", ((const double *)a->data)[k]);
}

static void vtu_array(FILE *f, const ex_vtu_array_t *a, int64_t n) {
  const int nc = ex_vtu_file_components(a->ncomp);
  fprintf(f, "<DataArray type=\"%s\"", ex_vtu_type_name(a->type));
  if (a->name) fprintf(f, " Name=\"%s\"", a->name);
  fprintf(f, " NumberOfComponents=\"%d\" format=\"ascii\">\n", nc);
  for (int64_t i = 0; i < n; ++i)
    for (int c = 0; c < nc; ++c) {
      vtu_value(f, a, i, c);
      fputc(c + 1 < nc ? ' ' : '\n', f);
    }
  fputs("</DataArray>\n", f);
}

int ex_vtu_write(const char *path, int64_t n, int dim, const double *x, int64_t ldx, int narrays,
                 const ex_vtu_array_t *arrays) {
  FILE *f = fopen(path, "w");
  if (!f) return 1;
  fprintf(f, "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" "
             "byte_order=\"LittleEndian\" header_type=\"UInt64\">\n<UnstructuredGrid>\n"
             "<Piece NumberOfPoints=\"%lld\" NumberOfCells=\"%lld\">\n<Points>\n",
          (long long)n, (long long)n);
  const ex_vtu_array_t points = {NULL, EX_VTU_FLOAT64, dim, x, ldx};
  /* (the points always have three components: those past dim are 0) */
  fprintf(f, "<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n");
  for (int64_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) {
      vtu_value(f, &points, i, c);
      fputc(c < 2 ? ' ' : '\n', f);
    }
  fputs("</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n", f);
  for (int64_t i = 0; i < n; ++i) fprintf(f, "%lld\n", (long long)i);
  fputs("</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n", f);
  for (int64_t i = 0; i < n; ++i) fprintf(f, "%lld\n", (long long)i + 1);
  fputs("</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n", f);
  for (int64_t i = 0; i < n; ++i) fputs("1\n", f);
  fputs("</DataArray>\n</Cells>\n<PointData>\n", f);
  for (int a = 0; a < narrays; ++a) vtu_array(f, &arrays[a], n);
  fputs("</PointData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n", f);
  const int bad = ferror(f);
  return (fclose(f) != 0) || bad;
}
