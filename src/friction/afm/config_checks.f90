!> The checks of a map's settings (afm_config's validate): every value of
!> &surface, &tip, &scan, &integrator, &verify and &thermal on its own, and
!> those that need the tip and the surface built (the Langevin step's
!> stability limit).  A submodule, so that the checks can use what the
!> settings build and what a trip records without a cycle of modules.
submodule (friction_afm_config) friction_afm_config_checks
   use friction_kinds, only: i8
   use friction_strings, only: itoa, rtoa, quoted, bytes_text
   use friction_files, only: file_exists
   use friction_ode_settings, only: check_integrator, check_verify
   use friction_afm_kramers, only: kmc_barrier_floor
   use friction_afm_trip, only: n_quantities
   implicit none

contains

   module procedure validate
      !> at a temperature, the settings with the damping &thermal
      !> attempt_frequency stands for (check_thermal)
      type(afm_config) :: eff

      if (.not. any(potential_names == self%potential)) call c%reject('surface', 'potential', &
         & "'"//trim(self%potential)//"'", 'unknown potential (known: '//quoted(potential_names)//')')
      call c%nonnegative('surface', 'v0', self%v0, 'eV')
      ! Lattice constants of crystals are angstroms: a tiny one overflows the surface's forces.
      call lattice_constant('ax', self%ax)
      call lattice_constant('ay', self%ay)
      call lattice_constant('a', self%a)
      call c%positive('tip', 'mass', self%mass, 'kg')
      call c%nonnegative('tip', 'kx', self%kx, 'N/m')
      call c%nonnegative('tip', 'ky', self%ky, 'N/m')
      call c%nonnegative('tip', 'cx', self%cx, 'N s/m')
      call c%nonnegative('tip', 'cy', self%cy, 'N s/m')
      call c%nonnegative('tip', 'cz', self%cz, 'N s/m')
      call c%finite('tip', 'support_z', self%support_z)
      if (.not. any(tip_model_names == self%model)) then
         call c%reject('tip', 'model', "'"//trim(self%model)//"'", 'unknown tip model (known: ' &
            & //quoted(tip_model_names)//')')
      else if (self%model == 'overdamped') then
         call require_damped('cx', self%cx)
         call require_damped('cy', self%cy)
         if (self%potential == 'lj') call require_damped('cz', self%cz)
      end if
      if (self%potential == 'lj') call check_net()
      call check_fourier()
      call c%positive('scan', 'velocity', self%velocity, 'Å/s; the direction is set by angle')
      call c%positive('scan', 'length', self%length, 'angstrom')
      call c%nonnegative('scan', 'width', self%width, 'angstrom')
      call c%finite('scan', 'angle', self%angle)
      call c%finite('scan', 'origin_x', self%origin_x)
      call c%finite('scan', 'origin_y', self%origin_y)
      call c%nonnegative('scan', 'lead_in', self%lead_in, 'angstrom')
      call c%nonnegative('scan', 'checkpoint_interval', self%checkpoint_interval, 's')
      if (self%nx < 2) call c%reject('scan', 'nx', itoa(self%nx), 'must be >= 2 (sample points per line)')
      if (self%ny < 1) call c%reject('scan', 'ny', itoa(self%ny), 'must be >= 1 (lines)')
      ! Sizes in 64 bits: a map's dataset holds nx * ny values, and one
      ! collective MPI-IO write takes at most 2**31 - 1 of them.
      if (int(self%nx, i8) * int(max(self%ny, 1), i8) > int(huge(1), i8)) call c%reject('scan', 'nx', &
         & itoa(self%nx), 'with ny = '//itoa(self%ny)//' the map has '//itoa(int(self%nx, i8) * self%ny) &
         & //' samples, more than 2147483647 per dataset (and '//bytes_text(8.0_wp * n_quantities &
         & * real(self%nx, wp) * self%ny)//' of memory for the trace alone)', against=['scan.ny'])
      call check_integrator(self%solver, c)
      call check_verify(self%verify, c, 'nN')
      call self%thermal%validate(c)
      ! (The check is of the stepper's tolerances: the quasi-static tip
      ! follows its equilibrium without them, the Langevin schemes take a
      ! fixed step.)
      if (self%verify%enabled .and. self%model == 'quasistatic') call c%reject('verify', 'check', '.true.', &
         & "compares two integrations of the tip: model = 'quasistatic' follows the equilibrium without " &
         & //"integrating (use 'inertial' or 'overdamped')")
      if (self%verify%enabled .and. self%thermal%enabled()) call c%reject('verify', 'check', '.true.', &
         & 'compares two integrations at two tolerances: at a temperature the Langevin scheme takes a fixed ' &
         & //'time step (compare runs at two &thermal time_step values instead)')
      if (.not. c%failed() .and. self%thermal%enabled()) call check_thermal()
      if (.not. c%failed()) call warn_other_units()

   contains

      !> Values every check accepts that look like numbers in another unit
      !> (docs/input.md, Units): warnings, the run goes on.
      subroutine warn_other_units()
         real(wp), parameter :: day = 86400.0_wp
         real(wp) :: line_time

         ! Cantilevers and contacts span about 0.01 to 100 N/m.
         call spring('kx', self%kx)
         call spring('ky', self%ky)
         if (self%moves_in_3d()) call spring('kz', self%kz)
         ! A line's duration sets the cost of a tip whose motion is
         ! integrated; the quasi-static and Kramers models step from sample
         ! to sample or from jump to jump, and slow scans are what they are for.
         if (self%model == 'quasistatic' .or. (self%thermal%enabled() .and. self%thermal%reduced())) return
         line_time = (self%length + self%lead_in) / self%velocity
         if (line_time > day) call c%warn('scan', 'velocity', rtoa(self%velocity), 'a line of ' &
            & //rtoa(self%length + self%lead_in)//' angstrom takes '//rtoa(line_time)//' s of scan time at this ' &
            & //'velocity, more than a day: the unit is angstrom/s (' &
            & //rtoa(self%velocity)//' m/s = '//rtoa(self%velocity * 1.0e10_wp)//' angstrom/s)')
      end subroutine warn_other_units

      subroutine spring(name, value)
         character(len=*), intent(in) :: name
         real(wp), intent(in) :: value

         if (value > 0.0_wp .and. (value < 1.0e-3_wp .or. value > 1.0e3_wp)) call c%warn('tip', name, rtoa(value), &
            & 'far outside the springs of AFM tips, 1e-3 to 1e3 N/m: the unit is N/m (1 nN/angstrom = 10 N/m, ' &
            & //'1 eV/angstrom^2 = 16.02 N/m)')
      end subroutine spring

      subroutine lattice_constant(name, value)
         character(len=*), intent(in) :: name
         real(wp), intent(in) :: value
         character(len=:), allocatable :: hint

         hint = ''
         if (value > 0.0_wp .and. value < 1.0e-6_wp) hint = '; it looks like metres: '//rtoa(value)//' m = ' &
            & //rtoa(value * 1.0e10_wp)//' angstrom'
         if (.not. (value >= 0.01_wp)) call c%reject('surface', name, rtoa(value), &
            & 'must be >= 0.01 angstrom (a lattice constant: crystals have 2 to 6 angstrom'//hint//')')
      end subroutine lattice_constant

      !> At T > 0: a tip model with thermal motion, a heat bath on every
      !> moving axis, a surface the thermal scan supports, and a step below
      !> the Langevin integrator's stability limit.
      subroutine check_thermal()
         real(wp) :: limit
         character(len=:), allocatable :: at

         at = ' at &thermal temperature = '//rtoa(self%thermal%temperature)//' K'
         if (self%model == 'quasistatic') then
            call c%reject('tip', 'model', "'quasistatic'", 'has no thermal motion'//at//": use 'inertial' " &
               & //"or 'overdamped' (with &thermal model = 'kramers' they choose the escape rate's prefactor)")
            return
         end if
         if (self%potential == 'lj' .and. self%thermal%model == 'kramers') then
            call c%reject('thermal', 'model', "'kramers'", "is not available for potential = 'lj' (the " &
               & //"lattice-sum surface, a tip moving in 3D): use model = 'langevin'")
            return
         end if
         if (self%thermal%attempt_frequency > 0.0_wp) then
            call check_attempt_frequency()
            if (c%failed()) return
         end if
         eff = with_attempt_damping(self)
         ! Fluctuation-dissipation: the bath that heats an axis is its damper.
         if (.not. (self%cx > 0.0_wp)) call c%reject('tip', 'cx', rtoa(self%cx), 'must be > 0 (N s/m)'//at// &
            & ': the heat bath acts through the damper (fluctuation-dissipation), an undamped axis has none', &
            & against=['thermal.temperature'])
         if (.not. (self%cy > 0.0_wp)) call c%reject('tip', 'cy', rtoa(self%cy), 'must be > 0 (N s/m)'//at// &
            & ': the heat bath acts through the damper (fluctuation-dissipation), an undamped axis has none', &
            & against=['thermal.temperature'])
         ! (cz's default 0 is refused only here and for the overdamped tip: with potential = 'lj'.)
         if (self%potential == 'lj' .and. .not. (self%cz > 0.0_wp)) call c%reject('tip', 'cz', rtoa(self%cz), &
            & 'must be > 0 (N s/m)'//at//': the heat bath acts through the damper (fluctuation-dissipation), ' &
            & //'an undamped axis has none', against=[character(len=19) :: 'thermal.temperature', 'surface.potential'])
         if (.not. c%failed() .and. self%thermal%model == 'kramers') call check_kramers()
         if (c%failed() .or. self%thermal%time_step == 0.0_wp) return
         ! (Here, where the message can name the variable, not in the scan at run time.)
         if (self%nx > 1 .and. self%velocity > 0.0_wp) then
            if (max(self%length / real(self%nx - 1, wp), self%lead_in) / self%velocity / self%thermal%time_step &
               & > 1.0e9_wp) call c%reject('thermal', 'time_step', rtoa(self%thermal%time_step), 'makes more ' &
               & //'than 1e9 Langevin steps between two samples (or over the lead-in): give a longer step, or 0 ' &
               & //'to choose one')
            if (c%failed()) return
         end if
         limit = thermal_step_limit(eff)
         if (limit > 0.0_wp .and. self%thermal%time_step >= limit) call c%reject('thermal', 'time_step', &
            & rtoa(self%thermal%time_step), 'is at or above the stability limit '//rtoa(limit)//' s of the ' &
            & //'Langevin integrator (2/omega_max inertial, 2 c/k_max overdamped; 0 chooses a step)')
      end subroutine check_thermal

      !> &thermal attempt_frequency stands for the damping: not with cx or cy
      !> given too, and only where some damping gives it (attempt_damping).
      subroutine check_attempt_frequency()
         character(len=:), allocatable :: why
         real(wp) :: damping

         if (self%damping_given) then
            call c%reject('thermal', 'attempt_frequency', rtoa(self%thermal%attempt_frequency), 'is given with ' &
               & //'&tip cx or cy (cx = '//rtoa(self%cx)//', cy = '//rtoa(self%cy)//' N s/m): the attempt ' &
               & //'frequency sets the damping cx = cy (docs/physics.md, The attempt frequency); give one of them')
            return
         end if
         call attempt_damping(self, damping, why)
         if (len(why) > 0) call c%reject('thermal', 'attempt_frequency', rtoa(self%thermal%attempt_frequency), why)
      end subroutine check_attempt_frequency

      !> model = 'kramers' with the inertial tip: Kramers' rate in the
      !> spatial-diffusion regime needs the damping not weak.  Below
      !> gamma = c/m ~ omega k_B T/Delta E the escape is limited by energy
      !> diffusion (Mel'nikov-Meshkov) and the rate is too high; the model
      !> jumps deterministically below kmc_barrier_floor k_B T (1), so gamma
      !> >= omega/kmc_barrier_floor keeps every rate it uses in the regime
      !> it holds in.  omega = sqrt(k/m) with the spring along the scan, the
      !> direction the jumps go (a stiff spring across it, which keeps the
      !> tip on a row, does not take part in them).
      subroutine check_kramers()
         ! What sets omega and the damping's floor, then the switch.
         character(len=*), parameter :: kramers_partners(5) = [character(len=13) :: 'tip.mass', 'tip.kx', &
            & 'tip.ky', 'scan.angle', 'thermal.model']
         real(wp) :: omega, least, theta
         character(len=:), allocatable :: why

         if (self%model /= 'inertial') return
         theta = self%angle * pi / 180.0_wp
         omega = sqrt((self%kx * cos(theta)**2 + self%ky * sin(theta)**2) / self%mass)
         least = omega / kmc_barrier_floor
         why = "a damping for &thermal model = 'kramers' (c/m = "
         if (self%thermal%attempt_frequency > 0.0_wp) then
            ! (The damping is the attempt frequency's: the message names it.)
            if (eff%cx / self%mass < least) call c%reject('thermal', 'attempt_frequency', &
               & rtoa(self%thermal%attempt_frequency), 'stands for a damping too weak '//why//rtoa(eff%cx / self%mass) &
               & //' /s below omega = '//rtoa(least)//" /s, with the spring along the scan: escape is then limited " &
               & //"by energy diffusion, where Kramers' rate does not hold); use model = 'langevin'")
            return
         end if
         if (self%cx / self%mass < least) call c%reject('tip', 'cx', rtoa(self%cx), 'is too weak '//why &
            & //rtoa(self%cx / self%mass)//' /s below omega = '//rtoa(least)//" /s, with the spring along " &
            & //"the scan: escape is then limited by energy diffusion, where Kramers' rate does not hold); " &
            & //"use model = 'langevin'", against=kramers_partners)
         if (self%cy / self%mass < least) call c%reject('tip', 'cy', rtoa(self%cy), 'is too weak '//why &
            & //rtoa(self%cy / self%mass)//' /s below omega = '//rtoa(least)//" /s, with the spring along " &
            & //"the scan: escape is then limited by energy diffusion, where Kramers' rate does not hold); " &
            & //"use model = 'langevin'", against=kramers_partners)
      end subroutine check_kramers

      !> &fourier: finite coefficients, not all zero, and only for potential = 'fourier'.
      subroutine check_fourier()
         integer :: n

         do n = 1, max_harmonics
            if (.not. (abs(self%cosine(n)) <= huge(1.0_wp))) call c%reject('fourier', 'cosine', &
               & rtoa(self%cosine(n)), 'must be a finite number (eV)', n)
            if (.not. (abs(self%sine(n)) <= huge(1.0_wp))) call c%reject('fourier', 'sine', &
               & rtoa(self%sine(n)), 'must be a finite number (eV)', n)
         end do
         if (c%failed()) return
         n = fourier_harmonics(self)
         if (self%potential == 'fourier') then
            if (all(self%cosine == 0.0_wp) .and. all(self%sine == 0.0_wp)) call c%reject('fourier', 'cosine', &
               & '0.0', "every coefficient of &fourier is 0 (a flat surface): give at least cosine(1), the " &
               & //"amplitude V0 of -V0 cos(2 pi x/ax)", against=['surface.potential'])
         else if (self%cosine(n) /= 0.0_wp) then
            call c%reject('fourier', 'cosine', rtoa(self%cosine(n)), "is used only with &surface potential = " &
               & //"'fourier' (here '"//trim(self%potential)//"')", n)
         else if (self%sine(n) /= 0.0_wp) then
            call c%reject('fourier', 'sine', rtoa(self%sine(n)), "is used only with &surface potential = " &
               & //"'fourier' (here '"//trim(self%potential)//"')", n)
         end if
      end subroutine check_fourier

      !> The overdamped model divides by the damping of every moving direction.
      subroutine require_damped(name, value)
         character(len=*), intent(in) :: name
         real(wp), intent(in) :: value

         if (.not. (value > 0.0_wp)) call c%reject('tip', name, rtoa(value), "must be > 0 (N s/m) for " &
            & //"model = 'overdamped': c dr/dt = -k (r - r_M) - grad V has no motion without damping " &
            & //"(use 'inertial', or 'quasistatic' for the slow limit)", &
            & against=[character(len=17) :: 'tip.model', 'surface.potential'])
      end subroutine require_damped

      !> The Lennard-Jones sum and its crystal net (Eq. 3).
      subroutine check_net()
         integer :: ns, k, sites

         call c%positive('tip', 'kz', self%kz, 'N/m; the tip moves in z over a lattice sum')
         if (.not. any(net_names == self%net)) call c%reject('surface', 'net', "'"//trim(self%net)//"'", &
            & 'unknown net (known: '//quoted(net_names)//')')
         ns = species_count(self)
         if (ns == 0) call c%reject('surface', 'species', "''", 'name at least one species')
         do k = 1, ns
            if (.not. (self%sigma(k) > 0.0_wp)) call c%reject('surface', 'sigma', rtoa(self%sigma(k)), &
               & 'must be > 0 (Å) for species '//trim(self%species(k)), k, against=['surface.species'])
            if (.not. (self%epsilon(k) >= 0.0_wp)) call c%reject('surface', 'epsilon', rtoa(self%epsilon(k)), &
               & 'must be >= 0 (eV) for species '//trim(self%species(k)), k)
         end do
         if (self%cutoff < 0.0_wp) call c%reject('surface', 'cutoff', rtoa(self%cutoff), &
            & 'must be >= 0 (Å; 0 chooses it)')
         if (ns > 0 .and. self%cutoff > 0.0_wp .and. self%cutoff < maxval(self%sigma(1:max(ns, 1)))) &
            & call c%reject('surface', 'cutoff', rtoa(self%cutoff), 'must not be below sigma ('// &
            & rtoa(maxval(self%sigma(1:max(ns, 1))))//' Å): the sum would miss the repulsive core')
         call c%positive('surface', 'cutoff_tolerance', self%cutoff_tolerance, 'nN')
         if (.not. any(evaluation_names == self%evaluation)) call c%reject('surface', 'evaluation', &
            & "'"//trim(self%evaluation)//"'", 'unknown evaluation (known: '//quoted(evaluation_names)//')')
         call c%nonnegative('surface', 'table_tolerance', self%table_tolerance, 'nN; 0: cutoff_tolerance')
         select case (trim(self%net))
         case ('graphite')
            if (self%shells < 0) call c%reject('surface', 'shells', itoa(self%shells), 'must be >= 0')
         case ('square')
            if (self%side < 1) call c%reject('surface', 'side', itoa(self%side), 'must be >= 1')
         case ('file')
            if (len_trim(self%net_file) == 0) then
               call c%reject('surface', 'net_file', "''", "name an XYZ file for net = 'file'", &
                  & against=['surface.net'])
            else if (.not. file_exists(trim(self%net_file))) then
               call c%reject('surface', 'net_file', "'"//trim(self%net_file)//"'", 'no such file')
            end if
         end select
         if (c%failed()) return
         sites = net_sites(self)
         do k = 1, max_defects
            if (self%vacancies(k) < 0 .or. (sites >= 0 .and. self%vacancies(k) > sites)) &
               & call c%reject('surface', 'vacancies', itoa(self%vacancies(k)), &
               & 'site outside the net of '//itoa(sites)//' sites', k)
            if (self%substitutions(k) < 0 .or. (sites >= 0 .and. self%substitutions(k) > sites)) &
               & call c%reject('surface', 'substitutions', itoa(self%substitutions(k)), &
               & 'site outside the net of '//itoa(sites)//' sites', k)
         end do
         if (any(self%substitutions > 0) .and. .not. any(self%species(1:max(ns, 1)) == self%substitution_species)) &
            & call c%reject('surface', 'substitution_species', "'"//trim(self%substitution_species)//"'", &
            & 'not in the species table (known: '//quoted(self%species(1:max(ns, 1)))//')', &
            & against=[character(len=21) :: 'surface.substitutions', 'surface.species'])
      end subroutine check_net

   end procedure validate

end submodule friction_afm_config_checks
