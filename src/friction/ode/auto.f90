!> method = 'auto', the rules that know no scene: each scene keeps its own
!> table of the fastest explicit stepper per tolerance (docs/speed.md, the
!> work-precision charts), and consults these rules first.
!>
!> A stiff system comes first: where the explicit steppers would be bound by
!> stability rather than accuracy, an implicit one is chosen whatever the
!> table says (the Rosenbrock stepper rodas4, or bsimp at tight tolerances).
!> The caller measures that as the stiffness
!>   S = (largest decay rate of the linearised system) x (output interval),
!> which is about three times the number of steps an explicit pair must take
!> between two outputs however loose the tolerance (its stability interval
!> on the negative real axis is about 3), while an implicit stepper can
!> step from output to output.  The crossovers S = rosenbrock_threshold and
!> S = stiff_threshold are measured (docs/speed.md, Stiff tips).
module friction_ode_auto
   use friction_kinds, only: wp
   implicit none
   private

   public :: auto_name, stiff_choice, stiff_threshold, stiff_method, oscillator_rate
   public :: rosenbrock_threshold, rosenbrock_method, rosenbrock_rtol, rosenbrock_stiff_rtol

   !> The method name that asks for the choice.
   character(len=*), parameter :: auto_name = 'auto'

   !> Stiffness S from which an implicit stepper is chosen: above it the
   !> explicit pairs are bound by stability (docs/speed.md, Stiff tips).
   real(wp), parameter :: stiff_threshold = 1000.0_wp

   !> The implicit stepper of stiff systems at tight tolerances (rtol below
   !> rosenbrock_stiff_rtol): GSL's fastest implicit stepper at equal error there.
   character(len=*), parameter :: stiff_method = 'bsimp'

   !> The library's Rosenbrock stepper (order 4, L-stable, one LU per step),
   !> the fastest on stiff systems from rtol rosenbrock_stiff_rtol up.
   character(len=*), parameter :: rosenbrock_method = 'rodas4'
   real(wp), parameter :: rosenbrock_stiff_rtol = 1.0e-6_wp

   !> From this S up, and at rtol from rosenbrock_rtol up, rodas4 beats the
   !> explicit pairs that pay for stability at loose tolerances.
   real(wp), parameter :: rosenbrock_threshold = 100.0_wp
   real(wp), parameter :: rosenbrock_rtol = 1.0e-4_wp

contains

   !> The implicit stepper a system of stiffness S needs at the asked relative
   !> tolerance, or '' where S leaves the choice to the scene's own table of
   !> explicit steppers (S not known: 0).
   pure function stiff_choice(rtol, stiffness) result(method)
      real(wp), intent(in) :: rtol, stiffness
      character(len=16) :: method

      method = ''
      if (stiffness >= stiff_threshold) then
         method = merge(rosenbrock_method//'  ', stiff_method//'   ', rtol >= rosenbrock_stiff_rtol)
      else if (stiffness >= rosenbrock_threshold .and. rtol >= rosenbrock_rtol) then
         method = rosenbrock_method
      end if
   end function stiff_choice

   !> The largest decay rate |lambda| (1/time) of a damped oscillator
   !> m x'' + c x' + k x = 0 whose stiffness k may be anywhere in
   !> [k_low, k_high] (a spring plus a surface curvature of either sign):
   !> the roots of m lambda**2 + c lambda + k = 0.  Over that range the
   !> largest |lambda| is at an end: the fast real root grows as k falls,
   !> the modulus sqrt(k/m) of complex roots as k rises.  Without inertia
   !> (m = 0) the rate is k/c; 0 when neither m nor c is positive.
   pure real(wp) function oscillator_rate(m, c, k_low, k_high) result(rate)
      real(wp), intent(in) :: m, c, k_low, k_high

      if (m > 0.0_wp) then
         rate = max(root_modulus(k_low), root_modulus(k_high))
      else if (c > 0.0_wp) then
         rate = max(abs(k_low), abs(k_high)) / c
      else
         rate = 0.0_wp
      end if
   contains
      pure real(wp) function root_modulus(k)
         real(wp), intent(in) :: k
         real(wp) :: half, discriminant

         half = 0.5_wp * c / m
         discriminant = half**2 - k / m
         if (discriminant >= 0.0_wp) then
            root_modulus = abs(half) + sqrt(discriminant)
         else
            root_modulus = sqrt(k / m)
         end if
      end function root_modulus
   end function oscillator_rate

end module friction_ode_auto
