/* The fluid's shape functions chosen through mfree_system_set_approximation: the dam
 * break of paper 003 (the set-up of t063: a column a x 2a released in a tank 5a long,
 * walls of boundary particles, 10 x 20 particles, leap-frog at CFL 0.25) to t = 0.15 s
 * (T = t sqrt(2g/a) = 2.8, the surge well on its way) with the default (MLS, order 1,
 * cubic spline) and with two other choices: RKPM of order 1 with Wendland C2, and MLS of
 * order 1 with the quintic spline (support 3h, not 2h: the neighbour lists follow the
 * kernel). For each choice:
 * - the run succeeds and the state is finite;
 * - the lumped masses sum to the total mass to round-off (a partition of unity: 003 eq 57);
 * - the surge front (the largest x of the particles over a) is within 2 % of the default
 *   run's, and the run is not the default one (some position differs), so the choice
 *   reached the tables;
 * and back to the default, a fresh run is bitwise the default run. Also the refusals:
 * a system that is not a fluid, a bad method, order or kernel, MPFEM (needs a mesh), a
 * kernel without the derivative the method needs; a refused choice leaves the previous
 * one in place. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"

static mfree_context_t *ctx;
static int setup(void **s) { (void)s; return mfree_context_create(&ctx) != MFREE_SUCCESS; }
static int teardown(void **s) { (void)s; return mfree_context_destroy(&ctx) != MFREE_SUCCESS; }

enum { NX = 10, NZ = 2 * NX, N = NX * NZ, NY = 5 * N };
static const double G = 9.81, RHO0 = 1000.0, GAMMA = 7.0, A = 0.05715, CFL = 0.25, T_END = 0.15;

typedef struct {
  mfree_system_t *sys;
  double y[NY], m[N];
} dam_t;

/* The column at rest with its hydrostatic density (003 eq 65) and the tank's walls. */
static void make_dam(dam_t *s) {
  const double H = 2.0 * A, L = 5.0 * A, d = A / NX, h = 1.5 * d;
  const double kappa = 100.0 * RHO0 * 2.0 * G * H / GAMMA; /* 003 eq 125 */
  memset(s->y, 0, sizeof s->y);
  for (int j = 0; j < NZ; ++j)
    for (int i = 0; i < NX; ++i) {
      const int q = j * NX + i;
      const double z = (j + 0.5) * d;
      s->y[2 * q] = (i + 0.5) * d;
      s->y[2 * q + 1] = z;
      s->y[4 * N + q] = RHO0 * pow(1.0 + RHO0 * G * (H - z) / kappa, 1.0 / GAMMA);
      s->m[q] = s->y[4 * N + q] * d * d;
    }
  const double off = 0.5 * d;
  double *wx = NULL, *wn = NULL;
  const int nw = mfree_test_tank_walls(L, d, off, 1.5 * H, &wx, &wn);
  s->sys = mfree_test_fluid_create(ctx, N, s->m, RHO0, kappa, GAMMA, 0.5, h);
  const double g[2] = {0.0, -G};
  assert_ok(ctx, mfree_system_set_gravity(s->sys, g));
  assert_ok(ctx, mfree_system_set_walls(s->sys, nw, wx, wn, 0.7 * h, 10.0));
  const double lo[2] = {-off, -off}, hi[2] = {L + off, 10.0 * H};
  assert_ok(ctx, mfree_system_set_box(s->sys, lo, hi));
  free(wx), free(wn);
}

/* Runs the dam from rest to T_END; returns the surge front over a. */
static double run(dam_t *s) {
  double t = 0.0;
  int64_t steps = 0;
  assert_ok(ctx, mfree_system_integrate(s->sys, MFREE_INTEGRATOR_LEAPFROG, s->y, &t, T_END, CFL, 0.0, NULL,
                                        NULL, &steps));
  assert_true(steps > 0);
  assert_true(fabs(t - T_END) < 1e-12);
  double front = 0.0;
  for (int i = 0; i < NY; ++i) assert_true(isfinite(s->y[i]));
  for (int q = 0; q < N; ++q) front = fmax(front, s->y[2 * q]);
  const double mass_diff = mfree_test_lumped_mass_rel_diff(ctx, s->sys, s->y, s->m, N);
  print_message("%lld steps, front %.4f a, lumped masses vs total %.1e\n", (long long)steps, front / A, mass_diff);
  assert_true(mass_diff <= 1e-12);
  return front / A;
}

static void test_choices_run_the_dam_break(void **state) {
  (void)state;
  dam_t *ref = malloc(sizeof *ref), *alt = malloc(sizeof *alt);
  make_dam(ref);
  const double front0 = run(ref);
  assert_true(front0 > 1.5 && front0 < 3.5); /* the surge moved (starting at 1) */
  const struct {
    mfree_method_t method;
    int32_t order;
    mfree_kernel_t kernel;
  } choices[2] = {{MFREE_METHOD_RKPM, 1, MFREE_KERNEL_WENDLAND_C2}, {MFREE_METHOD_MLS, 1, MFREE_KERNEL_QUINTIC_SPLINE}};
  for (int c = 0; c < 2; ++c) {
    make_dam(alt);
    assert_ok(ctx, mfree_system_set_approximation(alt->sys, choices[c].method, choices[c].order, choices[c].kernel, 0.0));
    const double front = run(alt);
    print_message("choice %d: front %.4f a, default %.4f a\n", c, front, front0);
    assert_true(fabs(front - front0) <= 0.02 * front0);
    assert_true(memcmp(alt->y, ref->y, sizeof ref->y) != 0);
    mfree_system_destroy(&alt->sys);
    /* back to the default: the default run, bitwise */
    make_dam(alt);
    assert_ok(ctx, mfree_system_set_approximation(alt->sys, choices[c].method, choices[c].order, choices[c].kernel, 0.0));
    assert_ok(ctx, mfree_system_set_approximation(alt->sys, MFREE_METHOD_MLS, 1, MFREE_KERNEL_CUBIC_SPLINE, 0.0));
    run(alt);
    assert_memory_equal(alt->y, ref->y, sizeof ref->y);
    mfree_system_destroy(&alt->sys);
  }
  mfree_system_destroy(&ref->sys);
  free(ref), free(alt);
}

static void test_refusals(void **state) {
  (void)state;
  dam_t *s = malloc(sizeof *s), *ref = malloc(sizeof *ref);
  make_dam(s);
  assert_int_equal(mfree_system_set_approximation(NULL, MFREE_METHOD_MLS, 1, MFREE_KERNEL_CUBIC_SPLINE, 0.0),
                   MFREE_ERR_NULL);
  assert_error(ctx, mfree_system_set_approximation(s->sys, (mfree_method_t)0, 1, MFREE_KERNEL_CUBIC_SPLINE, 0.0),
               MFREE_ERR_ARG, "method");
  assert_error(ctx, mfree_system_set_approximation(s->sys, MFREE_METHOD_MLS, 1, (mfree_kernel_t)99, 0.0),
               MFREE_ERR_ARG, "kernel");
  assert_error(ctx, mfree_system_set_approximation(s->sys, MFREE_METHOD_MLS, 4, MFREE_KERNEL_CUBIC_SPLINE, 0.0),
               MFREE_ERR_UNSUPPORTED, "orders");
  assert_error(ctx, mfree_system_set_approximation(s->sys, MFREE_METHOD_KB_METHOD1, 2, MFREE_KERNEL_CUBIC_SPLINE, 0.0),
               MFREE_ERR_UNSUPPORTED, "fixed order");
  assert_error(ctx, mfree_system_set_approximation(s->sys, MFREE_METHOD_MPFEM, 1, MFREE_KERNEL_COSINE, 0.0),
               MFREE_ERR_UNSUPPORTED, "mesh");
  assert_error(ctx, mfree_system_set_approximation(s->sys, MFREE_METHOD_RKPM, 1, MFREE_KERNEL_LINEAR, 0.0),
               MFREE_ERR_UNSUPPORTED, "linear kernel");
  /* the refusals left the default: the default run, bitwise */
  make_dam(ref);
  run(s);
  run(ref);
  assert_memory_equal(s->y, ref->y, sizeof ref->y);
  mfree_system_destroy(&s->sys);
  mfree_system_destroy(&ref->sys);
  free(s), free(ref);

  /* not a fluid: a 1D collocation bar (t703's set-up, smaller) */
  enum { NB = 11 };
  double x[NB];
  const double dx = 0.1, h = 1.5 * dx, vol = dx;
  for (int i = 0; i < NB; ++i) x[i] = i * dx;
  mfree_particles_t *ps = NULL;
  mfree_approximant_t *a = NULL;
  mfree_assembler_t *as = NULL;
  mfree_system_t *bar = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, 1, NB, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 1, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_volumes(ps, &vol, 0, MFREE_COPY));
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_SSPH, &a));
  assert_ok(ctx, mfree_approximant_set_kernel(a, MFREE_KERNEL_REVISED_SUPER_GAUSS, 1.6));
  assert_ok(ctx, mfree_approximant_set_order(a, 2));
  assert_ok(ctx, mfree_approximant_set_derivatives(a, 7));
  assert_ok(ctx, mfree_assembler_create(ctx, a, NULL, MFREE_FORM_COLLOCATION_LAPLACE, &as));
  assert_ok(ctx, mfree_assembler_setup(as));
  assert_ok(ctx, mfree_system_create_elastodynamic(ctx, as, 1.0, &bar));
  assert_error(ctx, mfree_system_set_approximation(bar, MFREE_METHOD_MLS, 1, MFREE_KERNEL_CUBIC_SPLINE, 0.0),
               MFREE_ERR_UNSUPPORTED, "not a fluid");
  mfree_system_destroy(&bar);
  mfree_assembler_destroy(&as);
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_choices_run_the_dam_break), cmocka_unit_test(test_refusals)};
  return cmocka_run_group_tests(tests, setup, teardown);
}
