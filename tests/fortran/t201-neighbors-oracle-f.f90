!> t201 (Fortran twin of t201-neighbors-oracle): mfree's cell-list search against an
!> O(N^2) brute-force oracle written here, on random clouds in 2D and 3D with variable
!> supports, for the three neighbour conventions, with ghosts and with a periodic box;
!> then the oracle's lists handed back as the host's own 1-based CSR (index_base = 1,
!> borrowed, rows in reverse order) come out as the same 0-based sorted lists; and the
!> search with a Verlet skin gives the oracle's lists through small and large moves.
program t201_neighbors_oracle_f
  use, intrinsic :: iso_c_binding
  use mfree
  use ftest
  implicit none

  integer, parameter :: n = 400
  real(c_double), parameter :: kappa = 2.0_c_double
  real(c_double), target :: x(3, n), h(n)
  integer(c_int64_t), allocatable, target :: hrow(:)
  integer(c_int32_t), allocatable, target :: hcol(:)
  type(mfree_context) :: ctx
  integer :: d, conv, i
  integer(c_int32_t) :: nghost
  integer(c_int) :: convs(3)

  convs = [MFREE_SEARCH_GATHER, MFREE_SEARCH_SYMMETRIC_MAX, MFREE_SEARCH_SYMMETRIC_MEAN]
  call check_ok(ctx, mfree_context_create(ctx), 'context')
  call rng_seed(201)

  do d = 2, 3
    do i = 1, n
      x(:, i) = [rng_uniform(), rng_uniform(), rng_uniform()]
      if (d == 2) x(3, i) = 0
      h(i) = merge(0.04_c_double, 0.09_c_double, d == 2) * (1 + rng_uniform())
    end do
    do conv = 1, 3
      call compare(d, convs(conv), 0_c_int32_t, .false.)
    end do
    nghost = 50
    call compare(d, MFREE_SEARCH_GATHER, nghost, .false.)
  end do

  ! periodic unit square, one support for all
  do i = 1, n
    x(:, i) = [rng_uniform(), rng_uniform(), 0.0_c_double]
  end do
  h = 0.04_c_double
  call compare(2, MFREE_SEARCH_GATHER, 0_c_int32_t, .true.)

  call check(mfree_context_destroy(ctx) == MFREE_SUCCESS, 'destroy context')
  call finish('t201-neighbors-oracle-f')

contains

  !> Distance of particles i and j, nearest image along periodic axes of [0,1)^dim.
  real(c_double) function dist(dim, i, j, periodic)
    integer, intent(in) :: dim, i, j
    logical, intent(in) :: periodic
    real(c_double) :: dx(3)
    dx(1:dim) = abs(x(1:dim, i) - x(1:dim, j))
    if (periodic) dx(1:dim) = min(dx(1:dim), 1 - dx(1:dim))
    dist = sqrt(sum(dx(1:dim)**2))
  end function dist

  !> Brute force: j is a neighbour of i when r < kappa * H(h_i, h_j) (closed supports:
  !> up to a relative 1e-13; random clouds have no pair that close to the edge).
  logical function oracle(dim, conv, i, j, periodic)
    integer, intent(in) :: dim, i, j
    integer(c_int), intent(in) :: conv
    logical, intent(in) :: periodic
    real(c_double) :: hh
    select case (conv)
    case (MFREE_SEARCH_GATHER)
      hh = h(i)
    case (MFREE_SEARCH_SYMMETRIC_MAX)
      hh = max(h(i), h(j))
    case default
      hh = 0.5_c_double * (h(i) + h(j))
    end select
    oracle = dist(dim, i, j, periodic) <= kappa * hh * (1 + 1e-13_c_double)
  end function oracle

  subroutine compare(dim, conv, ng, periodic)
    integer, intent(in) :: dim
    integer(c_int), intent(in) :: conv
    integer(c_int32_t), intent(in) :: ng
    logical, intent(in) :: periodic
    type(mfree_particles) :: ps, host
    integer(c_int64_t), allocatable :: rowptr(:), orow(:), grow(:)
    integer(c_int32_t), allocatable :: cols(:), ocol(:), gcol(:)
    integer(c_int64_t) :: nnz, onnz, k
    integer :: nown
    character(len=80) :: what
    real(c_double) :: lo(3), hi(3)
    integer(c_int32_t) :: per(3)

    write (what, '(a,i0,a,i0,a,i0,a,l1)') 'dim ', dim, ' convention ', conv, ' ghosts ', ng, &
      ' periodic ', periodic
    nown = n - ng
    call check_ok(ctx, mfree_particles_create(ctx, int(dim, c_int32_t), int(n, c_int32_t), &
                                              ps), 'create')
    call check_ok(ctx, mfree_particles_set_num_ghost(ps, ng), 'set_num_ghost')
    call check_ok(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 3_c_int64_t, &
                                                     MFREE_BORROW), 'set_positions')
    call check_ok(ctx, mfree_particles_set_support(ps, h, 1_c_int64_t, MFREE_BORROW), &
                  'set_support')
    call check_ok(ctx, mfree_particles_set_search(ps, conv, kappa), 'set_search')
    if (periodic) then
      lo = 0
      hi = 1
      per = 1
      call check_ok(ctx, mfree_particles_set_periodic(ps, lo, hi, per), 'set_periodic')
    end if
    call check_ok(ctx, mfree_particles_setup(ps), 'setup: '//trim(what))
    call check_ok(ctx, mfree_particles_get_neighbor_nnz(ps, nnz), 'nnz')
    allocate (rowptr(nown + 1), cols(nnz))
    call check_ok(ctx, mfree_particles_get_neighbors(ps, rowptr, cols), 'get_neighbors')

    allocate (orow(nown + 1), ocol(int(nown, c_int64_t) * n))
    call oracle_lists(dim, conv, nown, periodic, orow, ocol, onnz)
    call check(onnz == nnz, 'nnz equals the oracle''s: '//trim(what))
    call check(same_rows(nown, rowptr, cols, orow, ocol), &
               'every row equals the oracle''s: '//trim(what))
    call check(onnz > 5 * nown, 'several neighbours per particle: '//trim(what))

    ! the oracle's lists as the host's own: 1-based, each row reversed, borrowed
    if (.not. periodic .and. ng == 0) then
      allocate (hrow(nown + 1), hcol(onnz))
      hrow(1) = 1
      do i = 1, nown
        hrow(i + 1) = orow(i + 1) + 1
        do k = 0, orow(i + 1) - orow(i) - 1
          hcol(hrow(i) + k) = ocol(orow(i + 1) - k) + 1
        end do
      end do
      call check_ok(ctx, mfree_particles_create(ctx, int(dim, c_int32_t), &
                                                int(n, c_int32_t), host), 'create (host)')
      call check_ok(ctx, mfree_particles_set_positions(host, x, MFREE_LAYOUT_AOS, &
                                                       3_c_int64_t, MFREE_BORROW), 'positions')
      call check_ok(ctx, mfree_particles_set_neighbors(host, hrow, hcol, 1_c_int32_t, &
                                                       MFREE_BORROW), 'set_neighbors, base 1')
      call check_ok(ctx, mfree_particles_setup(host), 'setup with host lists')
      allocate (grow(nown + 1), gcol(onnz))
      call check_ok(ctx, mfree_particles_get_neighbors(host, grow, gcol), 'get (host)')
      call check(all(grow == orow) .and. all(gcol == ocol(1:onnz)), &
                 '1-based host lists come back 0-based and sorted: '//trim(what))
      call check(mfree_particles_destroy(host) == MFREE_SUCCESS, 'destroy host set')
      deallocate (hrow, hcol)
    end if
    call check(mfree_particles_destroy(ps) == MFREE_SUCCESS, 'destroy')
    if (.not. periodic) call compare_skin(dim, conv, ng, what)
  end subroutine compare

  !> The same search with a Verlet skin s (mfree_particles_set_search_skin): the lists
  !> equal the oracle's at the first setup, after moves shorter than s / 2 (no new
  !> search: the count stays 1) and after a longer move (a second search); x is restored.
  subroutine compare_skin(dim, conv, ng, what)
    integer, intent(in) :: dim
    integer(c_int), intent(in) :: conv
    integer(c_int32_t), intent(in) :: ng
    character(len=*), intent(in) :: what
    real(c_double), parameter :: s = 0.02_c_double
    real(c_double) :: x0(3, n)
    type(mfree_particles) :: ps
    integer(c_int64_t), allocatable :: rowptr(:), orow(:)
    integer(c_int32_t), allocatable :: cols(:), ocol(:)
    integer(c_int64_t) :: nnz, onnz, count
    integer :: i, nown, pass
    real(c_double) :: step, dx(3)

    nown = n - ng
    x0 = x
    allocate (orow(nown + 1), ocol(int(nown, c_int64_t) * n))
    call check_ok(ctx, mfree_particles_create(ctx, int(dim, c_int32_t), int(n, c_int32_t), &
                                              ps), 'create (skin)')
    call check_ok(ctx, mfree_particles_set_num_ghost(ps, ng), 'set_num_ghost (skin)')
    call check_ok(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 3_c_int64_t, &
                                                     MFREE_BORROW), 'set_positions (skin)')
    call check_ok(ctx, mfree_particles_set_support(ps, h, 1_c_int64_t, MFREE_BORROW), &
                  'set_support (skin)')
    call check_ok(ctx, mfree_particles_set_search(ps, conv, kappa), 'set_search (skin)')
    call check_ok(ctx, mfree_particles_set_search_skin(ps, s), 'set_search_skin')
    do pass = 1, 3
      ! pass 2: every particle moves by less than s / 2; pass 3: by more
      step = merge(0.0_c_double, merge(0.2_c_double * s, 0.8_c_double * s, pass == 2), &
                   pass == 1)
      do i = 1, n
        dx = [rng_uniform(), rng_uniform(), rng_uniform()] - 0.5_c_double
        x(1:dim, i) = x(1:dim, i) + step * dx(1:dim)
      end do
      call check_ok(ctx, mfree_particles_setup(ps), 'setup (skin): '//trim(what))
      call check_ok(ctx, mfree_particles_get_search_count(ps, count), 'get_search_count')
      call check(count == merge(2, 1, pass == 3), 'searches run with the skin: '//trim(what))
      call check_ok(ctx, mfree_particles_get_neighbor_nnz(ps, nnz), 'nnz (skin)')
      allocate (rowptr(nown + 1), cols(nnz))
      call check_ok(ctx, mfree_particles_get_neighbors(ps, rowptr, cols), 'get (skin)')
      call oracle_lists(dim, conv, nown, .false., orow, ocol, onnz)
      call check(onnz == nnz .and. same_rows(nown, rowptr, cols, orow, ocol), &
                 'lists with the skin equal the oracle''s: '//trim(what))
      deallocate (rowptr, cols)
    end do
    call check(mfree_particles_set_search_skin(ps, -1.0_c_double) == MFREE_ERR_ARG, &
               'a negative skin is refused')
    call check(mfree_particles_destroy(ps) == MFREE_SUCCESS, 'destroy (skin)')
    x = x0
  end subroutine compare_skin

  !> The oracle's lists of the owned particles, rows ascending like mfree's, 0-based.
  subroutine oracle_lists(dim, conv, nown, periodic, orow, ocol, onnz)
    integer, intent(in) :: dim, nown
    integer(c_int), intent(in) :: conv
    logical, intent(in) :: periodic
    integer(c_int64_t), intent(out) :: orow(:), onnz
    integer(c_int32_t), intent(out) :: ocol(:)
    integer :: i, j
    orow(1) = 0
    onnz = 0
    do i = 1, nown
      do j = 1, n
        if (oracle(dim, conv, i, j, periodic)) then
          onnz = onnz + 1
          ocol(onnz) = int(j - 1, c_int32_t)
        end if
      end do
      orow(i + 1) = onnz
    end do
  end subroutine oracle_lists

  !> Whether the CSR lists (rowptr, cols) have the rows (orow, ocol).
  logical function same_rows(nown, rowptr, cols, orow, ocol)
    integer, intent(in) :: nown
    integer(c_int64_t), intent(in) :: rowptr(:), orow(:)
    integer(c_int32_t), intent(in) :: cols(:), ocol(:)
    integer :: i
    same_rows = .true.
    do i = 1, nown
      if (orow(i + 1) /= rowptr(i + 1)) then
        same_rows = .false.
      else if (any(cols(rowptr(i) + 1:rowptr(i + 1)) /= ocol(orow(i) + 1:orow(i + 1)))) then
        same_rows = .false.
      end if
    end do
  end function same_rows

end program t201_neighbors_oracle_f
