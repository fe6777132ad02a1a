!> A surface table's differences (friction_surface_lennard_jones, `tabulate`):
!> the net less the perfect lattice it is cut from, the net's atoms on no site
!> of the lattice (weight +1) and the lattice's sites with no atom (weight
!> -1), found once within the cutoff of where the tip can be and kept as a
!> list per square cell of the plane, so that an evaluation finds those near
!> the tip with one look-up (`difference_cell`).
module friction_surface_differences
   use friction_kinds, only: wp
   use friction_surface_net, only: crystal_net, net_lattice
   use friction_surface_pair_cells, only: atom_cells, cell_range
   implicit none
   private

   public :: difference_lists, find_differences, mostly_different, difference_cell

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

contains

   !> The differences of the net binned in `atoms` (species' ε, σ, cutoff r_c
   !> and φ(r_c) `shift`) from the lattice within the cutoff (and a margin)
   !> of the table's box: net atoms on no site of their species (weight +1)
   !> and sites with no atom (weight -1), as lists, and how many there are.
   subroutine find_differences(atoms, epsilon, sigma, cutoff, shift, lattice, box, list, difference_count)
      type(atom_cells), intent(in) :: atoms
      real(wp), intent(in) :: epsilon(:), sigma(:), cutoff, shift(:)
      type(net_lattice), intent(in) :: lattice
      real(wp), intent(in) :: box(4)
      type(difference_lists), intent(out) :: list
      integer, intent(out) :: difference_count
      real(wp), parameter :: same = 1.0e-8_wp
      type(crystal_net) :: sites
      real(wp) :: region(4)
      real(wp), allocatable :: position(:, :), weight(:)
      integer, allocatable :: species(:)
      logical, allocatable :: matched(:)
      integer :: i, k, n

      region = box + (cutoff + 1.0_wp) * [-1.0_wp, 1.0_wp, -1.0_wp, 1.0_wp]
      sites = lattice%sites(region)
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
      call fill_difference_lists(position(:, 1:n), sigma(species(1:n))**2, &
         & 4.0_wp * epsilon(species(1:n)) * weight(1:n), shift(species(1:n)) * weight(1:n), cutoff, &
         & region, list)
      difference_count = n

   contains

      !> Whether an atom of the net, not matched before, sits on site k.
      logical function match(k)
         integer, intent(in) :: k
         integer :: lo(2), hi(2), cx, cy, c, i

         match = .false.
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
   !> more differences (`list`) than atoms of the net (`atoms`): then every
   !> evaluation would sum more pairs through the table than directly.
   logical function mostly_different(atoms, cutoff, box, list)
      type(atom_cells), intent(in) :: atoms
      real(wp), intent(in) :: cutoff, box(4)
      type(difference_lists), intent(in) :: list
      real(wp) :: middle(2)
      integer :: c, i, lo(2), hi(2), cx, cy, near, differences

      middle = [0.5_wp * (box(1) + box(2)), 0.5_wp * (box(3) + box(4))]
      c = difference_cell(list, middle)
      differences = 0
      if (c > 0) differences = count([((list%x(i) - middle(1))**2 + (list%y(i) - middle(2))**2 < cutoff**2, &
         & i = list%start(c), list%start(c + 1) - 1)])
      near = 0
      call cell_range(atoms, middle, cutoff, lo, hi)
      do cy = lo(2), hi(2)
         do cx = lo(1), hi(1)
            c = cx + cy * atoms%ncell(1) + 1
            do i = atoms%cell_start(c), atoms%cell_start(c + 1) - 1
               if (sum((atoms%position(1:2, i) - middle)**2) < cutoff**2) near = near + 1
            end do
         end do
      end do
      mostly_different = differences > near
   end function mostly_different

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

end module friction_surface_differences
