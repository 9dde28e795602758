!> t801 (Fortran twin of t601/t650 solved through the SuiteSparse adapter, from Fortran):
!>  A. strong-form collocation of -Lap u = f with SSPH (order 2) on a jittered 9 x 9
!>     cloud of the unit square, u quadratic, u = g on the boundary by row replacement,
!>     solved with UMFPACK and KLU: SSPH reproduces quadratics in the value and Hessian
!>     tables exactly (paper 001 Sect. 3, consistency), so the exact nodal values
!>     solve the discrete system and the error is round-off (tolerance 1e-9, as t601);
!>  B. Bubnov-Galerkin Laplace with MLS (order 1), background Gauss cells and Nitsche's
!>     method for u = g on the whole boundary, u linear, solved with CHOLMOD (Bubnov +
!>     symmetric Nitsche: symmetric positive definite). Nitsche is consistent and MLS is
!>     linearly complete, so the only error is the quadrature of the rational MLS
!>     functions: it falls with the Gauss order (checked), and with 8 x 8 points per cell
!>     it is below 1e-4 of the field's range (the bound t601 asserts for EFG patch tests).
!> Also: zero-copy CSR views of the matrix as Fortran pointers give the same product as
!> mfree_matrix_apply, an in-place solve, and solver statistics.
module t801_fields
  use, intrinsic :: iso_c_binding, only: c_ptr, c_double, c_f_pointer, c_associated
  implicit none
  private
  public :: quad_u, quad_f, lin_u

contains

  !> u = c(1) + c(2) x + c(3) y + c(4) x^2 + c(5) xy + c(6) y^2, c from the user pointer
  !> (the host's data reach a callback through user, as in C).
  subroutine quad_u(user, x, value) bind(C)
    type(c_ptr), value :: user
    real(c_double), intent(in) :: x(*)
    real(c_double), intent(out) :: value(*)
    real(c_double), pointer :: c(:)
    call c_f_pointer(user, c, [6])
    value(1) = c(1) + c(2) * x(1) + c(3) * x(2) + c(4) * x(1)**2 + c(5) * x(1) * x(2) + &
               c(6) * x(2)**2
  end subroutine quad_u

  !> f = -Lap u = -2 (c(4) + c(6)), constant: x enters with weight 0 (a reference keeps
  !> -Wall's unused-argument warning quiet).
  subroutine quad_f(user, x, value) bind(C)
    type(c_ptr), value :: user
    real(c_double), intent(in) :: x(*)
    real(c_double), intent(out) :: value(*)
    real(c_double), pointer :: c(:)
    call c_f_pointer(user, c, [6])
    value(1) = -2 * (c(4) + c(6)) + 0 * x(1)
  end subroutine quad_f

  !> u = 1 + 2x + 3y; no user data (NULL)
  subroutine lin_u(user, x, value) bind(C)
    type(c_ptr), value :: user
    real(c_double), intent(in) :: x(*)
    real(c_double), intent(out) :: value(*)
    if (c_associated(user)) error stop 'lin_u takes no user data'
    value(1) = 1 + 2 * x(1) + 3 * x(2)
  end subroutine lin_u

end module t801_fields

program t801_suitesparse_solve_f
  use, intrinsic :: iso_c_binding
  use mfree
  use mfree_suitesparse
  use ftest
  use t801_fields
  implicit none

  integer, parameter :: m = 9, n = m * m
  real(c_double), target :: x(2, n), h, vol
  ! u = 1 + 2x - y + 0.5x^2 - 0.3xy + 0.8y^2
  real(c_double), target :: coef(6) = [1.0_c_double, 2.0_c_double, -1.0_c_double, &
                                       0.5_c_double, -0.3_c_double, 0.8_c_double]
  integer(c_int32_t) :: bnd(n), nb
  type(mfree_context) :: ctx
  type(mfree_particles) :: ps
  real(c_double) :: errs(2)
  integer, parameter :: gauss_orders(2) = [2, 8]
  integer :: i, j, p, t
  logical :: onb

  call check_ok(ctx, mfree_context_create(ctx), 'context')
  call rng_seed(801)
  nb = 0
  do j = 0, m - 1
    do i = 0, m - 1
      p = j * m + i + 1
      onb = i == 0 .or. j == 0 .or. i == m - 1 .or. j == m - 1
      x(:, p) = [real(i, c_double), real(j, c_double)]
      if (.not. onb) x(:, p) = x(:, p) + 0.25_c_double * [2 * rng_uniform() - 1, &
                                                          2 * rng_uniform() - 1]
      x(:, p) = x(:, p) / (m - 1)
      if (onb) then
        nb = nb + 1
        bnd(nb) = int(p - 1, c_int32_t)   ! mfree takes 0-based particle indices here
      end if
    end do
  end do
  h = 1.6_c_double / (m - 1)
  vol = 1.0_c_double / (m - 1)**2
  call check_ok(ctx, mfree_particles_create(ctx, 2_c_int32_t, int(n, c_int32_t), ps), 'create')
  call check_ok(ctx, mfree_particles_set_positions(ps, x, MFREE_LAYOUT_AOS, 2_c_int64_t, &
                                                   MFREE_BORROW), 'positions')
  call check_ok(ctx, mfree_particles_set_support(ps, h, 0_c_int64_t, MFREE_COPY), 'support')
  call check_ok(ctx, mfree_particles_set_volumes(ps, vol, 0_c_int64_t, MFREE_COPY), 'volumes')
  call check_ok(ctx, mfree_particles_setup(ps), 'setup')

  call collocation(MFREE_SOLVER_UMFPACK)
  call collocation(MFREE_SOLVER_KLU)
  do t = 1, 2
    call galerkin(gauss_orders(t), errs(t))
  end do
  write (*, '(a,2es10.2)') 'Galerkin (MLS + Nitsche) nodal error, 2x2 and 8x8 Gauss:', errs
  call check(errs(2) < errs(1), 'Galerkin error falls with the quadrature order')
  call check(errs(2) < 1e-4_c_double * 5, 'Galerkin error < 1e-4 of the range of u (5)')

  call check(mfree_particles_destroy(ps) == MFREE_SUCCESS, 'destroy particles')
  call check(mfree_context_destroy(ctx) == MFREE_SUCCESS, 'destroy context')
  call finish('t801-suitesparse-solve-f')

contains

  subroutine collocation(kind)
    integer(c_int), intent(in) :: kind
    type(mfree_approximant) :: a
    type(mfree_assembler) :: as
    type(mfree_matrix) :: K
    type(mfree_solver) :: s
    integer(c_int32_t) :: ndofs
    real(c_double), allocatable, target :: f(:), u(:), f2(:, :), u2(:, :)
    real(c_double) :: exact(1), err, rcond
    integer(c_int32_t) :: width
    integer :: q

    call check_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_SSPH, a), 'SSPH')
    call check_ok(ctx, mfree_approximant_set_kernel(a, MFREE_KERNEL_REVISED_SUPER_GAUSS, &
                                                    1.6_c_double), 'kernel')
    call check_ok(ctx, mfree_approximant_set_order(a, 2_c_int32_t), 'order 2')
    call check_ok(ctx, mfree_approximant_set_derivatives(a, ior(ior(MFREE_DERIV_VALUE, &
                  MFREE_DERIV_GRADIENT), MFREE_DERIV_HESSIAN)), 'derivatives')
    call check_ok(ctx, mfree_assembler_create(ctx, a, mfree_approximant(), &
                                              MFREE_FORM_COLLOCATION_LAPLACE, as), 'assembler')
    call check_ok(ctx, mfree_assembler_set_body_force(as, quad_f, c_loc(coef)), 'body force')
    call check_ok(ctx, mfree_assembler_add_dirichlet_nodes(as, nb, bnd, 1_c_int32_t, quad_u, &
                                                        c_loc(coef)), &
                  'dirichlet nodes')
    call check_ok(ctx, mfree_assembler_setup(as), 'assembler setup')
    call check_ok(ctx, mfree_assembler_get_size(as, ndofs), 'size')
    call check(ndofs == n, 'one unknown per particle')
    call check_ok(ctx, mfree_assembler_assemble_matrix(as, K), 'assemble K')
    allocate (f(ndofs), u(ndofs), f2(ndofs, 2), u2(ndofs, 2))
    call check_ok(ctx, mfree_assembler_assemble_rhs(as, f), 'assemble f')

    call check_ok(ctx, mfree_suitesparse_create(ctx, kind, s), 'solver')
    call check_ok(ctx, mfree_suitesparse_setup(s, K), 'factorise')
    call check_ok(ctx, mfree_suitesparse_solve(s, 1_c_int32_t, f, int(ndofs, c_int64_t), u, &
                                               int(ndofs, c_int64_t)), 'solve')
    err = 0
    do q = 1, n
      call quad_u(c_loc(coef), x(:, q), exact)
      err = max(err, abs(u(q) - exact(1)))
    end do
    write (*, '(a,i0,a,es10.2)') 'SSPH collocation, solver ', kind, ': nodal error', err
    call check(err < 1e-9_c_double, 'SSPH collocation exact for a quadratic field')

    ! in place: x holds b on entry (b omitted)
    u = f
    call check_ok(ctx, mfree_suitesparse_solve(s, 1_c_int32_t, ldb=int(ndofs, c_int64_t), &
                                               x=u, ldx=int(ndofs, c_int64_t)), 'in place')
    err = 0
    do q = 1, n
      call quad_u(c_loc(coef), x(:, q), exact)
      err = max(err, abs(u(q) - exact(1)))
    end do
    call check(err < 1e-9_c_double, 'in-place solve gives the same solution')

    ! arrays too short for ldx * nrhs (x) or ldb * nrhs (b), x not contiguous: MFREE_ERR_ARG,
    ! nothing written; two right-hand sides in one rank-2 array
    u2 = -7
    call check(mfree_suitesparse_solve(s, 1_c_int32_t, f, int(ndofs, c_int64_t), u2(1:ndofs - 1, 1), &
                                       int(ndofs, c_int64_t)) == MFREE_ERR_ARG, 'x one short')
    call check(index(mfree_last_error(ctx), 'are needed') > 0, 'x one short: message')
    call check(mfree_suitesparse_solve(s, 2_c_int32_t, f, int(ndofs, c_int64_t), u2, &
                                       int(ndofs, c_int64_t)) == MFREE_ERR_ARG, 'b one column short')
    call check(mfree_suitesparse_solve(s, 1_c_int32_t, f, int(ndofs, c_int64_t), u2(1, :), &
                                       1_c_int64_t) == MFREE_ERR_ARG, 'x not contiguous')
    call check(index(mfree_last_error(ctx), 'not contiguous') > 0, 'x not contiguous: message')
    call check(all(u2 == -7), 'nothing written')
    f2(:, 1) = f
    f2(:, 2) = 2 * f
    call check_ok(ctx, mfree_suitesparse_solve(s, 2_c_int32_t, f2, int(ndofs, c_int64_t), u2, &
                                               int(ndofs, c_int64_t)), 'two right-hand sides')
    call check(maxval(abs(u2(:, 1) - u)) <= 1e-12_c_double * maxval(abs(u)) .and. &
               maxval(abs(u2(:, 2) - 2 * u)) <= 1e-12_c_double * maxval(abs(u)), &
               'two right-hand sides: both solutions')
    call check_ok(ctx, mfree_suitesparse_get_info(s, rcond=rcond, index_width=width), 'info')
    call check(rcond > 0 .and. width == 32, 'rcond > 0, 32-bit indices')
    call residual_check(K, u, f)

    call check(mfree_suitesparse_destroy(s) == MFREE_SUCCESS, 'destroy solver')
    call check(mfree_matrix_destroy(K) == MFREE_SUCCESS, 'destroy K')
    call check(mfree_assembler_destroy(as) == MFREE_SUCCESS, 'destroy assembler')
    call check(mfree_approximant_destroy(a) == MFREE_SUCCESS, 'destroy approximant')
  end subroutine collocation

  !> K u against the zero-copy CSR view read from Fortran (0-based offsets, columns).
  subroutine residual_check(kmat, u, f)
    type(mfree_matrix), intent(in) :: kmat
    real(c_double), intent(in) :: u(:), f(:)
    integer(c_int64_t), pointer :: rowptr(:)
    integer(c_int32_t), pointer :: cols(:)
    real(c_double), pointer :: vals(:)
    real(c_double) :: ku(size(u)), mine(size(u))
    integer(c_int64_t) :: k
    integer :: r
    call check_ok(ctx, mfree_matrix_get_csr(kmat, rowptr, cols, vals), 'CSR view')
    call check(size(rowptr) == size(u) + 1, 'view: rows + 1 offsets')
    do r = 1, size(u)
      mine(r) = 0
      do k = rowptr(r) + 1, rowptr(r + 1)
        mine(r) = mine(r) + vals(k) * u(cols(k) + 1)
      end do
    end do
    call check_ok(ctx, mfree_matrix_apply(kmat, u, ku), 'matrix apply')
    call check(maxval(abs(mine - ku)) <= 1e-12_c_double * maxval(abs(ku)) + 1e-300_c_double, &
               'Fortran product over the view equals mfree_matrix_apply')
    call check(maxval(abs(ku - f)) <= 1e-8_c_double * maxval(abs(f)), 'K u = f')
  end subroutine residual_check

  subroutine galerkin(ngauss, err)
    integer, intent(in) :: ngauss
    real(c_double), intent(out) :: err
    integer, parameter :: nseg = 4 * (m - 1), nbq = 4 * nseg * 2
    real(c_double), parameter :: g2(2) = [-0.5773502691896257_c_double, &
                                          0.5773502691896257_c_double]
    real(c_double) :: bx(2, nbq), bn(2, nbq), bw(nbq), tt, exact(1), lo(2), hi(2)
    real(c_double) :: px(4), py(4), nx(4), ny(4)
    integer(c_int32_t) :: ncells(2), sym
    type(mfree_approximant) :: a
    type(mfree_assembler) :: as
    type(mfree_matrix) :: K
    type(mfree_solver) :: s
    real(c_double), allocatable :: f(:), u(:), uh(:)
    integer(c_int32_t) :: ndofs
    integer :: e, c, q, nq

    ! boundary Gauss points (2 per segment, 4 segments per node interval), outward normals
    nq = 0
    do e = 1, 4
      do c = 0, nseg - 1
        do q = 1, 2
          tt = (c + 0.5_c_double + 0.5_c_double * g2(q)) / nseg
          px = [tt, 1.0_c_double, tt, 0.0_c_double]
          py = [0.0_c_double, tt, 1.0_c_double, tt]
          nx = [0.0_c_double, 1.0_c_double, 0.0_c_double, -1.0_c_double]
          ny = [-1.0_c_double, 0.0_c_double, 1.0_c_double, 0.0_c_double]
          nq = nq + 1
          bx(:, nq) = [px(e), py(e)]
          bn(:, nq) = [nx(e), ny(e)]
          bw(nq) = 0.5_c_double / nseg
        end do
      end do
    end do

    call check_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, a), 'MLS')
    call check_ok(ctx, mfree_assembler_create(ctx, a, mfree_approximant(), MFREE_FORM_LAPLACE, &
                                              as), 'assembler')
    lo = 0
    hi = 1
    ncells = m - 1
    call check_ok(ctx, mfree_assembler_set_quadrature_cells(as, lo, hi, ncells, &
                                                            int(ngauss, c_int32_t)), 'cells')
    call check_ok(ctx, mfree_assembler_add_dirichlet(as, MFREE_BC_NITSCHE, int(nq, c_int32_t), &
                  bx, MFREE_LAYOUT_AOS, 2_c_int64_t, bw, bn, 1_c_int32_t, lin_u), 'Nitsche')
    call check_ok(ctx, mfree_assembler_setup(as), 'setup')
    call check_ok(ctx, mfree_assembler_get_size(as, ndofs=ndofs), 'size')
    call check_ok(ctx, mfree_assembler_assemble_matrix(as, K), 'assemble K')
    call check_ok(ctx, mfree_matrix_get_symmetric(K, sym), 'symmetric?')
    call check(sym == 1, 'Bubnov-Galerkin with symmetric Nitsche: symmetric matrix')
    allocate (f(ndofs), u(ndofs), uh(n))
    call check_ok(ctx, mfree_assembler_assemble_rhs(as, f), 'assemble f')
    call check_ok(ctx, mfree_suitesparse_create(ctx, MFREE_SOLVER_CHOLMOD, s), 'CHOLMOD')
    call check_ok(ctx, mfree_suitesparse_setup(s, K), 'Cholesky factorisation')
    call check_ok(ctx, mfree_suitesparse_solve(s, 1_c_int32_t, f, int(ndofs, c_int64_t), u, &
                                               int(ndofs, c_int64_t)), 'solve')
    ! MLS is not interpolating: the field at the particles is u^h = Phi u
    call check_ok(ctx, mfree_approximant_setup(a), 'approximant setup')
    call check_ok(ctx, mfree_approximant_apply(a, MFREE_OP_VALUE, 1_c_int32_t, u, &
                  MFREE_LAYOUT_AOS, 1_c_int64_t, uh, MFREE_LAYOUT_AOS, 1_c_int64_t), 'u^h')
    err = 0
    do q = 1, n
      call lin_u(c_null_ptr, x(:, q), exact)
      err = max(err, abs(uh(q) - exact(1)))
    end do
    call check(mfree_suitesparse_destroy(s) == MFREE_SUCCESS, 'destroy solver')
    call check(mfree_matrix_destroy(K) == MFREE_SUCCESS, 'destroy K')
    call check(mfree_assembler_destroy(as) == MFREE_SUCCESS, 'destroy assembler')
    call check(mfree_approximant_destroy(a) == MFREE_SUCCESS, 'destroy approximant')
  end subroutine galerkin

end program t801_suitesparse_solve_f
