/* Verlet skin of the neighbour search (mfree_particles_set_search_skin): the setups of a
 * time loop with and without a skin, on jittered lattices in 2D and 3D with ~21 / ~57
 * neighbours (bench_util.h), every particle moving at its own constant random velocity.
 * Two sets borrow the same positions; at every step each is set up once (alternately,
 * so that a busy moment of the machine spoils both alike); their lists are equal (t210
 * checks it), only the cost differs. Prints the mean setup time of each over the loop,
 * their ratio, the searches the skin needed, and the mean time of a setup that reused
 * the candidates (a filter pass) against a fresh search.
 * Usage: bench_verlet [n [steps [skin [move]]]]   (defaults 1e5 40 0.25 0.01: skin and
 * the largest move per step and component in units of h; the fluid's skin is 0.25 h).
 * One thread, then MFREE_BENCH_THREADS (default all); best of MFREE_BENCH_REPS loops (3).
 * Never run by the tests. */
#include <stdio.h>
#include <stdlib.h>

#include "bench_util.h"
#include <mfree.h>

#define CHECK(call)                                                              \
  do {                                                                           \
    const mfree_status_t st_ = (call);                                           \
    if (st_ != MFREE_SUCCESS) {                                                  \
      fprintf(stderr, "%s failed: %s\n", #call, mfree_status_string(st_));       \
      exit(1);                                                                   \
    }                                                                            \
  } while (0)

typedef struct {
  double fresh, skin, reused; /* seconds: all fresh setups, all skin setups, the reused ones */
  int nreused;
  int64_t searches;
} loop_t;

static loop_t run_loop(int dim, int n, const double *x0, const double *vel, int steps, double h, double skin,
                       int threads) {
  mfree_context_t *ctx = NULL;
  CHECK(mfree_context_create(&ctx));
  bench_page_hints(ctx);
  CHECK(mfree_context_set_num_threads(ctx, threads));
  double *x = malloc(sizeof(double) * (size_t)dim * (size_t)n);
  for (size_t k = 0; k < (size_t)dim * (size_t)n; ++k) x[k] = x0[k];
  mfree_particles_t *ps[2] = {NULL, NULL};
  for (int s = 0; s < 2; ++s) {
    CHECK(mfree_particles_create(ctx, dim, n, &ps[s]));
    CHECK(mfree_particles_set_positions(ps[s], x, MFREE_LAYOUT_AOS, dim, MFREE_BORROW));
    CHECK(mfree_particles_set_support(ps[s], &h, 0, MFREE_COPY));
    if (s == 1) CHECK(mfree_particles_set_search_skin(ps[s], skin));
    CHECK(mfree_particles_setup(ps[s])); /* first setups (fresh buffers) not timed */
  }
  loop_t l = {0, 0, 0, 0, 0};
  int64_t c0 = 0, c1 = 0;
  CHECK(mfree_particles_get_search_count(ps[1], &c0));
  for (int step = 0; step < steps; ++step) {
    for (size_t k = 0; k < (size_t)dim * (size_t)n; ++k) x[k] += vel[k];
    for (int s = 0; s < 2; ++s) {
      const int which = (step + s) % 2; /* alternate the order */
      int64_t before = 0, after = 0;
      CHECK(mfree_particles_get_search_count(ps[which], &before));
      const double t0 = bench_now();
      CHECK(mfree_particles_setup(ps[which]));
      const double t = bench_now() - t0;
      CHECK(mfree_particles_get_search_count(ps[which], &after));
      if (which == 0) {
        l.fresh += t;
      } else {
        l.skin += t;
        if (after == before) {
          l.reused += t;
          ++l.nreused;
        }
      }
    }
  }
  CHECK(mfree_particles_get_search_count(ps[1], &c1));
  l.searches = c1 - c0;
  for (int s = 0; s < 2; ++s) mfree_particles_destroy(&ps[s]);
  mfree_context_destroy(&ctx);
  free(x);
  return l;
}

int main(int argc, char **argv) {
  const double n_target = argc > 1 ? atof(argv[1]) : 1e5;
  const int steps = argc > 2 ? atoi(argv[2]) : 40;
  const double skin_h = argc > 3 ? atof(argv[3]) : 0.25;
  const double move_h = argc > 4 ? atof(argv[4]) : 0.01;
  const int reps = bench_reps(3);
  const int threads[2] = {1, bench_threads()};
  char lbuf[64];
  for (int dim = 2; dim <= 3; ++dim) {
    int n = 0;
    double *x0 = bench_lattice(dim, bench_side(dim, n_target), 0.3, &n);
    const double h = 0.5 * bench_radius(dim); /* kappa 2: radius 2h */
    double *vel = malloc(sizeof(double) * (size_t)dim * (size_t)n);
    uint64_t seed = 0x5eed + (uint64_t)dim;
    for (size_t k = 0; k < (size_t)dim * (size_t)n; ++k) vel[k] = move_h * h * bench_rand(&seed);
    printf("%dD, %d particles, %d steps, skin %.3g h, move per step and component up to %.3g h\n", dim, n, steps,
           skin_h, move_h);
    for (int t = 0; t < 2; ++t) {
      const char *label = t == 0 ? "1 thread" : bench_threads_label(threads[1], lbuf, sizeof lbuf);
      loop_t best = {1e300, 1e300, 1e300, 1, 0};
      for (int r = 0; r < reps; ++r) {
        const loop_t l = run_loop(dim, n, x0, vel, steps, h, skin_h * h, threads[t]);
        if (l.fresh < best.fresh) best.fresh = l.fresh;
        if (l.skin < best.skin) {
          best.skin = l.skin;
          best.searches = l.searches;
        }
        if (l.nreused > 0 && l.reused / l.nreused < best.reused / best.nreused) {
          best.reused = l.reused;
          best.nreused = l.nreused;
        }
      }
      const double fresh = best.fresh / steps, skin = best.skin / steps, reused = best.reused / best.nreused;
      printf("  %-12s fresh search %8.3f ms/setup, with skin %8.3f ms/setup (%lld searches in %d steps): "
             "fresh/skin %.2f; a reused setup %8.3f ms: fresh/reused %.2f\n",
             label, 1e3 * fresh, 1e3 * skin, (long long)best.searches, steps, fresh / skin, 1e3 * reused,
             fresh / reused);
      bench_figure(fresh, "s", "verlet %dD %s fresh setup", dim, label);
      bench_figure(skin, "s", "verlet %dD %s skin setup", dim, label);
      bench_figure(reused, "s", "verlet %dD %s reused setup", dim, label);
    }
    free(x0);
    free(vel);
  }
  return 0;
}
