!> A mechanism's equations of motion with a law's force and states, and the
!> same flow with the kinks of the law's partial derivatives as its events
!> (docs/chaos.md, "The tangent of a stiff law"): where the exponential
!> tangent's steps must end (GMS's switch bands), on the machine and the
!> brake alike.
module friction_law_kinked
   use friction_kinds, only: wp
   use friction_ode_events, only: event_system
   use friction_ode_forwarding, only: forwarding_system
   use friction_law, only: sliding_law, max_law_states
   implicit none
   private

   public :: law_flow, kinked_system

   !> A mechanism's flow with a law: the law, how many states join the
   !> equations and their scales (in the law's units; the flow integrates
   !> them in units of their scale), and where in a state the law reads its
   !> arguments (`law_arguments`, in the law's units).
   type, abstract, extends(event_system) :: law_flow
      class(sliding_law), allocatable :: law
      integer :: n_states = 0
      real(wp) :: scale(max_law_states) = 1.0_wp
   contains
      procedure(arguments_interface), deferred :: law_arguments
   end type law_flow

   abstract interface
      !> The law's sliding velocity v, states z (n_states of them) and normal load at the flow's state y.
      pure subroutine arguments_interface(self, y, v, z, normal)
         import :: law_flow, wp
         class(law_flow), intent(in) :: self
         real(wp), intent(in) :: y(:)
         real(wp), intent(out) :: v, z(:), normal
      end subroutine arguments_interface
   end interface

   !> A flow of the mechanism (`model` itself, or in another frame, with the
   !> divergence appended, ...: its leading components those of `model`) with
   !> the kinks of model's law's partial derivatives as its events.
   type, extends(forwarding_system) :: kinked_system
      class(law_flow), allocatable :: model
   contains
      procedure :: event_count => kinked_event_count
      procedure :: event_values => kinked_event_values
   end type kinked_system

contains

   pure integer function kinked_event_count(self)
      class(kinked_system), intent(in) :: self

      kinked_event_count = self%model%law%kink_count()
   end function kinked_event_count

   pure subroutine kinked_event_values(self, t, y, g)
      class(kinked_system), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: y(:)
      real(wp), intent(out) :: g(:)
      real(wp) :: v, z(max_law_states), normal
      integer :: n

      n = self%model%n_states
      call self%model%law_arguments(y, v, z(1:n), normal)
      call self%model%law%kinks(v, z(1:n), normal, g)
   end subroutine kinked_event_values

end module friction_law_kinked
