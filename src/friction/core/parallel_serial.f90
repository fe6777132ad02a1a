!> friction_parallel for the serial program: one process alone, without
!> MPI (no MPI library is linked or loaded).  Every communicator here is
!> this one process: rank 0 of 1.  A broadcast and a reduction over one
!> rank leave the values as they are, a gather copies this rank's part to
!> its place, the shared counter is the process's own, and a rank alone
!> has no other rank to send to or receive from.  MPI cannot be started:
!> under a launcher the program hands the run to the parallel one
!> (app/cli.f90) before any job begins.
submodule(friction_parallel) friction_parallel_serial
   implicit none

contains

   module procedure parallel_built
      parallel_built = .false.
   end procedure parallel_built

   module procedure start_parallel
      stat = 1
   end procedure start_parallel

   module procedure finish_parallel
   end procedure finish_parallel

   module procedure parallel_started
      parallel_started = .false.
   end procedure parallel_started

   module procedure parallel_finished
      parallel_finished = .false.
   end procedure parallel_finished

   module procedure parallel_library
      text = 'none (the serial program; under a launcher it runs friction-mpi)'
   end procedure parallel_library

   ! The world of a process without MPI is that process.
   module procedure world_comm
      comm = serial_comm()
   end procedure world_comm

   module procedure self_comm
      comm = serial_comm()
   end procedure self_comm

   module procedure communicator_rank
      rank = 0
   end procedure communicator_rank

   module procedure communicator_size
      ranks = 1
   end procedure communicator_size

   module procedure broadcast_integer
   end procedure broadcast_integer

   module procedure broadcast_integers
   end procedure broadcast_integers

   module procedure broadcast_i8s
   end procedure broadcast_i8s

   module procedure broadcast_real
   end procedure broadcast_real

   module procedure broadcast_reals
   end procedure broadcast_reals

   module procedure broadcast_reals_2d
   end procedure broadcast_reals_2d

   module procedure broadcast_logical
   end procedure broadcast_logical

   module procedure broadcast_text
   end procedure broadcast_text

   module procedure reduce_all_integer
   end procedure reduce_all_integer

   module procedure reduce_all_i8
   end procedure reduce_all_i8

   module procedure reduce_all_i8s
   end procedure reduce_all_i8s

   module procedure reduce_all_real
   end procedure reduce_all_real

   module procedure reduce_all_reals
   end procedure reduce_all_reals

   module procedure reduce_all_logical
   end procedure reduce_all_logical

   module procedure reduce_to_root_integers
   end procedure reduce_to_root_integers

   module procedure reduce_to_root_reals
   end procedure reduce_to_root_reals

   module procedure gather_to_root
      values(1) = value
   end procedure gather_to_root

   module procedure gather_all
      values(1) = value
   end procedure gather_all

   module procedure gather_all_varying
      everything(:, displacements(1) + 1:displacements(1) + counts(1)) = items(:, 1:counts(1))
   end procedure gather_all_varying

   module procedure barrier
   end procedure barrier

   module procedure counter_create
      self%windowed = .false.
      self%local = 0
   end procedure counter_create

   module procedure counter_take
      value = self%local
      self%local = self%local + 1
   end procedure counter_take

   module procedure counter_free
      self%local = 0
   end procedure counter_free

   ! Only ranks other than 0 send (to rank 0), and one process has none: the
   ! sweep's rank 0 keeps its own points (job/sweep.f90).  So no send is
   ! ever in flight, and none arrives.
   module procedure send_async_integers
      request%active = .false.
   end procedure send_async_integers

   module procedure send_async_reals
      request%active = .false.
   end procedure send_async_reals

   module procedure send_async_text
      request%active = .false.
   end procedure send_async_text

   module procedure wait_sends
      requests%active = .false.
   end procedure wait_sends

   module procedure probe_any
      arrived = .false.
      source = -1
   end procedure probe_any

   module procedure receive_integers
   end procedure receive_integers

   module procedure receive_reals
   end procedure receive_reals

   module procedure receive_text
   end procedure receive_text

   ! One process writes its files with HDF5's default driver: nothing to set.
   module procedure set_parallel_file_access
      stat = 0
   end procedure set_parallel_file_access

   module procedure set_collective_transfer
      stat = 0
   end procedure set_collective_transfer

end submodule friction_parallel_serial
