!> The C API (include/friction.h), version 2: handles over the kernel.
!>
!> A configuration handle is a job's configuration (&job, the scene's
!> groups, &sweep) made with its scene's defaults and changed by namelist
!> files or by name ("tip.kx"), through the same description of the
!> variables (core/parameters.f90) and the same checks (the scene's own)
!> as the program's input.  Computations on the calling process (a scan
!> line, a whole scene into a result handle) use the scanner and the brake
!> run directly, without MPI; jobs run the program's job routine.
!>
!> Every call returns a status (0 on success, else one of the friction_error
!> codes) and, when the caller passes an error handle, fills it with the
!> status and a message.  No module variables: all state lives in the
!> caller's handles or in the call's locals, so threads may work at once on
!> different handles.
module friction_capi
   use, intrinsic :: iso_c_binding, only: c_ptr, c_char, c_int, c_double, c_size_t, c_null_char, c_null_ptr, &
      & c_associated, c_f_pointer, c_loc, c_funptr, c_f_procpointer, c_null_funptr
   use mpi_f08, only: MPI_Comm, MPI_Initialized, MPI_Finalized, MPI_Init_thread, MPI_THREAD_FUNNELED, &
      & MPI_COMM_WORLD, MPI_COMM_NULL
   use friction_kinds, only: wp, i8
   use friction_error, only: error_type, fatal_error, error_input, error_interrupted, error_internal
   use friction_strings, only: itoa, rtoa, join, quoted
   use friction_version, only: version_string
   use friction_parameters, only: configurable, parameter_info, list_parameters, set_parameter, &
      & set_parameter_number, get_parameter, kind_text, value_has_kind, unit_hint
   use friction_checks, only: config_checker
   use friction_input_reader, only: namelist_source, scan_files, apply_files, parse_variable_name
   use friction_scene, only: point_memory
   use friction_scene_sink, only: array_sink, named_array
   use friction_job_factory, only: scene_names, new_scene
   use friction_job_config, only: job_config, check_job, job_text, all_parameters, parameter_groups, not_in_scene
   use friction_job, only: run_job, run_job_config, job_reporter
   use friction_scene_report, only: progress_text
   implicit none
   private

   public :: friction_version_c, friction_api_version, friction_error_new, friction_error_free, &
      & friction_error_status, friction_error_message
   public :: friction_config_new, friction_config_free, friction_config_read, friction_config_set, &
      & friction_config_set_real, friction_config_get, friction_config_text, friction_config_names, &
      & friction_config_check
   public :: friction_afm_line, friction_compute, friction_compute_progress, friction_result_get, &
      & friction_result_shape, friction_result_names, friction_result_free
   public :: friction_run_job, friction_run_config
   !> For the C API's other files (capi/law.f90): the error handle's and the
   !> strings' helpers.
   public :: report, refuse, c_string, copy_text, set_checked_text, set_checked_number

   !> FRICTION_API_VERSION of include/friction.h.
   integer(c_int), parameter :: api_version = 2

   !> friction_run_job / friction_run_config flags.
   integer(c_int), parameter :: job_force = 1, job_resume = 2, job_init_mpi = 4

   !> The kinds of handle in the table of live ones (handles.c).
   integer(c_int), parameter :: kind_error = 1, kind_config = 2, kind_result = 3

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

   !> A job's or a computation's progress through the caller's C function.
   !> A job's (`call`, if any): void report(const char *message, double
   !> fraction, void *user), fraction in [0, 1] for progress and -1 for a
   !> note; it stops on friction_job_stop.  A computation's (`ask`): int
   !> progress(const char *message, double fraction, void *user), whose
   !> nonzero return stops it at its next safe point; the request is that
   !> call's own, so computations on other threads go on.
   type, extends(job_reporter) :: callback_reporter
      procedure(report_function), pointer, nopass :: call => null()
      procedure(progress_function), pointer, nopass :: ask => null()
      type(c_ptr) :: user = c_null_ptr
      logical :: stop = .false.   !! `ask` returned nonzero
   contains
      procedure :: progress => callback_progress
      procedure :: note => callback_note
      procedure :: stop_requested => callback_stop_requested
   end type callback_reporter

   abstract interface
      integer(c_int) function progress_function(message, fraction, user) bind(c)
         import :: c_char, c_double, c_ptr, c_int
         character(kind=c_char), intent(in) :: message(*)
         real(c_double), value :: fraction
         type(c_ptr), value :: user
      end function progress_function

      subroutine report_function(message, fraction, user) bind(c)
         import :: c_char, c_double, c_ptr
         character(kind=c_char), intent(in) :: message(*)
         real(c_double), value :: fraction
         type(c_ptr), value :: user
      end subroutine report_function
   end interface

   interface
      pure function c_strlen(s) bind(c, name='strlen') result(n)
         import :: c_ptr, c_size_t
         type(c_ptr), value :: s
         integer(c_size_t) :: n
      end function c_strlen

      !> One job at a time in the process (job_lock.c): 0 once the calling
      !> thread may run its job, 1 if it is running one already, 2 in a
      !> process forked while its parent ran one.
      function friction_job_begin() bind(c, name='friction_job_begin') result(busy)
         import :: c_int
         integer(c_int) :: busy
      end function friction_job_begin

      subroutine friction_job_end() bind(c, name='friction_job_end')
      end subroutine friction_job_end

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
      function friction_job_stop_asked() bind(c, name='friction_job_stop_asked') result(asked)
         import :: c_int
         integer(c_int) :: asked
      end function friction_job_stop_asked

      !> Around friction_config_read's file reading (job_lock.c): 1 if it
      !> took the lock, 0 if this thread holds it for its job, -1 in a
      !> process forked while its parent ran a job (no read then).
      function friction_read_begin() bind(c, name='friction_read_begin') result(taken)
         import :: c_int
         integer(c_int) :: taken
      end function friction_read_begin

      subroutine friction_read_end() bind(c, name='friction_read_end')
      end subroutine friction_read_end
   end interface

   !> Why a process forked while its parent ran a job or read a file can
   !> neither (job_lock.c).
   character(len=*), parameter :: forked_message = 'this process was forked while a job or a file read ran in ' &
      & //'its parent: its HDF5 and Fortran runtime are the parent''s, caught half-way; start worker processes ' &
      & //"with 'spawn' or 'forkserver' (Python's multiprocessing), or fork between jobs"

contains

   ! ---- strings, buffers, errors ----

   !> Copy text and a NUL into a caller buffer of len bytes; `needed` is the
   !> bytes it takes (NUL included).  False if the buffer is null or too
   !> small: then as much as fits is written, NUL-terminated (if len > 0).
   function copy_text(text, buf, len, needed) result(ok)
      character(len=*), intent(in) :: text
      type(c_ptr), intent(in) :: buf
      integer(c_size_t), intent(in) :: len
      type(c_ptr), intent(in), optional :: needed
      logical :: ok
      character(kind=c_char), pointer :: out(:)
      integer(c_size_t), pointer :: needed_out
      integer :: i, n

      if (present(needed)) then
         if (c_associated(needed)) then
            call c_f_pointer(needed, needed_out)
            needed_out = int(len_text(text) + 1, c_size_t)
         end if
      end if
      ok = .false.
      if (.not. c_associated(buf) .or. len < 1) return
      call c_f_pointer(buf, out, [len])
      n = int(min(int(len_text(text), c_size_t), len - 1))
      do i = 1, n
         out(i) = text(i:i)
      end do
      out(n + 1) = c_null_char
      ok = len_text(text) < len
   end function copy_text

   !> len(text), for the procedures whose argument `len` (the C name) hides
   !> the intrinsic.
   pure integer function len_text(text)
      character(len=*), intent(in) :: text

      len_text = len(text)
   end function len_text

   !> A C string as Fortran text; '' for a null pointer.
   function c_string(s) result(text)
      type(c_ptr), intent(in) :: s
      character(len=:), allocatable :: text
      character(kind=c_char), pointer :: chars(:)
      integer :: i, n

      if (.not. c_associated(s)) then
         text = ''
         return
      end if
      n = int(c_strlen(s))
      call c_f_pointer(s, chars, [n])
      allocate (character(len=n) :: text)
      do i = 1, n
         text(i:i) = chars(i)
      end do
   end function c_string

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

   ! ---- version and error handles ----

   !> int friction_version(char *buf, size_t len)
   integer(c_int) function friction_version_c(buf, len) bind(c, name='friction_version') result(status)
      type(c_ptr), value :: buf
      integer(c_size_t), value :: len

      status = 0
      if (.not. copy_text(version_string, buf, len)) status = error_input
   end function friction_version_c

   !> int friction_api_version(void)
   integer(c_int) function friction_api_version() bind(c, name='friction_api_version') result(version)
      version = api_version
   end function friction_api_version

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

   ! ---- configurations ----

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

   !> A name 'group.variable' or 'group.variable(k)' for set and get, in
   !> `job` (the handle's copy): its group, variable, element (0 for none)
   !> and the variable's description.  The messages are the namelist
   !> reader's where it has one.
   subroutine resolve_name(job, full, group, name, first, info, error)
      type(job_config), intent(inout) :: job
      character(len=*), intent(in) :: full
      character(len=:), allocatable, intent(out) :: group, name
      integer, intent(out) :: first
      type(parameter_info), intent(out) :: info
      type(error_type), allocatable, intent(out) :: error
      type(parameter_info), allocatable :: universe(:), mine(:)
      character(len=32), allocatable :: known(:)
      integer :: k

      universe = all_parameters()
      call parse_variable_name(full, parameter_groups(universe), group, name, first, error)
      if (allocated(error)) return
      mine = list_parameters(job)
      if (.not. any(mine%group == group)) then
         call fatal_error(error, not_in_scene(job, group), error_input)
         return
      end if
      do k = 1, size(mine)
         if (mine(k)%group == group .and. mine(k)%name == name) then
            info = mine(k)
            return
         end if
      end do
      known = pack(universe%name, universe%group == group)
      call fatal_error(error, '&'//group//": unknown variable '"//name//"' (known: "//join(known)//')', error_input)
   end subroutine resolve_name

   !> After a set of work's &job: the scene cannot change.
   subroutine check_scene_kept(config, work, value, error)
      type(capi_config), intent(in) :: config
      type(job_config), intent(in) :: work
      character(len=*), intent(in) :: value
      type(error_type), allocatable, intent(inout) :: error

      if (allocated(error) .or. work%scene_name == config%job%scene_name) return
      call fatal_error(error, '&job: scene = '//value//": the configuration is of scene '" &
         & //trim(config%job%scene_name)//"' (friction_config_new chooses the scene)", error_input)
   end subroutine check_scene_kept

   !> int friction_config_set(friction_config *cfg, const char *name, const char *value,
   !>                         friction_error *err)
   integer(c_int) function friction_config_set(cfg, name_c, value_c, handle) bind(c, name='friction_config_set_body') &
      & result(status)
      type(c_ptr), value :: cfg, name_c, value_c, handle
      type(capi_config), pointer :: config
      type(error_type), allocatable :: error
      type(job_config) :: work
      type(parameter_info) :: info
      character(len=:), allocatable :: full, value, group, name
      integer :: first

      if (.not. config_of(cfg, config, error)) then
         status = report(handle, error)
         return
      end if
      if (.not. c_associated(name_c) .or. .not. c_associated(value_c)) then
         status = refuse(handle, 'name and value must not be null pointers')
         return
      end if
      full = c_string(name_c)
      value = c_string(value_c)
      ! On a copy: a value refused changes nothing.
      work = config%job
      call resolve_name(work, full, group, name, first, info, error)
      if (.not. allocated(error)) call set_checked_text(work, group, name, first, info, value, error)
      if (allocated(error)) then
         status = report(handle, error)
         return
      end if
      call check_scene_kept(config, work, value, error)
      if (.not. allocated(error)) then
         config%job = work
         call config%origins%set_origin(group, name, '')
      end if
      status = report(handle, error)
   end function friction_config_set

   !> Set group.name (element `first`, 0 for all) of `obj` from namelist
   !> text after checking its kind (`info`): the C API's message when refused.
   subroutine set_checked_text(obj, group, name, first, info, value, error)
      class(configurable), intent(inout) :: obj
      character(len=*), intent(in) :: group, name, value
      integer, intent(in) :: first
      type(parameter_info), intent(in) :: info
      type(error_type), allocatable, intent(inout) :: error
      character(len=:), allocatable :: problem

      if (.not. value_has_kind(value, info%kind)) then
         call fatal_error(error, '&'//group//': '//name//' = '//value//': expected '//kind_text(info%kind) &
            & //unit_hint(info), error_input)
         return
      end if
      call set_parameter(obj, group, name, value, first, '', problem)
      if (len(problem) > 0) call fatal_error(error, '&'//group//': '//element_name(name, first)//' = '//value &
         & //': '//problem, error_input)
   end subroutine set_checked_text

   !> Set group.name (element `first`) of `obj` to the number x, checked.
   subroutine set_checked_number(obj, group, name, first, x, error)
      class(configurable), intent(inout) :: obj
      character(len=*), intent(in) :: group, name
      integer, intent(in) :: first
      real(wp), intent(in) :: x
      type(error_type), allocatable, intent(inout) :: error
      character(len=:), allocatable :: problem

      call set_parameter_number(obj, group, name, x, problem, first)
      if (len(problem) > 0) call fatal_error(error, '&'//group//': '//element_name(name, first)//' = '//rtoa(x) &
         & //': '//problem, error_input)
   end subroutine set_checked_number

   !> name, or name(first) for one element.
   pure function element_name(name, first) result(shown)
      character(len=*), intent(in) :: name
      integer, intent(in) :: first
      character(len=:), allocatable :: shown

      shown = name
      if (first > 0) shown = shown//'('//itoa(first)//')'
   end function element_name

   !> int friction_config_set_real(friction_config *cfg, const char *name, double x,
   !>                              friction_error *err)
   integer(c_int) function friction_config_set_real(cfg, name_c, x, handle) &
      & bind(c, name='friction_config_set_real_body') result(status)
      type(c_ptr), value :: cfg, name_c, handle
      real(c_double), value :: x
      type(capi_config), pointer :: config
      type(error_type), allocatable :: error
      type(job_config) :: work
      type(parameter_info) :: info
      character(len=:), allocatable :: full, group, name
      integer :: first

      if (.not. config_of(cfg, config, error)) then
         status = report(handle, error)
         return
      end if
      if (.not. c_associated(name_c)) then
         status = refuse(handle, 'name must not be a null pointer')
         return
      end if
      full = c_string(name_c)
      work = config%job
      call resolve_name(work, full, group, name, first, info, error)
      if (allocated(error)) then
         status = report(handle, error)
         return
      end if
      call set_checked_number(work, group, name, first, real(x, wp), error)
      if (.not. allocated(error)) then
         config%job = work
         call config%origins%set_origin(group, name, '')
      end if
      status = report(handle, error)
   end function friction_config_set_real

   !> int friction_config_get(const friction_config *cfg, const char *name, char *buf,
   !>                         size_t len, friction_error *err)
   integer(c_int) function friction_config_get(cfg, name_c, buf, len, handle) bind(c, name='friction_config_get_body') &
      & result(status)
      type(c_ptr), value :: cfg, name_c, buf, handle
      integer(c_size_t), value :: len
      type(capi_config), pointer :: config
      type(error_type), allocatable :: error
      type(job_config) :: work
      type(parameter_info) :: info
      character(len=:), allocatable :: full, group, name, text, problem
      integer :: first

      if (.not. config_of(cfg, config, error)) then
         status = report(handle, error)
         return
      end if
      if (.not. c_associated(name_c)) then
         status = refuse(handle, 'name must not be a null pointer')
         return
      end if
      full = c_string(name_c)
      work = config%job   ! (visiting writes each value back: a copy leaves the handle untouched)
      call resolve_name(work, full, group, name, first, info, error)
      if (allocated(error)) then
         status = report(handle, error)
         return
      end if
      call get_parameter(work, group, name, first, text, problem)
      if (len_text(problem) > 0) then
         call fatal_error(error, "name '"//full//"': "//problem, error_input)
      else if (.not. c_associated(buf)) then
         call fatal_error(error, 'buf is a null pointer', error_input)
      else if (.not. copy_text(text, buf, len)) then
         call fatal_error(error, 'a buffer of '//itoa(int(len))//' bytes is too small for the value of '//full &
            & //': '//itoa(len_text(text) + 1)//' bytes needed', error_input)
      end if
      status = report(handle, error)
   end function friction_config_get

   !> int friction_config_text(const friction_config *cfg, char *buf, size_t len, size_t *needed)
   integer(c_int) function friction_config_text(cfg, buf, len, needed) bind(c, name='friction_config_text_body') &
      & result(status)
      type(c_ptr), value :: cfg, buf, needed
      integer(c_size_t), value :: len
      type(capi_config), pointer :: config
      type(job_config) :: work
      character(len=:), allocatable :: text
      integer(c_int) :: taken

      status = error_input
      if (.not. c_associated(cfg)) return
      if (friction_handle_live(cfg, kind_config) == 0) return
      call c_f_pointer(cfg, config)
      work = config%job
      ! (The text is formatted by the Fortran runtime's internal writes, which
      ! raced with another thread's file reading: under the read lock.)
      taken = friction_read_begin()
      if (taken < 0) return   ! (a process forked mid-job: job_lock.c)
      text = job_text(work)
      if (taken /= 0) call friction_read_end()
      status = text_status(text, buf, len, needed)
   end function friction_config_text

   !> Text into a buffer: 0 when it fits; a size query (buf null, len 0)
   !> also succeeds; a buffer too small (truncated) or null is an input error.
   integer(c_int) function text_status(text, buf, len, needed) result(status)
      character(len=*), intent(in) :: text
      type(c_ptr), intent(in) :: buf, needed
      integer(c_size_t), intent(in) :: len

      status = 0
      if (copy_text(text, buf, len, needed)) return
      if (.not. (.not. c_associated(buf) .and. len == 0 .and. c_associated(needed))) status = error_input
   end function text_status

   !> int friction_config_names(const friction_config *cfg, char *buf, size_t len, size_t *needed):
   !> one line per variable: group.name, kind, elements, unit, tab-separated.
   integer(c_int) function friction_config_names(cfg, buf, len, needed) bind(c, name='friction_config_names') &
      & result(status)
      type(c_ptr), value :: cfg, buf, needed
      integer(c_size_t), value :: len
      type(capi_config), pointer :: config
      type(job_config) :: work
      type(parameter_info), allocatable :: list(:)
      character(len=:), allocatable :: text
      character(len=8) :: kind
      integer :: k

      status = error_input
      if (.not. c_associated(cfg)) return
      if (friction_handle_live(cfg, kind_config) == 0) return
      call c_f_pointer(cfg, config)
      work = config%job
      list = list_parameters(work)
      text = ''
      do k = 1, size(list)
         select case (list(k)%kind)
         case ('r'); kind = 'real'
         case ('i'); kind = 'integer'
         case ('l'); kind = 'logical'
         case default; kind = 'text'
         end select
         text = text//trim(list(k)%group)//'.'//trim(list(k)%name)//achar(9)//trim(kind)//achar(9) &
            & //itoa(list(k)%size)//achar(9)//trim(list(k)%unit)//new_line('a')
      end do
      status = text_status(text, buf, len, needed)
   end function friction_config_names

   !> int friction_config_read(friction_config *cfg, const char *path, friction_error *err):
   !> the file's values over the current ones, all or nothing.
   integer(c_int) function friction_config_read(cfg, path_c, handle) bind(c, name='friction_config_read_body') &
      & result(status)
      type(c_ptr), value :: cfg, path_c, handle
      type(capi_config), pointer :: config
      type(error_type), allocatable :: error
      type(namelist_source), allocatable :: sources(:)
      type(parameter_info), allocatable :: universe(:), mine(:)
      type(job_config) :: work, probe
      type(config_checker) :: origins
      character(len=:), allocatable :: path, problem, where
      character(len=4096) :: paths(1)
      integer :: k
      integer(c_int) :: taken

      if (.not. config_of(cfg, config, error)) then
         status = report(handle, error)
         return
      end if
      if (.not. c_associated(path_c)) then
         status = refuse(handle, 'path is a null pointer')
         return
      end if
      path = c_string(path_c)
      if (len(path) > len(paths) .or. len(path) == 0) then
         status = refuse(handle, "path '"//path//"': give a file name of 1 to "//itoa(len(paths))//' characters')
         return
      end if
      paths(1) = path
      universe = all_parameters()
      ! (One file read and parsed at a time in the process: job_lock.c.)
      taken = friction_read_begin()
      if (taken < 0) then
         status = refuse(handle, forked_message)
         return
      end if
      call scan_files(paths, parameter_groups(universe), sources, error)
      if (allocated(error)) then
         if (taken /= 0) call friction_read_end()
         status = report(handle, error)
         return
      end if
      ! The file may name this configuration's scene, no other; and only its groups.
      work = config%job
      mine = list_parameters(work)
      do k = 1, size(sources(1)%mentions)
         associate (m => sources(1)%mentions(k))
            where = path//':'//itoa(m%line)//': '
            if (m%group == 'job' .and. m%name == 'scene') then
               call set_parameter(probe, 'job', 'scene', m%value, 0, '', problem)
               if (len(problem) == 0 .and. probe%scene_name /= config%job%scene_name) then
                  call fatal_error(error, where//'&job: scene = '//trim(m%value)//": the configuration is of " &
                     & //"scene '"//trim(config%job%scene_name)//"' (friction_config_new chooses the scene)", &
                     & error_input)
                  exit
               end if
            end if
            if (.not. any(mine%group == m%group)) then
               call fatal_error(error, where//not_in_scene(work, m%group), error_input)
               exit
            end if
         end associate
      end do
      if (.not. allocated(error)) then
         origins = config%origins
         call apply_files(sources, universe, work, origins, error)
      end if
      if (taken /= 0) call friction_read_end()
      if (.not. allocated(error)) then
         config%job = work
         config%origins = origins
         config%files = [config%files, paths(1)]
      end if
      status = report(handle, error)
   end function friction_config_read

   !> The configuration's checks (those of a job read from files), on a copy.
   subroutine check_config(config, work, error)
      type(capi_config), intent(in) :: config
      type(job_config), intent(out) :: work
      type(error_type), allocatable, intent(out) :: error
      type(config_checker) :: checker

      work = config%job
      checker = config%origins
      call check_job(work, checker)
      if (checker%failed()) call move_alloc(checker%error, error)
   end subroutine check_config

   !> int friction_config_check(const friction_config *cfg, friction_error *err)
   integer(c_int) function friction_config_check(cfg, handle) bind(c, name='friction_config_check_body') result(status)
      type(c_ptr), value :: cfg, handle
      type(capi_config), pointer :: config
      type(error_type), allocatable :: error
      type(job_config) :: work

      if (config_of(cfg, config, error)) call check_config(config, work, error)
      status = report(handle, error)
   end function friction_config_check

   ! ---- computations on this process ----

   !> int friction_afm_line(friction_config *cfg, int line, int forward,
   !>                       double *fx, double *fy, size_t n, friction_error *err)
   integer(c_int) function friction_afm_line(cfg, line, forward, fx, fy, n, handle) &
      & bind(c, name='friction_afm_line_body') result(status)
      type(c_ptr), value :: cfg, fx, fy, handle
      integer(c_int), value :: line, forward
      integer(c_size_t), value :: n
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
      if (.not. allocated(error)) call work%scene%compute_line(int(line), forward /= 0, &
         & int(n, i8), arrays, config%memory, error)
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
   end function friction_afm_line

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

   ! ---- results ----

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

   !> void friction_result_free(friction_result *res); null is ignored.
   subroutine friction_result_free(res) bind(c, name='friction_result_free')
      type(c_ptr), value :: res
      type(capi_result), pointer :: result

      if (.not. c_associated(res)) return
      if (friction_handle_remove(res, kind_result) == 0) return   ! freed already, or not a result
      call c_f_pointer(res, result)
      deallocate (result)
   end subroutine friction_result_free

   ! ---- jobs ----

   !> The flags' checks and the job's communicator: MPI_COMM_WORLD when the
   !> caller initialised MPI, or when it passes FRICTION_JOB_INIT_MPI (MPI is
   !> initialised here); otherwise MPI_COMM_NULL, a serial job on this process
   !> that makes no MPI call.
   subroutine prepare_job(flags, comm, error)
      integer(c_int), intent(in) :: flags
      type(MPI_Comm), intent(out) :: comm
      type(error_type), allocatable, intent(inout) :: error
      logical :: ready, finished
      integer :: provided, ierror

      comm = MPI_COMM_NULL
      if (allocated(error)) return
      if (iand(flags, not(job_force + job_resume + job_init_mpi)) /= 0) then
         call fatal_error(error, 'flags = '//itoa(int(flags))//': unknown bits (known: FRICTION_JOB_FORCE, ' &
            & //'FRICTION_JOB_RESUME, FRICTION_JOB_INIT_MPI)', error_input)
         return
      end if
      call MPI_Finalized(finished)
      if (finished) then
         call fatal_error(error, 'MPI has been finalized: a job needs MPI (call it before MPI_Finalize)', &
            & error_input)
         return
      end if
      call MPI_Initialized(ready)
      if (.not. ready) then
         if (iand(flags, job_init_mpi) == 0) return   ! serial, without MPI
         call MPI_Init_thread(MPI_THREAD_FUNNELED, provided, ierror)
         if (ierror /= 0) then
            call fatal_error(error, 'MPI_Init_thread failed (error '//itoa(ierror)//')', error_input)
            return
         end if
      end if
      comm = MPI_COMM_WORLD
   end subroutine prepare_job

   !> int friction_run_job(const char *const *files, int nfiles, const char *output, int flags,
   !>                      friction_report_fn report, void *user, friction_error *err)
   integer(c_int) function friction_run_job(files, nfiles, output, flags, report_fn, user, handle) &
      & bind(c, name='friction_run_job_body') result(status)
      type(c_ptr), value :: files, output, user, handle
      integer(c_int), value :: nfiles, flags
      type(c_funptr), value :: report_fn
      type(error_type), allocatable :: error
      type(c_ptr), pointer :: names(:)
      character(len=4096), allocatable :: paths(:)
      character(len=:), allocatable :: summary, path
      type(callback_reporter) :: reporter
      type(MPI_Comm) :: comm
      integer :: k

      allocate (paths(0))
      if (.not. c_associated(files) .and. nfiles /= 0) then
         call fatal_error(error, 'files is a null pointer', error_input)
      else if (nfiles < 1) then
         call fatal_error(error, 'nfiles = '//itoa(int(nfiles))//': give at least one namelist file', error_input)
      else if (.not. c_associated(output)) then
         call fatal_error(error, 'output is a null pointer', error_input)
      else
         call c_f_pointer(files, names, [nfiles])
         deallocate (paths)
         allocate (paths(nfiles))
         do k = 1, nfiles
            if (.not. c_associated(names(k))) then
               call fatal_error(error, 'files['//itoa(k - 1)//'] is a null pointer', error_input)
               exit
            end if
            path = c_string(names(k))
            if (len(path) > len(paths)) then
               call fatal_error(error, 'files['//itoa(k - 1)//'] is longer than '//itoa(len(paths)) &
                  & //' characters', error_input)
               exit
            end if
            paths(k) = path
         end do
      end if
      if (.not. allocated(error)) call begin_job(error)
      if (allocated(error)) then
         status = report(handle, error)
         return
      end if
      call prepare_job(flags, comm, error)
      if (.not. allocated(error)) then
         reporter%user = user
         if (c_associated(report_fn)) call c_f_procpointer(report_fn, reporter%call)
         call run_job(paths, c_string(output), iand(flags, job_force) /= 0, iand(flags, job_resume) /= 0, &
            & comm, reporter, summary, error)
      end if
      call friction_job_end()
      status = report(handle, error)
   end function friction_run_job

   !> int friction_run_config(const friction_config *cfg, const char *output, int flags,
   !>                         friction_report_fn report, void *user, friction_error *err)
   integer(c_int) function friction_run_config(cfg, output, flags, report_fn, user, handle) &
      & bind(c, name='friction_run_config_body') result(status)
      type(c_ptr), value :: cfg, output, user, handle
      integer(c_int), value :: flags
      type(c_funptr), value :: report_fn
      type(capi_config), pointer :: config
      type(error_type), allocatable :: error
      character(len=:), allocatable :: summary
      type(callback_reporter) :: reporter
      type(MPI_Comm) :: comm

      if (config_of(cfg, config, error)) then
         if (.not. c_associated(output)) call fatal_error(error, 'output is a null pointer', error_input)
      end if
      if (.not. allocated(error)) call begin_job(error)
      if (allocated(error)) then
         status = report(handle, error)
         return
      end if
      call prepare_job(flags, comm, error)
      if (.not. allocated(error)) then
         reporter%user = user
         if (c_associated(report_fn)) call c_f_procpointer(report_fn, reporter%call)
         call run_job_config(config%job, c_string(output), iand(flags, job_force) /= 0, &
            & iand(flags, job_resume) /= 0, comm, reporter, summary, error, config%origins, config%files)
      end if
      call friction_job_end()
      status = report(handle, error)
   end function friction_run_config

   !> Wait until no other thread runs a job (job_lock.c); refused on a thread
   !> that runs one already (a report callback starting a job).  On success
   !> the caller ends with friction_job_end.
   subroutine begin_job(error)
      type(error_type), allocatable, intent(out) :: error

      select case (friction_job_begin())
      case (1)
         call fatal_error(error, 'a job is already running on this thread (a job cannot be started from its ' &
            & //'own report callback)', error_input)
      case (2)
         call fatal_error(error, forked_message, error_input)
      end select
   end subroutine begin_job

   subroutine callback_progress(self, done, total, what, last)
      class(callback_reporter), intent(inout) :: self
      real(wp), intent(in) :: done, total
      character(len=*), intent(in) :: what
      logical, intent(in) :: last
      character(len=:), allocatable :: text
      real(c_double) :: fraction

      text = progress_text(done, total, what)//c_null_char
      fraction = real(max(0.0_wp, min(1.0_wp, done / max(total, tiny(total)))), c_double)
      if (associated(self%call)) call self%call(text, fraction, self%user)
      if (associated(self%ask)) self%stop = self%stop .or. self%ask(text, fraction, self%user) /= 0
   end subroutine callback_progress

   subroutine callback_note(self, text)
      class(callback_reporter), intent(inout) :: self
      character(len=*), intent(in) :: text

      if (associated(self%call)) call self%call(text//c_null_char, -1.0_c_double, self%user)
   end subroutine callback_note

   !> Whether the computation's progress function asked to stop (returned
   !> nonzero), or for a job the host did (friction_job_stop, job_lock.c).
   logical function callback_stop_requested(self)
      class(callback_reporter), intent(inout) :: self

      if (associated(self%ask)) then
         callback_stop_requested = self%stop
      else
         callback_stop_requested = friction_job_stop_asked() /= 0
      end if
   end function callback_stop_requested

end module friction_capi
