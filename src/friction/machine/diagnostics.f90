!> The machine's chaos diagnostics (&analysis): the amplitude spectrum of x
!> or v over the analysis window, the largest Lyapunov exponent from the
!> equations (Benettin; through exact stick for a set-valued law) and from the
!> series (Rosenstein), the Poincaré maps
!> (section.f90) and the whole Lyapunov spectrum (lyapunov.f90), through the
!> library's scene-independent tools (analysis/).
module friction_machine_diagnostics
   use friction_kinds, only: wp
   use friction_error, only: error_type
   use friction_ode_watch, only: step_watch
   use friction_analysis_spectrum, only: spectrum_settings, spectrum_result, amplitude_spectrum
   use friction_analysis_lyapunov_flow, only: benettin_settings, benettin_accumulator, benettin_exponent
   use friction_analysis_lyapunov_series, only: rosenstein_result
   use friction_law, only: sliding_law
   use friction_law_factory, only: make_law
   use friction_output_law_files, only: law_with_files
   use friction_machine_config, only: machine_config
   use friction_machine_model, only: machine_smooth
   use friction_machine_run, only: machine_run, machine_watch
   use friction_machine_section, only: machine_poincare, machine_sections
   use friction_machine_lyapunov, only: machine_spectrum, machine_lyapunov_spectrum, smooth_start, piecewise_benettin, &
      & has_band
   use friction_analysis_periodic_orbit, only: orbit_settings
   use friction_machine_orbit, only: machine_orbit, machine_branch, machine_periodic_orbit, follow_machine_branch
   implicit none
   private

   public :: machine_diagnostics, diagnose_machine

   type :: machine_diagnostics
      logical :: spectrum = .false., lyapunov = .false.
      type(spectrum_result) :: peak
      logical :: rosenstein = .false.      !! &analysis rosenstein: the exponent from the series
      type(rosenstein_result) :: series
      real(wp) :: series_dt = 0.0_wp      !! the strided series' sample spacing (s)
      type(benettin_accumulator) :: flow
      logical :: poincare = .false., lyapunov_spectrum = .false.
      type(machine_poincare) :: sections
      type(machine_spectrum) :: qr
      logical :: orbit = .false.           !! &analysis orbit: the periodic orbit ...
      type(machine_orbit) :: periodic
      logical :: continued = .false.       !! ... and its continuation
      type(machine_branch) :: branch
   end type machine_diagnostics

contains

   !> `watch` (by default max_wall_time alone, from now) is asked inside
   !> Benettin's integrations and after each of its intervals.
   subroutine diagnose_machine(c, run, d, error, watch)
      type(machine_config), intent(in) :: c
      type(machine_run), intent(in) :: run
      type(machine_diagnostics), intent(out) :: d
      type(error_type), allocatable, intent(out) :: error
      class(step_watch), intent(inout), optional :: watch

      associate (a => c%analysis)
         d%spectrum = a%spectrum
         d%lyapunov = a%lyapunov
         if (a%spectrum) then
            block
               type(spectrum_settings) :: s
               logical :: inside(run%n)

               s%window = a%window
               s%segments = a%welch_segments
               inside = run%t >= a%window_start .and. run%t <= a%window_end
               if (a%series == 'v') then
                  call amplitude_spectrum(pack(run%v, inside), c%dt_out, s, d%peak, error)
               else
                  call amplitude_spectrum(pack(run%x, inside), c%dt_out, s, d%peak, error)
               end if
               if (allocated(error)) return
            end block
         end if
         if (a%lyapunov) call lyapunov(error)
         if (allocated(error)) return
         d%rosenstein = a%rosenstein
         if (a%rosenstein) then
            block
               logical :: inside(run%n)
               real(wp), allocatable :: window_series(:)

               inside = run%t >= a%window_start .and. run%t <= a%window_end
               if (a%series == 'v') then
                  window_series = pack(run%v, inside)
               else
                  window_series = pack(run%x, inside)
               end if
               call a%rosenstein_of(window_series, c%dt_out, d%series, d%series_dt, error)
               if (allocated(error)) return
            end block
         end if
         d%poincare = a%poincare
         d%lyapunov_spectrum = a%lyapunov_spectrum
         if (a%poincare) call machine_sections(c, run, d%sections, error)
         if (allocated(error)) return
         if (a%lyapunov_spectrum) then
            if (present(watch)) then
               call machine_lyapunov_spectrum(c, d%qr, error, watch)
            else
               block
                  class(step_watch), allocatable :: own
                  allocate (own, source=machine_watch(c, '&analysis: the Lyapunov spectrum'))
                  call machine_lyapunov_spectrum(c, d%qr, error, own)
               end block
            end if
         end if
         if (allocated(error)) return
         if (a%orbit) call periodic_orbit(error)
      end associate

   contains

      !> The run's ODE from its start: the transient, then Benettin's pair.
      subroutine lyapunov(error)
         type(error_type), allocatable, intent(out) :: error
         type(machine_smooth), target :: system
         class(sliding_law), allocatable :: law
         type(benettin_settings) :: b
         real(wp), allocatable :: y(:)

         call make_law(law_with_files(c%law), law, error)
         if (allocated(error)) return
         b%transient = c%analysis%lyapunov_transient
         b%duration = c%analysis%lyapunov_duration
         if (b%duration == 0.0_wp) b%duration = c%t_end - c%t_start - b%transient
         b%renormalise = c%analysis%lyapunov_renormalise
         b%d0 = c%analysis%lyapunov_d0
         if (law%set_valued() .or. has_band(law)) then
            ! Two runs through exact stick and slip, or through the band's switches (lyapunov.f90).
            if (present(watch)) then
               call piecewise_benettin(c, law, b, d%flow, error, watch)
            else
               block
                  class(step_watch), allocatable :: own
                  allocate (own, source=machine_watch(c, "&analysis: the Lyapunov exponent (Benettin)"))
                  call piecewise_benettin(c, law, b, d%flow, error, own)
               end block
            end if
            return
         end if
         call smooth_start(c, law, system, y)
         if (present(watch)) then
            call benettin_exponent(system, c%solver, y, c%t_start, b, d%flow, error, watch)
         else
            block
               class(step_watch), allocatable :: own
               allocate (own, source=machine_watch(c, "&analysis: the Lyapunov exponent (Benettin)"))
               call benettin_exponent(system, c%solver, y, c%t_start, b, d%flow, error, own)
            end block
         end if
      end subroutine lyapunov

      !> Newton from the run's section point after orbit_transient, and its branch.
      subroutine periodic_orbit(error)
         type(error_type), allocatable, intent(out) :: error
         type(orbit_settings) :: s

         s%tolerance = c%analysis%orbit_tolerance
         s%max_iterations = c%analysis%orbit_max_iterations
         d%orbit = .true.
         call machine_periodic_orbit(c, run, c%analysis%orbit_transient, s, d%periodic, error, watch)
         if (allocated(error) .or. len_trim(c%analysis%continuation) == 0) return
         d%continued = .true.
         call follow_machine_branch(c, d%periodic, c%analysis%continuation_end, c%analysis%continuation_points, &
            & c%analysis%orbit_transient, s, d%branch, error, watch)
      end subroutine periodic_orbit

   end subroutine diagnose_machine

end module friction_machine_diagnostics
