!> File-system operations Fortran lacks: atomic rename and removal through
!> the C library, so output appears under its final name only when complete,
!> and publication that never replaces a file it should not
!> (docs/reliability.md): without `replace` a file appears only if nothing is at its
!> name at that very moment (a hard link, which fails if the name exists);
!> with it, only a regular file is replaced, never a device, a directory or
!> a symbolic link.
module friction_files
   use, intrinsic :: iso_c_binding, only: c_int, c_char, c_null_char, c_double, c_long
   use friction_error, only: error_type, fatal_error, error_io, error_input
   use friction_strings, only: itoa, bytes_text
   implicit none
   private

   public :: rename_file, remove_file, file_exists, process_id, write_text_file, open_for_reading
   public :: path_kind, same_file, publish_file, truncate_file, output_problem, system_error_text, free_bytes
   public :: available_memory, write_bytes, min_free_bytes, full_text, size_limit_room
   public :: kind_none, kind_regular, kind_directory, kind_link, kind_other, kind_pipe, kind_unknown
   public :: read_text_line, max_line_length, sync_files

   !> Free space, bytes, below which no output is written: an HDF5 file that
   !> fails for a full disk can be closed (and so leave no handle open) only
   !> when its metadata, tens of kB, still finds room.
   real(c_double), parameter :: min_free_bytes = 1.0e6_c_double

   !> What path_kind finds at a path.
   integer, parameter :: kind_none = 0, kind_regular = 1, kind_directory = 2, kind_link = 3, kind_other = 4, &
      & kind_pipe = 5, kind_unknown = -1

   !> The longest line of an input text file (a namelist or an XYZ file):
   !> a longer one is refused as not text, so that a device or a stream
   !> without line ends (/dev/zero, a binary file) ends in an error, not in a
   !> read that fills the memory.
   integer, parameter :: max_line_length = 16 * 1048576

   interface
      function c_rename(from, to) result(stat) bind(c, name='rename')
         import :: c_int, c_char
         character(kind=c_char), intent(in) :: from(*), to(*)
         integer(c_int) :: stat
      end function c_rename

      function c_remove(path) result(stat) bind(c, name='remove')
         import :: c_int, c_char
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int) :: stat
      end function c_remove

      function c_path_kind(path, follow) result(kind) bind(c, name='friction_path_kind')
         import :: c_int, c_char
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int), value :: follow
         integer(c_int) :: kind
      end function c_path_kind

      function c_same_file(a, b) result(same) bind(c, name='friction_same_file')
         import :: c_int, c_char
         character(kind=c_char), intent(in) :: a(*), b(*)
         integer(c_int) :: same
      end function c_same_file

      function c_link(from, to) result(code) bind(c, name='friction_link')
         import :: c_int, c_char
         character(kind=c_char), intent(in) :: from(*), to(*)
         integer(c_int) :: code
      end function c_link

      function c_rename_noreplace(from, to) result(code) bind(c, name='friction_rename_noreplace')
         import :: c_int, c_char
         character(kind=c_char), intent(in) :: from(*), to(*)
         integer(c_int) :: code
      end function c_rename_noreplace

      function c_rename_errno(from, to) result(code) bind(c, name='friction_rename')
         import :: c_int, c_char
         character(kind=c_char), intent(in) :: from(*), to(*)
         integer(c_int) :: code
      end function c_rename_errno

      function c_unlink(path) result(code) bind(c, name='friction_unlink')
         import :: c_int, c_char
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int) :: code
      end function c_unlink

      function c_truncate(path) result(code) bind(c, name='friction_truncate')
         import :: c_int, c_char
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int) :: code
      end function c_truncate

      function c_errno_exists() result(code) bind(c, name='friction_errno_exists')
         import :: c_int
         integer(c_int) :: code
      end function c_errno_exists

      function c_size_limit_room(path) result(bytes) bind(c, name='friction_size_limit_room')
         import :: c_char, c_double
         character(kind=c_char), intent(in) :: path(*)
         real(c_double) :: bytes
      end function c_size_limit_room
      function c_free_bytes(path) result(bytes) bind(c, name='friction_free_bytes')
         import :: c_char, c_double
         character(kind=c_char), intent(in) :: path(*)
         real(c_double) :: bytes
      end function c_free_bytes

      function c_write_file(path, data, length, sync) result(code) bind(c, name='friction_write_file')
         import :: c_int, c_char, c_long
         character(kind=c_char), intent(in) :: path(*), data(*)
         integer(c_long), value :: length
         integer(c_int), value :: sync
         integer(c_int) :: code
      end function c_write_file

      function c_sync_files(path) result(code) bind(c, name='friction_sync_files')
         import :: c_int, c_char
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int) :: code
      end function c_sync_files

      subroutine c_error_text(code, buffer, size) bind(c, name='friction_error_text')
         import :: c_int, c_char
         integer(c_int), value :: code, size
         character(kind=c_char), intent(out) :: buffer(*)
      end subroutine c_error_text

      !> POSIX getpid (pid_t is an int on the platforms we build for).
      function c_getpid() result(pid) bind(c, name='getpid')
         import :: c_int
         integer(c_int) :: pid
      end function c_getpid
   end interface

contains

   !> Open an existing file to read: a missing file is bad input, one that
   !> cannot be opened an error of `category` (bad input by default).  Only
   !> a regular file (links followed), or a pipe with `pipe`, is opened: a
   !> directory, a device (/dev/zero would feed a read forever) or a socket
   !> is bad input.
   subroutine open_for_reading(path, unit, error, category, pipe)
      character(len=*), intent(in) :: path
      integer, intent(out) :: unit
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in), optional :: category
      logical, intent(in), optional :: pipe
      integer :: stat
      logical :: pipe_ok

      unit = -1
      pipe_ok = .false.
      if (present(pipe)) pipe_ok = pipe
      if (.not. file_exists(path)) then
         call fatal_error(error, path//': no such file', error_input)
         return
      end if
      select case (path_kind(path, follow=.true.))
      case (kind_directory)
         call fatal_error(error, path//': is a directory, not a file', error_input)
         return
      case (kind_other)
         if (pipe_ok) then
            call fatal_error(error, path//': is a device or socket, not a file; give a regular file or a pipe', &
               & error_input)
         else
            call fatal_error(error, path//': is a device or socket, not a file; give a regular file', error_input)
         end if
         return
      case (kind_pipe)
         if (.not. pipe_ok) then
            call fatal_error(error, path//': is a pipe, which can be read only once; give a regular file', &
               & error_input)
            return
         end if
      end select
      open (newunit=unit, file=path, status='old', action='read', iostat=stat)
      if (stat /= 0) then
         call fatal_error(error, path//': cannot open the file', error_input)
         if (present(category)) error%stat = category
      end if
   end subroutine open_for_reading

   !> One line of an input text file, however long (read in pieces without
   !> advancing), without its end.  stat < 0 at the end of the file, > 0 on
   !> a read error (`message` says which).  `problem` is set, with stat 0,
   !> when the line is not text: a control character other than tab, form
   !> feed and the CR of a CR LF line end (which becomes a blank), or more
   !> than max_line_length characters; the line is then read no further.  A
   !> last line without its newline still counts.
   subroutine read_text_line(unit, got, stat, message, problem)
      integer, intent(in) :: unit
      character(len=:), allocatable, intent(out) :: got
      integer, intent(out) :: stat
      character(len=*), intent(inout) :: message
      character(len=:), allocatable, intent(out) :: problem
      character(len=:), allocatable :: grown
      character(len=4096) :: piece
      integer :: size_read, used, i, code

      problem = ''
      allocate (character(len=4096) :: got)
      used = 0
      do
         read (unit, '(a)', advance='no', iostat=stat, iomsg=message, size=size_read) piece
         do i = 1, size_read
            code = iachar(piece(i:i))
            if (code == 13) then
               piece(i:i) = ' '
            else if (code < 32 .and. code /= 9 .and. code /= 12) then
               problem = 'control character (byte '//itoa(code)//') in column '//itoa(used + i) &
                  & //': not a text file'
               got = got(1:used)
               stat = 0
               return
            end if
         end do
         if (used + size_read > max_line_length) then
            problem = 'a line longer than '//itoa(max_line_length / 1048576)//' Mi characters: not a text file'
            got = got(1:used)
            stat = 0
            return
         end if
         if (used + size_read > len(got)) then
            allocate (character(len=max(2 * len(got), used + size_read)) :: grown)
            grown(1:used) = got(1:used)
            call move_alloc(grown, got)
         end if
         got(used + 1:used + size_read) = piece(1:size_read)
         used = used + size_read
         if (is_iostat_eor(stat)) then
            stat = 0
            exit
         end if
         if (stat /= 0) then
            if (is_iostat_end(stat) .and. used > 0) stat = 0
            exit
         end if
      end do
      got = got(1:used)
   end subroutine read_text_line

   logical function file_exists(path)
      character(len=*), intent(in) :: path

      inquire (file=path, exist=file_exists)
   end function file_exists

   !> What is at `path`: kind_none, kind_regular, kind_directory, kind_link,
   !> kind_other (a device, pipe or socket) or kind_unknown.  A symbolic link
   !> is reported as such unless `follow`.
   integer function path_kind(path, follow)
      character(len=*), intent(in) :: path
      logical, intent(in), optional :: follow
      integer(c_int) :: through

      through = 0
      if (present(follow)) through = merge(1, 0, follow)
      path_kind = int(c_path_kind(path//c_null_char, through))
   end function path_kind

   !> Whether both paths name one existing file (links followed).
   logical function same_file(a, b)
      character(len=*), intent(in) :: a, b

      same_file = c_same_file(a//c_null_char, b//c_null_char) /= 0
   end function same_file

   !> The C library's text for an errno value.
   function system_error_text(code) result(text)
      integer, intent(in) :: code
      character(len=:), allocatable :: text
      character(kind=c_char) :: buffer(200)
      integer :: n

      buffer = c_null_char
      call c_error_text(int(code, c_int), buffer, int(size(buffer), c_int))
      n = findloc(buffer, c_null_char, dim=1) - 1
      if (n < 0) n = size(buffer)
      allocate (character(len=n) :: text)
      text = transfer(buffer(1:n), text)
   end function system_error_text

   !> Why `path` cannot be an output ('' when it can): a symbolic link (never
   !> followed nor replaced), a directory, a device, pipe or socket, or a
   !> regular file without `replace`.
   function output_problem(path, replace) result(problem)
      character(len=*), intent(in) :: path
      logical, intent(in) :: replace
      character(len=:), allocatable :: problem

      problem = ''
      select case (path_kind(path))
      case (kind_link)
         problem = 'is a symbolic link; friction neither follows nor replaces links, so name the file itself'
      case (kind_directory)
         problem = 'is a directory'
      case (kind_other, kind_pipe)
         problem = 'is not a regular file (a device, pipe or socket); friction writes only regular files ' &
            & //'and --force replaces only a regular file'
      case (kind_regular)
         if (.not. replace) problem = 'the output file exists; use --force to overwrite it'
      end select
   end function output_problem

   !> Give the complete file `from` its final name `to`.  Without `replace`
   !> the name is taken only if nothing holds it at that moment: a hard link
   !> (link(2) fails if `to` exists), then `from` removed; where the file
   !> system has no hard links, rename(2) with RENAME_NOREPLACE.  With
   !> `replace`, `to` may be nothing or a regular file, replaced atomically by
   !> rename(2).  On failure `from` is left in place (the caller decides).
   subroutine publish_file(from, to, replace, error)
      character(len=*), intent(in) :: from, to
      logical, intent(in) :: replace
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: problem
      integer :: code, eexist

      eexist = int(c_errno_exists())
      ! (Without `replace` an existing name of any kind makes link(2) fail.)
      problem = ''
      if (replace) problem = output_problem(to, replace)
      if (len(problem) > 0) then
         call fatal_error(error, to//': '//problem, error_io)
         return
      end if
      if (replace) then
         code = c_rename_errno(from//c_null_char, to//c_null_char)
         if (code /= 0) call fatal_error(error, 'cannot rename '//from//' to '//to//' (' &
            & //system_error_text(code)//')', error_io)
         return
      end if
      code = c_link(from//c_null_char, to//c_null_char)
      if (code == 0) then
         code = c_unlink(from//c_null_char)
         return
      end if
      if (code /= eexist) code = c_rename_noreplace(from//c_null_char, to//c_null_char)
      if (code == 0) return
      if (code == eexist) then
         call fatal_error(error, to//': the output file appeared while this run computed (another run?) and is ' &
            & //'not overwritten; use --force to overwrite it', error_io)
      else
         call fatal_error(error, 'cannot give '//from//' the name '//to//' without the risk of replacing a file ' &
            & //'(' //system_error_text(code)//')', error_io)
      end if
   end subroutine publish_file

   !> Bytes that may still be written on the file system of `path` (or of
   !> its directory); negative when unknown.
   real(c_double) function free_bytes(path)
      character(len=*), intent(in) :: path

      free_bytes = c_free_bytes(path//c_null_char)
   end function free_bytes

   !> Bytes the process's file-size limit (`ulimit -f`) still lets the file
   !> at path grow by; negative without a limit.
   real(c_double) function size_limit_room(path)
      character(len=*), intent(in) :: path

      size_limit_room = c_size_limit_room(path//c_null_char)
   end function size_limit_room

   !> Why there is no room for the file at path, `free` (free_bytes) being
   !> too little, for messages: 'the disk is full (X free', or, when the
   !> process's file-size limit is what leaves so little, 'the file-size
   !> limit (ulimit -f) is reached (X left'.  The caller closes the bracket.
   function full_text(path, free) result(text)
      character(len=*), intent(in) :: path
      real(c_double), intent(in) :: free
      character(len=:), allocatable :: text
      real(c_double) :: limit

      limit = c_size_limit_room(path//c_null_char)
      if (limit >= 0.0_c_double .and. limit <= free) then
         text = 'the file-size limit (ulimit -f) is reached ('//bytes_text(free)//' left'
      else
         text = 'the disk is full ('//bytes_text(free)//' free'
      end if
   end function full_text

   !> Memory this machine can still give a process without swapping, bytes
   !> (MemAvailable of /proc/meminfo); negative when unknown.
   real(c_double) function available_memory() result(bytes)
      character(len=256) :: line
      integer :: unit, stat
      real(c_double) :: kb

      bytes = -1.0_c_double
      open (newunit=unit, file='/proc/meminfo', status='old', action='read', iostat=stat)
      if (stat /= 0) return
      do
         read (unit, '(a)', iostat=stat) line
         if (stat /= 0) exit
         if (line(1:13) == 'MemAvailable:') then
            read (line(14:), *, iostat=stat) kb
            if (stat == 0) bytes = 1024.0_c_double * kb
            exit
         end if
      end do
      close (unit)
   end function available_memory

   !> Cut a file to no bytes, best effort (gives back a full disk's space).
   subroutine truncate_file(path)
      character(len=*), intent(in) :: path
      integer(c_int) :: code

      code = c_truncate(path//c_null_char)
   end subroutine truncate_file

   !> Rename atomically (within one file system), replacing `to` if present.
   subroutine rename_file(from, to, error)
      character(len=*), intent(in) :: from, to
      type(error_type), allocatable, intent(out) :: error

      if (c_rename(from//c_null_char, to//c_null_char) /= 0) &
         & call fatal_error(error, 'cannot rename '//from//' to '//to, error_io)
   end subroutine rename_file

   !> Remove a file if it exists; failures are ignored (best effort cleanup).
   subroutine remove_file(path)
      character(len=*), intent(in) :: path
      integer(c_int) :: stat

      if (file_exists(path)) stat = c_remove(path//c_null_char)
   end subroutine remove_file

   !> This process's id, to make temporary file names unique.
   integer function process_id()
      process_id = int(c_getpid())
   end function process_id


   !> Write text as the whole content of a new file at `path` (replacing a
   !> file there), every step checked through the C library (gfortran's own
   !> writes report success on a full disk); `problem` says what failed ('' on
   !> success), and a file not written whole is removed.
   subroutine write_bytes(path, text, problem, sync)
      character(len=*), intent(in) :: path, text
      character(len=:), allocatable, intent(out) :: problem
      logical, intent(in), optional :: sync   !! .false.: no fsync; sync_files after many such writes
      integer :: code
      integer(c_int) :: flag

      flag = 1
      if (present(sync)) flag = merge(1, 0, sync)
      code = int(c_write_file(path//c_null_char, text, int(len(text), c_long), flag))
      problem = ''
      if (code /= 0) problem = system_error_text(code)
   end subroutine write_bytes

   !> The files written without sync (write_bytes) to the file system that
   !> holds `path`, on disk at once; `problem` says why not ('' when done).
   subroutine sync_files(path, problem)
      character(len=*), intent(in) :: path
      character(len=:), allocatable, intent(out) :: problem
      integer :: code

      code = int(c_sync_files(path//c_null_char))
      problem = ''
      if (code /= 0) problem = system_error_text(code)
   end subroutine sync_files

   !> Write text to path, complete or not at all (a temporary name beside it,
   !> published when written; see publish_file for `replace`, default true).
   subroutine write_text_file(path, text, error, replace)
      character(len=*), intent(in) :: path, text
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: replace
      character(len=:), allocatable :: temporary, problem
      logical :: may_replace

      may_replace = .true.
      if (present(replace)) may_replace = replace
      temporary = path//'.tmp-'//itoa(process_id())
      call write_bytes(temporary, text, problem)
      if (len(problem) > 0) then
         call fatal_error(error, path//': writing failed ('//problem//')', error_io)
         return
      end if
      call publish_file(temporary, path, may_replace, error)
      if (allocated(error)) call remove_file(temporary)
   end subroutine write_text_file

end module friction_files
