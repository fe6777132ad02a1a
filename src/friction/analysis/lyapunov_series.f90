!> Maximum Lyapunov exponent from a scalar time series (Rosenstein, Collins
!> and De Luca 1993): delay embedding, for each point its nearest neighbour
!> outside a Theiler window, the mean log distance of the pairs k samples
!> later (the divergence curve), and its least-squares slope over a fit
!> range divided by the sample spacing.  The neighbour search is O(M²) in
!> the M embedded points: keep M to a few thousand (stride the series).
!> OpenTSTool's largelyap reports log2 per sample: multiply by ln 2 / dt to
!> compare with the slope here, which is natural log per unit time.
module friction_analysis_lyapunov_series
   use friction_kinds, only: wp
   use friction_error, only: error_type, fatal_error, error_input
   implicit none
   private

   public :: rosenstein_settings, rosenstein_result, rosenstein_exponent

   type :: rosenstein_settings
      integer :: dimension = 4      !! embedding dimension m
      integer :: delay = 1          !! embedding delay, in samples
      integer :: theiler = 10       !! neighbours closer in time than this many samples are excluded
      integer :: horizon = 40       !! divergence curve length, in samples
      integer :: fit_start = 0      !! fit range of the divergence curve, in samples
      integer :: fit_end = 10
   end type rosenstein_settings

   type :: rosenstein_result
      real(wp) :: exponent = 0.0_wp        !! natural log per unit time
      real(wp), allocatable :: time(:)     !! k dt, k = 0 .. horizon
      real(wp), allocatable :: divergence(:)  !! mean ln distance after k samples
      integer :: points = 0                !! embedded points used as references
   end type rosenstein_result

contains

   !> The exponent of series sampled every dt.
   pure subroutine rosenstein_exponent(series, dt, settings, result, error)
      real(wp), intent(in) :: series(:)
      real(wp), intent(in) :: dt
      type(rosenstein_settings), intent(in) :: settings
      type(rosenstein_result), intent(out) :: result
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: embedded(:, :), total(:)
      integer, allocatable :: counts(:), neighbour(:)
      integer :: m, last, i, j, k, h
      real(wp) :: best, d

      associate (s => settings)
         if (s%dimension < 1 .or. s%delay < 1 .or. s%theiler < 0 .or. s%horizon < 1 &
            & .or. s%fit_start < 0 .or. s%fit_end <= s%fit_start .or. s%fit_end > s%horizon) then
            call fatal_error(error, 'Rosenstein: need dimension >= 1, delay >= 1, theiler >= 0, ' &
               & //'0 <= fit_start < fit_end <= horizon', error_input)
            return
         end if
         h = s%horizon
         m = size(series) - (s%dimension - 1) * s%delay
         last = m - h   ! references and neighbours must have h samples ahead
         if (last < 2 * (s%theiler + 1)) then
            call fatal_error(error, 'Rosenstein: the series is too short for these settings', error_input)
            return
         end if
         allocate (embedded(s%dimension, m))
         do k = 1, s%dimension
            embedded(k, :) = series(1 + (k - 1) * s%delay:m + (k - 1) * s%delay)
         end do
         allocate (neighbour(last))
         neighbour = 0
         do i = 1, last
            best = huge(best)
            do j = 1, last
               if (abs(i - j) <= s%theiler) cycle
               d = sum((embedded(:, i) - embedded(:, j))**2)
               if (d > 0.0_wp .and. d < best) then
                  best = d
                  neighbour(i) = j
               end if
            end do
         end do
         allocate (total(0:h), counts(0:h))
         total = 0.0_wp
         counts = 0
         do i = 1, last
            j = neighbour(i)
            if (j == 0) cycle
            do k = 0, h
               d = sqrt(sum((embedded(:, i + k) - embedded(:, j + k))**2))
               if (d > 0.0_wp) then
                  total(k) = total(k) + log(d)
                  counts(k) = counts(k) + 1
               end if
            end do
         end do
         result%points = last
         result%time = [(k * dt, k = 0, h)]
         result%divergence = total / max(counts, 1)
         ! Both arrays start at index 1 for k = 0.
         result%exponent = slope(result%time(s%fit_start + 1:s%fit_end + 1), &
            & result%divergence(s%fit_start + 1:s%fit_end + 1))
      end associate
   end subroutine rosenstein_exponent

   !> Least-squares slope of y against x.
   pure real(wp) function slope(x, y)
      real(wp), intent(in) :: x(:), y(:)
      real(wp) :: xm, ym

      xm = sum(x) / size(x)
      ym = sum(y) / size(y)
      slope = sum((x - xm) * (y - ym)) / sum((x - xm)**2)
   end function slope

end module friction_analysis_lyapunov_series
