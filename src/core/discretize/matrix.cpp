#include "core/discretize/matrix.hpp"

#include <cmath>
#include <limits>

namespace mfree {

SparseMatrix::SparseMatrix(int32_t nrows, int32_t ncols, std::vector<int64_t> rowptr,
                           std::vector<int32_t> cols, std::vector<double> vals) {
  set_pattern(nrows, ncols, std::move(rowptr), std::move(cols));
  vals_ = std::move(vals);
}

void SparseMatrix::set_pattern(int32_t nrows, int32_t ncols, std::vector<int64_t> rowptr,
                               std::vector<int32_t> cols) {
  std::lock_guard<std::mutex> lock(cache_mutex_);
  nrows_ = nrows;
  ncols_ = ncols;
  rowptr_ = std::move(rowptr);
  colidx_ = std::move(cols);
  vals_.assign(colidx_.size(), 0.0);
  ++pattern_id_;
  rowptr32_.clear();
  colidx64_.clear();
  csc_valid_ = false;
  cscptr_.clear();
}

int64_t SparseMatrix::find(int32_t i, int32_t j) const {
  int64_t lo = rowptr_[i], hi = rowptr_[i + 1];
  while (lo < hi) {
    const int64_t mid = (lo + hi) / 2;
    if (colidx_[mid] < j) lo = mid + 1;
    else hi = mid;
  }
  return (lo < rowptr_[i + 1] && colidx_[lo] == j) ? lo : -1;
}

const int32_t *SparseMatrix::rowptr32() const {
  if (nnz() > std::numeric_limits<int32_t>::max())
    throw Error(MFREE_ERR_UNSUPPORTED, "nnz = " + std::to_string(nnz()) +
                                           " does not fit 32-bit offsets: use the 64-bit view");
  std::lock_guard<std::mutex> lock(cache_mutex_);
  if (rowptr32_.size() != rowptr_.size())
    rowptr32_.assign(rowptr_.begin(), rowptr_.end());
  return rowptr32_.data();
}

const int64_t *SparseMatrix::colidx64() const {
  std::lock_guard<std::mutex> lock(cache_mutex_);
  if (colidx64_.size() != colidx_.size() || colidx64_.empty())
    colidx64_.assign(colidx_.begin(), colidx_.end());
  if (colidx64_.empty()) colidx64_.push_back(0);  // keep data() non-NULL
  return colidx64_.data();
}

void SparseMatrix::csc(const int64_t **colptr, const int32_t **rows, const double **vals) const {
  std::lock_guard<std::mutex> lock(cache_mutex_);
  if (cscptr_.empty()) {  // pattern part, once per pattern
    cscptr_.assign(static_cast<size_t>(ncols_) + 1, 0);
    for (int32_t c : colidx_) ++cscptr_[c + 1];
    for (int32_t c = 0; c < ncols_; ++c) cscptr_[c + 1] += cscptr_[c];
    cscrow_.resize(colidx_.size());
    csc_perm_.resize(colidx_.size());
    std::vector<int64_t> fill(cscptr_.begin(), cscptr_.end() - 1);
    for (int32_t i = 0; i < nrows_; ++i)
      for (int64_t k = rowptr_[i]; k < rowptr_[i + 1]; ++k) {
        const int64_t p = fill[colidx_[k]]++;
        cscrow_[p] = i;
        csc_perm_[p] = k;
      }
    csc_valid_ = false;
  }
  if (!csc_valid_) {
    cscval_.resize(colidx_.size());
    for (size_t p = 0; p < csc_perm_.size(); ++p) cscval_[p] = vals_[csc_perm_[p]];
    csc_valid_ = true;
  }
  *colptr = cscptr_.data();
  *rows = cscrow_.data();
  *vals = cscval_.data();
}

bool SparseMatrix::symmetric() const {
  if (nrows_ != ncols_) return false;
  double scale = 0.0;
  for (double v : vals_) scale = std::max(scale, std::fabs(v));
  const double tol = 1e-12 * scale;
  for (int32_t i = 0; i < nrows_; ++i)
    for (int64_t k = rowptr_[i]; k < rowptr_[i + 1]; ++k) {
      const int64_t t = find(colidx_[k], i);
      const double other = t < 0 ? 0.0 : vals_[t];
      if (std::fabs(vals_[k] - other) > tol) return false;
    }
  return true;
}

void SparseMatrix::apply(const double *x, double *y) const {
  for (int32_t i = 0; i < nrows_; ++i) {
    double acc = 0.0;
    for (int64_t k = rowptr_[i]; k < rowptr_[i + 1]; ++k) acc += vals_[k] * x[colidx_[k]];
    y[i] = acc;
  }
}

}  // namespace mfree
