!> What the brake's and the machine's continued branches of periodic orbits
!> write alike: the points and where each orbit came from, the attractor's
!> section points along the branch and the bifurcations group (docs/output.md).
module friction_output_branch
   use friction_kinds, only: wp
   use friction_strings, only: join
   use friction_output_h5, only: h5_file
   implicit none
   private

   public :: write_branch_points, write_branch_sections, write_bifurcations

contains

   !> The group `group` of a branch in the variable `variable`: its points'
   !> parameter (in `unit`), whether each has an orbit and where it came from.
   subroutine write_branch_points(file, group, variable, parameter, unit, found, source)
      type(h5_file), intent(inout) :: file
      character(len=*), intent(in) :: group, variable, unit
      real(wp), intent(in), contiguous :: parameter(:)
      logical, intent(in) :: found(:)
      integer, intent(in) :: source(:)

      call file%create_group(group)
      call file%write_attribute_text(group, 'variable', variable)
      call file%write_vector(group//'/parameter', parameter, unit)
      call file%write_vector_integer(group//'/found', merge(1, 0, found), '1')
      call file%write_vector_integer(group//'/source', source, '1')
      call file%write_attribute_text(group//'/source', 'names', '1 = continued, 2 = from the attractor')
   end subroutine write_branch_points

   !> group/section_parameter and group/section_x (x in m) with the one as
   !> the other's scale, and group/parameter as the scale of each `along` series.
   subroutine write_branch_sections(file, group, section_parameter, section_x, unit, along)
      type(h5_file), intent(inout) :: file
      character(len=*), intent(in) :: group, unit, along(:)
      real(wp), intent(in), contiguous :: section_parameter(:), section_x(:)
      integer :: k

      call file%write_vector(group//'/section_parameter', section_parameter, unit)
      call file%write_vector(group//'/section_x', section_x, 'm')
      call file%attach_scales(group//'/section_x', [group//'/section_parameter'])
      do k = 1, size(along)
         call file%attach_scales(group//'/'//trim(along(k)), [group//'/parameter'])
      end do
   end subroutine write_branch_sections

   !> The group `group` with its kind and parameter (in `unit`) per
   !> bifurcation, kind k named names(k) in the attribute kind_names.
   subroutine write_bifurcations(file, group, names, kind, at, unit)
      type(h5_file), intent(inout) :: file
      character(len=*), intent(in) :: group, names(:), unit
      integer, intent(in) :: kind(:)
      real(wp), intent(in), contiguous :: at(:)
      character(len=32) :: codes(size(names))
      integer :: k

      call file%create_group(group)
      do k = 1, size(names)
         write (codes(k), '(i0, a)') k, ' = '//trim(names(k))
      end do
      call file%write_attribute_text(group, 'kind_names', join(codes))
      call file%write_vector_integer(group//'/kind', kind, '1')
      call file%write_vector(group//'/parameter', at, unit)
   end subroutine write_bifurcations

end module friction_output_branch
