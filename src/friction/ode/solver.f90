!> Bridge to GSL's odeiv2 driver through ISO_C_BINDING.
!>
!> Every GSL step type is selectable by name; the implicit ones receive the
!> system's analytic Jacobian.  The names and types are the C shim's table
!> (gsl_shim.c), the only list of them.  Every call into GSL goes through
!> the shim, which keeps GSL's abort-on-error handler out of the way for
!> that call only and gives the program's handler back afterwards; every
!> failure (GSL status, an error GSL reported, too many steps, step size
!> below the minimum, NaN or Inf in the state) comes back as an error that
!> carries the time reached.
module friction_ode_solver
   use, intrinsic :: iso_c_binding, only: c_int, c_double, c_long, c_size_t, c_ptr, c_funptr, &
      & c_null_ptr, c_associated, c_loc, c_funloc, c_f_pointer, c_char, c_null_char
   use friction_kinds, only: wp, i8
   use friction_error, only: error_type, fatal_error, error_numerical, error_input, error_internal
   use friction_ode_system, only: ode_system
   use friction_ode_watch, only: step_watch
   use friction_strings, only: itoa, rtoa, etoa
   implicit none
   private

   public :: ode_solver, solver_settings, integrator_statistics
   public :: step_type_names, step_type_index, is_implicit_step_type, step_type_name_length

   !> Room for a step type name (as solver_settings%method).
   integer, parameter :: step_type_name_length = 16

   !> GSL status codes used here (gsl_errno.h).
   integer(c_int), parameter :: gsl_success = 0, gsl_enomem = 8, gsl_ebadfunc = 9

   !> What the user chooses about the integration.
   type :: solver_settings
      character(len=16) :: method = 'rkf45'  !! GSL step type name
      real(wp) :: rtol = 1.0e-3_wp     !! relative tolerance
      real(wp) :: atol = 1.0e-4_wp     !! absolute tolerance, in the state's units
      real(wp) :: h_start = 0.0_wp     !! first step; 0 lets the caller choose
      real(wp) :: h_min = 0.0_wp       !! smallest step allowed; 0 for no limit
      integer(i8) :: max_steps = 10000000_i8  !! per restart (per scan trip)
      real(wp) :: max_wall_time = 0.0_wp  !! s; 0 for no limit (honoured by step-by-step callers)
   end type solver_settings

   !> Cost counters, summed over restarts.
   type :: integrator_statistics
      integer(i8) :: steps = 0             !! accepted steps
      integer(i8) :: failed_steps = 0      !! rejected steps
      integer(i8) :: rhs_evaluations = 0   !! right-hand-side calls
      integer(i8) :: jacobian_evaluations = 0
   contains
      procedure :: add => statistics_add
   end type integrator_statistics

   !> Mirror of gsl_odeiv2_system.
   type, bind(c) :: gsl_odeiv2_system
      type(c_funptr) :: function
      type(c_funptr) :: jacobian
      integer(c_size_t) :: dimension
      type(c_ptr) :: params
   end type gsl_odeiv2_system

   !> What the C callbacks receive as params: the model, the counters and the
   !> Jacobian's room (allocated with the driver: no system size is too
   !> large, and the callback allocates nothing).
   type :: system_box
      class(ode_system), pointer :: model => null()
      integer :: n = 0
      integer(i8) :: rhs_evaluations = 0
      integer(i8) :: jacobian_evaluations = 0
      real(wp), allocatable :: jac(:, :), ft(:)
   end type system_box

   !> A GSL driver bound to one system.  The system must outlive the solver.
   type :: ode_solver
      private
      type(c_ptr) :: driver = c_null_ptr
      type(gsl_odeiv2_system), pointer :: sys => null()
      type(system_box), pointer :: box => null()
      integer(i8) :: max_steps = 0
      real(wp) :: h_min = 0.0_wp
      character(len=16) :: method = ''
      !> what the driver was made for (init reuses a driver made for the same)
      integer :: step_index = 0, controlled = 0, relative = 0
      real(wp) :: atol = 0.0_wp, rtol = 0.0_wp, reference = 0.0_wp, floor = 0.0_wp
      !> how messages name the time and its unit (the brake runs in nondimensional τ)
      character(len=8) :: time_name = 't', time_unit = ' s'
      !> counters of the finished restarts
      type(integrator_statistics) :: done
      !> a restart GSL refused, not yet reported (restart without error)
      character(len=:), allocatable :: failed_restart
   contains
      procedure :: init
      procedure :: restart
      procedure, private :: report_failed_restart
      procedure :: advance
      procedure :: step
      procedure :: step_size
      procedure :: has_dense_output
      procedure :: dense_output
      procedure :: set_time_label
      procedure :: time_at
      procedure :: statistics
      procedure :: destroy
      final :: finalize
   end type ode_solver

   interface
      pure function friction_gsl_step_type_count() result(n) bind(c, name='friction_gsl_step_type_count')
         import :: c_int
         integer(c_int) :: n
      end function friction_gsl_step_type_count

      pure subroutine friction_gsl_step_type_name_copy(index, buffer, length) &
         & bind(c, name='friction_gsl_step_type_name_copy')
         import :: c_int, c_char, c_size_t
         integer(c_int), value :: index
         character(kind=c_char), intent(inout) :: buffer(*)
         integer(c_size_t), value :: length
      end subroutine friction_gsl_step_type_name_copy

      pure function friction_gsl_step_type_index(name, length) result(index) &
         & bind(c, name='friction_gsl_step_type_index')
         import :: c_int, c_char, c_size_t
         character(kind=c_char), intent(in) :: name(*)
         integer(c_size_t), value :: length
         integer(c_int) :: index
      end function friction_gsl_step_type_index

      pure function friction_gsl_step_type_uses_jacobian(index) result(uses) &
         & bind(c, name='friction_gsl_step_type_uses_jacobian')
         import :: c_int
         integer(c_int), value :: index
         integer(c_int) :: uses
      end function friction_gsl_step_type_uses_jacobian

      function friction_gsl_driver_new(driver, sys, index, hstart, epsabs, epsrel, controlled, relative, &
         & reference, floor) result(status) bind(c, name='friction_gsl_driver_new')
         import :: c_ptr, c_int, c_double
         type(c_ptr), intent(out) :: driver
         type(c_ptr), value :: sys
         integer(c_int), value :: index
         real(c_double), value :: hstart, epsabs, epsrel
         integer(c_int), value :: controlled, relative
         real(c_double), value :: reference, floor
         integer(c_int) :: status
      end function friction_gsl_driver_new

      function friction_gsl_driver_set_limits(driver, nmax, hmin) result(status) &
         & bind(c, name='friction_gsl_driver_set_limits')
         import :: c_ptr, c_long, c_double, c_int
         type(c_ptr), value :: driver
         integer(c_long), value :: nmax
         real(c_double), value :: hmin
         integer(c_int) :: status
      end function friction_gsl_driver_set_limits

      function friction_gsl_driver_reset(driver, hstart) result(status) &
         & bind(c, name='friction_gsl_driver_reset')
         import :: c_ptr, c_double, c_int
         type(c_ptr), value :: driver
         real(c_double), value :: hstart
         integer(c_int) :: status
      end function friction_gsl_driver_reset

      function friction_gsl_driver_apply(driver, t, t1, y) result(status) &
         & bind(c, name='friction_gsl_driver_apply')
         import :: c_ptr, c_double, c_int
         type(c_ptr), value :: driver
         real(c_double), intent(inout) :: t
         real(c_double), value :: t1
         real(c_double), intent(inout) :: y(*)
         integer(c_int) :: status
      end function friction_gsl_driver_apply

      function friction_gsl_driver_apply_part(driver, t, t1, y, steps, first, done) result(status) &
         & bind(c, name='friction_gsl_driver_apply_part')
         import :: c_ptr, c_int, c_double, c_long
         type(c_ptr), value :: driver
         real(c_double), intent(inout) :: t
         real(c_double), value :: t1
         real(c_double), intent(inout) :: y(*)
         integer(c_long), value :: steps
         integer(c_int), value :: first
         integer(c_int), intent(out) :: done
         integer(c_int) :: status
      end function friction_gsl_driver_apply_part

      function friction_gsl_driver_step_once(driver, t, t1, y) result(status) &
         & bind(c, name='friction_gsl_driver_step_once')
         import :: c_ptr, c_double, c_int
         type(c_ptr), value :: driver
         real(c_double), intent(inout) :: t
         real(c_double), value :: t1
         real(c_double), intent(inout) :: y(*)
         integer(c_int) :: status
      end function friction_gsl_driver_step_once

      subroutine friction_gsl_driver_counts(driver, steps, failed) &
         & bind(c, name='friction_gsl_driver_counts')
         import :: c_ptr, c_long
         type(c_ptr), value :: driver
         integer(c_long), intent(out) :: steps, failed
      end subroutine friction_gsl_driver_counts

      function friction_gsl_driver_has_dense(driver) result(has) bind(c, name='friction_gsl_driver_has_dense')
         import :: c_ptr, c_int
         type(c_ptr), value :: driver
         integer(c_int) :: has
      end function friction_gsl_driver_has_dense

      function friction_gsl_driver_dense(driver, t, y) result(status) bind(c, name='friction_gsl_driver_dense')
         import :: c_ptr, c_double, c_int
         type(c_ptr), value :: driver
         real(c_double), value :: t
         real(c_double), intent(out) :: y(*)
         integer(c_int) :: status
      end function friction_gsl_driver_dense

      function friction_gsl_driver_step(driver) result(h) bind(c, name='friction_gsl_driver_step')
         import :: c_ptr, c_double
         type(c_ptr), value :: driver
         real(c_double) :: h
      end function friction_gsl_driver_step

      subroutine friction_gsl_driver_free(driver) bind(c, name='friction_gsl_driver_free')
         import :: c_ptr
         type(c_ptr), value :: driver
      end subroutine friction_gsl_driver_free

      function friction_gsl_error_reason() result(reason) bind(c, name='friction_gsl_error_reason')
         import :: c_ptr
         type(c_ptr) :: reason
      end function friction_gsl_error_reason

      function gsl_strerror(status) result(message) bind(c, name='gsl_strerror')
         import :: c_int, c_ptr
         integer(c_int), value :: status
         type(c_ptr) :: message
      end function gsl_strerror
   end interface

contains

   !> The GSL step type names, in the order of the C shim's table.
   pure function step_type_names() result(names)
      character(len=step_type_name_length), allocatable :: names(:)
      character(kind=c_char) :: buffer(step_type_name_length)
      integer :: i

      allocate (names(friction_gsl_step_type_count()))
      do i = 1, size(names)
         buffer = ' '
         call friction_gsl_step_type_name_copy(int(i, c_int), buffer, int(step_type_name_length, c_size_t))
         names(i) = transfer(buffer, names(i))
      end do
   end function step_type_names

   !> Index of a GSL step type name (case-sensitive, lower case; trailing
   !> blanks ignored), 0 if unknown.
   pure function step_type_index(name) result(index)
      character(len=*), intent(in) :: name
      integer :: index

      index = int(friction_gsl_step_type_index(name, int(len_trim(name), c_size_t)))
   end function step_type_index

   !> Whether a step type uses the Jacobian (implicit and BDF methods).
   pure logical function is_implicit_step_type(name)
      character(len=*), intent(in) :: name

      is_implicit_step_type = friction_gsl_step_type_uses_jacobian(int(step_type_index(name), c_int)) /= 0
   end function is_implicit_step_type

   !> Bind a driver to a system.  h_start must be > 0 here.
   subroutine init(self, model, settings, h_start, error)
      class(ode_solver), intent(inout) :: self
      class(ode_system), target, intent(in) :: model
      type(solver_settings), intent(in) :: settings
      real(wp), intent(in) :: h_start
      type(error_type), allocatable, intent(out) :: error
      integer :: index, relative
      integer(c_int) :: status
      real(wp) :: reference, floor

      call model%relative_component(relative, reference, floor)
      ! A driver made for the same stepper, size and tolerances is reset
      ! instead of made again: integrations that start over and over (a
      ! Lyapunov exponent's perturbed run, a phase of the switched brake)
      ! spent a tenth of their time allocating and freeing GSL's arrays.
      ! The reset driver steps as a new one would, bit for bit.
      if (reuse(self)) return
      call self%destroy()
      index = step_type_index(settings%method)
      if (index == 0) then
         call fatal_error(error, "unknown step type '"//trim(settings%method)//"'", error_input)
         return
      end if
      allocate (self%box, self%sys)
      self%box%model => model
      self%box%n = model%dimension()
      allocate (self%box%jac(self%box%n, self%box%n), self%box%ft(self%box%n))
      self%sys%function = c_funloc(gsl_rhs)
      self%sys%jacobian = c_funloc(gsl_jacobian)
      self%sys%dimension = int(self%box%n, c_size_t)
      self%sys%params = c_loc(self%box)
      status = friction_gsl_driver_new(self%driver, c_loc(self%sys), int(index, c_int), &
         & real(h_start, c_double), real(settings%atol, c_double), real(settings%rtol, c_double), &
         & int(model%controlled_dimension(), c_int), int(relative, c_int), real(reference, c_double), &
         & real(floor, c_double))
      if (status /= gsl_success) then
         if (status == gsl_enomem) then
            call fatal_error(error, 'GSL could not allocate a driver for '//trim(settings%method), &
               & error_internal)
         else
            call fatal_error(error, 'GSL refused a driver for '//trim(settings%method)//' (first step ' &
               & //rtoa(h_start)//', atol = '//rtoa(settings%atol)//', rtol = '//rtoa(settings%rtol) &
               & //'): '//gsl_description(status), error_input)
         end if
         return
      end if
      self%max_steps = settings%max_steps
      self%h_min = settings%h_min
      self%method = settings%method
      self%step_index = index
      self%controlled = model%controlled_dimension()
      self%relative = relative
      self%reference = reference
      self%floor = floor
      self%atol = settings%atol
      self%rtol = settings%rtol
      status = friction_gsl_driver_set_limits(self%driver, int(settings%max_steps, c_long), &
         & real(max(settings%h_min, 0.0_wp), c_double))
      if (status /= gsl_success) then
         call fatal_error(error, trim(settings%method)//': GSL refused h_min = '//rtoa(settings%h_min) &
            & //' with the first step '//rtoa(h_start)//' (h_min must not exceed it): ' &
            & //gsl_description(status), error_input)
         call self%destroy()
         return
      end if
      self%done = integrator_statistics()

   contains

      !> Whether the driver there was made for these settings and could be
      !> reset to start with h_start (else init makes a new one, and reports
      !> what GSL refuses).
      logical function reuse(self)
         class(ode_solver), intent(inout) :: self

         reuse = .false.
         if (.not. c_associated(self%driver)) return
         if (self%step_index /= step_type_index(settings%method) .or. self%box%n /= model%dimension() &
            & .or. self%controlled /= model%controlled_dimension() .or. self%atol /= settings%atol &
            & .or. self%rtol /= settings%rtol .or. self%h_min /= settings%h_min &
            & .or. self%max_steps /= settings%max_steps .or. self%relative /= relative &
            & .or. self%reference /= reference .or. self%floor /= floor) return
         if (friction_gsl_driver_reset(self%driver, real(h_start, c_double)) /= gsl_success) return
         self%box%model => model
         self%box%rhs_evaluations = 0
         self%box%jacobian_evaluations = 0
         self%method = settings%method
         if (allocated(self%failed_restart)) deallocate (self%failed_restart)
         self%done = integrator_statistics()
         reuse = .true.
      end function reuse
   end subroutine init

   !> Start afresh (new initial condition or changed model parameters):
   !> multistep methods forget their history; counters are kept.  GSL
   !> refuses a first step outside [h_min, h_max] or zero: the error comes
   !> back in error if present, else from the next advance or step.
   subroutine restart(self, h_start, error)
      class(ode_solver), intent(inout) :: self
      real(wp), intent(in) :: h_start
      type(error_type), allocatable, intent(out), optional :: error
      integer(c_int) :: status

      if (allocated(self%failed_restart)) deallocate (self%failed_restart)
      self%done = self%statistics()
      self%box%rhs_evaluations = 0
      self%box%jacobian_evaluations = 0
      status = friction_gsl_driver_reset(self%driver, real(h_start, c_double))
      if (status /= gsl_success) then
         self%failed_restart = trim(self%method)//': GSL could not restart the integration with the first step ' &
            & //rtoa(h_start)
         if (self%h_min > 0.0_wp) self%failed_restart = self%failed_restart//' (h_min = '//rtoa(self%h_min)//')'
         self%failed_restart = self%failed_restart//': '//gsl_description(status)
         if (present(error)) call self%report_failed_restart(error)
      end if
   end subroutine restart

   !> The error of a refused restart, once.
   subroutine report_failed_restart(self, error)
      class(ode_solver), intent(inout) :: self
      type(error_type), allocatable, intent(out) :: error

      if (.not. allocated(self%failed_restart)) return
      call fatal_error(error, self%failed_restart, error_numerical)
      deallocate (self%failed_restart)
   end subroutine report_failed_restart

   !> Advance y from t to t1.  On failure t holds the time reached.  With a
   !> watch, the trip goes in parts of watch_steps steps (the same steps as
   !> one piece, bit for bit) and the watch is asked after each: its error
   !> ends the trip there.
   subroutine advance(self, t, t1, y, error, watch)
      class(ode_solver), intent(inout) :: self
      real(wp), intent(inout) :: t
      real(wp), intent(in) :: t1
      real(wp), intent(inout) :: y(:)
      type(error_type), allocatable, intent(out) :: error
      class(step_watch), intent(inout), optional :: watch
      integer(c_int) :: status, done, first
      integer(c_long) :: steps, failed
      !> Steps between two looks of the watch: a few microseconds of the
      !> cheapest systems, so a look (a clock read) costs nothing in comparison.
      integer(c_long), parameter :: watch_steps = 16

      call self%report_failed_restart(error)
      if (allocated(error)) return
      if (present(watch)) then
         first = 1
         do
            status = friction_gsl_driver_apply_part(self%driver, t, t1, y, watch_steps, first, done)
            first = 0
            if (status /= gsl_success .or. done /= 0) exit
            call watch%check(t, error)
            if (allocated(error)) return
         end do
      else
         status = friction_gsl_driver_apply(self%driver, t, t1, y)
      end if
      call friction_gsl_driver_counts(self%driver, steps, failed)
      if (status /= gsl_success) then
         if (status == gsl_ebadfunc) then
            call fatal_error(error, trim(self%method)//': the right-hand side became NaN or Inf at ' &
               & //self%time_at(t), error_numerical)
         else
            call fatal_error(error, trim(self%method)//' failed at '//self%time_at(t) &
               & //': '//gsl_description(status)//step_hint(status), error_numerical)
         end if
      else if (.not. all(abs(y) <= huge(y))) then
         call fatal_error(error, trim(self%method)//': the state became NaN or Inf at ' &
            & //self%time_at(t), error_numerical)
      else if (steps > self%max_steps) then
         call fatal_error(error, trim(self%method)//': more than max_steps steps in one trip at ' &
            & //self%time_at(t), error_numerical)
      end if
   end subroutine advance

   !> One accepted step of the driver from t towards t1 (never past it), for
   !> callers that look at every step (event location).  The driver's
   !> h_min check applies; max_steps is the caller's to count.  On failure t
   !> holds the time reached.
   subroutine step(self, t, t1, y, error)
      class(ode_solver), intent(inout) :: self
      real(wp), intent(inout) :: t
      real(wp), intent(in) :: t1
      real(wp), intent(inout) :: y(:)
      type(error_type), allocatable, intent(out) :: error
      integer(c_int) :: status
      real(wp) :: t0

      call self%report_failed_restart(error)
      if (allocated(error)) return
      t0 = t
      status = friction_gsl_driver_step_once(self%driver, t, t1, y)
      if (status == gsl_ebadfunc) then
         call fatal_error(error, trim(self%method)//': the right-hand side became NaN or Inf at ' &
            & //self%time_at(t), error_numerical)
      else if (status /= gsl_success) then
         call fatal_error(error, trim(self%method)//' failed at '//self%time_at(t) &
            & //': '//gsl_description(status)//step_hint(status), error_numerical)
      else if (.not. all(abs(y) <= huge(y))) then
         call fatal_error(error, trim(self%method)//': the state became NaN or Inf at ' &
            & //self%time_at(t), error_numerical)
      else if (.not. (t > t0)) then
         ! A caller stepping until t reaches its target would loop for ever.
         call fatal_error(error, trim(self%method)//': no progress at '//self%time_at(t) &
            & //' (the step size fell below the resolution of the time)', error_numerical)
      end if
   end subroutine step

   !> The step size the driver will try next.
   function step_size(self) result(h)
      class(ode_solver), intent(in) :: self
      real(wp) :: h

      h = 0.0_wp
      if (c_associated(self%driver)) h = friction_gsl_driver_step(self%driver)
   end function step_size

   !> Whether the stepper has a continuous extension (rodas4): then a caller
   !> may take free steps and ask dense_output for the state in between.
   logical function has_dense_output(self)
      class(ode_solver), intent(in) :: self

      has_dense_output = .false.
      if (c_associated(self%driver)) has_dense_output = friction_gsl_driver_has_dense(self%driver) /= 0
   end function has_dense_output

   !> The state at t within the last step taken by `step`, from the
   !> stepper's continuous extension (of order 3 for rodas4): an error when
   !> the stepper has none or t is outside that step.
   subroutine dense_output(self, t, y, error)
      class(ode_solver), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(out) :: y(:)
      type(error_type), allocatable, intent(out) :: error

      y = 0.0_wp
      if (.not. c_associated(self%driver)) then
         call fatal_error(error, 'dense output asked of a solver without a driver', error_internal)
      else if (friction_gsl_driver_dense(self%driver, real(t, c_double), y) /= gsl_success) then
         call fatal_error(error, trim(self%method)//': no dense output at '//self%time_at(t) &
            & //' (not within the last step)', error_internal)
      end if
   end subroutine dense_output

   !> How messages name the time: 't', ' s' by default; a nondimensional
   !> scene passes its own symbol and an empty unit.
   subroutine set_time_label(self, name, unit)
      class(ode_solver), intent(inout) :: self
      character(len=*), intent(in) :: name, unit

      self%time_name = name
      self%time_unit = unit
   end subroutine set_time_label

   !> 't = 1.2345670E-03 s' for messages.
   function time_at(self, t) result(text)
      class(ode_solver), intent(in) :: self
      real(wp), intent(in) :: t
      character(len=:), allocatable :: text

      text = trim(self%time_name)//' = '//etoa(t, 7)//trim(self%time_unit)
   end function time_at

   !> Counters summed over all restarts so far.
   function statistics(self) result(stats)
      class(ode_solver), intent(in) :: self
      type(integrator_statistics) :: stats
      integer(c_long) :: steps, failed

      stats = self%done
      if (.not. c_associated(self%driver)) return
      call friction_gsl_driver_counts(self%driver, steps, failed)
      stats%steps = stats%steps + steps
      stats%failed_steps = stats%failed_steps + failed
      stats%rhs_evaluations = stats%rhs_evaluations + self%box%rhs_evaluations
      stats%jacobian_evaluations = stats%jacobian_evaluations + self%box%jacobian_evaluations
   end function statistics

   subroutine destroy(self)
      class(ode_solver), intent(inout) :: self

      if (c_associated(self%driver)) call friction_gsl_driver_free(self%driver)
      self%driver = c_null_ptr
      if (allocated(self%failed_restart)) deallocate (self%failed_restart)
      if (associated(self%sys)) deallocate (self%sys)
      if (associated(self%box)) deallocate (self%box)
   end subroutine destroy

   subroutine finalize(self)
      type(ode_solver), intent(inout) :: self

      call self%destroy()
   end subroutine finalize

   pure subroutine statistics_add(self, other)
      class(integrator_statistics), intent(inout) :: self
      type(integrator_statistics), intent(in) :: other

      self%steps = self%steps + other%steps
      self%failed_steps = self%failed_steps + other%failed_steps
      self%rhs_evaluations = self%rhs_evaluations + other%rhs_evaluations
      self%jacobian_evaluations = self%jacobian_evaluations + other%jacobian_evaluations
   end subroutine statistics_add

   !> GSL's text for a status code.
   function gsl_message(status) result(message)
      integer(c_int), intent(in) :: status
      character(len=:), allocatable :: message

      message = c_text(gsl_strerror(status))
   end function gsl_message

   !> GSL's text for a status code, and in parentheses what GSL reported
   !> when it did (the shim keeps that of this thread's last call).
   function gsl_description(status) result(message)
      integer(c_int), intent(in) :: status
      character(len=:), allocatable :: message, reason

      message = gsl_message(status)
      reason = c_text(friction_gsl_error_reason())
      if (len(reason) > 0) message = message//' ('//reason//')'
   end function gsl_description

   !> A NUL-terminated C string (at most 256 characters); '' for NULL.
   function c_text(pointer) result(text)
      type(c_ptr), intent(in) :: pointer
      character(len=:), allocatable :: text
      character(kind=c_char), pointer :: chars(:)
      integer :: n

      text = ''
      if (.not. c_associated(pointer)) return
      call c_f_pointer(pointer, chars, [256])
      n = 0
      do while (n < 256)
         if (chars(n + 1) == c_null_char) exit
         n = n + 1
      end do
      text = transfer(chars(1:n), repeat(' ', n))
   end function c_text

   !> What a user can do about a failure status.
   pure function step_hint(status) result(hint)
      integer(c_int), intent(in) :: status
      character(len=:), allocatable :: hint

      select case (status)
      case (11) ! GSL_EMAXITER
         hint = ' (max_steps reached; raise max_steps, loosen the tolerance or try an implicit method)'
      case (-1) ! GSL_FAILURE: the stepper failed at every step size GSL tried, down to t's spacing
         hint = ' (the stepper failed at every step size down to the spacing of t; for rodas3 and rodas4' &
            & //' that means a right-hand side or a result that is NaN or Inf at every step: the equations' &
            & //' overflow or divide by zero there)'
      case (27) ! GSL_ENOPROG
         hint = ' (step size fell below h_min; the problem may be stiff: try an implicit method)'
      case default
         hint = ''
      end select
   end function step_hint

   !> Right-hand side as GSL calls it.
   function gsl_rhs(t, y, dydt, params) result(status) bind(c)
      real(c_double), value :: t
      real(c_double), intent(in) :: y(*)
      real(c_double), intent(out) :: dydt(*)
      type(c_ptr), value :: params
      integer(c_int) :: status
      type(system_box), pointer :: box
      integer :: n, i

      call c_f_pointer(params, box)
      n = box%n
      call box%model%rhs(t, y(1:n), dydt(1:n))
      box%rhs_evaluations = box%rhs_evaluations + 1
      status = gsl_success
      ! NaN fails every comparison, Inf exceeds huge: both stop the driver at once.
      do i = 1, n
         if (.not. (abs(dydt(i)) <= huge(1.0_c_double))) status = gsl_ebadfunc
      end do
   end function gsl_rhs

   !> Jacobian as GSL wants it: dfdy row-major, dfdy[i*n + j] = ∂f_i/∂y_j.
   function gsl_jacobian(t, y, dfdy, dfdt, params) result(status) bind(c)
      real(c_double), value :: t
      real(c_double), intent(in) :: y(*)
      real(c_double), intent(out) :: dfdy(*)
      real(c_double), intent(out) :: dfdt(*)
      type(c_ptr), value :: params
      integer(c_int) :: status
      type(system_box), pointer :: box
      integer :: n, i

      call c_f_pointer(params, box)
      n = box%n
      call box%model%jacobian(t, y(1:n), box%jac, box%ft)
      box%jacobian_evaluations = box%jacobian_evaluations + 1
      do i = 1, n
         dfdy((i - 1) * n + 1:i * n) = box%jac(i, 1:n)
      end do
      dfdt(1:n) = box%ft
      status = gsl_success
   end function gsl_jacobian

end module friction_ode_solver
