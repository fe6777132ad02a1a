!> The C API's reporter: a job's or a computation's progress and notes
!> through the caller's C function, and the caller's requests to stop.
module friction_capi_reporter
   use, intrinsic :: iso_c_binding, only: c_ptr, c_char, c_int, c_double, c_null_char, c_null_ptr
   use friction_kinds, only: wp
   use friction_job, only: job_reporter
   use friction_scene_report, only: progress_text
   implicit none
   private

   public :: callback_reporter

   !> A job's or a computation's progress through the caller's C function.
   !> A job's (`call`, if any): void report(const char *message, double
   !> fraction, void *user), fraction in [0, 1] for progress and -1 for a
   !> note; it stops on friction_job_stop.  A computation's (`ask`): int
   !> progress(const char *message, double fraction, void *user), whose
   !> nonzero return stops it at its next safe point; the request is that
   !> call's own, so computations on other threads go on.
   type, extends(job_reporter) :: callback_reporter
      procedure(report_function), pointer, nopass :: call => null()
      procedure(progress_function), pointer, nopass :: ask => null()
      type(c_ptr) :: user = c_null_ptr
      logical :: stop = .false.   !! `ask` returned nonzero
      !> the last progress message given to `ask`, C string ('started' before any)
      character(len=:), allocatable :: last_text
   contains
      procedure :: progress => callback_progress
      procedure :: note => callback_note
      procedure :: stop_requested => callback_stop_requested
      procedure :: poll_stop => callback_poll_stop
   end type callback_reporter

   abstract interface
      integer(c_int) function progress_function(message, fraction, user) bind(c)
         import :: c_char, c_double, c_ptr, c_int
         character(kind=c_char), intent(in) :: message(*)
         real(c_double), value :: fraction
         type(c_ptr), value :: user
      end function progress_function

      subroutine report_function(message, fraction, user) bind(c)
         import :: c_char, c_double, c_ptr
         character(kind=c_char), intent(in) :: message(*)
         real(c_double), value :: fraction
         type(c_ptr), value :: user
      end subroutine report_function
   end interface

   interface
      function friction_job_stop_asked() bind(c, name='friction_job_stop_asked') result(asked)
         import :: c_int
         integer(c_int) :: asked
      end function friction_job_stop_asked
   end interface

contains

   subroutine callback_progress(self, done, total, what, last)
      class(callback_reporter), intent(inout) :: self
      real(wp), intent(in) :: done, total
      character(len=*), intent(in) :: what
      logical, intent(in) :: last
      character(len=:), allocatable :: text
      real(c_double) :: fraction

      text = progress_text(done, total, what)//c_null_char
      fraction = real(max(0.0_wp, min(1.0_wp, done / max(total, tiny(total)))), c_double)
      if (associated(self%call)) call self%call(text, fraction, self%user)
      if (associated(self%ask)) self%stop = self%stop .or. self%ask(text, fraction, self%user) /= 0
      self%last_text = text
   end subroutine callback_progress

   subroutine callback_note(self, text)
      class(callback_reporter), intent(inout) :: self
      character(len=*), intent(in) :: text

      if (associated(self%call)) call self%call(text//c_null_char, -1.0_c_double, self%user)
   end subroutine callback_note

   !> Whether the computation's progress function asked to stop (returned
   !> nonzero), or for a job the host did (friction_job_stop, job_lock.c).
   logical function callback_stop_requested(self)
      class(callback_reporter), intent(inout) :: self

      if (associated(self%ask)) then
         callback_stop_requested = self%stop
      else
         callback_stop_requested = friction_job_stop_asked() /= 0
      end if
   end function callback_stop_requested

   !> Within a piece of work: a computation's progress function is called
   !> again with the last message and fraction -1 (a poll, not progress:
   !> friction.h), and its nonzero return stops the computation there; a
   !> job's stop request as between pieces.
   logical function callback_poll_stop(self)
      class(callback_reporter), intent(inout) :: self

      if (.not. associated(self%ask)) then
         callback_poll_stop = self%stop_requested()
         return
      end if
      if (.not. allocated(self%last_text)) self%last_text = 'started'//c_null_char
      if (.not. self%stop) self%stop = self%ask(self%last_text, -1.0_c_double, self%user) /= 0
      callback_poll_stop = self%stop
   end function callback_poll_stop

end module friction_capi_reporter
