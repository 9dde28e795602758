/*
 * Size rule of the assembled systems (internal; C99 and C++ so that the test t690 can
 * check the limit without building a system of 2^31 unknowns, which would need about
 * 7e8 particles).
 */
#ifndef MFREE_CORE_UNKNOWNS_H
#define MFREE_CORE_UNKNOWNS_H

#include <stdint.h>

#include "mfree.h"

/* Unknowns of an assembled system: nparticles * ncomp particle unknowns followed by
 * nmult Lagrange multipliers. mfree_matrix_t rows and columns and the assembler's dof
 * numbers are int32_t, so a total above INT32_MAX is MFREE_ERR_ARG (nothing is
 * allocated: the caller reports it); negative counts or ncomp outside 1..3 are
 * MFREE_ERR_INPUT. On success *nunknowns holds the total. */
static inline mfree_status_t mfree_core_count_unknowns(int64_t nparticles, int32_t ncomp, int64_t nmult,
                                                       int32_t *nunknowns) {
  if (nparticles < 0 || nmult < 0 || ncomp < 1 || ncomp > 3) return MFREE_ERR_INPUT;
  /* nparticles * 3 cannot overflow int64 unless nparticles > 3e18: refuse those first */
  if (nparticles > INT64_C(2147483647) || nmult > INT64_C(2147483647)) return MFREE_ERR_ARG;
  const int64_t total = nparticles * ncomp + nmult;
  if (total > INT64_C(2147483647)) return MFREE_ERR_ARG;
  *nunknowns = (int32_t)total;
  return MFREE_SUCCESS;
}

#endif
