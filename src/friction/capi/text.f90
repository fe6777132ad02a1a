!> The C API's text: C strings read as Fortran text, and Fortran text
!> copied into the caller's buffers with the sizes the header promises.
module friction_capi_text
   use, intrinsic :: iso_c_binding, only: c_ptr, c_char, c_int, c_size_t, c_null_char, c_associated, c_f_pointer
   use friction_error, only: error_input
   use friction_strings, only: itoa
   implicit none
   private

   public :: c_string, copy_text, len_text, text_status, element_name

   interface
      pure function c_strlen(s) bind(c, name='strlen') result(n)
         import :: c_ptr, c_size_t
         type(c_ptr), value :: s
         integer(c_size_t) :: n
      end function c_strlen
   end interface

contains

   !> Copy text and a NUL into a caller buffer of len bytes; `needed` is the
   !> bytes it takes (NUL included).  False if the buffer is null or too
   !> small: then as much as fits is written, NUL-terminated (if len > 0).
   function copy_text(text, buf, len, needed) result(ok)
      character(len=*), intent(in) :: text
      type(c_ptr), intent(in) :: buf
      integer(c_size_t), intent(in) :: len
      type(c_ptr), intent(in), optional :: needed
      logical :: ok
      character(kind=c_char), pointer :: out(:)
      integer(c_size_t), pointer :: needed_out
      integer :: i, n

      if (present(needed)) then
         if (c_associated(needed)) then
            call c_f_pointer(needed, needed_out)
            needed_out = int(len_text(text) + 1, c_size_t)
         end if
      end if
      ok = .false.
      if (.not. c_associated(buf) .or. len < 1) return
      call c_f_pointer(buf, out, [len])
      n = int(min(int(len_text(text), c_size_t), len - 1))
      do i = 1, n
         out(i) = text(i:i)
      end do
      out(n + 1) = c_null_char
      ok = len_text(text) < len
   end function copy_text

   !> len(text), for the procedures whose argument `len` (the C name) hides
   !> the intrinsic.
   pure integer function len_text(text)
      character(len=*), intent(in) :: text

      len_text = len(text)
   end function len_text

   !> A C string as Fortran text; '' for a null pointer.
   function c_string(s) result(text)
      type(c_ptr), intent(in) :: s
      character(len=:), allocatable :: text
      character(kind=c_char), pointer :: chars(:)
      integer :: i, n

      if (.not. c_associated(s)) then
         text = ''
         return
      end if
      n = int(c_strlen(s))
      call c_f_pointer(s, chars, [n])
      allocate (character(len=n) :: text)
      do i = 1, n
         text(i:i) = chars(i)
      end do
   end function c_string

   !> Text into a buffer: 0 when it fits; a size query (buf null, len 0)
   !> also succeeds; a buffer too small (truncated) or null is an input error.
   integer(c_int) function text_status(text, buf, len, needed) result(status)
      character(len=*), intent(in) :: text
      type(c_ptr), intent(in) :: buf, needed
      integer(c_size_t), intent(in) :: len

      status = 0
      if (copy_text(text, buf, len, needed)) return
      if (.not. (.not. c_associated(buf) .and. len == 0 .and. c_associated(needed))) status = error_input
   end function text_status

   !> name, or name(first) for one element.
   pure function element_name(name, first) result(shown)
      character(len=*), intent(in) :: name
      integer, intent(in) :: first
      character(len=:), allocatable :: shown

      shown = name
      if (first > 0) shown = shown//'('//itoa(first)//')'
   end function element_name

end module friction_capi_text
