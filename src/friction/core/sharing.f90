!> Work dealt out over the processes of a job, as the layers below the
!> scenes see it (they use no MPI): this process's rank among how many, and
!> the collective sum and maximum the pieces are put together with.  The
!> base type is a process alone (its sum and maximum leave the values as
!> they are); friction_scene_context extends it over a job's communicator.
!> Every procedure is collective: all processes call it, in the same order.
module friction_sharing
   use friction_kinds, only: wp
   implicit none
   private

   public :: work_sharing

   type :: work_sharing
      integer :: rank = 0    !! this process, 0-based
      integer :: ranks = 1   !! processes sharing the work
   contains
      procedure :: sum_reals
      procedure :: max_real
      procedure :: every
   end type work_sharing

contains

   !> values(1:n) summed element by element over the processes, in place
   !> (each process passes its share, -0.0 where it computed nothing: the
   !> one value that adds nothing to any other, signed zeros included).
   subroutine sum_reals(self, values, n)
      class(work_sharing), intent(inout) :: self
      integer, intent(in) :: n
      real(wp), intent(inout) :: values(*)
   end subroutine sum_reals

   !> The largest x over the processes, in place.
   subroutine max_real(self, x)
      class(work_sharing), intent(inout) :: self
      real(wp), intent(inout) :: x
   end subroutine max_real

   !> Whether `flag` holds on every process (in place).
   subroutine every(self, flag)
      class(work_sharing), intent(inout) :: self
      logical, intent(inout) :: flag
   end subroutine every

end module friction_sharing
