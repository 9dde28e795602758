/* Migration round trips on 1-4 ranks (label mpi): a jittered cloud starts on random
 * owners with positions, velocities, densities, supports, global ids and a tag in a host
 * struct (arbitrary bits: NaN payloads, subnormals, signed zeros) registered, and moves
 *  - to owners the host chooses (mfree_migration_set_owners), after a first execute with
 *    a capacity one short on rank 0: MFREE_ERR_ARG on every rank with the size needed,
 *    nothing moved, the plan kept;
 *  - to Zoltan RCB regions (rebalance), then, as the cloud spreads and drifts, to the
 *    kept regions (only the particles that left theirs move; a second call moves none),
 *    then to Zoltan HSFC regions;
 *  - back to the starting owners.
 * After each move every particle's fields are bitwise those of its id, every id is owned
 * exactly once, and after the partitions the counts are within 10 % of the mean. Then
 * the halo and the particle set are rebuilt over the migrated particles and the
 * Randles-Libersky gradient at the owned particles is bitwise that of one rank holding
 * the whole cloud (matched by global id). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "migstate.h"

static int rank = 0, size = 1;

static void expect_ok(mfree_context_t *ctx, mfree_status_t st, const char *what) {
  char msg[600] = "";
  mfree_context_get_last_error(ctx, NULL, msg, sizeof msg);
  CHECK(st == MFREE_SUCCESS, "%s: status %d (%s)", what, (int)st, msg);
}

/* The Randles-Libersky gradient of u = sin(3x) + y^2 x at the n owned particles of (x, ld
 * 3, h, ids) with ghosts from halo (rebuilt here), or of the whole set when halo is NULL. */
static double *gradient(mfree_context_t *ctx, mfree_halo_t *halo, int n, const double *x, const double *h,
                        const int64_t *id, double width) {
  int32_t no = n, ng = 0;
  if (halo) {
    expect_ok(ctx, mfree_halo_setup(halo, n, x, 3, id, width), "halo setup after the migration");
    mfree_halo_get_size(halo, &no, &ng);
  }
  const int nn = no + ng;
  double *xx = malloc(sizeof(double) * 3 * (size_t)(nn + 1)), *hh = malloc(sizeof(double) * (size_t)(nn + 1));
  double *vv = malloc(sizeof(double) * (size_t)(nn + 1)), *u = malloc(sizeof(double) * (size_t)(nn + 1));
  double *g = malloc(sizeof(double) * 2 * (size_t)(no + 1));
  int64_t *gid = malloc(sizeof(int64_t) * (size_t)(nn + 1));
  memcpy(xx, x, sizeof(double) * 3 * (size_t)no);
  memcpy(hh, h, sizeof(double) * (size_t)no);
  memcpy(gid, id, sizeof(int64_t) * (size_t)no);
  for (int i = 0; i < no; ++i) u[i] = sin(3 * xx[3 * i]) + xx[3 * i + 1] * xx[3 * i + 1] * xx[3 * i];
  if (halo) {
    expect_ok(ctx, mfree_halo_exchange(halo, 3, xx, 3), "exchange x");
    expect_ok(ctx, mfree_halo_exchange(halo, 1, hh, 1), "exchange h");
    expect_ok(ctx, mfree_halo_exchange(halo, 1, u, 1), "exchange u");
    mfree_halo_get_global_ids(halo, gid);
  }
  for (int i = 0; i < nn; ++i) vv[i] = hh[i] * hh[i];
  mfree_particles_t *ps = NULL;
  mfree_approximant_t *a = NULL;
  mfree_particles_create(ctx, 2, nn, &ps);
  mfree_particles_set_num_ghost(ps, ng);
  mfree_particles_set_positions(ps, xx, MFREE_LAYOUT_AOS, 3, MFREE_BORROW);
  mfree_particles_set_support(ps, hh, 1, MFREE_BORROW);
  mfree_particles_set_volumes(ps, vv, 1, MFREE_BORROW);
  mfree_particles_set_global_ids(ps, gid, MFREE_BORROW);
  if (halo) mfree_particles_set_halo_width(ps, width);
  expect_ok(ctx, mfree_particles_setup(ps), "particle set");
  mfree_approximant_create(ctx, ps, MFREE_METHOD_RANDLES_LIBERSKY, &a);
  mfree_approximant_set_derivatives(a, MFREE_DERIV_GRADIENT);
  expect_ok(ctx, mfree_approximant_setup(a), "approximant");
  expect_ok(ctx, mfree_approximant_apply(a, MFREE_OP_GRADIENT, 1, u, MFREE_LAYOUT_AOS, 1, g, MFREE_LAYOUT_AOS, 2),
            "gradient");
  mfree_approximant_destroy(&a);
  mfree_particles_destroy(&ps);
  free(xx);
  free(hh);
  free(vv);
  free(u);
  free(gid);
  return g;
}

int main(int argc, char **argv) {
  (void)argc, (void)argv;
  MPI_Init(&argc, &argv);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  cloud_t c;
  cloud_make(&c, 2, 24, 180);
  int *start = malloc(sizeof(int) * (size_t)c.n), *owners = malloc(sizeof(int) * (size_t)c.n);
  decompose(&c, DECOMP_RANDOM, MPI_COMM_WORLD, start);
  mig_state_t s;
  mig_state_init(&s, &c, start, rank, c.n, 0.0);
  mig_state_check(&s, &c, 0.0, "start");

  mfree_context_t *ctx = NULL;
  mfree_migration_t *m = NULL;
  mfree_context_create(&ctx);
  expect_ok(ctx, mfree_migration_create(ctx, MPI_COMM_WORLD, 2, &m), "create");
  expect_ok(ctx, mig_state_register(&s, m), "register");

  /* 1. owners chosen by the host; a capacity one short on rank 0 first */
  for (int k = 0; k < s.n; ++k) owners[k] = (int)(mpitest_hash((uint64_t)s.id[k] * 5 + 1) % (uint64_t)size);
  int32_t n_new = -1, n_owned = -1, cnt_new = -1;
  int64_t n_send = -1, n_recv = -1;
  expect_ok(ctx, mfree_migration_set_owners(m, s.n, owners, &n_new), "set_owners");
  expect_ok(ctx, mfree_migration_get_counts(m, &n_owned, &cnt_new, &n_send, &n_recv), "get_counts");
  CHECK(n_owned == s.n && cnt_new == n_new, "counts %d %d, expected %d %d", n_owned, cnt_new, s.n, n_new);
  {
    int64_t mv[2] = {n_send, n_recv}, tot[2] = {0, 0};
    MPI_Allreduce(mv, tot, 2, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
    CHECK(tot[0] == tot[1], "sent %lld, received %lld over the ranks", (long long)tot[0], (long long)tot[1]);
    CHECK(n_new == s.n - n_send + n_recv, "n_new %d != %d - %lld + %lld", n_new, s.n, (long long)n_send,
          (long long)n_recv);
  }
  int32_t *got = malloc(sizeof(int32_t) * (size_t)(s.n + 1));
  expect_ok(ctx, mfree_migration_get_owners(m, got, s.n), "get_owners");
  for (int k = 0; k < s.n; ++k) CHECK(got[k] == owners[k], "owner of particle %d: %d, expected %d", k, got[k], owners[k]);
  free(got);
  {
    char msg[600] = "";
    const mfree_status_t st = mfree_migration_execute(m, rank == 0 && n_new > 0 ? n_new - 1 : s.cap);
    mfree_context_get_last_error(ctx, NULL, msg, sizeof msg);
    int short0 = rank == 0 && n_new > 0, any = 0;
    MPI_Allreduce(&short0, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    if (any) {
      CHECK(st == MFREE_ERR_ARG, "short capacity: status %d, expected MFREE_ERR_ARG", (int)st);
      CHECK(strstr(msg, "rank 0: capacity") && strstr(msg, "owns after the migration"), "message '%s'", msg);
      mig_state_check(&s, &c, 0.0, "after the refused execute (nothing moved)");
      expect_ok(ctx, mfree_migration_execute(m, s.cap), "execute after growing");
    } else {
      expect_ok(ctx, st, "execute");
    }
  }
  s.n = n_new;
  for (int k = 0; k < s.n; ++k)
    CHECK(mpitest_hash((uint64_t)s.id[k] * 5 + 1) % (uint64_t)size == (uint64_t)rank, "id %lld on the wrong rank",
          (long long)s.id[k]);
  mig_state_check(&s, &c, 0.0, "host owners");
  CHECK(mfree_migration_execute(m, s.cap) == MFREE_ERR_STATE, "a plan executes once");

#ifdef MFREE_TEST_ZOLTAN
  /* 2. RCB regions, balanced */
  expect_ok(ctx, mfree_migration_partition(m, s.n, s.x, 3, 1, &n_new), "RCB partition");
  expect_ok(ctx, mfree_migration_execute(m, s.cap), "RCB execute");
  s.n = n_new;
  mig_state_check(&s, &c, 0.0, "RCB");
  double imb = mig_imbalance(&s);
  CHECK(imb <= 1.10, "RCB: the largest count is %.3f times the mean", imb);

  /* 3. the cloud spreads and drifts; particles leaving their region move, others stay */
  const double ts[3] = {0.2, 0.5, 1.0};
  for (int w = 0; w < 3; ++w) {
    mig_state_move(&s, &c, ts[w]);
    expect_ok(ctx, mfree_migration_partition(m, s.n, s.x, 3, 0, &n_new), "kept regions");
    expect_ok(ctx, mfree_migration_execute(m, s.cap), "kept regions execute");
    s.n = n_new;
    mig_state_check(&s, &c, ts[w], "kept regions");
    /* every particle is now in its rank's region: nothing moves */
    expect_ok(ctx, mfree_migration_partition(m, s.n, s.x, 3, 0, &n_new), "kept regions again");
    expect_ok(ctx, mfree_migration_get_counts(m, NULL, NULL, &n_send, &n_recv), "counts");
    CHECK(n_send == 0 && n_recv == 0 && n_new == s.n, "a second assignment moves %lld particles", (long long)n_send);
  }

  /* 4. HSFC regions, balanced, of the spread cloud */
  expect_ok(ctx, mfree_migration_set_partitioner(m, MFREE_PARTITIONER_HSFC, 1.05), "HSFC");
  expect_ok(ctx, mfree_migration_partition(m, s.n, s.x, 3, 1, &n_new), "HSFC partition");
  expect_ok(ctx, mfree_migration_execute(m, s.cap), "HSFC execute");
  s.n = n_new;
  mig_state_check(&s, &c, 1.0, "HSFC");
  imb = mig_imbalance(&s);
  CHECK(imb <= 1.10, "HSFC: the largest count is %.3f times the mean", imb);
#else
  mig_state_move(&s, &c, 1.0);
  CHECK(mfree_migration_partition(m, s.n, s.x, 3, 1, &n_new) == MFREE_ERR_UNSUPPORTED, "without Zoltan");
#endif

  /* 5. the halo and particle set rebuilt over the migrated particles: the gradient at the
   * owned particles is bitwise that of one rank holding the whole cloud */
  {
    mig_state_t all;
    mig_state_init(&all, &c, NULL, 0, c.n, 1.0); /* (on every rank: the whole cloud) */
    double hmax = cloud_max_support(&c), width = KAPPA * hmax * 1.01;
    mfree_halo_t *halo = NULL;
    expect_ok(ctx, mfree_halo_create(ctx, MPI_COMM_WORLD, 2, &halo), "halo");
    double *g = gradient(ctx, halo, s.n, s.x, s.h, s.id, width);
    double *g1 = gradient(ctx, NULL, c.n, all.x, all.h, all.id, width);
    for (int k = 0; k < s.n; ++k) {
      const int i = (int)((s.id[k] - 5) / 2);
      CHECK(!memcmp(g + 2 * k, g1 + 2 * i, 2 * sizeof(double)), "gradient of id %lld: %.17g %.17g vs %.17g %.17g",
            (long long)s.id[k], g[2 * k], g[2 * k + 1], g1[2 * i], g1[2 * i + 1]);
    }
    free(g);
    free(g1);
    mfree_halo_destroy(&halo);
    mig_state_free(&all);
  }

  /* 6. back to the starting owners */
  for (int k = 0; k < s.n; ++k) owners[k] = start[(s.id[k] - 5) / 2];
  expect_ok(ctx, mfree_migration_set_owners(m, s.n, owners, &n_new), "set_owners back");
  expect_ok(ctx, mfree_migration_execute(m, s.cap), "execute back");
  s.n = n_new;
  for (int k = 0; k < s.n; ++k) CHECK(start[(s.id[k] - 5) / 2] == rank, "id %lld not back", (long long)s.id[k]);
  mig_state_check(&s, &c, 1.0, "round trip");

  mfree_migration_destroy(&m);
  mfree_context_destroy(&ctx);
  mig_state_free(&s);
  free(start);
  free(owners);
  cloud_free(&c);
  const int rc = mpitest_finish("t180-mpi-migrate");
  MPI_Finalize();
  return rc;
}
