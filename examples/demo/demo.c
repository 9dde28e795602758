/* mfree demo: a jittered 2D particle patch, its neighbours, and the SPH kernel sum
 * sum_j W(|x_i - x_j|, h) V_j (which equals 1 in the interior of a regular lattice and
 * drops towards 1/2 at a free edge, 1/4 at a corner: SPH is not zeroth-order complete
 * there). Usage: mfree_demo [particles-per-side] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include <mfree.h>

#define CHECK(call)                                                                  \
  do {                                                                               \
    mfree_status_t st_ = (call);                                                     \
    if (st_ != MFREE_SUCCESS) {                                                      \
      char msg_[512];                                                                \
      mfree_context_get_last_error(ctx, NULL, msg_, sizeof msg_);                    \
      fprintf(stderr, "%s failed: %s (%s)\n", #call, mfree_status_string(st_), msg_); \
      return 1;                                                                      \
    }                                                                                \
  } while (0)

static double now(void) {
  struct timespec t;
  timespec_get(&t, TIME_UTC);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

int main(int argc, char **argv) {
  const int m = argc > 1 ? atoi(argv[1]) : 200;
  if (m < 2 || m > 5000) {
    fprintf(stderr, "usage: mfree_demo [particles per side, 2..5000]\n");
    return 2;
  }
  const int n = m * m;
  const double dx = 1.0 / m, h = 1.3 * dx;
  double *x = malloc(sizeof(double) * 2 * (size_t)n);
  if (!x) return 1;
  srand(12345);
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < m; ++i) {
      const int p = j * m + i;
      x[2 * p + 0] = (i + 0.5) * dx + 0.1 * dx * (2.0 * rand() / RAND_MAX - 1.0);
      x[2 * p + 1] = (j + 0.5) * dx + 0.1 * dx * (2.0 * rand() / RAND_MAX - 1.0);
    }
  const double vol = dx * dx;

  mfree_context_t *ctx = NULL;
  mfree_particles_t *ps = NULL;
  if (mfree_context_create(&ctx) != MFREE_SUCCESS) return 1;
  printf("mfree %s: %d particles in the unit square, h = 1.3 dx, cubic spline\n",
         mfree_version_string(), n);

  CHECK(mfree_particles_create(ctx, 2, n, &ps));
  CHECK(mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 2, MFREE_BORROW));
  CHECK(mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  CHECK(mfree_particles_set_volumes(ps, &vol, 0, MFREE_COPY));
  double radius = 0.0;
  CHECK(mfree_kernel_get_support_radius(ctx, MFREE_KERNEL_CUBIC_SPLINE, 0.0, &radius));
  CHECK(mfree_particles_set_search(ps, MFREE_SEARCH_GATHER, radius));
  const double t0 = now();
  CHECK(mfree_particles_setup(ps));
  const double t1 = now();

  int64_t nnz = 0;
  CHECK(mfree_particles_get_neighbor_nnz(ps, &nnz));
  int64_t *rowptr = malloc(sizeof(int64_t) * (size_t)(n + 1));
  int32_t *cols = malloc(sizeof(int32_t) * (size_t)(nnz > 0 ? nnz : 1));
  double *r = malloc(sizeof(double) * (size_t)(nnz > 0 ? nnz : 1));
  double *w = malloc(sizeof(double) * (size_t)(nnz > 0 ? nnz : 1));
  if (!rowptr || !cols || !r || !w) return 1;
  CHECK(mfree_particles_get_neighbors(ps, rowptr, cols));

  for (int i = 0; i < n; ++i)
    for (int64_t k = rowptr[i]; k < rowptr[i + 1]; ++k) {
      const double ddx = x[2 * i] - x[2 * cols[k]], ddy = x[2 * i + 1] - x[2 * cols[k] + 1];
      r[k] = sqrt(ddx * ddx + ddy * ddy);
    }
  CHECK(mfree_kernel_eval(ctx, MFREE_KERNEL_CUBIC_SPLINE, 2, 0.0, h, nnz, r, w, NULL, NULL));

  int64_t kmin = nnz, kmax = 0;
  double smin = 1e300, smax = -1e300, sin_ = 0.0, corner = 0.0;
  int nin = 0;
  for (int i = 0; i < n; ++i) {
    const int64_t k = rowptr[i + 1] - rowptr[i];
    if (k < kmin) kmin = k;
    if (k > kmax) kmax = k;
    double s = 0.0;
    for (int64_t q = rowptr[i]; q < rowptr[i + 1]; ++q) s += w[q] * vol;
    if (s < smin) smin = s;
    if (s > smax) smax = s;
    const double xi = x[2 * i], yi = x[2 * i + 1];
    if (xi > 2 * radius * h && xi < 1 - 2 * radius * h && yi > 2 * radius * h &&
        yi < 1 - 2 * radius * h) {
      sin_ += s;
      ++nin;
    }
    if (i == 0) corner = s;
  }
  printf("neighbour search: %.3f s (%.3g particles/s), %lld pairs\n", t1 - t0,
         n / (t1 - t0 > 0 ? t1 - t0 : 1e-9), (long long)nnz);
  printf("neighbours per particle: min %lld, mean %.2f, max %lld\n", (long long)kmin,
         (double)nnz / n, (long long)kmax);
  printf("kernel sum: min %.4f, max %.4f, interior mean %.4f (%d particles), corner %.4f\n",
         smin, smax, nin ? sin_ / nin : 0.0, nin, corner);

  free(x); free(rowptr); free(cols); free(r); free(w);
  mfree_particles_destroy(&ps);
  mfree_context_destroy(&ctx);
  return 0;
}
