/* Paper 000 Sect. 6.2 (Belytschko, Krongauz, Dolbow, Gerlach 1998): the static
 * convergence study behind Table III, shared by the example program and its tests.
 *
 *  - es_geometry.c: the problems (cantilever beam 000 eqs 120-125, Kirsch plate with a
 *    hole 000 eqs 127-129 with the displacements of docs/papers.md, paper 000, choices 2,
 *    a linear patch test), their node clouds, Voronoi nodal volumes, boundary segments and background
 *    Gauss points;
 *  - es_solve.c: the seven schemes of 000 Sect. 6.2 on mfree's assembler, the essential
 *    boundary-condition variants, the UMFPACK solve and the error norms 000 eqs 114-119.
 */
#ifndef MFREE_EXAMPLES_ES_H
#define MFREE_EXAMPLES_ES_H

#include <stdint.h>

#include <mfree.h>

enum { ES_BEAM = 0, ES_HOLE = 1, ES_PATCH = 2 };

typedef struct {
  int kind;        /* ES_BEAM, ES_HOLE, ES_PATCH */
  double E, nu;    /* plane stress throughout (the beam solution is plane stress) */
  double P, L, D;  /* beam: end load, length, depth (000 eqs 120-125) */
  double a, b;     /* hole: radius, outer size of the quarter model [0, b]^2 */
  double c[6];     /* patch: u_x = c0 + c1 x + c2 y, u_y = c3 + c4 x + c5 y */
  int mapped;      /* hole: 1 = nodes of the mapped grid between the arc and the outer
                      edges (non-uniform, dense at the hole), 2 = the same map with rings
                      graded to square cells and per-node supports; 0 = the cut regular
                      grid */
  int beam_dyadic; /* beam levels: 0 = nodes per depth ny = 3, 4, 5, 7, 9, 13, 17, 25, 33
                      (17x3, 25x4, 33x5, 49x7, 65x9, ...: dx falls by about sqrt 2 per
                      level; the first five are the paper's likely regime, see
                      es_beam_ny); 1 = ny = 3, 5, 9, 17, 33, ... (dx halves per level) */
  int traction_gauss; /* 1: tractions by 4 Gauss points per boundary segment for every
                         scheme; 0 (default): nodal boundary quadrature Psi_J(x_I) dGamma_I
                         (000 eq 95) for the nodal-quadrature schemes, Gauss points for EFG
                         and with consistent integration (whose boundary rule they are) */
} es_problem_t;

/* Exact displacement u (2), strain eps (xx, yy, engineering gamma_xy) and stress sig
 * (xx, yy, xy) at x. Any output may be NULL. */
void es_exact(const es_problem_t *p, const double *x, double *u, double *eps, double *sig);

enum { ES_MAXCHAIN = 4 };

/* A discretisation level: nodes, boundaries, quadrature. */
typedef struct {
  double dx;          /* nominal nodal spacing (the abscissa of the rates) */
  double h;           /* smoothing length s of the cubic spline (support 2h) */
  double *hn, *hq;    /* graded hole: per-node s and per-background-point s; else NULL */
  int32_t n;          /* nodes */
  double *x;          /* 2n, AoS */
  double *vol;        /* n: Voronoi areas clipped to the domain (sum = area) */
  int32_t *dmask;     /* n: bit c set when u_c is prescribed at the node */
  /* essential boundary as segments between boundary nodes (Nitsche, penalty) */
  int32_t nds;
  double *dseg;       /* 4 per segment: a_x a_y b_x b_y */
  double *dnrm;       /* 2 per segment: outward unit normal */
  int32_t *dsmask;    /* per segment: components prescribed */
  /* essential boundary lines as sorted node chains (FE-layer emulation) */
  int nchain;
  int32_t chain_start[ES_MAXCHAIN + 1]; /* chain c: chain_nodes[chain_start[c] .. [c+1]) */
  int32_t *chain_nodes;
  double chain_nrm[2 * ES_MAXCHAIN];    /* outward unit normal of each chain */
  int32_t chain_mask[ES_MAXCHAIN];      /* components prescribed on each chain */
  /* traction edges: segments with one outward normal per segment */
  int32_t nts;
  double *tseg, *tnrm;
  /* background Gauss points and weights (EFG on curved domains; error norms always) */
  int32_t nq;
  double *xq, *wq;
  /* the whole boundary as Gauss points (4 per node interval, the exact arc on the
   * hole) with weights and outward normals: mfree_assembler_set_consistent_integration */
  int32_t nbp;
  double *bpx, *bpw, *bpn;
  /* background cells aligned with the nodes (beam, patch): EFG uses
   * mfree_assembler_set_quadrature_cells on them; 0 when not available (hole). */
  int cells;
  double lo[2], hi[2];
  int32_t ncells[2];
} es_level_t;

/* Nodes across the depth of beam level k (0 = coarsest; nx = 8 (ny - 1) + 1), 0 when k
 * is out of range. */
int32_t es_beam_ny(const es_problem_t *p, int k);

/* Build level k (0 = coarsest) of problem p; ngauss points per direction in each
 * background cell for xq/wq. Returns 0, or 1 on allocation failure. */
int es_level_build(const es_problem_t *p, int k, int ngauss, es_level_t *lv);
void es_level_free(es_level_t *lv);

/* Human-readable description of the node arrangement of problem kind. */
const char *es_nodes_text(int kind);

/* The seven schemes of 000 Sect. 6.2. */
typedef struct {
  const char *name;
  mfree_method_t trial;
  int32_t order;         /* 0: the method's own */
  mfree_method_t test;   /* 0: Bubnov-Galerkin */
  int efg;               /* background quadrature instead of nodal */
  int particles_only;    /* SPH, JB, RL: functions defined at the particles only */
} es_scheme_t;

enum { ES_NSCHEMES = 7 };
extern const es_scheme_t es_schemes[ES_NSCHEMES];

/* Essential boundary conditions. */
typedef enum {
  ES_BC_AUTO = 0,     /* ES_BC_FE_LAYER (every problem here has essential lines) */
  ES_BC_DIRECT = 1,   /* rows u_J = g(x_J) on the nodal parameters (example-side rows) */
  ES_BC_ROWS = 2,     /* mfree_assembler_add_dirichlet_nodes: u^h(x_J) = g(x_J) */
  ES_BC_NITSCHE = 3,  /* MFREE_BC_NITSCHE on boundary Gauss points */
  ES_BC_PENALTY = 4,  /* MFREE_BC_PENALTY on boundary Gauss points */
  ES_BC_LAGRANGE = 5, /* MFREE_BC_LAGRANGE, one point multiplier per boundary node */
  ES_BC_FE_LAYER = 6, /* mfree_assembler_set_fe_layer: the finite-element blending layer
                         of 000 Sect. 5.2.4, one call (component mask) per boundary line */
  ES_BC_FE_GAUSS = 8, /* the same layer, its elements integrated by 2 x 2 Gauss points with
                         the blended functions and the other nodes by nodal quadrature (the
                         interface nodes' volumes less their share of the layer): not the
                         paper's; shows what the layer's nodal quadrature costs */
  ES_BC_FE_NODAL = 7, /* the same layer as nodal quadrature sees it, built by the example
                         (000 eq 105, Fig. 2): element derivatives at the quadrature points
                         of the nodes on Gamma_u, prescribed values on their parameters;
                         nodal-quadrature schemes only; equals fe-layer to round-off */
  ES_BC_COLUMNS = 9,  /* beam, a diagnosis (not the paper's): rows u_J = g(x_J) on every
                         node of the first three node columns (x < 2.5 dx), so that no free
                         node's test function reaches x = 0 (support 2 s = 2.83 dx) */
  ES_BC_COLUMNS2 = 10 /* the same at both ends (also x > L - 2.5 dx): what remains is the
                         interior and the free edges */
} es_bc_t;

const char *es_bc_name(es_bc_t bc);
int es_bc_parse(const char *s, es_bc_t *bc);
/* The condition ES_BC_AUTO picks for scheme s on level lv. */
es_bc_t es_bc_resolve(const es_scheme_t *s, const es_level_t *lv, es_bc_t bc);

typedef struct {
  double l2, L2, energy; /* relative errors 000 eqs 114-119 */
  double energy_nodal;   /* eq 118 summed over the nodes with weights Delta V_I and the
                            scheme's own strains at the nodes (what nodal quadrature sees) */
  double seconds;        /* setup, assembly, solve and error evaluation */
  double rcond;          /* UMFPACK's pivot ratio */
  int32_t ndofs;
  es_bc_t bc;            /* the condition used */
  int vci;               /* consistent integration of the test functions was used */
  int traction_nodal;    /* tractions by nodal boundary quadrature (000 eq 95), else Gauss */
  int warn;              /* a positive (data-dependent) status was reported */
} es_result_t;

/* One run of scheme s on level lv of problem p with condition bc; efg_ngauss Gauss
 * points per direction in EFG's background cells (0 = 5). Returns MFREE_SUCCESS or the
 * failing status (message on ctx, and in err when err is not NULL). */
mfree_status_t es_run(mfree_context_t *ctx, const es_problem_t *p, const es_level_t *lv,
                      const es_scheme_t *s, es_bc_t bc, int efg_ngauss, es_result_t *r,
                      char *err, int errlen);
/* The same with variationally consistent integration of the test functions
 * (mfree_assembler_set_consistent_integration on the whole boundary) when vci is
 * nonzero: not the paper's; for the schemes whose test functions have values (CD1,
 * CD2, MLS, EFG). */
mfree_status_t es_run_vci(mfree_context_t *ctx, const es_problem_t *p, const es_level_t *lv,
                          const es_scheme_t *s, es_bc_t bc, int vci, int efg_ngauss,
                          es_result_t *r, char *err, int errlen);

/* Least-squares slope of log(e) against log(dx). */
double es_rate(int n, const double *dx, const double *e);

#endif
