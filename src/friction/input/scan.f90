!> A reading of namelist files that keeps what Fortran's own namelist input
!> loses: which groups a file has, which variables each one sets, with line
!> numbers and the value's text.  The reader (input/reader.f90) checks the
!> names and kinds and sets the values through the configuration's own
!> description of its variables (core/parameters.f90).
module friction_input_scan
   use friction_kinds, only: i8
   use friction_strings, only: join, lower, itoa
   use friction_error, only: error_type, fatal_error, error_input
   use friction_files, only: open_for_reading, read_text_line
   implicit none
   private

   public :: mention, scan_namelist_file

   !> One assignment `name = value` (or `name(first) = values`) inside group
   !> `&group` of a file; value is the text after '=' up to the next
   !> assignment or the group's closing '/', comments removed.
   type :: mention
      character(len=32) :: group = ''
      character(len=32) :: name = ''
      integer :: first = 0                      !! the index given, 0 for none
      integer :: line = 0
      character(len=:), allocatable :: value
   end type mention

contains

   pure logical function is_name_char(c)
      character, intent(in) :: c

      is_name_char = (c >= 'a' .and. c <= 'z') .or. (c >= '0' .and. c <= '9') .or. c == '_'
   end function is_name_char

   !> The groups and assignments of a namelist file.  Groups outside
   !> `known_groups`, a group given twice and a group not closed are errors
   !> naming the line.  `groups` and `group_lines`, if given, are the groups
   !> the file opens (empty ones too) and the line of each.
   subroutine scan_namelist_file(path, known_groups, mentions, error, groups, group_lines)
      character(len=*), intent(in) :: path
      character(len=*), intent(in) :: known_groups(:)
      type(mention), allocatable, intent(out) :: mentions(:)
      type(error_type), allocatable, intent(out) :: error
      character(len=32), allocatable, intent(out), optional :: groups(:)
      integer, allocatable, intent(out), optional :: group_lines(:)
      character(len=:), allocatable :: text, group
      integer, allocatable :: line_of(:)
      character(len=32), allocatable :: seen(:)
      integer, allocatable :: seen_lines(:)
      character :: quote
      integer :: i, j, k, n, value_from, first, count
      logical :: in_group, open_mention

      allocate (mentions(16), seen(0), seen_lines(0))
      count = 0
      if (present(groups)) allocate (groups(0))
      if (present(group_lines)) allocate (group_lines(0))
      call read_text(path, text, line_of, error)
      if (allocated(error)) return
      n = len(text)
      in_group = .false.
      open_mention = .false.
      quote = ' '
      group = ''
      value_from = 1
      i = 1
      do while (i <= n)
         associate (c => text(i:i))
            if (quote /= ' ') then
               if (c == quote) quote = ' '
            else if (.not. in_group .and. c /= '&' .and. c /= ' ' .and. c /= new_line('a') &
               & .and. c /= achar(9) .and. c /= achar(13)) then
               ! Outside a group nothing is read: text there would be dropped
               ! without a word (an assignment after '/', a group without '&').
               call outside_group_error(i)
               return
            else if (c == '"' .or. c == "'") then
               quote = c
            else if (c == '&' .and. .not. in_group) then
               j = i + 1
               do while (j <= n)
                  if (.not. is_name_char(lower(text(j:j)))) exit
                  j = j + 1
               end do
               group = lower(text(i + 1:j - 1))
               if (group == 'end' .or. group == '') then
                  i = j
                  cycle
               end if
               if (.not. any(known_groups == group)) then
                  call fatal_error(error, path//':'//itoa(line_of(i))//': unknown namelist group &' &
                     & //group//' (known: '//join(known_groups, ' ', '&')//')', error_input)
                  return
               end if
               if (any(seen == group)) then
                  call fatal_error(error, path//':'//itoa(line_of(i))//': group &'//group &
                     & //' appears twice in the file; only one is read, so merge them', error_input)
                  return
               end if
               seen = [character(len=32) :: seen, group]
               seen_lines = [seen_lines, line_of(i)]
               in_group = .true.
               i = j
               cycle
            else if (c == '/' .and. in_group) then
               call close_value(i - 1)
               in_group = .false.
            else if (c == '=' .and. in_group) then
               ! The name before '=': skip blanks (tabs too) and an index like (3) or (1:2).
               k = i - 1
               do while (k >= 1)
                  if (text(k:k) /= ' ' .and. text(k:k) /= achar(9) .and. text(k:k) /= new_line('a')) exit
                  k = k - 1
               end do
               first = 0
               if (k >= 1) then
                  if (text(k:k) == ')') then
                     ! An index is short: look no further back than 64 characters (a
                     ! long text of ')' would make every '=' rescan it).
                     j = index(text(max(1, k - 64):k), '(', back=.true.)
                     if (j > 0) j = j + max(1, k - 64) - 1
                     if (j > 0) then
                        call read_index(text(j + 1:k - 1), first)
                        if (first < 1) then
                           call index_error(j, k)
                           return
                        end if
                        k = j - 1
                     end if
                  end if
               end if
               j = k
               do while (j >= 1)
                  if (.not. is_name_char(lower(text(j:j)))) exit
                  j = j - 1
               end do
               if (k > j) then
                  call close_value(j)
                  if (count == size(mentions)) call resize(mentions, 2 * count)
                  count = count + 1
                  mentions(count)%group = group
                  mentions(count)%name = lower(text(j + 1:k))
                  mentions(count)%first = first
                  mentions(count)%line = line_of(j + 1)
                  mentions(count)%value = ''
                  open_mention = .true.
                  value_from = i + 1
               end if
            end if
         end associate
         i = i + 1
      end do
      if (in_group) then
         call fatal_error(error, path//': group &'//group//" is not closed with '/'", error_input)
         return
      end if
      call resize(mentions, count)
      if (present(groups)) groups = seen
      if (present(group_lines)) group_lines = seen_lines

   contains

      !> Text outside a group at text(at:): an error naming its line (the
      !> `$group ... $end` form of old compilers too, which Fortran does not read).
      subroutine outside_group_error(at)
         integer, intent(in) :: at
         integer :: stop_at
         character(len=:), allocatable :: shown

         stop_at = index(text(at:), new_line('a'))
         if (stop_at == 0) then
            stop_at = n
         else
            stop_at = at + stop_at - 2
         end if
         shown = trim(text(at:min(stop_at, at + 59)))
         if (text(at:at) == '$') then
            call fatal_error(error, path//':'//itoa(line_of(at))//": '"//shown//"': the $group ... $end form " &
               & //"is not read; write &group ... /", error_input)
         else if (len(group) > 0) then
            call fatal_error(error, path//':'//itoa(line_of(at))//": '"//shown//"' is outside a group (after " &
               & //"&"//group//" closed with '/'); it would be ignored: move it into the group or remove it", &
               & error_input)
         else
            call fatal_error(error, path//':'//itoa(line_of(at))//": '"//shown//"' is outside a group; a " &
               & //"group starts with &name and ends with '/'", error_input)
         end if
      end subroutine outside_group_error

      !> An element index that is not a whole number from 1 on, between
      !> text(open_at) '(' and text(close_at) ')': an error naming the line,
      !> group and variable (Fortran's own reading would set another element).
      subroutine index_error(open_at, close_at)
         integer, intent(in) :: open_at, close_at
         integer :: b

         b = open_at - 1
         do while (b >= 1)
            if (.not. is_name_char(lower(text(b:b)))) exit
            b = b - 1
         end do
         call fatal_error(error, path//':'//itoa(line_of(open_at))//': &'//group//': ' &
            & //lower(text(b + 1:open_at - 1))//text(open_at:close_at)//': the element is a whole number from 1 ' &
            & //'to '//itoa(huge(1))//' in parentheses, e.g. sigma(2) (a section such as (1:2) is not read)', &
            & error_input)
      end subroutine index_error

      !> The open assignment's value ends at `last`.
      subroutine close_value(last)
         integer, intent(in) :: last

         if (.not. open_mention) return
         mentions(count)%value = trim(adjustl(text(value_from:last)))
         open_mention = .false.
      end subroutine close_value

   end subroutine scan_namelist_file

   !> The element index in `digits` (blanks around it allowed): a whole
   !> number from 1 to huge(1), else 0.
   subroutine read_index(digits, first)
      character(len=*), intent(in) :: digits
      integer, intent(out) :: first
      character(len=:), allocatable :: t
      integer(i8) :: wide
      integer :: stat

      first = 0
      t = trim(adjustl(digits))
      if (len(t) == 0 .or. len(t) > 12 .or. verify(t, '0123456789') /= 0) return
      read (t, *, iostat=stat) wide
      if (stat /= 0 .or. wide < 1 .or. wide > huge(1)) return
      first = int(wide)
   end subroutine read_index

   !> The first `n` mentions (those beyond the old size empty), moved to an
   !> array of that size: the scan doubles its room, so that a file of many
   !> assignments takes time in proportion to them.  (Element by element:
   !> gfortran's array constructors mishandle deferred-length character
   !> components.)
   subroutine resize(mentions, n)
      type(mention), allocatable, intent(inout) :: mentions(:)
      integer, intent(in) :: n
      type(mention), allocatable :: moved(:)
      integer :: k

      allocate (moved(n))
      do k = 1, min(n, size(mentions))
         moved(k)%group = mentions(k)%group
         moved(k)%name = mentions(k)%name
         moved(k)%first = mentions(k)%first
         moved(k)%line = mentions(k)%line
         if (allocated(mentions(k)%value)) call move_alloc(mentions(k)%value, moved(k)%value)
      end do
      call move_alloc(moved, mentions)
   end subroutine resize

   !> The file as one text with newlines, comments blanked, and the line of
   !> every character.  Lines of any length up to max_line_length; a file
   !> that is not a regular one (a pipe) is read once, as it comes.  A
   !> control character or an overlong line (a binary file, a device) is an
   !> error naming the line, and so is a text beyond max_text_length (a
   !> pipe that never ends).
   subroutine read_text(path, text, line_of, error)
      character(len=*), intent(in) :: path
      character(len=:), allocatable, intent(out) :: text
      integer, allocatable, intent(out) :: line_of(:)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: max_text_length = 64 * 1048576
      character(len=:), allocatable :: buffer, problem
      character(len=:), allocatable :: whole
      character(len=256) :: message
      character :: quote
      integer :: unit, stat, line, i, n, used, filled

      call open_for_reading(path, unit, error, pipe=.true.)
      if (allocated(error)) return
      allocate (character(len=4096) :: whole)
      allocate (line_of(4096))
      used = 0
      line = 0
      message = ''
      do
         call read_text_line(unit, buffer, stat, message, problem)
         if (stat /= 0) exit
         line = line + 1
         ! A namelist file is text: a control character (a NUL, the bytes of a
         ! binary file given by mistake) is an error, not something to skip.
         if (len(problem) > 0) then
            close (unit)
            call fatal_error(error, path//':'//itoa(line)//': '//problem, error_input)
            return
         end if
         if (used + len(buffer) >= max_text_length) then
            close (unit)
            call fatal_error(error, path//':'//itoa(line)//': the file is longer than ' &
               & //itoa(max_text_length / 1048576)//' MiB: not a namelist file', error_input)
            return
         end if
         n = len_trim(buffer)
         quote = ' '
         do i = 1, n
            if (quote /= ' ') then
               if (buffer(i:i) == quote) quote = ' '
            else if (buffer(i:i) == '"' .or. buffer(i:i) == "'") then
               quote = buffer(i:i)
            else if (buffer(i:i) == '!') then
               n = i - 1
               exit
            end if
         end do
         call append(buffer(1:n)//new_line('a'), line)
      end do
      close (unit)
      if (stat > 0) then
         call fatal_error(error, path//':'//itoa(line + 1)//': cannot read the file ('//trim(message)//')', &
            & error_input)
         return
      end if
      text = whole(1:used)
      line_of = line_of(1:used)

   contains

      !> Add characters of one line to the text.
      subroutine append(more, line)
         character(len=*), intent(in) :: more
         integer, intent(in) :: line
         character(len=:), allocatable :: grown
         integer, allocatable :: lines(:)

         filled = used + len(more)
         if (filled > len(whole)) then
            allocate (character(len=max(2 * len(whole), filled)) :: grown)
            grown(1:used) = whole(1:used)
            call move_alloc(grown, whole)
            allocate (lines(len(whole)))
            lines(1:used) = line_of(1:used)
            call move_alloc(lines, line_of)
         end if
         whole(used + 1:filled) = more
         line_of(used + 1:filled) = line
         used = filled
      end subroutine append

   end subroutine read_text

end module friction_input_scan
