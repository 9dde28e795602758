// libmfree_sundials_mpi: reproducible global reductions for NVECTOR_PARALLEL (see
// mfree_sundials_mpi.h). The sums are exact (the core's ExactSum, header-only): each
// rank's accumulator is normalised and the ranks' are added by MPI_SUM on integers,
// which is exact in any order; the exact total is rounded once to a double, so the
// result depends on the terms only.
#include "mfree_sundials_mpi.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <new>
#include <string>
#include <type_traits>

#include "core/base/exact_sum.hpp"

static_assert(std::is_same<sunrealtype, double>::value, "the exact sums take doubles");

namespace {

using mfree::ExactSum;

// The normalised accumulator of this rank plus those of the others (MPI_SUM on
// integers: exact in any order).
bool allreduce(ExactSum &s, MPI_Comm comm) {
  s.normalise();
  return MPI_Allreduce(MPI_IN_PLACE, s.words(), ExactSum::kWords, MPI_INT64_T, MPI_SUM, comm) == MPI_SUCCESS;
}

// The exact global sum of f(i) over the local entries of the vector x.
template <class Term>
double global_sum(N_Vector x, Term &&f) {
  ExactSum s;
  const sunindextype n = NV_LOCLENGTH_P(x);
  for (sunindextype i = 0; i < n; ++i) s.add(f(i));
  if (!allreduce(s, NV_COMM_P(x))) return std::nan("");  // (SUNDIALS' reductions have no status)
  return s.value();
}

sunrealtype dot(N_Vector x, N_Vector y) {
  const double *a = NV_DATA_P(x), *b = NV_DATA_P(y);
  return global_sum(x, [&](sunindextype i) { return a[i] * b[i]; });
}

sunrealtype wsqrsum(N_Vector x, N_Vector w) {
  const double *a = NV_DATA_P(x), *b = NV_DATA_P(w);
  return global_sum(x, [&](sunindextype i) {
    const double p = a[i] * b[i];
    return p * p;
  });
}

sunrealtype wrmsnorm(N_Vector x, N_Vector w) {
  return std::sqrt(wsqrsum(x, w) / static_cast<double>(NV_GLOBLENGTH_P(x)));
}

sunrealtype wrmsnormmask(N_Vector x, N_Vector w, N_Vector id) {
  const double *a = NV_DATA_P(x), *b = NV_DATA_P(w), *m = NV_DATA_P(id);
  const double s = global_sum(x, [&](sunindextype i) {
    if (!(m[i] > 0.0)) return 0.0;
    const double p = a[i] * b[i];
    return p * p;
  });
  return std::sqrt(s / static_cast<double>(NV_GLOBLENGTH_P(x)));
}

sunrealtype wl2norm(N_Vector x, N_Vector w) { return std::sqrt(wsqrsum(x, w)); }

sunrealtype l1norm(N_Vector x) {
  const double *a = NV_DATA_P(x);
  return global_sum(x, [&](sunindextype i) { return std::fabs(a[i]); });
}

// st with its message on ctx; a NULL ctx (a collective call's fault taken part in the
// reductions, so the other ranks do not wait) gets st without one.
mfree_status_t record(mfree_context_t *ctx, mfree_status_t st, const char *fn, const std::string &msg) {
  if (!ctx) return st;
  const std::string text = std::string(fn) + ": " + msg;
  return mfree_context_set_error(ctx, st, text.c_str());
}

}  // namespace

extern "C" {

mfree_status_t mfree_sundials_mpi_set_reproducible(mfree_context_t *ctx, N_Vector v) {
  static const char *fn = "mfree_sundials_mpi_set_reproducible";
  if (!ctx) return MFREE_ERR_NULL;
  if (!v || !v->ops) return record(ctx, MFREE_ERR_NULL, fn, "vector is NULL or has no operations");
  if (!v->ops->nvgetvectorid || N_VGetVectorID(v) != SUNDIALS_NVEC_PARALLEL)
    return record(ctx, MFREE_ERR_UNSUPPORTED, fn, "the vector is not an NVECTOR_PARALLEL vector");
  N_Vector_Ops o = v->ops;
  o->nvdotprod = dot;
  o->nvwrmsnorm = wrmsnorm;
  o->nvwrmsnormmask = wrmsnormmask;
  o->nvwl2norm = wl2norm;
  o->nvl1norm = l1norm;
  // SUNDIALS falls back to the reductions above where these are missing
  o->nvdotprodmulti = nullptr;
  o->nvwrmsnormvectorarray = nullptr;
  o->nvwrmsnormmaskvectorarray = nullptr;
  o->nvdotprodlocal = nullptr;
  o->nvl1normlocal = nullptr;
  o->nvwsqrsumlocal = nullptr;
  o->nvwsqrsummasklocal = nullptr;
  o->nvdotprodmultilocal = nullptr;
  o->nvdotprodmultiallreduce = nullptr;
  return MFREE_SUCCESS;
}

mfree_status_t mfree_sundials_mpi_create_vector(mfree_context_t *ctx, mfree_system_t *sys, MPI_Comm comm,
                                                SUNContext sunctx, N_Vector *v) {
  static const char *fn = "mfree_sundials_mpi_create_vector";
  if (v) *v = nullptr;
  // this rank's fault and length, seen by every rank in one reduction (a NULL ctx too)
  int32_t neq = 0;
  int64_t mine[2] = {0, 0};  // (faulty ranks, local length)
  if (!ctx || !sys || !sunctx || !v || mfree_system_get_size(sys, &neq) != MFREE_SUCCESS)
    mine[0] = 1;
  else
    mine[1] = neq;
  int64_t all[2] = {0, 0};
  if (MPI_Allreduce(mine, all, 2, MPI_INT64_T, MPI_SUM, comm) != MPI_SUCCESS)
    return record(ctx, MFREE_ERR_INTERNAL, fn, "MPI_Allreduce failed");
  if (all[0] > 0)
    return record(ctx, MFREE_ERR_NULL, fn,
                  std::to_string(all[0]) + " rank(s) passed a NULL context, system, SUNContext or output" +
                      (mine[0] ? " (this one among them)" : ""));
  N_Vector y = N_VNew_Parallel(comm, neq, all[1], sunctx);
  int64_t bad = y ? 0 : 1, any = 0;
  if (MPI_Allreduce(&bad, &any, 1, MPI_INT64_T, MPI_SUM, comm) != MPI_SUCCESS || any > 0) {
    if (y) N_VDestroy(y);
    return record(ctx, MFREE_ERR_ALLOC, fn, "N_VNew_Parallel failed on " + std::to_string(any) + " rank(s)");
  }
  N_VConst(0.0, y);
  mfree_sundials_mpi_set_reproducible(ctx, y);
  *v = y;
  return MFREE_SUCCESS;
}

mfree_status_t mfree_sundials_mpi_sum(mfree_context_t *ctx, MPI_Comm comm, const double *x, int64_t n,
                                      double *sum) {
  static const char *fn = "mfree_sundials_mpi_sum";
  ExactSum s;
  // a bad argument on any rank (a NULL ctx too): no data reduced, every rank fails alike
  const bool bad = !ctx || n < 0 || (n > 0 && !x) || !sum;
  if (!bad)
    for (int64_t i = 0; i < n; ++i) s.add(x[i]);
  // (the most negative status of the ranks: MFREE_ERR_ARG before MFREE_ERR_NULL)
  int64_t fault = !bad ? 0 : (ctx && n < 0 ? MFREE_ERR_ARG : MFREE_ERR_NULL), worst = 0;
  if (MPI_Allreduce(&fault, &worst, 1, MPI_INT64_T, MPI_MIN, comm) != MPI_SUCCESS)
    return record(ctx, MFREE_ERR_INTERNAL, fn, "MPI_Allreduce failed");
  if (worst < 0)
    return record(ctx, static_cast<mfree_status_t>(worst), fn,
                  std::string("a rank passed a negative count or a NULL pointer") +
                      (bad ? " (this one among them)" : ""));
  if (!allreduce(s, comm)) return record(ctx, MFREE_ERR_INTERNAL, fn, "MPI_Allreduce failed");
  *sum = s.value();
  return MFREE_SUCCESS;
}

}  // extern "C"
