/* t682 (mpirun -np 1..3): faults of libmfree_petsc. A bad argument or a failed setup on
 * one rank makes every rank return the same documented status (the failing rank's
 * message there, "rank R failed: ..." on the others) without a hang (the test's timeout
 * bounds it), and a failed call changes nothing: the previous setup still solves.
 * Coordinates for the near null space on some ranks only: every rank refuses the setup. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pktest.h"

static int rank_, size_;

/* Every rank got `expected` from the call; the message names the failing rank `who`
 * on the others and contains `needle` on that rank. */
static void expect_all(mfree_context_t *ctx, mfree_status_t got, mfree_status_t expected, int who,
                       const char *needle, const char *what) {
  char msg[1024] = "";
  mfree_context_get_last_error(ctx, NULL, msg, sizeof msg);
  if (got != expected) fail_msg("%s: rank %d got %d, expected %d (%s)", what, rank_, (int)got, (int)expected, msg);
  if (rank_ == who) {
    if (needle && !strstr(msg, needle)) fail_msg("%s: message '%s' lacks '%s'", what, msg, needle);
  } else {
    char want[64];
    snprintf(want, sizeof want, "rank %d failed", who);
    if (!strstr(msg, want)) fail_msg("%s: message '%s' lacks '%s'", what, msg, want);
  }
  int bad = got != expected, any = 0;
  MPI_Allreduce(&bad, &any, 1, MPI_INT, MPI_MAX, PETSC_COMM_WORLD);
  assert_int_equal(any, 0);
}

static pk_problem_t prob;
static int *part;

static void faults(void **state) {
  (void)state;
  mfree_context_t *ctx = NULL;
  assert_int_equal(mfree_context_create(&ctx), MFREE_SUCCESS);
  pk_local_t l;
  pk_system_t s;
  pk_local(&prob, part, rank_, 5, &l);
  assert_ok(ctx, pk_system(ctx, &prob, &l, &s));
  const int last = size_ - 1;
  mfree_petsc_t *pk = (mfree_petsc_t *)&l;

  /* create: arguments (not collective) */
  assert_int_equal(mfree_petsc_create(NULL, PETSC_COMM_WORLD, &pk), MFREE_ERR_NULL);
  assert_error(ctx, mfree_petsc_create(ctx, PETSC_COMM_WORLD, NULL), MFREE_ERR_NULL, "NULL");
  assert_error(ctx, mfree_petsc_create(ctx, MPI_COMM_NULL, &pk), MFREE_ERR_ARG, "MPI_COMM_NULL");
  assert_null(pk);
  assert_ok(ctx, mfree_petsc_create(ctx, PETSC_COMM_WORLD, &pk));

  /* before setup: every collective call refuses on every rank */
  expect_all(ctx, mfree_petsc_solve(pk, NULL), MFREE_ERR_STATE, 0, "not set up", "solve before setup");
  expect_all(ctx, mfree_petsc_assemble(pk), MFREE_ERR_STATE, 0, "not set up", "assemble before setup");
  expect_all(ctx, mfree_petsc_set_dirichlet(pk, 0, NULL, NULL), MFREE_ERR_STATE, 0, "not set up",
             "dirichlet before setup");
  assert_error(ctx, mfree_petsc_get_numbering(pk, NULL, NULL, NULL), MFREE_ERR_STATE, "not set up");
  assert_error(ctx, mfree_petsc_get_objects(pk, NULL, NULL, NULL, NULL), MFREE_ERR_STATE, "not set up");

  /* local setters */
  assert_error(ctx, mfree_petsc_set_options_prefix(pk, "-x"), MFREE_ERR_ARG, "prefix");
  assert_error(ctx, mfree_petsc_set_options_prefix(pk, "9a"), MFREE_ERR_ARG, "prefix");
  assert_error(ctx, mfree_petsc_set_coordinates(pk, 4, l.nowned, s.x), MFREE_ERR_ARG, "dim");
  assert_error(ctx, mfree_petsc_set_coordinates(pk, 2, -1, s.x), MFREE_ERR_ARG, "negative");
  if (l.nowned > 0) {
    assert_error(ctx, mfree_petsc_set_coordinates(pk, 2, l.nowned, NULL), MFREE_ERR_NULL, "NULL");
    const double nanx[2] = {NAN, 0.0};
    assert_error(ctx, mfree_petsc_set_coordinates(pk, 2, 1, nanx), MFREE_ERR_INPUT, "not finite");
  }

  /* one rank fails its setup (its assembler was never set up) */
  mfree_assembler_t *raw = NULL;
  assert_ok(ctx, mfree_assembler_create(ctx, s.ap, NULL, MFREE_FORM_ELASTICITY_PLANE_STRESS, &raw));
  expect_all(ctx, mfree_petsc_setup(pk, rank_ == last ? raw : s.as, 2, l.nlocal, l.nowned, l.gid), MFREE_ERR_STATE,
             last, "not set up", "one rank's assembler not set up");
  mfree_assembler_destroy(&raw);
  /* bad arguments on one rank */
  expect_all(ctx, mfree_petsc_setup(pk, rank_ == 0 ? NULL : s.as, 2, l.nlocal, l.nowned, l.gid), MFREE_ERR_NULL, 0,
             "NULL", "NULL assembler on rank 0");
  expect_all(ctx, mfree_petsc_setup(pk, s.as, rank_ == last ? 5 : 2, l.nlocal, l.nowned, l.gid), MFREE_ERR_ARG,
             last, "ncomp", "ncomp 5 on the last rank");
  expect_all(ctx, mfree_petsc_setup(pk, s.as, rank_ == 0 ? 1 : 2, l.nlocal, l.nowned, l.gid), MFREE_ERR_MISMATCH, 0,
             "unknowns", "ncomp 1 on an elasticity assembler");
  expect_all(ctx, mfree_petsc_setup(pk, s.as, 2, l.nlocal, rank_ == last ? l.nlocal + 1 : l.nowned, l.gid),
             MFREE_ERR_ARG, last, "nowned", "nowned > nlocal");
  expect_all(ctx, mfree_petsc_setup(pk, s.as, 2, l.nlocal, l.nowned, rank_ == 0 ? NULL : l.gid), MFREE_ERR_NULL, 0,
             "NULL", "NULL ids");
  {
    int64_t *g = malloc(sizeof(int64_t) * (size_t)l.nlocal);
    memcpy(g, l.gid, sizeof(int64_t) * (size_t)l.nlocal);
    if (rank_ == last) g[0] = -3;
    expect_all(ctx, mfree_petsc_setup(pk, s.as, 2, l.nlocal, l.nowned, g), MFREE_ERR_INPUT, last, "-3",
               "negative id");
    memcpy(g, l.gid, sizeof(int64_t) * (size_t)l.nlocal);
    if (rank_ == last && l.nlocal > 1) g[1] = g[0];
    expect_all(ctx, mfree_petsc_setup(pk, s.as, 2, l.nlocal, l.nowned, g), MFREE_ERR_INPUT, last, "repeated",
               "an id twice on one rank");
    if (size_ > 1) {
      /* an owned id of rank 0 also owned by the last rank (where it is no neighbour) */
      memcpy(g, l.gid, sizeof(int64_t) * (size_t)l.nlocal);
      int64_t steal = -1;
      for (int32_t i = 0; i < prob.n && steal < 0; ++i) {
        if (part[i] != 0) continue;
        int local = 0;
        for (int32_t k = 0; k < l.nlocal && rank_ == last; ++k) local |= l.gid[k] == i;
        if (!local) steal = i;
      }
      MPI_Bcast(&steal, 1, MPI_INT64_T, last, PETSC_COMM_WORLD);
      assert_true(steal >= 0);
      if (rank_ == last) g[0] = steal;
      const mfree_status_t st = mfree_petsc_setup(pk, s.as, 2, l.nlocal, l.nowned, g);
      /* the mapping keeps one of the two owners, and the last rank's own id is now owned
       * by no one: some rank reports one or the other, every rank returns the status */
      char msg[1024] = "";
      mfree_context_get_last_error(ctx, NULL, msg, sizeof msg);
      assert_int_equal(st, MFREE_ERR_INPUT);
      assert_true(strstr(msg, "owned by another rank") || strstr(msg, "owned by no rank"));
      /* a ghost whose id no rank owns */
      memcpy(g, l.gid, sizeof(int64_t) * (size_t)l.nlocal);
      if (rank_ == 0 && l.nlocal > l.nowned) g[l.nowned] = prob.n + 5;
      int has = rank_ == 0 && l.nlocal > l.nowned;
      MPI_Bcast(&has, 1, MPI_INT, 0, PETSC_COMM_WORLD);
      if (has)
        expect_all(ctx, mfree_petsc_setup(pk, s.as, 2, l.nlocal, l.nowned, g), MFREE_ERR_INPUT, 0, "owned by no rank",
                   "ghost id without owner");
    }
    free(g);
  }
  /* a bad option value: every rank reads the same database */
  assert_ok(ctx, mfree_petsc_set_options_prefix(pk, "t682bad_"));
  PetscOptionsSetValue(NULL, "-t682bad_ksp_type", "no_such_krylov_method");
  {
    const mfree_status_t st = mfree_petsc_setup(pk, s.as, 2, l.nlocal, l.nowned, l.gid);
    assert_int_equal(st, MFREE_ERR_ARG);
  }
  PetscOptionsClearValue(NULL, "-t682bad_ksp_type");
  assert_error(ctx, mfree_petsc_get_objects(pk, NULL, NULL, NULL, NULL), MFREE_ERR_STATE, "not set up");

  /* coordinates of another node count */
  {
    double *c = calloc(2 * (size_t)(l.nowned + 1), sizeof(double));
    assert_ok(ctx, mfree_petsc_set_coordinates(pk, 2, l.nowned + 1, c));
    free(c);
  }
  expect_all(ctx, mfree_petsc_setup(pk, s.as, 2, l.nlocal, l.nowned, l.gid), MFREE_ERR_MISMATCH, 0, "coordinates",
             "coordinates of other nodes");
  assert_ok(ctx, mfree_petsc_set_coordinates(pk, 2, l.nowned, s.x));

  /* coordinates on rank 0 only, while every rank owns nodes: the near null space is
   * built on every rank or on none, so every rank refuses, naming one without them */
  if (size_ > 1) {
    mfree_petsc_t *pk2 = NULL;
    assert_ok(ctx, mfree_petsc_create(ctx, PETSC_COMM_WORLD, &pk2));
    if (rank_ == 0) assert_ok(ctx, mfree_petsc_set_coordinates(pk2, 2, l.nowned, s.x));
    const mfree_status_t st = mfree_petsc_setup(pk2, s.as, 2, l.nlocal, l.nowned, l.gid);
    char msg[1024] = "";
    mfree_context_get_last_error(ctx, NULL, msg, sizeof msg);
    assert_int_equal(st, MFREE_ERR_ARG);
    if (!strstr(msg, "rank 1 owns nodes but gave no coordinates") || !strstr(msg, "rank 0 gave them"))
      fail_msg("coordinates on rank 0 only: message '%s'", msg);
    assert_ok(ctx, mfree_petsc_destroy(&pk2));
  }

  /* a good setup, then failures that change nothing */
  assert_ok(ctx, mfree_petsc_set_options_prefix(pk, "t682_"));
  assert_ok(ctx, mfree_petsc_setup(pk, s.as, 2, l.nlocal, l.nowned, l.gid));
  int32_t nd = 0, *dofs = NULL;
  double *vals = NULL;
  pk_dirichlet(&prob, &l, &nd, &dofs, &vals);
  assert_ok(ctx, mfree_petsc_set_dirichlet(pk, nd, dofs, vals));
  double *u0 = malloc(sizeof(double) * 2 * (size_t)(l.nowned + 1)), *u1 = malloc(sizeof(double) * 2 * (size_t)(l.nowned + 1));
  assert_ok(ctx, mfree_petsc_solve(pk, u0));
  {
    const int32_t badd = rank_ == last ? l.nowned * 2 : 0;
    const double one = 1.0, nan = NAN;
    expect_all(ctx, mfree_petsc_set_dirichlet(pk, 1, &badd, &one), MFREE_ERR_INPUT, last, "not an unknown of an owned node", "Dirichlet dof out of range");
    expect_all(ctx, mfree_petsc_set_dirichlet(pk, rank_ == 0 ? -1 : 0, NULL, NULL), MFREE_ERR_ARG, 0, "negative",
               "negative count");
    const int32_t d0 = 0;
    if (l.nowned > 0 || rank_ != last)
      expect_all(ctx, mfree_petsc_set_dirichlet(pk, rank_ == last ? 1 : 0, &d0, &nan), MFREE_ERR_INPUT, last,
                 "not finite", "NaN value");
    int32_t two[2] = {0, 0};
    if (l.nowned > 0 || rank_ != 0)
      expect_all(ctx, mfree_petsc_set_dirichlet(pk, rank_ == 0 ? 2 : 0, two, vals), MFREE_ERR_INPUT, 0, "repeated",
                 "a dof twice");
  }
  assert_ok(ctx, mfree_petsc_solve(pk, u1));
  for (int32_t k = 0; k < 2 * l.nowned; ++k) assert_true(memcmp(&u0[k], &u1[k], sizeof(double)) == 0);

  /* the solver stopped at its iteration limit: MFREE_FAIL_SINGULAR on every rank */
  PetscOptionsSetValue(NULL, "-t682_ksp_max_it", "1");
  assert_ok(ctx, mfree_petsc_setup(pk, s.as, 2, l.nlocal, l.nowned, l.gid));
  assert_status(ctx, mfree_petsc_solve(pk, u1), MFREE_FAIL_SINGULAR);
  int32_t reason = 0, its = 0;
  assert_ok(ctx, mfree_petsc_get_info(pk, &its, NULL, &reason));
  assert_true(reason < 0);
  assert_int_equal(its, 1);
  PetscOptionsClearValue(NULL, "-t682_ksp_max_it");
  assert_int_equal(mfree_petsc_get_info(NULL, NULL, NULL, NULL), MFREE_ERR_NULL);
  assert_int_equal(mfree_petsc_solve(NULL, NULL), MFREE_ERR_NULL);
  assert_int_equal(mfree_petsc_setup(NULL, s.as, 2, 0, 0, NULL), MFREE_ERR_NULL);

  free(dofs), free(vals), free(u0), free(u1);
  assert_ok(ctx, mfree_petsc_destroy(&pk));
  assert_null(pk);
  assert_ok(ctx, mfree_petsc_destroy(&pk));
  assert_ok(ctx, mfree_petsc_destroy(NULL));
  pk_system_free(&s);
  pk_local_free(&l);
  mfree_context_destroy(&ctx);
}

int main(int argc, char **argv) {
  /* before PetscInitialize: create refuses */
  {
    MPI_Init(&argc, &argv);
    mfree_context_t *ctx = NULL;
    mfree_petsc_t *pk = NULL;
    if (mfree_context_create(&ctx) != MFREE_SUCCESS) return 1;
    if (mfree_petsc_create(ctx, MPI_COMM_WORLD, &pk) != MFREE_ERR_STATE || pk) return 1;
    mfree_context_destroy(&ctx);
  }
  if (PetscInitialize(&argc, &argv, NULL, NULL)) return 1;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank_);
  MPI_Comm_size(PETSC_COMM_WORLD, &size_);
  pk_problem_beam(&prob, 13, 4, PK_NODAL);
  part = malloc(sizeof(int) * (size_t)prob.n);
  pk_partition(&prob, PK_SLAB, size_, 0, part);
  const struct CMUnitTest tests[] = {cmocka_unit_test(faults)};
  const int rc = cmocka_run_group_tests(tests, NULL, NULL);
  free(part);
  pk_problem_free(&prob);
  PetscFinalize();
  MPI_Finalize();
  return rc;
}
