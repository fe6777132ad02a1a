!> The brake with any friction law of &law (&brake model = 'law';
!> docs/laws.md, "The brake with any law").  Eq. 10 with the law's force in
!> place of the arctan law's:
!>
!>   x'' = A - F(v_rel, z, N', A),   A = -(2x - y),   ξ y'' = x - κ y,
!>
!> A being the springs' pull on the block, in the brake's units (forces over
!> k1 in m, velocities in m per unit τ, time τ).  The law computes in its
!> own: a brake force is `force` N, a velocity `velocity` m/s and a unit τ
!> `time` s (brake_config%law_units: SI with units = 'dimensional', else 1).
!>
!> - A single-valued law (arctan, Dahl, LuGre, elasto-plastic, rate and
!>   state; Karnopp's flow too, which band.f90 runs with its band's edges
!>   located) is one ODE in (x, v_rel, y, w, ẑ), the slip rate
!>   v_rel = v - v_dr in place of v (x' = v_rel + v_dr, v_rel' = v'): a
!>   creep in stick far below the spacing of v_dr's doubles (rate and state)
!>   is resolved, not rounded to v_dr; the law's states in
!>   units of their scale (the tangent's and Benettin's state too: the
!>   integrator gives and takes them); events as the regularized model's: N' falling
!>   through 0 (the pad lifts off: an error) and the edges of the creep
!>   band |v_rel| <= stick_velocity that the output counts as stick.
!> - A set-valued law (Coulomb, Stribeck, the table) switches exactly as
!>   the switched model does: the stick phase in closed form
!>   (friction_brake_stick) until |2x - y| reaches the law's static limit,
!>   which is affine in N' (μs N' for Coulomb, F_s for the force laws;
!>   checked on input); a slip with the law's slip force at the sign s of
!>   v_rel held fixed, ended when s v_rel falls through 0.
module friction_brake_law_model
   use friction_kinds, only: wp
   use friction_error, only: error_type, fatal_error, error_numerical
   use friction_strings, only: rtoa
   use friction_ode_events, only: event_system, event_falling, event_either
   use friction_law, only: sliding_law, max_law_states
   use friction_law_kinked, only: law_flow
   use friction_law_factory, only: make_law
   use friction_output_law_files, only: law_with_files
   use friction_brake_params, only: brake_parameters
   use friction_brake_config, only: brake_config
   use friction_brake_integrator, only: brake_integrator
   use friction_brake_stick, only: stick_motion, stick_end_lift_off, stick_end_force_positive, stick_tangent
   use friction_brake_switched, only: saltation, stick_field, slip_events
   use friction_analysis_lyapunov_spectrum, only: tangent_system
   use friction_brake_record, only: brake_event_table, event_stick_to_slip, event_slip_to_stick, &
      & event_slip_reversal
   implicit none
   private

   public :: law_integrator, brake_law_flow, brake_law_slip, law_units, law_static_line

   !> The brake's units in the law's: one brake force is `force` N, one
   !> brake velocity `velocity` m/s, one unit τ `time` s.
   type :: law_units
      real(wp) :: force = 1.0_wp, velocity = 1.0_wp, time = 1.0_wp
   end type law_units

   !> Eq. 10 with a single-valued law and its states: (x, v_rel, y, w, ẑ)
   !> (the law, its states' count and scales: law_flow's).
   type, extends(law_flow) :: brake_law_flow
      type(brake_parameters) :: params
      type(law_units) :: units
      real(wp) :: stick_velocity = 1.0e-6_wp
   contains
      procedure :: dimension => flow_dimension
      procedure :: rhs => flow_rhs
      procedure :: jacobian => flow_jacobian
      procedure :: relative_component => flow_relative_component
      procedure :: event_count => flow_event_count
      procedure :: event_values => flow_event_values
      procedure :: friction => flow_friction
      procedure :: law_arguments => flow_law_arguments
      procedure :: first_step => flow_first_step
   end type brake_law_flow

   !> Eq. 10 in one slip of a set-valued law, s the sign of v_rel: (x, v, y, w).
   type, extends(event_system) :: brake_law_slip
      type(brake_parameters) :: params
      class(sliding_law), allocatable :: law
      type(law_units) :: units
      real(wp) :: direction = 1.0_wp
   contains
      procedure :: dimension => slip_dimension
      procedure :: rhs => slip_rhs
      procedure :: jacobian => slip_jacobian
      procedure :: event_count => slip_event_count
      procedure :: event_values => slip_event_values
   end type brake_law_slip

   type, extends(brake_integrator) :: law_integrator
      type(brake_parameters) :: p
      class(sliding_law), allocatable :: law
      type(law_units) :: units
      logical :: switching = .false.               !! a set-valued law: exact stick
      type(brake_law_flow), allocatable :: flow
      type(brake_law_slip), allocatable :: slip
      type(tangent_system), allocatable :: extended   !! the flow or the slip with its tangent (when tangent)
      type(stick_motion) :: stick
      logical :: sticking = .false.
      real(wp) :: z(max_law_states) = 0.0_wp       !! the law's states now, in its units
      real(wp) :: slope = 0.0_wp, level = 0.0_wp   !! the static limit slope N' + level
      real(wp) :: h_start = 1.0e-3_wp
   contains
      procedure :: start => law_start
      procedure :: advance_to => law_advance_to
      procedure :: is_sticking => law_sticking
      procedure :: state_count => law_state_count
      procedure :: get_states => law_get_states
      procedure :: set_states => law_set_states
      procedure :: limit
      procedure :: start_slipping => law_start_slipping
      procedure :: advance_to_slip_onset => law_advance_to_slip_onset
   end type law_integrator

contains

   ! ---- the single-valued law's flow ----

   pure function flow_dimension(self) result(n)
      class(brake_law_flow), intent(in) :: self
      integer :: n

      n = 4 + self%n_states
   end function flow_dimension

   !> The law's force in the brake's units at state y, with the springs' pull a.
   pure real(wp) function flow_friction(self, y, a) result(f)
      class(brake_law_flow), intent(in) :: self
      real(wp), intent(in) :: y(:), a
      real(wp) :: z(max_law_states), normal
      integer :: n

      n = self%n_states
      z(1:n) = y(5:4 + n) * self%scale(1:n)
      normal = (1.0_wp - self%params%kappa) * y(3) + self%params%g_prime
      f = self%law%force(y(2) * self%units%velocity, z(1:n), normal * self%units%force, &
         & a * self%units%force) / self%units%force
   end function flow_friction

   pure subroutine flow_rhs(self, t, y, dydt)
      class(brake_law_flow), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in), contiguous :: y(:)
      real(wp), intent(out), contiguous :: dydt(:)
      real(wp) :: a, z(max_law_states), rate(max_law_states), normal
      integer :: n

      n = self%n_states
      associate (p => self%params, u => self%units)
         a = -(2.0_wp * y(1) - y(3))
         dydt(1) = y(2) + p%v_dr
         dydt(2) = a - self%friction(y, a)
         dydt(3) = y(4)
         dydt(4) = (y(1) - p%kappa * y(3)) / p%xi
         if (n > 0) then
            z(1:n) = y(5:4 + n) * self%scale(1:n)
            normal = (1.0_wp - p%kappa) * y(3) + p%g_prime
            call self%law%state_rate(y(2) * u%velocity, z(1:n), normal * u%force, rate(1:n))
            ! ż per second to per unit τ, in units of the scale.
            dydt(5:4 + n) = rate(1:n) * u%time / self%scale(1:n)
         end if
      end associate
   end subroutine flow_rhs

   !> The exact Jacobian but ∂F/∂N', a central difference (the laws are
   !> linear in N or do not depend on it: exact to rounding); no law's state
   !> rate depends on N.  Autonomous: dfdt = 0.
   pure subroutine flow_jacobian(self, t, y, dfdy, dfdt)
      class(brake_law_flow), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: y(:)
      real(wp), intent(out) :: dfdy(:, :)
      real(wp), intent(out) :: dfdt(:)
      real(wp) :: a, z(max_law_states), dfdv, dfdz(max_law_states), dfda, dgdv(max_law_states), &
         & dgdz(max_law_states, max_law_states), normal, w, h, dfdn
      integer :: n, i, j

      n = self%n_states
      associate (p => self%params, u => self%units)
         a = -(2.0_wp * y(1) - y(3))
         z(1:n) = y(5:4 + n) * self%scale(1:n)
         normal = (1.0_wp - p%kappa) * y(3) + p%g_prime
         w = y(2) * u%velocity
         call self%law%partials(w, z(1:n), normal * u%force, a * u%force, dfdv, dfdz(1:n), dfda, dgdv(1:n), &
            & dgdz(1:n, 1:n))
         h = 1.0e-6_wp * max(abs(normal), 1.0e-6_wp)
         dfdn = (self%law%force(w, z(1:n), (normal + h) * u%force, a * u%force) &
            & - self%law%force(w, z(1:n), (normal - h) * u%force, a * u%force)) / (2.0_wp * h * u%force)
         dfdy = 0.0_wp
         dfdt = 0.0_wp
         dfdy(1, 2) = 1.0_wp
         ! v' = a - F(w, z, N', a) with ∂a/∂x = -2, ∂a/∂y = 1, ∂N'/∂y = 1 - κ.
         dfdy(2, 1) = -2.0_wp * (1.0_wp - dfda)
         dfdy(2, 2) = -dfdv * u%velocity / u%force
         dfdy(2, 3) = (1.0_wp - dfda) - dfdn * (1.0_wp - p%kappa)
         dfdy(3, 4) = 1.0_wp
         dfdy(4, 1) = 1.0_wp / p%xi
         dfdy(4, 3) = -p%kappa / p%xi
         do j = 1, n
            dfdy(2, 4 + j) = -dfdz(j) * self%scale(j) / u%force
            dfdy(4 + j, 2) = dgdv(j) * u%velocity * u%time / self%scale(j)
            do i = 1, n
               dfdy(4 + i, 4 + j) = dgdz(i, j) * self%scale(j) * u%time / self%scale(i)
            end do
         end do
      end associate
   end subroutine flow_jacobian

   !> The slip rate v_rel (component 2, measured from 0) when the law's force
   !> goes with its logarithm (rate and state), down to the law's floor in
   !> the brake's units.
   pure subroutine flow_relative_component(self, index, reference, floor)
      class(brake_law_flow), intent(in) :: self
      integer, intent(out) :: index
      real(wp), intent(out) :: reference, floor

      floor = self%law%log_slip_floor() / self%units%velocity
      index = merge(2, 0, floor > 0.0_wp)
      reference = 0.0_wp
   end subroutine flow_relative_component

   pure function flow_event_count(self) result(n)
      class(brake_law_flow), intent(in) :: self
      integer :: n

      n = 3
   end function flow_event_count

   !> 1: N' (falling through 0: the pad lifts off); 2, 3: v_rel ∓ stick_velocity.
   pure subroutine flow_event_values(self, t, y, g)
      class(brake_law_flow), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: y(:)
      real(wp), intent(out) :: g(:)

      associate (p => self%params)
         g(1) = (1.0_wp - p%kappa) * y(3) + p%g_prime
         g(2) = y(2) - self%stick_velocity
         g(3) = y(2) + self%stick_velocity
      end associate
   end subroutine flow_event_values

   !> The law's arguments at y in its units: the slip rate, the states, the normal load N'.
   pure subroutine flow_law_arguments(self, y, v, z, normal)
      class(brake_law_flow), intent(in) :: self
      real(wp), intent(in) :: y(:)
      real(wp), intent(out) :: v, z(:), normal

      v = y(2) * self%units%velocity
      z = y(5:4 + self%n_states) * self%scale(1:self%n_states)
      normal = ((1.0_wp - self%params%kappa) * y(3) + self%params%g_prime) * self%units%force
   end subroutine flow_law_arguments

   !> The first step from (t0, y) with the law's states z (in its units):
   !> h_start when set, else a tenth of the fastest time scale there (the
   !> velocity's under friction, the states' relaxation), at most 1e-3, and
   !> one that moves t (a creep's scale, at a restart late in a run, can lie
   !> below τ's spacing).  The run's start and the orbit's section map alike.
   pure real(wp) function flow_first_step(self, h_start, t0, y, z) result(h)
      class(brake_law_flow), intent(in) :: self
      real(wp), intent(in) :: h_start, t0, y(4), z(:)
      real(wp) :: normal, fastest, dfdv, dfdz(max_law_states), dfda, dgdv(max_law_states), &
         & dgdz(max_law_states, max_law_states)
      integer :: ns

      h = h_start
      if (h > 0.0_wp) return
      ns = self%n_states
      associate (p => self%params, u => self%units)
         normal = p%normal_force(y(3))
         call self%law%partials(y(2) * u%velocity, z(1:ns), normal * u%force, -p%elastic_force(y(1), y(3)) &
            & * u%force, dfdv, dfdz(1:ns), dfda, dgdv(1:ns), dgdz(1:ns, 1:ns))
         fastest = max(1.0_wp, abs(dfdv) * u%velocity / u%force)
         if (ns > 0) fastest = max(fastest, maxval(abs(dgdz(1:ns, 1:ns))) * u%time)
      end associate
      ! (A NaN partial makes the min NaN; the step then falls back to t's spacing and the run's own
      ! checks report the NaN, not the event locator.)
      h = min(1.0e-3_wp, 0.1_wp / fastest)
      if (.not. (h >= 0.0_wp)) h = 0.0_wp
      h = max(h, 2.0_wp * spacing(abs(t0)), tiny(1.0_wp))
   end function flow_first_step

   ! ---- a set-valued law in slip ----

   pure function slip_dimension(self) result(n)
      class(brake_law_slip), intent(in) :: self
      integer :: n

      n = 4
   end function slip_dimension

   pure subroutine slip_rhs(self, t, y, dydt)
      class(brake_law_slip), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in), contiguous :: y(:)
      real(wp), intent(out), contiguous :: dydt(:)
      real(wp) :: normal, none(0)

      associate (p => self%params, u => self%units)
         normal = (1.0_wp - p%kappa) * y(3) + p%g_prime
         dydt(1) = y(2)
         dydt(2) = -(2.0_wp * y(1) - y(3)) - self%law%slip_force((y(2) - p%v_dr) * u%velocity, none, &
            & normal * u%force, self%direction) / u%force
         dydt(3) = y(4)
         dydt(4) = (y(1) - p%kappa * y(3)) / p%xi
      end associate
   end subroutine slip_rhs

   !> ∂F/∂v and ∂F/∂N' of the slip force by central differences (it is
   !> smooth through v_rel = 0 and affine in N for these laws).
   pure subroutine slip_jacobian(self, t, y, dfdy, dfdt)
      class(brake_law_slip), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: y(:)
      real(wp), intent(out) :: dfdy(:, :)
      real(wp), intent(out) :: dfdt(:)
      real(wp) :: normal, w, h, k, dfdv, dfdn, none(0)

      associate (p => self%params, u => self%units)
         normal = (1.0_wp - p%kappa) * y(3) + p%g_prime
         w = (y(2) - p%v_dr) * u%velocity
         h = 1.0e-6_wp * max(abs(w), 1.0e-9_wp)
         dfdv = (self%law%slip_force(w + h, none, normal * u%force, self%direction) &
            & - self%law%slip_force(w - h, none, normal * u%force, self%direction)) / (2.0_wp * h)
         k = 1.0e-6_wp * max(abs(normal), 1.0e-6_wp)
         dfdn = (self%law%slip_force(w, none, (normal + k) * u%force, self%direction) &
            & - self%law%slip_force(w, none, (normal - k) * u%force, self%direction)) / (2.0_wp * k * u%force)
         dfdy = 0.0_wp
         dfdy(1, 2) = 1.0_wp
         dfdy(2, 1) = -2.0_wp
         dfdy(2, 2) = -dfdv * u%velocity / u%force
         dfdy(2, 3) = 1.0_wp - dfdn * (1.0_wp - p%kappa)
         dfdy(3, 4) = 1.0_wp
         dfdy(4, 1) = 1.0_wp / p%xi
         dfdy(4, 3) = -p%kappa / p%xi
         dfdt = 0.0_wp
      end associate
   end subroutine slip_jacobian

   pure function slip_event_count(self) result(n)
      class(brake_law_slip), intent(in) :: self
      integer :: n

      n = 2
   end function slip_event_count

   !> The slip's two events (slip_events).
   pure subroutine slip_event_values(self, t, y, g)
      class(brake_law_slip), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: y(:)
      real(wp), intent(out) :: g(:)

      call slip_events(self%params, self%direction, y, g)
   end subroutine slip_event_values

   ! ---- the integrator ----

   !> Start at (t0, y0) of the configuration the integrator was made for: the
   !> law made from &law at the first start (its table read once), its states
   !> in steady sliding at the initial v_rel; a set-valued law sticks when
   !> v_rel0 = 0 within the static limit, else slips.
   subroutine law_start(self, config, t0, y0, events, error)
      class(law_integrator), target, intent(inout) :: self
      type(brake_config), intent(in) :: config
      real(wp), intent(in) :: t0, y0(4)
      type(brake_event_table), intent(inout) :: events
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: normal, s(4 + max_law_states)
      integer :: ns

      ! An integrator runs one configuration (new_brake_integrator's) and Benettin restarts it every
      ! interval: the law, a table file read, is made at its first start only.
      if (.not. allocated(self%law)) then
         call make_law(law_with_files(config%law), self%law, error)
         if (allocated(error)) return
      end if
      self%p = config%params
      call config%law_units(self%units%force, self%units%velocity, self%units%time)
      self%switching = self%law%set_valued()
      self%t = t0
      self%y = y0
      ! A set-valued law keeps x' (its stick holds it at v_dr exactly; its slip is the switched model's).
      self%v_origin = 0.0_wp
      call events%clear()
      if (self%switching) then
         self%stick_time = 0.0_wp
         call law_static_line(self%law, self%units, self%slope, self%level)
         if (allocated(self%slip)) deallocate (self%slip)
         allocate (self%slip)
         self%slip%params = self%p
         allocate (self%slip%law, source=self%law)
         self%slip%units = self%units
         self%h_start = config%solver%h_start
         if (.not. (self%h_start > 0.0_wp)) self%h_start = 1.0e-3_wp
         if (self%tangent) then
            if (allocated(self%extended)) deallocate (self%extended)
            allocate (self%extended)
            allocate (self%extended%base, source=self%slip)
            call self%locator%init(self%extended, config%solver, [event_falling, event_falling], [.true., .true.], &
               & config%event_tolerance, self%h_start, error, time_name='τ', time_unit='')
            call self%start_tangent()
         else
            call self%locator%init(self%slip, config%solver, [event_falling, event_falling], [.true., .true.], &
               & config%event_tolerance, self%h_start, error, time_name='τ', time_unit='')
         end if
         if (allocated(error)) return
         if (y0(2) == self%p%v_dr .and. abs(self%p%elastic_force(y0(1), y0(3))) <= self%limit(y0(3))) then
            self%sticking = .true.
            call self%stick%start(self%p, t0, y0, self%slope, self%level)
         else if (y0(2) /= self%p%v_dr) then
            call slip_in(self, sign(1.0_wp, y0(2) - self%p%v_dr), self%h_start)
         else
            call slip_by_force(self, self%h_start)
         end if
         return
      end if
      self%stick_time = -1.0_wp
      ! The flow's coordinate is v_rel (module comment); the input's state is x'.
      self%v_origin = self%p%v_dr
      self%y(2) = y0(2) - self%p%v_dr
      if (allocated(self%flow)) deallocate (self%flow)
      allocate (self%flow)
      self%flow%params = self%p
      allocate (self%flow%law, source=self%law)
      self%flow%units = self%units
      self%flow%stick_velocity = config%stick_velocity
      ns = self%law%state_count()
      self%flow%n_states = ns
      if (ns > 0) call self%law%state_scale(self%flow%scale(1:ns))
      normal = self%p%normal_force(y0(3))
      self%z = 0.0_wp
      if (ns > 0) call self%law%steady_state(self%y(2) * self%units%velocity, normal * self%units%force, &
         & self%z(1:ns))
      self%h_start = self%flow%first_step(config%solver%h_start, t0, self%y, self%z(1:ns))
      if (self%tangent) then
         ! The tangent of (x, v_rel, y, w, ẑ): the law's states (in units of their scale) are in it.
         if (allocated(self%extended)) deallocate (self%extended)
         allocate (self%extended)
         allocate (self%extended%base, source=self%flow)
         call self%locator%init(self%extended, config%solver, [event_falling, event_either, event_either], &
            & [.true., .false., .false.], config%event_tolerance, self%h_start, error, time_name='τ', time_unit='')
         if (allocated(error)) return
         call self%start_tangent(ns)
         self%states = self%z(1:ns) / self%flow%scale(1:ns)
         call self%locator_restart(self%h_start)
         return
      end if
      call self%locator%init(self%flow, config%solver, [event_falling, event_either, event_either], &
         & [.true., .false., .false.], config%event_tolerance, self%h_start, error, time_name='τ', time_unit='')
      if (allocated(error)) return
      s(1:4) = self%y
      s(5:4 + ns) = self%z(1:ns) / self%flow%scale(1:ns)
      call self%locator%restart(t0, s(1:4 + ns), self%h_start)
   end subroutine law_start

   !> The static limit at N' = (1 - κ) y + g': slope N' + level.
   pure real(wp) function limit(self, y)
      class(law_integrator), intent(in) :: self
      real(wp), intent(in) :: y

      if (self%level == 0.0_wp) then
         limit = self%slope * self%p%normal_force(y)
      else
         limit = self%slope * self%p%normal_force(y) + self%level
      end if
   end function limit

   !> The single-valued law's states (a set-valued law has none here).
   pure integer function law_state_count(self)
      class(law_integrator), intent(in) :: self

      law_state_count = 0
      if (.not. self%switching .and. allocated(self%flow)) law_state_count = self%flow%n_states
   end function law_state_count

   !> The states as integrated: in units of their scale.
   subroutine law_get_states(self, states)
      class(law_integrator), intent(in) :: self
      real(wp), intent(out) :: states(:)
      integer :: ns

      ns = self%state_count()
      if (self%tangent) then
         states(1:ns) = self%states
      else
         states(1:ns) = self%z(1:ns) / self%flow%scale(1:ns)
      end if
   end subroutine law_get_states

   !> Start again from the states given (in units of their scale) at the
   !> current (t, y), with the first step of start.
   subroutine law_set_states(self, states)
      class(law_integrator), intent(inout) :: self
      real(wp), intent(in) :: states(:)
      real(wp) :: s(4 + max_law_states)
      integer :: ns

      ns = self%state_count()
      if (ns == 0) return
      self%z(1:ns) = states(1:ns) * self%flow%scale(1:ns)
      if (self%tangent) then
         self%states = states(1:ns)
         call self%locator_restart(self%h_start)
      else
         s(1:4) = self%y
         s(5:4 + ns) = states(1:ns)
         call self%locator%restart(self%t, s(1:4 + ns), self%h_start)
      end if
   end subroutine law_set_states

   logical function law_sticking(self)
      class(law_integrator), intent(in) :: self

      if (self%switching) then
         law_sticking = self%sticking
      else
         law_sticking = abs(self%y(2)) <= self%flow%stick_velocity
      end if
   end function law_sticking

   subroutine law_advance_to(self, t_target, events, error)
      class(law_integrator), intent(inout) :: self
      real(wp), intent(in) :: t_target
      type(brake_event_table), intent(inout) :: events
      type(error_type), allocatable, intent(out) :: error

      if (self%switching) then
         call advance_switching(self, t_target, events, error)
      else
         call advance_flow(self, t_target, events, error)
      end if
      if (allocated(error)) error%message = error%message//" (&brake model = 'law', &law model = '" &
         & //trim(self%law%p%model)//"')"
   end subroutine law_advance_to

   subroutine advance_flow(self, t_target, events, error)
      type(law_integrator), intent(inout) :: self
      real(wp), intent(in) :: t_target
      type(brake_event_table), intent(inout) :: events
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: s(4 + max_law_states)
      integer :: ns

      ns = self%flow%n_states
      if (self%tangent) then
         do while (self%t < t_target)
            call self%locator_advance(t_target, error)
            self%z(1:ns) = self%states * self%flow%scale(1:ns)
            if (allocated(error)) return
            call self%record_band_hits(events, '', error)
            if (allocated(error)) return
         end do
         return
      end if
      s(1:4) = self%y
      s(5:4 + ns) = self%z(1:ns) / self%flow%scale(1:ns)
      do while (self%t < t_target)
         call self%locator%advance(self%t, t_target, s(1:4 + ns), error)
         self%y = s(1:4)
         self%z(1:ns) = s(5:4 + ns) * self%flow%scale(1:ns)
         if (allocated(error)) return
         call self%record_band_hits(events, '', error)
         if (allocated(error)) return
      end do
   end subroutine advance_flow

   !> As the switched model: stick in closed form, slips located; with
   !> slip_onset present, up to the first stick-to-slip event (slip_onset =
   !> .true.) if it comes before t_target.
   subroutine advance_switching(self, t_target, events, error, slip_onset)
      type(law_integrator), intent(inout) :: self
      real(wp), intent(in) :: t_target
      type(brake_event_table), intent(inout) :: events
      type(error_type), allocatable, intent(out) :: error
      logical, intent(out), optional :: slip_onset
      logical :: found
      real(wp) :: t_end
      integer :: which

      if (present(slip_onset)) slip_onset = .false.
      do while (self%t < t_target)
         if (self%sticking) then
            call self%stick%find_end(self%t, t_target, found, t_end, which)
            if (.not. found) t_end = t_target
            self%stick_time = self%stick_time + (t_end - self%t)
            if (self%tangent) then
               self%phi = matmul(stick_tangent(self%p, t_end - self%t), self%phi)
               self%lost = 1
            end if
            self%y = self%stick%state_at(t_end)
            self%t = t_end
            if (.not. found) cycle
            if (which == stick_end_lift_off) then
               call fatal_error(error, "N' reached 0 at τ = "//rtoa(self%t) &
                  & //' in stick: the pad lifts off the belt, outside Eq. 10', error_numerical)
               return
            end if
            self%sticking = .false.
            if (self%tangent) call stick_exit_saltation(self, which)
            call slip_by_force(self, -1.0_wp)
            call events%add(self%t, event_stick_to_slip, self%y)
            if (present(slip_onset)) then
               slip_onset = .true.
               return
            end if
         else
            call self%locator_advance(t_target, error)
            if (allocated(error)) return
            if (self%locator%n_hits == 0) cycle
            select case (self%locator%hits(self%locator%n_hits)%which)
            case (1)
               if (abs(self%p%elastic_force(self%y(1), self%y(3))) <= self%limit(self%y(3))) then
                  self%sticking = .true.
                  if (self%tangent) then
                     call saltation(self%phi, slip_field(self, self%slip%direction), stick_field(self%p, self%y), &
                        & [0.0_wp, self%slip%direction, 0.0_wp, 0.0_wp])
                     self%lost = 1
                  end if
                  self%y(2) = self%p%v_dr   ! exact: the event left v_rel within the tolerance of 0
                  call self%stick%start(self%p, self%t, self%y, self%slope, self%level)
                  call events%add(self%t, event_slip_to_stick, self%y)
               else
                  if (self%tangent) call saltation(self%phi, slip_field(self, self%slip%direction), &
                     & slip_field(self, -self%slip%direction), [0.0_wp, self%slip%direction, 0.0_wp, 0.0_wp])
                  call slip_by_force(self, -1.0_wp)
                  call events%add(self%t, event_slip_reversal, self%y)
               end if
            case default
               call fatal_error(error, "N' reached 0 at τ = "//rtoa(self%t) &
                  & //' in slip: the pad lifts off the belt, outside Eq. 10', error_numerical)
               return
            end select
         end if
      end do
   end subroutine advance_switching

   !> Slip in the direction of the springs' pull -(2x - y) (its rate when
   !> the pull is exactly 0), as the switched model starts one; h_start <= 0
   !> keeps the step the stepper had reached.
   subroutine slip_by_force(self, h_start)
      type(law_integrator), intent(inout) :: self
      real(wp), intent(in) :: h_start
      real(wp) :: force

      force = self%p%elastic_force(self%y(1), self%y(3))
      if (force == 0.0_wp) force = 2.0_wp * self%y(2) - self%y(4)
      call slip_in(self, -sign(1.0_wp, force), h_start)
   end subroutine slip_by_force

   subroutine slip_in(self, s, h_start)
      type(law_integrator), intent(inout) :: self
      real(wp), intent(in) :: s, h_start

      self%sticking = .false.
      self%slip%direction = s
      if (self%tangent) then
         select type (b => self%extended%base)
         type is (brake_law_slip)
            b%direction = s
         end select
      end if
      call self%locator_restart(h_start)
   end subroutine slip_in

   !> The right-hand side of slip in direction s at the current state.
   function slip_field(self, s) result(f)
      type(law_integrator), intent(in) :: self
      real(wp), intent(in) :: s
      real(wp) :: f(4)
      type(brake_law_slip) :: slip

      slip%params = self%p
      allocate (slip%law, source=self%law)
      slip%units = self%units
      slip%direction = s
      call slip%rhs(self%t, self%y, f)
   end function slip_field

   !> Leaving stick where the limit `which` was reached: h = slope N' + level ∓ (2x - y)
   !> with normal ∇h, into slip in the direction the springs' pull drives (the
   !> switched model's, with the law's static limit).
   subroutine stick_exit_saltation(self, which)
      type(law_integrator), intent(inout) :: self
      integer, intent(in) :: which
      real(wp) :: sigma, normal(4)

      sigma = merge(1.0_wp, -1.0_wp, which == stick_end_force_positive)
      normal = [-2.0_wp * sigma, 0.0_wp, self%slope * (1.0_wp - self%p%kappa) + sigma, 0.0_wp]
      call saltation(self%phi, stick_field(self%p, self%y), slip_field(self, -sigma), normal)
   end subroutine stick_exit_saltation

   !> The static limit of a set-valued law in the brake's units, slope N' +
   !> level (affine in N': checked on input).
   pure subroutine law_static_line(law, units, slope, level)
      class(sliding_law), intent(in) :: law
      type(law_units), intent(in) :: units
      real(wp), intent(out) :: slope, level

      level = law%static_force(0.0_wp) / units%force
      slope = law%static_force(units%force) / units%force - level
   end subroutine law_static_line

   !> Start at (t0, y0) slipping in direction s = ±1 whatever the state: a
   !> point of the stick-to-slip section at the instant the slip begins (the
   !> periodic orbits of a set-valued law, brake/orbit.f90), as the switched
   !> model's start_slipping.
   subroutine law_start_slipping(self, config, t0, y0, s, events, error)
      class(law_integrator), target, intent(inout) :: self
      type(brake_config), intent(in) :: config
      real(wp), intent(in) :: t0, y0(4), s
      type(brake_event_table), intent(inout) :: events
      type(error_type), allocatable, intent(out) :: error

      call self%start(config, t0, y0, events, error)
      if (allocated(error)) return
      call slip_in(self, s, self%h_start)
   end subroutine law_start_slipping

   !> Advance to the next stick-to-slip event (found) and stop just after it
   !> (in slip, Φ through the saltation), or to t_limit (not found).  A
   !> set-valued law's run (started by start_slipping).
   subroutine law_advance_to_slip_onset(self, t_limit, events, found, error)
      class(law_integrator), intent(inout) :: self
      real(wp), intent(in) :: t_limit
      type(brake_event_table), intent(inout) :: events
      logical, intent(out) :: found
      type(error_type), allocatable, intent(out) :: error

      call advance_switching(self, t_limit, events, error, found)
      if (allocated(error)) error%message = error%message//" (&brake model = 'law', &law model = '" &
         & //trim(self%law%p%model)//"')"
   end subroutine law_advance_to_slip_onset

end module friction_brake_law_model
