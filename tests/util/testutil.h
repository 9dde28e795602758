/* Shared helpers for the cmocka tests. */
#ifndef MFREE_TESTUTIL_H
#define MFREE_TESTUTIL_H

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
/* cmocka needs the three headers above first */
#include <cmocka.h>
#include <stdlib.h>

#include <mfree.h>

/* Assert a call returns `expected`; on mismatch print the context's message. */
#define assert_status(ctx, call, expected)                                               \
  do {                                                                                   \
    mfree_status_t st_ = (call);                                                         \
    if (st_ != (expected)) {                                                             \
      char msg_[1024] = "";                                                              \
      if (ctx) mfree_context_get_last_error((ctx), NULL, msg_, sizeof msg_);             \
      fail_msg("%s returned %d (%s), expected %d; last error: %s", #call, (int)st_,      \
               mfree_status_string(st_), (int)(expected), msg_);                         \
    }                                                                                    \
  } while (0)

#define assert_ok(ctx, call) assert_status(ctx, call, MFREE_SUCCESS)

/* Assert a call fails with `expected` and leaves a non-empty message mentioning
 * `needle` (may be NULL) on the context. */
void mfree_test_expect_error(mfree_context_t *ctx, mfree_status_t got, mfree_status_t expected,
                             const char *needle, const char *what);
#define assert_error(ctx, call, expected, needle) \
  mfree_test_expect_error((ctx), (call), (expected), (needle), #call)

/* A published number checked: got within tol of want, else the test fails naming src (the
 * paper, table and row the number comes from). The caller includes <math.h>. */
#define expect_near(got, want, tol, src)                                                   \
  do {                                                                                     \
    const double g_ = (got), w_ = (want), t_ = (tol);                                      \
    if (!(fabs(g_ - w_) <= t_))                                                            \
      fail_msg("%s: got %.8g, expected %.8g +- %.3g", (src), g_, w_, t_);                  \
  } while (0)

/* Deterministic uniform random numbers in [0, 1) (xorshift64*). */
typedef struct { uint64_t s; } mfree_rng_t;
void mfree_rng_seed(mfree_rng_t *r, uint64_t seed);
double mfree_rng_uniform(mfree_rng_t *r);

/* The lumped masses M_i (n values) of a fluid system at state y: the velocity block of
 * mfree_system_assemble_mass (consistent = 0). Fails the test unless every velocity row
 * holds one diagonal entry, equal for all components of a particle, and the position and
 * density rows are identity rows. */
void mfree_test_lumped_masses(mfree_context_t *ctx, mfree_system_t *sys, const double *y, int dim, int n,
                              double *Mi);

/* Fluid systems: the Galerkin lumped masses of mfree_system_assemble_mass (row sums at the
 * first velocity component of each particle) summed over the n particles, and the total
 * of the particle masses m; returns |lumped - total| / total (003 eq 57 makes it zero). */
double mfree_test_lumped_mass_rel_diff(mfree_context_t *ctx, mfree_system_t *sys, const double *y,
                                       const double *m, int n);

/* The wall particles of examples/dam_break's tank (003 Sect. 6.2): a floor and two end walls
 * at spacing d / 3, set back by off from the fluid's edges x = 0, x = L and z = 0, up to
 * z = top, unit normals into the fluid. Returns the count; *x and *normals (2 values per
 * particle) are the caller's to free. */
int mfree_test_tank_walls(double L, double d, double off, double top, double **x, double **normals);

/* A 2D fluid system of n particles with masses m: one fluid of rest density rho0, Tait kappa
 * and gamma, viscosity mu, smoothing length h (no gravity, no walls). */
mfree_system_t *mfree_test_fluid_create(mfree_context_t *ctx, int n, const double *m, double rho0, double kappa,
                                        double gamma, double mu, double h);

/* The approximant the fluid's rows equal ([CuetoFelgueroso2004] Sect. 3): linear MLS with
 * the cubic spline, falling back to lower order, set up on a new particle set of n
 * particles of dimension dim at positions y (AoS, copied), support h (one value) and
 * volumes vol (n values, copied; NULL: none). Both handles are the caller's to destroy. */
void mfree_test_fluid_approximant(mfree_context_t *ctx, int dim, int n, const double *y, double h,
                                  const double *vol, mfree_particles_t **ps, mfree_approximant_t **a);

/* The collocation bar of paper 001 Sect. 6.4: n particles x_i = i L / (n - 1) written into
 * x (n values, borrowed by the set: they must outlive the bar), h = 1.5 dx, volumes dx;
 * SSPH with the revised super Gauss (a = 1.6), quadratic basis, derivatives to the second;
 * the collocation Laplacian with coefficient E (1D: rho u'' = E u''), traction nodes at
 * both ends (normals -1 and +1) loaded by traction; the elastodynamic system of density
 * rho with the load history history. Fails the test on any error. */
typedef struct {
  mfree_particles_t *ps;
  mfree_approximant_t *a;
  mfree_assembler_t *as;
  mfree_system_t *sys;
} mfree_test_bar_t;
mfree_test_bar_t mfree_test_bar_create(mfree_context_t *ctx, int n, double L, double E, double rho, double *x,
                                       mfree_field_fn traction, mfree_history_fn history);
void mfree_test_bar_destroy(mfree_test_bar_t *b);

/* 1 in optimised builds. Unoptimised ones (the asan preset compiles the tests without
 * __OPTIMIZE__) run Eigen about 100 times slower than Release: there a test checks a
 * reduced matrix, unless MFREE_TEST_FULL is set (to anything) in the environment. Inline,
 * so that the calling test's own compilation decides. */
static inline int mfree_test_full_matrix(void) {
#if defined(__OPTIMIZE__)
  return 1;
#else
  return getenv("MFREE_TEST_FULL") != NULL;
#endif
}

/* The backend a conformance test runs on: MFREE_BACKEND_REF when its first argument is
 * "ref" (CTest registers those tests once more as <name>-ref), else MFREE_BACKEND_OPT. */
int32_t mfree_test_backend(int argc, char **argv);

#endif
