!> What every job shares: its communicator and clock, the output's
!> temporary name and publication, and one error agreed on by all ranks.
!> A job whose communicator is not attached to MPI (serial_comm()) is
!> serial: one process, MPI not started (a run without a launcher, or the
!> serial program); every helper here then does on its own what the MPI
!> one does on one rank, so the job code is the same.
module friction_scene_context
   use friction_parallel, only: communicator, broadcast, reduce_all, reduce_to_root, &
      & op_sum, op_max, op_min, op_and
   use friction_kinds, only: wp
   use friction_clock, only: wall_seconds
   use friction_error, only: error_type, fatal_error, error_io
   use friction_strings, only: itoa, bytes_text
   use friction_files, only: publish_file, remove_file, process_id, free_bytes, min_free_bytes, full_text
   use friction_sharing, only: work_sharing
   implicit none
   private

   public :: job_context, agree_on_error, temporary_name, publish, check_writable, default_output, &
      & ranks_text, sum_to_root_real, sum_to_root_integer, share_of, job_wall_time, job_sharing, rank_sharing

   !> One job's run: where it runs, since when, what it read and writes.
   type :: job_context
      type(communicator) :: comm              !! not attached (the default): serial, without MPI
      integer :: rank = 0
      integer :: nranks = 1
      real(wp) :: t_start = 0.0_wp            !! wall_seconds() at the start of the job
      character(len=:), allocatable :: output
      character(len=:), allocatable :: input_text
      character(len=4096), allocatable :: files(:)
      logical :: resume = .false.
      logical :: replace = .false.           !! the output may replace a regular file (--force, --resume)
   contains
      procedure :: parallel
   end type job_context

   !> The job's ranks as friction_sharing's work_sharing: the layers below
   !> the scenes share work (a surface table's build) through it.
   type, extends(work_sharing) :: rank_sharing
      type(communicator) :: comm
   contains
      procedure :: sum_reals => ranks_sum_reals
      procedure :: max_real => ranks_max_real
      procedure :: every => ranks_every
   end type rank_sharing

contains

   !> The job's ranks, for work_sharing (serial: one process alone).
   function job_sharing(job) result(share)
      type(job_context), intent(in) :: job
      type(rank_sharing) :: share

      share%comm = job%comm
      share%rank = job%rank
      share%ranks = merge(job%nranks, 1, job%parallel())
   end function job_sharing

   subroutine ranks_sum_reals(self, values, n)
      class(rank_sharing), intent(inout) :: self
      integer, intent(in) :: n
      real(wp), intent(inout) :: values(*)

      if (.not. self%comm%parallel() .or. self%ranks < 2) return
      call reduce_all(self%comm, values(1:n), op_sum)
   end subroutine ranks_sum_reals

   subroutine ranks_max_real(self, x)
      class(rank_sharing), intent(inout) :: self
      real(wp), intent(inout) :: x

      if (.not. self%comm%parallel() .or. self%ranks < 2) return
      call reduce_all(self%comm, x, op_max)
   end subroutine ranks_max_real

   subroutine ranks_every(self, flag)
      class(rank_sharing), intent(inout) :: self
      logical, intent(inout) :: flag

      if (.not. self%comm%parallel() .or. self%ranks < 2) return
      call reduce_all(self%comm, flag, op_and)
   end subroutine ranks_every

   !> Whether the job runs on MPI (false: serial, no MPI call may be made).
   logical function parallel(self)
      class(job_context), intent(in) :: self

      parallel = self%comm%parallel()
   end function parallel

   !> Seconds since the job started (job%t_start), the longest of any rank:
   !> a run's wall_time.  Collective.
   function job_wall_time(job) result(wall)
      type(job_context), intent(in) :: job
      real(wp) :: wall

      wall = wall_seconds() - job%t_start
      call reduce_all(job%comm, wall, op_max)
   end function job_wall_time

   !> A rank's share of n items, dealt round-robin: items first, first +
   !> nranks, ... (0-based), count of them.  Neighbouring lines cost alike
   !> (they cross the same rows of atoms), so dealing them out in turn
   !> balances uneven maps better than contiguous blocks.  Each rank still
   !> writes one regular, strided hyperslab.
   pure subroutine share_of(n, nranks, rank, first, count)
      integer, intent(in) :: n, nranks, rank
      integer, intent(out) :: first, count

      first = rank
      count = max(0, (n - rank + nranks - 1) / nranks)
   end subroutine share_of

   !> After work that may fail on some ranks: if any rank holds an error,
   !> every rank returns with the error of the lowest such rank (its message
   !> and category broadcast), so callers report it once, from rank 0.
   subroutine agree_on_error(job, error)
      type(job_context), intent(in) :: job
      type(error_type), allocatable, intent(inout) :: error
      integer :: failed, header(2)
      character(len=:), allocatable :: message

      if (.not. job%parallel()) return
      failed = merge(job%rank, job%nranks, allocated(error))
      call reduce_all(job%comm, failed, op_min)
      if (failed == job%nranks) return
      if (job%rank == failed) then
         header = [error%stat, len(error%message)]
         message = error%message
      end if
      call broadcast(job%comm, header, failed)
      if (job%rank /= failed) allocate (character(len=header(2)) :: message)
      call broadcast(job%comm, message, failed)
      if (allocated(error)) deallocate (error)
      call fatal_error(error, message, header(1))
   end subroutine agree_on_error

   !> The name the output is written under until it is complete: unique per
   !> run (rank 0's process id), beside the output so the rename is atomic.
   function temporary_name(job) result(name)
      type(job_context), intent(in) :: job
      character(len=:), allocatable :: name
      integer :: pid

      pid = process_id()
      call broadcast(job%comm, pid, 0)
      name = job%output//'.tmp-'//itoa(pid)
   end function temporary_name

   !> After the (collective or rank-0) write to `temporary`: on success on
   !> every rank, give it the output's name (publish_file: without the job's
   !> `replace` a file that appeared at that name meanwhile is never
   !> overwritten; this run's file is then kept under its temporary name and
   !> the error says so); otherwise remove it.  Every rank returns the same
   !> error or none.
   subroutine publish(job, temporary, error)
      type(job_context), intent(in) :: job
      character(len=*), intent(in) :: temporary
      type(error_type), allocatable, intent(inout) :: error
      integer :: failed
      logical :: keep

      failed = merge(1, 0, allocated(error))
      call reduce_all(job%comm, failed, op_max)
      if (job%rank == 0) then
         keep = .false.
         if (failed == 0) then
            call publish_file(temporary, job%output, job%replace, error)
            if (allocated(error)) then
               keep = index(error%message, 'appeared while this run computed') > 0
               if (keep) error%message = error%message//'; this run''s file is kept as '//temporary
            end if
         else if (.not. allocated(error)) then
            call fatal_error(error, temporary//': writing failed on another rank', error_io)
         end if
         if (allocated(error) .and. .not. keep) then
            call remove_file(temporary)
            ! Name the output, not the temporary file that no longer exists.
            if (index(error%message, temporary) > 0) error%message = replaced(error%message, temporary, job%output) &
               & //' (nothing written: the partial file was removed)'
         end if
      end if
      call agree_on_error(job, error)
   end subroutine publish

   !> text with every `from` replaced by `to`.
   function replaced(text, from, to) result(out)
      character(len=*), intent(in) :: text, from, to
      character(len=:), allocatable :: out
      integer :: at, k

      out = ''
      k = 1
      do
         at = index(text(k:), from)
         if (at == 0 .or. len(from) == 0) exit
         out = out//text(k:k + at - 2)//to
         k = k + at - 1 + len(from)
      end do
      out = out//text(k:)
   end function replaced

   !> Create and remove a probe file beside the output.
   subroutine check_writable(path, error)
      character(len=*), intent(in) :: path
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: probe
      character(len=256) :: message
      integer :: unit, stat
      real(wp) :: free

      probe = path//'.tmp-'//itoa(process_id())
      open (newunit=unit, file=probe, status='new', action='write', iostat=stat, iomsg=message)
      if (stat /= 0) then
         call fatal_error(error, path//': cannot write the output here ('//trim(message)//')', error_io)
         return
      end if
      close (unit, status='delete')
      free = free_bytes(path)
      if (free >= 0.0_wp .and. free < min_free_bytes) call fatal_error(error, path//': '//full_text(path, free) &
         & //'; writing the output needs at least '//bytes_text(min_free_bytes) &
         & //' to spare)', error_io)
   end subroutine check_writable

   !> inputs/hopg.nml -> hopg.h5
   function default_output(path) result(name)
      character(len=*), intent(in) :: path
      character(len=:), allocatable :: name
      integer :: slash, dot

      slash = index(path, '/', back=.true.)
      name = trim(path(slash + 1:))
      dot = index(name, '.', back=.true.)
      if (dot > 1) name = name(1:dot - 1)
      name = name//'.h5'
   end function default_output

   !> "on 1 rank", "on 3 ranks"
   function ranks_text(nranks) result(text)
      integer, intent(in) :: nranks
      character(len=:), allocatable :: text

      text = 'on '//itoa(nranks)//trim(merge(' rank ', ' ranks', nranks == 1))
   end function ranks_text

   !> Sum a real array onto rank 0 (each entry has one non-zero contributor).
   subroutine sum_to_root_real(job, values)
      type(job_context), intent(in) :: job
      real(wp), intent(inout) :: values(:)

      call reduce_to_root(job%comm, values, op_sum)
   end subroutine sum_to_root_real

   !> Sum an integer array of `count` entries onto rank 0.
   subroutine sum_to_root_integer(job, values, count)
      type(job_context), intent(in) :: job
      integer, intent(inout) :: values(*)
      integer, intent(in) :: count

      call reduce_to_root(job%comm, values(1:count), op_sum)
   end subroutine sum_to_root_integer

end module friction_scene_context
