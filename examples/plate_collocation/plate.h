/* Paper 001 (Zhang & Batra, Comput Mech 43 (2009) 321-340) Sect. 6.3, with the errata
 * and choices of docs/papers.md (paper 001, errata 2, 3, choices 5-7): an infinite plate with a circular hole
 * under remote uniaxial tension sigma0 along x, modelled by a quarter of a finite square
 * plate with the exact Kirsch tractions on its outer edges, and solved by strong-form
 * collocation (MFREE_FORM_COLLOCATION_PLANE_STRAIN) with SSPH or MSPH shape functions.
 *
 * Shared by the example program (plate_collocation.c) and its test
 * (tests/collocation/), so that both run the very same problem.
 *
 * Notation: hole radius a, plate half-width b (the quarter model is [0, b]^2 minus the
 * disc r < a). Paper 001 calls the hole radius b; paper 000 and Timoshenko-Goodier call
 * it a, as here. */
#ifndef MFREE_EXAMPLES_PLATE_H
#define MFREE_EXAMPLES_PLATE_H

#include <mfree.h>

/* Particle arrangements (plate.c describes them). */
enum {
  PLATE_LAYOUT_RINGS = 0, /* rings with square cells, more particles per ring outwards
                             (the default) */
  PLATE_LAYOUT_RAYS = 1,  /* ruled: nt straight rays from the hole to equally spaced
                             points of the outer edges, nr particles on each, graded */
  PLATE_LAYOUT_POLAR = 2  /* the same with radial rays (theta = const) */
};

/* The two rows of the particles (a, 0) and (0, a) where the hole meets a symmetry line. */
enum {
  PLATE_CORNER_DIRICHLET = 0, /* the symmetry line's displacement condition and the
                                 hole's other traction component, as at the outer
                                 corners (b, 0), (0, b) (the default) */
  PLATE_CORNER_SYMMETRY = 1,  /* both rows of the symmetry line (u_n = 0, t_t = 0) */
  PLATE_CORNER_HOLE = 2       /* both hole tractions, no displacement condition */
};

typedef struct {
  double a;               /* hole radius (1) */
  double b;               /* half-width of the plate (10) */
  int nt;                 /* particles on the quarter hole, odd (symmetric about the
                             diagonal) */
  int nr;                 /* rings of particles from the hole to the outer edges
                             (plate_rings); for the ray layouts the particles on each
                             ray (plate_ray_particles) */
  mfree_method_t method;  /* MFREE_METHOD_SSPH or MFREE_METHOD_MSPH */
  double young, poisson;  /* 1, 0.25 (plane strain) */
  double sigma0;          /* remote tension, 1 */
  double kernel_param;    /* revised super Gauss decay a = 1.6 */
  double hfac;            /* h_i = hfac * Delta_i, 1.5 */
  double radial_step;     /* rings: the first radial step at the hole as a fraction of
                             the spacing a dtheta of the particles on the hole, (0, 2]
                             (0.6: a radially refined layer at the hole; 1: square
                             cells on the axes; plate.c says why 0.6) */
  int layout;             /* PLATE_LAYOUT_* */
  int hole_corner;        /* PLATE_CORNER_* */
  int search;             /* pair support: MFREE_SEARCH_GATHER, W(x_i - x_j, h_i) with
                             particle i's own h_i (001 eq 3.3, "W_i"; the default), or
                             MFREE_SEARCH_SYMMETRIC_MEAN / _MAX, h_ij = (h_i + h_j)/2 or
                             max(h_i, h_j) (measured, not the paper's reading) */
  int patch;              /* nonzero: uniform tension sigma_11 = sigma0 everywhere (its
                             tractions also on the hole) instead of Kirsch, a patch test
                             that quadratic shape functions must pass to round-off */
} plate_config_t;

/* Values along the x_2 axis (the particles on x = 0, from the hole outwards). */
typedef struct {
  int n;
  double *x2;        /* positions */
  double *u2;        /* SSPH/MSPH estimate sum_j Phi_j(x) u_2j */
  double *u2_nodal;  /* nodal unknowns u_2j */
  double *u2_exact;  /* Kirsch */
  double *sxx;       /* sigma_11 from the gradient shape functions applied to u */
  double *sxx_exact;
} plate_axis_t;

typedef struct {
  int n;             /* particles */
  int neq;           /* equations = unknowns = 2 n */
  double err_u2;     /* sqrt(int_a^b (u2^h - u2)^2 dx2) on x1 = 0, trapezoidal rule over
                        the particles on the axis, u2^h the estimate */
  double err_u2_nodal; /* the same with the nodal unknowns */
  double norm_u2;    /* sqrt(int_a^b u2^2 dx2): err_u2 / norm_u2 is a relative error */
  double scf;        /* sigma_11(0, a) / sigma0 */
  double scf_interp; /* the same from the exact nodal displacements (the error of the
                        gradient shape functions alone, without the solve's) */
  double max_err_u;  /* max over all particles of |u^h - u| (both components) */
  double residual;   /* ||K u - f||_inf / ||f||_inf after the solve */
  double rcond;      /* UMFPACK's min/max |pivot| */
  int32_t nfailed;   /* sites whose shape functions failed (must be 0) */
  int32_t min_neighbors;
  double t_setup;    /* seconds: particles, shape functions and assembly */
  double t_solve;    /* seconds: UMFPACK analysis, factorisation and solve */
  plate_axis_t axis;
  double *x;         /* particle positions (AoS, 2 n) */
  double *u;         /* nodal unknowns (AoS, 2 n) */
  double *uh;        /* estimates sum_j Phi_j(x_i) u_j at the particles (AoS, 2 n) */
  double *stress;    /* s11, s22, s12 at the particles from the gradient shape functions
                        applied to u (AoS, 3 n) */
  int32_t *tag;      /* PLATE_* boundary flags of each particle */
  int top;           /* the particle at (0, a) */
} plate_result_t;

/* Rings for nt particles on the quarter hole such that with radial_step 1 the rings
 * grow like r_{k+1} = r_k (1 + dtheta) on the axes, dtheta = pi / (2 (nt - 1)): square
 * cells there. b = 10 a: nt = 11 -> 17 (203 particles with radial_step 0.6, 209 with 1),
 * 21 -> 31 (679, 677). */
int plate_rings(double a, double b, int nt);

/* Particles on each ray of the ray layouts for nt rays: 1 + 8 (nt - 1)/5, the paper's
 * counts 188 = 11 x 17 + 1 and 686 ~ 21 x 33 (nt = 11 -> 17, 21 -> 33, 31 -> 49). */
int plate_ray_particles(int nt);

/* Defaults of paper 001 Sect. 6.3 (a = 1, b = 10, SSPH, E = 1, nu = 0.25, sigma0 = 1,
 * revised super Gauss a = 1.6, h_i = 1.5 Delta_i, PLATE_LAYOUT_RINGS with radial_step
 * 0.6, PLATE_CORNER_DIRICHLET, MFREE_SEARCH_GATHER) with nt particles on the hole and nr
 * rings (nr <= 0:
 * plate_rings(1, 10, nt); set it again after changing a or b). For the ray layouts set
 * layout and nr = plate_ray_particles(nt) afterwards. */
void plate_config_default(plate_config_t *cfg, int nt, int nr);

/* Builds the particles, assembles the collocation system, solves it with UMFPACK and
 * evaluates the errors. On failure returns the mfree status (message on ctx); a
 * positive status from an approximant or assembler setup is a failure here too
 * (res->nfailed then counts the failed sites). Call plate_result_free in any case. */
mfree_status_t plate_solve(mfree_context_t *ctx, const plate_config_t *cfg,
                           plate_result_t *res);
void plate_result_free(plate_result_t *res);

/* Boundary flags of a particle (or-ed at the corners of the model). */
enum {
  PLATE_HOLE = 1,    /* r = a */
  PLATE_SYM_Y0 = 2,  /* y = 0 */
  PLATE_SYM_X0 = 4,  /* x = 0 */
  PLATE_EDGE_XB = 8, /* x = b */
  PLATE_EDGE_YB = 16 /* y = b */
};

/* The particle arrangement alone: n particles, positions x (AoS, 2 n), volumes, supports
 * h_i = hfac Delta_i and boundary flags; ring by ring from the hole outwards, each ring
 * from y = 0 to x = 0. Arrays are malloc'ed; returns nonzero on bad input or no memory. */
int plate_particles(const plate_config_t *cfg, int *n, double **x, double **vol, double **h,
                    int32_t **tag);

/* Kirsch solution (001 eq 6.18 with docs/papers.md, paper 001, errata 2; 000 eqs 127-129
 * and docs/papers.md, paper 000, choices 2) at (x, y),
 * r >= a: stresses s = {s11, s22, s12}; plane-strain displacements u = {u1, u2}. */
void plate_kirsch_stress(double a, double sigma0, double x, double y, double s[3]);
void plate_kirsch_displacement(double a, double sigma0, double young, double poisson,
                               double x, double y, double u[2]);

#endif
