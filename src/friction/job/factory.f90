!> The one place that knows the concrete scenes: a scene from its name.
module friction_job_factory
   use friction_scene, only: scene
   use friction_afm_scene, only: afm_scene
   use friction_brake_scene, only: brake_scene
   use friction_machine_scene, only: machine_scene
   implicit none
   private

   public :: scene_names, new_scene

   !> &job scene = '...' (the first is the default).
   character(len=*), parameter :: scene_names(3) = [character(len=7) :: 'afm', 'brake', 'machine']

contains

   !> A scene of that name with its defaults; unallocated if there is none.
   subroutine new_scene(name, s)
      character(len=*), intent(in) :: name
      class(scene), allocatable, intent(out) :: s

      select case (trim(name))
      case ('afm')
         allocate (afm_scene :: s)
      case ('brake')
         allocate (brake_scene :: s)
      case ('machine')
         allocate (machine_scene :: s)
      end select
   end subroutine new_scene

end module friction_job_factory
