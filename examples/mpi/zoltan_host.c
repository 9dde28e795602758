/* zoltan_host: a C host on MPI ranks with libmfree_mpi for its halo and its partition.
 * Each rank starts with a block of rows of an m x m perturbed lattice on the unit square
 * (global ids = lattice index), Zoltan's recursive coordinate bisection (RCB) repartitions
 * them and libmfree_mpi's migration moves the particles (mfree_migration_*), then
 * libmfree_mpi builds the ghost layer and every step exchanges positions and the field,
 * and mfree computes the Randles-Libersky gradient of a linear field at the owned
 * particles, exact to round-off, with the bits of a one-rank run.
 *
 *   mpirun -np 4 ./mfree_mpi_zoltan_host [--m=1000] [--steps=3] [--check]
 *
 * --m: particles per side (default 1000: 10^6 particles); --check: exit 1 unless the
 * gradient is exact to 1e-10. Prints, on rank 0, the partition's time and the particles it
 * moved, the owned/ghost counts, the time per step and a checksum of the gradient bits keyed by global id (an exclusive or over the
 * ranks, independent of the decomposition). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <mfree_mpi.h>

static const double kA[2][2] = {{0.10, 0.40}, {-0.30, -0.05}}; /* u = A x + b, grad u = A */

typedef struct {
  int64_t n;
  double *x; /* 2 per particle */
  int64_t *id;
} owned_t;

static void die(mfree_context_t *ctx, mfree_status_t st, const char *what) {
  char msg[512] = "";
  if (st == MFREE_SUCCESS) return;
  mfree_context_get_last_error(ctx, NULL, msg, sizeof msg);
  fprintf(stderr, "zoltan_host: %s: %s: %s\n", what, mfree_status_string(st), msg);
  MPI_Abort(MPI_COMM_WORLD, 3);
}

/* RCB regions from Zoltan through libmfree_mpi's migration, which moves the positions
 * and ids to their new owners (one MPI_Alltoallv). */
static void partition(mfree_context_t *ctx, owned_t *o, int64_t *moved) {
  mfree_migration_t *mig = NULL;
  int32_t n_new = 0;
  die(ctx, mfree_migration_create(ctx, MPI_COMM_WORLD, 2, &mig), "migration create");
  die(ctx, mfree_migration_set_partitioner(mig, MFREE_PARTITIONER_RCB, 1.05), "partitioner");
  die(ctx, mfree_migration_partition(mig, (int32_t)o->n, o->x, 2, 1, &n_new), "partition");
  die(ctx, mfree_migration_get_counts(mig, NULL, NULL, moved, NULL), "counts");
  /* the arrays grow to the larger of the counts before and after */
  const int64_t cap = n_new > o->n ? n_new : o->n;
  o->x = realloc(o->x, sizeof(double) * 2 * (size_t)(cap + 1));
  o->id = realloc(o->id, sizeof(int64_t) * (size_t)(cap + 1));
  if (!o->x || !o->id) {
    fprintf(stderr, "zoltan_host: out of memory\n");
    MPI_Abort(MPI_COMM_WORLD, 4);
  }
  die(ctx, mfree_migration_add_field(mig, o->x, 2 * sizeof(double), 2 * sizeof(double)), "field x");
  die(ctx, mfree_migration_add_field(mig, o->id, sizeof(int64_t), sizeof(int64_t)), "field id");
  die(ctx, mfree_migration_execute(mig, (int32_t)cap), "migration");
  o->n = n_new;
  mfree_migration_destroy(&mig);
}

static uint64_t mix(uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  int rank, size, m = 1000, steps = 3, check = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  for (int a = 1; a < argc; ++a) {
    if (!strncmp(argv[a], "--m=", 4)) m = atoi(argv[a] + 4);
    else if (!strncmp(argv[a], "--steps=", 8)) steps = atoi(argv[a] + 8);
    else if (!strcmp(argv[a], "--check")) check = 1;
  }
  if (m < 4) m = 4;
  const int64_t N = (int64_t)m * m;
  const double dx = 1.0 / m, hsup = 1.3 * dx, vol = dx * dx, width = 2.0 * hsup * 1.05;

  /* ---- the starting share: a block of lattice indices per rank ---- */
  owned_t o;
  const int64_t k0 = N * rank / size, k1 = N * (rank + 1) / size;
  o.n = k1 - k0;
  o.x = malloc(sizeof(double) * 2 * (size_t)(o.n + 1));
  o.id = malloc(sizeof(int64_t) * (size_t)(o.n + 1));
  for (int64_t k = k0; k < k1; ++k) {
    const int64_t i = k - k0;
    o.x[2 * i] = ((double)(k % m) + 0.5 + 0.2 * ((double)(mix((uint64_t)k) >> 11) * 0x1.0p-53 - 0.5)) * dx;
    o.x[2 * i + 1] = ((double)(k / m) + 0.5 + 0.2 * ((double)(mix((uint64_t)k + N) >> 11) * 0x1.0p-53 - 0.5)) * dx;
    o.id[i] = k;
  }
  mfree_context_t *ctx = NULL;
  die(ctx, mfree_context_create(&ctx), "context");
  int64_t moved = 0;
  MPI_Barrier(MPI_COMM_WORLD);
  const double p0 = MPI_Wtime();
  partition(ctx, &o, &moved);
  double t_part = MPI_Wtime() - p0;

  /* ---- the halo by libmfree_mpi ---- */
  mfree_halo_t *halo = NULL;
  die(ctx, mfree_halo_create(ctx, MPI_COMM_WORLD, 2, &halo), "halo create");
  die(ctx, mfree_halo_setup(halo, (int32_t)o.n, o.x, 2, o.id, width), "halo setup");
  int32_t no = 0, ng = 0, nnb = 0;
  int64_t nsend = 0;
  die(ctx, mfree_halo_get_size(halo, &no, &ng), "halo size");
  die(ctx, mfree_halo_get_plan(halo, &nnb, &nsend, NULL), "halo plan");
  const int32_t n = no + ng;
  double *x = malloc(sizeof(double) * 2 * (size_t)(n + 1)), *u = malloc(sizeof(double) * 2 * (size_t)(n + 1));
  double *g = malloc(sizeof(double) * 4 * (size_t)(no + 1));
  int64_t *ids = malloc(sizeof(int64_t) * (size_t)(n + 1));
  die(ctx, mfree_halo_get_global_ids(halo, ids), "ids");
  memcpy(x, o.x, sizeof(double) * 2 * (size_t)no);

  mfree_particles_t *ps = NULL;
  mfree_approximant_t *ap = NULL;
  die(ctx, mfree_particles_create(ctx, 2, n, &ps), "particles");
  die(ctx, mfree_particles_set_num_ghost(ps, ng), "ghosts");
  die(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 2, MFREE_BORROW), "positions");
  die(ctx, mfree_particles_set_support(ps, &hsup, 0, MFREE_COPY), "support");
  die(ctx, mfree_particles_set_volumes(ps, &vol, 0, MFREE_COPY), "volumes");
  die(ctx, mfree_particles_set_global_ids(ps, ids, MFREE_BORROW), "ids");
  die(ctx, mfree_particles_set_halo_width(ps, width), "halo width");
  die(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_RANDLES_LIBERSKY, &ap), "approximant");
  die(ctx, mfree_approximant_set_derivatives(ap, MFREE_DERIV_GRADIENT), "derivatives");

  /* ---- steps: a small rigid drift (same neighbours), exchange, update, apply ---- */
  double t_step = 0, t_comm = 0;
  for (int s = 0; s <= steps; ++s) {
    MPI_Barrier(MPI_COMM_WORLD);
    const double t0 = MPI_Wtime();
    for (int32_t i = 0; i < no; ++i) {
      x[2 * i] += 1e-3 * dx;
      u[2 * i] = 1.0 + kA[0][0] * x[2 * i] + kA[0][1] * x[2 * i + 1];
      u[2 * i + 1] = -2.0 + kA[1][0] * x[2 * i] + kA[1][1] * x[2 * i + 1];
    }
    const double c0 = MPI_Wtime();
    die(ctx, mfree_halo_exchange(halo, 2, x, 2), "exchange x");
    die(ctx, mfree_halo_exchange(halo, 2, u, 2), "exchange u");
    const double c1 = MPI_Wtime();
    die(ctx, s == 0 ? mfree_particles_setup(ps) : mfree_particles_update(ps), "particle setup");
    die(ctx, s == 0 ? mfree_approximant_setup(ap) : mfree_approximant_update(ap), "approximant");
    die(ctx, mfree_approximant_apply(ap, MFREE_OP_GRADIENT, 2, u, MFREE_LAYOUT_AOS, 2, g, MFREE_LAYOUT_AOS, 4),
        "apply");
    const double t1 = MPI_Wtime();
    if (s > 0) { /* step 0 is the set-up */
      t_step += t1 - t0;
      t_comm += c1 - c0;
    }
  }
  double err = 0;
  uint64_t sum = 0, all = 0;
  for (int32_t i = 0; i < no; ++i) {
    uint64_t z = (uint64_t)ids[i];
    for (int c = 0; c < 2; ++c)
      for (int d = 0; d < 2; ++d) {
        err = fmax(err, fabs(g[4 * i + 2 * c + d] - kA[c][d]));
        uint64_t b;
        memcpy(&b, &g[4 * i + 2 * c + d], sizeof b);
        z = mix(z ^ b);
      }
    sum ^= z;
  }
  double errmax = 0, tstep = 0, tcomm = 0;
  int64_t gmax = 0, gsum = 0, g64 = ng;
  MPI_Reduce(&err, &errmax, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
  MPI_Reduce(&sum, &all, 1, MPI_UINT64_T, MPI_BXOR, 0, MPI_COMM_WORLD);
  MPI_Reduce(&t_step, &tstep, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
  MPI_Reduce(&t_comm, &tcomm, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
  MPI_Reduce(&g64, &gmax, 1, MPI_INT64_T, MPI_MAX, 0, MPI_COMM_WORLD);
  MPI_Reduce(&g64, &gsum, 1, MPI_INT64_T, MPI_SUM, 0, MPI_COMM_WORLD);
  int64_t moved_all = 0;
  MPI_Reduce(&moved, &moved_all, 1, MPI_INT64_T, MPI_SUM, 0, MPI_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, &t_part, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  if (rank == 0) {
    printf("partition and migration %.4f s: %lld particles moved (%.1f MB of 24-byte records)\n", t_part,
           (long long)moved_all, 24e-6 * (double)moved_all);
    printf("zoltan_host: %lld particles on %d ranks (Zoltan RCB), ghosts per rank %.0f avg / %lld max\n",
           (long long)N, size, (double)gsum / size, (long long)gmax);
    if (steps > 0)
      printf("time per step %.4f s (exchange %.4f s), max |grad u - A| = %.3e\n", tstep / steps, tcomm / steps,
             errmax);
    printf("checksum %016llx\n", (unsigned long long)all);
  }
  mfree_approximant_destroy(&ap);
  mfree_particles_destroy(&ps);
  mfree_halo_destroy(&halo);
  mfree_context_destroy(&ctx);
  free(x);
  free(u);
  free(g);
  free(ids);
  free(o.x);
  free(o.id);
  int bad = 0;
  if (rank == 0) bad = check && !(errmax < 1e-10);
  MPI_Bcast(&bad, 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (bad && rank == 0) printf("check FAILED: the RL gradient is not exact to 1e-10\n");
  MPI_Finalize();
  return bad;
}
