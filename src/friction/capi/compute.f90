!> The C API's computations on the calling process, without MPI: a scan
!> line of a map into the caller's arrays, a whole scene into a result
!> handle (the named arrays the scene's compute gives), and the reading of
!> a result's arrays.  The scene computes itself: no scene is named here.
module friction_capi_compute
   use, intrinsic :: iso_c_binding, only: c_ptr, c_int, c_double, c_size_t, c_null_ptr, c_associated, &
      & c_f_pointer, c_loc, c_funptr, c_f_procpointer, c_null_funptr
   use friction_kinds, only: i8
   use friction_error, only: error_type, fatal_error, error_input, error_internal
   use friction_strings, only: itoa, join
   use friction_scene_sink, only: array_sink
   use friction_job_config, only: job_config
   use friction_job, only: job_reporter
   use friction_capi_text, only: c_string, copy_text
   use friction_capi_handles, only: capi_config, capi_result, kind_result, friction_handle_add, &
      & friction_handle_live, report, refuse, config_of
   use friction_capi_config, only: check_config
   use friction_capi_reporter, only: callback_reporter
   implicit none
   private

   public :: friction_afm_line, friction_afm_line_progress, friction_compute, friction_compute_progress, &
      & friction_result_get, friction_result_shape, friction_result_names

contains

   !> int friction_afm_line(friction_config *cfg, int line, int forward,
   !>                       double *fx, double *fy, size_t n, friction_error *err)
   integer(c_int) function friction_afm_line(cfg, line, forward, fx, fy, n, handle) &
      & bind(c, name='friction_afm_line_body') result(status)
      type(c_ptr), value :: cfg, fx, fy, handle
      integer(c_int), value :: line, forward
      integer(c_size_t), value :: n

      status = friction_afm_line_progress(cfg, line, forward, fx, fy, n, c_null_funptr, c_null_ptr, handle)
   end function friction_afm_line

   !> int friction_afm_line_progress(friction_config *cfg, int line, int forward, double *fx,
   !>     double *fy, size_t n, friction_progress_fn progress, void *user, friction_error *err)
   integer(c_int) function friction_afm_line_progress(cfg, line, forward, fx, fy, n, progress, user, handle) &
      & bind(c, name='friction_afm_line_progress_body') result(status)
      type(c_ptr), value :: cfg, fx, fy, user, handle
      integer(c_int), value :: line, forward
      integer(c_size_t), value :: n
      type(c_funptr), value :: progress
      type(callback_reporter) :: reporter
      type(capi_config), pointer :: config
      type(error_type), allocatable :: error
      type(job_config) :: work
      type(array_sink) :: arrays
      real(c_double), pointer :: out(:)
      integer :: k, i

      if (.not. config_of(cfg, config, error)) then
         status = report(handle, error)
         return
      end if
      if (.not. (c_associated(fx) .and. c_associated(fy))) then
         status = refuse(handle, 'fx and fy must not be null pointers')
         return
      end if
      call check_config(config, work, error)
      if (.not. allocated(error)) then
         if (c_associated(progress)) then
            call c_f_procpointer(progress, reporter%ask)
            reporter%user = user
            call work%scene%compute_line(int(line), forward /= 0, int(n, i8), arrays, config%memory, error, &
               & reporter)
         else
            call work%scene%compute_line(int(line), forward /= 0, int(n, i8), arrays, config%memory, error)
         end if
      end if
      if (allocated(error)) then
         status = report(handle, error)
         return
      end if
      do k = 1, 2
         i = arrays%find(trim(merge('fx', 'fy', k == 1)))
         call c_f_pointer(merge(fx, fy, k == 1), out, [arrays%items(i)%rows])
         out = arrays%items(i)%values
      end do
      status = report(handle, error)
   end function friction_afm_line_progress

   !> friction_result *friction_compute(const friction_config *cfg, friction_error *err)
   type(c_ptr) function friction_compute(cfg, handle) bind(c, name='friction_compute_body') result(res)
      type(c_ptr), value :: cfg, handle

      res = friction_compute_progress(cfg, c_null_funptr, c_null_ptr, handle)
   end function friction_compute

   !> friction_result *friction_compute_progress(const friction_config *cfg,
   !>     friction_progress_fn progress, void *user, friction_error *err)
   type(c_ptr) function friction_compute_progress(cfg, progress, user, handle) &
      & bind(c, name='friction_compute_progress_body') result(res)
      type(c_ptr), value :: cfg, user, handle
      type(c_funptr), value :: progress
      type(callback_reporter) :: reporter
      type(job_reporter) :: silent

      if (.not. c_associated(progress)) then
         res = compute_scene(cfg, silent, handle)
         return
      end if
      call c_f_procpointer(progress, reporter%ask)
      reporter%user = user
      res = compute_scene(cfg, reporter, handle)
   end function friction_compute_progress

   !> friction_compute's work, with its progress and stop requests through
   !> `reporter`.
   type(c_ptr) function compute_scene(cfg, reporter, handle) result(res)
      type(c_ptr), value :: cfg, handle
      class(job_reporter), intent(inout) :: reporter
      type(capi_config), pointer :: config
      type(capi_result), pointer :: result
      type(error_type), allocatable :: error
      type(job_config) :: work
      integer(c_int) :: status

      res = c_null_ptr
      if (config_of(cfg, config, error)) call check_config(config, work, error)
      if (.not. allocated(error) .and. work%sweep%enabled()) call fatal_error(error, "&sweep: sweep_variable = '" &
         & //trim(work%sweep%variables(1))//"': friction_compute computes one scene; run the sweep with " &
         & //'friction_run_config', error_input)
      ! (A check asked for and not run would pass without a word.)
      if (.not. allocated(error)) then
         if (work%scene%verifies()) call fatal_error(error, '&verify: check = .true.: friction_compute runs ' &
            & //'no check; run the job with friction_run_config, which writes the check''s result', error_input)
      end if
      if (allocated(error)) then
         status = report(handle, error)
         return
      end if
      allocate (result)
      allocate (result%items(0))
      call work%scene%compute(result, config%memory, reporter, error)
      if (.not. allocated(error)) then
         if (friction_handle_add(c_loc(result), kind_result) == 0) call fatal_error(error, &
            & 'out of memory for a new result handle', error_internal)
      end if
      status = report(handle, error)
      if (allocated(error)) then
         deallocate (result)
      else
         res = c_loc(result)
      end if
   end function compute_scene

   !> The item of a result named by a C string; 0 (and an error) if none.
   integer function find_item(res, name_c, result, error) result(found)
      type(c_ptr), intent(in) :: res, name_c
      type(capi_result), pointer, intent(out) :: result
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: name
      integer :: k

      found = 0
      nullify (result)
      if (.not. c_associated(res)) then
         call fatal_error(error, 'the result is a null pointer', error_input)
         return
      end if
      if (friction_handle_live(res, kind_result) == 0) then
         call fatal_error(error, 'the result handle is not live (freed already, or not from friction_compute)', &
            & error_input)
         return
      end if
      call c_f_pointer(res, result)
      if (.not. c_associated(name_c)) then
         call fatal_error(error, 'name must not be a null pointer', error_input)
         return
      end if
      name = c_string(name_c)
      do k = 1, size(result%items)
         if (result%items(k)%name == name) then
            found = k
            return
         end if
      end do
      call fatal_error(error, "no result named '"//name//"' (known: "//join(result%items%name)//')', error_input)
   end function find_item

   !> int friction_result_get(const friction_result *res, const char *name, double *out,
   !>                         size_t n, size_t *needed, friction_error *err)
   integer(c_int) function friction_result_get(res, name_c, out, n, needed, handle) &
      & bind(c, name='friction_result_get') result(status)
      type(c_ptr), value :: res, name_c, out, needed, handle
      integer(c_size_t), value :: n
      type(capi_result), pointer :: result
      type(error_type), allocatable :: error
      integer(c_size_t), pointer :: needed_out
      real(c_double), pointer :: values(:)
      integer :: k, count

      k = find_item(res, name_c, result, error)
      if (k > 0) then
         count = size(result%items(k)%values)
         if (c_associated(needed)) then
            call c_f_pointer(needed, needed_out)
            needed_out = int(count, c_size_t)
         end if
         if (n < count) then
            ! A size query (out null, n 0) is not an error.
            if (c_associated(out) .or. n /= 0) call fatal_error(error, 'n = '//itoa(int(n))//': '// &
               & trim(result%items(k)%name)//' has '//itoa(count)//' values', error_input)
         else if (count > 0 .and. .not. c_associated(out)) then
            call fatal_error(error, 'out is a null pointer', error_input)
         else if (count > 0) then
            call c_f_pointer(out, values, [count])
            values = result%items(k)%values
         end if
      end if
      status = report(handle, error)
   end function friction_result_get

   !> int friction_result_shape(const friction_result *res, const char *name, size_t shape[2],
   !>                           friction_error *err)
   integer(c_int) function friction_result_shape(res, name_c, shape, handle) bind(c, name='friction_result_shape') &
      & result(status)
      type(c_ptr), value :: res, name_c, shape, handle
      type(capi_result), pointer :: result
      type(error_type), allocatable :: error
      integer(c_size_t), pointer :: out(:)
      integer :: k

      k = find_item(res, name_c, result, error)
      if (k > 0) then
         if (.not. c_associated(shape)) then
            call fatal_error(error, 'shape is a null pointer', error_input)
         else
            call c_f_pointer(shape, out, [2])
            out = int([result%items(k)%rows, result%items(k)%columns], c_size_t)
         end if
      end if
      status = report(handle, error)
   end function friction_result_shape

   !> int friction_result_names(const friction_result *res, char *buf, size_t len)
   integer(c_int) function friction_result_names(res, buf, len) bind(c, name='friction_result_names') &
      & result(status)
      type(c_ptr), value :: res, buf
      integer(c_size_t), value :: len
      type(capi_result), pointer :: result

      status = error_input
      if (.not. c_associated(res)) return
      if (friction_handle_live(res, kind_result) == 0) return
      call c_f_pointer(res, result)
      if (copy_text(join(result%items%name, new_line('a')), buf, len)) status = 0
   end function friction_result_names

end module friction_capi_compute
