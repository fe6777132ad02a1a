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
