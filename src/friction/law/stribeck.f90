!> The Stribeck curve and the Stribeck (Popp-Stelter) law with exact stick:
!>
!>   F = [F_c + (F_s - F_c) exp(-|v/v_s|^δ)] sgn v + σ2 v   (v ≠ 0),
!>   |F| <= F_s in stick (v = 0).
!>
!> The curve g(v) = F_c + (F_s - F_c) exp(-|v/v_s|^δ) is also the steady
!> level of LuGre, the elasto-plastic law and Karnopp's law.
module friction_law_stribeck
   use friction_kinds, only: wp
   use friction_strings, only: rtoa
   use friction_checks, only: config_checker
   use friction_law, only: sliding_law, exact_stick_force
   use friction_law_settings, only: law_settings, law_group
   implicit none
   private

   public :: stribeck_law, stribeck_curve, stribeck_slope, check_stribeck

   type, extends(sliding_law) :: stribeck_law
   contains
      procedure :: check
      procedure :: force
      procedure :: partials
      procedure :: set_valued
      procedure :: static_force
      procedure :: slip_force
   end type stribeck_law

contains

   !> g(|v|) = F_c + (F_s - F_c) exp(-|v/v_s|^δ), N.
   pure real(wp) function stribeck_curve(p, v)
      type(law_settings), intent(in) :: p
      real(wp), intent(in) :: v

      stribeck_curve = p%fc + (p%fs - p%fc) * exp(-abs(v / p%vs)**p%exponent)
   end function stribeck_curve

   !> dg/dv (odd in v; 0 at v = 0 for δ > 1).
   pure real(wp) function stribeck_slope(p, v)
      type(law_settings), intent(in) :: p
      real(wp), intent(in) :: v
      real(wp) :: u

      u = abs(v / p%vs)
      if (u == 0.0_wp) then
         stribeck_slope = 0.0_wp
         if (p%exponent == 1.0_wp) stribeck_slope = -sign((p%fs - p%fc) / p%vs, v)
         return
      end if
      stribeck_slope = -(p%fs - p%fc) * exp(-u**p%exponent) * p%exponent * u**(p%exponent - 1.0_wp) &
         & * sign(1.0_wp, v) / p%vs
   end function stribeck_slope

   !> F_c >= 0, F_s >= F_c, v_s > 0, δ > 0 and σ2 >= 0.
   subroutine check_stribeck(p, c)
      type(law_settings), intent(in) :: p
      type(config_checker), intent(inout) :: c

      call c%nonnegative(law_group, 'fc', p%fc, 'N')
      if (.not. (p%fs >= p%fc)) call c%reject(law_group, 'fs', rtoa(p%fs), &
         & 'must be >= fc = '//rtoa(p%fc)//' (the static level is not below the Coulomb level)', &
         & against=[law_group//'.fc'])
      call c%positive(law_group, 'vs', p%vs, 'm/s')
      call c%positive(law_group, 'exponent', p%exponent, '1')
      call c%finite(law_group, 'exponent', p%exponent)
      call c%nonnegative(law_group, 'sigma2', p%sigma2, 'N s/m')
      call c%finite(law_group, 'fs', p%fs)
      call c%finite(law_group, 'sigma2', p%sigma2)
   end subroutine check_stribeck

   subroutine check(self, c)
      class(stribeck_law), intent(in) :: self
      type(config_checker), intent(inout) :: c

      call check_stribeck(self%p, c)
   end subroutine check

   pure real(wp) function force(self, v, z, normal, applied)
      class(stribeck_law), intent(in) :: self
      real(wp), intent(in) :: v, normal, applied
      real(wp), intent(in) :: z(:)

      force = exact_stick_force(self, v, z, normal, applied)
   end function force

   pure subroutine partials(self, v, z, normal, applied, dfdv, dfdz, dfda, dgdv, dgdz)
      class(stribeck_law), intent(in) :: self
      real(wp), intent(in) :: v, normal, applied
      real(wp), intent(in) :: z(:)
      real(wp), intent(out) :: dfdv, dfdz(:), dfda, dgdv(:), dgdz(:, :)

      dfdv = stribeck_slope(self%p, v) * sign(1.0_wp, v) + self%p%sigma2
      dfda = 0.0_wp
      if (v == 0.0_wp .and. abs(applied) < self%p%fs) dfda = 1.0_wp
   end subroutine partials

   pure logical function set_valued(self)
      class(stribeck_law), intent(in) :: self

      set_valued = .true.
   end function set_valued

   pure real(wp) function static_force(self, normal)
      class(stribeck_law), intent(in) :: self
      real(wp), intent(in) :: normal

      static_force = self%p%fs
   end function static_force

   pure real(wp) function slip_force(self, v, z, normal, s)
      class(stribeck_law), intent(in) :: self
      real(wp), intent(in) :: v, normal, s
      real(wp), intent(in) :: z(:)

      slip_force = s * stribeck_curve(self%p, v) + self%p%sigma2 * v
   end function slip_force

end module friction_law_stribeck
