!> The Generalized Maxwell-Slip law (Al-Bender, Lampaert and Swevers, 2005):
!> N elements in parallel, element i a spring of stiffness k_i whose far end
!> slides once its force reaches its share w_i of the Stribeck curve g(v).
!> The states are the springs' deflections z_i (m); with u_i = k_i z_i sgn(v)/
!> (w_i g(v)) the element's force in the direction of motion over its limit,
!>
!>   F = Σ k_i z_i + σ2 v,
!>   ż_i = v                            (sticks: u_i < 1),
!>   ż_i = (C/k_i) sgn(v) (1 - u_i)     (slips: u_i >= 1),
!>
!> the slip law being the paper's dF_i/dt = C (sgn v - F_i/(w_i g(v))) in
!> terms of the deflection; C (N/s) is how fast a slipping element's force
!> approaches its limit.  The weights add up to 1, so steady sliding gives
!> F = g(v) sgn v + σ2 v.  Whether an element slips is read from its state
!> (the law is an ODE); the paper keeps an element slipping until the
!> velocity reverses, which differs only where the limit rises during a slip
!> (sliding that slows through the Stribeck curve): here the element then
!> follows the risen limit from just below it, there it approaches it at the
!> rate C.  A sticking element's rate falls from v to 0 over the last
!> `entry` of its way to the limit, so that the rate is continuous there.
!> With g constant the elements are Prandtl's elastic-perfectly plastic
!> elements: pre-sliding hysteresis with nonlocal memory, reversal branches
!> that are the virgin curve stretched twice (Masing's rule).
module friction_law_gms
   use friction_kinds, only: wp
   use friction_strings, only: rtoa, itoa
   use friction_checks, only: config_checker
   use friction_law, only: sliding_law
   use friction_law_settings, only: law_group, max_gms_elements
   use friction_law_stribeck, only: stribeck_curve, stribeck_slope, check_stribeck
   implicit none
   private

   public :: gms_law

   !> The fraction of its limit over which a sticking element's rate falls to
   !> the slip rate (0 at the limit): the force differs from switching
   !> outright by at most this fraction of the element's limit, and only
   !> over a displacement of this fraction of its break-away deflection.
   real(wp), parameter :: entry = 1.0e-5_wp

   type, extends(sliding_law) :: gms_law
   contains
      procedure :: check
      procedure :: force
      procedure :: state_count
      procedure :: state_rate
      procedure :: state_name
      procedure :: state_scale
      procedure :: steady_state
      procedure :: partials
      procedure :: kink_count
      procedure :: kinks
   end type gms_law

contains

   !> 1 <= N <= max_gms_elements, each k_i > 0 and w_i > 0, the weights
   !> adding up to 1, C > 0, F_c > 0 (an element's limit w_i g divides) and
   !> the Stribeck curve's.
   subroutine check(self, c)
      class(gms_law), intent(in) :: self
      type(config_checker), intent(inout) :: c
      integer :: i, n
      character(len=:), allocatable :: shown

      n = self%p%elements
      if (n < 1 .or. n > max_gms_elements) then
         call c%reject(law_group, 'elements', itoa(n), 'must be 1 to '//itoa(max_gms_elements))
         return
      end if
      do i = 1, n
         if (.not. (self%p%element_stiffness(i) > 0.0_wp .and. self%p%element_stiffness(i) <= huge(1.0_wp))) &
            & call c%reject(law_group, 'element_stiffness', rtoa(self%p%element_stiffness(i)), &
            & 'must be a finite number > 0 (N/m) for each of the '//itoa(n)//' elements', i, &
            & against=[law_group//'.elements'])
         if (.not. (self%p%element_weight(i) > 0.0_wp .and. self%p%element_weight(i) <= 1.0_wp)) &
            & call c%reject(law_group, 'element_weight', rtoa(self%p%element_weight(i)), &
            & 'must be > 0 and <= 1 for each of the '//itoa(n)//' elements', i, against=[law_group//'.elements'])
      end do
      if (c%failed()) return
      ! The weights share out the Stribeck curve: the steady force is g(v) only if they add up to 1.
      if (abs(sum(self%p%element_weight(1:n)) - 1.0_wp) > 1.0e-9_wp) then
         shown = rtoa(self%p%element_weight(1))
         do i = 2, n
            shown = shown//', '//rtoa(self%p%element_weight(i))
         end do
         call c%reject(law_group, 'element_weight', shown, 'the '//itoa(n)//' weights add up to ' &
            & //rtoa(sum(self%p%element_weight(1:n)))//', not 1 (they share out the Stribeck curve)', &
            & against=[law_group//'.elements'])
      end if
      call c%positive(law_group, 'attraction', self%p%attraction, 'N/s')
      call c%finite(law_group, 'attraction', self%p%attraction)
      call c%positive(law_group, 'fc', self%p%fc, 'N; each element''s limit w_i g(v) divides its slip rate')
      call check_stribeck(self%p, c)
   end subroutine check

   pure real(wp) function force(self, v, z, normal, applied)
      class(gms_law), intent(in) :: self
      real(wp), intent(in) :: v, normal, applied
      real(wp), intent(in) :: z(:)
      integer :: n

      n = self%p%elements
      force = sum(self%p%element_stiffness(1:n) * z(1:n)) + self%p%sigma2 * v
   end function force

   pure integer function state_count(self)
      class(gms_law), intent(in) :: self

      state_count = self%p%elements
   end function state_count

   !> An element slips when its force in the direction of motion has reached
   !> its limit w_i g(v); at rest (v = 0) every element sticks.  In the last
   !> `entry` of the way to its limit a sticking element's rate falls
   !> linearly from v to 0, the slip rate at the limit: the rate is
   !> continuous, so that a limit rising during a slip (sliding slowing
   !> through the Stribeck curve) holds the element just below it instead of
   !> switching it between stick and slip at every step.
   pure subroutine state_rate(self, v, z, normal, rate)
      class(gms_law), intent(in) :: self
      real(wp), intent(in) :: v, normal
      real(wp), intent(in) :: z(:)
      real(wp), intent(out) :: rate(:)
      real(wp) :: g, s, k, u
      integer :: i

      g = stribeck_curve(self%p, v)
      s = sign(1.0_wp, v)
      do i = 1, self%p%elements
         k = self%p%element_stiffness(i)
         ! u: the element's force in the direction of motion, in units of its limit.
         u = k * z(i) * s / (self%p%element_weight(i) * g)
         if (v == 0.0_wp .or. u < 1.0_wp - entry) then
            rate(i) = v
         else
            rate(i) = s * (1.0_wp - u) * pull(abs(v), self%p%attraction / k, u)
         end if
      end do
   end subroutine state_rate

   function state_name(self, i) result(name)
      class(gms_law), intent(in) :: self
      integer, intent(in) :: i
      character(len=:), allocatable :: name

      name = 'z'//itoa(i)
   end function state_name

   !> Each element's deflection at its static limit, w_i F_s/k_i.
   pure subroutine state_scale(self, scale)
      class(gms_law), intent(in) :: self
      real(wp), intent(out) :: scale(:)
      integer :: n

      n = self%p%elements
      scale(1:n) = self%p%element_weight(1:n) * self%p%fs / self%p%element_stiffness(1:n)
   end subroutine state_scale

   !> Every element at its limit: k_i z_i = w_i g(v) sgn v.
   pure subroutine steady_state(self, v, normal, z)
      class(gms_law), intent(in) :: self
      real(wp), intent(in) :: v, normal
      real(wp), intent(out) :: z(:)
      integer :: n

      n = self%p%elements
      z(1:n) = 0.0_wp
      if (v /= 0.0_wp) z(1:n) = sign(1.0_wp, v) * self%p%element_weight(1:n) * stribeck_curve(self%p, v) &
         & / self%p%element_stiffness(1:n)
   end subroutine steady_state

   pure subroutine partials(self, v, z, normal, applied, dfdv, dfdz, dfda, dgdv, dgdz)
      class(gms_law), intent(in) :: self
      real(wp), intent(in) :: v, normal, applied
      real(wp), intent(in) :: z(:)
      real(wp), intent(out) :: dfdv, dfdz(:), dfda, dgdv(:), dgdz(:, :)
      real(wp) :: g, dg, s, k, w, u, a, dadu, dudz, dudv
      integer :: i, n

      n = self%p%elements
      g = stribeck_curve(self%p, v)
      dg = stribeck_slope(self%p, v)
      s = sign(1.0_wp, v)
      dfdv = self%p%sigma2
      dfdz(1:n) = self%p%element_stiffness(1:n)
      dfda = 0.0_wp
      dgdz(1:n, 1:n) = 0.0_wp
      do i = 1, n
         k = self%p%element_stiffness(i)
         w = self%p%element_weight(i)
         u = k * z(i) * s / (w * g)
         if (v == 0.0_wp .or. u < 1.0_wp - entry) then
            dgdv(i) = 1.0_wp
         else
            ! ż = s (1 - u) a(|v|, u), ∂u/∂z = k s/(w g), ∂u/∂v = -k z s g'/(w g²).
            a = pull(abs(v), self%p%attraction / k, u)
            dadu = pull_slope(abs(v), self%p%attraction / k, u)
            dudz = k * s / (w * g)
            dudv = -k * z(i) * s * dg / (w * g * g)
            dgdz(i, i) = s * (-a + (1.0_wp - u) * dadu) * dudz
            dgdv(i) = s * (-a + (1.0_wp - u) * dadu) * dudv
            dgdv(i) = dgdv(i) + (1.0_wp - u) * blend(u) / entry   ! (∂a/∂|v| = blend/ε, ∂|v|/∂v = s)
         end if
      end do
   end subroutine partials

   !> The edges of each element's switch band, |u_i| = 1 - ε and 1 + ε
   !> (|u_i|: continuous through v = 0), where ∂ż_i/∂z_i jumps between 0,
   !> -|v|/(ε z_lim) and +|v|/(ε z_lim).  Not u_i = 1, where J is continuous
   !> (the factor 1 - u_i kills the kink of the pull) and where steady
   !> sliding sits to rounding: an event there would chatter.
   pure integer function kink_count(self)
      class(gms_law), intent(in) :: self

      kink_count = 2 * self%p%elements
   end function kink_count

   pure subroutine kinks(self, v, z, normal, g)
      class(gms_law), intent(in) :: self
      real(wp), intent(in) :: v, normal
      real(wp), intent(in) :: z(:)
      real(wp), intent(out) :: g(:)
      real(wp) :: limit, u
      integer :: i, n

      n = self%p%elements
      limit = stribeck_curve(self%p, v)
      do i = 1, n
         u = abs(self%p%element_stiffness(i) * z(i)) / (self%p%element_weight(i) * limit)
         g(i) = u - (1.0_wp - entry)
         g(n + i) = u - (1.0_wp + entry)
      end do
   end subroutine kinks

   !> The factor a of the rate ż = sgn(v) (1 - u) a near and beyond the
   !> limit: |v|/ε from the entry to the limit (the rate falls linearly from
   !> v to 0), the slip's C/k beyond 1 + ε, linear in u between, so that the
   !> rate is continuous and an element a step carries past its limit is
   !> pulled back at once, not at the slow rate C.
   pure real(wp) function pull(speed, slip, u)
      real(wp), intent(in) :: speed, slip, u

      pull = slip + (speed / entry - slip) * blend(u)
   end function pull

   !> ∂a/∂u.
   pure real(wp) function pull_slope(speed, slip, u)
      real(wp), intent(in) :: speed, slip, u

      pull_slope = 0.0_wp
      if (u > 1.0_wp .and. u < 1.0_wp + entry) pull_slope = -(speed / entry - slip) / entry
   end function pull_slope

   !> 1 up to the limit, 0 beyond 1 + ε, linear between.
   pure real(wp) function blend(u)
      real(wp), intent(in) :: u

      blend = max(0.0_wp, min(1.0_wp, (1.0_wp + entry - u) / entry))
   end function blend

end module friction_law_gms
