!> Small symmetric matrices (the tip's 1 to 3 coordinates): eigenvalues and
!> eigenvectors by cyclic Jacobi rotations, which are accurate to rounding
!> relative to the matrix norm, and the determinant of a small matrix.
module friction_symmetric
   use friction_kinds, only: wp
   implicit none
   private

   public :: symmetric_eigen, determinant

   integer, parameter :: max_sweeps = 50

contains

   !> a = V diag(values) Vᵀ for a symmetric a (only its upper triangle is
   !> read): values ascending, vectors(:, i) the unit eigenvector of
   !> values(i).
   pure subroutine symmetric_eigen(a, values, vectors)
      real(wp), intent(in) :: a(:, :)
      real(wp), intent(out) :: values(:)
      real(wp), intent(out) :: vectors(:, :)
      real(wp) :: m(size(a, 1), size(a, 1)), v(size(a, 1), size(a, 1)), off, scale
      real(wp) :: theta, t, c, s, tau, apq, mpp, mqq, mip, miq, vip, viq, swap_value
      real(wp) :: swap_vector(size(a, 1))
      integer :: n, p, q, i, sweep, k

      n = size(a, 1)
      do q = 1, n
         do p = 1, q
            m(p, q) = a(p, q)
            m(q, p) = a(p, q)
         end do
      end do
      v = 0.0_wp
      do i = 1, n
         v(i, i) = 1.0_wp
      end do
      scale = sqrt(sum(m**2))
      do sweep = 1, max_sweeps
         off = 0.0_wp
         do q = 2, n
            do p = 1, q - 1
               off = off + m(p, q)**2
            end do
         end do
         if (sqrt(off) <= epsilon(1.0_wp) * 1.0e-2_wp * scale .or. off == 0.0_wp) exit
         do q = 2, n
            do p = 1, q - 1
               apq = m(p, q)
               if (apq == 0.0_wp) cycle
               mpp = m(p, p)
               mqq = m(q, q)
               theta = (mqq - mpp) / (2.0_wp * apq)
               t = sign(1.0_wp, theta) / (abs(theta) + sqrt(theta**2 + 1.0_wp))
               c = 1.0_wp / sqrt(t**2 + 1.0_wp)
               s = t * c
               tau = s / (1.0_wp + c)
               m(p, p) = mpp - t * apq
               m(q, q) = mqq + t * apq
               m(p, q) = 0.0_wp
               m(q, p) = 0.0_wp
               do i = 1, n
                  if (i == p .or. i == q) cycle
                  mip = m(i, p)
                  miq = m(i, q)
                  m(i, p) = mip - s * (miq + tau * mip)
                  m(i, q) = miq + s * (mip - tau * miq)
                  m(p, i) = m(i, p)
                  m(q, i) = m(i, q)
               end do
               do i = 1, n
                  vip = v(i, p)
                  viq = v(i, q)
                  v(i, p) = vip - s * (viq + tau * vip)
                  v(i, q) = viq + s * (vip - tau * viq)
               end do
            end do
         end do
      end do
      do i = 1, n
         values(i) = m(i, i)
      end do
      ! ascending order (n <= 3: insertion sort)
      do i = 2, n
         k = i
         do while (k > 1)
            if (values(k - 1) <= values(k)) exit
            swap_value = values(k - 1)
            values(k - 1) = values(k)
            values(k) = swap_value
            swap_vector = v(:, k - 1)
            v(:, k - 1) = v(:, k)
            v(:, k) = swap_vector
            k = k - 1
         end do
      end do
      vectors(1:n, 1:n) = v
   end subroutine symmetric_eigen

   !> Determinant: closed forms up to 3×3, else Gaussian elimination with
   !> partial pivoting.
   pure function determinant(a) result(d)
      real(wp), intent(in) :: a(:, :)
      real(wp) :: d
      real(wp) :: lu(size(a, 1), size(a, 1)), swap, factor, largest
      integer :: n, i, j, k, p

      n = size(a, 1)
      select case (n)
      case (0)
         d = 1.0_wp
      case (1)
         d = a(1, 1)
      case (2)
         d = a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1)
      case (3)
         d = a(1, 1) * (a(2, 2) * a(3, 3) - a(2, 3) * a(3, 2)) &
            & - a(1, 2) * (a(2, 1) * a(3, 3) - a(2, 3) * a(3, 1)) &
            & + a(1, 3) * (a(2, 1) * a(3, 2) - a(2, 2) * a(3, 1))
      case default
         lu = a
         d = 1.0_wp
         do j = 1, n
            p = j
            largest = abs(lu(j, j))
            do i = j + 1, n
               if (abs(lu(i, j)) > largest) then
                  p = i
                  largest = abs(lu(i, j))
               end if
            end do
            if (largest == 0.0_wp) then
               d = 0.0_wp
               return
            end if
            if (p /= j) then
               do k = 1, n
                  swap = lu(j, k)
                  lu(j, k) = lu(p, k)
                  lu(p, k) = swap
               end do
               d = -d
            end if
            d = d * lu(j, j)
            do i = j + 1, n
               factor = lu(i, j) / lu(j, j)
               do k = j + 1, n
                  lu(i, k) = lu(i, k) - factor * lu(j, k)
               end do
            end do
         end do
      end select
   end function determinant

end module friction_symmetric
