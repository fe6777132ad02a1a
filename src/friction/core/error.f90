!> Error handling: library routines return an allocated `error_type` on
!> failure and never print or stop; only the application does that.
module friction_error
   implicit none
   private

   public :: error_type, fatal_error
   public :: error_input, error_numerical, error_io, error_internal, error_interrupted

   integer, parameter :: error_input = 1     !! bad input: file, group, variable, value
   integer, parameter :: error_numerical = 2 !! integration failed or produced NaN/Inf
   integer, parameter :: error_io = 3        !! file system or HDF5 failure
   integer, parameter :: error_internal = 4  !! a broken invariant of the program
   integer, parameter :: error_interrupted = 5 !! stopped on request; the output is valid and resumable

   !> An error: a category and a message for the user.
   type :: error_type
      integer :: stat = error_internal     !! one of the error_* codes
      character(len=:), allocatable :: message
   end type error_type

contains

   !> Create an error with a message (and a category, internal when absent).
   pure subroutine fatal_error(error, message, stat)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in) :: message
      integer, intent(in), optional :: stat

      allocate (error)
      error%message = message
      if (present(stat)) error%stat = stat
   end subroutine fatal_error

end module friction_error
