!> The program as the test suite runs it to interrupt a job at a chosen
!> place: the command line's own code (friction_app_cli) with a reporter
!> that asks for a stop once piece FRICTION_TEST_STOP_AFTER is done (a sweep
!> point's number, or how many lines of a map a process computed), as
!> SIGTERM there would.  Unset or not a positive number: never.  The
!> program `friction` itself reads no such variable.
module stop_after_reporter
   use friction_app_terminal_reporter, only: terminal_reporter
   implicit none
   private

   public :: stopping_reporter

   type, extends(terminal_reporter) :: stopping_reporter
      integer :: after = 0
   contains
      procedure :: stop_after => stop_after_item
   end type stopping_reporter

contains

   logical function stop_after_item(self, item)
      class(stopping_reporter), intent(inout) :: self
      integer, intent(in) :: item

      stop_after_item = self%stop_requested()
      if (self%after > 0 .and. item >= self%after) stop_after_item = .true.
   end function stop_after_item

end module stop_after_reporter

program friction_stop_after
   use stop_after_reporter, only: stopping_reporter
   use friction_app_cli, only: run_program
   implicit none

   type(stopping_reporter) :: reporter
   character(len=32) :: text
   integer :: length, stat

   call get_environment_variable('FRICTION_TEST_STOP_AFTER', text, length, stat)
   if (stat == 0 .and. length > 0) then
      read (text, *, iostat=stat) reporter%after
      if (stat /= 0 .or. reporter%after < 0) reporter%after = 0
   end if
   call run_program(reporter)
end program friction_stop_after
