!> Tricubic Hermite interpolation on a rectilinear grid: uniform along x and
!> y, any strictly increasing heights along z.
!>
!> Each node holds the function and seven derivatives,
!>   f, f_x, f_y, f_z, f_xy, f_xz, f_yz, f_xyz,
!> and each cell is the tensor product of the cubic Hermite polynomials of
!> its eight corners (Lekien and Marsden, Int. J. Numer. Meth. Engng 63
!> (2005) 455).  The interpolant is C1 everywhere: on a face shared by two
!> cells both use the same four corners' data, so the value and the first
!> derivatives agree across it (the second derivatives jump).  It
!> reproduces any polynomial of degree <= 3 in each variable exactly, and
!> for a smooth f its gradient is wrong by O(h^3) (value O(h^4)).
!>
!> For speed the grid can also hold each cell's polynomial in the power
!> basis of its local coordinates (`set_polynomials`, after the nodes are
!> filled): 64 coefficients per cell, contiguous, so that an evaluation
!> reads one block and contracts it cubic by cubic along z, y and x
!> instead of gathering and weighting eight corners' data.  It is the same
!> polynomial, to rounding.  Data symmetric under the point reflection
!> through the middle of the grid's (x, y) rectangle, or under the swap of
!> x and y, share polynomials: a cell whose image comes first is evaluated
!> through it, at the image point (a graphite table stores a quarter of its
!> cells, 2 times the nodes' memory instead of 8).
!>
!> Why this scheme: a lattice sum gives its derivatives analytically (the
!> cross derivatives too, from the pair's radial derivatives), so the data
!> cost one pass over the atoms per node; the interpolant is local (no
!> system to solve, no special boundaries) and gives the gradient and the
!> Hessian of one function, so an adaptive or implicit stepper sees a
!> consistent smooth field.  Cubic B-splines would be C2 with one value per
!> node but need a global solve and boundary conditions, and their gradient
!> error is about ten times larger at the same spacing.
module friction_surface_tricubic
   use friction_kinds, only: wp
   use friction_surface_cell_grid, only: cell_grid
   use friction_surface_table_kernels, only: power_polynomial, find_layer, image_point, lateral_back, &
      & n_cell_coefficients
   use friction_surface_table_kernels_wide, only: power_polynomial_wide => power_polynomial
   use, intrinsic :: iso_c_binding, only: c_size_t
   implicit none
   private

   public :: tricubic_grid, new_tricubic_grid, n_node_values, n_cell_coefficients

   !> Values per node: f, f_x, f_y, f_z, f_xy, f_xz, f_yz, f_xyz.
   integer, parameter :: n_node_values = 8

   interface
      !> The whole pages of the `bytes` from `p` backed with memory at once
      !> (pages.c): a trap per page at the first touch costs the table's
      !> build some 2 µs a page.  Pure: no value the program sees changes.
      pure subroutine populate(p, bytes) bind(c, name='friction_populate')
         import :: c_size_t
         type(*), intent(in) :: p(*)
         integer(c_size_t), value, intent(in) :: bytes
      end subroutine populate
   end interface

   !> The grid: its axes, layers and cells' polynomials (cell_grid), and
   !> the nodes' values.
   type, extends(cell_grid) :: tricubic_grid
      !> node(:, i, j, k): the eight values of node (x0 + (i-1) hx, y0 + (j-1) hy, z(k))
      real(wp), allocatable :: node(:, :, :, :)
      !> evaluate through the kernels compiled for AVX2 (faster, the same
      !> values to rounding; set only where the processor has it:
      !> friction_surface_table_kernels)
      logical :: wide = .false.
   contains
      procedure :: evaluate
      procedure :: set_polynomials
      procedure :: layer_below
      procedure :: bytes
   end type tricubic_grid

contains

   !> A grid of nx x ny x size(z) nodes, its values zero; `wide` its
   !> component of that name (default .false.).
   pure function new_tricubic_grid(x0, hx, nx, y0, hy, ny, z, wide) result(grid)
      real(wp), intent(in) :: x0, hx, y0, hy, z(:)
      integer, intent(in) :: nx, ny
      logical, intent(in), optional :: wide
      type(tricubic_grid) :: grid
      integer :: b, k, nbins

      if (present(wide)) grid%wide = wide
      grid%x0 = x0
      grid%hx = hx
      grid%nx = nx
      grid%y0 = y0
      grid%hy = hy
      grid%ny = ny
      allocate (grid%z, source=z)
      grid%inverse_hx = 1.0_wp / hx
      grid%inverse_hy = 1.0_wp / hy
      grid%inverse_dz = 1.0_wp / (z(2:) - z(:size(z) - 1))
      allocate (grid%node(n_node_values, nx, ny, size(z)))
      call populate(grid%node, storage_size(grid%node, c_size_t) / 8 * size(grid%node, kind=c_size_t))
      grid%node = 0.0_wp
      nbins = max(1, min(1000000, ceiling((z(size(z)) - z(1)) / minval(z(2:) - z(:size(z) - 1)))))
      grid%bin_width = (z(size(z)) - z(1)) / nbins
      grid%inverse_bin = 1.0_wp / grid%bin_width
      allocate (grid%bin_layer(nbins))
      k = 1
      do b = 1, nbins
         do while (k < size(z) - 1 .and. z(k + 1) <= z(1) + (b - 1) * grid%bin_width)
            k = k + 1
         end do
         grid%bin_layer(b) = k
      end do
   end function new_tricubic_grid

   !> Memory of the node values and the cells' polynomials, bytes.
   pure real(wp) function bytes(self)
      class(tricubic_grid), intent(in) :: self

      bytes = 0.0_wp
      if (allocated(self%node)) bytes = real(storage_size(self%node), wp) / 8.0_wp * real(size(self%node), wp)
      if (allocated(self%cell)) bytes = bytes + real(storage_size(self%cell), wp) / 8.0_wp * real(size(self%cell), wp)
   end function bytes

   !> The layer k with z(k) <= height < z(k+1) (1 <= k <= nz - 1; the end
   !> layers for heights outside: the interpolant continues as a cubic).
   pure integer function layer_below(self, height) result(k)
      class(tricubic_grid), intent(in) :: self
      real(wp), intent(in) :: height

      k = find_layer(self%cell_grid, height)
   end function layer_below

   !> The interpolant at p = (x, y, z): its value v, and for order >= 1 its
   !> gradient g, for order 2 also its Hessian h (zero when not asked for).
   !> Points outside the grid get the end cells' polynomials.
   pure subroutine evaluate(self, p, order, v, g, h)
      class(tricubic_grid), intent(in) :: self
      real(wp), intent(in) :: p(3)
      integer, intent(in) :: order
      real(wp), intent(out) :: v, g(3), h(3, 3)
      real(wp) :: bx(4, 0:2), by(4, 0:2), bz(4, 0:2), s, t, dz
      integer :: i, j, k

      s = (p(1) - self%x0) * self%inverse_hx
      t = (p(2) - self%y0) * self%inverse_hy
      i = int(min(real(self%nx - 2, wp), max(0.0_wp, s)))
      j = int(min(real(self%ny - 2, wp), max(0.0_wp, t)))
      k = find_layer(self%cell_grid, p(3))
      if (allocated(self%cell)) then
         associate (op => self%image(i, j))
            call cell_polynomial(self%cell(:, self%slot(i, j) + self%slots * (k - 1)), op, s - i, t - j, &
               & (p(3) - self%z(k)) * self%inverse_dz(k), [self%inverse_hx, self%inverse_hy, self%inverse_dz(k)], &
               & order, self%wide, v, g, h)
         end associate
         return
      end if
      dz = self%z(k + 1) - self%z(k)
      call hermite_basis(s - i, self%hx, self%inverse_hx, order, bx)
      call hermite_basis(t - j, self%hy, self%inverse_hy, order, by)
      call hermite_basis((p(3) - self%z(k)) * self%inverse_dz(k), dz, self%inverse_dz(k), order, bz)
      if (order <= 1) then
         call value_gradient(self, i, j, k, bx, by, bz, v, g)
         h = 0.0_wp
      else
         call with_hessian(self, i, j, k, bx, by, bz, v, g, h)
      end if
   end subroutine evaluate

   !> Each cell's polynomial in the power basis of its local coordinates
   !> (the component `cell`), from the nodes' values, which must be set;
   !> evaluate then uses these.  Along each axis, the cubic Hermite data of
   !> a cell of width w (values f0, f1 and derivatives d0, d1 at its ends)
   !> are the cubic p0 + p1 t + p2 t² + p3 t³ with p0 = f0, p1 = w d0,
   !> p2 = 3 (f1 - f0) - w (2 d0 + d1), p3 = 2 (f0 - f1) + w (d0 + d1).
   !> `inversion`: the data are symmetric under the point reflection through
   !> the middle of the (x, y) rectangle, (x, y) -> (2 x_m - x, 2 y_m - y);
   !> `swap`: under (x - x0, y - y0) -> (y - y0, x - x0) (ignored unless
   !> nx = ny and hx = hy).  A cell mapped by these onto one that comes
   !> earlier shares that cell's polynomial (to rounding, the same).
   pure subroutine set_polynomials(self, inversion, swap)
      class(tricubic_grid), intent(inout) :: self
      logical, intent(in), optional :: inversion, swap
      integer :: i, j, k, op, n, m, there(2), first
      logical :: used(3)

      n = self%nx - 1
      m = self%ny - 1
      used = .false.
      if (present(inversion)) used(1) = inversion
      if (present(swap)) used(2) = swap .and. n == m .and. self%hx == self%hy
      used(3) = used(1) .and. used(2)
      if (allocated(self%cell)) deallocate (self%cell)
      if (allocated(self%slot)) deallocate (self%slot, self%image)
      allocate (self%slot(0:n - 1, 0:m - 1), self%image(0:n - 1, 0:m - 1))
      ! Each cell's image that comes first (the ops with the identity form
      ! a group, so that is the first of its orbit, its own image 0): the
      ! cells computed.
      self%slots = 0
      do j = 0, m - 1
         do i = 0, n - 1
            self%image(i, j) = 0
            first = i + n * j
            do op = 1, 3
               if (.not. used(op)) cycle
               there = image_cell(op, i, j)
               if (there(1) + n * there(2) >= first) cycle
               first = there(1) + n * there(2)
               self%image(i, j) = op
            end do
            if (self%image(i, j) /= 0) cycle
            self%slots = self%slots + 1
            self%slot(i, j) = self%slots
         end do
      end do
      do j = 0, m - 1
         do i = 0, n - 1
            if (self%image(i, j) == 0) cycle
            there = image_cell(self%image(i, j), i, j)
            self%slot(i, j) = self%slot(there(1), there(2))
         end do
      end do
      allocate (self%cell(n_cell_coefficients, self%slots * (size(self%z) - 1)))
      call populate(self%cell, storage_size(self%cell, c_size_t) / 8 * size(self%cell, kind=c_size_t))
      do k = 1, size(self%z) - 1
         do j = 0, m - 1
            do i = 0, n - 1
               if (self%image(i, j) /= 0) cycle
               call cell_power(self, i, j, k, self%cell(:, self%slot(i, j) + self%slots * (k - 1)))
            end do
         end do
      end do

   contains

      !> The cell (0-based) that cell (i, j) maps onto under op (1 the
      !> reflection, 2 the swap, 3 both).
      pure function image_cell(op, i, j) result(cell)
         integer, intent(in) :: op, i, j
         integer :: cell(2)

         select case (op)
         case (1)
            cell = [n - 1 - i, m - 1 - j]
         case (2)
            cell = [j, i]
         case default
            cell = [m - 1 - j, n - 1 - i]
         end select
      end function image_cell

   end subroutine set_polynomials

   !> The polynomial of cell (i, j, k) (0-based lower corner in x and y, k
   !> the layer below) in the power basis, c(1 + l + 4m + 16n) the
   !> coefficient of ξ^l η^m ζ^n (set_polynomials): its Hermite data, then
   !> along each axis the 16 cubics' data turned into coefficients (to_power).
   pure subroutine cell_power(self, i, j, k, c)
      type(tricubic_grid), intent(in) :: self
      integer, intent(in) :: i, j, k
      real(wp), intent(out) :: c(4, 4, 4)

      c = hermite_data(self, i, j, k)
      call to_power(c(1, :, :), c(2, :, :), c(3, :, :), c(4, :, :), self%hx)
      call to_power(c(:, 1, :), c(:, 2, :), c(:, 3, :), c(:, 4, :), self%hy)
      call to_power(c(:, :, 1), c(:, :, 2), c(:, :, 3), c(:, :, 4), self%z(k + 1) - self%z(k))
   end subroutine cell_power

   !> The cubic Hermite data (f0, f1, d0, d1) on an interval of width w
   !> replaced by the power-basis coefficients (p0, p1, p2, p3) of the same
   !> cubic: p0 = f0, p1 = w d0, p2 = 3 (f1 - f0) - 2 w d0 - w d1,
   !> p3 = 2 (f0 - f1) + w d0 + w d1.
   elemental subroutine to_power(f0, f1, d0, d1, w)
      real(wp), intent(inout) :: f0, f1, d0, d1
      real(wp), intent(in) :: w
      real(wp) :: v0, v1, s0, s1

      v0 = f0
      v1 = f1
      s0 = w * d0
      s1 = w * d1
      f1 = s0
      d0 = 3.0_wp * (v1 - v0) - 2.0_wp * s0 - s1
      d1 = 2.0_wp * (v0 - v1) + s0 + s1
   end subroutine to_power

   !> The value v, gradient g (order >= 1) and Hessian h (order 2; else
   !> zero) at local coordinates (ξ, η, ζ) = (px, py, z) of a cell whose
   !> polynomial is that of cell c at the image point under op (0 none, 1
   !> the reflection: (1 - ξ, 1 - η), 2 the swap: (η, ξ), 3 both:
   !> (1 - η, 1 - ξ); set_polynomials), with inverse(:) the reciprocal cell
   !> widths, through the AVX2 kernel when `wide`.  The image's derivatives
   !> come back through the map (odd in x, y under the reflection, x and y
   !> trading places under the swap).
   pure subroutine cell_polynomial(c, op, px, py, z, inverse, order, wide, v, g, h)
      real(wp), intent(in) :: c(n_cell_coefficients), px, py, z, inverse(3)
      integer, intent(in) :: op, order
      logical, intent(in) :: wide
      real(wp), intent(out) :: v, g(3), h(3, 3)
      real(wp) :: x, y

      call image_point(op, px, py, x, y)
      if (wide) then
         call power_polynomial_wide(c, x, y, z, inverse, order, v, g, h)
      else
         call power_polynomial(c, x, y, z, inverse, order, v, g, h)
      end if
      call lateral_back(op, g)
      if (order < 2 .or. op == 0) return
      if (op /= 1) h = h([2, 1, 3], [2, 1, 3])
      if (op /= 2) then
         h(1:2, 3) = -h(1:2, 3)
         h(3, 1:2) = -h(3, 1:2)
      end if
   end subroutine cell_polynomial

   !> The value and gradient in cell (i, j, k) (0-based lower corner in x
   !> and y, k the layer below) from the axes' basis values: corner by
   !> corner, the eight data contracted along z, then y, then x.
   pure subroutine value_gradient(self, i, j, k, bx, by, bz, v, g)
      type(tricubic_grid), intent(in) :: self
      integer, intent(in) :: i, j, k
      real(wp), intent(in) :: bx(4, 0:2), by(4, 0:2), bz(4, 0:2)
      real(wp), intent(out) :: v, g(3)
      real(wp) :: a00, a10, a01, a11, a00z, a10z, a01z, a11z, b0, b1, b0y, b1y, b0z, b1z
      integer :: ox, oy, oz

      v = 0.0_wp
      g = 0.0_wp
      do oz = 0, 1
         do oy = 0, 1
            do ox = 0, 1
               ! a_XY: the datum with X, Y derivatives in x, y, contracted along z.
               associate (q => self%node(:, i + 1 + ox, j + 1 + oy, k + oz))
                  a00 = q(1) * bz(1 + oz, 0) + q(4) * bz(3 + oz, 0)
                  a10 = q(2) * bz(1 + oz, 0) + q(6) * bz(3 + oz, 0)
                  a01 = q(3) * bz(1 + oz, 0) + q(7) * bz(3 + oz, 0)
                  a11 = q(5) * bz(1 + oz, 0) + q(8) * bz(3 + oz, 0)
                  a00z = q(1) * bz(1 + oz, 1) + q(4) * bz(3 + oz, 1)
                  a10z = q(2) * bz(1 + oz, 1) + q(6) * bz(3 + oz, 1)
                  a01z = q(3) * bz(1 + oz, 1) + q(7) * bz(3 + oz, 1)
                  a11z = q(5) * bz(1 + oz, 1) + q(8) * bz(3 + oz, 1)
               end associate
               b0 = a00 * by(1 + oy, 0) + a01 * by(3 + oy, 0)
               b1 = a10 * by(1 + oy, 0) + a11 * by(3 + oy, 0)
               b0y = a00 * by(1 + oy, 1) + a01 * by(3 + oy, 1)
               b1y = a10 * by(1 + oy, 1) + a11 * by(3 + oy, 1)
               b0z = a00z * by(1 + oy, 0) + a01z * by(3 + oy, 0)
               b1z = a10z * by(1 + oy, 0) + a11z * by(3 + oy, 0)
               v = v + b0 * bx(1 + ox, 0) + b1 * bx(3 + ox, 0)
               g(1) = g(1) + b0 * bx(1 + ox, 1) + b1 * bx(3 + ox, 1)
               g(2) = g(2) + b0y * bx(1 + ox, 0) + b1y * bx(3 + ox, 0)
               g(3) = g(3) + b0z * bx(1 + ox, 0) + b1z * bx(3 + ox, 0)
            end do
         end do
      end do
   end subroutine value_gradient

   !> The 64 Hermite data of cell (i, j, k): index 1, 2 the lower and upper
   !> node's value along an axis, 3, 4 their derivatives.
   pure function hermite_data(self, i, j, k) result(c)
      type(tricubic_grid), intent(in) :: self
      integer, intent(in) :: i, j, k
      real(wp) :: c(4, 4, 4)
      integer :: ox, oy, oz

      do oz = 0, 1
         do oy = 0, 1
            do ox = 0, 1
               associate (q => self%node(:, i + 1 + ox, j + 1 + oy, k + oz))
                  c(1 + ox, 1 + oy, 1 + oz) = q(1)
                  c(3 + ox, 1 + oy, 1 + oz) = q(2)
                  c(1 + ox, 3 + oy, 1 + oz) = q(3)
                  c(1 + ox, 1 + oy, 3 + oz) = q(4)
                  c(3 + ox, 3 + oy, 1 + oz) = q(5)
                  c(3 + ox, 1 + oy, 3 + oz) = q(6)
                  c(1 + ox, 3 + oy, 3 + oz) = q(7)
                  c(3 + ox, 3 + oy, 3 + oz) = q(8)
               end associate
            end do
         end do
      end do
   end function hermite_data

   !> The value, gradient and Hessian in cell (i, j, k) (see value_gradient):
   !> the 64 coefficients in the Hermite basis (index 1, 2 the values at the
   !> lower and upper node of an axis, 3, 4 the slopes there), contracted
   !> along z, y and x.
   pure subroutine with_hessian(self, i, j, k, bx, by, bz, v, g, h)
      type(tricubic_grid), intent(in) :: self
      integer, intent(in) :: i, j, k
      real(wp), intent(in) :: bx(4, 0:2), by(4, 0:2), bz(4, 0:2)
      real(wp), intent(out) :: v, g(3), h(3, 3)
      real(wp) :: c(4, 4, 4), z0(4, 4), z1(4, 4), z2(4, 4), y00(4), y10(4), y01(4), y11(4), y20(4), y02(4)

      c = hermite_data(self, i, j, k)
      ! (zN: N-th z derivative; yMN: M-th in y, N-th in z.)
      z0 = c(:, :, 1) * bz(1, 0) + c(:, :, 2) * bz(2, 0) + c(:, :, 3) * bz(3, 0) + c(:, :, 4) * bz(4, 0)
      z1 = c(:, :, 1) * bz(1, 1) + c(:, :, 2) * bz(2, 1) + c(:, :, 3) * bz(3, 1) + c(:, :, 4) * bz(4, 1)
      z2 = c(:, :, 1) * bz(1, 2) + c(:, :, 2) * bz(2, 2) + c(:, :, 3) * bz(3, 2) + c(:, :, 4) * bz(4, 2)
      y00 = matmul(z0, by(:, 0))
      y10 = matmul(z0, by(:, 1))
      y01 = matmul(z1, by(:, 0))
      y11 = matmul(z1, by(:, 1))
      y20 = matmul(z0, by(:, 2))
      y02 = matmul(z2, by(:, 0))
      v = dot_product(y00, bx(:, 0))
      g(1) = dot_product(y00, bx(:, 1))
      g(2) = dot_product(y10, bx(:, 0))
      g(3) = dot_product(y01, bx(:, 0))
      h(1, 1) = dot_product(y00, bx(:, 2))
      h(2, 2) = dot_product(y20, bx(:, 0))
      h(3, 3) = dot_product(y02, bx(:, 0))
      h(1, 2) = dot_product(y10, bx(:, 1))
      h(1, 3) = dot_product(y01, bx(:, 1))
      h(2, 3) = dot_product(y11, bx(:, 0))
      h(2, 1) = h(1, 2)
      h(3, 1) = h(1, 3)
      h(3, 2) = h(2, 3)
   end subroutine with_hessian

   !> The cubic Hermite basis on a cell of width w (and its reciprocal) at
   !> t = (x - x_lower)/w:
   !> b(1:4, 0) the functions multiplying the lower value, the upper value,
   !> the lower slope and the upper slope (the slope functions carry the
   !> factor w, so the node data are plain derivatives), b(:, 1) and
   !> b(:, 2) their first and second derivatives in x (up to `order`).
   pure subroutine hermite_basis(t, w, inverse_w, order, b)
      real(wp), intent(in) :: t, w, inverse_w
      integer, intent(in) :: order
      real(wp), intent(out) :: b(4, 0:2)
      real(wp) :: t2, t3

      t2 = t * t
      t3 = t2 * t
      b(1, 0) = 2.0_wp * t3 - 3.0_wp * t2 + 1.0_wp
      b(2, 0) = -2.0_wp * t3 + 3.0_wp * t2
      b(3, 0) = (t3 - 2.0_wp * t2 + t) * w
      b(4, 0) = (t3 - t2) * w
      b(:, 1:2) = 0.0_wp
      if (order < 1) return
      b(1, 1) = (6.0_wp * t2 - 6.0_wp * t) * inverse_w
      b(2, 1) = -b(1, 1)
      b(3, 1) = 3.0_wp * t2 - 4.0_wp * t + 1.0_wp
      b(4, 1) = 3.0_wp * t2 - 2.0_wp * t
      if (order < 2) return
      b(1, 2) = (12.0_wp * t - 6.0_wp) * inverse_w**2
      b(2, 2) = -b(1, 2)
      b(3, 2) = (6.0_wp * t - 4.0_wp) * inverse_w
      b(4, 2) = (6.0_wp * t - 2.0_wp) * inverse_w
   end subroutine hermite_basis

end module friction_surface_tricubic
