!> What an integration asks while it runs: whether to go on.  The solver
!> and the event locator call a watch between pieces of a trip (a few steps
!> each), so that a stop request or a wall-clock limit reaches a trip that
!> crawls inside one output interval.  The ode layer knows no job: the scene
!> layer's watch (scene/report.f90) asks the job's reporter and clock.
module friction_ode_watch
   use friction_kinds, only: wp
   use friction_error, only: error_type
   implicit none
   private

   public :: step_watch

   type, abstract :: step_watch
   contains
      !> An error when the integration must end at time t (the system's time).
      procedure(check_interface), deferred :: check
   end type step_watch

   abstract interface
      subroutine check_interface(self, t, error)
         import :: step_watch, wp, error_type
         class(step_watch), intent(inout) :: self
         real(wp), intent(in) :: t
         type(error_type), allocatable, intent(out) :: error
      end subroutine check_interface
   end interface

end module friction_ode_watch
