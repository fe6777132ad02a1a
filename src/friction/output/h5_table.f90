!> An HDF5 file of 1-D columns written and read a range at a time by one
!> process: the sweep's checkpoint and its streamed output (docs/sweeps.md).
!> Every column is chunked, so a column of a million points is written in
!> pieces as they come and the writer holds only the piece in hand; a
!> column made with n < 0 is extendible (a flat list that grows by appends).
!>
!> A column takes all its space when it is made (or extended), filled with
!> zeros, and only after the disk and the file-size limit were found to
!> have room for it with min_free_bytes to spare: its writes then land in
!> space the file already holds and cannot fail for room.  A chunk write
!> that fails (a full disk, EFBIG past `ulimit -f`) makes HDF5 1.10 keep
!> the chunk's buffer: at exit it cannot close its library and prints
!> "infinite loop closing library" with a dump, or crashes; a column whose
!> making fails leaves nothing behind.
!>
!> One process, no MPI-IO: the file is opened with HDF5's default driver
!> (the parallel library serves that too).  Failures are kept, as h5_file
!> keeps them, and reported by close (or `failed`); HDF5's own printing is
!> switched off around each call and restored.
module friction_output_h5_table
   use, intrinsic :: iso_fortran_env, only: int8, int32, int64
   use, intrinsic :: iso_c_binding, only: c_ptr, c_loc, c_null_ptr, c_double
   use hdf5
   use friction_kinds, only: wp, i8
   use friction_error, only: error_type, fatal_error, error_io
   use friction_files, only: truncate_file, free_bytes, min_free_bytes, full_text
   use friction_strings, only: bytes_text
   use friction_output_h5, only: h5_status, error_printing, room_to_close, new_text_attribute, new_scalar_attribute, &
      & open_hdf5, attach_dimension_scales
   use friction_output_units, only: plain_unit, mentions_tau
   implicit none
   private

   public :: h5_table

   !> Points per chunk of a column: 4096 doubles = 32 kB, HDF5's sweet spot
   !> for its chunk cache (1 MB per open dataset).
   integer(hsize_t), parameter :: chunk_points = 4096

   type, extends(h5_status) :: h5_table
      private
      integer(hid_t) :: id = -1
      character(len=:), allocatable :: path
      logical :: read_only = .false.   !! opened to read another program's file: never cut, never written
   contains
      procedure :: create => table_create
      procedure :: open => table_open
      procedure :: close => table_close
      procedure :: flush => table_flush
      procedure :: failed => table_failed
      procedure :: add_column
      procedure :: add_text_column
      procedure :: length
      procedure, private :: put_real, put_int, put_long, put_bytes, put_text
      generic :: put => put_real, put_int, put_long, put_bytes, put_text
      procedure, private :: get_real, get_int, get_long, get_bytes
      generic :: get => get_real, get_int, get_long, get_bytes
      procedure :: attach_scales => table_attach_scales
      procedure :: set_text => set_text_attribute
      procedure :: text => text_attribute
      procedure :: set_integer => set_integer_attribute
      procedure :: integer => integer_attribute
      procedure, private :: transfer_range
   end type h5_table

contains

   !> Create (truncate) the file at path.
   subroutine table_create(self, path, error)
      class(h5_table), intent(inout) :: self
      character(len=*), intent(in) :: path
      type(error_type), allocatable, intent(out) :: error
      type(error_printing) :: printing
      integer :: stat

      self%path = path
      self%status = 0
      call printing%silence()
      call open_hdf5(stat)
      call h5fcreate_f(path, H5F_ACC_TRUNC_F, self%id, stat)
      call self%check(stat, 'creating the file')
      call printing%restore()
      if (self%status /= 0) call fatal_error(error, path//': HDF5 failed '//self%failed_at, error_io)
   end subroutine table_create

   !> Open an existing file at path for reading and writing, or for reading
   !> only (read_only: a file this program did not make, left as it is
   !> whatever fails).
   subroutine table_open(self, path, error, read_only)
      class(h5_table), intent(inout) :: self
      character(len=*), intent(in) :: path
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: read_only
      type(error_printing) :: printing
      integer :: stat

      self%path = path
      self%status = 0
      self%read_only = .false.
      if (present(read_only)) self%read_only = read_only
      call printing%silence()
      call open_hdf5(stat)
      if (self%read_only) then
         call h5fopen_f(path, H5F_ACC_RDONLY_F, self%id, stat)
      else
         call h5fopen_f(path, H5F_ACC_RDWR_F, self%id, stat)
      end if
      if (stat /= 0) self%id = -1
      call self%check(stat, 'opening the file')
      call printing%restore()
      if (self%status /= 0) call fatal_error(error, path//': not an HDF5 file that opens (damaged?)', error_io)
   end subroutine table_open

   !> Write what HDF5 holds in memory to the file, so that the file on disk
   !> is whole as it stands (the checkpoint's promise).
   subroutine table_flush(self)
      class(h5_table), intent(inout) :: self
      type(error_printing) :: printing
      character(len=:), allocatable :: problem
      integer :: stat

      if (self%status /= 0 .or. self%id < 0) return
      problem = room_to_close(self%id, self%path)
      if (len(problem) > 0) then
         call self%check(1, problem)
         return
      end if
      call printing%silence()
      call h5fflush_f(self%id, H5F_SCOPE_GLOBAL_F, stat)
      call self%check(stat, 'flushing the file')
      call printing%restore()
   end subroutine table_flush

   logical function table_failed(self)
      class(h5_table), intent(in) :: self

      table_failed = self%status /= 0
   end function table_failed

   !> Close; report the first failure since create or open.
   subroutine table_close(self, error)
      class(h5_table), intent(inout) :: self
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: problem
      type(error_printing) :: printing
      integer :: stat

      if (self%id >= 0 .and. self%status == 0 .and. .not. self%read_only) then
         problem = room_to_close(self%id, self%path)
         if (len(problem) > 0) call self%check(1, problem)
      end if
      call printing%silence()
      if (self%id >= 0) then
         ! After a failed write (a full disk) the file is cut to no bytes
         ! first: that gives its space back, so closing, which writes what
         ! HDF5 still holds, succeeds and leaves no handle open (HDF5's
         ! clean-up at exit would crash on one).  Such a file is for removal.
         if (self%status /= 0 .and. .not. self%read_only) call truncate_file(self%path)
         call h5fclose_f(self%id, stat)
         call self%check(stat, 'closing the file')
         self%id = -1
      end if
      call printing%restore()
      if (self%status /= 0) call fatal_error(error, self%path//': HDF5 failed '//self%failed_at, error_io)
   end subroutine table_close

   !> Whether the disk and the file-size limit leave room for a column
   !> growing from `from` to `to` elements of `type` in chunks of `chunk`,
   !> with min_free_bytes to spare for what HDF5 writes at its close; if not,
   !> the failure of `what` is kept.
   logical function has_room(self, what, type, chunk, from, to)
      class(h5_table), intent(inout) :: self
      character(len=*), intent(in) :: what
      integer(hid_t), intent(in) :: type
      integer(hsize_t), intent(in) :: chunk, from, to
      integer(size_t) :: bytes
      integer :: stat
      real(c_double) :: free, needed

      call h5tget_size_f(type, bytes, stat)
      needed = real((to + chunk - 1) / chunk - (from + chunk - 1) / chunk, c_double) * real(chunk, c_double) &
         & * real(bytes, c_double)
      free = free_bytes(self%path)
      has_room = free < 0.0_c_double .or. free >= needed + min_free_bytes
      if (.not. has_room) call self%check(1, what//': '//full_text(self%path, free)//'; it needs ' &
         & //bytes_text(needed)//' and '//bytes_text(min_free_bytes)//' to spare)')
   end function has_room

   !> The HDF5 type of a column kind: 'r' double, 'i' 32-bit integer, 'l'
   !> 64-bit integer, 'b' byte (text as bytes).
   integer(hid_t) function kind_type(kind) result(type)
      character, intent(in) :: kind

      select case (kind)
      case ('r')
         type = H5T_NATIVE_DOUBLE
      case ('i')
         type = h5kind_to_type(int32, H5_INTEGER_KIND)
      case ('l')
         type = h5kind_to_type(int64, H5_INTEGER_KIND)
      case default
         type = h5kind_to_type(int8, H5_INTEGER_KIND)
      end select
   end function kind_type

   !> A chunked column of n zeros (n < 0: extendible, of none yet), with a
   !> units attribute unless units is blank (a UDUNITS string, as h5_file writes it).
   subroutine add_column(self, name, kind, n, units)
      class(h5_table), intent(inout) :: self
      character(len=*), intent(in) :: name, units
      character, intent(in) :: kind
      integer(i8), intent(in) :: n

      call make_column(self, name, kind_type(kind), n, units)
   end subroutine add_column

   !> A chunked column of n fixed-width UTF-8 texts of `width` characters.
   subroutine add_text_column(self, name, width, n)
      class(h5_table), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer, intent(in) :: width
      integer(i8), intent(in) :: n
      integer(hid_t) :: type
      integer :: stat

      call h5tcopy_f(H5T_FORTRAN_S1, type, stat)
      call h5tset_size_f(type, int(max(1, width), size_t), stat)
      call h5tset_cset_f(type, H5T_CSET_UTF8_F, stat)
      call make_column(self, name, type, n, '')
      call h5tclose_f(type, stat)
   end subroutine add_text_column

   subroutine make_column(self, name, type, n, units)
      class(h5_table), intent(inout) :: self
      character(len=*), intent(in) :: name, units
      integer(hid_t), intent(in) :: type
      integer(i8), intent(in) :: n
      integer(hid_t) :: space, plist, dset
      integer(hsize_t) :: dims(1), maxdims(1), chunk(1)
      integer :: stat
      character(len=:), allocatable :: what
      type(error_printing) :: printing

      if (self%status /= 0) return
      dims = int(max(0_i8, n), hsize_t)
      maxdims = dims
      if (n < 0) maxdims = H5S_UNLIMITED_F
      chunk = max(1_hsize_t, min(chunk_points, dims))
      if (n < 0) chunk = chunk_points
      if (.not. has_room(self, 'creating dataset '//name, type, chunk(1), 0_hsize_t, dims(1))) return
      call printing%silence()
      call h5screate_simple_f(1, dims, space, stat, maxdims)
      call h5pcreate_f(H5P_DATASET_CREATE_F, plist, stat)
      call h5pset_chunk_f(plist, 1, chunk, stat)
      call h5pset_alloc_time_f(plist, H5D_ALLOC_TIME_EARLY_F, stat)
      call h5dcreate_f(self%id, name, type, space, dset, stat, dcpl_id=plist)
      call self%check(stat, 'creating dataset '//name)
      if (stat == 0) then
         if (len_trim(units) > 0) then
            call new_text_attribute(dset, 'units', plain_unit(units), stat, what)
            call self%check(stat, what)
            if (mentions_tau(units)) then
               call new_text_attribute(dset, 'units_tau', trim(units), stat, what)
               call self%check(stat, what)
            end if
         end if
         call h5dclose_f(dset, stat)
      end if
      call h5pclose_f(plist, stat)
      call h5sclose_f(space, stat)
      call printing%restore()
   end subroutine make_column

   !> The number of elements of column name (-1 where there is none).
   integer(i8) function length(self, name)
      class(h5_table), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer(hid_t) :: dset, space
      integer(hsize_t) :: dims(1), maxdims(1)
      integer :: stat
      type(error_printing) :: printing

      length = -1
      if (self%status /= 0) return
      call printing%silence()
      call h5dopen_f(self%id, name, dset, stat)
      if (stat == 0) then
         call h5dget_space_f(dset, space, stat)
         call h5sget_simple_extent_dims_f(space, dims, maxdims, stat)
         if (stat == 1) length = int(dims(1), i8)
         call h5sclose_f(space, stat)
         call h5dclose_f(dset, stat)
      end if
      call printing%restore()
   end function length

   !> Write (write = .true.) or read `count` elements of column name from
   !> element `first` (0-based) at `buffer`; a write past the end of an
   !> extendible column extends it.
   subroutine transfer_range(self, name, type, first, count, buffer, write)
      class(h5_table), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer(hid_t), intent(in) :: type
      integer(i8), intent(in) :: first, count
      type(c_ptr), intent(in) :: buffer
      logical, intent(in) :: write
      integer(hid_t) :: dset, filespace, memspace, file_type
      integer(hsize_t) :: dims(1), maxdims(1), offset(1), counts(1)
      integer :: stat
      type(c_ptr) :: target
      type(error_printing) :: printing

      if (self%status /= 0 .or. count <= 0) return
      call printing%silence()
      call h5dopen_f(self%id, name, dset, stat)
      call self%check(stat, 'opening dataset '//name)
      if (stat == 0) then
         offset = int(first, hsize_t)
         counts = int(count, hsize_t)
         call h5dget_space_f(dset, filespace, stat)
         call h5sget_simple_extent_dims_f(filespace, dims, maxdims, stat)
         ! A text column's type is its own (its width); numbers convert.
         file_type = type
         if (type == -1) call h5dget_type_f(dset, file_type, stat)
         if (write .and. offset(1) + counts(1) > dims(1)) then
            call h5sclose_f(filespace, stat)
            if (has_room(self, 'extending dataset '//name, file_type, chunk_points, dims(1), offset(1) + counts(1))) &
               & then
               call h5dset_extent_f(dset, offset + counts, stat)
               call self%check(stat, 'extending dataset '//name)
            end if
            call h5dget_space_f(dset, filespace, stat)
         end if
         call h5sselect_hyperslab_f(filespace, H5S_SELECT_SET_F, offset, counts, stat)
         call h5screate_simple_f(1, counts, memspace, stat)
         if (self%status == 0) then
            if (write) then
               call h5dwrite_f(dset, file_type, buffer, stat, mem_space_id=memspace, file_space_id=filespace)
               call self%check(stat, 'writing dataset '//name)
            else
               target = buffer   ! (HDF5 takes the address inout)
               call h5dread_f(dset, file_type, target, stat, mem_space_id=memspace, file_space_id=filespace)
               call self%check(stat, 'reading dataset '//name)
            end if
         end if
         if (type == -1) call h5tclose_f(file_type, stat)
         call h5sclose_f(memspace, stat)
         call h5sclose_f(filespace, stat)
         call h5dclose_f(dset, stat)
      end if
      call printing%restore()
   end subroutine transfer_range

   subroutine put_real(self, name, first, values)
      class(h5_table), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer(i8), intent(in) :: first
      real(wp), intent(in), target, contiguous :: values(:)

      if (size(values) > 0) call self%transfer_range(name, H5T_NATIVE_DOUBLE, first, size(values, kind=i8), &
         & c_loc(values), .true.)
   end subroutine put_real

   subroutine put_int(self, name, first, values)
      class(h5_table), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer(i8), intent(in) :: first
      integer(int32), intent(in), target, contiguous :: values(:)

      if (size(values) > 0) call self%transfer_range(name, kind_type('i'), first, size(values, kind=i8), &
         & c_loc(values), .true.)
   end subroutine put_int

   subroutine put_long(self, name, first, values)
      class(h5_table), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer(i8), intent(in) :: first
      integer(int64), intent(in), target, contiguous :: values(:)

      if (size(values) > 0) call self%transfer_range(name, kind_type('l'), first, size(values, kind=i8), &
         & c_loc(values), .true.)
   end subroutine put_long

   !> Text as bytes into a byte column.
   subroutine put_bytes(self, name, first, text)
      class(h5_table), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer(i8), intent(in) :: first
      character(len=*), intent(in) :: text
      integer(int8), allocatable, target :: bytes(:)
      integer :: k

      if (len(text) == 0) return
      allocate (bytes(len(text)))
      do k = 1, len(text)
         bytes(k) = int(transfer(text(k:k), 0_int8), int8)
      end do
      call self%transfer_range(name, kind_type('b'), first, size(bytes, kind=i8), c_loc(bytes), .true.)
   end subroutine put_bytes

   !> Fixed-width texts into a text column (each blank-padded to its width).
   subroutine put_text(self, name, first, texts)
      class(h5_table), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer(i8), intent(in) :: first
      character(len=*), intent(in), target, contiguous :: texts(:)

      if (size(texts) > 0) call self%transfer_range(name, -1_hid_t, first, size(texts, kind=i8), c_loc(texts), &
         & .true.)
   end subroutine put_text

   subroutine get_real(self, name, first, values)
      class(h5_table), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer(i8), intent(in) :: first
      real(wp), intent(out), target, contiguous :: values(:)

      if (size(values) > 0) call self%transfer_range(name, H5T_NATIVE_DOUBLE, first, size(values, kind=i8), &
         & c_loc(values), .false.)
   end subroutine get_real

   subroutine get_int(self, name, first, values)
      class(h5_table), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer(i8), intent(in) :: first
      integer(int32), intent(out), target, contiguous :: values(:)

      if (size(values) > 0) call self%transfer_range(name, kind_type('i'), first, size(values, kind=i8), &
         & c_loc(values), .false.)
   end subroutine get_int

   subroutine get_long(self, name, first, values)
      class(h5_table), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer(i8), intent(in) :: first
      integer(int64), intent(out), target, contiguous :: values(:)

      if (size(values) > 0) call self%transfer_range(name, kind_type('l'), first, size(values, kind=i8), &
         & c_loc(values), .false.)
   end subroutine get_long

   !> len(text) bytes of a byte column as text.
   subroutine get_bytes(self, name, first, text)
      class(h5_table), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer(i8), intent(in) :: first
      character(len=*), intent(out) :: text
      integer(int8), allocatable, target :: bytes(:)
      integer :: k

      text = ''
      if (len(text) == 0) return
      allocate (bytes(len(text)), source=0_int8)
      call self%transfer_range(name, kind_type('b'), first, size(bytes, kind=i8), c_loc(bytes), .false.)
      do k = 1, len(text)
         text(k:k) = transfer(bytes(k), 'a')
      end do
   end subroutine get_bytes

   !> The coordinates of a column's axis (h5_file's attach_scales).
   subroutine table_attach_scales(self, name, scales)
      class(h5_table), intent(inout) :: self
      character(len=*), intent(in) :: name, scales(:)
      type(error_printing) :: printing

      if (self%status /= 0) return
      call printing%silence()
      call attach_dimension_scales(self, self%id, name, scales)
      call printing%restore()
   end subroutine table_attach_scales

   !> A text attribute of the object at path object ('/' for the root).
   subroutine set_text_attribute(self, object, name, text)
      class(h5_table), intent(inout) :: self
      character(len=*), intent(in) :: object, name, text
      integer(hid_t) :: obj
      integer :: stat
      character(len=:), allocatable :: what
      logical :: exists
      type(error_printing) :: printing

      if (self%status /= 0) return
      call printing%silence()
      call h5oopen_f(self%id, object, obj, stat)
      call self%check(stat, 'opening '//object)
      if (stat == 0) then
         call h5aexists_f(obj, name, exists, stat)
         if (exists) call h5adelete_f(obj, name, stat)
         call new_text_attribute(obj, name, text, stat, what)
         call self%check(stat, what)
         call h5oclose_f(obj, stat)
      end if
      call printing%restore()
   end subroutine set_text_attribute

   !> The text attribute name of object ('' where there is none).
   function text_attribute(self, object, name) result(text)
      class(h5_table), intent(inout) :: self
      character(len=*), intent(in) :: object, name
      character(len=:), allocatable :: text
      integer(hid_t) :: attr, type
      integer(size_t) :: size
      integer :: stat
      logical :: exists
      type(error_printing) :: printing

      text = ''
      if (self%status /= 0) return
      call printing%silence()
      call h5aexists_by_name_f(self%id, object, name, exists, stat)
      if (stat == 0 .and. exists) then
         call h5aopen_by_name_f(self%id, object, name, attr, stat)
         call h5aget_type_f(attr, type, stat)
         call h5tget_size_f(type, size, stat)
         deallocate (text)
         allocate (character(len=size) :: text)
         call h5aread_f(attr, type, text, [1_hsize_t], stat)
         if (stat /= 0) text = ''
         call h5tclose_f(type, stat)
         call h5aclose_f(attr, stat)
      end if
      call printing%restore()
   end function text_attribute

   !> A 64-bit integer attribute of object (replaced if there is one).
   subroutine set_integer_attribute(self, object, name, value)
      class(h5_table), intent(inout) :: self
      character(len=*), intent(in) :: object, name
      integer(i8), intent(in), target :: value
      integer(hid_t) :: obj
      integer :: stat
      character(len=:), allocatable :: what
      logical :: exists
      type(error_printing) :: printing

      if (self%status /= 0) return
      call printing%silence()
      call h5oopen_f(self%id, object, obj, stat)
      call self%check(stat, 'opening '//object)
      if (stat == 0) then
         call h5aexists_f(obj, name, exists, stat)
         if (exists) call h5adelete_f(obj, name, stat)
         call new_scalar_attribute(obj, name, kind_type('l'), c_loc(value), stat, what)
         call self%check(stat, what)
         call h5oclose_f(obj, stat)
      end if
      call printing%restore()
   end subroutine set_integer_attribute

   !> The 64-bit integer attribute name of object (-1 where there is none).
   integer(i8) function integer_attribute(self, object, name) result(value)
      class(h5_table), intent(inout) :: self
      character(len=*), intent(in) :: object, name
      integer(i8), target :: read_value
      type(c_ptr) :: address
      integer(hid_t) :: attr
      integer :: stat
      logical :: exists
      type(error_printing) :: printing

      value = -1
      if (self%status /= 0) return
      call printing%silence()
      call h5aexists_by_name_f(self%id, object, name, exists, stat)
      if (stat == 0 .and. exists) then
         call h5aopen_by_name_f(self%id, object, name, attr, stat)
         address = c_loc(read_value)
         call h5aread_f(attr, kind_type('l'), address, stat)
         if (stat == 0) value = read_value
         call h5aclose_f(attr, stat)
      end if
      call printing%restore()
   end function integer_attribute

end module friction_output_h5_table
