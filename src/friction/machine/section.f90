!> The machine's Poincaré maps (&analysis poincare; docs/chaos.md, "The
!> machine"), from the finished run:
!>
!> - the strobe: the state every strobe_period from strobe_start, linearly
!>   interpolated between output points.  strobe_period = 0 takes the
!>   support's period 1/support_frequency when the support moves
!>   harmonically (the forced oscillator's natural section), else the
!>   period of the spectrum's peak of `series` over the analysis window;
!> - the section `section`: 'stick_to_slip', the located starts of slip
!>   (a set-valued law's events), or 'w_zero_up', the sliding velocity
!>   w = v - belt_velocity crossing 0 upwards between output points.
!>
!> The points hold x, v and the law's first state, as /machine does.
module friction_machine_section
   use friction_kinds, only: wp
   use friction_error, only: error_type, fatal_error, error_input
   use friction_output_h5, only: h5_file
   use friction_analysis_spectrum, only: spectrum_settings, spectrum_result, amplitude_spectrum
   use friction_analysis_poincare, only: stroboscopic_map, upward_section
   use friction_machine_config, only: machine_config
   use friction_machine_run, only: machine_run, event_stick_to_slip
   implicit none
   private

   public :: machine_poincare, machine_sections, write_machine_poincare

   type :: machine_poincare
      real(wp) :: strobe_period = 0.0_wp           !! s, the one used
      character(len=16) :: period_source = ''      !! 'strobe_period', 'support' or 'spectrum'
      real(wp), allocatable :: strobe_t(:), strobe_points(:, :)    !! (variables, n)
      real(wp), allocatable :: section_t(:), section_points(:, :)
   end type machine_poincare

contains

   !> The strobe and the section of run (settings c checked).
   subroutine machine_sections(c, run, p, error)
      type(machine_config), intent(in) :: c
      type(machine_run), intent(in) :: run
      type(machine_poincare), intent(out) :: p
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: states(:, :)
      real(wp) :: t_end
      integer :: nv
      logical, allocatable :: onset(:)

      nv = merge(3, 2, run%n_states > 0)
      allocate (states(nv, run%n))
      states(1, :) = run%x
      states(2, :) = run%v
      if (nv == 3) states(3, :) = run%states(1, :)
      associate (a => c%analysis)
         p%strobe_period = a%strobe_period
         p%period_source = 'strobe_period'
         if (p%strobe_period == 0.0_wp .and. c%support_amplitude > 0.0_wp .and. c%support_frequency > 0.0_wp) then
            p%strobe_period = 1.0_wp / c%support_frequency
            p%period_source = 'support'
         else if (p%strobe_period == 0.0_wp) then
            call peak_period(error)
            if (allocated(error)) return
            p%period_source = 'spectrum'
         end if
         t_end = a%strobe_end
         if (t_end == 0.0_wp) t_end = c%t_end
         call stroboscopic_map(run%t, states, a%strobe_start, t_end, p%strobe_period, p%strobe_t, p%strobe_points, &
            & error)
         if (allocated(error)) return
         select case (trim(a%section))
         case ('stick_to_slip')
            ! Located by the event machinery to event_tolerance (set-valued laws: no law state).
            onset = run%event_kind(1:run%n_events) == event_stick_to_slip .and. &
               & run%event_t(1:run%n_events) >= a%strobe_start .and. run%event_t(1:run%n_events) <= t_end
            p%section_t = pack(run%event_t(1:run%n_events), onset)
            allocate (p%section_points(nv, size(p%section_t)))
            p%section_points = 0.0_wp
            p%section_points(1, :) = pack(run%event_x(1:run%n_events), onset)
            p%section_points(2, :) = pack(run%event_v(1:run%n_events), onset)
         case ('w_zero_up')
            ! v crossing belt_velocity upwards is w crossing 0.
            call upward_section(run%t, states, 2, c%belt_velocity, a%strobe_start, t_end, p%section_t, &
               & p%section_points)
         case default
            allocate (p%section_t(0), p%section_points(nv, 0))
         end select
      end associate

   contains

      !> 1 / the spectrum's peak frequency of `series` over the window.
      subroutine peak_period(error)
         type(error_type), allocatable, intent(out) :: error
         type(spectrum_result) :: peak
         logical :: inside(run%n)

         associate (a => c%analysis)
            inside = run%t >= a%window_start .and. run%t <= a%window_end
            if (count(inside) < 16) then
               call fatal_error(error, '&analysis: fewer than 16 output points in [window_start, window_end] ' &
                  & //'to find the strobe period in; set strobe_period', error_input)
               return
            end if
            if (a%series == 'v') then
               call amplitude_spectrum(pack(run%v, inside), c%dt_out, spectrum_settings(window=a%window, &
                  & segments=a%welch_segments), peak, error)
            else
               call amplitude_spectrum(pack(run%x, inside), c%dt_out, spectrum_settings(window=a%window, &
                  & segments=a%welch_segments), peak, error)
            end if
            if (allocated(error)) return
            if (.not. (peak%peak_frequency > 0.0_wp)) then
               call fatal_error(error, '&analysis: no spectral peak to strobe at; set strobe_period', error_input)
               return
            end if
            p%strobe_period = 1.0_wp / peak%peak_frequency
         end associate
      end subroutine peak_period

   end subroutine machine_sections

   !> /machine/poincare (docs/output.md).
   subroutine write_machine_poincare(file, c, run, p)
      type(h5_file), intent(inout) :: file
      type(machine_config), intent(in) :: c
      type(machine_run), intent(in) :: run
      type(machine_poincare), intent(in) :: p
      character(len=*), parameter :: group = '/machine/poincare'
      character(len=16) :: names(3), units(3)
      integer :: k

      names = [character(len=16) :: 'x', 'v', '']
      units = [character(len=16) :: 'm', 'm/s', '']
      if (run%n_states > 0) then
         names(3) = run%state_names(1)
         units(3) = run%state_units(1)
      end if
      call file%create_group(group)
      call file%write_attribute_real(group, 'strobe_period', p%strobe_period, 's')
      call file%write_attribute_text(group, 'strobe_period_from', trim(p%period_source))
      call file%write_attribute_real(group, 'strobe_start', c%analysis%strobe_start, 's')
      call file%write_attribute_real(group, 'strobe_end', c%analysis%strobe_end, 's')
      call file%write_attribute_text(group, 'section', trim(c%analysis%section))
      call file%write_vector(group//'/strobe_t', p%strobe_t, 's')
      call file%write_vector(group//'/section_t', p%section_t, 's')
      do k = 1, size(p%strobe_points, 1)
         call file%write_vector(group//'/strobe_'//trim(names(k)), p%strobe_points(k, :), trim(units(k)))
         call file%write_vector(group//'/section_'//trim(names(k)), p%section_points(k, :), trim(units(k)))
         call file%attach_scales(group//'/strobe_'//trim(names(k)), [group//'/strobe_t'])
         call file%attach_scales(group//'/section_'//trim(names(k)), [group//'/section_t'])
      end do
   end subroutine write_machine_poincare

end module friction_machine_section
