/* The dam break on MPI ranks: the collapse of a water column of paper 003 (Martin & Moyce's
 * set-up of examples/dam_break, from fluid_common's fc_dam_*: column a wide and 2a high, tank
 * 5a, nx x 2 nx particles, leap-frog at CFL 0.5) by the fluid on ranks (docs/fluid-ranks.md),
 * partitioned by Zoltan and repartitioned between integration windows.
 *
 *   mpirun -np 2 ./mfree_mpi_dam_break [options]      (--help lists them)
 *
 * Set-up. Rank r first holds the particles with ids [r n / p, (r + 1) n / p) (rows of the
 * column, id q = j nx + i as examples/dam_break numbers them), a ghost layer of width
 * 4 h + 4 d (libmfree_mpi's halo: two support radii and a margin for the motion; the system
 * rebuilds it whenever the particles' displacements have used the margin up; 8 h + 4 d, four
 * radii, with --no-slip 1 and --diffusion D > 0 together) and the fluid on ranks over it.
 * --no-slip 1 and --diffusion D as examples/dam_break's: four layers of dummy particles
 * past the floor and both end walls, every rank holding all of them, and density diffusion.
 * Zoltan then partitions the particles (RCB, or HSFC with --partitioner hsfc, to
 * --imbalance 1.05) through mfree_halo_migrate_fluid before the first step.
 *
 * Windows. The run integrates from one front sample to the next, every 0.05 in T = t
 * sqrt(2 g / a), through the same integrate calls as examples/dam_break (so the same
 * steps), and every --window T (default 0.25) Zoltan repartitions the particles where they
 * are now: they move to their new owners with their state, masses and ids, and the ghosts
 * are rebuilt. After the first partition and after each repartition, the particle counts
 * per rank: their largest and smallest ratio to the mean. --acoustic-step 1 bounds the step
 * by the acoustic operator's largest frequency as examples/dam_break's option does (its
 * power iteration's vector travels with the particles).
 *
 * Front. Z = (max x + d/2) / a, the maximum over the ranks' owned particles (MPI_MAX, exact
 * in any order); Z_floor over the particles with z < 1.5 d. The fluid on ranks gives every
 * particle the bits of one rank whatever the partition, so Z(T) is the one-rank run's bit
 * for bit on any number of ranks, and up to 1,024 particles that of examples/dam_break
 * (docs/fluid-ranks.md); the JSON's digests of the history say so (t199). The head speed
 * dZ/dT, the least-squares slope of those reduced samples over 1 <= T <= 3 on rank 0, is
 * then the serial example's too.
 *
 * Output (rank 0) in DIR (--out, default mpi_dam_break_out): front.csv, front.gp and
 * front.png (gnuplot), and the summary mpi_dam_break.json (--json: on stdout too) with the
 * keys of examples/dam_break's ("front", "front_floor", their digests, "max_rel_dev",
 * "compared", "max_rel_dev_wide", "compared_wide", "time_offset", "particles", "steps",
 * "wall_seconds", "a", "nx", "cfl", "shepard_condition", "mu", "scheme", "status", "no_slip", "diffusion",
 * "error", "t_end", "head_speed", "head_speed_experiment", "head_fit_points"; "mass_rel_error" from the Galerkin lumped masses alone, summed over
 * the ranks, against the particles' total, 003 eq 57) and "ranks",
 * "partitioner", "window", "halo_width", "balance" ([T, max/mean, min/mean] after each
 * partition), "max_count_ratio", "min_count_ratio", "balanced" (1 when every partition left
 * every rank within 10 % of the mean), "partitions", "moved" (particles sent to another
 * rank, summed over the partitions), "migrate_seconds" and "acoustic_step". With --vtu DIR (or --vtu-every
 * T): DIR/dam_break.pvd indexing dam_break_NNNN.pvtu, each with one .vtu piece per rank
 * (position, velocity = interpolated v_hat, pressure, density, global id, rank) every 0.25
 * in T. Rank 0 alone draws the progress bar, on a terminal.
 *
 * Exit status, the same on every rank: 0; 2 for bad options; 3 when the run stopped on an
 * error on any rank (a particle leaving the tank, a non-finite state, a failed migration:
 * rank 0 prints the agreed message); 1 when any rank cannot write a file or runs out of
 * memory. */
#define _XOPEN_SOURCE 700
#include <math.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <mfree.h>
#include <mfree_mpi.h>

#include "fluid_common.h"
#include "pvtu.h"
#include "util.h"

static int g_rank = 0; /* usage on rank 0 only */

typedef struct {
  double a, tank, t_end, cfl, mu, strength, offset, shepard, window, imbalance, diffusion;
  int nx, scheme, lumping, partitioner, no_slip, acoustic_step;
  const char *data;
  fc_run_t run;
} options_t;

static const double kSample = 0.05; /* the front's sampling interval in T, examples/dam_break's */

static void usage(FILE *f) {
  if (g_rank != 0) return;
  fprintf(f, "usage: mpirun -np P mfree_mpi_dam_break [options]\n");
  fc_dam_usage(f);
  fprintf(f, "  --partitioner P rcb (default) | hsfc: Zoltan's method\n"
             "  --imbalance R   the largest count / mean Zoltan may leave, in [1, 10] (default 1.05)\n"
             "  --window W      repartition every W in T, a multiple of 0.05 (default 0.25)\n"
             "  --no-slip 0|1   no-slip floor and end walls: dummy particles past them (default 0)\n"
             "  --diffusion D   density diffusion (delta-SPH) coefficient, >= 0 (default 0)\n"
             "  --acoustic-step 0|1  the step also at most 1.5 / omega, omega the acoustic operator's largest\n"
             "                  frequency (mfree_system_set_acoustic_step; default 0)\n");
  fc_run_usage(f);
}

/* Returns 0 to go on, -1 after --help, 2 for bad options (the same on every rank). */
static int parse(int argc, char **argv, options_t *o) {
  const char *scheme = "leapfrog", *lumping = "galerkin", *partitioner = "rcb";
  const fc_option_t opts[] = {{"--nx", 'i', &o->nx},
                              {"--a", 'd', &o->a},
                              {"--tank", 'd', &o->tank},
                              {"--tend", 'd', &o->t_end},
                              {"--cfl", 'd', &o->cfl},
                              {"--mu", 'd', &o->mu},
                              {"--strength", 'd', &o->strength},
                              {"--offset", 'd', &o->offset},
                              {"--data", 's', &o->data},
                              {"--scheme", 's', &scheme},
                              {"--lumping", 's', &lumping},
                              {"--shepard-cond", 'd', &o->shepard},
                              {"--partitioner", 's', &partitioner},
                              {"--imbalance", 'd', &o->imbalance},
                              {"--window", 'd', &o->window},
                              {"--no-slip", 'i', &o->no_slip},
                              {"--diffusion", 'd', &o->diffusion},
                              {"--acoustic-step", 'i', &o->acoustic_step},
                              {NULL, 0, NULL}};
  const int parsed = fc_parse(argc, argv, &o->run, opts, usage);
  if (parsed) return parsed;
  o->scheme = !strcmp(scheme, "leapfrog") ? MFREE_INTEGRATOR_LEAPFROG
              : !strcmp(scheme, "pc")     ? MFREE_INTEGRATOR_PREDICTOR_CORRECTOR
                                          : -1;
  o->lumping = !strcmp(lumping, "galerkin") ? MFREE_LUMP_GALERKIN : !strcmp(lumping, "physical") ? MFREE_LUMP_PHYSICAL : -1;
  o->partitioner = !strcmp(partitioner, "rcb") ? MFREE_PARTITIONER_RCB
                   : !strcmp(partitioner, "hsfc") ? MFREE_PARTITIONER_HSFC
                                                  : -1;
  const double windows = o->window / kSample;
  const int ok = o->scheme >= 0 && o->lumping >= 0 && o->partitioner >= 0 && o->nx >= 2 && o->a > 0 &&
                 o->tank > 1 && o->t_end > 0 && o->cfl > 0 && o->cfl <= 1 && o->mu >= 0 && o->strength >= 0 &&
                 o->offset >= 0 && o->shepard >= 1 && o->imbalance >= 1 && o->imbalance <= 10 && windows >= 1 - 1e-9 &&
                 (o->no_slip == 0 || o->no_slip == 1) && o->diffusion >= 0 &&
                 fabs(windows - floor(windows + 0.5)) < 1e-9 &&
                 (o->acoustic_step == 0 || o->acoustic_step == 1);
  if (!ok) usage(stderr);
  return ok ? 0 : 2;
}

/* 1 on every rank when any rank's bad is nonzero. */
static int any(int bad) {
  int out = 1;
  MPI_Allreduce(&bad, &out, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  return out != 0;
}

/* One rank's share: the fluid system over the halo, its state y (capacity cap doubles),
 * the migration plan. */
typedef struct {
  mfree_context_t *ctx;
  mfree_halo_t *halo;
  mfree_migration_t *mig;
  mfree_system_t *sys;
  double *y;
  int64_t cap;
  int32_t n_owned;
} share_t;

/* The ranks' first share: ids [q0, q1) of the column at rest, a halo of the given width,
 * the ghosts' masses from their owners, the fluid configured as examples/dam_break's.
 * Collective; the same status on every rank (a local failure is agreed, message on its
 * rank). */
static mfree_status_t share_create(share_t *s, const fc_dam_t *dam, const options_t *o, int64_t q0, int64_t q1,
                                   double width) {
  const int32_t no = (int32_t)(q1 - q0);
  s->n_owned = no;
  s->cap = 5 * ((int64_t)no + no / 4 + 16); /* room for the partitions' imbalance */
  s->y = calloc((size_t)s->cap, sizeof *s->y);
  int64_t *ids = malloc(((size_t)no + 1) * sizeof *ids);
  double *m = NULL;
  mfree_status_t st = s->y && ids ? MFREE_SUCCESS : MFREE_ERR_ALLOC;
  for (int32_t k = 0; st == MFREE_SUCCESS && k < no; ++k) {
    double mk;
    ids[k] = q0 + k;
    fc_dam_particle(dam, q0 + k, s->y + 2 * k, s->y + 4 * (size_t)no + k, &mk);
  }
  if (any(st != MFREE_SUCCESS)) st = MFREE_ERR_ALLOC;
  if (st == MFREE_SUCCESS) st = mfree_halo_create(s->ctx, MPI_COMM_WORLD, 2, &s->halo);
  if (st == MFREE_SUCCESS) st = mfree_halo_setup(s->halo, no, s->y, 2, ids, width);
  int32_t n_owned = 0, n_ghost = 0;
  if (st == MFREE_SUCCESS) st = mfree_halo_get_size(s->halo, &n_owned, &n_ghost);
  if (st == MFREE_SUCCESS) {
    /* the owned particles keep their order: their masses, then the ghosts' by exchange */
    m = malloc(((size_t)n_owned + n_ghost + 1) * sizeof *m);
    if (m)
      for (int32_t k = 0; k < n_owned; ++k) {
        double x[2], rho;
        fc_dam_particle(dam, q0 + k, x, &rho, m + k);
      }
    if (any(!m)) st = MFREE_ERR_ALLOC;
  }
  if (st == MFREE_SUCCESS) st = mfree_halo_exchange(s->halo, 1, m, 1);
  if (st == MFREE_SUCCESS) st = mfree_halo_create_fluid(s->halo, 2, width, &s->sys);
  if (st == MFREE_SUCCESS) {
    mfree_status_t mine =
        fc_dam_configure(dam, s->sys, m, o->mu, o->strength, (mfree_lumping_t)o->lumping, o->shepard);
    if (mine == MFREE_SUCCESS) mine = mfree_system_set_density_diffusion(s->sys, o->diffusion);
    /* every rank the same dummies, all of them */
    if (mine == MFREE_SUCCESS && o->no_slip)
      mine = fc_dummy_tank(s->sys, (int)lround(dam->L / dam->d), 1.5 * dam->H, dam->d);
    if (mine == MFREE_SUCCESS) mine = mfree_system_set_acoustic_step(s->sys, o->acoustic_step);
    if (mine != MFREE_SUCCESS) fprintf(stderr, "mfree_mpi_dam_break: rank %d: the fluid's settings failed\n", g_rank);
    if (any(mine != MFREE_SUCCESS)) st = mine != MFREE_SUCCESS ? mine : MFREE_ERR_ARG;
  }
  if (st == MFREE_SUCCESS) st = mfree_migration_create(s->ctx, MPI_COMM_WORLD, 2, &s->mig);
  if (st == MFREE_SUCCESS) st = mfree_migration_set_partitioner(s->mig, o->partitioner, o->imbalance);
  free(ids);
  free(m);
  return st;
}

static void share_free(share_t *s) {
  mfree_system_destroy(&s->sys); /* before the halo it keeps a pointer to */
  mfree_migration_destroy(&s->mig);
  if (s->halo) mfree_halo_destroy(&s->halo);
  free(s->y);
  s->y = NULL;
}

/* The owned particles' global ids (n_owned of them, a new array), from the halo; NULL
 * when out of memory. */
static int64_t *owned_ids(const share_t *s) {
  int32_t no = 0, ng = 0;
  if (mfree_halo_get_size(s->halo, &no, &ng) != MFREE_SUCCESS) return NULL;
  int64_t *ids = malloc(((size_t)no + ng + 1) * sizeof *ids);
  if (ids && mfree_halo_get_global_ids(s->halo, ids) != MFREE_SUCCESS) {
    free(ids);
    return NULL;
  }
  return ids;
}

static int cmp_id(const void *a, const void *b) {
  const int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
  return (x > y) - (x < y);
}

/* Zoltan's partition of the particles where they are now, and their move with the
 * system's state, masses and ids (libmfree_mpi). Collective; *moved: the particles this
 * rank sent away (-1 when they could not be counted). */
static mfree_status_t share_partition(share_t *s, int64_t *moved) {
  const int32_t before = s->n_owned;
  int64_t *old = owned_ids(s);
  if (old) qsort(old, (size_t)before, sizeof *old, cmp_id);
  mfree_status_t st = MFREE_SUCCESS;
  for (int attempt = 0; attempt < 2; ++attempt) {
    int64_t neq = 0;
    st = mfree_halo_migrate_fluid(s->halo, s->mig, s->sys, 1, s->y, s->cap, &neq);
    if (st == MFREE_SUCCESS) {
      s->n_owned = (int32_t)(neq / 5);
      break;
    }
    /* (every rank fails alike when one rank's y is too small: those grow, all call again) */
    if (st != MFREE_ERR_ARG) break;
    if (neq <= s->cap) continue;
    const int64_t cap = neq + neq / 4 + 80;
    double *y = realloc(s->y, (size_t)cap * sizeof *y);
    if (y) s->y = y, s->cap = cap;
  }
  /* the particles kept: the new owned ids found among the old */
  int64_t *now = st == MFREE_SUCCESS && old ? owned_ids(s) : NULL;
  *moved = -1;
  if (now) {
    int64_t kept = 0;
    for (int32_t k = 0; k < s->n_owned; ++k) kept += bsearch(now + k, old, (size_t)before, sizeof *old, cmp_id) != NULL;
    *moved = before - kept;
  }
  free(old), free(now);
  return st;
}

/* The front: the largest x of the owned particles and of those on the floor, over the
 * ranks (exact in any order). */
static void front_max(const share_t *s, double d, double out[2]) {
  double loc[2] = {-1e300, -1e300};
  const double *y = s->y;
  for (int32_t q = 0; q < s->n_owned; ++q) {
    if (y[2 * q] > loc[0]) loc[0] = y[2 * q];
    if (y[2 * q + 1] < 1.5 * d && y[2 * q] > loc[1]) loc[1] = y[2 * q];
  }
  MPI_Allreduce(loc, out, 2, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
}

/* This rank's piece of the parallel VTU snapshot: the owned particles' positions,
 * interpolated velocities, pressures, densities (examples/dam_break's arrays), global ids
 * and rank. Collective; 0, or 1 on every rank after a failure. */
static int write_vtu(ex_pvtu_series_t *series, const share_t *s, double t) {
  const int32_t no = s->n_owned;
  int64_t *ids = owned_ids(s);
  int32_t *rank = malloc(((size_t)no + 1) * sizeof *rank);
  double *vhat = malloc((2 * (size_t)no + 1) * sizeof *vhat), *p = malloc(((size_t)no + 1) * sizeof *p);
  int bad = any(!ids || !rank || !vhat || !p);
  /* (the interpolated velocity is collective: every rank the same status) */
  if (!bad) bad = mfree_system_get_velocity(s->sys, s->y, vhat) != MFREE_SUCCESS;
  if (!bad) bad = any(mfree_system_get_pressure(s->sys, s->y, p) != MFREE_SUCCESS);
  if (!bad) {
    for (int32_t k = 0; k < no; ++k) rank[k] = g_rank;
    const ex_vtu_array_t arrays[5] = {{"velocity", EX_VTU_FLOAT64, 2, vhat, 2},
                                      {"pressure", EX_VTU_FLOAT64, 1, p, 1},
                                      {"density", EX_VTU_FLOAT64, 1, s->y + 4 * (size_t)no, 1},
                                      {"global_id", EX_VTU_INT64, 1, ids, 1},
                                      {"rank", EX_VTU_INT32, 1, rank, 1}};
    bad = ex_pvtu_series_write(series, t, no, 2, s->y, 2, 5, arrays);
  }
  free(ids), free(rank), free(vhat), free(p);
  return bad;
}

/* |sum of the Galerkin lumped masses - sum of the particle masses| / the latter (003 eq
 * 57), the lumped masses of the ranks' owned particles summed over the ranks; NaN when
 * they could not be assembled. Collective. */
static double lumped_mass_error(const share_t *s, const fc_dam_t *dam) {
  double mass0 = 0.0, mine = 0.0, all = 0.0;
  for (int64_t q = 0; q < dam->n; ++q) {
    double x[2], rho, m;
    fc_dam_particle(dam, q, x, &rho, &m);
    mass0 += m;
  }
  double *lumped = malloc(((size_t)s->n_owned + 1) * sizeof *lumped);
  if (any(!lumped) || !s->sys || fc_lumped_masses(s->sys, s->y, s->n_owned, lumped) != MFREE_SUCCESS) {
    free(lumped);
    return NAN;
  }
  for (int32_t k = 0; k < s->n_owned; ++k) mine += lumped[k];
  free(lumped);
  MPI_Allreduce(&mine, &all, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  return fabs(all - mass0) / mass0;
}

/* The counts per rank after a partition: [T, max / mean, min / mean]; *total: every rank's
 * owned particles. */
static void count_balance(const share_t *s, double T, int size, double row[3], int64_t *total) {
  int64_t mine = s->n_owned, mx = 0, mn = 0;
  MPI_Allreduce(&mine, &mx, 1, MPI_INT64_T, MPI_MAX, MPI_COMM_WORLD);
  MPI_Allreduce(&mine, &mn, 1, MPI_INT64_T, MPI_MIN, MPI_COMM_WORLD);
  MPI_Allreduce(&mine, total, 1, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
  const double mean = (double)*total / size;
  row[0] = T;
  row[1] = (double)mx / mean;
  row[2] = (double)mn / mean;
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  g_rank = rank;
  options_t o = {0.05715, 5.0, 3.2, 0.5, 0.5, 10.0, 0.5, 100.0, 0.25, 1.05, 0.0, 24, MFREE_INTEGRATOR_LEAPFROG,
                 MFREE_LUMP_GALERKIN, MFREE_PARTITIONER_RCB, 0, 0, MFREE_DATA_DIR "/martin_moyce_1952.csv", {0}};
  fc_run_init(&o.run, "mpi_dam_break", 0.25);
  const int parsed = parse(argc, argv, &o);
  if (parsed) {
    MPI_Finalize();
    return parsed < 0 ? 0 : parsed;
  }
  /* the directories by rank 0, before any rank writes a piece */
  if (any(rank == 0 && fc_run_prepare(&o.run))) {
    MPI_Finalize();
    return 1;
  }

  /* ---- set-up (003 Sect. 7.1, as examples/dam_break) ---- */
  fc_dam_t dam;
  int exit_status = 0;
  if (any(fc_dam_init(&dam, o.a, o.nx, o.tank, o.offset))) {
    if (rank == 0) fprintf(stderr, "mfree_mpi_dam_break: error: out of memory\n");
    MPI_Finalize();
    return 1;
  }
  /* two support radii (2 h each), four with dummies and density diffusion (docs/fluid-ranks.md) */
  const double radii = o.no_slip && o.diffusion > 0.0 ? 4.0 : 2.0;
  const double a = dam.a, d = dam.d, tscale = dam.tscale, width = 2.0 * radii * dam.h + 4.0 * d;
  const int n = dam.n;
  share_t s = {0};
  if (mfree_context_create(&s.ctx) != MFREE_SUCCESS) MPI_Abort(MPI_COMM_WORLD, 1);
  const double clock0 = MPI_Wtime();
  double migrate_seconds = 0.0;
  char msg[1024] = "";
  mfree_status_t run = share_create(&s, &dam, &o, (int64_t)n * rank / size, (int64_t)n * (rank + 1) / size, width);

  /* ---- the first partition, then windows ---- */
  double dT[64], dZ[64];
  const int ndata = fc_read_pairs(o.data, dT, dZ, 64);
  if (!ndata && !o.run.quiet && rank == 0)
    fprintf(stderr, "mfree_mpi_dam_break: no Martin & Moyce data at %s; the comparison is skipped\n", o.data);
  FILE *csv = rank == 0 ? fc_dam_csv(&o.run, &dam) : NULL;
  const char *vtu_dir = fc_run_vtu_dir(&o.run);
  ex_pvtu_series_t series = {0};
  double vtu_next = 0.0;
  int files_bad = any(rank == 0 && !csv);
  if (!files_bad && vtu_dir) files_bad = ex_pvtu_series_open(&series, MPI_COMM_WORLD, vtu_dir, "dam_break");
  const int nout = (int)floor(o.t_end / kSample + 1e-9), every = (int)floor(o.window / kSample + 0.5);
  double *fT = malloc((size_t)(nout + 1) * sizeof *fT), *fZ = malloc((size_t)(nout + 1) * sizeof *fZ);
  double *fZf = malloc((size_t)(nout + 1) * sizeof *fZf), *balance = malloc(3 * (size_t)(nout + 2) * sizeof *balance);
  if (any(!fT || !fZ || !fZf || !balance)) files_bad = 1;
  int nf = 0, nbal = 0;
  int64_t steps = 0, moved = 0, total = n;
  double t = 0.0;
  ex_progress_t prog;
  ex_progress_init(&prog, o.run.quiet || rank != 0, 0.0, o.t_end / tscale);
  /* under mpirun a rank's stderr is a pipe even on a terminal: rank 0 draws on its
     controlling terminal, when it has one */
  FILE *tty = rank == 0 && !o.run.quiet && !isatty(fileno(stderr)) ? fopen("/dev/tty", "w") : NULL;
  if (tty) ex_progress_to(&prog, tty);
  for (int io = 0; run == MFREE_SUCCESS && !files_bad && io <= nout; ++io) {
    if (io > 0) {
      run = fc_integrate(s.sys, (mfree_integrator_t)o.scheme, s.y, &t, io * kSample / tscale, o.cfl, &prog, &steps);
      if (run != MFREE_SUCCESS) break;
    }
    double xmax[2];
    front_max(&s, d, xmax);
    const double T = t * tscale, Z = (xmax[0] + 0.5 * d) / a, Zf = (xmax[1] + 0.5 * d) / a;
    fT[nf] = T;
    fZf[nf] = Zf;
    fZ[nf++] = Z;
    if (csv) fprintf(csv, "%.4f,%.5f,%.5f,%.6f,%lld\n", T, Z, Zf, t, (long long)steps);
    if (io % every == 0 && dam.L - xmax[0] >= 2.0 * d && io < nout) {
      /* Zoltan's partition where the particles are now (at T = 0 the first one) */
      const double m0 = MPI_Wtime();
      int64_t sent = 0, sent_all = 0;
      run = share_partition(&s, &sent);
      migrate_seconds += MPI_Wtime() - m0;
      if (run != MFREE_SUCCESS) break;
      MPI_Allreduce(&sent, &sent_all, 1, MPI_INT64_T, MPI_MIN, MPI_COMM_WORLD);
      if (sent_all >= 0) MPI_Allreduce(&sent, &sent_all, 1, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
      moved = moved >= 0 && sent_all >= 0 ? moved + sent_all : -1; /* -1: out of memory somewhere */
      count_balance(&s, T, size, balance + 3 * nbal++, &total);
      if (total != n) {
        run = MFREE_ERR_INTERNAL;
        snprintf(msg, sizeof msg, "%lld particles owned after the partition at T = %.3f, not %d", (long long)total,
                 T, n);
        break;
      }
    }
    if (vtu_dir && T >= vtu_next - 1e-9 * (1.0 + T)) {
      if ((files_bad = write_vtu(&series, &s, t)) != 0) break;
      while (vtu_next <= T + 1e-9 * (1.0 + T)) vtu_next += o.run.vtu_every;
    }
    if (dam.L - xmax[0] < 2.0 * d) break; /* the front reached the far wall */
  }
  double wall = MPI_Wtime() - clock0;
  MPI_Allreduce(MPI_IN_PLACE, &wall, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, &migrate_seconds, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  ex_progress_done(&prog, "mfree_mpi_dam_break", t);
  if (tty) fclose(tty);
  if (csv) files_bad |= (ferror(csv) != 0) | (fclose(csv) != 0);
  if (vtu_dir && series.comm) files_bad |= ex_pvtu_series_close(&series);
  files_bad = any(files_bad);
  if (files_bad && rank == 0) fprintf(stderr, "mfree_mpi_dam_break: error: an output file could not be written\n");
  if (run != MFREE_SUCCESS) {
    /* every rank holds the agreed status; rank 0 says it */
    if (!msg[0]) mfree_context_get_last_error(s.ctx, NULL, msg, sizeof msg);
    if (rank == 0)
      fprintf(stderr, "mfree_mpi_dam_break: error: the run stopped at T = %.4g (%s): %s\n", t * tscale,
              mfree_status_string(run), msg);
    exit_status = 3;
  } else if (files_bad) {
    exit_status = 1;
  }

  const double mass_err = lumped_mass_error(&s, &dam);

  /* ---- rank 0: the comparison with Martin & Moyce, plot, summary ---- */
  if (rank == 0 && !files_bad) {
    fc_front_cmp_t cmp;
    fc_front_compare(nf, fT, fZ, ndata, dT, dZ, &cmp);
    fc_dam_plot(&o.run, &dam, o.data, ndata, o.t_end);
    double worst = 0.0, least = INFINITY;
    for (int k = 0; k < nbal; ++k) worst = fmax(worst, balance[3 * k + 1]), least = fmin(least, balance[3 * k + 2]);
    const int balanced = nbal > 0 && worst <= 1.10 && least >= 0.90;
    fc_json_t js;
    fc_json_init(&js);
    const fc_dam_run_t info = {steps, wall, o.cfl, o.shepard, o.mu, t * tscale, o.scheme, run, msg};
    fc_dam_json(&js, &dam, nf, fT, fZ, fZf, &cmp, &info);
    fc_json_num(&js, "mass_rel_error", mass_err);
    fc_json_int(&js, "ranks", size);
    fc_json_str(&js, "partitioner", o.partitioner == MFREE_PARTITIONER_RCB ? "rcb" : "hsfc");
    fc_json_num(&js, "window", o.window);
    fc_json_num(&js, "halo_width", width);
    fc_json_int(&js, "no_slip", o.no_slip);
    fc_json_num(&js, "diffusion", o.diffusion);
    fc_json_table(&js, "balance", nbal, 3, balance);
    fc_json_num(&js, "max_count_ratio", nbal ? worst : NAN);
    fc_json_num(&js, "min_count_ratio", nbal ? least : NAN);
    fc_json_int(&js, "balanced", balanced);
    fc_json_int(&js, "partitions", nbal);
    fc_json_int(&js, "moved", moved);
    fc_json_num(&js, "migrate_seconds", migrate_seconds);
    fc_json_int(&js, "acoustic_step", o.acoustic_step);
    files_bad = fc_json_finish(&js, &o.run);
    if (!o.run.json_stdout) {
      printf("dam break on %d ranks: a = %g m, %d particles, %lld steps, %.1f s (%.2f s partitioning)\n", size, a, n,
             (long long)steps, wall, migrate_seconds);
      fc_dam_print(nf, fT, fZ, &cmp);
      if (nbal)
        printf("%d Zoltan partitions (%s), %lld particles moved; largest count %.3f x the mean, smallest %.3f x%s\n",
               nbal, o.partitioner == MFREE_PARTITIONER_RCB ? "RCB" : "HSFC", (long long)moved, worst, least,
               balanced ? "" : " (beyond 10 %)");
      printf("mass: the lumped masses' relative error %.2e; output in %s\n", mass_err, o.run.out);
    }
  }
  if (any(files_bad) && exit_status == 0) exit_status = 1;
  MPI_Allreduce(MPI_IN_PLACE, &exit_status, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);

  share_free(&s);
  mfree_context_destroy(&s.ctx);
  fc_dam_free(&dam);
  free(fT), free(fZ), free(fZf), free(balance);
  MPI_Finalize();
  return exit_status;
}
