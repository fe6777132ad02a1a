!> Periodic orbits of the machine, their Floquet multipliers, and their
!> continuation in one &machine variable (docs/chaos.md, "Orbits and
!> continuation of the machine"): Newton shooting on a section
!> (analysis/periodic_orbit.f90), the section map's Jacobian from the
!> variational equations Φ' = J Φ with the law's partial derivatives (the
!> analysis layer's tangent system), not from differences.  A set-valued law
!> (exact stick and slip) takes the same sections through the switching run
!> of switching.f90, with a saltation matrix at every switch; an orbit
!> through stick is superstable, its section multipliers 0 exactly.
!>
!> Coordinates.  The frame moves with the load point: e = x - load_velocity t
!> (e = x on the belt), so that the spring-slider driven at a constant
!> load-point velocity is autonomous too; the law's states in units of their
!> scale (as the run integrates them).
!>
!> Sections.  Without a moving support (support_amplitude or
!> support_frequency 0) the flow is autonomous: the section is v =
!> load_velocity crossed upwards (the spring's stretch at a minimum), its
!> coordinates e and the states; the multipliers are the trivial 1 and those
!> of the section map.  With one, the section is stroboscopic: the state at
!> t0 + j/support_frequency, all of it the section's coordinates, the period
!> 1/support_frequency.
!>
!> The equilibrium (autonomous, stiffness > 0): steady sliding at v =
!> load_velocity with the spring holding the law's steady force; its
!> eigenvalues locate a Hopf bifurcation along the continuation.
module friction_machine_orbit
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
   use friction_kinds, only: wp
   use friction_error, only: error_type, error_interrupted
   use friction_parameters, only: configurable, set_parameter_number, get_parameter, list_parameters, parameter_info
   use friction_ode_system, only: ode_system
   use friction_ode_solver, only: solver_settings
   use friction_ode_events, only: event_system
   use friction_ode_watch, only: step_watch
   use friction_law, only: sliding_law, max_law_states
   use friction_law_factory, only: make_law
   use friction_output_law_files, only: law_with_files
   use friction_analysis_periodic_orbit, only: section_map, orbit_settings, periodic_orbit, find_periodic_orbit, &
      & floquet_multipliers, floquet_exponents, hyperplane_map, stroboscopic_map, section_multipliers, &
      & halving_walk, branch_values, modulus_crossing
   use friction_machine_config, only: machine_config
   use friction_machine_run, only: machine_run, run_machine
   use friction_machine_switching, only: switching_section
   use friction_law_kinked, only: kinked_system
   use friction_machine_band, only: load_frame, band_frame, machine_band, band_none, band_at_section
   use friction_analysis_magnus_section, only: magnus_map
   implicit none
   private

   public :: machine_orbit, machine_periodic_orbit, machine_branch, follow_machine_branch, machine_bifurcation_names
   public :: machine_point_config, machine_orbit_forced, machine_orbit_names, machine_orbit_units

   !> /machine/orbit/bifurcations kinds: 1-3 as the brake's (a multiplier of the
   !> section map through -1, +1, a complex pair through |μ| = 1), 4 two orbits
   !> not continued one from the other, 5 Hopf of the equilibrium.
   integer, parameter :: bifurcation_discontinuity = 4, bifurcation_hopf = 5
   character(len=*), parameter :: machine_bifurcation_names(5) = [character(len=15) :: 'period_doubling', 'fold', &
      & 'neimark_sacker', 'discontinuity', 'hopf']

   !> Most section points of the attractor kept per point of the line (the diagram).
   integer, parameter :: max_section_points = 400

   !> The return map of a law with a band (either section, as hyperplane_map
   !> and stroboscopic_map), with a saltation matrix at every edge and the
   !> hold in the band at an edge as a mode of its own.
   type, extends(section_map) :: band_section
      type(band_frame) :: band
      type(solver_settings) :: solver
      logical :: forced = .false.
      real(wp) :: t0 = 0.0_wp, period = 0.0_wp, max_return = 0.0_wp, event_tolerance = 1.0e-10_wp
      class(step_watch), pointer :: watch => null()
   contains
      procedure :: dimension => band_section_dimension
      procedure :: evaluate => band_section_evaluate
   end type band_section

   !> Either section, a failed integration of a trial point being no return.
   type, extends(section_map) :: machine_section
      class(section_map), allocatable :: inner
      class(step_watch), pointer :: watch => null()
   contains
      procedure :: dimension => section_dimension
      procedure :: evaluate => section_evaluate
   end type machine_section

   !> A run's periodic orbit (/machine/orbit, docs/output.md).
   type :: machine_orbit
      type(periodic_orbit) :: orbit
      logical :: forced = .false.               !! stroboscopic section (a moving support)
      real(wp) :: guess_time = 0.0_wp           !! s: the run's section point Newton started from (t0 when forced)
      real(wp), allocatable :: state(:)         !! (2 + states) SI: e, v, the law's states at the section point
      real(wp), allocatable :: jacobian(:, :)   !! DP in SI section coordinates
      complex(wp), allocatable :: multipliers(:)  !! autonomous: 1 and the section map's; forced: the map's
      real(wp), allocatable :: exponents(:)     !! ln|μ|/T, 1/s
      integer :: sticks = -1                    !! stick phases over the period (a set-valued law's orbit; -1 none)
      real(wp) :: stick_time = 0.0_wp           !! s in stick over the period (the same)
      logical :: has_equilibrium = .false.
      real(wp), allocatable :: equilibrium(:)   !! (2 + states) SI
      complex(wp), allocatable :: eigenvalues(:)  !! of the equilibrium's Jacobian, 1/s, by decreasing real part
   end type machine_orbit

   !> The orbit followed along a line of one variable.
   type :: machine_branch
      character(len=24) :: variable = ''
      character(len=:), allocatable :: unit
      real(wp), allocatable :: parameter(:)           !! (p)
      logical, allocatable :: found(:)                !! (p)
      integer, allocatable :: source(:)               !! (p) 1: continued, 2: from the attractor
      real(wp), allocatable :: period(:)              !! (p) s; NaN where none
      real(wp), allocatable :: state(:, :)            !! (n, p)
      complex(wp), allocatable :: multipliers(:, :)   !! (m, p)
      real(wp), allocatable :: max_modulus(:)         !! (p) largest |μ| of the section map
      real(wp), allocatable :: growth(:)              !! (p) largest real part of the equilibrium's eigenvalues, 1/s
      integer, allocatable :: kind(:)                 !! bifurcations ...
      real(wp), allocatable :: at(:)                  !! ... at these values
      real(wp), allocatable :: section_parameter(:)   !! the attractor's section points: the variable ...
      real(wp), allocatable :: section_x(:)           !! ... and e there
   end type machine_branch

contains

   ! ---- a law with a band: its return map ----

   pure integer function band_section_dimension(self)
      class(band_section), intent(in) :: self

      band_section_dimension = self%band%dimension() - merge(0, 1, self%forced)
   end function band_section_dimension

   !> From the section point s with Φ = I to the return, as hyperplane_map
   !> or stroboscopic_map, through the band's switches (band.f90, the run's
   !> own; docs/chaos.md); without a moving support, Φ in a hold is projected
   !> along its one-dimensional flow (as exact stick's: switching.f90).
   subroutine band_section_evaluate(self, s, image, jacobian, period, returned, reason, error)
      class(band_section), intent(inout) :: self
      real(wp), intent(in) :: s(:)
      real(wp), intent(out) :: image(:), jacobian(:, :), period
      logical, intent(out) :: returned
      character(len=:), allocatable, intent(out) :: reason
      type(error_type), allocatable, intent(out) :: error
      type(machine_band), target :: run
      real(wp), allocatable :: y(:), f(:), row(:)
      real(wp) :: t_end, h
      integer :: n, i, outcome, events
      logical :: done
      !> Switches in one return beyond which the band's events are taken to chatter (no return).
      integer, parameter :: max_events = 100000

      n = self%band%dimension()
      image = s
      jacobian = 0.0_wp
      period = 0.0_wp
      returned = .false.
      reason = ''
      if (self%forced) then
         y = s
         t_end = self%t0 + self%period
      else
         y = [s(1), self%band%frame%base%m%load, s(2:)]
         t_end = self%t0 + self%max_return
      end if
      h = self%solver%h_start
      if (.not. (h > 0.0_wp)) h = 1.0e-6_wp
      run%project_in_hold = .not. self%forced
      call run%start(self%band, self%solver, self%event_tolerance, h, self%t0, y, .true., error)
      if (allocated(error)) return
      done = .false.
      events = 0
      do while (run%t < t_end)
         if (events >= max_events) then
            reason = 'more than 100000 switches at the band''s edges in one return'
            return
         end if
         events = events + 1
         if (associated(self%watch)) then
            call run%advance(t_end, outcome, error, self%watch)
         else
            call run%advance(t_end, outcome, error)
         end if
         if (allocated(error)) return
         if (outcome == band_none) exit
         ! A function exactly 0 at the start crosses at once (ode/events.f90): that is the start itself.
         if (outcome == band_at_section .and. run%t - self%t0 > 1.0e3_wp * self%event_tolerance) then
            done = .true.
            exit
         end if
      end do
      if (self%forced) then
         image = run%y
         jacobian = run%phi
         period = self%period
      else
         if (.not. done) then
            reason = 'no return to the section v = load_velocity within t_end - t_start'
            return
         end if
         ! The projection along the flow onto the section (hyperplane_map's).
         allocate (f(n))
         call self%band%rhs(run%t, run%y, f)
         row = run%phi(2, :)
         do i = 1, n
            run%phi(i, :) = run%phi(i, :) - f(i) * row / f(2)
         end do
         image = [run%y(1), run%y(3:n)]
         jacobian = run%phi([1, (i, i=3, n)], [1, (i, i=3, n)])
         period = run%t - self%t0
      end if
      returned = .true.
   end subroutine band_section_evaluate

   ! ---- the section, trial failures as no return ----

   pure integer function section_dimension(self)
      class(machine_section), intent(in) :: self

      section_dimension = self%inner%dimension()
   end function section_dimension

   subroutine section_evaluate(self, s, image, jacobian, period, returned, reason, error)
      class(machine_section), intent(inout) :: self
      real(wp), intent(in) :: s(:)
      real(wp), intent(out) :: image(:), jacobian(:, :), period
      logical, intent(out) :: returned
      character(len=:), allocatable, intent(out) :: reason
      type(error_type), allocatable, intent(out) :: error

      type(error_type), allocatable :: stop

      call self%inner%evaluate(s, image, jacobian, period, returned, reason, error)
      ! A stop request ends the search: the watch polls the reporter at intervals, so asking it again
      ! here would not say so and the request would pass for a trial's failure.
      if (allocated(error)) then
         if (error%stat == error_interrupted) return
      end if
      if (allocated(error) .and. associated(self%watch)) then
         ! max_wall_time ends the search (the watch still says so), with its own message.
         call self%watch%check(0.0_wp, stop)
         if (allocated(stop)) return
      end if
      if (allocated(error)) then
         ! A trial point of Newton's whose integration fails returns nowhere: a result of the search.
         returned = .false.
         reason = error%message
         deallocate (error)
      end if
   end subroutine section_evaluate

   ! ---- settings ----

   !> A moving support makes the flow periodic in time: the stroboscopic section.
   pure logical function machine_orbit_forced(c)
      type(machine_config), intent(in) :: c

      machine_orbit_forced = c%support_amplitude > 0.0_wp .and. c%support_frequency > 0.0_wp
   end function machine_orbit_forced

   !> Names and units of the orbit's state (e, v, the law's states).
   subroutine machine_orbit_names(c, names, units, error)
      type(machine_config), intent(in) :: c
      character(len=:), allocatable, intent(out) :: names, units
      type(error_type), allocatable, intent(out) :: error
      class(sliding_law), allocatable :: law
      integer :: k

      call make_law(law_with_files(c%law), law, error)
      if (allocated(error)) return
      names = 'x, v'
      units = 'm, m/s'
      do k = 1, law%state_count()
         names = names//', '//law%state_name(k)
         units = units//', '//law%state_unit(k)
      end do
   end subroutine machine_orbit_names

   !> The unit of the continuation variable and its value in c.
   subroutine machine_orbit_units(c, value, unit)
      type(machine_config), intent(in) :: c
      real(wp), intent(out) :: value
      character(len=:), allocatable, intent(out) :: unit
      type(machine_config) :: copy
      type(parameter_info), allocatable :: list(:)
      character(len=:), allocatable :: text, problem
      integer :: k, stat

      copy = c   ! (the visitor takes its object inout)
      call get_parameter(copy, 'machine', trim(c%analysis%continuation), 0, text, problem)
      value = 0.0_wp
      read (text, *, iostat=stat) value   ! (round-trip text of a checked variable: it reads)
      list = list_parameters(copy)
      unit = ''
      do k = 1, size(list)
         ! (The orbit's variables are named in no other group of the scene's.)
         if (list(k)%name == c%analysis%continuation) unit = trim(list(k)%unit)
      end do
   end subroutine machine_orbit_units

   !> c with the continuation variable set to `value` (and no continuation of its own).
   function machine_point_config(c, value) result(point)
      type(machine_config), intent(in) :: c
      real(wp), intent(in) :: value
      type(machine_config) :: point
      character(len=:), allocatable :: problem

      point = c
      point%analysis%continuation = ''
      call set_parameter_number(point, 'machine', trim(c%analysis%continuation), value, problem)
   end function machine_point_config

   ! ---- the orbit ----

   !> The system in the load point's frame and the law's state scales.
   subroutine frame_of(c, frame, scale, error)
      type(machine_config), intent(in) :: c
      type(load_frame), intent(out) :: frame
      real(wp), allocatable, intent(out) :: scale(:)
      type(error_type), allocatable, intent(out) :: error
      class(sliding_law), allocatable :: law
      integer :: ns

      call make_law(law_with_files(c%law), law, error)
      if (allocated(error)) return
      ns = law%state_count()
      call frame%base%m%from_config(c)
      allocate (frame%base%law, source=law)
      frame%base%n_states = ns
      if (ns > 0) call law%state_scale(frame%base%scale(1:ns))
      scale = [1.0_wp, 1.0_wp, frame%base%scale(1:ns)]
   end subroutine frame_of

   !> Steady sliding at v = load_velocity (autonomous, stiffness > 0) and the
   !> eigenvalues of the Jacobian there.
   subroutine equilibrium_of(c, result, error)
      type(machine_config), intent(in) :: c
      type(machine_orbit), intent(inout) :: result
      type(error_type), allocatable, intent(out) :: error
      type(load_frame) :: frame
      real(wp), allocatable :: scale(:), y(:), jac(:, :), dfdt(:)
      real(wp) :: w, force, z(max_law_states)
      complex(wp), allocatable :: mu(:)
      integer :: n, ns, i, j

      result%has_equilibrium = .false.
      call frame_of(c, frame, scale, error)
      if (allocated(error)) return
      n = frame%dimension()
      ns = n - 2
      if (machine_orbit_forced(c) .or. .not. (c%stiffness > 0.0_wp)) return
      w = c%load_velocity - c%belt_velocity
      ! A set-valued law at w = 0 holds the block in stick: no sliding state, no eigenvalues.
      if (frame%base%law%set_valued() .and. w == 0.0_wp) return
      z = 0.0_wp
      if (ns > 0) call frame%base%law%steady_state(w, c%normal, z(1:ns))
      force = frame%base%law%force(w, z(1:ns), c%normal, 0.0_wp)
      ! m v' = A - F = 0 with A = -k e at v = load_velocity.
      y = [-force / c%stiffness, c%load_velocity, z(1:ns) / frame%base%scale(1:ns)]
      allocate (jac(n, n), dfdt(n))
      call frame%jacobian(0.0_wp, y, jac, dfdt)
      mu = section_multipliers(jac)
      ! By decreasing real part (a complex pair: positive imaginary part first).
      do i = 1, n - 1
         do j = 1, n - i
            if (real(mu(j + 1)) > real(mu(j)) .or. (real(mu(j + 1)) == real(mu(j)) .and. &
               & aimag(mu(j + 1)) > aimag(mu(j)))) mu([j, j + 1]) = mu([j + 1, j])
         end do
      end do
      result%has_equilibrium = .true.
      result%equilibrium = y * scale
      result%eigenvalues = mu
   end subroutine equilibrium_of

   !> The section map of c (setup only) and its dimension.
   subroutine section_of(c, frame, t0, map, watch)
      type(machine_config), intent(in) :: c
      type(load_frame), intent(in) :: frame
      real(wp), intent(in) :: t0
      type(machine_section), intent(out) :: map
      class(step_watch), intent(inout), optional, target :: watch

      if (frame%base%law%set_valued()) then
         block
            ! Exact stick and slip: the switching run's map, saltations included (switching.f90).
            type(switching_section) :: jumps
            real(wp) :: period
            period = 0.0_wp
            if (machine_orbit_forced(c)) period = 1.0_wp / c%support_frequency
            call jumps%setup(c, frame%base%law, machine_orbit_forced(c), t0, period, c%t_end - c%t_start)
            if (present(watch)) jumps%watch => watch
            allocate (map%inner, source=jumps)
         end block
      else if (has_band(frame)) then
         block
            ! A band with a jumping force at its edges (Karnopp's): the events and saltations of band_section.
            type(band_section) :: banded
            banded%band%frame = frame
            call banded%band%set_limits()
            banded%band%sectioned = .not. machine_orbit_forced(c)
            banded%solver = c%solver
            banded%forced = machine_orbit_forced(c)
            banded%t0 = t0
            if (banded%forced) banded%period = 1.0_wp / c%support_frequency
            banded%max_return = c%t_end - c%t_start
            banded%event_tolerance = c%event_tolerance
            if (present(watch)) banded%watch => watch
            allocate (map%inner, source=banded)
         end block
      else if (frame%base%n_states > 0) then
         block
            ! A law with states (stiff bristles, GMS elements): the tangent by exponentials over the orbit's steps.
            type(magnus_map) :: exponential
            class(ode_system), allocatable :: flow
            type(kinked_system) :: kinked
            if (frame%base%law%kink_count() > 0) then
               allocate (kinked%base, source=frame)
               allocate (kinked%model, source=frame%base)
               allocate (flow, source=kinked)
            else
               allocate (flow, source=frame)
            end if
            if (machine_orbit_forced(c)) then
               call exponential%setup(flow, c%solver, .true., t0, 1.0_wp / c%support_frequency, 2, 0.0_wp, &
                  & 0.0_wp, c%event_tolerance)
            else
               call exponential%setup(flow, c%solver, .false., 0.0_wp, 0.0_wp, 2, c%load_velocity, &
                  & c%t_end - c%t_start, c%event_tolerance)
            end if
            if (present(watch)) exponential%watch => watch
            allocate (map%inner, source=exponential)
         end block
      else if (machine_orbit_forced(c)) then
         block
            type(stroboscopic_map) :: strobe
            call strobe%setup(frame, c%solver, t0, 1.0_wp / c%support_frequency)
            if (present(watch)) strobe%watch => watch
            allocate (map%inner, source=strobe)
         end block
      else
         block
            type(hyperplane_map) :: plane
            call plane%setup(frame, c%solver, 2, c%load_velocity, c%t_end - c%t_start, c%event_tolerance)
            if (present(watch)) plane%watch => watch
            allocate (map%inner, source=plane)
         end block
      end if
      if (present(watch)) map%watch => watch
   end subroutine section_of

   !> Whether the law has a band whose edges make its force jump.
   logical function has_band(frame)
      type(load_frame), intent(in) :: frame
      real(wp) :: width, limit

      call frame%base%law%band(width, limit)
      has_band = width > 0.0_wp
   end function has_band

   !> The run's state (frame coordinates, scaled) interpolated at the section
   !> point after t_start + transient: the first upward crossing of v =
   !> load_velocity, or t0 = t_start + j/support_frequency when forced.
   subroutine guess_from_run(c, run, scale, transient, guess, t_guess, found)
      type(machine_config), intent(in) :: c
      type(machine_run), intent(in) :: run
      real(wp), intent(in) :: scale(:), transient
      real(wp), allocatable, intent(out) :: guess(:)
      real(wp), intent(out) :: t_guess
      logical, intent(out) :: found
      real(wp) :: f, full(size(scale))
      integer :: i, n

      n = size(scale)
      found = .false.
      t_guess = 0.0_wp
      allocate (guess(0))
      do i = 2, run%n
         if (run%t(i) < c%t_start + transient) cycle
         if (machine_orbit_forced(c)) then
            t_guess = c%t_start + ceiling((transient - 1.0e-9_wp * c%dt_out) * c%support_frequency) &
               & / c%support_frequency
            if (.not. (run%t(i) >= t_guess .and. run%t(i - 1) <= t_guess)) cycle
            f = (t_guess - run%t(i - 1)) / (run%t(i) - run%t(i - 1))
         else
            if (.not. (run%v(i - 1) < c%load_velocity .and. run%v(i) >= c%load_velocity)) cycle
            f = (c%load_velocity - run%v(i - 1)) / (run%v(i) - run%v(i - 1))
            t_guess = run%t(i - 1) + f * (run%t(i) - run%t(i - 1))
         end if
         full(1) = (1.0_wp - f) * run%x(i - 1) + f * run%x(i) - c%load_velocity * t_guess
         full(2) = (1.0_wp - f) * run%v(i - 1) + f * run%v(i)
         if (n > 2) full(3:n) = ((1.0_wp - f) * run%states(1:n - 2, i - 1) + f * run%states(1:n - 2, i)) / scale(3:n)
         if (machine_orbit_forced(c)) then
            guess = full
         else
            guess = [full(1), full(3:n)]
         end if
         found = .true.
         return
      end do
   end subroutine guess_from_run

   !> The periodic orbit through the run's first section point after
   !> t_start + transient, Newton on its section.
   subroutine machine_periodic_orbit(c, run, transient, settings, result, error, watch)
      type(machine_config), intent(in) :: c
      type(machine_run), intent(in) :: run
      real(wp), intent(in) :: transient
      type(orbit_settings), intent(in) :: settings
      type(machine_orbit), intent(out) :: result
      type(error_type), allocatable, intent(out) :: error
      class(step_watch), intent(inout), optional :: watch   !! asked inside every integration of the search
      type(load_frame) :: frame
      real(wp), allocatable :: scale(:), guess(:)
      logical :: found

      call frame_of(c, frame, scale, error)
      if (allocated(error)) return
      call guess_from_run(c, run, scale, transient, guess, result%guess_time, found)
      if (.not. found) then
         result%forced = machine_orbit_forced(c)
         result%state = run_state_at_end()
         if (result%forced) then
            result%orbit%reason = 'the run does not reach a strobe after orbit_transient'
         else
            result%orbit%reason = 'v does not cross load_velocity upwards after orbit_transient (no oscillation)'
         end if
         call equilibrium_of(c, result, error)
         return
      end if
      call orbit_from(c, guess, result%guess_time, settings, result, error, watch)

   contains

      function run_state_at_end() result(y)
         real(wp), allocatable :: y(:)

         y = [run%x(run%n) - c%load_velocity * run%t(run%n), run%v(run%n), run%states(1:size(scale) - 2, run%n)]
      end function run_state_at_end

   end subroutine machine_periodic_orbit

   !> Newton from the section point `guess` (scaled section coordinates).
   subroutine orbit_from(c, guess, t_guess, settings, result, error, watch)
      type(machine_config), intent(in) :: c
      real(wp), intent(in) :: guess(:), t_guess
      type(orbit_settings), intent(in) :: settings
      type(machine_orbit), intent(inout) :: result
      type(error_type), allocatable, intent(out) :: error
      class(step_watch), intent(inout), optional, target :: watch
      type(load_frame) :: frame
      type(machine_section) :: map
      real(wp), allocatable :: scale(:), section_scale(:)
      complex(wp), allocatable :: logs(:)
      real(wp) :: start(size(guess))
      character(len=:), allocatable :: reason
      logical :: entered
      integer :: n, i, j

      call frame_of(c, frame, scale, error)
      if (allocated(error)) return
      n = size(scale)
      result%forced = machine_orbit_forced(c)
      result%guess_time = t_guess
      call section_of(c, frame, t_guess, map, watch)
      start = guess
      select type (inner => map%inner)
      type is (magnus_map)
         ! The run's interpolated section point may lie where the flow crosses downwards (rate and state's
         ! slow creep crosses v = load_velocity with v' ~ 1e-7 m/s^2): the flow's next upward crossing instead.
         call inner%enter(start, entered, reason, error)
         if (allocated(error)) return
         if (.not. entered) then
            result%orbit%point = guess
            result%orbit%reason = reason
            ! (The state too, which the file and a branch's point read: unset, its size was garbage.)
            result%state = state_at(guess)
            call equilibrium_of(c, result, error)
            return
         end if
      end select
      call find_periodic_orbit(map, start, settings, result%orbit, error)
      if (allocated(error)) return
      select type (inner => map%inner)
      type is (switching_section)
         ! The last evaluation was Newton's last iterate's; a strobe point in stick is one stick phase.
         result%sticks = max(inner%sticks, merge(1, 0, inner%stuck))
         result%stick_time = inner%stick_time
         ! Through a stick the stroboscopic DP = M [r; 0] (δv forgotten, M the rest of the period) has rank 1:
         ! its multipliers are trace DP and 0 exactly, not 0 plus the round-off of the closed form's det.
         if (result%orbit%found .and. result%forced .and. inner%stuck) result%orbit%multipliers = &
            & [cmplx(result%orbit%jacobian(1, 1) + result%orbit%jacobian(2, 2), 0.0_wp, wp), (0.0_wp, 0.0_wp)]
      end select
      call equilibrium_of(c, result, error)
      if (allocated(error)) return
      section_scale = scale
      if (.not. result%forced) section_scale = [scale(1), scale(3:n)]
      result%state = state_at(result%orbit%point)
      if (.not. result%orbit%found) return
      if (result%has_equilibrium) then
         ! Newton may close on the equilibrium itself, which lies on the section: no orbit.
         if (maxval(abs(result%state - result%equilibrium) / scale) <= 100.0_wp * settings%tolerance) then
            result%orbit%found = .false.
            result%orbit%reason = 'Newton reached the equilibrium (steady sliding), which is no orbit'
            return
         end if
      end if
      associate (m => size(result%orbit%jacobian, 1))
         allocate (result%jacobian(m, m))
         do j = 1, m
            do i = 1, m
               result%jacobian(i, j) = result%orbit%jacobian(i, j) * section_scale(i) / section_scale(j)
            end do
         end do
      end associate
      if (result%forced) then
         result%multipliers = result%orbit%multipliers
      else
         result%multipliers = floquet_multipliers(result%orbit, 0)
      end if
      result%exponents = floquet_exponents(result%multipliers, result%orbit%period)
      select type (inner => map%inner)
      type is (magnus_map)
         ! The multipliers from the monodromy's factors, resolved however small: exp of their logs (0 where
         ! that underflows), the exponents ln|μ|/T from the logs themselves (docs/chaos.md).
         logs = inner%log_multipliers()
         result%orbit%multipliers = exp(logs)
         if (result%forced) then
            result%multipliers = result%orbit%multipliers
            result%exponents = real(logs) / result%orbit%period
         else
            result%multipliers = floquet_multipliers(result%orbit, 0)
            result%exponents = [0.0_wp, real(logs) / result%orbit%period]
         end if
      end select

   contains

      !> A section point (scaled section coordinates) as the state in SI: e, v, the law's states.
      function state_at(point) result(state)
         real(wp), intent(in) :: point(:)
         real(wp), allocatable :: state(:)

         if (result%forced) then
            state = point * scale
         else
            state = [point(1), c%load_velocity, point(2:) * scale(3:n)]
         end if
      end function state_at
   end subroutine orbit_from

   ! ---- continuation ----

   !> The orbit `first` of the run of c followed along the line from the
   !> continuation variable's value in c to `last` in p points: Newton from
   !> the previous point's orbit (halving the step up to 5 times when it
   !> fails), else from the attractor of a run at the point; every point's
   !> run gives the attractor's section points; the equilibrium's
   !> eigenvalues at every point.  `watch` is asked between points.
   subroutine follow_machine_branch(c, first, last, p, transient, settings, branch, error, watch)
      type(machine_config), intent(in) :: c
      type(machine_orbit), intent(in) :: first
      real(wp), intent(in) :: last, transient
      integer, intent(in) :: p
      type(orbit_settings), intent(in) :: settings
      type(machine_branch), intent(out) :: branch
      type(error_type), allocatable, intent(out) :: error
      class(step_watch), intent(inout), optional :: watch   !! asked inside every integration
      type(machine_orbit) :: previous, current
      type(machine_config) :: point
      type(machine_run) :: run
      real(wp) :: start
      real(wp), allocatable :: points(:)
      integer :: k, n, m

      branch%variable = c%analysis%continuation
      call machine_orbit_units(c, start, branch%unit)
      n = size(first%state)
      m = n   ! forced: the section map's n; autonomous: 1 and the section map's n - 1
      allocate (branch%parameter(p), branch%found(p), branch%source(p), branch%period(p), branch%state(n, p), &
         & branch%multipliers(m, p), branch%max_modulus(p), branch%growth(p), branch%kind(0), branch%at(0), &
         & branch%section_parameter(0), branch%section_x(0))
      branch%parameter = branch_values(start, last, p)
      previous = first
      do k = 1, p
         point = machine_point_config(c, branch%parameter(k))
         call run_machine(point, run, error, watch)
         if (allocated(error)) return
         if (k == 1) then
            current = first
            branch%source(k) = 2
         else
            current = machine_orbit()
            if (previous%orbit%found) then
               call continue_along(c, branch%parameter(k - 1), branch%parameter(k), previous, settings, current, &
                  & error, watch)
               if (allocated(error)) return
            end if
            branch%source(k) = merge(1, 2, current%orbit%found)
            if (.not. current%orbit%found) then
               call machine_periodic_orbit(point, run, transient, settings, current, error, watch)
               if (allocated(error)) return
            end if
         end if
         if (.not. current%has_equilibrium .and. .not. allocated(current%eigenvalues)) then
            call equilibrium_of(point, current, error)
            if (allocated(error)) return
         end if
         points = attractor_points(point, run, transient)
         branch%section_parameter = [branch%section_parameter, spread(branch%parameter(k), 1, size(points))]
         branch%section_x = [branch%section_x, points]
         call record(k, current)
         previous = current
         if (present(watch) .and. k < p) then
            call watch%check(c%t_end, error)
            if (allocated(error)) return
         end if
      end do
      call detect(c, branch, error)

   contains

      subroutine record(k, o)
         integer, intent(in) :: k
         type(machine_orbit), intent(in) :: o
         real(wp) :: nan

         nan = ieee_value(1.0_wp, ieee_quiet_nan)
         branch%found(k) = o%orbit%found
         branch%state(:, k) = nan
         if (allocated(o%state)) branch%state(:, k) = o%state
         branch%multipliers(:, k) = cmplx(nan, nan, wp)
         branch%period(k) = nan
         branch%max_modulus(k) = nan
         if (o%orbit%found) then
            branch%multipliers(:, k) = o%multipliers
            branch%period(k) = o%orbit%period
            branch%max_modulus(k) = maxval(abs(o%orbit%multipliers))
         end if
         branch%growth(k) = nan
         if (o%has_equilibrium) branch%growth(k) = maxval(real(o%eigenvalues))
      end subroutine record

   end subroutine follow_machine_branch

   !> From the orbit `previous` at the value `from` to the value `to`.
   subroutine continue_along(c, from, to, previous, settings, result, error, watch)
      type(machine_config), intent(in) :: c
      real(wp), intent(in) :: from, to
      type(machine_orbit), intent(in) :: previous
      type(orbit_settings), intent(in) :: settings
      type(machine_orbit), intent(out) :: result
      type(error_type), allocatable, intent(out) :: error
      class(step_watch), intent(inout), optional :: watch
      type(machine_orbit) :: reached
      type(halving_walk) :: walk

      reached = previous
      call walk%start(from, to)
      do while (.not. walk%done)
         result = machine_orbit()
         call orbit_from(machine_point_config(c, walk%trial), reached%orbit%point, reached%guess_time, settings, &
            & result, error, watch)
         if (allocated(error)) return
         if (result%orbit%found) reached = result
         call walk%record(result%orbit%found)
      end do
   end subroutine continue_along

   !> e at the run's section points after the transient (at most
   !> max_section_points, the last ones), linearly interpolated on the grid.
   function attractor_points(c, run, transient) result(points)
      type(machine_config), intent(in) :: c
      type(machine_run), intent(in) :: run
      real(wp), intent(in) :: transient
      real(wp), allocatable :: points(:)
      real(wp) :: f, t, strobe
      integer :: i

      allocate (points(0))
      strobe = 0.0_wp
      if (machine_orbit_forced(c)) strobe = c%t_start + ceiling((transient - 1.0e-9_wp * c%dt_out) &
         & * c%support_frequency) / c%support_frequency
      do i = 2, run%n
         if (run%t(i) < c%t_start + transient) cycle
         if (machine_orbit_forced(c)) then
            if (.not. (run%t(i) >= strobe .and. run%t(i - 1) <= strobe)) cycle
            t = strobe
            f = (t - run%t(i - 1)) / (run%t(i) - run%t(i - 1))
            strobe = strobe + 1.0_wp / c%support_frequency
         else
            if (.not. (run%v(i - 1) < c%load_velocity .and. run%v(i) >= c%load_velocity)) cycle
            f = (c%load_velocity - run%v(i - 1)) / (run%v(i) - run%v(i - 1))
            t = run%t(i - 1) + f * (run%t(i) - run%t(i - 1))
         end if
         points = [points, (1.0_wp - f) * run%x(i - 1) + f * run%x(i) - c%load_velocity * t]
      end do
      if (size(points) > max_section_points) points = points(size(points) - max_section_points + 1:)
   end function attractor_points

   !> Between consecutive points: the largest |μ| of the section map through
   !> 1 (kinds 1-3, linear interpolation of |μ| - 1), unless the second orbit
   !> was not continued from the first (4, at the midpoint); the largest
   !> real part of the equilibrium's eigenvalues through 0 with a complex
   !> pair (5, Hopf), located by bisection on the equilibrium to 1e-12 of the step.
   subroutine detect(c, branch, error)
      type(machine_config), intent(in) :: c
      type(machine_branch), intent(inout) :: branch
      type(error_type), allocatable, intent(out) :: error
      integer :: k, critical, kind
      real(wp) :: at
      logical :: crossed

      do k = 2, size(branch%parameter)
         if (branch%found(k - 1) .and. branch%found(k)) then
            if (branch%source(k) /= 1) then
               branch%kind = [branch%kind, bifurcation_discontinuity]
               branch%at = [branch%at, (branch%parameter(k - 1) + branch%parameter(k)) / 2]
            else
               ! The section map's multipliers, the largest first (after the trivial 1 when autonomous).
               critical = merge(1, 2, machine_orbit_forced(c))
               call modulus_crossing(branch%parameter(k - 1), branch%parameter(k), branch%max_modulus(k - 1), &
                  & branch%max_modulus(k), branch%multipliers(critical, k - 1), branch%multipliers(critical, k), &
                  & crossed, kind, at)
               if (crossed) then
                  branch%kind = [branch%kind, kind]
                  branch%at = [branch%at, at]
               end if
            end if
         end if
         if (branch%growth(k - 1) * branch%growth(k) < 0.0_wp) then
            call hopf(branch%parameter(k - 1), branch%parameter(k), error)
            if (allocated(error)) return
         end if
      end do

   contains

      !> Bisection of the largest real part between a and b; a Hopf when the
      !> eigenvalue crossing is one of a complex pair.
      subroutine hopf(a, b, error)
         real(wp), intent(in) :: a, b
         type(error_type), allocatable, intent(out) :: error
         type(machine_orbit) :: e
         real(wp) :: lo, hi, mid, g_lo, g_mid
         integer :: iteration

         lo = a
         hi = b
         g_lo = growth_at(lo, e, error)
         if (allocated(error)) return
         do iteration = 1, 200
            if (abs(hi - lo) <= 1.0e-12_wp * abs(b - a)) exit
            mid = (lo + hi) / 2
            g_mid = growth_at(mid, e, error)
            if (allocated(error)) return
            if (g_mid * g_lo > 0.0_wp) then
               lo = mid
               g_lo = g_mid
            else
               hi = mid
            end if
         end do
         mid = (lo + hi) / 2
         g_mid = growth_at(mid, e, error)
         if (allocated(error)) return
         if (aimag(e%eigenvalues(1)) == 0.0_wp) return
         branch%kind = [branch%kind, bifurcation_hopf]
         branch%at = [branch%at, mid]
      end subroutine hopf

      real(wp) function growth_at(value, e, error)
         real(wp), intent(in) :: value
         type(machine_orbit), intent(out) :: e
         type(error_type), allocatable, intent(out) :: error

         call equilibrium_of(machine_point_config(c, value), e, error)
         growth_at = 0.0_wp
         if (allocated(error) .or. .not. e%has_equilibrium) return
         growth_at = real(e%eigenvalues(1))
      end function growth_at

   end subroutine detect

end module friction_machine_orbit
