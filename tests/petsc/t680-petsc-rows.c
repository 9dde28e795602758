/* t680 (mpirun -np 1..4): the rows of the owned nodes that libmfree_petsc puts into the
 * distributed matrix are bitwise equal to the rows of the one-rank assembly (the whole
 * cloud on one rank, global id = index), matched by global id, and so are the loads;
 * for paper 000's cantilever beam (MLS 1, nodal quadrature; and background Gauss cells
 * with penalty conditions) and a 3D block (background cells), on slab, recursive
 * bisection and random decompositions with the local particles in shuffled order. A
 * second assembly refills the matrix without a single new allocation. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pktest.h"

static int rank_, size_;

typedef struct {
  int64_t key;
  double v;
} entry_t;

static int by_key(const void *a, const void *b) {
  const int64_t x = ((const entry_t *)a)->key, y = ((const entry_t *)b)->key;
  return x < y ? -1 : x > y;
}

/* Entries of A's owned rows that differ in their bits from the one-rank rows. */
static int64_t compare_rows(const pk_problem_t *p, const pk_local_t *l, mfree_petsc_t *pk, const mfree_matrix_t *K1,
                            const double *f1) {
  const int nc = p->dim;
  Mat A = NULL;
  Vec b = NULL;
  assert_int_equal(mfree_petsc_get_objects(pk, &A, NULL, &b, NULL), MFREE_SUCCESS);
  int64_t first = 0, nglob = 0;
  int64_t *rows = malloc(sizeof(int64_t) * (size_t)(l->nlocal ? l->nlocal : 1));
  assert_int_equal(mfree_petsc_get_numbering(pk, &first, &nglob, rows), MFREE_SUCCESS);
  assert_int_equal(nglob, (int64_t)p->n * nc);
  /* PETSc node -> global id over the local nodes */
  entry_t *map = malloc(sizeof(entry_t) * (size_t)(l->nlocal ? l->nlocal : 1));
  for (int32_t k = 0; k < l->nlocal; ++k) map[k].key = rows[k], map[k].v = (double)l->gid[k];
  qsort(map, (size_t)l->nlocal, sizeof *map, by_key);
  const int64_t *rp = NULL;
  const int32_t *ci = NULL;
  const double *v1 = NULL;
  assert_int_equal(mfree_matrix_get_csr(K1, &rp, &ci, &v1), MFREE_SUCCESS);
  const PetscScalar *bb = NULL;
  VecGetArrayRead(b, &bb);
  int64_t bad = 0;
  entry_t *row = NULL;
  size_t cap = 0;
  for (int32_t a = 0; a < l->nowned; ++a)
    for (int c = 0; c < nc; ++c) {
      const PetscInt r = (PetscInt)(first + a * nc + c);
      assert_int_equal(rows[a] * nc + c, r);
      PetscInt ncols = 0;
      const PetscInt *cols = NULL;
      const PetscScalar *vals = NULL;
      MatGetRow(A, r, &ncols, &cols, &vals);
      if ((size_t)ncols > cap) cap = (size_t)ncols, row = realloc(row, sizeof(entry_t) * cap);
      for (PetscInt k = 0; k < ncols; ++k) {
        entry_t key = {cols[k] / nc, 0.0};
        const entry_t *m = bsearch(&key, map, (size_t)l->nlocal, sizeof *map, by_key);
        assert_non_null(m);
        row[k].key = (int64_t)m->v * nc + cols[k] % nc;
        row[k].v = vals[k];
      }
      const PetscInt len = ncols; /* MatRestoreRow zeroes ncols */
      MatRestoreRow(A, r, &ncols, &cols, &vals);
      qsort(row, (size_t)len, sizeof *row, by_key);
      const int64_t g = l->gid[a] * nc + c;
      assert_true(len > 0);
      if (rp[g + 1] - rp[g] != len) {
        bad += len;
        continue;
      }
      for (PetscInt k = 0; k < len; ++k) {
        const int64_t e = rp[g] + k;
        if (ci[e] != row[k].key || memcmp(&v1[e], &row[k].v, sizeof(double)) != 0) ++bad;
      }
      if (memcmp(&bb[a * nc + c], &f1[g], sizeof(double)) != 0) ++bad;
    }
  VecRestoreArrayRead(b, &bb);
  free(row), free(map), free(rows);
  return bad;
}

static double mallocs(mfree_petsc_t *pk) {
  Mat A = NULL;
  mfree_petsc_get_objects(pk, &A, NULL, NULL, NULL);
  MatInfo info;
  MatGetInfo(A, MAT_GLOBAL_SUM, &info);
  return info.mallocs;
}

static void run(pk_problem_t *p, const char *name) {
  mfree_context_t *ctx = NULL;
  assert_int_equal(mfree_context_create(&ctx), MFREE_SUCCESS);
  /* the one-rank rows, on every rank */
  pk_local_t l1;
  pk_system_t s1;
  pk_local_all(p, &l1);
  assert_ok(ctx, pk_system(ctx, p, &l1, &s1));
  mfree_matrix_t *K1 = NULL;
  assert_ok(ctx, mfree_assembler_assemble_matrix(s1.as, &K1));
  double *f1 = malloc(sizeof(double) * (size_t)p->n * (size_t)p->dim);
  assert_ok(ctx, mfree_assembler_assemble_rhs(s1.as, f1));
  int *part = malloc(sizeof(int) * (size_t)p->n);
  const int hows[3] = {PK_SLAB, PK_BISECT, PK_RANDOM};
  const char *hname[3] = {"slab", "bisection", "random"};
  for (int h = 0; h < 3; ++h) {
    pk_partition(p, hows[h], size_, 7, part);
    pk_local_t l;
    pk_system_t s;
    pk_local(p, part, rank_, 1234 + (uint64_t)rank_, &l);
    assert_ok(ctx, pk_system(ctx, p, &l, &s));
    mfree_petsc_t *pk = NULL;
    assert_ok(ctx, mfree_petsc_create(ctx, PETSC_COMM_WORLD, &pk));
    assert_ok(ctx, mfree_petsc_setup(pk, s.as, p->dim, l.nlocal, l.nowned, l.gid));
    const double m0 = mallocs(pk);
    int64_t bad = compare_rows(p, &l, pk, K1, f1), all = 0;
    /* new values on the same pattern (another Young's modulus) on both sides */
    assert_ok(ctx, mfree_assembler_set_material(s.as, 2.0 * p->E, p->nu));
    assert_ok(ctx, mfree_assembler_set_material(s1.as, 2.0 * p->E, p->nu));
    mfree_matrix_t *K2 = NULL;
    double *f2 = malloc(sizeof(double) * (size_t)p->n * (size_t)p->dim);
    assert_ok(ctx, mfree_assembler_assemble_matrix(s1.as, &K2));
    assert_ok(ctx, mfree_assembler_assemble_rhs(s1.as, f2));
    assert_ok(ctx, mfree_petsc_assemble(pk));
    bad += compare_rows(p, &l, pk, K2, f2);
    assert_ok(ctx, mfree_assembler_set_material(s1.as, p->E, p->nu));
    mfree_matrix_destroy(&K2);
    free(f2);
    const double m1 = mallocs(pk);
    MPI_Allreduce(&bad, &all, 1, MPI_INT64_T, MPI_SUM, PETSC_COMM_WORLD);
    if (rank_ == 0)
      print_message("%s, %s on %d ranks: %lld entries differ from one rank (mallocs %g, %g)\n", name, hname[h],
                    size_, (long long)all, m0, m1);
    assert_int_equal(all, 0);
    assert_true(m0 == 0.0 && m1 == 0.0);
    mfree_petsc_destroy(&pk);
    pk_system_free(&s);
    pk_local_free(&l);
  }
  free(part), free(f1);
  mfree_matrix_destroy(&K1);
  pk_system_free(&s1);
  pk_local_free(&l1);
  mfree_context_destroy(&ctx);
}

static void beam_nodal(void **state) {
  (void)state;
  pk_problem_t p;
  pk_problem_beam(&p, 25, 7, PK_NODAL);
  run(&p, "beam, nodal quadrature");
  pk_problem_free(&p);
}

static void beam_gauss(void **state) {
  (void)state;
  pk_problem_t p;
  pk_problem_beam(&p, 25, 7, PK_GAUSS);
  run(&p, "beam, Gauss cells and penalty");
  pk_problem_free(&p);
}

static void block(void **state) {
  (void)state;
  pk_problem_t p;
  pk_problem_block(&p, 9, 5, 5);
  run(&p, "3D block, Gauss cells");
  pk_problem_free(&p);
}

int main(int argc, char **argv) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(beam_nodal),
      cmocka_unit_test(beam_gauss),
      cmocka_unit_test(block),
  };
  return pk_main(&argc, &argv, tests, sizeof tests / sizeof tests[0], &rank_, &size_);
}
