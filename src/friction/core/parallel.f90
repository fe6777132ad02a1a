!> The one place the code meets MPI: a communicator and the operations the
!> jobs make on it, declared here and implemented twice, in submodules
!> (docs/layout.md, The two programs): on MPI (`parallel_mpi.f90`: the
!> library libfriction and the parallel program friction-mpi) and for one
!> process alone (`parallel_serial.f90`: the program friction, which then
!> loads no MPI library).  Nothing above this module names MPI.
!>
!> A communicator that is not attached to MPI (`serial_comm()`, the
!> default) is one process alone, a serial job: every operation does on it
!> what MPI does on a communicator of one rank (a broadcast or a reduction
!> leaves the values as they are, a gather copies), and makes no MPI call,
!> so a serial job runs without MPI_Init in either implementation.
module friction_parallel
   use, intrinsic :: iso_fortran_env, only: int64
   use friction_kinds, only: wp, i8
   implicit none
   private

   public :: communicator, serial_comm, world_comm, self_comm, attached_comm
   public :: parallel_built, start_parallel, finish_parallel, parallel_started, parallel_finished, parallel_library
   public :: broadcast, reduce_all, reduce_to_root, gather_to_root, gather_all, gather_all_varying, barrier
   public :: op_sum, op_max, op_min, op_and
   public :: shared_counter, send_request, send_async, wait_sends, probe_any, receive
   public :: set_parallel_file_access, set_collective_transfer

   !> The reductions of reduce_all and reduce_to_root.
   integer, parameter :: op_sum = 1, op_max = 2, op_min = 3, op_and = 4

   !> The processes of a job: attached to an MPI communicator, or one
   !> process alone (not attached: serial).
   type :: communicator
      private
      logical :: attached = .false.
      integer :: handle = 0        !! MPI's Fortran handle of the communicator, when attached
   contains
      procedure :: parallel => communicator_parallel
      procedure :: mpi_handle => communicator_handle
      procedure :: rank => communicator_rank
      procedure :: size => communicator_size
   end type communicator

   !> A counter on rank 0 that every rank takes the next number from
   !> (one-sided: rank 0 serves it without taking part).  On one process,
   !> the number it keeps itself.
   type :: shared_counter
      private
      logical :: windowed = .false.  !! an MPI window holds the counter
      integer :: handle = 0          !! MPI's Fortran handle of the window
      integer :: local = 0           !! the counter of one process alone
   contains
      procedure :: create => counter_create
      procedure :: take => counter_take
      procedure :: free => counter_free
   end type shared_counter

   !> A send in flight (send_async), until wait_sends.
   type :: send_request
      private
      logical :: active = .false.
      integer :: handle = 0          !! MPI's Fortran handle of the request
   end type send_request

   interface broadcast
      !> `buffer` on every rank becomes root's.
      module subroutine broadcast_integer(comm, buffer, root)
         type(communicator), intent(in) :: comm
         integer, intent(inout) :: buffer
         integer, intent(in) :: root
      end subroutine broadcast_integer
      module subroutine broadcast_integers(comm, buffer, root)
         type(communicator), intent(in) :: comm
         integer, contiguous, intent(inout) :: buffer(:)
         integer, intent(in) :: root
      end subroutine broadcast_integers
      module subroutine broadcast_i8s(comm, buffer, root)
         type(communicator), intent(in) :: comm
         integer(i8), contiguous, intent(inout) :: buffer(:)
         integer, intent(in) :: root
      end subroutine broadcast_i8s
      module subroutine broadcast_real(comm, buffer, root)
         type(communicator), intent(in) :: comm
         real(wp), intent(inout) :: buffer
         integer, intent(in) :: root
      end subroutine broadcast_real
      module subroutine broadcast_reals(comm, buffer, root)
         type(communicator), intent(in) :: comm
         real(wp), contiguous, intent(inout) :: buffer(:)
         integer, intent(in) :: root
      end subroutine broadcast_reals
      module subroutine broadcast_reals_2d(comm, buffer, root)
         type(communicator), intent(in) :: comm
         real(wp), contiguous, intent(inout) :: buffer(:, :)
         integer, intent(in) :: root
      end subroutine broadcast_reals_2d
      module subroutine broadcast_logical(comm, buffer, root)
         type(communicator), intent(in) :: comm
         logical, intent(inout) :: buffer
         integer, intent(in) :: root
      end subroutine broadcast_logical
      module subroutine broadcast_text(comm, buffer, root)
         type(communicator), intent(in) :: comm
         character(len=*), intent(inout) :: buffer
         integer, intent(in) :: root
      end subroutine broadcast_text
   end interface broadcast

   interface reduce_all
      !> `value` on every rank becomes the reduction `op` of all ranks' values.
      module subroutine reduce_all_integer(comm, value, op)
         type(communicator), intent(in) :: comm
         integer, intent(inout) :: value
         integer, intent(in) :: op
      end subroutine reduce_all_integer
      module subroutine reduce_all_i8(comm, value, op)
         type(communicator), intent(in) :: comm
         integer(i8), intent(inout) :: value
         integer, intent(in) :: op
      end subroutine reduce_all_i8
      module subroutine reduce_all_i8s(comm, values, op)
         type(communicator), intent(in) :: comm
         integer(i8), contiguous, intent(inout) :: values(:)
         integer, intent(in) :: op
      end subroutine reduce_all_i8s
      module subroutine reduce_all_real(comm, value, op)
         type(communicator), intent(in) :: comm
         real(wp), intent(inout) :: value
         integer, intent(in) :: op
      end subroutine reduce_all_real
      module subroutine reduce_all_reals(comm, values, op)
         type(communicator), intent(in) :: comm
         real(wp), contiguous, intent(inout) :: values(:)
         integer, intent(in) :: op
      end subroutine reduce_all_reals
      module subroutine reduce_all_logical(comm, value, op)
         type(communicator), intent(in) :: comm
         logical, intent(inout) :: value
         integer, intent(in) :: op
      end subroutine reduce_all_logical
   end interface reduce_all

   interface reduce_to_root
      !> On rank 0, `values` becomes the reduction `op` of all ranks' values
      !> (the other ranks' are left as they were).
      module subroutine reduce_to_root_integers(comm, values, op)
         type(communicator), intent(in) :: comm
         integer, contiguous, intent(inout) :: values(:)
         integer, intent(in) :: op
      end subroutine reduce_to_root_integers
      module subroutine reduce_to_root_reals(comm, values, op)
         type(communicator), intent(in) :: comm
         real(wp), contiguous, intent(inout) :: values(:)
         integer, intent(in) :: op
      end subroutine reduce_to_root_reals
   end interface reduce_to_root

   interface
      !> Whether this build runs jobs on MPI (false: the serial program).
      module logical function parallel_built()
      end function parallel_built

      !> Start MPI (with `funneled`: for a caller whose other threads make no
      !> MPI call); stat /= 0 if it failed or this build has no MPI.
      module subroutine start_parallel(funneled, stat)
         logical, intent(in) :: funneled
         integer, intent(out) :: stat
      end subroutine start_parallel

      module subroutine finish_parallel()
      end subroutine finish_parallel

      !> Whether MPI has been started (by this process, or its host).
      module logical function parallel_started()
      end function parallel_started

      !> Whether MPI has been finished (no job can start it again).
      module logical function parallel_finished()
      end function parallel_finished

      !> The MPI library's name and version (its first line), or what stands
      !> in for it in the serial program.
      module function parallel_library() result(text)
         character(len=:), allocatable :: text
      end function parallel_library

      !> All the processes MPI started (MPI_COMM_WORLD), attached.
      module function world_comm() result(comm)
         type(communicator) :: comm
      end function world_comm

      !> This process alone on MPI (MPI_COMM_SELF), attached.
      module function self_comm() result(comm)
         type(communicator) :: comm
      end function self_comm

      module integer function communicator_rank(self) result(rank)
         class(communicator), intent(in) :: self
      end function communicator_rank

      module integer function communicator_size(self) result(ranks)
         class(communicator), intent(in) :: self
      end function communicator_size

      !> Rank 0 gets every rank's `value` in values(1:size), in rank order.
      module subroutine gather_to_root(comm, value, values)
         type(communicator), intent(in) :: comm
         integer, intent(in) :: value
         integer, intent(inout) :: values(:)
      end subroutine gather_to_root

      !> Every rank gets every rank's `value` in values(1:size), in rank order.
      module subroutine gather_all(comm, value, values)
         type(communicator), intent(in) :: comm
         integer, intent(in) :: value
         integer, intent(out) :: values(:)
      end subroutine gather_all

      !> Every rank gets every rank's columns `items` in `everything`: rank
      !> r's counts(r+1) columns after the first displacements(r+1).
      module subroutine gather_all_varying(comm, items, counts, displacements, everything)
         type(communicator), intent(in) :: comm
         real(wp), contiguous, intent(in) :: items(:, :)
         integer, intent(in) :: counts(:), displacements(:)
         real(wp), contiguous, intent(inout) :: everything(:, :)
      end subroutine gather_all_varying

      module subroutine barrier(comm)
         type(communicator), intent(in) :: comm
      end subroutine barrier

      !> Set up the counter at 0 on the communicator's ranks (collective).
      module subroutine counter_create(self, comm)
         class(shared_counter), intent(inout) :: self
         type(communicator), intent(in) :: comm
      end subroutine counter_create

      !> The counter's value before this rank added one to it.
      module subroutine counter_take(self, value)
         class(shared_counter), intent(inout) :: self
         integer, intent(out) :: value
      end subroutine counter_take

      !> Release the counter (collective).
      module subroutine counter_free(self)
         class(shared_counter), intent(inout) :: self
      end subroutine counter_free

      !> Wait until every active send of `requests` has been received.
      module subroutine wait_sends(requests)
         type(send_request), intent(inout) :: requests(:)
      end subroutine wait_sends

      !> The source of a message with `tag` from any rank: with `wait`, wait
      !> for one; without, arrived says whether one has come.
      module subroutine probe_any(comm, tag, wait, arrived, source)
         type(communicator), intent(in) :: comm
         integer, intent(in) :: tag
         logical, intent(in) :: wait
         logical, intent(out) :: arrived
         integer, intent(out) :: source
      end subroutine probe_any

      !> A parallel HDF5 file's access list `fapl` on comm (HDF5's MPI-IO driver).
      module subroutine set_parallel_file_access(fapl, comm, stat)
         integer(int64), intent(in) :: fapl
         type(communicator), intent(in) :: comm
         integer, intent(out) :: stat
      end subroutine set_parallel_file_access

      !> A transfer list `xfer` whose writes every rank makes together.
      module subroutine set_collective_transfer(xfer, stat)
         integer(int64), intent(in) :: xfer
         integer, intent(out) :: stat
      end subroutine set_collective_transfer
   end interface

   interface send_async
      !> Start a synchronous send of `buffer` (kept unchanged until
      !> wait_sends) to rank `dest`: complete once dest has received it.
      module subroutine send_async_integers(comm, buffer, dest, tag, request)
         type(communicator), intent(in) :: comm
         integer, contiguous, asynchronous, intent(in) :: buffer(:)
         integer, intent(in) :: dest, tag
         type(send_request), intent(inout) :: request
      end subroutine send_async_integers
      module subroutine send_async_reals(comm, buffer, dest, tag, request)
         type(communicator), intent(in) :: comm
         real(wp), contiguous, asynchronous, intent(in) :: buffer(:)
         integer, intent(in) :: dest, tag
         type(send_request), intent(inout) :: request
      end subroutine send_async_reals
      module subroutine send_async_text(comm, buffer, dest, tag, request)
         type(communicator), intent(in) :: comm
         character(len=*), asynchronous, intent(in) :: buffer
         integer, intent(in) :: dest, tag
         type(send_request), intent(inout) :: request
      end subroutine send_async_text
   end interface send_async

   interface receive
      !> Receive into `buffer` the message with `tag` from rank `source`.
      module subroutine receive_integers(comm, buffer, source, tag)
         type(communicator), intent(in) :: comm
         integer, contiguous, intent(inout) :: buffer(:)
         integer, intent(in) :: source, tag
      end subroutine receive_integers
      module subroutine receive_reals(comm, buffer, source, tag)
         type(communicator), intent(in) :: comm
         real(wp), contiguous, intent(inout) :: buffer(:)
         integer, intent(in) :: source, tag
      end subroutine receive_reals
      module subroutine receive_text(comm, buffer, source, tag)
         type(communicator), intent(in) :: comm
         character(len=*), intent(inout) :: buffer
         integer, intent(in) :: source, tag
      end subroutine receive_text
   end interface receive

contains

   !> One process alone, without MPI: a serial job.
   pure function serial_comm() result(comm)
      type(communicator) :: comm

      comm%attached = .false.
   end function serial_comm

   !> A communicator of MPI's given by its Fortran handle (MPI_Comm's
   !> MPI_VAL), from a caller that made it (a test on its own ranks).
   pure function attached_comm(handle) result(comm)
      integer, intent(in) :: handle
      type(communicator) :: comm

      comm%attached = .true.
      comm%handle = handle
   end function attached_comm

   !> MPI's Fortran handle of an attached communicator.
   pure integer function communicator_handle(self) result(handle)
      class(communicator), intent(in) :: self

      handle = self%handle
   end function communicator_handle

   !> Whether the communicator is MPI's (false: one process alone, no MPI call).
   pure logical function communicator_parallel(self) result(parallel)
      class(communicator), intent(in) :: self

      parallel = self%attached
   end function communicator_parallel

end module friction_parallel
