!> The command line's reporter: a running job's progress and notes on
!> stderr, and SIGTERM/SIGINT as a request to stop a sweep.  Standard error
!> that cannot be written (a closed pipe, a full disk under a log) is a
!> request to stop too, and the program then exits with the I/O error's code.
module friction_app_terminal_reporter
   use, intrinsic :: iso_c_binding, only: c_int, c_char, c_size_t
   use friction_clock, only: wall_seconds
   use friction_kinds, only: wp
   use friction_job, only: job_reporter
   use friction_scene_report, only: progress_text
   implicit none
   private

   public :: terminal_reporter, say, write_fd

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
      integer(c_int) function friction_write_fd(fd, buf, n, message, length) bind(c)
         import :: c_int, c_char, c_size_t
         integer(c_int), value :: fd
         character(kind=c_char), intent(in) :: buf(*)
         integer(c_size_t), value :: n
         character(kind=c_char), intent(inout) :: message(*)
         integer(c_size_t), value :: length
      end function friction_write_fd
   end interface

   !> Progress on stderr (rank 0): redrawn in place on a terminal; otherwise
   !> plain lines, spaced further apart as the run goes on so that a long
   !> batch log stays short (under mpirun stderr is a pipe even at a terminal).
   type, extends(job_reporter) :: terminal_reporter
      logical :: quiet = .false.
      logical :: catching = .false.
      logical :: lost = .false.   !! a write to stderr failed: nobody hears the run any more
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

      if (self%quiet .or. self%lost) return
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
         call say(self, achar(13)//trim(text)//'   ', .false.)
         if (last) call say(self, '')
      else
         call say(self, trim(text))
      end if
   end subroutine show_progress

   subroutine show_note(self, text)
      class(terminal_reporter), intent(inout) :: self
      character(len=*), intent(in) :: text

      call say(self, 'friction: '//text)
   end subroutine show_note

   !> Write `text` on stderr (a line, unless `line` is false); a failure
   !> (EPIPE: SIGPIPE is ignored, app/signals.c) marks stderr lost.
   subroutine say(self, text, line)
      class(terminal_reporter), intent(inout) :: self
      character(len=*), intent(in) :: text
      logical, intent(in), optional :: line
      character(len=:), allocatable :: problem
      logical :: whole_line

      if (self%lost) return
      whole_line = .true.
      if (present(line)) whole_line = line
      if (whole_line) then
         call write_fd(2, text//new_line('a'), problem)
      else
         call write_fd(2, text, problem)
      end if
      if (len(problem) > 0) self%lost = .true.
   end subroutine say

   !> Write `text` to file descriptor fd (1 or 2) through the C library:
   !> gfortran's own write and flush report success on a closed pipe and on
   !> /dev/full.  `problem` is '' when written, else why not.
   subroutine write_fd(fd, text, problem)
      integer, intent(in) :: fd
      character(len=*), intent(in) :: text
      character(len=:), allocatable, intent(out) :: problem
      character(len=200) :: message
      integer :: nul

      message = ''
      problem = ''
      if (friction_write_fd(int(fd, c_int), text, int(len(text), c_size_t), message, &
         & int(len(message), c_size_t)) == 0) return
      nul = index(message, achar(0))
      if (nul == 0) nul = len(message) + 1
      problem = trim(message(1:nul - 1))
      if (len(problem) == 0) problem = 'a write error'
   end subroutine write_fd

   !> SIGTERM and SIGINT (Ctrl-C, a cluster's wall-time limit) stop a sweep
   !> between points.  The handler goes in at the first question, which is
   !> the start of a sweep: other jobs keep the default (Ctrl-C stops them).
   logical function signal_received(self)
      class(terminal_reporter), intent(inout) :: self

      if (.not. self%catching) then
         call friction_catch_signals()
         self%catching = .true.
      end if
      signal_received = friction_interrupted() /= 0 .or. self%lost
   end function signal_received

end module friction_app_terminal_reporter
