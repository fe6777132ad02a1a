!> Settings of a friction-force-map scene, in the units of the namelist
!> (see docs/input.md), and the conversion to the internal model; their
!> checks are the submodule friction_afm_config_checks.
module friction_afm_config
   use friction_kinds, only: wp, pi, kg_to_internal, n_per_m_to_internal, ns_per_m_to_internal, &
      & deg_to_rad
   use friction_error, only: error_type, fatal_error, error_input
   use friction_ode_solver, only: solver_settings
   use friction_surface_potential, only: surface_potential
   use friction_surface_naf, only: new_naf_potential
   use friction_surface_hopg, only: new_hopg_potential
   use friction_surface_row, only: new_row_potential
   use friction_surface_fourier, only: new_fourier_potential, max_harmonics
   use friction_surface_net, only: crystal_net, graphite_net, square_net, read_xyz, max_local_density, sort_order, &
      & net_lattice, graphite_lattice, square_lattice, detect_lattice
   use friction_surface_lennard_jones, only: lj_potential, new_lj_potential, cutoff_for_tolerance, table_settings
   use friction_clock, only: wall_seconds
   use friction_sharing, only: work_sharing
   use friction_kinds, only: ev_per_angstrom_to_nn
   use friction_afm_tip, only: afm_tip, model_inertial, model_overdamped, model_quasistatic, find_height
   use friction_files, only: open_for_reading
   use friction_parameters, only: configurable, parameter_visitor
   use friction_checks, only: config_checker
   use friction_ode_settings, only: visit_integrator, verify_settings, visit_verify
   use friction_afm_thermal, only: thermal_settings
   use friction_afm_langevin, only: langevin_time_step, largest_curvature
   use friction_ode_auto, only: oscillator_rate, stiff_choice
   implicit none
   private

   public :: afm_config, potential_names, net_names, tip_model_names, new_potential, new_tip, new_tip_owning, &
      & net_sites, max_species, max_defects, species_count, surface_curvature, thermal_step_limit, tip_stiffness, &
      & evaluation_names, surface_evaluation, table_energy_window, table_reach, scan_region, auto_method
   public :: attempt_damping, with_attempt_damping
   public :: surface_naf, surface_hopg, surface_lattice_sum, surface_row, surface_fourier, fourier_harmonics

   !> &surface potential as a kind (afm_config's surface_kind): the analytic
   !> NaF (Eq. 1) and HOPG (Eq. 2) surfaces, the Lennard-Jones lattice sum (Eq. 3),
   !> a one-dimensional row -V0 cos(2πx/ax) (friction_surface_row), a
   !> one-dimensional Fourier series along x (friction_surface_fourier).
   integer, parameter :: surface_naf = 1, surface_hopg = 2, surface_lattice_sum = 3, surface_row = 4, &
      & surface_fourier = 5

   character(len=*), parameter :: potential_names(5) = [character(len=7) :: 'naf', 'hopg', 'lj', 'row', 'fourier']
   character(len=*), parameter :: net_names(3) = [character(len=8) :: 'graphite', 'square', 'file']
   !> &surface evaluation of a lattice sum: interpolated from a table of the
   !> perfect lattice (where it meets table_tolerance), or the direct sum.
   character(len=*), parameter :: evaluation_names(2) = [character(len=6) :: 'table', 'direct']
   !> The table answers where the perfect lattice's energy is at most this
   !> much above its minimum, eV (docs/physics.md, The tabulated surface):
   !> 4 times the most the paper's undamped tip climbs at its samples (0.073 eV
   !> above the minimum, inputs/graphite.nml), 12 k_B T at 300 K.  Higher, nearer the
   !> atoms' cores, the direct sum answers: correct, only slower.
   real(wp), parameter :: table_energy_window = 0.3_wp
   !> How far beyond its support's scan box the table serves the tip, Å (the
   !> cell list's reach less the cutoff: new_potential); farther, the direct sum.
   real(wp), parameter :: table_reach = 10.0_wp
   !> &tip model: the full equations of motion, without inertia, or the
   !> equilibrium followed (docs/physics.md, reduced tip models).
   character(len=*), parameter :: tip_model_names(3) = [character(len=11) :: 'inertial', 'overdamped', &
      & 'quasistatic']
   integer, parameter :: max_species = 8, max_defects = 64

   type, extends(configurable) :: afm_config
      ! &surface
      character(len=16) :: potential = 'naf'  !! 'naf' (Eq. 1) or 'hopg' (Eq. 2)
      real(wp) :: v0 = 1.0_wp          !! potential amplitude, eV
      real(wp) :: ax = 4.62_wp         !! NaF period along x, Å
      real(wp) :: ay = 4.62_wp         !! NaF period along y, Å
      real(wp) :: a = 2.46_wp          !! HOPG, graphite or square-net lattice constant, Å
      ! &surface, Lennard-Jones sum over a crystal net (Eq. 3)
      character(len=16) :: net = 'graphite'   !! 'graphite', 'square' or 'file'
      character(len=1024) :: net_file = ''    !! XYZ file when net = 'file'
      integer :: shells = 9            !! graphite: hexagon shells around the central ring
      integer :: side = 20             !! square: atoms per edge
      !> Tip–atom pair parameters by species (Sasaki et al. for carbon); a
      !> blank name ends the table.
      character(len=8) :: species(max_species) = [character(len=8) :: 'C', '', '', '', '', '', '', '']
      real(wp) :: epsilon(max_species) = [0.87381e-2_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp]
      real(wp) :: sigma(max_species) = [2.4945_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp]
      integer :: vacancies(max_defects) = 0       !! site numbers (1-based); 0 unused
      integer :: substitutions(max_defects) = 0   !! site numbers (1-based); 0 unused
      character(len=8) :: substitution_species = ''
      real(wp) :: cutoff = 0.0_wp            !! Å; 0: from cutoff_tolerance
      real(wp) :: cutoff_tolerance = 1.0e-4_wp   !! largest force of the atoms beyond the cutoff, nN
      character(len=16) :: evaluation = 'table'   !! 'table' or 'direct'
      real(wp) :: table_tolerance = 0.0_wp       !! largest force error of the table, nN; 0: cutoff_tolerance
      ! &fourier: V = -Σ_n [cosine(n) cos(2πnx/ax) + sine(n) sin(2πnx/ax)] for potential = 'fourier'
      real(wp) :: cosine(max_harmonics) = 0.0_wp   !! eV
      real(wp) :: sine(max_harmonics) = 0.0_wp     !! eV
      ! &tip
      character(len=16) :: model = 'inertial'   !! 'inertial', 'overdamped' or 'quasistatic'
      real(wp) :: mass = 1.0e-8_wp     !! kg
      !> whether mass was set (from a file, --set, a sweep or the C API): the
      !> overdamped model has no mass, and its check of the damping ratio
      !> uses only a mass given for the tip, never the default
      logical :: mass_given = .false.
      !> whether cx or cy was set: &thermal attempt_frequency stands for them
      logical :: damping_given = .false.
      real(wp) :: kx = 10.0_wp         !! N/m
      real(wp) :: ky = 10.0_wp         !! N/m
      real(wp) :: cx = 1.0e-3_wp       !! N s/m
      real(wp) :: cy = 1.0e-3_wp       !! N s/m
      real(wp) :: kz = 0.25_wp         !! N/m (three-dimensional potentials)
      real(wp) :: cz = 0.0_wp          !! N s/m
      real(wp) :: support_z = 0.0_wp   !! support height from the contact height, Å
      ! &scan
      real(wp) :: velocity = 400.0_wp  !! support speed, Å/s
      real(wp) :: length = 20.0_wp     !! along the scan direction, Å
      real(wp) :: width = 20.0_wp      !! across, Å
      real(wp) :: angle = 0.0_wp       !! scan direction from the lattice x axis, degrees
      real(wp) :: origin_x = 0.0_wp    !! first point of the first line, Å (lattice frame)
      real(wp) :: origin_y = 0.0_wp
      real(wp) :: lead_in = 0.0_wp     !! support travel before the first sample, Å
      !> wall time between checkpoints of finished lines, s (0: every line);
      !> a map shorter than this writes none
      real(wp) :: checkpoint_interval = 60.0_wp
      integer :: nx = 128              !! sample points per line
      integer :: ny = 128              !! lines
      logical :: retrace = .true.      !! scan every line back as well
      ! &integrator
      type(solver_settings) :: solver
      ! &verify: the map integrated again and its forces compared
      type(verify_settings) :: verify
      ! &thermal
      type(thermal_settings) :: thermal
   contains
      procedure :: visit
      procedure :: validate
      procedure :: surface_kind
      procedure :: tip_model
      procedure :: moves_in_3d
      procedure :: scan_direction
      procedure :: across_direction
   end type afm_config

   !> How a lattice sum is evaluated (docs/output.md, /surface): the table's
   !> size and its error measured against the direct sum, or why not.
   type :: surface_evaluation
      character(len=:), allocatable :: evaluation   !! what runs: 'table' or 'direct'
      character(len=:), allocatable :: note         !! why the direct sum, when the table was asked for
      real(wp) :: tolerance = 0.0_wp                !! the table's bound, nN
      real(wp) :: error = 0.0_wp                    !! the largest force error measured, nN
      integer :: points = 0                         !! points it was measured at
      real(wp) :: bytes = 0.0_wp                    !! memory of the table
      integer :: nodes(3) = 0                       !! nodes along a1 and a2 per cell, layers
      real(wp) :: spacing = 0.0_wp                  !! the larger lateral node spacing, Å
      real(wp) :: floor = 0.0_wp                    !! the lowest layer, Å
      real(wp) :: energy_window = 0.0_wp            !! eV
      integer :: differences = 0                    !! atoms where the net differs from the lattice
      real(wp) :: build_time = 0.0_wp               !! s (this rank's)
   end type surface_evaluation

   interface
      !> Every value of the map's groups, or the first bad one to `c`
      !> (friction_afm_config_checks).
      module subroutine validate(self, c)
         class(afm_config), intent(in) :: self
         type(config_checker), intent(inout) :: c
      end subroutine validate
   end interface

contains

   !> The groups &surface, &tip, &scan, &integrator and &thermal (docs/input.md).
   subroutine visit(self, v)
      class(afm_config), intent(inout) :: self
      type(parameter_visitor), intent(inout) :: v
      logical :: given

      call v%begin_group('surface')
      call v%item('potential', self%potential, fold=.true.)
      call v%item('v0', self%v0, 'eV')
      call v%item('ax', self%ax, 'angstrom')
      call v%item('ay', self%ay, 'angstrom')
      call v%item('a', self%a, 'angstrom')
      call v%item('net', self%net, fold=.true.)
      call v%item('net_file', self%net_file, path=.true.)
      call v%item('shells', self%shells)
      call v%item('side', self%side)
      call v%item('species', self%species)
      call v%item('epsilon', self%epsilon, 'eV')
      call v%item('sigma', self%sigma, 'angstrom')
      call v%item('vacancies', self%vacancies)
      call v%item('substitutions', self%substitutions)
      call v%item('substitution_species', self%substitution_species)
      call v%item('cutoff', self%cutoff, 'angstrom')
      call v%item('cutoff_tolerance', self%cutoff_tolerance, 'nN')
      call v%item('evaluation', self%evaluation, fold=.true.)
      call v%item('table_tolerance', self%table_tolerance, 'nN')
      call v%end_group()
      ! (A group of its own, echoed only for potential = 'fourier' (afm_groups),
      ! so the other surfaces' echoed input is what it was.)
      call v%begin_group('fourier')
      call v%item('cosine', self%cosine, 'eV')
      call v%item('sine', self%sine, 'eV')
      call v%end_group()
      call v%begin_group('tip')
      call v%item('model', self%model, fold=.true.)
      given = v%found
      call v%item('mass', self%mass, 'kg')
      if (v%setting() .and. v%found .and. .not. given) self%mass_given = .true.
      call v%item('kx', self%kx, 'N/m')
      call v%item('ky', self%ky, 'N/m')
      call v%item('kz', self%kz, 'N/m')
      given = v%found
      call v%item('cx', self%cx, 'N s/m')
      call v%item('cy', self%cy, 'N s/m')
      if (v%setting() .and. v%found .and. .not. given) self%damping_given = .true.
      call v%item('cz', self%cz, 'N s/m')
      call v%item('support_z', self%support_z, 'angstrom')
      call v%end_group()
      call v%begin_group('scan')
      call v%item('velocity', self%velocity, 'angstrom/s')
      call v%item('length', self%length, 'angstrom')
      call v%item('width', self%width, 'angstrom')
      call v%item('angle', self%angle, 'degree')
      call v%item('origin_x', self%origin_x, 'angstrom')
      call v%item('origin_y', self%origin_y, 'angstrom')
      call v%item('lead_in', self%lead_in, 'angstrom')
      call v%item('nx', self%nx)
      call v%item('ny', self%ny)
      call v%item('retrace', self%retrace)
      call v%item('checkpoint_interval', self%checkpoint_interval, 's')
      call v%end_group()
      call visit_integrator(self%solver, v, 's')
      call visit_verify(self%verify, v, 'state units', 'nN')
      call self%thermal%visit(v)
   end subroutine visit

   !> Unit vector along the scan, lattice frame.
   pure function scan_direction(self) result(u)
      class(afm_config), intent(in) :: self
      real(wp) :: u(3)

      u = [cos(self%angle * deg_to_rad), sin(self%angle * deg_to_rad), 0.0_wp]
   end function scan_direction

   !> Unit vector across the scan (the scan direction turned by +90°).
   pure function across_direction(self) result(n)
      class(afm_config), intent(in) :: self
      real(wp) :: n(3)

      n = [-sin(self%angle * deg_to_rad), cos(self%angle * deg_to_rad), 0.0_wp]
   end function across_direction

   !> Species in use: the names before the first blank one.
   pure integer function species_count(config)
      type(afm_config), intent(in) :: config

      do species_count = 0, max_species - 1
         if (len_trim(config%species(species_count + 1)) == 0) return
      end do
      species_count = max_species
   end function species_count

   !> The harmonics of &fourier in use: up to the last nonzero coefficient (at least 1).
   pure integer function fourier_harmonics(config) result(n)
      type(afm_config), intent(in) :: config

      do n = max_harmonics, 2, -1
         if (config%cosine(n) /= 0.0_wp .or. config%sine(n) /= 0.0_wp) return
      end do
      n = 1
   end function fourier_harmonics

   !> Number of sites of the net the settings describe (before vacancies),
   !> without building it; -1 if an XYZ file cannot tell.
   function net_sites(config) result(n)
      type(afm_config), intent(in) :: config
      integer :: n, unit, stat
      type(error_type), allocatable :: error

      select case (trim(config%net))
      case ('graphite')
         n = 6 * (config%shells + 1)**2
      case ('square')
         n = config%side**2
      case default
         n = -1
         ! (A regular file only, as the net's reader opens it, which says
         ! what is wrong with another: a pipe would be used up, a device read
         ! forever.)
         call open_for_reading(trim(config%net_file), unit, error)
         if (allocated(error)) return
         read (unit, *, iostat=stat) n
         if (stat /= 0) n = -1
         close (unit)
      end select
   end function net_sites

   !> The crystal net with its defects.
   subroutine new_net(config, net, error)
      type(afm_config), intent(in) :: config
      type(crystal_net), intent(out) :: net
      type(error_type), allocatable, intent(out) :: error
      logical, allocatable :: vacant(:)
      integer :: substitute

      select case (trim(config%net))
      case ('graphite')
         net = graphite_net(config%a, config%shells)
      case ('square')
         net = square_net(config%a, config%side)
      case default
         call read_xyz(trim(config%net_file), config%species(1:species_count(config)), net, error)
         if (allocated(error)) return
      end select
      ! Substitutions first: site numbers refer to the net before vacancies.
      if (any(config%substitutions > 0)) then
         substitute = findloc(config%species, config%substitution_species, dim=1)
         call net%substitute(pack(config%substitutions, config%substitutions > 0), substitute)
      end if
      allocate (vacant(net%size()))
      vacant = .false.
      vacant(pack(config%vacancies, config%vacancies > 0)) = .true.
      call net%remove_sites(vacant)
   end subroutine new_net

   !> Atoms per Å² for the cutoff's error bound (cutoff_for_tolerance): the
   !> density within 8 Å of the net's middle (the median of the atoms'
   !> positions, which a far stray atom does not move, unlike the centroid),
   !> or the largest density over discs of 8 Å around its atoms if that is
   !> larger, so that the bound holds for any net.  (The density of the
   !> bounding box, used before for small nets, let one far atom shrink the
   !> cutoff.)
   pure real(wp) function net_density(net) result(density)
      type(crystal_net), intent(in) :: net
      real(wp), parameter :: radius = 8.0_wp
      real(wp) :: centre(2)
      integer :: inside, i, k, n
      integer, allocatable :: order(:)

      n = net%size()
      do k = 1, 2
         order = sort_order(net%position(k, :))
         centre(k) = 0.5_wp * (net%position(k, order((n + 1) / 2)) + net%position(k, order(n / 2 + 1)))
      end do
      inside = 0
      do i = 1, n
         if (sum((net%position(1:2, i) - centre)**2) < radius**2) inside = inside + 1
      end do
      density = max(inside / (pi * radius**2), max_local_density(net, radius))
   end function net_density

   !> The box (x_min, x_max, y_min, y_max, Å) of every support position of
   !> the map, widened by `margin` (the cutoff and the tip's excursion from
   !> its support): where the tip can reach atoms.
   pure function scan_region(config, margin) result(box)
      type(afm_config), intent(in) :: config
      real(wp), intent(in) :: margin
      real(wp) :: box(4)
      real(wp) :: corner(2, 4), along(3), across(3)

      along = config%scan_direction()
      across = config%across_direction()
      corner(:, 1) = [config%origin_x, config%origin_y] - config%lead_in * along(1:2)
      corner(:, 2) = corner(:, 1) + (config%length + 2.0_wp * config%lead_in) * along(1:2)
      corner(:, 3) = corner(:, 1) + config%width * across(1:2)
      corner(:, 4) = corner(:, 2) + config%width * across(1:2)
      box = [minval(corner(1, :)) - margin, maxval(corner(1, :)) + margin, &
         & minval(corner(2, :)) - margin, maxval(corner(2, :)) + margin]
   end function scan_region

   !> The surface potential the settings name; for a lattice sum also the
   !> net (for the output), the cutoff used and how it is evaluated.
   subroutine new_potential(config, potential, error, net, cutoff, evaluation, share)
      type(afm_config), intent(in) :: config
      class(surface_potential), allocatable, intent(out) :: potential
      type(error_type), allocatable, intent(out) :: error
      type(crystal_net), intent(out), optional :: net
      real(wp), intent(out), optional :: cutoff
      type(surface_evaluation), intent(out), optional :: evaluation
      !> the processes that build the same potential together (a lattice
      !> sum's table: collective over them); absent, this process alone
      class(work_sharing), intent(inout), optional :: share
      type(crystal_net) :: atoms
      type(surface_evaluation) :: how
      real(wp) :: rc
      integer :: ns

      select case (trim(config%potential))
      case ('naf')
         allocate (potential, source=new_naf_potential(config%v0, config%ax, config%ay))
      case ('hopg')
         allocate (potential, source=new_hopg_potential(config%v0, config%a))
      case ('row')
         allocate (potential, source=new_row_potential(config%v0, config%ax))
      case ('fourier')
         ns = fourier_harmonics(config)
         allocate (potential, source=new_fourier_potential(config%cosine(1:ns), config%sine(1:ns), config%ax))
      case ('lj')
         call new_net(config, atoms, error)
         if (allocated(error)) return
         if (atoms%size() == 0) then
            call fatal_error(error, 'the crystal net has no atoms left', error_input)
            return
         end if
         ns = species_count(config)
         rc = config%cutoff
         if (rc <= 0.0_wp) rc = cutoff_for_tolerance(maxval(config%epsilon(1:ns) * config%sigma(1:ns)**6), &
            & 1.0_wp, net_density(atoms), config%cutoff_tolerance / ev_per_angstrom_to_nn)
         ! (Built where it stays: a copy of a table costs as much as a good
         ! part of its build.)
         allocate (lj_potential :: potential)
         select type (lattice_sum => potential)
         type is (lj_potential)
            lattice_sum = new_lj_potential(atoms, config%epsilon(1:ns), config%sigma(1:ns), rc, &
               & scan_region(config, rc + table_reach))
            how%evaluation = 'direct'
            how%note = ''
            if (config%evaluation == 'table') call tabulate_net(config, atoms, lattice_sum, how, share)
         end select
         if (present(net)) net = atoms
         if (present(cutoff)) cutoff = rc
         if (present(evaluation)) evaluation = how
      case default
         call fatal_error(error, "unknown potential '"//trim(config%potential)//"'", error_input)
      end select
   end subroutine new_potential

   !> The table of a lattice sum (docs/physics.md, The tabulated surface),
   !> recorded in `how`; when the net has no lattice to tabulate or the table
   !> cannot meet its tolerance within its memory, the direct sum, and
   !> how%note says why.
   subroutine tabulate_net(config, atoms, lattice_sum, how, share)
      type(afm_config), intent(in) :: config
      type(crystal_net), intent(in) :: atoms
      type(lj_potential), intent(inout) :: lattice_sum
      type(surface_evaluation), intent(inout) :: how
      class(work_sharing), intent(inout), optional :: share
      type(net_lattice) :: lattice
      type(table_settings) :: settings
      character(len=:), allocatable :: reason
      real(wp) :: start

      start = wall_seconds()
      how%tolerance = config%table_tolerance
      if (how%tolerance <= 0.0_wp) how%tolerance = config%cutoff_tolerance
      select case (trim(config%net))
      case ('graphite')
         lattice = graphite_lattice(config%a)
      case ('square')
         lattice = square_lattice(config%a, config%side)
      case default
         call detect_lattice(atoms, lattice, reason)
         if (len(reason) > 0) then
            how%note = 'no lattice found in '//trim(config%net_file)//' ('//reason//')'
            return
         end if
      end select
      settings%tolerance = how%tolerance / ev_per_angstrom_to_nn
      settings%energy_window = table_energy_window
      settings%box = scan_region(config, table_reach)
      call lattice_sum%tabulate(lattice, settings, reason, share)
      how%build_time = wall_seconds() - start
      if (len(reason) > 0) then
         how%note = reason
         return
      end if
      associate (t => lattice_sum%table)
         how%evaluation = 'table'
         how%error = t%error * ev_per_angstrom_to_nn
         how%points = t%points
         how%bytes = t%grid%bytes()
         how%nodes = t%nodes
         how%spacing = max(norm2(t%vectors(:, 1)) / t%nodes(1), norm2(t%vectors(:, 2)) / t%nodes(2))
         how%floor = t%floor
         how%energy_window = t%energy_window
         how%differences = t%difference_count
      end associate
   end subroutine tabulate_net

   !> The largest curvature of the surface (eV/Å², >= 0) over one lattice
   !> cell, the Langevin step's scale (friction_afm_langevin): NaF over
   !> ax × ay, HOPG over the rectangular cell a × a√3, on 32² points; for a
   !> lattice sum (3D, its largest Hessian eigenvalue) over the scan's
   !> bounding box in the plane and from the loaded tip's rest height above
   !> the origin down 0.2 Å (three thermal spreads sqrt(k_B T/k_zz) at 300 K
   !> on graphite: the wall is what is stiff), on 12³ points; 0 when that
   !> height cannot be found (the run reports why).
   function surface_curvature(config, potential) result(curvature)
      type(afm_config), intent(in) :: config
      class(surface_potential), intent(in) :: potential
      real(wp) :: curvature
      type(afm_tip) :: tip
      type(error_type), allocatable :: error
      real(wp) :: origin(3), corners(3, 4), contact, rest
      integer :: k

      select case (trim(config%potential))
      case ('naf')
         curvature = largest_curvature(potential, [0.0_wp, 0.0_wp], [config%ax, config%ay], 32)
      case ('hopg')
         curvature = largest_curvature(potential, [0.0_wp, 0.0_wp], [config%a, sqrt(3.0_wp) * config%a], 32)
      case ('row')
         curvature = largest_curvature(potential, [0.0_wp, 0.0_wp], [config%ax, config%ax], 32)
      case ('fourier')
         ! (32 points per period of the highest harmonic; one harmonic samples as the row does.)
         curvature = largest_curvature(potential, [0.0_wp, 0.0_wp], [config%ax, config%ax], &
            & 32 * fourier_harmonics(config))
      case ('lj')
         curvature = 0.0_wp
         origin = [config%origin_x, config%origin_y, 0.0_wp]
         call new_tip(config, potential, tip)
         call find_height(tip, origin, 0.0_wp, contact, error)
         if (.not. allocated(error)) call find_height(tip, [origin(1), origin(2), contact + config%support_z], &
            & tip%spring(3), rest, error)
         if (allocated(error)) return
         do k = 1, 4
            corners(:, k) = origin + merge(config%length, 0.0_wp, k == 2 .or. k == 4) * config%scan_direction() &
               & + merge(config%width, 0.0_wp, k >= 3) * config%across_direction()
         end do
         curvature = max(largest_curvature(potential, [minval(corners(1, :)), minval(corners(2, :)), &
            & rest - 0.2_wp], [maxval(corners(1, :)), maxval(corners(2, :)), rest], 12), 0.0_wp)
      case default
         curvature = 0.0_wp
      end select
   end function surface_curvature

   !> The stability limit of the Langevin step for the settings' tip and
   !> surface, s (0 when it cannot be told: a surface or tip that does not
   !> build).
   function thermal_step_limit(config) result(limit)
      type(afm_config), intent(in) :: config
      real(wp) :: limit
      class(surface_potential), allocatable :: potential
      type(afm_config) :: exact
      type(afm_tip) :: tip
      type(error_type), allocatable :: error
      real(wp) :: dt

      limit = 0.0_wp
      ! (The curvature from the lattice sum itself: a table would be built
      ! for this check alone, most of a small thermal run's set-up and once
      ! per sweep point, and the sum is the quantity the table approximates.)
      exact = config
      exact%evaluation = 'direct'
      call new_potential(exact, potential, error)
      if (allocated(error)) return
      call new_tip_owning(config, potential, tip)
      call langevin_time_step(tip, surface_curvature(config, tip%potential), dt, limit, error)
      if (allocated(error)) limit = 0.0_wp
   end function thermal_step_limit

   !> The stepper method = 'auto' runs: an implicit one where the tip is stiff
   !> (friction_ode_auto's rules on tip_stiffness), else the explicit pair the
   !> surface's work-precision chart shows fastest at this rtol (docs/speed.md).
   function auto_method(config) result(method)
      type(afm_config), intent(in) :: config
      character(len=16) :: method
      real(wp) :: rtol

      rtol = config%solver%rtol
      method = stiff_choice(rtol, tip_stiffness(config))
      if (len_trim(method) > 0) return
      select case (config%surface_kind())
      case (surface_hopg)
         method = merge('rkck ', 'rk8pd', rtol >= 1.0e-6_wp)
      case (surface_lattice_sum)
         method = 'rk8pd'
      case default
         method = merge('rkck ', 'rk8pd', rtol >= 1.0e-7_wp)
      end select
   end function auto_method

   !> The stiffness S of the scan for method = 'auto' (friction_ode_auto):
   !> the largest decay rate of the tip linearised anywhere on the surface
   !> times the time between two samples.  Per direction the rate is that of
   !> the damped oscillator whose spring k_i is softened or stiffened by the
   !> surface's largest curvature (either sign: the tip also crosses
   !> maxima); the quasistatic model, which takes no steps of the motion,
   !> and the Lennard-Jones sums, whose curvature is not bounded here, give
   !> 0 (not known).
   function tip_stiffness(config) result(stiffness)
      type(afm_config), intent(in) :: config
      real(wp) :: stiffness
      class(surface_potential), allocatable :: potential
      type(afm_tip) :: tip
      type(error_type), allocatable :: error
      real(wp) :: curvature, rate, sample_time
      integer :: i

      stiffness = 0.0_wp
      if (config%tip_model() == model_quasistatic .or. config%moves_in_3d()) return
      if (config%nx < 2 .or. .not. config%velocity > 0.0_wp) return
      call new_potential(config, potential, error)
      if (allocated(error)) return
      call new_tip(config, potential, tip)
      curvature = surface_curvature(config, potential)
      rate = 0.0_wp
      do i = 1, tip%ndim
         rate = max(rate, oscillator_rate(merge(tip%mass, 0.0_wp, tip%model == model_inertial), &
            & tip%damping(i), tip%spring(i) - curvature, tip%spring(i) + curvature))
      end do
      sample_time = config%length / real(config%nx - 1, wp) / config%velocity
      stiffness = rate * sample_time
   end function tip_stiffness

   !> The tip model in internal units around a potential; the support path
   !> is set per trip.  The quasistatic model uses the damping only to relax
   !> the tip into a new minimum after a jump (friction_afm_deterministic_trip): with
   !> damping in every moving direction that is the overdamped motion at a
   !> fixed support; with none in some direction, plain steepest descent of
   !> the total energy (the same damping, 1e-3 N s/m, in every direction).
   subroutine new_tip(config, potential, tip)
      type(afm_config), intent(in) :: config
      class(surface_potential), intent(in) :: potential
      type(afm_tip), intent(out) :: tip

      allocate (tip%potential, source=potential)
      call set_up_tip(config, tip)
   end subroutine new_tip

   !> new_tip, the tip taking `potential` over (deallocated on return)
   !> instead of a copy: a tabulated surface is megabytes.
   subroutine new_tip_owning(config, potential, tip)
      type(afm_config), intent(in) :: config
      class(surface_potential), allocatable, intent(inout) :: potential
      type(afm_tip), intent(out) :: tip

      call move_alloc(potential, tip%potential)
      call set_up_tip(config, tip)
   end subroutine new_tip_owning

   !> &surface potential as a kind (surface_naf, surface_hopg or
   !> surface_lattice_sum); the names are compared here and in the checks only.
   pure integer function surface_kind(self) result(kind)
      class(afm_config), intent(in) :: self

      select case (trim(self%potential))
      case ('hopg')
         kind = surface_hopg
      case ('lj')
         kind = surface_lattice_sum
      case ('row')
         kind = surface_row
      case ('fourier')
         kind = surface_fourier
      case default
         kind = surface_naf
      end select
   end function surface_kind

   !> &tip model as a kind (friction_afm_tip's model_inertial,
   !> model_overdamped or model_quasistatic).
   pure integer function tip_model(self) result(kind)
      class(afm_config), intent(in) :: self

      select case (trim(self%model))
      case ('overdamped')
         kind = model_overdamped
      case ('quasistatic')
         kind = model_quasistatic
      case default
         kind = model_inertial
      end select
   end function tip_model

   !> Whether the surface moves the tip in three dimensions (the lattice sum:
   !> the tip's height is free), so the tip has a z axis with its spring and damper.
   pure logical function moves_in_3d(self)
      class(afm_config), intent(in) :: self

      moves_in_3d = self%surface_kind() == surface_lattice_sum
   end function moves_in_3d

   !> The damping c (N s/m, on x and y alike) for which the Kramers rate of
   !> the tip model has the prefactor f0 = &thermal attempt_frequency
   !> (docs/physics.md, The attempt frequency): for the tip at rest in a
   !> well of the surface's cut along the scan, with K the surface's
   !> curvature along the scan at its minimum at the origin and k the spring
   !> along the scan, the well's curvature is K + k and the barrier top's
   !> k - K.  Overdamped (Smoluchowski): f0 = sqrt(K**2 - k**2)/(2 pi c);
   !> inertial (Kramers, moderate to strong friction): f0 = (omega_w/(2 pi
   !> omega_b)) lambda, lambda = sqrt(gamma**2/4 + omega_b**2) - gamma/2,
   !> gamma = c/m, solved for gamma.  `why` is empty, or says why no
   !> damping gives f0 (then damping is 0).
   subroutine attempt_damping(config, damping, why)
      type(afm_config), intent(in) :: config
      real(wp), intent(out) :: damping
      character(len=:), allocatable, intent(out) :: why
      class(surface_potential), allocatable :: potential
      type(error_type), allocatable :: error
      real(wp) :: h(3, 3), d(3), curvature, spring, f0, omega_w, omega_b, lambda
      character(len=16) :: text

      damping = 0.0_wp
      why = ''
      f0 = config%thermal%attempt_frequency
      if (config%moves_in_3d()) then
         why = "stands for the damping of a tip in the well of a two-dimensional surface: not for potential = 'lj' " &
            & //'(give cx, cy and cz)'
         return
      end if
      call new_potential(config, potential, error)
      if (allocated(error)) then
         why = 'cannot be turned into a damping: '//error%message
         return
      end if
      call potential%hessian([0.0_wp, 0.0_wp, 0.0_wp], h)
      d = config%scan_direction()
      ! (N/m: the internal spring unit's factor is the damping's.)
      curvature = dot_product(d(1:2), matmul(h(1:2, 1:2), d(1:2))) / n_per_m_to_internal
      spring = config%kx * d(1)**2 + config%ky * d(2)**2
      if (.not. (curvature > spring)) then
         write (text, '(es12.5)') curvature
         why = 'has no barrier to stand for: the surface''s curvature along the scan at its minimum, K = ' &
            & //trim(adjustl(text))//' N/m, is not above the spring along the scan ('
         write (text, '(es12.5)') spring
         why = why//trim(adjustl(text))//' N/m), so the tip at rest does not sit in a well with a barrier'
         return
      end if
      if (config%tip_model() == model_inertial) then
         omega_w = sqrt((curvature + spring) / config%mass)
         omega_b = sqrt((curvature - spring) / config%mass)
         lambda = 2.0_wp * pi * f0 * omega_b / omega_w
         if (.not. (lambda < omega_b)) then
            write (text, '(es12.5)') omega_w / (2.0_wp * pi)
            why = 'is at or above the inertial tip''s highest prefactor, its frequency in the well ' &
               & //'sqrt((K + k)/m)/(2 pi) = '//trim(adjustl(text))//' Hz (no damping)'
            return
         end if
         damping = config%mass * (omega_b**2 - lambda**2) / lambda
      else
         damping = sqrt((curvature - spring) * (curvature + spring)) / (2.0_wp * pi * f0)
      end if
   end subroutine attempt_damping

   !> The settings with cx = cy the damping &thermal attempt_frequency stands
   !> for, at a temperature when it is given (unchanged otherwise, or when
   !> it stands for none: the checks say why).
   function with_attempt_damping(config) result(c)
      type(afm_config), intent(in) :: config
      type(afm_config) :: c
      character(len=:), allocatable :: why
      real(wp) :: damping

      c = config
      if (.not. (config%thermal%enabled() .and. config%thermal%attempt_frequency > 0.0_wp)) return
      call attempt_damping(config, damping, why)
      if (len(why) > 0) return
      c%cx = damping
      c%cy = damping
   end function with_attempt_damping

   !> The tip's model and constants around its potential (new_tip).
   subroutine set_up_tip(config, tip)
      type(afm_config), intent(in) :: config
      type(afm_tip), intent(inout) :: tip

      tip%ndim = tip%potential%dimensions()
      tip%mass = config%mass * kg_to_internal
      tip%spring = [config%kx, config%ky, config%kz] * n_per_m_to_internal
      tip%damping = [config%cx, config%cy, config%cz] * ns_per_m_to_internal
      tip%model = config%tip_model()
      if (tip%model == model_quasistatic .and. .not. all(tip%damping(1:tip%ndim) > 0.0_wp)) &
         & tip%damping = 1.0e-3_wp * ns_per_m_to_internal
   end subroutine set_up_tip

end module friction_afm_config
