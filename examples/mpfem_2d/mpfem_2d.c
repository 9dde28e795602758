/*
 * MPFEM in 2D (paper 004 Sect. 4.2) on a Poisson problem: -lap u = f on the unit
 * square, u = g on the boundary, exact u = sin(pi x) sin(pi y) + x y / 2, structured
 * meshes of n x n cells (n = 8, 16, 32) of QUAD4 or TRI3 (two per cell).
 *  - MPFEM: MFREE_METHOD_MPFEM, cosine tensor kernel; support square of side 2h on QUAD4
 *    and h on TRI3 (the largest sides 004 eq 13 allows on these meshes); Galerkin
 *    Laplace form with eq 21 derivatives, Gauss points per element from
 *    mfree_mesh_get_quadrature: 3 x 3 on QUAD4 (the kinks of the weights lie on the
 *    element edges there) and 5 x 5 on TRI3 (the square support's edges cross the
 *    triangles, and a 3 x 3 rule's error stalls the L2 rate: 1.44 at n = 32 -> 64,
 *    test t475); boundary nodal values imposed directly, UMFPACK.
 *  - FEM: the same program with a support of 1e-6 h, where MPFEM reduces to FEM at the
 *    Gauss points (004 Sect. 2.2).
 * Errors: L2 and the H1 semi-norm (MPFEM gradient by eq 21 and by eq 22), 5 x 5 Gauss.
 *
 * Usage: mfree_mpfem_2d [--json] [--out DIR] [--no-plot]; DIR/mpfem_2d.dat holds the errors
 * and DIR/mpfem_2d.png plots them (gnuplot on PATH).
 * Output: a table with rates, or one JSON object
 *   {"n":[...],"quad4":{"fem":{"L2":[...],"H1":[...]},"mpfem":{"L2":[...],"H1":[...],
 *    "H1_22":[...]}},"tri3":{...}}
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <mfree.h>
#include <mfree_suitesparse.h>

#include "util.h"

#define NL 3
static const int32_t kN[NL] = {8, 16, 32};
static const double PI = 3.14159265358979323846;
static mfree_context_t *ctx;

#define CHECK(call) ex_check_exit(ctx, "mfree_mpfem_2d", (call), #call)
#define xmalloc(n) ex_xmalloc("mfree_mpfem_2d", (n))

static double u_exact(const double *x) { return sin(PI * x[0]) * sin(PI * x[1]) + 0.5 * x[0] * x[1]; }
static void du_exact(const double *x, double *g) {
  g[0] = PI * cos(PI * x[0]) * sin(PI * x[1]) + 0.5 * x[1];
  g[1] = PI * sin(PI * x[0]) * cos(PI * x[1]) + 0.5 * x[0];
}
static void f_fn(void *user, const double *x, double *v) {
  (void)user;
  v[0] = 2.0 * PI * PI * sin(PI * x[0]) * sin(PI * x[1]);
}
static void g_fn(void *user, const double *x, double *v) { (void)user; v[0] = u_exact(x); }

typedef struct {
  double L2, H1, H1_22;
} err_t;

/* Gradient (deriv form) and optionally values of nodal vector u at points. */
static void eval(mfree_particles_t *ps, mfree_mesh_t *m, double hk, mfree_mpfem_deriv_t deriv, int32_t np,
                 const double *x, const double *u, double *v, double *g) {
  mfree_approximant_t *a = NULL;
  CHECK(mfree_approximant_create(ctx, ps, MFREE_METHOD_MPFEM, &a));
  CHECK(mfree_approximant_set_mesh(a, m));
  CHECK(mfree_approximant_set_mpfem(a, deriv, 8));
  CHECK(mfree_approximant_set_points(a, np, x, MFREE_LAYOUT_AOS, 2, &hk, 0, MFREE_COPY));
  CHECK(mfree_approximant_setup(a));
  if (v) CHECK(mfree_approximant_apply(a, MFREE_OP_VALUE, 1, u, MFREE_LAYOUT_AOS, 1, v, MFREE_LAYOUT_AOS, 1));
  CHECK(mfree_approximant_apply(a, MFREE_OP_GRADIENT, 1, u, MFREE_LAYOUT_AOS, 1, g, MFREE_LAYOUT_AOS, 2));
  mfree_approximant_destroy(&a);
}

static void solve(int32_t n, int tri, double hk_rel, err_t *err) {
  const int32_t nn = (n + 1) * (n + 1), ne = tri ? 2 * n * n : n * n;
  const double h = 1.0 / n, hk = hk_rel * h;
  double *x = xmalloc(sizeof(double) * 2 * (size_t)nn);
  int32_t *conn = xmalloc(sizeof(int32_t) * 6 * (size_t)n * (size_t)n), *bn = xmalloc(sizeof(int32_t) * 4 * (size_t)(n + 1));
  int32_t nb = 0;
  for (int32_t j = 0; j <= n; ++j)
    for (int32_t i = 0; i <= n; ++i) {
      const int32_t p = j * (n + 1) + i;
      x[2 * p] = i == n ? 1.0 : i * h;
      x[2 * p + 1] = j == n ? 1.0 : j * h;
      if (i == 0 || j == 0 || i == n || j == n) bn[nb++] = p;
    }
  for (int32_t j = 0; j < n; ++j)
    for (int32_t i = 0; i < n; ++i) {
      const int32_t n0 = j * (n + 1) + i, c = j * n + i;
      if (tri) {
        const int32_t t[6] = {n0, n0 + 1, n0 + n + 2, n0, n0 + n + 2, n0 + n + 1};
        memcpy(&conn[6 * c], t, sizeof t);
      } else {
        const int32_t q[4] = {n0, n0 + 1, n0 + n + 2, n0 + n + 1};
        memcpy(&conn[4 * c], q, sizeof q);
      }
    }
  mfree_particles_t *ps = NULL;
  mfree_mesh_t *m = NULL;
  mfree_approximant_t *a = NULL;
  mfree_assembler_t *as = NULL;
  mfree_matrix_t *K = NULL;
  mfree_suitesparse_t *s = NULL;
  CHECK(mfree_particles_create(ctx, 2, nn, &ps));
  CHECK(mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 2, MFREE_COPY));
  CHECK(mfree_particles_set_support(ps, &hk, 0, MFREE_COPY));
  CHECK(mfree_mesh_create(ctx, ps, &m));
  CHECK(mfree_mesh_add_elements(m, tri ? MFREE_ELEMENT_TRI3 : MFREE_ELEMENT_QUAD4, ne, conn, 0, MFREE_COPY));
  CHECK(mfree_approximant_create(ctx, ps, MFREE_METHOD_MPFEM, &a));
  CHECK(mfree_approximant_set_mesh(a, m));
  CHECK(mfree_assembler_create(ctx, a, NULL, MFREE_FORM_LAPLACE, &as));
  int32_t nq = 0;
  const int32_t ngauss = tri ? 5 : 3;
  CHECK(mfree_mesh_get_quadrature(m, ngauss, &nq, NULL, NULL));
  double *qx = xmalloc(sizeof(double) * 2 * (size_t)nq), *qw = xmalloc(sizeof(double) * (size_t)nq);
  CHECK(mfree_mesh_get_quadrature(m, ngauss, &nq, qx, qw));
  CHECK(mfree_assembler_set_quadrature_points(as, nq, qx, MFREE_LAYOUT_AOS, 2, qw));
  CHECK(mfree_assembler_set_body_force(as, f_fn, NULL));
  CHECK(mfree_assembler_add_dirichlet_nodes(as, nb, bn, 1, g_fn, NULL));
  CHECK(mfree_assembler_setup(as));
  CHECK(mfree_assembler_assemble_matrix(as, &K));
  double *f = xmalloc(sizeof(double) * (size_t)nn), *u = xmalloc(sizeof(double) * (size_t)nn);
  CHECK(mfree_assembler_assemble_rhs(as, f));
  CHECK(mfree_suitesparse_create(ctx, MFREE_SOLVER_UMFPACK, &s));
  CHECK(mfree_suitesparse_setup(s, K));
  CHECK(mfree_suitesparse_solve(s, 1, f, nn, u, nn));
  int32_t np = 0;
  CHECK(mfree_mesh_get_quadrature(m, 5, &np, NULL, NULL));
  double *ex = xmalloc(sizeof(double) * 2 * (size_t)np), *ew = xmalloc(sizeof(double) * (size_t)np);
  double *v = xmalloc(sizeof(double) * (size_t)np), *g = xmalloc(sizeof(double) * 2 * (size_t)np),
         *g22 = xmalloc(sizeof(double) * 2 * (size_t)np);
  CHECK(mfree_mesh_get_quadrature(m, 5, &np, ex, ew));
  eval(ps, m, hk, MFREE_MPFEM_DERIV_FULL, np, ex, u, v, g);
  eval(ps, m, hk, MFREE_MPFEM_DERIV_ASSUMED_STRAIN, np, ex, u, NULL, g22);
  double l2 = 0, h1 = 0, h22 = 0;
  for (int32_t p = 0; p < np; ++p) {
    double gx[2];
    du_exact(&ex[2 * p], gx);
    l2 += ew[p] * (v[p] - u_exact(&ex[2 * p])) * (v[p] - u_exact(&ex[2 * p]));
    for (int c = 0; c < 2; ++c) {
      h1 += ew[p] * (g[2 * p + c] - gx[c]) * (g[2 * p + c] - gx[c]);
      h22 += ew[p] * (g22[2 * p + c] - gx[c]) * (g22[2 * p + c] - gx[c]);
    }
  }
  err->L2 = sqrt(l2);
  err->H1 = sqrt(h1);
  err->H1_22 = sqrt(h22);
  mfree_suitesparse_destroy(&s);
  mfree_matrix_destroy(&K);
  mfree_assembler_destroy(&as);
  mfree_approximant_destroy(&a);
  mfree_mesh_destroy(&m);
  mfree_particles_destroy(&ps);
  free(x), free(conn), free(bn), free(qx), free(qw), free(f), free(u), free(ex), free(ew), free(v), free(g), free(g22);
}

static void json_array(const err_t *e, int which) {
  printf("[");
  for (int i = 0; i < NL; ++i) printf("%s%.10g", i ? "," : "", which == 0 ? e[i].L2 : which == 1 ? e[i].H1 : e[i].H1_22);
  printf("]");
}

static double rate(double a, double b) { return log(a / b) / log(2.0); }

/* The errors per mesh as DIR/mpfem_2d.dat (n, 1/n, then per element type FEM L2, H1 and
 * MPFEM L2, H1 (eq 21), H1 (eq 22)) and a log-log plot of them. Returns 0, or 1 when a
 * file cannot be written. */
static int plot_rates(const char *out, int plot, err_t fe[2][NL], err_t mp[2][NL], FILE *msg) {
  char dat[4200], gp[4200], png[4200];
  ex_join(dat, sizeof dat, out, "mpfem_2d.dat");
  ex_join(gp, sizeof gp, out, "mpfem_2d.gp");
  ex_join(png, sizeof png, out, "mpfem_2d.png");
  FILE *f = ex_plot_path_ok(dat) ? fopen(dat, "w") : NULL;
  FILE *g = f ? fopen(gp, "w") : NULL;
  if (!f || !g) {
    fprintf(stderr, "error: cannot write %s\n", f ? gp : dat);
    if (f) fclose(f);
    return 1;
  }
  fprintf(f, "# MPFEM 2D Poisson: n 1/n, then QUAD4 and TRI3: FEM_L2 FEM_H1 MPFEM_L2 MPFEM_H1(21) MPFEM_H1(22)\n");
  for (int i = 0; i < NL; ++i) {
    fprintf(f, "%d %.6e", kN[i], 1.0 / kN[i]);
    for (int t = 0; t < 2; ++t)
      fprintf(f, " %.6e %.6e %.6e %.6e %.6e", fe[t][i].L2, fe[t][i].H1, mp[t][i].L2, mp[t][i].H1, mp[t][i].H1_22);
    fprintf(f, "\n");
  }
  fclose(f);
  fprintf(g, "# gnuplot script written by mfree_mpfem_2d\n"
             "set terminal pngcairo size 1400,560\nset output '%s'\nset multiplot layout 1,2 "
             "title 'MPFEM (Hao, Liu and Belytschko 2004) and FEM on -lap u = f: errors against 1/n'\n"
             "set logscale xy\nset format y '10^{%%L}'\nset xlabel '1/n'\nset ylabel 'error'\n"
             "set key bottom right\nset grid\n", png);
  static const char *const mesh[2] = {"QUAD4", "TRI3"};
  for (int t = 0; t < 2; ++t) {
    const int c = 3 + 5 * t;
    fprintf(g, "set title '%s'\nplot '%s' u 2:%d w lp t 'FEM L2', '' u 2:%d w lp t 'FEM H1', "
               "'' u 2:%d w lp lw 2 t 'MPFEM L2', '' u 2:%d w lp lw 2 t 'MPFEM H1 (eq 21)', "
               "'' u 2:%d w lp dt 2 t 'MPFEM H1 (eq 22)'\n",
            mesh[t], dat, c, c + 1, c + 2, c + 3, c + 4);
  }
  fprintf(g, "unset multiplot\n");
  fclose(g);
  if (plot) ex_plot(gp, png, dat, msg);
  return 0;
}

int main(int argc, char **argv) {
  int json = 0, plot = 1;
  const char *out = ".";
  for (int i = 1; i < argc; ++i) {
    if (strcmp(argv[i], "--json") == 0) json = 1;
    else if (strcmp(argv[i], "--no-plot") == 0) plot = 0;
    else if (strcmp(argv[i], "--out") == 0 && i + 1 < argc) out = argv[++i];
    else {
      fprintf(stderr, "usage: mfree_mpfem_2d [--json] [--out DIR] [--no-plot]\n");
      return 2;
    }
  }
  if (mfree_context_create(&ctx) != MFREE_SUCCESS) return 1;
  err_t fe[2][NL], mp[2][NL];
  const double hk[2] = {1.0, 0.5};
  for (int t = 0; t < 2; ++t)
    for (int i = 0; i < NL; ++i) {
      solve(kN[i], t, 1e-6, &fe[t][i]);
      solve(kN[i], t, hk[t], &mp[t][i]);
    }
  const char *name[2] = {"quad4", "tri3"};
  if (plot_rates(out, plot, fe, mp, json ? stderr : stdout)) return 1;
  if (json) {
    printf("{\"n\":[%d,%d,%d]", kN[0], kN[1], kN[2]);
    for (int t = 0; t < 2; ++t) {
      printf(",\"%s\":{\"fem\":{\"L2\":", name[t]);
      json_array(fe[t], 0);
      printf(",\"H1\":");
      json_array(fe[t], 1);
      printf("},\"mpfem\":{\"L2\":");
      json_array(mp[t], 0);
      printf(",\"H1\":");
      json_array(mp[t], 1);
      printf(",\"H1_22\":");
      json_array(mp[t], 2);
      printf("}}");
    }
    printf("}\n");
  } else {
    printf("MPFEM in 2D: -lap u = f on the unit square, u = sin(pi x) sin(pi y) + x y / 2\n");
    for (int t = 0; t < 2; ++t) {
      printf("\n%s (support side %gh)  | FEM L2      H1         | MPFEM L2    H1(21)      H1(22)\n",
             t ? "TRI3 " : "QUAD4", 2 * hk[t]);
      for (int i = 0; i < NL; ++i)
        printf("  n = %2d                 | %.4e  %.4e | %.4e  %.4e  %.4e\n", kN[i], fe[t][i].L2, fe[t][i].H1,
               mp[t][i].L2, mp[t][i].H1, mp[t][i].H1_22);
      printf("  rates (n = %d -> %d)   | %10.3f  %10.3f | %10.3f  %10.3f  %10.3f\n", kN[NL - 2], kN[NL - 1],
             rate(fe[t][NL - 2].L2, fe[t][NL - 1].L2), rate(fe[t][NL - 2].H1, fe[t][NL - 1].H1),
             rate(mp[t][NL - 2].L2, mp[t][NL - 1].L2), rate(mp[t][NL - 2].H1, mp[t][NL - 1].H1),
             rate(mp[t][NL - 2].H1_22, mp[t][NL - 1].H1_22));
    }
  }
  mfree_context_destroy(&ctx);
  return 0;
}
