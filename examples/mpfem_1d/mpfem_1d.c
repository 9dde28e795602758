/*
 * Paper 004 (Hao, Liu, Belytschko 2004), Example B (Sect. 3.2, Figs. 5-6):
 *   u'' + g = 0 on [0, 1], u(0) = exp(-x0^2/alpha^2), u'(1) from the exact solution
 *   u = -x^3 + exp(-((x - x0)/alpha)^2), alpha = 0.02, x0 = 0.5 (eqs 29-33),
 * on uniform linear elements of spacing h = 0.1, 0.05, 0.02, 0.01, 0.005, 0.002, by
 *  - linear FEM (a tridiagonal system written out here), and
 *  - MPFEM through mfree: a LINE2 mesh over the particles, MFREE_METHOD_MPFEM with the
 *    cosine kernel of width d = 2h (support half width h), Bubnov-Galerkin Laplace form
 *    with the trial derivative of eq 21, ngauss Gauss points per element (default 3),
 *    u(0) imposed on the nodal value (Kronecker delta), UMFPACK through
 *    libmfree_suitesparse.
 * Errors: eq 34 (L2) and eq 35 (H1 semi-norm; MPFEM derivative by eq 22 as in the
 * paper), 10-point Gauss per half element. The reproduced values (docs/papers.md,
 * paper 004, reproduction) are the reference for --gauss 3.
 *
 * Usage: mfree_mpfem_1d [--json] [--out DIR] [--no-plot] [--gauss N]
 * Output: a table with rates (default) or one JSON object (--json)
 *   {"h":[...],"fem":{"L2":[...],"H1":[...]},"mpfem":{"L2":[...],"H1":[...]},
 *    "rates":{"fem":{"L2":[...],"H1":[...]},"mpfem":{"L2":[...],"H1":[...]}}}
 * (rates between successive spacings; the PNG's path goes to stderr). DIR/mpfem_1d_du.dat
 * holds u' of FEM, MPFEM (eq 22 and eq 21) and the exact solution at h = 0.02 (Fig. 5b),
 * DIR/mpfem_1d_rates.dat the errors per h; DIR/mpfem_1d.gp plots both to DIR/mpfem_1d.png
 * when gnuplot is on PATH (not --no-plot).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <mfree.h>
#include <mfree_suitesparse.h>

#include "util.h"

#define NH 6
static const double kH[NH] = {0.1, 0.05, 0.02, 0.01, 0.005, 0.002};
static const double ALPHA = 0.02, X0 = 0.5;
static const int PLOT_LEVEL = 2; /* h = 0.02 */

static double u_exact(double x) {
  const double s = (x - X0) / ALPHA;
  return -x * x * x + exp(-s * s);
}
static double du_exact(double x) {
  const double s = (x - X0) / ALPHA;
  return -3.0 * x * x - 2.0 * (x - X0) / (ALPHA * ALPHA) * exp(-s * s);
}
static double g_load(double x) { /* 004 eq 30 */
  const double s = (x - X0) / ALPHA, a2 = ALPHA * ALPHA, q = (2 * x - 2 * X0) / a2;
  return 6.0 * x + (2.0 / a2 - q * q) * exp(-s * s);
}
static void g_fn(void *user, const double *x, double *v) { (void)user; v[0] = g_load(x[0]); }
static void u_fn(void *user, const double *x, double *v) { (void)user; v[0] = u_exact(x[0]); }
static void t_fn(void *user, const double *x, double *v) { (void)user; v[0] = du_exact(x[0]); }

static mfree_context_t *ctx;

/* Stop on a failed call with mfree's message. */
#define CHECK(call) ex_check_exit(ctx, "mfree_mpfem_1d", (call), #call)
#define xmalloc(n) ex_xmalloc("mfree_mpfem_1d", (n))

/* Gauss-Legendre points on [-1, 1] from a one-element mesh's quadrature. */
static void gauss(int n, double *xg, double *wg) {
  const double x[2] = {-1.0, 1.0}, h = 1.0;
  const int32_t conn[2] = {0, 1};
  mfree_particles_t *ps = NULL;
  mfree_mesh_t *m = NULL;
  int32_t np = 0;
  CHECK(mfree_particles_create(ctx, 1, 2, &ps));
  CHECK(mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 1, MFREE_COPY));
  CHECK(mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  CHECK(mfree_mesh_create(ctx, ps, &m));
  CHECK(mfree_mesh_add_elements(m, MFREE_ELEMENT_LINE2, 1, conn, 0, MFREE_COPY));
  CHECK(mfree_mesh_get_quadrature(m, n, &np, xg, wg));
  mfree_mesh_destroy(&m);
  mfree_particles_destroy(&ps);
}

/* Error points: 10-point Gauss per half element. */
static int32_t error_points(int32_t n, double **xe, double **we) {
  double xg[10], wg[10];
  gauss(10, xg, wg);
  const int32_t ne = 2 * (n - 1), np = 10 * ne;
  *xe = xmalloc(sizeof(double) * (size_t)np);
  *we = xmalloc(sizeof(double) * (size_t)np);
  for (int32_t e = 0; e < ne; ++e)
    for (int g = 0; g < 10; ++g) {
      (*xe)[10 * e + g] = (e + 0.5 * (1.0 + xg[g])) / ne;
      (*we)[10 * e + g] = 0.5 * wg[g] / ne;
    }
  return np;
}

/* Linear FEM: returns L2 and H1 errors; du at the plot points when asked. */
static void fem(int32_t n, int ng, double *l2, double *h1, int32_t npl, const double *xpl, double *dupl) {
  const double h = 1.0 / (n - 1);
  double xg[10], wg[10];
  gauss(ng, xg, wg);
  double *f = calloc((size_t)n, sizeof(double)), *u = calloc((size_t)n, sizeof(double));
  double *d = xmalloc(sizeof(double) * (size_t)n);
  if (!f || !u) exit(1);
  for (int32_t e = 0; e + 1 < n; ++e)
    for (int g = 0; g < ng; ++g) {
      const double s = 0.5 * (1 + xg[g]), w = 0.5 * h * wg[g] * g_load((e + s) * h);
      f[e] += w * (1 - s);
      f[e + 1] += w * s;
    }
  f[n - 1] += du_exact(1.0);
  u[0] = u_exact(0.0);
  f[1] += u[0] / h;
  for (int32_t i = 1; i < n; ++i) d[i] = (i == n - 1 ? 1.0 : 2.0) / h;
  for (int32_t i = 2; i < n; ++i) { /* Thomas algorithm, off-diagonals -1/h */
    const double m = (-1.0 / h) / d[i - 1];
    d[i] -= m * (-1.0 / h);
    f[i] -= m * f[i - 1];
  }
  u[n - 1] = f[n - 1] / d[n - 1];
  for (int32_t i = n - 2; i >= 1; --i) u[i] = (f[i] + u[i + 1] / h) / d[i];
  double *xe, *we;
  const int32_t np = error_points(n, &xe, &we);
  double a = 0, b = 0;
  for (int32_t p = 0; p < np; ++p) {
    int32_t e = (int32_t)(xe[p] / h);
    if (e > n - 2) e = n - 2;
    const double s = xe[p] / h - e, uh = u[e] * (1 - s) + u[e + 1] * s, duh = (u[e + 1] - u[e]) / h;
    a += we[p] * (uh - u_exact(xe[p])) * (uh - u_exact(xe[p]));
    b += we[p] * (duh - du_exact(xe[p])) * (duh - du_exact(xe[p]));
  }
  *l2 = sqrt(a);
  *h1 = sqrt(b);
  for (int32_t p = 0; p < npl; ++p) {
    int32_t e = (int32_t)(xpl[p] / h);
    if (e > n - 2) e = n - 2;
    dupl[p] = (u[e + 1] - u[e]) / h;
  }
  free(xe), free(we), free(f), free(u), free(d);
}

/* MPFEM values and derivatives (deriv form) of the nodal vector u at points x. */
static void mpfem_eval(mfree_particles_t *ps, mfree_mesh_t *m, double hk, mfree_mpfem_deriv_t deriv, int32_t np,
                       const double *x, const double *u, double *v, double *du) {
  mfree_approximant_t *a = NULL;
  CHECK(mfree_approximant_create(ctx, ps, MFREE_METHOD_MPFEM, &a));
  CHECK(mfree_approximant_set_mesh(a, m));
  CHECK(mfree_approximant_set_kernel(a, MFREE_KERNEL_COSINE, 0.0));
  CHECK(mfree_approximant_set_mpfem(a, deriv, 8));
  CHECK(mfree_approximant_set_points(a, np, x, MFREE_LAYOUT_AOS, 1, &hk, 0, MFREE_COPY));
  CHECK(mfree_approximant_setup(a));
  if (v) CHECK(mfree_approximant_apply(a, MFREE_OP_VALUE, 1, u, MFREE_LAYOUT_AOS, 1, v, MFREE_LAYOUT_AOS, 1));
  CHECK(mfree_approximant_apply(a, MFREE_OP_GRADIENT, 1, u, MFREE_LAYOUT_AOS, 1, du, MFREE_LAYOUT_AOS, 1));
  mfree_approximant_destroy(&a);
}

static void mpfem(int32_t n, int ng, double *l2, double *h1, int32_t npl, const double *xpl, double *du22,
                  double *du21) {
  const double h = 1.0 / (n - 1), hk = h;
  double *x = xmalloc(sizeof(double) * (size_t)n), *f = xmalloc(sizeof(double) * (size_t)n),
         *u = xmalloc(sizeof(double) * (size_t)n);
  int32_t *conn = xmalloc(sizeof(int32_t) * 2 * (size_t)n);
  for (int32_t i = 0; i < n; ++i) x[i] = i * h;
  x[n - 1] = 1.0;
  for (int32_t e = 0; e + 1 < n; ++e) conn[2 * e] = e, conn[2 * e + 1] = e + 1;
  mfree_particles_t *ps = NULL;
  mfree_mesh_t *m = NULL;
  mfree_approximant_t *a = NULL;
  mfree_assembler_t *as = NULL;
  mfree_matrix_t *K = NULL;
  mfree_suitesparse_t *s = NULL;
  CHECK(mfree_particles_create(ctx, 1, n, &ps));
  CHECK(mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 1, MFREE_COPY));
  CHECK(mfree_particles_set_support(ps, &hk, 0, MFREE_COPY));
  CHECK(mfree_mesh_create(ctx, ps, &m));
  CHECK(mfree_mesh_add_elements(m, MFREE_ELEMENT_LINE2, n - 1, conn, 0, MFREE_COPY));
  CHECK(mfree_approximant_create(ctx, ps, MFREE_METHOD_MPFEM, &a));
  CHECK(mfree_approximant_set_mesh(a, m));
  CHECK(mfree_approximant_set_kernel(a, MFREE_KERNEL_COSINE, 0.0));
  CHECK(mfree_assembler_create(ctx, a, NULL, MFREE_FORM_LAPLACE, &as));
  int32_t nq = 0;
  CHECK(mfree_mesh_get_quadrature(m, ng, &nq, NULL, NULL));
  double *qx = xmalloc(sizeof(double) * (size_t)nq), *qw = xmalloc(sizeof(double) * (size_t)nq);
  CHECK(mfree_mesh_get_quadrature(m, ng, &nq, qx, qw));
  CHECK(mfree_assembler_set_quadrature_points(as, nq, qx, MFREE_LAYOUT_AOS, 1, qw));
  CHECK(mfree_assembler_set_body_force(as, g_fn, NULL));
  const double one = 1.0;
  const int32_t node0 = 0;
  CHECK(mfree_assembler_add_traction(as, 1, &one, MFREE_LAYOUT_AOS, 1, &one, t_fn, NULL));
  CHECK(mfree_assembler_add_dirichlet_nodes(as, 1, &node0, 1, u_fn, NULL));
  CHECK(mfree_assembler_setup(as));
  CHECK(mfree_assembler_assemble_matrix(as, &K));
  CHECK(mfree_assembler_assemble_rhs(as, f));
  CHECK(mfree_suitesparse_create(ctx, MFREE_SOLVER_UMFPACK, &s));
  CHECK(mfree_suitesparse_setup(s, K));
  CHECK(mfree_suitesparse_solve(s, 1, f, n, u, n));
  double *xe, *we;
  const int32_t np = error_points(n, &xe, &we);
  double *v = xmalloc(sizeof(double) * (size_t)np), *g = xmalloc(sizeof(double) * (size_t)np);
  mpfem_eval(ps, m, hk, MFREE_MPFEM_DERIV_ASSUMED_STRAIN, np, xe, u, v, g);
  double a2 = 0, b2 = 0;
  for (int32_t p = 0; p < np; ++p) {
    a2 += we[p] * (v[p] - u_exact(xe[p])) * (v[p] - u_exact(xe[p]));
    b2 += we[p] * (g[p] - du_exact(xe[p])) * (g[p] - du_exact(xe[p]));
  }
  *l2 = sqrt(a2);
  *h1 = sqrt(b2);
  if (npl > 0) {
    mpfem_eval(ps, m, hk, MFREE_MPFEM_DERIV_ASSUMED_STRAIN, npl, xpl, u, NULL, du22);
    mpfem_eval(ps, m, hk, MFREE_MPFEM_DERIV_FULL, npl, xpl, u, NULL, du21);
  }
  mfree_suitesparse_destroy(&s);
  mfree_matrix_destroy(&K);
  mfree_assembler_destroy(&as);
  mfree_approximant_destroy(&a);
  mfree_mesh_destroy(&m);
  mfree_particles_destroy(&ps);
  free(x), free(f), free(u), free(conn), free(qx), free(qw), free(xe), free(we), free(v), free(g);
}

static double rate(double e0, double e1, double h0, double h1) { return log(e0 / e1) / log(h0 / h1); }

static void json_array(const double *v, int n) {
  printf("[");
  for (int i = 0; i < n; ++i) printf("%s%.10g", i ? "," : "", v[i]);
  printf("]");
}

int main(int argc, char **argv) {
  int json = 0, plot = 1, ng = 3;
  const char *out = ".";
  for (int i = 1; i < argc; ++i) {
    if (strcmp(argv[i], "--json") == 0) json = 1;
    else if (strcmp(argv[i], "--no-plot") == 0) plot = 0;
    else if (strcmp(argv[i], "--out") == 0 && i + 1 < argc) out = argv[++i];
    else if (strcmp(argv[i], "--gauss") == 0 && i + 1 < argc) {
      ng = atoi(argv[++i]);
      if (ng < 1 || ng > 10) {
        fprintf(stderr, "error: --gauss takes 1..10\n");
        return 2;
      }
    } else {
      fprintf(stderr, "usage: mfree_mpfem_1d [--json] [--out DIR] [--no-plot] [--gauss N]\n");
      return 2;
    }
  }
  if (!ex_plot_path_ok(out)) {
    fprintf(stderr, "error: --out directory must not contain quotes\n");
    return 1;
  }
  if (mfree_context_create(&ctx) != MFREE_SUCCESS) return 1;
  double fl2[NH], fh1[NH], ml2[NH], mh1[NH];
  enum { NPL = 401 };
  double xpl[NPL], dfe[NPL], d22[NPL], d21[NPL];
  for (int p = 0; p < NPL; ++p) xpl[p] = (double)p / (NPL - 1);
  for (int i = 0; i < NH; ++i) {
    const int32_t n = (int32_t)lround(1.0 / kH[i]) + 1;
    const int pl = i == PLOT_LEVEL;
    fem(n, ng, &fl2[i], &fh1[i], pl ? NPL : 0, xpl, dfe);
    mpfem(n, ng, &ml2[i], &mh1[i], pl ? NPL : 0, xpl, d22, d21);
  }
  double rfl[NH - 1], rfh[NH - 1], rml[NH - 1], rmh[NH - 1];
  for (int i = 0; i + 1 < NH; ++i) {
    rfl[i] = rate(fl2[i], fl2[i + 1], kH[i], kH[i + 1]);
    rfh[i] = rate(fh1[i], fh1[i + 1], kH[i], kH[i + 1]);
    rml[i] = rate(ml2[i], ml2[i + 1], kH[i], kH[i + 1]);
    rmh[i] = rate(mh1[i], mh1[i + 1], kH[i], kH[i + 1]);
  }
  /* u' at h = 0.02 and the gnuplot script */
  char dat[4200], gp[4200], png[4200], rdat[4200];
  snprintf(rdat, sizeof rdat, "%s/mpfem_1d_rates.dat", out);
  FILE *r = fopen(rdat, "w");
  if (!r) {
    fprintf(stderr, "error: cannot write %s\n", rdat);
    mfree_context_destroy(&ctx);
    return 1;
  }
  fprintf(r, "# paper 004 Example B, %d Gauss points: h  FEM_L2  FEM_H1  MPFEM_L2  MPFEM_H1(eq 22)\n", ng);
  for (int i = 0; i < NH; ++i) fprintf(r, "%g %.10g %.10g %.10g %.10g\n", kH[i], fl2[i], fh1[i], ml2[i], mh1[i]);
  fclose(r);
  snprintf(dat, sizeof dat, "%s/mpfem_1d_du.dat", out);
  snprintf(gp, sizeof gp, "%s/mpfem_1d.gp", out);
  snprintf(png, sizeof png, "%s/mpfem_1d.png", out);
  FILE *f = fopen(dat, "w");
  FILE *g = f ? fopen(gp, "w") : NULL;
  if (!f || !g) {
    fprintf(stderr, "error: cannot write %s\n", f ? gp : dat);
    if (f) fclose(f);
    mfree_context_destroy(&ctx);
    return 1;
  }
  fprintf(f, "# paper 004 Example B, h = %g, %d Gauss points: x  u'_exact  u'_FEM  u'_MPFEM(eq 22)  u'_MPFEM(eq 21)\n",
          kH[PLOT_LEVEL], ng);
  for (int p = 0; p < NPL; ++p) fprintf(f, "%.6f %.10g %.10g %.10g %.10g\n", xpl[p], du_exact(xpl[p]), dfe[p], d22[p], d21[p]);
  fclose(f);
  fprintf(g, "# gnuplot script written by mfree_mpfem_1d (paper 004 Fig. 5b)\n"
             "set terminal pngcairo size 1500,600\nset output '%s'\nset multiplot layout 1,2\n"
             "set title \"Example B (Hao et al. 2004): u' at h = %g, FEM vs MPFEM\"\nset xlabel 'x'\nset ylabel \"u'\"\n"
             "set xrange [0.35:0.65]\nset key top left\n"
             "plot '%s' u 1:2 w l lw 2 t 'exact', '' u 1:3 w l t 'FEM (piecewise constant)', "
             "'' u 1:4 w l t 'MPFEM, eq 22', '' u 1:5 w l dt 2 t 'MPFEM, eq 21'\n"
             "set title 'Convergence: errors against h'\nset xlabel 'h'\nset ylabel 'error'\n"
             "set autoscale x\nset logscale xy\nset format y '10^{%%L}'\n"
             "plot '%s' u 1:2 w lp t 'FEM L2', '' u 1:3 w lp t 'FEM H1', '' u 1:4 w lp lw 2 t 'MPFEM L2', "
             "'' u 1:5 w lp lw 2 t 'MPFEM H1 (eq 22)'\nunset multiplot\n",
          png, kH[PLOT_LEVEL], dat, rdat);
  fclose(g);
  if (plot) ex_plot(gp, png, rdat, json ? stderr : stdout);
  if (json) {
    printf("{\"h\":");
    json_array(kH, NH);
    printf(",\"fem\":{\"L2\":");
    json_array(fl2, NH);
    printf(",\"H1\":");
    json_array(fh1, NH);
    printf("},\"mpfem\":{\"L2\":");
    json_array(ml2, NH);
    printf(",\"H1\":");
    json_array(mh1, NH);
    printf("},\"rates\":{\"fem\":{\"L2\":");
    json_array(rfl, NH - 1);
    printf(",\"H1\":");
    json_array(rfh, NH - 1);
    printf("},\"mpfem\":{\"L2\":");
    json_array(rml, NH - 1);
    printf(",\"H1\":");
    json_array(rmh, NH - 1);
    printf("}}}\n");
  } else {
    printf("Paper 004 Example B: u'' + g = 0, alpha = %g, x0 = %g; %d Gauss points per element\n", ALPHA, X0, ng);
    printf("MPFEM: cosine kernel, d = 2h, eq 21 stiffness; H1 semi-norm with eq 22 (paper)\n\n");
    printf("%-7s | %-11s %-11s %-6s %-6s | %-11s %-11s %-6s %-6s\n", "h", "FEM L2", "FEM H1", "rate", "rate",
           "MPFEM L2", "MPFEM H1", "rate", "rate");
    for (int i = 0; i < NH; ++i) {
      printf("%-7g | %.4e  %.4e  ", kH[i], fl2[i], fh1[i]);
      if (i) printf("%6.2f %6.2f | ", rfl[i - 1], rfh[i - 1]);
      else printf("%6s %6s | ", "-", "-");
      printf("%.4e  %.4e  ", ml2[i], mh1[i]);
      if (i) printf("%6.2f %6.2f\n", rml[i - 1], rmh[i - 1]);
      else printf("%6s %6s\n", "-", "-");
    }
    printf("\nu' at h = %g: %s; errors: %s\n", kH[PLOT_LEVEL], dat, rdat);
  }
  mfree_context_destroy(&ctx);
  return 0;
}
