// After the first setup, mfree_particles_update, mfree_approximant_update and
// mfree_approximant_apply make no heap allocation at all: neither through the
// context's allocator hook (counted by the hook below) nor through the C++ standard
// library (counted by replacing the global operator new, which every std::vector and
// std::string in libmfree reaches). One and two threads, 2D and 3D, positions moved
// between steps (borrowed, re-read by update). No cmocka: a plain C++ program that exits
// non-zero on failure.
#include <mfree.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <vector>

#include "../util/counting_new.hpp"

namespace {

void run(int dim, int threads, int method) {
  const int m = dim == 2 ? 24 : 9;
  int n = 1;
  for (int d = 0; d < dim; ++d) n *= m;
  std::vector<double> x(static_cast<size_t>(dim) * n), u(3 * static_cast<size_t>(n)),
      out(9 * static_cast<size_t>(n));
  unsigned s = 12345u + static_cast<unsigned>(dim);
  auto jitter = [&s]() {
    s = s * 1664525u + 1013904223u;
    return 0.3 * ((s >> 8) * (1.0 / 16777216.0) - 0.5);
  };
  for (int p = 0; p < n; ++p) {
    int q = p;
    for (int c = 0; c < dim; ++c) {
      x[static_cast<size_t>(dim) * p + c] = q % m + jitter();
      q /= m;
    }
  }
  for (size_t i = 0; i < u.size(); ++i) u[i] = 0.01 * static_cast<double>(i % 97);
  mfree_context_t *ctx = nullptr;
  OK(mfree_context_create(&ctx));
  OK(mfree_context_set_num_threads(ctx, threads));
  OK(mfree_context_set_allocator(ctx, hook_alloc, hook_free, nullptr));
  const double h = 1.3, vol = 1.0;
  mfree_particles_t *ps = nullptr;
  OK(mfree_particles_create(ctx, dim, n, &ps));
  OK(mfree_particles_set_positions(ps, x.data(), MFREE_LAYOUT_AOS, dim, MFREE_BORROW));
  OK(mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  OK(mfree_particles_set_volumes(ps, &vol, 0, MFREE_COPY));
  OK(mfree_particles_setup(ps));
  mfree_approximant_t *a = nullptr;
  OK(mfree_approximant_create(ctx, ps, static_cast<mfree_method_t>(method), &a));
  OK(mfree_approximant_set_derivatives(a, MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT));
  OK(mfree_approximant_setup(a));
  // one warm-up step outside the count: a thread team may be started by the runtime
  OK(mfree_particles_update(ps));
  OK(mfree_approximant_update(a));
  long pnew = 0, pcalls = 0, anew = 0, acalls = 0, onew = 0, ocalls = 0;
  for (int step = 0; step < 3; ++step) {
    for (auto &v : x) v += 1e-3 * jitter();
    long n0 = g_new, c0 = g_hook;
    g_counting = true;
    const mfree_status_t sp = mfree_particles_update(ps);
    g_counting = false;
    pnew += g_new - n0;
    pcalls += g_hook - c0;
    CHECK(sp == MFREE_SUCCESS, "particles_update: %d", static_cast<int>(sp));
    n0 = g_new;
    c0 = g_hook;
    g_counting = true;
    const mfree_status_t sa = mfree_approximant_update(a);
    g_counting = false;
    anew += g_new - n0;
    acalls += g_hook - c0;
    CHECK(sa == MFREE_SUCCESS, "approximant_update: %d", static_cast<int>(sa));
    n0 = g_new;
    c0 = g_hook;
    g_counting = true;
    mfree_status_t so = mfree_approximant_apply(a, MFREE_OP_GRADIENT, 1, u.data(), MFREE_LAYOUT_AOS, 1,
                                                out.data(), MFREE_LAYOUT_AOS, dim);
    if (so == MFREE_SUCCESS)
      so = mfree_approximant_apply(a, MFREE_OP_GRADIENT, 3, u.data(), MFREE_LAYOUT_AOS, 3, out.data(),
                                   MFREE_LAYOUT_AOS, 3 * dim);
    if (so == MFREE_SUCCESS)
      so = mfree_approximant_apply(a, MFREE_OP_GRADIENT, 3, u.data(), MFREE_LAYOUT_SOA, n, out.data(),
                                   MFREE_LAYOUT_SOA, n);
    if (so == MFREE_SUCCESS)
      so = mfree_approximant_apply_add(a, MFREE_OP_VALUE, 3, u.data(), MFREE_LAYOUT_AOS, 3, out.data(),
                                       MFREE_LAYOUT_AOS, 3);
    if (so == MFREE_SUCCESS)
      so = mfree_approximant_apply(a, MFREE_OP_DIVERGENCE, dim, u.data(), MFREE_LAYOUT_AOS, 3, out.data(),
                                   MFREE_LAYOUT_AOS, 1);
    g_counting = false;
    onew += g_new - n0;
    ocalls += g_hook - c0;
    CHECK(so == MFREE_SUCCESS, "apply: %d", static_cast<int>(so));
  }
  CHECK(pnew == 0 && pcalls == 0,
        "dim %d, %d threads, method %d: mfree_particles_update made %ld operator-new and %ld hook allocations",
        dim, threads, method, pnew, pcalls);
  CHECK(anew == 0 && acalls == 0,
        "dim %d, %d threads, method %d: mfree_approximant_update made %ld operator-new and %ld hook allocations",
        dim, threads, method, anew, acalls);
  CHECK(onew == 0 && ocalls == 0,
        "dim %d, %d threads, method %d: mfree_approximant_apply made %ld operator-new and %ld hook allocations",
        dim, threads, method, onew, ocalls);
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
  mfree_context_destroy(&ctx);
}

}  // namespace

int main() {
  const int methods[] = {MFREE_METHOD_SPH, MFREE_METHOD_MLS, MFREE_METHOD_RANDLES_LIBERSKY,
                         MFREE_METHOD_KB_METHOD1, MFREE_METHOD_SSPH};
  for (int dim = 2; dim <= 3; ++dim)
    for (int threads = 1; threads <= 2; ++threads)
      for (int method : methods) run(dim, threads, method);
  if (failures) std::fprintf(stderr, "%d failures\n", failures);
  else std::printf("ok: no allocation in particle update, approximant update and apply\n");
  return failures ? 1 : 0;
}
