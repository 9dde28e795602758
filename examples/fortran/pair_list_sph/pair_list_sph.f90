!> The kernel gradients of the pair loops, and the only code that uses mfree.
module pair_gradients
  implicit none
  private
  public :: gradients
  integer, parameter :: dp = kind(1.0d0)
contains

  !> The kernel gradients of the pair loops: the code's own (j side = -dwdx), or mfree's.
  subroutine gradients(gradient, ntotal, nvirt, maxn, maxi, x, mass, rho, hsml, niac, pair_i, &
                       pair_j, dwdx, dwdxj)
    character(len=*), intent(in) :: gradient
    integer, intent(in) :: ntotal, nvirt, maxn, maxi, niac
    real(dp), intent(in), target :: x(2, maxn), mass(maxn), rho(maxn), hsml(maxn)
    integer, intent(in), target :: pair_i(maxi), pair_j(maxi)
    real(dp), intent(inout) :: dwdx(2, maxi)
    real(dp), intent(out) :: dwdxj(2, maxi)
    if (gradient == 'own') then
      dwdxj(:, 1:niac) = -dwdx(:, 1:niac)
    else
      call mfree_dwdx(gradient, ntotal, nvirt, maxn, maxi, x, mass, rho, hsml, niac, pair_i, &
                      pair_j, dwdx, dwdxj)
    end if
  end subroutine gradients

  !> mfree's per-pair gradients for the code's pair list: the only place that uses mfree.
  !> Virtual particles are ghosts (the last nvirt): neighbours without rows of their own.
  subroutine mfree_dwdx(gradient, ntotal, nvirt, maxn, maxi, x, mass, rho, hsml, niac, pair_i, &
                        pair_j, dwdx, dwdxj)
    use, intrinsic :: iso_c_binding, only: c_int, c_double
    use mfree
    character(len=*), intent(in) :: gradient
    integer, intent(in) :: ntotal, nvirt, maxn, maxi, niac
    real(dp), intent(in), target :: x(2, maxn), mass(maxn), rho(maxn), hsml(maxn)
    integer, intent(in), target :: pair_i(maxi), pair_j(maxi)
    real(dp), intent(out) :: dwdx(2, maxi), dwdxj(2, maxi)
    type(mfree_context), save :: ctx
    type(mfree_particles), save :: ps
    type(mfree_approximant), save :: ap
    logical, save :: ready = .false.
    integer(c_int) :: st, method
    if (.not. ready) then  ! once: the code's arrays, borrowed
      select case (gradient)
      case ('sph')
        method = MFREE_METHOD_SPH
      case ('kb1')
        method = MFREE_METHOD_KB_METHOD1
      case ('mls1')
        method = MFREE_METHOD_MLS
      case default
        method = MFREE_METHOD_RANDLES_LIBERSKY
      end select
      st = mfree_context_create(ctx)
      st = ior(st, mfree_particles_create(ctx, 2, ntotal, ps))
      st = ior(st, mfree_particles_set_num_ghost(ps, nvirt))
      st = ior(st, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 2, MFREE_BORROW))
      st = ior(st, mfree_particles_set_support(ps, hsml, 1, MFREE_BORROW))
      st = ior(st, mfree_particles_set_masses(ps, mass, 1, MFREE_BORROW))
      st = ior(st, mfree_particles_set_densities(ps, rho, 1, MFREE_BORROW))
      st = ior(st, mfree_particles_set_search(ps, MFREE_SEARCH_SYMMETRIC_MEAN, 2.0_c_double))
      st = ior(st, mfree_approximant_create(ctx, ps, method, ap))
      st = ior(st, mfree_approximant_set_derivatives(ap, MFREE_DERIV_GRADIENT))
      if (st /= MFREE_SUCCESS) call fail('set-up')
      ready = .true.
    end if
    ! every step: the new pair list, rows from it, the tables, the pair gradients
    st = mfree_particles_set_pairs(ps, niac, pair_i, pair_j, 1, MFREE_BORROW)
    if (st == MFREE_SUCCESS) st = mfree_particles_setup(ps)
    if (st == MFREE_SUCCESS) st = mfree_approximant_setup(ap)
    if (st /= MFREE_SUCCESS) call fail('setup')
    if (gradient == 'rl-anti') then
      st = mfree_approximant_get_pair_gradients_antisymmetric(ap, dwdx)
      if (st == MFREE_SUCCESS) dwdxj(:, 1:niac) = -dwdx(:, 1:niac)
    else
      st = mfree_approximant_get_pair_gradients(ap, dwdx, dwdxj)
    end if
    if (st /= MFREE_SUCCESS) call fail('pair gradients')
  contains
    subroutine fail(what)
      character(len=*), intent(in) :: what
      write (*, '(a,a,a,a)') 'pair_list_sph: mfree ', what, ': ', mfree_last_error(ctx)
      stop 3
    end subroutine fail
  end subroutine mfree_dwdx

end module pair_gradients

!> pair_list_sph: a lid-driven cavity written the way legacy SPH hydrocodes are (fixed
!> arrays, a linked-list pair search filling pair_i, pair_j, niac, virtual boundary
!> particles stored after the real ones, summation density, momentum and energy in loops
!> over the pairs with one dwdx(:, k) per pair), whose kernel gradients can come from
!> mfree instead: the one line marked "SWITCH" below picks the code's own dwdx or mfree's
!> per-pair gradients (mfree_approximant_get_pair_gradients), fed with the code's own
!> arrays and pair list (subroutine mfree_dwdx, the only place that uses mfree).
!>
!>   'own'      the code's cubic-spline dwdx, j side = -dwdx (the default)
!>   'sph'      mfree's plain SPH pair gradients (the same numbers)
!>   'rl'       Randles-Libersky, 'kb1' Krongauz-Belytschko Method 1, 'mls1' MLS of
!>              order 1: corrected, so the j side is not -dwdx
!>   'rl-anti'  the antisymmetrised Randles-Libersky gradient (j side = -i side)
!>
!> Command line (all optional): --gradient=NAME overrides the switch; --steps=N (200);
!> --nside=M (M x M real particles, 20); --check=sph|linear|momentum runs one of the
!> checks of the tests and exits non-zero when it fails:
!>   sph       mfree's SPH pair gradients equal this code's dwdx to 1e-14 (relative, on
!>             every pair) and the j side is exactly -dwdx
!>   linear    the code's own velocity-gradient loop with the selected gradients gives
!>             the gradient of a linear field to 1e-12 at every real particle
!>   momentum  the total momentum (walls included: a virtual particle keeps the momentum
!>             it receives) stays at its initial value to round-off over the run, and
!>             the run stays finite
program pair_list_sph
  use pair_gradients, only: gradients
  implicit none
  integer, parameter :: dp = kind(1.0d0)
  integer, parameter :: dim = 2, maxn = 6000, max_interaction = 60 * maxn, layers = 3
  real(dp), parameter :: pi = 3.14159265358979323846_dp
  real(dp), parameter :: rho0 = 1000, ulid = 1, c0 = 10, visc = 10  ! mu = rho0 nu, Re = 100

  character(len=8) :: gradient = 'own'  ! SWITCH: 'own', 'sph', 'rl', 'kb1', 'mls1', 'rl-anti'

  real(dp), target :: x(dim, maxn), vx(dim, maxn), mass(maxn), rho(maxn), hsml(maxn)
  real(dp) :: p(maxn), e(maxn), dvx(dim, maxn), de(maxn), dvdx(dim, dim, maxn)
  real(dp) :: w(max_interaction), dwdx(dim, max_interaction), dwdxj(dim, max_interaction)
  real(dp) :: own(dim, max_interaction)
  integer, target :: pair_i(max_interaction), pair_j(max_interaction)
  integer :: niac, ntotal, nvirt, nside, steps, istep, i, k
  real(dp) :: dx, dt, mom(dim), mom0(dim), wall(dim, maxn), dmom, scale, err, worst
  real(dp) :: amat(dim, dim), bvec(dim)
  character(len=16) :: check

  check = ''
  steps = 200
  nside = 20
  call read_options(gradient, check, steps, nside)
  if (nside < 4 .or. (nside + 2 * layers)**2 > maxn) then
    write (*, '(a)') 'pair_list_sph: --nside out of range'
    stop 2
  end if
  if (all(gradient /= [character(len=8) :: 'own', 'sph', 'rl', 'kb1', 'mls1', 'rl-anti'])) then
    write (*, '(a,a)') 'pair_list_sph: unknown gradient ', trim(gradient)
    stop 2
  end if

  ! ---- particles: nside^2 real ones in the unit square, then layers of virtual ones ----
  dx = 1.0_dp / nside
  call make_particles(nside, dx, x, vx, mass, rho, hsml, e, ntotal, nvirt)
  dt = 0.2_dp * hsml(1) / (c0 + ulid)
  write (*, '(a,a,a,i0,a,i0,a,i0)') 'pair_list_sph: gradient=', trim(gradient), ' real=', &
    ntotal - nvirt, ' virtual=', nvirt, ' steps=', steps

  if (check == 'sph' .or. check == 'linear') then
    call find_pairs(ntotal, nvirt, x, hsml, niac, pair_i, pair_j, w, dwdx)
    own(:, 1:niac) = dwdx(:, 1:niac)
    call gradients(gradient, ntotal, nvirt, maxn, max_interaction, x, mass, rho, hsml, niac, &
                   pair_i, pair_j, dwdx, dwdxj)
    if (check == 'sph') then
      worst = 0
      do k = 1, niac
        err = maxval(abs(dwdx(:, k) - own(:, k))) / maxval(abs(own(:, k)))
        worst = max(worst, err)
        if (any(dwdxj(:, k) /= -dwdx(:, k))) then
          write (*, '(a,i0)') 'FAIL: j side is not -dwdx at pair ', k
          stop 1
        end if
      end do
      write (*, '(a,i0,a,es10.3)') 'check sph: ', niac, ' pairs, max relative difference ', worst
      if (worst > 1e-14_dp) stop 1
    else
      amat = reshape([0.3_dp, -1.1_dp, 0.7_dp, 0.2_dp], [2, 2])
      bvec = [0.5_dp, -0.25_dp]
      do i = 1, ntotal
        vx(:, i) = matmul(amat, x(:, i)) + bvec
      end do
      call velocity_gradient(ntotal, vx, mass, rho, niac, pair_i, pair_j, dwdx, dwdxj, dvdx)
      worst = 0
      do i = 1, ntotal - nvirt
        worst = max(worst, maxval(abs(dvdx(:, :, i) - amat)) / maxval(abs(amat)))
      end do
      write (*, '(a,es10.3)') 'check linear: max relative error at the real particles ', worst
      if (worst > 1e-12_dp) stop 1
    end if
    stop
  end if

  ! ---- time loop: symplectic Euler; virtual particles do not move --------------------------
  wall = 0
  mom0 = momentum(ntotal, mass, vx, wall)
  dmom = 0
  scale = 0
  do istep = 1, steps
    call find_pairs(ntotal, nvirt, x, hsml, niac, pair_i, pair_j, w, dwdx)
    call gradients(gradient, ntotal, nvirt, maxn, max_interaction, x, mass, rho, hsml, niac, &
                   pair_i, pair_j, dwdx, dwdxj)
    call sum_density(ntotal - nvirt, mass, hsml, niac, pair_i, pair_j, w, rho)
    do i = 1, ntotal
      p(i) = c0 * c0 * (rho(i) - rho0)
    end do
    call velocity_gradient(ntotal, vx, mass, rho, niac, pair_i, pair_j, dwdx, dwdxj, dvdx)
    call rates(ntotal, mass, rho, p, vx, dvdx, niac, pair_i, pair_j, dwdx, dwdxj, dvx, de)
    do i = 1, ntotal - nvirt
      vx(:, i) = vx(:, i) + dt * dvx(:, i)
      x(:, i) = x(:, i) + dt * vx(:, i)
      e(i) = e(i) + dt * de(i)
    end do
    do i = ntotal - nvirt + 1, ntotal  ! the walls keep what they receive
      wall(:, i) = wall(:, i) + dt * mass(i) * dvx(:, i)
    end do
    do i = 1, ntotal
      scale = scale + dt * mass(i) * sum(abs(dvx(:, i)))
    end do
    mom = momentum(ntotal, mass, vx, wall)
    dmom = max(dmom, maxval(abs(mom - mom0)))
    if (.not. all(abs(vx(:, 1:ntotal)) < huge(1.0_dp))) then
      write (*, '(a,i0)') 'FAIL: non-finite velocity at step ', istep
      stop 1
    end if
  end do
  write (*, '(a,es10.3,a,es10.3,a,es10.3)') 'momentum drift ', dmom, ' (exchanged ', scale, &
    '), max |v| ', maxval(abs(vx(:, 1:ntotal - nvirt)))
  write (*, '(a,2es12.4)') 'centre velocity ', vx(:, centre(ntotal - nvirt, x))
  if (check == 'momentum' .and. gradient == 'rl-anti' .and. dmom > 1e-12_dp * scale) then
    write (*, '(a)') 'FAIL: momentum not conserved to round-off'
    stop 1
  end if

contains

  function momentum(nt, m, v, wallmom) result(pm)
    integer, intent(in) :: nt
    real(dp), intent(in) :: m(:), v(:, :), wallmom(:, :)
    real(dp) :: pm(dim)
    integer :: q
    pm = 0
    do q = 1, nt
      pm = pm + m(q) * v(:, q) + wallmom(:, q)
    end do
  end function momentum

  integer function centre(nreal, xx)
    integer, intent(in) :: nreal
    real(dp), intent(in) :: xx(:, :)
    integer :: q
    real(dp) :: best, r
    centre = 1
    best = huge(1.0_dp)
    do q = 1, nreal
      r = (xx(1, q) - 0.5_dp)**2 + (xx(2, q) - 0.5_dp)**2
      if (r < best) then
        best = r
        centre = q
      end if
    end do
  end function centre

end program pair_list_sph

!> Real particles on a slightly perturbed lattice, then `layers` rows of virtual particles
!> around the box (the top ones move with the lid).
subroutine make_particles(nside, dx, x, vx, mass, rho, hsml, e, ntotal, nvirt)
  implicit none
  integer, parameter :: dp = kind(1.0d0), layers = 3
  integer, intent(in) :: nside
  real(dp), intent(in) :: dx
  real(dp), intent(out) :: x(2, *), vx(2, *), mass(*), rho(*), hsml(*), e(*)
  integer, intent(out) :: ntotal, nvirt
  integer :: a, b, pass, n
  logical :: inside
  n = 0
  do pass = 1, 2
    do b = -layers, nside - 1 + layers
      do a = -layers, nside - 1 + layers
        inside = a >= 0 .and. a < nside .and. b >= 0 .and. b < nside
        if (inside .neqv. pass == 1) cycle
        n = n + 1
        x(1, n) = (a + 0.5_dp) * dx
        x(2, n) = (b + 0.5_dp) * dx
        if (inside) then
          x(1, n) = x(1, n) + 0.15_dp * dx * sin(12.9898_dp * n)
          x(2, n) = x(2, n) + 0.15_dp * dx * cos(78.233_dp * n)
        end if
        vx(:, n) = 0
        if (b >= nside) vx(1, n) = 1  ! the lid
        rho(n) = 1000
        mass(n) = rho(n) * dx * dx
        hsml(n) = 1.2_dp * dx
        e(n) = 0
      end do
    end do
    if (pass == 1) nvirt = n
  end do
  ntotal = n
  nvirt = ntotal - nvirt
end subroutine make_particles

!> Cubic spline (000 eq 26, 2D constant 10 / (7 pi h^2)): value and grad_i W(x_i - x_j, h).
subroutine kernel(r, dxij, h, wij, dwdxij)
  implicit none
  integer, parameter :: dp = kind(1.0d0)
  real(dp), intent(in) :: r, dxij(2), h
  real(dp), intent(out) :: wij, dwdxij(2)
  real(dp), parameter :: pi = 3.14159265358979323846_dp
  real(dp) :: ih, q, factor, f, df
  ih = 1 / h
  q = r * ih
  factor = 10 / (7 * pi) * ih * ih
  if (q < 1) then
    f = 1 - 1.5_dp * q * q + 0.75_dp * q * q * q
    df = -3 * q + 2.25_dp * q * q
  else if (q < 2) then
    f = 0.25_dp * (2 - q)**3
    df = -0.75_dp * (2 - q) * (2 - q)
  else
    f = 0
    df = 0
  end if
  wij = factor * f
  if (r > 0) then
    dwdxij = factor * ih * df * dxij / r
  else
    dwdxij = 0
  end if
end subroutine kernel

!> Linked-list search: every pair within 2 h_ij, h_ij = (h_i + h_j) / 2, once (i < j),
!> none between two virtual particles; w(k) and dwdx(:, k) = grad_i W_ij for each.
subroutine find_pairs(ntotal, nvirt, x, hsml, niac, pair_i, pair_j, w, dwdx)
  implicit none
  integer, parameter :: dp = kind(1.0d0), maxcell = 100000
  integer, intent(in) :: ntotal, nvirt
  real(dp), intent(in) :: x(2, *), hsml(*)
  integer, intent(out) :: niac, pair_i(*), pair_j(*)
  real(dp), intent(out) :: w(*), dwdx(2, *)
  integer, save :: head(maxcell), next(6000)
  integer :: nc(2), cell(2), i, j, a, b, ci
  real(dp) :: lo(2), hi(2), size, hij, dxij(2), r
  lo = [minval(x(1, 1:ntotal)), minval(x(2, 1:ntotal))]
  hi = [maxval(x(1, 1:ntotal)), maxval(x(2, 1:ntotal))]
  size = 2 * maxval(hsml(1:ntotal))
  nc = max(1, min(int((hi - lo) / size) + 1, 300))
  head(1:nc(1) * nc(2)) = 0
  do i = 1, ntotal
    cell = min(int((x(:, i) - lo) / size), nc - 1)
    ci = cell(1) + nc(1) * cell(2) + 1
    next(i) = head(ci)
    head(ci) = i
  end do
  niac = 0
  do i = 1, ntotal
    cell = min(int((x(:, i) - lo) / size), nc - 1)
    do b = max(cell(2) - 1, 0), min(cell(2) + 1, nc(2) - 1)
      do a = max(cell(1) - 1, 0), min(cell(1) + 1, nc(1) - 1)
        j = head(a + nc(1) * b + 1)
        do while (j > 0)
          if (j > i .and. .not. (i > ntotal - nvirt .and. j > ntotal - nvirt)) then
            dxij = x(:, i) - x(:, j)
            r = sqrt(dxij(1) * dxij(1) + dxij(2) * dxij(2))
            hij = (hsml(i) + hsml(j)) / 2
            if (r < 2 * hij) then
              niac = niac + 1
              pair_i(niac) = i
              pair_j(niac) = j
              call kernel(r, dxij, hij, w(niac), dwdx(1, niac))
            end if
          end if
          j = next(j)
        end do
      end do
    end do
  end do
end subroutine find_pairs

!> Summation density at the real particles (self term W(0) included); the virtual ones
!> keep the reference density.
subroutine sum_density(nreal, mass, hsml, niac, pair_i, pair_j, w, rho)
  implicit none
  integer, parameter :: dp = kind(1.0d0)
  integer, intent(in) :: nreal, niac, pair_i(*), pair_j(*)
  real(dp), intent(in) :: mass(*), hsml(*), w(*)
  real(dp), intent(inout) :: rho(*)
  real(dp) :: w0, g(2), zero(2)
  integer :: i, j, k
  zero = 0
  do i = 1, nreal
    call kernel(0.0_dp, zero, hsml(i), w0, g)
    rho(i) = mass(i) * w0
  end do
  do k = 1, niac
    i = pair_i(k)
    j = pair_j(k)
    if (i <= nreal) rho(i) = rho(i) + mass(j) * w(k)
    if (j <= nreal) rho(j) = rho(j) + mass(i) * w(k)
  end do
end subroutine sum_density

!> Velocity gradient dvdx(a, b, i) = dv_a/dx_b = sum_j m_j/rho_j (v_j - v_i)_a g_b, with
!> the i side g = dwdx(:, k) and the j side g = dwdxj(:, k).
subroutine velocity_gradient(ntotal, vx, mass, rho, niac, pair_i, pair_j, dwdx, dwdxj, dvdx)
  implicit none
  integer, parameter :: dp = kind(1.0d0)
  integer, intent(in) :: ntotal, niac, pair_i(*), pair_j(*)
  real(dp), intent(in) :: vx(2, *), mass(*), rho(*), dwdx(2, *), dwdxj(2, *)
  real(dp), intent(out) :: dvdx(2, 2, *)
  real(dp) :: dv(2)
  integer :: i, j, k, a, b
  dvdx(:, :, 1:ntotal) = 0
  do k = 1, niac
    i = pair_i(k)
    j = pair_j(k)
    dv = vx(:, j) - vx(:, i)
    do b = 1, 2
      do a = 1, 2
        dvdx(a, b, i) = dvdx(a, b, i) + mass(j) / rho(j) * dv(a) * dwdx(b, k)
        dvdx(a, b, j) = dvdx(a, b, j) - mass(i) / rho(i) * dv(a) * dwdxj(b, k)
      end do
    end do
  end do
end subroutine velocity_gradient

!> Momentum and energy: sigma = -p I + mu (L + L^T - 2/3 tr L I);
!> dv_i += m_j (sigma_i/rho_i^2 + sigma_j/rho_j^2) . g_i, and j with g_j;
!> de_i += 1/2 m_j (p_i/rho_i^2 + p_j/rho_j^2) (v_i - v_j) . g_i, and j alike.
subroutine rates(ntotal, mass, rho, p, vx, dvdx, niac, pair_i, pair_j, dwdx, dwdxj, dvx, de)
  implicit none
  integer, parameter :: dp = kind(1.0d0)
  real(dp), parameter :: visc = 10
  integer, intent(in) :: ntotal, niac, pair_i(*), pair_j(*)
  real(dp), intent(in) :: mass(*), rho(*), p(*), vx(2, *), dvdx(2, 2, *), dwdx(2, *), dwdxj(2, *)
  real(dp), intent(out) :: dvx(2, *), de(*)
  real(dp) :: sig(2, 2, ntotal), s(2, 2), pij, dv(2), tr
  integer :: i, j, k, a
  do i = 1, ntotal
    tr = dvdx(1, 1, i) + dvdx(2, 2, i)
    s = visc * (dvdx(:, :, i) + transpose(dvdx(:, :, i)))
    do a = 1, 2
      s(a, a) = s(a, a) - visc * 2 * tr / 3 - p(i)
    end do
    sig(:, :, i) = s
  end do
  dvx(:, 1:ntotal) = 0
  de(1:ntotal) = 0
  do k = 1, niac
    i = pair_i(k)
    j = pair_j(k)
    s = sig(:, :, i) / rho(i)**2 + sig(:, :, j) / rho(j)**2
    dvx(:, i) = dvx(:, i) + mass(j) * matmul(s, dwdx(:, k))
    dvx(:, j) = dvx(:, j) + mass(i) * matmul(s, dwdxj(:, k))
    pij = p(i) / rho(i)**2 + p(j) / rho(j)**2
    dv = vx(:, i) - vx(:, j)
    de(i) = de(i) + 0.5_dp * mass(j) * pij * dot_product(dv, dwdx(:, k))
    de(j) = de(j) - 0.5_dp * mass(i) * pij * dot_product(dv, dwdxj(:, k))
  end do
end subroutine rates

subroutine read_options(gradient, check, steps, nside)
  implicit none
  character(len=*), intent(inout) :: gradient, check
  integer, intent(inout) :: steps, nside
  character(len=64) :: arg
  integer :: q, ios
  do q = 1, command_argument_count()
    call get_command_argument(q, arg)
    ios = 0
    if (arg(1:11) == '--gradient=') then
      gradient = arg(12:)
    else if (arg(1:8) == '--check=') then
      check = arg(9:)
    else if (arg(1:8) == '--steps=') then
      read (arg(9:), *, iostat=ios) steps
    else if (arg(1:8) == '--nside=') then
      read (arg(9:), *, iostat=ios) nside
    else
      ios = 1
    end if
    if (ios /= 0) then
      write (*, '(a,a)') 'pair_list_sph: bad option ', trim(arg)
      stop 2
    end if
  end do
end subroutine read_options
