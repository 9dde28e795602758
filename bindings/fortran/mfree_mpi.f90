!> module mfree_mpi: Fortran 2008 bindings of the MPI adapter
!> (adapters/mpi/include/mfree_mpi.h, library libmfree_mpi). Built into
!> libmfree_fortran_mpi only when the adapter is built; the core module mfree never
!> depends on MPI.
!>
!> Same two layers as module mfree: raw bind(C) interfaces, the C name with _c, and typed
!> wrappers with the C names. Communicators are the integer handles of `use mpi`
!> (mfree_halo_create takes one and calls mfree_halo_create_f: the C function with an
!> MPI_Comm has no portable Fortran interface). Arrays are AoS: x(ld, n), field(ld, n).
!> Fortran hosts give global ids (the C API's numbering by the plan, ids = NULL, is C only).
!>
!> The typed wrappers check every caller array as module mfree's do (its own checks,
!> mfree_wrapper_check_out and mfree_wrapper_view_dbl): an array too short for what the C
!> function reads or writes, or an output that is not contiguous, is MFREE_ERR_ARG with
!> nothing read or written. In the collective calls (setup, exchange) a rank whose check
!> fails still takes part: mfree_halo_set_pending_error hands its failure to the C call,
!> which returns it on every rank, so no rank is left waiting.
module mfree_mpi
  use, intrinsic :: iso_c_binding, only: c_int, c_int32_t, c_int64_t, c_double, c_ptr, &
    c_null_ptr, c_loc, c_f_pointer
  use mfree, only: mfree_context, mfree_approximant, MFREE_SUCCESS, mfree_wrapper_check_out, &
    mfree_wrapper_view_dbl, mfree_assembler, mfree_system
  implicit none
  private

  !> A halo plan (C: mfree_halo_t *).
  type, public :: mfree_halo
    type(c_ptr) :: ptr = c_null_ptr
  end type mfree_halo

  !> A migration plan (C: mfree_migration_t *).
  type, public :: mfree_migration
    type(c_ptr) :: ptr = c_null_ptr
  end type mfree_migration

  !> Partitioners of mfree_migration_set_partitioner (mfree_partitioner_t).
  integer(c_int), parameter, public :: MFREE_PARTITIONER_RCB = 1
  integer(c_int), parameter, public :: MFREE_PARTITIONER_HSFC = 2

  ! ---- raw bind(C) interfaces: one per public function of mfree_mpi.h (but the C-only
  ! mfree_halo_create and mfree_halo_get_communicator, whose MPI_Comm has no portable
  ! Fortran interface) ----
  interface
    integer(c_int) function mfree_halo_create_f_c(ctx, fcomm, dim, halo) &
        bind(C, name="mfree_halo_create_f")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: ctx
      integer(c_int32_t), value :: fcomm
      integer(c_int32_t), value :: dim
      type(c_ptr), intent(out) :: halo
    end function mfree_halo_create_f_c

    integer(c_int) function mfree_halo_destroy_c(halo) bind(C, name="mfree_halo_destroy")
      import :: c_int, c_ptr
      type(c_ptr), intent(inout) :: halo
    end function mfree_halo_destroy_c

    integer(c_int) function mfree_halo_setup_c(halo, n_owned, x, ld, ids, width) &
        bind(C, name="mfree_halo_setup")
      import :: c_int, c_int32_t, c_int64_t, c_double, c_ptr
      type(c_ptr), value :: halo
      integer(c_int32_t), value :: n_owned
      real(c_double), intent(in) :: x(*)
      integer(c_int64_t), value :: ld
      integer(c_int64_t), intent(in) :: ids(*)
      real(c_double), value :: width
    end function mfree_halo_setup_c

    integer(c_int) function mfree_halo_get_size_c(halo, n_owned, n_ghost) &
        bind(C, name="mfree_halo_get_size")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: halo
      integer(c_int32_t), intent(out) :: n_owned
      integer(c_int32_t), intent(out) :: n_ghost
    end function mfree_halo_get_size_c

    integer(c_int) function mfree_halo_get_global_ids_c(halo, ids) &
        bind(C, name="mfree_halo_get_global_ids")
      import :: c_int, c_int64_t, c_ptr
      type(c_ptr), value :: halo
      integer(c_int64_t), intent(out) :: ids(*)
    end function mfree_halo_get_global_ids_c

    integer(c_int) function mfree_halo_get_global_offset_c(halo, offset, total) &
        bind(C, name="mfree_halo_get_global_offset")
      import :: c_int, c_int64_t, c_ptr
      type(c_ptr), value :: halo
      integer(c_int64_t), intent(out) :: offset
      integer(c_int64_t), intent(out) :: total
    end function mfree_halo_get_global_offset_c

    integer(c_int) function mfree_halo_get_plan_c(halo, n_neighbors, n_send, n_recv) &
        bind(C, name="mfree_halo_get_plan")
      import :: c_int, c_int32_t, c_int64_t, c_ptr
      type(c_ptr), value :: halo
      integer(c_int32_t), intent(out) :: n_neighbors
      integer(c_int64_t), intent(out) :: n_send
      integer(c_int64_t), intent(out) :: n_recv
    end function mfree_halo_get_plan_c

    integer(c_int) function mfree_halo_exchange_correction_c(halo, a) &
        bind(C, name="mfree_halo_exchange_correction")
      import :: c_int, c_ptr
      type(c_ptr), value :: halo
      type(c_ptr), value :: a
    end function mfree_halo_exchange_correction_c

    integer(c_int) function mfree_halo_get_context_c(halo, ctx) &
        bind(C, name="mfree_halo_get_context")
      import :: c_int, c_ptr
      type(c_ptr), value :: halo
      type(c_ptr), intent(out) :: ctx
    end function mfree_halo_get_context_c

    integer(c_int) function mfree_halo_set_pending_error_c(halo) &
        bind(C, name="mfree_halo_set_pending_error")
      import :: c_int, c_ptr
      type(c_ptr), value :: halo
    end function mfree_halo_set_pending_error_c

    integer(c_int) function mfree_halo_exchange_c(halo, ncomp, field, ld) &
        bind(C, name="mfree_halo_exchange")
      import :: c_int, c_int32_t, c_int64_t, c_double, c_ptr
      type(c_ptr), value :: halo
      integer(c_int32_t), value :: ncomp
      real(c_double), intent(inout) :: field(*)
      integer(c_int64_t), value :: ld
    end function mfree_halo_exchange_c

    integer(c_int) function mfree_migration_create_f_c(ctx, fcomm, dim, migration) &
        bind(C, name="mfree_migration_create_f")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: ctx
      integer(c_int32_t), value :: fcomm
      integer(c_int32_t), value :: dim
      type(c_ptr), intent(out) :: migration
    end function mfree_migration_create_f_c

    integer(c_int) function mfree_migration_destroy_c(migration) bind(C, name="mfree_migration_destroy")
      import :: c_int, c_ptr
      type(c_ptr), intent(inout) :: migration
    end function mfree_migration_destroy_c

    integer(c_int) function mfree_migration_set_partitioner_c(migration, method, imbalance_tol) &
        bind(C, name="mfree_migration_set_partitioner")
      import :: c_int, c_int32_t, c_double, c_ptr
      type(c_ptr), value :: migration
      integer(c_int32_t), value :: method
      real(c_double), value :: imbalance_tol
    end function mfree_migration_set_partitioner_c

    integer(c_int) function mfree_migration_add_field_c(migration, data, item_bytes, stride_bytes) &
        bind(C, name="mfree_migration_add_field")
      import :: c_int, c_int64_t, c_ptr
      type(c_ptr), value :: migration
      type(c_ptr), value :: data
      integer(c_int64_t), value :: item_bytes
      integer(c_int64_t), value :: stride_bytes
    end function mfree_migration_add_field_c

    integer(c_int) function mfree_migration_clear_fields_c(migration) &
        bind(C, name="mfree_migration_clear_fields")
      import :: c_int, c_ptr
      type(c_ptr), value :: migration
    end function mfree_migration_clear_fields_c

    integer(c_int) function mfree_migration_partition_c(migration, n_owned, x, ld, rebalance, n_new) &
        bind(C, name="mfree_migration_partition")
      import :: c_int, c_int32_t, c_int64_t, c_double, c_ptr
      type(c_ptr), value :: migration
      integer(c_int32_t), value :: n_owned
      real(c_double), intent(in) :: x(*)
      integer(c_int64_t), value :: ld
      integer(c_int32_t), value :: rebalance
      integer(c_int32_t), intent(out) :: n_new
    end function mfree_migration_partition_c

    integer(c_int) function mfree_migration_set_owners_c(migration, n_owned, owners, n_new) &
        bind(C, name="mfree_migration_set_owners")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: migration
      integer(c_int32_t), value :: n_owned
      integer(c_int32_t), intent(in) :: owners(*)
      integer(c_int32_t), intent(out) :: n_new
    end function mfree_migration_set_owners_c

    integer(c_int) function mfree_migration_execute_c(migration, capacity) &
        bind(C, name="mfree_migration_execute")
      import :: c_int, c_int32_t, c_ptr
      type(c_ptr), value :: migration
      integer(c_int32_t), value :: capacity
    end function mfree_migration_execute_c

    integer(c_int) function mfree_migration_get_counts_c(migration, n_owned, n_new, n_send, n_recv) &
        bind(C, name="mfree_migration_get_counts")
      import :: c_int, c_int32_t, c_int64_t, c_ptr
      type(c_ptr), value :: migration
      integer(c_int32_t), intent(out) :: n_owned
      integer(c_int32_t), intent(out) :: n_new
      integer(c_int64_t), intent(out) :: n_send
      integer(c_int64_t), intent(out) :: n_recv
    end function mfree_migration_get_counts_c

    integer(c_int) function mfree_migration_get_owners_c(migration, owners, capacity) &
        bind(C, name="mfree_migration_get_owners")
      import :: c_int, c_int32_t, c_int64_t, c_ptr
      type(c_ptr), value :: migration
      integer(c_int32_t), intent(out) :: owners(*)
      integer(c_int64_t), value :: capacity
    end function mfree_migration_get_owners_c

    integer(c_int) function mfree_migration_get_context_c(migration, ctx) &
        bind(C, name="mfree_migration_get_context")
      import :: c_int, c_ptr
      type(c_ptr), value :: migration
      type(c_ptr), intent(out) :: ctx
    end function mfree_migration_get_context_c

    integer(c_int) function mfree_migration_set_pending_error_c(migration) &
        bind(C, name="mfree_migration_set_pending_error")
      import :: c_int, c_ptr
      type(c_ptr), value :: migration
    end function mfree_migration_set_pending_error_c

    integer(c_int) function mfree_halo_exchange_callback_c(halo, ncomp, field, ld) &
        bind(C, name="mfree_halo_exchange_callback")
      import :: c_int, c_int32_t, c_int64_t, c_double, c_ptr
      type(c_ptr), value :: halo
      integer(c_int32_t), value :: ncomp
      real(c_double), intent(inout) :: field(*)
      integer(c_int64_t), value :: ld
    end function mfree_halo_exchange_callback_c

    integer(c_int) function mfree_halo_allgather_c(halo, in, n, out, cap, total) &
        bind(C, name="mfree_halo_allgather")
      import :: c_int, c_int64_t, c_double, c_ptr
      type(c_ptr), value :: halo
      real(c_double), intent(in) :: in(*)
      integer(c_int64_t), value :: n
      real(c_double), intent(out) :: out(*)
      integer(c_int64_t), value :: cap
      integer(c_int64_t), intent(out) :: total
    end function mfree_halo_allgather_c

    integer(c_int) function mfree_halo_create_elastodynamic_c(halo, as, density, sys) &
        bind(C, name="mfree_halo_create_elastodynamic")
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: halo
      type(c_ptr), value :: as
      real(c_double), value :: density
      type(c_ptr), intent(out) :: sys
    end function mfree_halo_create_elastodynamic_c

    integer(c_int) function mfree_halo_create_fluid_c(halo, dim, width, sys) &
        bind(C, name="mfree_halo_create_fluid")
      import :: c_int, c_int32_t, c_double, c_ptr
      type(c_ptr), value :: halo
      integer(c_int32_t), value :: dim
      real(c_double), value :: width
      type(c_ptr), intent(out) :: sys
    end function mfree_halo_create_fluid_c

    integer(c_int) function mfree_halo_rebuild_callback_c(halo, n_owned, x, ld, global_ids, width, n_ghost, &
        all_ids) bind(C, name="mfree_halo_rebuild_callback")
      import :: c_int, c_int32_t, c_int64_t, c_double, c_ptr
      type(c_ptr), value :: halo
      integer(c_int32_t), value :: n_owned
      real(c_double), intent(in) :: x(*)
      integer(c_int64_t), value :: ld
      integer(c_int64_t), intent(in) :: global_ids(*)
      real(c_double), value :: width
      integer(c_int32_t), intent(out) :: n_ghost
      type(c_ptr), intent(out) :: all_ids
    end function mfree_halo_rebuild_callback_c

    integer(c_int) function mfree_halo_migrate_fluid_c(halo, migration, sys, rebalance, y, capacity, neq) &
        bind(C, name="mfree_halo_migrate_fluid")
      import :: c_int, c_int32_t, c_int64_t, c_double, c_ptr
      type(c_ptr), value :: halo
      type(c_ptr), value :: migration
      type(c_ptr), value :: sys
      integer(c_int32_t), value :: rebalance
      real(c_double), intent(inout) :: y(*)
      integer(c_int64_t), value :: capacity
      integer(c_int64_t), intent(out) :: neq
    end function mfree_halo_migrate_fluid_c
  end interface

  public :: mfree_halo_create_f_c, mfree_halo_destroy_c, mfree_halo_setup_c
  public :: mfree_halo_get_size_c, mfree_halo_get_global_ids_c
  public :: mfree_halo_get_global_offset_c, mfree_halo_get_plan_c, mfree_halo_exchange_c
  public :: mfree_halo_get_context_c, mfree_halo_set_pending_error_c
  public :: mfree_halo_exchange_correction_c
  public :: mfree_halo_create, mfree_halo_create_f, mfree_halo_destroy, mfree_halo_setup
  public :: mfree_halo_get_size, mfree_halo_get_global_ids, mfree_halo_get_global_offset
  public :: mfree_halo_get_plan, mfree_halo_exchange, mfree_halo_get_context
  public :: mfree_halo_set_pending_error, mfree_halo_exchange_correction
  public :: mfree_migration_create_f_c, mfree_migration_destroy_c, mfree_migration_set_partitioner_c
  public :: mfree_migration_add_field_c, mfree_migration_clear_fields_c, mfree_migration_partition_c
  public :: mfree_migration_set_owners_c, mfree_migration_execute_c, mfree_migration_get_counts_c
  public :: mfree_migration_get_owners_c, mfree_migration_get_context_c
  public :: mfree_migration_set_pending_error_c
  public :: mfree_migration_create, mfree_migration_create_f, mfree_migration_destroy
  public :: mfree_migration_set_partitioner, mfree_migration_add_field, mfree_migration_clear_fields
  public :: mfree_migration_partition, mfree_migration_set_owners, mfree_migration_execute
  public :: mfree_migration_get_counts, mfree_migration_get_owners, mfree_migration_get_context
  public :: mfree_migration_set_pending_error
  public :: mfree_halo_exchange_callback_c, mfree_halo_allgather_c, mfree_halo_create_elastodynamic_c
  public :: mfree_halo_create_elastodynamic
  public :: mfree_halo_create_fluid_c, mfree_halo_create_fluid
  public :: mfree_halo_exchange_callback, mfree_halo_allgather
  public :: mfree_halo_rebuild_callback_c, mfree_halo_rebuild_callback
  public :: mfree_halo_migrate_fluid_c, mfree_halo_migrate_fluid

  real(c_double), target, save :: empty_dbl(0)
  integer(c_int32_t), target, save :: empty_i32(0)
  integer(c_int64_t), target, save :: empty_i64(0)

contains

  !> A plan on the communicator comm (an integer handle of `use mpi`). Collective.
  integer(c_int) function mfree_halo_create(ctx, comm, dim, halo) result(st)
    type(mfree_context), intent(in) :: ctx
    integer, intent(in) :: comm
    integer(c_int32_t), intent(in) :: dim
    type(mfree_halo), intent(out) :: halo
    st = mfree_halo_create_f_c(ctx%ptr, int(comm, c_int32_t), dim, halo%ptr)
  end function mfree_halo_create

  !> The elastodynamic system of a collocation or Galerkin stiffness assembler over the
  !> plan's particles, on ranks (mfree_system_create_elastodynamic_ranks through the plan).
  !> Collective; the plan must outlive the system.
  integer(c_int) function mfree_halo_create_elastodynamic(halo, as, density, sys) result(st)
    type(mfree_halo), intent(in) :: halo
    type(mfree_assembler), intent(in) :: as
    real(c_double), intent(in) :: density
    type(mfree_system), intent(out) :: sys
    st = mfree_halo_create_elastodynamic_c(halo%ptr, as%ptr, density, sys%ptr)
  end function mfree_halo_create_elastodynamic

  !> The fluid over the plan's particles, on ranks (mfree_system_create_fluid_ranks through
  !> the plan). Collective; the plan must outlive the system.
  integer(c_int) function mfree_halo_create_fluid(halo, dim, width, sys) result(st)
    type(mfree_halo), intent(in) :: halo
    integer(c_int32_t), intent(in) :: dim
    real(c_double), intent(in) :: width
    type(mfree_system), intent(out) :: sys
    st = mfree_halo_create_fluid_c(halo%ptr, dim, width, sys%ptr)
  end function mfree_halo_create_fluid

  !> Typed wrapper of mfree_halo_rebuild_callback (mfree_mpi.h): the plan set up again
  !> around n_owned particles (x: ld values each, global_ids: n_owned, checked: a short
  !> array is handed to the plan as a failure every rank returns). all_ids points to the
  !> plan's ids (c_f_pointer with n_owned + n_ghost). Collective.
  integer(c_int) function mfree_halo_rebuild_callback(halo, n_owned, x, ld, global_ids, width, n_ghost, &
                                                       all_ids) result(st)
    type(mfree_halo), intent(in) :: halo
    integer(c_int32_t), intent(in) :: n_owned
    real(c_double), intent(in), contiguous :: x(:)
    integer(c_int64_t), intent(in) :: ld
    integer(c_int64_t), intent(in), contiguous :: global_ids(:)
    real(c_double), intent(in) :: width
    integer(c_int32_t), intent(out) :: n_ghost
    type(c_ptr), intent(out) :: all_ids
    integer(c_int64_t) :: no
    no = max(int(n_owned, c_int64_t), 0_c_int64_t)
    n_ghost = 0
    all_ids = c_null_ptr
    st = mfree_wrapper_check_out(halo_ctx(halo), 'mfree_halo_rebuild_callback', 'x', .true., &
                                 size(x, kind=c_int64_t), ld * no)
    if (st == MFREE_SUCCESS) &
      st = mfree_wrapper_check_out(halo_ctx(halo), 'mfree_halo_rebuild_callback', 'global_ids', .true., &
                                   size(global_ids, kind=c_int64_t), no)
    if (st /= MFREE_SUCCESS) then
      if (mfree_halo_set_pending_error_c(halo%ptr) /= MFREE_SUCCESS) return
      st = mfree_halo_rebuild_callback_c(halo%ptr, 0_c_int32_t, empty_dbl, ld, empty_i64, width, n_ghost, all_ids)
      return
    end if
    st = mfree_halo_rebuild_callback_c(halo%ptr, n_owned, x, ld, global_ids, width, n_ghost, all_ids)
  end function mfree_halo_rebuild_callback

  !> Typed wrapper of mfree_halo_migrate_fluid (mfree_mpi.h): y holds at least capacity
  !> values (checked: a shorter y is passed as a capacity of -1, which every rank refuses
  !> alike with MFREE_ERR_ARG, nothing moved). Collective.
  integer(c_int) function mfree_halo_migrate_fluid(halo, migration, sys, rebalance, y, capacity, neq) result(st)
    type(mfree_halo), intent(in) :: halo
    type(mfree_migration), intent(in) :: migration
    type(mfree_system), intent(in) :: sys
    integer(c_int32_t), intent(in) :: rebalance
    real(c_double), intent(inout), contiguous :: y(:)
    integer(c_int64_t), intent(in) :: capacity
    integer(c_int64_t), intent(out) :: neq
    integer(c_int64_t) :: cap
    cap = capacity
    if (size(y, kind=c_int64_t) < capacity) cap = -1_c_int64_t
    neq = 0
    st = mfree_halo_migrate_fluid_c(halo%ptr, migration%ptr, sys%ptr, rebalance, y, cap, neq)
  end function mfree_halo_migrate_fluid

  !> The same with the communicator already as integer(c_int32_t).
  integer(c_int) function mfree_halo_create_f(ctx, fcomm, dim, halo) result(st)
    type(mfree_context), intent(in) :: ctx
    integer(c_int32_t), intent(in) :: fcomm, dim
    type(mfree_halo), intent(out) :: halo
    st = mfree_halo_create_f_c(ctx%ptr, fcomm, dim, halo%ptr)
  end function mfree_halo_create_f

  !> Free the plan. Collective: every rank of the plan's communicator calls it (plans in
  !> the same order on every rank), before mpi_finalize or, memory only, after it.
  integer(c_int) function mfree_halo_destroy(halo) result(st)
    type(mfree_halo), intent(inout) :: halo
    st = mfree_halo_destroy_c(halo%ptr)
  end function mfree_halo_destroy

  !> Ghost layer and plan of n_owned particles x(ld, n_owned) with global ids(n_owned).
  !> Collective. x (any rank, read) holds at least ld * n_owned values and ids n_owned,
  !> else MFREE_ERR_ARG on every rank, naming this one.
  integer(c_int) function mfree_halo_setup(halo, n_owned, x, ld, ids, width) result(st)
    type(mfree_halo), intent(in) :: halo
    integer(c_int32_t), intent(in) :: n_owned
    real(c_double), intent(in), target :: x(..)
    integer(c_int64_t), intent(in) :: ld
    integer(c_int64_t), intent(in), contiguous :: ids(:)
    real(c_double), intent(in) :: width
    character(len=*), parameter :: fn = 'mfree_halo_setup'
    real(c_double), pointer :: px(:)
    real(c_double), allocatable, target :: tx(:)
    integer(c_int64_t) :: n
    n = max(int(n_owned, c_int64_t), 0_c_int64_t)
    st = mfree_wrapper_check_out(halo_ctx(halo), fn, 'x', .true., size(x, kind=c_int64_t), ld * n)
    if (st == MFREE_SUCCESS) &
      st = mfree_wrapper_check_out(halo_ctx(halo), fn, 'ids', .true., size(ids, kind=c_int64_t), n)
    if (st /= MFREE_SUCCESS) then
      if (mfree_halo_set_pending_error_c(halo%ptr) /= MFREE_SUCCESS) return
      st = mfree_halo_setup_c(halo%ptr, n_owned, empty_dbl, ld, ids, width)
      return
    end if
    call mfree_wrapper_view_dbl(x, tx, px)
    st = mfree_halo_setup_c(halo%ptr, n_owned, px, ld, ids, width)
  end function mfree_halo_setup

  integer(c_int) function mfree_halo_get_size(halo, n_owned, n_ghost) result(st)
    type(mfree_halo), intent(in) :: halo
    integer(c_int32_t), intent(out) :: n_owned, n_ghost
    st = mfree_halo_get_size_c(halo%ptr, n_owned, n_ghost)
  end function mfree_halo_get_size

  !> ids(n_owned + n_ghost): owned first, then the ghosts; contiguous and at least that
  !> long, else MFREE_ERR_ARG with nothing written.
  integer(c_int) function mfree_halo_get_global_ids(halo, ids) result(st)
    type(mfree_halo), intent(in) :: halo
    integer(c_int64_t), intent(out) :: ids(:)
    integer(c_int32_t) :: no, ng
    st = mfree_halo_get_size_c(halo%ptr, no, ng)
    if (st == MFREE_SUCCESS) &
      st = mfree_wrapper_check_out(halo_ctx(halo), 'mfree_halo_get_global_ids', 'ids', is_contiguous(ids), &
                                   size(ids, kind=c_int64_t), int(no, c_int64_t) + ng)
    if (st /= MFREE_SUCCESS) return
    st = mfree_halo_get_global_ids_c(halo%ptr, ids)
  end function mfree_halo_get_global_ids

  integer(c_int) function mfree_halo_get_global_offset(halo, offset, total) result(st)
    type(mfree_halo), intent(in) :: halo
    integer(c_int64_t), intent(out) :: offset, total
    st = mfree_halo_get_global_offset_c(halo%ptr, offset, total)
  end function mfree_halo_get_global_offset

  integer(c_int) function mfree_halo_get_plan(halo, n_neighbors, n_send, n_recv) result(st)
    type(mfree_halo), intent(in) :: halo
    integer(c_int32_t), intent(out) :: n_neighbors
    integer(c_int64_t), intent(out) :: n_send, n_recv
    st = mfree_halo_get_plan_c(halo%ptr, n_neighbors, n_send, n_recv)
  end function mfree_halo_get_plan

  !> field(ld, n_owned + n_ghost) (any rank: h(n) for a scalar): components 1..ncomp of
  !> the ghost columns from their owners. Collective. field must be contiguous and hold
  !> (n_owned + n_ghost - 1) * ld + ncomp values, else MFREE_ERR_ARG on every rank, naming
  !> this one, with nothing written.
  integer(c_int) function mfree_halo_exchange(halo, ncomp, field, ld) result(st)
    type(mfree_halo), intent(in) :: halo
    integer(c_int32_t), intent(in) :: ncomp
    real(c_double), intent(inout), target :: field(..)
    integer(c_int64_t), intent(in) :: ld
    real(c_double), pointer :: pf(:)
    st = exchange_field(halo, 'mfree_halo_exchange', ncomp, field, ld, pf)
    if (st == MFREE_SUCCESS) st = mfree_halo_exchange_c(halo%ptr, ncomp, pf, ld)
  end function mfree_halo_exchange

  !> Typed wrapper of mfree_halo_exchange_callback (mfree_mpi.h): the exchange a system on
  !> ranks calls, with mfree_halo_exchange's checks of field. Collective.
  integer(c_int) function mfree_halo_exchange_callback(halo, ncomp, field, ld) result(st)
    type(mfree_halo), intent(in) :: halo
    integer(c_int32_t), intent(in) :: ncomp
    real(c_double), intent(inout), target :: field(..)
    integer(c_int64_t), intent(in) :: ld
    real(c_double), pointer :: pf(:)
    st = exchange_field(halo, 'mfree_halo_exchange_callback', ncomp, field, ld, pf)
    if (st == MFREE_SUCCESS) st = mfree_halo_exchange_callback_c(halo%ptr, ncomp, pf, ld)
  end function mfree_halo_exchange_callback

  !> The check of field that both exchanges make (fn names the caller in the message): pf
  !> views field; or, when field is too short or not contiguous, pf is empty and the failure
  !> is handed to the plan, so that the exchange fails on every rank. A status other than
  !> MFREE_SUCCESS where even that failed: the caller returns it. A plan that is not set up,
  !> or a bad ncomp or ld, is left to the C call, which says so on every rank.
  integer(c_int) function exchange_field(halo, fn, ncomp, field, ld, pf) result(st)
    type(mfree_halo), intent(in) :: halo
    character(len=*), intent(in) :: fn
    integer(c_int32_t), intent(in) :: ncomp
    real(c_double), intent(inout), target :: field(..)
    integer(c_int64_t), intent(in) :: ld
    real(c_double), pointer, intent(out) :: pf(:)
    integer(c_int32_t) :: no, ng
    integer(c_int64_t) :: need
    st = MFREE_SUCCESS
    if (mfree_halo_get_size_c(halo%ptr, no, ng) == MFREE_SUCCESS .and. ncomp >= 1 .and. ld >= ncomp) then
      need = 0
      if (no + ng > 0) need = (int(no, c_int64_t) + ng - 1) * ld + ncomp
      st = mfree_wrapper_check_out(halo_ctx(halo), fn, 'field', is_contiguous(field), &
                                   size(field, kind=c_int64_t), need)
    end if
    pf => empty_dbl
    if (st /= MFREE_SUCCESS) then
      if (mfree_halo_set_pending_error_c(halo%ptr) == MFREE_SUCCESS) st = MFREE_SUCCESS
    else if (size(field) > 0) then
      call c_f_pointer(c_loc(field), pf, [size(field)])
    end if
  end function exchange_field

  !> Typed wrapper of mfree_halo_allgather (mfree_mpi.h): every rank's n values of in
  !> concatenated in rank order into out (cap values; cap = 0 asks for the total only).
  !> in must hold n values and out cap values (else MFREE_ERR_ARG on every rank).
  !> Collective.
  integer(c_int) function mfree_halo_allgather(halo, in, n, out, cap, total) result(st)
    type(mfree_halo), intent(in) :: halo
    real(c_double), intent(in) :: in(:)
    integer(c_int64_t), intent(in) :: n, cap
    real(c_double), intent(out) :: out(:)
    integer(c_int64_t), intent(out) :: total
    real(c_double) :: none(0)
    total = 0
    st = mfree_wrapper_check_out(halo_ctx(halo), 'mfree_halo_allgather', 'in', .true., &
                                 size(in, kind=c_int64_t), n)
    if (st == MFREE_SUCCESS) &
      st = mfree_wrapper_check_out(halo_ctx(halo), 'mfree_halo_allgather', 'out', .true., &
                                   size(out, kind=c_int64_t), cap)
    if (st /= MFREE_SUCCESS) then
      if (mfree_halo_set_pending_error_c(halo%ptr) /= MFREE_SUCCESS) return
      st = mfree_halo_allgather_c(halo%ptr, none, 0_c_int64_t, empty_dbl, 0_c_int64_t, total)
      return
    end if
    st = mfree_halo_allgather_c(halo%ptr, in, n, out, cap, total)
  end function mfree_halo_allgather

  !> The ghosts' correction records of approximant a from their owners (mfree_mpi.h).
  !> Collective; after every setup or update of a.
  integer(c_int) function mfree_halo_exchange_correction(halo, a) result(st)
    type(mfree_halo), intent(in) :: halo
    type(mfree_approximant), intent(in) :: a
    st = mfree_halo_exchange_correction_c(halo%ptr, a%ptr)
  end function mfree_halo_exchange_correction

  !> Typed wrapper of mfree_halo_get_context (mfree_mpi.h): the plan's context, borrowed.
  integer(c_int) function mfree_halo_get_context(halo, ctx) result(st)
    type(mfree_halo), intent(in) :: halo
    type(mfree_context), intent(out) :: ctx
    st = mfree_halo_get_context_c(halo%ptr, ctx%ptr)
  end function mfree_halo_get_context

  !> Typed wrapper of mfree_halo_set_pending_error (mfree_mpi.h).
  integer(c_int) function mfree_halo_set_pending_error(halo) result(st)
    type(mfree_halo), intent(in) :: halo
    st = mfree_halo_set_pending_error_c(halo%ptr)
  end function mfree_halo_set_pending_error

  !> The context of a plan (NULL for a NULL handle).
  type(c_ptr) function halo_ctx(halo) result(ctx)
    type(mfree_halo), intent(in) :: halo
    integer(c_int) :: st
    ctx = c_null_ptr
    st = mfree_halo_get_context_c(halo%ptr, ctx)
  end function halo_ctx

  ! ---- migration (mfree_mpi.h, "Migration") ----

  !> A migration plan on the communicator comm (an integer handle of `use mpi`). Collective.
  integer(c_int) function mfree_migration_create(ctx, comm, dim, migration) result(st)
    type(mfree_context), intent(in) :: ctx
    integer, intent(in) :: comm
    integer(c_int32_t), intent(in) :: dim
    type(mfree_migration), intent(out) :: migration
    st = mfree_migration_create_f_c(ctx%ptr, int(comm, c_int32_t), dim, migration%ptr)
  end function mfree_migration_create

  !> The same with the communicator already as integer(c_int32_t).
  integer(c_int) function mfree_migration_create_f(ctx, fcomm, dim, migration) result(st)
    type(mfree_context), intent(in) :: ctx
    integer(c_int32_t), intent(in) :: fcomm, dim
    type(mfree_migration), intent(out) :: migration
    st = mfree_migration_create_f_c(ctx%ptr, fcomm, dim, migration%ptr)
  end function mfree_migration_create_f

  !> Free the plan. Collective, like mfree_halo_destroy.
  integer(c_int) function mfree_migration_destroy(migration) result(st)
    type(mfree_migration), intent(inout) :: migration
    st = mfree_migration_destroy_c(migration%ptr)
  end function mfree_migration_destroy

  !> MFREE_PARTITIONER_RCB or _HSFC and Zoltan's imbalance tolerance (>= 1).
  integer(c_int) function mfree_migration_set_partitioner(migration, method, imbalance_tol) result(st)
    type(mfree_migration), intent(in) :: migration
    integer(c_int32_t), intent(in) :: method
    real(c_double), intent(in) :: imbalance_tol
    st = mfree_migration_set_partitioner_c(migration%ptr, method, imbalance_tol)
  end function mfree_migration_set_partitioner

  !> Register a field: data = c_loc of the first item of a contiguous array (with the
  !> target attribute, alive until the fields are cleared) that holds the capacity given
  !> to mfree_migration_execute; item_bytes per particle, stride_bytes between particles
  !> (x(ld, n) of real(c_double): item 8 * dim, stride 8 * ld). The module cannot see the
  !> array's size through a c_ptr: the host sizes it.
  integer(c_int) function mfree_migration_add_field(migration, data, item_bytes, stride_bytes) result(st)
    type(mfree_migration), intent(in) :: migration
    type(c_ptr), intent(in) :: data
    integer(c_int64_t), intent(in) :: item_bytes, stride_bytes
    st = mfree_migration_add_field_c(migration%ptr, data, item_bytes, stride_bytes)
  end function mfree_migration_add_field

  integer(c_int) function mfree_migration_clear_fields(migration) result(st)
    type(mfree_migration), intent(in) :: migration
    st = mfree_migration_clear_fields_c(migration%ptr)
  end function mfree_migration_clear_fields

  !> Destinations by Zoltan from positions x(ld, n_owned); n_new after the migration.
  !> Collective. x must hold ld * n_owned values, else MFREE_ERR_ARG on every rank.
  integer(c_int) function mfree_migration_partition(migration, n_owned, x, ld, rebalance, n_new) result(st)
    type(mfree_migration), intent(in) :: migration
    integer(c_int32_t), intent(in) :: n_owned, rebalance
    real(c_double), intent(in), target :: x(..)
    integer(c_int64_t), intent(in) :: ld
    integer(c_int32_t), intent(out) :: n_new
    real(c_double), pointer :: px(:)
    real(c_double), allocatable, target :: tx(:)
    n_new = 0
    st = mfree_wrapper_check_out(migration_ctx(migration), 'mfree_migration_partition', 'x', .true., &
                                 size(x, kind=c_int64_t), ld * max(int(n_owned, c_int64_t), 0_c_int64_t))
    if (st /= MFREE_SUCCESS) then
      if (mfree_migration_set_pending_error_c(migration%ptr) /= MFREE_SUCCESS) return
      st = mfree_migration_partition_c(migration%ptr, n_owned, empty_dbl, ld, rebalance, n_new)
      return
    end if
    call mfree_wrapper_view_dbl(x, tx, px)
    st = mfree_migration_partition_c(migration%ptr, n_owned, px, ld, rebalance, n_new)
  end function mfree_migration_partition

  !> Destinations chosen by the host: owners(n_owned) ranks in [0, size). Collective.
  !> owners must hold n_owned values, else MFREE_ERR_ARG on every rank.
  integer(c_int) function mfree_migration_set_owners(migration, n_owned, owners, n_new) result(st)
    type(mfree_migration), intent(in) :: migration
    integer(c_int32_t), intent(in) :: n_owned
    integer(c_int32_t), intent(in), contiguous :: owners(:)
    integer(c_int32_t), intent(out) :: n_new
    n_new = 0
    st = mfree_wrapper_check_out(migration_ctx(migration), 'mfree_migration_set_owners', 'owners', .true., &
                                 size(owners, kind=c_int64_t), max(int(n_owned, c_int64_t), 0_c_int64_t))
    if (st /= MFREE_SUCCESS) then
      if (mfree_migration_set_pending_error_c(migration%ptr) /= MFREE_SUCCESS) return
      st = mfree_migration_set_owners_c(migration%ptr, n_owned, empty_i32, n_new)
      return
    end if
    st = mfree_migration_set_owners_c(migration%ptr, n_owned, owners, n_new)
  end function mfree_migration_set_owners

  !> Move the planned particles with every registered field. Collective.
  integer(c_int) function mfree_migration_execute(migration, capacity) result(st)
    type(mfree_migration), intent(in) :: migration
    integer(c_int32_t), intent(in) :: capacity
    st = mfree_migration_execute_c(migration%ptr, capacity)
  end function mfree_migration_execute

  integer(c_int) function mfree_migration_get_counts(migration, n_owned, n_new, n_send, n_recv) result(st)
    type(mfree_migration), intent(in) :: migration
    integer(c_int32_t), intent(out) :: n_owned, n_new
    integer(c_int64_t), intent(out) :: n_send, n_recv
    st = mfree_migration_get_counts_c(migration%ptr, n_owned, n_new, n_send, n_recv)
  end function mfree_migration_get_counts

  !> owners(n_owned): each planned particle's destination; contiguous and long enough,
  !> else MFREE_ERR_ARG with nothing written.
  integer(c_int) function mfree_migration_get_owners(migration, owners) result(st)
    type(mfree_migration), intent(in) :: migration
    integer(c_int32_t), intent(out) :: owners(:)
    st = mfree_wrapper_check_out(migration_ctx(migration), 'mfree_migration_get_owners', 'owners', &
                                 is_contiguous(owners), 0_c_int64_t, 0_c_int64_t)
    if (st /= MFREE_SUCCESS) return
    st = mfree_migration_get_owners_c(migration%ptr, owners, size(owners, kind=c_int64_t))
  end function mfree_migration_get_owners

  !> Typed wrapper of mfree_migration_get_context (mfree_mpi.h): the plan's context, borrowed.
  integer(c_int) function mfree_migration_get_context(migration, ctx) result(st)
    type(mfree_migration), intent(in) :: migration
    type(mfree_context), intent(out) :: ctx
    st = mfree_migration_get_context_c(migration%ptr, ctx%ptr)
  end function mfree_migration_get_context

  !> Typed wrapper of mfree_migration_set_pending_error (mfree_mpi.h).
  integer(c_int) function mfree_migration_set_pending_error(migration) result(st)
    type(mfree_migration), intent(in) :: migration
    st = mfree_migration_set_pending_error_c(migration%ptr)
  end function mfree_migration_set_pending_error

  !> The context of a migration plan (NULL for a NULL handle).
  type(c_ptr) function migration_ctx(migration) result(ctx)
    type(mfree_migration), intent(in) :: migration
    integer(c_int) :: st
    ctx = c_null_ptr
    st = mfree_migration_get_context_c(migration%ptr, ctx)
  end function migration_ctx

end module mfree_mpi
