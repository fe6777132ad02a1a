!> Named parameters of a configuration, reached by visiting: a configurable
!> type lists each of its variables once, with its namelist group, name and
!> unit (`call v%item('mass', self%mass, 'kg')`), and the visitor does what
!> its mode says with each one: list them, set one from namelist text or a
!> number, get one as text, or write them all as namelist text that reads
!> back to the same values.  Reading files, the sweep's in-memory override,
!> the C API's set and get, and the echo of a run's input all go through
!> this one description, so a variable declared once is known everywhere.
module friction_parameters
   use friction_kinds, only: wp, i8
   use friction_strings, only: lower, itoa
   use friction_plausibility, only: unit_plausibility
   use friction_value_text, only: split_name, real_words, run_lengths, quote, is_quoted, unquote, value_items, &
      & range_problem, is_utf8, kind_text, value_has_kind, max_list_values
   implicit none
   private

   public :: configurable, parameter_visitor, parameter_info, unit_hint, parameter_finding
   public :: list_parameters, set_parameter, set_parameter_number, get_parameter, parameters_text
   public :: implausible_values
   public :: parameter_table
   public :: kind_text, value_has_kind, split_name, max_list_values

   integer, parameter :: mode_list = 1, mode_set = 2, mode_get = 3, mode_write = 4, mode_inspect = 5

   !> One variable: where it lives, its kind ('r' real, 'i' integer, 'l'
   !> logical, 'c' text), its number of elements (1 for a scalar) and unit.
   type :: parameter_info
      character(len=32) :: group = ''
      character(len=32) :: name = ''
      character :: kind = 'r'
      integer :: size = 1
      character(len=40) :: unit = ''
      real(wp) :: value = 0.0_wp    !! a real scalar's value when listed (what get_parameter would read back)
   end type parameter_info

   !> A real value that looks like a number in another unit than its
   !> variable's (friction_plausibility): which element, and why.
   type :: parameter_finding
      character(len=32) :: group = ''
      character(len=32) :: name = ''
      integer :: index = 0                      !! the element of an array; 0 for a scalar
      character(len=64) :: value = ''           !! the value as namelist text
      character(len=512) :: reason = ''
   end type parameter_finding

   type :: parameter_visitor
      integer :: mode = mode_list
      character(len=32) :: group = ''          !! the group being visited
      logical :: group_wanted = .false.        !! set, get: whether it is want_group (compared once a group)
      character(len=32) :: want_group = ''     !! set, get: the variable's group (or '' for all, write)
      character(len=32) :: want_name = ''      !! set, get: the variable's name
      integer :: first = 0                     !! set, get: the element given, name(first); 0 whole
      logical :: from_number = .false.         !! set: take `number` instead of `text`
      real(wp) :: number = 0.0_wp
      character(len=:), allocatable :: text    !! set: value text; get: the value; write: the namelist
      character(len=:), allocatable :: base    !! set: directory that relative paths are relative to
      character(len=:), allocatable :: problem !! set: why the value does not fit ('' when it did)
      logical :: found = .false.
      !> list: the variables, list(1:listed) (grown by doubling: appending
      !> one at a time copied the whole list at every variable)
      type(parameter_info), allocatable :: list(:)
      integer :: listed = 0
      character(len=32), allocatable :: only(:)  !! write: the groups to write (all when unallocated)
      logical :: in_group = .false.
      logical :: units = .false.                 !! write: each variable's unit as a comment after it
      type(parameter_finding), allocatable :: findings(:)  !! inspect: the implausible values
   contains
      procedure :: begin_group
      procedure :: end_group
      procedure, private :: real_scalar, real_array, integer_scalar, integer_array, long_scalar, &
         & logical_scalar, text_scalar, text_array
      generic :: item => real_scalar, real_array, integer_scalar, integer_array, long_scalar, &
         & logical_scalar, text_scalar, text_array
      !> A real list of any length (allocatable): a list given whole
      !> replaces it; an element past its end lengthens it.
      procedure :: real_list
      procedure :: setting
      procedure, private :: wants, add_info, add_line, element_ok, inspect_reals
   end type parameter_visitor

   !> The positions of (group, name) pairs in a list of variables, found by
   !> hashing: reading an input looks each assignment up in the list of every
   !> scene's variables, and building that list drops the pairs two scenes
   !> share, both in time in proportion to the list instead of its square.
   type :: parameter_table
      character(len=32), allocatable :: groups(:), names(:)   !! the pairs, in the order added
      integer, allocatable :: slots(:)   !! open addressing: 0 empty, else a position in groups/names
      integer :: n = 0
   contains
      procedure :: find => table_find
      procedure :: add => table_add
   end type parameter_table

   !> A type whose variables can be visited.
   type, abstract :: configurable
   contains
      procedure(visit_interface), deferred :: visit
   end type configurable

   abstract interface
      subroutine visit_interface(self, v)
         import :: configurable, parameter_visitor
         class(configurable), intent(inout) :: self
         type(parameter_visitor), intent(inout) :: v
      end subroutine visit_interface
   end interface


contains

   ! ---- the table of names ----

   !> The slot of group.name's hash (its first probe).  Names have no blanks
   !> inside, so each is hashed up to its first blank: texts equal but for
   !> trailing blanks hash alike.
   pure integer function table_hash(group, name, n_slots) result(slot)
      character(len=*), intent(in) :: group, name
      integer, intent(in) :: n_slots
      integer :: h, k, c

      ! (Masked to 24 bits at every step, so no product overflows; the
      ! characters as codes, which gfortran compares without a library call.)
      h = 7
      do k = 1, len(group)
         c = ichar(group(k:k))
         if (c == 32) exit
         h = iand(h * 33 + c, 16777215)
      end do
      h = iand(h * 33 + 46, 16777215)
      do k = 1, len(name)
         c = ichar(name(k:k))
         if (c == 32) exit
         h = iand(h * 33 + c, 16777215)
      end do
      slot = iand(h, n_slots - 1) + 1
   end function table_hash

   !> The slot holding group.name, or the empty slot where it would go.
   integer function table_slot(self, group, name) result(slot)
      class(parameter_table), intent(in) :: self
      character(len=*), intent(in) :: group, name
      integer :: k

      slot = table_hash(group, name, size(self%slots))
      do
         k = self%slots(slot)
         if (k == 0) return
         if (self%groups(k) == group .and. self%names(k) == name) return
         slot = iand(slot, size(self%slots) - 1) + 1
      end do
   end function table_slot

   !> The position of group.name in the table (0 if absent).
   integer function table_find(self, group, name) result(found)
      class(parameter_table), intent(in) :: self
      character(len=*), intent(in) :: group, name

      found = 0
      if (self%n > 0) found = self%slots(table_slot(self, group, name))
   end function table_find

   !> Add group.name unless it is there; `position` is its position either
   !> way and `added` whether it is new.
   subroutine table_add(self, group, name, position, added)
      class(parameter_table), intent(inout) :: self
      character(len=*), intent(in) :: group, name
      integer, intent(out) :: position
      logical, intent(out) :: added
      character(len=32), allocatable :: grown(:)
      integer :: k, slot

      if (.not. allocated(self%groups)) then
         ! (Room for the some 300 variables of every scene without a rehash.)
         allocate (self%groups(512), self%names(512), self%slots(1024))
         self%slots = 0
      end if
      slot = table_slot(self, group, name)
      position = self%slots(slot)
      added = position == 0
      if (.not. added) return
      if (self%n == size(self%groups)) then
         allocate (grown(2 * self%n))
         grown(1:self%n) = self%groups(1:self%n)
         call move_alloc(grown, self%groups)
         allocate (grown(2 * self%n))
         grown(1:self%n) = self%names(1:self%n)
         call move_alloc(grown, self%names)
      end if
      self%n = self%n + 1
      self%groups(self%n) = group
      self%names(self%n) = name
      position = self%n
      ! At most half full (a power of two in size), so a probe ends soon at an empty slot.
      if (2 * self%n > size(self%slots)) then
         deallocate (self%slots)
         allocate (self%slots(4 * size(self%groups)))
         self%slots = 0
         do k = 1, self%n
            slot = table_slot(self, self%groups(k), self%names(k))
            self%slots(slot) = k
         end do
      else
         self%slots(slot) = position
      end if
   end subroutine table_add

   ! ---- visiting ----

   !> Start the variables of a namelist group.
   subroutine begin_group(self, name)
      class(parameter_visitor), intent(inout) :: self
      character(len=*), intent(in) :: name
      logical :: shown

      self%group = name
      self%group_wanted = (self%mode == mode_set .or. self%mode == mode_get) .and. self%group == self%want_group
      if (self%mode /= mode_write) return
      shown = .true.
      if (allocated(self%only)) shown = any(self%only == name)
      self%in_group = shown
      if (shown) self%text = self%text//'&'//trim(name)//new_line('a')
   end subroutine begin_group

   subroutine end_group(self)
      class(parameter_visitor), intent(inout) :: self

      if (self%mode == mode_write .and. self%in_group) self%text = self%text//'/'//new_line('a')
      self%in_group = .false.
      self%group = ''
      self%group_wanted = .false.
   end subroutine end_group

   !> For a value refused as not of its variable's kind: which unit counts,
   !> for a real with one (a unit written in the value, `velocity = 10 nm/s`,
   !> is a common slip and is not read); '' otherwise.
   pure function unit_hint(info) result(text)
      type(parameter_info), intent(in) :: info
      character(len=:), allocatable :: text

      text = ''
      if (info%kind == 'r' .and. len_trim(info%unit) > 0 .and. info%unit /= '1') text = ' in '//trim(info%unit) &
         & //' (the unit is fixed: write the number alone, converted to it)'
   end function unit_hint

   !> Whether the visitor sets a variable (a configuration that must know
   !> which of its values were given compares `found` around an item).
   logical function setting(self)
      class(parameter_visitor), intent(in) :: self

      setting = self%mode == mode_set
   end function setting

   !> Whether this variable is the one to set or get.
   logical function wants(self, name)
      class(parameter_visitor), intent(in) :: self
      character(len=*), intent(in) :: name

      wants = self%group_wanted .and. .not. self%found .and. name == self%want_name
   end function wants

   !> Whether the element asked for (first, 0 for all) is one of the n; if
   !> not, the problem says so.
   logical function element_ok(self, n) result(ok)
      class(parameter_visitor), intent(inout) :: self
      integer, intent(in) :: n

      ok = self%first <= n
      if (ok) return
      if (self%mode == mode_get) then
         self%problem = 'index '//itoa(self%first)//' is outside the '//itoa(n)//' elements'
      else
         self%problem = 'more values than the '//itoa(n)//' elements'
      end if
   end function element_ok

   subroutine add_info(self, name, kind, n, unit)
      class(parameter_visitor), intent(inout) :: self
      character(len=*), intent(in) :: name
      character, intent(in) :: kind
      integer, intent(in) :: n
      character(len=*), intent(in), optional :: unit
      type(parameter_info) :: info
      type(parameter_info), allocatable :: grown(:)

      info%group = self%group
      info%name = name
      info%kind = kind
      info%size = n
      if (present(unit)) info%unit = unit
      if (.not. allocated(self%list)) allocate (self%list(64))
      if (self%listed == size(self%list)) then
         allocate (grown(2 * size(self%list)))
         grown(1:self%listed) = self%list(1:self%listed)
         call move_alloc(grown, self%list)
      end if
      self%listed = self%listed + 1
      self%list(self%listed) = info
   end subroutine add_info

   !> One assignment of the namelist being written; with `units`, the
   !> variable's unit follows as a comment (none for '1', a pure number).
   subroutine add_line(self, name, value, unit)
      class(parameter_visitor), intent(inout) :: self
      character(len=*), intent(in) :: name, value
      character(len=*), intent(in), optional :: unit
      character(len=:), allocatable :: line

      if (.not. self%in_group) return
      line = '  '//name//' = '//value
      if (self%units .and. present(unit)) then
         if (len_trim(unit) > 0 .and. unit /= '1') line = line//repeat(' ', max(2, 32 - len(line)))//'! ' &
            & //trim(unit)
      end if
      self%text = self%text//line//new_line('a')
   end subroutine add_line

   !> Inspect: the elements of a real variable that look like numbers in
   !> another unit than `unit`.
   subroutine inspect_reals(self, name, value, unit)
      class(parameter_visitor), intent(inout) :: self
      character(len=*), intent(in) :: name
      real(wp), intent(in) :: value(:)
      character(len=*), intent(in), optional :: unit
      type(parameter_finding) :: finding
      character(len=:), allocatable :: reason
      character(len=26) :: words(1)
      integer :: k

      if (.not. present(unit)) return
      if (.not. allocated(self%findings)) allocate (self%findings(0))
      do k = 1, size(value)
         reason = unit_plausibility(unit, value(k))
         if (len(reason) == 0) cycle
         finding%group = self%group
         finding%name = name
         finding%index = merge(k, 0, size(value) > 1)
         words = real_words(value(k:k))
         finding%value = words(1)
         finding%reason = reason
         self%findings = [self%findings, finding]
      end do
   end subroutine inspect_reals

   subroutine real_scalar(self, name, value, unit)
      class(parameter_visitor), intent(inout) :: self
      character(len=*), intent(in) :: name
      real(wp), intent(inout) :: value
      character(len=*), intent(in), optional :: unit
      real(wp) :: values(1)

      values(1) = value
      call real_array(self, name, values, unit)
      value = values(1)
   end subroutine real_scalar

   !> A real array; with `fill`, a list given whole replaces the whole array
   !> (the elements after it take `fill`), not only its first elements.
   subroutine real_array(self, name, value, unit, fill)
      class(parameter_visitor), intent(inout) :: self
      character(len=*), intent(in) :: name
      real(wp), intent(inout) :: value(:)
      character(len=*), intent(in), optional :: unit
      real(wp), intent(in), optional :: fill
      integer, allocatable :: from(:), to(:)
      integer :: k, stat, n

      select case (self%mode)
      case (mode_list)
         call self%add_info(name, 'r', size(value), unit)
         if (size(value) == 1) self%list(self%listed)%value = value(1)
      case (mode_inspect)
         if (.not. present(fill)) call self%inspect_reals(name, value, unit)
      case (mode_write)
         if (present(fill)) then
            n = size(value)
            do while (n > 0)
               if (value(n) /= fill) exit
               n = n - 1
            end do
            if (n > 0) call self%add_line(name, run_lengths(real_words(value(1:n))), unit)
         else
            call self%add_line(name, run_lengths(real_words(value)), unit)
         end if
      case default
         if (.not. self%wants(name)) return
         self%found = .true.
         if (self%mode == mode_get) then
            if (self%element_ok(size(value))) then
               if (self%first > 0) then
                  self%text = run_lengths(real_words(value(self%first:self%first)))
               else
                  self%text = run_lengths(real_words(value))
               end if
            end if
            return
         end if
         if (self%from_number) then
            if (.not. self%element_ok(size(value))) return
            if (present(fill) .and. self%first == 0) value = fill
            value(max(1, self%first)) = self%number
            return
         end if
         call value_items(self%text, size(value), self%first, from, to, self%problem)
         if (len(self%problem) > 0) return
         if (present(fill) .and. self%first == 0) value = fill
         do k = 1, size(from)
            if (to(k) < from(k)) cycle   ! a null value leaves the element
            read (self%text(from(k):to(k)), *, iostat=stat) value(max(1, self%first) + k - 1)
            if (stat /= 0) then
               self%problem = 'expected '//kind_text('r')
               return
            end if
            self%problem = range_problem(self%text(from(k):to(k)), value(max(1, self%first) + k - 1))
            if (len(self%problem) > 0) return
         end do
      end select
   end subroutine real_array

   !> A real list of any length (the sweep's values: as many as the input
   !> gives).  Setting it whole replaces it; setting element `first` past
   !> its end lengthens it (the elements between take `fill`).
   subroutine real_list(self, name, value, fill, unit)
      class(parameter_visitor), intent(inout) :: self
      character(len=*), intent(in) :: name
      real(wp), allocatable, intent(inout) :: value(:)
      real(wp), intent(in) :: fill   !! an element that was never given
      character(len=*), intent(in), optional :: unit
      real(wp), allocatable :: grown(:)
      integer, allocatable :: from(:), to(:)
      integer :: k, stat, first, last

      if (.not. allocated(value)) allocate (value(0))
      select case (self%mode)
      case (mode_list, mode_write, mode_inspect)
         call self%real_array(name, value, unit, fill)
      case default
         if (.not. self%wants(name)) return
         if (self%mode == mode_get) then
            call self%real_array(name, value, unit, fill)
            return
         end if
         self%found = .true.
         first = max(1, self%first)
         if (self%from_number) then
            last = first
         else
            call value_items(self%text, max_list_values, self%first, from, to, self%problem)
            if (len(self%problem) > 0) return
            last = first + size(from) - 1
         end if
         if (self%first == 0) then
            deallocate (value)
            allocate (value(last), source=fill)
         else if (last > size(value)) then
            allocate (grown(last), source=fill)
            grown(1:size(value)) = value
            call move_alloc(grown, value)
         end if
         if (self%from_number) then
            value(first) = self%number
            return
         end if
         do k = 1, size(from)
            if (to(k) < from(k)) cycle   ! a null value leaves the element
            if (k > 1) then
               if (from(k) == from(k - 1) .and. to(k) == to(k - 1)) then   ! a repeat: read once
                  value(first + k - 1) = value(first + k - 2)
                  cycle
               end if
            end if
            read (self%text(from(k):to(k)), *, iostat=stat) value(first + k - 1)
            if (stat /= 0) then
               self%problem = 'expected '//kind_text('r')
               return
            end if
            self%problem = range_problem(self%text(from(k):to(k)), value(first + k - 1))
            if (len(self%problem) > 0) return
         end do
      end select
   end subroutine real_list

   subroutine integer_scalar(self, name, value, unit)
      class(parameter_visitor), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer, intent(inout) :: value
      character(len=*), intent(in), optional :: unit
      integer :: values(1)

      values(1) = value
      call integer_array(self, name, values, unit)
      value = values(1)
   end subroutine integer_scalar

   subroutine integer_array(self, name, value, unit)
      class(parameter_visitor), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer, intent(inout) :: value(:)
      character(len=*), intent(in), optional :: unit
      integer(i8) :: wide(size(value))

      wide = value
      call long_values(self, name, wide, unit, int(huge(value), i8))
      value = int(wide)
   end subroutine integer_array

   subroutine long_scalar(self, name, value, unit)
      class(parameter_visitor), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer(i8), intent(inout) :: value
      character(len=*), intent(in), optional :: unit
      integer(i8) :: values(1)

      values(1) = value
      call long_values(self, name, values, unit, huge(value))
      value = values(1)
   end subroutine long_scalar

   !> Integers of either width; `largest` bounds the magnitude.
   subroutine long_values(self, name, value, unit, largest)
      class(parameter_visitor), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer(i8), intent(inout) :: value(:)
      character(len=*), intent(in), optional :: unit
      integer(i8), intent(in) :: largest
      integer, allocatable :: from(:), to(:)
      character(len=24), allocatable :: words(:)
      integer :: k, stat
      integer(i8) :: m

      select case (self%mode)
      case (mode_list)
         call self%add_info(name, 'i', size(value), unit)
      case (mode_write, mode_get)
         if (self%mode == mode_get) then
            if (.not. self%wants(name)) return
            self%found = .true.
            if (.not. self%element_ok(size(value))) return
         end if
         allocate (words(size(value)))
         do k = 1, size(value)
            write (words(k), '(i0)') value(k)
         end do
         if (self%mode == mode_get) then
            if (self%first > 0) then
               self%text = trim(words(self%first))
            else
               self%text = run_lengths(words)
            end if
         else
            call self%add_line(name, run_lengths(words), unit)
         end if
      case default
         if (.not. self%wants(name)) return
         self%found = .true.
         if (self%from_number) then
            if (.not. self%element_ok(size(value))) return
            if (self%number /= anint(self%number) .or. .not. abs(self%number) <= real(largest, wp)) then
               self%problem = 'expected '//kind_text('i')
            else
               value(max(1, self%first)) = nint(self%number, i8)
            end if
            return
         end if
         call value_items(self%text, size(value), self%first, from, to, self%problem)
         if (len(self%problem) > 0) return
         do k = 1, size(from)
            if (to(k) < from(k)) cycle
            read (self%text(from(k):to(k)), *, iostat=stat) m
            if (stat /= 0 .or. verify(self%text(from(k):to(k)), '0123456789+-') /= 0 .or. abs(m) > largest) then
               self%problem = 'expected '//kind_text('i')
               return
            end if
            value(max(1, self%first) + k - 1) = m
         end do
      end select
   end subroutine long_values

   subroutine logical_scalar(self, name, value, unit)
      class(parameter_visitor), intent(inout) :: self
      character(len=*), intent(in) :: name
      logical, intent(inout) :: value
      character(len=*), intent(in), optional :: unit
      integer, allocatable :: from(:), to(:)

      select case (self%mode)
      case (mode_list)
         call self%add_info(name, 'l', 1, unit)
      case (mode_write)
         call self%add_line(name, trim(merge('.true. ', '.false.', value)))
      case default
         if (.not. self%wants(name)) return
         self%found = .true.
         if (self%mode == mode_get) then
            if (self%element_ok(1)) self%text = trim(merge('.true. ', '.false.', value))
            return
         end if
         if (self%from_number) then
            self%problem = 'expected '//kind_text('l')
            return
         end if
         call value_items(self%text, 1, self%first, from, to, self%problem)
         if (len(self%problem) > 0) return
         if (to(1) < from(1)) return
         select case (lower(self%text(from(1):to(1))))
         case ('t', '.t.', '.true.', 'true')
            value = .true.
         case ('f', '.f.', '.false.', 'false')
            value = .false.
         case default
            self%problem = 'expected '//kind_text('l')
         end select
      end select
   end subroutine logical_scalar

   !> Text; `fold` stores it in lower case (names of models, methods, ...);
   !> `path` makes a relative file name relative to the namelist file's
   !> directory when set from a file.
   subroutine text_scalar(self, name, value, unit, fold, path)
      class(parameter_visitor), intent(inout) :: self
      character(len=*), intent(in) :: name
      character(len=*), intent(inout) :: value
      character(len=*), intent(in), optional :: unit
      logical, intent(in), optional :: fold, path
      character(len=len(value)) :: values(1)
      logical :: found_before

      found_before = self%found
      values(1) = value
      call text_array(self, name, values, unit, fold)
      value = values(1)
      if (self%mode == mode_set .and. present(path) .and. self%found .and. .not. found_before &
         & .and. len(self%problem) == 0) then
         if (path .and. allocated(self%base) .and. len_trim(value) > 0) then
            if (value(1:1) /= '/' .and. len(self%base) > 0) value = self%base//trim(value)
         end if
      end if
   end subroutine text_scalar

   subroutine text_array(self, name, value, unit, fold)
      class(parameter_visitor), intent(inout) :: self
      character(len=*), intent(in) :: name
      character(len=*), intent(inout) :: value(:)
      character(len=*), intent(in), optional :: unit
      logical, intent(in), optional :: fold
      integer, allocatable :: from(:), to(:)
      ! (Quoted with each quote doubled: up to twice the text and the quotes.)
      character(len=2 * len(value) + 2), allocatable :: words(:)
      integer :: k
      logical :: folding

      folding = .false.
      if (present(fold)) folding = fold
      select case (self%mode)
      case (mode_list)
         call self%add_info(name, 'c', size(value), unit)
      case (mode_write, mode_get)
         if (self%mode == mode_get) then
            if (.not. self%wants(name)) return
            self%found = .true.
            if (.not. self%element_ok(size(value))) return
         end if
         allocate (words(size(value)))
         do k = 1, size(value)
            words(k) = quote(trim(value(k)))
         end do
         if (self%mode == mode_get) then
            if (self%first > 0) then
               self%text = trim(words(self%first))
            else
               self%text = run_lengths(words)
            end if
         else
            call self%add_line(name, run_lengths(words), unit)
         end if
      case default
         if (.not. self%wants(name)) return
         self%found = .true.
         if (self%from_number) then
            self%problem = 'expected '//kind_text('c')
            return
         end if
         call value_items(self%text, size(value), self%first, from, to, self%problem)
         if (len(self%problem) > 0) return
         do k = 1, size(from)
            if (to(k) < from(k)) cycle
            if (.not. is_quoted(self%text(from(k):to(k)))) then
               self%problem = 'expected '//kind_text('c')
               return
            end if
            if (.not. is_utf8(self%text(from(k) + 1:to(k) - 1))) then
               self%problem = 'not UTF-8 text: the value goes into the output''s UTF-8 attributes'
               return
            end if
            ! (A name of a choice (folded) that is too long is an unknown
            ! choice, which its check reports with the choices.)
            if (.not. folding .and. len(unquote(self%text(from(k):to(k)))) > len(value)) then
               self%problem = 'longer than '//itoa(len(value))//' characters'
               return
            end if
            value(max(1, self%first) + k - 1) = unquote(self%text(from(k):to(k)))
            if (folding) value(max(1, self%first) + k - 1) = lower(value(max(1, self%first) + k - 1))
         end do
      end select
   end subroutine text_array

   ! ---- operations on a configurable ----

   !> Every variable of obj, in the order it visits them.
   function list_parameters(obj) result(list)
      class(configurable), intent(inout) :: obj
      type(parameter_info), allocatable :: list(:)
      type(parameter_visitor) :: v

      v%mode = mode_list
      call obj%visit(v)
      if (allocated(v%list)) then
         list = v%list(1:v%listed)
      else
         allocate (list(0))
      end if
   end function list_parameters

   !> Set group.name (elements from `first` on, 0 for the whole variable)
   !> from namelist value text; `base` is the directory of the file it came
   !> from ('' for none).  `problem` says why it failed ('' on success).
   subroutine set_parameter(obj, group, name, text, first, base, problem)
      class(configurable), intent(inout) :: obj
      character(len=*), intent(in) :: group, name, text, base
      integer, intent(in) :: first
      character(len=:), allocatable, intent(out) :: problem
      type(parameter_visitor) :: v

      v%mode = mode_set
      v%want_group = group
      v%want_name = name
      v%first = first
      v%text = text
      v%base = base
      v%problem = ''
      call obj%visit(v)
      if (.not. v%found) then
         problem = 'no variable '//trim(name)//' in &'//trim(group)
      else
         problem = v%problem
      end if
   end subroutine set_parameter

   !> Set a numeric group.name (element `first` of an array, 0 for the
   !> first element of a whole one) to a number (an integer variable takes
   !> it when it is whole): the sweep's override and the C API's, no text in
   !> between.
   subroutine set_parameter_number(obj, group, name, number, problem, first)
      class(configurable), intent(inout) :: obj
      character(len=*), intent(in) :: group, name
      real(wp), intent(in) :: number
      character(len=:), allocatable, intent(out) :: problem
      integer, intent(in), optional :: first
      type(parameter_visitor) :: v

      v%mode = mode_set
      v%want_group = group
      v%want_name = name
      if (present(first)) v%first = first
      v%from_number = .true.
      v%number = number
      v%problem = ''
      call obj%visit(v)
      if (.not. v%found) then
         problem = 'no variable '//trim(name)//' in &'//trim(group)
      else
         problem = v%problem
      end if
   end subroutine set_parameter_number

   !> The value of group.name (its element `first`, 0 for all of it) as
   !> namelist text; `problem` says why there is none ('' when there is).
   subroutine get_parameter(obj, group, name, first, text, problem)
      class(configurable), intent(inout) :: obj
      character(len=*), intent(in) :: group, name
      integer, intent(in) :: first
      character(len=:), allocatable, intent(out) :: text, problem
      type(parameter_visitor) :: v

      v%mode = mode_get
      v%want_group = group
      v%want_name = name
      v%first = first
      v%text = ''
      v%problem = ''
      call obj%visit(v)
      text = v%text
      if (.not. v%found) then
         problem = 'no variable '//trim(name)//' in &'//trim(group)
      else
         problem = v%problem
      end if
   end subroutine get_parameter

   !> All variables as namelist text (the groups in `only` when present),
   !> reals with 17 significant digits so the text reads back to the same
   !> doubles; with `units`, each variable's unit as a comment after it.
   function parameters_text(obj, only, units) result(text)
      class(configurable), intent(inout) :: obj
      character(len=*), intent(in), optional :: only(:)
      logical, intent(in), optional :: units
      character(len=:), allocatable :: text
      type(parameter_visitor) :: v

      v%mode = mode_write
      v%text = ''
      if (present(units)) v%units = units
      if (present(only)) then
         allocate (v%only(size(only)))
         v%only = only
      end if
      call obj%visit(v)
      text = v%text
   end function parameters_text

   !> The real values of `obj` that look like numbers in another unit than
   !> their variable's (friction_plausibility), in the order visited.
   function implausible_values(obj) result(findings)
      class(configurable), intent(inout) :: obj
      type(parameter_finding), allocatable :: findings(:)
      type(parameter_visitor) :: v

      v%mode = mode_inspect
      allocate (v%findings(0))
      call obj%visit(v)
      call move_alloc(v%findings, findings)
   end function implausible_values

end module friction_parameters
