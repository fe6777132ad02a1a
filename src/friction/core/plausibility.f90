!> Values that fit their variable's unit only as a slip: a number given in
!> another unit (radians for degrees, joules for eV, metres for angstroms)
!> is accepted by every check and computes a meaningless result.  Each rule
!> knows only the unit, so it holds for every variable that has that unit;
!> the values it flags are far from any a run of that unit could mean
!> (docs/input.md, Units).
module friction_plausibility
   use friction_kinds, only: wp
   use friction_strings, only: rtoa
   implicit none
   private

   public :: unit_plausibility

   !> one electronvolt in joules (SI, exact)
   real(wp), parameter :: electronvolt = 1.602176634e-19_wp
   real(wp), parameter :: two_pi = 6.283185307179586_wp

contains

   !> Why `value` looks like a number in another unit than `unit`; '' when
   !> it does not (or the unit has no rule).
   function unit_plausibility(unit, value) result(reason)
      character(len=*), intent(in) :: unit
      real(wp), intent(in) :: value
      character(len=:), allocatable :: reason
      real(wp) :: magnitude

      reason = ''
      magnitude = abs(value)
      if (.not. (magnitude > 0.0_wp .and. magnitude <= huge(magnitude))) return
      select case (trim(unit))
      case ('degree')
         ! Angles users give in degrees are whole or half degrees; pi/4,
         ! 0.122 or 1.5708 are radians.
         if (magnitude < two_pi .and. modulo(2.0_wp * magnitude, 1.0_wp) /= 0.0_wp) reason = 'below 2 pi and not a whole ' &
            & //'or half degree: it looks like radians, and the unit is degrees ('//rtoa(value)//' rad = ' &
            & //rtoa(value * 180.0_wp / (two_pi / 2.0_wp))//' degrees)'
      case ('eV')
         ! Surface energies are meV to eV; 1e-19 is a value in joules.
         if (magnitude < 1.0e-10_wp) reason = 'below 1e-10 eV: it looks like joules, and the unit is eV (' &
            & //rtoa(value)//' J = '//rtoa(value / electronvolt)//' eV)'
      case ('angstrom')
         ! Atomic lengths are tenths to hundreds of angstroms; 1e-10 is metres.
         if (magnitude < 1.0e-6_wp) reason = 'below 1e-6 angstrom: it looks like metres, and the unit is angstrom (' &
            & //rtoa(value)//' m = '//rtoa(value * 1.0e10_wp)//' angstrom)'
      end select
   end function unit_plausibility

end module friction_plausibility
