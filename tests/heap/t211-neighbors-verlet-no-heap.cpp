// With a search skin, a particle set set up again after small moves makes no heap
// allocation from its second setup on (the first builds the candidate lists and fills
// the rows from them): neither through the context's allocator hook nor through the
// C++ standard library. The one-block filter swaps the rows' storage with a buffer of
// its own at every setup, so the buffer must be sized at the first filter too: a
// setup that allocates every other time fails here (one thread). One and two threads,
// 2D and 3D, moves far below half the skin (the candidates are reused: the search count
// stays). No cmocka: a plain C++ program that exits non-zero on failure.
#include <mfree.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <vector>

#include "../util/counting_new.hpp"

namespace {

void run(int dim, int threads) {
  const int m = dim == 2 ? 48 : 13;
  int n = 1;
  for (int d = 0; d < dim; ++d) n *= m;
  std::vector<double> x(static_cast<size_t>(dim) * n);
  unsigned s = 211u + static_cast<unsigned>(dim);
  auto jitter = [&s]() {
    s = s * 1664525u + 1013904223u;
    return (s >> 8) * (1.0 / 16777216.0) - 0.5;
  };
  for (int p = 0; p < n; ++p) {
    int q = p;
    for (int c = 0; c < dim; ++c) {
      x[static_cast<size_t>(dim) * p + c] = q % m + 0.3 * jitter();
      q /= m;
    }
  }
  mfree_context_t *ctx = nullptr;
  OK(mfree_context_create(&ctx));
  OK(mfree_context_set_num_threads(ctx, threads));
  OK(mfree_context_set_allocator(ctx, hook_alloc, hook_free, nullptr));
  const double h = 1.3, skin = 0.4;
  mfree_particles_t *ps = nullptr;
  OK(mfree_particles_create(ctx, dim, n, &ps));
  OK(mfree_particles_set_positions(ps, x.data(), MFREE_LAYOUT_AOS, dim, MFREE_BORROW));
  OK(mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  OK(mfree_particles_set_search_skin(ps, skin));
  OK(mfree_particles_setup(ps));
  int64_t nnz0 = 0;
  OK(mfree_particles_get_neighbor_nnz(ps, &nnz0));
  long calls = 0, news = 0;
  for (int step = 0; step < 4; ++step) {
    for (auto &v : x) v += 1e-3 * jitter();  // at most 0.04 in all: far below skin / 2
    const long n0 = g_new, c0 = g_hook;
    g_counting = true;
    OK(mfree_particles_setup(ps));
    g_counting = false;
    news += g_new - n0;
    calls += g_hook - c0;
  }
  int64_t nnz = 0;
  OK(mfree_particles_get_neighbor_nnz(ps, &nnz));
  int64_t searches = 0;
  OK(mfree_particles_get_search_count(ps, &searches));
  CHECK(nnz > 0 && nnz0 > 0, "%dD: no neighbours", dim);
  CHECK(searches == 1, "%dD: %lld searches: the candidates were not reused", dim, static_cast<long long>(searches));
  CHECK(news == 0 && calls == 0, "%dD, %d thread(s): %ld operator new and %ld hook allocations in 4 setups after the first",
        dim, threads, news, calls);
  mfree_particles_destroy(&ps);
  mfree_context_destroy(&ctx);
}

}  // namespace

int main() {
  for (int dim = 2; dim <= 3; ++dim)
    for (int threads = 1; threads <= 2; ++threads) run(dim, threads);
  if (failures) std::fprintf(stderr, "%d failure(s)\n", failures);
  return failures ? 1 : 0;
}
