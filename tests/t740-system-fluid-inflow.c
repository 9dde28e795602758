/* Open boundaries of the Galerkin-SPH fluid: inflow gates and outflow planes
 * (mfree_system_set_active, _set_inflow, _set_outflow, _update_open_boundaries).
 *
 * 1. Gate into an empty channel: a gate of width W = 0.06 m (6 points at d = 0.01 m) at
 *    x = 0 injects water at U = 1 m/s into a system of 600 particles, all dormant at
 *    first. No gravity, no walls: the jet translates at U. After 0.2975 s (leap-frog
 *    and predictor-corrector; 0.2975 s: 30 rows in, 29.75 due): the released mass is the released count times rho d W / 6
 *    to round-off, rho U W t to half a row (and within 1 %), the lumped masses of the
 *    active particles (mfree_system_assemble_mass) sum to the released mass plus the
 *    buffer's to 1e-12, the buffer holds nb = ceil(2h / d) = 3 rows, the first row's front
 *    is at U t - d/2 to 1e-9, and no particle is beyond it.
 * 2. Outflow: the same channel with an outflow plane at x = 0.155 m: after 0.3 s the rows
 *    released before 0.3 - 0.155 / U s have crossed it (exactly those: the run ends with the
 *    nearest row half a spacing from the plane), their mass is the outflow's, and no active
 *    particle is past the plane.
 * 3. Pool exhaustion: a capacity of 60 particles (10 rows) stops the run with
 *    MFREE_FAIL_CAPACITY at the instant the 8th row must be activated behind the buffer,
 *    with nothing lost: the state is valid, the released mass is unchanged by a second
 *    update at that time, which fails the same way.
 * 4. A capacity system is the fluid of its active particles: with 40 dormant particles
 *    (NaN positions) appended to a 10 x 10 block, the rates of the block particles equal
 *    those of the plain 100-particle system bitwise (walls, gravity, density diffusion,
 *    velocity smoothing and the Shepard threshold set), the dormant rates are zero, and
 *    so is the integrated state after 20 leap-frog steps.
 * 5. Host integration (as a SUNDIALS host would): forward Euler on mfree_system_rhs with
 *    mfree_system_update_open_boundaries between windows of d / (4 U): the buffer moves
 *    at U exactly (position rates U n, zero velocity and density rates), dormant rates
 *    are zero, and the released mass after 0.1 s is rho U W t to half a row.
 * 6. A square gate in 3D (lattice, mass, buffer; parallel edges refused).
 * 7. Bad input: NULL pointers, non-unit or non-orthogonal normals, short edges, bad
 *    speed/density/spacing, non-finite coordinates, gate numbers out of order, an active
 *    count out of range or set after the first update, sizes that do not match.
 * 8. The kept mass of mfree_system_apply_mass follows the particles' states (below). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"

static mfree_context_t *ctx;
static int setup(void **s) { (void)s; return mfree_context_create(&ctx) != MFREE_SUCCESS; }
static int teardown(void **s) { (void)s; return mfree_context_destroy(&ctx) != MFREE_SUCCESS; }

static const double RHO = 1000.0, U = 1.0, D = 0.01, W = 0.06, GAMMA = 7.0;
static const double C0 = 10.0; /* sound speed: ten times the inflow speed */

static mfree_system_t *channel(int n, double **yout) {
  mfree_system_t *sys = NULL;
  assert_ok(ctx, mfree_system_create_fluid(ctx, 2, n, &sys));
  const double kappa = RHO * C0 * C0 / GAMMA;
  assert_ok(ctx, mfree_system_set_fluid(sys, &RHO, 0, kappa, GAMMA, 0.01));
  const double m = RHO * D * D;
  assert_ok(ctx, mfree_system_set_masses(sys, &m, 0));
  assert_ok(ctx, mfree_system_set_smoothing(sys, 1.5 * D));
  assert_ok(ctx, mfree_system_set_active(sys, 0));
  const double o[2] = {0.0, 0.0}, e[2] = {0.0, W}, nrm[2] = {1.0, 0.0};
  assert_ok(ctx, mfree_system_set_inflow(sys, 0, o, e, nrm, U, RHO, D));
  double *y = calloc(5 * (size_t)n, sizeof(double));
  for (int i = 0; i < n; ++i) { /* dormant: anywhere, here far away */
    y[2 * i] = -100.0;
    y[4 * n + i] = RHO;
  }
  *yout = y;
  return sys;
}

/* Sum of the lumped masses (velocity block diagonal) of the active particles. */
static double active_lumped_mass(mfree_system_t *sys, const double *y, int n, const int32_t *state) {
  double *Mi = malloc(sizeof(double) * n);
  mfree_test_lumped_masses(ctx, sys, y, 2, n, Mi);
  double s = 0.0;
  for (int i = 0; i < n; ++i)
    if (state[i] != MFREE_PARTICLE_DORMANT) s += Mi[i];
  free(Mi);
  return s;
}

static void gate_run(mfree_integrator_t scheme) {
  enum { N = 600 };
  double *y;
  mfree_system_t *sys = channel(N, &y);
  double t = 0.0;
  int64_t steps = 0;
  const double t_end = 0.2975; /* 30 rows in, 29.75 due: 0.83 % apart */
  assert_ok(ctx, mfree_system_integrate(sys, scheme, y, &t, t_end, 0.5, 0.0, NULL, NULL, &steps));
  assert_true(t == t_end);
  int64_t count = 0;
  double min = 0.0;
  assert_ok(ctx, mfree_system_get_inflow(sys, 0, &count, &min));
  const double me = RHO * D * W / 6; /* mass of an injected particle */
  const double expect = RHO * U * W * t_end, row = 6 * me;
  print_message("%s: %lld steps, %lld particles in, mass %.6g vs rho U W t = %.6g\n",
                scheme == MFREE_INTEGRATOR_LEAPFROG ? "leap-frog" : "PC", (long long)steps, (long long)count, min,
                expect);
  assert_true(fabs(min - (double)count * me) <= 1e-12 * min);
  assert_true(fabs(min - expect) <= 0.5 * row + 1e-12 * expect);
  assert_true(fabs(min - expect) <= 0.01 * expect);
  assert_int_equal(count % 6, 0);
  int32_t state[N], na = 0;
  assert_ok(ctx, mfree_system_get_active(sys, &na, N, state));
  int nbuf = 0, nfluid = 0;
  double front = -1.0, buf_mass = 0.0;
  for (int i = 0; i < N; ++i) {
    if (state[i] == MFREE_PARTICLE_INFLOW) {
      ++nbuf;
      assert_true(y[2 * i] < 0.0); /* upstream of the gate */
    }
    if (state[i] == MFREE_PARTICLE_FLUID) {
      ++nfluid;
      front = fmax(front, y[2 * i]);
    }
  }
  buf_mass = nbuf * me;
  assert_int_equal(nbuf, 3 * 6);
  assert_int_equal(nfluid, count);
  assert_int_equal(na, nbuf + nfluid);
  /* the first row entered at t = d / (2U) at x = 0 and moves at U */
  assert_true(fabs(front - (U * t_end - 0.5 * D)) < 1e-9);
  const double lumped = active_lumped_mass(sys, y, N, state);
  assert_true(fabs(lumped - (min + buf_mass)) <= 1e-12 * lumped);
  mfree_system_destroy(&sys);
  free(y);
}

static void test_gate_leapfrog(void **s) { (void)s; gate_run(MFREE_INTEGRATOR_LEAPFROG); }
static void test_gate_pc(void **s) { (void)s; gate_run(MFREE_INTEGRATOR_PREDICTOR_CORRECTOR); }

static void test_outflow(void **s) {
  (void)s;
  enum { N = 300 };
  double *y;
  mfree_system_t *sys = channel(N, &y);
  const double L = 0.155, p[2] = {L, 0.0}, nrm[2] = {1.0, 0.0};
  assert_ok(ctx, mfree_system_set_outflow(sys, 0, p, nrm));
  double t = 0.0;
  const double t_end = 0.3;
  assert_ok(ctx, mfree_system_integrate(sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, t_end, 0.5, 0.0, NULL, NULL, NULL));
  /* row k entered at (k + 1/2) d / U and is at U t - (k + 1/2) d: past L for k < 14.5 */
  int64_t in = 0, out = 0;
  double min = 0.0, mout = 0.0;
  assert_ok(ctx, mfree_system_get_inflow(sys, 0, &in, &min));
  assert_ok(ctx, mfree_system_get_outflow(sys, 0, &out, &mout));
  assert_int_equal(in, 30 * 6);
  assert_int_equal(out, 15 * 6);
  assert_true(fabs(mout - out * RHO * D * W / 6) <= 1e-12 * mout);
  int32_t state[N], na = 0;
  assert_ok(ctx, mfree_system_get_active(sys, &na, N, state));
  double fluid_mass = 0.0;
  for (int i = 0; i < N; ++i)
    if (state[i] == MFREE_PARTICLE_FLUID) {
      assert_true(y[2 * i] <= L);
      fluid_mass += RHO * D * W / 6;
    }
  assert_true(fabs(fluid_mass - (min - mout)) <= 1e-12 * min);
  assert_int_equal(na, (30 - 15 + 3) * 6);
  mfree_system_destroy(&sys);
  free(y);
}

static void test_pool_exhausted(void **s) {
  (void)s;
  enum { N = 60 };
  double *y;
  mfree_system_t *sys = channel(N, &y);
  double t = 0.0;
  mfree_status_t st = mfree_system_integrate(sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, 1.0, 0.5, 0.0, NULL, NULL, NULL);
  assert_error(ctx, st, MFREE_FAIL_CAPACITY, "exhausted");
  /* rows 0..9 fill the pool; row 10 is due when row 7 enters, at 7.5 d / U */
  assert_true(fabs(t - 7.5 * D / U) < 1e-12);
  int64_t count = 0;
  double min = 0.0, min2 = 0.0;
  assert_ok(ctx, mfree_system_get_inflow(sys, 0, &count, &min));
  assert_int_equal(count, 7 * 6);
  for (int q = 0; q < 5 * N; ++q) assert_true(isfinite(y[q]));
  double *y2 = malloc(sizeof(double) * 5 * N);
  memcpy(y2, y, sizeof(double) * 5 * N);
  assert_error(ctx, mfree_system_update_open_boundaries(sys, t, y2), MFREE_FAIL_CAPACITY, "gate 0");
  assert_true(memcmp(y, y2, sizeof(double) * 5 * N) == 0);
  assert_ok(ctx, mfree_system_get_inflow(sys, 0, &count, &min2));
  assert_true(min2 == min);
  int32_t na = 0;
  assert_ok(ctx, mfree_system_get_active(sys, &na, 0, NULL));
  assert_int_equal(na, N);
  mfree_system_destroy(&sys);
  free(y);
  free(y2);
}

/* a 10 x 10 block in a tank corner with walls and gravity, on its own or with dormant
 * particles appended */
static mfree_system_t *block_system(int n, int nactive, const double *wx, const double *wn, int nw) {
  mfree_system_t *sys = NULL;
  assert_ok(ctx, mfree_system_create_fluid(ctx, 2, n, &sys));
  const double kappa = RHO * C0 * C0 / GAMMA, m = RHO * D * D, g[2] = {0.0, -9.81};
  assert_ok(ctx, mfree_system_set_fluid(sys, &RHO, 0, kappa, GAMMA, 0.5));
  assert_ok(ctx, mfree_system_set_masses(sys, &m, 0));
  assert_ok(ctx, mfree_system_set_smoothing(sys, 1.5 * D));
  assert_ok(ctx, mfree_system_set_gravity(sys, g));
  assert_ok(ctx, mfree_system_set_walls(sys, nw, wx, wn, 1.05 * D, 10.0));
  assert_ok(ctx, mfree_system_set_density_diffusion(sys, 0.1));
  assert_ok(ctx, mfree_system_set_velocity_smoothing(sys, 0.1));
  assert_ok(ctx, mfree_system_set_shepard_condition(sys, 20.0));
  if (nactive < n) assert_ok(ctx, mfree_system_set_active(sys, nactive));
  return sys;
}

static int32_t stop_at_20(void *user, int64_t step, double t, double dt) {
  (void)user;
  (void)t;
  (void)dt;
  return step >= 20;
}

static void test_dormant_excluded(void **s) {
  (void)s;
  enum { NB = 100, ND = 40, N = NB + ND };
  double *wx, *wn;
  const int nw = mfree_test_tank_walls(0.3, D, 0.5 * D, 0.2, &wx, &wn);
  mfree_system_t *a = block_system(NB, NB, wx, wn, nw), *b = block_system(N, NB, wx, wn, nw);
  double ya[5 * NB], yb[5 * N], ra[5 * NB], rb[5 * N];
  for (int j = 0; j < 10; ++j)
    for (int i = 0; i < 10; ++i) {
      const int p = j * 10 + i;
      ya[2 * p] = (i + 0.5) * D;
      ya[2 * p + 1] = (j + 0.5) * D;
      ya[2 * NB + 2 * p] = 0.1 * sin(p);
      ya[2 * NB + 2 * p + 1] = -0.2;
      ya[4 * NB + p] = RHO * (1.0 + 1e-3 * cos(p));
    }
  for (int q = 0; q < 5 * N; ++q) yb[q] = NAN; /* dormant entries are never read */
  for (int p = 0; p < NB; ++p) {
    for (int c = 0; c < 2; ++c) {
      yb[2 * p + c] = ya[2 * p + c];
      yb[2 * N + 2 * p + c] = ya[2 * NB + 2 * p + c];
    }
    yb[4 * N + p] = ya[4 * NB + p];
  }
  assert_ok(ctx, mfree_system_rhs(a, 0.0, ya, ra));
  assert_ok(ctx, mfree_system_rhs(b, 0.0, yb, rb));
  for (int p = 0; p < NB; ++p) {
    for (int c = 0; c < 2; ++c) {
      assert_true(rb[2 * p + c] == ra[2 * p + c]);
      assert_true(rb[2 * N + 2 * p + c] == ra[2 * NB + 2 * p + c]);
    }
    assert_true(rb[4 * N + p] == ra[4 * NB + p]);
  }
  for (int p = NB; p < N; ++p) {
    for (int c = 0; c < 2; ++c) assert_true(rb[2 * p + c] == 0.0 && rb[2 * N + 2 * p + c] == 0.0);
    assert_true(rb[4 * N + p] == 0.0);
  }
  double ta = 0.0, tb = 0.0;
  int64_t ka = 0, kb = 0;
  assert_ok(ctx, mfree_system_integrate(a, MFREE_INTEGRATOR_LEAPFROG, ya, &ta, 1.0, 0.5, 0.0, stop_at_20, NULL, &ka));
  assert_ok(ctx, mfree_system_integrate(b, MFREE_INTEGRATOR_LEAPFROG, yb, &tb, 1.0, 0.5, 0.0, stop_at_20, NULL, &kb));
  assert_int_equal(ka, 20);
  assert_int_equal(kb, 20);
  assert_true(ta == tb);
  for (int p = 0; p < NB; ++p) {
    for (int c = 0; c < 2; ++c) {
      assert_true(yb[2 * p + c] == ya[2 * p + c]);
      assert_true(yb[2 * N + 2 * p + c] == ya[2 * NB + 2 * p + c]);
    }
    assert_true(yb[4 * N + p] == ya[4 * NB + p]);
  }
  for (int p = NB; p < N; ++p) assert_true(isnan(yb[2 * p]) && isnan(yb[4 * N + p]));
  mfree_system_destroy(&a);
  mfree_system_destroy(&b);
  free(wx);
  free(wn);
}


static void test_host_windows(void **s) {
  (void)s;
  enum { N = 200 };
  double *y;
  mfree_system_t *sys = channel(N, &y);
  double *r = malloc(sizeof(double) * 5 * N);
  int32_t state[N], na = 0;
  const double win = D / (4 * U), dt = win / 8, t_end = 0.1;
  double t = 0.0;
  assert_ok(ctx, mfree_system_update_open_boundaries(sys, t, y));
  for (int w = 0; t < t_end - 1e-12; ++w) {
    assert_ok(ctx, mfree_system_get_active(sys, &na, N, state));
    double xb0[N];
    for (int i = 0; i < N; ++i) xb0[i] = y[2 * i];
    for (int k = 0; k < 8; ++k) {
      assert_ok(ctx, mfree_system_rhs(sys, t, y, r));
      for (int i = 0; i < N; ++i) {
        if (state[i] == MFREE_PARTICLE_DORMANT)
          for (int c = 0; c < 2; ++c) assert_true(r[2 * i + c] == 0.0 && r[2 * N + 2 * i + c] == 0.0);
        if (state[i] == MFREE_PARTICLE_INFLOW) {
          assert_true(r[2 * i] == U && r[2 * i + 1] == 0.0);
          assert_true(r[2 * N + 2 * i] == 0.0 && r[2 * N + 2 * i + 1] == 0.0 && r[4 * N + i] == 0.0);
        }
        if (state[i] == MFREE_PARTICLE_DORMANT) assert_true(r[4 * N + i] == 0.0);
      }
      for (int q = 0; q < 5 * N; ++q) y[q] += dt * r[q];
      t = (w * 8 + k + 1) * dt;
    }
    for (int i = 0; i < N; ++i)
      if (state[i] == MFREE_PARTICLE_INFLOW) assert_true(fabs(y[2 * i] - xb0[i] - U * win) < 1e-12);
    assert_ok(ctx, mfree_system_update_open_boundaries(sys, t, y));
  }
  int64_t count = 0;
  double min = 0.0;
  assert_ok(ctx, mfree_system_get_inflow(sys, 0, &count, &min));
  const double expect = RHO * U * W * t;
  assert_true(fabs(min - expect) <= 0.5 * RHO * D * W + 1e-12 * expect);
  assert_int_equal(count, 10 * 6);
  mfree_system_destroy(&sys);
  free(y);
  free(r);
}

/* Test 8: mfree_system_apply_mass keeps the mass of one state, and an update that changes the
 * particles' states (a new row, releases) makes it assemble again even at the same y:
 * the product at the old state's bits equals a fresh mfree_system_assemble_mass's
 * (bit for bit) and differs from the product kept before the update. */
static void test_kept_mass_states(void **s) {
  (void)s;
  enum { N = 200 };
  double *y;
  mfree_system_t *sys = channel(N, &y);
  double *y0 = malloc(sizeof(double) * 5 * N), *v = malloc(sizeof(double) * 5 * N);
  double *m1 = malloc(sizeof(double) * 5 * N), *m2 = malloc(sizeof(double) * 5 * N);
  double *mr = malloc(sizeof(double) * 5 * N);
  for (int q = 0; q < 5 * N; ++q) v[q] = 1.0 + 1e-3 * q;
  assert_ok(ctx, mfree_system_update_open_boundaries(sys, 0.0, y));
  for (int consistent = 0; consistent < 2; ++consistent) {
    const double t = (1 + consistent) * D / U; /* one more row each time */
    memcpy(y0, y, sizeof(double) * 5 * N);
    int32_t na0 = 0, na1 = 0;
    assert_ok(ctx, mfree_system_get_active(sys, &na0, 0, NULL));
    assert_ok(ctx, mfree_system_apply_mass(sys, y0, consistent, v, m1));
    assert_ok(ctx, mfree_system_update_open_boundaries(sys, t, y));
    assert_ok(ctx, mfree_system_get_active(sys, &na1, 0, NULL));
    assert_true(na1 > na0);
    assert_ok(ctx, mfree_system_apply_mass(sys, y0, consistent, v, m2));
    mfree_matrix_t *M = NULL;
    assert_ok(ctx, mfree_system_assemble_mass(sys, y0, consistent, &M));
    assert_ok(ctx, mfree_matrix_apply(M, v, mr));
    mfree_matrix_destroy(&M);
    assert_memory_equal(m2, mr, sizeof(double) * 5 * N);
    assert_memory_not_equal(m1, m2, sizeof(double) * 5 * N);
  }
  mfree_system_destroy(&sys);
  free(y);
  free(y0);
  free(v);
  free(m1);
  free(m2);
  free(mr);
}

static void test_bad_input(void **s) {
  (void)s;
  double *y;
  mfree_system_t *sys = channel(50, &y);
  const double o[2] = {0.0, 0.0}, e[2] = {0.0, W}, nrm[2] = {1.0, 0.0}, tilted[2] = {0.8, 0.8};
  const double skew[2] = {0.6, 0.8}, shortedge[2] = {0.0, 0.4 * D}, nan2[2] = {NAN, 0.0};
  assert_error(ctx, mfree_system_set_inflow(sys, 1, NULL, e, nrm, U, RHO, D), MFREE_ERR_NULL, "NULL");
  assert_error(ctx, mfree_system_set_inflow(sys, 1, o, e, tilted, U, RHO, D), MFREE_ERR_ARG, "unit");
  assert_error(ctx, mfree_system_set_inflow(sys, 1, o, e, skew, U, RHO, D), MFREE_ERR_ARG, "orthogonal");
  assert_error(ctx, mfree_system_set_inflow(sys, 1, o, shortedge, nrm, U, RHO, D), MFREE_ERR_ARG, "shorter");
  assert_error(ctx, mfree_system_set_inflow(sys, 1, nan2, e, nrm, U, RHO, D), MFREE_ERR_INPUT, "finite");
  assert_error(ctx, mfree_system_set_inflow(sys, 1, o, e, nrm, 0.0, RHO, D), MFREE_ERR_ARG, "speed");
  assert_error(ctx, mfree_system_set_inflow(sys, 1, o, e, nrm, U, NAN, D), MFREE_ERR_ARG, "density");
  assert_error(ctx, mfree_system_set_inflow(sys, 1, o, e, nrm, U, RHO, -D), MFREE_ERR_ARG, "spacing");
  assert_error(ctx, mfree_system_set_inflow(sys, 3, o, e, nrm, U, RHO, D), MFREE_ERR_ARG, "numbered");
  assert_error(ctx, mfree_system_set_outflow(sys, 1, o, nrm), MFREE_ERR_ARG, "numbered");
  assert_error(ctx, mfree_system_set_outflow(sys, 0, o, tilted), MFREE_ERR_ARG, "unit");
  assert_error(ctx, mfree_system_set_outflow(sys, 0, NULL, nrm), MFREE_ERR_NULL, "NULL");
  assert_error(ctx, mfree_system_set_outflow(sys, 0, nan2, nrm), MFREE_ERR_INPUT, "finite");
  assert_error(ctx, mfree_system_set_active(sys, 51), MFREE_ERR_ARG, "active count");
  assert_error(ctx, mfree_system_set_active(sys, -1), MFREE_ERR_ARG, "active count");
  int32_t na = 0, st[49];
  assert_error(ctx, mfree_system_get_active(sys, &na, 49, st), MFREE_ERR_ARG, "50");
  assert_error(ctx, mfree_system_get_active(sys, NULL, 0, NULL), MFREE_ERR_NULL, "NULL");
  assert_error(ctx, mfree_system_get_inflow(sys, 1, NULL, NULL), MFREE_ERR_ARG, "not set");
  assert_error(ctx, mfree_system_get_outflow(sys, 0, NULL, NULL), MFREE_ERR_ARG, "not set");
  assert_error(ctx, mfree_system_update_open_boundaries(sys, NAN, y), MFREE_ERR_ARG, "finite");
  assert_error(ctx, mfree_system_update_open_boundaries(sys, 0.0, NULL), MFREE_ERR_NULL, "NULL");
  assert_ok(ctx, mfree_system_update_open_boundaries(sys, 0.0, y));
  assert_error(ctx, mfree_system_set_active(sys, 0), MFREE_ERR_STATE, "first update");
  assert_error(ctx, mfree_system_set_inflow(sys, 0, o, e, nrm, U, RHO, D), MFREE_ERR_STATE, "started");
  double t = 0.0;
  assert_error(ctx, mfree_system_integrate(sys, (mfree_integrator_t)9, y, &t, 1.0, 0.5, 0.0, NULL, NULL, NULL),
               MFREE_ERR_ARG, "integrator");
  mfree_system_destroy(&sys);
  free(y);
  /* the masses must be set before an update */
  mfree_system_t *bare = NULL;
  double yb[10] = {0};
  assert_ok(ctx, mfree_system_create_fluid(ctx, 2, 2, &bare));
  assert_ok(ctx, mfree_system_set_smoothing(bare, 1.5 * D));
  assert_error(ctx, mfree_system_update_open_boundaries(bare, 0.0, yb), MFREE_ERR_STATE, "masses");
  mfree_system_destroy(&bare);
}

/* 3D: a square gate 0.04 m x 0.04 m (4 x 4 points at d = 0.01 m) in the plane x = 0.02, its
 * edges along y and z, the normal +x; water at 1 m/s into 800 dormant particles. After
 * 0.1 s (10 rows) the released mass is 160 particles of rho d A / 16 = rho U A t, the buffer
 * 3 rows of 16 at x < 0.02, the lattice points at (j + 1/2) d on the gate, and the
 * released particles ahead of it moving at U (physical lumping: the jet is too thin for
 * positive Galerkin lumped masses at its edges). */
static void test_gate_3d(void **s) {
  (void)s;
  enum { N = 800 };
  mfree_system_t *sys = NULL;
  assert_ok(ctx, mfree_system_create_fluid(ctx, 3, N, &sys));
  const double kappa = RHO * C0 * C0 / GAMMA, m = RHO * D * D * D;
  assert_ok(ctx, mfree_system_set_fluid(sys, &RHO, 0, kappa, GAMMA, 0.01));
  assert_ok(ctx, mfree_system_set_masses(sys, &m, 0));
  assert_ok(ctx, mfree_system_set_smoothing(sys, 1.5 * D));
  /* a jet 4 particles across: Galerkin lumped masses of its edge sites can be negative */
  assert_ok(ctx, mfree_system_set_lumping(sys, MFREE_LUMP_PHYSICAL));
  assert_ok(ctx, mfree_system_set_active(sys, 0));
  const double o[3] = {0.02, -0.02, 0.0}, e[6] = {0.0, 0.04, 0.0, 0.0, 0.0, 0.04}, nrm[3] = {1.0, 0.0, 0.0};
  const double par[6] = {0.0, 0.04, 0.0, 0.0, 0.08, 0.0};
  assert_error(ctx, mfree_system_set_inflow(sys, 0, o, par, nrm, U, RHO, D), MFREE_ERR_ARG, "parallel");
  assert_ok(ctx, mfree_system_set_inflow(sys, 0, o, e, nrm, U, RHO, D));
  double *y = calloc(7 * (size_t)N, sizeof(double));
  for (int i = 0; i < N; ++i) y[6 * N + i] = RHO;
  double t = 0.0;
  assert_ok(ctx, mfree_system_integrate(sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, 0.1, 0.5, 0.0, NULL, NULL, NULL));
  int64_t count = 0;
  double min = 0.0;
  assert_ok(ctx, mfree_system_get_inflow(sys, 0, &count, &min));
  const double A = 0.04 * 0.04;
  assert_int_equal(count, 10 * 16);
  assert_true(fabs(min - RHO * U * A * t) <= 1e-12 * min);
  int32_t state[N], na = 0;
  assert_ok(ctx, mfree_system_get_active(sys, &na, N, state));
  assert_int_equal(na, 13 * 16);
  for (int i = 0; i < N; ++i) {
    if (state[i] == MFREE_PARTICLE_DORMANT) continue;
    const double *x = y + 3 * i;
    /* on the lattice (j + 1/2) d across the gate */
    for (int c = 1; c < 3; ++c) {
      const double q = (x[c] - o[c]) / D - 0.5;
      assert_true(fabs(q - round(q)) < 1e-9 && q > -0.5 && q < 3.5);
    }
    if (state[i] == MFREE_PARTICLE_INFLOW) assert_true(x[0] < 0.02);
    if (state[i] == MFREE_PARTICLE_FLUID) {
      assert_true(x[0] >= 0.02 - 1e-12);
      assert_true(fabs(y[3 * N + 3 * i] - U) < 1e-9);
    }
  }
  mfree_system_destroy(&sys);
  free(y);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_gate_leapfrog),
      cmocka_unit_test(test_gate_pc),
      cmocka_unit_test(test_outflow),
      cmocka_unit_test(test_pool_exhausted),
      cmocka_unit_test(test_dormant_excluded),
      cmocka_unit_test(test_host_windows),
      cmocka_unit_test(test_gate_3d),
      cmocka_unit_test(test_kept_mass_states),
      cmocka_unit_test(test_bad_input),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
