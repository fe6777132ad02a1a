!> A small assertion module shaped like pFUnit's: one procedure per property,
!> a failure message with expected and actual values, a runner that counts.
module testing
   use, intrinsic :: iso_fortran_env, only: error_unit, output_unit
   use friction_kinds, only: wp
   implicit none
   private

   public :: test_suite, check, check_close

   !> Name of the case being run, for suites that parametrise by name.
   character(len=64), public, protected :: current_test = ''

   abstract interface
      subroutine test_procedure(failure)
         import :: wp
         character(len=:), allocatable, intent(out) :: failure
      end subroutine test_procedure
   end interface

   type :: test_case
      character(len=64) :: name
      procedure(test_procedure), pointer, nopass :: run => null()
   end type test_case

   type :: test_suite
      character(len=64) :: name = ''
      type(test_case), allocatable :: cases(:)
   contains
      procedure :: add
      procedure :: run_all
   end type test_suite

contains

   subroutine add(self, name, proc)
      class(test_suite), intent(inout) :: self
      character(len=*), intent(in) :: name
      procedure(test_procedure) :: proc
      type(test_case) :: case

      if (.not. allocated(self%cases)) allocate (self%cases(0))
      case%name = name
      case%run => proc
      self%cases = [self%cases, case]
   end subroutine add

   !> Run every case, or only the one named by the first command argument;
   !> stop with a non-zero code when any fails.
   subroutine run_all(self)
      class(test_suite), intent(in) :: self
      character(len=:), allocatable :: failure
      character(len=64) :: only
      integer :: i, failed, ran

      call get_command_argument(1, only)
      failed = 0
      ran = 0
      do i = 1, size(self%cases)
         if (len_trim(only) > 0 .and. only /= self%cases(i)%name) cycle
         ran = ran + 1
         current_test = self%cases(i)%name
         call self%cases(i)%run(failure)
         if (allocated(failure)) then
            failed = failed + 1
            write (error_unit, '(a)') trim(self%name)//'::'//trim(self%cases(i)%name)//' FAILED: '//failure
         else
            write (output_unit, '(a)') trim(self%name)//'::'//trim(self%cases(i)%name)//' ok'
         end if
      end do
      write (output_unit, '(i0, a, i0, a)') ran - failed, ' passed, ', failed, ' failed'
      if (ran == 0) error stop 'no test matched'
      if (failed > 0) error stop 1, quiet=.true.
   end subroutine run_all

   !> Record a failure when condition is false.
   subroutine check(failure, condition, message)
      character(len=:), allocatable, intent(inout) :: failure
      logical, intent(in) :: condition
      character(len=*), intent(in) :: message

      if (allocated(failure)) return
      if (.not. condition) failure = message
   end subroutine check

   !> |actual - expected| <= tolerance, else a message with both values.
   subroutine check_close(failure, actual, expected, tolerance, what)
      character(len=:), allocatable, intent(inout) :: failure
      real(wp), intent(in) :: actual, expected, tolerance
      character(len=*), intent(in) :: what
      character(len=200) :: text

      if (allocated(failure)) return
      if (.not. (abs(actual - expected) <= tolerance)) then
         write (text, '(a, es23.15, a, es23.15, a, es10.3, a, es10.3)') ': expected ', expected, &
            & ', got ', actual, ', difference ', abs(actual - expected), ' > tolerance ', tolerance
         failure = what//trim(text)
      end if
   end subroutine check_close

end module testing
