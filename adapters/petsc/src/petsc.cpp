// libmfree_petsc: the owned rows of an mfree assembler's matrix on each rank, renumbered
// from global ids, in a PETSc MATAIJ with an exact preallocation, and a KSP solve. Only
// the public mfree API is used; the ranks agree on every outcome before PETSc's
// collective calls, so that a failure on one rank cannot leave the others waiting.
#include "mfree_petsc.h"

#include <petscao.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include "../../common/guard.hpp"

namespace {

// A PETSc call that failed, with PETSc's message.
struct PetscFailure {
  PetscErrorCode code;
  std::string what;
};

#define MFREE_PETSC_CALL(expr)                         \
  do {                                                 \
    const PetscErrorCode ierr_ = (expr);               \
    if (ierr_) throw PetscFailure{ierr_, #expr};       \
  } while (0)

// An outcome of one rank: status and message (without the function name).
struct Outcome {
  mfree_status_t status = MFREE_SUCCESS;
  std::string message;
};

Outcome fail(mfree_status_t st, std::string msg) { return Outcome{st, std::move(msg)}; }

using mfree_adapter::record;

Outcome petsc_outcome(const PetscFailure &f) {
  const char *text = nullptr;
  PetscErrorMessage(f.code, &text, nullptr);
  const mfree_status_t st =
      f.code == PETSC_ERR_MEM ? MFREE_ERR_ALLOC
      : (f.code >= PETSC_ERR_ARG_SIZ && f.code <= PETSC_ERR_ARG_IDN) || f.code == PETSC_ERR_ARG_UNKNOWN_TYPE ||
              f.code == PETSC_ERR_ARG_OUTOFRANGE || f.code == PETSC_ERR_ARG_WRONG
          ? MFREE_ERR_ARG
          : MFREE_ERR_INTERNAL;
  return fail(st, "PETSc error " + std::to_string(static_cast<int>(f.code)) + " (" + (text ? text : "?") +
                      ") in " + f.what);
}

// Run body, turning exceptions into an outcome of this rank.
template <class Body>
Outcome local(Body &&body) noexcept {
  try {
    return body();
  } catch (const PetscFailure &f) {
    try {
      return petsc_outcome(f);
    } catch (...) {
      return fail(MFREE_ERR_INTERNAL, "PETSc error");
    }
  } catch (const std::bad_alloc &) {
    return fail(MFREE_ERR_ALLOC, "out of memory");
  } catch (const std::exception &e) {
    try {
      return fail(MFREE_ERR_INTERNAL, std::string("internal error: ") + e.what());
    } catch (...) {
      return fail(MFREE_ERR_INTERNAL, "");
    }
  } catch (...) {
    return fail(MFREE_ERR_INTERNAL, "unknown exception");
  }
}

// PETSc's error printing off for the duration of an adapter call.
struct QuietPetsc {
  bool pushed;
  QuietPetsc() : pushed(PetscPushErrorHandler(PetscReturnErrorHandler, nullptr) == 0) {}
  ~QuietPetsc() {
    if (pushed) PetscPopErrorHandler();
  }
};

}  // namespace

struct mfree_petsc {
  mfree_context_t *ctx = nullptr;
  mfree_matrix_t *ctx_ref = nullptr;  // a 0 x 0 matrix: holds a reference on ctx
  MPI_Comm comm = MPI_COMM_NULL;
  int rank = 0, size = 1;
  std::string prefix;
  int32_t cdim = 0, cn = 0;
  std::vector<double> coords;
  // after setup
  bool ready = false;
  mfree_assembler_t *as = nullptr;
  int32_t nc = 1, nlocal = 0, nowned = 0;
  mfree_matrix_t *K = nullptr;  // the assembler's matrix of this rank's particles
  int64_t pattern = 0;
  std::vector<double> f;           // its right-hand side
  std::vector<PetscInt> node_row;  // PETSc node of each local particle
  std::vector<int64_t> gids;       // global id of each local particle
  std::vector<PetscInt> cols;      // PETSc columns of the entries of the owned rows
  PetscInt first_node = 0, nglobal_nodes = 0;
  Mat A = nullptr;
  Vec b = nullptr, x = nullptr;
  KSP ksp = nullptr;
  std::vector<PetscInt> drows;  // Dirichlet rows (global) and values
  std::vector<double> dvals;
  int32_t its = 0, reason = 0;
  double rnorm = 0.0;

  void release() {
    if (ksp) KSPDestroy(&ksp);
    if (A) MatDestroy(&A);
    if (b) VecDestroy(&b);
    if (x) VecDestroy(&x);
    if (K) mfree_matrix_destroy(&K);
    ready = false;
    as = nullptr;
  }
};

namespace {

// The ranks agree on the outcome: every rank gets the most negative status (the lowest
// rank among equals) and that rank's message. Positive statuses are not errors here.
mfree_status_t agree(mfree_petsc_t *pk, const char *fn, const Outcome &mine) {
  int in[2] = {mine.status < 0 ? static_cast<int>(mine.status) : 0, pk->rank}, out[2] = {0, 0};
  MPI_Allreduce(in, out, 1, MPI_2INT, MPI_MINLOC, pk->comm);
  if (out[0] == 0) return MFREE_SUCCESS;
  const int root = out[1];
  std::string msg = root == pk->rank ? mine.message : std::string();
  int len = static_cast<int>(std::min<size_t>(msg.size(), 4000));
  MPI_Bcast(&len, 1, MPI_INT, root, pk->comm);
  std::vector<char> buf(static_cast<size_t>(len) + 1, '\0');
  if (root == pk->rank) std::memcpy(buf.data(), msg.data(), static_cast<size_t>(len));
  MPI_Bcast(buf.data(), len, MPI_CHAR, root, pk->comm);
  const mfree_status_t st = static_cast<mfree_status_t>(out[0]);
  if (root == pk->rank) return record(pk->ctx, st, fn, mine.message);
  return record(pk->ctx, st, fn, "rank " + std::to_string(root) + " failed: " + buf.data());
}

// Copy the assembler's matrix values of the owned rows and its loads into A and b
// (collective), then apply the Dirichlet rows.
void fill(mfree_petsc_t *pk, Mat A, Vec b, Vec x, const std::vector<PetscInt> &cols) {
  const int64_t *rp = nullptr;
  const int32_t *ci = nullptr;
  const double *v = nullptr;
  if (mfree_matrix_get_csr(pk->K, &rp, &ci, &v) != MFREE_SUCCESS) throw std::logic_error("no CSR view of the local matrix");
  const int32_t nrows = pk->nowned * pk->nc;
  for (int32_t r = 0; r < nrows; ++r) {
    const PetscInt row = static_cast<PetscInt>(pk->first_node) * pk->nc + r;
    const PetscInt len = static_cast<PetscInt>(rp[r + 1] - rp[r]);
    MFREE_PETSC_CALL(MatSetValues(A, 1, &row, len, cols.data() + rp[r], v + rp[r], INSERT_VALUES));
  }
  MFREE_PETSC_CALL(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY));
  MFREE_PETSC_CALL(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY));
  PetscScalar *bb = nullptr;
  MFREE_PETSC_CALL(VecGetArray(b, &bb));
  for (int32_t r = 0; r < nrows; ++r) bb[r] = pk->f[static_cast<size_t>(r)];
  MFREE_PETSC_CALL(VecRestoreArray(b, &bb));
  MFREE_PETSC_CALL(VecSet(x, 0.0));
  // Dirichlet rows: MatZeroRowsColumns is collective, called on every rank. The unit
  // diagonal is scaled to the matrix's mean diagonal so that the constrained rows do not
  // spoil the conditioning that multigrid sees.
  PetscInt nd = static_cast<PetscInt>(pk->drows.size()), ndg = 0;
  MPI_Allreduce(&nd, &ndg, 1, MPIU_INT, MPI_SUM, pk->comm);
  if (ndg == 0) return;
  Vec d = nullptr;
  MFREE_PETSC_CALL(VecDuplicate(b, &d));
  MFREE_PETSC_CALL(MatGetDiagonal(A, d));
  PetscReal dsum = 0.0;
  MFREE_PETSC_CALL(VecNorm(d, NORM_1, &dsum));
  MFREE_PETSC_CALL(VecDestroy(&d));
  PetscInt N = 0;
  MFREE_PETSC_CALL(VecGetSize(b, &N));
  const PetscScalar diag = N > 0 && dsum > 0.0 ? dsum / N : 1.0;
  PetscScalar *xx = nullptr;
  MFREE_PETSC_CALL(VecGetArray(x, &xx));
  for (size_t k = 0; k < pk->drows.size(); ++k)
    xx[pk->drows[k] - static_cast<PetscInt>(pk->first_node) * pk->nc] = pk->dvals[k];
  MFREE_PETSC_CALL(VecRestoreArray(x, &xx));
  MFREE_PETSC_CALL(MatZeroRowsColumns(A, nd, pk->drows.data(), diag, x, b));
  MFREE_PETSC_CALL(VecSet(x, 0.0));
}

// The assembler's matrix and loads on this rank (local).
Outcome read_assembler(mfree_petsc_t *pk, mfree_assembler_t *as, mfree_matrix_t **K, std::vector<double> &f) {
  mfree_status_t st = mfree_assembler_assemble_matrix(as, K);
  if (st != MFREE_SUCCESS) {
    char msg[512] = "";
    mfree_context_get_last_error(pk->ctx, nullptr, msg, sizeof msg);
    return fail(st, std::string("assembling the local matrix: ") + msg);
  }
  int32_t nr = 0, ncol = 0;
  int64_t nnz = 0;
  if ((st = mfree_matrix_get_size(*K, &nr, &ncol, &nnz)) != MFREE_SUCCESS) return fail(st, "matrix size");
  f.assign(static_cast<size_t>(nr), 0.0);
  if ((st = mfree_assembler_assemble_rhs(as, f.data())) != MFREE_SUCCESS) {
    char msg[512] = "";
    mfree_context_get_last_error(pk->ctx, nullptr, msg, sizeof msg);
    return fail(st, std::string("assembling the local loads: ") + msg);
  }
  return Outcome{};
}

// Non-finite entries of the owned rows (matrix and loads).
Outcome check_finite(const mfree_petsc_t *pk, const mfree_matrix_t *K, const std::vector<double> &f,
                     int32_t nowned, int32_t nc, const int64_t *gids) {
  const int64_t *rp = nullptr;
  const int32_t *ci = nullptr;
  const double *v = nullptr;
  mfree_matrix_get_csr(K, &rp, &ci, &v);
  (void)pk;
  for (int32_t r = 0; r < nowned * nc; ++r) {
    bool ok = std::isfinite(f[static_cast<size_t>(r)]);
    for (int64_t k = rp[r]; ok && k < rp[r + 1]; ++k) ok = std::isfinite(v[k]);
    if (!ok)
      return fail(MFREE_ERR_INPUT, "a non-finite matrix or load entry in the row of owned node " +
                                       std::to_string(r / nc) + " (global id " + std::to_string(gids[r / nc]) + ")");
  }
  return Outcome{};
}

bool valid_prefix(const char *p) {
  const size_t n = std::strlen(p);
  if (n > 63) return false;
  for (size_t i = 0; i < n; ++i) {
    const char c = p[i];
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_' || (i > 0 && c >= '0' && c <= '9');
    if (!ok) return false;
  }
  return true;
}

}  // namespace

extern "C" {

mfree_status_t mfree_petsc_create(mfree_context_t *ctx, MPI_Comm comm, mfree_petsc_t **pk) {
  if (!ctx) return MFREE_ERR_NULL;
  static const char *fn = "mfree_petsc_create";
  const Outcome o = local([&]() -> Outcome {
    if (!pk) return fail(MFREE_ERR_NULL, "output pointer is NULL");
    *pk = nullptr;
    if (comm == MPI_COMM_NULL) return fail(MFREE_ERR_ARG, "the communicator is MPI_COMM_NULL");
    PetscBool init = PETSC_FALSE;
    PetscInitialized(&init);
    if (!init) return fail(MFREE_ERR_STATE, "PETSc is not initialised: call PetscInitialize first");
    std::unique_ptr<mfree_petsc_t> obj(new mfree_petsc_t());
    const int64_t zero = 0;
    const mfree_status_t st = mfree_matrix_create_csr(ctx, 0, 0, &zero, nullptr, nullptr, &obj->ctx_ref);
    if (st != MFREE_SUCCESS) return fail(st, "no memory for the context reference");
    obj->ctx = ctx;
    obj->comm = comm;
    MPI_Comm_rank(comm, &obj->rank);
    MPI_Comm_size(comm, &obj->size);
    *pk = obj.release();
    return Outcome{};
  });
  return o.status == MFREE_SUCCESS ? MFREE_SUCCESS : record(ctx, o.status, fn, o.message);
}

mfree_status_t mfree_petsc_destroy(mfree_petsc_t **pk) {
  if (!pk || !*pk) return MFREE_SUCCESS;
  mfree_petsc_t *obj = *pk;
  *pk = nullptr;
  {
    QuietPetsc quiet;
    obj->release();
  }
  mfree_matrix_t *ref = obj->ctx_ref;
  delete obj;
  mfree_matrix_destroy(&ref);
  return MFREE_SUCCESS;
}

mfree_status_t mfree_petsc_set_options_prefix(mfree_petsc_t *pk, const char *prefix) {
  if (!pk) return MFREE_ERR_NULL;
  static const char *fn = "mfree_petsc_set_options_prefix";
  const Outcome o = local([&]() -> Outcome {
    if (prefix && !valid_prefix(prefix))
      return fail(MFREE_ERR_ARG, "an options prefix is letters, digits and '_' (not first), at most 63 characters");
    pk->prefix = prefix ? prefix : "";
    return Outcome{};
  });
  return o.status == MFREE_SUCCESS ? MFREE_SUCCESS : record(pk->ctx, o.status, fn, o.message);
}

mfree_status_t mfree_petsc_set_coordinates(mfree_petsc_t *pk, int32_t dim, int32_t nowned, const double *x) {
  if (!pk) return MFREE_ERR_NULL;
  static const char *fn = "mfree_petsc_set_coordinates";
  const Outcome o = local([&]() -> Outcome {
    if (dim != 2 && dim != 3) return fail(MFREE_ERR_ARG, "dim must be 2 or 3, got " + std::to_string(dim));
    if (nowned < 0) return fail(MFREE_ERR_ARG, "negative node count");
    if (nowned > 0 && !x) return fail(MFREE_ERR_NULL, "coordinates are NULL");
    const size_t n = static_cast<size_t>(nowned) * static_cast<size_t>(dim);
    for (size_t k = 0; k < n; ++k)
      if (!std::isfinite(x[k]))
        return fail(MFREE_ERR_INPUT, "coordinate " + std::to_string(k % dim) + " of node " +
                                         std::to_string(k / dim) + " is not finite");
    std::vector<double> c(x, x + n);
    pk->coords.swap(c);
    pk->cdim = dim;
    pk->cn = nowned;
    return Outcome{};
  });
  return o.status == MFREE_SUCCESS ? MFREE_SUCCESS : record(pk->ctx, o.status, fn, o.message);
}

mfree_status_t mfree_petsc_setup(mfree_petsc_t *pk, mfree_assembler_t *as, int32_t ncomp, int32_t nlocal,
                                 int32_t nowned, const int64_t *gids) {
  if (!pk) return MFREE_ERR_NULL;
  static const char *fn = "mfree_petsc_setup";
  QuietPetsc quiet;
  mfree_matrix_t *K = nullptr;
  std::vector<double> f;
  // 1. local checks and the local matrix
  Outcome o = local([&]() -> Outcome {
    if (!as) return fail(MFREE_ERR_NULL, "the assembler is NULL");
    if (ncomp < 1 || ncomp > 3) return fail(MFREE_ERR_ARG, "ncomp must be 1, 2 or 3, got " + std::to_string(ncomp));
    if (nowned < 0 || nlocal < nowned)
      return fail(MFREE_ERR_ARG, "need 0 <= nowned <= nlocal, got nowned " + std::to_string(nowned) + ", nlocal " +
                                     std::to_string(nlocal));
    if (nlocal > 0 && !gids) return fail(MFREE_ERR_NULL, "global ids are NULL");
    const int64_t idmax = static_cast<int64_t>(INT32_MAX) / ncomp;
    for (int32_t i = 0; i < nlocal; ++i)
      if (gids[i] < 0 || gids[i] >= idmax)
        return fail(MFREE_ERR_INPUT, "global id " + std::to_string(gids[i]) + " of particle " + std::to_string(i) +
                                         " is outside [0, " + std::to_string(idmax) + ") (PETSc's 32-bit indices)");
    {
      std::vector<int64_t> s(gids, gids + nlocal);
      std::sort(s.begin(), s.end());
      const auto d = std::adjacent_find(s.begin(), s.end());
      if (d != s.end()) return fail(MFREE_ERR_INPUT, "global id " + std::to_string(*d) + " is repeated on this rank");
    }
    if (pk->cn != 0 && pk->cn != nowned)
      return fail(MFREE_ERR_MISMATCH, "the coordinates are of " + std::to_string(pk->cn) + " nodes, setup has " +
                                          std::to_string(nowned) + " owned nodes");
    Outcome r = read_assembler(pk, as, &K, f);
    if (r.status != MFREE_SUCCESS) return r;
    int32_t nr = 0, ncol = 0;
    int64_t nnz = 0;
    mfree_matrix_get_size(K, &nr, &ncol, &nnz);
    if (static_cast<int64_t>(nr) != static_cast<int64_t>(nlocal) * ncomp)
      return fail(MFREE_ERR_MISMATCH, "the assembler has " + std::to_string(nr) + " unknowns, not nlocal * ncomp = " +
                                          std::to_string(static_cast<int64_t>(nlocal) * ncomp) +
                                          " (another particle count, ncomp, or Lagrange multipliers)");
    return check_finite(pk, K, f, nowned, ncomp, gids);
  });
  mfree_status_t st = agree(pk, fn, o);
  if (st != MFREE_SUCCESS) {
    mfree_matrix_destroy(&K);
    return st;
  }
  // Arguments that must be common, agreed in one all-reduce of (value, rank) pairs:
  // ncomp (the unknowns per node of every row), and the near null space, which is built
  // collectively on every rank or on none: from the coordinates that every rank with
  // owned nodes gave for this ncomp, or from none (a rank without owned nodes takes part
  // either way).
  bool near_null = false;
  {
    const int has = pk->cdim > 1 && pk->cdim == ncomp && pk->cn == nowned ? 1 : 0;
    const int in[8] = {ncomp, pk->rank, -ncomp, pk->rank, nowned > 0 ? has : 1, pk->rank, -has, pk->rank};
    int out[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    MPI_Allreduce(in, out, 4, MPI_2INT, MPI_MINLOC, pk->comm);
    char msg[320] = "";
    if (out[0] != -out[2])
      std::snprintf(msg, sizeof msg,
                    "ranks disagree on ncomp: rank %d passes %d, rank %d passes %d (every rank must pass the same)",
                    out[1], out[0], out[3], -out[2]);
    else if (out[6] == -1 && out[4] == 0)
      std::snprintf(msg, sizeof msg,
                    "rank %d owns nodes but gave no coordinates for ncomp %d (mfree_petsc_set_coordinates) while "
                    "rank %d gave them: every rank with owned nodes gives them, or none does",
                    out[5], ncomp, out[7]);
    if (msg[0]) {
      mfree_matrix_destroy(&K);
      return record(pk->ctx, MFREE_ERR_ARG, fn, msg);
    }
    near_null = out[6] == -1;
  }
  // 2. numbering: owned nodes in rank order; ghosts through an application ordering
  PetscInt first = 0, total = 0;
  std::vector<PetscInt> node_row(static_cast<size_t>(nlocal));
  AO ao = nullptr;
  o = local([&]() -> Outcome {
    PetscInt mine = nowned;
    MPI_Exscan(&mine, &first, 1, MPIU_INT, MPI_SUM, pk->comm);
    if (pk->rank == 0) first = 0;
    MPI_Allreduce(&mine, &total, 1, MPIU_INT, MPI_SUM, pk->comm);
    std::vector<PetscInt> app(static_cast<size_t>(nowned)), pet(static_cast<size_t>(nowned));
    for (int32_t i = 0; i < nowned; ++i) app[i] = static_cast<PetscInt>(gids[i]), pet[i] = first + i;
    MFREE_PETSC_CALL(AOCreateMapping(pk->comm, nowned, app.data(), pet.data(), &ao));
    for (int32_t i = 0; i < nlocal; ++i) node_row[i] = static_cast<PetscInt>(gids[i]);
    MFREE_PETSC_CALL(AOApplicationToPetsc(ao, nlocal, node_row.data()));
    return Outcome{};
  });
  if (ao) AODestroy(&ao);
  // An owned id also owned elsewhere maps to one owner only; an id no rank owns to -1.
  if (o.status == MFREE_SUCCESS)
    for (int32_t i = 0; i < nlocal; ++i) {
      if (i < nowned && node_row[i] != first + i) {
        o = fail(MFREE_ERR_INPUT, "global id " + std::to_string(gids[i]) + " of owned node " + std::to_string(i) +
                                      " is owned by another rank too");
        break;
      }
      if (node_row[i] < 0) {
        o = fail(MFREE_ERR_INPUT, "global id " + std::to_string(gids[i]) + " of ghost " + std::to_string(i) +
                                      " is owned by no rank");
        break;
      }
    }
  if (o.status == MFREE_SUCCESS && static_cast<int64_t>(total) * ncomp > INT32_MAX)
    o = fail(MFREE_ERR_INPUT, "too many unknowns for PETSc's 32-bit indices");
  st = agree(pk, fn, o);
  if (st != MFREE_SUCCESS) {
    mfree_matrix_destroy(&K);
    return st;
  }
  // 3. columns, preallocation, objects, first fill
  Mat A = nullptr;
  Vec b = nullptr, x = nullptr;
  KSP ksp = nullptr;
  std::vector<PetscInt> cols;
  mfree_petsc_t trial;  // numbering for fill() before the commit
  o = local([&]() -> Outcome {
    const int64_t *rp = nullptr;
    const int32_t *ci = nullptr;
    const double *v = nullptr;
    mfree_matrix_get_csr(K, &rp, &ci, &v);
    const int32_t nrows = nowned * ncomp;
    const PetscInt lo = first * ncomp, hi = (first + nowned) * ncomp;
    cols.resize(static_cast<size_t>(rp[nrows]));
    std::vector<PetscInt> dnnz(static_cast<size_t>(nrows), 0), onnz(static_cast<size_t>(nrows), 0);
    for (int32_t r = 0; r < nrows; ++r)
      for (int64_t k = rp[r]; k < rp[r + 1]; ++k) {
        const int32_t c = ci[k];
        const PetscInt g = node_row[c / ncomp] * ncomp + c % ncomp;
        cols[k] = g;
        ++(g >= lo && g < hi ? dnnz[r] : onnz[r]);
      }
    MFREE_PETSC_CALL(MatCreate(pk->comm, &A));
    MFREE_PETSC_CALL(MatSetSizes(A, nrows, nrows, PETSC_DETERMINE, PETSC_DETERMINE));
    MFREE_PETSC_CALL(MatSetBlockSize(A, ncomp));
    MFREE_PETSC_CALL(MatSetType(A, MATAIJ));
    if (!pk->prefix.empty()) MFREE_PETSC_CALL(MatSetOptionsPrefix(A, pk->prefix.c_str()));
    MFREE_PETSC_CALL(MatSetFromOptions(A));
    MFREE_PETSC_CALL(MatXAIJSetPreallocation(A, 1, dnnz.data(), onnz.data(), nullptr, nullptr));
    MFREE_PETSC_CALL(MatSetOption(A, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE));
    MFREE_PETSC_CALL(MatSetOption(A, MAT_NO_OFF_PROC_ENTRIES, PETSC_TRUE));
    MFREE_PETSC_CALL(MatSetOption(A, MAT_KEEP_NONZERO_PATTERN, PETSC_TRUE));
    MFREE_PETSC_CALL(MatCreateVecs(A, &x, &b));
    if (near_null) {  // (a rank without owned nodes adds no rows)
      Vec c = nullptr;
      MatNullSpace nsp = nullptr;
      MFREE_PETSC_CALL(VecCreateMPI(pk->comm, nrows, PETSC_DETERMINE, &c));
      MFREE_PETSC_CALL(VecSetBlockSize(c, ncomp));
      PetscScalar *cc = nullptr;
      MFREE_PETSC_CALL(VecGetArray(c, &cc));
      for (int32_t k = 0; k < nrows; ++k) cc[k] = pk->coords[static_cast<size_t>(k)];
      MFREE_PETSC_CALL(VecRestoreArray(c, &cc));
      const PetscErrorCode e1 = MatNullSpaceCreateRigidBody(c, &nsp);
      VecDestroy(&c);
      if (e1) throw PetscFailure{e1, "MatNullSpaceCreateRigidBody"};
      const PetscErrorCode e2 = MatSetNearNullSpace(A, nsp);
      MatNullSpaceDestroy(&nsp);
      if (e2) throw PetscFailure{e2, "MatSetNearNullSpace"};
    }
    MFREE_PETSC_CALL(KSPCreate(pk->comm, &ksp));
    MFREE_PETSC_CALL(KSPSetOperators(ksp, A, A));
    MFREE_PETSC_CALL(KSPSetType(ksp, KSPCG));
    PC pc = nullptr;
    MFREE_PETSC_CALL(KSPGetPC(ksp, &pc));
    MFREE_PETSC_CALL(PCSetType(pc, PCGAMG));
    MFREE_PETSC_CALL(KSPSetTolerances(ksp, 1e-10, 1e-50, PETSC_DEFAULT, 10000));
    if (!pk->prefix.empty()) MFREE_PETSC_CALL(KSPSetOptionsPrefix(ksp, pk->prefix.c_str()));
    MFREE_PETSC_CALL(KSPSetFromOptions(ksp));
    trial.comm = pk->comm;
    trial.K = K;
    trial.f = f;
    trial.nc = ncomp;
    trial.nowned = nowned;
    trial.first_node = first;
    fill(&trial, A, b, x, cols);
    trial.K = nullptr;
    return Outcome{};
  });
  st = agree(pk, fn, o);
  if (st != MFREE_SUCCESS) {
    if (ksp) KSPDestroy(&ksp);
    if (A) MatDestroy(&A);
    if (b) VecDestroy(&b);
    if (x) VecDestroy(&x);
    mfree_matrix_destroy(&K);
    return st;
  }
  // 4. commit
  pk->release();
  pk->as = as;
  pk->nc = ncomp;
  pk->nlocal = nlocal;
  pk->nowned = nowned;
  pk->K = K;
  mfree_matrix_get_pattern_id(K, &pk->pattern);
  pk->f.swap(f);
  pk->node_row.swap(node_row);
  pk->gids.assign(gids, gids + nlocal);
  pk->cols.swap(cols);
  pk->first_node = first;
  pk->nglobal_nodes = total;
  pk->A = A;
  pk->b = b;
  pk->x = x;
  pk->ksp = ksp;
  pk->drows.clear();
  pk->dvals.clear();
  pk->its = pk->reason = 0;
  pk->rnorm = 0.0;
  pk->ready = true;
  return MFREE_SUCCESS;
}

mfree_status_t mfree_petsc_assemble(mfree_petsc_t *pk) {
  if (!pk) return MFREE_ERR_NULL;
  static const char *fn = "mfree_petsc_assemble";
  QuietPetsc quiet;
  std::vector<double> f;
  Outcome o = local([&]() -> Outcome {
    if (!pk->ready) return fail(MFREE_ERR_STATE, "the system is not set up (mfree_petsc_setup)");
    Outcome r = read_assembler(pk, pk->as, &pk->K, f);
    if (r.status != MFREE_SUCCESS) return r;
    int64_t id = 0;
    mfree_matrix_get_pattern_id(pk->K, &id);
    if (id != pk->pattern)
      return fail(MFREE_ERR_STATE, "the assembler's pattern changed (it was set up again): call mfree_petsc_setup");
    return check_finite(pk, pk->K, f, pk->nowned, pk->nc, pk->gids.data());
  });
  mfree_status_t st = agree(pk, fn, o);
  if (st != MFREE_SUCCESS) return st;
  o = local([&]() -> Outcome {
    pk->f.swap(f);
    fill(pk, pk->A, pk->b, pk->x, pk->cols);
    return Outcome{};
  });
  return agree(pk, fn, o);
}

mfree_status_t mfree_petsc_set_dirichlet(mfree_petsc_t *pk, int32_t n, const int32_t *dofs, const double *values) {
  if (!pk) return MFREE_ERR_NULL;
  static const char *fn = "mfree_petsc_set_dirichlet";
  QuietPetsc quiet;
  std::vector<PetscInt> rows;
  std::vector<double> vals;
  Outcome o = local([&]() -> Outcome {
    if (!pk->ready) return fail(MFREE_ERR_STATE, "the system is not set up (mfree_petsc_setup)");
    if (n < 0) return fail(MFREE_ERR_ARG, "negative count");
    if (n > 0 && (!dofs || !values)) return fail(MFREE_ERR_NULL, "dofs or values are NULL");
    const int32_t nrows = pk->nowned * pk->nc;
    std::vector<char> seen(static_cast<size_t>(nrows), 0);
    for (int32_t k = 0; k < n; ++k) {
      if (dofs[k] < 0 || dofs[k] >= nrows)
        return fail(MFREE_ERR_INPUT, "unknown " + std::to_string(dofs[k]) + " (entry " + std::to_string(k) +
                                         ") is not an unknown of an owned node [0, " + std::to_string(nrows) + ")");
      if (seen[dofs[k]]++) return fail(MFREE_ERR_INPUT, "unknown " + std::to_string(dofs[k]) + " is repeated");
      if (!std::isfinite(values[k]))
        return fail(MFREE_ERR_INPUT, "value " + std::to_string(k) + " is not finite");
      rows.push_back(static_cast<PetscInt>(pk->first_node) * pk->nc + dofs[k]);
      vals.push_back(values[k]);
    }
    return Outcome{};
  });
  mfree_status_t st = agree(pk, fn, o);
  if (st != MFREE_SUCCESS) return st;
  pk->drows.swap(rows);
  pk->dvals.swap(vals);
  o = local([&]() -> Outcome {
    fill(pk, pk->A, pk->b, pk->x, pk->cols);
    return Outcome{};
  });
  return agree(pk, fn, o);
}

mfree_status_t mfree_petsc_solve(mfree_petsc_t *pk, double *u) {
  if (!pk) return MFREE_ERR_NULL;
  static const char *fn = "mfree_petsc_solve";
  QuietPetsc quiet;
  Outcome o = local([&]() -> Outcome {
    if (!pk->ready) return fail(MFREE_ERR_STATE, "the system is not set up (mfree_petsc_setup)");
    return Outcome{};
  });
  mfree_status_t st = agree(pk, fn, o);
  if (st != MFREE_SUCCESS) return st;
  o = local([&]() -> Outcome {
    MFREE_PETSC_CALL(KSPSolve(pk->ksp, pk->b, pk->x));
    KSPConvergedReason reason = KSP_CONVERGED_ITERATING;
    PetscInt its = 0;
    PetscReal rn = 0.0;
    MFREE_PETSC_CALL(KSPGetConvergedReason(pk->ksp, &reason));
    MFREE_PETSC_CALL(KSPGetIterationNumber(pk->ksp, &its));
    MFREE_PETSC_CALL(KSPGetResidualNorm(pk->ksp, &rn));
    pk->reason = static_cast<int32_t>(reason);
    pk->its = static_cast<int32_t>(its);
    pk->rnorm = static_cast<double>(rn);
    if (u) {
      const PetscScalar *xx = nullptr;
      MFREE_PETSC_CALL(VecGetArrayRead(pk->x, &xx));
      for (int32_t k = 0; k < pk->nowned * pk->nc; ++k) u[k] = xx[k];
      MFREE_PETSC_CALL(VecRestoreArrayRead(pk->x, &xx));
    }
    return Outcome{};
  });
  st = agree(pk, fn, o);
  if (st != MFREE_SUCCESS) return st;
  if (pk->reason < 0) {
    const char *name = KSPConvergedReasons[pk->reason];
    return record(pk->ctx, MFREE_FAIL_SINGULAR, fn,
                  std::string("the Krylov solver stopped without converging: ") + (name ? name : "?") + " after " +
                      std::to_string(pk->its) + " iterations, residual norm " + std::to_string(pk->rnorm));
  }
  return MFREE_SUCCESS;
}

mfree_status_t mfree_petsc_get_info(const mfree_petsc_t *pk, int32_t *iterations, double *residual,
                                    int32_t *reason) {
  if (!pk) return MFREE_ERR_NULL;
  if (iterations) *iterations = pk->its;
  if (residual) *residual = pk->rnorm;
  if (reason) *reason = pk->reason;
  return MFREE_SUCCESS;
}

mfree_status_t mfree_petsc_get_numbering(const mfree_petsc_t *pk, int64_t *first, int64_t *nglobal,
                                         int64_t *node_rows) {
  if (!pk) return MFREE_ERR_NULL;
  if (!pk->ready)
    return record(pk->ctx, MFREE_ERR_STATE, "mfree_petsc_get_numbering", "the system is not set up (mfree_petsc_setup)");
  if (first) *first = static_cast<int64_t>(pk->first_node) * pk->nc;
  if (nglobal) *nglobal = static_cast<int64_t>(pk->nglobal_nodes) * pk->nc;
  if (node_rows)
    for (int32_t i = 0; i < pk->nlocal; ++i) node_rows[i] = static_cast<int64_t>(pk->node_row[i]);
  return MFREE_SUCCESS;
}

mfree_status_t mfree_petsc_get_objects(const mfree_petsc_t *pk, Mat *A, KSP *ksp, Vec *b, Vec *x) {
  if (!pk) return MFREE_ERR_NULL;
  if (!pk->ready)
    return record(pk->ctx, MFREE_ERR_STATE, "mfree_petsc_get_objects", "the system is not set up (mfree_petsc_setup)");
  if (A) *A = pk->A;
  if (ksp) *ksp = pk->ksp;
  if (b) *b = pk->b;
  if (x) *x = pk->x;
  return MFREE_SUCCESS;
}

}  // extern "C"
