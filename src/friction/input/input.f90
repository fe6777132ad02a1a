!> Reading a job from namelist files.
!>
!> Files are read in order; a later file overrides earlier values variable by
!> variable (Fortran namelist input leaves unnamed variables alone), so a
!> two-line override file tweaks or sweeps a job.  Unknown groups and
!> variables, unreadable values and non-physical settings are errors naming
!> the file, the group and the variable.  The resolved input comes back as
!> namelist text for the output file.
module friction_input
   use friction_kinds, only: wp, i8
   use friction_strings, only: itoa, rtoa, join, quoted
   use friction_error, only: error_type, fatal_error, error_input
   use friction_ode_solver, only: step_type_names, step_type_index
   use friction_ode_auto, only: auto_name, auto_method
   use friction_afm_config, only: afm_config, potential_names, net_names, net_sites, max_species, max_defects, &
      & tip_model_names
   use friction_files, only: file_exists
   use friction_brake_config, only: brake_config, model_names, units_names, brake_solver_defaults
   use friction_analysis_settings, only: section_names
   use friction_brake_diagnostics, only: series_names
   use friction_strings, only: lower
   use friction_input_scan, only: mention, scan_namelist_file, namelist_names, &
      & assigned_names, value_has_kind, kind_text
   implicit none
   private

   public :: job_config, read_input, group_names, sweep_settings, max_sweep_values

   character(len=*), parameter :: group_names(10) = [character(len=17) :: &
      & 'job', 'surface', 'tip', 'scan', 'integrator', 'brake', 'brake_dimensional', 'verify', 'analysis', &
      & 'sweep']

   integer, parameter :: max_sweep_values = 1024

   !> &sweep: one or two numeric namelist variables of the scene ('group.name'),
   !> each over a list, a linspace or a logspace; the points are the grid of
   !> the two (the second varies fastest) (README: Parameter sweeps).
   type :: sweep_settings
      logical :: enabled = .false.
      integer :: n_variables = 0
      character(len=64) :: variables(2) = ''   !! 'group.name', e.g. 'brake.v_dr_prime'
      logical :: integer_valued(2) = .false.   !! an integer variable (values are whole numbers)
      character(len=8) :: spacings(2) = 'list' !! 'list', 'linear' or 'log'
      integer :: shape(2) = 1                  !! values per variable (1 for an absent second)
      real(wp), allocatable :: values(:, :)    !! (n_variables, points): each point's values, in order
      character(len=8) :: schedule = 'dynamic' !! 'dynamic' (on demand) or 'static' (contiguous blocks)
      integer :: stop_after = 0                !! test hook: > 0 acts as an interruption after this point
   end type sweep_settings

   !> Everything a run needs from its input files.
   type :: job_config
      character(len=16) :: scene = 'afm'
      type(afm_config) :: afm
      type(brake_config) :: brake
      type(sweep_settings) :: sweep
   end type job_config

contains

   !> Read and validate the files in order into config; input_text is the
   !> resolved input as namelist text.
   subroutine read_input(paths, config, input_text, error)
      character(len=*), intent(in) :: paths(:)
      type(job_config), intent(out) :: config
      character(len=:), allocatable, intent(out) :: input_text
      type(error_type), allocatable, intent(out) :: error

      ! &job
      character(len=16) :: scene
      ! &surface
      character(len=16) :: potential, net
      real(wp) :: v0, ax, ay, a, cutoff, cutoff_tolerance
      character(len=1024) :: net_file
      integer :: shells, side
      character(len=8) :: species(max_species), substitution_species
      real(wp) :: epsilon(max_species), sigma(max_species)
      integer :: vacancies(max_defects), substitutions(max_defects)
      ! &tip (its `model` is read in tip_group: the name is the brake's here)
      real(wp) :: mass, kx, ky, kz, cx, cy, cz, support_z
      character(len=16) :: tip_model
      ! &scan
      real(wp) :: velocity, length, width, angle, origin_x, origin_y, lead_in
      integer :: nx, ny
      logical :: retrace
      ! &integrator
      character(len=16) :: method
      real(wp) :: rtol, atol, h_start, h_min
      integer(i8) :: max_steps
      real(wp) :: max_wall_time
      ! &brake (scene 'brake': Eq. 10, nondimensional; README: Girling brake)
      character(len=16) :: model, units
      real(wp) :: xi, kappa, g_prime, mu, mu_s, epsilon_prime, delta_prime, v_dr_prime
      real(wp) :: x0, y0, v_rel0, w0, t_start, t_end, dt_out, event_tolerance, stick_velocity
      ! &brake_dimensional (§6.2 data, SI; used when units = 'dimensional')
      ! (epsilon_si, delta_si, v_dr_si: the SI values of ε, δ, v_dr; &surface has its own epsilon)
      real(wp) :: arm_length, drum_radius, crank_mass, block_mass, k1, k2, k3, gravity
      real(wp) :: epsilon_si, delta_si, v_dr_si
      ! &verify (brake: a second run with another stepper or tighter tolerances)
      logical :: check
      character(len=16) :: check_method
      real(wp) :: check_rtol, check_atol, check_limit
      ! &analysis (brake: chaos diagnostics; README: Girling brake, chaos)
      logical :: spectrum, poincare, lyapunov, rosenstein
      character(len=8) :: series, window
      character(len=16) :: section
      real(wp) :: window_start, window_end, strobe_period, strobe_start, strobe_end
      real(wp) :: lyapunov_transient, lyapunov_duration, lyapunov_renormalise, lyapunov_d0
      ! &sweep (README: Parameter sweeps)
      character(len=64) :: sweep_variable, sweep_variable2
      character(len=8) :: sweep_spacing, sweep_schedule, sweep_spacing2
      real(wp) :: sweep_values(max_sweep_values), sweep_from, sweep_to
      real(wp) :: sweep_values2(max_sweep_values), sweep_from2, sweep_to2
      integer :: sweep_count, sweep_stop_after, sweep_count2
      integer :: welch_segments, rosenstein_stride, rosenstein_dimension, rosenstein_delay, &
         & rosenstein_theiler, rosenstein_horizon, rosenstein_fit_start, rosenstein_fit_end

      namelist /job/ scene
      namelist /surface/ potential, v0, ax, ay, a, net, net_file, shells, side, species, epsilon, sigma, &
         & vacancies, substitutions, substitution_species, cutoff, cutoff_tolerance
      namelist /scan/ velocity, length, width, angle, origin_x, origin_y, lead_in, nx, ny, retrace
      namelist /integrator/ method, rtol, atol, h_start, h_min, max_steps, max_wall_time
      namelist /brake/ model, units, xi, kappa, g_prime, mu, mu_s, epsilon_prime, delta_prime, v_dr_prime, &
         & x0, y0, v_rel0, w0, t_start, t_end, dt_out, event_tolerance, stick_velocity
      namelist /brake_dimensional/ arm_length, drum_radius, crank_mass, block_mass, k1, k2, k3, gravity, &
         & epsilon_si, delta_si, v_dr_si
      namelist /verify/ check, check_method, check_rtol, check_atol, check_limit
      namelist /analysis/ spectrum, series, window_start, window_end, window, welch_segments, &
         & poincare, strobe_period, strobe_start, strobe_end, section, &
         & lyapunov, lyapunov_transient, lyapunov_duration, lyapunov_renormalise, lyapunov_d0, &
         & rosenstein, rosenstein_stride, rosenstein_dimension, rosenstein_delay, rosenstein_theiler, &
         & rosenstein_horizon, rosenstein_fit_start, rosenstein_fit_end
      namelist /sweep/ sweep_variable, sweep_values, sweep_from, sweep_to, sweep_count, sweep_spacing, &
         & sweep_variable2, sweep_values2, sweep_from2, sweep_to2, sweep_count2, sweep_spacing2, &
         & sweep_schedule, sweep_stop_after

      type(mention), allocatable :: mentions(:), all_mentions(:)
      character(len=4096), allocatable :: source(:)
      integer :: ifile, unit, stat, k, g
      character(len=32), allocatable :: known(:)
      character, allocatable :: kinds(:)
      character :: kind

      call from_config()
      allocate (all_mentions(0))
      allocate (source(0))
      do ifile = 1, size(paths)
         call scan_namelist_file(trim(paths(ifile)), group_names, mentions, error)
         if (allocated(error)) return
         ! Unknown variables, with their line: clearer than the runtime's message.
         do k = 1, size(mentions)
            do g = 1, size(group_names)
               if (mentions(k)%group /= group_names(g)) cycle
               call namelist_names(group_as_text(g), known, kinds)
               if (.not. any(known == mentions(k)%name)) then
                  call fatal_error(error, trim(paths(ifile))//':'//itoa(mentions(k)%line)//': &' &
                     & //trim(mentions(k)%group)//": unknown variable '"//trim(mentions(k)%name) &
                     & //"' (known: "//join(known)//')', error_input)
                  return
               end if
               ! The runtime's own check is lenient (it skips some bad values).
               kind = kinds(findloc(known, mentions(k)%name, dim=1))
               if (.not. value_has_kind(mentions(k)%value, kind)) then
                  call fatal_error(error, trim(paths(ifile))//':'//itoa(mentions(k)%line)//': &' &
                     & //trim(mentions(k)%group)//': '//trim(mentions(k)%name)//' = ' &
                     & //trim(mentions(k)%value)//': expected '//kind_text(kind), error_input)
                  return
               end if
            end do
         end do
         ! A list given again replaces the earlier list whole (not element by
         ! element, which would keep an earlier, longer list's tail).
         do k = 1, size(mentions)
            if (mentions(k)%group /= 'sweep') cycle
            if (mentions(k)%name == 'sweep_values') sweep_values = huge(1.0_wp)
            if (mentions(k)%name == 'sweep_values2') sweep_values2 = huge(1.0_wp)
         end do
         open (newunit=unit, file=trim(paths(ifile)), status='old', action='read', iostat=stat)
         do g = 1, size(group_names)
            rewind (unit)
            call read_group(unit, trim(paths(ifile)), g)
            if (allocated(error)) then
               close (unit)
               return
            end if
         end do
         close (unit)
         all_mentions = [all_mentions, mentions]
         source = [character(len=len(source)) :: source, (paths(ifile), k=1, size(mentions))]
      end do
      call to_config()
      call resolve_net_file()
      call validate()
      if (allocated(error)) return
      ! Echo the groups the scene reads (the AFM's: 1-5; the brake's: job, integrator, 6-9).
      input_text = ''
      do g = 1, size(group_names)
         if (scene == 'brake' .and. any(g == [2, 3, 4])) cycle
         if (scene /= 'brake' .and. g > 5 .and. g < 10) cycle
         if (g == 10 .and. .not. config%sweep%enabled) cycle
         input_text = input_text//group_as_text(g)
      end do

   contains

      subroutine read_group(unit, path, g)
         integer, intent(in) :: unit, g
         character(len=*), intent(in) :: path
         character(len=512) :: msg, offending
         integer :: s, s2

         msg = ''
         select case (g)
         case (1); read (unit, nml=job, iostat=s, iomsg=msg)
         case (2); read (unit, nml=surface, iostat=s, iomsg=msg)
         case (3); call tip_group(unit, .true., s, msg)
         case (4); read (unit, nml=scan, iostat=s, iomsg=msg)
         case (5); read (unit, nml=integrator, iostat=s, iomsg=msg)
         case (6); read (unit, nml=brake, iostat=s, iomsg=msg)
         case (7); read (unit, nml=brake_dimensional, iostat=s, iomsg=msg)
         case (8); read (unit, nml=verify, iostat=s, iomsg=msg)
         case (9); read (unit, nml=analysis, iostat=s, iomsg=msg)
         case (10); read (unit, nml=sweep, iostat=s, iomsg=msg)
         end select
         if (is_iostat_end(s)) return  ! absent: keep what we have
         if (s /= 0) then
            ! Show the line the runtime stopped on.
            offending = ''
            backspace (unit, iostat=s2)
            if (s2 == 0) read (unit, '(a)', iostat=s2) offending
            if (len(assigned_names(offending)) > 0) then
               call fatal_error(error, path//': &'//trim(group_names(g))//': cannot read the value of ' &
                  & //assigned_names(offending)//' in "'//trim(adjustl(offending))//'" (' &
                  & //trim(msg)//'; check the type: number, integer, .true./.false. or ''text'')', &
                  & error_input)
            else
               call fatal_error(error, path//': &'//trim(group_names(g))//': '//trim(msg), error_input)
            end if
         end if
      end subroutine read_group

      !> Read (or write) &tip in a scope of its own: its variable `model`
      !> would otherwise be the same variable as &brake's `model`.
      subroutine tip_group(unit, reading, s, msg)
         integer, intent(in) :: unit
         logical, intent(in) :: reading
         integer, intent(out) :: s
         character(len=*), intent(inout) :: msg
         character(len=16) :: model
         namelist /tip/ model, mass, kx, ky, kz, cx, cy, cz, support_z

         model = tip_model
         s = 0
         if (reading) then
            read (unit, nml=tip, iostat=s, iomsg=msg)
         else
            write (unit, nml=tip)
         end if
         tip_model = model
      end subroutine tip_group

      !> The group's current values as namelist text.
      function group_as_text(g) result(text)
         integer, intent(in) :: g
         character(len=:), allocatable :: text
         character(len=1024) :: buffer
         character(len=512) :: msg
         integer :: scratch, s

         open (newunit=scratch, status='scratch', action='readwrite', form='formatted')
         select case (g)
         case (1); write (scratch, nml=job)
         case (2); write (scratch, nml=surface)
         case (3); call tip_group(scratch, .false., s, msg)
         case (4); write (scratch, nml=scan)
         case (5); write (scratch, nml=integrator)
         case (6); write (scratch, nml=brake)
         case (7); write (scratch, nml=brake_dimensional)
         case (8); write (scratch, nml=verify)
         case (9); write (scratch, nml=analysis)
         case (10); write (scratch, nml=sweep)
         end select
         rewind (scratch)
         text = ''
         do
            read (scratch, '(a)', iostat=s) buffer
            if (s /= 0) exit
            text = text//trim(buffer)//new_line('a')
         end do
         close (scratch)
      end function group_as_text

      subroutine from_config()
         type(job_config) :: defaults

         scene = defaults%scene
         associate (c => defaults%afm)
            potential = c%potential; v0 = c%v0; ax = c%ax; ay = c%ay; a = c%a
            net = c%net; net_file = c%net_file; shells = c%shells; side = c%side
            species = c%species; epsilon = c%epsilon; sigma = c%sigma
            vacancies = c%vacancies; substitutions = c%substitutions
            substitution_species = c%substitution_species; cutoff = c%cutoff
            cutoff_tolerance = c%cutoff_tolerance
            tip_model = c%model
            mass = c%mass; kx = c%kx; ky = c%ky; kz = c%kz; cx = c%cx; cy = c%cy; cz = c%cz
            support_z = c%support_z
            velocity = c%velocity; length = c%length; width = c%width; angle = c%angle
            origin_x = c%origin_x; origin_y = c%origin_y; lead_in = c%lead_in
            nx = c%nx; ny = c%ny; retrace = c%retrace
            method = c%solver%method; rtol = c%solver%rtol; atol = c%solver%atol
            h_start = c%solver%h_start; h_min = c%solver%h_min; max_steps = c%solver%max_steps
            max_wall_time = c%solver%max_wall_time
         end associate
         associate (b => defaults%brake, p => defaults%brake%params, d => defaults%brake%dimensional)
            model = b%model; units = b%units
            xi = p%xi; kappa = p%kappa; g_prime = p%g_prime; mu = p%mu; mu_s = p%mu_s
            epsilon_prime = p%epsilon_prime; delta_prime = p%delta_prime; v_dr_prime = p%v_dr
            x0 = b%x0; y0 = b%y0; v_rel0 = b%v_rel0; w0 = b%w0
            t_start = b%t_start; t_end = b%t_end; dt_out = b%dt_out
            event_tolerance = b%event_tolerance; stick_velocity = b%stick_velocity
            arm_length = d%arm_length; drum_radius = d%drum_radius; crank_mass = d%crank_mass
            block_mass = d%block_mass; k1 = d%k1; k2 = d%k2; k3 = d%k3; gravity = d%gravity
            epsilon_si = d%epsilon; delta_si = d%delta; v_dr_si = d%v_dr
            check = b%check%enabled; check_method = b%check%method; check_rtol = b%check%rtol
            check_atol = b%check%atol; check_limit = b%check%max_difference
         end associate
         associate (n => defaults%brake%analysis)
            spectrum = n%spectrum; series = n%series; window_start = n%window_start
            window_end = n%window_end; window = n%window; welch_segments = n%welch_segments
            poincare = n%poincare; strobe_period = n%strobe_period; strobe_start = n%strobe_start
            strobe_end = n%strobe_end; section = n%section
            lyapunov = n%lyapunov; lyapunov_transient = n%lyapunov_transient
            lyapunov_duration = n%lyapunov_duration; lyapunov_renormalise = n%lyapunov_renormalise
            lyapunov_d0 = n%lyapunov_d0
            rosenstein = n%rosenstein; rosenstein_stride = n%rosenstein_stride
            rosenstein_dimension = n%rosenstein_dimension; rosenstein_delay = n%rosenstein_delay
            rosenstein_theiler = n%rosenstein_theiler; rosenstein_horizon = n%rosenstein_horizon
            rosenstein_fit_start = n%rosenstein_fit_start; rosenstein_fit_end = n%rosenstein_fit_end
         end associate
         sweep_variable = ''; sweep_spacing = 'list'; sweep_schedule = 'dynamic'
         sweep_values = huge(1.0_wp); sweep_from = 0.0_wp; sweep_to = 0.0_wp; sweep_count = 0
         sweep_variable2 = ''; sweep_spacing2 = 'list'
         sweep_values2 = huge(1.0_wp); sweep_from2 = 0.0_wp; sweep_to2 = 0.0_wp; sweep_count2 = 0
         sweep_stop_after = 0
      end subroutine from_config

      subroutine to_config()
         method = lower(method)
         potential = lower(potential)
         tip_model = lower(tip_model)
         net = lower(net)
         scene = lower(scene)
         config%scene = scene
         associate (c => config%afm)
            c%potential = potential; c%v0 = v0; c%ax = ax; c%ay = ay; c%a = a
            c%net = net; c%net_file = net_file; c%shells = shells; c%side = side
            c%species = species; c%epsilon = epsilon; c%sigma = sigma
            c%vacancies = vacancies; c%substitutions = substitutions
            c%substitution_species = substitution_species; c%cutoff = cutoff
            c%cutoff_tolerance = cutoff_tolerance
            c%model = tip_model
            c%mass = mass; c%kx = kx; c%ky = ky; c%kz = kz; c%cx = cx; c%cy = cy; c%cz = cz
            c%support_z = support_z
            c%velocity = velocity; c%length = length; c%width = width; c%angle = angle
            c%origin_x = origin_x; c%origin_y = origin_y; c%lead_in = lead_in
            c%nx = nx; c%ny = ny; c%retrace = retrace
            c%solver%method = method; c%solver%rtol = rtol; c%solver%atol = atol
            c%solver%h_start = h_start; c%solver%h_min = h_min; c%solver%max_steps = max_steps
            c%solver%max_wall_time = max_wall_time
         end associate
         ! The brake's &integrator defaults differ from the AFM's (τ units, tight tolerances).
         if (scene == 'brake') then
            if (.not. is_set('integrator', 'method')) method = brake_solver_defaults%method
            if (.not. is_set('integrator', 'rtol')) rtol = brake_solver_defaults%rtol
            if (.not. is_set('integrator', 'atol')) atol = brake_solver_defaults%atol
         end if
         model = lower(model)
         units = lower(units)
         check_method = lower(check_method)
         associate (b => config%brake, p => config%brake%params, d => config%brake%dimensional)
            b%model = model; b%units = units
            p%xi = xi; p%kappa = kappa; p%g_prime = g_prime; p%mu = mu; p%mu_s = mu_s
            p%epsilon_prime = epsilon_prime; p%delta_prime = delta_prime; p%v_dr = v_dr_prime
            b%x0 = x0; b%y0 = y0; b%v_rel0 = v_rel0; b%w0 = w0
            b%t_start = t_start; b%t_end = t_end; b%dt_out = dt_out
            b%event_tolerance = event_tolerance; b%stick_velocity = stick_velocity
            d%arm_length = arm_length; d%drum_radius = drum_radius; d%crank_mass = crank_mass
            d%block_mass = block_mass; d%k1 = k1; d%k2 = k2; d%k3 = k3; d%gravity = gravity
            d%epsilon = epsilon_si; d%delta = delta_si; d%v_dr = v_dr_si
            b%check%enabled = check; b%check%method = check_method; b%check%rtol = check_rtol
            b%check%atol = check_atol; b%check%max_difference = check_limit
            b%solver%method = method; b%solver%rtol = rtol; b%solver%atol = atol
            b%solver%h_start = h_start; b%solver%h_min = h_min; b%solver%max_steps = max_steps
            b%solver%max_wall_time = max_wall_time
         end associate
         ! method = 'auto': the stepper the work-precision charts show fastest for
         ! the scene at this rtol; the input text keeps 'auto', the file's root
         ! attribute `method` records the choice.
         if (method == auto_name) then
            config%afm%solver%method = auto_method('afm', potential, config%afm%solver%rtol)
            config%brake%solver%method = auto_method('brake', model, rtol)
         end if
         series = lower(series)
         window = lower(window)
         section = lower(section)
         associate (n => config%brake%analysis)
            n%spectrum = spectrum; n%series = series; n%window_start = window_start
            n%window_end = window_end; n%window = window; n%welch_segments = welch_segments
            n%poincare = poincare; n%strobe_period = strobe_period; n%strobe_start = strobe_start
            n%strobe_end = strobe_end; n%section = section
            n%lyapunov = lyapunov; n%lyapunov_transient = lyapunov_transient
            n%lyapunov_duration = lyapunov_duration; n%lyapunov_renormalise = lyapunov_renormalise
            n%lyapunov_d0 = lyapunov_d0
            n%rosenstein = rosenstein; n%rosenstein_stride = rosenstein_stride
            n%rosenstein_dimension = rosenstein_dimension; n%rosenstein_delay = rosenstein_delay
            n%rosenstein_theiler = rosenstein_theiler; n%rosenstein_horizon = rosenstein_horizon
            n%rosenstein_fit_start = rosenstein_fit_start; n%rosenstein_fit_end = rosenstein_fit_end
         end associate
         sweep_variable = lower(sweep_variable)
         sweep_spacing = lower(sweep_spacing)
         sweep_variable2 = lower(sweep_variable2)
         sweep_spacing2 = lower(sweep_spacing2)
         sweep_schedule = lower(sweep_schedule)
         config%sweep%enabled = len_trim(sweep_variable) > 0
         config%sweep%n_variables = merge(2, 1, len_trim(sweep_variable2) > 0)
         config%sweep%variables = [sweep_variable, sweep_variable2]
         config%sweep%spacings = [sweep_spacing, sweep_spacing2]
         config%sweep%schedule = sweep_schedule
         config%sweep%stop_after = sweep_stop_after
      end subroutine to_config

      !> A relative net_file is relative to the namelist file that names it,
      !> so a job runs the same from any working directory.
      subroutine resolve_net_file()
         integer :: k, slash

         if (len_trim(net_file) == 0 .or. net_file(1:1) == '/') return
         do k = size(all_mentions), 1, -1
            if (all_mentions(k)%group == 'surface' .and. all_mentions(k)%name == 'net_file') then
               slash = index(source(k), '/', back=.true.)
               if (slash > 0) net_file = source(k)(1:slash)//trim(net_file)
               config%afm%net_file = net_file
               return
            end if
         end do
      end subroutine resolve_net_file

      !> Whether any file set a variable.
      logical function is_set(group, name)
         character(len=*), intent(in) :: group, name

         is_set = origin(group, name) /= '(default)'
      end function is_set

      !> The file that last set a variable, for messages.
      function origin(group, name) result(text)
         character(len=*), intent(in) :: group, name
         character(len=:), allocatable :: text
         integer :: k

         text = '(default)'
         do k = size(all_mentions), 1, -1
            if (all_mentions(k)%group == group .and. all_mentions(k)%name == name) then
               text = trim(source(k))//':'//itoa(all_mentions(k)%line)
               return
            end if
         end do
      end function origin

      !> The error for a bad value: where it was set, group, variable (with
      !> its array index when given), value and reason.
      subroutine reject(group, name, value, reason, index)
         character(len=*), intent(in) :: group, name, value, reason
         integer, intent(in), optional :: index
         character(len=:), allocatable :: shown

         if (allocated(error)) return
         shown = name
         if (present(index)) shown = name//'('//itoa(index)//')'
         call fatal_error(error, origin(group, name)//': &'//group//': '//shown//' = ' &
            & //value//': '//reason, error_input)
      end subroutine reject

      subroutine require_positive(group, name, value, unit_text)
         character(len=*), intent(in) :: group, name, unit_text
         real(wp), intent(in) :: value

         if (.not. (value > 0.0_wp)) call reject(group, name, rtoa(value), 'must be > 0 ('//unit_text//')')
      end subroutine require_positive

      subroutine require_nonnegative(group, name, value, unit_text)
         character(len=*), intent(in) :: group, name, unit_text
         real(wp), intent(in) :: value

         if (.not. (value >= 0.0_wp)) call reject(group, name, rtoa(value), 'must be >= 0 ('//unit_text//')')
      end subroutine require_nonnegative

      !> The overdamped model divides by the damping of every moving direction.
      subroutine require_damped(name, value)
         character(len=*), intent(in) :: name
         real(wp), intent(in) :: value

         if (.not. (value > 0.0_wp)) call reject('tip', name, rtoa(value), "must be > 0 (N s/m) for " &
            & //"model = 'overdamped': c dr/dt = -k (r - r_M) - grad V has no motion without damping " &
            & //"(use 'inertial', or 'quasistatic' for the slow limit)")
      end subroutine require_damped

      subroutine require_finite(group, name, value)
         character(len=*), intent(in) :: group, name
         real(wp), intent(in) :: value

         if (.not. (abs(value) <= huge(value))) call reject(group, name, rtoa(value), 'must be a finite number')
      end subroutine require_finite

      !> The Lennard-Jones sum and its crystal net (Eq. 3).
      subroutine validate_net()
         integer :: ns, k, sites

         call require_positive('tip', 'kz', kz, 'N/m; the tip moves in z over a lattice sum')
         if (.not. any(net_names == net)) call reject('surface', 'net', "'"//trim(net)//"'", &
            & 'unknown net (known: '//quoted(net_names)//')')
         ns = 0
         do while (ns < max_species)
            if (len_trim(species(ns + 1)) == 0) exit
            ns = ns + 1
         end do
         if (ns == 0) call reject('surface', 'species', "''", 'name at least one species')
         do k = 1, ns
            if (.not. (sigma(k) > 0.0_wp)) call reject('surface', 'sigma', rtoa(sigma(k)), &
               & 'must be > 0 (Å) for species '//trim(species(k)), k)
            if (.not. (epsilon(k) >= 0.0_wp)) call reject('surface', 'epsilon', rtoa(epsilon(k)), &
               & 'must be >= 0 (eV) for species '//trim(species(k)), k)
         end do
         if (cutoff < 0.0_wp) call reject('surface', 'cutoff', rtoa(cutoff), 'must be >= 0 (Å; 0 chooses it)')
         if (ns > 0 .and. cutoff > 0.0_wp .and. cutoff < maxval(sigma(1:max(ns, 1)))) &
            & call reject('surface', 'cutoff', rtoa(cutoff), 'must not be below sigma ('// &
            & rtoa(maxval(sigma(1:max(ns, 1))))//' Å): the sum would miss the repulsive core')
         call require_positive('surface', 'cutoff_tolerance', cutoff_tolerance, 'nN')
         select case (trim(net))
         case ('graphite')
            if (shells < 0) call reject('surface', 'shells', itoa(shells), 'must be >= 0')
         case ('square')
            if (side < 1) call reject('surface', 'side', itoa(side), 'must be >= 1')
         case ('file')
            if (len_trim(net_file) == 0) then
               call reject('surface', 'net_file', "''", "name an XYZ file for net = 'file'")
            else if (.not. file_exists(trim(net_file))) then
               call reject('surface', 'net_file', "'"//trim(net_file)//"'", 'no such file')
            end if
         end select
         if (allocated(error)) return
         sites = net_sites(config%afm)
         do k = 1, max_defects
            if (vacancies(k) < 0 .or. (sites >= 0 .and. vacancies(k) > sites)) &
               & call reject('surface', 'vacancies', itoa(vacancies(k)), &
               & 'site outside the net of '//itoa(sites)//' sites', k)
            if (substitutions(k) < 0 .or. (sites >= 0 .and. substitutions(k) > sites)) &
               & call reject('surface', 'substitutions', itoa(substitutions(k)), &
               & 'site outside the net of '//itoa(sites)//' sites', k)
         end do
         if (any(substitutions > 0) .and. .not. any(species(1:max(ns, 1)) == substitution_species)) &
            & call reject('surface', 'substitution_species', "'"//trim(substitution_species)//"'", &
            & 'not in the species table (known: '//quoted(species(1:max(ns, 1)))//')')
      end subroutine validate_net

      subroutine validate()
         if (scene /= 'afm' .and. scene /= 'brake') call reject('job', 'scene', "'"//trim(scene)//"'", &
            & "unknown scene (known: 'afm', 'brake')")
         if (.not. any(potential_names == potential)) call reject('surface', 'potential', &
            & "'"//trim(potential)//"'", 'unknown potential (known: '//quoted(potential_names)//')')
         call require_nonnegative('surface', 'v0', v0, 'eV')
         call require_positive('surface', 'ax', ax, 'Å')
         call require_positive('surface', 'ay', ay, 'Å')
         call require_positive('surface', 'a', a, 'Å')
         call require_positive('tip', 'mass', mass, 'kg')
         call require_nonnegative('tip', 'kx', kx, 'N/m')
         call require_nonnegative('tip', 'ky', ky, 'N/m')
         call require_nonnegative('tip', 'cx', cx, 'N s/m')
         call require_nonnegative('tip', 'cy', cy, 'N s/m')
         call require_nonnegative('tip', 'cz', cz, 'N s/m')
         call require_finite('tip', 'support_z', support_z)
         if (.not. any(tip_model_names == tip_model)) then
            call reject('tip', 'model', "'"//trim(tip_model)//"'", 'unknown tip model (known: ' &
               & //quoted(tip_model_names)//')')
         else if (tip_model == 'overdamped') then
            call require_damped('cx', cx)
            call require_damped('cy', cy)
            if (potential == 'lj') call require_damped('cz', cz)
         end if
         if (potential == 'lj') call validate_net()
         call require_positive('scan', 'velocity', velocity, 'Å/s; the direction is set by angle')
         call require_positive('scan', 'length', length, 'Å')
         call require_nonnegative('scan', 'width', width, 'Å')
         call require_finite('scan', 'angle', angle)
         call require_finite('scan', 'origin_x', origin_x)
         call require_finite('scan', 'origin_y', origin_y)
         call require_nonnegative('scan', 'lead_in', lead_in, 'Å')
         if (nx < 2) call reject('scan', 'nx', itoa(nx), 'must be >= 2 (sample points per line)')
         if (ny < 1) call reject('scan', 'ny', itoa(ny), 'must be >= 1 (lines)')
         if (method /= auto_name .and. step_type_index(method) == 0) call reject('integrator', 'method', &
            & "'"//trim(method)//"'", 'unknown GSL step type (known: '//quoted(step_type_names())//', or '// &
            & quoted([auto_name])//' to choose by scene and rtol)')
         call require_positive('integrator', 'rtol', rtol, 'relative tolerance')
         call require_positive('integrator', 'atol', atol, 'absolute tolerance, Å and Å/s')
         call require_nonnegative('integrator', 'h_start', h_start, 's; 0 chooses automatically')
         call require_nonnegative('integrator', 'h_min', h_min, 's; 0 for no limit')
         if (max_steps < 1) call reject('integrator', 'max_steps', itoa(max_steps), 'must be >= 1')
         call require_nonnegative('integrator', 'max_wall_time', max_wall_time, 's; 0 for no limit')
         if (scene == 'brake') call validate_brake()
         if (config%sweep%enabled) call validate_sweep()
      end subroutine validate

      !> &sweep: one or two known numeric variables of the scene's groups, and
      !> their points.
      subroutine validate_sweep()
         real(wp), allocatable :: axes(:, :)
         integer :: counts(2), v, i1, i2, p

         if (sweep_schedule /= 'dynamic' .and. sweep_schedule /= 'static') call reject('sweep', &
            & 'sweep_schedule', "'"//trim(sweep_schedule)//"'", "unknown schedule (known: 'dynamic', 'static')")
         if (sweep_stop_after < 0) call reject('sweep', 'sweep_stop_after', itoa(sweep_stop_after), &
            & 'must be >= 0 (0: never; a test hook)')
         allocate (axes(max_sweep_values, 2), source=0.0_wp)
         counts = 1
         call sweep_axis('', sweep_variable, sweep_spacing, sweep_values, sweep_from, sweep_to, sweep_count, &
            & config%sweep%integer_valued(1), axes(:, 1), counts(1))
         if (config%sweep%n_variables == 2) then
            if (sweep_variable2 == sweep_variable) call reject('sweep', 'sweep_variable2', &
               & "'"//trim(sweep_variable2)//"'", 'is sweep_variable already')
            call sweep_axis('2', sweep_variable2, sweep_spacing2, sweep_values2, sweep_from2, sweep_to2, &
               & sweep_count2, config%sweep%integer_valued(2), axes(:, 2), counts(2))
         end if
         if (allocated(error)) return
         if (counts(1) * counts(2) > max_sweep_values) then
            call reject('sweep', 'sweep_count2', itoa(counts(2)), 'the grid of '//itoa(counts(1))//' x ' &
               & //itoa(counts(2))//' points exceeds '//itoa(max_sweep_values)//' points')
            return
         end if
         v = config%sweep%n_variables
         config%sweep%shape = counts
         allocate (config%sweep%values(v, counts(1) * counts(2)))
         p = 0
         do i1 = 1, counts(1)
            do i2 = 1, counts(2)
               p = p + 1
               config%sweep%values(1, p) = axes(i1, 1)
               if (v == 2) config%sweep%values(2, p) = axes(i2, 2)
            end do
         end do
      end subroutine validate_sweep

      !> One swept variable (`suffix` '' or '2' names its namelist variables):
      !> a numeric variable of a group of this scene, and its values.
      subroutine sweep_axis(suffix, variable, spacing, listed, from, to, count, whole, axis, n)
         character(len=*), intent(in) :: suffix, variable, spacing
         real(wp), intent(in) :: listed(:), from, to
         integer, intent(in) :: count
         logical, intent(out) :: whole
         real(wp), intent(out) :: axis(:)
         integer, intent(out) :: n
         character(len=*), parameter :: afm_groups(*) = [character(len=17) :: 'surface', 'tip', 'scan', &
            & 'integrator']
         character(len=*), parameter :: brake_groups(*) = [character(len=17) :: 'brake', 'brake_dimensional', &
            & 'integrator', 'verify', 'analysis']
         character(len=32), allocatable :: known(:)
         character, allocatable :: kinds(:)
         integer :: dot, g, k
         logical :: ours
         character(len=:), allocatable :: group, name, shown

         n = 0
         whole = .false.
         shown = "'"//trim(variable)//"'"
         dot = index(variable, '.')
         group = variable(1:max(0, dot - 1))
         name = trim(variable(dot + 1:))
         ! (Loops, not findloc: gfortran's findloc on these deferred-length strings
         ! upset the one in the mention check above.)
         g = 0
         do k = 1, size(group_names)
            if (group_names(k) == group) g = k
         end do
         if (dot == 0 .or. g == 0 .or. g == 1 .or. g == 10) then
            call reject('sweep', 'sweep_variable'//suffix, shown, &
               & "name a variable as 'group.name' of a scene group (e.g. 'brake.v_dr_prime')")
            return
         end if
         ours = .false.
         if (scene == 'brake') then
            do k = 1, size(brake_groups)
               if (brake_groups(k) == group) ours = .true.
            end do
         else
            do k = 1, size(afm_groups)
               if (afm_groups(k) == group) ours = .true.
            end do
         end if
         if (.not. ours) then
            call reject('sweep', 'sweep_variable'//suffix, shown, 'group &'//group//' is not part of scene ' &
               & //"'"//trim(scene)//"'")
            return
         end if
         call namelist_names(group_as_text(g), known, kinds)
         dot = 0
         do k = 1, size(known)
            if (known(k) == name) dot = k
         end do
         k = dot
         if (k == 0) then
            call reject('sweep', 'sweep_variable'//suffix, shown, 'no variable '//name// &
               & ' in &'//group//' (known: '//join(known)//')')
            return
         end if
         if (kinds(k) /= 'r' .and. kinds(k) /= 'i') then
            call reject('sweep', 'sweep_variable'//suffix, shown, &
               & 'only numeric (real or integer) variables can be swept')
            return
         end if
         whole = kinds(k) == 'i'
         select case (trim(spacing))
         case ('list')
            do while (n < max_sweep_values)
               if (listed(n + 1) == huge(1.0_wp)) exit
               n = n + 1
            end do
            if (n == 0) call reject('sweep', 'sweep_values'//suffix, '(none)', "give at least one value for " &
               & //"sweep_spacing"//suffix//" = 'list'")
            axis(1:n) = listed(1:n)
         case ('linear', 'log')
            if (count < 1 .or. count > max_sweep_values) then
               call reject('sweep', 'sweep_count'//suffix, itoa(count), 'must be in [1, ' &
                  & //itoa(max_sweep_values)//']')
               return
            end if
            call require_finite('sweep', 'sweep_from'//suffix, from)
            call require_finite('sweep', 'sweep_to'//suffix, to)
            if (spacing == 'log') then
               if (.not. (from > 0.0_wp)) call reject('sweep', 'sweep_from'//suffix, rtoa(from), &
                  & "must be > 0 for sweep_spacing"//suffix//" = 'log'")
               if (.not. (to > 0.0_wp)) call reject('sweep', 'sweep_to'//suffix, rtoa(to), &
                  & "must be > 0 for sweep_spacing"//suffix//" = 'log'")
            end if
            if (allocated(error)) return
            n = count
            do k = 1, count
               if (count == 1) then
                  axis(k) = from
               else if (spacing == 'linear') then
                  axis(k) = from + (to - from) * (k - 1) / (count - 1)
               else
                  axis(k) = exp(log(from) + (log(to) - log(from)) * (k - 1) / (count - 1))
               end if
            end do
            ! An integer variable takes whole values: a spaced range is rounded
            ! (and must not repeat a value).
            if (whole) then
               axis(1:n) = anint(axis(1:n))
               do k = 2, n
                  if (axis(k) == axis(k - 1)) then
                     call reject('sweep', 'sweep_count'//suffix, itoa(count), 'integer variable '//name// &
                        & ' takes whole values: '//itoa(count)//' points from '//rtoa(from)//' to '//rtoa(to) &
                        & //' repeat '//rtoa(axis(k)))
                     return
                  end if
               end do
            end if
         case default
            call reject('sweep', 'sweep_spacing'//suffix, "'"//trim(spacing)//"'", &
               & "unknown spacing (known: 'list', 'linear', 'log')")
         end select
         if (whole .and. n > 0) then
            do k = 1, n
               if (axis(k) /= anint(axis(k)) .or. abs(axis(k)) > 2.0_wp**30) then
                  call reject('sweep', 'sweep_values'//suffix, rtoa(axis(k)), 'integer variable '//name// &
                     & ' takes whole values')
                  return
               end if
            end do
         end if
      end subroutine sweep_axis

      !> The brake scene's settings (README: Girling brake, input reference).
      subroutine validate_brake()
         type(error_type), allocatable :: derive_error
         real(wp) :: normal
         logical :: regularized, dimensional

         if (.not. any(model_names == model)) call reject('brake', 'model', "'"//trim(model)//"'", &
            & 'unknown friction model (known: '//quoted(model_names)//')')
         if (.not. any(units_names == units)) call reject('brake', 'units', "'"//trim(units)//"'", &
            & 'unknown parameter set (known: '//quoted(units_names)//')')
         if (allocated(error)) return
         regularized = model == 'regularized'
         dimensional = units == 'dimensional'
         call require_nonnegative('brake', 'mu', mu, 'kinetic friction coefficient')
         call require_nonnegative('brake', 'mu_s', mu_s, 'static friction coefficient')
         if (.not. regularized .and. mu > mu_s) call reject('brake', 'mu', rtoa(mu), &
            & 'the switched model needs mu <= mu_s = '//rtoa(mu_s)//' (a kinetic coefficient above the ' &
            & //'static one makes every slip stop at once: use the regularized model)')
         if (dimensional) then
            call require_positive('brake_dimensional', 'arm_length', arm_length, 'm')
            call require_nonnegative('brake_dimensional', 'drum_radius', drum_radius, 'm')
            call require_positive('brake_dimensional', 'crank_mass', crank_mass, 'kg')
            call require_positive('brake_dimensional', 'block_mass', block_mass, 'kg')
            call require_positive('brake_dimensional', 'k1', k1, 'N/m')
            call require_positive('brake_dimensional', 'k2', k2, 'N/m')
            call require_nonnegative('brake_dimensional', 'k3', k3, 'N/m')
            call require_nonnegative('brake_dimensional', 'gravity', gravity, 'm/s²')
            if (regularized) call require_positive('brake_dimensional', 'epsilon_si', epsilon_si, &
               & 's/m; the regularized law needs a steepness')
            call require_nonnegative('brake_dimensional', 'delta_si', delta_si, 's/m')
            call require_finite('brake_dimensional', 'v_dr_si', v_dr_si)
            if (abs(k2 - k1) > 1.0e-9_wp * k1) call reject('brake_dimensional', 'k2', rtoa(k2), &
               & 'must equal k1 = '//rtoa(k1)//': Eq. 10 assumes k2 = k1 (paper §4.1)')
            if (allocated(error)) return
            call config%brake%resolve(derive_error)
            if (allocated(derive_error)) then
               call reject('brake_dimensional', 'k2', rtoa(k2), derive_error%message)
               return
            end if
         else
            call require_positive('brake', 'xi', xi, 'J/(m L²)')
            call require_positive('brake', 'kappa', kappa, '(k1 + k3)/k1')
            call require_finite('brake', 'g_prime', g_prime)
            if (regularized) call require_positive('brake', 'epsilon_prime', epsilon_prime, &
               & 'the regularized law needs a steepness')
            call require_nonnegative('brake', 'delta_prime', delta_prime, 'velocity weakening')
            call require_finite('brake', 'v_dr_prime', v_dr_prime)
         end if
         call require_finite('brake', 'x0', x0)
         call require_finite('brake', 'y0', y0)
         call require_finite('brake', 'v_rel0', v_rel0)
         call require_finite('brake', 'w0', w0)
         call require_finite('brake', 't_start', t_start)
         call require_finite('brake', 't_end', t_end)
         if (.not. (t_end > t_start)) call reject('brake', 't_end', rtoa(t_end), &
            & 'must be after t_start = '//rtoa(t_start))
         call require_positive('brake', 'dt_out', dt_out, 'output grid step in τ')
         call require_positive('brake', 'event_tolerance', event_tolerance, 'τ')
         call require_positive('brake', 'stick_velocity', stick_velocity, 'm per unit τ')
         if (allocated(error)) return
         if ((t_end - t_start) / dt_out > 1.0e7_wp) call reject('brake', 'dt_out', rtoa(dt_out), &
            & 'gives more than 1e7 output points over [t_start, t_end]')
         associate (p => config%brake%params)
            normal = p%normal_force(y0)
            if (.not. (normal > 0.0_wp)) call reject('brake', 'y0', rtoa(y0), &
               & "the initial normal force N' = (1 - kappa) y0 + g_prime = "//rtoa(normal) &
               & //' must be > 0 (kappa = '//rtoa(p%kappa)//', g_prime = '//rtoa(p%g_prime)//')')
         end associate
         if (len_trim(check_method) > 0 .and. step_type_index(check_method) == 0) &
            & call reject('verify', 'check_method', "'"//trim(check_method)//"'", &
            & "unknown GSL step type (known: ''"//', '//quoted(step_type_names())//')')
         call require_nonnegative('verify', 'check_rtol', check_rtol, '0 for rtol / 1000')
         call require_nonnegative('verify', 'check_atol', check_atol, '0 for atol / 1000')
         call require_nonnegative('verify', 'check_limit', check_limit, 'm; 0 reports only')
         call validate_analysis()
      end subroutine validate_brake

      !> The chaos diagnostics' settings (README: Girling brake, chaos).
      subroutine validate_analysis()
         if (.not. any(series_names == series)) call reject('analysis', 'series', "'"//trim(series)//"'", &
            & 'unknown variable (known: '//quoted(series_names)//')')
         if (window /= 'hann' .and. window /= 'none') call reject('analysis', 'window', "'"//trim(window)//"'", &
            & "unknown window (known: 'hann', 'none')")
         if (.not. any(section_names == section)) call reject('analysis', 'section', "'"//trim(section)//"'", &
            & 'unknown section (known: '//quoted(section_names)//')')
         call require_finite('analysis', 'window_start', window_start)
         if (.not. (window_end > window_start)) call reject('analysis', 'window_end', rtoa(window_end), &
            & 'must be after window_start = '//rtoa(window_start))
         if (welch_segments < 1) call reject('analysis', 'welch_segments', itoa(welch_segments), 'must be >= 1')
         call require_nonnegative('analysis', 'strobe_period', strobe_period, 'τ; 0 for 1 / peak frequency')
         call require_finite('analysis', 'strobe_start', strobe_start)
         call require_nonnegative('analysis', 'strobe_end', strobe_end, 'τ; 0 for the end of the run')
         call require_nonnegative('analysis', 'lyapunov_transient', lyapunov_transient, 'τ')
         call require_nonnegative('analysis', 'lyapunov_duration', lyapunov_duration, 'τ; 0 for the rest of the run')
         call require_positive('analysis', 'lyapunov_renormalise', lyapunov_renormalise, 'τ')
         call require_positive('analysis', 'lyapunov_d0', lyapunov_d0, 'initial separation')
         if (lyapunov .and. lyapunov_duration == 0.0_wp .and. &
            & .not. (t_end - t_start - lyapunov_transient >= lyapunov_renormalise)) &
            & call reject('analysis', 'lyapunov_transient', rtoa(lyapunov_transient), &
            & 'leaves less than one renormalisation interval before t_end')
         if (rosenstein_stride < 1) call reject('analysis', 'rosenstein_stride', itoa(rosenstein_stride), &
            & 'must be >= 1')
         if (rosenstein_dimension < 1) call reject('analysis', 'rosenstein_dimension', &
            & itoa(rosenstein_dimension), 'must be >= 1')
         if (rosenstein_delay < 1) call reject('analysis', 'rosenstein_delay', itoa(rosenstein_delay), &
            & 'must be >= 1 (samples)')
         if (rosenstein_theiler < 0) call reject('analysis', 'rosenstein_theiler', itoa(rosenstein_theiler), &
            & 'must be >= 0 (samples)')
         if (rosenstein_horizon < 1) call reject('analysis', 'rosenstein_horizon', itoa(rosenstein_horizon), &
            & 'must be >= 1 (samples)')
         if (rosenstein_fit_start < 0) call reject('analysis', 'rosenstein_fit_start', &
            & itoa(rosenstein_fit_start), 'must be >= 0 (samples)')
         if (rosenstein_fit_end <= rosenstein_fit_start .or. rosenstein_fit_end > rosenstein_horizon) &
            & call reject('analysis', 'rosenstein_fit_end', itoa(rosenstein_fit_end), &
            & 'must be in (rosenstein_fit_start, rosenstein_horizon]')
      end subroutine validate_analysis

   end subroutine read_input

end module friction_input
