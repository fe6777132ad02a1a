!> The library leaves the process as it found it, seen from Fortran: GSL's
!> error handler and HDF5's automatic error printing are the program's
!> before and after every call, errors GSL reports inside the library come
!> back as error_type (naming what failed) instead of reaching the
!> program's handler, and the step types are one table, the one
!> include/friction.h documents (FRICTION_HEADER names the header).
module library_state_helpers
   use, intrinsic :: iso_c_binding, only: c_int, c_int64_t, c_ptr, c_funptr, c_size_t, c_char, &
      & c_f_pointer, c_funloc, c_associated
   implicit none
   private

   public :: gsl_calls, counting_handler, handler_is, gsl_set_error_handler, own_gsl_error
   public :: counting_printer, h5e_get_auto2, h5e_set_auto2, h5f_open

   !> Calls of counting_handler.
   integer, save :: gsl_calls = 0

   interface
      function gsl_set_error_handler(handler) result(previous) bind(c, name='gsl_set_error_handler')
         import :: c_funptr
         type(c_funptr), value :: handler
         type(c_funptr) :: previous
      end function gsl_set_error_handler

      function gsl_vector_calloc(n) result(vector) bind(c, name='gsl_vector_calloc')
         import :: c_size_t, c_ptr
         integer(c_size_t), value :: n
         type(c_ptr) :: vector
      end function gsl_vector_calloc

      function gsl_vector_memcpy(dest, src) result(status) bind(c, name='gsl_vector_memcpy')
         import :: c_ptr, c_int
         type(c_ptr), value :: dest, src
         integer(c_int) :: status
      end function gsl_vector_memcpy

      subroutine gsl_vector_free(vector) bind(c, name='gsl_vector_free')
         import :: c_ptr
         type(c_ptr), value :: vector
      end subroutine gsl_vector_free

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

      function h5f_open(name, flags, fapl) result(file) bind(c, name='H5Fopen')
         import :: c_char, c_int, c_int64_t
         character(kind=c_char), intent(in) :: name(*)
         integer(c_int), value :: flags
         integer(c_int64_t), value :: fapl
         integer(c_int64_t) :: file
      end function h5f_open
   end interface

contains

   !> A GSL error handler that only counts.
   subroutine counting_handler(reason, file, line, gsl_errno) bind(c)
      type(c_ptr), value :: reason, file
      integer(c_int), value :: line, gsl_errno

      gsl_calls = gsl_calls + 1
   end subroutine counting_handler

   !> An HDF5 automatic error function that counts into its client data.
   function counting_printer(stack, data) result(status) bind(c)
      integer(c_int64_t), value :: stack
      type(c_ptr), value :: data
      integer(c_int) :: status
      integer(c_int), pointer :: calls

      call c_f_pointer(data, calls)
      calls = calls + 1
      status = 0
   end function counting_printer

   !> A GSL error of the program's own: copying vectors of different
   !> lengths (GSL_EBADLEN, 19).
   integer(c_int) function own_gsl_error() result(status)
      type(c_ptr) :: a, b

      a = gsl_vector_calloc(1_c_size_t)
      b = gsl_vector_calloc(2_c_size_t)
      status = gsl_vector_memcpy(a, b)
      call gsl_vector_free(a)
      call gsl_vector_free(b)
   end function own_gsl_error

   !> Whether GSL's handler is `handler`; leaves `handler` installed.
   logical function handler_is(handler)
      type(c_funptr), intent(in) :: handler

      handler_is = c_associated(gsl_set_error_handler(handler), handler)
   end function handler_is

end module library_state_helpers

program test_library_state
   use, intrinsic :: iso_c_binding, only: c_int, c_int64_t, c_ptr, c_funptr, c_size_t, c_null_char, &
      & c_funloc, c_loc, c_associated, c_null_funptr, c_null_ptr
   use mpi_f08, only: MPI_Init, MPI_Initialized, MPI_Finalize, MPI_COMM_SELF
   use friction_kinds, only: wp
   use friction_strings, only: itoa
   use friction_error, only: error_type, error_input, error_numerical, error_io
   use friction_ode_solver, only: ode_solver, solver_settings, step_type_names, step_type_index, &
      & is_implicit_step_type
   use friction_output_h5, only: h5_file
   use test_systems, only: oscillator
   use testing, only: test_suite, check
   use library_state_helpers
   implicit none

   type(test_suite) :: suite
   logical :: mpi_ready
   integer(c_int64_t), parameter :: default_stack = 0   !! H5E_DEFAULT
   character(len=*), parameter :: h5_path = 'library_state_test.h5'

   call MPI_Initialized(mpi_ready)
   if (.not. mpi_ready) call MPI_Init()
   suite%name = 'library_state'
   call suite%add('step_types_as_the_header_documents', step_types_as_the_header_documents)
   call suite%add('gsl_reports_stay_inside', gsl_reports_stay_inside)
   call suite%add('hdf5_printing_kept', hdf5_printing_kept)
   call suite%run_all()
   call MPI_Finalize()

contains

   !> The names of include/friction.h ("stepper    GSL step type: ... , or
   !> "auto"") are the table's, in its order; index and Jacobian flag agree.
   subroutine step_types_as_the_header_documents(failure)
      character(len=:), allocatable, intent(out) :: failure
      character(len=:), allocatable :: names(:), text, documented(:)
      character(len=1024) :: path, line
      character(len=*), parameter :: start = 'GSL step type:', finish = ', or "auto"'
      integer :: unit, stat, at, i, n
      logical :: reading

      call get_environment_variable('FRICTION_HEADER', path, status=stat)
      call check(failure, stat == 0, 'FRICTION_HEADER is not set')
      if (allocated(failure)) return
      open (newunit=unit, file=trim(path), status='old', action='read', iostat=stat)
      call check(failure, stat == 0, 'cannot open '//trim(path))
      if (allocated(failure)) return
      text = ''
      reading = .false.
      do
         read (unit, '(a)', iostat=stat) line
         if (stat /= 0) exit
         if (.not. reading) then
            at = index(line, start)
            if (at == 0) cycle
            reading = .true.
            line = line(at + len(start):)
         else
            line = adjustl(line)
            if (line(1:1) == '*') line = line(2:)
         end if
         at = index(line, finish)
         if (at > 0) then
            text = text//' '//line(:at - 1)
            exit
         end if
         text = text//' '//trim(line)
      end do
      close (unit)
      call check(failure, reading .and. at > 0, 'no "'//start//' ...'//finish//'" in '//trim(path))
      if (allocated(failure)) return
      ! The words of text, in order.
      allocate (character(len=16) :: documented(0))
      text = adjustl(text)
      do while (len_trim(text) > 0)
         n = index(text, ' ')
         if (n == 0) n = len(text) + 1
         documented = [character(len=16) :: documented, text(:n - 1)]
         text = adjustl(text(n:))
      end do
      names = step_type_names()
      call check(failure, size(documented) == size(names) .and. size(names) == 11, &
         & 'the header documents '//itoa(size(documented))//' step types, the table has '//itoa(size(names)))
      if (allocated(failure)) return
      do i = 1, size(names)
         call check(failure, trim(documented(i)) == trim(names(i)), 'step type '//itoa(i)//': header ' &
            & //trim(documented(i))//', table '//trim(names(i)))
         call check(failure, step_type_index(names(i)) == i, 'index of '//trim(names(i)))
      end do
      call check(failure, step_type_index('euler') == 0 .and. step_type_index('') == 0 &
         & .and. step_type_index('rk8') == 0, 'an unknown name has an index')
      call check(failure, step_type_index('rk8pd   ') == 5, 'trailing blanks are not ignored')
      call check(failure, is_implicit_step_type('msbdf') .and. is_implicit_step_type('rk4imp') &
         & .and. is_implicit_step_type('bsimp'), 'an implicit method counts as explicit')
      call check(failure, .not. (is_implicit_step_type('msadams') .or. is_implicit_step_type('rk8pd') &
         & .or. is_implicit_step_type('euler')), 'an explicit or unknown method counts as implicit')
   end subroutine step_types_as_the_header_documents

   !> GSL reports an error inside each of these calls (it would abort with
   !> its default handler): they come back as errors, the program's handler
   !> is never called and is in place afterwards.
   subroutine gsl_reports_stay_inside(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(oscillator), target :: system
      type(ode_solver) :: solver
      type(solver_settings) :: settings
      type(error_type), allocatable :: error
      type(c_funptr) :: previous
      real(wp) :: t, y(2)

      previous = gsl_set_error_handler(c_funloc(counting_handler))
      gsl_calls = 0

      ! h_min above the first step: GSL refuses it (and returns success).
      settings%h_min = 1.0e-2_wp
      call solver%init(system, settings, 1.0e-3_wp, error)
      call check(failure, allocated(error), 'h_min above the first step accepted')
      if (allocated(failure)) return
      call check(failure, error%stat == error_input, 'h_min refusal is not an input error')
      call check(failure, index(error%message, 'h_min') > 0 .and. index(error%message, 'rkf45') > 0 &
         & .and. index(error%message, 'hmin <= fabs(h) <= hmax required') > 0, &
         & 'h_min refusal: '//error%message)
      call check(failure, handler_is(c_funloc(counting_handler)), 'handler changed by init')

      ! Backwards: GSL reports inconsistent limits (and returns success).
      settings%h_min = 0.0_wp
      call solver%init(system, settings, 1.0e-3_wp, error)
      call check(failure, .not. allocated(error), 'init failed')
      if (allocated(failure)) return
      t = 1.0_wp
      y = [1.0_wp, 0.0_wp]
      call solver%advance(t, 0.0_wp, y, error)
      call check(failure, allocated(error), 'integration backwards accepted')
      if (allocated(failure)) return
      call check(failure, error%stat == error_numerical .and. index(error%message, 'rkf45 failed at t = ') > 0 &
         & .and. index(error%message, 'integration limits and/or step direction not consistent') > 0, &
         & 'backwards: '//error%message)
      call check(failure, handler_is(c_funloc(counting_handler)), 'handler changed by advance')

      ! A zero first step at a restart: the next advance reports it, once.
      call solver%restart(0.0_wp)
      t = 0.0_wp
      call solver%advance(t, 1.0_wp, y, error)
      call check(failure, allocated(error), 'restart with a zero step accepted')
      if (allocated(failure)) return
      call check(failure, index(error%message, 'could not restart') > 0 &
         & .and. index(error%message, 'invalid hstart') > 0 .and. t == 0.0_wp, 'zero restart: '//error%message)
      call solver%restart(1.0e-3_wp)
      call solver%advance(t, 1.0_wp, y, error)
      call check(failure, .not. allocated(error) .and. t == 1.0_wp, 'no recovery after a good restart')
      if (allocated(failure)) return

      ! A restart below h_min, reported by restart itself.
      settings%h_min = 1.0e-3_wp
      call solver%init(system, settings, 1.0e-2_wp, error)
      call check(failure, .not. allocated(error), 'init with h_min below the first step failed')
      if (allocated(failure)) return
      call solver%restart(1.0e-4_wp, error)
      call check(failure, allocated(error), 'restart below h_min accepted')
      if (allocated(failure)) return
      call check(failure, index(error%message, 'h_min = ') > 0 &
         & .and. index(error%message, 'hmin <= fabs(h) <= hmax required') > 0, 'restart below h_min: '//error%message)
      call solver%destroy()

      call check(failure, gsl_calls == 0, 'the library called the program''s handler')
      call check(failure, handler_is(c_funloc(counting_handler)), 'handler changed by restart')
      ! The program's own GSL errors still reach its handler.
      call check(failure, own_gsl_error() == 19, 'copied a vector of 2 into one of 1')
      call check(failure, gsl_calls == 1, 'the program''s own GSL error did not reach its handler')
      previous = gsl_set_error_handler(previous)
   end subroutine gsl_reports_stay_inside

   !> A file written (and a failure of HDF5 inside the writer) leaves the
   !> program's automatic error printing as it was: the default (printing
   !> on), then a function of its own, which the writer never calls.
   subroutine hdf5_printing_kept(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(c_funptr) :: initial_func
      type(c_ptr) :: initial_data
      integer(c_int), target :: calls
      type(error_type), allocatable :: error
      integer :: unit, stat

      call get_printing(initial_func, initial_data, failure)
      call check(failure, c_associated(initial_func), 'printing is off before the test')
      if (allocated(failure)) return
      call write_file(.false., error, failure)
      if (allocated(failure)) return
      call check(failure, .not. allocated(error), 'writing failed')
      if (allocated(failure)) return

      calls = 0
      call check(failure, h5e_set_auto2(default_stack, c_funloc(counting_printer), c_loc(calls)) >= 0, &
         & 'H5Eset_auto2')
      call write_file(.true., error, failure)
      if (allocated(failure)) return
      call check(failure, allocated(error), 'a group created twice went unnoticed')
      if (allocated(failure)) return
      call check(failure, error%stat == error_io .and. index(error%message, 'creating group /twice') > 0, &
         & 'writer failure: '//error%message)
      call check(failure, calls == 0, 'the writer called the program''s error function')
      ! The program's own failing HDF5 call still reaches it.
      call check(failure, h5f_open('no-such-dir/missing.h5'//c_null_char, 0_c_int, 0_c_int64_t) < 0, &
         & 'opened a missing file')
      call check(failure, calls == 1, 'the program''s own HDF5 error reached its function ' &
         & //itoa(int(calls))//' times, not once')
      call check(failure, h5e_set_auto2(default_stack, initial_func, initial_data) >= 0, 'H5Eset_auto2 back')
      open (newunit=unit, file=h5_path, status='old', iostat=stat)
      if (stat == 0) close (unit, status='delete')
   end subroutine hdf5_printing_kept

   !> Create, write, (fail,) close; the setting checked after each.
   subroutine write_file(fail, error, failure)
      logical, intent(in) :: fail
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable, intent(inout) :: failure
      type(h5_file) :: file
      type(c_funptr) :: func
      type(c_ptr) :: data
      real(wp), target :: values(3) = [1.0_wp, 2.0_wp, 3.0_wp]

      call get_printing(func, data, failure)
      call file%create(h5_path, MPI_COMM_SELF, error)
      call check(failure, .not. allocated(error), 'create')
      call check_printing(func, data, 'create', failure)
      call file%write_vector('/values', values, 'm')
      call check_printing(func, data, 'write_vector', failure)
      call file%create_group('/twice')
      call check_printing(func, data, 'create_group', failure)
      call file%write_attribute_text('/twice', 'note', 'text')
      call check_printing(func, data, 'write_attribute_text', failure)
      if (fail) then
         call file%create_group('/twice')
         call check_printing(func, data, 'create_group again', failure)
      end if
      call file%close(error)
      call check_printing(func, data, 'close', failure)
   end subroutine write_file

   !> The setting is still (func, data).
   subroutine check_printing(func, data, after, failure)
      type(c_funptr), intent(in) :: func
      type(c_ptr), intent(in) :: data
      character(len=*), intent(in) :: after
      character(len=:), allocatable, intent(inout) :: failure
      type(c_funptr) :: f
      type(c_ptr) :: d

      call get_printing(f, d, failure)
      call check(failure, c_associated(f, func), 'automatic error printing changed by '//after)
      call check(failure, c_associated(d) .eqv. c_associated(data), &
         & 'automatic error printing data changed by '//after)
      if (c_associated(data)) call check(failure, c_associated(d, data), &
         & 'automatic error printing data changed by '//after)
   end subroutine check_printing

   subroutine get_printing(func, data, failure)
      type(c_funptr), intent(out) :: func
      type(c_ptr), intent(out) :: data
      character(len=:), allocatable, intent(inout) :: failure

      func = c_null_funptr
      data = c_null_ptr
      call check(failure, h5e_get_auto2(default_stack, func, data) >= 0, 'H5Eget_auto2')
   end subroutine get_printing

end program test_library_state
