!> Settings of the brake scene as the namelist gives them (README: input
!> reference, groups &brake, &brake_dimensional, &verify, &integrator), and
!> the parameters of Eq. 10 they resolve to.
module friction_brake_config
   use friction_kinds, only: wp, i8
   use friction_error, only: error_type
   use friction_ode_solver, only: solver_settings
   use friction_brake_params, only: brake_parameters, brake_dimensional, derive_parameters
   use friction_analysis_settings, only: analysis_settings
   implicit none
   private

   public :: brake_config, brake_check, model_names, units_names, brake_solver_defaults
   public :: model_regularized, model_switched

   character(len=*), parameter :: model_names(2) = [character(len=11) :: 'switched', 'regularized']
   character(len=*), parameter :: units_names(2) = [character(len=14) :: 'nondimensional', 'dimensional']
   character(len=*), parameter :: model_switched = 'switched', model_regularized = 'regularized'

   !> &integrator defaults for the brake when no file sets them: rk8pd, tight
   !> (the benchmark: the switched model reaches 1e-8 on x this way); times in τ.
   type(solver_settings), parameter :: brake_solver_defaults = solver_settings(method='rk8pd', &
      & rtol=1.0e-10_wp, atol=1.0e-12_wp, h_start=0.0_wp, h_min=0.0_wp, max_steps=10000000_i8, &
      & max_wall_time=0.0_wp)

   !> The second run of `verify`: another stepper or tighter tolerances.
   type :: brake_check
      logical :: enabled = .false.
      character(len=16) :: method = ''     !! '' for the main run's stepper
      real(wp) :: rtol = 0.0_wp            !! 0 for the main run's / 1000
      real(wp) :: atol = 0.0_wp            !! 0 for the main run's / 1000
      real(wp) :: max_difference = 0.0_wp  !! > 0: a larger difference in x fails the run
   end type brake_check

   type :: brake_config
      character(len=16) :: model = model_switched      !! 'switched' (Fig. 10) or 'regularized' (Eq. 10)
      character(len=16) :: units = 'nondimensional'    !! which parameter set is read
      type(brake_parameters) :: params                 !! Eq. 10 (given, or derived from dimensional)
      type(brake_dimensional) :: dimensional           !! §6.2 data, used when units = 'dimensional'
      ! Initial state (§4.1: x = y = 0, x' = v'_dr, y' = 0)
      real(wp) :: x0 = 0.0_wp       !! block displacement, m
      real(wp) :: y0 = 0.0_wp       !! crank arm tip displacement, m
      real(wp) :: v_rel0 = 0.0_wp   !! block velocity relative to the belt, x' - v'_dr, m per unit τ
      real(wp) :: w0 = 0.0_wp       !! crank arm tip velocity y', m per unit τ
      ! Output grid in τ
      real(wp) :: t_start = 0.0_wp
      real(wp) :: t_end = 3200.0_wp
      real(wp) :: dt_out = 0.1_wp
      ! Events and flags
      real(wp) :: event_tolerance = 1.0e-10_wp  !! bound on located event times, τ
      real(wp) :: stick_velocity = 1.0e-6_wp    !! regularized: |v_rel| below this counts as stick
      type(solver_settings) :: solver = brake_solver_defaults
      type(brake_check) :: check
      type(analysis_settings) :: analysis   !! chaos diagnostics (&analysis)
   contains
      procedure :: resolve
      procedure :: grid_size
      procedure :: grid_time
      procedure :: check_settings
   end type brake_config

contains

   !> With units = 'dimensional', derive params from the §6.2 data
   !> (keeping μ and μs); otherwise params stand as given.
   subroutine resolve(self, error)
      class(brake_config), intent(inout) :: self
      type(error_type), allocatable, intent(out) :: error
      type(brake_parameters) :: derived

      if (trim(self%units) /= 'dimensional') return
      call derive_parameters(self%dimensional, self%params%mu, self%params%mu_s, derived, error)
      if (allocated(error)) return
      self%params = derived
   end subroutine resolve

   !> Points of the output grid t_start + i dt_out, i = 0, 1, ..., up to
   !> t_end (included when t_end - t_start is a multiple of dt_out to 1e-9).
   pure integer function grid_size(self)
      class(brake_config), intent(in) :: self

      grid_size = int((self%t_end - self%t_start) / self%dt_out * (1.0_wp + 1.0e-9_wp) + 1.0e-9_wp) + 1
   end function grid_size

   !> Time of grid point i (1-based).
   pure real(wp) function grid_time(self, i)
      class(brake_config), intent(in) :: self
      integer, intent(in) :: i

      grid_time = self%t_start + real(i - 1, wp) * self%dt_out
   end function grid_time

   !> The verification run's settings: another stepper or tighter
   !> tolerances, and a thousandfold tighter event tolerance.
   function check_settings(self) result(other)
      class(brake_config), intent(in) :: self
      type(brake_config) :: other

      other = self
      other%check%enabled = .false.
      if (len_trim(self%check%method) > 0) other%solver%method = self%check%method
      other%solver%rtol = self%check%rtol
      if (.not. (other%solver%rtol > 0.0_wp)) other%solver%rtol = self%solver%rtol / 1000.0_wp
      other%solver%atol = self%check%atol
      if (.not. (other%solver%atol > 0.0_wp)) other%solver%atol = self%solver%atol / 1000.0_wp
      other%event_tolerance = self%event_tolerance / 1000.0_wp
   end function check_settings

end module friction_brake_config
