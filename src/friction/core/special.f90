!> Elementary functions without cancellation near zero: exp(x) - 1 and
!> log(1 + x), from the C library's expm1 and log1p (C99), which are
!> correctly rounded to within an ulp over the whole range.  The Langevin
!> step's noise amplitude needs 1 - exp(-2ch/m) for small ch/m
!> (friction_afm_langevin); the Kramers hazard's exponential rule needs
!> both (friction_afm_kramers).
module friction_special
   use, intrinsic :: iso_c_binding, only: c_double
   use friction_kinds, only: wp
   implicit none
   private

   public :: expm1, log1p

   interface
      pure function c_expm1(x) result(y) bind(c, name='expm1')
         import :: c_double
         real(c_double), value :: x
         real(c_double) :: y
      end function c_expm1

      pure function c_log1p(x) result(y) bind(c, name='log1p')
         import :: c_double
         real(c_double), value :: x
         real(c_double) :: y
      end function c_log1p
   end interface

contains

   !> exp(x) - 1.
   elemental function expm1(x) result(y)
      real(wp), intent(in) :: x
      real(wp) :: y

      y = real(c_expm1(real(x, c_double)), wp)
   end function expm1

   !> log(1 + x), x > -1.
   elemental function log1p(x) result(y)
      real(wp), intent(in) :: x
      real(wp) :: y

      y = real(c_log1p(real(x, c_double)), wp)
   end function log1p

end module friction_special
