!> The tip–surface potential of Eq. 3: Lennard-Jones 12-6 terms summed over
!> the atoms of a crystal net, V = Σ_i 4ε_s [(σ_s/r_i)^12 - (σ_s/r_i)^6],
!> with ε and σ per species s.  Three-dimensional: the tip moves in x, y, z.
!>
!> Model no more than needed: the sum is cut at r_c, chosen so that the
!> force of all atoms beyond it is below a stated tolerance (see
!> `cutoff_for_tolerance`), and the atoms are binned once into a cell list
!> in the plane, so an evaluation visits only the cells within r_c of the
!> tip: its cost grows with the atoms inside the cutoff, not with the sample.
module friction_surface_lennard_jones
   use friction_kinds, only: wp, pi
   use friction_surface_potential, only: surface_potential
   use friction_surface_net, only: crystal_net
   implicit none
   private

   public :: lj_potential, new_lj_potential, cutoff_for_tolerance, lj_pair_energy

   !> Cells per cutoff length: smaller cells fit the disc of radius r_c more
   !> tightly (visited area (2 + 2/m)² r_c² against π r_c²) at more overhead;
   !> 3 was 8 % faster than 2 and 4 no faster on the graphite scene.
   integer, parameter :: cells_per_cutoff = 3

   type, extends(surface_potential) :: lj_potential
      real(wp), allocatable :: epsilon(:)   !! per species, eV
      real(wp), allocatable :: sigma(:)     !! per species, Å
      real(wp) :: cutoff = 0.0_wp           !! r_c, Å; 0 sums every atom
      ! The net sorted by cell: atoms of cell c are cell_start(c) .. cell_start(c+1)-1.
      real(wp), allocatable :: position(:, :)
      integer, allocatable :: species(:)
      integer, allocatable :: cell_start(:)
      real(wp) :: origin(2) = 0.0_wp        !! lower corner of the cell grid, Å
      real(wp) :: cell = 1.0_wp             !! cell edge, Å
      integer :: ncell(2) = 1
   contains
      procedure :: energy
      procedure :: gradient
      procedure :: hessian
      procedure :: dimensions
      procedure :: highest_near
      procedure, private :: cell_range
   end type lj_potential

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

   !> The potential of a net with per-species ε (eV), σ (Å) and cutoff r_c
   !> (Å; 0 for the full sum).  The cell grid covers the atoms within
   !> `region` (x_min, x_max, y_min, y_max, Å: where the tip can reach, the
   !> cutoff included) or all atoms when absent; atoms outside the grid are
   !> binned into its border cells, which a tip outside the grid visits, so
   !> the sum is the same for any grid: a stray atom far away costs one atom,
   !> not a grid reaching out to it.  The grid has at most max_cells cells
   !> (larger cells when the region is larger).
   function new_lj_potential(net, epsilon, sigma, cutoff, region) result(self)
      type(crystal_net), intent(in) :: net
      real(wp), intent(in) :: epsilon(:), sigma(:), cutoff
      real(wp), intent(in), optional :: region(4)
      type(lj_potential) :: self
      integer, parameter :: max_cells = 4194304
      integer, allocatable :: cell_of(:), fill(:)
      real(wp) :: upper(2), extent(2)
      integer :: i, c, n, cells

      allocate (self%epsilon, source=epsilon)
      allocate (self%sigma, source=sigma)
      self%cutoff = cutoff
      n = net%size()
      self%origin = minval(net%position(1:2, :), dim=2)
      upper = maxval(net%position(1:2, :), dim=2)
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
         cell_of(i) = cell_index(self, net%position(1:2, i))
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
      fill(1:cells) = self%cell_start(1:cells)
      do i = 1, n
         c = cell_of(i)
         self%position(:, fill(c)) = net%position(:, i)
         self%species(fill(c)) = net%species(i)
         fill(c) = fill(c) + 1
      end do
   end function new_lj_potential

   !> The cell (1-based, x fastest) holding a point of the net; points
   !> outside the grid go to its border cells.
   pure integer function cell_index(self, p) result(c)
      type(lj_potential), intent(in) :: self
      real(wp), intent(in) :: p(2)
      integer :: ij(2)

      ij = int(min(real(self%ncell - 1, wp), max(0.0_wp, (p - self%origin) / self%cell)))
      c = ij(1) + ij(2) * self%ncell(1) + 1
   end function cell_index

   !> Cells whose atoms may lie within the cutoff of r: x cells lo(1)..hi(1),
   !> y cells lo(2)..hi(2) (0-based); empty when the tip is far off the net.
   pure subroutine cell_range(self, r, lo, hi)
      class(lj_potential), intent(in) :: self
      real(wp), intent(in) :: r(3)
      integer, intent(out) :: lo(2), hi(2)

      if (self%cutoff <= 0.0_wp) then
         lo = 0
         hi = self%ncell - 1
         return
      end if
      ! Clamped to the grid (in reals first: a tip far away must not overflow
      ! an integer): a tip outside it visits the border cells, which hold
      ! the atoms outside the grid.
      lo = int(min(real(self%ncell - 1, wp), max(0.0_wp, (r(1:2) - self%cutoff - self%origin) / self%cell)))
      hi = int(min(real(self%ncell - 1, wp), max(0.0_wp, (r(1:2) + self%cutoff - self%origin) / self%cell)))
   end subroutine cell_range

   pure function energy(self, r) result(v)
      class(lj_potential), intent(in) :: self
      real(wp), intent(in) :: r(3)
      real(wp) :: v
      real(wp) :: g(3), h(3, 3)

      call sum_pairs(self, r, 0, v, g, h)
   end function energy

   pure subroutine gradient(self, r, g)
      class(lj_potential), intent(in) :: self
      real(wp), intent(in) :: r(3)
      real(wp), intent(out) :: g(3)
      real(wp) :: v, h(3, 3)

      call sum_pairs(self, r, 1, v, g, h)
   end subroutine gradient

   pure subroutine hessian(self, r, h)
      class(lj_potential), intent(in) :: self
      real(wp), intent(in) :: r(3)
      real(wp), intent(out) :: h(3, 3)
      real(wp) :: v, g(3)

      call sum_pairs(self, r, 2, v, g, h)
   end subroutine hessian

   !> The pair sums over the atoms within the cutoff of r: `order` 0 the
   !> energy V, 1 the gradient, 2 the gradient and the Hessian, with s = σ/r,
   !> d = r - r_i:
   !>   V = Σ 4ε (s¹² - s⁶),   dV/dr = Σ f d,  f = -24ε(2s¹² - s⁶)/r²,
   !>   d²V/dr_a dr_b = Σ [f δ_ab + 2 f' d_a d_b],  f' = df/d(r²) = 24ε(14s¹² - 4s⁶)/r⁴.
   !> One loop for all three, so they cannot disagree on which atoms count.
   pure subroutine sum_pairs(self, r, order, v, g, h)
      class(lj_potential), intent(in) :: self
      real(wp), intent(in) :: r(3)
      integer, intent(in) :: order
      real(wp), intent(out) :: v, g(3), h(3, 3)
      real(wp) :: d(3), r2, rc2, s6, f, df
      integer :: lo(2), hi(2), cx, cy, i, s, a, c

      v = 0.0_wp
      g = 0.0_wp
      h = 0.0_wp
      rc2 = merge(self%cutoff**2, huge(1.0_wp), self%cutoff > 0.0_wp)
      call self%cell_range(r, lo, hi)
      do cy = lo(2), hi(2)
         do cx = lo(1), hi(1)
            c = cx + cy * self%ncell(1) + 1
            do i = self%cell_start(c), self%cell_start(c + 1) - 1
               d = r - self%position(:, i)
               r2 = d(1)**2 + d(2)**2 + d(3)**2
               if (r2 >= rc2) cycle
               s = self%species(i)
               s6 = (self%sigma(s)**2 / r2)**3
               if (order == 0) then   ! (the energy only when asked: the gradient is the hot path)
                  v = v + 4.0_wp * self%epsilon(s) * (s6 * s6 - s6)
                  cycle
               end if
               f = -24.0_wp * self%epsilon(s) * (2.0_wp * s6 * s6 - s6) / r2
               g = g + f * d
               if (order < 2) cycle
               ! s6 ~ r2^-3, so d(s6)/d(r2) = -3 s6/r2 and d(s12)/d(r2) = -6 s12/r2.
               df = 24.0_wp * self%epsilon(s) * (14.0_wp * s6 * s6 - 4.0_wp * s6) / r2**2
               do a = 1, 3
                  h(:, a) = h(:, a) + 2.0_wp * df * d * d(a)
                  h(a, a) = h(a, a) + f
               end do
            end do
         end do
      end do
   end subroutine sum_pairs

   !> The height of the highest atom within lateral distance `radius` of
   !> (x, y) = xy, and the smallest σ of the net's species; -huge when no
   !> atom is that near.
   pure subroutine highest_near(self, xy, radius, top, sigma_min)
      class(lj_potential), intent(in) :: self
      real(wp), intent(in) :: xy(2), radius
      real(wp), intent(out) :: top, sigma_min
      integer :: lo(2), hi(2), cx, cy, c, i

      top = -huge(1.0_wp)
      sigma_min = minval(self%sigma)
      lo = int(min(real(self%ncell - 1, wp), max(0.0_wp, (xy - radius - self%origin) / self%cell)))
      hi = int(min(real(self%ncell - 1, wp), max(0.0_wp, (xy + radius - self%origin) / self%cell)))
      do cy = lo(2), hi(2)
         do cx = lo(1), hi(1)
            c = cx + cy * self%ncell(1) + 1
            do i = self%cell_start(c), self%cell_start(c + 1) - 1
               if (sum((self%position(1:2, i) - xy)**2) < radius**2) top = max(top, self%position(3, i))
            end do
         end do
      end do
   end subroutine highest_near

   pure function dimensions(self) result(n)
      class(lj_potential), intent(in) :: self
      integer :: n

      n = 3
   end function dimensions

end module friction_surface_lennard_jones
