/* Faults on 1-4 ranks (label mpi): every rank returns the documented status and a
 * message, and no rank waits for ever (the CTest timeout bounds it):
 *  - one rank asks for a 4D plan: MFREE_ERR_ARG on every rank, naming that rank;
 *  - one rank's setup fails (a NaN position: MFREE_ERR_INPUT; a negative width:
 *    MFREE_ERR_ARG): every rank returns that status with "rank R: <its reason>", the
 *    plan is not set up (get/exchange: MFREE_ERR_STATE) and a correct setup recovers;
 *  - a rank without particles takes part; global ids from some ranks only:
 *    MFREE_ERR_ARG everywhere;
 *  - a global id given to particles of two ranks (of one rank on one rank):
 *    MFREE_ERR_INPUT everywhere, the message names the id;
 *  - ranks that disagree on an argument that must be common (the dimension at create,
 *    the width at setup, ncomp at exchange: another message size): MFREE_ERR_ARG
 *    everywhere, naming two ranks and their values; an exchange that fails on one rank
 *    (ld below ncomp, a NULL field) fails on every rank; no ghost item is written;
 *  - mfree_halo_exchange_correction: a method without correction records (SPH), ranks
 *    with different methods (other record lengths), an approximant on a set that is not
 *    the plan's on one rank, a NULL approximant on rank 0: every rank returns the status
 *    of the failing one with its message;
 *  - a halo too narrow for the supports: the particle set that declares the plan's width
 *    returns MFREE_ERR_HALO at setup on every rank, instead of rows that miss ghosts;
 *  - a plan destroyed after MPI_Finalize: its memory freed, no MPI call (no abort). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpitest.h"

static int rank = 0, size = 1;

/* The particle set of the plan (owned positions xo and supports ho given; ghosts
 * exchanged; volumes h^2), set up; the arrays it borrows are returned for freeing. */
static mfree_particles_t *plan_set(mfree_context_t *ctx, mfree_halo_t *halo, const double *xo, const double *ho,
                                   double **bufs) {
  int32_t n_owned = 0, n_ghost = 0;
  mfree_halo_get_size(halo, &n_owned, &n_ghost);
  const int nn = n_owned + n_ghost;
  double *xx = malloc(sizeof(double) * (size_t)(2 * nn + 2)), *hh = malloc(sizeof(double) * (size_t)(nn + 1));
  double *vv = malloc(sizeof(double) * (size_t)(nn + 1));
  int64_t *gid = malloc(sizeof(int64_t) * (size_t)(nn + 1));
  if (n_owned) {
    memcpy(xx, xo, sizeof(double) * 2 * (size_t)n_owned);
    memcpy(hh, ho, sizeof(double) * (size_t)n_owned);
  }
  mfree_halo_exchange(halo, 2, xx, 2);
  mfree_halo_exchange(halo, 1, hh, 1);
  mfree_halo_get_global_ids(halo, gid);
  for (int i = 0; i < nn; ++i) vv[i] = hh[i] * hh[i];
  mfree_particles_t *set = NULL;
  mfree_particles_create(ctx, 2, nn, &set);
  mfree_particles_set_num_ghost(set, n_ghost);
  mfree_particles_set_positions(set, xx, MFREE_LAYOUT_AOS, 2, MFREE_BORROW);
  mfree_particles_set_support(set, hh, 1, MFREE_BORROW);
  mfree_particles_set_volumes(set, vv, 1, MFREE_BORROW);
  mfree_particles_set_global_ids(set, gid, MFREE_BORROW);
  CHECK(mfree_particles_setup(set) == MFREE_SUCCESS, "set of the plan");
  bufs[0] = xx;
  bufs[1] = hh;
  bufs[2] = vv;
  bufs[3] = (double *)gid;
  return set;
}

static mfree_approximant_t *approximant(mfree_context_t *ctx, mfree_particles_t *ps, int method) {
  mfree_approximant_t *a = NULL;
  mfree_approximant_create(ctx, ps, method, &a);
  mfree_approximant_set_derivatives(a, MFREE_DERIV_GRADIENT);
  CHECK(mfree_approximant_setup(a) == MFREE_SUCCESS, "approximant %d", method);
  return a;
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const int last = size - 1;
  char who[32];
  snprintf(who, sizeof who, "rank %d:", last);
  mfree_context_t *ctx = NULL;
  mfree_context_create(&ctx);

  /* a bad argument on one rank at create */
  mfree_halo_t *halo = NULL;
  expect(ctx, mfree_halo_create(ctx, MPI_COMM_WORLD, rank == last ? 4 : 2, &halo), MFREE_ERR_ARG, who,
         "create, dim 4 on the last rank");
  CHECK(halo == NULL, "no plan after a failed create");
  if (size > 1) {
    expect(ctx, mfree_halo_create(ctx, MPI_COMM_WORLD, rank == last ? 3 : 2, &halo), MFREE_ERR_ARG,
           "ranks disagree on the dimension: rank 0 passes 2, rank", "create, dim 3 on the last rank only");
    CHECK(halo == NULL, "no plan after a disagreement");
  }
  CHECK(mfree_halo_create(ctx, MPI_COMM_WORLD, 2, &halo) == MFREE_SUCCESS, "create");

  cloud_t c;
  cloud_make(&c, 2, 16, 3);
  int *part = malloc(sizeof(int) * (size_t)c.n);
  decompose(&c, DECOMP_SLAB, MPI_COMM_WORLD, part);
  int no = 0;
  double *xo = malloc(sizeof(double) * (size_t)c.n * 2);
  int64_t *io = malloc(sizeof(int64_t) * (size_t)c.n);
  double *ho = malloc(sizeof(double) * (size_t)c.n);
  for (int i = 0; i < c.n; ++i)
    if (part[i] == rank) {
      xo[2 * no] = c.x[2 * i];
      xo[2 * no + 1] = c.x[2 * i + 1];
      io[no] = c.id[i];
      ho[no++] = c.h[i];
    }
  const double width = KAPPA * cloud_max_support(&c);

  /* one rank's setup fails: a NaN position, then a negative width */
  const double keep = xo[1];
  if (rank == last) xo[1] = NAN;
  expect(ctx, mfree_halo_setup(halo, no, xo, 2, io, width), MFREE_ERR_INPUT, "position of particle 0",
         "NaN position on the last rank");
  xo[1] = keep;
  char msg[600] = "";
  mfree_context_get_last_error(ctx, NULL, msg, sizeof msg);
  CHECK(strstr(msg, who) != NULL, "the message names the failing rank: %s", msg);
  int32_t n_owned = 0, n_ghost = 0;
  expect(ctx, mfree_halo_get_size(halo, &n_owned, &n_ghost), MFREE_ERR_STATE, "not set up", "size after failure");
  double u[4] = {0, 0, 0, 0};
  expect(ctx, mfree_halo_exchange(halo, 1, u, 1), MFREE_ERR_STATE, "not set up", "exchange after failure");
  expect(ctx, mfree_halo_setup(halo, no, xo, 2, io, rank == last ? -1.0 : width), MFREE_ERR_ARG, who,
         "negative width on the last rank");
  expect(ctx, mfree_halo_setup(halo, rank == 0 ? -5 : no, xo, 2, io, width), MFREE_ERR_ARG, "rank 0:",
         "negative count on rank 0");
  CHECK(mfree_halo_setup(halo, no, xo, 2, io, width) == MFREE_SUCCESS, "recovery");
  /* a rank without particles (NULL positions and ids) takes part and gets no ghosts */
  CHECK(mfree_halo_setup(halo, rank == last ? 0 : no, rank == last ? NULL : xo, 2, rank == last ? NULL : io,
                         width) == MFREE_SUCCESS,
        "a rank without particles");
  mfree_halo_get_size(halo, &n_owned, &n_ghost);
  CHECK(rank != last || (n_owned == 0 && n_ghost == 0), "the empty rank holds nothing");
  /* ids on some ranks only (the last gives none): MFREE_ERR_ARG everywhere */
  if (size > 1)
    expect(ctx, mfree_halo_setup(halo, no, xo, 2, rank == last ? NULL : io, width), MFREE_ERR_ARG,
           "all ranks with particles or none", "ids on some ranks only");
  /* a width of its own on the last rank (e.g. kappa times its own largest support) */
  if (size > 1)
    expect(ctx, mfree_halo_setup(halo, no, xo, 2, io, rank == last ? 1.5 * width : width), MFREE_ERR_ARG,
           "ranks disagree on the halo width", "a width of its own on the last rank");

  /* the same global id on two ranks (on one rank: twice on it) */
  const int64_t dup = c.id[0]; /* owned by rank 0 in the slab split */
  const int64_t keep_id = no > 1 ? io[1] : 0;
  if (rank == last && no > 1) io[1] = dup;
  char needle[64];
  snprintf(needle, sizeof needle, "global id %lld", (long long)dup);
  expect(ctx, mfree_halo_setup(halo, no, xo, 2, io, width), MFREE_ERR_INPUT, needle, "duplicate id");
  if (rank == last && no > 1) io[1] = keep_id;
  io[0] = -7;
  expect(ctx, mfree_halo_setup(halo, no, xo, 2, io, width), MFREE_ERR_INPUT, "must be >= 0", "negative id");
  for (int i = 0, k = 0; i < c.n; ++i)
    if (part[i] == rank) io[k++] = c.id[i];
  CHECK(mfree_halo_setup(halo, no, xo, 2, io, width) == MFREE_SUCCESS, "recovery after ids");

  /* exchanges that fail on one rank, or whose ranks disagree on ncomp: every rank
   * returns, nothing is written into the ghost items, and the next exchange works */
  {
    mfree_halo_get_size(halo, &n_owned, &n_ghost);
    const int nall = n_owned + n_ghost;
    double *f = malloc(sizeof(double) * (size_t)(2 * nall + 2));
    for (int i = 0; i < 2 * nall; ++i) f[i] = i < 2 * n_owned ? xo[i] : -1.0;
    if (size > 1)
      expect(ctx, mfree_halo_exchange(halo, rank == last ? 2 : 1, f, 2), MFREE_ERR_ARG,
             "ranks disagree on ncomp", "ncomp 2 on the last rank, 1 elsewhere");
    expect(ctx, mfree_halo_exchange(halo, 2, f, rank == last ? 1 : 2), MFREE_ERR_ARG, who,
           "ld below ncomp on the last rank");
    /* (rank 0 owns particles in the slab split) */
    expect(ctx, mfree_halo_exchange(halo, 2, rank == 0 ? NULL : f, 2), MFREE_ERR_NULL, "rank 0: field is NULL",
           "NULL field on rank 0");
    int untouched = 1;
    for (int i = 2 * n_owned; i < 2 * nall; ++i) untouched = untouched && f[i] == -1.0;
    CHECK(untouched, "no ghost item written by a failed exchange");
    CHECK(mfree_halo_exchange(halo, 2, f, 2) == MFREE_SUCCESS, "an exchange after the faults");
    int64_t *gid = malloc(sizeof(int64_t) * (size_t)(nall + 1));
    mfree_halo_get_global_ids(halo, gid);
    int exact = 1;
    for (int g = n_owned; g < nall; ++g) {
      const int64_t k = (gid[g] - 5) / 2; /* cloud ids are 5 + 2 i */
      exact = exact && f[2 * g] == c.x[2 * k] && f[2 * g + 1] == c.x[2 * k + 1];
    }
    CHECK(exact, "ghost positions are their owners' after the faults");
    free(gid);
    free(f);
  }

  /* a halo too narrow: the plan holds the ghosts within half the supports' reach; the
   * set that declares that width refuses to build rows */
  const double narrow = 0.5 * width;
  CHECK(mfree_halo_setup(halo, no, xo, 2, io, narrow) == MFREE_SUCCESS, "narrow plan");
  mfree_halo_get_size(halo, &n_owned, &n_ghost);
  const int n = n_owned + n_ghost;
  double *x = malloc(sizeof(double) * (size_t)(2 * n + 2)), *h = malloc(sizeof(double) * (size_t)(n + 1));
  int64_t *ids = malloc(sizeof(int64_t) * (size_t)(n + 1));
  memcpy(x, xo, sizeof(double) * 2 * (size_t)no);
  memcpy(h, ho, sizeof(double) * (size_t)no);
  mfree_halo_exchange(halo, 2, x, 2);
  mfree_halo_exchange(halo, 1, h, 1);
  mfree_halo_get_global_ids(halo, ids);
  mfree_particles_t *ps = NULL;
  mfree_particles_create(ctx, 2, n, &ps);
  mfree_particles_set_num_ghost(ps, n_ghost);
  mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 2, MFREE_BORROW);
  mfree_particles_set_support(ps, h, 1, MFREE_BORROW);
  mfree_particles_set_global_ids(ps, ids, MFREE_BORROW);
  mfree_particles_set_halo_width(ps, narrow);
  expect(ctx, mfree_particles_setup(ps), MFREE_ERR_HALO, "reaches past the declared halo width",
         "particle setup on a narrow halo");
  mfree_particles_set_halo_width(ps, width);  /* an honest width passes the set's check */
  CHECK(mfree_halo_setup(halo, no, xo, 2, io, width) == MFREE_SUCCESS, "wide plan");
  mfree_particles_destroy(&ps);
  free(x);
  free(h);
  free(ids);

  /* the ghosts' correction records (mfree_halo_exchange_correction): faults agreed */
  {
    double *bufs[4];
    mfree_particles_t *set = plan_set(ctx, halo, xo, ho, bufs), *other = NULL;
    int32_t nn = 0;
    mfree_particles_get_size(set, &nn, NULL);
    /* the same particles, every one owned: not the plan's layout where there are ghosts */
    mfree_particles_create(ctx, 2, nn, &other);
    mfree_particles_set_positions(other, bufs[0], MFREE_LAYOUT_AOS, 2, MFREE_BORROW);
    mfree_particles_set_support(other, bufs[1], 1, MFREE_BORROW);
    mfree_particles_set_volumes(other, bufs[2], 1, MFREE_BORROW);
    CHECK(mfree_particles_setup(other) == MFREE_SUCCESS, "set without ghosts");
    mfree_approximant_t *rl = approximant(ctx, set, MFREE_METHOD_RANDLES_LIBERSKY);
    mfree_approximant_t *sph = approximant(ctx, set, MFREE_METHOD_SPH);
    mfree_approximant_t *mls = approximant(ctx, set, MFREE_METHOD_MLS);
    mfree_approximant_t *rl_other = approximant(ctx, other, MFREE_METHOD_RANDLES_LIBERSKY);
    CHECK(mfree_halo_exchange_correction(halo, rl) == MFREE_SUCCESS, "RL records");
    expect(ctx, mfree_halo_exchange_correction(halo, sph), MFREE_ERR_UNSUPPORTED, "rank 0:",
           "SPH has no correction records");
    if (size > 1)
      expect(ctx, mfree_halo_exchange_correction(halo, rank == last ? mls : rl), MFREE_ERR_ARG,
             "ranks disagree on ncomp", "MLS on the last rank, RL elsewhere");
    /* (with more than one rank the last rank has ghosts: a set without them is not the plan's) */
    if (size > 1)
      expect(ctx, mfree_halo_exchange_correction(halo, rank == last ? rl_other : rl), MFREE_ERR_ARG, who,
             "a set that is not the plan's on the last rank");
    expect(ctx, mfree_halo_exchange_correction(halo, rank == 0 ? NULL : rl), MFREE_ERR_NULL,
           "rank 0: approximant is NULL", "NULL approximant on rank 0");
    CHECK(mfree_halo_exchange_correction(halo, rl) == MFREE_SUCCESS, "RL records again");
    mfree_approximant_destroy(&rl);
    mfree_approximant_destroy(&sph);
    mfree_approximant_destroy(&mls);
    mfree_approximant_destroy(&rl_other);
    mfree_particles_destroy(&set);
    mfree_particles_destroy(&other);
    for (int k = 0; k < 4; ++k) free(bufs[k]);
    /* a rank without particles takes part */
    CHECK(mfree_halo_setup(halo, rank == last ? 0 : no, rank == last ? NULL : xo, 2, rank == last ? NULL : io,
                           width) == MFREE_SUCCESS,
          "plan with an empty rank");
    set = plan_set(ctx, halo, xo, ho, bufs);
    rl = approximant(ctx, set, MFREE_METHOD_RANDLES_LIBERSKY);
    CHECK(mfree_halo_exchange_correction(halo, rl) == MFREE_SUCCESS, "RL records with an empty rank");
    mfree_approximant_destroy(&rl);
    mfree_particles_destroy(&set);
    for (int k = 0; k < 4; ++k) free(bufs[k]);
  }

  free(xo);
  free(io);
  free(ho);
  free(part);
  cloud_free(&c);
  mfree_halo_destroy(&halo);

  /* A plan set up (so with its neighbourhood graph) and destroyed after MPI_Finalize,
   * as a host's late clean-up does: only its memory is freed, no MPI call is made. */
  mfree_halo_t *late = NULL;
  const double xl[2] = {(double)rank, 0.0};
  CHECK(mfree_halo_create(ctx, MPI_COMM_WORLD, 2, &late) == MFREE_SUCCESS &&
            mfree_halo_setup(late, 1, xl, 2, NULL, 1.5) == MFREE_SUCCESS,
        "the plan destroyed after MPI_Finalize");
  mfree_context_destroy(&ctx); /* the plan keeps the context alive */
  int rc = mpitest_finish("t161-mpi-faults");
  MPI_Finalize();
  if (mfree_halo_destroy(&late) != MFREE_SUCCESS || late) {
    fprintf(stderr, "t161-mpi-faults: rank %d: mfree_halo_destroy after MPI_Finalize failed\n", rank);
    rc = 1;
  }
  return rc;
}
