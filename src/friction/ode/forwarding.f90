!> A system that wraps another as its `base` and is that system with
!> something changed: events of its own (a section, a law's kinks), a
!> tangent or a sum carried beside it.  Every procedure of the ODE system is
!> the base's until an extension overrides it, so a wrapper states only
!> what it changes; its events are its own (deferred).
module friction_ode_forwarding
   use friction_kinds, only: wp
   use friction_ode_system, only: ode_system
   use friction_ode_events, only: event_system
   implicit none
   private

   public :: forwarding_system

   !> The base's dimension, step-size control, relative component,
   !> right-hand side and Jacobian; the events are the extension's.
   type, abstract, extends(event_system) :: forwarding_system
      class(ode_system), allocatable :: base
   contains
      procedure :: dimension => forwarded_dimension
      procedure :: controlled_dimension => forwarded_controlled_dimension
      procedure :: relative_component => forwarded_relative_component
      procedure :: rhs => forwarded_rhs
      procedure :: jacobian => forwarded_jacobian
   end type forwarding_system

contains

   pure integer function forwarded_dimension(self)
      class(forwarding_system), intent(in) :: self

      forwarded_dimension = self%base%dimension()
   end function forwarded_dimension

   pure integer function forwarded_controlled_dimension(self)
      class(forwarding_system), intent(in) :: self

      forwarded_controlled_dimension = self%base%controlled_dimension()
   end function forwarded_controlled_dimension

   pure subroutine forwarded_relative_component(self, index, reference, floor)
      class(forwarding_system), intent(in) :: self
      integer, intent(out) :: index
      real(wp), intent(out) :: reference, floor

      call self%base%relative_component(index, reference, floor)
   end subroutine forwarded_relative_component

   pure subroutine forwarded_rhs(self, t, y, dydt)
      class(forwarding_system), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in), contiguous :: y(:)
      real(wp), intent(out), contiguous :: dydt(:)

      call self%base%rhs(t, y, dydt)
   end subroutine forwarded_rhs

   pure subroutine forwarded_jacobian(self, t, y, dfdy, dfdt)
      class(forwarding_system), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: y(:)
      real(wp), intent(out) :: dfdy(:, :)
      real(wp), intent(out) :: dfdt(:)

      call self%base%jacobian(t, y, dfdy, dfdt)
   end subroutine forwarded_jacobian

end module friction_ode_forwarding
