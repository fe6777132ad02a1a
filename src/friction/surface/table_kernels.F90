!> The kernels of the surface table (friction_surface_lattice_table,
!> friction_surface_lennard_jones and friction_surface_tricubic): the
!> lattice sum's value and derivatives at the nodes of one column of
!> heights (the table's build), the pair terms of a list of differences,
!> and a cell's polynomial (its evaluation).  A module of its own so that
!> it can be compiled for vectorization (CMakeLists.txt) without touching
!> the direct sum's code.
!>
!> Compiled twice: as friction_surface_table_kernels for every x86-64
!> processor, and through table_kernels_wide.F90 as
!> friction_surface_table_kernels_wide for those with AVX2 (x86-64-v3),
!> which the table chooses at run time when the processor of every process
!> building it has it (lattice_table.f90, `all_can_go_wide`).  The wide copy fuses
!> multiplies and adds, which shortens the cell's polynomial's chain of
!> dependent operations (the evaluation's cost), so the two copies agree to
!> rounding, not bit for bit (tests `table`); nothing here reorders a sum.
#ifndef TABLE_KERNELS
#define TABLE_KERNELS friction_surface_table_kernels
#endif
module TABLE_KERNELS
   use friction_kinds, only: wp
   use friction_surface_cell_grid, only: cell_grid
   implicit none
   private

   public :: column_sums, difference_terms, power_polynomial, lattice_gradient, find_layer, image_point, lateral_back, &
      & cell_fraction, from_fraction, n_cell_coefficients, column_lanes

   !> Coefficients of a cell's polynomial (power_polynomial; the cells of
   !> friction_surface_tricubic's set_polynomials).
   integer, parameter :: n_cell_coefficients = 64

   !> Pairs summed side by side in column_sums (its pair lists are padded to
   !> a multiple of this).
   integer, parameter :: column_lanes = 4

contains

   !> The eight node values at heights z(:) of a column, from the n pairs
   !> within the cutoff r_c (rc2 = r_c²) in the plane: for pair p the
   !> lateral distance² lateral(p), u_i(p) = a_i . d (a_i the lattice
   !> vectors, d the tip less the atom) and u12(p) = u1(p) u2(p), the
   !> atom's height, σ², 4ε and the energy shift φ(r_c).  With q = r², φ(q)
   !> and its q-derivatives φ1, φ2, φ3, w = d_z and c12 = a1 . a2, the values
   !> in the fractional coordinates of the lattice (d/ds_i = a_i . grad):
   !>   V, V_s1 = 2φ1 u1, V_s2 = 2φ1 u2, V_z = 2φ1 w,
   !>   V_s1s2 = 4φ2 u1 u2 + 2φ1 c12, V_s1z = 4φ2 u1 w, V_s2z = 4φ2 u2 w,
   !>   V_s1s2z = 8φ3 u1 u2 w + 4φ2 c12 w
   !> (the c12 terms as c12 times the sums of 2φ1 and 4φ2 w).  With
   !> values(9:12, :) too (size(values, 1) = 12), the in-plane second
   !> derivatives a node's images under the lattice's rotations need
   !> (c11 = a1 . a1, c22 = a2 . a2):
   !>   V_s1s1 = 4φ2 u1² + 2φ1 c11, V_s2s2 = 4φ2 u2² + 2φ1 c22,
   !>   V_s1s1z = 8φ3 u1² w + 4φ2 c11 w, V_s2s2z = 8φ3 u2² w + 4φ2 c22 w.
   !> n is a multiple of `column_lanes` (pad with pairs beyond the cutoff:
   !> lateral(p) >= rc2, e4 = shift = 0, which add exactly zero).
   pure subroutine column_sums(n, lateral, u1, u2, u12, height, sigma2, e4, shift, metric, rc2, z, values)
      integer, intent(in) :: n
      real(wp), intent(in), dimension(column_lanes, n / column_lanes) :: lateral, u1, u2, u12, height, sigma2, &
         & e4, shift
      !> the lattice vectors' products: c11, c12, c22
      real(wp), intent(in) :: metric(3)
      real(wp), intent(in) :: rc2, z(:)
      real(wp), intent(out) :: values(:, :)

      ! (Two calls, each with its flag a constant, so that the compiler makes
      ! each a loop of its own: the columns that need the first eight values
      ! alone, the checks', do not pay for the four more sums.)
      if (size(values, 1) >= 12) then
         call lane_sums(n, lateral, u1, u2, u12, height, sigma2, e4, shift, metric, rc2, z, .true., values)
      else
         call lane_sums(n, lateral, u1, u2, u12, height, sigma2, e4, shift, metric, rc2, z, .false., values)
      end if
   end subroutine column_sums

   !> column_sums' work, the in-plane second derivatives when `plane`.
   pure subroutine lane_sums(n, lateral, u1, u2, u12, height, sigma2, e4, shift, metric, rc2, z, plane, values)
      integer, intent(in) :: n
      real(wp), intent(in), dimension(column_lanes, n / column_lanes) :: lateral, u1, u2, u12, height, sigma2, &
         & e4, shift
      real(wp), intent(in) :: metric(3)
      real(wp), intent(in) :: rc2, z(:)
      logical, intent(in) :: plane
      real(wp), intent(out) :: values(:, :)
      ! (d1 = 2φ1, d2 = 4φ2, d3 = 8φ3: the derivatives as the sums want them.)
      real(wp) :: acc(column_lanes, 14), w, q, inside, e, iq, s6, s12, t1, t2, d1, d2, d3
      real(wp) :: total(14)
      integer :: k, c, l, m

      do k = 1, size(z)
         ! The pairs `column_lanes` at a time, each lane with running sums of
         ! its own, added up in a fixed order at the end: the lanes' loop
         ! vectorizes without reordering a sum the source does not (so the
         ! nodes do not depend on the vector width), and without a branch
         ! (pairs beyond the cutoff get weight 0).
         acc = 0.0_wp
         do c = 1, n / column_lanes
            do l = 1, column_lanes
               w = z(k) - height(l, c)
               q = lateral(l, c) + w * w
               inside = merge(1.0_wp, 0.0_wp, q < rc2)
               e = inside * e4(l, c)
               iq = 1.0_wp / q
               s6 = (sigma2(l, c) * iq)**3
               s12 = s6 * s6
               t1 = e * iq
               t2 = t1 * iq
               d1 = t1 * (6.0_wp * s6 - 12.0_wp * s12)
               d2 = t2 * (168.0_wp * s12 - 48.0_wp * s6)
               d3 = t2 * iq * (480.0_wp * s6 - 2688.0_wp * s12)
               acc(l, 1) = acc(l, 1) + (e * (s12 - s6) - inside * shift(l, c))
               acc(l, 2) = acc(l, 2) + d1 * u1(l, c)
               acc(l, 3) = acc(l, 3) + d1 * u2(l, c)
               acc(l, 4) = acc(l, 4) + d1 * w
               acc(l, 5) = acc(l, 5) + d2 * u12(l, c)
               acc(l, 6) = acc(l, 6) + d2 * w * u1(l, c)
               acc(l, 7) = acc(l, 7) + d2 * w * u2(l, c)
               acc(l, 8) = acc(l, 8) + d3 * w * u12(l, c)
               acc(l, 9) = acc(l, 9) + d1
               acc(l, 10) = acc(l, 10) + d2 * w
               if (.not. plane) cycle
               acc(l, 11) = acc(l, 11) + d2 * (u1(l, c) * u1(l, c))
               acc(l, 12) = acc(l, 12) + d2 * (u2(l, c) * u2(l, c))
               acc(l, 13) = acc(l, 13) + d3 * w * (u1(l, c) * u1(l, c))
               acc(l, 14) = acc(l, 14) + d3 * w * (u2(l, c) * u2(l, c))
            end do
         end do
         do m = 1, 14
            total(m) = (acc(1, m) + acc(2, m)) + (acc(3, m) + acc(4, m))
         end do
         values(1:8, k) = total(1:8)
         values(5, k) = total(5) + metric(2) * total(9)
         values(8, k) = total(8) + metric(2) * total(10)
         if (.not. plane) cycle
         values(9, k) = total(11) + metric(1) * total(9)
         values(10, k) = total(12) + metric(3) * total(9)
         values(11, k) = total(13) + metric(1) * total(10)
         values(12, k) = total(14) + metric(3) * total(10)
      end do
   end subroutine lane_sums

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

   !> The value v, gradient g (order >= 1) and Hessian h (order 2; else
   !> zero) of one cell's polynomial c (set_polynomials) at local
   !> coordinates (x, y, z), with inverse(:) the reciprocal cell widths:
   !> the cubics along z (16 at once), then y (4), then x (`cubic`).
   pure subroutine power_polynomial(c, x, y, z, inverse, order, v, g, h)
      real(wp), intent(in) :: c(n_cell_coefficients), x, y, z, inverse(3)
      integer, intent(in) :: order
      real(wp), intent(out) :: v, g(3), h(3, 3)
      ! (aN: N-th z derivative, 16 cubics in x, y; bMN: M-th y derivative
      ! and N-th z derivative, 4 cubics in x.)
      real(wp) :: a0(16), a1(16), a2(16), b00(4), b10(4), b01(4), b20(4), b11(4), b02(4), x2, y2

      h = 0.0_wp
      g = 0.0_wp
      if (order < 1) then
         a0 = cubic(c(1:16), c(17:32), c(33:48), c(49:64), z, z * z)
         b00 = cubic(a0(1:4), a0(5:8), a0(9:12), a0(13:16), y, y * y)
         v = cubic(b00(1), b00(2), b00(3), b00(4), x, x * x)
         return
      end if
      call cell_gradient(c, x, y, z, inverse(1), inverse(2), inverse(3), a0, a1, b00, b10, b01, v, g)
      if (order < 2) return
      x2 = x * x
      y2 = y * y
      a2 = 2.0_wp * c(33:48) + 6.0_wp * z * c(49:64)
      b20 = 2.0_wp * a0(9:12) + 6.0_wp * y * a0(13:16)
      b11 = cubic_slope(a1(5:8), a1(9:12), a1(13:16), y, y2)
      b02 = cubic(a2(1:4), a2(5:8), a2(9:12), a2(13:16), y, y2)
      h(1, 1) = (2.0_wp * b00(3) + 6.0_wp * x * b00(4)) * inverse(1)**2
      h(2, 2) = cubic(b20(1), b20(2), b20(3), b20(4), x, x2) * inverse(2)**2
      h(3, 3) = cubic(b02(1), b02(2), b02(3), b02(4), x, x2) * inverse(3)**2
      h(1, 2) = cubic_slope(b10(2), b10(3), b10(4), x, x2) * inverse(1) * inverse(2)
      h(1, 3) = cubic_slope(b01(2), b01(3), b01(4), x, x2) * inverse(1) * inverse(3)
      h(2, 3) = cubic(b11(1), b11(2), b11(3), b11(4), x, x2) * inverse(2) * inverse(3)
      h(2, 1) = h(1, 2)
      h(3, 1) = h(1, 3)
      h(3, 2) = h(2, 3)
   end subroutine power_polynomial

   !> The value v and gradient g of the cell's polynomial c (power_polynomial,
   !> order 1; ix, iy, iz the reciprocal widths), and the partial contractions
   !> the Hessian goes on from.
   pure subroutine cell_gradient(c, x, y, z, ix, iy, iz, a0, a1, b00, b10, b01, v, g)
      real(wp), intent(in) :: c(n_cell_coefficients), x, y, z, ix, iy, iz
      real(wp), intent(out) :: a0(16), a1(16), b00(4), b10(4), b01(4), v, g(3)
      real(wp) :: x2, y2, z2

      x2 = x * x
      y2 = y * y
      z2 = z * z
      a0 = cubic(c(1:16), c(17:32), c(33:48), c(49:64), z, z2)
      a1 = cubic_slope(c(17:32), c(33:48), c(49:64), z, z2)
      b00 = cubic(a0(1:4), a0(5:8), a0(9:12), a0(13:16), y, y2)
      b10 = cubic_slope(a0(5:8), a0(9:12), a0(13:16), y, y2)
      b01 = cubic(a1(1:4), a1(5:8), a1(9:12), a1(13:16), y, y2)
      v = cubic(b00(1), b00(2), b00(3), b00(4), x, x2)
      g(1) = cubic_slope(b00(2), b00(3), b00(4), x, x2) * ix
      g(2) = cubic(b10(1), b10(2), b10(3), b10(4), x, x2) * iy
      g(3) = cubic(b01(1), b01(2), b01(3), b01(4), x, x2) * iz
   end subroutine cell_gradient

   !> The cubic c0 + c1 x + c2 x² + c3 x³, with x2 = x², in Estrin's
   !> order: its two halves do not wait on each other, so the chain of
   !> operations that do is shorter than Horner's rule's.  The table's
   !> evaluation is bound by that chain: each right-hand side waits on the
   !> one before.
   pure elemental real(wp) function cubic(c0, c1, c2, c3, x, x2)
      real(wp), intent(in) :: c0, c1, c2, c3, x, x2

      cubic = (c0 + c1 * x) + x2 * (c2 + c3 * x)
   end function cubic

   !> The cubic's derivative c1 + 2 c2 x + 3 c3 x² (`cubic`).
   pure elemental real(wp) function cubic_slope(c1, c2, c3, x, x2)
      real(wp), intent(in) :: c1, c2, c3, x, x2

      cubic_slope = (c1 + (2.0_wp * x) * c2) + (3.0_wp * x2) * c3
   end function cubic_slope

   !> The point (x, y) of a cell's local coordinates (px, py) under the map
   !> `op` that takes a cell to the one whose polynomial it shares (0 none,
   !> 1 the reflection: (1 - ξ, 1 - η), 2 the swap: (η, ξ), 3 both:
   !> (1 - η, 1 - ξ); friction_surface_tricubic's set_polynomials).
   pure subroutine image_point(op, px, py, x, y)
      integer, intent(in) :: op
      real(wp), intent(in) :: px, py
      real(wp), intent(out) :: x, y

      select case (op)
      case (0)
         x = px
         y = py
      case (1)
         x = 1.0_wp - px
         y = 1.0_wp - py
      case (2)
         x = py
         y = px
      case default
         x = 1.0_wp - py
         y = 1.0_wp - px
      end select
   end subroutine image_point

   !> The layer k of the grid with z(k) <= height < z(k+1) (1 <= k <= nz - 1;
   !> the end layers for heights outside: the interpolant continues as a
   !> cubic).
   pure integer function find_layer(grid, height) result(k)
      type(cell_grid), intent(in) :: grid
      real(wp), intent(in) :: height
      integer :: last

      last = size(grid%z) - 1
      k = grid%bin_layer(int(min(real(size(grid%bin_layer), wp), max(1.0_wp, &
         & (height - grid%z(1)) * grid%inverse_bin + 1.0_wp))))
      ! A bin is narrower than any layer: at most one layer starts in it,
      ! so one step up, without a branch to mispredict as the tip moves
      ! across the layers (the loop only for rounding at a bin's edge).
      if (k < last) k = k + merge(1, 0, grid%z(k + 1) <= height)
      do while (k < last)
         if (grid%z(k + 1) > height) exit
         k = k + 1
      end do
   end function find_layer

   !> The value v and Cartesian gradient g at r (Å) of a lattice's table:
   !> the grid over the fractional coordinates (s1, s2, z) of the lattice's
   !> cell (grid_gradient), m the map to them (s = m (x, y)).  The table's
   !> hot path, every step in one routine.
   pure subroutine lattice_gradient(grid, m, r, v, g)
      type(cell_grid), intent(in) :: grid
      real(wp), intent(in) :: m(2, 2), r(3)
      real(wp), intent(out) :: v, g(3)
      real(wp) :: s(2), gs(3)

      s = cell_fraction(m, r(1:2))
      call grid_gradient(grid, s(1), s(2), r(3), v, gs)
      g = from_fraction(m, gs)
   end subroutine lattice_gradient

   !> The fractional coordinates in [0, 1) of the point xy (Å) in the plane
   !> within a lattice's cell, m the map to fractional coordinates.
   pure function cell_fraction(m, xy) result(s)
      real(wp), intent(in) :: m(2, 2), xy(2)
      real(wp) :: s(2)

      s(1) = m(1, 1) * xy(1) + m(1, 2) * xy(2)
      s(2) = m(2, 1) * xy(1) + m(2, 2) * xy(2)
      s = s - floor(s)
   end function cell_fraction

   !> The Cartesian gradient from gs = (V_s1, V_s2, V_z), the gradient in a
   !> lattice's fractional coordinates, m the map to them: dV/dx_j =
   !> Σ_i dV/ds_i m_ij, mᵀ gs in the plane.
   pure function from_fraction(m, gs) result(g)
      real(wp), intent(in) :: m(2, 2), gs(3)
      real(wp) :: g(3)

      g(1) = m(1, 1) * gs(1) + m(2, 1) * gs(2)
      g(2) = m(1, 2) * gs(1) + m(2, 2) * gs(2)
      g(3) = gs(3)
   end function from_fraction

   !> The value v and gradient g (no Hessian: the table's hot path) at
   !> (x, y, z) of the grid's interpolant through its cells' polynomials,
   !> which must be set: the cell, its layer, its image and the polynomial
   !> in one routine.  Points outside the grid get the end cells'
   !> polynomials.  The same operations as power_polynomial's order 1
   !> (friction_surface_tricubic's evaluate): the same bits in the plain
   !> copy; in the wide one the compiler may fuse them differently.
   pure subroutine grid_gradient(grid, x, y, z, v, g)
      type(cell_grid), intent(in) :: grid
      real(wp), intent(in) :: x, y, z
      real(wp), intent(out) :: v, g(3)
      real(wp) :: s, t, a0(16), a1(16), b00(4), b10(4), b01(4), px, py
      integer :: i, j, k, op

      s = (x - grid%x0) * grid%inverse_hx
      t = (y - grid%y0) * grid%inverse_hy
      i = int(min(real(grid%nx - 2, wp), max(0.0_wp, s)))
      j = int(min(real(grid%ny - 2, wp), max(0.0_wp, t)))
      k = find_layer(grid, z)
      ! The polynomial at the image point under the cell's map, its lateral
      ! gradient mapped back (odd under the reflection, trading places
      ! under the swap).
      op = grid%image(i, j)
      call image_point(op, s - i, t - j, px, py)
      call cell_gradient(grid%cell(:, grid%slot(i, j) + grid%slots * (k - 1)), px, py, &
         & (z - grid%z(k)) * grid%inverse_dz(k), grid%inverse_hx, grid%inverse_hy, grid%inverse_dz(k), &
         & a0, a1, b00, b10, b01, v, g)
      call lateral_back(op, g)
   end subroutine grid_gradient

   !> The lateral gradient g(1:2) taken at a cell's image point under `op`
   !> (image_point) mapped back to the cell: odd under the reflection, its
   !> components trading places under the swap.
   pure subroutine lateral_back(op, g)
      integer, intent(in) :: op
      real(wp), intent(inout) :: g(3)

      if (op == 0) return
      if (op /= 1) g(1:2) = [g(2), g(1)]
      if (op /= 2) g(1:2) = -g(1:2)
   end subroutine lateral_back

end module TABLE_KERNELS
