!> t701 (Fortran twin of t701-system-fluid): the Galerkin-SPH fluid system of paper 003
!> driven from Fortran. On a free jittered patch with random velocities and densities the
!> lumped-mass weighted accelerations sum to zero (linear momentum; docs/papers.md,
!> paper 003, derived results 1) to round-off;
!> a native integration with a progress callback written in Fortran stops when the
!> callback asks it to, and reports the steps taken. Without walls or gravity the walls' force
!> (mfree_system_get_wall_force) vanishes. The mass's product (mfree_system_apply_mass) is
!> the assembled lumped mass's, and a short output array is refused.
module t701_progress
  use, intrinsic :: iso_c_binding, only: c_ptr, c_int32_t, c_int64_t, c_double, c_f_pointer
  implicit none
  private
  public :: progress

contains

  !> Counts the accepted steps in the integer the user pointer points to; stops at 3.
  integer(c_int32_t) function progress(user, step, t, dt) bind(C)
    type(c_ptr), value :: user
    integer(c_int64_t), value :: step
    real(c_double), value :: t, dt
    integer, pointer :: calls
    call c_f_pointer(user, calls)
    calls = calls + 1
    progress = 0
    if (step >= 3 .or. .not. (t > 0 .and. dt > 0)) progress = 1
  end function progress

end module t701_progress

program t701_system_fluid_f
  use, intrinsic :: iso_c_binding
  use mfree
  use ftest
  use t701_progress
  implicit none

  integer, parameter :: nx = 10, nz = 10, n = nx * nz
  real(c_double), parameter :: d = 0.005_c_double, rho0 = 1000, g = 9.81_c_double
  real(c_double), parameter :: gam = 7
  type(mfree_context) :: ctx
  type(mfree_system) :: sys
  type(mfree_matrix) :: mm
  real(c_double) :: y(5 * n), yd(5 * n), m(n), kappa, mom(2), scale, fx, fz, t, hcol
  real(c_double) :: ftot(2), pbad(3), mv(5 * n)
  integer(c_int64_t), pointer :: rowptr(:)
  integer(c_int32_t), pointer :: cols(:)
  real(c_double), pointer :: vals(:)
  integer(c_int32_t) :: neq
  integer(c_int64_t) :: nsteps
  integer, target :: calls
  integer :: i, j, p, row

  call check_ok(ctx, mfree_context_create(ctx), 'context')
  call rng_seed(701)
  do j = 0, nz - 1
    do i = 0, nx - 1
      p = j * nx + i + 1
      y(2 * p - 1) = (i + 0.5_c_double + 0.2_c_double * (2 * rng_uniform() - 1)) * d
      y(2 * p) = (j + 0.5_c_double + 0.2_c_double * (2 * rng_uniform() - 1)) * d
      y(2 * n + 2 * p - 1) = 0.3_c_double * (2 * rng_uniform() - 1)
      y(2 * n + 2 * p) = 0.3_c_double * (2 * rng_uniform() - 1)
      y(4 * n + p) = rho0 * (1 + 0.01_c_double * (2 * rng_uniform() - 1))
      m(p) = y(4 * n + p) * d * d
    end do
  end do
  hcol = nz * d
  kappa = 100 * rho0 * 2 * g * hcol / gam   ! 003 eq 125

  call check_ok(ctx, mfree_system_create_fluid(ctx, 2_c_int32_t, int(n, c_int32_t), sys), &
                'create_fluid')
  call check_ok(ctx, mfree_system_set_fluid(sys, rho0, 0_c_int64_t, kappa, gam, &
                                            0.5_c_double), 'set_fluid (one rho0)')
  call check_ok(ctx, mfree_system_set_masses(sys, m, 1_c_int64_t), 'set_masses')
  call check_ok(ctx, mfree_system_set_smoothing(sys, 1.5_c_double * d), 'set_smoothing')
  ! the approximation setter: a bad order refused, the default chosen again
  call check(mfree_system_set_approximation(sys, MFREE_METHOD_MLS, 9_c_int32_t, MFREE_KERNEL_CUBIC_SPLINE, &
                                            0.0_c_double) == MFREE_ERR_UNSUPPORTED, 'set_approximation: order 9')
  call check_ok(ctx, mfree_system_set_approximation(sys, MFREE_METHOD_MLS, 1_c_int32_t, MFREE_KERNEL_CUBIC_SPLINE, &
                                                    0.0_c_double), 'set_approximation')
  call check_ok(ctx, mfree_system_get_size(sys, neq), 'get_size')
  call check(neq == 5 * n, 'state length (2 dim + 1) n')
  call check_ok(ctx, mfree_system_rhs(sys, 0.0_c_double, y, yd), 'rhs')
  call check_ok(ctx, mfree_system_assemble_mass(sys, y, 0_c_int32_t, mm), 'lumped mass')
  call check_ok(ctx, mfree_matrix_get_csr(mm, rowptr, cols, vals), 'mass view')
  mom = 0
  scale = 0
  do p = 1, n
    row = 2 * n + 2 * p - 1          ! velocity block, x component of particle p
    call check(rowptr(row + 1) - rowptr(row) == 1, 'lumped: one entry per velocity row')
    fx = vals(rowptr(row) + 1) * yd(2 * n + 2 * p - 1)
    fz = vals(rowptr(row) + 1) * yd(2 * n + 2 * p)
    mom = mom + [fx, fz]
    scale = scale + abs(fx) + abs(fz)
  end do
  call check(all(abs(mom) <= 1e-12_c_double * scale), &
             'lumped-mass accelerations conserve linear momentum (003 eq 43)')

  ! the mass's product (mfree_system_apply_mass): the lumped rows times yd, bit for bit;
  ! an Mv one value short is refused
  call check_ok(ctx, mfree_system_apply_mass(sys, y, 0_c_int32_t, yd, mv), 'apply_mass')
  do p = 1, n
    row = 2 * n + 2 * p - 1
    call check(mv(row) == vals(rowptr(row) + 1) * yd(row), 'apply_mass: the lumped row times yd')
  end do
  call check(mfree_system_apply_mass(sys, y, 1_c_int32_t, yd, mv(1:5 * n - 1)) == MFREE_ERR_ARG, &
             'apply_mass: an Mv one value short is refused')

  ! no walls and no gravity: the walls' force (the lumped-mass weighted accelerations' sum)
  ! vanishes to round-off; per_wall must hold dim values per wall particle
  call check_ok(ctx, mfree_system_get_wall_force(sys, y, ftot), 'wall force')
  call check(all(abs(ftot) <= 1e-12_c_double * scale), 'no walls: no wall force')
  call check(mfree_system_get_wall_force(sys, y, ftot, pbad) == MFREE_ERR_ARG, &
             'wall force: per_wall of 3 values in 2D is refused')

  calls = 0
  t = 0
  call check_ok(ctx, mfree_system_integrate(sys, MFREE_INTEGRATOR_LEAPFROG, y, t, &
                1.0_c_double, 0.2_c_double, 0.0_c_double, progress, c_loc(calls), nsteps), &
                'integrate')
  call check(calls == 3 .and. nsteps == 3, 'the Fortran progress callback stopped it at 3 steps')
  call check(t > 0 .and. t < 1, 'time advanced, not to the end')
  call check(all(y == y), 'state finite')

  call check(mfree_matrix_destroy(mm) == MFREE_SUCCESS, 'destroy mass matrix')
  call check(mfree_system_destroy(sys) == MFREE_SUCCESS .and. .not. c_associated(sys%ptr), &
             'destroy system')
  call check(mfree_context_destroy(ctx) == MFREE_SUCCESS, 'destroy context')
  call finish('t701-system-fluid-f')
end program t701_system_fluid_f
