!> Random streams (friction_random): one per (seed, line, trip, realization).
!>   - a tuple's stream is the same whatever other streams exist and in
!>     whatever order tuples are drawn; re-initialised, the same again;
!>     copies are independent streams in the same state;
!>   - streams of neighbouring tuples are uncorrelated: each sample
!>     correlation ρ of n pairs is N(0, 1/n) under independence, so
!>     |ρ| sqrt(n) < 4.5 for each pair (a false alarm 7e-6 a pair) and
!>     Σ n ρ² over m pairs is χ²_m (mean m, sd sqrt(2m));
!>   - the variates have the moments of their laws, to 4 standard errors;
!>   - an uninitialised stream gives NaN.
program test_random
   use, intrinsic :: ieee_arithmetic, only: ieee_is_nan
   use friction_kinds, only: wp, i8
   use friction_error, only: error_type
   use friction_random, only: random_stream, stream_hash
   use testing, only: test_suite, check, check_close
   implicit none

   type(test_suite) :: suite

   suite%name = 'random'
   call suite%add('order_independent', order_independent)
   call suite%add('copies', copies)
   call suite%add('tuples_distinct', tuples_distinct)
   call suite%add('streams_uncorrelated', streams_uncorrelated)
   call suite%add('moments', moments)
   call suite%add('uninitialised', uninitialised)
   call suite%run_all()

contains

   !> Six tuples, drawn one whole stream after another, then all at once
   !> round-robin in reverse order: bitwise the same variates.
   subroutine order_independent(failure)
      character(len=:), allocatable, intent(out) :: failure
      integer, parameter :: ntuple = 6, ndraw = 500
      integer(i8), parameter :: seeds(ntuple) = [1_i8, 1_i8, 1_i8, 1_i8, 2_i8, -7_i8]
      integer, parameter :: lines(ntuple) = [0, 1, 0, 0, 0, 3]
      integer, parameter :: trips(ntuple) = [0, 0, 1, 0, 0, 1]
      integer, parameter :: reals(ntuple) = [0, 0, 0, 1, 0, 2]
      real(wp) :: first(ndraw, ntuple), second(ndraw, ntuple), third(ndraw)
      type(random_stream) :: one, streams(ntuple)
      type(error_type), allocatable :: error
      integer :: i, k

      do k = 1, ntuple
         call one%init(seeds(k), lines(k), trips(k), reals(k), error)
         if (allocated(error)) then
            failure = error%message
            return
         end if
         do i = 1, ndraw
            if (mod(i, 50) == 0) then
               first(i, k) = one%uniform()
            else
               first(i, k) = one%gaussian()
            end if
         end do
      end do
      do k = ntuple, 1, -1
         call streams(k)%init(seeds(k), lines(k), trips(k), reals(k), error)
         if (allocated(error)) then
            failure = error%message
            return
         end if
      end do
      do i = 1, ndraw
         do k = ntuple, 1, -1
            if (mod(i, 50) == 0) then
               second(i, k) = streams(k)%uniform()
            else
               second(i, k) = streams(k)%gaussian()
            end if
         end do
      end do
      call check(failure, all(first == second), 'a stream depends on the order tuples are drawn in')
      ! Re-initialised: the same again; drawn in batches: the same again.
      call streams(2)%init(seeds(2), lines(2), trips(2), reals(2), error)
      do i = 1, 49
         third(i) = streams(2)%gaussian()
      end do
      third(50) = streams(2)%uniform()
      call streams(2)%gaussians(third(51:99))
      call check(failure, all(third(1:99) == first(1:99, 2)), 're-initialised or batched, a stream differs')
      do k = 1, ntuple
         call streams(k)%free()
      end do
      call one%free()
   end subroutine order_independent

   !> A copy continues with the original's variates, and drawing from one
   !> does not move the other.
   subroutine copies(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(random_stream) :: a, b
      type(error_type), allocatable :: error
      real(wp) :: x(100), y(100), z(100)
      integer :: i

      call a%init(42_i8, 5, 1, 3, error)
      if (allocated(error)) then
         failure = error%message
         return
      end if
      do i = 1, 37
         x(1) = a%gaussian()
      end do
      b = a
      call check(failure, b%ready(), 'the copy has no generator')
      call b%gaussians(y)
      call a%gaussians(x)
      call check(failure, all(x == y), 'a copy does not continue with the original''s variates')
      call a%gaussians(z)
      call b%gaussians(x)
      call check(failure, all(x == z), 'drawing from the original moved the copy')
      call a%free()
      call check(failure, b%ready(), 'freeing the original freed the copy')
      call b%free()
   end subroutine copies

   !> 2000 tuples on a grid: 2000 different hashes and first variates, and
   !> swapped components give different streams.
   subroutine tuples_distinct(failure)
      character(len=:), allocatable, intent(out) :: failure
      integer(i8) :: hashes(2000)
      real(wp) :: firsts(2000)
      type(random_stream) :: s
      type(error_type), allocatable :: error
      integer :: seed, line, trip, r, k, i

      k = 0
      do seed = 0, 3
         do line = 0, 49
            do trip = 0, 1
               do r = 0, 4
                  k = k + 1
                  hashes(k) = stream_hash(int(seed, i8), line, trip, r)
                  call s%init(int(seed, i8), line, trip, r, error)
                  if (allocated(error)) then
                     failure = error%message
                     return
                  end if
                  firsts(k) = s%gaussian()
               end do
            end do
         end do
      end do
      do i = 1, k - 1
         call check(failure, all(hashes(i + 1:k) /= hashes(i)), 'two tuples hash alike')
         call check(failure, all(firsts(i + 1:k) /= firsts(i)), 'two tuples start alike')
      end do
      call check(failure, stream_hash(0_i8, 1, 2, 0) /= stream_hash(0_i8, 2, 1, 0), &
         & '(line, trip) = (1, 2) and (2, 1) hash alike')
      call check(failure, stream_hash(0_i8, 0, 1, 2) /= stream_hash(0_i8, 0, 2, 1), &
         & '(trip, realization) = (1, 2) and (2, 1) hash alike')
      call s%free()
   end subroutine tuples_distinct

   !> Neighbouring tuples (one component apart, the streams a map uses side
   !> by side): correlations at lags -1, 0, 1 of 20000 Gaussian variates.
   subroutine streams_uncorrelated(failure)
      character(len=:), allocatable, intent(out) :: failure
      integer, parameter :: n = 20000, npairs = 40
      real(wp) :: x(n), y(n), rho, z, chi2, zmax
      type(random_stream) :: a, b
      type(error_type), allocatable :: error
      integer :: p, lag, m
      integer(i8) :: ta(4), tb(4)
      character(len=120) :: text

      chi2 = 0.0_wp
      zmax = 0.0_wp
      m = 0
      do p = 0, npairs - 1
         ta = [int(p / 4, i8), int(p, i8), int(mod(p, 2), i8), int(mod(p, 3), i8)]
         tb = ta
         tb(mod(p, 4) + 1) = tb(mod(p, 4) + 1) + 1   ! one component apart
         call a%init(ta(1), int(ta(2)), int(ta(3)), int(ta(4)), error)
         if (.not. allocated(error)) call b%init(tb(1), int(tb(2)), int(tb(3)), int(tb(4)), error)
         if (allocated(error)) then
            failure = error%message
            return
         end if
         call a%gaussians(x)
         call b%gaussians(y)
         do lag = -1, 1
            rho = correlation(x(max(1, 1 + lag):min(n, n + lag)), y(max(1, 1 - lag):min(n, n - lag)))
            z = rho * sqrt(real(n - abs(lag), wp))
            zmax = max(zmax, abs(z))
            chi2 = chi2 + z**2
            m = m + 1
         end do
      end do
      ! Each stream with itself at lag 1 too.
      rho = correlation(x(1:n - 1), x(2:n))
      zmax = max(zmax, abs(rho) * sqrt(real(n - 1, wp)))
      write (text, '(a, f6.2, a, f8.2, a, i0)') 'largest |rho| sqrt(n) = ', zmax, ', sum n rho^2 = ', chi2, &
         & ' over ', m
      write (*, '(a)') '  '//trim(text)
      call check(failure, zmax < 4.5_wp, 'streams correlated: '//trim(text))
      call check_close(failure, chi2, real(m, wp), 5.0_wp * sqrt(2.0_wp * m), 'sum of n rho^2 over pairs (chi2)')
      call a%free()
      call b%free()
   end subroutine streams_uncorrelated

   pure real(wp) function correlation(x, y)
      real(wp), intent(in) :: x(:), y(:)
      real(wp) :: mx, my

      mx = sum(x) / size(x)
      my = sum(y) / size(y)
      correlation = sum((x - mx) * (y - my)) / sqrt(sum((x - mx)**2) * sum((y - my)**2))
   end function correlation

   !> 1e6 Gaussian variates: mean 0 (se 1/sqrt n), variance 1 (sqrt(2/n)),
   !> fourth moment 3 (sqrt(96/n)), P(|x| > 3) = 0.0026998 (binomial);
   !> 1e5 uniform (mean 1/2, se 1/sqrt(12 n)) and exponential (mean 1,
   !> se 1/sqrt n) variates.
   subroutine moments(failure)
      character(len=:), allocatable, intent(out) :: failure
      integer, parameter :: n = 1000000, nu = 100000
      real(wp), allocatable :: x(:)
      real(wp) :: u(nu), e(nu), tail, p3
      type(random_stream) :: s
      type(error_type), allocatable :: error
      integer :: i

      call s%init(2024_i8, 7, 0, 11, error)
      if (allocated(error)) then
         failure = error%message
         return
      end if
      allocate (x(n))
      call s%gaussians(x)
      do i = 1, nu
         u(i) = s%uniform()
         e(i) = s%exponential()
      end do
      p3 = 2.6997960632601866e-3_wp   ! erfc(3/sqrt 2)
      tail = real(count(abs(x) > 3.0_wp), wp) / n
      write (*, '(a, 4es11.3)') '  mean, variance - 1, fourth moment - 3, tail - p: ', sum(x) / n, &
         & sum(x**2) / n - 1, sum(x**4) / n - 3, tail - p3
      call check_close(failure, sum(x) / n, 0.0_wp, 4.0_wp / sqrt(real(n, wp)), 'Gaussian mean')
      call check_close(failure, sum(x**2) / n, 1.0_wp, 4.0_wp * sqrt(2.0_wp / n), 'Gaussian variance')
      call check_close(failure, sum(x**4) / n, 3.0_wp, 4.0_wp * sqrt(96.0_wp / n), 'Gaussian fourth moment')
      call check_close(failure, tail, p3, 4.0_wp * sqrt(p3 * (1 - p3) / n), 'Gaussian tail beyond 3 sigma')
      call check(failure, all(u > 0.0_wp .and. u < 1.0_wp), 'uniform variate outside (0, 1)')
      call check_close(failure, sum(u) / nu, 0.5_wp, 4.0_wp / sqrt(12.0_wp * nu), 'uniform mean')
      call check_close(failure, sum(e) / nu, 1.0_wp, 4.0_wp / sqrt(real(nu, wp)), 'exponential mean')
      call s%free()
   end subroutine moments

   subroutine uninitialised(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(random_stream) :: s
      type(error_type), allocatable :: error

      call check(failure, .not. s%ready(), 'a new stream is ready')
      call check(failure, ieee_is_nan(s%gaussian()), 'an uninitialised stream gives a number')
      call s%init(1_i8, 0, 0, 0, error)
      call check(failure, .not. allocated(error) .and. s%ready(), 'init failed')
      call check(failure, .not. ieee_is_nan(s%gaussian()), 'an initialised stream gives NaN')
      call s%free()
      call check(failure, ieee_is_nan(s%uniform()), 'a freed stream gives a number')
   end subroutine uninitialised

end program test_random
