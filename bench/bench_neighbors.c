/* Neighbour-search benchmark: jittered lattices in 2D and 3D, support giving ~21 (2D)
 * or ~57 (3D) neighbours, cell-list search timed over repeated setups and, for small
 * sizes, against the O(N^2) brute-force search. Prints particles per second.
 * Usage: bench_neighbors [n] (default 100000). Run by hand; never part of the tests. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include <mfree.h>

static double now(void) {
  struct timespec t;
  timespec_get(&t, TIME_UTC);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static double brute(int dim, int n, const double *x, double r, long long *npairs) {
  double t0 = now();
  long long pairs = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      double d2 = 0;
      for (int c = 0; c < dim; ++c) {
        const double d = x[dim * i + c] - x[dim * j + c];
        d2 += d * d;
      }
      pairs += d2 < r * r;
    }
  *npairs = pairs;
  return now() - t0;
}

static void run(int dim, int n_target) {
  const int m = (int)floor(pow((double)n_target, 1.0 / dim) + 0.5);
  int n = 1;
  for (int d = 0; d < dim; ++d) n *= m;
  double *x = malloc(sizeof(double) * (size_t)dim * (size_t)n);
  srand(7);
  for (int p = 0; p < n; ++p) {
    int q = p;
    for (int c = 0; c < dim; ++c) {
      x[dim * p + c] = (q % m) + 0.3 * (2.0 * rand() / RAND_MAX - 1.0);
      q /= m;
    }
  }
  /* radius giving ~21 neighbours in 2D (pi r^2 = 21), ~57 in 3D (4/3 pi r^3 = 57) */
  const double r = dim == 2 ? sqrt(21.0 / 3.14159265358979) : cbrt(57.0 * 3.0 / (4.0 * 3.14159265358979));
  const double h = r / 2.0;
  mfree_context_t *ctx;
  mfree_particles_t *ps;
  mfree_context_create(&ctx);
  mfree_particles_create(ctx, dim, n, &ps);
  mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, dim, MFREE_BORROW);
  mfree_particles_set_support(ps, &h, 0, MFREE_COPY);
  int reps = n < 200000 ? 5 : 2;
  double best = 1e300;
  for (int k = 0; k < reps; ++k) {
    double t0 = now();
    mfree_particles_setup(ps);
    double t = now() - t0;
    if (t < best) best = t;
  }
  int64_t nnz;
  mfree_particles_get_neighbor_nnz(ps, &nnz);
  printf("%dD n=%8d  mean neighbours %6.2f  cell list %8.4f s  %10.3g particles/s", dim, n,
         (double)nnz / n, best, n / best);
  if (n <= 20000) {
    long long pairs = 0;
    double tb = brute(dim, n, x, r, &pairs);
    printf("  brute force %7.3f s (%lld pairs%s)  speed-up %6.1fx", tb, pairs,
           pairs == nnz ? ", same count" : ", COUNT DIFFERS", tb / best);
  }
  printf("\n");
  mfree_particles_destroy(&ps);
  mfree_context_destroy(&ctx);
  free(x);
}

int main(int argc, char **argv) {
  int n = argc > 1 ? atoi(argv[1]) : 100000;
  if (n < 1) n = 100000;
  run(2, 10000);
  run(3, 10000);
  run(2, n);
  run(3, n);
  return 0;
}
