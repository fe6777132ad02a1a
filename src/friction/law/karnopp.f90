!> Karnopp's law: a band |v| < Δv around zero velocity where the contact
!> holds whatever force the mechanism applies, up to F_s; outside it the
!> Stribeck curve:
!>
!>   F = clip(applied, -F_s, F_s)                     |v| < Δv,
!>   F = g(v) sgn v + σ2 v                            |v| >= Δv.
!>
!> In the band the body's acceleration is zero while the applied force stays
!> within F_s, so the velocity it entered with is kept, at the price of a
!> velocity error up to Δv.  The force jumps at the edges: the mechanisms
!> run them as located events (machine/band.f90, brake/band.f90).
module friction_law_karnopp
   use friction_kinds, only: wp
   use friction_checks, only: config_checker
   use friction_law, only: sliding_law
   use friction_law_settings, only: law_group
   use friction_law_stribeck, only: stribeck_curve, stribeck_slope, check_stribeck
   implicit none
   private

   public :: karnopp_law

   type, extends(sliding_law) :: karnopp_law
   contains
      procedure :: check
      procedure :: force
      procedure :: partials
      procedure :: band
   end type karnopp_law

contains

   subroutine check(self, c)
      class(karnopp_law), intent(in) :: self
      type(config_checker), intent(inout) :: c

      call check_stribeck(self%p, c)
      call c%positive(law_group, 'dv', self%p%dv, 'm/s; the half-width of the zero-velocity band')
      call c%finite(law_group, 'dv', self%p%dv)
   end subroutine check

   pure real(wp) function force(self, v, z, normal, applied)
      class(karnopp_law), intent(in) :: self
      real(wp), intent(in) :: v, normal, applied
      real(wp), intent(in) :: z(:)

      if (abs(v) < self%p%dv) then
         force = max(-self%p%fs, min(self%p%fs, applied))
      else
         force = sign(stribeck_curve(self%p, v), v) + self%p%sigma2 * v
      end if
   end function force

   pure subroutine partials(self, v, z, normal, applied, dfdv, dfdz, dfda, dgdv, dgdz)
      class(karnopp_law), intent(in) :: self
      real(wp), intent(in) :: v, normal, applied
      real(wp), intent(in) :: z(:)
      real(wp), intent(out) :: dfdv, dfdz(:), dfda, dgdv(:), dgdz(:, :)

      dfdv = 0.0_wp
      dfda = 0.0_wp
      if (abs(v) < self%p%dv) then
         if (abs(applied) < self%p%fs) dfda = 1.0_wp
      else
         dfdv = stribeck_slope(self%p, v) * sign(1.0_wp, v) + self%p%sigma2
      end if
   end subroutine partials

   pure subroutine band(self, half_width, limit)
      class(karnopp_law), intent(in) :: self
      real(wp), intent(out) :: half_width, limit

      half_width = self%p%dv
      limit = self%p%fs
   end subroutine band

end module friction_law_karnopp
