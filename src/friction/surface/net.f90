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
   use friction_strings, only: itoa, join
   use friction_files, only: open_for_reading
   implicit none
   private

   public :: crystal_net, graphite_net, square_net, read_xyz, write_xyz, vacancy_mark, sort_order, max_local_density, &
      & first_duplicate

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

contains

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
      character(len=1024) :: line
      character(len=64) :: label
      real(wp), allocatable :: position(:, :)
      integer, allocatable :: species(:)
      logical, allocatable :: vacant(:)
      integer, allocatable :: kept(:)
      type(crystal_net) :: atoms
      integer :: unit, stat, n, i, k

      call open_for_reading(path, unit, error, error_io)
      if (allocated(error)) return
      read (unit, '(a)', iostat=stat) line
      if (stat == 0) read (line, *, iostat=stat) n
      if (stat /= 0 .or. n < 1) then
         call fatal_error(error, path//':1: the first line must hold the number of atoms (>= 1)', error_input)
         close (unit)
         return
      end if
      read (unit, '(a)', iostat=stat) line   ! comment line
      allocate (position(3, n), species(n), vacant(n), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, path//':1: '//itoa(n)//' atoms announced: more than this machine can hold', &
            & error_input)
         close (unit)
         return
      end if
      do i = 1, n
         read (unit, '(a)', iostat=stat) line
         if (stat /= 0) then
            call fatal_error(error, path//':'//itoa(i + 2)//': the file ends after '//itoa(i - 1) &
               & //' atoms, but its first line announces '//itoa(n), error_input)
            close (unit)
            return
         end if
         read (line, *, iostat=stat) label, position(:, i)
         if (stat /= 0 .or. .not. all(abs(position(:, i)) <= huge(1.0_wp))) then
            call fatal_error(error, path//':'//itoa(i + 2)//': expected "species x y z" with numbers, got "' &
               & //trim(line)//'"', error_input)
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
         read (unit, '(a)', iostat=stat) line
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
