!> friction_parallel on MPI (mpi_f08) and parallel HDF5: the library and
!> the parallel program.  An attached communicator is MPI's; on one that is
!> not (a serial job) nothing calls MPI.
submodule(friction_parallel) friction_parallel_mpi
   use mpi_f08
   use hdf5, only: h5pset_fapl_mpio_f, h5pset_dxpl_mpio_f, H5FD_MPIO_COLLECTIVE_F
   implicit none

contains

   !> The MPI communicator of an attached one.
   type(MPI_Comm) function mpi_of(comm) result(c)
      type(communicator), intent(in) :: comm

      c%MPI_VAL = comm%handle
   end function mpi_of

   type(MPI_Op) function mpi_op_of(op) result(o)
      integer, intent(in) :: op

      select case (op)
      case (op_sum)
         o = MPI_SUM
      case (op_max)
         o = MPI_MAX
      case (op_min)
         o = MPI_MIN
      case default
         o = MPI_LAND
      end select
   end function mpi_op_of

   module procedure parallel_built
      parallel_built = .true.
   end procedure parallel_built

   module procedure start_parallel
      integer :: provided

      if (funneled) then
         call MPI_Init_thread(MPI_THREAD_FUNNELED, provided, stat)
      else
         call MPI_Init(stat)
      end if
   end procedure start_parallel

   module procedure finish_parallel
      call MPI_Finalize()
   end procedure finish_parallel

   module procedure parallel_started
      call MPI_Initialized(parallel_started)
   end procedure parallel_started

   module procedure parallel_finished
      call MPI_Finalized(parallel_finished)
   end procedure parallel_finished

   ! (MPI_Get_library_version may precede MPI_Init.)
   module procedure parallel_library
      character(len=MPI_MAX_LIBRARY_VERSION_STRING) :: mpi_text
      integer :: length, cut

      call MPI_Get_library_version(mpi_text, length)
      mpi_text = mpi_text(1:max(0, min(length, len(mpi_text))))
      cut = scan(mpi_text, new_line('a')//achar(0))
      if (cut > 0) mpi_text = mpi_text(1:cut - 1)
      text = trim(mpi_text)
   end procedure parallel_library

   module procedure world_comm
      comm%attached = .true.
      comm%handle = MPI_COMM_WORLD%MPI_VAL
   end procedure world_comm

   module procedure self_comm
      comm%attached = .true.
      comm%handle = MPI_COMM_SELF%MPI_VAL
   end procedure self_comm

   module procedure communicator_rank
      rank = 0
      if (self%attached) call MPI_Comm_rank(mpi_of(self), rank)
   end procedure communicator_rank

   module procedure communicator_size
      ranks = 1
      if (self%attached) call MPI_Comm_size(mpi_of(self), ranks)
   end procedure communicator_size

   module procedure broadcast_integer
      if (comm%attached) call MPI_Bcast(buffer, 1, MPI_INTEGER, root, mpi_of(comm))
   end procedure broadcast_integer

   module procedure broadcast_integers
      if (comm%attached) call MPI_Bcast(buffer, size(buffer), MPI_INTEGER, root, mpi_of(comm))
   end procedure broadcast_integers

   module procedure broadcast_i8s
      if (comm%attached) call MPI_Bcast(buffer, size(buffer), MPI_INTEGER8, root, mpi_of(comm))
   end procedure broadcast_i8s

   module procedure broadcast_real
      if (comm%attached) call MPI_Bcast(buffer, 1, MPI_DOUBLE_PRECISION, root, mpi_of(comm))
   end procedure broadcast_real

   module procedure broadcast_reals
      if (comm%attached) call MPI_Bcast(buffer, size(buffer), MPI_DOUBLE_PRECISION, root, mpi_of(comm))
   end procedure broadcast_reals

   module procedure broadcast_reals_2d
      if (comm%attached) call MPI_Bcast(buffer, size(buffer), MPI_DOUBLE_PRECISION, root, mpi_of(comm))
   end procedure broadcast_reals_2d

   module procedure broadcast_logical
      if (comm%attached) call MPI_Bcast(buffer, 1, MPI_LOGICAL, root, mpi_of(comm))
   end procedure broadcast_logical

   module procedure broadcast_text
      if (comm%attached) call MPI_Bcast(buffer, len(buffer), MPI_CHARACTER, root, mpi_of(comm))
   end procedure broadcast_text

   module procedure reduce_all_integer
      if (comm%attached) call MPI_Allreduce(MPI_IN_PLACE, value, 1, MPI_INTEGER, mpi_op_of(op), mpi_of(comm))
   end procedure reduce_all_integer

   module procedure reduce_all_i8
      if (comm%attached) call MPI_Allreduce(MPI_IN_PLACE, value, 1, MPI_INTEGER8, mpi_op_of(op), mpi_of(comm))
   end procedure reduce_all_i8

   module procedure reduce_all_i8s
      if (comm%attached) call MPI_Allreduce(MPI_IN_PLACE, values, size(values), MPI_INTEGER8, mpi_op_of(op), &
         & mpi_of(comm))
   end procedure reduce_all_i8s

   module procedure reduce_all_real
      if (comm%attached) call MPI_Allreduce(MPI_IN_PLACE, value, 1, MPI_DOUBLE_PRECISION, mpi_op_of(op), &
         & mpi_of(comm))
   end procedure reduce_all_real

   module procedure reduce_all_reals
      if (comm%attached) call MPI_Allreduce(MPI_IN_PLACE, values, size(values), MPI_DOUBLE_PRECISION, &
         & mpi_op_of(op), mpi_of(comm))
   end procedure reduce_all_reals

   module procedure reduce_all_logical
      if (comm%attached) call MPI_Allreduce(MPI_IN_PLACE, value, 1, MPI_LOGICAL, mpi_op_of(op), mpi_of(comm))
   end procedure reduce_all_logical

   module procedure reduce_to_root_integers
      if (.not. comm%attached) return
      if (comm%rank() == 0) then
         call MPI_Reduce(MPI_IN_PLACE, values, size(values), MPI_INTEGER, mpi_op_of(op), 0, mpi_of(comm))
      else
         call MPI_Reduce(values, values, size(values), MPI_INTEGER, mpi_op_of(op), 0, mpi_of(comm))
      end if
   end procedure reduce_to_root_integers

   module procedure reduce_to_root_reals
      if (.not. comm%attached) return
      if (comm%rank() == 0) then
         call MPI_Reduce(MPI_IN_PLACE, values, size(values), MPI_DOUBLE_PRECISION, mpi_op_of(op), 0, mpi_of(comm))
      else
         call MPI_Reduce(values, values, size(values), MPI_DOUBLE_PRECISION, mpi_op_of(op), 0, mpi_of(comm))
      end if
   end procedure reduce_to_root_reals

   module procedure gather_to_root
      if (comm%attached) then
         call MPI_Gather(value, 1, MPI_INTEGER, values, 1, MPI_INTEGER, 0, mpi_of(comm))
      else
         values(1) = value
      end if
   end procedure gather_to_root

   module procedure gather_all
      if (comm%attached) then
         call MPI_Allgather(value, 1, MPI_INTEGER, values, 1, MPI_INTEGER, mpi_of(comm))
      else
         values(1) = value
      end if
   end procedure gather_all

   module procedure gather_all_varying
      integer :: rows

      if (comm%attached) then
         rows = size(items, 1)
         call MPI_Allgatherv(items, rows * counts(1 + comm%rank()), MPI_DOUBLE_PRECISION, everything, &
            & rows * counts, rows * displacements, MPI_DOUBLE_PRECISION, mpi_of(comm))
      else
         everything(:, displacements(1) + 1:displacements(1) + counts(1)) = items(:, 1:counts(1))
      end if
   end procedure gather_all_varying

   module procedure barrier
      if (comm%attached) call MPI_Barrier(mpi_of(comm))
   end procedure barrier

   ! MPI_Win_allocate (not MPI_Win_create on a Fortran variable) lets Open MPI
   ! pick its shared-memory one-sided component on a node: the fetch is an
   ! atomic in memory and needs no progress from rank 0, which is busy
   ! computing (with MPI_Win_create a fetch waits for rank 0's point).
   module procedure counter_create
      use, intrinsic :: iso_c_binding, only: c_ptr, c_f_pointer
      integer(kind=MPI_ADDRESS_KIND) :: window_size
      type(c_ptr) :: base
      integer, pointer :: counter_value
      type(MPI_Win) :: window

      self%local = 0
      ! (One rank needs no window; Open MPI may have no one-sided component for it.)
      self%windowed = comm%attached .and. comm%size() > 1
      if (.not. self%windowed) return
      window_size = merge(4, 0, comm%rank() == 0)
      call MPI_Win_allocate(window_size, 4, MPI_INFO_NULL, mpi_of(comm), base, window)
      if (comm%rank() == 0) then
         call MPI_Win_lock(MPI_LOCK_EXCLUSIVE, 0, 0, window)
         call c_f_pointer(base, counter_value)
         counter_value = 0
         call MPI_Win_unlock(0, window)
      end if
      call MPI_Barrier(mpi_of(comm))
      self%handle = window%MPI_VAL
   end procedure counter_create

   module procedure counter_take
      integer :: one(1), fetched(1)
      type(MPI_Win) :: window

      if (.not. self%windowed) then
         value = self%local
         self%local = self%local + 1
         return
      end if
      window%MPI_VAL = self%handle
      one = 1
      call MPI_Win_lock(MPI_LOCK_EXCLUSIVE, 0, 0, window)
      call MPI_Fetch_and_op(one, fetched, MPI_INTEGER, 0, 0_MPI_ADDRESS_KIND, MPI_SUM, window)
      call MPI_Win_unlock(0, window)
      value = fetched(1)
   end procedure counter_take

   module procedure counter_free
      type(MPI_Win) :: window

      if (self%windowed) then
         window%MPI_VAL = self%handle
         call MPI_Win_free(window)
      end if
      self%windowed = .false.
      self%local = 0
   end procedure counter_free

   module procedure send_async_integers
      type(MPI_Request) :: r

      call MPI_Issend(buffer, size(buffer), MPI_INTEGER, dest, tag, mpi_of(comm), r)
      request%handle = r%MPI_VAL
      request%active = .true.
   end procedure send_async_integers

   module procedure send_async_reals
      type(MPI_Request) :: r

      call MPI_Issend(buffer, size(buffer), MPI_DOUBLE_PRECISION, dest, tag, mpi_of(comm), r)
      request%handle = r%MPI_VAL
      request%active = .true.
   end procedure send_async_reals

   module procedure send_async_text
      type(MPI_Request) :: r

      call MPI_Issend(buffer, len(buffer), MPI_CHARACTER, dest, tag, mpi_of(comm), r)
      request%handle = r%MPI_VAL
      request%active = .true.
   end procedure send_async_text

   module procedure wait_sends
      type(MPI_Request) :: r
      integer :: k

      do k = 1, size(requests)
         if (.not. requests(k)%active) cycle
         r%MPI_VAL = requests(k)%handle
         call MPI_Wait(r, MPI_STATUS_IGNORE)
         requests(k)%active = .false.
      end do
   end procedure wait_sends

   module procedure probe_any
      type(MPI_Status) :: status

      source = -1
      arrived = .false.
      if (.not. comm%attached) return
      if (wait) then
         call MPI_Probe(MPI_ANY_SOURCE, tag, mpi_of(comm), status)
         arrived = .true.
      else
         call MPI_Iprobe(MPI_ANY_SOURCE, tag, mpi_of(comm), arrived, status)
      end if
      if (arrived) source = status%MPI_SOURCE
   end procedure probe_any

   module procedure receive_integers
      call MPI_Recv(buffer, size(buffer), MPI_INTEGER, source, tag, mpi_of(comm), MPI_STATUS_IGNORE)
   end procedure receive_integers

   module procedure receive_reals
      call MPI_Recv(buffer, size(buffer), MPI_DOUBLE_PRECISION, source, tag, mpi_of(comm), MPI_STATUS_IGNORE)
   end procedure receive_reals

   module procedure receive_text
      call MPI_Recv(buffer, len(buffer), MPI_CHARACTER, source, tag, mpi_of(comm), MPI_STATUS_IGNORE)
   end procedure receive_text

   module procedure set_parallel_file_access
      call h5pset_fapl_mpio_f(fapl, comm%handle, MPI_INFO_NULL%MPI_VAL, stat)
   end procedure set_parallel_file_access

   module procedure set_collective_transfer
      call h5pset_dxpl_mpio_f(xfer, H5FD_MPIO_COLLECTIVE_F, stat)
   end procedure set_collective_transfer

end submodule friction_parallel_mpi
