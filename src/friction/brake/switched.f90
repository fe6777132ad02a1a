!> The switched friction model: the paper's decision algorithm (Fig. 10,
!> Eq. 5-7) with exact stick and located events.
!>
!> - Stick (v_rel = 0): x' = v'_dr exactly and the crank moves in closed form
!>   (friction_brake_stick); stick lasts while |2x - y| <= μs N'.  Its end
!>   is found to rounding.
!> - Slip: Eq. 10 with the sign of v_rel fixed for the whole slip, s, and
!>   the kinetic law F = -μ N' s / (1 + δ' s v_rel): the limit of the
!>   arctan law for ε' → ∞.  Writing s v_rel for |v_rel| keeps F smooth
!>   through v_rel = 0, so the integrator and the event locator can step a
!>   little beyond the event without a kink.
!> - Slip ends when v_rel reaches 0 (event 1, located to the event
!>   tolerance): stick if |2x - y| <= μs N' there (v set to v'_dr exactly),
!>   else slip the other way (slip reversal).  N' reaching 0 (event 2, or
!>   limit 3 in stick) is an error: the pad lifts off, Eq. 10 no longer holds.
!> - A slip starts with s = -sign(2x - y): the unbalanced spring force
!>   drives the block away from the belt.  Then s x'' = |2x - y| - μ N' >= 0
!>   because μ <= μs (checked on input: μ > μs would make the model chatter).
module friction_brake_switched
   use friction_kinds, only: wp
   use friction_error, only: error_type, fatal_error, error_numerical
   use friction_strings, only: rtoa
   use friction_ode_solver, only: solver_settings
   use friction_ode_events, only: event_system, event_falling
   use friction_brake_params, only: brake_parameters
   use friction_brake_config, only: brake_config
   use friction_brake_integrator, only: brake_integrator
   use friction_brake_stick, only: stick_motion, stick_end_lift_off, stick_end_force_positive, stick_tangent
   use friction_analysis_lyapunov_spectrum, only: tangent_system
   use friction_brake_record, only: brake_event_table, event_stick_to_slip, event_slip_to_stick, &
      & event_slip_reversal
   implicit none
   private

   public :: brake_slip, switched_integrator, kinetic_friction, saltation, stick_field, slip_events

   !> Eq. 10 during one slip, with s the sign of v_rel.
   type, extends(event_system) :: brake_slip
      type(brake_parameters) :: params
      real(wp) :: direction = 1.0_wp   !! s = ±1
   contains
      procedure :: dimension
      procedure :: rhs
      procedure :: jacobian
      procedure :: event_count
      procedure :: event_values
   end type brake_slip

   !> Integrates the switched model forward from an initial state.
   type, extends(brake_integrator) :: switched_integrator
      type(brake_parameters) :: p
      type(brake_slip), allocatable :: slip
      type(tangent_system), allocatable :: slip_tangent   !! slip with its tangent (when tangent)
      type(stick_motion) :: stick
      logical :: sticking = .true.
      real(wp) :: h_start = 0.0_wp
   contains
      procedure :: init
      procedure :: start => switched_start
      procedure :: advance_to
      procedure :: is_sticking => switched_sticking
      procedure :: start_slipping
      procedure :: advance_to_slip_onset
   end type switched_integrator

contains

   !> F/k1 in slip (m): the kinetic law with the direction s fixed.
   pure real(wp) function kinetic_friction(p, normal, v_rel, s)
      type(brake_parameters), intent(in) :: p
      real(wp), intent(in) :: normal, v_rel, s

      kinetic_friction = -p%mu * normal * s / (1.0_wp + p%delta_prime * s * v_rel)
   end function kinetic_friction

   pure function dimension(self) result(n)
      class(brake_slip), intent(in) :: self
      integer :: n

      n = 4
   end function dimension

   pure subroutine rhs(self, t, y, dydt)
      class(brake_slip), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in), contiguous :: y(:)
      real(wp), intent(out), contiguous :: dydt(:)
      real(wp) :: normal

      associate (p => self%params)
         normal = (1.0_wp - p%kappa) * y(3) + p%g_prime
         dydt(1) = y(2)
         dydt(2) = -(2.0_wp * y(1) - y(3)) + kinetic_friction(p, normal, y(2) - p%v_dr, self%direction)
         dydt(3) = y(4)
         dydt(4) = (y(1) - p%kappa * y(3)) / p%xi
      end associate
   end subroutine rhs

   pure subroutine jacobian(self, t, y, dfdy, dfdt)
      class(brake_slip), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: y(:)
      real(wp), intent(out) :: dfdy(:, :)
      real(wp), intent(out) :: dfdt(:)
      real(wp) :: normal, q, s

      associate (p => self%params)
         s = self%direction
         normal = (1.0_wp - p%kappa) * y(3) + p%g_prime
         q = 1.0_wp / (1.0_wp + p%delta_prime * s * (y(2) - p%v_dr))
         dfdy = 0.0_wp
         dfdy(1, 2) = 1.0_wp
         dfdy(2, 1) = -2.0_wp
         ! d/dv of -μ N' s q = μ N' s² δ' q² = μ N' δ' q²
         dfdy(2, 2) = p%mu * normal * p%delta_prime * q * q
         dfdy(2, 3) = 1.0_wp - p%mu * (1.0_wp - p%kappa) * s * q
         dfdy(3, 4) = 1.0_wp
         dfdy(4, 1) = 1.0_wp / p%xi
         dfdy(4, 3) = -p%kappa / p%xi
         dfdt = 0.0_wp
      end associate
   end subroutine jacobian

   pure function event_count(self) result(n)
      class(brake_slip), intent(in) :: self
      integer :: n

      n = 2
   end function event_count

   !> The slip's two events (slip_events).
   pure subroutine event_values(self, t, y, g)
      class(brake_slip), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: y(:)
      real(wp), intent(out) :: g(:)

      call slip_events(self%params, self%direction, y, g)
   end subroutine event_values

   !> A slip's two events, whatever its law: 1: s v_rel, falling through 0
   !> when the block catches up with the belt; 2: N', falling through 0 when
   !> the pad lifts off.
   pure subroutine slip_events(p, direction, y, g)
      type(brake_parameters), intent(in) :: p
      real(wp), intent(in) :: direction
      real(wp), intent(in) :: y(:)
      real(wp), intent(out) :: g(:)

      g(1) = direction * (y(2) - p%v_dr)
      g(2) = (1.0_wp - p%kappa) * y(3) + p%g_prime
   end subroutine slip_events

   subroutine switched_start(self, config, t0, y0, events, error)
      class(switched_integrator), target, intent(inout) :: self
      type(brake_config), intent(in) :: config
      real(wp), intent(in) :: t0, y0(4)
      type(brake_event_table), intent(inout) :: events
      type(error_type), allocatable, intent(out) :: error

      call self%init(config%params, config%solver, config%event_tolerance, t0, y0, events, error)
   end subroutine switched_start

   logical function switched_sticking(self)
      class(switched_integrator), intent(in) :: self

      switched_sticking = self%sticking
   end function switched_sticking

   !> Start at (t0, y0).  v_rel0 = 0 within the static limit sticks, else the
   !> block slips (in the direction of v_rel, or of the unbalanced force).
   subroutine init(self, p, settings, event_tolerance, t0, y0, events, error)
      class(switched_integrator), target, intent(inout) :: self
      type(brake_parameters), intent(in) :: p
      type(solver_settings), intent(in) :: settings
      real(wp), intent(in) :: event_tolerance, t0, y0(4)
      type(brake_event_table), intent(inout) :: events
      type(error_type), allocatable, intent(out) :: error

      self%p = p
      if (allocated(self%slip)) deallocate (self%slip)
      allocate (self%slip)
      self%slip%params = p
      self%h_start = settings%h_start
      if (.not. (self%h_start > 0.0_wp)) self%h_start = 1.0e-3_wp
      if (self%tangent) then
         if (allocated(self%slip_tangent)) deallocate (self%slip_tangent)
         allocate (self%slip_tangent)
         allocate (self%slip_tangent%base, source=self%slip)
         call self%locator%init(self%slip_tangent, settings, [event_falling, event_falling], [.true., .true.], &
            & event_tolerance, self%h_start, error, time_name='τ', time_unit='')
         call self%start_tangent()
      else
         call self%locator%init(self%slip, settings, [event_falling, event_falling], [.true., .true.], &
            & event_tolerance, self%h_start, error, time_name='τ', time_unit='')
      end if
      if (allocated(error)) return
      self%t = t0
      self%y = y0
      self%stick_time = 0.0_wp
      if (y0(2) == p%v_dr .and. abs(p%elastic_force(y0(1), y0(3))) <= p%mu_s * p%normal_force(y0(3))) then
         self%sticking = .true.
         call self%stick%start(p, t0, y0)
      else
         self%sticking = .false.
         if (y0(2) /= p%v_dr) then
            call start_slip_in(self, sign(1.0_wp, y0(2) - p%v_dr), self%h_start)
         else
            call start_slip(self, self%h_start)
         end if
      end if
      call events%clear()
   end subroutine init

   !> Start at (t0, y0) slipping in direction s = ±1 whatever the state:
   !> a point of the stick-to-slip section (v_rel = 0 on the static limit)
   !> at the instant the slip begins (the periodic orbits, brake/orbit.f90).
   subroutine start_slipping(self, config, t0, y0, s, events, error)
      class(switched_integrator), target, intent(inout) :: self
      type(brake_config), intent(in) :: config
      real(wp), intent(in) :: t0, y0(4), s
      type(brake_event_table), intent(inout) :: events
      type(error_type), allocatable, intent(out) :: error

      call self%init(config%params, config%solver, config%event_tolerance, t0, y0, events, error)
      if (allocated(error)) return
      self%sticking = .false.
      call start_slip_in(self, s, self%h_start)
   end subroutine start_slipping

   !> Advance to the next stick-to-slip event (found) and stop there, just
   !> after it (in slip, Φ through the saltation), or to t_limit (not found).
   subroutine advance_to_slip_onset(self, t_limit, events, found, error)
      class(switched_integrator), intent(inout) :: self
      real(wp), intent(in) :: t_limit
      type(brake_event_table), intent(inout) :: events
      logical, intent(out) :: found
      type(error_type), allocatable, intent(out) :: error

      call advance_switched(self, t_limit, events, error, found)
   end subroutine advance_to_slip_onset

   !> Advance to t_target, through any number of stick and slip phases;
   !> events go into the table.  On error, t is the time reached.
   subroutine advance_to(self, t_target, events, error)
      class(switched_integrator), intent(inout) :: self
      real(wp), intent(in) :: t_target
      type(brake_event_table), intent(inout) :: events
      type(error_type), allocatable, intent(out) :: error

      call advance_switched(self, t_target, events, error)
   end subroutine advance_to

   !> advance_to, or with slip_onset present, up to the first stick-to-slip
   !> event (slip_onset = .true.) if it comes before t_target.
   subroutine advance_switched(self, t_target, events, error, slip_onset)
      class(switched_integrator), intent(inout) :: self
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
               call fatal_error(error, "switched model: N' reached 0 at τ = "//rtoa(self%t) &
                  & //' in stick: the pad lifts off the belt, outside Eq. 10', error_numerical)
               return
            end if
            self%sticking = .false.
            if (self%tangent) call stick_exit_saltation(self, which)
            call start_slip(self, -1.0_wp)
            call events%add(self%t, event_stick_to_slip, self%y)
            if (present(slip_onset)) then
               slip_onset = .true.
               return
            end if
         else
            call self%locator_advance(t_target, error)
            if (allocated(error)) then
               error%message = error%message//' (switched model, in slip)'
               return
            end if
            if (self%locator%n_hits == 0) cycle
            select case (self%locator%hits(self%locator%n_hits)%which)
            case (1)
               if (abs(self%p%elastic_force(self%y(1), self%y(3))) <= &
                  & self%p%mu_s * self%p%normal_force(self%y(3))) then
                  self%sticking = .true.
                  if (self%tangent) then
                     call saltation(self%phi, slip_field(self, self%slip%direction), stick_field(self%p, self%y), &
                        & [0.0_wp, self%slip%direction, 0.0_wp, 0.0_wp])
                     self%lost = 1
                  end if
                  self%y(2) = self%p%v_dr   ! exact: the event left v_rel within the tolerance of 0
                  call self%stick%start(self%p, self%t, self%y)
                  call events%add(self%t, event_slip_to_stick, self%y)
               else
                  if (self%tangent) call saltation(self%phi, slip_field(self, self%slip%direction), &
                     & slip_field(self, -self%slip%direction), [0.0_wp, self%slip%direction, 0.0_wp, 0.0_wp])
                  call start_slip(self, -1.0_wp)
                  call events%add(self%t, event_slip_reversal, self%y)
               end if
            case default
               call fatal_error(error, "switched model: N' reached 0 at τ = "//rtoa(self%t) &
                  & //' in slip: the pad lifts off the belt, outside Eq. 10', error_numerical)
               return
            end select
         end if
      end do
   end subroutine advance_switched

   !> Slip from the current state in the direction of the unbalanced force
   !> -(2x - y) (its rate when the force is exactly 0).
   subroutine start_slip(self, h_start)
      class(switched_integrator), intent(inout) :: self
      real(wp), intent(in) :: h_start
      real(wp) :: force

      force = self%p%elastic_force(self%y(1), self%y(3))
      if (force == 0.0_wp) force = 2.0_wp * self%y(2) - self%y(4)
      call start_slip_in(self, -sign(1.0_wp, force), h_start)
   end subroutine start_slip

   subroutine start_slip_in(self, s, h_start)
      class(switched_integrator), intent(inout) :: self
      real(wp), intent(in) :: s, h_start

      self%slip%direction = s
      if (self%tangent) then
         select type (b => self%slip_tangent%base)
         type is (brake_slip)
            b%direction = s
         end select
      end if
      call self%locator_restart(h_start)
   end subroutine start_slip_in

   !> The right-hand side of slip in direction s at the current state.
   function slip_field(self, s) result(f)
      class(switched_integrator), intent(in) :: self
      real(wp), intent(in) :: s
      real(wp) :: f(4)
      type(brake_slip) :: slip

      slip%params = self%p
      slip%direction = s
      call slip%rhs(self%t, self%y, f)
   end function slip_field

   !> The right-hand side of stick at the state y (the block's velocity
   !> pinned to the belt), whatever the friction model.
   pure function stick_field(p, y) result(f)
      type(brake_parameters), intent(in) :: p
      real(wp), intent(in) :: y(4)
      real(wp) :: f(4)

      f = [p%v_dr, 0.0_wp, y(4), (y(1) - p%kappa * y(3)) / p%xi]
   end function stick_field

   !> Tangent vectors across a switching surface h = 0 with normal n = ∇h,
   !> crossed from the field f⁻ into f⁺ (docs/physics.md, the saltation
   !> matrix): Φ ← (I + (f⁺ - f⁻) nᵀ / (nᵀ f⁻)) Φ.  A grazing crossing
   !> (nᵀ f⁻ = 0, measure zero) leaves Φ as it is.
   pure subroutine saltation(phi, f_minus, f_plus, normal)
      real(wp), intent(inout) :: phi(4, 4)
      real(wp), intent(in) :: f_minus(4), f_plus(4), normal(4)
      real(wp) :: rate, row(4)
      integer :: i

      rate = dot_product(normal, f_minus)
      if (rate == 0.0_wp) return
      row = matmul(normal, phi) / rate
      do i = 1, 4
         phi(i, :) = phi(i, :) + (f_plus(i) - f_minus(i)) * row
      end do
   end subroutine saltation

   !> Leaving stick where the limit `which` was reached: h = μs N' ∓ (2x - y)
   !> with normal ∇h, into slip in the direction the unbalanced force drives.
   subroutine stick_exit_saltation(self, which)
      class(switched_integrator), intent(inout) :: self
      integer, intent(in) :: which
      real(wp) :: sigma, normal(4), s

      ! h = μs N' - σ (2x - y): σ = +1 at the positive limit, -1 at the negative.
      sigma = merge(1.0_wp, -1.0_wp, which == stick_end_force_positive)
      normal = [-2.0_wp * sigma, 0.0_wp, self%p%mu_s * (1.0_wp - self%p%kappa) + sigma, 0.0_wp]
      s = -sigma
      call saltation(self%phi, stick_field(self%p, self%y), slip_field(self, s), normal)
   end subroutine stick_exit_saltation

end module friction_brake_switched
