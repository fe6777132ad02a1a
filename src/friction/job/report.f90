!> How a running job talks to whoever started it, without printing: the
!> library calls these hooks (on rank 0 only) and the caller decides what to
!> show.  The base type is silent and never asks to stop; the command line
!> (app/) and the C API extend it.
module friction_job_report
   use friction_kinds, only: wp
   implicit none
   private

   public :: job_reporter

   type :: job_reporter
   contains
      !> Progress: `done` of `total` in units of `what` ('lines', 'tau' or
      !> 'points'); `last` marks the final report of a phase.
      procedure :: progress => silent_progress
      !> A message for the user that is not an error (a verify result, a
      !> warning about where a model holds).
      procedure :: note => silent_note
      !> Asked between independent pieces of work (sweep points): true stops
      !> the job there, leaving a valid, resumable file.
      procedure :: stop_requested => never_stop
   end type job_reporter

contains

   subroutine silent_progress(self, done, total, what, last)
      class(job_reporter), intent(inout) :: self
      real(wp), intent(in) :: done, total
      character(len=*), intent(in) :: what
      logical, intent(in) :: last
   end subroutine silent_progress

   subroutine silent_note(self, text)
      class(job_reporter), intent(inout) :: self
      character(len=*), intent(in) :: text
   end subroutine silent_note

   logical function never_stop(self)
      class(job_reporter), intent(inout) :: self

      never_stop = .false.
   end function never_stop

end module friction_job_report
