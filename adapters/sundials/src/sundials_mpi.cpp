// libmfree_sundials_mpi: reproducible global reductions for NVECTOR_PARALLEL (see
// mfree_sundials_mpi.h). The sums are exact: each term is split into its 53-bit integer
// mantissa and exponent and added into a fixed-point accumulator whose limbs hold 32
// bits each in 64-bit integers (2^31 additions before a limb could overflow; the
// accumulator is normalised before that and before the ranks' accumulators are added
// by MPI_SUM on integers, which is exact in any order). The exact total has one
// normalised form, rounded once to a double: the result depends on the terms only.
#include "mfree_sundials_mpi.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <new>
#include <string>
#include <type_traits>

static_assert(std::is_same<sunrealtype, double>::value, "the exact sums take doubles");

namespace {

class ExactSum {
 public:
  // limb k weighs 2^(32 k - 1152): the lowest bit of the smallest subnormal (2^-1074)
  // lies 26 or more bits above the bottom, and 2^1024 (beyond the largest double) below
  // limb 68, leaving limb 69 for the carries of up to 2^63 terms.
  static constexpr int kLimbs = 70;
  static constexpr int kBias = 1152;
  // the counts of +inf, -inf and NaN terms travel with the limbs
  static constexpr int kWords = kLimbs + 3;

  void add(double x) {
    if (!std::isfinite(x)) {
      ++w_[kLimbs + (std::isnan(x) ? 2 : (x > 0 ? 0 : 1))];
      return;
    }
    if (x == 0.0) return;
    int e = 0;
    const double m = std::frexp(x, &e);  // x = m 2^e, 1/2 <= |m| < 1
    const int64_t mi = static_cast<int64_t>(std::ldexp(m, 53));  // exact: x = mi 2^(e - 53)
    const int pos = e - 53 + kBias;                               // >= 26 (subnormals included)
    const int k = pos / 32;
    // (a product, not a left shift: shifting a negative value is undefined before C++20)
    __int128 v = static_cast<__int128>(mi) * (static_cast<__int128>(1) << (pos % 32));
    // v = c0 + c1 2^32 + c2 2^64, c0 and c1 in [0, 2^32), c2 signed and small
    w_[k] += static_cast<int64_t>(static_cast<uint64_t>(v) & 0xffffffffu);
    v >>= 32;
    w_[k + 1] += static_cast<int64_t>(static_cast<uint64_t>(v) & 0xffffffffu);
    v >>= 32;
    w_[k + 2] += static_cast<int64_t>(v);
    if (++adds_ == (int64_t{1} << 30)) normalise();
  }

  // Limbs 0 .. kLimbs-2 in [0, 2^32), the sign and any excess in the top limb.
  void normalise() {
    for (int k = 0; k + 1 < kLimbs; ++k) {
      const int64_t carry = w_[k] >> 32;  // (arithmetic: floor)
      w_[k] -= carry * (int64_t{1} << 32);
      w_[k + 1] += carry;
    }
    adds_ = 0;
  }

  int64_t *words() { return w_; }

  // The exact total rounded to the nearest double (once, from its canonical form).
  double value() {
    normalise();
    const int64_t pinf = w_[kLimbs], ninf = w_[kLimbs + 1], nan = w_[kLimbs + 2];
    if (nan > 0 || (pinf > 0 && ninf > 0)) return std::nan("");
    if (pinf > 0) return HUGE_VAL;
    if (ninf > 0) return -HUGE_VAL;
    const bool negative = w_[kLimbs - 1] < 0;
    if (negative) {
      for (int k = 0; k < kLimbs; ++k) w_[k] = -w_[k];
      normalise();
    }
    int hi = kLimbs - 1;
    while (hi >= 0 && w_[hi] == 0) --hi;
    if (hi < 0) return 0.0;
    // the top three limbs and a sticky bit for the rest: at least 65 significant bits,
    // so the sticky bit lies far below the rounding position of the conversion
    unsigned __int128 t = 0;
    bool sticky = false;
    for (int k = hi; k >= hi - 2; --k) t = (t << 32) | (k >= 0 ? static_cast<uint64_t>(w_[k]) : 0u);
    for (int k = hi - 3; k >= 0 && !sticky; --k) sticky = w_[k] != 0;
    if (sticky) t |= 1;
    const double d = std::ldexp(static_cast<double>(t), 32 * (hi - 2) - kBias);
    return negative ? -d : d;
  }

  bool allreduce(MPI_Comm comm) {
    normalise();
    return MPI_Allreduce(MPI_IN_PLACE, w_, kWords, MPI_INT64_T, MPI_SUM, comm) == MPI_SUCCESS;
  }

 private:
  int64_t w_[kWords] = {0};
  int64_t adds_ = 0;
};

// The exact global sum of f(i) over the local entries of the vector x.
template <class Term>
double global_sum(N_Vector x, Term &&f) {
  ExactSum s;
  const sunindextype n = NV_LOCLENGTH_P(x);
  for (sunindextype i = 0; i < n; ++i) s.add(f(i));
  if (!s.allreduce(NV_COMM_P(x))) return std::nan("");  // (SUNDIALS' reductions have no status)
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

mfree_status_t record(mfree_context_t *ctx, mfree_status_t st, const char *fn, const std::string &msg) {
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
  if (!ctx) return MFREE_ERR_NULL;
  if (v) *v = nullptr;
  // this rank's fault and length, seen by every rank in one reduction
  int32_t neq = 0;
  int64_t mine[2] = {0, 0};  // (faulty ranks, local length)
  if (!sys || !sunctx || !v || mfree_system_get_size(sys, &neq) != MFREE_SUCCESS)
    mine[0] = 1;
  else
    mine[1] = neq;
  int64_t all[2] = {0, 0};
  if (MPI_Allreduce(mine, all, 2, MPI_INT64_T, MPI_SUM, comm) != MPI_SUCCESS)
    return record(ctx, MFREE_ERR_INTERNAL, fn, "MPI_Allreduce failed");
  if (all[0] > 0)
    return record(ctx, MFREE_ERR_NULL, fn,
                  std::to_string(all[0]) + " rank(s) passed a NULL system, SUNContext or output" +
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
  if (!ctx) return MFREE_ERR_NULL;
  ExactSum s;
  // a bad argument on any rank: no data reduced, every rank fails alike
  const bool bad = n < 0 || (n > 0 && !x) || !sum;
  if (!bad)
    for (int64_t i = 0; i < n; ++i) s.add(x[i]);
  // (the most negative status of the ranks: MFREE_ERR_ARG before MFREE_ERR_NULL)
  int64_t fault = !bad ? 0 : (n < 0 ? MFREE_ERR_ARG : MFREE_ERR_NULL), worst = 0;
  if (MPI_Allreduce(&fault, &worst, 1, MPI_INT64_T, MPI_MIN, comm) != MPI_SUCCESS)
    return record(ctx, MFREE_ERR_INTERNAL, fn, "MPI_Allreduce failed");
  if (worst < 0)
    return record(ctx, static_cast<mfree_status_t>(worst), fn,
                  std::string("a rank passed a negative count or a NULL pointer") +
                      (bad ? " (this one among them)" : ""));
  if (!s.allreduce(comm)) return record(ctx, MFREE_ERR_INTERNAL, fn, "MPI_Allreduce failed");
  *sum = s.value();
  return MFREE_SUCCESS;
}

}  // extern "C"
