!> The machine's file (docs/laws.md, "Mechanisms"; /machine).  Collective:
!> every rank calls it with the same run (each computed it: a run is
!> deterministic), and rank 0 writes the values.
module friction_machine_output
   use friction_parallel, only: communicator
   use friction_kinds, only: wp
   use friction_error, only: error_type
   use friction_strings, only: join
   use friction_output_h5, only: h5_file
   use friction_output_parameters, only: write_parameter_attributes
   use friction_output_summary, only: run_summary, write_run_attributes
   use friction_machine_config, only: machine_config
   use friction_machine_run, only: machine_run, event_kind_names
   use friction_machine_diagnostics, only: machine_diagnostics
   use friction_machine_section, only: write_machine_poincare
   use friction_machine_lyapunov, only: write_machine_spectrum
   use friction_output_rosenstein, only: write_rosenstein
   use friction_machine_orbit_output, only: write_machine_orbit
   implicit none
   private

   public :: machine_summary, write_machine_file

   type, extends(run_summary) :: machine_summary
      real(wp) :: compute_time = 0.0_wp   !! s, the integration alone
   end type machine_summary

contains

   subroutine write_machine_file(path, comm, config, run, summary, diagnostics, error)
      character(len=*), intent(in) :: path
      type(communicator), intent(in) :: comm
      type(machine_config), intent(in) :: config
      type(machine_run), intent(in) :: run
      type(machine_summary), intent(in) :: summary
      type(machine_diagnostics), intent(in) :: diagnostics
      type(error_type), allocatable, intent(out) :: error
      type(h5_file) :: file
      type(error_type), allocatable :: close_error
      type(machine_config) :: copy
      character(len=32) :: codes(size(event_kind_names))
      integer :: k, n
      !> the run's series, along /machine/t
      character(len=*), parameter :: along_t(4) = [character(len=5) :: 'x', 'v', 'force', 'stick']
      character(len=*), parameter :: event_series(4) = [character(len=4) :: 't', 'kind', 'x', 'v']

      call file%create(path, comm, error)
      if (allocated(error)) then
         call file%close(close_error)
         return
      end if
      call write_run_attributes(file, 'machine', trim(config%solver%method), summary)
      call file%create_group('/machine')
      call file%write_attribute_text('/machine', 'law', trim(config%law%model))
      call file%write_attribute_real('/machine', 'compute_time', summary%compute_time, 's')
      call file%write_attribute_real('/machine', 'stick_time', run%stick_time, 's')
      call file%write_attribute_real('/machine', 'rtol', config%solver%rtol)
      call file%write_attribute_real('/machine', 'atol', config%solver%atol)
      copy = config
      call write_parameter_attributes(file, '/machine', copy, [character(len=8) :: 'machine', 'law'])
      call file%write_vector('/machine/t', run%t, 's')
      call file%write_vector('/machine/x', run%x, 'm')
      call file%write_vector('/machine/v', run%v, 'm/s')
      call file%write_vector('/machine/force', run%force, 'N')
      call file%write_vector_integer('/machine/stick', run%stick, '1')
      do k = 1, run%n_states
         call file%write_vector('/machine/'//trim(run%state_names(k)), run%states(k, :), trim(run%state_units(k)))
      end do
      do k = 1, size(along_t)
         call file%attach_scales('/machine/'//trim(along_t(k)), ['/machine/t'])
      end do
      do k = 1, run%n_states
         call file%attach_scales('/machine/'//trim(run%state_names(k)), ['/machine/t'])
      end do
      call file%create_group('/machine/events')
      do k = 1, size(event_kind_names)
         write (codes(k), '(i0, a)') k, ' = '//trim(event_kind_names(k))
      end do
      call file%write_attribute_text('/machine/events', 'kind_names', join(codes))
      n = run%n_events
      call file%write_vector('/machine/events/t', run%event_t(1:n), 's')
      call file%write_vector_integer('/machine/events/kind', run%event_kind(1:n), '1')
      call file%write_vector('/machine/events/x', run%event_x(1:n), 'm')
      call file%write_vector('/machine/events/v', run%event_v(1:n), 'm/s')
      ! The events' own axis (their time t cannot be: a child's dimension t would clash with the run's).
      call file%write_vector_integer('/machine/events/event', [(k, k = 1, n)], '1')
      do k = 1, size(event_series)
         call file%attach_scales('/machine/events/'//trim(event_series(k)), ['/machine/events/event'])
         ! t as each event's time coordinate (CF's auxiliary coordinates), as netCDF readers take it
         if (k > 1) call file%write_attribute_text('/machine/events/'//trim(event_series(k)), 'coordinates', 't')
      end do
      if (diagnostics%spectrum) then
         associate (p => diagnostics%peak, a => config%analysis)
            call file%create_group('/machine/spectrum')
            call file%write_attribute_text('/machine/spectrum', 'series', trim(a%series))
            call file%write_attribute_text('/machine/spectrum', 'window', trim(a%window))
            call file%write_attribute_real('/machine/spectrum', 'window_start', a%window_start, 's')
            call file%write_attribute_real('/machine/spectrum', 'window_end', a%window_end, 's')
            call file%write_attribute_real('/machine/spectrum', 'peak_frequency', p%peak_frequency, 'Hz')
            call file%write_attribute_real('/machine/spectrum', 'peak_amplitude', p%peak_amplitude)
            call file%write_attribute_real('/machine/spectrum', 'resolution', p%resolution, 'Hz')
            call file%write_vector('/machine/spectrum/frequency', p%frequency, 'Hz')
            call file%write_vector('/machine/spectrum/amplitude', p%amplitude, merge('m  ', 'm/s', a%series == 'x'))
            call file%attach_scales('/machine/spectrum/amplitude', ['/machine/spectrum/frequency'])
         end associate
      end if
      if (diagnostics%lyapunov) then
         associate (f => diagnostics%flow)
            call file%create_group('/machine/lyapunov')
            call file%write_attribute_real('/machine/lyapunov', 'exponent', f%current(), '1/s')
            call file%write_attribute_real('/machine/lyapunov', 'd0', f%d0)
            call file%write_vector('/machine/lyapunov/time', f%time(1:f%n), 's')
            call file%write_vector('/machine/lyapunov/estimate', f%estimate(1:f%n), '1/s')
            call file%attach_scales('/machine/lyapunov/estimate', ['/machine/lyapunov/time'])
         end associate
      end if
      if (diagnostics%lyapunov_spectrum) then
         if (.not. diagnostics%lyapunov) call file%create_group('/machine/lyapunov')
         call write_machine_spectrum(file, '/machine/lyapunov', diagnostics%qr)
      end if
      if (diagnostics%rosenstein) then
         if (.not. (diagnostics%lyapunov .or. diagnostics%lyapunov_spectrum)) call file%create_group('/machine/lyapunov')
         call write_rosenstein(file, '/machine/lyapunov', config%analysis, diagnostics%series, diagnostics%series_dt, &
            & '1/s', 's', 's')
      end if
      if (diagnostics%poincare) call write_machine_poincare(file, config, run, diagnostics%sections)
      if (diagnostics%orbit) then
         call write_machine_orbit(file, config, diagnostics%periodic, diagnostics%continued, diagnostics%branch, error)
         if (allocated(error)) then
            call file%close(close_error)
            return
         end if
      end if
      call file%close(error)
   end subroutine write_machine_file

end module friction_machine_output
