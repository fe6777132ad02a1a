!> The trips at a temperature with the Langevin tip (&thermal model =
!> 'langevin'; README: Friction at a temperature): friction_afm_langevin's
!> BAOAB, or Leimkuhler–Matthews without inertia, at a fixed step, the
!> largest not above the chosen one that divides the sample interval (and
!> the lead-in) into whole steps, so that samples fall on steps.  The tip
!> starts at the support with a velocity drawn from the bath's
!> Maxwell–Boltzmann distribution; the noise is the random stream of (seed,
!> line, trip, realization), trip 0 the trace and 1 the retrace, so a
!> trip's samples depend on nothing else (not on the ranks).
!>
!> Slips (see check_slips): every check_distance of support travel (and at
!> every sample) the tip's state is quenched, by Newton's method on the
!> total energy (friction_afm_kramers' find_minimum), into the minimum
!> whose basin it is in; a slip is a change of that minimum by more than
!> slip_distance.  Recorded: where the support was and the force along the
!> scan at the last check before the slip, and the jump of the minimum
!> along the support's motion (negative for a slip back) and across the
!> scan.  The checks split the Langevin steps into calls, which leaves the
!> trajectory bit for bit as it is.
module friction_afm_langevin_trip
   use friction_kinds, only: wp, i8
   use friction_error, only: error_type, fatal_error, error_input
   use friction_random, only: random_stream
   use friction_afm_config, only: afm_config, surface_curvature
   use friction_afm_tip, only: afm_tip
   use friction_afm_langevin, only: langevin_integrator, langevin_state, langevin_time_step
   use friction_afm_kramers, only: find_minimum
   use friction_afm_trip, only: trip_record, trip_path, slip_list, start_height, slip_distance
   use friction_afm_guard, only: trip_guard
   use friction_strings, only: rtoa
   implicit none
   private

   public :: langevin_trip

   !> The support travel between two quenches, Å: in a stick the force then
   !> changes by the stick slope times 0.05 Å, ~0.04 nN on NaF, below its
   !> thermal spread sqrt(k k_B T) = 0.2 nN at 300 K (the quenches' cost:
   !> docs/speed.md).
   real(wp), parameter :: check_distance = 0.05_wp
   !> Langevin steps between two looks at the clock: a stop is seen within a small part of a second.
   integer, parameter :: langevin_chunk = 100000

   !> The Langevin trips of one tip: the steps and their counts.
   type :: langevin_trip
      type(langevin_integrator) :: step        !! the step between samples
      type(langevin_integrator) :: lead_step   !! the step of the lead-in
      integer :: sample_steps = 0              !! steps between two samples
      integer :: lead_steps = 0                !! steps of the lead-in
      integer :: check_steps = 0               !! steps between two slip checks
      integer(i8) :: steps = 0, force_evaluations = 0   !! of all trips so far
   contains
      procedure :: init
      procedure :: run
      procedure :: time_step
   end type langevin_trip

contains

   !> The Langevin steps for `tip` under `config`: the largest not above the
   !> chosen one (the input's time_step, or langevin_time_step's default)
   !> that divide the sample interval and the lead-in into whole steps.
   subroutine init(self, tip, config, error)
      class(langevin_trip), intent(inout) :: self
      type(afm_tip), intent(in) :: tip
      type(afm_config), intent(in) :: config
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: curvature, dt, limit, lead_time, sample_time

      sample_time = config%length / real(config%nx - 1, wp) / config%velocity
      curvature = surface_curvature(config, tip%potential)
      call langevin_time_step(tip, curvature, dt, limit, error)
      if (allocated(error)) return
      if (config%thermal%time_step > 0.0_wp) dt = config%thermal%time_step
      if (max(sample_time, config%lead_in / config%velocity) / dt > 1.0e9_wp) then
         call fatal_error(error, 'Langevin: a step of '//rtoa(dt)//' s makes more than 1e9 steps between ' &
            & //'two samples', error_input)
         return
      end if
      self%sample_steps = max(1, ceiling(sample_time / dt))
      call self%step%init(tip, config%thermal%temperature, sample_time / self%sample_steps, error, &
         & curvature=curvature)
      if (allocated(error)) return
      self%check_steps = max(1, min(self%sample_steps, int(check_distance / (config%velocity * self%step%dt))))
      lead_time = config%lead_in / config%velocity
      self%lead_steps = 0
      if (lead_time > 0.0_wp) then
         self%lead_steps = max(1, ceiling(lead_time / dt))
         call self%lead_step%init(tip, config%thermal%temperature, lead_time / self%lead_steps, error, &
            & curvature=curvature)
      end if
   end subroutine init

   !> The Langevin step between samples, s.
   pure real(wp) function time_step(self)
      class(langevin_trip), intent(in) :: self

      time_step = self%step%dt
   end function time_step

   !> The trip `path` (start_trip has set the tip's support on it) with the
   !> noise of its realization into `record`; the slips between the first
   !> and the last sample appended to `slips` when given.
   subroutine run(self, tip, config, guard, path, record, error, slips)
      class(langevin_trip), intent(inout) :: self
      type(afm_tip), intent(inout) :: tip
      type(afm_config), intent(in) :: config
      type(trip_guard), intent(inout) :: guard
      type(trip_path), intent(in) :: path
      type(trip_record), intent(inout) :: record
      type(error_type), allocatable, intent(out) :: error
      type(slip_list), intent(inout), optional :: slips
      type(random_stream) :: stream
      type(langevin_state) :: state
      real(wp) :: minimum(3), last_support, last_force   !! at the last check of slips
      integer :: nd
      logical :: in_well

      nd = tip%ndim
      in_well = .false.
      call record%reserve(config%nx, error)
      if (.not. allocated(error)) call path%noise(config, stream, error)
      if (.not. allocated(error)) call samples()
      call stream%free()

   contains

      !> The trip's samples from its stream.
      subroutine samples()
         real(wp) :: u0(3), t
         integer :: i, k, done, n, stride

         ! At the support (in z at its static equilibrium under the load),
         ! with a thermal velocity (inertial tip).
         u0 = 0.0_wp
         if (nd == 3) then
            call start_height(tip, config, path, u0(3), error)
            if (allocated(error)) return
         end if
         if (self%lead_steps > 0) then
            call self%lead_step%start(stream, 0.0_wp, u0, state)
            call self%lead_step%advance(tip, stream, state, self%lead_steps, error)
            self%steps = self%steps + self%lead_steps
            self%force_evaluations = self%force_evaluations + self%lead_steps + 1
            ! on with the samples' step from the end of the lead-in
            state%t0 = config%lead_in / config%velocity
            state%steps = 0
         else
            call self%step%start(stream, 0.0_wp, u0, state)
         end if
         ! With slips, in stretches of check_steps, each followed by a
         ! check; else in chunks, the clock looked at between them (the same
         ! trajectory bit for bit: the steps do not depend on the calls).
         stride = merge(self%check_steps, langevin_chunk, present(slips))
         do k = 1, config%nx
            i = path%sample(config, k)
            if (k > 1 .and. .not. allocated(error)) then
               done = 0
               do while (done < self%sample_steps .and. .not. allocated(error))
                  n = min(stride, self%sample_steps - done)
                  call self%step%advance(tip, stream, state, n, error)
                  self%force_evaluations = self%force_evaluations + n + 1
                  done = done + n
                  if (present(slips) .and. .not. allocated(error)) call check_slips()
                  if (.not. allocated(error) .and. done < self%sample_steps) &
                     & call guard%check('Langevin', self%step%time_of(state), error)
               end do
               self%steps = self%steps + self%sample_steps
            else if (k == 1 .and. present(slips) .and. .not. allocated(error)) then
               call check_slips()
            end if
            t = self%step%time_of(state)
            if (.not. allocated(error)) call guard%check('Langevin', t, error)
            if (allocated(error)) then
               error%message = error%message//path%where(config, t)
               return
            end if
            call record%put(i, tip, config, path, t, state%u, 0, error)
            if (allocated(error)) return
         end do
      end subroutine samples

      !> Quench the state into its minimum; a slip when the minimum moved by
      !> more than slip_distance since the last check.  (A quench that does
      !> not converge leaves the check out.)
      subroutine check_slips()
         type(error_type), allocatable :: quench_error
         real(wp) :: u_min(3), here(3), tn

         tn = self%step%time_of(state)
         u_min = 0.0_wp
         call find_minimum(tip, tn, state%u(1:nd), u_min(1:nd), quench_error)
         if (allocated(quench_error)) return
         here = tip%support(tn)
         here(1:nd) = here(1:nd) + u_min(1:nd)
         if (in_well) then
            if (norm2(here(1:nd) - minimum(1:nd)) > slip_distance) &
               & call slips%add_jump(path, last_support, last_force, here - minimum)
         end if
         minimum = here
         last_support = path%position(config, tn)
         last_force = path%spring_force(tip, state%u)
         in_well = .true.
      end subroutine check_slips

   end subroutine run

end module friction_afm_langevin_trip
