!> The C API (include/friction.h): bind(c) functions over the kernel for
!> callers that compute without files.  Every call returns a status (0 on
!> success, else one of the friction_error codes) and, when the caller passes
!> an error handle, fills it with the status and a message.  No module
!> variables: all context lives in the call's locals or in the caller's
!> handle, so threads may call the API at once.
module friction_capi
   use, intrinsic :: iso_c_binding, only: c_ptr, c_char, c_int, c_double, c_size_t, c_null_char, &
      & c_associated, c_f_pointer, c_loc, c_funptr, c_f_procpointer
   use mpi_f08, only: MPI_Initialized, MPI_Init_thread, MPI_THREAD_FUNNELED, MPI_COMM_WORLD
   use friction_kinds, only: wp
   use friction_error, only: error_type, fatal_error, error_input
   use friction_version, only: version_string
   use friction_ode_solver, only: step_type_index
   use friction_ode_auto, only: auto_name, auto_method
   use friction_surface_potential, only: surface_potential
   use friction_afm_config, only: afm_config, new_potential
   use friction_afm_scan, only: afm_scanner, trip_record, q_fx, q_fy
   use friction_brake_config, only: brake_config, model_names
   use friction_brake_simulate, only: brake_run
   use friction_strings, only: rtoa
   use friction_job, only: run_job, job_reporter
   use friction_scene_report, only: progress_text
   implicit none
   private

   public :: friction_version_c, friction_error_new, friction_error_free, friction_error_status, &
      & friction_error_message, friction_afm_line, friction_brake, friction_run_job

   !> What an opaque `friction_error *` points to.
   type :: capi_error
      integer :: status = 0
      character(len=:), allocatable :: message
   end type capi_error

   integer(c_int), parameter :: job_force = 1, job_resume = 2   !! friction_run_job flags

   !> A job's progress and notes through the caller's C function (if any):
   !> void report(const char *message, double fraction, void *user), with
   !> fraction in [0, 1] for progress and -1 for a note.
   type, extends(job_reporter) :: callback_reporter
      procedure(report_function), pointer, nopass :: call => null()
      type(c_ptr) :: user
   contains
      procedure :: progress => callback_progress
      procedure :: note => callback_note
   end type callback_reporter

   abstract interface
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
   end interface

contains

   !> Copy text into a caller buffer of len bytes, NUL-terminated; false if
   !> the buffer is null or too small (nothing written but a NUL then).
   function copy_out(text, buf, len) result(ok)
      character(len=*), intent(in) :: text
      type(c_ptr), intent(in) :: buf
      integer(c_size_t), intent(in) :: len
      logical :: ok
      character(kind=c_char), pointer :: out(:)
      integer :: i, n

      ok = .false.
      if (.not. c_associated(buf) .or. len < 1) return
      call c_f_pointer(buf, out, [len])
      n = min(len_trim(text), int(len) - 1)
      do i = 1, n
         out(i) = text(i:i)
      end do
      out(n + 1) = c_null_char
      ok = len_trim(text) < len
   end function copy_out

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
      call c_f_pointer(handle, err)
      err%status = status
      if (allocated(error)) then
         err%message = error%message
      else
         err%message = ''
      end if
   end function report

   !> int friction_version(char *buf, size_t len)
   integer(c_int) function friction_version_c(buf, len) bind(c, name='friction_version') result(status)
      type(c_ptr), value :: buf
      integer(c_size_t), value :: len

      status = 0
      if (.not. copy_out(version_string, buf, len)) status = error_input
   end function friction_version_c

   !> friction_error *friction_error_new(void)
   type(c_ptr) function friction_error_new() bind(c, name='friction_error_new') result(handle)
      type(capi_error), pointer :: err

      allocate (err)
      err%message = ''
      handle = c_loc(err)
   end function friction_error_new

   !> void friction_error_free(friction_error *err); null is ignored.
   subroutine friction_error_free(handle) bind(c, name='friction_error_free')
      type(c_ptr), value :: handle
      type(capi_error), pointer :: err

      if (.not. c_associated(handle)) return
      call c_f_pointer(handle, err)
      deallocate (err)
   end subroutine friction_error_free

   !> int friction_error_status(const friction_error *err); -1 for null.
   integer(c_int) function friction_error_status(handle) bind(c, name='friction_error_status') result(status)
      type(c_ptr), value :: handle
      type(capi_error), pointer :: err

      status = -1
      if (.not. c_associated(handle)) return
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
         copied = copy_out('', buf, len)   ! an empty message, still a failure
         return
      end if
      call c_f_pointer(handle, err)
      if (copy_out(err%message, buf, len)) status = 0
   end function friction_error_message

   !> Check a real is finite and above (or, when allow_zero, at least) zero.
   subroutine require(name, value, allow_zero, error)
      character(len=*), intent(in) :: name
      real(c_double), intent(in) :: value
      logical, intent(in) :: allow_zero
      type(error_type), allocatable, intent(inout) :: error

      if (allocated(error)) return
      if (.not. (abs(value) <= huge(value))) then
         call fatal_error(error, name//' must be finite', error_input)
      else if (allow_zero .and. value < 0.0_wp) then
         call fatal_error(error, name//' = '//rtoa(real(value, wp))//': must be >= 0', error_input)
      else if (.not. allow_zero .and. value <= 0.0_wp) then
         call fatal_error(error, name//' = '//rtoa(real(value, wp))//': must be > 0', error_input)
      end if
   end subroutine require

   !> One AFM scan line: the lateral force fx, fy (nN) at nx support positions
   !> from (x0, y0) along angle (degrees) over length (Å), forward (trace) or
   !> backward (retrace, still stored by position).  Units as the namelist:
   !> V0 eV, lattice Å, mass kg, k N/m, c N s/m, velocity Å/s.
   integer(c_int) function friction_afm_line(potential, v0, ax, ay, a, mass, kx, ky, cx, cy, velocity, &
      & x0, y0, angle, length, nx, forward, stepper, rtol, atol, fx, fy, handle) &
      & bind(c, name='friction_afm_line') result(status)
      type(c_ptr), value :: potential, stepper, fx, fy, handle
      real(c_double), value :: v0, ax, ay, a, mass, kx, ky, cx, cy, velocity, x0, y0, angle, length, &
         & rtol, atol
      integer(c_int), value :: nx, forward
      type(error_type), allocatable :: error
      type(afm_config) :: config
      class(surface_potential), allocatable :: surface
      type(afm_scanner) :: scanner
      type(trip_record) :: record
      real(c_double), pointer :: fx_out(:), fy_out(:)
      character(len=:), allocatable :: name, method

      name = c_string(potential)
      method = c_string(stepper)
      if (method == auto_name) method = auto_method('afm', name, real(rtol, wp))
      if (.not. c_associated(potential)) then
         call fatal_error(error, 'potential name is a null pointer', error_input)
      else if (.not. c_associated(stepper)) then
         call fatal_error(error, 'stepper name is a null pointer', error_input)
      else if (.not. (c_associated(fx) .and. c_associated(fy))) then
         call fatal_error(error, 'fx and fy must not be null', error_input)
      else if (name /= 'naf' .and. name /= 'hopg') then
         call fatal_error(error, "unknown potential '"//name//"': expected 'naf' or 'hopg'", error_input)
      else if (len(method) > len(config%solver%method) .or. step_type_index(method) == 0) then
         call fatal_error(error, "unknown stepper '"//method//"'", error_input)
      else if (nx < 2) then
         call fatal_error(error, 'nx must be >= 2', error_input)
      end if
      call require('V0', v0, .true., error)
      if (name == 'naf') then
         call require('ax', ax, .false., error)
         call require('ay', ay, .false., error)
      else
         call require('a', a, .false., error)
      end if
      call require('mass', mass, .false., error)
      call require('kx', kx, .true., error)
      call require('ky', ky, .true., error)
      call require('cx', cx, .true., error)
      call require('cy', cy, .true., error)
      call require('velocity', velocity, .false., error)
      call require('length', length, .false., error)
      call require('rtol', rtol, .false., error)
      call require('atol', atol, .false., error)
      if (.not. allocated(error) .and. .not. (abs(x0) <= huge(x0) .and. abs(y0) <= huge(y0) &
         & .and. abs(angle) <= huge(angle))) call fatal_error(error, 'x0, y0 and angle must be finite', error_input)
      if (allocated(error)) then
         status = report(handle, error)
         return
      end if

      config%potential = name
      config%v0 = v0
      config%ax = ax
      config%ay = ay
      config%a = a
      config%mass = mass
      config%kx = kx
      config%ky = ky
      config%cx = cx
      config%cy = cy
      config%velocity = velocity
      config%origin_x = x0
      config%origin_y = y0
      config%angle = angle
      config%length = length
      config%width = 0.0_wp
      config%lead_in = 0.0_wp
      config%nx = nx
      config%ny = 1
      config%solver%method = method
      config%solver%rtol = rtol
      config%solver%atol = atol

      call new_potential(config, surface, error)
      if (.not. allocated(error)) call scanner%init(config, surface, error)
      if (.not. allocated(error)) call scanner%run_trip(0, forward /= 0, record, error)
      if (.not. allocated(error)) then
         call c_f_pointer(fx, fx_out, [nx])
         call c_f_pointer(fy, fy_out, [nx])
         fx_out = record%values(:, q_fx)
         fy_out = record%values(:, q_fy)
      end if
      status = report(handle, error)
   end function friction_afm_line

   !> The brake (Eq. 10, nondimensional parameters) from the state of §4.1
   !> on the grid 0, dt_out, ..., t_end (τ) into t, x, v, y, w of length n.
   !> If n is too small, *needed gets the length and the status is an
   !> input error; needed may be null.
   integer(c_int) function friction_brake(model, xi, kappa, g_prime, mu, mu_s, epsilon_prime, delta_prime, &
      & v_dr, t_end, dt_out, stepper, rtol, atol, t, x, v, y, w, n, needed, handle) &
      & bind(c, name='friction_brake') result(status)
      type(c_ptr), value :: model, stepper, t, x, v, y, w, needed, handle
      real(c_double), value :: xi, kappa, g_prime, mu, mu_s, epsilon_prime, delta_prime, v_dr, t_end, &
         & dt_out, rtol, atol
      integer(c_size_t), value :: n
      type(error_type), allocatable :: error
      type(brake_config) :: config
      type(brake_run), target :: run
      character(len=:), allocatable :: name, method
      integer(c_size_t), pointer :: needed_out
      real(c_double), pointer :: out(:)
      integer :: points

      name = c_string(model)
      method = c_string(stepper)
      if (method == auto_name) method = auto_method('brake', name, real(rtol, wp))
      if (.not. c_associated(model)) then
         call fatal_error(error, 'model name is a null pointer', error_input)
      else if (.not. c_associated(stepper)) then
         call fatal_error(error, 'stepper name is a null pointer', error_input)
      else if (.not. any(name == model_names)) then
         call fatal_error(error, "unknown model '"//name//"': expected 'switched' or 'regularized'", error_input)
      else if (len(method) > len(config%solver%method) .or. step_type_index(method) == 0) then
         call fatal_error(error, "unknown stepper '"//method//"'", error_input)
      end if
      call require('xi', xi, .false., error)
      call require('kappa', kappa, .false., error)
      call require('mu', mu, .true., error)
      call require('mu_s', mu_s, .true., error)
      ! As the namelist: epsilon' matters only to the regularized model.
      if (name == 'regularized') call require('epsilon_prime', epsilon_prime, .false., error)
      call require('delta_prime', delta_prime, .true., error)
      call require('t_end', t_end, .false., error)
      call require('dt_out', dt_out, .false., error)
      call require('rtol', rtol, .false., error)
      call require('atol', atol, .false., error)
      if (.not. allocated(error) .and. .not. (abs(v_dr) <= huge(v_dr) .and. abs(g_prime) <= huge(g_prime) &
         & .and. abs(epsilon_prime) <= huge(epsilon_prime))) &
         & call fatal_error(error, 'v_dr, g_prime and epsilon_prime must be finite', error_input)
      ! The switched model's stick/slip decision needs mu <= mu_s (as the namelist).
      if (.not. allocated(error) .and. name == 'switched' .and. mu_s < mu) &
         & call fatal_error(error, 'mu_s = '//rtoa(real(mu_s, wp))//': must be >= mu = '//rtoa(real(mu, wp)) &
         & //' for the switched model', error_input)
      if (.not. allocated(error) .and. t_end / dt_out > 1.0e9_wp) &
         & call fatal_error(error, 't_end / dt_out is too large (> 1e9 points)', error_input)
      if (allocated(error)) then
         status = report(handle, error)
         return
      end if

      config%model = name
      config%params%xi = xi
      config%params%kappa = kappa
      config%params%g_prime = g_prime
      config%params%mu = mu
      config%params%mu_s = mu_s
      config%params%epsilon_prime = epsilon_prime
      config%params%delta_prime = delta_prime
      config%params%v_dr = v_dr
      config%t_start = 0.0_wp
      config%t_end = t_end
      config%dt_out = dt_out
      config%solver%method = method
      config%solver%rtol = rtol
      config%solver%atol = atol
      points = config%grid_size()
      if (c_associated(needed)) then
         call c_f_pointer(needed, needed_out)
         needed_out = int(points, c_size_t)
      end if
      if (n < points) then
         call fatal_error(error, 'arrays of length '//itoa(int(n))//' are too small: '//itoa(points) &
            & //' points needed', error_input)
      else if (.not. (c_associated(t) .and. c_associated(x) .and. c_associated(v) .and. c_associated(y) &
         & .and. c_associated(w))) then
         call fatal_error(error, 't, x, v, y and w must not be null', error_input)
      end if
      if (.not. allocated(error)) call run%init(config, error)
      if (.not. allocated(error)) call run%run_until(points, error)
      if (.not. allocated(error)) then
         call c_f_pointer(t, out, [points])
         out = run%trajectory%t(1:points)
         call c_f_pointer(x, out, [points])
         out = run%trajectory%x(1:points)
         call c_f_pointer(v, out, [points])
         out = run%trajectory%v(1:points)
         call c_f_pointer(y, out, [points])
         out = run%trajectory%y(1:points)
         call c_f_pointer(w, out, [points])
         out = run%trajectory%w(1:points)
      end if
      status = report(handle, error)
   end function friction_brake

   !> int friction_run_job(const char *const *files, int nfiles, const char *output, int flags,
   !>                      friction_report_fn report, void *user, friction_error *err)
   !> The command line's job: namelist files in, an HDF5 file out.  Collective
   !> over MPI_COMM_WORLD when the caller has initialised MPI; otherwise MPI
   !> is initialised here (once, left for the process's exit) and the job runs
   !> on this process alone.
   integer(c_int) function friction_run_job(files, nfiles, output, flags, report_fn, user, handle) &
      & bind(c, name='friction_run_job') result(status)
      type(c_ptr), value :: files, output, user, handle
      integer(c_int), value :: nfiles, flags
      type(c_funptr), value :: report_fn
      type(error_type), allocatable :: error
      type(c_ptr), pointer :: names(:)
      character(len=4096), allocatable :: paths(:)
      character(len=:), allocatable :: summary, path
      type(callback_reporter) :: reporter
      logical :: ready
      integer :: k, provided

      allocate (paths(0))
      if (.not. c_associated(files) .and. nfiles /= 0) then
         call fatal_error(error, 'files is a null pointer', error_input)
      else if (nfiles < 1) then
         call fatal_error(error, 'nfiles = '//itoa(int(nfiles))//': give at least one namelist file', error_input)
      else if (.not. c_associated(output)) then
         call fatal_error(error, 'output is a null pointer', error_input)
      else if (iand(flags, not(job_force + job_resume)) /= 0) then
         call fatal_error(error, 'flags = '//itoa(int(flags))//': unknown bits (known: FRICTION_JOB_FORCE, ' &
            & //'FRICTION_JOB_RESUME)', error_input)
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
      if (allocated(error)) then
         status = report(handle, error)
         return
      end if
      call MPI_Initialized(ready)
      if (.not. ready) call MPI_Init_thread(MPI_THREAD_FUNNELED, provided)
      reporter%user = user
      if (c_associated(report_fn)) call c_f_procpointer(report_fn, reporter%call)
      call run_job(paths, c_string(output), iand(flags, job_force) /= 0, iand(flags, job_resume) /= 0, &
         & MPI_COMM_WORLD, reporter, summary, error)
      status = report(handle, error)
   end function friction_run_job

   subroutine callback_progress(self, done, total, what, last)
      class(callback_reporter), intent(inout) :: self
      real(wp), intent(in) :: done, total
      character(len=*), intent(in) :: what
      logical, intent(in) :: last
      character(len=120) :: text

      if (.not. associated(self%call)) return
      text = progress_text(done, total, what)
      call self%call(trim(text)//c_null_char, real(max(0.0_wp, min(1.0_wp, done / max(total, tiny(total)))), &
         & c_double), self%user)
   end subroutine callback_progress

   subroutine callback_note(self, text)
      class(callback_reporter), intent(inout) :: self
      character(len=*), intent(in) :: text

      if (associated(self%call)) call self%call(text//c_null_char, -1.0_c_double, self%user)
   end subroutine callback_note

   pure function itoa(i) result(text)
      integer, intent(in) :: i
      character(len=:), allocatable :: text
      character(len=12) :: buffer

      write (buffer, '(i0)') i
      text = trim(buffer)
   end function itoa

end module friction_capi
