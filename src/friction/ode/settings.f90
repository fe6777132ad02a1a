!> &integrator: the stepper settings as a namelist group, shared by every
!> scene (each scene keeps its own defaults), and their checks; and
!> &verify, the second integration that checks a run.
module friction_ode_settings
   use friction_kinds, only: wp
   use friction_strings, only: itoa, quoted, rtoa
   use friction_parameters, only: parameter_visitor
   use friction_checks, only: config_checker
   use friction_ode_solver, only: solver_settings, step_type_names, step_type_index
   use friction_ode_auto, only: auto_name
   implicit none
   private

   public :: visit_integrator, check_integrator, check_tolerance_bounds
   public :: verify_settings, visit_verify, check_verify, verify_solver

   !> &verify: the run integrated again with another stepper or tighter
   !> tolerances, and the two compared (docs/input.md, &verify).
   type :: verify_settings
      logical :: enabled = .false.
      character(len=16) :: method = ''     !! '' for the run's stepper
      real(wp) :: rtol = 0.0_wp            !! 0 for the run's / 1000
      real(wp) :: atol = 0.0_wp            !! 0 for the run's / 1000
      real(wp) :: max_difference = 0.0_wp  !! > 0: a larger difference fails the run
   end type verify_settings

contains

   !> The group &integrator of a scene; `time_unit` is the unit of its times
   !> ('s' for the microscope, 'tau' for the brake).
   subroutine visit_integrator(s, v, time_unit)
      type(solver_settings), intent(inout) :: s
      type(parameter_visitor), intent(inout) :: v
      character(len=*), intent(in) :: time_unit

      call v%begin_group('integrator')
      call v%item('method', s%method, fold=.true.)
      call v%item('rtol', s%rtol, '1')
      call v%item('atol', s%atol, 'state units')
      call v%item('h_start', s%h_start, time_unit)
      call v%item('h_min', s%h_min, time_unit)
      call v%item('max_steps', s%max_steps, '1')
      call v%item('max_wall_time', s%max_wall_time, 's')
      call v%end_group()
   end subroutine visit_integrator

   subroutine check_integrator(s, c)
      type(solver_settings), intent(in) :: s
      type(config_checker), intent(inout) :: c

      if (s%method /= auto_name .and. step_type_index(s%method) == 0) call c%reject('integrator', 'method', &
         & "'"//trim(s%method)//"'", 'unknown GSL step type (known: '//quoted(step_type_names())//', or '// &
         & quoted([auto_name])//' to choose by scene and rtol)')
      call c%positive('integrator', 'rtol', s%rtol, 'relative tolerance')
      call c%positive('integrator', 'atol', s%atol, 'absolute tolerance, Å and Å/s')
      call check_tolerance_bounds(c, 'integrator', 'rtol', 'atol', s%rtol, s%atol)
      call c%nonnegative('integrator', 'h_start', s%h_start, 's; 0 chooses automatically')
      call c%nonnegative('integrator', 'h_min', s%h_min, 's; 0 for no limit')
      if (s%h_start > 0.0_wp .and. s%h_min > s%h_start) call c%reject('integrator', 'h_min', rtoa(s%h_min), &
         & 'must not exceed h_start = '//rtoa(s%h_start)//' (the first step)')
      if (s%max_steps < 1) call c%reject('integrator', 'max_steps', itoa(s%max_steps), 'must be >= 1')
      call c%nonnegative('integrator', 'max_wall_time', s%max_wall_time, 's; 0 for no limit')
   end subroutine check_integrator

   !> Upper bounds of the tolerances.  GSL accepts a step whose error estimate
   !> is below atol + rtol |y|: with rtol >= 1 any step whose error is as
   !> large as the state itself passes, and an atol of 1 is already a whole
   !> Å (or m, m/τ: the brake's state is far smaller) on every component; a
   !> larger one lets the stepper take steps of any size, and the run ends
   !> with exit 0 and meaningless numbers (rtol = atol = 1e300 gave forces of
   !> 1e181 nN).  So rtol < 1 and atol <= 1.
   subroutine check_tolerance_bounds(c, group, rtol_name, atol_name, rtol, atol)
      type(config_checker), intent(inout) :: c
      character(len=*), intent(in) :: group, rtol_name, atol_name
      real(wp), intent(in) :: rtol, atol

      if (rtol >= 1.0_wp) call c%reject(group, rtol_name, rtoa(rtol), 'must be < 1: a relative tolerance of ' &
         & //'100 % or more accepts any step')
      if (atol > 1.0_wp) call c%reject(group, atol_name, rtoa(atol), 'must be <= 1: an absolute tolerance above ' &
         & //'1 (Å, Å/s; the brake''s m, m/τ) accepts steps of any size')
   end subroutine check_tolerance_bounds

   !> The group &verify; `atol_unit` is that of the state, `limit_unit` that
   !> of the quantity compared (the brake's x in m, the map's forces in nN).
   subroutine visit_verify(s, v, atol_unit, limit_unit)
      type(verify_settings), intent(inout) :: s
      type(parameter_visitor), intent(inout) :: v
      character(len=*), intent(in) :: atol_unit, limit_unit

      call v%begin_group('verify')
      call v%item('check', s%enabled)
      call v%item('check_method', s%method, fold=.true.)
      call v%item('check_rtol', s%rtol, '1')
      call v%item('check_atol', s%atol, atol_unit)
      call v%item('check_limit', s%max_difference, limit_unit)
      call v%end_group()
   end subroutine visit_verify

   subroutine check_verify(s, c, limit_unit)
      type(verify_settings), intent(in) :: s
      type(config_checker), intent(inout) :: c
      character(len=*), intent(in) :: limit_unit

      if (len_trim(s%method) > 0 .and. step_type_index(s%method) == 0) &
         & call c%reject('verify', 'check_method', "'"//trim(s%method)//"'", &
         & "unknown GSL step type (known: ''"//', '//quoted(step_type_names())//')')
      call c%nonnegative('verify', 'check_rtol', s%rtol, '0 for rtol / 1000')
      call c%nonnegative('verify', 'check_atol', s%atol, '0 for atol / 1000')
      call check_tolerance_bounds(c, 'verify', 'check_rtol', 'check_atol', s%rtol, s%atol)
      call c%nonnegative('verify', 'check_limit', s%max_difference, limit_unit//'; 0 reports only')
   end subroutine check_verify

   !> The check run's stepper settings: check_method, else the run's
   !> (resolved) stepper; check_rtol and check_atol, else the run's / 1000.
   function verify_solver(s, run) result(other)
      type(verify_settings), intent(in) :: s
      type(solver_settings), intent(in) :: run
      type(solver_settings) :: other

      other = run
      if (len_trim(s%method) > 0) other%method = s%method
      other%rtol = s%rtol
      if (.not. (other%rtol > 0.0_wp)) other%rtol = run%rtol / 1000.0_wp
      other%atol = s%atol
      if (.not. (other%atol > 0.0_wp)) other%atol = run%atol / 1000.0_wp
   end function verify_solver

end module friction_ode_settings
