!> Installed-tree Fortran consumer of module mfree_suitesparse (t954): the 1D Laplacian
!> tridiag(-1, 2, -1) of order 10 from 0-based CSR host arrays, solved with each solver
!> for x = 1..10 (b = A x); one line per solver ending in ": ok".
program app_suitesparse
  use, intrinsic :: iso_c_binding
  use mfree
  use mfree_suitesparse
  implicit none
  integer, parameter :: n = 10
  integer(c_int64_t) :: rowptr(n + 1)
  integer(c_int32_t) :: cols(3 * n)
  real(c_double) :: vals(3 * n), xtrue(n), b(n), x(n)
  type(mfree_context) :: ctx
  type(mfree_matrix) :: a
  type(mfree_solver) :: s
  integer(c_int) :: st, kinds(3)
  integer :: i, k, nnz
  logical :: ok, all_ok

  nnz = 0
  rowptr(1) = 0
  do i = 1, n
    do k = max(i - 1, 1), min(i + 1, n)
      nnz = nnz + 1
      cols(nnz) = int(k - 1, c_int32_t)
      vals(nnz) = merge(2.0_c_double, -1.0_c_double, k == i)
    end do
    rowptr(i + 1) = nnz
    xtrue(i) = i
  end do
  kinds = [MFREE_SOLVER_CHOLMOD, MFREE_SOLVER_UMFPACK, MFREE_SOLVER_KLU]
  all_ok = .true.
  st = mfree_context_create(ctx)
  if (st == MFREE_SUCCESS) st = mfree_matrix_create_csr(ctx, int(n, c_int32_t), &
                                int(n, c_int32_t), rowptr, cols, vals, a)
  if (st == MFREE_SUCCESS) st = mfree_matrix_apply(a, xtrue, b)
  do k = 1, 3
    x = 0
    if (st == MFREE_SUCCESS) st = mfree_suitesparse_create(ctx, kinds(k), s)
    if (st == MFREE_SUCCESS) st = mfree_suitesparse_setup(s, a)
    if (st == MFREE_SUCCESS) st = mfree_suitesparse_solve(s, 1_c_int32_t, b, &
                                  int(n, c_int64_t), x, int(n, c_int64_t))
    ok = st == MFREE_SUCCESS .and. maxval(abs(x - xtrue)) < 1e-12_c_double
    all_ok = all_ok .and. ok
    write (*, '(a,i0,a,a)') 'mfree_suitesparse Fortran consumer, solver ', kinds(k), ': ', &
      merge('ok    ', 'FAILED', ok)
    if (mfree_suitesparse_destroy(s) /= MFREE_SUCCESS) all_ok = .false.
  end do
  if (st /= MFREE_SUCCESS) write (*, '(a,a)') 'mfree: ', mfree_last_error(ctx)
  st = mfree_matrix_destroy(a)
  st = mfree_context_destroy(ctx)
  if (.not. all_ok) stop 1
end program app_suitesparse
