!> The quasistatic tip: where the spring and the surface balance,
!>   G(u) = k u + dV/dr (r_M + u) = 0,   u = r - r_M,
!> with the Jacobian J = K + H (K = diag(k), H the potential's analytic
!> Hessian), which is also the Hessian of the total energy
!> E = V(r) + ½ Σ k_i (r_i - r_M,i)².  A minimum of E has J positive
!> definite; the tip follows such a minimum as the support moves, and the
!> minimum ends at a fold, where J becomes singular (docs/physics.md, Prandtl–Tomlinson: the slip of
!> the Prandtl–Tomlinson model).  The trips that follow a minimum
!> (friction_afm_deterministic_trip, friction_afm_slow_limit) land the tip
!> after a fold each their own way; here are the pure pieces: Newton's
!> method kept inside the convex region, the tangent of the branch, and one
!> step of the continuation along it up to a fold.
module friction_afm_quasistatic
   use friction_kinds, only: wp
   use friction_afm_tip, only: afm_tip
   implicit none
   private

   public :: newton_equilibrium, equilibrium_tangent, force_imbalance, continuation_step, landing_distance

   !> The continuation (continuation_step): the support travel, Å, to which a
   !> fold is located (the force near a fold varies like the square root of
   !> the distance to it: ~1e-4 nN here); the push, Å, that starts the tip
   !> off the vanished minimum (small against any lattice period, large
   !> against the ~sqrt(fold_resolution) ghost of the minimum).
   real(wp), parameter :: fold_resolution = 1.0e-9_wp, jump_push = 0.05_wp
   !> How close, Å, a relaxed or descended state must be to the minimum
   !> Newton's method finds from it to count as landed there.
   real(wp), parameter :: landing_distance = 0.05_wp

   !> Newton's method stops when the update is below this, Å: far below
   !> any tolerance a map is integrated to (atol 1e-4 Å), and well above
   !> the rounding of u (~1e-16 Å per Å of u).
   real(wp), parameter :: newton_tolerance = 1.0e-11_wp
   integer, parameter :: newton_iterations = 12

contains

   !> G(u) at support time t, eV/Å.
   pure function force_imbalance(tip, t, u) result(g)
      type(afm_tip), intent(in) :: tip
      real(wp), intent(in) :: t, u(:)
      real(wp) :: g(size(u))
      real(wp) :: grad(3)

      call tip%potential%gradient(tip%tip_position(t, u), grad)
      g = tip%spring(1:size(u)) * u + grad(1:size(u))
   end function force_imbalance

   !> J = K + H at support time t and displacement u, eV/Å².
   pure function total_hessian(tip, t, u) result(j)
      type(afm_tip), intent(in) :: tip
      real(wp), intent(in) :: t, u(:)
      real(wp) :: j(size(u), size(u))
      real(wp) :: h(3, 3)
      integer :: i, n

      n = size(u)
      call tip%potential%hessian(tip%tip_position(t, u), h)
      j = h(1:n, 1:n)
      do i = 1, n
         j(i, i) = j(i, i) + tip%spring(i)
      end do
   end function total_hessian

   !> Solve a x = b for a symmetric a by Cholesky; ok = .false. when a is
   !> not positive definite (the test the tracking relies on).
   pure subroutine cholesky_solve(a, b, x, ok)
      real(wp), intent(in) :: a(:, :), b(:)
      real(wp), intent(out) :: x(:)
      logical, intent(out) :: ok
      real(wp) :: l(size(b), size(b)), d
      integer :: i, j, n

      n = size(b)
      l = 0.0_wp
      ok = .false.
      x = 0.0_wp
      do j = 1, n
         d = a(j, j) - sum(l(j, 1:j - 1)**2)
         if (.not. (d > 0.0_wp)) return
         l(j, j) = sqrt(d)
         do i = j + 1, n
            l(i, j) = (a(i, j) - sum(l(i, 1:j - 1) * l(j, 1:j - 1))) / l(j, j)
         end do
      end do
      do i = 1, n
         x(i) = (b(i) - sum(l(i, 1:i - 1) * x(1:i - 1))) / l(i, i)
      end do
      do i = n, 1, -1
         x(i) = (x(i) - sum(l(i + 1:n, i) * x(i + 1:n))) / l(i, i)
      end do
      ok = .true.
   end subroutine cholesky_solve

   !> Newton's method for G(u) = 0 at support time t from the guess u0.
   !> ok only if every iterate had J positive definite (so the iterates stay
   !> in the convex part of one well of E and cannot wander to a saddle or a
   !> maximum) and the update fell below newton_tolerance within
   !> newton_iterations.
   pure subroutine newton_equilibrium(tip, t, u0, u, ok)
      type(afm_tip), intent(in) :: tip
      real(wp), intent(in) :: t, u0(:)
      real(wp), intent(out) :: u(:)
      logical, intent(out) :: ok
      real(wp) :: delta(size(u0))
      integer :: k

      u = u0
      do k = 1, newton_iterations
         call cholesky_solve(total_hessian(tip, t, u), -force_imbalance(tip, t, u), delta, ok)
         if (.not. ok) return
         u = u + delta
         if (.not. all(abs(u) <= huge(u))) exit
         if (norm2(delta) <= newton_tolerance) then
            ! J at the converged point too.
            call cholesky_solve(total_hessian(tip, t, u), -force_imbalance(tip, t, u), delta, ok)
            return
         end if
      end do
      ok = .false.
   end subroutine newton_equilibrium

   !> du/dt along the branch of equilibria at (t, u): differentiating
   !> G(u(t), t) = 0 with r = r_M + u gives J dr/dt = K v_M, so
   !> du/dt = J⁻¹ K v_M - v_M.  ok = .false. if J is not positive definite.
   pure subroutine equilibrium_tangent(tip, t, u, dudt, ok)
      type(afm_tip), intent(in) :: tip
      real(wp), intent(in) :: t, u(:)
      real(wp), intent(out) :: dudt(:)
      logical, intent(out) :: ok
      integer :: n

      n = size(u)
      call cholesky_solve(total_hessian(tip, t, u), tip%spring(1:n) * tip%support_velocity(1:n), dudt, ok)
      dudt = dudt - tip%support_velocity(1:n)
   end subroutine equilibrium_tangent

   !> One step of the continuation of a minimum u of E from support time t
   !> towards t1, support speed `speed` (Å/s), trying the step h: a
   !> tangent predictor (equilibrium_tangent) and Newton's method as
   !> corrector.  The step is accepted only when Newton converges with J
   !> positive definite at every iterate and lands within half a step (the
   !> larger of the predicted move and the support's travel) of the
   !> prediction: the minimum cannot then have been left for another well;
   !> t and u advance and h doubles.  Otherwise h is quartered; once it is
   !> below fold_resolution of support travel the minimum has ended at a
   !> fold: `folded`, t goes past the fold and u is pushed jump_push along
   !> the tip's motion dr/dt = du/dt + v_M (the direction in which the
   !> minimum vanished) off the ghost of the minimum, kept in `ghost`.  The
   !> caller lands the tip from there and sets h.
   pure subroutine continuation_step(tip, t, t1, h, speed, u, folded, ghost)
      type(afm_tip), intent(in) :: tip
      real(wp), intent(inout) :: t, h
      real(wp), intent(in) :: t1, speed
      real(wp), intent(inout) :: u(:)
      logical, intent(out) :: folded
      real(wp), intent(out) :: ghost(:)
      real(wp) :: dudt(size(u)), predicted(size(u)), corrected(size(u)), motion(size(u))
      logical :: ok, last

      folded = .false.
      last = t + h >= t1
      if (last) h = t1 - t
      call equilibrium_tangent(tip, t, u, dudt, ok)
      if (.not. ok) dudt = 0.0_wp
      predicted = u + h * dudt
      call newton_equilibrium(tip, t + h, predicted, corrected, ok)
      if (ok) ok = norm2(corrected - predicted) <= 0.5_wp * max(norm2(predicted - u), h * speed)
      if (ok) then
         t = merge(t1, t + h, last)
         u = corrected
         h = 2.0_wp * h
      else if (h > fold_resolution / speed) then
         h = 0.25_wp * h
      else
         folded = .true.
         motion = dudt + tip%support_velocity(1:size(u))
         ghost = u
         if (norm2(motion) > 0.0_wp) u = u + jump_push * motion / norm2(motion)
         t = merge(t1, t + h, last)
      end if
   end subroutine continuation_step

end module friction_afm_quasistatic
