/*
 * t210: the Verlet skin of the neighbour search (mfree_particles_set_search_skin)
 * against a fresh search.
 *
 * A set with a skin keeps candidate lists of radius kappa h + skin and filters its rows
 * from them until some particle has moved (or grown its radius) by more than half the
 * skin. Its lists must be those of a set without a skin, bit for bit (the same sets, in
 * the same order), after every setup. Here both sets borrow the same positions and
 * supports, which move at random for many steps, and are set up after each step; the
 * fresh set is the oracle (t201 checks it against the O(N^2) criterion). In 1D, 2D and
 * 3D, on one and two threads (enough particles that two threads split every pass), for
 * the three conventions, with:
 *  - uniform supports, lattice (spatial) order and a random particle order;
 *  - supports that change every step (the radius growth spends the skin too);
 *  - a periodic box (positions leave it and wrap), SoA positions;
 *  - ghosts and global ids (rows in id order);
 *  - a particle whose position turns non-finite and later finite again (it is isolated,
 *    then must be found again);
 *  - a pure translation of an unjittered lattice with pairs exactly at the support edge;
 *  - a periodic box too short for the candidates but not for the supports (a search at
 *    every setup) and one too short for the supports (the fresh set's error).
 * The search count (mfree_particles_get_search_count) shows that the candidates were
 * reused (fewer searches than setups, none when nothing moved) and rebuilt (more than
 * one). Bad input: a negative, NaN or infinite skin is MFREE_ERR_ARG naming the skin and
 * changes nothing (the set stays set up, the skin in force); NULL handle and output.
 */
#include "testutil.h"
#include "nbr_lists.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
  int dim;
  int32_t n, ghosts;
  int layout;                 /* MFREE_LAYOUT_AOS or _SOA */
  mfree_search_t conv;
  double kappa, skin;
  int periodic;               /* every axis periodic, box [lo, hi) */
  double lo, hi;
  int ids;                    /* global ids: reversed indices */
  double move;                /* largest move per component and step */
  double grow;                /* relative change of each support per step (0: fixed) */
  int nonfinite;              /* particle 7 non-finite at steps 0-1 and 5-6 */
  int translate;              /* every particle moved by the same vector */
  int steps;
  int every;                  /* candidates never fit: a search at every setup */
} scene_t;

/* Positions of the scene's n particles: a lattice of spacing 1 (jittered unless
 * translated), in lattice order or shuffled. */
static void place(const scene_t *s, double *x, int shuffle, mfree_rng_t *r) {
  int m = 1;
  while (1) {
    int64_t p = 1;
    for (int d = 0; d < s->dim; ++d) p *= m;
    if (p >= s->n) break;
    ++m;
  }
  int32_t *perm = malloc(sizeof(int32_t) * (size_t)s->n);
  assert_non_null(perm);
  for (int32_t i = 0; i < s->n; ++i) perm[i] = i;
  if (shuffle)
    for (int32_t i = s->n - 1; i > 0; --i) {
      const int32_t j = (int32_t)(mfree_rng_uniform(r) * (i + 1));
      const int32_t t = perm[i];
      perm[i] = perm[j];
      perm[j] = t;
    }
  for (int32_t p = 0; p < s->n; ++p) {
    int32_t q = p;
    for (int d = 0; d < s->dim; ++d) {
      const double jit = s->translate ? 0.0 : 0.3 * (2.0 * mfree_rng_uniform(r) - 1.0);
      const double v = (q % m) + jit;
      const int32_t i = perm[p];
      if (s->layout == MFREE_LAYOUT_AOS) x[(size_t)s->dim * i + d] = v;
      else x[(size_t)s->n * d + i] = v;
      q /= m;
    }
  }
  free(perm);
}

static double *xat(const scene_t *s, double *x, int32_t i, int d) {
  return s->layout == MFREE_LAYOUT_AOS ? &x[(size_t)s->dim * i + d] : &x[(size_t)s->n * d + i];
}

static mfree_particles_t *make_set(mfree_context_t *ctx, const scene_t *s, double *x, double *h,
                                   const int64_t *ids, double skin) {
  mfree_particles_t *ps = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, s->dim, s->n, &ps));
  const int64_t ld = s->layout == MFREE_LAYOUT_AOS ? s->dim : s->n;
  assert_ok(ctx, mfree_particles_set_positions(ps, x, (mfree_layout_t)s->layout, ld, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_support(ps, h, 1, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_search(ps, s->conv, s->kappa));
  if (s->ghosts) assert_ok(ctx, mfree_particles_set_num_ghost(ps, s->ghosts));
  if (s->periodic) {
    const double lo[3] = {s->lo, s->lo, s->lo}, hi[3] = {s->hi, s->hi, s->hi};
    const int32_t per[3] = {1, 1, 1};
    assert_ok(ctx, mfree_particles_set_periodic(ps, lo, hi, per));
  }
  if (ids) assert_ok(ctx, mfree_particles_set_global_ids(ps, ids, MFREE_BORROW));
  if (skin > 0.0) assert_ok(ctx, mfree_particles_set_search_skin(ps, skin));
  return ps;
}

static void assert_same_status(mfree_context_t *ctx, mfree_particles_t *a, mfree_particles_t *b, int32_t n) {
  int32_t *sa = malloc(sizeof(int32_t) * (size_t)n), *sb = malloc(sizeof(int32_t) * (size_t)n);
  int32_t fa = -1, fb = -1;
  assert_non_null(sa);
  assert_non_null(sb);
  assert_ok(ctx, mfree_particles_get_site_status(a, sa, &fa));
  assert_ok(ctx, mfree_particles_get_site_status(b, sb, &fb));
  assert_int_equal(fa, fb);
  assert_memory_equal(sa, sb, sizeof(int32_t) * (size_t)n);
  free(sa);
  free(sb);
}

/* The scene for `steps` steps with the skin and without; returns the skin set's search
 * count. Every setup's lists must be equal. */
static int64_t run(const scene_t *s, int threads, int shuffle, uint64_t seed) {
  mfree_rng_t r;
  mfree_rng_seed(&r, seed);
  mfree_context_t *ctx = NULL;
  assert_ok(ctx, mfree_context_create(&ctx));
  assert_ok(ctx, mfree_context_set_num_threads(ctx, threads));
  double *x = malloc(sizeof(double) * (size_t)s->dim * (size_t)s->n);
  double *h = malloc(sizeof(double) * (size_t)s->n);
  int64_t *ids = s->ids ? malloc(sizeof(int64_t) * (size_t)s->n) : NULL;
  assert_non_null(x);
  assert_non_null(h);
  place(s, x, shuffle, &r);
  for (int32_t i = 0; i < s->n; ++i) h[i] = s->grow > 0.0 ? 0.8 + 0.4 * mfree_rng_uniform(&r) : 1.0;
  if (ids)
    for (int32_t i = 0; i < s->n; ++i) ids[i] = 10 * (int64_t)(s->n - i);
  mfree_particles_t *fresh = make_set(ctx, s, x, h, ids, 0.0);
  mfree_particles_t *verlet = make_set(ctx, s, x, h, ids, s->skin);
  double saved = 0.0;
  for (int step = 0; step < s->steps; ++step) {
    if (step > 0) {
      double t[3];
      for (int d = 0; d < s->dim; ++d) t[d] = s->move * (2.0 * mfree_rng_uniform(&r) - 1.0);
      for (int32_t i = 0; i < s->n; ++i) {
        for (int d = 0; d < s->dim; ++d)
          *xat(s, x, i, d) += s->translate ? t[d] : s->move * (2.0 * mfree_rng_uniform(&r) - 1.0);
        if (s->grow > 0.0) {
          h[i] *= 1.0 + s->grow * (2.0 * mfree_rng_uniform(&r) - 1.0);
          h[i] = h[i] < 0.6 ? 0.6 : (h[i] > 1.4 ? 1.4 : h[i]);
        }
      }
    }
    /* invalid at the first build (steps 0-1), valid, invalid again (steps 5-6) */
    if (s->nonfinite && (step == 0 || step == 5)) {
      saved = *xat(s, x, 7, 0);
      *xat(s, x, 7, 0) = NAN;
    }
    if (s->nonfinite && (step == 2 || step == 7)) *xat(s, x, 7, 0) = saved;
    const mfree_status_t st = mfree_particles_setup(fresh);
    assert_status(ctx, mfree_particles_setup(verlet), st);
    assert_true(st >= 0);
    lists_t a = lists_fetch(ctx, fresh), b = lists_fetch(ctx, verlet);
    assert_lists_equal(&a, &b);
    lists_free(&a);
    lists_free(&b);
    assert_same_status(ctx, fresh, verlet, s->n);
  }
  int64_t nf = -1, nv = -1;
  assert_ok(ctx, mfree_particles_get_search_count(fresh, &nf));
  assert_ok(ctx, mfree_particles_get_search_count(verlet, &nv));
  assert_int_equal(nf, s->steps);
  assert_true(nv >= 1 && nv <= nf);
  if (s->every) assert_int_equal(nv, nf);
  /* nothing moves: no search (unless there are no candidates) */
  assert_ok(ctx, mfree_particles_setup(verlet));
  int64_t again = -1;
  assert_ok(ctx, mfree_particles_get_search_count(verlet, &again));
  assert_int_equal(again, nv + (s->every ? 1 : 0));
  mfree_particles_destroy(&fresh);
  mfree_particles_destroy(&verlet);
  mfree_context_destroy(&ctx);
  free(x);
  free(h);
  free(ids);
  return nv;
}

static const int32_t kN[4] = {0, 3000, 2500, 2744};

static scene_t base(int dim) {
  scene_t s;
  memset(&s, 0, sizeof s);
  s.dim = dim;
  s.n = kN[dim];
  s.layout = MFREE_LAYOUT_AOS;
  s.conv = MFREE_SEARCH_GATHER;
  s.kappa = 2.0;
  s.skin = 0.3;
  s.move = 0.04;
  s.steps = 20;
  return s;
}

/* Both thread counts; the candidates must have been reused and rebuilt. */
static void run_both(const scene_t *s, int shuffle, uint64_t seed) {
  for (int t = 1; t <= 2; ++t) {
    const int64_t nv = run(s, t, shuffle, seed);
    assert_true(nv > 1);
    assert_true(nv < s->steps);
  }
}

static void test_uniform(void **state) {
  (void)state;
  for (int dim = 1; dim <= 3; ++dim) {
    scene_t s = base(dim);
    run_both(&s, 0, 0x2100 + dim);
    run_both(&s, 1, 0x2110 + dim);
  }
}

static void test_conventions_growing(void **state) {
  (void)state;
  const mfree_search_t conv[3] = {MFREE_SEARCH_GATHER, MFREE_SEARCH_SYMMETRIC_MAX, MFREE_SEARCH_SYMMETRIC_MEAN};
  for (int dim = 1; dim <= 3; ++dim)
    for (int c = 0; c < 3; ++c) {
      scene_t s = base(dim);
      s.conv = conv[c];
      s.grow = 0.01;
      s.move = 0.02;
      run_both(&s, c == 1, 0x2120 + 3 * dim + c);
    }
}

static void test_periodic(void **state) {
  (void)state;
  for (int dim = 1; dim <= 3; ++dim) {
    scene_t s = base(dim);
    s.periodic = 1;
    s.layout = MFREE_LAYOUT_SOA;
    s.lo = -0.5;
    s.hi = dim == 1 ? 2999.5 : (dim == 2 ? 49.5 : 13.5);
    s.move = 0.05;  /* drifts out of the box and wraps */
    for (int t = 1; t <= 2; ++t) assert_true(run(&s, t, 0, 0x2130 + dim) > 1);
  }
}

static void test_ghosts_ids(void **state) {
  (void)state;
  for (int dim = 1; dim <= 3; ++dim) {
    scene_t s = base(dim);
    s.ghosts = s.n / 5;
    s.ids = 1;
    s.conv = dim == 2 ? MFREE_SEARCH_SYMMETRIC_MAX : MFREE_SEARCH_GATHER;
    run_both(&s, dim == 3, 0x2140 + dim);
  }
}

static void test_nonfinite(void **state) {
  (void)state;
  for (int dim = 1; dim <= 3; ++dim) {
    scene_t s = base(dim);
    s.nonfinite = 1;
    s.steps = 12;
    s.move = 0.005;
    for (int t = 1; t <= 2; ++t) assert_true(run(&s, t, 0, 0x2150 + dim) > 1);
  }
}

/* An unjittered lattice with kappa h equal to the spacing: every lattice neighbour sits
 * at the edge of the closed support, then the whole lattice moves (the rounding of the
 * differences decides), and the skin is so small that every few steps rebuild. */
static void test_edge(void **state) {
  (void)state;
  for (int dim = 1; dim <= 3; ++dim) {
    scene_t s = base(dim);
    s.translate = 1;
    s.kappa = 1.0;
    s.skin = 0.05;
    s.move = 0.01;
    for (int t = 1; t <= 2; ++t) assert_true(run(&s, t, 0, 0x2160 + dim) > 1);
  }
}

/* Box of 4.5: the supports (radius 2) fit, the candidates (2 + 0.3) do not: a search at
 * every setup, the same lists. Box of 3.5: both sets fail alike. */
static void test_short_box(void **state) {
  (void)state;
  scene_t s = base(2);
  s.n = 16;
  s.periodic = 1;
  s.lo = -0.5;
  s.hi = 4.0;
  s.steps = 5;
  s.every = 1;
  run(&s, 1, 0, 0x2170);

  mfree_context_t *ctx = NULL;
  assert_ok(ctx, mfree_context_create(&ctx));
  double x[2 * 9], h[9];
  mfree_rng_t r;
  mfree_rng_seed(&r, 0x2171);
  s.n = 9;
  s.hi = 2.5;
  place(&s, x, 0, &r);
  for (int i = 0; i < 9; ++i) h[i] = 1.0;
  mfree_particles_t *ps = make_set(ctx, &s, x, h, NULL, 0.3);
  assert_error(ctx, mfree_particles_setup(ps), MFREE_ERR_INPUT, "periodic box");
  mfree_particles_destroy(&ps);
  mfree_context_destroy(&ctx);
}

static void test_bad_input(void **state) {
  (void)state;
  mfree_context_t *ctx = NULL;
  assert_ok(ctx, mfree_context_create(&ctx));
  scene_t s = base(2);
  s.n = 100;
  double x[200], h[100];
  mfree_rng_t r;
  mfree_rng_seed(&r, 0x2180);
  place(&s, x, 0, &r);
  for (int i = 0; i < 100; ++i) h[i] = 1.0;
  mfree_particles_t *ps = make_set(ctx, &s, x, h, NULL, 0.3);
  assert_ok(ctx, mfree_particles_setup(ps));
  lists_t before = lists_fetch(ctx, ps);
  const double bad[3] = {-0.1, NAN, INFINITY};
  for (int k = 0; k < 3; ++k) {
    assert_error(ctx, mfree_particles_set_search_skin(ps, bad[k]), MFREE_ERR_ARG, "skin");
    lists_t now = lists_fetch(ctx, ps); /* still set up, the same lists */
    assert_lists_equal(&before, &now);
    lists_free(&now);
  }
  /* the skin of 0.3 still in force: a small move searches nothing */
  x[0] += 0.1;
  assert_ok(ctx, mfree_particles_setup(ps));
  int64_t count = -1;
  assert_ok(ctx, mfree_particles_get_search_count(ps, &count));
  assert_int_equal(count, 1);
  /* 0 turns the skin off: every setup searches */
  assert_ok(ctx, mfree_particles_set_search_skin(ps, 0.0));
  assert_ok(ctx, mfree_particles_setup(ps));
  assert_ok(ctx, mfree_particles_setup(ps));
  assert_ok(ctx, mfree_particles_get_search_count(ps, &count));
  assert_int_equal(count, 3);
  assert_error(ctx, mfree_particles_get_search_count(ps, NULL), MFREE_ERR_NULL, "NULL");
  assert_int_equal(mfree_particles_set_search_skin(NULL, 0.1), MFREE_ERR_NULL);
  assert_int_equal(mfree_particles_get_search_count(NULL, &count), MFREE_ERR_NULL);
  lists_free(&before);
  mfree_particles_destroy(&ps);
  mfree_context_destroy(&ctx);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_uniform),     cmocka_unit_test(test_conventions_growing),
      cmocka_unit_test(test_periodic),    cmocka_unit_test(test_ghosts_ids),
      cmocka_unit_test(test_nonfinite),   cmocka_unit_test(test_edge),
      cmocka_unit_test(test_short_box),   cmocka_unit_test(test_bad_input),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
