!> Checkpoints: small text files beside an output that let `--resume`
!> finish an interrupted job (a sweep's points, a map's lines).  A
!> checkpoint is whole or absent: it is written under a temporary name with
!> every write checked, then renamed.  Its first line names the format and
!> the hash of the job's whole resolved input; its last line holds the
!> number of lines before it and a checksum of them.  Reals are written as
!> the 16 hexadecimal digits of their bits, which read back to the same
!> double (decimal text with 17 digits did too, at 25 times the cost: a
!> map's periodic checkpoints took more time than its lines).
module friction_output_checkpoint
   use friction_kinds, only: wp, i8
   use friction_error, only: error_type
   use friction_strings, only: itoa, text_hash
   use friction_files, only: write_bytes, sync_files, rename_file, remove_file, file_exists
   implicit none
   private

   public :: write_checkpoint, publish_checkpoints, discard_checkpoints, checkpoint_body, &
      & real_line, read_reals, next_line

   !> The first word of a checkpoint (its format's version).
   character(len=*), parameter :: checkpoint_magic = 'friction-checkpoint-3'

   !> The digits of real_line's numbers.
   character(len=16), parameter :: hex_digits = '0123456789abcdef'

contains

   !> Write `body` (whole lines) as the checkpoint at `path` for the input
   !> whose hash is `input_hash`, under its temporary name and not yet
   !> synced: publish_checkpoints then syncs many at once and renames them
   !> (an fsync a line costs as much as a short line's computation).  `problem` says why it could not
   !> be written ('' when written); a checkpoint that could not be written
   !> whole (a full disk) is removed, never renamed into place.
   subroutine write_checkpoint(path, input_hash, body, problem)
      character(len=*), intent(in) :: path, input_hash, body
      character(len=:), allocatable, intent(out) :: problem
      character(len=:), allocatable :: text

      text = checkpoint_magic//' input '//input_hash//new_line('a')//body
      text = text//'end '//itoa(count_lines(text))//' '//text_hash(text)//new_line('a')
      call write_bytes(path//'.tmp', text, problem, sync=.false.)
      if (len(problem) > 0) problem = path//': the checkpoint could not be written ('//problem//')'
   end subroutine write_checkpoint

   !> The checkpoints write_checkpoint wrote (all on one file system: beside
   !> one output), on disk and then under their names.  On a failure none
   !> that is not on disk is renamed, and the temporary files are removed.
   subroutine publish_checkpoints(paths, problem)
      character(len=*), intent(in) :: paths(:)
      character(len=:), allocatable, intent(out) :: problem
      type(error_type), allocatable :: save_error
      integer :: k

      problem = ''
      if (size(paths) == 0) return
      call sync_files(trim(paths(1))//'.tmp', problem)
      if (len(problem) > 0) then
         problem = trim(paths(1))//': the checkpoints could not be synced to disk ('//problem//')'
         call discard_checkpoints(paths)
         return
      end if
      do k = 1, size(paths)
         call rename_file(trim(paths(k))//'.tmp', trim(paths(k)), save_error)
         if (allocated(save_error)) then
            problem = save_error%message
            call discard_checkpoints(paths(k:))
            return
         end if
      end do
   end subroutine publish_checkpoints

   !> Remove the temporary files of checkpoints not published.
   subroutine discard_checkpoints(paths)
      character(len=*), intent(in) :: paths(:)
      integer :: k

      do k = 1, size(paths)
         call remove_file(trim(paths(k))//'.tmp')
      end do
   end subroutine discard_checkpoints

   !> The body of the checkpoint at `path` (what write_checkpoint was given),
   !> or why it cannot serve this run: written for another input (its hash
   !> is not `input_hash`), by another format, or damaged (not whole, or its
   !> checksum does not match).  No file: `problem` is '' and `body` is not
   !> allocated.
   subroutine checkpoint_body(path, input_hash, body, problem)
      character(len=*), intent(in) :: path, input_hash
      character(len=:), allocatable, intent(out) :: body
      character(len=:), allocatable, intent(out) :: problem
      character(len=:), allocatable :: text, whole, last
      integer :: cut, stat, n_lines, first_end
      character(len=16) :: sum_text
      logical :: ok

      problem = ''
      if (.not. file_exists(path)) return
      call read_whole(path, text, ok)
      if (.not. ok) then
         problem = path//': the checkpoint cannot be read'
         return
      end if
      ! The last line: 'end LINES CHECKSUM'.
      cut = 0
      if (len(text) > 1) cut = index(text(1:len(text) - 1), new_line('a'), back=.true.)
      if (len(text) == 0 .or. text(len(text):len(text)) /= new_line('a') .or. cut == 0) then
         problem = path//': the checkpoint is damaged (it does not end with its checksum line)'
         return
      end if
      whole = text(1:cut)
      last = text(cut + 1:len(text) - 1)
      n_lines = -1
      sum_text = ''
      if (last(1:min(4, len(last))) == 'end ') then
         read (last(5:), *, iostat=stat) n_lines, sum_text
         if (stat /= 0) n_lines = -1
      end if
      if (n_lines /= count_lines(whole) .or. sum_text /= text_hash(whole)) then
         problem = path//': the checkpoint is damaged (its line count or checksum does not match its content)'
         return
      end if
      first_end = index(whole, new_line('a'))
      if (whole(1:first_end - 1) /= checkpoint_magic//' input '//input_hash) then
         if (index(whole(1:first_end - 1), checkpoint_magic//' input ') == 1) then
            problem = path//': the checkpoint was written for another input (its resolved input, every ' &
               & //'group and the sweep, differs from this run''s)'
         else
            problem = path//': not a checkpoint of this version of friction'
         end if
         return
      end if
      body = whole(first_end + 1:)
   end subroutine checkpoint_body

   !> Numbers on one line, each the 16 hexadecimal digits of its bits and a
   !> blank (exact, and written without the runtime's formatting).
   pure function real_line(values) result(line)
      real(wp), intent(in) :: values(:)
      character(len=:), allocatable :: line
      integer(i8) :: bits
      integer :: k, d, at, nibble

      allocate (character(len=17 * size(values) + 1) :: line)
      at = 0
      do k = 1, size(values)
         bits = transfer(values(k), bits)
         do d = 15, 0, -1
            at = at + 1
            nibble = int(ibits(bits, 4 * d, 4)) + 1
            line(at:at) = hex_digits(nibble:nibble)
         end do
         at = at + 1
         line(at:at) = ' '
      end do
      line(at + 1:at + 1) = new_line('a')
   end function real_line

   !> The numbers real_line wrote on `line` (without its end): `ok` when it
   !> holds exactly size(values) of them.
   pure subroutine read_reals(line, values, ok)
      character(len=*), intent(in) :: line
      real(wp), intent(out) :: values(:)
      logical, intent(out) :: ok
      integer(i8) :: bits
      integer :: k, d, at, nibble

      values = 0.0_wp
      ok = len(line) == 17 * size(values)
      if (.not. ok) return
      at = 0
      do k = 1, size(values)
         bits = 0_i8
         do d = 1, 16
            at = at + 1
            nibble = index(hex_digits, line(at:at)) - 1
            if (nibble < 0) then
               ok = .false.
               return
            end if
            bits = ior(ishft(bits, 4), int(nibble, i8))
         end do
         at = at + 1
         if (line(at:at) /= ' ') then
            ok = .false.
            return
         end if
         values(k) = transfer(bits, values(k))
      end do
   end subroutine read_reals

   !> The line of `text` that starts at `at` (without its end), and `at`
   !> moved to the next one; '' past the end.
   function next_line(text, at) result(line)
      character(len=*), intent(in) :: text
      integer, intent(inout) :: at
      character(len=:), allocatable :: line
      integer :: next

      line = ''
      if (at > len(text)) return
      next = index(text(at:), new_line('a'))
      if (next == 0) then
         line = text(at:)
         at = len(text) + 1
      else
         line = text(at:at + next - 2)
         at = at + next
      end if
   end function next_line

   pure integer function count_lines(text) result(n)
      character(len=*), intent(in) :: text
      integer :: k

      n = 0
      do k = 1, len(text)
         if (text(k:k) == new_line('a')) n = n + 1
      end do
   end function count_lines

   !> The whole text of a file ('' with ok false when it cannot be read).
   subroutine read_whole(path, text, ok)
      character(len=*), intent(in) :: path
      character(len=:), allocatable, intent(out) :: text
      logical, intent(out) :: ok
      integer :: unit, stat
      integer(i8) :: bytes

      text = ''
      ok = .false.
      open (newunit=unit, file=path, status='old', action='read', form='unformatted', access='stream', iostat=stat)
      if (stat /= 0) return
      inquire (unit=unit, size=bytes)
      if (bytes < 0 .or. bytes > 1000000000_i8) then
         close (unit)
         return
      end if
      deallocate (text)
      allocate (character(len=int(bytes)) :: text)
      stat = 0
      if (bytes > 0) read (unit, iostat=stat) text
      close (unit)
      ok = stat == 0
   end subroutine read_whole

end module friction_output_checkpoint
