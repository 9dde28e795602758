#include <algorithm>

#include "handles.hpp"

namespace {

void release_approximant(mfree_approximant_t *a) {
  if (a && a->refs.fetch_sub(1, std::memory_order_acq_rel) == 1) {
    mfree_particles_t *p = a->ps;
    mfree_context_t *c = a->ctx;
    delete a;
    mfree::release(p);
    mfree::release(c);
  }
}


void check_layout(int layout, int64_t ld, int64_t need_aos, int64_t need_soa, const char *what) {
  if (layout != MFREE_LAYOUT_AOS && layout != MFREE_LAYOUT_SOA)
    throw mfree::Error(MFREE_ERR_ARG, std::string("unknown layout of ") + what);
  const int64_t need = layout == MFREE_LAYOUT_AOS ? need_aos : need_soa;
  if (ld < need)
    throw mfree::Error(MFREE_ERR_ARG, std::string("leading dimension of ") + what + " is " +
                                          std::to_string(ld) + ", below " + std::to_string(need));
}

template <class T>
void copy_site_vector(const mfree::Approximant &ap, const mfree::HVec<T> &v, T *dst) {
  if (!ap.is_setup()) throw mfree::Error(MFREE_ERR_STATE, "the approximant is not set up");
  if (!dst && !v.empty()) throw mfree::Error(MFREE_ERR_NULL, "output pointer is NULL");
  std::copy(v.begin(), v.end(), dst);
}

mfree_status_t apply_impl(const mfree_approximant_t *a, const char *fn, mfree_op_t op,
                          int32_t ncomp, const double *u, mfree_layout_t ulayout, int64_t uld,
                          double *out, mfree_layout_t olayout, int64_t old, bool add) {
  return mfree::with_handle(a, fn, [&](const mfree::Approximant &ap) {
    MFREE_REQUIRE(ap.is_setup(), MFREE_ERR_STATE, "the approximant is not set up (call setup)");
    MFREE_REQUIRE(ncomp >= 1, MFREE_ERR_ARG, "ncomp = " + std::to_string(ncomp) + " must be >= 1");
    const int ocomp = ap.op_components(op, ncomp);
    const int need = (op == MFREE_OP_VALUE) ? MFREE_DERIV_VALUE
                     : (op == MFREE_OP_GRADIENT || op == MFREE_OP_DIVERGENCE) ? MFREE_DERIV_GRADIENT
                                                                              : MFREE_DERIV_HESSIAN;
    MFREE_REQUIRE(ap.flags() & need, MFREE_ERR_STATE,
                  std::string("the ") +
                      (need == MFREE_DERIV_VALUE ? "value"
                       : need == MFREE_DERIV_GRADIENT ? "gradient"
                                                      : "Hessian") +
                      " table was not built (mfree_approximant_set_derivatives before setup)");
    int32_t n = 0;
    n = a->ps->set.size();
    MFREE_REQUIRE(u || n == 0, MFREE_ERR_NULL, "field pointer u is NULL");
    MFREE_REQUIRE(out || ap.num_sites() == 0, MFREE_ERR_NULL, "output pointer is NULL");
    check_layout(ulayout, uld, ncomp, n, "u");
    check_layout(olayout, old, ocomp, ap.num_sites(), "out");
    mfree::check_extent(n, ncomp, ulayout, uld, "u");
    mfree::check_extent(ap.num_sites(), ocomp, olayout, old, "out");
    ap.apply(op, ncomp, u, ulayout, uld, out, olayout, old, add);
    return MFREE_SUCCESS;
  });
}

}  // namespace

extern "C" {

mfree_status_t mfree_approximant_create(mfree_context_t *ctx, mfree_particles_t *ps,
                                        mfree_method_t method, mfree_approximant_t **a) {
  if (!ctx) return MFREE_ERR_NULL;
  return mfree::guard(ctx, "mfree_approximant_create", [&]() {
    MFREE_REQUIRE(a, MFREE_ERR_NULL, "output pointer is NULL");
    *a = nullptr;
    MFREE_REQUIRE(ps, MFREE_ERR_NULL, "particle set is NULL");
    auto *p = new mfree_approximant_t(ctx, ps, method);
    mfree::retain(ctx);
    mfree::retain(ps);
    *a = p;
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_approximant_destroy(mfree_approximant_t **a) {
  if (!a || !*a) return MFREE_SUCCESS;
  release_approximant(*a);
  *a = nullptr;
  return MFREE_SUCCESS;
}

mfree_status_t mfree_approximant_set_kernel(mfree_approximant_t *a, mfree_kernel_t kernel,
                                            double param) {
  return mfree::with_handle(a, "mfree_approximant_set_kernel", [&](mfree::Approximant &ap) {
    ap.set_kernel(kernel, param);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_approximant_set_order(mfree_approximant_t *a, int32_t order) {
  return mfree::with_handle(a, "mfree_approximant_set_order", [&](mfree::Approximant &ap) {
    ap.set_order(order);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_approximant_set_derivatives(mfree_approximant_t *a, int32_t flags) {
  return mfree::with_handle(a, "mfree_approximant_set_derivatives", [&](mfree::Approximant &ap) {
    ap.set_derivatives(flags);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_approximant_set_fallback(mfree_approximant_t *a, mfree_fallback_t policy) {
  return mfree::with_handle(a, "mfree_approximant_set_fallback", [&](mfree::Approximant &ap) {
    ap.set_fallback(policy);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_approximant_set_points(mfree_approximant_t *a, int32_t npts,
                                            const double *x, mfree_layout_t layout, int64_t ld,
                                            const double *h, int64_t h_stride, mfree_mem_t mem) {
  return mfree::with_handle(a, "mfree_approximant_set_points", [&](mfree::Approximant &ap) {
    ap.set_points(npts, x, layout, ld, h, h_stride, mem);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_approximant_setup(mfree_approximant_t *a) { return mfree::setup_on_set(a, "mfree_approximant_setup"); }

mfree_status_t mfree_approximant_update(mfree_approximant_t *a) {
  return mfree::with_handle(a, "mfree_approximant_update", [&](mfree::Approximant &ap) {
    return mfree::finish(a->ctx, "mfree_approximant_update", ap.update());
  });
}

mfree_status_t mfree_approximant_apply(const mfree_approximant_t *a, mfree_op_t op, int32_t ncomp,
                                       const double *u, mfree_layout_t ulayout, int64_t uld,
                                       double *out, mfree_layout_t olayout, int64_t old) {
  return apply_impl(a, "mfree_approximant_apply", op, ncomp, u, ulayout, uld, out, olayout, old,
                    false);
}

mfree_status_t mfree_approximant_apply_add(const mfree_approximant_t *a, mfree_op_t op,
                                           int32_t ncomp, const double *u, mfree_layout_t ulayout,
                                           int64_t uld, double *out, mfree_layout_t olayout,
                                           int64_t old) {
  return apply_impl(a, "mfree_approximant_apply_add", op, ncomp, u, ulayout, uld, out, olayout,
                    old, true);
}

mfree_status_t mfree_approximant_get_num_sites(const mfree_approximant_t *a, int32_t *nsites) {
  return mfree::with_handle(a, "mfree_approximant_get_num_sites", [&](const mfree::Approximant &ap) {
    MFREE_REQUIRE(nsites, MFREE_ERR_NULL, "output pointer is NULL");
    MFREE_REQUIRE(ap.is_setup(), MFREE_ERR_STATE, "the approximant is not set up");
    *nsites = ap.num_sites();
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_approximant_get_nnz(const mfree_approximant_t *a, int64_t *nnz) {
  return mfree::with_handle(a, "mfree_approximant_get_nnz", [&](const mfree::Approximant &ap) {
    MFREE_REQUIRE(nnz, MFREE_ERR_NULL, "output pointer is NULL");
    MFREE_REQUIRE(ap.is_setup(), MFREE_ERR_STATE, "the approximant is not set up");
    *nnz = ap.nnz();
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_approximant_assemble_csr(const mfree_approximant_t *a, mfree_deriv_t deriv,
                                              int32_t component, int64_t *rowptr, int32_t *cols,
                                              double *vals) {
  return mfree::with_handle(a, "mfree_approximant_assemble_csr", [&](const mfree::Approximant &ap) {
    MFREE_REQUIRE(ap.is_setup(), MFREE_ERR_STATE, "the approximant is not set up");
    MFREE_REQUIRE(rowptr || cols || vals, MFREE_ERR_NULL, "all outputs are NULL");
    ap.export_csr(deriv, component, rowptr, cols, vals);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_approximant_check_reproduction(const mfree_approximant_t *a, int32_t order,
                                                    double *fn_err, double *deriv_err) {
  return mfree::with_handle(a, "mfree_approximant_check_reproduction", [&](const mfree::Approximant &ap) {
    MFREE_REQUIRE(fn_err && deriv_err, MFREE_ERR_NULL, "output pointer is NULL");
    MFREE_REQUIRE(ap.is_setup(), MFREE_ERR_STATE, "the approximant is not set up");
    ap.check_reproduction(order, *fn_err, *deriv_err);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_approximant_get_site_status(const mfree_approximant_t *a, int32_t *status,
                                                 int32_t *nfailed) {
  return mfree::with_handle(a, "mfree_approximant_get_site_status", [&](const mfree::Approximant &ap) {
    MFREE_REQUIRE(status || nfailed, MFREE_ERR_NULL, "both outputs are NULL");
    MFREE_REQUIRE(ap.is_setup(), MFREE_ERR_STATE, "the approximant is not set up");
    const auto &st = ap.site_status();
    if (status) std::copy(st.begin(), st.end(), status);
    if (nfailed)
      *nfailed = static_cast<int32_t>(std::count_if(st.begin(), st.end(), [](int32_t v) { return v != 0; }));
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_approximant_get_neighbor_counts(const mfree_approximant_t *a, int32_t *counts) {
  return mfree::with_handle(a, "mfree_approximant_get_neighbor_counts", [&](const mfree::Approximant &ap) {
    copy_site_vector(ap, ap.site_support(), counts);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_approximant_get_condition(const mfree_approximant_t *a, double *cond) {
  return mfree::with_handle(a, "mfree_approximant_get_condition", [&](const mfree::Approximant &ap) {
    copy_site_vector(ap, ap.site_cond(), cond);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_approximant_get_site_order(const mfree_approximant_t *a, int32_t *order) {
  return mfree::with_handle(a, "mfree_approximant_get_site_order", [&](const mfree::Approximant &ap) {
    copy_site_vector(ap, ap.site_order(), order);
    return MFREE_SUCCESS;
  });
}

}  // extern "C"
