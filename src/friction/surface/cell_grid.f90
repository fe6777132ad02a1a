!> The part of a tricubic grid (friction_surface_tricubic) that an
!> evaluation through its cells' polynomials reads: the axes, the layers'
!> search table and the polynomials.  A type of its own so that the table's
!> kernels (table_kernels.F90), compiled for two processor levels, can take
!> a whole grid and do every step of an evaluation in one routine.
module friction_surface_cell_grid
   use friction_kinds, only: wp
   implicit none
   private

   public :: cell_grid

   type :: cell_grid
      real(wp) :: x0 = 0.0_wp, hx = 1.0_wp   !! first node and spacing along x
      real(wp) :: y0 = 0.0_wp, hy = 1.0_wp   !! along y
      integer :: nx = 0, ny = 0              !! nodes along x and y (>= 2)
      real(wp), allocatable :: z(:)          !! node heights, strictly increasing (>= 2)
      !> The layer below each of nbins equal bins of [z(1), z(nz)], finer
      !> than the closest layers, so that the layer search looks at one or two.
      integer, allocatable :: bin_layer(:)
      real(wp) :: bin_width = 1.0_wp
      ! Reciprocals, so that an evaluation divides by nothing.
      real(wp) :: inverse_hx = 1.0_wp, inverse_hy = 1.0_wp, inverse_bin = 1.0_wp
      real(wp), allocatable :: inverse_dz(:)
      !> cell(:, c): when allocated, the polynomial of a cell in its local
      !> coordinates ξ, η, ζ in [0, 1], coefficient 1 + l + 4m + 16n of
      !> ξ^l η^m ζ^n; cell (i, j) of layer k (i, j 0-based, k the layer
      !> below) is c = slot(i, j) + slots (k - 1), evaluated at the point
      !> mapped by image(i, j) (the kernels' image_point).
      real(wp), allocatable :: cell(:, :)
      integer, allocatable :: slot(:, :), image(:, :)
      integer :: slots = 0
   end type cell_grid

end module friction_surface_cell_grid
