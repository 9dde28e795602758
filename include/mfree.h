/**
 * @file mfree.h
 * @brief mfree: embeddable meshfree particle approximations (the public C ABI).
 *
 * C99-clean, usable from C++ and, through module mfree, from Fortran 2008. The user
 * guide (docs/index.md) explains the concepts; docs/references.md lists the papers
 * cited here by key, e.g. [Belytschko1998] eq 47.
 *
 * Conventions shared by every function:
 *  - Statuses: every function returns an mfree_status_t: 0 success; negative for
 *    misuse or a resource failure, in which case nothing was changed; positive for a
 *    data-dependent numerical failure, in which case the call completed what it could
 *    and names the affected particles or sites. docs/status-codes.md says what each
 *    code means and what to do. Besides the statuses a function lists, any function
 *    returns MFREE_ERR_NULL for a NULL handle or required pointer and MFREE_ERR_ALLOC
 *    when memory runs out.
 *  - The rule that keeps a host safe (docs/robustness.md): after a negative status the
 *    objects given to the call are unchanged (a failed copy leaves the previous array;
 *    the one exception is stated at mfree_particles_setup); after a positive status,
 *    every site reported valid (status 0 in get_site_status) holds finite values, and
 *    a site whose own data or a neighbour's are invalid, or whose results are not
 *    finite, fails with MFREE_FAIL_NONFINITE or MFREE_FAIL_INVALID_DATA and an all-zero
 *    row.
 *  - Messages: the message of the last failure is kept on the context
 *    (mfree_context_get_last_error); the library never prints, aborts or exits.
 *    Objects sharing a context may fail on several threads at once: the last error is
 *    written and read under a lock, and the error handler may be called concurrently.
 *  - Types: reals are double, particle indices int32_t, offsets and counts of non-zeros
 *    int64_t.
 *  - Ownership: pointer arguments are borrowed for the call only (read or written
 *    during the call, not kept) unless the parameter says "copied" (the host may free
 *    its array on return) or takes an mfree_mem_t (MFREE_COPY: copied; MFREE_BORROW:
 *    the pointer is kept and the array re-read at every setup, update or apply, so the
 *    host keeps it alive). Handles given to a create function are kept alive by the
 *    new object (reference counting), so objects may be destroyed in any order.
 *  - Lifetimes: destroy(&h) accepts NULL and a NULL *h, and sets *h to NULL.
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

/** Status of every call (docs/status-codes.md). Values are frozen. */
typedef MFREE_ENUM(mfree_status) {
  MFREE_SUCCESS = 0,          /**< the call succeeded */

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
  MFREE_ERR_HALO = -8,        /**< an owned particle's support reaches past the halo
                                   width the host declared: its row would miss ghosts */
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
  MFREE_FAIL_SUPPORT = 7      /**< a kernel support exceeds a method's size limit: an
                                   MPFEM node's support reaches an element not
                                   connected to it, so the functions do not interpolate
                                   ([Hao2004] eq 13) */,
  MFREE_FAIL_CAPACITY = 8     /**< a fluid's pool of dormant particles cannot supply an
                                   inflow gate: nothing was changed, the state is the
                                   last valid one */
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
 * Supports are closed: a pair within a relative 1e-13 of the limit counts, so that
 * pairs exactly on the edge are treated alike whatever their round-off. */
typedef MFREE_ENUM(mfree_search) {
  MFREE_SEARCH_GATHER = 1,         /**< r < kappa h_i (row i uses its own support) */
  MFREE_SEARCH_SYMMETRIC_MAX = 2,  /**< r < kappa max(h_i, h_j) */
  MFREE_SEARCH_SYMMETRIC_MEAN = 3  /**< r < kappa (h_i + h_j)/2 */
} mfree_search_t;

/**
 * Smoothing kernels W(r, h) = C_dim / h^dim f(q), q = r/h, with support q <= R.
 * C_dim makes the integral of W over R^dim equal 1 in dimension dim = 1, 2, 3.
 */
typedef MFREE_ENUM(mfree_kernel) {
  MFREE_KERNEL_CUBIC_SPLINE = 1,        /**< cubic B-spline ([Belytschko1998] eq 26,
                                             [ZhangBatra2009] eq 6.6); R = 2 */
  MFREE_KERNEL_QUARTIC = 2,             /**< 1 - 3/2 q^2 + q^3 - 3/16 q^4 ([Lucy1977],
                                             [ZhangBatra2009] eq 6.7); R = 2 */
  MFREE_KERNEL_QUINTIC_SPLINE = 3,      /**< quintic spline ([Morris1996]); R = 3 */
  MFREE_KERNEL_GAUSSIAN = 4,            /**< exp(-q^2), truncated and renormalised at
                                             R = 3 */
  MFREE_KERNEL_SUPER_GAUSS = 5,         /**< (5/2 - q^2) exp(-q^2) ([ZhangBatra2009]
                                             eq 6.9), truncated and renormalised at
                                             R = 3; negative for q^2 > 5/2 */
  MFREE_KERNEL_REVISED_GAUSS = 6,       /**< exp(-q^2) - exp(-4) ([ZhangBatra2009]
                                             eq 6.8); R = 2 */
  MFREE_KERNEL_REVISED_SUPER_GAUSS = 7, /**< (4 - q^2) exp(-a q^2) ([ZhangBatra2009]
                                             eqs 6.10, 6.17); R = 2; parameter a,
                                             default 1 */
  MFREE_KERNEL_WENDLAND_C2 = 8,         /**< Wendland C2 ([Wendland1995]; 1D psi_{2,1},
                                             2D/3D psi_{3,1}); R = 2 */
  MFREE_KERNEL_WENDLAND_C4 = 9,         /**< Wendland C4 ([Wendland1995]; 1D psi_{3,2},
                                             2D/3D psi_{4,2}); R = 2 */
  MFREE_KERNEL_LINEAR = 10,             /**< (2 - q)/4 ([ZhangBatra2009] eq 6.4); R = 2 */
  MFREE_KERNEL_QUADRATIC = 11,          /**< (1 - q/2)^2 ([ZhangBatra2009] eq 6.5);
                                             R = 2 */
  MFREE_KERNEL_QUARTIC_SPLINE = 12,     /**< quartic spline ([Morris1996]); R = 5/2 */
  MFREE_KERNEL_COSINE = 13,             /**< cos(pi q / 2), the MPFEM kernel ([Hao2004]
                                             eq 28, corrected); R = 1, so in 1D
                                             W = (pi/(2d)) cos(pi t/d) with width d = 2h;
                                             C0, gives C1 MPFEM functions */
  MFREE_KERNEL_COSINE_SQUARED = 14,     /**< cos^2(pi q / 2); R = 1 (1D: (2/d)
                                             cos^2(pi t/d)); C1 with zero slope at the
                                             edge ([Hao2004] eq 36), gives C2 */
  MFREE_KERNEL_HAAR = 15                /**< box 1 for q <= 1 ([Hao2004] Sect. 4.2);
                                             R = 1; discontinuous: use it with the
                                             assumed-strain derivatives */
} mfree_kernel_t;

/** Approximation methods; docs/methods.md compares them. Values are frozen. */
typedef MFREE_ENUM(mfree_method) {
  MFREE_METHOD_SPH = 1,               /**< kernel sum and kernel gradient
                                           ([Belytschko1998] eqs 21, 29) */
  MFREE_METHOD_SPH_SYMMETRIC = 2,     /**< symmetrised (difference) gradient
                                           ([Belytschko1998] eq 47); particles only;
                                           the assembler's loads use the kernel
                                           values W dV */
  MFREE_METHOD_SHEPARD = 3,           /**< Shepard functions ([Belytschko1998]
                                           eqs 38-39) */
  MFREE_METHOD_MLS = 4,               /**< moving least squares, order 0..3, shifted and
                                           scaled basis ([Belytschko1998] eqs 43-46) */
  MFREE_METHOD_RKPM = 5,              /**< reproducing kernel particle method, order 0..3
                                           ([ZhangBatra2009] Sect. 4; weights W V, true
                                           derivatives) */
  MFREE_METHOD_JOHNSON_BEISSEL = 6,   /**< Johnson-Beissel correction ([Belytschko1998]
                                           eqs 49, 52); particles only; under an
                                           elasticity form the assembler keeps the
                                           symmetrised SPH shear strain and its loads
                                           use the kernel values W dV */
  MFREE_METHOD_RANDLES_LIBERSKY = 7,  /**< renormalised gradient ([Belytschko1998]
                                           eqs 68-69); particles only; the assembler's
                                           loads use Shepard values (eq 70) */
  MFREE_METHOD_KB_METHOD1 = 8,        /**< Krongauz-Belytschko corrected derivatives,
                                           Method 1 ([Belytschko1998] eqs 55-61) */
  MFREE_METHOD_KB_METHOD2 = 9,        /**< corrected derivatives Method 2, diffuse MLS
                                           derivatives ([Belytschko1998] eqs 63-64) */
  MFREE_METHOD_KB_METHOD3 = 10,       /**< corrected derivatives Method 3
                                           ([Belytschko1998] eqs 65-66) */
  MFREE_METHOD_MSPH = 11,             /**< modified SPH, order 1..2 ([ZhangBatra2009]
                                           Sect. 2) */
  MFREE_METHOD_SSPH = 12,             /**< symmetric SPH, order 1..3 ([ZhangBatra2009]
                                           Sect. 3) */
  MFREE_METHOD_MPFEM = 13             /**< moving particle FEM ([Hao2004]): element
                                           interpolants blended by moving-kernel
                                           weights; needs a mesh
                                           (mfree_approximant_set_mesh) */
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
  MFREE_FALLBACK_LOWER_ORDER = 2  /**< retry with lower orders down to Shepard (as
                                       [CuetoFelgueroso2004] does); sites that still fail
                                       are reported */
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
  MFREE_FORM_COLLOCATION_PLANE_STRESS = 8,     /**< Navier rows at the particles
                                                    ([ZhangBatra2009] Sect. 6.3) */
  MFREE_FORM_COLLOCATION_PLANE_STRAIN = 9      /**< Navier rows, plane strain */
} mfree_form_t;

/** How essential boundary conditions are imposed (docs/boundary-conditions.md). */
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

/** How MPFEM differentiates ([Hao2004]). Values are frozen. */
typedef MFREE_ENUM(mfree_mpfem_deriv) {
  MFREE_MPFEM_DERIV_FULL = 1,           /**< derivative of the approximation, weights
                                             differentiated too ([Hao2004] eq 21); C^n
                                             for a C^(n-1) kernel */
  MFREE_MPFEM_DERIV_ASSUMED_STRAIN = 2, /**< weights not differentiated ([Hao2004]
                                             eq 22): continuous for any kernel, Haar
                                             included */
  MFREE_MPFEM_DERIV_NODAL = 3           /**< at the nodes only: eq 22 with the weights
                                             of the elements around the node by inverse
                                             length/area/volume ([Hao2004] eqs 37-38) */
} mfree_mpfem_deriv_t;

/** Native time integrators ([CuetoFelgueroso2004] eqs 108-121). */
typedef MFREE_ENUM(mfree_integrator) {
  MFREE_INTEGRATOR_LEAPFROG = 1,            /**< leapfrog ([CuetoFelgueroso2004]
                                                 eqs 108-110) */
  MFREE_INTEGRATOR_PREDICTOR_CORRECTOR = 2  /**< predictor-corrector
                                                 ([CuetoFelgueroso2004] eqs 111-119) */
} mfree_integrator_t;

/** Lumped mass of the Galerkin-SPH fluid ([CuetoFelgueroso2004] Sect. 4.3). */
typedef MFREE_ENUM(mfree_lumping) {
  MFREE_LUMP_GALERKIN = 1, /**< M_i = sum_k N_i(x_k) M_k ([CuetoFelgueroso2004] eq 56),
                                the default */
  MFREE_LUMP_PHYSICAL = 2  /**< M_i = physical particle mass ([CuetoFelgueroso2004]
                                eq 58) */
} mfree_lumping_t;

/** Which implementation of the numerics a context's calls run
 * (mfree_context_set_backend), as libCEED's ref and opt backends. */
typedef MFREE_ENUM(mfree_backend) {
  MFREE_BACKEND_REF = 1, /**< the reference path for every method: general shape
                              functions over dense small solves, one plain loop per
                              operator; the oracle of the optimised path */
  MFREE_BACKEND_OPT = 2  /**< the optimised path where a method has one (the common
                              methods' shape functions, fixed-size operator kernels,
                              AVX2 + FMA copies chosen from the CPU), else the
                              reference path; equal to it to round-off. The default */
} mfree_backend_t;

/** OS-level memory tuning a context may ask for (mfree_context_set_page_hints); flags,
 * combined with |. Only without an allocator hook and on Linux; elsewhere ignored. */
typedef MFREE_ENUM(mfree_pages) {
  MFREE_PAGES_DEFAULT = 0,  /**< malloc's pages, no advice (the default) */
  MFREE_PAGES_HUGE = 1,     /**< blocks of 2 MiB or more in mappings of their own advised
                                 MADV_HUGEPAGE (fewer page faults and TLB misses; resident
                                 memory rounded up to whole huge pages) */
  MFREE_PAGES_PREFAULT = 2  /**< tables about to be written front to back are faulted in
                                 with one system call (MADV_POPULATE_WRITE) */
} mfree_pages_t;

/* ------------------------------------------------------------------------------------ */
/* Opaque handles                                                                         */
/* ------------------------------------------------------------------------------------ */

/** Error state, thread count, error handler and allocator; one per host thread. */
typedef struct mfree_context mfree_context_t;
/** Particle positions, volumes, supports and neighbour lists. */
typedef struct mfree_particles mfree_particles_t;
/** Shape-function tables of one method at a set of sites. */
typedef struct mfree_approximant mfree_approximant_t;
/** A sparse matrix in CSR form. */
typedef struct mfree_matrix mfree_matrix_t;
/** Builds Galerkin or collocation matrices and load vectors. */
typedef struct mfree_assembler mfree_assembler_t;
/** A semi-discrete particle system y' = f(t, y). */
typedef struct mfree_system mfree_system_t;
/** Element connectivity over the particles (MPFEM). */
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

/** Run-time version of the library loaded.
 * @return "MAJOR.MINOR.PATCH", a static string */
MFREE_API const char *mfree_version_string(void);

/** Run-time version numbers (compare with the MFREE_VERSION_* macros).
 * @param[out] major  major version, or NULL
 * @param[out] minor  minor version, or NULL
 * @param[out] patch  patch version, or NULL
 * @return MFREE_SUCCESS always */
MFREE_API mfree_status_t mfree_version_get(int32_t *major, int32_t *minor, int32_t *patch);

/** A human-readable name for a status code.
 * @param[in] status  any value
 * @return a static string; "unknown status" for a value that is not a status */
MFREE_API const char *mfree_status_string(mfree_status_t status);

/* ------------------------------------------------------------------------------------ */
/* Context                                                                                */
/* ------------------------------------------------------------------------------------ */

/** Create a context: error state, thread count, error handler, allocator. Use one per
 * host thread.
 * @param[out] ctx  the new context
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_context_create(mfree_context_t **ctx);

/** Release a context. Objects created on it keep it alive until they are destroyed.
 * @param[in,out] ctx  may be NULL or point to NULL; set to NULL
 * @return MFREE_SUCCESS (also for NULL) */
MFREE_API mfree_status_t mfree_context_destroy(mfree_context_t **ctx);

/** The last failure recorded on the context (successful calls leave it unchanged).
 * @param[in]  ctx      the context
 * @param[out] code     the status of the failing call (MFREE_SUCCESS if none); may be NULL
 * @param[out] message  buffer for the NUL-terminated message; may be NULL
 * @param[in]  len      size of message in bytes; the message is truncated to fit
 * @return MFREE_ERR_ARG when message is given and len < 1 */
MFREE_API mfree_status_t mfree_context_get_last_error(const mfree_context_t *ctx,
                                                      mfree_status_t *code, char *message,
                                                      int64_t len);

/** Record a failure on the context as mfree itself does, for adapters and host wrappers
 * built on mfree: sets the last error code and message and calls the error handler.
 * @param[in] ctx      the context
 * @param[in] code     the status to record
 * @param[in] message  NUL-terminated, copied; NULL records an empty message
 * @return code, so that `return mfree_context_set_error(...)` reads naturally */
MFREE_API mfree_status_t mfree_context_set_error(mfree_context_t *ctx, mfree_status_t code,
                                                 const char *message);

/** Install an error handler (NULL removes it). The handler must not call back into
 * mfree with the same context.
 * @param[in] ctx      the context
 * @param[in] handler  called on every recorded failure, or NULL
 * @param[in] user     passed to the handler; kept, not dereferenced by mfree
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_context_set_error_handler(mfree_context_t *ctx,
                                                         mfree_error_handler_t handler,
                                                         void *user);

/** Threads used by objects created on this context (default 1; 0 means all cores).
 * mfree never calls omp_set_* itself.
 * @param[in] ctx       the context
 * @param[in] nthreads  >= 0, else MFREE_ERR_ARG
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_context_set_num_threads(mfree_context_t *ctx,
                                                       int32_t nthreads);
/** The thread count set by mfree_context_set_num_threads.
 * @param[in]  ctx       the context
 * @param[out] nthreads  the count (0: all cores)
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL output */
MFREE_API mfree_status_t mfree_context_get_num_threads(const mfree_context_t *ctx,
                                                       int32_t *nthreads);

/** Run the reference or the optimised path in calls on objects of this context
 * (default MFREE_BACKEND_OPT). Takes effect at the next call; set-up tables are kept
 * (an apply uses the backend in force at the apply).
 * @param[in] ctx      the context
 * @param[in] backend  MFREE_BACKEND_REF or MFREE_BACKEND_OPT, else MFREE_ERR_ARG
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_context_set_backend(mfree_context_t *ctx, int32_t backend);
/** The backend set by mfree_context_set_backend.
 * @param[in]  ctx      the context
 * @param[out] backend  MFREE_BACKEND_REF or MFREE_BACKEND_OPT
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL output */
MFREE_API mfree_status_t mfree_context_get_backend(const mfree_context_t *ctx, int32_t *backend);

/** Ask for OS-level memory tuning in calls on objects of this context (default
 * MFREE_PAGES_DEFAULT: none). For hosts that want the last per cent of speed and accept
 * larger resident memory and extra system calls; ignored with an allocator hook
 * installed and off Linux; MFREE_HUGEPAGES=0 in the environment turns it off for
 * debugging (docs/performance.md).
 * @param[in] ctx    the context
 * @param[in] flags  MFREE_PAGES_* flags combined with |, else MFREE_ERR_ARG
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_context_set_page_hints(mfree_context_t *ctx, int32_t flags);
/** The flags set by mfree_context_set_page_hints.
 * @param[in]  ctx    the context
 * @param[out] flags  MFREE_PAGES_* flags
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL output */
MFREE_API mfree_status_t mfree_context_get_page_hints(const mfree_context_t *ctx, int32_t *flags);

/**
 * Install an allocator for the large arrays (neighbour lists, shape-function tables,
 * their scratch) of calls on objects of this context. Every block goes back to the
 * free function of the allocator that made it, even after the allocator is changed.
 * Both NULL restores the default (malloc; huge pages for large blocks on Linux when
 * asked for with mfree_context_set_page_hints).
 * @param[in] ctx      the context
 * @param[in] alloc    allocation function, or NULL
 * @param[in] release  matching free function, or NULL (both NULL or neither, else
 *                     MFREE_ERR_ARG)
 * @param[in] user     passed to both; kept and not dereferenced by mfree. alloc, release
 *                     and user must stay valid until the objects that used them are
 *                     destroyed
 * @return MFREE_SUCCESS, or a failure named with the parameters
 */
MFREE_API mfree_status_t mfree_context_set_allocator(mfree_context_t *ctx, mfree_alloc_fn alloc,
                                                     mfree_free_fn release, void *user);

/**
 * The context an object was created on, for host wrappers that check arguments
 * themselves and record their failures with mfree_context_set_error (the Fortran module
 * does). One function per object type, all alike.
 * @param[in]  ps   the object (particle set, approximant, mesh, matrix, assembler,
 *                  system)
 * @param[out] ctx  its context, borrowed: the object keeps it alive; never destroy it
 * @return MFREE_SUCCESS; MFREE_ERR_NULL (without a message: there is no context to
 *         hold one) for a NULL handle or output
 */
MFREE_API mfree_status_t mfree_particles_get_context(const mfree_particles_t *ps,
                                                     mfree_context_t **ctx);
/** As mfree_particles_get_context, for an approximant.
 * @param[in] a the approximant @param[out] ctx its context (borrowed)
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL handle or output */
MFREE_API mfree_status_t mfree_approximant_get_context(const mfree_approximant_t *a,
                                                       mfree_context_t **ctx);
/** As mfree_particles_get_context, for a mesh.
 * @param[in] mesh the mesh @param[out] ctx its context (borrowed)
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL handle or output */
MFREE_API mfree_status_t mfree_mesh_get_context(const mfree_mesh_t *mesh, mfree_context_t **ctx);
/** As mfree_particles_get_context, for a matrix.
 * @param[in] A the matrix @param[out] ctx its context (borrowed)
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL handle or output */
MFREE_API mfree_status_t mfree_matrix_get_context(const mfree_matrix_t *A, mfree_context_t **ctx);
/** As mfree_particles_get_context, for an assembler.
 * @param[in] as the assembler @param[out] ctx its context (borrowed)
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL handle or output */
MFREE_API mfree_status_t mfree_assembler_get_context(const mfree_assembler_t *as,
                                                     mfree_context_t **ctx);
/** As mfree_particles_get_context, for a system.
 * @param[in] sys the system @param[out] ctx its context (borrowed)
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL handle or output */
MFREE_API mfree_status_t mfree_system_get_context(const mfree_system_t *sys,
                                                  mfree_context_t **ctx);

/** The particle set an approximant is built on, so that a wrapper can size the arrays it
 * passes (dimension, particle count, pairs).
 * @param[in] a the approximant @param[out] ps its particle set, borrowed (a keeps it
 * alive; never destroy it)
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL handle or output */
MFREE_API mfree_status_t mfree_approximant_get_particles(const mfree_approximant_t *a,
                                                         mfree_particles_t **ps);
/** The particle set a mesh is built on (as mfree_approximant_get_particles).
 * @param[in] mesh the mesh @param[out] ps its particle set (borrowed)
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL handle or output */
MFREE_API mfree_status_t mfree_mesh_get_particles(const mfree_mesh_t *mesh,
                                                  mfree_particles_t **ps);

/* ------------------------------------------------------------------------------------ */
/* Kernels                                                                                */
/* ------------------------------------------------------------------------------------ */

/**
 * Evaluate a kernel and its radial derivatives at n distances.
 * @param[in]  ctx     context for the error message
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
 * @return MFREE_ERR_ARG for an unknown kernel or a bad dim, param, h or n;
 *         MFREE_ERR_INPUT for a negative or non-finite distance
 */
MFREE_API mfree_status_t mfree_kernel_eval(mfree_context_t *ctx, mfree_kernel_t kernel,
                                           int32_t dim, double param, double h, int64_t n,
                                           const double *r, double *w, double *dwdr,
                                           double *d2wdr2);

/** Support radius R in units of h: W(r, h) = 0 for r > R h. The support is closed: at
 * r = R h (up to a relative 1e-13) W and its derivatives take their values from inside.
 * @param[in]  ctx     context for the error message
 * @param[in]  kernel  an mfree_kernel_t (else MFREE_ERR_ARG)
 * @param[in]  param   shape parameter, as for mfree_kernel_eval
 * @param[out] radius  R
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL output */
MFREE_API mfree_status_t mfree_kernel_get_support_radius(mfree_context_t *ctx,
                                                         mfree_kernel_t kernel,
                                                         double param, double *radius);

/** The constant C_dim in W = C_dim / h^dim f(q). For the Gauss family of
 * [ZhangBatra2009] (W = G/(h sqrt(pi))^dim f) this is G / pi^(dim/2).
 * @param[in]  ctx     context for the error message
 * @param[in]  kernel  an mfree_kernel_t (else MFREE_ERR_ARG)
 * @param[in]  dim     1, 2 or 3 (else MFREE_ERR_ARG)
 * @param[in]  param   shape parameter, as for mfree_kernel_eval
 * @param[out] c       C_dim
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL output */
MFREE_API mfree_status_t mfree_kernel_get_normalization(mfree_context_t *ctx,
                                                        mfree_kernel_t kernel, int32_t dim,
                                                        double param, double *c);

/* ------------------------------------------------------------------------------------ */
/* Particle sets                                                                          */
/* ------------------------------------------------------------------------------------ */

/**
 * Create a particle set of n particles in dimension dim. The last n_ghost particles
 * (mfree_particles_set_num_ghost) are ghosts: they serve as neighbours but get no rows
 * of their own.
 * @param[in]  ctx  context (kept alive by the set)
 * @param[in]  dim  1, 2 or 3 (else MFREE_ERR_ARG)
 * @param[in]  n    number of particles, owned plus ghost (>= 0, else MFREE_ERR_ARG)
 * @param[out] ps   the new particle set
 * @return MFREE_SUCCESS, or a failure named with the parameters
 */
MFREE_API mfree_status_t mfree_particles_create(mfree_context_t *ctx, int32_t dim,
                                                int32_t n, mfree_particles_t **ps);

/** Release a particle set (objects built on it keep it alive).
 * @param[in,out] ps  may be NULL or point to NULL; set to NULL
 * @return MFREE_SUCCESS (also for NULL) */
MFREE_API mfree_status_t mfree_particles_destroy(mfree_particles_t **ps);

/** Make the last n_ghost particles ghosts. Default 0.
 * @param[in] ps       the set
 * @param[in] n_ghost  0 <= n_ghost <= n, else MFREE_ERR_ARG
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_particles_set_num_ghost(mfree_particles_t *ps,
                                                       int32_t n_ghost);

/**
 * Positions, dim components per particle. Required before setup.
 * @param[in] ps      the set
 * @param[in] x       coordinates (finite, else MFREE_ERR_INPUT for copied arrays);
 *                    copied or borrowed according to mem
 * @param[in] layout  MFREE_LAYOUT_AOS (x[i*ld + d], ld >= dim) or
 *                    MFREE_LAYOUT_SOA (x[d*ld + i], ld >= n)
 * @param[in] ld      leading dimension, in doubles (too small, or so large that the last
 *                    entry's offset overflows a 64-bit index: MFREE_ERR_ARG)
 * @param[in] mem     MFREE_COPY or MFREE_BORROW
 * @return MFREE_SUCCESS, or a failure named with the parameters
 */
MFREE_API mfree_status_t mfree_particles_set_positions(mfree_particles_t *ps,
                                                       const double *x,
                                                       mfree_layout_t layout, int64_t ld,
                                                       mfree_mem_t mem);

/**
 * Per-particle scalars: element i is a[i*stride]; stride 0 gives every particle a[0];
 * a negative stride is MFREE_ERR_ARG. Values must be finite and > 0 (else
 * MFREE_ERR_INPUT for copied arrays; borrowed ones are checked at setup). Copied or
 * borrowed according to mem.
 *  - volumes: Delta V_i. When unset, volumes are masses / densities.
 *  - masses, densities: used for volumes (V_i = m_i / rho_i) when volumes are unset.
 *  - support: smoothing lengths h_i (the kernel support radius is R h_i); required
 *    before a search.
 * @param[in] ps      the set
 * @param[in] v       the values
 * @param[in] stride  distance between consecutive values, in doubles (>= 0)
 * @param[in] mem     MFREE_COPY or MFREE_BORROW
 * @return MFREE_SUCCESS, or a failure named with the parameters
 */
MFREE_API mfree_status_t mfree_particles_set_volumes(mfree_particles_t *ps,
                                                     const double *v, int64_t stride,
                                                     mfree_mem_t mem);
/** Particle masses; as mfree_particles_set_volumes.
 * @param[in] ps the set @param[in] m masses @param[in] stride >= 0
 * @param[in] mem MFREE_COPY or MFREE_BORROW
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_particles_set_masses(mfree_particles_t *ps,
                                                    const double *m, int64_t stride,
                                                    mfree_mem_t mem);
/** Particle densities; as mfree_particles_set_volumes.
 * @param[in] ps the set @param[in] rho densities @param[in] stride >= 0
 * @param[in] mem MFREE_COPY or MFREE_BORROW
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_particles_set_densities(mfree_particles_t *ps,
                                                       const double *rho, int64_t stride,
                                                       mfree_mem_t mem);
/** Smoothing lengths h_i; as mfree_particles_set_volumes.
 * @param[in] ps the set @param[in] h supports @param[in] stride >= 0
 * @param[in] mem MFREE_COPY or MFREE_BORROW
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_particles_set_support(mfree_particles_t *ps,
                                                     const double *h, int64_t stride,
                                                     mfree_mem_t mem);

/**
 * Neighbour criterion and radius multiplier: j is a neighbour of i when their distance
 * is below kappa times the convention's support. Default MFREE_SEARCH_GATHER, kappa 2
 * (the support of the cubic spline and of the kernels of [ZhangBatra2009]).
 * @param[in] ps          the set
 * @param[in] convention  an mfree_search_t (else MFREE_ERR_ARG)
 * @param[in] kappa       finite and > 0 (else MFREE_ERR_ARG)
 * @return MFREE_SUCCESS, or a failure named with the parameters
 */
MFREE_API mfree_status_t mfree_particles_set_search(mfree_particles_t *ps,
                                                    mfree_search_t convention,
                                                    double kappa);

/**
 * Verlet skin of the neighbour search, for sets set up again after small moves (time
 * steps). With skin s > 0 a setup that searches keeps candidate lists of search radius
 * kappa h + s; later setups filter their rows from the candidates while no valid
 * particle has moved, plus grown its radius kappa h_i, by more than s / 2 since the
 * candidates were built, and search again otherwise. The lists of
 * mfree_particles_get_neighbors are always those of a search without a skin, in the same
 * order; only the cost changes (mfree_particles_get_search_count counts the searches).
 * A periodic axis shorter than 2 (kappa h + s) gets a search at every setup. Costs
 * memory for the candidates (about (1 + s / (kappa h))^dim times the lists) and the
 * positions at the last search.
 * @param[in] ps    the set
 * @param[in] skin  finite and >= 0, in length units (else MFREE_ERR_ARG, nothing
 *                  changed); 0, the default, searches at every setup
 * @return MFREE_SUCCESS, or a failure naming the value
 */
MFREE_API mfree_status_t mfree_particles_set_search_skin(mfree_particles_t *ps, double skin);

/**
 * Number of neighbour searches the setups of the set have run: every setup without a
 * skin (unless the lists are the host's), with a skin only those that (re)built the
 * candidate lists.
 * @param[in]  ps     the set
 * @param[out] count  the count (0 before the first setup)
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL output
 */
MFREE_API mfree_status_t mfree_particles_get_search_count(const mfree_particles_t *ps,
                                                          int64_t *count);

/**
 * A box [lo, hi) with periodic axes. Distances use the nearest image along periodic
 * axes; kappa h must stay below half the box length there.
 * @param[in] ps        the set
 * @param[in] lo        dim lower bounds (finite, else MFREE_ERR_INPUT; copied)
 * @param[in] hi        dim upper bounds, hi > lo (else MFREE_ERR_ARG; copied); a
 *                      periodic axis whose length hi - lo overflows is MFREE_ERR_INPUT
 * @param[in] periodic  dim flags, nonzero for a periodic axis (copied)
 * @return MFREE_SUCCESS, or a failure named with the parameters
 */
MFREE_API mfree_status_t mfree_particles_set_periodic(mfree_particles_t *ps,
                                                      const double *lo, const double *hi,
                                                      const int32_t *periodic);

/**
 * Host-supplied neighbour lists, one row per owned particle (CSR); mfree then does no
 * search of its own (docs/drop-in-csr.md). Rows need not be sorted nor contain the
 * particle itself. A malformed list (a column out of range or twice in a row, rowptr
 * not monotone) is MFREE_ERR_INPUT.
 * @param[in] ps          the set
 * @param[in] rowptr      n_owned + 1 monotone offsets, rowptr[0] = index_base
 * @param[in] cols        column indices in [index_base, index_base + n)
 * @param[in] index_base  0 (C) or 1 (Fortran) for both arrays (else MFREE_ERR_ARG)
 * @param[in] mem         copied or borrowed (borrowed lists are re-validated at setup)
 * @return MFREE_SUCCESS, or a failure named with the parameters
 */
MFREE_API mfree_status_t mfree_particles_set_neighbors(mfree_particles_t *ps,
                                                       const int64_t *rowptr,
                                                       const int32_t *cols,
                                                       int32_t index_base,
                                                       mfree_mem_t mem);

/**
 * Global ids (optional), one per particle, owned and ghost (a ghost carries the id of the
 * particle it copies). With ids every neighbour row (searched or the host's), table row
 * and sum over a row (setup, update, apply) runs in ascending global-id order, so an
 * owned particle's results depend only on its neighbourhood, never on the local
 * numbering: split over ranks, it gets the bits of the one-rank run (docs/mpi.md). Rows
 * of mfree_particles_get_neighbors and mfree_approximant_assemble_csr are then in id
 * order (columns stay local indices). Without ids (the default) rows are sorted by index.
 * @param[in] ps   the set
 * @param[in] ids  n values, >= 0 and unique in the set, or NULL to remove the ids;
 *                 copied or borrowed (borrowed ids are re-checked at every setup)
 * @param[in] mem  MFREE_COPY or MFREE_BORROW (else MFREE_ERR_ARG)
 * @return MFREE_ERR_INPUT for a negative or repeated id (the message names both
 *         particles; at setup for borrowed ids), nothing changed
 */
MFREE_API mfree_status_t mfree_particles_set_global_ids(mfree_particles_t *ps,
                                                        const int64_t *ids, mfree_mem_t mem);

/** Copy the global ids.
 * @param[in]  ps   the set
 * @param[out] ids  n values
 * @return MFREE_ERR_STATE when the set has no global ids */
MFREE_API mfree_status_t mfree_particles_get_global_ids(const mfree_particles_t *ps,
                                                        int64_t *ids);

/**
 * Declare the halo width: the host promises that every particle within distance w of an
 * owned particle is in the set (owned or ghost). Particle setup then checks the search
 * radius kappa h_i of every valid owned particle (with the symmetric conventions, kappa
 * times the largest support present), approximant setup the kernel support R h, against
 * w, instead of building rows that silently miss ghosts. The ghosts each method needs:
 * docs/mpi.md (one support radius for rows at owned particles).
 * @param[in] ps  the set
 * @param[in] w   finite and >= 0 (else MFREE_ERR_ARG); 0, the default, checks nothing
 * @return MFREE_SUCCESS; setups then return MFREE_ERR_HALO naming the particle
 */
MFREE_API mfree_status_t mfree_particles_set_halo_width(mfree_particles_t *ps, double w);

/**
 * A host half pair list instead of CSR lists (each replaces the other; docs/pair-lists.md):
 * pair k joins particles pair_i[k] and pair_j[k], each unordered pair listed once, in
 * any order, as a legacy hydrocode's pair_i, pair_j, niac. Setup builds the rows from it
 * in O(npairs + n), without a search: row i holds every j paired with i, ascending (by
 * global id when the set has ids), as CSR lists of the same neighbourhoods would (the
 * tables are the same bit for bit).
 * Pairs may join owned particles and ghosts (ghosts get no rows); pairs between two
 * ghosts are ignored. The pair order is kept for mfree_approximant_get_pair_gradients.
 * Messages name pairs and particles in the host's numbering (1-based for index_base 1).
 * @param[in] ps              the set
 * @param[in] npairs          number of pairs (>= 0, else MFREE_ERR_ARG)
 * @param[in] pair_i, pair_j  npairs particle indices each, in [index_base,
 *                            index_base + n); may be NULL when npairs is 0
 * @param[in] index_base      0 (C) or 1 (Fortran) (else MFREE_ERR_ARG)
 * @param[in] mem             copied or borrowed (borrowed lists are re-read and
 *                            re-checked at every setup)
 * @return MFREE_SUCCESS; MFREE_ERR_INPUT for an index out of range or a self pair (here
 *         and at setup) and, at setup, for a pair listed twice in either orientation
 */
MFREE_API mfree_status_t mfree_particles_set_pairs(mfree_particles_t *ps, int64_t npairs,
                                                   const int32_t *pair_i,
                                                   const int32_t *pair_j,
                                                   int32_t index_base, mfree_mem_t mem);

/** Number of pairs of the set's pair list.
 * @param[in] ps the set @param[out] npairs the count
 * @return MFREE_SUCCESS; MFREE_ERR_STATE when the set has no pair list */
MFREE_API mfree_status_t mfree_particles_get_num_pairs(const mfree_particles_t *ps,
                                                       int64_t *npairs);

/**
 * Validate the particle data and build the neighbour lists (cell-list search, or the
 * host's lists). A particle whose borrowed data are non-finite or out of range is
 * isolated (empty row, listed by no other row) and named by
 * mfree_particles_get_site_status. The set keeps the search's buffers, so a repeated
 * setup (e.g. every time step) allocates nothing once sizes have settled. One exception
 * to "a failed call changes nothing": when memory runs out while a one-thread search
 * grows its lists, the old lists are gone and the set is no longer set up.
 * @param[in] ps  the set
 * @return MFREE_ERR_STATE without positions or supports; MFREE_ERR_MISMATCH when host
 *         lists do not match the owned count; MFREE_ERR_INPUT for malformed borrowed
 *         lists; MFREE_FAIL_NONFINITE or MFREE_FAIL_INVALID_DATA for isolated particles
 */
MFREE_API mfree_status_t mfree_particles_setup(mfree_particles_t *ps);

/** Re-read and re-validate borrowed data after particles moved; the neighbour lists
 * are kept (use setup to search again).
 * @param[in] ps  the set
 * @return MFREE_ERR_STATE before setup; positive statuses as setup */
MFREE_API mfree_status_t mfree_particles_update(mfree_particles_t *ps);

/** The dimension of the set.
 * @param[in] ps the set @param[out] dim 1, 2 or 3
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL output */
MFREE_API mfree_status_t mfree_particles_get_dimension(const mfree_particles_t *ps,
                                                       int32_t *dim);
/** Particle counts.
 * @param[in]  ps       the set
 * @param[out] n        owned plus ghost particles, or NULL
 * @param[out] n_ghost  ghosts, or NULL
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL output */
MFREE_API mfree_status_t mfree_particles_get_size(const mfree_particles_t *ps, int32_t *n,
                                                  int32_t *n_ghost);

/** Number of stored neighbour pairs.
 * @param[in] ps the set @param[out] nnz the count
 * @return MFREE_ERR_STATE before setup */
MFREE_API mfree_status_t mfree_particles_get_neighbor_nnz(const mfree_particles_t *ps,
                                                          int64_t *nnz);

/**
 * Copy the neighbour lists: 0-based CSR, one row per owned particle, each row sorted
 * ascending (by ascending global id when the set has ids); searched rows include the
 * particle itself.
 * @param[in]  ps      the set
 * @param[out] rowptr  n_owned + 1 offsets
 * @param[out] cols    nnz column indices (size from mfree_particles_get_neighbor_nnz)
 * @return MFREE_ERR_STATE before setup
 */
MFREE_API mfree_status_t mfree_particles_get_neighbors(const mfree_particles_t *ps,
                                                       int64_t *rowptr, int32_t *cols);

/**
 * Copy the particle volumes: the set volumes, or masses / densities when volumes are
 * unset (borrowed arrays are read now).
 * @param[in]  ps  the set
 * @param[out] v   n values
 * @return MFREE_ERR_STATE when neither volumes nor masses and densities are set
 */
MFREE_API mfree_status_t mfree_particles_get_volumes(const mfree_particles_t *ps, double *v);

/**
 * Per-particle status of the last setup or update: 0, or the positive status that
 * isolated the particle.
 * @param[in]  ps       the set
 * @param[out] status   n values
 * @param[out] nfailed  number of nonzero entries, or NULL
 * @return MFREE_ERR_STATE before setup
 */
MFREE_API mfree_status_t mfree_particles_get_site_status(const mfree_particles_t *ps,
                                                         int32_t *status, int32_t *nfailed);

/* ------------------------------------------------------------------------------------ */
/* Meshes (element connectivity over the particles, for MPFEM)                            */
/* ------------------------------------------------------------------------------------ */

/**
 * A finite-element mesh whose nodes are the particles of ps: the nodes move with the
 * particles (borrowed positions are re-read at every setup). Add blocks of elements
 * with mfree_mesh_add_elements; a mesh may mix element types of its dimension.
 * @param[in]  ctx   context (kept alive)
 * @param[in]  ps    the particle set (kept alive)
 * @param[out] mesh  the new mesh
 * @return MFREE_SUCCESS, or a failure named with the parameters
 */
MFREE_API mfree_status_t mfree_mesh_create(mfree_context_t *ctx, mfree_particles_t *ps,
                                           mfree_mesh_t **mesh);
/** Release a mesh (approximants using it keep it alive).
 * @param[in,out] mesh  may be NULL or point to NULL; set to NULL
 * @return MFREE_SUCCESS (also for NULL) */
MFREE_API mfree_status_t mfree_mesh_destroy(mfree_mesh_t **mesh);

/**
 * Append nelem elements of one type.
 * @param[in] mesh        the mesh
 * @param[in] type        an mfree_element_t whose dimension is the particle set's
 *                        (else MFREE_ERR_MISMATCH)
 * @param[in] nelem       number of elements (>= 0)
 * @param[in] conn        nodes per element (2, 3, 4, 8) consecutive per element:
 *                        particle indices in [index_base, index_base + n); copied or
 *                        borrowed (re-read and re-checked at every setup) per mem
 * @param[in] index_base  0 (C) or 1 (Fortran)
 * @param[in] mem         MFREE_COPY or MFREE_BORROW
 * @return MFREE_ERR_INPUT for an index out of range or repeated within an element
 *         (copied arrays are checked here, borrowed ones at setup)
 */
MFREE_API mfree_status_t mfree_mesh_add_elements(mfree_mesh_t *mesh, mfree_element_t type,
                                                 int32_t nelem, const int32_t *conn,
                                                 int32_t index_base, mfree_mem_t mem);

/**
 * Check the mesh at the current node positions: indices in range, positive length
 * (LINE2), positive Jacobian at every corner (TRI3, QUAD4 counter-clockwise and convex;
 * HEX8), and solvable general shape functions (a QUAD4 whose nodes make {1, x, y, xy}
 * singular is rejected). Approximants repeat these checks at their own setup.
 * @param[in] mesh  the mesh
 * @return MFREE_ERR_INPUT naming the first bad element
 */
MFREE_API mfree_status_t mfree_mesh_setup(mfree_mesh_t *mesh);

/** Number of elements.
 * @param[in] mesh the mesh @param[out] nelem the count
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL output */
MFREE_API mfree_status_t mfree_mesh_get_size(const mfree_mesh_t *mesh, int32_t *nelem);

/**
 * Gauss quadrature over the mesh, e.g. for mfree_assembler_set_quadrature_points:
 * ngauss points per direction and element (LINE2 ngauss, QUAD4 ngauss^2 and HEX8
 * ngauss^3 through the isoparametric map, TRI3 a collapsed ngauss^2 rule), in element
 * order. Call with x = w = NULL to get the count first. MPFEM integrands are not
 * polynomials; docs/methods.md says how many points they need.
 * @param[in]  mesh    the mesh
 * @param[in]  ngauss  1..10 (else MFREE_ERR_ARG)
 * @param[out] npts    number of points
 * @param[out] x       dim coordinates per point (AoS), or NULL
 * @param[out] w       weights (|J| times the rule's weight), or NULL
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL output
 */
MFREE_API mfree_status_t mfree_mesh_get_quadrature(mfree_mesh_t *mesh, int32_t ngauss,
                                                   int32_t *npts, double *x, double *w);

/* ------------------------------------------------------------------------------------ */
/* Approximants                                                                           */
/* ------------------------------------------------------------------------------------ */

/**
 * Create an approximant of the given method on a particle set. Defaults: cubic spline
 * kernel (cosine for MPFEM), derivatives VALUE|GRADIENT, order 1 for MLS and KB Method
 * 2, 2 for RKPM, MSPH and SSPH; sites = the owned particles; no fallback. The kernel's
 * support radius R must not exceed the set's search multiplier kappa.
 * @param[in]  ctx     context (kept alive)
 * @param[in]  ps      the particle set (kept alive)
 * @param[in]  method  an mfree_method_t (else MFREE_ERR_ARG)
 * @param[out] a       the new approximant
 * @return MFREE_SUCCESS, or a failure named with the parameters
 */
MFREE_API mfree_status_t mfree_approximant_create(mfree_context_t *ctx,
                                                  mfree_particles_t *ps,
                                                  mfree_method_t method,
                                                  mfree_approximant_t **a);
/** Release an approximant (assemblers copy their configuration and do not need it).
 * @param[in,out] a  may be NULL or point to NULL; set to NULL
 * @return MFREE_SUCCESS (also for NULL) */
MFREE_API mfree_status_t mfree_approximant_destroy(mfree_approximant_t **a);

/** Kernel (weight function) and its shape parameter.
 * @param[in] a       the approximant
 * @param[in] kernel  an mfree_kernel_t (else MFREE_ERR_ARG)
 * @param[in] param   shape parameter, 0 for the default
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_approximant_set_kernel(mfree_approximant_t *a,
                                                      mfree_kernel_t kernel, double param);
/** Polynomial order of MLS and RKPM (0..3), SSPH (1..3), MSPH (1..2), KB Method 2
 * (1..2); other methods accept only their own order.
 * @param[in] a      the approximant
 * @param[in] order  the order (outside the method's range: MFREE_ERR_UNSUPPORTED)
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_approximant_set_order(mfree_approximant_t *a, int32_t order);
/** Tables to build.
 * @param[in] a      the approximant
 * @param[in] flags  an or of mfree_deriv_t flags
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_approximant_set_derivatives(mfree_approximant_t *a,
                                                           int32_t flags);
/** What setup does at a site whose local system fails.
 * @param[in] a       the approximant
 * @param[in] policy  an mfree_fallback_t (else MFREE_ERR_ARG)
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_approximant_set_fallback(mfree_approximant_t *a,
                                                        mfree_fallback_t policy);

/**
 * The mesh of an MPFEM approximant, required before its setup ([Hao2004];
 * docs/methods.md describes the construction, its kernels and quadrature). Setup
 * checks the interpolation condition at every node: when a node's support reaches an
 * element that does not contain it, the tables are still built but setup returns
 * MFREE_FAIL_SUPPORT naming the node; a site whose support reaches no element gets a
 * zero row and MFREE_FAIL_NEIGHBORS. HEX8 elements must be axis-aligned bricks.
 * @param[in] a     an MFREE_METHOD_MPFEM approximant (else MFREE_ERR_UNSUPPORTED)
 * @param[in] mesh  a mesh on the approximant's particle set (else MFREE_ERR_MISMATCH);
 *                  kept alive
 * @return MFREE_SUCCESS, or a failure named with the parameters
 */
MFREE_API mfree_status_t mfree_approximant_set_mesh(mfree_approximant_t *a,
                                                    mfree_mesh_t *mesh);

/**
 * MPFEM options (defaults: MFREE_MPFEM_DERIV_FULL, ngauss 8).
 * @param[in] a       an MPFEM approximant
 * @param[in] deriv   how gradients and Hessians are formed (mfree_mpfem_deriv_t);
 *                    MFREE_MPFEM_DERIV_NODAL needs the sites to be the particles; FULL
 *                    Hessians need a continuous kernel (not MFREE_KERNEL_HAAR)
 * @param[in] ngauss  Gauss points per smooth piece of the edge integrals (1..20)
 * @return MFREE_SUCCESS, or a failure named with the parameters
 */
MFREE_API mfree_status_t mfree_approximant_set_mpfem(mfree_approximant_t *a,
                                                     mfree_mpfem_deriv_t deriv,
                                                     int32_t ngauss);

/**
 * Evaluate at host points (e.g. quadrature points) instead of the particles. Each
 * point's support is the site's h; neighbours are searched with the particle set's
 * convention and kappa. Not available for particles-only methods
 * (MFREE_ERR_UNSUPPORTED).
 * @param[in] a         the approximant
 * @param[in] npts      number of points (>= 0)
 * @param[in] x         coordinates; copied or borrowed per mem
 * @param[in] layout    as for particle positions
 * @param[in] ld        leading dimension, in doubles
 * @param[in] h         point supports, element i at h[i*h_stride]; copied or borrowed
 *                      per mem
 * @param[in] h_stride  stride of h (0: one value)
 * @param[in] mem       MFREE_COPY or MFREE_BORROW
 * @return MFREE_SUCCESS, or a failure named with the parameters
 */
MFREE_API mfree_status_t mfree_approximant_set_points(mfree_approximant_t *a, int32_t npts,
                                                      const double *x, mfree_layout_t layout,
                                                      int64_t ld, const double *h,
                                                      int64_t h_stride, mfree_mem_t mem);

/**
 * Build the shape-function tables (setting up the particle set first if it never was).
 * Sites whose local system fails get all-zero rows and are listed by
 * mfree_approximant_get_site_status; with MFREE_FALLBACK_LOWER_ORDER they first retry
 * lower orders (mfree_approximant_get_site_order).
 * @param[in] a  the approximant
 * @return MFREE_FAIL_SINGULAR or MFREE_FAIL_NEIGHBORS for failed sites;
 *         MFREE_FAIL_NONFINITE for a site whose results are not finite (e.g. a support
 *         so small that the kernel overflows); the particle set's statuses;
 *         MFREE_FAIL_SUPPORT (MPFEM)
 */
MFREE_API mfree_status_t mfree_approximant_setup(mfree_approximant_t *a);

/** Recompute the tables after particles (borrowed positions) moved, keeping the
 * neighbour pattern. Allocates nothing. Borrowed data are re-read: a site whose own
 * data or a neighbour's turned non-finite or out of range fails (MFREE_FAIL_NONFINITE,
 * MFREE_FAIL_INVALID_DATA) with an all-zero row, also without mfree_particles_update.
 * @param[in] a  the approximant
 * @return MFREE_ERR_STATE before setup, and when the particle set changed under the
 *         approximant: a set_* call on the set since its last setup, or a setup of the
 *         set that found another ghost count or other neighbour lists than the
 *         approximant's setup saw (call mfree_approximant_setup; the tables are kept
 *         unchanged meanwhile); positive statuses as setup */
MFREE_API mfree_status_t mfree_approximant_update(mfree_approximant_t *a);

/**
 * out = op(u) at every site. Allocates nothing.
 * @param[in]  a        a set-up approximant (else MFREE_ERR_STATE)
 * @param[in]  op       an mfree_op_t whose table was built (else MFREE_ERR_STATE)
 * @param[in]  ncomp    components of u (MFREE_OP_DIVERGENCE needs ncomp = dim)
 * @param[in]  u        field at the n particles (owned and ghost)
 * @param[in]  ulayout  layout of u
 * @param[in]  uld      leading dimension of u: AOS >= ncomp, SOA >= n
 * @param[out] out      one row per site with the op's output components
 * @param[in]  olayout  layout of out
 * @param[in]  old      leading dimension of out: AOS >= output components, SOA >= sites
 *                      (uld, old so large that the last entry's offset overflows a
 *                      64-bit index: MFREE_ERR_ARG)
 * @return MFREE_SUCCESS, or a failure named with the parameters
 */
MFREE_API mfree_status_t mfree_approximant_apply(const mfree_approximant_t *a, mfree_op_t op,
                                                 int32_t ncomp, const double *u,
                                                 mfree_layout_t ulayout, int64_t uld,
                                                 double *out, mfree_layout_t olayout,
                                                 int64_t old);
/** out += op(u) at every site; parameters and statuses as mfree_approximant_apply.
 * @param[in] a the approximant @param[in] op operator @param[in] ncomp components
 * @param[in] u field @param[in] ulayout layout of u @param[in] uld its leading dimension
 * @param[in,out] out accumulated rows @param[in] olayout layout of out
 * @param[in] old its leading dimension
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_approximant_apply_add(const mfree_approximant_t *a,
                                                     mfree_op_t op, int32_t ncomp,
                                                     const double *u, mfree_layout_t ulayout,
                                                     int64_t uld, double *out,
                                                     mfree_layout_t olayout, int64_t old);

/** Number of sites (owned particles or host points).
 * @param[in] a the approximant @param[out] nsites the count
 * @return MFREE_ERR_STATE before setup */
MFREE_API mfree_status_t mfree_approximant_get_num_sites(const mfree_approximant_t *a,
                                                         int32_t *nsites);
/** Non-zeros of each table (one per site-neighbour pair).
 * @param[in] a the approximant @param[out] nnz the count
 * @return MFREE_ERR_STATE before setup */
MFREE_API mfree_status_t mfree_approximant_get_nnz(const mfree_approximant_t *a,
                                                   int64_t *nnz);
/**
 * Copy one table as CSR (rows = sites, columns = particles).
 * @param[in]  a          a set-up approximant
 * @param[in]  deriv      MFREE_DERIV_VALUE, MFREE_DERIV_GRADIENT or MFREE_DERIV_HESSIAN,
 *                        a table that was built (else MFREE_ERR_STATE)
 * @param[in]  component  direction (gradient) or packed index (Hessian); 0 for values
 * @param[out] rowptr     nsites + 1 offsets
 * @param[out] cols       nnz column indices
 * @param[out] vals       nnz values
 * @return MFREE_SUCCESS, or a failure named with the parameters
 */
MFREE_API mfree_status_t mfree_approximant_assemble_csr(const mfree_approximant_t *a,
                                                        mfree_deriv_t deriv,
                                                        int32_t component, int64_t *rowptr,
                                                        int32_t *cols, double *vals);

/**
 * Maximum violation over all valid sites of the reproducing conditions
 * ([Belytschko1998] eqs 5-9) for every monomial of degree <= order in local
 * coordinates (x_j - x)/h. A table that was not built contributes 0.
 * @param[in]  a          a set-up approximant
 * @param[in]  order      highest monomial degree (0..3)
 * @param[out] fn_err     error of the values
 * @param[out] deriv_err  error of the gradient (scaled by h) and Hessian (by h^2)
 * @return MFREE_SUCCESS, or a failure named with the parameters
 */
MFREE_API mfree_status_t mfree_approximant_check_reproduction(const mfree_approximant_t *a,
                                                              int32_t order, double *fn_err,
                                                              double *deriv_err);

/** Per-site status of the last setup or update: 0 or a positive status.
 * @param[in]  a        a set-up approximant
 * @param[out] status   nsites values
 * @param[out] nfailed  number of nonzero entries, or NULL
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL output */
MFREE_API mfree_status_t mfree_approximant_get_site_status(const mfree_approximant_t *a,
                                                           int32_t *status,
                                                           int32_t *nfailed);
/** Neighbours with non-zero weight at each site.
 * @param[in] a a set-up approximant @param[out] counts nsites values
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL output */
MFREE_API mfree_status_t mfree_approximant_get_neighbor_counts(const mfree_approximant_t *a,
                                                               int32_t *counts);
/** Condition number of each site's local system: the larger of ||A||_1 ||A^-1||_1 and
 * the ratio of the largest to the smallest pivot; infinite when singular; above 1e12
 * the site falls back or fails; 1 where the method solves none.
 * @param[in] a a set-up approximant @param[out] cond nsites values
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL output */
MFREE_API mfree_status_t mfree_approximant_get_condition(const mfree_approximant_t *a,
                                                         double *cond);
/** Order used at each site (differs from the set order after a fallback; -1 for a
 * failed site).
 * @param[in] a a set-up approximant @param[out] order nsites values
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL output */
MFREE_API mfree_status_t mfree_approximant_get_site_order(const mfree_approximant_t *a,
                                                          int32_t *order);

/**
 * Per-pair kernel gradients for a host that loops over its half pair list
 * (mfree_particles_set_pairs; the approximant set up after the set; docs/pair-lists.md).
 * For pair k = (i, j) in the host's order, gi[k*ld + c] is the gradient entry of
 * particle i's row at j and gj[k*ld + c] that of j's row at i, each per unit volume (the
 * table entry divided by V_j, resp. V_i, or by 1 when the set has no volumes), so that
 * summing V_j (u_j - u_i) gi over i's pairs (gj where i is the pair's second particle)
 * gives the method's gradient of u at i, for every method whose rows sum to zero (all
 * the corrected ones). Signs are those of a hydrocode's dwdx = grad_i W(x_i - x_j, h_ij):
 * for MFREE_METHOD_SPH and _SPH_SYMMETRIC, gi is exactly that, from the kernel, and
 * gj = -gi exactly when h_ij is symmetric (search convention SYMMETRIC_MEAN or _MAX, or
 * one h for all). Corrected gradients are not antisymmetric: gj != -gi. For the methods
 * with correction data (mfree_approximant_get_correction) each side is computed from its
 * particle's record and the pair's kernel gradient (RL: M grad w), equal to the table
 * entry divided by the volume to round-off. A side whose particle has no row (a ghost, an
 * isolated particle, a failed site) is 0, except for SPH, which needs no row, and a
 * ghost whose record was given (mfree_approximant_set_ghost_correction); a pair outside
 * the kernel's support is 0. No allocation.
 * @param[in]  a         a set-up approximant at the particles (not MPFEM, not host
 *                       points: MFREE_ERR_UNSUPPORTED) with a gradient table
 * @param[out] gi, gj    npairs records of dim doubles every ld; gj may be NULL
 * @param[in]  ld        doubles from one record to the next (>= dim; 3 for a Fortran
 *                       dwdx(3, :))
 * @param[in]  capacity  doubles each buffer holds, at least (npairs - 1) * ld + dim
 * @return MFREE_SUCCESS; MFREE_ERR_ARG (nothing written) for ld < dim or a capacity too
 *         small; MFREE_ERR_STATE when the set has no pair list, was set up again after
 *         the approximant, or the gradient table was not built
 */
MFREE_API mfree_status_t mfree_approximant_get_pair_gradients(const mfree_approximant_t *a,
                                                              double *gi, double *gj,
                                                              int64_t ld, int64_t capacity);

/**
 * One antisymmetrised gradient per pair, g = (gi - gj) / 2 of
 * mfree_approximant_get_pair_gradients, the j side being -g (a pair with one side
 * without a row takes the other side's). A pair loop that adds m_j F g to i and
 * subtracts m_i F g from j conserves linear momentum to round-off; the price is the
 * method's first-order consistency (the gradient of a linear field is no longer exact).
 * For SPH, g = gi.
 * @param[in] a the approximant @param[out] g npairs records of dim doubles every ld
 * @param[in] ld >= dim @param[in] capacity doubles g holds
 * @return as mfree_approximant_get_pair_gradients
 */
MFREE_API mfree_status_t mfree_approximant_get_pair_gradients_antisymmetric(
    const mfree_approximant_t *a, double *g, int64_t ld, int64_t capacity);

/** Doubles per particle of mfree_approximant_get_correction for the approximant's
 * method (listed there).
 * @param[in] a the approximant @param[out] ncoef the record length
 * @return MFREE_SUCCESS; MFREE_ERR_UNSUPPORTED for a method without correction data */
MFREE_API mfree_status_t mfree_approximant_get_correction_size(const mfree_approximant_t *a,
                                                               int32_t *ncoef);

/**
 * Per-particle correction data, for hosts that apply the correction themselves: one
 * record of ncoef doubles per owned particle i at c[i*ld]. With d = dim,
 * w_j = W(|x_j - x_i|, h_ij), grad w_j its gradient with respect to x_i (the dwdx of the
 * pair (i, j)), V_j the volumes and matrices stored column by column (M(a, b) at
 * a + b*d, Fortran's order), the records are:
 *  - RANDLES_LIBERSKY, d*d: M, the corrected gradient being M grad w_j (M = B^T of
 *    [Belytschko1998] eqs 68-69); the table entry is M grad w_j V_j.
 *  - KB_METHOD1, d*d + 1 + d: M, S = sum_j w_j, grad S; the gradient of neighbour j is
 *    M grad(w_j / S), grad(w_j / S) = grad w_j / S - w_j grad S / S^2 (M = A^-T of
 *    [Belytschko1998] eqs 56-61).
 *  - MLS, RKPM of order <= 2, (d + 1) L with L the basis size: gamma (L), then
 *    d gamma / dx_c (L) for c = 0 .. d-1, so that with s = (x_j - x_i) / h_i and the
 *    monomials p(s) in the order 1; s_1 .. s_d; s_1^2 .. s_d^2; s_1 s_2, s_2 s_3, s_3 s_1:
 *    Phi_j = o_j gamma . p(s) and dPhi_j/dx_c = o_j (d gamma/dx_c) . p(s) +
 *    (grad o_j)_c gamma . p(s), o_j = w_j (MLS) or w_j V_j (RKPM).
 *  - SHEPARD, 1 + d: S and grad S as above. JOHNSON_BEISSEL, d: beta_c
 *    ([Belytschko1998] eq 52).
 * A particle whose site failed or fell back to another order gets zeros (see
 * mfree_approximant_get_site_status, _get_site_order). Every particle's record has the
 * same layout.
 * @param[in]  a         a set-up approximant at the particles
 * @param[out] c         records of ncoef doubles every ld
 * @param[in]  ld        >= ncoef
 * @param[in]  capacity  doubles c holds, at least (n_owned - 1) * ld + ncoef
 * @return MFREE_SUCCESS; MFREE_ERR_ARG (nothing written) for ld or capacity too small;
 *         MFREE_ERR_UNSUPPORTED for a method without correction data (MLS/RKPM of order 3
 *         included); MFREE_ERR_STATE when the set was set up again after the approximant
 */
MFREE_API mfree_status_t mfree_approximant_get_correction(const mfree_approximant_t *a,
                                                          double *c, int64_t ld,
                                                          int64_t capacity);

/**
 * The ghosts' correction data, for a rank whose ghosts are other ranks' particles
 * (docs/mpi.md): c holds one record of ncoef doubles (mfree_approximant_get_correction_size)
 * per ghost, ghost g (g = 0 .. n_ghost-1, the set's ghost order: particle n_owned + g) at
 * c[g*ld], each the record mfree_approximant_get_correction gives for that particle
 * where it is owned. The data are copied. The ghost side of
 * mfree_approximant_get_pair_gradients (and so the antisymmetrised form) is then
 * computed from the ghost's record exactly as the owned side of a particle is from its
 * own (every side of a method with correction data is computed from a record), so that
 * with the records of the ghosts' owners and the same rows (global ids,
 * mfree_particles_set_global_ids) a rank's pair gradients equal those of one process
 * bit for bit. A record of zeros (a site that failed or fell back at its owner) leaves
 * that ghost's side 0. The next mfree_approximant_setup or _update drops the data: the
 * ghost side is 0 again until the next call.
 * @param[in] a         a set-up approximant at the particles
 * @param[in] c         n_ghost records of ncoef doubles every ld; may be NULL without ghosts
 * @param[in] ld        >= ncoef
 * @param[in] capacity  doubles c holds, at least (n_ghost - 1) * ld + ncoef
 * @return MFREE_SUCCESS; MFREE_ERR_ARG for ld or capacity too small; MFREE_ERR_NULL for
 *         c NULL with ghosts; MFREE_ERR_INPUT for a non-finite value (named);
 *         MFREE_ERR_UNSUPPORTED for a method without correction data, host points or
 *         MPFEM; MFREE_ERR_STATE when the approximant is not set up or the set was set
 *         up again after it. A failed call changes nothing.
 */
MFREE_API mfree_status_t mfree_approximant_set_ghost_correction(mfree_approximant_t *a,
                                                                const double *c, int64_t ld,
                                                                int64_t capacity);

/* ------------------------------------------------------------------------------------ */
/* Sparse matrices                                                                        */
/* ------------------------------------------------------------------------------------ */

/**
 * A sparse matrix in CSR form (rows sorted by column) from host arrays, as the
 * assembler produces them. Views give zero-copy access to its arrays for solvers; a
 * view stays valid until the matrix is refilled with another pattern or destroyed.
 * @param[in]  ctx     context (kept alive)
 * @param[in]  nrows   rows (>= 0)
 * @param[in]  ncols   columns (>= 0)
 * @param[in]  rowptr  nrows + 1 offsets (copied)
 * @param[in]  cols    rowptr[nrows] column indices (copied)
 * @param[in]  vals    rowptr[nrows] values (copied)
 * @param[out] A       the new matrix
 * @return MFREE_ERR_INPUT for a malformed CSR
 */
MFREE_API mfree_status_t mfree_matrix_create_csr(mfree_context_t *ctx, int32_t nrows,
                                                 int32_t ncols, const int64_t *rowptr,
                                                 const int32_t *cols, const double *vals,
                                                 mfree_matrix_t **A);
/** Free the matrix; views into it become invalid.
 * @param[in,out] A  may be NULL or point to NULL; set to NULL
 * @return MFREE_SUCCESS (also for NULL) */
MFREE_API mfree_status_t mfree_matrix_destroy(mfree_matrix_t **A);
/** Rows, columns and stored entries.
 * @param[in]  A      the matrix
 * @param[out] nrows  rows, or NULL
 * @param[out] ncols  columns, or NULL
 * @param[out] nnz    stored entries, or NULL
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL output */
MFREE_API mfree_status_t mfree_matrix_get_size(const mfree_matrix_t *A, int32_t *nrows,
                                               int32_t *ncols, int64_t *nnz);
/** Zero-copy CSR view with the ABI index types (borrowed from the matrix).
 * @param[in] A the matrix @param[out] rowptr offsets @param[out] cols columns
 * @param[out] vals values
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL output */
MFREE_API mfree_status_t mfree_matrix_get_csr(const mfree_matrix_t *A,
                                              const int64_t **rowptr,
                                              const int32_t **cols, const double **vals);
/** CSR view with 32-bit offsets (int SuiteSparse variants): index arrays converted once
 * and cached; values not copied.
 * @param[in] A the matrix @param[out] rowptr offsets @param[out] cols columns
 * @param[out] vals values
 * @return MFREE_ERR_UNSUPPORTED when nnz does not fit 32 bits */
MFREE_API mfree_status_t mfree_matrix_get_csr_i32(const mfree_matrix_t *A,
                                                  const int32_t **rowptr,
                                                  const int32_t **cols, const double **vals);
/** CSR view with 64-bit offsets and columns (SuiteSparse_long variants).
 * @param[in] A the matrix @param[out] rowptr offsets @param[out] cols columns
 * @param[out] vals values
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL output */
MFREE_API mfree_status_t mfree_matrix_get_csr_i64(const mfree_matrix_t *A,
                                                  const int64_t **rowptr,
                                                  const int64_t **cols, const double **vals);
/** CSC view (computed on the first request after a fill, then cached).
 * @param[in] A the matrix @param[out] colptr offsets @param[out] rows row indices
 * @param[out] vals values
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL output */
MFREE_API mfree_status_t mfree_matrix_get_csc(const mfree_matrix_t *A,
                                              const int64_t **colptr, const int32_t **rows,
                                              const double **vals);
/** Pattern counter: changes whenever the matrix gets a new sparsity pattern (a refill
 * of the values keeps it), so a solver knows when to redo its symbolic analysis.
 * @param[in] A the matrix @param[out] id the counter
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL output */
MFREE_API mfree_status_t mfree_matrix_get_pattern_id(const mfree_matrix_t *A, int64_t *id);
/** Whether the matrix is symmetric (checked numerically to round-off).
 * @param[in] A the matrix @param[out] symmetric 1 or 0
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL output */
MFREE_API mfree_status_t mfree_matrix_get_symmetric(const mfree_matrix_t *A,
                                                    int32_t *symmetric);
/** y = A x.
 * @param[in] A the matrix @param[in] x ncols values @param[out] y nrows values
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_matrix_apply(const mfree_matrix_t *A, const double *x,
                                            double *y);

/* ------------------------------------------------------------------------------------ */
/* Assembly                                                                               */
/* ------------------------------------------------------------------------------------ */

/**
 * An assembler of the given form with trial functions from trial and test functions
 * from test (NULL: Bubnov-Galerkin, test = trial; Shepard test functions with
 * corrected-derivative trial functions give the Petrov-Galerkin scheme of
 * [Belytschko1998] Sect. 5.2.1). The approximants' configuration (method, kernel,
 * order) is copied. Unknowns are node-major, dof = particle * ncomp + component
 * (ncomp = dim for elasticity, else 1), followed by Lagrange multipliers.
 * @param[in]  ctx    context (kept alive)
 * @param[in]  trial  trial approximant (configuration copied)
 * @param[in]  test   test approximant on the same particle set (else
 *                    MFREE_ERR_MISMATCH), or NULL
 * @param[in]  form   an mfree_form_t (else MFREE_ERR_ARG)
 * @param[out] as     the new assembler
 * @return MFREE_SUCCESS, or a failure named with the parameters
 */
MFREE_API mfree_status_t mfree_assembler_create(mfree_context_t *ctx,
                                                const mfree_approximant_t *trial,
                                                const mfree_approximant_t *test,
                                                mfree_form_t form, mfree_assembler_t **as);
/** Free the assembler; matrices it assembled stay valid (separate objects).
 * @param[in,out] as  may be NULL or point to NULL; set to NULL
 * @return MFREE_SUCCESS (also for NULL) */
MFREE_API mfree_status_t mfree_assembler_destroy(mfree_assembler_t **as);

/** Young's modulus and Poisson ratio of the elasticity forms. Default 1, 0.
 * @param[in] as the assembler @param[in] young E, finite and > 0
 * @param[in] poisson nu, -1 < nu < 1/2 (else MFREE_ERR_ARG)
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_assembler_set_material(mfree_assembler_t *as, double young,
                                                      double poisson);
/** Coefficient c of the Laplace forms, or density rho of the mass forms. Default 1.
 * @param[in] as the assembler @param[in] c finite and > 0 (else MFREE_ERR_ARG)
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_assembler_set_coefficient(mfree_assembler_t *as, double c);

/** Nodal quadrature: points = the particles, weights = their volumes (the default);
 * setup is then MFREE_ERR_STATE when the particle set has no volumes.
 * @param[in] as  the assembler
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_assembler_set_quadrature_nodal(mfree_assembler_t *as);
/**
 * Background cells: a structured grid of ncells[d] cells over [lo, hi] with ngauss^dim
 * Gauss points per cell; points for which inside() is 0 are dropped.
 * @param[in] as      the assembler
 * @param[in] lo      dim lower corners (copied)
 * @param[in] hi      dim upper corners (copied)
 * @param[in] ncells  dim cell counts (copied)
 * @param[in] ngauss  Gauss points per direction and cell
 * @param[in] inside  inside-test, or NULL for all points
 * @param[in] user    passed to inside; kept until setup
 * @return MFREE_SUCCESS, or a failure named with the parameters
 */
MFREE_API mfree_status_t mfree_assembler_set_quadrature_cells(mfree_assembler_t *as,
                                                              const double *lo,
                                                              const double *hi,
                                                              const int32_t *ncells,
                                                              int32_t ngauss,
                                                              mfree_inside_fn inside,
                                                              void *user);
/** Host quadrature points and weights.
 * @param[in] as      the assembler
 * @param[in] npts    number of points
 * @param[in] x       coordinates (copied)
 * @param[in] layout  layout of x
 * @param[in] ld      leading dimension of x
 * @param[in] w       weights, finite and >= 0 (copied; else MFREE_ERR_INPUT)
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_assembler_set_quadrature_points(mfree_assembler_t *as,
                                                               int32_t npts,
                                                               const double *x,
                                                               mfree_layout_t layout,
                                                               int64_t ld, const double *w);

/** Body force b(x).
 * @param[in] as the assembler @param[in] f ncomp values at x, or NULL for none
 * @param[in] user passed to f; kept
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_assembler_set_body_force(mfree_assembler_t *as,
                                                        mfree_field_fn f, void *user);
/**
 * Natural boundary condition on boundary quadrature points: adds
 * sum_p w_p Psi_J(x_p) t(x_p) to the load. For collocation forms use
 * mfree_assembler_add_traction_nodes.
 * @param[in] as      the assembler
 * @param[in] npts    number of points
 * @param[in] x       coordinates (copied)
 * @param[in] layout  layout of x
 * @param[in] ld      leading dimension of x
 * @param[in] w       weights (copied)
 * @param[in] t       the traction, ncomp values at x
 * @param[in] user    passed to t; kept
 * @return MFREE_SUCCESS, or a failure named with the parameters
 */
MFREE_API mfree_status_t mfree_assembler_add_traction(mfree_assembler_t *as, int32_t npts,
                                                      const double *x,
                                                      mfree_layout_t layout, int64_t ld,
                                                      const double *w, mfree_field_fn t,
                                                      void *user);
/** Traction on 2D boundary segments with ngauss Gauss points per segment.
 * @param[in] as      the assembler
 * @param[in] nseg    number of segments
 * @param[in] x       endpoints a_s, b_s at x[4 s .. 4 s + 3] (copied); a segment of zero
 *                    length is MFREE_ERR_INPUT
 * @param[in] ngauss  points per segment
 * @param[in] t       the traction
 * @param[in] user    passed to t; kept
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_assembler_add_traction_segments(mfree_assembler_t *as,
                                                               int32_t nseg,
                                                               const double *x,
                                                               int32_t ngauss,
                                                               mfree_field_fn t, void *user);
/** Traction on 3D boundary triangles with ngauss x ngauss points per triangle (a
 * collapsed Gauss product rule, exact for degree 2 ngauss - 2). Split quadrilateral
 * facets into two triangles.
 * @param[in] as      the assembler
 * @param[in] nfacet  number of triangles
 * @param[in] x       vertices a_f, b_f, c_f at x[9 f .. 9 f + 8] (copied); a triangle of
 *                    zero area is MFREE_ERR_INPUT
 * @param[in] ngauss  points per direction
 * @param[in] t       the traction
 * @param[in] user    passed to t; kept
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_assembler_add_traction_facets(mfree_assembler_t *as,
                                                             int32_t nfacet,
                                                             const double *x,
                                                             int32_t ngauss,
                                                             mfree_field_fn t, void *user);
/**
 * Essential boundary condition u_c = g_c for the components c set in component_mask,
 * on boundary quadrature points, by penalty, Lagrange multipliers or Nitsche's method
 * (docs/boundary-conditions.md compares them; Nitsche passes patch tests, point
 * multipliers do not).
 * @param[in] as              the assembler
 * @param[in] method          MFREE_BC_PENALTY, MFREE_BC_LAGRANGE or MFREE_BC_NITSCHE
 * @param[in] npts            number of points
 * @param[in] x               coordinates (copied)
 * @param[in] layout          layout of x
 * @param[in] ld              leading dimension of x
 * @param[in] w               weights (copied; unused by Lagrange)
 * @param[in] normals         outward unit normals, dim per point (copied; Nitsche),
 *                            else may be NULL
 * @param[in] component_mask  bit c set: component c is prescribed
 * @param[in] g               the prescribed values
 * @param[in] user            passed to g; kept
 * @return MFREE_SUCCESS, or a failure named with the parameters
 */
MFREE_API mfree_status_t mfree_assembler_add_dirichlet(mfree_assembler_t *as,
                                                       mfree_bc_t method, int32_t npts,
                                                       const double *x,
                                                       mfree_layout_t layout, int64_t ld,
                                                       const double *w,
                                                       const double *normals,
                                                       int32_t component_mask,
                                                       mfree_field_fn g, void *user);
/** Essential condition by row replacement at particles (MFREE_BC_COLLOCATION): each
 * prescribed component's row becomes u^h(x_J) = g(x_J); for the particles-only methods
 * it becomes u_J = g(x_J) on the particle value.
 * @param[in] as              the assembler
 * @param[in] nnodes          number of particles
 * @param[in] nodes           0-based particle indices (copied)
 * @param[in] component_mask  bit c set: component c is prescribed
 * @param[in] g               the prescribed values
 * @param[in] user            passed to g; kept
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_assembler_add_dirichlet_nodes(mfree_assembler_t *as,
                                                             int32_t nnodes,
                                                             const int32_t *nodes,
                                                             int32_t component_mask,
                                                             mfree_field_fn g, void *user);
/** Collocation forms: traction rows sigma(u) n = t (Laplace: c grad u . n = t) replace
 * the PDE rows at the given particles.
 * @param[in] as       the assembler
 * @param[in] nnodes   number of particles
 * @param[in] nodes    0-based particle indices (copied)
 * @param[in] normals  outward unit normals, dim per node (copied)
 * @param[in] t        the traction
 * @param[in] user     passed to t; kept
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_assembler_add_traction_nodes(mfree_assembler_t *as,
                                                            int32_t nnodes,
                                                            const int32_t *nodes,
                                                            const double *normals,
                                                            mfree_field_fn t, void *user);
/**
 * The finite-element blending layer of [Belytschko1998] eqs 100-105: one layer of
 * elements along the essential boundary in which the functions blend into FE
 * functions, so that u_c = g_c is imposed directly on the boundary nodes
 * (docs/boundary-conditions.md). Calls accumulate, each with its own nodes, mask and g;
 * every call must use the same element type (else MFREE_ERR_ARG).
 * @param[in] as                 the assembler
 * @param[in] nelem              number of elements
 * @param[in] nodes_per_element  3 (triangles) or 4 (quadrilaterals), 2D
 * @param[in] connectivity       counter-clockwise particle indices (copied)
 * @param[in] ngu                number of layer nodes on the essential boundary
 * @param[in] gu                 those nodes (copied); the other layer nodes form the
 *                               interface to the meshfree region
 * @param[in] component_mask     bit c set: component c is prescribed
 * @param[in] g                  the prescribed values
 * @param[in] user               passed to g; kept
 * @return MFREE_SUCCESS, or a failure named with the parameters
 */
MFREE_API mfree_status_t mfree_assembler_set_fe_layer(mfree_assembler_t *as, int32_t nelem,
                                                      int32_t nodes_per_element,
                                                      const int32_t *connectivity,
                                                      int32_t ngu, const int32_t *gu,
                                                      int32_t component_mask,
                                                      mfree_field_fn g, void *user);
/** Penalty factor alpha (default 1e6 times the modulus E or coefficient c), which is
 * also Nitsche's beta when set (default 100 modulus / mean h).
 * @param[in] as the assembler @param[in] alpha the factor
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_assembler_set_penalty(mfree_assembler_t *as, double alpha);
/**
 * Variationally consistent integration, second order ([Chen2013]), for the Galerkin
 * stiffness forms: corrected test gradients make any domain quadrature, nodal included,
 * pass the linear (quadratic) patch test with linearly (quadratically) complete trial
 * functions (docs/boundary-conditions.md). The matrix is then unsymmetric.
 * @param[in] as       the assembler
 * @param[in] npts     boundary points; 0 switches the correction off
 * @param[in] x        points on the whole boundary (essential and natural parts;
 *                     copied)
 * @param[in] layout   layout of x
 * @param[in] ld       leading dimension of x
 * @param[in] w        weights, non-negative and finite (copied)
 * @param[in] normals  outward unit normals, dim per point (AoS; copied)
 * @return MFREE_ERR_UNSUPPORTED for mass and collocation forms and for particles-only
 *         test functions
 */
MFREE_API mfree_status_t mfree_assembler_set_consistent_integration(mfree_assembler_t *as,
                                                                    int32_t npts,
                                                                    const double *x,
                                                                    mfree_layout_t layout,
                                                                    int64_t ld, const double *w,
                                                                    const double *normals);

/**
 * Build the quadrature, the shape-function tables at the quadrature and boundary points,
 * and the sparsity pattern.
 * @param[in] as  the assembler
 * @return MFREE_FAIL_NEIGHBORS for a quadrature point outside every support or a
 *         particle no quadrature point sees (instead of a silently singular matrix);
 *         MFREE_ERR_STATE for nodal quadrature without volumes
 */
MFREE_API mfree_status_t mfree_assembler_setup(mfree_assembler_t *as);
/** Recompute the tables after particles moved, keeping the pattern.
 * @param[in] as  a set-up assembler (else MFREE_ERR_STATE)
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_assembler_update(mfree_assembler_t *as);
/** Number of unknowns (particles * ncomp + multipliers) and of quadrature points.
 * @param[in] as a set-up assembler @param[out] ndofs unknowns, or NULL
 * @param[out] nquad quadrature points, or NULL
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL output */
MFREE_API mfree_status_t mfree_assembler_get_size(const mfree_assembler_t *as,
                                                  int32_t *ndofs, int32_t *nquad);
/** Assemble the system matrix.
 * @param[in]     as  a set-up assembler
 * @param[in,out] K   *K NULL: a new matrix is created (owned by the host); else it is
 *                    refilled, keeping its pattern when that did not change
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_assembler_assemble_matrix(mfree_assembler_t *as,
                                                         mfree_matrix_t **K);
/** Assemble the right-hand side.
 * @param[in] as a set-up assembler @param[out] f ndofs values
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_assembler_assemble_rhs(mfree_assembler_t *as, double *f);

/* ------------------------------------------------------------------------------------ */
/* Semi-discrete particle systems y' = f(t, y)                                            */
/* ------------------------------------------------------------------------------------ */

/**
 * Weakly compressible free-surface flow by Galerkin SPH with MLS shape functions
 * ([CuetoFelgueroso2004]; docs/fluid.md). State y, length (2 dim + 1) n: positions
 * (AoS), velocity parameters (AoS), densities. Particle masses are constant. The
 * functions for fluid systems return MFREE_ERR_UNSUPPORTED on other systems.
 * @param[in]  ctx  context (kept alive)
 * @param[in]  dim  2 or 3 (else MFREE_ERR_ARG)
 * @param[in]  n    number of fluid particles (>= 0)
 * @param[out] sys  the new system
 * @return MFREE_SUCCESS, or a failure named with the parameters
 */
MFREE_API mfree_status_t mfree_system_create_fluid(mfree_context_t *ctx, int32_t dim,
                                                   int32_t n, mfree_system_t **sys);
/** Release a system.
 * @param[in,out] sys  may be NULL or point to NULL; set to NULL
 * @return MFREE_SUCCESS (also for NULL) */
MFREE_API mfree_status_t mfree_system_destroy(mfree_system_t **sys);

/** Fluid properties: Tait equation of state p = kappa ((rho/rho0)^gamma - 1) and
 * viscosity. Defaults: rho0 1000, kappa 1, gamma 7, mu 0.
 * @param[in] sys     a fluid system
 * @param[in] rho0    rest densities (copied)
 * @param[in] stride  stride of rho0 (0: one fluid)
 * @param[in] kappa   Tait stiffness
 * @param[in] gamma   Tait exponent
 * @param[in] mu      dynamic viscosity
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_system_set_fluid(mfree_system_t *sys, const double *rho0,
                                                int64_t stride, double kappa, double gamma,
                                                double mu);
/** Particle masses. Required.
 * @param[in] sys a fluid system @param[in] m masses (copied)
 * @param[in] stride stride of m (0: one value)
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_system_set_masses(mfree_system_t *sys, const double *m,
                                                 int64_t stride);
/** Constant smoothing length of the cubic-spline MLS weights ([CuetoFelgueroso2004]
 * uses 1.5 times the spacing).
 * @param[in] sys a fluid system @param[in] h the smoothing length
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_system_set_smoothing(mfree_system_t *sys, double h);
/** Gravity. Default zero.
 * @param[in] sys a fluid system @param[in] g dim values (copied)
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_system_set_gravity(mfree_system_t *sys, const double *g);
/** Lumped mass of the fluid. Default MFREE_LUMP_GALERKIN.
 * @param[in] sys a fluid system @param[in] lump an mfree_lumping_t (else MFREE_ERR_ARG)
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_system_set_lumping(mfree_system_t *sys, mfree_lumping_t lump);
/**
 * Solid walls as boundary particles exerting the repulsive force of
 * [CuetoFelgueroso2004] eqs 122-124 on approaching fluid particles closer than r0
 * (docs/fluid.md).
 * @param[in] sys       a fluid system
 * @param[in] nwall     number of wall particles
 * @param[in] x         positions, dim per particle (copied)
 * @param[in] normals   unit normals pointing into the fluid, dim per particle (copied)
 * @param[in] r0        reach of the force (the paper: 0.7 h)
 * @param[in] strength  its strength A (the paper: 10)
 * @return MFREE_SUCCESS, or a failure named with the parameters
 */
MFREE_API mfree_status_t mfree_system_set_walls(mfree_system_t *sys, int32_t nwall,
                                                const double *x, const double *normals,
                                                double r0, double strength);
/** A box the particles must stay in; leaving it is MFREE_FAIL_DOMAIN. Default: none.
 * @param[in] sys a fluid system @param[in] lo dim values (copied)
 * @param[in] hi dim values (copied)
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_system_set_box(mfree_system_t *sys, const double *lo,
                                              const double *hi);

/**
 * Shepard fallback: particles whose linear MLS moment matrix has a condition estimate
 * above max_cond use Shepard functions instead (singular sites always do). Default 100
 * (docs/fluid.md says why); INFINITY for singular sites only, 1 for Shepard functions
 * everywhere.
 * @param[in] sys       a fluid system
 * @param[in] max_cond  >= 1 (NaN or below 1: MFREE_ERR_ARG)
 * @return MFREE_SUCCESS, or a failure named with the parameters
 */
MFREE_API mfree_status_t mfree_system_set_shepard_condition(mfree_system_t *sys,
                                                            double max_cond);

/**
 * The fluid's shape functions: the method, order and kernel of an approximant
 * (mfree_approximant_create, _set_order, _set_kernel), built at the particles (and dummy
 * particles) on their neighbours within the kernel's support, with the fallback
 * MFREE_FALLBACK_LOWER_ORDER and the Shepard condition of
 * mfree_system_set_shepard_condition. Default: MFREE_METHOD_MLS, order 1,
 * MFREE_KERNEL_CUBIC_SPLINE ([CuetoFelgueroso2004]).
 * @param[in] sys     a fluid system (else MFREE_ERR_UNSUPPORTED)
 * @param[in] method  an mfree_method_t (else MFREE_ERR_ARG); MFREE_METHOD_MPFEM, which needs a
 *                    mesh: MFREE_ERR_UNSUPPORTED
 * @param[in] order   the order, as mfree_approximant_set_order accepts it for the method
 *                    (else MFREE_ERR_UNSUPPORTED)
 * @param[in] kernel  an mfree_kernel_t (else MFREE_ERR_ARG); one whose derivative the method
 *                    needs and does not have: MFREE_ERR_UNSUPPORTED
 * @param[in] param   the kernel's shape parameter, as mfree_approximant_set_kernel takes it
 *                    (0 for the default)
 * @return MFREE_SUCCESS, or a failure named with the parameters (the previous choice stays)
 */
MFREE_API mfree_status_t mfree_system_set_approximation(mfree_system_t *sys,
                                                        mfree_method_t method, int32_t order,
                                                        mfree_kernel_t kernel, double param);

/**
 * Dummy wall particles ([Adami2012]; not in [CuetoFelgueroso2004]): fixed particles
 * filling the solid past the walls, at least 4h - d deep, with the pressure
 * extrapolated from the fluid; they give fluid nodes near a wall full supports and the
 * wall traction (docs/fluid.md). May be combined with the wall force. On ranks every rank passes the same dummies, all
 * of them (bitwise one rank's); with density diffusion too the ghost layer must reach four support radii (docs/fluid-ranks.md).
 * @param[in] sys      a fluid system
 * @param[in] n        number of dummy particles; 0 removes them (the default)
 * @param[in] x        positions, dim per particle (AoS; copied)
 * @param[in] volumes  volumes V_w > 0 (copied), typically d^dim
 * @param[in] stride   stride of volumes (0: one value)
 * @return MFREE_SUCCESS, or a failure named with the parameters
 */
MFREE_API mfree_status_t mfree_system_set_dummy_particles(mfree_system_t *sys, int32_t n,
                                                          const double *x,
                                                          const double *volumes,
                                                          int64_t stride);
/**
 * Density diffusion (delta-SPH, [MolteniColagrossi2009] with the correction of
 * [Antuono2010]; not in [CuetoFelgueroso2004]): damps the odd-even density modes that
 * nodal integration does not see and leaves linear density fields unchanged
 * (docs/fluid.md). Usual delta: 0.1. Default 0 (off).
 * @param[in] sys    a fluid system
 * @param[in] delta  finite, >= 0
 * @return MFREE_SUCCESS, or a failure named with the parameters
 */
MFREE_API mfree_status_t mfree_system_set_density_diffusion(mfree_system_t *sys,
                                                            double delta);
/**
 * Variationally consistent nodal integration of the momentum equation ([Chen2013],
 * constant correction; not in [CuetoFelgueroso2004]): a uniform pressure then exerts no
 * force on a disordered particle set; linear and angular momentum are no longer
 * conserved to round-off (docs/fluid.md).
 * @param[in] sys  a fluid system
 * @param[in] on   0 (default, the paper's nodal integration) or 1; else MFREE_ERR_ARG
 * @return MFREE_SUCCESS, or a failure named with the parameters
 */
MFREE_API mfree_status_t mfree_system_set_consistent_integration(mfree_system_t *sys,
                                                                 int32_t on);
/**
 * Conservative velocity smoothing (the Randles-Libersky smoothing of [Belytschko1998]
 * Sect. 6.3, as a rate): damps the zero-energy modes of the velocity parameters;
 * conserves linear momentum; acts like an artificial viscosity of order beta c h / 10
 * (docs/fluid.md). Default 0 (off).
 * @param[in] sys   a fluid system
 * @param[in] beta  finite, >= 0
 * @return MFREE_SUCCESS, or a failure named with the parameters
 */
MFREE_API mfree_status_t mfree_system_set_velocity_smoothing(mfree_system_t *sys,
                                                             double beta);
/**
 * The fluid's CFL step with the Galerkin lumped masses (not in [CuetoFelgueroso2004]; a
 * time-step control, the scheme is unchanged): mfree_system_integrate's step becomes
 * cfl h / max_i (c_i + |v_i|) sqrt(M_i / m_i), the square root taken only where a
 * particle's lumped mass m_i (eq 56) is below its particle mass M_i. Next to
 * ill-conditioned linear MLS rows m_i falls to a third of M_i, the local acoustic
 * frequency grows as sqrt(M_i / m_i), and the step of eq 120 crosses the explicit
 * schemes' stability limit (docs/time-integration.md). No effect with
 * MFREE_LUMP_PHYSICAL.
 * @param[in] sys  a fluid system
 * @param[in] on   0 (default: the step of eq 120) or 1; else MFREE_ERR_ARG
 * @return MFREE_SUCCESS, or a failure named with the parameters
 */
MFREE_API mfree_status_t mfree_system_set_lumped_mass_step(mfree_system_t *sys, int32_t on);
/**
 * The fluid's step also bounded by the largest frequency of its linearised acoustic
 * operator (not in [CuetoFelgueroso2004]; a time-step control, the scheme is unchanged):
 * mfree_system_integrate's step is at most 1.5 / omega, where omega^2 is the largest
 * eigenvalue of M_L^-1 B^T M C B (B the rows' gradients that give the divergence of eq 70
 * at each particle, M the particle masses, C = gamma kappa / rho_k as in eq 121, M_L the
 * masses the acceleration divides by), found by a power iteration whose vector is kept
 * from step to step (two iterations a step): three quarters of the explicit schemes'
 * limit omega dt = 2, which the step of eq 120 approaches where ill-conditioned rows at a
 * wall or in a crowded cluster have large gradients or small lumped masses
 * (docs/time-integration.md). The bound applies to a fixed step (cfl <= 0, dt_max) too.
 * Dummy particles are left out of the operator. With mfree_system_set_lumped_mass_step
 * as well, the smaller of the two steps. The iteration's sums over the particles are
 * exact (rounded once), so that on a fluid on ranks (mfree_system_create_fluid_ranks)
 * omega and the steps are bitwise one rank's, whatever the partition: there the vector is
 * exchanged at the ghosts before each product and travels with the particles through
 * ghost rebuilds and mfree_system_move_particles; every rank must set the same (ranks
 * that disagree make mfree_system_integrate return MFREE_ERR_ARG on every rank).
 * @param[in] sys  a fluid system
 * @param[in] on   0 (default: off) or 1; else MFREE_ERR_ARG
 * @return MFREE_SUCCESS, or a failure named with the parameters
 */
MFREE_API mfree_status_t mfree_system_set_acoustic_step(mfree_system_t *sys, int32_t on);

/** Length of the state vector.
 * @param[in] sys the system @param[out] neq the length
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL output */
MFREE_API mfree_status_t mfree_system_get_size(const mfree_system_t *sys, int32_t *neq);
/** Spatial dimension and number of particles of a system, the sizes of get_pressure
 * (n values), get_velocity (dim n) and get_stress (n times 1, 3 or 6 for dim 1, 2, 3);
 * on ranks n is the rank's owned particles.
 * @param[in] sys the system @param[out] dim, n either may be NULL, not both
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for two NULL outputs */
MFREE_API mfree_status_t mfree_system_get_dimension(const mfree_system_t *sys, int32_t *dim,
                                                    int32_t *n);
/** ydot = f(t, y).
 * @param[in] sys the system @param[in] t time @param[in] y state
 * @param[out] ydot its rate (unspecified after a positive status)
 * @return a positive status naming the particle for a non-finite or out-of-range
 *         state; MFREE_ERR_NULL for a NULL y or ydot (neq > 0). On ranks collective: a
 *         NULL array on one rank makes every rank return MFREE_ERR_NULL with that rank's
 *         message ("rank R: y or ydot is NULL"), no output written (docs/mpi.md) */
MFREE_API mfree_status_t mfree_system_rhs(mfree_system_t *sys, double t, const double *y,
                                          double *ydot);
/** Mass matrix of the state: the identity except the velocity block, which holds the
 * lumped or consistent Galerkin mass: M y' = M f(t, y) (fluid and Galerkin elastodynamics
 * on ranks: owned rows, lumped only, MFREE_ERR_UNSUPPORTED for the consistent mass, whose
 * products are mfree_system_apply_mass's).
 * @param[in]     sys         the system
 * @param[in]     y           state
 * @param[in]     consistent  0 lumped, nonzero consistent
 * @param[in,out] M           *M NULL: created (owned by the host); else refilled
 * @return MFREE_SUCCESS, or a failure named with the parameters; MFREE_ERR_NULL for a
 *         NULL M or y (neq > 0). The fluid on ranks: collective, a NULL on one rank is
 *         MFREE_ERR_NULL on every rank ("rank R: ..."), no matrix made or changed */
MFREE_API mfree_status_t mfree_system_assemble_mass(mfree_system_t *sys, const double *y,
                                                    int32_t consistent, mfree_matrix_t **M);
/** S_kj = N_j(x_k) at the state's positions: initial velocity parameters solve
 * S v = v_hat ([CuetoFelgueroso2004] eq 99). Fluid on ranks (collective): the owned
 * particles' rows in the host's order, n_owned x (n_owned + n_ghost), the columns the
 * host's items (owned, then ghosts, named by the global ids given at creation or by the
 * last halo rebuild), each entry bitwise one rank's; S v needs v at the ghosts.
 * @param[in] sys a fluid system @param[in] y state
 * @param[in,out] S *S NULL: created (owned by the host); else refilled
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_system_assemble_interpolation(mfree_system_t *sys,
                                                             const double *y,
                                                             mfree_matrix_t **S);
/** Mv = M(y) v, the mass matrix of mfree_system_assemble_mass applied to v, for
 * matrix-free mass solvers. The mass assembled at y is kept for the next call with the
 * same y (bit for bit), kind and options, so that the products of one solve assemble it
 * once. Fluid on ranks (collective, every rank alike): the rank's rows, bitwise one
 * rank's; the consistent mass, whose rows couple owned particles to ghosts, reads v's
 * velocities at the ghosts through one exchange (docs/fluid-ranks.md). Galerkin
 * elastodynamics on ranks (collective): the lumped mass locally, the consistent mass of
 * `density` on the stiffness's points (built at the first product) with v's velocities
 * exchanged at the ghosts, bitwise the one-process system's with an MFREE_FORM_MASS
 * assembler on the same points (docs/mpi.md).
 * @param[in]  sys         the system
 * @param[in]  y           state (neq values)
 * @param[in]  consistent  0 lumped, nonzero consistent
 * @param[in]  v           neq values
 * @param[out] Mv          neq values (unspecified after a failure)
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL array (on ranks: on every rank when
 *         one rank passes one); a positive status naming the particle for a non-finite
 *         or out-of-range state */
MFREE_API mfree_status_t mfree_system_apply_mass(mfree_system_t *sys, const double *y,
                                                 int32_t consistent, const double *v,
                                                 double *Mv);
/** Pressure at the particles from the state's densities.
 * @param[in] sys a fluid system @param[in] y state @param[out] p n values (on ranks: n_owned)
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL output */
MFREE_API mfree_status_t mfree_system_get_pressure(const mfree_system_t *sys,
                                                   const double *y, double *p);
/** Interpolated velocities v_hat(x_k) (on ranks: of the owned particles; collective).
 * @param[in] sys a fluid system @param[in] y state
 * @param[out] vhat dim values per particle (AoS)
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL y or vhat (on ranks: on every rank,
 *         with the rank's message "rank R: y or vhat is NULL") */
MFREE_API mfree_status_t mfree_system_get_velocity(mfree_system_t *sys, const double *y,
                                                   double *vhat);

/**
 * Force the walls exert on the fluid at state y (the force on the walls is its opposite).
 * total: the fluid's net force sum_i m_i a_i less its weight (m_i the masses the
 * accelerations use: the lumped masses, or the particle masses with physical lumping;
 * internal forces cancel), i.e. the wall particles' force ([CuetoFelgueroso2004] eqs
 * 122-124) and, with dummy particles, their traction and no-slip smoothing; with
 * consistent integration it includes that integration's momentum error. A leap-frog step
 * of length dt from y changes sum_i m_i v_i by dt (M g + total). per_wall: each wall
 * particle's share of the eqs 122-124 force, in the order of mfree_system_set_walls (its
 * sum is total with neither dummy particles nor consistent integration; ranks: see create_fluid_ranks).
 * @param[in]  sys       a fluid system
 * @param[in]  y         state
 * @param[out] total     dim values, or NULL
 * @param[in]  nwall     number of wall particles per_wall holds: the system's wall count
 *                       (else MFREE_ERR_ARG; ignored when per_wall is NULL)
 * @param[out] per_wall  dim values per wall particle (AoS), or NULL (not both NULL)
 * @return MFREE_SUCCESS, or a failure named with the parameters; a positive status
 *         naming the particle for a non-finite or out-of-range state. On ranks every
 *         failure, a NULL y or both outputs NULL on one rank too, is every rank's
 */
MFREE_API mfree_status_t mfree_system_get_wall_force(mfree_system_t *sys, const double *y,
                                                     double *total, int32_t nwall,
                                                     double *per_wall);

/**
 * Integrate y from *t to t_end with a native scheme and the CFL step
 * dt = cfl h / max_i (c_i + |v_i|) ([CuetoFelgueroso2004] eqs 120-121) capped by dt_max
 * (docs/time-integration.md). A non-finite state, a particle outside the box or a step
 * that no longer advances t stops the run; y and *t then hold the last good state and
 * the message names the step and particle.
 * @param[in]     sys       the system
 * @param[in]     scheme    an mfree_integrator_t
 * @param[in,out] y         state, updated in place
 * @param[in,out] t         time
 * @param[in]     t_end     end time
 * @param[in]     cfl       CFL number; <= 0: the step is dt_max, and a step above the
 *                          CFL limit is MFREE_FAIL_CFL before anything changes
 * @param[in]     dt_max    largest step (0: no cap)
 * @param[in]     progress  called after every step, or NULL
 * @param[in]     user      passed to progress
 * @param[out]    nsteps    steps taken, or NULL
 * @return MFREE_FAIL_NONFINITE, MFREE_FAIL_DOMAIN or MFREE_FAIL_CFL as above;
 *         MFREE_ERR_NULL for a NULL t or y (neq > 0). On ranks collective: a NULL on
 *         one rank makes every rank return MFREE_ERR_NULL ("rank R: y or t is NULL")
 *         before any step, y and t unchanged
 */
MFREE_API mfree_status_t mfree_system_integrate(mfree_system_t *sys,
                                                mfree_integrator_t scheme, double *y,
                                                double *t, double t_end, double cfl,
                                                double dt_max, mfree_progress_fn progress,
                                                void *user, int64_t *nsteps);

/* ---- Open boundaries of the fluid: inflow gates and outflow planes ----
 * A fluid created with n particles can keep some of them dormant: a pool that inflow
 * gates draw from and outflow planes return to, so that the state keeps its length
 * (2 dim + 1) n (docs/fluid.md, "Inflow and outflow"). Dormant particles keep their entries
 * in y, get zero rates and take no part in the nodes, the checks or the step. The native
 * integrator updates the boundaries between steps; a host integrating with SUNDIALS calls
 * mfree_system_update_open_boundaries between its windows. On ranks
 * (mfree_system_create_fluid_ranks, docs/fluid-ranks.md) the capacity is every rank's
 * particles, global ids 0 .. N - 1, particle i of the one-process fluid being global id i:
 * every rank sets the same active count, gates and planes (the update and the integration
 * agree on them: else MFREE_ERR_ARG), the update is collective, injected particles take
 * the lowest dormant ids as in one process and belong to the rank that owns the id, a halo
 * rebuild callback is required (MFREE_ERR_STATE), and the states, the right-hand side, the
 * integration and the outputs are bitwise the one-process fluid's (the walls' total force
 * to rounding). */

/** States of a fluid's particles (mfree_system_get_active). */
typedef enum {
  MFREE_PARTICLE_DORMANT = 0, /**< in the pool: no part in the flow, zero rates */
  MFREE_PARTICLE_FLUID = 1,   /**< an active fluid particle */
  MFREE_PARTICLE_INFLOW = 2   /**< in a gate's buffer: active, its motion imposed */
} mfree_particle_state_t;

/**
 * Make particles 0 .. nactive - 1 the fluid and the others dormant (default: all active).
 * Only before the boundaries' first update (an integration or
 * mfree_system_update_open_boundaries); else MFREE_ERR_STATE.
 * @param[in] sys      a fluid system
 * @param[in] nactive  0 <= nactive <= n (else MFREE_ERR_ARG; on ranks n is every rank's
 *                     particles, checked at the first update)
 * @return MFREE_SUCCESS, or a failure named with the parameters
 */
MFREE_API mfree_status_t mfree_system_set_active(mfree_system_t *sys, int32_t nactive);
/**
 * Set inflow gate number gate: a segment (2D: origin + s e1) or parallelogram (3D: origin
 * + s e1 + u e2), s, u in [0, 1], through which fluid of the given density enters along
 * the unit normal at the given speed. The gate carries a lattice of round(|e_k| / spacing)
 * points per edge (at least one); behind it a buffer of rows at the spacing, as deep as
 * the support radius, moves at the imposed velocity with imposed density. When the front
 * row reaches the gate it joins the fluid and a row of dormant particles (the lowest
 * indices first) is activated at the back, so the mass entering by time t is rho U A
 * (t - t0) to half a row, t0 being the gate's first update. Injected particles take the
 * density as rest density and the mass rho spacing A / (points on the gate).
 * @param[in] sys      a fluid system
 * @param[in] gate     0 .. the number of gates (that number adds one; else MFREE_ERR_ARG);
 *                     a gate that has started injecting cannot be replaced (MFREE_ERR_STATE)
 * @param[in] origin   dim values (copied)
 * @param[in] edges    e1 (2D) or e1, e2 (3D), dim values each (copied); each at least
 *                     spacing / 2 long and orthogonal to the normal, in 3D not parallel
 *                     (else MFREE_ERR_ARG)
 * @param[in] normal   unit normal pointing into the fluid domain, dim values (copied)
 * @param[in] speed    U > 0
 * @param[in] density  rho > 0
 * @param[in] spacing  particle spacing d > 0 along the normal and, rounded to fit, along
 *                     the edges
 * @return MFREE_SUCCESS; MFREE_ERR_NULL; MFREE_ERR_INPUT for non-finite coordinates;
 *         MFREE_ERR_ARG for bad values or geometry
 */
MFREE_API mfree_status_t mfree_system_set_inflow(mfree_system_t *sys, int32_t gate,
                                                 const double *origin, const double *edges,
                                                 const double *normal, double speed,
                                                 double density, double spacing);
/**
 * Set outflow plane number k: an active fluid particle x with (x - point).normal > 0 is
 * returned to the dormant pool at the next update (between steps of the native
 * integrator). Keep the box, if any, a few spacings beyond the plane.
 * @param[in] sys     a fluid system
 * @param[in] k       0 .. the number of outflow planes (that number adds one; else
 *                    MFREE_ERR_ARG)
 * @param[in] point   a point of the plane, dim values (copied)
 * @param[in] normal  unit normal pointing out of the fluid domain, dim values (copied)
 * @return MFREE_SUCCESS; MFREE_ERR_NULL; MFREE_ERR_INPUT; MFREE_ERR_ARG
 */
MFREE_API mfree_status_t mfree_system_set_outflow(mfree_system_t *sys, int32_t k,
                                                  const double *point, const double *normal);
/**
 * Update the open boundaries at time t: particles past an outflow plane become dormant,
 * gate rows that reached their gate join the fluid, new buffer rows are activated and
 * every buffer particle is put at its imposed position, velocity and density in y.
 * mfree_system_integrate does this itself; a host integrating otherwise calls it once
 * before integrating and between windows (a window longer than spacing / (2 speed) lets
 * rows join late, their mass counted all the same), and restarts its integrator there.
 * @param[in]     sys  a fluid system
 * On ranks collective: every rank returns the same status.
 * @param[in]     t    time (finite, else MFREE_ERR_ARG)
 * @param[in,out] y    state of length (2 dim + 1) n (on ranks the owned particles')
 * @return MFREE_SUCCESS; MFREE_FAIL_CAPACITY when the dormant pool cannot supply a row
 *         (nothing changed; the message names the gate and the counts); MFREE_ERR_STATE
 *         when the masses or the smoothing length are not set
 */
MFREE_API mfree_status_t mfree_system_update_open_boundaries(mfree_system_t *sys, double t,
                                                             double *y);
/**
 * Number of active particles and, optionally, every particle's mfree_particle_state_t.
 * @param[in]  sys      a fluid system
 * @param[out] nactive  active particles (fluid and buffer)
 * @param[in]  n        values state holds: the system's particle count (on ranks the
 *                      owned count; else MFREE_ERR_ARG; ignored when state is NULL)
 * @param[out] state    n values, or NULL
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL nactive
 */
MFREE_API mfree_status_t mfree_system_get_active(const mfree_system_t *sys, int32_t *nactive,
                                                 int32_t n, int32_t *state);
/**
 * Particles gate has released into the fluid and their total mass.
 * @param[in]  sys    a fluid system
 * @param[in]  gate   a set gate (else MFREE_ERR_ARG)
 * @param[out] count  particles, or NULL
 * @param[out] mass   their mass, or NULL
 * @return MFREE_SUCCESS, or a failure named with the parameters
 */
MFREE_API mfree_status_t mfree_system_get_inflow(const mfree_system_t *sys, int32_t gate,
                                                 int64_t *count, double *mass);
/**
 * Particles outflow plane k has returned to the pool and their total mass.
 * @param[in]  sys    a fluid system
 * @param[in]  k      a set outflow plane (else MFREE_ERR_ARG)
 * @param[out] count  particles, or NULL
 * @param[out] mass   their mass, or NULL
 * @return MFREE_SUCCESS, or a failure named with the parameters
 */
MFREE_API mfree_status_t mfree_system_get_outflow(const mfree_system_t *sys, int32_t k,
                                                  int64_t *count, double *mass);

/**
 * Linear elastodynamics by strong-form collocation ([ZhangBatra2009] Sect. 6.4):
 * rho u'' = Navier(u) + b at the interior particles of a set-up collocation assembler,
 * its boundary rows kept as constraints scaled by the load history g(t)
 * (docs/time-integration.md). State y: displacements then velocities. Integrate with
 * MFREE_INTEGRATOR_LEAPFROG.
 * @param[in]  ctx      context (kept alive)
 * @param[in]  as       a set-up assembler of a collocation form (kept alive)
 * @param[in]  density  rho > 0
 * @param[out] sys      the new system
 * @return MFREE_SUCCESS, or a failure named with the parameters
 */
MFREE_API mfree_status_t mfree_system_create_elastodynamic(mfree_context_t *ctx,
                                                           mfree_assembler_t *as,
                                                           double density,
                                                           mfree_system_t **sys);
/**
 * Linear elastodynamics by Galerkin with any approximant: M u'' = g(t) f - K u with K
 * and f from a set-up stiffness assembler and M from a set-up mass assembler on the same
 * particles (docs/time-integration.md). State y: displacements then velocities.
 * Integrate with MFREE_INTEGRATOR_LEAPFROG; the step limit is 2 / omega_max of M^-1 K.
 * @param[in]  ctx        context (kept alive)
 * @param[in]  stiffness  a Galerkin assembler (Laplace or elasticity; kept alive)
 * @param[in]  mass       an MFREE_FORM_MASS or MFREE_FORM_MASS_LUMPED assembler (kept
 *                        alive)
 * @param[out] sys        the new system
 * @return MFREE_ERR_UNSUPPORTED for Lagrange multipliers
 */
MFREE_API mfree_status_t mfree_system_create_elastodynamic_galerkin(mfree_context_t *ctx,
                                                                    mfree_assembler_t *stiffness,
                                                                    mfree_assembler_t *mass,
                                                                    mfree_system_t **sys);
/** Load history g(t) of an elastodynamic system (default 1).
 * @param[in] sys an elastodynamic system (else MFREE_ERR_UNSUPPORTED)
 * @param[in] g the history, or NULL for 1
 * @param[in] user passed to g; kept
 * @return MFREE_SUCCESS, or a failure named with the parameters */
MFREE_API mfree_status_t mfree_system_set_load_history(mfree_system_t *sys,
                                                       mfree_history_fn g, void *user);
/** Stress at the particles (1D: sigma = E u'; 2D: xx, yy, xy), boundary constraints
 * applied at time t.
 * @param[in] sys a collocation elastodynamic system (Galerkin: MFREE_ERR_UNSUPPORTED)
 * @param[in] t time @param[in] y state @param[out] sigma stresses
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL y or sigma (on ranks, where the
 *         call is collective: on every rank, with the rank's message "rank R: ...") */
MFREE_API mfree_status_t mfree_system_get_stress(mfree_system_t *sys, double t,
                                                 const double *y, double *sigma);

/**
 * Forward halo exchange for a system on ranks (mfree_system_create_elastodynamic_ranks):
 * the owners' values of a per-particle field written into this rank's ghost items.
 * Collective over the system's ranks; the core never calls MPI, the host (or
 * libmfree_mpi's mfree_halo_exchange_callback) does.
 * @param[in]     user   the pointer given at the system's creation
 * @param[in]     ncomp  components per particle (>= 1), the same on every rank
 * @param[in,out] field  AoS items of ld doubles, the particle set's order (owned, then
 *                       ghosts): owned items read, components [0, ncomp) of ghosts written
 * @param[in]     ld     leading dimension (>= ncomp)
 * @return MFREE_SUCCESS, or a failure status that every rank returns alike
 */
typedef mfree_status_t (*mfree_exchange_fn)(void *user, int32_t ncomp, double *field,
                                            int64_t ld);
/**
 * All-gather for a system on ranks: every rank's n doubles concatenated in rank order.
 * Collective. The values travel as bits (integers are packed into doubles by memcpy).
 * @param[in]  user   the pointer given at the system's creation
 * @param[in]  in     this rank's n values (may be NULL when n is 0)
 * @param[in]  n      this rank's count (>= 0; may differ between ranks)
 * @param[out] out    cap doubles; written only when cap >= *total on every rank
 * @param[in]  cap    capacity of out (0: ask for the total only)
 * @param[out] total  the sum of the ranks' n
 * @return MFREE_SUCCESS, or a failure status that every rank returns alike
 */
typedef mfree_status_t (*mfree_allgather_fn)(void *user, const double *in, int64_t n,
                                             double *out, int64_t cap, int64_t *total);

/**
 * Linear elastodynamics, as mfree_system_create_elastodynamic (or _galerkin, below), on
 * one rank of several: the assembler is set up over this rank's owned particles plus
 * ghosts (a particle set with mfree_particles_set_num_ghost and global ids, ghosts at
 * least one support deep), and the state y of this rank holds its owned particles only
 * (displacements of the owned particles, then their velocities: neq = 2 ncomp n_owned).
 * Every right-hand side, native step and stress evaluation is collective: it exchanges
 * the ghosts' displacements through exchange, and gathers the boundary rows' data through
 * allgather (the boundary unknowns are solved in global-id order on every rank, so that
 * the owned particles' results are bitwise those of one rank, whatever the partition).
 * A failure on one rank (a non-finite state: MFREE_FAIL_NONFINITE; a NULL array or
 * output passed to a collective call: MFREE_ERR_NULL, the rank still taking part) is
 * returned by every rank with that rank's message ("rank R: ..."). Creation is collective too: a NULL
 * assembler or a bad density on one rank, or ranks that disagree on the density, the
 * form or its coefficients, make every rank fail alike (MFREE_ERR_NULL, MFREE_ERR_ARG).
 * A Galerkin stiffness assembler (Laplace or elasticity form, as for
 * mfree_system_create_elastodynamic_galerkin) gives Galerkin elastodynamics with the
 * lumped mass of density rho on the stiffness's quadrature points (MFREE_FORM_MASS_LUMPED:
 * bitwise the one-process system with such a mass assembler); its ghosts must reach two
 * support radii, and its quadrature points (mfree_assembler_set_quadrature_points) and
 * boundary points are those within one support radius of the owned particles, in the same
 * global order on every rank (docs/mpi.md). MFREE_ERR_UNSUPPORTED on ranks: nodal
 * quadrature, an FE layer, consistent integration, Lagrange multipliers. The right-hand
 * side divides by the lumped mass (a consistent mass's inverse would couple every unknown
 * at each evaluation); the consistent mass is applied by mfree_system_apply_mass (for
 * ARKStep's mass form with a Krylov mass solver), not handed out as a matrix.
 * libmfree_mpi's mfree_halo_create_elastodynamic supplies the callbacks from a halo plan.
 * @param[in]  ctx        context (kept alive); NULL: MFREE_ERR_NULL on this rank alone
 * @param[in]  as         a set-up collocation or Galerkin stiffness assembler over owned
 *                        particles and ghosts (kept alive), or NULL (every rank then fails)
 * @param[in]  density    rho > 0, the same on every rank
 * @param[in]  exchange   the forward halo exchange (NULL: MFREE_ERR_NULL, local)
 * @param[in]  allgather  the all-gather (NULL: MFREE_ERR_NULL, local)
 * @param[in]  user       passed to both callbacks; kept
 * @param[out] sys        the new system (NULL: the rank takes part, every rank fails
 *                        with MFREE_ERR_NULL)
 * @return MFREE_SUCCESS, or a failure named with the parameters, alike on every rank
 */
MFREE_API mfree_status_t mfree_system_create_elastodynamic_ranks(
    mfree_context_t *ctx, mfree_assembler_t *as, double density, mfree_exchange_fn exchange,
    mfree_allgather_fn allgather, void *user, mfree_system_t **sys);

/**
 * The Galerkin SPH fluid (mfree_system_create_fluid, [CuetoFelgueroso2004]) on one rank
 * of several: the system's particles are this rank's n_owned owned particles and n_ghost
 * ghosts, in the host's order (owned first), with their global ids; the ghosts must
 * hold every particle within width of an owned particle, and width must reach two
 * support radii (2 R h: an owned particle's terms come from the rows of its neighbours,
 * which need their own neighbours; four, 4 R h, with dummy particles and density diffusion together: docs/fluid-ranks.md).
 * The per-particle setters (mfree_system_set_fluid, mfree_system_set_masses) take the n_owned + n_ghost items in the host's order; the
 * state y of this rank holds its owned particles only (positions, velocities, densities
 * of the owned items: neq = (2 dim + 1) n_owned). Every right-hand side and native step
 * is collective: it exchanges the ghosts' states through exchange and agrees on the
 * status and the step limit through allgather. The rows, their sums and the assembly of
 * the forces run in global-id order, so that every owned particle's position, velocity
 * and density are bitwise those of the same system on one rank, whatever the partition
 * (the one-process mfree_system_create_fluid sums the forces in another order).
 * The halo is checked at every evaluation against the owned particles' displacements
 * since the first (or the last rebuild): when the layer may miss a particle, the ghosts
 * are rebuilt through the host's rebuild callback (mfree_system_set_halo_rebuild) or,
 * without one, every rank returns MFREE_ERR_HALO (rebuild the halo and the system).
 * Particles move between ranks with mfree_system_move_particles. A failure on one rank (a non-finite
 * state: MFREE_FAIL_NONFINITE; a NULL array or output passed to a collective call:
 * MFREE_ERR_NULL, the rank still taking part) is returned by every rank with that rank's
 * message ("rank R: ..."). Both native integrators; dummy particles (the same on every rank), density diffusion, velocity smoothing,
 * consistent integration, the lumped-mass step and the acoustic step as on one process; no open
 * boundaries (MFREE_ERR_UNSUPPORTED at their setters). Outputs: the owned
 * particles' (docs/fluid-ranks.md); the consistent mass as products (mfree_system_apply_mass). Creation is collective: bad input on one rank, or ranks that
 * disagree on dim or width, make every rank fail alike.
 * libmfree_mpi's mfree_halo_create_fluid supplies the callbacks from a halo plan.
 * @param[in]  ctx         context (kept alive); NULL: MFREE_ERR_NULL on this rank alone
 * @param[in]  dim         2 or 3, the same on every rank
 * @param[in]  n_owned     owned particles on this rank (>= 0)
 * @param[in]  n_ghost     ghosts on this rank (>= 0)
 * @param[in]  global_ids  n_owned + n_ghost distinct ids >= 0, owned first (copied)
 * @param[in]  width       depth of the ghost layer (> 0, the same on every rank)
 * @param[in]  exchange    the forward halo exchange (NULL: MFREE_ERR_NULL, local)
 * @param[in]  allgather   the all-gather (NULL: MFREE_ERR_NULL, local)
 * @param[in]  user        passed to both callbacks; kept
 * @param[out] sys         the new system (NULL: the rank takes part, every rank fails
 *                         with MFREE_ERR_NULL)
 * @return MFREE_SUCCESS, or a failure named with the parameters, alike on every rank
 */
MFREE_API mfree_status_t mfree_system_create_fluid_ranks(
    mfree_context_t *ctx, int32_t dim, int32_t n_owned, int32_t n_ghost,
    const int64_t *global_ids, double width, mfree_exchange_fn exchange,
    mfree_allgather_fn allgather, void *user, mfree_system_t **sys);

/**
 * Ghost-layer rebuild for the fluid on ranks (mfree_system_set_halo_rebuild): set the
 * host's halo up again around this rank's owned particles at their current positions, so
 * that the ghosts hold every particle within width of them, and give the new ghosts'
 * global ids. Collective over the system's ranks (every rank calls it at the same
 * point); afterwards the system's exchange callback serves the new ghosts. libmfree_mpi's
 * mfree_halo_rebuild_callback does this for a halo plan.
 * @param[in]  user        the pointer given at the system's creation
 * @param[in]  n_owned     owned particles on this rank (>= 0)
 * @param[in]  x           their positions, AoS, particle i's at x[i*ld, i*ld + dim)
 * @param[in]  ld          leading dimension (the dimension)
 * @param[in]  global_ids  their n_owned global ids, in the order the host's halo must list
 *                         its owned items
 * @param[in]  width       the depth of the layer (the system's width)
 * @param[out] n_ghost     the new ghosts' count
 * @param[out] all_ids     n_owned + n_ghost global ids (the owned ones first, as given,
 *                         then the ghosts in the order of the host's exchange), borrowed:
 *                         read before the host's next callback returns
 * @return MFREE_SUCCESS, or a failure status that every rank returns alike
 */
typedef mfree_status_t (*mfree_halo_rebuild_fn)(void *user, int32_t n_owned, const double *x,
                                                int64_t ld, const int64_t *global_ids,
                                                double width, int32_t *n_ghost,
                                                const int64_t **all_ids);

/**
 * Let a fluid on ranks (mfree_system_create_fluid_ranks) rebuild its ghosts as particles
 * move: when a right-hand side or a native step finds the ghost layer no longer deep
 * enough (see mfree_system_create_fluid_ranks), every rank calls rebuild (with the
 * system's user pointer) around its owned particles' current positions, re-seats the
 * system on the new ghosts (their rest densities and masses by one exchange) and
 * evaluates again, so that the run goes on with the results it would have had on one
 * rank, bitwise. Without a rebuild callback (the default, or rebuild = NULL) such an
 * evaluation returns MFREE_ERR_HALO. Not collective, but every rank sets the same.
 * libmfree_mpi's mfree_halo_create_fluid sets its own. A rebuild that fails (a failing
 * callback, ids that change an owned item, repeat or are negative) is returned by every
 * rank, and the system then returns MFREE_ERR_STATE from every evaluation (its ghosts
 * no longer match the host's halo: create it again).
 * @param[in] sys      a fluid on ranks
 * @param[in] rebuild  the host's rebuild, or NULL (none)
 * @return MFREE_SUCCESS; MFREE_ERR_NULL for a NULL system; MFREE_ERR_UNSUPPORTED if sys is not a
 *         fluid on ranks
 */
MFREE_API mfree_status_t mfree_system_set_halo_rebuild(mfree_system_t *sys,
                                                       mfree_halo_rebuild_fn rebuild);

/**
 * Particle move for mfree_system_move_particles: send this rank's owned records to their
 * new owners and receive the records of the n_new particles this rank owns afterwards.
 * Collective. A record is nrec doubles whose bytes must arrive unchanged: the position
 * (dim values) first, then data of the system's own (state, rest density, mass, global
 * id as bits).
 * @param[in]     user     the move_user pointer of mfree_system_move_particles
 * @param[in]     nrec     doubles per record
 * @param[in]     n_owned  records given (this rank's owned particles)
 * @param[in,out] records  max(n_owned, n_new) records: n_owned in, n_new out (any order)
 * @param[in]     n_new    records this rank receives and keeps
 * @return MFREE_SUCCESS, or a failure status that every rank returns alike (nothing moved)
 */
typedef mfree_status_t (*mfree_particles_move_fn)(void *user, int32_t nrec, int32_t n_owned,
                                                  double *records, int32_t n_new);

/**
 * Move a fluid on ranks' owned particles to other ranks: the particles' records (the
 * state from y, rest density, mass, global id) go through the host's move, the system's
 * rebuild callback (mfree_system_set_halo_rebuild, required) sets the halo up around the
 * n_new particles that arrived, and the system is re-seated on them, every option kept.
 * y then holds the new owned particles' state in the order of the records move left
 * (neq = (2 dim + 1) n_new; mfree_system_get_size): a host integrating with its own
 * vectors re-creates them with the new length (SUNDIALS: a new vector and ARKODE's
 * ReInit). Collective; the checks come first and are agreed (nothing moved when one rank
 * fails them). libmfree_mpi's mfree_halo_migrate_fluid calls it with Zoltan's partition.
 * @param[in]     sys        a fluid on ranks with a rebuild callback
 * @param[in]     n_new      the particles this rank owns after the move (>= 0)
 * @param[in]     move       the host's move (NULL: MFREE_ERR_NULL on every rank)
 * @param[in]     move_user  passed to move
 * @param[in,out] y          this rank's state ((2 dim + 1) n_owned doubles) in, the new
 *                           one out
 * @param[in]     capacity   doubles y holds (>= (2 dim + 1) n_new and >= the current neq)
 * @return MFREE_SUCCESS; on every rank alike: MFREE_ERR_ARG (n_new < 0, a capacity below
 *         the new or the current state), MFREE_ERR_NULL, MFREE_ERR_STATE (no rebuild callback, masses not
 *         set, a system whose rebuild failed), the move's or the rebuild's failure (a failed
 *         move leaves the system and y as they were; a failed rebuild, the system unusable);
 *         MFREE_ERR_NULL (local) for a NULL system, MFREE_ERR_UNSUPPORTED (local) if it is not a
 *         fluid on ranks
 */
MFREE_API mfree_status_t mfree_system_move_particles(mfree_system_t *sys, int32_t n_new,
                                                     mfree_particles_move_fn move, void *move_user,
                                                     double *y, int64_t capacity);

/**
 * Make a fault found on this rank before a collective call the outcome of that call, for
 * hosts and bindings that check what the C API cannot see (the Fortran module: an output
 * array too short; libmfree_sundials: an N_Vector of another length), so that the rank
 * still takes part instead of returning while the others wait. The next call on sys of
 * those that are collective on ranks (mfree_system_rhs, _integrate, _assemble_mass,
 * _assemble_interpolation, _apply_mass, _get_velocity, _get_wall_force, _get_stress,
 * _move_particles, _update_open_boundaries) takes the fault: on this rank it reads and writes none of its arrays
 * (they may be NULL, or any size); on ranks it takes part in the call's first agreement,
 * and every rank returns status with this rank's message ("rank R: <message>"), nothing
 * changed, as for a NULL argument; in one process, or where the call is local on ranks
 * (an elastodynamic system's mass), it returns status and message on this rank at once.
 * The fault is reported once: the call after it runs as usual. Other calls leave it
 * pending; a second call of this function replaces it. Not collective.
 * @param[in] sys      the system
 * @param[in] status   the fault: a negative mfree_status_t; MFREE_SUCCESS clears a fault
 *                     not yet taken (else MFREE_ERR_ARG)
 * @param[in] message  why (copied), as "<reason>" or "mfree_<fn>: <reason>" (the leading
 *                     "mfree_<fn>: " dropped: the collective call names itself); NULL:
 *                     the status's mfree_status_string
 * @return MFREE_SUCCESS; MFREE_ERR_NULL (without a message) for a NULL system;
 *         MFREE_ERR_ARG for a status that is neither negative nor MFREE_SUCCESS, or unknown
 */
MFREE_API mfree_status_t mfree_system_set_pending_error(mfree_system_t *sys, mfree_status_t status,
                                                        const char *message);

#ifdef __cplusplus
}
#endif

#endif /* MFREE_H */
