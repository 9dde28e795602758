/* The walls' force on the fluid (mfree_system_get_wall_force) of the Galerkin-SPH fluid of
 * paper 003 with the wall particles of eqs 122-124.
 *
 * 1. Momentum balance, step by step: a block of water 0.06 m square (12 x 12 particles,
 *    d = 5 mm, h = 1.5 d, rho0 = 1000, gamma = 7, kappa of eq 125, mu = 0.5) thrown at
 *    (-0.4, -0.8) m/s into the corner of a tank (floor and side walls at spacing d/3 set
 *    back by d/2, r0 = 0.7 h, A = 10), gravity -9.81. Each leap-frog step of length dt
 *    from state y changes the momentum sum_i m_i v_i, with m_i the lumped masses at y
 *    (assembled independently by mfree_system_assemble_mass), by dt (M g + F), F the
 *    total wall force at y: checked to 1e-9 of dt M g at every step of 400, with the
 *    Galerkin lumped masses (003 eq 56) and with physical lumping (m_i the particle
 *    masses, eq 58). The per-wall-particle forces sum to the total to 1e-12 (no dummy
 *    particles): two computations of the same force (the total from the accelerations,
 *    the shares from the wall pairs). The walls must act in at least 100 of the steps.
 * 2. Still column (the setting of t702 test 2: 30 x 10 particles, H = 0.1 m, mu = 50,
 *    CFL 0.2): averaged over 0.1 <= t <= 0.3 s, the floor carries the column's weight and
 *    each side wall the hydrostatic thrust rho0 g H^2 / 2 (per unit depth), the wall
 *    force being sampled at every step (the one-sided force of eq 123 acts in bursts). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"

static mfree_context_t *ctx;
static int setup(void **s) { (void)s; return mfree_context_create(&ctx) != MFREE_SUCCESS; }
static int teardown(void **s) { (void)s; return mfree_context_destroy(&ctx) != MFREE_SUCCESS; }

static const double RHO0 = 1000.0, G = 9.81, GAMMA = 7.0;

/* Walls of a tank [0, W] x [0, top]: floor, then left and right walls, set back by off, at
 * spacing d/3; side[k] = 0 floor, 1 left, 2 right. Returns the count. */
static int tank_walls(double W, double top, double d, double **wx, double **wn, int **side) {
  const double off = 0.5 * d;
  const int nb = (int)lround((W + 2 * off) / (d / 3)) + 1, ns = (int)lround((top + off) / (d / 3));
  const int nw = nb + 2 * ns;
  *wx = malloc(2 * sizeof(double) * nw);
  *wn = malloc(2 * sizeof(double) * nw);
  *side = malloc(sizeof(int) * nw);
  int k = 0;
  for (int q = 0; q < nb; ++q, ++k) {
    (*wx)[2 * k] = -off + q * (W + 2 * off) / (nb - 1);
    (*wx)[2 * k + 1] = -off;
    (*wn)[2 * k] = 0.0;
    (*wn)[2 * k + 1] = 1.0;
    (*side)[k] = 0;
  }
  for (int q = 1; q <= ns; ++q)
    for (int sd = 0; sd < 2; ++sd, ++k) {
      (*wx)[2 * k] = sd ? W + off : -off;
      (*wx)[2 * k + 1] = -off + q * d / 3;
      (*wn)[2 * k] = sd ? -1.0 : 1.0;
      (*wn)[2 * k + 1] = 0.0;
      (*side)[k] = 1 + sd;
    }
  return nw;
}

/* nx x nz lattice of spacing d from (x0, 0), hydrostatic below H (003 eq 65), masses
 * rho d^2, velocity parameters (u, w). */
static double *block(int nx, int nz, double d, double x0, double H, double kappa, double u, double w, double *m) {
  const int n = nx * nz;
  double *y = calloc(5 * (size_t)n, sizeof(double));
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nx; ++i) {
      const int p = j * nx + i;
      const double z = (j + 0.5) * d;
      y[2 * p] = x0 + (i + 0.5) * d;
      y[2 * p + 1] = z;
      y[2 * n + 2 * p] = u;
      y[2 * n + 2 * p + 1] = w;
      y[4 * n + p] = RHO0 * pow(1 + RHO0 * G * (H - z) / kappa, 1 / GAMMA);
      m[p] = y[4 * n + p] * d * d;
    }
  return y;
}

static mfree_system_t *make_fluid(int n, const double *m, double kappa, double mu, double h, int nw,
                                  const double *wx, const double *wn, mfree_lumping_t lump) {
  mfree_system_t *sys = NULL;
  assert_ok(ctx, mfree_system_create_fluid(ctx, 2, n, &sys));
  assert_ok(ctx, mfree_system_set_fluid(sys, &RHO0, 0, kappa, GAMMA, mu));
  assert_ok(ctx, mfree_system_set_masses(sys, m, 1));
  assert_ok(ctx, mfree_system_set_smoothing(sys, h));
  const double g[2] = {0.0, -G};
  assert_ok(ctx, mfree_system_set_gravity(sys, g));
  assert_ok(ctx, mfree_system_set_lumping(sys, lump));
  assert_ok(ctx, mfree_system_set_walls(sys, nw, wx, wn, 0.7 * h, 10.0));
  return sys;
}

/* progress callback: stop after one step */
static int32_t one_step(void *user, int64_t step, double t, double dt) {
  (void)user;
  (void)step;
  (void)t;
  (void)dt;
  return 1;
}

/* the diagonal of the velocity block of the lumped mass matrix: one value per particle */
static void lumped_masses(mfree_system_t *sys, const double *y, int n, double *ml) {
  mfree_matrix_t *M = NULL;
  assert_ok(ctx, mfree_system_assemble_mass(sys, y, 0, &M));
  const int64_t *rp;
  const int32_t *ci;
  const double *v;
  assert_ok(ctx, mfree_matrix_get_csr(M, &rp, &ci, &v));
  for (int i = 0; i < n; ++i) {
    const int64_t row = 2 * n + 2 * i; /* x-velocity row of particle i */
    ml[i] = 0.0;
    for (int64_t e = rp[row]; e < rp[row + 1]; ++e)
      if (ci[e] == row) ml[i] = v[e];
  }
  mfree_matrix_destroy(&M);
}

static void check_balance(mfree_lumping_t lump) {
  enum { NX = 12, NZ = 12, N = NX * NZ };
  const double d = 0.005, h = 1.5 * d, H = NZ * d, W = 3 * NX * d;
  const double kappa = 100.0 * RHO0 * 2.0 * G * H / GAMMA; /* 003 eq 125 */
  double m[N], ml[N], vold[2 * N], F[2];
  double *y = block(NX, NZ, d, 2 * d, H, kappa, -0.4, -0.8, m);
  for (int p = 0; p < N; ++p) y[2 * p + 1] += 2 * d; /* a little above the floor */
  double *wx, *wn;
  int *side;
  const int nw = tank_walls(W, 2 * H, d, &wx, &wn, &side);
  mfree_system_t *sys = make_fluid(N, m, kappa, 0.5, h, nw, wx, wn, lump);
  double M = 0.0;
  for (int p = 0; p < N; ++p) M += m[p];
  double *pw = malloc(2 * sizeof(double) * nw);
  double t = 0.0, worst = 0.0, worst_split = 0.0;
  int active = 0;
  for (int step = 0; step < 400; ++step) {
    assert_ok(ctx, mfree_system_get_wall_force(sys, y, F, nw, pw));
    double s[2] = {0, 0};
    for (int k = 0; k < nw; ++k) {
      s[0] += pw[2 * k];
      s[1] += pw[2 * k + 1];
    }
    const double scale = M * G;
    worst_split = fmax(worst_split, fmax(fabs(s[0] - F[0]), fabs(s[1] - F[1])) / scale);
    if (hypot(F[0], F[1]) > 1e-3 * scale) ++active;
    if (lump == MFREE_LUMP_GALERKIN) lumped_masses(sys, y, N, ml);
    else memcpy(ml, m, sizeof ml);
    memcpy(vold, y + 2 * N, sizeof vold);
    const double t0 = t;
    int64_t steps = 0;
    assert_ok(ctx, mfree_system_integrate(sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, 1.0, 0.3, 0.0, one_step, NULL,
                                          &steps));
    assert_int_equal(steps, 1);
    const double dt = t - t0;
    double dp[2] = {0, 0};
    for (int p = 0; p < N; ++p)
      for (int c = 0; c < 2; ++c) dp[c] += ml[p] * (y[2 * N + 2 * p + c] - vold[2 * p + c]);
    const double expect[2] = {dt * F[0], dt * (F[1] - M * G)};
    worst = fmax(worst, fmax(fabs(dp[0] - expect[0]), fabs(dp[1] - expect[1])) / (dt * scale));
  }
  print_message("%s lumping: momentum change against dt (M g + F) within %.2e of dt M g; per-wall sum within "
                "%.2e; walls acting in %d of 400 steps (t = %.4f s)\n",
                lump == MFREE_LUMP_GALERKIN ? "Galerkin" : "physical", worst, worst_split, active, t);
  assert_true(worst < 1e-9);
  assert_true(worst_split < 1e-12);
  assert_true(active >= 100);
  free(pw);
  free(wx);
  free(wn);
  free(side);
  free(y);
  mfree_system_destroy(&sys);
}

static void test_momentum_balance_galerkin(void **s) {
  (void)s;
  check_balance(MFREE_LUMP_GALERKIN);
}

static void test_momentum_balance_physical(void **s) {
  (void)s;
  check_balance(MFREE_LUMP_PHYSICAL);
}

static void test_still_column(void **s) {
  (void)s;
  enum { NZ = 10, NX = 3 * NZ, N = NX * NZ };
  const double H = 0.1, W = 3 * H, d = H / NZ, h = 1.5 * d;
  const double kappa = 100.0 * RHO0 * 2.0 * G * H / GAMMA;
  double m[N], F[2];
  double *y = block(NX, NZ, d, 0.0, H, kappa, 0.0, 0.0, m);
  double *wx, *wn;
  int *side;
  const int nw = tank_walls(W, 1.5 * H, d, &wx, &wn, &side);
  mfree_system_t *sys = make_fluid(N, m, kappa, 50.0, h, nw, wx, wn, MFREE_LUMP_GALERKIN);
  const double lo[2] = {-0.5 * d, -0.5 * d}, hi[2] = {W + 0.5 * d, 2 * H};
  assert_ok(ctx, mfree_system_set_box(sys, lo, hi));
  double M = 0.0;
  for (int p = 0; p < N; ++p) M += m[p];
  double *pw = malloc(2 * sizeof(double) * nw);
  double t = 0.0, imp[3] = {0, 0, 0}, impz = 0.0, span = 0.0;
  int64_t nsteps = 0;
  while (t < 0.3) {
    assert_ok(ctx, mfree_system_get_wall_force(sys, y, F, nw, pw));
    const double t0 = t;
    int64_t steps = 0;
    assert_ok(ctx, mfree_system_integrate(sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, 0.3, 0.2, 0.0, one_step, NULL,
                                          &steps));
    ++nsteps;
    if (t0 < 0.1) continue;
    const double dt = t - t0;
    span += dt;
    impz += dt * F[1];
    for (int k = 0; k < nw; ++k) imp[side[k]] += dt * pw[2 * k + (side[k] == 0 ? 1 : 0)];
  }
  const double weight = M * G, thrust = 0.5 * RHO0 * G * H * H;
  const double floor_f = imp[0] / span, left = imp[1] / span, right = -imp[2] / span, total = impz / span;
  print_message("still column, mean over 0.1-0.3 s (%lld steps): total vertical %.3f N/m, floor %.3f, weight %.3f "
                "(%+.2f %%); side walls %.3f and %.3f N/m, rho0 g H^2 / 2 = %.3f (%+.2f %%, %+.2f %%)\n",
                (long long)nsteps, total, floor_f, weight, 100 * (floor_f - weight) / weight, left, right, thrust,
                100 * (left - thrust) / thrust, 100 * (right - thrust) / thrust);
  assert_true(fabs(total - weight) < 0.02 * weight);
  assert_true(fabs(floor_f - weight) < 0.02 * weight);
  assert_true(fabs(left - thrust) < 0.1 * thrust && fabs(right - thrust) < 0.1 * thrust);
  free(pw);
  free(wx);
  free(wn);
  free(side);
  free(y);
  mfree_system_destroy(&sys);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_momentum_balance_galerkin),
      cmocka_unit_test(test_momentum_balance_physical),
      cmocka_unit_test(test_still_column),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
