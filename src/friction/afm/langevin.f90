!> Fixed-step stochastic integration of the microscope tip at a temperature
!> T: friction_afm_tip's Eq. 4 with a heat bath,
!>   inertial:    m r'' = -k u - ∇V(r) - c r' + ξ(t),
!>   overdamped:  c r'  = -k u - ∇V(r) + ξ(t),
!> for each moving direction i, with u = r - r_M(t), r_M(t) = r_M(0) + v_M t
!> and ξ Gaussian white noise, ⟨ξ_i(t) ξ_j(t')⟩ = 2 c_i k_B T δ_ij δ(t - t')
!> (fluctuation–dissipation: the bath that damps axis i heats it).  The tip's
!> data (mass, springs, dampers, support, surface) are friction_afm_tip's;
!> internal units Å, eV, s; T in K.  A direction without damping has no bath:
!> at T > 0 that is an input error (init refuses it); at T = 0 both schemes
!> are deterministic and draw no variates.
!>
!> Inertial tip: BAOAB (Leimkuhler & Matthews, Appl. Math. Res. Express 2013,
!> 34; J. Chem. Phys. 138, 174102 (2013)).  One step of length h:
!>   B  r' += h/(2m) F(t_n, u)            F = -k u - ∇V(r_M(t) + u)
!>   A  u  += h/2 (r' - v_M)
!>   O  r' <- a r' + sqrt((1 - a²) k_B T/m) R,   a = exp(-c h/m), R ~ N(0, 1)
!>   A  u  += h/2 (r' - v_M)
!>   B  r' += h/(2m) F(t_n + h, u)
!> Why BAOAB:
!>   - the O step solves friction and noise together exactly (an
!>     Ornstein–Uhlenbeck step), so any damping is stable and the noise
!>     always matches its friction; with c_i = 0 it is the identity on axis i;
!>   - configurational averages are second order in h, and exact for a
!>     harmonic potential (k⟨δu²⟩ = k_B T at any stable h); the velocity
!>     variance at full steps is low by the factor 1 - (ωh)²/4 there
!>     (ω² = k/m), which the tests check at ωh = 1;
!>   - its B-A-B part is velocity Verlet: stable for h < 2/ω_max, as the
!>     deterministic scheme, and the O step only contracts;
!>   - one force evaluation a step: the last B's force is the next step's
!>     first (an advance call evaluates one more, at its start, so that the
!>     state holds no cached force and results never depend on how the
!>     steps are split into calls).
!> Moving frame: u is measured from a support moving at v_M, and in u the
!> drag reads -c (u' + v_M).  The state carries the lab-frame velocity
!> r' = u' + v_M (as friction_afm_tip's does): the A steps move u by
!> (r' - v_M) h/2, and the O step relaxes r' towards 0 (the bath is at rest
!> in the lab) with its noise, so the drag -c v_M on u comes out of the
!> exact OU step with no term of its own.  In a flat potential the mean
!> shift -c v_M/k comes out multiplied by tanh(γh/2)/(γh/2) = 1 - (γh)²/12,
!> γ = c/m.
!>
!> Overdamped tip: the Leimkuhler–Matthews scheme (Leimkuhler, Matthews &
!> Tretyakov, Proc. R. Soc. A 470, 20140120 (2014)), BAOAB's limit of
!> infinite friction:
!>   u_{n+1} = u_n + h (F(t_n, u_n)/c - v_M) + sqrt(2 k_B T h/c) (R_n + R_{n+1})/2.
!> It costs what Euler–Maruyama costs (one force and one variate per axis
!> a step) and samples the invariant measure to second order in h where
!> Euler–Maruyama is first order; for a harmonic tip it is exact,
!> k⟨δu²⟩ = k_B T at any stable h (Euler–Maruyama: k_B T/(1 - kh/(2c)),
!> which the tests tell apart at kh/c = 1).  Its paths are, like
!> Euler–Maruyama's, weakly first order: escape times carry an O(h) bias,
!> measured +0.3 to +0.5 κh (κ the largest curvature over c) on mean first
!> passage times over 5 and 10 k_B T barriers, where BAOAB's was within the
!> statistics (1.7 %) up to ωh = 0.2 (tests/test_langevin.pf).  The state
!> keeps R_n from one step (and call) to the next.
!>
!> Stability: both schemes need h < 2/ω_max (inertial, ω_max² the largest
!> curvature of the total energy over m) or h < 2/κ_max (overdamped, κ the
!> curvature over c).  langevin_time_step gives that limit and a default
!> step from the fastest time scale; init refuses a step at or above the
!> limit when it is given the curvature.
module friction_afm_langevin
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use friction_kinds, only: wp, i8
   use friction_error, only: error_type, fatal_error, error_input, error_numerical
   use friction_strings, only: rtoa, itoa
   use friction_random, only: random_stream
   use friction_special, only: expm1
   use friction_symmetric, only: symmetric_eigen
   use friction_surface_potential, only: surface_potential
   use friction_afm_tip, only: afm_tip, model_inertial, model_overdamped
   implicit none
   private

   public :: boltzmann, langevin_integrator, langevin_state, langevin_time_step, largest_curvature
   public :: default_step_fraction

   !> Boltzmann's constant in eV/K (SI 2019: exact in J/K, with e exact).
   real(wp), parameter :: boltzmann = 8.617333262e-5_wp

   !> Default step as a share of the fastest time scale (see
   !> langevin_time_step): at ωh = 0.05 BAOAB's O(h²) errors are ~(ωh)²/4
   !> = 6e-4, and the overdamped scheme's escape-time bias ~2 %.
   real(wp), parameter :: default_step_fraction = 0.05_wp

   character(len=1), parameter :: axis_name(3) = ['x', 'y', 'z']

   !> Where a trajectory is: the support time t = t0 + steps h, the
   !> displacement u from the support and the lab-frame velocity r'.
   type :: langevin_state
      real(wp) :: t0 = 0.0_wp                 !! support time at steps = 0, s
      integer(i8) :: steps = 0                !! steps taken since t0
      real(wp) :: u(3) = 0.0_wp               !! u = r - r_M, Å
      real(wp) :: velocity(3) = 0.0_wp        !! r' (lab frame), Å/s; inertial tip only
      real(wp) :: noise(3) = 0.0_wp           !! overdamped: the variate R_n of the next step
      logical :: noise_drawn = .false.        !! overdamped: noise holds R_n
   end type langevin_state

   !> The scheme's coefficients for one tip, temperature and step.
   type :: langevin_integrator
      integer :: model = model_inertial
      integer :: ndim = 0
      real(wp) :: dt = 0.0_wp                 !! step h, s
      real(wp) :: temperature = 0.0_wp        !! K
      real(wp) :: half_dt = 0.0_wp            !! h/2
      real(wp) :: half_dt_over_mass = 0.0_wp  !! h/(2m)
      real(wp) :: decay(3) = 1.0_wp           !! O step: exp(-c h/m)
      real(wp) :: kick(3) = 0.0_wp            !! O step: sqrt((1 - a²) k_B T/m), Å/s
      real(wp) :: thermal_speed(3) = 0.0_wp   !! sqrt(k_B T/m), Å/s
      real(wp) :: drift(3) = 0.0_wp           !! overdamped: h/c, Å²/eV
      real(wp) :: spread(3) = 0.0_wp          !! overdamped: sqrt(2 k_B T h/c)/2, Å
      logical :: noisy = .false.              !! T > 0: variates are drawn
   contains
      procedure :: init
      procedure :: start
      procedure :: advance
      procedure :: time_of
   end type langevin_integrator

contains

   !> Coefficients for tip (its model, ndim, mass, spring, damping) at
   !> temperature (K) with step dt (s).  Errors (error_input): a model other
   !> than inertial or overdamped; T < 0 or not finite; dt <= 0 or not
   !> finite; m <= 0 (inertial); a damping < 0, or = 0 on a moving axis of
   !> the overdamped tip or at T > 0; and, when curvature (the largest
   !> curvature of V, eV/Å², see largest_curvature) is given, dt at or above
   !> the stability limit of langevin_time_step.
   subroutine init(self, tip, temperature, dt, error, curvature)
      class(langevin_integrator), intent(out) :: self
      type(afm_tip), intent(in) :: tip
      real(wp), intent(in) :: temperature, dt
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(in), optional :: curvature
      real(wp) :: kt, a, dt_default, dt_limit
      integer :: nd, i

      nd = tip%ndim
      if (tip%model /= model_inertial .and. tip%model /= model_overdamped) then
         call fatal_error(error, 'Langevin integrator: the tip model must be inertial or overdamped', error_input)
         return
      end if
      if (nd < 1 .or. nd > 3) then
         call fatal_error(error, 'Langevin integrator: the tip moves in '//itoa(nd)//' dimensions, not 1 to 3', &
            & error_input)
         return
      end if
      if (.not. (ieee_is_finite(temperature) .and. temperature >= 0.0_wp)) then
         call fatal_error(error, 'Langevin integrator: temperature = '//rtoa(temperature)// &
            & ' K, must be >= 0', error_input)
         return
      end if
      if (.not. (ieee_is_finite(dt) .and. dt > 0.0_wp)) then
         call fatal_error(error, 'Langevin integrator: time step = '//rtoa(dt)//' s, must be > 0', error_input)
         return
      end if
      if (tip%model == model_inertial .and. .not. (tip%mass > 0.0_wp)) then
         call fatal_error(error, 'Langevin integrator: mass = '//rtoa(tip%mass)//', must be > 0', error_input)
         return
      end if
      do i = 1, nd
         if (.not. (tip%damping(i) >= 0.0_wp)) then
            call fatal_error(error, 'Langevin integrator: damping along '//axis_name(i)//' = ' &
               & //rtoa(tip%damping(i))//', must be >= 0', error_input)
            return
         end if
         if (tip%damping(i) == 0.0_wp .and. tip%model == model_overdamped) then
            call fatal_error(error, 'Langevin integrator: no damping along '//axis_name(i)// &
               & ' (the overdamped tip needs it on every moving axis)', error_input)
            return
         end if
         if (tip%damping(i) == 0.0_wp .and. temperature > 0.0_wp) then
            call fatal_error(error, 'Langevin integrator: no damping along '//axis_name(i)// &
               & ' (at T > 0 every moving axis needs its heat bath)', error_input)
            return
         end if
      end do
      if (present(curvature)) then
         call langevin_time_step(tip, curvature, dt_default, dt_limit, error)
         if (allocated(error)) return
         if (dt >= dt_limit) then
            call fatal_error(error, 'Langevin integrator: time step '//rtoa(dt)//' s is at or above the '// &
               & 'stability limit '//rtoa(dt_limit)//' s', error_input)
            return
         end if
      end if

      kt = boltzmann * temperature
      self%model = tip%model
      self%ndim = nd
      self%dt = dt
      self%temperature = temperature
      self%half_dt = 0.5_wp * dt
      self%noisy = temperature > 0.0_wp
      if (tip%model == model_inertial) then
         self%half_dt_over_mass = 0.5_wp * dt / tip%mass
         do i = 1, nd
            a = exp(-tip%damping(i) * dt / tip%mass)
            self%decay(i) = a
            ! 1 - a², accurate for small ch/m too
            self%kick(i) = sqrt(-expm1(-2.0_wp * tip%damping(i) * dt / tip%mass) * kt / tip%mass)
            self%thermal_speed(i) = sqrt(kt / tip%mass)
         end do
      else
         do i = 1, nd
            self%drift(i) = dt / tip%damping(i)
            self%spread(i) = 0.5_wp * sqrt(2.0_wp * kt * dt / tip%damping(i))
         end do
      end if
   end subroutine init

   !> Support time of a state, s.
   pure function time_of(self, state) result(t)
      class(langevin_integrator), intent(in) :: self
      type(langevin_state), intent(in) :: state
      real(wp) :: t

      t = state%t0 + real(state%steps, wp) * self%dt
   end function time_of

   !> A trajectory's start at support time t0 with displacement u0 (Å).  The
   !> inertial tip gets the lab-frame velocity given (Å/s), or else one drawn
   !> from the Maxwell–Boltzmann distribution of the bath at rest in the lab
   !> (zero at T = 0); the overdamped tip draws its first variate R_0.
   subroutine start(self, stream, t0, u0, state, velocity)
      class(langevin_integrator), intent(in) :: self
      type(random_stream), intent(inout) :: stream
      real(wp), intent(in) :: t0, u0(:)
      type(langevin_state), intent(out) :: state
      real(wp), intent(in), optional :: velocity(:)
      integer :: i, nd

      nd = self%ndim
      state%t0 = t0
      state%steps = 0
      state%u = 0.0_wp
      state%u(1:nd) = u0(1:nd)
      state%velocity = 0.0_wp
      state%noise = 0.0_wp
      state%noise_drawn = .false.
      if (self%model == model_inertial) then
         if (present(velocity)) then
            state%velocity(1:nd) = velocity(1:nd)
         else if (self%noisy) then
            do i = 1, nd
               state%velocity(i) = self%thermal_speed(i) * stream%gaussian()
            end do
         end if
      else if (self%noisy) then
         do i = 1, nd
            state%noise(i) = stream%gaussian()
         end do
         state%noise_drawn = .true.
      end if
   end subroutine start

   !> nsteps steps of state on tip (the tip init was given) with the noise
   !> of stream.  Optionally records after each step j the displacement u
   !> (positions(1:ndim, j), Å) and, for the inertial tip, the lab-frame
   !> velocity r' (velocities(1:ndim, j), Å/s).  error_numerical when the
   !> state stops being finite (the step is then too large for the
   !> landscape); error_input for a tip that does not match init's or
   !> records too small.
   subroutine advance(self, tip, stream, state, nsteps, error, positions, velocities)
      class(langevin_integrator), intent(in) :: self
      type(afm_tip), intent(in) :: tip
      type(random_stream), intent(inout) :: stream
      type(langevin_state), intent(inout) :: state
      integer, intent(in) :: nsteps
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(inout), optional :: positions(:, :)
      real(wp), intent(inout), optional :: velocities(:, :)
      real(wp) :: u(3), w(3), f(3), g(3), r(3), start(3), vm(3), spring(3), noise(3), fresh, t
      integer :: nd, i, j
      logical :: record_u, record_v

      nd = self%ndim
      if (nd < 1) then
         call fatal_error(error, 'Langevin integrator: advance before init', error_input)
         return
      end if
      if (tip%ndim /= nd .or. tip%model /= self%model) then
         call fatal_error(error, 'Langevin integrator: the tip is not the one the integrator was set up for', &
            & error_input)
         return
      end if
      if (nsteps <= 0) return
      record_u = present(positions)
      record_v = present(velocities)
      if (record_u) then
         if (size(positions, 1) < nd .or. size(positions, 2) < nsteps) then
            call fatal_error(error, 'Langevin integrator: positions must hold '//itoa(nd)//' x '// &
               & itoa(nsteps)//' values', error_input)
            return
         end if
      end if
      if (record_v) then
         if (self%model /= model_inertial) then
            call fatal_error(error, 'Langevin integrator: the overdamped tip has no velocity to record', &
               & error_input)
            return
         end if
         if (size(velocities, 1) < nd .or. size(velocities, 2) < nsteps) then
            call fatal_error(error, 'Langevin integrator: velocities must hold '//itoa(nd)//' x '// &
               & itoa(nsteps)//' values', error_input)
            return
         end if
      end if

      start = tip%support_start
      vm = tip%support_velocity
      spring = tip%spring
      u = state%u
      w = state%velocity
      r = 0.0_wp
      t = self%time_of(state)
      ! The force at the start: F = -k u - ∇V(r_M(t) + u).
      do i = 1, 3
         r(i) = start(i) + vm(i) * t
      end do
      r(1:nd) = r(1:nd) + u(1:nd)
      call tip%potential%gradient(r, g)
      do i = 1, nd
         f(i) = -spring(i) * u(i) - g(i)
      end do

      if (self%model == model_inertial) then
         do j = 1, nsteps
            do i = 1, nd
               w(i) = w(i) + self%half_dt_over_mass * f(i)           ! B
               u(i) = u(i) + self%half_dt * (w(i) - vm(i))            ! A
            end do
            if (self%noisy) then
               do i = 1, nd                                          ! O
                  w(i) = self%decay(i) * w(i) + self%kick(i) * stream%gaussian()
               end do
            else
               do i = 1, nd
                  w(i) = self%decay(i) * w(i)
               end do
            end if
            t = state%t0 + real(state%steps + j, wp) * self%dt
            do i = 1, 3
               r(i) = start(i) + vm(i) * t
            end do
            do i = 1, nd
               u(i) = u(i) + self%half_dt * (w(i) - vm(i))            ! A
               r(i) = r(i) + u(i)
            end do
            call tip%potential%gradient(r, g)
            do i = 1, nd
               f(i) = -spring(i) * u(i) - g(i)
               w(i) = w(i) + self%half_dt_over_mass * f(i)           ! B
            end do
            if (record_u) positions(1:nd, j) = u(1:nd)
            if (record_v) velocities(1:nd, j) = w(1:nd)
         end do
      else
         noise = state%noise
         if (self%noisy .and. .not. state%noise_drawn) then
            do i = 1, nd
               noise(i) = stream%gaussian()
            end do
         end if
         do j = 1, nsteps
            t = state%t0 + real(state%steps + j, wp) * self%dt
            do i = 1, 3
               r(i) = start(i) + vm(i) * t
            end do
            do i = 1, nd
               u(i) = u(i) + self%drift(i) * f(i) - self%dt * vm(i)
               if (self%noisy) then
                  fresh = stream%gaussian()
                  u(i) = u(i) + self%spread(i) * (noise(i) + fresh)
                  noise(i) = fresh
               end if
               r(i) = r(i) + u(i)
            end do
            call tip%potential%gradient(r, g)
            do i = 1, nd
               f(i) = -spring(i) * u(i) - g(i)
            end do
            if (record_u) positions(1:nd, j) = u(1:nd)
         end do
         state%noise = noise
         state%noise_drawn = self%noisy
      end if

      state%steps = state%steps + nsteps
      state%u = u
      state%velocity = w
      if (.not. all(ieee_is_finite(u(1:nd))) .or. .not. all(ieee_is_finite(w(1:nd)))) then
         call fatal_error(error, 'Langevin integrator: the state is not finite at t = '// &
            & rtoa(self%time_of(state))//' s (a step of '//rtoa(self%dt)// &
            & ' s too large for the landscape, or an uninitialised random stream)', error_numerical)
      end if
   end subroutine advance

   !> The default step and the stability limit for tip, given the largest
   !> curvature of V (eV/Å², >= 0; see largest_curvature).  With
   !> k_eff = max k_i + curvature:
   !>   inertial:   ω_max = sqrt(k_eff/m); limit 2/ω_max (velocity Verlet's;
   !>               none without restoring force); default
   !>               fraction × min(1/ω_max, m/max c_i), the fastest of the
   !>               oscillation and the velocity relaxation;
   !>   overdamped: κ_max = k_eff/min c_i; limit 2/κ_max; default
   !>               fraction/κ_max.
   !> fraction defaults to default_step_fraction.  error_input when the tip
   !> has no time scale (no mass or damping to set one) or bad data.
   pure subroutine langevin_time_step(tip, curvature, dt, dt_limit, error, fraction)
      type(afm_tip), intent(in) :: tip
      real(wp), intent(in) :: curvature
      real(wp), intent(out) :: dt, dt_limit
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(in), optional :: fraction
      real(wp) :: share, k_eff, omega, fastest, c_max, c_min
      integer :: nd

      dt = 0.0_wp
      dt_limit = 0.0_wp
      share = default_step_fraction
      if (present(fraction)) share = fraction
      nd = tip%ndim
      if (nd < 1 .or. nd > 3 .or. .not. (share > 0.0_wp) .or. .not. (curvature >= 0.0_wp)) then
         call fatal_error(error, 'Langevin time step: needs 1 to 3 dimensions, fraction > 0 and curvature >= 0', &
            & error_input)
         return
      end if
      k_eff = maxval(tip%spring(1:nd)) + curvature
      c_max = maxval(tip%damping(1:nd))
      c_min = minval(tip%damping(1:nd))
      if (tip%model == model_inertial) then
         if (.not. (tip%mass > 0.0_wp)) then
            call fatal_error(error, 'Langevin time step: the inertial tip needs a mass > 0', error_input)
            return
         end if
         omega = sqrt(max(k_eff, 0.0_wp) / tip%mass)
         dt_limit = huge(1.0_wp)
         if (omega > 0.0_wp) dt_limit = 2.0_wp / omega
         fastest = huge(1.0_wp)
         if (omega > 0.0_wp) fastest = 1.0_wp / omega
         if (c_max > 0.0_wp) fastest = min(fastest, tip%mass / c_max)
         if (fastest >= huge(1.0_wp)) then
            call fatal_error(error, 'Langevin time step: neither spring, surface nor damping sets a time scale', &
               & error_input)
            return
         end if
         dt = share * fastest
      else if (tip%model == model_overdamped) then
         if (.not. (c_min > 0.0_wp) .or. .not. (k_eff > 0.0_wp)) then
            call fatal_error(error, 'Langevin time step: the overdamped tip needs damping > 0 on every axis '// &
               & 'and a spring or surface curvature > 0', error_input)
            return
         end if
         dt_limit = 2.0_wp * c_min / k_eff
         dt = share * c_min / k_eff
      else
         call fatal_error(error, 'Langevin time step: the tip model must be inertial or overdamped', error_input)
         return
      end if
      dt = min(dt, 0.5_wp * dt_limit)
   end subroutine langevin_time_step

   !> The largest eigenvalue of V's Hessian (its ndim × ndim block) over a
   !> grid of points^ndim positions spanning the box [low, high] (Å; other
   !> coordinates 0), and 0 if none is positive, eV/Å².  For a periodic
   !> surface one unit cell is enough; points = 32 resolves the largest
   !> curvature of NaF and HOPG to ~1 % (cos near its extremum).
   pure function largest_curvature(potential, low, high, points) result(curvature)
      class(surface_potential), intent(in) :: potential
      real(wp), intent(in) :: low(:), high(:)
      integer, intent(in) :: points
      real(wp) :: curvature
      real(wp) :: r(3), h(3, 3), values(3), vectors(3, 3), step(3)
      integer :: nd, idx(3), i, total, k, m

      nd = min(size(low), size(high), 3)
      curvature = 0.0_wp
      if (nd < 1 .or. points < 1) return
      step = 0.0_wp
      do i = 1, nd
         if (points > 1) step(i) = (high(i) - low(i)) / real(points - 1, wp)
      end do
      total = points**nd
      do k = 0, total - 1
         m = k
         do i = 1, nd
            idx(i) = mod(m, points)
            m = m / points
         end do
         r = 0.0_wp
         do i = 1, nd
            r(i) = low(i) + step(i) * real(idx(i), wp)
         end do
         call potential%hessian(r, h)
         call symmetric_eigen(h(1:nd, 1:nd), values(1:nd), vectors(1:nd, 1:nd))
         curvature = max(curvature, values(nd))
      end do
   end function largest_curvature

end module friction_afm_langevin
