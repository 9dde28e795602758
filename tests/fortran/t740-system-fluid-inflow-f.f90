!> t740 (Fortran twin of t740-system-fluid-inflow): an inflow gate driven from Fortran. A gate
!> of 6 points at spacing d = 0.01 m injects water at 1 m/s into a system of 200 particles,
!> all dormant at first; after 0.1 s (10 rows) the released mass is the count times
!> rho d W / 6 and rho U W t to half a row, the buffer holds 3 rows, and the typed wrappers
!> refuse a state array of the wrong size and a gate normal of one value.
program t740_system_fluid_inflow_f
  use, intrinsic :: iso_c_binding
  use mfree
  use ftest
  implicit none

  integer, parameter :: n = 200
  real(c_double), parameter :: rho = 1000, u = 1, d = 0.01_c_double, w = 0.06_c_double, gam = 7
  type(mfree_context) :: ctx
  type(mfree_system) :: sys
  real(c_double) :: y(5 * n), t, mass, me, kappa, m
  integer(c_int32_t) :: state(n), bad(n - 1), na
  integer(c_int64_t) :: nin
  integer :: i

  call check_ok(ctx, mfree_context_create(ctx), 'context')
  kappa = rho * 100 / gam
  m = rho * d * d
  call check_ok(ctx, mfree_system_create_fluid(ctx, 2_c_int32_t, int(n, c_int32_t), sys), 'create_fluid')
  call check_ok(ctx, mfree_system_set_fluid(sys, rho, 0_c_int64_t, kappa, gam, 0.01_c_double), 'set_fluid')
  call check_ok(ctx, mfree_system_set_masses(sys, m, 0_c_int64_t), 'set_masses')
  call check_ok(ctx, mfree_system_set_smoothing(sys, 1.5_c_double * d), 'set_smoothing')
  call check_ok(ctx, mfree_system_set_active(sys, 0_c_int32_t), 'set_active')
  call check_ok(ctx, mfree_system_set_inflow(sys, 0_c_int32_t, [0.0_c_double, 0.0_c_double], [0.0_c_double, w], &
                                             [1.0_c_double, 0.0_c_double], u, rho, d), 'set_inflow')
  call check(mfree_system_set_inflow(sys, 1_c_int32_t, [0.0_c_double, 0.0_c_double], [0.0_c_double, w], &
                                     [1.0_c_double], u, rho, d) == MFREE_ERR_ARG, 'set_inflow: a normal of one value')
  y = 0
  do i = 1, n
    y(2 * i - 1) = -100
    y(4 * n + i) = rho
  end do
  t = 0
  call check_ok(ctx, mfree_system_integrate(sys, MFREE_INTEGRATOR_LEAPFROG, y, t, 0.1_c_double, 0.5_c_double, &
                                            0.0_c_double), 'integrate')
  call check_ok(ctx, mfree_system_get_inflow(sys, 0_c_int32_t, nin, mass), 'get_inflow')
  me = rho * d * w / 6
  call check(nin == 60, '10 rows of 6 released')
  call check(abs(mass - nin * me) <= 1e-12_c_double * mass, 'released mass = count x particle mass')
  call check(abs(mass - rho * u * w * t) <= 0.5_c_double * rho * d * w + 1e-12_c_double, 'rho U W t to half a row')
  call check_ok(ctx, mfree_system_get_active(sys, na, state), 'get_active')
  call check(count(state == MFREE_PARTICLE_INFLOW) == 18, 'a buffer of 3 rows')
  call check(na == 60 + 18, 'active = released + buffer')
  call check(mfree_system_get_active(sys, na, bad) == MFREE_ERR_ARG, 'get_active: state of n - 1 values refused')
  call check(mfree_system_destroy(sys) == MFREE_SUCCESS, 'destroy system')
  call check(mfree_context_destroy(ctx) == MFREE_SUCCESS, 'destroy context')
  call finish('t740-system-fluid-inflow-f')
end program t740_system_fluid_inflow_f
