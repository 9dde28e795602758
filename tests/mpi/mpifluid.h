/* The dam break of paper 003 (Martin & Moyce's column, the examples' set-up: water
 * block a wide and 2a high in a tank 5a long, leap-frog) for the fluid on ranks: every
 * rank builds the same particles (global id = index), a decomposition gives each its
 * owned particles, and a halo plan of libmfree_mpi its ghosts and the system's callbacks
 * (mfree_halo_create_fluid). */
#ifndef MFREE_MPIFLUID_H
#define MFREE_MPIFLUID_H

#include <mpi.h>
#include <stdint.h>

#include "mfree.h"
#include "mfree_mpi.h"

typedef struct {
  int n, nwall;
  double a, d, h, kappa;
  double *y;        /* 5 n: positions, velocities, densities of every particle */
  double *m;        /* n masses */
  double *wx, *wn;  /* wall particles and their normals (2 per wall particle) */
} damb_t;

/* nx x nz particles at rest, hydrostatic densities (003 eq 65). */
void damb_make(damb_t *b, int nx, int nz);
void damb_free(damb_t *b);
/* Everything but the masses: Tait (rho0 1000, gamma 7, kappa), viscosity, h, gravity,
 * the walls (003 Sect. 6.2). */
mfree_status_t damb_configure(const damb_t *b, mfree_system_t *sys);

/* An open channel in the same structure (t195, t198): n particles, all dormant, spread
 * far upstream (x = -1 - i d, d = 0.01 m), walls along y = -d/2 and y = W + d/2 (W = 0.06 m,
 * spacing d/3), h = 1.5 d, sound speed 10 m/s; damb_configure sets the rest (gravity
 * too). */
void mpifluid_channel(damb_t *b, int n);
/* The channel's open boundaries on sys: every particle dormant, an inflow gate of width W
 * at x = 0 (six points, spacing d, water at speed m/s, or 1 m/s for speed <= 0) and an
 * outflow plane at x = 0.155 m. */
mfree_status_t mpifluid_open(mfree_system_t *sys, double speed);

/* owner[i] = the rank of particle i by size slabs of the water block along x (the
 * decomposition most fluid tests on ranks use). */
void mpifluid_slabs(const damb_t *b, int size, int *owner);
/* The start of those tests: mpitest_start (its context returned, this rank and the number
 * of ranks of MPI_COMM_WORLD), the dam break of nx x nz particles in *b (damb_make) and
 * *owner, b->n values by mpifluid_slabs over the ranks (to be freed). */
mfree_context_t *mpifluid_start(int *argc, char ***argv, int *rank, int *size, damb_t *b, int nx, int nz,
                                int **owner);

/* The dam break on the ranks of comm: owner[i] is the rank owning particle i. The owned
 * items are listed in ascending id order, or descending with reverse (the local order
 * must not matter). */
typedef struct {
  mfree_halo_t *halo;
  mfree_system_t *sys;
  int n_owned, n_ghost;
  int64_t *id; /* owned then ghosts */
  double *y;   /* the owned particles' state (5 n_owned) */
} rankfluid_t;
/* Collective; the status of the system's creation (every rank the same). */
mfree_status_t rankfluid_make(rankfluid_t *r, mfree_context_t *ctx, MPI_Comm comm, const damb_t *b,
                              const int *owner, double width, int reverse);
void rankfluid_free(rankfluid_t *r);

/* The fault tests' start: mpifluid_start with the dam break of 12 x 24 particles on slabs,
 * the ghost layer 4 h + 2 d deep (*width, unless width is NULL), and two systems alike (rankfluid_make, ids
 * ascending): *s, which sees the bad calls, and *twin, which sees only the good ones (a
 * failed creation is a failed check). mpifluid_pair_free frees all but the context. */
mfree_context_t *mpifluid_pair(int *argc, char ***argv, int *rank, int *size, damb_t *b, int **owner,
                               double *width, rankfluid_t *s, rankfluid_t *twin);
void mpifluid_pair_free(damb_t *b, int *owner, rankfluid_t *s, rankfluid_t *twin);

/* Every owned item's per values (vals: per values per owned item, in the items' order),
 * gathered on every rank of comm by global id: out holds per values per particle. */
void mpifluid_collect(MPI_Comm comm, int n_owned, const int64_t *id, const double *vals, int per, double *out);
/* The owned state y (positions, velocities, densities of the owned items) gathered by
 * global id into out, the state of all n particles in the system's layout. */
void mpifluid_state(MPI_Comm comm, const rankfluid_t *r, const double *y, int n, double *out);

/* Absolute tolerances of the ARKODE tests for no owned particles' state: 1e-2 d for
 * positions, 1e-2 m/s for velocities, 1 kg/m3 for densities. */
void mpifluid_tolerances(const damb_t *b, int no, double *atol);

/* Progress callback stopping after *(int64_t *)user steps. */
int32_t mpifluid_stop_at(void *user, int64_t step, double t, double dt);
/* The context's last message (a static buffer). */
const char *mpifluid_error(const mfree_context_t *ctx);

#endif
