!> The friction loop's forces that experiments report besides the friction
!> (docs/physics.md, The friction loop's mean |F| and peak force): the
!> mean of |F| over the loop, and the mean of its peaks, the force at the
!> top of each stick-slip sawtooth before the slip, both from the sampled
!> force along the scan.
module friction_afm_loop
   use friction_kinds, only: wp
   implicit none
   private

   public :: loop_abs_sum, loop_peaks, loop_forces

   !> A peak is where a fall of the force begins that drops by more than
   !> this share of the trip's range (max - min of its samples) before the
   !> force rises again: a slip, not the wiggle of a thermal mean.
   real(wp), parameter :: slip_fall = 0.25_wp

contains

   !> The sum of |F| over a trip's samples, nN.
   pure real(wp) function loop_abs_sum(force) result(total)
      real(wp), intent(in) :: force(:)

      total = sum(abs(force))
   end function loop_abs_sum

   !> The peaks of one trip, its force along the scan `force` (nN, samples in
   !> the order of the support's position along the line) met in the order
   !> of the support's motion (`forward`: the trace; else the retrace, whose
   !> force against the motion is -force): their sum (nN, as a force
   !> resisting the motion) and number; without a slip, the trip's largest
   !> force against the motion, once.
   pure subroutine loop_peaks(force, forward, total, count)
      real(wp), intent(in) :: force(:)
      logical, intent(in) :: forward
      real(wp), intent(out) :: total
      integer, intent(out) :: count
      real(wp), allocatable :: f(:)
      real(wp) :: least
      integer :: i, j, n

      total = 0.0_wp
      count = 0
      n = size(force)
      if (n < 1) return
      if (forward) then
         f = force
      else
         f = -force(n:1:-1)
      end if
      least = slip_fall * (maxval(f) - minval(f))
      i = 1
      do while (i < n)
         if (.not. (f(i + 1) < f(i))) then
            i = i + 1
            cycle
         end if
         ! A fall from i: down to j, where the force stops falling.
         j = i + 1
         do while (j < n)
            if (.not. (f(j + 1) < f(j))) exit
            j = j + 1
         end do
         if (f(i) - f(j) > least) then
            total = total + f(i)
            count = count + 1
         end if
         i = j
      end do
      ! A trip without a slip slides smoothly: its top is its peak.
      if (count == 0) then
         total = maxval(f)
         count = 1
      end if
   end subroutine loop_peaks

   !> Per line of a map (trace(:, j) and retrace(:, j): line j's force along
   !> the scan, nN): the mean |F| over both trips' samples, and the mean of
   !> both trips' peaks.
   pure subroutine loop_forces(trace, retrace, mean_abs, peak)
      real(wp), intent(in) :: trace(:, :), retrace(:, :)
      real(wp), intent(out) :: mean_abs(size(trace, 2)), peak(size(trace, 2))
      real(wp) :: sum_trace, sum_retrace
      integer :: j, n_trace, n_retrace

      do j = 1, size(trace, 2)
         mean_abs(j) = (loop_abs_sum(trace(:, j)) + loop_abs_sum(retrace(:, j))) / real(2 * size(trace, 1), wp)
         call loop_peaks(trace(:, j), .true., sum_trace, n_trace)
         call loop_peaks(retrace(:, j), .false., sum_retrace, n_retrace)
         peak(j) = (sum_trace + sum_retrace) / real(n_trace + n_retrace, wp)
      end do
   end subroutine loop_forces

end module friction_afm_loop
