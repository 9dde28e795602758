/* Helpers of the migration tests (t180-t189): a particle state whose every field travels
 * with mfree_migration_*, and checks that each particle's bytes are those of its global
 * id wherever it lives. */
#ifndef MFREE_MIGSTATE_H
#define MFREE_MIGSTATE_H

#include "mpitest.h"

/* A host struct of which only one member is registered (an arbitrary strided field). */
typedef struct {
  double other;
  int32_t tag;
  int32_t pad;
} mig_flags_t;

/* Owned particles of a cloud (mpitest.h) on this rank, room for cap of them: positions
 * (x, ld 3, dim components registered), velocities (2), density, support, global id and
 * a tag in a struct array. Velocities, densities and tags are arbitrary bits of the id
 * (NaN payloads, subnormals, -0), so that any change of a byte shows. */
typedef struct {
  int dim, n, cap;
  double *x, *v, *rho, *h;
  int64_t *id;
  mig_flags_t *flags;
} mig_state_t;

/* The particles i of c with part[i] == rank (all when part is NULL and rank is 0; none
 * on other ranks), positions shifted by mig_shift(id, t). */
void mig_state_init(mig_state_t *s, const cloud_t *c, const int *part, int rank, int cap, double t);
void mig_state_free(mig_state_t *s);
/* Registers every field of s on m (after clearing). */
mfree_status_t mig_state_register(const mig_state_t *s, mfree_migration_t *m);
/* The position of cloud particle i at time t (a shear and a drift, deterministic). */
void mig_position(const cloud_t *c, int i, double t, double *p);
/* Moves every owned particle to its position at time t. */
void mig_state_move(mig_state_t *s, const cloud_t *c, double t);
/* Checks every owned particle's bits against its id (positions at time t) and, over all
 * ranks, that every id of c is owned exactly once. Returns the failures (agreed). */
int mig_state_check(const mig_state_t *s, const cloud_t *c, double t, const char *what);
/* Largest owned count over the mean (1 = perfect balance). Collective. */
double mig_imbalance(const mig_state_t *s);

#endif
