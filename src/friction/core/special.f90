!> Elementary functions without cancellation near zero: exp(x) - 1 and
!> log(1 + x), from the C library's expm1 and log1p (C99), which are
!> correctly rounded to within an ulp over the whole range.  The Langevin
!> step's noise amplitude needs 1 - exp(-2ch/m) for small ch/m
!> (friction_afm_langevin); the Kramers hazard's exponential rule needs
!> both (friction_afm_kramers).
!>
!> And sin and cos of one argument at once, for the periodic surfaces
!> (NaF, HOPG), whose gradient is a third of a map's time: the C library's
!> sincos handles any argument, these only the phases a scan reaches
!> (|x| < 2^20), which lets them be three times as fast (sin_cos below).
module friction_special
   use, intrinsic :: iso_c_binding, only: c_double
   use, intrinsic :: iso_fortran_env, only: int64
   use friction_kinds, only: wp
   implicit none
   private

   public :: expm1, log1p, sin_cos

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

   !> sin(x) and cos(x) of two arguments at once (a periodic surface's two
   !> phases), written so the compiler evaluates both in one pair of vector
   !> lanes: no branch but the range check.  |x| < 2^20 (a million radians,
   !> far beyond any scan's phase): x is reduced to r in [-π/4, π/4] by the
   !> nearest multiple n of π/2, with π/2 split in two (a 33-bit head, so n
   !> times it is exact, and the rest), and sin r, cos r come from their
   !> Taylor series through r^17 and r^18, whose remainders are below 1e-19
   !> there, summed in Estrin's order (short dependency chains).  The result
   !> is within a few units of the last place of the correctly rounded one
   !> (tests/test_special.pf: 2 ulp of 1 against the C library's at a
   !> million points).  Beyond 2^20 the intrinsics answer.
   pure subroutine sin_cos(x, s, c)
      real(wp), intent(in) :: x(2)
      real(wp), intent(out) :: s(2), c(2)
      real(wp), parameter :: two_over_pi = 0.63661977236758134308_wp
      real(wp), parameter :: round_shift = 6755399441055744.0_wp   ! 1.5 * 2^52: adding it rounds to an integer
      real(wp), parameter :: half_pi_head = 1.570796326734125614166259765625_wp   ! 33 significant bits
      real(wp), parameter :: half_pi_tail = 6.0771005065061926014751442098585e-11_wp
      real(wp), parameter :: s3 = -1.0_wp / 6.0_wp, s5 = 1.0_wp / 120.0_wp, s7 = -1.0_wp / 5040.0_wp, &
         & s9 = 1.0_wp / 362880.0_wp, s11 = -1.0_wp / 39916800.0_wp, s13 = 1.0_wp / 6227020800.0_wp, &
         & s15 = -1.0_wp / 1307674368000.0_wp, s17 = 1.0_wp / 355687428096000.0_wp
      real(wp), parameter :: c2 = -0.5_wp, c4 = 1.0_wp / 24.0_wp, c6 = -1.0_wp / 720.0_wp, &
         & c8 = 1.0_wp / 40320.0_wp, c10 = -1.0_wp / 3628800.0_wp, c12 = 1.0_wp / 479001600.0_wp, &
         & c14 = -1.0_wp / 87178291200.0_wp, c16 = 1.0_wp / 20922789888000.0_wp, &
         & c18 = -1.0_wp / 6402373705728000.0_wp
      real(wp) :: shifted(2), n(2), r(2), r2(2), r4(2), r8(2), sr(2), cr(2)
      integer(int64) :: quadrant(2)

      if (.not. (abs(x(1)) < 1048576.0_wp .and. abs(x(2)) < 1048576.0_wp)) then
         s = sin(x)
         c = cos(x)
         return
      end if
      shifted = x * two_over_pi + round_shift
      n = shifted - round_shift
      quadrant = iand(transfer(shifted, quadrant), 3_int64)   ! n mod 4, from the low bits
      r = (x - n * half_pi_head) - n * half_pi_tail
      r2 = r * r
      r4 = r2 * r2
      r8 = r4 * r4
      sr = r + r * r2 * ((s3 + s5 * r2) + r4 * (s7 + s9 * r2) + r8 * ((s11 + s13 * r2) + r4 * (s15 + s17 * r2)))
      cr = 1.0_wp + r2 * ((c2 + c4 * r2) + r4 * (c6 + c8 * r2) + r8 * ((c10 + c12 * r2) + r4 * (c14 + c16 * r2)) &
         & + r8 * r8 * c18)
      ! quadrant 0: (sr, cr), 1: (cr, -sr), 2: (-sr, -cr), 3: (-cr, sr)
      s = merge(cr, sr, iand(quadrant, 1_int64) == 1_int64)
      c = merge(sr, cr, iand(quadrant, 1_int64) == 1_int64)
      s = merge(-s, s, quadrant >= 2_int64)
      c = merge(-c, c, quadrant == 1_int64 .or. quadrant == 2_int64)
   end subroutine sin_cos

end module friction_special
