!> Amplitude spectrum of a uniformly sampled real series with FFTW3's
!> real-to-complex transform: a window (Hann or none), optional Welch
!> averaging over half-overlapping segments, and the highest peak refined by
!> the ratio of the larger neighbour to the peak bin (Jain's method).
!> The bin width 1/(segment length × dt) is reported beside the peak: it is
!> the resolution; the interpolation only places a single tone within it.
module friction_analysis_spectrum
   use, intrinsic :: iso_c_binding, only: c_ptr, c_int, c_double, c_double_complex, c_associated, c_loc, &
      & c_null_ptr
   use friction_kinds, only: wp, pi
   use friction_error, only: error_type, fatal_error, error_input, error_internal
   implicit none
   private

   public :: spectrum_settings, spectrum_result, amplitude_spectrum
   public :: window_hann, window_none

   character(len=*), parameter :: window_hann = 'hann', window_none = 'none'

   !> FFTW_ESTIMATE: plans without trial transforms, so planning leaves the
   !> input alone.  FFTW's planner is not thread-safe; the program calls it
   !> from one thread per rank.
   integer(c_int), parameter :: fftw_estimate = 64

   !> The last plan, kept for the next transform of the same length: a
   !> sweep's points all take one, and planning is dear (prime lengths).  Kept with
   !> the alignments of the arrays it was made for, as FFTW's new-array
   !> execute requires.  Jobs run one at a time (capi/job_lock.c), and the
   !> C API's in-memory computations take no spectrum.
   type(c_ptr), save :: kept_plan = c_null_ptr
   integer, save :: kept_length = 0
   integer(c_int), save :: kept_alignment(2) = -1

   !> What the user chooses.
   type :: spectrum_settings
      character(len=8) :: window = window_hann  !! 'hann' or 'none'
      integer :: segments = 1                   !! Welch segments (50 % overlap); 1: one window
   end type spectrum_settings

   type :: spectrum_result
      real(wp), allocatable :: frequency(:)   !! cycles per unit of the sample spacing's unit
      real(wp), allocatable :: amplitude(:)   !! one-sided amplitude (a sine of amplitude A gives ≈ A)
      real(wp) :: peak_frequency = 0.0_wp     !! interpolated between bins
      real(wp) :: peak_amplitude = 0.0_wp     !! amplitude of the peak bin
      real(wp) :: resolution = 0.0_wp         !! bin width
      integer :: segment_length = 0
   end type spectrum_result

   interface
      function fftw_plan_dft_r2c_1d(n, in, out, flags) result(plan) bind(c, name='fftw_plan_dft_r2c_1d')
         import :: c_ptr, c_int, c_double, c_double_complex
         integer(c_int), value :: n
         real(c_double), intent(inout) :: in(*)
         complex(c_double_complex), intent(inout) :: out(*)
         integer(c_int), value :: flags
         type(c_ptr) :: plan
      end function fftw_plan_dft_r2c_1d

      subroutine fftw_execute_dft_r2c(plan, in, out) bind(c, name='fftw_execute_dft_r2c')
         import :: c_ptr, c_double, c_double_complex
         type(c_ptr), value :: plan
         real(c_double), intent(inout) :: in(*)
         complex(c_double_complex), intent(inout) :: out(*)
      end subroutine fftw_execute_dft_r2c

      subroutine fftw_destroy_plan(plan) bind(c, name='fftw_destroy_plan')
         import :: c_ptr
         type(c_ptr), value :: plan
      end subroutine fftw_destroy_plan

      function fftw_alignment_of(p) result(alignment) bind(c, name='fftw_alignment_of')
         import :: c_ptr, c_int
         type(c_ptr), value :: p
         integer(c_int) :: alignment
      end function fftw_alignment_of
   end interface

contains

   !> The spectrum of signal sampled every dt.  Each segment has its mean
   !> removed before windowing, so the zero bin does not hide the peak.
   subroutine amplitude_spectrum(signal, dt, settings, result, error)
      real(wp), intent(in) :: signal(:)
      real(wp), intent(in) :: dt
      type(spectrum_settings), intent(in) :: settings
      type(spectrum_result), intent(out) :: result
      type(error_type), allocatable, intent(out) :: error
      real(c_double), allocatable, target :: buffer(:)
      complex(c_double_complex), allocatable, target :: transform(:)
      real(wp), allocatable :: window(:), power(:)
      type(c_ptr) :: plan
      integer(c_int) :: alignment(2)
      integer :: n, length, hop, nbins, s, start, k
      real(wp) :: offset

      n = size(signal)
      if (settings%segments < 1) then
         call fatal_error(error, 'spectrum: segments must be >= 1', error_input)
         return
      end if
      if (.not. (dt > 0.0_wp)) then
         call fatal_error(error, 'spectrum: the sample spacing must be > 0', error_input)
         return
      end if
      ! K half-overlapping segments of length L cover (K + 1) L / 2 samples.
      length = (2 * n) / (settings%segments + 1)
      if (settings%segments == 1) length = n
      if (length < 8) then
         call fatal_error(error, 'spectrum: fewer than 8 samples per segment', error_input)
         return
      end if
      hop = max(1, length / 2)
      nbins = length / 2 + 1
      allocate (window(length), power(nbins), buffer(length), transform(nbins))
      select case (trim(settings%window))
      case (window_hann)
         window = [(0.5_wp - 0.5_wp * cos(2.0_wp * pi * real(k, wp) / real(length, wp)), k = 0, length - 1)]
      case (window_none)
         window = 1.0_wp
      case default
         call fatal_error(error, "spectrum: unknown window '"//trim(settings%window) &
            & //"' (hann, none)", error_input)
         return
      end select
      buffer = 0.0_wp
      alignment = [fftw_alignment_of(c_loc(buffer)), fftw_alignment_of(c_loc(transform))]
      if (c_associated(kept_plan) .and. kept_length == length .and. all(kept_alignment == alignment)) then
         plan = kept_plan
      else
         if (c_associated(kept_plan)) call fftw_destroy_plan(kept_plan)
         kept_length = 0
         kept_plan = fftw_plan_dft_r2c_1d(int(length, c_int), buffer, transform, fftw_estimate)
         if (.not. c_associated(kept_plan)) then
            call fatal_error(error, 'spectrum: FFTW could not plan the transform', error_internal)
            return
         end if
         kept_length = length
         kept_alignment = alignment
         plan = kept_plan
      end if
      power = 0.0_wp
      do s = 1, settings%segments
         start = (s - 1) * hop + 1
         buffer = signal(start:start + length - 1)
         buffer = (buffer - sum(buffer) / length) * window
         call fftw_execute_dft_r2c(plan, buffer, transform)
         power = power + abs(transform)**2
      end do
      ! One-sided amplitude: a sine of amplitude A gives A at its bin.
      result%amplitude = 2.0_wp * sqrt(power / settings%segments) / sum(window)
      result%amplitude(1) = result%amplitude(1) / 2.0_wp
      result%frequency = [(real(k, wp) / (length * dt), k = 0, nbins - 1)]
      result%resolution = 1.0_wp / (length * dt)
      result%segment_length = length
      k = maxloc(result%amplitude(2:), 1) + 1
      result%peak_amplitude = result%amplitude(k)
      offset = 0.0_wp
      if (k > 1 .and. k < nbins) offset = peak_offset(result%amplitude(k - 1:k + 1), settings%window)
      result%peak_frequency = (real(k - 1, wp) + offset) * result%resolution
   end subroutine amplitude_spectrum

   !> Offset of a single tone from the centre bin, in bins, from the
   !> amplitudes of the peak bin and its neighbours (Jain's method): the
   !> larger neighbour's ratio r to the peak gives r / (1 + r) for the
   !> rectangular window and (2r - 1) / (1 + r) for Hann, exact for one tone
   !> away from other tones and from zero frequency.
   pure real(wp) function peak_offset(amplitudes, window) result(offset)
      real(wp), intent(in) :: amplitudes(3)   !! bins k - 1, k, k + 1
      character(len=*), intent(in) :: window
      real(wp) :: ratio, direction

      offset = 0.0_wp
      if (.not. (amplitudes(2) > 0.0_wp)) return
      if (amplitudes(3) >= amplitudes(1)) then
         ratio = amplitudes(3) / amplitudes(2)
         direction = 1.0_wp
      else
         ratio = amplitudes(1) / amplitudes(2)
         direction = -1.0_wp
      end if
      if (trim(window) == window_hann) then
         offset = direction * max(0.0_wp, (2.0_wp * ratio - 1.0_wp) / (1.0_wp + ratio))
      else
         offset = direction * ratio / (1.0_wp + ratio)
      end if
   end function peak_offset

end module friction_analysis_spectrum
