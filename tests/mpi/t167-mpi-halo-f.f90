!> Module mfree_mpi from Fortran on 1-4 ranks (label mpi): a slab of a 1D row of
!> particles per rank (x_k = k / n, global id k), a plan on MPI_COMM_WORLD of `use mpi`,
!> the ghosts' ids and exchanged positions equal their owners' (x = id / n), the global
!> offset is the exclusive scan, and a plan that is not set up answers MFREE_ERR_STATE.
!> The wrappers' array checks: an ids array too short for get_global_ids is MFREE_ERR_ARG
!> with nothing written; in the collective calls an array too short (or a strided field)
!> on one rank is MFREE_ERR_ARG on every rank, naming that rank, with no ghost written and
!> no rank left waiting; a scalar field h(n) is exchanged as it is. The ghosts' correction
!> records of an RL approximant on the plan's particles come from their owners
!> (mfree_halo_exchange_correction), and SPH, which has none, fails on every rank. The
!> callbacks of systems on ranks: the all-gather in rank order (a capacity beyond out on
!> one rank fails on every rank, one below the total writes nothing) and the exchange
!> callback (a field one short on one rank fails on every rank, naming that rank).
program t167_mpi_halo_f
  use, intrinsic :: iso_c_binding, only: c_int, c_int32_t, c_int64_t, c_double
  use mpi
  use mfree
  use mfree_mpi
  use mpitest_f
  implicit none
  integer, parameter :: per_rank = 50
  type(mfree_context) :: ctx
  type(mfree_halo) :: halo
  real(c_double), allocatable :: x(:, :)
  integer(c_int64_t), allocatable :: ids(:)
  integer(c_int32_t) :: no, ng, nn
  integer(c_int64_t) :: off, total, ns, nr
  integer(c_int) :: st_
  integer :: rank, nprocs, k, last
  real(c_double) :: n
  integer(c_int64_t), allocatable :: short_ids(:)
  real(c_double), allocatable :: h(:), f(:, :)
  type(mfree_context) :: hctx
  type(mfree_particles) :: ps
  type(mfree_approximant) :: rl, sph
  real(c_double), allocatable :: hs(:), vs(:)
  character(len=16) :: who

  call mpitest_start(rank, nprocs)
  n = real(per_rank * nprocs, c_double)
  call check(mfree_context_create(ctx) == MFREE_SUCCESS, 'context')
  call check(mfree_halo_create(ctx, MPI_COMM_WORLD, 1_c_int32_t, halo) == MFREE_SUCCESS, 'create')
  call check(mfree_halo_get_size(halo, no, ng) == MFREE_ERR_STATE, 'not set up')
  allocate (x(1, per_rank + 8), ids(per_rank + 8))
  do k = 1, per_rank
    ids(k) = int(rank * per_rank + k - 1, c_int64_t)
    x(1, k) = real(ids(k), c_double) / n
  end do
  call check(mfree_halo_setup(halo, int(per_rank, c_int32_t), x, 1_c_int64_t, ids, 3.5_c_double / n) &
             == MFREE_SUCCESS, 'setup')
  call check(mfree_halo_get_size(halo, no, ng) == MFREE_SUCCESS, 'size')
  call check(no == per_rank, 'owned count')
  ! 3 ghosts from each side that has a neighbour rank (x within 3.5 / n of the slab)
  call check(ng == 3 * (merge(1, 0, rank > 0) + merge(1, 0, rank < nprocs - 1)), 'ghost count')
  call check(mfree_halo_get_global_ids(halo, ids) == MFREE_SUCCESS, 'ids')
  x(1, no + 1:) = -1
  call check(mfree_halo_exchange(halo, 1_c_int32_t, x, 1_c_int64_t) == MFREE_SUCCESS, 'exchange')
  do k = no + 1, no + ng
    call check(x(1, k) == real(ids(k), c_double) / n, 'ghost position is its owner''s')
    call check(ids(k) < rank * per_rank .or. ids(k) >= (rank + 1) * per_rank, 'ghost from another rank')
  end do
  call check(mfree_halo_get_global_offset(halo, off, total) == MFREE_SUCCESS, 'offset')
  call check(off == rank * per_rank .and. total == per_rank * nprocs, 'exclusive scan')
  call check(mfree_halo_get_plan(halo, nn, ns, nr) == MFREE_SUCCESS, 'plan')
  call check(nr == ng .and. ns == ng .and. nn == merge(1, 0, rank > 0) + merge(1, 0, rank < nprocs - 1), &
             'plan sizes')

  ! ---- the wrappers' array checks ----
  last = nprocs - 1
  write (who, '(a,i0,a)') 'rank ', last, ':'
  call check(mfree_halo_get_context(halo, hctx) == MFREE_SUCCESS, 'get_context')
  allocate (short_ids(no + ng - 1))
  short_ids = -9
  if (no + ng > 0) then
    call check(mfree_halo_get_global_ids(halo, short_ids) == MFREE_ERR_ARG, 'ids one short')
    call check(index(mfree_last_error(hctx), 'ids holds') > 0, 'ids message: '//mfree_last_error(hctx))
    call check(all(short_ids == -9), 'nothing written into a short ids')
  end if
  ! a field one item short on the last rank: every rank fails, naming it, no ghost written
  allocate (f(2, no + ng))
  do k = 1, no + ng
    f(:, k) = merge(real(ids(k), c_double), -1.0_c_double, k <= no)
  end do
  if (rank == last) then
    st_ = mfree_halo_exchange(halo, 2_c_int32_t, f(:, 1:no + ng - 1), 2_c_int64_t)
  else
    st_ = mfree_halo_exchange(halo, 2_c_int32_t, f, 2_c_int64_t)
  end if
  call check(st_ == MFREE_ERR_ARG, 'short field on the last rank: MFREE_ERR_ARG everywhere')
  call check(index(mfree_last_error(hctx), trim(who)) > 0 .and. &
             index(mfree_last_error(hctx), 'field holds') > 0, 'short field message: '//mfree_last_error(hctx))
  call check(all(f(:, no + 1:) == -1.0_c_double), 'no ghost written after a short field')
  ! a strided field (every second column of a wider array) on rank 0
  if (rank == 0) then
    st_ = mfree_halo_exchange(halo, 1_c_int32_t, f(1, :), 2_c_int64_t)
  else
    st_ = mfree_halo_exchange(halo, 1_c_int32_t, f, 2_c_int64_t)
  end if
  call check(st_ == MFREE_ERR_ARG, 'strided field on rank 0: MFREE_ERR_ARG everywhere')
  call check(index(mfree_last_error(hctx), 'rank 0:') > 0 .and. &
             index(mfree_last_error(hctx), 'not contiguous') > 0, 'strided field message: '//mfree_last_error(hctx))
  call check(all(f(:, no + 1:) == -1.0_c_double), 'no ghost written after a strided field')
  ! then the whole field, and a scalar h(n): the owners' values
  call check(mfree_halo_exchange(halo, 2_c_int32_t, f, 2_c_int64_t) == MFREE_SUCCESS, 'exchange after the faults')
  allocate (h(no + ng))
  h = -1
  h(1:no) = 2 * real(ids(1:no), c_double)
  call check(mfree_halo_exchange(halo, 1_c_int32_t, h, 1_c_int64_t) == MFREE_SUCCESS, 'scalar exchange')
  do k = no + 1, no + ng
    call check(f(1, k) == real(ids(k), c_double) .and. f(2, k) == real(ids(k), c_double), 'field at a ghost')
    call check(h(k) == 2 * real(ids(k), c_double), 'scalar at a ghost')
  end do
  ! ids one short on rank 0 at setup: every rank fails, naming rank 0; the plan recovers
  st_ = mfree_halo_setup(halo, no, x, 1_c_int64_t, ids(1:merge(no - 1, no + 0, rank == 0)), 3.5_c_double / n)
  call check(st_ == MFREE_ERR_ARG, 'setup with short ids on rank 0: MFREE_ERR_ARG everywhere')
  call check(index(mfree_last_error(hctx), 'rank 0:') > 0 .and. &
             index(mfree_last_error(hctx), 'ids holds') > 0, 'short ids message: '//mfree_last_error(hctx))
  call check(mfree_halo_setup(halo, no, x, 1_c_int64_t, ids(1:no), 3.5_c_double / n) == MFREE_SUCCESS, &
             'setup again')


  ! ---- the ghosts' correction records ----
  call check(mfree_halo_get_size(halo, no, ng) == MFREE_SUCCESS, 'size again')
  call check(mfree_halo_get_global_ids(halo, ids(1:no + ng)) == MFREE_SUCCESS, 'ids again')
  call check(mfree_halo_exchange(halo, 1_c_int32_t, x(:, 1:no + ng), 1_c_int64_t) == MFREE_SUCCESS, &
             'positions again')
  allocate (hs(no + ng), vs(no + ng))
  hs = 1.2_c_double / n
  vs = 1 / n
  call check(mfree_particles_create(ctx, 1_c_int32_t, no + ng, ps) == MFREE_SUCCESS, 'set')
  call check(mfree_particles_set_num_ghost(ps, ng) == MFREE_SUCCESS, 'ghosts')
  call check(mfree_particles_set_positions(ps, x(:, 1:no + ng), MFREE_LAYOUT_AOS, 1_c_int64_t, MFREE_COPY) &
             == MFREE_SUCCESS, 'positions')
  call check(mfree_particles_set_support(ps, hs, 1_c_int64_t, MFREE_COPY) == MFREE_SUCCESS, 'support')
  call check(mfree_particles_set_volumes(ps, vs, 1_c_int64_t, MFREE_COPY) == MFREE_SUCCESS, 'volumes')
  call check(mfree_particles_set_global_ids(ps, ids(1:no + ng), MFREE_COPY) == MFREE_SUCCESS, 'set ids')
  call check(mfree_particles_setup(ps) == MFREE_SUCCESS, 'set setup')
  call check(mfree_approximant_create(ctx, ps, MFREE_METHOD_RANDLES_LIBERSKY, rl) == MFREE_SUCCESS, 'RL')
  call check(mfree_approximant_create(ctx, ps, MFREE_METHOD_SPH, sph) == MFREE_SUCCESS, 'SPH')
  call check(mfree_approximant_set_derivatives(rl, MFREE_DERIV_GRADIENT) == MFREE_SUCCESS, 'RL gradient')
  call check(mfree_approximant_set_derivatives(sph, MFREE_DERIV_GRADIENT) == MFREE_SUCCESS, 'SPH gradient')
  call check(mfree_approximant_setup(rl) == MFREE_SUCCESS, 'RL setup')
  call check(mfree_approximant_setup(sph) == MFREE_SUCCESS, 'SPH setup')
  call check(mfree_halo_exchange_correction(halo, rl) == MFREE_SUCCESS, 'RL records')
  st_ = mfree_halo_exchange_correction(halo, sph)
  call check(st_ == MFREE_ERR_UNSUPPORTED .and. index(mfree_last_error(hctx), 'rank 0:') > 0, &
             'SPH has no records: '//mfree_last_error(hctx))
  call check(mfree_approximant_destroy(rl) == MFREE_SUCCESS .and. mfree_approximant_destroy(sph) == MFREE_SUCCESS, &
             'approximants destroy')
  call check(mfree_particles_destroy(ps) == MFREE_SUCCESS, 'set destroy')

  ! ---- the callbacks of systems on ranks, called from Fortran ----
  ! the all-gather: rank r gives r + 1 values r; the total and the concatenation in rank
  ! order; an out one short on the last rank fails on every rank, nothing written
  deallocate (hs, vs)
  allocate (hs(rank + 1), vs(nprocs * (nprocs + 1) / 2))
  hs = real(rank, c_double)
  vs = -1
  call check(mfree_halo_allgather(halo, hs, int(rank + 1, c_int64_t), vs, size(vs, kind=c_int64_t), total) &
             == MFREE_SUCCESS, 'allgather')
  call check(total == nprocs * (nprocs + 1) / 2, 'allgather total')
  do k = 0, nprocs - 1
    call check(all(vs(k * (k + 1) / 2 + 1:k * (k + 1) / 2 + k + 1) == real(k, c_double)), &
               'allgather: rank order')
  end do
  vs = -1
  st_ = mfree_halo_allgather(halo, hs, int(rank + 1, c_int64_t), vs, &
                             size(vs, kind=c_int64_t) + merge(1, 0, rank == last), total)
  call check(st_ == MFREE_ERR_ARG .and. index(mfree_last_error(hctx), trim(who)) > 0, &
             'allgather, a capacity beyond out on the last rank: '//mfree_last_error(hctx))
  call check(all(vs == -1), 'nothing written by a failed allgather')
  ! a capacity below the total on one rank: no rank writes, the total is given
  total = -1
  call check(mfree_halo_allgather(halo, hs, int(rank + 1, c_int64_t), vs, &
                                  size(vs, kind=c_int64_t) - merge(1, 0, rank == last), total) &
             == MFREE_SUCCESS .and. total == nprocs * (nprocs + 1) / 2, 'allgather, total only')
  call check(all(vs == -1), 'nothing written below the total')
  ! the exchange callback: the ghosts' positions again
  x(1, no + 1:no + ng) = -1
  call check(mfree_halo_exchange_callback(halo, 1_c_int32_t, x, 1_c_int64_t) == MFREE_SUCCESS, &
             'exchange callback')
  do k = no + 1, no + ng
    call check(x(1, k) == real(ids(k), c_double) / n, 'exchange callback: ghost position is its owner''s')
  end do
  ! the callback with a field one item short on the last rank: every rank fails, naming it,
  ! no ghost written
  x(1, no + 1:no + ng) = -1
  if (rank == last) then
    st_ = mfree_halo_exchange_callback(halo, 1_c_int32_t, x(:, 1:no + ng - 1), 1_c_int64_t)
  else
    st_ = mfree_halo_exchange_callback(halo, 1_c_int32_t, x(:, 1:no + ng), 1_c_int64_t)
  end if
  call check(st_ == MFREE_ERR_ARG .and. index(mfree_last_error(hctx), trim(who)) > 0 .and. &
             index(mfree_last_error(hctx), 'field holds') > 0, &
             'exchange callback, short field on the last rank: '//mfree_last_error(hctx))
  call check(all(x(1, no + 1:no + ng) == -1.0_c_double), 'no ghost written by a failed exchange callback')
  deallocate (hs, vs)

  call check(mfree_halo_destroy(halo) == MFREE_SUCCESS, 'destroy')
  call check(mfree_context_destroy(ctx) == MFREE_SUCCESS, 'context destroy')
  call mpitest_finish('t167-mpi-halo-f')

end program t167_mpi_halo_f
