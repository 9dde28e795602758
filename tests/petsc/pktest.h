/* Shared helpers of the libmfree_petsc tests (label mpi): node clouds (paper 000's
 * cantilever beam, a 3D block), decompositions over ranks, each rank's local particle
 * set (owned nodes, then the halo the assembler needs), and the assembler of a problem
 * on any subset of the cloud. */
#ifndef MFREE_PKTEST_H
#define MFREE_PKTEST_H

#include <stdint.h>

#include <mfree_petsc.h>

#include "testutil.h"

enum { PK_BEAM = 1, PK_BLOCK = 2 };
enum { PK_SLAB = 1, PK_RANDOM = 2, PK_BISECT = 3 };
enum { PK_NODAL = 0, PK_GAUSS = 1 };

/* The global problem: nodes (gid = index), volumes, support, boundary and quadrature
 * points in one fixed order. */
typedef struct {
  int kind, dim, quad;
  int32_t n;
  double *x, *vol;
  double h, R; /* support h and search radius R = kappa h */
  /* background Gauss points (PK_GAUSS) */
  int32_t nq;
  double *qx, *qw;
  /* beam: traction points at x = L, penalty points at x = 0 */
  int32_t nt, np;
  double *tx, *tw, *px, *pw;
  /* beam constants (paper 000 Sect. 6.2.1) */
  double P, L, D, E, nu;
} pk_problem_t;

void pk_problem_beam(pk_problem_t *p, int32_t nx, int32_t ny, int quad);
void pk_problem_block(pk_problem_t *p, int32_t nx, int32_t ny, int32_t nz);
void pk_problem_free(pk_problem_t *p);

/* Rank of each node for a decomposition over size ranks. */
void pk_partition(const pk_problem_t *p, int how, int size, uint64_t seed, int *part);

/* One rank's particles: idx[0..nowned) owned, then the inner halo (non-owned nodes
 * within R of an owned node: quadrature points of nodal quadrature, non-ghosts of the
 * set), then the outer halo (within 2R: ghosts of the set); each group shuffled with
 * seed (0: ascending global id). */
typedef struct {
  int32_t nlocal, nowned, ninner, nghost;
  int32_t *idx;
  int64_t *gid;
} pk_local_t;

void pk_local(const pk_problem_t *p, const int *part, int rank, uint64_t seed, pk_local_t *l);
void pk_local_all(const pk_problem_t *p, pk_local_t *l); /* every node owned, in order */
void pk_local_free(pk_local_t *l);

/* The particle set, approximant and assembler of the problem on the local particles
 * (MLS order 1, cubic spline), set up. Boundary and quadrature points: those within R of
 * an owned node, in the global order. */
typedef struct {
  mfree_particles_t *ps;
  mfree_approximant_t *ap;
  mfree_assembler_t *as;
  double *x; /* local positions */
  double *buf;
} pk_system_t;

mfree_status_t pk_system(mfree_context_t *ctx, const pk_problem_t *p, const pk_local_t *l, pk_system_t *s);
void pk_system_free(pk_system_t *s);

/* The exact beam displacement (paper 000 eqs 120-121). */
void pk_beam_exact(const pk_problem_t *p, const double *x, double *u);

/* Essential conditions of a problem on the owned nodes (clamped x = 0 face for the block:
 * zero; the beam's x = 0 edge: the exact displacement): n unknowns, their local dofs and
 * values (caller frees). */
void pk_dirichlet(const pk_problem_t *p, const pk_local_t *l, int32_t *n, int32_t **dofs, double **vals);

/* PetscInitialize, the rank and size of PETSC_COMM_WORLD, the cmocka tests, PetscFinalize:
 * the main program of a test. */
int pk_main(int *argc, char ***argv, const struct CMUnitTest *tests, size_t n, int *rank, int *size);

#endif
