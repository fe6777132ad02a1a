!> The machine as a scene (docs/laws.md, "Mechanisms"): one degree of
!> freedom with any friction law, the belt oscillator and the spring-slider.
!> Every rank integrates the same run (it is deterministic and short), so
!> the file does not depend on the number of ranks and nothing is broadcast.
module friction_machine_scene
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
   use friction_kinds, only: wp, i8
   use friction_strings, only: fixed_text
   use friction_error, only: error_type, fatal_error, error_input
   use friction_version, only: version_string
   use friction_clock, only: wall_seconds
   use friction_parameters, only: parameter_visitor
   use friction_checks, only: config_checker
   use friction_scene, only: scene, point_result, point_memory, result_sink
   use friction_scene_report, only: job_reporter
   use friction_scene_context, only: job_context, agree_on_error, ranks_text, job_wall_time
   use friction_machine_config, only: machine_config
   use friction_machine_run, only: machine_run, run_machine, machine_watch
   use friction_ode_watch, only: step_watch
   use friction_machine_output, only: machine_summary, write_machine_file
   use friction_machine_diagnostics, only: machine_diagnostics, diagnose_machine
   implicit none
   private

   public :: machine_scene

   type, extends(scene) :: machine_scene
      type(machine_config) :: config
      type(machine_run), private :: result
      type(machine_summary), private :: record
      type(machine_diagnostics), private :: diagnostics
   contains
      procedure :: name => machine_name
      procedure :: groups => machine_groups
      procedure :: visit => machine_visit
      procedure :: check => machine_check
      procedure :: method => machine_method
      procedure :: run => machine_run_scene
      procedure :: write_output => machine_write
      procedure :: summary => machine_summary_text
      procedure :: point_results => machine_point_results
      procedure :: point_series => machine_point_series
      procedure :: run_point => machine_run_point
      procedure :: compute => machine_compute
      procedure :: netlist => machine_netlist
   end type machine_scene

contains

   function machine_name(self) result(name)
      class(machine_scene), intent(in) :: self
      character(len=:), allocatable :: name

      name = 'machine'
   end function machine_name

   subroutine machine_groups(self, names)
      class(machine_scene), intent(in) :: self
      character(len=32), allocatable, intent(out) :: names(:)

      names = [character(len=32) :: 'integrator', 'machine', 'law', 'analysis']
   end subroutine machine_groups

   subroutine machine_visit(self, v)
      class(machine_scene), intent(inout) :: self
      type(parameter_visitor), intent(inout) :: v

      call self%config%visit(v)
   end subroutine machine_visit

   subroutine machine_check(self, checker)
      class(machine_scene), intent(in) :: self
      type(config_checker), intent(inout) :: checker

      call self%config%validate(checker)
   end subroutine machine_check

   function machine_method(self) result(name)
      class(machine_scene), intent(in) :: self
      character(len=:), allocatable :: name

      name = trim(self%config%solver%method)
   end function machine_method

   subroutine machine_run_scene(self, job, reporter, error)
      class(machine_scene), intent(inout) :: self
      type(job_context), intent(in) :: job
      class(job_reporter), intent(inout) :: reporter
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: start
      class(step_watch), allocatable :: watch

      start = wall_seconds()
      ! Stop requests and max_wall_time reach the integration between its steps (a stiff law
      ! can crawl through one output interval), and the diagnostics' from their start.
      allocate (watch, source=machine_watch(self%config, 'the run', reporter))
      call run_machine(self%config, self%result, error, watch)
      self%record%compute_time = wall_seconds() - start
      if (.not. allocated(error)) then
         deallocate (watch)
         if (self%config%analysis%orbit .and. .not. (self%config%analysis%lyapunov .or. &
            & self%config%analysis%lyapunov_spectrum)) then
            allocate (watch, source=machine_watch(self%config, '&analysis: the periodic orbit', reporter))
         else
            allocate (watch, source=machine_watch(self%config, '&analysis: the Lyapunov '//trim(merge('exponent (Benettin)', &
               & 'spectrum           ', self%config%analysis%lyapunov .or. .not. self%config%analysis%lyapunov_spectrum)), &
               & reporter))
         end if
         call diagnose_machine(self%config, self%result, self%diagnostics, error, watch)
      end if
      call agree_on_error(job, error)
      if (allocated(error)) return
      call reporter%progress(self%config%t_end - self%config%t_start, self%config%t_end - self%config%t_start, &
         & 's', .true.)
      self%record%stats = self%result%stats
      self%record%input_text = job%input_text
      self%record%version = version_string
      self%record%nranks = job%nranks
      self%record%wall_time = job_wall_time(job)
   end subroutine machine_run_scene

   subroutine machine_write(self, path, job, error)
      class(machine_scene), intent(inout) :: self
      character(len=*), intent(in) :: path
      type(job_context), intent(in) :: job
      type(error_type), allocatable, intent(out) :: error

      call write_machine_file(path, job%comm, self%config, self%result, self%record, self%diagnostics, error)
   end subroutine machine_write

   function machine_summary_text(self, job) result(text)
      class(machine_scene), intent(in) :: self
      type(job_context), intent(in) :: job
      character(len=:), allocatable :: text
      character(len=200) :: line

      write (line, '(a, i0, a, i0, a)') trim(self%config%law%model)//' law, ', self%result%n, &
         & ' points to t = '//fixed_text(self%config%t_end, 2)//' s, ', self%result%n_events, ' events, ' &
         & //fixed_text(self%record%wall_time, 3)//' s'
      text = trim(line)//' '//ranks_text(job%nranks)
   end function machine_summary_text

   function machine_point_results(self) result(results)
      class(machine_scene), intent(in) :: self
      type(point_result), allocatable :: results(:)

      results = [point_result('events', '1', .true.), point_result('stick_fraction', '1', .false.), &
         & point_result('velocity_range', 'm/s', .false.), point_result('force_mean', 'N', .false.), &
         & point_result('peak_frequency', 'Hz', .false.), point_result('lyapunov', '1/s', .false.), &
         & point_result('orbit_found', '1', .true.), point_result('orbit_period', 's', .false.), &
         & point_result('orbit_max_multiplier', '1', .false.), point_result('orbit_critical_real', '1', .false.), &
         & point_result('orbit_critical_imag', '1', .false.)]
   end function machine_point_results

   subroutine machine_point_series(self, name, unit)
      class(machine_scene), intent(in) :: self
      character(len=:), allocatable, intent(out) :: name, unit

      name = 'maxima'
      unit = 'm'
   end subroutine machine_point_series

   !> A sweep point: the run's events, the fraction of the output grid in
   !> stick, the range of the velocity and the mean friction force over the
   !> second half of the run (after a transient), the spectrum's peak and
   !> Benettin's exponent when asked, the periodic orbit with &analysis
   !> orbit (found, period, the section map's largest |mu| and that
   !> multiplier; NaN where no orbit was found or none was asked, since 0 is
   !> a multiplier an orbit can have), and the local maxima of x in the
   !> second half (the bifurcation diagram).  The run and the diagnostics
   !> ask one watch, from the point's start: max_wall_time, and the stop
   !> requests of `reporter` if given (a point that crawls ends inside).
   subroutine machine_run_point(self, sink, memory, error, reporter)
      class(machine_scene), intent(inout) :: self
      class(result_sink), intent(inout) :: sink
      type(point_memory), intent(inout) :: memory
      type(error_type), allocatable, intent(out) :: error
      class(job_reporter), intent(inout), optional :: reporter
      real(wp) :: results(11)
      type(machine_run) :: run
      type(machine_diagnostics) :: d
      class(step_watch), allocatable :: watch
      logical, allocatable :: peak(:)
      integer :: j, half

      results = 0.0_wp
      results(8:11) = ieee_value(1.0_wp, ieee_quiet_nan)
      allocate (watch, source=machine_watch(self%config, 'the sweep point', reporter))
      call run_machine(self%config, run, error, watch)
      if (allocated(error)) return
      half = run%n / 2 + 1
      results(1) = run%n_events
      results(2) = real(count(run%stick(half:) == 1), wp) / real(run%n - half + 1, wp)
      results(3) = maxval(run%v(half:)) - minval(run%v(half:))
      results(4) = sum(run%force(half:)) / real(run%n - half + 1, wp)
      ! A point's results need neither the Poincaré maps, the whole spectrum nor Rosenstein's exponent:
      ! not computed there;
      ! a point is one run: its orbit (if asked) is not followed along a line.
      block
         type(machine_config) :: point
         point = self%config
         point%analysis%poincare = .false.
         point%analysis%lyapunov_spectrum = .false.
         point%analysis%rosenstein = .false.
         point%analysis%continuation = ''
         call diagnose_machine(point, run, d, error, watch)
      end block
      if (allocated(error)) return
      if (d%spectrum) results(5) = d%peak%peak_frequency
      if (d%lyapunov) results(6) = d%flow%current()
      if (d%orbit) then
         associate (o => d%periodic%orbit)
            if (o%found .and. size(o%multipliers) > 0) then
               ! The section map's multipliers come by decreasing modulus: the first is the critical one.
               results(7:11) = [1.0_wp, o%period, abs(o%multipliers(1)), real(o%multipliers(1)), &
                  & aimag(o%multipliers(1))]
            end if
         end associate
      end if
      allocate (peak(run%n), source=.false.)
      do j = max(2, half), run%n - 1
         peak(j) = run%x(j) > run%x(j - 1) .and. run%x(j) >= run%x(j + 1)
      end do
      call self%put_point(sink, results, pack(run%x, peak))
   end subroutine machine_run_point

   !> The run on this process into named arrays, as /machine holds them:
   !> "t", "x", "v", "force", "stick", the law's states ("z", "theta", "z1"
   !> ... "zN") if it has any, and "events/t", "events/kind", "events/x", "events/v".
   subroutine machine_compute(self, sink, memory, reporter, error)
      class(machine_scene), intent(inout) :: self
      class(result_sink), intent(inout) :: sink
      type(point_memory), intent(inout) :: memory
      class(job_reporter), intent(inout) :: reporter
      type(error_type), allocatable, intent(out) :: error
      type(machine_run) :: run
      class(step_watch), allocatable :: watch
      integer :: n, k

      allocate (watch, source=machine_watch(self%config, 'the run', reporter))
      call run_machine(self%config, run, error, watch)
      if (allocated(error)) return
      call reporter%progress(self%config%t_end - self%config%t_start, self%config%t_end - self%config%t_start, &
         & 's', .true.)
      call sink%add('t', run%n, 1, run%t)
      call sink%add('x', run%n, 1, run%x)
      call sink%add('v', run%n, 1, run%v)
      call sink%add('force', run%n, 1, run%force)
      call sink%add('stick', run%n, 1, real(run%stick, wp))
      do k = 1, run%n_states
         call sink%add(trim(run%state_names(k)), run%n, 1, run%states(k, :))
      end do
      n = run%n_events
      call sink%add('events/t', n, 1, run%event_t(1:n))
      call sink%add('events/kind', n, 1, real(run%event_kind(1:n), wp))
      call sink%add('events/x', n, 1, run%event_x(1:n))
      call sink%add('events/v', n, 1, run%event_v(1:n))
   end subroutine machine_compute

   !> No circuit form: the laws with states and the exact stick have no
   !> SPICE element here.
   subroutine machine_netlist(self, data_file, version, text, note, error, origins)
      class(machine_scene), intent(in) :: self
      character(len=*), intent(in) :: data_file, version
      character(len=:), allocatable, intent(out) :: text, note
      type(error_type), allocatable, intent(out) :: error
      type(config_checker), intent(in), optional :: origins

      type(config_checker) :: refusal

      text = ''
      note = ''
      ! Named where &job scene was set, as an input error is.
      if (present(origins)) refusal = origins
      if (allocated(refusal%error)) deallocate (refusal%error)
      call refusal%reject('job', 'scene', "'machine'", "--netlist: no netlist: the friction laws at the machine " &
         & //"scale have no circuit form in this program (the brake's has one: &job scene = 'brake')")
      call move_alloc(refusal%error, error)
   end subroutine machine_netlist

end module friction_machine_scene
