!> Coulomb's law with exact stick and an optional viscous term:
!>
!>   F = μ N sgn v + σ2 v   (v ≠ 0),   |F| <= μs N in stick (v = 0).
!>
!> The switched brake's law (docs/physics.md) with a constant normal load.
module friction_law_coulomb
   use friction_kinds, only: wp
   use friction_strings, only: rtoa
   use friction_checks, only: config_checker
   use friction_law, only: sliding_law, exact_stick_force
   use friction_law_settings, only: law_group
   implicit none
   private

   public :: coulomb_law

   type, extends(sliding_law) :: coulomb_law
   contains
      procedure :: check
      procedure :: force
      procedure :: partials
      procedure :: set_valued
      procedure :: static_force
      procedure :: slip_force
   end type coulomb_law

contains

   !> 0 <= μ <= μs: a kinetic coefficient above the static one would stop
   !> every slip at once (the brake's switched model makes the same check).
   subroutine check(self, c)
      class(coulomb_law), intent(in) :: self
      type(config_checker), intent(inout) :: c

      call c%nonnegative(law_group, 'mu', self%p%mu, 'kinetic friction coefficient')
      call c%finite(law_group, 'mu', self%p%mu)
      call c%finite(law_group, 'mu_s', self%p%mu_s)
      if (.not. (self%p%mu_s >= self%p%mu)) call c%reject(law_group, 'mu_s', rtoa(self%p%mu_s), &
         & 'must be >= mu = '//rtoa(self%p%mu)//' (exact stick needs a static coefficient not below the kinetic one)', &
         & against=[law_group//'.mu'])
      call c%nonnegative(law_group, 'sigma2', self%p%sigma2, 'N s/m')
      call c%finite(law_group, 'sigma2', self%p%sigma2)
   end subroutine check

   pure real(wp) function force(self, v, z, normal, applied)
      class(coulomb_law), intent(in) :: self
      real(wp), intent(in) :: v, normal, applied
      real(wp), intent(in) :: z(:)

      force = exact_stick_force(self, v, z, normal, applied)
   end function force

   pure subroutine partials(self, v, z, normal, applied, dfdv, dfdz, dfda, dgdv, dgdz)
      class(coulomb_law), intent(in) :: self
      real(wp), intent(in) :: v, normal, applied
      real(wp), intent(in) :: z(:)
      real(wp), intent(out) :: dfdv, dfdz(:), dfda, dgdv(:), dgdz(:, :)

      dfdv = self%p%sigma2
      dfda = 0.0_wp
      if (v == 0.0_wp .and. abs(applied) < self%p%mu_s * normal) dfda = 1.0_wp
   end subroutine partials

   pure logical function set_valued(self)
      class(coulomb_law), intent(in) :: self

      set_valued = .true.
   end function set_valued

   pure real(wp) function static_force(self, normal)
      class(coulomb_law), intent(in) :: self
      real(wp), intent(in) :: normal

      static_force = self%p%mu_s * normal
   end function static_force

   pure real(wp) function slip_force(self, v, z, normal, s)
      class(coulomb_law), intent(in) :: self
      real(wp), intent(in) :: v, normal, s
      real(wp), intent(in) :: z(:)

      slip_force = s * self%p%mu * normal + self%p%sigma2 * v
   end function slip_force

end module friction_law_coulomb
