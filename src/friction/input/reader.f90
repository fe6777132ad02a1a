!> Namelist files into a configuration.  Files are read in order and a later
!> file overrides earlier values variable by variable, so a two-line
!> override file tweaks or sweeps a job.  Every assignment is checked
!> against the variables the configurations declare (an unknown variable or
!> a value of the wrong kind is an error naming the file, line, group and
!> variable) and set through the configuration's own description of its
!> variables (core/parameters.f90); where each value came from is kept for
!> the messages of the configuration's checks.
module friction_input_reader
   use friction_strings, only: itoa, join
   use friction_error, only: error_type, fatal_error, error_input
   use friction_parameters, only: configurable, parameter_info, set_parameter, list_parameters, kind_text, value_has_kind, &
      & split_name
   use friction_checks, only: config_checker
   use friction_input_scan, only: mention, scan_namelist_file
   implicit none
   private

   public :: namelist_source, scan_files, last_text, apply_files

   !> The assignments of one file.
   type :: namelist_source
      character(len=:), allocatable :: path
      type(mention), allocatable :: mentions(:)
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
         call scan_namelist_file(sources(k)%path, known_groups, sources(k)%mentions, error)
         if (allocated(error)) return
      end do
   end subroutine scan_files

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
   !> checker learns where each value came from.
   subroutine apply_files(sources, universe, target, checker, error)
      type(namelist_source), intent(in) :: sources(:)
      type(parameter_info), intent(in) :: universe(:)
      class(configurable), intent(inout) :: target
      type(config_checker), intent(inout) :: checker
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: problem, base, where, shown
      character(len=32), allocatable :: known(:)
      type(parameter_info), allocatable :: mine(:)
      integer :: f, k, u, slash

      mine = list_parameters(target)
      do f = 1, size(sources)
         ! Relative file names in a file are relative to its directory, made
         ! absolute so that the echoed input reads back from anywhere.
         slash = index(sources(f)%path, '/', back=.true.)
         base = sources(f)%path(1:slash)
         if (sources(f)%path(1:1) /= '/') base = working_directory()//base
         ! Names and kinds first, for the whole file: nothing is set from a file
         ! with a bad assignment.
         do k = 1, size(sources(f)%mentions)
            associate (m => sources(f)%mentions(k))
               where = sources(f)%path//':'//itoa(m%line)//': &'//trim(m%group)//': '
               u = find(m%group, m%name)
               if (u == 0) then
                  known = pack(universe%name, universe%group == m%group)
                  call fatal_error(error, where//"unknown variable '"//trim(m%name)//"' (known: " &
                     & //join(known)//')', error_input)
                  return
               end if
               if (.not. value_has_kind(m%value, universe(u)%kind)) then
                  call fatal_error(error, where//trim(m%name)//' = '//trim(one_line(m%value))//': expected ' &
                     & //kind_text(universe(u)%kind), error_input)
                  return
               end if
            end associate
         end do
         do k = 1, size(sources(f)%mentions)
            associate (m => sources(f)%mentions(k))
               if (.not. any(mine%group == m%group)) cycle   ! another scene's group
               where = sources(f)%path//':'//itoa(m%line)
               call set_parameter(target, trim(m%group), trim(m%name), m%value, m%first, base, problem)
               if (len(problem) > 0) then
                  shown = trim(m%name)
                  if (m%first > 0) shown = shown//'('//itoa(m%first)//')'
                  call fatal_error(error, where//': &'//trim(m%group)//': '//shown//' = '//trim(one_line(m%value)) &
                     & //': '//problem, error_input)
                  return
               end if
               call checker%set_origin(trim(m%group), trim(m%name), where)
            end associate
         end do
      end do

   contains

      integer function find(group, name)
         character(len=*), intent(in) :: group, name

         do find = 1, size(universe)
            if (universe(find)%group == group .and. universe(find)%name == name) return
         end do
         find = 0
      end function find

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

   !> A value's text on one line, for messages.
   pure function one_line(text) result(out)
      character(len=*), intent(in) :: text
      character(len=len(text)) :: out
      integer :: i

      out = text
      do i = 1, len(out)
         if (out(i:i) == new_line('a')) out(i:i) = ' '
      end do
   end function one_line

end module friction_input_reader
