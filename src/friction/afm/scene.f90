!> The friction-force map as a scene: the tip dragged over a surface line
!> by line (docs/physics.md).  Lines are dealt round-robin over the ranks;
!> the file is written together, each rank its own lines.
module friction_afm_scene
   use friction_parallel, only: reduce_all, op_sum, op_max
   use friction_kinds, only: wp, i8
   use friction_error, only: error_type, fatal_error, error_input, error_interrupted, error_numerical
   use friction_strings, only: itoa, bytes_text
   use friction_version, only: version_string
   use friction_parameters, only: parameter_visitor, parameters_text
   use friction_checks, only: config_checker
   use friction_ode_solver, only: integrator_statistics
   use friction_ode_auto, only: auto_name
   use friction_surface_potential, only: surface_potential
   use friction_output_summary, only: run_summary
   use friction_scene, only: scene, point_result, point_memory, result_sink
   use friction_scene_report, only: job_reporter
   use friction_scene_context, only: job_context, agree_on_error, ranks_text, share_of, job_wall_time, &
      & job_sharing, rank_sharing
   use friction_afm_tip, only: model_overdamped, model_quasistatic
   use friction_afm_config, only: afm_config, auto_method, new_potential, species_count, scan_region, surface_fourier, &
      & with_attempt_damping
   use friction_afm_scan, only: afm_scanner
   use friction_afm_trip, only: line_record, trip_record, q_fx, q_fy, q_f_along, q_jumps, quantity_names, &
      & quantity_count, support_along, support_across
   use friction_afm_output, only: write_afm_file, afm_surface_record, afm_thermal_record, afm_verify_record, &
      & line_friction
   use friction_afm_validity, only: afm_model_warnings, quasistatic_friction_warning, following_bias, &
      & following_bias_warning
   use friction_afm_netlist, only: afm_netlist
   use friction_afm_line_checkpoint, only: line_checkpoint_name
   use friction_afm_map_share, only: map_share
   use friction_afm_map_verify, only: verify_map
   use friction_afm_shape, only: shape_summary
   use friction_afm_loop, only: loop_abs_sum, loop_peaks, loop_forces
   implicit none
   private

   public :: afm_scene, afm_friction, take_surface

   type, extends(scene) :: afm_scene
      type(afm_config) :: config                 !! as the input gives it ('auto' unresolved)
      ! The run's results on this rank
      type(afm_config), private :: ran           !! the settings that ran
      type(map_share), private :: map            !! this rank's lines
      !> The map's slips (all ranks', ordered by line, realization, trip and
      !> time): line, realization, trip, support (Å), force (nN), jump along
      !> and across (Å).
      real(wp), allocatable, private :: slips(:, :)
      real(wp), private :: time_step = 0.0_wp   !! the Langevin step, s
      character(len=:), allocatable, private :: scheme
      type(afm_surface_record), private :: surface
      type(afm_verify_record), private :: verify
      type(run_summary), private :: record
      logical, private :: three_d = .false.
   contains
      procedure :: name => afm_name
      procedure :: groups => afm_groups
      procedure :: visit => afm_visit
      procedure :: check => afm_check
      procedure :: method => afm_method
      procedure :: run => afm_run
      procedure :: write_output => afm_write
      procedure :: summary => afm_summary
      procedure :: point_results => afm_point_results
      procedure :: point_series => afm_point_series
      procedure :: run_point => afm_run_point
      procedure :: compute => afm_compute
      procedure :: compute_line => afm_compute_line
      procedure :: netlist => afm_netlist_text
      procedure :: verifies => afm_verifies
      procedure :: resolved
   end type afm_scene

contains

   function afm_name(self) result(name)
      class(afm_scene), intent(in) :: self
      character(len=:), allocatable :: name

      name = 'afm'
   end function afm_name

   subroutine afm_groups(self, names)
      class(afm_scene), intent(in) :: self
      character(len=32), allocatable, intent(out) :: names(:)

      names = [character(len=32) :: 'surface', 'tip', 'scan', 'integrator']
      ! &fourier only for its surface: the others' echo stays as it was.
      if (self%config%surface_kind() == surface_fourier) names = [character(len=32) :: names, 'fourier']
      ! &thermal only at a temperature: at T = 0 its other variables do
      ! nothing, and the echo is the deterministic program's.
      if (self%config%thermal%enabled()) names = [character(len=32) :: names, 'thermal']
      ! &verify likewise only when it checks.
      if (self%verifies()) names = [character(len=32) :: names, 'verify']
   end subroutine afm_groups

   logical function afm_verifies(self)
      class(afm_scene), intent(in) :: self

      afm_verifies = self%config%verify%enabled
   end function afm_verifies

   subroutine afm_visit(self, v)
      class(afm_scene), intent(inout) :: self
      type(parameter_visitor), intent(inout) :: v

      call self%config%visit(v)
   end subroutine afm_visit

   subroutine afm_check(self, checker)
      class(afm_scene), intent(in) :: self
      type(config_checker), intent(inout) :: checker

      call self%config%validate(checker)
   end subroutine afm_check

   !> The settings that run: &thermal attempt_frequency becomes the damping
   !> it stands for (with_attempt_damping); method = 'auto' becomes the stepper the
   !> work-precision charts show fastest for the potential at this rtol, or
   !> the implicit one where the tip is stiff (tip_stiffness).
   function resolved(self) result(c)
      class(afm_scene), intent(in) :: self
      type(afm_config) :: c

      c = with_attempt_damping(self%config)
      if (c%solver%method == auto_name) c%solver%method = auto_method(c)
   end function resolved

   !> The stepper that runs; at a temperature the Langevin scheme.
   function afm_method(self) result(name)
      class(afm_scene), intent(in) :: self
      character(len=:), allocatable :: name
      type(afm_config) :: c

      c = self%resolved()
      name = trim(c%solver%method)
      if (c%thermal%enabled()) name = thermal_scheme(c)
   end function afm_method

   !> The thermal scheme: the Langevin scheme of the tip model, or the
   !> kinetic Monte Carlo of the thermal reduced model.
   function thermal_scheme(c) result(name)
      type(afm_config), intent(in) :: c
      character(len=:), allocatable :: name

      if (c%thermal%reduced()) then
         name = 'kramers-kmc'
      else if (c%tip_model() == model_overdamped) then
         name = 'leimkuhler-matthews'
      else
         name = 'baoab'
      end if
   end function thermal_scheme

   !> Compute this rank's lines of the map.
   subroutine afm_run(self, job, reporter, error)
      class(afm_scene), intent(inout) :: self
      type(job_context), intent(in) :: job
      class(job_reporter), intent(inout) :: reporter
      type(error_type), allocatable, intent(out) :: error
      type(afm_scanner), target :: scanner
      class(surface_potential), allocatable :: potential
      type(rank_sharing) :: share
      type(line_record) :: line
      integer(i8) :: counts(4)
      integer :: j, flag
      logical :: interrupted
      integer(i8) :: probe_started

      self%ran = self%resolved()
      self%verify = afm_verify_record()
      probe_started = 0
      associate (c => self%ran, map => self%map)
         ! The surface first, identically on every rank (its table, if any,
         ! built by all together): a bad net or defect is bad input,
         ! reported before any work.
         share = job_sharing(job)
         call new_potential(c, potential, error, self%surface%net, self%surface%cutoff, self%surface%evaluation, &
            & share)
         if (allocated(error)) return
         if (job%rank == 0) call note_model(potential)
         self%surface%species_names = c%species(1:species_count(c))
         ! The map's share of this rank, checked before it is allocated.
         call map%init(c, job, c%thermal%enabled(), error)
         if (.not. allocated(error)) call scanner%init_owning(c, potential, error)
         ! Within a line too (a slow thermal line can take minutes): the
         ! process's stop request, through a copy of the reporter.
         if (.not. allocated(error)) allocate (scanner%guard%stopper, source=reporter)
         ! max_wall_time counts from the reduced model's probe, when there was one.
         if (probe_started > 0) scanner%guard%clock_start = probe_started
         if (.not. allocated(error) .and. scanner%thermal) then
            self%time_step = scanner%time_step()
            self%scheme = thermal_scheme(c)
         end if
         self%surface%contact_height = scanner%contact_height
         self%surface%support_height = scanner%support_height
         if (allocated(scanner%tip)) self%three_d = scanner%tip%ndim == 3
         ! Finished lines go to checkpoints beside the output (every
         ! checkpoint_interval of wall time, and when stopped) for --resume.
         interrupted = .false.
         do j = 1, map%count
            if (allocated(error)) exit
            ! Between lines: a stop request ends the map here.
            if (reporter%stop_after(map%computed)) then
               interrupted = .true.
               exit
            end if
            if (job%resume) call map%resume_line(j, error)
            if (allocated(error)) exit
            if (.not. map%loaded(j)) then
               counts = scanner_counts()
               call scanner%run_line(map%global_line(j), line, error)
               if (allocated(error)) then
                  ! Stopped within the line: as between lines, the lines done kept.
                  if (error%stat == error_interrupted) then
                     interrupted = .true.
                     deallocate (error)
                  end if
                  exit
               end if
               call map%store(j, line, real(scanner_counts() - counts, wp))
               if (map%save_due()) call map%save_lines(j, error)
            end if
            if (job%rank == 0) call reporter%progress(real(map%lines_done(j), wp), real(c%ny, wp), 'lines', .false.)
         end do
         if (interrupted .and. .not. allocated(error)) call map%save_lines(j - 1, error)
         if (job%rank == 0 .and. .not. allocated(error) .and. .not. interrupted) &
            & call reporter%progress(real(map%lines_done(map%count), wp), real(c%ny, wp), 'lines', .true.)

         ! A failure on any rank stops all of them here, before anything is written.
         call agree_on_error(job, error)
         if (allocated(error)) return
         flag = merge(1, 0, interrupted)
         call reduce_all(job%comm, flag, op_max)
         if (flag /= 0) then
            call fatal_error(error, 'map interrupted: no file written; the lines done are checkpointed beside ' &
               & //'the output ('//line_checkpoint_name(job%output, 0)//' ...): run again with --resume to ' &
               & //'compute only the others', error_interrupted)
            return
         end if
         if (c%tip_model() == model_overdamped .and. .not. scanner%thermal) call check_following()
         if (c%verify%enabled) then
            ! (The surface the map ran on, handed over: a table is not built again.)
            call scanner%release_potential(potential)
            call verify_map(map, potential, self%three_d, job, reporter, self%verify, error)
            if (allocated(error)) return
         end if
         if (c%tip_model() == model_quasistatic) call check_friction()
         if (scanner%thermal) call map%gather_slips(job, self%slips)

         ! The counts of every line, computed now or loaded: a resumed map
         ! records what an uninterrupted one does.
         counts = nint(sum(map%line_counts, dim=2), i8)
         call reduce_all(job%comm, counts, op_sum)
         ! (Component by component: gfortran's structure constructor mis-sizes a
         ! deferred-length component copied from another derived type's.)
         self%record%input_text = job%input_text
         self%record%nranks = job%nranks
         self%record%wall_time = job_wall_time(job)
         self%record%stats = integrator_statistics(counts(1), counts(2), counts(3), counts(4))
         ! Complete: the checkpoints have served.
         call map%remove_checkpoints()
      end associate

   contains

      !> A reduced tip model outside where it holds (docs/physics.md, reduced
      !> tip models) and a table declined: one note per reason.
      subroutine note_model(potential)
         class(surface_potential), intent(in) :: potential
         character(len=:), allocatable :: warnings
         integer :: start, end

         if (self%ran%moves_in_3d() .and. len(self%surface%evaluation%note) > 0) call reporter%note( &
            & "note: &surface evaluation = 'table': the direct sum instead: "//self%surface%evaluation%note)
         warnings = afm_model_warnings(self%ran, potential, reporter, job%nranks, probe_started)
         start = 1
         do while (start <= len(warnings))
            end = index(warnings(start:), new_line('a'))
            end = merge(len(warnings), start + end - 2, end == 0)
            call reporter%note('warning: '//warnings(start:end))
            start = end + 2
         end do
      end subroutine note_model

      !> The scanner's integrator counts so far.
      function scanner_counts() result(now)
         integer(i8) :: now(4)
         type(integrator_statistics) :: so_far

         so_far = scanner%statistics()
         now = [so_far%steps, so_far%failed_steps, so_far%rhs_evaluations, so_far%jacobian_evaluations]
      end function scanner_counts

      !> The overdamped map at T = 0: a bias of its integration where the tip
      !> follows its minimum (friction_afm_validity's following_bias).
      subroutine check_following()
         real(wp) :: worst
         character(len=:), allocatable :: warning

         worst = following_bias(self%ran, scanner%tip, self%map%trace, self%map%retrace)
         call reduce_all(job%comm, worst, op_max)
         warning = following_bias_warning(self%ran, worst)
         if (job%rank == 0 .and. len(warning) > 0) call reporter%note('warning: '//warning)
      end subroutine check_following

      !> The quasistatic map's mean friction against the drag it leaves out.
      subroutine check_friction()
         real(wp) :: sums(2)
         character(len=:), allocatable :: warning

         associate (trace => self%map%trace, retrace => self%map%retrace)
            sums = [sum(trace(:, :, q_f_along)), real(size(trace(:, :, q_f_along)), wp)]
            if (self%ran%retrace) sums(1) = 0.5_wp * (sums(1) - sum(retrace(:, :, q_f_along)))
         end associate
         call reduce_all(job%comm, sums, op_sum)
         warning = quasistatic_friction_warning(self%ran, sums(1) / max(1.0_wp, sums(2)))
         if (job%rank == 0 .and. len(warning) > 0) call reporter%note('warning: '//warning)
      end subroutine check_friction

   end subroutine afm_run

   subroutine afm_write(self, path, job, error)
      class(afm_scene), intent(inout) :: self
      character(len=*), intent(in) :: path
      type(job_context), intent(in) :: job
      type(error_type), allocatable, intent(out) :: error
      type(afm_thermal_record) :: thermal

      self%record%version = version_string
      if (allocated(self%map%trace_sem)) then
         ! (Component by component: gfortran's structure constructor mishandles
         ! deferred-length components.)
         thermal%trace_sem = self%map%trace_sem
         thermal%retrace_sem = self%map%retrace_sem
         thermal%friction_sem = self%map%friction_sem
         thermal%time_step = self%time_step
         thermal%scheme = self%scheme
         thermal%slips = self%slips
         if (self%three_d) then
            call write_afm_file(path, job%comm, self%ran, self%map%first, job%nranks, self%map%trace, self%map%retrace, &
               & self%record, error, self%surface, thermal=thermal, verify=self%verify)
         else
            call write_afm_file(path, job%comm, self%ran, self%map%first, job%nranks, self%map%trace, self%map%retrace, &
               & self%record, error, thermal=thermal, verify=self%verify)
         end if
      else if (self%three_d) then
         call write_afm_file(path, job%comm, self%ran, self%map%first, job%nranks, self%map%trace, self%map%retrace, &
            & self%record, error, self%surface, verify=self%verify)
      else
         call write_afm_file(path, job%comm, self%ran, self%map%first, job%nranks, self%map%trace, self%map%retrace, &
            & self%record, error, verify=self%verify)
      end if
   end subroutine afm_write

   function afm_summary(self, job) result(text)
      class(afm_scene), intent(in) :: self
      type(job_context), intent(in) :: job
      character(len=:), allocatable :: text
      character(len=12) :: seconds

      write (seconds, '(f12.2)') self%record%wall_time
      text = itoa(self%ran%ny)//' lines x '//itoa(self%ran%nx)//' points, '//trim(adjustl(seconds))//' s ' &
         & //ranks_text(job%nranks)
      ! The surface table's cost, which the file leaves out (it is a timing).
      if (self%three_d .and. allocated(self%surface%evaluation%evaluation)) then
         if (self%surface%evaluation%evaluation == 'table') then
            ! (Milliseconds: a build takes tens of them.)
            write (seconds, '(f12.3)') self%surface%evaluation%build_time
            text = text//'; surface table '//bytes_text(self%surface%evaluation%bytes)//', built in ' &
               & //trim(adjustl(seconds))//' s'
         end if
      end if
      if (self%ran%surface_kind() == surface_fourier) text = text//'; '//shape_summary(self%ran)
   end function afm_summary

   function afm_point_results(self) result(results)
      class(afm_scene), intent(in) :: self
      type(point_result), allocatable :: results(:)

      results = [point_result('mean_friction', 'nN', .false.), point_result('max_force', 'nN', .false.), &
         & point_result('mean_abs_force', 'nN', .false.), point_result('peak_force', 'nN', .false.)]
   end function afm_point_results

   subroutine afm_point_series(self, name, unit)
      class(afm_scene), intent(in) :: self
      character(len=:), allocatable, intent(out) :: name, unit

      name = ''
      unit = ''
   end subroutine afm_point_series

   subroutine afm_run_point(self, sink, memory, error, reporter)
      class(afm_scene), intent(inout) :: self
      class(result_sink), intent(inout) :: sink
      type(point_memory), intent(inout) :: memory
      type(error_type), allocatable, intent(out) :: error
      class(job_reporter), intent(inout), optional :: reporter
      real(wp) :: results(4)

      results = 0.0_wp
      call afm_friction(self%resolved(), results(1), results(2), error, memory, results(3), results(4))
      if (.not. allocated(error)) call self%put_point(sink, results, [real(wp) ::])
   end subroutine afm_run_point

   !> The whole map on this process: every line's trace (and retrace), as
   !> the program's file holds them under /afm; at a temperature the means
   !> over the realizations, and NAME_sem beside every NAME.  The surface
   !> is memory's when it still holds (take_surface), and left in it.
   subroutine afm_compute(self, sink, memory, reporter, error)
      class(afm_scene), intent(inout) :: self
      class(result_sink), intent(inout) :: sink
      type(point_memory), intent(inout) :: memory
      class(job_reporter), intent(inout) :: reporter
      type(error_type), allocatable, intent(out) :: error
      type(afm_config) :: c
      class(surface_potential), allocatable :: potential
      type(afm_scanner), target :: scanner
      type(line_record) :: line
      real(wp), allocatable :: trace(:, :, :), retrace(:, :, :), trace_sem(:, :, :), retrace_sem(:, :, :)
      real(wp), allocatable :: friction_sem(:)
      integer :: j, q

      c = self%resolved()
      call take_surface(c, memory, potential, error)
      if (allocated(error)) return
      call scanner%init_owning(c, potential, error)
      if (allocated(error)) return
      ! Within a line too (a thermal line can take minutes): the caller's
      ! stop request, through a copy of the reporter made anew after each report.
      allocate (scanner%guard%stopper, source=reporter)
      call poll_later()
      ! (line j's samples are trace(:, j, q): row-major (ny, nx) as it lies)
      allocate (trace(c%nx, c%ny, size(quantity_names)), retrace(c%nx, merge(c%ny, 0, c%retrace), &
         & size(quantity_names)))
      allocate (trace_sem, mold=trace)
      allocate (retrace_sem, mold=retrace)
      allocate (friction_sem(c%ny))
      do j = 1, c%ny
         call scanner%run_line(j - 1, line, error)
         if (allocated(error)) exit
         trace(:, j, :) = line%trace
         trace_sem(:, j, :) = line%trace_sem
         if (c%retrace) then
            retrace(:, j, :) = line%retrace
            retrace_sem(:, j, :) = line%retrace_sem
            friction_sem(j) = line%friction_sem
         end if
         call reporter%progress(real(j, wp), real(c%ny, wp), 'lines', j == c%ny)
         deallocate (scanner%guard%stopper)
         allocate (scanner%guard%stopper, source=reporter)
         call poll_later()
         if (j < c%ny .and. reporter%stop_requested()) then
            call fatal_error(error, 'the map stopped on request after '//itoa(j)//' of '//itoa(c%ny) &
               & //' lines: no result', error_interrupted)
            exit
         end if
      end do
      call scanner%release_potential(memory%surface)
      if (allocated(error)) return
      call sink%add('support_x', c%nx, 1, support_along(c))
      call sink%add('support_y', c%ny, 1, support_across(c))
      call add_trips('trace', trace, '')
      if (scanner%thermal) call add_trips('trace', trace_sem, '_sem')
      if (c%retrace) then
         call add_trips('retrace', retrace, '')
         if (scanner%thermal) call add_trips('retrace', retrace_sem, '_sem')
         call sink%add('friction', c%ny, 1, line_friction(trace, retrace))
         if (scanner%thermal) call sink%add('friction_sem', c%ny, 1, friction_sem)
         call add_loop_forces()
      end if

   contains

      !> The first look at the stop request within a line a poll interval
      !> from now: a line shorter than that asks only its report.
      subroutine poll_later()
         integer(i8) :: now

         call system_clock(now)
         scanner%guard%next_poll = scanner%guard%next_look(now)
      end subroutine poll_later

      !> Each line's mean |F| and mean peak force, as /afm holds them.
      subroutine add_loop_forces()
         real(wp) :: mean_abs(c%ny), peak(c%ny)

         call loop_forces(trace(:, :, q_f_along), retrace(:, :, q_f_along), mean_abs, peak)
         call sink%add('mean_abs_force', c%ny, 1, mean_abs)
         call sink%add('peak_force', c%ny, 1, peak)
      end subroutine add_loop_forces

      subroutine add_trips(trip_name, values, suffix)
         character(len=*), intent(in) :: trip_name, suffix
         real(wp), intent(in) :: values(:, :, :)

         do q = 1, quantity_count(scanner%tip%ndim)
            call sink%add(trip_name//'/'//trim(quantity_names(q))//suffix, c%ny, c%nx, &
               & reshape(values(:, :, q), [c%nx * c%ny]))
         end do
         if (c%tip_model() == model_quasistatic) call sink%add(trip_name//'/'//trim(quantity_names(q_jumps)) &
            & //suffix, c%ny, c%nx, reshape(values(:, :, q_jumps), [c%nx * c%ny]))
      end subroutine add_trips

   end subroutine afm_compute

   !> Line `line` (0 to ny - 1) of the map, trace or retrace, on this
   !> process: 'fx' and 'fy' (nN) over the support's nx positions; at a
   !> temperature the means over the realizations of whole lines (a trip's
   !> noise is its own, whatever else is computed).  `capacity` below nx is
   !> an input error.
   subroutine afm_compute_line(self, line, forward, capacity, sink, memory, error, reporter)
      class(afm_scene), intent(inout) :: self
      integer, intent(in) :: line
      logical, intent(in) :: forward
      integer(i8), intent(in) :: capacity
      class(result_sink), intent(inout) :: sink
      type(point_memory), intent(inout) :: memory
      type(error_type), allocatable, intent(out) :: error
      class(job_reporter), intent(inout), optional :: reporter
      type(afm_config) :: c
      class(surface_potential), allocatable :: potential
      type(afm_scanner), target :: scanner
      type(trip_record) :: trip
      type(line_record) :: mean

      c = self%resolved()
      if (line < 0 .or. line >= c%ny) then
         call fatal_error(error, 'line = '//itoa(line)//': the map has lines 0 to '//itoa(c%ny - 1) &
            & //' (scan.ny = '//itoa(c%ny)//')', error_input)
         return
      end if
      if (capacity < c%nx) then
         call fatal_error(error, 'n = '//itoa(capacity)//': fx and fy must hold scan.nx = '//itoa(c%nx) &
            & //' values', error_input)
         return
      end if
      call take_surface(c, memory, potential, error)
      if (.not. allocated(error)) call scanner%init_owning(c, potential, error)
      if (.not. allocated(error) .and. present(reporter)) then
         ! The caller's stop request within the line, as afm_compute asks it.
         allocate (scanner%guard%stopper, source=reporter)
         block
            integer(i8) :: now
            call system_clock(now)
            scanner%guard%next_poll = scanner%guard%next_look(now)
         end block
      end if
      if (allocated(error)) then
         continue
      else if (scanner%thermal) then
         call scanner%run_line(line, mean, error, with_retrace=.not. forward)
         if (.not. allocated(error)) then
            if (forward) then
               trip%values = mean%trace
            else
               trip%values = mean%retrace
            end if
         end if
      else
         call scanner%run_trip(line, forward, trip, error)
      end if
      call scanner%release_potential(memory%surface)
      if (allocated(error)) return
      if (present(reporter)) call reporter%progress(1.0_wp, 1.0_wp, 'lines', .true.)
      call sink%add('fx', c%nx, 1, trip%values(:, q_fx))
      call sink%add('fy', c%nx, 1, trip%values(:, q_fy))
   end subroutine afm_compute_line

   subroutine afm_netlist_text(self, data_file, version, text, note, error, origins)
      class(afm_scene), intent(in) :: self
      character(len=*), intent(in) :: data_file, version
      character(len=:), allocatable, intent(out) :: text, note
      type(error_type), allocatable, intent(out) :: error
      type(config_checker), intent(in), optional :: origins

      note = ''
      if (self%config%thermal%enabled()) note = 'the netlist is the deterministic tip: &thermal ' &
         & //'temperature > 0 adds thermal noise, which it does not model'
      call afm_netlist(self%resolved(), data_file, version, text, error)
   end subroutine afm_netlist_text

   !> The whole map of `c` on this process, reduced to the numbers a
   !> parameter scan charts: the mean friction (half the width of the
   !> friction loop, the mean of (trace - retrace) f_along / 2 over the map;
   !> the mean trace f_along without retrace) and the maximum lateral force
   !> |(fx, fy)| over all samples, both nN; at a temperature both of the
   !> samples' means over the realizations.  Holds one line at a time.
   !> With `memory`, the surface is taken from it when it was made from the
   !> same settings (surface_key) and left in it for the next point: a sweep
   !> over the tip, the scan's speed or sampling or the integrator builds a
   !> lattice sum's table once per process, not once per point.
   subroutine afm_friction(c, mean_friction, max_force, error, memory, mean_abs_force, peak_force)
      type(afm_config), intent(in) :: c
      real(wp), intent(out) :: mean_friction, max_force
      type(error_type), allocatable, intent(out) :: error
      type(point_memory), intent(inout), optional :: memory
      !> the mean |F| along the scan over every sample of the trips run, and
      !> the mean of their peaks (friction_afm_loop)
      real(wp), intent(out), optional :: mean_abs_force, peak_force
      type(afm_scanner), target :: scanner
      class(surface_potential), allocatable :: potential
      type(line_record) :: line
      real(wp) :: total, abs_total, peak_total, peaks
      integer :: j, count

      mean_friction = 0.0_wp
      max_force = 0.0_wp
      if (present(memory)) then
         call take_surface(c, memory, potential, error)
      else
         call new_potential(c, potential, error)
      end if
      if (allocated(error)) return
      call scanner%init_owning(c, potential, error)
      if (allocated(error)) return
      total = 0.0_wp
      abs_total = 0.0_wp
      peak_total = 0.0_wp
      peaks = 0.0_wp
      do j = 0, c%ny - 1
         call scanner%run_line(j, line, error)
         if (allocated(error)) exit
         total = total + sum(line%trace(:, q_f_along))
         max_force = max(max_force, maxval(hypot(line%trace(:, q_fx), line%trace(:, q_fy))))
         abs_total = abs_total + loop_abs_sum(line%trace(:, q_f_along))
         call add_peaks(line%trace(:, q_f_along), .true.)
         if (c%retrace) then
            total = total - sum(line%retrace(:, q_f_along))
            max_force = max(max_force, maxval(hypot(line%retrace(:, q_fx), line%retrace(:, q_fy))))
            abs_total = abs_total + loop_abs_sum(line%retrace(:, q_f_along))
            call add_peaks(line%retrace(:, q_f_along), .false.)
         end if
      end do
      ! (The surface goes back also after a failed line: it is not what failed.)
      if (present(memory)) call scanner%release_potential(memory%surface)
      if (allocated(error)) then
         max_force = 0.0_wp
         return
      end if
      mean_friction = total / (real(c%nx, wp) * c%ny * merge(2, 1, c%retrace))
      if (present(mean_abs_force)) mean_abs_force = abs_total / (real(c%nx, wp) * c%ny * merge(2, 1, c%retrace))
      if (present(peak_force)) peak_force = peak_total / max(peaks, 1.0_wp)

   contains

      subroutine add_peaks(force, forward)
         real(wp), intent(in) :: force(:)
         logical, intent(in) :: forward
         real(wp) :: part

         call loop_peaks(force, forward, part, count)
         peak_total = peak_total + part
         peaks = peaks + count
      end subroutine add_peaks

   end subroutine afm_friction

   !> The surface of `c` for a scan: `memory`'s when it was made from the
   !> same settings (surface_key), else a new one.  Until the scan gives it
   !> back (afm_scanner's release_potential into memory%surface), memory
   !> holds no surface, only the key of this one.
   subroutine take_surface(c, memory, potential, error)
      type(afm_config), intent(in) :: c
      type(point_memory), intent(inout) :: memory
      class(surface_potential), allocatable, intent(out) :: potential
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: key

      key = surface_key(c)
      if (allocated(memory%surface) .and. allocated(memory%surface_key)) then
         if (memory%surface_key == key) call move_alloc(memory%surface, potential)
      end if
      if (allocated(memory%surface)) deallocate (memory%surface)
      memory%surface_key = key
      if (.not. allocated(potential)) call new_potential(c, potential, error)
   end subroutine take_surface

   !> What the surface new_potential builds depends on: the &surface group
   !> and the scan's rectangle (the lattice sum keeps the atoms near it and
   !> tabulates over it), as exact text (the rectangle's bits in hex).
   function surface_key(c) result(key)
      type(afm_config), intent(in) :: c
      character(len=:), allocatable :: key
      type(afm_config) :: copy
      character(len=68) :: rectangle

      copy = c
      write (rectangle, '(4(1x, z16.16))') transfer(scan_region(c, 0.0_wp), [0_i8])
      key = parameters_text(copy, [character(len=7) :: 'surface', 'fourier'])//' scan rectangle'//rectangle
   end function surface_key

end module friction_afm_scene
