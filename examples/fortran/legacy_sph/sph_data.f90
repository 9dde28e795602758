!> Data of the legacy SPH code: fixed-size arrays sized at compile time, as such codes
!> have them. TARGET because mfree borrows some of them (x, h, pm, rho, nbrow, nbcol):
!> it keeps their addresses and re-reads them at every update.
module sph_data
  implicit none
  integer, parameter :: dp = kind(1.0d0)
  integer, parameter :: NMAX = 6400          ! particles
  integer, parameter :: NBMAX = 40 * NMAX    ! neighbour pairs
  integer, parameter :: NCMAX = 128 * 128    ! linked cells

  integer :: n                               ! particles in use
  real(dp), target :: x(3, NMAX)             ! positions (2D run: third row unused)
  real(dp), target :: v(3, NMAX)             ! velocities
  real(dp), target :: h(NMAX)                ! smoothing lengths
  real(dp), target :: pm(NMAX)               ! masses
  real(dp), target :: rho(NMAX)              ! densities
  real(dp) :: drho(NMAX)                     ! continuity: d rho / dt
  real(dp) :: dvdx(2, 2, NMAX)               ! dvdx(d, c, i) = d v_c / d x_d at i

  ! neighbour list, CSR with Fortran (1-based) indices: the neighbours of i are
  ! nbcol(nbrow(i) : nbrow(i+1) - 1). int64 offsets and int32 columns, the index types
  ! of the mfree ABI, so that the list can be lent to mfree as it is.
  integer(8), target :: nbrow(NMAX + 1)
  integer(4), target :: nbcol(NBMAX)

  ! linked cells
  integer :: head(NCMAX), next(NMAX)
end module sph_data
