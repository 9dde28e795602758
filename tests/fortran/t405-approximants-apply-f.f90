!> t405 (Fortran twin of t405-approximants-apply and of the completeness table of t412):
!> every approximation method applies its gradient operator to linear fields held in
!> host arrays (a scalar u(n) and a vector v(3,n) with ld = 3 in 2D) on a jittered cloud
!> with a free boundary. The methods that claim linear derivative completeness (paper 000
!> Sect. 4 summary: MLS/RKPM, Randles-Libersky, Krongauz-Belytschko Methods 1-3; paper
!> 001: MSPH, SSPH, exact at the particles for degree m) give the exact gradient and
!> divergence to 1e-10; SPH, symmetrised SPH and Shepard do not (O(1) at the boundary);
!> Johnson-Beissel fails the field v = a(x + y) of 000 eqs 53-54.
program t405_approximants_apply_f
  use, intrinsic :: iso_c_binding
  use mfree
  use ftest
  implicit none

  integer, parameter :: m = 10, n = m * m
  real(c_double), parameter :: tol = 1e-10_c_double
  real(c_double), target :: x(3, n), vol, h
  real(c_double) :: u(n), v(3, n), ujb(n), gu(2, n), gv(2, 2, n), divv(n), gjb(2, n)
  real(c_double), parameter :: c0 = 0.3_c_double, c1 = 1.7_c_double, c2 = -0.8_c_double
  real(c_double), parameter :: amat(2, 2) = reshape([0.5_c_double, -1.1_c_double, &
                                                     0.9_c_double, 0.25_c_double], [2, 2])
  type(mfree_context) :: ctx
  type(mfree_particles) :: ps
  real(c_double) :: dx, eu, ev, ed, ejb
  integer :: i, j, p

  call check_ok(ctx, mfree_context_create(ctx), 'context')
  call rng_seed(405)
  dx = 1.0_c_double / m
  do j = 1, m
    do i = 1, m
      p = (j - 1) * m + i
      x(1, p) = (i - 0.5_c_double + 0.35_c_double * (2 * rng_uniform() - 1)) * dx
      x(2, p) = (j - 0.5_c_double + 0.35_c_double * (2 * rng_uniform() - 1)) * dx
      x(3, p) = 0
    end do
  end do
  vol = dx * dx
  h = 1.9_c_double * dx
  do p = 1, n
    u(p) = c0 + c1 * x(1, p) + c2 * x(2, p)
    ! v_c = b_c + sum_d A(c, d) x_d; the third row is padding (ld = 3)
    v(1:2, p) = [0.2_c_double, -0.4_c_double] + matmul(amat, x(1:2, p))
    v(3, p) = huge(1.0_c_double)
    ujb(p) = 2.5_c_double * (x(1, p) + x(2, p))
  end do

  call check_ok(ctx, mfree_particles_create(ctx, 2_c_int32_t, int(n, c_int32_t), ps), 'create')
  call check_ok(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 3_c_int64_t, &
                                                   MFREE_BORROW), 'positions x(3,n)')
  call check_ok(ctx, mfree_particles_set_volumes(ps, vol, 0_c_int64_t, MFREE_COPY), 'volumes')
  call check_ok(ctx, mfree_particles_set_support(ps, h, 0_c_int64_t, MFREE_COPY), 'support')

  !            method                        order  claims linear derivatives
  call run(MFREE_METHOD_SPH, -1, .false.)
  call run(MFREE_METHOD_SPH_SYMMETRIC, -1, .false.)
  call run(MFREE_METHOD_SHEPARD, -1, .false.)
  call run(MFREE_METHOD_MLS, 1, .true.)
  call run(MFREE_METHOD_MLS, 2, .true.)
  call run(MFREE_METHOD_MLS, 3, .true.)
  call run(MFREE_METHOD_RKPM, 1, .true.)
  call run(MFREE_METHOD_RKPM, 2, .true.)
  call run(MFREE_METHOD_JOHNSON_BEISSEL, -1, .false.)
  call run(MFREE_METHOD_RANDLES_LIBERSKY, -1, .true.)
  call run(MFREE_METHOD_KB_METHOD1, -1, .true.)
  call run(MFREE_METHOD_KB_METHOD2, 1, .true.)
  call run(MFREE_METHOD_KB_METHOD2, 2, .true.)
  call run(MFREE_METHOD_KB_METHOD3, -1, .true.)
  call run(MFREE_METHOD_MSPH, 1, .true.)
  call run(MFREE_METHOD_MSPH, 2, .true.)
  call run(MFREE_METHOD_SSPH, 1, .true.)
  call run(MFREE_METHOD_SSPH, 2, .true.)
  call run(MFREE_METHOD_SSPH, 3, .true.)

  call check(mfree_particles_destroy(ps) == MFREE_SUCCESS, 'destroy particles')
  call check(mfree_context_destroy(ctx) == MFREE_SUCCESS, 'destroy context')
  call finish('t405-approximants-apply-f')

contains

  subroutine run(method, order, claims)
    integer(c_int), intent(in) :: method
    integer, intent(in) :: order
    logical, intent(in) :: claims
    type(mfree_approximant) :: a
    character(len=48) :: what
    integer :: q

    write (what, '(a,i0,a,i0)') 'method ', method, ' order ', order
    call check_ok(ctx, mfree_approximant_create(ctx, ps, method, a), 'create '//what)
    if (order >= 0) call check_ok(ctx, mfree_approximant_set_order(a, int(order, c_int32_t)), &
                                  'set_order '//what)
    call check_ok(ctx, mfree_approximant_set_derivatives(a, &
                  ior(MFREE_DERIV_VALUE, MFREE_DERIV_GRADIENT)), 'set_derivatives')
    call check_ok(ctx, mfree_approximant_setup(a), 'setup '//what)
    ! grad u: one component, out(dim, n); grad v: out(dim, ncomp, n), AoS ld = 4
    call check_ok(ctx, mfree_approximant_apply(a, MFREE_OP_GRADIENT, 1_c_int32_t, u, &
                  MFREE_LAYOUT_AOS, 1_c_int64_t, gu, MFREE_LAYOUT_AOS, 2_c_int64_t), 'grad u')
    call check_ok(ctx, mfree_approximant_apply(a, MFREE_OP_GRADIENT, 2_c_int32_t, v, &
                  MFREE_LAYOUT_AOS, 3_c_int64_t, gv, MFREE_LAYOUT_AOS, 4_c_int64_t), 'grad v')
    call check_ok(ctx, mfree_approximant_apply(a, MFREE_OP_DIVERGENCE, 2_c_int32_t, v, &
                  MFREE_LAYOUT_AOS, 3_c_int64_t, divv, MFREE_LAYOUT_AOS, 1_c_int64_t), 'div v')
    call check_ok(ctx, mfree_approximant_apply(a, MFREE_OP_GRADIENT, 1_c_int32_t, ujb, &
                  MFREE_LAYOUT_AOS, 1_c_int64_t, gjb, MFREE_LAYOUT_AOS, 2_c_int64_t), 'grad a(x+y)')
    eu = 0
    ev = 0
    ed = 0
    ejb = 0
    do q = 1, n
      eu = max(eu, abs(gu(1, q) - c1), abs(gu(2, q) - c2))
      ! gv(d, c, q) = d v_c / d x_d = A(c, d)
      ev = max(ev, maxval(abs(transpose(gv(:, :, q)) - amat)))
      ed = max(ed, abs(divv(q) - (amat(1, 1) + amat(2, 2))))
      ejb = max(ejb, abs(gjb(1, q) - 2.5_c_double), abs(gjb(2, q) - 2.5_c_double))
    end do
    write (*, '(a,a,3es10.2,a,es10.2)') trim(what), ': grad u, grad v, div v errors', eu, ev, ed, &
      '; a(x+y):', ejb
    if (claims) then
      call check(eu < tol .and. ev < tol .and. ed < tol, &
                 trim(what)//': exact gradient and divergence of linear fields')
    else
      call check(eu > 1e-3_c_double .and. ev > 1e-3_c_double, &
                 trim(what)//': not exact for linear fields (as the papers say)')
    end if
    if (method == MFREE_METHOD_JOHNSON_BEISSEL) then
      call check(ejb > 1e-3_c_double, 'Johnson-Beissel fails v = a(x + y) (000 eqs 53-54)')
    end if
    if (method == MFREE_METHOD_SPH) then
      call check(eu > 0.1_c_double * abs(c1), 'SPH is O(1) wrong at the free boundary')
    end if
    call check(mfree_approximant_destroy(a) == MFREE_SUCCESS, 'destroy '//what)
  end subroutine run

end program t405_approximants_apply_f
