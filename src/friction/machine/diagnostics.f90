!> The machine's chaos diagnostics (&analysis): the amplitude spectrum of x
!> or v over the analysis window, and the largest Lyapunov exponent from the
!> equations (Benettin) for a law that is one ODE, through the library's
!> scene-independent tools (analysis/).
module friction_machine_diagnostics
   use friction_kinds, only: wp
   use friction_error, only: error_type
   use friction_ode_watch, only: step_watch
   use friction_analysis_spectrum, only: spectrum_settings, spectrum_result, amplitude_spectrum
   use friction_analysis_lyapunov_flow, only: benettin_settings, benettin_accumulator, benettin_exponent
   use friction_law, only: sliding_law, max_law_states
   use friction_law_factory, only: make_law
   use friction_output_law_files, only: law_with_files
   use friction_machine_config, only: machine_config
   use friction_machine_model, only: machine_smooth
   use friction_machine_run, only: machine_run, machine_watch
   implicit none
   private

   public :: machine_diagnostics, diagnose_machine

   type :: machine_diagnostics
      logical :: spectrum = .false., lyapunov = .false.
      type(spectrum_result) :: peak
      type(benettin_accumulator) :: flow
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
      end associate

   contains

      !> The run's ODE from its start: the transient, then Benettin's pair.
      subroutine lyapunov(error)
         type(error_type), allocatable, intent(out) :: error
         type(machine_smooth), target :: system
         class(sliding_law), allocatable :: law
         type(benettin_settings) :: b
         real(wp) :: y(2 + max_law_states), z(max_law_states)
         integer :: ns

         call make_law(law_with_files(c%law), law, error)
         if (allocated(error)) return
         ns = law%state_count()
         call system%m%from_config(c)
         allocate (system%law, source=law)
         system%n_states = ns
         if (ns > 0) call law%state_scale(system%scale(1:ns))
         z = 0.0_wp
         if (ns > 0 .and. c%steady_start) call law%steady_state(c%v0 - c%belt_velocity, c%normal, z(1:ns))
         y(1:2) = [c%x0, c%v0]
         y(3:2 + ns) = z(1:ns) / system%scale(1:ns)
         b%transient = c%analysis%lyapunov_transient
         b%duration = c%analysis%lyapunov_duration
         if (b%duration == 0.0_wp) b%duration = c%t_end - c%t_start - b%transient
         b%renormalise = c%analysis%lyapunov_renormalise
         b%d0 = c%analysis%lyapunov_d0
         if (present(watch)) then
            call benettin_exponent(system, c%solver, y(1:2 + ns), c%t_start, b, d%flow, error, watch)
         else
            block
               class(step_watch), allocatable :: own
               allocate (own, source=machine_watch(c, "&analysis: the Lyapunov exponent (Benettin)"))
               call benettin_exponent(system, c%solver, y(1:2 + ns), c%t_start, b, d%flow, error, own)
            end block
         end if
      end subroutine lyapunov

   end subroutine diagnose_machine

end module friction_machine_diagnostics
