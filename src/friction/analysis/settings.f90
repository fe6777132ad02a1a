!> What a user chooses about the chaos diagnostics (docs/input.md, &analysis), in
!> the units of the scene's time.  Scene-independent: a scene maps `series`
!> to one of its variables and `section` to one of its sections.
module friction_analysis_settings
   use friction_kinds, only: wp
   use friction_analysis_spectrum, only: window_hann
   use friction_error, only: error_type
   use friction_analysis_lyapunov_series, only: rosenstein_settings, rosenstein_result, rosenstein_exponent
   use friction_strings, only: itoa, rtoa, quoted
   use friction_parameters, only: parameter_visitor
   use friction_checks, only: config_checker
   implicit none
   private

   public :: analysis_settings, section_names

   !> The most renormalisation intervals a Lyapunov estimate may take, and
   !> the most points a continuation may follow (both: hours to days of work).
   real(wp), parameter :: max_renormalisations = 1.0e7_wp
   integer, parameter :: max_continuation_points = 100000
   !> The most Newton steps a periodic orbit may take.
   integer, parameter :: max_newton_steps = 1000
   !> The largest separation Benettin's two runs may start at.
   real(wp), parameter :: max_separation = 1.0e-3_wp

   character(len=*), parameter :: section_names(3) = [character(len=13) :: 'none', 'stick_to_slip', 'w_zero_up']

   type :: analysis_settings
      ! Spectrum (Fig. 13)
      logical :: spectrum = .false.
      character(len=8) :: series = 'x'             !! the variable analysed (spectrum, Rosenstein)
      real(wp) :: window_start = 100.0_wp          !! analysis window in time (spectrum, Rosenstein)
      real(wp) :: window_end = 1000.0_wp
      character(len=8) :: window = window_hann     !! 'hann' or 'none'
      integer :: welch_segments = 1                !! half-overlapping segments averaged
      ! Poincaré maps (Fig. 14)
      logical :: poincare = .false.
      real(wp) :: strobe_period = 0.0_wp           !! 0: 1 / peak frequency of the spectrum
      real(wp) :: strobe_start = 0.0_wp
      real(wp) :: strobe_end = 0.0_wp              !! 0: the end of the run
      character(len=16) :: section = 'stick_to_slip'
      ! Maximum Lyapunov exponent from the equations (Benettin)
      logical :: lyapunov = .false.
      real(wp) :: lyapunov_transient = 100.0_wp    !! from the start of the run
      real(wp) :: lyapunov_duration = 0.0_wp       !! 0: to the end of the run
      real(wp) :: lyapunov_renormalise = 1.0_wp
      real(wp) :: lyapunov_d0 = 1.0e-8_wp
      ! The whole spectrum from the tangent equations (QR)
      logical :: lyapunov_spectrum = .false.
      real(wp) :: lyapunov_spectrum_transient = 100.0_wp    !! from the start of the run
      real(wp) :: lyapunov_spectrum_duration = 0.0_wp       !! 0: to the end of the run
      real(wp) :: lyapunov_spectrum_renormalise = 1.0_wp    !! between QR factorisations
      ! Periodic orbit by Newton shooting on the section (Floquet multipliers)
      logical :: orbit = .false.
      real(wp) :: orbit_transient = 100.0_wp       !! Newton starts from the first section point after it
      real(wp) :: orbit_tolerance = 1.0e-9_wp      !! max |P(s) - s| accepted, in the section's units
      integer :: orbit_max_iterations = 20         !! Newton steps
      ! ... followed along a line of one variable of the scene (the branch)
      character(len=24) :: continuation = ''        !! the variable varied; '' for none
      real(wp) :: continuation_end = 0.0_wp         !! its value at the end of the line
      integer :: continuation_points = 11           !! points on the line, both ends included
      ! ... and from the series (Rosenstein); lengths in samples of the strided series
      logical :: rosenstein = .false.
      integer :: rosenstein_stride = 4
      integer :: rosenstein_dimension = 4
      integer :: rosenstein_delay = 8
      integer :: rosenstein_theiler = 35
      integer :: rosenstein_horizon = 150
      integer :: rosenstein_fit_start = 0
      integer :: rosenstein_fit_end = 50
   contains
      procedure :: visit
      procedure :: validate
      procedure :: rosenstein_of
   end type analysis_settings

contains

   !> Rosenstein's exponent of a scene's window series sampled every `dt`,
   !> strided by rosenstein_stride (the strided spacing in `spacing`), with
   !> these settings; an error says which settings the series is too short for.
   subroutine rosenstein_of(self, window_series, dt, result, spacing, error)
      class(analysis_settings), intent(in) :: self
      real(wp), intent(in) :: window_series(:), dt
      type(rosenstein_result), intent(out) :: result
      real(wp), intent(out) :: spacing
      type(error_type), allocatable, intent(out) :: error

      spacing = dt * self%rosenstein_stride
      call rosenstein_exponent(window_series(1::self%rosenstein_stride), spacing, &
         & rosenstein_settings(dimension=self%rosenstein_dimension, delay=self%rosenstein_delay, &
         & theiler=self%rosenstein_theiler, horizon=self%rosenstein_horizon, &
         & fit_start=self%rosenstein_fit_start, fit_end=self%rosenstein_fit_end), result, error)
      if (allocated(error)) error%message = '&analysis: '//error%message//' (the window [window_start, ' &
         & //'window_end] strided by rosenstein_stride against the embedding and rosenstein_horizon)'
   end subroutine rosenstein_of

   !> The group &analysis; `time_unit` is the unit of the scene's time.
   subroutine visit(self, v, time_unit)
      class(analysis_settings), intent(inout) :: self
      type(parameter_visitor), intent(inout) :: v
      character(len=*), intent(in) :: time_unit

      call v%begin_group('analysis')
      call v%item('spectrum', self%spectrum)
      call v%item('series', self%series, fold=.true.)
      call v%item('window_start', self%window_start, time_unit)
      call v%item('window_end', self%window_end, time_unit)
      call v%item('window', self%window, fold=.true.)
      call v%item('welch_segments', self%welch_segments)
      call v%item('poincare', self%poincare)
      call v%item('strobe_period', self%strobe_period, time_unit)
      call v%item('strobe_start', self%strobe_start, time_unit)
      call v%item('strobe_end', self%strobe_end, time_unit)
      call v%item('section', self%section, fold=.true.)
      call v%item('lyapunov', self%lyapunov)
      call v%item('lyapunov_transient', self%lyapunov_transient, time_unit)
      call v%item('lyapunov_duration', self%lyapunov_duration, time_unit)
      call v%item('lyapunov_renormalise', self%lyapunov_renormalise, time_unit)
      call v%item('lyapunov_d0', self%lyapunov_d0)
      call v%item('lyapunov_spectrum', self%lyapunov_spectrum)
      call v%item('lyapunov_spectrum_transient', self%lyapunov_spectrum_transient, time_unit)
      call v%item('lyapunov_spectrum_duration', self%lyapunov_spectrum_duration, time_unit)
      call v%item('lyapunov_spectrum_renormalise', self%lyapunov_spectrum_renormalise, time_unit)
      call v%item('orbit', self%orbit)
      call v%item('orbit_transient', self%orbit_transient, time_unit)
      call v%item('orbit_tolerance', self%orbit_tolerance, 'm')
      call v%item('orbit_max_iterations', self%orbit_max_iterations)
      call v%item('continuation', self%continuation, fold=.true.)
      call v%item('continuation_end', self%continuation_end)
      call v%item('continuation_points', self%continuation_points)
      call v%item('rosenstein', self%rosenstein)
      call v%item('rosenstein_stride', self%rosenstein_stride, 'samples')
      call v%item('rosenstein_dimension', self%rosenstein_dimension)
      call v%item('rosenstein_delay', self%rosenstein_delay, 'samples')
      call v%item('rosenstein_theiler', self%rosenstein_theiler, 'samples')
      call v%item('rosenstein_horizon', self%rosenstein_horizon, 'samples')
      call v%item('rosenstein_fit_start', self%rosenstein_fit_start, 'samples')
      call v%item('rosenstein_fit_end', self%rosenstein_fit_end, 'samples')
      call v%end_group()
   end subroutine visit

   !> The diagnostics' settings over a run from t_start to t_end sampled
   !> every `dt` (if given); `series` names the scene's variables that can
   !> be analysed.
   !> `strobe_known`: the scene has the strobe period without the spectrum
   !> (the machine's moving support); `series_points`: the fewest output
   !> points in the window the spectrum and Rosenstein's series take (16);
   !> `run_group`: the group of t_start, t_end and dt_out, so that a default
   !> refused against them names the line that set them.
   subroutine validate(self, c, t_start, t_end, series, dt, strobe_known, series_points, run_group)
      class(analysis_settings), intent(in) :: self
      type(config_checker), intent(inout) :: c
      real(wp), intent(in) :: t_start, t_end
      character(len=*), intent(in) :: series(:)
      real(wp), intent(in), optional :: dt
      logical, intent(in), optional :: strobe_known
      integer, intent(in), optional :: series_points
      character(len=*), intent(in), optional :: run_group
      character(len=64) :: run(3), tools(2)
      real(wp) :: samples
      integer :: need, points
      logical :: strobe_given
      character(len=:), allocatable :: what

      ! (Without a group the names are blank, which the checker skips.)
      run = ''
      if (present(run_group)) then
         run(1) = run_group//'.t_end'
         run(2) = run_group//'.t_start'
         run(3) = run_group//'.dt_out'
      end if
      if (.not. any(series == self%series)) call c%reject('analysis', 'series', "'"//trim(self%series)//"'", &
         & 'unknown variable (known: '//quoted(series)//')')
      if (self%window /= 'hann' .and. self%window /= 'none') call c%reject('analysis', 'window', &
         & "'"//trim(self%window)//"'", "unknown window (known: 'hann', 'none')")
      if (.not. any(section_names == self%section)) call c%reject('analysis', 'section', &
         & "'"//trim(self%section)//"'", 'unknown section (known: '//quoted(section_names)//')')
      call c%finite('analysis', 'window_start', self%window_start)
      if (.not. (self%window_end > self%window_start)) call c%reject('analysis', 'window_end', &
         & rtoa(self%window_end), 'must be after window_start = '//rtoa(self%window_start), &
         & against=partners(run, 'analysis.window_start'))
      if (self%welch_segments < 1) call c%reject('analysis', 'welch_segments', itoa(self%welch_segments), &
         & 'must be >= 1')
      ! K half-overlapping segments of the window's samples: each needs 8 (the
      ! spectrum's own check, which named no variable).
      strobe_given = .false.
      if (present(strobe_known)) strobe_given = strobe_known
      if (present(dt) .and. self%welch_segments > 1 .and. (self%spectrum .or. (self%poincare .and. &
         & self%strobe_period == 0.0_wp .and. .not. strobe_given))) then
         samples = (min(self%window_end, t_end) - max(self%window_start, t_start)) / dt + 1.0_wp
         if (samples > 0.0_wp .and. 2.0_wp * samples / (self%welch_segments + 1.0_wp) < 8.0_wp) &
            & call c%reject('analysis', 'welch_segments', itoa(self%welch_segments), 'leaves fewer than 8 ' &
            & //'samples a segment of the window [window_start, window_end] ('//itoa(int(samples)) &
            & //' samples); at most '//itoa(max(1, int(samples) / 4 - 1)), &
            & against=partners(run, 'run', 'analysis.window_start', 'analysis.window_end'))
      end if
      ! The window's output points, which the diagnostics counted only after the
      ! whole run, with a message that named no file (a run shorter than window_start).
      if (present(dt) .and. .not. c%failed()) then
         need = 0
         if (self%spectrum .or. self%rosenstein) need = 16
         if (present(series_points) .and. need > 0) need = series_points
         if (self%poincare .and. self%strobe_period == 0.0_wp .and. .not. strobe_given) need = 16
         points = window_points(self%window_start, self%window_end, t_start, t_end, dt)
         if (need > 0 .and. points < need) then
            what = 'the spectrum or Rosenstein''s series'
            if (.not. (self%spectrum .or. self%rosenstein)) what = 'the spectrum of the strobe period'
            ! The switches that need the window, last: with the whole window at its defaults, the line
            ! that asked for it.
            tools = ''
            if (self%spectrum) tools(1) = 'analysis.spectrum'
            if (self%rosenstein) tools(2) = 'analysis.rosenstein'
            if (.not. (self%spectrum .or. self%rosenstein)) tools(1) = 'analysis.poincare'
            if (self%window_end < t_end) then
               call c%reject('analysis', 'window_end', rtoa(self%window_end), window_text(), &
                  & against=partners(run, 'run', 'analysis.window_start', tools(1), tools(2)))
            else
               call c%reject('analysis', 'window_start', rtoa(self%window_start), window_text(), &
                  & against=partners(run, 'run', 'analysis.window_end', tools(1), tools(2)))
            end if
         end if
      end if
      call c%nonnegative('analysis', 'strobe_period', self%strobe_period, 'τ; 0 for 1 / peak frequency')
      call c%finite('analysis', 'strobe_start', self%strobe_start)
      call c%nonnegative('analysis', 'strobe_end', self%strobe_end, 'τ; 0 for the end of the run')
      call c%nonnegative('analysis', 'lyapunov_transient', self%lyapunov_transient, 'τ')
      call c%nonnegative('analysis', 'lyapunov_duration', self%lyapunov_duration, 'τ; 0 for the rest of the run')
      call c%positive('analysis', 'lyapunov_renormalise', self%lyapunov_renormalise, 'τ')
      call c%positive('analysis', 'lyapunov_d0', self%lyapunov_d0, 'initial separation')
      ! Benettin's separation is infinitesimal; 1e300 overflowed the perturbed
      ! run, which was then reported as the pad lifting off.
      if (self%lyapunov_d0 > max_separation) call c%reject('analysis', 'lyapunov_d0', rtoa(self%lyapunov_d0), &
         & 'must be <= '//rtoa(max_separation)//' (a small separation of the two runs; the motion itself is of ' &
         & //'order 1e-2)')
      if (self%lyapunov .and. self%lyapunov_duration == 0.0_wp .and. &
         & .not. (t_end - t_start - self%lyapunov_transient >= self%lyapunov_renormalise)) &
         & call c%reject('analysis', 'lyapunov_transient', rtoa(self%lyapunov_transient), &
         & 'leaves less than one renormalisation interval before t_end', &
         & against=partners(run, 'run', 'analysis.lyapunov_renormalise', 'analysis.lyapunov'))
      call c%nonnegative('analysis', 'lyapunov_spectrum_transient', self%lyapunov_spectrum_transient, 'τ')
      call c%nonnegative('analysis', 'lyapunov_spectrum_duration', self%lyapunov_spectrum_duration, &
         & 'τ; 0 for the rest of the run')
      call c%positive('analysis', 'lyapunov_spectrum_renormalise', self%lyapunov_spectrum_renormalise, 'τ')
      if (self%lyapunov_spectrum .and. self%lyapunov_spectrum_duration == 0.0_wp .and. &
         & .not. (t_end - t_start - self%lyapunov_spectrum_transient >= self%lyapunov_spectrum_renormalise)) &
         & call c%reject('analysis', 'lyapunov_spectrum_transient', rtoa(self%lyapunov_spectrum_transient), &
         & 'leaves less than one renormalisation interval before t_end', against=partners(run, 'run', &
         & 'analysis.lyapunov_spectrum_renormalise', 'analysis.lyapunov_spectrum'))
      if (self%lyapunov_spectrum .and. self%lyapunov_spectrum_duration > 0.0_wp .and. &
         & self%lyapunov_spectrum_duration < self%lyapunov_spectrum_renormalise) &
         & call c%reject('analysis', 'lyapunov_spectrum_duration', rtoa(self%lyapunov_spectrum_duration), &
         & 'shorter than one renormalisation interval, lyapunov_spectrum_renormalise = ' &
         & //rtoa(self%lyapunov_spectrum_renormalise), against=partners(run, 'analysis.lyapunov_spectrum_renormalise'))
      ! Each renormalisation is an integration of its own: a tiny interval
      ! makes the loop endless in practice (1e-300 ran for hours, 1e-13 too).
      if (self%lyapunov) call check_intervals('lyapunov_renormalise', self%lyapunov_renormalise, &
         & self%lyapunov_duration, self%lyapunov_transient, .false., 'lyapunov')
      ! (The spectrum's transient is integrated in renormalisation intervals too.)
      if (self%lyapunov_spectrum) call check_intervals('lyapunov_spectrum_renormalise', &
         & self%lyapunov_spectrum_renormalise, self%lyapunov_spectrum_duration, self%lyapunov_spectrum_transient, &
         & .true., 'lyapunov_spectrum')
      call c%nonnegative('analysis', 'orbit_transient', self%orbit_transient, 'τ')
      call c%positive('analysis', 'orbit_tolerance', self%orbit_tolerance, 'm and m per unit time')
      if (self%orbit_max_iterations < 1) call c%reject('analysis', 'orbit_max_iterations', &
         & itoa(self%orbit_max_iterations), 'must be >= 1')
      ! Each Newton step is a return to the section, up to the whole run long:
      ! Newton converges in tens where it converges at all.
      if (self%orbit_max_iterations > max_newton_steps) call c%reject('analysis', 'orbit_max_iterations', &
         & itoa(self%orbit_max_iterations), 'must be <= '//itoa(max_newton_steps)//' (Newton converges in ' &
         & //'tens of steps where it converges at all; each is a run to the section)')
      call c%finite('analysis', 'continuation_end', self%continuation_end)
      if (self%continuation_points < 2) call c%reject('analysis', 'continuation_points', &
         & itoa(self%continuation_points), 'must be >= 2 (both ends of the line)')
      ! Each point is a periodic orbit found by Newton shooting: more than
      ! max_continuation_points would run for years (2**31 - 1 asked 64 GB).
      if (self%continuation_points > max_continuation_points) call c%reject('analysis', 'continuation_points', &
         & itoa(self%continuation_points), 'must be <= '//itoa(max_continuation_points) &
         & //' (each point is a periodic orbit of its own)')
      if (len_trim(self%continuation) > 0 .and. .not. self%orbit) call c%reject('analysis', 'continuation', &
         & "'"//trim(self%continuation)//"'", 'follows the periodic orbit: needs orbit = .true.')
      if (self%rosenstein_stride < 1) call c%reject('analysis', 'rosenstein_stride', &
         & itoa(self%rosenstein_stride), 'must be >= 1')
      if (self%rosenstein_dimension < 1) call c%reject('analysis', 'rosenstein_dimension', &
         & itoa(self%rosenstein_dimension), 'must be >= 1')
      if (self%rosenstein_delay < 1) call c%reject('analysis', 'rosenstein_delay', itoa(self%rosenstein_delay), &
         & 'must be >= 1 (samples)')
      if (self%rosenstein_theiler < 0) call c%reject('analysis', 'rosenstein_theiler', &
         & itoa(self%rosenstein_theiler), 'must be >= 0 (samples)')
      if (self%rosenstein_horizon < 1) call c%reject('analysis', 'rosenstein_horizon', &
         & itoa(self%rosenstein_horizon), 'must be >= 1 (samples)')
      if (self%rosenstein_fit_start < 0) call c%reject('analysis', 'rosenstein_fit_start', &
         & itoa(self%rosenstein_fit_start), 'must be >= 0 (samples)')
      if (self%rosenstein_fit_end <= self%rosenstein_fit_start .or. &
         & self%rosenstein_fit_end > self%rosenstein_horizon) call c%reject('analysis', 'rosenstein_fit_end', &
         & itoa(self%rosenstein_fit_end), 'must be in (rosenstein_fit_start, rosenstein_horizon]', &
         & against=partners(run, 'analysis.rosenstein_fit_start', 'analysis.rosenstein_horizon'))
   contains

      !> The renormalisation interval `name` over its span (duration, or the
      !> run after the transient; the transient too when `stepped`) gives at
      !> most max_renormalisations intervals.
      subroutine check_intervals(name, interval, duration, transient, stepped, tool)
         character(len=*), intent(in) :: name, tool
         real(wp), intent(in) :: interval, duration, transient
         logical, intent(in) :: stepped
         real(wp) :: span

         if (.not. (interval > 0.0_wp)) return   ! refused above
         span = duration
         if (span == 0.0_wp) span = t_end - t_start - transient
         if (stepped) span = span + transient
         if (.not. (span / interval <= max_renormalisations)) call c%reject('analysis', name, rtoa(interval), &
            & 'gives '//rtoa(span / interval)//' renormalisation intervals over '//rtoa(span)//' τ; at most ' &
            & //rtoa(max_renormalisations)//' (each is an integration of its own): give a longer interval', &
            & against=partners(run, 'analysis.'//tool//'_duration', 'analysis.'//tool//'_transient', 'run', &
            & 'analysis.'//tool))
      end subroutine check_intervals

      function window_text() result(text)
         character(len=:), allocatable :: text

         text = 'leaves '//itoa(points)//' output points in [window_start, window_end] = ['//rtoa(self%window_start) &
            & //', '//rtoa(self%window_end)//'] within the run ['//rtoa(t_start)//', '//rtoa(t_end) &
            & //'] every dt_out = '//rtoa(dt)//'; '//what//' needs '//itoa(need)
      end function window_text
   end subroutine validate

   !> The variables a check compares, 'group.name' ('run': the run's
   !> t_end, t_start and dt_out), for the checker's `against`.  (Built
   !> element by element: gfortran's typed array constructors of concatenated
   !> strings here corrupted the heap.)
   function partners(run, a, b, c, d) result(list)
      character(len=*), intent(in) :: run(:), a
      character(len=*), intent(in), optional :: b, c, d
      character(len=64) :: list(6)
      integer :: n

      list = ''
      n = 0
      call add(a)
      if (present(b)) call add(b)
      if (present(c)) call add(c)
      if (present(d)) call add(d)
   contains
      subroutine add(name)
         character(len=*), intent(in) :: name

         if (name == 'run') then
            list(n + 1:n + 3) = run
            n = n + 3
         else
            n = n + 1
            list(n) = name
         end if
      end subroutine add
   end function partners

   !> The output points t_start + k dt (k = 0, 1, ...) up to t_end that lie in
   !> [window_start, window_end] (a margin of 1e-9 of a step for the rounding of the grid).
   pure integer function window_points(window_start, window_end, t_start, t_end, dt) result(points)
      real(wp), intent(in) :: window_start, window_end, t_start, t_end, dt
      real(wp) :: low, high

      low = max(window_start, t_start)
      high = min(window_end, t_end)
      points = 0
      if (.not. (high >= low .and. dt > 0.0_wp)) return
      ! (In reals: the counts of a long run at a tiny step overflow an integer.)
      points = int(min(down((high - t_start) / dt + 1.0e-9_wp) - up((low - t_start) / dt - 1.0e-9_wp) + 1.0_wp, &
         & real(huge(points), wp)))
      points = max(points, 0)
   contains
      pure real(wp) function down(x)
         real(wp), intent(in) :: x
         down = aint(x) - merge(1.0_wp, 0.0_wp, x < aint(x))
      end function down
      pure real(wp) function up(x)
         real(wp), intent(in) :: x
         up = aint(x) + merge(1.0_wp, 0.0_wp, x > aint(x))
      end function up
   end function window_points

end module friction_analysis_settings
