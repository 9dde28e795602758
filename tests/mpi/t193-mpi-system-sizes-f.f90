!> Module mfree's wrappers of the collective calls of a system on ranks from Fortran, on
!> 1-4 ranks (label mpi, under a timeout that fails a hang): the fluid over a halo plan of
!> module mfree_mpi (a lattice in slabs); on one rank only an output too short
!> (mfree_system_rhs's ydot, mfree_system_get_velocity's vhat, mfree_system_get_wall_force's
!> total, mfree_system_apply_mass's Mv, mfree_system_integrate's y) makes every rank
!> return MFREE_ERR_ARG with the faulty rank's message ("rank R: ydot holds ..."), no
!> output written on any rank (the short one and the others keep a sentinel; y and t
!> unchanged), and the next good call gives the values the same call gave before the
!> fault, bit for bit. mfree_system_set_pending_error from Fortran: a fault set on one
!> rank is returned by the next right-hand side on every rank. mfree_system_create_fluid_ranks
!> with global_ids too short on one rank: every rank returns MFREE_ERR_ARG, no system
!> made, the faulty rank's message naming global_ids. The faulty rank is the last, then
!> rank 0.
program t193_mpi_system_sizes_f
  use, intrinsic :: iso_c_binding, only: c_int, c_int32_t, c_int64_t, c_double, c_associated, c_funloc, &
    c_funptr
  use mpi
  use mfree
  use mfree_mpi
  use mpitest_f
  implicit none
  integer, parameter :: nx = 6, nz = 8
  real(c_double), parameter :: d = 0.01_c_double, rho0 = 1000, sentinel = -12345.5_c_double
  type(mfree_context) :: ctx
  type(mfree_halo) :: halo
  type(mfree_system) :: sys, sys2
  real(c_double), allocatable :: x(:, :), y(:), y0(:), yd(:), ref(:), short(:), out(:), vh(:, :), vref(:, :)
  real(c_double), allocatable :: mv(:), mref(:), v(:)
  integer(c_int64_t), allocatable :: ids(:)
  real(c_double) :: width, tot(2), tref(2), tone(1), t
  type(c_funptr) :: exchange, allgather
  integer(c_int32_t) :: no, ng, neq
  integer(c_int64_t) :: nsteps
  integer :: ierr, rank, nprocs, k, i, j, turn, badrank
  character(len=16) :: who

  call mpitest_start(rank, nprocs)
  call check(mfree_context_create(ctx) == MFREE_SUCCESS, 'context')
  call check(mfree_halo_create(ctx, MPI_COMM_WORLD, 2_c_int32_t, halo) == MFREE_SUCCESS, 'halo')
  ! this rank's slab: columns rank * nx .. rank * nx + nx - 1 of an (nx nprocs) x nz lattice
  allocate (x(2, nx * nz), ids(4 * nx * nz * nprocs))
  k = 0
  do j = 0, nz - 1
    do i = 0, nx - 1
      k = k + 1
      x(1, k) = (rank * nx + i + 0.5_c_double) * d
      x(2, k) = (j + 0.5_c_double) * d
      ids(k) = int(j * nx * nprocs + rank * nx + i, c_int64_t)
    end do
  end do
  width = 4 * 1.3_c_double * d + 0.5_c_double * d
  call check(mfree_halo_setup(halo, int(nx * nz, c_int32_t), x, 2_c_int64_t, ids, width) == MFREE_SUCCESS, &
             'halo setup')
  call check(mfree_halo_get_size(halo, no, ng) == MFREE_SUCCESS .and. no == nx * nz, 'halo size')
  call check(mfree_halo_get_global_ids(halo, ids) == MFREE_SUCCESS, 'ids')
  call check(mfree_halo_create_fluid(halo, 2_c_int32_t, width, sys) == MFREE_SUCCESS, 'fluid on ranks')
  call check(mfree_system_set_fluid(sys, rho0, 0_c_int64_t, 1.0e5_c_double, 7.0_c_double, 0.5_c_double) &
             == MFREE_SUCCESS, 'set_fluid')
  call check(mfree_system_set_masses(sys, rho0 * d * d, 0_c_int64_t) == MFREE_SUCCESS, 'set_masses')
  call check(mfree_system_set_smoothing(sys, 1.3_c_double * d) == MFREE_SUCCESS, 'set_smoothing')
  call check(mfree_system_get_size(sys, neq) == MFREE_SUCCESS .and. neq == 5 * no, 'neq')
  allocate (y(5 * no), y0(5 * no), yd(5 * no), ref(5 * no), short(5 * no - 1), out(5 * no), v(5 * no))
  allocate (vh(2, no), vref(2, no), mv(5 * no), mref(5 * no))
  do k = 1, no
    y(2 * k - 1:2 * k) = x(:, k)
    y(2 * no + 2 * k - 1) = 0.1_c_double * sin(real(ids(k), c_double))
    y(2 * no + 2 * k) = 0.1_c_double * cos(real(ids(k), c_double))
    y(4 * no + k) = rho0 * (1 + 1e-3_c_double * sin(0.7_c_double * real(ids(k), c_double)))
  end do
  v = 1
  ! the references, before any fault
  call check(mfree_system_rhs(sys, 0.0_c_double, y, ref) == MFREE_SUCCESS, 'rhs')
  call check(mfree_system_get_velocity(sys, y, vref) == MFREE_SUCCESS, 'velocity')
  call check(mfree_system_get_wall_force(sys, y, tref) == MFREE_SUCCESS, 'wall force')
  call check(mfree_system_apply_mass(sys, y, 0_c_int32_t, v, mref) == MFREE_SUCCESS, 'mass product')
  y0 = y

  do turn = 0, 1
    badrank = merge(nprocs - 1, 0, turn == 0)
    write (who, '(a,i0,a)') 'rank ', badrank, ': '

    ! the right-hand side: ydot one short on the faulty rank
    short = sentinel
    out = sentinel
    if (rank == badrank) then
      call agreed(mfree_system_rhs(sys, 0.0_c_double, y, short), MFREE_ERR_ARG, 'ydot holds', 'rhs')
    else
      call agreed(mfree_system_rhs(sys, 0.0_c_double, y, out), MFREE_ERR_ARG, 'ydot holds', 'rhs')
    end if
    call check(all(short == sentinel) .and. all(out == sentinel), 'rhs: an output written by the failed call')
    call check(mfree_system_rhs(sys, 0.0_c_double, y, yd) == MFREE_SUCCESS, 'rhs after the fault')
    call check(same(yd, ref), 'rhs after the fault differs')

    ! the interpolated velocity: vhat one short
    short = sentinel
    vh = sentinel
    if (rank == badrank) then
      call agreed(mfree_system_get_velocity(sys, y, short(1:2 * no - 1)), MFREE_ERR_ARG, 'vhat holds', 'velocity')
    else
      call agreed(mfree_system_get_velocity(sys, y, vh), MFREE_ERR_ARG, 'vhat holds', 'velocity')
    end if
    call check(all(short == sentinel) .and. all(vh == sentinel), 'velocity: an output written by the failed call')
    call check(mfree_system_get_velocity(sys, y, vh) == MFREE_SUCCESS, 'velocity after the fault')
    call check(same(reshape(vh, [2 * no]), reshape(vref, [2 * no])), 'velocity after the fault differs')

    ! the wall force: total one short
    tone = sentinel
    tot = sentinel
    if (rank == badrank) then
      call agreed(mfree_system_get_wall_force(sys, y, tone), MFREE_ERR_ARG, 'total holds', 'wall force')
    else
      call agreed(mfree_system_get_wall_force(sys, y, tot), MFREE_ERR_ARG, 'total holds', 'wall force')
    end if
    call check(all(tone == sentinel) .and. all(tot == sentinel), 'wall force: an output written by the failed call')
    call check(mfree_system_get_wall_force(sys, y, tot) == MFREE_SUCCESS, 'wall force after the fault')
    call check(same(tot, tref), 'wall force after the fault differs')

    ! the mass product: Mv one short
    short = sentinel
    mv = sentinel
    if (rank == badrank) then
      call agreed(mfree_system_apply_mass(sys, y, 0_c_int32_t, v, short), MFREE_ERR_ARG, 'Mv holds', 'mass product')
    else
      call agreed(mfree_system_apply_mass(sys, y, 0_c_int32_t, v, mv), MFREE_ERR_ARG, 'Mv holds', 'mass product')
    end if
    call check(all(short == sentinel) .and. all(mv == sentinel), 'mass product: an output written by the failed call')
    call check(mfree_system_apply_mass(sys, y, 0_c_int32_t, v, mv) == MFREE_SUCCESS, 'mass product after the fault')
    call check(same(mv, mref), 'mass product after the fault differs')

    ! the integration: y one short; y and t unchanged everywhere, no step
    short = sentinel
    t = 0.5_c_double
    nsteps = -1
    if (rank == badrank) then
      call agreed(mfree_system_integrate(sys, MFREE_INTEGRATOR_LEAPFROG, short, t, 1.0_c_double, 0.5_c_double, &
                                         0.0_c_double, nsteps=nsteps), MFREE_ERR_ARG, 'y holds', 'integrate')
    else
      call agreed(mfree_system_integrate(sys, MFREE_INTEGRATOR_LEAPFROG, y, t, 1.0_c_double, 0.5_c_double, &
                                         0.0_c_double, nsteps=nsteps), MFREE_ERR_ARG, 'y holds', 'integrate')
    end if
    call check(all(short == sentinel) .and. same(y, y0), 'integrate: y written by the failed call')
    call check(t == 0.5_c_double .and. nsteps == 0, 'integrate: t or the step count changed by the failed call')

    ! the setter from Fortran: the next right-hand side fails on every rank with its message
    if (rank == badrank) &
      call check(mfree_system_set_pending_error(sys, MFREE_ERR_MISMATCH, 'mfree_host_check: q holds 2 values') &
                 == MFREE_SUCCESS, 'set_pending_error')
    out = sentinel
    call agreed(mfree_system_rhs(sys, 0.0_c_double, y, out), MFREE_ERR_MISMATCH, 'q holds 2 values', 'pending')
    call check(all(out == sentinel), 'pending: an output written by the failed call')
    call check(mfree_system_rhs(sys, 0.0_c_double, y, out) == MFREE_SUCCESS .and. same(out, ref), &
               'rhs after the pending fault')

    ! creation with global_ids one short on the faulty rank: no system anywhere (the
    ! callbacks' addresses taken at run time: a constant would need a text relocation)
    exchange = c_funloc(mfree_halo_exchange_callback_c)
    allgather = c_funloc(mfree_halo_allgather_c)
    if (rank == badrank) then
      call agreed(mfree_system_create_fluid_ranks(ctx, 2_c_int32_t, no, ng, ids(1:no + ng - 1), width, &
                                                  exchange, allgather, halo%ptr, sys2), &
                  MFREE_ERR_ARG, '', 'creation')
      call check(index(mfree_last_error(ctx), 'global_ids holds') > 0, 'creation: message ' // mfree_last_error(ctx))
    else
      call agreed(mfree_system_create_fluid_ranks(ctx, 2_c_int32_t, no, ng, ids(1:no + ng), width, &
                                                  exchange, allgather, halo%ptr, sys2), &
                  MFREE_ERR_ARG, '', 'creation')
    end if
    call check(.not. c_associated(sys2%ptr), 'creation: a system made by a failed creation')
  end do

  call check(mfree_system_destroy(sys) == MFREE_SUCCESS, 'destroy')
  call check(mfree_halo_destroy(halo) == MFREE_SUCCESS, 'halo destroy')
  call check(mfree_context_destroy(ctx) == MFREE_SUCCESS, 'context destroy')
  call mpitest_finish('t193-mpi-system-sizes-f')

contains

  !> st is want on every rank, and this rank's message names the faulty rank and why
  !> (why empty: only the status is checked).
  subroutine agreed(st, want, why, what)
    integer(c_int), intent(in) :: st, want
    character(len=*), intent(in) :: why, what
    integer :: lo, hi, mine
    mine = st
    call MPI_Allreduce(mine, lo, 1, MPI_INTEGER, MPI_MIN, MPI_COMM_WORLD, ierr)
    call MPI_Allreduce(mine, hi, 1, MPI_INTEGER, MPI_MAX, MPI_COMM_WORLD, ierr)
    call check(lo == want .and. hi == want, what // ': statuses differ from the expected one on some rank')
    if (len(why) > 0) &
      call check(index(mfree_last_error(ctx), trim(who) // ' ' // why) > 0, &
                 what // ': message "' // mfree_last_error(ctx) // '"')
  end subroutine agreed

  !> a and b hold the same bits (the values here are finite).
  logical function same(a, b)
    real(c_double), intent(in) :: a(:), b(:)
    same = size(a) == size(b)
    if (same) same = all(transfer(a, 1_c_int64_t, size(a)) == transfer(b, 1_c_int64_t, size(b)))
  end function same

end program t193_mpi_system_sizes_f
