!> A light reading of namelist files that Fortran's own namelist input does
!> not offer: which groups a file has and which variables each one sets,
!> with line numbers.  It lets the input reader reject unknown groups and
!> variables with a precise message, and name the file a value came from.
module friction_io_namelist_scan
   use friction_error, only: error_type, fatal_error, error_input
   implicit none
   private

   public :: mention, scan_namelist_file, lower, namelist_names

   !> One assignment `name = ...` inside group `&group` of a file.
   type :: mention
      character(len=32) :: group = ''
      character(len=32) :: name = ''
      integer :: line = 0
   end type mention

contains

   pure function lower(text) result(out)
      character(len=*), intent(in) :: text
      character(len=len(text)) :: out
      integer :: i

      out = text
      do i = 1, len(text)
         if (text(i:i) >= 'A' .and. text(i:i) <= 'Z') out(i:i) = achar(iachar(text(i:i)) + 32)
      end do
   end function lower

   pure logical function is_name_char(c)
      character, intent(in) :: c

      is_name_char = (c >= 'a' .and. c <= 'z') .or. (c >= '0' .and. c <= '9') .or. c == '_'
   end function is_name_char

   !> The variable names of a group as written by `write(unit, nml=...)`,
   !> given that text (one `NAME=value` per line, as gfortran writes it).
   subroutine namelist_names(text, names)
      character(len=*), intent(in) :: text
      character(len=32), allocatable, intent(out) :: names(:)
      integer :: start, eol, eq
      character(len=:), allocatable :: line

      allocate (names(0))
      start = 1
      do while (start <= len(text))
         eol = index(text(start:), new_line('a'))
         if (eol == 0) then
            eol = len(text) + 1
         else
            eol = start + eol - 1
         end if
         line = adjustl(text(start:eol - 1))
         eq = index(line, '=')
         if (eq > 1 .and. line(1:1) /= '&') then
            if (verify(lower(trim(line(1:eq - 1))), 'abcdefghijklmnopqrstuvwxyz0123456789_') == 0) &
               & names = [character(len=32) :: names, lower(trim(line(1:eq - 1)))]
         end if
         start = eol + 1
      end do
   end subroutine namelist_names

   !> The groups and assignments of a namelist file.  Groups outside
   !> `known_groups`, and a group given twice, are errors naming the line.
   subroutine scan_namelist_file(path, known_groups, mentions, error)
      character(len=*), intent(in) :: path
      character(len=*), intent(in) :: known_groups(:)
      type(mention), allocatable, intent(out) :: mentions(:)
      type(error_type), allocatable, intent(out) :: error
      character(len=1024) :: buffer
      character(len=32) :: group, seen(64)
      character(len=8) :: lineno
      character :: quote
      integer :: unit, stat, line, i, j, k, nseen, n
      logical :: in_group

      logical :: exists

      allocate (mentions(0))
      inquire (file=path, exist=exists)
      if (.not. exists) then
         call fatal_error(error, path//': no such file', error_input)
         return
      end if
      open (newunit=unit, file=path, status='old', action='read', iostat=stat)
      if (stat /= 0) then
         call fatal_error(error, path//': cannot open the file', error_input)
         return
      end if
      in_group = .false.
      group = ''
      quote = ' '
      nseen = 0
      line = 0
      do
         read (unit, '(a)', iostat=stat) buffer
         if (stat /= 0) exit
         line = line + 1
         write (lineno, '(i0)') line
         n = len_trim(buffer)
         i = 1
         do while (i <= n)
            associate (c => buffer(i:i))
               if (quote /= ' ') then
                  if (c == quote) quote = ' '
                  i = i + 1
                  cycle
               end if
               if (c == '"' .or. c == "'") then
                  quote = c
               else if (c == '!') then
                  exit
               else if (c == '&' .and. .not. in_group) then
                  j = i + 1
                  do while (j <= n)
                     if (.not. is_name_char(lower(buffer(j:j)))) exit
                     j = j + 1
                  end do
                  group = lower(buffer(i + 1:j - 1))
                  if (group == 'end' .or. group == '') then
                     i = j
                     cycle
                  end if
                  if (.not. any(known_groups == group)) then
                     call fatal_error(error, path//':'//trim(lineno)//': unknown namelist group &' &
                        & //trim(group)//' (known: '//join(known_groups)//')', error_input)
                     close (unit)
                     return
                  end if
                  if (any(seen(1:nseen) == group)) then
                     call fatal_error(error, path//':'//trim(lineno)//': group &'//trim(group) &
                        & //' appears twice in the file; only one is read, so merge them', error_input)
                     close (unit)
                     return
                  end if
                  nseen = nseen + 1
                  seen(nseen) = group
                  in_group = .true.
                  i = j
                  cycle
               else if (c == '/' .and. in_group) then
                  in_group = .false.
               else if (c == '=' .and. in_group) then
                  ! The name before '=': skip blanks and an index like (1) or (1:2).
                  k = i - 1
                  do while (k >= 1)
                     if (buffer(k:k) /= ' ') exit
                     k = k - 1
                  end do
                  if (k >= 1) then
                     if (buffer(k:k) == ')') then
                        k = index(buffer(1:k), '(', back=.true.) - 1
                     end if
                  end if
                  j = k
                  do while (j >= 1)
                     if (.not. is_name_char(lower(buffer(j:j)))) exit
                     j = j - 1
                  end do
                  if (k > j) mentions = [mentions, mention(group, lower(buffer(j + 1:k)), line)]
               end if
            end associate
            i = i + 1
         end do
      end do
      close (unit)
      if (in_group) then
         call fatal_error(error, path//': group &'//trim(group)//" is not closed with '/'", error_input)
      end if
   end subroutine scan_namelist_file

   pure function join(words) result(text)
      character(len=*), intent(in) :: words(:)
      character(len=:), allocatable :: text
      integer :: i

      text = ''
      do i = 1, size(words)
         text = text//'&'//trim(words(i))
         if (i < size(words)) text = text//' '
      end do
   end function join

end module friction_io_namelist_scan
