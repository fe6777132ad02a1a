!> The kernels of the surface table (friction_surface_lennard_jones): the
!> lattice sum's value and derivatives at the nodes of one column of heights
!> (the table's build), and the pair terms of a list of differences (its
!> evaluation).  A module of its own so that it can be compiled for
!> vectorization (CMakeLists.txt) without touching the direct sum's code.
module friction_surface_lj_columns
   use friction_kinds, only: wp
   implicit none
   private

   public :: column_sums, difference_terms

contains

   !> The eight node values at heights z(:) of a column, from the n pairs
   !> within the cutoff r_c (rc2 = r_c²) in the plane: for pair p the
   !> lateral distance² lateral(p), u_i(p) = a_i . d (a_i the lattice
   !> vectors, d the tip less the atom), the atom's height, σ², 4ε and the
   !> energy shift φ(r_c).  With q = r², φ(q) and its q-derivatives
   !> φ1, φ2, φ3, w = d_z and c12 = a1 . a2, the values in the fractional
   !> coordinates of the lattice (d/ds_i = a_i . grad):
   !>   V, V_s1 = 2φ1 u1, V_s2 = 2φ1 u2, V_z = 2φ1 w,
   !>   V_s1s2 = 4φ2 u1 u2 + 2φ1 c12, V_s1z = 4φ2 u1 w, V_s2z = 4φ2 u2 w,
   !>   V_s1s2z = 8φ3 u1 u2 w + 4φ2 c12 w.
   pure subroutine column_sums(n, lateral, u1, u2, height, sigma2, e4, shift, c12, rc2, z, values)
      integer, intent(in) :: n
      real(wp), intent(in) :: lateral(:), u1(:), u2(:), height(:), sigma2(:), e4(:), shift(:), c12, rc2, z(:)
      real(wp), intent(out) :: values(:, :)
      real(wp) :: f0(n), f1(n), f2(n), f3(n), dz(n), acc(8), w, q, inside, iq, s6, s12
      integer :: k, p

      do k = 1, size(z)
         ! The radial derivatives pair by pair (no branch, so that the loop
         ! vectorizes: pairs beyond the cutoff get weight 0), then the sums
         ! in the pairs' order.  (Eight arrays of terms summed by `sum`
         ! instead took twice as long.)
         do p = 1, n
            w = z(k) - height(p)
            q = lateral(p) + w * w
            inside = merge(1.0_wp, 0.0_wp, q < rc2)
            iq = 1.0_wp / q
            s6 = (sigma2(p) * iq)**3
            s12 = s6 * s6
            dz(p) = w
            f0(p) = inside * (e4(p) * (s12 - s6) - shift(p))
            f1(p) = inside * e4(p) * (-6.0_wp * s12 + 3.0_wp * s6) * iq
            f2(p) = inside * e4(p) * (42.0_wp * s12 - 12.0_wp * s6) * iq * iq
            f3(p) = inside * e4(p) * (-336.0_wp * s12 + 60.0_wp * s6) * iq * iq * iq
         end do
         acc = 0.0_wp
         do p = 1, n
            acc(1) = acc(1) + f0(p)
            acc(2) = acc(2) + 2.0_wp * f1(p) * u1(p)
            acc(3) = acc(3) + 2.0_wp * f1(p) * u2(p)
            acc(4) = acc(4) + 2.0_wp * f1(p) * dz(p)
            acc(5) = acc(5) + 4.0_wp * f2(p) * u1(p) * u2(p) + 2.0_wp * f1(p) * c12
            acc(6) = acc(6) + 4.0_wp * f2(p) * u1(p) * dz(p)
            acc(7) = acc(7) + 4.0_wp * f2(p) * u2(p) * dz(p)
            acc(8) = acc(8) + (8.0_wp * f3(p) * u1(p) * u2(p) + 4.0_wp * f2(p) * c12) * dz(p)
         end do
         values(:, k) = acc
      end do
   end subroutine column_sums

   !> The energy v and gradient g (order 1; energy alone for order 0) at r of
   !> the pairs of a list, as arrays: position (x, y, z), σ², the weighted
   !> 4εw and φ(r_c)w (w = ±1), cut at rc2 = r_c².  Pair by pair without a
   !> branch (pairs beyond the cutoff get weight 0), so that the loop
   !> vectorizes, then the sums in the list's order.
   pure subroutine difference_terms(n, x, y, z, sigma2, e4w, shiftw, rc2, r, order, v, g)
      integer, intent(in) :: n, order
      real(wp), intent(in) :: x(:), y(:), z(:), sigma2(:), e4w(:), shiftw(:), rc2, r(3)
      real(wp), intent(out) :: v, g(3)
      real(wp) :: ev(n), gx(n), gy(n), gz(n), dx, dy, dz, q, inside, iq, s6, f
      integer :: p

      do p = 1, n
         dx = r(1) - x(p)
         dy = r(2) - y(p)
         dz = r(3) - z(p)
         q = dx * dx + dy * dy + dz * dz
         inside = merge(1.0_wp, 0.0_wp, q < rc2)
         iq = 1.0_wp / q
         s6 = (sigma2(p) * iq)**3
         ev(p) = inside * (e4w(p) * (s6 * s6 - s6) - shiftw(p))
         f = -inside * 6.0_wp * e4w(p) * (2.0_wp * s6 * s6 - s6) * iq
         gx(p) = f * dx
         gy(p) = f * dy
         gz(p) = f * dz
      end do
      v = sum(ev)
      g = 0.0_wp
      if (order < 1) return
      g = [sum(gx), sum(gy), sum(gz)]
   end subroutine difference_terms

end module friction_surface_lj_columns
