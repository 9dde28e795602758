!> t101 (Fortran twin of t101-particles-data): particle sets built on the host's own
!> arrays without copies. x(3,n) is MFREE_LAYOUT_AOS with ld = 3 (also in 2D, where the
!> third row is skipped), x(n,3) is MFREE_LAYOUT_SOA with ld = n, padded arrays use their
!> leading extent; all give the same neighbour lists. Borrowed arrays changed by the host
!> after the call are seen at the next setup (positions) or read (volumes, masses,
!> densities); copied ones are not.
module t101_util
  use, intrinsic :: iso_c_binding
  use mfree
  use ftest
  implicit none
  private
  public :: lists_t, get_lists, same_lists

  type :: lists_t
    integer(c_int64_t), allocatable :: rowptr(:)
    integer(c_int32_t), allocatable :: cols(:)
  end type lists_t

contains

  subroutine get_lists(ctx, ps, n, l)
    type(mfree_context), intent(in) :: ctx
    type(mfree_particles), intent(in) :: ps
    integer, intent(in) :: n
    type(lists_t), intent(out) :: l
    integer(c_int64_t) :: nnz
    call check_ok(ctx, mfree_particles_get_neighbor_nnz(ps, nnz), 'get_neighbor_nnz')
    allocate (l%rowptr(n + 1), l%cols(max(nnz, 1_c_int64_t)))
    call check_ok(ctx, mfree_particles_get_neighbors(ps, l%rowptr, l%cols), 'get_neighbors')
  end subroutine get_lists

  logical function same_lists(a, b)
    type(lists_t), intent(in) :: a, b
    integer(c_int64_t) :: nnz
    same_lists = all(a%rowptr == b%rowptr)
    if (.not. same_lists) return
    nnz = a%rowptr(size(a%rowptr))
    same_lists = all(a%cols(1:nnz) == b%cols(1:nnz))
  end function same_lists

end module t101_util

program t101_particles_data_f
  use, intrinsic :: iso_c_binding
  use mfree
  use ftest
  use t101_util
  implicit none

  integer, parameter :: n = 80
  integer(c_int32_t), parameter :: n32 = n
  ! Host arrays: TARGET because mfree keeps their addresses (MFREE_BORROW).
  real(c_double), target :: xa(3, n), xs(n, 3), xpad(5, n), xspad(n + 7, 3), x2(2, n)
  real(c_double), target :: hs, h(n), vol(n), m(n), rho(n), got(n)
  type(mfree_context) :: ctx
  type(mfree_particles) :: pa, psoa, ppad, pspad, pcopy, p2a, p2c
  type(lists_t) :: la, ls, lpad, lspad, lcopy, l2a, l2c, lmoved
  integer(c_int32_t) :: dim, nn, ng
  integer(c_int64_t) :: k
  integer :: i, far
  logical :: ok

  call rng_seed(101)
  do i = 1, n
    xa(:, i) = [rng_uniform(), rng_uniform(), rng_uniform()]
  end do
  xs = transpose(xa)
  xpad = -1.0e30_c_double        ! padding rows must never be read
  xpad(1:3, :) = xa
  xspad = -1.0e30_c_double
  xspad(1:n, :) = xs
  hs = 0.12_c_double
  h = hs

  call check_ok(ctx, mfree_context_create(ctx), 'context')

  ! ---- the same cloud through four layouts, all borrowed, one copied --------------------
  call new_set(pa, 3_c_int32_t, xa, MFREE_LAYOUT_AOS, 3_c_int64_t, MFREE_BORROW)
  call new_set(psoa, 3_c_int32_t, xs, MFREE_LAYOUT_SOA, int(n, c_int64_t), MFREE_BORROW)
  call new_set(ppad, 3_c_int32_t, xpad, MFREE_LAYOUT_AOS, 5_c_int64_t, MFREE_BORROW)
  call new_set(pspad, 3_c_int32_t, xspad, MFREE_LAYOUT_SOA, int(n + 7, c_int64_t), &
               MFREE_BORROW)
  call new_set(pcopy, 3_c_int32_t, xa, MFREE_LAYOUT_AOS, 3_c_int64_t, MFREE_COPY)
  call get_lists(ctx, pa, n, la)
  call get_lists(ctx, psoa, n, ls)
  call get_lists(ctx, ppad, n, lpad)
  call get_lists(ctx, pspad, n, lspad)
  call get_lists(ctx, pcopy, n, lcopy)
  call check(la%rowptr(n + 1) > 2 * n, 'the cloud has neighbour pairs beyond the self pairs')
  call check(same_lists(la, ls), 'x(3,n) AoS ld=3 and x(n,3) SoA ld=n: same lists')
  call check(same_lists(la, lpad), 'x(5,n) AoS ld=5: same lists')
  call check(same_lists(la, lspad), 'x(n+7,3) SoA ld=n+7: same lists')
  call check(same_lists(la, lcopy), 'copied positions: same lists')

  call check_ok(ctx, mfree_particles_get_dimension(pa, dim), 'get_dimension')
  call check_ok(ctx, mfree_particles_get_size(pa, nn, ng), 'get_size')
  call check(dim == 3 .and. nn == n .and. ng == 0, 'dimension 3, n particles, no ghosts')
  call check_ok(ctx, mfree_particles_get_size(pa, n_ghost=ng), 'get_size, n omitted')

  ! ---- 2D from x(3,n) with ld = 3 equals 2D from a compact copy x2(2,n) ------------------
  x2 = xa(1:2, :)
  call new_set(p2a, 2_c_int32_t, xa, MFREE_LAYOUT_AOS, 3_c_int64_t, MFREE_BORROW)
  call new_set(p2c, 2_c_int32_t, x2, MFREE_LAYOUT_AOS, 2_c_int64_t, MFREE_COPY)
  call get_lists(ctx, p2a, n, l2a)
  call get_lists(ctx, p2c, n, l2c)
  call check(same_lists(l2a, l2c), '2D: x(3,n) ld=3 equals x2(2,n) ld=2')
  call check(l2a%rowptr(n + 1) > la%rowptr(n + 1), '2D lists are denser than 3D ones')

  ! ---- no copies: move a particle far away in the host arrays, set up again -------------
  far = 17
  xa(:, far) = [10.0_c_double, 10.0_c_double, 10.0_c_double]
  xs(far, :) = xa(:, far)
  call check_ok(ctx, mfree_particles_update(pa), 'update (lists kept)')
  call get_lists(ctx, pa, n, lmoved)
  call check(same_lists(la, lmoved), 'update re-reads positions but keeps the lists')
  call check_ok(ctx, mfree_particles_setup(pa), 'setup after the move (AoS)')
  call check_ok(ctx, mfree_particles_setup(psoa), 'setup after the move (SoA)')
  call check_ok(ctx, mfree_particles_setup(pcopy), 'setup (copied positions)')
  call get_lists(ctx, pa, n, la)
  call get_lists(ctx, psoa, n, ls)
  call get_lists(ctx, pcopy, n, lmoved)
  call check(la%rowptr(far + 1) - la%rowptr(far) == 1, 'AoS: moved particle sees only itself')
  call check(la%cols(la%rowptr(far) + 1) == far - 1, 'its row holds its own 0-based index')
  ok = .true.
  do i = 1, n
    if (i == far) cycle
    do k = la%rowptr(i) + 1, la%rowptr(i + 1)
      if (la%cols(k) == far - 1) ok = .false.
    end do
  end do
  call check(ok, 'AoS: no other row lists the moved particle')
  call check(same_lists(la, ls), 'SoA sees the same move')
  call check(same_lists(lmoved, lcopy), 'the copied set did not see the move')

  ! ---- borrowed volumes, masses and densities are read when used -------------------------
  do i = 1, n
    vol(i) = 1.0e-3_c_double * i
    m(i) = 2.0e-3_c_double * i
    rho(i) = 1000.0_c_double + i
  end do
  call check_ok(ctx, mfree_particles_set_volumes(pa, vol, 1_c_int64_t, MFREE_BORROW), &
                'set_volumes (borrowed)')
  call check_ok(ctx, mfree_particles_get_volumes(pa, got), 'get_volumes')
  call check(all(got == vol), 'volumes read from the host array')
  vol(5) = 0.5_c_double
  call check_ok(ctx, mfree_particles_get_volumes(pa, got), 'get_volumes after a change')
  call check(got(5) == 0.5_c_double, 'a changed borrowed volume is seen without a new set')

  call check_ok(ctx, mfree_particles_set_masses(psoa, m, 1_c_int64_t, MFREE_BORROW), &
                'set_masses (borrowed)')
  call check_ok(ctx, mfree_particles_set_densities(psoa, rho, 1_c_int64_t, MFREE_BORROW), &
                'set_densities (borrowed)')
  call check_ok(ctx, mfree_particles_get_volumes(psoa, got), 'get_volumes = m/rho')
  call check(maxval(abs(got - m / rho)) <= 1e-15_c_double, 'volumes are m/rho')
  rho(9) = 2.0_c_double * rho(9)
  m(10) = 3.0_c_double * m(10)
  call check_ok(ctx, mfree_particles_get_volumes(psoa, got), 'get_volumes after changes')
  call check(abs(got(9) - m(9) / rho(9)) <= 1e-18_c_double .and. &
             abs(got(10) - m(10) / rho(10)) <= 1e-18_c_double, &
             'changed borrowed masses and densities are seen')

  ! one mass for all (stride 0, a scalar), copied: later host changes are not seen
  hs = 7.0_c_double
  call check_ok(ctx, mfree_particles_set_masses(psoa, hs, 0_c_int64_t, MFREE_COPY), &
                'set_masses (scalar, copied)')
  hs = 8.0_c_double
  call check_ok(ctx, mfree_particles_get_volumes(psoa, got), 'get_volumes')
  call check(maxval(abs(got - 7.0_c_double / rho)) <= 1e-15_c_double, &
             'a copied scalar is not re-read')

  call check(mfree_particles_destroy(pa) == MFREE_SUCCESS, 'destroy')
  call check(mfree_particles_destroy(psoa) == MFREE_SUCCESS, 'destroy')
  call check(mfree_particles_destroy(ppad) == MFREE_SUCCESS, 'destroy')
  call check(mfree_particles_destroy(pspad) == MFREE_SUCCESS, 'destroy')
  call check(mfree_particles_destroy(pcopy) == MFREE_SUCCESS, 'destroy')
  call check(mfree_particles_destroy(p2a) == MFREE_SUCCESS, 'destroy')
  call check(mfree_particles_destroy(p2c) == MFREE_SUCCESS, 'destroy')
  call check(mfree_context_destroy(ctx) == MFREE_SUCCESS, 'destroy context')
  call finish('t101-particles-data-f')

contains

  !> A set of n particles on the host array x (any rank; passed by address), support h.
  subroutine new_set(ps, d, x, layout, ld, mem)
    type(mfree_particles), intent(out) :: ps
    integer(c_int32_t), intent(in) :: d
    real(c_double), intent(in), target :: x(*)
    integer(c_int), intent(in) :: layout, mem
    integer(c_int64_t), intent(in) :: ld
    call check_ok(ctx, mfree_particles_create(ctx, d, n32, ps), 'particles_create')
    call check_ok(ctx, mfree_particles_set_positions(ps, x, layout, ld, mem), 'set_positions')
    call check_ok(ctx, mfree_particles_set_support(ps, h, 1_c_int64_t, MFREE_BORROW), &
                  'set_support (array)')
    call check_ok(ctx, mfree_particles_setup(ps), 'setup')
  end subroutine new_set

end program t101_particles_data_f
