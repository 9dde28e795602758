/* The elastodynamic bar of paper 001 Sect. 6.4 (as t703: E = 200 GPa, rho = 7865 kg/m3,
 * L = 0.1 m, -1 GPa at the right end for T0 = 3 us, left end free; SSPH collocation,
 * revised super Gauss a = 1.6, h = 1.5 dx, quadratic basis) on the ranks of a
 * communicator: particle i has global id i and lies at x = i dx; its owner is chosen by
 * a decomposition, the ghosts come from a halo plan. */
#ifndef MFREE_MPIBAR_H
#define MFREE_MPIBAR_H

#include <mpi.h>
#include <stdint.h>

#include "mfree.h"
#include "mfree_mpi.h"

#define BAR_L 0.1
#define BAR_E 200e9
#define BAR_RHO 7865.0
#define BAR_T0 3e-6

/* Decompositions: contiguous slabs, slabs in reverse rank order, owners by a hash of
 * the id (scattered: many ghosts), everything on the last rank (the others empty). */
enum { BAR_SLAB = 0, BAR_REVERSED = 1, BAR_HASHED = 2, BAR_LAST = 3 };

typedef struct {
  MPI_Comm comm;
  int n, n_owned, n_ghost;
  mfree_halo_t *halo;
  mfree_particles_t *ps;
  mfree_approximant_t *a;
  mfree_assembler_t *as;
  mfree_system_t *sys;
  double *x;   /* n_owned + n_ghost positions */
  int64_t *id; /* their global ids */
} mpibar_t;

/* The discretisations: t703's collocation; t704's Galerkin (MLS, linear basis, cubic
 * spline, h = 1.5 dx, K = int E Phi' Phi' on 2-point Gauss cells between the particles,
 * the end load as a point traction at x = L, the lumped mass) with the left end free or
 * held by a node row (u(0) = 0, an essential condition), and the same Galerkin bar on
 * nodal quadrature (refused on ranks). On ranks each rank passes the Gauss points and the
 * traction point within one support radius of its owned particles, in the cells' order. */
enum { BAR_COLLOCATION = 0, BAR_GALERKIN = 1, BAR_GALERKIN_FIXED = 2, BAR_GALERKIN_NODAL = 3 };

/* Builds the bar on comm (collective); 0 on success. */
int mpibar_make(mpibar_t *b, mfree_context_t *ctx, MPI_Comm comm, int n, int how);
/* The same with one of the discretisations above. */
int mpibar_make_kind(mpibar_t *b, mfree_context_t *ctx, MPI_Comm comm, int n, int how, int kind);
void mpibar_free(mpibar_t *b);
/* The faults every elastodynamic system on ranks answers alike, on MPI_COMM_WORLD (b on
 * slabs of n particles, y its zero state, yd room for the rate): a NaN displacement, then
 * a NaN velocity, on the last rank (its first owned particle): mfree_system_rhs and
 * mfree_system_integrate return MFREE_FAIL_NONFINITE on every rank, naming the rank and
 * the global id, the integration before any step; a load history that turns NaN on the
 * last rank after 1 us: every rank stops at the same step and time, y the last good
 * state. Leaves the pulse as the history. */
void mpibar_check_faults(mpibar_t *b, mfree_context_t *ctx, double *y, double *yd);
/* The pulse T0 long (the load history of the system). */
double mpibar_pulse(void *user, double t);
/* Every rank's owned values (ncomp per owned particle, in the bar's local order) into
 * out[id * ncomp + c] on every rank (n ncomp values). Collective. */
void mpibar_collect(const mpibar_t *b, const double *vals, int ncomp, double *out);
/* The serial system of the same bar (mfree_system_create_elastodynamic, t703's; Galerkin:
 * mfree_system_create_elastodynamic_galerkin with a lumped mass assembler on the same
 * points). */
typedef struct {
  mfree_particles_t *ps;
  mfree_approximant_t *a;
  mfree_assembler_t *as, *mass;
  mfree_system_t *sys;
  double *x;
} serialbar_t;
int serialbar_make(serialbar_t *b, mfree_context_t *ctx, int n);
int serialbar_make_kind(serialbar_t *b, mfree_context_t *ctx, int n, int kind);
/* The same Galerkin bar with the mass assembler's form (MFREE_FORM_MASS: the consistent
 * mass, the one-process equal of the consistent mass's products on ranks). */
int serialbar_make_mass(serialbar_t *b, mfree_context_t *ctx, int n, int kind, mfree_form_t mass_form);
void serialbar_free(serialbar_t *b);

#endif
