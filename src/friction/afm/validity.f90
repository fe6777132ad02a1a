!> Where the reduced tip models hold (docs/physics.md, reduced tip models).  The
!> program warns, it does not refuse: a reduced model outside its limit
!> still runs, and docs/speed.md shows what it costs in accuracy.
module friction_afm_validity
   use friction_kinds, only: wp, i8, ev_per_angstrom_to_nn, deg_to_rad
   use friction_error, only: error_type
   use friction_afm_config, only: afm_config, new_tip, tip_stiffness, surface_hopg, surface_row, surface_fourier
   use friction_ode_auto, only: stiff_threshold
   use friction_afm_tip, only: afm_tip, model_inertial, model_overdamped, model_quasistatic, find_height
   use friction_afm_scan, only: afm_scanner
   use friction_surface_potential, only: surface_potential
   use friction_strings, only: rtoa, itoa, fixed_text
   use friction_scene_report, only: job_reporter
   use friction_afm_slow_limit, only: in_slow_limit, following_excess, bias_factor
   use friction_afm_trip, only: q_fx, q_fy, q_tip_x, q_tip_y
   implicit none
   private

   public :: afm_model_warnings, surface_force_scale, quasistatic_friction_warning, following_bias, &
      & following_bias_warning

   !> quasistatic: largest viscous drag c v, as a share of the surface force
   real(wp), parameter :: drag_share = 0.01_wp
   !> overdamped: largest quality factor sqrt(m k)/c (damping ratio 1/2: a
   !> slip overshoots its new minimum by exp(-π/√3) = 16 %)
   real(wp), parameter :: quality_limit = 1.0_wp
   !> grid points per side over the scan area for the surface force
   integer, parameter :: grid = 64
   !> thermal reduced model: the largest share of its jumps it may force at
   !> its barrier floor (where no clock fired before the barrier fell to
   !> 1 k_B T).  Calibrated on NaF at 300 K against the Langevin tip
   !> (docs/physics.md): it agrees at 30 Å/s, where the share is below
   !> 10 %, and is 12 standard errors low at 100 Å/s, where it is 36 %
   !> (70 % at 300 Å/s); the limit falls at 42 Å/s.
   real(wp), parameter :: forced_share_limit = 0.1_wp
   !> thermal reduced model: the estimated computing time per process, s,
   !> above which the program says so before the run (a minute: the
   !> estimate's error is a factor of about 2, and below a minute a user
   !> waits without being told)
   real(wp), parameter :: kramers_cost_limit = 60.0_wp
   !> the wall time, s, of the sample the estimate scales up (the rest of
   !> the trip is extrapolated)
   real(wp), parameter :: cost_sample = 5.0_wp
   !> GSL's explicit steppers: on a stiff tip their steps are bound by
   !> stability (docs/physics.md, reduced tip models)
   character(len=*), parameter :: explicit_steppers(6) = [character(len=7) :: 'rk2', 'rk4', 'rkf45', 'rkck', &
      & 'rk8pd', 'msadams']

contains

   !> Why the settings' reduced model may not hold, one reason per line
   !> ('' when it holds or the model is the full one).  Settings as in the
   !> namelist (SI for the tip, Å/s for the scan), with the run's surface
   !> (so a lattice sum is not built twice).
   !>   quasistatic: the viscous drag c v along the scan is more than 1 % of
   !>     the largest lateral surface force (damping then raises the
   !>     friction with the velocity), or the full tip takes longer to settle
   !>     after a slip (5 decay times, to 1 %) than the support takes to the
   !>     next sample (samples then catch it still moving; undamped it
   !>     never settles);
   !>   overdamped: in some moving direction sqrt(m k)/c > 1 (the tip
   !>     overshoots after a slip, which needs inertia).
   !>   thermal reduced model: above its velocity range (too many jumps
   !>     forced at its barrier floor), or an estimated cost above
   !>     kramers_cost_limit per process.
   !> The reduced model's probe (a trip of line 0) honours max_wall_time and
   !> the stop requests of `stopper`; `started` (the clock count at its
   !> start, 0 without a probe) lets the run count its time from there.
   function afm_model_warnings(config, potential, stopper, nranks, started) result(text)
      type(afm_config), intent(in) :: config
      class(surface_potential), intent(in) :: potential   !! the run's surface, built from config
      class(job_reporter), intent(in), optional :: stopper
      integer, intent(in), optional :: nranks             !! processes sharing the lines (default 1)
      integer(i8), intent(out), optional :: started
      character(len=:), allocatable :: text
      real(wp) :: mass, spring(3), damping(3), drag, scale, settle, spacing, quality, theta
      integer :: nd, i
      character(len=:), allocatable :: axes
      character(len=1), parameter :: axis(3) = ['x', 'y', 'z']
      real(wp), allocatable :: hazards(:)   !! kramers_note's probe

      text = ''
      if (present(started)) started = 0
      if (config%thermal%enabled() .and. config%thermal%reduced()) call kramers_note()
      if (.not. config%thermal%enabled()) call stiff_note()
      if (config%tip_model() == model_inertial) return
      nd = merge(3, 2, config%moves_in_3d())
      mass = config%mass
      spring = [config%kx, config%ky, config%kz]
      damping = [config%cx, config%cy, config%cz]
      if (config%tip_model() == model_overdamped) then
         ! (The overdamped model has no mass; the check needs the tip's own,
         ! not the default of the inertial model.)
         if (.not. config%mass_given) return
         axes = ''
         do i = 1, nd
            if (.not. (damping(i) > 0.0_wp)) cycle
            quality = sqrt(mass * spring(i)) / damping(i)
            if (quality > quality_limit) axes = axes//merge(', ', '  ', len(axes) > 0)//axis(i)//' (' &
               & //fixed(quality, 2)//')'
         end do
         if (len(axes) > 0) call add('overdamped model with an underdamped tip: sqrt(m k)/c > ' &
            & //fixed(quality_limit, 1)//' along '//axes(3:)//' with &tip mass = '//rtoa(mass) &
            & //" kg; it overshoots after a slip, which the overdamped model leaves out (use 'inertial')")
         return
      end if
      ! Quasistatic: drag against the surface force.
      theta = config%angle * deg_to_rad
      drag = (config%cx * cos(theta)**2 + config%cy * sin(theta)**2) * config%velocity * 0.1_wp  ! nN
      scale = surface_force_scale(config, potential)
      if (scale > 0.0_wp .and. drag > drag_share * scale) call add('quasistatic model at a speed where ' &
         & //'the viscous drag c v = '//fixed(drag, 4)//' nN is '//fixed(100 * drag / scale, 1) &
         & //' % of the largest surface force '//fixed(scale, 2)//' nN (> '//itoa(nint(100 * drag_share)) &
         & //" %): damping raises the friction, which the quasistatic model leaves out (use 'inertial')")
      ! Settling after a slip against the time between samples.
      spacing = config%length / real(config%nx - 1, wp)
      settle = 0.0_wp
      do i = 1, nd
         if (.not. (damping(i) > 0.0_wp)) then
            call add('quasistatic model for an undamped tip (c'//axis(i)//' = 0): the full tip rings ' &
               & //'after every slip, the quasistatic one lands at rest in the next minimum')
            return
         end if
         settle = max(settle, 5.0_wp * decay_time(mass, spring(i), damping(i)))
      end do
      if (settle * config%velocity > spacing) call add('quasistatic model while the tip takes ' &
         & //rtoa(settle)//' s to settle after a slip, '//fixed(settle * config%velocity, 3) &
         & //' Å of support travel, more than the sample spacing '//fixed(spacing, 3) &
         & //" Å: samples after a slip see the full tip still moving (use 'inertial' or a lower velocity)")

   contains

      !> An explicit stepper on a stiff tip (stiffness S = the largest decay
      !> rate times the sample interval above stiff_threshold, where
      !> method = 'auto' picks an implicit one): its steps hover at its
      !> stability limit, where its error estimate can miss the growth of the
      !> stiff component until the tip is pushed out of its well (measured
      !> on the overdamped tip: slips a sample or two early at rtol 1e-3).
      subroutine stiff_note()
         real(wp) :: stiffness

         if (config%tip_model() == model_quasistatic .or. .not. any(explicit_steppers == config%solver%method)) return
         stiffness = tip_stiffness(config)
         if (stiffness > stiff_threshold) call add("explicit stepper '"//trim(config%solver%method) &
            & //"' on a stiff tip (stiffness "//speed(stiffness)//': its fastest decay rate times the sample ' &
            & //'interval, above '//itoa(nint(stiff_threshold))//'): its steps are bound by stability, and at ' &
            & //'loose tolerances its error control can let the tip slip early; use '//"method = 'auto' " &
            & //"(rodas4 here) or tighter rtol and atol")
      end subroutine stiff_note

      !> The thermal reduced model above its velocity range: too many of its
      !> jumps come at the floor, forced, instead of by thermal escape
      !> (afm_scanner%kramers_escape_hazards; a jump after hazard H is
      !> forced with probability exp(-H), and H scales as 1/v).
      subroutine kramers_note()
         type(afm_scanner) :: scanner
         type(error_type), allocatable :: error
         real(wp) :: share, low, high, middle, cost, theta, period
         logical :: lower
         integer :: k

         call scanner%init(config, potential, error)
         if (allocated(error)) return
         if (present(started)) started = scanner%guard%clock_start
         if (present(stopper)) allocate (scanner%guard%stopper, source=stopper)
         ! (A probe stopped by max_wall_time or a request says nothing: the
         ! run, which counts its time from the probe's start, stops at once.)
         ! The cost first: a sample of one trip, scaled to the map.
         ! The period along the scan: where the scan line first crosses a
         ! line of the lattice (HOPG: its longer rectangular period, a√3).
         theta = config%angle * deg_to_rad
         if (config%surface_kind() == surface_hopg) then
            period = sqrt(3.0_wp) * config%a
         else if (config%surface_kind() == surface_row .or. config%surface_kind() == surface_fourier) then
            period = config%ax / max(abs(cos(theta)), 1.0e-12_wp)
         else
            period = min(config%ax / max(abs(cos(theta)), 1.0e-12_wp), config%ay / max(abs(sin(theta)), 1.0e-12_wp))
         end if
         cost = scanner%kramers_trip_cost(config%lead_in + period, cost_sample, lower) * merge(2, 1, config%retrace) &
            & * config%thermal%realizations * config%ny
         if (present(nranks)) cost = cost / max(1, nranks)
         if (cost > kramers_cost_limit) call add("thermal reduced model (&thermal model = 'kramers'): " &
            & //trim(merge('at least', 'about   ', lower))//' '//itoa(nint(cost, i8))//' s of computing per ' &
            & //'process for this map (from a sample of line 0): the jumps back and forth between ' &
            & //'neighbouring minima, whose number grows as 1/(v c) (v the velocity, c the damping) in the ' &
            & //'thermolubric regime, take the time; fewer realizations or lines, or a higher velocity, cost less')
         call scanner%kramers_escape_hazards(hazards, error)
         if (allocated(error)) return
         if (size(hazards) == 0) return
         share = forced_share(1.0_wp)
         if (share <= forced_share_limit) return
         ! The velocity at which the share falls to the limit: bisection in log v.
         low = log(1.0e-6_wp)
         high = 0.0_wp
         if (forced_share(exp(low)) > forced_share_limit) then
            high = low
         else
            do k = 1, 60
               middle = 0.5_wp * (low + high)
               if (forced_share(exp(middle)) > forced_share_limit) then
                  high = middle
               else
                  low = middle
               end if
            end do
         end if
         call add("thermal reduced model (&thermal model = 'kramers') above its velocity range: " &
            & //itoa(nint(100 * share))//' % of its jumps on line 0 would come where the barrier has ' &
            & //'fallen to its 1 k_B T floor, forced, not by thermal escape (more than ' &
            & //itoa(nint(100 * forced_share_limit))//' %; it holds below '//speed(exp(high) * config%velocity) &
            & //" Å/s): its friction is then too low (use model = 'langevin')")
      end subroutine kramers_note

      !> The mean of exp(-H v/v') over the probe's jumps, at v'/v = ratio.
      real(wp) function forced_share(ratio)
         real(wp), intent(in) :: ratio

         forced_share = sum(exp(-hazards / ratio)) / size(hazards)
      end function forced_share

      subroutine add(line)
         character(len=*), intent(in) :: line

         if (len(text) > 0) text = text//new_line('a')
         text = text//line
      end subroutine add

   end function afm_model_warnings

   !> After a quasistatic map: '' or a warning when the viscous drag c v
   !> along the scan is more than 1 % of the mean friction the map found
   !> (nN), the friction the full model would add to.  The rule before the
   !> run compares the drag with the surface force, which can be far above
   !> the friction (HOPG at 400 Å/s: drag 0.96 % of the force, 3 % of the
   !> friction; docs/physics.md, reduced tip models).
   function quasistatic_friction_warning(config, friction) result(text)
      type(afm_config), intent(in) :: config
      real(wp), intent(in) :: friction
      character(len=:), allocatable :: text
      real(wp) :: theta, drag

      text = ''
      if (config%tip_model() /= model_quasistatic .or. .not. (friction > 0.0_wp)) return
      theta = config%angle * deg_to_rad
      drag = (config%cx * cos(theta)**2 + config%cy * sin(theta)**2) * config%velocity * 0.1_wp  ! nN
      if (drag > drag_share * friction) text = 'quasistatic model: the viscous drag c v = '//fixed(drag, 4) &
         & //' nN is '//fixed(100 * drag / friction, 1)//' % of the mean friction of this map, ' &
         & //fixed(friction, 4)//" nN (> "//itoa(nint(100 * drag_share))//" %): the full model's friction is " &
         & //"higher by at least that (use 'inertial' or a lower velocity)"
   end function quasistatic_friction_warning

   !> After an overdamped map at T = 0 in the slow limit (in_slow_limit):
   !> the largest distance of a sample from where the tip follows its
   !> minimum, in units of the tolerances' bound (following_excess), over
   !> the samples of `trace` and `retrace` (values(i, j, q) of this rank's
   !> lines) whose two intervals before, in the order of the support's
   !> motion, hold no slip (the tip moved less than 0.5 Å in each; the
   !> first two samples of a trip have none); 0 where not checked.  The
   !> slip check (friction_afm_slow_limit) catches wrong slips during the
   !> trip; this catches a bias that leaves every slip where it belongs.
   function following_bias(config, tip, trace, retrace) result(worst)
      type(afm_config), intent(in) :: config
      type(afm_tip), intent(in) :: tip
      real(wp), intent(in) :: trace(:, :, :), retrace(:, :, :)
      real(wp) :: worst
      type(afm_tip) :: probe
      real(wp) :: d(3), excess, minimum(2, 3)
      integer :: j, k, i, trip, n, step, first, last
      logical :: valid

      worst = 0.0_wp
      if (config%tip_model() /= model_overdamped .or. config%thermal%enabled() .or. tip%ndim /= 2) return
      if (.not. in_slow_limit(tip, config%velocity)) return
      probe = tip
      d = config%scan_direction()
      n = size(trace, 1)
      do trip = 0, merge(1, 0, config%retrace)
         do j = 1, size(trace, 2)
            first = merge(1, n, trip == 0)
            last = merge(n, 1, trip == 0)
            step = merge(1, -1, trip == 0)
            probe%support_velocity = merge(1.0_wp, -1.0_wp, trip == 0) * config%velocity * d
            minimum = huge(1.0_wp)
            do i = first, last, step
               if (trip == 0) then
                  call at_sample(trace(i, j, :))
               else
                  call at_sample(retrace(i, j, :))
               end if
            end do
         end do
      end do

   contains

      !> One sample in the order of the motion: its minimum's absolute
      !> position kept for the next two (minimum(:, 1) the newest), and its
      !> excess where the two intervals before hold no slip.
      subroutine at_sample(values)
         real(wp), intent(in) :: values(:)
         real(wp) :: u(2), r(2)
         logical :: followed

         r = [values(q_tip_x), values(q_tip_y)]
         ! F = k (r_M - r) = -k u, nN against eV/Å².
         u = -[values(q_fx), values(q_fy)] / (ev_per_angstrom_to_nn * tip%spring(1:2))
         probe%support_start(1:2) = r - u
         probe%support_start(3) = 0.0_wp
         call following_excess(probe, 0.0_wp, u, [config%solver%rtol, config%solver%atol], excess, valid)
         ! (The tip's own position stands for its minimum's: a slip moves both a lattice site.)
         minimum(:, 3) = minimum(:, 2)
         minimum(:, 2) = minimum(:, 1)
         minimum(:, 1) = r
         followed = norm2(minimum(:, 1) - minimum(:, 2)) < 0.5_wp .and. norm2(minimum(:, 2) - minimum(:, 3)) < 0.5_wp
         if (valid .and. followed) worst = max(worst, excess)
      end subroutine at_sample

   end function following_bias

   !> '' or the warning when following_bias (over the whole map) is above
   !> bias_factor: the stepper, its tolerances and the remedy.
   function following_bias_warning(config, worst) result(text)
      type(afm_config), intent(in) :: config
      real(wp), intent(in) :: worst
      character(len=:), allocatable :: text

      text = ''
      if (.not. (worst > bias_factor)) return
      text = 'overdamped tip at T = 0: where it follows its minimum of the total energy, the tip is up to ' &
         & //fixed(worst, 1)//' times the tolerances'' bound atol + rtol |u| from where it lags behind it ' &
         & //'(a bias of '//trim(config%solver%method)//' at rtol = '//rtoa(config%solver%rtol)//', atol = ' &
         & //rtoa(config%solver%atol)//": the tolerances bound each step, not the run; on a stiff 1-D row " &
         & //"rk4imp's bias moved the friction by 1.1e-3 nN): tighten rtol and atol, or use method = " &
         & //"'rodas4' or 'auto' (docs/physics.md, reduced tip models)"
   end function following_bias_warning

   !> The slowest decay time of m x'' + c x' + k x = 0, s (SI inputs): the
   !> envelope 2m/c when underdamped, else the slow root's 1/|λ|.
   pure real(wp) function decay_time(m, k, c) result(tau)
      real(wp), intent(in) :: m, k, c

      if (c**2 <= 4.0_wp * m * k) then
         tau = 2.0_wp * m / c
      else
         tau = 2.0_wp * m / (c - sqrt(c**2 - 4.0_wp * m * k))
      end if
   end function decay_time

   !> The largest lateral force of the surface over the scan area, nN, on a
   !> 64 x 64 grid: for a lattice sum at the height the loaded tip rests at
   !> above the scan origin (0 if that height cannot be found).
   function surface_force_scale(config, potential) result(scale)
      type(afm_config), intent(in) :: config
      class(surface_potential), intent(in) :: potential
      real(wp) :: scale
      type(afm_tip) :: tip
      type(error_type), allocatable :: error
      real(wp) :: origin(3), height, contact, r(3), g(3)
      integer :: i, j

      scale = 0.0_wp
      origin = [config%origin_x, config%origin_y, 0.0_wp]
      height = 0.0_wp
      if (potential%dimensions() == 3) then
         call new_tip(config, potential, tip)
         call find_height(tip, origin, 0.0_wp, contact, error)
         if (allocated(error)) return
         call find_height(tip, [origin(1), origin(2), contact + config%support_z], tip%spring(3), height, error)
         if (allocated(error)) return
      end if
      do j = 0, grid - 1
         do i = 0, grid - 1
            r = origin + config%length * i / (grid - 1) * config%scan_direction() &
               & + config%width * j / (grid - 1) * config%across_direction()
            r(3) = height
            call potential%gradient(r, g)
            scale = max(scale, norm2(g(1:2)))
         end do
      end do
      scale = scale * ev_per_angstrom_to_nn
   end function surface_force_scale

   !> A velocity with two significant digits, no padding: 42.0, 3.1, 0.0042
   !> (a fixed number of decimals gave 0.0 below 0.05 Å/s).
   function speed(value) result(text)
      real(wp), intent(in) :: value
      character(len=:), allocatable :: text
      character(len=32) :: buffer

      if (value >= 10.0_wp) then
         text = itoa(nint(value, i8))
      else if (value >= 1.0_wp) then
         text = fixed(value, 1)
      else
         write (buffer, '(es8.1)') value
         text = trim(adjustl(buffer))
      end if
   end function speed

   !> A number with `digits` decimals, no padding.
   function fixed(value, digits) result(text)
      real(wp), intent(in) :: value
      integer, intent(in) :: digits
      character(len=:), allocatable :: text

      text = fixed_text(value, digits)
   end function fixed

end module friction_afm_validity
