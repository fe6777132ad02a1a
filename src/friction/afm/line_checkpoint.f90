!> A map's finished lines as checkpoints beside the output
!> (output/checkpoint.f90), so that `--resume` finishes a map that a time
!> limit or a signal stopped, with the file an uninterrupted run writes.
!> A line's checkpoint holds everything the map keeps of it: the samples of
!> its trips, at a temperature their standard errors, the friction's
!> standard error and the slips, and the integrator's counts.
module friction_afm_line_checkpoint
   use friction_kinds, only: wp
   use friction_strings, only: itoa
   use friction_output_checkpoint, only: write_checkpoint, publish_checkpoints, discard_checkpoints, &
      & checkpoint_body, real_line, read_reals, next_line
   implicit none
   private

   public :: line_checkpoint_name, save_line, load_line, publish_checkpoints, discard_checkpoints

contains

   !> Where line `line` (0-based) of the map written to `output` keeps its
   !> checkpoint (named 1-based, as users count lines).
   function line_checkpoint_name(output, line) result(name)
      character(len=*), intent(in) :: output
      integer, intent(in) :: line
      character(len=:), allocatable :: name

      name = output//'.line-'//itoa(line + 1)//'.ckpt'
   end function line_checkpoint_name

   !> Write line `line`'s checkpoint under its temporary name, to be
   !> published with the others of the same save (publish_checkpoints: one
   !> sync for all of them).  `trace` and `retrace` are (nx,
   !> quantities), `retrace` of no columns without a retrace; the `_sem`
   !> arrays likewise, of no rows when not at a temperature; `slips` holds
   !> the line's slips as columns; `counts` the integrator's counts.
   subroutine save_line(path, input_hash, line, trace, retrace, trace_sem, retrace_sem, friction_sem, slips, &
      & counts, problem)
      character(len=*), intent(in) :: path, input_hash
      integer, intent(in) :: line
      real(wp), intent(in) :: trace(:, :), retrace(:, :), trace_sem(:, :), retrace_sem(:, :)
      real(wp), intent(in) :: friction_sem, slips(:, :), counts(:)
      character(len=:), allocatable, intent(out) :: problem
      character(len=:), allocatable :: text
      integer :: k

      text = 'line '//itoa(line)//' '//itoa(size(trace, 1))//' '//itoa(size(trace, 2))//' ' &
         & //itoa(size(retrace, 1))//' '//itoa(size(trace_sem, 1))//' '//itoa(size(retrace_sem, 1))//' ' &
         & //itoa(size(slips, 1))//' '//itoa(size(slips, 2))//' '//itoa(size(counts))//new_line('a')
      text = text//real_line([counts, friction_sem])
      call columns(trace)
      call columns(retrace)
      call columns(trace_sem)
      call columns(retrace_sem)
      do k = 1, size(slips, 2)
         text = text//real_line(slips(:, k))
      end do
      call write_checkpoint(path, input_hash, text, problem)

   contains

      subroutine columns(a)
         real(wp), intent(in) :: a(:, :)
         integer :: q

         if (size(a, 1) == 0) return
         do q = 1, size(a, 2)
            text = text//real_line(a(:, q))
         end do
      end subroutine columns

   end subroutine save_line

   !> Line `line`'s checkpoint, when there is one for this input and these
   !> shapes (`loaded`).  `problem` says why a checkpoint that exists cannot
   !> serve: another input, damaged, or of another shape.  The arrays are
   !> filled as save_line was given them; `slips` is allocated with the
   !> line's slips as columns.
   subroutine load_line(path, input_hash, line, trace, retrace, trace_sem, retrace_sem, friction_sem, slips, &
      & counts, loaded, problem)
      character(len=*), intent(in) :: path, input_hash
      integer, intent(in) :: line
      real(wp), intent(inout) :: trace(:, :), retrace(:, :), trace_sem(:, :), retrace_sem(:, :)
      real(wp), intent(out) :: friction_sem
      real(wp), allocatable, intent(out) :: slips(:, :)
      real(wp), intent(out) :: counts(:)
      logical, intent(out) :: loaded
      character(len=:), allocatable, intent(out) :: problem
      character(len=:), allocatable :: body, text
      character(len=8) :: word
      integer :: shape(9), at, stat, k
      real(wp) :: head(size(counts) + 1)
      logical :: ok

      loaded = .false.
      friction_sem = 0.0_wp
      counts = 0.0_wp
      allocate (slips(0, 0))
      call checkpoint_body(path, input_hash, body, problem)
      if (len(problem) > 0 .or. .not. allocated(body)) return
      at = 1
      text = next_line(body, at)
      read (text, *, iostat=stat) word, shape
      if (stat /= 0 .or. word /= 'line') then
         problem = path//': the checkpoint is damaged (its first line does not read)'
         return
      end if
      if (any(shape /= [line, size(trace, 1), size(trace, 2), size(retrace, 1), size(trace_sem, 1), &
         & size(retrace_sem, 1), shape(7), shape(8), size(counts)]) .or. shape(8) < 0 .or. shape(7) < 0) then
         problem = path//': the checkpoint is of another line or map (line '//itoa(shape(1) + 1)//', ' &
            & //itoa(shape(2))//' samples)'
         return
      end if
      call read_reals(next_line(body, at), head, ok)
      if (ok) call columns(trace)
      if (ok) call columns(retrace)
      if (ok) call columns(trace_sem)
      if (ok) call columns(retrace_sem)
      deallocate (slips)
      allocate (slips(shape(7), shape(8)))
      do k = 1, shape(8)
         if (.not. ok) exit
         call read_reals(next_line(body, at), slips(:, k), ok)
      end do
      if (.not. ok) then
         problem = path//': the checkpoint is damaged (its values do not read)'
         return
      end if
      counts = head(1:size(counts))
      friction_sem = head(size(head))
      loaded = .true.

   contains

      subroutine columns(a)
         real(wp), intent(inout) :: a(:, :)
         integer :: q

         if (size(a, 1) == 0) return
         do q = 1, size(a, 2)
            if (.not. ok) return
            call read_reals(next_line(body, at), a(:, q), ok)
         end do
      end subroutine columns

   end subroutine load_line

end module friction_afm_line_checkpoint
