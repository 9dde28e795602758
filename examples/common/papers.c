#include "papers.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void papers_sine(double x, double out[3]) {
  const double s8 = sin(8.0);
  out[0] = sin(8.0 * (1.0 - x)) / s8;
  out[1] = -8.0 * cos(8.0 * (1.0 - x)) / s8;
  out[2] = -64.0 * sin(8.0 * (1.0 - x)) / s8;
}

void papers_gauss(double x, double out[3]) {
  const double e = exp(-x * x);
  out[0] = e;
  out[1] = -2.0 * x * e;
  out[2] = (4.0 * x * x - 2.0) * e;
}

#define TRY(call)                         \
  do {                                    \
    st = (call);                          \
    if (st != MFREE_SUCCESS) goto done;   \
  } while (0)

mfree_status_t papers_norms_1d(mfree_context_t *ctx, mfree_method_t method, int order,
                               mfree_kernel_t kernel, double kparam, int n, double hfac,
                               papers_fn_t fn, int nderiv, double *norms) {
  mfree_status_t st = MFREE_SUCCESS;
  mfree_particles_t *ps = NULL;
  mfree_approximant_t *a = NULL;
  const double delta = 1.0 / n, h = hfac * delta;
  double *x = malloc(sizeof(double) * (size_t)n);
  double *f = malloc(sizeof(double) * (size_t)n * 3);  /* exact f, f_x, f_xx */
  double *est = malloc(sizeof(double) * (size_t)n);
  if (!x || !f || !est) {
    st = MFREE_ERR_ALLOC;
    goto done;
  }
  for (int i = 0; i < n; ++i) {
    x[i] = (i + 0.5) * delta;
    fn(x[i], f + 3 * i);
  }
  double radius = 0.0;
  TRY(mfree_kernel_get_support_radius(ctx, kernel, kparam, &radius));
  TRY(mfree_particles_create(ctx, 1, n, &ps));
  TRY(mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 1, MFREE_COPY));
  TRY(mfree_particles_set_volumes(ps, &delta, 0, MFREE_COPY));
  TRY(mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  TRY(mfree_particles_set_search(ps, MFREE_SEARCH_GATHER, radius));
  TRY(mfree_approximant_create(ctx, ps, method, &a));
  TRY(mfree_approximant_set_kernel(a, kernel, kparam));
  TRY(mfree_approximant_set_order(a, order));
  TRY(mfree_approximant_set_derivatives(
      a, MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT | (nderiv >= 2 ? MFREE_DERIV_HESSIAN : 0)));
  TRY(mfree_approximant_setup(a));
  static const mfree_op_t ops[3] = {MFREE_OP_VALUE, MFREE_OP_GRADIENT, MFREE_OP_HESSIAN};
  for (int k = 0; k <= nderiv; ++k) {
    /* in 1D every operator has one output component per input component */
    TRY(mfree_approximant_apply(a, ops[k], 1, f, MFREE_LAYOUT_AOS, 3, est, MFREE_LAYOUT_AOS, 1));
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
      const double e = est[i] - f[3 * i + k];
      sum += e * e;
    }
    norms[k] = sqrt(delta * sum);
  }
done:
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
  free(x);
  free(f);
  free(est);
  return st;
}

double papers_slope(int n, const double *x, const double *y) {
  double mx = 0.0, my = 0.0;
  for (int i = 0; i < n; ++i) {
    mx += x[i];
    my += y[i];
  }
  mx /= n;
  my /= n;
  double sxy = 0.0, sxx = 0.0;
  for (int i = 0; i < n; ++i) {
    sxy += (x[i] - mx) * (y[i] - my);
    sxx += (x[i] - mx) * (x[i] - mx);
  }
  return sxy / sxx;
}

double papers_rate(int nn, const int *N, const double *e) {
  double lx[32], ly[32];
  if (nn > 32) nn = 32;
  for (int i = 0; i < nn; ++i) {
    lx[i] = log(1.0 / N[i]);
    ly[i] = log(e[i]);
  }
  return papers_slope(nn, lx, ly);
}

int papers_report(mfree_context_t *ctx, mfree_status_t st, const char *what) {
  char msg[1024] = "";
  if (ctx) mfree_context_get_last_error(ctx, NULL, msg, sizeof msg);
  fprintf(stderr, "error: %s: %s (%d)%s%s\n", what, mfree_status_string(st), (int)st,
          msg[0] ? ": " : "", msg);
  return 1;
}

int papers_parse(int argc, char **argv, const char *usage, int *json, papers_opt_t extra,
                 void *user) {
  *json = 0;
  for (int i = 1; i < argc; ++i) {
    if (strcmp(argv[i], "--json") == 0) {
      *json = 1;
    } else if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
      printf("%s", usage);
      exit(0);
    } else if (!(extra && extra(argc, argv, &i, user))) {
      fprintf(stderr, "%s: unknown or incomplete option '%s'\n%s", argv[0], argv[i], usage);
      return 2;
    }
  }
  return 0;
}
