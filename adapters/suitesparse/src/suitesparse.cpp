// libmfree_suitesparse: CHOLMOD, UMFPACK and KLU behind the C ABI of
// mfree_suitesparse.h. Matrices are read through mfree's zero-copy CSR views (CSR of A
// is CSC of A^T); only the public mfree API is used.
#include "mfree_suitesparse.h"

#include <cholmod.h>
#include <klu.h>
#include <umfpack.h>

#include <cfloat>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <new>
#include <string>
#include <type_traits>
#include <vector>

#include "../../common/guard.hpp"
#include "index_width.h"

static_assert(std::is_same<int32_t, int>::value, "the 32-bit SuiteSparse variants take int");
static_assert(std::is_same<int64_t, SuiteSparse_long>::value,
              "the 64-bit SuiteSparse variants take SuiteSparse_long, which must be int64_t "
              "for the matrix views to be passed without conversion");

namespace {

// ---- outcome of a step ------------------------------------------------------------------

struct Outcome {
  mfree_status_t status = MFREE_SUCCESS;
  std::string message;    // without the function-name prefix
  bool overflow = false;  // a 32-bit variant ran out of index range: retry with 64 bits
  bool ok() const { return status == MFREE_SUCCESS; }
};

Outcome fail(mfree_status_t status, std::string message, bool overflow = false) {
  Outcome o;
  o.status = status;
  o.message = std::move(message);
  o.overflow = overflow;
  return o;
}

// The matrix as the solvers see it: CSC of A^T, with index type I.
template <class I>
struct View {
  I n = 0;
  int64_t nnz = 0;
  I *p = nullptr;  // SuiteSparse takes non-const pointers but documents "not modified"
  I *i = nullptr;
  double *x = nullptr;
};

const char *kind_name(mfree_solver_kind_t kind) {
  switch (kind) {
    case MFREE_SOLVER_CHOLMOD: return "CHOLMOD";
    case MFREE_SOLVER_UMFPACK: return "UMFPACK";
    case MFREE_SOLVER_KLU: return "KLU";
  }
  return "unknown solver";
}

// ---- common interface of the six (solver, index width) back ends --------------------------

class Backend {
 public:
  virtual ~Backend() = default;
  virtual int32_t width() const = 0;
  // Symbolic analysis; releases any previous analysis and factors first.
  virtual Outcome analyze(const void *view) = 0;
  // Numeric factorisation on the current analysis (refactor: values changed only).
  virtual Outcome factor(const void *view, bool refactor) = 0;
  // x(:, j) = A^{-1} b(:, j); arguments already checked; n > 0, nrhs > 0.
  virtual Outcome solve(int32_t nrhs, const double *b, int64_t ldb, double *x, int64_t ldx) = 0;
  virtual double rcond() const = 0;
  virtual int64_t factor_nnz() const = 0;
};

// ---- KLU ------------------------------------------------------------------------------------

template <class I>
struct KluApi;

template <>
struct KluApi<int32_t> {
  using Common = klu_common;
  using Symbolic = klu_symbolic;
  using Numeric = klu_numeric;
  static void defaults(Common *c) { klu_defaults(c); }
  static Symbolic *analyze(int n, int *p, int *i, Common *c) { return klu_analyze(n, p, i, c); }
  static Numeric *factor(int *p, int *i, double *x, Symbolic *s, Common *c) {
    return klu_factor(p, i, x, s, c);
  }
  static bool refactor(int *p, int *i, double *x, Symbolic *s, Numeric *f, Common *c) {
    return klu_refactor(p, i, x, s, f, c) != 0;
  }
  static bool tsolve(Symbolic *s, Numeric *f, int ld, int nrhs, double *b, Common *c) {
    return klu_tsolve(s, f, ld, nrhs, b, c) != 0;
  }
  static void rcond(Symbolic *s, Numeric *f, Common *c) { klu_rcond(s, f, c); }
  static void free_symbolic(Symbolic **s, Common *c) { klu_free_symbolic(s, c); }
  static void free_numeric(Numeric **f, Common *c) { klu_free_numeric(f, c); }
};

template <>
struct KluApi<int64_t> {
  using Common = klu_l_common;
  using Symbolic = klu_l_symbolic;
  using Numeric = klu_l_numeric;
  static void defaults(Common *c) { klu_l_defaults(c); }
  static Symbolic *analyze(int64_t n, int64_t *p, int64_t *i, Common *c) {
    return klu_l_analyze(n, p, i, c);
  }
  static Numeric *factor(int64_t *p, int64_t *i, double *x, Symbolic *s, Common *c) {
    return klu_l_factor(p, i, x, s, c);
  }
  static bool refactor(int64_t *p, int64_t *i, double *x, Symbolic *s, Numeric *f, Common *c) {
    return klu_l_refactor(p, i, x, s, f, c) != 0;
  }
  static bool tsolve(Symbolic *s, Numeric *f, int64_t ld, int64_t nrhs, double *b, Common *c) {
    return klu_l_tsolve(s, f, ld, nrhs, b, c) != 0;
  }
  static void rcond(Symbolic *s, Numeric *f, Common *c) { klu_l_rcond(s, f, c); }
  static void free_symbolic(Symbolic **s, Common *c) { klu_l_free_symbolic(s, c); }
  static void free_numeric(Numeric **f, Common *c) { klu_l_free_numeric(f, c); }
};

template <class I>
class KluBackend final : public Backend {
  using Api = KluApi<I>;

 public:
  KluBackend() {
    Api::defaults(&common_);
    // Stop at the first zero pivot: a singular matrix is reported, never solved with.
    common_.halt_if_singular = 1;
  }
  ~KluBackend() override { release(); }
  int32_t width() const override { return sizeof(I) == 4 ? 32 : 64; }

  Outcome analyze(const void *v) override {
    const auto &a = *static_cast<const View<I> *>(v);
    release();
    n_ = a.n;
    symbolic_ = Api::analyze(a.n, a.p, a.i, &common_);
    if (!symbolic_) return status_error("klu_analyze");
    return {};
  }

  Outcome factor(const void *v, bool refactor) override {
    const auto &a = *static_cast<const View<I> *>(v);
    rcond_ = 0.0;
    if (refactor && numeric_) {
      // Reuse the pivot order of the last factorisation; when the new values make
      // those pivots fail or degrade (pivot ratio below eps^(2/3)), pivot afresh.
      if (Api::refactor(a.p, a.i, a.x, symbolic_, numeric_, &common_)) {
        Api::rcond(symbolic_, numeric_, &common_);
        if (common_.status == KLU_OK && common_.rcond >= std::pow(DBL_EPSILON, 2.0 / 3.0)) {
          rcond_ = common_.rcond;
          return {};
        }
      } else if (common_.status < KLU_OK && common_.status != KLU_SINGULAR) {
        Outcome o = status_error("klu_refactor");
        Api::free_numeric(&numeric_, &common_);
        return o;
      }
    }
    if (numeric_) Api::free_numeric(&numeric_, &common_);
    numeric_ = Api::factor(a.p, a.i, a.x, symbolic_, &common_);
    if (!numeric_ || common_.status != KLU_OK) {
      Outcome o = status_error("klu_factor");
      if (numeric_) Api::free_numeric(&numeric_, &common_);
      return o;
    }
    Api::rcond(symbolic_, numeric_, &common_);
    rcond_ = common_.rcond;
    return {};
  }

  Outcome solve(int32_t nrhs, const double *b, int64_t ldb, double *x, int64_t ldx) override {
    for (int32_t j = 0; j < nrhs; ++j)
      if (b + j * ldb != x + j * ldx)
        std::memcpy(x + j * ldx, b + j * ldb, sizeof(double) * static_cast<size_t>(n_));
    // KLU walks the right-hand sides four at a time with I arithmetic on ld: with
    // 32-bit indices a huge ld is passed one column at a time (ld = n) instead.
    const bool whole = sizeof(I) == 8 || ldx <= INT32_MAX / 4;
    if (whole) {
      if (!Api::tsolve(symbolic_, numeric_, static_cast<I>(ldx), static_cast<I>(nrhs), x,
                       &common_))
        return status_error("klu_tsolve");
    } else {
      for (int32_t j = 0; j < nrhs; ++j)
        if (!Api::tsolve(symbolic_, numeric_, n_, 1, x + j * ldx, &common_))
          return status_error("klu_tsolve");
    }
    return {};
  }

  double rcond() const override { return numeric_ ? rcond_ : 0.0; }
  int64_t factor_nnz() const override {
    if (!numeric_) return 0;
    return static_cast<int64_t>(numeric_->lnz) + numeric_->unz + numeric_->nzoff;
  }

 private:
  void release() {
    if (numeric_) Api::free_numeric(&numeric_, &common_);
    if (symbolic_) Api::free_symbolic(&symbolic_, &common_);
  }

  Outcome status_error(const char *call) const {
    const std::string where = std::string(" (") + call + ")";
    switch (common_.status) {
      case KLU_SINGULAR: {
        std::string msg = "KLU: the matrix is singular";
        // KLU factors A^T: its column singular_col is row singular_col of A.
        if (common_.singular_col >= 0 && common_.singular_col < n_)
          msg += ": zero pivot at row " + std::to_string(common_.singular_col);
        if (common_.structural_rank >= 0 && common_.structural_rank < n_)
          msg += ", structural rank " + std::to_string(common_.structural_rank) + " < n = " +
                 std::to_string(n_);
        return fail(MFREE_FAIL_SINGULAR, msg + " (KLU_SINGULAR)" + where);
      }
      case KLU_OUT_OF_MEMORY:
        return fail(MFREE_ERR_ALLOC, "KLU: out of memory (KLU_OUT_OF_MEMORY)" + where);
      case KLU_TOO_LARGE:
        return fail(MFREE_ERR_UNSUPPORTED,
                    "KLU: integer overflow in the factors (KLU_TOO_LARGE): use 64-bit indices" +
                        where,
                    sizeof(I) == 4);
      case KLU_INVALID:
        return fail(MFREE_ERR_INPUT, "KLU: the matrix was rejected as invalid (KLU_INVALID)" + where);
      default:
        return fail(MFREE_ERR_INTERNAL,
                    "KLU: unexpected status " + std::to_string(common_.status) + where);
    }
  }

  typename Api::Common common_{};
  typename Api::Symbolic *symbolic_ = nullptr;
  typename Api::Numeric *numeric_ = nullptr;
  I n_ = 0;
  double rcond_ = 0.0;
};

// ---- UMFPACK --------------------------------------------------------------------------------

template <class I>
struct UmfApi;

template <>
struct UmfApi<int32_t> {
  static void defaults(double *control) { umfpack_di_defaults(control); }
  static int symbolic(int n, const int *p, const int *i, const double *x, void **s,
                      const double *control, double *info) {
    return umfpack_di_symbolic(n, n, p, i, x, s, control, info);
  }
  static int numeric(const int *p, const int *i, const double *x, void *s, void **f,
                     const double *control, double *info) {
    return umfpack_di_numeric(p, i, x, s, f, control, info);
  }
  static int wsolve(double *x, const double *b, void *f, const double *control, double *info,
                    int *wi, double *w) {
    return umfpack_di_wsolve(UMFPACK_At, nullptr, nullptr, nullptr, x, b, f, control, info,
                             wi, w);
  }
  static void free_symbolic(void **s) { umfpack_di_free_symbolic(s); }
  static void free_numeric(void **f) { umfpack_di_free_numeric(f); }
};

template <>
struct UmfApi<int64_t> {
  static void defaults(double *control) { umfpack_dl_defaults(control); }
  static int64_t symbolic(int64_t n, const int64_t *p, const int64_t *i, const double *x,
                          void **s, const double *control, double *info) {
    return umfpack_dl_symbolic(n, n, p, i, x, s, control, info);
  }
  static int64_t numeric(const int64_t *p, const int64_t *i, const double *x, void *s,
                         void **f, const double *control, double *info) {
    return umfpack_dl_numeric(p, i, x, s, f, control, info);
  }
  static int64_t wsolve(double *x, const double *b, void *f, const double *control,
                        double *info, int64_t *wi, double *w) {
    return umfpack_dl_wsolve(UMFPACK_At, nullptr, nullptr, nullptr, x, b, f, control, info,
                             wi, w);
  }
  static void free_symbolic(void **s) { umfpack_dl_free_symbolic(s); }
  static void free_numeric(void **f) { umfpack_dl_free_numeric(f); }
};

template <class I>
class UmfpackBackend final : public Backend {
  using Api = UmfApi<I>;

 public:
  UmfpackBackend() {
    Api::defaults(control_);
    control_[UMFPACK_PRL] = 0;     // never print
    control_[UMFPACK_IRSTEP] = 0;  // refinement would need A at solve time (not kept)
  }
  ~UmfpackBackend() override { release(); }
  int32_t width() const override { return sizeof(I) == 4 ? 32 : 64; }

  Outcome analyze(const void *v) override {
    const auto &a = *static_cast<const View<I> *>(v);
    release();
    n_ = a.n;
    wi_.assign(static_cast<size_t>(a.n), 0);
    w_.assign(static_cast<size_t>(a.n), 0.0);
    col_.assign(static_cast<size_t>(a.n), 0.0);
    const auto st = Api::symbolic(a.n, a.p, a.i, a.x, &symbolic_, control_, info_);
    if (st != UMFPACK_OK) {
      Outcome o = status_error(static_cast<int>(st), "umfpack_symbolic");
      if (symbolic_) Api::free_symbolic(&symbolic_);
      return o;
    }
    return {};
  }

  Outcome factor(const void *v, bool) override {
    const auto &a = *static_cast<const View<I> *>(v);
    if (numeric_) Api::free_numeric(&numeric_);
    const auto st = Api::numeric(a.p, a.i, a.x, symbolic_, &numeric_, control_, info_);
    // Under- or overflow of the determinant is harmless for solving.
    if (st != UMFPACK_OK && st != UMFPACK_WARNING_determinant_underflow &&
        st != UMFPACK_WARNING_determinant_overflow) {
      if (numeric_) Api::free_numeric(&numeric_);
      return status_error(static_cast<int>(st), "umfpack_numeric");
    }
    rcond_ = info_[UMFPACK_RCOND];
    lunz_ = info_[UMFPACK_LNZ] + info_[UMFPACK_UNZ];
    return {};
  }

  Outcome solve(int32_t nrhs, const double *b, int64_t ldb, double *x, int64_t ldx) override {
    for (int32_t j = 0; j < nrhs; ++j) {
      const double *bj = b + j * ldb;
      double *xj = x + j * ldx;
      if (bj == xj) {  // in place: UMFPACK needs X and B apart
        std::memcpy(col_.data(), bj, sizeof(double) * static_cast<size_t>(n_));
        bj = col_.data();
      }
      const auto st = Api::wsolve(xj, bj, numeric_, control_, info_, wi_.data(), w_.data());
      if (st != UMFPACK_OK) return status_error(static_cast<int>(st), "umfpack_wsolve");
    }
    return {};
  }

  double rcond() const override { return numeric_ ? rcond_ : 0.0; }
  int64_t factor_nnz() const override { return numeric_ ? static_cast<int64_t>(lunz_) : 0; }

 private:
  void release() {
    if (numeric_) Api::free_numeric(&numeric_);
    if (symbolic_) Api::free_symbolic(&symbolic_);
  }

  static Outcome status_error(int st, const char *call) {
    const std::string where = std::string(" (") + call + ")";
    switch (st) {
      case UMFPACK_WARNING_singular_matrix:
        return fail(MFREE_FAIL_SINGULAR,
                    "UMFPACK: the matrix is singular (UMFPACK_WARNING_singular_matrix)" + where);
      case UMFPACK_ERROR_out_of_memory:
        return fail(MFREE_ERR_ALLOC, "UMFPACK: out of memory (UMFPACK_ERROR_out_of_memory)" + where);
      case UMFPACK_ERROR_invalid_matrix:
        return fail(MFREE_ERR_INPUT,
                    "UMFPACK: the matrix was rejected as invalid (UMFPACK_ERROR_invalid_matrix)" +
                        where);
      default:
        return fail(MFREE_ERR_INTERNAL, "UMFPACK: unexpected status " + std::to_string(st) + where);
    }
  }

  double control_[UMFPACK_CONTROL] = {};
  double info_[UMFPACK_INFO] = {};
  void *symbolic_ = nullptr;
  void *numeric_ = nullptr;
  I n_ = 0;
  double rcond_ = 0.0, lunz_ = 0.0;
  std::vector<I> wi_;        // wsolve workspace: n indices
  std::vector<double> w_;    // and n doubles (no iterative refinement)
  std::vector<double> col_;  // copy of b for an in-place solve
};

// ---- CHOLMOD --------------------------------------------------------------------------------

template <class I>
struct CholApi;

template <>
struct CholApi<int32_t> {
  static constexpr int itype = CHOLMOD_INT;
  static void start(cholmod_common *c) { cholmod_start(c); }
  static void finish(cholmod_common *c) { cholmod_finish(c); }
  static cholmod_factor *analyze(cholmod_sparse *a, cholmod_common *c) {
    return cholmod_analyze(a, c);
  }
  static bool factorize(cholmod_sparse *a, cholmod_factor *l, cholmod_common *c) {
    return cholmod_factorize(a, l, c) != 0;
  }
  static bool solve2(cholmod_factor *l, cholmod_dense *b, cholmod_dense **x, cholmod_dense **y,
                     cholmod_dense **e, cholmod_common *c) {
    return cholmod_solve2(CHOLMOD_A, l, b, nullptr, x, nullptr, y, e, c) != 0;
  }
  static double rcond(cholmod_factor *l, cholmod_common *c) { return cholmod_rcond(l, c); }
  static void free_factor(cholmod_factor **l, cholmod_common *c) { cholmod_free_factor(l, c); }
  static void free_dense(cholmod_dense **d, cholmod_common *c) { cholmod_free_dense(d, c); }
};

template <>
struct CholApi<int64_t> {
  static constexpr int itype = CHOLMOD_LONG;
  static void start(cholmod_common *c) { cholmod_l_start(c); }
  static void finish(cholmod_common *c) { cholmod_l_finish(c); }
  static cholmod_factor *analyze(cholmod_sparse *a, cholmod_common *c) {
    return cholmod_l_analyze(a, c);
  }
  static bool factorize(cholmod_sparse *a, cholmod_factor *l, cholmod_common *c) {
    return cholmod_l_factorize(a, l, c) != 0;
  }
  static bool solve2(cholmod_factor *l, cholmod_dense *b, cholmod_dense **x, cholmod_dense **y,
                     cholmod_dense **e, cholmod_common *c) {
    return cholmod_l_solve2(CHOLMOD_A, l, b, nullptr, x, nullptr, y, e, c) != 0;
  }
  static double rcond(cholmod_factor *l, cholmod_common *c) { return cholmod_l_rcond(l, c); }
  static void free_factor(cholmod_factor **l, cholmod_common *c) { cholmod_l_free_factor(l, c); }
  static void free_dense(cholmod_dense **d, cholmod_common *c) { cholmod_l_free_dense(d, c); }
};

template <class I>
class CholmodBackend final : public Backend {
  using Api = CholApi<I>;

 public:
  CholmodBackend() {
    Api::start(&common_);
    common_.print = 0;               // never print, not even warnings
    common_.error_handler = nullptr; // statuses are read from common_.status
    common_.quick_return_if_not_posdef = 1;
    // L L^T also for the simplicial method, whose default L D L^T would factor a
    // symmetric indefinite matrix without complaint: the solver is for SPD matrices
    // and must say when one is not.
    common_.final_ll = 1;
  }
  ~CholmodBackend() override {
    release();
    Api::finish(&common_);
  }
  int32_t width() const override { return sizeof(I) == 4 ? 32 : 64; }

  Outcome analyze(const void *v) override {
    const auto &a = *static_cast<const View<I> *>(v);
    release();
    n_ = a.n;
    cholmod_sparse h = header(a);
    factor_ = Api::analyze(&h, &common_);
    if (!factor_) return status_error("cholmod_analyze");
    lnz_ = common_.lnz;
    return {};
  }

  Outcome factor(const void *v, bool) override {
    const auto &a = *static_cast<const View<I> *>(v);
    numeric_ok_ = false;
    cholmod_sparse h = header(a);
    const bool ok = Api::factorize(&h, factor_, &common_);
    // CHOLMOD_DSMALL (a tiny diagonal entry) is a warning only.
    if (!ok || (common_.status != CHOLMOD_OK && common_.status != CHOLMOD_DSMALL))
      return status_error("cholmod_factorize");
    numeric_ok_ = true;
    rcond_ = Api::rcond(factor_, &common_);
    return {};
  }

  Outcome solve(int32_t nrhs, const double *b, int64_t ldb, double *x, int64_t ldx) override {
    // A header over the host's right-hand sides: CHOLMOD reads them in place.
    cholmod_dense bh{};
    bh.nrow = static_cast<size_t>(n_);
    bh.ncol = static_cast<size_t>(nrhs);
    bh.nzmax = static_cast<size_t>(ldb) * static_cast<size_t>(nrhs);
    bh.d = static_cast<size_t>(ldb);
    bh.x = const_cast<double *>(b);
    bh.z = nullptr;
    bh.xtype = CHOLMOD_REAL;
    bh.dtype = CHOLMOD_DOUBLE;
    if (!Api::solve2(factor_, &bh, &x_, &y_, &e_, &common_)) return status_error("cholmod_solve2");
    const auto *xs = static_cast<const double *>(x_->x);
    for (int32_t j = 0; j < nrhs; ++j)
      std::memcpy(x + j * ldx, xs + static_cast<size_t>(j) * x_->d,
                  sizeof(double) * static_cast<size_t>(n_));
    return {};
  }

  double rcond() const override { return numeric_ok_ ? rcond_ : 0.0; }
  int64_t factor_nnz() const override { return factor_ ? static_cast<int64_t>(lnz_) : 0; }

 private:
  // A symmetric matrix: its CSR arrays are its CSC arrays. stype = 1 reads the upper
  // triangle (in CSC terms) and ignores the other one.
  static cholmod_sparse header(const View<I> &a) {
    cholmod_sparse h{};
    h.nrow = h.ncol = static_cast<size_t>(a.n);
    h.nzmax = static_cast<size_t>(a.nnz);
    h.p = a.p;
    h.i = a.i;
    h.nz = nullptr;
    h.x = a.x;
    h.z = nullptr;
    h.stype = 1;
    h.itype = Api::itype;
    h.xtype = CHOLMOD_REAL;
    h.dtype = CHOLMOD_DOUBLE;
    h.sorted = 1;
    h.packed = 1;
    return h;
  }

  void release() {
    numeric_ok_ = false;
    if (factor_) Api::free_factor(&factor_, &common_);
    if (x_) Api::free_dense(&x_, &common_);
    if (y_) Api::free_dense(&y_, &common_);
    if (e_) Api::free_dense(&e_, &common_);
  }

  Outcome status_error(const char *call) const {
    const std::string where = std::string(" (") + call + ")";
    switch (common_.status) {
      case CHOLMOD_NOT_POSDEF: {
        std::string msg = "CHOLMOD: the matrix is not positive definite";
        if (factor_ && factor_->minor < static_cast<size_t>(n_))
          msg += ": the factorisation broke down at pivot " + std::to_string(factor_->minor) +
                 " of the reordered matrix";
        return fail(MFREE_FAIL_SINGULAR, msg + " (CHOLMOD_NOT_POSDEF)" + where);
      }
      case CHOLMOD_OUT_OF_MEMORY:
        return fail(MFREE_ERR_ALLOC, "CHOLMOD: out of memory (CHOLMOD_OUT_OF_MEMORY)" + where);
      case CHOLMOD_TOO_LARGE:
        return fail(MFREE_ERR_UNSUPPORTED,
                    "CHOLMOD: integer overflow (CHOLMOD_TOO_LARGE): use 64-bit indices" + where,
                    sizeof(I) == 4);
      case CHOLMOD_INVALID:
        return fail(MFREE_ERR_INPUT, "CHOLMOD: the matrix was rejected as invalid (CHOLMOD_INVALID)" +
                                         where);
      default:
        return fail(MFREE_ERR_INTERNAL,
                    "CHOLMOD: unexpected status " + std::to_string(common_.status) + where);
    }
  }

  cholmod_common common_{};
  cholmod_factor *factor_ = nullptr;  // symbolic analysis, then the numeric factor
  cholmod_dense *x_ = nullptr, *y_ = nullptr, *e_ = nullptr;  // solve2 workspace
  I n_ = 0;
  bool numeric_ok_ = false;
  double rcond_ = 0.0, lnz_ = 0.0;
};

std::unique_ptr<Backend> make_backend(mfree_solver_kind_t kind, int32_t bits) {
  const bool wide = bits == 64;
  switch (kind) {
    case MFREE_SOLVER_CHOLMOD:
      if (wide) return std::unique_ptr<Backend>(new CholmodBackend<int64_t>());
      return std::unique_ptr<Backend>(new CholmodBackend<int32_t>());
    case MFREE_SOLVER_UMFPACK:
      if (wide) return std::unique_ptr<Backend>(new UmfpackBackend<int64_t>());
      return std::unique_ptr<Backend>(new UmfpackBackend<int32_t>());
    case MFREE_SOLVER_KLU:
      if (wide) return std::unique_ptr<Backend>(new KluBackend<int64_t>());
      return std::unique_ptr<Backend>(new KluBackend<int32_t>());
  }
  return nullptr;
}

// ---- pattern fingerprint ----------------------------------------------------------------------

uint64_t mix64(uint64_t z) {
  z += 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

struct Fingerprint {
  int32_t n = -1;
  int64_t nnz = -1;
  uint64_t h1 = 0, h2 = 0;
  void add(uint64_t v) {
    h1 = (h1 ^ mix64(v)) * 0x100000001b3ull;
    h2 = ((h2 << 29) | (h2 >> 35)) ^ mix64(v ^ 0xd6e8feb86659fd93ull);
    h2 *= 0x9fb21c651e98df25ull;
  }
  bool operator==(const Fingerprint &o) const {
    return n == o.n && nnz == o.nnz && h1 == o.h1 && h2 == o.h2;
  }
};

// What setup / update learn from the matrix before touching the factors.
struct Inspection {
  int32_t n = 0, ncols = 0;
  int64_t nnz = 0;
  Fingerprint fp;
  bool finite = true;
  int32_t bad_row = -1;
};

}  // namespace

// Default singularity threshold on the reciprocal condition estimate (see
// mfree_suitesparse_set_rcond_threshold), from measurements (tests t474, t807 and the
// examples under an instrumented build): singular matrices whose zero pivot round-off
// turned into a tiny nonzero one give estimates that grow roughly like n eps (MPFEM Haar
// ring n = 40: 1.7e-15; Neumann grid Laplacians n = 2500: 1.3e-13, n = 160000: 6.8e-12),
// while the smallest estimate of a legitimate system was 6.4e-8 (the penalty-constrained
// Table III systems of examples/elastostatics; Lagrange multipliers 1.0e-7, the rest of
// the suite 1e-5 and above). 1e-10 sits 15x above the largest singular residue measured
// and 640x below the smallest legitimate estimate.
constexpr double kDefaultRcondThreshold = 1e-10;

struct mfree_suitesparse {
  mfree_context_t *ctx = nullptr;
  mfree_matrix_t *ctx_ref = nullptr;  // a 0 x 0 matrix: holds a reference on ctx
  mfree_solver_kind_t kind = MFREE_SOLVER_UMFPACK;
  int32_t width_request = 0;
  double rcond_threshold = kDefaultRcondThreshold;
  std::unique_ptr<Backend> backend;
  bool analysed = false;  // a symbolic analysis of pattern `fp` exists
  bool factored = false;  // and a usable numeric factorisation
  Fingerprint fp;
};

namespace {

using mfree_adapter::guarded;
using mfree_adapter::record;

// Size, pattern fingerprint and finiteness, from the matrix's own arrays.
mfree_status_t inspect(const mfree_matrix_t *A, Inspection *out) {
  int32_t nrows = 0, ncols = 0;
  int64_t nnz = 0;
  mfree_status_t st = mfree_matrix_get_size(A, &nrows, &ncols, &nnz);
  if (st != MFREE_SUCCESS) return st;
  const int64_t *rowptr = nullptr;
  const int32_t *cols = nullptr;
  const double *vals = nullptr;
  st = mfree_matrix_get_csr(A, &rowptr, &cols, &vals);
  if (st != MFREE_SUCCESS) return st;
  out->n = nrows;
  out->ncols = ncols;
  out->nnz = nnz;
  out->fp.n = nrows;
  out->fp.nnz = nnz;
  out->fp.add(static_cast<uint64_t>(nrows));
  out->fp.add(static_cast<uint64_t>(ncols));
  for (int32_t r = 0; r <= nrows; ++r) out->fp.add(static_cast<uint64_t>(rowptr[r]));
  for (int64_t k = 0; k < nnz; ++k) out->fp.add(static_cast<uint64_t>(cols[k]));
  for (int32_t r = 0; r < nrows && out->finite; ++r)
    for (int64_t k = rowptr[r]; k < rowptr[r + 1]; ++k)
      if (!std::isfinite(vals[k])) {
        out->finite = false;
        out->bad_row = r;
        break;
      }
  return MFREE_SUCCESS;
}

template <class I>
mfree_status_t make_view(const mfree_matrix_t *A, const Inspection &in, View<I> *v);

template <>
mfree_status_t make_view<int32_t>(const mfree_matrix_t *A, const Inspection &in,
                                  View<int32_t> *v) {
  const int32_t *p = nullptr, *i = nullptr;
  const double *x = nullptr;
  const mfree_status_t st = mfree_matrix_get_csr_i32(A, &p, &i, &x);
  if (st != MFREE_SUCCESS) return st;
  v->n = in.n;
  v->nnz = in.nnz;
  v->p = const_cast<int32_t *>(p);
  v->i = const_cast<int32_t *>(i);
  v->x = const_cast<double *>(x);
  return MFREE_SUCCESS;
}

template <>
mfree_status_t make_view<int64_t>(const mfree_matrix_t *A, const Inspection &in,
                                  View<int64_t> *v) {
  const int64_t *p = nullptr, *i = nullptr;
  const double *x = nullptr;
  const mfree_status_t st = mfree_matrix_get_csr_i64(A, &p, &i, &x);
  if (st != MFREE_SUCCESS) return st;
  v->n = in.n;
  v->nnz = in.nnz;
  v->p = const_cast<int64_t *>(p);
  v->i = const_cast<int64_t *>(i);
  v->x = const_cast<double *>(x);
  return MFREE_SUCCESS;
}

// An empty matrix may give NULL index or value arrays, which SuiteSparse rejects as
// missing arguments; it reads nothing from them when nnz = 0.
template <class I>
void nonnull(View<I> *v) {
  static I dummy_index = 0;
  static double dummy_value = 0.0;
  if (!v->i) v->i = &dummy_index;
  if (!v->x) v->x = &dummy_value;
}

// Analyse (when analyse is set) and factorise A with the backend's width.
template <class I>
Outcome run(Backend &be, const mfree_matrix_t *A, const Inspection &in, bool analyse,
            bool refactor, bool *analysed) {
  View<I> v;
  const mfree_status_t st = make_view<I>(A, in, &v);
  if (st != MFREE_SUCCESS)
    return fail(st, std::string("cannot get the ") + (sizeof(I) == 4 ? "32" : "64") +
                        "-bit CSR view of the matrix: " + mfree_status_string(st));
  nonnull(&v);
  if (analyse) {
    Outcome o = be.analyze(&v);
    if (!o.ok()) return o;
  }
  *analysed = true;
  return be.factor(&v, refactor);
}

Outcome run_width(Backend &be, const mfree_matrix_t *A, const Inspection &in, bool analyse,
                  bool refactor, bool *analysed) {
  if (be.width() == 32) return run<int32_t>(be, A, in, analyse, refactor, analysed);
  return run<int64_t>(be, A, in, analyse, refactor, analysed);
}

mfree_status_t check_symmetric(mfree_suitesparse_t *s, const mfree_matrix_t *A, const char *fn) {
  if (s->kind != MFREE_SOLVER_CHOLMOD) return MFREE_SUCCESS;
  int32_t sym = 0;
  const mfree_status_t st = mfree_matrix_get_symmetric(A, &sym);
  if (st != MFREE_SUCCESS)
    return record(s->ctx, st, fn, std::string("cannot query the matrix: ") + mfree_status_string(st));
  if (!sym)
    return record(s->ctx, MFREE_ERR_MISMATCH, fn,
                  "CHOLMOD needs a symmetric positive definite matrix and this one is not "
                  "symmetric: use MFREE_SOLVER_UMFPACK or MFREE_SOLVER_KLU");
  return MFREE_SUCCESS;
}

// A factorisation SuiteSparse accepted, judged by the singularity threshold: UMFPACK and
// KLU flag exactly zero pivots only, so a singular matrix whose zero pivot round-off made
// tiny is otherwise factorised and "solved" silently.
Outcome judge_rcond(const mfree_suitesparse_t *s, Outcome o) {
  if (!o.ok() || !(s->rcond_threshold > 0.0) || !s->backend) return o;
  const double rc = s->backend->rcond();
  if (rc >= s->rcond_threshold) return o;
  char buf[160];
  std::snprintf(buf, sizeof buf, "%.3g is below the threshold %.3g", rc, s->rcond_threshold);
  return fail(MFREE_FAIL_SINGULAR,
              std::string(kind_name(s->kind)) +
                  ": the matrix is numerically singular: its reciprocal condition estimate " + buf +
                  " (mfree_suitesparse_set_rcond_threshold; 0 disables the check); the factors are "
                  "not used");
}

mfree_status_t nonfinite(mfree_suitesparse_t *s, const char *fn, const Inspection &in) {
  return record(s->ctx, MFREE_FAIL_NONFINITE, fn,
                std::string(kind_name(s->kind)) + ": the matrix has a non-finite value in row " +
                    std::to_string(in.bad_row) + "; nothing was factorised");
}

}  // namespace

extern "C" {

mfree_status_t mfree_suitesparse_create(mfree_context_t *ctx, mfree_solver_kind_t kind,
                                        mfree_suitesparse_t **s) {
  if (!ctx) return MFREE_ERR_NULL;
  static const char *fn = "mfree_suitesparse_create";
  return guarded(ctx, fn, [&]() {
    if (!s) return record(ctx, MFREE_ERR_NULL, fn, "output pointer is NULL");
    *s = nullptr;
    const int k = static_cast<int>(kind);
    if (k != MFREE_SOLVER_CHOLMOD && k != MFREE_SOLVER_UMFPACK && k != MFREE_SOLVER_KLU)
      return record(ctx, MFREE_ERR_ARG, fn,
                    "unknown solver kind " + std::to_string(k) +
                        " (MFREE_SOLVER_CHOLMOD = 1, _UMFPACK = 2, _KLU = 3)");
    std::unique_ptr<mfree_suitesparse_t> obj(new mfree_suitesparse_t());
    // The ABI has no context retain: an empty matrix on ctx keeps it alive for us.
    const int64_t zero = 0;
    const mfree_status_t st = mfree_matrix_create_csr(ctx, 0, 0, &zero, nullptr, nullptr,
                                                      &obj->ctx_ref);
    if (st != MFREE_SUCCESS) return st;
    obj->ctx = ctx;
    obj->kind = kind;
    *s = obj.release();
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_suitesparse_destroy(mfree_suitesparse_t **s) {
  if (!s || !*s) return MFREE_SUCCESS;
  mfree_suitesparse_t *obj = *s;
  *s = nullptr;
  mfree_matrix_t *ref = obj->ctx_ref;
  delete obj;  // the factors first, then the context may go
  mfree_matrix_destroy(&ref);
  return MFREE_SUCCESS;
}

mfree_status_t mfree_suitesparse_set_index_width(mfree_suitesparse_t *s, int32_t bits) {
  if (!s) return MFREE_ERR_NULL;
  static const char *fn = "mfree_suitesparse_set_index_width";
  return guarded(s->ctx, fn, [&]() {
    if (bits != 0 && bits != 32 && bits != 64)
      return record(s->ctx, MFREE_ERR_ARG, fn,
                    "index width " + std::to_string(bits) + " is not 0 (automatic), 32 or 64");
    s->width_request = bits;
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_suitesparse_set_rcond_threshold(mfree_suitesparse_t *s, double threshold) {
  if (!s) return MFREE_ERR_NULL;
  static const char *fn = "mfree_suitesparse_set_rcond_threshold";
  return guarded(s->ctx, fn, [&]() {
    if (!(threshold >= 0.0 && threshold < 1.0)) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "%g", threshold);
      return record(s->ctx, MFREE_ERR_ARG, fn,
                    std::string("rcond threshold ") + buf +
                        " is not in [0, 1) (0 disables the singularity check)");
    }
    s->rcond_threshold = threshold;
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_suitesparse_setup(mfree_suitesparse_t *s, const mfree_matrix_t *A) {
  if (!s) return MFREE_ERR_NULL;
  static const char *fn = "mfree_suitesparse_setup";
  return guarded(s->ctx, fn, [&]() {
    if (!A) return record(s->ctx, MFREE_ERR_NULL, fn, "matrix is NULL");
    Inspection in;
    mfree_status_t st = inspect(A, &in);
    if (st != MFREE_SUCCESS)
      return record(s->ctx, st, fn, std::string("cannot read the matrix: ") + mfree_status_string(st));
    if (in.ncols != in.n)
      return record(s->ctx, MFREE_ERR_MISMATCH, fn,
                    std::string(kind_name(s->kind)) + " needs a square matrix, this one is " +
                        std::to_string(in.n) + " x " + std::to_string(in.ncols));
    st = check_symmetric(s, A, fn);
    if (st != MFREE_SUCCESS) return st;
    int32_t bits = 0;
    st = mfree_ss_select_index_width(s->width_request, in.nnz, &bits);
    if (st != MFREE_SUCCESS)
      return record(s->ctx, st, fn,
                    "32-bit indices were forced but nnz = " + std::to_string(in.nnz) +
                        " exceeds INT32_MAX: use mfree_suitesparse_set_index_width(s, 0 or 64)");

    // From here on the previous factorisation is replaced.
    s->analysed = s->factored = false;
    if (!in.finite) {
      s->backend.reset();
      return nonfinite(s, fn, in);
    }
    if (in.n == 0) {  // nothing to factorise; solve is a no-op
      s->backend.reset();
      s->fp = in.fp;
      s->analysed = s->factored = true;
      return MFREE_SUCCESS;
    }
    for (;;) {
      if (!s->backend || s->backend->width() != bits) {
        s->backend.reset();
        s->backend = make_backend(s->kind, bits);
      }
      bool analysed = false;
      Outcome o = run_width(*s->backend, A, in, true, false, &analysed);
      if (o.overflow && s->width_request == 0 && bits == 32) {
        bits = 64;  // the factors outgrow int: the automatic choice moves to 64 bits
        continue;
      }
      s->analysed = analysed;
      if (analysed) s->fp = in.fp;
      o = judge_rcond(s, std::move(o));
      s->factored = o.ok();
      if (!o.ok()) return record(s->ctx, o.status, fn, o.message);
      return MFREE_SUCCESS;
    }
  });
}

mfree_status_t mfree_suitesparse_update(mfree_suitesparse_t *s, const mfree_matrix_t *A) {
  if (!s) return MFREE_ERR_NULL;
  static const char *fn = "mfree_suitesparse_update";
  return guarded(s->ctx, fn, [&]() {
    if (!A) return record(s->ctx, MFREE_ERR_NULL, fn, "matrix is NULL");
    if (!s->analysed)
      return record(s->ctx, MFREE_ERR_STATE, fn,
                    std::string(kind_name(s->kind)) +
                        ": no symbolic analysis to reuse: call mfree_suitesparse_setup first");
    Inspection in;
    mfree_status_t st = inspect(A, &in);
    if (st != MFREE_SUCCESS)
      return record(s->ctx, st, fn, std::string("cannot read the matrix: ") + mfree_status_string(st));
    if (!(in.fp == s->fp))
      return record(s->ctx, MFREE_ERR_STATE, fn,
                    std::string(kind_name(s->kind)) +
                        ": the matrix pattern differs from the one analysed by the last setup "
                        "(n = " + std::to_string(in.n) + ", nnz = " + std::to_string(in.nnz) +
                        " vs n = " + std::to_string(s->fp.n) + ", nnz = " +
                        std::to_string(s->fp.nnz) + "): call mfree_suitesparse_setup");
    st = check_symmetric(s, A, fn);
    if (st != MFREE_SUCCESS) return st;
    s->factored = false;
    if (!in.finite) return nonfinite(s, fn, in);
    if (in.n == 0) {
      s->factored = true;
      return MFREE_SUCCESS;
    }
    bool analysed = false;
    Outcome o = judge_rcond(s, run_width(*s->backend, A, in, false, true, &analysed));
    s->factored = o.ok();
    if (!o.ok()) return record(s->ctx, o.status, fn, o.message);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_suitesparse_solve(mfree_suitesparse_t *s, int32_t nrhs, const double *b,
                                       int64_t ldb, double *x, int64_t ldx) {
  if (!s) return MFREE_ERR_NULL;
  static const char *fn = "mfree_suitesparse_solve";
  return guarded(s->ctx, fn, [&]() {
    if (nrhs < 0)
      return record(s->ctx, MFREE_ERR_ARG, fn, "nrhs = " + std::to_string(nrhs) + " is negative");
    if (nrhs > 0 && (!b || !x))
      return record(s->ctx, MFREE_ERR_NULL, fn, b ? "x is NULL" : "b is NULL");
    if (!s->factored)
      return record(s->ctx, MFREE_ERR_STATE, fn,
                    std::string(kind_name(s->kind)) +
                        (s->analysed ? ": the last factorisation failed: call "
                                       "mfree_suitesparse_update or _setup with a nonsingular "
                                       "matrix first"
                                     : ": nothing is factorised: call mfree_suitesparse_setup "
                                       "first"));
    const int64_t n = s->fp.n;
    const int64_t need = n > 1 ? n : 1;
    if (ldb < need || ldx < need)
      return record(s->ctx, MFREE_ERR_ARG, fn,
                    "leading dimensions ldb = " + std::to_string(ldb) + ", ldx = " +
                        std::to_string(ldx) + " must be >= max(1, n) = " + std::to_string(need));
    // the last right-hand side starts at (nrhs - 1) * ld: beyond a 64-bit byte offset
    // the index would wrap and read or write elsewhere
    const int64_t lim = INT64_MAX / static_cast<int64_t>(sizeof(double));
    if (nrhs > 1 && (ldb > (lim - n) / (nrhs - 1) || ldx > (lim - n) / (nrhs - 1)))
      return record(s->ctx, MFREE_ERR_ARG, fn,
                    "leading dimensions ldb = " + std::to_string(ldb) + ", ldx = " + std::to_string(ldx) +
                        " are too large for " + std::to_string(nrhs) +
                        " right-hand sides: the last one's offset overflows a 64-bit index");
    if (nrhs > 0 && b == x && ldb != ldx)
      return record(s->ctx, MFREE_ERR_ARG, fn, "an in-place solve (b == x) needs ldb == ldx");
    if (nrhs == 0 || n == 0) return MFREE_SUCCESS;
    Outcome o = s->backend->solve(nrhs, b, ldb, x, ldx);
    if (!o.ok()) return record(s->ctx, o.status, fn, o.message);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_suitesparse_get_info(const mfree_suitesparse_t *s, double *rcond,
                                          int64_t *factor_nnz, int32_t *index_width) {
  if (!s) return MFREE_ERR_NULL;
  static const char *fn = "mfree_suitesparse_get_info";
  return guarded(s->ctx, fn, [&]() {
    if (!s->analysed)
      return record(s->ctx, MFREE_ERR_STATE, fn,
                    std::string(kind_name(s->kind)) +
                        ": nothing is analysed: call mfree_suitesparse_setup first");
    const Backend *be = s->backend.get();
    if (rcond) *rcond = be ? be->rcond() : (s->factored ? 1.0 : 0.0);
    if (factor_nnz) *factor_nnz = be ? be->factor_nnz() : 0;
    if (index_width) {
      int32_t bits = 32;
      if (be) bits = be->width();
      else mfree_ss_select_index_width(s->width_request, 0, &bits);
      *index_width = bits;
    }
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_suitesparse_get_context(const mfree_suitesparse_t *s, mfree_context_t **ctx) {
  if (!s || !ctx) return MFREE_ERR_NULL;
  *ctx = s->ctx;
  return MFREE_SUCCESS;
}

}  // extern "C"
