!> The crank in stick as an ODE of its own, for an oracle independent of the
!> closed form: ξ y'' + κ y = x(τ), x = x0 + v'_dr (τ - τ0), state (y, y').
module brake_test_systems
   use friction_kinds, only: wp
   use friction_error, only: error_type
   use friction_ode_system, only: ode_system
   use friction_ode_solver, only: ode_solver, solver_settings
   use friction_brake_params, only: brake_parameters
   implicit none
   private
   public :: crank_in_stick, stick_end_oracle

   type, extends(ode_system) :: crank_in_stick
      real(wp) :: xi = 0.412_wp, kappa = 1.5_wp, x0 = 0.0_wp, v_dr = 0.0_wp, t0 = 0.0_wp
   contains
      procedure :: dimension
      procedure :: rhs
      procedure :: jacobian
   end type crank_in_stick

contains

   pure integer function dimension(self) result(n)
      class(crank_in_stick), intent(in) :: self
      n = 2
   end function dimension

   pure subroutine rhs(self, t, y, dydt)
      class(crank_in_stick), intent(in) :: self
      real(wp), intent(in) :: t, y(:)
      real(wp), intent(out) :: dydt(:)
      dydt(1) = y(2)
      dydt(2) = (self%x0 + self%v_dr * (t - self%t0) - self%kappa * y(1)) / self%xi
   end subroutine rhs

   pure subroutine jacobian(self, t, y, dfdy, dfdt)
      class(crank_in_stick), intent(in) :: self
      real(wp), intent(in) :: t, y(:)
      real(wp), intent(out) :: dfdy(:, :), dfdt(:)
      dfdy = reshape([0.0_wp, -self%kappa / self%xi, 1.0_wp, 0.0_wp], [2, 2])
      dfdt = [0.0_wp, self%v_dr / self%xi]
   end subroutine jacobian

   !> Where the integrated stick ODE from (t0, y0) first reaches the static
   !> limit: sample 200 points up to t_guess (and as far again), then
   !> bisect to 1e-11.  Each trial integrates afresh from t0.
   subroutine stick_end_oracle(p, t0, y0, t_guess, t_end, message)
      type(brake_parameters), intent(in) :: p
      real(wp), intent(in) :: t0, y0(4), t_guess
      real(wp), intent(out) :: t_end
      character(len=:), allocatable, intent(inout) :: message
      real(wp) :: a, b, m
      integer :: i

      a = t0
      b = t0
      do i = 1, 400
         b = t0 + i * (t_guess - t0) / 200
         if (limit_margin(p, t0, y0, b, message) < 0.0_wp) exit
         a = b
      end do
      do while (b - a > 1.0e-11_wp)
         m = 0.5_wp * (a + b)
         if (limit_margin(p, t0, y0, m, message) < 0.0_wp) then
            b = m
         else
            a = m
         end if
      end do
      t_end = b
   end subroutine stick_end_oracle

   !> μs N' - |2x - y| at time t of a stick from (t0, y0), the crank integrated
   !> by GSL rk8pd at 1e-13.
   real(wp) function limit_margin(p, t0, y0, t, message)
      type(brake_parameters), intent(in) :: p
      real(wp), intent(in) :: t0, y0(4), t
      character(len=:), allocatable, intent(inout) :: message
      type(crank_in_stick), target :: crank
      type(ode_solver) :: solver
      type(solver_settings) :: settings
      type(error_type), allocatable :: error
      real(wp) :: s, y(2), x

      crank%xi = p%xi
      crank%kappa = p%kappa
      crank%x0 = y0(1)
      crank%v_dr = p%v_dr
      crank%t0 = t0
      settings%method = 'rk8pd'
      settings%rtol = 1.0e-13_wp
      settings%atol = 1.0e-15_wp
      call solver%init(crank, settings, 1.0e-3_wp, error)
      s = t0
      y = y0(3:4)
      if (t > t0) call solver%advance(s, t, y, error)
      if (allocated(error)) message = error%message
      x = y0(1) + p%v_dr * (t - t0)
      limit_margin = p%mu_s * ((1.0_wp - p%kappa) * y(1) + p%g_prime) - abs(2.0_wp * x - y(1))
   end function limit_margin

end module brake_test_systems

!> The Girling brake (paper §4, §6.2; docs/physics.md, The Girling brake):
!> derived parameters, the
!> exact stick phase, the linear motion for μ = 0, the regularized law's
!> approach to the switched model, event-time convergence, Jacobians, and
!> the failure guards.  Each property against an oracle computed here.
program test_brake
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
   use friction_kinds, only: wp, i8, pi
   use friction_error, only: error_type
   use friction_ode_solver, only: ode_solver, solver_settings
   use friction_brake_params, only: brake_parameters, brake_dimensional, derive_parameters, time_scale
   use friction_brake_config, only: brake_config
   use friction_brake_record, only: event_stick_to_slip, event_slip_to_stick, event_slip_reversal
   use friction_brake_regularized, only: brake_regularized
   use friction_brake_switched, only: brake_slip
   use friction_brake_simulate, only: brake_run, simulate_brake
   use friction_brake_diagnostics, only: brake_benettin
   use friction_analysis_lyapunov_flow, only: benettin_settings, benettin_accumulator
   use brake_test_systems, only: crank_in_stick, stick_end_oracle
   use testing, only: test_suite, check, check_close
   implicit none

   type(test_suite) :: suite

   suite%name = 'brake'
   call suite%add('derived_parameters_of_section_6_2', derived_parameters_of_section_6_2)
   call suite%add('natural_frequencies', natural_frequencies)
   call suite%add('stick_velocity_is_exact', stick_velocity_is_exact)
   call suite%add('stick_ends_at_the_static_limit', stick_ends_at_the_static_limit)
   call suite%add('stick_closed_form_matches_its_ode', stick_closed_form_matches_its_ode)
   call suite%add('linear_motion_is_modal', linear_motion_is_modal)
   call suite%add('linear_spectrum_peaks', linear_spectrum_peaks)
   call suite%add('regularized_approaches_switched', regularized_approaches_switched)
   call suite%add('event_times_converge', event_times_converge)
   call suite%add('jacobians_match_differences', jacobians_match_differences)
   call suite%add('explicit_stepper_on_stiff_law_stops', explicit_stepper_on_stiff_law_stops)
   call suite%add('wall_time_guard_stops', wall_time_guard_stops)
   call suite%add('nan_is_caught', nan_is_caught)
   call suite%add('lift_off_is_an_error', lift_off_is_an_error)
   call suite%add('benettin_of_linear_motion_is_zero', benettin_of_linear_motion_is_zero)
   call suite%run_all()

contains

   !> The paper's case over [0, t_end] on a grid dt: switched, rk8pd tight.
   function paper_case(t_end, dt) result(c)
      real(wp), intent(in) :: t_end, dt
      type(brake_config) :: c

      c%t_end = t_end
      c%dt_out = dt
      c%solver%method = 'rk8pd'
      c%solver%rtol = 1.0e-12_wp
      c%solver%atol = 1.0e-14_wp
      c%event_tolerance = 1.0e-12_wp
   end function paper_case

   !> Run or fail with the error message.
   subroutine run_or_fail(c, run, failure)
      type(brake_config), intent(in) :: c
      type(brake_run), target, intent(inout) :: run
      character(len=:), allocatable, intent(inout) :: failure
      type(error_type), allocatable :: error

      call simulate_brake(c, run, error)
      if (allocated(error)) failure = error%message
   end subroutine run_or_fail

   !> §6.2: ξ = 1/3 m_c/m = 0.412, κ = 1.5, g' = 0.01778 m, printed to the
   !> digits the paper gives (tolerance half a unit of the last digit), and
   !> the derivation's formulas exactly; ε = 1e6 s/m, δ = 0.1 s/m and
   !> v_dr = -0.097916 m/s give the paper's ε' = 3.5121e7, δ' = 3.5121
   !> (3.51205 rounded: 2e-5 relative) and v'_dr = -0.002788 m.
   subroutine derived_parameters_of_section_6_2(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(brake_dimensional) :: data
      type(brake_parameters) :: p
      type(error_type), allocatable :: error
      real(wp) :: root

      call derive_parameters(data, 0.59_wp, 0.59_wp, p, error)
      if (allocated(error)) then
         failure = error%message
         return
      end if
      call check_close(failure, p%xi, 0.412_wp, 5.0e-4_wp, 'xi against the paper')
      call check_close(failure, p%kappa, 1.5_wp, 5.0e-2_wp, 'kappa against the paper')
      call check_close(failure, p%g_prime, 0.01778_wp, 5.0e-6_wp, 'g_prime against the paper (m)')
      call check_close(failure, p%xi, 0.215_wp / (3.0_wp * 0.174_wp), 1.0e-15_wp, 'xi = m_c/(3 m)')
      call check_close(failure, p%kappa, (214.62_wp + 107.31_wp) / 214.62_wp, 1.0e-15_wp, 'kappa')
      call check_close(failure, p%g_prime, 9.81_wp * (0.174_wp + 0.215_wp) / 214.62_wp, 1.0e-17_wp, &
         & 'g_prime = g (m + m_c)/k1')
      root = sqrt(214.62_wp / 0.174_wp)
      call check_close(failure, p%epsilon_prime, 1.0e6_wp * root, 1.0e-7_wp, 'epsilon_prime = epsilon sqrt(k1/m)')
      call check_close(failure, p%epsilon_prime / 3.5121e7_wp, 1.0_wp, 2.0e-5_wp, 'epsilon_prime against the paper')
      call check_close(failure, p%delta_prime / 3.5121_wp, 1.0_wp, 2.0e-5_wp, 'delta_prime against the paper')
      call check_close(failure, p%v_dr, -0.002788_wp, 5.0e-7_wp, 'v_dr_prime against the paper (m)')
      ! 0.028474 s is often quoted (docs/physics.md, Equations and parameters);
      ! the data give 0.0284734 s.
      call check_close(failure, time_scale(data), sqrt(0.174_wp / 214.62_wp), 1.0e-17_wp, 'sqrt(m/k1) (s)')
      call check_close(failure, time_scale(data), 0.028473_wp, 1.0e-6_wp, 'sqrt(m/k1) (s), rounded')
      call check(failure, p%mu == 0.59_wp .and. p%mu_s == 0.59_wp, 'mu, mu_s not passed through')
      ! k2 /= k1 has no place in Eq. 10.
      data%k2 = 200.0_wp
      call derive_parameters(data, 0.59_wp, 0.59_wp, p, error)
      call check(failure, allocated(error), 'k2 /= k1 accepted')
   end subroutine derived_parameters_of_section_6_2

   !> μ = 0: the eigenvalues of M⁻¹K = [2 -1; -1/ξ κ/ξ] from its trace and
   !> determinant, against 0.1638 and 0.3406 cycles per unit τ (docs/physics.md,
   !> Equations and parameters).
   subroutine natural_frequencies(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(brake_parameters) :: p
      real(wp) :: f(2), trace, det, lambda(2)

      f = p%natural_frequencies()
      trace = 2.0_wp + p%kappa / p%xi
      det = (2.0_wp * p%kappa - 1.0_wp) / p%xi
      lambda = [trace - sqrt(trace**2 - 4 * det), trace + sqrt(trace**2 - 4 * det)] / 2
      call check_close(failure, f(1), sqrt(lambda(1)) / (2 * pi), 1.0e-14_wp, 'lower frequency')
      call check_close(failure, f(2), sqrt(lambda(2)) / (2 * pi), 1.0e-14_wp, 'upper frequency')
      call check_close(failure, f(1), 0.1638_wp, 5.0e-5_wp, 'lower frequency against docs/physics.md')
      call check_close(failure, f(2), 0.3406_wp, 1.0e-4_wp, 'upper frequency against docs/physics.md')
   end subroutine natural_frequencies

   !> In stick, x' is v'_dr exactly (bitwise), at every grid point flagged
   !> stick and in the state of every slip-to-stick event.
   subroutine stick_velocity_is_exact(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(brake_run), target :: run
      type(brake_config) :: c
      integer :: n_stick, k

      c = paper_case(200.0_wp, 0.01_wp)
      call run_or_fail(c, run, failure)
      if (allocated(failure)) return
      n_stick = count(run%trajectory%stick == 1)
      call check(failure, n_stick > 500, 'fewer than 500 grid points in stick: nothing tested')
      call check(failure, all(pack(run%trajectory%v, run%trajectory%stick == 1) == c%params%v_dr), &
         & "x' differs from v'_dr at a stick point")
      do k = 1, run%events%n
         if (run%events%kind(k) == event_slip_to_stick) &
            & call check(failure, run%events%state(2, k) == c%params%v_dr, "x' /= v'_dr entering stick")
      end do
   end subroutine stick_velocity_is_exact

   !> Every stick ends where |2x - y| = μs N': the event state meets the
   !> limit to rounding (|h| <= 1e-15 m against forces of 1e-2 m), and an
   !> independent oracle, the crank's stick ODE integrated from the stick's
   !> start (rk8pd, 1e-13) and bisected, puts the crossing at the same time.
   subroutine stick_ends_at_the_static_limit(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(brake_run), target :: run
      type(brake_config) :: c
      integer :: k, checked
      real(wp) :: h, t_oracle
      character(len=80) :: text

      c = paper_case(120.0_wp, 0.1_wp)
      call run_or_fail(c, run, failure)
      if (allocated(failure)) return
      checked = 0
      associate (p => c%params, e => run%events)
         do k = 2, e%n
            if (e%kind(k) /= event_stick_to_slip .or. e%kind(k - 1) /= event_slip_to_stick) cycle
            h = p%mu_s * p%normal_force(e%state(3, k)) - abs(p%elastic_force(e%state(1, k), e%state(3, k)))
            write (text, '(a, f0.6)') 'static limit at the stick end τ = ', e%t(k)
            call check_close(failure, h, 0.0_wp, 1.0e-15_wp, trim(text))
            call stick_end_oracle(p, e%t(k - 1), e%state(:, k - 1), e%t(k), t_oracle, failure)
            call check_close(failure, e%t(k), t_oracle, 2.0e-9_wp, 'stick end against the stick ODE')
            checked = checked + 1
            if (allocated(failure)) return
         end do
      end associate
      call check(failure, checked >= 5, 'fewer than 5 stick phases in [0, 120]')
   end subroutine stick_ends_at_the_static_limit

   !> The stick phase's closed form against its ODE integrated by GSL
   !> (rk8pd, 1e-13) over 10 τ from a state with both parts of the motion.
   subroutine stick_closed_form_matches_its_ode(failure)
      use friction_brake_stick, only: stick_motion
      character(len=:), allocatable, intent(out) :: failure
      type(stick_motion) :: stick
      type(brake_parameters) :: p
      type(crank_in_stick), target :: crank
      type(ode_solver) :: solver
      type(solver_settings) :: settings
      type(error_type), allocatable :: error
      real(wp) :: t, y(2), exact(4), y0(4)
      integer :: k

      y0 = [-0.009_wp, p%v_dr, -0.006_wp, 0.0013_wp]
      call stick%start(p, 5.0_wp, y0)
      crank%xi = p%xi
      crank%kappa = p%kappa
      crank%x0 = y0(1)
      crank%v_dr = p%v_dr
      crank%t0 = 5.0_wp
      settings%method = 'rk8pd'
      settings%rtol = 1.0e-13_wp
      settings%atol = 1.0e-15_wp
      call solver%init(crank, settings, 1.0e-3_wp, error)
      t = 5.0_wp
      y = y0(3:4)
      do k = 1, 20
         call solver%advance(t, 5.0_wp + 0.5_wp * k, y, error)
         if (allocated(error)) then
            failure = error%message
            return
         end if
         exact = stick%state_at(t)
         call check_close(failure, exact(1), y0(1) + p%v_dr * (t - 5.0_wp), 1.0e-16_wp, 'x in stick')
         call check(failure, exact(2) == p%v_dr, "x' in stick")
         call check_close(failure, exact(3), y(1), 1.0e-12_wp, 'y in stick')
         call check_close(failure, exact(4), y(2), 1.0e-12_wp, "y' in stick")
      end do
   end subroutine stick_closed_form_matches_its_ode

   !> μ = μs = 0: Eq. 10 is linear, M q'' + K q = 0, q = (x, y).  Modal
   !> solution: eigenpairs λ, φ = (1, 2 - λ) of M⁻¹K, amplitudes from the
   !> initial state.  The switched model (which still stops at every v_rel
   !> = 0 and reverses) must follow it to the integrator's accuracy.
   subroutine linear_motion_is_modal(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(brake_run), target :: run
      type(brake_config) :: c
      real(wp) :: worst, x_modal, t
      integer :: i, model

      do model = 1, 2
         c = paper_case(200.0_wp, 0.1_wp)
         c%params%mu = 0.0_wp
         c%params%mu_s = 0.0_wp
         c%x0 = 0.004_wp
         c%y0 = -0.002_wp
         c%v_rel0 = 0.001_wp
         c%w0 = 0.0005_wp
         if (model == 2) then
            c%model = 'regularized'
            c%solver%method = 'rk8pd'
         end if
         call run_or_fail(c, run, failure)
         if (allocated(failure)) return
         worst = 0.0_wp
         do i = 1, run%n
            t = run%trajectory%t(i)
            x_modal = modal_x(c, t)
            worst = max(worst, abs(run%trajectory%x(i) - x_modal))
         end do
         call check_close(failure, worst, 0.0_wp, 1.0e-10_wp, 'max |x - x_modal| on [0, 200], m, '//trim(c%model))
      end do
      call check(failure, count(run%events%kind == event_slip_reversal) == 0, &
         & 'the regularized model reports reversals')
   end subroutine linear_motion_is_modal

   !> With μ = μs = 0 Eq. 10 is linear and undamped: the separation of two
   !> runs is a quasi-periodic function of time, bounded above and below,
   !> so the Benettin sum stays bounded and the estimate is O(1/T).  Both
   !> runs go through the brake's own logic (the switched model here, with
   !> its reversal events).  The bound 5e-3 is ln(100)/1000: a separation
   !> that varies a hundredfold over the orbit; a chaotic 0.05 would exceed
   !> it tenfold.
   subroutine benettin_of_linear_motion_is_zero(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(brake_config) :: c
      type(benettin_accumulator) :: result
      type(error_type), allocatable :: error
      integer :: model

      do model = 1, 2
         c = paper_case(1100.0_wp, 0.1_wp)
         c%params%mu = 0.0_wp
         c%params%mu_s = 0.0_wp
         c%x0 = 0.004_wp
         c%y0 = -0.002_wp
         c%v_rel0 = 0.001_wp
         c%w0 = 0.0005_wp
         c%solver%rtol = 1.0e-10_wp
         c%solver%atol = 1.0e-12_wp
         if (model == 2) c%model = 'regularized'
         call brake_benettin(c, benettin_settings(transient=100.0_wp, duration=1000.0_wp, renormalise=1.0_wp, &
            & d0=1.0e-8_wp), result, error)
         if (allocated(error)) then
            failure = error%message
            return
         end if
         call check_close(failure, result%current(), 0.0_wp, 5.0e-3_wp, 'Benettin, linear brake, '//trim(c%model))
         call check(failure, result%n == 1000, 'one running estimate per renormalisation')
      end do
   end subroutine benettin_of_linear_motion_is_zero

   !> x(τ) of the linear system from the modal decomposition.
   pure real(wp) function modal_x(c, t)
      type(brake_config), intent(in) :: c
      real(wp), intent(in) :: t
      real(wp) :: trace, det, lambda(2), omega(2), phi(2), q0(2), dq0(2), a(2), b(2), d

      trace = 2.0_wp + c%params%kappa / c%params%xi
      det = (2.0_wp * c%params%kappa - 1.0_wp) / c%params%xi
      lambda = [trace - sqrt(trace**2 - 4 * det), trace + sqrt(trace**2 - 4 * det)] / 2
      omega = sqrt(lambda)
      phi = 2.0_wp - lambda             ! y-components of the modes (x-components 1)
      q0 = [c%x0, c%y0]
      dq0 = [c%params%v_dr + c%v_rel0, c%w0]
      ! q0 = a1 (1, φ1) + a2 (1, φ2); likewise dq0 with b_i ω_i.
      d = phi(2) - phi(1)
      a = [(q0(1) * phi(2) - q0(2)) / d, (q0(2) - q0(1) * phi(1)) / d]
      b = [(dq0(1) * phi(2) - dq0(2)) / d, (dq0(2) - dq0(1) * phi(1)) / d] / omega
      modal_x = sum(a * cos(omega * t) + b * sin(omega * t))
   end function modal_x

   !> μ = 0: the spectrum of x over τ in [0, 1200] (Hann window, evaluated
   !> on a 1e-5 grid) peaks at the natural frequencies 0.1638 and 0.3406.
   !> Resolution 1/1200; a windowed tone's peak sits on its frequency up to
   !> the other tone's leakage, far below 2e-4 at this separation.
   subroutine linear_spectrum_peaks(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(brake_run), target :: run
      type(brake_config) :: c
      real(wp) :: f_peak(2), band(2, 2), window(12001), signal(12001)
      integer :: n, k, j

      c = paper_case(1200.0_wp, 0.1_wp)
      c%params%mu = 0.0_wp
      c%params%mu_s = 0.0_wp
      c%x0 = 0.004_wp
      c%solver%rtol = 1.0e-10_wp
      c%solver%atol = 1.0e-12_wp
      call run_or_fail(c, run, failure)
      if (allocated(failure)) return
      n = run%n
      call check(failure, n == size(signal), 'unexpected grid size')
      if (allocated(failure)) return
      window = [(0.5_wp - 0.5_wp * cos(2 * pi * (k - 1) / (n - 1)), k = 1, n)]
      signal = (run%trajectory%x - sum(run%trajectory%x) / n) * window
      band = reshape([0.12_wp, 0.22_wp, 0.28_wp, 0.40_wp], [2, 2])
      do j = 1, 2
         ! Scan the band at 2e-4, then around the best point at 1e-6.
         f_peak(j) = scan_peak(signal(1:n), run%trajectory%t(2) - run%trajectory%t(1), &
            & band(1, j), band(2, j), 2.0e-4_wp)
         f_peak(j) = scan_peak(signal(1:n), run%trajectory%t(2) - run%trajectory%t(1), &
            & f_peak(j) - 4.0e-4_wp, f_peak(j) + 4.0e-4_wp, 1.0e-6_wp)
      end do
      call check_close(failure, f_peak(1), 0.1638_wp, 2.0e-4_wp, 'lower spectral peak (cycles per unit τ)')
      call check_close(failure, f_peak(2), 0.3406_wp, 2.0e-4_wp, 'upper spectral peak (cycles per unit τ)')
   end subroutine linear_spectrum_peaks

   !> The frequency of largest |Σ s_k exp(-2πi f k dt)| on [f0, f1] in steps df.
   real(wp) function scan_peak(signal, dt, f0, f1, df) result(f_best)
      real(wp), intent(in) :: signal(:), dt, f0, f1, df
      complex(wp) :: z, rotor, total
      real(wp) :: f, best
      integer :: i

      best = -1.0_wp
      f_best = f0
      f = f0
      do while (f <= f1)
         ! The exponentials by recurrence on the uniform grid.
         rotor = exp(cmplx(0.0_wp, -2 * pi * f * dt, wp))
         z = (1.0_wp, 0.0_wp)
         total = (0.0_wp, 0.0_wp)
         do i = 1, size(signal)
            total = total + signal(i) * z
            z = z * rotor
         end do
         if (abs(total) > best) then
            best = abs(total)
            f_best = f
         end if
         f = f + df
      end do
   end function scan_peak

   !> The regularized law tends to the switched model as ε' grows: over
   !> τ in [0, 20] the largest difference in x falls by at least a factor 2
   !> per decade of ε' (measured: 1.9e-3, 4.6e-4, 9.4e-5, 1.8e-5 m for
   !> ε' = 1e4 .. 1e7) and ends below 5e-5 m.  Both at tight tolerances
   !> (rk4imp with the analytic Jacobian for the stiff law).
   subroutine regularized_approaches_switched(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(brake_run), target :: switched, regularized
      type(brake_config) :: c
      real(wp) :: difference(4)
      integer :: k
      character(len=60) :: text

      c = paper_case(20.0_wp, 0.05_wp)
      call run_or_fail(c, switched, failure)
      if (allocated(failure)) return
      do k = 1, 4
         c%model = 'regularized'
         c%params%epsilon_prime = 10.0_wp**(k + 3)
         c%solver%method = 'rk4imp'
         c%solver%rtol = 1.0e-10_wp
         c%solver%atol = 1.0e-12_wp
         call run_or_fail(c, regularized, failure)
         if (allocated(failure)) return
         difference(k) = maxval(abs(regularized%trajectory%x - switched%trajectory%x))
         if (k > 1) then
            write (text, '(a, es8.1)') 'difference does not halve at epsilon_prime = ', c%params%epsilon_prime
            call check(failure, difference(k) < 0.5_wp * difference(k - 1), trim(text))
         end if
      end do
      call check_close(failure, difference(4), 0.0_wp, 5.0e-5_wp, 'max |x_reg - x_switched| at epsilon_prime 1e7')
   end subroutine regularized_approaches_switched

   !> Event times converge as the event tolerance shrinks: over τ in
   !> [0, 100], every located event (slip to stick, reversal) of a run at
   !> tolerance tol lies within 2 tol + 1e-9 of the run at 1e-12 (the
   !> locator's bound, plus integration error), and the worst case falls.
   subroutine event_times_converge(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(brake_run), target :: reference, run
      type(brake_config) :: c
      real(wp) :: tolerance, worst, previous
      integer :: k, i
      character(len=60) :: text

      c = paper_case(100.0_wp, 1.0_wp)
      call run_or_fail(c, reference, failure)
      if (allocated(failure)) return
      call check(failure, reference%events%n >= 10, 'fewer than 10 events in [0, 100]')
      previous = huge(1.0_wp)
      do k = 2, 8, 2
         tolerance = 10.0_wp**(-k)
         c%event_tolerance = tolerance
         call run_or_fail(c, run, failure)
         if (allocated(failure)) return
         write (text, '(a, es8.1)') 'event count at tolerance ', tolerance
         call check(failure, run%events%n == reference%events%n, trim(text))
         if (allocated(failure)) return
         worst = 0.0_wp
         do i = 1, run%events%n
            if (run%events%kind(i) == event_stick_to_slip) cycle
            worst = max(worst, abs(run%events%t(i) - reference%events%t(i)))
         end do
         write (text, '(a, es8.1)') 'worst event time error at tolerance ', tolerance
         call check_close(failure, worst, 0.0_wp, 2.0_wp * tolerance + 1.0e-9_wp, trim(text))
         call check(failure, worst < previous .or. worst < 1.0e-12_wp, trim(text)//' did not fall')
         previous = worst
      end do
   end subroutine event_times_converge

   !> Analytic Jacobians of the regularized and slip systems against central
   !> differences (relative 1e-6), near v_rel = 0 and in slip.
   subroutine jacobians_match_differences(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(brake_regularized) :: regularized
      type(brake_slip) :: slip
      real(wp) :: y(4), v_rel(5), jac(4, 4), dfdt(4), fp(4), fm(4), numeric(4, 4), h, scale
      integer :: i, j, s
      character(len=60) :: text

      regularized%params%epsilon_prime = 1.0e5_wp   ! steep, but resolvable by differences
      v_rel = [-3.0e-3_wp, -2.0e-5_wp, 1.0e-6_wp, 4.0e-5_wp, 2.0e-3_wp]
      do s = 1, size(v_rel)
         y = [-0.009_wp, regularized%params%v_dr + v_rel(s), -0.006_wp, 0.001_wp]
         call regularized%jacobian(0.0_wp, y, jac, dfdt)
         do j = 1, 4
            h = 1.0e-7_wp * max(abs(y(j)), 1.0e-3_wp)
            if (j == 2) h = 1.0e-4_wp * max(abs(v_rel(s)), 1.0e-6_wp)
            y(j) = y(j) + h
            call regularized%rhs(0.0_wp, y, fp)
            y(j) = y(j) - 2 * h
            call regularized%rhs(0.0_wp, y, fm)
            y(j) = y(j) + h
            numeric(:, j) = (fp - fm) / (2 * h)
         end do
         scale = maxval(abs(numeric))
         write (text, '(a, es9.2)') 'regularized Jacobian at v_rel = ', v_rel(s)
         call check_close(failure, maxval(abs(jac - numeric)), 0.0_wp, 1.0e-6_wp * scale, trim(text))
      end do
      do s = -1, 1, 2
         slip%direction = real(s, wp)
         y = [-0.009_wp, slip%params%v_dr + s * 1.0e-3_wp, -0.006_wp, 0.001_wp]
         call slip%jacobian(0.0_wp, y, jac, dfdt)
         do j = 1, 4
            h = 1.0e-6_wp * max(abs(y(j)), 1.0e-3_wp)
            y(j) = y(j) + h
            call slip%rhs(0.0_wp, y, fp)
            y(j) = y(j) - 2 * h
            call slip%rhs(0.0_wp, y, fm)
            y(j) = y(j) + h
            numeric(:, j) = (fp - fm) / (2 * h)
         end do
         do i = 1, 4
            call check_close(failure, maxval(abs(jac(i, :) - numeric(i, :))), 0.0_wp, &
               & 1.0e-6_wp * maxval(abs(numeric)), 'slip Jacobian row')
         end do
      end do
   end subroutine jacobians_match_differences

   !> The case built to fail: rk4 (explicit) on the regularized law with the
   !> paper's ε' = 3.5e7 and a budget of 5000 steps.  It must stop with a
   !> message naming the stepper, the budget, the time and the remedy.
   subroutine explicit_stepper_on_stiff_law_stops(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(brake_run), target :: run
      type(brake_config) :: c
      type(error_type), allocatable :: error

      c%model = 'regularized'
      c%t_end = 100.0_wp
      c%solver%method = 'rk4'
      c%solver%rtol = 1.0e-6_wp
      c%solver%atol = 1.0e-8_wp
      c%solver%max_steps = 5000
      call simulate_brake(c, run, error)
      call check(failure, allocated(error), 'rk4 on the stiff law did not stop')
      if (allocated(failure)) return
      call check(failure, index(error%message, 'rk4') > 0, 'no stepper in: '//error%message)
      call check(failure, index(error%message, 'max_steps = 5000') > 0, 'no budget in: '//error%message)
      call check(failure, index(error%message, 'τ = ') > 0, 'no time in: '//error%message)
      call check(failure, index(error%message, 'implicit') > 0, 'no remedy in: '//error%message)
      call check(failure, run%time_reached() < 100.0_wp, 'time reached not before the end')
      ! h_min: the stiff law needs steps far below 1e-3.
      c%solver%max_steps = 10000000
      c%solver%h_min = 1.0e-3_wp
      c%solver%method = 'rkf45'
      call simulate_brake(c, run, error)
      call check(failure, allocated(error), 'rkf45 with h_min = 1e-3 did not stop')
      if (allocated(failure)) return
      call check(failure, index(error%message, 'h_min') > 0 .and. index(error%message, 'rkf45') > 0, &
         & 'no h_min or stepper in: '//error%message)
   end subroutine explicit_stepper_on_stiff_law_stops

   !> max_wall_time stops a run that would take a minute (rkf45 on the stiff
   !> law over 1e6 τ with no step budget) within a second or two of the limit.
   subroutine wall_time_guard_stops(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(brake_run), target :: run
      type(brake_config) :: c
      type(error_type), allocatable :: error
      integer(i8) :: start, finish, rate

      c%model = 'regularized'
      c%t_end = 1.0e6_wp
      c%dt_out = 100.0_wp
      c%solver%method = 'rkf45'
      c%solver%rtol = 1.0e-8_wp
      c%solver%atol = 1.0e-10_wp
      c%solver%max_steps = huge(1_i8)
      c%solver%max_wall_time = 0.3_wp
      call system_clock(start, rate)
      call simulate_brake(c, run, error)
      call system_clock(finish)
      call check(failure, allocated(error), 'the run was not stopped')
      if (allocated(failure)) return
      call check(failure, index(error%message, 'max_wall_time') > 0 .and. index(error%message, 'rkf45') > 0 &
         & .and. index(error%message, 'τ = ') > 0, 'message lacks guard, stepper or time: '//error%message)
      call check_close(failure, real(finish - start, wp) / rate, 0.3_wp, 2.0_wp, 'seconds until stopped')
   end subroutine wall_time_guard_stops

   subroutine nan_is_caught(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(brake_run), target :: run
      type(brake_config) :: c
      type(error_type), allocatable :: error
      integer :: model

      do model = 1, 2
         c%model = trim(merge('switched   ', 'regularized', model == 1))
         c%t_end = 10.0_wp
         c%x0 = ieee_value(1.0_wp, ieee_quiet_nan)
         c%v_rel0 = 1.0e-3_wp
         c%solver%method = 'bsimp'
         call simulate_brake(c, run, error)
         call check(failure, allocated(error), trim(c%model)//': NaN state not caught')
         if (allocated(failure)) return
         call check(failure, index(error%message, 'NaN') > 0, 'message lacks NaN: '//error%message)
      end do
   end subroutine nan_is_caught

   !> N' = g' - y/2 driven to 0 (y0 = 0.03 m rising) is an error in both
   !> models, at the time the pad lifts off.
   subroutine lift_off_is_an_error(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(brake_run), target :: run
      type(brake_config) :: c
      type(error_type), allocatable :: error
      integer :: model

      do model = 1, 2
         c = paper_case(10.0_wp, 0.1_wp)
         if (model == 2) then
            c%model = 'regularized'
            c%solver%method = 'rk4imp'
            c%solver%rtol = 1.0e-8_wp
            c%solver%atol = 1.0e-10_wp
         end if
         c%y0 = 0.03_wp
         c%w0 = 0.05_wp
         call simulate_brake(c, run, error)
         call check(failure, allocated(error), trim(c%model)//": N' <= 0 not reported")
         if (allocated(failure)) return
         call check(failure, index(error%message, "N' reached 0") > 0, 'message: '//error%message)
         call check(failure, run%time_reached() < 10.0_wp, 'the run went on after lift-off')
      end do
   end subroutine lift_off_is_an_error

end program test_brake
