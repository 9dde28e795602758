/*
 * mfree — embeddable meshfree particle approximations.
 *
 * Public C ABI. C99-clean, usable from C++ and (through module mfree) Fortran 2008.
 *
 * Conventions (see ../shared/STYLE.md in the project tree):
 *  - every function returns mfree_status_t: 0 success, negative misuse or resource
 *    failure (nothing changed), positive data-dependent numerical failure (the call
 *    completed what it could);
 *  - the message of the last failure is kept on the context
 *    (mfree_context_get_last_error); the library never prints, aborts or exits;
 *  - reals are double, particle indices int32_t, offsets and counts of non-zeros int64_t;
 *  - destroy(&h) accepts NULL and sets h = NULL; objects are reference counted, so the
 *    order of destruction does not matter.
 */
#ifndef MFREE_H
#define MFREE_H

#include <stdint.h>

#include "mfree_version.h"

#if defined(_WIN32)
#if defined(MFREE_BUILDING)
#define MFREE_API __declspec(dllexport)
#else
#define MFREE_API
#endif
#elif defined(__GNUC__) && __GNUC__ >= 4
#define MFREE_API __attribute__((visibility("default")))
#else
#define MFREE_API
#endif

/** True when the headers are at least version a.b.c. */
#define MFREE_VERSION_GE(a, b, c)                                                        \
  ((MFREE_VERSION_MAJOR > (a)) ||                                                        \
   (MFREE_VERSION_MAJOR == (a) && MFREE_VERSION_MINOR > (b)) ||                          \
   (MFREE_VERSION_MAJOR == (a) && MFREE_VERSION_MINOR == (b) &&                          \
    MFREE_VERSION_PATCH >= (c)))

/* Enumerations have int as their underlying type in C and C++ alike, so that a host
 * passing any int (e.g. from Fortran) is well defined and gets MFREE_ERR_ARG back. */
#ifdef __cplusplus
#define MFREE_ENUM(name) enum name : int
#else
#define MFREE_ENUM(name) enum name
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------------------------------------ */
/* Status codes. Values are frozen: never renumbered, never reused.                      */
/* ------------------------------------------------------------------------------------ */

typedef MFREE_ENUM(mfree_status) {
  MFREE_SUCCESS = 0,

  /* Negative: misuse or resource failure. Nothing was changed. */
  MFREE_ERR_NULL = -1,        /**< a required handle or pointer is NULL */
  MFREE_ERR_ARG = -2,         /**< an argument is out of range (dimension, count,
                                   leading dimension, unknown enumerator) */
  MFREE_ERR_STATE = -3,       /**< the object is not in a state that allows the call */
  MFREE_ERR_ALLOC = -4,       /**< memory allocation failed */
  MFREE_ERR_MISMATCH = -5,    /**< objects or sizes that must agree do not */
  MFREE_ERR_UNSUPPORTED = -6, /**< a valid request this method/kernel does not provide */
  MFREE_ERR_INPUT = -7,       /**< invalid values in an input array (NaN/Inf, zero or
                                   negative volume or support, malformed CSR) */
  MFREE_ERR_INTERNAL = -99,   /**< a bug in mfree; please report it */

  /* Positive: data-dependent failure. The call completed what it could and reports
   * the affected particles or sites. */
  MFREE_FAIL_NONFINITE = 1,   /**< a non-finite value in borrowed data or a result */
  MFREE_FAIL_INVALID_DATA = 2,/**< a borrowed value outside its range (e.g. a volume or
                                   support that became <= 0 after it was set) */
  MFREE_FAIL_SINGULAR = 3,    /**< singular or ill-conditioned local system */
  MFREE_FAIL_NEIGHBORS = 4,   /**< too few neighbours (isolated site, basis too large) */
  MFREE_FAIL_DOMAIN = 5,      /**< a particle left the domain box */
  MFREE_FAIL_CFL = 6,         /**< a time step violates the CFL condition */
  MFREE_FAIL_SUPPORT = 7      /**< a kernel support exceeds a method's size limit (MPFEM,
                                   004 eq 13: a node's support reaches an element not
                                   connected to it, so the functions do not interpolate) */
} mfree_status_t;

/** How an input array is held. */
typedef MFREE_ENUM(mfree_mem) {
  MFREE_COPY = 1,  /**< copied at the call; the host may free or reuse its array */
  MFREE_BORROW = 2 /**< kept as a pointer and re-read at every setup/update/apply; the
                        host keeps it alive and may change its values between calls */
} mfree_mem_t;

/** Layout of a multi-component array of n items with ncomp components. */
typedef MFREE_ENUM(mfree_layout) {
  MFREE_LAYOUT_AOS = 1, /**< item i, component c at a[i*ld + c], ld >= ncomp
                             (Fortran x(3,n); an array of host structs) */
  MFREE_LAYOUT_SOA = 2  /**< item i, component c at a[c*ld + i], ld >= n
                             (Fortran x(n,3)) */
} mfree_layout_t;

/** Neighbour criterion for particles i, j at distance r with supports h_i, h_j.
 * Supports are closed: a pair within a relative 1e-13 of the limit counts (paper 001's
 * d <= 2), so pairs exactly on the edge are treated alike whatever their round-off. */
typedef MFREE_ENUM(mfree_search) {
  MFREE_SEARCH_GATHER = 1,         /**< r < kappa*h_i (row i uses its own support) */
  MFREE_SEARCH_SYMMETRIC_MAX = 2,  /**< r < kappa*max(h_i, h_j) */
  MFREE_SEARCH_SYMMETRIC_MEAN = 3  /**< r < kappa*(h_i + h_j)/2 */
} mfree_search_t;

/**
 * Smoothing kernels W(r, h) = C_dim / h^dim * f(q), q = r/h, with support q < R.
 * C_dim makes the integral of W over R^dim equal 1 in dimension dim = 1, 2, 3.
 */
typedef MFREE_ENUM(mfree_kernel) {
  MFREE_KERNEL_CUBIC_SPLINE = 1,        /**< 000 eq 26, 001 eq 6.6; R = 2 */
  MFREE_KERNEL_QUARTIC = 2,             /**< 001 eq 6.7, 1 - 3/2q^2 + q^3 - 3/16q^4
                                             (Lucy); R = 2 */
  MFREE_KERNEL_QUINTIC_SPLINE = 3,      /**< Morris' quintic spline; R = 3 */
  MFREE_KERNEL_GAUSSIAN = 4,            /**< exp(-q^2), truncated and renormalised at
                                             R = 3 */
  MFREE_KERNEL_SUPER_GAUSS = 5,         /**< 001 eq 6.9, (5/2 - q^2) exp(-q^2),
                                             truncated and renormalised at R = 3;
                                             negative for q^2 > 5/2 */
  MFREE_KERNEL_REVISED_GAUSS = 6,       /**< 001 eq 6.8, exp(-q^2) - exp(-4); R = 2 */
  MFREE_KERNEL_REVISED_SUPER_GAUSS = 7, /**< 001 eqs 6.10/6.17, (4 - q^2) exp(-a q^2);
                                             R = 2; parameter a, default 1 */
  MFREE_KERNEL_WENDLAND_C2 = 8,         /**< Wendland C2 (1D: psi_{2,1}; 2D/3D:
                                             psi_{3,1}); R = 2 */
  MFREE_KERNEL_WENDLAND_C4 = 9,         /**< Wendland C4 (1D: psi_{3,2}; 2D/3D:
                                             psi_{4,2}); R = 2 */
  MFREE_KERNEL_LINEAR = 10,             /**< 001 eq 6.4, (2 - q)/4; R = 2 */
  MFREE_KERNEL_QUADRATIC = 11,          /**< 001 eq 6.5, (1 - q/2)^2; R = 2 */
  MFREE_KERNEL_QUARTIC_SPLINE = 12,     /**< Morris' quartic spline; R = 5/2 */
  MFREE_KERNEL_COSINE = 13,             /**< MPFEM kernel, 004 eq 28 as corrected in the
                                             spec: cos(pi q / 2); R = 1, so in 1D
                                             W = (pi/(2d)) cos(pi t/d) with width d = 2h;
                                             C0, gives C1 MPFEM functions */
  MFREE_KERNEL_COSINE_SQUARED = 14,     /**< cos^2(pi q / 2); R = 1 (1D: (2/d)
                                             cos^2(pi t/d)); C1 with zero slope at the
                                             edge (004 eq 36), gives C2 */
  MFREE_KERNEL_HAAR = 15                /**< box 1 for q <= 1 (004 Sect. 4.2); R = 1;
                                             discontinuous: use with the assumed-strain
                                             derivatives (004 eq 22) */
} mfree_kernel_t;

/** Approximation methods (papers 000 and 001). Values are frozen. */
typedef MFREE_ENUM(mfree_method) {
  MFREE_METHOD_SPH = 1,               /**< kernel sum and kernel gradient, 000 eqs 21, 29 */
  MFREE_METHOD_SPH_SYMMETRIC = 2,     /**< symmetrised (difference) gradient, 000 eq 47;
                                           particles only; the assembler's loads use
                                           the kernel values W dV (000 eq 21) */
  MFREE_METHOD_SHEPARD = 3,           /**< Shepard functions, 000 eqs 38-39 */
  MFREE_METHOD_MLS = 4,               /**< moving least squares, order 0..3, shifted and
                                           scaled basis, 000 eqs 43-46 */
  MFREE_METHOD_RKPM = 5,              /**< reproducing kernel particle method, order 0..3,
                                           001 Sect. 4 (weights W V; true derivatives) */
  MFREE_METHOD_JOHNSON_BEISSEL = 6,   /**< 000 eqs 49, 52; particles only; under an
                                           elasticity form the assembler keeps the
                                           symmetrised SPH shear strain (eqs 48-52)
                                           and its loads use the kernel values W dV */
  MFREE_METHOD_RANDLES_LIBERSKY = 7,  /**< renormalised gradient, 000 eqs 68-69;
                                           particles only; the assembler's loads use
                                           Shepard values (000 eq 70) */
  MFREE_METHOD_KB_METHOD1 = 8,        /**< Krongauz-Belytschko corrected derivatives,
                                           000 eqs 55-61 (alpha = A^-T) */
  MFREE_METHOD_KB_METHOD2 = 9,        /**< corrected derivatives Method 2 (diffuse MLS
                                           derivatives), 000 eqs 63-64 */
  MFREE_METHOD_KB_METHOD3 = 10,       /**< corrected derivatives Method 3, 000 eqs 65-66 */
  MFREE_METHOD_MSPH = 11,             /**< modified SPH, order 1..2, 001 Sect. 2 */
  MFREE_METHOD_SSPH = 12,             /**< symmetric SPH, order 1..3, 001 Sect. 3 */
  MFREE_METHOD_MPFEM = 13             /**< moving particle FEM, 004: element interpolants
                                           extended over the domain ("general shape
                                           functions", eqs 1-3), blended with element
                                           weights from a moving kernel (eqs 4-13); needs
                                           a mesh (mfree_approximant_set_mesh) */
} mfree_method_t;

/** Shape-function tables an approximant builds (bit flags, may be or-ed). */
typedef MFREE_ENUM(mfree_deriv) {
  MFREE_DERIV_VALUE = 1,    /**< values Phi_j(x) */
  MFREE_DERIV_GRADIENT = 2, /**< first derivatives (corrected where the method corrects) */
  MFREE_DERIV_HESSIAN = 4   /**< second derivatives, packed xx | xx,xy,yy | xx,xy,xz,yy,yz,zz */
} mfree_deriv_t;

/** Operators applied to host fields. */
typedef MFREE_ENUM(mfree_op) {
  MFREE_OP_VALUE = 1,      /**< ncomp in, ncomp out */
  MFREE_OP_GRADIENT = 2,   /**< ncomp in, ncomp*dim out: component c, direction d at c*dim+d */
  MFREE_OP_DIVERGENCE = 3, /**< dim in, 1 out */
  MFREE_OP_LAPLACIAN = 4,  /**< ncomp in, ncomp out (trace of the Hessian table) */
  MFREE_OP_HESSIAN = 5     /**< ncomp in, ncomp*nh out, nh = 1, 3, 6 packed as above */
} mfree_op_t;

/** What setup does at a site whose local system is singular or under-determined. */
typedef MFREE_ENUM(mfree_fallback) {
  MFREE_FALLBACK_NONE = 1,        /**< the site fails: zero rows, positive status */
  MFREE_FALLBACK_LOWER_ORDER = 2  /**< retry with lower orders down to Shepard (as paper
                                       003 does); sites that still fail are reported */
} mfree_fallback_t;

/** Weak (Galerkin) and strong (collocation) forms the assembler builds. */
typedef MFREE_ENUM(mfree_form) {
  MFREE_FORM_LAPLACE = 1,                      /**< int grad Psi . c grad Phi */
  MFREE_FORM_ELASTICITY_PLANE_STRESS = 2,      /**< int B_Psi^T D B_Phi, 2D plane stress */
  MFREE_FORM_ELASTICITY_PLANE_STRAIN = 3,      /**< 2D plane strain */
  MFREE_FORM_ELASTICITY_3D = 4,                /**< 3D */
  MFREE_FORM_MASS = 5,                         /**< consistent mass int rho Psi Phi */
  MFREE_FORM_MASS_LUMPED = 6,                  /**< row-sum lumped mass */
  MFREE_FORM_COLLOCATION_LAPLACE = 7,          /**< rows -c Lap u = f at the particles */
  MFREE_FORM_COLLOCATION_PLANE_STRESS = 8,     /**< Navier rows at the particles (001 6.3) */
  MFREE_FORM_COLLOCATION_PLANE_STRAIN = 9
} mfree_form_t;

/** How essential boundary conditions are imposed. */
typedef MFREE_ENUM(mfree_bc) {
  MFREE_BC_PENALTY = 1,     /**< alpha int Psi (u - g) on boundary quadrature points */
  MFREE_BC_LAGRANGE = 2,    /**< point multipliers: extra unknowns and rows [K G; G^T 0] */
  MFREE_BC_COLLOCATION = 3, /**< the rows of the given particles are replaced by
                                 u^h(x_J) = g(x_J): direct imposition for interpolating
                                 approximants, boundary collocation otherwise */
  MFREE_BC_NITSCHE = 4      /**< symmetric Nitsche terms on boundary quadrature points
                                 with outward normals: consistent, passes patch tests */
} mfree_bc_t;

/** Element types of a mesh (mfree_mesh_add_elements). Values are frozen. */
typedef MFREE_ENUM(mfree_element) {
  MFREE_ELEMENT_LINE2 = 1, /**< 1D two-node line, x_1 < x_2 */
  MFREE_ELEMENT_TRI3 = 2,  /**< 2D three-node triangle, counter-clockwise */
  MFREE_ELEMENT_QUAD4 = 3, /**< 2D four-node quadrilateral, counter-clockwise, convex */
  MFREE_ELEMENT_HEX8 = 4   /**< 3D eight-node hexahedron, nodes as in VTK: bottom face
                                counter-clockwise seen from above, then the top face */
} mfree_element_t;

/** How MPFEM differentiates (paper 004). Values are frozen. */
typedef MFREE_ENUM(mfree_mpfem_deriv) {
  MFREE_MPFEM_DERIV_FULL = 1,           /**< derivative of the approximation, weights
                                             differentiated too (004 eq 21); C^n for a
                                             C^(n-1) kernel */
  MFREE_MPFEM_DERIV_ASSUMED_STRAIN = 2, /**< weights not differentiated (004 eq 22):
                                             continuous for any kernel, Haar included */
  MFREE_MPFEM_DERIV_NODAL = 3           /**< at the nodes only: eq 22 with the weights
                                             of the elements around the node by inverse
                                             length/area/volume (004 eqs 37-38) */
} mfree_mpfem_deriv_t;

/** Native time integrators of paper 003 (eqs 108-121). */
typedef MFREE_ENUM(mfree_integrator) {
  MFREE_INTEGRATOR_LEAPFROG = 1,            /**< 003 eqs 108-110 and the ten-step algorithm */
  MFREE_INTEGRATOR_PREDICTOR_CORRECTOR = 2  /**< 003 eqs 111-119 */
} mfree_integrator_t;

/** Lumped mass of the Galerkin-SPH fluid (paper 003 Sect. 4.3). */
typedef MFREE_ENUM(mfree_lumping) {
  MFREE_LUMP_GALERKIN = 1, /**< M_i = sum_k N_i(x_k) M_k (003 eq 56), the default */
  MFREE_LUMP_PHYSICAL = 2  /**< M_i = physical particle mass (003 eq 58) */
} mfree_lumping_t;

/* ------------------------------------------------------------------------------------ */
/* Opaque handles                                                                         */
/* ------------------------------------------------------------------------------------ */

typedef struct mfree_context mfree_context_t;
typedef struct mfree_particles mfree_particles_t;
typedef struct mfree_approximant mfree_approximant_t;
typedef struct mfree_matrix mfree_matrix_t;
typedef struct mfree_assembler mfree_assembler_t;
typedef struct mfree_system mfree_system_t;
typedef struct mfree_mesh mfree_mesh_t;

/** Progress of a native integration: called after every accepted step; a nonzero
 * return stops the integration (MFREE_SUCCESS is returned, t tells where). It may read
 * the state being integrated but must not change it (the fluid's next step reuses the
 * check the state has just passed). */
typedef int32_t (*mfree_progress_fn)(void *user, int64_t step, double t, double dt);
/** A load history g(t): scales the boundary data of an elastodynamic system. */
typedef double (*mfree_history_fn)(void *user, double t);

/** A host function of position: writes ncomp values at x (dim coordinates). */
typedef void (*mfree_field_fn)(void *user, const double *x, double *value);
/** A host inside-test: nonzero when x lies in the domain. */
typedef int32_t (*mfree_inside_fn)(void *user, const double *x);

/** Called on every failure recorded on a context (from the failing call's thread). */
typedef void (*mfree_error_handler_t)(void *user, mfree_status_t code, const char *message);
/** Allocation hook (mfree_context_set_allocator): return bytes bytes aligned as malloc's
 * are, or NULL on failure (the call then returns MFREE_ERR_ALLOC). May be called from
 * any of the call's OpenMP threads at once. */
typedef void *(*mfree_alloc_fn)(void *user, int64_t bytes);
/** Release a block of the matching mfree_alloc_fn; bytes is the size it was asked for. */
typedef void (*mfree_free_fn)(void *user, void *ptr, int64_t bytes);

/* ------------------------------------------------------------------------------------ */
/* Version and status                                                                     */
/* ------------------------------------------------------------------------------------ */

/** Run-time version, "MAJOR.MINOR.PATCH"; a static string. */
MFREE_API const char *mfree_version_string(void);

/** Run-time version numbers (compare with the MFREE_VERSION_* macros).
 * @param[out] major, minor, patch  each may be NULL */
MFREE_API mfree_status_t mfree_version_get(int32_t *major, int32_t *minor, int32_t *patch);

/** A static, human-readable name for a status code ("unknown status" if not one). */
MFREE_API const char *mfree_status_string(mfree_status_t status);

/* ------------------------------------------------------------------------------------ */
/* Context                                                                                */
/* ------------------------------------------------------------------------------------ */

/** Create a context: error state, thread count, error handler. Use one per host thread.
 * @param[out] ctx  the new context */
MFREE_API mfree_status_t mfree_context_create(mfree_context_t **ctx);

/** Release a context. Objects created on it keep it alive until they are destroyed.
 * @param[in,out] ctx  may be NULL or point to NULL; set to NULL */
MFREE_API mfree_status_t mfree_context_destroy(mfree_context_t **ctx);

/** The last failure recorded on the context (successful calls leave it unchanged).
 * @param[out] code     the status of the failing call (MFREE_SUCCESS if none); may be NULL
 * @param[out] message  buffer for the NUL-terminated message; may be NULL
 * @param[in]  len      size of message in bytes; the message is truncated to fit */
MFREE_API mfree_status_t mfree_context_get_last_error(const mfree_context_t *ctx,
                                                      mfree_status_t *code, char *message,
                                                      int64_t len);

/** Record a failure on the context as mfree itself does (for adapters and host
 * wrappers built on mfree): sets the last error code and message and calls the error
 * handler. Returns code, so that `return mfree_context_set_error(...)` reads naturally.
 * @param[in] message  NUL-terminated, copied; NULL records an empty message */
MFREE_API mfree_status_t mfree_context_set_error(mfree_context_t *ctx, mfree_status_t code,
                                                 const char *message);

/** Install an error handler (NULL removes it). The handler must not call back into
 * mfree with the same context. */
MFREE_API mfree_status_t mfree_context_set_error_handler(mfree_context_t *ctx,
                                                         mfree_error_handler_t handler,
                                                         void *user);

/** Threads used by objects created on this context (default 1; 0 means all cores).
 * mfree never calls omp_set_* itself. */
MFREE_API mfree_status_t mfree_context_set_num_threads(mfree_context_t *ctx,
                                                       int32_t nthreads);
MFREE_API mfree_status_t mfree_context_get_num_threads(const mfree_context_t *ctx,
                                                       int32_t *nthreads);

/**
 * Install an allocator for the large arrays mfree allocates while it runs a call on an
 * object of this context: neighbour lists, shape-function tables and their per-site
 * scratch (small bookkeeping such as messages uses the C++ runtime). Every block goes
 * back to the free function of the allocator that made it, even after the allocator is
 * changed, so alloc, release and user must stay valid until the objects that used them
 * are destroyed. After the first setup, mfree_approximant_update and _apply allocate
 * nothing. Both NULL restores the default: malloc, and on Linux with transparent huge
 * pages available, blocks of 2 MiB or more from mappings of their own advised
 * MADV_HUGEPAGE (fewer page faults and TLB misses; MFREE_HUGEPAGES=0 in the environment
 * turns this off).
 * @param[in] alloc    allocation function, or NULL
 * @param[in] release  matching free function, or NULL (both NULL or neither)
 * @param[in] user     passed to both; not dereferenced by mfree
 */
MFREE_API mfree_status_t mfree_context_set_allocator(mfree_context_t *ctx, mfree_alloc_fn alloc,
                                                     mfree_free_fn release, void *user);

/* ------------------------------------------------------------------------------------ */
/* Kernels                                                                                */
/* ------------------------------------------------------------------------------------ */

/**
 * Evaluate a kernel and its radial derivatives at n distances.
 * @param[in]  kernel  an mfree_kernel_t
 * @param[in]  dim     1, 2 or 3 (selects the normalisation and, for Wendland, the form)
 * @param[in]  param   shape parameter: the decay a of MFREE_KERNEL_REVISED_SUPER_GAUSS
 *                     (> 0); 0 selects the default (1); ignored by the other kernels
 * @param[in]  h       smoothing length (> 0, finite)
 * @param[in]  n       number of distances (>= 0)
 * @param[in]  r       distances (>= 0, finite), length n
 * @param[out] w       W(r), or NULL
 * @param[out] dwdr    dW/dr, or NULL
 * @param[out] d2wdr2  d2W/dr2, or NULL
 */
MFREE_API mfree_status_t mfree_kernel_eval(mfree_context_t *ctx, mfree_kernel_t kernel,
                                           int32_t dim, double param, double h, int64_t n,
                                           const double *r, double *w, double *dwdr,
                                           double *d2wdr2);

/** Support radius R in units of h: W(r, h) = 0 for r > R h. The support is closed: at
 * r = R h (up to a relative 1e-13) W and its derivatives take their values from inside. */
MFREE_API mfree_status_t mfree_kernel_get_support_radius(mfree_context_t *ctx,
                                                         mfree_kernel_t kernel,
                                                         double param, double *radius);

/** The constant C_dim in W = C_dim / h^dim f(q). For the Gauss family of paper 001
 * (W = G/(h sqrt(pi))^dim f) this is G / pi^(dim/2). */
MFREE_API mfree_status_t mfree_kernel_get_normalization(mfree_context_t *ctx,
                                                        mfree_kernel_t kernel, int32_t dim,
                                                        double param, double *c);

/* ------------------------------------------------------------------------------------ */
/* Particle sets                                                                          */
/* ------------------------------------------------------------------------------------ */

/**
 * Create a particle set of n particles in dimension dim. The last n_ghost particles
 * (mfree_particles_set_num_ghost, default 0) are ghosts: they serve as neighbours but
 * get no rows of their own.
 * @param[in]  dim  1, 2 or 3
 * @param[in]  n    number of particles, owned plus ghost (>= 0)
 * @param[out] ps   the new particle set
 */
MFREE_API mfree_status_t mfree_particles_create(mfree_context_t *ctx, int32_t dim,
                                                int32_t n, mfree_particles_t **ps);

/** Release a particle set (objects built on it keep it alive).
 * @param[in,out] ps  may be NULL or point to NULL; set to NULL */
MFREE_API mfree_status_t mfree_particles_destroy(mfree_particles_t **ps);

/** The last n_ghost particles are ghosts (0 <= n_ghost <= n). Default 0. */
MFREE_API mfree_status_t mfree_particles_set_num_ghost(mfree_particles_t *ps,
                                                       int32_t n_ghost);

/**
 * Positions, dim components per particle.
 * @param[in] x       coordinates (finite); copied or borrowed according to mem
 * @param[in] layout  MFREE_LAYOUT_AOS (x[i*ld + d], ld >= dim) or
 *                    MFREE_LAYOUT_SOA (x[d*ld + i], ld >= n)
 * @param[in] ld      leading dimension, in doubles
 */
MFREE_API mfree_status_t mfree_particles_set_positions(mfree_particles_t *ps,
                                                       const double *x,
                                                       mfree_layout_t layout, int64_t ld,
                                                       mfree_mem_t mem);

/**
 * Per-particle scalars: element i is a[i*stride]; stride 0 gives every particle a[0].
 * Values must be finite and > 0. Copied or borrowed according to mem.
 *  - volumes: Delta V_i. When unset, volumes are masses/densities.
 *  - masses, densities: used for volumes (V_i = m_i / rho_i) when volumes are unset.
 *  - support: smoothing lengths h_i (the kernel support radius is R h_i).
 */
MFREE_API mfree_status_t mfree_particles_set_volumes(mfree_particles_t *ps,
                                                     const double *v, int64_t stride,
                                                     mfree_mem_t mem);
MFREE_API mfree_status_t mfree_particles_set_masses(mfree_particles_t *ps,
                                                    const double *m, int64_t stride,
                                                    mfree_mem_t mem);
MFREE_API mfree_status_t mfree_particles_set_densities(mfree_particles_t *ps,
                                                       const double *rho, int64_t stride,
                                                       mfree_mem_t mem);
MFREE_API mfree_status_t mfree_particles_set_support(mfree_particles_t *ps,
                                                     const double *h, int64_t stride,
                                                     mfree_mem_t mem);

/**
 * Neighbour criterion and radius multiplier: j is a neighbour of i when their distance
 * is below kappa times the convention's support. Default MFREE_SEARCH_GATHER, kappa 2
 * (the support of the 001 kernels and the cubic spline).
 */
MFREE_API mfree_status_t mfree_particles_set_search(mfree_particles_t *ps,
                                                    mfree_search_t convention,
                                                    double kappa);

/**
 * A box [lo, hi) with periodic axes (copied). Distances use the nearest image along
 * periodic axes; kappa * h must stay below half the box length there.
 * @param[in] lo, hi     dim values each, hi > lo
 * @param[in] periodic   dim flags, nonzero for a periodic axis
 */
MFREE_API mfree_status_t mfree_particles_set_periodic(mfree_particles_t *ps,
                                                      const double *lo, const double *hi,
                                                      const int32_t *periodic);

/**
 * Host-supplied neighbour lists, one row per owned particle (CSR). mfree then does no
 * search of its own. Rows need not be sorted nor contain the particle itself.
 * @param[in] rowptr      n_owned + 1 monotone offsets, rowptr[0] = base
 * @param[in] cols        column indices in [base, base + n)
 * @param[in] index_base  0 (C) or 1 (Fortran) for both arrays
 * @param[in] mem         copied or borrowed (borrowed lists are re-validated at setup)
 */
MFREE_API mfree_status_t mfree_particles_set_neighbors(mfree_particles_t *ps,
                                                       const int64_t *rowptr,
                                                       const int32_t *cols,
                                                       int32_t index_base,
                                                       mfree_mem_t mem);

/**
 * Validate the particle data and build the neighbour lists (cell-list search, or the
 * host's lists). A particle whose borrowed data are non-finite or out of range is
 * isolated: its row is empty and no other row lists it; the call then returns
 * MFREE_FAIL_NONFINITE or MFREE_FAIL_INVALID_DATA and mfree_particles_get_site_status
 * names the particles. The set keeps the search's grid and buffers (through the
 * context's allocator; 1.5-2.5 times the size of the lists) so that the next setup of
 * the same set, e.g. every time step, allocates nothing once the sizes have settled;
 * they are freed with the set. One exception to "a failed call changes nothing": a
 * one-thread search writes the new lists over the old ones as it goes, so if memory
 * runs out while it grows them (MFREE_ERR_ALLOC, the rows outgrew the storage), the old
 * lists are gone and the set is no longer set up; call setup again.
 */
MFREE_API mfree_status_t mfree_particles_setup(mfree_particles_t *ps);

/** Re-read and re-validate borrowed data after particles moved; the neighbour lists
 * are kept (use setup to search again). */
MFREE_API mfree_status_t mfree_particles_update(mfree_particles_t *ps);

MFREE_API mfree_status_t mfree_particles_get_dimension(const mfree_particles_t *ps,
                                                       int32_t *dim);
/** @param[out] n  owned plus ghost particles; @param[out] n_ghost  ghosts; either NULL */
MFREE_API mfree_status_t mfree_particles_get_size(const mfree_particles_t *ps, int32_t *n,
                                                  int32_t *n_ghost);

/** Number of stored neighbour pairs (after setup). */
MFREE_API mfree_status_t mfree_particles_get_neighbor_nnz(const mfree_particles_t *ps,
                                                          int64_t *nnz);

/**
 * Copy the neighbour lists (0-based CSR, one row per owned particle, each row sorted
 * ascending; searched rows include the particle itself).
 * @param[out] rowptr  n_owned + 1 offsets
 * @param[out] cols    nnz column indices (size from mfree_particles_get_neighbor_nnz)
 */
MFREE_API mfree_status_t mfree_particles_get_neighbors(const mfree_particles_t *ps,
                                                       int64_t *rowptr, int32_t *cols);

/**
 * Copy the particle volumes: the set volumes, or masses / densities when volumes are
 * unset (borrowed arrays are read now). @param[out] v  n values
 */
MFREE_API mfree_status_t mfree_particles_get_volumes(const mfree_particles_t *ps, double *v);

/**
 * Per-particle status of the last setup/update: 0, or the positive status that
 * isolated the particle. @param[out] status  n values
 * @param[out] nfailed  number of nonzero entries (may be NULL)
 */
MFREE_API mfree_status_t mfree_particles_get_site_status(const mfree_particles_t *ps,
                                                         int32_t *status, int32_t *nfailed);

/* ------------------------------------------------------------------------------------ */
/* Meshes (element connectivity over the particles, for MPFEM)                            */
/* ------------------------------------------------------------------------------------ */

/**
 * A finite-element mesh whose nodes are the particles of ps (which it keeps alive):
 * the nodes move with the particles (borrowed positions are re-read at every setup).
 * Add blocks of elements with mfree_mesh_add_elements; a mesh may mix element types of
 * its dimension (e.g. triangles and quadrilaterals, 004 Sect. 2.1).
 * @param[out] mesh  the new mesh
 */
MFREE_API mfree_status_t mfree_mesh_create(mfree_context_t *ctx, mfree_particles_t *ps,
                                           mfree_mesh_t **mesh);
/** Release a mesh (approximants using it keep it alive). */
MFREE_API mfree_status_t mfree_mesh_destroy(mfree_mesh_t **mesh);

/**
 * Append nelem elements of one type.
 * @param[in] type        an mfree_element_t whose dimension is the particle set's
 *                        (else MFREE_ERR_MISMATCH: a mesh of mixed dimension)
 * @param[in] nelem       number of elements (>= 0)
 * @param[in] conn        nodes per element (2, 3, 4, 8) consecutive per element:
 *                        particle indices in [index_base, index_base + n); copied or
 *                        borrowed (re-read and re-checked at every setup) per mem
 * @param[in] index_base  0 (C) or 1 (Fortran)
 * @return MFREE_ERR_INPUT for an index out of range or repeated within an element
 *         (copied arrays are checked here, borrowed ones at setup)
 */
MFREE_API mfree_status_t mfree_mesh_add_elements(mfree_mesh_t *mesh, mfree_element_t type,
                                                 int32_t nelem, const int32_t *conn,
                                                 int32_t index_base, mfree_mem_t mem);

/**
 * Check the mesh at the current node positions: indices in range, and every element
 * valid: positive length (LINE2, x_1 < x_2), positive Jacobian at every corner
 * (TRI3, QUAD4 counter-clockwise and convex; HEX8), and solvable general shape
 * functions (a QUAD4 whose nodes make {1, x, y, xy} singular, like the diamond
 * (+-1, 0), (0, +-1), is rejected). Failures: MFREE_ERR_INPUT, naming the element.
 * Approximants repeat these checks at their own setup.
 */
MFREE_API mfree_status_t mfree_mesh_setup(mfree_mesh_t *mesh);

/** Number of elements. */
MFREE_API mfree_status_t mfree_mesh_get_size(const mfree_mesh_t *mesh, int32_t *nelem);

/**
 * Gauss quadrature over the mesh, e.g. for mfree_assembler_set_quadrature_points:
 * ngauss points per direction and element (LINE2 ngauss, QUAD4 ngauss^2, HEX8 ngauss^3
 * through the isoparametric map; TRI3 a collapsed ngauss^2 rule), in element order.
 * Call with x = w = NULL to get the count first. MPFEM integrands are not polynomials,
 * and where the kernel support's edges cross the elements (TRI3 with a square support)
 * they have kinks inside them: the relative quadrature error then does not shrink under
 * refinement, so take more points there (test t475: TRI3 Poisson L2 rate 1.44 with 3,
 * 2.00 with 5 points per direction, n = 32 -> 64).
 * @param[in]  ngauss  1..10
 * @param[out] npts    number of points
 * @param[out] x       dim coordinates per point (AoS), or NULL
 * @param[out] w       weights (|J| times the rule's weight), or NULL
 */
MFREE_API mfree_status_t mfree_mesh_get_quadrature(mfree_mesh_t *mesh, int32_t ngauss,
                                                   int32_t *npts, double *x, double *w);

/* ------------------------------------------------------------------------------------ */
/* Approximants                                                                           */
/* ------------------------------------------------------------------------------------ */

/**
 * Create an approximant of the given method on a particle set (which it keeps alive).
 * Defaults: cubic spline kernel, derivatives VALUE|GRADIENT, order 1 for MLS and KB
 * Method 2, 2 for RKPM, MSPH and SSPH; sites = the owned particles; no fallback.
 * The kernel's support radius R must not exceed the set's search multiplier kappa.
 */
MFREE_API mfree_status_t mfree_approximant_create(mfree_context_t *ctx,
                                                  mfree_particles_t *ps,
                                                  mfree_method_t method,
                                                  mfree_approximant_t **a);
MFREE_API mfree_status_t mfree_approximant_destroy(mfree_approximant_t **a);

/** Kernel (weight function) and its shape parameter (0 = default). */
MFREE_API mfree_status_t mfree_approximant_set_kernel(mfree_approximant_t *a,
                                                      mfree_kernel_t kernel, double param);
/** Polynomial order of MLS/RKPM (0..3), SSPH (1..3), MSPH (1..2), KB Method 2 (1..2);
 * other methods accept only their own order (MFREE_ERR_UNSUPPORTED otherwise). */
MFREE_API mfree_status_t mfree_approximant_set_order(mfree_approximant_t *a, int32_t order);
/** Tables to build: an or of mfree_deriv_t flags. */
MFREE_API mfree_status_t mfree_approximant_set_derivatives(mfree_approximant_t *a,
                                                           int32_t flags);
MFREE_API mfree_status_t mfree_approximant_set_fallback(mfree_approximant_t *a,
                                                        mfree_fallback_t policy);

/**
 * The mesh of an MPFEM approximant (MFREE_METHOD_MPFEM only; else MFREE_ERR_UNSUPPORTED;
 * it must be built on the approximant's particle set, else MFREE_ERR_MISMATCH). The
 * approximant keeps the mesh alive. Required before setup.
 *
 * MPFEM (paper 004): u^h(x) = sum_e omega_e(x) sum_{I in e} Nhat^e_I(x) u_I, where
 * Nhat^e is element e's interpolant ({1,x}, {1,x,y}, {1,x,y,xy}, {1,x,y,z,xy,yz,zx,xyz}
 * in physical coordinates) extended over the whole domain (eqs 1-3), and
 * omega_e(x) = int_{e} phi(y - x) dy / int_{mesh} phi(y - x) dy (eqs 6, 11; normalised
 * per point, so the weights sum to one up to the boundary, eq 12). The kernel phi is the
 * tensor product prod_c W1(|t_c|, h) of the approximant's kernel in its 1D form, so the
 * support is the box |t_c| <= R h around x (004 Sect. 4.2); h is the site's support
 * (the particle's, or the point's). The default kernel is MFREE_KERNEL_COSINE. The
 * integrals are exact in 1D and on axis-aligned rectangles and bricks; on triangles and
 * other quadrilaterals they are edge integrals (divergence theorem) with ngauss points
 * per smooth piece. HEX8 elements must be axis-aligned bricks (else MFREE_ERR_UNSUPPORTED).
 *
 * Setup checks the interpolation condition (eq 13) at every node: when a node's
 * support reaches an element that does not contain it, the tables are still built but
 * setup returns MFREE_FAIL_SUPPORT naming the node (004 Sect. 4.1: no Kronecker delta).
 * A site whose support reaches no element gets a zero row and MFREE_FAIL_NEIGHBORS.
 * Update recomputes the rows, and may change the pattern when nodes moved across
 * supports.
 */
MFREE_API mfree_status_t mfree_approximant_set_mesh(mfree_approximant_t *a,
                                                    mfree_mesh_t *mesh);

/**
 * MPFEM options (defaults: MFREE_MPFEM_DERIV_FULL, ngauss 8).
 * @param[in] deriv   how gradients and Hessians are formed (mfree_mpfem_deriv_t);
 *                    MFREE_MPFEM_DERIV_NODAL needs the sites to be the particles; FULL
 *                    Hessians need a continuous kernel (not MFREE_KERNEL_HAAR)
 * @param[in] ngauss  Gauss points per smooth piece of the edge integrals (1..20)
 */
MFREE_API mfree_status_t mfree_approximant_set_mpfem(mfree_approximant_t *a,
                                                     mfree_mpfem_deriv_t deriv,
                                                     int32_t ngauss);

/**
 * Evaluate at host points instead of the particles (e.g. quadrature points). Each point
 * has a support size used as the site's h; neighbours are searched with the particle
 * set's convention and kappa. Not available for particles-only methods.
 * @param[in] npts    number of points (>= 0)
 * @param[in] x       coordinates, layout/ld as for particle positions; copied or borrowed
 * @param[in] h       point supports, element i at h[i*h_stride] (stride 0: one value)
 */
MFREE_API mfree_status_t mfree_approximant_set_points(mfree_approximant_t *a, int32_t npts,
                                                      const double *x, mfree_layout_t layout,
                                                      int64_t ld, const double *h,
                                                      int64_t h_stride, mfree_mem_t mem);

/**
 * Build the shape-function tables (sets up the particle set first if it never was).
 * Sites whose local system fails are reported by a positive status
 * (MFREE_FAIL_SINGULAR, MFREE_FAIL_NEIGHBORS), get all-zero rows and are listed by
 * mfree_approximant_get_site_status; with MFREE_FALLBACK_LOWER_ORDER such sites first
 * retry lower orders (mfree_approximant_get_site_order tells the order used).
 */
MFREE_API mfree_status_t mfree_approximant_setup(mfree_approximant_t *a);

/** Recompute the tables after particles (borrowed positions) moved, keeping the
 * neighbour pattern. */
MFREE_API mfree_status_t mfree_approximant_update(mfree_approximant_t *a);

/**
 * out = op(u) at every site (apply) or out += op(u) (apply_add). No allocation.
 * @param[in]  ncomp  components of u (op DIVERGENCE needs ncomp = dim)
 * @param[in]  u      field at the n particles (owned and ghost), borrowed for the call
 * @param[in]  ulayout, uld  layout of u: AOS ld >= ncomp, SOA ld >= n
 * @param[out] out    one row per site, ocomp = the op's output components
 * @param[in]  olayout, old  layout of out: AOS ld >= ocomp, SOA ld >= number of sites
 */
MFREE_API mfree_status_t mfree_approximant_apply(const mfree_approximant_t *a, mfree_op_t op,
                                                 int32_t ncomp, const double *u,
                                                 mfree_layout_t ulayout, int64_t uld,
                                                 double *out, mfree_layout_t olayout,
                                                 int64_t old);
MFREE_API mfree_status_t mfree_approximant_apply_add(const mfree_approximant_t *a,
                                                     mfree_op_t op, int32_t ncomp,
                                                     const double *u, mfree_layout_t ulayout,
                                                     int64_t uld, double *out,
                                                     mfree_layout_t olayout, int64_t old);

/** Number of sites (owned particles or host points) after setup. */
MFREE_API mfree_status_t mfree_approximant_get_num_sites(const mfree_approximant_t *a,
                                                         int32_t *nsites);
/** Non-zeros of each table (one per site-neighbour pair). */
MFREE_API mfree_status_t mfree_approximant_get_nnz(const mfree_approximant_t *a,
                                                   int64_t *nnz);
/**
 * Copy one table as CSR (rows = sites, columns = particles).
 * @param[in] deriv      MFREE_DERIV_VALUE, MFREE_DERIV_GRADIENT or MFREE_DERIV_HESSIAN
 * @param[in] component  direction (gradient) or packed index (Hessian); 0 for values
 * @param[out] rowptr    nsites + 1; @param[out] cols, vals  nnz each
 */
MFREE_API mfree_status_t mfree_approximant_assemble_csr(const mfree_approximant_t *a,
                                                        mfree_deriv_t deriv,
                                                        int32_t component, int64_t *rowptr,
                                                        int32_t *cols, double *vals);

/**
 * Maximum violation over all valid sites of the reproducing conditions (000 eqs 5-9)
 * for every monomial of degree <= order in local coordinates (x_j - x)/h: fn_err for
 * the values, deriv_err for the gradient (scaled by h) and Hessian (scaled by h^2).
 * A table that was not built contributes 0.
 */
MFREE_API mfree_status_t mfree_approximant_check_reproduction(const mfree_approximant_t *a,
                                                              int32_t order, double *fn_err,
                                                              double *deriv_err);

/** Per-site diagnostics, nsites entries each: status (0 or a positive status), number
 * of neighbours with non-zero weight, condition number of the local system (the larger
 * of the exact 1-norm condition number ||A||_1 ||A^-1||_1 and the ratio of the largest to
 * the smallest pivot; infinite for a singular system; above 1e12 the site falls back or
 * fails; 1 where the method solves none), order used (differs from the set order after a
 * fallback; -1 for a failed site). */
MFREE_API mfree_status_t mfree_approximant_get_site_status(const mfree_approximant_t *a,
                                                           int32_t *status,
                                                           int32_t *nfailed);
MFREE_API mfree_status_t mfree_approximant_get_neighbor_counts(const mfree_approximant_t *a,
                                                               int32_t *counts);
MFREE_API mfree_status_t mfree_approximant_get_condition(const mfree_approximant_t *a,
                                                         double *cond);
MFREE_API mfree_status_t mfree_approximant_get_site_order(const mfree_approximant_t *a,
                                                          int32_t *order);

/* ------------------------------------------------------------------------------------ */
/* Sparse matrices                                                                        */
/* ------------------------------------------------------------------------------------ */

/**
 * A sparse matrix in CSR form (rows sorted by column), as produced by the assembler, or
 * created from host arrays (copied). Views give zero-copy access to its arrays for
 * solvers (the SuiteSparse adapter); a view stays valid until the matrix is refilled
 * with another pattern or destroyed.
 * @param[in] rowptr  nrows + 1 offsets; @param[in] cols, vals  rowptr[nrows] entries
 */
MFREE_API mfree_status_t mfree_matrix_create_csr(mfree_context_t *ctx, int32_t nrows,
                                                 int32_t ncols, const int64_t *rowptr,
                                                 const int32_t *cols, const double *vals,
                                                 mfree_matrix_t **A);
/** Free the matrix and set *A = NULL (NULL and *A == NULL accepted); views into it
 * become invalid. */
MFREE_API mfree_status_t mfree_matrix_destroy(mfree_matrix_t **A);
/** Rows, columns and stored entries; each output may be NULL. */
MFREE_API mfree_status_t mfree_matrix_get_size(const mfree_matrix_t *A, int32_t *nrows,
                                               int32_t *ncols, int64_t *nnz);
/** Zero-copy CSR view with the ABI index types. */
MFREE_API mfree_status_t mfree_matrix_get_csr(const mfree_matrix_t *A,
                                              const int64_t **rowptr,
                                              const int32_t **cols, const double **vals);
/** CSR view with 32-bit offsets (int SuiteSparse variants); MFREE_ERR_UNSUPPORTED when
 * nnz does not fit. Index arrays are converted once and cached; values are not copied. */
MFREE_API mfree_status_t mfree_matrix_get_csr_i32(const mfree_matrix_t *A,
                                                  const int32_t **rowptr,
                                                  const int32_t **cols, const double **vals);
/** CSR view with 64-bit offsets and columns (SuiteSparse_long variants). */
MFREE_API mfree_status_t mfree_matrix_get_csr_i64(const mfree_matrix_t *A,
                                                  const int64_t **rowptr,
                                                  const int64_t **cols, const double **vals);
/** CSC view (computed on first request after a fill, then cached). */
MFREE_API mfree_status_t mfree_matrix_get_csc(const mfree_matrix_t *A,
                                              const int64_t **colptr, const int32_t **rows,
                                              const double **vals);
/** Pattern counter of this matrix: it changes whenever the matrix gets a new sparsity
 * pattern (a refill of the values keeps it), so a solver that analysed this matrix
 * knows when its symbolic analysis must be redone. */
MFREE_API mfree_status_t mfree_matrix_get_pattern_id(const mfree_matrix_t *A, int64_t *id);
/** 1 if the matrix is symmetric (checked numerically to round-off), else 0. */
MFREE_API mfree_status_t mfree_matrix_get_symmetric(const mfree_matrix_t *A,
                                                    int32_t *symmetric);
/** y = A x (x of length ncols, y of length nrows; borrowed for the call). */
MFREE_API mfree_status_t mfree_matrix_apply(const mfree_matrix_t *A, const double *x,
                                            double *y);

/* ------------------------------------------------------------------------------------ */
/* Assembly                                                                               */
/* ------------------------------------------------------------------------------------ */

/**
 * An assembler of the given form with trial functions from `trial` and test functions
 * from `test` (NULL: Bubnov-Galerkin, test = trial; e.g. Shepard test functions with
 * corrected-derivative trial functions give the Petrov-Galerkin scheme of 000 5.3.1).
 * The approximants' configuration (method, kernel, order) is copied: the assembler
 * evaluates its own copies at its quadrature points. Unknowns are node-major,
 * dof = particle * ncomp + component (ncomp = dim for elasticity, else 1), followed by
 * Lagrange multipliers. Both approximants must be on the same particle set.
 */
MFREE_API mfree_status_t mfree_assembler_create(mfree_context_t *ctx,
                                                const mfree_approximant_t *trial,
                                                const mfree_approximant_t *test,
                                                mfree_form_t form, mfree_assembler_t **as);
/** Free the assembler and set *as = NULL (NULL and *as == NULL accepted); matrices it
 * assembled stay valid (they are separate objects). */
MFREE_API mfree_status_t mfree_assembler_destroy(mfree_assembler_t **as);

/** Young's modulus and Poisson ratio (elasticity forms). Default 1, 0. */
MFREE_API mfree_status_t mfree_assembler_set_material(mfree_assembler_t *as, double young,
                                                      double poisson);
/** Coefficient c of the Laplace forms, or density rho of the mass forms. Default 1. */
MFREE_API mfree_status_t mfree_assembler_set_coefficient(mfree_assembler_t *as, double c);

/** Nodal quadrature: points = the particles, weights = their volumes (the default);
 * mfree_assembler_setup is MFREE_ERR_STATE when the particle set has no volumes (nor
 * masses and densities). */
MFREE_API mfree_status_t mfree_assembler_set_quadrature_nodal(mfree_assembler_t *as);
/**
 * Background cells: a structured grid of ncells[d] cells over [lo, hi], ngauss^dim
 * Gauss points per cell; points for which inside() is 0 are dropped (inside may be NULL).
 */
MFREE_API mfree_status_t mfree_assembler_set_quadrature_cells(mfree_assembler_t *as,
                                                              const double *lo,
                                                              const double *hi,
                                                              const int32_t *ncells,
                                                              int32_t ngauss,
                                                              mfree_inside_fn inside,
                                                              void *user);
/** Host points and weights (copied; weights finite and >= 0). */
MFREE_API mfree_status_t mfree_assembler_set_quadrature_points(mfree_assembler_t *as,
                                                               int32_t npts,
                                                               const double *x,
                                                               mfree_layout_t layout,
                                                               int64_t ld, const double *w);

/** Body force b(x) (ncomp values), NULL for none. */
MFREE_API mfree_status_t mfree_assembler_set_body_force(mfree_assembler_t *as,
                                                        mfree_field_fn f, void *user);
/**
 * Natural boundary condition on boundary quadrature points (copied): adds
 * sum_p w_p Psi_J(x_p) t(x_p) to the load. For collocation forms use
 * mfree_assembler_add_traction_nodes.
 */
MFREE_API mfree_status_t mfree_assembler_add_traction(mfree_assembler_t *as, int32_t npts,
                                                      const double *x,
                                                      mfree_layout_t layout, int64_t ld,
                                                      const double *w, mfree_field_fn t,
                                                      void *user);
/** Traction on 2D boundary segments (endpoints a_s, b_s at x[4 s .. 4 s + 3]), with
 * ngauss Gauss points per segment; a segment of zero length is an input error. */
MFREE_API mfree_status_t mfree_assembler_add_traction_segments(mfree_assembler_t *as,
                                                               int32_t nseg,
                                                               const double *x,
                                                               int32_t ngauss,
                                                               mfree_field_fn t, void *user);
/** Traction on 3D boundary triangles (vertices a_f, b_f, c_f at x[9 f .. 9 f + 8]),
 * with ngauss x ngauss points per triangle (collapsed Gauss product rule, exact for
 * polynomials of degree 2 ngauss - 2 over the triangle); a triangle of zero area is an
 * input error. Quadrilateral facets: split them into two triangles. */
MFREE_API mfree_status_t mfree_assembler_add_traction_facets(mfree_assembler_t *as,
                                                             int32_t nfacet,
                                                             const double *x,
                                                             int32_t ngauss,
                                                             mfree_field_fn t, void *user);
/**
 * Essential boundary condition u_c = g_c for the components c set in component_mask
 * (bit c), on boundary quadrature points (copied) with weights w.
 *  - MFREE_BC_PENALTY: alpha sum_p w_p Psi_J (u - g)(x_p);
 *  - MFREE_BC_LAGRANGE: one multiplier per point and component, u^h(x_p) = g(x_p)
 *    (weights unused; point multipliers cannot represent the boundary flux exactly,
 *    so this does not pass patch tests: prefer Nitsche);
 *  - MFREE_BC_NITSCHE: -<Psi, (sigma(u) n)_c> - <(sigma(Psi) n)_c, u_c - g_c>
 *    + beta <Psi, u_c - g_c> with beta from mfree_assembler_set_penalty (default
 *    100 modulus / mean h); needs the outward unit normals (dim per point).
 * @param[in] normals  dim values per point (Nitsche), else may be NULL
 */
MFREE_API mfree_status_t mfree_assembler_add_dirichlet(mfree_assembler_t *as,
                                                       mfree_bc_t method, int32_t npts,
                                                       const double *x,
                                                       mfree_layout_t layout, int64_t ld,
                                                       const double *w,
                                                       const double *normals,
                                                       int32_t component_mask,
                                                       mfree_field_fn g, void *user);
/** Essential condition by row replacement at particles (MFREE_BC_COLLOCATION): the row of
 * each prescribed component becomes u^h(x_J) = g(x_J) with the trial values at the node;
 * for the particles-only methods (symmetrised SPH, Johnson-Beissel, Randles-Libersky),
 * whose derivatives act on the particle values, u_J = g(x_J) on the particle value. */
MFREE_API mfree_status_t mfree_assembler_add_dirichlet_nodes(mfree_assembler_t *as,
                                                             int32_t nnodes,
                                                             const int32_t *nodes,
                                                             int32_t component_mask,
                                                             mfree_field_fn g, void *user);
/** Collocation forms: traction rows sigma(u) n = t at the given particles with outward
 * normals (dim per node, copied) replace the PDE rows (Laplace: c grad u . n = t). */
MFREE_API mfree_status_t mfree_assembler_add_traction_nodes(mfree_assembler_t *as,
                                                            int32_t nnodes,
                                                            const int32_t *nodes,
                                                            const double *normals,
                                                            mfree_field_fn t, void *user);
/**
 * The finite-element blending layer of paper 000 (eqs 100-105): a single layer of
 * elements (2D: 3-node triangles or 4-node quadrilaterals, counter-clockwise, particle
 * indices, copied) along the essential boundary; gu lists the layer nodes on that
 * boundary (the others form the interface to the meshfree region). Inside the layer the
 * functions become (1 - r) N_I + r Phi_I with r = 3R^2 - 2R^3, R = sum of the FE
 * functions of the interface nodes; at nodal quadrature points on the boundary the FE
 * functions are used, the node's volume split among its elements. The boundary nodes
 * are interpolating there, so u_c = g_c (components in component_mask) is imposed
 * directly on their unknowns. Calls accumulate: each adds its elements to one layer and
 * its own mask and g for its nodes (e.g. u_y = 0 on y = 0, u_x = 0 on x = 0); every call
 * must use the same element type (MFREE_ERR_ARG otherwise).
 */
MFREE_API mfree_status_t mfree_assembler_set_fe_layer(mfree_assembler_t *as, int32_t nelem,
                                                      int32_t nodes_per_element,
                                                      const int32_t *connectivity,
                                                      int32_t ngu, const int32_t *gu,
                                                      int32_t component_mask,
                                                      mfree_field_fn g, void *user);
/** Penalty factor alpha (default 1e6 times the modulus E or coefficient c), which is
 * also Nitsche's beta when set (default 100 modulus / mean h). */
MFREE_API mfree_status_t mfree_assembler_set_penalty(mfree_assembler_t *as, double alpha);
/**
 * Variationally consistent integration (VCI; Chen, Hillman and Rueter, IJNME 93 (2013)
 * 245-267), second order, for the Galerkin stiffness forms (elasticity, Laplace): the
 * test gradients at the quadrature points of each test function J get a correction
 * xi_J + eta_J (x - x_J)/h_J, constant and linear over J's support, such that the
 * quadrature satisfies the divergence theorem for Psi_J and Psi_J (x - x_J)/h_J:
 * sum_q grad(Psi_J P)(x_q) w_q = sum_p (Psi_J P)(x_p) n_p w_p on the boundary points
 * given here (P = 1, (x - x_J)/h_J). Trial functions that reproduce linear (quadratic)
 * fields then pass the linear (quadratic) patch test with any domain quadrature, nodal
 * quadrature included, and the finite-element layer's strip
 * (mfree_assembler_set_fe_layer) is consistent too. Not in paper 000: an option beside
 * its schemes. The assembled matrix is then unsymmetric even for Bubnov-Galerkin.
 * @param[in] npts     boundary points (copied); 0 switches the correction off
 * @param[in] x        the points: the whole boundary of the domain (essential and
 *                     natural parts alike), best the same rule as the tractions on the
 *                     natural part
 * @param[in] w        weights (non-negative, finite)
 * @param[in] normals  outward unit normals, dim per point (AoS)
 * MFREE_ERR_UNSUPPORTED for mass and collocation forms and for test functions without
 * values between the particles (symmetrised SPH, Johnson-Beissel, Randles-Libersky).
 */
MFREE_API mfree_status_t mfree_assembler_set_consistent_integration(mfree_assembler_t *as,
                                                                    int32_t npts,
                                                                    const double *x,
                                                                    mfree_layout_t layout,
                                                                    int64_t ld, const double *w,
                                                                    const double *normals);

/**
 * Build the quadrature, the shape-function tables at the quadrature and boundary points,
 * and the sparsity pattern. A quadrature point outside every support, or a particle
 * that no quadrature point sees (a zero row), is reported with a positive status
 * (MFREE_FAIL_NEIGHBORS) instead of yielding a silently singular matrix.
 */
MFREE_API mfree_status_t mfree_assembler_setup(mfree_assembler_t *as);
/** Recompute the tables after particles moved, keeping the pattern (refill only). */
MFREE_API mfree_status_t mfree_assembler_update(mfree_assembler_t *as);
/** Number of unknowns (particles * ncomp + multipliers) and quadrature points. */
MFREE_API mfree_status_t mfree_assembler_get_size(const mfree_assembler_t *as,
                                                  int32_t *ndofs, int32_t *nquad);
/** Assemble the system matrix into *K (created when *K is NULL, else refilled: the
 * pattern is kept when it did not change, so a solver can refactor numerically). */
MFREE_API mfree_status_t mfree_assembler_assemble_matrix(mfree_assembler_t *as,
                                                         mfree_matrix_t **K);
/** Assemble the right-hand side (ndofs values). */
MFREE_API mfree_status_t mfree_assembler_assemble_rhs(mfree_assembler_t *as, double *f);

/* ------------------------------------------------------------------------------------ */
/* Semi-discrete particle systems y' = f(t, y)                                            */
/* ------------------------------------------------------------------------------------ */

/**
 * Weakly compressible free-surface flow by Galerkin SPH with MLS shape functions (paper
 * 003): nodal integration, internal force from the Cauchy stress -p I + 2 mu d' (d' with
 * the paper's 1/3), Tait equation of state p = kappa ((rho/rho0)^gamma - 1), continuity
 * collocated at the particles, particles moved with the interpolated velocity, the
 * wall-particle boundary force of 003 Sect. 6.2, Shepard fallback at degenerate sites.
 * State y (length (2 dim + 1) n): positions (AoS, dim per particle), velocity parameters
 * (AoS), densities. The particles' masses are constant.
 */
MFREE_API mfree_status_t mfree_system_create_fluid(mfree_context_t *ctx, int32_t dim,
                                                   int32_t n, mfree_system_t **sys);
MFREE_API mfree_status_t mfree_system_destroy(mfree_system_t **sys);

/** Rest density rho0 (per particle, stride 0 for one fluid; copied), Tait kappa and
 * gamma, dynamic viscosity mu. Defaults: 1000, 1, 7, 0. */
MFREE_API mfree_status_t mfree_system_set_fluid(mfree_system_t *sys, const double *rho0,
                                                int64_t stride, double kappa, double gamma,
                                                double mu);
/** Particle masses (copied; stride 0 = one value). Required. */
MFREE_API mfree_status_t mfree_system_set_masses(mfree_system_t *sys, const double *m,
                                                 int64_t stride);
/** Constant smoothing length h of the cubic-spline MLS weights (paper: 1.5 d). */
MFREE_API mfree_status_t mfree_system_set_smoothing(mfree_system_t *sys, double h);
/** Gravity (dim values). Default zero. */
MFREE_API mfree_status_t mfree_system_set_gravity(mfree_system_t *sys, const double *g);
MFREE_API mfree_status_t mfree_system_set_lumping(mfree_system_t *sys, mfree_lumping_t lump);
/**
 * Solid walls as boundary particles (copied) with unit normals pointing into the fluid;
 * fluid particles closer than r0 to a wall particle and approaching it feel
 * (A/r)((r0/r)^4 - (r0/r)^2) n, spread to their neighbours through the shape functions
 * (003 eqs 122-124; paper: spacing d/3, r0 = 0.7 h, A = 10).
 */
MFREE_API mfree_status_t mfree_system_set_walls(mfree_system_t *sys, int32_t nwall,
                                                const double *x, const double *normals,
                                                double r0, double strength);
/** A box the particles must stay in (dim values each); leaving it is
 * MFREE_FAIL_DOMAIN. Default: none. */
MFREE_API mfree_status_t mfree_system_set_box(mfree_system_t *sys, const double *lo,
                                              const double *hi);

/**
 * Shepard fallback of the fluid (003 Sect. 6): at every evaluation, the particles whose
 * linear MLS moment matrix has a condition estimate above max_cond use Shepard functions
 * N_j = W_j V_j / sum_k W_k V_k (constant basis) instead; singular sites always do. The
 * paper gives no tolerance. Default 100: lattice sites estimate 10-15, free edges and
 * corners 30-60, while particles left in thin sheets climb past 1e3 within a few steps and
 * their gradients then drive densities negative (dam break, T ~ 2.2). Pass INFINITY for
 * singular sites only, 1 for Shepard functions everywhere (no linear consistency).
 * @param[in] max_cond  >= 1 (NaN or below 1: MFREE_ERR_ARG)
 */
MFREE_API mfree_status_t mfree_system_set_shepard_condition(mfree_system_t *sys,
                                                            double max_cond);

/**
 * Dummy wall particles (not in paper 003; Adami, Hu & Adams 2012, J. Comput. Phys. 231,
 * 7057): fixed particles that fill the solid past the walls, best continuing the fluid's
 * lattice, at least 4h - d deep (four layers at spacing d for h = 1.5 d: the MLS
 * functions at the dummies a fluid node reaches must see full supports; with three
 * layers the floor row of a still column is pushed up by 6 % of g). They are nodes
 * of the MLS approximation with zero velocity parameters (walls at rest, no-slip) and
 * quadrature points of the momentum equation, with the pressure extrapolated from the
 * fluid at every evaluation,
 * p_w = sum_f W_wf (p_f + rho_f g.(x_w - x_f)) / sum_f W_wf (fluid neighbours f within
 * the support), their density from the inverse equation of state, their mass
 * rho_w V_w feeling gravity. So a fluid node next to a wall sees a full support, and the
 * dummy region supplies the wall traction that the paper's force (mfree_system_set_walls,
 * active only on approaching particles) cannot: it holds a still column (t702). The
 * Galerkin lumped mass of a fluid node becomes sum_k N_i(x_k) M_k / sum_j N_j(x_k) over
 * the fluid particles k and fluid nodes j, so that the fluid nodes carry the whole mass;
 * interpolation and mass matrices keep the fluid rows and columns. May be combined with
 * the wall force. n = 0 removes them (the default).
 * @param[in] x        positions, dim per particle (AoS; copied)
 * @param[in] volumes  volumes V_w > 0 (stride 0 = one value; copied), typically d^dim
 */
MFREE_API mfree_status_t mfree_system_set_dummy_particles(mfree_system_t *sys, int32_t n,
                                                          const double *x,
                                                          const double *volumes,
                                                          int64_t stride);
/**
 * Density diffusion (not in paper 003; delta-SPH of Molteni & Colagrossi 2009 with the
 * correction of Antuono et al. 2010): d rho_i/dt gains
 * delta h c0_i sum_j psi_ji . grad_i W_ij V_j, psi_ji = 2 (rho_j - rho_i) x_ji / |x_ji|^2 -
 * (grad rho_i + grad rho_j), c0_i = sqrt(gamma kappa / rho0_i), W the cubic spline, the
 * gradients those of the MLS functions (so a linear, e.g. hydrostatic, density field is
 * left unchanged, free surface included). It damps the odd-even density modes that nodal
 * integration does not see. Particle masses stay constant. Usual delta: 0.1.
 * Default 0 (off).
 * @param[in] delta  finite, >= 0
 */
MFREE_API mfree_status_t mfree_system_set_density_diffusion(mfree_system_t *sys,
                                                            double delta);
/**
 * Variationally consistent nodal integration of the fluid's momentum equation (not in
 * paper 003; Chen, Hillman & Rueter 2013, constant correction): the test-function
 * gradients at the quadrature points become grad N_i(x_k) + xi_i N_i(x_k) with xi_i such
 * that sum_k V_k grad N~_i(x_k) = 0 for every node whose support lies in the fluid (with
 * the dummy particles; nodes near a free surface, kernel volume sum below 0.95, are
 * blended out, below 0.85 uncorrected). A uniform pressure then exerts no force on a
 * disordered particle set; without the correction it does, and that force destabilises
 * the particle positions at a rate growing as sqrt(p) (a still column goes unstable
 * after ~0.5 s, t702). Linear and angular momentum are then no longer conserved to
 * round-off.
 * @param[in] on  0 (default, the paper's nodal integration) or 1; else MFREE_ERR_ARG
 */
MFREE_API mfree_status_t mfree_system_set_consistent_integration(mfree_system_t *sys,
                                                                 int32_t on);
/**
 * Conservative velocity smoothing (not in paper 003; the Randles-Libersky smoothing
 * that paper 000 Sect. 6.3 uses, coefficient 0.1, against the instabilities of nodal
 * quadrature; here a rate in the right-hand side): the acceleration of fluid node i gains
 * (1 / m_i) sum_j beta c_ij / h (m_i V_j + m_j V_i) / 2 W_ij (v_j - v_i) over the nodes j
 * within 2h (dummy particles included, at rest), m_i the lumped mass, m_j the particle
 * masses, V = m / rho, W the cubic spline, c_ij the mean of the two sound speeds
 * sqrt(gamma kappa / rho0). Pair forces are equal and opposite: linear momentum stays
 * exact; they are not central, so angular momentum is not (a rigid rotation is braked
 * only where a neighbourhood is one-sided, at a free surface). A linear velocity field
 * gets no force in the interior of a regular lattice; the term acts like an artificial
 * viscosity of order beta c h / 10. It damps the zero-energy modes of the velocity
 * parameters (checkerboards that move particles without a density response, t702 test
 * 1), which otherwise let a still column drift away from hydrostatic: with beta = 0.1
 * and dummy particles, density diffusion 0.1 and consistent integration, a still column
 * holds within 2 % to t = 2 s (t702 test 3). Default 0 (off).
 * @param[in] beta  finite, >= 0
 */
MFREE_API mfree_status_t mfree_system_set_velocity_smoothing(mfree_system_t *sys,
                                                             double beta);

/** Length of the state vector. */
MFREE_API mfree_status_t mfree_system_get_size(const mfree_system_t *sys, int32_t *neq);
/** ydot = f(t, y) (y and ydot borrowed for the call). Non-finite or out-of-range state
 * gives a positive status with the particle named, ydot then unspecified. */
MFREE_API mfree_status_t mfree_system_rhs(mfree_system_t *sys, double t, const double *y,
                                          double *ydot);
/** Mass matrix of the state (identity except the velocity block, which holds the
 * lumped or, with consistent != 0, the consistent Galerkin mass), so that
 * M y' = M f(t, y) is the mass-matrix form of the system. */
MFREE_API mfree_status_t mfree_system_assemble_mass(mfree_system_t *sys, const double *y,
                                                    int32_t consistent, mfree_matrix_t **M);
/** S_kj = N_j(x_k) at the state's positions: initial velocity parameters solve
 * S v = v_hat (003 eq 99). */
MFREE_API mfree_status_t mfree_system_assemble_interpolation(mfree_system_t *sys,
                                                             const double *y,
                                                             mfree_matrix_t **S);
/** Pressure at the particles from the state's densities (n values). */
MFREE_API mfree_status_t mfree_system_get_pressure(const mfree_system_t *sys,
                                                   const double *y, double *p);
/** Interpolated velocities v_hat(x_k) (dim per particle, AoS). */
MFREE_API mfree_status_t mfree_system_get_velocity(mfree_system_t *sys, const double *y,
                                                   double *vhat);

/**
 * Integrate y from *t to t_end with a native scheme and the CFL step
 * dt = cfl h / max_i (c_i + |v_i|), c_i = sqrt(gamma kappa / rho_i) (003 eqs 120-121),
 * capped by dt_max (0: no cap). With cfl <= 0 the step is dt_max, and a step above the
 * CFL limit returns MFREE_FAIL_CFL before anything is changed. A non-finite state or a
 * particle outside the box stops the run with a positive status naming the step and
 * particle; y and *t then hold the last good state. The message names the step that
 * failed, nsteps + 1 ("(predictor)": the predictor-corrector's half step). A step that
 * no longer advances t stops the run the same way with MFREE_FAIL_CFL: speeds so large
 * that the CFL step is 0 (|v|^2 or gamma kappa / rho overflow; the fastest particle is
 * named), or dt_max below the resolution of t.
 * @param[in,out] y   state, updated in place
 * @param[in,out] t   time
 * @param[out] nsteps steps taken (may be NULL)
 */
MFREE_API mfree_status_t mfree_system_integrate(mfree_system_t *sys,
                                                mfree_integrator_t scheme, double *y,
                                                double *t, double t_end, double cfl,
                                                double dt_max, mfree_progress_fn progress,
                                                void *user, int64_t *nsteps);

/**
 * Linear elastodynamics by strong-form collocation (paper 001 Sect. 6.4): rho u'' =
 * Navier(u) + b at the interior particles of a set-up collocation assembler
 * (MFREE_FORM_COLLOCATION_PLANE_STRESS/STRAIN; MFREE_FORM_COLLOCATION_LAPLACE with c = E
 * gives the 1D bar rho u'' = E u''), its traction and displacement rows kept as
 * constraints that fix the boundary particles' displacements at every evaluation (the
 * boundary data scaled by the load history g(t), default 1). State y: displacements then
 * velocities (ncomp per particle each); the entries of the boundary unknowns are
 * overwritten. The system keeps the assembler alive; integrate with
 * MFREE_INTEGRATOR_LEAPFROG (central differences, CFL dt <= dx_min / c).
 */
MFREE_API mfree_status_t mfree_system_create_elastodynamic(mfree_context_t *ctx,
                                                           mfree_assembler_t *as,
                                                           double density,
                                                           mfree_system_t **sys);
/**
 * Linear elastodynamics by Galerkin with any approximant: M u'' = g(t) f - K u, K and f
 * from a set-up Galerkin assembler (MFREE_FORM_LAPLACE with c = E for the 1D bar
 * rho u'' = E u'', or an MFREE_FORM_ELASTICITY_* form; tractions, body forces, penalty or
 * Nitsche terms as assembled; the load history g(t) scales the whole load vector), M
 * from a set-up mass assembler on the same particles (MFREE_FORM_MASS, consistent, or
 * MFREE_FORM_MASS_LUMPED; coefficient = density; Bubnov). Unknowns whose rows a node
 * condition replaced (mfree_assembler_add_dirichlet_nodes, FE layer) are constraints as
 * in the collocation system; their mass couplings are dropped (exact for a lumped mass
 * or constant boundary data). Lagrange multipliers are MFREE_ERR_UNSUPPORTED. State
 * y: displacements then velocities (ncomp per particle each). Central differences
 * (MFREE_INTEGRATOR_LEAPFROG) with the step limit 2 / omega_max of M^-1 K (lumped:
 * Gershgorin's bound; consistent: power iteration plus 5 %); mfree_system_assemble_mass
 * gives the identity and, in the velocity block, the mass the right-hand side divides
 * by. The system keeps both assemblers alive. mfree_system_get_stress is
 * MFREE_ERR_UNSUPPORTED: apply the trial approximant's gradient to the displacements.
 */
MFREE_API mfree_status_t mfree_system_create_elastodynamic_galerkin(mfree_context_t *ctx,
                                                                    mfree_assembler_t *stiffness,
                                                                    mfree_assembler_t *mass,
                                                                    mfree_system_t **sys);
MFREE_API mfree_status_t mfree_system_set_load_history(mfree_system_t *sys,
                                                       mfree_history_fn g, void *user);
/** Stress at the particles (1D: sigma = E u'; 2D: xx, yy, xy), boundary constraints
 * applied at time t. */
MFREE_API mfree_status_t mfree_system_get_stress(mfree_system_t *sys, double t,
                                                 const double *y, double *sigma);

#ifdef __cplusplus
}
#endif

#endif /* MFREE_H */
