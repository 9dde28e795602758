/*
 * Choice of the SuiteSparse integer variant (internal; C99 and C++ so that the test
 * t806 can check the thresholds without allocating a matrix with 2^31 entries).
 */
#ifndef MFREE_SUITESPARSE_INDEX_WIDTH_H
#define MFREE_SUITESPARSE_INDEX_WIDTH_H

#include <stdint.h>

#include "mfree.h"

/* The 32-bit variants (int) hold offsets up to INT32_MAX: they fit a matrix whose nnz
 * is at most that (n always fits: mfree matrices have int32_t sizes). */
#define MFREE_SS_INT32_NNZ_MAX INT64_C(2147483647)

/* requested: 0 (automatic), 32 or 64; nnz: entries of the matrix. On success *bits is
 * 32 or 64. A forced 32 that does not fit is MFREE_ERR_UNSUPPORTED; an unknown request
 * is MFREE_ERR_ARG; a negative nnz is MFREE_ERR_INPUT. */
static inline mfree_status_t mfree_ss_select_index_width(int32_t requested, int64_t nnz,
                                                         int32_t *bits) {
  if (nnz < 0) return MFREE_ERR_INPUT;
  switch (requested) {
    case 0:
      *bits = nnz <= MFREE_SS_INT32_NNZ_MAX ? 32 : 64;
      return MFREE_SUCCESS;
    case 32:
      if (nnz > MFREE_SS_INT32_NNZ_MAX) return MFREE_ERR_UNSUPPORTED;
      *bits = 32;
      return MFREE_SUCCESS;
    case 64:
      *bits = 64;
      return MFREE_SUCCESS;
    default:
      return MFREE_ERR_ARG;
  }
}

#endif
