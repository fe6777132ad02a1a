!> The brake file (docs/output.md, /brake).  Collective: every
!> rank calls it with the same data (rank 0 computed it and broadcast it;
!> the datasets are small), and rank 0 writes the values.
module friction_brake_output
   use friction_parallel, only: communicator
   use friction_kinds, only: wp, i8
   use friction_error, only: error_type
   use friction_strings, only: join
   use friction_ode_solver, only: integrator_statistics
   use friction_brake_config, only: brake_config
   use friction_brake_params, only: time_scale
   use friction_brake_record, only: brake_trajectory, brake_event_table, event_kind_names
   use friction_brake_simulate, only: brake_comparison
   use friction_brake_diagnostics, only: brake_diagnostics
   use friction_brake_orbit, only: orbit_branch, bifurcation_names
   use friction_output_h5, only: h5_file
   use friction_output_branch, only: write_branch_points, write_branch_sections, write_bifurcations
   use friction_output_rosenstein, only: write_rosenstein
   use friction_output_parameters, only: write_parameter_attributes
   use friction_output_summary, only: run_summary, write_run_attributes
   implicit none
   private

   public :: brake_run_summary, brake_check_summary, write_brake_file

   !> The units of the state's columns (x, x', y, y') in τ: their `units` is 'm' at τ = 1.
   character(len=*), parameter :: state_units_tau = 'm, m/tau, m, m/tau'

   !> What the file records about the run besides the trajectory.
   type, extends(run_summary) :: brake_run_summary
      real(wp) :: compute_time = 0.0_wp    !! s, integration of the main run alone
      real(wp) :: stick_time = 0.0_wp      !! τ spent in stick
   end type brake_run_summary

   !> The verification run: its settings, cost and differences.
   type :: brake_check_summary
      logical :: enabled = .false.
      type(brake_config) :: config
      type(brake_comparison) :: comparison
      type(integrator_statistics) :: stats
      real(wp) :: compute_time = 0.0_wp
   end type brake_check_summary

contains

   !> A &law unit (SI) as the nondimensional brake's law reads its value
   !> (docs/laws.md, "The brake with any law"): a force over k1 in m, a time in τ.
   pure function brake_unit(unit) result(mapped)
      character(len=*), intent(in) :: unit
      character(len=:), allocatable :: mapped

      select case (unit)
      case ('N')
         mapped = 'm'
      case ('s')
         mapped = 'tau'
      case ('m/s')
         mapped = 'm/tau'
      case ('s/m')
         mapped = 'tau/m'
      case ('N/m')
         mapped = '1'
      case ('N s/m')
         mapped = 'tau'
      case default   ! '1', 'm'
         mapped = unit
      end select
   end function brake_unit

   subroutine write_brake_file(path, comm, config, trajectory, events, summary, check, error, diagnostics)
      character(len=*), intent(in) :: path
      type(communicator), intent(in) :: comm
      type(brake_config), intent(in) :: config
      type(brake_trajectory), intent(in) :: trajectory
      type(brake_event_table), intent(in) :: events
      type(brake_run_summary), intent(in) :: summary
      type(brake_check_summary), intent(in) :: check
      type(error_type), allocatable, intent(out) :: error
      type(brake_diagnostics), intent(in), optional :: diagnostics   !! with &analysis on
      type(h5_file) :: file
      type(error_type), allocatable :: close_error
      type(brake_config) :: copy
      real(wp) :: f(2)
      integer :: n, k
      character(len=32) :: codes(size(event_kind_names))
      !> the trajectory's series, along /brake/t
      character(len=*), parameter :: along_t(5) = [character(len=5) :: 'x', 'v', 'y', 'w', 'stick']
      character(len=*), parameter :: event_series(6) = [character(len=4) :: 't', 'kind', 'x', 'v', 'y', 'w']

      call file%create(path, comm, error)
      if (allocated(error)) then
         call file%close(close_error)
         return
      end if
      call write_run_attributes(file, 'brake', trim(config%solver%method), summary)

      call file%create_group('/brake')
      call file%write_attribute_text('/brake', 'model', trim(config%model))
      call file%write_attribute_text('/brake', 'units', trim(config%units))
      associate (p => config%params)
         ! The parameters of Eq. 10 the run used (derived when units = 'dimensional').
         call file%write_attribute_real('/brake', 'xi', p%xi)
         call file%write_attribute_real('/brake', 'kappa', p%kappa)
         call file%write_attribute_real('/brake', 'g_prime', p%g_prime, 'm')
         call file%write_attribute_real('/brake', 'mu', p%mu)
         call file%write_attribute_real('/brake', 'mu_s', p%mu_s)
         call file%write_attribute_real('/brake', 'epsilon_prime', p%epsilon_prime, 'tau/m')
         call file%write_attribute_real('/brake', 'delta_prime', p%delta_prime, 'tau/m')
         call file%write_attribute_real('/brake', 'v_dr_prime', p%v_dr, 'm/tau')
         f = p%natural_frequencies()
         call file%write_attribute_real('/brake', 'natural_frequency_1', f(1), '1/tau')
         call file%write_attribute_real('/brake', 'natural_frequency_2', f(2), '1/tau')
      end associate
      if (trim(config%units) == 'dimensional') &
         & call file%write_attribute_real('/brake', 'time_scale', time_scale(config%dimensional), 's')
      call file%write_attribute_real('/brake', 't_start', config%t_start, 'tau')
      call file%write_attribute_real('/brake', 't_end', config%t_end, 'tau')
      call file%write_attribute_real('/brake', 'dt_out', config%dt_out, 'tau')
      call file%write_attribute_real('/brake', 'event_tolerance', config%event_tolerance, 'tau')
      call file%write_attribute_real('/brake', 'stick_velocity', config%stick_velocity, 'm/tau')
      call file%write_attribute_real('/brake', 'compute_time', summary%compute_time, 's')
      call file%write_attribute_real('/brake', 'stick_time', summary%stick_time, 'tau')
      call file%write_attribute_real('/brake', 'rtol', config%solver%rtol)
      call file%write_attribute_real('/brake', 'atol', config%solver%atol)
      copy = config
      if (trim(config%units) == 'dimensional') then
         call write_parameter_attributes(file, '/brake', copy, [character(len=17) :: 'brake', 'brake_dimensional'])
      else
         call write_parameter_attributes(file, '/brake', copy, [character(len=17) :: 'brake'])
      end if
      if (config%uses_law()) then
         ! The law's parameters in its own group (names such as mu and delta are &brake's too).
         call file%create_group('/brake/law')
         call file%write_attribute_text('/brake/law', 'model', trim(config%law%model))
         if (trim(config%units) == 'dimensional') then
            call write_parameter_attributes(file, '/brake/law', copy, [character(len=17) :: 'law'])
         else
            call write_parameter_attributes(file, '/brake/law', copy, [character(len=17) :: 'law'], brake_unit)
         end if
      end if

      call file%write_vector('/brake/t', trajectory%t, 'tau')
      call file%write_vector('/brake/x', trajectory%x, 'm')
      call file%write_vector('/brake/v', trajectory%v, 'm/tau')
      call file%write_vector('/brake/y', trajectory%y, 'm')
      call file%write_vector('/brake/w', trajectory%w, 'm/tau')
      call file%write_vector_integer('/brake/stick', trajectory%stick, '1')
      call file%write_attribute_text('/brake/t', 'long_name', 'dimensionless time tau')
      call file%write_attribute_text('/brake/x', 'long_name', 'block displacement x')
      call file%write_attribute_text('/brake/v', 'long_name', "block velocity x' = dx/dtau")
      call file%write_attribute_text('/brake/y', 'long_name', 'crank-tip displacement y')
      call file%write_attribute_text('/brake/w', 'long_name', "crank-tip velocity y' = dy/dtau")
      do k = 1, 5
         call file%attach_scales('/brake/'//trim(along_t(k)), ['/brake/t'])
      end do

      n = events%n
      call file%create_group('/brake/events')
      do n = 1, size(event_kind_names)
         write (codes(n), '(i0, a)') n, ' = '//trim(event_kind_names(n))
      end do
      n = events%n
      call file%write_attribute_text('/brake/events', 'kind_names', join(codes))
      call file%write_vector('/brake/events/t', event_column(0), 'tau')
      call file%write_vector_integer('/brake/events/kind', event_kinds(), '1')
      call file%write_vector('/brake/events/x', event_column(1), 'm')
      call file%write_vector('/brake/events/v', event_column(2), 'm/tau')
      call file%write_vector('/brake/events/y', event_column(3), 'm')
      call file%write_vector('/brake/events/w', event_column(4), 'm/tau')
      ! The events' own axis: their number, the coordinate every /brake/events dataset runs along
      ! (their time t cannot be: a child's dimension named t would clash with the trajectory's).
      call file%write_vector_integer('/brake/events/event', [(k, k = 1, n)], '1')
      do k = 1, size(event_series)
         call file%attach_scales('/brake/events/'//trim(event_series(k)), ['/brake/events/event'])
         ! t as each event's time coordinate (CF's auxiliary coordinates), as netCDF readers take it
         if (k > 1) call file%write_attribute_text('/brake/events/'//trim(event_series(k)), 'coordinates', 't')
      end do

      if (check%enabled) then
         call file%create_group('/brake/verify')
         associate (c => check%config, d => check%comparison)
            call file%write_attribute_text('/brake/verify', 'method', trim(c%solver%method))
            call file%write_attribute_real('/brake/verify', 'rtol', c%solver%rtol)
            call file%write_attribute_real('/brake/verify', 'atol', c%solver%atol)
            call file%write_attribute_real('/brake/verify', 'event_tolerance', c%event_tolerance, 'tau')
            call file%write_attribute_real('/brake/verify', 'max_difference_x', d%max_difference(1), 'm')
            call file%write_attribute_real('/brake/verify', 'max_difference_v', d%max_difference(2), 'm/tau')
            call file%write_attribute_real('/brake/verify', 'max_difference_y', d%max_difference(3), 'm')
            call file%write_attribute_real('/brake/verify', 'max_difference_w', d%max_difference(4), 'm/tau')
            call file%write_attribute_real('/brake/verify', 'end_difference_x', d%end_difference(1), 'm')
            call file%write_attribute_integer('/brake/verify', 'events', int(d%events, i8))
            call file%write_attribute_integer('/brake/verify', 'check_events', int(d%check_events, i8))
            ! Events pair up in order only when both runs have as many.
            if (d%events == d%check_events) call file%write_attribute_real('/brake/verify', &
               & 'max_event_time_difference', d%max_event_time_difference)
            call file%write_attribute_integer('/brake/verify', 'rhs_evaluations', check%stats%rhs_evaluations)
            call file%write_attribute_real('/brake/verify', 'compute_time', check%compute_time, 's')
         end associate
      end if
      if (present(diagnostics)) call write_diagnostics(file, diagnostics)
      call file%close(error)

   contains

      !> Column k of the event table: 0 the times, 1..4 the state.
      function event_column(k) result(values)
         integer, intent(in) :: k
         real(wp) :: values(n)

         if (n == 0) return
         if (k == 0) then
            values = events%t(1:n)
         else
            values = events%state(k, 1:n)
         end if
      end function event_column

      function event_kinds() result(values)
         integer :: values(n)

         if (n == 0) return
         values = events%kind(1:n)
      end function event_kinds

   end subroutine write_brake_file

   !> /brake/spectrum, /brake/poincare, /brake/lyapunov (docs/output.md).
   subroutine write_diagnostics(file, d)
      type(h5_file), intent(inout) :: file
      type(brake_diagnostics), intent(in) :: d
      character(len=*), parameter :: frequency_unit = '1/tau'   !! cycles per unit τ
      integer :: k
      character(len=*), parameter :: names(4) = ['x', 'v', 'y', 'w']
      character(len=*), parameter :: units(4) = [character(len=5) :: 'm', 'm/tau', 'm', 'm/tau']

      associate (a => d%settings)
         if (a%spectrum) then
            call file%create_group('/brake/spectrum')
            call file%write_attribute_text('/brake/spectrum', 'series', trim(a%series))
            call file%write_attribute_text('/brake/spectrum', 'window', trim(a%window))
            call file%write_attribute_integer('/brake/spectrum', 'welch_segments', int(a%welch_segments, i8))
            call file%write_attribute_integer('/brake/spectrum', 'segment_length', &
               & int(d%spectrum%segment_length, i8))
            call file%write_attribute_real('/brake/spectrum', 'window_start', a%window_start, 'tau')
            call file%write_attribute_real('/brake/spectrum', 'window_end', a%window_end, 'tau')
            call file%write_attribute_real('/brake/spectrum', 'peak_frequency', d%spectrum%peak_frequency, '1/tau')
            call file%write_attribute_real('/brake/spectrum', 'peak_amplitude', d%spectrum%peak_amplitude)
            call file%write_attribute_real('/brake/spectrum', 'resolution', d%spectrum%resolution, '1/tau')
            call file%write_vector('/brake/spectrum/frequency', d%spectrum%frequency, frequency_unit)
            call file%write_attribute_text('/brake/spectrum/frequency', 'long_name', 'frequency in cycles per unit tau')
            k = findloc(names, trim(a%series), 1)
            call file%write_vector('/brake/spectrum/amplitude', d%spectrum%amplitude, trim(units(max(k, 1))))
            call file%attach_scales('/brake/spectrum/amplitude', ['/brake/spectrum/frequency'])
         end if
         if (a%poincare) then
            call file%create_group('/brake/poincare')
            call file%write_attribute_real('/brake/poincare', 'strobe_period', d%strobe_period, 'tau')
            call file%write_attribute_real('/brake/poincare', 'strobe_start', a%strobe_start, 'tau')
            call file%write_attribute_real('/brake/poincare', 'strobe_end', a%strobe_end, 'tau')
            call file%write_attribute_text('/brake/poincare', 'section', trim(a%section))
            call file%write_vector('/brake/poincare/strobe_t', d%strobe_t, 'tau')
            call file%write_vector('/brake/poincare/section_t', d%section_t, 'tau')
            do k = 1, 4
               call file%write_vector('/brake/poincare/strobe_'//names(k), d%strobe_points(k, :), trim(units(k)))
               call file%write_vector('/brake/poincare/section_'//names(k), d%section_points(k, :), trim(units(k)))
               call file%attach_scales('/brake/poincare/strobe_'//names(k), ['/brake/poincare/strobe_t '])
               call file%attach_scales('/brake/poincare/section_'//names(k), ['/brake/poincare/section_t'])
            end do
         end if
         if (a%lyapunov .or. a%rosenstein .or. a%lyapunov_spectrum) call file%create_group('/brake/lyapunov')
         if (a%lyapunov_spectrum) then
            call file%write_vector('/brake/lyapunov/exponents', d%exponents, '1/tau')
            call file%write_vector('/brake/lyapunov/exponents_time', d%qr%time(1:d%qr%count), 'tau')
            call file%write_matrix('/brake/lyapunov/exponents_history', d%qr%history(:, 1:d%qr%count), '1/tau')
            call file%write_attribute_real('/brake/lyapunov', 'kaplan_yorke_dimension', d%kaplan_yorke, '1')
            call file%write_attribute_integer('/brake/lyapunov', 'spectrum_lost_directions', int(d%qr%lost, i8))
            call file%write_attribute_real('/brake/lyapunov', 'spectrum_transient', d%tangent%transient, 'tau')
            call file%write_attribute_real('/brake/lyapunov', 'spectrum_duration', d%tangent%duration, 'tau')
            call file%write_attribute_real('/brake/lyapunov', 'spectrum_renormalise', d%tangent%renormalise, 'tau')
            if (allocated(d%divergence)) &
               & call file%write_attribute_real('/brake/lyapunov', 'spectrum_divergence', d%divergence, '1/tau')
         end if
         if (a%lyapunov) then
            call file%write_attribute_real('/brake/lyapunov', 'benettin_exponent', d%flow%current(), '1/tau')
            call file%write_attribute_real('/brake/lyapunov', 'benettin_transient', d%benettin%transient, 'tau')
            call file%write_attribute_real('/brake/lyapunov', 'benettin_duration', d%benettin%duration, 'tau')
            call file%write_attribute_real('/brake/lyapunov', 'benettin_renormalise', d%benettin%renormalise, 'tau')
            call file%write_attribute_real('/brake/lyapunov', 'benettin_d0', d%benettin%d0)
            call file%write_vector('/brake/lyapunov/benettin_time', d%flow%time(1:d%flow%n), 'tau')
            call file%write_vector('/brake/lyapunov/benettin_estimate', d%flow%estimate(1:d%flow%n), '1/tau')
            call file%attach_scales('/brake/lyapunov/benettin_estimate', ['/brake/lyapunov/benettin_time'])
         end if
         if (a%orbit) call write_orbit(file, d)
         if (a%rosenstein) call write_rosenstein(file, '/brake/lyapunov', a, d%series, d%series_dt, '1/tau', '1')
      end associate
   end subroutine write_diagnostics

   !> /brake/orbit (docs/output.md): the periodic orbit through the
   !> stick-to-slip section, or found = 0 and the reason.
   subroutine write_orbit(file, d)
      type(h5_file), intent(inout) :: file
      type(brake_diagnostics), intent(in) :: d
      character(len=*), parameter :: group = '/brake/orbit'
      real(wp), allocatable :: parts(:, :)

      associate (a => d%settings, o => d%orbit, m => d%orbit%n_states)
         call file%create_group(group)
         call file%write_attribute_integer(group, 'found', merge(1_i8, 0_i8, o%orbit%found))
         if (.not. o%orbit%found) call file%write_attribute_text(group, 'reason', o%orbit%reason)
         call file%write_attribute_text(group, 'section', trim(o%section))
         call file%write_attribute_integer(group, 'static_limit', int(nint(o%limit), i8))
         call file%write_attribute_real(group, 'guess_time', o%guess_time, 'tau')
         call file%write_attribute_real(group, 'transient', a%orbit_transient, 'tau')
         call file%write_attribute_real(group, 'tolerance', a%orbit_tolerance, 'm')
         call file%write_attribute_integer(group, 'iterations', int(o%orbit%iterations, i8))
         call file%write_attribute_real(group, 'residual', o%orbit%residual, 'm')
         ! The fixed point, or Newton's last iterate when none was found.
         call file%write_vector(group//'/point', o%state, 'm')
         call file%write_attribute_text(group//'/point', 'names', 'x, v, y, w')
         call file%write_attribute_text(group//'/point', 'column_units_tau', state_units_tau)
         if (m > 0) then
            ! The law's states on the section (the Jacobian's coordinates 4 to 3 + m are them over their scale).
            call file%write_vector(group//'/law_states', o%states(1:m) * o%scale(1:m), '')
            call file%write_attribute_text(group//'/law_states', 'names', join(o%state_names(1:m)))
            call file%write_attribute_text(group//'/law_states', 'units', join(o%state_units(1:m)))
            call file%write_vector(group//'/law_state_scale', o%scale(1:m), '')
         end if
         if (len_trim(a%continuation) > 0) call write_branch(file, d%branch)
         if (.not. o%orbit%found) return
         call file%write_attribute_real(group, 'period', o%orbit%period, 'tau')
         call file%write_matrix(group//'/section_jacobian', o%orbit%jacobian, '1')
         allocate (parts(2, 4 + m))
         parts(1, :) = real(o%multipliers(1:4 + m))
         parts(2, :) = aimag(o%multipliers(1:4 + m))
         call file%write_matrix(group//'/floquet_multipliers', parts, '1')
         call file%write_attribute_text(group//'/floquet_multipliers', 'columns', 'real, imag')
         call file%write_vector(group//'/floquet_exponents', o%exponents(1:4 + m), '1/tau')
         call file%write_vector_integer(group//'/events_per_period', o%pattern, '1')
         call file%write_attribute_text(group//'/events_per_period', 'names', join(event_kind_names))
      end associate
   end subroutine write_orbit

   !> /brake/orbit/branch and /brake/orbit/bifurcations (docs/output.md).
   subroutine write_branch(file, b)
      type(h5_file), intent(inout) :: file
      type(orbit_branch), intent(in) :: b
      character(len=*), parameter :: group = '/brake/orbit/branch'
      !> the branch's series along its points, whose coordinate is the parameter (a coordinate is on
      !> every axis of a dataset or on none: netCDF's readers refuse a mix)
      character(len=*), parameter :: along_branch(4) = [character(len=11) :: 'found', 'source', 'period', &
         & 'max_modulus']

      call write_branch_points(file, group, trim(b%variable), b%parameter, b%unit, b%found, b%source)
      call file%write_vector(group//'/period', b%period, 'tau')
      call file%write_matrix(group//'/point', b%state, 'm')
      call file%write_attribute_text(group//'/point', 'column_units_tau', state_units_tau)
      call file%write_matrix(group//'/floquet_multipliers_real', real(b%multipliers), '1')
      call file%write_matrix(group//'/floquet_multipliers_imag', aimag(b%multipliers), '1')
      call file%write_vector(group//'/max_modulus', b%max_modulus, '1')
      call file%write_matrix(group//'/events_per_period', real(b%pattern, wp), '1')
      call write_branch_sections(file, group, b%section_parameter, b%section_x, b%unit, along_branch)
      call write_bifurcations(file, '/brake/orbit/bifurcations', bifurcation_names, b%kind, b%at, b%unit)
   end subroutine write_branch

end module friction_brake_output
