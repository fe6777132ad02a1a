!> The chaos diagnostics against known answers: Lorenz and a periodic
!> orbit from the equations (Benettin) and from the series (Rosenstein),
!> the logistic map, tones in a spectrum, maps of a periodic orbit.
program test_analysis
   use friction_kinds, only: wp, pi
   use friction_error, only: error_type
   use friction_ode_system, only: ode_system
   use friction_ode_solver, only: ode_solver, solver_settings
   use friction_analysis_spectrum, only: spectrum_settings, spectrum_result, amplitude_spectrum, window_none
   use friction_analysis_lyapunov_series, only: rosenstein_settings, rosenstein_result, rosenstein_exponent
   use friction_analysis_lyapunov_flow, only: benettin_settings, benettin_accumulator, benettin_exponent
   use friction_analysis_poincare, only: stroboscopic_map, upward_section, located_section
   use test_systems, only: lorenz, oscillator
   use testing, only: test_suite, check, check_close
   implicit none

   type(test_suite) :: suite
   real(wp), parameter :: lorenz_exponent = 0.906_wp

   suite%name = 'analysis'
   call suite%add('lorenz_from_equations', lorenz_from_equations)
   call suite%add('lorenz_from_series', lorenz_from_series)
   call suite%add('periodic_from_equations', periodic_from_equations)
   call suite%add('periodic_from_series', periodic_from_series)
   call suite%add('logistic_from_series', logistic_from_series)
   call suite%add('tones_within_resolution', tones_within_resolution)
   call suite%add('tone_interpolated_in_tenth_bin', tone_interpolated_in_tenth_bin)
   call suite%add('welch_keeps_the_peak', welch_keeps_the_peak)
   call suite%add('strobe_of_periodic_orbit_is_a_point', strobe_of_periodic_orbit_is_a_point)
   call suite%add('section_of_periodic_orbit_is_a_point', section_of_periodic_orbit_is_a_point)
   call suite%add('located_section_of_periodic_orbit_is_a_point', located_section_of_periodic_orbit_is_a_point)
   call suite%add('bad_settings_are_errors', bad_settings_are_errors)
   call suite%run_all()

contains

   !> Samples every dt of a system's trajectory from y0 after a transient.
   subroutine sample(system, y0, transient, dt, n, t, states, error)
      class(ode_system), target, intent(in) :: system
      real(wp), intent(in) :: y0(:), transient, dt
      integer, intent(in) :: n
      real(wp), allocatable, intent(out) :: t(:), states(:, :)
      type(error_type), allocatable, intent(out) :: error
      type(ode_solver) :: solver
      type(solver_settings) :: settings
      real(wp) :: time, y(size(y0))
      integer :: i

      settings%method = 'rk8pd'
      settings%rtol = 1.0e-10_wp
      settings%atol = 1.0e-10_wp
      call solver%init(system, settings, 1.0e-3_wp, error)
      if (allocated(error)) return
      y = y0
      time = 0.0_wp
      call solver%advance(time, transient, y, error)
      if (allocated(error)) return
      allocate (t(n), states(size(y0), n))
      time = 0.0_wp
      do i = 1, n
         if (i > 1) call solver%advance(time, (i - 1) * dt, y, error)
         if (allocated(error)) return
         t(i) = (i - 1) * dt
         states(:, i) = y
      end do
      call solver%destroy()
   end subroutine sample

   subroutine lorenz_from_equations(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(lorenz), target :: system
      type(solver_settings) :: solver
      type(benettin_settings) :: settings
      type(benettin_accumulator) :: result
      type(error_type), allocatable :: error

      solver%method = 'rk8pd'
      solver%rtol = 1.0e-10_wp
      solver%atol = 1.0e-10_wp
      settings%transient = 50.0_wp
      settings%duration = 400.0_wp
      settings%renormalise = 0.5_wp
      settings%d0 = 1.0e-8_wp
      call benettin_exponent(system, solver, [1.0_wp, 1.0_wp, 1.0_wp], 0.0_wp, settings, result, error)
      if (allocated(error)) then
         failure = error%message
         return
      end if
      call check_close(failure, result%current(), lorenz_exponent, 0.05_wp * lorenz_exponent, &
         & 'Lorenz exponent (Benettin)')
      call check(failure, result%n == 800, 'one running estimate per renormalisation')
   end subroutine lorenz_from_equations

   !> x sampled every 0.02 over 200 time units; embedding dimension 5, delay
   !> 0.1 (a tenth of the mean orbit period), Theiler window one orbit; the
   !> fit over τ in [0.5, 2] skips the first rise, where neighbours turn onto
   !> the unstable direction, and stops before the curve saturates.
   subroutine lorenz_from_series(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(lorenz), target :: system
      type(rosenstein_settings) :: settings
      type(rosenstein_result) :: result
      type(error_type), allocatable :: error
      real(wp), allocatable :: t(:), states(:, :)

      call sample(system, [1.0_wp, 1.0_wp, 1.0_wp], 50.0_wp, 0.02_wp, 10000, t, states, error)
      if (allocated(error)) then
         failure = error%message
         return
      end if
      settings = rosenstein_settings(dimension=5, delay=5, theiler=50, horizon=150, fit_start=25, fit_end=100)
      call rosenstein_exponent(states(1, :), 0.02_wp, settings, result, error)
      if (allocated(error)) then
         failure = error%message
         return
      end if
      call check_close(failure, result%exponent, lorenz_exponent, 0.15_wp * lorenz_exponent, &
         & 'Lorenz exponent (Rosenstein)')
   end subroutine lorenz_from_series

   !> The oscillator is isochronous: nearby orbits neither separate nor
   !> close in, so the estimate is 0 up to the integration error; 1e-3 is
   !> three orders below the Lorenz value.
   subroutine periodic_from_equations(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(oscillator), target :: system
      type(solver_settings) :: solver
      type(benettin_settings) :: settings
      type(benettin_accumulator) :: result
      type(error_type), allocatable :: error

      solver%method = 'rk8pd'
      solver%rtol = 1.0e-10_wp
      solver%atol = 1.0e-10_wp
      settings = benettin_settings(transient=10.0_wp, duration=300.0_wp, renormalise=1.0_wp, d0=1.0e-8_wp)
      call benettin_exponent(system, solver, [1.0_wp, 0.0_wp], 0.0_wp, settings, result, error)
      if (allocated(error)) then
         failure = error%message
         return
      end if
      call check_close(failure, result%current(), 0.0_wp, 1.0e-3_wp, 'oscillator exponent (Benettin)')
   end subroutine periodic_from_equations

   !> On a periodic orbit the nearest neighbour is the same phase one period
   !> away and the divergence curve stays flat: the slope is bounded by the
   !> interpolation-free sampling jitter; 0.05 is a twentieth of Lorenz's.
   subroutine periodic_from_series(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(rosenstein_settings) :: settings
      type(rosenstein_result) :: result
      type(error_type), allocatable :: error
      real(wp), allocatable :: series(:)
      integer :: i
      real(wp), parameter :: dt = 0.05_wp

      series = [(cos(2.0_wp * pi * 0.1_wp * sqrt(2.0_wp) * i * dt), i = 0, 3999)]
      settings = rosenstein_settings(dimension=3, delay=10, theiler=100, horizon=200, fit_start=0, fit_end=100)
      call rosenstein_exponent(series, dt, settings, result, error)
      if (allocated(error)) then
         failure = error%message
         return
      end if
      call check_close(failure, result%exponent, 0.0_wp, 0.05_wp, 'periodic exponent (Rosenstein)')
   end subroutine periodic_from_series

   subroutine logistic_from_series(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(rosenstein_settings) :: settings
      type(rosenstein_result) :: result
      type(error_type), allocatable :: error
      real(wp) :: series(4000)
      integer :: i

      series(1) = 0.3_wp
      do i = 2, size(series)
         series(i) = 4.0_wp * series(i - 1) * (1.0_wp - series(i - 1))
      end do
      settings = rosenstein_settings(dimension=1, delay=1, theiler=0, horizon=10, fit_start=0, fit_end=6)
      call rosenstein_exponent(series, 1.0_wp, settings, result, error)
      if (allocated(error)) then
         failure = error%message
         return
      end if
      call check_close(failure, result%exponent, log(2.0_wp), 0.1_wp * log(2.0_wp), &
         & 'logistic map exponent (Rosenstein)')
   end subroutine logistic_from_series

   !> Three well-separated tones: each a local maximum within one bin.
   subroutine tones_within_resolution(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(spectrum_settings) :: settings
      type(spectrum_result) :: result
      type(error_type), allocatable :: error
      real(wp), parameter :: dt = 0.1_wp, f(3) = [0.1234_wp, 0.7321_wp, 1.9_wp], a(3) = [3.0_wp, 1.0_wp, 0.5_wp]
      real(wp) :: signal(9000)
      integer :: i, j, k

      do i = 1, size(signal)
         signal(i) = sum(a * sin(2.0_wp * pi * f * (i - 1) * dt + [0.3_wp, 1.1_wp, 2.0_wp]))
      end do
      call amplitude_spectrum(signal, dt, settings, result, error)
      if (allocated(error)) then
         failure = error%message
         return
      end if
      call check_close(failure, result%peak_frequency, f(1), result%resolution, 'highest tone')
      do j = 2, 3
         k = minloc(abs(result%frequency - f(j)), 1)
         i = maxloc(result%amplitude(k - 2:k + 2), 1) + k - 3
         call check_close(failure, result%frequency(i), f(j), result%resolution, 'tone frequency')
         call check_close(failure, result%amplitude(i), a(j), 0.5_wp * a(j), 'tone amplitude')
      end do
      call check_close(failure, result%resolution, 1.0_wp / (size(signal) * dt), 1.0e-12_wp, 'bin width')
   end subroutine tones_within_resolution

   !> A tone at many offsets within a bin: the interpolated peak within a
   !> tenth of a bin, with the Hann window and with none.
   subroutine tone_interpolated_in_tenth_bin(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(spectrum_settings) :: settings
      type(spectrum_result) :: result
      type(error_type), allocatable :: error
      real(wp), parameter :: dt = 1.0_wp
      real(wp) :: signal(1000), f
      integer :: i, j, w

      do w = 1, 2
         if (w == 2) settings%window = window_none
         do j = 0, 10
            f = (100.0_wp + j / 10.0_wp) / (size(signal) * dt)
            signal = [(sin(2.0_wp * pi * f * (i - 1) * dt) + 0.3_wp * sin(2.0_wp * pi * 0.37_wp * i), &
               & i = 1, size(signal))]
            call amplitude_spectrum(signal, dt, settings, result, error)
            if (allocated(error)) then
               failure = error%message
               return
            end if
            call check_close(failure, result%peak_frequency, f, 0.1_wp * result%resolution, &
               & 'interpolated peak ('//trim(settings%window)//')')
         end do
      end do
   end subroutine tone_interpolated_in_tenth_bin

   subroutine welch_keeps_the_peak(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(spectrum_settings) :: settings
      type(spectrum_result) :: result
      type(error_type), allocatable :: error
      real(wp) :: signal(8000)
      integer :: i

      signal = [(2.0_wp * cos(2.0_wp * pi * 0.05_wp * i) + 0.1_wp * sin(0.77_wp * i**2), i = 1, size(signal))]
      settings%segments = 7
      call amplitude_spectrum(signal, 1.0_wp, settings, result, error)
      if (allocated(error)) then
         failure = error%message
         return
      end if
      call check(failure, result%segment_length == 2000, 'seven half-overlapping segments of 2000')
      call check_close(failure, result%peak_frequency, 0.05_wp, 0.1_wp * result%resolution, 'Welch peak')
      call check_close(failure, result%peak_amplitude, 2.0_wp, 0.3_wp, 'Welch amplitude')
   end subroutine welch_keeps_the_peak

   !> Strobing at the orbit's own period: every point the same, up to the
   !> integration and interpolation error (dt ω)² / 8 of the amplitude.
   subroutine strobe_of_periodic_orbit_is_a_point(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(oscillator), target :: system
      type(error_type), allocatable :: error
      real(wp), allocatable :: t(:), states(:, :), times(:), points(:, :)
      integer :: k

      system%omega = 1.3_wp
      call sample(system, [1.0_wp, 0.0_wp], 0.0_wp, 0.01_wp, 20000, t, states, error)
      if (.not. allocated(error)) &
         & call stroboscopic_map(t, states, 3.0_wp, 200.0_wp, 2.0_wp * pi / system%omega, times, points, error)
      if (allocated(error)) then
         failure = error%message
         return
      end if
      call check(failure, size(times) == 41, 'forty-one strobe points in [3, 200]')
      do k = 1, 2
         call check_close(failure, maxval(points(k, :)) - minval(points(k, :)), 0.0_wp, 2.0e-4_wp, &
            & 'spread of the stroboscopic map')
      end do
      call stroboscopic_map(t, states, 3.0_wp, 200.0_wp, 1.0_wp, times, points, error)
      call check(failure, maxval(points(1, :)) - minval(points(1, :)) > 1.0_wp, &
         & 'strobing at another period smears the orbit')
   end subroutine strobe_of_periodic_orbit_is_a_point

   !> Upward crossings of x' = 0 (x at its minimum): one point (-1, 0).
   subroutine section_of_periodic_orbit_is_a_point(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(oscillator), target :: system
      type(error_type), allocatable :: error
      real(wp), allocatable :: t(:), states(:, :), times(:), points(:, :)
      integer :: k

      system%omega = 1.3_wp
      call sample(system, [1.0_wp, 0.0_wp], 0.0_wp, 0.01_wp, 20000, t, states, error)
      if (allocated(error)) then
         failure = error%message
         return
      end if
      call upward_section(t, states, 2, 0.0_wp, 0.0_wp, 200.0_wp, times, points)
      call check(failure, size(times) == 41, 'one crossing per period')
      call check_close(failure, maxval(points(1, :)), -1.0_wp, 1.0e-4_wp, 'section point x')
      call check_close(failure, minval(points(1, :)), -1.0_wp, 1.0e-4_wp, 'section point x')
      do k = 2, size(times)
         call check_close(failure, times(k) - times(k - 1), 2.0_wp * pi / system%omega, 1.0e-3_wp, &
            & 'return time')
      end do
   end subroutine section_of_periodic_orbit_is_a_point

   !> The same section located by the event machinery: the point (-1, 0)
   !> to the integration tolerance, crossings at ωt = π + 2πk to the time
   !> tolerance plus the state error over the crossing speed ω².
   subroutine located_section_of_periodic_orbit_is_a_point(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(oscillator), target :: system
      type(solver_settings) :: settings
      type(error_type), allocatable :: error
      real(wp), allocatable :: times(:), points(:, :)
      integer :: k

      system%omega = 1.3_wp
      settings%method = 'rk8pd'
      settings%rtol = 1.0e-10_wp
      settings%atol = 1.0e-10_wp
      ! 83 crossings: past the first storage block of 64.
      call located_section(system, settings, 0.0_wp, [1.0_wp, 0.0_wp], 400.0_wp, 1, 1.0e-10_wp, &
         & times, points, error)
      if (allocated(error)) then
         failure = error%message
         return
      end if
      call check(failure, size(times) == 83, 'one crossing per period')
      do k = 1, size(times)
         call check_close(failure, points(1, k), -1.0_wp, 1.0e-8_wp, 'located section point x')
         call check_close(failure, times(k), (2 * k - 1) * pi / system%omega, 1.0e-8_wp, 'crossing time')
      end do
   end subroutine located_section_of_periodic_orbit_is_a_point

   subroutine bad_settings_are_errors(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(spectrum_settings) :: settings
      type(spectrum_result) :: result
      type(rosenstein_result) :: lyap
      type(error_type), allocatable :: error
      real(wp) :: signal(100)

      signal = 1.0_wp
      settings%window = 'kaiser'
      call amplitude_spectrum(signal, 1.0_wp, settings, result, error)
      call check(failure, allocated(error), 'unknown window is an error')
      call rosenstein_exponent(signal, 1.0_wp, rosenstein_settings(horizon=200), lyap, error)
      call check(failure, allocated(error), 'a series shorter than the horizon is an error')
   end subroutine bad_settings_are_errors

end program test_analysis
