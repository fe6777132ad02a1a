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
!> Output: one rank-0 writer after reductions.  A point's results are a few
!> numbers and a few hundred maxima (kB), so the gathered data are small and
!> parallel HDF5's collective metadata would buy nothing.  A rank holds one
!> point's trajectory or map at a time and n numbers per result: its memory
!> does not grow with the points other ranks hold.
module friction_job_sweep
   use, intrinsic :: iso_c_binding, only: c_ptr, c_f_pointer
   use mpi_f08
   use friction_kinds, only: wp, i8
   use friction_clock, only: wall_seconds
   use friction_error, only: error_type, fatal_error, error_interrupted, error_input, error_numerical
   use friction_strings, only: itoa, text_hash
   use friction_output_checkpoint, only: save_checkpoint, checkpoint_body, real_line, next_line
   use friction_version, only: version_string
   use friction_ode_solver, only: integrator_statistics
   use friction_parameters, only: set_parameter_number, split_name, parameter_info, list_parameters
   use friction_checks, only: config_checker
   use friction_scene, only: scene, point_result
   use friction_job_config, only: job_config
   use friction_output_h5, only: h5_file
   use friction_output_summary, only: run_summary, write_run_attributes
   use friction_files, only: remove_file
   use friction_scene_report, only: job_reporter
   use friction_scene_context, only: job_context, temporary_name, publish, ranks_text, sum_to_root_real, &
      & sum_to_root_integer, agree_on_error, job_wall_time
   implicit none
   private

   public :: run_sweep_job

   !> A failed point's reason ('' for the others).
   type :: reason_text
      character(len=:), allocatable :: text
   end type reason_text

   integer, parameter :: status_done = 1, status_failed = 2

contains

   !> Run the sweep of `config`; a stop request or the stop_after hook of the
   !> job's options ends it early (the file then marks the points not done as
   !> pending and the error says so, with stat error_interrupted).
   subroutine run_sweep_job(job, config, reporter, summary, error)
      type(job_context), intent(in) :: job
      type(job_config), intent(in) :: config
      class(job_reporter), intent(inout) :: reporter
      character(len=:), allocatable, intent(out) :: summary
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: point_error
      character(len=:), allocatable :: temporary, series_name, series_unit, reason
      type(point_result), allocatable :: names(:)
      type(reason_text), allocatable :: reasons(:)
      type(error_type), allocatable :: checkpoint_error
      character(len=:), allocatable :: input_hash, problem
      integer :: unsaved, last_taken
      logical :: all_failed
      real(wp), allocatable :: results(:, :), cost(:), maxima(:), point_maxima(:), flat(:)
      integer, allocatable :: status(:), counts(:), offsets(:), owner(:), computed_by_run(:)
      integer, allocatable :: memory(:)
      integer :: n, i, k, next, total, computed, flag
      integer(kind=MPI_ADDRESS_KIND) :: window_size
      integer :: one(1), fetched(1), block_first, block_last
      type(c_ptr) :: counter_base
      integer, pointer :: counter_value
      type(MPI_Win) :: window
      type(run_summary) :: record
      real(wp) :: wall, t0
      character(len=12) :: seconds
      logical :: dynamic, interrupted, loaded

      names = config%scene%point_results()
      call config%scene%point_series(series_name, series_unit)
      n = size(config%sweep%values, 2)
      input_hash = text_hash(job%input_text)
      ! --resume: every checkpoint there is must be of this very input and
      ! whole, or nothing is computed (README: Parameter sweeps).
      if (job%resume) then
         if (job%rank == 0) then
            do i = 1, n
               problem = checkpoint_problem(checkpoint_name(job, i), input_hash, config%sweep%values(:, i))
               if (len(problem) > 0) then
                  if (index(problem, 'another input') > 0 .or. index(problem, 'other values') > 0) then
                     problem = problem//'; --resume reuses only the checkpoints of the same input: run with ' &
                        & //'the input of the interrupted run, or remove '//job%output//'.point-*.ckpt to start afresh'
                  else
                     problem = problem//'; remove it, and --resume computes that point again'
                  end if
                  call fatal_error(error, problem, error_input)
                  exit
               end if
            end do
         end if
         call agree_on_error(job, error)
         if (allocated(error)) return
      end if
      unsaved = 0
      allocate (results(size(names), n), cost(n), source=0.0_wp)
      allocate (status(n), counts(n), owner(n), computed_by_run(n), source=0)
      allocate (reasons(n))
      allocate (maxima(0))

      one = 1
      window_size = merge(4, 0, job%rank == 0)
      ! (One rank needs no counter; Open MPI may have no one-sided component for it.)
      dynamic = config%sweep%schedule == 'dynamic' .and. job%nranks > 1
      ! MPI_Win_allocate (not MPI_Win_create on a Fortran variable) lets Open MPI
      ! pick its shared-memory one-sided component on a node: the fetch is an
      ! atomic in memory and needs no progress from rank 0, which is busy
      ! computing.  (Measured: with MPI_Win_create a fetch waited for rank 0 to
      ! finish its point, and the dynamic schedule lost to the static one.)
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
      block_first = int(int(n, i8) * job%rank / job%nranks)
      block_last = int(int(n, i8) * (job%rank + 1) / job%nranks)
      computed = 0
      interrupted = .false.
      last_taken = 0
      do
         ! Between points: a stop request ends the sweep here, the point in hand done.
         ! (The test hook likewise, once this rank has done point stop_after:
         ! with stop_after = n, a stop request after the last point.)
         if (reporter%stop_requested() .or. (job%stop_after > 0 .and. last_taken >= job%stop_after)) then
            interrupted = .true.
            exit
         end if
         if (.not. dynamic) then
            ! The naive static split, for the benchmark: contiguous blocks of
            ! points, so a run of expensive neighbours lands on one rank.
            next = block_first + computed
            if (next >= block_last) next = n
         else
            call MPI_Win_lock(MPI_LOCK_EXCLUSIVE, 0, 0, window)
            call MPI_Fetch_and_op(one, fetched, MPI_INTEGER, 0, 0_MPI_ADDRESS_KIND, MPI_SUM, window)
            call MPI_Win_unlock(0, window)
            next = fetched(1)
         end if
         i = next + 1
         if (i > n) exit
         last_taken = i
         if (job%stop_after > 0 .and. i > job%stop_after) then
            interrupted = .true.   ! the test hook: as if a signal came after that point
            exit
         end if
         computed = computed + 1
         owner(i) = job%rank + 1
         if (job%resume) then
            call load_point(checkpoint_name(job, i), input_hash, config%sweep%values(:, i), status(i), results(:, i), &
               & cost(i), reason, point_maxima, loaded)
            if (loaded) then
               counts(i) = size(point_maxima)
               maxima = [maxima, point_maxima]
               reasons(i)%text = reason
               cycle
            end if
         end if
         computed_by_run(i) = 1
         t0 = wall_seconds()
         call run_point(config, i, results(:, i), point_maxima, point_error)
         if (allocated(point_error)) then
            status(i) = status_failed
            reasons(i)%text = point_error%message
            results(:, i) = 0.0_wp
            if (allocated(point_maxima)) deallocate (point_maxima)
            allocate (point_maxima(0))
         else
            status(i) = status_done
            reasons(i)%text = ''
         end if
         counts(i) = size(point_maxima)
         maxima = [maxima, point_maxima]
         cost(i) = wall_seconds() - t0
         call save_point(checkpoint_name(job, i), input_hash, config%sweep%values(:, i), status(i), results(:, i), &
            & cost(i), reasons(i)%text, point_maxima, problem)
         if (len(problem) > 0) then
            unsaved = unsaved + 1
            if (.not. allocated(checkpoint_error)) call fatal_error(checkpoint_error, problem)
         end if
         deallocate (point_maxima)
         if (allocated(point_error)) deallocate (point_error)
         if (job%rank == 0) call reporter%progress(real(i, wp), real(n, wp), 'points', .false.)
      end do
      if (dynamic) call MPI_Win_free(window)
      ! Checkpoints that could not be written: the points are in memory and go
      ! into the file, but an interrupted run would compute them again.
      if (job%parallel()) call MPI_Allreduce(MPI_IN_PLACE, unsaved, 1, MPI_INTEGER, MPI_SUM, job%comm)
      call agree_on_error(job, checkpoint_error)
      if (unsaved > 0 .and. job%rank == 0) call reporter%note('warning: '//itoa(unsaved) &
         & //' checkpoint(s) could not be written, so --resume would compute those points again; first: ' &
         & //checkpoint_error%message)

      ! Each point has exactly one owner; the others hold zeros, so a sum gathers it exactly.
      if (job%parallel()) call MPI_Allreduce(MPI_IN_PLACE, counts, n, MPI_INTEGER, MPI_SUM, job%comm)
      allocate (offsets(n))
      total = 0
      do i = 1, n
         offsets(i) = total
         total = total + counts(i)
      end do
      allocate (flat(total), source=0.0_wp)
      k = 0
      do i = 1, n
         if (owner(i) == 0) cycle
         flat(offsets(i) + 1:offsets(i) + counts(i)) = maxima(k + 1:k + counts(i))
         k = k + counts(i)
      end do
      call sum_to_root_real(job, flat)
      do k = 1, size(names)
         call sum_to_root_real(job, results(k, :))
      end do
      call sum_to_root_real(job, cost)
      call sum_to_root_integer(job, status, n)
      call gather_reasons(job, owner, reasons)
      call sum_to_root_integer(job, owner, n)
      call sum_to_root_integer(job, computed_by_run, n)
      flag = merge(1, 0, interrupted)
      if (job%parallel()) call MPI_Allreduce(MPI_IN_PLACE, flag, 1, MPI_INTEGER, MPI_MAX, job%comm)
      ! A stop request after the last point stopped nothing: the sweep is complete.
      if (job%rank == 0 .and. flag /= 0 .and. all(status /= 0)) flag = 0
      if (job%parallel()) call MPI_Bcast(flag, 1, MPI_INTEGER, 0, job%comm)
      interrupted = flag /= 0

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
      if (job%rank == 0) call write_sweep_file(temporary, config, record, names, series_name, series_unit, &
         & results, flat, offsets, counts, status, reasons, cost, computed_by_run, memory, interrupted, &
         & job%parallel(), error)
      call publish(job, temporary, error)
      if (allocated(error)) return
      write (seconds, '(f12.2)') wall
      summary = itoa(count(status /= 0))//' of '//itoa(n)//' sweep points done, ' &
         & //itoa(count(status == status_failed))//' failed, '//itoa(sum(computed_by_run)) &
         & //' computed in this run, '//trim(adjustl(seconds))//' s '//ranks_text(job%nranks)
      if (interrupted) then
         call fatal_error(error, 'sweep interrupted; the file marks the points not done as pending ' &
            & //'(status 0): run again with --resume to compute only those', error_interrupted)
         return
      end if
      ! Complete: the checkpoints have served.
      if (job%rank == 0) then
         do i = 1, n
            call remove_file(checkpoint_name(job, i))
         end do
      end if
      ! A sweep of which no point succeeded has no result to show: the file
      ! holds every point's reason, and the exit says it failed (rank 0 holds
      ! the reasons; its message is the one every rank returns).
      all_failed = n > 0 .and. count(status == status_failed) == n   ! (rank 0 holds the statuses)
      if (job%parallel()) call MPI_Bcast(all_failed, 1, MPI_LOGICAL, 0, job%comm)
      if (all_failed) then
         reason = ''
         if (job%rank == 0 .and. allocated(reasons(1)%text)) reason = ': point 1: '//reasons(1)%text
         call fatal_error(error, 'every one of the '//itoa(n)//' sweep points failed; the file holds each ' &
            & //'point''s reason (/sweep/reason)'//reason, error_numerical)
         call agree_on_error(job, error)
      end if
   end subroutine run_sweep_job

   !> Point i: a copy of the scene with the swept variables set in memory,
   !> checked as the input is, then run on this process.
   subroutine run_point(config, i, results, series, error)
      type(job_config), intent(in) :: config
      integer, intent(in) :: i
      real(wp), intent(out) :: results(:)
      real(wp), allocatable, intent(out) :: series(:)
      type(error_type), allocatable, intent(out) :: error
      class(scene), allocatable :: point
      type(config_checker) :: checker
      character(len=:), allocatable :: group, name, problem
      integer :: v

      results = 0.0_wp
      allocate (series(0))
      allocate (point, source=config%scene)
      do v = 1, config%sweep%n_variables
         call split_name(config%sweep%variables(v), group, name)
         call set_parameter_number(point, group, name, config%sweep%values(v, i), problem)
         if (len(problem) > 0) then
            call fatal_error(error, 'sweep point '//itoa(i)//': &'//group//': '//name//': '//problem, error_input)
            return
         end if
         call checker%set_origin(group, name, 'sweep point '//itoa(i))
      end do
      call point%check(checker)
      if (checker%failed()) then
         call move_alloc(checker%error, error)
         return
      end if
      deallocate (series)
      call point%run_point(results, series, error)
   end subroutine run_point

   !> Every failed point's reason to rank 0, as text: each rank sends the
   !> reasons of the points it owns, in order.
   subroutine gather_reasons(job, owner, reasons)
      type(job_context), intent(in) :: job
      integer, intent(in) :: owner(:)
      type(reason_text), intent(inout) :: reasons(:)
      integer, allocatable :: lengths(:), sizes(:), displacements(:), owners(:)
      character(len=:), allocatable :: mine, all
      integer :: i, r, at, total

      if (.not. job%parallel()) return   ! serial: this process holds every reason
      allocate (lengths(size(owner)), source=0)
      mine = ''
      do i = 1, size(owner)
         if (owner(i) /= job%rank + 1) cycle
         if (.not. allocated(reasons(i)%text)) reasons(i)%text = ''
         lengths(i) = len(reasons(i)%text)
         mine = mine//reasons(i)%text
      end do
      allocate (sizes(job%nranks), displacements(job%nranks))
      call MPI_Gather(len(mine), 1, MPI_INTEGER, sizes, 1, MPI_INTEGER, 0, job%comm)
      call sum_to_root_integer(job, lengths, size(lengths))
      owners = owner
      call sum_to_root_integer(job, owners, size(owners))
      total = 0
      if (job%rank == 0) then
         do r = 1, job%nranks
            displacements(r) = total
            total = total + sizes(r)
         end do
      end if
      allocate (character(len=max(1, total)) :: all)
      call MPI_Gatherv(mine, len(mine), MPI_CHARACTER, all, sizes, displacements, MPI_CHARACTER, 0, job%comm)
      if (job%rank /= 0) return
      ! Walk the ranks' texts in rank order, each its own points in order.
      do r = 1, job%nranks
         at = displacements(r)
         do i = 1, size(owners)
            if (owners(i) /= r) cycle
            reasons(i)%text = all(at + 1:at + lengths(i))
            at = at + lengths(i)
         end do
      end do
   end subroutine gather_reasons

   !> The sweep file, written by rank 0 alone.
   subroutine write_sweep_file(path, config, record, names, series_name, series_unit, results, flat, offsets, &
      & counts, status, reasons, cost, computed_by_run, memory, interrupted, parallel, error)
      character(len=*), intent(in) :: path
      type(job_config), intent(in) :: config
      type(run_summary), intent(in) :: record
      type(point_result), intent(in) :: names(:)
      character(len=*), intent(in) :: series_name, series_unit
      real(wp), intent(in) :: results(:, :), flat(:), cost(:)
      integer, intent(in) :: offsets(:), counts(:), status(:), computed_by_run(:), memory(:)
      type(reason_text), intent(in) :: reasons(:)
      logical, intent(in) :: interrupted
      logical, intent(in) :: parallel   !! on MPI (rank 0 writes through MPI_COMM_SELF), else serial
      type(error_type), allocatable, intent(out) :: error
      type(h5_file) :: file
      character(len=:), allocatable :: name, lines(:)
      integer :: i, k, longest

      longest = 1
      do i = 1, size(status)
         if (allocated(reasons(i)%text)) longest = max(longest, len(reasons(i)%text))
      end do
      allocate (character(len=longest) :: lines(size(status)))
      do i = 1, size(status)
         lines(i) = ''
         if (allocated(reasons(i)%text)) lines(i) = reasons(i)%text
      end do
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
      do k = 1, config%sweep%n_variables
         name = '/sweep/values'
         if (k == 2) name = '/sweep/values2'
         call file%write_vector(name, config%sweep%values(k, :), variable_unit(k))
         call file%write_attribute_text(name, 'variable', trim(config%sweep%variables(k)))
      end do
      do k = 1, size(names)
         if (names(k)%whole) then
            call file%write_integer_vector('/sweep/'//trim(names(k)%name), nint(results(k, :)))
         else
            call file%write_vector('/sweep/'//trim(names(k)%name), results(k, :), trim(names(k)%unit))
         end if
      end do
      if (len(series_name) > 0) then
         call file%write_vector('/sweep/'//series_name, flat, series_unit)
         call file%write_integer_vector('/sweep/'//series_name//'_offset', offsets)
         call file%write_integer_vector('/sweep/'//series_name//'_count', counts)
      end if
      call file%write_integer_vector('/sweep/status', status)
      call file%write_attribute_text('/sweep/status', 'meaning', '0 pending, 1 done, 2 failed')
      call file%write_text_vector('/sweep/reason', lines)
      call file%write_attribute_text('/sweep/reason', 'meaning', 'a failed point''s error message (empty otherwise)')
      call file%write_vector('/sweep/compute_time', cost, 's')
      call file%write_integer_vector('/sweep/computed_by_this_run', computed_by_run)
      call file%write_integer_vector('/sweep/peak_memory_per_rank', memory)
      call file%write_attribute_text('/sweep/peak_memory_per_rank', 'units', 'kB (VmHWM; 0: unknown)')
      call file%write_attribute_integer('/sweep', 'complete', int(merge(0, 1, interrupted), i8))
      call file%close(error)

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

   !> A finished point's checkpoint (output/checkpoint.f90): its swept
   !> values, status, results, cost, reason and maxima.  `problem` says why
   !> it could not be written ('' when written).
   subroutine save_point(path, input_hash, values, status, results, cost, reason, maxima, problem)
      character(len=*), intent(in) :: path, input_hash, reason
      real(wp), intent(in) :: values(:), results(:), cost, maxima(:)
      integer, intent(in) :: status
      character(len=:), allocatable, intent(out) :: problem
      character(len=:), allocatable :: text, one_line
      integer :: k

      ! The reason on one line.
      one_line = trim(reason)
      do k = 1, len(one_line)
         if (one_line(k:k) == new_line('a') .or. one_line(k:k) == achar(13)) one_line(k:k) = ' '
      end do
      text = real_line(values)//itoa(status)//' '//itoa(size(results))//' '//itoa(size(maxima))//new_line('a') &
         & //real_line([results, cost])//one_line//new_line('a')
      do k = 1, size(maxima)
         text = text//real_line(maxima(k:k))
      end do
      call save_checkpoint(path, input_hash, text, problem)
   end subroutine save_point

   !> Why the checkpoint at `path` cannot serve this run ('' when it can, or
   !> when there is none): written for another input, damaged, or for other
   !> values of the swept variables.
   function checkpoint_problem(path, input_hash, values) result(problem)
      character(len=*), intent(in) :: path, input_hash
      real(wp), intent(in) :: values(:)
      character(len=:), allocatable :: problem
      character(len=:), allocatable :: body
      real(wp) :: saved(size(values))
      integer :: stat

      call checkpoint_body(path, input_hash, body, problem)
      if (len(problem) > 0 .or. .not. allocated(body)) return
      read (body, *, iostat=stat) saved
      if (stat /= 0) then
         problem = path//': the checkpoint is damaged (its values do not read)'
      else if (.not. all(saved == values)) then
         problem = path//': the checkpoint is for other values of the swept variables'
      end if
   end function checkpoint_problem

   !> A point's checkpoint, if there is a whole one for the same input and
   !> values (checkpoint_problem finds none).
   subroutine load_point(path, input_hash, values, status, results, cost, reason, maxima, loaded)
      character(len=*), intent(in) :: path, input_hash
      real(wp), intent(in) :: values(:)
      integer, intent(inout) :: status
      real(wp), intent(inout) :: results(:), cost
      character(len=:), allocatable, intent(out) :: reason
      real(wp), allocatable, intent(out) :: maxima(:)
      logical, intent(out) :: loaded
      real(wp) :: numbers(size(results) + 1)
      character(len=:), allocatable :: body, problem, line
      integer :: stat, found(3), at

      loaded = .false.
      reason = ''
      if (len(checkpoint_problem(path, input_hash, values)) > 0) return
      call checkpoint_body(path, input_hash, body, problem)
      if (.not. allocated(body)) return
      ! Lines: values, counts, results and cost, reason, then maxima.
      at = 1
      line = next_line(body, at)   ! (the values, checked above)
      line = next_line(body, at)
      read (line, *, iostat=stat) found
      if (stat /= 0 .or. found(2) /= size(results) .or. found(3) < 0) return
      line = next_line(body, at)
      read (line, *, iostat=stat) numbers
      if (stat /= 0) return
      reason = next_line(body, at)
      allocate (maxima(found(3)))
      if (found(3) > 0) then
         read (body(at:), *, iostat=stat) maxima
         if (stat /= 0) return
      end if
      status = found(1)
      results = numbers(1:size(results))
      cost = numbers(size(results) + 1)
      loaded = .true.
   end subroutine load_point

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

   !> Where point i's checkpoint lives: beside the output.
   function checkpoint_name(job, i) result(name)
      type(job_context), intent(in) :: job
      integer, intent(in) :: i
      character(len=:), allocatable :: name

      name = job%output//'.point-'//itoa(i)//'.ckpt'
   end function checkpoint_name

end module friction_job_sweep
