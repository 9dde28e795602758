!> Fortran twin of t441: bad input through module mfree cannot corrupt the host. Arrays
!> one element too short, non-contiguous sections where mfree writes or borrows, bad pair
!> lists: each returns its documented status with a message, writes nothing, and leaves
!> the objects usable. Also: default-kind integers for strides and counts, 32-bit CSR
!> offsets (copied), and the same pair gradients through the Fortran and C layouts.
program t442
  use, intrinsic :: iso_c_binding, only: c_int, c_int32_t, c_int64_t, c_double
  use mfree
  use ftest
  implicit none
  integer, parameter :: m = 6, n = m * m
  real(c_double), target :: x(3, n), h(n), vol(n), big(4, 4 * n * n)
  real(c_double), allocatable, target :: gi(:, :), gj(:, :), ref(:, :), cor(:, :)
  real(c_double), allocatable, target :: gg(:, :), ggj(:, :), refj(:, :)
  integer, target :: pi(n * n), pj(n * n), nbrow(n + 1), nbcol(n * n)
  integer(c_int64_t), target :: rowptr(n + 1)
  integer(c_int32_t), target :: cols(n * n)
  integer :: niac, p, q, k, nnz
  integer(c_int) :: st
  integer(c_int32_t) :: nc
  type(mfree_context) :: ctx
  type(mfree_particles) :: ps, pc, pg
  type(mfree_approximant) :: a, ag
  character(len=:), allocatable :: msg

  do p = 1, n
    x(1, p) = mod(p - 1, m) + 0.01_c_double * mod(p, 3)
    x(2, p) = (p - 1) / m + 0.01_c_double * mod(p, 5)
    x(3, p) = 0
    h(p) = 1.2_c_double
    vol(p) = 1
  end do
  niac = 0
  do p = 1, n
    do q = p + 1, n
      if (sum((x(1:2, p) - x(1:2, q))**2) < 4 * 1.2_c_double**2) then
        niac = niac + 1
        pi(niac) = p
        pj(niac) = q
      end if
    end do
  end do

  call check_ok(ctx, mfree_context_create(ctx), 'context')
  call check_ok(ctx, mfree_particles_create(ctx, 2, n, ps), 'create')
  ! default-kind integers for leading dimensions and strides
  call check_ok(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 3, MFREE_BORROW), 'x')
  call check_ok(ctx, mfree_particles_set_support(ps, h, 1, MFREE_BORROW), 'h')
  call check_ok(ctx, mfree_particles_set_volumes(ps, vol(1), 0, MFREE_COPY), 'volumes')

  ! ---- borrowing a non-contiguous section is refused; copying it is fine ----------------
  st = mfree_particles_set_positions(ps, big(1:3, 1:n), MFREE_LAYOUT_AOS, 3, MFREE_BORROW)
  call check(st == MFREE_ERR_ARG, 'borrowing a section of x: MFREE_ERR_ARG')
  msg = mfree_last_error(ctx)
  call check(index(msg, 'not contiguous') > 0, 'message names the non-contiguous array: ' // msg)
  st = mfree_particles_set_support(ps, big(1, 1:2 * n:2), 1, MFREE_BORROW)
  call check(st == MFREE_ERR_ARG, 'borrowing a strided h: MFREE_ERR_ARG')
  big(1:3, 1:n) = x
  call check_ok(ctx, mfree_particles_set_positions(ps, big(1:3, 1:n), MFREE_LAYOUT_AOS, 3, &
                                                   MFREE_COPY), 'copying a section of x')
  call check_ok(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 3, MFREE_BORROW), 'x again')

  ! ---- pair lists: default-kind niac, 1-based; bad lists ----------------------------------
  st = mfree_particles_set_pairs(ps, niac, pi, pj, 1, MFREE_BORROW)
  call check_ok(ctx, st, 'set_pairs')
  call check(mfree_particles_set_pairs(ps, -1, pi, pj, 1, MFREE_COPY) == MFREE_ERR_ARG, 'negative count')
  call check(mfree_particles_set_pairs(ps, niac, pi, pj, 2, MFREE_COPY) == MFREE_ERR_ARG, 'index base 2')
  call check(mfree_particles_set_pairs(ps, niac, pi, pj, 0, MFREE_COPY) == MFREE_ERR_INPUT, &
             '1-based list passed as 0-based')
  call check(mfree_particles_set_pairs(ps, niac + 1, pi(1:niac), pj(1:niac), 1, MFREE_COPY) == &
             MFREE_ERR_ARG, 'pair arrays shorter than npairs')
  call check(index(mfree_last_error(ctx), 'npairs') > 0, 'message names npairs')
  call check(mfree_particles_set_pairs(ps, niac, pi(1:2 * niac:2), pj, 1, MFREE_BORROW) == &
             MFREE_ERR_ARG, 'borrowing strided pair_i')
  q = pi(3)
  pi(3) = pj(3)
  st = mfree_particles_set_pairs(ps, niac, pi, pj, 1, MFREE_COPY)
  call check(st == MFREE_ERR_INPUT, 'self pair')
  call check(index(mfree_last_error(ctx), 'pair 3 (1-based)') > 0, 'self pair named 1-based: ' // &
             mfree_last_error(ctx))
  pi(3) = q
  pi(niac + 1) = pj(5)
  pj(niac + 1) = pi(5)
  call check_ok(ctx, mfree_particles_set_pairs(ps, niac + 1, pi, pj, 1, MFREE_COPY), 'duplicate list')
  call check(mfree_particles_setup(ps) == MFREE_ERR_INPUT, 'duplicate pair at setup')
  call check(index(mfree_last_error(ctx), 'duplicate') > 0, 'duplicate named')
  call check_ok(ctx, mfree_particles_set_pairs(ps, niac, pi, pj, 1, MFREE_BORROW), 'good list')
  call check_ok(ctx, mfree_particles_setup(ps), 'setup')

  ! ---- pair gradients: arrays too small or not contiguous; nothing written -----------------
  call check_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_RANDLES_LIBERSKY, a), 'create')
  call check_ok(ctx, mfree_approximant_set_derivatives(a, MFREE_DERIV_GRADIENT), 'flags')
  call check_ok(ctx, mfree_approximant_setup(a), 'approximant setup')
  allocate (ref(3, niac), gi(3, niac), gj(3, niac))
  call check_ok(ctx, mfree_approximant_get_pair_gradients(a, ref), 'reference gradients')
  gi = -7
  gj = -7
  call check(mfree_approximant_get_pair_gradients(a, gi(:, 1:niac - 1)) == MFREE_ERR_ARG, &
             'gi one column short')
  call check(index(mfree_last_error(ctx), 'are needed') > 0, 'short gi: message')
  call check(mfree_approximant_get_pair_gradients(a, gi, gj(:, 1:niac - 1)) == MFREE_ERR_ARG, &
             'gj one column short')
  call check(mfree_approximant_get_pair_gradients(a, gi(1:1, :)) == MFREE_ERR_ARG, 'gi with one row')
  call check(mfree_approximant_get_pair_gradients(a, big(1:3, 1:2 * niac:2)) == MFREE_ERR_ARG, &
             'strided gi')
  call check(mfree_approximant_get_pair_gradients_antisymmetric(a, gi(:, 1:niac - 1)) == &
             MFREE_ERR_ARG, 'antisymmetric one column short')
  call check(all(gi == -7) .and. all(gj == -7), 'nothing written')
  call check_ok(ctx, mfree_approximant_get_pair_gradients(a, gi, gj), 'pair gradients')
  call check(all(gi(1:2, :) == ref(1:2, :)), 'same gradients after the failures')
  ! the C layout: ld = 2 records
  deallocate (gi)
  allocate (gi(2, niac))
  call check_ok(ctx, mfree_approximant_get_pair_gradients(a, gi), 'gi(2, niac)')
  call check(all(gi == ref(1:2, :)), 'ld 2 and ld 3 agree')

  ! ---- correction data ----------------------------------------------------------------
  call check_ok(ctx, mfree_approximant_get_correction_size(a, nc), 'correction size')
  call check(nc == 4, 'RL: 4 doubles in 2D')
  allocate (cor(nc, n))
  cor = -7
  call check(mfree_approximant_get_correction(a, cor(:, 1:n - 1)) == MFREE_ERR_ARG, 'correction short')
  call check(mfree_approximant_get_correction(a, cor(1:nc - 1, :)) == MFREE_ERR_ARG, 'correction rows')
  call check(all(cor == -7), 'correction: nothing written')
  call check_ok(ctx, mfree_approximant_get_correction(a, cor), 'correction')
  ! the RL gradient of pair 1 is M dwdx with M = reshape(cor(:, i), [2, 2])
  k = 1
  call check(maxval(abs(gi(:, k) - matmul(reshape(cor(:, pi(k)), [2, 2]), rl_dwdx(k)))) <= &
             1e-12_c_double * maxval(abs(gi(:, k))), 'RL record: M dwdx')

  ! ---- ghost correction data: the last row of particles as ghosts, their records from a ----
  ! ---- (where they are owned): too small is refused; a strided section is packed ---------
  call check_ok(ctx, mfree_particles_create(ctx, 2, n, pg), 'pg create')
  call check_ok(ctx, mfree_particles_set_num_ghost(pg, m), 'pg ghosts')
  call check_ok(ctx, mfree_particles_set_positions(pg, x, MFREE_LAYOUT_AOS, 3, MFREE_BORROW), 'pg x')
  call check_ok(ctx, mfree_particles_set_support(pg, h, 1, MFREE_BORROW), 'pg h')
  call check_ok(ctx, mfree_particles_set_volumes(pg, vol(1), 0, MFREE_COPY), 'pg volumes')
  call check_ok(ctx, mfree_particles_set_pairs(pg, niac, pi, pj, 1, MFREE_BORROW), 'pg pairs')
  call check_ok(ctx, mfree_particles_setup(pg), 'pg setup')
  call check_ok(ctx, mfree_approximant_create(ctx, pg, MFREE_METHOD_RANDLES_LIBERSKY, ag), 'ag create')
  call check_ok(ctx, mfree_approximant_set_derivatives(ag, MFREE_DERIV_GRADIENT), 'ag flags')
  call check_ok(ctx, mfree_approximant_setup(ag), 'ag setup')
  call check(mfree_approximant_set_ghost_correction(ag, cor(:, n - m + 1:n - 1)) == MFREE_ERR_ARG, &
             'ghost correction one column short')
  call check(index(mfree_last_error(ctx), 'are needed') > 0, 'short ghost records: message')
  call check(mfree_approximant_set_ghost_correction(ag, cor(1:nc - 1, n - m + 1:n)) == MFREE_ERR_ARG, &
             'ghost correction rows')
  big(1:nc, 1:2 * m:2) = cor(:, n - m + 1:n)
  call check_ok(ctx, mfree_approximant_set_ghost_correction(ag, big(1:nc, 1:2 * m:2)), 'ghost records')
  allocate (gg(3, niac), ggj(3, niac), refj(3, niac))
  call check_ok(ctx, mfree_approximant_get_pair_gradients(a, ref, refj), 'one set, both sides')
  call check_ok(ctx, mfree_approximant_get_pair_gradients(ag, gg, ggj), 'ghosts, both sides')
  call check(all(gg(1:2, :) == ref(1:2, :)) .and. all(ggj(1:2, :) == refj(1:2, :)), &
             'ghost sides from the records: equal')
  call check_ok(ctx, mfree_approximant_destroy(ag), 'destroy ag')
  call check_ok(ctx, mfree_particles_destroy(pg), 'destroy pg')

  ! ---- exports: too short or not contiguous -------------------------------------------------
  call check_ok(ctx, mfree_particles_get_neighbor_nnz(ps, rowptr(1)), 'nnz')
  nnz = int(rowptr(1))
  call check(mfree_particles_get_neighbors(ps, rowptr(1:n), cols) == MFREE_ERR_ARG, 'rowptr short')
  call check(mfree_particles_get_neighbors(ps, rowptr, cols(1:nnz - 1)) == MFREE_ERR_ARG, 'cols short')
  call check_ok(ctx, mfree_particles_get_neighbors(ps, rowptr, cols), 'get_neighbors')
  call check(mfree_particles_get_volumes(ps, vol(1:n - 1)) == MFREE_ERR_ARG, 'volumes short')
  call check(mfree_approximant_assemble_csr(a, MFREE_DERIV_GRADIENT, 0, vals=big(1, 1:nnz - 1)) == &
             MFREE_ERR_ARG, 'assemble_csr: vals not contiguous')
  call check(mfree_approximant_apply(a, MFREE_OP_GRADIENT, 1, h, MFREE_LAYOUT_AOS, 1, &
                                     big(1:2, 1:n - 1), MFREE_LAYOUT_AOS, 2) == MFREE_ERR_ARG, &
             'apply: out not contiguous')
  call check(mfree_approximant_apply(a, MFREE_OP_GRADIENT, 1, h, MFREE_LAYOUT_AOS, 1, &
                                     gi(:, 1:n - 1), MFREE_LAYOUT_AOS, 2) == MFREE_ERR_ARG, &
             'apply: out one particle short')
  call check_ok(ctx, mfree_approximant_apply(a, MFREE_OP_GRADIENT, 1, h, MFREE_LAYOUT_AOS, 1, &
                                             gi(:, 1:n), MFREE_LAYOUT_AOS, 2), 'apply')

  ! ---- host CSR lists with 32-bit offsets: copied, equal to the pair list's rows ------------
  nbrow(1) = 1
  do p = 1, n
    nbrow(p + 1) = nbrow(p) + int(rowptr(p + 1) - rowptr(p))
    nbcol(nbrow(p):nbrow(p + 1) - 1) = cols(rowptr(p) + 1:rowptr(p + 1)) + 1
  end do
  call check_ok(ctx, mfree_particles_create(ctx, 2, n, pc), 'create pc')
  call check_ok(ctx, mfree_particles_set_positions(pc, x, MFREE_LAYOUT_AOS, 3, MFREE_BORROW), 'pc x')
  call check(mfree_particles_set_neighbors(pc, nbrow, nbcol, 1, MFREE_BORROW) == MFREE_ERR_ARG, &
             '32-bit offsets cannot be borrowed')
  call check_ok(ctx, mfree_particles_set_neighbors(pc, nbrow, nbcol, 1, MFREE_COPY), '32-bit offsets')
  call check_ok(ctx, mfree_particles_setup(pc), 'pc setup')
  call check_ok(ctx, mfree_particles_get_neighbor_nnz(pc, rowptr(1)), 'pc nnz')
  call check(rowptr(1) == nnz, 'same neighbour count from 32-bit CSR lists')

  call check_ok(ctx, mfree_approximant_destroy(a), 'destroy a')
  call check_ok(ctx, mfree_particles_destroy(pc), 'destroy pc')
  call check_ok(ctx, mfree_particles_destroy(ps), 'destroy ps')
  call check_ok(ctx, mfree_context_destroy(ctx), 'destroy ctx')
  deallocate (gi, gj, ref, cor, gg, ggj, refj, msg)  ! (a main program's allocatables live to the end)
  call finish('t442')

contains

  !> grad_i W(x_i - x_j, h) of pair k, from mfree's kernel evaluation.
  function rl_dwdx(kk) result(g)
    integer, intent(in) :: kk
    real(c_double) :: g(2), d(2), r(1), dw(1)
    d = x(1:2, pi(kk)) - x(1:2, pj(kk))
    r(1) = sqrt(sum(d**2))
    call check_ok(ctx, mfree_kernel_eval(ctx, MFREE_KERNEL_CUBIC_SPLINE, 2, 0.0_c_double, &
                                         1.2_c_double, 1, r, dwdr=dw), 'kernel')
    g = dw(1) * d / r(1)
  end function rl_dwdx

end program t442
