!> method = 'auto': the stepper (GSL's, or the library's Rosenbrock) that the
!> work-precision charts show to be the fastest for a scene at the asked
!> tolerance.
!>
!> The table and its evidence are in docs/speed.md:
!> scripts/work_precision measures every stepper on every scene over a
!> ladder of tolerances against a far tighter reference, and for each rung
!> finds the fastest stepper reaching the error that rung asks for
!> (atol + rtol times the scale of the measured quantity).  The bands below
!> are those findings; a scene not measured falls back on the stepper of the
!> nearest measured scene.
!>
!> A stiff scene comes first: where the explicit steppers would be bound by
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

   public :: auto_name, auto_method, stiff_threshold, stiff_method, oscillator_rate
   public :: rosenbrock_threshold, rosenbrock_method, rosenbrock_rtol, rosenbrock_stiff_rtol
   public :: rodas4_transition_bound, transition_bound

   !> The method name that asks for the choice.
   character(len=*), parameter :: auto_name = 'auto'

   !> Stiffness S from which the implicit stiff_method is chosen.  Measured on
   !> NaF and HOPG lines of 128 samples (docs/speed.md, Stiff tips): below
   !> S = 100 the explicit pairs are 2 to 5 times faster at equal error; from
   !> 120 to 460 either may win by up to 2 times, depending on how much of
   !> the cost is the slips (accuracy) rather than the sticks (stability);
   !> from 1200 on bsimp wins by 6 times and more.  Hence the switch at 1000.
   real(wp), parameter :: stiff_threshold = 1000.0_wp

   !> The stepper of stiff scenes at tight tolerances (rtol below
   !> rosenbrock_stiff_rtol): the Bader-Deuflhard extrapolation with the
   !> analytic Jacobian; the fastest of GSL's implicit steppers at equal error
   !> on the stiff tips measured (msbdf, rk4imp and rk2imp are slower or less
   !> accurate than asked).
   character(len=*), parameter :: stiff_method = 'bsimp'

   !> The library's Rosenbrock stepper (order 4, L-stable, one LU per step):
   !> on the stiff tips measured (16 lines, c = 3e-2 and 1e-1 N s/m, S = 1181
   !> and 3937) 5 to 20 times faster than bsimp at rtol 1e-3 to 1e-5 and
   !> still ahead at 1e-6 (72 against 84 ms, 17 against 106 ms), with errors
   !> within the asked tolerance; at 1e-7 bsimp is 3 times faster.
   character(len=*), parameter :: rosenbrock_method = 'rodas4'
   real(wp), parameter :: rosenbrock_stiff_rtol = 1.0e-6_wp

   !> Between S = rosenbrock_threshold and stiff_threshold the explicit pairs
   !> pay for stability at loose tolerances only: there rodas4 is 1.7 to 10
   !> times faster than rkck at rtol 1e-3 and 1e-4 (NaF c = 3e-3 and 1e-2
   !> N s/m, S = 121 and 394), and slower at 1e-5 (S = 121).  Below
   !> S = 100 (the paper's tips, S = 46 and 60) the explicit pairs win at
   !> every rtol (rodas4 1.2 to 4 times slower).
   real(wp), parameter :: rosenbrock_threshold = 100.0_wp
   real(wp), parameter :: rosenbrock_rtol = 1.0e-4_wp

   !> The regularized brake law's transition: its slope changes over |v_rel|
   !> of about 1/epsilon_prime, and a stepper whose velocity tolerance in
   !> stick (atol + rtol |v_dr'|) spans several such widths may step across
   !> it without its error estimate seeing it.  Measured on the paper's
   !> brake, epsilon_prime 1e5 to 1e10 (docs/speed.md, "The regularized
   !> law's steppers"), against T = epsilon_prime (atol + rtol |v_dr'|):
   !> rodas4 within 32 times the asked tolerance up to T = 1.4, 88 to 113
   !> times at 3.8 to 4.5, 289 to 12 500 times from 11.5 on; rodas3 within 56
   !> times up to T = 6.4, 99 to 107 at 12.8 to 13.5, 280 to 980 beyond; the
   !> explicit rkf45 and rkck 140 to 1300 times from 12.8 on.  T, not the
   !> split between atol and rtol, decides (the same at atol = rtol / 100
   !> and at atol from 1e-10 to 1e-6 with rtol 1e-8 or 1e-4).  Above
   !> rodas4_transition_bound `auto` does not pick rodas4, and the brake
   !> warns about rodas4; above transition_bound about rodas3, rkf45, rkck.
   real(wp), parameter :: rodas4_transition_bound = 3.0_wp
   real(wp), parameter :: transition_bound = 10.0_wp

contains

   !> The stepper for a scene ('afm' or 'brake'), its model (for the AFM the
   !> potential: 'naf', 'hopg', 'lj'; for the brake 'regularized' or
   !> 'switched'), the asked relative tolerance and, where the caller can
   !> tell, the stiffness S (see above; absent or 0: not known, the table
   !> alone decides).  For the regularized brake law, `transition` is its
   !> velocity tolerance in units of the arctan's transition (see
   !> rodas4_transition_bound; absent: resolved, as on the paper's brake at
   !> rtol below 1e-6).  Always a known step type.
   pure function auto_method(scene, model, rtol, stiffness, transition) result(method)
      character(len=*), intent(in) :: scene, model
      real(wp), intent(in) :: rtol
      real(wp), intent(in), optional :: stiffness, transition
      character(len=16) :: method

      if (present(stiffness)) then
         if (stiffness >= stiff_threshold) then
            if (rtol >= rosenbrock_stiff_rtol) then
               method = rosenbrock_method
            else
               method = stiff_method
            end if
            return
         else if (stiffness >= rosenbrock_threshold .and. rtol >= rosenbrock_rtol) then
            method = rosenbrock_method
            return
         end if
      end if
      select case (trim(scene))
      case ('brake')
         select case (trim(model))
         case ('regularized')
            ! Stiff near v_rel = 0 (epsilon' = 3.5e7): the L-stable rk4imp is
            ! cheapest down to 1e-6 among those right at their rtol; tighter,
            ! the library's rodas4 (L-stable, one LU a step) is 2.5 to 3.5
            ! times faster than the explicit pairs down to 1e-9, where its
            ! velocity tolerance resolves the law's transition; where it does
            ! not (epsilon' above about 2e8 at rtol 1e-6), rk8pd, right at
            ! every epsilon' and rtol measured.  Tighter than 1e-9 accuracy
            ! costs more than stability and rk8pd wins.  (rk2, rk4imp and
            ! rk8pd in their bands were within 90 times the asked tolerance
            ! at every epsilon' from 1e3 to 1e10 measured.)
            if (rtol >= 1.0e-3_wp) then
               method = 'rk2'
            else if (rtol >= 1.0e-6_wp) then
               method = 'rk4imp'
            else if (rtol >= 1.0e-9_wp) then
               method = 'rodas4'
               if (present(transition)) then
                  if (transition > rodas4_transition_bound) method = 'rk8pd'
               end if
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
