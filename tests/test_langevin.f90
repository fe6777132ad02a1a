!> The Langevin tip (friction_afm_langevin) against exact statistical
!> mechanics and the Kramers rate.  Tolerances are 3 standard errors (block
!> averages over 100 blocks, each thousands of correlation times long; for
!> escape times the sample standard deviation over realizations) plus the
!> stated bias of the scheme.
!>   - equipartition on a flat surface, inputs/naf.nml's tip (m = 1e-8 kg,
!>     k = 10 N/m, c = 1e-3 N s/m), T = 300 K, support moving at
!>     (4000, -3000) Å/s: per axis k⟨δu²⟩ = k_B T, m⟨δr'²⟩ = k_B T, ⟨r'⟩ = v_M
!>     and ⟨u⟩ = -c v_M/k (the drag), with BAOAB's exact discrete values
!>     for a harmonic tip: k⟨δu²⟩ exact, m⟨δr'²⟩ × (1 - (ωh)²/4),
!>     ⟨u⟩ × tanh(γh/2)/(γh/2); at the default step these biases are 6e-5
!>     and 2e-4, far below the < 1 % standard errors; at ωh = 1 they are
!>     0.25 and 0.42 and the test tells BAOAB from other splittings;
!>   - the same for the overdamped tip (Leimkuhler–Matthews: k⟨δu²⟩ = k_B T
!>     exactly at any stable step; Euler–Maruyama would give 2 k_B T at
!>     kh/c = 1, where the test runs too);
!>   - escape from a tilted cosine well (period 4.62 Å, tilt F = 0.3 U0 q,
!>     barrier 5 and 10 k_B T at 300 K; 1D, no spring, the support at rest):
!>     mean first passage time to halfway down into the next well (6.6 and
!>     13 k_B T below the saddle: no return) over many realizations, against
!>     the Kramers–Langer rate of friction_afm_kramers:
!>       inertial, γ = c/m = ω_b (moderate friction: Mel'nikov–Meshkov's
!>       energy-diffusion parameter Δ = γ I_b/k_B T = 37 and 73, their
!>       correction below 4e-5; Kramers' spatial-diffusion rate holds up to
!>       its finite-barrier correction);
!>       overdamped, against the exact MFPT of the Smoluchowski equation
!>       (Pontryagin's double integral, by quadrature) and against Kramers.
!>     The finite-barrier correction of Kramers' formula, τ r_K - 1, is
!>     O(k_B T/ΔE); the exact overdamped MFPT gives it for this landscape:
!>     +0.093 at 5 k_B T, +0.040 at 10 k_B T.  The inertial runs are checked
!>     against 1 + that correction with its whole size added to the
!>     tolerance (measured in development: 1.065 to 1.077 ± 0.017 at 5 k_B T,
!>     0.99 ± 0.03 at 10 k_B T).  BAOAB's step bias on escape times was
!>     below the statistics at ωh <= 0.2 (5 k_B T: 1.065, 1.077, 1.070 ±
!>     0.017 at ωh = 0.05, 0.1, 0.2; 1.095 at 0.4), so none is allowed.  The
!>     overdamped scheme's paths are weakly first order: its MFPT is long by
!>     ~0.3 to 0.5 κh (κ the largest curvature over c; measured against the
!>     exact MFPT: +2.0, +4.0, +7.4, +17.7 % ± 1.7 % at κh = 0.05, 0.1, 0.2,
!>     0.4 at 5 k_B T; +2.3, +6.9 % ± 3.5 % at κh = 0.1, 0.2 at 10 k_B T),
!>     so [0, κh] is allowed on top of 3 standard errors.
program test_langevin
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use friction_kinds, only: wp, i8, pi
   use friction_error, only: error_type, error_input, error_numerical
   use friction_random, only: random_stream
   use friction_afm_tip, only: afm_tip, model_inertial, model_overdamped, model_quasistatic
   use friction_afm_langevin, only: boltzmann, langevin_integrator, langevin_state, langevin_time_step, &
      & largest_curvature
   use friction_afm_kramers, only: find_minimum, find_saddle, langer_rate
   use thermal_support, only: tilted_washboard, washboard_points, block_average, naf_tip, naf_mass, &
      & naf_spring, naf_damping
   use testing, only: test_suite, check, check_close
   implicit none

   real(wp), parameter :: temperature = 300.0_wp, kt = boltzmann * temperature
   real(wp), parameter :: support_velocity(2) = [4000.0_wp, -3000.0_wp]   ! Å/s
   type(test_suite) :: suite

   suite%name = 'langevin'
   call suite%add('equipartition_inertial', equipartition_inertial)
   call suite%add('baoab_large_step', baoab_large_step)
   call suite%add('equipartition_overdamped', equipartition_overdamped)
   call suite%add('overdamped_large_step', overdamped_large_step)
   call suite%add('deterministic_limit', deterministic_limit)
   call suite%add('split_calls', split_calls)
   call suite%add('time_step', time_step)
   call suite%add('rejects', rejects)
   call suite%add('escape_inertial_5kT', escape_inertial_5kt)
   call suite%add('escape_inertial_10kT', escape_inertial_10kt)
   call suite%add('escape_overdamped_5kT', escape_overdamped_5kt)
   call suite%add('escape_overdamped_10kT', escape_overdamped_10kt)
   call suite%run_all()

contains

   subroutine fail_on(failure, error)
      character(len=:), allocatable, intent(inout) :: failure
      type(error_type), allocatable, intent(in) :: error

      if (allocated(error) .and. .not. allocated(failure)) failure = error%message
   end subroutine fail_on

   !> Run the flat-surface NaF tip (support moving at support_velocity) with
   !> step dt for total seconds after a burn-in of 200 relaxation times, and
   !> gather block averages of u and (inertial) r' per axis.
   subroutine sample_flat(model, dt, total, seed, u_stats, w_stats, failure)
      integer, intent(in) :: model
      real(wp), intent(in) :: dt, total
      integer(i8), intent(in) :: seed
      type(block_average), intent(out) :: u_stats(2), w_stats(2)
      character(len=:), allocatable, intent(inout) :: failure
      integer, parameter :: chunk = 4096
      type(afm_tip) :: tip
      type(langevin_integrator) :: integrator
      type(langevin_state) :: state
      type(random_stream) :: stream
      type(error_type), allocatable :: error
      real(wp), allocatable :: u(:, :), w(:, :)
      integer(i8) :: nsteps, done
      integer :: n, i, j

      tip = naf_tip(model, 0.0_wp)
      tip%support_velocity(1:2) = support_velocity
      call integrator%init(tip, temperature, dt, error, curvature=0.0_wp)
      if (.not. allocated(error)) call stream%init(seed, 0, 0, 0, error)
      call fail_on(failure, error)
      if (allocated(failure)) return
      call integrator%start(stream, 0.0_wp, [0.0_wp, 0.0_wp], state)
      ! burn-in: 200 c/k
      call integrator%advance(tip, stream, state, int(200 * naf_damping / naf_spring / dt) + 1, error)
      call fail_on(failure, error)
      if (allocated(failure)) return
      nsteps = int(total / dt, i8)
      do i = 1, 2
         call u_stats(i)%init(100, nsteps)
         call w_stats(i)%init(100, nsteps)
      end do
      allocate (u(2, chunk), w(2, chunk))
      done = 0
      do while (done < nsteps)
         n = int(min(int(chunk, i8), nsteps - done))
         if (model == model_inertial) then
            call integrator%advance(tip, stream, state, n, error, positions=u, velocities=w)
         else
            call integrator%advance(tip, stream, state, n, error, positions=u)
         end if
         call fail_on(failure, error)
         if (allocated(failure)) return
         do j = 1, n
            do i = 1, 2
               call u_stats(i)%add(u(i, j))
               if (model == model_inertial) call w_stats(i)%add(w(i, j))
            end do
         end do
         done = done + n
      end do
      call stream%free()
   end subroutine sample_flat

   !> Checks and prints one axis: the variance ratios against their exact
   !> discrete values, the means against drag and support velocity.
   subroutine check_axis(failure, label, axis, model, dt, u_stats, w_stats)
      character(len=:), allocatable, intent(inout) :: failure
      character(len=*), intent(in) :: label
      integer, intent(in) :: axis, model
      real(wp), intent(in) :: dt
      type(block_average), intent(in) :: u_stats, w_stats
      real(wp) :: var, se, mean, mean_se, omega, gamma_h, shift, expected_w
      character(len=1), parameter :: names(2) = ['x', 'y']
      character(len=:), allocatable :: what

      what = label//' '//names(axis)
      call u_stats%variance(var, se)
      call u_stats%mean(mean, mean_se)
      shift = -naf_damping * support_velocity(axis) / naf_spring
      if (model == model_inertial) then
         gamma_h = naf_damping / naf_mass * dt
         shift = shift * tanh(0.5_wp * gamma_h) / (0.5_wp * gamma_h)
      end if
      write (*, '(2x, a, a, f8.5, a, f7.5, a, f9.5, a, f9.5, a, f7.5, a)') what, ': k<du^2>/kT = ', &
         & naf_spring * var / kt, ' +- ', naf_spring * se / kt, ';  <u> = ', mean, ' (expected ', shift, &
         & ') +- ', mean_se, ' A'
      call check(failure, naf_spring * se / kt < 0.01_wp, what//': standard error of k<du^2>/kT above 1 %')
      call check_close(failure, naf_spring * var / kt, 1.0_wp, 3.0_wp * naf_spring * se / kt, what//': k<du^2>/kT')
      call check_close(failure, mean, shift, 3.0_wp * mean_se, what//': <u> (drag -c v/k)')
      if (model /= model_inertial) return
      omega = sqrt(naf_spring / naf_mass)
      expected_w = 1.0_wp - (omega * dt)**2 / 4.0_wp
      call w_stats%variance(var, se)
      call w_stats%mean(mean, mean_se)
      write (*, '(2x, a, a, f8.5, a, f7.5, a, f8.5, a, f9.2, a, f7.2, a)') what, ': m<dr''^2>/kT = ', &
         & naf_mass * var / kt, ' +- ', naf_mass * se / kt, ' (expected ', expected_w, ');  <r''> - v = ', &
         & mean - support_velocity(axis), ' +- ', mean_se, ' A/s'
      call check(failure, naf_mass * se / kt < 0.01_wp, what//': standard error of m<dr''^2>/kT above 1 %')
      call check_close(failure, naf_mass * var / kt, expected_w, 3.0_wp * naf_mass * se / kt, &
         & what//': m<dr''^2>/kT')
      call check_close(failure, mean, support_velocity(axis), 3.0_wp * mean_se, what//': <r''> (support velocity)')
   end subroutine check_axis

   !> Default step (ωh = 0.016, γh = 0.05), 16 s: 3.2e7 steps.
   subroutine equipartition_inertial(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(block_average) :: u_stats(2), w_stats(2)
      type(error_type), allocatable :: error
      real(wp) :: dt, limit
      integer :: i

      call langevin_time_step(naf_tip(model_inertial, 0.0_wp), 0.0_wp, dt, limit, error)
      call fail_on(failure, error)
      if (allocated(failure)) return
      call sample_flat(model_inertial, dt, 16.0_wp, 101_i8, u_stats, w_stats, failure)
      if (allocated(failure)) return
      do i = 1, 2
         call check_axis(failure, 'inertial, h = '//trim(fmt(dt))//' s,', i, model_inertial, dt, &
            & u_stats(i), w_stats(i))
      end do
   end subroutine equipartition_inertial

   !> ωh = 1 (γh = 3.2): k<δu²> still k_B T, m<δr'²> = 0.75 k_B T, the drag
   !> shift × 0.58 — BAOAB's signature (ABOBA, say, has the velocity exact
   !> and the position off).
   subroutine baoab_large_step(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(block_average) :: u_stats(2), w_stats(2)
      real(wp) :: dt
      integer :: i

      dt = 1.0_wp / sqrt(naf_spring / naf_mass)
      call sample_flat(model_inertial, dt, 256.0_wp, 102_i8, u_stats, w_stats, failure)
      if (allocated(failure)) return
      do i = 1, 2
         call check_axis(failure, 'inertial, omega h = 1,', i, model_inertial, dt, u_stats(i), w_stats(i))
      end do
   end subroutine baoab_large_step

   !> Default step (κh = 0.05), 16 s.
   subroutine equipartition_overdamped(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(block_average) :: u_stats(2), w_stats(2)
      type(error_type), allocatable :: error
      real(wp) :: dt, limit
      integer :: i

      call langevin_time_step(naf_tip(model_overdamped, 0.0_wp), 0.0_wp, dt, limit, error)
      call fail_on(failure, error)
      if (allocated(failure)) return
      call sample_flat(model_overdamped, dt, 16.0_wp, 103_i8, u_stats, w_stats, failure)
      if (allocated(failure)) return
      do i = 1, 2
         call check_axis(failure, 'overdamped, h = '//trim(fmt(dt))//' s,', i, model_overdamped, dt, &
            & u_stats(i), w_stats(i))
      end do
   end subroutine equipartition_overdamped

   !> κh = kh/c = 1: Leimkuhler–Matthews still gives k_B T (Euler–Maruyama
   !> would give 2 k_B T).
   subroutine overdamped_large_step(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(block_average) :: u_stats(2), w_stats(2)
      real(wp) :: dt
      integer :: i

      dt = naf_damping / naf_spring
      call sample_flat(model_overdamped, dt, 256.0_wp, 104_i8, u_stats, w_stats, failure)
      if (allocated(failure)) return
      do i = 1, 2
         call check_axis(failure, 'overdamped, kh/c = 1,', i, model_overdamped, dt, u_stats(i), w_stats(i))
      end do
   end subroutine overdamped_large_step

   !> At T = 0 no variates are drawn and both schemes follow the
   !> deterministic tip: on a flat surface u relaxes to the drag shift (the
   !> discrete fixed point), and an uninitialised stream is never touched.
   subroutine deterministic_limit(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(afm_tip) :: tip
      type(langevin_integrator) :: integrator
      type(langevin_state) :: state
      type(random_stream) :: none
      type(error_type), allocatable :: error
      real(wp) :: dt, gamma_h, shift
      integer :: model, i

      do model = model_inertial, model_overdamped
         tip = naf_tip(model, 0.0_wp)
         tip%support_velocity(1:2) = support_velocity
         dt = 1.0e-6_wp
         call integrator%init(tip, 0.0_wp, dt, error)
         call fail_on(failure, error)
         if (allocated(failure)) return
         call integrator%start(none, 0.0_wp, [0.0_wp, 0.0_wp], state)
         call integrator%advance(tip, none, state, 200000, error)   ! 2000 c/k
         call fail_on(failure, error)
         if (allocated(failure)) return
         do i = 1, 2
            shift = -naf_damping * support_velocity(i) / naf_spring
            if (model == model_inertial) then
               gamma_h = naf_damping / naf_mass * dt
               shift = shift * tanh(0.5_wp * gamma_h) / (0.5_wp * gamma_h)
               call check_close(failure, state%velocity(i), support_velocity(i), 1.0e-9_wp * 4000, &
                  & 'T = 0 inertial: r'' at rest in the support''s frame')
            end if
            call check_close(failure, state%u(i), shift, 1.0e-12_wp, 'T = 0: u at the drag shift')
         end do
      end do
   end subroutine deterministic_limit

   !> 3000 steps in one call, or in calls of 1, 7 and 992 steps: bitwise the
   !> same (on NaF with V0 = 1 eV, so the force changes along the path).
   subroutine split_calls(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(afm_tip) :: tip
      type(langevin_integrator) :: integrator
      type(langevin_state) :: one, many
      type(random_stream) :: s1, s2
      type(error_type), allocatable :: error
      real(wp) :: dt, limit, curvature
      integer :: model, k

      do model = model_inertial, model_overdamped
         tip = naf_tip(model, 1.0_wp)
         tip%support_velocity(1:2) = [400.0_wp, 0.0_wp]
         tip%support_start(1:2) = [0.3_wp, 0.8_wp]
         curvature = largest_curvature(tip%potential, [0.0_wp, 0.0_wp], [4.62_wp, 4.62_wp], 32)
         call langevin_time_step(tip, curvature, dt, limit, error)
         if (.not. allocated(error)) call integrator%init(tip, temperature, dt, error, curvature=curvature)
         if (.not. allocated(error)) call s1%init(5_i8, 3, 1, 0, error)
         if (.not. allocated(error)) call s2%init(5_i8, 3, 1, 0, error)
         call fail_on(failure, error)
         if (allocated(failure)) return
         call integrator%start(s1, 0.0_wp, [0.0_wp, 0.0_wp], one)
         call integrator%start(s2, 0.0_wp, [0.0_wp, 0.0_wp], many)
         call integrator%advance(tip, s1, one, 3000, error)
         do k = 1, 3
            call integrator%advance(tip, s2, many, 1, error)
            call integrator%advance(tip, s2, many, 7, error)
            call integrator%advance(tip, s2, many, 992, error)
         end do
         call check(failure, all(one%u == many%u) .and. all(one%velocity == many%velocity) .and. &
            & one%steps == many%steps, 'split calls differ from one call')
         call check(failure, integrator%time_of(one) == 3000 * dt, 'time after 3000 steps')
      end do
   end subroutine split_calls

   !> The step helper: NaF's largest curvature V0 (2π/a)² = 1.8496 eV/Å²
   !> (sampled on 32² points: to 1 %), the limits 2/ω_max and 2c/k_eff, and
   !> init refusing a step at the limit.
   subroutine time_step(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(afm_tip) :: tip
      type(langevin_integrator) :: integrator
      type(error_type), allocatable :: error
      real(wp) :: curvature, dt, limit, exact, k_eff

      tip = naf_tip(model_inertial, 1.0_wp)
      exact = (2.0_wp * pi / 4.62_wp)**2
      curvature = largest_curvature(tip%potential, [0.0_wp, 0.0_wp], [4.62_wp, 4.62_wp], 32)
      call check_close(failure, curvature, exact, 0.01_wp * exact, 'largest NaF curvature')
      k_eff = naf_spring + curvature
      call langevin_time_step(tip, curvature, dt, limit, error)
      call fail_on(failure, error)
      call check_close(failure, limit, 2.0_wp / sqrt(k_eff / naf_mass), 1.0e-12_wp * limit, 'inertial limit')
      call check_close(failure, dt, 0.05_wp * min(sqrt(naf_mass / k_eff), naf_mass / naf_damping), 1.0e-12_wp * dt, &
         & 'inertial default step')
      call integrator%init(tip, temperature, limit, error, curvature=curvature)
      call check(failure, allocated(error), 'a step at the stability limit accepted')
      call integrator%init(tip, temperature, 0.99_wp * limit, error, curvature=curvature)
      call check(failure, .not. allocated(error), 'a step below the stability limit refused')
      tip%model = model_overdamped
      call langevin_time_step(tip, curvature, dt, limit, error)
      call fail_on(failure, error)
      call check_close(failure, limit, 2.0_wp * naf_damping / k_eff, 1.0e-12_wp * limit, 'overdamped limit')
      call check_close(failure, dt, 0.05_wp * naf_damping / k_eff, 1.0e-12_wp * dt, 'overdamped default step')
   end subroutine time_step

   !> Bad input is an input error, a blown-up state a numerical one.
   subroutine rejects(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(afm_tip) :: tip
      type(langevin_integrator) :: integrator
      type(langevin_state) :: state
      type(random_stream) :: stream
      type(error_type), allocatable :: error
      real(wp) :: record(2, 10)

      tip = naf_tip(model_inertial, 1.0_wp)
      tip%damping(2) = 0.0_wp
      call integrator%init(tip, temperature, 1.0e-7_wp, error)
      call check(failure, is_input_error(error), 'an undamped axis at T > 0 accepted')
      call integrator%init(tip, 0.0_wp, 1.0e-7_wp, error)
      call check(failure, .not. allocated(error), 'an undamped axis at T = 0 refused')
      tip = naf_tip(model_overdamped, 1.0_wp)
      tip%damping(1) = 0.0_wp
      call integrator%init(tip, 0.0_wp, 1.0e-7_wp, error)
      call check(failure, is_input_error(error), 'an undamped overdamped tip accepted')
      tip = naf_tip(model_inertial, 1.0_wp)
      call integrator%init(tip, -1.0_wp, 1.0e-7_wp, error)
      call check(failure, is_input_error(error), 'a negative temperature accepted')
      call integrator%init(tip, temperature, 0.0_wp, error)
      call check(failure, is_input_error(error), 'a zero step accepted')
      tip%mass = 0.0_wp
      call integrator%init(tip, temperature, 1.0e-7_wp, error)
      call check(failure, is_input_error(error), 'a zero mass accepted')
      tip = naf_tip(model_quasistatic, 1.0_wp)
      call integrator%init(tip, temperature, 1.0e-7_wp, error)
      call check(failure, is_input_error(error), 'the quasistatic model accepted')
      ! Overdamped: no velocities to record; records too small.
      tip = naf_tip(model_overdamped, 1.0_wp)
      call integrator%init(tip, temperature, 1.0e-7_wp, error)
      call stream%init(1_i8, 0, 0, 0, error)
      call integrator%start(stream, 0.0_wp, [0.0_wp, 0.0_wp], state)
      call integrator%advance(tip, stream, state, 10, error, velocities=record)
      call check(failure, is_input_error(error), 'overdamped velocities recorded')
      call integrator%advance(tip, stream, state, 11, error, positions=record)
      call check(failure, is_input_error(error), 'a record too small accepted')
      ! A step 100 times the stability limit on NaF: the state blows up.
      tip = naf_tip(model_inertial, 1.0_wp)
      call integrator%init(tip, temperature, 100 * 2.0_wp * sqrt(naf_mass / naf_spring), error)
      call integrator%start(stream, 0.0_wp, [0.3_wp, 0.1_wp], state)
      call integrator%advance(tip, stream, state, 5000, error)
      call check(failure, allocated(error), 'a blown-up state not reported')
      if (allocated(error)) call check(failure, error%stat == error_numerical, 'blow-up not a numerical error')
      call stream%free()
   end subroutine rejects

   logical function is_input_error(error)
      type(error_type), allocatable, intent(in) :: error

      is_input_error = .false.
      if (allocated(error)) is_input_error = error%stat == error_input
   end function is_input_error

   character(len=16) function fmt(x)
      real(wp), intent(in) :: x

      write (fmt, '(es9.2)') x
      fmt = adjustl(fmt)
   end function fmt

   !> Mean first passage time (s) and its standard error from the minimum
   !> of the tilted washboard with the given barrier (k_B T units) to
   !> halfway down into the next well, over nreal realizations with step
   !> fraction × the fastest time scale; and the Langer rate of
   !> friction_afm_kramers, the exact overdamped MFPT (Pontryagin) and the
   !> step used.
   subroutine escape_times(model, barrier_kt, nreal, fraction, seed, mean, se, rate, exact, dt, damping, failure)
      integer, intent(in) :: model, nreal
      real(wp), intent(in) :: barrier_kt, fraction
      integer(i8), intent(in) :: seed
      real(wp), intent(out) :: mean, se, rate, exact, dt, damping
      character(len=:), allocatable, intent(inout) :: failure
      integer, parameter :: chunk = 256
      real(wp), parameter :: a = 4.62_wp, tilt_ratio = 0.3_wp
      type(tilted_washboard) :: surface
      type(afm_tip) :: tip
      type(langevin_integrator) :: integrator
      type(langevin_state) :: state
      type(random_stream) :: stream
      type(error_type), allocatable :: error
      real(wp) :: s_min, s_saddle, curvature, limit, target, u_min(1), u_saddle(1), sum1, sum2, tau
      real(wp) :: path(1, chunk)
      integer(i8) :: steps, cap
      integer :: r, j

      mean = 0.0_wp
      se = 0.0_wp
      rate = 0.0_wp
      exact = 0.0_wp
      dt = 0.0_wp
      damping = 0.0_wp
      call washboard_points(a, tilt_ratio, barrier_kt * kt, surface, s_min, s_saddle, curvature)
      tip%ndim = 1
      tip%model = model
      allocate (tip%potential, source=surface)
      if (model == model_inertial) then
         tip%mass = naf_mass
         tip%damping(1) = naf_mass * sqrt(curvature / naf_mass)   ! γ = ω_b
      else
         tip%damping(1) = naf_damping
      end if
      call langevin_time_step(tip, surface%u0 * surface%q**2, dt, limit, error, fraction=fraction)
      if (.not. allocated(error)) call integrator%init(tip, temperature, dt, error)
      ! The rate as the thermal_jumps model will get it: minimum and saddle
      ! found from a guess off the minimum.
      if (.not. allocated(error)) call find_minimum(tip, 0.0_wp, [s_min + 0.4_wp], u_min, error)
      if (.not. allocated(error)) call find_saddle(tip, 0.0_wp, u_min, [1.0_wp], u_saddle, error)
      if (.not. allocated(error)) call langer_rate(tip, 0.0_wp, u_min, u_saddle, temperature, rate, error)
      call fail_on(failure, error)
      if (allocated(failure)) return
      call check_close(failure, u_min(1), s_min, 1.0e-9_wp, 'washboard minimum')
      call check_close(failure, u_saddle(1), s_saddle, 1.0e-9_wp, 'washboard saddle')
      target = 0.5_wp * (s_saddle + s_min + a)
      damping = tip%damping(1)
      exact = pontryagin_mfpt(surface, damping, s_min, target, a)
      cap = int(200.0_wp / rate / dt, i8)
      sum1 = 0.0_wp
      sum2 = 0.0_wp
      do r = 0, nreal - 1
         call stream%init(seed, 0, 0, r, error)
         call fail_on(failure, error)
         if (allocated(failure)) return
         call integrator%start(stream, 0.0_wp, [s_min], state)
         steps = 0
         passage: do
            call integrator%advance(tip, stream, state, chunk, error, positions=path)
            call fail_on(failure, error)
            if (allocated(failure)) return
            do j = 1, chunk
               if (path(1, j) >= target) exit passage
            end do
            steps = steps + chunk
            if (steps > cap) then
               failure = 'no escape within 200 Kramers times'
               return
            end if
         end do passage
         tau = real(steps + j, wp) * dt
         sum1 = sum1 + tau
         sum2 = sum2 + tau**2
      end do
      call stream%free()
      mean = sum1 / nreal
      se = sqrt(max(sum2 / nreal - mean**2, 0.0_wp) / (nreal - 1))
   end subroutine escape_times

   !> The exact MFPT of c x' = -V'(x) + ξ from x0 to target (reflecting at
   !> -∞, where the tilt raises V):
   !>   τ = (c/k_B T) ∫_{x0}^{target} dy e^{V(y)/k_B T} ∫_{-∞}^{y} e^{-V(z)/k_B T} dz,
   !> by the trapezoidal rule on 1e5 points a period (relative error ~1e-9);
   !> the inner integral starts 4 periods below x0.
   function pontryagin_mfpt(surface, c, x0, target, a) result(tau)
      type(tilted_washboard), intent(in) :: surface
      real(wp), intent(in) :: c, x0, target, a
      real(wp) :: tau
      real(wp) :: h, inner, y, v0, e_prev, e_now, outer_prev, outer_now
      integer :: n_low, n_high, i

      v0 = surface%energy([x0, 0.0_wp, 0.0_wp])
      n_high = nint((target - x0) / a * 1.0e5_wp)
      h = (target - x0) / n_high
      n_low = nint(4.0_wp * a / h)
      inner = 0.0_wp
      tau = 0.0_wp
      y = x0 - n_low * h
      e_prev = exp(-(surface%energy([y, 0.0_wp, 0.0_wp]) - v0) / kt)
      outer_prev = 0.0_wp
      do i = -n_low + 1, n_high
         y = x0 + i * h
         e_now = exp(-(surface%energy([y, 0.0_wp, 0.0_wp]) - v0) / kt)
         inner = inner + 0.5_wp * h * (e_prev + e_now)
         e_prev = e_now
         outer_now = inner / e_now
         if (i >= 1) tau = tau + 0.5_wp * h * (outer_prev + outer_now)
         outer_prev = outer_now
      end do
      tau = tau * c / kt
   end function pontryagin_mfpt

   !> Checks and prints an escape run against Kramers (and the exact MFPT).
   subroutine check_escape(failure, label, model, barrier_kt, nreal, fraction, seed, bias_per_step)
      character(len=:), allocatable, intent(inout) :: failure
      character(len=*), intent(in) :: label
      integer, intent(in) :: model, nreal
      real(wp), intent(in) :: barrier_kt, fraction, bias_per_step
      integer(i8), intent(in) :: seed
      real(wp) :: mean, se, rate, exact, dt, correction, bias, damping

      call escape_times(model, barrier_kt, nreal, fraction, seed, mean, se, rate, exact, dt, damping, failure)
      if (allocated(failure)) return
      ! Kramers' finite-barrier correction for this landscape, exact in the
      ! overdamped limit: τ_exact r_K - 1 with r_K the Smoluchowski rate, both
      ! for the damping the MFPT was computed with (the ratio is independent
      ! of it).
      correction = exact * overdamped_kramers(barrier_kt, damping) - 1.0_wp
      bias = bias_per_step * fraction
      write (*, '(2x, a, a, i0, a, es9.2, a, f7.4, a, f6.4, a, f7.4)') label, ': ', nreal, &
         & ' escapes, h = ', dt, ' s: tau r_K = ', mean * rate, ' +- ', se * rate, &
         & ', finite-barrier correction ', correction
      if (model == model_overdamped) then
         write (*, '(2x, a, a, f7.4, a, f6.4, a, f6.4, a)') label, ': tau/tau_exact = ', mean / exact, ' +- ', &
            & se / exact, ' (step bias allowed: ', bias, ')'
         call check_close(failure, mean / exact, 1.0_wp + 0.5_wp * bias, 3.0_wp * se / exact + 0.5_wp * bias, &
            & label//': MFPT / exact MFPT')
         call check_close(failure, mean * rate, 1.0_wp + correction + 0.5_wp * bias, &
            & 3.0_wp * se * rate + 0.5_wp * bias, label//': MFPT x Kramers rate')
      else
         call check_close(failure, mean * rate, 1.0_wp + correction, 3.0_wp * se * rate + abs(correction) + bias, &
            & label//': MFPT x Kramers rate')
      end if
   end subroutine check_escape

   !> The Smoluchowski–Kramers rate sqrt(κ0 κb)/(2πc) e^{-ΔE/kT} of the
   !> escape landscape with damping c, in closed form (κ0 = κb).
   real(wp) function overdamped_kramers(barrier_kt, c)
      real(wp), intent(in) :: barrier_kt, c
      type(tilted_washboard) :: surface
      real(wp) :: s_min, s_saddle, curvature

      call washboard_points(4.62_wp, 0.3_wp, barrier_kt * kt, surface, s_min, s_saddle, curvature)
      overdamped_kramers = curvature / (2.0_wp * pi * c) * exp(-barrier_kt)
   end function overdamped_kramers

   subroutine escape_inertial_5kt(failure)
      character(len=:), allocatable, intent(out) :: failure
      call check_escape(failure, 'inertial, 5 kT', model_inertial, 5.0_wp, 4000, 0.1_wp, 501_i8, 0.0_wp)
   end subroutine escape_inertial_5kt

   subroutine escape_inertial_10kt(failure)
      character(len=:), allocatable, intent(out) :: failure
      call check_escape(failure, 'inertial, 10 kT', model_inertial, 10.0_wp, 200, 0.2_wp, 1001_i8, 0.0_wp)
   end subroutine escape_inertial_10kt

   subroutine escape_overdamped_5kt(failure)
      character(len=:), allocatable, intent(out) :: failure
      call check_escape(failure, 'overdamped, 5 kT', model_overdamped, 5.0_wp, 4000, 0.05_wp, 502_i8, 1.0_wp)
   end subroutine escape_overdamped_5kt

   subroutine escape_overdamped_10kt(failure)
      character(len=:), allocatable, intent(out) :: failure
      call check_escape(failure, 'overdamped, 10 kT', model_overdamped, 10.0_wp, 200, 0.1_wp, 1002_i8, 1.0_wp)
   end subroutine escape_overdamped_10kt

end program test_langevin
