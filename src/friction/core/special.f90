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

   ! sin_cos's table and constants, from π in quadruple precision (folded at
   ! compile time): the step 2π/256 and the table's angles k 2π/256 exact
   ! to far below an ulp, so neither the reduction nor the table inherits
   ! the rounding of 2π/256 to double precision.
   integer, parameter :: table_size = 256
   integer, parameter :: qp = selected_real_kind(30)
   real(qp), parameter :: table_step_qp = 2.0_qp * acos(-1.0_qp) / table_size
   real(wp), parameter :: steps_per_radian = real(1.0_qp / table_step_qp, wp)
   real(wp), parameter :: round_shift = 6755399441055744.0_wp   ! 1.5 * 2^52: adding it rounds to an integer
   ! 2π/256 = step_head + step_tail, step_head with 26 significant bits:
   ! n step_head is exact for |n| < 2^26, that is |x| < 2^20 rad
   real(wp), parameter :: step_head = real(int(table_step_qp * 2.0_qp**31, int64), wp) / 2.0_wp**31
   real(wp), parameter :: step_tail = real(table_step_qp - step_head, wp)
   integer :: table_index   ! (the implied loops' index below: a name, never a value)
   real(wp), parameter :: sin_table(0:table_size - 1) = &
      & [(real(sin(table_step_qp * table_index), wp), table_index = 0, table_size - 1)]
   real(wp), parameter :: cos_table(0:table_size - 1) = &
      & [(real(cos(table_step_qp * table_index), wp), table_index = 0, table_size - 1)]
   real(wp), parameter :: s3 = -1.0_wp / 6.0_wp, s5 = 1.0_wp / 120.0_wp, s7 = -1.0_wp / 5040.0_wp
   real(wp), parameter :: c2 = -0.5_wp, c4 = 1.0_wp / 24.0_wp, c6 = -1.0_wp / 720.0_wp

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
   !> far beyond any scan's phase): x = a + b with a the nearest multiple
   !> k 2π/256 and |b| <= π/256, 2π/256 split in two (a 26-bit head, so k
   !> times it is exact, and the rest); sin a and cos a come from a table of
   !> 256 correctly rounded pairs (the compiler's, at compile time), sin b
   !> and cos b - 1 from their Taylor series through b^7 and b^6, whose
   !> remainders are below 1e-22 there, and
   !>   sin x = sin a + (sin a (cos b - 1) + cos a sin b),
   !>   cos x = cos a + (cos a (cos b - 1) - sin a sin b):
   !> the table's rounding (half an ulp) plus a correction below 0.013.  The
   !> result is within about an ulp of 1 of the correctly rounded one
   !> (tests/test_potentials.pf: 2 ulp of 1 against the C library's at a
   !> million points).  Beyond 2^20 the intrinsics answer.
   pure subroutine sin_cos(x, s, c)
      real(wp), intent(in) :: x(2)
      real(wp), intent(out) :: s(2), c(2)
      real(wp) :: shifted(2), n(2), b(2), b2(2), sin_b(2), cos_b_minus_1(2), sin_a(2), cos_a(2)
      integer(int64) :: k(2)

      if (.not. (abs(x(1)) < 1048576.0_wp .and. abs(x(2)) < 1048576.0_wp)) then
         s = sin(x)
         c = cos(x)
         return
      end if
      shifted = x * steps_per_radian + round_shift
      n = shifted - round_shift
      k = iand(transfer(shifted, k), int(table_size - 1, int64))   ! n mod 256, from the low bits
      b = (x - n * step_head) - n * step_tail
      b2 = b * b
      sin_b = b + b * b2 * (s3 + b2 * (s5 + b2 * s7))
      cos_b_minus_1 = b2 * (c2 + b2 * (c4 + b2 * c6))
      sin_a = [sin_table(k(1)), sin_table(k(2))]
      cos_a = [cos_table(k(1)), cos_table(k(2))]
      s = sin_a + (sin_a * cos_b_minus_1 + cos_a * sin_b)
      c = cos_a + (cos_a * cos_b_minus_1 - sin_a * sin_b)
   end subroutine sin_cos

end module friction_special
