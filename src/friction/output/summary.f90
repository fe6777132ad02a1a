!> What every output file records about its run, at the root: program,
!> version, source revision, creation time (UTC), scene, the resolved input,
!> ranks, wall time and integrator cost.
module friction_output_summary
   use friction_kinds, only: wp, i8
   use friction_ode_solver, only: integrator_statistics
   use friction_output_h5, only: h5_file
   use friction_version, only: revision_string
   use friction_clock, only: utc_now
   implicit none
   private

   public :: run_summary, write_run_attributes

   type :: run_summary
      character(len=:), allocatable :: input_text   !! resolved input, namelist text
      character(len=:), allocatable :: version
      integer :: nranks = 1
      real(wp) :: wall_time = 0.0_wp                !! s, up to the write
      type(integrator_statistics) :: stats
   end type run_summary

contains

   !> The root attributes of an output file (collective).
   subroutine write_run_attributes(file, scene, method, summary)
      type(h5_file), intent(inout) :: file
      character(len=*), intent(in) :: scene, method
      class(run_summary), intent(in) :: summary

      call file%write_attribute_text('/', 'program', 'friction')
      call file%write_attribute_text('/', 'version', summary%version)
      call file%write_attribute_text('/', 'scene', scene)
      call file%write_attribute_text('/', 'input', summary%input_text)
      call file%write_attribute_integer('/', 'nranks', int(summary%nranks, i8))
      call file%write_attribute_real('/', 'wall_time', summary%wall_time, 's')
      call file%write_attribute_text('/', 'created', utc_now())
      call file%write_attribute_text('/', 'revision', revision_string)
      call file%write_attribute_text('/', 'method', method)
      call file%write_attribute_integer('/', 'integrator_steps', summary%stats%steps)
      call file%write_attribute_integer('/', 'integrator_rejected_steps', summary%stats%failed_steps)
      call file%write_attribute_integer('/', 'rhs_evaluations', summary%stats%rhs_evaluations)
      call file%write_attribute_integer('/', 'jacobian_evaluations', summary%stats%jacobian_evaluations)
   end subroutine write_run_attributes

end module friction_output_summary
