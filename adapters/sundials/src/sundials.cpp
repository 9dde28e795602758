// libmfree_sundials: an mfree_system_t behind SUNDIALS' callback signatures (ARKRhsFn,
// ARKLsMassFn, IDAResFn). Only the public mfree API and SUNDIALS' public API are used;
// of SUNDIALS' modules only the sparse matrix (SUNSparseMatrix_*) is called directly.
#include "mfree_sundials.h"

#include <sunmatrix/sunmatrix_sparse.h>

#include <limits>
#include <memory>
#include <new>
#include <string>
#include <type_traits>
#include <vector>

#include "../../common/guard.hpp"

static_assert(std::is_same<sunrealtype, double>::value,
              "mfree hands N_Vector data to the system without conversion: sunrealtype must "
              "be double");

struct mfree_sundials {
  mfree_context_t *ctx = nullptr;
  mfree_matrix_t *ctx_ref = nullptr;  // a 0 x 0 matrix on ctx: holds a reference on it
  mfree_system_t *sys = nullptr;      // borrowed (the host keeps it alive)
  int32_t neq = 0;
  bool consistent = false;
  SUNLinearSolver mass_solver = nullptr;

  // the state the mass function starts from (see mfree_sundials_mass): the argument of
  // the last right-hand side, with its time and rate, or a state set by the host
  std::vector<double> state, rate, predicted;
  bool has_state = false;
  bool state_timed = false;  // from a right-hand side: state_t and rate are meaningful
  double state_t = 0.0;
  int64_t state_gen = 0;     // states kept so far
  // mass_at's last assembly (state_gen, t and kind), reused at the same point: a mass
  // solver's products within one solve ask for the same mass (-1: none to reuse)
  int64_t mass_gen = -1;
  double mass_t = 0.0;
  bool mass_consistent = false;

  // mfree matrices refilled at every call (created at the first)
  mfree_matrix_t *lumped = nullptr;  // M_L: the mass form's force, the lumped residual
  mfree_matrix_t *mass = nullptr;    // the consistent mass (residual, mass function)
  std::vector<double> work, force;

  // the pattern last written into a host SUNMatrix, to detect pattern changes
  SUNMatrix last_matrix = nullptr;
  int last_sparsetype = -1;
  std::vector<int64_t> last_ptr;
  std::vector<int32_t> last_idx;

  int64_t nrhs = 0, nres = 0, nmass = 0, nmass_predicted = 0, npattern = 0;
};

namespace {

using mfree_adapter::guarded;
using mfree_adapter::record;

// SUNDIALS' convention: 0 success, > 0 recoverable, < 0 unrecoverable. mfree's positive
// statuses are its data-dependent (recoverable) failures; they pass through unchanged.
int to_sundials(mfree_status_t st) {
  if (st == MFREE_SUCCESS) return 0;
  return st > 0 ? static_cast<int>(st) : -1;
}

// A callback body returning an mfree status, mapped to SUNDIALS' int.
template <class Body>
int callback(mfree_sundials_t *ad, const char *fn, Body &&body) noexcept {
  if (!ad) return -1;  // no context to tell: user_data was not an adapter
  return to_sundials(guarded(ad->ctx, fn, body));
}

// The data of an N_Vector of the system's length, or a recorded failure. The generic
// N_VGetLength / N_VGetArrayPointer of 6.x call the operation without checking it
// exists, so an empty custom vector is checked here first.
mfree_status_t vector_data(mfree_sundials_t *ad, const char *fn, const char *name, N_Vector v,
                           double **data) {
  *data = nullptr;
  if (!v) return record(ad->ctx, MFREE_ERR_NULL, fn, std::string(name) + " is NULL");
  if (!v->ops || !v->ops->nvgetlength)
    return record(ad->ctx, MFREE_ERR_UNSUPPORTED, fn,
                  std::string(name) +
                      " has no length operation (nvgetlength): the adapter needs vectors "
                      "with one contiguous host array (NVECTOR_SERIAL, OPENMP, PTHREADS)");
  // Vectors over ranks (NVECTOR_PARALLEL, MPIPLUSX) hold this rank's part of the state:
  // their local length is the system's size on this rank.
  const N_Vector_ID id = v->ops->nvgetvectorid ? N_VGetVectorID(v) : SUNDIALS_NVEC_CUSTOM;
  const bool ranks = (id == SUNDIALS_NVEC_PARALLEL || id == SUNDIALS_NVEC_MPIPLUSX) && v->ops->nvgetlocallength;
  const sunindextype len = ranks ? v->ops->nvgetlocallength(v) : N_VGetLength(v);
  if (len != static_cast<sunindextype>(ad->neq))
    return record(ad->ctx, MFREE_ERR_MISMATCH, fn,
                  std::string(name) + " has length " + std::to_string(static_cast<int64_t>(len)) +
                      ", the system has " + std::to_string(ad->neq) + " equations");
  double *p = v->ops->nvgetarraypointer ? N_VGetArrayPointer(v) : nullptr;
  if (!p && ad->neq > 0)
    return record(ad->ctx, MFREE_ERR_UNSUPPORTED, fn,
                  std::string(name) +
                      " has no data array (N_VGetArrayPointer returned NULL): the adapter "
                      "needs vectors with one contiguous host array (NVECTOR_SERIAL, "
                      "OPENMP, PTHREADS), not empty or device-only vectors");
  *data = p;
  return MFREE_SUCCESS;
}

// A callback's vectors: their data, or this rank's first fault among them (vector_data's)
// made pending on the system (mfree_system_set_pending_error), so that the system call the
// callback still makes, on no data, returns it on every rank of a system on ranks instead
// of leaving the others waiting in that call's collective (in one process the call
// returns it at once).
struct Vectors {
  mfree_sundials_t *ad;
  const char *fn;
  mfree_status_t fault = MFREE_SUCCESS;
  bool pending = false;

  // *data: v's data, NULL after a fault.
  void get(const char *name, N_Vector v, double **data) {
    *data = nullptr;
    if (fault == MFREE_SUCCESS) fault = vector_data(ad, fn, name, v, data);
  }
  bool faulty() const { return fault != MFREE_SUCCESS; }
  // A fault of another argument, taken as a vector's (the first one counts).
  void refuse(mfree_status_t st, const char *why) {
    if (fault == MFREE_SUCCESS) fault = record(ad->ctx, st, fn, why);
  }
  // MFREE_SUCCESS when the callback goes on to its system calls (the fault, if any,
  // pending); else the fault, returned at once (it cannot be made pending).
  mfree_status_t go() {
    if (!faulty()) return MFREE_SUCCESS;
    char msg[512] = {0};
    mfree_context_get_last_error(ad->ctx, nullptr, msg, sizeof msg);
    pending = mfree_system_set_pending_error(ad->sys, fault, msg) == MFREE_SUCCESS;
    return pending ? MFREE_SUCCESS : fault;
  }
  // The callback's outcome st; after a fault that no system call took (the callback
  // failed before its system call), the fault, cleared from the system.
  mfree_status_t finish(mfree_status_t st) {
    if (!pending) return st;
    mfree_system_set_pending_error(ad->sys, MFREE_SUCCESS, nullptr);
    return st != MFREE_SUCCESS ? st : fault;
  }
};

// Remember y (and, from a right-hand side, its time and rate y') for the mass function.
void keep_state(mfree_sundials_t *ad, const double *y, const double *rate, double t) {
  ad->state.assign(y, y + ad->neq);
  ++ad->state_gen;
  ad->has_state = true;
  ad->state_timed = rate != nullptr;
  ad->state_t = t;
  if (rate) ad->rate.assign(rate, rate + ad->neq);
}

// ad->work = f(t, y), then out = M_L(y) ad->work.
mfree_status_t mass_form(mfree_sundials_t *ad, double t, const double *y, double *out) {
  ad->work.resize(static_cast<size_t>(ad->neq));
  mfree_status_t st = mfree_system_rhs(ad->sys, t, y, ad->work.data());
  if (st != MFREE_SUCCESS) return st;
  st = mfree_system_assemble_mass(ad->sys, y, 0, &ad->lumped);
  if (st != MFREE_SUCCESS) return st;
  return mfree_matrix_apply(ad->lumped, ad->work.data(), out);
}

// The state the mass at time t is assembled at. M depends on positions and densities,
// whose rows of M y' = F are y' = f: they are predicted to time t from the last
// right-hand side (first order in t - state_t).
mfree_status_t mass_state(mfree_sundials_t *ad, const char *fn, double t, const double **at) {
  if (!ad->has_state)
    return record(ad->ctx, MFREE_ERR_STATE, fn,
                  "no state to assemble the mass at: evaluate a right-hand side of the "
                  "adapter or call mfree_sundials_set_state first");
  *at = ad->state.data();
  if (ad->state_timed && t != ad->state_t) {
    ++ad->nmass_predicted;
    ad->predicted.resize(static_cast<size_t>(ad->neq));
    const double dt = t - ad->state_t;
    for (int32_t q = 0; q < ad->neq; ++q) ad->predicted[q] = ad->state[q] + dt * ad->rate[q];
    *at = ad->predicted.data();
  }
  return MFREE_SUCCESS;
}

// ad->mass = the mass at time t (at mass_state's state).
mfree_status_t mass_at(mfree_sundials_t *ad, const char *fn, double t) {
  const double *at = nullptr;
  const mfree_status_t sst = mass_state(ad, fn, t, &at);
  if (sst != MFREE_SUCCESS) return sst;
  // (the same decision on every rank of a system on ranks: the states kept and t are)
  if (ad->mass && ad->mass_gen == ad->state_gen && ad->mass_t == t && ad->mass_consistent == ad->consistent)
    return MFREE_SUCCESS;
  ad->mass_gen = -1;
  const mfree_status_t st = mfree_system_assemble_mass(ad->sys, at, ad->consistent ? 1 : 0, &ad->mass);
  if (st == MFREE_SUCCESS) {
    ad->mass_gen = ad->state_gen;
    ad->mass_t = t;
    ad->mass_consistent = ad->consistent;
  }
  return st;
}

// Copy an mfree matrix (CSR view or its CSC view) into the host's SUNSparseMatrix.
mfree_status_t fill_sparse(mfree_sundials_t *ad, const char *fn, const mfree_matrix_t *A,
                           SUNMatrix M) {
  if (!M) return record(ad->ctx, MFREE_ERR_NULL, fn, "matrix is NULL");
  if (!M->ops || !M->ops->getid || SUNMatGetID(M) != SUNMATRIX_SPARSE)
    return record(ad->ctx, MFREE_ERR_UNSUPPORTED, fn,
                  "the mass matrix must be a SUNSparseMatrix (SUNMATRIX_SPARSE)");
  const sunindextype rows = SUNSparseMatrix_Rows(M), cols = SUNSparseMatrix_Columns(M);
  if (rows != ad->neq || cols != ad->neq)
    return record(ad->ctx, MFREE_ERR_MISMATCH, fn,
                  "the matrix is " + std::to_string(static_cast<int64_t>(rows)) + " x " +
                      std::to_string(static_cast<int64_t>(cols)) + ", the system has " +
                      std::to_string(ad->neq) + " equations");
  const int type = SUNSparseMatrix_SparseType(M);
  if (type != CSR_MAT && type != CSC_MAT)
    return record(ad->ctx, MFREE_ERR_UNSUPPORTED, fn,
                  "unknown sparse type " + std::to_string(type) + " (CSR_MAT or CSC_MAT)");
  const int64_t *ptr = nullptr;
  const int32_t *idx = nullptr;
  const double *vals = nullptr;
  mfree_status_t st = type == CSR_MAT ? mfree_matrix_get_csr(A, &ptr, &idx, &vals)
                                      : mfree_matrix_get_csc(A, &ptr, &idx, &vals);
  if (st != MFREE_SUCCESS) return st;
  const int64_t nnz = ptr[ad->neq];
  if (nnz > static_cast<int64_t>(std::numeric_limits<sunindextype>::max()))
    return record(ad->ctx, MFREE_ERR_UNSUPPORTED, fn,
                  "the mass has " + std::to_string(nnz) +
                      " entries, more than sunindextype holds");
  if (SUNSparseMatrix_NNZ(M) < static_cast<sunindextype>(nnz)) {
    // never shrink to 0: SUNDIALS' sparse matrices keep at least one entry
    if (SUNSparseMatrix_Reallocate(M, static_cast<sunindextype>(nnz > 0 ? nnz : 1)) != 0)
      return record(ad->ctx, MFREE_ERR_ALLOC, fn,
                    "SUNSparseMatrix_Reallocate to " + std::to_string(nnz) + " entries failed");
  }
  sunindextype *mp = SUNSparseMatrix_IndexPointers(M);
  sunindextype *mi = SUNSparseMatrix_IndexValues(M);
  double *mx = SUNSparseMatrix_Data(M);
  if (!mp || !mi || !mx)
    return record(ad->ctx, MFREE_ERR_STATE, fn, "the sparse matrix has no storage");

  // same pattern as the last fill of this matrix?
  bool same = ad->last_matrix == M && ad->last_sparsetype == type &&
              ad->last_ptr.size() == static_cast<size_t>(ad->neq) + 1;
  for (int32_t k = 0; same && k <= ad->neq; ++k) same = ad->last_ptr[k] == ptr[k];
  for (int64_t e = 0; same && e < nnz; ++e) same = ad->last_idx[e] == idx[e];
  for (int32_t k = 0; k <= ad->neq; ++k) mp[k] = static_cast<sunindextype>(ptr[k]);
  for (int64_t e = 0; e < nnz; ++e) {
    mi[e] = static_cast<sunindextype>(idx[e]);
    mx[e] = vals[e];
  }
  if (!same) {
    const bool refill = ad->last_matrix == M;  // a first fill needs no re-analysis
    ad->last_matrix = M;
    ad->last_sparsetype = type;
    ad->last_ptr.assign(ptr, ptr + ad->neq + 1);
    ad->last_idx.assign(idx, idx + nnz);
    if (refill) {
      ++ad->npattern;
      // SUNDIALS' sparse direct solvers (KLU, SuperLU_MT) analyse afresh at the setup
      // after an initialize; their refactorisation would reuse the old analysis
      if (ad->mass_solver && SUNLinSolInitialize(ad->mass_solver) != 0)
        return record(ad->ctx, MFREE_ERR_INTERNAL, fn,
                      "SUNLinSolInitialize of the mass solver failed after the mass "
                      "pattern changed");
    }
  }
  return MFREE_SUCCESS;
}

}  // namespace

extern "C" {

mfree_status_t mfree_sundials_create(mfree_context_t *ctx, mfree_system_t *sys,
                                     mfree_sundials_t **ad) {
  static const char *fn = "mfree_sundials_create";
  if (!ctx) return MFREE_ERR_NULL;
  return guarded(ctx, fn, [&]() {
    if (!ad) return record(ctx, MFREE_ERR_NULL, fn, "output pointer is NULL");
    *ad = nullptr;
    if (!sys) return record(ctx, MFREE_ERR_NULL, fn, "system is NULL");
    int32_t neq = 0;
    mfree_status_t st = mfree_system_get_size(sys, &neq);
    if (st != MFREE_SUCCESS)
      return record(ctx, st, fn, std::string("cannot query the system's size: ") +
                                     mfree_status_string(st));
    std::unique_ptr<mfree_sundials_t> obj(new mfree_sundials_t());
    // The ABI has no context retain: an empty matrix on ctx keeps it alive for us.
    const int64_t zero = 0;
    st = mfree_matrix_create_csr(ctx, 0, 0, &zero, nullptr, nullptr, &obj->ctx_ref);
    if (st != MFREE_SUCCESS) return st;
    obj->ctx = ctx;
    obj->sys = sys;
    obj->neq = neq;
    *ad = obj.release();
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_sundials_destroy(mfree_sundials_t **ad) {
  if (!ad || !*ad) return MFREE_SUCCESS;
  mfree_sundials_t *obj = *ad;
  *ad = nullptr;
  mfree_matrix_destroy(&obj->lumped);
  mfree_matrix_destroy(&obj->mass);
  mfree_matrix_t *ref = obj->ctx_ref;
  delete obj;
  mfree_matrix_destroy(&ref);  // last: the context may go now
  return MFREE_SUCCESS;
}

mfree_status_t mfree_sundials_set_consistent_mass(mfree_sundials_t *ad, int32_t consistent) {
  if (!ad) return MFREE_ERR_NULL;
  ad->consistent = consistent != 0;
  return MFREE_SUCCESS;
}

mfree_status_t mfree_sundials_set_state(mfree_sundials_t *ad, N_Vector y) {
  if (!ad) return MFREE_ERR_NULL;
  static const char *fn = "mfree_sundials_set_state";
  return guarded(ad->ctx, fn, [&]() {
    double *py = nullptr;
    const mfree_status_t st = vector_data(ad, fn, "y", y, &py);
    if (st != MFREE_SUCCESS) return st;
    keep_state(ad, py, nullptr, 0.0);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_sundials_set_mass_solver(mfree_sundials_t *ad, SUNLinearSolver LS) {
  if (!ad) return MFREE_ERR_NULL;
  static const char *fn = "mfree_sundials_set_mass_solver";
  if (LS && (!LS->ops || !LS->ops->initialize))
    return record(ad->ctx, MFREE_ERR_UNSUPPORTED, fn,
                  "the linear solver has no initialize operation");
  ad->mass_solver = LS;
  return MFREE_SUCCESS;
}

mfree_status_t mfree_sundials_create_mass_matrix(mfree_sundials_t *ad, SUNContext sunctx,
                                                 N_Vector y, SUNMatrix *M) {
  if (!ad) return MFREE_ERR_NULL;
  static const char *fn = "mfree_sundials_create_mass_matrix";
  return guarded(ad->ctx, fn, [&]() {
    // (every argument's fault is pending for the assembly: on ranks it is collective)
    Vectors vs{ad, fn};
    if (M)
      *M = nullptr;
    else
      vs.refuse(MFREE_ERR_NULL, "output pointer is NULL");
    if (!sunctx) vs.refuse(MFREE_ERR_NULL, "SUNContext is NULL");
    double *py = nullptr;
    vs.get("y", y, &py);
    mfree_status_t st = vs.go();
    if (st != MFREE_SUCCESS) return st;
    ad->mass_gen = -1;
    st = mfree_system_assemble_mass(ad->sys, py, ad->consistent ? 1 : 0, &ad->mass);
    if (st != MFREE_SUCCESS || vs.faulty()) return vs.finish(st);
    int32_t nr = 0, nc = 0;
    int64_t nnz = 0;
    st = mfree_matrix_get_size(ad->mass, &nr, &nc, &nnz);
    if (st != MFREE_SUCCESS) return st;
    if (nnz > static_cast<int64_t>(std::numeric_limits<sunindextype>::max()))
      return record(ad->ctx, MFREE_ERR_UNSUPPORTED, fn,
                    "the mass has " + std::to_string(nnz) +
                        " entries, more than sunindextype holds");
    SUNMatrix A = SUNSparseMatrix(ad->neq, ad->neq, static_cast<sunindextype>(nnz > 0 ? nnz : 1),
                                  CSR_MAT, sunctx);
    if (!A) return record(ad->ctx, MFREE_ERR_ALLOC, fn, "SUNSparseMatrix failed");
    st = fill_sparse(ad, fn, ad->mass, A);
    if (st != MFREE_SUCCESS) {
      SUNMatDestroy(A);
      return st;
    }
    keep_state(ad, py, nullptr, 0.0);
    *M = A;
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_sundials_get_stats(const mfree_sundials_t *ad, int64_t *nrhs,
                                        int64_t *nres, int64_t *nmass, int64_t *nmass_predicted,
                                        int64_t *npattern) {
  if (!ad) return MFREE_ERR_NULL;
  if (nrhs) *nrhs = ad->nrhs;
  if (nres) *nres = ad->nres;
  if (nmass) *nmass = ad->nmass;
  if (nmass_predicted) *nmass_predicted = ad->nmass_predicted;
  if (npattern) *npattern = ad->npattern;
  return MFREE_SUCCESS;
}

int mfree_sundials_rhs(sunrealtype t, N_Vector y, N_Vector ydot, void *user_data) {
  static const char *fn = "mfree_sundials_rhs";
  mfree_sundials_t *ad = static_cast<mfree_sundials_t *>(user_data);
  return callback(ad, fn, [&]() {
    ++ad->nrhs;
    double *py = nullptr, *pd = nullptr;
    Vectors vs{ad, fn};
    vs.get("y", y, &py);
    vs.get("ydot", ydot, &pd);
    mfree_status_t st = vs.go();
    if (st != MFREE_SUCCESS) return st;
    st = mfree_system_rhs(ad->sys, t, py, pd);  // records its own message
    if (st == MFREE_SUCCESS && !vs.faulty()) keep_state(ad, py, pd, t);
    return vs.finish(st);
  });
}

int mfree_sundials_rhs_mass_form(sunrealtype t, N_Vector y, N_Vector F, void *user_data) {
  static const char *fn = "mfree_sundials_rhs_mass_form";
  mfree_sundials_t *ad = static_cast<mfree_sundials_t *>(user_data);
  return callback(ad, fn, [&]() {
    ++ad->nrhs;
    double *py = nullptr, *pf = nullptr;
    Vectors vs{ad, fn};
    vs.get("y", y, &py);
    vs.get("F", F, &pf);
    mfree_status_t st = vs.go();
    if (st != MFREE_SUCCESS) return st;
    st = mass_form(ad, t, py, pf);  // (its first call, the right-hand side, takes a fault)
    if (st == MFREE_SUCCESS && !vs.faulty()) keep_state(ad, py, ad->work.data(), t);  // work = f(t, y)
    return vs.finish(st);
  });
}

int mfree_sundials_mass(sunrealtype t, SUNMatrix M, void *user_data, N_Vector tmp1,
                        N_Vector tmp2, N_Vector tmp3) {
  (void)tmp1;
  (void)tmp2;
  (void)tmp3;
  static const char *fn = "mfree_sundials_mass";
  mfree_sundials_t *ad = static_cast<mfree_sundials_t *>(user_data);
  return callback(ad, fn, [&]() {
    ++ad->nmass;
    mfree_status_t st = mass_at(ad, fn, t);
    if (st != MFREE_SUCCESS) return st;
    return fill_sparse(ad, fn, ad->mass, M);
  });
}

int mfree_sundials_mass_times(N_Vector v, N_Vector Mv, sunrealtype t, void *mtimes_data) {
  static const char *fn = "mfree_sundials_mass_times";
  mfree_sundials_t *ad = static_cast<mfree_sundials_t *>(mtimes_data);
  return callback(ad, fn, [&]() {
    ++ad->nmass;
    double *pv = nullptr, *pm = nullptr;
    Vectors vs{ad, fn};
    vs.get("v", v, &pv);
    vs.get("Mv", Mv, &pm);
    mfree_status_t st = vs.go();
    if (st != MFREE_SUCCESS) return st;
    // The system's own product, which keeps the mass of one state: on ranks it is
    // collective at every point (a fault here reaches every rank through it; a mass kept
    // by the adapter would make no call), and the consistent mass couples owned particles
    // to ghosts, which only the system exchanges.
    const double *at = nullptr;
    st = mass_state(ad, fn, t, &at);
    if (st == MFREE_SUCCESS) st = mfree_system_apply_mass(ad->sys, at, ad->consistent ? 1 : 0, pv, pm);
    return vs.finish(st);
  });
}

int mfree_sundials_residual(sunrealtype t, N_Vector y, N_Vector yp, N_Vector r,
                            void *user_data) {
  static const char *fn = "mfree_sundials_residual";
  mfree_sundials_t *ad = static_cast<mfree_sundials_t *>(user_data);
  return callback(ad, fn, [&]() {
    ++ad->nres;
    double *py = nullptr, *pp = nullptr, *pr = nullptr;
    Vectors vs{ad, fn};
    vs.get("y", y, &py);
    vs.get("yp", yp, &pp);
    vs.get("r", r, &pr);
    mfree_status_t st = vs.go();
    if (st != MFREE_SUCCESS) return st;
    if (!ad->consistent) {
      // M_L^{-1} (M_L y' - M_L f) = y' - f: the same roots, no mass assembly
      st = mfree_system_rhs(ad->sys, t, py, pr);
      if (st != MFREE_SUCCESS || vs.faulty()) return vs.finish(st);
      for (int32_t q = 0; q < ad->neq; ++q) pr[q] = pp[q] - pr[q];
    } else {
      ad->force.resize(static_cast<size_t>(ad->neq));
      st = mass_form(ad, t, py, ad->force.data());
      if (st != MFREE_SUCCESS || vs.faulty()) return vs.finish(st);
      ad->mass_gen = -1;
      st = mfree_system_assemble_mass(ad->sys, py, 1, &ad->mass);
      if (st != MFREE_SUCCESS) return st;
      st = mfree_matrix_apply(ad->mass, pp, pr);
      if (st != MFREE_SUCCESS) return st;
      for (int32_t q = 0; q < ad->neq; ++q) pr[q] -= ad->force[q];
    }
    keep_state(ad, py, pp, t);
    return MFREE_SUCCESS;
  });
}

}  // extern "C"
