/* Collapse of a water column (2D dam break) by the Galerkin-SPH fluid of paper 003
 * (Cueto-Felgueroso et al. 2004), surge front against Martin & Moyce (1952).
 *
 * Set-up. A column of width a and height 2a (Martin & Moyce's n^2 = 2; default
 * a = 0.05715 m = 2.25 in, their column) stands at the left end of a tank of length L =
 * --tank a (default 5a) and is released at t = 0. Everything else is paper 003 Sect. 7.1
 * (spec 003 section 3.1): particles on the cell-centred lattice of spacing d = a / nx,
 * h = 1.5 d, rho0 = 1000, gamma = 7, kappa = 100 rho0 (2 g H) / gamma with H = 2a (eq 125),
 * mu = 0.5, hydrostatic initial densities (eq 65), masses rho_i d^2, MLS with a linear
 * basis, nodal integration, Galerkin lumped mass (eq 56), leap-frog (eqs 108-110) with
 * the CFL step (eq 120), wall particles at spacing d/3 with normals into the fluid,
 * r0 = 0.7 h, A = 10 (eqs 122-124).
 *
 * Wall position. The walls are set back by d/2 from the fluid's edge (first particle
 * layer at d from the wall particles, r0 / r = 1.05): with the walls on the fluid's edge
 * the first layer starts at r0 / r = 2.1, where the Lennard-Jones term is 15 A / r and
 * the first kick throws the layer off (see tests/t702). The fluid's edge x = 0 is the
 * column's far face (Martin & Moyce's origin) and z = 0 the floor.
 *
 * Front. Z = (max_i x_i + d/2) / a over all fluid particles (a particle stands for the
 * cell of width d around it, so Z = 1 at t = 0), against T = t sqrt(2 g / a). The front
 * of the particles touching the floor (z_i < 1.5 d) is written to the CSV too.
 *
 * Output in DIR (--out, default dam_break_out): dam_break.pvd indexing dam_break_NNNN.vtu
 * (ASCII VTU: position, velocity = interpolated v_hat, pressure, density), front.csv,
 * front.gp and front.png (gnuplot on PATH, not --no-plot). With --json one JSON object on
 * stdout: {"front":[[T,Z],...],"max_rel_dev":..,"particles":..,"steps":..,
 * "wall_seconds":..,...}, where max_rel_dev is the largest |Z - Z_exp| / Z_exp over the
 * data points with 1 <= T <= 3 (Z linearly interpolated in T); -1 when no data file. */
#define _XOPEN_SOURCE 700
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <mfree.h>

#include "util.h"

static const double kG = 9.81, kRho0 = 1000.0, kGamma = 7.0;

typedef struct {
  double a, tank, t_end, cfl, mu, strength, offset, out_dt, vtu_dt;
  int nx, json, quiet, plot, vtu, scheme, lumping;
  const char *out_dir, *data;
} options_t;

static void usage(FILE *f) {
  fprintf(f,
          "usage: mfree_dam_break [options]\n"
          "  --nx N          particles across the column width a (default 24; 2N up its height)\n"
          "  --a A           column width in m (default 0.05715, Martin & Moyce's 2.25 in)\n"
          "  --tank L        tank length in units of a (default 5)\n"
          "  --tend T        end time in units of sqrt(a / (2 g)) (default 3.2)\n"
          "  --cfl C         CFL number of 003 eq 120 (default 0.5)\n"
          "  --mu MU         dynamic viscosity (default 0.5, paper 003)\n"
          "  --strength A    wall-force constant A (default 10, paper 003)\n"
          "  --offset F      walls set back by F d from the fluid's edge (default 0.5)\n"
          "  --scheme S      leapfrog (default) | pc (predictor-corrector)\n"
          "  --lumping L     galerkin (default, 003 eq 56) | physical (eq 58)\n"
          "  --data PATH     Martin & Moyce CSV (default: the repository's data/martin_moyce_1952.csv)\n"
          "  --out DIR       output directory (default dam_break_out)\n"
          "  --vtu-every T   VTU interval in units of T (default 0.25; 0 = no VTU)\n"
          "  --no-plot       do not run gnuplot\n"
          "  --quiet         no progress bar\n"
          "  --json          one JSON object on stdout\n");
}

static int parse(int argc, char **argv, options_t *o) {
  for (int i = 1; i < argc; ++i) {
    const char *s = argv[i];
    const int has = i + 1 < argc;
    if (!strcmp(s, "--help")) {
      usage(stdout);
      exit(0);
    } else if (!strcmp(s, "--json")) o->json = 1;
    else if (!strcmp(s, "--quiet")) o->quiet = 1;
    else if (!strcmp(s, "--no-plot")) o->plot = 0;
    else if (!strcmp(s, "--nx") && has) o->nx = atoi(argv[++i]);
    else if (!strcmp(s, "--a") && has) o->a = atof(argv[++i]);
    else if (!strcmp(s, "--tank") && has) o->tank = atof(argv[++i]);
    else if (!strcmp(s, "--tend") && has) o->t_end = atof(argv[++i]);
    else if (!strcmp(s, "--cfl") && has) o->cfl = atof(argv[++i]);
    else if (!strcmp(s, "--mu") && has) o->mu = atof(argv[++i]);
    else if (!strcmp(s, "--strength") && has) o->strength = atof(argv[++i]);
    else if (!strcmp(s, "--offset") && has) o->offset = atof(argv[++i]);
    else if (!strcmp(s, "--data") && has) o->data = argv[++i];
    else if (!strcmp(s, "--out") && has) o->out_dir = argv[++i];
    else if (!strcmp(s, "--vtu-every") && has) o->vtu_dt = atof(argv[++i]);
    else if (!strcmp(s, "--scheme") && has) {
      const char *v = argv[++i];
      if (!strcmp(v, "leapfrog")) o->scheme = MFREE_INTEGRATOR_LEAPFROG;
      else if (!strcmp(v, "pc")) o->scheme = MFREE_INTEGRATOR_PREDICTOR_CORRECTOR;
      else return 0;
    } else if (!strcmp(s, "--lumping") && has) {
      const char *v = argv[++i];
      if (!strcmp(v, "galerkin")) o->lumping = MFREE_LUMP_GALERKIN;
      else if (!strcmp(v, "physical")) o->lumping = MFREE_LUMP_PHYSICAL;
      else return 0;
    } else return 0;
  }
  return o->nx >= 2 && o->a > 0 && o->tank > 1 && o->t_end > 0 && o->cfl > 0 && o->cfl <= 1 &&
         o->mu >= 0 && o->strength >= 0 && o->offset >= 0 && o->vtu_dt >= 0;
}

/* Martin & Moyce points (T, Z); returns the count, 0 if the file is missing. */
static int read_data(const char *path, double *T, double *Z, int cap) {
  FILE *f = path ? fopen(path, "r") : NULL;
  if (!f) return 0;
  char line[512];
  int n = 0;
  while (fgets(line, sizeof line, f) && n < cap) {
    double t, z;
    if (line[0] == '#') continue;
    if (sscanf(line, "%lf,%lf", &t, &z) == 2) {
      T[n] = t;
      Z[n] = z;
      ++n;
    }
  }
  fclose(f);
  return n;
}

static int write_vtu(const char *path, int n, const double *y, const double *vhat, const double *p) {
  FILE *f = fopen(path, "w");
  if (!f) return 1;
  fprintf(f, "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" "
             "byte_order=\"LittleEndian\">\n<UnstructuredGrid>\n<Piece NumberOfPoints=\"%d\" "
             "NumberOfCells=\"%d\">\n<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" "
             "format=\"ascii\">\n", n, n);
  for (int i = 0; i < n; ++i) fprintf(f, "%.9g %.9g 0\n", y[2 * i], y[2 * i + 1]);
  fprintf(f, "</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int32\" Name=\"connectivity\" "
             "format=\"ascii\">\n");
  for (int i = 0; i < n; ++i) fprintf(f, "%d\n", i);
  fprintf(f, "</DataArray>\n<DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">\n");
  for (int i = 0; i < n; ++i) fprintf(f, "%d\n", i + 1);
  fprintf(f, "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
  for (int i = 0; i < n; ++i) fprintf(f, "1\n");
  fprintf(f, "</DataArray>\n</Cells>\n<PointData Scalars=\"pressure\" Vectors=\"velocity\">\n"
             "<DataArray type=\"Float64\" Name=\"velocity\" NumberOfComponents=\"3\" format=\"ascii\">\n");
  for (int i = 0; i < n; ++i) fprintf(f, "%.6g %.6g 0\n", vhat[2 * i], vhat[2 * i + 1]);
  fprintf(f, "</DataArray>\n<DataArray type=\"Float64\" Name=\"pressure\" format=\"ascii\">\n");
  for (int i = 0; i < n; ++i) fprintf(f, "%.6g\n", p[i]);
  fprintf(f, "</DataArray>\n<DataArray type=\"Float64\" Name=\"density\" format=\"ascii\">\n");
  for (int i = 0; i < n; ++i) fprintf(f, "%.8g\n", y[4 * n + i]);
  fprintf(f, "</DataArray>\n</PointData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
  return fclose(f) != 0;
}

#define CHECK(call)                                                               \
  do {                                                                            \
    const mfree_status_t st_ = (call);                                            \
    if (st_ != MFREE_SUCCESS) return ex_fail(ctx, "mfree_dam_break", st_, #call); \
  } while (0)

int main(int argc, char **argv) {
  options_t o = {0.05715, 5.0, 3.2, 0.5, 0.5, 10.0, 0.5, 0.05, 0.25,
                 24,      0,   0,   1,   1,   MFREE_INTEGRATOR_LEAPFROG, MFREE_LUMP_GALERKIN,
                 "dam_break_out", MFREE_DATA_DIR "/martin_moyce_1952.csv"};
  if (!parse(argc, argv, &o)) {
    usage(stderr);
    return 2;
  }
  o.vtu = o.vtu_dt > 0;
  if (mkdir(o.out_dir, 0777) != 0 && access(o.out_dir, W_OK) != 0) {
    fprintf(stderr, "mfree_dam_break: cannot create or write %s\n", o.out_dir);
    return 1;
  }

  /* ---- geometry and initial state (spec 003 section 3.1) ---- */
  const double a = o.a, H = 2.0 * a, L = o.tank * a, d = a / o.nx, h = 1.5 * d;
  const double kappa = 100.0 * kRho0 * 2.0 * kG * H / kGamma; /* 003 eq 125 */
  const double tscale = sqrt(2.0 * kG / a);                   /* T = t sqrt(2 g / a) */
  const int nx = o.nx, nz = 2 * o.nx, n = nx * nz;
  double *y = calloc(5 * (size_t)n, sizeof *y), *m = malloc((size_t)n * sizeof *m);
  double *vhat = malloc(2 * (size_t)n * sizeof *vhat), *p = malloc((size_t)n * sizeof *p);
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nx; ++i) {
      const int q = j * nx + i;
      const double z = (j + 0.5) * d;
      y[2 * q] = (i + 0.5) * d;
      y[2 * q + 1] = z;
      y[4 * n + q] = kRho0 * pow(1.0 + kRho0 * kG * (H - z) / kappa, 1.0 / kGamma); /* 003 eq 65 */
      m[q] = y[4 * n + q] * d * d;
    }
  /* walls: floor and both ends, spacing d/3, set back by offset * d, up to 1.5 H */
  const double off = o.offset * d, ws = d / 3.0, top = 1.5 * H;
  const int nb = (int)ceil((L + 2 * off) / ws) + 1, ns = (int)ceil((top + off) / ws);
  const int nw = nb + 2 * ns;
  double *wx = malloc(2 * (size_t)nw * sizeof *wx), *wn = malloc(2 * (size_t)nw * sizeof *wn);
  int k = 0;
  for (int q = 0; q < nb; ++q, ++k) {
    wx[2 * k] = -off + q * (L + 2 * off) / (nb - 1);
    wx[2 * k + 1] = -off;
    wn[2 * k] = 0.0;
    wn[2 * k + 1] = 1.0;
  }
  for (int q = 1; q <= ns; ++q)
    for (int side = 0; side < 2; ++side, ++k) {
      wx[2 * k] = side ? L + off : -off;
      wx[2 * k + 1] = -off + q * (top + off) / ns;
      wn[2 * k] = side ? -1.0 : 1.0;
      wn[2 * k + 1] = 0.0;
    }

  mfree_context_t *ctx = NULL;
  if (mfree_context_create(&ctx) != MFREE_SUCCESS) return 1;
  mfree_system_t *sys = NULL;
  CHECK(mfree_system_create_fluid(ctx, 2, n, &sys));
  CHECK(mfree_system_set_fluid(sys, &kRho0, 0, kappa, kGamma, o.mu));
  CHECK(mfree_system_set_masses(sys, m, 1));
  CHECK(mfree_system_set_smoothing(sys, h));
  const double g[2] = {0.0, -kG};
  CHECK(mfree_system_set_gravity(sys, g));
  CHECK(mfree_system_set_lumping(sys, (mfree_lumping_t)o.lumping));
  CHECK(mfree_system_set_walls(sys, nw, wx, wn, 0.7 * h, o.strength)); /* 003 Sect. 6.2 */
  const double lo[2] = {-off, -off}, hi[2] = {L + off, 10.0 * H}; /* crossing a wall fails */
  CHECK(mfree_system_set_box(sys, lo, hi));
  double mass0 = 0.0;
  for (int q = 0; q < n; ++q) mass0 += m[q];

  /* ---- run ---- */
  double dT[64], dZ[64];
  const int ndata = read_data(o.data, dT, dZ, 64);
  if (!ndata && !o.quiet)
    fprintf(stderr, "mfree_dam_break: no Martin & Moyce data at %s; the comparison is skipped\n", o.data);
  char path[4096];
  snprintf(path, sizeof path, "%s/front.csv", o.out_dir);
  FILE *csv = fopen(path, "w");
  snprintf(path, sizeof path, "%s/dam_break.pvd", o.out_dir);
  FILE *pvd = o.vtu ? fopen(path, "w") : NULL;
  if (!csv || (o.vtu && !pvd)) {
    fprintf(stderr, "mfree_dam_break: cannot write in %s\n", o.out_dir);
    return 1;
  }
  fprintf(csv, "# Martin & Moyce dam break, a = %g m, nx = %d, %d particles\n"
               "# T = t sqrt(2 g / a), Z = (max x + d/2) / a, Z_floor: particles with z < 1.5 d\n"
               "T,Z,Z_floor,t,steps\n", a, nx, n);
  if (pvd) fprintf(pvd, "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n");

  const int nout = (int)floor(o.t_end / o.out_dt + 1e-9);
  double *fT = malloc((size_t)(nout + 1) * sizeof *fT), *fZ = malloc((size_t)(nout + 1) * sizeof *fZ);
  int nf = 0, nvtu = 0;
  double t = 0.0, next_vtu = 0.0;
  int64_t steps = 0;
  mfree_status_t run = MFREE_SUCCESS;
  ex_progress_t prog;
  ex_progress_init(&prog, o.quiet, 0.0, o.t_end / tscale);
  struct timespec c0, c1;
  clock_gettime(CLOCK_MONOTONIC, &c0);
  for (int io = 0; io <= nout; ++io) {
    const double T_target = io * o.out_dt;
    if (io > 0) {
      int64_t ns_ = 0;
      run = mfree_system_integrate(sys, (mfree_integrator_t)o.scheme, y, &t, T_target / tscale, o.cfl, 0.0,
                                   ex_progress, &prog, &ns_);
      steps += ns_;
      ex_progress_steps(&prog, ns_);
      if (run != MFREE_SUCCESS) break;
    }
    double xmax = -1e300, xfloor = -1e300;
    for (int q = 0; q < n; ++q) {
      if (y[2 * q] > xmax) xmax = y[2 * q];
      if (y[2 * q + 1] < 1.5 * d && y[2 * q] > xfloor) xfloor = y[2 * q];
    }
    const double T = t * tscale, Z = (xmax + 0.5 * d) / a, Zf = (xfloor + 0.5 * d) / a;
    fT[nf] = T;
    fZ[nf++] = Z;
    fprintf(csv, "%.4f,%.5f,%.5f,%.6f,%lld\n", T, Z, Zf, t, (long long)steps);
    if (pvd && T >= next_vtu - 1e-9) {
      CHECK(mfree_system_get_velocity(sys, y, vhat));
      CHECK(mfree_system_get_pressure(sys, y, p));
      snprintf(path, sizeof path, "%s/dam_break_%04d.vtu", o.out_dir, nvtu);
      if (write_vtu(path, n, y, vhat, p)) {
        fprintf(stderr, "mfree_dam_break: cannot write %s\n", path);
        return 1;
      }
      fprintf(pvd, "<DataSet timestep=\"%.6f\" group=\"\" part=\"0\" file=\"dam_break_%04d.vtu\"/>\n", t, nvtu);
      ++nvtu;
      next_vtu += o.vtu_dt;
    }
    if (L - xmax < 2.0 * d) break; /* the front reached the far wall */
  }
  clock_gettime(CLOCK_MONOTONIC, &c1);
  const double wall = (double)(c1.tv_sec - c0.tv_sec) + 1e-9 * (double)(c1.tv_nsec - c0.tv_nsec);
  ex_progress_done(&prog, "mfree_dam_break", t);
  fclose(csv);
  if (pvd) {
    fprintf(pvd, "</Collection>\n</VTKFile>\n");
    fclose(pvd);
  }
  char msg[1024] = "";
  if (run != MFREE_SUCCESS) mfree_context_get_last_error(ctx, NULL, msg, sizeof msg);

  /* ---- mass: constant particle masses, none lost (the box), and the Galerkin lumped
   * masses summing to the total (003 eq 57) ---- */
  mfree_matrix_t *M = NULL;
  double lumped = 0.0, mass1 = 0.0;
  for (int q = 0; q < n; ++q) mass1 += m[q];
  CHECK(mfree_system_assemble_mass(sys, y, 0, &M));
  const int64_t *rp;
  const int32_t *ci;
  const double *mv;
  CHECK(mfree_matrix_get_csr(M, &rp, &ci, &mv));
  for (int q = 0; q < n; ++q) lumped += mv[rp[2 * n + 2 * q]];
  mfree_matrix_destroy(&M);
  const double mass_err = fmax(fabs(mass1 - mass0), fabs(lumped - mass0)) / mass0;

  /* ---- comparison with Martin & Moyce (1 <= T <= 3) ---- */
  double maxdev = -1.0;
  int compared = 0;
  for (int q = 0; q < ndata; ++q) {
    if (dT[q] < 1.0 || dT[q] > 3.0) continue;
    for (int r = 0; r + 1 < nf; ++r)
      if (fT[r] <= dT[q] && fT[r + 1] >= dT[q]) {
        const double w = (dT[q] - fT[r]) / (fT[r + 1] - fT[r]);
        const double Zs = (1 - w) * fZ[r] + w * fZ[r + 1];
        maxdev = fmax(maxdev, fabs(Zs - dZ[q]) / dZ[q]);
        ++compared;
        break;
      }
  }
  if (ndata && !compared) maxdev = -1.0;

  /* ---- plot: the front against the experiment ---- */
  char gp_path[4096] = "", png_path[4096] = "", csv_path[4096] = "";
  ex_join(gp_path, sizeof gp_path, o.out_dir, "front.gp");
  ex_join(png_path, sizeof png_path, o.out_dir, "front.png");
  ex_join(csv_path, sizeof csv_path, o.out_dir, "front.csv");
  if (o.plot && ex_plot_path_ok(png_path) && ex_plot_path_ok(o.data)) {
    FILE *gp = fopen(gp_path, "w");
    if (gp) {
      fprintf(gp, "set terminal pngcairo size 800,560\nset output '%s'\nset datafile separator ','\n"
                  "set key top left\nset grid\nset xlabel 'T = t (2g/a)^{1/2}'\nset ylabel 'Z = z/a'\n"
                  "set title 'Dam break, n^2 = 2: Galerkin SPH (Cueto-Felgueroso et al. 2004) vs Martin and Moyce (1952)'\n"
                  "set xrange [0:%g]\n"
                  "plot '%s' using 1:2 with lines lw 2 title 'front, all particles (%d)', "
                  "'%s' using 1:3 with lines dt 2 title 'front, particles on the floor'",
              png_path, o.t_end + 0.5, csv_path, n, csv_path);
      if (ndata) fprintf(gp, ", '%s' using 1:2 with points pt 7 title 'Martin and Moyce (1952), n^2 = 2'", o.data);
      fprintf(gp, "\n");
      fclose(gp);
      ex_plot(gp_path, png_path, csv_path, o.json ? stderr : stdout);
    }
  }

  if (o.json) {
    printf("{\"front\":[");
    for (int q = 0; q < nf; ++q) printf("%s[%.4f,%.5f]", q ? "," : "", fT[q], fZ[q]);
    printf("],\"max_rel_dev\":%.5f,\"compared\":%d,\"particles\":%d,\"steps\":%lld,\"wall_seconds\":%.2f,"
           "\"mass_rel_error\":%.3e,\"a\":%g,\"nx\":%d,\"status\":%d,\"t_end\":%.5f}\n",
           maxdev, compared, n, (long long)steps, wall, mass_err, a, nx, (int)run, t * tscale);
  } else {
    printf("dam break: a = %g m, %d particles, %lld steps, %.1f s\n", a, n, (long long)steps, wall);
    for (int q = 0; q < nf; q += 4) printf("  T = %5.2f  Z = %6.3f\n", fT[q], fZ[q]);
    if (maxdev >= 0) printf("max |Z - Z_exp| / Z_exp over 1 <= T <= 3: %.3f (%d points)\n", maxdev, compared);
    printf("mass: relative error %.2e; output in %s\n", mass_err, o.out_dir);
  }
  if (run != MFREE_SUCCESS) fprintf(stderr, "mfree_dam_break: stopped at T = %.3f: %s\n", t * tscale, msg);
  mfree_system_destroy(&sys);
  mfree_context_destroy(&ctx);
  free(y);
  free(m);
  free(vhat);
  free(p);
  free(wx);
  free(wn);
  free(fT);
  free(fZ);
  return run == MFREE_SUCCESS ? 0 : 3;
}
