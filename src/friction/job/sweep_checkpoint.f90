!> Rank 0's checkpoint of a sweep, OUTPUT.ckpt (docs/sweeps.md): one HDF5
!> file of chunked columns indexed by point (output/h5_table.f90), into
!> which rank 0 writes the points it gathers a batch at a time, flushed
!> after each batch, and from which the output is copied at the end.
!>
!> Why a checkpoint file beside the output and not the output in progress:
!> points finish in an order that depends on the ranks, and a point's maxima
!> are a list of its own length; the output keeps them in one flat list in
!> point order (the documented layout, the same bits on any number of
!> ranks), which only a copy at the end can give.  The checkpoint keeps them
!> in the order they came, indexed by offset and count per point, each row
!> with a checksum that --resume checks.
module friction_job_sweep_checkpoint
   use friction_kinds, only: wp, i8
   use friction_clock, only: wall_seconds
   use friction_error, only: error_type, fatal_error, error_input, error_io
   use friction_strings, only: itoa, text_hash_bits
   use friction_output_checkpoint, only: real_line
   use friction_output_h5_table, only: h5_table
   use friction_files, only: remove_file, free_bytes, min_free_bytes, rename_file, full_text
   use friction_job_sweep_point, only: finished_point, status_pending, status_done, status_failed
   implicit none
   private

   public :: sweep_checkpoint, copy_points

   !> Points rank 0 gathers before it writes them to the checkpoint (and
   !> values of their series: the batch is written when either is reached).
   integer, parameter :: batch_points = 1024, batch_series = 1048576
   !> Seconds after which a batch is written however small (how much a
   !> killed run can lose).
   real(wp), parameter :: batch_seconds = 10.0_wp
   !> Points read at a time from the checkpoint (resume's checks, the copy
   !> into the output): what bounds the memory of a pass over all points.
   integer, parameter :: copy_points = 4096

   !> The kinds of the checkpoint's columns of column_names (h5_table's add_column).
   character(len=8), parameter :: column_kinds = 'iirlilil'

   !> Rank 0's points not yet in the checkpoint, in the order they came.
   type :: point_batch
      integer :: n = 0
      integer, allocatable :: point(:), status(:), series_count(:), reason_length(:)
      real(wp), allocatable :: results(:, :), cost(:)
      real(wp), allocatable :: series(:)
      integer :: n_series = 0
      character(len=:), allocatable :: reasons
      real(wp) :: since = 0.0_wp   !! when the last batch was written
   end type point_batch

   !> Rank 0's checkpoint: the file, this run's number, where its flat lists
   !> end, and the batch of points not yet in it.  The file, its path and
   !> the run are what the output's copy reads; the rest is its own.
   type :: sweep_checkpoint
      type(h5_table) :: file
      character(len=:), allocatable :: path
      integer :: run = 1
      character(len=:), allocatable, private :: hash   !! of the input it belongs to
      integer, private :: points = 0
      integer, private :: results = 0   !! per point, the sweep's own included
      logical, private :: opened = .false.
      integer(i8), private :: series_end = 0, reason_end = 0
      integer, private :: received = 0   !! points done in this run
      type(error_type), allocatable, private :: error   !! the first failure to write it
      type(point_batch), private :: batch
   contains
      procedure :: init => checkpoint_init
      procedure :: resume => checkpoint_resume
      procedure :: start_batch => checkpoint_start_batch
      procedure :: keep => checkpoint_keep
      procedure :: taken => checkpoint_taken
      procedure :: close => checkpoint_close
      procedure, private :: write_batch => checkpoint_write_batch
      procedure, private :: create => checkpoint_create
      procedure, private :: damaged_rows => checkpoint_damaged_rows
   end type sweep_checkpoint

contains

   !> The checkpoint of a sweep of `points` points of `results` results each,
   !> at `path`, for the input whose text_hash is `hash`; nothing is opened.
   subroutine checkpoint_init(self, path, hash, points, results)
      class(sweep_checkpoint), intent(inout) :: self
      character(len=*), intent(in) :: path, hash
      integer, intent(in) :: points, results

      self%path = path
      self%hash = hash
      self%points = points
      self%results = results
   end subroutine checkpoint_init

   !> Rank 0, before its first point: an empty batch.
   subroutine checkpoint_start_batch(self)
      class(sweep_checkpoint), intent(inout) :: self

      associate (batch => self%batch)
         allocate (batch%point(batch_points), batch%status(batch_points), batch%series_count(batch_points), &
            & batch%reason_length(batch_points), source=0)
         allocate (batch%results(self%results, batch_points), batch%cost(batch_points), source=0.0_wp)
         allocate (batch%series(1024))
         batch%reasons = ''
         batch%since = wall_seconds()
      end associate
   end subroutine checkpoint_start_batch

   !> Keep a finished point: into the batch, and the batch into the file
   !> when it is due (every add is followed by a write: a batch never overflows).
   subroutine checkpoint_keep(self, point)
      class(sweep_checkpoint), intent(inout) :: self
      type(finished_point), intent(in) :: point

      call add_point(self%batch, point)
      call self%write_batch(.false.)
   end subroutine checkpoint_keep

   !> The points this run has kept: those written and those in the batch.
   integer function checkpoint_taken(self) result(taken)
      class(sweep_checkpoint), intent(in) :: self

      taken = self%received + self%batch%n
   end function checkpoint_taken

   !> Write what the batch holds and close the file; a checkpoint that
   !> could not be written is an error (checkpoint_lost), for the points of
   !> this run are lost with it.
   subroutine checkpoint_close(self, error)
      class(sweep_checkpoint), intent(inout) :: self
      type(error_type), allocatable, intent(out) :: error

      call self%write_batch(.true.)
      if (self%opened) call self%file%close(error)
      if (allocated(error) .and. .not. allocated(self%error)) call move_alloc(error, self%error)
      if (allocated(self%error)) call fatal_error(error, checkpoint_lost(self), error_io)
   end subroutine checkpoint_close

   !> Append a finished point to the batch.
   subroutine add_point(batch, point)
      type(point_batch), intent(inout) :: batch
      type(finished_point), intent(in) :: point
      real(wp), allocatable :: grown(:)
      integer :: k, m, nres

      k = batch%n + 1
      nres = point%header(3)
      m = point%header(4)
      batch%point(k) = point%header(1)
      batch%status(k) = point%header(2)
      batch%series_count(k) = m
      batch%reason_length(k) = len(point%reason)
      batch%results(:, k) = point%numbers(1:nres)
      batch%cost(k) = point%numbers(nres + 1)
      if (batch%n_series + m > size(batch%series)) then
         allocate (grown(max(2 * size(batch%series), batch%n_series + m)))
         grown(1:batch%n_series) = batch%series(1:batch%n_series)
         call move_alloc(grown, batch%series)
      end if
      batch%series(batch%n_series + 1:batch%n_series + m) = point%numbers(nres + 2:nres + 1 + m)
      batch%n_series = batch%n_series + m
      batch%reasons = batch%reasons//point%reason
      batch%n = k
   end subroutine add_point

   !> Write the batch into the checkpoint (creating it at the first point)
   !> and flush it, when it is full, when it waited long enough, at the
   !> first point of a run, or always with `now`.
   subroutine checkpoint_write_batch(self, now)
      class(sweep_checkpoint), intent(inout) :: self
      logical, intent(in) :: now
      integer, allocatable :: order(:)
      integer(i8), allocatable :: series_offset(:), reason_offset(:), checksum(:)
      integer(i8) :: s, r
      integer :: k, a, b, j, s_in, r_in

      associate (batch => self%batch)
      if (batch%n == 0) return
      if (.not. (now .or. batch%n == batch_points .or. batch%n_series >= batch_series .or. self%received == 0 &
         & .or. wall_seconds() - batch%since >= batch_seconds)) return
      self%received = self%received + batch%n
      ! Not on a (nearly) full disk: a write that fails there leaves HDF5
      ! unable to close the file; with room to spare, the checkpoint closes.
      if (.not. allocated(self%error)) then
         if (.not. room_for(self%path, 8.0_wp * (batch%n_series + batch%n * (self%results + 8)) &
            & + len(batch%reasons))) then
            if (self%opened) call self%file%close(self%error)
            if (.not. allocated(self%error)) call fatal_error(self%error, self%path//': ' &
               & //full_text(self%path, free_bytes(self%path))//')', error_io)
            self%opened = .false.
            call remove_file(self%path)
         else if (.not. self%opened) then
            call self%create()
         end if
      end if
      if (allocated(self%error)) then
         batch%n = 0   ! nowhere to keep them: the run fails at its end
         batch%n_series = 0
         batch%reasons = ''
         return
      end if
      ! Each point's place in the flat lists, in the order they came.
      allocate (series_offset(batch%n), reason_offset(batch%n), checksum(batch%n))
      s = self%series_end
      r = self%reason_end
      s_in = 0
      r_in = 0
      do k = 1, batch%n
         series_offset(k) = s
         reason_offset(k) = r
         checksum(k) = point_checksum(batch%status(k), self%run, batch%cost(k), s, batch%series_count(k), r, &
            & batch%reason_length(k), batch%results(:, k), batch%series(s_in + 1:s_in + batch%series_count(k)), &
            & batch%reasons(r_in + 1:r_in + batch%reason_length(k)))
         s = s + batch%series_count(k)
         r = r + batch%reason_length(k)
         s_in = s_in + batch%series_count(k)
         r_in = r_in + batch%reason_length(k)
      end do
      call self%file%put('series', self%series_end, batch%series(1:batch%n_series))
      call self%file%put('reason', self%reason_end, batch%reasons)
      self%series_end = s
      self%reason_end = r
      ! The per-point columns, a run of consecutive points at a time.
      order = sorted_order(batch%point(1:batch%n))
      a = 1
      do while (a <= batch%n)
         b = a
         do while (b < batch%n)
            if (batch%point(order(b + 1)) /= batch%point(order(b)) + 1) exit
            b = b + 1
         end do
         associate (first => int(batch%point(order(a)) - 1, i8), pick => order(a:b))
            call self%file%put('status', first, batch%status(pick))
            call self%file%put('run', first, [(self%run, j = a, b)])
            call self%file%put('compute_time', first, batch%cost(pick))
            call self%file%put('series_offset', first, series_offset(pick))
            call self%file%put('series_count', first, batch%series_count(pick))
            call self%file%put('reason_offset', first, reason_offset(pick))
            call self%file%put('reason_length', first, batch%reason_length(pick))
            call self%file%put('checksum', first, checksum(pick))
            do j = 1, self%results
               call self%file%put('result'//itoa(j), first, batch%results(j, pick))
            end do
         end associate
         a = b + 1
      end do
      call self%file%flush()
      if (self%file%failed()) call self%file%close(self%error)
      ! A checkpoint that failed a write cannot be trusted: it goes, and the
      ! run fails at its end (checkpoint_lost).
      if (allocated(self%error)) then
         self%opened = .false.
         call remove_file(self%path)
      end if
      batch%n = 0
      batch%n_series = 0
      batch%reasons = ''
      batch%since = wall_seconds()
      end associate
   end subroutine checkpoint_write_batch

   !> Whether the disk at path has room for `bytes` more and min_free_bytes
   !> to spare (true where it cannot tell).
   logical function room_for(path, bytes)
      character(len=*), intent(in) :: path
      real(wp), intent(in) :: bytes
      real(wp) :: free

      free = free_bytes(path)
      room_for = free < 0.0_wp .or. free >= bytes + min_free_bytes
   end function room_for

   !> Why the run failed when its checkpoint could not be written: a full
   !> disk only when the disk is full (a damaged checkpoint that HDF5 cannot
   !> write into is not one).
   function checkpoint_lost(self) result(message)
      class(sweep_checkpoint), intent(in) :: self
      character(len=:), allocatable :: message
      real(wp) :: free
      logical :: full

      message = self%error%message
      free = free_bytes(self%path)
      full = free >= 0.0_wp .and. free < min_free_bytes
      if (full .and. index(message, ' free') == 0 .and. index(message, ' left') == 0) &
         & message = message//' ('//full_text(self%path, free)//')'
      message = message//'; the checkpoint could not be written and was removed (a failed write leaves it ' &
         & //'untrustworthy), and the points of this run are lost with it'
      if (full) then
         message = message//': run again when there is room'
      else
         message = message//' (the disk has room: a damaged checkpoint, or a file-size limit)'
      end if
   end function checkpoint_lost

   !> The permutation that sorts `keys` (a batch: insertion sort, as the
   !> points come nearly in order).
   function sorted_order(keys) result(order)
      integer, intent(in) :: keys(:)
      integer, allocatable :: order(:)
      integer :: k, j, held

      order = [(k, k = 1, size(keys))]
      do k = 2, size(keys)
         held = order(k)
         j = k - 1
         do while (j >= 1)
            if (keys(order(j)) <= keys(held)) exit
            order(j + 1) = order(j)
            j = j - 1
         end do
         order(j + 1) = held
      end do
   end function sorted_order

   !> A new checkpoint: the input's hash, the number of points and results,
   !> its columns (zeros: every point pending) and a reserve of
   !> reserve_bytes.  The reserve is what a full disk gives back: after a
   !> failed write the file is cut to no bytes before it is closed
   !> (h5_table's close), and closing needs room for what HDF5 still holds.
   !> Made under another name and renamed, so it appears whole, reserve and all.
   subroutine checkpoint_create(self)
      class(sweep_checkpoint), intent(inout) :: self
      integer, parameter :: reserve_bytes = 1048576
      character(len=:), allocatable :: fresh
      integer :: j
      integer(i8) :: n

      n = self%points
      fresh = self%path//'.new'
      call self%file%create(fresh, self%error)
      if (allocated(self%error)) return
      call self%file%set_text('/', 'input_hash', self%hash)
      call self%file%set_integer('/', 'points', n)
      call self%file%set_integer('/', 'results', int(self%results, i8))
      call self%file%set_integer('/', 'runs', int(self%run, i8))
      do j = 1, len(column_kinds)
         call self%file%add_column(trim(column_names(j)), column_kinds(j:j), n, '')
      end do
      do j = 1, self%results
         call self%file%add_column('result'//itoa(j), 'r', n, '')
      end do
      call self%file%add_column('series', 'r', -1_i8, '')
      call self%file%add_column('reason', 'b', -1_i8, '')
      call self%file%add_column('reserve', 'b', int(reserve_bytes, i8), '')
      call self%file%put('reserve', 0_i8, repeat(' ', reserve_bytes))
      call self%file%close(self%error)
      if (.not. allocated(self%error)) call rename_file(fresh, self%path, self%error)
      if (allocated(self%error)) then
         call remove_file(fresh)
         return
      end if
      call self%file%open(self%path, self%error)
      self%opened = .not. allocated(self%error)
      if (.not. self%opened) call remove_file(self%path)
   end subroutine checkpoint_create

   !> --resume: open the checkpoint, check it is of this input and whole, and
   !> list the points still to do (pending ones) in the file todo_path.
   subroutine checkpoint_resume(self, todo_path, n_todo, error)
      class(sweep_checkpoint), intent(inout) :: self
      character(len=*), intent(in) :: todo_path
      integer, intent(out) :: n_todo
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: ignored
      integer, allocatable :: status(:)
      character(len=:), allocatable :: problem
      integer :: unit, stat, first, count, k, j, n, n_results
      logical :: whole

      n = self%points
      n_results = self%results
      n_todo = 0
      call self%file%open(self%path, error)
      if (allocated(error)) then
         call fatal_error(error, self%path//': the checkpoint is damaged (it does not open as HDF5); remove it, ' &
            & //'and --resume computes every point again', error_input)
         return
      end if
      if (len(self%file%text('/', 'input_hash')) == 0 .or. self%file%integer('/', 'runs') < 1) then
         call self%file%close(ignored)
         call fatal_error(error, self%path//': the checkpoint is damaged (it lacks its input_hash or runs); ' &
            & //'remove it, and --resume computes every point again', error_input)
         return
      end if
      if (self%file%text('/', 'input_hash') /= self%hash) then
         call self%file%close(ignored)
         call fatal_error(error, self%path//': the checkpoint is of another input; --resume reuses only the ' &
            & //'checkpoint of the same input: run with the input of the interrupted run, or remove ' &
            & //self%path//' to start afresh', error_input)
         return
      end if
      whole = self%file%integer('/', 'points') == n .and. self%file%integer('/', 'results') == n_results &
         & .and. self%file%integer('/', 'runs') >= 1
      do k = 1, len(column_kinds)
         whole = whole .and. self%file%length(trim(column_names(k))) == n
      end do
      do j = 1, n_results
         whole = whole .and. self%file%length('result'//itoa(j)) == n
      end do
      whole = whole .and. self%file%length('series') >= 0 .and. self%file%length('reason') >= 0
      if (.not. whole) then
         call self%file%close(ignored)
         call fatal_error(error, self%path//': the checkpoint is damaged (its columns are not those of this ' &
            & //'sweep); remove it, and --resume computes every point again', error_input)
         return
      end if
      problem = self%damaged_rows()
      if (len(problem) > 0) then
         call self%file%close(ignored)
         call fatal_error(error, self%path//': the checkpoint is damaged ('//problem//'); remove it, and ' &
            & //'--resume computes every point again', error_input)
         return
      end if
      self%opened = .true.
      self%run = int(self%file%integer('/', 'runs')) + 1
      call self%file%set_integer('/', 'runs', int(self%run, i8))
      self%series_end = self%file%length('series')
      self%reason_end = self%file%length('reason')
      open (newunit=unit, file=todo_path, access='stream', form='unformatted', action='write', &
         & status='replace', iostat=stat)
      if (stat /= 0) then
         call fatal_error(error, todo_path//': cannot write the list of points to do', error_io)
         return
      end if
      allocate (status(copy_points))
      do first = 1, n, copy_points
         count = min(copy_points, n - first + 1)
         call self%file%get('status', int(first - 1, i8), status(1:count))
         do k = 1, count
            if (status(k) /= status_pending) cycle
            write (unit, iostat=stat) first + k - 1
            n_todo = n_todo + 1
         end do
      end do
      close (unit)
      if (self%file%failed()) then
         call self%file%close(ignored)
         call fatal_error(error, self%path//': the checkpoint is damaged (its statuses do not read); remove ' &
            & //'it, and --resume computes every point again', error_input)
      end if
   end subroutine checkpoint_resume

   !> The checksum of a point's row of the checkpoint: the 64-bit FNV-1a
   !> hash (text_hash_bits) of its numbers' bits as a map's line checkpoints
   !> write them (real_line), and of its reason.  A flipped bit or a changed
   !> value anywhere in the row, its series or its reason changes it.
   function point_checksum(status, run, cost, series_offset, series_count, reason_offset, reason_length, results, &
      & series, reason) result(bits)
      integer, intent(in) :: status, run, series_count, reason_length
      real(wp), intent(in) :: cost, results(:), series(:)
      integer(i8), intent(in) :: series_offset, reason_offset
      character(len=*), intent(in) :: reason
      integer(i8) :: bits

      bits = text_hash_bits(real_line([real(status, wp), real(run, wp), cost, real(series_offset, wp), &
         & real(series_count, wp), real(reason_offset, wp), real(reason_length, wp), results, series])//reason)
   end function point_checksum

   !> --resume: every point's row of the checkpoint against its checksum, a
   !> piece of copy_points points at a time; '' when all agree, else what
   !> is damaged (a status that is none of the three, a row that does not
   !> match its checksum, a row that points outside the flat lists).
   function checkpoint_damaged_rows(self) result(problem)
      class(sweep_checkpoint), intent(inout) :: self
      character(len=:), allocatable :: problem
      integer, allocatable :: status(:), run(:), series_count(:), reason_length(:)
      integer(i8), allocatable :: series_offset(:), reason_offset(:), checksum(:)
      real(wp), allocatable :: cost(:), results(:, :), series(:)
      character(len=:), allocatable :: reason
      integer(i8) :: series_end, reason_end
      integer :: first, piece, k, j, n, n_results

      n = self%points
      n_results = self%results
      problem = ''
      series_end = self%file%length('series')
      reason_end = self%file%length('reason')
      allocate (status(copy_points), run(copy_points), series_count(copy_points), reason_length(copy_points))
      allocate (series_offset(copy_points), reason_offset(copy_points), checksum(copy_points))
      allocate (cost(copy_points), results(copy_points, n_results))
      do first = 1, n, copy_points
         piece = min(copy_points, n - first + 1)
         associate (at => int(first - 1, i8), c => piece)
            call self%file%get('status', at, status(1:c))
            call self%file%get('run', at, run(1:c))
            call self%file%get('compute_time', at, cost(1:c))
            call self%file%get('series_offset', at, series_offset(1:c))
            call self%file%get('series_count', at, series_count(1:c))
            call self%file%get('reason_offset', at, reason_offset(1:c))
            call self%file%get('reason_length', at, reason_length(1:c))
            call self%file%get('checksum', at, checksum(1:c))
            do j = 1, n_results
               call self%file%get('result'//itoa(j), at, results(1:c, j))
            end do
         end associate
         if (self%file%failed()) then
            problem = 'its columns do not read'
            return
         end if
         do k = 1, piece
            if (status(k) == status_pending) cycle
            if (status(k) /= status_done .and. status(k) /= status_failed) then
               problem = 'point '//itoa(first + k - 1)//' has the status '//itoa(status(k))//', none of 0, 1, 2'
               return
            end if
            if (series_count(k) < 0 .or. reason_length(k) < 0 .or. series_offset(k) < 0 .or. reason_offset(k) < 0 &
               & .or. series_offset(k) + series_count(k) > series_end &
               & .or. reason_offset(k) + reason_length(k) > reason_end) then
               problem = 'point '//itoa(first + k - 1)//' points outside its series or reasons'
               return
            end if
            allocate (series(series_count(k)))
            allocate (character(len=reason_length(k)) :: reason)
            if (series_count(k) > 0) call self%file%get('series', series_offset(k), series)
            if (reason_length(k) > 0) call self%file%get('reason', reason_offset(k), reason)
            if (point_checksum(status(k), run(k), cost(k), series_offset(k), series_count(k), reason_offset(k), &
               & reason_length(k), results(k, :), series, reason) /= checksum(k) .or. self%file%failed()) then
               problem = 'point '//itoa(first + k - 1)//'''s values do not match their checksum'
               return
            end if
            deallocate (series, reason)
         end do
      end do
   end function checkpoint_damaged_rows

   !> The checkpoint's per-point columns besides the results.
   pure function column_names(k) result(name)
      integer, intent(in) :: k
      character(len=16) :: name
      character(len=16), parameter :: names(8) = [character(len=16) :: 'status', 'run', 'compute_time', &
         & 'series_offset', 'series_count', 'reason_offset', 'reason_length', 'checksum']

      name = names(k)
   end function column_names

end module friction_job_sweep_checkpoint
