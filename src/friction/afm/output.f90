!> The friction-force-map file (docs/output.md).  Collective: all
!> ranks call it; each passes the block of lines it computed.
module friction_afm_output
   use friction_parallel, only: communicator
   use friction_kinds, only: wp, i8
   use friction_error, only: error_type
   use friction_ode_solver, only: integrator_statistics
   use friction_afm_config, only: afm_config, surface_evaluation, surface_fourier
   use friction_afm_shape, only: write_shape
   use friction_afm_trip, only: quantity_names, quantity_units, quantity_count, q_f_along, q_jumps, &
      & support_along, support_across
   use friction_output_h5, only: h5_file
   use friction_output_parameters, only: write_parameter_attributes
   use friction_output_summary, only: run_summary, write_run_attributes
   use friction_surface_net, only: crystal_net
   use friction_afm_tip, only: model_quasistatic
   use friction_strings, only: join
   use friction_afm_loop, only: loop_forces
   implicit none
   private

   public :: write_afm_file, line_friction, afm_surface_record, afm_thermal_record, afm_verify_record

   !> The sample of a lattice-sum scene, for pictures that overlay it.
   type :: afm_surface_record
      type(crystal_net) :: net
      character(len=8), allocatable :: species_names(:)
      real(wp) :: cutoff = 0.0_wp           !! Å
      real(wp) :: contact_height = 0.0_wp   !! Å
      real(wp) :: support_height = 0.0_wp   !! Å
      type(surface_evaluation) :: evaluation   !! the table, or the direct sum
   end type afm_surface_record

   !> A map at a temperature (README: Friction at a temperature): this
   !> rank's standard errors over the realizations, of every sample
   !> (trace_sem(:, j, q) beside trace(:, j, q)) and of every line's
   !> friction; the Langevin step and scheme.
   type :: afm_thermal_record
      real(wp), allocatable :: trace_sem(:, :, :), retrace_sem(:, :, :)
      real(wp), allocatable :: friction_sem(:)
      real(wp) :: time_step = 0.0_wp
      character(len=:), allocatable :: scheme
      !> every rank's slips, the same on every rank: line, realization,
      !> trip, support (Å), force (nN), jump along and across (Å), and the
      !> reduced model's barrier (eV) and prefactor (1/s) for each
      real(wp), allocatable :: slips(:, :)
   end type afm_thermal_record

   !> &verify: the check run's stepper settings, the largest difference of
   !> each force component between the map and the check run over every
   !> sample of both trips (fz: 3D tips), and the check run's right-hand
   !> sides, all ranks'.
   type :: afm_verify_record
      logical :: enabled = .false.
      character(len=16) :: method = ''
      real(wp) :: rtol = 0.0_wp, atol = 0.0_wp
      real(wp) :: max_difference(3) = 0.0_wp   !! fx, fy, fz; nN
      integer(i8) :: rhs_evaluations = 0
   end type afm_verify_record


contains

   !> Friction of each line: half the difference of the mean force along
   !> the scan on trace and retrace (docs/physics.md, Scan geometry, trips and the lateral force), nN.
   pure function line_friction(trace, retrace) result(friction)
      real(wp), intent(in) :: trace(:, :, :), retrace(:, :, :)
      real(wp) :: friction(size(trace, 2))
      integer :: j, nx

      nx = size(trace, 1)
      do j = 1, size(trace, 2)
         friction(j) = 0.5_wp * (sum(trace(:, j, q_f_along)) - sum(retrace(:, j, q_f_along))) / nx
      end do
   end function line_friction

   !> Write the scan.  trace(:, j, q) holds quantity q of local line j, which
   !> is line first + (j - 1) * stride of the map (0-based); retrace likewise
   !> when config%retrace.  At a temperature trace and retrace are the means
   !> over the realizations, and `thermal` holds their standard errors: each
   !> dataset NAME gets NAME_sem beside it, /afm/friction (the mean) gets
   !> /afm/friction_sem, and /afm the attributes temperature, seed,
   !> realizations, time_step (the Langevin step used) and scheme; and the
   !> slips, /afm/slips/line, realization, trip, support, force, jump,
   !> jump_across (and barrier, prefactor for the thermal reduced model).  With the retrace, each line's mean |F| and mean peak
   !> force, /afm/mean_abs_force and /afm/peak_force.
   subroutine write_afm_file(path, comm, config, first, stride, trace, retrace, summary, error, surface, thermal, &
      & verify)
      character(len=*), intent(in) :: path
      type(communicator), intent(in) :: comm
      type(afm_config), intent(in) :: config
      integer, intent(in) :: first, stride
      real(wp), intent(in) :: trace(:, :, :), retrace(:, :, :)
      type(run_summary), intent(in) :: summary
      type(error_type), allocatable, intent(out) :: error
      !> present for a tip moving in 3D over a crystal net
      type(afm_surface_record), intent(in), optional :: surface
      !> present at a temperature
      type(afm_thermal_record), intent(in), optional :: thermal
      !> /afm/verify when present and enabled
      type(afm_verify_record), intent(in), optional :: verify
      type(h5_file) :: file
      type(error_type), allocatable :: close_error
      type(afm_config) :: copy
      integer :: q, nq
      !> a map's axes: across the scan (its lines), along it
      character(len=*), parameter :: map_axes(2) = [character(len=14) :: '/afm/support_y', '/afm/support_x']

      call file%create(path, comm, error)
      if (allocated(error)) then
         call file%close(close_error)
         return
      end if
      if (present(thermal)) then
         call write_run_attributes(file, 'afm', thermal%scheme, summary)
      else
         call write_run_attributes(file, 'afm', trim(config%solver%method), summary)
      end if

      call file%create_group('/afm')
      call file%write_attribute_text('/afm', 'potential', trim(config%potential))
      call file%write_attribute_text('/afm', 'model', trim(config%model))
      call file%write_attribute_real('/afm', 'angle', config%angle, 'degree')
      call file%write_attribute_real('/afm', 'origin_x', config%origin_x, 'angstrom')
      call file%write_attribute_real('/afm', 'origin_y', config%origin_y, 'angstrom')
      call file%write_vector('/afm/support_x', support_along(config), 'angstrom')
      call file%write_vector('/afm/support_y', support_across(config), 'angstrom')
      nq = quantity_count(merge(3, 2, present(surface)))
      if (present(surface)) then
         call file%write_attribute_real('/afm', 'contact_height', surface%contact_height, 'angstrom')
         call file%write_attribute_real('/afm', 'support_height', surface%support_height, 'angstrom')
         call file%create_group('/surface')
         call file%write_matrix('/surface/atoms', surface%net%position, 'angstrom')
         call file%write_integer_vector('/surface/species', surface%net%species)
         call file%write_attribute_text('/surface', 'species_names', join(surface%species_names))
         call file%write_attribute_real('/surface', 'cutoff', surface%cutoff, 'angstrom')
         call write_evaluation(surface%evaluation)
      end if
      ! A Fourier landscape: its coefficients and its barrier's shape.
      if (config%surface_kind() == surface_fourier) call write_shape(file, config)
      if (present(thermal)) then
         call file%write_attribute_real('/afm', 'temperature', config%thermal%temperature, 'K')
         call file%write_attribute_integer('/afm', 'seed', config%thermal%seed)
         call file%write_attribute_integer('/afm', 'realizations', int(config%thermal%realizations, i8))
         call file%write_attribute_real('/afm', 'time_step', thermal%time_step, 's')
         call file%write_attribute_text('/afm', 'scheme', thermal%scheme)
      end if
      copy = config
      call write_parameter_attributes(file, '/afm', copy, [character(len=8) :: 'surface', 'tip', 'scan'])
      call write_trips('/afm/trace', trace)
      if (present(thermal)) call write_trips('/afm/trace', thermal%trace_sem, '_sem')
      if (config%retrace) then
         call write_trips('/afm/retrace', retrace)
         if (present(thermal)) call write_trips('/afm/retrace', thermal%retrace_sem, '_sem')
         call file%write_vector_block('/afm/friction', line_friction(trace, retrace), &
            & config%ny, first, stride, 'nN')
         if (present(thermal)) call file%write_vector_block('/afm/friction_sem', thermal%friction_sem, &
            & config%ny, first, stride, 'nN')
         call file%attach_scales('/afm/friction', map_axes(1:1))
         if (present(thermal)) call file%attach_scales('/afm/friction_sem', map_axes(1:1))
         call write_loop_forces()
      end if
      if (present(thermal)) then
         call file%create_group('/afm/slips')
         call file%write_integer_vector('/afm/slips/line', nint(thermal%slips(1, :)))
         call file%write_integer_vector('/afm/slips/realization', nint(thermal%slips(2, :)))
         call file%write_integer_vector('/afm/slips/trip', nint(thermal%slips(3, :)))
         call file%write_vector('/afm/slips/support', thermal%slips(4, :), 'angstrom')
         call file%write_vector('/afm/slips/force', thermal%slips(5, :), 'nN')
         call file%write_vector('/afm/slips/jump', thermal%slips(6, :), 'angstrom')
         call file%write_vector('/afm/slips/jump_across', thermal%slips(7, :), 'angstrom')
         if (config%thermal%reduced()) then
            call file%write_vector('/afm/slips/barrier', thermal%slips(8, :), 'eV')
            call file%write_vector('/afm/slips/prefactor', thermal%slips(9, :), '1/s')
         end if
      end if
      if (present(verify)) then
         if (verify%enabled) then
            call file%create_group('/afm/verify')
            call file%write_attribute_text('/afm/verify', 'method', trim(verify%method))
            call file%write_attribute_real('/afm/verify', 'rtol', verify%rtol)
            call file%write_attribute_real('/afm/verify', 'atol', verify%atol)
            call file%write_attribute_real('/afm/verify', 'max_difference', maxval(verify%max_difference), 'nN')
            call file%write_attribute_real('/afm/verify', 'max_difference_fx', verify%max_difference(1), 'nN')
            call file%write_attribute_real('/afm/verify', 'max_difference_fy', verify%max_difference(2), 'nN')
            if (present(surface)) call file%write_attribute_real('/afm/verify', 'max_difference_fz', &
               & verify%max_difference(3), 'nN')
            call file%write_attribute_integer('/afm/verify', 'rhs_evaluations', verify%rhs_evaluations)
         end if
      end if
      call file%close(error)

   contains

      !> Each line's mean |F| and mean peak force of its friction loop
      !> (friction_afm_loop), at a temperature those of the mean loop.
      subroutine write_loop_forces()
         real(wp) :: mean_abs(size(trace, 2)), peak(size(trace, 2))

         call loop_forces(trace(:, :, q_f_along), retrace(:, :, q_f_along), mean_abs, peak)
         call file%write_vector_block('/afm/mean_abs_force', mean_abs, config%ny, first, stride, 'nN')
         call file%attach_scales('/afm/mean_abs_force', map_axes(1:1))
         call file%write_vector_block('/afm/peak_force', peak, config%ny, first, stride, 'nN')
         call file%attach_scales('/afm/peak_force', map_axes(1:1))
      end subroutine write_loop_forces

      !> How the lattice sum was evaluated: /surface evaluation and, for the
      !> table, its size and its force error measured against the direct sum
      !> (docs/output.md).  (Not its build time: the file is the same for the
      !> same input, however long a rank took.)
      subroutine write_evaluation(how)
         type(surface_evaluation), intent(in) :: how

         call file%write_attribute_text('/surface', 'evaluation', how%evaluation)
         if (len(how%note) > 0) call file%write_attribute_text('/surface', 'evaluation_note', how%note)
         if (how%evaluation /= 'table') return
         call file%write_attribute_real('/surface', 'table_tolerance', how%tolerance, 'nN')
         call file%write_attribute_real('/surface', 'table_error', how%error, 'nN')
         call file%write_attribute_integer('/surface', 'table_points', int(how%points, i8))
         call file%write_attribute_integer('/surface', 'table_bytes', int(how%bytes, i8), 'byte')
         call file%write_attribute_integer('/surface', 'table_nodes', int(how%nodes(1), i8) * how%nodes(2) &
            & * how%nodes(3))
         call file%write_attribute_integer('/surface', 'table_layers', int(how%nodes(3), i8))
         call file%write_attribute_real('/surface', 'table_spacing', how%spacing, 'angstrom')
         call file%write_attribute_real('/surface', 'table_floor', how%floor, 'angstrom')
         call file%write_attribute_real('/surface', 'table_energy_window', how%energy_window, 'eV')
         call file%write_attribute_integer('/surface', 'table_differences', int(how%differences, i8))
      end subroutine write_evaluation

      !> The datasets of a trip's quantities, their names + suffix ('_sem').
      subroutine write_trips(group, values, suffix)
         character(len=*), intent(in) :: group
         real(wp), intent(in) :: values(:, :, :)
         character(len=*), intent(in), optional :: suffix
         character(len=:), allocatable :: tail

         tail = ''
         if (present(suffix)) then
            tail = suffix
         else
            call file%create_group(group)
         end if
         do q = 1, nq
            call file%write_line_block(group//'/'//trim(quantity_names(q))//tail, values(:, :, q), &
               & config%ny, first, stride, trim(quantity_units(q)))
            call file%attach_scales(group//'/'//trim(quantity_names(q))//tail, map_axes)
         end do
         if (config%tip_model() == model_quasistatic) then
            call file%write_line_block(group//'/'//trim(quantity_names(q_jumps))//tail, values(:, :, q_jumps), &
               & config%ny, first, stride, trim(quantity_units(q_jumps)))
            call file%attach_scales(group//'/'//trim(quantity_names(q_jumps))//tail, map_axes)
         end if
      end subroutine write_trips

   end subroutine write_afm_file

end module friction_afm_output
