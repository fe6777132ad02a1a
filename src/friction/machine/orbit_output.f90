!> /machine/orbit, /machine/orbit/branch and /machine/orbit/bifurcations
!> (docs/output.md): the machine's periodic orbit, its continuation and the
!> bifurcations found along it, in the layout of the brake's /brake/orbit.
module friction_machine_orbit_output
   use friction_kinds, only: wp, i8
   use friction_error, only: error_type
   use friction_output_h5, only: h5_file
   use friction_output_branch, only: write_branch_points, write_branch_sections, write_bifurcations
   use friction_machine_config, only: machine_config
   use friction_machine_orbit, only: machine_orbit, machine_branch, machine_bifurcation_names, machine_orbit_names
   implicit none
   private

   public :: write_machine_orbit

contains

   subroutine write_machine_orbit(file, c, o, continued, branch, error)
      type(h5_file), intent(inout) :: file
      type(machine_config), intent(in) :: c
      type(machine_orbit), intent(in) :: o
      logical, intent(in) :: continued
      type(machine_branch), intent(in) :: branch
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: group = '/machine/orbit'
      character(len=:), allocatable :: names, units
      real(wp), allocatable :: parts(:, :)

      call machine_orbit_names(c, names, units, error)
      if (allocated(error)) return
      call file%create_group(group)
      call file%write_attribute_integer(group, 'found', merge(1_i8, 0_i8, o%orbit%found))
      if (.not. o%orbit%found) call file%write_attribute_text(group, 'reason', o%orbit%reason)
      call file%write_attribute_text(group, 'section', merge('stroboscopic', 'v_rising    ', o%forced))
      call file%write_attribute_real(group, 'guess_time', o%guess_time, 's')
      call file%write_attribute_real(group, 'transient', c%analysis%orbit_transient, 's')
      call file%write_attribute_real(group, 'tolerance', c%analysis%orbit_tolerance, '1')
      call file%write_attribute_integer(group, 'iterations', int(o%orbit%iterations, i8))
      call file%write_attribute_real(group, 'residual', o%orbit%residual, '1')
      ! The orbit's section point, or Newton's last iterate (the run's last state when it had none).
      ! Its columns differ in unit: no single `units`, each column's in `column_units` (UDUNITS each).
      call file%write_vector(group//'/point', o%state, '')
      call file%write_attribute_text(group//'/point', 'names', names)
      call file%write_attribute_text(group//'/point', 'column_units', units)
      if (o%has_equilibrium) then
         call file%write_vector(group//'/equilibrium', o%equilibrium, '')
         call file%write_attribute_text(group//'/equilibrium', 'names', names)
         call file%write_attribute_text(group//'/equilibrium', 'column_units', units)
         allocate (parts(2, size(o%eigenvalues)))
         parts(1, :) = real(o%eigenvalues)
         parts(2, :) = aimag(o%eigenvalues)
         call file%write_matrix(group//'/equilibrium_eigenvalues', parts, '1/s')
         call file%write_attribute_text(group//'/equilibrium_eigenvalues', 'columns', 'real, imag')
         deallocate (parts)
      end if
      if (continued) call write_branch(file, branch, units)
      if (.not. o%orbit%found) return
      call file%write_attribute_real(group, 'period', o%orbit%period, 's')
      ! A set-valued law's orbit: its stick phases and time in stick per period (a stick makes it superstable).
      if (o%sticks >= 0) then
         call file%write_attribute_integer(group, 'stick_phases', int(o%sticks, i8))
         call file%write_attribute_real(group, 'stick_time', o%stick_time, 's')
      end if
      call file%write_matrix(group//'/section_jacobian', o%jacobian, '1')
      allocate (parts(2, size(o%multipliers)))
      parts(1, :) = real(o%multipliers)
      parts(2, :) = aimag(o%multipliers)
      call file%write_matrix(group//'/floquet_multipliers', parts, '1')
      call file%write_attribute_text(group//'/floquet_multipliers', 'columns', 'real, imag')
      call file%write_vector(group//'/floquet_exponents', o%exponents, '1/s')
   end subroutine write_machine_orbit

   subroutine write_branch(file, b, units)
      type(h5_file), intent(inout) :: file
      type(machine_branch), intent(in) :: b
      character(len=*), intent(in) :: units
      character(len=*), parameter :: group = '/machine/orbit/branch'
      !> the branch's series along its points, whose coordinate is the parameter
      character(len=*), parameter :: along_branch(5) = [character(len=11) :: 'found', 'source', 'period', &
         & 'max_modulus', 'growth']

      call write_branch_points(file, group, trim(b%variable), b%parameter, b%unit, b%found, b%source)
      call file%write_vector(group//'/period', b%period, 's')
      call file%write_matrix(group//'/point', b%state, '')
      call file%write_attribute_text(group//'/point', 'column_units', units)
      call file%write_matrix(group//'/floquet_multipliers_real', real(b%multipliers), '1')
      call file%write_matrix(group//'/floquet_multipliers_imag', aimag(b%multipliers), '1')
      call file%write_vector(group//'/max_modulus', b%max_modulus, '1')
      call file%write_vector(group//'/growth', b%growth, '1/s')
      call write_branch_sections(file, group, b%section_parameter, b%section_x, b%unit, along_branch)
      call write_bifurcations(file, '/machine/orbit/bifurcations', machine_bifurcation_names, b%kind, b%at, b%unit)
   end subroutine write_branch

end module friction_machine_orbit_output
