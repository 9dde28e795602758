!> The mfree glue of the legacy SPH code: the host's own arrays are lent to mfree (no
!> copies), and mfree's corrected gradient replaces the SPH velocity gradient. These are
!> the lines a host adds (bindings/fortran/README.md quotes them).
module sph_mfree
  use, intrinsic :: iso_c_binding, only: c_int, c_int32_t, c_int64_t
  use mfree
  use sph_data
  implicit none
  private
  public :: mfree_gradient_init, mfree_gradient, mfree_gradient_done

  type(mfree_context) :: ctx
  type(mfree_particles) :: ps
  type(mfree_approximant) :: ap

contains

  !> Lend x(3,n), h(n), pm(n), rho(n) (and the host's 1-based CSR neighbour list) to
  !> mfree and build the gradient tables of the given method.
  subroutine mfree_gradient_init(method, host_neighbors)
    integer(c_int), intent(in) :: method
    logical, intent(in) :: host_neighbors
    call ok(mfree_context_create(ctx))
    call ok(mfree_particles_create(ctx, 2_c_int32_t, int(n, c_int32_t), ps))
    call ok(mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 3_c_int64_t, MFREE_BORROW))
    call ok(mfree_particles_set_support(ps, h, 1_c_int64_t, MFREE_BORROW))
    call ok(mfree_particles_set_masses(ps, pm, 1_c_int64_t, MFREE_BORROW))
    call ok(mfree_particles_set_densities(ps, rho, 1_c_int64_t, MFREE_BORROW))
    if (host_neighbors) call ok(mfree_particles_set_neighbors(ps, nbrow, nbcol, &
                                                              1_c_int32_t, MFREE_BORROW))
    call ok(mfree_approximant_create(ctx, ps, method, ap))
    call ok(mfree_approximant_set_derivatives(ap, MFREE_DERIV_GRADIENT))
    call ok(mfree_approximant_setup(ap))
  end subroutine mfree_gradient_init

  !> dvdx(d, c, i) = d v_c / d x_d: mfree writes direction d of component c at c*dim + d,
  !> which is dvdx(d, c, i) for dvdx(2, 2, n). moved: particles moved since the last call
  !> (re-read the borrowed arrays, keep the neighbour pattern).
  subroutine mfree_gradient(moved)
    logical, intent(in) :: moved
    if (moved) then
      call ok(mfree_particles_update(ps))
      call ok(mfree_approximant_update(ap))
    end if
    call ok(mfree_approximant_apply(ap, MFREE_OP_GRADIENT, 2_c_int32_t, v, MFREE_LAYOUT_AOS, &
                                    3_c_int64_t, dvdx, MFREE_LAYOUT_AOS, 4_c_int64_t))
  end subroutine mfree_gradient

  subroutine mfree_gradient_done()
    call ok(mfree_approximant_destroy(ap))
    call ok(mfree_particles_destroy(ps))
    call ok(mfree_context_destroy(ctx))
  end subroutine mfree_gradient_done

  !> Stop with mfree's message on any failure.
  subroutine ok(st)
    integer(c_int), intent(in) :: st
    if (st /= MFREE_SUCCESS) then
      write (*, '(a,a,a,a)') 'legacy_sph: mfree: ', mfree_status_string(st), ': ', &
        mfree_last_error(ctx)
      error stop 3
    end if
  end subroutine ok

end module sph_mfree
