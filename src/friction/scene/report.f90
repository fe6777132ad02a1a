!> How a running job talks to whoever started it, without printing: the
!> library calls these hooks (on rank 0 only) and the caller decides what to
!> show.  The base type is silent and never asks to stop; the command line
!> (app/) and the C API extend it.
module friction_scene_report
   use friction_kinds, only: wp
   use friction_strings, only: fixed_text, rtoa
   use friction_error, only: error_type, fatal_error, error_interrupted, error_numerical
   use friction_clock, only: wall_seconds
   use friction_ode_watch, only: step_watch
   implicit none
   private

   public :: job_reporter, progress_text, loop_guard, job_watch, new_job_watch

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
      !> Asked once piece `item` is done (a sweep point's number, or how many
      !> lines of a map this process computed): true stops the job there as
      !> a stop request would.  By default a stop request alone; a test's
      !> reporter stops after a given piece.
      procedure :: stop_after => stop_after_request
      !> Asked from within a piece of work, at most every 0.1 s (a thermal
      !> trip's guard): true stops it.  By default stop_requested; the C
      !> API's computation asks its caller's progress function again.
      procedure :: poll_stop => poll_request
   end type job_reporter

   !> What a long loop inside a run asks between its pieces (a Lyapunov
   !> estimate's renormalisations, a continuation's points): whether a stop
   !> was requested, and whether the integrator's max_wall_time has passed
   !> since the loop's work began.  Each piece is short and bounded, so the
   !> loop ends within one piece of the request or the limit.
   type :: loop_guard
      real(wp) :: started = 0.0_wp   !! wall_seconds() when the work began
      real(wp) :: limit = 0.0_wp     !! s; 0 for none
   contains
      procedure :: check => guard_check
   end type loop_guard

   !> A loop guard asked from inside an integration (the ode layer's watch):
   !> a trip that crawls through one output interval (a stiff law near a
   !> singular point takes steps of 1e-20 s) still ends on a stop request
   !> and at max_wall_time.  It holds a copy of the job's reporter (the
   !> request is the process's, not the copy's), asked at most every
   !> poll_interval s: a C API caller's stop function may be dear.
   type, extends(step_watch) :: job_watch
      type(loop_guard) :: guard
      class(job_reporter), allocatable :: stopper   !! none: max_wall_time alone
      character(len=:), allocatable :: what, unit
      real(wp) :: next_poll = -huge(1.0_wp)   !! wall_seconds() of the next look at stopper
   contains
      procedure :: check => watch_check
   end type job_watch

   !> Seconds between two looks at a watch's stopper.
   real(wp), parameter :: poll_interval = 0.05_wp

contains

   !> A watch over work that begins now: `what` and `unit` name the work and
   !> its time in the messages, `limit` is max_wall_time (0 for none).
   function new_job_watch(what, unit, limit, reporter) result(watch)
      character(len=*), intent(in) :: what, unit
      real(wp), intent(in) :: limit
      class(job_reporter), intent(in), optional :: reporter
      type(job_watch) :: watch

      watch%guard = loop_guard(started=wall_seconds(), limit=limit)
      watch%what = what
      watch%unit = unit
      if (present(reporter)) allocate (watch%stopper, source=reporter)
   end function new_job_watch

   subroutine watch_check(self, t, error)
      class(job_watch), intent(inout) :: self
      real(wp), intent(in) :: t
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: now

      now = wall_seconds()
      if (allocated(self%stopper) .and. now >= self%next_poll) then
         self%next_poll = now + poll_interval
         call self%guard%check(self%stopper, self%what, t, self%unit, error)
      else
         call self%guard%check(what=self%what, t=t, unit=self%unit, error=error)
      end if
   end subroutine watch_check

   !> An error when the loop must end: stopped on request (`reporter`, if
   !> given, asked), or max_wall_time reached; `what` names the work and
   !> `t` (in `unit`) how far it came, in the message.
   subroutine guard_check(self, reporter, what, t, unit, error)
      class(loop_guard), intent(in) :: self
      class(job_reporter), intent(inout), optional :: reporter
      character(len=*), intent(in) :: what, unit
      real(wp), intent(in) :: t
      type(error_type), allocatable, intent(inout) :: error

      if (allocated(error)) return
      if (present(reporter)) then
         if (reporter%stop_requested()) then
            call fatal_error(error, what//' stopped on request at '//unit//' = '//rtoa(t) &
               & //': no file written (run it again)', error_interrupted)
            return
         end if
      end if
      if (self%limit > 0.0_wp) then
         if (wall_seconds() - self%started > self%limit) call fatal_error(error, what//': max_wall_time = ' &
            & //rtoa(self%limit)//' s reached at '//unit//' = '//rtoa(t), error_numerical)
      end if
   end subroutine guard_check

   !> What a progress report says, for any reporter: "τ = 120.0 of 3200.0",
   !> "12 of 64 lines", "20 of 48 points started" (rank 0 knows the index of
   !> the point it last took; points are handed out in order, so that many
   !> have been started across the ranks).
   function progress_text(done, total, what) result(text)
      real(wp), intent(in) :: done, total
      character(len=*), intent(in) :: what
      character(len=:), allocatable :: text
      character(len=80) :: buffer

      if (what == 'tau') then
         buffer = 'τ = '//fixed_text(done, 1)//' of '//fixed_text(total, 1)
      else
         write (buffer, '(i0, a, i0, a)') nint(done), ' of ', nint(total), ' '//what
         if (what == 'points') buffer = trim(buffer)//' started'
      end if
      text = trim(buffer)
   end function progress_text

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

   logical function poll_request(self)
      class(job_reporter), intent(inout) :: self

      poll_request = self%stop_requested()
   end function poll_request

   logical function stop_after_request(self, item)
      class(job_reporter), intent(inout) :: self
      integer, intent(in) :: item

      stop_after_request = self%stop_requested()
   end function stop_after_request

end module friction_scene_report
