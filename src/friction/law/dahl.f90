!> Dahl's law: friction as the stress of a deflected contact whose
!> stiffness falls as the force approaches the Coulomb level.  With the
!> deflection z (m) as the state:
!>
!>   F = σ0 z,   ż = v |1 - σ0 z sgn(v)/F_c|^α sgn(1 - σ0 z sgn(v)/F_c).
!>
!> The law depends on the path only (rate-independent): dF/dx = σ0 (1 -
!> F sgn(v)/F_c)^α.  α >= 1 keeps the rate Lipschitz in z, so a path has one
!> solution.  For α = 1 a displacement oscillating between ±A gives the
!> closed loop whose tips are ±F_c tanh(σ0 A/F_c) (docs/laws.md).
module friction_law_dahl
   use friction_kinds, only: wp
   use friction_strings, only: rtoa
   use friction_checks, only: config_checker
   use friction_law, only: sliding_law
   use friction_law_settings, only: law_group
   implicit none
   private

   public :: dahl_law

   type, extends(sliding_law) :: dahl_law
   contains
      procedure :: check
      procedure :: force
      procedure :: state_count
      procedure :: state_rate
      procedure :: state_scale
      procedure :: steady_state
      procedure :: partials
   end type dahl_law

contains

   subroutine check(self, c)
      class(dahl_law), intent(in) :: self
      type(config_checker), intent(inout) :: c

      call c%positive(law_group, 'sigma0', self%p%sigma0, 'N/m')
      call c%finite(law_group, 'sigma0', self%p%sigma0)
      call c%positive(law_group, 'fc', self%p%fc, 'N')
      call c%finite(law_group, 'fc', self%p%fc)
      if (.not. (self%p%alpha >= 1.0_wp .and. self%p%alpha <= huge(1.0_wp))) call c%reject(law_group, 'alpha', &
         & rtoa(self%p%alpha), 'must be >= 1 (below, the deflection''s rate is not Lipschitz at the Coulomb level)')
   end subroutine check

   pure real(wp) function force(self, v, z, normal, applied)
      class(dahl_law), intent(in) :: self
      real(wp), intent(in) :: v, normal, applied
      real(wp), intent(in) :: z(:)

      force = self%p%sigma0 * z(1)
   end function force

   pure integer function state_count(self)
      class(dahl_law), intent(in) :: self

      state_count = 1
   end function state_count

   pure subroutine state_rate(self, v, z, normal, rate)
      class(dahl_law), intent(in) :: self
      real(wp), intent(in) :: v, normal
      real(wp), intent(in) :: z(:)
      real(wp), intent(out) :: rate(:)
      real(wp) :: u

      u = 1.0_wp - self%p%sigma0 * z(1) * sign(1.0_wp, v) / self%p%fc
      if (self%p%alpha == 1.0_wp) then
         rate(1) = v * u
      else
         rate(1) = v * sign(abs(u)**self%p%alpha, u)
      end if
   end subroutine state_rate

   pure subroutine state_scale(self, scale)
      class(dahl_law), intent(in) :: self
      real(wp), intent(out) :: scale(:)

      scale(1) = self%p%fc / self%p%sigma0
   end subroutine state_scale

   pure subroutine steady_state(self, v, normal, z)
      class(dahl_law), intent(in) :: self
      real(wp), intent(in) :: v, normal
      real(wp), intent(out) :: z(:)

      z(1) = 0.0_wp
      if (v /= 0.0_wp) z(1) = sign(self%p%fc / self%p%sigma0, v)
   end subroutine steady_state

   pure subroutine partials(self, v, z, normal, applied, dfdv, dfdz, dfda, dgdv, dgdz)
      class(dahl_law), intent(in) :: self
      real(wp), intent(in) :: v, normal, applied
      real(wp), intent(in) :: z(:)
      real(wp), intent(out) :: dfdv, dfdz(:), dfda, dgdv(:), dgdz(:, :)
      real(wp) :: u, s

      s = sign(1.0_wp, v)
      u = 1.0_wp - self%p%sigma0 * z(1) * s / self%p%fc
      dfdv = 0.0_wp
      dfdz(1) = self%p%sigma0
      dfda = 0.0_wp
      ! ż = v φ(u) with φ(u) = |u|^α sgn u, φ' = α |u|^(α-1); u depends on sgn v only.
      dgdv(1) = sign(abs(u)**self%p%alpha, u)
      dgdz(1, 1) = -abs(v) * self%p%alpha * abs(u)**(self%p%alpha - 1.0_wp) * self%p%sigma0 / self%p%fc
   end subroutine partials

end module friction_law_dahl
