/*
 * t204: the huge-page path of the internal allocator (src/core/base/alloc.hpp).
 *
 * With huge pages asked for on the context (mfree_context_set_page_hints,
 * MFREE_PAGES_HUGE) and without an allocator hook, blocks of 2 MiB and more (here the neighbour lists of a
 * 10^5-particle set) get mappings of their own, advised MADV_HUGEPAGE, and are unmapped
 * when freed. The particles are stored in random order: a one-thread search of particles
 * in spatial order (AVX2) writes its lists in place on small pages (neighbors.cpp,
 * host_order_rows; alloc.hpp, SmallPages), the general path used here on huge pages.
 * Observed from outside through
 * /proc/self/smaps (the "hg" VmFlag that MADV_HUGEPAGE sets on a mapping):
 *  - a set-up 10^5 set holds advised mappings, and after it is destroyed every advised
 *    byte is gone again (no block is lost or unmapped twice: the advised total returns to
 *    its value before the set);
 *  - its rows equal the O(N) per-row brute-force oracle on 1,000 sampled rows (exact
 *    sets, no pair within 1e-9 of the threshold), and the whole relation is symmetric,
 *    with rows strictly ascending, with one thread and with two;
 *  - with a hook installed the memory is the host's: no advised mapping appears, the
 *    hook's allocations and frees balance to the byte, and the lists are identical to
 *    those of the huge-page run;
 *  - without the request (the default) no advised mapping appears either.
 * Skipped where the path is off (not Linux, THP "never", MFREE_HUGEPAGES=0, small page
 * other than 4 KiB). No timing.
 */
#include "count_alloc.h"
#include "testutil.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#if defined(__linux__)
#include <unistd.h>
#endif

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* The huge-page path is on in this process (same conditions as alloc.hpp). */
static int huge_path_on(void) {
#if defined(__linux__)
  const char *env = getenv("MFREE_HUGEPAGES");
  if (env && env[0] == '0') return 0;
  if (sysconf(_SC_PAGESIZE) != 4096) return 0;
  FILE *f = fopen("/sys/kernel/mm/transparent_hugepage/enabled", "r");
  if (!f) return 0;
  char line[128] = {0};
  const int ok = fgets(line, sizeof line, f) != NULL && strstr(line, "[never]") == NULL;
  fclose(f);
  return ok;
#else
  return 0;
#endif
}

/* Total size in KiB of this process's mappings advised MADV_HUGEPAGE ("hg" in VmFlags);
 * adjacent advised mappings may be merged by the kernel, so sizes, not counts. */
static long advised_kib(void) {
  FILE *f = fopen("/proc/self/smaps", "r");
  assert_non_null(f);
  char line[512];
  long size = 0, total = 0;
  while (fgets(line, sizeof line, f)) {
    long v = 0;
    if (sscanf(line, "Size: %ld kB", &v) == 1) size = v;
    else if (strncmp(line, "VmFlags:", 8) == 0 && strstr(line, " hg")) total += size;
  }
  fclose(f);
  return total;
}


enum { M = 320 }; /* 102,400 particles */

/* Jittered M x M lattice, spacing 1, AoS, its points in random order. */
static double *lattice(int32_t *n) {
  *n = M * M;
  double *x = malloc(sizeof(double) * 2 * (size_t)*n);
  assert_non_null(x);
  mfree_rng_t r;
  mfree_rng_seed(&r, 204);
  for (int32_t p = 0; p < *n; ++p) {
    x[2 * p] = (p % M) + 0.3 * (2.0 * mfree_rng_uniform(&r) - 1.0);
    x[2 * p + 1] = (p / M) + 0.3 * (2.0 * mfree_rng_uniform(&r) - 1.0);
  }
  for (int32_t p = *n - 1; p > 0; --p) { /* Fisher-Yates */
    int32_t q = (int32_t)(mfree_rng_uniform(&r) * (p + 1));
    if (q > p) q = p;
    for (int c = 0; c < 2; ++c) {
      const double t = x[2 * p + c];
      x[2 * p + c] = x[2 * q + c];
      x[2 * q + c] = t;
    }
  }
  return x;
}

typedef struct {
  int64_t *rowptr;
  int32_t *cols;
  int64_t nnz;
} lists_t;

/* Set up a gather search (kappa h = r, ~21 neighbours) and copy its lists out. */
static lists_t search(mfree_context_t *ctx, const double *x, int32_t n, double r, long *advised_during) {
  mfree_particles_t *ps = NULL;
  const double h = 0.5 * r;
  assert_ok(ctx, mfree_particles_create(ctx, 2, n, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 2, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_set_search(ps, MFREE_SEARCH_GATHER, 2.0));
  assert_ok(ctx, mfree_particles_setup(ps));
  *advised_during = advised_kib();
  lists_t g;
  assert_ok(ctx, mfree_particles_get_neighbor_nnz(ps, &g.nnz));
  g.rowptr = malloc(sizeof(int64_t) * ((size_t)n + 1));
  g.cols = malloc(sizeof(int32_t) * (size_t)g.nnz);
  assert_non_null(g.rowptr);
  assert_non_null(g.cols);
  assert_ok(ctx, mfree_particles_get_neighbors(ps, g.rowptr, g.cols));
  mfree_particles_destroy(&ps);
  return g;
}

static int in_row(const lists_t *g, int32_t i, int32_t j) {
  int64_t a = g->rowptr[i], b = g->rowptr[i + 1];
  while (a < b) {
    const int64_t m = a + (b - a) / 2;
    if (g->cols[m] < j) a = m + 1;
    else b = m;
  }
  return a < g->rowptr[i + 1] && g->cols[a] == j;
}

/* Sampled rows against the brute-force oracle; the whole relation symmetric and sorted. */
static void check_lists(const lists_t *g, const double *x, int32_t n, double r) {
  assert_int_equal(g->rowptr[0], 0);
  assert_int_equal(g->rowptr[n], g->nnz);
  for (int32_t i = 0; i < n; ++i) {
    assert_true(g->rowptr[i + 1] > g->rowptr[i]); /* every particle is its own neighbour */
    for (int64_t k = g->rowptr[i]; k < g->rowptr[i + 1]; ++k) {
      const int32_t j = g->cols[k];
      assert_true(j >= 0 && j < n);
      if (k > g->rowptr[i]) assert_true(g->cols[k - 1] < j);
      assert_true(in_row(g, j, i));
    }
  }
  const double r2 = r * r;
  int32_t *want = malloc(sizeof(int32_t) * (size_t)n);
  assert_non_null(want);
  mfree_rng_t rng;
  mfree_rng_seed(&rng, 2040);
  for (int s = 0; s < 1000; ++s) {
    const int32_t i = s == 0 ? 0 : (s == 1 ? n - 1 : (int32_t)(mfree_rng_uniform(&rng) * n));
    int64_t cnt = 0;
    for (int32_t j = 0; j < n; ++j) {
      const double dx = x[2 * i] - x[2 * j], dy = x[2 * i + 1] - x[2 * j + 1];
      const double d2 = dx * dx + dy * dy;
      if (fabs(d2 - r2) <= 1e-9 * r2) fail_msg("pair (%d, %d) within 1e-9 of the threshold", i, j);
      if (d2 < r2) want[cnt++] = j;
    }
    const int64_t got = g->rowptr[i + 1] - g->rowptr[i];
    if (got != cnt || memcmp(want, g->cols + g->rowptr[i], sizeof(int32_t) * (size_t)cnt) != 0)
      fail_msg("row %d: %lld entries, oracle %lld (or different members)", i, (long long)got, (long long)cnt);
  }
  free(want);
}

static void test_huge_pages(void **state) {
  (void)state;
  if (!huge_path_on()) skip();
  int32_t n = 0;
  double *x = lattice(&n);
  const double r = sqrt(21.0 / M_PI);
  const long before = advised_kib();
  lists_t ref = {NULL, NULL, 0};
  for (int threads = 1; threads <= 2; ++threads) {
    mfree_context_t *ctx = NULL;
    assert_ok(NULL, mfree_context_create(&ctx));
    assert_ok(ctx, mfree_context_set_page_hints(ctx, MFREE_PAGES_HUGE)); /* opt-in */
    assert_ok(ctx, mfree_context_set_num_threads(ctx, threads));
    long during = 0;
    lists_t g = search(ctx, x, n, r, &during);
    /* the lists alone are ~8 MiB: at least that much was advised while the set lived */
    if (during - before < 4096) fail_msg("advised mappings during the search: %ld KiB", during - before);
    mfree_context_destroy(&ctx);
    assert_int_equal(advised_kib(), before);  /* every huge block unmapped */
    check_lists(&g, x, n, r);
    if (threads == 1) {
      ref = g;
    } else {
      assert_int_equal(g.nnz, ref.nnz);
      assert_memory_equal(g.rowptr, ref.rowptr, sizeof(int64_t) * ((size_t)n + 1));
      assert_memory_equal(g.cols, ref.cols, sizeof(int32_t) * (size_t)g.nnz);
      free(g.rowptr);
      free(g.cols);
    }
  }
  /* a hook installed: the host's memory, balanced, and the same lists */
  counter_t c = {0, 0, 0, -1};
  mfree_context_t *ctx = NULL;
  assert_ok(NULL, mfree_context_create(&ctx));
  assert_ok(ctx, mfree_context_set_page_hints(ctx, MFREE_PAGES_HUGE)); /* asked, but the hook wins */
  assert_ok(ctx, mfree_context_set_allocator(ctx, count_alloc, count_free, &c));
  long during = 0;
  lists_t g = search(ctx, x, n, r, &during);
  assert_int_equal(during, before);
  mfree_context_destroy(&ctx);
  /* not asked for (the default): malloc's pages, no advised mapping, the same lists */
  assert_ok(NULL, mfree_context_create(&ctx));
  lists_t d = search(ctx, x, n, r, &during);
  assert_int_equal(during, before);
  mfree_context_destroy(&ctx);
  assert_int_equal(d.nnz, ref.nnz);
  assert_memory_equal(d.cols, ref.cols, sizeof(int32_t) * (size_t)d.nnz);
  free(d.rowptr);
  free(d.cols);
  assert_true(c.calls > 0);
  assert_int_equal(c.calls, c.frees);
  assert_int_equal(c.held, 0);
  assert_int_equal(g.nnz, ref.nnz);
  assert_memory_equal(g.rowptr, ref.rowptr, sizeof(int64_t) * ((size_t)n + 1));
  assert_memory_equal(g.cols, ref.cols, sizeof(int32_t) * (size_t)g.nnz);
  free(g.rowptr);
  free(g.cols);
  free(ref.rowptr);
  free(ref.cols);
  free(x);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_huge_pages),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
