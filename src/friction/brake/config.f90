!> Settings of the brake scene as the namelist gives them (docs/input.md, groups &brake, &brake_dimensional, &verify, &integrator), and
!> the parameters of Eq. 10 they resolve to.
module friction_brake_config
   use friction_kinds, only: wp, i8
   use friction_error, only: error_type
   use friction_ode_solver, only: solver_settings
   use friction_brake_params, only: brake_parameters, brake_dimensional, derive_parameters
   use friction_analysis_settings, only: analysis_settings
   use friction_strings, only: rtoa, itoa, quoted, bytes_text
   use friction_parameters, only: configurable, parameter_visitor, parameter_info, set_parameter_number, &
      & get_parameter, list_parameters
   use friction_checks, only: config_checker
   use friction_ode_settings, only: visit_integrator, check_integrator, verify_settings, visit_verify, check_verify, &
      & verify_solver
   use friction_law_settings, only: law_settings, law_group
   use friction_law_factory, only: check_law, new_law, make_law
   use friction_output_law_files, only: law_with_files
   use friction_law, only: sliding_law
   implicit none
   private

   public :: brake_config, model_names, units_names, brake_solver_defaults
   public :: model_regularized, model_switched, model_law, series_names, continuation_names, continuation_config, &
      & continuation_variable, rodas4_transition_bound, transition_bound, law_continuation_names, &
      & brake_law_continuation_names

   character(len=*), parameter :: model_names(3) = [character(len=11) :: 'switched', 'regularized', 'law']
   character(len=*), parameter :: units_names(2) = [character(len=14) :: 'nondimensional', 'dimensional']
   character(len=*), parameter :: model_switched = 'switched', model_regularized = 'regularized', model_law = 'law'
   !> The regularized law's transition in units of its width that a stepper's
   !> velocity tolerance may span and stay within 100 times the asked tolerance
   !> (transition_tolerance; docs/speed.md, "The regularized law's steppers"):
   !> rodas4 up to rodas4_transition_bound, rodas3, rkf45 and rkck up to transition_bound.
   real(wp), parameter :: rodas4_transition_bound = 3.0_wp
   real(wp), parameter :: transition_bound = 10.0_wp
   character(len=*), parameter :: series_names(4) = [character(len=1) :: 'x', 'v', 'y', 'w']
   !> The &brake variables a periodic orbit can be continued in (&analysis continuation).
   character(len=*), parameter :: continuation_names(7) = [character(len=11) :: 'mu', 'mu_s', 'xi', 'kappa', &
      & 'g_prime', 'delta_prime', 'v_dr_prime']
   !> With model = 'law' the friction is &law's: the orbit follows the &brake
   !> variables of the mechanism, or a real parameter of &law's laws (a name
   !> both groups have, mu or mu_s, is &law's: &brake's is unused then).
   character(len=*), parameter :: brake_law_continuation_names(4) = [character(len=10) :: 'xi', 'kappa', &
      & 'g_prime', 'v_dr_prime']
   character(len=*), parameter :: law_continuation_names(21) = [character(len=10) :: 'mu', 'mu_s', 'epsilon', &
      & 'delta', 'fc', 'fs', 'vs', 'exponent', 'sigma2', 'scale', 'dv', 'sigma0', 'sigma1', 'alpha', 'z_ba', &
      & 'mu0', 'a', 'b', 'dc', 'v0', 'attraction']

   !> &integrator defaults for the brake when no file sets them: rk8pd, tight
   !> (the benchmark: the switched model reaches 1e-8 on x this way); times in τ.
   type(solver_settings), parameter :: brake_solver_defaults = solver_settings(method='rk8pd', &
      & rtol=1.0e-10_wp, atol=1.0e-12_wp, h_start=0.0_wp, h_min=0.0_wp, max_steps=10000000_i8, &
      & max_wall_time=0.0_wp)

   type, extends(configurable) :: brake_config
      character(len=16) :: model = model_switched      !! 'switched' (Fig. 10), 'regularized' (Eq. 10) or 'law' (&law)
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
      type(verify_settings) :: verify   !! &verify: the difference compared is x's
      type(analysis_settings) :: analysis   !! chaos diagnostics (&analysis)
      type(law_settings) :: law             !! &law: the friction law of model = 'law'
   contains
      procedure :: visit
      procedure :: uses_law
      procedure :: law_units
      procedure :: validate
      procedure :: resolve
      procedure :: switched
      procedure :: auto_method
      procedure :: grid_size
      procedure :: grid_time
      procedure :: check_settings
      procedure :: creep_band_warning
      procedure :: velocity_tolerance
      procedure :: transition_tolerance
      procedure :: stepper_warning
   end type brake_config

contains

   !> The groups &integrator, &brake, &brake_dimensional, &verify and
   !> &analysis (docs/input.md).
   subroutine visit(self, v)
      class(brake_config), intent(inout) :: self
      type(parameter_visitor), intent(inout) :: v

      call visit_integrator(self%solver, v, 'tau')
      call v%begin_group('brake')
      call v%item('model', self%model, fold=.true.)
      call v%item('units', self%units, fold=.true.)
      associate (p => self%params)
         call v%item('xi', p%xi, '1')
         call v%item('kappa', p%kappa, '1')
         call v%item('g_prime', p%g_prime, 'm')
         call v%item('mu', p%mu, '1')
         call v%item('mu_s', p%mu_s, '1')
         call v%item('epsilon_prime', p%epsilon_prime, 'tau/m')
         call v%item('delta_prime', p%delta_prime, 'tau/m')
         call v%item('v_dr_prime', p%v_dr, 'm/tau')
      end associate
      call v%item('x0', self%x0, 'm')
      call v%item('y0', self%y0, 'm')
      call v%item('v_rel0', self%v_rel0, 'm/tau')
      call v%item('w0', self%w0, 'm/tau')
      call v%item('t_start', self%t_start, 'tau')
      call v%item('t_end', self%t_end, 'tau')
      call v%item('dt_out', self%dt_out, 'tau')
      call v%item('event_tolerance', self%event_tolerance, 'tau')
      call v%item('stick_velocity', self%stick_velocity, 'm/tau')
      call v%end_group()
      call v%begin_group('brake_dimensional')
      associate (d => self%dimensional)
         call v%item('arm_length', d%arm_length, 'm')
         call v%item('drum_radius', d%drum_radius, 'm')
         call v%item('crank_mass', d%crank_mass, 'kg')
         call v%item('block_mass', d%block_mass, 'kg')
         call v%item('k1', d%k1, 'N/m')
         call v%item('k2', d%k2, 'N/m')
         call v%item('k3', d%k3, 'N/m')
         call v%item('gravity', d%gravity, 'm/s^2')
         call v%item('epsilon_si', d%epsilon, 's/m')
         call v%item('delta_si', d%delta, 's/m')
         call v%item('v_dr_si', d%v_dr, 'm/s')
      end associate
      call v%end_group()
      call visit_verify(self%verify, v, 'm', 'm')
      call self%analysis%visit(v, 'tau')
      call self%law%visit(v)
   end subroutine visit

   !> Whether the friction is the &law group's law (model = 'law').
   pure logical function uses_law(self)
      class(brake_config), intent(in) :: self

      uses_law = trim(self%model) == model_law
   end function uses_law

   !> The brake's units in the law's (docs/laws.md, "The brake with any
   !> law"): a force of the brake's (over k1, in m) is `force` N, a velocity
   !> (m per unit τ) `velocity` m/s, a unit τ `time` s.  With units =
   !> 'dimensional' the law's parameters are SI (k1, 1/√(m/k1), √(m/k1));
   !> else the law works in the brake's own units (all three 1, exactly).
   !> Resolved settings.
   pure subroutine law_units(self, force, velocity, time)
      class(brake_config), intent(in) :: self
      real(wp), intent(out) :: force, velocity, time

      force = 1.0_wp
      velocity = 1.0_wp
      time = 1.0_wp
      if (trim(self%units) /= 'dimensional') return
      time = sqrt(self%dimensional%block_mass / self%dimensional%k1)
      force = self%dimensional%k1
      velocity = 1.0_wp / time
   end subroutine law_units

   !> Every value of the brake's groups, or the first bad one to `c`.
   subroutine validate(self, c)
      class(brake_config), intent(in) :: self
      type(config_checker), intent(inout) :: c
      type(brake_config) :: resolved
      type(error_type), allocatable :: derive_error
      real(wp) :: normal
      logical :: regularized, dimensional

      call check_integrator(self%solver, c)
      if (.not. any(model_names == self%model)) call c%reject('brake', 'model', "'"//trim(self%model)//"'", &
         & 'unknown friction model (known: '//quoted(model_names)//')')
      if (.not. any(units_names == self%units)) call c%reject('brake', 'units', "'"//trim(self%units)//"'", &
         & 'unknown parameter set (known: '//quoted(units_names)//')')
      if (c%failed()) return
      regularized = self%model == 'regularized'
      dimensional = self%units == 'dimensional'
      associate (p => self%params, d => self%dimensional)
         call c%nonnegative('brake', 'mu', p%mu, 'kinetic friction coefficient')
         call c%nonnegative('brake', 'mu_s', p%mu_s, 'static friction coefficient')
         if (self%model == model_switched .and. p%mu > p%mu_s) call c%reject('brake', 'mu', rtoa(p%mu), &
            & 'the switched model needs mu <= mu_s = '//rtoa(p%mu_s)//' (a kinetic coefficient above the ' &
            & //'static one makes every slip stop at once: use the regularized model)', &
            & against=[character(len=16) :: 'brake.mu_s', 'brake.model'])
         if (dimensional) then
            call c%positive('brake_dimensional', 'arm_length', d%arm_length, 'm')
            call c%nonnegative('brake_dimensional', 'drum_radius', d%drum_radius, 'm')
            call c%positive('brake_dimensional', 'crank_mass', d%crank_mass, 'kg')
            call c%positive('brake_dimensional', 'block_mass', d%block_mass, 'kg')
            call c%positive('brake_dimensional', 'k1', d%k1, 'N/m')
            call c%positive('brake_dimensional', 'k2', d%k2, 'N/m')
            call c%nonnegative('brake_dimensional', 'k3', d%k3, 'N/m')
            call c%nonnegative('brake_dimensional', 'gravity', d%gravity, 'm/s²')
            if (regularized) call c%positive('brake_dimensional', 'epsilon_si', d%epsilon, &
               & 's/m; the regularized law needs a steepness')
            call c%nonnegative('brake_dimensional', 'delta_si', d%delta, 's/m')
            call c%finite('brake_dimensional', 'v_dr_si', d%v_dr)
            if (abs(d%k2 - d%k1) > 1.0e-9_wp * d%k1) call c%reject('brake_dimensional', 'k2', rtoa(d%k2), &
               & 'must equal k1 = '//rtoa(d%k1)//': Eq. 10 assumes k2 = k1 (paper §4.1)', &
               & against=['brake_dimensional.k1'])
         else
            call c%positive('brake', 'xi', p%xi, 'J/(m L²)')
            call c%positive('brake', 'kappa', p%kappa, '(k1 + k3)/k1')
            call c%finite('brake', 'g_prime', p%g_prime)
            if (regularized) call c%positive('brake', 'epsilon_prime', p%epsilon_prime, &
               & 'the regularized law needs a steepness')
            call c%nonnegative('brake', 'delta_prime', p%delta_prime, 'velocity weakening')
            call c%finite('brake', 'v_dr_prime', p%v_dr)
         end if
      end associate
      if (c%failed()) return
      resolved = self
      call resolved%resolve(derive_error)
      if (allocated(derive_error)) then
         call c%reject('brake_dimensional', 'k2', rtoa(self%dimensional%k2), derive_error%message)
         return
      end if
      call c%finite('brake', 'x0', self%x0)
      call c%finite('brake', 'y0', self%y0)
      call c%finite('brake', 'v_rel0', self%v_rel0)
      call c%finite('brake', 'w0', self%w0)
      call c%finite('brake', 't_start', self%t_start)
      call c%finite('brake', 't_end', self%t_end)
      if (.not. (self%t_end > self%t_start)) call c%reject('brake', 't_end', rtoa(self%t_end), &
         & 'must be after t_start = '//rtoa(self%t_start), against=['brake.t_start'])
      call c%positive('brake', 'dt_out', self%dt_out, 'output grid step in τ')
      call c%positive('brake', 'event_tolerance', self%event_tolerance, 'τ')
      call c%positive('brake', 'stick_velocity', self%stick_velocity, 'm per unit τ')
      if (c%failed()) return
      if ((self%t_end - self%t_start) / self%dt_out > 1.0e7_wp) call c%reject('brake', 'dt_out', &
         & rtoa(self%dt_out), 'gives more than 1e7 output points over [t_start, t_end] (' &
         & //rtoa((self%t_end - self%t_start) / self%dt_out)//' points would need ' &
         & //bytes_text(44.0_wp * (self%t_end - self%t_start) / self%dt_out)//' of memory for the trajectory alone)', &
         & against=[character(len=16) :: 'brake.t_end', 'brake.t_start'])
      associate (p => resolved%params)
         normal = p%normal_force(self%y0)
         ! A default y0 = 0 gives N' = g_prime: refused against g_prime, or the data it is derived from.
         if (.not. (normal > 0.0_wp)) call c%reject('brake', 'y0', rtoa(self%y0), &
            & "the initial normal force N' = (1 - kappa) y0 + g_prime = "//rtoa(normal) &
            & //' must be > 0 (kappa = '//rtoa(p%kappa)//', g_prime = '//rtoa(p%g_prime)//')', &
            & against=merge([character(len=29) :: 'brake_dimensional.gravity', 'brake_dimensional.block_mass', &
            & 'brake_dimensional.crank_mass', 'brake_dimensional.k1'], [character(len=29) :: 'brake.g_prime', '', &
            & '', ''], dimensional))
      end associate
      call check_verify(self%verify, c, 'm')
      call self%analysis%validate(c, self%t_start, self%t_end, series_names, self%dt_out, run_group='brake')
      if (c%failed()) return
      call check_law_choice(self, c)
      if (c%failed() .or. len_trim(self%analysis%continuation) == 0) return
      if (self%model == model_regularized) then
         call c%reject('analysis', 'continuation', "'"//trim(self%analysis%continuation)//"'", &
            & "follows the periodic orbit, which the regularized model does not compute: needs model = " &
            & //"'switched' or 'law'")
         return
      end if
      if (self%uses_law()) then
         call check_law_continuation(self, c)
      else if (.not. any(continuation_names == self%analysis%continuation)) then
         call c%reject('analysis', 'continuation', "'"//trim(self%analysis%continuation)//"'", &
            & 'not a variable of &brake the orbit can follow (known: '//quoted(continuation_names)//')')
         return
      end if
      if (c%failed()) return
      if (self%units == 'dimensional' .and. .not. self%uses_law() .and. self%analysis%continuation /= 'mu' .and. &
         & self%analysis%continuation /= 'mu_s') then
         call c%reject('analysis', 'continuation', "'"//trim(self%analysis%continuation)//"'", &
            & "with units = 'dimensional' only 'mu' and 'mu_s' (the others are derived from &brake_dimensional)")
         return
      end if
      ! The other end of the line must be a valid brake too (the line is straight, the checks convex).
      block
         type(brake_config) :: end_point
         type(config_checker) :: inner
         end_point = continuation_config(self, self%analysis%continuation_end)
         call end_point%validate(inner)
         if (inner%failed()) then
            ! The inner checker knows no file: drop its '(default): ' origin.
            associate (message => inner%error%message, origin => index(inner%error%message, '(default): '))
               call c%reject('analysis', 'continuation_end', rtoa(self%analysis%continuation_end), &
                  & 'the end of the line is not a valid brake: '//message(merge(origin + 11, 1, origin == 1):), &
                  & against=['analysis.continuation'])
            end associate
         end if
      end block
   end subroutine validate

   !> &law with model = 'law': the law's own checks, and the tools that need
   !> more than this model gives refused by name.  &law without it: refused
   !> (it would be ignored), at the first variable the input set.
   subroutine check_law_choice(self, c)
      type(brake_config), intent(in) :: self
      type(config_checker), intent(inout) :: c
      class(sliding_law), allocatable :: law
      integer :: k

      if (.not. self%uses_law()) then
         if (.not. allocated(c%origins)) return
         do k = 1, size(c%origins)
            if (c%origins(k)%group /= law_group) cycle
            block
               type(brake_config) :: copy
               character(len=:), allocatable :: text, problem
               copy = self   ! (the visitor takes its object inout)
               call get_parameter(copy, law_group, trim(c%origins(k)%name), 0, text, problem)
               call c%reject(law_group, trim(c%origins(k)%name), text, "is read only with &brake model = 'law' " &
               & //"(here model = '"//trim(self%model)//"', whose friction is &brake's mu, mu_s, epsilon_prime " &
               & //'and delta_prime)')
            end block
            return
         end do
         return
      end if
      call check_law(law_with_files(self%law), c)
      if (c%failed()) return
      call new_law(self%law, law)
      call check_band_stepper(self, law, c)
      if (c%failed()) return
      ! Exact stick holds the closed-form stick phase, whose end needs a static limit affine in N'.
      if (law%set_valued()) then
         block
            real(wp) :: f0, f1, f2
            type(error_type), allocatable :: error
            ! The law ready to compute: a table's static limit is its first row (its file read).
            call make_law(law_with_files(self%law), law, error)
            if (allocated(error)) then
               call c%reject(law_group, 'table_file', "'"//trim(self%law%table_file)//"'", error%message)
               return
            end if
            f0 = law%static_force(0.0_wp)
            f1 = law%static_force(1.0_wp)
            f2 = law%static_force(2.0_wp)
            if (abs(f2 - 2.0_wp * f1 + f0) > 1.0e-12_wp * max(abs(f2), abs(f1), abs(f0), tiny(1.0_wp))) &
               & call c%reject(law_group, 'model', "'"//trim(self%law%model)//"'", 'its static limit is not ' &
               & //"affine in the normal load, which the brake's exact stick needs")
         end block
      end if
   end subroutine check_law_choice

   !> A band law with GSL's multistep steppers: the force jumps at an edge,
   !> located only after a step has crossed it, and they crawl into the holds
   !> (docs/speed.md, "Multistep steppers and Karnopp's band").
   subroutine check_band_stepper(self, law, c)
      type(brake_config), intent(in) :: self
      class(sliding_law), intent(in) :: law
      type(config_checker), intent(inout) :: c
      real(wp) :: width, limit

      if (self%solver%method /= 'msadams' .and. self%solver%method /= 'msbdf') return
      call law%band(width, limit)
      if (width > 0.0_wp) call c%reject('integrator', 'method', "'"//trim(self%solver%method)//"'", &
         & "a multistep stepper on &law model = '"//trim(self%law%model)//"': the force jumps at the " &
         & //'band''s edges, and every step that crosses one on the way into a hold is rejected with the ' &
         & //'history spanning the jump (58 times rk8pd''s steps at rtol 1e-6, its events 6e-2 tau off; at ' &
         & //'rtol 1e-10 10 million steps by tau = 58): use a one-step method such as rk8pd')
   end subroutine check_band_stepper

   !> The configuration with the continuation variable set to `value` (and no
   !> continuation of its own).
   function continuation_config(self, value) result(point)
      type(brake_config), intent(in) :: self
      real(wp), intent(in) :: value
      type(brake_config) :: point
      character(len=:), allocatable :: problem

      point = self
      point%analysis%continuation = ''
      call set_parameter_number(point, continuation_group(self), trim(self%analysis%continuation), value, problem)
   end function continuation_config

   !> The group of the continuation variable: &law's for a law parameter
   !> with model = 'law', else &brake.
   pure function continuation_group(self) result(group)
      type(brake_config), intent(in) :: self
      character(len=:), allocatable :: group

      group = 'brake'
      if (self%uses_law() .and. any(law_continuation_names == self%analysis%continuation)) group = law_group
   end function continuation_group

   !> The continuation variable of the brake with a law: a &brake variable of
   !> the mechanism (not with units = 'dimensional', which derives them) or
   !> a parameter of &law.
   subroutine check_law_continuation(self, c)
      type(brake_config), intent(in) :: self
      type(config_checker), intent(inout) :: c

      associate (name => self%analysis%continuation)
         if (any(law_continuation_names == name)) return
         if (.not. any(brake_law_continuation_names == name)) then
            call c%reject('analysis', 'continuation', "'"//trim(name)//"'", "not a variable the orbit of " &
               & //"&brake model = 'law' can follow (known: &brake's "//quoted(brake_law_continuation_names) &
               & //" and &law's "//quoted(law_continuation_names)//')')
         else if (self%units == 'dimensional') then
            call c%reject('analysis', 'continuation', "'"//trim(name)//"'", "with units = 'dimensional' only " &
               & //"&law's parameters (the &brake variables are derived from &brake_dimensional)")
         end if
      end associate
   end subroutine check_law_continuation

   !> The continuation variable's value in self and its unit, through the
   !> same description of the variables that continuation_config sets by.
   subroutine continuation_variable(self, value, unit)
      type(brake_config), intent(in) :: self
      real(wp), intent(out) :: value
      character(len=:), allocatable, intent(out) :: unit
      type(brake_config) :: copy
      type(parameter_info), allocatable :: list(:)
      character(len=:), allocatable :: text, problem
      integer :: k, stat

      copy = self   ! (the visitor takes its object inout)
      call get_parameter(copy, continuation_group(self), trim(self%analysis%continuation), 0, text, problem)
      read (text, *, iostat=stat) value   ! (round-trip text of a checked variable: it reads)
      list = list_parameters(copy)
      unit = ''
      do k = 1, size(list)
         if (list(k)%group == continuation_group(self) .and. list(k)%name == self%analysis%continuation) &
            & unit = trim(list(k)%unit)
      end do
   end subroutine continuation_variable

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
      other%verify%enabled = .false.
      other%solver = verify_solver(self%verify, self%solver)
      other%event_tolerance = self%event_tolerance / 1000.0_wp
   end function check_settings

   !> Whether the friction law is the exact stick/slip switching (Fig. 10)
   !> rather than the regularized law of Eq. 10.
   pure logical function switched(self)
      class(brake_config), intent(in) :: self

      switched = trim(self%model) == model_switched
   end function switched

   !> The stepper method = 'auto' runs (resolved settings): the switched law
   !> is smooth between its located events, so the high-order rk8pd; the
   !> regularized law is stiff near v_rel = 0, so by tolerance the L-stable
   !> rk4imp, rodas4 where its velocity tolerance resolves the arctan's
   !> transition, else rk8pd (docs/speed.md, "The regularized law's steppers").
   function auto_method(self) result(method)
      class(brake_config), intent(in) :: self
      character(len=16) :: method
      real(wp) :: rtol

      rtol = self%solver%rtol
      method = 'rk8pd'
      if (self%switched()) return
      if (self%uses_law()) then
         ! Set-valued laws switch like the switched model; the others have stiff states (LuGre,
         ! rate and state) or a stiff transition (the arctan law): the L-stable Rosenbrock stepper.
         block
            class(sliding_law), allocatable :: law
            call new_law(self%law, law)
            if (.not. law%set_valued()) method = 'rodas4'
         end block
         return
      end if
      if (rtol >= 1.0e-3_wp) then
         method = 'rk2'
      else if (rtol >= 1.0e-6_wp) then
         method = 'rk4imp'
      else if (rtol >= 1.0e-9_wp .and. .not. self%transition_tolerance() > rodas4_transition_bound) then
         method = 'rodas4'
      end if
   end function auto_method

   !> '' or a warning: the regularized model's creep band is narrower than
   !> the integrator can resolve.  In stick x' = v'_dr, and the step control
   !> holds the velocity to atol + rtol |v'_dr| (GSL's y_new control, which
   !> the Rosenbrock steppers share).  When that is not well inside the
   !> band's half-width stick_velocity, the error of x' alone carries |v_rel|
   !> in and out of the band: /brake/events then holds spurious stick and
   !> slip events, and the stick flags flicker (docs/speed.md).  The bound
   !> is half the band, below which none were seen.
   !> Resolved settings (nondimensional parameters).
   function creep_band_warning(self) result(text)
      class(brake_config), intent(in) :: self
      character(len=:), allocatable :: text
      real(wp) :: tolerance

      text = ''
      if (self%model /= model_regularized) return
      tolerance = self%velocity_tolerance()
      if (tolerance <= 0.5_wp * self%stick_velocity) return
      text = '&integrator: the velocity tolerance in stick, atol + rtol |v_dr_prime| = '//rtoa(tolerance) &
         & //' m/tau, is not below half of &brake stick_velocity = '//rtoa(self%stick_velocity) &
         & //' m/tau: the stepper cannot hold |v_rel| inside the creep band, and /brake/events and the ' &
         & //'stick flags may hold spurious stick and slip events; lower atol and rtol (or raise stick_velocity)'
   end function creep_band_warning

   !> The step control's hold on the velocity in stick, where x' = v_dr_prime:
   !> atol + rtol |v_dr_prime| (m/tau).  Resolved settings.
   pure real(wp) function velocity_tolerance(self)
      class(brake_config), intent(in) :: self

      velocity_tolerance = self%solver%atol + self%solver%rtol * abs(self%params%v_dr)
   end function velocity_tolerance

   !> The velocity tolerance in stick in units of the arctan law's
   !> transition, whose slope changes over |v_rel| of about 1/epsilon_prime:
   !> epsilon_prime (atol + rtol |v_dr_prime|).  Above a few, a step may
   !> cross the transition without the error estimate seeing it
   !> (stepper_warning).  Resolved settings.
   pure real(wp) function transition_tolerance(self)
      class(brake_config), intent(in) :: self

      transition_tolerance = self%params%epsilon_prime * self%velocity_tolerance()
   end function transition_tolerance

   !> '' or a warning: on the regularized law the stepper, at these settings,
   !> falls in a region where it was measured wrong by more than 100 times
   !> the asked tolerance while reporting success (docs/speed.md, "The
   !> regularized law's steppers", gives the measurements behind each case).
   !> Resolved settings.
   function stepper_warning(self) result(text)
      class(brake_config), intent(in) :: self
      character(len=:), allocatable :: text
      character(len=:), allocatable :: why
      real(wp) :: eps, resolution

      text = ''
      if (self%model /= model_regularized) return
      eps = self%params%epsilon_prime
      resolution = self%transition_tolerance()
      why = ''
      select case (trim(self%solver%method))
      case ('rk1imp', 'rk2imp', 'msadams', 'msbdf')
         if (eps >= 1.0e4_wp) why = 'from epsilon_prime = 1e4 on (here '//rtoa(eps)//')'
      case ('bsimp')
         if (eps >= 1.0e6_wp) why = 'from epsilon_prime = 1e6 on (here '//rtoa(eps)//')'
      case ('rodas4')
         if (resolution > rodas4_transition_bound) why = transition_text(rodas4_transition_bound)
      case ('rodas3', 'rkf45', 'rkck')
         if (resolution > transition_bound) why = transition_text(transition_bound)
      case ('rk4', 'rk4imp')
         if (eps >= 1.0e7_wp .and. self%solver%rtol < 5.0e-8_wp) why = 'at rtol below 5e-8 from ' &
            & //'epsilon_prime = 1e7 on (here '//rtoa(self%solver%rtol)//' and '//rtoa(eps)//')'
      end select
      if (len(why) == 0) return
      text = '&integrator: method = '''//trim(self%solver%method)//''' on the regularized law was measured wrong ' &
         & //'by more than 100 times the asked tolerance, while reporting success, '//why &
         & //' (docs/speed.md, "The regularized law''s steppers"); method = ''auto'' picks a stepper measured ' &
         & //'right, or check with &verify'
   contains
      function transition_text(bound) result(phrase)
         real(wp), intent(in) :: bound
         character(len=:), allocatable :: phrase

         phrase = 'where the velocity tolerance in stick spans more than '//itoa(nint(bound))//' widths of the ' &
            & //'arctan''s transition: epsilon_prime (atol + rtol |v_dr_prime|) = '//rtoa(resolution)
      end function transition_text
   end function stepper_warning

end module friction_brake_config
