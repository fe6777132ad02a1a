!> The C API's friction laws (include/friction.h, "friction laws"): a law's
!> handle, made from its name with the &law defaults, changed by name
!> ("law.sigma0", "integrator.rtol") through the same description of the
!> variables and checked by the law's own checks; and the law along a
!> prescribed velocity or displacement history into the caller's arrays
!> (friction_law_history).  No module variables: the state lives in the
!> handles, which the table of live handles (handles.c) records as the
!> configurations: a law freed twice, or used after its free, is refused.
module friction_capi_law
   use, intrinsic :: iso_c_binding, only: c_ptr, c_int, c_double, c_size_t, c_associated, c_f_pointer, c_loc, &
      & c_null_ptr
   use friction_kinds, only: wp
   use friction_error, only: error_type, fatal_error, error_input
   use friction_strings, only: itoa, rtoa, join
   use friction_parameters, only: configurable, parameter_visitor, parameter_info, list_parameters, get_parameter
   use friction_checks, only: config_checker
   use friction_input_reader, only: parse_variable_name
   use friction_ode_solver, only: solver_settings
   use friction_ode_settings, only: visit_integrator, check_integrator
   use friction_law, only: sliding_law
   use friction_law_settings, only: law_settings
   use friction_law_factory, only: new_law, check_law, make_law, law_names
   use friction_output_law_files, only: law_with_files
   use friction_law_history, only: law_history, history_velocity, history_displacement, history_solver_defaults
   use friction_capi_text, only: c_string, copy_text
   use friction_capi_handles, only: report, refuse, kind_law, friction_handle_add, friction_handle_remove, &
      & friction_handle_live
   use friction_capi_config, only: set_checked_text, set_checked_number
   implicit none
   private

   public :: friction_law_new, friction_law_free, friction_law_set, friction_law_set_real, friction_law_get, &
      & friction_law_check, friction_law_state_count, friction_law_history

   !> What an opaque `friction_law *` points to: &law and the &integrator of
   !> its states' integration.
   type, extends(configurable) :: capi_law
      type(law_settings) :: p
      type(solver_settings) :: solver = history_solver_defaults
   contains
      procedure :: visit => capi_law_visit
   end type capi_law

contains

   subroutine capi_law_visit(self, v)
      class(capi_law), intent(inout) :: self
      type(parameter_visitor), intent(inout) :: v

      call self%p%visit(v)
      call visit_integrator(self%solver, v, 's')
   end subroutine capi_law_visit

   logical function law_of(handle, law, error) result(ok)
      type(c_ptr), intent(in) :: handle
      type(capi_law), pointer, intent(out) :: law
      type(error_type), allocatable, intent(out) :: error

      ok = c_associated(handle)
      nullify (law)
      if (.not. ok) then
         call fatal_error(error, 'the law handle is a null pointer', error_input)
         return
      end if
      ok = friction_handle_live(handle, kind_law) /= 0
      if (.not. ok) then
         call fatal_error(error, 'the law handle is not live (freed already, or not from friction_law_new)', &
            & error_input)
         return
      end if
      call c_f_pointer(handle, law)
   end function law_of

   !> "law.sigma0" into its group, name and element; an unknown one is an error.
   subroutine resolve(law, full, group, name, first, info, error)
      type(capi_law), intent(inout) :: law
      character(len=*), intent(in) :: full
      character(len=:), allocatable, intent(out) :: group, name
      integer, intent(out) :: first
      type(parameter_info), intent(out) :: info
      type(error_type), allocatable, intent(out) :: error
      type(parameter_info), allocatable :: mine(:)
      integer :: k

      mine = list_parameters(law)
      call parse_variable_name(full, ['law       ', 'integrator'], group, name, first, error)
      if (allocated(error)) return
      do k = 1, size(mine)
         if (mine(k)%group == group .and. mine(k)%name == name) then
            info = mine(k)
            return
         end if
      end do
      call fatal_error(error, '&'//group//": unknown variable '"//name//"' (known: " &
         & //join(pack(mine%name, mine%group == group))//')', error_input)
   end subroutine resolve

   !> friction_law *friction_law_new(const char *model, friction_error *err):
   !> the law of that name with the &law defaults; NULL on an unknown name.
   type(c_ptr) function friction_law_new(model_c, handle) bind(c, name='friction_law_new_body') result(res)
      type(c_ptr), value :: model_c, handle
      type(capi_law), pointer :: law
      class(sliding_law), allocatable :: probe
      type(law_settings) :: p
      integer(c_int) :: status

      res = c_null_ptr
      if (.not. c_associated(model_c)) then
         status = refuse(handle, 'model must not be a null pointer')
         return
      end if
      p%model = c_string(model_c)
      call new_law(p, probe)
      if (.not. allocated(probe) .or. len(c_string(model_c)) > len(p%model)) then
         status = refuse(handle, "unknown friction law '"//c_string(model_c)//"' (known: "//join(law_names)//')')
         return
      end if
      allocate (law)
      law%p = p
      res = c_loc(law)
      if (friction_handle_add(res, kind_law) == 0) then
         deallocate (law)
         res = c_null_ptr
         status = refuse(handle, 'out of memory for a new law handle')
         return
      end if
      block
         type(error_type), allocatable :: none
         status = report(handle, none)
      end block
   end function friction_law_new

   !> void friction_law_free(friction_law *law); NULL is ignored.
   subroutine friction_law_free(handle) bind(c, name='friction_law_free')
      type(c_ptr), value :: handle
      type(capi_law), pointer :: law

      if (.not. c_associated(handle)) return
      if (friction_handle_remove(handle, kind_law) == 0) return   ! freed already, or not a law
      call c_f_pointer(handle, law)
      deallocate (law)
   end subroutine friction_law_free

   !> int friction_law_set(friction_law *law, const char *name, const char *value, friction_error *err)
   integer(c_int) function friction_law_set(handle, name_c, value_c, err) bind(c, name='friction_law_set_body') &
      & result(status)
      type(c_ptr), value :: handle, name_c, value_c, err
      type(capi_law), pointer :: law
      type(capi_law) :: work
      type(error_type), allocatable :: error
      type(parameter_info) :: info
      character(len=:), allocatable :: group, name, value
      integer :: first

      if (.not. law_of(handle, law, error)) then
         status = report(err, error)
         return
      end if
      if (.not. c_associated(name_c) .or. .not. c_associated(value_c)) then
         status = refuse(err, 'name and value must not be null pointers')
         return
      end if
      value = c_string(value_c)
      work = law   ! a value refused changes nothing
      call resolve(work, c_string(name_c), group, name, first, info, error)
      if (.not. allocated(error)) call set_checked_text(work, group, name, first, info, value, error)
      if (.not. allocated(error)) law = work
      status = report(err, error)
   end function friction_law_set

   !> int friction_law_set_real(friction_law *law, const char *name, double x, friction_error *err)
   integer(c_int) function friction_law_set_real(handle, name_c, x, err) bind(c, name='friction_law_set_real_body') &
      & result(status)
      type(c_ptr), value :: handle, name_c, err
      real(c_double), value :: x
      type(capi_law), pointer :: law
      type(capi_law) :: work
      type(error_type), allocatable :: error
      type(parameter_info) :: info
      character(len=:), allocatable :: group, name
      integer :: first

      if (.not. law_of(handle, law, error)) then
         status = report(err, error)
         return
      end if
      if (.not. c_associated(name_c)) then
         status = refuse(err, 'name must not be a null pointer')
         return
      end if
      work = law
      call resolve(work, c_string(name_c), group, name, first, info, error)
      if (.not. allocated(error)) call set_checked_number(work, group, name, first, real(x, wp), error)
      if (.not. allocated(error)) law = work
      status = report(err, error)
   end function friction_law_set_real

   !> int friction_law_get(const friction_law *law, const char *name, char *buf, size_t len, friction_error *err)
   integer(c_int) function friction_law_get(handle, name_c, buf, buf_len, err) bind(c, name='friction_law_get_body') &
      & result(status)
      type(c_ptr), value :: handle, name_c, buf, err
      integer(c_size_t), value :: buf_len
      type(capi_law), pointer :: law
      type(capi_law) :: work
      type(error_type), allocatable :: error
      type(parameter_info) :: info
      character(len=:), allocatable :: group, name, text, problem
      integer :: first

      if (.not. law_of(handle, law, error)) then
         status = report(err, error)
         return
      end if
      if (.not. c_associated(name_c)) then
         status = refuse(err, 'name must not be a null pointer')
         return
      end if
      work = law
      call resolve(work, c_string(name_c), group, name, first, info, error)
      if (.not. allocated(error)) then
         call get_parameter(work, group, name, first, text, problem)
         if (len(problem) > 0) then
            call fatal_error(error, '&'//group//': '//name//': '//problem, error_input)
         else if (.not. copy_text(text, buf, buf_len)) then
            call fatal_error(error, 'a buffer of '//itoa(int(buf_len))//' bytes is too small for the value of ' &
               & //group//'.'//name//': '//itoa(len(text) + 1)//' bytes needed', error_input)
         end if
      end if
      status = report(err, error)
   end function friction_law_get

   !> The law's checks and the integrator's; the first bad value.  Every
   !> value was set in memory, by name: no file to name in the message.
   subroutine check_all(law, error)
      type(capi_law), intent(in) :: law
      type(error_type), allocatable, intent(out) :: error
      type(config_checker) :: c
      type(capi_law) :: copy
      type(parameter_info), allocatable :: listed(:)
      integer :: k

      copy = law
      listed = list_parameters(copy)
      do k = 1, size(listed)
         call c%set_origin(listed(k)%group, listed(k)%name, '')
      end do
      call check_law(law_with_files(law%p), c)
      if (.not. c%failed()) call check_integrator(law%solver, c)
      if (c%failed()) call move_alloc(c%error, error)
   end subroutine check_all

   !> int friction_law_check(const friction_law *law, friction_error *err)
   integer(c_int) function friction_law_check(handle, err) bind(c, name='friction_law_check_body') result(status)
      type(c_ptr), value :: handle, err
      type(capi_law), pointer :: law
      type(error_type), allocatable :: error

      if (law_of(handle, law, error)) call check_all(law, error)
      status = report(err, error)
   end function friction_law_check

   !> int friction_law_state_count(const friction_law *law, friction_error *err):
   !> the number of internal states, or -1 (and a message) on an error.
   integer(c_int) function friction_law_state_count(handle, err) bind(c, name='friction_law_state_count') &
      & result(count)
      type(c_ptr), value :: handle, err
      type(capi_law), pointer :: law
      type(error_type), allocatable :: error
      class(sliding_law), allocatable :: made
      integer(c_int) :: status

      count = -1
      if (law_of(handle, law, error)) then
         call new_law(law%p, made)
         if (allocated(made)) count = int(made%state_count(), c_int)
         if (.not. allocated(made)) call fatal_error(error, "unknown friction law '"//trim(law%p%model)//"'", &
            & error_input)
      end if
      status = report(err, error)
   end function friction_law_state_count

   !> int friction_law_history(const friction_law *law, double normal, const double *t,
   !>     const double *u, size_t n, int displacement, double *force, double *states,
   !>     size_t states_len, friction_error *err)
   integer(c_int) function friction_law_history(handle, normal, t_c, u_c, n, displacement, force_c, states_c, &
      & states_len, err) bind(c, name='friction_law_history_body') result(status)
      type(c_ptr), value :: handle, t_c, u_c, force_c, states_c, err
      real(c_double), value :: normal
      integer(c_size_t), value :: n, states_len
      integer(c_int), value :: displacement
      type(capi_law), pointer :: law
      type(error_type), allocatable :: error
      class(sliding_law), allocatable :: made
      real(c_double), pointer :: t(:), u(:), force(:), states_out(:)
      real(wp), allocatable :: states(:, :)
      integer :: m, i

      if (.not. law_of(handle, law, error)) then
         status = report(err, error)
         return
      end if
      if (n < 1 .or. .not. c_associated(t_c) .or. .not. c_associated(u_c) .or. .not. c_associated(force_c)) then
         status = refuse(err, 't, u and force must not be null pointers, and n must be at least 1')
         return
      end if
      if (displacement /= 0 .and. displacement /= 1) then
         status = refuse(err, 'displacement = '//itoa(int(displacement))//': 0 (u is a velocity history, m/s) ' &
            & //'or 1 (a displacement history, m)')
         return
      end if
      ! (>= 0 as &machine normal: a negative load turned the coefficient laws' force against the motion.)
      if (.not. (normal >= 0.0_c_double .and. normal <= huge(normal))) then
         status = refuse(err, 'normal = '//rtoa(real(normal, wp))//': must be a finite number >= 0 (N)')
         return
      end if
      call check_all(law, error)
      if (.not. allocated(error)) call make_law(law_with_files(law%p), made, error)
      if (allocated(error)) then
         status = report(err, error)
         return
      end if
      m = made%state_count()
      if (c_associated(states_c) .and. states_len < n * int(m, c_size_t)) then
         status = refuse(err, 'states_len = '//itoa(int(states_len))//': the states need n x '//itoa(m)//' = ' &
            & //itoa(int(n) * m)//' values')
         return
      end if
      call c_f_pointer(t_c, t, [n])
      call c_f_pointer(u_c, u, [n])
      call c_f_pointer(force_c, force, [n])
      allocate (states(max(m, 1), n))
      call law_history(made, real(normal, wp), t, u, merge(history_displacement, history_velocity, displacement == 1), &
         & law%solver, force, states, error)
      if (.not. allocated(error) .and. c_associated(states_c) .and. m > 0) then
         call c_f_pointer(states_c, states_out, [n * int(m, c_size_t)])
         do i = 1, int(n)
            states_out((i - 1) * m + 1:i * m) = states(1:m, i)
         end do
      end if
      status = report(err, error)
   end function friction_law_history

end module friction_capi_law
