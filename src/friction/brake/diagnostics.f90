!> The chaos diagnostics of a brake run (docs/physics.md, chaos diagnostics):
!> the spectrum of one variable over a window, the stroboscopic map and a
!> section, and the maximum Lyapunov exponent from the equations (two runs
!> through the same stick/slip logic, Benettin) and from the series
!> (Rosenstein).  Deterministic: every rank computes the same numbers.
module friction_brake_diagnostics
   use friction_kinds, only: wp, i8
   use friction_error, only: error_type, fatal_error, error_input, error_numerical
   use friction_strings, only: rtoa
   use friction_brake_config, only: brake_config, series_names
   use friction_brake_record, only: brake_trajectory, brake_event_table, event_stick_to_slip
   use friction_brake_simulate, only: initial_state, new_brake_integrator
   use friction_brake_integrator, only: brake_integrator
   use friction_brake_law_model, only: law_integrator
   use friction_law, only: sliding_law
   use friction_law_factory, only: make_law
   use friction_output_law_files, only: law_with_files
   use friction_ode_solver, only: ode_solver
   use friction_ode_events, only: event_locator, event_either
   use friction_law_kinked, only: kinked_system
   use friction_analysis_tangent_magnus, only: orbit_step, tangent_over_step, jacobian_trace, simpson_trace, &
      & step_state
   use friction_analysis_settings, only: analysis_settings
   use friction_analysis_spectrum, only: spectrum_settings, spectrum_result, amplitude_spectrum
   use friction_analysis_poincare, only: stroboscopic_map, upward_section
   use friction_analysis_lyapunov_flow, only: benettin_settings, benettin_accumulator
   use friction_analysis_lyapunov_spectrum, only: tangent_settings, spectrum_accumulator, kaplan_yorke, &
      & generic_frame
   use friction_analysis_lyapunov_series, only: rosenstein_result
   use friction_analysis_periodic_orbit, only: orbit_settings
   use friction_brake_orbit, only: brake_orbit, brake_periodic_orbit, orbit_branch, follow_branch
   use friction_scene_report, only: job_reporter, loop_guard, job_watch, new_job_watch
   use friction_clock, only: wall_seconds
   implicit none
   private

   public :: brake_diagnostics, diagnose_brake, brake_benettin, brake_lyapunov_spectrum, series_names


   type :: brake_diagnostics
      type(analysis_settings) :: settings
      type(spectrum_result) :: spectrum
      real(wp) :: strobe_period = 0.0_wp
      real(wp), allocatable :: strobe_t(:), strobe_points(:, :)     !! (4, n): x, v, y, w
      real(wp), allocatable :: section_t(:), section_points(:, :)   !! (4, n)
      type(benettin_settings) :: benettin
      type(benettin_accumulator) :: flow
      type(tangent_settings) :: tangent
      type(spectrum_accumulator) :: qr                !! the whole spectrum (tangent equations, QR)
      real(wp), allocatable :: exponents(:)          !! largest first; -inf for directions lost in stick
      real(wp) :: kaplan_yorke = 0.0_wp
      !> 1/τ: the time average of tr J over the spectrum's span, for a law
      !> that is one ODE without a band (unallocated otherwise: law_flow_spectrum)
      real(wp), allocatable :: divergence
      type(rosenstein_result) :: series
      real(wp) :: series_dt = 0.0_wp   !! sample spacing of the strided series
      type(brake_orbit) :: orbit       !! the periodic orbit through the section (Newton)
      type(orbit_branch) :: branch     !! ... followed along the continuation line
   end type brake_diagnostics

contains

   !> Everything the settings switch on, from a finished run.  The long
   !> loops (the Lyapunov estimates' intervals, the continuation's points)
   !> end on a stop request of `reporter` (if given) and at the integrator's
   !> max_wall_time since the diagnostics began.
   subroutine diagnose_brake(config, trajectory, events, result, error, reporter)
      type(brake_config), intent(in) :: config
      type(brake_trajectory), intent(in) :: trajectory
      type(brake_event_table), intent(in) :: events
      type(brake_diagnostics), intent(out) :: result
      type(error_type), allocatable, intent(out) :: error
      class(job_reporter), intent(inout), optional :: reporter
      real(wp), allocatable :: states(:, :), window_series(:)
      integer :: first, last, k, column
      real(wp) :: t_end
      type(loop_guard) :: guard
      type(job_watch), target :: watch

      guard = loop_guard(started=wall_seconds(), limit=config%solver%max_wall_time)

      associate (a => config%analysis)
         result%settings = a
         allocate (states(4, size(trajectory%t)))
         states(1, :) = trajectory%x
         states(2, :) = trajectory%v
         states(3, :) = trajectory%y
         states(4, :) = trajectory%w
         column = findloc(series_names, trim(a%series), 1)
         if (column == 0) then
            call fatal_error(error, "&analysis: unknown series '"//trim(a%series)//"'", error_input)
            return
         end if
         first = count(trajectory%t < a%window_start) + 1
         last = count(trajectory%t <= a%window_end)
         if (a%spectrum .or. a%rosenstein .or. (a%poincare .and. a%strobe_period == 0.0_wp)) then
            if (last - first + 1 < 16) then
               call fatal_error(error, '&analysis: fewer than 16 output points in [window_start, window_end]', &
                  & error_input)
               return
            end if
            window_series = states(column, first:last)
         end if
         if (a%spectrum .or. (a%poincare .and. a%strobe_period == 0.0_wp)) then
            call amplitude_spectrum(window_series, config%dt_out, &
               & spectrum_settings(window=a%window, segments=a%welch_segments), result%spectrum, error)
            if (allocated(error)) return
         end if
         if (a%poincare) then
            result%strobe_period = a%strobe_period
            if (result%strobe_period == 0.0_wp) then
               if (.not. (result%spectrum%peak_frequency > 0.0_wp)) then
                  call fatal_error(error, '&analysis: no spectral peak to strobe at; set strobe_period', &
                     & error_input)
                  return
               end if
               result%strobe_period = 1.0_wp / result%spectrum%peak_frequency
            end if
            t_end = a%strobe_end
            if (t_end == 0.0_wp) t_end = config%t_end
            call stroboscopic_map(trajectory%t, states, a%strobe_start, t_end, result%strobe_period, &
               & result%strobe_t, result%strobe_points, error)
            if (allocated(error)) return
            select case (trim(a%section))
            case ('stick_to_slip')
               ! Located by the event machinery to event_tolerance.
               k = count(events%kind(1:events%n) == event_stick_to_slip)
               result%section_t = pack(events%t(1:events%n), events%kind(1:events%n) == event_stick_to_slip)
               allocate (result%section_points(4, k))
               do column = 1, 4
                  result%section_points(column, :) = pack(events%state(column, 1:events%n), &
                     & events%kind(1:events%n) == event_stick_to_slip)
               end do
            case ('w_zero_up')
               call upward_section(trajectory%t, states, 4, 0.0_wp, a%strobe_start, t_end, &
                  & result%section_t, result%section_points)
            case default
               allocate (result%section_t(0), result%section_points(4, 0))
            end select
         end if
         if (a%lyapunov) then
            result%benettin%transient = a%lyapunov_transient
            result%benettin%duration = a%lyapunov_duration
            if (result%benettin%duration == 0.0_wp) &
               & result%benettin%duration = config%t_end - config%t_start - a%lyapunov_transient
            result%benettin%renormalise = a%lyapunov_renormalise
            result%benettin%d0 = a%lyapunov_d0
            call brake_benettin(config, result%benettin, result%flow, error, guard, reporter)
            if (allocated(error)) return
         end if
         if (a%lyapunov_spectrum) then
            result%tangent%transient = a%lyapunov_spectrum_transient
            result%tangent%duration = a%lyapunov_spectrum_duration
            if (result%tangent%duration == 0.0_wp) &
               & result%tangent%duration = config%t_end - config%t_start - a%lyapunov_spectrum_transient
            result%tangent%renormalise = a%lyapunov_spectrum_renormalise
            call brake_lyapunov_spectrum(config, result%tangent, result%qr, error, guard, reporter, &
               & result%divergence)
            if (allocated(error)) return
            result%exponents = result%qr%exponents()
            result%kaplan_yorke = kaplan_yorke(result%exponents)
         end if
         if (a%orbit .and. .not. (config%switched() .or. config%uses_law())) then
            result%orbit%orbit%reason = "the section is the switched model's located slip onsets: model = 'switched'"
         else if (a%orbit) then
            ! Not finding one is a result (orbit%found), not an error.  A Newton step's trial points can
            ! take long (rate and state on the slow belt): the watch is asked after each and inside the map.
            watch = new_job_watch('&analysis: the periodic orbit''s search', 'the return''s τ', &
               & config%solver%max_wall_time, reporter)
            watch%guard = guard
            call brake_periodic_orbit(config, events, a%orbit_transient, &
               & orbit_settings(tolerance=a%orbit_tolerance, max_iterations=a%orbit_max_iterations), &
               & result%orbit, error, watch)
            if (allocated(error)) return
            if (len_trim(a%continuation) > 0) then
               call follow_branch(config, result%orbit, a%continuation_end, a%continuation_points, &
                  & a%orbit_transient, orbit_settings(tolerance=a%orbit_tolerance, &
                  & max_iterations=a%orbit_max_iterations), result%branch, error, guard, reporter, watch)
               if (allocated(error)) return
            end if
         end if
         if (a%rosenstein) then
            call a%rosenstein_of(window_series, config%dt_out, result%series, result%series_dt, error)
            if (allocated(error)) return
         end if
      end associate
   end subroutine diagnose_brake

   !> Benettin for the brake: a reference and a perturbed run advanced in
   !> lockstep through the same stick/slip logic; after each interval the
   !> perturbed run restarts from the reference plus the separation scaled
   !> back to d0.  The state is (x, x', y, y') and a law's internal states in
   !> units of their scale, which the perturbed run's restarts carry.  In
   !> stick the perturbation is put on the positions (and states) only so
   !> that both runs start in the same phase; a separation with a velocity
   !> part restarts the perturbed run in slip, as the logic decides.
   subroutine brake_benettin(config, settings, result, error, guard, reporter)
      type(brake_config), intent(in) :: config
      type(benettin_settings), intent(in) :: settings
      type(benettin_accumulator), intent(out) :: result
      type(error_type), allocatable, intent(out) :: error
      type(loop_guard), intent(in), optional :: guard   !! a stop request and max_wall_time, checked each interval
      class(job_reporter), intent(inout), optional :: reporter
      class(brake_integrator), allocatable, target :: reference_run, perturbed_run
      type(brake_event_table) :: reference_events, perturbed_events
      real(wp) :: t
      real(wp), allocatable :: reference(:), perturbed(:), direction(:)
      integer :: k, intervals, n

      if (.not. (settings%renormalise > 0.0_wp .and. settings%duration >= settings%renormalise &
         & .and. settings%d0 > 0.0_wp .and. settings%transient >= 0.0_wp)) then
         call fatal_error(error, '&analysis: Benettin needs lyapunov_renormalise > 0, a duration of at ' &
            & //'least one interval after lyapunov_transient, lyapunov_d0 > 0', error_input)
         return
      end if
      call new_brake_integrator(config, reference_run)
      call new_brake_integrator(config, perturbed_run)
      t = config%t_start + settings%transient
      call reference_run%start(config, config%t_start, initial_state(config), reference_events, error)
      if (allocated(error)) return
      ! The whole state: the four variables and a law's internal states, which
      ! the perturbed run's restarts carry (a law's states start steady otherwise).
      n = 4 + reference_run%state_count()
      allocate (reference(n), perturbed(n), direction(n))
      call advance(reference_run, reference_events, t, reference)
      if (allocated(error)) return
      direction = 1.0_wp
      if (reference_run%is_sticking()) direction(2:4:2) = 0.0_wp
      perturbed = reference + settings%d0 * direction / norm2(direction)
      intervals = int(settings%duration / settings%renormalise + 1.0e-9_wp)
      call result%start(settings%d0, intervals)
      do k = 1, intervals
         ! start takes (x, x', y, y'); the states' restart then sets the integrated coordinates exactly (a
         ! law's creeping v_rel would lose its last digits to v_dr's spacing in x').
         call perturbed_run%start(config, t, reference_run%physical(perturbed(1:4)), perturbed_events, error)
         if (allocated(error)) return
         if (n > 4) then
            perturbed_run%y = perturbed(1:4)
            call perturbed_run%set_states(perturbed(5:n))
         end if
         t = config%t_start + settings%transient + k * settings%renormalise
         call advance(reference_run, reference_events, t, reference)
         if (allocated(error)) return
         call advance(perturbed_run, perturbed_events, t, perturbed)
         if (allocated(error)) return
         call result%renormalise(reference, perturbed, settings%renormalise)
         ! Long runs: keep the event tables from growing without bound.
         call reference_events%clear()
         if (present(guard)) then
            call guard%check(reporter, '&analysis: the Lyapunov exponent (Benettin)', t, 'τ', error)
            if (allocated(error)) return
         end if
      end do

   contains

      subroutine advance(run, events, t1, y)
         class(brake_integrator), intent(inout) :: run
         type(brake_event_table), intent(inout) :: events
         real(wp), intent(in) :: t1
         real(wp), intent(out) :: y(:)

         call run%advance_to(t1, events, error)
         ! As integrated: (x, v_rel, y, w) for a law's flow (law_model.f90).
         y(1:4) = run%y
         if (size(y) > 4) call run%get_states(y(5:))
      end subroutine advance

   end subroutine brake_benettin

   !> The whole spectrum of the brake: one run of either model with its
   !> tangent matrix (the switched model applies the saltation matrices at
   !> its events and the stick flow, which forgets the block's velocity);
   !> after the transient, a QR step every renormalisation interval.  A
   !> law that is one ODE without a band (&brake model = 'law'): law_flow_spectrum,
   !> which also gives `divergence` (1/τ, the time average of tr J; left
   !> unallocated for the other models, whose exponents do not sum to it:
   !> docs/chaos.md); with Karnopp's band, the band's run (band.f90): its
   !> edges and the ends of its hold located, a saltation at each jump, δv
   !> forgotten in a hold.
   subroutine brake_lyapunov_spectrum(config, settings, result, error, guard, reporter, divergence)
      type(brake_config), intent(in) :: config
      type(tangent_settings), intent(in) :: settings
      type(spectrum_accumulator), intent(out) :: result
      type(error_type), allocatable, intent(out) :: error
      type(loop_guard), intent(in), optional :: guard   !! a stop request and max_wall_time, checked each interval
      class(job_reporter), intent(inout), optional :: reporter
      real(wp), allocatable, intent(out), optional :: divergence
      class(brake_integrator), allocatable, target :: run
      class(sliding_law), allocatable :: law
      type(brake_event_table) :: events
      real(wp), allocatable :: phi(:, :)
      real(wp) :: t0, half_width, limit
      integer :: k, intervals, n

      if (.not. (settings%renormalise > 0.0_wp .and. settings%duration >= settings%renormalise &
         & .and. settings%transient >= 0.0_wp)) then
         call fatal_error(error, '&analysis: the Lyapunov spectrum needs lyapunov_spectrum_renormalise > 0, ' &
            & //'a duration of at least one interval after lyapunov_spectrum_transient', error_input)
         return
      end if
      half_width = 0.0_wp
      if (config%uses_law()) then
         call make_law(law_with_files(config%law), law, error)
         if (allocated(error)) return
         call law%band(half_width, limit)
         if (.not. law%set_valued() .and. half_width == 0.0_wp) then
            block
               real(wp) :: average

               call law_flow_spectrum(config, settings, result, average, error, guard, reporter)
               if (present(divergence) .and. .not. allocated(error)) divergence = average
            end block
            return
         end if
      end if
      ! (A band law's integrator is the band's run, band.f90.)
      call new_brake_integrator(config, run)
      run%tangent = .true.
      call run%start(config, config%t_start, initial_state(config), events, error)
      if (allocated(error)) return
      ! The tangent's dimension: the four variables and a law's internal states.
      n = size(run%phi, 1)
      phi = generic_frame(n)
      t0 = config%t_start + settings%transient
      ! The transient in renormalisation intervals too, so that Φ stays bounded.
      do while (run%t < t0)
         call run%advance_to(min(run%t + settings%renormalise, t0), events, error)
         if (allocated(error)) return
         call events%clear()
         call run%reset_tangent(phi)
         call check_guard()
         if (allocated(error)) return
      end do
      intervals = int(settings%duration / settings%renormalise + 1.0e-9_wp)
      call result%start(n, intervals)
      do k = 1, intervals
         call run%advance_to(t0 + k * settings%renormalise, events, error)
         if (allocated(error)) return
         ! Long runs: keep the event table from growing without bound.
         call events%clear()
         phi = run%phi
         call result%renormalise(phi, settings%renormalise, run%lost)
         call run%reset_tangent(phi)
         call check_guard()
         if (allocated(error)) return
      end do

   contains

      subroutine check_guard()
         if (present(guard)) call guard%check(reporter, '&analysis: the Lyapunov spectrum', run%t, 'τ', error)
      end subroutine check_guard

   end subroutine brake_lyapunov_spectrum

   !> A law that is one ODE without Karnopp's band (arctan, Dahl, LuGre,
   !> elasto-plastic, rate and state, GMS): the orbit alone through the transient (the run's
   !> event locator: a lift-off is an error), then stepped one accepted step
   !> at a time with Φ carried over each by exponentials and factored within
   !> the step (analysis/tangent_magnus.f90, as the machine's), the logs
   !> summed over each renormalisation interval.  The flow's events (the
   !> creep band's edges) change neither the field nor the state: Φ needs no
   !> saltation there, and the stepper does not stop at them; the kinks a law
   !> declares (GMS's switch bands) it does stop at, as the machine's (kinked_system).  `divergence`:
   !> ∫ tr J dt by Simpson's rule on each step (simpson_trace) over the
   !> span's length, what the exponents sum to.  A law whose force goes with
   !> the slip rate's logarithm (rate and state) relaxes a creeping v_rel
   !> at up to N' a / v_rel, without bound as v_rel falls: the last column of
   !> Φ is closed by the trace there (tangent_magnus.f90's `closed`), the one
   !> direction the exponentials' parts cannot follow.
   subroutine law_flow_spectrum(config, settings, result, divergence, error, guard, reporter)
      type(brake_config), intent(in) :: config
      type(tangent_settings), intent(in) :: settings
      type(spectrum_accumulator), intent(out) :: result
      real(wp), intent(out) :: divergence
      type(error_type), allocatable, intent(out) :: error
      type(loop_guard), intent(in), optional :: guard
      class(job_reporter), intent(inout), optional :: reporter
      type(law_integrator), target :: run
      type(brake_event_table) :: events
      type(ode_solver) :: orbit
      type(kinked_system), target :: kinked
      type(event_locator) :: locator
      real(wp), allocatable :: z(:), y_a(:), f_a(:), f_b(:), phi(:, :), logs(:), middle(:)
      real(wp) :: t, t0, t_a, t_target, trace_a, trace_b, integral, total, reference, floor, h
      integer(i8) :: steps
      integer :: n, k, intervals, depth, m, relative
      logical :: kinks, closed

      divergence = 0.0_wp
      call run%start(config, config%t_start, initial_state(config), events, error)
      if (allocated(error)) return
      t0 = config%t_start + settings%transient
      t = run%t
      do while (run%t < t0)
         call run%advance_to(min(run%t + settings%renormalise, t0), events, error)
         if (allocated(error)) return
         call events%clear()
         t = run%t
         call check_guard()
         if (allocated(error)) return
      end do
      n = 4 + run%state_count()
      allocate (z(n), y_a(n), f_a(n), f_b(n), logs(n), middle(n))
      ! The flow's own coordinates: (x, v_rel, y, w) (law_model.f90).
      z(1:4) = run%y
      if (n > 4) call run%get_states(z(5:n))
      t = run%t
      phi = generic_frame(n)
      call run%flow%relative_component(relative, reference, floor)
      closed = relative > 0
      ! The run's first step, unless it cannot move t here (a creep's relaxation at τ = 0 is 1e-31 τ for
      ! rate and state, below the spacing of a τ of 190): then the run's first-step rule at this state.
      h = run%h_start
      if (.not. (t + h > t)) h = run%flow%first_step(config%solver%h_start, t, z(1:4), &
         & z(5:n) * run%flow%scale(1:n - 4))
      kinks = run%law%kink_count() > 0
      if (kinks) then
         ! The law's kinks (GMS's switch bands) located: each ends a step (docs/chaos.md).
         allocate (kinked%base, source=run%flow)
         allocate (kinked%model, source=run%flow)
         m = kinked%event_count()
         call locator%init(kinked, config%solver, spread(event_either, 1, m), spread(.true., 1, m), &
            & config%event_tolerance, h, error, time_name='τ', time_unit='')
         if (allocated(error)) return
         call locator%restart(t, z, h)
      else
         call orbit%init(run%flow, config%solver, h, error)
         if (allocated(error)) return
      end if
      intervals = int(settings%duration / settings%renormalise + 1.0e-9_wp)
      call result%start(n, intervals)
      call run%flow%rhs(t, z, f_a)
      trace_a = jacobian_trace(run%flow, t, z)
      total = 0.0_wp
      depth = 0
      do k = 1, intervals
         t_target = t0 + k * settings%renormalise
         logs = 0.0_wp
         steps = 0
         do while (t < t_target)
            if (kinks) then
               call kink_step(error)
            else
               call orbit_step(orbit, config%solver%method, config%solver%max_steps, t, t_target, z, t_a, y_a, &
                  & steps, error)
            end if
            if (allocated(error)) exit
            ! (At a step's end: a dip of N' below 0 within one step is the stepper's to resolve.)
            if (.not. (run%p%normal_force(z(3)) > 0.0_wp)) then
               call fatal_error(error, "N' reached 0 at τ = "//rtoa(t) &
                  & //': the pad lifts off the belt, outside Eq. 10', error_numerical)
               exit
            end if
            f_b = f_a
            if (t > t_a) then
               call tangent_over_step(run%flow, orbit, t_a, y_a, f_b, t, z, phi, logs, depth, error, closed)
               if (allocated(error)) exit
            end if
            if (kinks) call restart_past_kink()
            if (closed) then
               ! (The same states as the exponentials': the stepper's own between its ends.)
               call step_state(orbit, 0.5_wp, t_a, t - t_a, y_a, f_a, z, f_b, middle)
               call simpson_trace(run%flow, t_a, y_a, f_a, t, z, f_b, trace_a, trace_b, integral, middle)
            else
               call simpson_trace(run%flow, t_a, y_a, f_a, t, z, f_b, trace_a, trace_b, integral)
            end if
            total = total + integral
            trace_a = trace_b
            f_a = f_b
            ! (The guard every 16 steps, and after every step whose exponentials took thousands of parts.)
            if (mod(steps, 16_i8) == 0 .or. depth >= 12) then
               call check_guard()
               if (allocated(error)) exit
            end if
         end do
         if (allocated(error)) exit
         call result%add_logs(logs, settings%renormalise, 0)
         call check_guard()
         if (allocated(error)) exit
      end do
      call orbit%destroy()
      if (result%elapsed > 0.0_wp) divergence = total / result%elapsed
      if (allocated(error)) error%message = error%message//" (&brake model = 'law', &law model = '" &
         & //trim(run%law%p%model)//"')"

   contains

      !> One accepted step of the kinked flow, ending at a kink if one comes first.
      subroutine kink_step(error)
         type(error_type), allocatable, intent(out) :: error

         t_a = t
         y_a = z
         call locator%advance(t, t_target, z, error, single=.true.)
         if (allocated(error)) return
         steps = steps + 1
         if (steps > config%solver%max_steps) call fatal_error(error, trim(config%solver%method) &
            & //': more than max_steps steps in one renormalisation interval at τ = '//rtoa(t), error_numerical)
      end subroutine kink_step

      !> Past a kink, on with a step of event_tolerance: a stepper that keeps its long step damps the fast
      !> growth of the band's upper half (an L-stable method damps h λ >> 1 either way) and sits on its edge.
      subroutine restart_past_kink()
         if (locator%n_hits == 0) return
         if (locator%hits(locator%n_hits)%terminal) call locator%restart(t, z, config%event_tolerance)
      end subroutine restart_past_kink

      subroutine check_guard()
         if (present(guard)) call guard%check(reporter, '&analysis: the Lyapunov spectrum', t, 'τ', error)
      end subroutine check_guard

   end subroutine law_flow_spectrum

end module friction_brake_diagnostics
