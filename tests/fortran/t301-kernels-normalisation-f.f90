!> t301 (Fortran twin of t301-kernels-normalisation): every kernel integrates to 1 in
!> 1D, 2D and 3D (radial Gauss-Legendre quadrature written here, on pieces that end at
!> every breakpoint of the spline kernels, so that it is exact for them), published
!> normalisation constants, support radii, and dW/dr against a central difference.
program t301_kernels_normalisation_f
  use, intrinsic :: iso_c_binding
  use mfree
  use ftest
  implicit none

  real(c_double), parameter :: pi = acos(-1.0_c_double)
  integer(c_int), parameter :: kernels(12) = [MFREE_KERNEL_CUBIC_SPLINE, &
    MFREE_KERNEL_QUARTIC, MFREE_KERNEL_QUINTIC_SPLINE, MFREE_KERNEL_GAUSSIAN, &
    MFREE_KERNEL_SUPER_GAUSS, MFREE_KERNEL_REVISED_GAUSS, MFREE_KERNEL_REVISED_SUPER_GAUSS, &
    MFREE_KERNEL_WENDLAND_C2, MFREE_KERNEL_WENDLAND_C4, MFREE_KERNEL_LINEAR, &
    MFREE_KERNEL_QUADRATIC, MFREE_KERNEL_QUARTIC_SPLINE]
  ! 5-point Gauss-Legendre on [-1, 1]: exact for degree 9 (spline pieces times r^2)
  real(c_double), parameter :: gx(5) = [-0.9061798459386640_c_double, &
    -0.5384693101056831_c_double, 0.0_c_double, 0.5384693101056831_c_double, &
    0.9061798459386640_c_double]
  real(c_double), parameter :: gw(5) = [0.2369268850561891_c_double, &
    0.4786286704993665_c_double, 0.5688888888888889_c_double, 0.4786286704993665_c_double, &
    0.2369268850561891_c_double]
  integer, parameter :: per_half = 40  ! pieces per 0.5 in q: breakpoints at multiples of 0.5

  type(mfree_context) :: ctx
  real(c_double) :: radius, c, total, h, surface, dq, q0
  real(c_double), parameter :: surfaces(3) = [2.0_c_double, 2 * pi, 4 * pi]
  real(c_double), allocatable :: r(:), w(:), dw(:), wp(:), wm(:)
  integer :: ik, dim, npieces, p, g, m
  integer(c_int64_t) :: nr
  character(len=60) :: what

  call check_ok(ctx, mfree_context_create(ctx), 'context')
  h = 0.7_c_double
  do ik = 1, size(kernels)
    call check_ok(ctx, mfree_kernel_get_support_radius(ctx, kernels(ik), 0.0_c_double, &
                                                       radius), 'support radius')
    npieces = nint(radius / 0.5_c_double) * per_half
    nr = int(npieces * 5, c_int64_t)
    allocate (r(nr), w(nr))
    dq = radius / npieces
    m = 0
    do p = 1, npieces
      q0 = (p - 1) * dq
      do g = 1, 5
        m = m + 1
        r(m) = h * (q0 + 0.5_c_double * dq * (1 + gx(g)))
      end do
    end do
    do dim = 1, 3
      call check_ok(ctx, mfree_kernel_eval(ctx, kernels(ik), int(dim, c_int32_t), &
                                           0.0_c_double, h, nr, r, w=w), 'kernel_eval')
      surface = surfaces(dim)
      total = 0
      m = 0
      do p = 1, npieces
        do g = 1, 5
          m = m + 1
          total = total + gw(g) * 0.5_c_double * dq * h * surface * r(m)**(dim - 1) * w(m)
        end do
      end do
      write (what, '(a,i0,a,i0,a)') 'kernel ', kernels(ik), ' in ', dim, 'D integrates to 1'
      call check_close(total, 1.0_c_double, 1e-10_c_double, trim(what))
    end do
    deallocate (r, w)
  end do

  ! published constants C_dim of W = C_dim / h^dim f(r/h)
  call check_ok(ctx, mfree_kernel_get_normalization(ctx, MFREE_KERNEL_CUBIC_SPLINE, &
                                                    2_c_int32_t, 0.0_c_double, c), 'C 2D')
  call check_close(c, 10 / (7 * pi), 1e-14_c_double, &
                   'cubic spline 2D: 10/(7 pi) (paper 000 eq 26 in 2D)')
  call check_ok(ctx, mfree_kernel_get_normalization(ctx, MFREE_KERNEL_CUBIC_SPLINE, &
                                                    1_c_int32_t, 0.0_c_double, c), 'C 1D')
  call check_close(c, 2.0_c_double / 3, 1e-14_c_double, 'cubic spline 1D: 2/3 (000 eq 26)')
  call check_ok(ctx, mfree_kernel_get_normalization(ctx, MFREE_KERNEL_CUBIC_SPLINE, &
                                                    3_c_int32_t, 0.0_c_double, c), 'C 3D')
  call check_close(c, 1 / pi, 1e-14_c_double, 'cubic spline 3D: 1/pi')
  call check_ok(ctx, mfree_kernel_get_normalization(ctx, MFREE_KERNEL_WENDLAND_C2, &
                                                    2_c_int32_t, 0.0_c_double, c), 'C2 2D')
  call check_close(c, 7 / (4 * pi), 1e-14_c_double, 'Wendland C2 2D: 7/(4 pi)')
  call check_ok(ctx, mfree_kernel_get_normalization(ctx, MFREE_KERNEL_REVISED_GAUSS, &
                                                    2_c_int32_t, 0.0_c_double, c), 'RG 2D')
  call check_close(c * pi, 1.10081_c_double, 5e-6_c_double, &
                   'revised Gauss 2D: G = 1.10081 (paper 001 sect. 6.1)')
  ! W(0) of the 2D cubic spline is C/h^2
  allocate (r(1), w(1), dw(1), wp(1), wm(1))
  r = 0
  call check_ok(ctx, mfree_kernel_eval(ctx, MFREE_KERNEL_CUBIC_SPLINE, 2_c_int32_t, &
                                       0.0_c_double, h, 1_c_int64_t, r, w=w), 'W(0)')
  call check_close(w(1), 10 / (7 * pi * h * h), 1e-13_c_double, 'cubic 2D W(0) = 10/(7 pi h^2)')

  ! dW/dr against a central difference, inside the support, every kernel, 2D
  do ik = 1, size(kernels)
    r = 0.63_c_double * h
    call check_ok(ctx, mfree_kernel_eval(ctx, kernels(ik), 2_c_int32_t, 0.0_c_double, h, &
                                         1_c_int64_t, r, dwdr=dw), 'dW/dr')
    r = 0.63_c_double * h + 1e-6_c_double
    call check_ok(ctx, mfree_kernel_eval(ctx, kernels(ik), 2_c_int32_t, 0.0_c_double, h, &
                                         1_c_int64_t, r, w=wp), 'W(r + e)')
    r = 0.63_c_double * h - 1e-6_c_double
    call check_ok(ctx, mfree_kernel_eval(ctx, kernels(ik), 2_c_int32_t, 0.0_c_double, h, &
                                         1_c_int64_t, r, w=wm), 'W(r - e)')
    write (what, '(a,i0,a)') 'kernel ', kernels(ik), ': dW/dr = central difference'
    call check_close(dw(1), (wp(1) - wm(1)) / 2e-6_c_double, 1e-6_c_double * max(1.0_c_double, &
                     abs(dw(1))), trim(what))
  end do

  deallocate (r, w, dw, wp, wm)  ! main-program allocatables are not freed at exit
  call check(mfree_context_destroy(ctx) == MFREE_SUCCESS, 'destroy context')
  call finish('t301-kernels-normalisation-f')
end program t301_kernels_normalisation_f
