!> The regularized friction law: Eq. 10 as one smooth ODE, with the arctan
!> standing in for the sign of v_rel.  State y = (x, x', y, y') as
!> (x, v, y, w); time τ.
!>
!>   x' = v,  v' = -(2x - y) + F(N', v_rel),  y' = w,  w' = (x - κ y)/ξ
!>   F = -μ N' (2/π) arctan(ε' v_rel) / (1 + δ' |v_rel|)
!>
!> With ε' = 3.5e7 the system is very stiff near v_rel = 0: ∂v'/∂v is about
!> -(2/π) μ N' ε' ≈ -2.3e5 there, against natural frequencies of order 1.
!> The analytic Jacobian serves the implicit steppers.
!>
!> Event functions (for the event locator): 1. N' (falling to 0 is an
!> error: the block lifts off); 2., 3. v_rel ∓ stick_velocity, the edges of
!> the creep band the output counts as stick.
module friction_brake_regularized
   use friction_kinds, only: wp
   use friction_error, only: error_type
   use friction_ode_solver, only: solver_settings, is_implicit_step_type
   use friction_ode_events, only: event_system, event_falling, event_either
   use friction_law_arctan, only: arctan_force, arctan_slope
   use friction_brake_params, only: brake_parameters
   use friction_brake_config, only: brake_config
   use friction_brake_integrator, only: brake_integrator
   use friction_brake_record, only: brake_event_table
   use friction_analysis_lyapunov_spectrum, only: tangent_system
   implicit none
   private

   public :: brake_regularized, regularized_friction, regularized_friction_slope
   public :: regularized_integrator

   type, extends(event_system) :: brake_regularized
      type(brake_parameters) :: params
      real(wp) :: stick_velocity = 1.0e-6_wp   !! half-width of the creep band
   contains
      procedure :: dimension
      procedure :: rhs
      procedure :: jacobian
      procedure :: event_count
      procedure :: event_values
   end type brake_regularized

   !> Integrates the regularized model forward from an initial state; records
   !> when |v_rel| enters and leaves the creep band as events.
   type, extends(brake_integrator) :: regularized_integrator
      type(brake_regularized), allocatable :: system
      type(tangent_system), allocatable :: extended   !! with its tangent (when tangent)
      character(len=16) :: method = ''
   contains
      procedure :: init => integrator_init
      procedure :: start => regularized_start
      procedure :: advance_to => integrator_advance_to
      procedure :: is_sticking => regularized_sticking
   end type regularized_integrator

contains

   !> F/k1 of Eq. 10 (m): the friction force on the block, regularized (the
   !> law's one formula, friction_law_arctan, in the units of Eq. 10).
   pure real(wp) function regularized_friction(p, normal, v_rel)
      type(brake_parameters), intent(in) :: p
      real(wp), intent(in) :: normal, v_rel

      regularized_friction = -arctan_force(p%mu, normal, p%epsilon_prime, p%delta_prime, v_rel)
   end function regularized_friction

   !> ∂F/∂v_rel at fixed N'.
   pure real(wp) function regularized_friction_slope(p, normal, v_rel)
      type(brake_parameters), intent(in) :: p
      real(wp), intent(in) :: normal, v_rel

      regularized_friction_slope = -arctan_slope(p%mu, normal, p%epsilon_prime, p%delta_prime, v_rel)
   end function regularized_friction_slope

   pure function dimension(self) result(n)
      class(brake_regularized), intent(in) :: self
      integer :: n

      n = 4
   end function dimension

   !> Eq. 10.
   pure subroutine rhs(self, t, y, dydt)
      class(brake_regularized), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in), contiguous :: y(:)
      real(wp), intent(out), contiguous :: dydt(:)
      real(wp) :: normal

      associate (p => self%params)
         normal = (1.0_wp - p%kappa) * y(3) + p%g_prime
         dydt(1) = y(2)
         dydt(2) = -(2.0_wp * y(1) - y(3)) + regularized_friction(p, normal, y(2) - p%v_dr)
         dydt(3) = y(4)
         dydt(4) = (y(1) - p%kappa * y(3)) / p%xi
      end associate
   end subroutine rhs

   !> Analytic Jacobian; autonomous, so dfdt = 0.
   pure subroutine jacobian(self, t, y, dfdy, dfdt)
      class(brake_regularized), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: y(:)
      real(wp), intent(out) :: dfdy(:, :)
      real(wp), intent(out) :: dfdt(:)
      real(wp) :: normal, v_rel

      associate (p => self%params)
         normal = (1.0_wp - p%kappa) * y(3) + p%g_prime
         v_rel = y(2) - p%v_dr
         dfdy = 0.0_wp
         dfdy(1, 2) = 1.0_wp
         dfdy(2, 1) = -2.0_wp
         dfdy(2, 2) = regularized_friction_slope(p, normal, v_rel)
         ! F is linear in N', and ∂N'/∂y = 1 - κ.
         dfdy(2, 3) = 1.0_wp + (1.0_wp - p%kappa) * regularized_friction(p, 1.0_wp, v_rel)
         dfdy(3, 4) = 1.0_wp
         dfdy(4, 1) = 1.0_wp / p%xi
         dfdy(4, 3) = -p%kappa / p%xi
         dfdt = 0.0_wp
      end associate
   end subroutine jacobian

   pure function event_count(self) result(n)
      class(brake_regularized), intent(in) :: self
      integer :: n

      n = 3
   end function event_count

   pure subroutine event_values(self, t, y, g)
      class(brake_regularized), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: y(:)
      real(wp), intent(out) :: g(:)

      associate (p => self%params)
         g(1) = (1.0_wp - p%kappa) * y(3) + p%g_prime
         g(2) = y(2) - p%v_dr - self%stick_velocity
         g(3) = y(2) - p%v_dr + self%stick_velocity
      end associate
   end subroutine event_values

   subroutine regularized_start(self, config, t0, y0, events, error)
      class(regularized_integrator), target, intent(inout) :: self
      type(brake_config), intent(in) :: config
      real(wp), intent(in) :: t0, y0(4)
      type(brake_event_table), intent(inout) :: events
      type(error_type), allocatable, intent(out) :: error

      call self%init(config%params, config%stick_velocity, config%solver, config%event_tolerance, t0, y0, &
         & events, error)
   end subroutine regularized_start

   !> Within the creep band |v_rel| <= stick_velocity counts as stick.
   logical function regularized_sticking(self)
      class(regularized_integrator), intent(in) :: self

      regularized_sticking = abs(self%y(2) - self%system%params%v_dr) <= self%system%stick_velocity
   end function regularized_sticking

   subroutine integrator_init(self, p, stick_velocity, settings, event_tolerance, t0, y0, events, error)
      class(regularized_integrator), target, intent(inout) :: self
      type(brake_parameters), intent(in) :: p
      real(wp), intent(in) :: stick_velocity, event_tolerance, t0, y0(4)
      type(solver_settings), intent(in) :: settings
      type(brake_event_table), intent(inout) :: events
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: h_start

      if (allocated(self%system)) deallocate (self%system)
      allocate (self%system)
      self%system%params = p
      self%system%stick_velocity = stick_velocity
      self%method = settings%method
      ! The fastest time scale near v_rel = 0 is 1/|∂v'/∂v| ~ 1/((2/π) μ N' ε').
      h_start = settings%h_start
      if (.not. (h_start > 0.0_wp)) h_start = min(1.0e-3_wp, &
         & 0.1_wp / max(1.0_wp, abs(regularized_friction_slope(p, p%normal_force(y0(3)), 0.0_wp))))
      if (self%tangent) then
         if (allocated(self%extended)) deallocate (self%extended)
         allocate (self%extended)
         allocate (self%extended%base, source=self%system)
         call self%locator%init(self%extended, settings, [event_falling, event_either, event_either], &
            & [.true., .false., .false.], event_tolerance, h_start, error, time_name='τ', time_unit='')
      else
         call self%locator%init(self%system, settings, [event_falling, event_either, event_either], &
            & [.true., .false., .false.], event_tolerance, h_start, error, time_name='τ', time_unit='')
      end if
      if (allocated(error)) return
      self%t = t0
      self%y = y0
      if (self%tangent) call self%start_tangent()
      call self%locator_restart(h_start)
      call events%clear()
   end subroutine integrator_init

   !> Advance to t_target; creep-band crossings go into the table.
   subroutine integrator_advance_to(self, t_target, events, error)
      class(regularized_integrator), intent(inout) :: self
      real(wp), intent(in) :: t_target
      type(brake_event_table), intent(inout) :: events
      type(error_type), allocatable, intent(out) :: error

      do while (self%t < t_target)
         call self%locator_advance(t_target, error)
         if (allocated(error)) then
            error%message = error%message//' (regularized model'
            if (.not. is_implicit_step_type(self%method)) error%message = error%message &
               & //'; with a large epsilon_prime the law is stiff near v_rel = 0: try an implicit' &
               & //' stepper (rodas4, rodas3, rk4imp; bsimp and msbdf are wrong here at most tolerances)' &
               & //' or the switched model'
            error%message = error%message//')'
            return
         end if
         call self%record_band_hits(events, 'regularized model: ', error)
         if (allocated(error)) return
      end do
   end subroutine integrator_advance_to

end module friction_brake_regularized
