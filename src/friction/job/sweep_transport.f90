!> A finished sweep point's way to rank 0 (docs/sweeps.md).  A rank sends
!> each point as soon as it is computed, with at most `in_flight` sends
!> unmatched, so that neither the rank nor rank 0's MPI queue holds more
!> than a bounded number of points whatever the sweep's size; rank 0 takes
!> them between its own points, and at the end until every rank has said
!> it finished.
module friction_job_sweep_transport
   use friction_parallel, only: send_request, send_async, wait_sends, probe_any, receive
   use friction_kinds, only: wp
   use friction_scene_context, only: job_context
   use friction_job_sweep_point, only: finished_point
   implicit none
   private

   public :: point_transport

   !> Sends of finished points a rank may have unmatched by rank 0: what
   !> rank 0's MPI layer can hold for each rank while it computes a point.
   integer, parameter :: in_flight = 16

   integer, parameter :: tag_header = 7301, tag_numbers = 7302, tag_reason = 7303

   !> A point on its way, kept until rank 0 has matched its sends.
   type, extends(finished_point) :: outbox_slot
      type(send_request) :: requests(3)
      logical :: busy = .false.
   end type outbox_slot

   !> A rank's sends (its outbox) and rank 0's count of ranks that finished.
   type :: point_transport
      private
      type(outbox_slot), allocatable :: outbox(:)
      integer :: slot = 0
      integer :: finished = 0
   contains
      procedure :: send => transport_send
      procedure :: finish => transport_finish
      procedure :: receive => transport_receive
   end type point_transport

contains

   !> A rank other than 0: send a finished point from the next slot of the
   !> outbox, waiting first for that slot's previous sends to be matched.
   subroutine transport_send(self, job, point)
      class(point_transport), intent(inout) :: self
      type(job_context), intent(in) :: job
      type(finished_point), intent(in) :: point

      if (.not. allocated(self%outbox)) allocate (self%outbox(in_flight))
      self%slot = mod(self%slot, size(self%outbox)) + 1
      associate (box => self%outbox(self%slot))
         if (box%busy) call wait_sends(box%requests)
         box%header = point%header
         box%numbers = point%numbers
         box%reason = point%reason
         ! Synchronous sends: done only when rank 0 has taken them, so a rank
         ! has at most size(outbox) points on their way.
         call send_async(job%comm, box%header, 0, tag_header, box%requests(1))
         if (box%header(1) > 0) then
            call send_async(job%comm, box%numbers, 0, tag_numbers, box%requests(2))
            if (len(box%reason) > 0) call send_async(job%comm, box%reason, 0, tag_reason, box%requests(3))
         end if
         box%busy = .true.
      end associate
   end subroutine transport_send

   !> A rank other than 0 that has finished: say so (and whether it was
   !> interrupted), and wait until rank 0 has taken every point it sent.
   subroutine transport_finish(self, job, interrupted)
      class(point_transport), intent(inout) :: self
      type(job_context), intent(in) :: job
      logical, intent(in) :: interrupted
      type(finished_point) :: last
      integer :: k

      last%header = [0, merge(1, 0, interrupted), 0, 0, 0]
      last%numbers = [real(wp) ::]
      last%reason = ''
      call self%send(job, last)
      do k = 1, size(self%outbox)
         if (self%outbox(k)%busy) call wait_sends(self%outbox(k)%requests)
      end do
   end subroutine transport_finish

   !> Rank 0: the next point another rank has sent, if one has come
   !> (`arrived`); with `wait`, wait for one until every other rank has
   !> said it finished.  Nothing arrives in a serial job.
   subroutine transport_receive(self, job, wait, point, arrived)
      class(point_transport), intent(inout) :: self
      type(job_context), intent(in) :: job
      logical, intent(in) :: wait
      type(finished_point), intent(inout) :: point
      logical, intent(out) :: arrived
      integer :: source

      arrived = .false.
      if (.not. job%parallel()) return
      do
         if (wait) then
            if (self%finished == job%nranks - 1) return
         end if
         call probe_any(job%comm, tag_header, wait, arrived, source)
         if (.not. arrived) return
         call receive(job%comm, point%header, source, tag_header)
         if (point%header(1) == 0) then
            self%finished = self%finished + 1
            arrived = .false.
            cycle
         end if
         if (allocated(point%numbers)) deallocate (point%numbers)
         allocate (point%numbers(point%header(3) + 1 + point%header(4)))
         call receive(job%comm, point%numbers, source, tag_numbers)
         if (allocated(point%reason)) deallocate (point%reason)
         allocate (character(len=point%header(5)) :: point%reason)
         if (point%header(5) > 0) call receive(job%comm, point%reason, source, tag_reason)
         arrived = .true.
         return
      end do
   end subroutine transport_receive

end module friction_job_sweep_transport
