!> Periodic orbits of the switched brake and their Floquet multipliers
!> (docs/physics.md, periodic orbits): Newton shooting on the stick-to-slip
!> section (analysis/periodic_orbit.f90).
!>
!> Section.  A slip starts when the elastic force reaches the static limit,
!> 2x - y = σ μs N'(y) with σ = ±1, at v = v'_dr.  Given σ, the points of
!> the section are (y, w): x = (y + σ μs N'(y))/2 and v = v'_dr follow.
!> The return map P(y, w) starts a slip there (direction -σ), integrates
!> through any number of slips, slip reversals and sticks with the tangent
!> matrix Φ (saltation matrices at every switching, the exact stick flow)
!> and stops at the next stick-to-slip event, located by the event
!> machinery.  DP = the (y, w) rows of (I - f nᵀ/(nᵀ f)) Φ B: Φ projected
!> along the flow f onto the section (normal n), B the section's tangent
!> vectors ∂(x, v, y, w)/∂(y, w).  A return at the other limit (σ changes)
!> is no return of this section.
!>
!> Multipliers.  The orbit's four: the trivial 1 along the flow, the two of
!> DP, and 0 exactly -- the stick forgets the block's velocity, the
!> direction the Lyapunov spectrum reports with exponent -inf.
!>
!> A single-valued law (no exact stick) takes the creep band's exit
!> instead, a hyperplane of its smooth flow (x, v, y, w, ẑ): the section's
!> coordinates are x, y, w and the law's states ẑ in units of their scale,
!> 3 + m of them; the multipliers the trivial 1 and the map's 3 + m.
module friction_brake_orbit
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
   use friction_kinds, only: wp, pi
   use friction_error, only: error_type, error_interrupted
   use friction_ode_watch, only: step_watch
   use friction_brake_config, only: brake_config, continuation_config, continuation_variable
   use friction_brake_simulate, only: brake_run, simulate_brake, initial_state
   use friction_brake_params, only: brake_parameters
   use friction_brake_record, only: brake_event_table, event_stick_to_slip, event_kind_names
   use friction_brake_switched, only: switched_integrator, brake_slip
   use friction_brake_law_model, only: law_integrator, brake_law_slip, brake_law_flow, law_units, law_static_line
   use friction_brake_integrator, only: brake_integrator
   use friction_brake_band, only: band_integrator, band_law
   use friction_law, only: sliding_law, max_law_states, band_hold_limit
   use friction_law_factory, only: make_law, new_law
   use friction_output_law_files, only: law_with_files
   use friction_scene_report, only: job_reporter, loop_guard
   use friction_analysis_periodic_orbit, only: section_map, orbit_settings, periodic_orbit, &
      & find_periodic_orbit, floquet_multipliers, floquet_exponents, bifurcation_period_doubling, &
      & bifurcation_fold, bifurcation_neimark_sacker, halving_walk, branch_values, &
      & modulus_crossing, hyperplane_map
   use friction_analysis_magnus_section, only: magnus_map
   use friction_law_kinked, only: kinked_system
   implicit none
   private

   public :: brake_section_map, brake_orbit, brake_periodic_orbit, section_state, section_limit
   public :: brake_band_map, exact_stick, band_law, orbit_states
   public :: orbit_branch, follow_branch, detect_bifurcations, bifurcation_names
   public :: bifurcation_period_doubling, bifurcation_fold, bifurcation_neimark_sacker, bifurcation_discontinuity

   ! Where a multiplier of the section map leaves (or enters) the unit circle: the kinds 1 to 3
   ! of analysis/periodic_orbit.f90 (period doubling, fold, Neimark–Sacker), shared with the machine.
   !> The orbits at two consecutive points are not on one smooth branch:
   !> their patterns of events differ, or the period jumps by more than half
   !> the crank's period in stick, π/ω with ω = √(κ/ξ) (the stick ends at
   !> another lobe of the static limit: a grazing of the stick's exit), or
   !> Newton jumped to another orbit.
   integer, parameter :: bifurcation_discontinuity = 4
   character(len=*), parameter :: bifurcation_names(4) = [character(len=15) :: 'period_doubling', 'fold', &
      & 'neimark_sacker', 'discontinuity']

   !> Most slip onsets of the attractor kept per point of the line (the diagram).
   integer, parameter :: max_section_points = 400

   !> The orbit followed along a line of one variable (docs/physics.md).
   type :: orbit_branch
      character(len=16) :: variable = ''
      character(len=:), allocatable :: unit          !! the variable's unit (as &brake gives it)
      real(wp), allocatable :: parameter(:)          !! (n) the variable's values
      logical, allocatable :: found(:)               !! (n)
      integer, allocatable :: source(:)              !! (n) 1: continued from the previous orbit, 2: from the attractor
      real(wp), allocatable :: period(:)             !! (n) τ; NaN where none
      real(wp), allocatable :: state(:, :)           !! (4, n) slip onset of the orbit
      complex(wp), allocatable :: multipliers(:, :)  !! (4 + m, n) as brake_orbit%multipliers, m law states
      real(wp), allocatable :: max_modulus(:)        !! (n) largest |μ| of the section map
      integer, allocatable :: pattern(:, :)          !! (3, n) as brake_orbit%pattern
      integer, allocatable :: kind(:)                !! bifurcations: bifurcation_* ...
      real(wp), allocatable :: at(:)                 !! ... at these values (linear interpolation of |μ| - 1)
      real(wp), allocatable :: section_parameter(:)  !! the attractor's slip onsets: the variable ...
      real(wp), allocatable :: section_x(:)          !! ... and x there (the bifurcation diagram)
   end type orbit_branch

   !> The return map of the stick-to-slip section at the limit σ: the
   !> switched model's, or a set-valued law's (&brake model = 'law'), whose
   !> static limit is slope N' + level.
   type, extends(section_map) :: brake_section_map
      type(brake_config) :: config
      real(wp) :: limit = 1.0_wp          !! σ
      real(wp) :: max_return = 1.0e4_wp   !! τ; no slip onset by then: no return
      logical :: tangent = .true.         !! .false.: P alone (jacobian = 0)
      integer :: counts(size(event_kind_names)) = 0   !! events by kind over the last return
      class(step_watch), pointer :: watch => null()   !! asked after every return when associated
      logical, private :: prepared = .false.          !! slope and level known (model = 'law')
      logical, private :: band = .false.              !! a band law: the end of a hold at the edge (band.f90)
      real(wp), private :: slope = 0.0_wp, level = 0.0_wp
   contains
      procedure :: dimension => brake_map_dimension
      procedure :: evaluate => brake_map_evaluate
   end type brake_section_map

   !> The return map of a single-valued law (&brake model = 'law'): the exit
   !> from the creep band v_rel = s v_s (s = -σ, v_s the brake's
   !> stick_velocity) crossed away from 0, the flow's own slip onset;
   !> coordinates (x, y, w, ẑ), ẑ the law's states in units of their scale
   !> (none for arctan), the Jacobian from the variational equations with
   !> the law's partial derivatives (analysis/periodic_orbit.f90's
   !> hyperplane map; a law with kinks, GMS, the exponential tangent's map of
   !> analysis/magnus_section.f90 with them located).  A trial point whose
   !> integration fails returns nowhere.
   type, extends(section_map) :: brake_band_map
      class(section_map), allocatable :: plane
      type(brake_law_flow) :: flow   !! the flow the plane steps: its first-step rule at each start
      class(step_watch), pointer :: watch => null()   !! the plane's too: asked inside its integration
   contains
      procedure :: dimension => band_map_dimension
      procedure :: evaluate => band_map_evaluate
   end type brake_band_map

   !> A brake run's periodic orbit (/brake/orbit, docs/output.md).
   type :: brake_orbit
      type(periodic_orbit) :: orbit
      real(wp) :: limit = 1.0_wp              !! σ of the section
      real(wp) :: guess_time = 0.0_wp         !! τ of the run's slip onset Newton started from
      real(wp) :: state(4) = 0.0_wp           !! the orbit's slip onset (x, v, y, w)
      integer :: n_states = 0                 !! m, the law's states on the creep band's exit
      real(wp) :: states(max_law_states) = 0.0_wp   !! (m) their values there, in units of their scale
      real(wp) :: scale(max_law_states) = 1.0_wp    !! (m) the scales, in the law's units
      character(len=16) :: state_names(max_law_states) = '', state_units(max_law_states) = ''
      !> 1, those of DP (by modulus), 0 (exact stick); 1 and the 3 + m of DP (the creep band's exit)
      complex(wp) :: multipliers(4 + max_law_states) = (0.0_wp, 0.0_wp)
      real(wp) :: exponents(4 + max_law_states) = 0.0_wp   !! ln|μ|/T; -inf for the stick's 0
      !> Events of each kind over one period (stick-to-slip, slip-to-stick,
      !> slip reversal): the orbit's pattern, which a continuous branch keeps.
      integer :: pattern(size(event_kind_names)) = 0
      !> The section: 'stick_to_slip' (exact stick), 'band_hold_end' (a
      !> band law: a hold at the band's edge ending as the pull reaches F_s),
      !> or 'creep_band_exit' (a single-valued law: |v_rel| leaving stick_velocity).
      character(len=16) :: section = 'stick_to_slip'
   end type brake_orbit

contains

   !> The section's state at (y, w) = s for the limit σ.
   pure function section_state(p, limit, s) result(z)
      type(brake_parameters), intent(in) :: p
      real(wp), intent(in) :: limit, s(2)
      real(wp) :: z(4)

      z = [(s(1) + limit * p%mu_s * p%normal_force(s(1))) / 2, p%v_dr, s(1), s(2)]
   end function section_state

   !> The section's state at (y, w) = s for the limit σ of a static limit
   !> slope N' + level.
   pure function limit_state(p, slope, level, limit, s) result(z)
      type(brake_parameters), intent(in) :: p
      real(wp), intent(in) :: slope, level, limit, s(2)
      real(wp) :: z(4)

      if (level == 0.0_wp) then
         z = [(s(1) + limit * slope * p%normal_force(s(1))) / 2, p%v_dr, s(1), s(2)]
      else
         z = [(s(1) + limit * (slope * p%normal_force(s(1)) + level)) / 2, p%v_dr, s(1), s(2)]
      end if
   end function limit_state

   !> Whether the brake's friction sticks exactly (the switched model, or a
   !> set-valued law of &law): the stick-to-slip section; else the creep band's exit.
   logical function exact_stick(config)
      type(brake_config), intent(in) :: config
      class(sliding_law), allocatable :: law

      exact_stick = .not. config%uses_law()
      if (exact_stick) return
      call new_law(config%law, law)
      exact_stick = law%set_valued()
   end function exact_stick

   !> σ of a slip onset: the sign of the elastic force 2x - y there.
   pure real(wp) function section_limit(p, z)
      type(brake_parameters), intent(in) :: p
      real(wp), intent(in) :: z(4)

      section_limit = sign(1.0_wp, p%elastic_force(z(1), z(3)))
   end function section_limit

   pure integer function brake_map_dimension(self)
      class(brake_section_map), intent(in) :: self

      brake_map_dimension = 2
   end function brake_map_dimension

   subroutine brake_map_evaluate(self, s, image, jacobian, period, returned, reason, error)
      class(brake_section_map), intent(inout) :: self
      real(wp), intent(in) :: s(:)
      real(wp), intent(out) :: image(:), jacobian(:, :), period
      logical, intent(out) :: returned
      character(len=:), allocatable, intent(out) :: reason
      type(error_type), allocatable, intent(out) :: error
      type(switched_integrator), target :: switched
      type(law_integrator), target :: with_law
      type(band_integrator), target :: with_band
      class(brake_integrator), pointer :: run
      type(brake_event_table) :: events
      type(brake_slip) :: slip
      type(brake_law_slip) :: law_slip
      real(wp) :: normal(4), f(4), b(4, 2), projected(4, 2), slope
      integer :: i
      logical :: ends

      image = s
      jacobian = 0.0_wp
      period = 0.0_wp
      returned = .false.
      reason = ''
      associate (p => self%config%params, sigma => self%limit)
         if (self%config%uses_law()) then
            if (.not. self%prepared) then
               call prepare_limit(self, error)
               if (allocated(error)) return
            end if
            slope = self%slope
            if (self%band) then
               ! The hold at the edge -σ ends: the block leaves it at once (band.f90).
               with_band%tangent = self%tangent
               call with_band%start_leaving(self%config, 0.0_wp, limit_state(p, slope, self%level, sigma, &
                  & s(1:2)), -sigma, events, error)
               if (allocated(error)) return
               call with_band%advance_to_hold_end(self%max_return, events, returned, error)
               run => with_band
            else
               with_law%tangent = self%tangent
               call with_law%start_slipping(self%config, 0.0_wp, limit_state(p, slope, self%level, sigma, &
                  & s(1:2)), -sigma, events, error)
               if (allocated(error)) return
               call with_law%advance_to_slip_onset(self%max_return, events, returned, error)
               run => with_law
            end if
         else
            slope = p%mu_s
            switched%tangent = self%tangent
            call switched%start_slipping(self%config, 0.0_wp, section_state(p, sigma, s(1:2)), -sigma, events, error)
            if (allocated(error)) return
            call switched%advance_to_slip_onset(self%max_return, events, returned, error)
            run => switched
         end if
         ! (The switched and law integrators take no watch: it is asked after each return.)
         call search_end(self%watch, run%t, error, ends)
         if (ends) return
         if (allocated(error)) then
            ! A trial point of Newton's whose orbit leaves Eq. 10 (the pad lifts
            ! off) or defeats the stepper returns nowhere: a result of the search.
            returned = .false.
            reason = error%message
            deallocate (error)
            return
         end if
         if (.not. returned) then
            reason = 'no slip onset within the longest return time'
            if (self%band) reason = 'no end of a hold at the band''s edge within the longest return time'
            return
         end if
         if (section_limit(p, run%y) /= sigma) then
            returned = .false.
            reason = 'the slip starts at the other static limit'
            return
         end if
         do i = 1, size(self%counts)
            self%counts(i) = count(events%kind(1:events%n) == i)
         end do
         period = run%t
         image = run%y(3:4)
         if (.not. self%tangent) return
         ! h = slope N' + level - σ (2x - y) (switched.f90, stick_exit_saltation).
         normal = [-2.0_wp * sigma, 0.0_wp, slope * (1.0_wp - p%kappa) + sigma, 0.0_wp]
         if (self%band) then
            ! The field outside the edge the block has just left by (slope 0: a hold's limit is constant).
            f = with_band%field()
         else if (self%config%uses_law()) then
            law_slip%params = p
            allocate (law_slip%law, source=with_law%law)
            law_slip%units = with_law%units
            law_slip%direction = -sigma
            call law_slip%rhs(run%t, run%y, f)
         else
            slip%params = p
            slip%direction = -sigma
            call slip%rhs(run%t, run%y, f)
         end if
         b = 0.0_wp
         b(:, 1) = [(1.0_wp + sigma * slope * (1.0_wp - p%kappa)) / 2, 0.0_wp, 1.0_wp, 0.0_wp]
         b(4, 2) = 1.0_wp
         projected = matmul(run%phi, b)
         do i = 1, 2
            projected(:, i) = projected(:, i) - f * dot_product(normal, projected(:, i)) / dot_product(normal, f)
         end do
         jacobian = projected(3:4, :)
      end associate
   end subroutine brake_map_evaluate

   !> The static limit's slope and level of the map's set-valued law; of a
   !> band law, the hold's limit max(F_s, the force just outside the edge) (slope 0).
   subroutine prepare_limit(map, error)
      type(brake_section_map), intent(inout) :: map
      type(error_type), allocatable, intent(out) :: error
      class(sliding_law), allocatable :: law
      type(law_units) :: units
      real(wp) :: half_width, limit

      call make_law(law_with_files(map%config%law), law, error)
      if (allocated(error)) return
      call map%config%law_units(units%force, units%velocity, units%time)
      call law%band(half_width, limit)
      map%band = half_width > 0.0_wp
      if (map%band) then
         ! The hold ends where the pull reaches its limit: F_s, or the force just outside the edge when larger.
         map%slope = 0.0_wp
         map%level = band_hold_limit(law, 1.0_wp) / units%force
      else
         call law_static_line(law, units, map%slope, map%level)
      end if
      map%prepared = .true.
   end subroutine prepare_limit

   pure integer function band_map_dimension(self)
      class(brake_band_map), intent(in) :: self

      band_map_dimension = self%plane%dimension()
   end function band_map_dimension

   subroutine band_map_evaluate(self, s, image, jacobian, period, returned, reason, error)
      class(brake_band_map), intent(inout) :: self
      real(wp), intent(in) :: s(:)
      real(wp), intent(out) :: image(:), jacobian(:, :), period
      logical, intent(out) :: returned
      character(len=:), allocatable, intent(out) :: reason
      type(error_type), allocatable, intent(out) :: error
      integer :: ns
      logical :: ends

      ! The run's first step at the section point (law_model.f90's rule), not a fixed one: from the
      ! creep band's edge a rate-and-state slip rate relaxes far faster than 1e-3 τ.
      ! (The exponential tangent's map of a law with kinks keeps its own.)
      ns = self%flow%n_states
      select type (plane => self%plane)
      type is (hyperplane_map)
         plane%first_step = self%flow%first_step(plane%solver%h_start, 0.0_wp, [s(1), plane%level, s(2), s(3)], &
            & s(4:3 + ns) * self%flow%scale(1:ns))
      end select
      call self%plane%evaluate(s, image, jacobian, period, returned, reason, error)
      call search_end(self%watch, period, error, ends)
      if (ends) return
      if (allocated(error)) then
         ! A trial point whose integration fails (the stepper gives up) returns nowhere.
         returned = .false.
         reason = error%message
         deallocate (error)
      end if
   end subroutine band_map_evaluate

   !> Whether a trial point's return ends the search: stopped on request
   !> inside its integration (the watch polls the reporter at intervals, so
   !> asking it again might not say so), or the watch says so now (a stop
   !> request, max_wall_time: an integration that failed keeps its error,
   !> the watch's own where it fired inside, with the time it reached).
   !> Otherwise a failed integration is the trial's result, no return.
   subroutine search_end(watch, t, error, ends)
      class(step_watch), pointer, intent(in) :: watch
      real(wp), intent(in) :: t
      type(error_type), allocatable, intent(inout) :: error
      logical, intent(out) :: ends
      type(error_type), allocatable :: stop

      ends = .false.
      if (.not. associated(watch)) return
      if (allocated(error)) then
         ends = error%stat == error_interrupted
         if (ends) return
      end if
      call watch%check(t, stop)
      ends = allocated(stop)
      if (ends .and. .not. allocated(error)) call move_alloc(stop, error)
   end subroutine search_end

   !> The periodic orbit through the run's first slip onset at or after
   !> t_start + transient (the guess), Newton on its section.  No slip onset
   !> there, or no convergence: found = .false. with the reason.  A
   !> single-valued law's slip onsets are the exits from the creep band.
   !> `watch` (a stop request, max_wall_time) ends the search with its error.
   subroutine brake_periodic_orbit(config, events, transient, settings, result, error, watch)
      type(brake_config), intent(in) :: config
      type(brake_event_table), intent(in) :: events
      real(wp), intent(in) :: transient
      type(orbit_settings), intent(in) :: settings
      type(brake_orbit), intent(out) :: result
      type(error_type), allocatable, intent(out) :: error
      class(step_watch), intent(inout), optional, target :: watch   !! asked in the search (search_end)
      integer :: j
      real(wp), allocatable :: times(:), states(:, :)
      type(error_type), allocatable :: run_error

      if (band_law(config)) then
         ! The run's events are the law's flow's; the band's own run finds the ends of its holds.
         result%section = 'band_hold_end'
         call hold_ends(config, config%t_start + transient, 1, times, states, run_error)
         if (allocated(run_error)) then
            result%orbit%reason = 'the run to the first end of a hold failed: '//run_error%message
            return
         end if
         if (size(times) == 0) then
            result%orbit%reason = 'no end of a hold at the band''s edge after orbit_transient'
            return
         end if
         result%guess_time = times(1)
         result%limit = section_limit(config%params, states(:, 1))
         call continue_orbit(config, result%limit, states(3:4, 1), settings, result, error, watch)
         return
      end if
      if (.not. exact_stick(config)) result%section = 'creep_band_exit'
      do j = 1, events%n
         if (events%kind(j) == event_stick_to_slip .and. events%t(j) >= config%t_start + transient) exit
      end do
      if (j > events%n) then
         result%orbit%reason = 'no slip onset after orbit_transient'
         return
      end if
      result%guess_time = events%t(j)
      if (exact_stick(config)) then
         result%limit = section_limit(config%params, events%state(:, j))
         call continue_orbit(config, result%limit, events%state(3:4, j), settings, result, error, watch)
      else
         ! The slip leaves the band in the direction s = -σ.
         result%limit = -sign(1.0_wp, events%state(2, j) - config%params%v_dr)
         block
            real(wp), allocatable :: states(:)
            call law_states_at(config, events%t(j), states, error)
            if (allocated(error)) then
               ! The run to the guess failed (it had not before): no guess, a result.
               result%orbit%reason = 'the run to the slip onset failed: '//error%message
               deallocate (error)
               return
            end if
            if (present(watch)) then
               ! (The run to the guess takes no watch: asked once it is done.)
               call watch%check(events%t(j), error)
               if (allocated(error)) return
            end if
            call continue_orbit(config, result%limit, [events%state([1, 3, 4], j), states], settings, result, &
               & error, watch)
         end block
      end if
   end subroutine brake_periodic_orbit

   !> The law's states (in units of their scale; none for a law without)
   !> at time t of the configuration's run: the event table keeps (x, v, y,
   !> w) alone, so the run is repeated up to t, the same stepper and
   !> tolerances (its states there as close to the first run's as the
   !> tolerances make them: a guess for Newton).
   subroutine law_states_at(config, t, states, error)
      type(brake_config), intent(in) :: config
      real(wp), intent(in) :: t
      real(wp), allocatable, intent(out) :: states(:)
      type(error_type), allocatable, intent(out) :: error
      type(law_integrator) :: run
      type(brake_event_table) :: events

      allocate (states(0))
      call run%start(config, config%t_start, initial_state(config), events, error)
      if (allocated(error)) return
      if (run%state_count() == 0) return
      call run%advance_to(t, events, error)
      if (allocated(error)) return
      deallocate (states)
      allocate (states(run%state_count()))
      call run%get_states(states)
   end subroutine law_states_at

   !> Newton from the section point guess at the limit σ: (y, w) on the
   !> stick-to-slip section, (x, y, w) on the creep band's exit.
   subroutine continue_orbit(config, limit, guess, settings, result, error, watch)
      type(brake_config), intent(in) :: config
      real(wp), intent(in) :: limit, guess(:)
      type(orbit_settings), intent(in) :: settings
      type(brake_orbit), intent(inout) :: result
      type(error_type), allocatable, intent(out) :: error
      class(step_watch), intent(inout), optional, target :: watch   !! asked in the search (search_end)
      type(brake_section_map) :: map
      logical :: band

      band = band_law(config)
      if (.not. (exact_stick(config) .or. band)) then
         call band_orbit(config, limit, guess, settings, result, error, watch)
         return
      end if
      if (band) result%section = 'band_hold_end'
      map%config = config
      map%limit = limit
      map%max_return = config%t_end - config%t_start
      if (present(watch)) map%watch => watch
      result%limit = limit
      call find_periodic_orbit(map, guess, settings, result%orbit, error)
      if (allocated(error)) return
      if (config%uses_law()) then
         result%state = limit_state(config%params, map%slope, map%level, limit, result%orbit%point)
         if (band) result%state(2) = hold_velocity(config, -limit)
      else
         result%state = section_state(config%params, limit, result%orbit%point)
      end if
      if (.not. result%orbit%found) return
      ! Newton's last evaluation was at the fixed point.
      result%pattern = map%counts
      result%multipliers(1:4) = floquet_multipliers(result%orbit, 1)
      result%exponents(1:4) = floquet_exponents(result%multipliers(1:4), result%orbit%period)
   end subroutine continue_orbit

   !> Newton on the creep band's exit of a single-valued law, guess (x, y, w,
   !> ẑ); the multipliers the trivial 1 and the 3 + m of the section map (no
   !> direction is forgotten: the creep only contracts).  The events of one
   !> period from a run of the orbit, over [T/2, 3T/2) (away from the
   !> section's own crossing at 0 and T).
   subroutine band_orbit(config, limit, guess, settings, result, error, watch)
      type(brake_config), intent(in) :: config
      real(wp), intent(in) :: limit, guess(:)
      type(orbit_settings), intent(in) :: settings
      type(brake_orbit), intent(inout) :: result
      type(error_type), allocatable, intent(out) :: error
      class(step_watch), intent(inout), optional, target :: watch   !! asked in the search (search_end)
      type(brake_law_flow) :: flow
      type(brake_band_map) :: map
      type(hyperplane_map) :: plane
      type(magnus_map) :: exponential
      type(kinked_system) :: kinked
      type(law_integrator), target :: run
      type(brake_event_table) :: events
      type(error_type), allocatable :: run_error
      real(wp) :: level, period
      integer :: i, ns

      result%section = 'creep_band_exit'
      result%limit = limit
      flow%params = config%params
      call make_law(law_with_files(config%law), flow%law, error)
      if (allocated(error)) return
      ! The flow with the law's states in units of their scale, as the run integrates them.
      ns = flow%law%state_count()
      result%n_states = ns
      flow%n_states = ns
      if (ns > 0) call flow%law%state_scale(flow%scale(1:ns))
      result%scale(1:ns) = flow%scale(1:ns)
      do i = 1, ns
         result%state_names(i) = flow%law%state_name(i)
         result%state_units(i) = flow%law%state_unit(i)
      end do
      call config%law_units(flow%units%force, flow%units%velocity, flow%units%time)
      flow%stick_velocity = config%stick_velocity
      ! The flow's coordinate 2 is v_rel (law_model.f90): the band's exit at -σ v_s, the kink at 0.
      level = -limit * config%stick_velocity
      if (present(watch)) then
         map%watch => watch
         exponential%watch => watch
         plane%watch => watch
      end if
      if (flow%law%kink_count() > 0) then
         ! The kinks the law declares (GMS's switch bands, whose elements relax at up to ~1e8 1/s): the
         ! tangent by exponentials over the orbit's steps, each kink a step's end, as the machine's map.
         allocate (kinked%base, source=flow)
         allocate (kinked%model, source=flow)
         call exponential%setup(kinked, config%solver, .false., 0.0_wp, 0.0_wp, 2, level, &
            & config%t_end - config%t_start, config%event_tolerance, falling=limit > 0.0_wp, &
            & rearm_level=-limit * config%stick_velocity / 2)
         allocate (map%plane, source=exponential)
      else if (ns > 0) then
         ! The states' rates have a kink at v_rel = 0 (|v_rel|, sgn v_rel), which the stick crosses.  A
         ! return must come back from half the band: the bristles' quick oscillation about the band's
         ! edge (stiff σ0) grazes it and would make a fixed point of P with a return time near 0.
         call plane%setup(flow, config%solver, 2, level, config%t_end - config%t_start, config%event_tolerance, &
            & falling=limit > 0.0_wp, kink_coordinate=[2], kink_level=[0.0_wp], &
            & rearm_level=-limit * config%stick_velocity / 2)
         allocate (map%plane, source=plane)
      else
         call plane%setup(flow, config%solver, 2, level, config%t_end - config%t_start, config%event_tolerance, &
            & falling=limit > 0.0_wp)
         allocate (map%plane, source=plane)
      end if
      map%flow = flow
      call find_periodic_orbit(map, guess, settings, result%orbit, error)
      if (allocated(error)) return
      result%state = [result%orbit%point(1), config%params%v_dr + level, result%orbit%point(2), result%orbit%point(3)]
      result%states(1:ns) = result%orbit%point(4:3 + ns)
      if (.not. result%orbit%found) return
      result%multipliers(1:4 + ns) = floquet_multipliers(result%orbit, 0)
      result%exponents(1:4 + ns) = floquet_exponents(result%multipliers(1:4 + ns), result%orbit%period)
      period = result%orbit%period
      call run%start(config, 0.0_wp, result%state, events, run_error)
      ! (start puts the states in steady sliding: the orbit's instead)
      if (.not. allocated(run_error) .and. ns > 0) call run%set_states(result%orbit%point(4:3 + ns))
      if (.not. allocated(run_error)) call run%advance_to(1.5_wp * period, events, run_error)
      if (allocated(run_error)) return   ! (the orbit closed; its pattern stays unknown, 0)
      do i = 1, size(result%pattern)
         result%pattern(i) = count(events%kind(1:events%n) == i .and. events%t(1:events%n) >= period / 2 &
            & .and. events%t(1:events%n) < 1.5_wp * period)
      end do
   end subroutine band_orbit

   !> The block's velocity in a hold at the band's edge of sign s (the
   !> edge's, in the brake's units).
   function hold_velocity(config, s) result(v)
      type(brake_config), intent(in) :: config
      real(wp), intent(in) :: s
      real(wp) :: v
      class(sliding_law), allocatable :: law
      type(law_units) :: units
      real(wp) :: half_width, limit

      call new_law(config%law, law)
      call law%band(half_width, limit)
      call config%law_units(units%force, units%velocity, units%time)
      v = config%params%v_dr + s * half_width / units%velocity
   end function hold_velocity

   !> A band law's run from the configuration's initial state through its
   !> band's switches (band.f90): the times and states of the ends of holds
   !> at the band's edge from t_from on, the first `most` of them, to t_end.
   subroutine hold_ends(config, t_from, most, times, states, error)
      type(brake_config), intent(in) :: config
      real(wp), intent(in) :: t_from
      integer, intent(in) :: most
      real(wp), allocatable, intent(out) :: times(:), states(:, :)
      type(error_type), allocatable, intent(out) :: error
      type(band_integrator), target :: run
      type(brake_event_table) :: events
      logical :: found

      allocate (times(0), states(4, 0))
      call run%start(config, config%t_start, initial_state(config), events, error)
      if (allocated(error)) return
      do while (run%t < config%t_end .and. size(times) < most)
         call run%advance_to_hold_end(config%t_end, events, found, error)
         if (allocated(error)) return
         call events%clear()
         if (found .and. run%t >= t_from) then
            times = [times, run%t]
            states = reshape([states, run%state()], [4, size(times)])
         end if
      end do
   end subroutine hold_ends

   !> The orbit `first` of the run (config) followed along the line from the
   !> continuation variable's value in config to `last` in n points: at each
   !> point Newton starts from the previous point's orbit (halving the step
   !> in the variable up to 5 times when it fails); where there was none or
   !> that fails, from the first slip onset after `transient` of a run at
   !> the point.  Every point's run also gives the attractor's slip onsets.
   !> Sequential: the result does not depend on ranks.
   subroutine follow_branch(config, first, last, n, transient, settings, branch, error, guard, reporter, watch)
      type(brake_config), intent(in) :: config
      type(brake_orbit), intent(in) :: first
      real(wp), intent(in) :: last, transient
      integer, intent(in) :: n
      type(orbit_settings), intent(in) :: settings
      type(orbit_branch), intent(out) :: branch
      type(error_type), allocatable, intent(out) :: error
      type(loop_guard), intent(in), optional :: guard   !! a stop request and max_wall_time, checked each point
      class(job_reporter), intent(inout), optional :: reporter
      class(step_watch), intent(inout), optional, target :: watch   !! asked in each point's orbit search
      type(brake_orbit) :: previous, current
      type(brake_config) :: point
      real(wp) :: start
      real(wp), allocatable :: onsets(:)
      integer :: k

      branch%variable = config%analysis%continuation
      call continuation_variable(config, start, branch%unit)
      allocate (branch%parameter(n), branch%found(n), branch%source(n), branch%period(n), branch%state(4, n), &
         & branch%multipliers(4 + orbit_states(config), n), branch%max_modulus(n), branch%kind(0), branch%at(0), &
         & branch%pattern(size(event_kind_names), n), &
         & branch%section_parameter(0), branch%section_x(0))
      branch%parameter = branch_values(start, last, n)
      previous = first
      do k = 1, n
         point = continuation_config(config, branch%parameter(k))
         if (k == 1) then
            current = first
            branch%source(k) = 2
            call attractor_onsets(point, transient, onsets, current, .false., error)
         else
            current = brake_orbit()
            if (previous%orbit%found) then
               call continue_along(config, branch%parameter(k - 1), branch%parameter(k), previous, settings, &
                  & current, error, watch)
               if (allocated(error)) return
            end if
            branch%source(k) = merge(1, 2, current%orbit%found)
            call attractor_onsets(point, transient, onsets, current, .not. current%orbit%found, error, settings, &
               & watch)
         end if
         if (allocated(error)) return
         branch%section_parameter = [branch%section_parameter, spread(branch%parameter(k), 1, size(onsets))]
         branch%section_x = [branch%section_x, onsets]
         call record(k, current)
         previous = current
         if (present(guard) .and. k < n) then
            call guard%check(reporter, '&analysis: the continuation of the orbit', branch%parameter(k), &
               & trim(branch%variable), error)
            if (allocated(error)) return
         end if
      end do
      call detect_bifurcations(config, branch)

   contains

      subroutine record(k, o)
         integer, intent(in) :: k
         type(brake_orbit), intent(in) :: o

         branch%found(k) = o%orbit%found
         branch%state(:, k) = o%state
         branch%multipliers(:, k) = o%multipliers(1:size(branch%multipliers, 1))
         branch%pattern(:, k) = o%pattern
         if (o%orbit%found) then
            branch%period(k) = o%orbit%period
            branch%max_modulus(k) = maxval(abs(o%orbit%multipliers))
         else
            branch%period(k) = ieee_value(1.0_wp, ieee_quiet_nan)
            branch%max_modulus(k) = ieee_value(1.0_wp, ieee_quiet_nan)
         end if
      end subroutine record

   end subroutine follow_branch

   !> m, the law's states the orbit's section carries: those of a
   !> single-valued law of &law (the creep band's exit), else none.
   integer function orbit_states(config)
      type(brake_config), intent(in) :: config
      class(sliding_law), allocatable :: law

      orbit_states = 0
      if (exact_stick(config)) return
      call new_law(config%law, law)
      orbit_states = law%state_count()
   end function orbit_states

   !> From the orbit `previous` at the value `from` to the value `to`.
   subroutine continue_along(config, from, to, previous, settings, result, error, watch)
      type(brake_config), intent(in) :: config
      real(wp), intent(in) :: from, to
      type(brake_orbit), intent(in) :: previous
      type(orbit_settings), intent(in) :: settings
      type(brake_orbit), intent(out) :: result
      type(error_type), allocatable, intent(out) :: error
      class(step_watch), intent(inout), optional, target :: watch
      type(brake_orbit) :: reached
      type(halving_walk) :: walk

      reached = previous
      call walk%start(from, to)
      do while (.not. walk%done)
         result = brake_orbit()
         call continue_orbit(continuation_config(config, walk%trial), reached%limit, reached%orbit%point, settings, &
            & result, error, watch)
         if (allocated(error)) return
         if (result%orbit%found) reached = result
         call walk%record(result%orbit%found)
      end do
   end subroutine continue_along

   !> A run at the point: x at its slip onsets after `transient` (at most
   !> max_section_points, the last ones) and, with `fresh`, the orbit through
   !> the first of them.  A run that fails (the pad lifts off) gives none.
   subroutine attractor_onsets(point, transient, onsets, orbit, fresh, error, settings, watch)
      type(brake_config), intent(in) :: point
      real(wp), intent(in) :: transient
      real(wp), allocatable, intent(out) :: onsets(:)
      type(brake_orbit), intent(inout) :: orbit
      logical, intent(in) :: fresh
      type(error_type), allocatable, intent(out) :: error
      type(orbit_settings), intent(in), optional :: settings
      class(step_watch), intent(inout), optional, target :: watch
      type(brake_run), target :: run
      type(error_type), allocatable :: run_error
      logical, allocatable :: keep(:)
      real(wp), allocatable :: times(:), states(:, :)

      allocate (onsets(0))
      if (band_law(point)) then
         ! The slip onsets are the ends of the band's holds, from the band's own run.
         call hold_ends(point, point%t_start + transient, huge(1), times, states, run_error)
         if (allocated(run_error)) then
            if (fresh) orbit%orbit%reason = 'the run at this point failed: '//run_error%message
            return
         end if
         onsets = states(1, max(1, size(times) - max_section_points + 1):)
         if (fresh) call brake_periodic_orbit(point, run%events, transient, settings, orbit, error, watch)
         return
      end if
      call simulate_brake(point, run, run_error)
      if (allocated(run_error)) then
         if (fresh) orbit%orbit%reason = 'the run at this point failed: '//run_error%message
         return
      end if
      associate (e => run%events)
         keep = e%kind(1:e%n) == event_stick_to_slip .and. e%t(1:e%n) >= point%t_start + transient
         onsets = pack(e%state(1, 1:e%n), keep)
         if (size(onsets) > max_section_points) onsets = onsets(size(onsets) - max_section_points + 1:)
      end associate
      if (fresh) call brake_periodic_orbit(point, run%events, transient, settings, orbit, error, watch)
   end subroutine attractor_onsets

   !> Between consecutive points with an orbit: a discontinuity (recorded at
   !> the midpoint, no multiplier compared), or
   !> the largest |μ| of the section map crossing 1: the kind from the critical multiplier on the
   !> outer side (complex: Neimark–Sacker; real < 0: period doubling; real
   !> > 0: fold), the value by linear interpolation of |μ| - 1.
   subroutine detect_bifurcations(config, branch)
      type(brake_config), intent(in) :: config
      type(orbit_branch), intent(inout) :: branch
      integer :: k, kind
      real(wp) :: half_crank_period, at
      logical :: crossed

      do k = 2, size(branch%parameter)
         if (.not. (branch%found(k - 1) .and. branch%found(k))) cycle
         ! κ, ξ at the midpoint (they can be the continuation variable).
         associate (p => continuation_config(config, (branch%parameter(k - 1) + branch%parameter(k)) / 2))
            half_crank_period = pi / sqrt(p%params%kappa / p%params%xi)
         end associate
         if (any(branch%pattern(:, k) /= branch%pattern(:, k - 1)) .or. &
            & abs(branch%period(k) - branch%period(k - 1)) > half_crank_period) then
            branch%kind = [branch%kind, bifurcation_discontinuity]
            branch%at = [branch%at, (branch%parameter(k - 1) + branch%parameter(k)) / 2]
            cycle
         end if
         ! Multipliers 2:3 are the section map's, the larger first.
         call modulus_crossing(branch%parameter(k - 1), branch%parameter(k), branch%max_modulus(k - 1), &
            & branch%max_modulus(k), branch%multipliers(2, k - 1), branch%multipliers(2, k), crossed, kind, at)
         if (.not. crossed) cycle
         branch%kind = [branch%kind, kind]
         branch%at = [branch%at, at]
      end do
   end subroutine detect_bifurcations

end module friction_brake_orbit
