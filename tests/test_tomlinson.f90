!> Prandtl–Tomlinson exact results (docs/physics.md, Prandtl–Tomlinson) on a 1D cut of the NaF
!> potential: along y = 0 the y-gradient vanishes, so the tip moves on the
!> line V = -U0 cos(2πx/a) with U0 = V0.  At very low velocity the
!> integrated motion must approach the quasi-static results:
!>   - the largest lateral force is F* = 2πU0/a, reached while sticking at
!>     the inflection point of V;
!>   - the tip slips where cos(2πx/a) = -1/η, at the force F* √(1 - 1/η²);
!>   - slips repeat with the lattice period a;
!>   - the force rises at the start of a stick with slope k η/(1 + η);
!>   - for η < 1 there is no slip and no hysteresis (trace = retrace).
!> Note: the issue text says the maximum force approaches F* √(1 - 1/η²);
!> that is the force at the slip, and the maximum over a cycle is F*.
program test_tomlinson
   use friction_kinds, only: wp, pi, ev_per_angstrom_to_nn, n_per_m_to_internal
   use friction_error, only: error_type
   use friction_afm_config, only: afm_config, new_potential
   use friction_surface_potential, only: surface_potential
   use friction_afm_scan, only: afm_scanner, trip_record, q_f_along, q_fy
   use testing, only: test_suite, check, check_close
   implicit none

   real(wp), parameter :: a = 4.62_wp, u0 = 1.0_wp   ! Å, eV
   type(test_suite) :: suite

   suite%name = 'tomlinson'
   call suite%add('maximum_force', maximum_force)
   call suite%add('slip_force_and_period', slip_force_and_period)
   call suite%add('stick_slope', stick_slope)
   call suite%add('no_stick_slip_below_one', no_stick_slip_below_one)
   call suite%run_all()

contains

   !> A 1D cut: four lattice periods along x at y = 0, finely sampled.
   function cut(k, velocity) result(c)
      real(wp), intent(in) :: k, velocity   !! N/m, Å/s
      type(afm_config) :: c

      c%potential = 'naf'
      c%v0 = u0
      c%ax = a
      c%ay = a
      c%kx = k
      c%ky = k
      c%velocity = velocity
      c%length = 4 * a
      c%nx = 4001
      c%ny = 1
      c%retrace = .true.
   end function cut

   subroutine scan_line(c, trace, retrace, failure)
      type(afm_config), intent(in) :: c
      real(wp), allocatable, intent(out) :: trace(:, :), retrace(:, :)
      character(len=:), allocatable, intent(inout) :: failure
      type(afm_scanner), target :: scanner
      type(trip_record) :: trip
      type(error_type), allocatable :: error
      class(surface_potential), allocatable :: potential

      call new_potential(c, potential, error)
      if (.not. allocated(error)) call scanner%init(c, potential, error)
      if (.not. allocated(error)) call scanner%run_trip(0, .true., trip, error)
      if (.not. allocated(error)) trace = trip%values
      if (.not. allocated(error)) call scanner%run_trip(0, .false., trip, error)
      if (.not. allocated(error)) retrace = trip%values
      if (allocated(error)) failure = error%message
   end subroutine scan_line

   real(wp) function eta_of(k)
      real(wp), intent(in) :: k
      eta_of = 4 * pi**2 * u0 / (k * n_per_m_to_internal * a**2)
   end function eta_of

   real(wp) function f_star()
      f_star = 2 * pi * u0 / a * ev_per_angstrom_to_nn
   end function f_star

   !> Indices i where the force drops between samples i and i+1 by more
   !> than a quarter of F*: slips (a stick never lowers the force that fast).
   function slips(force) result(at)
      real(wp), intent(in) :: force(:)
      integer, allocatable :: at(:)
      integer :: i

      allocate (at(0))
      do i = 1, size(force) - 1
         if (force(i) - force(i + 1) > 0.25_wp * f_star()) then
            if (size(at) > 0) then
               if (i - at(size(at)) < 10) cycle  ! the same slip seen over two samples
            end if
            at = [at, i]
         end if
      end do
   end function slips

   !> The maximum lateral force approaches F* as v -> 0.  In this overdamped
   !> scene the excess over F* is a viscous lag, proportional to v: about
   !> 0.04 nN at 400 Å/s, so 1e-4 nN at 1 Å/s; the tolerance 1e-3 F*
   !> (2e-3 nN) leaves a margin of 20 and still rejects F* √(1 - 1/η²).
   subroutine maximum_force(failure)
      character(len=:), allocatable, intent(out) :: failure
      real(wp), allocatable :: slow(:, :), fast(:, :), back(:, :)

      call scan_line(cut(10.0_wp, 1.0_wp), slow, back, failure)
      if (allocated(failure)) return
      call scan_line(cut(10.0_wp, 64.0_wp), fast, back, failure)
      if (allocated(failure)) return
      call check_close(failure, maxval(slow(:, q_f_along)), f_star(), 1.0e-3_wp * f_star(), &
         & 'maximum force at 1 Å/s against F*')
      call check(failure, maxval(fast(:, q_f_along)) - f_star() > maxval(slow(:, q_f_along)) - f_star(), &
         & 'the excess over F* does not shrink with the velocity')
      call check(failure, maxval(abs(slow(:, q_fy))) < 1.0e-9_wp, 'the tip left the line y = 0')
   end subroutine maximum_force

   !> The force just before each slip is F* √(1 - 1/η²); slips are one lattice
   !> period apart.  The force near the fold varies like the square root of
   !> the distance to it, so one sample spacing (a/1000) before the fold it
   !> sits ~0.5 % above the fold value (measured 2.062 against 2.051 nN), and
   !> the lag at 1 Å/s moves it a little more: tolerance 2 %, well below the
   !> 6 % gap to F* that a wrong fold condition would give.
   subroutine slip_force_and_period(failure)
      character(len=:), allocatable, intent(out) :: failure
      real(wp), allocatable :: trace(:, :), back(:, :)
      integer, allocatable :: at(:)
      real(wp) :: eta, expected, dx
      integer :: n
      character(len=16) :: label

      call scan_line(cut(10.0_wp, 1.0_wp), trace, back, failure)
      if (allocated(failure)) return
      eta = eta_of(10.0_wp)
      expected = f_star() * sqrt(1 - 1 / eta**2)
      at = slips(trace(:, q_f_along))
      call check(failure, size(at) >= 3, 'fewer than three slips over four periods')
      if (allocated(failure)) return
      dx = 4 * a / 4000
      do n = 1, size(at)
         write (label, '(i0)') n
         call check_close(failure, trace(at(n), q_f_along), expected, 0.02_wp * expected, &
            & 'force before slip '//trim(label))
      end do
      do n = 2, size(at)
         write (label, '(i0)') n
         call check_close(failure, (at(n) - at(n - 1)) * dx, a, 2 * dx, 'distance between slips '//trim(label))
      end do
   end subroutine slip_force_and_period

   !> At the start the tip sits in a minimum: dF/dx_M = k η/(1 + η).
   !> Measured over 0.02 Å of travel after the start-up transient (~1e-4 s,
   !> 1e-4 Å at 1 Å/s); the curvature of F(x_M) changes the slope over that
   !> span by ~ (q dx)² ≈ 1e-4 relative, hence the tolerance 1e-4 k.
   subroutine stick_slope(failure)
      character(len=:), allocatable, intent(out) :: failure
      real(wp), allocatable :: trace(:, :), back(:, :)
      real(wp) :: eta, k_nn_per_angstrom, dx, slope

      call scan_line(cut(10.0_wp, 1.0_wp), trace, back, failure)
      if (allocated(failure)) return
      eta = eta_of(10.0_wp)
      k_nn_per_angstrom = 10.0_wp * 0.1_wp  ! 1 N/m = 0.1 nN/Å
      dx = 4 * a / 4000
      slope = (trace(6, q_f_along) - trace(2, q_f_along)) / (4 * dx)
      call check_close(failure, slope, k_nn_per_angstrom * eta / (1 + eta), &
         & 1.0e-4_wp * k_nn_per_angstrom, 'stick slope against k η/(1+η)')
   end subroutine stick_slope

   !> η = 0.5 (k six times the NaF value): smooth sliding.  No slips, and the
   !> friction (half the trace-retrace difference of the mean force) is only
   !> the viscous c v = 1e-4 nN, against 0.7 nN with η = 2.96 at the same v.
   subroutine no_stick_slip_below_one(failure)
      character(len=:), allocatable, intent(out) :: failure
      real(wp), allocatable :: trace(:, :), back(:, :)
      real(wp) :: k, friction_smooth, friction_sticky
      integer, allocatable :: at(:)

      k = 10.0_wp * eta_of(10.0_wp) / 0.5_wp
      call check_close(failure, eta_of(k), 0.5_wp, 1.0e-12_wp, 'η of the smooth case')
      call scan_line(cut(k, 1.0_wp), trace, back, failure)
      if (allocated(failure)) return
      at = slips(trace(:, q_f_along))
      call check(failure, size(at) == 0, 'slips found for η < 1')
      friction_smooth = 0.5_wp * (sum(trace(:, q_f_along)) - sum(back(:, q_f_along))) / size(trace, 1)
      call check_close(failure, friction_smooth, 0.0_wp, 1.0e-3_wp, 'friction for η < 1, nN')
      call scan_line(cut(10.0_wp, 1.0_wp), trace, back, failure)
      if (allocated(failure)) return
      friction_sticky = 0.5_wp * (sum(trace(:, q_f_along)) - sum(back(:, q_f_along))) / size(trace, 1)
      call check(failure, friction_sticky > 0.3_wp, 'no friction for η > 1')
   end subroutine no_stick_slip_below_one

end program test_tomlinson
