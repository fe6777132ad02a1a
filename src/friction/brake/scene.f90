!> The Girling brake as a scene (docs/physics.md, the Girling brake): one trajectory.
!> Rank 0 integrates it; with verify on, the check run goes to rank 1 when
!> there is one (concurrently), else rank 0 runs it after the main run.  The
!> results are broadcast (a few MB at most) so that every rank takes part in
!> the collective writes with the same data; the file does not depend on
!> the number of ranks.
module friction_brake_scene
   use friction_parallel, only: broadcast
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
   use friction_kinds, only: wp, i8
   use friction_strings, only: fixed_text, etoa, itoa
   use friction_error, only: error_type, fatal_error, error_numerical, error_interrupted
   use friction_version, only: version_string
   use friction_parameters, only: parameter_visitor
   use friction_checks, only: config_checker
   use friction_ode_solver, only: integrator_statistics
   use friction_ode_auto, only: auto_name
   use friction_scene, only: scene, point_result, point_memory, result_sink
   use friction_scene_report, only: job_reporter
   use friction_scene_context, only: job_context, agree_on_error, ranks_text, job_wall_time
   use friction_brake_config, only: brake_config
   use friction_brake_simulate, only: brake_run, compare_runs
   use friction_brake_output, only: brake_run_summary, brake_check_summary, write_brake_file
   use friction_brake_diagnostics, only: brake_diagnostics, diagnose_brake
   use friction_brake_netlist, only: brake_netlist
   implicit none
   private

   public :: brake_scene, integrate_brake

   type, extends(scene) :: brake_scene
      type(brake_config) :: config                 !! as the input gives it
      type(brake_config), private :: ran           !! resolved: dimensional data derived, 'auto' chosen
      type(brake_run), private :: main_run
      type(brake_run_summary), private :: record
      type(brake_check_summary), private :: check_record
      type(brake_diagnostics), private :: diagnostics
      logical, private :: analysing = .false.
   contains
      procedure :: name => brake_name
      procedure :: groups => brake_groups
      procedure :: visit => brake_visit
      procedure :: check => brake_check_values
      procedure :: method => brake_method
      procedure :: run => brake_run_scene
      procedure :: write_output => brake_write
      procedure :: summary => brake_summary
      procedure :: point_results => brake_point_results
      procedure :: point_series => brake_point_series
      procedure :: run_point => brake_run_point
      procedure :: compute => brake_compute
      procedure :: netlist => brake_netlist_text
      procedure :: settings_warning => brake_settings_warning
      procedure :: verifies => brake_verifies
      procedure :: resolved
   end type brake_scene

contains

   function brake_name(self) result(name)
      class(brake_scene), intent(in) :: self
      character(len=:), allocatable :: name

      name = 'brake'
   end function brake_name

   subroutine brake_groups(self, names)
      class(brake_scene), intent(in) :: self
      character(len=32), allocatable, intent(out) :: names(:)

      names = [character(len=32) :: 'integrator', 'brake', 'brake_dimensional', 'verify', 'analysis']
      ! &law is the friction of model = 'law' only (the others' files are as before).
      if (self%config%uses_law()) names = [character(len=32) :: names, 'law']
   end subroutine brake_groups

   subroutine brake_visit(self, v)
      class(brake_scene), intent(inout) :: self
      type(parameter_visitor), intent(inout) :: v

      call self%config%visit(v)
   end subroutine brake_visit

   subroutine brake_check_values(self, checker)
      class(brake_scene), intent(in) :: self
      type(config_checker), intent(inout) :: checker

      call self%config%validate(checker)
   end subroutine brake_check_values

   !> The settings that run: the parameters of Eq. 10 derived from the
   !> dimensional data (units = 'dimensional'), and method = 'auto' resolved
   !> to the stepper the work-precision charts show fastest for the model.
   !> The configuration must have passed its checks.
   function resolved(self) result(c)
      class(brake_scene), intent(in) :: self
      type(brake_config) :: c
      type(error_type), allocatable :: error

      c = self%config
      call c%resolve(error)   ! (cannot fail on checked settings)
      if (c%solver%method == auto_name) c%solver%method = c%auto_method()
   end function resolved

   function brake_method(self) result(name)
      class(brake_scene), intent(in) :: self
      character(len=:), allocatable :: name
      type(brake_config) :: c

      c = self%resolved()
      name = trim(c%solver%method)
   end function brake_method

   subroutine brake_run_scene(self, job, reporter, error)
      class(brake_scene), intent(inout) :: self
      type(job_context), intent(in) :: job
      class(job_reporter), intent(inout) :: reporter
      type(error_type), allocatable, intent(out) :: error
      type(brake_run), target :: check_run
      type(brake_config) :: check_config
      type(error_type), allocatable :: check_error
      integer :: check_rank
      real(wp) :: wall, stick_time
      integer(i8) :: counts(4)

      self%ran = self%resolved()
      associate (settings => self%ran, check => self%check_record, record => self%record, &
         & main_run => self%main_run)
         check%enabled = settings%verify%enabled
         check_rank = merge(1, 0, job%nranks > 1)
         if (job%rank == 0) call integrate_brake(main_run, settings, reporter, error)
         if (check%enabled) then
            check_config = settings%check_settings()
            if (job%rank == check_rank) then
               if (check_rank == 0) then
                  call integrate_brake(check_run, check_config, reporter, check_error)
               else
                  block
                     type(job_reporter) :: silent
                     call integrate_brake(check_run, check_config, silent, check_error)
                  end block
               end if
            end if
            if (allocated(check_error) .and. .not. allocated(error)) then
               call move_alloc(check_error, error)
               error%message = 'verify run: '//error%message
            end if
         end if
         call agree_on_error(job, error)
         if (allocated(error)) return

         call share_brake_run(job, main_run, 0, settings%grid_size(), counts, record%compute_time, stick_time)
         record%stats = integrator_statistics(counts(1), counts(2), counts(3), counts(4))
         record%stick_time = stick_time
         if (check%enabled) then
            call share_brake_run(job, check_run, check_rank, settings%grid_size(), counts, check%compute_time, &
               & stick_time)
            check%stats = integrator_statistics(counts(1), counts(2), counts(3), counts(4))
            check%config = check_config
            check%comparison = compare_runs(main_run, check_run)
            associate (d => check%comparison, c => check_config%solver)
               if (job%rank == 0) then
                  call reporter%note('verify: '//trim(c%method)//' at rtol '//etoa(c%rtol, 2)//', atol ' &
                     & //etoa(c%atol, 2)//': max |dx| = '//etoa(d%max_difference(1), 2)//' m over the grid; events ' &
                     & //itoa(d%events)//' vs '//itoa(d%check_events))
               end if
               if (settings%verify%max_difference > 0.0_wp .and. &
                  & .not. (d%max_difference(1) <= settings%verify%max_difference)) then
                  call fatal_error(error, 'verify failed: the check run differs by '//etoa(d%max_difference(1), 2) &
                     & //' m in x, more than check_limit = '//etoa(settings%verify%max_difference, 2) &
                     & //' m (docs/speed.md, which steppers need verify)', error_numerical)
                  return
               end if
            end associate
         end if

         ! The diagnostics are deterministic functions of the shared run (and, for
         ! Benettin, of the settings): every rank computes the same numbers, so
         ! the file does not depend on the number of ranks.
         associate (a => settings%analysis)
            self%analysing = a%spectrum .or. a%poincare .or. a%lyapunov .or. a%rosenstein .or. a%lyapunov_spectrum &
               & .or. a%orbit
         end associate
         if (self%analysing) then
            ! A stop request or max_wall_time may end the long loops on some
            ! ranks sooner than on others: they agree before going on.
            call diagnose_brake(settings, main_run%trajectory, main_run%events, self%diagnostics, error, reporter)
            call agree_on_error(job, error)
            if (allocated(error)) return
         end if

         wall = job_wall_time(job)
         record%input_text = job%input_text
         record%version = version_string
         record%nranks = job%nranks
         record%wall_time = wall
      end associate
   end subroutine brake_run_scene

   subroutine brake_write(self, path, job, error)
      class(brake_scene), intent(inout) :: self
      character(len=*), intent(in) :: path
      type(job_context), intent(in) :: job
      type(error_type), allocatable, intent(out) :: error

      if (self%analysing) then
         call write_brake_file(path, job%comm, self%ran, self%main_run%trajectory, self%main_run%events, &
            & self%record, self%check_record, error, self%diagnostics)
      else
         call write_brake_file(path, job%comm, self%ran, self%main_run%trajectory, self%main_run%events, &
            & self%record, self%check_record, error)
      end if
   end subroutine brake_write

   function brake_summary(self, job) result(text)
      class(brake_scene), intent(in) :: self
      type(job_context), intent(in) :: job
      character(len=:), allocatable :: text
      character(len=240) :: line
      character(len=12) :: seconds

      write (seconds, '(f12.3)') self%record%wall_time
      write (line, '(a, i0, a)') ' model, ', self%main_run%n, ' points to τ = ' &
         & //fixed_text(self%ran%grid_time(self%main_run%n), 1)
      write (line, '(a, a, i0, a)') trim(line), ', ', self%main_run%events%n, ' events, '
      text = trim(self%ran%model)//trim(line)//' '//trim(adjustl(seconds))//' s '//ranks_text(job%nranks)
   end function brake_summary

   function brake_point_results(self) result(results)
      class(brake_scene), intent(in) :: self
      type(point_result), allocatable :: results(:)

      results = [point_result('events', '1', .true.), point_result('peak_frequency', '1/tau', .false.), &
         & point_result('lyapunov', '1/tau', .false.), point_result('stick_fraction', '1', .false.), &
         & point_result('orbit_found', '1', .true.), point_result('orbit_period', 'tau', .false.), &
         & point_result('orbit_max_multiplier', '1', .false.), point_result('orbit_critical_real', '1', .false.), &
         & point_result('orbit_critical_imag', '1', .false.)]
   end function brake_point_results

   subroutine brake_point_series(self, name, unit)
      class(brake_scene), intent(in) :: self
      character(len=:), allocatable, intent(out) :: name, unit

      name = 'maxima'
      unit = 'm'
   end subroutine brake_point_series

   !> A sweep point: the run, its diagnostics, its periodic orbit (found,
   !> period, the largest |μ| and the critical μ; NaN where no orbit was
   !> found or none was asked, as the machine's: 0 is the multiplier of an
   !> orbit through stick) and the local maxima of x after the transient
   !> (the bifurcation diagram).  (A brake point keeps nothing in `memory`:
   !> its set-up costs nothing.)
   subroutine brake_run_point(self, sink, memory, error, reporter)
      class(brake_scene), intent(inout) :: self
      class(result_sink), intent(inout) :: sink
      type(point_memory), intent(inout) :: memory
      type(error_type), allocatable, intent(out) :: error
      class(job_reporter), intent(inout), optional :: reporter
      real(wp) :: results(9)
      type(brake_config) :: point
      type(brake_run), target :: run
      type(brake_diagnostics) :: diagnostics
      type(job_reporter) :: silent
      logical, allocatable :: peak(:)
      integer :: j

      results = 0.0_wp
      results(6:9) = ieee_value(1.0_wp, ieee_quiet_nan)
      point = self%resolved()
      ! A sweep point reports no spectrum: skip its cost.
      point%analysis%lyapunov_spectrum = .false.
      call integrate_brake(run, point, silent, error)
      if (allocated(error)) return
      associate (a => point%analysis)
         if (a%spectrum .or. a%lyapunov .or. a%orbit) then
            ! A point is one run: the orbit is not continued from another point's.
            point%analysis%continuation = ''
            call diagnose_brake(point, run%trajectory, run%events, diagnostics, error)
            if (allocated(error)) return
            if (a%spectrum) results(2) = diagnostics%spectrum%peak_frequency
            if (a%lyapunov) results(3) = diagnostics%flow%current()
            if (diagnostics%orbit%orbit%found) then
               ! The section map's multiplier of largest modulus (the critical one).
               associate (o => diagnostics%orbit)
                  results(5:9) = [1.0_wp, o%orbit%period, abs(o%multipliers(2)), real(o%multipliers(2)), &
                     & aimag(o%multipliers(2))]
               end associate
            end if
         end if
         results(1) = run%events%n
         results(4) = run%stick_time() / (point%t_end - point%t_start)
         allocate (peak(run%n), source=.false.)
         associate (t => run%trajectory%t, x => run%trajectory%x)
            do j = 2, run%n - 1
               peak(j) = t(j) >= a%window_start .and. x(j) > x(j - 1) .and. x(j) >= x(j + 1)
            end do
            call self%put_point(sink, results, pack(x(1:run%n), peak))
         end associate
      end associate
   end subroutine brake_run_point

   !> The creep band's warning and the stepper's (brake_config%creep_band_warning,
   !> %stepper_warning) for the resolved settings, one after the other.
   logical function brake_verifies(self)
      class(brake_scene), intent(in) :: self

      brake_verifies = self%config%verify%enabled
   end function brake_verifies

   function brake_settings_warning(self) result(text)
      class(brake_scene), intent(in) :: self
      character(len=:), allocatable :: text
      character(len=:), allocatable :: stepper
      type(brake_config) :: resolved

      resolved = self%resolved()
      text = resolved%creep_band_warning()
      stepper = resolved%stepper_warning()
      if (len(text) > 0 .and. len(stepper) > 0) then
         text = text//'; and '//stepper
      else if (len(stepper) > 0) then
         text = stepper
      end if
   end function brake_settings_warning

   !> The brake's trajectory and events on this process, as the program's
   !> file holds them under /brake.
   subroutine brake_compute(self, sink, memory, reporter, error)
      class(brake_scene), intent(inout) :: self
      class(result_sink), intent(inout) :: sink
      type(point_memory), intent(inout) :: memory
      class(job_reporter), intent(inout) :: reporter
      type(error_type), allocatable, intent(out) :: error
      type(brake_run), target :: run
      integer :: n, k

      call integrate_brake(run, self%resolved(), reporter, error, &
         & lost='no result (a trajectory keeps no checkpoints; compute it again)')
      if (allocated(error)) return
      n = run%n
      associate (r => run%trajectory)
         call sink%add('t', n, 1, r%t(1:n))
         call sink%add('x', n, 1, r%x(1:n))
         call sink%add('v', n, 1, r%v(1:n))
         call sink%add('y', n, 1, r%y(1:n))
         call sink%add('w', n, 1, r%w(1:n))
         call sink%add('stick', n, 1, real(r%stick(1:n), wp))
      end associate
      n = run%events%n
      if (n == 0) then
         ! (The event table's arrays may not exist without events.)
         call sink%add('events/t', 0, 1, [real(wp) ::])
         call sink%add('events/kind', 0, 1, [real(wp) ::])
         do k = 1, 4
            call sink%add('events/'//'xvyw'(k:k), 0, 1, [real(wp) ::])
         end do
         return
      end if
      call sink%add('events/t', n, 1, run%events%t(1:n))
      call sink%add('events/kind', n, 1, real(run%events%kind(1:n), wp))
      do k = 1, 4
         call sink%add('events/'//'xvyw'(k:k), n, 1, run%events%state(k, 1:n))
      end do
   end subroutine brake_compute

   subroutine brake_netlist_text(self, data_file, version, text, note, error, origins)
      class(brake_scene), intent(in) :: self
      character(len=*), intent(in) :: data_file, version
      character(len=:), allocatable, intent(out) :: text, note
      type(error_type), allocatable, intent(out) :: error
      type(config_checker), intent(in), optional :: origins

      call brake_netlist(self%resolved(), data_file, version, text, note, error, origins)
   end subroutine brake_netlist_text

   !> One brake run, in pieces so that long runs can report progress in τ,
   !> and stop between them when asked (Ctrl-C, friction_job_stop, a C API
   !> progress function): a trajectory has no checkpoints, so nothing is
   !> written then.  `lost` ends the message of a stop (default: that no
   !> file was written).
   subroutine integrate_brake(run, settings, reporter, error, lost)
      type(brake_run), target, intent(inout) :: run
      type(brake_config), intent(in) :: settings
      class(job_reporter), intent(inout) :: reporter
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in), optional :: lost
      character(len=:), allocatable :: tail
      integer :: piece, last

      call run%init(settings, error)
      if (allocated(error)) return
      piece = max(1, run%n / 200)
      do last = piece, run%n + piece - 1, piece
         call run%run_until(min(last, run%n), error)
         if (allocated(error)) return
         call reporter%progress(run%time_reached() - settings%t_start, settings%t_end - settings%t_start, &
            & 'tau', .false.)
         if (last < run%n .and. reporter%stop_requested()) then
            tail = 'no file written (a trajectory keeps no checkpoints; run it again)'
            if (present(lost)) tail = lost
            call fatal_error(error, 'brake run stopped on request at τ = '//fixed_text(run%time_reached(), 1) &
               & //' of '//fixed_text(settings%t_end, 1)//': '//tail, error_interrupted)
            return
         end if
      end do
      call reporter%progress(run%time_reached() - settings%t_start, settings%t_end - settings%t_start, &
         & 'tau', .true.)
   end subroutine integrate_brake

   !> Give every rank root's trajectory, events and counters.
   subroutine share_brake_run(job, run, root, n, counts, compute_time, stick_time)
      type(job_context), intent(in) :: job
      type(brake_run), intent(inout) :: run
      integer, intent(in) :: root, n
      integer(i8), intent(out) :: counts(4)
      real(wp), intent(out) :: compute_time, stick_time
      type(integrator_statistics) :: stats
      integer :: n_events
      real(wp) :: times(2)

      if (job%rank == root) then
         stats = run%statistics()
         counts = [stats%steps, stats%failed_steps, stats%rhs_evaluations, stats%jacobian_evaluations]
         times = [run%compute_time, run%stick_time()]
         n_events = run%events%n
         if (.not. job%parallel()) then   ! serial: root is this process, which holds the run
            compute_time = times(1)
            stick_time = times(2)
            return
         end if
      else
         call run%trajectory%allocate_points(n)
         run%n = n
         run%done = n
      end if
      call broadcast(job%comm, counts, root)
      call broadcast(job%comm, times, root)
      call broadcast(job%comm, n_events, root)
      compute_time = times(1)
      stick_time = times(2)
      call broadcast(job%comm, run%trajectory%t(1:n), root)
      call broadcast(job%comm, run%trajectory%x(1:n), root)
      call broadcast(job%comm, run%trajectory%v(1:n), root)
      call broadcast(job%comm, run%trajectory%y(1:n), root)
      call broadcast(job%comm, run%trajectory%w(1:n), root)
      call broadcast(job%comm, run%trajectory%stick(1:n), root)
      if (job%rank /= root) then
         run%events%n = n_events
         if (allocated(run%events%t)) deallocate (run%events%t, run%events%kind, run%events%state)
         allocate (run%events%t(max(1, n_events)), run%events%kind(max(1, n_events)), &
            & run%events%state(4, max(1, n_events)))
      end if
      if (n_events > 0) then
         call broadcast(job%comm, run%events%t(1:n_events), root)
         call broadcast(job%comm, run%events%kind(1:n_events), root)
         call broadcast(job%comm, run%events%state(:, 1:n_events), root)
      end if
   end subroutine share_brake_run

end module friction_brake_scene
