!> The command line's reporter: a running job's progress and notes on
!> stderr, and SIGTERM/SIGINT as a request to stop a sweep.
module friction_app_terminal_reporter
   use, intrinsic :: iso_c_binding, only: c_int
   use, intrinsic :: iso_fortran_env, only: error_unit
   use friction_clock, only: wall_seconds
   use friction_kinds, only: wp
   use friction_job, only: job_reporter
   use friction_scene_report, only: progress_text
   implicit none
   private

   public :: terminal_reporter

   interface
      function friction_stderr_is_terminal() result(yes) bind(c)
         import :: c_int
         integer(c_int) :: yes
      end function friction_stderr_is_terminal
      subroutine friction_catch_signals() bind(c)
      end subroutine friction_catch_signals
      function friction_interrupted() result(yes) bind(c)
         import :: c_int
         integer(c_int) :: yes
      end function friction_interrupted
   end interface

   !> Progress on stderr (rank 0): redrawn in place on a terminal; otherwise
   !> plain lines, spaced further apart as the run goes on so that a long
   !> batch log stays short (under mpirun stderr is a pipe even at a terminal).
   type, extends(job_reporter) :: terminal_reporter
      logical :: quiet = .false.
      logical :: catching = .false.
      real(wp) :: t_start = 0.0_wp
      real(wp) :: shown = -1.0_wp
      real(wp) :: shown_done = -1.0_wp
   contains
      procedure :: progress => show_progress
      procedure :: note => show_note
      procedure :: stop_requested => signal_received
   end type terminal_reporter

contains

   !> `done` of `total` lines, τ or sweep points, with the time elapsed and
   !> an estimate of the time remaining.
   subroutine show_progress(self, done, total, what, last)
      class(terminal_reporter), intent(inout) :: self
      real(wp), intent(in) :: done, total
      character(len=*), intent(in) :: what
      logical, intent(in) :: last
      real(wp) :: now, elapsed, remaining, interval
      logical :: tty
      character(len=200) :: text
      character(len=12) :: seconds(2)

      if (self%quiet) return
      now = wall_seconds()
      tty = friction_stderr_is_terminal() /= 0
      interval = 0.5_wp
      if (.not. tty) interval = max(2.0_wp, 0.1_wp * (now - self%t_start))
      if (.not. last .and. now - max(self%shown, self%t_start) < interval) return
      if (last .and. (self%shown < 0.0_wp .or. done == self%shown_done)) return   ! nothing new to say
      self%shown = now
      self%shown_done = done
      elapsed = now - self%t_start
      remaining = 0.0_wp
      if (done > 0.0_wp) remaining = elapsed * max(0.0_wp, total - done) / done
      ! (f0.1 would drop the leading zero of 0.5 s.)
      write (seconds(1), '(f12.1)') elapsed
      write (seconds(2), '(f12.1)') remaining
      text = 'friction:'
      if (what == 'points') text = 'friction: sweep:'
      text = trim(text)//' '//progress_text(done, total, what)//', '//trim(adjustl(seconds(1)))//' s elapsed, ' &
         & //trim(adjustl(seconds(2)))//' s remaining'
      if (tty) then
         write (error_unit, '(a)', advance='no') achar(13)//trim(text)//'   '
         if (last) write (error_unit, '(a)') ''
      else
         write (error_unit, '(a)') trim(text)
      end if
      flush (error_unit)
   end subroutine show_progress

   subroutine show_note(self, text)
      class(terminal_reporter), intent(inout) :: self
      character(len=*), intent(in) :: text

      write (error_unit, '(a)') 'friction: '//text
      flush (error_unit)
   end subroutine show_note

   !> SIGTERM and SIGINT (Ctrl-C, a cluster's wall-time limit) stop a sweep
   !> between points.  The handler goes in at the first question, which is
   !> the start of a sweep: other jobs keep the default (Ctrl-C stops them).
   logical function signal_received(self)
      class(terminal_reporter), intent(inout) :: self

      if (.not. self%catching) then
         call friction_catch_signals()
         self%catching = .true.
      end if
      signal_received = friction_interrupted() /= 0
   end function signal_received

end module friction_app_terminal_reporter
