!> Scan geometry and the integration of one trip of the support.
!>
!> Line j (0-based) runs along the scan direction at the offset
!> t_j = j * width / (ny - 1) across it (the direction turned by +90°) from the origin.
!> Sample i sits at s_i = i * length / (nx - 1) along the line.  A trace trip
!> moves the support from s = -lead_in to s = length; a retrace trip from
!> s = length + lead_in back to 0; samples are stored by i either way, so
!> trace and retrace share the support_x axis.  Each trip starts with the tip
!> at the support and at rest (paper §3.1, §5.1); the quasistatic tip starts
!> in the minimum it relaxes into from there.
!>
!> The reduced models (docs/physics.md, reduced tip models): the overdamped tip is
!> integrated like the full one (friction_afm_tip); the quasistatic tip is
!> followed from sample to sample along its minimum of the total energy
!> (friction_afm_quasistatic), and jumps to the next minimum where its own
!> disappears (see follow).
!>
!> At a temperature (&thermal temperature > 0; README: Friction at a
!> temperature) a trip is integrated with the Langevin tip
!> (friction_afm_langevin: BAOAB, or Leimkuhler–Matthews without inertia) at
!> a fixed step, the largest not above the chosen one that divides the
!> sample interval (and the lead-in) into whole steps, so that samples fall
!> on steps.  The tip starts at the support with a velocity drawn from the
!> bath's Maxwell–Boltzmann distribution; the noise is the random stream of
!> (seed, line, trip, realization), trip 0 the trace and 1 the retrace, so
!> a trip's samples depend on nothing else (not on the ranks).  run_line
!> gives a line's trips over all realizations: the mean of every sample,
!> its standard error, and the friction with its standard error.
!>
!> Slips at a temperature (see check_slips): every check_distance of
!> support travel (and at every sample) the tip's state is quenched, by
!> Newton's method on the total energy (friction_afm_kramers'
!> find_minimum), into the minimum whose basin it is in; a slip is a change
!> of that minimum by more than slip_distance.  Recorded: where the support
!> was and the force along the scan at the last check before the slip, and
!> the jump of the minimum along the support's motion (negative for a slip
!> back) and across the scan.  The checks split the Langevin steps into calls, which leaves the
!> trajectory bit for bit as it is.
module friction_afm_scan
   use friction_kinds, only: wp, i8, pi, ev_per_angstrom_to_nn
   use friction_error, only: error_type, fatal_error, error_input, error_numerical, error_interrupted
   use friction_ode_solver, only: ode_solver, integrator_statistics
   use friction_afm_config, only: afm_config, new_tip_owning, surface_curvature
   use friction_afm_tip, only: afm_tip, model_inertial, model_overdamped, model_quasistatic, find_height
   use friction_afm_thermal, only: welford_add, welford_sem
   use friction_afm_langevin, only: langevin_integrator, langevin_state, langevin_time_step, boltzmann
   use friction_afm_kramers, only: find_minimum, hazard_path, hazard_start, hazard_advance, jump_landing, &
      & hazard_running, hazard_low_barrier, hazard_paused, kmc_barrier_floor
   use friction_scene_report, only: job_reporter
   use friction_random, only: random_stream
   use friction_afm_quasistatic, only: newton_equilibrium, equilibrium_tangent, force_imbalance
   use friction_surface_potential, only: surface_potential
   use friction_surface_lennard_jones, only: lj_potential
   use friction_strings, only: rtoa, itoa, bytes_text, fixed_text
   use friction_files, only: available_memory
   implicit none
   private

   public :: afm_scanner, trip_record, quantity_names, quantity_units, n_quantities, quantity_count
   public :: q_fx, q_fy, q_f_along, q_f_across, q_tip_x, q_tip_y, q_fz, q_tip_z, q_jumps
   public :: support_along, support_across, find_height, support_at, line_offset, line_record, slip_list

   integer, parameter :: n_quantities = 9
   integer, parameter :: q_fx = 1, q_fy = 2, q_f_along = 3, q_f_across = 4, q_tip_x = 5, q_tip_y = 6, &
      & q_fz = 7, q_tip_z = 8, q_jumps = 9
   !> HDF5 dataset names and units of the recorded quantities; fz and tip_z
   !> only for a tip that moves in z; jumps (those of the quasistatic tip
   !> since the previous sample) only for the quasistatic model.
   character(len=*), parameter :: quantity_names(n_quantities) = [character(len=8) :: &
      & 'fx', 'fy', 'f_along', 'f_across', 'tip_x', 'tip_y', 'fz', 'tip_z', 'jumps']
   character(len=*), parameter :: quantity_units(n_quantities) = [character(len=8) :: &
      & 'nN', 'nN', 'nN', 'nN', 'angstrom', 'angstrom', 'nN', 'angstrom', '1']

   !> Quasistatic tracking (see follow): the support travel, Å, to which a
   !> fold is located (the force near a fold varies like the square root of
   !> the distance to it: ~1e-4 nN here); the push, Å, that starts the tip
   !> off the vanished minimum (small against any lattice period, large
   !> against the ~sqrt(fold_resolution) ghost of the minimum); how close,
   !> Å, the relaxed state must be to the minimum Newton's method finds from
   !> it; relaxation stretches (of 10 relaxation times) before giving up.
   real(wp), parameter :: fold_resolution = 1.0e-9_wp, jump_push = 0.05_wp, landing_distance = 0.05_wp
   integer, parameter :: max_stretches = 100000
   !> Slips at a temperature (see check_slips): the support travel between
   !> two quenches, Å (in a stick the force then changes by the stick slope
   !> times 0.05 Å, ~0.04 nN on NaF, below its thermal spread sqrt(k k_B T)
   !> = 0.2 nN at 300 K; the quenches' cost: docs/speed.md); the jump of
   !> the quenched minimum that is a slip, Å (below any well spacing of NaF
   !> or HOPG, above any drift of a minimum between two checks).
   real(wp), parameter :: check_distance = 0.05_wp, slip_distance = 0.5_wp
   !> The thermal reduced model (see run_kramers_trip): the exits searched
   !> from a minimum (along the support's motion and against it, each also
   !> turned by ±exit_angle, rad: 40°, between the motion and the diagonal
   !> saddles of a square lattice); the support travel between two searches, Å (a tenth of
   !> NaF's shortest well spacing); the barrier, in k_B T, below which an
   !> exit fires at once: friction_afm_kramers' kmc_barrier_floor (1 k_B T,
   !> down to which the Kramers rate of a cubic barrier holds within 10 %).
   integer, parameter :: n_exits = 6
   real(wp), parameter :: exit_angle = 40.0_wp * pi / 180.0_wp, search_distance = 0.1_wp
   real(wp), parameter :: barrier_floor = kmc_barrier_floor
   !> Wall time, s, between two looks at the stop request within a trip (the
   !> C API's request is a call into the caller's code), and the Langevin
   !> steps between two looks at the clock: at ~100 ns a step, ~10 ms.
   real(wp), parameter :: stop_poll = 0.1_wp
   !> The overdamped tip's slips at T = 0 (check_overdamped_slip): checked
   !> where the support travels at most slow_travel Å in the tip's slowest
   !> spring relaxation time c_i/k_i (then it lags its minimum by about that
   !> much, and lands where the descent at a fixed support lands: the slow
   !> limit), and from samples within check_lag Å of their minimum; two
   !> minima are the same within same_minimum Å (below any well spacing of
   !> NaF or HOPG); the descent's step, Å.
   real(wp), parameter :: slow_travel = 2.5e-3_wp, check_lag = 0.05_wp, same_minimum = 0.25_wp
   !> and how many times the time the slip takes from the fold (the
   !> passage through the fold's bottleneck and the relaxation into the new
   !> well, integrated by slip_duration) a tip may take to land
   real(wp), parameter :: late_factor = 3.0_wp
   real(wp), parameter :: descent_step = 0.01_wp
   integer, parameter :: langevin_chunk = 100000

   !> One trip's samples: values(i, q) for sample i and quantity q (output units).
   type :: trip_record
      real(wp), allocatable :: values(:, :)
   end type trip_record

   !> One line over all realizations (run_line): per trip the mean of every
   !> sample, values(i, q) as trip_record's, and its standard error over the
   !> realizations (NaN for one realization; 0 at T = 0, where there is one
   !> deterministic trip); the line's friction (half the difference of the
   !> mean force along on trace and retrace) and its standard error.
   !> Slips in the order they happened: realization (0-based), trip (0
   !> trace, 1 retrace), support position along the line (Å, as
   !> support_along), force along the scan before the slip (nN), jump of
   !> the minimum along the support's motion and across the scan (Å).
   type :: slip_list
      integer :: n = 0
      integer, allocatable :: realization(:), trip(:)
      real(wp), allocatable :: support(:), force(:), jump(:), jump_across(:)
   contains
      procedure :: clear => slips_clear
      procedure :: add => slips_add
   end type slip_list

   type :: line_record
      real(wp), allocatable :: trace(:, :), retrace(:, :)
      real(wp), allocatable :: trace_sem(:, :), retrace_sem(:, :)
      real(wp) :: friction = 0.0_wp, friction_sem = 0.0_wp
      type(slip_list) :: slips   !! at a temperature
   end type line_record

   !> Integrates trips of one scene; owns one tip model and its solver.
   type :: afm_scanner
      type(afm_config) :: config
      type(afm_tip), allocatable :: tip
      type(ode_solver) :: solver
      real(wp) :: h_start = 0.0_wp
      integer(i8) :: clock_start = 0, clock_rate = 1   !! wall clock at init, for max_wall_time
      integer(i8) :: next_poll = 0                     !! clock count of the next look at `stopper`
      !> kramers_trip_cost: the clock count at which its sample ends (0: none),
      !> and the support time the sample reached
      integer(i8) :: sample_end = 0
      real(wp) :: reached = 0.0_wp
      real(wp) :: sample_stop = 0.0_wp     !! and the support time at which it ends
      !> asked within a trip whether the job should stop (a copy of the job's
      !> reporter: its request is the process's, not the copy's); none: never
      class(job_reporter), allocatable :: stopper
      real(wp) :: contact_height = 0.0_wp   !! z0: free tip's equilibrium height at the origin, Å (3D)
      real(wp) :: support_height = 0.0_wp   !! z_M = z0 + support_z, Å (3D)
      ! At a temperature (config%thermal)
      logical :: thermal = .false.
      logical :: kramers = .false.                 !! &thermal model = 'kramers' (no Langevin steps)
      type(langevin_integrator) :: langevin        !! the step between samples
      type(langevin_integrator) :: lead_langevin   !! the step of the lead-in
      integer :: sample_steps = 0                  !! Langevin steps between two samples
      integer :: lead_steps = 0                    !! Langevin steps of the lead-in
      integer :: check_steps = 0                   !! Langevin steps between two slip checks
      integer(i8) :: langevin_steps = 0, force_evaluations = 0
      integer(i8) :: hazard_steps = 0              !! model = 'kramers': steps along the KMC paths
      type(random_stream) :: stream
   contains
      procedure :: init
      procedure :: init_owning
      procedure :: release_potential
      procedure :: run_trip
      procedure :: run_thermal_trip
      procedure :: run_kramers_trip
      procedure :: kramers_escape_hazards
      procedure :: kramers_trip_cost
      procedure :: run_line
      procedure :: time_step
      procedure :: statistics
      procedure :: check_halt
      procedure, private :: follow
      procedure, private :: start_thermal_trip
      procedure, private :: start_height
      procedure, private :: relax
   end type afm_scanner

contains

   !> Quantities recorded for a tip moving in ndim dimensions (jumps apart).
   pure integer function quantity_count(ndim)
      integer, intent(in) :: ndim

      quantity_count = merge(q_tip_z, q_tip_y, ndim == 3)
   end function quantity_count

   !> Support position of sample i (0-based) along the line, Å.
   pure real(wp) function support_at(config, i) result(s)
      type(afm_config), intent(in) :: config
      integer, intent(in) :: i

      s = config%length * real(i, wp) / real(config%nx - 1, wp)
   end function support_at

   !> Offset of line j (0-based) across the scan, Å.
   pure real(wp) function line_offset(config, j) result(t)
      type(afm_config), intent(in) :: config
      integer, intent(in) :: j

      t = 0.0_wp
      if (config%ny > 1) t = config%width * real(j, wp) / real(config%ny - 1, wp)
   end function line_offset

   !> Support positions along the line, Å.
   pure function support_along(config) result(s)
      type(afm_config), intent(in) :: config
      real(wp), allocatable :: s(:)
      integer :: i

      allocate (s(config%nx))
      do i = 1, config%nx
         s(i) = support_at(config, i - 1)
      end do
   end function support_along

   !> Offsets of the lines across the scan, Å.
   pure function support_across(config) result(t)
      type(afm_config), intent(in) :: config
      real(wp), allocatable :: t(:)
      integer :: j

      allocate (t(config%ny))
      do j = 1, config%ny
         t(j) = line_offset(config, j - 1)
      end do
   end function support_across

   !> init_owning on a copy of `potential`.
   subroutine init(self, config, potential, error)
      class(afm_scanner), intent(inout) :: self
      type(afm_config), intent(in) :: config
      class(surface_potential), intent(in) :: potential
      type(error_type), allocatable, intent(out) :: error
      class(surface_potential), allocatable :: copy

      allocate (copy, source=potential)
      call self%init_owning(config, copy, error)
   end subroutine init

   !> init, the scanner's tip taking `potential` over (deallocated on
   !> return) instead of a copy.
   subroutine init_owning(self, config, potential, error)
      class(afm_scanner), intent(inout) :: self
      type(afm_config), intent(in) :: config
      class(surface_potential), allocatable, intent(inout) :: potential
      type(error_type), allocatable, intent(out) :: error

      if (allocated(self%tip)) deallocate (self%tip)
      allocate (self%tip)
      call new_tip_owning(config, potential, self%tip)
      call set_up(self, config, error)
   end subroutine init_owning

   !> The surface potential handed back (init_owning's in reverse), for a
   !> later scan of the same surface; the scanner can no longer run.
   subroutine release_potential(self, potential)
      class(afm_scanner), intent(inout) :: self
      class(surface_potential), allocatable, intent(inout) :: potential

      if (allocated(potential)) deallocate (potential)
      if (allocated(self%tip)) then
         if (allocated(self%tip%potential)) call move_alloc(self%tip%potential, potential)
      end if
   end subroutine release_potential

   !> The rest of init, around the tip made.
   subroutine set_up(self, config, error)
      class(afm_scanner), intent(inout) :: self
      type(afm_config), intent(in) :: config
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: sample_time, period

      self%config = config
      call system_clock(self%clock_start, self%clock_rate)
      if (self%tip%ndim == 3) then
         ! The support's height is set from the contact of the free tip at the
         ! scan origin: z_M = z0 + support_z (support_z < 0 presses the tip).
         call find_height(self%tip, [config%origin_x, config%origin_y, 0.0_wp], 0.0_wp, &
            & self%contact_height, error)
         if (allocated(error)) return
         if (below_net(self%tip, [config%origin_x, config%origin_y, self%contact_height])) call fatal_error(error, &
            & 'the contact height found at the scan origin lies within the layer of atoms, not above it: ' &
            & //'the net is too sparse for the tip (its atoms too far apart for their sigma, or a single atom ' &
            & //'away from the origin), so the tip would fall through; use a denser net, a larger sigma, or ' &
            & //'start the scan over the atoms', error_input)
         if (allocated(error)) return
         self%support_height = self%contact_height + config%support_z
      end if
      ! First step: a small fraction of the fastest time scale in sight
      ! (without inertia: the relaxation time c/k).
      sample_time = config%length / real(config%nx - 1, wp) / config%velocity
      period = sample_time
      if (maxval(self%tip%spring) > 0.0_wp) then
         if (self%tip%model == model_inertial) then
            period = min(period, 2.0_wp * pi * sqrt(self%tip%mass / maxval(self%tip%spring)))
         else
            period = min(period, minval(self%tip%damping(1:self%tip%ndim)) / maxval(self%tip%spring))
         end if
      end if
      self%h_start = config%solver%h_start
      ! (An h_min above the automatic first step raises it, as for the brake.)
      if (self%h_start <= 0.0_wp) self%h_start = max(1.0e-3_wp * period, config%solver%h_min)
      call self%solver%init(self%tip, config%solver, self%h_start, error)
      if (allocated(error)) return
      self%thermal = config%thermal%enabled()
      self%kramers = self%thermal .and. config%thermal%reduced()
      if (self%thermal .and. .not. self%kramers) call init_thermal()

   contains

      !> The Langevin steps: the largest not above the chosen one (the
      !> input's time_step, or langevin_time_step's default) that divide the
      !> sample interval and the lead-in into whole steps.
      subroutine init_thermal()
         real(wp) :: curvature, dt, limit, lead_time

         curvature = surface_curvature(config, self%tip%potential)
         call langevin_time_step(self%tip, curvature, dt, limit, error)
         if (allocated(error)) return
         if (config%thermal%time_step > 0.0_wp) dt = config%thermal%time_step
         if (max(sample_time, config%lead_in / config%velocity) / dt > 1.0e9_wp) then
            call fatal_error(error, 'Langevin: a step of '//rtoa(dt)//' s makes more than 1e9 steps between ' &
               & //'two samples', error_input)
            return
         end if
         self%sample_steps = max(1, ceiling(sample_time / dt))
         call self%langevin%init(self%tip, config%thermal%temperature, sample_time / self%sample_steps, error, &
            & curvature=curvature)
         if (allocated(error)) return
         self%check_steps = max(1, min(self%sample_steps, &
            & int(check_distance / (config%velocity * self%langevin%dt))))
         lead_time = config%lead_in / config%velocity
         self%lead_steps = 0
         if (lead_time > 0.0_wp) then
            self%lead_steps = max(1, ceiling(lead_time / dt))
            call self%lead_langevin%init(self%tip, config%thermal%temperature, lead_time / self%lead_steps, &
               & error, curvature=curvature)
         end if
      end subroutine init_thermal

   end subroutine set_up

   !> The Langevin step between samples, s (0 at T = 0).
   pure real(wp) function time_step(self)
      class(afm_scanner), intent(in) :: self

      time_step = 0.0_wp
      if (self%thermal) time_step = self%langevin%dt
   end function time_step

   !> Line j (0-based) over all realizations: its trace, and its retrace
   !> when the configuration scans back or `with_retrace` asks for it
   !> (line_record).  At T = 0 the deterministic trips (run_trip), standard
   !> errors 0.
   subroutine run_line(self, j, line, error, with_retrace)
      class(afm_scanner), intent(inout) :: self
      integer, intent(in) :: j
      type(line_record), intent(inout) :: line
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: with_retrace
      type(trip_record) :: trace, retrace
      real(wp) :: friction, m2
      integer :: r, nx, n
      logical :: back

      nx = self%config%nx
      back = self%config%retrace
      if (present(with_retrace)) back = with_retrace
      if (.not. self%thermal) then
         call self%run_trip(j, .true., trace, error)
         if (allocated(error)) return
         line%trace = trace%values
         line%trace_sem = 0.0_wp * trace%values
         if (back) then
            call self%run_trip(j, .false., retrace, error)
            if (allocated(error)) return
            line%retrace = retrace%values
            line%retrace_sem = 0.0_wp * retrace%values
            line%friction = 0.5_wp * (sum(trace%values(:, q_f_along)) - sum(retrace%values(:, q_f_along))) / nx
            line%friction_sem = 0.0_wp
         end if
         return
      end if
      n = self%config%thermal%realizations
      if (allocated(line%trace)) deallocate (line%trace, line%trace_sem)
      if (allocated(line%retrace)) deallocate (line%retrace, line%retrace_sem)
      allocate (line%trace(nx, n_quantities), line%trace_sem(nx, n_quantities))
      if (back) allocate (line%retrace(nx, n_quantities), line%retrace_sem(nx, n_quantities))
      line%friction = 0.0_wp
      m2 = 0.0_wp
      call line%slips%clear()
      do r = 1, n
         call self%run_thermal_trip(j, .true., r - 1, trace, error, line%slips)
         if (allocated(error)) return
         ! (the sums of squares go in the _sem arrays until the end)
         call welford_add(line%trace, line%trace_sem, trace%values, r)
         if (.not. back) cycle
         call self%run_thermal_trip(j, .false., r - 1, retrace, error, line%slips)
         if (allocated(error)) return
         call welford_add(line%retrace, line%retrace_sem, retrace%values, r)
         friction = 0.5_wp * (sum(trace%values(:, q_f_along)) - sum(retrace%values(:, q_f_along))) / nx
         call welford_add(line%friction, m2, friction, r)
      end do
      line%trace_sem = welford_sem(line%trace_sem, n)
      if (back) then
         line%retrace_sem = welford_sem(line%retrace_sem, n)
         line%friction_sem = welford_sem(m2, n)
      end if
   end subroutine run_line

   !> One Langevin trip along line j (0-based), trace when forward, with the
   !> noise of realization (0-based): samples as run_trip's; the slips
   !> between the first and the last sample appended to `slips` when given.
   subroutine run_thermal_trip(self, j, forward, realization, record, error, slips)
      class(afm_scanner), intent(inout) :: self
      integer, intent(in) :: j, realization
      logical, intent(in) :: forward
      type(trip_record), intent(inout) :: record
      type(error_type), allocatable, intent(out) :: error
      type(slip_list), intent(inout), optional :: slips
      type(langevin_state) :: state
      real(wp) :: along(3), across(3), s_start, force(3), tip_r(3), t
      real(wp) :: u0(3), minimum(3), last_support, last_force, motion(3)
      integer(i8) :: now
      integer :: i, k, nx, nd, done, n
      logical :: in_well
      character(len=128) :: where

      if (self%kramers) then
         call self%run_kramers_trip(j, forward, realization, record, error, slips)
         return
      end if
      call self%start_thermal_trip(j, forward, realization, record, along, across, s_start, error)
      if (allocated(error)) return
      associate (c => self%config, tip => self%tip)
         nx = c%nx
         ! At the support (in z at its static equilibrium under the load),
         ! with a thermal velocity (inertial tip).
         u0 = 0.0_wp
         if (tip%ndim == 3) then
            call self%start_height(j, u0(3), error)
            if (allocated(error)) then
               call self%stream%free()
               return
            end if
         end if
         t = 0.0_wp
         if (self%lead_steps > 0) then
            call self%lead_langevin%start(self%stream, 0.0_wp, u0, state)
            call self%lead_langevin%advance(tip, self%stream, state, self%lead_steps, error)
            self%langevin_steps = self%langevin_steps + self%lead_steps
            self%force_evaluations = self%force_evaluations + self%lead_steps + 1
            ! on with the samples' step from the end of the lead-in
            state%t0 = c%lead_in / c%velocity
            state%steps = 0
         else
            call self%langevin%start(self%stream, 0.0_wp, u0, state)
         end if
         nd = tip%ndim
         motion = tip%support_velocity / c%velocity
         in_well = .false.
         do k = 1, nx
            i = merge(k, nx + 1 - k, forward)
            if (k > 1 .and. .not. allocated(error)) then
               if (present(slips)) then
                  ! In stretches of check_steps, each followed by a check.
                  done = 0
                  do while (done < self%sample_steps .and. .not. allocated(error))
                     n = min(self%check_steps, self%sample_steps - done)
                     call self%langevin%advance(tip, self%stream, state, n, error)
                     self%force_evaluations = self%force_evaluations + n + 1
                     done = done + n
                     if (.not. allocated(error)) call check_slips()
                     if (.not. allocated(error) .and. done < self%sample_steps) &
                        & call self%check_halt('Langevin', self%langevin%time_of(state), error)
                  end do
               else
                  ! In chunks, the clock looked at between them (the same
                  ! trajectory bit for bit: the steps do not depend on the calls).
                  done = 0
                  do while (done < self%sample_steps .and. .not. allocated(error))
                     n = min(langevin_chunk, self%sample_steps - done)
                     call self%langevin%advance(tip, self%stream, state, n, error)
                     self%force_evaluations = self%force_evaluations + n + 1
                     done = done + n
                     if (.not. allocated(error) .and. done < self%sample_steps) &
                        & call self%check_halt('Langevin', self%langevin%time_of(state), error)
                  end do
               end if
               self%langevin_steps = self%langevin_steps + self%sample_steps
            else if (k == 1 .and. present(slips)) then
               call check_slips()
            end if
            t = self%langevin%time_of(state)
            if (.not. allocated(error)) call self%check_halt('Langevin', t, error)
            if (allocated(error)) then
               write (where, '(a, i0, a, i0, a, f0.4, a)') ' (line ', j, &
                  & trim(merge(' trace  ', ' retrace', forward))//', realization ', realization, &
                  & ', support at ', c%velocity * t, ' Å into the trip)'
               error%message = error%message//trim(where)
               call self%stream%free()
               return
            end if
            force = tip%lateral_force(state%u) * ev_per_angstrom_to_nn
            tip_r = tip%tip_position(t, state%u)
            if (nd == 3) then
               ! (The message is built only when it is needed: a sample's check
               ! must not format numbers.)
               if (below_net(tip, tip_r)) call fatal_error(error, 'the tip went below the layer of atoms at (' &
                  & //rtoa(tip_r(1))//', '//rtoa(tip_r(2))//', '//rtoa(tip_r(3))//') Å (line '//itoa(j) &
                  & //trim(merge(' trace  ', ' retrace', forward))//', realization '//itoa(realization) &
                  & //'): off the edge of the net, or pressed through it by the load; scan over the net, or ' &
                  & //'raise support_z', error_input)
               if (allocated(error)) then
                  call self%stream%free()
                  return
               end if
            end if
            record%values(i, q_fx) = force(1)
            record%values(i, q_fy) = force(2)
            record%values(i, q_f_along) = dot_product(force, along)
            record%values(i, q_f_across) = dot_product(force, across)
            record%values(i, q_tip_x) = tip_r(1)
            record%values(i, q_tip_y) = tip_r(2)
            record%values(i, q_fz) = force(3)
            record%values(i, q_tip_z) = tip_r(3)
            record%values(i, q_jumps) = 0.0_wp
         end do
         call self%stream%free()
      end associate

   contains

      !> Quench the state into its minimum; a slip when the minimum moved by
      !> more than slip_distance since the last check.  (A quench that does
      !> not converge leaves the check out.)
      subroutine check_slips()
         type(error_type), allocatable :: quench_error
         real(wp) :: u_min(3), here(3), support_now, force_now, tn

         associate (c => self%config, tip => self%tip)
            tn = self%langevin%time_of(state)
            u_min = 0.0_wp
            call find_minimum(tip, tn, state%u(1:nd), u_min(1:nd), quench_error)
            if (allocated(quench_error)) return
            here = tip%support(tn)
            here(1:nd) = here(1:nd) + u_min(1:nd)
            support_now = merge(s_start + c%velocity * tn, s_start - c%velocity * tn, forward)
            force_now = -dot_product(tip%spring(1:nd) * state%u(1:nd), along(1:nd)) * ev_per_angstrom_to_nn
            if (in_well) then
               if (norm2(here(1:nd) - minimum(1:nd)) > slip_distance) call slips%add(realization, &
                  & merge(0, 1, forward), last_support, last_force, dot_product(here - minimum, motion), &
                  & dot_product(here - minimum, across))
            end if
            minimum = here
            last_support = support_now
            last_force = force_now
            in_well = .true.
         end associate
      end subroutine check_slips

   end subroutine run_thermal_trip

   !> The tip's start in z (3D tip) on line j, the support's path set: the
   !> support at its height, the tip at its static equilibrium under it;
   !> returns u_z = z - z_M.  An error when the load presses the tip into
   !> the layer of atoms.
   subroutine start_height(self, j, u_z, error)
      class(afm_scanner), intent(inout) :: self
      integer, intent(in) :: j
      real(wp), intent(out) :: u_z
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: z_start

      associate (c => self%config, tip => self%tip)
         u_z = 0.0_wp
         tip%support_start(3) = self%support_height
         call find_height(tip, tip%support_start, tip%spring(3), z_start, error)
         if (allocated(error)) return
         if (below_net(tip, [tip%support_start(1:2), z_start])) call fatal_error(error, 'at the start of line ' &
            & //itoa(j)//' the load presses the tip into the layer of atoms (support_z = '//rtoa(c%support_z) &
            & //' Å from the contact height, kz = '//rtoa(c%kz)//' N/m): raise support_z', error_input)
         if (allocated(error)) return
         u_z = z_start - self%support_height
      end associate
   end subroutine start_height

   !> What a trip at a temperature starts with: the support at the start of
   !> line j (0-based), moving forward (trace) or back, the trip's record,
   !> and the random stream of (seed, line, trip, realization).
   subroutine start_thermal_trip(self, j, forward, realization, record, along, across, s_start, error)
      class(afm_scanner), intent(inout) :: self
      integer, intent(in) :: j, realization
      logical, intent(in) :: forward
      type(trip_record), intent(inout) :: record
      real(wp), intent(out) :: along(3), across(3), s_start
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: line_start(3), offset(self%config%ny)

      associate (c => self%config, tip => self%tip)
         along = c%scan_direction()
         across = c%across_direction()
         offset = support_across(c)
         line_start = [c%origin_x, c%origin_y, 0.0_wp] + offset(j + 1) * across
         if (forward) then
            s_start = -c%lead_in
            tip%support_velocity = c%velocity * along
         else
            s_start = c%length + c%lead_in
            tip%support_velocity = -c%velocity * along
         end if
         tip%support_start = line_start + s_start * along
         if (.not. allocated(record%values)) allocate (record%values(c%nx, n_quantities))
         call self%stream%init(c%thermal%seed, j, merge(0, 1, forward), realization, error)
      end associate
   end subroutine start_thermal_trip

   !> One trip of the thermal reduced model (&thermal model = 'kramers')
   !> along line j (0-based), trace when forward, with the random stream of
   !> realization (0-based); samples and slips as run_thermal_trip's.
   !>
   !> The tip sits in a minimum of its total energy E (surface and springs)
   !> and leaves it over one of the first-order saddles ahead (see
   !> start_exits), each at its Kramers–Langer rate r_s(t), whose prefactor
   !> is the tip model's: Kramers' moderate-to-strong friction rate for the
   !> inertial tip, Smoluchowski's for the overdamped one.  As the support
   !> moves the barriers fall and the rates grow.  Every exit has its own
   !> clock: it fires when its ∫ r_s dt reaches an exponential variate of
   !> its own (hazard_advance); the first to fire is the jump (competing
   !> independent clocks: the total rate is Σ r_s, and an exit is taken
   !> with probability r_s/Σ r_s).  An exit also fires, at once, where its
   !> barrier has fallen below barrier_floor k_B T or the minimum has
   !> vanished at a fold: there the rate formula stops holding, and escape
   !> takes of the order of the inverse attempt frequency, during which a
   !> slow support does not move.  The tip lands in the minimum past the
   !> saddle (jump_landing).  Jumps back, over the saddles behind, are
   !> exits like the others.
   !>
   !> The exits are searched after every jump.  Where no saddle is found
   !> (the search gives up on barriers of ~1 eV on NaF, e^-40 at 300 K) the
   !> minimum is followed for search_distance of support travel with no
   !> jump and searched again, with new variates (exponential clocks have
   !> no memory, so a new start is exact); if the minimum vanished
   !> meanwhile, the tip's descent into the next one is the jump, as in the
   !> quasistatic model.  A saddle lost while its
   !> barrier is still high (it merges with another stationary point)
   !> starts a new search there.  A sample records the tip in its minimum:
   !> the force -k u_min is the mean over the well's thermal spread up to
   !> O(k_B T) anharmonic terms.  Slips: every jump, with the support where
   !> it happened, the force before it and the move of the minimum.
   subroutine run_kramers_trip(self, j, forward, realization, record, error, slips, jump_hazards)
      class(afm_scanner), intent(inout) :: self
      integer, intent(in) :: j, realization
      logical, intent(in) :: forward
      type(trip_record), intent(inout) :: record
      type(error_type), allocatable, intent(out) :: error
      type(slip_list), intent(inout), optional :: slips
      !> A probe (see kramers_escape_hazards): no clock fires, every jump
      !> comes at the floor or a fold, and for each the hazard ∫ r dt all
      !> exits accumulated since the previous jump is listed here.
      real(wp), allocatable, intent(out), optional :: jump_hazards(:)
      !> Searches allowed between two samples before the trip is reported
      !> as stuck.
      integer, parameter :: max_searches = 100000
      type(hazard_path) :: paths(n_exits)
      real(wp) :: along(3), across(3), s_start, force(3), tip_r(3), t_sample, targets(n_exits), motion(3)
      real(wp) :: u_cur(3), u_next(3), t_cur, t_end, temperature, t_event, t_first, carried
      !> support time of the last search; of the next, when an exit was dropped
      real(wp) :: t_search, t_research, u_before(3)
      logical :: active(n_exits), need_search, probing
      integer(i8) :: now
      integer :: i, k, nx, nd, status, searches, p, first

      call self%start_thermal_trip(j, forward, realization, record, along, across, s_start, error)
      if (allocated(error)) return
      associate (c => self%config, tip => self%tip)
         nx = c%nx
         nd = tip%ndim
         temperature = c%thermal%temperature
         motion = tip%support_velocity / c%velocity
         ! From the support, into the minimum it relaxes to.
         u_cur = 0.0_wp
         u_next = 0.0_wp
         t_cur = 0.0_wp
         call find_minimum(tip, t_cur, u_next(1:nd), u_cur(1:nd), error)
         need_search = .true.
         t_search = t_cur
         t_research = huge(1.0_wp)
         probing = present(jump_hazards)
         carried = 0.0_wp
         if (probing) allocate (jump_hazards(0))
         do k = 1, nx
            i = merge(k, nx + 1 - k, forward)
            t_sample = abs(support_at(c, i - 1) - s_start) / c%velocity
            searches = 0
            do while (.not. allocated(error))
               if (.not. (t_cur < t_sample)) exit
               if (need_search) then
                  searches = searches + 1
                  if (searches > max_searches) then
                     call fatal_error(error, 'kramers: more than '//itoa(max_searches)//' searches for exits ' &
                        & //'between two samples at t = '//rtoa(t_cur)//' s', error_numerical)
                     exit
                  end if
                  call start_exits()
                  t_search = t_cur
                  t_research = huge(1.0_wp)
                  need_search = .not. any(active)
                  if (need_search) then
                     t_end = min(t_sample, t_cur + search_distance / c%velocity)
                     if (t_sample - t_end <= 1.0e-9_wp * (t_end - t_cur)) t_end = t_sample
                     call follow_minimum()
                     cycle
                  end if
               end if
               call self%check_halt('kramers', t_cur, error)
               if (allocated(error)) exit
               if (.not. any(active)) then
                  ! Every exit dropped (below): the minimum alone up to the next search.
                  t_end = min(t_sample, max(t_research, t_cur))
                  u_before = u_cur
                  call follow_minimum()
                  if (allocated(error)) exit
                  need_search = t_cur < t_sample .or. t_research <= t_sample &
                     & .or. norm2(u_cur(1:nd) - u_before(1:nd)) > slip_distance
                  cycle
               end if
               if (t_research <= t_cur) then
                  need_search = .true.
                  cycle
               end if
               ! Every clock on to the sample (or the search due) or to the first event so far.
               t_first = min(t_sample, t_research)
               first = 0
               do p = 1, n_exits
                  if (.not. active(p)) cycle
                  do
                     call system_clock(now)
                     call hazard_advance(tip, paths(p), t_first, targets(p), status, t_event, error, &
                        & barrier_floor=barrier_floor, pause_at=now + int(stop_poll * self%clock_rate, i8))
                     self%hazard_steps = self%hazard_steps + paths(p)%steps
                     paths(p)%steps = 0
                     if (allocated(error) .or. status /= hazard_paused) exit
                     call self%check_halt('kramers', paths(p)%t, error)
                     if (allocated(error)) exit
                  end do
                  if (allocated(error)) exit
                  if (status == hazard_running) cycle
                  if (status == hazard_low_barrier .and. paths(p)%barrier > 1.001_wp * barrier_floor &
                     & * boltzmann * temperature .and. .not. (paths(p)%t > t_search)) then
                     ! A saddle lost where it was found: at its own fold, where it
                     ! merges with the minimum beyond it (a search from here finds
                     ! it again, lost again at once).  Dropped; the exits are
                     ! searched again search_distance of support travel on.
                     active(p) = .false.
                     t_research = min(t_research, t_search + search_distance / c%velocity)
                     cycle
                  end if
                  first = p
                  t_first = t_event
                  ! A saddle lost, not overcome: a new search from there.
                  if (status == hazard_low_barrier .and. paths(p)%barrier > 1.001_wp * barrier_floor &
                     & * boltzmann * temperature) first = -p
               end do
               if (allocated(error)) exit
               if (first == 0 .and. .not. any(active)) cycle
               if (first > 0) then
                  if (probing) call note_jump(sum(paths%hazard, mask=active))
                  call jump(paths(first), t_first)
                  need_search = .true.
               else if (first < 0) then
                  if (probing) carried = carried + sum(paths%hazard, mask=active)
                  t_cur = paths(-first)%t
                  u_cur = paths(-first)%u_min
                  need_search = .true.
               else
                  t_cur = t_first
                  u_cur = paths(findloc(active, .true., 1))%u_min
                  if (t_first < t_sample) need_search = .true.
               end if
            end do
            if (.not. allocated(error)) call self%check_halt('kramers', t_cur, error)
            if (allocated(error)) then
               error%message = error%message//' (line '//itoa(j)//trim(merge(' trace  ', ' retrace', forward)) &
                  & //', realization '//itoa(realization)//', support at '//fixed_text(c%velocity * t_cur, 4) &
                  & //' Å into the trip)'
               call self%stream%free()
               return
            end if
            force = tip%lateral_force(u_cur) * ev_per_angstrom_to_nn
            tip_r = tip%tip_position(t_sample, u_cur)
            record%values(i, q_fx) = force(1)
            record%values(i, q_fy) = force(2)
            record%values(i, q_f_along) = dot_product(force, along)
            record%values(i, q_f_across) = dot_product(force, across)
            record%values(i, q_tip_x) = tip_r(1)
            record%values(i, q_tip_y) = tip_r(2)
            record%values(i, q_fz) = force(3)
            record%values(i, q_tip_z) = tip_r(3)
            record%values(i, q_jumps) = 0.0_wp
         end do
         call self%stream%free()
      end associate

   contains

      !> The exits from the minimum u_cur at support time t_cur: the saddles
      !> found from it along the support's motion and against it, each also
      !> turned by ±exit_angle in the scan plane (on a line of symmetry the
      !> saddle ahead is a pair, and the search along the motion alone stops
      !> on the ridge between them; off it the pair's barriers differ),
      !> without repeats; each with its clock's variate, drawn in order.
      !> The exits behind are the back jumps, which bring the mean force to
      !> zero as v -> 0 (detailed balance between neighbouring wells).
      subroutine start_exits()
         type(error_type), allocatable :: search_error
         real(wp) :: d(3), normal(3)
         integer :: q, m, found

         associate (tip => self%tip)
            active = .false.
            found = 0
            normal = [-motion(2), motion(1), 0.0_wp]
            do q = 1, n_exits
               ! Ahead (1-3) and behind (4-6).
               d = merge(1.0_wp, -1.0_wp, q <= 3) * motion
               if (mod(q, 3) == 2) d = d + tan(exit_angle) * normal
               if (mod(q, 3) == 0) d = d - tan(exit_angle) * normal
               call hazard_start(tip, temperature, t_cur, u_cur(1:nd), paths(found + 1), search_error, &
                  & direction=d(1:nd))
               if (allocated(search_error)) then
                  deallocate (search_error)
                  cycle
               end if
               if (any([(norm2(paths(m)%u_saddle(1:nd) - paths(found + 1)%u_saddle(1:nd)) <= &
                  & landing_distance, m = 1, found)])) cycle
               found = found + 1
               active(found) = .true.
            end do
            do q = 1, found
               targets(q) = self%stream%exponential()
               if (probing) targets(q) = huge(1.0_wp)
            end do
         end associate
      end subroutine start_exits

      !> No exit found: the minimum followed from t_cur to t_end; a jump if
      !> it vanished meanwhile (the descent lands elsewhere).
      subroutine follow_minimum()
         associate (tip => self%tip)
            call find_minimum(tip, t_end, u_cur(1:nd), u_next(1:nd), error)
            if (allocated(error)) return
            if (norm2(u_next(1:nd) - u_cur(1:nd)) > slip_distance) then
               call add_slip(t_end, u_cur, u_next)
               if (probing) call note_jump(0.0_wp)
            end if
            u_cur = u_next
            t_cur = t_end
         end associate
      end subroutine follow_minimum

      !> A probe's jump after `hazard` on the exits since the last search.
      subroutine note_jump(hazard)
         real(wp), intent(in) :: hazard

         jump_hazards = [jump_hazards, carried + hazard]
         carried = 0.0_wp
      end subroutine note_jump

      !> The jump at support time te from the path's minimum over its saddle.
      subroutine jump(path, te)
         type(hazard_path), intent(in) :: path
         real(wp), intent(in) :: te

         call jump_landing(self%tip, te, path%u_min(1:nd), path%u_saddle(1:nd), u_next(1:nd), error)
         if (allocated(error)) return
         call add_slip(te, path%u_min, u_next)
         u_cur = u_next
         t_cur = te
      end subroutine jump

      !> A slip at support time te from the minimum `before` to `after`.
      subroutine add_slip(te, before, after)
         real(wp), intent(in) :: te, before(3), after(3)
         real(wp) :: support_now, force_now

         if (.not. present(slips)) return
         associate (c => self%config, tip => self%tip)
            support_now = merge(s_start + c%velocity * te, s_start - c%velocity * te, forward)
            force_now = -dot_product(tip%spring(1:nd) * before(1:nd), along(1:nd)) * ev_per_angstrom_to_nn
            call slips%add(realization, merge(0, 1, forward), support_now, force_now, &
               & dot_product(after - before, motion), dot_product(after - before, across))
         end associate
      end subroutine add_slip

   end subroutine run_kramers_trip

   !> Where the thermal reduced model holds (friction_afm_validity): line
   !> 0's trace with clocks that never fire, so that every jump comes where
   !> an exit's barrier reaches the floor (or at a fold).  For each jump,
   !> the hazard H = ∫ Σ r dt its exits accumulated before it: at this
   !> velocity the model forces that jump at the floor with probability
   !> exp(-H) (no clock fired before), and H scales as 1/v (the path of the
   !> minimum and the saddles does not depend on v).
   subroutine kramers_escape_hazards(self, hazards, error)
      class(afm_scanner), intent(inout) :: self
      real(wp), allocatable, intent(out) :: hazards(:)
      type(error_type), allocatable, intent(out) :: error
      type(trip_record) :: record

      call self%run_kramers_trip(0, .true., 0, record, error, jump_hazards=hazards)
   end subroutine kramers_escape_hazards

   !> The computing time of one trip of the thermal reduced model, s,
   !> estimated from a sample: line 0's trace (realization 0) over the
   !> support travel `travel` Å (the lead-in and one period of the surface
   !> along the scan: the jumps, where the time goes, come once per period),
   !> its time scaled to the whole trip.  Where the jumps back and forth
   !> (the thermolubric regime, their number growing as 1/(v c)) make the
   !> sample longer than `budget` s of wall time, it ends there and the
   !> estimate, scaled from the travel covered, is a lower bound (`lower`):
   !> the part of a period before its slip costs least.  0 when the sample
   !> fails.
   function kramers_trip_cost(self, travel, budget, lower) result(cost)
      class(afm_scanner), intent(inout) :: self
      real(wp), intent(in) :: travel, budget
      logical, intent(out) :: lower
      real(wp) :: cost
      type(trip_record) :: record
      type(error_type), allocatable :: error
      integer(i8) :: start, finish
      real(wp) :: trip

      cost = 0.0_wp
      lower = .false.
      trip = (self%config%length + self%config%lead_in) / self%config%velocity
      call system_clock(start)
      self%sample_end = start + int(budget * self%clock_rate, i8)
      self%sample_stop = min(travel / self%config%velocity, trip)
      self%reached = 0.0_wp
      call self%run_kramers_trip(0, .true., 0, record, error)
      self%sample_end = 0
      call system_clock(finish)
      cost = real(finish - start, wp) / self%clock_rate
      if (.not. allocated(error)) return
      if (error%stat /= error_interrupted .or. .not. (self%reached > 0.0_wp)) then
         cost = 0.0_wp
         return
      end if
      lower = self%reached < self%sample_stop
      cost = cost * trip / self%reached
   end function kramers_trip_cost

   subroutine slips_clear(self)
      class(slip_list), intent(inout) :: self

      self%n = 0
   end subroutine slips_clear

   subroutine slips_add(self, realization, trip, support, force, jump, jump_across)
      class(slip_list), intent(inout) :: self
      integer, intent(in) :: realization, trip
      real(wp), intent(in) :: support, force, jump, jump_across
      integer, allocatable :: ints(:)
      real(wp), allocatable :: reals(:)
      integer :: room

      if (.not. allocated(self%realization)) then
         allocate (self%realization(16), self%trip(16), self%support(16), self%force(16), self%jump(16), &
            & self%jump_across(16))
      end if
      room = size(self%realization)
      if (self%n == room) then
         allocate (ints(2 * room))
         ints(1:room) = self%realization
         call move_alloc(ints, self%realization)
         allocate (ints(2 * room))
         ints(1:room) = self%trip
         call move_alloc(ints, self%trip)
         allocate (reals(2 * room))
         reals(1:room) = self%support
         call move_alloc(reals, self%support)
         allocate (reals(2 * room))
         reals(1:room) = self%force
         call move_alloc(reals, self%force)
         allocate (reals(2 * room))
         reals(1:room) = self%jump
         call move_alloc(reals, self%jump)
         allocate (reals(2 * room))
         reals(1:room) = self%jump_across
         call move_alloc(reals, self%jump_across)
      end if
      self%n = self%n + 1
      self%realization(self%n) = realization
      self%trip(self%n) = trip
      self%support(self%n) = support
      self%force(self%n) = force
      self%jump(self%n) = jump
      self%jump_across(self%n) = jump_across
   end subroutine slips_add

   !> One trip along line j (0-based): trace when forward, else retrace.
   subroutine run_trip(self, j, forward, record, error)
      class(afm_scanner), intent(inout) :: self
      integer, intent(in) :: j
      logical, intent(in) :: forward
      type(trip_record), intent(inout) :: record
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: along(3), across(3), line_start(3)
      real(wp) :: y(6), t, t_sample, s_start, force(3), tip_r(3), u_z, t_last, u_last(3), pending
      integer :: i, k, nx, nd, jumps, i_last
      logical :: checking
      character(len=96) :: where

      associate (c => self%config, tip => self%tip)
         nx = c%nx
         nd = tip%ndim
         along = c%scan_direction()
         across = c%across_direction()
         line_start = [c%origin_x, c%origin_y, 0.0_wp] + line_offset(c, j) * across
         if (forward) then
            s_start = -c%lead_in
            tip%support_velocity = c%velocity * along
         else
            s_start = c%length + c%lead_in
            tip%support_velocity = -c%velocity * along
         end if
         tip%support_start = line_start + s_start * along
         ! At the support and at rest: r - r_M = 0, r' = 0; in z at the
         ! static equilibrium under the support (paper §3.1: z differs).
         y = 0.0_wp
         if (nd == 3) then
            call self%start_height(j, u_z, error)
            if (allocated(error)) return
            y(3) = u_z
         end if
         t = 0.0_wp
         jumps = 0
         ! The overdamped tip in its slow limit: its slips are checked.
         checking = tip%model == model_overdamped .and. all(tip%spring(1:nd) > 0.0_wp)
         if (checking) checking = c%velocity * maxval(tip%damping(1:nd) / tip%spring(1:nd)) <= slow_travel
         t_last = -1.0_wp
         pending = -1.0_wp
         u_last = 0.0_wp
         i_last = 0
         call self%solver%restart(self%h_start)
         if (tip%model == model_quasistatic) call self%relax(t, y(1:nd), error)
         if (.not. allocated(record%values)) then
            call allocate_trip(record, nx, error)
            if (allocated(error)) return
         end if
         do k = 1, nx
            i = merge(k, nx + 1 - k, forward)
            t_sample = abs(support_at(c, i - 1) - s_start) / c%velocity
            if (allocated(error)) then
               continue
            else if (tip%model == model_quasistatic) then
               if (t_sample > t) call self%follow(t, t_sample, y(1:nd), jumps, error)
            else
               if (t_sample > t) call self%solver%advance(t, t_sample, y(1:tip%dimension()), error)
            end if
            if (.not. allocated(error)) call self%check_halt(trim(c%solver%method), t, error)
            if (checking .and. t_last >= 0.0_wp .and. .not. allocated(error)) then
               call check_overdamped_slip(tip, t_last, u_last(1:nd), t, y(1:nd), pending, error)
               if (allocated(error)) error%message = 'overdamped tip at T = 0, between the samples at support ' &
                  & //fixed_text(support_at(c, i_last - 1), 4)//' and '//fixed_text(support_at(c, i - 1), 4) &
                  & //' Å: '//error%message//': an integration error of '//trim(c%solver%method)//' at rtol = ' &
                  & //rtoa(c%solver%rtol)//', atol = '//rtoa(c%solver%atol)//" (&integrator): tighten them, or " &
                  & //"use method = 'rodas4' or 'auto' (docs/physics.md, reduced tip models)"
            end if
            if (allocated(error)) then
               write (where, '(a, i0, a)') ' (line ', j, trim(merge(' trace  ', ' retrace', forward)) &
                  & //', support at '//fixed_text(c%velocity * t, 4)//' Å into the trip)'
               error%message = error%message//trim(where)
               return
            end if
            t_last = t
            u_last(1:nd) = y(1:nd)
            i_last = i
            force = tip%lateral_force(y) * ev_per_angstrom_to_nn
            tip_r = tip%tip_position(t, y)
            if (nd == 3) then
               ! (The message is built only when it is needed: formatting is dear.)
               if (below_net(tip, tip_r)) call fatal_error(error, 'the tip went below the layer of atoms at (' &
                  & //rtoa(tip_r(1))//', '//rtoa(tip_r(2))//', '//rtoa(tip_r(3))//') Å (line '//itoa(j) &
                  & //trim(merge(' trace  ', ' retrace', forward))//'): off the edge of the net, or pressed ' &
                  & //'through it by the load (support_z = '//rtoa(c%support_z)//' Å); scan over the net, or ' &
                  & //'raise support_z', error_input)
               if (allocated(error)) return
            end if
            record%values(i, q_fx) = force(1)
            record%values(i, q_fy) = force(2)
            record%values(i, q_f_along) = dot_product(force, along)
            record%values(i, q_f_across) = dot_product(force, across)
            record%values(i, q_tip_x) = tip_r(1)
            record%values(i, q_tip_y) = tip_r(2)
            record%values(i, q_fz) = force(3)
            record%values(i, q_tip_z) = tip_r(3)
            record%values(i, q_jumps) = jumps
            jumps = 0
         end do
      end associate
   end subroutine run_trip

   !> The overdamped tip at T = 0 from the sample (t0, u0) to the next, (t1,
   !> u1), against the slow limit it follows: an error when it slipped
   !> where that limit does not.  The overdamped tip lags behind its
   !> minimum of the total energy E, on the side away from the saddle ahead
   !> (at the minimum u' = -v_M, while the minimum moves forward), so it
   !> cannot leave the minimum before the minimum ends at its fold; and
   !> where the support hardly moves during a slip (slow_travel) it lands
   !> where the descent at the support of the fold lands.  So: the minimum
   !> of the tip at t0 is followed to t1 as the quasistatic model follows
   !> it (continuation; at a fold, a push along the motion and the descent
   !> of the overdamped flow, c u' = -grad E, at that support), and the tip
   !> at t1 must be in that minimum.  An explicit pair at its stability
   !> limit on a stiff tip lets the stiff component grow unseen until the
   !> tip leaves a minimum that still exists; a stepper that steps over a
   !> slip can land a site too far.  No claim (no error) where the tip is
   !> mid-slip or lags at t0, or a descent does not settle.  The message
   !> says what went wrong; the caller says where.
   subroutine check_overdamped_slip(tip, t0, u0, t1, u1, pending, error)
      type(afm_tip), intent(in) :: tip
      real(wp), intent(in) :: t0, u0(:), t1, u1(:)
      !> the support time by which the tip must have landed from a fold it
      !> had not yet landed from at t0 (negative: none); on return, at t1
      real(wp), intent(inout) :: pending
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: m(size(u0)), w(size(u0)), predicted(size(u0)), corrected(size(u0)), dudt(size(u0))
      real(wp) :: motion(size(u0)), t, h, h_min, speed, deadline, ghost(size(u0))
      logical :: ok, folded, last
      integer :: steps, n

      n = size(u0)
      speed = norm2(tip%support_velocity(1:n))
      if (.not. (speed > 0.0_wp)) return
      call newton_equilibrium(tip, t0, u0, m, ok)
      if (ok) ok = norm2(m - u0) <= check_lag
      if (.not. ok) then
         ! Mid-slip (no claim), or still on its way from a fold: the slow
         ! limit is then where the descent from here lands.
         if (pending < 0.0_wp) return
         m = u0
         call descend(t0, m, ok)
         if (.not. ok) then
            pending = -1.0_wp
            return
         end if
      else
         pending = -1.0_wp
      end if
      h_min = fold_resolution / speed
      t = t0
      h = t1 - t0
      folded = pending >= 0.0_wp
      deadline = merge(pending, huge(1.0_wp), folded)
      pending = -1.0_wp
      steps = 0
      do while (t < t1)
         steps = steps + 1
         if (steps > 100000) return
         last = t + h >= t1
         if (last) h = t1 - t
         call equilibrium_tangent(tip, t, m, dudt, ok)
         if (.not. ok) dudt = 0.0_wp
         predicted = m + h * dudt
         call newton_equilibrium(tip, t + h, predicted, corrected, ok)
         if (ok) ok = norm2(corrected - predicted) <= 0.5_wp * max(norm2(predicted - m), h * speed)
         if (ok) then
            t = merge(t1, t + h, last)
            m = corrected
            h = 2.0_wp * h
         else if (h > h_min) then
            h = 0.25_wp * h
         else
            motion = dudt + tip%support_velocity(1:n)
            ghost = m
            if (norm2(motion) > 0.0_wp) m = m + jump_push * motion / norm2(motion)
            t = merge(t1, t + h, last)
            call descend(t, m, ok)
            if (.not. ok) return
            if (.not. folded) deadline = t + late_factor * slip_duration(t, ghost, m)
            folded = .true.
            h = t1 - t
         end if
      end do
      w = u1
      call descend(t1, w, ok)
      if (.not. ok) return
      if (norm2(w - m) <= same_minimum) then
         if (folded .and. norm2(u1 - m) > check_lag) then
            if (t1 > deadline) then
               call fatal_error(error, 'the tip had not slipped '//fixed_text(speed * (t1 - deadline), 4) &
                  & //' Å of support travel after it should have landed from the fold of its minimum of the ' &
                  & //'total energy ('//rtoa(late_factor)//' times the time the slip takes)', error_numerical)
            else
               pending = deadline
            end if
         end if
         return
      end if
      if (folded) then
         call fatal_error(error, 'the tip slipped into the minimum at '//fixed_text(norm2(w - m), 3) &
            & //' Å from the one its slow limit reaches (a site skipped or a wrong landing)', error_numerical)
      else
         call fatal_error(error, 'the tip slipped out of its minimum of the total energy while that minimum ' &
            & //'still existed (it can slip only where its minimum ends)', error_numerical)
      end if

   contains

      !> The time the overdamped tip takes from the ghost of its minimum at
      !> the fold (support time tf) to within check_lag of the minimum it
      !> lands in (near `landing`), the support moving: explicit Euler on
      !> the tip's own equation at a tenth of its stability limit (the
      !> curvature of V from its Hessian at every step); huge when it does
      !> not land within 1e6 steps (no claim).
      real(wp) function slip_duration(tf, start, landing) result(duration)
         real(wp), intent(in) :: tf, start(:), landing(:)
         real(wp) :: u(size(start)), dudt(size(start)), hess(3, 3), minimum(size(start)), tt, dt
         integer :: step
         logical :: settled

         u = start
         tt = tf
         duration = huge(1.0_wp)
         do step = 1, 1000000
            call tip%potential%hessian(tip%tip_position(tt, u), hess)
            dt = 0.1_wp * minval(tip%damping(1:n)) / (maxval(tip%spring(1:n)) + norm2(hess(1:n, 1:n)))
            call tip%rhs(tt, u, dudt)
            u = u + dt * dudt
            tt = tt + dt
            if (mod(step, 64) == 0 .and. norm2(u - landing) <= same_minimum) then
               call newton_equilibrium(tip, tt, u, minimum, settled)
               if (settled .and. norm2(minimum - u) <= check_lag) then
                  duration = tt - tf
                  return
               end if
            end if
         end do
      end function slip_duration

      !> u down the overdamped flow c u' = -grad E at the support of time
      !> ts (normalised steps of descent_step: the flow's path, not its
      !> time), into the minimum Newton's method then confirms.
      subroutine descend(ts, u, settled)
         real(wp), intent(in) :: ts
         real(wp), intent(inout) :: u(:)
         logical, intent(out) :: settled
         real(wp) :: g(size(u)), d(size(u)), minimum(size(u))
         integer :: iter

         do iter = 0, 20000
            if (mod(iter, 8) == 0) then
               call newton_equilibrium(tip, ts, u, minimum, settled)
               if (settled) settled = norm2(minimum - u) <= landing_distance
               if (settled) then
                  u = minimum
                  return
               end if
            end if
            g = force_imbalance(tip, ts, u)
            d = -g / tip%damping(1:size(u))
            if (.not. (norm2(d) > 0.0_wp)) exit
            u = u + descent_step * d / norm2(d)
         end do
         settled = .false.
      end subroutine descend

   end subroutine check_overdamped_slip

   !> For a tip over a lattice sum: whether the tip at `r` is not above the
   !> atoms under it, i.e. less than half the smallest σ above the highest
   !> atom within 2 σ_max laterally (the caller's error, bad input).  A root
   !> of the force balance in the plane of the atoms (a sparse net, tiny σ or
   !> a) or a tip pushed through the layer is not a contact.
   logical function below_net(tip, r)
      type(afm_tip), intent(in) :: tip
      real(wp), intent(in) :: r(3)
      real(wp) :: top, sigma_min

      below_net = .false.
      select type (p => tip%potential)
      type is (lj_potential)
         call p%highest_near(r(1:2), 2.0_wp * maxval(p%sigma), top, sigma_min)
         if (top > -huge(1.0_wp) .and. .not. (r(3) > top + 0.5_wp * sigma_min)) below_net = .true.
         if (top == -huge(1.0_wp) .and. r(3) < 0.5_wp * sigma_min + minval(p%atoms%position(3, :))) &
            & below_net = .true.
      end select
   end function below_net

   !> One trip's record of nx samples, or an error stating the memory it
   !> needs when this machine has not that much available.
   subroutine allocate_trip(record, nx, error)
      type(trip_record), intent(inout) :: record
      integer, intent(in) :: nx
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: needed, available
      integer :: stat

      needed = 8.0_wp * real(nx, wp) * n_quantities
      available = available_memory()
      stat = 0
      if (.not. (available > 0.0_wp .and. needed > available)) allocate (record%values(nx, n_quantities), stat=stat)
      if (stat /= 0 .or. (available > 0.0_wp .and. needed > available)) call fatal_error(error, &
         & 'one scan line of '//itoa(nx)//' points needs '//bytes_text(needed)//' of memory, more than this ' &
         & //'machine has available ('//bytes_text(max(available, 0.0_wp))//'): use fewer points (&scan nx)', &
         & error_input)
   end subroutine allocate_trip


   !> The quasistatic tip from support time t to t1 (the next sample), u its
   !> displacement from the support (ndim components), jumps counted.
   !>
   !> Why this algorithm: the quasistatic model is the v -> 0 limit of the
   !> full one, in which the tip sits in a minimum of the total energy E
   !> while sticking and slips, faster than the support moves, when that
   !> minimum ends at a fold (saddle-node).  So the tip is followed along
   !> its minimum by continuation: a tangent predictor (J du/dt = -H v_M,
   !> friction_afm_quasistatic) and Newton's method as corrector.  A step is
   !> accepted only when Newton converges with J = K + H positive definite
   !> at every iterate and lands within half a step (the larger of the
   !> predicted move and the support's travel) of the prediction: it cannot
   !> then have slipped into another well.  Otherwise the step is quartered;
   !> once it is below fold_resolution of support travel the minimum has
   !> ended: the tip is pushed jump_push along its motion (the direction in
   !> which the minimum vanished) and relaxed into the minimum it falls
   !> into at the support position just past the fold (relax), and the jump
   !> is counted.  Where the minimum moves smoothly one predictor-corrector
   !> step (2-3 Newton iterations) covers a whole sample interval: that is
   !> what the model saves against integrating the motion.
   subroutine follow(self, t, t1, u, jumps, error)
      class(afm_scanner), intent(inout) :: self
      real(wp), intent(inout) :: t
      real(wp), intent(in) :: t1
      real(wp), intent(inout) :: u(:)
      integer, intent(inout) :: jumps
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: h, h_min, speed, dudt(size(u)), predicted(size(u)), corrected(size(u)), motion(size(u))
      logical :: ok, last
      integer :: steps

      associate (tip => self%tip)
         speed = norm2(tip%support_velocity)
         h_min = fold_resolution / speed
         h = t1 - t
         steps = 0
         do while (t < t1)
            steps = steps + 1
            if (steps > 1000000) then
               call fatal_error(error, 'quasistatic: more than 1e6 continuation steps between two samples at t = ' &
                  & //rtoa(t)//' s', error_numerical)
               return
            end if
            last = t + h >= t1
            if (last) h = t1 - t
            call equilibrium_tangent(tip, t, u, dudt, ok)
            if (.not. ok) dudt = 0.0_wp
            predicted = u + h * dudt
            call newton_equilibrium(tip, t + h, predicted, corrected, ok)
            if (ok) ok = norm2(corrected - predicted) <= 0.5_wp * max(norm2(predicted - u), h * speed)
            if (ok) then
               t = merge(t1, t + h, last)
               u = corrected
               h = 2.0_wp * h
            else if (h > h_min) then
               h = 0.25_wp * h
            else
               ! The fold: off the ghost of the minimum in the tip's direction
               ! of motion dr/dt = du/dt + v_M, then downhill.
               motion = dudt + tip%support_velocity(1:size(u))
               if (norm2(motion) > 0.0_wp) u = u + jump_push * motion / norm2(motion)
               t = merge(t1, t + h, last)
               call self%relax(t, u, error)
               if (allocated(error)) return
               jumps = jumps + 1
               h = t1 - t
            end if
         end do
      end associate
   end subroutine follow

   !> Relax the quasistatic tip, support held at its position of time t,
   !> into a minimum of E: the first-order motion c u' = -(k u + dV/dr)
   !> (friction_afm_tip with model_quasistatic) in stretches of ten
   !> relaxation times, until Newton's method from the state converges, with
   !> J positive definite, to a minimum within landing_distance.
   subroutine relax(self, t, u, error)
      class(afm_scanner), intent(inout) :: self
      real(wp), intent(in) :: t
      real(wp), intent(inout) :: u(:)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: saved_start(3), saved_velocity(3), tau, s, minimum(size(u))
      logical :: ok
      integer :: k, nd

      associate (tip => self%tip)
         nd = size(u)
         saved_start = tip%support_start
         saved_velocity = tip%support_velocity
         tip%support_start = tip%support(t)
         tip%support_velocity = 0.0_wp
         tau = maxval(tip%damping(1:nd) / max(tip%spring(1:nd), 1.0e-3_wp * maxval(tip%spring(1:nd)), &
            & tiny(1.0_wp)))
         call self%solver%restart(min(self%h_start, 1.0e-3_wp * tau))
         s = 0.0_wp
         ok = .false.
         do k = 1, max_stretches
            call newton_equilibrium(tip, 0.0_wp, u, minimum, ok)
            if (ok) ok = norm2(minimum - u) <= landing_distance
            if (ok) exit
            call self%solver%advance(s, s + 10.0_wp * tau, u, error)
            if (allocated(error)) exit
         end do
         if (.not. allocated(error) .and. .not. ok) call fatal_error(error, 'quasistatic: the tip found no ' &
            & //'minimum in '//rtoa(10.0_wp * max_stretches * tau)//' s of relaxation', error_numerical)
         if (allocated(error)) then
            error%message = error%message//' (relaxing the quasistatic tip into a minimum; t counts from ' &
               & //'the start of the relaxation)'
         else
            u = minimum
         end if
         tip%support_start = saved_start
         tip%support_velocity = saved_velocity
      end associate
   end subroutine relax

   !> Integrator counters of all trips so far (at T > 0 the Langevin steps
   !> and force evaluations).
   function statistics(self) result(stats)
      class(afm_scanner), intent(in) :: self
      type(integrator_statistics) :: stats

      stats = self%solver%statistics()
      if (self%thermal) then
         stats%steps = stats%steps + self%langevin_steps + self%hazard_steps
         stats%rhs_evaluations = stats%rhs_evaluations + self%force_evaluations
      end if
   end function statistics

   !> An error when the trip must end here: the wall time since init has
   !> passed &integrator max_wall_time (error_numerical, as before), or the
   !> job's stopper, looked at every stop_poll s, asks to stop
   !> (error_interrupted).  `what` names the scheme, t the support time.
   subroutine check_halt(self, what, t, error)
      class(afm_scanner), intent(inout) :: self
      character(len=*), intent(in) :: what
      real(wp), intent(in) :: t
      type(error_type), allocatable, intent(inout) :: error
      integer(i8) :: now

      if (allocated(error)) return
      call system_clock(now)
      if (self%sample_end > 0 .and. (now >= self%sample_end .or. t >= self%sample_stop)) then
         self%reached = t
         call fatal_error(error, what//': the sample of the cost estimate ended', error_interrupted)
         return
      end if
      associate (limit => self%config%solver%max_wall_time)
         if (limit > 0.0_wp .and. real(now - self%clock_start, wp) / self%clock_rate > limit) then
            call fatal_error(error, what//': max_wall_time = '//rtoa(limit)//' s reached at t = '//rtoa(t) &
               & //' s', error_numerical)
            return
         end if
      end associate
      if (.not. allocated(self%stopper) .or. now < self%next_poll) return
      self%next_poll = now + int(stop_poll * self%clock_rate, i8)
      if (self%stopper%stop_requested()) call fatal_error(error, what//': stopped on request at t = '//rtoa(t) &
         & //' s', error_interrupted)
   end subroutine check_halt

end module friction_afm_scan
