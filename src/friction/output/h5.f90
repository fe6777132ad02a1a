!> HDF5 output behind one file type (create / group / write / attribute /
!> close), opened with the MPI-IO driver so every rank writes its own block
!> of scan lines collectively.  Every call is collective: all ranks call it
!> with the same names and the same small data.  A `units` attribute goes on
!> every dataset, a UDUNITS string (output/units.f90: a unit in τ as its
!> value at τ = 1, and as given in `units_tau`).
!>
!> HDF5's automatic error printing is the program's: every operation saves
!> the setting of the default error stack, switches printing off for its
!> own HDF5 calls (their failures come back through stat) and restores the
!> saved setting before it returns.  (HDF5 built without thread safety, as
!> the parallel builds are, keeps one such setting per process; the writer
!> is for one thread at a time, as friction_run_job says.)
module friction_output_h5
   use, intrinsic :: iso_fortran_env, only: int64
   use, intrinsic :: iso_c_binding, only: c_ptr, c_loc, c_funptr, c_int, c_int64_t, c_null_ptr, c_null_funptr, &
      & c_size_t, c_double, c_char, c_null_char
   use friction_parallel, only: communicator, broadcast, reduce_all, barrier, op_max, set_parallel_file_access, &
      & set_collective_transfer
   use hdf5
   use friction_kinds, only: wp, i8
   use friction_error, only: error_type, fatal_error, error_io
   use friction_files, only: truncate_file, free_bytes, min_free_bytes, full_text, size_limit_room
   use friction_strings, only: bytes_text
   use friction_output_units, only: plain_unit, mentions_tau
   implicit none
   private

   interface
      !> The metadata cache's current size (what a flush may still write).
      function h5fget_mdc_size(file, max_size, min_clean_size, cur_size, cur_num_entries) result(status) &
         & bind(c, name='H5Fget_mdc_size')
         import :: c_int64_t, c_size_t, c_int
         integer(c_int64_t), value :: file   !! an hid_t
         integer(c_size_t), intent(out) :: max_size, min_clean_size, cur_size
         integer(c_int), intent(out) :: cur_num_entries
         integer(c_int) :: status
      end function h5fget_mdc_size
   end interface

   interface
      !> HDF5's dimension scales (the high-level library): what netCDF and
      !> xarray read as a dataset's coordinates.
      function h5ds_set_scale(dataset, name) result(status) bind(c, name='H5DSset_scale')
         import :: c_int64_t, c_char, c_int
         integer(c_int64_t), value :: dataset
         character(kind=c_char), intent(in) :: name(*)
         integer(c_int) :: status
      end function h5ds_set_scale
      function h5ds_is_scale(dataset) result(status) bind(c, name='H5DSis_scale')
         import :: c_int64_t, c_int
         integer(c_int64_t), value :: dataset
         integer(c_int) :: status
      end function h5ds_is_scale
      function h5ds_attach_scale(dataset, scale, axis) result(status) bind(c, name='H5DSattach_scale')
         import :: c_int64_t, c_int
         integer(c_int64_t), value :: dataset, scale
         integer(c_int), value :: axis
         integer(c_int) :: status
      end function h5ds_attach_scale
   end interface

   public :: h5_file, h5_status, error_printing, room_to_close, new_text_attribute, new_scalar_attribute, open_hdf5, &
      & attach_dimension_scales

   !> H5E_DEFAULT of the C API: the default error stack (hid_t is int64_t
   !> since HDF5 1.10).
   integer(c_int64_t), parameter :: default_error_stack = 0

   !> The program's automatic error printing, while an operation runs.
   type :: error_printing
      private
      logical :: saved = .false.
      type(c_funptr) :: func = c_null_funptr
      type(c_ptr) :: data = c_null_ptr
   contains
      procedure :: silence => printing_silence
      procedure :: restore => printing_restore
   end type error_printing

   interface
      function h5e_get_auto2(stack, func, data) result(status) bind(c, name='H5Eget_auto2')
         import :: c_int64_t, c_funptr, c_ptr, c_int
         integer(c_int64_t), value :: stack
         type(c_funptr), intent(out) :: func
         type(c_ptr), intent(out) :: data
         integer(c_int) :: status
      end function h5e_get_auto2

      function h5e_set_auto2(stack, func, data) result(status) bind(c, name='H5Eset_auto2')
         import :: c_int64_t, c_funptr, c_ptr, c_int
         integer(c_int64_t), value :: stack
         type(c_funptr), value :: func
         type(c_ptr), value :: data
         integer(c_int) :: status
      end function h5e_set_auto2
   end interface

   !> The first HDF5 failure of a file, kept until checked (h5_file here,
   !> h5_table of the sweep's checkpoint): `check` records a call's status
   !> and what it was doing, unless an earlier failure is already kept.
   type :: h5_status
      integer :: status = 0
      character(len=:), allocatable :: failed_at
   contains
      procedure :: check
   end type h5_status

   !> How many objects a file keeps open (h5_file%kept).
   integer, parameter :: kept_objects = 16

   !> An object kept open, by the path it was opened with.
   type :: kept_object
      integer(hid_t) :: id = -1
      character(len=:), allocatable :: path
   end type kept_object

   type, extends(h5_status) :: h5_file
      private
      integer(hid_t) :: id = -1
      character(len=:), allocatable :: path
      integer :: rank = 0         !! this process in the communicator
      type(communicator) :: comm  !! the file's communicator
      logical :: parallel = .true. !! written through MPI-IO (.false.: serial, MPI not started; sec2 driver)
      !> The objects last written or opened, kept open for what comes next
      !> (a group's attributes one after another, a dataset's coordinates
      !> after its values): opening an object by its path cost more than
      !> writing an attribute on it.  Closed with the file.
      type(kept_object) :: kept(kept_objects)
      integer :: next_kept = 1   !! the entry the next object takes
   contains
      procedure :: create
      procedure :: create_group
      procedure :: write_vector
      procedure :: write_integer_vector
      procedure :: write_matrix
      procedure :: write_vector_block
      procedure :: write_line_block
      procedure :: write_vector_integer
      procedure :: write_text_vector
      procedure :: write_attribute_text
      procedure :: write_attribute_real
      procedure :: write_attribute_integer
      procedure :: write_attribute_units
      procedure :: attach_scales
      procedure :: has_attribute
      procedure :: close
      procedure, private :: agree
      procedure, private :: create_dataset
      procedure, private :: open_object
      procedure, private :: keep_object
      procedure, private :: close_objects
   end type h5_file

contains

   !> HDF5's Fortran interface, opened once for the process and left open
   !> (HDF5 closes it at exit).  Each h5open_f copies HDF5's predefined types
   !> and h5close_f does not release all of the copies: opened and closed
   !> around every file, it kept 2.6 kB a job in a host that ran jobs in a
   !> loop (and the checkpoint tables, opened without a close, more).  Jobs
   !> run one at a time (capi/job_lock.c), so the flag needs no lock.
   subroutine open_hdf5(stat)
      integer, intent(out) :: stat
      logical, save :: opened = .false.

      stat = 0
      if (opened) return
      call h5open_f(stat)
      opened = stat == 0
   end subroutine open_hdf5

   !> Create (truncate) a file for parallel writing on communicator comm;
   !> comm not attached to MPI: a serial run, written by this process
   !> alone with HDF5's default (sec2) driver (the mpio driver needs MPI_Init).
   subroutine create(self, path, comm, error)
      class(h5_file), intent(inout) :: self
      character(len=*), intent(in) :: path
      type(communicator), intent(in) :: comm
      type(error_type), allocatable, intent(out) :: error
      integer(hid_t) :: fapl
      integer :: stat
      type(error_printing) :: printing
      real(c_double) :: free

      self%path = path
      self%status = 0
      self%comm = comm
      self%parallel = comm%parallel()
      self%rank = comm%rank()
      ! Not on a (nearly) full disk: room to spare is what lets a failed
      ! file be closed (give_back_space).
      free = -1.0_c_double
      if (self%rank == 0) free = free_bytes(path)
      if (self%parallel) call broadcast(comm, free, 0)
      if (free >= 0.0_c_double .and. free < min_free_bytes) then
         call fatal_error(error, path//': '//full_text(path, free)//'; writing ' &
            & //'the output needs at least '//bytes_text(real(min_free_bytes, wp))//' to spare)', error_io)
         return
      end if
      ! The library never prints: failures come back through stat.
      call printing%silence()
      call open_hdf5(stat)
      call self%check(stat, 'initialising HDF5')
      call h5pcreate_f(H5P_FILE_ACCESS_F, fapl, stat)
      call self%check(stat, 'creating the file access list')
      if (self%parallel) then
         call set_parallel_file_access(fapl, comm, stat)
         call self%check(stat, 'selecting the MPI-IO driver')
      end if
      call h5fcreate_f(path, H5F_ACC_TRUNC_F, self%id, stat, access_prp=fapl)
      call self%check(stat, 'creating the file')
      call h5pclose_f(fapl, stat)
      call printing%restore()
      if (self%status /= 0) call fatal_error(error, path//': HDF5 failed '//self%failed_at, error_io)
   end subroutine create

   subroutine create_group(self, name)
      class(h5_file), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer(hid_t) :: group
      integer :: stat
      type(error_printing) :: printing

      if (self%status /= 0) return
      call printing%silence()
      call h5gcreate_f(self%id, name, group, stat)
      call self%check(stat, 'creating group '//name)
      if (stat == 0) call h5gclose_f(group, stat)
      call printing%restore()
   end subroutine create_group

   !> A 1-D dataset that every rank holds whole; rank 0 writes it.
   subroutine write_vector(self, name, values, units)
      class(h5_file), intent(inout) :: self
      character(len=*), intent(in) :: name, units
      real(wp), intent(in), target, contiguous :: values(:)
      integer :: held

      held = merge(size(values), 0, self%rank == 0)
      call write_block(self, name, H5T_NATIVE_DOUBLE, c_loc(values), [1, held], size(values), 0, 1, units, .true.)
   end subroutine write_vector

   !> A 1-D integer dataset that every rank holds whole; rank 0 writes it.
   subroutine write_integer_vector(self, name, values)
      class(h5_file), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer, intent(in), target, contiguous :: values(:)
      integer :: held

      held = merge(size(values), 0, self%rank == 0)
      call write_block(self, name, H5T_NATIVE_INTEGER, c_loc(values), [1, held], size(values), 0, 1, '', .true.)
   end subroutine write_integer_vector

   !> A 2-D dataset (size(values, 2), size(values, 1)) in h5py that every
   !> rank holds whole; rank 0 writes it.
   subroutine write_matrix(self, name, values, units)
      class(h5_file), intent(inout) :: self
      character(len=*), intent(in) :: name, units
      real(wp), intent(in), target, contiguous :: values(:, :)
      integer :: held

      held = merge(size(values, 2), 0, self%rank == 0)
      call write_block(self, name, H5T_NATIVE_DOUBLE, c_loc(values), [size(values, 1), held], &
         & size(values, 2), 0, 1, units, .false.)
   end subroutine write_matrix

   !> A 1-D dataset of n_total values to which this rank contributes
   !> values(k) at index first + (k - 1) * stride (0-based).
   subroutine write_vector_block(self, name, values, n_total, first, stride, units)
      class(h5_file), intent(inout) :: self
      character(len=*), intent(in) :: name, units
      real(wp), intent(in), target, contiguous :: values(:)
      integer, intent(in) :: n_total, first, stride

      call write_block(self, name, H5T_NATIVE_DOUBLE, c_loc(values), [1, size(values)], n_total, first, &
         & stride, units, .true.)
   end subroutine write_vector_block

   !> A dataset of shape (nx, n_total) in Fortran, (n_total, nx) in h5py, to
   !> which this rank contributes column k of block at first + (k - 1) * stride.
   subroutine write_line_block(self, name, block, n_total, first, stride, units)
      class(h5_file), intent(inout) :: self
      character(len=*), intent(in) :: name, units
      real(wp), intent(in), target, contiguous :: block(:, :)
      integer, intent(in) :: n_total, first, stride

      call write_block(self, name, H5T_NATIVE_DOUBLE, c_loc(block), shape(block), n_total, first, stride, &
         & units, .false.)
   end subroutine write_line_block

   !> Collective write of this rank's `held` columns (Fortran shape held(1) x
   !> held(2), at `buffer`) of a (held(1), n_total) dataset, or of a 1-D
   !> dataset of n_total values when one_d: one regular (strided) hyperslab
   !> per rank.  A units attribute is added unless units is blank.
   subroutine write_block(self, name, type, buffer, held, n_total, first, stride, units, one_d)
      class(h5_file), intent(inout) :: self
      character(len=*), intent(in) :: name, units
      integer(hid_t), intent(in) :: type
      type(c_ptr), intent(in) :: buffer
      integer, intent(in) :: held(2), n_total, first, stride
      logical, intent(in) :: one_d
      type(error_printing) :: printing

      if (self%status /= 0) return
      call printing%silence()
      call write_block_silently(self, name, type, buffer, held, n_total, first, stride, units, one_d)
      call printing%restore()
   end subroutine write_block

   subroutine write_block_silently(self, name, type, buffer, held, n_total, first, stride, units, one_d)
      class(h5_file), intent(inout) :: self
      character(len=*), intent(in) :: name, units
      integer(hid_t), intent(in) :: type
      type(c_ptr), intent(in) :: buffer
      integer, intent(in) :: held(2), n_total, first, stride
      logical, intent(in) :: one_d
      integer(hid_t) :: filespace, memspace, dset, xfer
      integer(hsize_t) :: dims(2), count(2), offset(2), step(2)
      integer :: stat, rank

      if (self%status /= 0) return
      if (one_d) then
         rank = 1
         dims = [int(n_total, hsize_t), 0_hsize_t]
         count = [int(held(2), hsize_t), 0_hsize_t]
         offset = [int(first, hsize_t), 0_hsize_t]
         step = [int(stride, hsize_t), 1_hsize_t]
      else
         rank = 2
         dims = [int(held(1), hsize_t), int(n_total, hsize_t)]
         count = [int(held(1), hsize_t), int(held(2), hsize_t)]
         offset = [0_hsize_t, int(first, hsize_t)]
         step = [1_hsize_t, int(stride, hsize_t)]
      end if
      call h5screate_simple_f(rank, dims(1:rank), filespace, stat)
      if (.not. self%create_dataset(name, type, filespace, dset)) return
      if (n_total == 0) then   ! an empty dataset: nothing to write (and no buffer to point at)
         if (len_trim(units) > 0) call dataset_units(self, dset, units)
         call keep_or_close(self, name, dset)
         call h5sclose_f(filespace, stat)
         return
      end if
      call h5screate_simple_f(rank, count(1:rank), memspace, stat)
      if (int(held(1), i8) * held(2) > 0) then
         call h5sselect_hyperslab_f(filespace, H5S_SELECT_SET_F, offset(1:rank), count(1:rank), stat, &
            & stride=step(1:rank))
      else
         ! A rank with nothing to write still takes part in the collective write.
         call h5sselect_none_f(filespace, stat)
         call h5sselect_none_f(memspace, stat)
      end if
      call h5pcreate_f(H5P_DATASET_XFER_F, xfer, stat)
      if (self%parallel) call set_collective_transfer(xfer, stat)
      call h5dwrite_f(dset, type, buffer, stat, mem_space_id=memspace, file_space_id=filespace, &
         & xfer_prp=xfer)
      call self%agree(stat)
      call self%check(stat, 'writing dataset '//name)
      call h5pclose_f(xfer, stat)
      call h5sclose_f(memspace, stat)
      call h5sclose_f(filespace, stat)
      if (len_trim(units) > 0) call dataset_units(self, dset, units)
      call keep_or_close(self, name, dset)
   end subroutine write_block_silently

   !> A dataset just written kept open (its coordinates or attributes come
   !> next), or closed at once after a failure: an object left open on a
   !> full disk could not be closed later, and HDF5's clean-up at exit
   !> would crash on it.
   subroutine keep_or_close(self, name, dset)
      class(h5_file), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer(hid_t), intent(in) :: dset
      integer :: stat

      if (self%status == 0) then
         call self%keep_object(name, dset)
      else
         call h5dclose_f(dset, stat)
      end if
   end subroutine keep_or_close

   !> The coordinates of a dataset's axes: scales(k) (a dataset's path, or
   !> blank for none) becomes a dimension scale named by its last path
   !> element and is attached to axis k of dataset name, the axes in the
   !> file's order (slowest first, as h5py and xarray show them).
   subroutine attach_scales(self, name, scales)
      class(h5_file), intent(inout) :: self
      character(len=*), intent(in) :: name, scales(:)
      type(error_printing) :: printing
      integer(hid_t) :: dset, scale
      integer :: stat, k
      character(len=:), allocatable :: path

      if (self%status /= 0) return
      call printing%silence()
      call self%open_object(name, dset, stat)
      do k = 1, size(scales)
         path = trim(scales(k))
         if (self%status /= 0 .or. len(path) == 0) cycle
         call self%open_object(path, scale, stat, spare=dset)
         if (stat /= 0) cycle
         call attach_one_scale(self, dset, scale, name, path, k)
      end do
      call printing%restore()
   end subroutine attach_scales

   !> Make the open dataset scale (at path) a dimension scale, unless it is
   !> one, and attach it to axis k of the open dataset dset (at name).
   subroutine attach_one_scale(status, dset, scale, name, path, k)
      class(h5_status), intent(inout) :: status
      integer(hid_t), intent(in) :: dset, scale
      character(len=*), intent(in) :: name, path
      integer, intent(in) :: k

      if (h5ds_is_scale(scale) <= 0) call status%check(int(h5ds_set_scale(scale, &
         & path(index(path, '/', back=.true.) + 1:)//c_null_char)), 'making '//path//' a dimension scale')
      call status%check(int(h5ds_attach_scale(dset, scale, int(k - 1, c_int))), &
         & 'attaching coordinate '//path//' to '//name)
   end subroutine attach_one_scale

   !> attach_scales on the file `file` (an hid_t), the failure kept in status.
   subroutine attach_dimension_scales(status, file, name, scales)
      class(h5_status), intent(inout) :: status
      integer(hid_t), intent(in) :: file
      character(len=*), intent(in) :: name, scales(:)
      integer(hid_t) :: dset, scale
      integer :: stat, k
      character(len=:), allocatable :: path

      call h5dopen_f(file, name, dset, stat)
      call status%check(stat, 'opening dataset '//name//' for its coordinates')
      if (stat /= 0) return
      do k = 1, size(scales)
         path = trim(scales(k))
         if (status%status /= 0 .or. len(path) == 0) cycle
         call h5dopen_f(file, path, scale, stat)
         call status%check(stat, 'opening coordinate '//path)
         if (stat /= 0) cycle
         call attach_one_scale(status, dset, scale, name, path, k)
         call h5dclose_f(scale, stat)
      end do
      call h5dclose_f(dset, stat)
   end subroutine attach_dimension_scales

   !> A 1-D integer dataset that every rank holds whole; rank 0 writes it
   !> (flags, codes).  Collective like the others.
   subroutine write_vector_integer(self, name, values, units)
      class(h5_file), intent(inout) :: self
      character(len=*), intent(in) :: name, units
      integer, intent(in) :: values(:)
      type(error_printing) :: printing

      if (self%status /= 0) return
      call printing%silence()
      call write_vector_integer_silently(self, name, values, units)
      call printing%restore()
   end subroutine write_vector_integer

   subroutine write_vector_integer_silently(self, name, values, units)
      class(h5_file), intent(inout) :: self
      character(len=*), intent(in) :: name, units
      integer, intent(in) :: values(:)
      integer(hid_t) :: filespace, memspace, dset, xfer
      integer(hsize_t) :: dims(1)
      integer :: stat

      dims = [int(size(values), hsize_t)]
      call h5screate_simple_f(1, dims, filespace, stat)
      if (.not. self%create_dataset(name, H5T_NATIVE_INTEGER, filespace, dset)) return
      if (size(values) == 0) then   ! an empty dataset: nothing to write
         call dataset_units(self, dset, units)
         call keep_or_close(self, name, dset)
         call h5sclose_f(filespace, stat)
         return
      end if
      call h5screate_simple_f(1, dims, memspace, stat)
      if (self%rank /= 0 .or. size(values) == 0) then
         call h5sselect_none_f(filespace, stat)
         call h5sselect_none_f(memspace, stat)
      end if
      call h5pcreate_f(H5P_DATASET_XFER_F, xfer, stat)
      if (self%parallel) call set_collective_transfer(xfer, stat)
      call h5dwrite_f(dset, H5T_NATIVE_INTEGER, values, dims, stat, &
         & mem_space_id=memspace, file_space_id=filespace, xfer_prp=xfer)
      call self%agree(stat)
      call self%check(stat, 'writing dataset '//name)
      call h5pclose_f(xfer, stat)
      call h5sclose_f(memspace, stat)
      call h5sclose_f(filespace, stat)
      call dataset_units(self, dset, units)
      call keep_or_close(self, name, dset)
   end subroutine write_vector_integer_silently

   !> A 1-D dataset of fixed-length UTF-8 texts (rank 0's are written; the
   !> call is collective).  Texts of any number and length: an attribute
   !> would stop at HDF5's 64 kB limit on attributes.
   subroutine write_text_vector(self, name, texts)
      class(h5_file), intent(inout) :: self
      character(len=*), intent(in) :: name
      character(len=*), intent(in) :: texts(:)
      integer(hid_t) :: filespace, memspace, dset, xfer, type
      integer(hsize_t) :: dims(1)
      integer :: stat
      type(error_printing) :: printing

      if (self%status /= 0) return
      call printing%silence()
      dims = [int(size(texts), hsize_t)]
      call h5tcopy_f(H5T_FORTRAN_S1, type, stat)
      call h5tset_size_f(type, int(max(1, len(texts)), size_t), stat)
      call h5tset_cset_f(type, H5T_CSET_UTF8_F, stat)
      call h5screate_simple_f(1, dims, filespace, stat)
      if (self%create_dataset(name, type, filespace, dset)) then
         if (size(texts) > 0) then
            call h5screate_simple_f(1, dims, memspace, stat)
            if (self%rank /= 0) then
               call h5sselect_none_f(filespace, stat)
               call h5sselect_none_f(memspace, stat)
            end if
            call h5pcreate_f(H5P_DATASET_XFER_F, xfer, stat)
            if (self%parallel) call set_collective_transfer(xfer, stat)
            call h5dwrite_f(dset, type, texts, dims, stat, mem_space_id=memspace, file_space_id=filespace, &
               & xfer_prp=xfer)
            call self%agree(stat)
            call self%check(stat, 'writing dataset '//name)
            call h5pclose_f(xfer, stat)
            call h5sclose_f(memspace, stat)
         end if
         call h5sclose_f(filespace, stat)
         call h5dclose_f(dset, stat)
      end if
      call h5tclose_f(type, stat)
      call printing%restore()
   end subroutine write_text_vector

   !> A text attribute on the object at path object ('/' for the root).
   subroutine write_attribute_text(self, object, name, text)
      class(h5_file), intent(inout) :: self
      character(len=*), intent(in) :: object, name, text
      integer(hid_t) :: obj
      integer :: stat
      type(error_printing) :: printing

      if (self%status /= 0) return
      call printing%silence()
      call self%open_object(object, obj, stat)
      if (stat == 0) call attribute_text(self, obj, name, text)
      call printing%restore()
   end subroutine write_attribute_text

   !> The object at path object, kept open or opened and kept (stat 0), the
   !> failure kept in status; `spare`, an object the caller still holds,
   !> is not closed to make room.  Every rank opens the same objects in the
   !> same order, so all keep the same.
   subroutine open_object(self, object, obj, stat, spare)
      class(h5_file), intent(inout) :: self
      character(len=*), intent(in) :: object
      integer(hid_t), intent(out) :: obj
      integer, intent(out) :: stat
      integer(hid_t), intent(in), optional :: spare
      integer :: k

      stat = 0
      do k = 1, kept_objects
         if (self%kept(k)%id < 0) cycle
         if (self%kept(k)%path == object) then
            obj = self%kept(k)%id
            return
         end if
      end do
      call h5oopen_f(self%id, object, obj, stat)
      call self%check(stat, 'opening '//object)
      if (stat == 0) call self%keep_object(object, obj, spare)
   end subroutine open_object

   !> Keep the open object obj (at path object) until the file's close,
   !> closing the oldest kept one (other than `spare`) when all are taken.
   subroutine keep_object(self, object, obj, spare)
      class(h5_file), intent(inout) :: self
      character(len=*), intent(in) :: object
      integer(hid_t), intent(in) :: obj
      integer(hid_t), intent(in), optional :: spare
      integer :: stat

      if (present(spare)) then
         if (self%kept(self%next_kept)%id == spare) self%next_kept = mod(self%next_kept, kept_objects) + 1
      end if
      associate (entry => self%kept(self%next_kept))
         if (entry%id >= 0) call h5oclose_f(entry%id, stat)
         entry%id = obj
         entry%path = object
      end associate
      self%next_kept = mod(self%next_kept, kept_objects) + 1
   end subroutine keep_object

   subroutine close_objects(self)
      class(h5_file), intent(inout) :: self
      integer :: k, stat

      do k = 1, kept_objects
         if (self%kept(k)%id >= 0) call h5oclose_f(self%kept(k)%id, stat)
         self%kept(k)%id = -1
      end do
      self%next_kept = 1
   end subroutine close_objects

   !> A dataset's `units`, a UDUNITS string; a unit in τ also as given, in
   !> `units_tau`.
   subroutine dataset_units(self, dset, units)
      class(h5_file), intent(inout) :: self
      integer(hid_t), intent(in) :: dset
      character(len=*), intent(in) :: units

      call attribute_text(self, dset, 'units', plain_unit(units))
      if (mentions_tau(units)) call attribute_text(self, dset, 'units_tau', trim(units))
   end subroutine dataset_units

   subroutine attribute_text(self, obj, name, text)
      class(h5_file), intent(inout) :: self
      integer(hid_t), intent(in) :: obj
      character(len=*), intent(in) :: name, text
      integer :: stat
      character(len=:), allocatable :: what

      if (self%status /= 0) return
      call new_text_attribute(obj, name, text, stat, what)
      call self%check(stat, what)
   end subroutine attribute_text

   !> Create the scalar text attribute name (UTF-8, its length that of text)
   !> on the open object obj; stat is HDF5's, `what` the step that failed.
   !> (Shared by the files this module and h5_table write.)
   subroutine new_text_attribute(obj, name, text, stat, what)
      integer(hid_t), intent(in) :: obj
      character(len=*), intent(in) :: name, text
      integer, intent(out) :: stat
      character(len=:), allocatable, intent(out) :: what
      integer(hid_t) :: space, type, attr
      integer :: ignored

      what = ''
      call h5screate_f(H5S_SCALAR_F, space, ignored)
      call h5tcopy_f(H5T_FORTRAN_S1, type, ignored)
      call h5tset_size_f(type, int(max(1, len(text)), size_t), ignored)
      call h5tset_cset_f(type, H5T_CSET_UTF8_F, ignored)
      call h5acreate_f(obj, name, type, space, attr, stat)
      if (stat /= 0) then
         what = 'creating attribute '//name
      else
         call h5awrite_f(attr, type, text, [1_hsize_t], stat)
         if (stat /= 0) what = 'writing attribute '//name
         call h5aclose_f(attr, ignored)
      end if
      call h5tclose_f(type, ignored)
      call h5sclose_f(space, ignored)
   end subroutine new_text_attribute

   !> Create the scalar attribute name of HDF5 type `type` on the open object
   !> obj and write it from the address value; stat and `what` as above.
   subroutine new_scalar_attribute(obj, name, type, value, stat, what)
      integer(hid_t), intent(in) :: obj, type
      character(len=*), intent(in) :: name
      type(c_ptr), intent(in) :: value
      integer, intent(out) :: stat
      character(len=:), allocatable, intent(out) :: what
      integer(hid_t) :: space, attr
      integer :: ignored

      what = ''
      call h5screate_f(H5S_SCALAR_F, space, ignored)
      call h5acreate_f(obj, name, type, space, attr, stat)
      if (stat /= 0) then
         what = 'creating attribute '//name
      else
         call h5awrite_f(attr, type, value, stat)
         if (stat /= 0) what = 'writing attribute '//name
         call h5aclose_f(attr, ignored)
      end if
      call h5sclose_f(space, ignored)
   end subroutine new_scalar_attribute

   !> A real attribute; with `units`, its unit goes beside it as the text
   !> attribute NAME_units (attributes cannot carry attributes).
   subroutine write_attribute_real(self, object, name, value, units)
      class(h5_file), intent(inout) :: self
      character(len=*), intent(in) :: object, name
      real(wp), intent(in), target :: value
      character(len=*), intent(in), optional :: units

      call scalar_attribute(self, object, name, H5T_NATIVE_DOUBLE, c_loc(value))
      if (present(units)) call self%write_attribute_units(object, name, units)
   end subroutine write_attribute_real

   subroutine write_attribute_integer(self, object, name, value, units)
      class(h5_file), intent(inout) :: self
      character(len=*), intent(in) :: object, name
      integer(i8), intent(in), target :: value
      character(len=*), intent(in), optional :: units

      call scalar_attribute(self, object, name, h5kind_to_type(int64, H5_INTEGER_KIND), c_loc(value))
      if (present(units)) call self%write_attribute_units(object, name, units)
   end subroutine write_attribute_integer

   !> The unit of attribute name as the text attribute NAME_units, a UDUNITS
   !> string; a unit in τ also as given, in NAME_units_tau.
   subroutine write_attribute_units(self, object, name, units)
      class(h5_file), intent(inout) :: self
      character(len=*), intent(in) :: object, name, units

      call self%write_attribute_text(object, name//'_units', plain_unit(units))
      if (mentions_tau(units)) call self%write_attribute_text(object, name//'_units_tau', trim(units))
   end subroutine write_attribute_units

   !> Whether the object at path object has an attribute of that name.
   logical function has_attribute(self, object, name)
      class(h5_file), intent(inout) :: self
      character(len=*), intent(in) :: object, name
      integer :: stat
      integer(hid_t) :: obj
      type(error_printing) :: printing

      has_attribute = .false.
      if (self%status /= 0) return
      call printing%silence()
      call self%open_object(object, obj, stat)
      if (stat == 0) then
         call h5aexists_f(obj, name, has_attribute, stat)
         call self%check(stat, 'looking for attribute '//name)
      end if
      call printing%restore()
   end function has_attribute

   !> A scalar numeric attribute of HDF5 type `type` read from `value`.
   subroutine scalar_attribute(self, object, name, type, value)
      class(h5_file), intent(inout) :: self
      character(len=*), intent(in) :: object, name
      integer(hid_t), intent(in) :: type
      type(c_ptr), intent(in) :: value
      integer(hid_t) :: obj
      integer :: stat
      character(len=:), allocatable :: what
      type(error_printing) :: printing

      if (self%status /= 0) return
      call printing%silence()
      call self%open_object(object, obj, stat)
      if (stat == 0) then
         call new_scalar_attribute(obj, name, type, value, stat, what)
         call self%check(stat, what)
      end if
      call printing%restore()
   end subroutine scalar_attribute

   !> Close the file; report the first failure since create, if any.
   subroutine close(self, error)
      class(h5_file), intent(inout) :: self
      type(error_type), allocatable, intent(out) :: error
      integer :: stat
      type(error_printing) :: printing

      call printing%silence()
      if (self%id >= 0) then
         ! (The kept objects after the file is cut, if it is: with a failed
         ! write behind them they could not be flushed to a full disk.)
         call give_back_space(self)
         call self%close_objects()
         call h5fclose_f(self%id, stat)
         call self%check(stat, 'closing the file')
         self%id = -1
      end if
      call printing%restore()
      if (self%status /= 0) call fatal_error(error, self%path//': HDF5 failed '//self%failed_at, error_io)
   end subroutine close

   !> Save the program's automatic error printing and switch it off.  If
   !> HDF5 cannot tell the setting (a program that set it through the
   !> deprecated H5Eset_auto1), it is left alone: it could not be restored.
   subroutine printing_silence(self)
      class(error_printing), intent(inout) :: self
      integer(c_int) :: status

      self%saved = h5e_get_auto2(default_error_stack, self%func, self%data) >= 0
      if (self%saved) status = h5e_set_auto2(default_error_stack, c_null_funptr, c_null_ptr)
   end subroutine printing_silence

   !> Put the saved setting back.
   subroutine printing_restore(self)
      class(error_printing), intent(inout) :: self
      integer(c_int) :: status

      if (self%saved) status = h5e_set_auto2(default_error_stack, self%func, self%data)
      self%saved = .false.
   end subroutine printing_restore

   !> Before closing (collective): closing writes the metadata HDF5 holds in
   !> its cache, and an HDF5 file (1.10) whose close fails for a full disk
   !> stays half open: its handle cannot be closed again and HDF5's clean-up
   !> at MPI_Finalize crashes in H5F__close_cb.  So a close must not fail:
   !> rank 0 first checks that the disk has room for the cached metadata
   !> (with 1 MB to spare), and if it has not, or any rank failed to write,
   !> the file is cut to no bytes, which gives back the space its data took,
   !> so that closing succeeds and leaves no handle open.  (The failed file
   !> is removed by its writer anyway.)  A flush is not tried instead: a
   !> failed flush leaves the cache unable to close.
   subroutine give_back_space(self)
      class(h5_file), intent(inout) :: self
      character(len=:), allocatable :: problem
      integer :: failed

      if (self%rank == 0 .and. self%status == 0) then
         problem = room_to_close(self%id, self%path)
         if (len(problem) > 0) call self%check(1, problem)
      end if
      failed = merge(1, 0, self%status /= 0)
      if (self%parallel) call reduce_all(self%comm, failed, op_max)
      if (failed == 0) return
      call self%check(1, 'writing the file on another rank')
      call barrier(self%comm)
      if (self%rank == 0) call truncate_file(self%path)
      call barrier(self%comm)
   end subroutine give_back_space

   !> Whether the disk has room for the metadata HDF5 holds in its cache for
   !> file `id` at `path` (with 1 MB to spare): '' if it has, else the
   !> failure to report.  A flush or close that fails for want of room
   !> leaves the file half open (see give_back_space), so it is not tried.
   function room_to_close(id, path) result(problem)
      integer(hid_t), intent(in) :: id
      character(len=*), intent(in) :: path
      character(len=:), allocatable :: problem
      integer(c_size_t) :: max_size, min_clean, cached
      integer(c_int) :: entries
      real(c_double) :: free

      problem = ''
      if (h5fget_mdc_size(id, max_size, min_clean, cached, entries) < 0) return
      free = free_bytes(path)
      if (free >= 0.0_c_double .and. free < 1.25_c_double * real(cached, c_double) + 8192.0_c_double) &
         & problem = 'writing the file: '//full_text(path, free)//', closing needs ' &
         & //'up to '//bytes_text(1.25_wp * real(cached, wp) + 8192.0_wp)//')'
   end function room_to_close

   !> Create a dataset on every rank, or none: on a failure anywhere the
   !> dataset (where created) and `filespace` are closed, and false returned.
   logical function create_dataset(self, name, type, filespace, dset) result(ok)
      class(h5_file), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer(hid_t), intent(in) :: type, filespace
      integer(hid_t), intent(out) :: dset
      integer :: stat
      integer(hsize_t) :: points
      integer(size_t) :: bytes
      real(c_double) :: room
      logical :: created

      ! Under a file-size limit (ulimit -f) a write past it fails with EFBIG
      ! at any offset, so a file that failed there cannot be closed (not even
      ! cut to no bytes, as on a full disk) and HDF5's clean-up at exit
      ! crashed: the dataset must fit, with min_free_bytes for the metadata.
      room = -1.0_c_double
      if (self%rank == 0) room = size_limit_room(self%path)
      if (self%parallel) call broadcast(self%comm, room, 0)
      if (room >= 0.0_c_double) then
         call h5sget_simple_extent_npoints_f(filespace, points, stat)
         call h5tget_size_f(type, bytes, stat)
         if (room < real(points, c_double) * real(bytes, c_double) + min_free_bytes) then
            call self%check(1, 'writing dataset '//name//': '//full_text(self%path, room)//')')
            call h5sclose_f(filespace, stat)
            ok = .false.
            return
         end if
      end if
      call h5dcreate_f(self%id, name, type, filespace, dset, stat)
      created = stat == 0
      call self%agree(stat)
      call self%check(stat, 'creating dataset '//name)
      ok = stat == 0
      if (ok) return
      if (created) call h5dclose_f(dset, stat)
      call h5sclose_f(filespace, stat)
   end function create_dataset

   !> A collective write's status, the same on every rank: a write can fail
   !> on one rank alone (a full disk), and a rank that then skipped the next
   !> collective call would leave the others waiting in it.
   subroutine agree(self, stat)
      class(h5_file), intent(inout) :: self
      integer, intent(inout) :: stat
      integer :: failed

      failed = merge(1, 0, stat /= 0)
      if (self%parallel) call reduce_all(self%comm, failed, op_max)
      if (failed /= 0 .and. stat == 0) stat = -1
   end subroutine agree

   subroutine check(self, stat, what)
      class(h5_status), intent(inout) :: self
      integer, intent(in) :: stat
      character(len=*), intent(in) :: what

      if (stat /= 0 .and. self%status == 0) then
         self%status = stat
         self%failed_at = what
      end if
   end subroutine check

end module friction_output_h5
