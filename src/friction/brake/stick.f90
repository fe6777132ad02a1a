!> The stick phase of the switched model in closed form.
!>
!> While the block sticks to the belt (Eq. 6) x' = v'_dr exactly, so x is
!> prescribed, x(τ) = x0 + v'_dr u with u = τ - τ0, and the crank obeys the
!> linear ξ y'' + κ y = x(τ) (Eq. 10, second line).  Its solution is exact:
!>
!>   y(u) = x(u)/κ + A cos(ω u) + B sin(ω u),   ω = √(κ/ξ),
!>   A = y0 - x0/κ,   B = (y0' - v'_dr/κ)/ω,
!>
!> since x'' = 0 makes x/κ a particular solution.  No integrator is
!> involved, so the stick phase costs nothing and has no truncation error.
!>
!> Stick ends when the elastic force |2x - y| reaches μs N' (Eq. 5; with
!> a law of &law, its static limit slope N' + level), and
!> N' must stay positive.  Each of the three functions
!>   h1 = μs N' - (2x - y),  h2 = μs N' + (2x - y),  h3 = N'
!> is c0 + c1 u + (trigonometric part of amplitude a_k) along the stick, so
!> |h_k''| <= a_k ω².  The first zero is found by subdivision that excludes
!> an interval when min(h(a), h(b)) - a_k ω² (b - a)²/8 > 0 (h cannot dip
!> below its chord by more than that), and bisection once a zero is
!> bracketed, down to adjacent floating-point times: the end of stick is
!> exact to rounding, not to a tolerance.
module friction_brake_stick
   use friction_kinds, only: wp, pi
   use friction_brake_params, only: brake_parameters
   implicit none
   private

   public :: stick_tangent, stick_motion, stick_end_force_positive, stick_end_force_negative, stick_end_lift_off

   !> Which limit ended the stick.
   integer, parameter :: stick_end_force_positive = 1  !! 2x - y reached +μs N'
   integer, parameter :: stick_end_force_negative = 2  !! 2x - y reached -μs N'
   integer, parameter :: stick_end_lift_off = 3        !! N' reached 0

   type :: stick_motion
      type(brake_parameters) :: p
      real(wp) :: t0 = 0.0_wp, x0 = 0.0_wp
      real(wp) :: a = 0.0_wp, b = 0.0_wp     !! A, B of the crank's free oscillation
      real(wp) :: omega = 1.0_wp
      !> The static limit slope N' + level: μs N' unless start is told otherwise.
      real(wp) :: slope = 0.0_wp, level = 0.0_wp
   contains
      procedure :: start
      procedure :: state_at
      procedure :: find_end
      procedure, private :: limit_value
   end type stick_motion

contains

   !> Stick from time t0 and state y = (x, v, y, w); v is taken as v'_dr.
   !> The static limit is μs N', or slope N' + level when given.
   pure subroutine start(self, p, t0, y, slope, level)
      class(stick_motion), intent(inout) :: self
      type(brake_parameters), intent(in) :: p
      real(wp), intent(in) :: t0, y(4)
      real(wp), intent(in), optional :: slope, level

      self%p = p
      self%slope = p%mu_s
      self%level = 0.0_wp
      if (present(slope)) self%slope = slope
      if (present(level)) self%level = level
      self%t0 = t0
      self%x0 = y(1)
      self%omega = sqrt(p%kappa / p%xi)
      self%a = y(3) - y(1) / p%kappa
      self%b = (y(4) - p%v_dr / p%kappa) / self%omega
   end subroutine start

   !> The state (x, v, y, w) at time t, with v = v'_dr exactly.
   pure function state_at(self, t) result(y)
      class(stick_motion), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp) :: y(4)
      real(wp) :: u, c, s

      u = t - self%t0
      c = cos(self%omega * u)
      s = sin(self%omega * u)
      y(1) = self%x0 + self%p%v_dr * u
      y(2) = self%p%v_dr
      y(3) = y(1) / self%p%kappa + self%a * c + self%b * s
      y(4) = self%p%v_dr / self%p%kappa + self%omega * (self%b * c - self%a * s)
   end function state_at

   !> The derivative of the stick flow over a time u: the state after u with
   !> respect to the state before, (x, y, w) by the closed form above and
   !> the velocity pinned to the belt (its row and column 0).  It depends on
   !> u only, so pieces of one stick compose.
   pure function stick_tangent(p, u) result(m)
      type(brake_parameters), intent(in) :: p
      real(wp), intent(in) :: u
      real(wp) :: m(4, 4)
      real(wp) :: omega, c, s

      omega = sqrt(p%kappa / p%xi)
      c = cos(omega * u)
      s = sin(omega * u)
      m = 0.0_wp
      m(1, 1) = 1.0_wp
      m(3, 1) = (1.0_wp - c) / p%kappa
      m(3, 3) = c
      m(3, 4) = s / omega
      m(4, 1) = omega * s / p%kappa
      m(4, 3) = -omega * s
      m(4, 4) = c
   end function stick_tangent

   !> h_k at time t, and its time derivative.
   pure subroutine limit_value(self, k, t, h, dh)
      class(stick_motion), intent(in) :: self
      integer, intent(in) :: k
      real(wp), intent(in) :: t
      real(wp), intent(out) :: h, dh
      real(wp) :: y(4), normal, force, d_normal, d_force

      y = self%state_at(t)
      associate (p => self%p)
         normal = (1.0_wp - p%kappa) * y(3) + p%g_prime
         force = 2.0_wp * y(1) - y(3)
         d_normal = (1.0_wp - p%kappa) * y(4)
         d_force = 2.0_wp * y(2) - y(4)
         ! (The level apart when it is 0: the switched model's limit as it always was, bit for bit.)
         select case (k)
         case (stick_end_force_positive)
            if (self%level == 0.0_wp) then
               h = self%slope * normal - force
            else
               h = self%slope * normal + (self%level - force)
            end if
            dh = self%slope * d_normal - d_force
         case (stick_end_force_negative)
            if (self%level == 0.0_wp) then
               h = self%slope * normal + force
            else
               h = self%slope * normal + (self%level + force)
            end if
            dh = self%slope * d_normal + d_force
         case default
            h = normal
            dh = d_normal
         end select
      end associate
   end subroutine limit_value

   !> The first time in (t0, t_max] at which a stick limit is reached: found,
   !> its time t_end (the first representable time at or beyond the limit)
   !> and which limit (stick_end_*).  A limit already reached at t0 with h
   !> decreasing ends the stick at t0.
   pure subroutine find_end(self, t_from, t_max, found, t_end, which)
      class(stick_motion), intent(in) :: self
      real(wp), intent(in) :: t_from, t_max
      logical, intent(out) :: found
      real(wp), intent(out) :: t_end
      integer, intent(out) :: which
      real(wp) :: curvature, segment, t_root, amplitude
      integer :: k
      logical :: hit

      found = .false.
      t_end = t_max
      which = 0
      amplitude = hypot(self%a, self%b) * self%omega**2
      ! A few segments per period of the crank's free oscillation.
      segment = 2.0_wp * pi / self%omega / 8.0_wp
      do k = 1, 3
         associate (p => self%p)
            select case (k)
            case (stick_end_force_positive)
               curvature = abs(1.0_wp + self%slope * (1.0_wp - p%kappa)) * amplitude
            case (stick_end_force_negative)
               curvature = abs(self%slope * (1.0_wp - p%kappa) - 1.0_wp) * amplitude
            case default
               curvature = abs(1.0_wp - p%kappa) * amplitude
            end select
         end associate
         call first_zero(self, k, t_from, min(t_max, t_end), curvature, segment, hit, t_root)
         if (hit .and. (.not. found .or. t_root < t_end)) then
            found = .true.
            t_end = t_root
            which = k
         end if
      end do
   end subroutine find_end

   !> First zero of h_k in [t_from, t_max] (see the module comment).
   pure subroutine first_zero(self, k, t_from, t_max, curvature, segment, found, t_root)
      type(stick_motion), intent(in) :: self
      integer, intent(in) :: k
      real(wp), intent(in) :: t_from, t_max, curvature, segment
      logical, intent(out) :: found
      real(wp), intent(out) :: t_root
      real(wp) :: a, b, ha, hb, dh
      integer, parameter :: max_depth = 80
      ! Explicit stack of intervals still to examine, earliest on top.
      real(wp) :: stack_a(max_depth), stack_b(max_depth), stack_ha(max_depth), stack_hb(max_depth)
      integer :: top

      found = .false.
      t_root = t_max
      call self%limit_value(k, t_from, ha, dh)
      if (ha < 0.0_wp .or. (ha == 0.0_wp .and. dh < 0.0_wp)) then
         found = .true.
         t_root = t_from
         return
      end if
      a = t_from
      do while (a < t_max)
         b = min(a + segment, t_max)
         call self%limit_value(k, b, hb, dh)
         top = 1
         stack_a(1) = a
         stack_b(1) = b
         stack_ha(1) = ha
         stack_hb(1) = hb
         do while (top > 0)
            associate (ia => stack_a(top), ib => stack_b(top), iha => stack_ha(top), ihb => stack_hb(top))
               if (ihb <= 0.0_wp .and. ib - ia <= 2.0_wp * spacing(abs(ib))) then
                  ! Bracketed to adjacent times, and nothing earlier: the zero.
                  found = .true.
                  t_root = ib
                  return
               end if
               if (ihb > 0.0_wp .and. (min(iha, ihb) - curvature * (ib - ia)**2 / 8.0_wp > 0.0_wp &
                  & .or. ib - ia <= 2.0_wp * spacing(abs(ib)))) then
                  ! No zero here (a tangency narrower than rounding counts as none).
                  top = top - 1
                  cycle
               end if
            end associate
            if (top >= max_depth - 1) then
               ! Cannot happen for intervals that halve from a finite segment
               ! down to adjacent doubles; give up on this interval safely.
               top = top - 1
               cycle
            end if
            ! Split: the right half goes below the left one on the stack.
            block
               real(wp) :: m, hm, ia, ib, iha, ihb
               ia = stack_a(top)
               ib = stack_b(top)
               iha = stack_ha(top)
               ihb = stack_hb(top)
               m = 0.5_wp * (ia + ib)
               call self%limit_value(k, m, hm, dh)
               stack_a(top) = m
               stack_b(top) = ib
               stack_ha(top) = hm
               stack_hb(top) = ihb
               top = top + 1
               stack_a(top) = ia
               stack_b(top) = m
               stack_ha(top) = iha
               stack_hb(top) = hm
            end block
         end do
         a = b
         ha = hb
      end do
   end subroutine first_zero

end module friction_brake_stick
