!> Which rank computes which sweep point (docs/sweeps.md).
!>
!> With sweep_schedule = 'dynamic' every rank takes the next point from a
!> counter on rank 0 (friction_parallel's shared_counter, one-sided): no master
!> serving requests between its own points (no polling, rank 0 computes
!> like the others), and points handed out on demand, so a chaotic, long
!> point does not hold up a whole static share.  'static' is the naive
!> split into contiguous blocks, kept for the benchmark.  On --resume the
!> points still to do come from a list in a file every rank reads, so that
!> no rank holds a list over all points.
module friction_job_sweep_schedule
   use friction_parallel, only: shared_counter
   use friction_kinds, only: i8
   use friction_error, only: error_type, fatal_error, error_io
   use friction_scene_context, only: job_context, agree_on_error
   implicit none
   private

   public :: sweep_scheduler

   type :: sweep_scheduler
      private
      logical :: dynamic = .false.
      type(shared_counter) :: counter
      integer :: n_work = 0          !! points to hand out (all, or those the list holds)
      integer :: block_first = 0, block_last = 0   !! static: this rank's block, [first, last)
      integer :: taken = 0           !! static: points this rank has taken
      logical :: listed = .false.    !! the points to do come from a list (resuming)
      integer :: todo_unit = -1
   contains
      procedure :: start => scheduler_start
      procedure :: next => scheduler_next
      procedure :: finish => scheduler_finish
   end type sweep_scheduler

contains

   !> Hand out `n_work` points over the job's ranks (collective): point w
   !> is w itself, or the w-th of the list `todo_path` when one is given
   !> (non-empty).  Every rank returns the same error or none.
   subroutine scheduler_start(self, job, dynamic, n_work, todo_path, error)
      class(sweep_scheduler), intent(inout) :: self
      type(job_context), intent(in) :: job
      logical, intent(in) :: dynamic
      integer, intent(in) :: n_work
      character(len=*), intent(in) :: todo_path
      type(error_type), allocatable, intent(out) :: error
      integer :: stat

      self%n_work = n_work
      self%listed = len(todo_path) > 0
      if (self%listed) then
         open (newunit=self%todo_unit, file=todo_path, access='stream', form='unformatted', action='read', &
            & status='old', iostat=stat)
         if (stat /= 0) call fatal_error(error, todo_path//': cannot read the list of points to do', error_io)
         call agree_on_error(job, error)
         if (allocated(error)) then
            if (stat == 0) close (self%todo_unit)
            self%listed = .false.
            return
         end if
      end if
      ! (One rank takes its points in order: a block of all of them.)
      self%dynamic = dynamic .and. job%nranks > 1
      if (self%dynamic) call self%counter%create(job%comm)
      self%block_first = int(int(n_work, i8) * job%rank / job%nranks)
      self%block_last = int(int(n_work, i8) * (job%rank + 1) / job%nranks)
      self%taken = 0
   end subroutine scheduler_start

   !> The next point this rank computes (1 to the sweep's points), or 0
   !> when none is left.
   subroutine scheduler_next(self, point)
      class(sweep_scheduler), intent(inout) :: self
      integer, intent(out) :: point
      integer :: next, w

      if (.not. self%dynamic) then
         ! Contiguous blocks: a run of expensive neighbours lands on one rank.
         next = self%block_first + self%taken
         if (next >= self%block_last) next = self%n_work
      else
         call self%counter%take(next)
      end if
      w = next + 1
      point = 0
      if (w > self%n_work) return
      point = w
      if (self%listed) read (self%todo_unit, pos=int(w - 1, i8) * 4 + 1) point
      self%taken = self%taken + 1
   end subroutine scheduler_next

   !> Close the list and free the counter (collective: only once every
   !> point is on its way, or a rank waiting for rank 0 to take its points
   !> would wait for ever).
   subroutine scheduler_finish(self)
      class(sweep_scheduler), intent(inout) :: self

      if (self%listed) close (self%todo_unit)
      self%listed = .false.
      if (self%dynamic) call self%counter%free()
      self%dynamic = .false.
   end subroutine scheduler_finish

end module friction_job_sweep_schedule
