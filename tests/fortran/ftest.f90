!> Minimal test support for the Fortran twins: checks that count failures, a status
!> check that prints the context's message, a deterministic random generator, and a
!> summary that ends the program with a non-zero exit status when anything failed.
module ftest
  use, intrinsic :: iso_c_binding, only: c_int, c_int64_t, c_double
  use mfree, only: mfree_context, mfree_last_error, mfree_status_string, MFREE_SUCCESS
  implicit none
  private
  public :: check, check_ok, check_close, finish, rng_seed, rng_uniform

  integer, save :: nfail = 0, ncheck = 0
  integer(c_int64_t), save :: rng_state = 88172645463325252_c_int64_t

contains

  subroutine check(cond, what)
    logical, intent(in) :: cond
    character(len=*), intent(in) :: what
    ncheck = ncheck + 1
    if (.not. cond) then
      nfail = nfail + 1
      write (*, '(a,a)') 'FAILED: ', what
    end if
  end subroutine check

  !> st must be MFREE_SUCCESS; otherwise print its name and the context's message.
  subroutine check_ok(ctx, st, what)
    type(mfree_context), intent(in) :: ctx
    integer(c_int), intent(in) :: st
    character(len=*), intent(in) :: what
    ncheck = ncheck + 1
    if (st /= MFREE_SUCCESS) then
      nfail = nfail + 1
      write (*, '(a,a,a,i0,a,a,a,a)') 'FAILED: ', what, ': status ', st, ' (', &
        mfree_status_string(st), '): ', mfree_last_error(ctx)
    end if
  end subroutine check_ok

  !> |got - want| <= tol.
  subroutine check_close(got, want, tol, what)
    real(c_double), intent(in) :: got, want, tol
    character(len=*), intent(in) :: what
    ncheck = ncheck + 1
    if (.not. abs(got - want) <= tol) then
      nfail = nfail + 1
      write (*, '(a,a,a,es24.16,a,es24.16,a,es9.2,a)') 'FAILED: ', what, ': got ', got, &
        ', expected ', want, ' (tolerance ', tol, ')'
    end if
  end subroutine check_close

  !> Summary; a non-zero exit status when a check failed.
  subroutine finish(name)
    character(len=*), intent(in) :: name
    if (nfail > 0) then
      write (*, '(a,a,i0,a,i0,a)') name, ': ', nfail, ' of ', ncheck, ' checks FAILED'
      error stop 1
    end if
    write (*, '(a,a,i0,a)') name, ': all ', ncheck, ' checks passed'
  end subroutine finish

  !> xorshift64: the same numbers on every platform, independent of random_number.
  subroutine rng_seed(seed)
    integer, intent(in) :: seed
    rng_state = 88172645463325252_c_int64_t + int(seed, c_int64_t) * 7919_c_int64_t
  end subroutine rng_seed

  !> Uniform in [0, 1).
  real(c_double) function rng_uniform()
    rng_state = ieor(rng_state, ishft(rng_state, 13))
    rng_state = ieor(rng_state, ishft(rng_state, -7))
    rng_state = ieor(rng_state, ishft(rng_state, 17))
    rng_uniform = real(ishft(rng_state, -11), c_double) / 9007199254740992.0_c_double
  end function rng_uniform

end module ftest
