#include <algorithm>
#include <cmath>

#include "handles.hpp"

namespace mfree {
void release(mfree_matrix_t *m) {
  if (m && m->refs.fetch_sub(1, std::memory_order_acq_rel) == 1) {
    mfree_context_t *c = m->ctx;
    delete m;
    release(c);
  }
}
}  // namespace mfree

namespace {
}  // namespace

extern "C" {

mfree_status_t mfree_matrix_create_csr(mfree_context_t *ctx, int32_t nrows, int32_t ncols,
                                       const int64_t *rowptr, const int32_t *cols,
                                       const double *vals, mfree_matrix_t **A) {
  if (!ctx) return MFREE_ERR_NULL;
  return mfree::guard(ctx, "mfree_matrix_create_csr", [&]() {
    MFREE_REQUIRE(A, MFREE_ERR_NULL, "output pointer is NULL");
    *A = nullptr;
    MFREE_REQUIRE(nrows >= 0 && ncols >= 0, MFREE_ERR_ARG, "negative matrix size");
    MFREE_REQUIRE(rowptr, MFREE_ERR_NULL, "rowptr is NULL");
    MFREE_REQUIRE(rowptr[0] == 0, MFREE_ERR_INPUT, "rowptr[0] must be 0");
    for (int32_t i = 0; i < nrows; ++i)
      MFREE_REQUIRE(rowptr[i + 1] >= rowptr[i], MFREE_ERR_INPUT,
                    "rowptr is not monotone at row " + std::to_string(i));
    const int64_t nnz = rowptr[nrows];
    MFREE_REQUIRE(nnz == 0 || (cols && vals), MFREE_ERR_NULL, "cols or vals is NULL");
    for (int32_t i = 0; i < nrows; ++i)
      for (int64_t k = rowptr[i]; k < rowptr[i + 1]; ++k) {
        MFREE_REQUIRE(cols[k] >= 0 && cols[k] < ncols, MFREE_ERR_INPUT,
                      "column " + std::to_string(cols[k]) + " in row " + std::to_string(i) + " is out of range");
        MFREE_REQUIRE(k == rowptr[i] || cols[k] > cols[k - 1], MFREE_ERR_INPUT,
                      "row " + std::to_string(i) + " is not sorted by column or has duplicates");
        MFREE_REQUIRE(std::isfinite(vals[k]), MFREE_ERR_INPUT,
                      "value at row " + std::to_string(i) + " is not finite");
      }
    auto *m = new mfree_matrix_t(ctx);
    m->m.set_pattern(nrows, ncols, std::vector<int64_t>(rowptr, rowptr + nrows + 1),
                     std::vector<int32_t>(cols, cols + nnz));
    if (nnz > 0) std::copy(vals, vals + nnz, m->m.values_mut().begin());
    mfree::retain(ctx);
    *A = m;
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_matrix_destroy(mfree_matrix_t **A) {
  if (!A || !*A) return MFREE_SUCCESS;
  mfree::release(*A);
  *A = nullptr;
  return MFREE_SUCCESS;
}

mfree_status_t mfree_matrix_get_size(const mfree_matrix_t *A, int32_t *nrows, int32_t *ncols,
                                     int64_t *nnz) {
  return mfree::with_handle(A, "mfree_matrix_get_size", [&](const mfree::SparseMatrix &m) {
    if (nrows) *nrows = m.rows();
    if (ncols) *ncols = m.cols();
    if (nnz) *nnz = m.nnz();
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_matrix_get_csr(const mfree_matrix_t *A, const int64_t **rowptr,
                                    const int32_t **cols, const double **vals) {
  return mfree::with_handle(A, "mfree_matrix_get_csr", [&](const mfree::SparseMatrix &m) {
    MFREE_REQUIRE(rowptr && cols && vals, MFREE_ERR_NULL, "output pointer is NULL");
    *rowptr = m.rowptr().data();
    *cols = m.colidx().data();
    *vals = m.values().data();
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_matrix_get_csr_i32(const mfree_matrix_t *A, const int32_t **rowptr,
                                        const int32_t **cols, const double **vals) {
  return mfree::with_handle(A, "mfree_matrix_get_csr_i32", [&](const mfree::SparseMatrix &m) {
    MFREE_REQUIRE(rowptr && cols && vals, MFREE_ERR_NULL, "output pointer is NULL");
    *rowptr = m.rowptr32();
    *cols = m.colidx().data();
    *vals = m.values().data();
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_matrix_get_csr_i64(const mfree_matrix_t *A, const int64_t **rowptr,
                                        const int64_t **cols, const double **vals) {
  return mfree::with_handle(A, "mfree_matrix_get_csr_i64", [&](const mfree::SparseMatrix &m) {
    MFREE_REQUIRE(rowptr && cols && vals, MFREE_ERR_NULL, "output pointer is NULL");
    *rowptr = m.rowptr().data();
    *cols = m.colidx64();
    *vals = m.values().data();
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_matrix_get_csc(const mfree_matrix_t *A, const int64_t **colptr,
                                    const int32_t **rows, const double **vals) {
  return mfree::with_handle(A, "mfree_matrix_get_csc", [&](const mfree::SparseMatrix &m) {
    MFREE_REQUIRE(colptr && rows && vals, MFREE_ERR_NULL, "output pointer is NULL");
    m.csc(colptr, rows, vals);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_matrix_get_pattern_id(const mfree_matrix_t *A, int64_t *id) {
  return mfree::with_handle(A, "mfree_matrix_get_pattern_id", [&](const mfree::SparseMatrix &m) {
    MFREE_REQUIRE(id, MFREE_ERR_NULL, "output pointer is NULL");
    *id = m.pattern_id();
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_matrix_get_symmetric(const mfree_matrix_t *A, int32_t *symmetric) {
  return mfree::with_handle(A, "mfree_matrix_get_symmetric", [&](const mfree::SparseMatrix &m) {
    MFREE_REQUIRE(symmetric, MFREE_ERR_NULL, "output pointer is NULL");
    *symmetric = m.symmetric() ? 1 : 0;
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_matrix_apply(const mfree_matrix_t *A, const double *x, double *y) {
  return mfree::with_handle(A, "mfree_matrix_apply", [&](const mfree::SparseMatrix &m) {
    MFREE_REQUIRE((x || m.cols() == 0) && (y || m.rows() == 0), MFREE_ERR_NULL, "x or y is NULL");
    m.apply(x, y);
    return MFREE_SUCCESS;
  });
}

}  // extern "C"
