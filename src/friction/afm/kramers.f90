!> Thermally activated jumps of the tip between minima of its total energy
!>   E(u; t) = V(r_M(t) + u) + ½ Σ_i k_i u_i²,   u = r - r_M(t),
!> over the tip's ndim (1 to 3) moving coordinates (friction_afm_tip's data),
!> for a reduced model at slow support velocities where the tip sits in a
!> minimum and leaves it by thermal escape over a saddle.
!>
!> Rate (Kramers 1940 in the spatial-diffusion regime; Langer 1969 in many
!> dimensions):
!>   r = (λ₊/2π) sqrt(det H_min / |det H_saddle|) exp(-ΔE/k_B T),
!> H the Hessian of E, ΔE = E(saddle) - E(min), and λ₊ the growth rate of
!> the one unstable mode of the dynamics linearised at the saddle:
!>   inertial:   det(λ² m I + λ C + H_s) = 0,   C = diag(c_i),
!>   overdamped: det(λ C + H_s) = 0.
!> In 1D that is Kramers' moderate-to-strong friction rate,
!> (ω_0/2πω_b)(sqrt(γ²/4 + ω_b²) - γ/2) e^{-ΔE/kT}, and its Smoluchowski
!> limit ω_0 ω_b/(2πγ) e^{-ΔE/kT}.  Where it holds: ΔE ≳ 5 k_B T (the
!> corrections are O(k_B T/ΔE)), and damping not weak: below γ ~ ω k_B T/ΔE
!> escape is limited by energy diffusion (Mel'nikov–Meshkov) and this rate
!> is too high.
!>
!> Stationary points:
!>   - minimum: Newton's method on ∇E with the analytic Hessian, its
!>     negative eigenvalues flipped and small ones floored ("saddle-free"
!>     Newton: always a descent direction), steps capped and backtracked on
!>     E until the Hessian is positive definite, then full Newton steps;
!>   - saddle, from a minimum along a direction d (the support's motion):
!>     first the maximum of E on the line u_min + s d (scanned in steps of
!>     0.01 Å, then bisected on the directional derivative): a point on the
!>     ridge between the two wells, near the saddle; from there eigenvector
!>     following (Cerjan & Miller 1981; Baker 1986): Newton steps in the
!>     Hessian's eigenbasis, uphill along the mode that overlaps most the
!>     one followed so far (at first d), downhill along the others, in a
!>     trust radius that halves when the gradient grows; the result must
!>     have exactly one negative Hessian eigenvalue.  Where E has no maximum
!>     on the line (the springs outgrow the surface along d, while the
!>     valley out of the well bends away from it), the following starts at
!>     the minimum and climbs along the softest mode nearest d until E turns
!>     concave.  In 1D this is the line search and Newton's polish.
!>
!> Kinetic Monte Carlo along the support's path: with the support moving,
!> the barrier and the rate r(t) change; the tip jumps when the cumulative
!> hazard ∫ r dt reaches an exponential variate -ln U.  hazard_advance
!> follows the minimum and the saddle by Newton continuation, integrates
!> r(t) with a rule exact for ln r linear in t (steps chosen so ln r
!> changes by at most 0.1 and neither point moves more than 0.05 Å a step;
!> the relative error of ∫ r dt is then ~5e-5, see the tests) and
!> inverts it inside the step where the target is reached.  It stops where
!> the barrier falls below a floor (3 k_B T by default), where the rate
!> formula stops holding: the caller then jumps deterministically or
!> integrates the Langevin tip.
module friction_afm_kramers
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use friction_kinds, only: wp, i8, pi
   use friction_error, only: error_type, fatal_error, error_input, error_numerical
   use friction_strings, only: rtoa, itoa
   use friction_symmetric, only: symmetric_eigen, determinant
   use friction_special, only: expm1, log1p
   use friction_afm_tip, only: afm_tip, model_inertial, model_overdamped
   use friction_afm_langevin, only: boltzmann
   implicit none
   private

   public :: landscape_energy, landscape_gradient, landscape_hessian
   public :: find_minimum, find_saddle, unstable_growth_rate, langer_rate, jump_landing
   public :: hazard_path, hazard_start, hazard_advance
   public :: hazard_running, hazard_jumped, hazard_low_barrier, hazard_paused, kmc_barrier_floor

   !> hazard_advance's outcomes
   integer, parameter :: hazard_running = 0      !! t_end reached, no jump yet
   integer, parameter :: hazard_jumped = 1       !! ∫ r dt reached the target at t_event
   integer, parameter :: hazard_low_barrier = 2  !! the barrier fell to the floor at t_event
   !> the wall clock passed the caller's `pause_at` between two steps; the
   !> path is consistent at path%t and a call with the same arguments goes on
   integer, parameter :: hazard_paused = 3

   !> Stationary points are converged when a Newton step is below this, Å.
   real(wp), parameter :: point_tolerance = 1.0e-11_wp
   !> Largest step of the minimiser and of the saddle search, Å.
   real(wp), parameter :: max_step = 0.1_wp
   !> The saddle search's line scan: step and range, Å.
   real(wp), parameter :: scan_step = 0.01_wp, scan_range = 20.0_wp
   !> Continuation: largest move of a stationary point per path step, Å.
   real(wp), parameter :: max_shift = 0.05_wp
   !> Default largest change of ln r per path step, and barrier floor in k_B T.
   real(wp), parameter :: default_log_change = 0.1_wp, default_floor = 3.0_wp
   integer, parameter :: max_iterations = 500
   !> The barrier, in k_B T, below which the reduced model of the scan
   !> (friction_afm_kramers_trip) fires an exit at once.  Near the fold where the
   !> jumps come the barrier is cubic, and there the escape rate of a well
   !> in equilibrium (the lowest eigenvalue of the Smoluchowski operator,
   !> absorbing past the saddle) is Kramers' within 10 % down to 1 k_B T:
   !> 0.91 to 0.96 of it from 1.5 to 7 k_B T, 1.04 at 1 k_B T, 1.28 at
   !> 0.5 (docs/physics.md).  A 10 % rate error moves a jump by 0.1 k_B T
   !> of barrier.  Below 1 k_B T escape is no longer slow against the
   !> well's relaxation, and a rate stops describing it.
   real(wp), parameter :: kmc_barrier_floor = 1.0_wp

   !> A KMC path: the tip's minimum and the saddle ahead of it at support
   !> time t, the rate there, and the hazard accumulated since the start.
   type :: hazard_path
      real(wp) :: t = 0.0_wp              !! support time, s
      real(wp) :: temperature = 0.0_wp    !! K
      real(wp) :: u_min(3) = 0.0_wp       !! minimum, Å (u = r - r_M)
      real(wp) :: u_saddle(3) = 0.0_wp    !! saddle, Å
      real(wp) :: barrier = 0.0_wp        !! ΔE at t, eV
      real(wp) :: log_rate = 0.0_wp       !! ln(r s) at t
      real(wp) :: hazard = 0.0_wp         !! ∫ r dt since hazard_start
      real(wp) :: step = 0.0_wp           !! next trial step, s
      integer :: steps = 0                !! accepted steps
   end type hazard_path

contains

   !> E(u; t) = V(r_M(t) + u) + ½ Σ k_i u_i², eV.
   pure function landscape_energy(tip, t, u) result(e)
      type(afm_tip), intent(in) :: tip
      real(wp), intent(in) :: t, u(:)
      real(wp) :: e
      integer :: n

      n = tip%ndim
      e = tip%potential%energy(tip%tip_position(t, u(1:n))) + 0.5_wp * sum(tip%spring(1:n) * u(1:n)**2)
   end function landscape_energy

   !> ∇E = k u + ∇V, eV/Å.
   pure function landscape_gradient(tip, t, u) result(g)
      type(afm_tip), intent(in) :: tip
      real(wp), intent(in) :: t, u(:)
      real(wp) :: g(tip%ndim)
      real(wp) :: grad(3)
      integer :: n

      n = tip%ndim
      call tip%potential%gradient(tip%tip_position(t, u(1:n)), grad)
      g = tip%spring(1:n) * u(1:n) + grad(1:n)
   end function landscape_gradient

   !> Hessian K + H of E, eV/Å².
   pure function landscape_hessian(tip, t, u) result(h)
      type(afm_tip), intent(in) :: tip
      real(wp), intent(in) :: t, u(:)
      real(wp) :: h(tip%ndim, tip%ndim)
      real(wp) :: full(3, 3)
      integer :: n, i

      n = tip%ndim
      call tip%potential%hessian(tip%tip_position(t, u(1:n)), full)
      h = full(1:n, 1:n)
      do i = 1, n
         h(i, i) = h(i, i) + tip%spring(i)
      end do
   end function landscape_hessian

   !> Number of negative eigenvalues of E's Hessian at u.
   pure integer function morse_index(tip, t, u)
      type(afm_tip), intent(in) :: tip
      real(wp), intent(in) :: t, u(:)
      real(wp) :: values(tip%ndim), vectors(tip%ndim, tip%ndim)

      call symmetric_eigen(landscape_hessian(tip, t, u), values, vectors)
      morse_index = count(values < 0.0_wp)
   end function morse_index

   !> The minimum of E at support time t from the guess u0 (Å): the well
   !> u0 lies in, or the one descent leads to from there.
   subroutine find_minimum(tip, t, u0, u, error)
      type(afm_tip), intent(in) :: tip
      real(wp), intent(in) :: t, u0(:)
      real(wp), intent(out) :: u(:)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: x(tip%ndim), g(tip%ndim), h(tip%ndim, tip%ndim), values(tip%ndim)
      real(wp) :: vectors(tip%ndim, tip%ndim), p(tip%ndim), e0, slope, alpha, floor, length
      integer :: n, iter, i
      logical :: convex

      n = tip%ndim
      x = u0(1:n)
      u = 0.0_wp
      do iter = 1, max_iterations
         g = landscape_gradient(tip, t, x)
         h = landscape_hessian(tip, t, x)
         call symmetric_eigen(h, values, vectors)
         convex = all(values > 0.0_wp)
         floor = max(1.0e-8_wp * maxval(abs(values)), tiny(1.0_wp))
         p = 0.0_wp
         do i = 1, n
            p = p - dot_product(vectors(:, i), g) / max(abs(values(i)), floor) * vectors(:, i)
         end do
         length = norm2(p)
         if (.not. ieee_is_finite(length)) exit
         if (convex .and. length <= max_step) then
            ! Newton's region: full steps, quadratic convergence.
            x = x + p
            if (length <= point_tolerance) then
               u(1:n) = x
               if (morse_index(tip, t, x) == 0) return
               exit
            end if
            cycle
         end if
         if (length == 0.0_wp) then
            ! A stationary point that is not a minimum: leave it downhill
            ! along the most negative mode.
            p = max_step * vectors(:, 1)
            if (landscape_energy(tip, t, x - p) < landscape_energy(tip, t, x + p)) p = -p
            length = max_step
         end if
         if (length > max_step) p = p * (max_step / length)
         e0 = landscape_energy(tip, t, x)
         slope = dot_product(g, p)
         alpha = 1.0_wp
         do while (landscape_energy(tip, t, x + alpha * p) > e0 + 1.0e-4_wp * alpha * slope)
            alpha = 0.5_wp * alpha
            if (alpha < 1.0e-12_wp) exit
         end do
         if (alpha < 1.0e-12_wp) exit
         x = x + alpha * p
      end do
      call fatal_error(error, 'minimum of the tip energy not found from u = '//vector_text(u0(1:n))// &
         & ' Å at t = '//rtoa(t)//' s', error_numerical)
   end subroutine find_minimum

   !> The first-order saddle of E at support time t ahead of the minimum
   !> u_min (Å) along direction (any length; the support's motion): from
   !> the maximum of E on the line u_min + s d, or, when E rises all along
   !> it for 20 Å, from u_min itself, by eigenvector following.
   !> error_numerical when no saddle is found within 20 Å.
   subroutine find_saddle(tip, t, u_min, direction, u_saddle, error)
      type(afm_tip), intent(in) :: tip
      real(wp), intent(in) :: t, u_min(:), direction(:)
      real(wp), intent(out) :: u_saddle(:)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: d(tip%ndim), x(tip%ndim), s_low, s_high, s_mid, slope
      integer :: n, k, nscan

      n = tip%ndim
      u_saddle = 0.0_wp
      if (.not. (norm2(direction(1:n)) > 0.0_wp)) then
         call fatal_error(error, 'saddle search: the direction is zero', error_input)
         return
      end if
      d = direction(1:n) / norm2(direction(1:n))
      ! The line's maximum: the first sign change of dE/ds from + to -.
      nscan = nint(scan_range / scan_step)
      s_low = 0.0_wp
      s_high = -1.0_wp
      do k = 1, nscan
         slope = dot_product(d, landscape_gradient(tip, t, u_min(1:n) + real(k, wp) * scan_step * d))
         if (slope <= 0.0_wp) then
            s_high = real(k, wp) * scan_step
            exit
         end if
         s_low = real(k, wp) * scan_step
      end do
      if (s_high < 0.0_wp .or. s_low == 0.0_wp) then
         ! No maximum on the line (the springs outgrow the surface along it):
         ! climb from the minimum itself along the mode nearest d.
         x = u_min(1:n)
         call follow_mode(tip, t, x, d, error)
         if (allocated(error)) return
         u_saddle(1:n) = x
         return
      end if
      do k = 1, 60
         s_mid = 0.5_wp * (s_low + s_high)
         if (dot_product(d, landscape_gradient(tip, t, u_min(1:n) + s_mid * d)) > 0.0_wp) then
            s_low = s_mid
         else
            s_high = s_mid
         end if
         if (s_high - s_low <= point_tolerance) exit
      end do
      x = u_min(1:n) + 0.5_wp * (s_low + s_high) * d
      call follow_mode(tip, t, x, d, error)
      if (allocated(error)) return
      u_saddle(1:n) = x
   end subroutine find_saddle

   !> Eigenvector following from x to a first-order saddle, uphill along
   !> the mode that overlaps most with mode (updated as it is followed):
   !> while E is convex along that mode, a trust radius on along it; past
   !> the inflection, Newton's step for its maximum; Newton's step for the
   !> minimum along the others.  Gives up after 20 Å.
   subroutine follow_mode(tip, t, x, mode, error)
      type(afm_tip), intent(in) :: tip
      real(wp), intent(in) :: t
      real(wp), intent(inout) :: x(:), mode(:)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: g(size(x)), h(size(x), size(x)), values(size(x)), vectors(size(x), size(x))
      real(wp) :: p(size(x)), g_trial(size(x)), radius, floor, length, gi, climbed
      integer :: n, iter, i, k
      logical :: quadratic

      n = size(x)
      radius = max_step
      climbed = 0.0_wp
      do iter = 1, max_iterations
         g = landscape_gradient(tip, t, x)
         h = landscape_hessian(tip, t, x)
         call symmetric_eigen(h, values, vectors)
         k = maxloc(abs(matmul(mode, vectors)), 1)
         if (dot_product(mode, vectors(:, k)) < 0.0_wp) vectors(:, k) = -vectors(:, k)
         mode = vectors(:, k)
         floor = max(1.0e-8_wp * maxval(abs(values)), tiny(1.0_wp))
         p = 0.0_wp
         do i = 1, n
            gi = dot_product(vectors(:, i), g)
            if (i /= k) then
               p = p - gi / max(abs(values(i)), floor) * vectors(:, i)
            else if (values(k) > 0.0_wp) then
               ! Still convex along the mode: climb a trust radius on.
               p = p + radius * vectors(:, i)
            else
               p = p + gi / max(abs(values(i)), floor) * vectors(:, i)
            end if
         end do
         climbed = climbed + norm2(p)
         if (climbed > scan_range) exit
         ! In the saddle's quadratic region (mode k the only negative one)
         ! this is Newton's step.
         quadratic = values(k) < 0.0_wp .and. count(values < 0.0_wp) == 1
         length = norm2(p)
         if (.not. ieee_is_finite(length)) exit
         if (quadratic .and. length <= point_tolerance) then
            x = x + p
            if (morse_index(tip, t, x) == 1) return
            exit
         end if
         do
            if (length > radius) then
               p = p * (radius / length)
               length = radius
            end if
            g_trial = landscape_gradient(tip, t, x + p)
            if (norm2(g_trial) <= norm2(g) .or. .not. quadratic) exit
            radius = 0.5_wp * radius
            if (radius < point_tolerance) exit
         end do
         if (radius < point_tolerance) exit
         x = x + p
         radius = min(2.0_wp * radius, max_step)
      end do
      call fatal_error(error, 'saddle search: eigenvector following did not converge near u = '// &
         & vector_text(x)//' Å at t = '//rtoa(t)//' s', error_numerical)
   end subroutine follow_mode

   !> λ₊, the growth rate (1/s) of the unstable mode at a saddle with
   !> Hessian h_saddle (eV/Å², exactly one negative eigenvalue): the one
   !> positive root of det(λ² m I + λ C + H) (inertial tip) or
   !> det(λ C + H) (overdamped), found by bisection between 0 (det H < 0)
   !> and a bound where the matrix is positive definite.  With M, C > 0 the
   !> linearised flow has exactly as many growing modes as H has negative
   !> eigenvalues, so the root is unique.
   subroutine unstable_growth_rate(tip, h_saddle, lambda, error)
      type(afm_tip), intent(in) :: tip
      real(wp), intent(in) :: h_saddle(:, :)
      real(wp), intent(out) :: lambda
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: values(size(h_saddle, 1)), vectors(size(h_saddle, 1), size(h_saddle, 1))
      real(wp) :: low, high, mid, d_low
      integer :: n, k

      n = size(h_saddle, 1)
      lambda = 0.0_wp
      call symmetric_eigen(h_saddle, values, vectors)
      if (.not. (values(1) < 0.0_wp) .or. count(values < 0.0_wp) /= 1) then
         call fatal_error(error, 'unstable mode: the Hessian has '//itoa(count(values < 0.0_wp))// &
            & ' negative eigenvalues, a first-order saddle has one', error_input)
         return
      end if
      if (tip%model == model_inertial) then
         if (.not. (tip%mass > 0.0_wp) .or. any(tip%damping(1:n) < 0.0_wp)) then
            call fatal_error(error, 'unstable mode: the inertial tip needs a mass > 0 and damping >= 0', &
               & error_input)
            return
         end if
         high = sqrt(-values(1) / tip%mass)
      else if (tip%model == model_overdamped) then
         if (.not. all(tip%damping(1:n) > 0.0_wp)) then
            call fatal_error(error, 'unstable mode: the overdamped tip needs damping > 0 on every axis', &
               & error_input)
            return
         end if
         high = -values(1) / minval(tip%damping(1:n))
      else
         call fatal_error(error, 'unstable mode: the tip model must be inertial or overdamped', error_input)
         return
      end if
      low = 0.0_wp
      d_low = pencil_determinant(tip, h_saddle, low)
      ! At the bound the matrix is positive semidefinite; a little beyond
      ! it definite (exactly at it when some axis is undamped).
      high = high * (1.0_wp + 1.0e-9_wp) + tiny(1.0_wp)
      do k = 1, 60
         if (pencil_determinant(tip, h_saddle, high) > 0.0_wp) exit
         high = 2.0_wp * high
      end do
      do k = 1, 200
         mid = 0.5_wp * (low + high)
         if (mid <= low .or. mid >= high) exit
         if (sign(1.0_wp, pencil_determinant(tip, h_saddle, mid)) == sign(1.0_wp, d_low)) then
            low = mid
         else
            high = mid
         end if
         if (high - low <= 4.0_wp * epsilon(1.0_wp) * high) exit
      end do
      lambda = 0.5_wp * (low + high)
   end subroutine unstable_growth_rate

   pure function pencil_determinant(tip, h, lambda) result(d)
      type(afm_tip), intent(in) :: tip
      real(wp), intent(in) :: h(:, :), lambda
      real(wp) :: d
      real(wp) :: a(size(h, 1), size(h, 1))
      integer :: i

      a = h
      do i = 1, size(h, 1)
         if (tip%model == model_inertial) then
            a(i, i) = a(i, i) + lambda**2 * tip%mass + lambda * tip%damping(i)
         else
            a(i, i) = a(i, i) + lambda * tip%damping(i)
         end if
      end do
      d = determinant(a)
   end function pencil_determinant

   !> The Kramers–Langer escape rate (1/s) from the minimum u_min over the
   !> saddle u_saddle (Å) at support time t and temperature (K > 0); also
   !> the barrier ΔE (eV), ln(r s) (finite where r underflows) and the
   !> prefactor (λ₊/2π) sqrt(det H_min/|det H_s|) (1/s).
   subroutine langer_rate(tip, t, u_min, u_saddle, temperature, rate, error, barrier, log_rate, prefactor)
      type(afm_tip), intent(in) :: tip
      real(wp), intent(in) :: t, u_min(:), u_saddle(:), temperature
      real(wp), intent(out) :: rate
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(out), optional :: barrier, log_rate, prefactor
      real(wp) :: h_min(tip%ndim, tip%ndim), h_s(tip%ndim, tip%ndim), v_min(tip%ndim), v_s(tip%ndim)
      real(wp) :: vectors(tip%ndim, tip%ndim), lambda, delta, log_prefactor
      integer :: n

      n = tip%ndim
      rate = 0.0_wp
      if (.not. (temperature > 0.0_wp)) then
         call fatal_error(error, 'Kramers rate: temperature = '//rtoa(temperature)//' K, must be > 0', &
            & error_input)
         return
      end if
      h_min = landscape_hessian(tip, t, u_min(1:n))
      h_s = landscape_hessian(tip, t, u_saddle(1:n))
      call symmetric_eigen(h_min, v_min, vectors)
      call symmetric_eigen(h_s, v_s, vectors)
      if (.not. all(v_min > 0.0_wp)) then
         call fatal_error(error, 'Kramers rate: u = '//vector_text(u_min(1:n))//' Å is not a minimum', &
            & error_input)
         return
      end if
      call unstable_growth_rate(tip, h_s, lambda, error)
      if (allocated(error)) return
      delta = landscape_energy(tip, t, u_saddle(1:n)) - landscape_energy(tip, t, u_min(1:n))
      ! det as products of eigenvalues: no cancellation.
      log_prefactor = log(lambda / (2.0_wp * pi)) + 0.5_wp * (sum(log(v_min)) - sum(log(abs(v_s))))
      rate = exp(log_prefactor - delta / (boltzmann * temperature))
      if (present(barrier)) barrier = delta
      if (present(log_rate)) log_rate = log_prefactor - delta / (boltzmann * temperature)
      if (present(prefactor)) prefactor = exp(log_prefactor)
   end subroutine langer_rate

   !> Where the tip lands after crossing the saddle u_saddle from the
   !> minimum u_min at support time t: it is pushed 0.05 Å past the saddle
   !> along the unstable mode, away from u_min, and descends to a minimum.
   !> error_numerical if it falls back into u_min.
   subroutine jump_landing(tip, t, u_min, u_saddle, u_new, error)
      type(afm_tip), intent(in) :: tip
      real(wp), intent(in) :: t, u_min(:), u_saddle(:)
      real(wp), intent(out) :: u_new(:)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: values(tip%ndim), vectors(tip%ndim, tip%ndim), e(tip%ndim)
      integer :: n

      n = tip%ndim
      call symmetric_eigen(landscape_hessian(tip, t, u_saddle(1:n)), values, vectors)
      e = vectors(:, 1)
      if (dot_product(e, u_saddle(1:n) - u_min(1:n)) < 0.0_wp) e = -e
      call find_minimum(tip, t, u_saddle(1:n) + max_shift * e, u_new, error)
      if (allocated(error)) return
      if (norm2(u_new(1:n) - u_min(1:n)) <= 10.0_wp * max_shift) then
         call fatal_error(error, 'jump landing: the tip fell back into its minimum '// &
            & vector_text(u_min(1:n))//' Å at t = '//rtoa(t)//' s', error_numerical)
      end if
   end subroutine jump_landing

   !> Start a KMC path at support time t from the minimum nearest u_guess
   !> (Å), with the saddle ahead along direction (default: the support's
   !> velocity), at temperature (K > 0).
   subroutine hazard_start(tip, temperature, t, u_guess, path, error, direction)
      type(afm_tip), intent(in) :: tip
      real(wp), intent(in) :: temperature, t, u_guess(:)
      type(hazard_path), intent(out) :: path
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(in), optional :: direction(:)
      real(wp) :: d(tip%ndim), rate, speed
      integer :: n

      n = tip%ndim
      if (present(direction)) then
         d = direction(1:n)
      else
         d = tip%support_velocity(1:n)
      end if
      path%t = t
      path%temperature = temperature
      call find_minimum(tip, t, u_guess, path%u_min(1:n), error)
      if (allocated(error)) return
      call find_saddle(tip, t, path%u_min(1:n), d, path%u_saddle(1:n), error)
      if (allocated(error)) return
      call langer_rate(tip, t, path%u_min(1:n), path%u_saddle(1:n), temperature, rate, error, &
         & barrier=path%barrier, log_rate=path%log_rate)
      if (allocated(error)) return
      path%hazard = 0.0_wp
      path%steps = 0
      speed = norm2(tip%support_velocity(1:n))
      path%step = huge(1.0_wp)
      if (speed > 0.0_wp) path%step = 1.0e-3_wp / speed
   end subroutine hazard_start

   !> Newton's method on ∇E = 0 at time t from x0 with full steps, each at
   !> most max_shift; ok when it converges to a point of Morse index
   !> `index` within max_shift of x0.
   subroutine continue_point(tip, t, x0, index, x, ok)
      type(afm_tip), intent(in) :: tip
      real(wp), intent(in) :: t, x0(:)
      integer, intent(in) :: index
      real(wp), intent(out) :: x(:)
      logical, intent(out) :: ok
      real(wp) :: h(size(x0), size(x0)), values(size(x0)), vectors(size(x0), size(x0)), g(size(x0))
      real(wp) :: p(size(x0))
      integer :: iter, i, n

      n = size(x0)
      x = x0
      ok = .false.
      do iter = 1, 30
         g = landscape_gradient(tip, t, x)
         h = landscape_hessian(tip, t, x)
         call symmetric_eigen(h, values, vectors)
         if (count(values < 0.0_wp) /= index .or. any(values == 0.0_wp)) return
         p = 0.0_wp
         do i = 1, n
            p = p - dot_product(vectors(:, i), g) / values(i) * vectors(:, i)
         end do
         if (.not. (norm2(p) <= max_shift)) return
         x = x + p
         if (norm2(x - x0) > max_shift) return
         if (norm2(p) <= point_tolerance) then
            ok = morse_index(tip, t, x) == index
            return
         end if
      end do
   end subroutine continue_point

   !> The path's minimum, saddle, barrier and ln r at time t, continued from
   !> the path's current points; ok = .false. when either is lost.
   subroutine path_at(tip, path, t, u_min, u_saddle, barrier, log_rate, ok)
      type(afm_tip), intent(in) :: tip
      type(hazard_path), intent(in) :: path
      real(wp), intent(in) :: t
      real(wp), intent(out) :: u_min(:), u_saddle(:), barrier, log_rate
      logical, intent(out) :: ok
      type(error_type), allocatable :: error
      real(wp) :: rate
      integer :: n

      n = tip%ndim
      barrier = 0.0_wp
      log_rate = 0.0_wp
      call continue_point(tip, t, path%u_min(1:n), 0, u_min(1:n), ok)
      if (.not. ok) return
      call continue_point(tip, t, path%u_saddle(1:n), 1, u_saddle(1:n), ok)
      if (.not. ok) return
      call langer_rate(tip, t, u_min(1:n), u_saddle(1:n), path%temperature, rate, error, &
         & barrier=barrier, log_rate=log_rate)
      ok = .not. allocated(error)
   end subroutine path_at

   !> ∫ r dt over a step of length h where ln r goes linearly from l0 to l1.
   pure function step_hazard(h, l0, l1) result(dh)
      real(wp), intent(in) :: h, l0, l1
      real(wp) :: dh
      real(wp) :: x

      x = l1 - l0
      if (abs(x) < 1.0e-8_wp) then
         dh = h * exp(l0) * (1.0_wp + 0.5_wp * x)
      else
         dh = h * exp(l0) * expm1(x) / x
      end if
   end function step_hazard

   !> Follow the path from path%t towards t_end until the hazard reaches
   !> target (an exponential variate: status hazard_jumped, t_event the jump
   !> time, the path's points and hazard there), the barrier falls to
   !> barrier_floor k_B T (default 3; status hazard_low_barrier, t_event
   !> where it does), or t_end (status hazard_running; call again to go on).
   !> max_log_change (default 0.1) bounds the change of ln r per step.
   !> With pause_at (a count of the processor's system_clock), the path
   !> returns hazard_paused between two steps once the clock has passed it,
   !> so that its caller can look at its wall-time limit and stop requests:
   !> a path near a degenerate saddle can take very many short steps.
   subroutine hazard_advance(tip, path, t_end, target, status, t_event, error, max_log_change, barrier_floor, &
      & pause_at)
      type(afm_tip), intent(in) :: tip
      type(hazard_path), intent(inout) :: path
      real(wp), intent(in) :: t_end, target
      integer, intent(out) :: status
      real(wp), intent(out) :: t_event
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(in), optional :: max_log_change, barrier_floor
      integer(i8), intent(in), optional :: pause_at
      real(wp) :: change, floor, h, t1, u_min(3), u_saddle(3), barrier, log_rate, dh, s, tau
      real(wp) :: t_low, t_high, h_smallest
      logical :: ok, floor_reached
      integer(i8) :: now
      integer :: n, k

      n = tip%ndim
      status = hazard_running
      t_event = path%t
      change = default_log_change
      if (present(max_log_change)) change = max_log_change
      floor = default_floor
      if (present(barrier_floor)) floor = barrier_floor
      floor = floor * boltzmann * path%temperature
      u_min = 0.0_wp
      u_saddle = 0.0_wp
      if (.not. (change > 0.0_wp) .or. .not. (target >= 0.0_wp)) then
         call fatal_error(error, 'hazard: max_log_change must be > 0 and the target >= 0', error_input)
         return
      end if
      if (path%barrier <= floor) then
         status = hazard_low_barrier
         return
      end if
      h_smallest = 1.0e-14_wp * max(abs(path%t), abs(t_end), 1.0e-300_wp)
      do while (path%t < t_end)
         if (present(pause_at)) then
            call system_clock(now)
            if (now >= pause_at) then
               status = hazard_paused
               t_event = path%t
               return
            end if
         end if
         h = min(path%step, t_end - path%t)
         ! A step that keeps both points on their branches and ln r smooth.
         do
            t1 = path%t + h
            if (t_end - t1 <= h_smallest) t1 = t_end
            call path_at(tip, path, t1, u_min(1:n), u_saddle(1:n), barrier, log_rate, ok)
            if (ok) ok = abs(log_rate - path%log_rate) <= change .or. barrier <= floor
            if (ok) exit
            h = 0.5_wp * h
            if (h < h_smallest) then
               ! The minimum or the saddle vanishes here: a fold, where the
               ! barrier is already below any useful floor.
               status = hazard_low_barrier
               t_event = path%t
               return
            end if
         end do
         floor_reached = barrier <= floor
         if (floor_reached) then
            ! Locate where the barrier crosses the floor, to 1e-9 of the step.
            t_low = path%t
            t_high = t1
            do k = 1, 200
               if (t_high - t_low <= 1.0e-9_wp * h .or. t_high - t_low <= h_smallest) exit
               t1 = 0.5_wp * (t_low + t_high)
               call path_at(tip, path, t1, u_min(1:n), u_saddle(1:n), barrier, log_rate, ok)
               if (ok .and. barrier > floor) then
                  t_low = t1
               else
                  t_high = t1
               end if
            end do
            t1 = t_low
            call path_at(tip, path, t1, u_min(1:n), u_saddle(1:n), barrier, log_rate, ok)
            if (.not. ok) then
               call fatal_error(error, 'hazard: the path is lost near t = '//rtoa(t1)//' s', error_numerical)
               return
            end if
            h = t1 - path%t
         end if
         dh = step_hazard(t1 - path%t, path%log_rate, log_rate)
         if (path%hazard + dh >= target) then
            ! The jump is inside this step: invert the exponential rule.
            s = (log_rate - path%log_rate) / (t1 - path%t)
            if (abs(s * (t1 - path%t)) < 1.0e-8_wp) then
               tau = (target - path%hazard) / exp(path%log_rate)
            else
               tau = log1p(s * (target - path%hazard) / exp(path%log_rate)) / s
            end if
            tau = min(max(tau, 0.0_wp), t1 - path%t)
            t_event = path%t + tau
            call path_at(tip, path, t_event, u_min(1:n), u_saddle(1:n), barrier, log_rate, ok)
            if (ok) then
               path%u_min(1:n) = u_min(1:n)
               path%u_saddle(1:n) = u_saddle(1:n)
               path%barrier = barrier
               path%log_rate = log_rate
            end if
            path%t = t_event
            path%hazard = target
            path%steps = path%steps + 1
            status = hazard_jumped
            return
         end if
         path%hazard = path%hazard + dh
         path%t = t1
         path%u_min(1:n) = u_min(1:n)
         path%u_saddle(1:n) = u_saddle(1:n)
         path%barrier = barrier
         path%log_rate = log_rate
         path%steps = path%steps + 1
         if (floor_reached) then
            status = hazard_low_barrier
            t_event = path%t
            return
         end if
         path%step = 2.0_wp * h
      end do
      t_event = path%t
   end subroutine hazard_advance

   pure function vector_text(x) result(text)
      real(wp), intent(in) :: x(:)
      character(len=:), allocatable :: text
      integer :: i

      text = '('
      do i = 1, size(x)
         text = text//rtoa(x(i))
         if (i < size(x)) text = text//', '
      end do
      text = text//')'
   end function vector_text

end module friction_afm_kramers
