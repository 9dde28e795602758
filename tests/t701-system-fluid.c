/* Galerkin-SPH fluid system (paper 003): exact conservation of linear and angular
 * momentum by the nodal-integrated internal forces (docs/papers.md, paper 003, derived
 * results 1), hydrostatic equilibrium of the interior at t = 0 with the initial densities of
 * 003 eq 65, and the failure modes (non-finite state, particle leaving the
 * box, CFL violation), each keeping the last good state. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"

static mfree_context_t *ctx;
static int setup(void **s) { (void)s; return mfree_context_create(&ctx) != MFREE_SUCCESS; }
static int teardown(void **s) { (void)s; return mfree_context_destroy(&ctx) != MFREE_SUCCESS; }

enum { NX = 12, NZ = 12, N = NX * NZ };
static const double D = 0.005, RHO0 = 1000.0, G = 9.81, GAMMA = 7.0;
static double kappa_of(double H) { return 100.0 * RHO0 * 2.0 * G * H / GAMMA; } /* 003 eq 125 */

/* Lattice patch with spacing D; returns the state y (x, v, rho) and masses. */
static double *patch(double *m, int jitter, int hydrostatic) {
  double *y = calloc(5 * (size_t)N, sizeof(double));
  mfree_rng_t r;
  mfree_rng_seed(&r, 99);
  const double H = NZ * D, kap = kappa_of(H);
  for (int j = 0; j < NZ; ++j)
    for (int i = 0; i < NX; ++i) {
      const int p = j * NX + i;
      const double jx = jitter ? 0.2 * D * (2 * mfree_rng_uniform(&r) - 1) : 0.0;
      const double jz = jitter ? 0.2 * D * (2 * mfree_rng_uniform(&r) - 1) : 0.0;
      y[2 * p] = (i + 0.5) * D + jx;
      y[2 * p + 1] = (j + 0.5) * D + jz;
      const double z = (j + 0.5) * D;
      const double rho = hydrostatic ? RHO0 * pow(1 + RHO0 * G * (H - z) / kap, 1 / GAMMA) /* 003 eq 65 */
                                     : RHO0 * (1 + 0.01 * (2 * mfree_rng_uniform(&r) - 1));
      y[4 * N + p] = rho;
      m[p] = rho * D * D;
      if (!hydrostatic) {
        y[2 * N + 2 * p] = 0.3 * (2 * mfree_rng_uniform(&r) - 1);
        y[2 * N + 2 * p + 1] = 0.3 * (2 * mfree_rng_uniform(&r) - 1);
      }
    }
  return y;
}

static mfree_system_t *fluid(const double *m, double H, double mu, int gravity) {
  mfree_system_t *s = NULL;
  assert_ok(ctx, mfree_system_create_fluid(ctx, 2, N, &s));
  assert_ok(ctx, mfree_system_set_fluid(s, &RHO0, 0, kappa_of(H), GAMMA, mu));
  assert_ok(ctx, mfree_system_set_masses(s, m, 1));
  assert_ok(ctx, mfree_system_set_smoothing(s, 1.5 * D));
  if (gravity) {
    const double g[2] = {0.0, -G};
    assert_ok(ctx, mfree_system_set_gravity(s, g));
  }
  return s;
}

/* Free patch, no walls, no gravity, random velocities and densities: the lumped-mass
 * weighted accelerations sum to zero (linear momentum, test functions constant
 * complete) and so do their moments (angular momentum, linear completeness and a
 * symmetric Cauchy stress), docs/papers.md, paper 003, derived results 1, and 000 eqs
 * 106-111, to round-off. */
static void test_conservation(void **s) {
  (void)s;
  for (int lump = MFREE_LUMP_GALERKIN; lump <= MFREE_LUMP_PHYSICAL; ++lump) {
    double m[N];
    double *y = patch(m, 1, 0);
    mfree_system_t *sys = fluid(m, NZ * D, 0.5, 0);
    assert_ok(ctx, mfree_system_set_lumping(sys, (mfree_lumping_t)lump));
    int32_t neq = 0;
    assert_ok(ctx, mfree_system_get_size(sys, &neq));
    assert_int_equal(neq, 5 * N);
    double *yd = calloc((size_t)neq, sizeof(double));
    assert_ok(ctx, mfree_system_rhs(sys, 0.0, y, yd));
    double Ml[N]; /* the velocity block is diagonal, the other rows identity rows */
    mfree_test_lumped_masses(ctx, sys, y, 2, N, Ml);
    double P[2] = {0, 0}, Lz = 0.0, scale = 0.0;
    for (int i = 0; i < N; ++i) {
      const double Mi = Ml[i];
      const double fx = Mi * yd[2 * N + 2 * i], fz = Mi * yd[2 * N + 2 * i + 1];
      P[0] += fx;
      P[1] += fz;
      Lz += y[2 * i] * fz - y[2 * i + 1] * fx;
      scale += fabs(fx) + fabs(fz);
    }
    if (fabs(P[0]) > 1e-12 * scale || fabs(P[1]) > 1e-12 * scale)
      fail_msg("lumping %d: momentum rate (%g, %g), scale %g", lump, P[0], P[1], scale);
    if (fabs(Lz) > 1e-12 * scale * NX * D) fail_msg("lumping %d: angular momentum rate %g", lump, Lz);
    /* the density rates and interpolated velocities are finite */
    for (int q = 0; q < neq; ++q) assert_true(isfinite(yd[q]));
    free(yd);
    free(y);
    mfree_system_destroy(&sys);
  }
}

/* The same free patch over a run: 40 leap-frog steps (CFL 0.25) with the physical
 * masses as lumped masses (003 eq 58), so that the velocity parameters carry the
 * momentum sum_i m_i v_i: it stays at its initial value to round-off (the internal
 * forces sum to zero at every step), and the angular-momentum rate of the moving,
 * deforming patch stays zero to round-off at every step. The particle masses (the total
 * mass) are constants of the state. */
static void test_conservation_run(void **s) {
  (void)s;
  double m[N];
  double *y = patch(m, 1, 0);
  mfree_system_t *sys = fluid(m, NZ * D, 0.5, 0);
  assert_ok(ctx, mfree_system_set_lumping(sys, MFREE_LUMP_PHYSICAL));
  double P0[2] = {0, 0}, pscale = 0.0;
  for (int i = 0; i < N; ++i)
    for (int c = 0; c < 2; ++c) P0[c] += m[i] * y[2 * N + 2 * i + c], pscale += m[i] * fabs(y[2 * N + 2 * i + c]);
  double *yd = calloc(5 * (size_t)N, sizeof(double)), t = 0.0, moved = 0.0;
  const double x0 = y[0];
  for (int step = 0; step < 40; ++step) {
    int64_t ns = 0;
    /* one CFL step at a time: integrate to a t_end beyond the next step with a cap */
    assert_ok(ctx, mfree_system_integrate(sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, t + 1e-4, 0.25, 1e-4, NULL, NULL, &ns));
    double P[2] = {0, 0};
    for (int i = 0; i < N; ++i)
      for (int c = 0; c < 2; ++c) P[c] += m[i] * y[2 * N + 2 * i + c];
    if (fabs(P[0] - P0[0]) > 1e-13 * pscale || fabs(P[1] - P0[1]) > 1e-13 * pscale)
      fail_msg("step %d: momentum (%.17g, %.17g) vs initial (%.17g, %.17g)", step, P[0], P[1], P0[0], P0[1]);
    assert_ok(ctx, mfree_system_rhs(sys, t, y, yd));
    double Lz = 0.0, fscale = 0.0;
    for (int i = 0; i < N; ++i) {
      const double fx = m[i] * yd[2 * N + 2 * i], fz = m[i] * yd[2 * N + 2 * i + 1];
      Lz += y[2 * i] * fz - y[2 * i + 1] * fx;
      fscale += fabs(fx) + fabs(fz);
    }
    if (fabs(Lz) > 1e-12 * fscale * NX * D) fail_msg("step %d: angular momentum rate %g (scale %g)", step, Lz, fscale);
  }
  moved = fabs(y[0] - x0);
  assert_true(t > 3e-3 && moved > 1e-6); /* the patch did move */
  free(yd);
  free(y);
  mfree_system_destroy(&sys);
}

/* 003 eq 65 initial densities make p = rho0 g (H - z) exactly (eq 64); away from the
 * free surface and the bottom the pressure gradient then balances gravity: interior
 * accelerations below 1 % of g at t = 0 (linear completeness of the MLS gradients). */
static void test_hydrostatic_interior(void **s) {
  (void)s;
  double m[N];
  double *y = patch(m, 0, 1);
  const double H = NZ * D;
  mfree_system_t *sys = fluid(m, H, 0.5, 1);
  double p[N];
  assert_ok(ctx, mfree_system_get_pressure(sys, y, p));
  for (int i = 0; i < N; ++i) assert_true(fabs(p[i] - RHO0 * G * (H - y[2 * i + 1])) < 1e-9 * RHO0 * G * H);
  double *yd = calloc(5 * (size_t)N, sizeof(double));
  assert_ok(ctx, mfree_system_rhs(sys, 0.0, y, yd));
  int checked = 0;
  for (int i = 0; i < N; ++i) {
    const double x = y[2 * i], z = y[2 * i + 1], h = 1.5 * D;
    if (x < 3 * h || x > NX * D - 3 * h || z < 3 * h || z > H - 3 * h) continue;
    const double ax = yd[2 * N + 2 * i], az = yd[2 * N + 2 * i + 1];
    if (fabs(ax) > 0.01 * G || fabs(az) > 0.01 * G) fail_msg("particle %d at z %g: a = (%g, %g)", i, z, ax, az);
    ++checked;
  }
  assert_true(checked > 0);
  free(yd);
  free(y);
  mfree_system_destroy(&sys);
}

static int count_steps(void *user, int64_t step, double t, double dt) {
  (void)t;
  (void)dt;
  *(int64_t *)user = step;
  return 0;
}

static void test_failures(void **s) {
  (void)s;
  double m[N];
  double *y = patch(m, 1, 0);
  mfree_system_t *sys = NULL;
  assert_error(ctx, mfree_system_create_fluid(ctx, 1, N, &sys), MFREE_ERR_ARG, "2D or 3D");
  assert_error(ctx, mfree_system_create_fluid(ctx, 2, -1, &sys), MFREE_ERR_ARG, "negative");
  assert_int_equal(mfree_system_create_fluid(NULL, 2, N, &sys), MFREE_ERR_NULL);
  assert_ok(ctx, mfree_system_create_fluid(ctx, 2, N, &sys));
  double *yd = calloc(5 * (size_t)N, sizeof(double));
  assert_error(ctx, mfree_system_rhs(sys, 0.0, y, yd), MFREE_ERR_STATE, "masses");
  mfree_system_destroy(&sys);

  sys = fluid(m, NZ * D, 0.5, 0);
  assert_error(ctx, mfree_system_set_fluid(sys, &RHO0, 0, -1.0, GAMMA, 0.0), MFREE_ERR_ARG, "kappa");
  const double badm = -1.0;
  assert_error(ctx, mfree_system_set_masses(sys, &badm, 0), MFREE_ERR_INPUT, "mass");
  assert_error(ctx, mfree_system_set_smoothing(sys, 0.0), MFREE_ERR_ARG, "h must be");
  const double wn[2] = {0.0, 2.0}, wx[2] = {0.0, 0.0};
  assert_error(ctx, mfree_system_set_walls(sys, 1, wx, wn, 0.01, 10.0), MFREE_ERR_INPUT, "unit vector");
  assert_error(ctx, mfree_system_rhs(sys, 0.0, NULL, yd), MFREE_ERR_NULL, "NULL");

  /* non-finite state: positive status naming the particle */
  double keep = y[2 * N + 7];
  y[2 * N + 7] = NAN;
  assert_error(ctx, mfree_system_rhs(sys, 0.0, y, yd), MFREE_FAIL_NONFINITE, "particle 3");
  y[2 * N + 7] = keep;
  keep = y[4 * N + 5];
  y[4 * N + 5] = -1.0;
  assert_error(ctx, mfree_system_rhs(sys, 0.0, y, yd), MFREE_FAIL_INVALID_DATA, "particle 5");
  y[4 * N + 5] = keep;
  /* the state check's fast path (src/core/systems/fluid.cpp) works on pairs of densities and
   * whole particles: the last particle, an infinite density, a position, two at once */
  keep = y[4 * N + N - 1];
  y[4 * N + N - 1] = INFINITY;
  assert_error(ctx, mfree_system_rhs(sys, 0.0, y, yd), MFREE_FAIL_NONFINITE, "particle 143");
  y[4 * N + N - 1] = keep;
  keep = y[2 * (N - 1) + 1];
  y[2 * (N - 1) + 1] = -INFINITY;
  assert_error(ctx, mfree_system_rhs(sys, 0.0, y, yd), MFREE_FAIL_NONFINITE, "particle 143");
  const double keep2 = y[2 * 40];
  y[2 * 40] = NAN;
  assert_error(ctx, mfree_system_rhs(sys, 0.0, y, yd), MFREE_FAIL_NONFINITE, "particle 40 ");
  y[2 * (N - 1) + 1] = keep;
  y[2 * 40] = keep2;
  assert_ok(ctx, mfree_system_rhs(sys, 0.0, y, yd));

  /* a fixed step above the CFL limit: positive status before anything changes */
  double *y0 = malloc(5 * sizeof(double) * N);
  memcpy(y0, y, 5 * sizeof(double) * N);
  double t = 0.0;
  int64_t ns = -1;
  assert_error(ctx, mfree_system_integrate(sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, 1.0, 0.0, 1e-2, NULL, NULL, &ns),
               MFREE_FAIL_CFL, "CFL");
  assert_memory_equal(y, y0, 5 * sizeof(double) * N);
  assert_true(t == 0.0);

  /* particles leave a tight box: positive status, the last good state kept */
  const double lo[2] = {-0.001, -0.001}, hi[2] = {NX * D + 0.001, NZ * D + 0.001};
  assert_ok(ctx, mfree_system_set_box(sys, lo, hi));
  int64_t seen = 0;
  const mfree_status_t st =
      mfree_system_integrate(sys, MFREE_INTEGRATOR_LEAPFROG, y, &t, 1.0, 0.3, 0.0, count_steps, &seen, &ns);
  assert_int_equal(st, MFREE_FAIL_DOMAIN);
  char msg[512];
  mfree_context_get_last_error(ctx, NULL, msg, sizeof msg);
  assert_non_null(strstr(msg, "left the box"));
  assert_int_equal(ns, seen);
  for (int i = 0; i < N; ++i) /* the returned state is inside */
    for (int c = 0; c < 2; ++c) assert_true(y[2 * i + c] >= lo[c] && y[2 * i + c] <= hi[c]);
  assert_true(t > 0.0 && t < 1.0);
  assert_error(ctx, mfree_system_integrate(sys, (mfree_integrator_t)9, y, &t, 1.0, 0.3, 0.0, NULL, NULL, &ns),
               MFREE_ERR_ARG, "integrator");
  free(y0);
  free(yd);
  free(y);
  mfree_system_destroy(&sys);
}

/* The Shepard fallback threshold (mfree_system_set_shepard_condition; 003 Sect. 6): on
 * the lattice patch every site's condition estimate is below the default 100, so the
 * interpolation matrix S_kj = N_j(x_k) reproduces linear fields (MLS, to round-off) and
 * equals the one with the threshold at infinity; with threshold 1 every row is a Shepard
 * row: non-negative, summing to 1, and no longer linear at the patch's edges. */
static double linear_error(mfree_matrix_t *S, const double *y, double *rowsum_err, double *minval) {
  const int64_t *rp;
  const int32_t *ci;
  const double *v;
  assert_ok(ctx, mfree_matrix_get_csr(S, &rp, &ci, &v));
  double err = 0.0;
  *rowsum_err = 0.0;
  *minval = 1e300;
  for (int k = 0; k < N; ++k) {
    double sx = 0.0, sz = 0.0, s1 = 0.0;
    for (int64_t e = rp[k]; e < rp[k + 1]; ++e) {
      sx += v[e] * y[2 * ci[e]];
      sz += v[e] * y[2 * ci[e] + 1];
      s1 += v[e];
      *minval = fmin(*minval, v[e]);
    }
    err = fmax(err, fmax(fabs(sx - y[2 * k]), fabs(sz - y[2 * k + 1])));
    *rowsum_err = fmax(*rowsum_err, fabs(s1 - 1.0));
  }
  return err;
}

static void test_shepard_condition(void **s) {
  (void)s;
  double m[N];
  double *y = patch(m, 0, 1);
  mfree_system_t *sys = fluid(m, NZ * D, 0.0, 1);
  assert_error(ctx, mfree_system_set_shepard_condition(sys, 0.5), MFREE_ERR_ARG, "Shepard");
  assert_error(ctx, mfree_system_set_shepard_condition(sys, NAN), MFREE_ERR_ARG, "Shepard");
  mfree_matrix_t *S = NULL, *Sinf = NULL, *S1 = NULL;
  double rs, mn;
  assert_ok(ctx, mfree_system_assemble_interpolation(sys, y, &S)); /* default 100 */
  const double e_default = linear_error(S, y, &rs, &mn);
  assert_true(e_default < 1e-12 * NX * D);
  assert_true(mn < 0.0); /* MLS rows at the edges have negative entries */
  assert_ok(ctx, mfree_system_set_shepard_condition(sys, INFINITY));
  assert_ok(ctx, mfree_system_assemble_interpolation(sys, y, &Sinf));
  const int64_t *rp, *rp2;
  const int32_t *ci, *ci2;
  const double *v, *v2;
  assert_ok(ctx, mfree_matrix_get_csr(S, &rp, &ci, &v));
  assert_ok(ctx, mfree_matrix_get_csr(Sinf, &rp2, &ci2, &v2));
  assert_memory_equal(rp, rp2, (N + 1) * sizeof(int64_t));
  assert_memory_equal(v, v2, (size_t)rp[N] * sizeof(double));
  assert_ok(ctx, mfree_system_set_shepard_condition(sys, 1.0));
  assert_ok(ctx, mfree_system_assemble_interpolation(sys, y, &S1));
  const double e_shepard = linear_error(S1, y, &rs, &mn);
  assert_true(rs < 1e-14);
  assert_true(mn >= 0.0);
  assert_true(e_shepard > 0.1 * D); /* edge rows pull towards the interior */
  mfree_matrix_destroy(&S);
  mfree_matrix_destroy(&Sinf);
  mfree_matrix_destroy(&S1);
  mfree_system_destroy(&sys);
  free(y);
}

/* Dummy wall particles (mfree_system_set_dummy_particles; Adami, Hu & Adams 2012): four
 * layers at the fluid spacing below the floor and beside both walls, up to 1.5 H. With
 * them every particle below the free-surface rows is in equilibrium at t = 0 to 1 % of
 * g, the wall rows included (the residual, 0.2-0.5 % of g, is eq 65's p = rho0 g (H - z)
 * against the weight of the slightly denser fluid); the free surface rows are left out
 * (nodal integration's one-sided rows there are off by up to 12 % of g at this
 * resolution). Without walls the bottom rows fall: the contrast shows what the dummies
 * carry. The Galerkin lumped masses still add up to the fluid's mass. */
static void test_dummy_walls(void **s) {
  (void)s;
  enum { L = 4, NZW = 3 * NZ / 2, CAP = (NX + 2 * L) * (NZW + L) };
  double m[N];
  double *y = patch(m, 0, 1);
  const double H = NZ * D;
  double *dx = malloc(2 * sizeof(double) * CAP);
  int nd = 0;
  for (int j = -L; j < NZW; ++j)
    for (int i = -L; i < NX + L; ++i) {
      if (j >= 0 && i >= 0 && i < NX) continue;
      dx[2 * nd] = (i + 0.5) * D;
      dx[2 * nd + 1] = (j + 0.5) * D;
      ++nd;
    }
  double *yd = calloc(5 * (size_t)N, sizeof(double));
  for (int with = 0; with < 2; ++with) {
    mfree_system_t *sys = fluid(m, H, 0.5, 1);
    const double vol = D * D;
    if (with) assert_ok(ctx, mfree_system_set_dummy_particles(sys, nd, dx, &vol, 0));
    assert_ok(ctx, mfree_system_rhs(sys, 0.0, y, yd));
    double amax = 0.0;
    for (int i = 0; i < N; ++i) {
      if (y[2 * i + 1] > H - 2 * 1.5 * D) continue;
      amax = fmax(amax, fmax(fabs(yd[2 * N + 2 * i]), fabs(yd[2 * N + 2 * i + 1])));
      assert_true(yd[4 * N + i] == 0.0); /* at rest: no density rate */
    }
    if (with && amax > 0.01 * G) fail_msg("with dummies: |a| up to %g m/s^2 below the surface rows", amax);
    if (!with && amax < 0.5 * G) fail_msg("without walls the bottom should fall: |a| only %g", amax);
    if (with) {
      assert_true(mfree_test_lumped_mass_rel_diff(ctx, sys, y, m, N) < 1e-12);
      /* the interpolation matrix keeps the fluid columns: n x n */
      mfree_matrix_t *S = NULL;
      assert_ok(ctx, mfree_system_assemble_interpolation(sys, y, &S));
      int32_t nr = 0, nc = 0;
      assert_ok(ctx, mfree_matrix_get_size(S, &nr, &nc, NULL));
      assert_int_equal(nr, N);
      assert_int_equal(nc, N);
      mfree_matrix_destroy(&S);
      /* removing them restores the paper's system */
      assert_ok(ctx, mfree_system_set_dummy_particles(sys, 0, NULL, NULL, 0));
      assert_ok(ctx, mfree_system_rhs(sys, 0.0, y, yd));
      assert_true(fabs(yd[2 * N + 1]) > 0.5 * G);
    }
    mfree_system_destroy(&sys);
  }
  free(yd);
  free(dx);
  free(y);
}

/* Density diffusion (mfree_system_set_density_diffusion; delta-SPH with the MLS-gradient
 * correction): a linear density field at rest gets no density rate, free edges and
 * corners included (exact identity: psi_ji . x_ji = 0 pair by pair), while row-alternating
 * densities are damped at every interior particle. */
static void test_density_diffusion(void **s) {
  (void)s;
  double m[N];
  double *y = patch(m, 1, 1);
  for (int p = 0; p < 2 * N; ++p) y[2 * N + p] = 0.0;
  const double L = NX * D;
  double *yd = calloc(5 * (size_t)N, sizeof(double));
  mfree_system_t *sys = fluid(m, NZ * D, 0.5, 0);
  assert_ok(ctx, mfree_system_set_density_diffusion(sys, 0.1));
  /* row-alternating densities (+-0.1 %) on the jittered patch */
  for (int p = 0; p < N; ++p) y[4 * N + p] = RHO0 * (1.0 + ((p / NX) % 2 ? -1e-3 : 1e-3));
  assert_ok(ctx, mfree_system_rhs(sys, 0.0, y, yd));
  double scale = 0.0;
  for (int j = 2; j < NZ - 2; ++j)
    for (int i = 2; i < NX - 2; ++i) {
      const int p = j * NX + i;
      const double dev = y[4 * N + p] - RHO0;
      if (!(yd[4 * N + p] * dev < 0.0)) fail_msg("particle %d: deviation %g, rate %g", p, dev, yd[4 * N + p]);
      scale = fmax(scale, fabs(yd[4 * N + p]));
    }
  /* a linear field */
  for (int p = 0; p < N; ++p) y[4 * N + p] = RHO0 * (1.0 + 0.004 * (y[2 * p] + 2.0 * y[2 * p + 1]) / L);
  assert_ok(ctx, mfree_system_rhs(sys, 0.0, y, yd));
  for (int p = 0; p < N; ++p)
    if (fabs(yd[4 * N + p]) > 1e-9 * scale) fail_msg("particle %d: rate %g of a linear field", p, yd[4 * N + p]);
  assert_error(ctx, mfree_system_set_density_diffusion(sys, -1.0), MFREE_ERR_ARG, "density-diffusion");
  assert_error(ctx, mfree_system_set_dummy_particles(sys, 1, y, &RHO0, -1), MFREE_ERR_ARG, "stride");
  mfree_system_destroy(&sys);
  free(yd);
  free(y);
}

/* Consistent nodal integration (mfree_system_set_consistent_integration): fluid at rest
 * under a uniform pressure (rho = 1.01 rho0 everywhere, no gravity) on a jittered lattice
 * (+-0.2 d) closed by four layers of dummy particles on all sides. Every node's support
 * then lies in fluid and dummies, so with the correction no particle feels a force (to
 * round-off against p / (rho0 d)); without it the integration-constraint error of nodal
 * integration pushes the particles by a sizeable fraction of p / (rho0 d), the force that
 * destabilises the positions of a still column (t702 test 3). */
static void test_consistent_integration(void **s) {
  (void)s;
  enum { L = 4, CAP = (NX + 2 * L) * (NZ + 2 * L) };
  double m[N];
  double *y = patch(m, 1, 1);
  for (int p = 0; p < 2 * N; ++p) y[2 * N + p] = 0.0;
  for (int p = 0; p < N; ++p) y[4 * N + p] = 1.01 * RHO0;
  double *dx = malloc(2 * sizeof(double) * CAP);
  int nd = 0;
  for (int j = -L; j < NZ + L; ++j)
    for (int i = -L; i < NX + L; ++i) {
      if (j >= 0 && j < NZ && i >= 0 && i < NX) continue;
      dx[2 * nd] = (i + 0.5) * D;
      dx[2 * nd + 1] = (j + 0.5) * D;
      ++nd;
    }
  const double vol = D * D, kap = kappa_of(NZ * D);
  const double scale = kap * (pow(1.01, GAMMA) - 1.0) / (RHO0 * D); /* p / (rho0 d) */
  double *yd = calloc(5 * (size_t)N, sizeof(double));
  double amax[2] = {0, 0};
  for (int on = 0; on < 2; ++on) {
    mfree_system_t *sys = fluid(m, NZ * D, 0.5, 0);
    assert_ok(ctx, mfree_system_set_dummy_particles(sys, nd, dx, &vol, 0));
    assert_ok(ctx, mfree_system_set_consistent_integration(sys, on));
    assert_ok(ctx, mfree_system_rhs(sys, 0.0, y, yd));
    for (int p = 0; p < 2 * N; ++p) amax[on] = fmax(amax[on], fabs(yd[2 * N + p]));
    if (on) {
      assert_error(ctx, mfree_system_set_consistent_integration(sys, 2), MFREE_ERR_ARG, "consistent");
    }
    mfree_system_destroy(&sys);
  }
  if (amax[1] > 1e-10 * scale) fail_msg("with the correction: |a| up to %g (scale %g)", amax[1], scale);
  if (amax[0] < 1e-3 * scale) fail_msg("without the correction: |a| only %g (scale %g)", amax[0], scale);
  print_message("uniform pressure, jittered lattice: |a| %.3g without, %.3g with consistent integration "
                "(p / (rho0 d) = %.3g)\n", amax[0], amax[1], scale);
  free(yd);
  free(dx);
  free(y);
}

/* Velocity smoothing (mfree_system_set_velocity_smoothing): on the jittered free patch
 * with random velocities and densities, the extra forces M_i (a_i(beta) - a_i(0)) are
 * pairwise equal and opposite, so they sum to zero (linear momentum, to round-off, with
 * Galerkin and physical lumping) and are not small; a uniform velocity gets no extra force
 * at all; on the regular lattice a linear velocity field (shear and rotation) gets none
 * at the particles 2h from the edges (symmetric neighbourhoods, to round-off), and a
 * checkerboard of velocities (a zero-energy mode of nodal integration, t702 test 1) is
 * opposed at every interior particle. Positions and densities do not see the term. */
static void rhs_pair(mfree_system_t *sys, const double *y, double beta, double *y0, double *y1) {
  assert_ok(ctx, mfree_system_set_velocity_smoothing(sys, 0.0));
  assert_ok(ctx, mfree_system_rhs(sys, 0.0, y, y0));
  assert_ok(ctx, mfree_system_set_velocity_smoothing(sys, beta));
  assert_ok(ctx, mfree_system_rhs(sys, 0.0, y, y1));
  for (int q = 0; q < 2 * N; ++q) assert_true(y1[q] == y0[q]);
  for (int q = 4 * N; q < 5 * N; ++q) assert_true(y1[q] == y0[q]);
}

static void test_velocity_smoothing(void **s) {
  (void)s;
  double m[N];
  const double beta = 0.1, c = sqrt(GAMMA * kappa_of(NZ * D) / RHO0);
  const double aref = beta * c / (1.5 * D) * 0.3; /* beta c / h times the velocity scale */
  double *y0 = calloc(5 * (size_t)N, sizeof(double)), *y1 = calloc(5 * (size_t)N, sizeof(double));
  for (int lump = MFREE_LUMP_GALERKIN; lump <= MFREE_LUMP_PHYSICAL; ++lump) {
    double *y = patch(m, 1, 0);
    mfree_system_t *sys = fluid(m, NZ * D, 0.5, 0);
    assert_ok(ctx, mfree_system_set_lumping(sys, (mfree_lumping_t)lump));
    rhs_pair(sys, y, beta, y0, y1);
    double Ml[N];
    mfree_test_lumped_masses(ctx, sys, y, 2, N, Ml);
    double P[2] = {0, 0}, scale = 0.0, amax = 0.0;
    for (int i = 0; i < N; ++i) {
      const double Mi = Ml[i];
      const double ax = y1[2 * N + 2 * i] - y0[2 * N + 2 * i], az = y1[2 * N + 2 * i + 1] - y0[2 * N + 2 * i + 1];
      P[0] += Mi * ax;
      P[1] += Mi * az;
      scale += Mi * (fabs(ax) + fabs(az));
      amax = fmax(amax, hypot(ax, az));
    }
    if (amax < 0.1 * aref) fail_msg("lumping %d: smoothing acceleration only %g (scale %g)", lump, amax, aref);
    if (fabs(P[0]) > 1e-12 * scale || fabs(P[1]) > 1e-12 * scale)
      fail_msg("lumping %d: momentum rate (%g, %g), scale %g", lump, P[0], P[1], scale);
    for (int p = 0; p < N; ++p) { /* uniform velocity */
      y[2 * N + 2 * p] = 0.2;
      y[2 * N + 2 * p + 1] = -0.1;
    }
    rhs_pair(sys, y, beta, y0, y1);
    for (int q = 2 * N; q < 4 * N; ++q)
      if (fabs(y1[q] - y0[q]) > 1e-12 * aref) fail_msg("uniform velocity: smoothing acceleration %g", y1[q] - y0[q]);
    mfree_system_destroy(&sys);
    free(y);
  }
  /* regular lattice at rest density: linear field, then checkerboard */
  double *y = patch(m, 0, 1);
  for (int p = 0; p < N; ++p) {
    y[4 * N + p] = RHO0;
    m[p] = RHO0 * D * D;
    y[2 * N + 2 * p] = 0.1 + 20.0 * y[2 * p] - 30.0 * y[2 * p + 1];
    y[2 * N + 2 * p + 1] = -0.2 + 40.0 * y[2 * p] + 10.0 * y[2 * p + 1];
  }
  mfree_system_t *sys = fluid(m, NZ * D, 0.5, 0);
  rhs_pair(sys, y, beta, y0, y1);
  for (int j = 3; j < NZ - 3; ++j)
    for (int i = 3; i < NX - 3; ++i)
      for (int c2 = 0; c2 < 2; ++c2) {
        const int q = 2 * N + 2 * (j * NX + i) + c2;
        if (fabs(y1[q] - y0[q]) > 1e-10 * aref) fail_msg("linear field, particle %d: smoothing acceleration %g", j * NX + i, y1[q] - y0[q]);
      }
  for (int p = 0; p < N; ++p) {
    y[2 * N + 2 * p] = ((p % NX) + (p / NX)) % 2 ? -0.01 : 0.01;
    y[2 * N + 2 * p + 1] = 0.0;
  }
  rhs_pair(sys, y, beta, y0, y1);
  for (int j = 2; j < NZ - 2; ++j)
    for (int i = 2; i < NX - 2; ++i) {
      const int p = j * NX + i;
      const double da = y1[2 * N + 2 * p] - y0[2 * N + 2 * p];
      if (!(da * y[2 * N + 2 * p] < 0.0)) fail_msg("particle %d: velocity %g, smoothing acceleration %g", p, y[2 * N + 2 * p], da);
    }
  assert_error(ctx, mfree_system_set_velocity_smoothing(sys, -1.0), MFREE_ERR_ARG, "velocity-smoothing");
  assert_error(ctx, mfree_system_set_velocity_smoothing(sys, NAN), MFREE_ERR_ARG, "velocity-smoothing");
  mfree_system_destroy(&sys);
  free(y0);
  free(y1);
  free(y);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_conservation),
      cmocka_unit_test(test_conservation_run),
      cmocka_unit_test(test_hydrostatic_interior),
      cmocka_unit_test(test_failures),
      cmocka_unit_test(test_shepard_condition),
      cmocka_unit_test(test_dummy_walls),
      cmocka_unit_test(test_density_diffusion),
      cmocka_unit_test(test_consistent_integration),
      cmocka_unit_test(test_velocity_smoothing),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
