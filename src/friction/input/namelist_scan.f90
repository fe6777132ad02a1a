!> A light reading of namelist files that Fortran's own namelist input does
!> not offer: which groups a file has and which variables each one sets,
!> with line numbers.  It lets the input reader reject unknown groups and
!> variables with a precise message, and name the file a value came from.
module friction_input_scan
   use, intrinsic :: iso_fortran_env, only: int64
   use friction_kinds, only: wp
   use friction_strings, only: join, lower
   use friction_error, only: error_type, fatal_error, error_input
   implicit none
   private

   public :: mention, scan_namelist_file, namelist_names, assigned_names, value_has_kind, &
      & kind_text

   !> One assignment `name = value` inside group `&group` of a file; value
   !> is the text after '=' on the same line, up to the next assignment.
   type :: mention
      character(len=32) :: group = ''
      character(len=32) :: name = ''
      integer :: line = 0
      character(len=256) :: value = ''
   end type mention

contains

   pure logical function is_name_char(c)
      character, intent(in) :: c

      is_name_char = (c >= 'a' .and. c <= 'z') .or. (c >= '0' .and. c <= '9') .or. c == '_'
   end function is_name_char

   !> The variable names of a group as written by `write(unit, nml=...)`,
   !> given that text (one `NAME=value` per line, as gfortran writes it),
   !> and the kind of each value: 'c' text, 'l' logical, 'r' real, 'i' integer.
   subroutine namelist_names(text, names, kinds)
      character(len=*), intent(in) :: text
      character(len=32), allocatable, intent(out) :: names(:)
      character, allocatable, intent(out) :: kinds(:)
      integer :: start, eol, eq
      character(len=:), allocatable :: line, value
      character :: kind

      allocate (names(0), kinds(0))
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
            if (verify(lower(trim(line(1:eq - 1))), 'abcdefghijklmnopqrstuvwxyz0123456789_') == 0) then
               value = trim(adjustl(line(eq + 1:)))
               if (value(1:1) == '"' .or. value(1:1) == "'") then
                  kind = 'c'
               else if (value == 'T,' .or. value == 'F,') then
                  kind = 'l'
               else if (scan(value, '.Ee') > 0) then
                  kind = 'r'
               else
                  kind = 'i'
               end if
               names = [character(len=32) :: names, lower(trim(line(1:eq - 1)))]
               kinds = [kinds, kind]
            end if
         end if
         start = eol + 1
      end do
   end subroutine namelist_names

   !> What a kind code means, for messages.
   pure function kind_text(kind) result(text)
      character, intent(in) :: kind
      character(len=:), allocatable :: text

      select case (kind)
      case ('c'); text = "quoted text, like 'rkf45'"
      case ('l'); text = '.true. or .false.'
      case ('r'); text = 'a number'
      case default; text = 'an integer'
      end select
   end function kind_text

   !> Whether every item of a value (separated by commas or blanks outside
   !> quotes) reads as the kind; an empty value is left to the runtime.
   logical function value_has_kind(value, kind) result(ok)
      character(len=*), intent(in) :: value
      character, intent(in) :: kind
      character(len=len(value)) :: item
      integer :: i, n, stat, star
      real(wp) :: x
      integer(int64) :: m
      character :: quote

      ok = .true.
      n = 0
      item = ''
      quote = ' '
      do i = 1, len_trim(value) + 1
         if (i <= len_trim(value)) then
            if (quote /= ' ') then
               if (value(i:i) == quote) quote = ' '
               n = n + 1
               item(n:n) = value(i:i)
               cycle
            end if
            if (value(i:i) == '"' .or. value(i:i) == "'") quote = value(i:i)
            if (value(i:i) /= ',' .and. value(i:i) /= ' ') then
               n = n + 1
               item(n:n) = value(i:i)
               cycle
            end if
         end if
         if (n == 0) cycle
         ! A repeat count r*value checks the value.
         star = index(item(1:n), '*')
         if (star > 1) then
            if (verify(item(1:star - 1), '0123456789') == 0) then
               item = item(star + 1:n)
               n = n - star
               if (n == 0) cycle
            end if
         end if
         select case (kind)
         case ('c')
            ok = (item(1:1) == '"' .or. item(1:1) == "'") .and. item(n:n) == item(1:1) .and. n >= 2
         case ('l')
            select case (lower(item(1:n)))
            case ('t', 'f', '.t.', '.f.', '.true.', '.false.', 'true', 'false')
            case default
               ok = .false.
            end select
         case ('r')
            read (item(1:n), *, iostat=stat) x
            ok = stat == 0 .and. verify(lower(item(1:n)), '0123456789+-.ed') == 0
         case default
            read (item(1:n), *, iostat=stat) m
            ok = stat == 0 .and. verify(item(1:n), '0123456789+-') == 0
         end select
         if (.not. ok) return
         n = 0
         item = ''
      end do
   end function value_has_kind

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
      integer :: unit, stat, line, i, j, k, nseen, n, value_from
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
                        & //trim(group)//' (known: '//join(known_groups, ' ', '&')//')', error_input)
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
                  if (k > j) then
                     ! The previous assignment's value ends where this name starts.
                     if (size(mentions) > 0) then
                        if (mentions(size(mentions))%line == line) &
                           & mentions(size(mentions))%value = value_text(buffer(value_from:j))
                     end if
                     mentions = [mentions, mention(group, lower(buffer(j + 1:k)), line, &
                        & value_text(buffer(i + 1:)))]
                     value_from = i + 1
                  end if
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

   !> A value's text: up to a closing '/' or a comment outside quotes.
   pure function value_text(text) result(value)
      character(len=*), intent(in) :: text
      character(len=256) :: value
      character :: quote
      integer :: i

      quote = ' '
      do i = 1, len(text)
         if (quote /= ' ') then
            if (text(i:i) == quote) quote = ' '
         else if (text(i:i) == '"' .or. text(i:i) == "'") then
            quote = text(i:i)
         else if (text(i:i) == '/' .or. text(i:i) == '!') then
            value = adjustl(text(1:i - 1))
            return
         end if
      end do
      value = adjustl(text)
   end function value_text

   !> The variable names assigned on one line (`name = value`, outside quotes).
   pure function assigned_names(line) result(text)
      character(len=*), intent(in) :: line
      character(len=:), allocatable :: text
      character :: quote
      integer :: i, j, k

      text = ''
      quote = ' '
      do i = 1, len_trim(line)
         if (quote /= ' ') then
            if (line(i:i) == quote) quote = ' '
         else if (line(i:i) == '"' .or. line(i:i) == "'") then
            quote = line(i:i)
         else if (line(i:i) == '!') then
            exit
         else if (line(i:i) == '=') then
            k = len_trim(line(1:i - 1))
            j = k
            do while (j >= 1)
               if (.not. is_name_char(lower(line(j:j)))) exit
               j = j - 1
            end do
            if (k > j) then
               if (len(text) > 0) text = text//', '
               text = text//lower(line(j + 1:k))
            end if
         end if
      end do
   end function assigned_names

end module friction_input_scan
