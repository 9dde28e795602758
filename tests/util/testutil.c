#include "testutil.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void mfree_test_expect_error(mfree_context_t *ctx, mfree_status_t got, mfree_status_t expected,
                             const char *needle, const char *what) {
  char msg[1024] = "";
  mfree_status_t code = MFREE_SUCCESS;
  if (ctx) mfree_context_get_last_error(ctx, &code, msg, sizeof msg);
  if (got != expected)
    fail_msg("%s returned %d (%s), expected %d; last error: %s", what, (int)got,
             mfree_status_string(got), (int)expected, msg);
  if (ctx) {
    if (code != expected) fail_msg("%s: context code %d, expected %d", what, (int)code, (int)expected);
    if (msg[0] == '\0') fail_msg("%s: empty message on the context", what);
    if (needle && !strstr(msg, needle))
      fail_msg("%s: message \"%s\" does not mention \"%s\"", what, msg, needle);
  }
}

void mfree_rng_seed(mfree_rng_t *r, uint64_t seed) { r->s = seed * 2654435761u + 88172645463325252ull; }

double mfree_rng_uniform(mfree_rng_t *r) {
  r->s ^= r->s >> 12;
  r->s ^= r->s << 25;
  r->s ^= r->s >> 27;
  return (double)((r->s * 2685821657736338717ull) >> 11) * (1.0 / 9007199254740992.0);
}

void mfree_test_lumped_masses(mfree_context_t *ctx, mfree_system_t *sys, const double *y, int dim, int n,
                              double *Mi) {
  mfree_matrix_t *M = NULL;
  assert_ok(ctx, mfree_system_assemble_mass(sys, y, 0, &M));
  const int64_t *rp;
  const int32_t *ci;
  const double *mv;
  assert_ok(ctx, mfree_matrix_get_csr(M, &rp, &ci, &mv));
  const int64_t vel = (int64_t)dim * n, rho = 2 * vel;
  for (int64_t row = 0; row < rho + n; ++row) { /* state: x (dim n), v (dim n), rho (n) */
    assert_int_equal(rp[row + 1] - rp[row], 1);
    assert_int_equal(ci[rp[row]], row);
    if (row < vel || row >= rho) assert_true(mv[rp[row]] == 1.0);
  }
  for (int q = 0; q < n; ++q) {
    Mi[q] = mv[rp[vel + (int64_t)dim * q]];
    for (int c = 1; c < dim; ++c) assert_true(mv[rp[vel + (int64_t)dim * q + c]] == Mi[q]);
  }
  mfree_matrix_destroy(&M);
}

double mfree_test_lumped_mass_rel_diff(mfree_context_t *ctx, mfree_system_t *sys, const double *y,
                                       const double *m, int n) {
  double *Mi = malloc(sizeof(double) * (size_t)n), total = 0.0, lumped = 0.0;
  assert_non_null(Mi);
  mfree_test_lumped_masses(ctx, sys, y, 2, n, Mi);
  for (int q = 0; q < n; ++q) {
    total += m[q];
    lumped += Mi[q];
  }
  free(Mi);
  return fabs(lumped - total) / total;
}

int mfree_test_tank_walls(double L, double d, double off, double top, double **x, double **normals) {
  const double ws = d / 3.0;
  const int nb = (int)ceil((L + 2 * off) / ws) + 1, ns = (int)ceil((top + off) / ws), nw = nb + 2 * ns;
  double *wx = malloc(2 * (size_t)nw * sizeof *wx), *wn = malloc(2 * (size_t)nw * sizeof *wn);
  assert_non_null(wx);
  assert_non_null(wn);
  int k = 0;
  for (int q = 0; q < nb; ++q, ++k) {
    wx[2 * k] = -off + q * (L + 2 * off) / (nb - 1), wx[2 * k + 1] = -off;
    wn[2 * k] = 0.0, wn[2 * k + 1] = 1.0;
  }
  for (int q = 1; q <= ns; ++q)
    for (int side = 0; side < 2; ++side, ++k) {
      wx[2 * k] = side ? L + off : -off, wx[2 * k + 1] = -off + q * (top + off) / ns;
      wn[2 * k] = side ? -1.0 : 1.0, wn[2 * k + 1] = 0.0;
    }
  *x = wx;
  *normals = wn;
  return nw;
}

mfree_system_t *mfree_test_fluid_create(mfree_context_t *ctx, int n, const double *m, double rho0, double kappa,
                                        double gamma, double mu, double h) {
  mfree_system_t *sys = NULL;
  assert_ok(ctx, mfree_system_create_fluid(ctx, 2, n, &sys));
  assert_ok(ctx, mfree_system_set_fluid(sys, &rho0, 0, kappa, gamma, mu));
  assert_ok(ctx, mfree_system_set_masses(sys, m, 1));
  assert_ok(ctx, mfree_system_set_smoothing(sys, h));
  return sys;
}

void mfree_test_fluid_approximant(mfree_context_t *ctx, int dim, int n, const double *y, double h,
                                  const double *vol, mfree_particles_t **ps, mfree_approximant_t **a) {
  assert_ok(ctx, mfree_particles_create(ctx, dim, n, ps));
  assert_ok(ctx, mfree_particles_set_positions(*ps, y, MFREE_LAYOUT_AOS, dim, MFREE_COPY));
  if (vol) assert_ok(ctx, mfree_particles_set_volumes(*ps, vol, 1, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_support(*ps, &h, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_setup(*ps));
  assert_ok(ctx, mfree_approximant_create(ctx, *ps, MFREE_METHOD_MLS, a));
  assert_ok(ctx, mfree_approximant_set_kernel(*a, MFREE_KERNEL_CUBIC_SPLINE, 0.0));
  assert_ok(ctx, mfree_approximant_set_order(*a, 1));
  assert_ok(ctx, mfree_approximant_set_fallback(*a, MFREE_FALLBACK_LOWER_ORDER));
  assert_ok(ctx, mfree_approximant_setup(*a));
}

int32_t mfree_test_backend(int argc, char **argv) {
  return argc > 1 && strcmp(argv[1], "ref") == 0 ? MFREE_BACKEND_REF : MFREE_BACKEND_OPT;
}

mfree_test_bar_t mfree_test_bar_create(mfree_context_t *ctx, int n, double L, double E, double rho, double *x,
                                       mfree_field_fn traction, mfree_history_fn history) {
  mfree_test_bar_t b;
  const double dx = L / (n - 1), h = 1.5 * dx, vol = dx;
  for (int i = 0; i < n; ++i) x[i] = i * dx;
  assert_ok(ctx, mfree_particles_create(ctx, 1, n, &b.ps));
  assert_ok(ctx, mfree_particles_set_positions(b.ps, x, MFREE_LAYOUT_AOS, 1, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_support(b.ps, &h, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_volumes(b.ps, &vol, 0, MFREE_COPY));
  assert_ok(ctx, mfree_approximant_create(ctx, b.ps, MFREE_METHOD_SSPH, &b.a));
  assert_ok(ctx, mfree_approximant_set_kernel(b.a, MFREE_KERNEL_REVISED_SUPER_GAUSS, 1.6));
  assert_ok(ctx, mfree_approximant_set_order(b.a, 2));
  assert_ok(ctx, mfree_approximant_set_derivatives(b.a, 7));
  assert_ok(ctx, mfree_assembler_create(ctx, b.a, NULL, MFREE_FORM_COLLOCATION_LAPLACE, &b.as));
  assert_ok(ctx, mfree_assembler_set_coefficient(b.as, E));
  const int32_t ends[2] = {0, n - 1};
  const double normals[2] = {-1.0, 1.0};
  assert_ok(ctx, mfree_assembler_add_traction_nodes(b.as, 2, ends, normals, traction, NULL));
  assert_ok(ctx, mfree_assembler_setup(b.as));
  assert_ok(ctx, mfree_system_create_elastodynamic(ctx, b.as, rho, &b.sys));
  assert_ok(ctx, mfree_system_set_load_history(b.sys, history, NULL));
  return b;
}

void mfree_test_bar_destroy(mfree_test_bar_t *b) {
  mfree_system_destroy(&b->sys);
  mfree_assembler_destroy(&b->as);
  mfree_approximant_destroy(&b->a);
  mfree_particles_destroy(&b->ps);
}
