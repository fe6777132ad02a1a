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
!>
!> Here the potential and its evaluation, the hot path; the cell list in
!> friction_surface_pair_cells, the table's build in
!> friction_surface_lattice_table, the differences' lists in
!> friction_surface_differences.
module friction_surface_lennard_jones
   use friction_kinds, only: wp, pi
   use friction_surface_potential, only: surface_potential, spice_form
   use friction_surface_net, only: crystal_net, net_lattice, fraction_map
   use friction_surface_tricubic, only: new_tricubic_grid
   use friction_surface_table_kernels, only: difference_terms, lattice_gradient, cell_fraction, from_fraction
   use friction_surface_table_kernels_wide, only: lattice_gradient_wide => lattice_gradient
   use friction_surface_pair_cells, only: atom_cells, new_atom_cells, cell_range, lj_pair_energy, cutoff_for_tolerance
   use friction_surface_differences, only: difference_cell, find_differences, mostly_different
   use friction_surface_lattice_table, only: table_settings, lj_table, ideal_lattice, lattice_near_cell, &
      & all_can_go_wide, point_group, reflection_and_swap, has_op, identity_op, swap_op, choose_layers, &
      & choose_spacing, fill_grid, halton
   use friction_strings, only: rtoa, itoa
   use friction_sharing, only: work_sharing
   implicit none
   private

   public :: lj_potential, new_lj_potential, cutoff_for_tolerance, lj_pair_energy, lj_table, table_settings

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
      procedure :: spice
   end type lj_potential

contains

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
      call cell_range(self%atoms, r(1:2), self%cutoff, lo, hi)
      ! (rc2 after the call to another module: so it stays in a register through the loops)
      rc2 = merge(self%cutoff**2, huge(1.0_wp), self%cutoff > 0.0_wp)
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
      type(ideal_lattice) :: ideal
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
      ideal = lattice_near_cell(lattice, self%epsilon, self%sigma, self%cutoff)
      call find_differences(self%atoms, self%epsilon, self%sigma, self%cutoff, t%shift, lattice, t%box, &
         & t%differences, t%difference_count)
      if (mostly_different(self%atoms, self%cutoff, t%box, t%differences)) then
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

   !> No SPICE form: the sum over the net's atoms would be one pair term per
   !> atom in a behavioural source, re-derived at every Newton iteration.
   pure subroutine spice(self, form)
      class(lj_potential), intent(in) :: self
      type(spice_form), intent(out) :: form

      allocate (form%comment(0), form%names(0), form%values(0))
      form%gradient_x = ''
      form%gradient_y = ''
      form%why = 'the Lennard-Jones lattice sum (Eq. 3) over hundreds of atoms would be hundreds of pair terms ' &
         & //'in behavioural sources, re-derived at every Newton iteration: impractical in SPICE'
   end subroutine spice

end module friction_surface_lennard_jones
