/* Weak scaling of a distributed gradient step with libmfree_mpi (run by hand):
 *   mpirun --oversubscribe -np P ./bench/bench_mpi_weak [--side=500] [--steps=20]
 *          [--migrate-every=K]
 * Each rank owns a side x side block of a perturbed 2D lattice (2.5e5 particles at the
 * default), the blocks in a row along x, so inner ranks have two neighbours. A step:
 * owned particles drift, the halo exchange sends positions (2 doubles) and one field,
 * the particle set and a Randles-Libersky approximant update on the kept pattern, and
 * the gradient of the field is applied. Rank 0 prints the time per step (slowest rank),
 * the time in the step's two exchanges (which includes waiting for slower ranks) and in
 * the same two exchanges repeated after a barrier (the transfer alone); their fractions
 * of the step are the reference measured in the same run. Then the bytes each rank sends
 * per step, the ghosts, and the cost of the first plan and of a rebuild.
 * With --migrate-every=K (K >= 1) the particles move instead along a cellular flow whose
 * cells straddle the ranks' boundaries (run_migrating, below): every K steps they migrate
 * to the owners of Zoltan's RCB partition (mfree_migration_*) and the halo, the particle
 * set and the approximant are built anew; the report adds the bytes and time of the
 * migrations and the fraction of the step spent communicating.
 * On a machine with fewer cores than ranks (--oversubscribe) the ranks share cores:
 * those times are not speed-ups. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <mfree_mpi.h>

#include "bench_util.h"

static void ok(mfree_context_t *ctx, mfree_status_t st, const char *what) {
  if (st == MFREE_SUCCESS) return;
  char msg[512] = "";
  mfree_context_get_last_error(ctx, NULL, msg, sizeof msg);
  fprintf(stderr, "bench_mpi_weak: %s: %s\n", what, msg);
  MPI_Abort(MPI_COMM_WORLD, 2);
}

/* ---- particles that move and migrate (--migrate-every=K) ------------------------------ */

/* The cellular flow v = a (sin(pi (x + 1/2)) cos(pi y), -cos(pi (x + 1/2)) sin(pi y)):
 * divergence-free, so the particles stay evenly spread and the counts balanced; its cells
 * are centred on the ranks' boundaries x = 1, 2, ..., so the particles near a boundary
 * turn about its middle and cross it, most at mid-height. a is the largest displacement
 * per step. */
static void flow(double a, const double *x, double *v) {
  const double pi = 3.14159265358979323846, px = pi * (x[0] + 0.5), py = pi * x[1];
  v[0] = a * sin(px) * cos(py);
  v[1] = -a * cos(px) * sin(py);
}

/* One rank's moving particles: positions, velocities and global ids travel in a migration
 * (items [0, no) owned; x also holds the ghosts after them); ids are the particle set's
 * (owned, then ghosts), u the field and g its gradient. */
typedef struct {
  mfree_context_t *ctx;
  mfree_halo_t *halo;
  mfree_particles_t *ps;
  mfree_approximant_t *ap;
  int32_t cap, no, ng;
  int64_t nsend;
  double *x, *v, *u, *g, hs, vol, width;
  int64_t *gid, *ids;
} movers_t;

static void field(movers_t *m) {
  for (int32_t i = 0; i < m->no; ++i) m->u[i] = sin(3.0 * m->x[2 * i]) * m->x[2 * i + 1];
}

/* The halo plan for the current owned particles (returns its time: communication), then
 * a new particle set and approximant on owned + ghosts (*t_setup: local work). */
static double build(movers_t *m, double *t_setup) {
  const double t0 = MPI_Wtime();
  ok(m->ctx, mfree_halo_setup(m->halo, m->no, m->x, 2, m->gid, m->width), "halo setup");
  int32_t no;
  ok(m->ctx, mfree_halo_get_size(m->halo, &no, &m->ng), "size");
  ok(m->ctx, mfree_halo_get_plan(m->halo, NULL, &m->nsend, NULL), "plan");
  if ((int64_t)m->no + m->ng > m->cap) {
    fprintf(stderr, "bench_mpi_weak: %d owned + %d ghosts exceed the arrays' %d\n", (int)m->no, (int)m->ng,
            (int)m->cap);
    MPI_Abort(MPI_COMM_WORLD, 2);
  }
  ok(m->ctx, mfree_halo_get_global_ids(m->halo, m->ids), "ids");
  ok(m->ctx, mfree_halo_exchange(m->halo, 2, m->x, 2), "exchange x");
  const double t1 = MPI_Wtime();
  mfree_approximant_destroy(&m->ap);
  mfree_particles_destroy(&m->ps);
  ok(m->ctx, mfree_particles_create(m->ctx, 2, m->no + m->ng, &m->ps), "particles");
  mfree_particles_set_num_ghost(m->ps, m->ng);
  mfree_particles_set_positions(m->ps, m->x, MFREE_LAYOUT_AOS, 2, MFREE_BORROW);
  mfree_particles_set_support(m->ps, &m->hs, 0, MFREE_COPY);
  mfree_particles_set_volumes(m->ps, &m->vol, 0, MFREE_COPY);
  mfree_particles_set_global_ids(m->ps, m->ids, MFREE_BORROW);
  ok(m->ctx, mfree_particles_setup(m->ps), "particle setup");
  ok(m->ctx, mfree_approximant_create(m->ctx, m->ps, MFREE_METHOD_RANDLES_LIBERSKY, &m->ap), "approximant");
  ok(m->ctx, mfree_approximant_set_derivatives(m->ap, MFREE_DERIV_GRADIENT), "derivatives");
  ok(m->ctx, mfree_approximant_setup(m->ap), "approximant setup");
  *t_setup = MPI_Wtime() - t1;
  return t1 - t0;
}

/* Move every owned particle to its owner in Zoltan's RCB partition of all positions (new
 * regions each time); without Zoltan, to the rank of its unit slab along x. Returns the
 * particles this rank sent. */
static int64_t migrate(movers_t *m, mfree_migration_t *mig, int32_t *owners, int *slabs) {
  int32_t n_new = 0;
  mfree_status_t st = mfree_migration_partition(mig, m->no, m->x, 2, 1, &n_new);
  if (st == MFREE_ERR_UNSUPPORTED) {
    int size;
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    for (int32_t i = 0; i < m->no; ++i) {
      const double f = floor(m->x[2 * i]);
      owners[i] = f < 0 ? 0 : f >= size ? size - 1 : (int32_t)f;
    }
    st = mfree_migration_set_owners(mig, m->no, owners, &n_new);
    *slabs = 1;
  }
  ok(m->ctx, st, "partition");
  if (n_new > m->cap) {
    fprintf(stderr, "bench_mpi_weak: %d particles after the migration exceed the arrays' %d\n", (int)n_new,
            (int)m->cap);
    MPI_Abort(MPI_COMM_WORLD, 2);
  }
  int64_t sent = 0;  /* (the plan's counts are gone once it is executed) */
  ok(m->ctx, mfree_migration_get_counts(mig, NULL, NULL, &sent, NULL), "counts");
  ok(m->ctx, mfree_migration_execute(mig, m->cap), "migration");
  m->no = n_new;
  return sent;
}

/* The migrating run: one timed loop and its report, together, so that what the report
 * divides is visibly what the loop summed. */
static void run_migrating(int side, int steps, int every) {
  int rank, size;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const int32_t n0 = side * side;
  const double dx = 1.0 / side, move = 0.1 * dx;
  movers_t m;
  memset(&m, 0, sizeof m);
  /* room for the largest owned count after a rebalance (1.05 x the mean) and the ghosts */
  m.cap = 2 * n0;
  m.no = n0;
  m.hs = 1.3 * dx;
  m.vol = dx * dx;
  /* the ghosts must hold every neighbour until the next rebuild: the support radius with
   * the fixed-pattern run's margin, plus two particles' largest approach over a window */
  m.width = 2.0 * m.hs * 1.05 + 2.0 * every * move;
  m.x = malloc(sizeof(double) * 2 * (size_t)m.cap);
  m.v = malloc(sizeof(double) * 2 * (size_t)m.cap);
  m.u = malloc(sizeof(double) * (size_t)m.cap);
  m.g = malloc(sizeof(double) * 2 * (size_t)m.cap);
  m.gid = malloc(sizeof(int64_t) * (size_t)m.cap);
  m.ids = malloc(sizeof(int64_t) * (size_t)m.cap);
  int32_t *owners = malloc(sizeof(int32_t) * (size_t)m.cap);
  for (int32_t k = 0; k < n0; ++k) {
    m.x[2 * k] = rank + ((k % side) + 0.5 + 0.1 * sin(12.9898 * k)) * dx;
    m.x[2 * k + 1] = ((k / side) + 0.5 + 0.1 * cos(78.233 * k)) * dx;
    m.gid[k] = (int64_t)rank * n0 + k;
  }
  ok(m.ctx, mfree_context_create(&m.ctx), "context");
  bench_page_hints(m.ctx);
  ok(m.ctx, mfree_halo_create(m.ctx, MPI_COMM_WORLD, 2, &m.halo), "halo");
  mfree_migration_t *mig = NULL;
  ok(m.ctx, mfree_migration_create(m.ctx, MPI_COMM_WORLD, 2, &mig), "migration");
  ok(m.ctx, mfree_migration_set_partitioner(mig, MFREE_PARTITIONER_RCB, 1.05), "partitioner");
  ok(m.ctx, mfree_migration_add_field(mig, m.x, 2 * sizeof(double), 2 * sizeof(double)), "field x");
  ok(m.ctx, mfree_migration_add_field(mig, m.v, 2 * sizeof(double), 2 * sizeof(double)), "field v");
  ok(m.ctx, mfree_migration_add_field(mig, m.gid, sizeof(int64_t), sizeof(int64_t)), "field id");
  const int64_t record = 2 * sizeof(double) + 2 * sizeof(double) + sizeof(int64_t);
  double t_setup = 0;
  build(&m, &t_setup);

  /* per category, the slowest rank's time of each step, summed: the step, its halo
   * exchanges, the migrations (partition + execute), the halo plans of the rebuilds, the
   * set and approximant setups of the rebuilds, the bare exchanges after a barrier */
  double sum[6] = {0, 0, 0, 0, 0, 0};
  int64_t halo_bytes = 0, mig_bytes = 0, mig_max = 0, sent_total = 0;
  int n_mig = 0, slabs = 0;
  /* per migration, the particles this rank sent and then owned: a halo setup after ids
   * changed on any rank sends every owned id to the rank of its hash (the duplicate-id
   * check), which the plans' bytes count */
  int64_t *mig_sent = calloc((size_t)(steps / every + 1), sizeof(int64_t));
  int64_t *mig_owned = calloc((size_t)(steps / every + 1), sizeof(int64_t));
  for (int s = 0; s < steps; ++s) {
    MPI_Barrier(MPI_COMM_WORLD);
    const double t0 = MPI_Wtime();
    double t_exch = 0, t_mig = 0, t_plan = 0;
    t_setup = 0;
    for (int32_t i = 0; i < m.no; ++i) {
      flow(move, m.x + 2 * i, m.v + 2 * i);
      m.x[2 * i] += m.v[2 * i];
      m.x[2 * i + 1] += m.v[2 * i + 1];
    }
    if ((s + 1) % every == 0) {
      const double m0 = MPI_Wtime();
      const int64_t sent = migrate(&m, mig, owners, &slabs);
      t_mig = MPI_Wtime() - m0;
      /* the records, and the count per rank pair that precedes them */
      const int64_t bytes = sent * record + 4 * (int64_t)size;
      mig_bytes += bytes;
      mig_max = bytes > mig_max ? bytes : mig_max;
      sent_total += sent;
      mig_sent[n_mig] = sent;
      mig_owned[n_mig] = m.no;
      ++n_mig;
      t_plan = build(&m, &t_setup);
      halo_bytes += m.nsend * 2 * (int64_t)sizeof(double);  /* the positions, in build */
      field(&m);
      const double c0 = MPI_Wtime();
      ok(m.ctx, mfree_halo_exchange(m.halo, 1, m.u, 1), "exchange u");
      t_exch = MPI_Wtime() - c0;
      halo_bytes += m.nsend * (int64_t)sizeof(double);
    } else {
      field(&m);
      const double c0 = MPI_Wtime();
      ok(m.ctx, mfree_halo_exchange(m.halo, 2, m.x, 2), "exchange x");
      ok(m.ctx, mfree_halo_exchange(m.halo, 1, m.u, 1), "exchange u");
      t_exch = MPI_Wtime() - c0;
      halo_bytes += m.nsend * 3 * (int64_t)sizeof(double);
      ok(m.ctx, mfree_particles_update(m.ps), "update");
      ok(m.ctx, mfree_approximant_update(m.ap), "approximant update");
    }
    ok(m.ctx,
       mfree_approximant_apply(m.ap, MFREE_OP_GRADIENT, 1, m.u, MFREE_LAYOUT_AOS, 1, m.g, MFREE_LAYOUT_AOS, 2),
       "apply");
    const double t1 = MPI_Wtime();
    MPI_Barrier(MPI_COMM_WORLD);
    const double e0 = MPI_Wtime();
    ok(m.ctx, mfree_halo_exchange(m.halo, 2, m.x, 2), "exchange x");
    ok(m.ctx, mfree_halo_exchange(m.halo, 1, m.u, 1), "exchange u");
    double loc[6] = {t1 - t0, t_exch, t_mig, t_plan, t_setup, MPI_Wtime() - e0}, mx[6];
    MPI_Allreduce(loc, mx, 6, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    for (int k = 0; k < 6; ++k) sum[k] += mx[k];
  }
  /* the largest rank's bytes, the particles sent in all, the counts' spread at the end */
  int64_t check_bytes = 0;
  MPI_Allreduce(MPI_IN_PLACE, mig_sent, n_mig, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
  for (int j = 0; j < n_mig; ++j)
    if (mig_sent[j] > 0) check_bytes += mig_owned[j] * (int64_t)sizeof(int64_t);
  int64_t loc64[4] = {halo_bytes, mig_bytes, mig_max, check_bytes}, max64[4], sent_all = 0;
  MPI_Reduce(loc64, max64, 4, MPI_INT64_T, MPI_MAX, 0, MPI_COMM_WORLD);
  MPI_Reduce(&sent_total, &sent_all, 1, MPI_INT64_T, MPI_SUM, 0, MPI_COMM_WORLD);
  int32_t cmin = 0, cmax = 0, gmax = 0;
  MPI_Reduce(&m.no, &cmin, 1, MPI_INT32_T, MPI_MIN, 0, MPI_COMM_WORLD);
  MPI_Reduce(&m.no, &cmax, 1, MPI_INT32_T, MPI_MAX, 0, MPI_COMM_WORLD);
  MPI_Reduce(&m.ng, &gmax, 1, MPI_INT32_T, MPI_MAX, 0, MPI_COMM_WORLD);
  if (rank == 0) {
    const double comm = sum[1] + sum[2] + sum[3], nm = n_mig > 0 ? n_mig : 1;
    printf("bench_mpi_weak: %d ranks x %d particles moving, migrating every %d steps (%s, %d migrations): "
           "%.4f s/step; halo exchanges %.4f s/step (%.1f %%; after a barrier %.5f s, %.2f %%); per migration: "
           "partition + execute %.4f s, halo plan %.4f s, set + approximant setup %.4f s; communication "
           "(exchanges, migrations, plans) %.1f %% of the time; per rank (max): halo %.1f KB/step, migration "
           "%.1f KB/step (%.1f KB per migration at most), %.0f particles sent per migration (all ranks), "
           "duplicate-id checks of the rebuilt plans %.1f KB/step (%.1f KB per migration), ghosts %d; owned "
           "counts %d-%d after the last migration\n",
           size, n0, every, slabs ? "unit slabs, no Zoltan" : "Zoltan RCB", n_mig, sum[0] / steps, sum[1] / steps,
           100.0 * sum[1] / sum[0], sum[5] / steps, 100.0 * sum[5] / sum[0], sum[2] / nm, sum[3] / nm,
           sum[4] / nm, 100.0 * comm / sum[0], max64[0] / 1e3 / steps, max64[1] / 1e3 / steps, max64[2] / 1e3,
           (double)sent_all / nm, max64[3] / 1e3 / steps, max64[3] / 1e3 / nm, (int)gmax, (int)cmin, (int)cmax);
    bench_figure(sum[0] / steps, "s", "mpi_weak_migrate %d ranks x %d step", size, n0);
    bench_figure(sum[2] / nm, "s", "mpi_weak_migrate %d ranks x %d migration", size, n0);
  }
  mfree_migration_destroy(&mig);
  mfree_approximant_destroy(&m.ap);
  mfree_particles_destroy(&m.ps);
  mfree_halo_destroy(&m.halo);
  mfree_context_destroy(&m.ctx);
  free(m.x);
  free(m.v);
  free(m.u);
  free(m.g);
  free(m.gid);
  free(m.ids);
  free(owners);
  free(mig_sent);
  free(mig_owned);
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  int rank, size, side = 500, steps = 20, every = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  for (int a = 1; a < argc; ++a) {
    if (!strncmp(argv[a], "--side=", 7)) side = atoi(argv[a] + 7);
    if (!strncmp(argv[a], "--steps=", 8)) steps = atoi(argv[a] + 8);
    if (!strncmp(argv[a], "--migrate-every=", 16)) every = atoi(argv[a] + 16);
  }
  if (every > 0) {
    run_migrating(side, steps, every);
    MPI_Finalize();
    return 0;
  }
  const int32_t no = side * side;
  const double dx = 1.0 / side, hs = 1.3 * dx, vol = dx * dx, width = 2.0 * hs * 1.05;
  double *xo = malloc(sizeof(double) * 2 * (size_t)no);
  int64_t *io = malloc(sizeof(int64_t) * (size_t)no);
  for (int32_t k = 0; k < no; ++k) {
    xo[2 * k] = rank + ((k % side) + 0.5 + 0.1 * sin(12.9898 * k)) * dx;
    xo[2 * k + 1] = ((k / side) + 0.5 + 0.1 * cos(78.233 * k)) * dx;
    io[k] = (int64_t)rank * no + k;
  }
  mfree_context_t *ctx = NULL;
  mfree_halo_t *halo = NULL;
  ok(ctx, mfree_context_create(&ctx), "context");
  bench_page_hints(ctx);
  ok(ctx, mfree_halo_create(ctx, MPI_COMM_WORLD, 2, &halo), "halo");
  MPI_Barrier(MPI_COMM_WORLD);
  double t0 = MPI_Wtime();
  ok(ctx, mfree_halo_setup(halo, no, xo, 2, io, width), "halo setup");
  const double t_plan = MPI_Wtime() - t0;
  int32_t n_owned, ng, nnb;
  int64_t nsend;
  ok(ctx, mfree_halo_get_size(halo, &n_owned, &ng), "size");
  ok(ctx, mfree_halo_get_plan(halo, &nnb, &nsend, NULL), "plan");
  const int32_t n = no + ng;
  double *x = malloc(sizeof(double) * 2 * (size_t)n), *u = malloc(sizeof(double) * (size_t)n);
  double *g = malloc(sizeof(double) * 2 * (size_t)no);
  int64_t *ids = malloc(sizeof(int64_t) * (size_t)n);
  memcpy(x, xo, sizeof(double) * 2 * (size_t)no);
  ok(ctx, mfree_halo_get_global_ids(halo, ids), "ids");
  mfree_particles_t *ps = NULL;
  mfree_approximant_t *ap = NULL;
  ok(ctx, mfree_particles_create(ctx, 2, n, &ps), "particles");
  mfree_particles_set_num_ghost(ps, ng);
  mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 2, MFREE_BORROW);
  mfree_particles_set_support(ps, &hs, 0, MFREE_COPY);
  mfree_particles_set_volumes(ps, &vol, 0, MFREE_COPY);
  mfree_particles_set_global_ids(ps, ids, MFREE_BORROW);
  ok(ctx, mfree_halo_exchange(halo, 2, x, 2), "exchange");
  ok(ctx, mfree_particles_setup(ps), "particle setup");
  ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_RANDLES_LIBERSKY, &ap), "approximant");
  ok(ctx, mfree_approximant_set_derivatives(ap, MFREE_DERIV_GRADIENT), "derivatives");
  ok(ctx, mfree_approximant_setup(ap), "approximant setup");
  double t_step = 0, t_comm = 0, t_bare = 0;
  for (int s = 0; s < steps; ++s) {
    MPI_Barrier(MPI_COMM_WORLD);
    t0 = MPI_Wtime();
    for (int32_t i = 0; i < no; ++i) {
      x[2 * i] += 1e-4 * dx * cos(x[2 * i + 1] + s);
      u[i] = sin(3.0 * x[2 * i]) * x[2 * i + 1];
    }
    const double c0 = MPI_Wtime();
    ok(ctx, mfree_halo_exchange(halo, 2, x, 2), "exchange x");
    ok(ctx, mfree_halo_exchange(halo, 1, u, 1), "exchange u");
    const double c1 = MPI_Wtime();
    ok(ctx, mfree_particles_update(ps), "update");
    ok(ctx, mfree_approximant_update(ap), "approximant update");
    ok(ctx, mfree_approximant_apply(ap, MFREE_OP_GRADIENT, 1, u, MFREE_LAYOUT_AOS, 1, g, MFREE_LAYOUT_AOS, 2),
       "apply");
    const double t1 = MPI_Wtime();
    /* the same two exchanges again after a barrier: the transfer alone, without the
     * wait for slower ranks that the step's exchanges include */
    MPI_Barrier(MPI_COMM_WORLD);
    const double e0 = MPI_Wtime();
    ok(ctx, mfree_halo_exchange(halo, 2, x, 2), "exchange x");
    ok(ctx, mfree_halo_exchange(halo, 1, u, 1), "exchange u");
    const double e1 = MPI_Wtime();
    /* the slowest rank's step, its exchanges, the bare exchanges */
    double loc[3] = {t1 - t0, c1 - c0, e1 - e0}, mx[3];
    MPI_Allreduce(loc, mx, 3, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    t_step += mx[0];
    t_comm += mx[1];
    t_bare += mx[2];
  }
  MPI_Barrier(MPI_COMM_WORLD);
  t0 = MPI_Wtime();
  ok(ctx, mfree_halo_setup(halo, no, x, 2, io, width), "rebuild");
  double t_rebuild = MPI_Wtime() - t0, tp[2] = {t_plan, t_rebuild}, tpm[2];
  MPI_Reduce(tp, tpm, 2, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
  int64_t bytes = nsend * 3 * (int64_t)sizeof(double), bmax = 0;
  MPI_Reduce(&bytes, &bmax, 1, MPI_INT64_T, MPI_MAX, 0, MPI_COMM_WORLD);
  int32_t ngmax = 0;
  MPI_Reduce(&ng, &ngmax, 1, MPI_INT32_T, MPI_MAX, 0, MPI_COMM_WORLD);
  if (rank == 0)
    printf("bench_mpi_weak: %d ranks x %d particles: %.4f s/step, exchanges %.4f s/step (%.1f %%; "
           "after a barrier %.5f s, %.2f %%), %.3f MB sent per rank per step (max), ghosts %d (max), "
           "plan %.4f s, rebuild %.4f s\n",
           size, no, t_step / steps, t_comm / steps, 100.0 * t_comm / t_step, t_bare / steps,
           100.0 * t_bare / t_step, bmax / 1e6, ngmax, tpm[0], tpm[1]);
  if (rank == 0) {
    bench_figure(t_step / steps, "s", "mpi_weak %d ranks x %d step", size, no);
    bench_figure(t_comm / steps, "s", "mpi_weak %d ranks x %d exchanges in the step", size, no);
  }
  mfree_approximant_destroy(&ap);
  mfree_particles_destroy(&ps);
  mfree_halo_destroy(&halo);
  mfree_context_destroy(&ctx);
  free(xo);
  free(io);
  free(x);
  free(u);
  free(g);
  free(ids);
  MPI_Finalize();
  return 0;
}
