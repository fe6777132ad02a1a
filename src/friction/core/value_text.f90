!> Namelist value text: reading a value's items (quotes, repeat counts,
!> nulls, lists), the shortest text of a real that reads back to the same
!> double, and the checks of a value's kind, range and encoding.  The
!> parameter visitor (parameters.f90) sets and writes variables through it.
module friction_value_text
   use, intrinsic :: iso_c_binding, only: c_double, c_char, c_int
   use friction_kinds, only: wp, i8
   use friction_strings, only: lower, itoa
   implicit none
   private

   public :: split_name, real_words, shortest, run_lengths, quote, is_quoted, unquote, value_items, &
      & range_problem, is_utf8, kind_text, value_has_kind, max_list_values

   !> The most values a list of any length (real_list: a sweep's values)
   !> takes, repeat counts included: a bound on the memory a value text can
   !> ask for.
   integer, parameter :: max_list_values = 10000000

   interface
      !> x's shortest text into text (no NUL), its length into n.
      pure subroutine c_shortest(x, text, n) bind(c, name='friction_shortest')
         import :: c_double, c_char, c_int
         real(c_double), value :: x
         character(kind=c_char), intent(out) :: text(32)
         integer(c_int), intent(out) :: n
      end subroutine c_shortest
   end interface

contains


   !> 'group.name' into its parts ('' group when there is no dot).
   subroutine split_name(full, group, name)
      character(len=*), intent(in) :: full
      character(len=:), allocatable, intent(out) :: group, name
      integer :: dot

      dot = index(full, '.')
      group = lower(trim(adjustl(full(1:max(0, dot - 1)))))
      name = lower(trim(adjustl(full(dot + 1:))))
   end subroutine split_name

   !> Reals as text that reads back to the same doubles: the fewest
   !> significant digits that do.
   pure function real_words(values) result(words)
      real(wp), intent(in) :: values(:)
      character(len=26) :: words(size(values))
      integer :: k

      do k = 1, size(values)
         words(k) = shortest(values(k))
      end do
   end function real_words

   !> The fewest significant digits that read back, from the C library's
   !> correctly rounded printf and strtod (core/shortest.c): the text that
   !> Fortran's es and f0.d edit descriptors gave, which cost most of a
   !> short run's echo of its input.  1.5e-3 is written 0.0015; plain
   !> decimals for decimal exponents -3 to 14, else 1.5e-20.
   pure function shortest(x) result(word)
      real(wp), intent(in) :: x
      character(len=26) :: word
      character(kind=c_char) :: buffer(32)
      integer(c_int) :: n
      integer :: k

      call c_shortest(real(x, c_double), buffer, n)
      word = ''
      do k = 1, min(n, len(word))
         word(k:k) = buffer(k)
      end do
   end function shortest

   !> Values joined by ', ', repeats as n*value (in two passes, the length
   !> and then the text: time in proportion to the values).
   pure function run_lengths(words) result(text)
      character(len=*), intent(in) :: words(:)
      character(len=:), allocatable :: text
      character(len=:), allocatable :: piece
      integer :: k, n, pass, used

      allocate (character(len=0) :: text)
      do pass = 1, 2
         used = 0
         k = 1
         do while (k <= size(words))
            n = 1
            do while (k + n <= size(words))
               if (words(k + n) /= words(k)) exit
               n = n + 1
            end do
            piece = trim(words(k))
            if (n > 1) piece = itoa(n)//'*'//piece
            if (used > 0) piece = ', '//piece
            if (pass == 2) text(used + 1:used + len(piece)) = piece
            used = used + len(piece)
            k = k + n
         end do
         if (pass == 1) then
            deallocate (text)
            allocate (character(len=used) :: text)
         end if
      end do
   end function run_lengths

   pure function quote(text) result(out)
      character(len=*), intent(in) :: text
      character(len=:), allocatable :: out
      character(len=2 * len(text) + 2) :: buffer
      integer :: i, n

      buffer(1:1) = "'"
      n = 1
      do i = 1, len(text)
         n = n + 1
         buffer(n:n) = text(i:i)
         if (text(i:i) == "'") then
            n = n + 1
            buffer(n:n) = "'"
         end if
      end do
      out = buffer(1:n)//"'"
   end function quote

   pure logical function is_quoted(item)
      character(len=*), intent(in) :: item

      is_quoted = .false.
      if (len(item) < 2) return
      is_quoted = (item(1:1) == '"' .or. item(1:1) == "'") .and. item(len(item):len(item)) == item(1:1)
   end function is_quoted

   !> A quoted item's text, with doubled quotes undone.
   pure function unquote(item) result(text)
      character(len=*), intent(in) :: item
      character(len=:), allocatable :: text
      character(len=max(len(item) - 2, 0)) :: buffer
      integer :: i, n
      character :: q

      q = item(1:1)
      n = 0
      i = 2
      do while (i < len(item))
         n = n + 1
         buffer(n:n) = item(i:i)
         if (item(i:i) == q .and. i + 1 < len(item)) then
            if (item(i + 1:i + 1) == q) i = i + 1
         end if
         i = i + 1
      end do
      text = buffer(1:n)
   end function unquote

   !> The items of a value (separated by commas or blanks outside quotes;
   !> r*value repeats; an empty item between commas is a null value, which
   !> leaves its element alone), at most `room` of them from element
   !> `first` (0: the whole variable from its first element), as the bounds
   !> of each item in the text (an empty item has to < from).  (Bounds, not
   !> an array of strings: gfortran mishandles deferred-length arrays.)
   subroutine value_items(text, room, first, from, to, problem)
      character(len=*), intent(in) :: text
      integer, intent(in) :: room, first
      integer, allocatable, intent(out) :: from(:), to(:)
      character(len=:), allocatable, intent(out) :: problem
      integer, allocatable :: word_from(:), word_to(:)
      integer :: i, n, star, repeat, stat, k, start, words
      character :: q, c
      logical :: comma_last, in_word

      problem = ''
      allocate (word_from(16), word_to(16), from(16), to(16))
      words = 0
      n = 0
      q = ' '
      comma_last = .true.
      in_word = .false.
      start = 1
      do i = 1, len(text) + 1
         c = ','
         if (i <= len(text)) c = text(i:i)
         if (q /= ' ') then
            if (c == q) q = ' '
            if (i <= len(text)) cycle
         end if
         if (i <= len(text) .and. (c == '"' .or. c == "'")) then
            q = c
            if (.not. in_word) start = i
            in_word = .true.
            cycle
         end if
         if (c /= ',' .and. c /= ' ' .and. c /= achar(9) .and. c /= new_line('a')) then
            if (.not. in_word) start = i
            in_word = .true.
            cycle
         end if
         if (in_word) then
            call push(word_from, word_to, words, start, i - 1)
            in_word = .false.
            comma_last = .false.
         else if (i <= len(text) .and. c == ',') then
            if (comma_last) call push(word_from, word_to, words, i, i - 1)   ! a null value
         end if
         if (i <= len(text) .and. c == ',') comma_last = .true.
      end do
      if (q /= ' ') then
         problem = 'the quoted text is not closed'
         return
      end if
      do k = 1, words
         repeat = 1
         if (word_to(k) >= word_from(k)) then
            star = index(text(word_from(k):word_to(k)), '*')
            if (star > 1 .and. .not. is_quoted(text(word_from(k):word_to(k)))) then
               if (verify(text(word_from(k):word_from(k) + star - 2), '0123456789') == 0) then
                  read (text(word_from(k):word_from(k) + star - 2), *, iostat=stat) repeat
                  if (stat /= 0 .or. repeat < 1) then
                     problem = 'bad repeat count in '//text(word_from(k):word_to(k))
                     return
                  end if
                  word_from(k) = word_from(k) + star
               end if
            end if
         end if
         if (repeat > room - n) then
            problem = 'more values than the '//itoa(room)//' elements'
            if (room == max_list_values) problem = 'more than '//itoa(room)//' values, the most a list holds'
            return
         end if
         do i = 1, repeat
            call push(from, to, n, word_from(k), word_to(k))
         end do
      end do
      from = from(1:n)
      to = to(1:n)
      if (n == 0) then
         problem = 'no value'
         return
      end if
      if (max(1, first) + n - 1 > room) problem = 'more values than the '//itoa(room)//' elements'

   contains

      !> Bounds (a, b) after the first `count` pairs, the room doubled when
      !> full: time in proportion to the items, however many.
      pure subroutine push(lower_bounds, upper_bounds, count, a, b)
         integer, allocatable, intent(inout) :: lower_bounds(:), upper_bounds(:)
         integer, intent(inout) :: count
         integer, intent(in) :: a, b
         integer, allocatable :: grown(:)

         if (count == size(lower_bounds)) then
            allocate (grown(2 * count))
            grown(1:count) = lower_bounds(1:count)
            call move_alloc(grown, lower_bounds)
            allocate (grown(2 * count))
            grown(1:count) = upper_bounds(1:count)
            call move_alloc(grown, upper_bounds)
         end if
         count = count + 1
         lower_bounds(count) = a
         upper_bounds(count) = b
      end subroutine push

   end subroutine value_items

   !> Why a number read from `text` is not the number the text says ('' when
   !> it is): a literal beyond the largest double (1e400 reads as Infinity)
   !> or a non-zero one below the smallest (1e-400 reads as 0).  The value
   !> text of a real never spells Inf or NaN (value_has_kind allows digits,
   !> signs, '.', 'e' and 'd' only), so any non-finite value overflowed.
   function range_problem(text, x) result(problem)
      character(len=*), intent(in) :: text
      real(wp), intent(in) :: x
      character(len=:), allocatable :: problem
      integer :: e

      problem = ''
      if (.not. (abs(x) <= huge(x))) then
         problem = 'out of range: larger than the largest number, '//trim(shortest(huge(x)))
         return
      end if
      if (x /= 0.0_wp) return
      e = scan(lower(text), 'ed')
      if (e == 0) e = len(text) + 1
      if (verify(text(1:e - 1), '+-.0') /= 0) problem = 'out of range: a non-zero number below the smallest, ' &
         & //trim(shortest(tiny(x)))
   end function range_problem

   !> Whether text is well-formed UTF-8 (ASCII included) without control
   !> characters other than tab.
   pure logical function is_utf8(text) result(ok)
      character(len=*), intent(in) :: text
      integer :: i, c, follow, k, low, high

      ok = .false.
      i = 1
      do while (i <= len(text))
         c = iachar(text(i:i))
         if (c < 0) c = c + 256
         ! The second byte's range: narrower after E0, ED, F0 and F4, which
         ! would else start an overlong form, a surrogate or a code point
         ! beyond U+10FFFF (not UTF-8; a reader's decoding of the output fails).
         low = 128
         high = 191
         select case (c)
         case (224); low = 160
         case (237); high = 159
         case (240); low = 144
         case (244); high = 143
         end select
         if (c < 128) then
            if (c < 32 .and. c /= 9) return
            if (c == 127) return
            follow = 0
         else if (c >= 194 .and. c <= 223) then
            follow = 1
         else if (c >= 224 .and. c <= 239) then
            follow = 2
         else if (c >= 240 .and. c <= 244) then
            follow = 3
         else
            return
         end if
         if (i + follow > len(text)) return
         do k = 1, follow
            c = iachar(text(i + k:i + k))
            if (c < 0) c = c + 256
            if (c < 128 .or. c > 191) return
            if (k == 1 .and. (c < low .or. c > high)) return
         end do
         i = i + follow + 1
      end do
      ok = .true.
   end function is_utf8

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

   !> Whether every item of a value reads as the kind.
   logical function value_has_kind(text, kind) result(ok)
      character(len=*), intent(in) :: text
      character, intent(in) :: kind
      character(len=:), allocatable :: problem
      integer, allocatable :: from(:), to(:)
      integer :: k, stat
      real(wp) :: x
      integer(i8) :: m

      call value_items(text, max_list_values, 0, from, to, problem)
      ok = .true.
      if (len(problem) > 0) then
         ok = problem == 'no value' .or. index(problem, 'more ') == 1   ! left to the setter
         return
      end if
      do k = 1, size(from)
         if (to(k) < from(k)) cycle
         if (k > 1) then
            if (from(k) == from(k - 1) .and. to(k) == to(k - 1)) cycle   ! a repeat, checked already
         end if
         select case (kind)
         case ('c')
            ok = is_quoted(text(from(k):to(k)))
         case ('l')
            select case (lower(text(from(k):to(k))))
            case ('t', 'f', '.t.', '.f.', '.true.', '.false.', 'true', 'false')
            case default
               ok = .false.
            end select
         case ('r')
            read (text(from(k):to(k)), *, iostat=stat) x
            ok = stat == 0 .and. verify(lower(text(from(k):to(k))), '0123456789+-.ed') == 0
         case default
            read (text(from(k):to(k)), *, iostat=stat) m
            ok = stat == 0 .and. verify(text(from(k):to(k)), '0123456789+-') == 0
         end select
         if (.not. ok) return
      end do
   end function value_has_kind

end module friction_value_text
