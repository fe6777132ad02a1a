!> Parameter sweeps over the MPI ranks (docs/sweeps.md).  Each
!> point is a copy of the job's scene with the swept variables set in memory
!> and checked by the scene's own checks; an invalid or failing point is
!> recorded as failed with its reason and the sweep goes on.
!>
!> Load balancing: with sweep_schedule = 'dynamic' every rank takes the next
!> point from a counter on rank 0 with MPI_Fetch_and_op (passive target).
!> This is simpler than a master that serves requests between its own points
!> (no polling, rank 0 computes like the others) and hands out points on
!> demand, so a chaotic, long point does not hold up a whole static share.
!> Each point is computed alone and deterministically: the results do not
!> depend on which rank took it or on the number of ranks.
!>
!> Streaming, with memory per rank independent of the number of points: a
!> rank sends each finished point to rank 0 at once (at most `in_flight`
!> sends unmatched, so rank 0's MPI queue is bounded too), and rank 0
!> gathers them in a batch of at most `batch_points` points that it writes
!> into the checkpoint OUTPUT.ckpt, one HDF5 file of chunked columns
!> indexed by point (output/h5_table.f90), flushed after each batch.  At the
!> end rank 0 copies the checkpoint into the output in point order, a chunk
!> of points at a time.  No rank holds an array over all points.
!>
!> Why a checkpoint file beside the output and not the output in progress:
!> points finish in an order that depends on the ranks, and a point's maxima
!> are a list of its own length; the output keeps them in one flat list in
!> point order (the documented layout, the same bits on any number of
!> ranks), which only a copy at the end can give.  The checkpoint keeps them
!> in the order they came, indexed by offset and count per point.
module friction_job_sweep
   use, intrinsic :: iso_c_binding, only: c_ptr, c_f_pointer
   use mpi_f08
   use friction_kinds, only: wp, i8
   use friction_clock, only: wall_seconds
   use friction_error, only: error_type, fatal_error, error_interrupted, error_input, error_numerical, error_io
   use friction_strings, only: itoa, text_hash, text_hash_bits, bytes_text, one_line
   use friction_output_checkpoint, only: real_line
   use friction_version, only: version_string
   use friction_ode_solver, only: integrator_statistics, step_type_index, step_type_names, step_type_name_length
   use friction_parameters, only: set_parameter_number, split_name, parameter_info, list_parameters
   use friction_checks, only: config_checker
   use friction_scene, only: scene, point_result, point_memory
   use friction_job_config, only: job_config
   use friction_output_h5, only: h5_file
   use friction_output_h5_table, only: h5_table
   use friction_output_summary, only: run_summary, write_run_attributes
   use friction_files, only: remove_file, file_exists, free_bytes, min_free_bytes, rename_file, full_text
   use friction_scene_report, only: job_reporter
   use friction_scene_context, only: job_context, temporary_name, publish, ranks_text, agree_on_error, job_wall_time
   implicit none
   private

   public :: run_sweep_job

   integer, parameter :: status_pending = 0, status_done = 1, status_failed = 2

   !> Sends of finished points a rank may have unmatched by rank 0: what
   !> rank 0's MPI layer can hold for each rank while it computes a point.
   integer, parameter :: in_flight = 16
   !> Points rank 0 gathers before it writes them to the checkpoint (and
   !> values of their series: the batch is written when either is reached).
   integer, parameter :: batch_points = 1024, batch_series = 1048576
   !> Seconds after which a batch is written however small (how much a
   !> killed run can lose).
   real(wp), parameter :: batch_seconds = 10.0_wp
   !> Points per piece of the final copy into the output.
   integer, parameter :: copy_points = 4096

   !> The kinds of the checkpoint's columns of column_names (h5_table's add_column).
   character(len=8), parameter :: column_kinds = 'iirlilil'

   integer, parameter :: tag_header = 7301, tag_numbers = 7302, tag_reason = 7303

   !> The result the sweep adds after the scene's own: the stepper point i ran,
   !> carried as its step type's index (0: none, the point failed its check)
   !> and written as its name, /sweep/method.  A point resolves method =
   !> 'auto' for its own values, so a sweep over a tip's damping, epsilon' or
   !> a tolerance can run different steppers at different points.
   character(len=*), parameter :: method_result = 'method'

   !> One finished point as sent to rank 0: header = point (0: this rank has
   !> finished; then header(2) says whether it was interrupted), status,
   !> number of results, series length, reason length.
   type :: point_message
      integer :: header(5) = 0
      real(wp), allocatable :: numbers(:)   !! results, cost, series
      character(len=:), allocatable :: reason
      type(MPI_Request) :: requests(3)
      logical :: busy = .false.
   end type point_message

   !> Rank 0's points not yet in the checkpoint, in the order they came.
   type :: point_batch
      integer :: n = 0
      integer, allocatable :: point(:), status(:), series_count(:), reason_length(:)
      real(wp), allocatable :: results(:, :), cost(:)
      real(wp), allocatable :: series(:)
      integer :: n_series = 0
      character(len=:), allocatable :: reasons
      real(wp) :: since = 0.0_wp   !! when the last batch was written
   end type point_batch

   !> Rank 0's checkpoint: the file, this run's number, where its flat lists end.
   type :: checkpoint
      type(h5_table) :: file
      character(len=:), allocatable :: path
      character(len=:), allocatable :: hash   !! of the input it belongs to
      integer :: points = 0
      logical :: opened = .false.
      integer :: run = 1
      integer(i8) :: series_end = 0, reason_end = 0
      integer :: received = 0   !! points done in this run
      type(error_type), allocatable :: error   !! the first failure to write it
   end type checkpoint

contains

   !> Run the sweep of `config`; a stop request (the reporter's stop_after)
   !> ends it early (the file then marks the points not done as pending and
   !> the error says so, with stat error_interrupted).
   subroutine run_sweep_job(job, config, reporter, summary, error)
      type(job_context), intent(in) :: job
      type(job_config), intent(in) :: config
      class(job_reporter), intent(inout) :: reporter
      character(len=:), allocatable, intent(out) :: summary
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: point_error
      character(len=:), allocatable :: temporary, series_name, series_unit, input_hash, todo_path, first_reason
      character(len=:), allocatable :: warning
      !> points of this run whose settings the scene warns about, and the first of them
      integer :: warned, first_warned
      type(point_result), allocatable :: names(:)
      type(point_message), allocatable :: outbox(:)
      type(point_message) :: mine
      type(checkpoint) :: ckpt
      type(point_batch) :: batch
      type(point_memory) :: kept   !! what this rank's points leave for its next ones
      real(wp), allocatable :: results(:), series(:)
      integer, allocatable :: memory(:)
      integer :: n, n_work, w, i, next, computed, flag, last_taken, slot, finished, todo_unit, counts(3), stat
      integer(kind=MPI_ADDRESS_KIND) :: window_size
      integer :: one(1), fetched(1), block_first, block_last
      type(c_ptr) :: counter_base
      integer, pointer :: counter_value
      type(MPI_Win) :: window
      type(run_summary) :: record
      real(wp) :: wall, t0, cost
      character(len=12) :: seconds
      logical :: dynamic, interrupted, all_failed, use_todo

      names = [config%scene%point_results(), point_result(method_result, '', .false.)]
      call config%scene%point_series(series_name, series_unit)
      n = config%sweep%points()
      input_hash = text_hash(job%input_text)
      ckpt%path = job%output//'.ckpt'
      ckpt%hash = input_hash
      ckpt%points = n
      todo_path = job%output//'.ckpt-todo'
      n_work = n
      use_todo = .false.
      ! --resume: the checkpoint must be of this very input and whole, or
      ! nothing is computed (README: Parameter sweeps).  Rank 0 lists the
      ! points still to do in a file every rank reads, so that no rank holds
      ! a list over all points.
      if (job%rank == 0) call check_room(job, config, n, size(names), error)
      if (job%rank == 0 .and. .not. allocated(error)) then
         if (job%resume .and. file_exists(ckpt%path)) then
            call open_checkpoint(ckpt, input_hash, n, size(names), todo_path, n_work, error)
            use_todo = .not. allocated(error)
         else
            call remove_file(ckpt%path)   ! another run's, which this one does not resume
         end if
      end if
      call agree_on_error(job, error)
      if (allocated(error)) return
      if (job%parallel()) then
         call MPI_Bcast(n_work, 1, MPI_INTEGER, 0, job%comm)
         call MPI_Bcast(use_todo, 1, MPI_LOGICAL, 0, job%comm)
      end if
      todo_unit = -1
      if (use_todo) then
         open (newunit=todo_unit, file=todo_path, access='stream', form='unformatted', action='read', &
            & status='old', iostat=stat)
         if (stat /= 0) call fatal_error(error, todo_path//': cannot read the list of points to do', error_io)
         call agree_on_error(job, error)
         if (allocated(error)) return
      end if

      allocate (results(size(names)))
      allocate (outbox(in_flight))
      if (job%rank == 0) call start_batch(batch, size(names))
      one = 1
      window_size = merge(4, 0, job%rank == 0)
      ! (One rank needs no counter; Open MPI may have no one-sided component for it.)
      dynamic = config%sweep%schedule == 'dynamic' .and. job%nranks > 1
      ! MPI_Win_allocate (not MPI_Win_create on a Fortran variable) lets Open MPI
      ! pick its shared-memory one-sided component on a node: the fetch is an
      ! atomic in memory and needs no progress from rank 0, which is busy
      ! computing (with MPI_Win_create a fetch waits for rank 0's point).
      if (dynamic) then
         call MPI_Win_allocate(window_size, 4, MPI_INFO_NULL, job%comm, counter_base, window)
         if (job%rank == 0) then
            call MPI_Win_lock(MPI_LOCK_EXCLUSIVE, 0, 0, window)
            call c_f_pointer(counter_base, counter_value)
            counter_value = 0
            call MPI_Win_unlock(0, window)
         end if
         call MPI_Barrier(job%comm)
      end if
      block_first = int(int(n_work, i8) * job%rank / job%nranks)
      block_last = int(int(n_work, i8) * (job%rank + 1) / job%nranks)
      computed = 0
      warned = 0
      first_warned = huge(1)
      interrupted = .false.
      last_taken = 0
      slot = 0
      finished = 0
      do
         ! Between points: a stop request ends the sweep here, the point in hand done.
         if (reporter%stop_after(last_taken)) then
            interrupted = .true.
            exit
         end if
         if (.not. dynamic) then
            ! The naive static split, for the benchmark: contiguous blocks of
            ! points, so a run of expensive neighbours lands on one rank.
            next = block_first + computed
            if (next >= block_last) next = n_work
         else
            call MPI_Win_lock(MPI_LOCK_EXCLUSIVE, 0, 0, window)
            call MPI_Fetch_and_op(one, fetched, MPI_INTEGER, 0, 0_MPI_ADDRESS_KIND, MPI_SUM, window)
            call MPI_Win_unlock(0, window)
            next = fetched(1)
         end if
         w = next + 1
         if (w > n_work) exit
         i = w
         if (use_todo) read (todo_unit, pos=int(w - 1, i8) * 4 + 1) i
         last_taken = i
         ! (A stop after the point before this one, which another rank may have taken.)
         if (i > 1) then
            if (reporter%stop_after(i - 1)) then
               interrupted = .true.
               exit
            end if
         end if
         computed = computed + 1
         t0 = wall_seconds()
         call run_point(config, i, results, series, kept, warning, point_error)
         if (len(warning) > 0) then
            warned = warned + 1
            first_warned = min(first_warned, i)
         end if
         if (.not. allocated(series)) allocate (series(0))
         cost = wall_seconds() - t0
         mine%header = [i, status_done, size(names), size(series), 0]
         mine%reason = ''
         if (allocated(point_error)) then
            mine%header(2) = status_failed
            mine%reason = one_line(trim(point_error%message))
            results(:size(results) - 1) = 0.0_wp   ! (the stepper it ran stays)
            deallocate (point_error)
            if (allocated(series)) deallocate (series)
            allocate (series(0))
         end if
         mine%header(4) = size(series)
         mine%header(5) = len(mine%reason)
         mine%numbers = [results, cost, series]
         if (job%rank == 0) then
            call add_point(batch, mine)
            call write_batch(ckpt, batch, names, .false.)   ! (every add is followed by one: a batch never overflows)
            call receive_points(job, ckpt, batch, names, finished, .false.)
            ! (The points rank 0 has taken: those written and those in its batch.)
            call reporter%progress(real(ckpt%received + batch%n, wp), real(n_work, wp), 'points', .false.)
         else
            call send_point(job, outbox, slot, mine)
         end if
      end do
      if (todo_unit >= 0) close (todo_unit)
      ! This rank has finished: it says so (and whether it was interrupted),
      ! and rank 0 takes every point still on its way.
      if (job%rank /= 0) then
         mine%header = [0, merge(1, 0, interrupted), 0, 0, 0]
         mine%numbers = [real(wp) ::]
         mine%reason = ''
         call send_point(job, outbox, slot, mine)
         do slot = 1, in_flight
            if (outbox(slot)%busy) call MPI_Waitall(3, outbox(slot)%requests, MPI_STATUSES_IGNORE)
         end do
      else
         if (job%parallel()) call receive_points(job, ckpt, batch, names, finished, .true.)
         call write_batch(ckpt, batch, names, .true.)
         if (ckpt%opened) call ckpt%file%close(error)
         if (allocated(error) .and. .not. allocated(ckpt%error)) call move_alloc(error, ckpt%error)
         if (allocated(ckpt%error)) call fatal_error(error, checkpoint_lost(ckpt), error_io)
      end if
      ! (Collective: only once every point is on its way, or a rank waiting
      ! for rank 0 to take its points would wait for ever.)
      if (dynamic) call MPI_Win_free(window)
      flag = merge(1, 0, interrupted)
      if (job%parallel()) call MPI_Allreduce(MPI_IN_PLACE, flag, 1, MPI_INTEGER, MPI_MAX, job%comm)
      interrupted = flag /= 0
      ! One warning for the whole sweep, not one a point: how many points
      ! the scene warned about, and the first one's words.
      if (job%parallel()) then
         call MPI_Allreduce(MPI_IN_PLACE, warned, 1, MPI_INTEGER, MPI_SUM, job%comm)
         call MPI_Allreduce(MPI_IN_PLACE, first_warned, 1, MPI_INTEGER, MPI_MIN, job%comm)
      end if
      if (job%rank == 0 .and. warned > 0) then
         warning = point_warning(config, first_warned)
         call reporter%note('warning: '//itoa(warned)//' of the sweep points computed in this run, the first ' &
            & //'point '//itoa(first_warned)//': '//warning)
      end if

      ! Peak resident memory of every rank, for the benchmark (docs/sweeps.md).
      allocate (memory(job%nranks))
      wall = job_wall_time(job)
      if (job%parallel()) then
         call MPI_Gather(peak_memory_kb(), 1, MPI_INTEGER, memory, 1, MPI_INTEGER, 0, job%comm)
      else
         memory(1) = peak_memory_kb()
      end if
      ! (Component by component: gfortran's structure constructor mis-sizes a
      ! deferred-length component copied from another derived type's.)
      record%input_text = job%input_text
      record%version = version_string
      record%nranks = job%nranks
      record%wall_time = wall
      record%stats = integrator_statistics(0, 0, 0, 0)
      temporary = temporary_name(job)
      counts = 0
      first_reason = ''
      if (job%rank == 0 .and. .not. allocated(error)) call write_sweep_file(temporary, ckpt, config, record, &
         & names, series_name, series_unit, memory, interrupted, job%parallel(), counts, first_reason, error)
      if (job%parallel()) call MPI_Bcast(counts, 3, MPI_INTEGER, 0, job%comm)
      ! A stop request after the last point stopped nothing: the sweep is complete.
      interrupted = interrupted .and. counts(1) + counts(2) < n
      call publish(job, temporary, error)
      if (job%rank == 0 .and. use_todo) call remove_file(todo_path)
      if (allocated(error)) return
      write (seconds, '(f12.2)') wall
      summary = itoa(counts(1) + counts(2))//' of '//itoa(n)//' sweep points done, '//itoa(counts(2)) &
         & //' failed, '//itoa(counts(3))//' computed in this run, '//trim(adjustl(seconds))//' s ' &
         & //ranks_text(job%nranks)
      if (interrupted) then
         call fatal_error(error, 'sweep interrupted; the file marks the points not done as pending ' &
            & //'(status 0): run again with --resume to compute only those', error_interrupted)
         return
      end if
      ! Complete: the checkpoint has served.
      if (job%rank == 0) call remove_file(ckpt%path)
      ! A sweep of which no point succeeded has no result to show: the file
      ! holds every point's reason, and the exit says it failed (rank 0 holds
      ! point 1's reason; its message is the one every rank returns).
      all_failed = n > 0 .and. counts(2) == n
      if (all_failed) then
         if (len(first_reason) > 0) first_reason = ': point 1: '//first_reason
         call fatal_error(error, 'every one of the '//itoa(n)//' sweep points failed; the file holds each ' &
            & //'point''s reason (/sweep/reason)'//first_reason, error_numerical)
         call agree_on_error(job, error)
      end if
   end subroutine run_sweep_job

   !> Point i: a copy of the scene with the swept variables set in memory,
   !> checked as the input is, then run on this process, with what its
   !> earlier points left in `kept` (point_memory).  `results`: the scene's
   !> point results, then the index of the stepper it ran (method_result).
   !> `warning`: the scene's settings_warning for the point ('' for none, or
   !> when its check failed).
   subroutine run_point(config, i, results, series, kept, warning, error)
      type(job_config), intent(in) :: config
      integer, intent(in) :: i
      real(wp), intent(out) :: results(:)
      real(wp), allocatable, intent(out) :: series(:)
      type(point_memory), intent(inout) :: kept
      character(len=:), allocatable, intent(out) :: warning
      type(error_type), allocatable, intent(out) :: error
      class(scene), allocatable :: point

      results = 0.0_wp
      warning = ''
      allocate (series(0))
      call point_scene(config, i, point, error)
      if (allocated(error)) return
      warning = point%settings_warning()
      results(size(results)) = real(step_type_index(point%method()), wp)
      deallocate (series)
      call point%run_point(results(:size(results) - 1), series, kept, error)
   end subroutine run_point

   !> The scene's warning about point i's settings ('' for none or a point
   !> that fails its check).
   function point_warning(config, i) result(text)
      type(job_config), intent(in) :: config
      integer, intent(in) :: i
      character(len=:), allocatable :: text
      class(scene), allocatable :: point
      type(error_type), allocatable :: error

      text = ''
      call point_scene(config, i, point, error)
      if (.not. allocated(error)) text = point%settings_warning()
   end function point_warning

   !> Point i's scene: a copy with the swept variables set in memory,
   !> checked as the input is.
   subroutine point_scene(config, i, point, error)
      type(job_config), intent(in) :: config
      integer, intent(in) :: i
      class(scene), allocatable, intent(out) :: point
      type(error_type), allocatable, intent(out) :: error
      type(config_checker) :: checker
      character(len=:), allocatable :: group, name, problem
      integer :: v

      allocate (point, source=config%scene)
      do v = 1, config%sweep%n_variables
         call split_name(config%sweep%variables(v), group, name)
         call set_parameter_number(point, group, name, config%sweep%point_value(v, i), problem)
         if (len(problem) > 0) then
            call fatal_error(error, 'sweep point '//itoa(i)//': &'//group//': '//name//': '//problem, error_input)
            return
         end if
         call checker%set_origin(group, name, 'sweep point '//itoa(i))
      end do
      call point%check(checker)
      if (checker%failed()) call move_alloc(checker%error, error)
   end subroutine point_scene

   ! ---- a finished point's way to rank 0 ----

   !> Send a finished point (or the end) to rank 0 from the next slot of the
   !> outbox, waiting first for that slot's previous sends to be matched.
   subroutine send_point(job, outbox, slot, point)
      type(job_context), intent(in) :: job
      type(point_message), intent(inout) :: outbox(:)
      integer, intent(inout) :: slot
      type(point_message), intent(in) :: point

      slot = mod(slot, size(outbox)) + 1
      associate (box => outbox(slot))
         if (box%busy) call MPI_Waitall(3, box%requests, MPI_STATUSES_IGNORE)
         box%header = point%header
         box%numbers = point%numbers
         box%reason = point%reason
         box%requests = MPI_REQUEST_NULL
         ! Synchronous sends: done only when rank 0 has taken them, so a rank
         ! has at most size(outbox) points on their way.
         call MPI_Issend(box%header, 5, MPI_INTEGER, 0, tag_header, job%comm, box%requests(1))
         if (box%header(1) > 0) then
            call MPI_Issend(box%numbers, size(box%numbers), MPI_DOUBLE_PRECISION, 0, tag_numbers, job%comm, &
               & box%requests(2))
            if (len(box%reason) > 0) call MPI_Issend(box%reason, len(box%reason), MPI_CHARACTER, 0, tag_reason, &
               & job%comm, box%requests(3))
         end if
         box%busy = .true.
      end associate
   end subroutine send_point

   !> Rank 0: take the points the other ranks have sent; with `wait`, until
   !> every other rank has said it finished.
   subroutine receive_points(job, ckpt, batch, names, finished, wait)
      type(job_context), intent(in) :: job
      type(checkpoint), intent(inout) :: ckpt
      type(point_batch), intent(inout) :: batch
      type(point_result), intent(in) :: names(:)
      integer, intent(inout) :: finished
      logical, intent(in) :: wait
      type(point_message) :: point
      type(MPI_Status) :: status
      logical :: arrived
      integer :: source

      if (.not. job%parallel()) return
      do
         if (wait) then
            if (finished == job%nranks - 1) return
            call MPI_Probe(MPI_ANY_SOURCE, tag_header, job%comm, status)
         else
            call MPI_Iprobe(MPI_ANY_SOURCE, tag_header, job%comm, arrived, status)
            if (.not. arrived) return
         end if
         source = status%MPI_SOURCE
         call MPI_Recv(point%header, 5, MPI_INTEGER, source, tag_header, job%comm, MPI_STATUS_IGNORE)
         if (point%header(1) == 0) then
            finished = finished + 1
            cycle
         end if
         if (allocated(point%numbers)) deallocate (point%numbers)
         allocate (point%numbers(point%header(3) + 1 + point%header(4)))
         call MPI_Recv(point%numbers, size(point%numbers), MPI_DOUBLE_PRECISION, source, tag_numbers, job%comm, &
            & MPI_STATUS_IGNORE)
         if (allocated(point%reason)) deallocate (point%reason)
         allocate (character(len=point%header(5)) :: point%reason)
         if (point%header(5) > 0) call MPI_Recv(point%reason, point%header(5), MPI_CHARACTER, source, tag_reason, &
            & job%comm, MPI_STATUS_IGNORE)
         call add_point(batch, point)
         call write_batch(ckpt, batch, names, .false.)
      end do
   end subroutine receive_points

   ! ---- rank 0's batch and checkpoint ----

   subroutine start_batch(batch, n_results)
      type(point_batch), intent(inout) :: batch
      integer, intent(in) :: n_results

      allocate (batch%point(batch_points), batch%status(batch_points), batch%series_count(batch_points), &
         & batch%reason_length(batch_points), source=0)
      allocate (batch%results(n_results, batch_points), batch%cost(batch_points), source=0.0_wp)
      allocate (batch%series(1024))
      batch%reasons = ''
      batch%since = wall_seconds()
   end subroutine start_batch

   subroutine add_point(batch, point)
      type(point_batch), intent(inout) :: batch
      type(point_message), intent(in) :: point
      real(wp), allocatable :: grown(:)
      integer :: k, m, nres

      k = batch%n + 1
      nres = point%header(3)
      m = point%header(4)
      batch%point(k) = point%header(1)
      batch%status(k) = point%header(2)
      batch%series_count(k) = m
      batch%reason_length(k) = len(point%reason)
      batch%results(:, k) = point%numbers(1:nres)
      batch%cost(k) = point%numbers(nres + 1)
      if (batch%n_series + m > size(batch%series)) then
         allocate (grown(max(2 * size(batch%series), batch%n_series + m)))
         grown(1:batch%n_series) = batch%series(1:batch%n_series)
         call move_alloc(grown, batch%series)
      end if
      batch%series(batch%n_series + 1:batch%n_series + m) = point%numbers(nres + 2:nres + 1 + m)
      batch%n_series = batch%n_series + m
      batch%reasons = batch%reasons//point%reason
      batch%n = k
   end subroutine add_point

   !> Write the batch into the checkpoint (creating it at the first point)
   !> and flush it, when it is full, when it waited long enough, at the
   !> first point of a run, or always with `now`.
   subroutine write_batch(ckpt, batch, names, now)
      type(checkpoint), intent(inout) :: ckpt
      type(point_batch), intent(inout) :: batch
      type(point_result), intent(in) :: names(:)
      logical, intent(in) :: now
      integer, allocatable :: order(:)
      integer(i8), allocatable :: series_offset(:), reason_offset(:), checksum(:)
      integer(i8) :: s, r
      integer :: k, a, b, j, s_in, r_in

      if (batch%n == 0) return
      if (.not. (now .or. batch%n == batch_points .or. batch%n_series >= batch_series .or. ckpt%received == 0 &
         & .or. wall_seconds() - batch%since >= batch_seconds)) return
      ckpt%received = ckpt%received + batch%n
      ! Not on a (nearly) full disk: a write that fails there leaves HDF5
      ! unable to close the file; with room to spare, the checkpoint closes.
      if (.not. allocated(ckpt%error)) then
         if (.not. room_for(ckpt%path, 8.0_wp * (batch%n_series + batch%n * (size(names) + 8)) &
            & + len(batch%reasons))) then
            if (ckpt%opened) call ckpt%file%close(ckpt%error)
            if (.not. allocated(ckpt%error)) call fatal_error(ckpt%error, ckpt%path//': ' &
               & //full_text(ckpt%path, free_bytes(ckpt%path))//')', error_io)
            ckpt%opened = .false.
            call remove_file(ckpt%path)
         else if (.not. ckpt%opened) then
            call create_checkpoint(ckpt, names)
         end if
      end if
      if (allocated(ckpt%error)) then
         batch%n = 0   ! nowhere to keep them: the run fails at its end
         batch%n_series = 0
         batch%reasons = ''
         return
      end if
      ! Each point's place in the flat lists, in the order they came.
      allocate (series_offset(batch%n), reason_offset(batch%n), checksum(batch%n))
      s = ckpt%series_end
      r = ckpt%reason_end
      s_in = 0
      r_in = 0
      do k = 1, batch%n
         series_offset(k) = s
         reason_offset(k) = r
         checksum(k) = point_checksum(batch%status(k), ckpt%run, batch%cost(k), s, batch%series_count(k), r, &
            & batch%reason_length(k), batch%results(:, k), batch%series(s_in + 1:s_in + batch%series_count(k)), &
            & batch%reasons(r_in + 1:r_in + batch%reason_length(k)))
         s = s + batch%series_count(k)
         r = r + batch%reason_length(k)
         s_in = s_in + batch%series_count(k)
         r_in = r_in + batch%reason_length(k)
      end do
      call ckpt%file%put('series', ckpt%series_end, batch%series(1:batch%n_series))
      call ckpt%file%put('reason', ckpt%reason_end, batch%reasons)
      ckpt%series_end = s
      ckpt%reason_end = r
      ! The per-point columns, a run of consecutive points at a time.
      order = sorted_order(batch%point(1:batch%n))
      a = 1
      do while (a <= batch%n)
         b = a
         do while (b < batch%n)
            if (batch%point(order(b + 1)) /= batch%point(order(b)) + 1) exit
            b = b + 1
         end do
         associate (first => int(batch%point(order(a)) - 1, i8), pick => order(a:b))
            call ckpt%file%put('status', first, batch%status(pick))
            call ckpt%file%put('run', first, [(ckpt%run, j = a, b)])
            call ckpt%file%put('compute_time', first, batch%cost(pick))
            call ckpt%file%put('series_offset', first, series_offset(pick))
            call ckpt%file%put('series_count', first, batch%series_count(pick))
            call ckpt%file%put('reason_offset', first, reason_offset(pick))
            call ckpt%file%put('reason_length', first, batch%reason_length(pick))
            call ckpt%file%put('checksum', first, checksum(pick))
            do j = 1, size(names)
               call ckpt%file%put('result'//itoa(j), first, batch%results(j, pick))
            end do
         end associate
         a = b + 1
      end do
      call ckpt%file%flush()
      if (ckpt%file%failed()) call ckpt%file%close(ckpt%error)
      ! A checkpoint that failed a write cannot be trusted: it goes, and the
      ! run fails at its end (checkpoint_lost).
      if (allocated(ckpt%error)) then
         ckpt%opened = .false.
         call remove_file(ckpt%path)
      end if
      batch%n = 0
      batch%n_series = 0
      batch%reasons = ''
      batch%since = wall_seconds()
   end subroutine write_batch

   !> A sweep whose file and checkpoint cannot fit on the output's disk is
   !> refused before computing: the file holds a row for every point, pending
   !> ones too.  (sweep_count = 1e8 with 48 MB free computed for seconds,
   !> filled the disk with pending rows and lost what it had computed.)  Each
   !> point takes 8 bytes a column: the results, the sweep's own columns
   !> (about 8) in the file, and as many in the checkpoint.
   subroutine check_room(job, config, n, n_results, error)
      type(job_context), intent(in) :: job
      type(job_config), intent(in) :: config
      integer, intent(in) :: n, n_results
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: needed, free
      character(len=:), allocatable :: counts

      needed = 8.0_wp * real(n, wp) * (2 * n_results + 16)
      free = free_bytes(job%output)
      if (free < 0.0_wp .or. needed + min_free_bytes <= free) return
      counts = 'sweep_count = '//itoa(config%sweep%shape(1))
      if (config%sweep%n_variables == 2) counts = counts//', sweep_count2 = '//itoa(config%sweep%shape(2))
      call fatal_error(error, '&sweep: '//counts//': '//itoa(n)//' points need about '//bytes_text(needed) &
         & //' on disk for the sweep''s file and its checkpoint, but beside '//job%output//' ' &
         & //full_text(job%output, free)//'): sweep fewer points, or write the output where there is room', &
         & error_input)
   end subroutine check_room

   !> Whether the disk at path has room for `bytes` more and min_free_bytes
   !> to spare (true where it cannot tell).
   logical function room_for(path, bytes)
      character(len=*), intent(in) :: path
      real(wp), intent(in) :: bytes
      real(wp) :: free

      free = free_bytes(path)
      room_for = free < 0.0_wp .or. free >= bytes + min_free_bytes
   end function room_for

   !> Why the run failed when its checkpoint could not be written: a full
   !> disk only when the disk is full (a damaged checkpoint that HDF5 cannot
   !> write into is not one).
   function checkpoint_lost(ckpt) result(message)
      type(checkpoint), intent(in) :: ckpt
      character(len=:), allocatable :: message
      real(wp) :: free
      logical :: full

      message = ckpt%error%message
      free = free_bytes(ckpt%path)
      full = free >= 0.0_wp .and. free < min_free_bytes
      if (full .and. index(message, ' free') == 0 .and. index(message, ' left') == 0) &
         & message = message//' ('//full_text(ckpt%path, free)//')'
      message = message//'; the checkpoint could not be written and was removed (a failed write leaves it ' &
         & //'untrustworthy), and the points of this run are lost with it'
      if (full) then
         message = message//': run again when there is room'
      else
         message = message//' (the disk has room: a damaged checkpoint, or a file-size limit)'
      end if
   end function checkpoint_lost

   !> The permutation that sorts `keys` (a batch: insertion sort, as the
   !> points come nearly in order).
   function sorted_order(keys) result(order)
      integer, intent(in) :: keys(:)
      integer, allocatable :: order(:)
      integer :: k, j, held

      order = [(k, k = 1, size(keys))]
      do k = 2, size(keys)
         held = order(k)
         j = k - 1
         do while (j >= 1)
            if (keys(order(j)) <= keys(held)) exit
            order(j + 1) = order(j)
            j = j - 1
         end do
         order(j + 1) = held
      end do
   end function sorted_order

   !> A new checkpoint: the input's hash, the number of points and results,
   !> its columns (zeros: every point pending) and a reserve of
   !> reserve_bytes.  The reserve is what a full disk gives back: after a
   !> failed write the file is cut to no bytes before it is closed
   !> (h5_table's close), and closing needs room for what HDF5 still holds.
   !> Made under another name and renamed, so it appears whole, reserve and all.
   subroutine create_checkpoint(ckpt, names)
      type(checkpoint), intent(inout) :: ckpt
      type(point_result), intent(in) :: names(:)
      integer, parameter :: reserve_bytes = 1048576
      character(len=:), allocatable :: fresh
      integer :: j
      integer(i8) :: n

      n = ckpt%points
      fresh = ckpt%path//'.new'
      call ckpt%file%create(fresh, ckpt%error)
      if (allocated(ckpt%error)) return
      call ckpt%file%set_text('/', 'input_hash', ckpt%hash)
      call ckpt%file%set_integer('/', 'points', n)
      call ckpt%file%set_integer('/', 'results', int(size(names), i8))
      call ckpt%file%set_integer('/', 'runs', int(ckpt%run, i8))
      do j = 1, len(column_kinds)
         call ckpt%file%add_column(trim(column_names(j)), column_kinds(j:j), n, '')
      end do
      do j = 1, size(names)
         call ckpt%file%add_column('result'//itoa(j), 'r', n, '')
      end do
      call ckpt%file%add_column('series', 'r', -1_i8, '')
      call ckpt%file%add_column('reason', 'b', -1_i8, '')
      call ckpt%file%add_column('reserve', 'b', int(reserve_bytes, i8), '')
      call ckpt%file%put('reserve', 0_i8, repeat(' ', reserve_bytes))
      call ckpt%file%close(ckpt%error)
      if (.not. allocated(ckpt%error)) call rename_file(fresh, ckpt%path, ckpt%error)
      if (allocated(ckpt%error)) then
         call remove_file(fresh)
         return
      end if
      call ckpt%file%open(ckpt%path, ckpt%error)
      ckpt%opened = .not. allocated(ckpt%error)
      if (.not. ckpt%opened) call remove_file(ckpt%path)
   end subroutine create_checkpoint

   !> --resume: open the checkpoint, check it is of this input and whole, and
   !> list the points still to do (pending ones) in the file todo_path.
   subroutine open_checkpoint(ckpt, input_hash, n, n_results, todo_path, n_todo, error)
      type(checkpoint), intent(inout) :: ckpt
      character(len=*), intent(in) :: input_hash, todo_path
      integer, intent(in) :: n, n_results
      integer, intent(out) :: n_todo
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: ignored
      integer, allocatable :: status(:)
      character(len=:), allocatable :: problem
      integer :: unit, stat, first, count, k, j
      logical :: whole

      n_todo = 0
      call ckpt%file%open(ckpt%path, error)
      if (allocated(error)) then
         call fatal_error(error, ckpt%path//': the checkpoint is damaged (it does not open as HDF5); remove it, ' &
            & //'and --resume computes every point again', error_input)
         return
      end if
      if (len(ckpt%file%text('/', 'input_hash')) == 0 .or. ckpt%file%integer('/', 'runs') < 1) then
         call ckpt%file%close(ignored)
         call fatal_error(error, ckpt%path//': the checkpoint is damaged (it lacks its input_hash or runs); ' &
            & //'remove it, and --resume computes every point again', error_input)
         return
      end if
      if (ckpt%file%text('/', 'input_hash') /= input_hash) then
         call ckpt%file%close(ignored)
         call fatal_error(error, ckpt%path//': the checkpoint is of another input; --resume reuses only the ' &
            & //'checkpoint of the same input: run with the input of the interrupted run, or remove ' &
            & //ckpt%path//' to start afresh', error_input)
         return
      end if
      whole = ckpt%file%integer('/', 'points') == n .and. ckpt%file%integer('/', 'results') == n_results &
         & .and. ckpt%file%integer('/', 'runs') >= 1
      do k = 1, len(column_kinds)
         whole = whole .and. ckpt%file%length(trim(column_names(k))) == n
      end do
      do j = 1, n_results
         whole = whole .and. ckpt%file%length('result'//itoa(j)) == n
      end do
      whole = whole .and. ckpt%file%length('series') >= 0 .and. ckpt%file%length('reason') >= 0
      if (.not. whole) then
         call ckpt%file%close(ignored)
         call fatal_error(error, ckpt%path//': the checkpoint is damaged (its columns are not those of this ' &
            & //'sweep); remove it, and --resume computes every point again', error_input)
         return
      end if
      problem = damaged_rows(ckpt, n, n_results)
      if (len(problem) > 0) then
         call ckpt%file%close(ignored)
         call fatal_error(error, ckpt%path//': the checkpoint is damaged ('//problem//'); remove it, and ' &
            & //'--resume computes every point again', error_input)
         return
      end if
      ckpt%opened = .true.
      ckpt%run = int(ckpt%file%integer('/', 'runs')) + 1
      call ckpt%file%set_integer('/', 'runs', int(ckpt%run, i8))
      ckpt%series_end = ckpt%file%length('series')
      ckpt%reason_end = ckpt%file%length('reason')
      open (newunit=unit, file=todo_path, access='stream', form='unformatted', action='write', &
         & status='replace', iostat=stat)
      if (stat /= 0) then
         call fatal_error(error, todo_path//': cannot write the list of points to do', error_io)
         return
      end if
      allocate (status(copy_points))
      do first = 1, n, copy_points
         count = min(copy_points, n - first + 1)
         call ckpt%file%get('status', int(first - 1, i8), status(1:count))
         do k = 1, count
            if (status(k) /= status_pending) cycle
            write (unit, iostat=stat) first + k - 1
            n_todo = n_todo + 1
         end do
      end do
      close (unit)
      if (ckpt%file%failed()) then
         call ckpt%file%close(ignored)
         call fatal_error(error, ckpt%path//': the checkpoint is damaged (its statuses do not read); remove ' &
            & //'it, and --resume computes every point again', error_input)
      end if
   end subroutine open_checkpoint

   !> The checksum of a point's row of the checkpoint: the 64-bit FNV-1a
   !> hash (text_hash_bits) of its numbers' bits as a map's line checkpoints
   !> write them (real_line), and of its reason.  A flipped bit or a changed
   !> value anywhere in the row, its series or its reason changes it.
   function point_checksum(status, run, cost, series_offset, series_count, reason_offset, reason_length, results, &
      & series, reason) result(bits)
      integer, intent(in) :: status, run, series_count, reason_length
      real(wp), intent(in) :: cost, results(:), series(:)
      integer(i8), intent(in) :: series_offset, reason_offset
      character(len=*), intent(in) :: reason
      integer(i8) :: bits

      bits = text_hash_bits(real_line([real(status, wp), real(run, wp), cost, real(series_offset, wp), &
         & real(series_count, wp), real(reason_offset, wp), real(reason_length, wp), results, series])//reason)
   end function point_checksum

   !> --resume: every point's row of the checkpoint against its checksum, a
   !> piece of copy_points points at a time; '' when all agree, else what
   !> is damaged (a status that is none of the three, a row that does not
   !> match its checksum, a row that points outside the flat lists).
   function damaged_rows(ckpt, n, n_results) result(problem)
      type(checkpoint), intent(inout) :: ckpt
      integer, intent(in) :: n, n_results
      character(len=:), allocatable :: problem
      integer, allocatable :: status(:), run(:), series_count(:), reason_length(:)
      integer(i8), allocatable :: series_offset(:), reason_offset(:), checksum(:)
      real(wp), allocatable :: cost(:), results(:, :), series(:)
      character(len=:), allocatable :: reason
      integer(i8) :: series_end, reason_end
      integer :: first, piece, k, j

      problem = ''
      series_end = ckpt%file%length('series')
      reason_end = ckpt%file%length('reason')
      allocate (status(copy_points), run(copy_points), series_count(copy_points), reason_length(copy_points))
      allocate (series_offset(copy_points), reason_offset(copy_points), checksum(copy_points))
      allocate (cost(copy_points), results(copy_points, n_results))
      do first = 1, n, copy_points
         piece = min(copy_points, n - first + 1)
         associate (at => int(first - 1, i8), c => piece)
            call ckpt%file%get('status', at, status(1:c))
            call ckpt%file%get('run', at, run(1:c))
            call ckpt%file%get('compute_time', at, cost(1:c))
            call ckpt%file%get('series_offset', at, series_offset(1:c))
            call ckpt%file%get('series_count', at, series_count(1:c))
            call ckpt%file%get('reason_offset', at, reason_offset(1:c))
            call ckpt%file%get('reason_length', at, reason_length(1:c))
            call ckpt%file%get('checksum', at, checksum(1:c))
            do j = 1, n_results
               call ckpt%file%get('result'//itoa(j), at, results(1:c, j))
            end do
         end associate
         if (ckpt%file%failed()) then
            problem = 'its columns do not read'
            return
         end if
         do k = 1, piece
            if (status(k) == status_pending) cycle
            if (status(k) /= status_done .and. status(k) /= status_failed) then
               problem = 'point '//itoa(first + k - 1)//' has the status '//itoa(status(k))//', none of 0, 1, 2'
               return
            end if
            if (series_count(k) < 0 .or. reason_length(k) < 0 .or. series_offset(k) < 0 .or. reason_offset(k) < 0 &
               & .or. series_offset(k) + series_count(k) > series_end &
               & .or. reason_offset(k) + reason_length(k) > reason_end) then
               problem = 'point '//itoa(first + k - 1)//' points outside its series or reasons'
               return
            end if
            allocate (series(series_count(k)))
            allocate (character(len=reason_length(k)) :: reason)
            if (series_count(k) > 0) call ckpt%file%get('series', series_offset(k), series)
            if (reason_length(k) > 0) call ckpt%file%get('reason', reason_offset(k), reason)
            if (point_checksum(status(k), run(k), cost(k), series_offset(k), series_count(k), reason_offset(k), &
               & reason_length(k), results(k, :), series, reason) /= checksum(k) .or. ckpt%file%failed()) then
               problem = 'point '//itoa(first + k - 1)//'''s values do not match their checksum'
               return
            end if
            deallocate (series, reason)
         end do
      end do
   end function damaged_rows

   !> The checkpoint's per-point columns besides the results.
   pure function column_names(k) result(name)
      integer, intent(in) :: k
      character(len=16) :: name
      character(len=16), parameter :: names(8) = [character(len=16) :: 'status', 'run', 'compute_time', &
         & 'series_offset', 'series_count', 'reason_offset', 'reason_length', 'checksum']

      name = names(k)
   end function column_names

   ! ---- the output ----

   !> The sweep file, written by rank 0 alone from the checkpoint: the run's
   !> attributes first, then every column, a piece of copy_points points at
   !> a time in point order.  counts = points done, failed, computed in this
   !> run; first_reason = point 1's reason.
   subroutine write_sweep_file(path, ckpt, config, record, names, series_name, series_unit, memory, &
      & interrupted, parallel, counts, first_reason, error)
      character(len=*), intent(in) :: path
      type(checkpoint), intent(inout) :: ckpt
      type(job_config), intent(in) :: config
      type(run_summary), intent(in) :: record
      type(point_result), intent(in) :: names(:)
      character(len=*), intent(in) :: series_name, series_unit
      integer, intent(in) :: memory(:)
      logical, intent(in) :: interrupted
      logical, intent(in) :: parallel   !! on MPI (rank 0 writes through MPI_COMM_SELF), else serial
      integer, intent(out) :: counts(3)
      character(len=:), allocatable, intent(out) :: first_reason
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: ignored
      type(h5_file) :: file
      type(h5_table) :: out
      character(len=:), allocatable :: name, texts(:)
      character(len=step_type_name_length), allocatable :: steppers(:)
      character(len=:), allocatable :: stepper(:)   !! as wide as the column (the memory type is the file's)
      integer, allocatable :: status(:), run(:), series_count(:), reason_length(:), whole(:)
      integer(i8), allocatable :: series_offset(:), reason_offset(:), out_offset(:)
      real(wp), allocatable :: cost(:), values(:), results(:), series(:)
      integer(i8) :: total, written
      integer :: n, k, j, first, piece, longest, a, b
      logical :: have

      n = config%sweep%points()
      counts = 0
      first_reason = ''
      ! The run's attributes and the small datasets, through the program's
      ! one file type; then the columns, streamed.
      call file%create(path, merge(MPI_COMM_SELF, MPI_COMM_NULL, parallel), error)
      if (allocated(error)) return
      call write_run_attributes(file, 'sweep', config%scene%method(), record)
      call file%write_attribute_text('/', 'sweep_scene', trim(config%scene_name))
      call file%write_attribute_text('/', 'sweep_variable', trim(config%sweep%variables(1)))
      if (config%sweep%n_variables == 2) &
         & call file%write_attribute_text('/', 'sweep_variable2', trim(config%sweep%variables(2)))
      call file%write_attribute_text('/', 'sweep_schedule', trim(config%sweep%schedule))
      call file%create_group('/sweep')
      call file%write_attribute_integer('/sweep', 'shape', int(config%sweep%shape(1), i8))
      call file%write_attribute_integer('/sweep', 'shape2', int(config%sweep%shape(2), i8))
      call file%write_integer_vector('/sweep/peak_memory_per_rank', memory)
      call file%write_attribute_text('/sweep/peak_memory_per_rank', 'units', 'kB (VmHWM; 0: unknown)')
      call file%close(error)
      if (allocated(error)) return

      have = file_exists(ckpt%path)
      if (have) then
         call ckpt%file%open(ckpt%path, error)
         if (allocated(error)) return
      end if
      call out%open(path, error)
      if (allocated(error)) then
         if (have) call ckpt%file%close(ignored)
         return
      end if
      allocate (status(copy_points), run(copy_points), series_count(copy_points), reason_length(copy_points), &
         & whole(copy_points), source=0)
      allocate (series_offset(copy_points), reason_offset(copy_points), out_offset(copy_points), source=0_i8)
      allocate (cost(copy_points), values(copy_points), results(copy_points), source=0.0_wp)
      steppers = step_type_names()
      allocate (character(len=maxval(len_trim(steppers))) :: stepper(copy_points))
      ! First pass: the length of the flat series and of the longest reason.
      total = 0
      longest = 1
      if (have) then
         do first = 1, n, copy_points
            piece = min(copy_points, n - first + 1)
            call ckpt%file%get('series_count', int(first - 1, i8), series_count(1:piece))
            call ckpt%file%get('reason_length', int(first - 1, i8), reason_length(1:piece))
            total = total + sum(int(series_count(1:piece), i8))
            longest = max(longest, maxval(reason_length(1:piece)))
         end do
      end if
      do k = 1, config%sweep%n_variables
         name = merge('sweep/values ', 'sweep/values2', k == 1)
         call out%add_column(trim(name), 'r', int(n, i8), variable_unit(k))
         call out%set_text(trim(name), 'variable', trim(config%sweep%variables(k)))
      end do
      do j = 1, size(names)
         if (names(j)%name == method_result) then
            call out%add_text_column('sweep/'//method_result, len(stepper), int(n, i8))
            call out%set_text('sweep/'//method_result, 'meaning', 'the stepper the point ran (method = ''auto'' ' &
               & //'resolved for its own values); empty for a point that failed its check or is pending')
         else
            call out%add_column('sweep/'//trim(names(j)%name), merge('i', 'r', names(j)%whole), int(n, i8), &
               & trim(names(j)%unit))
         end if
      end do
      if (len(series_name) > 0) then
         call out%add_column('sweep/'//series_name, 'r', total, series_unit)
         call out%add_column('sweep/'//series_name//'_offset', 'l', int(n, i8), '')
         call out%add_column('sweep/'//series_name//'_count', 'i', int(n, i8), '')
      end if
      call out%add_column('sweep/status', 'i', int(n, i8), '')
      call out%set_text('sweep/status', 'meaning', '0 pending, 1 done, 2 failed')
      call out%add_text_column('sweep/reason', longest, int(n, i8))
      call out%set_text('sweep/reason', 'meaning', 'a failed point''s error message (empty otherwise)')
      call out%add_column('sweep/compute_time', 'r', int(n, i8), 's')
      call out%add_column('sweep/computed_by_this_run', 'i', int(n, i8), '')
      allocate (character(len=longest) :: texts(copy_points))

      ! Second pass: every column, a piece at a time, in point order.
      written = 0
      do first = 1, n, copy_points
         piece = min(copy_points, n - first + 1)
         associate (at => int(first - 1, i8), c => piece)
            status(1:c) = status_pending
            run(1:c) = 0
            cost(1:c) = 0.0_wp
            series_count(1:c) = 0
            reason_length(1:c) = 0
            if (have) then
               call ckpt%file%get('status', at, status(1:c))
               call ckpt%file%get('run', at, run(1:c))
               call ckpt%file%get('compute_time', at, cost(1:c))
               call ckpt%file%get('series_offset', at, series_offset(1:c))
               call ckpt%file%get('series_count', at, series_count(1:c))
               call ckpt%file%get('reason_offset', at, reason_offset(1:c))
               call ckpt%file%get('reason_length', at, reason_length(1:c))
            end if
            do k = 1, config%sweep%n_variables
               do j = 1, c
                  values(j) = config%sweep%point_value(k, first + j - 1)
               end do
               name = merge('sweep/values ', 'sweep/values2', k == 1)
               call out%put(trim(name), at, values(1:c))
            end do
            do j = 1, size(names)
               results(1:c) = 0.0_wp
               if (have) call ckpt%file%get('result'//itoa(j), at, results(1:c))
               if (names(j)%name == method_result) then
                  do k = 1, c
                     stepper(k) = ''
                     if (nint(results(k)) >= 1 .and. nint(results(k)) <= size(steppers)) &
                        & stepper(k) = steppers(nint(results(k)))
                  end do
                  call out%put('sweep/'//method_result, at, stepper(1:c))
               else if (names(j)%whole) then
                  whole(1:c) = nint(results(1:c))
                  call out%put('sweep/'//trim(names(j)%name), at, whole(1:c))
               else
                  call out%put('sweep/'//trim(names(j)%name), at, results(1:c))
               end if
            end do
            ! The series of the piece, read a run of adjacent ones at a time.
            if (len(series_name) > 0) then
               allocate (series(sum(series_count(1:c))))
               b = 0
               a = 1
               do while (a <= c)
                  j = a
                  do while (j < c)
                     if (series_offset(j + 1) /= series_offset(j) + series_count(j)) exit
                     j = j + 1
                  end do
                  k = sum(series_count(a:j))
                  if (k > 0) call ckpt%file%get('series', series_offset(a), series(b + 1:b + k))
                  b = b + k
                  a = j + 1
               end do
               do j = 1, c
                  out_offset(j) = written
                  written = written + series_count(j)
               end do
               call out%put('sweep/'//series_name, out_offset(1), series)
               call out%put('sweep/'//series_name//'_offset', at, out_offset(1:c))
               call out%put('sweep/'//series_name//'_count', at, series_count(1:c))
               deallocate (series)
            end if
            do j = 1, c
               texts(j) = ''
               if (reason_length(j) > 0) call ckpt%file%get('reason', reason_offset(j), texts(j)(1:reason_length(j)))
            end do
            if (first == 1) first_reason = trim(texts(1))
            call out%put('sweep/status', at, status(1:c))
            call out%put('sweep/reason', at, texts(1:c))
            call out%put('sweep/compute_time', at, cost(1:c))
            whole(1:c) = merge(1, 0, run(1:c) == ckpt%run .and. status(1:c) /= status_pending)
            call out%put('sweep/computed_by_this_run', at, whole(1:c))
            counts(1) = counts(1) + count(status(1:c) == status_done)
            counts(2) = counts(2) + count(status(1:c) == status_failed)
            counts(3) = counts(3) + sum(whole(1:c))
         end associate
      end do
      call out%set_integer('sweep', 'complete', int(merge(0, 1, interrupted .and. counts(1) + counts(2) < n), i8))
      if (have) then
         call ckpt%file%close(error)
         if (allocated(error)) then
            call out%close(ignored)
            return
         end if
      end if
      call out%close(error)

   contains

      !> The unit of swept variable k, as its configuration declares it.
      function variable_unit(k) result(unit)
         integer, intent(in) :: k
         character(len=:), allocatable :: unit
         type(parameter_info), allocatable :: list(:)
         character(len=:), allocatable :: group, variable
         class(scene), allocatable :: copy
         integer :: m

         unit = '1'
         allocate (copy, source=config%scene)
         list = list_parameters(copy)
         call split_name(config%sweep%variables(k), group, variable)
         do m = 1, size(list)
            if (list(m)%group == group .and. list(m)%name == variable .and. len_trim(list(m)%unit) > 0) &
               & unit = trim(list(m)%unit)
         end do
      end function variable_unit

   end subroutine write_sweep_file

   !> This process's peak resident set (VmHWM of /proc/self/status) in kB;
   !> 0 where there is no such file.
   integer function peak_memory_kb() result(kb)
      integer :: unit, stat
      character(len=256) :: line

      kb = 0
      open (newunit=unit, file='/proc/self/status', status='old', action='read', iostat=stat)
      if (stat /= 0) return
      do
         read (unit, '(a)', iostat=stat) line
         if (stat /= 0) exit
         if (line(1:6) == 'VmHWM:') then
            read (line(7:), *, iostat=stat) kb
            if (stat /= 0) kb = 0
            exit
         end if
      end do
      close (unit)
   end function peak_memory_kb

end module friction_job_sweep
