!> Installed-tree Fortran consumer (t954): 4 particles on a unit square plus one far away,
!> positions borrowed from x(3,n) (ld = 3, 2D), h = 0.6, gather search with kappa 2:
!> each corner sees itself and its two edge neighbours but not the diagonal one, the far
!> particle only itself: 13 neighbour pairs. The MLS gradient of u = 2x - 3y at the
!> corners is exact. Prints "...: ok" on success.
program app
  use, intrinsic :: iso_c_binding
  use mfree
  implicit none
  real(c_double), target :: x(3, 5), h
  real(c_double) :: u(5), g(2, 4)
  type(mfree_context) :: ctx
  type(mfree_particles) :: ps
  type(mfree_approximant) :: a
  integer(c_int64_t) :: nnz
  integer(c_int) :: st
  logical :: ok

  x = reshape([0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 5, 5, 0], [3, 5])
  h = 0.6_c_double
  u = 2 * x(1, :) - 3 * x(2, :)
  nnz = -1
  g = 0
  ok = mfree_version_check()
  st = mfree_context_create(ctx)
  if (st == MFREE_SUCCESS) st = mfree_particles_create(ctx, 2_c_int32_t, 5_c_int32_t, ps)
  if (st == MFREE_SUCCESS) st = mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, &
                                                              3_c_int64_t, MFREE_BORROW)
  if (st == MFREE_SUCCESS) st = mfree_particles_set_support(ps, h, 0_c_int64_t, MFREE_COPY)
  if (st == MFREE_SUCCESS) st = mfree_particles_setup(ps)
  if (st == MFREE_SUCCESS) st = mfree_particles_get_neighbor_nnz(ps, nnz)
  ok = ok .and. st == MFREE_SUCCESS .and. nnz == 13
  ! the far particle has no neighbours to fit a gradient: the four corners only
  if (st == MFREE_SUCCESS) st = mfree_particles_set_num_ghost(ps, 1_c_int32_t)
  if (st == MFREE_SUCCESS) st = mfree_particles_setup(ps)
  if (st == MFREE_SUCCESS) st = mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, a)
  if (st == MFREE_SUCCESS) st = mfree_approximant_setup(a)
  if (st == MFREE_SUCCESS) st = mfree_approximant_apply(a, MFREE_OP_GRADIENT, 1_c_int32_t, u, &
                                MFREE_LAYOUT_AOS, 1_c_int64_t, g, MFREE_LAYOUT_AOS, 2_c_int64_t)
  ok = ok .and. st == MFREE_SUCCESS .and. maxval(abs(g(1, :) - 2)) < 1e-12_c_double .and. &
       maxval(abs(g(2, :) + 3)) < 1e-12_c_double
  if (st /= MFREE_SUCCESS) write (*, '(a,a)') 'mfree: ', mfree_last_error(ctx)
  write (*, '(a,a,a,i0,a,a)') 'mfree ', mfree_version_string(), ' Fortran consumer: ', nnz, &
    ' neighbour pairs (expected 13), exact MLS gradient: ', merge('ok    ', 'FAILED', ok)
  st = mfree_approximant_destroy(a)
  st = mfree_particles_destroy(ps)
  st = mfree_context_destroy(ctx)
  if (.not. ok) stop 1
end program app
