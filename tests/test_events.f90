!> A test system with events and an exact solution.
module event_test_systems
   use friction_kinds, only: wp
   use friction_ode_events, only: event_system
   implicit none
   private
   public :: ringing

   !> x'' = -ω² x as (x, v) from (1, 0): x = cos ωt, v = -ω sin ωt.
   !> Events: 1. x (zero at ωt = π/2 + kπ), 2. v (zero at ωt = kπ).
   type, extends(event_system) :: ringing
      real(wp) :: omega = 3.0_wp
      real(wp) :: offset = 0.0_wp   !! events at x, v = offset (2 never fires)
   contains
      procedure :: dimension
      procedure :: rhs
      procedure :: jacobian
      procedure :: event_count
      procedure :: event_values
   end type ringing

contains

   pure integer function dimension(self) result(n)
      class(ringing), intent(in) :: self
      n = 2
   end function dimension

   pure subroutine rhs(self, t, y, dydt)
      class(ringing), intent(in) :: self
      real(wp), intent(in) :: t, y(:)
      real(wp), intent(out) :: dydt(:)
      dydt(1) = y(2)
      dydt(2) = -self%omega**2 * y(1)
   end subroutine rhs

   pure subroutine jacobian(self, t, y, dfdy, dfdt)
      class(ringing), intent(in) :: self
      real(wp), intent(in) :: t, y(:)
      real(wp), intent(out) :: dfdy(:, :), dfdt(:)
      dfdy = reshape([0.0_wp, -self%omega**2, 1.0_wp, 0.0_wp], [2, 2])
      dfdt = 0.0_wp
   end subroutine jacobian

   pure integer function event_count(self) result(n)
      class(ringing), intent(in) :: self
      n = 2
   end function event_count

   pure subroutine event_values(self, t, y, g)
      class(ringing), intent(in) :: self
      real(wp), intent(in) :: t, y(:)
      real(wp), intent(out) :: g(:)
      g = y(1:2) - self%offset
   end subroutine event_values

end module event_test_systems

!> The event locator (friction_ode_events) against exact crossing times of
!> a harmonic oscillator, with every GSL stepper; terminal and non-terminal
!> events, the tolerance, functions that start at zero, and the guards.
program test_events
   use friction_kinds, only: wp, i8, pi
   use friction_error, only: error_type
   use friction_ode_solver, only: solver_settings, step_type_names
   use friction_ode_events, only: event_locator, event_rising, event_falling, event_either
   use event_test_systems, only: ringing
   use testing, only: test_suite, check, check_close, current_test
   implicit none

   type(test_suite) :: suite
   integer :: m
   character(len=:), allocatable :: names(:)

   suite%name = 'events'
   names = step_type_names()
   do m = 1, size(names)
      call suite%add('crossings_'//trim(names(m)), crossings_case)
   end do
   call suite%add('terminal_stops_at_the_event', terminal_stops_at_the_event)
   call suite%add('time_error_within_tolerance', time_error_within_tolerance)
   call suite%add('zero_at_restart', zero_at_restart)
   call suite%add('non_terminal_leaves_integration_alone', non_terminal_leaves_integration_alone)
   call suite%add('dips_within_a_step', dips_within_a_step)
   call suite%add('step_budget_reported', step_budget_reported)
   call suite%add('wall_time_reported', wall_time_reported)
   call suite%add('h_min_reported', h_min_reported)
   call suite%run_all()

contains

   !> Every zero of x in (0, 10] (either direction, non-terminal) against
   !> ωt = π/2 + kπ.  An event time can be off by the time tolerance plus the
   !> state error divided by the speed of the crossing, |x'| = ω; the state
   !> error is measured against the exact solution at every stop.
   subroutine crossings_case(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(ringing), target :: system
      type(event_locator) :: locator
      type(solver_settings) :: settings
      type(error_type), allocatable :: error
      real(wp) :: t, y(2), state_error, t_exact, bound
      real(wp), parameter :: time_tolerance = 1.0e-9_wp
      integer :: found, i, direction
      character(len=:), allocatable :: method
      character(len=120) :: text

      method = trim(current_test(index(current_test, '_') + 1:))
      settings%method = method
      ! Low-order methods get a tolerance they can meet in a few thousand steps.
      select case (method)
      case ('rk2', 'rk2imp', 'rk1imp')
         settings%rtol = 1.0e-7_wp
      case default
         settings%rtol = 1.0e-10_wp
      end select
      settings%atol = settings%rtol
      call locator%init(system, settings, [event_either, event_either], [.false., .false.], &
         & time_tolerance, 1.0e-4_wp, error)
      if (allocated(error)) then
         failure = error%message
         return
      end if
      t = 0.0_wp
      y = [1.0_wp, 0.0_wp]
      call locator%restart(t, y, 0.0_wp)
      found = 0
      state_error = 0.0_wp
      do while (t < 10.0_wp)
         call locator%advance(t, 10.0_wp, y, error)
         if (allocated(error)) then
            failure = error%message
            return
         end if
         state_error = max(state_error, abs(y(1) - cos(3.0_wp * t)), abs(y(2) + 3.0_wp * sin(3.0_wp * t)))
         do i = 1, locator%n_hits
            if (locator%hits(i)%which /= 1) cycle
            found = found + 1
            t_exact = (pi / 2 + (found - 1) * pi) / 3.0_wp
            bound = time_tolerance + 3.0_wp * max(state_error, settings%rtol) / 3.0_wp
            write (text, '(a, i0)') method//': crossing ', found
            call check_close(failure, locator%hits(i)%t, t_exact, bound, trim(text))
            ! x = cos falls through its odd zeros and rises through the even ones.
            direction = merge(event_falling, event_rising, mod(found, 2) == 1)
            call check(failure, locator%hits(i)%direction == direction, trim(text)//': wrong direction')
         end do
      end do
      ! ωt = π/2 + kπ <= 30: k = 0 .. 9
      call check(failure, found == 10, method//': expected 10 crossings of x')
   end subroutine crossings_case

   !> A terminal event stops the integration at the crossing, on its far
   !> side; after a restart the next one comes a period later.
   subroutine terminal_stops_at_the_event(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(ringing), target :: system
      type(event_locator) :: locator
      type(solver_settings) :: settings
      type(error_type), allocatable :: error
      real(wp) :: t, y(2)
      integer :: k

      settings%method = 'rk8pd'
      settings%rtol = 1.0e-12_wp
      settings%atol = 1.0e-12_wp
      call locator%init(system, settings, [event_falling, event_either], [.true., .false.], &
         & 1.0e-11_wp, 1.0e-4_wp, error)
      t = 0.0_wp
      y = [1.0_wp, 0.0_wp]
      call locator%restart(t, y, 0.0_wp)
      do k = 1, 2
         do
            call locator%advance(t, 10.0_wp, y, error)
            if (allocated(error)) then
               failure = error%message
               return
            end if
            if (locator%n_hits > 0) then
               if (locator%hits(locator%n_hits)%terminal) exit
            end if
            if (t >= 10.0_wp) exit
         end do
         call check(failure, locator%n_hits > 0, 'no terminal event before t = 10')
         if (allocated(failure)) return
         call check_close(failure, t, (pi / 2 + 2 * (k - 1) * pi) / 3.0_wp, 1.0e-10_wp, 'terminal event time')
         call check(failure, y(1) <= 0.0_wp, 'state not on the far side of the falling crossing')
         call check_close(failure, y(1), 0.0_wp, 1.0e-10_wp, 'x at the event')
         call locator%restart(t, y, 0.0_wp)
      end do
   end subroutine terminal_stops_at_the_event

   !> The located time is the far end of a bracket of the root: at most the
   !> tolerance after the crossing of the integrated path, never before it
   !> (beyond the integrator's error, here 1e-13).
   subroutine time_error_within_tolerance(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(ringing), target :: system
      type(event_locator) :: locator
      type(solver_settings) :: settings
      type(error_type), allocatable :: error
      real(wp) :: t, y(2), tolerance, t_exact, previous
      character(len=40) :: text
      integer :: k

      settings%method = 'rk8pd'
      settings%rtol = 1.0e-13_wp
      settings%atol = 1.0e-13_wp
      t_exact = pi / 6.0_wp
      previous = huge(1.0_wp)
      do k = 2, 12, 2
         tolerance = 10.0_wp**(-k)
         call locator%init(system, settings, [event_falling, event_either], [.true., .false.], &
            & tolerance, 1.0e-3_wp, error)
         t = 0.0_wp
         y = [1.0_wp, 0.0_wp]
         call locator%restart(t, y, 0.0_wp)
         do while (t < 1.0_wp)
            call locator%advance(t, 1.0_wp, y, error)
            if (allocated(error)) then
               failure = error%message
               return
            end if
            if (locator%n_hits > 0) exit
         end do
         write (text, '(a, es8.1)') 'event time at tolerance ', tolerance
         call check(failure, t >= t_exact - 1.0e-12_wp, trim(text)//': before the crossing')
         call check_close(failure, t, t_exact, tolerance + 1.0e-12_wp, trim(text))
         previous = abs(t - t_exact)
      end do
   end subroutine time_error_within_tolerance

   !> v = 0 at t = 0.  Falling-only: v goes negative at once, so the start is
   !> a crossing (at t0 within the tolerance).  Rising-only: no event at the
   !> start; the first is at ωt = π.
   subroutine zero_at_restart(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(ringing), target :: system
      type(event_locator) :: locator
      type(solver_settings) :: settings
      type(error_type), allocatable :: error
      real(wp) :: t, y(2)
      integer :: direction

      settings%method = 'rkf45'
      settings%rtol = 1.0e-10_wp
      settings%atol = 1.0e-10_wp
      do direction = -1, 1, 2
         call locator%init(system, settings, [event_either, direction], [.false., .true.], &
            & 1.0e-10_wp, 1.0e-3_wp, error)
         t = 0.0_wp
         y = [1.0_wp, 0.0_wp]
         call locator%restart(t, y, 0.0_wp)
         do while (t < 2.0_wp)
            call locator%advance(t, 2.0_wp, y, error)
            if (allocated(error)) then
               failure = error%message
               return
            end if
            if (locator%n_hits > 0) then
               if (locator%hits(locator%n_hits)%terminal) exit
            end if
         end do
         if (direction == event_falling) then
            call check_close(failure, t, 0.0_wp, 1.0e-10_wp, 'falling v from zero: event at the start')
         else
            call check_close(failure, t, pi / 3.0_wp, 1.0e-8_wp, 'rising v from zero: first event at ωt = π')
         end if
      end do
   end subroutine zero_at_restart

   !> Locating non-terminal events uses the probe driver only: the main
   !> integration ends in the same state, bit for bit, as when no event
   !> fires (multistep history included).
   subroutine non_terminal_leaves_integration_alone(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(ringing), target :: system
      type(event_locator) :: locator
      type(solver_settings) :: settings
      type(error_type), allocatable :: error
      real(wp) :: t, y(2), y_plain(2)
      integer :: m, pass, hits
      character(len=8), parameter :: methods(2) = [character(len=8) :: 'rk8pd', 'msbdf']

      do m = 1, size(methods)
         settings%method = methods(m)
         settings%rtol = 1.0e-8_wp
         settings%atol = 1.0e-8_wp
         do pass = 1, 2
            system%offset = merge(2.0_wp, 0.0_wp, pass == 1)
            call locator%init(system, settings, [event_either, event_either], [.false., .false.], &
               & 1.0e-10_wp, 1.0e-3_wp, error)
            t = 0.0_wp
            y = [1.0_wp, 0.0_wp]
            call locator%restart(t, y, 0.0_wp)
            hits = 0
            do while (t < 7.0_wp)
               call locator%advance(t, 7.0_wp, y, error)
               if (allocated(error)) then
                  failure = error%message
                  return
               end if
               hits = hits + locator%n_hits
            end do
            if (pass == 1) y_plain = y
         end do
         call check(failure, hits == 13, trim(settings%method)//': expected 13 crossings of x and v in (0, 7]')
         call check(failure, all(y == y_plain), trim(settings%method) &
            & //': locating events changed the integration')
      end do
   end subroutine non_terminal_leaves_integration_alone

   !> x - 0.99 is positive only for |3t - 2πk| < acos(0.99) = 0.14: a bump
   !> 0.094 wide, a third of rk8pd's steps at 1e-6 (about 0.3), 0.01 high
   !> against the Hermite interpolant's error of about 2e-3 at such steps.
   !> Both crossings of every bump are found, at the exact times.
   subroutine dips_within_a_step(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(ringing), target :: system
      type(event_locator) :: locator
      type(solver_settings) :: settings
      type(error_type), allocatable :: error
      real(wp) :: t, y(2), expected(9), half_width
      integer :: i, found, k
      character(len=40) :: text

      half_width = acos(0.99_wp) / 3.0_wp
      expected(1) = half_width
      do k = 1, 4
         expected(2 * k) = 2 * pi * k / 3.0_wp - half_width
         expected(2 * k + 1) = 2 * pi * k / 3.0_wp + half_width
      end do
      system%offset = 0.99_wp
      settings%method = 'rk8pd'
      settings%rtol = 1.0e-6_wp
      settings%atol = 1.0e-6_wp
      call locator%init(system, settings, [event_either, event_either], [.false., .false.], &
         & 1.0e-10_wp, 1.0e-3_wp, error)
      t = 0.0_wp
      y = [1.0_wp, 0.0_wp]
      call locator%restart(t, y, 0.0_wp)
      found = 0
      do while (t < 10.0_wp)
         call locator%advance(t, 10.0_wp, y, error)
         if (allocated(error)) then
            failure = error%message
            return
         end if
         do i = 1, locator%n_hits
            if (locator%hits(i)%which /= 1) cycle
            found = found + 1
            if (found > size(expected)) exit
            write (text, '(a, i0)') 'crossing of x = 0.99, number ', found
            ! State error at rtol 1e-6 (a few 1e-6) over the speed |x'| = 0.42 there.
            call check_close(failure, locator%hits(i)%t, expected(found), 1.0e-5_wp, trim(text))
         end do
      end do
      call check(failure, found == size(expected), 'expected 9 crossings of x = 0.99 in (0, 10]')
      call check(failure, locator%steps_taken() < 100, 'steps too short to test dips within a step')
   end subroutine dips_within_a_step

   subroutine step_budget_reported(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(ringing), target :: system
      type(event_locator) :: locator
      type(solver_settings) :: settings
      type(error_type), allocatable :: error
      real(wp) :: t, y(2)

      settings%method = 'rkf45'
      settings%rtol = 1.0e-10_wp
      settings%atol = 1.0e-10_wp
      settings%max_steps = 100
      call locator%init(system, settings, [event_either, event_either], [.false., .false.], &
         & 1.0e-10_wp, 1.0e-3_wp, error)
      t = 0.0_wp
      y = [1.0_wp, 0.0_wp]
      call locator%restart(t, y, 0.0_wp)
      do while (t < 100.0_wp .and. .not. allocated(error))
         call locator%advance(t, 100.0_wp, y, error)
      end do
      call check(failure, allocated(error), 'no error after 100 steps')
      if (allocated(failure)) return
      call check(failure, index(error%message, 'rkf45') > 0 .and. index(error%message, 'max_steps = 100') > 0 &
         & .and. index(error%message, 't = ') > 0, 'message lacks stepper, budget or time: '//error%message)
      call check(failure, locator%steps_taken() == 101, 'the budget counts steps over advances')
   end subroutine step_budget_reported

   !> A run of 1e9 periods stops after max_wall_time, not after hours.
   subroutine wall_time_reported(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(ringing), target :: system
      type(event_locator) :: locator
      type(solver_settings) :: settings
      type(error_type), allocatable :: error
      real(wp) :: t, y(2), seconds
      integer(i8) :: start, finish, rate

      settings%method = 'rk2'
      settings%rtol = 1.0e-12_wp
      settings%atol = 1.0e-12_wp
      settings%max_steps = huge(1_i8)
      settings%max_wall_time = 0.2_wp
      call system_clock(start, rate)
      call locator%init(system, settings, [event_either, event_either], [.false., .false.], &
         & 1.0e-10_wp, 1.0e-3_wp, error)
      t = 0.0_wp
      y = [1.0_wp, 0.0_wp]
      call locator%restart(t, y, 0.0_wp)
      do while (t < 1.0e9_wp .and. .not. allocated(error))
         call locator%advance(t, 1.0e9_wp, y, error)
      end do
      call system_clock(finish)
      seconds = real(finish - start, wp) / rate
      call check(failure, allocated(error), 'no error from the wall-time guard')
      if (allocated(failure)) return
      call check(failure, index(error%message, 'max_wall_time') > 0 .and. index(error%message, 'rk2') > 0, &
         & 'message lacks max_wall_time or the stepper: '//error%message)
      ! 0.2 s plus one step and the event location of that step.
      call check_close(failure, seconds, 0.2_wp, 2.0_wp, 'seconds until the guard stopped the run')
   end subroutine wall_time_reported

   subroutine h_min_reported(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(ringing), target :: system
      type(event_locator) :: locator
      type(solver_settings) :: settings
      type(error_type), allocatable :: error
      real(wp) :: t, y(2)

      settings%method = 'rkf45'
      settings%rtol = 1.0e-12_wp
      settings%atol = 1.0e-12_wp
      settings%h_min = 0.1_wp
      call locator%init(system, settings, [event_either, event_either], [.false., .false.], &
         & 1.0e-10_wp, 0.1_wp, error)
      t = 0.0_wp
      y = [1.0_wp, 0.0_wp]
      call locator%restart(t, y, 0.0_wp)
      do while (t < 10.0_wp .and. .not. allocated(error))
         call locator%advance(t, 10.0_wp, y, error)
      end do
      call check(failure, allocated(error), 'no error although steps must fall below h_min')
      if (allocated(failure)) return
      call check(failure, index(error%message, 'h_min') > 0, 'message lacks h_min: '//error%message)
   end subroutine h_min_reported

end program test_events
