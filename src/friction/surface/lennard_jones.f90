!> The tip–surface potential of Eq. 3: Lennard-Jones 12-6 terms summed over
!> the atoms of a crystal net, V = Σ_i 4ε_s [(σ_s/r_i)^12 - (σ_s/r_i)^6],
!> with ε and σ per species s.  Three-dimensional: the tip moves in x, y, z.
!>
!> Model no more than needed: the sum is cut at r_c, chosen so that the
!> force of all atoms beyond it is below a stated tolerance (see
!> `cutoff_for_tolerance`), and the atoms are binned once into a cell list
!> in the plane, so an evaluation visits only the cells within r_c of the
!> tip: its cost grows with the atoms inside the cutoff, not with the sample.
!>
!> Tabulated evaluation (`tabulate`, docs/physics.md, "The tabulated
!> surface"): a net cut from a periodic lattice is the perfect lattice plus
!> its differences (the sites outside a flake, vacancies, substitutions),
!> so V = V_lattice + Σ_differences ±φ.  V_lattice is periodic: it is
!> tabulated once over one cell of the lattice (tricubic Hermite,
!> friction_surface_tricubic) and the few differences within r_c of the tip
!> are summed directly.  The table answers where the tip can be, above a
!> floor set by an energy cap; elsewhere the direct sum does.
module friction_surface_lennard_jones
   use friction_kinds, only: wp, pi
   use friction_surface_potential, only: surface_potential
   use friction_surface_net, only: crystal_net, net_lattice, fraction_map
   use friction_surface_tricubic, only: tricubic_grid, new_tricubic_grid, n_node_values
   use friction_surface_table_kernels, only: column_sums, difference_terms, column_lanes, lattice_gradient, &
      & cell_fraction, from_fraction
   use friction_surface_table_kernels_wide, only: column_sums_wide => column_sums, &
      & lattice_gradient_wide => lattice_gradient
   use friction_strings, only: rtoa, itoa
   use friction_sharing, only: work_sharing
   use, intrinsic :: iso_c_binding, only: c_int
   implicit none
   private

   public :: lj_potential, new_lj_potential, cutoff_for_tolerance, lj_pair_energy, lj_table, table_settings

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

   !> A table's differences as lists per square cell of the plane: list c
   !> holds every difference within the cutoff of any point of cell c
   !> (copied, so that a list lies in one piece), entries start(c) ..
   !> start(c+1)-1.  Most of the tip's path has empty lists: no cell walk.
   type :: difference_lists
      !> one array per quantity, for difference_terms: the position x, y, z,
      !> σ², 4εw and φ(r_c)w, with w = +1 an atom the lattice lacks, -1 a
      !> site the net lacks
      real(wp), allocatable :: x(:), y(:), z(:), sigma2(:), e4w(:), shiftw(:)
      integer, allocatable :: start(:)
      real(wp) :: origin(2) = 0.0_wp, cell = 1.0_wp, inverse_cell = 1.0_wp
      integer :: ncell(2) = 1
   end type difference_lists

   !> The pairs of one column of the table's build (column_values), kept
   !> from column to column: one array per quantity, as column_sums wants.
   type :: column_pairs
      integer :: n = 0                      !! pairs (padded: gather_pairs)
      real(wp) :: rc2 = 0.0_wp              !! the cutoff squared, Å²
      real(wp), allocatable :: u1(:), u2(:), u12(:), lateral(:), height(:), sigma2(:), e4(:), shift(:)
   end type column_pairs

   !> How to build a table (`tabulate`).
   type :: table_settings
      !> largest force error allowed against the direct sum, eV/Å
      real(wp) :: tolerance = 1.0e-4_wp / 1.602176634_wp
      !> the table answers where the perfect lattice's energy is at most
      !> this much above its minimum, eV; closer to the atoms the direct sum
      real(wp) :: energy_window = 1.0_wp
      real(wp) :: max_bytes = 512.0_wp * 1024.0_wp**2   !! the largest table allowed
      !> box (x_min, x_max, y_min, y_max), Å, where the table answers: the
      !> differences are complete within the cutoff of it
      real(wp) :: box(4) = 0.0_wp
      integer :: verify_points = 4096   !! points checked against the direct sum
      !> build and evaluate through the kernels compiled for AVX2 where the
      !> processor of every process sharing the build has it (the same
      !> values to rounding: friction_surface_table_kernels)
      logical :: wide_kernels = .true.
      !> compute the nodes of one column in each orbit of the lattice's
      !> whole point group (graphite: a twelfth), not only under s -> -s and
      !> the swap (a quarter); the same nodes to rounding (tests `table`)
      logical :: point_group = .true.
   end type table_settings

   !> The identity and the swap of fractional coordinates, s -> (s2, s1),
   !> as elements of a lattice's point group (point_group).
   integer, parameter :: identity_op(2, 2) = reshape([1, 0, 0, 1], [2, 2]), swap_op(2, 2) = reshape([0, 1, 1, 0], [2, 2])

   !> The tabulated perfect lattice and the net's differences from it.
   type :: lj_table
      type(tricubic_grid) :: grid           !! V over (s1, s2, z): s the fractional coordinates
      real(wp) :: vectors(2, 2) = 0.0_wp    !! the lattice vectors (columns), Å
      real(wp) :: to_fraction(2, 2) = 0.0_wp   !! s = to_fraction (x, y)
      real(wp) :: box(4) = 0.0_wp           !! where the table answers, Å
      real(wp) :: floor = 0.0_wp            !! lowest height of the table, Å
      real(wp) :: top = 0.0_wp              !! the lattice's V is zero above, Å
      real(wp) :: ceiling = 0.0_wp          !! every atom beyond the cutoff above, Å
      real(wp) :: energy_cap = 0.0_wp       !! the table answers where V_lattice <= this, eV
      real(wp), allocatable :: shift(:)     !! φ_s(r_c) per species, eV
      type(difference_lists) :: differences   !! the net less the lattice
      ! What was built and measured (for the output file).
      integer :: nodes(3) = 0               !! nodes per cell along a1, a2 and layers
      real(wp) :: error = 0.0_wp            !! largest force error found, eV/Å
      real(wp) :: tolerance = 0.0_wp        !! the bound, eV/Å
      real(wp) :: energy_window = 0.0_wp    !! eV
      integer :: points = 0                 !! points the error was measured at
      integer :: difference_count = 0       !! atoms in the differences
   end type lj_table

   type, extends(surface_potential) :: lj_potential
      real(wp), allocatable :: epsilon(:)   !! per species, eV
      real(wp), allocatable :: sigma(:)     !! per species, Å
      real(wp) :: cutoff = 0.0_wp           !! r_c, Å; 0 sums every atom
      type(atom_cells) :: atoms             !! the net, binned
      logical :: tabulated = .false.        !! evaluate through `table` where it answers
      type(lj_table) :: table
   contains
      procedure :: energy
      procedure :: gradient
      procedure :: hessian
      procedure :: dimensions
      procedure :: highest_near
      procedure :: tabulate
      procedure :: table_answers
      procedure :: direct_gradient
   end type lj_potential

   interface
      !> Whether the kernels compiled for AVX2 (x86-64-v3) can run here:
      !> this build has them and the processor has the instructions (cpu.c).
      integer(c_int) function friction_wide_kernels() bind(c, name='friction_wide_kernels')
         import :: c_int
      end function friction_wide_kernels
   end interface

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

      allocate (self%epsilon, source=epsilon)
      allocate (self%sigma, source=sigma)
      self%cutoff = cutoff
      self%atoms = new_atom_cells(net%position, net%species, cutoff, region)
   end function new_lj_potential

   !> Atoms binned for sums cut at `cutoff` (see new_lj_potential).
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

   pure function energy(self, r) result(v)
      class(lj_potential), intent(in) :: self
      real(wp), intent(in) :: r(3)
      real(wp) :: v
      real(wp) :: g(3), h(3, 3)
      logical :: answered

      if (self%tabulated) then
         call self%table_answers(r, 0, answered, v, g, h)
         if (answered) return
      end if
      call sum_pairs(self, r, 0, v, g, h)
   end function energy

   pure subroutine gradient(self, r, g)
      class(lj_potential), intent(in) :: self
      real(wp), intent(in) :: r(3)
      real(wp), intent(out) :: g(3)
      real(wp) :: v, h(3, 3)
      logical :: answered

      if (self%tabulated) then
         call table_gradient(self, r, answered, g)
         if (answered) return
      end if
      call sum_pairs(self, r, 1, v, g, h)
   end subroutine gradient

   !> table_answers' gradient alone (the hot path of a tabulated surface):
   !> the same answer, bit for bit with the plain kernels and to rounding
   !> with the AVX2 ones, whose fused multiply-adds may fall differently in
   !> the two paths (tests `table`).
   pure subroutine table_gradient(self, r, answered, g)
      class(lj_potential), intent(in) :: self
      real(wp), intent(in) :: r(3)
      logical, intent(out) :: answered
      real(wp), intent(out) :: g(3)
      real(wp) :: v, h(3, 3)
      integer :: c

      g = 0.0_wp
      associate (t => self%table)
         answered = r(3) >= t%ceiling
         if (answered .or. .not. table_holds(t, r)) return
         v = 0.0_wp
         if (r(3) < t%top) then
            if (t%grid%wide) then
               call lattice_gradient_wide(t%grid%cell_grid, t%to_fraction, r, v, g)
            else
               call lattice_gradient(t%grid%cell_grid, t%to_fraction, r, v, g)
            end if
            if (v > t%energy_cap) then
               g = 0.0_wp
               return
            end if
         end if
         answered = .true.
         c = difference_cell(t%differences, r(1:2))
         if (c > 0) call difference_sums(self, r, c, 1, v, g, h)
      end associate
   end subroutine table_gradient

   !> Whether r lies between the table's floor and its ceiling and within
   !> its box (elsewhere the direct sum answers).
   pure logical function table_holds(t, r)
      type(lj_table), intent(in) :: t
      real(wp), intent(in) :: r(3)

      table_holds = .not. (r(3) < t%floor .or. r(1) < t%box(1) .or. r(1) > t%box(2) .or. r(2) < t%box(3) &
         & .or. r(2) > t%box(4))
   end function table_holds

   pure subroutine hessian(self, r, h)
      class(lj_potential), intent(in) :: self
      real(wp), intent(in) :: r(3)
      real(wp), intent(out) :: h(3, 3)
      real(wp) :: v, g(3)
      logical :: answered

      if (self%tabulated) then
         call self%table_answers(r, 2, answered, v, g, h)
         if (answered) return
      end if
      call sum_pairs(self, r, 2, v, g, h)
   end subroutine hessian

   !> The gradient of the direct sum, whatever the evaluation.
   pure subroutine direct_gradient(self, r, g)
      class(lj_potential), intent(in) :: self
      real(wp), intent(in) :: r(3)
      real(wp), intent(out) :: g(3)
      real(wp) :: v, h(3, 3)

      call sum_pairs(self, r, 1, v, g, h)
   end subroutine direct_gradient

   !> The pair sums over the atoms within the cutoff of r: `order` 0 the
   !> energy V, 1 the gradient, 2 the gradient and the Hessian, with s = σ/r,
   !> d = r - r_i:
   !>   V = Σ 4ε (s¹² - s⁶),   dV/dr = Σ f d,  f = -24ε(2s¹² - s⁶)/r²,
   !>   d²V/dr_a dr_b = Σ [f δ_ab + 2 f' d_a d_b],  f' = df/d(r²) = 24ε(14s¹² - 4s⁶)/r⁴.
   !> One loop for all three, so they cannot disagree on which atoms count.
   !> A tabulated potential's energies are shifted by φ(r_c) per pair (as its
   !> table's, so the energy is continuous where one hands over to the other).
   pure subroutine sum_pairs(self, r, order, v, g, h)
      class(lj_potential), intent(in) :: self
      real(wp), intent(in) :: r(3)
      integer, intent(in) :: order
      real(wp), intent(out) :: v, g(3), h(3, 3)
      real(wp) :: d(3), r2, rc2, s6
      integer :: lo(2), hi(2), cx, cy, i, s, c

      v = 0.0_wp
      g = 0.0_wp
      h = 0.0_wp
      rc2 = merge(self%cutoff**2, huge(1.0_wp), self%cutoff > 0.0_wp)
      call cell_range(self%atoms, r(1:2), self%cutoff, lo, hi)
      associate (atoms => self%atoms)
         do cy = lo(2), hi(2)
            do cx = lo(1), hi(1)
               c = cx + cy * atoms%ncell(1) + 1
               do i = atoms%cell_start(c), atoms%cell_start(c + 1) - 1
                  d = r - atoms%position(:, i)
                  r2 = d(1)**2 + d(2)**2 + d(3)**2
                  if (r2 >= rc2) cycle
                  s = atoms%species(i)
                  s6 = (self%sigma(s)**2 / r2)**3
                  if (order == 0) then   ! (the energy only when asked: the gradient is the hot path)
                     v = v + 4.0_wp * self%epsilon(s) * (s6 * s6 - s6)
                     if (self%tabulated) v = v - self%table%shift(s)
                     cycle
                  end if
                  call add_pair_derivatives(self%epsilon(s), s6, r2, d, order, g, h)
               end do
            end do
         end do
      end associate
   end subroutine sum_pairs

   !> One pair's share of sum_pairs' gradient (order >= 1) and Hessian
   !> (order 2), added to g and h: ε the pair's well depth (times a weight),
   !> s6 = (σ²/r²)³, d = r - r_i.
   pure subroutine add_pair_derivatives(epsilon, s6, r2, d, order, g, h)
      real(wp), intent(in) :: epsilon, s6, r2, d(3)
      integer, intent(in) :: order
      real(wp), intent(inout) :: g(3), h(3, 3)
      real(wp) :: f, df
      integer :: a

      f = -24.0_wp * epsilon * (2.0_wp * s6 * s6 - s6) / r2
      g = g + f * d
      if (order < 2) return
      ! s6 ~ r2^-3, so d(s6)/d(r2) = -3 s6/r2 and d(s12)/d(r2) = -6 s12/r2.
      df = 24.0_wp * epsilon * (14.0_wp * s6 * s6 - 4.0_wp * s6) / r2**2
      do a = 1, 3
         h(:, a) = h(:, a) + 2.0_wp * df * d * d(a)
         h(a, a) = h(a, a) + f
      end do
   end subroutine add_pair_derivatives

   !> The table's answer at r, when it has one (`answered`): above the
   !> ceiling zero (no atom within the cutoff); between the floor and the
   !> ceiling, inside the table's box and where the lattice's interpolated
   !> energy is at most the cap, the interpolated lattice plus the
   !> differences summed directly.  Elsewhere (near the atoms' cores, below
   !> the floor, outside the box) not answered: the direct sum's turn.
   pure subroutine table_answers(self, r, order, answered, v, g, h)
      class(lj_potential), intent(in) :: self
      real(wp), intent(in) :: r(3)
      integer, intent(in) :: order
      logical, intent(out) :: answered
      real(wp), intent(out) :: v, g(3), h(3, 3)
      integer :: c

      call lattice_answer(self%table, r, order, answered, v, g, h)
      if (.not. answered) return
      c = difference_cell(self%table%differences, r(1:2))
      if (c > 0) call difference_sums(self, r, c, order, v, g, h)
   end subroutine table_answers

   !> table_answers without the differences: whether the table answers at r,
   !> and the interpolated lattice's part of the answer.
   pure subroutine lattice_answer(t, r, order, answered, v, g, h)
      type(lj_table), intent(in) :: t
      real(wp), intent(in) :: r(3)
      integer, intent(in) :: order
      logical, intent(out) :: answered
      real(wp), intent(out) :: v, g(3), h(3, 3)
      real(wp) :: s(2), gs(3), hs(3, 3), m(2, 2)

      v = 0.0_wp
      g = 0.0_wp
      h = 0.0_wp
      answered = r(3) >= t%ceiling
      if (answered .or. .not. table_holds(t, r)) return
      if (r(3) < t%top) then
         m = t%to_fraction
         s = cell_fraction(t%to_fraction, r(1:2))
         ! (order 0: the energy alone; the cap needs it in any case)
         call t%grid%evaluate([s(1), s(2), r(3)], order, v, gs, hs)
         if (v > t%energy_cap) return
         if (order >= 1) g = from_fraction(t%to_fraction, gs)
         if (order >= 2) then
            h(1:2, 1:2) = matmul(transpose(m), matmul(hs(1:2, 1:2), m))
            h(1:2, 3) = matmul(transpose(m), hs(1:2, 3))
            h(3, 1:2) = h(1:2, 3)
            h(3, 3) = hs(3, 3)
         end if
      end if
      answered = .true.
   end subroutine lattice_answer

   !> The list (difference_lists' cell) of the differences near xy (Å),
   !> within the lists' region or at its edge; 0 when that list is empty.
   pure integer function difference_cell(list, xy) result(c)
      type(difference_lists), intent(in) :: list
      real(wp), intent(in) :: xy(2)
      integer :: ij(2)

      ij = int(min(real(list%ncell - 1, wp), max(0.0_wp, (xy - list%origin) * list%inverse_cell)))
      c = ij(1) + ij(2) * list%ncell(1) + 1
      if (list%start(c + 1) == list%start(c)) c = 0
   end function difference_cell

   !> Adds the pair terms of the table's differences within the cutoff of r
   !> (weight +1 an atom the lattice lacks, -1 a site the net lacks), with
   !> energies shifted by φ(r_c) as the table's; c the list near r, not
   !> empty (difference_cell).
   pure subroutine difference_sums(self, r, c, order, v, g, h)
      class(lj_potential), intent(in) :: self
      real(wp), intent(in) :: r(3)
      integer, intent(in) :: c, order
      real(wp), intent(inout) :: v, g(3), h(3, 3)
      real(wp) :: d(3), r2, rc2, s6, dv, dg(3)
      integer :: i

      rc2 = self%cutoff**2
      associate (list => self%table%differences)
         if (order < 2) then
            associate (from => list%start(c), to => list%start(c + 1) - 1)
               call difference_terms(to - from + 1, list%x(from:to), list%y(from:to), list%z(from:to), &
                  & list%sigma2(from:to), list%e4w(from:to), list%shiftw(from:to), rc2, r, order, dv, dg)
            end associate
            v = v + dv
            g = g + dg
            return
         end if
         ! (w ε = 4εw / 4 exactly, and w = ±1 multiplies exactly: the same
         ! terms as the direct sum's with w applied last.)
         do i = list%start(c), list%start(c + 1) - 1
            d = r - [list%x(i), list%y(i), list%z(i)]
            r2 = d(1)**2 + d(2)**2 + d(3)**2
            if (r2 >= rc2) cycle
            s6 = (list%sigma2(i) / r2)**3
            v = v + (list%e4w(i) * (s6 * s6 - s6) - list%shiftw(i))
            call add_pair_derivatives(0.25_wp * list%e4w(i), s6, r2, d, order, g, h)
         end do
      end associate
   end subroutine difference_sums

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
      call cell_range(self%atoms, xy, radius, lo, hi)
      do cy = lo(2), hi(2)
         do cx = lo(1), hi(1)
            c = cx + cy * self%atoms%ncell(1) + 1
            do i = self%atoms%cell_start(c), self%atoms%cell_start(c + 1) - 1
               if (sum((self%atoms%position(1:2, i) - xy)**2) < radius**2) top = max(top, self%atoms%position(3, i))
            end do
         end do
      end do
   end subroutine highest_near

   pure function dimensions(self) result(n)
      class(lj_potential), intent(in) :: self
      integer :: n

      n = 3
   end function dimensions

   ! ------------------------------------------------------------------
   ! Building the table
   ! ------------------------------------------------------------------

   !> Tabulate the potential of a net cut from `lattice` (docs/physics.md,
   !> "The tabulated surface"), so that its force is within
   !> settings%tolerance of the direct sum wherever the table answers.
   !> On success self%tabulated; otherwise `reason` says why not (and the
   !> potential stays the direct sum).
   !>
   !> 1. The lattice's sites near one cell, and the differences between the
   !>    net and the lattice within the cutoff of the box (atoms matched to
   !>    sites within 1e-8 Å and of the same species are the lattice's).
   !> 2. The heights: layers from the top (the lattice's atoms plus r_c,
   !>    where V is zero) down, each spacing as large as keeps the error of
   !>    the interpolation along z within 0.4 tolerance at check columns (36
   !>    and the atoms' sites), until every check column's energy is above
   !>    the cap (the lowest energy met plus the energy window): the floor.
   !> 3. The lateral spacing: as large as keeps the error within 0.4
   !>    tolerance at points in the layers, measured on trial spacings.
   !> 4. The table: every node of one cell on every layer, then the cells'
   !>    polynomials (once per orbit of the lattice's symmetries).
   !> 5. The check: the force against the direct sum over the net at
   !>    settings%verify_points quasi-random points (Halton, the same on
   !>    every rank) in the box where the table answers; above the tolerance
   !>    the targets are halved and the table built again (twice at most).
   subroutine tabulate(self, lattice, settings, reason, share)
      class(lj_potential), intent(inout) :: self
      type(net_lattice), intent(in) :: lattice
      type(table_settings), intent(in) :: settings
      character(len=:), allocatable, intent(out) :: reason
      !> the processes building the same table, each a share of its nodes and
      !> checks (absent: this process alone)
      class(work_sharing), intent(inout), optional :: share
      type(work_sharing) :: alone
      type(lj_potential) :: ideal
      type(lj_table) :: t
      real(wp), allocatable :: layers(:), node(:, :, :, :), cell(:, :)
      real(wp) :: target, spacing, vmin, measured, det
      integer :: attempt, n1, n2
      integer, allocatable :: group(:, :, :), nodes_group(:, :, :)

      reason = ''
      self%tabulated = .false.
      if (.not. (self%cutoff > 0.0_wp)) then
         reason = 'the table needs a finite cutoff'
         return
      end if
      t%vectors = lattice%vectors
      det = t%vectors(1, 1) * t%vectors(2, 2) - t%vectors(1, 2) * t%vectors(2, 1)
      if (.not. (abs(det) > 1.0e-6_wp)) then
         reason = 'the lattice vectors are parallel'
         return
      end if
      t%to_fraction = fraction_map(t%vectors)
      t%box = settings%box
      ! A lattice so dense that a node would sum more pairs than this, or a
      ! box holding more sites, costs more to tabulate than it saves.
      associate (per_site => abs(det) / size(lattice%species), box => settings%box, rc => self%cutoff)
         if (pi * rc**2 / per_site > 20000.0_wp) then
            reason = 'the lattice has '//itoa(nint(pi * rc**2 / per_site))//' sites within the cutoff: ' &
               & //'a table would cost more to build than it saves'
            return
         end if
         if ((box(2) - box(1) + 2 * rc + 2) * (box(4) - box(3) + 2 * rc + 2) / per_site > 2.0e6_wp) then
            reason = 'the box the tip can reach holds more than 2e6 sites of the lattice'
            return
         end if
      end associate
      t%tolerance = settings%tolerance
      t%energy_window = settings%energy_window
      ! (The grid's flag also chooses the build's kernels, from before the
      ! grid has nodes: column_values.)  The two copies round differently
      ! (the wide one fuses multiplies and adds), so the processes that
      ! share the build, and then the lines, take the wide copy only if
      ! every one of them can: the nodes and the lines' bits must not depend
      ! on which process computed them.
      if (present(share)) then
         t%grid%wide = all_can_go_wide(settings, share)
      else
         t%grid%wide = all_can_go_wide(settings, alone)
      end if
      t%shift = lj_pair_energy(self%epsilon, self%sigma, self%cutoff)
      t%top = maxval(lattice%basis(3, :)) + self%cutoff
      t%ceiling = max(t%top, maxval(self%atoms%position(3, :)) + self%cutoff)
      ideal = lattice_near_cell(self, lattice)
      call find_differences(self, lattice, t)
      if (mostly_different(self, t)) then
         reason = 'the net differs from its lattice at more places than it agrees with it, within the cutoff ' &
            & //'of the middle of the scan (a flake smaller than the cutoff, or no lattice): the direct sum is cheaper'
         return
      end if
      target = 0.4_wp * settings%tolerance
      group = point_group(lattice)
      nodes_group = group
      if (.not. settings%point_group) nodes_group = reflection_and_swap(group)
      do attempt = 1, 3
         if (present(share)) then
            call choose_layers(ideal, t, group, target, settings%energy_window, layers, vmin, reason, share)
         else
            call choose_layers(ideal, t, group, target, settings%energy_window, layers, vmin, reason, alone)
         end if
         if (len(reason) > 0) return
         t%energy_cap = vmin + settings%energy_window
         if (present(share)) then
            call choose_spacing(ideal, t, layers, target, spacing, reason, share)
         else
            call choose_spacing(ideal, t, layers, target, spacing, reason, alone)
         end if
         if (len(reason) > 0) return
         n1 = max(4, ceiling(norm2(t%vectors(:, 1)) / spacing))
         n2 = max(4, ceiling(norm2(t%vectors(:, 2)) / spacing))
         if (64.0_wp * (n1 + 1) * (n2 + 1) * size(layers) + 512.0_wp * n1 * n2 * (size(layers) - 1) &
            & > settings%max_bytes) then
            reason = 'a table of '//itoa(n1)//' x '//itoa(n2)//' x '//itoa(size(layers))//' nodes would exceed ' &
               & //rtoa(settings%max_bytes / 1024.0_wp**2)//' MiB'
            return
         end if
         t%grid = new_tricubic_grid(0.0_wp, 1.0_wp / n1, n1 + 1, 0.0_wp, 1.0_wp / n2, n2 + 1, layers, &
            & wide=(t%grid%wide))
         if (present(share)) then
            call fill_grid(ideal, t, nodes_group, share)
         else
            call fill_grid(ideal, t, nodes_group, alone)
         end if
         ! (The table's grid is the cell [0, 1]²: s -> -s is the reflection
         ! through its middle, by periodicity.)
         call t%grid%set_polynomials(has_op(group, -identity_op), has_op(group, swap_op))
         t%floor = layers(1)
         t%nodes = [n1, n2, size(layers)]
         ! (One copy of the nodes and the cells' polynomials, not two.)
         call move_alloc(t%grid%node, node)
         call move_alloc(t%grid%cell, cell)
         self%table = t
         call move_alloc(node, self%table%grid%node)
         call move_alloc(cell, self%table%grid%cell)
         self%tabulated = .true.
         if (present(share)) then
            call verify(self, settings%verify_points, measured, share)
         else
            call verify(self, settings%verify_points, measured, alone)
         end if
         self%table%error = measured
         if (measured <= settings%tolerance) return
         self%tabulated = .false.
         deallocate (self%table%grid%node, self%table%grid%cell, self%table%grid%slot, self%table%grid%image)
         target = 0.5_wp * target
      end do
      reason = 'the table missed the tolerance '//rtoa(settings%tolerance)//' eV/Å by '//rtoa(measured) &
         & //' eV/Å after three refinements'
   end subroutine tabulate

   !> Whether every process of `share` is asked for, and can run, the table's
   !> kernels for AVX2 (friction_surface_table_kernels).  Collective.
   logical function all_can_go_wide(settings, share) result(wide)
      type(table_settings), intent(in) :: settings
      class(work_sharing), intent(inout) :: share

      wide = settings%wide_kernels .and. friction_wide_kernels() /= 0
      call share%every(wide)
   end function all_can_go_wide

   !> The perfect lattice's sites within the cutoff (and a margin) of the
   !> cell spanned by its vectors at the origin, as a potential.
   function lattice_near_cell(self, lattice) result(ideal)
      type(lj_potential), intent(in) :: self
      type(net_lattice), intent(in) :: lattice
      type(lj_potential) :: ideal
      real(wp) :: corners(2, 4), box(4), margin

      corners(:, 1) = 0.0_wp
      corners(:, 2) = lattice%vectors(:, 1)
      corners(:, 3) = lattice%vectors(:, 2)
      corners(:, 4) = lattice%vectors(:, 1) + lattice%vectors(:, 2)
      margin = self%cutoff + 1.0_wp
      box = [minval(corners(1, :)) - margin, maxval(corners(1, :)) + margin, &
         & minval(corners(2, :)) - margin, maxval(corners(2, :)) + margin]
      ideal = new_lj_potential(lattice%sites(box), self%epsilon, self%sigma, self%cutoff)
   end function lattice_near_cell

   !> The net's differences from the lattice within the cutoff (and a
   !> margin) of the table's box: net atoms on no site of their species
   !> (weight +1) and sites with no atom (weight -1).
   subroutine find_differences(self, lattice, t)
      type(lj_potential), intent(in) :: self
      type(net_lattice), intent(in) :: lattice
      type(lj_table), intent(inout) :: t
      real(wp), parameter :: same = 1.0e-8_wp
      type(crystal_net) :: sites
      real(wp) :: region(4)
      real(wp), allocatable :: position(:, :), weight(:)
      integer, allocatable :: species(:)
      logical, allocatable :: matched(:)
      integer :: i, k, n

      region = t%box + (self%cutoff + 1.0_wp) * [-1.0_wp, 1.0_wp, -1.0_wp, 1.0_wp]
      sites = lattice%sites(region)
      associate (atoms => self%atoms)
         allocate (matched(size(atoms%species)), source=.false.)
         n = sites%size() + size(atoms%species)
         allocate (position(3, n), species(n), weight(n))
         n = 0
         do k = 1, sites%size()
            if (match(k)) cycle
            n = n + 1
            position(:, n) = sites%position(:, k)
            species(n) = sites%species(k)
            weight(n) = -1.0_wp
         end do
         do i = 1, size(atoms%species)
            if (matched(i)) cycle
            if (atoms%position(1, i) < region(1) .or. atoms%position(1, i) > region(2) .or. &
               & atoms%position(2, i) < region(3) .or. atoms%position(2, i) > region(4)) cycle
            n = n + 1
            position(:, n) = atoms%position(:, i)
            species(n) = atoms%species(i)
            weight(n) = 1.0_wp
         end do
      end associate
      call fill_difference_lists(position(:, 1:n), self%sigma(species(1:n))**2, &
         & 4.0_wp * self%epsilon(species(1:n)) * weight(1:n), t%shift(species(1:n)) * weight(1:n), self%cutoff, &
         & region, t%differences)
      t%difference_count = n

   contains

      !> Whether an atom of the net, not matched before, sits on site k.
      logical function match(k)
         integer, intent(in) :: k
         integer :: lo(2), hi(2), cx, cy, c, i

         match = .false.
         associate (atoms => self%atoms)
            call cell_range(atoms, sites%position(1:2, k), same, lo, hi)
            do cy = lo(2), hi(2)
               do cx = lo(1), hi(1)
                  c = cx + cy * atoms%ncell(1) + 1
                  do i = atoms%cell_start(c), atoms%cell_start(c + 1) - 1
                     if (matched(i) .or. atoms%species(i) /= sites%species(k)) cycle
                     if (all(abs(atoms%position(:, i) - sites%position(:, k)) <= same)) then
                        matched(i) = .true.
                        match = .true.
                        return
                     end if
                  end do
               end do
            end do
         end associate
      end function match

   end subroutine find_differences

   !> The lists of the differences (see difference_lists) over `region`
   !> (x_min, x_max, y_min, y_max, Å), in cells of 2 Å (or r_c/3 if smaller):
   !> a list holds the differences within r_c plus half the cell's diagonal
   !> of its centre, some 20 % more than the disc of r_c holds.  Difference
   !> i is at position(:, i), with σ², 4εw and φ(r_c)w of its species.
   subroutine fill_difference_lists(position, sigma2, e4w, shiftw, cutoff, region, self)
      real(wp), intent(in) :: position(:, :), sigma2(:), e4w(:), shiftw(:), cutoff, region(4)
      type(difference_lists), intent(out) :: self
      real(wp) :: centre(2), reach
      integer :: cx, cy, c, i, pass, lo(2), hi(2)
      integer, allocatable :: next(:), member(:)

      self%cell = min(2.0_wp, cutoff / 3.0_wp)
      self%inverse_cell = 1.0_wp / self%cell
      self%origin = [region(1), region(3)]
      self%ncell = max(1, ceiling([region(2) - region(1), region(4) - region(3)] / self%cell))
      reach = cutoff + self%cell / sqrt(2.0_wp)
      allocate (self%start(self%ncell(1) * self%ncell(2) + 1), next(self%ncell(1) * self%ncell(2)))
      ! Two passes over the differences, each to the cells whose centre is
      ! within reach (a list in the differences' order): the lists'
      ! lengths, then which difference each entry is.
      self%start = 0
      do pass = 1, 2
         do i = 1, size(sigma2)
            lo = max(0, floor((position(1:2, i) - reach - self%origin) / self%cell - 0.5_wp))
            hi = min(self%ncell - 1, ceiling((position(1:2, i) + reach - self%origin) / self%cell - 0.5_wp))
            do cy = lo(2), hi(2)
               do cx = lo(1), hi(1)
                  centre = self%origin + ([cx, cy] + 0.5_wp) * self%cell
                  if (sum((position(1:2, i) - centre)**2) >= reach**2) cycle
                  c = cx + cy * self%ncell(1) + 1
                  if (pass == 1) then
                     self%start(c + 1) = self%start(c + 1) + 1
                     cycle
                  end if
                  member(next(c)) = i
                  next(c) = next(c) + 1
               end do
            end do
         end do
         if (pass == 2) exit
         self%start(1) = 1
         do c = 1, size(next)
            self%start(c + 1) = self%start(c) + self%start(c + 1)
         end do
         next = self%start(1:size(next))
         allocate (member(self%start(size(self%start)) - 1))
      end do
      self%x = position(1, member)
      self%y = position(2, member)
      self%z = position(3, member)
      self%sigma2 = sigma2(member)
      self%e4w = e4w(member)
      self%shiftw = shiftw(member)
   end subroutine fill_difference_lists

   !> Whether, within the cutoff of the middle of the table's box, there are
   !> more differences than atoms of the net: then every evaluation would
   !> sum more pairs through the table than directly.
   logical function mostly_different(self, t)
      type(lj_potential), intent(in) :: self
      type(lj_table), intent(in) :: t
      real(wp) :: middle(2)
      integer :: c, i, lo(2), hi(2), cx, cy, atoms, differences

      middle = [0.5_wp * (t%box(1) + t%box(2)), 0.5_wp * (t%box(3) + t%box(4))]
      associate (list => t%differences)
         c = difference_cell(list, middle)
         differences = 0
         if (c > 0) differences = count([((list%x(i) - middle(1))**2 + (list%y(i) - middle(2))**2 < self%cutoff**2, &
            & i = list%start(c), list%start(c + 1) - 1)])
      end associate
      atoms = 0
      call cell_range(self%atoms, middle, self%cutoff, lo, hi)
      do cy = lo(2), hi(2)
         do cx = lo(1), hi(1)
            c = cx + cy * self%atoms%ncell(1) + 1
            do i = self%atoms%cell_start(c), self%atoms%cell_start(c + 1) - 1
               if (sum((self%atoms%position(1:2, i) - middle)**2) < self%cutoff**2) atoms = atoms + 1
            end do
         end do
      end do
      mostly_different = differences > atoms
   end function mostly_different

   !> The eight node values of the lattice potential at heights z(:) above
   !> the point xy (Å), in the fractional coordinates of the lattice
   !> (friction_surface_table_kernels' column_sums): the pairs within the
   !> cutoff in the plane gathered once for the column, into `pairs` (kept
   !> by the caller from column to column: no allocation per column).
   pure subroutine column_values(ideal, t, xy, z, values, pairs)
      type(lj_potential), intent(in) :: ideal
      type(lj_table), intent(in) :: t
      real(wp), intent(in) :: xy(2), z(:)
      real(wp), intent(out) :: values(:, :)
      type(column_pairs), intent(inout) :: pairs

      call gather_pairs(ideal, t, xy, pairs)
      call pair_sums(t, pairs, z, values)
   end subroutine column_values

   !> The sites of the lattice within the cutoff of the column above xy in
   !> the plane, with what the pair terms need of them (u_i = a_i . d does
   !> not change along the column), padded to whole lanes of column_sums
   !> with pairs beyond the cutoff, which add zero.
   pure subroutine gather_pairs(ideal, t, xy, pairs)
      type(lj_potential), intent(in) :: ideal
      type(lj_table), intent(in) :: t
      real(wp), intent(in) :: xy(2)
      type(column_pairs), intent(inout) :: pairs
      real(wp) :: a1(2), a2(2), rc2, dx, dy
      integer :: lo(2), hi(2), cx, cy, c, i, n, s, most, capacity

      a1 = t%vectors(:, 1)
      a2 = t%vectors(:, 2)
      rc2 = ideal%cutoff**2
      call cell_range(ideal%atoms, xy, ideal%cutoff, lo, hi)
      most = 0
      do cy = lo(2), hi(2)
         c = lo(1) + cy * ideal%atoms%ncell(1) + 1
         most = most + ideal%atoms%cell_start(c + hi(1) - lo(1) + 1) - ideal%atoms%cell_start(c)
      end do
      most = column_lanes * ((most + column_lanes - 1) / column_lanes)
      capacity = 0
      if (allocated(pairs%u1)) capacity = size(pairs%u1)
      if (capacity < most) then
         if (allocated(pairs%u1)) deallocate (pairs%u1, pairs%u2, pairs%u12, pairs%lateral, pairs%height, &
            & pairs%sigma2, pairs%e4, pairs%shift)
         most = max(most, 2 * capacity)
         allocate (pairs%u1(most), pairs%u2(most), pairs%u12(most), pairs%lateral(most), pairs%height(most), &
            & pairs%sigma2(most), pairs%e4(most), pairs%shift(most))
      end if
      n = 0
      associate (u1 => pairs%u1, u2 => pairs%u2, u12 => pairs%u12, lateral => pairs%lateral, &
         & height => pairs%height, sigma2 => pairs%sigma2, e4 => pairs%e4, shift => pairs%shift)
         do cy = lo(2), hi(2)
            do cx = lo(1), hi(1)
               c = cx + cy * ideal%atoms%ncell(1) + 1
               do i = ideal%atoms%cell_start(c), ideal%atoms%cell_start(c + 1) - 1
                  dx = xy(1) - ideal%atoms%position(1, i)
                  dy = xy(2) - ideal%atoms%position(2, i)
                  if (dx**2 + dy**2 >= rc2) cycle
                  n = n + 1
                  s = ideal%atoms%species(i)
                  lateral(n) = dx**2 + dy**2
                  u1(n) = a1(1) * dx + a1(2) * dy
                  u2(n) = a2(1) * dx + a2(2) * dy
                  u12(n) = u1(n) * u2(n)
                  height(n) = ideal%atoms%position(3, i)
                  sigma2(n) = ideal%sigma(s)**2
                  e4(n) = 4.0_wp * ideal%epsilon(s)
                  shift(n) = t%shift(s)
               end do
            end do
         end do
         do while (mod(n, column_lanes) /= 0)
            n = n + 1
            lateral(n) = rc2
            u1(n) = 0.0_wp
            u2(n) = 0.0_wp
            u12(n) = 0.0_wp
            height(n) = 0.0_wp
            sigma2(n) = 0.0_wp
            e4(n) = 0.0_wp
            shift(n) = 0.0_wp
         end do
      end associate
      pairs%n = n
      pairs%rc2 = rc2
   end subroutine gather_pairs

   !> The eight node values at heights z(:) of the column whose pairs are
   !> `pairs` (gather_pairs), and with values(9:12, :) the four in-plane
   !> second derivatives too (column_sums), through the kernels for AVX2
   !> where the table uses them.
   pure subroutine pair_sums(t, pairs, z, values)
      type(lj_table), intent(in) :: t
      type(column_pairs), intent(in) :: pairs
      real(wp), intent(in) :: z(:)
      real(wp), intent(out) :: values(:, :)
      real(wp) :: metric(3)

      associate (a => t%vectors)
         metric = [dot_product(a(:, 1), a(:, 1)), dot_product(a(:, 1), a(:, 2)), dot_product(a(:, 2), a(:, 2))]
      end associate
      associate (n => pairs%n)
         if (t%grid%wide) then
            call column_sums_wide(n, pairs%lateral, pairs%u1, pairs%u2, pairs%u12, pairs%height, pairs%sigma2, &
               & pairs%e4, pairs%shift, metric, pairs%rc2, z, values)
         else
            call column_sums(n, pairs%lateral, pairs%u1, pairs%u2, pairs%u12, pairs%height, pairs%sigma2, &
               & pairs%e4, pairs%shift, metric, pairs%rc2, z, values)
         end if
      end associate
   end subroutine pair_sums

   !> The Cartesian point of fractional coordinates s.
   pure function cartesian(t, s) result(xy)
      type(lj_table), intent(in) :: t
      real(wp), intent(in) :: s(2)
      real(wp) :: xy(2)

      xy = s(1) * t%vectors(:, 1) + s(2) * t%vectors(:, 2)
   end function cartesian

   !> The Cartesian gradient from a node's values (V_si = a_i . grad: back
   !> through the inverse).
   pure function cartesian_gradient(t, values) result(g)
      type(lj_table), intent(in) :: t
      real(wp), intent(in) :: values(n_node_values)
      real(wp) :: g(3)

      g = from_fraction(t%to_fraction, values(2:4))
   end function cartesian_gradient

   !> Step 2 of `tabulate`: the heights of the layers, ascending, and the
   !> lowest energy of the lattice met (at the check columns' nodes).  The
   !> processes share the check columns, and all take the same steps.
   subroutine choose_layers(ideal, t, ops, target, window, layers, vmin, reason, share)
      type(lj_potential), intent(in) :: ideal
      type(lj_table), intent(in) :: t
      !> the lattice's point group (point_group)
      integer, intent(in) :: ops(:, :, :)
      real(wp), intent(in) :: target, window
      real(wp), allocatable, intent(out) :: layers(:)
      real(wp), intent(out) :: vmin
      character(len=:), allocatable, intent(inout) :: reason
      !> the processes sharing the columns (each a share, then summed)
      class(work_sharing), intent(inout) :: share
      integer, parameter :: side = 6, max_layers = 4000
      real(wp), parameter :: check_at(3) = [0.2113248654051871_wp, 0.5_wp, 0.7886751345948129_wp]
      real(wp), allocatable :: columns(:, :), upper(:, :), lower(:, :), found(:), checked(:, :, :)
      !> the check columns' fractional coordinates
      real(wp), allocatable :: kept(:, :)
      real(wp) :: step, z, z_new, worst, bottom, ratio, g(3), r(3), v, gi(3), s(2)
      !> each check column's pairs, gathered once for all the heights tried
      type(column_pairs), allocatable :: pairs(:)
      integer :: ncol, i, j, k, m
      logical :: all_above

      ! Check columns: a side x side grid of the cell (its corner, thirds and
      ! halves among them) and the sites of the atoms in the cell, one of
      ! each orbit of the lattice's point group: along the others the energy
      ! is the same and the gradient the same rotated, so are the errors
      ! (graphite: 7 columns of 38, its atoms' sites among the grid's).
      allocate (columns(2, side * side + size(ideal%atoms%species)), kept(2, side * side + size(ideal%atoms%species)))
      ncol = 0
      do j = 0, side - 1
         do i = 0, side - 1
            call add_column([real(i, wp), real(j, wp)] / side)
         end do
      end do
      do i = 1, size(ideal%atoms%species)
         s = matmul(t%to_fraction, ideal%atoms%position(1:2, i))
         if (any(s < 0.0_wp) .or. any(s >= 1.0_wp)) cycle
         call add_column(s)
      end do
      allocate (upper(n_node_values, ncol), lower(n_node_values, ncol), checked(n_node_values, 4, ncol))
      bottom = minval(ideal%atoms%position(3, :))
      z = t%top
      allocate (pairs(ncol))
      do m = 1, ncol
         call gather_pairs(ideal, t, columns(:, m), pairs(m))
         call pair_sums(t, pairs(m), [z], upper(:, m:m))
      end do
      vmin = minval(upper(1, :))
      found = [z]
      step = 1.0_wp
      do
         z_new = z - step
         if (z_new <= bottom) then
            reason = 'no floor for the table: the energy stays below the cap down to the atoms'
            return
         end if
         ! The new layer's values and the lattice's at the check heights,
         ! column by column (one gathering of the pairs for all four), the
         ! columns dealt round-robin over the processes and summed (-0.0
         ! where a process computes nothing: the same values on every one).
         if (share%ranks > 1) checked = -0.0_wp
         do m = 1, ncol
            if (mod(m - 1, share%ranks) /= share%rank) cycle
            call pair_sums(t, pairs(m), [z_new, z_new + check_at * step], checked(:, :, m))
         end do
         if (share%ranks > 1) call share%sum_reals(checked, size(checked))
         lower = checked(:, 1, :)
         ! The error of the interpolation along z at the check columns, where
         ! the energy is under the cap (the lowest energy so far: the cap
         ! only falls as the march goes down through the well).
         worst = 0.0_wp
         do m = 1, ncol
            do k = 1, size(check_at)
               r = [columns(:, m), z_new + check_at(k) * step]
               call hermite_column(lower(:, m), upper(:, m), z_new, z, r(3), v, gi)
               if (v > min(vmin, minval(lower(1, :))) + window) cycle
               g = cartesian_gradient(t, checked(:, 1 + k, m))
               gi = from_fraction(t%to_fraction, gi)
               worst = max(worst, norm2(gi - g))
            end do
         end do
         ratio = (target / max(worst, tiny(1.0_wp)))**(1.0_wp / 3.0_wp)
         if (worst > target) then
            step = step * max(0.2_wp, 0.9_wp * ratio)
            if (step < 1.0e-4_wp) then
               reason = 'the layers would need to be closer than 1e-4 Å'
               return
            end if
            cycle
         end if
         z = z_new
         upper = lower
         found = [found, z]
         vmin = min(vmin, minval(lower(1, :)))
         if (size(found) > max_layers) then
            reason = 'more than '//itoa(max_layers)//' layers'
            return
         end if
         all_above = all(lower(1, :) > vmin + window)
         if (all_above) exit
         step = step * min(2.0_wp, 0.9_wp * ratio)
      end do
      layers = found(size(found):1:-1)

   contains

      !> Adds the column at fractional coordinates f unless an element of
      !> ops takes it onto one already there (modulo the lattice).
      subroutine add_column(f)
         real(wp), intent(in) :: f(2)
         real(wp) :: d(2)
         integer :: m, c

         do m = 1, size(ops, 3)
            do c = 1, ncol
               d = matmul(real(ops(:, :, m), wp), f) - kept(:, c)
               if (all(abs(d - nint(d)) < 1.0e-9_wp)) return
            end do
         end do
         ncol = ncol + 1
         kept(:, ncol) = f
         columns(:, ncol) = cartesian(t, f)
      end subroutine add_column

   end subroutine choose_layers

   !> The cubic Hermite interpolation along z between two nodes' values
   !> (lower at z0, upper at z1) at height z: the energy and the gradient in
   !> fractional coordinates (the lateral components from V_si and V_siz).
   pure subroutine hermite_column(lower, upper, z0, z1, z, v, g)
      real(wp), intent(in) :: lower(:), upper(:), z0, z1, z
      real(wp), intent(out) :: v, g(3)
      real(wp) :: t, w, h00, h01, h10, h11, d00, d01, d10, d11

      w = z1 - z0
      t = (z - z0) / w
      h00 = 2 * t**3 - 3 * t**2 + 1
      h01 = -2 * t**3 + 3 * t**2
      h10 = (t**3 - 2 * t**2 + t) * w
      h11 = (t**3 - t**2) * w
      d00 = (6 * t**2 - 6 * t) / w
      d01 = -d00
      d10 = 3 * t**2 - 4 * t + 1
      d11 = 3 * t**2 - 2 * t
      v = h00 * lower(1) + h01 * upper(1) + h10 * lower(4) + h11 * upper(4)
      g(3) = d00 * lower(1) + d01 * upper(1) + d10 * lower(4) + d11 * upper(4)
      g(1) = h00 * lower(2) + h01 * upper(2) + h10 * lower(6) + h11 * upper(6)
      g(2) = h00 * lower(3) + h01 * upper(3) + h10 * lower(7) + h11 * upper(7)
   end subroutine hermite_column

   !> Step 3 of `tabulate`: the lateral spacing (Å) that keeps the error of
   !> the interpolation within the layers under `target`, measured at
   !> quasi-random points of the layers (energy under the cap) on trial
   !> spacings: the error goes as the spacing cubed.  Each layer gets
   !> `per_layer` points; a point (Halton, in the plane) serves every
   !> `stride`-th layer, so that one gathering of its pairs, and of its
   !> cell's corners', serves all of them.  The processes share the points
   !> and take the largest error of all.
   subroutine choose_spacing(ideal, t, layers, target, spacing, reason, share)
      type(lj_potential), intent(in) :: ideal
      type(lj_table), intent(in) :: t
      real(wp), intent(in) :: layers(:), target
      real(wp), intent(out) :: spacing
      character(len=:), allocatable, intent(inout) :: reason
      !> the processes sharing the points (each a share, then the largest error)
      class(work_sharing), intent(inout) :: share
      integer, parameter :: per_layer = 16, stride = 6, trials = 6
      real(wp) :: worst, s(2), f(2), n(2), v, gi(3), hi(3, 3)
      real(wp), allocatable :: corner(:, :, :, :), exact(:, :, :)
      type(tricubic_grid) :: cell
      type(column_pairs) :: pairs
      integer :: trial, k, j, i, point, first, points, nz

      ! Point j serves layers first(j), first(j) + stride, ...: first(j) =
      ! 1 + mod(j - 1, stride), so that each layer has per_layer points.
      points = per_layer * min(stride, size(layers))
      nz = (size(layers) + stride - 1) / stride
      allocate (corner(n_node_values, nz, 2, 2), exact(n_node_values, nz, points))
      ! The lattice at each point's layers: the same for every trial.
      do point = 1, points
         if (mod(point - 1, share%ranks) /= share%rank) cycle
         first = 1 + mod(point - 1, min(stride, size(layers)))
         associate (z => layers(first::min(stride, size(layers))))
            call gather_pairs(ideal, t, cartesian(t, [halton(point + 16, 2), halton(point + 16, 3)]), pairs)
            call pair_sums(t, pairs, z, exact(:, :size(z), point))
         end associate
      end do
      spacing = 0.1_wp
      do trial = 1, trials
         n = max(4.0_wp, real(ceiling([norm2(t%vectors(:, 1)), norm2(t%vectors(:, 2))] / spacing), wp))
         ! One cell of the trial spacing (moved to each point's below), its
         ! two layers holding the same data: the interpolation in the plane.
         cell = new_tricubic_grid(0.0_wp, 1.0_wp / n(1), 2, 0.0_wp, 1.0_wp / n(2), 2, [0.0_wp, 1.0_wp])
         worst = 0.0_wp
         do point = 1, points
            if (mod(point - 1, share%ranks) /= share%rank) cycle
            s = [halton(point + 16, 2), halton(point + 16, 3)]
            first = 1 + mod(point - 1, min(stride, size(layers)))
            associate (z => layers(first::min(stride, size(layers))))
               ! The cell holding s, its four corners at the point's layers.
               f = floor(s * n)
               do j = 0, 1
                  do i = 0, 1
                     call gather_pairs(ideal, t, cartesian(t, (f + [i, j]) / n), pairs)
                     call pair_sums(t, pairs, z, corner(:, :size(z), i + 1, j + 1))
                  end do
               end do
               cell%x0 = f(1) / n(1)
               cell%y0 = f(2) / n(2)
               do k = 1, size(z)
                  cell%node(:, :, :, 1) = corner(:, k, :, :)
                  cell%node(:, :, :, 2) = corner(:, k, :, :)
                  call cell%evaluate([s(1), s(2), 0.0_wp], 1, v, gi, hi)
                  if (v > t%energy_cap) cycle
                  gi = from_fraction(t%to_fraction, gi)
                  worst = max(worst, norm2(gi - cartesian_gradient(t, exact(:, k, point))))
               end do
            end associate
         end do
         call share%max_real(worst)
         if (worst <= target .and. trial > 1) return
         ! Error ~ spacing³: aim 10 % below the target.
         spacing = spacing * min(1.5_wp, 0.9_wp * (target / max(worst, tiny(1.0_wp)))**(1.0_wp / 3.0_wp))
         if (spacing < 1.0e-3_wp) then
            reason = 'the lateral spacing would need to be below 1e-3 Å'
            return
         end if
      end do
      ! (The last trial's spacing, refined once more, stands: step 5 checks it.)
   end subroutine choose_spacing

   !> The lattice's point group in fractional coordinates: the integer
   !> matrices A (entries -1, 0 or 1, determinant ±1) under which s -> A s
   !> keeps the lattice's metric (AᵀGA = G, G the lattice vectors' dot
   !> products: a rotation or a mirror through the origin) and takes every
   !> atom of the cell to an atom of its species and height, less a lattice
   !> vector; ops(:, :, m) the m-th.  Graphite's
   !> lattice, centred on a hexagon, has 12: the rotations by multiples of
   !> 60° and six mirrors.  Should the matrices found not form a group (a
   !> product with an entry beyond ±1, which a reduced pair of lattice
   !> vectors does not give), only the identity, s -> -s, the swap
   !> s -> (s2, s1) and their product are kept, those among them found.
   pure function point_group(lattice) result(ops)
      type(net_lattice), intent(in) :: lattice
      integer, allocatable :: ops(:, :, :)
      integer :: found(2, 2, 81), a(2, 2), k, n, e(4)
      real(wp) :: metric(2, 2)
      !> the basis atoms' fractional coordinates in the plane
      real(wp) :: fraction(2, size(lattice%species))

      metric = matmul(transpose(lattice%vectors), lattice%vectors)
      fraction = matmul(fraction_map(lattice%vectors), lattice%basis(1:2, :))
      n = 0
      do k = 0, 80
         e = [mod(k / 27, 3), mod(k / 9, 3), mod(k / 3, 3), mod(k, 3)] - 1
         a = reshape(e, [2, 2])
         if (abs(a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1)) /= 1) cycle
         if (maxval(abs(matmul(transpose(real(a, wp)), matmul(metric, real(a, wp))) - metric)) &
            & > 1.0e-9_wp * maxval(abs(metric))) cycle
         if (.not. keeps_atoms(a)) cycle
         n = n + 1
         found(:, :, n) = a
      end do
      ops = found(:, :, 1:n)
      if (.not. closed(ops)) ops = reflection_and_swap(ops)

   contains

      !> Whether s -> a s takes every atom of the cell to one of its species
      !> and height, less a lattice vector.
      pure logical function keeps_atoms(a)
         integer, intent(in) :: a(2, 2)
         real(wp) :: f(2)
         integer :: b, c

         do b = 1, size(lattice%species)
            keeps_atoms = .false.
            do c = 1, size(lattice%species)
               if (lattice%species(c) /= lattice%species(b)) cycle
               if (abs(lattice%basis(3, c) - lattice%basis(3, b)) > 1.0e-9_wp) cycle
               f = matmul(real(a, wp), fraction(:, b)) - fraction(:, c)
               if (all(abs(f - nint(f)) < 1.0e-9_wp)) keeps_atoms = .true.
            end do
            if (.not. keeps_atoms) return
         end do
      end function keeps_atoms

      !> Whether every product of two of ops is among them.
      pure logical function closed(ops)
         integer, intent(in) :: ops(:, :, :)
         integer :: i, j

         closed = .true.
         do j = 1, size(ops, 3)
            do i = 1, size(ops, 3)
               if (.not. has_op(ops, matmul(ops(:, :, i), ops(:, :, j)))) closed = .false.
            end do
         end do
      end function closed

   end function point_group

   !> Those of ops (point_group) among the identity, s -> -s, the swap
   !> s -> (s2, s1) and their product, which form a group of their own.
   pure function reflection_and_swap(ops) result(kept)
      integer, intent(in) :: ops(:, :, :)
      integer, allocatable :: kept(:, :, :)
      integer :: basic(2, 2, 4), m

      basic = reshape([identity_op, -identity_op, swap_op, -swap_op], [2, 2, 4])
      kept = ops(:, :, pack([(m, m = 1, size(ops, 3))], [(has_op(basic, ops(:, :, m)), m = 1, size(ops, 3))]))
   end function reflection_and_swap

   !> Whether a is among ops (point_group).
   pure logical function has_op(ops, a)
      integer, intent(in) :: ops(:, :, :), a(2, 2)
      integer :: m

      has_op = any([(all(ops(:, :, m) == a), m = 1, size(ops, 3))])
   end function has_op

   !> Step 4 of `tabulate`: every node's values (the last row and column
   !> repeat the first: the lattice is periodic).  The lattice's point group
   !> `ops` (point_group) takes nodes to nodes (those of its matrices that do
   !> not mix the axes, unless there are as many nodes along a1 as along
   !> a2): of each orbit one column is computed, the first in the grid's
   !> order, with the in-plane second derivatives too, and the others are
   !> its images.  Where A takes node p to q, V(q) = V(p), and with C = A⁻¹
   !> the gradient in the plane is Cᵀ ∇V(p) and the in-plane Hessian
   !> Cᵀ H(p) C (their z-derivatives alike), whose off-diagonal entry is
   !> the node's cross derivative.  Graphite computes a twelfth of its
   !> columns.  The columns computed are dealt round-robin over the
   !> processes of `share`, each its own, and summed.
   subroutine fill_grid(ideal, t, ops, share)
      type(lj_potential), intent(in) :: ideal
      type(lj_table), intent(inout) :: t
      integer, intent(in) :: ops(:, :, :)
      class(work_sharing), intent(inout) :: share
      real(wp), allocatable :: packed(:, :, :)
      type(column_pairs) :: pairs
      integer :: i, j, k, n1, n2, dealt, m, q(2)
      logical :: usable(size(ops, 3))
      !> each node's column (its number in `packed`) and the inverse of the
      !> element taking the column to it
      integer, allocatable :: from(:, :), map(:, :, :, :)
      !> whether a node comes first among its images (it is computed)
      logical, allocatable :: first(:, :)

      n1 = t%grid%nx - 1
      n2 = t%grid%ny - 1
      usable = [(n1 == n2 .or. (ops(1, 2, m) == 0 .and. ops(2, 1, m) == 0), m = 1, size(ops, 3))]
      allocate (first(n1, n2), source=.true.)
      do j = 1, n2
         do i = 1, n1
            do m = 1, size(ops, 3)
               if (.not. usable(m)) cycle
               q = image(m, i, j)
               if (q(1) + n1 * q(2) < i + n1 * j) first(i, j) = .false.
            end do
         end do
      end do
      ! (-0.0 where this process computes nothing: see work_sharing's sum.)
      allocate (packed(12, size(t%grid%z), count(first)), source=-0.0_wp)
      dealt = 0
      do j = 1, n2
         do i = 1, n1
            if (.not. first(i, j)) cycle
            dealt = dealt + 1
            if (mod(dealt - 1, share%ranks) /= share%rank) cycle
            call column_values(ideal, t, cartesian(t, [real(i - 1, wp) / n1, real(j - 1, wp) / n2]), t%grid%z, &
               & packed(:, :, dealt), pairs)
         end do
      end do
      if (share%ranks > 1) call share%sum_reals(packed, size(packed))
      ! Every node's column and the map from the column computed: first the
      ! list, then layer by layer (a layer's nodes lie together).
      allocate (from(n1, n2), map(2, 2, n1, n2))
      dealt = 0
      do j = 1, n2
         do i = 1, n1
            if (.not. first(i, j)) cycle
            dealt = dealt + 1
            from(i, j) = dealt
            map(:, :, i, j) = identity_op
            do m = 1, size(ops, 3)
               if (.not. usable(m)) cycle
               q = image(m, i, j)
               ! (The column itself, or the image of it under another element.)
               if (first(q(1), q(2))) cycle
               from(q(1), q(2)) = dealt
               map(:, :, q(1), q(2)) = inverse(ops(:, :, m))
            end do
         end do
      end do
      do k = 1, size(t%grid%z)
         do j = 1, n2
            do i = 1, n1
               call map_values(map(:, :, i, j), packed(:, k, from(i, j)), t%grid%node(:, i, j, k))
            end do
         end do
      end do
      t%grid%node(:, n1 + 1, 1:n2, :) = t%grid%node(:, 1, 1:n2, :)
      t%grid%node(:, :, n2 + 1, :) = t%grid%node(:, :, 1, :)

   contains

      !> The node (1-based) that node (i, j) goes to under ops(:, :, m).
      pure function image(m, i, j) result(node)
         integer, intent(in) :: m, i, j
         integer :: node(2)

         node = modulo(matmul(ops(:, :, m), [i - 1, j - 1]), [n1, n2]) + 1
      end function image

      !> The inverse of an integer matrix of determinant ±1.
      pure function inverse(a) result(b)
         integer, intent(in) :: a(2, 2)
         integer :: b(2, 2)

         b = (a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1)) * reshape([a(2, 2), -a(2, 1), -a(1, 2), a(1, 1)], [2, 2])
      end function inverse

      !> A node's values at the image of a column (`to`, n_node_values of
      !> them) from the column's values with the in-plane second derivatives
      !> at that height (`from`, 12: column_sums), c the inverse of the
      !> element taking the column there (the identity: the column itself).
      pure subroutine map_values(c, from, to)
         integer, intent(in) :: c(2, 2)
         real(wp), intent(in) :: from(12)
         real(wp), intent(out) :: to(n_node_values)

         to(1) = from(1)
         to(4) = from(4)
         to(2) = c(1, 1) * from(2) + c(2, 1) * from(3)
         to(3) = c(1, 2) * from(2) + c(2, 2) * from(3)
         to(6) = c(1, 1) * from(6) + c(2, 1) * from(7)
         to(7) = c(1, 2) * from(6) + c(2, 2) * from(7)
         ! (Cᵀ H C)_12 = c11 c12 H11 + (c11 c22 + c21 c12) H12 + c21 c22 H22
         to(5) = c(1, 1) * c(1, 2) * from(9) + (c(1, 1) * c(2, 2) + c(2, 1) * c(1, 2)) * from(5) &
            & + c(2, 1) * c(2, 2) * from(10)
         to(8) = c(1, 1) * c(1, 2) * from(11) + (c(1, 1) * c(2, 2) + c(2, 1) * c(1, 2)) * from(8) &
            & + c(2, 1) * c(2, 2) * from(12)
      end subroutine map_values

   end subroutine fill_grid

   !> Step 5 of `tabulate`: the largest force error (eV/Å) of the tabulated
   !> potential against the direct sum over the net, at `points`
   !> quasi-random points where the table answers below the ceiling
   !> (lateral: the box; height: uniform in the layer index, so the layers
   !> near the floor, where the field is steep, get their share).
   subroutine verify(self, points, measured, share)
      type(lj_potential), intent(inout) :: self
      integer, intent(in) :: points
      real(wp), intent(out) :: measured
      class(work_sharing), intent(inout) :: share
      real(wp) :: r(3), u, v, g(3), h(3, 3), gd(3)
      integer :: k, tried, counted, nz
      logical :: answered

      measured = 0.0_wp
      counted = 0
      tried = 0
      nz = size(self%table%grid%z)
      associate (t => self%table, box => self%table%box)
         do while (counted < points .and. tried < 20 * points)
            tried = tried + 1
            r(1) = box(1) + (box(2) - box(1)) * halton(tried + 20, 2)
            r(2) = box(3) + (box(4) - box(3)) * halton(tried + 20, 3)
            u = (nz - 1) * halton(tried + 20, 5)
            k = min(nz - 1, int(u) + 1)
            r(3) = t%grid%z(k) + (u - (k - 1)) * (t%grid%z(k + 1) - t%grid%z(k))
            ! (Whether the table answers needs the lattice's energy alone;
            ! the points dealt round-robin over the processes, each its
            ! points' answers, the differences' sums with them, and direct
            ! sums; the largest error of all.)
            call lattice_answer(t, r, 0, answered, v, g, h)
            if (.not. answered) cycle
            counted = counted + 1
            if (mod(counted - 1, share%ranks) /= share%rank) cycle
            call self%table_answers(r, 1, answered, v, g, h)
            call sum_pairs(self, r, 1, v, gd, h)
            measured = max(measured, norm2(g - gd))
         end do
         t%points = counted
      end associate
      call share%max_real(measured)
   end subroutine verify

   !> The k-th element of the van der Corput sequence in base b (k >= 1):
   !> Halton points, the same on every run and every rank.
   pure real(wp) function halton(k, b) result(x)
      integer, intent(in) :: k, b
      real(wp) :: f
      integer :: i

      x = 0.0_wp
      f = 1.0_wp
      i = k
      do while (i > 0)
         f = f / b
         x = x + f * mod(i, b)
         i = i / b
      end do
   end function halton

end module friction_surface_lennard_jones
