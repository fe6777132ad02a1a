!> friction: friction-force maps of a microscope tip over a crystal surface,
!> and the stick-slip of a Girling brake (scene 'brake', run_brake).
!>
!>   mpirun -n N friction [options] FILE.nml [MORE.nml ...]
!>
!> The only place that prints and sets the exit code.  Scan lines are dealt
!> round-robin to the MPI ranks; the file is written collectively under a
!> temporary name and renamed when complete.
program friction_main
   use, intrinsic :: iso_c_binding, only: c_int, c_ptr, c_f_pointer
   use, intrinsic :: iso_fortran_env, only: error_unit, output_unit
   use mpi_f08
   use friction_kinds, only: wp, i8
   use friction_error, only: error_type, fatal_error, error_input, error_io, error_numerical
   use friction_version, only: version_string
   use friction_strings, only: itoa
   use friction_io_input, only: job_config, read_input
   use friction_io_h5_file, only: h5_file
   use friction_io_run_summary, only: write_run_attributes
   use friction_io_files, only: file_exists, rename_file, remove_file
   use friction_ode_solver, only: integrator_statistics
   use friction_afm_scan, only: afm_scanner, trip_record, share_of, n_quantities
   use friction_afm_output, only: write_afm_file, afm_surface_record
   use friction_afm_validity, only: afm_model_warnings
   use friction_io_run_summary, only: run_summary
   use friction_afm_config, only: new_potential, species_count
   use friction_surface_potential, only: surface_potential
   use friction_brake_config, only: brake_config
   use friction_brake_simulate, only: brake_run, brake_comparison, compare_runs
   use friction_brake_output, only: brake_run_summary, brake_check_summary, write_brake_file
   use friction_brake_diagnostics, only: brake_diagnostics, diagnose_brake
   implicit none

   interface
      function friction_stderr_is_terminal() result(yes) bind(c)
         import :: c_int
         integer(c_int) :: yes
      end function friction_stderr_is_terminal
      function friction_process_id() result(pid) bind(c)
         import :: c_int
         integer(c_int) :: pid
      end function friction_process_id
      subroutine friction_catch_signals() bind(c)
      end subroutine friction_catch_signals
      function friction_interrupted() result(yes) bind(c)
         import :: c_int
         integer(c_int) :: yes
      end function friction_interrupted
      !> The C library's exit: a status code without the runtime's backtrace.
      subroutine c_exit(status) bind(c, name='exit')
         import :: c_int
         integer(c_int), value :: status
      end subroutine c_exit
   end interface

   integer, parameter :: reason_length = 240   !! characters of a failed sweep point's reason
   integer, parameter :: exit_usage = 2, exit_input = 3, exit_numerical = 4, exit_io = 5, exit_interrupted = 6

   type :: options
      character(len=:), allocatable :: output
      logical :: force = .false.
      logical :: quiet = .false.
      logical :: resume = .false.
      character(len=4096), allocatable :: files(:)
   end type options

   type(options) :: opts
   type(job_config) :: config
   character(len=:), allocatable :: input_text
   type(error_type), allocatable :: error
   integer :: rank, nranks, code
   real(wp) :: t_start

   call MPI_Init()
   t_start = MPI_Wtime()
   call MPI_Comm_rank(MPI_COMM_WORLD, rank)
   call MPI_Comm_size(MPI_COMM_WORLD, nranks)

   code = parse_arguments(opts)
   if (code >= 0) call finish(code)

   call read_input(opts%files, config, input_text, error)
   if (allocated(error)) call fail(error)
   if (.not. allocated(opts%output)) opts%output = default_output(opts%files(1))
   if (file_exists(opts%output) .and. .not. (opts%force .or. (opts%resume .and. config%sweep%enabled))) then
      call fatal_error(error, opts%output//': the output file exists; use --force to overwrite it', &
         & error_input)
      call fail(error)
   end if
   ! Find out now, not after the computation, whether the output can be written.
   if (rank == 0) call check_writable(opts%output, error)
   code = merge(1, 0, allocated(error))
   call MPI_Bcast(code, 1, MPI_INTEGER, 0, MPI_COMM_WORLD)
   if (code /= 0) then
      if (rank == 0) call report(error)
      call finish(exit_io)
   end if

   ! A reduced tip model outside where it holds (README: Reduced models (AFM)).
   if (rank == 0 .and. config%scene == 'afm' .and. .not. config%sweep%enabled) &
      & call warn(afm_model_warnings(config%afm))

   if (config%sweep%enabled) then
      call run_sweep()
   else if (config%scene == 'brake') then
      call run_brake()
   else
      call run_afm()
   end if
   call finish(0)

contains

   !> Scan this rank's lines, then write the file together.
   subroutine run_afm()
      type(afm_scanner), target :: scanner
      class(surface_potential), allocatable :: potential
      type(afm_surface_record) :: surface
      type(trip_record) :: trip
      real(wp), allocatable :: trace(:, :, :), retrace(:, :, :)
      type(run_summary) :: summary
      type(integrator_statistics) :: stats
      integer(i8) :: counts(4)
      integer :: first, count, j, failed_rank
      real(wp) :: wall
      character(len=:), allocatable :: temporary
      character(len=12) :: seconds

      associate (c => config%afm)
         ! The surface first, identically on every rank: a bad net or defect is
         ! bad input, reported before any work.
         call new_potential(c, potential, error, surface%net, surface%cutoff)
         if (allocated(error)) call fail(error)
         surface%species_names = c%species(1:species_count(c))
         call share_of(c%ny, nranks, rank, first, count)
         allocate (trace(c%nx, count, n_quantities))
         allocate (retrace(c%nx, merge(count, 0, c%retrace), n_quantities))
         call scanner%init(c, potential, error)
         surface%contact_height = scanner%contact_height
         surface%support_height = scanner%support_height
         do j = 1, count
            if (allocated(error)) exit
            call scanner%run_trip(first + (j - 1) * nranks, .true., trip, error)
            if (allocated(error)) exit
            trace(:, j, :) = trip%values
            if (c%retrace) then
               call scanner%run_trip(first + (j - 1) * nranks, .false., trip, error)
               if (allocated(error)) exit
               retrace(:, j, :) = trip%values
            end if
            if (rank == 0) call show_progress(j, count, c%ny, .false.)
         end do
         if (rank == 0) call show_progress(count, count, c%ny, .true.)
      end associate

      ! A failure on any rank stops all of them here, before anything is written.
      failed_rank = merge(rank, nranks, allocated(error))
      call MPI_Allreduce(MPI_IN_PLACE, failed_rank, 1, MPI_INTEGER, MPI_MIN, MPI_COMM_WORLD)
      if (failed_rank < nranks) then
         code = exit_numerical
         if (rank == failed_rank) then
            call report(error)
            code = exit_code(error)
         end if
         call MPI_Bcast(code, 1, MPI_INTEGER, failed_rank, MPI_COMM_WORLD)
         call finish(code)
      end if

      stats = scanner%statistics()
      counts = [stats%steps, stats%failed_steps, stats%rhs_evaluations, stats%jacobian_evaluations]
      call MPI_Allreduce(MPI_IN_PLACE, counts, 4, MPI_INTEGER8, MPI_SUM, MPI_COMM_WORLD)
      stats = integrator_statistics(counts(1), counts(2), counts(3), counts(4))
      wall = MPI_Wtime() - t_start
      call MPI_Allreduce(MPI_IN_PLACE, wall, 1, MPI_DOUBLE_PRECISION, MPI_MAX, MPI_COMM_WORLD)
      summary = run_summary(input_text, version_string, nranks, wall, stats)

      temporary = temporary_name()
      if (scanner%tip%ndim == 3) then
         call write_afm_file(temporary, MPI_COMM_WORLD, config%afm, first, nranks, trace, retrace, summary, &
            & error, surface)
      else
         call write_afm_file(temporary, MPI_COMM_WORLD, config%afm, first, nranks, trace, retrace, summary, &
            & error)
      end if
      write (seconds, '(f12.2)') wall
      call publish(temporary, itoa(config%afm%ny)//' lines x '//itoa(config%afm%nx)//' points, ' &
         & //trim(adjustl(seconds))//' s on '//itoa(nranks)//trim(merge(' rank ', ' ranks', nranks == 1)))
   end subroutine run_afm

   !> The brake is one trajectory: rank 0 integrates it; with verify on, the
   !> check run goes to rank 1 when there is one (concurrently), else rank 0
   !> runs it after the main run.  The results are broadcast (a few MB at
   !> most) so that every rank takes part in the collective writes with the
   !> same data; the file does not depend on the number of ranks.
   subroutine run_brake()
      type(brake_run), target :: main_run, check_run
      type(brake_config) :: check_config
      type(brake_run_summary) :: summary
      type(brake_check_summary) :: check
      type(brake_diagnostics) :: diagnostics
      type(error_type), allocatable :: check_error
      logical :: analysing
      integer :: check_rank, failed_rank
      real(wp) :: wall, stick_time
      integer(i8) :: counts(4)
      character(len=:), allocatable :: temporary
      character(len=160) :: line
      character(len=12) :: seconds

      check%enabled = config%brake%check%enabled
      check_rank = merge(1, 0, nranks > 1)
      if (rank == 0) call integrate_brake(main_run, config%brake, .true., error)
      if (check%enabled) then
         check_config = config%brake%check_settings()
         if (rank == check_rank) call integrate_brake(check_run, check_config, check_rank /= 0, check_error)
         if (allocated(check_error) .and. .not. allocated(error)) then
            call move_alloc(check_error, error)
            error%message = 'verify run: '//error%message
         end if
      end if
      failed_rank = merge(rank, nranks, allocated(error))
      call MPI_Allreduce(MPI_IN_PLACE, failed_rank, 1, MPI_INTEGER, MPI_MIN, MPI_COMM_WORLD)
      if (failed_rank < nranks) then
         if (rank == failed_rank) call report(error)
         call finish(exit_numerical)
      end if

      call share_brake_run(main_run, 0, config%brake%grid_size(), counts, summary%compute_time, stick_time)
      summary%stats = integrator_statistics(counts(1), counts(2), counts(3), counts(4))
      summary%stick_time = stick_time
      if (check%enabled) then
         call share_brake_run(check_run, check_rank, config%brake%grid_size(), counts, check%compute_time, &
            & stick_time)
         check%stats = integrator_statistics(counts(1), counts(2), counts(3), counts(4))
         check%config = check_config
         check%comparison = compare_runs(main_run, check_run)
         associate (d => check%comparison, c => check_config%solver)
            if (rank == 0) then
               write (line, '(a, es8.2, a, es8.2, a, es8.2, a, i0, a, i0)') 'friction: verify: ' &
                  & //trim(c%method)//' at rtol ', c%rtol, ', atol ', c%atol, ': max |dx| = ', &
                  & d%max_difference(1), ' m over the grid; events ', d%events, ' vs ', d%check_events
               write (error_unit, '(a)') trim(line)
            end if
            if (config%brake%check%max_difference > 0.0_wp .and. &
               & .not. (d%max_difference(1) <= config%brake%check%max_difference)) then
               write (line, '(a, es8.2, a, es8.2, a)') 'verify failed: the check run differs by ', &
                  & d%max_difference(1), ' m in x, more than check_limit = ', &
                  & config%brake%check%max_difference, ' m (README: Girling brake, which steppers need verify)'
               call fatal_error(error, trim(line), error_numerical)
               if (rank == 0) call report(error)
               call finish(exit_numerical)
            end if
         end associate
      end if

      ! The diagnostics are deterministic functions of the shared run (and, for
      ! Benettin, of the settings): every rank computes the same numbers, so
      ! the file does not depend on the number of ranks.
      associate (a => config%brake%analysis)
         analysing = a%spectrum .or. a%poincare .or. a%lyapunov .or. a%rosenstein
      end associate
      if (analysing) then
         call diagnose_brake(config%brake, main_run%trajectory, main_run%events, diagnostics, error)
         if (allocated(error)) call fail(error)
      end if

      wall = MPI_Wtime() - t_start
      call MPI_Allreduce(MPI_IN_PLACE, wall, 1, MPI_DOUBLE_PRECISION, MPI_MAX, MPI_COMM_WORLD)
      summary%input_text = input_text
      summary%version = version_string
      summary%nranks = nranks
      summary%wall_time = wall

      temporary = temporary_name()
      if (analysing) then
         call write_brake_file(temporary, MPI_COMM_WORLD, config%brake, main_run%trajectory, main_run%events, &
            & summary, check, error, diagnostics)
      else
         call write_brake_file(temporary, MPI_COMM_WORLD, config%brake, main_run%trajectory, main_run%events, &
            & summary, check, error)
      end if
      write (seconds, '(f12.3)') wall
      write (line, '(a, i0, a, f0.1, a, i0, a)') ' model, ', main_run%n, ' points to τ = ', &
         & config%brake%grid_time(main_run%n), ', ', main_run%events%n, ' events, '
      call publish(temporary, trim(config%brake%model)//trim(line)//' '//trim(adjustl(seconds))//' s on ' &
         & //itoa(nranks)//trim(merge(' rank ', ' ranks', nranks == 1)))
   end subroutine run_brake

   !> A parameter sweep of the brake (README: Parameter sweeps).  Each point
   !> is the scene re-read from the input files plus a one-line override file,
   !> so read_input validates it; an invalid or failing point is recorded as
   !> failed with its reason and the sweep goes on.
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
   !> parallel HDF5's collective metadata would buy nothing.
   subroutine run_sweep()
      integer, parameter :: status_done = 1, status_failed = 2
      type(job_config) :: point_config
      type(brake_run), target :: point_run
      type(brake_diagnostics) :: diagnostics
      type(error_type), allocatable :: point_error
      character(len=:), allocatable :: point_text, override, temporary, variable_group, variable_name
      character(len=4096), allocatable :: point_files(:)
      real(wp), allocatable :: values(:), peak(:), exponent(:), stick(:), cost(:), maxima(:), flat(:)
      integer, allocatable :: status(:), events(:), counts(:), offsets(:), reason_codes(:, :), owner(:)
      integer :: n, i, k, next, unit, dot, total, computed
      integer(kind=MPI_ADDRESS_KIND) :: window_size
      integer :: one(1), fetched(1)
      type(c_ptr) :: counter_base
      integer, pointer :: counter_value
      type(MPI_Win) :: window
      type(h5_file) :: file
      character(len=reason_length) :: reason
      character(len=:), allocatable :: reasons
      type(run_summary) :: summary
      real(wp) :: wall, transient, t0
      character(len=12) :: seconds
      logical :: dynamic, interrupted, loaded
      integer :: block_first, block_last
      integer, allocatable :: memory(:)
      real(wp), allocatable :: loaded_maxima(:)
      integer, allocatable :: computed_by_run(:)

      values = config%sweep%values
      n = size(values)
      allocate (peak(n), exponent(n), stick(n), cost(n), source=0.0_wp)
      allocate (status(n), events(n), counts(n), owner(n), computed_by_run(n), source=0)
      allocate (reason_codes(reason_length, n), source=0)
      allocate (maxima(0))
      dot = index(config%sweep%variable, '.')
      variable_group = trim(config%sweep%variable(1:dot - 1))
      variable_name = trim(config%sweep%variable(dot + 1:))
      override = opts%output//'.override-'//itoa(rank)//'-'//itoa(friction_process_id())//'.nml'
      point_files = [opts%files, [character(len=4096) :: override]]

      one = 1
      window_size = merge(4, 0, rank == 0)
      ! (One rank needs no counter; Open MPI may have no one-sided component for it.)
      dynamic = config%sweep%schedule == 'dynamic' .and. nranks > 1
      ! MPI_Win_allocate (not MPI_Win_create on a Fortran variable) lets Open MPI
      ! pick its shared-memory one-sided component on a node: the fetch is an
      ! atomic in memory and needs no progress from rank 0, which is busy
      ! computing.  (Measured: with MPI_Win_create a fetch waited for rank 0 to
      ! finish its point, and the dynamic schedule lost to the static one.)
      if (dynamic) then
         call MPI_Win_allocate(window_size, 4, MPI_INFO_NULL, MPI_COMM_WORLD, counter_base, window)
         if (rank == 0) then
            call MPI_Win_lock(MPI_LOCK_EXCLUSIVE, 0, 0, window)
            call c_f_pointer(counter_base, counter_value)
            counter_value = 0
            call MPI_Win_unlock(0, window)
         end if
         call MPI_Barrier(MPI_COMM_WORLD)
      end if
      block_first = int(int(n, i8) * rank / nranks)
      block_last = int(int(n, i8) * (rank + 1) / nranks)
      computed = 0
      interrupted = .false.
      call friction_catch_signals()
      do
         ! Between points: a signal stops the sweep here, the point in hand done.
         if (friction_interrupted() /= 0) then
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
         owner(i) = rank + 1
         if (opts%resume) then
            call load_point(checkpoint_name(i), values(i), status(i), events(i), peak(i), exponent(i), &
               & stick(i), cost(i), reason, loaded_maxima, loaded)
            if (loaded) then
               counts(i) = size(loaded_maxima)
               maxima = [maxima, loaded_maxima]
               do k = 1, reason_length
                  reason_codes(k, i) = ichar(reason(k:k))
               end do
               cycle
            end if
         end if
         computed_by_run(i) = 1
         t0 = MPI_Wtime()
         open (newunit=unit, file=override, status='replace', action='write')
         write (unit, '(a, es25.17e3, a)') '&'//variable_group//' '//variable_name//' = ', values(i), ' /'
         close (unit)
         call read_input(point_files, point_config, point_text, point_error)
         if (.not. allocated(point_error)) call integrate_brake(point_run, point_config%brake, .false., &
            & point_error)
         if (.not. allocated(point_error)) then
            associate (a => point_config%brake%analysis)
               if (a%spectrum .or. a%lyapunov) then
                  call diagnose_brake(point_config%brake, point_run%trajectory, point_run%events, &
                     & diagnostics, point_error)
                  if (.not. allocated(point_error)) then
                     if (a%spectrum) peak(i) = diagnostics%spectrum%peak_frequency
                     if (a%lyapunov) exponent(i) = diagnostics%flow%current()
                  end if
               end if
               transient = a%window_start
            end associate
         end if
         if (allocated(point_error)) then
            status(i) = status_failed
            reason = point_error%message
            do k = 1, reason_length
               reason_codes(k, i) = ichar(reason(k:k))
            end do
         else
            status(i) = status_done
            events(i) = point_run%events%n
            stick(i) = point_run%stick_time() / (point_config%brake%t_end - point_config%brake%t_start)
            call append_maxima(point_run, transient, maxima, counts(i))
         end if
         cost(i) = MPI_Wtime() - t0
         call save_point(checkpoint_name(i), values(i), status(i), events(i), peak(i), exponent(i), &
            & stick(i), cost(i), reason_text(reason_codes(:, i)), maxima(size(maxima) - counts(i) + 1:))
         if (rank == 0 .and. .not. opts%quiet) write (error_unit, '(a, i0, a, i0, a)') 'friction: sweep: rank 0 ' &
            & //'finished point ', i, ' of ', n, ' (points are taken in order)'
      end do
      if (dynamic) call MPI_Win_free(window)
      call remove_file(override)

      ! Each point has exactly one owner; the others hold zeros, so a sum gathers it exactly.
      call MPI_Allreduce(MPI_IN_PLACE, counts, n, MPI_INTEGER, MPI_SUM, MPI_COMM_WORLD)
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
      call sum_to_root_real(flat)
      call sum_to_root_real(peak)
      call sum_to_root_real(exponent)
      call sum_to_root_real(stick)
      call sum_to_root_real(cost)
      call sum_to_root_integer(status, n)
      call sum_to_root_integer(events, n)
      call sum_to_root_integer(owner, n)
      call sum_to_root_integer(computed_by_run, n)
      code = merge(1, 0, interrupted)
      call MPI_Allreduce(MPI_IN_PLACE, code, 1, MPI_INTEGER, MPI_MAX, MPI_COMM_WORLD)
      interrupted = code /= 0
      call sum_to_root_integer(reason_codes, reason_length * n)

      ! Peak resident memory of every rank, for the benchmark (README: Parameter sweeps).
      allocate (memory(nranks))
      call MPI_Gather(peak_memory_kb(), 1, MPI_INTEGER, memory, 1, MPI_INTEGER, 0, MPI_COMM_WORLD)
      wall = MPI_Wtime() - t_start
      call MPI_Allreduce(MPI_IN_PLACE, wall, 1, MPI_DOUBLE_PRECISION, MPI_MAX, MPI_COMM_WORLD)
      summary = run_summary(input_text, version_string, nranks, wall, integrator_statistics(0, 0, 0, 0))
      temporary = temporary_name()
      if (rank == 0) then
         reasons = ''
         do i = 1, n
            do k = 1, reason_length
               reason(k:k) = achar(max(32, reason_codes(k, i)))
            end do
            reasons = reasons//trim(reason)//new_line('a')
         end do
         call file%create(temporary, MPI_COMM_SELF, error)
         if (.not. allocated(error)) then
            call write_run_attributes(file, 'sweep', trim(config%brake%solver%method), summary)
            call file%write_attribute_text('/', 'sweep_variable', trim(config%sweep%variable))
            call file%write_attribute_text('/', 'sweep_schedule', trim(config%sweep%schedule))
            call file%create_group('/sweep')
            call file%write_vector('/sweep/values', values, trim(config%sweep%variable))
            call file%write_vector('/sweep/maxima', flat, 'm')
            call file%write_integer_vector('/sweep/maxima_offset', offsets)
            call file%write_integer_vector('/sweep/maxima_count', counts)
            call file%write_vector('/sweep/peak_frequency', peak, '1/tau')
            call file%write_vector('/sweep/lyapunov', exponent, '1/tau')
            call file%write_vector('/sweep/stick_fraction', stick, '1')
            call file%write_integer_vector('/sweep/events', events)
            call file%write_integer_vector('/sweep/status', status)
            call file%write_attribute_text('/sweep/status', 'meaning', '0 pending, 1 done, 2 failed')
            call file%write_attribute_text('/sweep/status', 'reason', reasons)
            call file%write_vector('/sweep/compute_time', cost, 's')
            call file%write_integer_vector('/sweep/computed_by_this_run', computed_by_run)
            call file%write_integer_vector('/sweep/peak_memory_per_rank', memory)
            call file%write_attribute_text('/sweep/peak_memory_per_rank', 'units', 'kB (VmHWM; 0: unknown)')
            call file%write_attribute_integer('/sweep', 'complete', int(merge(0, 1, interrupted), i8))
            call file%close(error)
         end if
      end if
      write (seconds, '(f12.2)') wall
      call publish(temporary, itoa(count(status /= 0))//' of '//itoa(n)//' sweep points done, ' &
         & //itoa(count(status == status_failed))//' failed, '//itoa(sum(computed_by_run)) &
         & //' computed in this run, '//trim(adjustl(seconds))//' s on '//itoa(nranks) &
         & //trim(merge(' rank ', ' ranks', nranks == 1)))
      if (interrupted) then
         if (rank == 0) write (error_unit, '(a)') 'friction: sweep interrupted; the file marks the points ' &
            & //'not done as pending (status 0): run again with --resume to compute only those'
         call finish(exit_interrupted)
      end if
      ! Complete: the checkpoints have served.
      if (rank == 0) then
         do i = 1, n
            call remove_file(checkpoint_name(i))
         end do
      end if

   end subroutine run_sweep

   !> A finished sweep point's results, written under a temporary name and
   !> renamed, so a checkpoint is whole or absent.  Reals with 17
   !> significant digits read back to the same double.
   subroutine save_point(path, value, status, events, peak, exponent, stick, cost, reason, maxima)
      character(len=*), intent(in) :: path, reason
      real(wp), intent(in) :: value, peak, exponent, stick, cost, maxima(:)
      integer, intent(in) :: status, events
      type(error_type), allocatable :: save_error
      integer :: unit, stat

      open (newunit=unit, file=path//'.tmp', status='replace', action='write', iostat=stat)
      if (stat /= 0) return   ! no checkpoint: the point is computed again on --resume
      write (unit, '(es26.17e3)') value
      write (unit, '(3(i0, 1x))') status, events, size(maxima)
      write (unit, '(4es26.17e3)') peak, exponent, stick, cost
      write (unit, '(a)') trim(reason)
      if (size(maxima) > 0) write (unit, '(es26.17e3)') maxima
      close (unit)
      call rename_file(path//'.tmp', path, save_error)
   end subroutine save_point

   !> A sweep point's checkpoint, if there is a whole one for the same value.
   subroutine load_point(path, value, status, events, peak, exponent, stick, cost, reason, maxima, loaded)
      character(len=*), intent(in) :: path
      real(wp), intent(in) :: value
      integer, intent(inout) :: status, events
      real(wp), intent(inout) :: peak, exponent, stick, cost
      character(len=reason_length), intent(out) :: reason
      real(wp), allocatable, intent(out) :: maxima(:)
      logical, intent(out) :: loaded
      real(wp) :: saved_value, numbers(4)
      integer :: unit, stat, found(3)

      loaded = .false.
      reason = ''
      if (.not. file_exists(path)) return
      open (newunit=unit, file=path, status='old', action='read', iostat=stat)
      if (stat /= 0) return
      read (unit, *, iostat=stat) saved_value
      if (stat == 0 .and. saved_value == value) then
         read (unit, *, iostat=stat) found
         if (stat == 0) read (unit, *, iostat=stat) numbers
         if (stat == 0) read (unit, '(a)', iostat=stat) reason
         if (stat == 0) then
            allocate (maxima(max(0, found(3))))
            if (found(3) > 0) read (unit, *, iostat=stat) maxima
         end if
         if (stat == 0) then
            status = found(1)
            events = found(2)
            peak = numbers(1); exponent = numbers(2); stick = numbers(3); cost = numbers(4)
            loaded = .true.
         end if
      end if
      close (unit)
   end subroutine load_point

   function reason_text(codes) result(text)
      integer, intent(in) :: codes(reason_length)
      character(len=reason_length) :: text
      integer :: j

      do j = 1, reason_length
         text(j:j) = achar(max(32, codes(j)))
      end do
   end function reason_text

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

   !> Where a sweep point's checkpoint lives: beside the output.
   function checkpoint_name(i) result(name)
      integer, intent(in) :: i
      character(len=:), allocatable :: name

      name = opts%output//'.point-'//itoa(i)//'.ckpt'
   end function checkpoint_name

   !> Local maxima of x after the transient, appended to `maxima` (once per
   !> point: appending value by value would copy the array for every maximum).
   subroutine append_maxima(run, transient, maxima, found)
      type(brake_run), intent(in) :: run
      real(wp), intent(in) :: transient
      real(wp), allocatable, intent(inout) :: maxima(:)
      integer, intent(out) :: found
      logical, allocatable :: peak(:)
      integer :: j

      allocate (peak(run%n), source=.false.)
      associate (t => run%trajectory%t, x => run%trajectory%x)
         do j = 2, run%n - 1
            peak(j) = t(j) >= transient .and. x(j) > x(j - 1) .and. x(j) >= x(j + 1)
         end do
         found = count(peak)
         maxima = [maxima, pack(x(1:run%n), peak)]
      end associate
   end subroutine append_maxima

   !> Sum a real array onto rank 0 (each entry has one non-zero contributor).
   subroutine sum_to_root_real(values)
      real(wp), intent(inout) :: values(:)

      if (rank == 0) then
         call MPI_Reduce(MPI_IN_PLACE, values, size(values), MPI_DOUBLE_PRECISION, MPI_SUM, 0, MPI_COMM_WORLD)
      else
         call MPI_Reduce(values, values, size(values), MPI_DOUBLE_PRECISION, MPI_SUM, 0, MPI_COMM_WORLD)
      end if
   end subroutine sum_to_root_real

   !> Sum an integer array of `count` entries onto rank 0.
   subroutine sum_to_root_integer(values, count)
      integer, intent(inout) :: values(*)
      integer, intent(in) :: count

      if (rank == 0) then
         call MPI_Reduce(MPI_IN_PLACE, values, count, MPI_INTEGER, MPI_SUM, 0, MPI_COMM_WORLD)
      else
         call MPI_Reduce(values, values, count, MPI_INTEGER, MPI_SUM, 0, MPI_COMM_WORLD)
      end if
   end subroutine sum_to_root_integer

   !> One brake run, in pieces so that long runs can show progress.
   subroutine integrate_brake(run, settings, show, error)
      type(brake_run), target, intent(inout) :: run
      type(brake_config), intent(in) :: settings
      logical, intent(in) :: show
      type(error_type), allocatable, intent(out) :: error
      integer :: piece, last

      call run%init(settings, error)
      if (allocated(error)) return
      piece = max(1, run%n / 200)
      do last = piece, run%n + piece - 1, piece
         call run%run_until(min(last, run%n), error)
         if (allocated(error)) return
         if (show) call show_brake_progress(run%time_reached(), settings%t_start, settings%t_end, .false.)
      end do
      if (show) call show_brake_progress(run%time_reached(), settings%t_start, settings%t_end, .true.)
   end subroutine integrate_brake

   !> Give every rank root's trajectory, events and counters.
   subroutine share_brake_run(run, root, n, counts, compute_time, stick_time)
      type(brake_run), intent(inout) :: run
      integer, intent(in) :: root, n
      integer(i8), intent(out) :: counts(4)
      real(wp), intent(out) :: compute_time, stick_time
      type(integrator_statistics) :: stats
      integer :: n_events
      real(wp) :: times(2)

      if (rank == root) then
         stats = run%statistics()
         counts = [stats%steps, stats%failed_steps, stats%rhs_evaluations, stats%jacobian_evaluations]
         times = [run%compute_time, run%stick_time()]
         n_events = run%events%n
      else
         call run%trajectory%allocate_points(n)
         run%n = n
         run%done = n
      end if
      call MPI_Bcast(counts, 4, MPI_INTEGER8, root, MPI_COMM_WORLD)
      call MPI_Bcast(times, 2, MPI_DOUBLE_PRECISION, root, MPI_COMM_WORLD)
      call MPI_Bcast(n_events, 1, MPI_INTEGER, root, MPI_COMM_WORLD)
      compute_time = times(1)
      stick_time = times(2)
      call MPI_Bcast(run%trajectory%t, n, MPI_DOUBLE_PRECISION, root, MPI_COMM_WORLD)
      call MPI_Bcast(run%trajectory%x, n, MPI_DOUBLE_PRECISION, root, MPI_COMM_WORLD)
      call MPI_Bcast(run%trajectory%v, n, MPI_DOUBLE_PRECISION, root, MPI_COMM_WORLD)
      call MPI_Bcast(run%trajectory%y, n, MPI_DOUBLE_PRECISION, root, MPI_COMM_WORLD)
      call MPI_Bcast(run%trajectory%w, n, MPI_DOUBLE_PRECISION, root, MPI_COMM_WORLD)
      call MPI_Bcast(run%trajectory%stick, n, MPI_INTEGER, root, MPI_COMM_WORLD)
      if (rank /= root) then
         run%events%n = n_events
         if (allocated(run%events%t)) deallocate (run%events%t, run%events%kind, run%events%state)
         allocate (run%events%t(max(1, n_events)), run%events%kind(max(1, n_events)), &
            & run%events%state(4, max(1, n_events)))
      end if
      if (n_events > 0) then
         call MPI_Bcast(run%events%t, n_events, MPI_DOUBLE_PRECISION, root, MPI_COMM_WORLD)
         call MPI_Bcast(run%events%kind, n_events, MPI_INTEGER, root, MPI_COMM_WORLD)
         call MPI_Bcast(run%events%state, 4 * n_events, MPI_DOUBLE_PRECISION, root, MPI_COMM_WORLD)
      end if
   end subroutine share_brake_run

   !> Rank 0's progress through τ, in the style of show_progress.
   subroutine show_brake_progress(t, t_first, t_last, last)
      real(wp), intent(in) :: t, t_first, t_last
      logical, intent(in) :: last
      real(wp), save :: shown = -1.0_wp
      real(wp) :: now, elapsed, remaining, interval, fraction
      logical :: tty
      character(len=160) :: text
      character(len=12) :: seconds(2)

      if (opts%quiet) return
      tty = friction_stderr_is_terminal() /= 0
      now = MPI_Wtime()
      interval = 0.5_wp
      if (.not. tty) interval = max(2.0_wp, 0.1_wp * (now - t_start))
      if (.not. last .and. now - max(shown, t_start) < interval) return
      if (last .and. shown < 0.0_wp) return   ! finished before the first report: say nothing
      shown = now
      elapsed = now - t_start
      fraction = max(1.0e-9_wp, (t - t_first) / (t_last - t_first))
      remaining = elapsed * (1.0_wp - fraction) / fraction
      ! (f0.1 would drop the leading zero of 0.5 s.)
      write (seconds(1), '(f12.1)') elapsed
      write (seconds(2), '(f12.1)') remaining
      write (text, '(a, f0.1, a, f0.1, a)') 'friction: τ = ', t, ' of ', t_last, ', ' &
         & //trim(adjustl(seconds(1)))//' s elapsed, '//trim(adjustl(seconds(2)))//' s remaining'
      if (tty) then
         write (error_unit, '(a)', advance='no') achar(13)//trim(text)//'   '
         if (last) write (error_unit, '(a)') ''
      else
         write (error_unit, '(a)') trim(text)
      end if
      flush (error_unit)
   end subroutine show_brake_progress

   !> Rank 0's progress: its share is as large as any other and spread over
   !> the whole map, so its fraction done is the map's fraction done.
   subroutine show_progress(done, share, total, last)
      integer, intent(in) :: done, share, total
      logical, intent(in) :: last
      real(wp), save :: shown = -1.0_wp
      integer, save :: shown_done = -1
      real(wp) :: now, elapsed, remaining, interval
      integer :: lines
      logical :: tty

      if (opts%quiet) return
      tty = friction_stderr_is_terminal() /= 0
      now = MPI_Wtime()
      ! Under mpirun stderr is a pipe even at a terminal: plain lines there,
      ! spaced further apart as the run goes on so a long batch log stays short.
      interval = 0.5_wp
      if (.not. tty) interval = max(2.0_wp, 0.1_wp * (now - t_start))
      if (.not. last .and. now - max(shown, t_start) < interval) return
      if (last .and. (shown < 0.0_wp .or. done == shown_done)) return   ! nothing new to say
      shown = now
      shown_done = done
      elapsed = now - t_start
      lines = min(total, int(real(done, wp) / max(1, share) * total))
      remaining = 0.0_wp
      if (done > 0) remaining = elapsed * real(share - done, wp) / done
      if (tty) then
         write (error_unit, '(a, i0, a, i0, a, f0.1, a, f0.1, a)', advance='no') achar(13)// &
            & 'friction: ', lines, ' of ', total, ' lines, ', elapsed, ' s elapsed, ', remaining, &
            & ' s remaining   '
         if (last) write (error_unit, '(a)') ''
      else
         write (error_unit, '(a, i0, a, i0, a, f0.1, a, f0.1, a)') 'friction: ', lines, ' of ', total, &
            & ' lines, ', elapsed, ' s elapsed, ', remaining, ' s remaining'
      end if
      flush (error_unit)
   end subroutine show_progress

   !> Arguments; returns -1 to go on, else the exit code to finish with.
   integer function parse_arguments(opts) result(code)
      type(options), intent(inout) :: opts
      character(len=4096) :: arg
      integer :: i, n

      code = -1
      allocate (opts%files(0))
      n = command_argument_count()
      i = 0
      do while (i < n)
         i = i + 1
         call get_command_argument(i, arg)
         select case (trim(arg))
         case ('-h', '--help')
            if (rank == 0) call print_help()
            code = 0
            return
         case ('-V', '--version')
            if (rank == 0) write (output_unit, '(a)') 'friction '//version_string
            code = 0
            return
         case ('-o', '--output')
            if (i == n) then
               code = usage_error('option '//trim(arg)//' needs a file name')
               return
            end if
            i = i + 1
            call get_command_argument(i, arg)
            opts%output = trim(arg)
         case ('-f', '--force')
            opts%force = .true.
         case ('-q', '--quiet')
            opts%quiet = .true.
         case ('--resume')
            opts%resume = .true.
         case default
            if (arg(1:1) == '-') then
               code = usage_error('unknown option '//trim(arg))
               return
            end if
            opts%files = [opts%files, arg]
         end select
      end do
      if (size(opts%files) == 0) code = usage_error('no input file given')
   end function parse_arguments

   integer function usage_error(message) result(code)
      character(len=*), intent(in) :: message

      if (rank == 0) write (error_unit, '(a)') 'friction: '//message// &
         & new_line('a')//'usage: friction [options] FILE.nml [MORE.nml ...]  (friction --help)'
      code = exit_usage
   end function usage_error

   subroutine print_help()
      write (output_unit, '(a)') &
         & 'usage: [mpirun -n N] friction [options] FILE.nml [MORE.nml ...]', &
         & '', &
         & 'Friction-force maps of a microscope tip dragged over a crystal surface', &
         & '(NaF, HOPG): the tip''s equations of motion integrated with GSL odeiv2,', &
         & 'scan lines shared among MPI ranks, results in one HDF5 file.', &
         & 'With &job scene = ''brake'': the stick-slip of a Girling brake (one', &
         & 'trajectory; inputs/brake.nml; groups &brake &brake_dimensional &verify &analysis).', &
         & 'With a &sweep group: a brake parameter sweep over the MPI ranks (inputs/brake_sweep.nml;', &
         & 'README: Parameter sweeps).', &
         & '', &
         & 'Input files are namelist files read in order; a later file overrides', &
         & 'earlier values variable by variable.  Groups: &job &surface &tip &scan', &
         & '&integrator (see README.md, input reference).', &
         & '', &
         & 'options:', &
         & '  -o, --output FILE  output file (default: first input''s name with .h5,', &
         & '                     in the current directory)', &
         & '  -f, --force        overwrite an existing output file', &
         & '  -q, --quiet        no progress or summary on stderr', &
         & '      --resume       sweeps: reuse the points an interrupted run completed', &
         & '                     (its checkpoints beside the output); overwrites the output', &
         & '  -h, --help         this help', &
         & '  -V, --version      the version', &
         & '', &
         & 'exit codes: 0 done, 2 usage, 3 bad input, 4 integration failed, 5 output failed,', &
         & '            6 sweep interrupted (file written with the points done; --resume)'
   end subroutine print_help

   !> The name the output is written under until it is complete: unique per
   !> run (rank 0's process id), beside the output so the rename is atomic.
   function temporary_name() result(name)
      character(len=:), allocatable :: name
      integer :: pid

      pid = friction_process_id()
      call MPI_Bcast(pid, 1, MPI_INTEGER, 0, MPI_COMM_WORLD)
      name = opts%output//'.tmp-'//itoa(pid)
   end function temporary_name

   !> After the collective write to `temporary`: on success on every rank,
   !> rename it to the output and summarise (`what`); otherwise remove it,
   !> report and stop.
   subroutine publish(temporary, what)
      character(len=*), intent(in) :: temporary, what

      code = merge(1, 0, allocated(error))
      call MPI_Allreduce(MPI_IN_PLACE, code, 1, MPI_INTEGER, MPI_MAX, MPI_COMM_WORLD)
      if (rank == 0) then
         if (code == 0) then
            call rename_file(temporary, opts%output, error)
         else if (.not. allocated(error)) then
            call fatal_error(error, temporary//': writing failed on another rank', error_io)
         end if
         if (allocated(error)) then
            call remove_file(temporary)
            call report(error)
         else if (.not. opts%quiet) then
            write (error_unit, '(a)') 'friction: wrote '//opts%output//' ('//what//')'
         end if
      end if
      code = merge(1, 0, allocated(error))
      call MPI_Bcast(code, 1, MPI_INTEGER, 0, MPI_COMM_WORLD)
      if (code /= 0) call finish(exit_io)
   end subroutine publish

   !> Create and remove a probe file beside the output.
   subroutine check_writable(path, error)
      character(len=*), intent(in) :: path
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: probe
      character(len=256) :: message
      integer :: unit, stat

      probe = path//'.tmp-'//itoa(friction_process_id())
      open (newunit=unit, file=probe, status='new', action='write', iostat=stat, iomsg=message)
      if (stat /= 0) then
         call fatal_error(error, path//': cannot write the output here ('//trim(message)//')', error_io)
         return
      end if
      close (unit, status='delete')
   end subroutine check_writable

   !> inputs/hopg.nml -> hopg.h5
   function default_output(path) result(name)
      character(len=*), intent(in) :: path
      character(len=:), allocatable :: name
      integer :: slash, dot

      slash = index(path, '/', back=.true.)
      name = trim(path(slash + 1:))
      dot = index(name, '.', back=.true.)
      if (dot > 1) name = name(1:dot - 1)
      name = name//'.h5'
   end function default_output

   !> Each line of text as a warning on stderr.
   subroutine warn(text)
      character(len=*), intent(in) :: text
      integer :: start, end

      start = 1
      do while (start <= len(text))
         end = index(text(start:), new_line('a'))
         end = merge(len(text), start + end - 2, end == 0)
         write (error_unit, '(a)') 'friction: warning: '//text(start:end)
         start = end + 2
      end do
   end subroutine warn

   subroutine report(error)
      type(error_type), intent(in) :: error

      write (error_unit, '(a)') 'friction: error: '//error%message
      flush (error_unit)
   end subroutine report

   !> Report an error met identically on every rank (input), then stop.
   subroutine fail(error)
      type(error_type), intent(in) :: error

      if (rank == 0) call report(error)
      call finish(exit_code(error))
   end subroutine fail

   integer function exit_code(error)
      type(error_type), intent(in) :: error

      select case (error%stat)
      case (error_input)
         exit_code = exit_input
      case (error_io)
         exit_code = exit_io
      case default
         exit_code = exit_numerical
      end select
   end function exit_code

   subroutine finish(code)
      integer, intent(in) :: code

      call MPI_Finalize()
      flush (error_unit)
      flush (output_unit)
      call c_exit(int(code, c_int))
   end subroutine finish

end program friction_main
