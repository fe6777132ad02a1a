!> The physical parameters of a run as attributes with units on its scene's
!> group, so scripts read `kx` and `kx_units` instead of parsing the echoed
!> namelist: every real scalar variable of the given namelist groups that
!> declares a unit (core/parameters.f90).  An attribute the scene's writer
!> already wrote keeps its value and gets its unit beside it.
module friction_output_parameters
   use friction_parameters, only: configurable, parameter_info, list_parameters
   use friction_output_h5, only: h5_file
   implicit none
   private

   public :: write_parameter_attributes, unit_map

   abstract interface
      !> A declared unit in the units the object's values are in, when a
      !> scene computes in other units than its input declares.
      pure function unit_map(unit) result(mapped)
         character(len=*), intent(in) :: unit
         character(len=:), allocatable :: mapped
      end function unit_map
   end interface

contains

   subroutine write_parameter_attributes(file, object, config, groups, unit_of)
      type(h5_file), intent(inout) :: file
      character(len=*), intent(in) :: object
      class(configurable), intent(inout) :: config
      character(len=*), intent(in) :: groups(:)
      procedure(unit_map), optional :: unit_of   !! the declared units' counterparts (default: as declared)
      type(parameter_info), allocatable :: list(:)
      character(len=:), allocatable :: unit
      integer :: k

      list = list_parameters(config)
      do k = 1, size(list)
         associate (p => list(k))
            if (.not. any(groups == p%group) .or. p%kind /= 'r' .or. p%size /= 1 .or. len_trim(p%unit) == 0) cycle
            unit = trim(p%unit)
            if (present(unit_of)) unit = unit_of(unit)
            if (file%has_attribute(object, trim(p%name))) then
               if (.not. file%has_attribute(object, trim(p%name)//'_units')) &
                  & call file%write_attribute_units(object, trim(p%name), unit)
               cycle
            end if
            call file%write_attribute_real(object, trim(p%name), p%value, unit)
         end associate
      end do
   end subroutine write_parameter_attributes

end module friction_output_parameters
