!> module mfree_suitesparse: Fortran 2008 bindings of the SuiteSparse adapter
!> (adapters/suitesparse/include/mfree_suitesparse.h, library libmfree_suitesparse).
!> Built into libmfree_fortran_suitesparse only when the adapter is built; the core
!> module mfree (libmfree_fortran) never depends on SuiteSparse.
!>
!> Same two layers as module mfree: raw bind(C) interfaces, the C name with _c, with the exact C
!> types, and typed wrappers with the C names. The solver handle is type(mfree_solver)
!> (C: mfree_suitesparse_t): a type named mfree_suitesparse would clash with this
!> module's name in every program that uses it.
module mfree_suitesparse
  use, intrinsic :: iso_c_binding, only: c_int, c_int32_t, c_int64_t, c_double, c_ptr, &
    c_null_ptr, c_loc, c_f_pointer
  use mfree, only: mfree_context, mfree_matrix, MFREE_SUCCESS, mfree_wrapper_check_out, &
    mfree_wrapper_view_dbl
  implicit none
  private

  ! ---- mfree_solver_kind_t; values frozen --------------------------------------------
  integer(c_int), parameter, public :: MFREE_SOLVER_CHOLMOD = 1
  integer(c_int), parameter, public :: MFREE_SOLVER_UMFPACK = 2
  integer(c_int), parameter, public :: MFREE_SOLVER_KLU = 3

  !> A direct solver (C: mfree_suitesparse_t *).
  type, public :: mfree_solver
    type(c_ptr) :: ptr = c_null_ptr
  end type mfree_solver

  ! ---- raw bind(C) interfaces: one per public function of mfree_suitesparse.h -------
  interface
    integer(c_int) function mfree_suitesparse_create_c(ctx, kind, s) &
        bind(C, name="mfree_suitesparse_create")
      import :: c_int, c_ptr
      type(c_ptr), value :: ctx
      integer(c_int), value :: kind
      type(c_ptr), intent(out) :: s
    end function mfree_suitesparse_create_c

    integer(c_int) function mfree_suitesparse_destroy_c(s) &
        bind(C, name="mfree_suitesparse_destroy")
      import :: c_int, c_ptr
      type(c_ptr), intent(inout) :: s
    end function mfree_suitesparse_destroy_c

    integer(c_int) function mfree_suitesparse_set_index_width_c(s, bits) &
        bind(C, name="mfree_suitesparse_set_index_width")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: s
      integer(c_int32_t), value :: bits
    end function mfree_suitesparse_set_index_width_c

    integer(c_int) function mfree_suitesparse_set_rcond_threshold_c(s, threshold) &
        bind(C, name="mfree_suitesparse_set_rcond_threshold")
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: s
      real(c_double), value :: threshold
    end function mfree_suitesparse_set_rcond_threshold_c

    integer(c_int) function mfree_suitesparse_setup_c(s, A) &
        bind(C, name="mfree_suitesparse_setup")
      import :: c_int, c_ptr
      type(c_ptr), value :: s
      type(c_ptr), value :: A
    end function mfree_suitesparse_setup_c

    integer(c_int) function mfree_suitesparse_update_c(s, A) &
        bind(C, name="mfree_suitesparse_update")
      import :: c_int, c_ptr
      type(c_ptr), value :: s
      type(c_ptr), value :: A
    end function mfree_suitesparse_update_c

    integer(c_int) function mfree_suitesparse_solve_c(s, nrhs, b, ldb, x, ldx) &
        bind(C, name="mfree_suitesparse_solve")
      import :: c_int, c_int32_t, c_int64_t, c_double, c_ptr
      type(c_ptr), value :: s
      integer(c_int32_t), value :: nrhs
      real(c_double), intent(in) :: b(*)
      integer(c_int64_t), value :: ldb
      real(c_double), intent(inout) :: x(*)
      integer(c_int64_t), value :: ldx
    end function mfree_suitesparse_solve_c

    integer(c_int) function mfree_suitesparse_get_info_c(s, rcond, factor_nnz, index_width) &
        bind(C, name="mfree_suitesparse_get_info")
      import :: c_int, c_ptr
      type(c_ptr), value :: s
      type(c_ptr), value :: rcond
      type(c_ptr), value :: factor_nnz
      type(c_ptr), value :: index_width
    end function mfree_suitesparse_get_info_c

    integer(c_int) function mfree_suitesparse_get_context_c(s, ctx) &
        bind(C, name="mfree_suitesparse_get_context")
      import :: c_int, c_ptr
      type(c_ptr), value :: s
      type(c_ptr), intent(out) :: ctx
    end function mfree_suitesparse_get_context_c
  end interface
  public :: mfree_suitesparse_create_c, mfree_suitesparse_destroy_c
  public :: mfree_suitesparse_set_index_width_c, mfree_suitesparse_setup_c
  public :: mfree_suitesparse_update_c, mfree_suitesparse_solve_c
  public :: mfree_suitesparse_get_info_c, mfree_suitesparse_set_rcond_threshold_c
  public :: mfree_suitesparse_get_context_c

  public :: mfree_suitesparse_create, mfree_suitesparse_destroy
  public :: mfree_suitesparse_set_index_width, mfree_suitesparse_setup
  public :: mfree_suitesparse_update, mfree_suitesparse_solve, mfree_suitesparse_get_info
  public :: mfree_suitesparse_set_rcond_threshold, mfree_suitesparse_get_context

  real(c_double), target, save :: empty_dbl(0)

contains

  !> Typed wrapper of mfree_suitesparse_create (mfree_suitesparse.h).
  integer(c_int) function mfree_suitesparse_create(ctx, kind, s) result(st)
    type(mfree_context), intent(in) :: ctx
    integer(c_int), intent(in) :: kind
    type(mfree_solver), intent(out) :: s
    st = mfree_suitesparse_create_c(ctx%ptr, kind, s%ptr)
  end function mfree_suitesparse_create

  !> Typed wrapper of mfree_suitesparse_destroy (mfree_suitesparse.h).
  integer(c_int) function mfree_suitesparse_destroy(s) result(st)
    type(mfree_solver), intent(inout) :: s
    st = mfree_suitesparse_destroy_c(s%ptr)
  end function mfree_suitesparse_destroy

  !> 0 (automatic), 32 or 64.
  integer(c_int) function mfree_suitesparse_set_index_width(s, bits) result(st)
    type(mfree_solver), intent(in) :: s
    integer(c_int32_t), intent(in) :: bits
    st = mfree_suitesparse_set_index_width_c(s%ptr, bits)
  end function mfree_suitesparse_set_index_width

  !> Singularity threshold on the reciprocal condition estimate, in [0, 1); 0 disables.
  integer(c_int) function mfree_suitesparse_set_rcond_threshold(s, threshold) result(st)
    type(mfree_solver), intent(in) :: s
    real(c_double), intent(in) :: threshold
    st = mfree_suitesparse_set_rcond_threshold_c(s%ptr, threshold)
  end function mfree_suitesparse_set_rcond_threshold

  !> Typed wrapper of mfree_suitesparse_setup (mfree_suitesparse.h).
  integer(c_int) function mfree_suitesparse_setup(s, A) result(st)
    type(mfree_solver), intent(in) :: s
    type(mfree_matrix), intent(in) :: A
    st = mfree_suitesparse_setup_c(s%ptr, A%ptr)
  end function mfree_suitesparse_setup

  !> Typed wrapper of mfree_suitesparse_update (mfree_suitesparse.h).
  integer(c_int) function mfree_suitesparse_update(s, A) result(st)
    type(mfree_solver), intent(in) :: s
    type(mfree_matrix), intent(in) :: A
    st = mfree_suitesparse_update_c(s%ptr, A%ptr)
  end function mfree_suitesparse_update

  !> Solve A X = B, column-major b(ldb, nrhs), x(ldx, nrhs), arrays of any rank. Omit b
  !> to solve in place (x holds B on entry; ldb is then ldx): st =
  !> mfree_suitesparse_solve(s, nrhs, ldb=n, x=x, ldx=n). Passing the same array as b and
  !> x would alias two Fortran dummy arguments, which the standard forbids. x must be
  !> contiguous and hold ldx * nrhs values, b ldb * nrhs (a non-contiguous b is packed
  !> first): else MFREE_ERR_ARG, nothing written.
  integer(c_int) function mfree_suitesparse_solve(s, nrhs, b, ldb, x, ldx) result(st)
    type(mfree_solver), intent(in) :: s
    integer(c_int32_t), intent(in) :: nrhs
    real(c_double), intent(in), optional, target :: b(..)
    integer(c_int64_t), intent(in) :: ldb, ldx
    real(c_double), intent(inout), target :: x(..)
    character(len=*), parameter :: fn = 'mfree_suitesparse_solve'
    real(c_double), allocatable, target :: tb(:)
    real(c_double), pointer :: pb(:), px(:)
    integer(c_int64_t) :: k
    k = max(int(nrhs, c_int64_t), 0_c_int64_t)
    st = mfree_wrapper_check_out(solver_ctx(s), fn, 'x', is_contiguous(x), size(x, kind=c_int64_t), &
                                 max(ldx, 0_c_int64_t) * k)
    if (st == MFREE_SUCCESS .and. present(b)) &
      st = mfree_wrapper_check_out(solver_ctx(s), fn, 'b', .true., size(b, kind=c_int64_t), &
                                   max(ldb, 0_c_int64_t) * k)
    if (st /= MFREE_SUCCESS) return
    px => empty_dbl
    if (size(x) > 0) call c_f_pointer(c_loc(x), px, [size(x)])
    if (present(b)) then
      call mfree_wrapper_view_dbl(b, tb, pb)
    else
      pb => px
    end if
    st = mfree_suitesparse_solve_c(s%ptr, nrhs, pb, merge(ldb, ldx, present(b)), px, ldx)
  end function mfree_suitesparse_solve

  !> Typed wrapper of mfree_suitesparse_get_context (mfree_suitesparse.h): the solver's
  !> context, borrowed.
  integer(c_int) function mfree_suitesparse_get_context(s, ctx) result(st)
    type(mfree_solver), intent(in) :: s
    type(mfree_context), intent(out) :: ctx
    st = mfree_suitesparse_get_context_c(s%ptr, ctx%ptr)
  end function mfree_suitesparse_get_context

  !> The solver's context (NULL for a NULL handle), where the wrappers record failures.
  type(c_ptr) function solver_ctx(s) result(ctx)
    type(mfree_solver), intent(in) :: s
    integer(c_int) :: st
    ctx = c_null_ptr
    st = mfree_suitesparse_get_context_c(s%ptr, ctx)
  end function solver_ctx

  !> Facts about the current factorisation; each output optional.
  integer(c_int) function mfree_suitesparse_get_info(s, rcond, factor_nnz, index_width) &
      result(st)
    type(mfree_solver), intent(in) :: s
    real(c_double), intent(out), optional, target :: rcond
    integer(c_int64_t), intent(out), optional, target :: factor_nnz
    integer(c_int32_t), intent(out), optional, target :: index_width
    type(c_ptr) :: pr, pf, pw
    pr = c_null_ptr
    pf = c_null_ptr
    pw = c_null_ptr
    if (present(rcond)) pr = c_loc(rcond)
    if (present(factor_nnz)) pf = c_loc(factor_nnz)
    if (present(index_width)) pw = c_loc(index_width)
    st = mfree_suitesparse_get_info_c(s%ptr, pr, pf, pw)
  end function mfree_suitesparse_get_info

end module mfree_suitesparse
