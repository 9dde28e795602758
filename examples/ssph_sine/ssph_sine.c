/* Paper 001 (Zhang & Batra, "Symmetric smoothed particle hydrodynamics (SSPH) method and
 * its application to elastic problems", Comput Mech 43 (2009) 321-340), Sect. 6.1:
 * f = sin(8(1 - x)) / sin 8 on [0, 1] (eq 6.1), revised Gauss kernel (eq 6.2),
 * h = 1.5 Delta, quadratic basis; MSPH, SSPH and RKPM estimates of f, f_x, f_xx at the
 * particles; Table 1 (10 particles) and Table 2 (convergence rates over N = 10, 20, 30,
 * 50, 100, 250, 500: least-squares slopes of ln ||e|| against ln Delta).
 *
 * Particles sit at the cell centres x_i = (i - 1/2)/N, the only layout that reproduces
 * the paper's SSPH numbers; norms are sqrt(Delta sum e_i^2), the midpoint rule
 * (docs/papers.md, paper 001, choices 1 and 2).
 *
 * Support edge: with h = 1.5 Delta the neighbours i +- 3 lie exactly at distance 2h,
 * where the revised Gauss kernel vanishes but its derivative jumps. SSPH never uses W',
 * so it does not care; MSPH and RKPM do. With h = 1.5 Delta computed in floating point,
 * whether such a pair counts as inside depends on the rounding of x_j - x_i, pair by
 * pair. --edge include / exclude shift h by a relative 1e-12 so that all of them are
 * inside / outside (the paper's "d <= 2" convention is include; see docs/papers.md,
 * paper 001, choices 3).
 *
 * Output: a table (default) or one JSON object (--json) on stdout; the convergence data
 * go to DIR/ssph_sine.dat with a gnuplot script DIR/ssph_sine.gp, which is run to make
 * DIR/ssph_sine.png when gnuplot is on PATH (and --no-plot is not given).
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "papers.h"
#include "util.h"

#define NN 7
#define NM 3
static const int kN[NN] = {10, 20, 30, 50, 100, 250, 500};
static const mfree_method_t kMethod[NM] = {MFREE_METHOD_MSPH, MFREE_METHOD_SSPH,
                                           MFREE_METHOD_RKPM};
static const char *const kName[NM] = {"MSPH", "SSPH", "RKPM"};

/* Paper 001 Table 1 (N = 10) and Table 2 (rates), columns MSPH, SSPH, RKPM. */
static const double kPaperT1[NM][3] = {{2.86e-2, 1.40, 20.1}, {1.88e-2, 1.21, 17.2},
                                       {1.88e-2, 0.59, 32.8}};
static const char *const kPaperT1Text[NM][3] = {{"2.86E-2", "1.40", "20.1"},
                                                {"1.88E-2", "1.21", "17.2"},
                                                {"1.88E-2", "0.59", "32.8"}};
static const double kPaperRate[NM][3] = {{3.52, 1.92, 1.47}, {3.54, 1.96, 1.49},
                                         {3.54, 1.80, 1.54}};

typedef struct {
  const char *out_dir;
  int plot;
  int edge; /* 0 as is, +1 include, -1 exclude */
} options_t;

static int parse_extra(int argc, char **argv, int *i, void *user) {
  options_t *o = user;
  if (ex_plot_option(argc, argv, i, &o->out_dir, &o->plot)) return 1;
  if (strcmp(argv[*i], "--edge") == 0 && *i + 1 < argc) {
    const char *v = argv[++*i];
    if (strcmp(v, "as-is") == 0) o->edge = 0;
    else if (strcmp(v, "include") == 0) o->edge = 1;
    else if (strcmp(v, "exclude") == 0) o->edge = -1;
    else return 0;
    return 1;
  }
  return 0;
}

static const char *edge_name(int e) { return e > 0 ? "include" : (e < 0 ? "exclude" : "as-is"); }

/* Writes the data file and the gnuplot script; returns 0 or 1 (message on stderr). */
static int write_files(const options_t *o, double e[NM][NN][3], char *dat, char *gp,
                       char *png, size_t size) {
  ex_join(dat, size, o->out_dir, "ssph_sine.dat");
  ex_join(gp, size, o->out_dir, "ssph_sine.gp");
  ex_join(png, size, o->out_dir, "ssph_sine.png");
  if (!ex_plot_path_ok(o->out_dir)) {
    fprintf(stderr, "error: --out directory must not contain quotes\n");
    return 1;
  }
  FILE *f = fopen(dat, "w");
  if (!f) {
    fprintf(stderr, "error: cannot write %s\n", dat);
    return 1;
  }
  fprintf(f, "# paper 001 Sect. 6.1: sine test, revised Gauss, h = 1.5 Delta (edge %s)\n",
          edge_name(o->edge));
  fprintf(f, "# N Delta  MSPH_e0 MSPH_e1 MSPH_e2  SSPH_e0 SSPH_e1 SSPH_e2  RKPM_e0 RKPM_e1 RKPM_e2\n");
  for (int k = 0; k < NN; ++k) {
    fprintf(f, "%d %.6e", kN[k], 1.0 / kN[k]);
    for (int m = 0; m < NM; ++m)
      for (int c = 0; c < 3; ++c) fprintf(f, " %.6e", e[m][k][c]);
    fprintf(f, "\n");
  }
  if (fclose(f) != 0) {
    fprintf(stderr, "error: cannot write %s\n", dat);
    return 1;
  }
  f = fopen(gp, "w");
  if (!f) {
    fprintf(stderr, "error: cannot write %s\n", gp);
    return 1;
  }
  static const char *const title[3] = {"L^2 error of f", "H^1: L^2 error of f_x",
                                       "H^2: L^2 error of f_{xx}"};
  fprintf(f, "# gnuplot script written by mfree_ssph_sine (paper 001 Fig. 3)\n");
  fprintf(f, "set terminal png size 1500,500\nset output '%s'\n", png);
  fprintf(f, "set multiplot layout 1,3 title 'SSPH / MSPH / RKPM, f = sin(8(1-x))/sin 8, "
             "revised Gauss, h = 1.5 Delta'\n");
  fprintf(f, "set logscale xy\nset format y '10^{%%L}'\nset xlabel 'Delta'\nset key top left\n");
  for (int c = 0; c < 3; ++c) {
    fprintf(f, "set title '%s'\nplot", title[c]);
    for (int m = 0; m < NM; ++m)
      fprintf(f, "%s '%s' using 2:%d with linespoints lw 1.5 dt %d title '%s'", m ? "," : "",
              dat, 3 + 3 * m + c, m == 2 ? 2 : 1, kName[m]);
    fprintf(f, "\n");
  }
  fprintf(f, "unset multiplot\n");
  if (fclose(f) != 0) {
    fprintf(stderr, "error: cannot write %s\n", gp);
    return 1;
  }
  return 0;
}

static void json_triple(const double v[3]) {
  printf("{\"e0\":%.10e,\"e1\":%.10e,\"e2\":%.10e}", v[0], v[1], v[2]);
}

int main(int argc, char **argv) {
  static const char usage[] =
      "usage: mfree_ssph_sine [--json] [--out DIR] [--no-plot] [--edge as-is|include|exclude]\n"
      "Paper 001 Tables 1 and 2 (sine test, MSPH/SSPH/RKPM) next to the paper's values;\n"
      "writes DIR/ssph_sine.dat (+ .gp, and .png when gnuplot is on PATH).\n";
  options_t opt = {".", 1, 0};
  int json = 0;
  if (papers_parse(argc, argv, usage, &json, parse_extra, &opt)) return 2;

  mfree_context_t *ctx = NULL;
  if (mfree_context_create(&ctx) != MFREE_SUCCESS) {
    fprintf(stderr, "error: cannot create an mfree context\n");
    return 1;
  }
  const double hfac = 1.5 * (1.0 + 1e-12 * opt.edge);
  double e[NM][NN][3], rate[NM][3];
  for (int m = 0; m < NM; ++m) {
    for (int k = 0; k < NN; ++k) {
      const mfree_status_t st = papers_norms_1d(ctx, kMethod[m], 2, MFREE_KERNEL_REVISED_GAUSS,
                                                0.0, kN[k], hfac, papers_sine, 2, e[m][k]);
      if (st != MFREE_SUCCESS) {
        char what[64];
        snprintf(what, sizeof what, "%s with N = %d", kName[m], kN[k]);
        papers_report(ctx, st, what);
        mfree_context_destroy(&ctx);
        return 1;
      }
    }
    for (int c = 0; c < 3; ++c) {
      double v[NN];
      for (int k = 0; k < NN; ++k) v[k] = e[m][k][c];
      rate[m][c] = papers_rate(NN, kN, v);
    }
  }
  mfree_context_destroy(&ctx);

  char dat[4200], gp[4200], png[4200];
  if (write_files(&opt, e, dat, gp, png, sizeof dat)) return 1;
  if (json) {
    const int have_png = opt.plot && ex_plot(gp, png, dat, stderr);
    printf("{\"edge\":\"%s\",\"N\":[", edge_name(opt.edge));
    for (int k = 0; k < NN; ++k) printf("%s%d", k ? "," : "", kN[k]);
    printf("],\"table1\":{");
    for (int m = 0; m < NM; ++m) {
      printf("%s\"%s\":", m ? "," : "", kName[m]);
      json_triple(e[m][0]);
    }
    printf("},\"rates\":{");
    for (int m = 0; m < NM; ++m) {
      printf("%s\"%s\":", m ? "," : "", kName[m]);
      json_triple(rate[m]);
    }
    printf("},\"per_n\":{");
    for (int m = 0; m < NM; ++m) {
      printf("%s\"%s\":{", m ? "," : "", kName[m]);
      for (int c = 0; c < 3; ++c) {
        printf("%s\"e%d\":[", c ? "," : "", c);
        for (int k = 0; k < NN; ++k) printf("%s%.10e", k ? "," : "", e[m][k][c]);
        printf("]");
      }
      printf("}");
    }
    printf("},\"paper\":{\"table1\":{");
    for (int m = 0; m < NM; ++m) {
      printf("%s\"%s\":", m ? "," : "", kName[m]);
      json_triple(kPaperT1[m]);
    }
    printf("},\"rates\":{");
    for (int m = 0; m < NM; ++m) {
      printf("%s\"%s\":", m ? "," : "", kName[m]);
      json_triple(kPaperRate[m]);
    }
    printf("}},\"files\":{\"data\":\"%s\",\"script\":\"%s\",\"plot\":", dat, gp);
    if (have_png) printf("\"%s\"}}\n", png);
    else printf("null}}\n");
    return 0;
  }

  printf("Paper 001 Sect. 6.1: f = sin(8(1-x))/sin 8, revised Gauss, h = 1.5 Delta, quadratic\n"
         "basis, particles at cell centres, norms sqrt(Delta sum e_i^2); support edge: %s.\n\n",
         edge_name(opt.edge));
  printf("Table 1 (N = 10)      %-21s %-21s %-21s\n", "MSPH", "SSPH", "RKPM");
  printf("                      %-10s %-10s %-10s %-10s %-10s %-10s\n", "mfree", "paper",
         "mfree", "paper", "mfree", "paper");
  static const char *const rowname[3] = {"||e||_0 (L2)", "||e||_1 (H1)", "||e||_2 (H2)"};
  for (int c = 0; c < 3; ++c) {
    printf("%-21s", rowname[c]);
    for (int m = 0; m < NM; ++m)
      printf(c == 0 ? " %-10.3E %-10s" : " %-10.4g %-10s", e[m][0][c], kPaperT1Text[m][c]);
    printf("\n");
  }
  printf("\nTable 2 (rates)\n");
  for (int c = 0; c < 3; ++c) {
    printf("%-21s", rowname[c]);
    for (int m = 0; m < NM; ++m) printf(" %-10.3f %-10.2f", rate[m][c], kPaperRate[m][c]);
    printf("\n");
  }
  printf("\nError norms per N (Fig. 3)\n%5s", "N");
  for (int m = 0; m < NM; ++m) printf("  %-9s %-9s %-9s", kName[m], "", "");
  printf("\n");
  for (int k = 0; k < NN; ++k) {
    printf("%5d", kN[k]);
    for (int m = 0; m < NM; ++m)
      printf("  %-9.3e %-9.3e %-9.3e", e[m][k][0], e[m][k][1], e[m][k][2]);
    printf("\n");
  }
  printf("\nSSPH reproduces the paper exactly. MSPH and RKPM derivatives depend on whether the\n"
         "neighbours at exactly 2h (i +- 3) count (try --edge include / exclude); the paper's\n"
         "MSPH/RKPM numbers match neither convention to the printed digits.\n\n");
  printf("data: %s\nscript: %s\n", dat, gp);
  if (opt.plot) ex_plot(gp, png, dat, stdout);
  else printf("plot: not made (--no-plot); run gnuplot %s\n", gp);
  return 0;
}
