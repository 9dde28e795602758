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

/* Builds the bar on comm (collective); 0 on success. */
int mpibar_make(mpibar_t *b, mfree_context_t *ctx, MPI_Comm comm, int n, int how);
void mpibar_free(mpibar_t *b);
/* The pulse T0 long (the load history of the system). */
double mpibar_pulse(void *user, double t);
/* Every rank's owned values (ncomp per owned particle, in the bar's local order) into
 * out[id * ncomp + c] on every rank (n ncomp values). Collective. */
void mpibar_collect(const mpibar_t *b, const double *vals, int ncomp, double *out);
/* The serial system of the same bar (mfree_system_create_elastodynamic, t703's). */
typedef struct {
  mfree_particles_t *ps;
  mfree_approximant_t *a;
  mfree_assembler_t *as;
  mfree_system_t *sys;
  double *x;
} serialbar_t;
int serialbar_make(serialbar_t *b, mfree_context_t *ctx, int n);
void serialbar_free(serialbar_t *b);

#endif
