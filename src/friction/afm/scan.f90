!> The scanner: one tip over one surface and the kinds of trip it makes
!> along the scan lines (friction_afm_trip: the geometry and the record).
!>
!> At T = 0 a line is one trace trip and one retrace trip of the
!> deterministic tip (friction_afm_deterministic_trip: integrated, or the
!> quasistatic tip followed along its minimum).  At a temperature (&thermal
!> temperature > 0; README: Friction at a temperature) each trip is made
!> once per realization, with the Langevin tip
!> (friction_afm_langevin_trip) or the thermal reduced model
!> (friction_afm_kramers_trip), and run_line gives the mean of every
!> sample, its standard error, and the friction with its standard error.
!> Every trip answers to the scanner's guard (friction_afm_guard): the
!> wall-time limit and the job's stop request.
module friction_afm_scan
   use friction_kinds, only: wp
   use friction_error, only: error_type, fatal_error, error_input
   use friction_ode_solver, only: integrator_statistics
   use friction_afm_config, only: afm_config, new_tip_owning
   use friction_afm_tip, only: afm_tip, find_height
   use friction_afm_thermal, only: welford_add, welford_sem
   use friction_surface_potential, only: surface_potential
   use friction_afm_trip, only: trip_record, line_record, slip_list, trip_path, start_trip, below_net, &
      & n_quantities, q_f_along
   use friction_afm_guard, only: trip_guard
   use friction_afm_deterministic_trip, only: deterministic_trip
   use friction_afm_langevin_trip, only: langevin_trip
   use friction_afm_kramers_trip, only: kramers_trip
   implicit none
   private

   public :: afm_scanner

   !> Integrates trips of one scene; owns one tip model and its trip kinds.
   type :: afm_scanner
      type(afm_config) :: config
      type(afm_tip), allocatable :: tip
      type(trip_guard) :: guard   !! the wall-time limit and the stop request every trip answers to
      real(wp) :: contact_height = 0.0_wp   !! z0: free tip's equilibrium height at the origin, Å (3D)
      real(wp) :: support_height = 0.0_wp   !! z_M = z0 + support_z, Å (3D)
      logical :: thermal = .false.          !! at a temperature (config%thermal)
      logical :: kramers = .false.          !! &thermal model = 'kramers' (no Langevin steps)
      type(deterministic_trip) :: deterministic
      type(langevin_trip) :: langevin
      type(kramers_trip) :: reduced
   contains
      procedure :: init
      procedure :: init_owning
      procedure :: release_potential
      procedure :: run_trip
      procedure :: run_thermal_trip
      procedure :: run_line
      procedure :: kramers_escape_hazards
      procedure :: kramers_trip_cost
      procedure :: time_step
      procedure :: statistics
      procedure, private :: set_up
   end type afm_scanner

contains

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
      call self%set_up(config, error)
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

      self%config = config
      call self%guard%start(config%solver%max_wall_time)
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
      call self%deterministic%init(self%tip, config, error)
      if (allocated(error)) return
      self%thermal = config%thermal%enabled()
      self%kramers = self%thermal .and. config%thermal%reduced()
      if (self%thermal .and. .not. self%kramers) call self%langevin%init(self%tip, config, error)
   end subroutine set_up

   !> The Langevin step between samples, s (0 at T = 0 and for the reduced model).
   pure real(wp) function time_step(self)
      class(afm_scanner), intent(in) :: self

      time_step = 0.0_wp
      if (self%thermal .and. .not. self%kramers) time_step = self%langevin%time_step()
   end function time_step

   !> One trip along line j (0-based) at T = 0: trace when forward, else retrace.
   subroutine run_trip(self, j, forward, record, error)
      class(afm_scanner), intent(inout) :: self
      integer, intent(in) :: j
      logical, intent(in) :: forward
      type(trip_record), intent(inout) :: record
      type(error_type), allocatable, intent(out) :: error
      type(trip_path) :: path

      path = start_trip(self%config, self%tip, j, forward, support_height=self%support_height)
      call self%deterministic%run(self%tip, self%config, self%guard, path, record, error)
   end subroutine run_trip

   !> One trip at a temperature along line j (0-based), trace when forward,
   !> with the noise of realization (0-based): samples as run_trip's; the
   !> slips between the first and the last sample appended to `slips` when
   !> given.
   subroutine run_thermal_trip(self, j, forward, realization, record, error, slips)
      class(afm_scanner), intent(inout) :: self
      integer, intent(in) :: j, realization
      logical, intent(in) :: forward
      type(trip_record), intent(inout) :: record
      type(error_type), allocatable, intent(out) :: error
      type(slip_list), intent(inout), optional :: slips
      type(trip_path) :: path

      path = start_trip(self%config, self%tip, j, forward, realization, self%support_height)
      if (self%kramers) then
         call self%reduced%run(self%tip, self%config, self%guard, path, record, error, slips)
      else
         call self%langevin%run(self%tip, self%config, self%guard, path, record, error, slips)
      end if
   end subroutine run_thermal_trip

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

   !> Where the thermal reduced model holds (friction_afm_validity): the
   !> hazards before each jump of line 0's trace (kramers_trip's escape_hazards).
   subroutine kramers_escape_hazards(self, hazards, error)
      class(afm_scanner), intent(inout) :: self
      real(wp), allocatable, intent(out) :: hazards(:)
      type(error_type), allocatable, intent(out) :: error

      call self%reduced%escape_hazards(self%tip, self%config, self%guard, hazards, error)
   end subroutine kramers_escape_hazards

   !> The computing time of one trip of the thermal reduced model, s,
   !> estimated from a sample of `travel` Å within `budget` s of wall time
   !> (kramers_trip's trip_cost; `lower` when it is a lower bound).
   function kramers_trip_cost(self, travel, budget, lower) result(cost)
      class(afm_scanner), intent(inout) :: self
      real(wp), intent(in) :: travel, budget
      logical, intent(out) :: lower
      real(wp) :: cost

      cost = self%reduced%trip_cost(self%tip, self%config, self%guard, travel, budget, lower)
   end function kramers_trip_cost

   !> Integrator counters of all trips so far (at T > 0 the Langevin steps
   !> and force evaluations, and the steps along the reduced model's paths).
   function statistics(self) result(stats)
      class(afm_scanner), intent(in) :: self
      type(integrator_statistics) :: stats

      stats = self%deterministic%solver%statistics()
      if (self%thermal) then
         stats%steps = stats%steps + self%langevin%steps + self%reduced%steps
         stats%rhs_evaluations = stats%rhs_evaluations + self%langevin%force_evaluations
      end if
   end function statistics

end module friction_afm_scan
