/* libFuzzer harness: semi-discrete systems. Bytes -> (a) a weakly compressible fluid
 * (2D or 3D, particles jittered around a lattice, state with NaN, Inf, coincident
 * particles, zero or negative densities; fluid properties, masses, smoothing, gravity,
 * a box, walls, dummy particles, the Shepard threshold, density diffusion, velocity
 * smoothing, consistent integration, lumping), its right-hand side, mass and
 * interpolation matrices, pressure, smoothed velocity, a few integrator steps; (b) linear elastodynamics by Galerkin (Laplace or elasticity
 * stiffness with a mass assembler) and by collocation, its right-hand side and stress.
 * Oracles: documented statuses; a success status of the right-hand side on a finite
 * state gives a finite rate. */
#include "fuzz_util.h"

enum { MAXM = 5, MAXN = MAXM * MAXM * MAXM };

static double history(void *user, double t) {
  (void)user;
  return t < 1e300 ? 1.0 + t : NAN;
}

static void fluid(fz_bytes_t *b, mfree_context_t *ctx) {
  const int dim = 2 + (int)(fz_u8(b) & 1);
  const int m = 2 + (int)(fz_u8(b) % (MAXM - 1));
  const int n = dim == 2 ? m * m : m * m * m;
  const unsigned opts = fz_u8(b), opts2 = fz_u8(b), opts3 = fz_u8(b);
  const double sp = 1.0 / m;
  static double y[7 * MAXN], ydot[7 * MAXN], mass[MAXN], p[MAXN], vhat[3 * MAXN], rho0[MAXN], walls[6 * 8],
      dummy[3 * 8];
  const int npos = dim * n;
  int finite = 1;
  for (int q = 0; q < n; ++q) {
    const int idx[3] = {q % m, (q / m) % m, q / (m * m)};
    for (int c = 0; c < dim; ++c) {
      const unsigned j = fz_u8(b);
      y[dim * q + c] = (idx[c] + 0.5 + (j == 255 ? NAN : j == 254 ? INFINITY : (j / 255.0 - 0.5) * 0.5)) * sp;
      finite &= j < 254;
      y[npos + dim * q + c] = ((int)fz_u8(b) - 128) * 0.01;
    }
    const unsigned j = fz_u8(b);
    y[2 * npos + q] = j == 0 ? 0.0 : j == 1 ? -1000.0 : 1000.0 * (1.0 + (j - 128) * 0.0005);
    finite &= j > 1;
    mass[q] = 1000.0 * pow(sp, dim);
    rho0[q] = 1000.0 + q;
  }
  mfree_system_t *sys = NULL;
  FZ_CHECK(mfree_system_create_fluid(ctx, dim, n, &sys));
  if (!sys) return;
  if (opts & 1) {
    const double kappa = fz_positive(b, 10.0), gamma = 1.0 + (fz_u8(b) % 8);
    /* one rest density for all, or one per particle */
    FZ_CHECK(mfree_system_set_fluid(sys, rho0, (opts3 & 2) ? 1 : 0, kappa, gamma, (fz_u8(b) % 4) * 0.001));
  }
  if (!(opts & 2)) FZ_CHECK(mfree_system_set_masses(sys, mass, 1));
  if (!(opts & 4)) FZ_CHECK(mfree_system_set_smoothing(sys, (opts2 & 1) ? fz_positive(b, sp) : 1.5 * sp));
  if (opts & 8) {
    const double g[3] = {0.0, -9.81, 0.0};
    FZ_CHECK(mfree_system_set_gravity(sys, g));
  }
  if (opts & 16) {
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, (opts2 & 2) ? -1.0 : 1.0};
    FZ_CHECK(mfree_system_set_box(sys, lo, hi));
  }
  if (opts & 32) {
    const int nw = (int)(fz_u8(b) % 8);
    for (int w = 0; w < nw; ++w)
      for (int c = 0; c < dim; ++c) walls[dim * w + c] = (c == 0) ? -0.05 : w * 0.1, walls[3 * 8 + dim * w + c] = c == 0;
    FZ_CHECK(mfree_system_set_walls(sys, nw, walls, walls + 3 * 8, 0.7 * sp, (opts2 & 4) ? -1.0 : 10.0));
  }
  if (opts & 64) {
    const int nd = (int)(fz_u8(b) % 8);
    const double vol = pow(sp, dim);
    for (int w = 0; w < nd; ++w)
      for (int c = 0; c < dim; ++c) dummy[dim * w + c] = (c == 1) ? -0.5 * sp : w * sp;
    FZ_CHECK(mfree_system_set_dummy_particles(sys, nd, dummy, &vol, 0));
  }
  if (opts & 128) FZ_CHECK(mfree_system_set_shepard_condition(sys, (opts2 & 8) ? NAN : 1.0 + (fz_u8(b) % 200)));
  if (opts2 & 16) FZ_CHECK(mfree_system_set_density_diffusion(sys, (fz_u8(b) % 4) * 0.05));
  if (opts2 & 32) FZ_CHECK(mfree_system_set_velocity_smoothing(sys, (fz_u8(b) % 3) * 0.25));
  if (opts2 & 64) FZ_CHECK(mfree_system_set_lumping(sys, (mfree_lumping_t)(fz_u8(b) % 4)));
  if (opts3 & 1) FZ_CHECK(mfree_system_set_consistent_integration(sys, (int32_t)(fz_u8(b) % 3) - 1));
  int32_t neq = 0;
  FZ_TRAP_IF(mfree_system_get_size(sys, &neq) != MFREE_SUCCESS);
  /* extreme (valid) stiffness or smoothing may overflow the rate: no finiteness oracle */
  finite &= !(opts & 1) && !(opts2 & 1);
  const mfree_status_t st = mfree_system_rhs(sys, 0.0, y, ydot);
  FZ_TRAP_IF(!fz_valid_status(st));
  if (st == MFREE_SUCCESS && finite)
    for (int32_t k = 0; k < neq; ++k) FZ_TRAP_IF(!isfinite(ydot[k]));
  mfree_matrix_t *M = NULL, *S = NULL;
  FZ_CHECK(mfree_system_assemble_mass(sys, y, (int32_t)(opts2 >> 7), &M));
  FZ_CHECK(mfree_system_assemble_interpolation(sys, y, &S));
  FZ_CHECK(mfree_system_get_pressure(sys, y, p));
  FZ_CHECK(mfree_system_get_velocity(sys, y, vhat));
  if (finite && (fz_u8(b) & 1)) {
    double t = 0.0;
    int64_t steps = 0;
    FZ_CHECK(mfree_system_integrate(sys, (mfree_integrator_t)(1 + fz_u8(b) % 3), y, &t, 1e-4, 0.2, 1e-5, NULL,
                                    NULL, &steps));
  }
  mfree_matrix_destroy(&M);
  mfree_matrix_destroy(&S);
  mfree_system_destroy(&sys);
}

static void elastic(fz_bytes_t *b, mfree_context_t *ctx) {
  const int dim = 1 + (int)(fz_u8(b) % 2);
  const int m = 3 + (int)(fz_u8(b) % 4);
  const int n = dim == 1 ? m : m * m;
  const unsigned opts = fz_u8(b);
  const double sp = 1.0 / (m - 1);
  static double x[2 * 36], y[4 * 36], ydot[4 * 36], sig[3 * 36];
  for (int q = 0; q < n; ++q) {
    x[dim * q] = (q % m) * sp;
    if (dim == 2) x[dim * q + 1] = (q / m) * sp;
  }
  const double h = (1.5 + (fz_u8(b) % 4) * 0.5) * sp, vol = pow(sp, dim);
  mfree_particles_t *ps = NULL;
  mfree_approximant_t *a = NULL;
  mfree_assembler_t *K = NULL, *Mass = NULL;
  mfree_system_t *sys = NULL;
  FZ_CHECK(mfree_particles_create(ctx, dim, n, &ps));
  if (!ps) return;
  FZ_CHECK(mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, dim, MFREE_COPY));
  FZ_CHECK(mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  FZ_CHECK(mfree_particles_set_volumes(ps, &vol, 0, MFREE_COPY));
  FZ_CHECK(mfree_particles_set_search(ps, MFREE_SEARCH_GATHER, 3.0));
  FZ_CHECK(mfree_approximant_create(ctx, ps, (mfree_method_t)(1 + fz_u8(b) % 12), &a));
  const int collocation = opts & 1;
  const mfree_form_t kf = collocation ? (dim == 1 ? MFREE_FORM_COLLOCATION_LAPLACE : MFREE_FORM_COLLOCATION_PLANE_STRESS)
                                      : (dim == 1 ? MFREE_FORM_LAPLACE : MFREE_FORM_ELASTICITY_PLANE_STRAIN);
  if (a) FZ_CHECK(mfree_assembler_create(ctx, a, NULL, kf, &K));
  if (a && !collocation) FZ_CHECK(mfree_assembler_create(ctx, a, NULL, (opts & 2) ? MFREE_FORM_MASS : MFREE_FORM_MASS_LUMPED, &Mass));
  if (K && (opts & 4)) {
    const int32_t node0 = 0;
    FZ_CHECK(mfree_assembler_add_dirichlet_nodes(K, 1, &node0, 3, NULL, NULL));
  }
  mfree_status_t st = K ? mfree_assembler_setup(K) : MFREE_ERR_STATE;
  FZ_TRAP_IF(!fz_valid_status(st));
  if (Mass) FZ_CHECK(mfree_assembler_setup(Mass));
  if (collocation && K) FZ_CHECK(mfree_system_create_elastodynamic(ctx, K, (opts & 8) ? -1.0 : 1.0, &sys));
  else if (K && Mass) FZ_CHECK(mfree_system_create_elastodynamic_galerkin(ctx, K, Mass, &sys));
  if (sys) {
    int32_t neq = 0;
    FZ_TRAP_IF(mfree_system_get_size(sys, &neq) != MFREE_SUCCESS);
    if (neq <= 4 * 36) {
      for (int32_t k = 0; k < neq; ++k) {
        const unsigned w = fz_u8(b);
        y[k] = w == 255 ? NAN : ((int)w - 128) * 1e-3;
      }
      if (opts & 16) FZ_CHECK(mfree_system_set_load_history(sys, history, NULL));
      const double t = (opts & 32) ? 1e301 : 0.5;
      FZ_CHECK(mfree_system_rhs(sys, t, y, ydot));
      if (collocation) FZ_CHECK(mfree_system_get_stress(sys, t, y, sig));
    }
  }
  mfree_system_destroy(&sys);
  mfree_assembler_destroy(&Mass);
  mfree_assembler_destroy(&K);
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  fz_bytes_t b = {data, size};
  mfree_context_t *ctx = NULL;
  if (mfree_context_create(&ctx) != MFREE_SUCCESS) return 0;
  if (fz_u8(&b) & 1) fluid(&b, ctx);
  else elastic(&b, ctx);
  mfree_context_destroy(&ctx);
  return 0;
}
