!> The sweep's output file (docs/sweeps.md), written by rank 0 alone from
!> the checkpoint once the points are computed: the run's attributes, then
!> every column in point order, a piece of copy_points points at a time, so
!> that the copy holds no array over all points.
module friction_job_sweep_output
   use friction_parallel, only: self_comm, serial_comm
   use friction_kinds, only: wp, i8
   use friction_error, only: error_type
   use friction_strings, only: itoa
   use friction_ode_solver, only: step_type_names, step_type_name_length
   use friction_parameters, only: split_name, parameter_info, list_parameters
   use friction_scene, only: scene, point_result
   use friction_job_config, only: job_config, sweep_settings
   use friction_output_h5, only: h5_file
   use friction_output_h5_table, only: h5_table
   use friction_output_summary, only: run_summary, write_run_attributes
   use friction_files, only: file_exists
   use friction_job_sweep_point, only: point_names, status_pending, status_done, status_failed, method_result
   use friction_job_sweep_checkpoint, only: sweep_checkpoint, copy_points
   implicit none
   private

   public :: sweep_writer

   !> What the sweep's file holds besides the checkpoint's points: the
   !> sweep and its scene (from `describe`), the run's record and each
   !> rank's peak memory; `write` returns the counts and point 1's reason.
   type :: sweep_writer
      type(sweep_settings) :: sweep
      character(len=:), allocatable :: scene_name, method
      type(point_result), allocatable :: names(:)   !! a point's results (point_names)
      character(len=:), allocatable :: series_name, series_unit   !! '' when a point has no series
      character(len=:), allocatable :: units(:)   !! of the swept variables, as their configuration declares them
      type(run_summary) :: record
      integer, allocatable :: memory(:)   !! peak resident memory of each rank, kB
      logical :: interrupted = .false.
      logical :: parallel = .false.   !! on MPI (rank 0 writes on MPI_COMM_SELF), else serial
      integer :: counts(3) = 0   !! after `write`: points done, failed, computed in this run
      character(len=:), allocatable :: first_reason   !! after `write`: point 1's reason
   contains
      procedure :: describe => writer_describe
      procedure :: write => writer_write
   end type sweep_writer

contains

   !> The sweep and the scene of `config`, as the file describes them.
   subroutine writer_describe(self, config)
      class(sweep_writer), intent(inout) :: self
      type(job_config), intent(in) :: config
      integer :: k

      self%sweep = config%sweep
      self%scene_name = trim(config%scene_name)
      self%method = config%scene%method()
      self%names = point_names(config)
      call config%scene%point_series(self%series_name, self%series_unit)
      ! (As wide as a declared unit can be: parameter_info's.)
      allocate (character(len=40) :: self%units(config%sweep%n_variables))
      do k = 1, config%sweep%n_variables
         self%units(k) = variable_unit(config, k)
      end do
   end subroutine writer_describe

   !> The unit of swept variable k, as its configuration declares it.
   function variable_unit(config, k) result(unit)
      type(job_config), intent(in) :: config
      integer, intent(in) :: k
      character(len=:), allocatable :: unit
      type(parameter_info), allocatable :: list(:)
      character(len=:), allocatable :: group, variable
      class(scene), allocatable :: copy
      integer :: m

      unit = '1'
      allocate (copy, source=config%scene)
      list = list_parameters(copy)
      call split_name(config%sweep%variables(k), group, variable)
      do m = 1, size(list)
         if (list(m)%group == group .and. list(m)%name == variable .and. len_trim(list(m)%unit) > 0) &
            & unit = trim(list(m)%unit)
      end do
   end function variable_unit

   !> Write the sweep's file `path` from the checkpoint: the run's attributes
   !> first, then every column, a piece of copy_points points at a time in
   !> point order; then `counts` and `first_reason` say what it holds.
   subroutine writer_write(self, path, ckpt, error)
      class(sweep_writer), intent(inout) :: self
      character(len=*), intent(in) :: path
      type(sweep_checkpoint), intent(inout) :: ckpt
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: ignored
      type(h5_file) :: file
      type(h5_table) :: out
      character(len=:), allocatable :: name, texts(:)
      character(len=step_type_name_length), allocatable :: steppers(:)
      character(len=:), allocatable :: stepper(:)   !! as wide as the column (the memory type is the file's)
      integer, allocatable :: status(:), run(:), series_count(:), reason_length(:), whole(:)
      integer(i8), allocatable :: series_offset(:), reason_offset(:), out_offset(:)
      real(wp), allocatable :: cost(:), values(:), results(:), series(:), bytes(:)
      integer(i8) :: total, written
      integer :: n, k, j, first, piece, longest, a, b
      logical :: have

      n = self%sweep%points()
      self%counts = 0
      self%first_reason = ''
      ! The run's attributes and the small datasets, through the program's
      ! one file type; then the columns, streamed.
      call file%create(path, merge(self_comm(), serial_comm(), self%parallel), error)
      if (allocated(error)) return
      call write_run_attributes(file, 'sweep', self%method, self%record)
      call file%write_attribute_text('/', 'sweep_scene', self%scene_name)
      call file%write_attribute_text('/', 'sweep_variable', trim(self%sweep%variables(1)))
      if (self%sweep%n_variables == 2) &
         & call file%write_attribute_text('/', 'sweep_variable2', trim(self%sweep%variables(2)))
      call file%write_attribute_text('/', 'sweep_schedule', trim(self%sweep%schedule))
      call file%create_group('/sweep')
      call file%write_attribute_integer('/sweep', 'shape', int(self%sweep%shape(1), i8))
      call file%write_attribute_integer('/sweep', 'shape2', int(self%sweep%shape(2), i8))
      ! In bytes: UDUNITS knows no kibibyte (VmHWM's kB are 1024 bytes).
      bytes = 1024.0_wp * real(self%memory, wp)
      call file%write_vector('/sweep/peak_memory_per_rank', bytes, 'byte')
      call file%write_attribute_text('/sweep/peak_memory_per_rank', 'long_name', &
         & 'peak resident memory (VmHWM) of each rank; 0: unknown')
      call file%close(error)
      if (allocated(error)) return

      have = file_exists(ckpt%path)
      if (have) then
         call ckpt%file%open(ckpt%path, error)
         if (allocated(error)) return
      end if
      call out%open(path, error)
      if (allocated(error)) then
         if (have) call ckpt%file%close(ignored)
         return
      end if
      allocate (status(copy_points), run(copy_points), series_count(copy_points), reason_length(copy_points), &
         & whole(copy_points), source=0)
      allocate (series_offset(copy_points), reason_offset(copy_points), out_offset(copy_points), source=0_i8)
      allocate (cost(copy_points), values(copy_points), results(copy_points), source=0.0_wp)
      steppers = step_type_names()
      allocate (character(len=maxval(len_trim(steppers))) :: stepper(copy_points))
      ! First pass: the length of the flat series and of the longest reason.
      total = 0
      longest = 1
      if (have) then
         do first = 1, n, copy_points
            piece = min(copy_points, n - first + 1)
            call ckpt%file%get('series_count', int(first - 1, i8), series_count(1:piece))
            call ckpt%file%get('reason_length', int(first - 1, i8), reason_length(1:piece))
            total = total + sum(int(series_count(1:piece), i8))
            longest = max(longest, maxval(reason_length(1:piece)))
         end do
      end if
      do k = 1, self%sweep%n_variables
         name = merge('sweep/values ', 'sweep/values2', k == 1)
         call out%add_column(trim(name), 'r', int(n, i8), trim(self%units(k)))
         call out%set_text(trim(name), 'variable', trim(self%sweep%variables(k)))
      end do
      do j = 1, size(self%names)
         if (self%names(j)%name == method_result) then
            call out%add_text_column('sweep/'//method_result, len(stepper), int(n, i8))
            call out%set_text('sweep/'//method_result, 'meaning', 'the stepper the point ran (method = ''auto'' ' &
               & //'resolved for its own values); empty for a point that failed its check or is pending')
         else
            call out%add_column('sweep/'//trim(self%names(j)%name), merge('i', 'r', self%names(j)%whole), &
               & int(n, i8), trim(self%names(j)%unit))
         end if
      end do
      if (len(self%series_name) > 0) then
         call out%add_column('sweep/'//self%series_name, 'r', total, self%series_unit)
         call out%add_column('sweep/'//self%series_name//'_offset', 'l', int(n, i8), '')
         call out%add_column('sweep/'//self%series_name//'_count', 'i', int(n, i8), '')
      end if
      call out%add_column('sweep/status', 'i', int(n, i8), '')
      call out%set_text('sweep/status', 'meaning', '0 pending, 1 done, 2 failed')
      call out%add_text_column('sweep/reason', longest, int(n, i8))
      call out%set_text('sweep/reason', 'meaning', 'a failed point''s error message (empty otherwise)')
      call out%add_column('sweep/compute_time', 'r', int(n, i8), 's')
      call out%add_column('sweep/computed_by_this_run', 'i', int(n, i8), '')
      call describe_axes(out)
      allocate (character(len=longest) :: texts(copy_points))

      ! Second pass: every column, a piece at a time, in point order.
      written = 0
      do first = 1, n, copy_points
         piece = min(copy_points, n - first + 1)
         associate (at => int(first - 1, i8), c => piece)
            status(1:c) = status_pending
            run(1:c) = 0
            cost(1:c) = 0.0_wp
            series_count(1:c) = 0
            reason_length(1:c) = 0
            if (have) then
               call ckpt%file%get('status', at, status(1:c))
               call ckpt%file%get('run', at, run(1:c))
               call ckpt%file%get('compute_time', at, cost(1:c))
               call ckpt%file%get('series_offset', at, series_offset(1:c))
               call ckpt%file%get('series_count', at, series_count(1:c))
               call ckpt%file%get('reason_offset', at, reason_offset(1:c))
               call ckpt%file%get('reason_length', at, reason_length(1:c))
            end if
            do k = 1, self%sweep%n_variables
               do j = 1, c
                  values(j) = self%sweep%point_value(k, first + j - 1)
               end do
               name = merge('sweep/values ', 'sweep/values2', k == 1)
               call out%put(trim(name), at, values(1:c))
            end do
            do j = 1, size(self%names)
               results(1:c) = 0.0_wp
               if (have) call ckpt%file%get('result'//itoa(j), at, results(1:c))
               if (self%names(j)%name == method_result) then
                  do k = 1, c
                     stepper(k) = ''
                     if (nint(results(k)) >= 1 .and. nint(results(k)) <= size(steppers)) &
                        & stepper(k) = steppers(nint(results(k)))
                  end do
                  call out%put('sweep/'//method_result, at, stepper(1:c))
               else if (self%names(j)%whole) then
                  whole(1:c) = nint(results(1:c))
                  call out%put('sweep/'//trim(self%names(j)%name), at, whole(1:c))
               else
                  call out%put('sweep/'//trim(self%names(j)%name), at, results(1:c))
               end if
            end do
            ! The series of the piece, read a run of adjacent ones at a time.
            if (len(self%series_name) > 0) then
               allocate (series(sum(series_count(1:c))))
               b = 0
               a = 1
               do while (a <= c)
                  j = a
                  do while (j < c)
                     if (series_offset(j + 1) /= series_offset(j) + series_count(j)) exit
                     j = j + 1
                  end do
                  k = sum(series_count(a:j))
                  if (k > 0) call ckpt%file%get('series', series_offset(a), series(b + 1:b + k))
                  b = b + k
                  a = j + 1
               end do
               do j = 1, c
                  out_offset(j) = written
                  written = written + series_count(j)
               end do
               call out%put('sweep/'//self%series_name, out_offset(1), series)
               call out%put('sweep/'//self%series_name//'_offset', at, out_offset(1:c))
               call out%put('sweep/'//self%series_name//'_count', at, series_count(1:c))
               deallocate (series)
            end if
            do j = 1, c
               texts(j) = ''
               if (reason_length(j) > 0) call ckpt%file%get('reason', reason_offset(j), texts(j)(1:reason_length(j)))
            end do
            if (first == 1) self%first_reason = trim(texts(1))
            call out%put('sweep/status', at, status(1:c))
            call out%put('sweep/reason', at, texts(1:c))
            call out%put('sweep/compute_time', at, cost(1:c))
            whole(1:c) = merge(1, 0, run(1:c) == ckpt%run .and. status(1:c) /= status_pending)
            call out%put('sweep/computed_by_this_run', at, whole(1:c))
            call out%put('sweep/point', at, [(first + k - 1, k = 1, c)])
            self%counts(1) = self%counts(1) + count(status(1:c) == status_done)
            self%counts(2) = self%counts(2) + count(status(1:c) == status_failed)
            self%counts(3) = self%counts(3) + sum(whole(1:c))
         end associate
      end do
      call out%set_integer('sweep', 'complete', &
         & int(merge(0, 1, self%interrupted .and. self%counts(1) + self%counts(2) < n), i8))
      if (have) then
         call ckpt%file%close(error)
         if (allocated(error)) then
            call out%close(ignored)
            return
         end if
      end if
      call out%close(error)

   contains

      !> The points' own axis for netCDF readers: /sweep/point (1 to n) as
      !> the dimension scale of every per-point column, the swept values as
      !> their CF coordinates (a grid's two are not an axis each: the points
      !> are stored flat, the second variable fastest).
      subroutine describe_axes(out)
         type(h5_table), intent(inout) :: out
         character(len=:), allocatable :: along(:), coordinates
         integer :: i

         call out%add_column('sweep/point', 'i', int(n, i8), '1')
         call out%set_text('sweep/point', 'meaning', 'the point''s number, 1 to n, in the order of the points')
         coordinates = merge('values values2', 'values        ', self%sweep%n_variables == 2)
         along = [character(len=64) :: 'values', 'values2', (self%names(i)%name, i = 1, size(self%names)), &
            & 'status', 'reason', 'compute_time', 'computed_by_this_run']
         if (len(self%series_name) > 0) along = [character(len=64) :: along, self%series_name//'_offset', &
            & self%series_name//'_count']
         do i = 1, size(along)
            if (trim(along(i)) == 'values2' .and. self%sweep%n_variables < 2) cycle
            call out%attach_scales('sweep/'//trim(along(i)), ['sweep/point'])
            if (trim(along(i)) /= 'values' .and. trim(along(i)) /= 'values2') &
               & call out%set_text('sweep/'//trim(along(i)), 'coordinates', trim(coordinates))
         end do
      end subroutine describe_axes
   end subroutine writer_write

end module friction_job_sweep_output
