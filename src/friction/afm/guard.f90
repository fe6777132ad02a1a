!> When a trip must end before its last sample: the wall time of
!> &integrator max_wall_time has passed, the job asks to stop, or the sample
!> of a cost estimate has run its course.  Every trip kind asks its guard
!> between the stretches it integrates.
module friction_afm_guard
   use friction_kinds, only: wp, i8
   use friction_error, only: error_type, fatal_error, error_numerical, error_interrupted
   use friction_scene_report, only: job_reporter
   use friction_strings, only: rtoa
   implicit none
   private

   public :: trip_guard

   !> Wall time, s, between two looks at the stop request within a trip: the
   !> C API's request is a call into the caller's code.
   real(wp), parameter :: stop_poll = 0.1_wp

   !> The clock and the stop request a scanner's trips answer to.
   type :: trip_guard
      real(wp) :: max_wall_time = 0.0_wp              !! s; 0: none
      integer(i8) :: clock_start = 0, clock_rate = 1   !! wall clock at start, for max_wall_time
      integer(i8) :: next_poll = 0                     !! clock count of the next look at `stopper`
      !> a cost estimate's sample: the clock count at which it ends (0:
      !> none), the support time at which it ends, and the support time it
      !> reached
      integer(i8) :: sample_end = 0
      real(wp) :: sample_stop = 0.0_wp
      real(wp) :: reached = 0.0_wp
      !> asked within a trip whether the job should stop (a copy of the job's
      !> reporter: its request is the process's, not the copy's); none: never
      class(job_reporter), allocatable :: stopper
   contains
      procedure :: start
      procedure :: check
      procedure :: next_look
   end type trip_guard

contains

   !> The clock started now, with the wall-time limit, s (0: none).
   subroutine start(self, max_wall_time)
      class(trip_guard), intent(inout) :: self
      real(wp), intent(in) :: max_wall_time

      self%max_wall_time = max_wall_time
      call system_clock(self%clock_start, self%clock_rate)
   end subroutine start

   !> The clock count stop_poll s after `now`: where a long computation
   !> pauses to let the guard look.
   pure integer(i8) function next_look(self, now)
      class(trip_guard), intent(in) :: self
      integer(i8), intent(in) :: now

      next_look = now + int(stop_poll * self%clock_rate, i8)
   end function next_look

   !> An error when the trip must end here: the wall time since start has
   !> passed max_wall_time (error_numerical), the cost sample has ended, or
   !> the stopper, looked at every stop_poll s, asks to stop
   !> (error_interrupted).  `what` names the scheme, t the support time.
   subroutine check(self, what, t, error)
      class(trip_guard), intent(inout) :: self
      character(len=*), intent(in) :: what
      real(wp), intent(in) :: t
      type(error_type), allocatable, intent(inout) :: error
      integer(i8) :: now

      if (allocated(error)) return
      call system_clock(now)
      if (self%sample_end > 0 .and. (now >= self%sample_end .or. t >= self%sample_stop)) then
         self%reached = t
         call fatal_error(error, what//': the sample of the cost estimate ended', error_interrupted)
         return
      end if
      if (self%max_wall_time > 0.0_wp .and. real(now - self%clock_start, wp) / self%clock_rate &
         & > self%max_wall_time) then
         call fatal_error(error, what//': max_wall_time = '//rtoa(self%max_wall_time)//' s reached at t = ' &
            & //rtoa(t)//' s', error_numerical)
         return
      end if
      if (.not. allocated(self%stopper) .or. now < self%next_poll) return
      self%next_poll = self%next_look(now)
      if (self%stopper%poll_stop()) call fatal_error(error, what//': stopped on request at t = '//rtoa(t) &
         & //' s', error_interrupted)
   end subroutine check

end module friction_afm_guard
