!> module mfree: Fortran 2008 bindings of the mfree C ABI (include/mfree.h).
!>
!> Two layers, both public:
!>  - raw interfaces named after the C function with the suffix _c, one per public C
!>    function, bound with bind(C, name=...) to the C name and declared with the exact
!>    C types (int32_t -> integer(c_int32_t), int64_t -> integer(c_int64_t),
!>    double -> real(c_double), enumerations -> integer(c_int), handles ->
!>    type(c_ptr), function pointers -> type(c_funptr); pointers that may be NULL are
!>    type(c_ptr), value);
!>  - typed wrappers named exactly like the C functions, taking the handle types
!>    type(mfree_context), type(mfree_particles), ... so that the compiler rejects a
!>    particle set passed where an approximant is expected, optional arguments where C
!>    accepts NULL, and Fortran strings where C takes or returns char *.
!> Every function returns the C status as integer(c_int) (MFREE_SUCCESS = 0).
!>
!> Borrowed arrays (MFREE_BORROW): mfree keeps the address of the host's array and
!> re-reads it at every setup / update / apply. Give such arrays the TARGET attribute
!> (or POINTER), pass whole contiguous arrays (never an array section, an expression or
!> a constant, which would pass the address of a temporary), and keep them alive until
!> the object is destroyed or the array is replaced. Fortran x(3,n) is
!> MFREE_LAYOUT_AOS with ld = 3 (also for dim = 2: the third row is skipped), x(n,3) is
!> MFREE_LAYOUT_SOA with ld = n.
!>
!> Indices: mfree_particles_set_neighbors takes 1-based lists with index_base = 1.
!> Everything mfree returns (neighbour lists, CSR tables, matrix views) and the particle
!> indices mfree_assembler_add_dirichlet_nodes / add_traction_nodes / set_fe_layer take
!> are 0-based, as in C.
module mfree
  use, intrinsic :: iso_c_binding, only: c_int, c_int32_t, c_int64_t, c_double, c_char, &
    c_ptr, c_funptr, c_null_ptr, c_null_funptr, c_null_char, c_size_t, c_loc, c_funloc, &
    c_f_pointer, c_associated
  implicit none
  private

  ! ---- version of the headers this module was built from (CMake project version) ----
  include 'mfree_version.inc'

  ! ---- status codes (mfree_status_t); values frozen --------------------------------
  integer(c_int), parameter, public :: MFREE_SUCCESS = 0
  integer(c_int), parameter, public :: MFREE_ERR_NULL = -1
  integer(c_int), parameter, public :: MFREE_ERR_ARG = -2
  integer(c_int), parameter, public :: MFREE_ERR_STATE = -3
  integer(c_int), parameter, public :: MFREE_ERR_ALLOC = -4
  integer(c_int), parameter, public :: MFREE_ERR_MISMATCH = -5
  integer(c_int), parameter, public :: MFREE_ERR_UNSUPPORTED = -6
  integer(c_int), parameter, public :: MFREE_ERR_INPUT = -7
  integer(c_int), parameter, public :: MFREE_ERR_HALO = -8
  integer(c_int), parameter, public :: MFREE_ERR_INTERNAL = -99
  integer(c_int), parameter, public :: MFREE_FAIL_NONFINITE = 1
  integer(c_int), parameter, public :: MFREE_FAIL_INVALID_DATA = 2
  integer(c_int), parameter, public :: MFREE_FAIL_SINGULAR = 3
  integer(c_int), parameter, public :: MFREE_FAIL_NEIGHBORS = 4
  integer(c_int), parameter, public :: MFREE_FAIL_DOMAIN = 5
  integer(c_int), parameter, public :: MFREE_FAIL_CFL = 6
  integer(c_int), parameter, public :: MFREE_FAIL_SUPPORT = 7
  integer(c_int), parameter, public :: MFREE_FAIL_CAPACITY = 8

  ! ---- mfree_mem_t ---------------------------------------------------------------
  integer(c_int), parameter, public :: MFREE_COPY = 1
  integer(c_int), parameter, public :: MFREE_BORROW = 2

  ! ---- mfree_layout_t ------------------------------------------------------------
  integer(c_int), parameter, public :: MFREE_LAYOUT_AOS = 1
  integer(c_int), parameter, public :: MFREE_LAYOUT_SOA = 2

  ! ---- mfree_search_t ------------------------------------------------------------
  integer(c_int), parameter, public :: MFREE_SEARCH_GATHER = 1
  integer(c_int), parameter, public :: MFREE_SEARCH_SYMMETRIC_MAX = 2
  integer(c_int), parameter, public :: MFREE_SEARCH_SYMMETRIC_MEAN = 3

  ! ---- mfree_kernel_t ------------------------------------------------------------
  integer(c_int), parameter, public :: MFREE_KERNEL_CUBIC_SPLINE = 1
  integer(c_int), parameter, public :: MFREE_KERNEL_QUARTIC = 2
  integer(c_int), parameter, public :: MFREE_KERNEL_QUINTIC_SPLINE = 3
  integer(c_int), parameter, public :: MFREE_KERNEL_GAUSSIAN = 4
  integer(c_int), parameter, public :: MFREE_KERNEL_SUPER_GAUSS = 5
  integer(c_int), parameter, public :: MFREE_KERNEL_REVISED_GAUSS = 6
  integer(c_int), parameter, public :: MFREE_KERNEL_REVISED_SUPER_GAUSS = 7
  integer(c_int), parameter, public :: MFREE_KERNEL_WENDLAND_C2 = 8
  integer(c_int), parameter, public :: MFREE_KERNEL_WENDLAND_C4 = 9
  integer(c_int), parameter, public :: MFREE_KERNEL_LINEAR = 10
  integer(c_int), parameter, public :: MFREE_KERNEL_QUADRATIC = 11
  integer(c_int), parameter, public :: MFREE_KERNEL_QUARTIC_SPLINE = 12
  integer(c_int), parameter, public :: MFREE_KERNEL_COSINE = 13
  integer(c_int), parameter, public :: MFREE_KERNEL_COSINE_SQUARED = 14
  integer(c_int), parameter, public :: MFREE_KERNEL_HAAR = 15

  ! ---- mfree_method_t ------------------------------------------------------------
  integer(c_int), parameter, public :: MFREE_METHOD_SPH = 1
  integer(c_int), parameter, public :: MFREE_METHOD_SPH_SYMMETRIC = 2
  integer(c_int), parameter, public :: MFREE_METHOD_SHEPARD = 3
  integer(c_int), parameter, public :: MFREE_METHOD_MLS = 4
  integer(c_int), parameter, public :: MFREE_METHOD_RKPM = 5
  integer(c_int), parameter, public :: MFREE_METHOD_JOHNSON_BEISSEL = 6
  integer(c_int), parameter, public :: MFREE_METHOD_RANDLES_LIBERSKY = 7
  integer(c_int), parameter, public :: MFREE_METHOD_KB_METHOD1 = 8
  integer(c_int), parameter, public :: MFREE_METHOD_KB_METHOD2 = 9
  integer(c_int), parameter, public :: MFREE_METHOD_KB_METHOD3 = 10
  integer(c_int), parameter, public :: MFREE_METHOD_MSPH = 11
  integer(c_int), parameter, public :: MFREE_METHOD_SSPH = 12
  integer(c_int), parameter, public :: MFREE_METHOD_MPFEM = 13

  ! ---- mfree_deriv_t (bit flags: combine with ior) --------------------------------
  integer(c_int), parameter, public :: MFREE_DERIV_VALUE = 1
  integer(c_int), parameter, public :: MFREE_DERIV_GRADIENT = 2
  integer(c_int), parameter, public :: MFREE_DERIV_HESSIAN = 4

  ! ---- mfree_op_t ----------------------------------------------------------------
  integer(c_int), parameter, public :: MFREE_OP_VALUE = 1
  integer(c_int), parameter, public :: MFREE_OP_GRADIENT = 2
  integer(c_int), parameter, public :: MFREE_OP_DIVERGENCE = 3
  integer(c_int), parameter, public :: MFREE_OP_LAPLACIAN = 4
  integer(c_int), parameter, public :: MFREE_OP_HESSIAN = 5

  ! ---- mfree_fallback_t ----------------------------------------------------------
  integer(c_int), parameter, public :: MFREE_FALLBACK_NONE = 1
  integer(c_int), parameter, public :: MFREE_FALLBACK_LOWER_ORDER = 2

  ! ---- mfree_form_t --------------------------------------------------------------
  integer(c_int), parameter, public :: MFREE_FORM_LAPLACE = 1
  integer(c_int), parameter, public :: MFREE_FORM_ELASTICITY_PLANE_STRESS = 2
  integer(c_int), parameter, public :: MFREE_FORM_ELASTICITY_PLANE_STRAIN = 3
  integer(c_int), parameter, public :: MFREE_FORM_ELASTICITY_3D = 4
  integer(c_int), parameter, public :: MFREE_FORM_MASS = 5
  integer(c_int), parameter, public :: MFREE_FORM_MASS_LUMPED = 6
  integer(c_int), parameter, public :: MFREE_FORM_COLLOCATION_LAPLACE = 7
  integer(c_int), parameter, public :: MFREE_FORM_COLLOCATION_PLANE_STRESS = 8
  integer(c_int), parameter, public :: MFREE_FORM_COLLOCATION_PLANE_STRAIN = 9

  ! ---- mfree_bc_t ----------------------------------------------------------------
  integer(c_int), parameter, public :: MFREE_BC_PENALTY = 1
  integer(c_int), parameter, public :: MFREE_BC_LAGRANGE = 2
  integer(c_int), parameter, public :: MFREE_BC_COLLOCATION = 3
  integer(c_int), parameter, public :: MFREE_BC_NITSCHE = 4

  ! ---- mfree_integrator_t --------------------------------------------------------
  integer(c_int), parameter, public :: MFREE_INTEGRATOR_LEAPFROG = 1
  integer(c_int), parameter, public :: MFREE_INTEGRATOR_PREDICTOR_CORRECTOR = 2

  ! ---- mfree_lumping_t -----------------------------------------------------------
  integer(c_int), parameter, public :: MFREE_LUMP_GALERKIN = 1
  integer(c_int), parameter, public :: MFREE_LUMP_PHYSICAL = 2
  integer(c_int), parameter, public :: MFREE_PARTICLE_DORMANT = 0
  integer(c_int), parameter, public :: MFREE_PARTICLE_FLUID = 1
  integer(c_int), parameter, public :: MFREE_PARTICLE_INFLOW = 2
  ! mfree_backend_t, mfree_pages_t (mfree.h)
  integer(c_int), parameter, public :: MFREE_BACKEND_REF = 1
  integer(c_int), parameter, public :: MFREE_BACKEND_OPT = 2
  integer(c_int), parameter, public :: MFREE_PAGES_DEFAULT = 0
  integer(c_int), parameter, public :: MFREE_PAGES_HUGE = 1
  integer(c_int), parameter, public :: MFREE_PAGES_PREFAULT = 2

  ! ---- mfree_element_t (mesh element types) -----------------------------------------
  integer(c_int), parameter, public :: MFREE_ELEMENT_LINE2 = 1
  integer(c_int), parameter, public :: MFREE_ELEMENT_TRI3 = 2
  integer(c_int), parameter, public :: MFREE_ELEMENT_QUAD4 = 3
  integer(c_int), parameter, public :: MFREE_ELEMENT_HEX8 = 4

  ! ---- mfree_mpfem_deriv_t (MPFEM derivative forms, paper 004) -----------------------
  integer(c_int), parameter, public :: MFREE_MPFEM_DERIV_FULL = 1
  integer(c_int), parameter, public :: MFREE_MPFEM_DERIV_ASSUMED_STRAIN = 2
  integer(c_int), parameter, public :: MFREE_MPFEM_DERIV_NODAL = 3

  ! ---- typed handles: one C handle each; null until created, null again after destroy
  type, public :: mfree_context
    type(c_ptr) :: ptr = c_null_ptr
  end type mfree_context
  type, public :: mfree_particles
    type(c_ptr) :: ptr = c_null_ptr
  end type mfree_particles
  type, public :: mfree_approximant
    type(c_ptr) :: ptr = c_null_ptr
  end type mfree_approximant
  type, public :: mfree_matrix
    type(c_ptr) :: ptr = c_null_ptr
  end type mfree_matrix
  type, public :: mfree_assembler
    type(c_ptr) :: ptr = c_null_ptr
  end type mfree_assembler
  type, public :: mfree_system
    type(c_ptr) :: ptr = c_null_ptr
  end type mfree_system
  type, public :: mfree_mesh
    type(c_ptr) :: ptr = c_null_ptr
  end type mfree_mesh

  ! ---- host callbacks: write bind(C) procedures with these interfaces ---------------
  abstract interface
    !> mfree_field_fn: write the ncomp values of a field at x (dim coordinates).
    subroutine mfree_field_fn(user, x, value) bind(C)
      import :: c_ptr, c_double
      type(c_ptr), value :: user
      real(c_double), intent(in) :: x(*)
      real(c_double), intent(out) :: value(*)
    end subroutine mfree_field_fn
    !> mfree_inside_fn: nonzero when x lies in the domain.
    integer(c_int32_t) function mfree_inside_fn(user, x) bind(C)
      import :: c_ptr, c_double, c_int32_t
      type(c_ptr), value :: user
      real(c_double), intent(in) :: x(*)
    end function mfree_inside_fn
    !> mfree_error_handler_t: message is a NUL-terminated C string (mfree_c_string).
    subroutine mfree_error_handler(user, code, message) bind(C)
      import :: c_ptr, c_int
      type(c_ptr), value :: user
      integer(c_int), value :: code
      type(c_ptr), value :: message
    end subroutine mfree_error_handler
    !> mfree_progress_fn: after every accepted step of mfree_system_integrate; return
    !> nonzero to stop.
    integer(c_int32_t) function mfree_progress_fn(user, step, t, dt) bind(C)
      import :: c_ptr, c_int32_t, c_int64_t, c_double
      type(c_ptr), value :: user
      integer(c_int64_t), value :: step
      real(c_double), value :: t, dt
    end function mfree_progress_fn
    !> mfree_history_fn: the load history g(t) of an elastodynamic system.
    real(c_double) function mfree_history_fn(user, t) bind(C)
      import :: c_ptr, c_double
      type(c_ptr), value :: user
      real(c_double), value :: t
    end function mfree_history_fn
  end interface
  public :: mfree_field_fn, mfree_inside_fn, mfree_error_handler, mfree_progress_fn
  public :: mfree_history_fn

  ! ---- raw bind(C) interfaces: one per public function of mfree.h ------------------
  interface
    ! -- version and status
    type(c_ptr) function mfree_version_string_c() &
        bind(C, name="mfree_version_string")
      import :: c_ptr
    end function mfree_version_string_c

    integer(c_int) function mfree_version_get_c(major, minor, patch) &
        bind(C, name="mfree_version_get")
      import :: c_int, c_ptr
      type(c_ptr), value :: major
      type(c_ptr), value :: minor
      type(c_ptr), value :: patch
    end function mfree_version_get_c

    type(c_ptr) function mfree_status_string_c(status) &
        bind(C, name="mfree_status_string")
      import :: c_int, c_ptr
      integer(c_int), value :: status
    end function mfree_status_string_c

    ! -- context
    integer(c_int) function mfree_context_create_c(ctx) &
        bind(C, name="mfree_context_create")
      import :: c_int, c_ptr
      type(c_ptr), intent(out) :: ctx
    end function mfree_context_create_c

    integer(c_int) function mfree_context_destroy_c(ctx) &
        bind(C, name="mfree_context_destroy")
      import :: c_int, c_ptr
      type(c_ptr), intent(inout) :: ctx
    end function mfree_context_destroy_c

    integer(c_int) function mfree_context_get_last_error_c(ctx, code, message, len) &
        bind(C, name="mfree_context_get_last_error")
      import :: c_int, c_int64_t, c_ptr
      type(c_ptr), value :: ctx
      type(c_ptr), value :: code
      type(c_ptr), value :: message
      integer(c_int64_t), value :: len
    end function mfree_context_get_last_error_c

    integer(c_int) function mfree_context_set_error_c(ctx, code, message) &
        bind(C, name="mfree_context_set_error")
      import :: c_int, c_ptr
      type(c_ptr), value :: ctx
      integer(c_int), value :: code
      type(c_ptr), value :: message
    end function mfree_context_set_error_c

    integer(c_int) function mfree_context_set_error_handler_c(ctx, handler, user) &
        bind(C, name="mfree_context_set_error_handler")
      import :: c_int, c_ptr, c_funptr
      type(c_ptr), value :: ctx
      type(c_funptr), value :: handler
      type(c_ptr), value :: user
    end function mfree_context_set_error_handler_c

    integer(c_int) function mfree_context_set_num_threads_c(ctx, nthreads) &
        bind(C, name="mfree_context_set_num_threads")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: ctx
      integer(c_int32_t), value :: nthreads
    end function mfree_context_set_num_threads_c

    integer(c_int) function mfree_context_get_num_threads_c(ctx, nthreads) &
        bind(C, name="mfree_context_get_num_threads")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: ctx
      integer(c_int32_t), intent(out) :: nthreads
    end function mfree_context_get_num_threads_c

    integer(c_int) function mfree_context_set_backend_c(ctx, backend) &
        bind(C, name="mfree_context_set_backend")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: ctx
      integer(c_int32_t), value :: backend
    end function mfree_context_set_backend_c

    integer(c_int) function mfree_context_get_backend_c(ctx, backend) &
        bind(C, name="mfree_context_get_backend")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: ctx
      integer(c_int32_t), intent(out) :: backend
    end function mfree_context_get_backend_c

    integer(c_int) function mfree_context_set_page_hints_c(ctx, flags) &
        bind(C, name="mfree_context_set_page_hints")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: ctx
      integer(c_int32_t), value :: flags
    end function mfree_context_set_page_hints_c

    integer(c_int) function mfree_context_get_page_hints_c(ctx, flags) &
        bind(C, name="mfree_context_get_page_hints")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: ctx
      integer(c_int32_t), intent(out) :: flags
    end function mfree_context_get_page_hints_c

    ! alloc: type(c_funptr) to a bind(C) function returning type(c_ptr) with arguments
    ! (type(c_ptr), value :: user; integer(c_int64_t), value :: bytes); release: a
    ! bind(C) subroutine (user, ptr, bytes); both c_null_funptr restores malloc.
    integer(c_int) function mfree_context_set_allocator_c(ctx, alloc, release, user) &
        bind(C, name="mfree_context_set_allocator")
      import :: c_int, c_ptr, c_funptr
      type(c_ptr), value :: ctx
      type(c_funptr), value :: alloc, release
      type(c_ptr), value :: user
    end function mfree_context_set_allocator_c

    ! -- kernels
    integer(c_int) function mfree_kernel_eval_c(ctx, kernel, dim, param, h, n, r, w, dwdr, &
                                                d2wdr2) &
        bind(C, name="mfree_kernel_eval")
      import :: c_int, c_int32_t, c_int64_t, c_double, c_ptr
      type(c_ptr), value :: ctx
      integer(c_int), value :: kernel
      integer(c_int32_t), value :: dim
      real(c_double), value :: param
      real(c_double), value :: h
      integer(c_int64_t), value :: n
      real(c_double), intent(in) :: r(*)
      type(c_ptr), value :: w
      type(c_ptr), value :: dwdr
      type(c_ptr), value :: d2wdr2
    end function mfree_kernel_eval_c

    integer(c_int) function mfree_kernel_get_support_radius_c(ctx, kernel, param, radius) &
        bind(C, name="mfree_kernel_get_support_radius")
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: ctx
      integer(c_int), value :: kernel
      real(c_double), value :: param
      real(c_double), intent(out) :: radius
    end function mfree_kernel_get_support_radius_c

    integer(c_int) function mfree_kernel_get_normalization_c(ctx, kernel, dim, param, c) &
        bind(C, name="mfree_kernel_get_normalization")
      import :: c_int, c_int32_t, c_double, c_ptr
      type(c_ptr), value :: ctx
      integer(c_int), value :: kernel
      integer(c_int32_t), value :: dim
      real(c_double), value :: param
      real(c_double), intent(out) :: c
    end function mfree_kernel_get_normalization_c

    ! -- particle sets
    integer(c_int) function mfree_particles_create_c(ctx, dim, n, ps) &
        bind(C, name="mfree_particles_create")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: ctx
      integer(c_int32_t), value :: dim
      integer(c_int32_t), value :: n
      type(c_ptr), intent(out) :: ps
    end function mfree_particles_create_c

    integer(c_int) function mfree_particles_destroy_c(ps) &
        bind(C, name="mfree_particles_destroy")
      import :: c_int, c_ptr
      type(c_ptr), intent(inout) :: ps
    end function mfree_particles_destroy_c

    integer(c_int) function mfree_particles_set_num_ghost_c(ps, n_ghost) &
        bind(C, name="mfree_particles_set_num_ghost")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: ps
      integer(c_int32_t), value :: n_ghost
    end function mfree_particles_set_num_ghost_c

    integer(c_int) function mfree_particles_set_positions_c(ps, x, layout, ld, mem) &
        bind(C, name="mfree_particles_set_positions")
      import :: c_int, c_int64_t, c_double, c_ptr
      type(c_ptr), value :: ps
      real(c_double), intent(in), target :: x(*)
      integer(c_int), value :: layout
      integer(c_int64_t), value :: ld
      integer(c_int), value :: mem
    end function mfree_particles_set_positions_c

    integer(c_int) function mfree_particles_set_volumes_c(ps, v, stride, mem) &
        bind(C, name="mfree_particles_set_volumes")
      import :: c_int, c_int64_t, c_double, c_ptr
      type(c_ptr), value :: ps
      real(c_double), intent(in), target :: v(*)
      integer(c_int64_t), value :: stride
      integer(c_int), value :: mem
    end function mfree_particles_set_volumes_c

    integer(c_int) function mfree_particles_set_masses_c(ps, m, stride, mem) &
        bind(C, name="mfree_particles_set_masses")
      import :: c_int, c_int64_t, c_double, c_ptr
      type(c_ptr), value :: ps
      real(c_double), intent(in), target :: m(*)
      integer(c_int64_t), value :: stride
      integer(c_int), value :: mem
    end function mfree_particles_set_masses_c

    integer(c_int) function mfree_particles_set_densities_c(ps, rho, stride, mem) &
        bind(C, name="mfree_particles_set_densities")
      import :: c_int, c_int64_t, c_double, c_ptr
      type(c_ptr), value :: ps
      real(c_double), intent(in), target :: rho(*)
      integer(c_int64_t), value :: stride
      integer(c_int), value :: mem
    end function mfree_particles_set_densities_c

    integer(c_int) function mfree_particles_set_support_c(ps, h, stride, mem) &
        bind(C, name="mfree_particles_set_support")
      import :: c_int, c_int64_t, c_double, c_ptr
      type(c_ptr), value :: ps
      real(c_double), intent(in), target :: h(*)
      integer(c_int64_t), value :: stride
      integer(c_int), value :: mem
    end function mfree_particles_set_support_c

    integer(c_int) function mfree_particles_set_search_c(ps, convention, kappa) &
        bind(C, name="mfree_particles_set_search")
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: ps
      integer(c_int), value :: convention
      real(c_double), value :: kappa
    end function mfree_particles_set_search_c

    integer(c_int) function mfree_particles_set_periodic_c(ps, lo, hi, periodic) &
        bind(C, name="mfree_particles_set_periodic")
      import :: c_int, c_int32_t, c_double, c_ptr
      type(c_ptr), value :: ps
      real(c_double), intent(in) :: lo(*)
      real(c_double), intent(in) :: hi(*)
      integer(c_int32_t), intent(in) :: periodic(*)
    end function mfree_particles_set_periodic_c

    integer(c_int) function mfree_particles_set_neighbors_c(ps, rowptr, cols, index_base, mem) &
        bind(C, name="mfree_particles_set_neighbors")
      import :: c_int, c_int32_t, c_int64_t, c_ptr
      type(c_ptr), value :: ps
      integer(c_int64_t), intent(in), target :: rowptr(*)
      integer(c_int32_t), intent(in), target :: cols(*)
      integer(c_int32_t), value :: index_base
      integer(c_int), value :: mem
    end function mfree_particles_set_neighbors_c

    integer(c_int) function mfree_particles_set_global_ids_c(ps, ids, mem) &
        bind(C, name="mfree_particles_set_global_ids")
      import :: c_int, c_int64_t, c_ptr
      type(c_ptr), value :: ps
      integer(c_int64_t), intent(in), target :: ids(*)
      integer(c_int), value :: mem
    end function mfree_particles_set_global_ids_c

    integer(c_int) function mfree_particles_get_global_ids_c(ps, ids) &
        bind(C, name="mfree_particles_get_global_ids")
      import :: c_int, c_int64_t, c_ptr
      type(c_ptr), value :: ps
      integer(c_int64_t), intent(out) :: ids(*)
    end function mfree_particles_get_global_ids_c

    integer(c_int) function mfree_particles_set_halo_width_c(ps, w) &
        bind(C, name="mfree_particles_set_halo_width")
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: ps
      real(c_double), value :: w
    end function mfree_particles_set_halo_width_c

    integer(c_int) function mfree_particles_set_search_skin_c(ps, skin) &
        bind(C, name="mfree_particles_set_search_skin")
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: ps
      real(c_double), value :: skin
    end function mfree_particles_set_search_skin_c

    integer(c_int) function mfree_particles_get_search_count_c(ps, count) &
        bind(C, name="mfree_particles_get_search_count")
      import :: c_int, c_int64_t, c_ptr
      type(c_ptr), value :: ps
      integer(c_int64_t), intent(out) :: count
    end function mfree_particles_get_search_count_c

    integer(c_int) function mfree_particles_setup_c(ps) &
        bind(C, name="mfree_particles_setup")
      import :: c_int, c_ptr
      type(c_ptr), value :: ps
    end function mfree_particles_setup_c

    integer(c_int) function mfree_particles_update_c(ps) &
        bind(C, name="mfree_particles_update")
      import :: c_int, c_ptr
      type(c_ptr), value :: ps
    end function mfree_particles_update_c

    integer(c_int) function mfree_particles_get_dimension_c(ps, dim) &
        bind(C, name="mfree_particles_get_dimension")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: ps
      integer(c_int32_t), intent(out) :: dim
    end function mfree_particles_get_dimension_c

    integer(c_int) function mfree_particles_get_size_c(ps, n, n_ghost) &
        bind(C, name="mfree_particles_get_size")
      import :: c_int, c_ptr
      type(c_ptr), value :: ps
      type(c_ptr), value :: n
      type(c_ptr), value :: n_ghost
    end function mfree_particles_get_size_c

    integer(c_int) function mfree_particles_get_neighbor_nnz_c(ps, nnz) &
        bind(C, name="mfree_particles_get_neighbor_nnz")
      import :: c_int, c_int64_t, c_ptr
      type(c_ptr), value :: ps
      integer(c_int64_t), intent(out) :: nnz
    end function mfree_particles_get_neighbor_nnz_c

    integer(c_int) function mfree_particles_get_neighbors_c(ps, rowptr, cols) &
        bind(C, name="mfree_particles_get_neighbors")
      import :: c_int, c_int32_t, c_int64_t, c_ptr
      type(c_ptr), value :: ps
      integer(c_int64_t), intent(out) :: rowptr(*)
      integer(c_int32_t), intent(out) :: cols(*)
    end function mfree_particles_get_neighbors_c

    integer(c_int) function mfree_particles_get_volumes_c(ps, v) &
        bind(C, name="mfree_particles_get_volumes")
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: ps
      real(c_double), intent(out) :: v(*)
    end function mfree_particles_get_volumes_c

    integer(c_int) function mfree_particles_get_site_status_c(ps, status, nfailed) &
        bind(C, name="mfree_particles_get_site_status")
      import :: c_int, c_ptr
      type(c_ptr), value :: ps
      type(c_ptr), value :: status
      type(c_ptr), value :: nfailed
    end function mfree_particles_get_site_status_c

    ! -- pair lists, per-pair gradients, correction data
    integer(c_int) function mfree_particles_set_pairs_c(ps, npairs, pair_i, pair_j, &
                                                       index_base, mem) &
        bind(C, name="mfree_particles_set_pairs")
      import :: c_int, c_int32_t, c_int64_t, c_ptr
      type(c_ptr), value :: ps
      integer(c_int64_t), value :: npairs
      type(c_ptr), value :: pair_i
      type(c_ptr), value :: pair_j
      integer(c_int32_t), value :: index_base
      integer(c_int), value :: mem
    end function mfree_particles_set_pairs_c

    integer(c_int) function mfree_particles_get_num_pairs_c(ps, npairs) &
        bind(C, name="mfree_particles_get_num_pairs")
      import :: c_int, c_int64_t, c_ptr
      type(c_ptr), value :: ps
      integer(c_int64_t), intent(out) :: npairs
    end function mfree_particles_get_num_pairs_c

    integer(c_int) function mfree_approximant_get_pair_gradients_c(a, gi, gj, ld, capacity) &
        bind(C, name="mfree_approximant_get_pair_gradients")
      import :: c_int, c_int64_t, c_ptr
      type(c_ptr), value :: a
      type(c_ptr), value :: gi
      type(c_ptr), value :: gj
      integer(c_int64_t), value :: ld
      integer(c_int64_t), value :: capacity
    end function mfree_approximant_get_pair_gradients_c

    integer(c_int) function mfree_approximant_get_pair_gradients_antisymmetric_c(a, g, ld, &
                                                                                capacity) &
        bind(C, name="mfree_approximant_get_pair_gradients_antisymmetric")
      import :: c_int, c_int64_t, c_ptr
      type(c_ptr), value :: a
      type(c_ptr), value :: g
      integer(c_int64_t), value :: ld
      integer(c_int64_t), value :: capacity
    end function mfree_approximant_get_pair_gradients_antisymmetric_c

    integer(c_int) function mfree_approximant_get_correction_size_c(a, ncoef) &
        bind(C, name="mfree_approximant_get_correction_size")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: a
      integer(c_int32_t), intent(out) :: ncoef
    end function mfree_approximant_get_correction_size_c

    integer(c_int) function mfree_approximant_get_correction_c(a, c, ld, capacity) &
        bind(C, name="mfree_approximant_get_correction")
      import :: c_int, c_int64_t, c_ptr
      type(c_ptr), value :: a
      type(c_ptr), value :: c
      integer(c_int64_t), value :: ld
      integer(c_int64_t), value :: capacity
    end function mfree_approximant_get_correction_c

    integer(c_int) function mfree_approximant_set_ghost_correction_c(a, c, ld, capacity) &
        bind(C, name="mfree_approximant_set_ghost_correction")
      import :: c_int, c_int64_t, c_ptr, c_double
      type(c_ptr), value :: a
      real(c_double), intent(in) :: c(*)
      integer(c_int64_t), value :: ld
      integer(c_int64_t), value :: capacity
    end function mfree_approximant_set_ghost_correction_c

    ! -- an object's context and particle set (for the wrappers' own checks)
    integer(c_int) function mfree_particles_get_context_c(ps, ctx) &
        bind(C, name="mfree_particles_get_context")
      import :: c_int, c_ptr
      type(c_ptr), value :: ps
      type(c_ptr) :: ctx
    end function mfree_particles_get_context_c

    integer(c_int) function mfree_approximant_get_context_c(a, ctx) &
        bind(C, name="mfree_approximant_get_context")
      import :: c_int, c_ptr
      type(c_ptr), value :: a
      type(c_ptr) :: ctx
    end function mfree_approximant_get_context_c

    integer(c_int) function mfree_mesh_get_context_c(mesh, ctx) &
        bind(C, name="mfree_mesh_get_context")
      import :: c_int, c_ptr
      type(c_ptr), value :: mesh
      type(c_ptr) :: ctx
    end function mfree_mesh_get_context_c

    integer(c_int) function mfree_matrix_get_context_c(A, ctx) &
        bind(C, name="mfree_matrix_get_context")
      import :: c_int, c_ptr
      type(c_ptr), value :: A
      type(c_ptr) :: ctx
    end function mfree_matrix_get_context_c

    integer(c_int) function mfree_assembler_get_context_c(as, ctx) &
        bind(C, name="mfree_assembler_get_context")
      import :: c_int, c_ptr
      type(c_ptr), value :: as
      type(c_ptr) :: ctx
    end function mfree_assembler_get_context_c

    integer(c_int) function mfree_system_get_context_c(sys, ctx) &
        bind(C, name="mfree_system_get_context")
      import :: c_int, c_ptr
      type(c_ptr), value :: sys
      type(c_ptr) :: ctx
    end function mfree_system_get_context_c

    integer(c_int) function mfree_system_set_pending_error_c(sys, status, message) &
        bind(C, name="mfree_system_set_pending_error")
      import :: c_int, c_ptr
      type(c_ptr), value :: sys
      integer(c_int), value :: status
      type(c_ptr), value :: message
    end function mfree_system_set_pending_error_c

    integer(c_int) function mfree_approximant_get_particles_c(a, ps) &
        bind(C, name="mfree_approximant_get_particles")
      import :: c_int, c_ptr
      type(c_ptr), value :: a
      type(c_ptr) :: ps
    end function mfree_approximant_get_particles_c

    integer(c_int) function mfree_mesh_get_particles_c(mesh, ps) &
        bind(C, name="mfree_mesh_get_particles")
      import :: c_int, c_ptr
      type(c_ptr), value :: mesh
      type(c_ptr) :: ps
    end function mfree_mesh_get_particles_c

    integer(c_int) function mfree_system_get_dimension_c(sys, dim, n) &
        bind(C, name="mfree_system_get_dimension")
      import :: c_int, c_ptr
      type(c_ptr), value :: sys
      type(c_ptr), value :: dim
      type(c_ptr), value :: n
    end function mfree_system_get_dimension_c

    ! -- approximants
    integer(c_int) function mfree_approximant_create_c(ctx, ps, method, a) &
        bind(C, name="mfree_approximant_create")
      import :: c_int, c_ptr
      type(c_ptr), value :: ctx
      type(c_ptr), value :: ps
      integer(c_int), value :: method
      type(c_ptr), intent(out) :: a
    end function mfree_approximant_create_c

    integer(c_int) function mfree_approximant_destroy_c(a) &
        bind(C, name="mfree_approximant_destroy")
      import :: c_int, c_ptr
      type(c_ptr), intent(inout) :: a
    end function mfree_approximant_destroy_c

    integer(c_int) function mfree_approximant_set_kernel_c(a, kernel, param) &
        bind(C, name="mfree_approximant_set_kernel")
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: a
      integer(c_int), value :: kernel
      real(c_double), value :: param
    end function mfree_approximant_set_kernel_c

    integer(c_int) function mfree_approximant_set_order_c(a, order) &
        bind(C, name="mfree_approximant_set_order")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: a
      integer(c_int32_t), value :: order
    end function mfree_approximant_set_order_c

    integer(c_int) function mfree_approximant_set_derivatives_c(a, flags) &
        bind(C, name="mfree_approximant_set_derivatives")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: a
      integer(c_int32_t), value :: flags
    end function mfree_approximant_set_derivatives_c

    integer(c_int) function mfree_approximant_set_fallback_c(a, policy) &
        bind(C, name="mfree_approximant_set_fallback")
      import :: c_int, c_ptr
      type(c_ptr), value :: a
      integer(c_int), value :: policy
    end function mfree_approximant_set_fallback_c

    integer(c_int) function mfree_approximant_set_points_c(a, npts, x, layout, ld, h, &
                                                           h_stride, mem) &
        bind(C, name="mfree_approximant_set_points")
      import :: c_int, c_int32_t, c_int64_t, c_double, c_ptr
      type(c_ptr), value :: a
      integer(c_int32_t), value :: npts
      real(c_double), intent(in), target :: x(*)
      integer(c_int), value :: layout
      integer(c_int64_t), value :: ld
      real(c_double), intent(in), target :: h(*)
      integer(c_int64_t), value :: h_stride
      integer(c_int), value :: mem
    end function mfree_approximant_set_points_c

    integer(c_int) function mfree_mesh_create_c(ctx, ps, mesh) &
        bind(C, name="mfree_mesh_create")
      import :: c_int, c_ptr
      type(c_ptr), value :: ctx
      type(c_ptr), value :: ps
      type(c_ptr) :: mesh
    end function mfree_mesh_create_c

    integer(c_int) function mfree_mesh_destroy_c(mesh) &
        bind(C, name="mfree_mesh_destroy")
      import :: c_int, c_ptr
      type(c_ptr) :: mesh
    end function mfree_mesh_destroy_c

    integer(c_int) function mfree_mesh_add_elements_c(mesh, type, nelem, conn, index_base, &
                                                      mem) &
        bind(C, name="mfree_mesh_add_elements")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: mesh
      integer(c_int), value :: type
      integer(c_int32_t), value :: nelem
      integer(c_int32_t), intent(in), target :: conn(*)
      integer(c_int32_t), value :: index_base
      integer(c_int), value :: mem
    end function mfree_mesh_add_elements_c

    integer(c_int) function mfree_mesh_setup_c(mesh) &
        bind(C, name="mfree_mesh_setup")
      import :: c_int, c_ptr
      type(c_ptr), value :: mesh
    end function mfree_mesh_setup_c

    integer(c_int) function mfree_mesh_get_size_c(mesh, nelem) &
        bind(C, name="mfree_mesh_get_size")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: mesh
      integer(c_int32_t), intent(out) :: nelem
    end function mfree_mesh_get_size_c

    integer(c_int) function mfree_mesh_get_quadrature_c(mesh, ngauss, npts, x, w) &
        bind(C, name="mfree_mesh_get_quadrature")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: mesh
      integer(c_int32_t), value :: ngauss
      integer(c_int32_t), intent(out) :: npts
      type(c_ptr), value :: x
      type(c_ptr), value :: w
    end function mfree_mesh_get_quadrature_c

    integer(c_int) function mfree_approximant_set_mesh_c(a, mesh) &
        bind(C, name="mfree_approximant_set_mesh")
      import :: c_int, c_ptr
      type(c_ptr), value :: a
      type(c_ptr), value :: mesh
    end function mfree_approximant_set_mesh_c

    integer(c_int) function mfree_approximant_set_mpfem_c(a, deriv, ngauss) &
        bind(C, name="mfree_approximant_set_mpfem")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: a
      integer(c_int), value :: deriv
      integer(c_int32_t), value :: ngauss
    end function mfree_approximant_set_mpfem_c

    integer(c_int) function mfree_approximant_setup_c(a) &
        bind(C, name="mfree_approximant_setup")
      import :: c_int, c_ptr
      type(c_ptr), value :: a
    end function mfree_approximant_setup_c

    integer(c_int) function mfree_approximant_update_c(a) &
        bind(C, name="mfree_approximant_update")
      import :: c_int, c_ptr
      type(c_ptr), value :: a
    end function mfree_approximant_update_c

    integer(c_int) function mfree_approximant_apply_c(a, op, ncomp, u, ulayout, uld, out, &
                                                      olayout, old) &
        bind(C, name="mfree_approximant_apply")
      import :: c_int, c_int32_t, c_int64_t, c_double, c_ptr
      type(c_ptr), value :: a
      integer(c_int), value :: op
      integer(c_int32_t), value :: ncomp
      real(c_double), intent(in) :: u(*)
      integer(c_int), value :: ulayout
      integer(c_int64_t), value :: uld
      real(c_double), intent(out) :: out(*)
      integer(c_int), value :: olayout
      integer(c_int64_t), value :: old
    end function mfree_approximant_apply_c

    integer(c_int) function mfree_approximant_apply_add_c(a, op, ncomp, u, ulayout, uld, &
                                                          out, olayout, old) &
        bind(C, name="mfree_approximant_apply_add")
      import :: c_int, c_int32_t, c_int64_t, c_double, c_ptr
      type(c_ptr), value :: a
      integer(c_int), value :: op
      integer(c_int32_t), value :: ncomp
      real(c_double), intent(in) :: u(*)
      integer(c_int), value :: ulayout
      integer(c_int64_t), value :: uld
      real(c_double), intent(inout) :: out(*)
      integer(c_int), value :: olayout
      integer(c_int64_t), value :: old
    end function mfree_approximant_apply_add_c

    integer(c_int) function mfree_approximant_get_num_sites_c(a, nsites) &
        bind(C, name="mfree_approximant_get_num_sites")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: a
      integer(c_int32_t), intent(out) :: nsites
    end function mfree_approximant_get_num_sites_c

    integer(c_int) function mfree_approximant_get_nnz_c(a, nnz) &
        bind(C, name="mfree_approximant_get_nnz")
      import :: c_int, c_int64_t, c_ptr
      type(c_ptr), value :: a
      integer(c_int64_t), intent(out) :: nnz
    end function mfree_approximant_get_nnz_c

    integer(c_int) function mfree_approximant_assemble_csr_c(a, deriv, component, rowptr, &
                                                             cols, vals) &
        bind(C, name="mfree_approximant_assemble_csr")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: a
      integer(c_int), value :: deriv
      integer(c_int32_t), value :: component
      type(c_ptr), value :: rowptr
      type(c_ptr), value :: cols
      type(c_ptr), value :: vals
    end function mfree_approximant_assemble_csr_c

    integer(c_int) function mfree_approximant_check_reproduction_c(a, order, fn_err, &
                                                                   deriv_err) &
        bind(C, name="mfree_approximant_check_reproduction")
      import :: c_int, c_int32_t, c_double, c_ptr
      type(c_ptr), value :: a
      integer(c_int32_t), value :: order
      real(c_double), intent(out) :: fn_err
      real(c_double), intent(out) :: deriv_err
    end function mfree_approximant_check_reproduction_c

    integer(c_int) function mfree_approximant_get_site_status_c(a, status, nfailed) &
        bind(C, name="mfree_approximant_get_site_status")
      import :: c_int, c_ptr
      type(c_ptr), value :: a
      type(c_ptr), value :: status
      type(c_ptr), value :: nfailed
    end function mfree_approximant_get_site_status_c

    integer(c_int) function mfree_approximant_get_neighbor_counts_c(a, counts) &
        bind(C, name="mfree_approximant_get_neighbor_counts")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: a
      integer(c_int32_t), intent(out) :: counts(*)
    end function mfree_approximant_get_neighbor_counts_c

    integer(c_int) function mfree_approximant_get_condition_c(a, cond) &
        bind(C, name="mfree_approximant_get_condition")
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: a
      real(c_double), intent(out) :: cond(*)
    end function mfree_approximant_get_condition_c

    integer(c_int) function mfree_approximant_get_site_order_c(a, order) &
        bind(C, name="mfree_approximant_get_site_order")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: a
      integer(c_int32_t), intent(out) :: order(*)
    end function mfree_approximant_get_site_order_c

    ! -- sparse matrices
    integer(c_int) function mfree_matrix_create_csr_c(ctx, nrows, ncols, rowptr, cols, &
                                                      vals, A) &
        bind(C, name="mfree_matrix_create_csr")
      import :: c_int, c_int32_t, c_int64_t, c_double, c_ptr
      type(c_ptr), value :: ctx
      integer(c_int32_t), value :: nrows
      integer(c_int32_t), value :: ncols
      integer(c_int64_t), intent(in) :: rowptr(*)
      integer(c_int32_t), intent(in) :: cols(*)
      real(c_double), intent(in) :: vals(*)
      type(c_ptr), intent(out) :: A
    end function mfree_matrix_create_csr_c

    integer(c_int) function mfree_matrix_destroy_c(A) &
        bind(C, name="mfree_matrix_destroy")
      import :: c_int, c_ptr
      type(c_ptr), intent(inout) :: A
    end function mfree_matrix_destroy_c

    integer(c_int) function mfree_matrix_get_size_c(A, nrows, ncols, nnz) &
        bind(C, name="mfree_matrix_get_size")
      import :: c_int, c_ptr
      type(c_ptr), value :: A
      type(c_ptr), value :: nrows
      type(c_ptr), value :: ncols
      type(c_ptr), value :: nnz
    end function mfree_matrix_get_size_c

    integer(c_int) function mfree_matrix_get_csr_c(A, rowptr, cols, vals) &
        bind(C, name="mfree_matrix_get_csr")
      import :: c_int, c_ptr
      type(c_ptr), value :: A
      type(c_ptr), intent(out) :: rowptr
      type(c_ptr), intent(out) :: cols
      type(c_ptr), intent(out) :: vals
    end function mfree_matrix_get_csr_c

    integer(c_int) function mfree_matrix_get_csr_i32_c(A, rowptr, cols, vals) &
        bind(C, name="mfree_matrix_get_csr_i32")
      import :: c_int, c_ptr
      type(c_ptr), value :: A
      type(c_ptr), intent(out) :: rowptr
      type(c_ptr), intent(out) :: cols
      type(c_ptr), intent(out) :: vals
    end function mfree_matrix_get_csr_i32_c

    integer(c_int) function mfree_matrix_get_csr_i64_c(A, rowptr, cols, vals) &
        bind(C, name="mfree_matrix_get_csr_i64")
      import :: c_int, c_ptr
      type(c_ptr), value :: A
      type(c_ptr), intent(out) :: rowptr
      type(c_ptr), intent(out) :: cols
      type(c_ptr), intent(out) :: vals
    end function mfree_matrix_get_csr_i64_c

    integer(c_int) function mfree_matrix_get_csc_c(A, colptr, rows, vals) &
        bind(C, name="mfree_matrix_get_csc")
      import :: c_int, c_ptr
      type(c_ptr), value :: A
      type(c_ptr), intent(out) :: colptr
      type(c_ptr), intent(out) :: rows
      type(c_ptr), intent(out) :: vals
    end function mfree_matrix_get_csc_c

    integer(c_int) function mfree_matrix_get_pattern_id_c(A, id) &
        bind(C, name="mfree_matrix_get_pattern_id")
      import :: c_int, c_int64_t, c_ptr
      type(c_ptr), value :: A
      integer(c_int64_t), intent(out) :: id
    end function mfree_matrix_get_pattern_id_c

    integer(c_int) function mfree_matrix_get_symmetric_c(A, symmetric) &
        bind(C, name="mfree_matrix_get_symmetric")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: A
      integer(c_int32_t), intent(out) :: symmetric
    end function mfree_matrix_get_symmetric_c

    integer(c_int) function mfree_matrix_apply_c(A, x, y) &
        bind(C, name="mfree_matrix_apply")
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: A
      real(c_double), intent(in) :: x(*)
      real(c_double), intent(out) :: y(*)
    end function mfree_matrix_apply_c

    ! -- assembly
    integer(c_int) function mfree_assembler_create_c(ctx, trial, test, form, as) &
        bind(C, name="mfree_assembler_create")
      import :: c_int, c_ptr
      type(c_ptr), value :: ctx
      type(c_ptr), value :: trial
      type(c_ptr), value :: test
      integer(c_int), value :: form
      type(c_ptr), intent(out) :: as
    end function mfree_assembler_create_c

    integer(c_int) function mfree_assembler_destroy_c(as) &
        bind(C, name="mfree_assembler_destroy")
      import :: c_int, c_ptr
      type(c_ptr), intent(inout) :: as
    end function mfree_assembler_destroy_c

    integer(c_int) function mfree_assembler_set_material_c(as, young, poisson) &
        bind(C, name="mfree_assembler_set_material")
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: as
      real(c_double), value :: young
      real(c_double), value :: poisson
    end function mfree_assembler_set_material_c

    integer(c_int) function mfree_assembler_set_coefficient_c(as, c) &
        bind(C, name="mfree_assembler_set_coefficient")
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: as
      real(c_double), value :: c
    end function mfree_assembler_set_coefficient_c

    integer(c_int) function mfree_assembler_set_quadrature_nodal_c(as) &
        bind(C, name="mfree_assembler_set_quadrature_nodal")
      import :: c_int, c_ptr
      type(c_ptr), value :: as
    end function mfree_assembler_set_quadrature_nodal_c

    integer(c_int) function mfree_assembler_set_quadrature_cells_c(as, lo, hi, ncells, &
                                                                   ngauss, inside, user) &
        bind(C, name="mfree_assembler_set_quadrature_cells")
      import :: c_int, c_int32_t, c_double, c_ptr, c_funptr
      type(c_ptr), value :: as
      real(c_double), intent(in) :: lo(*)
      real(c_double), intent(in) :: hi(*)
      integer(c_int32_t), intent(in) :: ncells(*)
      integer(c_int32_t), value :: ngauss
      type(c_funptr), value :: inside
      type(c_ptr), value :: user
    end function mfree_assembler_set_quadrature_cells_c

    integer(c_int) function mfree_assembler_set_quadrature_points_c(as, npts, x, layout, &
                                                                    ld, w) &
        bind(C, name="mfree_assembler_set_quadrature_points")
      import :: c_int, c_int32_t, c_int64_t, c_double, c_ptr
      type(c_ptr), value :: as
      integer(c_int32_t), value :: npts
      real(c_double), intent(in) :: x(*)
      integer(c_int), value :: layout
      integer(c_int64_t), value :: ld
      real(c_double), intent(in) :: w(*)
    end function mfree_assembler_set_quadrature_points_c

    integer(c_int) function mfree_assembler_set_body_force_c(as, f, user) &
        bind(C, name="mfree_assembler_set_body_force")
      import :: c_int, c_ptr, c_funptr
      type(c_ptr), value :: as
      type(c_funptr), value :: f
      type(c_ptr), value :: user
    end function mfree_assembler_set_body_force_c

    integer(c_int) function mfree_assembler_add_traction_c(as, npts, x, layout, ld, w, t, &
                                                           user) &
        bind(C, name="mfree_assembler_add_traction")
      import :: c_int, c_int32_t, c_int64_t, c_double, c_ptr, c_funptr
      type(c_ptr), value :: as
      integer(c_int32_t), value :: npts
      real(c_double), intent(in) :: x(*)
      integer(c_int), value :: layout
      integer(c_int64_t), value :: ld
      real(c_double), intent(in) :: w(*)
      type(c_funptr), value :: t
      type(c_ptr), value :: user
    end function mfree_assembler_add_traction_c

    integer(c_int) function mfree_assembler_add_traction_segments_c(as, nseg, x, ngauss, t, &
                                                                    user) &
        bind(C, name="mfree_assembler_add_traction_segments")
      import :: c_int, c_int32_t, c_double, c_ptr, c_funptr
      type(c_ptr), value :: as
      integer(c_int32_t), value :: nseg
      real(c_double), intent(in) :: x(*)
      integer(c_int32_t), value :: ngauss
      type(c_funptr), value :: t
      type(c_ptr), value :: user
    end function mfree_assembler_add_traction_segments_c

    integer(c_int) function mfree_assembler_add_traction_facets_c(as, nfacet, x, ngauss, t, &
                                                                  user) &
        bind(C, name="mfree_assembler_add_traction_facets")
      import :: c_int, c_int32_t, c_double, c_ptr, c_funptr
      type(c_ptr), value :: as
      integer(c_int32_t), value :: nfacet
      real(c_double), intent(in) :: x(*)
      integer(c_int32_t), value :: ngauss
      type(c_funptr), value :: t
      type(c_ptr), value :: user
    end function mfree_assembler_add_traction_facets_c

    integer(c_int) function mfree_assembler_add_dirichlet_c(as, method, npts, x, layout, &
                                                            ld, w, normals, component_mask, &
                                                            g, user) &
        bind(C, name="mfree_assembler_add_dirichlet")
      import :: c_int, c_int32_t, c_int64_t, c_double, c_ptr, c_funptr
      type(c_ptr), value :: as
      integer(c_int), value :: method
      integer(c_int32_t), value :: npts
      real(c_double), intent(in) :: x(*)
      integer(c_int), value :: layout
      integer(c_int64_t), value :: ld
      real(c_double), intent(in) :: w(*)
      type(c_ptr), value :: normals
      integer(c_int32_t), value :: component_mask
      type(c_funptr), value :: g
      type(c_ptr), value :: user
    end function mfree_assembler_add_dirichlet_c

    integer(c_int) function mfree_assembler_add_dirichlet_nodes_c(as, nnodes, nodes, &
                                                                  component_mask, g, user) &
        bind(C, name="mfree_assembler_add_dirichlet_nodes")
      import :: c_int, c_int32_t, c_ptr, c_funptr
      type(c_ptr), value :: as
      integer(c_int32_t), value :: nnodes
      integer(c_int32_t), intent(in) :: nodes(*)
      integer(c_int32_t), value :: component_mask
      type(c_funptr), value :: g
      type(c_ptr), value :: user
    end function mfree_assembler_add_dirichlet_nodes_c

    integer(c_int) function mfree_assembler_add_traction_nodes_c(as, nnodes, nodes, &
                                                                 normals, t, user) &
        bind(C, name="mfree_assembler_add_traction_nodes")
      import :: c_int, c_int32_t, c_double, c_ptr, c_funptr
      type(c_ptr), value :: as
      integer(c_int32_t), value :: nnodes
      integer(c_int32_t), intent(in) :: nodes(*)
      real(c_double), intent(in) :: normals(*)
      type(c_funptr), value :: t
      type(c_ptr), value :: user
    end function mfree_assembler_add_traction_nodes_c

    integer(c_int) function mfree_assembler_set_fe_layer_c(as, nelem, nodes_per_element, &
                                                           connectivity, ngu, gu, &
                                                           component_mask, g, user) &
        bind(C, name="mfree_assembler_set_fe_layer")
      import :: c_int, c_int32_t, c_ptr, c_funptr
      type(c_ptr), value :: as
      integer(c_int32_t), value :: nelem
      integer(c_int32_t), value :: nodes_per_element
      integer(c_int32_t), intent(in) :: connectivity(*)
      integer(c_int32_t), value :: ngu
      integer(c_int32_t), intent(in) :: gu(*)
      integer(c_int32_t), value :: component_mask
      type(c_funptr), value :: g
      type(c_ptr), value :: user
    end function mfree_assembler_set_fe_layer_c

    integer(c_int) function mfree_assembler_set_penalty_c(as, alpha) &
        bind(C, name="mfree_assembler_set_penalty")
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: as
      real(c_double), value :: alpha
    end function mfree_assembler_set_penalty_c

    integer(c_int) function mfree_assembler_set_consistent_integration_c(as, npts, x, layout, &
                                                                         ld, w, normals) &
        bind(C, name="mfree_assembler_set_consistent_integration")
      import :: c_int, c_int32_t, c_int64_t, c_double, c_ptr
      type(c_ptr), value :: as
      integer(c_int32_t), value :: npts
      real(c_double), intent(in) :: x(*)
      integer(c_int), value :: layout
      integer(c_int64_t), value :: ld
      real(c_double), intent(in) :: w(*), normals(*)
    end function mfree_assembler_set_consistent_integration_c

    integer(c_int) function mfree_assembler_setup_c(as) &
        bind(C, name="mfree_assembler_setup")
      import :: c_int, c_ptr
      type(c_ptr), value :: as
    end function mfree_assembler_setup_c

    integer(c_int) function mfree_assembler_update_c(as) &
        bind(C, name="mfree_assembler_update")
      import :: c_int, c_ptr
      type(c_ptr), value :: as
    end function mfree_assembler_update_c

    integer(c_int) function mfree_assembler_get_size_c(as, ndofs, nquad) &
        bind(C, name="mfree_assembler_get_size")
      import :: c_int, c_ptr
      type(c_ptr), value :: as
      type(c_ptr), value :: ndofs
      type(c_ptr), value :: nquad
    end function mfree_assembler_get_size_c

    integer(c_int) function mfree_assembler_assemble_matrix_c(as, K) &
        bind(C, name="mfree_assembler_assemble_matrix")
      import :: c_int, c_ptr
      type(c_ptr), value :: as
      type(c_ptr), intent(inout) :: K
    end function mfree_assembler_assemble_matrix_c

    integer(c_int) function mfree_assembler_assemble_rhs_c(as, f) &
        bind(C, name="mfree_assembler_assemble_rhs")
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: as
      real(c_double), intent(out) :: f(*)
    end function mfree_assembler_assemble_rhs_c

    ! -- semi-discrete particle systems
    integer(c_int) function mfree_system_create_fluid_c(ctx, dim, n, sys) &
        bind(C, name="mfree_system_create_fluid")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: ctx
      integer(c_int32_t), value :: dim
      integer(c_int32_t), value :: n
      type(c_ptr), intent(out) :: sys
    end function mfree_system_create_fluid_c

    integer(c_int) function mfree_system_destroy_c(sys) &
        bind(C, name="mfree_system_destroy")
      import :: c_int, c_ptr
      type(c_ptr), intent(inout) :: sys
    end function mfree_system_destroy_c

    integer(c_int) function mfree_system_set_fluid_c(sys, rho0, stride, kappa, gamma, mu) &
        bind(C, name="mfree_system_set_fluid")
      import :: c_int, c_int64_t, c_double, c_ptr
      type(c_ptr), value :: sys
      real(c_double), intent(in) :: rho0(*)
      integer(c_int64_t), value :: stride
      real(c_double), value :: kappa
      real(c_double), value :: gamma
      real(c_double), value :: mu
    end function mfree_system_set_fluid_c

    integer(c_int) function mfree_system_set_masses_c(sys, m, stride) &
        bind(C, name="mfree_system_set_masses")
      import :: c_int, c_int64_t, c_double, c_ptr
      type(c_ptr), value :: sys
      real(c_double), intent(in) :: m(*)
      integer(c_int64_t), value :: stride
    end function mfree_system_set_masses_c

    integer(c_int) function mfree_system_set_smoothing_c(sys, h) &
        bind(C, name="mfree_system_set_smoothing")
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: sys
      real(c_double), value :: h
    end function mfree_system_set_smoothing_c

    integer(c_int) function mfree_system_set_gravity_c(sys, g) &
        bind(C, name="mfree_system_set_gravity")
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: sys
      real(c_double), intent(in) :: g(*)
    end function mfree_system_set_gravity_c

    integer(c_int) function mfree_system_set_lumping_c(sys, lump) &
        bind(C, name="mfree_system_set_lumping")
      import :: c_int, c_ptr
      type(c_ptr), value :: sys
      integer(c_int), value :: lump
    end function mfree_system_set_lumping_c

    integer(c_int) function mfree_system_set_walls_c(sys, nwall, x, normals, r0, strength) &
        bind(C, name="mfree_system_set_walls")
      import :: c_int, c_int32_t, c_double, c_ptr
      type(c_ptr), value :: sys
      integer(c_int32_t), value :: nwall
      real(c_double), intent(in) :: x(*)
      real(c_double), intent(in) :: normals(*)
      real(c_double), value :: r0
      real(c_double), value :: strength
    end function mfree_system_set_walls_c

    integer(c_int) function mfree_system_set_dummy_particles_c(sys, n, x, volumes, stride) &
        bind(C, name="mfree_system_set_dummy_particles")
      import :: c_int, c_int32_t, c_int64_t, c_double, c_ptr
      type(c_ptr), value :: sys
      integer(c_int32_t), value :: n
      real(c_double), intent(in) :: x(*)
      real(c_double), intent(in) :: volumes(*)
      integer(c_int64_t), value :: stride
    end function mfree_system_set_dummy_particles_c

    integer(c_int) function mfree_system_set_density_diffusion_c(sys, delta) &
        bind(C, name="mfree_system_set_density_diffusion")
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: sys
      real(c_double), value :: delta
    end function mfree_system_set_density_diffusion_c

    integer(c_int) function mfree_system_set_consistent_integration_c(sys, on) &
        bind(C, name="mfree_system_set_consistent_integration")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: sys
      integer(c_int32_t), value :: on
    end function mfree_system_set_consistent_integration_c

    integer(c_int) function mfree_system_set_velocity_smoothing_c(sys, beta) &
        bind(C, name="mfree_system_set_velocity_smoothing")
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: sys
      real(c_double), value :: beta
    end function mfree_system_set_velocity_smoothing_c

    integer(c_int) function mfree_system_set_lumped_mass_step_c(sys, on) &
        bind(C, name="mfree_system_set_lumped_mass_step")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: sys
      integer(c_int32_t), value :: on
    end function mfree_system_set_lumped_mass_step_c

    integer(c_int) function mfree_system_set_acoustic_step_c(sys, on) &
        bind(C, name="mfree_system_set_acoustic_step")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: sys
      integer(c_int32_t), value :: on
    end function mfree_system_set_acoustic_step_c

    integer(c_int) function mfree_system_set_box_c(sys, lo, hi) &
        bind(C, name="mfree_system_set_box")
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: sys
      real(c_double), intent(in) :: lo(*)
      real(c_double), intent(in) :: hi(*)
    end function mfree_system_set_box_c

    integer(c_int) function mfree_system_get_size_c(sys, neq) &
        bind(C, name="mfree_system_get_size")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: sys
      integer(c_int32_t), intent(out) :: neq
    end function mfree_system_get_size_c

    integer(c_int) function mfree_system_rhs_c(sys, t, y, ydot) &
        bind(C, name="mfree_system_rhs")
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: sys
      real(c_double), value :: t
      real(c_double), intent(in) :: y(*)
      real(c_double), intent(out) :: ydot(*)
    end function mfree_system_rhs_c

    integer(c_int) function mfree_system_assemble_mass_c(sys, y, consistent, M) &
        bind(C, name="mfree_system_assemble_mass")
      import :: c_int, c_int32_t, c_double, c_ptr
      type(c_ptr), value :: sys
      real(c_double), intent(in) :: y(*)
      integer(c_int32_t), value :: consistent
      type(c_ptr), intent(inout) :: M
    end function mfree_system_assemble_mass_c

    integer(c_int) function mfree_system_assemble_interpolation_c(sys, y, S) &
        bind(C, name="mfree_system_assemble_interpolation")
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: sys
      real(c_double), intent(in) :: y(*)
      type(c_ptr), intent(inout) :: S
    end function mfree_system_assemble_interpolation_c

    integer(c_int) function mfree_system_apply_mass_c(sys, y, consistent, v, Mv) &
        bind(C, name="mfree_system_apply_mass")
      import :: c_int, c_int32_t, c_double, c_ptr
      type(c_ptr), value :: sys
      real(c_double), intent(in) :: y(*)
      integer(c_int32_t), value :: consistent
      real(c_double), intent(in) :: v(*)
      real(c_double), intent(out) :: Mv(*)
    end function mfree_system_apply_mass_c

    integer(c_int) function mfree_system_get_pressure_c(sys, y, p) &
        bind(C, name="mfree_system_get_pressure")
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: sys
      real(c_double), intent(in) :: y(*)
      real(c_double), intent(out) :: p(*)
    end function mfree_system_get_pressure_c

    integer(c_int) function mfree_system_get_velocity_c(sys, y, vhat) &
        bind(C, name="mfree_system_get_velocity")
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: sys
      real(c_double), intent(in) :: y(*)
      real(c_double), intent(out) :: vhat(*)
    end function mfree_system_get_velocity_c

    integer(c_int) function mfree_system_get_wall_force_c(sys, y, total, nwall, per_wall) &
        bind(C, name="mfree_system_get_wall_force")
      import :: c_int, c_int32_t, c_double, c_ptr
      type(c_ptr), value :: sys
      real(c_double), intent(in) :: y(*)
      type(c_ptr), value :: total
      integer(c_int32_t), value :: nwall
      type(c_ptr), value :: per_wall
    end function mfree_system_get_wall_force_c

    integer(c_int) function mfree_system_set_active_c(sys, nactive) &
        bind(C, name="mfree_system_set_active")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: sys
      integer(c_int32_t), value :: nactive
    end function mfree_system_set_active_c

    integer(c_int) function mfree_system_set_inflow_c(sys, gate, origin, edges, normal, speed, &
                                                      density, spacing) &
        bind(C, name="mfree_system_set_inflow")
      import :: c_int, c_int32_t, c_double, c_ptr
      type(c_ptr), value :: sys
      integer(c_int32_t), value :: gate
      real(c_double), intent(in) :: origin(*), edges(*), normal(*)
      real(c_double), value :: speed, density, spacing
    end function mfree_system_set_inflow_c

    integer(c_int) function mfree_system_set_outflow_c(sys, k, point, normal) &
        bind(C, name="mfree_system_set_outflow")
      import :: c_int, c_int32_t, c_double, c_ptr
      type(c_ptr), value :: sys
      integer(c_int32_t), value :: k
      real(c_double), intent(in) :: point(*), normal(*)
    end function mfree_system_set_outflow_c

    integer(c_int) function mfree_system_update_open_boundaries_c(sys, t, y) &
        bind(C, name="mfree_system_update_open_boundaries")
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: sys
      real(c_double), value :: t
      real(c_double), intent(inout) :: y(*)
    end function mfree_system_update_open_boundaries_c

    integer(c_int) function mfree_system_get_active_c(sys, nactive, n, state) &
        bind(C, name="mfree_system_get_active")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: sys
      integer(c_int32_t), intent(out) :: nactive
      integer(c_int32_t), value :: n
      type(c_ptr), value :: state
    end function mfree_system_get_active_c

    integer(c_int) function mfree_system_get_inflow_c(sys, gate, count, mass) &
        bind(C, name="mfree_system_get_inflow")
      import :: c_int, c_int32_t, c_int64_t, c_double, c_ptr
      type(c_ptr), value :: sys
      integer(c_int32_t), value :: gate
      integer(c_int64_t), intent(out) :: count
      real(c_double), intent(out) :: mass
    end function mfree_system_get_inflow_c

    integer(c_int) function mfree_system_get_outflow_c(sys, k, count, mass) &
        bind(C, name="mfree_system_get_outflow")
      import :: c_int, c_int32_t, c_int64_t, c_double, c_ptr
      type(c_ptr), value :: sys
      integer(c_int32_t), value :: k
      integer(c_int64_t), intent(out) :: count
      real(c_double), intent(out) :: mass
    end function mfree_system_get_outflow_c

    integer(c_int) function mfree_system_integrate_c(sys, scheme, y, t, t_end, cfl, dt_max, &
                                                     progress, user, nsteps) &
        bind(C, name="mfree_system_integrate")
      import :: c_int, c_double, c_ptr, c_funptr
      type(c_ptr), value :: sys
      integer(c_int), value :: scheme
      real(c_double), intent(inout) :: y(*)
      real(c_double), intent(inout) :: t
      real(c_double), value :: t_end
      real(c_double), value :: cfl
      real(c_double), value :: dt_max
      type(c_funptr), value :: progress
      type(c_ptr), value :: user
      type(c_ptr), value :: nsteps
    end function mfree_system_integrate_c

    integer(c_int) function mfree_system_set_shepard_condition_c(sys, max_cond) &
        bind(C, name="mfree_system_set_shepard_condition")
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: sys
      real(c_double), value :: max_cond
    end function mfree_system_set_shepard_condition_c

    integer(c_int) function mfree_system_set_approximation_c(sys, method, order, kernel, param) &
        bind(C, name="mfree_system_set_approximation")
      import :: c_int, c_int32_t, c_double, c_ptr
      type(c_ptr), value :: sys
      integer(c_int), value :: method
      integer(c_int32_t), value :: order
      integer(c_int), value :: kernel
      real(c_double), value :: param
    end function mfree_system_set_approximation_c

    integer(c_int) function mfree_system_create_elastodynamic_c(ctx, as, density, sys) &
        bind(C, name="mfree_system_create_elastodynamic")
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: ctx
      type(c_ptr), value :: as
      real(c_double), value :: density
      type(c_ptr), intent(out) :: sys
    end function mfree_system_create_elastodynamic_c

    integer(c_int) function mfree_system_create_elastodynamic_galerkin_c(ctx, stiffness, mass, sys) &
        bind(C, name="mfree_system_create_elastodynamic_galerkin")
      import :: c_int, c_ptr
      type(c_ptr), value :: ctx
      type(c_ptr), value :: stiffness
      type(c_ptr), value :: mass
      type(c_ptr), intent(out) :: sys
    end function mfree_system_create_elastodynamic_galerkin_c

    integer(c_int) function mfree_system_set_load_history_c(sys, g, user) &
        bind(C, name="mfree_system_set_load_history")
      import :: c_int, c_ptr, c_funptr
      type(c_ptr), value :: sys
      type(c_funptr), value :: g
      type(c_ptr), value :: user
    end function mfree_system_set_load_history_c

    ! (exchange, allgather: bind(C) functions of the interfaces mfree_exchange_fn and
    ! mfree_allgather_fn of mfree.h, passed with c_funloc; libmfree_mpi supplies both)
    integer(c_int) function mfree_system_create_elastodynamic_ranks_c(ctx, as, density, exchange, &
        allgather, user, sys) bind(C, name="mfree_system_create_elastodynamic_ranks")
      import :: c_int, c_double, c_ptr, c_funptr
      type(c_ptr), value :: ctx
      type(c_ptr), value :: as
      real(c_double), value :: density
      type(c_funptr), value :: exchange
      type(c_funptr), value :: allgather
      type(c_ptr), value :: user
      type(c_ptr), intent(out) :: sys
    end function mfree_system_create_elastodynamic_ranks_c

    integer(c_int) function mfree_system_create_fluid_ranks_c(ctx, dim, n_owned, n_ghost, global_ids, &
        width, exchange, allgather, user, sys) bind(C, name="mfree_system_create_fluid_ranks")
      import :: c_int, c_int32_t, c_int64_t, c_double, c_ptr, c_funptr
      type(c_ptr), value :: ctx
      integer(c_int32_t), value :: dim
      integer(c_int32_t), value :: n_owned
      integer(c_int32_t), value :: n_ghost
      integer(c_int64_t), intent(in) :: global_ids(*)
      real(c_double), value :: width
      type(c_funptr), value :: exchange
      type(c_funptr), value :: allgather
      type(c_ptr), value :: user
      type(c_ptr), intent(out) :: sys
    end function mfree_system_create_fluid_ranks_c

    integer(c_int) function mfree_system_set_halo_rebuild_c(sys, rebuild) &
        bind(C, name="mfree_system_set_halo_rebuild")
      import :: c_int, c_ptr, c_funptr
      type(c_ptr), value :: sys
      type(c_funptr), value :: rebuild
    end function mfree_system_set_halo_rebuild_c

    integer(c_int) function mfree_system_move_particles_c(sys, n_new, move, move_user, y, capacity) &
        bind(C, name="mfree_system_move_particles")
      import :: c_int, c_int32_t, c_int64_t, c_double, c_ptr, c_funptr
      type(c_ptr), value :: sys
      integer(c_int32_t), value :: n_new
      type(c_funptr), value :: move
      type(c_ptr), value :: move_user
      real(c_double), intent(inout) :: y(*)
      integer(c_int64_t), value :: capacity
    end function mfree_system_move_particles_c

    integer(c_int) function mfree_system_get_stress_c(sys, t, y, sigma) &
        bind(C, name="mfree_system_get_stress")
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: sys
      real(c_double), value :: t
      real(c_double), intent(in) :: y(*)
      real(c_double), intent(out) :: sigma(*)
    end function mfree_system_get_stress_c

    ! -- C library (private): length of a NUL-terminated string
    integer(c_size_t) function strlen_c(s) bind(C, name="strlen")
      import :: c_size_t, c_ptr
      type(c_ptr), value :: s
    end function strlen_c
  end interface
  public :: mfree_version_string_c, mfree_version_get_c, mfree_status_string_c
  public :: mfree_context_create_c, mfree_context_destroy_c
  public :: mfree_context_get_last_error_c, mfree_context_set_error_c
  public :: mfree_context_set_error_handler_c, mfree_context_set_num_threads_c
  public :: mfree_context_get_num_threads_c, mfree_kernel_eval_c
  public :: mfree_context_set_backend_c, mfree_context_get_backend_c
  public :: mfree_context_set_page_hints_c, mfree_context_get_page_hints_c
  public :: mfree_context_set_allocator_c
  public :: mfree_kernel_get_support_radius_c, mfree_kernel_get_normalization_c
  public :: mfree_particles_create_c, mfree_particles_destroy_c
  public :: mfree_particles_set_num_ghost_c, mfree_particles_set_positions_c
  public :: mfree_particles_set_volumes_c, mfree_particles_set_masses_c
  public :: mfree_particles_set_densities_c, mfree_particles_set_support_c
  public :: mfree_particles_set_search_c, mfree_particles_set_periodic_c
  public :: mfree_particles_set_neighbors_c, mfree_particles_setup_c
  public :: mfree_particles_set_global_ids_c, mfree_particles_get_global_ids_c
  public :: mfree_particles_set_halo_width_c
  public :: mfree_particles_set_search_skin_c, mfree_particles_get_search_count_c
  public :: mfree_particles_update_c, mfree_particles_get_dimension_c
  public :: mfree_particles_get_size_c, mfree_particles_get_neighbor_nnz_c
  public :: mfree_particles_get_neighbors_c, mfree_particles_get_volumes_c
  public :: mfree_particles_get_site_status_c, mfree_approximant_create_c
  public :: mfree_particles_set_pairs_c, mfree_particles_get_num_pairs_c
  public :: mfree_approximant_get_pair_gradients_c
  public :: mfree_approximant_get_pair_gradients_antisymmetric_c
  public :: mfree_approximant_get_correction_size_c, mfree_approximant_get_correction_c
  public :: mfree_approximant_set_ghost_correction_c
  public :: mfree_particles_get_context_c, mfree_approximant_get_context_c
  public :: mfree_mesh_get_context_c, mfree_matrix_get_context_c
  public :: mfree_assembler_get_context_c, mfree_system_get_context_c
  public :: mfree_system_set_pending_error_c
  public :: mfree_approximant_get_particles_c, mfree_mesh_get_particles_c
  public :: mfree_system_get_dimension_c
  public :: mfree_approximant_destroy_c, mfree_approximant_set_kernel_c
  public :: mfree_approximant_set_order_c, mfree_approximant_set_derivatives_c
  public :: mfree_approximant_set_fallback_c, mfree_approximant_set_points_c
  public :: mfree_approximant_setup_c, mfree_approximant_update_c
  public :: mfree_approximant_apply_c, mfree_approximant_apply_add_c
  public :: mfree_approximant_get_num_sites_c, mfree_approximant_get_nnz_c
  public :: mfree_approximant_assemble_csr_c, mfree_approximant_check_reproduction_c
  public :: mfree_approximant_get_site_status_c, mfree_approximant_get_neighbor_counts_c
  public :: mfree_approximant_get_condition_c, mfree_approximant_get_site_order_c
  public :: mfree_mesh_create_c, mfree_mesh_destroy_c, mfree_mesh_add_elements_c
  public :: mfree_mesh_setup_c, mfree_mesh_get_size_c, mfree_mesh_get_quadrature_c
  public :: mfree_approximant_set_mesh_c, mfree_approximant_set_mpfem_c
  public :: mfree_matrix_create_csr_c, mfree_matrix_destroy_c, mfree_matrix_get_size_c
  public :: mfree_matrix_get_csr_c, mfree_matrix_get_csr_i32_c, mfree_matrix_get_csr_i64_c
  public :: mfree_matrix_get_csc_c, mfree_matrix_get_pattern_id_c
  public :: mfree_matrix_get_symmetric_c, mfree_matrix_apply_c, mfree_assembler_create_c
  public :: mfree_assembler_destroy_c, mfree_assembler_set_material_c
  public :: mfree_assembler_set_coefficient_c, mfree_assembler_set_quadrature_nodal_c
  public :: mfree_assembler_set_quadrature_cells_c
  public :: mfree_assembler_set_quadrature_points_c, mfree_assembler_set_body_force_c
  public :: mfree_assembler_add_traction_c, mfree_assembler_add_traction_segments_c
  public :: mfree_assembler_add_traction_facets_c
  public :: mfree_assembler_add_dirichlet_c, mfree_assembler_add_dirichlet_nodes_c
  public :: mfree_assembler_add_traction_nodes_c, mfree_assembler_set_fe_layer_c
  public :: mfree_assembler_set_penalty_c, mfree_assembler_setup_c
  public :: mfree_assembler_set_consistent_integration_c
  public :: mfree_assembler_update_c, mfree_assembler_get_size_c
  public :: mfree_assembler_assemble_matrix_c, mfree_assembler_assemble_rhs_c
  public :: mfree_system_create_fluid_c, mfree_system_destroy_c, mfree_system_set_fluid_c
  public :: mfree_system_set_masses_c, mfree_system_set_smoothing_c
  public :: mfree_system_set_gravity_c, mfree_system_set_lumping_c
  public :: mfree_system_set_walls_c, mfree_system_set_box_c, mfree_system_get_size_c
  public :: mfree_system_set_dummy_particles_c, mfree_system_set_density_diffusion_c
  public :: mfree_system_set_consistent_integration_c, mfree_system_set_velocity_smoothing_c
  public :: mfree_system_set_lumped_mass_step_c
  public :: mfree_system_set_acoustic_step_c
  public :: mfree_system_rhs_c, mfree_system_assemble_mass_c
  public :: mfree_system_assemble_interpolation_c, mfree_system_get_pressure_c
  public :: mfree_system_apply_mass_c
  public :: mfree_system_get_velocity_c, mfree_system_integrate_c
  public :: mfree_system_get_wall_force_c
  public :: mfree_system_set_active_c, mfree_system_set_inflow_c, mfree_system_set_outflow_c
  public :: mfree_system_update_open_boundaries_c, mfree_system_get_active_c
  public :: mfree_system_get_inflow_c, mfree_system_get_outflow_c
  public :: mfree_system_create_elastodynamic_c, mfree_system_set_load_history_c
  public :: mfree_system_create_elastodynamic_galerkin_c
  public :: mfree_system_create_elastodynamic_ranks_c
  public :: mfree_system_create_elastodynamic_ranks
  public :: mfree_system_create_fluid_ranks_c, mfree_system_create_fluid_ranks
  public :: mfree_system_set_halo_rebuild_c, mfree_system_set_halo_rebuild
  public :: mfree_system_move_particles_c, mfree_system_move_particles
  public :: mfree_system_set_shepard_condition_c
  public :: mfree_system_set_approximation_c
  public :: mfree_system_get_stress_c

  ! ---- generic wrappers: strides, leading dimensions and counts of either integer kind
  ! (c_int64_t, or a legacy code's default integers); arrays of any rank; per-particle
  ! scalars as an array, or one value with stride 0
  interface mfree_particles_set_positions
    module procedure mfree_particles_set_positions_i64, mfree_particles_set_positions_i32
  end interface mfree_particles_set_positions
  interface mfree_particles_set_volumes
    module procedure mfree_particles_set_volumes_i64, mfree_particles_set_volumes_i32
  end interface mfree_particles_set_volumes
  interface mfree_particles_set_masses
    module procedure mfree_particles_set_masses_i64, mfree_particles_set_masses_i32
  end interface mfree_particles_set_masses
  interface mfree_particles_set_densities
    module procedure mfree_particles_set_densities_i64, mfree_particles_set_densities_i32
  end interface mfree_particles_set_densities
  interface mfree_particles_set_support
    module procedure mfree_particles_set_support_i64, mfree_particles_set_support_i32
  end interface mfree_particles_set_support
  interface mfree_particles_set_neighbors
    module procedure mfree_particles_set_neighbors_i64, mfree_particles_set_neighbors_i32
  end interface mfree_particles_set_neighbors
  interface mfree_particles_set_pairs
    module procedure mfree_particles_set_pairs_i64, mfree_particles_set_pairs_i32
  end interface mfree_particles_set_pairs
  interface mfree_approximant_set_points
    module procedure mfree_approximant_set_points_i64, mfree_approximant_set_points_i32
  end interface mfree_approximant_set_points
  interface mfree_approximant_apply
    module procedure mfree_approximant_apply_i64, mfree_approximant_apply_i32
  end interface mfree_approximant_apply
  interface mfree_approximant_apply_add
    module procedure mfree_approximant_apply_add_i64, mfree_approximant_apply_add_i32
  end interface mfree_approximant_apply_add
  interface mfree_kernel_eval
    module procedure mfree_kernel_eval_i64, mfree_kernel_eval_i32
  end interface mfree_kernel_eval
  interface mfree_system_set_fluid
    module procedure mfree_system_set_fluid_array, mfree_system_set_fluid_scalar
  end interface mfree_system_set_fluid
  interface mfree_system_set_masses
    module procedure mfree_system_set_masses_array, mfree_system_set_masses_scalar
  end interface mfree_system_set_masses

  ! ---- typed wrappers (C names) and helpers -----------------------------------------
  public :: mfree_version_string, mfree_version_get, mfree_status_string
  public :: mfree_version_ge, mfree_version_check, mfree_c_string, mfree_last_error
  public :: mfree_context_create, mfree_context_destroy, mfree_context_get_last_error
  public :: mfree_context_set_error, mfree_context_set_error_handler
  public :: mfree_context_set_num_threads, mfree_context_get_num_threads
  public :: mfree_context_set_backend, mfree_context_get_backend
  public :: mfree_context_set_page_hints, mfree_context_get_page_hints
  public :: mfree_context_set_allocator
  public :: mfree_kernel_eval, mfree_kernel_get_support_radius
  public :: mfree_kernel_get_normalization
  public :: mfree_particles_create, mfree_particles_destroy, mfree_particles_set_num_ghost
  public :: mfree_particles_set_positions, mfree_particles_set_volumes
  public :: mfree_particles_set_masses, mfree_particles_set_densities
  public :: mfree_particles_set_support, mfree_particles_set_search
  public :: mfree_particles_set_periodic, mfree_particles_set_neighbors
  public :: mfree_particles_set_global_ids, mfree_particles_get_global_ids
  public :: mfree_particles_set_halo_width
  public :: mfree_particles_set_search_skin, mfree_particles_get_search_count
  public :: mfree_particles_setup, mfree_particles_update, mfree_particles_get_dimension
  public :: mfree_particles_get_size, mfree_particles_get_neighbor_nnz
  public :: mfree_particles_get_neighbors, mfree_particles_get_volumes
  public :: mfree_particles_get_site_status
  public :: mfree_particles_set_pairs, mfree_particles_get_num_pairs
  public :: mfree_approximant_get_pair_gradients
  public :: mfree_approximant_get_pair_gradients_antisymmetric
  public :: mfree_approximant_get_correction_size, mfree_approximant_get_correction
  public :: mfree_approximant_set_ghost_correction
  public :: mfree_particles_get_context, mfree_approximant_get_context
  public :: mfree_mesh_get_context, mfree_matrix_get_context
  public :: mfree_assembler_get_context, mfree_system_get_context
  public :: mfree_system_set_pending_error
  public :: mfree_approximant_get_particles, mfree_mesh_get_particles
  public :: mfree_system_get_dimension
  public :: mfree_approximant_create, mfree_approximant_destroy
  public :: mfree_approximant_set_kernel, mfree_approximant_set_order
  public :: mfree_approximant_set_derivatives, mfree_approximant_set_fallback
  public :: mfree_approximant_set_points, mfree_approximant_setup, mfree_approximant_update
  public :: mfree_approximant_apply, mfree_approximant_apply_add
  public :: mfree_approximant_get_num_sites, mfree_approximant_get_nnz
  public :: mfree_approximant_assemble_csr, mfree_approximant_check_reproduction
  public :: mfree_approximant_get_site_status, mfree_approximant_get_neighbor_counts
  public :: mfree_approximant_get_condition, mfree_approximant_get_site_order
  public :: mfree_mesh_create, mfree_mesh_destroy, mfree_mesh_add_elements
  public :: mfree_mesh_setup, mfree_mesh_get_size, mfree_mesh_get_quadrature
  public :: mfree_approximant_set_mesh, mfree_approximant_set_mpfem
  public :: mfree_matrix_create_csr, mfree_matrix_destroy, mfree_matrix_get_size
  public :: mfree_matrix_get_csr, mfree_matrix_get_csr_i32, mfree_matrix_get_csr_i64
  public :: mfree_matrix_get_csc, mfree_matrix_get_pattern_id, mfree_matrix_get_symmetric
  public :: mfree_matrix_apply
  public :: mfree_assembler_create, mfree_assembler_destroy, mfree_assembler_set_material
  public :: mfree_assembler_set_coefficient, mfree_assembler_set_quadrature_nodal
  public :: mfree_assembler_set_quadrature_cells, mfree_assembler_set_quadrature_points
  public :: mfree_assembler_set_body_force, mfree_assembler_add_traction
  public :: mfree_assembler_add_traction_segments, mfree_assembler_add_dirichlet
  public :: mfree_assembler_add_traction_facets
  public :: mfree_assembler_add_dirichlet_nodes, mfree_assembler_add_traction_nodes
  public :: mfree_assembler_set_fe_layer, mfree_assembler_set_penalty
  public :: mfree_assembler_set_consistent_integration
  public :: mfree_assembler_setup, mfree_assembler_update, mfree_assembler_get_size
  public :: mfree_assembler_assemble_matrix, mfree_assembler_assemble_rhs
  public :: mfree_system_create_fluid, mfree_system_destroy, mfree_system_set_fluid
  public :: mfree_system_set_masses, mfree_system_set_smoothing, mfree_system_set_gravity
  public :: mfree_system_set_lumping, mfree_system_set_walls, mfree_system_set_box
  public :: mfree_system_set_dummy_particles, mfree_system_set_density_diffusion
  public :: mfree_system_set_consistent_integration, mfree_system_set_velocity_smoothing
  public :: mfree_system_set_lumped_mass_step
  public :: mfree_system_set_acoustic_step
  public :: mfree_system_get_size, mfree_system_rhs, mfree_system_assemble_mass
  public :: mfree_system_assemble_interpolation, mfree_system_get_pressure
  public :: mfree_system_apply_mass
  public :: mfree_system_get_velocity, mfree_system_integrate
  public :: mfree_system_get_wall_force
  public :: mfree_system_set_active, mfree_system_set_inflow, mfree_system_set_outflow
  public :: mfree_system_update_open_boundaries, mfree_system_get_active
  public :: mfree_system_get_inflow, mfree_system_get_outflow
  public :: mfree_system_create_elastodynamic, mfree_system_set_load_history
  public :: mfree_system_create_elastodynamic_galerkin
  public :: mfree_system_set_shepard_condition
  public :: mfree_system_set_approximation
  public :: mfree_system_get_stress

  ! Targets of zero-length matrix views (a C view of an empty array may be NULL).
  integer(c_int64_t), target, save :: empty_i64(0)
  integer(c_int32_t), target, save :: empty_i32(0)
  real(c_double), target, save :: empty_dbl(0)

  ! The wrappers' argument checks (check_out, view_dbl below), for the adapter modules
  ! (mfree_mpi), which check their arrays the same way; not meant for hosts. Generic
  ! names with the mfree_ prefix, so that a host's own check_out does not clash.
  interface mfree_wrapper_check_out
    module procedure check_out
  end interface mfree_wrapper_check_out
  interface mfree_wrapper_view_dbl
    module procedure view_dbl
  end interface mfree_wrapper_view_dbl
  public :: mfree_wrapper_check_out, mfree_wrapper_view_dbl

contains

  ! ==== helpers ========================================================================

  !> A Fortran copy of a NUL-terminated C string ('' for NULL), e.g. the message an
  !> error handler receives or what mfree_version_string_c returns.
  function mfree_c_string(p) result(s)
    type(c_ptr), intent(in) :: p
    character(len=:), allocatable :: s
    character(kind=c_char), pointer :: chars(:)
    integer(c_size_t) :: n
    integer :: i
    if (.not. c_associated(p)) then
      s = ''
      return
    end if
    n = strlen_c(p)
    call c_f_pointer(p, chars, [n])
    allocate (character(len=int(n)) :: s)
    do i = 1, int(n)
      s(i:i) = chars(i)
    end do
  end function mfree_c_string

  !> The characters of buf before its first NUL.
  function from_c_chars(buf) result(s)
    character(kind=c_char), intent(in) :: buf(:)
    character(len=:), allocatable :: s
    integer :: i, n
    n = size(buf)
    do i = 1, size(buf)
      if (buf(i) == c_null_char) then
        n = i - 1
        exit
      end if
    end do
    allocate (character(len=n) :: s)
    do i = 1, n
      s(i:i) = buf(i)
    end do
  end function from_c_chars

  !> A NUL-terminated copy of a Fortran string (trailing blanks kept).
  subroutine to_c_chars(s, buf)
    character(len=*), intent(in) :: s
    character(kind=c_char), allocatable, intent(out) :: buf(:)
    integer :: i
    allocate (buf(len(s) + 1))
    do i = 1, len(s)
      buf(i) = s(i:i)
    end do
    buf(len(s) + 1) = c_null_char
  end subroutine to_c_chars

  ! ==== argument checks of the wrappers =================================================
  ! Every wrapper that writes into a caller array checks it first: contiguous, and large
  ! enough for what mfree will write (else MFREE_ERR_ARG, recorded on the object's
  ! context like mfree's own failures, and nothing is written). Borrowed inputs must be
  ! contiguous (a section would be passed as a temporary that dies with the call);
  ! copied ones may be sections (they are packed here first).

  !> Record a failure a wrapper found before calling mfree on context ctx and return its
  !> code (MFREE_ERR_NULL when there is no context: a NULL handle).
  integer(c_int) function wrapper_error(ctx, code, message) result(st)
    type(c_ptr), intent(in) :: ctx
    integer(c_int), intent(in) :: code
    character(len=*), intent(in) :: message
    character(kind=c_char), allocatable, target :: buf(:)
    st = MFREE_ERR_NULL
    if (.not. c_associated(ctx)) return
    call to_c_chars(message, buf)
    st = mfree_context_set_error_c(ctx, code, c_loc(buf))
  end function wrapper_error

  !> A 64-bit integer as text.
  function int_str(i) result(s)
    integer(c_int64_t), intent(in) :: i
    character(len=:), allocatable :: s
    character(len=24) :: b
    write (b, '(i0)') i
    s = trim(b)
  end function int_str

  !> MFREE_SUCCESS when an output array (contiguous: is_contiguous, have elements) can
  !> take need elements; else MFREE_ERR_ARG recorded on ctx.
  integer(c_int) function check_out(ctx, fn, what, contig, have, need) result(st)
    type(c_ptr), intent(in) :: ctx
    character(len=*), intent(in) :: fn, what
    logical, intent(in) :: contig
    integer(c_int64_t), intent(in) :: have, need
    st = MFREE_SUCCESS
    if (.not. contig) then
      st = wrapper_error(ctx, MFREE_ERR_ARG, fn // ': ' // what // &
                         ' is not contiguous (a strided section?): mfree writes it as one block')
    else if (have < need) then
      st = wrapper_error(ctx, MFREE_ERR_ARG, fn // ': ' // what // ' holds ' // &
                         int_str(have) // ' elements, ' // int_str(need) // ' are needed')
    end if
  end function check_out

  !> MFREE_SUCCESS unless a non-contiguous array is to be borrowed (MFREE_ERR_ARG).
  integer(c_int) function check_borrow(ctx, fn, what, contig, mem) result(st)
    type(c_ptr), intent(in) :: ctx
    character(len=*), intent(in) :: fn, what
    logical, intent(in) :: contig
    integer(c_int), intent(in) :: mem
    st = MFREE_SUCCESS
    if (mem == MFREE_BORROW .and. .not. contig) &
      st = wrapper_error(ctx, MFREE_ERR_ARG, fn // ': ' // what // &
                         ' is not contiguous and cannot be borrowed (its temporary copy would die' // &
                         ' with the call): pass a whole contiguous array, or MFREE_COPY')
  end function check_borrow

  ! A rank-1 view of an array of any rank: the array itself when contiguous, else a packed
  ! copy in tmp (for copied inputs); empty arrays view a static empty array.
  !> A rank-1 view of a real array of any rank (packed into tmp when not contiguous).
  subroutine view_dbl(x, tmp, p)
    real(c_double), intent(in), target :: x(..)
    real(c_double), allocatable, target, intent(inout) :: tmp(:)
    real(c_double), pointer, intent(out) :: p(:)
    if (size(x) == 0) then
      p => empty_dbl
    else if (is_contiguous(x)) then
      call c_f_pointer(c_loc(x), p, [size(x)])
    else
      select rank (x)
      rank (0)
        tmp = [x]
      rank (1)
        tmp = x
      rank (2)
        tmp = reshape(x, [size(x)])
      rank (3)
        tmp = reshape(x, [size(x)])
      end select
      p => tmp
    end if
  end subroutine view_dbl

  !> A rank-1 view of an integer array of any rank (packed into tmp when not contiguous).
  subroutine view_i32(x, tmp, p)
    integer(c_int32_t), intent(in), target :: x(..)
    integer(c_int32_t), allocatable, target, intent(inout) :: tmp(:)
    integer(c_int32_t), pointer, intent(out) :: p(:)
    if (size(x) == 0) then
      p => empty_i32
    else if (is_contiguous(x)) then
      call c_f_pointer(c_loc(x), p, [size(x)])
    else
      select rank (x)
      rank (0)
        tmp = [x]
      rank (1)
        tmp = x
      rank (2)
        tmp = reshape(x, [size(x)])
      end select
      p => tmp
    end if
  end subroutine view_i32

  !> The C address of a contiguous output array (NULL when it is empty).
  type(c_ptr) function out_loc(x) result(p)
    type(*), intent(in), target :: x(..)
    p = c_null_ptr
    if (size(x) > 0) p = c_loc(x)
  end function out_loc

  !> The context of a particle set (NULL for a NULL handle).
  type(c_ptr) function ctx_of_particles(ps) result(ctx)
    type(mfree_particles), intent(in) :: ps
    integer(c_int) :: st
    ctx = c_null_ptr
    st = mfree_particles_get_context_c(ps%ptr, ctx)
  end function ctx_of_particles

  !> The context of an approximant (NULL for a NULL handle).
  type(c_ptr) function ctx_of_approximant(a) result(ctx)
    type(mfree_approximant), intent(in) :: a
    integer(c_int) :: st
    ctx = c_null_ptr
    st = mfree_approximant_get_context_c(a%ptr, ctx)
  end function ctx_of_approximant

  !> Dimension, particles (owned and ghost) and ghosts of an approximant's particle set.
  integer(c_int) function approximant_sizes(a, dim, n, ng) result(st)
    type(mfree_approximant), intent(in) :: a
    integer(c_int32_t), intent(out) :: dim, n, ng
    type(c_ptr) :: ps
    integer(c_int32_t), target :: tn, tg
    dim = 0
    n = 0
    ng = 0
    ps = c_null_ptr
    st = mfree_approximant_get_particles_c(a%ptr, ps)
    if (st /= MFREE_SUCCESS) return
    st = mfree_particles_get_dimension_c(ps, dim)
    if (st /= MFREE_SUCCESS) return
    st = mfree_particles_get_size_c(ps, c_loc(tn), c_loc(tg))
    n = tn
    ng = tg
  end function approximant_sizes

  ! ==== version and status =============================================================

  !> Run-time library version "MAJOR.MINOR.PATCH".
  function mfree_version_string() result(s)
    character(len=:), allocatable :: s
    s = mfree_c_string(mfree_version_string_c())
  end function mfree_version_string

  !> Run-time version numbers; each output optional.
  integer(c_int) function mfree_version_get(major, minor, patch) result(st)
    integer(c_int32_t), intent(out), optional, target :: major, minor, patch
    type(c_ptr) :: pmaj, pmin, ppat
    pmaj = c_null_ptr
    pmin = c_null_ptr
    ppat = c_null_ptr
    if (present(major)) pmaj = c_loc(major)
    if (present(minor)) pmin = c_loc(minor)
    if (present(patch)) ppat = c_loc(patch)
    st = mfree_version_get_c(pmaj, pmin, ppat)
  end function mfree_version_get

  !> The name of a status code.
  function mfree_status_string(status) result(s)
    integer(c_int), intent(in) :: status
    character(len=:), allocatable :: s
    s = mfree_c_string(mfree_status_string_c(status))
  end function mfree_status_string

  !> MFREE_VERSION_GE of the C header: this module is at least version a.b.c.
  logical function mfree_version_ge(a, b, c)
    integer, intent(in) :: a, b, c
    mfree_version_ge = MFREE_VERSION_MAJOR > a .or. &
      (MFREE_VERSION_MAJOR == a .and. MFREE_VERSION_MINOR > b) .or. &
      (MFREE_VERSION_MAJOR == a .and. MFREE_VERSION_MINOR == b .and. &
       MFREE_VERSION_PATCH >= c)
  end function mfree_version_ge

  !> True when the library loaded at run time can serve this module: same major version
  !> and a minor.patch at least the module's (an older library may lack functions).
  logical function mfree_version_check()
    integer(c_int32_t) :: major, minor, patch
    mfree_version_check = .false.
    if (mfree_version_get(major, minor, patch) /= MFREE_SUCCESS) return
    mfree_version_check = major == MFREE_VERSION_MAJOR .and. &
      (minor > MFREE_VERSION_MINOR .or. &
       (minor == MFREE_VERSION_MINOR .and. patch >= MFREE_VERSION_PATCH))
  end function mfree_version_check

  ! ==== context ========================================================================

  !> Typed wrapper of mfree_context_create (mfree.h).
  integer(c_int) function mfree_context_create(ctx) result(st)
    type(mfree_context), intent(out) :: ctx
    st = mfree_context_create_c(ctx%ptr)
  end function mfree_context_create

  !> Typed wrapper of mfree_context_destroy (mfree.h).
  integer(c_int) function mfree_context_destroy(ctx) result(st)
    type(mfree_context), intent(inout) :: ctx
    st = mfree_context_destroy_c(ctx%ptr)
  end function mfree_context_destroy

  !> The last failure: its code and/or its message, blank-padded or truncated to
  !> len(message) (mfree_last_error returns the whole message).
  integer(c_int) function mfree_context_get_last_error(ctx, code, message) result(st)
    type(mfree_context), intent(in) :: ctx
    integer(c_int), intent(out), optional, target :: code
    character(len=*), intent(out), optional :: message
    character(kind=c_char), allocatable, target :: buf(:)
    type(c_ptr) :: pcode
    pcode = c_null_ptr
    if (present(code)) pcode = c_loc(code)
    if (present(message)) then
      allocate (buf(len(message) + 1))
      buf = c_null_char
      st = mfree_context_get_last_error_c(ctx%ptr, pcode, c_loc(buf), &
                                          int(size(buf), c_int64_t))
      message = from_c_chars(buf)
    else
      st = mfree_context_get_last_error_c(ctx%ptr, pcode, c_null_ptr, 0_c_int64_t)
    end if
  end function mfree_context_get_last_error

  !> The whole message of the last failure recorded on ctx ('' if none or ctx is null).
  function mfree_last_error(ctx) result(msg)
    type(mfree_context), intent(in) :: ctx
    character(len=:), allocatable :: msg
    character(kind=c_char), allocatable, target :: buf(:)
    integer :: n, i, used
    ! The C call truncates to the buffer and cannot report the full length: grow the
    ! buffer until the message ends before its last byte.
    n = 256
    do
      allocate (buf(n))
      buf = c_null_char
      if (mfree_context_get_last_error_c(ctx%ptr, c_null_ptr, c_loc(buf), &
                                         int(n, c_int64_t)) /= MFREE_SUCCESS) then
        msg = ''
        return
      end if
      used = n
      do i = 1, n
        if (buf(i) == c_null_char) then
          used = i - 1
          exit
        end if
      end do
      if (used < n - 1 .or. n >= 2**24) exit
      deallocate (buf)
      n = 2 * n
    end do
    msg = from_c_chars(buf)
  end function mfree_last_error

  !> Record a failure as mfree does (for host wrappers); returns code.
  integer(c_int) function mfree_context_set_error(ctx, code, message) result(st)
    type(mfree_context), intent(in) :: ctx
    integer(c_int), intent(in) :: code
    character(len=*), intent(in), optional :: message
    character(kind=c_char), allocatable, target :: buf(:)
    if (present(message)) then
      call to_c_chars(message, buf)
      st = mfree_context_set_error_c(ctx%ptr, code, c_loc(buf))
    else
      st = mfree_context_set_error_c(ctx%ptr, code, c_null_ptr)
    end if
  end function mfree_context_set_error

  !> Install handler (absent: remove it) with an optional user pointer.
  integer(c_int) function mfree_context_set_error_handler(ctx, handler, user) result(st)
    type(mfree_context), intent(in) :: ctx
    procedure(mfree_error_handler), optional :: handler
    type(c_ptr), intent(in), optional :: user
    type(c_funptr) :: fp
    type(c_ptr) :: up
    fp = c_null_funptr
    up = c_null_ptr
    if (present(handler)) fp = c_funloc(handler)
    if (present(user)) up = user
    st = mfree_context_set_error_handler_c(ctx%ptr, fp, up)
  end function mfree_context_set_error_handler

  !> Typed wrapper of mfree_context_set_num_threads (mfree.h).
  integer(c_int) function mfree_context_set_num_threads(ctx, nthreads) result(st)
    type(mfree_context), intent(in) :: ctx
    integer(c_int32_t), intent(in) :: nthreads
    st = mfree_context_set_num_threads_c(ctx%ptr, nthreads)
  end function mfree_context_set_num_threads

  !> Typed wrapper of mfree_context_get_num_threads (mfree.h).
  integer(c_int) function mfree_context_get_num_threads(ctx, nthreads) result(st)
    type(mfree_context), intent(in) :: ctx
    integer(c_int32_t), intent(out) :: nthreads
    st = mfree_context_get_num_threads_c(ctx%ptr, nthreads)
  end function mfree_context_get_num_threads

  !> Typed wrapper of mfree_context_set_backend (mfree.h).
  integer(c_int) function mfree_context_set_backend(ctx, backend) result(st)
    type(mfree_context), intent(in) :: ctx
    integer(c_int32_t), intent(in) :: backend
    st = mfree_context_set_backend_c(ctx%ptr, backend)
  end function mfree_context_set_backend

  !> Typed wrapper of mfree_context_get_backend (mfree.h).
  integer(c_int) function mfree_context_get_backend(ctx, backend) result(st)
    type(mfree_context), intent(in) :: ctx
    integer(c_int32_t), intent(out) :: backend
    st = mfree_context_get_backend_c(ctx%ptr, backend)
  end function mfree_context_get_backend

  !> Typed wrapper of mfree_context_set_page_hints (mfree.h).
  integer(c_int) function mfree_context_set_page_hints(ctx, flags) result(st)
    type(mfree_context), intent(in) :: ctx
    integer(c_int32_t), intent(in) :: flags
    st = mfree_context_set_page_hints_c(ctx%ptr, flags)
  end function mfree_context_set_page_hints

  !> Typed wrapper of mfree_context_get_page_hints (mfree.h).
  integer(c_int) function mfree_context_get_page_hints(ctx, flags) result(st)
    type(mfree_context), intent(in) :: ctx
    integer(c_int32_t), intent(out) :: flags
    st = mfree_context_get_page_hints_c(ctx%ptr, flags)
  end function mfree_context_get_page_hints

  !> Install an allocator (mfree_context_set_allocator): alloc = c_funloc of a bind(C)
  !> function (user, bytes) returning type(c_ptr), release = c_funloc of a bind(C)
  !> subroutine (user, ptr, bytes); both absent restores malloc.
  integer(c_int) function mfree_context_set_allocator(ctx, alloc, release, user) result(st)
    type(mfree_context), intent(in) :: ctx
    type(c_funptr), intent(in), optional :: alloc, release
    type(c_ptr), intent(in), optional :: user
    type(c_funptr) :: fa, fr
    type(c_ptr) :: up
    fa = c_null_funptr
    fr = c_null_funptr
    up = c_null_ptr
    if (present(alloc)) fa = alloc
    if (present(release)) fr = release
    if (present(user)) up = user
    st = mfree_context_set_allocator_c(ctx%ptr, fa, fr, up)
  end function mfree_context_set_allocator

  ! ==== kernels ========================================================================

  !> W, dW/dr, d2W/dr2 at the n distances r; request any subset of the outputs, each of
  !> at least n values (as r; else MFREE_ERR_ARG); n of either integer kind.
  integer(c_int) function mfree_kernel_eval_i64(ctx, kernel, dim, param, h, n, r, w, dwdr, &
                                                d2wdr2) result(st)
    type(mfree_context), intent(in) :: ctx
    integer(c_int), intent(in) :: kernel
    integer(c_int32_t), intent(in) :: dim
    real(c_double), intent(in) :: param, h
    integer(c_int64_t), intent(in) :: n
    real(c_double), intent(in) :: r(:)
    real(c_double), intent(out), optional, target :: w(:), dwdr(:), d2wdr2(:)
    type(c_ptr) :: pw, pd, pd2
    character(len=*), parameter :: fn = 'mfree_kernel_eval'
    pw = c_null_ptr
    pd = c_null_ptr
    pd2 = c_null_ptr
    st = check_out(ctx%ptr, fn, 'r', .true., size(r, kind=c_int64_t), n)
    if (st /= MFREE_SUCCESS) return
    if (present(w)) then
      st = check_out(ctx%ptr, fn, 'w', is_contiguous(w), size(w, kind=c_int64_t), n)
      if (st /= MFREE_SUCCESS) return
      pw = out_loc(w)
    end if
    if (present(dwdr)) then
      st = check_out(ctx%ptr, fn, 'dwdr', is_contiguous(dwdr), size(dwdr, kind=c_int64_t), n)
      if (st /= MFREE_SUCCESS) return
      pd = out_loc(dwdr)
    end if
    if (present(d2wdr2)) then
      st = check_out(ctx%ptr, fn, 'd2wdr2', is_contiguous(d2wdr2), size(d2wdr2, kind=c_int64_t), n)
      if (st /= MFREE_SUCCESS) return
      pd2 = out_loc(d2wdr2)
    end if
    st = mfree_kernel_eval_c(ctx%ptr, kernel, dim, param, h, n, r, pw, pd, pd2)
  end function mfree_kernel_eval_i64

  !> Typed wrapper of mfree_kernel_eval (mfree.h).
  integer(c_int) function mfree_kernel_eval_i32(ctx, kernel, dim, param, h, n, r, w, dwdr, &
                                                d2wdr2) result(st)
    type(mfree_context), intent(in) :: ctx
    integer(c_int), intent(in) :: kernel
    integer(c_int32_t), intent(in) :: dim
    real(c_double), intent(in) :: param, h
    integer(c_int32_t), intent(in) :: n
    real(c_double), intent(in) :: r(:)
    real(c_double), intent(out), optional, target :: w(:), dwdr(:), d2wdr2(:)
    st = mfree_kernel_eval_i64(ctx, kernel, dim, param, h, int(n, c_int64_t), r, w, dwdr, d2wdr2)
  end function mfree_kernel_eval_i32

  !> Typed wrapper of mfree_kernel_get_support_radius (mfree.h).
  integer(c_int) function mfree_kernel_get_support_radius(ctx, kernel, param, radius) &
      result(st)
    type(mfree_context), intent(in) :: ctx
    integer(c_int), intent(in) :: kernel
    real(c_double), intent(in) :: param
    real(c_double), intent(out) :: radius
    st = mfree_kernel_get_support_radius_c(ctx%ptr, kernel, param, radius)
  end function mfree_kernel_get_support_radius

  !> Typed wrapper of mfree_kernel_get_normalization (mfree.h).
  integer(c_int) function mfree_kernel_get_normalization(ctx, kernel, dim, param, c) &
      result(st)
    type(mfree_context), intent(in) :: ctx
    integer(c_int), intent(in) :: kernel
    integer(c_int32_t), intent(in) :: dim
    real(c_double), intent(in) :: param
    real(c_double), intent(out) :: c
    st = mfree_kernel_get_normalization_c(ctx%ptr, kernel, dim, param, c)
  end function mfree_kernel_get_normalization

  ! ==== particle sets ==================================================================

  !> Typed wrapper of mfree_particles_create (mfree.h).
  integer(c_int) function mfree_particles_create(ctx, dim, n, ps) result(st)
    type(mfree_context), intent(in) :: ctx
    integer(c_int32_t), intent(in) :: dim, n
    type(mfree_particles), intent(out) :: ps
    st = mfree_particles_create_c(ctx%ptr, dim, n, ps%ptr)
  end function mfree_particles_create

  !> Typed wrapper of mfree_particles_destroy (mfree.h).
  integer(c_int) function mfree_particles_destroy(ps) result(st)
    type(mfree_particles), intent(inout) :: ps
    st = mfree_particles_destroy_c(ps%ptr)
  end function mfree_particles_destroy

  !> Typed wrapper of mfree_particles_set_num_ghost (mfree.h).
  integer(c_int) function mfree_particles_set_num_ghost(ps, n_ghost) result(st)
    type(mfree_particles), intent(in) :: ps
    integer(c_int32_t), intent(in) :: n_ghost
    st = mfree_particles_set_num_ghost_c(ps%ptr, n_ghost)
  end function mfree_particles_set_num_ghost

  !> Positions: x(3,n) -> MFREE_LAYOUT_AOS, ld = 3; x(n,3) -> MFREE_LAYOUT_SOA, ld = n.
  !> With MFREE_BORROW, x must be contiguous with the TARGET attribute (else
  !> MFREE_ERR_ARG); a copied x may be any array or section. ld of any integer kind.
  integer(c_int) function mfree_particles_set_positions_i64(ps, x, layout, ld, mem) result(st)
    type(mfree_particles), intent(in) :: ps
    real(c_double), intent(in), target :: x(..)
    integer(c_int), intent(in) :: layout, mem
    integer(c_int64_t), intent(in) :: ld
    real(c_double), allocatable, target :: tmp(:)
    real(c_double), pointer :: p(:)
    st = check_borrow(ctx_of_particles(ps), 'mfree_particles_set_positions', 'x', &
                      is_contiguous(x), mem)
    if (st /= MFREE_SUCCESS) return
    call view_dbl(x, tmp, p)
    st = mfree_particles_set_positions_c(ps%ptr, p, layout, ld, mem)
  end function mfree_particles_set_positions_i64

  !> Typed wrapper of mfree_particles_set_positions (mfree.h).
  integer(c_int) function mfree_particles_set_positions_i32(ps, x, layout, ld, mem) result(st)
    type(mfree_particles), intent(in) :: ps
    real(c_double), intent(in), target :: x(..)
    integer(c_int), intent(in) :: layout, mem
    integer(c_int32_t), intent(in) :: ld
    st = mfree_particles_set_positions_i64(ps, x, layout, int(ld, c_int64_t), mem)
  end function mfree_particles_set_positions_i32

  !> Per-particle scalars (an array, or one value with stride 0), as for positions.
  integer(c_int) function set_scalar(ps, fn, v, stride, mem, which) result(st)
    type(mfree_particles), intent(in) :: ps
    character(len=*), intent(in) :: fn
    real(c_double), intent(in), target :: v(..)
    integer(c_int64_t), intent(in) :: stride
    integer(c_int), intent(in) :: mem, which
    real(c_double), allocatable, target :: tmp(:)
    real(c_double), pointer :: p(:)
    st = check_borrow(ctx_of_particles(ps), fn, 'the array', is_contiguous(v), mem)
    if (st /= MFREE_SUCCESS) return
    call view_dbl(v, tmp, p)
    select case (which)
    case (1)
      st = mfree_particles_set_volumes_c(ps%ptr, p, stride, mem)
    case (2)
      st = mfree_particles_set_masses_c(ps%ptr, p, stride, mem)
    case (3)
      st = mfree_particles_set_densities_c(ps%ptr, p, stride, mem)
    case default
      st = mfree_particles_set_support_c(ps%ptr, p, stride, mem)
    end select
  end function set_scalar

  !> Typed wrapper of mfree_particles_set_volumes (mfree.h).
  integer(c_int) function mfree_particles_set_volumes_i64(ps, v, stride, mem) result(st)
    type(mfree_particles), intent(in) :: ps
    real(c_double), intent(in), target :: v(..)
    integer(c_int64_t), intent(in) :: stride
    integer(c_int), intent(in) :: mem
    st = set_scalar(ps, 'mfree_particles_set_volumes', v, stride, mem, 1)
  end function mfree_particles_set_volumes_i64
  !> Typed wrapper of mfree_particles_set_volumes (mfree.h).
  integer(c_int) function mfree_particles_set_volumes_i32(ps, v, stride, mem) result(st)
    type(mfree_particles), intent(in) :: ps
    real(c_double), intent(in), target :: v(..)
    integer(c_int32_t), intent(in) :: stride
    integer(c_int), intent(in) :: mem
    st = set_scalar(ps, 'mfree_particles_set_volumes', v, int(stride, c_int64_t), mem, 1)
  end function mfree_particles_set_volumes_i32
  !> Typed wrapper of mfree_particles_set_masses (mfree.h).
  integer(c_int) function mfree_particles_set_masses_i64(ps, m, stride, mem) result(st)
    type(mfree_particles), intent(in) :: ps
    real(c_double), intent(in), target :: m(..)
    integer(c_int64_t), intent(in) :: stride
    integer(c_int), intent(in) :: mem
    st = set_scalar(ps, 'mfree_particles_set_masses', m, stride, mem, 2)
  end function mfree_particles_set_masses_i64
  !> Typed wrapper of mfree_particles_set_masses (mfree.h).
  integer(c_int) function mfree_particles_set_masses_i32(ps, m, stride, mem) result(st)
    type(mfree_particles), intent(in) :: ps
    real(c_double), intent(in), target :: m(..)
    integer(c_int32_t), intent(in) :: stride
    integer(c_int), intent(in) :: mem
    st = set_scalar(ps, 'mfree_particles_set_masses', m, int(stride, c_int64_t), mem, 2)
  end function mfree_particles_set_masses_i32
  !> Typed wrapper of mfree_particles_set_densities (mfree.h).
  integer(c_int) function mfree_particles_set_densities_i64(ps, rho, stride, mem) result(st)
    type(mfree_particles), intent(in) :: ps
    real(c_double), intent(in), target :: rho(..)
    integer(c_int64_t), intent(in) :: stride
    integer(c_int), intent(in) :: mem
    st = set_scalar(ps, 'mfree_particles_set_densities', rho, stride, mem, 3)
  end function mfree_particles_set_densities_i64
  !> Typed wrapper of mfree_particles_set_densities (mfree.h).
  integer(c_int) function mfree_particles_set_densities_i32(ps, rho, stride, mem) result(st)
    type(mfree_particles), intent(in) :: ps
    real(c_double), intent(in), target :: rho(..)
    integer(c_int32_t), intent(in) :: stride
    integer(c_int), intent(in) :: mem
    st = set_scalar(ps, 'mfree_particles_set_densities', rho, int(stride, c_int64_t), mem, 3)
  end function mfree_particles_set_densities_i32
  !> Typed wrapper of mfree_particles_set_support (mfree.h).
  integer(c_int) function mfree_particles_set_support_i64(ps, h, stride, mem) result(st)
    type(mfree_particles), intent(in) :: ps
    real(c_double), intent(in), target :: h(..)
    integer(c_int64_t), intent(in) :: stride
    integer(c_int), intent(in) :: mem
    st = set_scalar(ps, 'mfree_particles_set_support', h, stride, mem, 4)
  end function mfree_particles_set_support_i64
  !> Typed wrapper of mfree_particles_set_support (mfree.h).
  integer(c_int) function mfree_particles_set_support_i32(ps, h, stride, mem) result(st)
    type(mfree_particles), intent(in) :: ps
    real(c_double), intent(in), target :: h(..)
    integer(c_int32_t), intent(in) :: stride
    integer(c_int), intent(in) :: mem
    st = set_scalar(ps, 'mfree_particles_set_support', h, int(stride, c_int64_t), mem, 4)
  end function mfree_particles_set_support_i32

  !> Host CSR lists, 1-based with index_base = 1. rowptr may be 64-bit or 32-bit (legacy
  !> codes); 32-bit offsets are converted, so they can only be copied (MFREE_COPY; with
  !> MFREE_BORROW: MFREE_ERR_ARG). Borrowed arrays must be contiguous.
  integer(c_int) function mfree_particles_set_neighbors_i64(ps, rowptr, cols, index_base, &
                                                            mem) result(st)
    type(mfree_particles), intent(in) :: ps
    integer(c_int64_t), intent(in), target :: rowptr(:)
    integer(c_int32_t), intent(in), target :: cols(:)
    integer(c_int32_t), intent(in) :: index_base
    integer(c_int), intent(in) :: mem
    integer(c_int64_t), allocatable, target :: rtmp(:)
    integer(c_int32_t), allocatable, target :: ctmp(:)
    character(len=*), parameter :: fn = 'mfree_particles_set_neighbors'
    st = check_borrow(ctx_of_particles(ps), fn, 'rowptr', is_contiguous(rowptr), mem)
    if (st == MFREE_SUCCESS) &
      st = check_borrow(ctx_of_particles(ps), fn, 'cols', is_contiguous(cols), mem)
    if (st /= MFREE_SUCCESS) return
    if (is_contiguous(rowptr) .and. is_contiguous(cols)) then
      st = mfree_particles_set_neighbors_c(ps%ptr, rowptr, cols, index_base, mem)
    else
      rtmp = rowptr
      ctmp = cols
      st = mfree_particles_set_neighbors_c(ps%ptr, rtmp, ctmp, index_base, mem)
    end if
  end function mfree_particles_set_neighbors_i64

  !> Typed wrapper of mfree_particles_set_neighbors (mfree.h).
  integer(c_int) function mfree_particles_set_neighbors_i32(ps, rowptr, cols, index_base, &
                                                            mem) result(st)
    type(mfree_particles), intent(in) :: ps
    integer(c_int32_t), intent(in), target :: rowptr(:)
    integer(c_int32_t), intent(in), target :: cols(:)
    integer(c_int32_t), intent(in) :: index_base
    integer(c_int), intent(in) :: mem
    integer(c_int64_t), allocatable, target :: r64(:)
    integer(c_int32_t), allocatable, target :: ctmp(:)
    if (mem == MFREE_BORROW) then
      st = wrapper_error(ctx_of_particles(ps), MFREE_ERR_ARG, 'mfree_particles_set_neighbors: ' // &
                         '32-bit rowptr offsets are converted to 64 bits, so they cannot be ' // &
                         'borrowed: pass MFREE_COPY (and set the lists again when they change)')
      return
    end if
    allocate (r64(size(rowptr)))
    r64 = int(rowptr, c_int64_t)
    ctmp = cols
    if (size(ctmp) == 0) ctmp = [index_base]
    st = mfree_particles_set_neighbors_c(ps%ptr, r64, ctmp, index_base, mem)
  end function mfree_particles_set_neighbors_i32

  !> A half pair list (pair k joins pair_i(k) and pair_j(k), k = 1..npairs; each pair
  !> once), 1-based with index_base = 1; npairs of any integer kind (a legacy code's
  !> niac). pair_i and pair_j must hold npairs values (else MFREE_ERR_ARG) and, borrowed,
  !> be contiguous.
  integer(c_int) function mfree_particles_set_pairs_i64(ps, npairs, pair_i, pair_j, &
                                                        index_base, mem) result(st)
    type(mfree_particles), intent(in) :: ps
    integer(c_int64_t), intent(in) :: npairs
    integer(c_int32_t), intent(in), target :: pair_i(:), pair_j(:)
    integer(c_int32_t), intent(in) :: index_base
    integer(c_int), intent(in) :: mem
    integer(c_int32_t), allocatable, target :: ti(:), tj(:)
    character(len=*), parameter :: fn = 'mfree_particles_set_pairs'
    type(c_ptr) :: ctx, pi, pj
    ctx = ctx_of_particles(ps)
    st = check_borrow(ctx, fn, 'pair_i', is_contiguous(pair_i), mem)
    if (st == MFREE_SUCCESS) st = check_borrow(ctx, fn, 'pair_j', is_contiguous(pair_j), mem)
    if (st /= MFREE_SUCCESS) return
    if (npairs > 0 .and. (size(pair_i, kind=c_int64_t) < npairs .or. &
                          size(pair_j, kind=c_int64_t) < npairs)) then
      st = wrapper_error(ctx, MFREE_ERR_ARG, fn // ': pair_i and pair_j hold ' // &
                         int_str(min(size(pair_i, kind=c_int64_t), size(pair_j, kind=c_int64_t))) // &
                         ' values, npairs = ' // int_str(npairs))
      return
    end if
    pi = c_null_ptr
    pj = c_null_ptr
    if (npairs > 0) then
      if (is_contiguous(pair_i) .and. is_contiguous(pair_j)) then
        pi = c_loc(pair_i)
        pj = c_loc(pair_j)
      else
        ti = pair_i(1:npairs)
        tj = pair_j(1:npairs)
        pi = c_loc(ti)
        pj = c_loc(tj)
      end if
    end if
    st = mfree_particles_set_pairs_c(ps%ptr, npairs, pi, pj, index_base, mem)
  end function mfree_particles_set_pairs_i64

  !> Typed wrapper of mfree_particles_set_pairs (mfree.h).
  integer(c_int) function mfree_particles_set_pairs_i32(ps, npairs, pair_i, pair_j, &
                                                        index_base, mem) result(st)
    type(mfree_particles), intent(in) :: ps
    integer(c_int32_t), intent(in) :: npairs
    integer(c_int32_t), intent(in), target :: pair_i(:), pair_j(:)
    integer(c_int32_t), intent(in) :: index_base
    integer(c_int), intent(in) :: mem
    st = mfree_particles_set_pairs_i64(ps, int(npairs, c_int64_t), pair_i, pair_j, index_base, &
                                       mem)
  end function mfree_particles_set_pairs_i32

  !> Typed wrapper of mfree_particles_get_num_pairs (mfree.h).
  integer(c_int) function mfree_particles_get_num_pairs(ps, npairs) result(st)
    type(mfree_particles), intent(in) :: ps
    integer(c_int64_t), intent(out) :: npairs
    st = mfree_particles_get_num_pairs_c(ps%ptr, npairs)
  end function mfree_particles_get_num_pairs

  !> Typed wrapper of mfree_particles_set_search (mfree.h).
  integer(c_int) function mfree_particles_set_search(ps, convention, kappa) result(st)
    type(mfree_particles), intent(in) :: ps
    integer(c_int), intent(in) :: convention
    real(c_double), intent(in) :: kappa
    st = mfree_particles_set_search_c(ps%ptr, convention, kappa)
  end function mfree_particles_set_search

  !> Typed wrapper of mfree_particles_set_periodic (mfree.h).
  integer(c_int) function mfree_particles_set_periodic(ps, lo, hi, periodic) result(st)
    type(mfree_particles), intent(in) :: ps
    real(c_double), intent(in) :: lo(*), hi(*)
    integer(c_int32_t), intent(in) :: periodic(*)
    st = mfree_particles_set_periodic_c(ps%ptr, lo, hi, periodic)
  end function mfree_particles_set_periodic

  !> Global ids, one per particle (owned and ghost): ids must hold n values (else
  !> MFREE_ERR_ARG); borrowed ids must be contiguous with a target that outlives the
  !> set's setups.
  integer(c_int) function mfree_particles_set_global_ids(ps, ids, mem) result(st)
    type(mfree_particles), intent(in) :: ps
    integer(c_int64_t), intent(in), target :: ids(:)
    integer(c_int), intent(in) :: mem
    integer(c_int64_t), allocatable, target :: tmp(:)
    integer(c_int32_t), target :: n
    character(len=*), parameter :: fn = 'mfree_particles_set_global_ids'
    st = check_borrow(ctx_of_particles(ps), fn, 'ids', is_contiguous(ids), mem)
    if (st == MFREE_SUCCESS) st = mfree_particles_get_size_c(ps%ptr, c_loc(n), c_null_ptr)
    if (st == MFREE_SUCCESS) st = check_out(ctx_of_particles(ps), fn, 'ids', .true., &
                                            size(ids, kind=c_int64_t), int(n, c_int64_t))
    if (st /= MFREE_SUCCESS) return
    if (is_contiguous(ids)) then
      st = mfree_particles_set_global_ids_c(ps%ptr, ids, mem)
    else
      tmp = ids
      st = mfree_particles_set_global_ids_c(ps%ptr, tmp, mem)
    end if
  end function mfree_particles_set_global_ids

  !> ids must be contiguous and hold n values (else MFREE_ERR_ARG).
  integer(c_int) function mfree_particles_get_global_ids(ps, ids) result(st)
    type(mfree_particles), intent(in) :: ps
    integer(c_int64_t), intent(out), target :: ids(:)
    integer(c_int32_t), target :: n
    st = mfree_particles_get_size_c(ps%ptr, c_loc(n), c_null_ptr)
    if (st == MFREE_SUCCESS) st = check_out(ctx_of_particles(ps), 'mfree_particles_get_global_ids', &
                                            'ids', is_contiguous(ids), size(ids, kind=c_int64_t), &
                                            int(n, c_int64_t))
    if (st /= MFREE_SUCCESS) return
    st = mfree_particles_get_global_ids_c(ps%ptr, ids)
  end function mfree_particles_get_global_ids

  !> Typed wrapper of mfree_particles_set_halo_width (mfree.h).
  integer(c_int) function mfree_particles_set_halo_width(ps, w) result(st)
    type(mfree_particles), intent(in) :: ps
    real(c_double), intent(in) :: w
    st = mfree_particles_set_halo_width_c(ps%ptr, w)
  end function mfree_particles_set_halo_width

  !> Typed wrapper of mfree_particles_set_search_skin (mfree.h).
  integer(c_int) function mfree_particles_set_search_skin(ps, skin) result(st)
    type(mfree_particles), intent(in) :: ps
    real(c_double), intent(in) :: skin
    st = mfree_particles_set_search_skin_c(ps%ptr, skin)
  end function mfree_particles_set_search_skin

  !> Typed wrapper of mfree_particles_get_search_count (mfree.h).
  integer(c_int) function mfree_particles_get_search_count(ps, count) result(st)
    type(mfree_particles), intent(in) :: ps
    integer(c_int64_t), intent(out) :: count
    st = mfree_particles_get_search_count_c(ps%ptr, count)
  end function mfree_particles_get_search_count

  !> Typed wrapper of mfree_particles_setup (mfree.h).
  integer(c_int) function mfree_particles_setup(ps) result(st)
    type(mfree_particles), intent(in) :: ps
    st = mfree_particles_setup_c(ps%ptr)
  end function mfree_particles_setup

  !> Typed wrapper of mfree_particles_update (mfree.h).
  integer(c_int) function mfree_particles_update(ps) result(st)
    type(mfree_particles), intent(in) :: ps
    st = mfree_particles_update_c(ps%ptr)
  end function mfree_particles_update

  !> Typed wrapper of mfree_particles_get_dimension (mfree.h).
  integer(c_int) function mfree_particles_get_dimension(ps, dim) result(st)
    type(mfree_particles), intent(in) :: ps
    integer(c_int32_t), intent(out) :: dim
    st = mfree_particles_get_dimension_c(ps%ptr, dim)
  end function mfree_particles_get_dimension

  !> Typed wrapper of mfree_particles_get_size (mfree.h).
  integer(c_int) function mfree_particles_get_size(ps, n, n_ghost) result(st)
    type(mfree_particles), intent(in) :: ps
    integer(c_int32_t), intent(out), optional, target :: n, n_ghost
    type(c_ptr) :: pn, pg
    pn = c_null_ptr
    pg = c_null_ptr
    if (present(n)) pn = c_loc(n)
    if (present(n_ghost)) pg = c_loc(n_ghost)
    st = mfree_particles_get_size_c(ps%ptr, pn, pg)
  end function mfree_particles_get_size

  !> Typed wrapper of mfree_particles_get_neighbor_nnz (mfree.h).
  integer(c_int) function mfree_particles_get_neighbor_nnz(ps, nnz) result(st)
    type(mfree_particles), intent(in) :: ps
    integer(c_int64_t), intent(out) :: nnz
    st = mfree_particles_get_neighbor_nnz_c(ps%ptr, nnz)
  end function mfree_particles_get_neighbor_nnz

  !> 0-based CSR copy: row i (1-based) is cols(rowptr(i)+1 : rowptr(i+1)), values 0..n-1.
  !> rowptr must hold n_owned + 1 values and cols the neighbour count (else MFREE_ERR_ARG).
  integer(c_int) function mfree_particles_get_neighbors(ps, rowptr, cols) result(st)
    type(mfree_particles), intent(in) :: ps
    integer(c_int64_t), intent(out), target :: rowptr(:)
    integer(c_int32_t), intent(out), target :: cols(:)
    integer(c_int32_t), target :: n, ng
    integer(c_int64_t) :: nnz
    character(len=*), parameter :: fn = 'mfree_particles_get_neighbors'
    st = mfree_particles_get_size_c(ps%ptr, c_loc(n), c_loc(ng))
    if (st == MFREE_SUCCESS) st = mfree_particles_get_neighbor_nnz_c(ps%ptr, nnz)
    if (st /= MFREE_SUCCESS) return
    st = check_out(ctx_of_particles(ps), fn, 'rowptr', is_contiguous(rowptr), &
                   size(rowptr, kind=c_int64_t), int(n - ng, c_int64_t) + 1)
    if (st == MFREE_SUCCESS) st = check_out(ctx_of_particles(ps), fn, 'cols', &
                                            is_contiguous(cols), size(cols, kind=c_int64_t), nnz)
    if (st /= MFREE_SUCCESS) return
    st = mfree_particles_get_neighbors_c(ps%ptr, rowptr, cols)
  end function mfree_particles_get_neighbors

  !> v must hold n values (else MFREE_ERR_ARG).
  integer(c_int) function mfree_particles_get_volumes(ps, v) result(st)
    type(mfree_particles), intent(in) :: ps
    real(c_double), intent(out), target :: v(:)
    integer(c_int32_t), target :: n
    st = mfree_particles_get_size_c(ps%ptr, c_loc(n), c_null_ptr)
    if (st == MFREE_SUCCESS) st = check_out(ctx_of_particles(ps), 'mfree_particles_get_volumes', &
                                            'v', is_contiguous(v), size(v, kind=c_int64_t), &
                                            int(n, c_int64_t))
    if (st /= MFREE_SUCCESS) return
    st = mfree_particles_get_volumes_c(ps%ptr, v)
  end function mfree_particles_get_volumes

  !> status, if present, must hold n values (else MFREE_ERR_ARG).
  integer(c_int) function mfree_particles_get_site_status(ps, status, nfailed) result(st)
    type(mfree_particles), intent(in) :: ps
    integer(c_int32_t), intent(out), optional, target :: status(:)
    integer(c_int32_t), intent(out), optional, target :: nfailed
    type(c_ptr) :: pstat, pf
    integer(c_int32_t), target :: n
    pstat = c_null_ptr
    pf = c_null_ptr
    if (present(status)) then
      st = mfree_particles_get_size_c(ps%ptr, c_loc(n), c_null_ptr)
      if (st == MFREE_SUCCESS) st = check_out(ctx_of_particles(ps), &
                                              'mfree_particles_get_site_status', 'status', &
                                              is_contiguous(status), &
                                              size(status, kind=c_int64_t), int(n, c_int64_t))
      if (st /= MFREE_SUCCESS) return
      pstat = out_loc(status)
    end if
    if (present(nfailed)) pf = c_loc(nfailed)
    st = mfree_particles_get_site_status_c(ps%ptr, pstat, pf)
  end function mfree_particles_get_site_status

  !> Typed wrapper of mfree_particles_get_context (mfree.h).
  integer(c_int) function mfree_particles_get_context(ps, ctx) result(st)
    type(mfree_particles), intent(in) :: ps
    type(mfree_context), intent(out) :: ctx
    st = mfree_particles_get_context_c(ps%ptr, ctx%ptr)
  end function mfree_particles_get_context

  ! ==== approximants ===================================================================

  !> Typed wrapper of mfree_approximant_create (mfree.h).
  integer(c_int) function mfree_approximant_create(ctx, ps, method, a) result(st)
    type(mfree_context), intent(in) :: ctx
    type(mfree_particles), intent(in) :: ps
    integer(c_int), intent(in) :: method
    type(mfree_approximant), intent(out) :: a
    st = mfree_approximant_create_c(ctx%ptr, ps%ptr, method, a%ptr)
  end function mfree_approximant_create

  !> Typed wrapper of mfree_approximant_destroy (mfree.h).
  integer(c_int) function mfree_approximant_destroy(a) result(st)
    type(mfree_approximant), intent(inout) :: a
    st = mfree_approximant_destroy_c(a%ptr)
  end function mfree_approximant_destroy

  !> Typed wrapper of mfree_approximant_set_kernel (mfree.h).
  integer(c_int) function mfree_approximant_set_kernel(a, kernel, param) result(st)
    type(mfree_approximant), intent(in) :: a
    integer(c_int), intent(in) :: kernel
    real(c_double), intent(in) :: param
    st = mfree_approximant_set_kernel_c(a%ptr, kernel, param)
  end function mfree_approximant_set_kernel

  ! ---- meshes and MPFEM (paper 004) ----------------------------------------------------
  !> Connectivity conn(nodes per element, nelem); index_base 1 for Fortran numbering.
  integer(c_int) function mfree_mesh_create(ctx, ps, mesh) result(st)
    type(mfree_context), intent(in) :: ctx
    type(mfree_particles), intent(in) :: ps
    type(mfree_mesh), intent(out) :: mesh
    st = mfree_mesh_create_c(ctx%ptr, ps%ptr, mesh%ptr)
  end function mfree_mesh_create

  !> Typed wrapper of mfree_mesh_destroy (mfree.h).
  integer(c_int) function mfree_mesh_destroy(mesh) result(st)
    type(mfree_mesh), intent(inout) :: mesh
    st = mfree_mesh_destroy_c(mesh%ptr)
  end function mfree_mesh_destroy

  !> conn(nodes per element, nelem), any rank; borrowed: contiguous (else MFREE_ERR_ARG).
  integer(c_int) function mfree_mesh_add_elements(mesh, type, nelem, conn, index_base, mem) &
      result(st)
    type(mfree_mesh), intent(in) :: mesh
    integer(c_int), intent(in) :: type
    integer(c_int32_t), intent(in) :: nelem
    integer(c_int32_t), intent(in), target :: conn(..)
    integer(c_int32_t), intent(in) :: index_base
    integer(c_int), intent(in) :: mem
    integer(c_int32_t), allocatable, target :: tmp(:)
    integer(c_int32_t), pointer :: p(:)
    type(c_ptr) :: ctx
    ctx = c_null_ptr
    st = mfree_mesh_get_context_c(mesh%ptr, ctx)
    st = check_borrow(ctx, 'mfree_mesh_add_elements', 'conn', is_contiguous(conn), mem)
    if (st /= MFREE_SUCCESS) return
    call view_i32(conn, tmp, p)
    st = mfree_mesh_add_elements_c(mesh%ptr, type, nelem, p, index_base, mem)
  end function mfree_mesh_add_elements

  !> Typed wrapper of mfree_mesh_setup (mfree.h).
  integer(c_int) function mfree_mesh_setup(mesh) result(st)
    type(mfree_mesh), intent(in) :: mesh
    st = mfree_mesh_setup_c(mesh%ptr)
  end function mfree_mesh_setup

  !> Typed wrapper of mfree_mesh_get_size (mfree.h).
  integer(c_int) function mfree_mesh_get_size(mesh, nelem) result(st)
    type(mfree_mesh), intent(in) :: mesh
    integer(c_int32_t), intent(out) :: nelem
    st = mfree_mesh_get_size_c(mesh%ptr, nelem)
  end function mfree_mesh_get_size

  !> x(dim, npts) and w(npts) are optional: call without them for the count first; with
  !> them, each must be contiguous and hold dim*npts, npts values (else MFREE_ERR_ARG).
  integer(c_int) function mfree_mesh_get_quadrature(mesh, ngauss, npts, x, w) result(st)
    type(mfree_mesh), intent(in) :: mesh
    integer(c_int32_t), intent(in) :: ngauss
    integer(c_int32_t), intent(out) :: npts
    real(c_double), intent(out), optional, target :: x(..), w(:)
    type(c_ptr) :: px, pw, ctx, ps
    integer(c_int32_t) :: dim
    character(len=*), parameter :: fn = 'mfree_mesh_get_quadrature'
    px = c_null_ptr
    pw = c_null_ptr
    st = mfree_mesh_get_quadrature_c(mesh%ptr, ngauss, npts, px, pw)
    if (st /= MFREE_SUCCESS .or. .not. (present(x) .or. present(w))) return
    ctx = c_null_ptr
    ps = c_null_ptr
    st = mfree_mesh_get_context_c(mesh%ptr, ctx)
    if (st == MFREE_SUCCESS) st = mfree_mesh_get_particles_c(mesh%ptr, ps)
    if (st == MFREE_SUCCESS) st = mfree_particles_get_dimension_c(ps, dim)
    if (st /= MFREE_SUCCESS) return
    if (present(x)) then
      st = check_out(ctx, fn, 'x', is_contiguous(x), size(x, kind=c_int64_t), &
                     int(dim, c_int64_t) * npts)
      if (st /= MFREE_SUCCESS) return
      px = out_loc(x)
    end if
    if (present(w)) then
      st = check_out(ctx, fn, 'w', is_contiguous(w), size(w, kind=c_int64_t), int(npts, c_int64_t))
      if (st /= MFREE_SUCCESS) return
      pw = out_loc(w)
    end if
    st = mfree_mesh_get_quadrature_c(mesh%ptr, ngauss, npts, px, pw)
  end function mfree_mesh_get_quadrature

  !> Typed wrapper of mfree_mesh_get_context (mfree.h).
  integer(c_int) function mfree_mesh_get_context(mesh, ctx) result(st)
    type(mfree_mesh), intent(in) :: mesh
    type(mfree_context), intent(out) :: ctx
    st = mfree_mesh_get_context_c(mesh%ptr, ctx%ptr)
  end function mfree_mesh_get_context

  !> Typed wrapper of mfree_mesh_get_particles (mfree.h).
  integer(c_int) function mfree_mesh_get_particles(mesh, ps) result(st)
    type(mfree_mesh), intent(in) :: mesh
    type(mfree_particles), intent(out) :: ps
    st = mfree_mesh_get_particles_c(mesh%ptr, ps%ptr)
  end function mfree_mesh_get_particles

  !> Typed wrapper of mfree_approximant_set_mesh (mfree.h).
  integer(c_int) function mfree_approximant_set_mesh(a, mesh) result(st)
    type(mfree_approximant), intent(in) :: a
    type(mfree_mesh), intent(in) :: mesh
    st = mfree_approximant_set_mesh_c(a%ptr, mesh%ptr)
  end function mfree_approximant_set_mesh

  !> Typed wrapper of mfree_approximant_set_mpfem (mfree.h).
  integer(c_int) function mfree_approximant_set_mpfem(a, deriv, ngauss) result(st)
    type(mfree_approximant), intent(in) :: a
    integer(c_int), intent(in) :: deriv
    integer(c_int32_t), intent(in) :: ngauss
    st = mfree_approximant_set_mpfem_c(a%ptr, deriv, ngauss)
  end function mfree_approximant_set_mpfem

  !> Typed wrapper of mfree_approximant_set_order (mfree.h).
  integer(c_int) function mfree_approximant_set_order(a, order) result(st)
    type(mfree_approximant), intent(in) :: a
    integer(c_int32_t), intent(in) :: order
    st = mfree_approximant_set_order_c(a%ptr, order)
  end function mfree_approximant_set_order

  !> flags: ior of MFREE_DERIV_* values.
  integer(c_int) function mfree_approximant_set_derivatives(a, flags) result(st)
    type(mfree_approximant), intent(in) :: a
    integer(c_int32_t), intent(in) :: flags
    st = mfree_approximant_set_derivatives_c(a%ptr, flags)
  end function mfree_approximant_set_derivatives

  !> Typed wrapper of mfree_approximant_set_fallback (mfree.h).
  integer(c_int) function mfree_approximant_set_fallback(a, policy) result(st)
    type(mfree_approximant), intent(in) :: a
    integer(c_int), intent(in) :: policy
    st = mfree_approximant_set_fallback_c(a%ptr, policy)
  end function mfree_approximant_set_fallback

  !> Typed wrapper of mfree_approximant_set_points (mfree.h).
  integer(c_int) function mfree_approximant_set_points_i64(a, npts, x, layout, ld, h, &
                                                           h_stride, mem) result(st)
    type(mfree_approximant), intent(in) :: a
    integer(c_int32_t), intent(in) :: npts
    real(c_double), intent(in), target :: x(..), h(..)
    integer(c_int), intent(in) :: layout, mem
    integer(c_int64_t), intent(in) :: ld, h_stride
    real(c_double), allocatable, target :: tx(:), th(:)
    real(c_double), pointer :: px(:), ph(:)
    character(len=*), parameter :: fn = 'mfree_approximant_set_points'
    st = check_borrow(ctx_of_approximant(a), fn, 'x', is_contiguous(x), mem)
    if (st == MFREE_SUCCESS) st = check_borrow(ctx_of_approximant(a), fn, 'h', is_contiguous(h), mem)
    if (st /= MFREE_SUCCESS) return
    call view_dbl(x, tx, px)
    call view_dbl(h, th, ph)
    st = mfree_approximant_set_points_c(a%ptr, npts, px, layout, ld, ph, h_stride, mem)
  end function mfree_approximant_set_points_i64

  !> Typed wrapper of mfree_approximant_set_points (mfree.h).
  integer(c_int) function mfree_approximant_set_points_i32(a, npts, x, layout, ld, h, &
                                                           h_stride, mem) result(st)
    type(mfree_approximant), intent(in) :: a
    integer(c_int32_t), intent(in) :: npts
    real(c_double), intent(in), target :: x(..), h(..)
    integer(c_int), intent(in) :: layout, mem
    integer(c_int32_t), intent(in) :: ld, h_stride
    st = mfree_approximant_set_points_i64(a, npts, x, layout, int(ld, c_int64_t), h, &
                                          int(h_stride, c_int64_t), mem)
  end function mfree_approximant_set_points_i32

  !> Doubles apply writes for op on ncomp components with layout olayout/old (0 when the
  !> arguments are invalid: the C call then reports them).
  integer(c_int) function apply_need(a, op, ncomp, olayout, old, need) result(st)
    type(mfree_approximant), intent(in) :: a
    integer(c_int), intent(in) :: op, olayout
    integer(c_int32_t), intent(in) :: ncomp
    integer(c_int64_t), intent(in) :: old
    integer(c_int64_t), intent(out) :: need
    integer(c_int32_t) :: dim, n, ng, nsites
    integer(c_int64_t) :: oc
    need = 0
    st = approximant_sizes(a, dim, n, ng)
    if (st == MFREE_SUCCESS) st = mfree_approximant_get_num_sites_c(a%ptr, nsites)
    if (st /= MFREE_SUCCESS) return
    select case (op)
    case (MFREE_OP_VALUE, MFREE_OP_LAPLACIAN)
      oc = ncomp
    case (MFREE_OP_GRADIENT)
      oc = int(ncomp, c_int64_t) * dim
    case (MFREE_OP_DIVERGENCE)
      oc = 1
    case (MFREE_OP_HESSIAN)
      oc = int(ncomp, c_int64_t) * (dim * (dim + 1) / 2)
    case default
      return
    end select
    if (nsites <= 0 .or. oc <= 0) return
    if (olayout == MFREE_LAYOUT_AOS .and. old >= oc) then
      need = (nsites - 1) * old + oc
    else if (olayout == MFREE_LAYOUT_SOA .and. old >= nsites) then
      need = (oc - 1) * old + nsites
    end if
  end function apply_need

  !> The checks and the call shared by apply and apply_add.
  integer(c_int) function apply_common(a, fn, op, ncomp, u, ulayout, uld, out, olayout, old, &
                                       add) result(st)
    type(mfree_approximant), intent(in) :: a
    character(len=*), intent(in) :: fn
    integer(c_int), intent(in) :: op, ulayout, olayout
    integer(c_int32_t), intent(in) :: ncomp
    real(c_double), intent(in), target :: u(..)
    integer(c_int64_t), intent(in) :: uld, old
    real(c_double), intent(inout), target :: out(..)
    logical, intent(in) :: add
    integer(c_int64_t) :: need
    real(c_double), pointer :: po(:), pu(:)
    real(c_double), allocatable, target :: tu(:)
    st = apply_need(a, op, ncomp, olayout, old, need)
    if (st == MFREE_SUCCESS) st = check_out(ctx_of_approximant(a), fn, 'out', is_contiguous(out), &
                                            size(out, kind=c_int64_t), need)
    if (st /= MFREE_SUCCESS) return
    po => empty_dbl
    if (size(out) > 0) call c_f_pointer(c_loc(out), po, [size(out)])
    call view_dbl(u, tu, pu)
    if (add) then
      st = mfree_approximant_apply_add_c(a%ptr, op, ncomp, pu, ulayout, uld, po, olayout, old)
    else
      st = mfree_approximant_apply_c(a%ptr, op, ncomp, pu, ulayout, uld, po, olayout, old)
    end if
  end function apply_common

  !> out = op(u). For u(ncomp,n) use MFREE_LAYOUT_AOS with uld = ncomp (or the leading
  !> extent of a larger array, e.g. 3 for v(3,n) in 2D); MFREE_OP_GRADIENT writes
  !> direction d of component c at c*dim + d, i.e. out(d, c, i) for out(dim, ncomp, n)
  !> with old = dim*ncomp. out (any rank) must be contiguous and large enough for what
  !> the layout addresses (else MFREE_ERR_ARG, nothing written); uld and old of either
  !> integer kind (both the same).
  integer(c_int) function mfree_approximant_apply_i64(a, op, ncomp, u, ulayout, uld, out, &
                                                      olayout, old) result(st)
    type(mfree_approximant), intent(in) :: a
    integer(c_int), intent(in) :: op, ulayout, olayout
    integer(c_int32_t), intent(in) :: ncomp
    real(c_double), intent(in), target :: u(..)
    integer(c_int64_t), intent(in) :: uld, old
    real(c_double), intent(out), target :: out(..)
    st = apply_common(a, 'mfree_approximant_apply', op, ncomp, u, ulayout, uld, out, olayout, &
                      old, .false.)
  end function mfree_approximant_apply_i64

  !> Typed wrapper of mfree_approximant_apply (mfree.h).
  integer(c_int) function mfree_approximant_apply_i32(a, op, ncomp, u, ulayout, uld, out, &
                                                      olayout, old) result(st)
    type(mfree_approximant), intent(in) :: a
    integer(c_int), intent(in) :: op, ulayout, olayout
    integer(c_int32_t), intent(in) :: ncomp
    real(c_double), intent(in), target :: u(..)
    integer(c_int32_t), intent(in) :: uld, old
    real(c_double), intent(out), target :: out(..)
    st = apply_common(a, 'mfree_approximant_apply', op, ncomp, u, ulayout, int(uld, c_int64_t), &
                      out, olayout, int(old, c_int64_t), .false.)
  end function mfree_approximant_apply_i32

  !> Typed wrapper of mfree_approximant_apply_add (mfree.h).
  integer(c_int) function mfree_approximant_apply_add_i64(a, op, ncomp, u, ulayout, uld, out, &
                                                          olayout, old) result(st)
    type(mfree_approximant), intent(in) :: a
    integer(c_int), intent(in) :: op, ulayout, olayout
    integer(c_int32_t), intent(in) :: ncomp
    real(c_double), intent(in), target :: u(..)
    integer(c_int64_t), intent(in) :: uld, old
    real(c_double), intent(inout), target :: out(..)
    st = apply_common(a, 'mfree_approximant_apply_add', op, ncomp, u, ulayout, uld, out, &
                      olayout, old, .true.)
  end function mfree_approximant_apply_add_i64

  !> Typed wrapper of mfree_approximant_apply_add (mfree.h).
  integer(c_int) function mfree_approximant_apply_add_i32(a, op, ncomp, u, ulayout, uld, out, &
                                                          olayout, old) result(st)
    type(mfree_approximant), intent(in) :: a
    integer(c_int), intent(in) :: op, ulayout, olayout
    integer(c_int32_t), intent(in) :: ncomp
    real(c_double), intent(in), target :: u(..)
    integer(c_int32_t), intent(in) :: uld, old
    real(c_double), intent(inout), target :: out(..)
    st = apply_common(a, 'mfree_approximant_apply_add', op, ncomp, u, ulayout, &
                      int(uld, c_int64_t), out, olayout, int(old, c_int64_t), .true.)
  end function mfree_approximant_apply_add_i32

  !> MFREE_SUCCESS when an output of one value per site (nsites, contiguous) fits.
  integer(c_int) function check_sites(a, fn, what, contig, have, extra) result(st)
    type(mfree_approximant), intent(in) :: a
    character(len=*), intent(in) :: fn, what
    logical, intent(in) :: contig
    integer(c_int64_t), intent(in) :: have
    integer(c_int32_t), intent(in) :: extra
    integer(c_int32_t) :: nsites
    st = mfree_approximant_get_num_sites_c(a%ptr, nsites)
    if (st /= MFREE_SUCCESS) return
    st = check_out(ctx_of_approximant(a), fn, what, contig, have, int(nsites + extra, c_int64_t))
  end function check_sites

  !> One table as 0-based CSR; any of rowptr (nsites + 1), cols and vals (nnz each) may be
  !> omitted (not all); each present one must be contiguous and large enough.
  integer(c_int) function mfree_approximant_assemble_csr(a, deriv, component, rowptr, cols, &
                                                         vals) result(st)
    type(mfree_approximant), intent(in) :: a
    integer(c_int), intent(in) :: deriv
    integer(c_int32_t), intent(in) :: component
    integer(c_int64_t), intent(out), optional, target :: rowptr(:)
    integer(c_int32_t), intent(out), optional, target :: cols(:)
    real(c_double), intent(out), optional, target :: vals(:)
    type(c_ptr) :: pr, pc, pv
    integer(c_int64_t) :: nnz
    character(len=*), parameter :: fn = 'mfree_approximant_assemble_csr'
    pr = c_null_ptr
    pc = c_null_ptr
    pv = c_null_ptr
    st = mfree_approximant_get_nnz_c(a%ptr, nnz)
    if (st /= MFREE_SUCCESS) return
    if (present(rowptr)) then
      st = check_sites(a, fn, 'rowptr', is_contiguous(rowptr), size(rowptr, kind=c_int64_t), 1)
      if (st /= MFREE_SUCCESS) return
      pr = c_loc(rowptr)
    end if
    if (present(cols)) then
      st = check_out(ctx_of_approximant(a), fn, 'cols', is_contiguous(cols), &
                     size(cols, kind=c_int64_t), nnz)
      if (st /= MFREE_SUCCESS) return
      pc = c_loc(cols)
    end if
    if (present(vals)) then
      st = check_out(ctx_of_approximant(a), fn, 'vals', is_contiguous(vals), &
                     size(vals, kind=c_int64_t), nnz)
      if (st /= MFREE_SUCCESS) return
      pv = c_loc(vals)
    end if
    st = mfree_approximant_assemble_csr_c(a%ptr, deriv, component, pr, pc, pv)
  end function mfree_approximant_assemble_csr

  !> Per-site outputs: nsites values each (else MFREE_ERR_ARG).
  integer(c_int) function mfree_approximant_get_site_status(a, status, nfailed) result(st)
    type(mfree_approximant), intent(in) :: a
    integer(c_int32_t), intent(out), optional, target :: status(:)
    integer(c_int32_t), intent(out), optional, target :: nfailed
    type(c_ptr) :: pstat, pf
    pstat = c_null_ptr
    pf = c_null_ptr
    if (present(status)) then
      st = check_sites(a, 'mfree_approximant_get_site_status', 'status', is_contiguous(status), &
                       size(status, kind=c_int64_t), 0)
      if (st /= MFREE_SUCCESS) return
      pstat = out_loc(status)
    end if
    if (present(nfailed)) pf = c_loc(nfailed)
    st = mfree_approximant_get_site_status_c(a%ptr, pstat, pf)
  end function mfree_approximant_get_site_status

  !> Typed wrapper of mfree_approximant_get_neighbor_counts (mfree.h).
  integer(c_int) function mfree_approximant_get_neighbor_counts(a, counts) result(st)
    type(mfree_approximant), intent(in) :: a
    integer(c_int32_t), intent(out) :: counts(:)
    st = check_sites(a, 'mfree_approximant_get_neighbor_counts', 'counts', &
                     is_contiguous(counts), size(counts, kind=c_int64_t), 0)
    if (st /= MFREE_SUCCESS) return
    st = mfree_approximant_get_neighbor_counts_c(a%ptr, counts)
  end function mfree_approximant_get_neighbor_counts

  !> Typed wrapper of mfree_approximant_get_condition (mfree.h).
  integer(c_int) function mfree_approximant_get_condition(a, cond) result(st)
    type(mfree_approximant), intent(in) :: a
    real(c_double), intent(out) :: cond(:)
    st = check_sites(a, 'mfree_approximant_get_condition', 'cond', is_contiguous(cond), &
                     size(cond, kind=c_int64_t), 0)
    if (st /= MFREE_SUCCESS) return
    st = mfree_approximant_get_condition_c(a%ptr, cond)
  end function mfree_approximant_get_condition

  !> Typed wrapper of mfree_approximant_get_site_order (mfree.h).
  integer(c_int) function mfree_approximant_get_site_order(a, order) result(st)
    type(mfree_approximant), intent(in) :: a
    integer(c_int32_t), intent(out) :: order(:)
    st = check_sites(a, 'mfree_approximant_get_site_order', 'order', is_contiguous(order), &
                     size(order, kind=c_int64_t), 0)
    if (st /= MFREE_SUCCESS) return
    st = mfree_approximant_get_site_order_c(a%ptr, order)
  end function mfree_approximant_get_site_order

  !> Per-pair gradients into gi(ld, npairs) and, optionally, gj(ld, npairs), ld >= dim
  !> (e.g. a legacy code's dwdx(3, max_interaction)): gi(:, k) is particle pair_i(k)'s
  !> row at pair_j(k), per unit volume (for plain SPH exactly the code's dwdx(:, k)), gj
  !> the other side (mfree.h). Arrays that are not contiguous or have fewer than npairs
  !> columns give MFREE_ERR_ARG and nothing is written.
  integer(c_int) function mfree_approximant_get_pair_gradients(a, gi, gj) result(st)
    type(mfree_approximant), intent(in) :: a
    real(c_double), intent(out), target :: gi(:, :)
    real(c_double), intent(out), optional, target :: gj(:, :)
    type(c_ptr) :: pj
    character(len=*), parameter :: fn = 'mfree_approximant_get_pair_gradients'
    st = check_pair_array(a, fn, 'gi', is_contiguous(gi), size(gi, 1, kind=c_int64_t), &
                          size(gi, 2, kind=c_int64_t))
    if (st /= MFREE_SUCCESS) return
    pj = c_null_ptr
    if (present(gj)) then
      st = check_pair_array(a, fn, 'gj', is_contiguous(gj), size(gj, 1, kind=c_int64_t), &
                            size(gj, 2, kind=c_int64_t))
      if (st /= MFREE_SUCCESS) return
      if (size(gi, 1) /= size(gj, 1)) then
        st = wrapper_error(ctx_of_approximant(a), MFREE_ERR_ARG, fn // &
                           ': gi and gj have different leading extents')
        return
      end if
      pj = out_loc(gj)
    end if
    st = mfree_approximant_get_pair_gradients_c(a%ptr, out_loc(gi), pj, &
                                                size(gi, 1, kind=c_int64_t), &
                                                size(gi, kind=c_int64_t))
  end function mfree_approximant_get_pair_gradients

  !> The antisymmetrised per-pair gradient g(ld, npairs) (j side = -g), as above.
  integer(c_int) function mfree_approximant_get_pair_gradients_antisymmetric(a, g) result(st)
    type(mfree_approximant), intent(in) :: a
    real(c_double), intent(out), target :: g(:, :)
    st = check_pair_array(a, 'mfree_approximant_get_pair_gradients_antisymmetric', 'g', &
                          is_contiguous(g), size(g, 1, kind=c_int64_t), size(g, 2, kind=c_int64_t))
    if (st /= MFREE_SUCCESS) return
    st = mfree_approximant_get_pair_gradients_antisymmetric_c(a%ptr, out_loc(g), &
                                                              size(g, 1, kind=c_int64_t), &
                                                              size(g, kind=c_int64_t))
  end function mfree_approximant_get_pair_gradients_antisymmetric

  !> A pair-gradient array (ld, ncol): contiguous, ld >= dim, ncol >= npairs.
  integer(c_int) function check_pair_array(a, fn, what, contig, ld, ncol) result(st)
    type(mfree_approximant), intent(in) :: a
    character(len=*), intent(in) :: fn, what
    logical, intent(in) :: contig
    integer(c_int64_t), intent(in) :: ld, ncol
    integer(c_int32_t) :: dim, n, ng
    integer(c_int64_t) :: np
    type(c_ptr) :: ps
    st = approximant_sizes(a, dim, n, ng)
    if (st /= MFREE_SUCCESS) return
    st = mfree_approximant_get_particles_c(a%ptr, ps)
    if (st == MFREE_SUCCESS) st = mfree_particles_get_num_pairs_c(ps, np)
    if (st /= MFREE_SUCCESS) return
    if (ld < dim) then
      st = wrapper_error(ctx_of_approximant(a), MFREE_ERR_ARG, fn // ': ' // what // ' has ' // &
                         int_str(ld) // ' rows, below the dimension ' // int_str(int(dim, c_int64_t)))
      return
    end if
    st = check_out(ctx_of_approximant(a), fn, what // ' columns', contig, ncol, np)
  end function check_pair_array

  !> Typed wrapper of mfree_approximant_get_correction_size (mfree.h).
  integer(c_int) function mfree_approximant_get_correction_size(a, ncoef) result(st)
    type(mfree_approximant), intent(in) :: a
    integer(c_int32_t), intent(out) :: ncoef
    st = mfree_approximant_get_correction_size_c(a%ptr, ncoef)
  end function mfree_approximant_get_correction_size

  !> Per-particle correction data c(ld, n_owned), ld >= ncoef (layout in mfree.h; a
  !> matrix M of particle i is reshape(c(1:dim*dim, i), [dim, dim]), so that the
  !> corrected gradient is matmul(M, dwdx)). MFREE_ERR_ARG, nothing written, when c is
  !> not contiguous or too small.
  integer(c_int) function mfree_approximant_get_correction(a, c) result(st)
    type(mfree_approximant), intent(in) :: a
    real(c_double), intent(out), target :: c(:, :)
    integer(c_int32_t) :: nsites
    st = mfree_approximant_get_num_sites_c(a%ptr, nsites)
    if (st == MFREE_SUCCESS) st = check_correction_array(a, 'mfree_approximant_get_correction', &
                                                         is_contiguous(c), size(c, 1, kind=c_int64_t), &
                                                         size(c, 2, kind=c_int64_t), nsites)
    if (st /= MFREE_SUCCESS) return
    st = mfree_approximant_get_correction_c(a%ptr, out_loc(c), size(c, 1, kind=c_int64_t), &
                                            size(c, kind=c_int64_t))
  end function mfree_approximant_get_correction

  !> The ghosts' correction data c(ld, n_ghost), ld >= ncoef, ghost g in column g (the
  !> records mfree_approximant_get_correction gives where the ghosts are owned; mfree.h).
  !> Copied (a non-contiguous section is packed first). MFREE_ERR_ARG, nothing read, when
  !> c is too small.
  integer(c_int) function mfree_approximant_set_ghost_correction(a, c) result(st)
    type(mfree_approximant), intent(in) :: a
    real(c_double), intent(in), target :: c(:, :)
    integer(c_int32_t) :: dim, n, ng
    real(c_double), allocatable, target :: tc(:)
    real(c_double), pointer :: pc(:)
    st = approximant_sizes(a, dim, n, ng)
    if (st == MFREE_SUCCESS) st = check_correction_array(a, 'mfree_approximant_set_ghost_correction', &
                                                         .true., size(c, 1, kind=c_int64_t), &
                                                         size(c, 2, kind=c_int64_t), ng)
    if (st /= MFREE_SUCCESS) return
    call view_dbl(c, tc, pc)
    st = mfree_approximant_set_ghost_correction_c(a%ptr, pc, size(c, 1, kind=c_int64_t), &
                                                  size(c, kind=c_int64_t))
  end function mfree_approximant_set_ghost_correction

  !> A correction-data array (ld, ncol): ld >= ncoef, ncol >= count, contiguous.
  integer(c_int) function check_correction_array(a, fn, contig, ld, ncol, count) result(st)
    type(mfree_approximant), intent(in) :: a
    character(len=*), intent(in) :: fn
    logical, intent(in) :: contig
    integer(c_int64_t), intent(in) :: ld, ncol
    integer(c_int32_t), intent(in) :: count
    integer(c_int32_t) :: nc
    st = mfree_approximant_get_correction_size_c(a%ptr, nc)
    if (st /= MFREE_SUCCESS) return
    if (ld < nc) then
      st = wrapper_error(ctx_of_approximant(a), MFREE_ERR_ARG, fn // ': c has ' // int_str(ld) // &
                         ' rows, ' // int_str(int(nc, c_int64_t)) // ' are needed')
      return
    end if
    st = check_out(ctx_of_approximant(a), fn, 'c columns', contig, ncol, int(count, c_int64_t))
  end function check_correction_array

  !> The context (borrowed: do not destroy it) and the particle set (borrowed) of a.
  integer(c_int) function mfree_approximant_get_context(a, ctx) result(st)
    type(mfree_approximant), intent(in) :: a
    type(mfree_context), intent(out) :: ctx
    st = mfree_approximant_get_context_c(a%ptr, ctx%ptr)
  end function mfree_approximant_get_context

  !> Typed wrapper of mfree_approximant_get_particles (mfree.h).
  integer(c_int) function mfree_approximant_get_particles(a, ps) result(st)
    type(mfree_approximant), intent(in) :: a
    type(mfree_particles), intent(out) :: ps
    st = mfree_approximant_get_particles_c(a%ptr, ps%ptr)
  end function mfree_approximant_get_particles

  !> Typed wrapper of mfree_approximant_setup (mfree.h).
  integer(c_int) function mfree_approximant_setup(a) result(st)
    type(mfree_approximant), intent(in) :: a
    st = mfree_approximant_setup_c(a%ptr)
  end function mfree_approximant_setup

  !> Typed wrapper of mfree_approximant_update (mfree.h).
  integer(c_int) function mfree_approximant_update(a) result(st)
    type(mfree_approximant), intent(in) :: a
    st = mfree_approximant_update_c(a%ptr)
  end function mfree_approximant_update

  !> Typed wrapper of mfree_approximant_get_num_sites (mfree.h).
  integer(c_int) function mfree_approximant_get_num_sites(a, nsites) result(st)
    type(mfree_approximant), intent(in) :: a
    integer(c_int32_t), intent(out) :: nsites
    st = mfree_approximant_get_num_sites_c(a%ptr, nsites)
  end function mfree_approximant_get_num_sites

  !> Typed wrapper of mfree_approximant_get_nnz (mfree.h).
  integer(c_int) function mfree_approximant_get_nnz(a, nnz) result(st)
    type(mfree_approximant), intent(in) :: a
    integer(c_int64_t), intent(out) :: nnz
    st = mfree_approximant_get_nnz_c(a%ptr, nnz)
  end function mfree_approximant_get_nnz

  !> Typed wrapper of mfree_approximant_check_reproduction (mfree.h).
  integer(c_int) function mfree_approximant_check_reproduction(a, order, fn_err, deriv_err) &
      result(st)
    type(mfree_approximant), intent(in) :: a
    integer(c_int32_t), intent(in) :: order
    real(c_double), intent(out) :: fn_err, deriv_err
    st = mfree_approximant_check_reproduction_c(a%ptr, order, fn_err, deriv_err)
  end function mfree_approximant_check_reproduction

  ! ==== sparse matrices ================================================================

  !> A matrix from 0-based CSR host arrays (copied).
  integer(c_int) function mfree_matrix_create_csr(ctx, nrows, ncols, rowptr, cols, vals, A) &
      result(st)
    type(mfree_context), intent(in) :: ctx
    integer(c_int32_t), intent(in) :: nrows, ncols
    integer(c_int64_t), intent(in) :: rowptr(*)
    integer(c_int32_t), intent(in) :: cols(*)
    real(c_double), intent(in) :: vals(*)
    type(mfree_matrix), intent(out) :: A
    st = mfree_matrix_create_csr_c(ctx%ptr, nrows, ncols, rowptr, cols, vals, A%ptr)
  end function mfree_matrix_create_csr

  !> Typed wrapper of mfree_matrix_destroy (mfree.h).
  integer(c_int) function mfree_matrix_destroy(A) result(st)
    type(mfree_matrix), intent(inout) :: A
    st = mfree_matrix_destroy_c(A%ptr)
  end function mfree_matrix_destroy

  !> Typed wrapper of mfree_matrix_get_size (mfree.h).
  integer(c_int) function mfree_matrix_get_size(A, nrows, ncols, nnz) result(st)
    type(mfree_matrix), intent(in) :: A
    integer(c_int32_t), intent(out), optional, target :: nrows, ncols
    integer(c_int64_t), intent(out), optional, target :: nnz
    type(c_ptr) :: pr, pc, pn
    pr = c_null_ptr
    pc = c_null_ptr
    pn = c_null_ptr
    if (present(nrows)) pr = c_loc(nrows)
    if (present(ncols)) pc = c_loc(ncols)
    if (present(nnz)) pn = c_loc(nnz)
    st = mfree_matrix_get_size_c(A%ptr, pr, pc, pn)
  end function mfree_matrix_get_size

  !> Sizes of the views: rows + 1 (or columns + 1 for CSC) offsets and nnz entries.
  integer(c_int) function view_sizes(A, csc, noff, nnz) result(st)
    type(mfree_matrix), intent(in) :: A
    logical, intent(in) :: csc
    integer(c_int64_t), intent(out) :: noff, nnz
    integer(c_int32_t), target :: nrows, ncols
    integer(c_int64_t), target :: nz
    noff = 0
    nnz = 0
    st = mfree_matrix_get_size_c(A%ptr, c_loc(nrows), c_loc(ncols), c_loc(nz))
    if (st /= MFREE_SUCCESS) return
    if (csc) then
      noff = int(ncols, c_int64_t) + 1
    else
      noff = int(nrows, c_int64_t) + 1
    end if
    nnz = nz
  end function view_sizes

  !> Zero-copy CSR view as Fortran pointers (read only; 0-based offsets and columns:
  !> row i holds k = rowptr(i)+1 .. rowptr(i+1), column cols(k)+1, value vals(k)). The
  !> pointers stay valid until A is refilled with another pattern or destroyed.
  integer(c_int) function mfree_matrix_get_csr(A, rowptr, cols, vals) result(st)
    type(mfree_matrix), intent(in) :: A
    integer(c_int64_t), pointer, intent(out) :: rowptr(:)
    integer(c_int32_t), pointer, intent(out) :: cols(:)
    real(c_double), pointer, intent(out) :: vals(:)
    type(c_ptr) :: pr, pc, pv
    integer(c_int64_t) :: noff, nnz
    nullify (rowptr, cols, vals)
    st = view_sizes(A, .false., noff, nnz)
    if (st /= MFREE_SUCCESS) return
    st = mfree_matrix_get_csr_c(A%ptr, pr, pc, pv)
    if (st /= MFREE_SUCCESS) return
    call c_f_pointer(pr, rowptr, [noff])
    if (nnz > 0) then
      call c_f_pointer(pc, cols, [nnz])
      call c_f_pointer(pv, vals, [nnz])
    else
      cols => empty_i32
      vals => empty_dbl
    end if
  end function mfree_matrix_get_csr

  !> As mfree_matrix_get_csr with 32-bit offsets (MFREE_ERR_UNSUPPORTED if nnz is too big).
  integer(c_int) function mfree_matrix_get_csr_i32(A, rowptr, cols, vals) result(st)
    type(mfree_matrix), intent(in) :: A
    integer(c_int32_t), pointer, intent(out) :: rowptr(:)
    integer(c_int32_t), pointer, intent(out) :: cols(:)
    real(c_double), pointer, intent(out) :: vals(:)
    type(c_ptr) :: pr, pc, pv
    integer(c_int64_t) :: noff, nnz
    nullify (rowptr, cols, vals)
    st = view_sizes(A, .false., noff, nnz)
    if (st /= MFREE_SUCCESS) return
    st = mfree_matrix_get_csr_i32_c(A%ptr, pr, pc, pv)
    if (st /= MFREE_SUCCESS) return
    call c_f_pointer(pr, rowptr, [noff])
    if (nnz > 0) then
      call c_f_pointer(pc, cols, [nnz])
      call c_f_pointer(pv, vals, [nnz])
    else
      cols => empty_i32
      vals => empty_dbl
    end if
  end function mfree_matrix_get_csr_i32

  !> As mfree_matrix_get_csr with 64-bit offsets and columns.
  integer(c_int) function mfree_matrix_get_csr_i64(A, rowptr, cols, vals) result(st)
    type(mfree_matrix), intent(in) :: A
    integer(c_int64_t), pointer, intent(out) :: rowptr(:)
    integer(c_int64_t), pointer, intent(out) :: cols(:)
    real(c_double), pointer, intent(out) :: vals(:)
    type(c_ptr) :: pr, pc, pv
    integer(c_int64_t) :: noff, nnz
    nullify (rowptr, cols, vals)
    st = view_sizes(A, .false., noff, nnz)
    if (st /= MFREE_SUCCESS) return
    st = mfree_matrix_get_csr_i64_c(A%ptr, pr, pc, pv)
    if (st /= MFREE_SUCCESS) return
    call c_f_pointer(pr, rowptr, [noff])
    if (nnz > 0) then
      call c_f_pointer(pc, cols, [nnz])
      call c_f_pointer(pv, vals, [nnz])
    else
      cols => empty_i64
      vals => empty_dbl
    end if
  end function mfree_matrix_get_csr_i64

  !> Zero-copy CSC view (0-based), computed on first request after a fill.
  integer(c_int) function mfree_matrix_get_csc(A, colptr, rows, vals) result(st)
    type(mfree_matrix), intent(in) :: A
    integer(c_int64_t), pointer, intent(out) :: colptr(:)
    integer(c_int32_t), pointer, intent(out) :: rows(:)
    real(c_double), pointer, intent(out) :: vals(:)
    type(c_ptr) :: pcp, pr, pv
    integer(c_int64_t) :: noff, nnz
    nullify (colptr, rows, vals)
    st = view_sizes(A, .true., noff, nnz)
    if (st /= MFREE_SUCCESS) return
    st = mfree_matrix_get_csc_c(A%ptr, pcp, pr, pv)
    if (st /= MFREE_SUCCESS) return
    call c_f_pointer(pcp, colptr, [noff])
    if (nnz > 0) then
      call c_f_pointer(pr, rows, [nnz])
      call c_f_pointer(pv, vals, [nnz])
    else
      rows => empty_i32
      vals => empty_dbl
    end if
  end function mfree_matrix_get_csc

  !> Typed wrapper of mfree_matrix_get_pattern_id (mfree.h).
  integer(c_int) function mfree_matrix_get_pattern_id(A, id) result(st)
    type(mfree_matrix), intent(in) :: A
    integer(c_int64_t), intent(out) :: id
    st = mfree_matrix_get_pattern_id_c(A%ptr, id)
  end function mfree_matrix_get_pattern_id

  !> Typed wrapper of mfree_matrix_get_symmetric (mfree.h).
  integer(c_int) function mfree_matrix_get_symmetric(A, symmetric) result(st)
    type(mfree_matrix), intent(in) :: A
    integer(c_int32_t), intent(out) :: symmetric
    st = mfree_matrix_get_symmetric_c(A%ptr, symmetric)
  end function mfree_matrix_get_symmetric

  !> y = A x; y must be contiguous and hold nrows values (else MFREE_ERR_ARG).
  integer(c_int) function mfree_matrix_apply(A, x, y) result(st)
    type(mfree_matrix), intent(in) :: A
    real(c_double), intent(in) :: x(*)
    real(c_double), intent(out), target :: y(:)
    integer(c_int32_t), target :: nrows
    type(c_ptr) :: ctx
    st = mfree_matrix_get_size_c(A%ptr, c_loc(nrows), c_null_ptr, c_null_ptr)
    if (st /= MFREE_SUCCESS) return
    ctx = c_null_ptr
    st = mfree_matrix_get_context_c(A%ptr, ctx)
    st = check_out(ctx, 'mfree_matrix_apply', 'y', is_contiguous(y), size(y, kind=c_int64_t), &
                   int(nrows, c_int64_t))
    if (st /= MFREE_SUCCESS) return
    st = mfree_matrix_apply_c(A%ptr, x, y)
  end function mfree_matrix_apply

  !> Typed wrapper of mfree_matrix_get_context (mfree.h).
  integer(c_int) function mfree_matrix_get_context(A, ctx) result(st)
    type(mfree_matrix), intent(in) :: A
    type(mfree_context), intent(out) :: ctx
    st = mfree_matrix_get_context_c(A%ptr, ctx%ptr)
  end function mfree_matrix_get_context

  ! ==== assembly =======================================================================

  !> Bubnov-Galerkin: pass a null test approximant, mfree_approximant().
  integer(c_int) function mfree_assembler_create(ctx, trial, test, form, as) result(st)
    type(mfree_context), intent(in) :: ctx
    type(mfree_approximant), intent(in) :: trial, test
    integer(c_int), intent(in) :: form
    type(mfree_assembler), intent(out) :: as
    st = mfree_assembler_create_c(ctx%ptr, trial%ptr, test%ptr, form, as%ptr)
  end function mfree_assembler_create

  !> Typed wrapper of mfree_assembler_destroy (mfree.h).
  integer(c_int) function mfree_assembler_destroy(as) result(st)
    type(mfree_assembler), intent(inout) :: as
    st = mfree_assembler_destroy_c(as%ptr)
  end function mfree_assembler_destroy

  !> Typed wrapper of mfree_assembler_set_material (mfree.h).
  integer(c_int) function mfree_assembler_set_material(as, young, poisson) result(st)
    type(mfree_assembler), intent(in) :: as
    real(c_double), intent(in) :: young, poisson
    st = mfree_assembler_set_material_c(as%ptr, young, poisson)
  end function mfree_assembler_set_material

  !> Typed wrapper of mfree_assembler_set_coefficient (mfree.h).
  integer(c_int) function mfree_assembler_set_coefficient(as, c) result(st)
    type(mfree_assembler), intent(in) :: as
    real(c_double), intent(in) :: c
    st = mfree_assembler_set_coefficient_c(as%ptr, c)
  end function mfree_assembler_set_coefficient

  !> Typed wrapper of mfree_assembler_set_quadrature_nodal (mfree.h).
  integer(c_int) function mfree_assembler_set_quadrature_nodal(as) result(st)
    type(mfree_assembler), intent(in) :: as
    st = mfree_assembler_set_quadrature_nodal_c(as%ptr)
  end function mfree_assembler_set_quadrature_nodal

  !> Background cells; inside (optional) drops the points where it returns 0.
  integer(c_int) function mfree_assembler_set_quadrature_cells(as, lo, hi, ncells, ngauss, &
                                                               inside, user) result(st)
    type(mfree_assembler), intent(in) :: as
    real(c_double), intent(in) :: lo(*), hi(*)
    integer(c_int32_t), intent(in) :: ncells(*)
    integer(c_int32_t), intent(in) :: ngauss
    procedure(mfree_inside_fn), optional :: inside
    type(c_ptr), intent(in), optional :: user
    type(c_funptr) :: fp
    fp = c_null_funptr
    if (present(inside)) fp = c_funloc(inside)
    st = mfree_assembler_set_quadrature_cells_c(as%ptr, lo, hi, ncells, ngauss, fp, &
                                                user_ptr(user))
  end function mfree_assembler_set_quadrature_cells

  !> Typed wrapper of mfree_assembler_set_quadrature_points (mfree.h).
  integer(c_int) function mfree_assembler_set_quadrature_points(as, npts, x, layout, ld, w) &
      result(st)
    type(mfree_assembler), intent(in) :: as
    integer(c_int32_t), intent(in) :: npts
    real(c_double), intent(in) :: x(*), w(*)
    integer(c_int), intent(in) :: layout
    integer(c_int64_t), intent(in) :: ld
    st = mfree_assembler_set_quadrature_points_c(as%ptr, npts, x, layout, ld, w)
  end function mfree_assembler_set_quadrature_points

  !> Body force b(x); absent f removes it.
  integer(c_int) function mfree_assembler_set_body_force(as, f, user) result(st)
    type(mfree_assembler), intent(in) :: as
    procedure(mfree_field_fn), optional :: f
    type(c_ptr), intent(in), optional :: user
    type(c_funptr) :: fp
    fp = c_null_funptr
    if (present(f)) fp = c_funloc(f)
    st = mfree_assembler_set_body_force_c(as%ptr, fp, user_ptr(user))
  end function mfree_assembler_set_body_force

  !> Typed wrapper of mfree_assembler_add_traction (mfree.h).
  integer(c_int) function mfree_assembler_add_traction(as, npts, x, layout, ld, w, t, user) &
      result(st)
    type(mfree_assembler), intent(in) :: as
    integer(c_int32_t), intent(in) :: npts
    real(c_double), intent(in) :: x(*), w(*)
    integer(c_int), intent(in) :: layout
    integer(c_int64_t), intent(in) :: ld
    procedure(mfree_field_fn) :: t
    type(c_ptr), intent(in), optional :: user
    st = mfree_assembler_add_traction_c(as%ptr, npts, x, layout, ld, w, c_funloc(t), &
                                        user_ptr(user))
  end function mfree_assembler_add_traction

  !> Typed wrapper of mfree_assembler_add_traction_segments (mfree.h).
  integer(c_int) function mfree_assembler_add_traction_segments(as, nseg, x, ngauss, t, &
                                                                user) result(st)
    type(mfree_assembler), intent(in) :: as
    integer(c_int32_t), intent(in) :: nseg, ngauss
    real(c_double), intent(in) :: x(*)
    procedure(mfree_field_fn) :: t
    type(c_ptr), intent(in), optional :: user
    st = mfree_assembler_add_traction_segments_c(as%ptr, nseg, x, ngauss, c_funloc(t), &
                                                 user_ptr(user))
  end function mfree_assembler_add_traction_segments

  !> Traction on 3D triangles (9 coordinates each), ngauss x ngauss points per triangle.
  integer(c_int) function mfree_assembler_add_traction_facets(as, nfacet, x, ngauss, t, &
                                                              user) result(st)
    type(mfree_assembler), intent(in) :: as
    integer(c_int32_t), intent(in) :: nfacet, ngauss
    real(c_double), intent(in) :: x(*)
    procedure(mfree_field_fn) :: t
    type(c_ptr), intent(in), optional :: user
    st = mfree_assembler_add_traction_facets_c(as%ptr, nfacet, x, ngauss, c_funloc(t), &
                                               user_ptr(user))
  end function mfree_assembler_add_traction_facets

  !> Essential condition on boundary points; normals (dim per point) only for Nitsche.
  integer(c_int) function mfree_assembler_add_dirichlet(as, method, npts, x, layout, ld, w, &
                                                        normals, component_mask, g, user) &
      result(st)
    type(mfree_assembler), intent(in) :: as
    integer(c_int), intent(in) :: method, layout
    integer(c_int32_t), intent(in) :: npts, component_mask
    real(c_double), intent(in) :: x(*), w(*)
    integer(c_int64_t), intent(in) :: ld
    real(c_double), intent(in), optional, target :: normals(*)
    procedure(mfree_field_fn) :: g
    type(c_ptr), intent(in), optional :: user
    type(c_ptr) :: pn
    pn = c_null_ptr
    if (present(normals)) pn = c_loc(normals)
    st = mfree_assembler_add_dirichlet_c(as%ptr, method, npts, x, layout, ld, w, pn, &
                                         component_mask, c_funloc(g), user_ptr(user))
  end function mfree_assembler_add_dirichlet

  !> Row replacement at particles; nodes are 0-based particle indices.
  integer(c_int) function mfree_assembler_add_dirichlet_nodes(as, nnodes, nodes, &
                                                              component_mask, g, user) &
      result(st)
    type(mfree_assembler), intent(in) :: as
    integer(c_int32_t), intent(in) :: nnodes, component_mask
    integer(c_int32_t), intent(in) :: nodes(*)
    procedure(mfree_field_fn) :: g
    type(c_ptr), intent(in), optional :: user
    st = mfree_assembler_add_dirichlet_nodes_c(as%ptr, nnodes, nodes, component_mask, &
                                               c_funloc(g), user_ptr(user))
  end function mfree_assembler_add_dirichlet_nodes

  !> Collocation traction rows at particles (0-based indices), normals dim per node.
  integer(c_int) function mfree_assembler_add_traction_nodes(as, nnodes, nodes, normals, t, &
                                                             user) result(st)
    type(mfree_assembler), intent(in) :: as
    integer(c_int32_t), intent(in) :: nnodes
    integer(c_int32_t), intent(in) :: nodes(*)
    real(c_double), intent(in) :: normals(*)
    procedure(mfree_field_fn) :: t
    type(c_ptr), intent(in), optional :: user
    st = mfree_assembler_add_traction_nodes_c(as%ptr, nnodes, nodes, normals, c_funloc(t), &
                                              user_ptr(user))
  end function mfree_assembler_add_traction_nodes

  !> Finite-element blending layer; connectivity and gu are 0-based particle indices.
  integer(c_int) function mfree_assembler_set_fe_layer(as, nelem, nodes_per_element, &
                                                       connectivity, ngu, gu, &
                                                       component_mask, g, user) result(st)
    type(mfree_assembler), intent(in) :: as
    integer(c_int32_t), intent(in) :: nelem, nodes_per_element, ngu, component_mask
    integer(c_int32_t), intent(in) :: connectivity(*), gu(*)
    procedure(mfree_field_fn) :: g
    type(c_ptr), intent(in), optional :: user
    st = mfree_assembler_set_fe_layer_c(as%ptr, nelem, nodes_per_element, connectivity, &
                                        ngu, gu, component_mask, c_funloc(g), user_ptr(user))
  end function mfree_assembler_set_fe_layer

  !> Typed wrapper of mfree_assembler_set_penalty (mfree.h).
  integer(c_int) function mfree_assembler_set_penalty(as, alpha) result(st)
    type(mfree_assembler), intent(in) :: as
    real(c_double), intent(in) :: alpha
    st = mfree_assembler_set_penalty_c(as%ptr, alpha)
  end function mfree_assembler_set_penalty

  !> Variationally consistent integration: the whole boundary as points, weights and
  !> outward unit normals (dim per point); npts = 0 switches it off.
  integer(c_int) function mfree_assembler_set_consistent_integration(as, npts, x, layout, ld, &
                                                                     w, normals) result(st)
    type(mfree_assembler), intent(in) :: as
    integer(c_int32_t), intent(in) :: npts
    real(c_double), intent(in) :: x(*), w(*), normals(*)
    integer(c_int), intent(in) :: layout
    integer(c_int64_t), intent(in) :: ld
    st = mfree_assembler_set_consistent_integration_c(as%ptr, npts, x, layout, ld, w, normals)
  end function mfree_assembler_set_consistent_integration

  !> Typed wrapper of mfree_assembler_setup (mfree.h).
  integer(c_int) function mfree_assembler_setup(as) result(st)
    type(mfree_assembler), intent(in) :: as
    st = mfree_assembler_setup_c(as%ptr)
  end function mfree_assembler_setup

  !> Typed wrapper of mfree_assembler_update (mfree.h).
  integer(c_int) function mfree_assembler_update(as) result(st)
    type(mfree_assembler), intent(in) :: as
    st = mfree_assembler_update_c(as%ptr)
  end function mfree_assembler_update

  !> Typed wrapper of mfree_assembler_get_size (mfree.h).
  integer(c_int) function mfree_assembler_get_size(as, ndofs, nquad) result(st)
    type(mfree_assembler), intent(in) :: as
    integer(c_int32_t), intent(out), optional, target :: ndofs, nquad
    type(c_ptr) :: pd, pq
    pd = c_null_ptr
    pq = c_null_ptr
    if (present(ndofs)) pd = c_loc(ndofs)
    if (present(nquad)) pq = c_loc(nquad)
    st = mfree_assembler_get_size_c(as%ptr, pd, pq)
  end function mfree_assembler_get_size

  !> K null: a new matrix; else refilled (same pattern kept when it did not change).
  integer(c_int) function mfree_assembler_assemble_matrix(as, K) result(st)
    type(mfree_assembler), intent(in) :: as
    type(mfree_matrix), intent(inout) :: K
    st = mfree_assembler_assemble_matrix_c(as%ptr, K%ptr)
  end function mfree_assembler_assemble_matrix

  !> f must be contiguous and hold ndofs values (else MFREE_ERR_ARG).
  integer(c_int) function mfree_assembler_assemble_rhs(as, f) result(st)
    type(mfree_assembler), intent(in) :: as
    real(c_double), intent(out), target :: f(:)
    integer(c_int32_t), target :: ndofs
    type(c_ptr) :: ctx
    st = mfree_assembler_get_size_c(as%ptr, c_loc(ndofs), c_null_ptr)
    if (st /= MFREE_SUCCESS) return
    ctx = c_null_ptr
    st = mfree_assembler_get_context_c(as%ptr, ctx)
    st = check_out(ctx, 'mfree_assembler_assemble_rhs', 'f', is_contiguous(f), &
                   size(f, kind=c_int64_t), int(ndofs, c_int64_t))
    if (st /= MFREE_SUCCESS) return
    st = mfree_assembler_assemble_rhs_c(as%ptr, f)
  end function mfree_assembler_assemble_rhs

  !> Typed wrapper of mfree_assembler_get_context (mfree.h).
  integer(c_int) function mfree_assembler_get_context(as, ctx) result(st)
    type(mfree_assembler), intent(in) :: as
    type(mfree_context), intent(out) :: ctx
    st = mfree_assembler_get_context_c(as%ptr, ctx%ptr)
  end function mfree_assembler_get_context

  ! ==== semi-discrete particle systems =================================================

  !> State y((2 dim + 1) n): positions y(1 : dim n) as x(dim, n), velocity parameters
  !> as v(dim, n), then the n densities.
  integer(c_int) function mfree_system_create_fluid(ctx, dim, n, sys) result(st)
    type(mfree_context), intent(in) :: ctx
    integer(c_int32_t), intent(in) :: dim, n
    type(mfree_system), intent(out) :: sys
    st = mfree_system_create_fluid_c(ctx%ptr, dim, n, sys%ptr)
  end function mfree_system_create_fluid

  !> Typed wrapper of mfree_system_destroy (mfree.h).
  integer(c_int) function mfree_system_destroy(sys) result(st)
    type(mfree_system), intent(inout) :: sys
    st = mfree_system_destroy_c(sys%ptr)
  end function mfree_system_destroy

  !> Rest densities rho0 (array with stride, or one value with stride 0; copied).
  integer(c_int) function mfree_system_set_fluid_array(sys, rho0, stride, kappa, gamma, mu) &
      result(st)
    type(mfree_system), intent(in) :: sys
    real(c_double), intent(in) :: rho0(*)
    integer(c_int64_t), intent(in) :: stride
    real(c_double), intent(in) :: kappa, gamma, mu
    st = mfree_system_set_fluid_c(sys%ptr, rho0, stride, kappa, gamma, mu)
  end function mfree_system_set_fluid_array

  !> Typed wrapper of mfree_system_set_fluid_scalar (mfree.h).
  integer(c_int) function mfree_system_set_fluid_scalar(sys, rho0, stride, kappa, gamma, mu) &
      result(st)
    type(mfree_system), intent(in) :: sys
    real(c_double), intent(in) :: rho0
    integer(c_int64_t), intent(in) :: stride
    real(c_double), intent(in) :: kappa, gamma, mu
    real(c_double) :: one(1)
    one(1) = rho0  ! copied by mfree: a local array will do
    st = mfree_system_set_fluid_c(sys%ptr, one, stride, kappa, gamma, mu)
  end function mfree_system_set_fluid_scalar

  !> Typed wrapper of mfree_system_set_masses_array (mfree.h).
  integer(c_int) function mfree_system_set_masses_array(sys, m, stride) result(st)
    type(mfree_system), intent(in) :: sys
    real(c_double), intent(in) :: m(*)
    integer(c_int64_t), intent(in) :: stride
    st = mfree_system_set_masses_c(sys%ptr, m, stride)
  end function mfree_system_set_masses_array

  !> Typed wrapper of mfree_system_set_masses_scalar (mfree.h).
  integer(c_int) function mfree_system_set_masses_scalar(sys, m, stride) result(st)
    type(mfree_system), intent(in) :: sys
    real(c_double), intent(in) :: m
    integer(c_int64_t), intent(in) :: stride
    real(c_double) :: one(1)
    one(1) = m
    st = mfree_system_set_masses_c(sys%ptr, one, stride)
  end function mfree_system_set_masses_scalar

  !> Typed wrapper of mfree_system_set_smoothing (mfree.h).
  integer(c_int) function mfree_system_set_smoothing(sys, h) result(st)
    type(mfree_system), intent(in) :: sys
    real(c_double), intent(in) :: h
    st = mfree_system_set_smoothing_c(sys%ptr, h)
  end function mfree_system_set_smoothing

  !> Typed wrapper of mfree_system_set_gravity (mfree.h).
  integer(c_int) function mfree_system_set_gravity(sys, g) result(st)
    type(mfree_system), intent(in) :: sys
    real(c_double), intent(in) :: g(*)
    st = mfree_system_set_gravity_c(sys%ptr, g)
  end function mfree_system_set_gravity

  !> Typed wrapper of mfree_system_set_lumping (mfree.h).
  integer(c_int) function mfree_system_set_lumping(sys, lump) result(st)
    type(mfree_system), intent(in) :: sys
    integer(c_int), intent(in) :: lump
    st = mfree_system_set_lumping_c(sys%ptr, lump)
  end function mfree_system_set_lumping

  !> Wall particles x(dim, nwall) with unit normals(dim, nwall) into the fluid (copied).
  integer(c_int) function mfree_system_set_walls(sys, nwall, x, normals, r0, strength) &
      result(st)
    type(mfree_system), intent(in) :: sys
    integer(c_int32_t), intent(in) :: nwall
    real(c_double), intent(in) :: x(*), normals(*)
    real(c_double), intent(in) :: r0, strength
    st = mfree_system_set_walls_c(sys%ptr, nwall, x, normals, r0, strength)
  end function mfree_system_set_walls

  !> Dummy wall particles x(dim, n) with volumes (stride 0: one value), copied; n = 0 removes them.
  integer(c_int) function mfree_system_set_dummy_particles(sys, n, x, volumes, stride) &
      result(st)
    type(mfree_system), intent(in) :: sys
    integer(c_int32_t), intent(in) :: n
    real(c_double), intent(in) :: x(*), volumes(*)
    integer(c_int64_t), intent(in) :: stride
    st = mfree_system_set_dummy_particles_c(sys%ptr, n, x, volumes, stride)
  end function mfree_system_set_dummy_particles

  !> delta-SPH density diffusion coefficient (default 0 = off; usual 0.1).
  integer(c_int) function mfree_system_set_density_diffusion(sys, delta) result(st)
    type(mfree_system), intent(in) :: sys
    real(c_double), intent(in) :: delta
    st = mfree_system_set_density_diffusion_c(sys%ptr, delta)
  end function mfree_system_set_density_diffusion

  !> Consistent nodal integration of the fluid (constant correction): 0 off (default), 1 on.
  integer(c_int) function mfree_system_set_consistent_integration(sys, on) result(st)
    type(mfree_system), intent(in) :: sys
    integer(c_int32_t), intent(in) :: on
    st = mfree_system_set_consistent_integration_c(sys%ptr, on)
  end function mfree_system_set_consistent_integration

  !> Conservative velocity smoothing coefficient beta of the fluid (default 0 = off; 0.1).
  integer(c_int) function mfree_system_set_velocity_smoothing(sys, beta) result(st)
    type(mfree_system), intent(in) :: sys
    real(c_double), intent(in) :: beta
    st = mfree_system_set_velocity_smoothing_c(sys%ptr, beta)
  end function mfree_system_set_velocity_smoothing

  !> The fluid's CFL step with the Galerkin lumped masses: 0 off (default, eq 120), 1 on.
  integer(c_int) function mfree_system_set_lumped_mass_step(sys, on) result(st)
    type(mfree_system), intent(in) :: sys
    integer(c_int32_t), intent(in) :: on
    st = mfree_system_set_lumped_mass_step_c(sys%ptr, on)
  end function mfree_system_set_lumped_mass_step

  !> The fluid's step also bounded by the acoustic operator's largest frequency: 0 off (default), 1 on.
  integer(c_int) function mfree_system_set_acoustic_step(sys, on) result(st)
    type(mfree_system), intent(in) :: sys
    integer(c_int32_t), intent(in) :: on
    st = mfree_system_set_acoustic_step_c(sys%ptr, on)
  end function mfree_system_set_acoustic_step

  !> Typed wrapper of mfree_system_set_box (mfree.h).
  integer(c_int) function mfree_system_set_box(sys, lo, hi) result(st)
    type(mfree_system), intent(in) :: sys
    real(c_double), intent(in) :: lo(*), hi(*)
    st = mfree_system_set_box_c(sys%ptr, lo, hi)
  end function mfree_system_set_box

  !> Typed wrapper of mfree_system_get_size (mfree.h).
  integer(c_int) function mfree_system_get_size(sys, neq) result(st)
    type(mfree_system), intent(in) :: sys
    integer(c_int32_t), intent(out) :: neq
    st = mfree_system_get_size_c(sys%ptr, neq)
  end function mfree_system_get_size

  !> MFREE_SUCCESS when an output of a system (per: values per particle, 0: neq values)
  !> is contiguous and large enough.
  integer(c_int) function check_system_out(sys, fn, what, contig, have, per) result(st)
    type(mfree_system), intent(in) :: sys
    character(len=*), intent(in) :: fn, what
    logical, intent(in) :: contig
    integer(c_int64_t), intent(in) :: have
    integer, intent(in) :: per
    integer(c_int32_t), target :: dim, n
    integer(c_int32_t) :: neq
    integer(c_int64_t) :: need
    type(c_ptr) :: ctx
    if (per == 0) then
      st = mfree_system_get_size_c(sys%ptr, neq)
      need = neq
    else
      st = mfree_system_get_dimension_c(sys%ptr, c_loc(dim), c_loc(n))
      select case (per)
      case (-1)  ! dim per particle
        need = int(dim, c_int64_t) * n
      case (-2)  ! stress components per particle
        need = int(merge(1, merge(3, 6, dim == 2), dim == 1), c_int64_t) * n
      case default
        need = int(per, c_int64_t) * n
      end select
    end if
    if (st /= MFREE_SUCCESS) return
    ctx = c_null_ptr
    st = mfree_system_get_context_c(sys%ptr, ctx)
    st = check_out(ctx, fn, what, contig, have, need)
  end function check_system_out

  !> A caller array's fault st that a system wrapper found (its message recorded on the
  !> system's context) made pending on the system (mfree_system_set_pending_error): the
  !> collective call the wrapper then still makes, on empty stand-ins of the faulty arrays,
  !> returns st on every rank with this rank's message, so that no rank waits for this
  !> one. .false. when it cannot be made pending (a NULL system): the wrapper returns st.
  logical function pend_system_fault(sys, st) result(pending)
    type(mfree_system), intent(in) :: sys
    integer(c_int), intent(in) :: st
    character(kind=c_char), target :: msg(512)
    type(c_ptr) :: ctx
    pending = .false.
    ctx = c_null_ptr
    if (mfree_system_get_context_c(sys%ptr, ctx) /= MFREE_SUCCESS) return
    msg = c_null_char
    if (mfree_context_get_last_error_c(ctx, c_null_ptr, c_loc(msg), size(msg, kind=c_int64_t)) /= &
        MFREE_SUCCESS) return
    pending = mfree_system_set_pending_error_c(sys%ptr, st, c_loc(msg)) == MFREE_SUCCESS
  end function pend_system_fault

  !> ydot must be contiguous and hold neq values (else MFREE_ERR_ARG, on ranks on every
  !> rank: the wrappers of collective calls hand the fault to the C call, pend_system_fault).
  integer(c_int) function mfree_system_rhs(sys, t, y, ydot) result(st)
    type(mfree_system), intent(in) :: sys
    real(c_double), intent(in) :: t
    real(c_double), intent(in) :: y(*)
    real(c_double), intent(out), target :: ydot(:)
    st = check_system_out(sys, 'mfree_system_rhs', 'ydot', is_contiguous(ydot), &
                          size(ydot, kind=c_int64_t), 0)
    if (st /= MFREE_SUCCESS) then
      if (pend_system_fault(sys, st)) st = mfree_system_rhs_c(sys%ptr, t, y, empty_dbl)
      return
    end if
    st = mfree_system_rhs_c(sys%ptr, t, y, ydot)
  end function mfree_system_rhs

  !> p must be contiguous and hold n values (else MFREE_ERR_ARG).
  integer(c_int) function mfree_system_get_pressure(sys, y, p) result(st)
    type(mfree_system), intent(in) :: sys
    real(c_double), intent(in) :: y(*)
    real(c_double), intent(out), target :: p(:)
    st = check_system_out(sys, 'mfree_system_get_pressure', 'p', is_contiguous(p), &
                          size(p, kind=c_int64_t), 1)
    if (st /= MFREE_SUCCESS) return
    st = mfree_system_get_pressure_c(sys%ptr, y, p)
  end function mfree_system_get_pressure

  !> vhat(dim, n), contiguous (else MFREE_ERR_ARG, on ranks on every rank).
  integer(c_int) function mfree_system_get_velocity(sys, y, vhat) result(st)
    type(mfree_system), intent(in) :: sys
    real(c_double), intent(in) :: y(*)
    real(c_double), intent(out), target :: vhat(..)
    real(c_double), pointer :: pv(:)
    st = check_system_out(sys, 'mfree_system_get_velocity', 'vhat', is_contiguous(vhat), &
                          size(vhat, kind=c_int64_t), -1)
    if (st /= MFREE_SUCCESS) then
      if (pend_system_fault(sys, st)) st = mfree_system_get_velocity_c(sys%ptr, y, empty_dbl)
      return
    end if
    pv => empty_dbl
    if (size(vhat) > 0) call c_f_pointer(c_loc(vhat), pv, [size(vhat)])
    st = mfree_system_get_velocity_c(sys%ptr, y, pv)
  end function mfree_system_get_velocity

  !> The walls' force on the fluid at state y: total (dim values, contiguous) and, when
  !> present, per_wall(dim, nwall) for the system's nwall wall particles (contiguous;
  !> its size a multiple of dim; else MFREE_ERR_ARG, on ranks on every rank; an empty one
  !> is ignored).
  integer(c_int) function mfree_system_get_wall_force(sys, y, total, per_wall) result(st)
    type(mfree_system), intent(in) :: sys
    real(c_double), intent(in) :: y(*)
    real(c_double), intent(out), target :: total(:)
    real(c_double), intent(out), target, optional :: per_wall(..)
    integer(c_int32_t), target :: dim, n
    integer(c_int32_t) :: nwall
    type(c_ptr) :: ctx, pw
    st = mfree_system_get_dimension_c(sys%ptr, c_loc(dim), c_loc(n))
    if (st /= MFREE_SUCCESS) return
    ctx = c_null_ptr
    st = mfree_system_get_context_c(sys%ptr, ctx)
    st = check_out(ctx, 'mfree_system_get_wall_force', 'total', is_contiguous(total), &
                   size(total, kind=c_int64_t), int(dim, c_int64_t))
    pw = c_null_ptr
    nwall = 0
    if (st == MFREE_SUCCESS .and. present(per_wall)) then
      if (.not. is_contiguous(per_wall) .or. mod(size(per_wall), dim) /= 0) then
        st = wrapper_error(ctx, MFREE_ERR_ARG, 'mfree_system_get_wall_force: per_wall is not ' // &
                           'contiguous or its size ' // int_str(size(per_wall, kind=c_int64_t)) // &
                           ' is not a multiple of dim')
      else
        nwall = int(size(per_wall) / dim, c_int32_t)
        if (size(per_wall) > 0) pw = c_loc(per_wall)
      end if
    end if
    if (st /= MFREE_SUCCESS) then
      if (pend_system_fault(sys, st)) &
        st = mfree_system_get_wall_force_c(sys%ptr, y, c_null_ptr, 0_c_int32_t, c_null_ptr)
      return
    end if
    st = mfree_system_get_wall_force_c(sys%ptr, y, c_loc(total), nwall, pw)
  end function mfree_system_get_wall_force

  !> Particles 0 .. nactive - 1 active, the others dormant (open boundaries, mfree.h).
  integer(c_int) function mfree_system_set_active(sys, nactive) result(st)
    type(mfree_system), intent(in) :: sys
    integer(c_int32_t), intent(in) :: nactive
    st = mfree_system_set_active_c(sys%ptr, nactive)
  end function mfree_system_set_active

  !> Inflow gate (mfree.h): origin(dim), edges(dim * (dim - 1)), normal(dim), each at
  !> least that long (else MFREE_ERR_ARG).
  integer(c_int) function mfree_system_set_inflow(sys, gate, origin, edges, normal, speed, &
                                                  density, spacing) result(st)
    type(mfree_system), intent(in) :: sys
    integer(c_int32_t), intent(in) :: gate
    real(c_double), intent(in) :: origin(:), edges(:), normal(:)
    real(c_double), intent(in) :: speed, density, spacing
    integer(c_int32_t), target :: dim, n
    type(c_ptr) :: ctx
    st = mfree_system_get_dimension_c(sys%ptr, c_loc(dim), c_loc(n))
    if (st /= MFREE_SUCCESS) return
    ctx = c_null_ptr
    st = mfree_system_get_context_c(sys%ptr, ctx)
    st = check_out(ctx, 'mfree_system_set_inflow', 'origin', .true., size(origin, kind=c_int64_t), &
                   int(dim, c_int64_t))
    if (st == MFREE_SUCCESS) &
      st = check_out(ctx, 'mfree_system_set_inflow', 'edges', .true., size(edges, kind=c_int64_t), &
                     int(dim, c_int64_t) * (dim - 1))
    if (st == MFREE_SUCCESS) &
      st = check_out(ctx, 'mfree_system_set_inflow', 'normal', .true., size(normal, kind=c_int64_t), &
                     int(dim, c_int64_t))
    if (st /= MFREE_SUCCESS) return
    st = mfree_system_set_inflow_c(sys%ptr, gate, origin, edges, normal, speed, density, spacing)
  end function mfree_system_set_inflow

  !> Outflow plane (mfree.h): point(dim), normal(dim) (else MFREE_ERR_ARG).
  integer(c_int) function mfree_system_set_outflow(sys, k, point, normal) result(st)
    type(mfree_system), intent(in) :: sys
    integer(c_int32_t), intent(in) :: k
    real(c_double), intent(in) :: point(:), normal(:)
    integer(c_int32_t), target :: dim, n
    type(c_ptr) :: ctx
    st = mfree_system_get_dimension_c(sys%ptr, c_loc(dim), c_loc(n))
    if (st /= MFREE_SUCCESS) return
    ctx = c_null_ptr
    st = mfree_system_get_context_c(sys%ptr, ctx)
    st = check_out(ctx, 'mfree_system_set_outflow', 'point', .true., size(point, kind=c_int64_t), &
                   int(dim, c_int64_t))
    if (st == MFREE_SUCCESS) &
      st = check_out(ctx, 'mfree_system_set_outflow', 'normal', .true., size(normal, kind=c_int64_t), &
                     int(dim, c_int64_t))
    if (st /= MFREE_SUCCESS) return
    st = mfree_system_set_outflow_c(sys%ptr, k, point, normal)
  end function mfree_system_set_outflow

  !> Update the open boundaries at t; y holds neq values, contiguous (else MFREE_ERR_ARG).
  integer(c_int) function mfree_system_update_open_boundaries(sys, t, y) result(st)
    type(mfree_system), intent(in) :: sys
    real(c_double), intent(in) :: t
    real(c_double), intent(inout), target :: y(:)
    st = check_system_out(sys, 'mfree_system_update_open_boundaries', 'y', is_contiguous(y), &
                          size(y, kind=c_int64_t), 0)
    if (st /= MFREE_SUCCESS) return
    st = mfree_system_update_open_boundaries_c(sys%ptr, t, y)
  end function mfree_system_update_open_boundaries

  !> Active count; state (optional) receives n values, its size exactly n (else MFREE_ERR_ARG).
  integer(c_int) function mfree_system_get_active(sys, nactive, state) result(st)
    type(mfree_system), intent(in) :: sys
    integer(c_int32_t), intent(out) :: nactive
    integer(c_int32_t), intent(out), target, optional :: state(:)
    integer(c_int32_t) :: ns
    type(c_ptr) :: ps
    ps = c_null_ptr
    ns = 0
    if (present(state)) then
      st = check_system_out(sys, 'mfree_system_get_active', 'state', is_contiguous(state), &
                            size(state, kind=c_int64_t), 1)
      if (st /= MFREE_SUCCESS) return
      ns = int(size(state), c_int32_t)
      if (size(state) > 0) ps = c_loc(state)
    end if
    st = mfree_system_get_active_c(sys%ptr, nactive, ns, ps)
  end function mfree_system_get_active

  !> Particles a gate released into the fluid and their mass.
  integer(c_int) function mfree_system_get_inflow(sys, gate, count, mass) result(st)
    type(mfree_system), intent(in) :: sys
    integer(c_int32_t), intent(in) :: gate
    integer(c_int64_t), intent(out) :: count
    real(c_double), intent(out) :: mass
    st = mfree_system_get_inflow_c(sys%ptr, gate, count, mass)
  end function mfree_system_get_inflow

  !> Particles an outflow plane returned to the pool and their mass.
  integer(c_int) function mfree_system_get_outflow(sys, k, count, mass) result(st)
    type(mfree_system), intent(in) :: sys
    integer(c_int32_t), intent(in) :: k
    integer(c_int64_t), intent(out) :: count
    real(c_double), intent(out) :: mass
    st = mfree_system_get_outflow_c(sys%ptr, k, count, mass)
  end function mfree_system_get_outflow

  !> Integrate y (neq values, contiguous: else MFREE_ERR_ARG, on ranks on every rank, y and t
  !> unchanged) from t to t_end (both updated
  !> in place); progress (optional) is called after every accepted step; nsteps
  !> (optional) receives the number of steps.
  integer(c_int) function mfree_system_integrate(sys, scheme, y, t, t_end, cfl, dt_max, &
                                                 progress, user, nsteps) result(st)
    type(mfree_system), intent(in) :: sys
    integer(c_int), intent(in) :: scheme
    real(c_double), intent(inout), target :: y(:)
    real(c_double), intent(inout) :: t
    real(c_double), intent(in) :: t_end, cfl, dt_max
    procedure(mfree_progress_fn), optional :: progress
    type(c_ptr), intent(in), optional :: user
    integer(c_int64_t), intent(out), optional, target :: nsteps
    type(c_funptr) :: fp
    type(c_ptr) :: pn
    st = check_system_out(sys, 'mfree_system_integrate', 'y', is_contiguous(y), &
                          size(y, kind=c_int64_t), 0)
    fp = c_null_funptr
    pn = c_null_ptr
    if (present(progress)) fp = c_funloc(progress)
    if (present(nsteps)) pn = c_loc(nsteps)
    if (st /= MFREE_SUCCESS) then
      if (pend_system_fault(sys, st)) &
        st = mfree_system_integrate_c(sys%ptr, scheme, empty_dbl, t, t_end, cfl, dt_max, fp, &
                                      user_ptr(user), pn)
      return
    end if
    st = mfree_system_integrate_c(sys%ptr, scheme, y, t, t_end, cfl, dt_max, fp, &
                                  user_ptr(user), pn)
  end function mfree_system_integrate

  !> consistent: 0 lumped, nonzero consistent velocity block. M null: created.
  integer(c_int) function mfree_system_assemble_mass(sys, y, consistent, M) result(st)
    type(mfree_system), intent(in) :: sys
    real(c_double), intent(in) :: y(*)
    integer(c_int32_t), intent(in) :: consistent
    type(mfree_matrix), intent(inout) :: M
    st = mfree_system_assemble_mass_c(sys%ptr, y, consistent, M%ptr)
  end function mfree_system_assemble_mass

  !> Typed wrapper of mfree_system_assemble_interpolation (mfree.h).
  integer(c_int) function mfree_system_assemble_interpolation(sys, y, S) result(st)
    type(mfree_system), intent(in) :: sys
    real(c_double), intent(in) :: y(*)
    type(mfree_matrix), intent(inout) :: S
    st = mfree_system_assemble_interpolation_c(sys%ptr, y, S%ptr)
  end function mfree_system_assemble_interpolation

  !> Mv = M(y) v (consistent: 0 lumped, nonzero consistent); Mv must be contiguous and
  !> hold neq values (else MFREE_ERR_ARG, on ranks on every rank).
  integer(c_int) function mfree_system_apply_mass(sys, y, consistent, v, Mv) result(st)
    type(mfree_system), intent(in) :: sys
    real(c_double), intent(in) :: y(*)
    integer(c_int32_t), intent(in) :: consistent
    real(c_double), intent(in) :: v(*)
    real(c_double), intent(out), target :: Mv(:)
    st = check_system_out(sys, 'mfree_system_apply_mass', 'Mv', is_contiguous(Mv), &
                          size(Mv, kind=c_int64_t), 0)
    if (st /= MFREE_SUCCESS) then
      if (pend_system_fault(sys, st)) st = mfree_system_apply_mass_c(sys%ptr, y, consistent, v, empty_dbl)
      return
    end if
    st = mfree_system_apply_mass_c(sys%ptr, y, consistent, v, Mv)
  end function mfree_system_apply_mass

  !> Elastodynamics by collocation on a set-up collocation assembler (kept alive).
  integer(c_int) function mfree_system_create_elastodynamic(ctx, as, density, sys) result(st)
    type(mfree_context), intent(in) :: ctx
    type(mfree_assembler), intent(in) :: as
    real(c_double), intent(in) :: density
    type(mfree_system), intent(out) :: sys
    st = mfree_system_create_elastodynamic_c(ctx%ptr, as%ptr, density, sys%ptr)
  end function mfree_system_create_elastodynamic

  !> Typed wrapper of mfree_system_create_elastodynamic_ranks (mfree.h). exchange and
  !> allgather are C function pointers (c_funloc of bind(C) procedures with the
  !> interfaces of mfree_exchange_fn and mfree_allgather_fn); module mfree_mpi's
  !> mfree_halo_create_elastodynamic passes libmfree_mpi's own.
  integer(c_int) function mfree_system_create_elastodynamic_ranks(ctx, as, density, exchange, &
                                                                  allgather, user, sys) result(st)
    type(mfree_context), intent(in) :: ctx
    type(mfree_assembler), intent(in) :: as
    real(c_double), intent(in) :: density
    type(c_funptr), intent(in) :: exchange, allgather
    type(c_ptr), intent(in) :: user
    type(mfree_system), intent(out) :: sys
    st = mfree_system_create_elastodynamic_ranks_c(ctx%ptr, as%ptr, density, exchange, allgather, &
                                                   user, sys%ptr)
  end function mfree_system_create_elastodynamic_ranks

  !> Typed wrapper of mfree_system_create_fluid_ranks (mfree.h): global_ids holds the
  !> n_owned + n_ghost ids (checked: a shorter one is passed as n_ghost = -1 and no ids,
  !> which every rank refuses alike with MFREE_ERR_ARG, no system made; this rank's
  !> message then names global_ids); exchange and allgather as for
  !> mfree_system_create_elastodynamic_ranks; module mfree_mpi's mfree_halo_create_fluid
  !> passes libmfree_mpi's own.
  integer(c_int) function mfree_system_create_fluid_ranks(ctx, dim, n_owned, n_ghost, global_ids, &
                                                          width, exchange, allgather, user, sys) result(st)
    type(mfree_context), intent(in) :: ctx
    integer(c_int32_t), intent(in) :: dim, n_owned, n_ghost
    integer(c_int64_t), intent(in) :: global_ids(:)
    real(c_double), intent(in) :: width
    type(c_funptr), intent(in) :: exchange, allgather
    type(c_ptr), intent(in) :: user
    type(mfree_system), intent(out) :: sys
    integer(c_int64_t) :: none(1)
    none = 0
    if (n_owned >= 0 .and. n_ghost >= 0 .and. &
        size(global_ids, kind=c_int64_t) < int(n_owned, c_int64_t) + int(n_ghost, c_int64_t)) then
      st = mfree_system_create_fluid_ranks_c(ctx%ptr, dim, n_owned, -1_c_int32_t, none, width, exchange, &
                                             allgather, user, sys%ptr)
      if (st /= MFREE_SUCCESS) &
        st = wrapper_error(ctx%ptr, st, 'mfree_system_create_fluid_ranks: global_ids holds ' // &
                           int_str(size(global_ids, kind=c_int64_t)) // ' values, n_owned + n_ghost = ' // &
                           int_str(int(n_owned, c_int64_t) + int(n_ghost, c_int64_t)))
      return
    end if
    st = mfree_system_create_fluid_ranks_c(ctx%ptr, dim, n_owned, n_ghost, global_ids, width, exchange, &
                                           allgather, user, sys%ptr)
  end function mfree_system_create_fluid_ranks

  !> Typed wrapper of mfree_system_set_halo_rebuild (mfree.h): rebuild is the host's
  !> mfree_halo_rebuild_fn (c_funloc of a bind(C) function; c_null_funptr: none). Module
  !> mfree_mpi's mfree_halo_create_fluid sets libmfree_mpi's own.
  integer(c_int) function mfree_system_set_halo_rebuild(sys, rebuild) result(st)
    type(mfree_system), intent(in) :: sys
    type(c_funptr), intent(in) :: rebuild
    st = mfree_system_set_halo_rebuild_c(sys%ptr, rebuild)
  end function mfree_system_set_halo_rebuild

  !> Typed wrapper of mfree_system_move_particles (mfree.h): y holds at least capacity
  !> values (checked: a shorter y is passed as a capacity of -1, which every rank refuses
  !> alike with MFREE_ERR_ARG, nothing moved). Collective.
  integer(c_int) function mfree_system_move_particles(sys, n_new, move, move_user, y, capacity) result(st)
    type(mfree_system), intent(in) :: sys
    integer(c_int32_t), intent(in) :: n_new
    type(c_funptr), intent(in) :: move
    type(c_ptr), intent(in) :: move_user
    real(c_double), intent(inout), contiguous :: y(:)
    integer(c_int64_t), intent(in) :: capacity
    integer(c_int64_t) :: cap
    cap = capacity
    if (size(y, kind=c_int64_t) < capacity) cap = -1_c_int64_t
    st = mfree_system_move_particles_c(sys%ptr, n_new, move, move_user, y, cap)
  end function mfree_system_move_particles

  !> Condition threshold of the fluid's Shepard fallback (default 100).
  integer(c_int) function mfree_system_set_shepard_condition(sys, max_cond) result(st)
    type(mfree_system), intent(in) :: sys
    real(c_double), intent(in) :: max_cond
    st = mfree_system_set_shepard_condition_c(sys%ptr, max_cond)
  end function mfree_system_set_shepard_condition

  !> The fluid's shape functions: an approximant's method, order, kernel and shape parameter.
  integer(c_int) function mfree_system_set_approximation(sys, method, order, kernel, param) result(st)
    type(mfree_system), intent(in) :: sys
    integer(c_int), intent(in) :: method
    integer(c_int32_t), intent(in) :: order
    integer(c_int), intent(in) :: kernel
    real(c_double), intent(in) :: param
    st = mfree_system_set_approximation_c(sys%ptr, method, order, kernel, param)
  end function mfree_system_set_approximation

  !> Galerkin elastodynamics M u'' = g(t) f - K u from a stiffness and a mass assembler.
  integer(c_int) function mfree_system_create_elastodynamic_galerkin(ctx, stiffness, mass, sys) result(st)
    type(mfree_context), intent(in) :: ctx
    type(mfree_assembler), intent(in) :: stiffness, mass
    type(mfree_system), intent(out) :: sys
    st = mfree_system_create_elastodynamic_galerkin_c(ctx%ptr, stiffness%ptr, mass%ptr, sys%ptr)
  end function mfree_system_create_elastodynamic_galerkin

  !> Load history g(t) scaling the boundary data; absent g: back to the default 1.
  integer(c_int) function mfree_system_set_load_history(sys, g, user) result(st)
    type(mfree_system), intent(in) :: sys
    procedure(mfree_history_fn), optional :: g
    type(c_ptr), intent(in), optional :: user
    type(c_funptr) :: fp
    fp = c_null_funptr
    if (present(g)) fp = c_funloc(g)
    st = mfree_system_set_load_history_c(sys%ptr, fp, user_ptr(user))
  end function mfree_system_set_load_history

  !> Stress at the particles (1D: sigma(n); 2D: sigma(3, n) as xx, yy, xy) at time t;
  !> sigma contiguous and large enough (else MFREE_ERR_ARG, on ranks on every rank).
  integer(c_int) function mfree_system_get_stress(sys, t, y, sigma) result(st)
    type(mfree_system), intent(in) :: sys
    real(c_double), intent(in) :: t
    real(c_double), intent(in) :: y(*)
    real(c_double), intent(out), target :: sigma(..)
    real(c_double), pointer :: ps(:)
    st = check_system_out(sys, 'mfree_system_get_stress', 'sigma', is_contiguous(sigma), &
                          size(sigma, kind=c_int64_t), -2)
    if (st /= MFREE_SUCCESS) then
      if (pend_system_fault(sys, st)) st = mfree_system_get_stress_c(sys%ptr, t, y, empty_dbl)
      return
    end if
    ps => empty_dbl
    if (size(sigma) > 0) call c_f_pointer(c_loc(sigma), ps, [size(sigma)])
    st = mfree_system_get_stress_c(sys%ptr, t, y, ps)
  end function mfree_system_get_stress

  !> Typed wrapper of mfree_system_get_context (mfree.h).
  integer(c_int) function mfree_system_get_context(sys, ctx) result(st)
    type(mfree_system), intent(in) :: sys
    type(mfree_context), intent(out) :: ctx
    st = mfree_system_get_context_c(sys%ptr, ctx%ptr)
  end function mfree_system_get_context

  !> Typed wrapper of mfree_system_set_pending_error (mfree.h): the next collective call
  !> on sys returns status and message (absent: the status's description) on every rank.
  integer(c_int) function mfree_system_set_pending_error(sys, status, message) result(st)
    type(mfree_system), intent(in) :: sys
    integer(c_int), intent(in) :: status
    character(len=*), intent(in), optional :: message
    character(kind=c_char), allocatable, target :: buf(:)
    if (.not. present(message)) then
      st = mfree_system_set_pending_error_c(sys%ptr, status, c_null_ptr)
      return
    end if
    call to_c_chars(message, buf)
    st = mfree_system_set_pending_error_c(sys%ptr, status, c_loc(buf))
  end function mfree_system_set_pending_error

  !> Spatial dimension and number of particles of a system (each optional).
  integer(c_int) function mfree_system_get_dimension(sys, dim, n) result(st)
    type(mfree_system), intent(in) :: sys
    integer(c_int32_t), intent(out), optional, target :: dim, n
    type(c_ptr) :: pd, pn
    pd = c_null_ptr
    pn = c_null_ptr
    if (present(dim)) pd = c_loc(dim)
    if (present(n)) pn = c_loc(n)
    st = mfree_system_get_dimension_c(sys%ptr, pd, pn)
  end function mfree_system_get_dimension

  !> The user pointer of a callback: c_null_ptr when absent.
  type(c_ptr) function user_ptr(user)
    type(c_ptr), intent(in), optional :: user
    user_ptr = c_null_ptr
    if (present(user)) user_ptr = user
  end function user_ptr

end module mfree
