!> Module mfree_mpi's migration from Fortran on 1-4 ranks (label mpi): a block of a 1D row
!> of particles per rank (x = id / n, velocity (id, -id), global id), registered by c_loc;
!> the host sends every particle to the mirrored rank (set_owners), then Zoltan RCB
!> rebalances (when libmfree_mpi has Zoltan); after each execute every particle's fields
!> are its id's, and the counts sum to the total. The wrappers' array checks in the
!> collective plan calls: an owners or positions array too short on the last rank is
!> MFREE_ERR_ARG on every rank, naming that rank, with no rank left waiting; get_owners
!> with a short array is MFREE_ERR_ARG with nothing written.
program t184_mpi_migrate_f
  use, intrinsic :: iso_c_binding, only: c_int, c_int32_t, c_int64_t, c_double, c_loc
  use mpi
  use mfree
  use mfree_mpi
  use mpitest_f
  implicit none
  integer, parameter :: per_rank = 40
  type(mfree_context) :: ctx
  type(mfree_migration) :: mig
  real(c_double), allocatable, target :: x(:, :), v(:, :)
  integer(c_int64_t), allocatable, target :: ids(:)
  integer(c_int32_t), allocatable :: owners(:), short(:)
  integer(c_int32_t) :: no, n_new, cap, n_owned
  integer(c_int64_t) :: ns, nr
  integer(c_int) :: st_
  integer :: ierr, rank, nprocs, k, last, total
  real(c_double) :: n
  character(len=16) :: who

  call mpitest_start(rank, nprocs)
  last = nprocs - 1
  write (who, '(a,i0,a)') 'rank ', last, ':'
  n = real(per_rank * nprocs, c_double)
  cap = int(per_rank * nprocs, c_int32_t)
  allocate (x(1, cap), v(2, cap), ids(cap), owners(cap), short(1))
  do k = 1, per_rank
    ids(k) = int(rank * per_rank + k - 1, c_int64_t)
  end do
  no = per_rank
  call fill_check(.false., 'start')
  call check(mfree_context_create(ctx) == MFREE_SUCCESS, 'context')
  call check(mfree_migration_create(ctx, MPI_COMM_WORLD, 1_c_int32_t, mig) == MFREE_SUCCESS, 'create')
  call check(mfree_migration_add_field(mig, c_loc(x), 8_c_int64_t, 8_c_int64_t) == MFREE_SUCCESS, 'x')
  call check(mfree_migration_add_field(mig, c_loc(v), 16_c_int64_t, 16_c_int64_t) == MFREE_SUCCESS, 'v')
  call check(mfree_migration_add_field(mig, c_loc(ids), 8_c_int64_t, 8_c_int64_t) == MFREE_SUCCESS, 'ids')

  ! every particle to the mirrored rank
  owners(1:no) = int(nprocs - 1 - rank, c_int32_t)
  call check(mfree_migration_set_owners(mig, no, owners, n_new) == MFREE_SUCCESS, 'set_owners')
  call check(n_new == per_rank, 'n_new')
  call check(mfree_migration_get_counts(mig, n_owned, n_new, ns, nr) == MFREE_SUCCESS, 'counts')
  call check(n_owned == no .and. ns == merge(0, per_rank, nprocs - 1 - rank == rank) .and. ns == nr, 'sent, received')
  if (no > 1) then
    st_ = mfree_migration_get_owners(mig, short)
    call check(st_ == MFREE_ERR_ARG .and. index(mfree_last_error(ctx), 'capacity 1') > 0, &
               'get_owners, short: '//mfree_last_error(ctx))
  end if
  call check(mfree_migration_get_owners(mig, owners) == MFREE_SUCCESS, 'get_owners')
  call check(all(owners(1:no) == nprocs - 1 - rank), 'owners')
  call check(mfree_migration_execute(mig, cap) == MFREE_SUCCESS, 'execute')
  no = n_new
  call check(all(ids(1:no) / per_rank == nprocs - 1 - rank), 'ids of the mirrored rank')
  call fill_check(.true., 'mirrored')

  ! Zoltan RCB, when built in
  st_ = mfree_migration_partition(mig, no, x, 1_c_int64_t, 1_c_int32_t, n_new)
  call check(st_ == MFREE_SUCCESS .or. st_ == MFREE_ERR_UNSUPPORTED, 'partition: '//mfree_last_error(ctx))
  if (st_ == MFREE_SUCCESS) then
    call check(mfree_migration_execute(mig, cap) == MFREE_SUCCESS, 'execute RCB')
    no = n_new
    call fill_check(.true., 'RCB')
  end if

  ! arrays too short on the last rank: every rank fails alike
  if (rank == last) then
    st_ = mfree_migration_set_owners(mig, no, short(1:0), n_new)
  else
    st_ = mfree_migration_set_owners(mig, no, owners, n_new)
  end if
  call check(st_ == MFREE_ERR_ARG .and. index(mfree_last_error(ctx), trim(who)) > 0, &
             'owners too short on the last rank: '//mfree_last_error(ctx))
  if (rank == last .and. no > 0) then
    st_ = mfree_migration_partition(mig, no, x(:, 1:0), 1_c_int64_t, 1_c_int32_t, n_new)
  else
    st_ = mfree_migration_partition(mig, no, x, 1_c_int64_t, 1_c_int32_t, n_new)
  end if
  if (no > 0 .or. rank /= last) &
    call check(st_ /= MFREE_SUCCESS, 'positions too short on the last rank: '//mfree_last_error(ctx))
  call fill_check(.true., 'after the refusals')

  call check(mfree_migration_destroy(mig) == MFREE_SUCCESS, 'destroy')
  call check(mfree_context_destroy(ctx) == MFREE_SUCCESS, 'context destroy')
  call mpitest_finish('t184-mpi-migrate-f')

contains

  !> Fills the fields from the ids (verify = .false.), or checks them; and, collectively,
  !> that the counts sum to the total.
  subroutine fill_check(verify, what)
    logical, intent(in) :: verify
    character(len=*), intent(in) :: what
    integer :: j
    do j = 1, no
      if (verify) then
        call check(x(1, j) == real(ids(j), c_double) / n .and. v(1, j) == real(ids(j), c_double) .and. &
                   v(2, j) == -real(ids(j), c_double), what//': fields of an id')
      else
        x(1, j) = real(ids(j), c_double) / n
        v(:, j) = [real(ids(j), c_double), -real(ids(j), c_double)]
      end if
    end do
    call MPI_Allreduce(int(no), total, 1, MPI_INTEGER, MPI_SUM, MPI_COMM_WORLD, ierr)
    call check(total == per_rank * nprocs, what//': the counts sum to the total')
  end subroutine fill_check

end program t184_mpi_migrate_f
