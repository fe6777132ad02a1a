!> Poincaré maps of a sampled trajectory: stroboscopic (the state at
!> t_start + k period, interpolated between samples) and a true section (the
!> states where a chosen variable crosses a level upwards, located between
!> samples), and a located section of a flow: the crossings of one event
!> function of an `event_system`, found by the event locator (non-terminal,
!> so the integration is the same as without them) to a time tolerance.
!> Interpolation is linear: its error is of order (dt ω)² of the amplitude.
module friction_analysis_poincare
   use friction_kinds, only: wp
   use friction_error, only: error_type, fatal_error, error_input
   use friction_ode_solver, only: solver_settings
   use friction_ode_events, only: event_system, event_locator, event_rising
   implicit none
   private

   public :: stroboscopic_map, upward_section, located_section

contains

   !> states(:, i) at times t(i) (increasing, uniform or not); points(:, k)
   !> at t_start + (k - 1) period within [t_start, t_end] and the trajectory.
   pure subroutine stroboscopic_map(t, states, t_start, t_end, period, times, points, error)
      real(wp), intent(in) :: t(:), states(:, :)
      real(wp), intent(in) :: t_start, t_end, period
      real(wp), allocatable, intent(out) :: times(:), points(:, :)
      type(error_type), allocatable, intent(out) :: error
      integer :: n, k, i, count
      real(wp) :: s, lo, hi, w

      if (.not. (period > 0.0_wp)) then
         call fatal_error(error, 'stroboscopic map: the period must be > 0', error_input)
         return
      end if
      n = size(t)
      lo = max(t_start, t(1))
      hi = min(t_end, t(n))
      count = 0
      if (hi >= lo) count = int((hi - lo) / period) + 1
      allocate (times(count), points(size(states, 1), count))
      i = 1
      do k = 1, count
         s = lo + (k - 1) * period
         do while (i < n - 1 .and. t(i + 1) < s)
            i = i + 1
         end do
         w = 0.0_wp
         if (n > 1) w = min(1.0_wp, max(0.0_wp, (s - t(i)) / (t(i + 1) - t(i))))
         times(k) = s
         if (n > 1) then
            points(:, k) = (1.0_wp - w) * states(:, i) + w * states(:, i + 1)
         else
            points(:, k) = states(:, 1)
         end if
      end do
   end subroutine stroboscopic_map

   !> States where states(variable, :) crosses level upwards within
   !> [t_start, t_end], linearly interpolated between samples.
   pure subroutine upward_section(t, states, variable, level, t_start, t_end, times, points)
      real(wp), intent(in) :: t(:), states(:, :)
      integer, intent(in) :: variable
      real(wp), intent(in) :: level, t_start, t_end
      real(wp), allocatable, intent(out) :: times(:), points(:, :)
      integer :: i, count
      real(wp) :: a, b, w
      real(wp), allocatable :: tt(:), pp(:, :)

      allocate (tt(size(t)), pp(size(states, 1), size(t)))
      count = 0
      do i = 1, size(t) - 1
         if (t(i) < t_start .or. t(i + 1) > t_end) cycle
         a = states(variable, i) - level
         b = states(variable, i + 1) - level
         if (a < 0.0_wp .and. b >= 0.0_wp) then
            w = a / (a - b)
            count = count + 1
            tt(count) = t(i) + w * (t(i + 1) - t(i))
            pp(:, count) = (1.0_wp - w) * states(:, i) + w * states(:, i + 1)
         end if
      end do
      times = tt(1:count)
      points = pp(:, 1:count)
   end subroutine upward_section

   !> Upward crossings of event function `which` of system along the
   !> trajectory from (t0, y0) to t1, located to time_tolerance; every
   !> event function is watched upward and the others are ignored.
   subroutine located_section(system, settings, t0, y0, t1, which, time_tolerance, times, points, error)
      class(event_system), target, intent(in) :: system
      type(solver_settings), intent(in) :: settings
      real(wp), intent(in) :: t0, y0(:), t1, time_tolerance
      integer, intent(in) :: which
      real(wp), allocatable, intent(out) :: times(:), points(:, :)
      type(error_type), allocatable, intent(out) :: error
      type(event_locator) :: locator
      real(wp) :: t, y(size(y0))
      real(wp), allocatable :: tt(:), pp(:, :)
      integer :: m, count, i, n

      m = system%event_count()
      n = size(y0)
      if (which < 1 .or. which > m) then
         call fatal_error(error, 'located section: no such event function', error_input)
         return
      end if
      call locator%init(system, settings, [(event_rising, i = 1, m)], [(.false., i = 1, m)], &
         & time_tolerance, 1.0e-3_wp, error)
      if (allocated(error)) return
      t = t0
      y = y0
      call locator%restart(t, y, 0.0_wp)
      allocate (tt(64), pp(n, 64))
      count = 0
      do while (t < t1)
         call locator%advance(t, t1, y, error)
         if (allocated(error)) return
         do i = 1, locator%n_hits
            if (locator%hits(i)%which /= which) cycle
            if (count == size(tt)) then
               tt = [tt, tt]
               pp = reshape([pp, pp], [n, 2 * count])
            end if
            count = count + 1
            tt(count) = locator%hits(i)%t
            pp(:, count) = locator%hits(i)%y(1:n)
         end do
      end do
      times = tt(1:count)
      points = pp(:, 1:count)
   end subroutine located_section

end module friction_analysis_poincare
