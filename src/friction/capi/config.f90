!> The C API's configurations: a job's configuration (&job, the scene's
!> groups, &sweep) changed by namelist files or by name ("tip.kx"), through
!> the same description of the variables (core/parameters.f90) and the same
!> checks (the scene's own) as the program's input; read back by name, as
!> namelist text and as the list of its variables.
module friction_capi_config
   use, intrinsic :: iso_c_binding, only: c_ptr, c_int, c_double, c_size_t, c_associated, c_f_pointer
   use friction_kinds, only: wp
   use friction_error, only: error_type, fatal_error, error_input
   use friction_strings, only: itoa, rtoa, join
   use friction_parameters, only: configurable, parameter_info, list_parameters, set_parameter, &
      & set_parameter_number, get_parameter, kind_text, value_has_kind, unit_hint
   use friction_checks, only: config_checker
   use friction_input_reader, only: namelist_source, scan_files, apply_files, parse_variable_name
   use friction_job_config, only: job_config, check_job, job_text, all_parameters, parameter_groups, not_in_scene, &
      & warn_units
   use friction_capi_text, only: c_string, copy_text, len_text, text_status, element_name
   use friction_capi_handles, only: capi_config, kind_config, friction_handle_live, report, refuse, config_of
   implicit none
   private

   public :: friction_config_set, friction_config_set_real, friction_config_get, friction_config_text, &
      & friction_config_names, friction_config_read, friction_config_check, friction_config_warnings
   !> For the C API's other files: the checks, the setting of a checked
   !> value (the laws' too), and the message of a forked process.
   public :: check_config, set_checked_text, set_checked_number, forked_message

   interface
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

   !> The start of every call on one variable: the live configuration of
   !> cfg, a copy of its job (work: a value refused changes nothing) and the
   !> variable name_c names in the copy.  False when the handle, a pointer
   !> (value_c too, when given) or the name is wrong, its error reported
   !> through handle into status.
   logical function variable_of(cfg, name_c, handle, config, work, full, group, name, first, info, status, &
      & value_c) result(ok)
      type(c_ptr), intent(in) :: cfg, name_c, handle
      type(capi_config), pointer, intent(out) :: config
      type(job_config), intent(out) :: work
      character(len=:), allocatable, intent(out) :: full, group, name
      integer, intent(out) :: first
      type(parameter_info), intent(out) :: info
      integer(c_int), intent(out) :: status
      type(c_ptr), intent(in), optional :: value_c
      type(error_type), allocatable :: error

      ok = .false.
      status = 0
      if (.not. config_of(cfg, config, error)) then
         status = report(handle, error)
      else if (present(value_c) .and. (.not. c_associated(name_c) .or. .not. c_associated(value_c))) then
         status = refuse(handle, 'name and value must not be null pointers')
      else if (.not. c_associated(name_c)) then
         status = refuse(handle, 'name must not be a null pointer')
      else
         full = c_string(name_c)
         work = config%job
         call resolve_name(work, full, group, name, first, info, error)
         if (allocated(error)) then
            status = report(handle, error)
         else
            ok = .true.
         end if
      end if
   end function variable_of

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

      if (.not. variable_of(cfg, name_c, handle, config, work, full, group, name, first, info, status, value_c)) &
         & return
      value = c_string(value_c)
      call set_checked_text(work, group, name, first, info, value, error)
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

      if (.not. variable_of(cfg, name_c, handle, config, work, full, group, name, first, info, status)) return
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

      ! (work: visiting writes each value back, and a copy leaves the handle untouched)
      if (.not. variable_of(cfg, name_c, handle, config, work, full, group, name, first, info, status)) return
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

   !> int friction_config_warnings(const friction_config *cfg, char *buf, size_t len, size_t *needed):
   !> the warnings the program's input would give for these values, one a
   !> line (the library prints nothing: the host shows them).  None when the
   !> checks refuse the configuration (friction_config_check says why).
   integer(c_int) function friction_config_warnings(cfg, buf, len, needed) &
      & bind(c, name='friction_config_warnings_body') result(status)
      type(c_ptr), value :: cfg, buf, needed
      integer(c_size_t), value :: len
      type(capi_config), pointer :: config
      type(job_config) :: work
      type(config_checker) :: checker
      character(len=:), allocatable :: text
      integer :: k
      integer(c_int) :: taken

      status = error_input
      if (.not. c_associated(cfg)) return
      if (friction_handle_live(cfg, kind_config) == 0) return
      call c_f_pointer(cfg, config)
      work = config%job
      checker = config%origins
      ! (The numbers are formatted by internal writes: under the read lock, as friction_config_text.)
      taken = friction_read_begin()
      if (taken < 0) return   ! (a process forked mid-job: job_lock.c)
      call check_job(work, checker)
      text = ''
      if (.not. checker%failed()) then
         call warn_units(work, checker)
         if (allocated(checker%warnings)) then
            do k = 1, size(checker%warnings)
               text = text//trim(checker%warnings(k))//new_line('a')
            end do
         end if
      end if
      if (taken /= 0) call friction_read_end()
      status = text_status(text, buf, len, needed)
   end function friction_config_warnings

end module friction_capi_config
