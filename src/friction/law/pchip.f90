!> Monotone piecewise cubic Hermite interpolation (Fritsch and Carlson's
!> shape-preserving slopes, in Fritsch and Butland's weighted harmonic mean
!> form, with the three-point end slopes limited to keep monotone data
!> monotone): the interpolant never overshoots the data, so a tabulated
!> friction curve keeps the sign of its slope between the rows.  The same
!> slopes as SciPy's PchipInterpolator (the tabulated law's test compares).
module friction_law_pchip
   use friction_kinds, only: wp
   implicit none
   private

   public :: pchip_curve

   type :: pchip_curve
      real(wp), allocatable :: x(:), y(:), d(:)   !! nodes, values, slopes
   contains
      procedure :: build
      procedure :: value
      procedure :: slope
      procedure, private :: locate
   end type pchip_curve

contains

   !> The curve through (x_i, y_i), x strictly increasing, at least 2 nodes.
   pure subroutine build(self, x, y)
      class(pchip_curve), intent(inout) :: self
      real(wp), intent(in) :: x(:), y(:)
      real(wp), allocatable :: h(:), m(:)
      real(wp) :: w1, w2
      integer :: n, k

      n = size(x)
      self%x = x
      self%y = y
      allocate (self%d(n), h(n - 1), m(n - 1))
      h = x(2:n) - x(1:n - 1)
      m = (y(2:n) - y(1:n - 1)) / h
      if (n == 2) then
         self%d = m(1)
         return
      end if
      do k = 2, n - 1
         if (m(k - 1) * m(k) <= 0.0_wp) then
            self%d(k) = 0.0_wp   ! an extremum or a flat stretch: a flat tangent keeps the shape
         else
            w1 = 2.0_wp * h(k) + h(k - 1)
            w2 = h(k) + 2.0_wp * h(k - 1)
            self%d(k) = (w1 + w2) / (w1 / m(k - 1) + w2 / m(k))
         end if
      end do
      self%d(1) = end_slope(h(1), h(2), m(1), m(2))
      self%d(n) = end_slope(h(n - 1), h(n - 2), m(n - 1), m(n - 2))
   end subroutine build

   !> The non-centred three-point slope at an end, limited: 0 when its sign
   !> differs from the end interval's secant, three secants at most where
   !> the data turn.
   pure real(wp) function end_slope(h0, h1, m0, m1) result(d)
      real(wp), intent(in) :: h0, h1, m0, m1

      d = ((2.0_wp * h0 + h1) * m0 - h0 * m1) / (h0 + h1)
      if (signum(d) /= signum(m0)) then
         d = 0.0_wp
      else if (signum(m0) /= signum(m1) .and. abs(d) > abs(3.0_wp * m0)) then
         d = 3.0_wp * m0
      end if
   end function end_slope

   !> -1, 0 or 1 (zero has no sign here, unlike the intrinsic's).
   pure real(wp) function signum(x)
      real(wp), intent(in) :: x

      signum = merge(sign(1.0_wp, x), 0.0_wp, x /= 0.0_wp)
   end function signum

   !> The interval [x_k, x_k+1] that holds t (the first or last for t outside).
   pure integer function locate(self, t) result(k)
      class(pchip_curve), intent(in) :: self
      real(wp), intent(in) :: t
      integer :: lo, hi, mid

      lo = 1
      hi = size(self%x)
      do while (hi - lo > 1)
         mid = (lo + hi) / 2
         if (t >= self%x(mid)) then
            lo = mid
         else
            hi = mid
         end if
      end do
      k = lo
   end function locate

   !> The cubic on its interval (extended beyond the ends: callers clamp).
   pure real(wp) function value(self, t)
      class(pchip_curve), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp) :: h, s, h00, h10, h01, h11
      integer :: k

      k = self%locate(t)
      h = self%x(k + 1) - self%x(k)
      s = (t - self%x(k)) / h
      h00 = (1.0_wp + 2.0_wp * s) * (1.0_wp - s)**2
      h10 = s * (1.0_wp - s)**2
      h01 = s * s * (3.0_wp - 2.0_wp * s)
      h11 = s * s * (s - 1.0_wp)
      value = h00 * self%y(k) + h * h10 * self%d(k) + h01 * self%y(k + 1) + h * h11 * self%d(k + 1)
   end function value

   pure real(wp) function slope(self, t)
      class(pchip_curve), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp) :: h, s
      integer :: k

      k = self%locate(t)
      h = self%x(k + 1) - self%x(k)
      s = (t - self%x(k)) / h
      slope = (6.0_wp * s * (s - 1.0_wp)) * (self%y(k) - self%y(k + 1)) / h &
         & + (1.0_wp - s) * (1.0_wp - 3.0_wp * s) * self%d(k) + s * (3.0_wp * s - 2.0_wp) * self%d(k + 1)
   end function slope

end module friction_law_pchip
