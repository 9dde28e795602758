!> legacy_slab: a 2D particle code on MPI ranks written the way legacy hydrocodes are:
!> fixed-size arrays, its own slab decomposition along x (rank r owns the particles with
!> r/P <= x < (r+1)/P) and its own halo exchange (MPI_Sendrecv of the particles within
!> the halo width of each slab edge to the left and right neighbour), calling mfree's
!> Randles-Libersky corrected gradient on owned + ghost particles with global ids.
!>
!> The velocity is linear, v = A x + b, which RL differentiates exactly; the code prints
!> the largest error of grad v at its owned particles and a checksum of the gradient bits
!> keyed by global id (an exclusive or over the ranks: independent of the decomposition),
!> so that runs on 1 and on P ranks can be compared bit for bit.
!>   --nside=M   M x M particles (default 120)     --check   exit 1 unless exact to 1e-10
program legacy_slab
  use, intrinsic :: iso_c_binding, only: c_int, c_int32_t, c_int64_t, c_double
  use mpi
  use mfree
  implicit none

  integer, parameter :: dp = c_double, NMAX = 400000
  real(dp), parameter :: amat(2, 2) = reshape([0.10_dp, -0.30_dp, 0.40_dp, -0.05_dp], [2, 2])
  real(dp), parameter :: bvec(2) = [0.02_dp, -0.01_dp]
  ! one record per particle, owned then ghosts: x, y, h, m, rho, vx, vy
  integer, parameter :: NREC = 7
  real(dp) :: rec(NREC, NMAX), dvdx(2, 2, NMAX), sendl(NREC, NMAX), sendr(NREC, NMAX)
  integer(c_int64_t) :: gid(NMAX), gsendl(NMAX), gsendr(NMAX)
  integer :: nside, nown, nghost, ntot, ierr, rank, nprocs, i, k, nl, nr, rl, rr, left, right
  integer :: status(MPI_STATUS_SIZE)
  real(dp) :: dx, width, x0, x1, xi, yi, err, errmax
  integer(c_int64_t) :: csum, csum_all
  logical :: check
  character(len=64) :: arg
  type(mfree_context) :: ctx
  type(mfree_particles) :: ps
  type(mfree_approximant) :: ap

  call MPI_Init(ierr)
  call MPI_Comm_rank(MPI_COMM_WORLD, rank, ierr)
  call MPI_Comm_size(MPI_COMM_WORLD, nprocs, ierr)
  nside = 120
  check = .false.
  do i = 1, command_argument_count()
    call get_command_argument(i, arg)
    if (arg(1:8) == '--nside=') read (arg(9:), *) nside
    if (arg == '--check') check = .true.
  end do

  ! ---- own particles: the slab [x0, x1) of a perturbed lattice on the unit square ----
  dx = 1.0_dp / nside
  x0 = real(rank, dp) / nprocs
  x1 = real(rank + 1, dp) / nprocs
  nown = 0
  do k = 0, nside * nside - 1
    xi = (mod(k, nside) + 0.5_dp + 0.1_dp * sin(12.9898_dp * k)) * dx
    yi = (k / nside + 0.5_dp + 0.1_dp * cos(78.233_dp * k)) * dx
    if (xi < x0 .or. (xi >= x1 .and. rank < nprocs - 1)) cycle
    nown = nown + 1
    if (nown > NMAX) error stop 'legacy_slab: NMAX too small'
    rec(:, nown) = [xi, yi, 1.3_dp * dx, 1000 * dx * dx, 1000.0_dp, 0.0_dp, 0.0_dp]
    rec(6:7, nown) = bvec + matmul(amat, rec(1:2, nown))
    gid(nown) = k
  end do

  ! ---- its own halo exchange: particles within the width of each slab edge ----
  width = 2 * maxval(rec(3, 1:nown)) * 1.1_dp
  call MPI_Allreduce(MPI_IN_PLACE, width, 1, MPI_DOUBLE_PRECISION, MPI_MAX, MPI_COMM_WORLD, ierr)
  left = merge(rank - 1, MPI_PROC_NULL, rank > 0)
  right = merge(rank + 1, MPI_PROC_NULL, rank < nprocs - 1)
  nl = 0
  nr = 0
  do i = 1, nown
    if (rec(1, i) < x0 + width) then
      nl = nl + 1
      sendl(:, nl) = rec(:, i)
      gsendl(nl) = gid(i)
    end if
    if (rec(1, i) >= x1 - width) then
      nr = nr + 1
      sendr(:, nr) = rec(:, i)
      gsendr(nr) = gid(i)
    end if
  end do
  rl = 0
  rr = 0
  call MPI_Sendrecv(nl, 1, MPI_INTEGER, left, 1, rr, 1, MPI_INTEGER, right, 1, MPI_COMM_WORLD, status, ierr)
  call MPI_Sendrecv(nr, 1, MPI_INTEGER, right, 2, rl, 1, MPI_INTEGER, left, 2, MPI_COMM_WORLD, status, ierr)
  nghost = rl + rr
  ntot = nown + nghost
  if (ntot > NMAX) error stop 'legacy_slab: NMAX too small for the ghosts'
  call MPI_Sendrecv(sendl, NREC * nl, MPI_DOUBLE_PRECISION, left, 3, rec(1, nown + 1), NREC * rr, &
                    MPI_DOUBLE_PRECISION, right, 3, MPI_COMM_WORLD, status, ierr)
  call MPI_Sendrecv(gsendl, nl, MPI_INTEGER8, left, 4, gid(nown + 1), rr, MPI_INTEGER8, right, 4, &
                    MPI_COMM_WORLD, status, ierr)
  call MPI_Sendrecv(sendr, NREC * nr, MPI_DOUBLE_PRECISION, right, 5, rec(1, nown + rr + 1), NREC * rl, &
                    MPI_DOUBLE_PRECISION, left, 5, MPI_COMM_WORLD, status, ierr)
  call MPI_Sendrecv(gsendr, nr, MPI_INTEGER8, right, 6, gid(nown + rr + 1), rl, MPI_INTEGER8, left, 6, &
                    MPI_COMM_WORLD, status, ierr)

  ! ---- mfree's RL gradient on the host's arrays (borrowed), ghosts last, global ids ----
  call ok(mfree_context_create(ctx))
  call ok(mfree_particles_create(ctx, 2_c_int32_t, int(ntot, c_int32_t), ps))
  call ok(mfree_particles_set_num_ghost(ps, int(nghost, c_int32_t)))
  ! (array elements, not sections: a strided section would be lent as a temporary copy)
  call ok(mfree_particles_set_positions(ps, rec, MFREE_LAYOUT_AOS, int(NREC, c_int64_t), MFREE_BORROW))
  call ok(mfree_particles_set_support(ps, rec(3, 1), int(NREC, c_int64_t), MFREE_BORROW))
  call ok(mfree_particles_set_masses(ps, rec(4, 1), int(NREC, c_int64_t), MFREE_BORROW))
  call ok(mfree_particles_set_densities(ps, rec(5, 1), int(NREC, c_int64_t), MFREE_BORROW))
  call ok(mfree_particles_set_global_ids(ps, gid, MFREE_BORROW))
  call ok(mfree_particles_set_halo_width(ps, width))
  call ok(mfree_approximant_create(ctx, ps, MFREE_METHOD_RANDLES_LIBERSKY, ap))
  call ok(mfree_approximant_set_derivatives(ap, MFREE_DERIV_GRADIENT))
  call ok(mfree_approximant_setup(ap))
  call ok(mfree_approximant_apply(ap, MFREE_OP_GRADIENT, 2_c_int32_t, rec(6, 1), MFREE_LAYOUT_AOS, &
                                  int(NREC, c_int64_t), dvdx, MFREE_LAYOUT_AOS, 4_c_int64_t))

  ! ---- error at owned particles and the checksum of the gradient bits by global id ----
  errmax = 0
  csum = 0
  do i = 1, nown
    err = maxval(abs(dvdx(:, :, i) - transpose(amat)))
    errmax = max(errmax, err)
    csum = ieor(csum, mix(gid(i), dvdx(:, :, i)))
  end do
  call MPI_Allreduce(MPI_IN_PLACE, errmax, 1, MPI_DOUBLE_PRECISION, MPI_MAX, MPI_COMM_WORLD, ierr)
  call MPI_Allreduce(csum, csum_all, 1, MPI_INTEGER8, MPI_BXOR, MPI_COMM_WORLD, ierr)
  if (rank == 0) then
    write (*, '(a,i0,a,i0,a,es10.3)') 'legacy_slab: ', nside * nside, ' particles on ', nprocs, &
      ' ranks, max |grad v - A| = ', errmax
    write (*, '(a,z16.16)') 'checksum ', csum_all
  end if
  call ok(mfree_approximant_destroy(ap))
  call ok(mfree_particles_destroy(ps))
  call ok(mfree_context_destroy(ctx))
  if (check .and. .not. errmax < 1e-10_dp) then
    if (rank == 0) write (*, '(a)') 'check FAILED: RL is not exact to 1e-10'
    call MPI_Finalize(ierr)
    stop 1
  end if
  call MPI_Finalize(ierr)

contains

  !> The bits of the four gradient components mixed with the particle's global id.
  integer(c_int64_t) function mix(id, g)
    integer(c_int64_t), intent(in) :: id
    real(dp), intent(in) :: g(4)
    integer(c_int64_t) :: z
    integer :: q
    z = id
    do q = 1, 4
      z = ieor(ishftc(z, 23), transfer(g(q), z))
      z = ieor(z, ishft(z, -29))
    end do
    mix = z
  end function mix

  subroutine ok(st)
    integer(c_int), intent(in) :: st
    if (st /= MFREE_SUCCESS) then
      write (*, '(a,i0,a,a)') 'legacy_slab: rank ', rank, ': mfree: ', mfree_last_error(ctx)
      call MPI_Abort(MPI_COMM_WORLD, 3, ierr)
    end if
  end subroutine ok

end program legacy_slab
