!> t010 (Fortran twin of t001 and of the error checks of t101/t301): version constants
!> and the run-time version check, status names, a bad argument returning the
!> documented status with a message readable from Fortran (whole, truncated, through an
!> error handler written in Fortran), host-recorded errors, and null handles.
module t010_handler
  use, intrinsic :: iso_c_binding, only: c_int, c_ptr, c_f_pointer
  use mfree, only: mfree_c_string
  implicit none
  private
  public :: seen_t, on_error

  !> What the handler saw; reached through the user pointer.
  type :: seen_t
    integer :: calls = 0
    integer(c_int) :: code = 0
    character(len=:), allocatable :: message
  end type seen_t

contains

  subroutine on_error(user, code, message) bind(C)
    type(c_ptr), value :: user
    integer(c_int), value :: code
    type(c_ptr), value :: message
    type(seen_t), pointer :: seen
    call c_f_pointer(user, seen)
    seen%calls = seen%calls + 1
    seen%code = code
    seen%message = mfree_c_string(message)
  end subroutine on_error

end module t010_handler

program t010_context_errors_f
  use, intrinsic :: iso_c_binding
  use mfree
  use ftest
  use t010_handler
  implicit none

  type(mfree_context) :: ctx
  type(mfree_particles) :: ps, null_ps
  type(seen_t), target :: seen
  integer(c_int) :: st, code
  integer(c_int32_t) :: major, minor, patch, nthreads
  character(len=:), allocatable :: msg, long
  character(len=12) :: short
  real(c_double), target :: x(3, 4), r(2), w(2)
  integer :: i

  ! ---- versions ------------------------------------------------------------------------
  call check(mfree_version_check(), 'run-time library version compatible with the module')
  call check(mfree_version_string() == MFREE_MODULE_VERSION, &
             'mfree_version_string() == MFREE_MODULE_VERSION')
  st = mfree_version_get(major, minor, patch)
  call check(st == MFREE_SUCCESS .and. major == MFREE_VERSION_MAJOR .and. &
             minor == MFREE_VERSION_MINOR .and. patch == MFREE_VERSION_PATCH, &
             'mfree_version_get equals the module constants')
  st = mfree_version_get(minor=minor)
  call check(st == MFREE_SUCCESS .and. minor == MFREE_VERSION_MINOR, &
             'mfree_version_get with one output (the others NULL)')
  call check(mfree_version_ge(0, 0, 0), 'mfree_version_ge(0, 0, 0)')
  call check(mfree_version_ge(int(MFREE_VERSION_MAJOR), int(MFREE_VERSION_MINOR), &
                              int(MFREE_VERSION_PATCH)), 'mfree_version_ge(own version)')
  call check(.not. mfree_version_ge(int(MFREE_VERSION_MAJOR) + 1, 0, 0), &
             'not mfree_version_ge(next major)')

  ! ---- status names --------------------------------------------------------------------
  call check(len(mfree_status_string(MFREE_ERR_ARG)) > 0, 'MFREE_ERR_ARG has a name')
  call check(mfree_status_string(MFREE_ERR_ARG) /= mfree_status_string(MFREE_ERR_NULL), &
             'status names differ')
  call check(mfree_status_string(12345_c_int) == 'unknown status', &
             'an unknown status is "unknown status"')

  ! ---- a bad argument: documented status, readable message ------------------------------
  st = mfree_context_create(ctx)
  call check(st == MFREE_SUCCESS .and. c_associated(ctx%ptr), 'mfree_context_create')
  st = mfree_context_get_last_error(ctx, code)
  call check(st == MFREE_SUCCESS .and. code == MFREE_SUCCESS, 'no error recorded yet')

  st = mfree_particles_create(ctx, 4_c_int32_t, 10_c_int32_t, ps)
  call check(st == MFREE_ERR_ARG, 'dimension 4 is MFREE_ERR_ARG (mfree.h: dim 1, 2 or 3)')
  call check(.not. c_associated(ps%ptr), 'no particle set created')
  msg = mfree_last_error(ctx)
  write (*, '(a,a)') 'message: ', msg
  call check(index(msg, 'mfree_particles_create') == 1, &
             'the message names the failing function')
  st = mfree_context_get_last_error(ctx, code, short)
  call check(st == MFREE_SUCCESS .and. code == MFREE_ERR_ARG, 'last error code')
  call check(short == msg(1:len(short)), 'message truncated to len(message)')

  ! a leading dimension below dim is an argument error too (mfree.h: ld >= dim)
  st = mfree_particles_create(ctx, 3_c_int32_t, 4_c_int32_t, ps)
  call check_ok(ctx, st, 'mfree_particles_create')
  x = 0
  st = mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 2_c_int64_t, MFREE_COPY)
  call check(st == MFREE_ERR_ARG, 'AoS ld 2 < dim 3 is MFREE_ERR_ARG')
  call check(index(mfree_last_error(ctx), 'mfree_particles_set_positions') == 1, &
             'message of set_positions')
  st = mfree_particles_set_positions(ps, x, 42_c_int, 3_c_int64_t, MFREE_COPY)
  call check(st == MFREE_ERR_ARG, 'unknown layout is MFREE_ERR_ARG')

  ! an unknown kernel (any int may be passed from Fortran: the C enums are int)
  r = [0.1_c_double, 0.2_c_double]
  st = mfree_kernel_eval(ctx, 99_c_int, 2_c_int32_t, 0.0_c_double, 1.0_c_double, &
                         2_c_int64_t, r, w)
  call check(st == MFREE_ERR_ARG, 'unknown kernel is MFREE_ERR_ARG')
  st = mfree_context_set_num_threads(ctx, -1_c_int32_t)
  call check(st == MFREE_ERR_ARG, 'negative thread count is MFREE_ERR_ARG')
  st = mfree_context_set_num_threads(ctx, 2_c_int32_t)
  st = mfree_context_get_num_threads(ctx, nthreads)
  call check(st == MFREE_SUCCESS .and. nthreads == 2, 'thread count round trip')
  st = mfree_context_set_backend(ctx, 7_c_int32_t)
  call check(st == MFREE_ERR_ARG, 'unknown backend is MFREE_ERR_ARG')
  st = mfree_context_set_backend(ctx, MFREE_BACKEND_REF)
  st = mfree_context_get_backend(ctx, nthreads)
  call check(st == MFREE_SUCCESS .and. nthreads == MFREE_BACKEND_REF, 'backend round trip')
  st = mfree_context_set_backend(ctx, MFREE_BACKEND_OPT)
  st = mfree_context_set_page_hints(ctx, 4_c_int32_t)
  call check(st == MFREE_ERR_ARG, 'unknown page flags are MFREE_ERR_ARG')
  st = mfree_context_set_page_hints(ctx, ior(MFREE_PAGES_HUGE, MFREE_PAGES_PREFAULT))
  st = mfree_context_get_page_hints(ctx, nthreads)
  call check(st == MFREE_SUCCESS .and. nthreads == 3, 'page hints round trip')
  st = mfree_context_set_page_hints(ctx, MFREE_PAGES_DEFAULT)

  ! ---- null handles --------------------------------------------------------------------
  call check(mfree_particles_setup(null_ps) == MFREE_ERR_NULL, 'null particle set')
  call check(mfree_particles_destroy(null_ps) == MFREE_SUCCESS, 'destroy(null) is a no-op')

  ! ---- an error handler written in Fortran ----------------------------------------------
  st = mfree_context_set_error_handler(ctx, on_error, c_loc(seen))
  call check_ok(ctx, st, 'mfree_context_set_error_handler')
  st = mfree_particles_set_search(ps, 77_c_int, 2.0_c_double)
  call check(st == MFREE_ERR_ARG, 'unknown search convention is MFREE_ERR_ARG')
  call check(seen%calls == 1 .and. seen%code == MFREE_ERR_ARG, 'handler called once')
  if (allocated(seen%message)) then
    call check(seen%message == mfree_last_error(ctx), 'handler got the recorded message')
  else
    call check(.false., 'handler got a message')
  end if
  st = mfree_context_set_error_handler(ctx)  ! remove it
  st = mfree_particles_set_search(ps, 77_c_int, 2.0_c_double)
  call check(seen%calls == 1, 'removed handler is not called')

  ! ---- errors recorded by the host, long messages -----------------------------------------
  st = mfree_context_set_error(ctx, MFREE_FAIL_SINGULAR, 'host: custom failure')
  call check(st == MFREE_FAIL_SINGULAR, 'mfree_context_set_error returns the code')
  call check(mfree_last_error(ctx) == 'host: custom failure', 'host message round trip')
  allocate (character(len=1000) :: long)
  do i = 1, len(long)
    long(i:i) = achar(iachar('a') + mod(i, 26))
  end do
  st = mfree_context_set_error(ctx, MFREE_ERR_INPUT, long)
  call check(mfree_last_error(ctx) == long, 'a 1000-character message comes back whole')
  deallocate (long)  ! main-program allocatables are not freed at exit (LeakSanitizer)
  st = mfree_context_set_error(ctx, MFREE_ERR_STATE)
  msg = mfree_last_error(ctx)
  call check(st == MFREE_ERR_STATE .and. msg == '', 'no message (NULL) records an empty one')
  deallocate (msg)  ! as for long: LeakSanitizer reports main-program allocatables

  st = mfree_particles_destroy(ps)
  call check(st == MFREE_SUCCESS .and. .not. c_associated(ps%ptr), 'destroy nulls the handle')
  st = mfree_context_destroy(ctx)
  call check(st == MFREE_SUCCESS .and. .not. c_associated(ctx%ptr), 'context destroyed')
  call check(mfree_last_error(ctx) == '', 'message of a null context is empty')
  call finish('t010-context-errors-f')
end program t010_context_errors_f
