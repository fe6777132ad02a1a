!> Text helpers: numbers and lists as text for messages, case folding.
module friction_strings
   use friction_kinds, only: wp, i8
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   implicit none
   private

   public :: itoa, rtoa, etoa, join, quoted, lower, text_hash, text_hash_bits, bytes_text, fixed_text, one_line

   !> An integer as text, without blanks.
   interface itoa
      module procedure itoa4, itoa8
   end interface itoa

contains

   !> ASCII letters in lower case.
   pure function lower(text) result(out)
      character(len=*), intent(in) :: text
      character(len=len(text)) :: out
      integer :: i

      out = text
      do i = 1, len(text)
         if (text(i:i) >= 'A' .and. text(i:i) <= 'Z') out(i:i) = achar(iachar(text(i:i)) + 32)
      end do
   end function lower

   pure function itoa4(i) result(text)
      integer, intent(in) :: i
      character(len=:), allocatable :: text

      text = itoa8(int(i, i8))
   end function itoa4

   !> (Digit by digit: an internal write costs about a microsecond, and a
   !> run's input places, names and messages take hundreds of these.)
   pure function itoa8(i) result(text)
      integer(i8), intent(in) :: i
      character(len=:), allocatable :: text
      character(len=20) :: buffer   ! 19 digits and a sign
      integer(i8) :: rest
      integer :: k

      k = len(buffer) + 1
      rest = i
      do
         k = k - 1
         ! (mod and / truncate toward zero: a negative rest gives digits
         ! of the same magnitude, so -2**63 needs no special case.)
         buffer(k:k) = achar(iachar('0') + int(abs(mod(rest, 10_i8))))
         rest = rest / 10_i8
         if (rest == 0) exit
      end do
      if (i < 0) then
         k = k - 1
         buffer(k:k) = '-'
      end if
      text = buffer(k:)
   end function itoa8

   !> A text on one line, for messages: newlines and carriage returns as
   !> blanks; with `longest`, a text longer than that is cut to its first
   !> longest - 20 characters and a count of the rest.
   pure function one_line(text, longest) result(out)
      character(len=*), intent(in) :: text
      integer, intent(in), optional :: longest
      character(len=:), allocatable :: out
      integer :: i

      out = text
      if (present(longest)) then
         if (len(text) > longest) out = text(1:longest - 20)//' ... ('//itoa(len(text) - longest + 20) &
            & //' more characters)'
      end if
      do i = 1, len(out)
         if (out(i:i) == new_line('a') .or. out(i:i) == achar(13)) out(i:i) = ' '
      end do
   end function one_line

   !> A real in scientific notation with `digits` decimals, as the es edit
   !> descriptor writes it ('1.30E-05'), and with three exponent digits where
   !> it needs them ('1.30E-152': es alone drops the E there, '1.30-152').
   pure function etoa(x, digits) result(text)
      real(wp), intent(in) :: x
      integer, intent(in) :: digits
      character(len=:), allocatable :: text
      character(len=40) :: buffer, edit

      write (edit, '(a, i0, a, i0, a)') '(es', digits + 8, '.', digits, ')'
      write (buffer, edit) x
      if (abs(x) <= huge(x) .and. scan(buffer, 'E') == 0) then
         write (edit, '(a, i0, a, i0, a)') '(es', digits + 9, '.', digits, 'e3)'
         write (buffer, edit) x
      end if
      text = trim(adjustl(buffer))
   end function etoa

   !> A real as text with 7 significant digits.
   pure function rtoa(x) result(text)
      real(wp), intent(in) :: x
      character(len=:), allocatable :: text
      character(len=32) :: buffer

      write (buffer, '(1pg0.6)') x
      text = trim(adjustl(buffer))
   end function rtoa

   !> A real with `digits` decimals and no padding ('0.25', '-3.1'); beyond
   !> 1e15 in magnitude, or not finite, in scientific notation, so that any
   !> value fits (an internal write that overflows its buffer aborts).
   pure function fixed_text(x, digits) result(text)
      real(wp), intent(in) :: x
      integer, intent(in) :: digits
      character(len=:), allocatable :: text
      character(len=64) :: buffer, form

      if (.not. (abs(x) < 1.0e15_wp)) then
         write (buffer, '(es14.4e3)') x
      else
         write (form, '(a, i0, a)') '(f0.', max(0, min(digits, 30)), ')'
         write (buffer, form) x
      end if
      text = trim(adjustl(buffer))
      if (text(1:1) == '.') text = '0'//text
      if (len(text) > 1) then
         if (text(1:2) == '-.') text = '-0'//text(2:)
      end if
   end function fixed_text

   !> Words separated by a separator (', ' when absent), each with a prefix.
   pure function join(words, separator, prefix) result(text)
      character(len=*), intent(in) :: words(:)
      character(len=*), intent(in), optional :: separator, prefix
      character(len=:), allocatable :: text, sep, pre
      integer :: i

      sep = ', '
      if (present(separator)) sep = separator
      pre = ''
      if (present(prefix)) pre = prefix
      text = ''
      do i = 1, size(words)
         text = text//pre//trim(words(i))
         if (i < size(words)) text = text//sep
      end do
   end function join

   !> Words in single quotes, separated by commas.
   pure function quoted(words) result(text)
      character(len=*), intent(in) :: words(:)
      character(len=:), allocatable :: text
      integer :: i

      text = ''
      do i = 1, size(words)
         text = text//"'"//trim(words(i))//"'"
         if (i < size(words)) text = text//', '
      end do
   end function quoted

   !> The 64-bit FNV-1a hash of a text as 16 hex digits: a fingerprint
   !> (not a cryptographic hash) that tells whether two texts are the same,
   !> e.g. a checkpoint's input and the run's.
   pure function text_hash(text) result(hex)
      character(len=*), intent(in) :: text
      character(len=16) :: hex
      integer(i8) :: bits

      bits = text_hash_bits(text)
      write (hex, '(z8.8, z8.8)') shiftr(bits, 32), iand(bits, 4294967295_i8)   ! two non-negative halves
      hex = lower(hex)
   end function text_hash

   !> text_hash as its 64 bits.  Computed in two 32-bit halves so no integer
   !> arithmetic overflows: h * p mod 2**64 with the prime p = 2**40 + 435
   !> is h * 435 + (h * 2**40 mod 2**64).
   pure function text_hash_bits(text) result(bits)
      character(len=*), intent(in) :: text
      integer(i8) :: bits
      integer(i8), parameter :: mask32 = 4294967295_i8, mask24 = 16777215_i8
      integer(i8) :: hi, lo, t
      integer :: i

      hi = 3421674724_i8   ! the offset basis cbf29ce4 84222325
      lo = 2216829733_i8
      do i = 1, len(text)
         lo = ieor(lo, int(iachar(text(i:i)), i8))
         t = lo * 435_i8                                        ! < 2**41
         hi = iand(hi * 435_i8 + shiftr(t, 32) + shiftl(iand(lo, mask24), 8), mask32)
         lo = iand(t, mask32)
      end do
      bits = ior(shiftl(hi, 32), lo)
   end function text_hash_bits

   !> A size in bytes as text for messages: '512 bytes', '3.2 MB', '288.0 GB'.
   pure function bytes_text(bytes) result(text)
      real(wp), intent(in) :: bytes
      character(len=:), allocatable :: text
      character(len=32) :: buffer
      character(len=*), parameter :: units(4) = ['kB', 'MB', 'GB', 'TB']
      real(wp) :: x
      integer :: k

      if (.not. ieee_is_finite(bytes)) then
         text = 'an unbounded size'
         return
      end if
      if (bytes < 1000.0_wp) then
         write (buffer, '(i0, a)') nint(bytes), ' bytes'
         text = trim(buffer)
         return
      end if
      x = bytes
      k = 0
      do while (x >= 1000.0_wp .and. k < size(units))
         x = x / 1000.0_wp
         k = k + 1
      end do
      text = fixed_text(x, 1)//' '//units(k)
   end function bytes_text

end module friction_strings
