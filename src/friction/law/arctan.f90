!> Eq. 10's regularized law, the arctan standing in for sgn v:
!>
!>   F = μ N (2/π) arctan(ε v) / (1 + δ |v|).
!>
!> The one place of its formula: the brake's regularized model
!> (brake/regularized.f90) evaluates it through arctan_force and
!> arctan_slope in its nondimensional units (ε', δ', N' = N/k1).
module friction_law_arctan
   use friction_kinds, only: wp, pi
   use friction_checks, only: config_checker
   use friction_law, only: sliding_law
   use friction_law_settings, only: law_group
   implicit none
   private

   public :: arctan_law, arctan_force, arctan_slope

   type, extends(sliding_law) :: arctan_law
   contains
      procedure :: check
      procedure :: force
      procedure :: partials
   end type arctan_law

contains

   !> μ N (2/π) arctan(ε v) / (1 + δ |v|), in the units of N.
   pure real(wp) function arctan_force(mu, normal, epsilon, delta, v)
      real(wp), intent(in) :: mu, normal, epsilon, delta, v

      arctan_force = mu * normal * (2.0_wp / pi) * atan(epsilon * v) / (1.0_wp + delta * abs(v))
   end function arctan_force

   !> ∂F/∂v at fixed N.  The kink of |v| at 0 multiplies arctan(0) = 0, so
   !> the derivative is continuous.
   pure real(wp) function arctan_slope(mu, normal, epsilon, delta, v)
      real(wp), intent(in) :: mu, normal, epsilon, delta, v
      real(wp) :: ev, denominator

      ev = epsilon * v
      denominator = 1.0_wp + delta * abs(v)
      arctan_slope = mu * normal * (2.0_wp / pi) * &
         & (epsilon / (1.0_wp + ev * ev) / denominator - atan(ev) * delta * sign(1.0_wp, v) / denominator**2)
   end function arctan_slope

   subroutine check(self, c)
      class(arctan_law), intent(in) :: self
      type(config_checker), intent(inout) :: c

      call c%nonnegative(law_group, 'mu', self%p%mu, 'friction coefficient')
      call c%finite(law_group, 'mu', self%p%mu)
      call c%positive(law_group, 'epsilon', self%p%epsilon, 's/m; the arctan law needs a steepness')
      call c%finite(law_group, 'epsilon', self%p%epsilon)
      call c%nonnegative(law_group, 'delta', self%p%delta, 's/m')
      call c%finite(law_group, 'delta', self%p%delta)
   end subroutine check

   pure real(wp) function force(self, v, z, normal, applied)
      class(arctan_law), intent(in) :: self
      real(wp), intent(in) :: v, normal, applied
      real(wp), intent(in) :: z(:)

      force = arctan_force(self%p%mu, normal, self%p%epsilon, self%p%delta, v)
   end function force

   pure subroutine partials(self, v, z, normal, applied, dfdv, dfdz, dfda, dgdv, dgdz)
      class(arctan_law), intent(in) :: self
      real(wp), intent(in) :: v, normal, applied
      real(wp), intent(in) :: z(:)
      real(wp), intent(out) :: dfdv, dfdz(:), dfda, dgdv(:), dgdz(:, :)

      dfdv = arctan_slope(self%p%mu, normal, self%p%epsilon, self%p%delta, v)
      dfda = 0.0_wp
   end subroutine partials

end module friction_law_arctan
