#include <cmath>

#include "core/base/kernel.hpp"
#include "handles.hpp"

extern "C" {

mfree_status_t mfree_kernel_eval(mfree_context_t *ctx, mfree_kernel_t kernel, int32_t dim,
                                 double param, double h, int64_t n, const double *r, double *w,
                                 double *dwdr, double *d2wdr2) {
  if (!ctx) return MFREE_ERR_NULL;
  return mfree::guard(ctx, "mfree_kernel_eval", [&]() {
    MFREE_REQUIRE(n >= 0, MFREE_ERR_ARG, "n = " + std::to_string(n) + " is negative");
    MFREE_REQUIRE(std::isfinite(h) && h > 0.0, MFREE_ERR_ARG, "h must be finite and > 0");
    MFREE_REQUIRE(n == 0 || r, MFREE_ERR_NULL, "r is NULL");
    const mfree::Kernel k(kernel, dim, param);
    for (int64_t i = 0; i < n; ++i)
      MFREE_REQUIRE(std::isfinite(r[i]) && r[i] >= 0.0, MFREE_ERR_INPUT,
                    "r[" + std::to_string(i) + "] = " + std::to_string(r[i]) +
                        " must be finite and >= 0");
    for (int64_t i = 0; i < n; ++i) {
      double a, b, c;
      k.eval(r[i], h, a, b, c);
      if (w) w[i] = a;
      if (dwdr) dwdr[i] = b;
      if (d2wdr2) d2wdr2[i] = c;
    }
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_kernel_get_support_radius(mfree_context_t *ctx, mfree_kernel_t kernel,
                                               double param, double *radius) {
  if (!ctx) return MFREE_ERR_NULL;
  return mfree::guard(ctx, "mfree_kernel_get_support_radius", [&]() {
    MFREE_REQUIRE(radius, MFREE_ERR_NULL, "radius is NULL");
    const mfree::Kernel k(kernel, 1, param);
    *radius = k.radius();
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_kernel_get_normalization(mfree_context_t *ctx, mfree_kernel_t kernel,
                                              int32_t dim, double param, double *c) {
  if (!ctx) return MFREE_ERR_NULL;
  return mfree::guard(ctx, "mfree_kernel_get_normalization", [&]() {
    MFREE_REQUIRE(c, MFREE_ERR_NULL, "output pointer is NULL");
    const mfree::Kernel k(kernel, dim, param);
    *c = k.norm();
    return MFREE_SUCCESS;
  });
}

}  // extern "C"
