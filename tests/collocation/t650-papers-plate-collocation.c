/* t650: paper 001 (Zhang & Batra, Comput Mech 43 (2009) 321-340) Sect. 6.3, the plate
 * with a circular hole under remote tension (Kirsch), by strong-form collocation
 * (MFREE_FORM_COLLOCATION_PLANE_STRAIN) with SSPH and MSPH shape functions and UMFPACK;
 * the errata and choices of docs/papers.md, paper 001. The problem code is the
 * example's (examples/plate_collocation/plate.c): quarter plate [0, 10]^2, hole radius
 * 1, E = 1, nu = 0.25, sigma0 = 1, revised super Gauss a = 1.6, quadratic basis,
 * h_i = 1.5 Delta_i; rings graded from a radially refined layer at the hole (first
 * radial step 0.6 of the hole spacing, plate.h radial_step); 11, 21 and 31 particles on
 * the quarter hole (203, 679 and 1502 particles; the paper: 188 with 11 and 686 with 21).
 *
 * The paper's plate size, hole radius and particle arrangement are unknown
 * (docs/papers.md, paper 001, choices 5), so its error norms (SSPH 0.0216 / 0.0044, MSPH 0.0304 / 0.0050) are not
 * compared directly; the checks are the paper's claims that do not depend on them.
 *
 * The layer at the hole decides the paper's ordering SSPH <= MSPH. With radial_step 0.6
 * SSPH is below MSPH at every resolution from 9 to 31 particles on the hole (ratios
 * 0.87 / 0.55 / 0.56 at 203 / 679 / 1502) and, at 11 and 21 on the hole, on the plate
 * sizes b = 5, 8, 10, 12, 15 a, with every corner rule, with the Dirichlet rows on the
 * nodal values and with h_ij = (h_i + h_j)/2 (ratios 0.60-0.93 at ~200 particles,
 * 0.47-0.59 at ~700); radial_step 0.5 and 0.55 behave alike. With square cells at the
 * hole (radial_step 1, the default until this recheck) MSPH wins at the paper's
 * resolutions, and from 0.7 up the ordering is lost somewhere (0.7: 0.80 / 0.67 but 1.23
 * at 1486; 0.75: 7.8 / 0.93; 0.8: 1.03 / 1.08; 0.9: 1.11 / 0.84): the rings' first gap
 * is 1.46 times larger at 45 degrees than on the axes, so with square cells on the axes
 * the hole particles at 45 degrees (h_i = 1.5 Delta_i set by the hole spacing) reach
 * only one ring inwards and take the normal curvature of their quadratic
 * fit from the hole's own curvature (radial-derivative stencil sum |N| h 11.4 against
 * 5.4 with 0.6, which reaches two rings); their traction rows then leave residuals up to
 * 0.52 on the exact field, to which SSPH's solve responds more than MSPH's. The paper's
 * "coarser with the distance from the hole" (Figs. 11, 13 missing) allows both; 0.6 is
 * the middle of the range where the ordering holds whatever else is chosen.
 *
 * Square-cell rings and the other arrangements measured, e(u2) SSPH / MSPH,
 * default corner rows:
 *   rings b = 10, radial_step 1  209: 0.189 / 0.075  677: 0.0210 / 0.0150  1492: 0.0076 / 0.0103
 *   same, b = 5              142: 0.455 / 0.139   472: 0.0537 / 0.0111  1063: 0.0270 / 0.0092
 *   rays b = 10 (11x17 ...)  187: 0.149 / 0.131   693: 0.0487 / 0.0353  1519: 0.0236 / 0.0166
 *   polar rays b = 10        187: 0.644 / 0.117   693: 0.0465 / 0.0384  1519: 0.0236 / 0.0205
 *   rays b = 10 with the axis ray's spacings as fractions on every ray (not the default
 *   square cells at the whole hole): 187: 0.137 / 0.091, 693: 0.0518 / 0.0331, 1519:
 *   0.0221 / 0.0097
 *   rays b = 9: 187: 0.150 / 0.132 (693 singular); b = 11: 0.141 / 0.123, 0.0438 / 0.0352;
 *   b = 12: 0.131 / 0.123, 0.0408 / 0.0310; b = 15: 0.119 / 0.127, 0.0359 / 0.0254
 *   rays on b = 5 to 8 (the standard b = 5 a of paper 000 included) and polar rays on
 *   b = 5: the quadratic fit is singular at some particles with h_i = 1.5 Delta_i
 *   (tested below).
 *   rays b = 10 with other supports (not the paper's 1.5; recorded, not used):
 *   h_i = 1.3 Delta_i singular; 1.7: 187: 0.0518 / 0.0578, 693: 0.0279 / 0.0311 (SSPH
 *   below MSPH at both); 2.0: 0.0435 / 0.0664, 0.0137 / 0.0114.
 * The ruled rays match the paper's counts best (188 = 11 x 17 + 1, 686 ~ 21 x 33) and
 * b = 10 a is where their square cells end (plate.c); on them SSPH is above MSPH at
 * every resolution. Hole-corner rows (plate.h, PLATE_CORNER_*), rings 209 / 677:
 * symmetry 0.0792 / 0.0807, 0.0208 / 0.0178; hole 0.0883 / 0.0876, 0.0201 / 0.0206; on
 * the rays SSPH stays above MSPH with each. Not the shape functions: applied to the
 * exact Kirsch field the SSPH Navier rows leave a smaller residual than MSPH's (interior
 * max / rms 0.227 / 0.039 against 0.266 / 0.048 at 209 rings, 0.213 / 0.026 against
 * 0.239 / 0.030 at 677; rays 187: 0.181 against 0.229) and the same gradient error at
 * the boundary (0.72 at 209); the largest solution errors sit on the hole near 45
 * degrees (u_1 off by 0.35 SSPH, 0.25 MSPH at 209), so the collocation system amplifies
 * SSPH's truncation error more than MSPH's at these resolutions. Split by rows (the
 * error K^-1 r of each group's share of the residual r = f - K u_exact, axis norm of
 * u_2): rings 209, hole rows 0.178 SSPH against 0.047 MSPH from equal residuals (0.52);
 * rays 693, interior rows 0.0187 against 0.0098 from a smaller SSPH residual (0.157
 * against 0.185). The norm with the nodal values instead of the estimates differs by
 * < 1 %.
 *
 * Rechecked (the choices the paper leaves open), SSPH/MSPH error ratio at the
 * paper's two resolutions, square-cell rings 209 / 677 and rays 187 / 693 (b = 10 a):
 *   as above (u on the estimate, gather h_i, corner rows "dirichlet"): 2.52 / 1.40, 1.14 / 1.38
 *   u_1 = 0, u_2 = 0 on the nodal unknowns:                           3.13 / 1.36, 0.87 / 1.37
 *   h_ij = (h_i + h_j)/2 (MFREE_SEARCH_SYMMETRIC_MEAN):                4.04 / 2.76, 0.95 / 1.07
 *   h_ij = max(h_i, h_j):                                              11.1 / 5.02, 0.11 / 0.89
 *     (the latter with MSPH 1.69 at 187: a broken solve, not a better SSPH)
 *   all 36 combinations of {estimate, nodal} x {gather, mean} x {3 corner rules} on
 *   square-cell rings, rays and a log-polar grid r_k = a (1 + dtheta)^k clipped at the
 *   square (b = 9.75 a: 191 / 684 particles, the paper's 188 / 686 within 2 %): none has
 *   SSPH <= MSPH at both resolutions (closest: rings, "hole" corners, 1.01 / 0.97);
 *   plate sizes b = 8 ... 15 a: square-cell rings 1.98-3.26 at ~200 and 0.99-1.68 at
 *   ~700, rays 0.94-1.15 at 187 and 1.24-1.42 at 693; SSPH's SCF at ~200 is 3.9-4.7 on all of them
 *   (MSPH 2.8-3.2);
 *   rings with the first radial step a dtheta on every ray (square cells along the whole
 *   hole; the square-cell rings have them only on the axes, and at 45 degrees the hole
 *   particles' supports reach one ring inwards, the normal curvature of their fit then
 *   coming from the hole's own curvature): 193 / 655 / 1438: 1.87 / 1.28 / 1.13;
 *   V_j = 1 instead of the cell areas: rings 0.71 / 3.88, rays 1.70 / 1.42, log-polar
 *   1.89 / 1.25.
 * Checked and not the cause: the fit at every particle (boundary and hole included)
 * reproduces value, gradient and Hessian of a quadratic (test below), MSPH's weights are
 * W and its first and second xi-derivatives (001 eq 2.9) and the 1D tables anchor both
 * methods (t410), Delta_i is the nearest distance (which always lies in the support).
 * Where SSPH loses: swapping one row group of the SSPH system for MSPH's, square-cell
 * rings 209: the 18 hole traction rows (corners apart) take SSPH from 0.190 to 0.062
 * (MSPH 0.074; the other groups change it < 25 %), although both methods' hole rows
 * leave the same residual on the exact field (up to 0.52 at 45 degrees, sum 1.37 vs
 * 1.15); rays 187 / 693: the interior Navier rows (0.150 -> 0.122, 0.049 -> 0.043). The absolute numbers are not
 * comparable with the paper's: e(u_2) is dimensional, scaling exactly as a^{3/2} with
 * the hole radius a at a fixed shape (test below), and the paper gives no radius; with
 * a = 0.3 the square-cell rings give 0.031 / 0.012 and 0.0034 / 0.0025, the default
 * rings 0.0153 / 0.0175 and 0.0020 / 0.0037 (the paper 0.0216 / 0.0304 and 0.0044 /
 * 0.0050). Only the ratios and the rates are comparable. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "plate.h"
#include "testutil.h"

enum { NRES = 3, NM = 2 };
static const int kHole[NRES] = {11, 21, 31};
static const char *const kName[NM] = {"SSPH", "MSPH"};
static const double kPi = 3.14159265358979323846;

/* The ruled arrangement of the paper's counts (PLATE_LAYOUT_RAYS, b = 10 a): 11 and 21
 * rays of 17 and 33 particles. */
enum { NRAY = 2 };
static const int kRays[NRAY] = {11, 21};

typedef struct {
  mfree_context_t *ctx;
  plate_config_t cfg[NRES];
  plate_result_t res[NRES][NM];
  plate_result_t ray[NRAY][NM];
} fixture_t;

static void ray_config(plate_config_t *c, int nt, double b) {
  plate_config_default(c, nt, plate_ray_particles(nt));
  c->layout = PLATE_LAYOUT_RAYS;
  c->b = b;
}

static void solve_or_fail(fixture_t *f, plate_config_t *cfg, plate_result_t *res) {
  const mfree_status_t st = plate_solve(f->ctx, cfg, res);
  if (st != MFREE_SUCCESS) {
    char msg[1024] = "";
    mfree_context_get_last_error(f->ctx, NULL, msg, sizeof msg);
    fail_msg("plate_solve (method %d, %d on the hole) returned %d: %s (%d failed sites)",
             (int)cfg->method, cfg->nt, (int)st, msg, (int)res->nfailed);
  }
}

/* In the group setup (no cmocka assertions there): 1 if the plate was solved, else the
 * message on stderr and 0. */
static int solved_quietly(fixture_t *f, plate_config_t *cfg, plate_result_t *res, const char *what) {
  if (plate_solve(f->ctx, cfg, res) == MFREE_SUCCESS) return 1;
  char msg[1024] = "";
  mfree_context_get_last_error(f->ctx, NULL, msg, sizeof msg);
  fprintf(stderr, "plate_solve (%s) failed: %s\n", what, msg);
  return 0;
}

/* All solves once (about a second); the tests read the results. */
static int group_setup(void **state) {
  fixture_t *f = calloc(1, sizeof *f);
  if (!f || mfree_context_create(&f->ctx) != MFREE_SUCCESS) return 1;
  for (int k = 0; k < NRES; ++k) {
    plate_config_default(&f->cfg[k], kHole[k], 0);
    for (int m = 0; m < NM; ++m) {
      plate_config_t c = f->cfg[k];
      c.method = m ? MFREE_METHOD_MSPH : MFREE_METHOD_SSPH;
      if (!solved_quietly(f, &c, &f->res[k][m], "rings")) return 1;
    }
  }
  for (int k = 0; k < NRAY; ++k)
    for (int m = 0; m < NM; ++m) {
      plate_config_t c;
      ray_config(&c, kRays[k], 10.0);
      c.method = m ? MFREE_METHOD_MSPH : MFREE_METHOD_SSPH;
      if (!solved_quietly(f, &c, &f->ray[k][m], "rays")) return 1;
    }
  *state = f;
  return 0;
}

static int group_teardown(void **state) {
  fixture_t *f = *state;
  if (!f) return 0;
  for (int k = 0; k < NRES; ++k)
    for (int m = 0; m < NM; ++m) plate_result_free(&f->res[k][m]);
  for (int k = 0; k < NRAY; ++k)
    for (int m = 0; m < NM; ++m) plate_result_free(&f->ray[k][m]);
  mfree_context_destroy(&f->ctx);
  free(f);
  return 0;
}

/* ---- the analytic solution (001 eq 6.18, docs/papers.md, paper 001, errata 2) -------- */

static void kirsch_solution(void **state) {
  (void)state;
  const double a = 1.0, E = 1.0, nu = 0.25, s0 = 1.0;
  const double lam = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
  double s[3], u[2];
  /* sigma_11(0, a) = 3 sigma0, the stress concentration factor */
  plate_kirsch_stress(a, s0, 0.0, a, s);
  assert_true(fabs(s[0] - 3.0) < 1e-14);
  const double pts[4][2] = {{1.3, 0.4}, {0.2, 2.5}, {3.0, 3.0}, {7.5, 1.1}};
  for (int q = 0; q < 4; ++q) {
    const double x = pts[q][0], y = pts[q][1], d = 1e-5;
    /* plane-strain Hooke's law of the displacements (central differences) gives the
     * stresses: the corrected (6.18), docs/papers.md, paper 001, errata 2 */
    double up[2], um[2], vp[2], vm[2];
    plate_kirsch_displacement(a, s0, E, nu, x + d, y, up);
    plate_kirsch_displacement(a, s0, E, nu, x - d, y, um);
    plate_kirsch_displacement(a, s0, E, nu, x, y + d, vp);
    plate_kirsch_displacement(a, s0, E, nu, x, y - d, vm);
    const double e11 = (up[0] - um[0]) / (2 * d), e22 = (vp[1] - vm[1]) / (2 * d);
    const double g12 = (vp[0] - vm[0]) / (2 * d) + (up[1] - um[1]) / (2 * d);
    plate_kirsch_stress(a, s0, x, y, s);
    if (!(fabs((lam + 2 * mu) * e11 + lam * e22 - s[0]) < 1e-8 &&
          fabs(lam * e11 + (lam + 2 * mu) * e22 - s[1]) < 1e-8 && fabs(mu * g12 - s[2]) < 1e-8))
      fail_msg("001 eq 6.18 corrected: Hooke's law of u differs from sigma at (%g, %g)", x, y);
  }
  /* traction-free hole: sigma_rr = sigma_rtheta = 0 at r = a */
  for (int q = 0; q <= 8; ++q) {
    const double th = 0.5 * kPi * q / 8, c = cos(th), sn = sin(th);
    plate_kirsch_stress(a, s0, a * c, a * sn, s);
    const double srr = s[0] * c * c + s[1] * sn * sn + 2 * s[2] * c * sn;
    const double srt = (s[1] - s[0]) * c * sn + s[2] * (c * c - sn * sn);
    assert_true(fabs(srr) < 1e-13 && fabs(srt) < 1e-13);
  }
  /* symmetry: u_1 = 0 on x = 0, u_2 = 0 on y = 0; u_2 on the x_2 axis is the paper's
   * theta = pi/2 formula (Sect. 6.3), (1 + nub)/Eb sigma0 (-nub/(1 + nub) x2 - (1 - nub)/(1 + nub)
   * b^2/x2 - b^2/(2 x2) + b^4/(2 x2^3)), nub = nu/(1 - nu), Eb = E/(1 - nu^2) */
  const double Eb = E / (1 - nu * nu), nub = nu / (1 - nu);
  for (int q = 0; q < 6; ++q) {
    const double r = 1.0 + 1.7 * q;
    plate_kirsch_displacement(a, s0, E, nu, 0.0, r, u);
    const double want = (1 + nub) / Eb * s0 *
                        (-nub / (1 + nub) * r - (1 - nub) / (1 + nub) / r - 0.5 / r +
                         0.5 / (r * r * r));
    assert_true(fabs(u[0]) < 1e-14 && fabs(u[1] - want) < 1e-13);
    plate_kirsch_displacement(a, s0, E, nu, r, 0.0, u);
    assert_true(fabs(u[1]) < 1e-14);
  }
}

/* ---- the discrete problem -------------------------------------------------------------- */

/* 2 N equations for N particles (001 Sect. 6.3), every site set up, a solved system. */
static void system_size_and_solve(void **state) {
  fixture_t *f = *state;
  for (int k = 0; k < NRES; ++k)
    for (int m = 0; m < NM; ++m) {
      const plate_result_t *r = &f->res[k][m];
      assert_int_equal(r->neq, 2 * r->n);
      assert_int_equal(r->nfailed, 0);
      assert_true(r->min_neighbors >= 6); /* a quadratic basis in 2D needs 6 */
      if (!(r->residual < 1e-9))
        fail_msg("%s, %d particles: relative residual %.3e", kName[m], r->n, r->residual);
    }
  /* the arrangement: 11 and 21 particles on the quarter hole as in the paper */
  assert_int_equal(f->res[0][0].n, 203);
  assert_int_equal(f->res[1][0].n, 679);
}

/* Uniform tension (its tractions also on the hole) is a linear displacement field:
 * quadratic shape functions reproduce it, so collocation must return it to round-off.
 * Checks the Navier rows, the traction rows with their normals and the Dirichlet rows
 * that replace one component of the symmetry lines' traction rows. */
static void patch_test(void **state) {
  fixture_t *f = *state;
  for (int m = 0; m < 2 * NM; ++m) { /* rings, then rays */
    plate_config_t c = f->cfg[0];
    if (m >= NM) ray_config(&c, kRays[0], 10.0);
    c.method = m % NM ? MFREE_METHOD_MSPH : MFREE_METHOD_SSPH;
    c.patch = 1;
    plate_result_t r;
    solve_or_fail(f, &c, &r);
    if (!(r.max_err_u < 1e-10 && fabs(r.scf - 1.0) < 1e-10))
      fail_msg("%s patch test (%s): max |u^h - u| = %.3e, s11(0, a) = %.15g", kName[m % NM],
               m < NM ? "rings" : "rays", r.max_err_u, r.scf);
    plate_result_free(&r);
  }
}

/* The boundary rows hold in the solution: u_2 = 0 on y = 0 and u_1 = 0 on x = 0
 * (Dirichlet rows act on the estimate sum_j Phi_j u_j), sigma n = 0 on the hole for the
 * components not replaced by a Dirichlet row, exact tractions on the outer edges. */
static void check_boundary_rows(const plate_result_t *r, const char *name) {
  const double *x = r->x;
  double worst = 0.0;
  for (int p = 0; p < r->n; ++p) {
    const int32_t t = r->tag[p];
    const double *s = &r->stress[3 * p];
    if (t & PLATE_SYM_Y0) worst = fmax(worst, fabs(r->uh[2 * p + 1]));
    if (t & PLATE_SYM_X0) worst = fmax(worst, fabs(r->uh[2 * p]));
    double n[2] = {0, 0}, want[2] = {0, 0};
    if (t & PLATE_HOLE) {
      n[0] = -x[2 * p], n[1] = -x[2 * p + 1];
    } else if (t & (PLATE_EDGE_XB | PLATE_EDGE_YB)) {
      n[0] = (t & PLATE_EDGE_XB) ? 1.0 : 0.0;
      n[1] = (t & PLATE_EDGE_YB) ? 1.0 : 0.0;
      const double len = hypot(n[0], n[1]);
      n[0] /= len, n[1] /= len;
      double se[3];
      plate_kirsch_stress(1.0, 1.0, x[2 * p], x[2 * p + 1], se);
      want[0] = se[0] * n[0] + se[2] * n[1];
      want[1] = se[2] * n[0] + se[1] * n[1];
    } else {
      continue;
    }
    const double tr[2] = {s[0] * n[0] + s[2] * n[1], s[2] * n[0] + s[1] * n[1]};
    if (!(t & PLATE_SYM_X0)) worst = fmax(worst, fabs(tr[0] - want[0]));
    if (!(t & PLATE_SYM_Y0)) worst = fmax(worst, fabs(tr[1] - want[1]));
  }
  if (!(worst < 1e-9))
    fail_msg("%s, %d particles: a boundary row is violated by %.3e", name, r->n, worst);
}

static void boundary_rows_hold(void **state) {
  fixture_t *f = *state;
  for (int m = 0; m < NM; ++m) {
    for (int k = 0; k < NRES; ++k) check_boundary_rows(&f->res[k][m], kName[m]);
    for (int k = 0; k < NRAY; ++k) check_boundary_rows(&f->ray[k][m], kName[m]);
  }
}

/* ---- the paper's claims ---------------------------------------------------------------- */

/* The error norm is dimensional: at a fixed shape (b / a, the same layout and
 * h_i = 1.5 Delta_i), every length scaled by s scales the discrete solution by s (the
 * shape functions' derivatives by 1/s, the normalisation and the volumes cancel), so
 * e(u_2) = sqrt(int e^2 dx_2) scales by s^{3/2} and the stress concentration not at all.
 * The paper gives no hole radius, so its absolute errors fix no scale. */
static void error_scales_with_hole_radius(void **state) {
  fixture_t *f = *state;
  const double s = 0.3;
  for (int m = 0; m < NM; ++m) {
    plate_config_t c = f->cfg[0];
    c.method = m ? MFREE_METHOD_MSPH : MFREE_METHOD_SSPH;
    c.a *= s;
    c.b *= s;
    plate_result_t r;
    solve_or_fail(f, &c, &r);
    const plate_result_t *r1 = &f->res[0][m];
    const double want = r1->err_u2 * pow(s, 1.5);
    assert_int_equal(r.n, r1->n);
    if (!(fabs(r.err_u2 - want) <= 1e-8 * want && fabs(r.scf - r1->scf) <= 1e-8 * r1->scf))
      fail_msg("%s: e(u2) %.12e at a = %g, expected %.12e (a = 1: %.12e); SCF %.12g vs %.12g",
               kName[m], r.err_u2, s, want, r1->err_u2, r.scf, r1->scf);
    plate_result_free(&r);
  }
}

/* The traction rows at boundary particles use the particle's own fit: it must be the full
 * quadratic one there too (value, gradient and Hessian of a quadratic reproduced at every
 * particle, the hole and the corners included), for both methods and arrangements. */
static void boundary_fits_are_complete(void **state) {
  fixture_t *f = *state;
  for (int lay = 0; lay < 2; ++lay)
    for (int m = 0; m < NM; ++m) {
      plate_config_t c = f->cfg[0];
      if (lay) ray_config(&c, kRays[0], 10.0);
      int n = 0;
      double *x = NULL, *v = NULL, *h = NULL;
      int32_t *tag = NULL;
      assert_int_equal(plate_particles(&c, &n, &x, &v, &h, &tag), 0);
      mfree_particles_t *ps = NULL;
      mfree_approximant_t *ap = NULL;
      assert_ok(f->ctx, mfree_particles_create(f->ctx, 2, n, &ps));
      assert_ok(f->ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 2, MFREE_COPY));
      assert_ok(f->ctx, mfree_particles_set_volumes(ps, v, 1, MFREE_COPY));
      assert_ok(f->ctx, mfree_particles_set_support(ps, h, 1, MFREE_COPY));
      assert_ok(f->ctx, mfree_particles_setup(ps));
      const mfree_method_t meth = m ? MFREE_METHOD_MSPH : MFREE_METHOD_SSPH;
      assert_ok(f->ctx, mfree_approximant_create(f->ctx, ps, meth, &ap));
      assert_ok(f->ctx, mfree_approximant_set_kernel(ap, MFREE_KERNEL_REVISED_SUPER_GAUSS, 1.6));
      assert_ok(f->ctx, mfree_approximant_set_order(ap, 2));
      assert_ok(f->ctx, mfree_approximant_set_derivatives(
                            ap, MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT | MFREE_DERIV_HESSIAN));
      assert_ok(f->ctx, mfree_approximant_setup(ap));
      double *q = malloc(sizeof(double) * 7 * (size_t)n); /* field, value, gradient, Hessian */
      assert_non_null(q);
      double *val = q + n, *g = q + 2 * n, *H = q + 4 * n;
      for (int p = 0; p < n; ++p) {
        const double X = x[2 * p], Y = x[2 * p + 1];
        q[p] = 0.3 + 0.7 * X - 0.2 * Y + 0.5 * X * X - 0.8 * X * Y + 0.9 * Y * Y;
      }
      assert_ok(f->ctx, mfree_approximant_apply(ap, MFREE_OP_VALUE, 1, q, MFREE_LAYOUT_AOS, 1, val,
                                                MFREE_LAYOUT_AOS, 1));
      assert_ok(f->ctx, mfree_approximant_apply(ap, MFREE_OP_GRADIENT, 1, q, MFREE_LAYOUT_AOS, 1, g,
                                                MFREE_LAYOUT_AOS, 2));
      assert_ok(f->ctx, mfree_approximant_apply(ap, MFREE_OP_HESSIAN, 1, q, MFREE_LAYOUT_AOS, 1, H,
                                                MFREE_LAYOUT_AOS, 3));
      double worst = 0.0;
      int at = -1;
      for (int p = 0; p < n; ++p) {
        const double X = x[2 * p], Y = x[2 * p + 1];
        const double e[6] = {val[p] - q[p],          g[2 * p] - (0.7 + X - 0.8 * Y),
                             g[2 * p + 1] - (-0.2 - 0.8 * X + 1.8 * Y), H[3 * p] - 1.0,
                             H[3 * p + 1] + 0.8,     H[3 * p + 2] - 1.8};
        for (int k = 0; k < 6; ++k)
          if (fabs(e[k]) > worst) worst = fabs(e[k]), at = p;
      }
      if (!(worst < 1e-9))
        fail_msg("%s, %s: a quadratic is not reproduced at particle %d (tag %d): %.3e", kName[m],
                 lay ? "rays" : "rings", at, at >= 0 ? (int)tag[at] : -1, worst);
      free(q);
      mfree_approximant_destroy(&ap);
      mfree_particles_destroy(&ps);
      free(x), free(v), free(h), free(tag);
    }
}

/* Paper 001 Sect. 6.3, Fig. 15: both methods predict the stress
 * concentration 3.0 at 686 particles. Measured s11(0, a) at 679 particles:
 * SSPH 3.0124 (+0.4 %), MSPH 3.0044 (+0.1 %); at 1502: 2.9999, 2.9980; at 203: 3.104,
 * 3.058 (not checked, the paper claims only 686). (The shape functions applied to the
 * exact displacements give 3.0156 and 3.0154 at 679.) With square-cell rings
 * (radial_step 1): 3.125 / 3.098 at 677, and 4.52 (SSPH) at 209. */
static void stress_concentration(void **state) {
  fixture_t *f = *state;
  for (int k = 1; k < NRES; ++k)
    for (int m = 0; m < NM; ++m) {
      const double scf = f->res[k][m].scf;
      if (!(fabs(scf - 3.0) <= 0.05 * 3.0))
        fail_msg("paper 001 Sect. 6.3 Fig. 15: %s, %d particles: s11(0, a)/s0 = %.4f, "
                 "expected 3.0 within 5 %%", kName[m], f->res[k][m].n, scf);
    }
  /* and it approaches 3 with refinement */
  for (int m = 0; m < NM; ++m)
    assert_true(fabs(f->res[2][m].scf - 3.0) < fabs(f->res[1][m].scf - 3.0));
}

/* Paper 001 Sect. 6.3: the error of u_2 along x_2 falls with
 * refinement, about 5x for SSPH from 188 to 686 particles (0.0216 -> 0.0044) and 6x for
 * MSPH (0.0304 -> 0.0050). Measured, 203 -> 679 -> 1502 particles:
 * SSPH 0.09326 -> 0.01224 -> 0.00275 (7.6x, then 4.5x),
 * MSPH 0.10664 -> 0.02242 -> 0.00491 (4.8x, then 4.6x). */
static void error_falls_with_refinement(void **state) {
  fixture_t *f = *state;
  for (int m = 0; m < NM; ++m)
    for (int k = 1; k < NRES; ++k)
      if (!(f->res[k][m].err_u2 < f->res[k - 1][m].err_u2))
        fail_msg("paper 001 Sect. 6.3: %s error %.4e at %d particles is not below %.4e at %d",
                 kName[m], f->res[k][m].err_u2, f->res[k][m].n, f->res[k - 1][m].err_u2,
                 f->res[k - 1][m].n);
  /* 188 -> 686 in the paper: 4.9x (SSPH), 6.1x (MSPH); here 7.6x and 4.8x */
  for (int m = 0; m < NM; ++m) {
    const double ratio = f->res[0][m].err_u2 / f->res[1][m].err_u2;
    if (!(ratio > 4.0))
      fail_msg("paper 001 Sect. 6.3: %s error falls %.2fx from %d to %d particles, the paper "
               "about 5x", kName[m], ratio, f->res[0][m].n, f->res[1][m].n);
  }
}

/* Paper 001 Sect. 6.3: SSPH's error is below MSPH's (0.0216 vs
 * 0.0304 at 188 particles, ratio 0.71; 0.0044 vs 0.0050 at 686, 0.88). Measured on the
 * default rings: 0.09326 / 0.10664 = 0.87 at 203 particles, 0.01224 / 0.02242 = 0.55 at
 * 679, 0.00275 / 0.00491 = 0.56 at 1502. This holds because of the radially refined
 * layer at the hole (see the top of this file: with square cells there, 2.52 and 1.40
 * at 209 and 677, and none of the paper's other open choices restores it). */
static void ssph_versus_msph(void **state) {
  fixture_t *f = *state;
  for (int k = 0; k < NRES; ++k) {
    const double ratio = f->res[k][0].err_u2 / f->res[k][1].err_u2;
    if (!(ratio <= 1.0))
      fail_msg("paper 001 Sect. 6.3: SSPH/MSPH error ratio %.3f at %d particles, expected "
               "<= 1 (measured 0.87, 0.55, 0.56 at 203, 679, 1502)", ratio, f->res[k][0].n);
  }
}

/* The ruled arrangement that the paper's counts suggest (188 = 11 x 17 + 1, 686 ~ 21 x 33;
 * plate.c): on the plate b = 10 a (where 17 square cells along the axis end, see plate.c)
 * it is solved with 187 and 693 particles. Measured, SSPH / MSPH: 187: 0.1493 / 0.1308,
 * 693: 0.04866 / 0.03534 (1519, 31 x 49: 0.02357 / 0.01659); SCF at 693: 3.061 / 3.046.
 * The error falls 3.1x / 3.7x from 187 to 693 (the paper 4.9x / 6.1x), and the paper's
 * ordering SSPH <= MSPH does not hold at any of the three resolutions (ratios 1.14, 1.38,
 * 1.42): asserted is what holds, SCF within 5 %, the fall, SSPH <= 1.5 MSPH. */
static void ruled_arrangement(void **state) {
  fixture_t *f = *state;
  assert_int_equal(f->ray[0][0].n, 11 * 17);
  assert_int_equal(f->ray[1][0].n, 21 * 33);
  for (int k = 0; k < NRAY; ++k)
    for (int m = 0; m < NM; ++m) {
      const plate_result_t *r = &f->ray[k][m];
      assert_int_equal(r->nfailed, 0);
      if (!(r->residual < 1e-9))
        fail_msg("rays, %s, %d particles: relative residual %.3e", kName[m], r->n, r->residual);
    }
  for (int m = 0; m < NM; ++m) {
    const double scf = f->ray[1][m].scf, fall = f->ray[0][m].err_u2 / f->ray[1][m].err_u2;
    if (!(fabs(scf - 3.0) <= 0.05 * 3.0))
      fail_msg("paper 001 Sect. 6.3 Fig. 15: rays, %s, 693 particles: s11(0, a)/s0 = %.4f", kName[m],
               scf);
    if (!(fall > 2.5))
      fail_msg("rays, %s: the error falls %.2fx from 187 to 693 particles (measured 3.1x, 3.7x)",
               kName[m], fall);
  }
  for (int k = 0; k < NRAY; ++k) {
    const double ratio = f->ray[k][0].err_u2 / f->ray[k][1].err_u2;
    if (!(ratio <= 1.5))
      fail_msg("rays: SSPH/MSPH error ratio %.3f at %d particles (measured 1.14, 1.38)", ratio,
               f->ray[k][0].n);
  }
}

/* The same ruled arrangement on the standard plate of paper 000 (b = 5 a) cannot carry a
 * quadratic basis with h_i = 1.5 Delta_i: near the outer edges the rays are about 4x
 * farther apart than the particles on them, so supports reach only two rays; setup says
 * so (a positive status, the failed sites counted), it does not return a wrong solution. */
static void ruled_arrangement_on_small_plate_is_reported(void **state) {
  fixture_t *f = *state;
  plate_config_t c;
  ray_config(&c, 11, 5.0);
  plate_result_t r;
  const mfree_status_t st = plate_solve(f->ctx, &c, &r);
  assert_int_equal(st, MFREE_FAIL_SINGULAR);
  assert_true(r.nfailed > 0);
  char msg[1024] = "";
  mfree_context_get_last_error(f->ctx, NULL, msg, sizeof msg);
  assert_non_null(strstr(msg, "singular"));
  plate_result_free(&r);
  /* and a bad arrangement is refused */
  ray_config(&c, 11, 10.0);
  c.layout = 7;
  assert_int_equal(plate_solve(f->ctx, &c, &r), MFREE_ERR_ARG);
  plate_result_free(&r);
  ray_config(&c, 11, 10.0);
  c.hole_corner = -1;
  assert_int_equal(plate_solve(f->ctx, &c, &r), MFREE_ERR_ARG);
  plate_result_free(&r);
  ray_config(&c, 11, 10.0);
  c.radial_step = 0.0;
  assert_error(f->ctx, plate_solve(f->ctx, &c, &r), MFREE_ERR_ARG, "plate: needs");
  plate_result_free(&r);
  ray_config(&c, 11, 10.0);
  c.search = 0;
  assert_error(f->ctx, plate_solve(f->ctx, &c, &r), MFREE_ERR_ARG, "MFREE_SEARCH_");
  plate_result_free(&r);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(kirsch_solution),
      cmocka_unit_test(system_size_and_solve),
      cmocka_unit_test(patch_test),
      cmocka_unit_test(boundary_rows_hold),
      cmocka_unit_test(boundary_fits_are_complete),
      cmocka_unit_test(error_scales_with_hole_radius),
      cmocka_unit_test(stress_concentration),
      cmocka_unit_test(error_falls_with_refinement),
      cmocka_unit_test(ssph_versus_msph),
      cmocka_unit_test(ruled_arrangement),
      cmocka_unit_test(ruled_arrangement_on_small_plate_is_reported),
  };
  return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
