!> What the machine's Lyapunov diagnostics (lyapunov.f90) ask of a run
!> through switches, whichever law it is of: a set-valued law's exact stick
!> and slip (switching.f90) or a band law's located edges and holds
!> (band.f90).  Started from checked settings at any (t0, y0), advanced to a
!> time, its Φ reset, and whether the block is held (stuck, or in the band),
!> so that one spectrum loop and one Benettin loop serve both.
module friction_machine_piecewise
   use friction_kinds, only: wp
   use friction_error, only: error_type
   use friction_ode_watch, only: step_watch
   use friction_law, only: sliding_law
   use friction_machine_config, only: machine_config
   implicit none
   private

   public :: piecewise_run

   type, abstract :: piecewise_run
      real(wp) :: t = 0.0_wp                !! time reached, s
      real(wp), allocatable :: y(:)         !! the state there, as the run integrates it
      real(wp), allocatable :: phi(:, :)    !! the tangent beside it (when started with it)
      integer :: lost = 0                   !! directions stick or a hold mapped to 0 since the last reset
   contains
      !> Start at t0 from y0, else from the settings' initial state, with Φ = I beside it when `tangent`.
      procedure(start_interface), deferred :: start_from
      !> Advance to t_target through any number of switches.
      procedure(advance_interface), deferred :: advance_to
      !> Φ = q from here on; the lost count cleared.
      procedure(reset_interface), deferred :: reset
      !> Whether the block is held now: stuck to the belt, or inside the band.
      procedure(held_interface), deferred :: is_held
   end type piecewise_run

   abstract interface
      subroutine start_interface(self, c, law, t0, tangent, error, y0)
         import :: piecewise_run, machine_config, sliding_law, wp, error_type
         class(piecewise_run), target, intent(inout) :: self
         type(machine_config), intent(in) :: c
         class(sliding_law), intent(in) :: law
         real(wp), intent(in) :: t0
         logical, intent(in) :: tangent
         type(error_type), allocatable, intent(out) :: error
         real(wp), intent(in), optional :: y0(:)
      end subroutine start_interface

      subroutine advance_interface(self, t_target, error, watch)
         import :: piecewise_run, wp, error_type, step_watch
         class(piecewise_run), intent(inout) :: self
         real(wp), intent(in) :: t_target
         type(error_type), allocatable, intent(out) :: error
         class(step_watch), intent(inout), optional :: watch
      end subroutine advance_interface

      subroutine reset_interface(self, q)
         import :: piecewise_run, wp
         class(piecewise_run), intent(inout) :: self
         real(wp), intent(in) :: q(:, :)
      end subroutine reset_interface

      logical function held_interface(self)
         import :: piecewise_run
         class(piecewise_run), intent(in) :: self
      end function held_interface
   end interface

end module friction_machine_piecewise
