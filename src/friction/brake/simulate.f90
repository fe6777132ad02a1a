!> A brake run: either friction model integrated over the output grid, the
!> trajectory and event table it records, and the comparison of two runs
!> (`verify`).  The run can be driven in pieces (run_until) so that the
!> program can report progress between them.
module friction_brake_simulate
   use friction_kinds, only: wp, i8
   use friction_error, only: error_type
   use friction_ode_solver, only: integrator_statistics
   use friction_brake_config, only: brake_config
   use friction_brake_record, only: brake_trajectory, brake_event_table
   use friction_brake_integrator, only: brake_integrator
   use friction_brake_switched, only: switched_integrator
   use friction_brake_regularized, only: regularized_integrator
   use friction_brake_law_model, only: law_integrator
   use friction_brake_band, only: band_integrator, band_law
   implicit none
   private

   public :: brake_run, brake_comparison, compare_runs, simulate_brake, initial_state, new_brake_integrator

   type :: brake_run
      type(brake_config) :: config
      type(brake_trajectory) :: trajectory
      type(brake_event_table) :: events
      class(brake_integrator), allocatable :: integrator   !! the friction model
      integer :: n = 0             !! grid points
      integer :: done = 0          !! grid points filled so far
      real(wp) :: compute_time = 0.0_wp   !! wall-clock seconds spent integrating
   contains
      procedure :: init
      procedure :: run_until
      procedure :: statistics
      procedure :: stick_time
      procedure :: time_reached
   end type brake_run

   !> Differences of a run from a check run on the same grid.
   type :: brake_comparison
      real(wp) :: max_difference(4) = 0.0_wp    !! max over the grid of |Δx|, |Δv|, |Δy|, |Δw|
      real(wp) :: end_difference(4) = 0.0_wp    !! the same at the last grid point
      integer :: events = 0, check_events = 0   !! event counts of both runs
      real(wp) :: max_event_time_difference = 0.0_wp  !! over events paired in order (only when counts agree)
   end type brake_comparison

contains

   !> The initial state (x, x', y, y') of the settings, x' = v'_dr + v_rel0.
   pure function initial_state(config) result(y)
      type(brake_config), intent(in) :: config
      real(wp) :: y(4)

      y = [config%x0, config%params%v_dr + config%v_rel0, config%y0, config%w0]
   end function initial_state

   !> Set up a run of a resolved configuration (parameters of Eq. 10 set)
   !> that has passed its checks (brake_config%validate: among them a
   !> positive normal force N' at the start; the job, the sweep and the C
   !> API all check before they run).
   subroutine init(self, config, error)
      class(brake_run), target, intent(inout) :: self
      type(brake_config), intent(in) :: config
      type(error_type), allocatable, intent(out) :: error

      self%config = config
      self%n = config%grid_size()
      self%done = 0
      self%compute_time = 0.0_wp
      call self%trajectory%allocate_points(self%n)
      call new_brake_integrator(config, self%integrator)
      call self%integrator%start(config, config%t_start, initial_state(config), self%events, error)
   end subroutine init

   !> Fill the grid up to point last (or the end).  On error the points
   !> before the failure are filled and time_reached tells how far it got.
   subroutine run_until(self, last, error)
      class(brake_run), intent(inout) :: self
      integer, intent(in) :: last
      type(error_type), allocatable, intent(out) :: error
      integer :: i
      integer(i8) :: start, finish, rate
      real(wp) :: t, y(4)
      logical :: stick

      call system_clock(start, rate)
      do i = self%done + 1, min(last, self%n)
         t = self%config%grid_time(i)
         call self%integrator%advance_to(t, self%events, error)
         y = self%integrator%state()
         stick = self%integrator%is_sticking()
         if (allocated(error)) exit
         self%trajectory%t(i) = t
         self%trajectory%x(i) = y(1)
         self%trajectory%v(i) = y(2)
         self%trajectory%y(i) = y(3)
         self%trajectory%w(i) = y(4)
         self%trajectory%stick(i) = merge(1, 0, stick)
         self%done = i
      end do
      call system_clock(finish)
      self%compute_time = self%compute_time + real(finish - start, wp) / real(rate, wp)
   end subroutine run_until

   function statistics(self) result(stats)
      class(brake_run), intent(in) :: self
      type(integrator_statistics) :: stats

      stats = self%integrator%statistics()
   end function statistics

   !> Time spent in stick: exact for the switched model; for the regularized
   !> one the grid's share of stick points times the span.
   pure real(wp) function stick_time(self)
      class(brake_run), intent(in) :: self

      if (self%integrator%stick_time >= 0.0_wp) then
         stick_time = self%integrator%stick_time
      else if (self%done > 1) then
         stick_time = real(count(self%trajectory%stick(1:self%done) == 1), wp) / self%done &
            & * (self%trajectory%t(self%done) - self%trajectory%t(1))
      else
         stick_time = 0.0_wp
      end if
   end function stick_time

   pure real(wp) function time_reached(self)
      class(brake_run), intent(in) :: self

      time_reached = self%integrator%t
   end function time_reached

   !> The integrator of the configuration's friction model: a law with a
   !> zero-velocity band (Karnopp's) runs through its band's switches (band.f90).
   subroutine new_brake_integrator(config, integrator)
      type(brake_config), intent(in) :: config
      class(brake_integrator), allocatable, intent(out) :: integrator

      if (config%switched()) then
         allocate (switched_integrator :: integrator)
      else if (band_law(config)) then
         allocate (band_integrator :: integrator)
      else if (config%uses_law()) then
         allocate (law_integrator :: integrator)
      else
         allocate (regularized_integrator :: integrator)
      end if
   end subroutine new_brake_integrator

   !> A whole run in one call.
   subroutine simulate_brake(config, run, error)
      type(brake_config), intent(in) :: config
      type(brake_run), target, intent(inout) :: run
      type(error_type), allocatable, intent(out) :: error

      call run%init(config, error)
      if (allocated(error)) return
      call run%run_until(run%n, error)
   end subroutine simulate_brake

   !> How far a run is from a check run of the same grid.
   pure function compare_runs(run, check) result(cmp)
      type(brake_run), intent(in) :: run, check
      type(brake_comparison) :: cmp
      integer :: n

      n = min(run%done, check%done)
      cmp%events = run%events%n
      cmp%check_events = check%events%n
      if (n < 1) return
      associate (a => run%trajectory, b => check%trajectory)
         cmp%max_difference = [maxval(abs(a%x(1:n) - b%x(1:n))), maxval(abs(a%v(1:n) - b%v(1:n))), &
            & maxval(abs(a%y(1:n) - b%y(1:n))), maxval(abs(a%w(1:n) - b%w(1:n)))]
         cmp%end_difference = abs([a%x(n) - b%x(n), a%v(n) - b%v(n), a%y(n) - b%y(n), a%w(n) - b%w(n)])
      end associate
      if (run%events%n == check%events%n .and. run%events%n > 0) &
         & cmp%max_event_time_difference = maxval(abs(run%events%t(1:run%events%n) &
         & - check%events%t(1:run%events%n)))
   end function compare_runs

end module friction_brake_simulate
