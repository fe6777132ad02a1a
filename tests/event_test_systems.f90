!> A test system with events and an exact solution.
module event_test_systems
   use friction_kinds, only: wp
   use friction_ode_events, only: event_system
   implicit none
   private
   public :: ringing

   !> x'' = -ω² x as (x, v) from (1, 0): x = cos ωt, v = -ω sin ωt.
   !> Events: 1. x (zero at ωt = π/2 + kπ), 2. v (zero at ωt = kπ).
   type, extends(event_system) :: ringing
      real(wp) :: omega = 3.0_wp
      real(wp) :: offset = 0.0_wp   !! events at x, v = offset (2 never fires)
   contains
      procedure :: dimension
      procedure :: rhs
      procedure :: jacobian
      procedure :: event_count
      procedure :: event_values
   end type ringing

contains

   pure integer function dimension(self) result(n)
      class(ringing), intent(in) :: self
      n = 2
   end function dimension

   pure subroutine rhs(self, t, y, dydt)
      class(ringing), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in), contiguous :: y(:)
      real(wp), intent(out), contiguous :: dydt(:)
      dydt(1) = y(2)
      dydt(2) = -self%omega**2 * y(1)
   end subroutine rhs

   pure subroutine jacobian(self, t, y, dfdy, dfdt)
      class(ringing), intent(in) :: self
      real(wp), intent(in) :: t, y(:)
      real(wp), intent(out) :: dfdy(:, :), dfdt(:)
      dfdy = reshape([0.0_wp, -self%omega**2, 1.0_wp, 0.0_wp], [2, 2])
      dfdt = 0.0_wp
   end subroutine jacobian

   pure integer function event_count(self) result(n)
      class(ringing), intent(in) :: self
      n = 2
   end function event_count

   pure subroutine event_values(self, t, y, g)
      class(ringing), intent(in) :: self
      real(wp), intent(in) :: t, y(:)
      real(wp), intent(out) :: g(:)
      g = y(1:2) - self%offset
   end subroutine event_values

end module event_test_systems
