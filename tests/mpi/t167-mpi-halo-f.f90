!> Module mfree_mpi from Fortran on 1-4 ranks (label mpi): a slab of a 1D row of
!> particles per rank (x_k = k / n, global id k), a plan on MPI_COMM_WORLD of `use mpi`,
!> the ghosts' ids and exchanged positions equal their owners' (x = id / n), the global
!> offset is the exclusive scan, and a plan that is not set up answers MFREE_ERR_STATE.
program t167_mpi_halo_f
  use, intrinsic :: iso_c_binding, only: c_int, c_int32_t, c_int64_t, c_double
  use mpi
  use mfree
  use mfree_mpi
  implicit none
  integer, parameter :: per_rank = 50
  type(mfree_context) :: ctx
  type(mfree_halo) :: halo
  real(c_double), allocatable :: x(:, :)
  integer(c_int64_t), allocatable :: ids(:)
  integer(c_int32_t) :: no, ng, nn
  integer(c_int64_t) :: off, total, ns, nr
  integer :: ierr, rank, nprocs, k, bad, allbad
  real(c_double) :: n

  call MPI_Init(ierr)
  call MPI_Comm_rank(MPI_COMM_WORLD, rank, ierr)
  call MPI_Comm_size(MPI_COMM_WORLD, nprocs, ierr)
  bad = 0
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
  call check(mfree_halo_destroy(halo) == MFREE_SUCCESS, 'destroy')
  call check(mfree_context_destroy(ctx) == MFREE_SUCCESS, 'context destroy')
  call MPI_Allreduce(bad, allbad, 1, MPI_INTEGER, MPI_SUM, MPI_COMM_WORLD, ierr)
  if (rank == 0) write (*, '(a,i0,a)') 't167-mpi-halo-f: ', allbad, ' failed checks'
  call MPI_Finalize(ierr)
  if (allbad /= 0) stop 1

contains

  subroutine check(cond, what)
    logical, intent(in) :: cond
    character(len=*), intent(in) :: what
    if (.not. cond) then
      write (*, '(a,i0,a,a)') 'rank ', rank, ': check failed: ', what
      bad = bad + 1
    end if
  end subroutine check

end program t167_mpi_halo_f
