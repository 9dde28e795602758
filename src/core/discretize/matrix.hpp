// Sparse CSR matrix with cached index conversions and a CSC transpose.
#pragma once

#include <cstdint>
#include <mutex>
#include <vector>

#include "core/base/error.hpp"

namespace mfree {

class SparseMatrix {
 public:
  SparseMatrix() = default;
  SparseMatrix(int32_t nrows, int32_t ncols, std::vector<int64_t> rowptr, std::vector<int32_t> cols,
               std::vector<double> vals);

  int32_t rows() const { return nrows_; }
  int32_t cols() const { return ncols_; }
  int64_t nnz() const { return static_cast<int64_t>(colidx_.size()); }
  const std::vector<int64_t> &rowptr() const { return rowptr_; }
  const std::vector<int32_t> &colidx() const { return colidx_; }
  const std::vector<double> &values() const { return vals_; }
  std::vector<double> &values_mut() { invalidate_values(); return vals_; }
  int64_t pattern_id() const { return pattern_id_; }

  // Replace the pattern (sorted rows, no duplicates) and zero the values.
  void set_pattern(int32_t nrows, int32_t ncols, std::vector<int64_t> rowptr, std::vector<int32_t> cols);
  // Position of (i, j) in the value array, or -1.
  int64_t find(int32_t i, int32_t j) const;

  const int32_t *rowptr32() const;  // throws MFREE_ERR_UNSUPPORTED if nnz >= 2^31
  const int64_t *colidx64() const;
  void csc(const int64_t **colptr, const int32_t **rows, const double **vals) const;
  bool symmetric() const;
  void apply(const double *x, double *y) const;

 private:
  void invalidate_values() { csc_valid_ = false; }
  int32_t nrows_ = 0, ncols_ = 0;
  std::vector<int64_t> rowptr_{0};
  std::vector<int32_t> colidx_;
  std::vector<double> vals_;
  int64_t pattern_id_ = 0;
  // caches (const views fill them on demand)
  mutable std::mutex cache_mutex_;
  mutable std::vector<int32_t> rowptr32_;
  mutable std::vector<int64_t> colidx64_;
  mutable bool csc_valid_ = false;
  mutable std::vector<int64_t> cscptr_;
  mutable std::vector<int32_t> cscrow_;
  mutable std::vector<double> cscval_;
  mutable std::vector<int64_t> csc_perm_;
};

}  // namespace mfree
