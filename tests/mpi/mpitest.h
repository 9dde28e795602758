/* Helpers of the MPI tests (label mpi): a cloud every rank builds alike, its
 * decompositions, checks that end every rank with the same verdict, and a file reader. */
#ifndef MFREE_MPITEST_H
#define MFREE_MPITEST_H

#include <mpi.h>
#include <stdint.h>
#include <stdio.h> /* CHECK prints */

#include "mfree.h"
#include "mfree_mpi.h"

#define KAPPA 2.0

/* One failed check on this rank: prints it and counts it; mpitest_finish agrees. */
extern int mpitest_failures;
#define CHECK(cond, ...)                                             \
  do {                                                               \
    if (!(cond)) {                                                   \
      int r_;                                                        \
      MPI_Comm_rank(MPI_COMM_WORLD, &r_);                            \
      fprintf(stderr, "rank %d, %s:%d: check failed: %s: ", r_, __FILE__, __LINE__, #cond); \
      fprintf(stderr, __VA_ARGS__);                                  \
      fprintf(stderr, "\n");                                         \
      ++mpitest_failures;                                            \
    }                                                                \
  } while (0)

/* One call's outcome on this rank, checked where every rank must agree (a collective call
 * returns the same status everywhere): status want, and a context message holding needle
 * (NULL: any message); what names the case in a failed check. */
void expect(mfree_context_t *ctx, mfree_status_t got, mfree_status_t want, const char *needle, const char *what);

/* st, checked to be the same on every rank of MPI_COMM_WORLD (else one failed check naming
 * what and the range of statuses). Collective. */
mfree_status_t mpitest_same_status(mfree_status_t st, const char *what);

/* expect for a collective call: got the same on every rank of MPI_COMM_WORLD, want, and a
 * message naming the rank that failed, "rank <bad>: <why>". Collective. */
void expect_agreed(mfree_context_t *ctx, mfree_status_t got, mfree_status_t want, int bad, const char *why,
                   const char *what);

/* a and b, n doubles each, hold the same bits: else one failed check naming what and the
 * first item that differs (its two values). Returns 1 when they do. */
int mpitest_same_bits(const double *a, const double *b, int64_t n, const char *what);

/* The whole file at path, NUL-terminated, to be freed; NULL when it cannot be read. */
char *slurp(const char *path);

/* The start of every MPI test's main: MPI_Init, this rank and the number of ranks of
 * MPI_COMM_WORLD, and a fresh context (NULL if it could not be made). */
mfree_context_t *mpitest_start(int *argc, char ***argv, int *rank, int *size);

/* 0 when no rank failed a check (printed by rank 0), else 1: main's exit code. */
int mpitest_finish(const char *name);

/* A jittered lattice of m^dim particles on [0,1]^dim, supports varying by +-10 %, volumes
 * dx^dim +-10 %, global ids 5 + 2 i (not contiguous), the same on every rank. */
typedef struct {
  int dim, n;
  double *x, *h, *v;
  int64_t *id;
} cloud_t;
void cloud_make(cloud_t *c, int dim, int m, uint64_t seed);
void cloud_free(cloud_t *c);
double cloud_max_support(const cloud_t *c);

/* part[i] = the rank owning particle i: slab (along x), random (hash of the id), or
 * Zoltan RCB (collective; returns -1 when Zoltan is not built in). */
enum { DECOMP_SLAB = 0, DECOMP_RANDOM = 1, DECOMP_RCB = 2 };
int decompose(const cloud_t *c, int how, MPI_Comm comm, int *part);

uint64_t mpitest_hash(uint64_t z);

#endif
