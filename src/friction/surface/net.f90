!> Crystal nets: the atoms of a rigid sample surface, each with a species.
!>
!> Generated nets: one graphite (graphene) layer as a hexagonal flake of
!> hexagons in shells around a central ring (shells = 9 gives the paper's 271
!> hexagons and 600 atoms: 1 + 3n(n+1) hexagons, 6(n+1)² atoms), and square
!> nets.  Any net can be read from, and written to, a plain XYZ file
!> (count, comment, then `species x y z` per line, Å).  Defects: vacancies
!> (sites removed) and substitutional atoms (another species at a site), by
!> site number (1-based, in the order of the generated or read net).
module friction_surface_net
   use friction_kinds, only: wp
   use friction_error, only: error_type, fatal_error, error_input, error_io
   use friction_strings, only: itoa, join, one_line
   use friction_files, only: open_for_reading, read_text_line
   implicit none
   private

   public :: crystal_net, graphite_net, square_net, read_xyz, write_xyz, vacancy_mark, sort_order, max_local_density, &
      & first_duplicate, net_lattice, graphite_lattice, square_lattice, detect_lattice, fraction_map

   !> Species label that marks a vacant site in an XYZ file.
   character(len=*), parameter :: vacancy_mark = 'X'

   type :: crystal_net
      real(wp), allocatable :: position(:, :)   !! (3, n) atom positions, Å
      integer, allocatable :: species(:)        !! (n) index into the species table
   contains
      procedure :: size => net_size
      procedure :: remove_sites
      procedure :: substitute
   end type crystal_net

   !> The periodic lattice a net is cut from: the lateral lattice vectors
   !> a1, a2 (columns of `vectors`, Å, in the plane of the net) and the
   !> atoms of the cell at the origin.  A net of this lattice has its atoms
   !> at i a1 + j a2 + basis(:, b) (integer i, j), less its vacancies and
   !> edges, its substitutions of another species; friction_surface_lennard_jones
   !> tabulates the potential of the perfect lattice over one cell and sums
   !> the differences directly.
   type :: net_lattice
      real(wp) :: vectors(2, 2) = 0.0_wp
      real(wp), allocatable :: basis(:, :)   !! (3, atoms per cell), Å
      integer, allocatable :: species(:)     !! (atoms per cell)
   contains
      procedure :: sites => lattice_sites
   end type net_lattice

contains

   !> The lattice of graphite_net(a, shells): vectors (a, 0), (a/2, a√3/2)
   !> and the two atoms (0, ±a/√3, 0) of the hexagon centred on the origin.
   pure function graphite_lattice(a) result(lattice)
      real(wp), intent(in) :: a
      type(net_lattice) :: lattice

      lattice%vectors = reshape([a, 0.0_wp, a / 2, a * sqrt(3.0_wp) / 2], [2, 2])
      lattice%basis = reshape([0.0_wp, a / sqrt(3.0_wp), 0.0_wp, 0.0_wp, -a / sqrt(3.0_wp), 0.0_wp], [3, 2])
      lattice%species = [1, 1]
   end function graphite_lattice

   !> The lattice of square_net(a, side): vectors (a, 0), (0, a), one atom,
   !> at the origin for an odd side and at (a/2, a/2) for an even one.
   pure function square_lattice(a, side) result(lattice)
      real(wp), intent(in) :: a
      integer, intent(in) :: side
      type(net_lattice) :: lattice
      real(wp) :: offset

      lattice%vectors = reshape([a, 0.0_wp, 0.0_wp, a], [2, 2])
      offset = merge(0.0_wp, 0.5_wp * a, mod(side, 2) == 1)
      lattice%basis = reshape([offset, offset, 0.0_wp], [3, 1])
      lattice%species = [1]
   end function square_lattice

   !> The map from a point (x, y) of the plane to its fractional
   !> coordinates s in the lattice vectors (vectors(:, i), not parallel):
   !> s = m (x, y), m the inverse of the matrix whose columns they are.
   pure function fraction_map(vectors) result(m)
      real(wp), intent(in) :: vectors(2, 2)
      real(wp) :: m(2, 2)

      associate (v => vectors)
         m = reshape([v(2, 2), -v(2, 1), -v(1, 2), v(1, 1)], [2, 2]) / (v(1, 1) * v(2, 2) - v(1, 2) * v(2, 1))
      end associate
   end function fraction_map

   !> The sites of the lattice whose (x, y) lie in box = (x_min, x_max,
   !> y_min, y_max), Å, with their species, as a net.
   pure function lattice_sites(self, box) result(net)
      class(net_lattice), intent(in) :: self
      real(wp), intent(in) :: box(4)
      type(crystal_net) :: net
      real(wp) :: inverse(2, 2), corner(2), s(2), lower(2), upper(2), p(2)
      integer :: i, j, b, k, n, lo(2), hi(2)
      real(wp), allocatable :: position(:, :)
      integer, allocatable :: species(:)

      inverse = fraction_map(self%vectors)
      ! The range of cell indices whose cells can reach into the box.
      lower = huge(1.0_wp)
      upper = -huge(1.0_wp)
      do k = 1, 4
         corner = [box(1 + merge(1, 0, k > 2)), box(3 + mod(k - 1, 2))]
         do b = 1, size(self%species)
            s = matmul(inverse, corner - self%basis(1:2, b))
            lower = min(lower, s)
            upper = max(upper, s)
         end do
      end do
      lo = floor(lower) - 1
      hi = ceiling(upper) + 1
      allocate (position(3, (hi(1) - lo(1) + 1) * (hi(2) - lo(2) + 1) * size(self%species)))
      allocate (species(size(position, 2)))
      n = 0
      do j = lo(2), hi(2)
         do i = lo(1), hi(1)
            do b = 1, size(self%species)
               ! (As graphite_net computes its positions, so the sites match its atoms bit for bit.)
               p = i * self%vectors(:, 1) + j * self%vectors(:, 2) + self%basis(1:2, b)
               if (p(1) < box(1) .or. p(1) > box(2) .or. p(2) < box(3) .or. p(2) > box(4)) cycle
               n = n + 1
               position(1:2, n) = p
               position(3, n) = self%basis(3, b)
               species(n) = self%species(b)
            end do
         end do
      end do
      net%position = position(:, 1:n)
      net%species = species(1:n)
   end function lattice_sites

   !> The lattice a net (read from a file) is cut from, found around its
   !> middle; `reason` says why not when it has none (then empty on success).
   !> Around an atom o near the middle (the median of the positions; the
   !> next nearest when o is no site of a lattice, an adatom say) the 48
   !> atoms nearest to it; a difference p_j - p_o in the plane is a lattice
   !> vector when it carries at least 3/4 of those atoms onto atoms of their
   !> species (a vacancy or an edge spoils a few).  a1 is the shortest such,
   !> a2 the shortest not parallel to it (the two shortest independent
   !> vectors of a plane lattice are a basis of it), each averaged over the
   !> pairs it carries (positions in files are rounded).  The basis: the
   !> positions of those atoms within the cell, by species, that hold at
   !> least a quarter of the atoms of the most common one (a substitution
   !> or an adatom is a difference, not a site).  Correctness does not rest
   !> on this: the table adds every difference between the net and the
   !> lattice back, a poor lattice only makes those many.
   subroutine detect_lattice(net, lattice, reason)
      type(crystal_net), intent(in) :: net
      type(net_lattice), intent(out) :: lattice
      character(len=:), allocatable, intent(out) :: reason
      integer, parameter :: near = 48, tries = 4
      real(wp), parameter :: same = 1.0e-6_wp
      integer, allocatable :: by_x(:), by_distance(:)
      real(wp) :: middle(2)
      integer :: n, k, attempt

      reason = ''
      n = net%size()
      if (n < 4) then
         reason = 'fewer than 4 atoms'
         return
      end if
      by_x = sort_order(net%position(1, :))
      do k = 1, 2
         block
            integer, allocatable :: order(:)
            order = sort_order(net%position(k, :))
            middle(k) = 0.5_wp * (net%position(k, order((n + 1) / 2)) + net%position(k, order(n / 2 + 1)))
         end block
      end do
      by_distance = sort_order((net%position(1, :) - middle(1))**2 + (net%position(2, :) - middle(2))**2)
      do attempt = 1, min(tries, n)
         call around(by_distance(attempt))
         if (len(reason) == 0) return
      end do

   contains

      !> The lattice around atom o, or `reason`.
      subroutine around(o)
         integer, intent(in) :: o
         integer, allocatable :: local(:), lengths(:)
         real(wp), allocatable :: candidates(:, :), averaged(:, :)
         logical, allocatable :: accepted(:)
         real(wp) :: t(3), total(2), inverse(2, 2), f(2), cross
         integer :: m, i, j, found, partner, nc, first, second, most
         integer, allocatable :: class_of(:), count_of(:)
         real(wp), allocatable :: class_position(:, :)
         integer, allocatable :: class_species(:)

         reason = ''
         m = min(near, n)
         local = sort_order((net%position(1, :) - net%position(1, o))**2 &
            & + (net%position(2, :) - net%position(2, o))**2)
         local = local(1:m)
         allocate (candidates(3, m), averaged(2, m), accepted(m))
         nc = 0
         do j = 1, m
            t = net%position(:, local(j)) - net%position(:, o)
            if (abs(t(3)) > same .or. norm2(t(1:2)) < 1.0e-3_wp) cycle
            found = 0
            total = 0.0_wp
            do i = 1, m
               partner = atom_at(net%position(:, local(i)) + t, net%species(local(i)))
               if (partner == 0) cycle
               found = found + 1
               total = total + net%position(1:2, partner) - net%position(1:2, local(i))
            end do
            if (4 * found < 3 * m) cycle
            nc = nc + 1
            candidates(:, nc) = t
            averaged(:, nc) = total / found
         end do
         if (nc < 2) then
            reason = 'no two translations carry the atoms around the middle onto atoms'
            return
         end if
         ! The shortest, then the shortest not parallel to it (ties: the order found).
         lengths = sort_order(norm2(candidates(1:2, 1:nc), dim=1))
         first = lengths(1)
         second = 0
         do k = 2, nc
            j = lengths(k)
            cross = averaged(1, first) * averaged(2, j) - averaged(2, first) * averaged(1, j)
            if (abs(cross) > 1.0e-3_wp * norm2(averaged(:, first)) * norm2(averaged(:, j))) then
               second = j
               exit
            end if
         end do
         if (second == 0) then
            reason = 'the translations around the middle are all parallel'
            return
         end if
         lattice%vectors(:, 1) = averaged(:, first)
         lattice%vectors(:, 2) = averaged(:, second) * sign(1.0_wp, &
            & averaged(1, first) * averaged(2, second) - averaged(2, first) * averaged(1, second))
         inverse = fraction_map(lattice%vectors)
         ! The basis: the atoms' positions in the cell of o, by species.
         allocate (class_of(m), count_of(m), class_position(3, m), class_species(m))
         most = 0
         count_of = 0
         k = 0
         do i = 1, m
            f = matmul(inverse, net%position(1:2, local(i)) - net%position(1:2, o))
            f = f - floor(f + 1.0e-6_wp)
            class_of(i) = 0
            do j = 1, k
               if (class_species(j) == net%species(local(i)) .and. &
                  & all(abs(class_position(1:2, j) - f) < 1.0e-4_wp) .and. &
                  & abs(class_position(3, j) - net%position(3, local(i))) < 1.0e-4_wp) class_of(i) = j
            end do
            if (class_of(i) == 0) then
               k = k + 1
               class_of(i) = k
               class_position(:, k) = [f(1), f(2), net%position(3, local(i))]
               class_species(k) = net%species(local(i))
            end if
            count_of(class_of(i)) = count_of(class_of(i)) + 1
         end do
         most = maxval(count_of(1:k))
         lattice%basis = reshape([real(wp) ::], [3, 0])
         lattice%species = [integer ::]
         do j = 1, k
            if (4 * count_of(j) < most) cycle
            ! (Two species at one place: the more common is the lattice's.)
            if (any(count_of(1:k) > count_of(j) .and. [(all(abs(class_position(:, i) - class_position(:, j)) &
               & < 1.0e-4_wp), i = 1, k)])) cycle
            lattice%basis = reshape([lattice%basis, net%position(1:2, o) + class_position(1, j) * lattice%vectors(:, 1) &
               & + class_position(2, j) * lattice%vectors(:, 2), class_position(3, j)], [3, size(lattice%species) + 1])
            lattice%species = [lattice%species, class_species(j)]
         end do
      end subroutine around

      !> The atom of `species` within `same` of p, or 0 (through the order by x).
      integer function atom_at(p, species) result(found)
         real(wp), intent(in) :: p(3)
         integer, intent(in) :: species
         integer :: low, high, middle_index, k

         found = 0
         ! The first atom with x >= p(1) - same.
         low = 1
         high = n + 1
         do while (low < high)
            middle_index = (low + high) / 2
            if (net%position(1, by_x(middle_index)) < p(1) - same) then
               low = middle_index + 1
            else
               high = middle_index
            end if
         end do
         do k = low, n
            if (net%position(1, by_x(k)) > p(1) + same) exit
            if (net%species(by_x(k)) /= species) cycle
            if (all(abs(net%position(:, by_x(k)) - p) <= same)) then
               found = by_x(k)
               return
            end if
         end do
      end function atom_at

   end subroutine detect_lattice

   pure integer function net_size(self)
      class(crystal_net), intent(in) :: self

      net_size = 0
      if (allocated(self%species)) net_size = size(self%species)
   end function net_size

   !> One graphene layer in the plane z = 0: the hexagons within `shells`
   !> hexagon-steps of the central one, centred on the origin, with lattice
   !> constant a (C–C bond a/√3).  Lattice vectors (a, 0), (a/2, a√3/2): the
   !> zigzag rows run along x, as for Eq. 2.  All atoms get species 1.
   pure function graphite_net(a, shells) result(net)
      real(wp), intent(in) :: a
      integer, intent(in) :: shells
      type(crystal_net) :: net
      ! A hexagon centred on cell (i, j) has its A atoms (offset (0, a/√3)) in
      ! cells (i, j), (i, j-1), (i+1, j-1) and its B atoms (offset (0, -a/√3))
      ! in cells (i, j), (i, j+1), (i-1, j+1): marking them on the cell grid
      ! shares the atoms of neighbouring hexagons without any search.
      integer, parameter :: a_cells(2, 3) = reshape([0, 0, 0, -1, 1, -1], [2, 3])
      integer, parameter :: b_cells(2, 3) = reshape([0, 0, 0, 1, -1, 1], [2, 3])
      logical :: occupied(-shells - 1:shells + 1, -shells - 1:shells + 1, 2)
      real(wp) :: a1(2), a2(2), offset(2, 2)
      integer :: i, j, k, sub, n

      a1 = [a, 0.0_wp]
      a2 = [a / 2, a * sqrt(3.0_wp) / 2]
      offset(:, 1) = [0.0_wp, a / sqrt(3.0_wp)]
      offset(:, 2) = [0.0_wp, -a / sqrt(3.0_wp)]
      occupied = .false.
      ! Hexagon centres i a1 + j a2 with hexagonal distance max(|i|, |j|, |i+j|) <= shells.
      do j = -shells, shells
         do i = -shells, shells
            if (max(abs(i), abs(j), abs(i + j)) > shells) cycle
            do k = 1, 3
               occupied(i + a_cells(1, k), j + a_cells(2, k), 1) = .true.
               occupied(i + b_cells(1, k), j + b_cells(2, k), 2) = .true.
            end do
         end do
      end do
      n = count(occupied)
      allocate (net%position(3, n), net%species(n))
      n = 0
      do j = -shells - 1, shells + 1
         do i = -shells - 1, shells + 1
            do sub = 1, 2
               if (.not. occupied(i, j, sub)) cycle
               n = n + 1
               net%position(1:2, n) = i * a1 + j * a2 + offset(:, sub)
            end do
         end do
      end do
      net%position(3, :) = 0.0_wp
      net%species = 1
   end function graphite_net

   !> A square net of side atoms per edge, spacing a, centred on the origin,
   !> in the plane z = 0; species 1.
   pure function square_net(a, side) result(net)
      real(wp), intent(in) :: a
      integer, intent(in) :: side
      type(crystal_net) :: net
      integer :: i, j, n

      allocate (net%position(3, side * side), net%species(side * side))
      n = 0
      do j = 1, side
         do i = 1, side
            n = n + 1
            net%position(:, n) = [(i - 1 - (side - 1) / 2.0_wp) * a, (j - 1 - (side - 1) / 2.0_wp) * a, 0.0_wp]
         end do
      end do
      net%species = 1
   end function square_net

   !> Remove the sites marked (vacancies).
   pure subroutine remove_sites(self, vacant)
      class(crystal_net), intent(inout) :: self
      logical, intent(in) :: vacant(:)
      real(wp), allocatable :: position(:, :)
      integer, allocatable :: species(:)
      integer :: i, n

      allocate (position(3, count(.not. vacant)), species(count(.not. vacant)))
      n = 0
      do i = 1, size(vacant)
         if (vacant(i)) cycle
         n = n + 1
         position(:, n) = self%position(:, i)
         species(n) = self%species(i)
      end do
      call move_alloc(position, self%position)
      call move_alloc(species, self%species)
   end subroutine remove_sites

   !> Put species `kind` at the given sites.
   pure subroutine substitute(self, sites, kind)
      class(crystal_net), intent(inout) :: self
      integer, intent(in) :: sites(:), kind

      self%species(sites) = kind
   end subroutine substitute

   !> Read a net from an XYZ file.  Species labels are looked up in
   !> species_names; the label `X` marks a vacancy (the site counts for site
   !> numbers but holds no atom).  Errors name the file and the line.
   subroutine read_xyz(path, species_names, net, error)
      character(len=*), intent(in) :: path
      character(len=*), intent(in) :: species_names(:)
      type(crystal_net), intent(out) :: net
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: line, problem
      character(len=256) :: message
      character(len=64) :: label
      real(wp), allocatable :: position(:, :)
      integer, allocatable :: species(:)
      logical, allocatable :: vacant(:)
      integer, allocatable :: kept(:)
      type(crystal_net) :: atoms
      integer :: unit, stat, n, i, k, number

      call open_for_reading(path, unit, error, error_io)
      if (allocated(error)) return
      message = ''
      number = 0
      call next_line()
      if (allocated(error)) return
      if (stat == 0) read (line, *, iostat=stat) n
      if (stat /= 0 .or. n < 1) then
         call fatal_error(error, path//':1: the first line must hold the number of atoms (>= 1)', error_input)
         close (unit)
         return
      end if
      call next_line()   ! comment line
      if (allocated(error)) return
      allocate (position(3, n), species(n), vacant(n), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, path//':1: '//itoa(n)//' atoms announced: more than this machine can hold', &
            & error_input)
         close (unit)
         return
      end if
      do i = 1, n
         call next_line()
         if (allocated(error)) return
         if (stat /= 0) then
            call fatal_error(error, path//':'//itoa(i + 2)//': the file ends after '//itoa(i - 1) &
               & //' atoms, but its first line announces '//itoa(n), error_input)
            close (unit)
            return
         end if
         read (line, *, iostat=stat) label, position(:, i)
         if (stat /= 0 .or. .not. all(abs(position(:, i)) <= huge(1.0_wp))) then
            call fatal_error(error, path//':'//itoa(i + 2)//': expected "species x y z" with numbers, got "' &
               & //one_line(trim(line), 100)//'"', error_input)
            close (unit)
            return
         end if
         vacant(i) = trim(label) == vacancy_mark
         species(i) = 0
         do k = 1, size(species_names)
            if (trim(label) == trim(species_names(k))) species(i) = k
         end do
         if (species(i) == 0 .and. .not. vacant(i)) then
            call fatal_error(error, path//':'//itoa(i + 2)//": unknown species '"//trim(label) &
               & //"' (known: "//join(species_names)//', and '//vacancy_mark//' for a vacancy)', error_input)
            close (unit)
            return
         end if
      end do
      ! Anything but blank lines after the announced atoms means a wrong count.
      do
         call next_line()
         if (allocated(error)) return
         if (stat /= 0) exit
         if (len_trim(line) > 0) then
            call fatal_error(error, path//':'//itoa(n + 3)//': more atoms than the '//itoa(n) &
               & //' the first line announces', error_input)
            close (unit)
            return
         end if
      end do
      close (unit)
      net%position = position
      net%species = max(species, 1)
      ! Two atoms at one place (a copied line, a net written twice) make no
      ! physical sample and multiply the cost: an error naming both lines.
      kept = pack([(i, i = 1, n)], .not. vacant)
      atoms%position = position(:, kept)
      atoms%species = net%species(kept)
      call first_duplicate(atoms, 1.0e-6_wp, i, k)
      if (i > 0) then
         call fatal_error(error, path//':'//itoa(kept(k) + 2)//': the atom is at the position of the atom on ' &
            & //'line '//itoa(kept(i) + 2)//' (within 1e-6 Å); remove the duplicate', error_input)
         return
      end if
      call net%remove_sites(vacant)

   contains

      !> The next line in `line` (stat < 0 at the end); a line that is not
      !> text (a control character, a device's endless bytes) or a read error
      !> closes the file with an error naming the line.
      subroutine next_line()
         call read_text_line(unit, line, stat, message, problem)
         if (stat > 0) then
            call fatal_error(error, path//':'//itoa(number + 1)//': cannot read the file ('//trim(message)//')', &
               & error_io)
         else if (stat == 0) then
            number = number + 1
            if (len(problem) > 0) call fatal_error(error, path//':'//itoa(number)//': '//problem, error_input)
         end if
         if (allocated(error)) close (unit)
      end subroutine next_line

   end subroutine read_xyz

   !> The indices that put `values` in ascending order (a stable bottom-up
   !> merge sort: n log n for nets of any size).
   pure function sort_order(values) result(order)
      real(wp), intent(in) :: values(:)
      integer :: order(size(values))
      integer :: scratch(size(values))
      integer :: n, width, left, middle, right, i, j, k

      n = size(values)
      order = [(i, i = 1, n)]
      width = 1
      do while (width < n)
         left = 1
         do while (left <= n)
            middle = min(left + width, n + 1)
            right = min(left + 2 * width, n + 1)
            i = left
            j = middle
            do k = left, right - 1
               if (i < middle .and. (j >= right .or. values(order(min(i, n))) <= values(order(min(j, n))))) then
                  scratch(k) = order(i)
                  i = i + 1
               else
                  scratch(k) = order(j)
                  j = j + 1
               end if
            end do
            left = right
         end do
         order = scratch
         width = 2 * width
      end do
   end function sort_order

   !> The largest areal density, atoms/Å², of the net seen from above over
   !> discs of `radius` (Å) centred on its atoms: an upper bound of the
   !> density anywhere in it (however far its atoms spread), unlike the
   !> density of its bounding box.
   pure real(wp) function max_local_density(net, radius) result(density)
      type(crystal_net), intent(in) :: net
      real(wp), intent(in) :: radius
      integer, allocatable :: order(:)
      integer :: n, k, low, m, inside, best, i, j

      n = net%size()
      density = 0.0_wp
      if (n == 0) return
      order = sort_order(net%position(1, :))
      best = 0
      low = 1
      do k = 1, n
         i = order(k)
         do while (net%position(1, order(low)) < net%position(1, i) - radius)
            low = low + 1
         end do
         inside = 0
         m = low
         do while (m <= n)
            j = order(m)
            if (net%position(1, j) > net%position(1, i) + radius) exit
            if (sum((net%position(1:2, j) - net%position(1:2, i))**2) < radius**2) inside = inside + 1
            m = m + 1
         end do
         best = max(best, inside)
      end do
      density = best / (3.14159265358979323846_wp * radius**2)
   end function max_local_density

   !> The first pair of atoms (i < j, in the net's order) closer than
   !> `distance` (Å) in 3D; 0, 0 when there is none.
   pure subroutine first_duplicate(net, distance, first, second)
      type(crystal_net), intent(in) :: net
      real(wp), intent(in) :: distance
      integer, intent(out) :: first, second
      integer, allocatable :: order(:)
      integer :: n, k, m, i, j

      first = 0
      second = 0
      n = net%size()
      if (n < 2) return
      order = sort_order(net%position(1, :))
      do k = 1, n - 1
         i = order(k)
         do m = k + 1, n
            j = order(m)
            if (net%position(1, j) - net%position(1, i) >= distance) exit
            if (sum((net%position(:, j) - net%position(:, i))**2) < distance**2) then
               if (first == 0 .or. min(i, j) < first .or. (min(i, j) == first .and. max(i, j) < second)) then
                  first = min(i, j)
                  second = max(i, j)
               end if
            end if
         end do
      end do
   end subroutine first_duplicate

   !> Write a net as XYZ (positions to 1e-10 Å).
   subroutine write_xyz(path, net, species_names, comment, error)
      character(len=*), intent(in) :: path, comment
      type(crystal_net), intent(in) :: net
      character(len=*), intent(in) :: species_names(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: unit, stat, i

      open (newunit=unit, file=path, status='replace', action='write', iostat=stat)
      if (stat /= 0) then
         call fatal_error(error, path//': cannot write the file', error_io)
         return
      end if
      write (unit, '(i0)') net%size()
      write (unit, '(a)') comment
      do i = 1, net%size()
         write (unit, '(a, 3(1x, f18.10))') trim(species_names(net%species(i))), net%position(:, i)
      end do
      close (unit)
   end subroutine write_xyz

end module friction_surface_net
