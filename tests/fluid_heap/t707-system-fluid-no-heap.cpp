// After the first step, a Galerkin-SPH fluid step (mfree_system_integrate, leap-frog and
// predictor-corrector, walls, 1 and 2 threads) makes no heap allocation while its
// neighbour lists are reused: neither through the context's allocator hook nor
// through the C++ standard library (global operator new replaced and counted). A column
// of fluid at rest under gravity moves far less than the lists' skin in the steps below,
// so no list is rebuilt (a rebuild re-runs the search, whose buffers grow only with the
// set). No cmocka: a plain C++ program that exits non-zero on failure.
#include <mfree.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <vector>

#include "../util/counting_new.hpp"

namespace {

int stop_after_one(void *, int64_t step, double, double) { return step >= 1; }

// A 16 x 32 column (the dam break's, as in bench_dambreak) with walls on three sides.
void run(int threads, mfree_integrator_t scheme) {
  const int nx = 16, nz = 2 * nx, n = nx * nz;
  const double a = 0.05715, rho0 = 1000.0, gam = 7.0, grav = 9.81, H = 2.0 * a, L = 5.0 * a;
  const double d = a / nx, h = 1.5 * d, kappa = 100.0 * rho0 * 2.0 * grav * H / gam;
  std::vector<double> y(5 * static_cast<size_t>(n), 0.0), m(n);
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nx; ++i) {
      const int q = j * nx + i;
      const double z = (j + 0.5) * d;
      y[2 * q] = (i + 0.5) * d;
      y[2 * q + 1] = z;
      y[4 * static_cast<size_t>(n) + q] = rho0 * std::pow(1.0 + rho0 * grav * (H - z) / kappa, 1.0 / gam);
      m[q] = y[4 * static_cast<size_t>(n) + q] * d * d;
    }
  const double off = 0.5 * d, ws = d / 3.0, top = 1.5 * H;
  const int nb = static_cast<int>(std::ceil((L + 2 * off) / ws)) + 1, ns = static_cast<int>(std::ceil((top + off) / ws));
  std::vector<double> wx, wn;
  for (int q = 0; q < nb; ++q) {
    wx.insert(wx.end(), {-off + q * (L + 2 * off) / (nb - 1), -off});
    wn.insert(wn.end(), {0.0, 1.0});
  }
  for (int q = 1; q <= ns; ++q)
    for (int side = 0; side < 2; ++side) {
      wx.insert(wx.end(), {side ? L + off : -off, -off + q * (top + off) / ns});
      wn.insert(wn.end(), {side ? -1.0 : 1.0, 0.0});
    }
  mfree_context_t *ctx = nullptr;
  mfree_system_t *sys = nullptr;
  OK(mfree_context_create(&ctx));
  OK(mfree_context_set_num_threads(ctx, threads));
  OK(mfree_context_set_allocator(ctx, hook_alloc, hook_free, nullptr));
  OK(mfree_system_create_fluid(ctx, 2, n, &sys));
  OK(mfree_system_set_fluid(sys, &rho0, 0, kappa, gam, 1e-3));
  OK(mfree_system_set_masses(sys, m.data(), 1));
  OK(mfree_system_set_smoothing(sys, h));
  const double g[2] = {0.0, -grav};
  OK(mfree_system_set_gravity(sys, g));
  OK(mfree_system_set_walls(sys, static_cast<int32_t>(wn.size() / 2), wx.data(), wn.data(), 0.7 * h, 10.0));
  double t = 0.0;
  int64_t done = 0;
  OK(mfree_system_integrate(sys, scheme, y.data(), &t, 1.0, 0.25, 0.0, stop_after_one, nullptr, &done));
  g_new = 0;
  g_hook = 0;
  g_counting = true;
  for (int step = 0; step < 5; ++step)
    OK(mfree_system_integrate(sys, scheme, y.data(), &t, 1.0, 0.25, 0.0, stop_after_one, nullptr, &done));
  g_counting = false;
  CHECK(g_new == 0 && g_hook == 0, "%d thread(s), scheme %d: %ld operator new and %ld hook allocations in 5 steps",
        threads, scheme, g_new.load(), g_hook.load());
  mfree_system_destroy(&sys);
  mfree_context_destroy(&ctx);
}

}  // namespace

int main() {
  for (int threads = 1; threads <= 2; ++threads) {
    run(threads, MFREE_INTEGRATOR_LEAPFROG);
    run(threads, MFREE_INTEGRATOR_PREDICTOR_CORRECTOR);
  }
  if (failures) std::fprintf(stderr, "%d failure(s)\n", failures);
  return failures ? 1 : 0;
}
