/* The fluid's matrices on ranks (label mpi), on the dam break of paper 003 (12 x 24
 * particles) at rest and moving (a state the one-process fluid reaches by leap-frog, its
 * particles up to several spacings from where the ghost layers were built, so that the
 * ranks rebuild their ghosts inside the calls), on 1-4 ranks for horizontal layers,
 * owners by a hash of the id and slabs listed in reverse order:
 * - mfree_system_apply_mass with the consistent mass (003 eq 42: rows coupling owned
 *   particles to ghosts, v's velocities exchanged) and the lumped mass: every owned
 *   particle's five products, matched by global id, bitwise those of one rank and of the
 *   one-process fluid (whose matrix from mfree_system_assemble_mass gives the same
 *   products, bitwise), for two vectors v on the mass kept from the first;
 * - an oracle independent of the numbering: the linear MLS functions sum to one at every
 *   point, so the consistent mass times a uniform velocity is the lumped mass times it
 *   (each row's sum, 003 eq 56) to rounding, and the total is the particles' mass;
 * - mfree_system_assemble_interpolation: the owned rows, columns the rank's items named
 *   by the halo's global ids, every entry (row id, column id, value) bitwise the
 *   one-process fluid's S_kj = N_j(x_k), and each row summing to one to rounding;
 * - faults: a NULL v, Mv or y on one rank, a non-finite state on one rank: every rank
 *   returns the same status and none waits; afterwards the same calls work again. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpifluid.h"
#include "mpitest.h"

/* A vector of the system's layout for n particles: distinct values of both signs. */
static void test_vector(int n, int seed, double *v) {
  for (int q = 0; q < 5 * n; ++q) v[q] = sin(0.37 * q + seed) + 0.25 * cos(1.3 * seed * q);
}

/* The owned part (positions, velocities, densities of the owned items, in their order)
   of a full vector of n particles. */
static void owned_part(const rankfluid_t *r, int n, const double *full, double *own) {
  const size_t no = (size_t)r->n_owned;
  for (int k = 0; k < r->n_owned; ++k) {
    const int64_t q = r->id[k];
    memcpy(own + 2 * k, full + 2 * q, 2 * sizeof(double));
    memcpy(own + 2 * no + 2 * k, full + 2 * (size_t)n + 2 * q, 2 * sizeof(double));
    own[4 * no + k] = full[4 * (size_t)n + q];
  }
}

/* (row id, column id, value) of every entry of every rank's S, gathered on every rank in
   the order of (row id, column id). ids: the rank's items' global ids. Returns the count. */
typedef struct {
  int64_t row, col;
  double val;
} entry_t;
static int by_ids(const void *a, const void *b) {
  const entry_t *x = a, *y = b;
  if (x->row != y->row) return x->row < y->row ? -1 : 1;
  return x->col < y->col ? -1 : x->col > y->col;
}
static int gather_entries(MPI_Comm comm, const mfree_matrix_t *S, const int64_t *row_id, const int64_t *col_id,
                          entry_t **out) {
  int32_t nr = 0, nc = 0;
  int64_t nnz = 0;
  const int64_t *ptr = NULL;
  const int32_t *idx = NULL;
  const double *val = NULL;
  CHECK(mfree_matrix_get_size(S, &nr, &nc, &nnz) == MFREE_SUCCESS && mfree_matrix_get_csr(S, &ptr, &idx, &val) ==
                                                                       MFREE_SUCCESS,
        "S's CSR");
  double *mine = malloc(3 * ((size_t)nnz + 1) * sizeof *mine);
  for (int32_t i = 0; i < nr; ++i)
    for (int64_t e = ptr[i]; e < ptr[i + 1]; ++e) {
      const double r = (double)row_id[i], c = (double)col_id[idx[e]];
      mine[3 * e] = r, mine[3 * e + 1] = c, mine[3 * e + 2] = val[e];
    }
  int size = 1, cnt = (int)(3 * nnz), total = 0;
  MPI_Comm_size(comm, &size);
  int *counts = malloc(sizeof(int) * (size_t)size), *displs = malloc(sizeof(int) * (size_t)size);
  MPI_Allgather(&cnt, 1, MPI_INT, counts, 1, MPI_INT, comm);
  for (int p = 0; p < size; ++p) displs[p] = total, total += counts[p];
  double *all = malloc(((size_t)total + 1) * sizeof *all);
  MPI_Allgatherv(mine, cnt, MPI_DOUBLE, all, counts, displs, MPI_DOUBLE, comm);
  const int ne = total / 3;
  entry_t *e = malloc(((size_t)ne + 1) * sizeof *e);
  for (int k = 0; k < ne; ++k) e[k].row = (int64_t)all[3 * k], e[k].col = (int64_t)all[3 * k + 1], e[k].val = all[3 * k + 2];
  qsort(e, (size_t)ne, sizeof *e, by_ids);
  free(mine), free(counts), free(displs), free(all);
  *out = e;
  return ne;
}

int main(int argc, char **argv) {
  int rank = 0, size = 1;
  mfree_context_t *ctx = mpitest_start(&argc, &argv, &rank, &size);
  damb_t b;
  damb_make(&b, 12, 24);
  const int n = b.n;
  const size_t N5 = 5 * (size_t)n;
  double *y1 = malloc(N5 * sizeof *y1), *v1 = malloc(N5 * sizeof *v1), *v2 = malloc(N5 * sizeof *v2),
         *ones = malloc(N5 * sizeof *ones);
  test_vector(n, 1, v1);
  test_vector(n, 2, v2);
  for (size_t q = 0; q < N5; ++q) ones[q] = 1.0;

  /* the one-process fluid (global id = index): the moving state, the reference products
     and the interpolation matrix, on every rank alike */
  mfree_system_t *one = NULL;
  CHECK(mfree_system_create_fluid(ctx, 2, n, &one) == MFREE_SUCCESS && damb_configure(&b, one) == MFREE_SUCCESS &&
            mfree_system_set_masses(one, b.m, 1) == MFREE_SUCCESS,
        "one-process fluid: %s", mpifluid_error(ctx));
  memcpy(y1, b.y, N5 * sizeof *y1);
  double t = 0.0;
  int64_t steps = 0;
  CHECK(mfree_system_integrate(one, MFREE_INTEGRATOR_LEAPFROG, y1, &t, 0.05, 0.5, 0.0, NULL, NULL, &steps) ==
            MFREE_SUCCESS,
        "leap-frog: %s", mpifluid_error(ctx));
  double dmax = 0.0;
  for (int q = 0; q < n; ++q) dmax = fmax(dmax, hypot(y1[2 * q] - b.y[2 * q], y1[2 * q + 1] - b.y[2 * q + 1]));
  /* the layer of 4 h + 4 d is rebuilt when a particle has moved 2 d */
  CHECK(dmax > 2.5 * b.d, "the state has moved %.3g spacings only", dmax / b.d);
  const double *states[2] = {b.y, y1};
  double *ref[2][3], *lumped[2];
  entry_t *sref[2];
  int nsref[2];
  for (int s = 0; s < 2; ++s) {
    for (int k = 0; k < 3; ++k) ref[s][k] = malloc(N5 * sizeof(double));
    lumped[s] = malloc(N5 * sizeof(double));
    CHECK(mfree_system_apply_mass(one, states[s], 1, v1, ref[s][0]) == MFREE_SUCCESS &&
              mfree_system_apply_mass(one, states[s], 1, v2, ref[s][1]) == MFREE_SUCCESS &&
              mfree_system_apply_mass(one, states[s], 0, v1, ref[s][2]) == MFREE_SUCCESS,
          "one-process products: %s", mpifluid_error(ctx));
    /* the products are those of the assembled matrix */
    mfree_matrix_t *M = NULL;
    double *w = malloc(N5 * sizeof *w);
    CHECK(mfree_system_assemble_mass(one, states[s], 1, &M) == MFREE_SUCCESS &&
              mfree_matrix_apply(M, v2, w) == MFREE_SUCCESS,
          "assembled consistent mass: %s", mpifluid_error(ctx));
    CHECK(memcmp(w, ref[s][1], N5 * sizeof *w) == 0, "state %d: apply_mass differs from the assembled matrix's product", s);
    /* oracle: M_C 1 = M_L 1 (row sums), total the particles' mass */
    double *c1 = malloc(N5 * sizeof *c1);
    CHECK(mfree_system_apply_mass(one, states[s], 1, ones, c1) == MFREE_SUCCESS &&
              mfree_system_apply_mass(one, states[s], 0, ones, lumped[s]) == MFREE_SUCCESS,
          "products of ones: %s", mpifluid_error(ctx));
    double worst = 0.0, total = 0.0, mtot = 0.0;
    for (int q = 0; q < n; ++q) {
      for (int c = 0; c < 2; ++c) {
        const size_t k = 2 * (size_t)n + 2 * q + c;
        worst = fmax(worst, fabs(c1[k] - lumped[s][k]) / lumped[s][k]);
      }
      total += c1[2 * (size_t)n + 2 * q];
      mtot += b.m[q];
    }
    CHECK(worst < 1e-12, "state %d: consistent row sums differ from the lumped masses by %.3g", s, worst);
    CHECK(fabs(total - mtot) < 1e-12 * mtot, "state %d: consistent mass total %.17g, particles %.17g", s, total, mtot);
    mfree_matrix_t *S = NULL;
    CHECK(mfree_system_assemble_interpolation(one, states[s], &S) == MFREE_SUCCESS, "one-process S: %s",
          mpifluid_error(ctx));
    int64_t *iota = malloc(((size_t)n + 1) * sizeof *iota);
    for (int q = 0; q < n; ++q) iota[q] = q;
    nsref[s] = gather_entries(MPI_COMM_SELF, S, iota, iota, &sref[s]);
    double rowsum_err = 0.0, acc = 0.0;
    for (int k = 0; k < nsref[s]; ++k) {
      acc += sref[s][k].val;
      if (k + 1 == nsref[s] || sref[s][k + 1].row != sref[s][k].row) rowsum_err = fmax(rowsum_err, fabs(acc - 1.0)), acc = 0.0;
    }
    CHECK(rowsum_err < 1e-12, "state %d: an interpolation row sums to 1 + %.3g", s, rowsum_err);
    free(iota), free(c1), free(w);
    mfree_matrix_destroy(&M);
    mfree_matrix_destroy(&S);
  }

  int *owner = malloc((size_t)n * sizeof *owner);
  double *got = malloc(N5 * sizeof *got);
  static const char *names[3] = {"layers", "hashed", "reversed slabs"};
  int rebuilt = 0;
  for (int how = 0; how < 3; ++how) {
    for (int i = 0; i < n; ++i) {
      int p = (int)(b.y[2 * i + 1] / (2.0 * b.a) * size);
      p = p < 0 ? 0 : p >= size ? size - 1 : p;
      owner[i] = how == 1 ? (int)(mpitest_hash((uint64_t)i) % (uint64_t)size) : p;
    }
    rankfluid_t r;
    const mfree_status_t st = rankfluid_make(&r, ctx, MPI_COMM_WORLD, &b, owner, 4.0 * b.h + 4.0 * b.d, how == 2);
    CHECK(st == MFREE_SUCCESS, "%s: system: %s", names[how], mpifluid_error(ctx));
    if (st != MFREE_SUCCESS) continue;
    const size_t no5 = 5 * (size_t)r.n_owned + 1;
    double *yo = malloc(no5 * sizeof *yo), *vo = malloc(no5 * sizeof *vo), *mo = malloc(no5 * sizeof *mo);
    for (int s = 0; s < 2; ++s) {
      owned_part(&r, n, states[s], yo);
      for (int k = 0; k < 3; ++k) {
        owned_part(&r, n, k == 1 ? v2 : v1, vo);
        const mfree_status_t sm = mfree_system_apply_mass(r.sys, yo, k == 2 ? 0 : 1, vo, mo);
        CHECK(sm == MFREE_SUCCESS, "%s, state %d, product %d: status %d: %s", names[how], s, k, (int)sm,
              mpifluid_error(ctx));
        mpifluid_state(MPI_COMM_WORLD, &r, mo, n, got);
        int bad = 0;
        for (int q = 0; q < n; ++q)
          bad += memcmp(got + 2 * q, ref[s][k] + 2 * q, 16) ||
                 memcmp(got + 2 * (size_t)n + 2 * q, ref[s][k] + 2 * (size_t)n + 2 * q, 16) ||
                 memcmp(got + 4 * (size_t)n + q, ref[s][k] + 4 * (size_t)n + q, 8);
        CHECK(bad == 0, "%s, state %d, %s product %d: %d of %d particles differ from the one-process fluid's",
              names[how], s, k == 2 ? "lumped" : "consistent", k, bad, n);
      }
      /* the interpolation matrix's owned rows, columns named by the halo's ids (after the
         rebuilds the calls above made) */
      int32_t n_owned = 0, n_ghost = 0;
      CHECK(mfree_halo_get_size(r.halo, &n_owned, &n_ghost) == MFREE_SUCCESS && n_owned == r.n_owned, "halo size");
      int64_t *ids = malloc(((size_t)n_owned + n_ghost + 1) * sizeof *ids);
      CHECK(mfree_halo_get_global_ids(r.halo, ids) == MFREE_SUCCESS, "halo ids");
      if (s == 1 && (n_ghost != r.n_ghost || memcmp(ids + n_owned, r.id + n_owned, (size_t)n_ghost * sizeof *ids)))
        rebuilt = 1;
      mfree_matrix_t *S = NULL;
      const mfree_status_t si = mfree_system_assemble_interpolation(r.sys, yo, &S);
      CHECK(si == MFREE_SUCCESS, "%s, state %d: interpolation status %d: %s", names[how], s, (int)si,
            mpifluid_error(ctx));
      int32_t nr = -1, nc = -1;
      int64_t nnz = 0;
      mfree_matrix_get_size(S, &nr, &nc, &nnz);
      CHECK(nr == n_owned && nc == n_owned + n_ghost, "%s: S is %d x %d, %d owned and %d ghosts", names[how], (int)nr,
            (int)nc, (int)n_owned, (int)n_ghost);
      entry_t *e = NULL;
      const int ne = gather_entries(MPI_COMM_WORLD, S, ids, ids, &e);
      int same = ne == nsref[s];
      for (int k = 0; same && k < ne; ++k)
        same = e[k].row == sref[s][k].row && e[k].col == sref[s][k].col && memcmp(&e[k].val, &sref[s][k].val, 8) == 0;
      CHECK(same, "%s, state %d: the interpolation matrix (%d entries) differs from the one-process fluid's (%d)",
            names[how], s, ne, nsref[s]);
      free(e), free(ids);
      mfree_matrix_destroy(&S);
    }

    /* faults on the last rank: every rank returns the same status, then works again */
    const int last = rank == size - 1;
    owned_part(&r, n, y1, yo);
    owned_part(&r, n, v1, vo);
    mfree_status_t f = mfree_system_apply_mass(r.sys, yo, 1, last ? NULL : vo, mo);
    CHECK(f == MFREE_ERR_NULL, "%s: a NULL v on rank %d: status %d", names[how], size - 1, (int)f);
    CHECK(strstr(mpifluid_error(ctx), "NULL") != NULL, "message: %s", mpifluid_error(ctx));
    f = mfree_system_apply_mass(r.sys, last ? NULL : yo, 1, vo, mo);
    CHECK(f == MFREE_ERR_NULL, "%s: a NULL y on rank %d: status %d", names[how], size - 1, (int)f);
    f = mfree_system_apply_mass(r.sys, yo, 0, vo, last ? NULL : mo);
    CHECK(f == MFREE_ERR_NULL, "%s: a NULL Mv on rank %d: status %d", names[how], size - 1, (int)f);
    mfree_matrix_t *S = NULL;
    f = mfree_system_assemble_interpolation(r.sys, last ? NULL : yo, &S);
    CHECK(f == MFREE_ERR_NULL && !S, "%s: a NULL state for S on rank %d: status %d", names[how], size - 1, (int)f);
    const double keep = yo[0];
    if (last && r.n_owned > 0) yo[0] = NAN;
    f = mfree_system_apply_mass(r.sys, yo, 1, vo, mo);
    const int any = size > 1 || r.n_owned > 0;
    CHECK(!any || f == MFREE_FAIL_NONFINITE, "%s: a NaN position on rank %d: status %d", names[how], size - 1, (int)f);
    CHECK(!any || strstr(mpifluid_error(ctx), "non-finite") != NULL, "message: %s", mpifluid_error(ctx));
    f = mfree_system_assemble_interpolation(r.sys, yo, &S);
    CHECK(!any || (f == MFREE_FAIL_NONFINITE && !S), "%s: S at a NaN position: status %d", names[how], (int)f);
    yo[0] = keep;
    f = mfree_system_apply_mass(r.sys, yo, 1, vo, mo);
    CHECK(f == MFREE_SUCCESS, "%s: after the faults: status %d: %s", names[how], (int)f, mpifluid_error(ctx));
    mpifluid_state(MPI_COMM_WORLD, &r, mo, n, got);
    CHECK(memcmp(got + 2 * (size_t)n, ref[1][0] + 2 * (size_t)n, 2 * (size_t)n * sizeof(double)) == 0,
          "%s: the product after the faults differs", names[how]);
    free(yo), free(vo), free(mo);
    rankfluid_free(&r);
  }
  int any_rebuilt = 0;
  MPI_Allreduce(&rebuilt, &any_rebuilt, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  CHECK(size == 1 || any_rebuilt, "no rank rebuilt its ghosts for the moving state");
  if (rank == 0)
    printf("t155: consistent and lumped mass products and S on %d ranks, at rest and after %ld steps (%.2f spacings)\n",
           size, (long)steps, dmax / b.d);
  for (int s = 0; s < 2; ++s) {
    for (int k = 0; k < 3; ++k) free(ref[s][k]);
    free(lumped[s]), free(sref[s]);
  }
  free(owner), free(got), free(y1), free(v1), free(v2), free(ones);
  mfree_system_destroy(&one);
  damb_free(&b);
  mfree_context_destroy(&ctx);
  const int rc = mpitest_finish("t155-mpi-fluid-matrices");
  MPI_Finalize();
  return rc;
}
