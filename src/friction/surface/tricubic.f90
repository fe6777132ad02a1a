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
   implicit none
   private

   public :: tricubic_grid, new_tricubic_grid, n_node_values

   !> Values per node: f, f_x, f_y, f_z, f_xy, f_xz, f_yz, f_xyz.
   integer, parameter :: n_node_values = 8

   type :: tricubic_grid
      real(wp) :: x0 = 0.0_wp, hx = 1.0_wp   !! first node and spacing along x
      real(wp) :: y0 = 0.0_wp, hy = 1.0_wp   !! along y
      integer :: nx = 0, ny = 0              !! nodes along x and y (>= 2)
      real(wp), allocatable :: z(:)          !! node heights, strictly increasing (>= 2)
      !> The layer below each of nbins equal bins of [z(1), z(nz)], finer
      !> than the closest layers, so that layer_below looks at one or two.
      integer, allocatable :: bin_layer(:)
      real(wp) :: bin_width = 1.0_wp
      ! Reciprocals, so that an evaluation divides by nothing.
      real(wp) :: inverse_hx = 1.0_wp, inverse_hy = 1.0_wp, inverse_bin = 1.0_wp
      real(wp), allocatable :: inverse_dz(:)
      !> node(:, i, j, k): the eight values of node (x0 + (i-1) hx, y0 + (j-1) hy, z(k))
      real(wp), allocatable :: node(:, :, :, :)
   contains
      procedure :: evaluate
      procedure :: layer_below
      procedure :: bytes
   end type tricubic_grid

contains

   !> A grid of nx x ny x size(z) nodes, its values zero.
   pure function new_tricubic_grid(x0, hx, nx, y0, hy, ny, z) result(grid)
      real(wp), intent(in) :: x0, hx, y0, hy, z(:)
      integer, intent(in) :: nx, ny
      type(tricubic_grid) :: grid
      integer :: b, k, nbins

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
      allocate (grid%node(n_node_values, nx, ny, size(z)), source=0.0_wp)
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

   !> Memory of the node values, bytes.
   pure real(wp) function bytes(self)
      class(tricubic_grid), intent(in) :: self

      bytes = 0.0_wp
      if (allocated(self%node)) bytes = real(storage_size(self%node), wp) / 8.0_wp * real(size(self%node), wp)
   end function bytes

   !> The layer k with z(k) <= height < z(k+1) (1 <= k <= nz - 1; the end
   !> layers for heights outside: the interpolant continues as a cubic).
   pure integer function layer_below(self, height) result(k)
      class(tricubic_grid), intent(in) :: self
      real(wp), intent(in) :: height
      integer :: last

      last = size(self%z) - 1
      k = self%bin_layer(int(min(real(size(self%bin_layer), wp), max(1.0_wp, &
         & (height - self%z(1)) * self%inverse_bin + 1.0_wp))))
      ! (A bin is narrower than any layer: at most one layer starts in it.)
      do while (k < last)
         if (self%z(k + 1) > height) exit
         k = k + 1
      end do
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
      k = self%layer_below(p(3))
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
