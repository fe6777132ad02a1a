!> An ordinary differential equation system dy/dt = f(t, y) as an abstract
!> type: the right-hand side and its analytic Jacobian (for the implicit
!> steppers).  Model parameters live in the extending type, never in module
!> variables, so two systems can be integrated at once.
module friction_ode_system
   use friction_kinds, only: wp
   implicit none
   private

   public :: ode_system

   type, abstract :: ode_system
   contains
      procedure(dimension_interface), deferred :: dimension
      procedure(rhs_interface), deferred :: rhs
      procedure(jacobian_interface), deferred :: jacobian
      procedure :: controlled_dimension
      procedure :: relative_component
   end type ode_system

   abstract interface
      !> Number of state variables.
      pure function dimension_interface(self) result(n)
         import :: ode_system
         class(ode_system), intent(in) :: self
         integer :: n
      end function dimension_interface

      !> dydt = f(t, y).  y and dydt are contiguous (the integrators' state
      !> vectors always are), so an implementation indexes them without the
      !> strides of a general array section: the right-hand side is the
      !> innermost call of every integration.
      pure subroutine rhs_interface(self, t, y, dydt)
         import :: ode_system, wp
         class(ode_system), intent(in) :: self
         real(wp), intent(in) :: t
         real(wp), intent(in), contiguous :: y(:)
         real(wp), intent(out), contiguous :: dydt(:)
      end subroutine rhs_interface

      !> dfdy(i, j) = ∂f_i/∂y_j and dfdt(i) = ∂f_i/∂t.
      pure subroutine jacobian_interface(self, t, y, dfdy, dfdt)
         import :: ode_system, wp
         class(ode_system), intent(in) :: self
         real(wp), intent(in) :: t
         real(wp), intent(in) :: y(:)
         real(wp), intent(out) :: dfdy(:, :)
         real(wp), intent(out) :: dfdt(:)
      end subroutine jacobian_interface
   end interface

contains

   !> The leading components the step-size control measures (all of them
   !> unless a system says otherwise: a trajectory with its tangent vectors
   !> lets the trajectory alone set the steps).
   pure function controlled_dimension(self) result(n)
      class(ode_system), intent(in) :: self
      integer :: n

      n = self%dimension()
   end function controlled_dimension

   !> A component whose error the control also holds below a tenth of its
   !> distance from `reference`, down to `floor` (index 0: none, the
   !> default): a slip rate that a friction law takes the logarithm of, which
   !> an absolute tolerance above the slip rate would leave unmeasured.
   pure subroutine relative_component(self, index, reference, floor)
      class(ode_system), intent(in) :: self
      integer, intent(out) :: index
      real(wp), intent(out) :: reference, floor

      index = 0
      reference = 0.0_wp
      floor = 0.0_wp
   end subroutine relative_component

end module friction_ode_system
