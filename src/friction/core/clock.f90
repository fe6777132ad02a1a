!> Wall-clock time for the record of a run.
module friction_clock
   use, intrinsic :: iso_c_binding, only: c_char, c_int, c_size_t, c_null_char
   use, intrinsic :: iso_fortran_env, only: int64, real64
   implicit none
   private

   public :: utc_now, wall_seconds

   interface
      function c_utc_now(buf, len) bind(c, name='friction_utc_now') result(stat)
         import :: c_char, c_int, c_size_t
         character(kind=c_char), intent(out) :: buf(*)
         integer(c_size_t), value :: len
         integer(c_int) :: stat
      end function c_utc_now
   end interface

contains

   !> Now as ISO 8601 UTC, e.g. 2026-11-23T11:30:00Z ('unknown' if the clock fails).
   function utc_now() result(text)
      character(len=:), allocatable :: text
      character(kind=c_char) :: buffer(32)
      integer :: n

      text = 'unknown'
      if (c_utc_now(buffer, size(buffer, kind=c_size_t)) /= 0) return
      n = findloc(buffer, c_null_char, dim=1) - 1
      if (n < 1) return
      text = transfer(buffer(1:n), repeat(' ', n))
   end function utc_now

   !> Seconds on a monotonic wall clock from an arbitrary origin, for
   !> durations (a run's wall_time, progress): without MPI, so a serial run
   !> does not need MPI_Wtime.
   function wall_seconds() result(seconds)
      real(real64) :: seconds
      integer(int64) :: count, rate

      call system_clock(count, rate)
      seconds = real(count, real64) / real(max(rate, 1_int64), real64)
   end function wall_seconds

end module friction_clock
