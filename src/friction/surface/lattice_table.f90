!> Building the surface table (friction_surface_lennard_jones' `tabulate`,
!> docs/physics.md, "The tabulated surface"): how to build it, the table
!> itself, the lattice's point group, the node values of a column summed
!> over the perfect lattice (friction_surface_table_kernels), and the steps
!> of the build: the heights of the layers, the lateral spacing, every node
!> of one cell.  The table's evaluation, and the check of the built table
!> against the direct sum, are the potential's (friction_surface_lennard_jones).
module friction_surface_lattice_table
   use friction_kinds, only: wp
   use friction_surface_net, only: crystal_net, net_lattice, fraction_map
   use friction_surface_tricubic, only: tricubic_grid, new_tricubic_grid, n_node_values
   use friction_surface_table_kernels, only: column_sums, column_lanes, from_fraction
   use friction_surface_table_kernels_wide, only: column_sums_wide => column_sums
   use friction_surface_pair_cells, only: atom_cells, new_atom_cells, cell_range
   use friction_surface_differences, only: difference_lists
   use friction_strings, only: itoa
   use friction_sharing, only: work_sharing
   use, intrinsic :: iso_c_binding, only: c_int
   implicit none
   private

   public :: table_settings, lj_table, ideal_lattice, lattice_near_cell, all_can_go_wide, point_group, &
      & reflection_and_swap, has_op, identity_op, swap_op, choose_layers, choose_spacing, fill_grid, halton

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

   !> The perfect lattice's sites near one cell (lattice_near_cell), binned,
   !> with the species' ε and σ and the cutoff: what the nodes are summed
   !> over (the same names as friction_surface_lennard_jones' lj_potential).
   type :: ideal_lattice
      real(wp), allocatable :: epsilon(:)   !! per species, eV
      real(wp), allocatable :: sigma(:)     !! per species, Å
      real(wp) :: cutoff = 0.0_wp           !! r_c, Å
      type(atom_cells) :: atoms             !! the sites, binned
   end type ideal_lattice

   interface
      !> Whether the kernels compiled for AVX2 (x86-64-v3) can run here:
      !> this build has them and the processor has the instructions (cpu.c).
      integer(c_int) function friction_wide_kernels() bind(c, name='friction_wide_kernels')
         import :: c_int
      end function friction_wide_kernels
   end interface

contains

   !> Whether every process of `share` is asked for, and can run, the table's
   !> kernels for AVX2 (friction_surface_table_kernels).  Collective.
   logical function all_can_go_wide(settings, share) result(wide)
      type(table_settings), intent(in) :: settings
      class(work_sharing), intent(inout) :: share

      wide = settings%wide_kernels .and. friction_wide_kernels() /= 0
      call share%every(wide)
   end function all_can_go_wide

   !> The perfect lattice's sites within the cutoff (and a margin) of the
   !> cell spanned by its vectors at the origin, binned as a potential's
   !> (friction_surface_lennard_jones' new_lj_potential).
   function lattice_near_cell(lattice, epsilon, sigma, cutoff) result(ideal)
      type(net_lattice), intent(in) :: lattice
      real(wp), intent(in) :: epsilon(:), sigma(:), cutoff
      type(ideal_lattice) :: ideal
      type(crystal_net) :: sites
      real(wp) :: corners(2, 4), box(4), margin

      corners(:, 1) = 0.0_wp
      corners(:, 2) = lattice%vectors(:, 1)
      corners(:, 3) = lattice%vectors(:, 2)
      corners(:, 4) = lattice%vectors(:, 1) + lattice%vectors(:, 2)
      margin = cutoff + 1.0_wp
      box = [minval(corners(1, :)) - margin, maxval(corners(1, :)) + margin, &
         & minval(corners(2, :)) - margin, maxval(corners(2, :)) + margin]
      sites = lattice%sites(box)
      allocate (ideal%epsilon, source=epsilon)
      allocate (ideal%sigma, source=sigma)
      ideal%cutoff = cutoff
      ideal%atoms = new_atom_cells(sites%position, sites%species, cutoff)
   end function lattice_near_cell

   !> The eight node values of the lattice potential at heights z(:) above
   !> the point xy (Å), in the fractional coordinates of the lattice
   !> (friction_surface_table_kernels' column_sums): the pairs within the
   !> cutoff in the plane gathered once for the column, into `pairs` (kept
   !> by the caller from column to column: no allocation per column).
   pure subroutine column_values(ideal, t, xy, z, values, pairs)
      type(ideal_lattice), intent(in) :: ideal
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
      type(ideal_lattice), intent(in) :: ideal
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
      type(ideal_lattice), intent(in) :: ideal
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
      type(ideal_lattice), intent(in) :: ideal
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
      type(ideal_lattice), intent(in) :: ideal
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

end module friction_surface_lattice_table
