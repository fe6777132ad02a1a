!> Namelist files into a configuration.  Files are read in order and a later
!> file overrides earlier values variable by variable, so a two-line
!> override file tweaks or sweeps a job.  Every assignment is checked
!> against the variables the configurations declare (an unknown variable or
!> a value of the wrong kind is an error naming the file, line, group and
!> variable) and set through the configuration's own description of its
!> variables (core/parameters.f90); where each value came from is kept for
!> the messages of the configuration's checks.
module friction_input_reader
   use friction_strings, only: itoa, join, one_line
   use friction_error, only: error_type, fatal_error, error_input
   use friction_parameters, only: configurable, parameter_info, set_parameter, list_parameters, kind_text, value_has_kind, &
      & unit_hint, split_name, parameter_table
   use friction_checks, only: config_checker
   use friction_input_scan, only: mention, scan_namelist_file
   implicit none
   private

   public :: namelist_source, scan_files, last_text, apply_files, parse_variable_name, override_source, &
      & source_place

   !> The assignments of one file, or of one command-line override
   !> `--set group.variable=value` (its "file" is '--set group.variable=value',
   !> its one mention has no line, and relative file names in its value are
   !> relative to the working directory).
   type :: namelist_source
      character(len=:), allocatable :: path
      type(mention), allocatable :: mentions(:)
      logical :: override = .false.
      character(len=32), allocatable :: groups(:)   !! the groups the file opens (empty ones too)
      integer, allocatable :: group_lines(:)        !! and the line of each
   end type namelist_source

contains

   !> Scan every file (unknown groups, unclosed groups and missing files are
   !> errors here).
   subroutine scan_files(paths, known_groups, sources, error)
      character(len=*), intent(in) :: paths(:)
      character(len=*), intent(in) :: known_groups(:)
      type(namelist_source), allocatable, intent(out) :: sources(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: k

      allocate (sources(size(paths)))
      do k = 1, size(paths)
         sources(k)%path = trim(paths(k))
         call scan_namelist_file(sources(k)%path, known_groups, sources(k)%mentions, error, sources(k)%groups, &
            & sources(k)%group_lines)
         if (allocated(error)) return
      end do
   end subroutine scan_files

   !> Where a source's line is, for messages: 'file:line', or the override
   !> itself ('--set group.variable=value').
   function source_place(source, line) result(place)
      type(namelist_source), intent(in) :: source
      integer, intent(in) :: line
      character(len=:), allocatable :: place

      place = source%path
      if (.not. source%override) place = place//':'//itoa(line)
   end function source_place

   !> A variable's name 'group.variable' or 'group.variable(k)' (the C API's
   !> names, and --set's): its group (one of `known_groups`), variable and
   !> element (0 for none).  Whether the variable exists is the reader's
   !> check (apply_files), or the caller's.
   subroutine parse_variable_name(full, known_groups, group, name, first, error)
      character(len=*), intent(in) :: full
      character(len=*), intent(in) :: known_groups(:)
      character(len=:), allocatable, intent(out) :: group, name
      integer, intent(out) :: first
      type(error_type), allocatable, intent(out) :: error
      integer :: paren, stat

      first = 0
      call split_name(full, group, name)
      if (index(full, '.') == 0 .or. len(group) == 0 .or. len(name) == 0) then
         call fatal_error(error, "name '"//full//"': give a variable as 'group.variable', e.g. 'tip.kx' or " &
            & //"'surface.sigma(2)'", error_input)
         return
      end if
      paren = index(name, '(')
      if (paren > 0) then
         stat = 1
         if (name(len(name):) == ')' .and. paren < len(name) - 1) then
            if (verify(name(paren + 1:len(name) - 1), '0123456789') == 0) &
               & read (name(paren + 1:len(name) - 1), *, iostat=stat) first
         end if
         if (stat /= 0 .or. first < 1) then
            call fatal_error(error, "name '"//full//"': the element is a whole number >= 1 in parentheses, " &
               & //"e.g. 'surface.sigma(2)'", error_input)
            return
         end if
         name = name(1:paren - 1)
      end if
      if (.not. any(known_groups == group)) then
         call fatal_error(error, 'unknown namelist group &'//group//' (known: '//join(known_groups, ' ', '&')//')', &
            & error_input)
         return
      end if
   end subroutine parse_variable_name

   !> The source of one command-line override 'group.variable=value' (the
   !> text after --set); an error names '--set' and the override as its file.
   subroutine override_source(text, known_groups, source, error)
      character(len=*), intent(in) :: text
      character(len=*), intent(in) :: known_groups(:)
      type(namelist_source), intent(out) :: source
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: group, name
      integer :: equals, first

      source%path = '--set '//one_line(trim(text), 100)
      source%override = .true.
      allocate (source%mentions(1), source%groups(0), source%group_lines(0))
      equals = index(text, '=')
      if (equals == 0) then
         call fatal_error(error, source%path//": give 'group.variable=value', e.g. 'tip.kx=12.5'", error_input)
         return
      end if
      call parse_variable_name(trim(adjustl(text(1:equals - 1))), known_groups, group, name, first, error)
      if (allocated(error)) then
         error%message = source%path//': '//error%message
         return
      end if
      source%mentions(1)%group = group
      source%mentions(1)%name = name
      source%mentions(1)%first = first
      source%mentions(1)%value = trim(adjustl(text(equals + 1:)))
   end subroutine override_source

   !> The value text the files last give group.name ('' if none).
   function last_text(sources, group, name) result(text)
      type(namelist_source), intent(in) :: sources(:)
      character(len=*), intent(in) :: group, name
      character(len=:), allocatable :: text
      integer :: f, k

      text = ''
      do f = 1, size(sources)
         do k = 1, size(sources(f)%mentions)
            if (sources(f)%mentions(k)%group == group .and. sources(f)%mentions(k)%name == name) &
               & text = sources(f)%mentions(k)%value
         end do
      end do
   end function last_text

   !> Set `target` from the files, in order.  `universe` lists every variable
   !> of every group the files may name (groups of other scenes included,
   !> checked and ignored); only the groups `target` visits are set.  The
   !> checker learns where each value came from.  `table`, if given, holds
   !> universe's names, each at its position in universe (no name twice).
   subroutine apply_files(sources, universe, target, checker, error, table)
      type(namelist_source), intent(in) :: sources(:)
      type(parameter_info), intent(in) :: universe(:)
      class(configurable), intent(inout) :: target
      type(config_checker), intent(inout) :: checker
      type(error_type), allocatable, intent(out) :: error
      type(parameter_table), intent(in), optional :: table
      character(len=:), allocatable :: problem, base, where, shown
      character(len=32), allocatable :: known(:), own_groups(:)
      type(parameter_info), allocatable :: mine(:)
      type(parameter_table) :: names
      integer, allocatable :: first_at(:)   !! a name's first position in universe, by its position in names
      integer :: f, k, u, slash, position
      logical :: added

      mine = list_parameters(target)
      ! Each assignment is looked up by name, and each group once per
      ! variable listed: a search of the whole list per assignment cost more
      ! than setting the values.
      if (.not. present(table)) then
         allocate (first_at(size(universe)))
         do k = 1, size(universe)
            call names%add(universe(k)%group, universe(k)%name, position, added)
            if (added) first_at(position) = k
         end do
      end if
      allocate (own_groups(0))
      do k = 1, size(mine)
         if (k > 1) then
            if (mine(k)%group == mine(k - 1)%group) cycle
         end if
         if (.not. any(own_groups == mine(k)%group)) own_groups = [character(len=32) :: own_groups, mine(k)%group]
      end do
      do f = 1, size(sources)
         ! Relative file names in a file are relative to its directory, made
         ! absolute so that the echoed input reads back from anywhere.
         if (sources(f)%override) then
            base = working_directory()
         else
            slash = index(sources(f)%path, '/', back=.true.)
            base = sources(f)%path(1:slash)
            if (sources(f)%path(1:1) /= '/') base = working_directory()//base
         end if
         ! Names and kinds first, for the whole file: nothing is set from a file
         ! with a bad assignment.
         do k = 1, size(sources(f)%mentions)
            associate (m => sources(f)%mentions(k))
               if (present(table)) then
                  u = table%find(m%group, m%name)
               else
                  u = names%find(m%group, m%name)
                  if (u > 0) u = first_at(u)
               end if
               if (u == 0) then
                  where = source_place(sources(f), m%line)//': &'//trim(m%group)//': '
                  known = pack(universe%name, universe%group == m%group)
                  call fatal_error(error, where//"unknown variable '"//trim(m%name)//"' (known: " &
                     & //join(known)//')', error_input)
                  return
               end if
               if (.not. value_has_kind(m%value, universe(u)%kind)) then
                  where = source_place(sources(f), m%line)//': &'//trim(m%group)//': '
                  call fatal_error(error, where//trim(m%name)//' = '//trim(one_line(m%value, 100))//': expected ' &
                     & //kind_text(universe(u)%kind)//unit_hint(universe(u)), error_input)
                  return
               end if
            end associate
         end do
         do k = 1, size(sources(f)%mentions)
            associate (m => sources(f)%mentions(k))
               if (.not. any(own_groups == m%group)) cycle   ! another scene's group
               where = source_place(sources(f), m%line)
               call set_parameter(target, trim(m%group), trim(m%name), m%value, m%first, base, problem)
               if (len(problem) > 0) then
                  shown = trim(m%name)
                  if (m%first > 0) shown = shown//'('//itoa(m%first)//')'
                  call fatal_error(error, where//': &'//trim(m%group)//': '//shown//' = ' &
                     & //trim(one_line(m%value, 100))//': '//problem, error_input)
                  return
               end if
               call checker%set_origin(trim(m%group), trim(m%name), where)
            end associate
         end do
      end do

   end subroutine apply_files

   !> The working directory with a trailing '/' ('' if unknown).
   function working_directory() result(path)
      character(len=:), allocatable :: path
      character(len=4096) :: buffer
      integer :: stat

      call getcwd(buffer, stat)
      path = ''
      if (stat == 0) path = trim(buffer)//'/'
   end function working_directory

end module friction_input_reader
