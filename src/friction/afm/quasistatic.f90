!> The quasistatic tip: where the spring and the surface balance,
!>   G(u) = k u + dV/dr (r_M + u) = 0,   u = r - r_M,
!> with the Jacobian J = K + H (K = diag(k), H the potential's analytic
!> Hessian), which is also the Hessian of the total energy
!> E = V(r) + ½ Σ k_i (r_i - r_M,i)².  A minimum of E has J positive
!> definite; the tip follows such a minimum as the support moves, and the
!> minimum ends at a fold, where J becomes singular (docs/physics.md, Prandtl–Tomlinson: the slip of
!> the Prandtl–Tomlinson model).  The tracking loop and the jump at a fold
!> live in friction_afm_scan; here are the pure pieces: Newton's method
!> kept inside the convex region, and the tangent of the branch.
module friction_afm_quasistatic
   use friction_kinds, only: wp
   use friction_afm_tip, only: afm_tip
   implicit none
   private

   public :: newton_equilibrium, equilibrium_tangent, force_imbalance

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

end module friction_afm_quasistatic
