!> Text helpers: numbers and lists as text for messages, case folding.
module friction_strings
   use friction_kinds, only: wp, i8
   implicit none
   private

   public :: itoa, rtoa, join, quoted, lower

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

   pure function itoa8(i) result(text)
      integer(i8), intent(in) :: i
      character(len=:), allocatable :: text
      character(len=24) :: buffer

      write (buffer, '(i0)') i
      text = trim(buffer)
   end function itoa8

   !> A real as text with 7 significant digits.
   pure function rtoa(x) result(text)
      real(wp), intent(in) :: x
      character(len=:), allocatable :: text
      character(len=32) :: buffer

      write (buffer, '(1pg0.6)') x
      text = trim(adjustl(buffer))
   end function rtoa

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

end module friction_strings
