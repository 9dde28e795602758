/* Bad input to the pair-list functions: each case returns its documented status with a
 * message in the host's numbering, writes nothing, and leaves the objects usable (the
 * next good call gives the same results as before). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"

enum { M = 6, N = M * M };

static double x[2 * N], h = 0.0;
static int32_t pi[4 * N * N], pj[4 * N * N];
static int64_t np = 0;

/* A 6 x 6 lattice, spacing 1, h = 1.2, pairs within 2h in 1-based numbering. */
static void make(void) {
  for (int p = 0; p < N; ++p) {
    x[2 * p] = p % M + 0.01 * (p % 3);
    x[2 * p + 1] = p / M + 0.01 * (p % 5);
  }
  h = 1.2;
  np = 0;
  for (int a = 0; a < N; ++a)
    for (int b = a + 1; b < N; ++b) {
      const double dx = x[2 * a] - x[2 * b], dy = x[2 * a + 1] - x[2 * b + 1];
      if (dx * dx + dy * dy < 4.0 * h * h) {
        pi[np] = a + 1;
        pj[np] = b + 1;
        ++np;
      }
    }
}

static mfree_particles_t *set_on(mfree_context_t *ctx) {
  mfree_particles_t *ps = NULL;
  assert_ok(ctx, mfree_particles_create(ctx, 2, N, &ps));
  assert_ok(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 2, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  const double v = 1.0;
  assert_ok(ctx, mfree_particles_set_volumes(ps, &v, 0, MFREE_COPY));
  return ps;
}

static void test_set_pairs_errors(void **state) {
  (void)state;
  make();
  mfree_context_t *ctx = NULL;
  assert_ok(ctx, mfree_context_create(&ctx));
  mfree_particles_t *ps = set_on(ctx);
  assert_ok(ctx, mfree_particles_set_pairs(ps, np, pi, pj, 1, MFREE_COPY));
  assert_ok(ctx, mfree_particles_setup(ps));
  int64_t nnz0 = 0;
  assert_ok(ctx, mfree_particles_get_neighbor_nnz(ps, &nnz0));
  assert_int_equal(nnz0, 2 * np);

  /* set time: negative count, NULL arrays, base, mem, range, self pair */
  assert_error(ctx, mfree_particles_set_pairs(ps, -1, pi, pj, 1, MFREE_COPY), MFREE_ERR_ARG, "negative");
  assert_error(ctx, mfree_particles_set_pairs(ps, np, NULL, pj, 1, MFREE_COPY), MFREE_ERR_NULL, "NULL");
  assert_error(ctx, mfree_particles_set_pairs(ps, np, pi, NULL, 1, MFREE_COPY), MFREE_ERR_NULL, "NULL");
  assert_error(ctx, mfree_particles_set_pairs(ps, np, pi, pj, 2, MFREE_COPY), MFREE_ERR_ARG, "base");
  assert_error(ctx, mfree_particles_set_pairs(ps, np, pi, pj, 1, (mfree_mem_t)7), MFREE_ERR_ARG, "mem");
  assert_error(NULL, mfree_particles_set_pairs(NULL, np, pi, pj, 1, MFREE_COPY), MFREE_ERR_NULL, NULL);
  /* 1-based lists passed as 0-based: the largest index is out of range */
  assert_error(ctx, mfree_particles_set_pairs(ps, np, pi, pj, 0, MFREE_COPY), MFREE_ERR_INPUT,
               "is outside [0, 35]");
  const int32_t s0 = pi[2];
  pi[2] = 0; /* 0 in a 1-based list: pair 3 */
  assert_error(ctx, mfree_particles_set_pairs(ps, np, pi, pj, 1, MFREE_COPY), MFREE_ERR_INPUT,
               "pair 3 (1-based): pair_i = 0 is outside [1, 36]");
  pi[2] = N + 1;
  assert_error(ctx, mfree_particles_set_pairs(ps, np, pi, pj, 1, MFREE_COPY), MFREE_ERR_INPUT,
               "pair_i = 37 is outside [1, 36]");
  pi[2] = pj[2]; /* self pair, named in 1-based numbering */
  char want[128];
  snprintf(want, sizeof want, "pair 3 (1-based) joins particle %d with itself", (int)pj[2]);
  assert_error(ctx, mfree_particles_set_pairs(ps, np, pi, pj, 1, MFREE_COPY), MFREE_ERR_INPUT, want);
  pi[2] = s0;
  /* nothing changed: still set up, same lists */
  int64_t nnz = 0;
  assert_ok(ctx, mfree_particles_get_neighbor_nnz(ps, &nnz));
  assert_int_equal(nnz, nnz0);

  /* duplicates (same and reversed orientation) are found at setup, in 1-based terms */
  const int32_t ti = pi[np - 1], tj = pj[np - 1];
  pi[np - 1] = pi[4];
  pj[np - 1] = pj[4];
  assert_ok(ctx, mfree_particles_set_pairs(ps, np, pi, pj, 1, MFREE_BORROW));
  snprintf(want, sizeof want, "pairs 5 and %d (1-based) both join particles %d and %d", (int)np,
           (int)pi[4], (int)pj[4]);
  assert_error(ctx, mfree_particles_setup(ps), MFREE_ERR_INPUT, want);
  pi[np - 1] = pj[4];
  pj[np - 1] = pi[4];
  assert_error(ctx, mfree_particles_setup(ps), MFREE_ERR_INPUT, "duplicate pair");
  /* a borrowed list that turned bad is caught at setup too */
  pi[np - 1] = ti;
  pj[np - 1] = tj;
  pj[0] = pi[0];
  assert_error(ctx, mfree_particles_setup(ps), MFREE_ERR_INPUT, "with itself");
  make();
  assert_ok(ctx, mfree_particles_setup(ps));
  assert_ok(ctx, mfree_particles_get_neighbor_nnz(ps, &nnz));
  assert_int_equal(nnz, nnz0);
  /* 0 pairs: empty rows */
  assert_ok(ctx, mfree_particles_set_pairs(ps, 0, NULL, NULL, 0, MFREE_COPY));
  assert_ok(ctx, mfree_particles_setup(ps));
  assert_ok(ctx, mfree_particles_get_neighbor_nnz(ps, &nnz));
  assert_int_equal(nnz, 0);
  mfree_particles_destroy(&ps);
  mfree_context_destroy(&ctx);
}

static void test_pair_gradient_errors(void **state) {
  (void)state;
  make();
  mfree_context_t *ctx = NULL;
  assert_ok(ctx, mfree_context_create(&ctx));
  mfree_particles_t *ps = set_on(ctx);
  mfree_approximant_t *a = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_RANDLES_LIBERSKY, &a));
  const int64_t cap = 3 * np;
  double *gi = malloc(sizeof(double) * cap), *gj = malloc(sizeof(double) * cap);
  double *ref = malloc(sizeof(double) * cap);
  /* not set up; then set up on searched lists: no pair list */
  assert_error(ctx, mfree_approximant_get_pair_gradients(a, gi, gj, 2, cap), MFREE_ERR_STATE, "not set up");
  assert_ok(ctx, mfree_approximant_setup(a));
  assert_error(ctx, mfree_approximant_get_pair_gradients(a, gi, gj, 2, cap), MFREE_ERR_STATE, "no pair list");
  assert_ok(ctx, mfree_particles_set_pairs(ps, np, pi, pj, 1, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_setup(ps));
  /* the set was set up again after the approximant */
  assert_error(ctx, mfree_approximant_get_pair_gradients(a, gi, gj, 2, cap), MFREE_ERR_STATE,
               "changed since");
  assert_ok(ctx, mfree_approximant_setup(a));
  assert_ok(ctx, mfree_approximant_get_pair_gradients(a, ref, NULL, 2, cap));

  for (int64_t k = 0; k < cap; ++k) gi[k] = gj[k] = -7.0;
  assert_error(ctx, mfree_approximant_get_pair_gradients(a, gi, gj, 2, 2 * np - 1), MFREE_ERR_ARG,
               "are needed");
  assert_error(ctx, mfree_approximant_get_pair_gradients(a, gi, gj, 3, 3 * np - 2), MFREE_ERR_ARG,
               "are needed");
  assert_error(ctx, mfree_approximant_get_pair_gradients(a, gi, gj, 1, cap), MFREE_ERR_ARG,
               "leading dimension");
  assert_error(ctx, mfree_approximant_get_pair_gradients(a, gi, gj, 2, -1), MFREE_ERR_ARG, "negative");
  assert_error(ctx, mfree_approximant_get_pair_gradients(a, NULL, gj, 2, cap), MFREE_ERR_NULL, "gi");
  assert_error(NULL, mfree_approximant_get_pair_gradients(NULL, gi, gj, 2, cap), MFREE_ERR_NULL, NULL);
  assert_error(ctx, mfree_approximant_get_pair_gradients_antisymmetric(a, gi, 2, 2 * np - 1),
               MFREE_ERR_ARG, "are needed");
  for (int64_t k = 0; k < cap; ++k) assert_true(gi[k] == -7.0 && gj[k] == -7.0); /* nothing written */
  /* still usable: the same gradients; the exact capacity is enough */
  assert_ok(ctx, mfree_approximant_get_pair_gradients(a, gi, gj, 2, 2 * np));
  assert_memory_equal(gi, ref, sizeof(double) * 2 * np);
  /* gradient table not built */
  assert_ok(ctx, mfree_approximant_set_derivatives(a, MFREE_DERIV_VALUE));
  assert_ok(ctx, mfree_approximant_setup(a));
  assert_error(ctx, mfree_approximant_get_pair_gradients(a, gi, gj, 2, cap), MFREE_ERR_STATE,
               "gradient table");

  /* correction data: size, capacity, methods without */
  assert_ok(ctx, mfree_approximant_set_derivatives(a, MFREE_DERIV_GRADIENT));
  assert_ok(ctx, mfree_approximant_setup(a));
  int32_t nc = 0;
  assert_ok(ctx, mfree_approximant_get_correction_size(a, &nc));
  assert_int_equal(nc, 4);
  double *cor = malloc(sizeof(double) * 4 * N);
  for (int k = 0; k < 4 * N; ++k) cor[k] = -7.0;
  assert_error(ctx, mfree_approximant_get_correction(a, cor, 4, 4 * N - 1), MFREE_ERR_ARG, "are needed");
  assert_error(ctx, mfree_approximant_get_correction(a, cor, 3, 4 * N), MFREE_ERR_ARG, "leading dimension");
  assert_error(ctx, mfree_approximant_get_correction(a, NULL, 4, 4 * N), MFREE_ERR_NULL, "NULL");
  for (int k = 0; k < 4 * N; ++k) assert_true(cor[k] == -7.0);
  assert_ok(ctx, mfree_approximant_get_correction(a, cor, 4, 4 * N));
  assert_error(NULL, mfree_approximant_get_correction_size(a, NULL), MFREE_ERR_NULL, NULL);
  mfree_approximant_t *sph = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_SPH, &sph));
  assert_error(ctx, mfree_approximant_get_correction_size(sph, &nc), MFREE_ERR_UNSUPPORTED, "defined for");
  mfree_approximant_t *mls3 = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, &mls3));
  assert_ok(ctx, mfree_approximant_set_order(mls3, 3));
  assert_error(ctx, mfree_approximant_get_correction_size(mls3, &nc), MFREE_ERR_UNSUPPORTED, "order 2");
  /* host points: no pairs */
  mfree_approximant_t *pts = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, &pts));
  const double xp[2] = {2.5, 2.5}, hp = 1.2;
  assert_ok(ctx, mfree_approximant_set_points(pts, 1, xp, MFREE_LAYOUT_AOS, 2, &hp, 0, MFREE_COPY));
  assert_ok(ctx, mfree_approximant_setup(pts));
  assert_error(ctx, mfree_approximant_get_pair_gradients(pts, gi, gj, 2, cap), MFREE_ERR_UNSUPPORTED,
               "host points");
  /* a set without pairs */
  int64_t cnt = 0;
  mfree_particles_t *plain = set_on(ctx);
  assert_error(ctx, mfree_particles_get_num_pairs(plain, &cnt), MFREE_ERR_STATE, "no pair list");
  assert_error(NULL, mfree_particles_get_num_pairs(ps, NULL), MFREE_ERR_NULL, NULL);
  /* CSR lists replace the pairs, and pairs replace CSR lists */
  int64_t rowptr[N + 1];
  for (int p = 0; p <= N; ++p) rowptr[p] = 0;
  assert_ok(ctx, mfree_particles_set_neighbors(ps, rowptr, pi, 0, MFREE_COPY));
  assert_error(ctx, mfree_particles_get_num_pairs(ps, &cnt), MFREE_ERR_STATE, "no pair list");
  assert_ok(ctx, mfree_particles_set_pairs(ps, np, pi, pj, 1, MFREE_BORROW));
  assert_ok(ctx, mfree_particles_setup(ps));
  assert_ok(ctx, mfree_approximant_setup(a));
  assert_ok(ctx, mfree_approximant_get_pair_gradients(a, gi, NULL, 2, 2 * np));
  assert_memory_equal(gi, ref, sizeof(double) * 2 * np);
  mfree_particles_destroy(&plain);
  mfree_approximant_destroy(&pts);
  mfree_approximant_destroy(&mls3);
  mfree_approximant_destroy(&sph);
  free(cor);
  free(gi);
  free(gj);
  free(ref);
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
  mfree_context_destroy(&ctx);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_set_pairs_errors),
      cmocka_unit_test(test_pair_gradient_errors),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
