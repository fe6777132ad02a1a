!> The elasto-plastic law (Dupont, Hayward, Armstrong and Altpeter): LuGre's
!> bristle with a purely elastic range, so that small oscillations of the
!> applied force do not drift (no creep below the break-away deflection):
!>
!>   ż = v (1 - α(z, v) σ0 z sgn(v) / g(v)),   F = σ0 z + σ1 ż + σ2 v,
!>
!> α = 0 when z and v differ in sign or |z| <= z_ba; α = 1 when
!> |z| >= z_ss = g(v)/σ0; in between ½ sin(π (|z| - (z_ss + z_ba)/2) /
!> (z_ss - z_ba)) + ½.  Needs 0 <= z_ba < F_c/σ0, the least z_ss.  Its
!> partial derivatives are the abstract law's central differences.
module friction_law_elastoplastic
   use friction_kinds, only: wp, pi
   use friction_strings, only: rtoa
   use friction_checks, only: config_checker
   use friction_law, only: difference_partials
   use friction_law_lugre, only: lugre_law
   use friction_law_settings, only: law_group
   use friction_law_stribeck, only: stribeck_curve
   implicit none
   private

   public :: elastoplastic_law

   !> LuGre's force, state, scale and steady state; its own ż and checks,
   !> and the abstract law's difference partials for ż's switching share.
   type, extends(lugre_law) :: elastoplastic_law
   contains
      procedure :: check
      procedure :: state_rate
      procedure :: partials
   end type elastoplastic_law

contains

   subroutine check(self, c)
      class(elastoplastic_law), intent(in) :: self
      type(config_checker), intent(inout) :: c

      call self%lugre_law%check(c)
      if (c%failed()) return
      if (.not. (self%p%z_ba >= 0.0_wp .and. self%p%z_ba < self%p%fc / self%p%sigma0)) &
         & call c%reject(law_group, 'z_ba', rtoa(self%p%z_ba), 'must be >= 0 and below fc/sigma0 = ' &
         & //rtoa(self%p%fc / self%p%sigma0)//' m (the break-away deflection below the least steady one)', &
         & against=[character(len=16) :: law_group//'.fc', law_group//'.sigma0'])
   end subroutine check

   !> α(z, v): the share of the motion that is plastic.
   pure real(wp) function plastic_share(p_law, v, z) result(share)
      class(elastoplastic_law), intent(in) :: p_law
      real(wp), intent(in) :: v, z
      real(wp) :: z_ss, u

      share = 0.0_wp
      if (v == 0.0_wp .or. z == 0.0_wp .or. sign(1.0_wp, v) /= sign(1.0_wp, z)) return
      u = abs(z)
      z_ss = stribeck_curve(p_law%p, v) / p_law%p%sigma0
      if (u <= p_law%p%z_ba) return
      if (u >= z_ss) then
         share = 1.0_wp
      else
         share = 0.5_wp * sin(pi * (u - 0.5_wp * (z_ss + p_law%p%z_ba)) / (z_ss - p_law%p%z_ba)) + 0.5_wp
      end if
   end function plastic_share

   pure subroutine state_rate(self, v, z, normal, rate)
      class(elastoplastic_law), intent(in) :: self
      real(wp), intent(in) :: v, normal
      real(wp), intent(in) :: z(:)
      real(wp), intent(out) :: rate(:)

      rate(1) = v * (1.0_wp - plastic_share(self, v, z(1)) * self%p%sigma0 * abs(z(1)) / stribeck_curve(self%p, v))
   end subroutine state_rate

   pure subroutine partials(self, v, z, normal, applied, dfdv, dfdz, dfda, dgdv, dgdz)
      class(elastoplastic_law), intent(in) :: self
      real(wp), intent(in) :: v, normal, applied
      real(wp), intent(in) :: z(:)
      real(wp), intent(out) :: dfdv, dfdz(:), dfda, dgdv(:), dgdz(:, :)

      call difference_partials(self, v, z, normal, applied, dfdv, dfdz, dfda, dgdv, dgdz)
   end subroutine partials

end module friction_law_elastoplastic
