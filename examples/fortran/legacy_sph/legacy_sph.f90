!> legacy_sph: a small 2D SPH program written the way legacy hydrocodes are (fixed-size
!> arrays, its own linked-cell neighbour search, the standard SPH velocity gradient
!> sum_j m_j/rho_j (v_j - v_i) grad W_ij, the continuity equation), run on a free patch
!> of particles under the prescribed linear velocity field v = A x + b.
!>
!> One switch replaces its gradient with mfree's corrected gradient, fed with the host's
!> own arrays (sph_mfree.f90):
!>   --gradient=sph   the code's own SPH gradient (default)
!>   --gradient=rl    MFREE_METHOD_RANDLES_LIBERSKY
!>   --gradient=kb1   MFREE_METHOD_KB_METHOD1 (Krongauz-Belytschko)
!>   --gradient=mls   MFREE_METHOD_MLS (linear)
!>   --host-neighbors mfree uses the code's own neighbour list (1-based CSR)
!>   --steps=N        time steps (default 5); --nside=M  M x M particles (default 40)
!>   --input=FILE     read the namelist &sph_run (gradient, host_neighbors, steps,
!>                    nside, check) from FILE; later flags override it
!>   --check          exit non-zero unless a corrected gradient is exact to 1e-10 or the
!>                    SPH gradient is O(1) wrong at the free boundary (> 0.1 |A|)
!> It prints the velocity-gradient error at the free boundary and inside, every step, and
!> the cost per step (gradient, with mfree's update, and continuity). Nothing is
!> allocated after the set-up.
program legacy_sph
  use sph_data
  use sph_mfree
  use mfree, only: MFREE_METHOD_RANDLES_LIBERSKY, MFREE_METHOD_KB_METHOD1, MFREE_METHOD_MLS
  implicit none

  real(dp), parameter :: amat(2, 2) = reshape([0.10_dp, -0.30_dp, 0.40_dp, -0.05_dp], [2, 2])
  real(dp), parameter :: bvec(2) = [0.02_dp, -0.01_dp]
  real(dp), parameter :: pi = 3.14159265358979323846_dp

  character(len=8) :: gradient
  logical :: host_neighbors, check
  integer :: steps, nside
  namelist /sph_run/ gradient, host_neighbors, steps, nside, check

  real(dp) :: dx, dt, t0, t1, tset, tstep, ebnd, eint, ebnd_max, eint_max, amax
  integer(8) :: c0, c1, crate
  integer :: istep, i
  logical :: boundary(NMAX), mfree_grad

  gradient = 'sph'
  host_neighbors = .false.
  check = .false.
  steps = 5
  nside = 40
  call read_options()
  if (nside * nside > NMAX .or. nside < 4) then
    write (*, '(a,i0,a,i0)') 'legacy_sph: --nside must be 4 .. ', int(sqrt(real(NMAX))), &
      ', got ', nside
    stop 2
  end if
  mfree_grad = gradient /= 'sph'

  ! ---- initial state: a slightly perturbed lattice in the unit square, free boundary ----
  n = nside * nside
  dx = 1.0_dp / nside
  do i = 1, n
    x(1, i) = (mod(i - 1, nside) + 0.5_dp + 0.1_dp * sin(12.9898_dp * i)) * dx
    x(2, i) = ((i - 1) / nside + 0.5_dp + 0.1_dp * cos(78.233_dp * i)) * dx
    x(3, i) = 0
    h(i) = 1.3_dp * dx
    rho(i) = 1000
    pm(i) = rho(i) * dx * dx
    ! within 2h of the edge of the patch: the kernel support is cut by the free surface
    boundary(i) = min(x(1, i), x(2, i), 1 - x(1, i), 1 - x(2, i)) < 2 * h(i)
  end do
  call set_velocity()
  amax = maxval(abs(amat))
  dt = 0.05_dp * dx / maxval(abs(v(1:2, 1:n)))

  write (*, '(a,a,a,l1,a,i0,a,i0)') 'legacy_sph: gradient=', trim(gradient), &
    ' host_neighbors=', host_neighbors, ' particles=', n, ' steps=', steps

  ! ---- set-up: neighbour list (and mfree's tables) once ------------------------------------
  call system_clock(c0, crate)
  call build_neighbors()
  select case (gradient)
  case ('rl')
    call mfree_gradient_init(MFREE_METHOD_RANDLES_LIBERSKY, host_neighbors)
  case ('kb1')
    call mfree_gradient_init(MFREE_METHOD_KB_METHOD1, host_neighbors)
  case ('mls')
    call mfree_gradient_init(MFREE_METHOD_MLS, host_neighbors)
  end select
  call system_clock(c1)
  tset = real(c1 - c0, dp) / crate

  ! ---- time steps: gradient, continuity, move ---------------------------------------------
  write (*, '(a)') ' step        time   max|grad v - A| boundary    inside'
  ebnd_max = 0
  eint_max = 0
  tstep = 0
  do istep = 0, steps
    call cpu_time(t0)
    if (mfree_grad) then
      call mfree_gradient(moved=istep > 0)
    else
      call sph_velocity_gradient()
    end if
    do i = 1, n
      drho(i) = -rho(i) * (dvdx(1, 1, i) + dvdx(2, 2, i))
    end do
    call cpu_time(t1)
    if (istep > 0) tstep = tstep + (t1 - t0)
    call gradient_error(ebnd, eint)
    ebnd_max = max(ebnd_max, ebnd)
    eint_max = max(eint_max, eint)
    write (*, '(i5,es12.4,2es24.3)') istep, istep * dt, ebnd, eint
    if (istep == steps) exit
    do i = 1, n
      x(1:2, i) = x(1:2, i) + dt * v(1:2, i)
      rho(i) = rho(i) + dt * drho(i)
    end do
    call set_velocity()
  end do
  if (steps > 0) tstep = tstep / steps
  write (*, '(a,es10.3,a,es10.3,a,es10.3,a,es10.3,a)') 'errors: boundary ', ebnd_max, &
    ' inside ', eint_max, ' (|A| = ', amax, '); cost per step ', tstep, ' s'
  write (*, '(a,es10.3,a)') 'set-up (neighbour list and tables) ', tset, ' s'
  if (mfree_grad) call mfree_gradient_done()

  if (check) then
    if (mfree_grad) then
      if (.not. (max(ebnd_max, eint_max) < 1e-10_dp)) then
        write (*, '(a)') 'check FAILED: the corrected gradient is not exact to 1e-10'
        stop 1
      end if
      write (*, '(a)') 'check: corrected gradient exact to 1e-10: ok'
    else
      if (.not. (ebnd_max > 0.1_dp * amax)) then
        write (*, '(a)') 'check FAILED: SPH is not O(1) wrong at the free boundary'
        stop 1
      end if
      write (*, '(a)') 'check: SPH gradient O(1) wrong at the free boundary: ok'
    end if
  end if

contains

  subroutine set_velocity()
    integer :: j
    do j = 1, n
      v(1:2, j) = bvec + matmul(amat, x(1:2, j))
      v(3, j) = 0
    end do
  end subroutine set_velocity

  !> Linked cells of side 2 h_max; pairs with r < 2 h_i (the cubic spline's support),
  !> the particle itself included, into the 1-based CSR nbrow / nbcol.
  subroutine build_neighbors()
    real(dp) :: xmin(2), cell, r2, rad
    integer :: ncx, ncy, ic, jc, kc, ci, cj, i, j, nnb
    xmin = [minval(x(1, 1:n)), minval(x(2, 1:n))]
    cell = 2 * maxval(h(1:n))
    ncx = int((maxval(x(1, 1:n)) - xmin(1)) / cell) + 1
    ncy = int((maxval(x(2, 1:n)) - xmin(2)) / cell) + 1
    if (ncx * ncy > NCMAX) error stop 'legacy_sph: too many cells (NCMAX)'
    head(1:ncx * ncy) = 0
    do i = 1, n
      ic = min(int((x(1, i) - xmin(1)) / cell), ncx - 1)
      jc = min(int((x(2, i) - xmin(2)) / cell), ncy - 1)
      kc = jc * ncx + ic + 1
      next(i) = head(kc)
      head(kc) = i
    end do
    nnb = 0
    do i = 1, n
      nbrow(i) = nnb + 1
      rad = 2 * h(i)
      ic = min(int((x(1, i) - xmin(1)) / cell), ncx - 1)
      jc = min(int((x(2, i) - xmin(2)) / cell), ncy - 1)
      do cj = max(jc - 1, 0), min(jc + 1, ncy - 1)
        do ci = max(ic - 1, 0), min(ic + 1, ncx - 1)
          j = head(cj * ncx + ci + 1)
          do while (j > 0)
            r2 = (x(1, i) - x(1, j))**2 + (x(2, i) - x(2, j))**2
            if (r2 < rad * rad) then
              if (nnb >= NBMAX) error stop 'legacy_sph: too many neighbour pairs (NBMAX)'
              nnb = nnb + 1
              nbcol(nnb) = j
            end if
            j = next(j)
          end do
        end do
      end do
    end do
    nbrow(n + 1) = nnb + 1
  end subroutine build_neighbors

  !> Cubic spline, 2D: dW/dr / r (so that grad_i W_ij = (x_i - x_j) * dwr).
  real(dp) function dwdr_over_r(r, hh)
    real(dp), intent(in) :: r, hh
    real(dp) :: q, sigma
    q = r / hh
    sigma = 10.0_dp / (7.0_dp * pi * hh * hh)
    if (q < 1.0e-12_dp) then
      dwdr_over_r = 0
    else if (q < 1) then
      dwdr_over_r = sigma * (-3 * q + 2.25_dp * q * q) / (hh * r)
    else if (q < 2) then
      dwdr_over_r = sigma * (-0.75_dp * (2 - q)**2) / (hh * r)
    else
      dwdr_over_r = 0
    end if
  end function dwdr_over_r

  !> The standard SPH velocity gradient: dv_c/dx_d (i) = sum_j m_j/rho_j (v_c(j) -
  !> v_c(i)) d W_ij / d x_d(i).
  subroutine sph_velocity_gradient()
    integer :: i, j, k
    real(dp) :: dxij(2), r, f
    do i = 1, n
      dvdx(:, :, i) = 0
      do k = int(nbrow(i)), int(nbrow(i + 1)) - 1
        j = nbcol(k)
        if (j == i) cycle
        dxij = x(1:2, i) - x(1:2, j)
        r = sqrt(dxij(1)**2 + dxij(2)**2)
        f = pm(j) / rho(j) * dwdr_over_r(r, h(i))
        dvdx(:, 1, i) = dvdx(:, 1, i) + f * (v(1, j) - v(1, i)) * dxij
        dvdx(:, 2, i) = dvdx(:, 2, i) + f * (v(2, j) - v(2, i)) * dxij
      end do
    end do
  end subroutine sph_velocity_gradient

  !> max |dv_c/dx_d - A(c, d)| over boundary and interior particles.
  subroutine gradient_error(eb, ei)
    real(dp), intent(out) :: eb, ei
    real(dp) :: e
    integer :: i, c, d
    eb = 0
    ei = 0
    do i = 1, n
      e = 0
      do c = 1, 2
        do d = 1, 2
          e = max(e, abs(dvdx(d, c, i) - amat(c, d)))
        end do
      end do
      if (boundary(i)) then
        eb = max(eb, e)
      else
        ei = max(ei, e)
      end if
    end do
  end subroutine gradient_error

  subroutine read_options()
    character(len=256) :: arg
    integer :: k, u, ios
    do k = 1, command_argument_count()
      call get_command_argument(k, arg)
      if (arg(1:8) == '--input=') then
        open (newunit=u, file=trim(arg(9:)), status='old', action='read', iostat=ios)
        if (ios /= 0) then
          write (*, '(a,a)') 'legacy_sph: cannot open ', trim(arg(9:))
          stop 2
        end if
        read (u, nml=sph_run, iostat=ios)
        close (u)
        if (ios /= 0) then
          write (*, '(a,a)') 'legacy_sph: bad namelist &sph_run in ', trim(arg(9:))
          stop 2
        end if
      end if
    end do
    do k = 1, command_argument_count()
      call get_command_argument(k, arg)
      if (arg(1:11) == '--gradient=') then
        gradient = arg(12:)
      else if (arg == '--host-neighbors') then
        host_neighbors = .true.
      else if (arg == '--check') then
        check = .true.
      else if (arg(1:8) == '--steps=') then
        read (arg(9:), *, iostat=ios) steps
        if (ios /= 0 .or. steps < 0) call usage(arg)
      else if (arg(1:8) == '--nside=') then
        read (arg(9:), *, iostat=ios) nside
        if (ios /= 0) call usage(arg)
      else if (arg(1:8) /= '--input=') then
        call usage(arg)
      end if
    end do
    select case (gradient)
    case ('sph', 'rl', 'kb1', 'mls')
    case default
      call usage('--gradient='//trim(gradient))
    end select
    if (host_neighbors .and. gradient == 'sph') then
      ! the SPH gradient always uses the host's list: nothing to lend
      host_neighbors = .false.
    end if
  end subroutine read_options

  subroutine usage(arg)
    character(len=*), intent(in) :: arg
    write (*, '(a,a)') 'legacy_sph: bad option ', trim(arg)
    write (*, '(a)') 'usage: legacy_sph [--gradient=sph|rl|kb1|mls] [--host-neighbors] ' // &
      '[--steps=N] [--nside=M] [--input=FILE] [--check]'
    stop 2
  end subroutine usage

end program legacy_sph
