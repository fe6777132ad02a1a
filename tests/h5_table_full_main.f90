!> The sweep's table file (output/h5_table.f90) where it does not fit: eight
!> columns of 200000 doubles (12.8 MB) on a small disk or under a file-size
!> limit, or a disk that fills after the columns are made (`fill`: this
!> program fills it).  Prints "ok" after reading back every value written,
!> or "error: " and the table's message; HDF5 must then close cleanly, with
!> nothing of its own on stderr at exit (h5_write_failure_test.py checks).
!>
!>     h5_table_full PATH [fill]
program h5_table_full
   use, intrinsic :: iso_c_binding, only: c_char, c_int, c_size_t, c_intptr_t, c_ptr, c_loc, c_null_char
   use friction_kinds, only: wp, i8
   use friction_error, only: error_type
   use friction_output_h5_table, only: h5_table
   implicit none

   interface
      integer(c_int) function c_creat(path, mode) bind(c, name='creat')
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int), value :: mode
      end function c_creat
      integer(c_intptr_t) function c_write(fd, buffer, count) bind(c, name='write')
         import :: c_int, c_ptr, c_size_t, c_intptr_t
         integer(c_int), value :: fd
         type(c_ptr), value :: buffer
         integer(c_size_t), value :: count
      end function c_write
      integer(c_int) function c_close(fd) bind(c, name='close')
         import :: c_int
         integer(c_int), value :: fd
      end function c_close

      !> The program's signal set-up (app/signals.c): SIGXFSZ ignored, so a
      !> write past a file-size limit fails with EFBIG instead of killing.
      subroutine friction_ignore_write_signals() bind(c, name='friction_ignore_write_signals')
      end subroutine friction_ignore_write_signals
   end interface

   integer(i8), parameter :: n = 200000, step = 5000
   integer, parameter :: columns = 8
   type(h5_table) :: table
   type(error_type), allocatable :: error
   character(len=4096) :: path, mode
   real(wp), allocatable :: piece(:), back(:)
   integer(i8) :: at
   integer :: c
   logical :: same

   call friction_ignore_write_signals()
   call get_command_argument(1, path)
   call get_command_argument(2, mode)
   call table%create(trim(path), error)
   if (allocated(error)) call finish(error)
   do c = 1, columns
      call table%add_column(trim(column(c)), 'r', n, 'm')
   end do
   if (trim(mode) == 'fill') call fill_disk(trim(path)//'.filler')
   allocate (piece(step), back(step))
   at = 0
   do while (at < n)
      do c = 1, columns
         piece = values(c, at)
         call table%put(trim(column(c)), at, piece)
      end do
      at = at + step
   end do
   same = .true.
   at = 0
   do while (at < n .and. .not. table%failed())
      do c = 1, columns
         call table%get(trim(column(c)), at, back)
         same = same .and. all(back == values(c, at))
      end do
      at = at + step
   end do
   call table%close(error)
   if (.not. allocated(error) .and. .not. same) then
      print '(a)', 'wrong: a value read back differs from the one written'
      error stop 1
   end if
   call finish(error)

contains

   character(len=8) function column(c)
      integer, intent(in) :: c

      write (column, '(a, i0)') 'col', c
   end function column

   !> Column c's values from element `at` on: c + k/n, each one distinct.
   function values(c, at) result(x)
      integer, intent(in) :: c
      integer(i8), intent(in) :: at
      real(wp) :: x(step)
      integer(i8) :: k

      x = [(real(c, wp) + real(at + k, wp) / real(n, wp), k = 0, step - 1)]
   end function values

   !> Write zeros to `filler` until the disk refuses another byte (through
   !> the C library: the Fortran runtime's buffer hides the failures).
   subroutine fill_disk(filler)
      character(len=*), intent(in) :: filler
      character(kind=c_char), target :: block(4096)
      integer(c_int) :: fd, ignored
      integer(c_size_t) :: count

      block = c_null_char
      fd = c_creat(filler//c_null_char, int(o'644', c_int))
      if (fd < 0) return
      count = size(block, kind=c_size_t)
      do while (count > 0)
         if (c_write(fd, c_loc(block), count) <= 0) count = count / 2
      end do
      ignored = c_close(fd)
   end subroutine fill_disk

   subroutine finish(error)
      type(error_type), allocatable, intent(in) :: error

      if (allocated(error)) then
         print '(a)', 'error: '//error%message
      else
         print '(a)', 'ok'
      end if
      stop
   end subroutine finish

end program h5_table_full
