!> ODE systems with known answers, shared by the test suites: an oscillator
!> (exact solution, zero exponent, an event function for sections), an
!> exponential decay that can turn NaN, and Lorenz (exponent 0.906); and the
!> step types the suites have a case for.
module test_systems
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
   use friction_kinds, only: wp
   use friction_ode_system, only: ode_system
   use friction_ode_events, only: event_system
   implicit none
   private
   public :: lorenz, oscillator, decay, hopf, logistic, step_types_with_cases

   !> The GSL step types that test_steppers.pf and test_events.pf have cases
   !> for, one each (and so one CTest test each).  Their guard cases require
   !> the library's step_type_names to be this list, so that a new step type
   !> cannot go untested.
   character(len=*), parameter :: step_types_with_cases(*) = [character(len=7) :: &
      & 'rk2', 'rk4', 'rkf45', 'rkck', 'rk8pd', 'rk1imp', 'rk2imp', 'rk4imp', 'bsimp', &
      & 'msadams', 'msbdf', 'rodas3', 'rodas4']

   !> Lorenz (σ, ρ, β) = (10, 28, 8/3): maximum exponent 0.906.
   type, extends(ode_system) :: lorenz
      real(wp) :: sigma = 10.0_wp, rho = 28.0_wp, beta = 8.0_wp / 3.0_wp
   contains
      procedure :: dimension => lorenz_dimension
      procedure :: rhs => lorenz_rhs
      procedure :: jacobian => lorenz_jacobian
   end type lorenz

   !> Hopf normal form x' = a x - ω y - x r², y' = ω x + a y - y r²: the
   !> limit cycle r = √a of period 2π/ω with exponents exactly 0 (along the
   !> orbit) and -2a (radial: r' = a r - r³ has slope a - 3a there).
   type, extends(ode_system) :: hopf
      real(wp) :: a = 1.0_wp, omega = 6.283185307179586_wp
   contains
      procedure :: dimension => hopf_dimension
      procedure :: rhs => hopf_rhs
      procedure :: jacobian => hopf_jacobian
   end type hopf

   !> x'' = -ω² x: every orbit periodic, exponent 0.  Event function: x'
   !> (upward zero at the minimum of x), for a located section.
   type, extends(event_system) :: oscillator
      real(wp) :: omega = 1.0_wp
   contains
      procedure :: dimension => oscillator_dimension
      procedure :: rhs => oscillator_rhs
      procedure :: jacobian => oscillator_jacobian
      procedure :: event_count => oscillator_event_count
      procedure :: event_values => oscillator_event_values
   end type oscillator

   !> y' = -λ y, and a right-hand side that turns NaN after t_bad.
   type, extends(ode_system) :: decay
      real(wp) :: rate = 1.0_wp
      real(wp) :: t_bad = huge(1.0_wp)
   contains
      procedure :: dimension => decay_dimension
      procedure :: rhs => decay_rhs
      procedure :: jacobian => decay_jacobian
   end type decay

   !> y' = y (1 - y): one variable whose Jacobian 1 - 2y depends on it.
   type, extends(ode_system) :: logistic
   contains
      procedure :: dimension => logistic_dimension
      procedure :: rhs => logistic_rhs
      procedure :: jacobian => logistic_jacobian
   end type logistic

contains

   pure integer function logistic_dimension(self) result(n)
      class(logistic), intent(in) :: self
      n = 1
   end function logistic_dimension

   pure subroutine logistic_rhs(self, t, y, dydt)
      class(logistic), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in), contiguous :: y(:)
      real(wp), intent(out), contiguous :: dydt(:)
      dydt(1) = y(1) * (1.0_wp - y(1))
   end subroutine logistic_rhs

   pure subroutine logistic_jacobian(self, t, y, dfdy, dfdt)
      class(logistic), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: y(:)
      real(wp), intent(out) :: dfdy(:, :)
      real(wp), intent(out) :: dfdt(:)
      dfdy(1, 1) = 1.0_wp - 2.0_wp * y(1)
      dfdt(1) = 0.0_wp
   end subroutine logistic_jacobian

   pure integer function lorenz_dimension(self) result(n)
      class(lorenz), intent(in) :: self
      n = 3
   end function lorenz_dimension

   pure subroutine lorenz_rhs(self, t, y, dydt)
      class(lorenz), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in), contiguous :: y(:)
      real(wp), intent(out), contiguous :: dydt(:)
      dydt(1) = self%sigma * (y(2) - y(1))
      dydt(2) = y(1) * (self%rho - y(3)) - y(2)
      dydt(3) = y(1) * y(2) - self%beta * y(3)
   end subroutine lorenz_rhs

   pure subroutine lorenz_jacobian(self, t, y, dfdy, dfdt)
      class(lorenz), intent(in) :: self
      real(wp), intent(in) :: t, y(:)
      real(wp), intent(out) :: dfdy(:, :), dfdt(:)
      dfdy(1, :) = [-self%sigma, self%sigma, 0.0_wp]
      dfdy(2, :) = [self%rho - y(3), -1.0_wp, -y(1)]
      dfdy(3, :) = [y(2), y(1), -self%beta]
      dfdt = 0.0_wp
   end subroutine lorenz_jacobian

   pure integer function oscillator_dimension(self) result(n)
      class(oscillator), intent(in) :: self
      n = 2
   end function oscillator_dimension

   pure subroutine oscillator_rhs(self, t, y, dydt)
      class(oscillator), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in), contiguous :: y(:)
      real(wp), intent(out), contiguous :: dydt(:)
      dydt(1) = y(2)
      dydt(2) = -self%omega**2 * y(1)
   end subroutine oscillator_rhs

   pure subroutine oscillator_jacobian(self, t, y, dfdy, dfdt)
      class(oscillator), intent(in) :: self
      real(wp), intent(in) :: t, y(:)
      real(wp), intent(out) :: dfdy(:, :), dfdt(:)
      dfdy = reshape([0.0_wp, -self%omega**2, 1.0_wp, 0.0_wp], [2, 2])
      dfdt = 0.0_wp
   end subroutine oscillator_jacobian

   pure integer function oscillator_event_count(self) result(n)
      class(oscillator), intent(in) :: self
      n = 1
   end function oscillator_event_count

   pure subroutine oscillator_event_values(self, t, y, g)
      class(oscillator), intent(in) :: self
      real(wp), intent(in) :: t, y(:)
      real(wp), intent(out) :: g(:)
      g(1) = y(2)
   end subroutine oscillator_event_values

   pure integer function decay_dimension(self) result(n)
      class(decay), intent(in) :: self
      n = 1
   end function decay_dimension

   pure subroutine decay_rhs(self, t, y, dydt)
      class(decay), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in), contiguous :: y(:)
      real(wp), intent(out), contiguous :: dydt(:)
      dydt(1) = -self%rate * y(1)
      if (t > self%t_bad) dydt(1) = ieee_value(1.0_wp, ieee_quiet_nan)
   end subroutine decay_rhs

   pure subroutine decay_jacobian(self, t, y, dfdy, dfdt)
      class(decay), intent(in) :: self
      real(wp), intent(in) :: t, y(:)
      real(wp), intent(out) :: dfdy(:, :), dfdt(:)
      dfdy(1, 1) = -self%rate
      dfdt = 0.0_wp
   end subroutine decay_jacobian

   pure function hopf_dimension(self) result(n)
      class(hopf), intent(in) :: self
      integer :: n
      n = 2
   end function hopf_dimension

   pure subroutine hopf_rhs(self, t, y, dydt)
      class(hopf), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in), contiguous :: y(:)
      real(wp), intent(out), contiguous :: dydt(:)
      real(wp) :: r2
      r2 = y(1)**2 + y(2)**2
      dydt(1) = self%a * y(1) - self%omega * y(2) - y(1) * r2
      dydt(2) = self%omega * y(1) + self%a * y(2) - y(2) * r2
   end subroutine hopf_rhs

   pure subroutine hopf_jacobian(self, t, y, dfdy, dfdt)
      class(hopf), intent(in) :: self
      real(wp), intent(in) :: t, y(:)
      real(wp), intent(out) :: dfdy(:, :), dfdt(:)
      real(wp) :: r2
      r2 = y(1)**2 + y(2)**2
      dfdy(1, :) = [self%a - r2 - 2.0_wp * y(1)**2, -self%omega - 2.0_wp * y(1) * y(2)]
      dfdy(2, :) = [self%omega - 2.0_wp * y(1) * y(2), self%a - r2 - 2.0_wp * y(2)**2]
      dfdt = 0.0_wp
   end subroutine hopf_jacobian

end module test_systems
