!> File-system operations Fortran lacks: atomic rename and removal through
!> the C library, so output appears under its final name only when complete.
module friction_files
   use, intrinsic :: iso_c_binding, only: c_int, c_char, c_null_char
   use friction_error, only: error_type, fatal_error, error_io, error_input
   implicit none
   private

   public :: rename_file, remove_file, file_exists, process_id, write_text_file, open_for_reading

   interface
      function c_rename(from, to) result(stat) bind(c, name='rename')
         import :: c_int, c_char
         character(kind=c_char), intent(in) :: from(*), to(*)
         integer(c_int) :: stat
      end function c_rename

      function c_remove(path) result(stat) bind(c, name='remove')
         import :: c_int, c_char
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int) :: stat
      end function c_remove

      !> POSIX getpid (pid_t is an int on the platforms we build for).
      function c_getpid() result(pid) bind(c, name='getpid')
         import :: c_int
         integer(c_int) :: pid
      end function c_getpid
   end interface

contains

   !> Open an existing file to read: a missing file is bad input, one that
   !> cannot be opened an error of `category` (bad input by default).
   subroutine open_for_reading(path, unit, error, category)
      character(len=*), intent(in) :: path
      integer, intent(out) :: unit
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in), optional :: category
      integer :: stat

      if (.not. file_exists(path)) then
         call fatal_error(error, path//': no such file', error_input)
         return
      end if
      open (newunit=unit, file=path, status='old', action='read', iostat=stat)
      if (stat /= 0) then
         call fatal_error(error, path//': cannot open the file', error_input)
         if (present(category)) error%stat = category
      end if
   end subroutine open_for_reading

   logical function file_exists(path)
      character(len=*), intent(in) :: path

      inquire (file=path, exist=file_exists)
   end function file_exists

   !> Rename atomically (within one file system), replacing `to` if present.
   subroutine rename_file(from, to, error)
      character(len=*), intent(in) :: from, to
      type(error_type), allocatable, intent(out) :: error

      if (c_rename(from//c_null_char, to//c_null_char) /= 0) &
         & call fatal_error(error, 'cannot rename '//from//' to '//to, error_io)
   end subroutine rename_file

   !> Remove a file if it exists; failures are ignored (best effort cleanup).
   subroutine remove_file(path)
      character(len=*), intent(in) :: path
      integer(c_int) :: stat

      if (file_exists(path)) stat = c_remove(path//c_null_char)
   end subroutine remove_file

   !> This process's id, to make temporary file names unique.
   integer function process_id()
      process_id = int(c_getpid())
   end function process_id


   !> Write text to path, complete or not at all (a temporary name beside it,
   !> renamed when written).
   subroutine write_text_file(path, text, error)
      character(len=*), intent(in) :: path, text
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: temporary
      character(len=256) :: message
      integer :: unit, stat

      temporary = path//'.tmp'
      open (newunit=unit, file=temporary, status='replace', action='write', form='unformatted', &
         & access='stream', iostat=stat, iomsg=message)
      if (stat /= 0) then
         call fatal_error(error, path//': cannot write the file here ('//trim(message)//')', error_io)
         return
      end if
      write (unit, iostat=stat, iomsg=message) text
      if (stat /= 0) then
         close (unit, status='delete')
         call fatal_error(error, path//': writing failed ('//trim(message)//')', error_io)
         return
      end if
      close (unit)
      call rename_file(temporary, path, error)
      if (allocated(error)) call remove_file(temporary)
   end subroutine write_text_file

end module friction_files
