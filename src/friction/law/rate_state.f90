!> Dieterich-Ruina rate-and-state friction, F = N μ(v, θ), θ (s) the
!> contact's age:
!>
!>   μ = a asinh( v/(2 v0) exp(Ψ/a) ),   Ψ = μ0 + b ln(v0 θ / D_c),
!>   aging law: θ' = 1 - |v| θ / D_c;   slip law: θ' = -(|v| θ/D_c) ln(|v| θ/D_c).
!>
!> The asinh form (Rice and Ben-Zion's regularization) is the classic
!> μ0 + a ln(v/v0) + b ln(v0 θ/D_c) to a relative a exp(-2L)/4 with
!> L = ln(|v|/(2 v0)) + Ψ/a (below rounding for L > 18, which the usual
!> parameters give down to v ~ 1e-20 v0), and is defined through v = 0.  In
!> steady sliding θ = D_c/|v| and μ = μ0 + (a - b) ln(v/v0): velocity
!> weakening when b > a.
module friction_law_rate_state
   use friction_kinds, only: wp
   use friction_strings, only: rtoa
   use friction_checks, only: config_checker
   use friction_law, only: sliding_law
   use friction_law_settings, only: law_group
   implicit none
   private

   public :: rate_state_law

   character(len=*), parameter :: evolution_names = "'aging', 'slip'"

   type, extends(sliding_law) :: rate_state_law
   contains
      procedure :: check
      procedure :: force
      procedure :: state_count
      procedure :: state_rate
      procedure :: state_name
      procedure :: state_unit
      procedure :: state_scale
      procedure :: steady_state
      procedure :: log_slip_floor
      procedure :: partials
      procedure :: coefficient
   end type rate_state_law

contains

   subroutine check(self, c)
      class(rate_state_law), intent(in) :: self
      type(config_checker), intent(inout) :: c

      call c%finite(law_group, 'mu0', self%p%mu0)
      call c%positive(law_group, 'a', self%p%a, 'the direct effect')
      call c%finite(law_group, 'a', self%p%a)
      call c%nonnegative(law_group, 'b', self%p%b, 'the evolution effect')
      call c%finite(law_group, 'b', self%p%b)
      call c%positive(law_group, 'dc', self%p%dc, 'm')
      call c%finite(law_group, 'dc', self%p%dc)
      call c%positive(law_group, 'v0', self%p%v0, 'm/s')
      call c%finite(law_group, 'v0', self%p%v0)
      if (self%p%evolution /= 'aging' .and. self%p%evolution /= 'slip') call c%reject(law_group, 'evolution', &
         & "'"//trim(self%p%evolution)//"'", 'unknown evolution law (known: '//evolution_names//')')
   end subroutine check

   !> μ(v, θ) and its partial derivatives ∂μ/∂v, ∂μ/∂θ.  With x = v/(2 v0)
   !> exp(Ψ/a) = sgn(v) e^L: asinh x for moderate L, sgn(v) (L + ln 2 +
   !> e^(-2L)/4) beyond (x would overflow first); ∂μ/∂v = a/(|v| √(1 +
   !> e^(-2L))), ∂μ/∂Ψ = sgn(v)/√(1 + e^(-2L)).
   pure subroutine coefficient(self, v, theta, mu, dmu_dv, dmu_dtheta)
      class(rate_state_law), intent(in) :: self
      real(wp), intent(in) :: v, theta
      real(wp), intent(out) :: mu, dmu_dv, dmu_dtheta
      real(wp) :: psi, big_l, q

      associate (p => self%p)
         psi = p%mu0 + p%b * log(p%v0 * max(theta, tiny(1.0_wp)) / p%dc)
         if (v == 0.0_wp) then
            mu = 0.0_wp
            dmu_dv = exp(min(psi / p%a, 700.0_wp)) / (2.0_wp * p%v0) * p%a
            dmu_dtheta = 0.0_wp
            return
         end if
         big_l = log(abs(v) / (2.0_wp * p%v0)) + psi / p%a
         if (big_l > 18.0_wp) then
            mu = sign(p%a * (big_l + log(2.0_wp) + 0.25_wp * exp(-2.0_wp * big_l)), v)
         else
            mu = p%a * asinh(sign(exp(big_l), v))
         end if
         q = 1.0_wp / sqrt(1.0_wp + exp(-2.0_wp * max(big_l, -300.0_wp)))
         dmu_dv = p%a * q / abs(v)
         dmu_dtheta = sign(q, v) * p%b / max(theta, tiny(1.0_wp))
      end associate
   end subroutine coefficient

   pure real(wp) function force(self, v, z, normal, applied)
      class(rate_state_law), intent(in) :: self
      real(wp), intent(in) :: v, normal, applied
      real(wp), intent(in) :: z(:)
      real(wp) :: mu, d1, d2

      call self%coefficient(v, z(1), mu, d1, d2)
      force = normal * mu
   end function force

   pure integer function state_count(self)
      class(rate_state_law), intent(in) :: self

      state_count = 1
   end function state_count

   pure subroutine state_rate(self, v, z, normal, rate)
      class(rate_state_law), intent(in) :: self
      real(wp), intent(in) :: v, normal
      real(wp), intent(in) :: z(:)
      real(wp), intent(out) :: rate(:)
      real(wp) :: q

      q = abs(v) * z(1) / self%p%dc
      if (self%p%evolution == 'slip') then
         rate(1) = 0.0_wp
         if (q > 0.0_wp) rate(1) = -q * log(q)
      else
         rate(1) = 1.0_wp - q
      end if
   end subroutine state_rate

   function state_name(self, i) result(name)
      class(rate_state_law), intent(in) :: self
      integer, intent(in) :: i
      character(len=:), allocatable :: name

      name = 'theta'
   end function state_name

   function state_unit(self, i) result(unit)
      class(rate_state_law), intent(in) :: self
      integer, intent(in) :: i
      character(len=:), allocatable :: unit

      unit = 's'
   end function state_unit

   pure subroutine state_scale(self, scale)
      class(rate_state_law), intent(in) :: self
      real(wp), intent(out) :: scale(:)

      scale(1) = self%p%dc / self%p%v0
   end subroutine state_scale

   !> θ = D_c/|v|; at rest the age grows without bound (the aging law's
   !> θ = t), and D_c/v0 stands for it.
   pure subroutine steady_state(self, v, normal, z)
      class(rate_state_law), intent(in) :: self
      real(wp), intent(in) :: v, normal
      real(wp), intent(out) :: z(:)

      z(1) = self%p%dc / self%p%v0
      if (v /= 0.0_wp) z(1) = self%p%dc / abs(v)
   end subroutine steady_state

   !> 2 v0 exp(-μ0/a): below it the asinh form turns linear in v (at the age
   !> D_c/v0 of steady sliding at v0; an older contact's floor is lower
   !> still), above it μ goes with a ln|v|, so an error δv of the slip rate
   !> costs a N δv/|v| of force at any |v|.
   pure real(wp) function log_slip_floor(self)
      class(rate_state_law), intent(in) :: self

      log_slip_floor = 2.0_wp * self%p%v0 * exp(min(-self%p%mu0 / self%p%a, 700.0_wp))
   end function log_slip_floor

   pure subroutine partials(self, v, z, normal, applied, dfdv, dfdz, dfda, dgdv, dgdz)
      class(rate_state_law), intent(in) :: self
      real(wp), intent(in) :: v, normal, applied
      real(wp), intent(in) :: z(:)
      real(wp), intent(out) :: dfdv, dfdz(:), dfda, dgdv(:), dgdz(:, :)
      real(wp) :: mu, dmu_dv, dmu_dtheta, q, dq

      call self%coefficient(v, z(1), mu, dmu_dv, dmu_dtheta)
      dfdv = normal * dmu_dv
      dfdz(1) = normal * dmu_dtheta
      dfda = 0.0_wp
      q = abs(v) * z(1) / self%p%dc
      if (self%p%evolution == 'slip') then
         dq = 0.0_wp
         if (q > 0.0_wp) dq = -(log(q) + 1.0_wp)   ! d(-q ln q)/dq
      else
         dq = -1.0_wp
      end if
      dgdv(1) = dq * sign(1.0_wp, v) * z(1) / self%p%dc
      if (v == 0.0_wp) dgdv(1) = 0.0_wp
      dgdz(1, 1) = dq * abs(v) / self%p%dc
   end subroutine partials

end module friction_law_rate_state
