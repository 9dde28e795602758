/* Shared pieces of the SUNDIALS adapter tests (7xx, label dynamics): the Galerkin-SPH
 * fluid patch of paper 003 and block-wise comparisons of states. */
#ifndef MFREE_SUNTEST_H
#define MFREE_SUNTEST_H

#include <nvector/nvector_serial.h>

#include <mfree_sundials.h>

#include "testutil.h"

/* 8 x 8 particles, spacing D, h = 1.5 D, rest density 1000, kappa of 003 eq 125 with
 * H = 0.04, gamma 7, mu 0.5, no gravity, no walls. */
enum { SUN_NX = 8, SUN_N = SUN_NX * SUN_NX, SUN_NEQ = 5 * SUN_N };
#define SUN_D 0.005
#define SUN_RHO0 1000.0
#define SUN_GAMMA 7.0
#define SUN_MU 0.5
#define SUN_H 0.04
#define SUN_U 0.1 /* amplitude of the initial velocity, m/s */

/* kappa = 100 rho0 (2 g H) / gamma (003 eq 125) = 11211.4 Pa. */
double sun_kappa(void);

/* The fluid system of the patch on ctx (masses rho0 D^2, lumped Galerkin mass). */
mfree_system_t *sun_fluid(mfree_context_t *ctx);

/* The initial state: lattice positions ((i + 1/2) D, (j + 1/2) D), rest densities, and
 * velocity parameters equal to the divergence-free field of the stream function
 * psi = U L / pi sin(pi x / L) sin(pi y / L), L = 8 D (u = dpsi/dy, v = -dpsi/dx). */
void sun_initial_state(double *y);

/* The group fixture of the patch's tests: an mfree context, a SUNDIALS context and the
 * initial state in ystart (SUN_NEQ values); each returns 0 on success (cmocka's group
 * setup and teardown). */
int sun_fixture_setup(mfree_context_t **ctx, SUNContext *sunctx, double *ystart);
int sun_fixture_teardown(mfree_context_t **ctx, SUNContext *sunctx);

/* Block-wise difference of two states a, b of the patch, each relative to the size of
 * the reference's motion: positions and densities to max |b - y0| over the block (the
 * displacement and the density change), velocities to max |b|. */
typedef struct {
  double x, v, rho;
} sun_diff_t;
sun_diff_t sun_compare(const double *a, const double *b, const double *y0);
double sun_diff_max(sun_diff_t d);

/* Wall-clock seconds (monotonic). */
double sun_seconds(void);

#endif
