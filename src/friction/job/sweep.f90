!> Parameter sweeps over the MPI ranks (README: Parameter sweeps).  Each
!> point is the scene re-read from the input files plus a one-line override
!> file, so read_input validates it; an invalid or failing point is recorded
!> as failed with its reason and the sweep goes on.
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
   use friction_error, only: error_type, fatal_error, error_interrupted
   use friction_strings, only: itoa
   use friction_version, only: version_string
   use friction_ode_solver, only: integrator_statistics
   use friction_input, only: job_config, read_input
   use friction_output_h5, only: h5_file
   use friction_output_summary, only: run_summary, write_run_attributes
   use friction_files, only: file_exists, rename_file, remove_file, process_id
   use friction_brake_simulate, only: brake_run
   use friction_brake_diagnostics, only: brake_diagnostics, diagnose_brake
   use friction_scene_report, only: job_reporter
   use friction_scene_context, only: job_context, temporary_name, publish, ranks_text, sum_to_root_real, &
      & sum_to_root_integer
   use friction_job_brake, only: integrate_brake
   use friction_job_afm, only: afm_friction
   implicit none
   private

   public :: run_sweep_job

   integer, parameter :: reason_length = 240   !! characters of a failed point's reason
   integer, parameter :: status_done = 1, status_failed = 2

   !> Per-point results of a scene: names, units and what they mean.
   character(len=*), parameter :: brake_results(4) = [character(len=16) :: 'events', 'peak_frequency', &
      & 'lyapunov', 'stick_fraction']
   character(len=*), parameter :: brake_units(4) = [character(len=16) :: '1', '1/tau', '1/tau', '1']
   character(len=*), parameter :: afm_results(2) = [character(len=16) :: 'mean_friction', 'max_force']
   character(len=*), parameter :: afm_units(2) = [character(len=16) :: 'nN', 'nN']

contains

   !> Run the sweep of `config`; `interrupted` when a stop request or the
   !> stop_after hook ended it early (the file then marks the points not done
   !> as pending and the error says so, with stat error_interrupted).
   subroutine run_sweep_job(job, config, reporter, summary, error)
      type(job_context), intent(in) :: job
      type(job_config), intent(in) :: config
      class(job_reporter), intent(inout) :: reporter
      character(len=:), allocatable, intent(out) :: summary
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: point_error
      character(len=:), allocatable :: override, temporary
      character(len=4096), allocatable :: point_files(:)
      character(len=16), allocatable :: names(:), units(:)
      real(wp), allocatable :: results(:, :), cost(:), maxima(:), point_maxima(:), flat(:)
      integer, allocatable :: status(:), counts(:), offsets(:), reason_codes(:, :), owner(:), computed_by_run(:)
      integer, allocatable :: memory(:)
      integer :: n, i, k, next, total, computed, flag
      integer(kind=MPI_ADDRESS_KIND) :: window_size
      integer :: one(1), fetched(1), block_first, block_last
      type(c_ptr) :: counter_base
      integer, pointer :: counter_value
      type(MPI_Win) :: window
      character(len=reason_length) :: reason
      type(run_summary) :: record
      real(wp) :: wall, t0
      character(len=12) :: seconds
      logical :: dynamic, interrupted, loaded, brake

      brake = config%scene == 'brake'
      if (brake) then
         names = brake_results
         units = brake_units
      else
         names = afm_results
         units = afm_units
      end if
      n = size(config%sweep%values, 2)
      allocate (results(size(names), n), cost(n), source=0.0_wp)
      allocate (status(n), counts(n), owner(n), computed_by_run(n), source=0)
      allocate (reason_codes(reason_length, n), source=0)
      allocate (maxima(0))
      override = job%output//'.override-'//itoa(job%rank)//'-'//itoa(process_id())//'.nml'
      point_files = [job%files, [character(len=4096) :: override]]

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
      do
         ! Between points: a stop request ends the sweep here, the point in hand done.
         if (reporter%stop_requested()) then
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
         if (config%sweep%stop_after > 0 .and. i > config%sweep%stop_after) then
            interrupted = .true.   ! the test hook: as if a signal came after that point
            exit
         end if
         computed = computed + 1
         owner(i) = job%rank + 1
         if (job%resume) then
            call load_point(checkpoint_name(job, i), config%sweep%values(:, i), status(i), results(:, i), &
               & cost(i), reason, point_maxima, loaded)
            if (loaded) then
               counts(i) = size(point_maxima)
               maxima = [maxima, point_maxima]
               call encode(reason, reason_codes(:, i))
               cycle
            end if
         end if
         computed_by_run(i) = 1
         t0 = MPI_Wtime()
         call write_override(override, config, i, point_error)
         if (.not. allocated(point_error)) then
            if (brake) then
               call brake_point(point_files, results(:, i), point_maxima, point_error)
            else
               call afm_point(point_files, results(:, i), point_error)
               allocate (point_maxima(0))
            end if
         end if
         if (allocated(point_error)) then
            status(i) = status_failed
            reason = point_error%message
            results(:, i) = 0.0_wp
            if (allocated(point_maxima)) deallocate (point_maxima)
            allocate (point_maxima(0))
         else
            status(i) = status_done
            reason = ''
         end if
         call encode(reason, reason_codes(:, i))
         counts(i) = size(point_maxima)
         maxima = [maxima, point_maxima]
         cost(i) = MPI_Wtime() - t0
         call save_point(checkpoint_name(job, i), config%sweep%values(:, i), status(i), results(:, i), &
            & cost(i), reason, point_maxima)
         deallocate (point_maxima)
         if (allocated(point_error)) deallocate (point_error)
         if (job%rank == 0) call reporter%progress(real(i, wp), real(n, wp), 'points', .false.)
      end do
      if (dynamic) call MPI_Win_free(window)
      call remove_file(override)

      ! Each point has exactly one owner; the others hold zeros, so a sum gathers it exactly.
      call MPI_Allreduce(MPI_IN_PLACE, counts, n, MPI_INTEGER, MPI_SUM, job%comm)
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
      call sum_to_root_integer(job, owner, n)
      call sum_to_root_integer(job, computed_by_run, n)
      call sum_to_root_integer(job, reason_codes, reason_length * n)
      flag = merge(1, 0, interrupted)
      call MPI_Allreduce(MPI_IN_PLACE, flag, 1, MPI_INTEGER, MPI_MAX, job%comm)
      interrupted = flag /= 0

      ! Peak resident memory of every rank, for the benchmark (README: Parameter sweeps).
      allocate (memory(job%nranks))
      call MPI_Gather(peak_memory_kb(), 1, MPI_INTEGER, memory, 1, MPI_INTEGER, 0, job%comm)
      wall = MPI_Wtime() - job%t_start
      call MPI_Allreduce(MPI_IN_PLACE, wall, 1, MPI_DOUBLE_PRECISION, MPI_MAX, job%comm)
      ! (Component by component: gfortran's structure constructor mis-sizes a
      ! deferred-length component copied from another derived type's.)
      record%input_text = job%input_text
      record%version = version_string
      record%nranks = job%nranks
      record%wall_time = wall
      record%stats = integrator_statistics(0, 0, 0, 0)
      temporary = temporary_name(job)
      if (job%rank == 0) call write_sweep_file(temporary, config, record, names, units, results, flat, offsets, &
         & counts, status, reason_codes, cost, computed_by_run, memory, interrupted, error)
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
   end subroutine run_sweep_job

   !> The one-line namelist file that sets point i's values.
   subroutine write_override(path, config, i, error)
      character(len=*), intent(in) :: path
      type(job_config), intent(in) :: config
      integer, intent(in) :: i
      type(error_type), allocatable, intent(out) :: error
      character(len=64) :: variable
      character(len=40) :: value
      integer :: unit, stat, v, dot

      open (newunit=unit, file=path, status='replace', action='write', iostat=stat)
      if (stat /= 0) then
         call fatal_error(error, path//': cannot write the point''s override file')
         return
      end if
      do v = 1, config%sweep%n_variables
         variable = config%sweep%variables(v)
         dot = index(variable, '.')
         if (config%sweep%integer_valued(v)) then
            write (value, '(i0)') nint(config%sweep%values(v, i))
         else
            write (value, '(es25.17e3)') config%sweep%values(v, i)
         end if
         write (unit, '(a)') '&'//variable(1:dot - 1)//' '//trim(variable(dot + 1:))//' = '//trim(adjustl(value)) &
            & //' /'
      end do
      close (unit)
   end subroutine write_override

   !> A brake point: the run, its diagnostics and the local maxima of x after
   !> the transient (the bifurcation diagram).
   subroutine brake_point(files, results, maxima, error)
      character(len=*), intent(in) :: files(:)
      real(wp), intent(out) :: results(:)
      real(wp), allocatable, intent(out) :: maxima(:)
      type(error_type), allocatable, intent(out) :: error
      type(job_config) :: point
      character(len=:), allocatable :: text
      type(brake_run), target :: run
      type(brake_diagnostics) :: diagnostics
      type(job_reporter) :: silent
      logical, allocatable :: peak(:)
      integer :: j

      results = 0.0_wp
      call read_input(files, point, text, error)
      if (allocated(error)) return
      call integrate_brake(run, point%brake, silent, error)
      if (allocated(error)) return
      associate (a => point%brake%analysis)
         if (a%spectrum .or. a%lyapunov) then
            call diagnose_brake(point%brake, run%trajectory, run%events, diagnostics, error)
            if (allocated(error)) return
            if (a%spectrum) results(2) = diagnostics%spectrum%peak_frequency
            if (a%lyapunov) results(3) = diagnostics%flow%current()
         end if
         results(1) = run%events%n
         results(4) = run%stick_time() / (point%brake%t_end - point%brake%t_start)
         allocate (peak(run%n), source=.false.)
         associate (t => run%trajectory%t, x => run%trajectory%x)
            do j = 2, run%n - 1
               peak(j) = t(j) >= a%window_start .and. x(j) > x(j - 1) .and. x(j) >= x(j + 1)
            end do
            maxima = pack(x(1:run%n), peak)
         end associate
      end associate
   end subroutine brake_point

   !> An AFM point: the whole map on this rank; its mean friction and maximum force.
   subroutine afm_point(files, results, error)
      character(len=*), intent(in) :: files(:)
      real(wp), intent(out) :: results(:)
      type(error_type), allocatable, intent(out) :: error
      type(job_config) :: point
      character(len=:), allocatable :: text

      results = 0.0_wp
      call read_input(files, point, text, error)
      if (allocated(error)) return
      call afm_friction(point%afm, results(1), results(2), error)
   end subroutine afm_point

   !> The sweep file, written by rank 0 alone.
   subroutine write_sweep_file(path, config, record, names, units, results, flat, offsets, counts, status, &
      & reason_codes, cost, computed_by_run, memory, interrupted, error)
      character(len=*), intent(in) :: path
      type(job_config), intent(in) :: config
      type(run_summary), intent(in) :: record
      character(len=*), intent(in) :: names(:), units(:)
      real(wp), intent(in) :: results(:, :), flat(:), cost(:)
      integer, intent(in) :: offsets(:), counts(:), status(:), reason_codes(:, :), computed_by_run(:), memory(:)
      logical, intent(in) :: interrupted
      type(error_type), allocatable, intent(out) :: error
      type(h5_file) :: file
      character(len=:), allocatable :: reasons, method
      character(len=reason_length) :: reason
      integer :: i, k

      reasons = ''
      do i = 1, size(status)
         call decode(reason_codes(:, i), reason)
         reasons = reasons//trim(reason)//new_line('a')
      end do
      method = trim(config%afm%solver%method)
      if (config%scene == 'brake') method = trim(config%brake%solver%method)
      call file%create(path, MPI_COMM_SELF, error)
      if (allocated(error)) return
      call write_run_attributes(file, 'sweep', method, record)
      call file%write_attribute_text('/', 'sweep_scene', trim(config%scene))
      call file%write_attribute_text('/', 'sweep_variable', trim(config%sweep%variables(1)))
      if (config%sweep%n_variables == 2) &
         & call file%write_attribute_text('/', 'sweep_variable2', trim(config%sweep%variables(2)))
      call file%write_attribute_text('/', 'sweep_schedule', trim(config%sweep%schedule))
      call file%create_group('/sweep')
      call file%write_attribute_integer('/sweep', 'shape', int(config%sweep%shape(1), i8))
      call file%write_attribute_integer('/sweep', 'shape2', int(config%sweep%shape(2), i8))
      call file%write_vector('/sweep/values', config%sweep%values(1, :), trim(config%sweep%variables(1)))
      if (config%sweep%n_variables == 2) call file%write_vector('/sweep/values2', config%sweep%values(2, :), &
         & trim(config%sweep%variables(2)))
      do k = 1, size(names)
         if (trim(names(k)) == 'events') then
            call file%write_integer_vector('/sweep/events', nint(results(k, :)))
         else
            call file%write_vector('/sweep/'//trim(names(k)), results(k, :), trim(units(k)))
         end if
      end do
      if (config%scene == 'brake') then
         call file%write_vector('/sweep/maxima', flat, 'm')
         call file%write_integer_vector('/sweep/maxima_offset', offsets)
         call file%write_integer_vector('/sweep/maxima_count', counts)
      end if
      call file%write_integer_vector('/sweep/status', status)
      call file%write_attribute_text('/sweep/status', 'meaning', '0 pending, 1 done, 2 failed')
      call file%write_attribute_text('/sweep/status', 'reason', reasons)
      call file%write_vector('/sweep/compute_time', cost, 's')
      call file%write_integer_vector('/sweep/computed_by_this_run', computed_by_run)
      call file%write_integer_vector('/sweep/peak_memory_per_rank', memory)
      call file%write_attribute_text('/sweep/peak_memory_per_rank', 'units', 'kB (VmHWM; 0: unknown)')
      call file%write_attribute_integer('/sweep', 'complete', int(merge(0, 1, interrupted), i8))
      call file%close(error)
   end subroutine write_sweep_file

   !> Text as character codes, so a sum over ranks gathers it.
   pure subroutine encode(text, codes)
      character(len=*), intent(in) :: text
      integer, intent(out) :: codes(:)
      integer :: k

      codes = 0
      do k = 1, min(len(text), size(codes))
         codes(k) = ichar(text(k:k))
      end do
   end subroutine encode

   pure subroutine decode(codes, text)
      integer, intent(in) :: codes(:)
      character(len=*), intent(out) :: text
      integer :: k

      text = ''
      do k = 1, min(len(text), size(codes))
         text(k:k) = achar(max(32, codes(k)))
      end do
   end subroutine decode

   !> A finished point's results, written under a temporary name and renamed,
   !> so a checkpoint is whole or absent.  Reals with 17 significant digits
   !> read back to the same double.
   subroutine save_point(path, values, status, results, cost, reason, maxima)
      character(len=*), intent(in) :: path, reason
      real(wp), intent(in) :: values(:), results(:), cost, maxima(:)
      integer, intent(in) :: status
      type(error_type), allocatable :: save_error
      integer :: unit, stat

      open (newunit=unit, file=path//'.tmp', status='replace', action='write', iostat=stat)
      if (stat /= 0) return   ! no checkpoint: the point is computed again on --resume
      write (unit, '(*(es26.17e3))') values
      write (unit, '(3(i0, 1x))') status, size(results), size(maxima)
      write (unit, '(*(es26.17e3))') results, cost
      write (unit, '(a)') trim(reason)
      if (size(maxima) > 0) write (unit, '(es26.17e3)') maxima
      close (unit)
      call rename_file(path//'.tmp', path, save_error)
   end subroutine save_point

   !> A point's checkpoint, if there is a whole one for the same values.
   subroutine load_point(path, values, status, results, cost, reason, maxima, loaded)
      character(len=*), intent(in) :: path
      real(wp), intent(in) :: values(:)
      integer, intent(inout) :: status
      real(wp), intent(inout) :: results(:), cost
      character(len=reason_length), intent(out) :: reason
      real(wp), allocatable, intent(out) :: maxima(:)
      logical, intent(out) :: loaded
      real(wp) :: saved_values(size(values)), numbers(size(results) + 1)
      integer :: unit, stat, found(3)

      loaded = .false.
      reason = ''
      if (.not. file_exists(path)) return
      open (newunit=unit, file=path, status='old', action='read', iostat=stat)
      if (stat /= 0) return
      read (unit, *, iostat=stat) saved_values
      if (stat == 0 .and. all(saved_values == values)) then
         read (unit, *, iostat=stat) found
         if (stat == 0 .and. found(2) /= size(results)) stat = 1
         if (stat == 0) read (unit, *, iostat=stat) numbers
         if (stat == 0) read (unit, '(a)', iostat=stat) reason
         if (stat == 0) then
            allocate (maxima(max(0, found(3))))
            if (found(3) > 0) read (unit, *, iostat=stat) maxima
         end if
         if (stat == 0) then
            status = found(1)
            results = numbers(1:size(results))
            cost = numbers(size(results) + 1)
            loaded = .true.
         end if
      end if
      close (unit)
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
