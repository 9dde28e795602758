/* Thread safety (STYLE.md "apply on a set-up object is reentrant and
 * deterministic; different objects may be used from different threads"):
 *  1. several threads apply ONE set-up approximant to different fields at once (values,
 *     gradients, Laplacians, divergence, apply_add) and get bitwise the results of one
 *     thread;
 *  2. several threads each build their own context, particle set, approximant (a
 *     different method per thread), assembler and fluid system at once and get bitwise
 *     the results of the same work done on one thread.
 * Run under ThreadSanitizer by the tsan preset (CMakePresets.json); in the other builds
 * it checks the bitwise equality. */
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"

enum { M = 14, N = M * M, NTHREADS = 4, NFIELDS = 3, REPEAT = 3 };
static const double SP = 1.0 / M;

static void lattice(double *x, uint64_t seed) {
  mfree_rng_t r;
  mfree_rng_seed(&r, seed);
  for (int j = 0; j < M; ++j)
    for (int i = 0; i < M; ++i) {
      x[2 * (j * M + i)] = (i + 0.5 + 0.25 * (2 * mfree_rng_uniform(&r) - 1)) * SP;
      x[2 * (j * M + i) + 1] = (j + 0.5 + 0.25 * (2 * mfree_rng_uniform(&r) - 1)) * SP;
    }
}

static void field(const double *x, int k, double *u) {
  for (int p = 0; p < N; ++p) {
    const double a = x[2 * p], b = x[2 * p + 1];
    u[p] = sin(1.0 + k * a) * cos(2.0 * b - k) + 0.1 * k * a * b;
  }
}

/* ---- 1. one approximant, many threads ---------------------------------------------- */

typedef struct {
  double value[N], grad[2 * N], lap[N], div[N], acc[N];
} results_t;

static mfree_context_t *shared_ctx;
static mfree_approximant_t *shared_a;
static double X[2 * N];

static int apply_all(const mfree_approximant_t *a, int k, results_t *r) {
  double u[N], v[2 * N];
  field(X, k, u);
  for (int p = 0; p < N; ++p) v[2 * p] = u[p], v[2 * p + 1] = 0.5 * u[p] * u[p];
  int bad = 0;
  bad |= mfree_approximant_apply(a, MFREE_OP_VALUE, 1, u, MFREE_LAYOUT_AOS, 1, r->value,
                                 MFREE_LAYOUT_AOS, 1) != MFREE_SUCCESS;
  bad |= mfree_approximant_apply(a, MFREE_OP_GRADIENT, 1, u, MFREE_LAYOUT_SOA, N, r->grad,
                                 MFREE_LAYOUT_AOS, 2) != MFREE_SUCCESS;
  bad |= mfree_approximant_apply(a, MFREE_OP_LAPLACIAN, 1, u, MFREE_LAYOUT_AOS, 1, r->lap,
                                 MFREE_LAYOUT_AOS, 1) != MFREE_SUCCESS;
  bad |= mfree_approximant_apply(a, MFREE_OP_DIVERGENCE, 2, v, MFREE_LAYOUT_AOS, 2, r->div,
                                 MFREE_LAYOUT_AOS, 1) != MFREE_SUCCESS;
  for (int p = 0; p < N; ++p) r->acc[p] = 1.0;
  bad |= mfree_approximant_apply_add(a, MFREE_OP_VALUE, 1, u, MFREE_LAYOUT_AOS, 1, r->acc,
                                     MFREE_LAYOUT_AOS, 1) != MFREE_SUCCESS;
  return bad;
}

static results_t ref_shared[NTHREADS * NFIELDS];

typedef struct {
  int id;
  int mismatches, errors;
} job_t;

static void *shared_worker(void *arg) {
  job_t *job = arg;
  results_t *r = malloc(sizeof *r);
  for (int rep = 0; rep < REPEAT; ++rep)
    for (int f = 0; f < NFIELDS; ++f) {
      const int k = job->id * NFIELDS + f;
      job->errors += apply_all(shared_a, k + 1, r);
      job->mismatches += memcmp(r, &ref_shared[k], sizeof *r) != 0;
    }
  free(r);
  return NULL;
}

static void test_shared_approximant(void **state) {
  (void)state;
  lattice(X, 62);
  const double h = 1.6 * SP, vol = SP * SP;
  mfree_particles_t *ps = NULL;
  assert_ok(NULL, mfree_context_create(&shared_ctx));
  assert_ok(shared_ctx, mfree_particles_create(shared_ctx, 2, N, &ps));
  assert_ok(shared_ctx, mfree_particles_set_positions(ps, X, MFREE_LAYOUT_AOS, 2, MFREE_BORROW));
  assert_ok(shared_ctx, mfree_particles_set_support(ps, &h, 0, MFREE_COPY));
  assert_ok(shared_ctx, mfree_particles_set_volumes(ps, &vol, 0, MFREE_COPY));
  assert_ok(shared_ctx, mfree_approximant_create(shared_ctx, ps, MFREE_METHOD_MLS, &shared_a));
  assert_ok(shared_ctx, mfree_approximant_set_order(shared_a, 2));
  assert_ok(shared_ctx, mfree_approximant_set_derivatives(
                            shared_a, MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT | MFREE_DERIV_HESSIAN));
  assert_ok(shared_ctx, mfree_approximant_setup(shared_a));
  mfree_particles_destroy(&ps); /* the approximant keeps it alive */

  for (int k = 0; k < NTHREADS * NFIELDS; ++k)
    assert_int_equal(apply_all(shared_a, k + 1, &ref_shared[k]), 0);
  /* the references differ from field to field (so equality below means something) */
  assert_true(memcmp(&ref_shared[0], &ref_shared[1], sizeof ref_shared[0]) != 0);

  pthread_t th[NTHREADS];
  job_t jobs[NTHREADS];
  for (int t = 0; t < NTHREADS; ++t) {
    jobs[t] = (job_t){t, 0, 0};
    assert_int_equal(pthread_create(&th[t], NULL, shared_worker, &jobs[t]), 0);
  }
  for (int t = 0; t < NTHREADS; ++t) assert_int_equal(pthread_join(th[t], NULL), 0);
  for (int t = 0; t < NTHREADS; ++t) {
    assert_int_equal(jobs[t].errors, 0);
    assert_int_equal(jobs[t].mismatches, 0);
  }
  mfree_status_t code = MFREE_ERR_INTERNAL;
  assert_ok(shared_ctx, mfree_context_get_last_error(shared_ctx, &code, NULL, 0));
  assert_int_equal(code, MFREE_SUCCESS); /* successful calls leave the context alone */
  mfree_approximant_destroy(&shared_a);
  mfree_context_destroy(&shared_ctx);
}

/* ---- 2. independent objects on independent contexts ------------------------------- */

typedef struct {
  double grad[2 * N];
  double kvals[160 * N];
  int64_t knnz;
  double ydot[5 * N];
} build_t;

static const mfree_method_t METHOD_OF[NTHREADS] = {MFREE_METHOD_RKPM, MFREE_METHOD_SSPH,
                                                  MFREE_METHOD_KB_METHOD1,
                                                  MFREE_METHOD_RANDLES_LIBERSKY};

/* Everything from scratch on a fresh context; returns the number of failed calls. */
static int build_everything(int id, build_t *out) {
  int bad = 0;
  double x[2 * N], u[N], m[N], y[5 * N];
  lattice(x, 100 + (uint64_t)id);
  field(x, id + 1, u);
  const double h = 1.5 * SP, vol = SP * SP, rho0 = 1000.0;
  mfree_context_t *ctx = NULL;
  mfree_particles_t *ps = NULL;
  mfree_approximant_t *a = NULL, *g = NULL;
  mfree_assembler_t *as = NULL;
  mfree_matrix_t *K = NULL;
  mfree_system_t *sys = NULL;
  bad += mfree_context_create(&ctx) != MFREE_SUCCESS;
  bad += mfree_particles_create(ctx, 2, N, &ps) != MFREE_SUCCESS;
  bad += mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 2, MFREE_COPY) != MFREE_SUCCESS;
  bad += mfree_particles_set_support(ps, &h, 0, MFREE_COPY) != MFREE_SUCCESS;
  bad += mfree_particles_set_volumes(ps, &vol, 0, MFREE_COPY) != MFREE_SUCCESS;
  bad += mfree_approximant_create(ctx, ps, METHOD_OF[id], &a) != MFREE_SUCCESS;
  bad += mfree_approximant_setup(a) != MFREE_SUCCESS;
  bad += mfree_approximant_apply(a, MFREE_OP_GRADIENT, 1, u, MFREE_LAYOUT_AOS, 1, out->grad,
                                 MFREE_LAYOUT_AOS, 2) != MFREE_SUCCESS;
  /* a Galerkin Laplace matrix with MLS functions */
  bad += mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, &g) != MFREE_SUCCESS;
  bad += mfree_assembler_create(ctx, g, NULL, MFREE_FORM_LAPLACE, &as) != MFREE_SUCCESS;
  bad += mfree_assembler_setup(as) != MFREE_SUCCESS;
  bad += mfree_assembler_assemble_matrix(as, &K) != MFREE_SUCCESS;
  int32_t nr = 0, nc = 0;
  const int64_t *rp = NULL;
  const int32_t *ci = NULL;
  const double *va = NULL;
  bad += mfree_matrix_get_size(K, &nr, &nc, &out->knnz) != MFREE_SUCCESS;
  bad += mfree_matrix_get_csr(K, &rp, &ci, &va) != MFREE_SUCCESS;
  if (va && out->knnz <= 160 * N) memcpy(out->kvals, va, (size_t)out->knnz * sizeof(double));
  else bad++;
  /* a fluid right-hand side */
  for (int p = 0; p < N; ++p) {
    y[2 * p] = x[2 * p], y[2 * p + 1] = x[2 * p + 1];
    y[2 * N + 2 * p] = 0.01 * u[p], y[2 * N + 2 * p + 1] = -0.02 * u[p];
    y[4 * N + p] = rho0 * (1.0 + 0.001 * u[p]);
    m[p] = rho0 * vol;
  }
  bad += mfree_system_create_fluid(ctx, 2, N, &sys) != MFREE_SUCCESS;
  bad += mfree_system_set_fluid(sys, &rho0, 0, 1.0e4, 7.0, 1.0e-3) != MFREE_SUCCESS;
  bad += mfree_system_set_masses(sys, m, 1) != MFREE_SUCCESS;
  bad += mfree_system_set_smoothing(sys, h) != MFREE_SUCCESS;
  bad += mfree_system_rhs(sys, 0.0, y, out->ydot) != MFREE_SUCCESS;
  mfree_system_destroy(&sys);
  mfree_matrix_destroy(&K);
  mfree_assembler_destroy(&as);
  mfree_approximant_destroy(&g);
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
  mfree_context_destroy(&ctx);
  return bad;
}

static build_t ref_build[NTHREADS], par_build[NTHREADS];

static void *build_worker(void *arg) {
  job_t *job = arg;
  job->errors = build_everything(job->id, &par_build[job->id]);
  return NULL;
}

static void test_independent_objects(void **state) {
  (void)state;
  for (int t = 0; t < NTHREADS; ++t) assert_int_equal(build_everything(t, &ref_build[t]), 0);
  pthread_t th[NTHREADS];
  job_t jobs[NTHREADS];
  for (int t = 0; t < NTHREADS; ++t) {
    jobs[t] = (job_t){t, 0, 0};
    assert_int_equal(pthread_create(&th[t], NULL, build_worker, &jobs[t]), 0);
  }
  for (int t = 0; t < NTHREADS; ++t) assert_int_equal(pthread_join(th[t], NULL), 0);
  for (int t = 0; t < NTHREADS; ++t) {
    assert_int_equal(jobs[t].errors, 0);
    assert_int_equal(par_build[t].knnz, ref_build[t].knnz);
    assert_memory_equal(par_build[t].grad, ref_build[t].grad, sizeof ref_build[t].grad);
    assert_memory_equal(par_build[t].kvals, ref_build[t].kvals,
                        (size_t)ref_build[t].knnz * sizeof(double));
    assert_memory_equal(par_build[t].ydot, ref_build[t].ydot, sizeof ref_build[t].ydot);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_shared_approximant),
      cmocka_unit_test(test_independent_objects),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
