!> Settings of the machine scene (docs/laws.md, "Mechanisms"): the groups
!> &machine, &law and &integrator.  One degree of freedom: a block of mass m
!> on a surface moving at belt_velocity, tied by a spring k and a dashpot c
!> to a support at u(t) = load_velocity t + support_amplitude sin(2π
!> support_frequency t), pressed on by the normal load:
!>
!>   m x'' = -k (x - u) - c (x' - u') - F(x' - belt_velocity, z),
!>
!> F the &law's friction force at the sliding velocity.  The belt oscillator
!> of Popp and Stelter and of the LuGre paper is load_velocity = 0; the
!> spring-slider of rate and state is belt_velocity = 0 with the load point
!> at load_velocity.
module friction_machine_config
   use friction_kinds, only: wp, i8
   use friction_strings, only: rtoa, quoted
   use friction_parameters, only: configurable, parameter_visitor, set_parameter_number
   use friction_checks, only: config_checker
   use friction_ode_solver, only: solver_settings
   use friction_ode_settings, only: visit_integrator, check_integrator
   use friction_ode_auto, only: auto_name
   use friction_law_settings, only: law_settings
   use friction_law_factory, only: check_law, new_law
   use friction_output_law_files, only: law_with_files
   use friction_law, only: sliding_law
   use friction_analysis_settings, only: analysis_settings
   implicit none
   private

   public :: machine_config, machine_solver_defaults, orbit_variables

   !> Rodas4 at tight tolerances: the laws with states are stiff (LuGre's
   !> contact period is 20 ms against seconds of stick-slip).
   type(solver_settings), parameter :: machine_solver_defaults = solver_settings(method='rodas4', &
      & rtol=1.0e-9_wp, atol=1.0e-12_wp, h_start=0.0_wp, h_min=0.0_wp, max_steps=100000000_i8, max_wall_time=0.0_wp)

   !> The analysis in the machine's own run: its default run is 100 s (the brake's
   !> window and transients, 100 τ and beyond, would leave it nothing), so the window
   !> and the transients default to its second half.
   type(analysis_settings), parameter :: machine_analysis_defaults = analysis_settings(window_start=50.0_wp, &
      & window_end=100.0_wp, lyapunov_transient=50.0_wp, lyapunov_spectrum_transient=50.0_wp, orbit_transient=50.0_wp)

   type, extends(configurable) :: machine_config
      real(wp) :: mass = 1.0_wp              !! m, kg
      real(wp) :: stiffness = 2.0_wp         !! k, N/m
      real(wp) :: damping = 0.0_wp           !! c, N s/m
      real(wp) :: normal = 1.0_wp            !! normal load N, N
      real(wp) :: belt_velocity = 0.1_wp     !! the surface's velocity, m/s
      real(wp) :: load_velocity = 0.0_wp     !! the support's (load point's) velocity, m/s
      real(wp) :: support_amplitude = 0.0_wp !! m
      real(wp) :: support_frequency = 0.0_wp !! Hz
      real(wp) :: x0 = 0.0_wp                !! initial displacement, m
      real(wp) :: v0 = 0.1_wp                !! initial velocity, m/s
      logical :: steady_start = .true.       !! the law's states start in steady sliding at v0 - belt_velocity
      real(wp) :: t_start = 0.0_wp           !! s
      real(wp) :: t_end = 100.0_wp           !! s
      real(wp) :: dt_out = 0.01_wp           !! s
      real(wp) :: event_tolerance = 1.0e-10_wp   !! s: the stick/slip events' times
      real(wp) :: stick_velocity = 1.0e-6_wp !! m/s: |v - belt_velocity| below this counts as stick (smooth laws)
      !> smooth laws: free steps and the output grid from the stepper's continuous extension (rodas4)
      logical :: dense_output = .true.
      type(law_settings) :: law
      type(solver_settings) :: solver = machine_solver_defaults
      type(analysis_settings) :: analysis = machine_analysis_defaults  !! &analysis: the spectrum and the Lyapunov exponent
   contains
      procedure :: visit
      procedure :: validate
      procedure :: grid_size
      procedure :: grid_time
      procedure :: first_step
   end type machine_config

   !> The &machine variables a periodic orbit can be continued in (&analysis continuation).
   character(len=*), parameter :: orbit_variables(8) = [character(len=17) :: 'belt_velocity', 'stiffness', &
      & 'damping', 'normal', 'mass', 'load_velocity', 'support_amplitude', 'support_frequency']

contains

   subroutine visit(self, v)
      class(machine_config), intent(inout) :: self
      type(parameter_visitor), intent(inout) :: v

      call visit_integrator(self%solver, v, 's')
      call v%begin_group('machine')
      call v%item('mass', self%mass, 'kg')
      call v%item('stiffness', self%stiffness, 'N/m')
      call v%item('damping', self%damping, 'N s/m')
      call v%item('normal', self%normal, 'N')
      call v%item('belt_velocity', self%belt_velocity, 'm/s')
      call v%item('load_velocity', self%load_velocity, 'm/s')
      call v%item('support_amplitude', self%support_amplitude, 'm')
      call v%item('support_frequency', self%support_frequency, 'Hz')
      call v%item('x0', self%x0, 'm')
      call v%item('v0', self%v0, 'm/s')
      call v%item('steady_start', self%steady_start)
      call v%item('t_start', self%t_start, 's')
      call v%item('t_end', self%t_end, 's')
      call v%item('dt_out', self%dt_out, 's')
      call v%item('event_tolerance', self%event_tolerance, 's')
      call v%item('stick_velocity', self%stick_velocity, 'm/s')
      call v%item('dense_output', self%dense_output)
      call v%end_group()
      call self%law%visit(v)
      call self%analysis%visit(v, 's')
   end subroutine visit

   subroutine validate(self, c)
      class(machine_config), intent(in) :: self
      type(config_checker), intent(inout) :: c

      call check_integrator(self%solver, c)
      ! 'auto' passes the common check (it is the AFM's and the brake's), but the machine has no choice table.
      if (trim(self%solver%method) == auto_name) call c%reject('integrator', 'method', "'"//auto_name//"'", &
         & "the machine scene has no automatic choice of stepper: leave method unset for its default 'rodas4' " &
         & //'(every law runs with it), or name a stepper')
      call c%positive('machine', 'mass', self%mass, 'kg')
      call c%finite('machine', 'mass', self%mass)
      call c%nonnegative('machine', 'stiffness', self%stiffness, 'N/m')
      call c%finite('machine', 'stiffness', self%stiffness)
      call c%nonnegative('machine', 'damping', self%damping, 'N s/m')
      call c%finite('machine', 'damping', self%damping)
      call c%nonnegative('machine', 'normal', self%normal, 'N')
      call c%finite('machine', 'normal', self%normal)
      call c%finite('machine', 'belt_velocity', self%belt_velocity)
      call c%finite('machine', 'load_velocity', self%load_velocity)
      call c%nonnegative('machine', 'support_amplitude', self%support_amplitude, 'm')
      call c%finite('machine', 'support_amplitude', self%support_amplitude)
      call c%nonnegative('machine', 'support_frequency', self%support_frequency, 'Hz')
      call c%finite('machine', 'support_frequency', self%support_frequency)
      call c%finite('machine', 'x0', self%x0)
      call c%finite('machine', 'v0', self%v0)
      call c%finite('machine', 't_start', self%t_start)
      call c%finite('machine', 't_end', self%t_end)
      if (.not. (self%t_end > self%t_start)) call c%reject('machine', 't_end', rtoa(self%t_end), &
         & 'must be after t_start = '//rtoa(self%t_start), against=['machine.t_start'])
      call c%positive('machine', 'dt_out', self%dt_out, 's')
      call c%positive('machine', 'event_tolerance', self%event_tolerance, 's')
      call c%positive('machine', 'stick_velocity', self%stick_velocity, 'm/s')
      if (c%failed()) return
      if ((self%t_end - self%t_start) / self%dt_out > 1.0e7_wp) call c%reject('machine', 'dt_out', &
         & rtoa(self%dt_out), 'gives more than 1e7 output points over [t_start, t_end]', &
         & against=[character(len=16) :: 'machine.t_end', 'machine.t_start'])
      call check_law(law_with_files(self%law), c)
      if (c%failed()) return
      call check_band_stepper(self, c)
      if (c%failed()) return
      call self%analysis%validate(c, self%t_start, self%t_end, ['x', 'v'], self%dt_out, &
         & strobe_known=self%support_amplitude > 0.0_wp .and. self%support_frequency > 0.0_wp, series_points=8, &
         & run_group='machine')
      if (c%failed()) return
      ! Every diagnostic of &analysis runs on the machine; what a law cannot give is refused by name.
      associate (a => self%analysis)
         if (a%orbit) call check_orbit(self, c)
         if (a%poincare) call check_sections(self, c)
      end associate
   end subroutine validate

   !> A band law's force jumps at the band's edges, located only after a step
   !> has crossed one: GSL's multistep steppers reject step after step on the
   !> way in, their history spanning the jump, crawl, and miss their tolerance
   !> (docs/speed.md, "Multistep steppers and Karnopp's band").
   subroutine check_band_stepper(self, c)
      class(machine_config), intent(in) :: self
      type(config_checker), intent(inout) :: c
      class(sliding_law), allocatable :: law
      real(wp) :: width, limit

      if (self%solver%method /= 'msadams' .and. self%solver%method /= 'msbdf') return
      call new_law(self%law, law)
      call law%band(width, limit)
      if (width > 0.0_wp) call c%reject('integrator', 'method', "'"//trim(self%solver%method)//"'", &
         & "a multistep stepper on &law model = '"//trim(self%law%model)//"': the force jumps at the " &
         & //'band''s edges, and every step that crosses one on the way into a hold is rejected with the ' &
         & //'history spanning the jump (200 times rk8pd''s steps at rtol 1e-6, its events 1e-2 s off; at ' &
         & //'rtol 1e-9 not done in 30 s of CPU): use a one-step method such as rodas4 or rk8pd')
   end subroutine check_band_stepper

   !> What the machine's Poincaré maps need of the law: the located slip
   !> onsets exist for a set-valued law and a band law (the ends of its holds) only.  (The Lyapunov spectrum needs
   !> nothing: the tangent equations take any number of states.)
   subroutine check_sections(self, c)
      class(machine_config), intent(in) :: self
      type(config_checker), intent(inout) :: c
      class(sliding_law), allocatable :: law

      real(wp) :: width, limit

      call new_law(self%law, law)
      call law%band(width, limit)
      associate (a => self%analysis)
         if (a%poincare .and. trim(a%section) == 'stick_to_slip' .and. .not. law%set_valued() .and. &
            & .not. width > 0.0_wp) &
            & call c%reject('analysis', 'section', "'stick_to_slip'", "the located slip onsets are the events of " &
            & //"exact stick; &law model = '"//trim(self%law%model)//"' has none: use section = 'w_zero_up' " &
            & //"(the sliding velocity crossing 0 upwards) or 'none'", &
            & against=[character(len=17) :: 'law.model', 'analysis.poincare'])
      end associate
   end subroutine check_sections

   !> &analysis orbit (and continuation): any law, with any number of states
   !> (the section's multipliers beyond 3 x 3 are LAPACK's); the line's end a
   !> valid machine of the same kind (forced or not).
   subroutine check_orbit(self, c)
      type(machine_config), intent(in) :: self
      type(config_checker), intent(inout) :: c
      logical :: forced

      forced = self%support_amplitude > 0.0_wp .and. self%support_frequency > 0.0_wp
      if (len_trim(self%analysis%continuation) == 0) return
      if (.not. any(orbit_variables == self%analysis%continuation)) then
         call c%reject('analysis', 'continuation', "'"//trim(self%analysis%continuation)//"'", &
            & 'not a variable of &machine the orbit can follow (known: '//quoted(orbit_variables)//')')
         return
      end if
      block
         type(machine_config) :: end_point
         type(config_checker) :: inner
         character(len=:), allocatable :: problem
         end_point = self
         end_point%analysis%continuation = ''
         call set_parameter_number(end_point, 'machine', trim(self%analysis%continuation), &
            & self%analysis%continuation_end, problem)
         call end_point%validate(inner)
         if (inner%failed()) then
            associate (message => inner%error%message, origin => index(inner%error%message, '(default): '))
               call c%reject('analysis', 'continuation_end', rtoa(self%analysis%continuation_end), &
                  & 'the end of the line is not a valid machine: '//message(merge(origin + 11, 1, origin == 1):), &
                  & against=['analysis.continuation'])
            end associate
         else if ((end_point%support_amplitude > 0.0_wp .and. end_point%support_frequency > 0.0_wp) .neqv. forced) then
            call c%reject('analysis', 'continuation_end', rtoa(self%analysis%continuation_end), 'the line must ' &
               & //'keep the support moving (support_amplitude and support_frequency > 0) or keep it still at ' &
               & //'both ends: the section changes between them', against=['analysis.continuation'])
         end if
      end block
   end subroutine check_orbit

   pure integer function grid_size(self)
      class(machine_config), intent(in) :: self

      grid_size = int((self%t_end - self%t_start) / self%dt_out * (1.0_wp + 1.0e-9_wp) + 1.0e-9_wp) + 1
   end function grid_size

   pure real(wp) function grid_time(self, i)
      class(machine_config), intent(in) :: self
      integer, intent(in) :: i

      grid_time = self%t_start + real(i - 1, wp) * self%dt_out
   end function grid_time

   !> The integrators' first step: &integrator h_start, else 1e-6 dt_out.
   pure real(wp) function first_step(self)
      class(machine_config), intent(in) :: self

      first_step = self%solver%h_start
      if (.not. (first_step > 0.0_wp)) first_step = 1.0e-6_wp * self%dt_out
   end function first_step

end module friction_machine_config
