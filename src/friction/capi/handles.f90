!> The C API's handles: what each opaque pointer of include/friction.h
!> points to, the table of the live ones (handles.c), and their making and
!> freeing; the error handle, which every call fills with its status and
!> message.  A handle not in the table (freed, never given out, or of
!> another kind) is refused by the calls that take it and ignored by the
!> frees.
module friction_capi_handles
   use, intrinsic :: iso_c_binding, only: c_ptr, c_int, c_size_t, c_null_ptr, c_associated, c_f_pointer, c_loc
   use friction_error, only: error_type, fatal_error, error_input
   use friction_strings, only: quoted
   use friction_checks, only: config_checker
   use friction_scene, only: point_memory
   use friction_scene_sink, only: array_sink
   use friction_job_factory, only: scene_names, new_scene
   use friction_job_config, only: job_config
   use friction_capi_text, only: c_string, copy_text
   implicit none
   private

   public :: capi_error, capi_config, capi_result
   public :: kind_error, kind_config, kind_result, kind_law
   public :: friction_handle_add, friction_handle_remove, friction_handle_live
   public :: report, refuse, config_of
   public :: friction_error_new, friction_error_free, friction_error_status, friction_error_message
   public :: friction_config_new, friction_config_free, friction_result_free

   !> The kinds of handle in the table of live ones (handles.c).
   integer(c_int), parameter :: kind_error = 1, kind_config = 2, kind_result = 3, kind_law = 4

   !> What an opaque `friction_error *` points to.
   type :: capi_error
      integer :: status = 0
      character(len=:), allocatable :: message
   end type capi_error

   !> What an opaque `friction_config *` points to: the configuration and
   !> where each value was last set (a file and line; '' when set by name),
   !> for the checks' messages.
   type :: capi_config
      type(job_config) :: job
      type(config_checker) :: origins
      !> the files read into it: a job's output must not be one of them
      character(len=4096), allocatable :: files(:)
      !> the surface of the last line or computation (take_surface), for the
      !> next one while &surface and the scan's rectangle stay as they were:
      !> a Lennard-Jones net's table is built once, not once per line
      type(point_memory) :: memory
   end type capi_config

   !> What an opaque `friction_result *` points to: the named arrays a
   !> scene computed (scene's compute).
   type, extends(array_sink) :: capi_result
   end type capi_result

   interface
      !> The live handles (handles.c): recorded when made, taken out when
      !> freed; a handle not live (freed, or never given out) is refused.
      integer(c_int) function friction_handle_add(handle, kind) bind(c, name='friction_handle_add')
         import :: c_ptr, c_int
         type(c_ptr), value :: handle
         integer(c_int), value :: kind
      end function friction_handle_add
      integer(c_int) function friction_handle_remove(handle, kind) bind(c, name='friction_handle_remove')
         import :: c_ptr, c_int
         type(c_ptr), value :: handle
         integer(c_int), value :: kind
      end function friction_handle_remove
      integer(c_int) function friction_handle_live(handle, kind) bind(c, name='friction_handle_live')
         import :: c_ptr, c_int
         type(c_ptr), value :: handle
         integer(c_int), value :: kind
      end function friction_handle_live
   end interface

contains

   !> Store the outcome in the handle (if any) and return its status.
   integer(c_int) function report(handle, error) result(status)
      type(c_ptr), intent(in) :: handle
      type(error_type), allocatable, intent(in) :: error
      type(capi_error), pointer :: err

      status = 0
      if (allocated(error)) status = int(error%stat, c_int)
      if (.not. c_associated(handle)) return
      if (friction_handle_live(handle, kind_error) == 0) return   ! freed: nowhere to say it
      call c_f_pointer(handle, err)
      err%status = status
      if (allocated(error)) then
         err%message = error%message
      else
         err%message = ''
      end if
   end function report

   !> An input error with a message, stored in the handle; its status.
   integer(c_int) function refuse(handle, message) result(status)
      type(c_ptr), intent(in) :: handle
      character(len=*), intent(in) :: message
      type(error_type), allocatable :: error

      call fatal_error(error, message, error_input)
      status = report(handle, error)
   end function refuse

   !> friction_error *friction_error_new(void)
   type(c_ptr) function friction_error_new() bind(c, name='friction_error_new') result(handle)
      type(capi_error), pointer :: err

      allocate (err)
      err%message = ''
      handle = c_loc(err)
      if (friction_handle_add(handle, kind_error) == 0) then
         deallocate (err)
         handle = c_null_ptr
      end if
   end function friction_error_new

   !> void friction_error_free(friction_error *err); null is ignored.
   subroutine friction_error_free(handle) bind(c, name='friction_error_free')
      type(c_ptr), value :: handle
      type(capi_error), pointer :: err

      if (.not. c_associated(handle)) return
      if (friction_handle_remove(handle, kind_error) == 0) return   ! freed already, or not an error handle
      call c_f_pointer(handle, err)
      deallocate (err)
   end subroutine friction_error_free

   !> int friction_error_status(const friction_error *err); -1 for null.
   integer(c_int) function friction_error_status(handle) bind(c, name='friction_error_status') result(status)
      type(c_ptr), value :: handle
      type(capi_error), pointer :: err

      status = -1
      if (.not. c_associated(handle)) return
      if (friction_handle_live(handle, kind_error) == 0) return
      call c_f_pointer(handle, err)
      status = err%status
   end function friction_error_status

   !> int friction_error_message(const friction_error *err, char *buf, size_t len):
   !> the message, truncated to fit; non-zero if null or truncated.
   integer(c_int) function friction_error_message(handle, buf, len) bind(c, name='friction_error_message') &
      & result(status)
      type(c_ptr), value :: handle, buf
      integer(c_size_t), value :: len
      type(capi_error), pointer :: err
      logical :: copied

      status = error_input
      if (.not. c_associated(handle)) then
         copied = copy_text('', buf, len)   ! an empty message, still a failure
         return
      end if
      if (friction_handle_live(handle, kind_error) == 0) then
         copied = copy_text('the error handle is not live (freed already, or not from friction_error_new)', buf, len)
         return
      end if
      call c_f_pointer(handle, err)
      if (copy_text(err%message, buf, len)) status = 0
   end function friction_error_message

   !> friction_config *friction_config_new(const char *scene, friction_error *err):
   !> a configuration of the scene with its defaults; NULL on an unknown scene.
   type(c_ptr) function friction_config_new(scene_name, handle) bind(c, name='friction_config_new_body') result(cfg)
      type(c_ptr), value :: scene_name, handle
      type(capi_config), pointer :: config
      character(len=:), allocatable :: name
      integer(c_int) :: status
      type(error_type), allocatable :: none

      cfg = c_null_ptr
      if (.not. c_associated(scene_name)) then
         status = refuse(handle, 'scene is a null pointer (known: '//quoted(scene_names)//')')
         return
      end if
      name = c_string(scene_name)
      allocate (config)
      call new_scene(name, config%job%scene)
      if (.not. allocated(config%job%scene) .or. len(name) > len(config%job%scene_name)) then
         deallocate (config)
         status = refuse(handle, "unknown scene '"//name//"' (known: "//quoted(scene_names)//')')
         return
      end if
      config%job%scene_name = name
      allocate (config%files(0))
      cfg = c_loc(config)
      if (friction_handle_add(cfg, kind_config) == 0) then
         deallocate (config)
         cfg = c_null_ptr
         status = refuse(handle, 'out of memory for a new configuration handle')
         return
      end if
      status = report(handle, none)
   end function friction_config_new

   !> void friction_config_free(friction_config *cfg); null is ignored.
   subroutine friction_config_free(cfg) bind(c, name='friction_config_free')
      type(c_ptr), value :: cfg
      type(capi_config), pointer :: config

      if (.not. c_associated(cfg)) return
      if (friction_handle_remove(cfg, kind_config) == 0) return   ! freed already, or not a configuration
      call c_f_pointer(cfg, config)
      deallocate (config)
   end subroutine friction_config_free

   !> The configuration behind a handle; false (and an error) for null.
   function config_of(cfg, config, error) result(ok)
      type(c_ptr), intent(in) :: cfg
      type(capi_config), pointer, intent(out) :: config
      type(error_type), allocatable, intent(inout) :: error
      logical :: ok

      ok = c_associated(cfg)
      nullify (config)
      if (.not. ok) then
         call fatal_error(error, 'the configuration is a null pointer', error_input)
      else if (friction_handle_live(cfg, kind_config) == 0) then
         ok = .false.
         call fatal_error(error, 'the configuration handle is not live (freed already, or not from ' &
            & //'friction_config_new)', error_input)
      else
         call c_f_pointer(cfg, config)
      end if
   end function config_of

   !> void friction_result_free(friction_result *res); null is ignored.
   subroutine friction_result_free(res) bind(c, name='friction_result_free')
      type(c_ptr), value :: res
      type(capi_result), pointer :: result

      if (.not. c_associated(res)) return
      if (friction_handle_remove(res, kind_result) == 0) return   ! freed already, or not a result
      call c_f_pointer(res, result)
      deallocate (result)
   end subroutine friction_result_free

end module friction_capi_handles
