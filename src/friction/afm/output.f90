!> The friction-force-map file (docs/output.md).  Collective: all
!> ranks call it; each passes the block of lines it computed.
module friction_afm_output
   use mpi_f08, only: MPI_Comm
   use friction_kinds, only: wp, i8
   use friction_error, only: error_type
   use friction_ode_solver, only: integrator_statistics
   use friction_afm_config, only: afm_config
   use friction_afm_scan, only: quantity_names, quantity_units, quantity_count, q_f_along, q_jumps, &
      & support_along, support_across
   use friction_output_h5, only: h5_file
   use friction_output_parameters, only: write_parameter_attributes
   use friction_output_summary, only: run_summary, write_run_attributes
   use friction_surface_net, only: crystal_net
   use friction_strings, only: join
   implicit none
   private

   public :: write_afm_file, line_friction, afm_surface_record

   !> The sample of a lattice-sum scene, for pictures that overlay it.
   type :: afm_surface_record
      type(crystal_net) :: net
      character(len=8), allocatable :: species_names(:)
      real(wp) :: cutoff = 0.0_wp           !! Å
      real(wp) :: contact_height = 0.0_wp   !! Å
      real(wp) :: support_height = 0.0_wp   !! Å
   end type afm_surface_record


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
   !> when config%retrace.
   subroutine write_afm_file(path, comm, config, first, stride, trace, retrace, summary, error, surface)
      character(len=*), intent(in) :: path
      type(MPI_Comm), intent(in) :: comm
      type(afm_config), intent(in) :: config
      integer, intent(in) :: first, stride
      real(wp), intent(in) :: trace(:, :, :), retrace(:, :, :)
      type(run_summary), intent(in) :: summary
      type(error_type), allocatable, intent(out) :: error
      !> present for a tip moving in 3D over a crystal net
      type(afm_surface_record), intent(in), optional :: surface
      type(h5_file) :: file
      type(error_type), allocatable :: close_error
      type(afm_config) :: copy
      integer :: q, nq

      call file%create(path, comm, error)
      if (allocated(error)) then
         call file%close(close_error)
         return
      end if
      call write_run_attributes(file, 'afm', trim(config%solver%method), summary)

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
      end if
      copy = config
      call write_parameter_attributes(file, '/afm', copy, [character(len=8) :: 'surface', 'tip', 'scan'])
      call write_trips('/afm/trace', trace)
      if (config%retrace) then
         call write_trips('/afm/retrace', retrace)
         call file%write_vector_block('/afm/friction', line_friction(trace, retrace), &
            & config%ny, first, stride, 'nN')
      end if
      call file%close(error)

   contains

      subroutine write_trips(group, values)
         character(len=*), intent(in) :: group
         real(wp), intent(in) :: values(:, :, :)

         call file%create_group(group)
         do q = 1, nq
            call file%write_line_block(group//'/'//trim(quantity_names(q)), values(:, :, q), &
               & config%ny, first, stride, trim(quantity_units(q)))
         end do
         if (config%model == 'quasistatic') call file%write_line_block(group//'/'//trim(quantity_names(q_jumps)), &
            & values(:, :, q_jumps), config%ny, first, stride, trim(quantity_units(q_jumps)))
      end subroutine write_trips

   end subroutine write_afm_file

end module friction_afm_output
