!> method = 'auto': the GSL stepper that the work-precision charts show to be
!> the fastest for a scene at the asked tolerance.
!>
!> The table and its evidence are in docs/speed.md:
!> scripts/work_precision measures every stepper on every scene over a
!> ladder of tolerances against a far tighter reference, and for each rung
!> finds the fastest stepper reaching the error that rung asks for
!> (atol + rtol times the scale of the measured quantity).  The bands below
!> are those findings; a scene not measured falls back on the stepper of the
!> nearest measured scene.
module friction_ode_auto
   use friction_kinds, only: wp
   implicit none
   private

   public :: auto_name, auto_method

   !> The method name that asks for the choice.
   character(len=*), parameter :: auto_name = 'auto'

contains

   !> The stepper for a scene ('afm' or 'brake'), its model (for the AFM the
   !> potential: 'naf', 'hopg', 'lj'; for the brake 'regularized' or
   !> 'switched') and the asked relative tolerance.  Always a known step type.
   pure function auto_method(scene, model, rtol) result(method)
      character(len=*), intent(in) :: scene, model
      real(wp), intent(in) :: rtol
      character(len=16) :: method

      select case (trim(scene))
      case ('brake')
         select case (trim(model))
         case ('regularized')
            ! Stiff near v_rel = 0 (epsilon' = 3.5e7): the L-stable rk4imp is
            ! cheapest down to 1e-6; tighter, accuracy costs more than
            ! stability and the explicit pairs win.
            if (rtol >= 1.0e-3_wp) then
               method = 'rk2'
            else if (rtol >= 1.0e-6_wp) then
               method = 'rk4imp'
            else if (rtol >= 1.0e-9_wp) then
               method = 'rkck'
            else
               method = 'rk8pd'
            end if
         case default  ! 'switched': smooth between located events
            method = 'rk8pd'
         end select
      case default  ! 'afm'
         select case (trim(model))
         case ('hopg')
            method = merge('rkck ', 'rk8pd', rtol >= 1.0e-6_wp)
         case ('lj')
            method = 'rk8pd'
         case default  ! 'naf'
            method = merge('rkck ', 'rk8pd', rtol >= 1.0e-7_wp)
         end select
      end select
   end function auto_method

end module friction_ode_auto
