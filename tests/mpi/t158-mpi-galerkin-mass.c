/* The consistent mass of Galerkin elastodynamics on ranks (label mpi): the bar of paper
 * 001 Sect. 6.4 by t704's Galerkin discretisation (t169's), its left end free and held by
 * a node row, on 1-3 ranks for slabs, slabs in reverse rank order, owners by a hash of
 * the id and everything on the last rank:
 * - mfree_system_apply_mass with the consistent mass (its owned rows couple owned
 *   particles to ghosts: v's velocities exchanged): every particle's two products,
 *   matched by global id, bitwise those of one rank and of the one-process system
 *   (mfree_system_create_elastodynamic_galerkin with an MFREE_FORM_MASS assembler on the
 *   same points), for two vectors v on the mass built at the first product; the lumped
 *   mass (consistent = 0) bitwise the one-process lumped system's;
 * - an oracle independent of the numbering: the linear MLS functions sum to one at every
 *   point, so on the free bar the consistent mass times a uniform velocity is the lumped
 *   mass times it (each row's sum) to rounding, while for a varying v the two differ;
 * - faults: a NULL v, Mv or y on one rank makes every rank return MFREE_ERR_NULL naming
 *   that rank; mfree_system_assemble_mass refuses the consistent mass on ranks
 *   (MFREE_ERR_UNSUPPORTED, naming its products); afterwards the product works again. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpibar.h"
#include "mpitest.h"

enum { N = 120 };

/* A velocity-sized test vector by global id: distinct values of both signs. */
static double test_value(int64_t q, int seed) { return sin(0.37 * (double)q + seed) + 0.25 * cos(1.3 * seed * (double)q); }

/* The products M v for v = test vectors 1 and 2 (2 N values each, by global id), and
   M_C 1, M_L 1 on the velocities (N each) */
typedef struct {
  double mc[2][2 * N], ml[2 * N], ones_c[N], ones_l[N];
} products_t;

static void by_rank(mfree_context_t *ctx, MPI_Comm comm, int how, int kind, products_t *p) {
  mpibar_t b;
  CHECK(mpibar_make_kind(&b, ctx, comm, N, how, kind) == MFREE_SUCCESS, "bar %d, decomposition %d", kind, how);
  const int no = b.n_owned, neq = 2 * no;
  double *y = calloc((size_t)neq + 1, sizeof(double)), *v = calloc((size_t)neq + 1, sizeof(double)),
         *mv = calloc((size_t)neq + 1, sizeof(double));
  for (int s = 0; s < 2; ++s) {
    for (int i = 0; i < no; ++i) {
      v[i] = test_value(b.id[i], s + 1);
      v[no + i] = test_value(N + b.id[i], s + 1);
    }
    CHECK(mfree_system_apply_mass(b.sys, y, 1, v, mv) == MFREE_SUCCESS, "consistent product %d", s);
    mpibar_collect(&b, mv, 1, p->mc[s]);
    mpibar_collect(&b, mv + no, 1, p->mc[s] + N);
    if (s == 0) {
      CHECK(mfree_system_apply_mass(b.sys, y, 0, v, mv) == MFREE_SUCCESS, "lumped product");
      mpibar_collect(&b, mv, 1, p->ml);
      mpibar_collect(&b, mv + no, 1, p->ml + N);
    }
  }
  for (int q = 0; q < neq; ++q) v[q] = 1.0;
  CHECK(mfree_system_apply_mass(b.sys, y, 1, v, mv) == MFREE_SUCCESS, "consistent product of ones");
  mpibar_collect(&b, mv + no, 1, p->ones_c);
  CHECK(mfree_system_apply_mass(b.sys, y, 0, v, mv) == MFREE_SUCCESS, "lumped product of ones");
  mpibar_collect(&b, mv + no, 1, p->ones_l);

  if (comm == MPI_COMM_WORLD && how == BAR_SLAB) {
    int size = 1, rank = 0;
    MPI_Comm_size(comm, &size);
    MPI_Comm_rank(comm, &rank);
    const int bad = size - 1, mine = rank == bad;
    expect_agreed(ctx, mfree_system_apply_mass(b.sys, y, 1, mine ? NULL : v, mv), MFREE_ERR_NULL, bad,
                  "y, v or Mv is NULL", "NULL v on the last rank");
    expect_agreed(ctx, mfree_system_apply_mass(b.sys, y, 1, v, mine ? NULL : mv), MFREE_ERR_NULL, bad,
                  "y, v or Mv is NULL", "NULL Mv on the last rank");
    expect_agreed(ctx, mfree_system_apply_mass(b.sys, mine ? NULL : y, 1, v, mv), MFREE_ERR_NULL, bad,
                  "y, v or Mv is NULL", "NULL y on the last rank");
    mfree_matrix_t *M = NULL;
    expect(ctx, mfree_system_assemble_mass(b.sys, y, 1, &M), MFREE_ERR_UNSUPPORTED, "mfree_system_apply_mass",
           "consistent mass matrix on ranks");
    CHECK(M == NULL, "no matrix made");
    CHECK(mfree_system_assemble_mass(b.sys, y, 0, &M) == MFREE_SUCCESS, "the lumped mass matrix");
    mfree_matrix_destroy(&M);
    CHECK(mfree_system_apply_mass(b.sys, y, 1, v, mv) == MFREE_SUCCESS, "the product after the faults");
  }
  free(y);
  free(v);
  free(mv);
  mpibar_free(&b);
}

/* The one-process system's products (consistent: an MFREE_FORM_MASS assembler; its mass
   is the assembler's whatever the flag) */
static void serial(mfree_context_t *ctx, int kind, mfree_form_t form, products_t *p) {
  serialbar_t sb;
  CHECK(serialbar_make_mass(&sb, ctx, N, kind, form) == MFREE_SUCCESS, "serial bar %d", kind);
  const int cons = form == MFREE_FORM_MASS;
  static double y[2 * N], v[2 * N], mv[2 * N];
  for (int s = 0; s < (cons ? 2 : 1); ++s) {
    for (int q = 0; q < 2 * N; ++q) v[q] = test_value(q, s + 1);
    CHECK(mfree_system_apply_mass(sb.sys, y, cons, v, cons ? p->mc[s] : p->ml) == MFREE_SUCCESS, "serial product");
  }
  for (int q = 0; q < 2 * N; ++q) v[q] = 1.0;
  CHECK(mfree_system_apply_mass(sb.sys, y, cons, v, mv) == MFREE_SUCCESS, "serial product of ones");
  memcpy(cons ? p->ones_c : p->ones_l, mv + N, sizeof(double) * N);
  serialbar_free(&sb);
}

int main(int argc, char **argv) {
  int rank = 0, size = 1;
  mfree_context_t *ctx = mpitest_start(&argc, &argv, &rank, &size);
  static products_t ser, one, p;
  for (int kind = BAR_GALERKIN; kind <= BAR_GALERKIN_FIXED; ++kind) {
    serial(ctx, kind, MFREE_FORM_MASS, &ser);
    serial(ctx, kind, MFREE_FORM_MASS_LUMPED, &ser);
    by_rank(ctx, MPI_COMM_SELF, BAR_SLAB, kind, &one);
    char what[160];
    snprintf(what, sizeof what, "bar %d, one rank vs one process, consistent", kind);
    mpitest_same_bits(one.mc[0], ser.mc[0], 2 * N, what);
    mpitest_same_bits(one.mc[1], ser.mc[1], 2 * N, what);
    snprintf(what, sizeof what, "bar %d, one rank vs one process, lumped", kind);
    mpitest_same_bits(one.ml, ser.ml, 2 * N, what);
    mpitest_same_bits(one.ones_l, ser.ones_l, N, what);
    /* the oracle: row sums; and the consistent mass is not the lumped one */
    double worst = 0.0, apart = 0.0, scale = 0.0;
    for (int i = 0; i < N; ++i) {
      scale = fmax(scale, fabs(one.ones_l[i]));
      if (kind == BAR_GALERKIN) worst = fmax(worst, fabs(one.ones_c[i] - one.ones_l[i]));
      apart = fmax(apart, fabs(one.mc[0][N + i] - one.ml[N + i]));
    }
    CHECK(worst <= 1e-13 * scale, "bar %d: M_C 1 - M_L 1 = %g (scale %g)", kind, worst, scale);
    CHECK(apart > 1e-3 * scale, "bar %d: M_C v and M_L v differ by %g only (scale %g)", kind, apart, scale);
    /* the displacement rows are the identity */
    for (int i = 0; i < N; ++i) CHECK(one.mc[0][i] == test_value(i, 1), "bar %d: displacement row %d", kind, i);
    for (int how = BAR_SLAB; how <= BAR_LAST; ++how) {
      by_rank(ctx, MPI_COMM_WORLD, how, kind, &p);
      snprintf(what, sizeof what, "bar %d, decomposition %d, consistent", kind, how);
      mpitest_same_bits(p.mc[0], one.mc[0], 2 * N, what);
      mpitest_same_bits(p.mc[1], one.mc[1], 2 * N, what);
      mpitest_same_bits(p.ones_c, one.ones_c, N, what);
      snprintf(what, sizeof what, "bar %d, decomposition %d, lumped", kind, how);
      mpitest_same_bits(p.ml, one.ml, 2 * N, what);
    }
    if (rank == 0)
      printf("t158: bar %d: consistent and lumped products bitwise one rank's and the one-process system's on %d "
             "ranks; |M_C v - M_L v| up to %.3e of %.3e\n",
             kind, size, apart, scale);
  }
  mfree_context_destroy(&ctx);
  const int rc = mpitest_finish("t158-mpi-galerkin-mass");
  MPI_Finalize();
  return rc;
}
