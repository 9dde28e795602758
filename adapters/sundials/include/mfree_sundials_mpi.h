/**
 * @file mfree_sundials_mpi.h
 * @brief SUNDIALS' NVECTOR_PARALLEL for mfree systems on ranks, with global reductions
 * that give one rank's values bit for bit (libmfree_sundials_mpi, CMake
 * mfree::mfree_sundials_mpi; built when MPI and SUNDIALS' nvecparallel are found).
 *
 * A system on ranks (mfree_system_create_elastodynamic_ranks) integrates with ERKStep or
 * ARKStep through libmfree_sundials' callbacks (mfree_sundials_rhs, ...) on parallel
 * vectors whose local part is this rank's state. The right-hand side gives bitwise one
 * rank's values; ARKODE's step control then depends on the vectors' global reductions
 * (WRMS norms of the error estimate, dot products of iterative mass solvers), which
 * NVECTOR_PARALLEL computes as an MPI_Allreduce of per-rank floating-point sums: their
 * rounding depends on the partition. mfree_sundials_mpi_set_reproducible replaces the
 * summing reductions by exact ones: every term (a product, a square, an absolute value,
 * computed as NVECTOR_PARALLEL does) is added without rounding into a long fixed-point
 * accumulator (70 limbs of 32 bits from 2^-1152, held in 64-bit integers), the ranks'
 * accumulators are added with one MPI_Allreduce of 70 integers (integer sums: any order
 * gives the same), and the exact total is rounded once. The result is a function of the
 * terms alone, the same on any number of ranks and in any order; it costs a few integer
 * operations per term instead of one addition, and 70 integers instead of one double per
 * reduction (BENCHMARKS.md, "Exact reductions"; docs/mpi.md). Maxima, minima and the boolean tests
 * are exact already and stay NVECTOR_PARALLEL's. The fused and local reductions
 * (N_VDotProdMulti, N_VWrmsNormVectorArray, N_VDotProdLocal, N_VWSqrSumLocal, ...) are
 * removed from the vector, so that SUNDIALS falls back to the reproducible ones (the
 * local ones are partition-dependent by nature: MPIManyVector, which needs them, is not
 * supported). Clones (N_VClone, as ARKODE makes them) inherit the operations.
 */
#ifndef MFREE_SUNDIALS_MPI_H
#define MFREE_SUNDIALS_MPI_H

#include <mpi.h>
#include <nvector/nvector_parallel.h>
#include <stdint.h>

#include "mfree.h"
#include "mfree_sundials.h"

#ifdef __cplusplus
extern "C" {
#endif

#if defined(_WIN32)
#if defined(MFREE_SUNDIALS_MPI_BUILDING)
#define MFREE_SUNDIALS_MPI_API __declspec(dllexport)
#else
#define MFREE_SUNDIALS_MPI_API
#endif
#elif defined(__GNUC__) && __GNUC__ >= 4
#define MFREE_SUNDIALS_MPI_API __attribute__((visibility("default")))
#else
#define MFREE_SUNDIALS_MPI_API
#endif

/**
 * Replace the summing global reductions of an NVECTOR_PARALLEL vector (N_VDotProd,
 * N_VWrmsNorm, N_VWrmsNormMask, N_VWL2Norm, N_VL1Norm) by exact, reproducible ones and
 * remove its fused and local reductions (see the file's description). Not collective.
 * @param[in]     ctx  context for errors
 * @param[in,out] v    an NVECTOR_PARALLEL vector (its clones made afterwards inherit the
 *                     change; a clone made before keeps NVECTOR_PARALLEL's sums, and
 *                     SUNDIALS 6 computes N_VDotProd(x, y) with y's operations, so call
 *                     this before cloning)
 * @return MFREE_SUCCESS; MFREE_ERR_NULL (NULL ctx: without a message); MFREE_ERR_UNSUPPORTED
 *         for another vector type
 */
MFREE_SUNDIALS_MPI_API mfree_status_t mfree_sundials_mpi_set_reproducible(mfree_context_t *ctx, N_Vector v);

/**
 * A new NVECTOR_PARALLEL vector for a system on ranks: local length the system's neq on
 * this rank, global length their sum, reductions reproducible
 * (mfree_sundials_mpi_set_reproducible), values zero. Collective over comm: a rank that
 * fails makes every rank fail alike.
 * @param[in]  ctx     context for errors
 * @param[in]  sys     the system (its size on this rank)
 * @param[in]  comm    the system's ranks
 * @param[in]  sunctx  the SUNDIALS context
 * @param[out] v       the new vector (the host destroys it with N_VDestroy); NULL on failure
 * @return MFREE_SUCCESS; on every rank alike: MFREE_ERR_NULL (a NULL ctx, system,
 *         SUNContext or output on some rank; the rank with the NULL ctx gets no message),
 *         MFREE_ERR_ALLOC, MFREE_ERR_INTERNAL (an MPI failure)
 */
MFREE_SUNDIALS_MPI_API mfree_status_t mfree_sundials_mpi_create_vector(mfree_context_t *ctx, mfree_system_t *sys,
                                                                       MPI_Comm comm, SUNContext sunctx,
                                                                       N_Vector *v);

/**
 * The exact sum over all ranks of every rank's n values, rounded once to the nearest
 * double: the same on every rank and for any partition of the values (the reduction of
 * mfree_sundials_mpi_set_reproducible, for a host's own totals). Collective. Infinities
 * and NaNs propagate as in a plain sum (+inf and -inf together give NaN).
 * @param[in]  ctx   context for errors
 * @param[in]  comm  the ranks
 * @param[in]  x     this rank's n values (may be NULL when n is 0)
 * @param[in]  n     this rank's count (>= 0)
 * @param[out] sum   the total
 * @return MFREE_SUCCESS; MFREE_ERR_NULL (a NULL ctx, x or sum on some rank; the rank with
 *         the NULL ctx gets no message), MFREE_ERR_ARG (a negative n) on every rank alike;
 *         MFREE_ERR_INTERNAL for an MPI failure
 */
MFREE_SUNDIALS_MPI_API mfree_status_t mfree_sundials_mpi_sum(mfree_context_t *ctx, MPI_Comm comm, const double *x,
                                                             int64_t n, double *sum);

#ifdef __cplusplus
}
#endif

#endif /* MFREE_SUNDIALS_MPI_H */
