!> The atoms of a net binned into square cells in the plane, for the pair
!> sums of the Lennard-Jones lattice sum cut at r_c (its direct sum in
!> friction_surface_lennard_jones, the table's build in
!> friction_surface_lattice_table): a sum visits only the cells within r_c
!> of its point, so its cost grows with the atoms inside the cutoff, not
!> with the sample.  With the pair's energy and the cutoff that keeps the
!> force of the atoms beyond it below a tolerance.
module friction_surface_pair_cells
   use friction_kinds, only: wp, pi
   implicit none
   private

   public :: atom_cells, new_atom_cells, cell_range, lj_pair_energy, cutoff_for_tolerance

   !> Cells per cutoff length: smaller cells fit the disc of radius r_c more
   !> tightly (visited area (2 + 2/m)² r_c² against π r_c²) at more overhead;
   !> 3 is the fastest on graphite (docs/speed.md).
   integer, parameter :: cells_per_cutoff = 3

   !> Atoms binned into a grid of square cells in the plane: the atoms of
   !> cell c are cell_start(c) .. cell_start(c+1)-1.
   type :: atom_cells
      real(wp), allocatable :: position(:, :)
      integer, allocatable :: species(:)
      real(wp), allocatable :: weight(:)    !! ±1 for a table's differences; absent: 1
      integer, allocatable :: cell_start(:)
      real(wp) :: origin(2) = 0.0_wp        !! lower corner of the cell grid, Å
      real(wp) :: cell = 1.0_wp             !! cell edge, Å
      integer :: ncell(2) = 1
   end type atom_cells

contains

   !> One pair's energy 4ε[(σ/r)^12 - (σ/r)^6] at distance r.
   pure elemental real(wp) function lj_pair_energy(epsilon, sigma, r) result(v)
      real(wp), intent(in) :: epsilon, sigma, r
      real(wp) :: s6

      s6 = (sigma / r)**6
      v = 4.0_wp * epsilon * (s6 * s6 - s6)
   end function lj_pair_energy

   !> The cutoff beyond which the atoms of a net of areal density `density`
   !> (atoms/Å²) exert less than `tolerance` (eV/Å) on the tip, bounding the
   !> tail by the integral of |F| = 24εσ⁶/r⁷ (1 - 2(σ/r)⁶) <= 24εσ⁶/r⁷ (r > σ)
   !> over the plane outside r_c:
   !>   Σ_{r > r_c} |F| ≈ ∫ 24εσ⁶/r⁷ ρ 2πr dr = 48π ρ ε σ⁶ / (5 r_c⁵).
   !> The bound ignores that opposite atoms cancel, so the true error is
   !> smaller; tests check it against the full sum.
   pure real(wp) function cutoff_for_tolerance(epsilon, sigma, density, tolerance) result(rc)
      real(wp), intent(in) :: epsilon, sigma, density, tolerance

      rc = (48.0_wp * pi * density * epsilon * sigma**6 / (5.0_wp * tolerance))**0.2_wp
      rc = max(rc, 2.0_wp * sigma)
   end function cutoff_for_tolerance

   !> Atoms binned for sums cut at `cutoff` (see friction_surface_lennard_jones'
   !> new_lj_potential).
   function new_atom_cells(position, species, cutoff, region, weight) result(self)
      real(wp), intent(in) :: position(:, :)
      integer, intent(in) :: species(:)
      real(wp), intent(in) :: cutoff
      real(wp), intent(in), optional :: region(4)
      real(wp), intent(in), optional :: weight(:)
      type(atom_cells) :: self
      integer, parameter :: max_cells = 4194304
      integer, allocatable :: cell_of(:), fill(:)
      real(wp) :: upper(2), extent(2)
      integer :: i, c, n, cells

      n = size(species)
      if (n > 0) then
         self%origin = minval(position(1:2, :), dim=2)
         upper = maxval(position(1:2, :), dim=2)
      else
         self%origin = 0.0_wp
         upper = 0.0_wp
      end if
      if (present(region)) then
         self%origin = max(self%origin, [region(1), region(3)])
         upper = min(upper, [region(2), region(4)])
         upper = max(upper, self%origin)   ! no atom in the region: one row or column of cells
      end if
      self%origin = self%origin - 1.0e-9_wp
      upper = upper + 1.0e-9_wp
      extent = upper - self%origin
      if (cutoff > 0.0_wp) then
         self%cell = cutoff / cells_per_cutoff
         do while ((extent(1) / self%cell + 1.0_wp) * (extent(2) / self%cell + 1.0_wp) > max_cells)
            self%cell = 1.5_wp * self%cell
         end do
      else
         self%cell = max(extent(1), extent(2)) + 1.0_wp
      end if
      self%ncell = max(1, min(max_cells, ceiling(min(extent / self%cell, real(max_cells, wp)))))
      cells = self%ncell(1) * self%ncell(2)
      allocate (cell_of(n), fill(cells + 1))
      do i = 1, n
         cell_of(i) = cell_index(self, position(1:2, i))
      end do
      ! Counting sort of the atoms by cell (stable: keeps the net's order).
      fill = 0
      do i = 1, n
         fill(cell_of(i) + 1) = fill(cell_of(i) + 1) + 1
      end do
      allocate (self%cell_start(cells + 1))
      self%cell_start(1) = 1
      do c = 1, cells
         self%cell_start(c + 1) = self%cell_start(c) + fill(c + 1)
      end do
      allocate (self%position(3, n), self%species(n))
      if (present(weight)) allocate (self%weight(n))
      fill(1:cells) = self%cell_start(1:cells)
      do i = 1, n
         c = cell_of(i)
         self%position(:, fill(c)) = position(:, i)
         self%species(fill(c)) = species(i)
         if (present(weight)) self%weight(fill(c)) = weight(i)
         fill(c) = fill(c) + 1
      end do
   end function new_atom_cells

   !> The cell (1-based, x fastest) holding a point of the net; points
   !> outside the grid go to its border cells.
   pure integer function cell_index(self, p) result(c)
      type(atom_cells), intent(in) :: self
      real(wp), intent(in) :: p(2)
      integer :: ij(2)

      ij = int(min(real(self%ncell - 1, wp), max(0.0_wp, (p - self%origin) / self%cell)))
      c = ij(1) + ij(2) * self%ncell(1) + 1
   end function cell_index

   !> Cells whose atoms may lie within `radius` of xy in the plane: x cells
   !> lo(1)..hi(1), y cells lo(2)..hi(2) (0-based); radius <= 0: all cells.
   !> Clamped to the grid (in reals first: a tip far away must not overflow
   !> an integer): a tip outside it visits the border cells, which hold the
   !> atoms outside the grid.
   pure subroutine cell_range(self, xy, radius, lo, hi)
      type(atom_cells), intent(in) :: self
      real(wp), intent(in) :: xy(2), radius
      integer, intent(out) :: lo(2), hi(2)

      if (radius <= 0.0_wp) then
         lo = 0
         hi = self%ncell - 1
         return
      end if
      lo = int(min(real(self%ncell - 1, wp), max(0.0_wp, (xy - radius - self%origin) / self%cell)))
      hi = int(min(real(self%ncell - 1, wp), max(0.0_wp, (xy + radius - self%origin) / self%cell)))
   end subroutine cell_range

end module friction_surface_pair_cells
