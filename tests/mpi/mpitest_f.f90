!> Helpers of the Fortran MPI tests (label mpi), as mpitest.c's for C: the start (MPI_Init,
!> this rank and the number of ranks of MPI_COMM_WORLD), a check that prints and counts its
!> failures on this rank, and the end, where the ranks agree on the verdict.
module mpitest_f
  use mpi
  implicit none
  private
  public :: mpitest_start, check, mpitest_finish
  integer, save :: my_rank = 0, failures = 0
contains

  !> MPI_Init; rank and nprocs of MPI_COMM_WORLD.
  subroutine mpitest_start(rank, nprocs)
    integer, intent(out) :: rank, nprocs
    integer :: ierr
    call MPI_Init(ierr)
    call MPI_Comm_rank(MPI_COMM_WORLD, rank, ierr)
    call MPI_Comm_size(MPI_COMM_WORLD, nprocs, ierr)
    my_rank = rank
  end subroutine mpitest_start

  !> A failed check (cond false): printed with this rank and what, and counted.
  subroutine check(cond, what)
    logical, intent(in) :: cond
    character(len=*), intent(in) :: what
    if (.not. cond) then
      write (*, '(a,i0,a,a)') 'rank ', my_rank, ': check failed: ', what
      failures = failures + 1
    end if
  end subroutine check

  !> Every rank's failed checks summed and printed by rank 0 ("<name>: N failed checks"),
  !> then MPI_Finalize; the program stops with code 1 when any rank failed a check.
  subroutine mpitest_finish(name)
    character(len=*), intent(in) :: name
    integer :: total, ierr
    call MPI_Allreduce(failures, total, 1, MPI_INTEGER, MPI_SUM, MPI_COMM_WORLD, ierr)
    if (my_rank == 0) write (*, '(a,a,i0,a)') name, ': ', total, ' failed checks'
    call MPI_Finalize(ierr)
    if (total /= 0) stop 1
  end subroutine mpitest_finish

end module mpitest_f
