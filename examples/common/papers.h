/* Shared helpers for the paper-reproduction examples (papers 000 and 001).
 *
 * Paper 001 (Zhang & Batra, Comput Mech 43 (2009) 321-340), Sect. 6, with the choices of
 * docs/papers.md, paper 001, choices 1 and 2: N particles at the cell centres
 * x_i = (i - 1/2)/N of [0, 1] (the only layout that reproduces Table 1), volumes
 * Delta = 1/N, support h = hfac * Delta, kernel support 2h (gather), estimates at the
 * particles, error norms by the midpoint rule ||e||_k = sqrt(Delta * sum_i e_i^2). */
#ifndef MFREE_EXAMPLES_PAPERS_H
#define MFREE_EXAMPLES_PAPERS_H

#include <stdio.h>

#include <mfree.h>

/* A test function: f, f_x, f_xx at x. */
typedef void (*papers_fn_t)(double x, double out[3]);

/* 001 eq 6.1: f = sin(8(1 - x)) / sin 8. */
void papers_sine(double x, double out[3]);
/* 001 Sect. 6.2: f = exp(-x^2). */
void papers_gauss(double x, double out[3]);

/* One 1D experiment: method (order), kernel (param, 0 = default), N particles,
 * h = hfac / N. nderiv = 1 (values and first derivatives) or 2 (also second
 * derivatives). norms[0..nderiv] receive ||e||_0, ||e||_1 (and ||e||_2). Returns the
 * first failing mfree status (its message is on ctx) or MFREE_SUCCESS. */
mfree_status_t papers_norms_1d(mfree_context_t *ctx, mfree_method_t method, int order,
                               mfree_kernel_t kernel, double kparam, int n, double hfac,
                               papers_fn_t fn, int nderiv, double *norms);

/* Least-squares slope of y against x (n >= 2 points). */
double papers_slope(int n, const double *x, const double *y);

/* Rate of convergence: slope of ln e against ln(1/N) over the given N. */
double papers_rate(int nn, const int *N, const double *e);

/* Print ctx's last error for a failed call, prefixed with what; returns 1. */
int papers_report(mfree_context_t *ctx, mfree_status_t st, const char *what);

/* Options every example understands: --json, --help (prints usage, exits 0). Returns 0
 * on success, 2 on a bad option (after printing usage to stderr). Other options go to
 * extra when it is non-NULL: extra(argc, argv, &i, user) returns 1 if it consumed
 * argv[i] (advancing i past any value it took), 0 if the option is unknown or invalid. */
typedef int (*papers_opt_t)(int argc, char **argv, int *i, void *user);
int papers_parse(int argc, char **argv, const char *usage, int *json, papers_opt_t extra,
                 void *user);

#endif
