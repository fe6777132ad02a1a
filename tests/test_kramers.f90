!> Escape rates and jump times (friction_afm_kramers) against closed forms
!> and independent computations:
!>   - stationary points of the tilted washboard (closed forms, 1e-9 Å) from
!>     guesses across the well;
!>   - a washboard turned by 30° in 2D with an isotropic spring, searched
!>     along x: the saddle and the Langer rate equal the 1D problem along the
!>     washboard's normal (found here by bisection, rate in closed form);
!>   - the unstable growth rate: Kramers' 1D roots, the undamped and
!>     overdamped limits, and a 2D pencil with anisotropic damping (det = 0,
!>     one positive root);
!>   - NaF with inputs/naf.nml's tip: the saddle ahead is stationary and of
!>     index 1 by finite differences of the energy alone, and joins the
!>     tip's well to the next one;
!>   - the KMC hazard on a Prandtl–Tomlinson tip (η = 4) at 1 Å/s against a
!>     dense Simpson quadrature of the closed-form 1D rate, and at rest
!>     against target/r;
!>   - KMC jump times against the Langevin tip's on the same tip.
program test_kramers
   use friction_kinds, only: wp, i8, pi
   use friction_error, only: error_type
   use friction_random, only: random_stream
   use friction_symmetric, only: symmetric_eigen, determinant
   use friction_afm_tip, only: afm_tip, model_inertial, model_overdamped
   use friction_afm_langevin, only: boltzmann, langevin_integrator, langevin_state, langevin_time_step
   use friction_afm_kramers, only: find_minimum, find_saddle, unstable_growth_rate, langer_rate, &
      & jump_landing, landscape_energy, landscape_gradient, hazard_path, hazard_start, hazard_advance, &
      & hazard_running, hazard_jumped, hazard_low_barrier
   use thermal_support, only: tilted_washboard, washboard_points, naf_tip, naf_mass, naf_damping
   use testing, only: test_suite, check, check_close
   implicit none

   real(wp), parameter :: temperature = 300.0_wp, kt = boltzmann * temperature
   real(wp), parameter :: lattice = 4.62_wp
   !> The Prandtl–Tomlinson tip of the hazard tests: U0 = 0.2 eV, η = 4,
   !> NaF's mass, damping rate γ = 3e4 /s, support at 1 Å/s from where the
   !> barrier is 12 k_B T.
   real(wp), parameter :: pt_u0 = 0.2_wp, pt_eta = 4.0_wp, pt_gamma = 3.0e4_wp, pt_velocity = 1.0_wp
   type(test_suite) :: suite

   suite%name = 'kramers'
   call suite%add('washboard_points', washboard_stationary)
   call suite%add('rotated_2d', rotated_2d)
   call suite%add('growth_rate', growth_rate)
   call suite%add('naf_saddle', naf_saddle)
   call suite%add('hazard_quadrature', hazard_quadrature)
   call suite%add('hazard_at_rest', hazard_at_rest)
   call suite%add('kmc_vs_langevin', kmc_vs_langevin)
   call suite%run_all()

contains

   subroutine fail_on(failure, error)
      character(len=:), allocatable, intent(inout) :: failure
      type(error_type), allocatable, intent(in) :: error

      if (allocated(error) .and. .not. allocated(failure)) failure = error%message
   end subroutine fail_on

   !> Tilt ratios 0, 0.3, 0.7; guesses from the bottom to near the saddle.
   subroutine washboard_stationary(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(tilted_washboard) :: w
      type(afm_tip) :: tip
      type(error_type), allocatable :: error
      real(wp), parameter :: ratios(3) = [0.0_wp, 0.3_wp, 0.7_wp]
      real(wp) :: f, s_min, s_saddle, curvature, u(1), us(1), rate, barrier, prefactor, guess
      integer :: i, k

      do i = 1, 3
         f = ratios(i)
         call washboard_points(lattice, f, 0.2_wp, w, s_min, s_saddle, curvature)
         tip%ndim = 1
         tip%model = model_overdamped
         tip%damping(1) = naf_damping
         if (allocated(tip%potential)) deallocate (tip%potential)
         allocate (tip%potential, source=w)
         do k = 0, 4
            guess = s_min + (s_saddle - s_min) * (-0.4_wp + 0.3_wp * k)
            call find_minimum(tip, 0.0_wp, [guess], u, error)
            call fail_on(failure, error)
            if (allocated(failure)) return
            call check_close(failure, u(1), s_min, 1.0e-9_wp, 'washboard minimum')
         end do
         call find_saddle(tip, 0.0_wp, u, [1.0_wp], us, error)
         call fail_on(failure, error)
         if (allocated(failure)) return
         call check_close(failure, us(1), s_saddle, 1.0e-9_wp, 'washboard saddle')
         call langer_rate(tip, 0.0_wp, u, us, temperature, rate, error, barrier=barrier, prefactor=prefactor)
         call fail_on(failure, error)
         call check_close(failure, barrier, 0.2_wp, 1.0e-12_wp, 'washboard barrier')
         ! Smoluchowski: κ/(2πc) with κ0 = κb.
         call check_close(failure, prefactor, curvature / (2 * pi * naf_damping), 1.0e-9_wp * prefactor, &
            & 'overdamped prefactor')
         call check_close(failure, rate, prefactor * exp(-0.2_wp / kt), 1.0e-12_wp * rate, 'rate')
      end do
   end subroutine washboard_stationary

   !> The 1D problem along n: E(s) = -U0 cos(qs) - F s + ½ k s².
   subroutine line_points(w, k, s_min, s_saddle)
      type(tilted_washboard), intent(in) :: w
      real(wp), intent(in) :: k
      real(wp), intent(out) :: s_min, s_saddle
      real(wp) :: s, g_prev, g, ds
      integer :: i, found

      ds = 1.0e-3_wp
      found = 0
      s_min = 0.0_wp
      s_saddle = 0.0_wp
      s = -0.25_wp * lattice
      g_prev = line_slope(w, k, s)
      do i = 1, 8000
         g = line_slope(w, k, s + ds)
         if (g_prev < 0.0_wp .and. g >= 0.0_wp .and. found == 0) then
            s_min = bisect_slope(w, k, 0.0_wp, s, s + ds)
            found = 1
         else if (g_prev > 0.0_wp .and. g <= 0.0_wp .and. found == 1) then
            s_saddle = bisect_slope(w, k, 0.0_wp, s, s + ds)
            return
         end if
         s = s + ds
         g_prev = g
      end do
   end subroutine line_points

   !> dE/ds of -U0 cos(qs) - F s + ½ k (s - s0)².
   pure real(wp) function line_slope(w, k, s, s0)
      type(tilted_washboard), intent(in) :: w
      real(wp), intent(in) :: k, s
      real(wp), intent(in), optional :: s0
      real(wp) :: centre

      centre = 0.0_wp
      if (present(s0)) centre = s0
      line_slope = w%u0 * w%q * sin(w%q * s) - w%tilt + k * (s - centre)
   end function line_slope

   !> The zero of line_slope in [lo, hi] (a sign change), by bisection.
   pure real(wp) function bisect_slope(w, k, s0, lo, hi)
      type(tilted_washboard), intent(in) :: w
      real(wp), intent(in) :: k, s0, lo, hi
      real(wp) :: a, b, m
      integer :: j

      a = lo
      b = hi
      do j = 1, 200
         m = 0.5_wp * (a + b)
         if (sign(1.0_wp, line_slope(w, k, m, s0)) == sign(1.0_wp, line_slope(w, k, a, s0))) then
            a = m
         else
            b = m
         end if
      end do
      bisect_slope = 0.5_wp * (a + b)
   end function bisect_slope

   !> Kramers' 1D rate in closed form: inertial (λ₊ = sqrt(γ²/4 + ω_b²) - γ/2)
   !> or overdamped (λ₊ = κ_b/c), times sqrt(κ0/κb) e^{-ΔE/kT}/2π.
   real(wp) function kramers_1d(model, mass, c, kappa_min, kappa_saddle, barrier)
      integer, intent(in) :: model
      real(wp), intent(in) :: mass, c, kappa_min, kappa_saddle, barrier
      real(wp) :: lambda, gamma

      if (model == model_inertial) then
         gamma = c / mass
         lambda = sqrt(gamma**2 / 4 + abs(kappa_saddle) / mass) - gamma / 2
      else
         lambda = abs(kappa_saddle) / c
      end if
      kramers_1d = lambda / (2 * pi) * sqrt(kappa_min / abs(kappa_saddle)) * exp(-barrier / kt)
   end function kramers_1d

   subroutine rotated_2d(failure)
      character(len=:), allocatable, intent(out) :: failure
      real(wp), parameter :: k = 0.05_wp, angle = pi / 6
      type(tilted_washboard) :: w
      type(afm_tip) :: tip
      type(error_type), allocatable :: error
      real(wp) :: n(2), s_min, s_saddle, dummy(3), u(2), us(2), rate, barrier, expected, e_min, e_s
      integer :: model

      call washboard_points(lattice, 0.3_wp, 0.25_wp, w, dummy(1), dummy(2), dummy(3))
      n = [cos(angle), sin(angle)]
      w%normal = [n(1), n(2), 0.0_wp]
      call line_points(w, k, s_min, s_saddle)
      do model = model_inertial, model_overdamped
         tip%ndim = 2
         tip%model = model
         tip%mass = naf_mass
         tip%spring(1:2) = k
         tip%damping(1:2) = naf_damping
         if (allocated(tip%potential)) deallocate (tip%potential)
         allocate (tip%potential, source=w)
         call find_minimum(tip, 0.0_wp, [0.3_wp, -0.2_wp], u, error)
         if (.not. allocated(error)) call find_saddle(tip, 0.0_wp, u, [1.0_wp, 0.0_wp], us, error)
         if (.not. allocated(error)) call langer_rate(tip, 0.0_wp, u, us, temperature, rate, error, barrier=barrier)
         call fail_on(failure, error)
         if (allocated(failure)) return
         call check_close(failure, norm2(u - s_min * n), 0.0_wp, 1.0e-9_wp, '2D minimum on the normal')
         call check_close(failure, norm2(us - s_saddle * n), 0.0_wp, 1.0e-9_wp, '2D saddle on the normal')
         e_min = -w%u0 * cos(w%q * s_min) - w%tilt * s_min + 0.5_wp * k * s_min**2
         e_s = -w%u0 * cos(w%q * s_saddle) - w%tilt * s_saddle + 0.5_wp * k * s_saddle**2
         call check_close(failure, barrier, e_s - e_min, 1.0e-12_wp, '2D barrier')
         expected = kramers_1d(model, naf_mass, naf_damping, w%u0 * w%q**2 * cos(w%q * s_min) + k, &
            & w%u0 * w%q**2 * cos(w%q * s_saddle) + k, e_s - e_min)
         call check_close(failure, rate, expected, 1.0e-8_wp * expected, '2D Langer rate = 1D Kramers rate')
      end do
   end subroutine rotated_2d

   subroutine growth_rate(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(afm_tip) :: tip
      type(error_type), allocatable :: error
      real(wp) :: lambda, kappa, gamma, h(2, 2), rot(2, 2), a(2, 2), values(2), vectors(2, 2), d_prev, d, x
      real(wp), parameter :: dampings(3) = [0.0_wp, 1.0e-5_wp, 1.0e-3_wp]
      integer, parameter :: models(2) = [model_inertial, model_overdamped]
      integer :: changes, i, j

      kappa = 0.7_wp
      tip%ndim = 1
      tip%model = model_inertial
      tip%mass = naf_mass
      do i = 1, 3
         tip%damping(1) = dampings(i)
         call unstable_growth_rate(tip, reshape([-kappa], [1, 1]), lambda, error)
         call fail_on(failure, error)
         gamma = tip%damping(1) / naf_mass
         call check_close(failure, lambda, sqrt(gamma**2 / 4 + kappa / naf_mass) - gamma / 2, &
            & 1.0e-12_wp * sqrt(kappa / naf_mass), 'Kramers 1D growth rate')
      end do
      tip%model = model_overdamped
      tip%damping(1) = naf_damping
      call unstable_growth_rate(tip, reshape([-kappa], [1, 1]), lambda, error)
      call fail_on(failure, error)
      call check_close(failure, lambda, kappa / naf_damping, 1.0e-12_wp * lambda, 'overdamped growth rate')
      ! 2D: H = R diag(-0.4, 1.3) Rᵀ (R by 0.6 rad), c = (1e-4, 3e-5), m.
      rot = reshape([cos(0.6_wp), sin(0.6_wp), -sin(0.6_wp), cos(0.6_wp)], [2, 2])
      h = matmul(rot, matmul(reshape([-0.4_wp, 0.0_wp, 0.0_wp, 1.3_wp], [2, 2]), transpose(rot)))
      tip%ndim = 2
      tip%damping(1:2) = [1.0e-4_wp, 3.0e-5_wp]
      do i = 1, 2
         tip%model = models(i)
         call unstable_growth_rate(tip, h, lambda, error)
         call fail_on(failure, error)
         if (allocated(failure)) return
         a = h
         a(1, 1) = a(1, 1) + lambda * tip%damping(1)
         a(2, 2) = a(2, 2) + lambda * tip%damping(2)
         if (tip%model == model_inertial) then
            a(1, 1) = a(1, 1) + lambda**2 * naf_mass
            a(2, 2) = a(2, 2) + lambda**2 * naf_mass
         end if
         call symmetric_eigen(a, values, vectors)
         call check(failure, lambda > 0.0_wp .and. minval(abs(values)) < 1.0e-10_wp * maxval(abs(values)), &
            & '2D pencil not singular at the growth rate')
         ! one sign change of det over (0, 100 λ]
         changes = 0
         d_prev = determinant(h)
         do j = 1, 20000
            x = 100.0_wp * lambda * j / 20000
            a = h
            a(1, 1) = a(1, 1) + x * tip%damping(1)
            a(2, 2) = a(2, 2) + x * tip%damping(2)
            if (tip%model == model_inertial) then
               a(1, 1) = a(1, 1) + x**2 * naf_mass
               a(2, 2) = a(2, 2) + x**2 * naf_mass
            end if
            d = determinant(a)
            if (sign(1.0_wp, d) /= sign(1.0_wp, d_prev)) changes = changes + 1
            d_prev = d
         end do
         call check(failure, changes == 1, '2D pencil: not exactly one positive root')
      end do
      ! A minimum is no saddle.
      tip%model = model_inertial
      call unstable_growth_rate(tip, reshape([1.0_wp, 0.0_wp, 0.0_wp, 2.0_wp], [2, 2]), lambda, error)
      call check(failure, allocated(error), 'a minimum''s Hessian accepted as a saddle')
   end subroutine growth_rate

   !> NaF, inputs/naf.nml's tip (η = 2.96), support off the row at
   !> (1.2, 0.8) Å, where E rises all along x from the tip's well (the
   !> search climbs from the minimum; the saddle is the diagonal one, near
   !> (a/4, a/4)), and at (2.5, 0.8) Å (from the line's maximum): the saddle
   !> ahead is stationary and of index 1 by finite differences of the energy
   !> alone, and joins the tip's well to another.
   subroutine naf_saddle(failure)
      character(len=:), allocatable, intent(out) :: failure
      real(wp), parameter :: fd = 1.0e-4_wp, fd2 = 1.0e-3_wp
      real(wp), parameter :: supports(2, 2) = reshape([1.2_wp, 0.8_wp, 2.5_wp, 0.8_wp], [2, 2])
      type(afm_tip) :: tip
      type(error_type), allocatable :: error
      real(wp) :: u(2), us(2), back(2), ahead(2), g(2), h(2, 2), values(2), vectors(2, 2), e(2, 2), rate, barrier
      integer :: i, j, k

      tip = naf_tip(model_inertial, 1.0_wp)
      tip%support_velocity(1:2) = [400.0_wp, 0.0_wp]
      e = reshape([1.0_wp, 0.0_wp, 0.0_wp, 1.0_wp], [2, 2])
      do k = 1, 2
         tip%support_start(1:2) = supports(:, k)
         call find_minimum(tip, 0.0_wp, [0.0_wp, 0.0_wp], u, error)
         if (.not. allocated(error)) call find_saddle(tip, 0.0_wp, u, tip%support_velocity(1:2), us, error)
         if (.not. allocated(error)) call langer_rate(tip, 0.0_wp, u, us, temperature, rate, error, barrier=barrier)
         call fail_on(failure, error)
         if (allocated(failure)) return
         do i = 1, 2
            g(i) = (landscape_energy(tip, 0.0_wp, us + fd * e(:, i)) &
               & - landscape_energy(tip, 0.0_wp, us - fd * e(:, i))) / (2 * fd)
            do j = 1, 2
               h(i, j) = (landscape_energy(tip, 0.0_wp, us + fd2 * (e(:, i) + e(:, j))) &
                  & - landscape_energy(tip, 0.0_wp, us + fd2 * (e(:, i) - e(:, j))) &
                  & - landscape_energy(tip, 0.0_wp, us - fd2 * (e(:, i) - e(:, j))) &
                  & + landscape_energy(tip, 0.0_wp, us - fd2 * (e(:, i) + e(:, j)))) / (4 * fd2**2)
            end do
         end do
         call symmetric_eigen(h, values, vectors)
         write (*, '(2x, a, 2f5.2, a, 2f9.5, a, 2f9.5, a, f8.5, a, es10.3, a)') 'NaF, support (', supports(:, k), &
            & ') A: minimum u = (', u, ') A, saddle (', us, ') A, barrier ', barrier, ' eV, rate ', rate, ' /s'
         call check(failure, norm2(g) < 1.0e-6_wp, 'NaF saddle: finite-difference gradient not zero')
         call check(failure, values(1) < -0.01_wp .and. values(2) > 0.01_wp, 'NaF saddle: not of index 1')
         call check(failure, barrier > 0.0_wp .and. us(1) > u(1), 'NaF saddle: not ahead and above')
         ! Down from the saddle: back into the well on one side, into
         ! another minimum on the other.
         call find_minimum(tip, 0.0_wp, us + 0.05_wp * (u - us) / norm2(u - us), back, error)
         if (.not. allocated(error)) call jump_landing(tip, 0.0_wp, u, us, ahead, error)
         call fail_on(failure, error)
         if (allocated(failure)) return
         call check_close(failure, norm2(back - u), 0.0_wp, 1.0e-8_wp, 'NaF saddle: back into the well')
         call check(failure, norm2(ahead - u) > 1.0_wp .and. &
            & landscape_energy(tip, 0.0_wp, ahead) < landscape_energy(tip, 0.0_wp, us), 'NaF saddle: landing elsewhere')
      end do
   end subroutine naf_saddle

   !> The Prandtl–Tomlinson tip of the hazard tests, 1D, with its support
   !> starting where the barrier ahead is 12 k_B T.
   function pt_tip(model) result(tip)
      integer, intent(in) :: model
      type(afm_tip) :: tip
      type(tilted_washboard) :: w

      w%u0 = pt_u0
      w%q = 2 * pi / lattice
      w%tilt = 0.0_wp
      tip%ndim = 1
      tip%model = model
      tip%mass = naf_mass
      tip%damping(1) = pt_gamma * naf_mass
      tip%spring(1) = 4 * pi**2 * pt_u0 / (pt_eta * lattice**2)
      tip%support_velocity(1) = pt_velocity
      allocate (tip%potential, source=w)
      tip%support_start(1) = support_at_barrier(tip, 12.0_wp * kt)
   end function pt_tip

   !> The 1D Tomlinson landscape in r = x_M + u, independently of the
   !> module: minimum (the tip's well: the first zero of E' from the left
   !> with E'' > 0) and the saddle after it, by scan and bisection.
   subroutine pt_points(tip, xm, r_min, r_saddle, barrier, rate, ok)
      type(afm_tip), intent(in) :: tip
      real(wp), intent(in) :: xm
      real(wp), intent(out) :: r_min, r_saddle, barrier, rate
      logical, intent(out) :: ok
      type(tilted_washboard) :: w
      real(wp) :: r, g_prev, g, dr, q, k
      integer :: i, found

      q = 2 * pi / lattice
      k = tip%spring(1)
      w%u0 = pt_u0
      w%q = q
      w%tilt = 0.0_wp
      dr = 1.0e-3_wp
      found = 0
      ok = .false.
      r_min = 0.0_wp
      r_saddle = 0.0_wp
      barrier = 0.0_wp
      rate = 0.0_wp
      r = -0.25_wp * lattice
      g_prev = line_slope(w, k, r, xm)
      do i = 1, 8000
         g = line_slope(w, k, r + dr, xm)
         if (g_prev < 0.0_wp .and. g >= 0.0_wp .and. found == 0) then
            r_min = bisect_slope(w, k, xm, r, r + dr)
            found = 1
         else if (g_prev > 0.0_wp .and. g <= 0.0_wp .and. found == 1) then
            r_saddle = bisect_slope(w, k, xm, r, r + dr)
            found = 2
            exit
         end if
         r = r + dr
         g_prev = g
      end do
      if (found < 2) return
      ok = .true.
      barrier = (-pt_u0 * cos(q * r_saddle) + 0.5_wp * k * (r_saddle - xm)**2) &
         & - (-pt_u0 * cos(q * r_min) + 0.5_wp * k * (r_min - xm)**2)
      rate = kramers_1d(tip%model, tip%mass, tip%damping(1), pt_u0 * q**2 * cos(q * r_min) + k, &
         & pt_u0 * q**2 * cos(q * r_saddle) + k, barrier)
   end subroutine pt_points

   !> The support position where the barrier is `barrier` (eV), the
   !> barrier falling as the support moves on: bisection between where
   !> the first saddle appears and the fold.
   real(wp) function support_at_barrier(tip, barrier)
      type(afm_tip), intent(in) :: tip
      real(wp), intent(in) :: barrier
      real(wp) :: lo, hi, mid, r_min, r_saddle, b, rate
      logical :: ok
      integer :: j

      ! Bracket: from 1 Å (barrier ~ 24 k_B T) towards the fold (no saddle).
      lo = 1.0_wp
      hi = lattice
      do j = 1, 200
         mid = 0.5_wp * (lo + hi)
         call pt_points(tip, mid, r_min, r_saddle, b, rate, ok)
         if (ok .and. b > barrier) then
            lo = mid
         else
            hi = mid
         end if
      end do
      support_at_barrier = 0.5_wp * (lo + hi)
   end function support_at_barrier

   !> H(t) = ∫_0^t r dt by composite Simpson on n intervals (closed-form
   !> rate; t within the path's life).
   real(wp) function oracle_hazard(tip, t, n)
      type(afm_tip), intent(in) :: tip
      real(wp), intent(in) :: t
      integer, intent(in) :: n
      real(wp) :: h, r_min, r_saddle, b, rate
      logical :: ok
      integer :: i

      h = t / n
      oracle_hazard = 0.0_wp
      do i = 0, n
         call pt_points(tip, tip%support_start(1) + pt_velocity * i * h, r_min, r_saddle, b, rate, ok)
         if (i == 0 .or. i == n) then
            oracle_hazard = oracle_hazard + rate
         else
            oracle_hazard = oracle_hazard + merge(4.0_wp, 2.0_wp, mod(i, 2) == 1) * rate
         end if
      end do
      oracle_hazard = oracle_hazard * h / 3
   end function oracle_hazard

   !> Jump times for targets 1e-3 ... 5 against the oracle's hazard there
   !> (the log-linear rule with |Δ ln r| <= 0.1 a step: relative error
   !> measured 1e-5 to 5e-5, growing with the target; asserted 2e-4), and
   !> the floor crossing against the oracle.
   subroutine hazard_quadrature(failure)
      character(len=:), allocatable, intent(out) :: failure
      real(wp), parameter :: targets(4) = [1.0e-3_wp, 0.1_wp, 1.0_wp, 5.0_wp]
      type(afm_tip) :: tip
      type(hazard_path) :: path
      type(error_type), allocatable :: error
      real(wp) :: t_event, t_end, h_oracle, r_min, r_saddle, b, rate, t_floor, lo, hi
      integer :: i, status, j
      logical :: ok

      tip = pt_tip(model_inertial)
      call hazard_start(tip, temperature, 0.0_wp, [0.0_wp], path, error)
      call fail_on(failure, error)
      if (allocated(failure)) return
      call check_close(failure, path%barrier, 12.0_wp * kt, 1.0e-9_wp, 'start barrier')
      t_end = 10.0_wp / pt_velocity
      do i = 1, size(targets)
         call hazard_advance(tip, path, t_end, targets(i), status, t_event, error)
         call fail_on(failure, error)
         if (allocated(failure)) return
         call check(failure, status == hazard_jumped, 'no jump before the floor')
         if (allocated(failure)) return
         h_oracle = oracle_hazard(tip, t_event, 4000)
         write (*, '(2x, a, es9.2, a, f9.6, a, es10.2, a, i0, a)') 'target ', targets(i), ': jump at t = ', &
            & t_event, ' s, oracle hazard - target = ', h_oracle - targets(i), ' (', path%steps, ' steps)'
         call check_close(failure, h_oracle, targets(i), 2.0e-4_wp * targets(i), 'hazard at the jump time')
      end do
      ! On to the floor (3 k_B T).
      call hazard_advance(tip, path, t_end, huge(1.0_wp), status, t_event, error)
      call fail_on(failure, error)
      call check(failure, status == hazard_low_barrier, 'the floor not reported')
      lo = 0.0_wp
      hi = t_end
      do j = 1, 100
         t_floor = 0.5_wp * (lo + hi)
         call pt_points(tip, tip%support_start(1) + pt_velocity * t_floor, r_min, r_saddle, b, rate, ok)
         if (ok .and. b > 3.0_wp * kt) then
            lo = t_floor
         else
            hi = t_floor
         end if
      end do
      write (*, '(2x, a, f10.7, a, f10.7, a)') 'floor at t = ', t_event, ' s (oracle ', t_floor, ' s)'
      call check_close(failure, t_event, t_floor, 1.0e-7_wp, 'time the barrier reaches 3 kT')
      call check_close(failure, path%barrier, 3.0_wp * kt, 1.0e-6_wp * kt, 'barrier at the floor')
   end subroutine hazard_quadrature

   !> Support at rest: the rate is constant and the jump comes at target/r.
   subroutine hazard_at_rest(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(afm_tip) :: tip
      type(hazard_path) :: path
      type(error_type), allocatable :: error
      real(wp) :: t_event, rate
      integer :: status

      tip = pt_tip(model_overdamped)
      tip%support_velocity = 0.0_wp
      call hazard_start(tip, temperature, 0.0_wp, [0.0_wp], path, error, direction=[1.0_wp])
      call fail_on(failure, error)
      if (allocated(failure)) return
      rate = exp(path%log_rate)
      call hazard_advance(tip, path, 1.0e6_wp, 0.7_wp, status, t_event, error)
      call fail_on(failure, error)
      call check(failure, status == hazard_jumped, 'no jump at rest')
      call check_close(failure, t_event, 0.7_wp / rate, 1.0e-12_wp * t_event, 'jump time at rest')
      call hazard_advance(tip, path, 2 * t_event, 10.0_wp, status, t_event, error)
      call check(failure, status == hazard_running, 'the path did not stop at t_end')
      call check_close(failure, path%hazard, 1.4_wp, 1.0e-12_wp, 'hazard at t_end')
      tip%support_velocity = 0.0_wp
      call hazard_start(tip, temperature, 0.0_wp, [0.0_wp], path, error)
      call check(failure, allocated(error), 'a support at rest without direction accepted')
   end subroutine hazard_at_rest

   !> The jump time, capped at the 3 k_B T floor, of the Langevin tip (300
   !> realizations; jumped = the tip past 0.8 a, on the next well's side of
   !> the crest, >= 8 k_B T below the saddle where jumps happen) against the
   !> KMC's (20000
   !> exponential targets on one path).  Expected difference: Kramers'
   !> finite-barrier correction (rate ~9 % high at 5 k_B T, see
   !> test_langevin) delays the Langevin jumps by ln(r_K/r)/(d ln r/dt);
   !> allowed up to ln 1.2, plus 3 combined standard errors.
   subroutine kmc_vs_langevin(failure)
      character(len=:), allocatable, intent(out) :: failure
      integer, parameter :: nkmc = 20000, nlangevin = 300, chunk = 1024
      type(afm_tip) :: tip
      type(hazard_path) :: path
      type(error_type), allocatable :: error
      type(random_stream) :: stream
      type(langevin_integrator) :: integrator
      type(langevin_state) :: state
      real(wp) :: targets(nkmc), times(nkmc), logs(nkmc), t_event, t_floor, mean_k, se_k, slope
      real(wp) :: mean_l, se_l, sum1, sum2, dt, limit, u0(1), path_u(1, chunk), t_jump, tolerance
      integer :: i, status, r, j, floor_count
      integer(i8) :: steps

      tip = pt_tip(model_inertial)
      ! KMC: sorted targets along one path.
      call stream%init(77_i8, 0, 0, 0, error)
      call fail_on(failure, error)
      if (allocated(failure)) return
      do i = 1, nkmc
         targets(i) = stream%exponential()
      end do
      call sort(targets)
      call hazard_start(tip, temperature, 0.0_wp, [0.0_wp], path, error)
      call fail_on(failure, error)
      if (allocated(failure)) return
      u0 = path%u_min(1:1)
      t_floor = -1.0_wp
      do i = 1, nkmc
         if (t_floor < 0.0_wp) then
            call hazard_advance(tip, path, 100.0_wp, targets(i), status, t_event, error)
            call fail_on(failure, error)
            if (allocated(failure)) return
            if (status == hazard_low_barrier) t_floor = t_event
         end if
         if (t_floor >= 0.0_wp) then
            times(i) = t_floor
            logs(i) = path%log_rate
         else
            times(i) = t_event
            logs(i) = path%log_rate
         end if
      end do
      mean_k = sum(times) / nkmc
      se_k = sqrt(sum((times - mean_k)**2) / (nkmc - 1) / nkmc)
      ! d ln r/dt between the 40 % and 60 % quantiles.
      slope = (logs(nint(0.6_wp * nkmc)) - logs(nint(0.4_wp * nkmc))) / &
         & (times(nint(0.6_wp * nkmc)) - times(nint(0.4_wp * nkmc)))
      if (t_floor < 0.0_wp) then
         call hazard_advance(tip, path, 100.0_wp, huge(1.0_wp), status, t_floor, error)
         call fail_on(failure, error)
         if (allocated(failure)) return
      end if
      floor_count = count(times >= t_floor)
      ! Langevin: the tip from its minimum, thermal velocity.
      call langevin_time_step(tip, pt_u0 * (2 * pi / lattice)**2, dt, limit, error)
      if (.not. allocated(error)) call integrator%init(tip, temperature, dt, error)
      call fail_on(failure, error)
      if (allocated(failure)) return
      sum1 = 0.0_wp
      sum2 = 0.0_wp
      do r = 0, nlangevin - 1
         call stream%init(78_i8, 0, 0, r, error)
         call fail_on(failure, error)
         if (allocated(failure)) return
         call integrator%start(stream, 0.0_wp, u0, state)
         steps = 0
         t_jump = t_floor
         passage: do while (real(steps, wp) * dt < t_floor)
            call integrator%advance(tip, stream, state, chunk, error, positions=path_u)
            call fail_on(failure, error)
            if (allocated(failure)) return
            do j = 1, chunk
               if (tip%support_start(1) + pt_velocity * (steps + j) * dt + path_u(1, j) >= &
                  & 0.8_wp * lattice) then
                  t_jump = min(real(steps + j, wp) * dt, t_floor)
                  exit passage
               end if
            end do
            steps = steps + chunk
         end do passage
         sum1 = sum1 + t_jump
         sum2 = sum2 + t_jump**2
      end do
      call stream%free()
      mean_l = sum1 / nlangevin
      se_l = sqrt(max(sum2 / nlangevin - mean_l**2, 0.0_wp) / (nlangevin - 1))
      tolerance = 3.0_wp * sqrt(se_k**2 + se_l**2) + log(1.2_wp) / slope
      write (*, '(2x, a, f9.5, a, f8.5, a, f9.5, a, f8.5, a, f8.5, a, f8.5, a, i0, a)') 'jump time: KMC ', mean_k, &
         & ' +- ', se_k, ' s, Langevin ', mean_l, ' +- ', se_l, ' s; ln 1.2/(d ln r/dt) = ', &
         & log(1.2_wp) / slope, ' s; floor at ', t_floor, ' s (', floor_count, ' KMC draws reach it)'
      call check_close(failure, mean_l, mean_k, tolerance, 'mean jump time, Langevin vs KMC')
   end subroutine kmc_vs_langevin

   subroutine sort(x)
      real(wp), intent(inout) :: x(:)
      real(wp) :: v
      integer :: i, j, n, gap

      ! Shell sort (Ciura-like gaps by 2.25).
      n = size(x)
      gap = 1
      do while (gap < n / 3)
         gap = int(2.25_wp * gap) + 1
      end do
      do while (gap >= 1)
         do i = gap + 1, n
            v = x(i)
            j = i
            do while (j > gap)
               if (x(j - gap) <= v) exit
               x(j) = x(j - gap)
               j = j - gap
            end do
            x(j) = v
         end do
         if (gap == 1) exit
         gap = max(1, int(gap / 2.25_wp))
      end do
   end subroutine sort

end program test_kramers
