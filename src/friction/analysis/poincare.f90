!> Poincaré maps of a sampled trajectory: stroboscopic (the state at
!> t_start + k period, interpolated between samples) and a true section (the
!> states where a chosen variable crosses a level upwards, located between
!> samples).  Sections located exactly by the event machinery (the brake's
!> stick-to-slip events) come from the scene's event table instead.
!> Interpolation is linear: its error is of order (dt ω)² of the amplitude.
module friction_analysis_poincare
   use friction_kinds, only: wp
   use friction_error, only: error_type, fatal_error, error_input
   implicit none
   private

   public :: stroboscopic_map, upward_section

contains

   !> states(:, i) at times t(i) (increasing, uniform or not); points(:, k)
   !> at t_start + (k - 1) period within [t_start, t_end] and the trajectory.
   subroutine stroboscopic_map(t, states, t_start, t_end, period, times, points, error)
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

end module friction_analysis_poincare
