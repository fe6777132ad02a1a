!> The LuGre law (Canudas de Wit, Olsson, Åström and Lischinsky, 1995): the
!> contact as bristles of mean deflection z (m),
!>
!>   ż = v - σ0 |v| z / g(v),   F = σ0 z + σ1 ż + σ2 v,
!>
!> g the Stribeck curve (friction_law_stribeck).  In steady sliding
!> z = g(v) sgn(v)/σ0 and F = g(v) sgn v + σ2 v; about rest the contact is a
!> spring σ0 with damping σ1 + σ2 (pre-sliding), and the break-away force
!> rises with the rate the applied force grows at.
module friction_law_lugre
   use friction_kinds, only: wp
   use friction_checks, only: config_checker
   use friction_law, only: sliding_law
   use friction_law_settings, only: law_group
   use friction_law_stribeck, only: stribeck_curve, stribeck_slope, check_stribeck
   implicit none
   private

   public :: lugre_law

   type, extends(sliding_law) :: lugre_law
   contains
      procedure :: check
      procedure :: force
      procedure :: state_count
      procedure :: state_rate
      procedure :: state_scale
      procedure :: steady_state
      procedure :: partials
   end type lugre_law

contains

   !> The Stribeck curve's parameters (F_c > 0: g is a divisor), σ0 > 0,
   !> σ1 >= 0.
   subroutine check(self, c)
      class(lugre_law), intent(in) :: self
      type(config_checker), intent(inout) :: c

      call c%positive(law_group, 'sigma0', self%p%sigma0, 'N/m')
      call c%finite(law_group, 'sigma0', self%p%sigma0)
      call c%nonnegative(law_group, 'sigma1', self%p%sigma1, 'N s/m')
      call c%finite(law_group, 'sigma1', self%p%sigma1)
      call c%positive(law_group, 'fc', self%p%fc, 'N; the bristles'' steady deflection g(v)/sigma0 needs it')
      call check_stribeck(self%p, c)
   end subroutine check

   pure real(wp) function force(self, v, z, normal, applied)
      class(lugre_law), intent(in) :: self
      real(wp), intent(in) :: v, normal, applied
      real(wp), intent(in) :: z(:)
      real(wp) :: rate(1)

      call self%state_rate(v, z, normal, rate)
      force = self%p%sigma0 * z(1) + self%p%sigma1 * rate(1) + self%p%sigma2 * v
   end function force

   pure integer function state_count(self)
      class(lugre_law), intent(in) :: self

      state_count = 1
   end function state_count

   pure subroutine state_rate(self, v, z, normal, rate)
      class(lugre_law), intent(in) :: self
      real(wp), intent(in) :: v, normal
      real(wp), intent(in) :: z(:)
      real(wp), intent(out) :: rate(:)

      rate(1) = v - self%p%sigma0 * abs(v) * z(1) / stribeck_curve(self%p, v)
   end subroutine state_rate

   pure subroutine state_scale(self, scale)
      class(lugre_law), intent(in) :: self
      real(wp), intent(out) :: scale(:)

      scale(1) = self%p%fs / self%p%sigma0
   end subroutine state_scale

   pure subroutine steady_state(self, v, normal, z)
      class(lugre_law), intent(in) :: self
      real(wp), intent(in) :: v, normal
      real(wp), intent(out) :: z(:)

      z(1) = 0.0_wp
      if (v /= 0.0_wp) z(1) = sign(stribeck_curve(self%p, v) / self%p%sigma0, v)
   end subroutine steady_state

   pure subroutine partials(self, v, z, normal, applied, dfdv, dfdz, dfda, dgdv, dgdz)
      class(lugre_law), intent(in) :: self
      real(wp), intent(in) :: v, normal, applied
      real(wp), intent(in) :: z(:)
      real(wp), intent(out) :: dfdv, dfdz(:), dfda, dgdv(:), dgdz(:, :)
      real(wp) :: g, dg

      g = stribeck_curve(self%p, v)
      dg = stribeck_slope(self%p, v)
      ! ż = v - σ0 z |v|/g: d(|v|/g)/dv = sgn(v)/g - |v| g'/g².
      dgdv(1) = 1.0_wp - self%p%sigma0 * z(1) * (sign(1.0_wp, v) / g - abs(v) * dg / (g * g))
      dgdz(1, 1) = -self%p%sigma0 * abs(v) / g
      dfdv = self%p%sigma1 * dgdv(1) + self%p%sigma2
      dfdz(1) = self%p%sigma0 + self%p%sigma1 * dgdz(1, 1)
      dfda = 0.0_wp
   end subroutine partials

end module friction_law_lugre
