!> Every GSL step type through the bridge: a harmonic oscillator and an
!> exponential decay against their exact solutions; failures come back as
!> errors that carry the time reached.
program test_steppers
   use friction_kinds, only: wp, i8, pi
   use friction_error, only: error_type
   use test_systems, only: oscillator, decay
   use friction_ode_solver, only: ode_solver, solver_settings, step_type_names, integrator_statistics
   use testing, only: test_suite, check, check_close, current_test
   implicit none

   type(test_suite) :: suite
   integer :: m
   character(len=:), allocatable :: names(:)

   suite%name = 'steppers'
   names = step_type_names()
   do m = 1, size(names)
      call suite%add('oscillator_'//trim(names(m)), oscillator_case)
      call suite%add('decay_'//trim(names(m)), decay_case)
   end do
   call suite%add('max_steps_reported', max_steps_reported)
   call suite%add('nan_reported', nan_reported)
   call suite%add('h_min_reported', h_min_reported)
   call suite%add('unknown_method', unknown_method)
   call suite%add('restart_keeps_counts', restart_keeps_counts)
   call suite%run_all()

contains

   !> The test's method, from its name.
   function method_of_current() result(name)
      character(len=:), allocatable :: name
      name = trim(current_test(index(current_test, '_') + 1:))
   end function method_of_current

   !> Maximum error over samples of x(t) = cos(ωt) on [0, 2 periods], at
   !> tolerance tol; also the accepted steps.
   subroutine oscillator_error(method, tol, max_error, steps, error)
      character(len=*), intent(in) :: method
      real(wp), intent(in) :: tol
      real(wp), intent(out) :: max_error
      integer(i8), intent(out) :: steps
      type(error_type), allocatable, intent(out) :: error
      type(oscillator), target :: system
      type(ode_solver) :: solver
      type(solver_settings) :: settings
      real(wp) :: t, y(2), t1
      integer :: k

      system%omega = 3.0_wp
      settings%method = method
      settings%rtol = tol
      settings%atol = tol
      call solver%init(system, settings, 1.0e-6_wp, error)
      if (allocated(error)) return
      t = 0.0_wp
      y = [1.0_wp, 0.0_wp]
      max_error = 0.0_wp
      do k = 1, 40
         t1 = k * (4.0_wp * pi / system%omega) / 40
         call solver%advance(t, t1, y, error)
         if (allocated(error)) return
         max_error = max(max_error, abs(y(1) - cos(system%omega * t)), &
            & abs(y(2) + system%omega * sin(system%omega * t)) / system%omega)
      end do
      block
         type(integrator_statistics) :: stats
         stats = solver%statistics()
         steps = stats%steps
      end block
   end subroutine oscillator_error

   !> Each step keeps its local error estimate below tol (|y| <= 1 here), and
   !> for this non-expanding flow the global error is at most the sum of the
   !> local ones: bound = tol x steps.  A convergent method must also gain
   !> accuracy when the tolerance tightens a hundredfold.
   subroutine oscillator_case(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(error_type), allocatable :: error
      real(wp) :: err_loose, err_tight, tol
      integer(i8) :: steps_loose, steps_tight
      character(len=:), allocatable :: method

      method = method_of_current()
      tol = 1.0e-6_wp
      call oscillator_error(method, tol, err_loose, steps_loose, error)
      if (allocated(error)) then
         failure = error%message
         return
      end if
      call oscillator_error(method, tol / 100, err_tight, steps_tight, error)
      if (allocated(error)) then
         failure = error%message
         return
      end if
      call check_close(failure, err_loose, 0.0_wp, tol * steps_loose, method//' error at tol 1e-6')
      call check_close(failure, err_tight, 0.0_wp, tol / 100 * steps_tight, method//' error at tol 1e-8')
      ! (unless the loose run already meets the tight tolerance, as rk8pd and
      ! bsimp do when the 40 output times, not accuracy, limit their steps)
      call check(failure, err_tight < err_loose .or. err_loose <= tol / 100, &
         & method//': error does not fall as the tolerance tightens')
   end subroutine oscillator_case

   !> y = exp(-λt) on [0, 5/λ]; the same bound as for the oscillator.
   subroutine decay_case(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(decay), target :: system
      type(ode_solver) :: solver
      type(solver_settings) :: settings
      type(error_type), allocatable :: error
      real(wp) :: t, y(1), max_error, tol
      type(integrator_statistics) :: stats
      integer :: k

      tol = 1.0e-8_wp
      system%rate = 2.0_wp
      settings%method = method_of_current()
      settings%rtol = tol
      settings%atol = tol
      call solver%init(system, settings, 1.0e-6_wp, error)
      t = 0.0_wp
      y = 1.0_wp
      max_error = 0.0_wp
      do k = 1, 25
         if (.not. allocated(error)) call solver%advance(t, k * 0.1_wp, y, error)
         max_error = max(max_error, abs(y(1) - exp(-system%rate * t)))
      end do
      if (allocated(error)) then
         failure = error%message
         return
      end if
      stats = solver%statistics()
      call check_close(failure, max_error, 0.0_wp, tol * stats%steps, trim(settings%method)//' decay error')
   end subroutine decay_case

   subroutine max_steps_reported(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(oscillator), target :: system
      type(ode_solver) :: solver
      type(solver_settings) :: settings
      type(error_type), allocatable :: error
      real(wp) :: t, y(2)

      settings%max_steps = 50
      call solver%init(system, settings, 1.0e-3_wp, error)
      t = 0.0_wp
      y = [1.0_wp, 0.0_wp]
      call solver%advance(t, 1000.0_wp, y, error)
      call check(failure, allocated(error), 'no error after exceeding max_steps')
      if (allocated(failure)) return
      call check(failure, index(error%message, 'max_steps') > 0, 'message lacks max_steps: '//error%message)
      call check(failure, index(error%message, 't = ') > 0, 'message lacks the time: '//error%message)
      call check(failure, t > 0.0_wp .and. t < 1000.0_wp, 'time reached not reported in t')
   end subroutine max_steps_reported

   subroutine nan_reported(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(decay), target :: system
      type(ode_solver) :: solver
      type(solver_settings) :: settings
      type(error_type), allocatable :: error
      real(wp) :: t, y(1)
      integer :: m
      character(len=:), allocatable :: methods(:)

      system%t_bad = 0.5_wp
      methods = step_type_names()
      do m = 1, size(methods)
         settings%method = methods(m)
         call solver%init(system, settings, 1.0e-3_wp, error)
         t = 0.0_wp
         y = 1.0_wp
         call solver%advance(t, 1.0_wp, y, error)
         call check(failure, allocated(error), trim(settings%method)//': NaN not reported')
         if (allocated(failure)) return
         call check(failure, index(error%message, 'NaN') > 0, 'message lacks NaN: '//error%message)
         ! The driver stops at the step that met NaN: t is before the bad region plus a step.
         call check(failure, t <= 0.5_wp + 0.2_wp, trim(settings%method)//': time reached past the NaN')
      end do
   end subroutine nan_reported

   subroutine h_min_reported(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(oscillator), target :: system
      type(ode_solver) :: solver
      type(solver_settings) :: settings
      type(error_type), allocatable :: error
      real(wp) :: t, y(2)

      ! A minimum step far above what the tolerance needs: GSL must give up.
      settings%rtol = 1.0e-12_wp
      settings%atol = 1.0e-12_wp
      settings%h_min = 0.1_wp
      call solver%init(system, settings, 0.1_wp, error)
      t = 0.0_wp
      y = [1.0_wp, 0.0_wp]
      call solver%advance(t, 10.0_wp, y, error)
      call check(failure, allocated(error), 'no error although steps must fall below h_min')
      if (allocated(failure)) return
      call check(failure, index(error%message, 'h_min') > 0, 'message lacks h_min: '//error%message)
   end subroutine h_min_reported

   subroutine unknown_method(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(oscillator), target :: system
      type(ode_solver) :: solver
      type(solver_settings) :: settings
      type(error_type), allocatable :: error

      settings%method = 'rk45'
      call solver%init(system, settings, 1.0e-3_wp, error)
      call check(failure, allocated(error), 'unknown step type accepted')
   end subroutine unknown_method

   !> Counters add up over restarts: two identical runs cost twice one.
   subroutine restart_keeps_counts(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(oscillator), target :: system
      type(ode_solver) :: solver
      type(solver_settings) :: settings
      type(error_type), allocatable :: error
      type(integrator_statistics) :: one, two
      real(wp) :: t, y(2)
      integer :: k

      call solver%init(system, settings, 1.0e-3_wp, error)
      do k = 1, 2
         call solver%restart(1.0e-3_wp)
         t = 0.0_wp
         y = [1.0_wp, 0.0_wp]
         call solver%advance(t, 10.0_wp, y, error)
         if (k == 1) one = solver%statistics()
      end do
      two = solver%statistics()
      call check(failure, one%steps > 0 .and. two%steps == 2 * one%steps, 'steps do not add up')
      call check(failure, two%rhs_evaluations == 2 * one%rhs_evaluations, 'evaluations do not add up')
   end subroutine restart_keeps_counts

end program test_steppers
