/* The fluid on ranks across ghost rebuilds and migrations (t189-t192): a dam break
 * (mpifluid.h) whose system runs through counting wrappers of a halo plan's callbacks,
 * so that the tests see how often the ghosts were rebuilt, and its state compared with a
 * one-rank run by global id. */
#ifndef MFREE_MPIMOVE_H
#define MFREE_MPIMOVE_H

#include "mpifluid.h"

typedef struct {
  mfree_halo_t *halo;
  int rebuilds;  /* calls of the rebuild callback */
  int fail_rebuild; /* 1: the rebuild fails (fault tests) */
} counted_t;

/* The system of r replaced by one over the same plan created by
 * mfree_system_create_fluid_ranks with counting callbacks (w, kept by the system). */
mfree_status_t mpimove_counted(rankfluid_t *r, mfree_context_t *ctx, const damb_t *b, double width, counted_t *w);
/* The counting rebuild callback (user: the counted_t). */
mfree_status_t mpimove_rebuild(void *user, int32_t n_owned, const double *x, int64_t ld, const int64_t *ids,
                               double width, int32_t *n_ghost, const int64_t **all_ids);
/* This rank's owned particles that differ (position, velocity or density bits) from
 * ref (5 n values, every particle in id order); *first: the first such id or -1. The
 * owned ids are the plan's (they change with migrations). */
int mpimove_differs(const rankfluid_t *r, const double *y, const double *ref, int n, int *first);

#endif
