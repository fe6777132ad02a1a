!> One run of the machine (docs/laws.md, "Mechanisms"): the trajectory on
!> the output grid and the stick/slip events.  Set-valued laws switch
!> exactly between stick and slip as the brake's switched model does
!> (located events; in stick v = belt_velocity exactly; a slip that ends
!> beyond the static limit reverses); a law with a zero-velocity band
!> (Karnopp's) runs with the band's edges and the ends of its holds located
!> (band.f90), and the output counts the band as stick; the other laws are
!> one ODE with the law's states, and the output counts |w| <= stick_velocity
!> as stick.
module friction_machine_run
   use friction_kinds, only: wp, i8
   use friction_error, only: error_type, fatal_error, error_numerical
   use friction_strings, only: rtoa, itoa
   use friction_ode_solver, only: ode_solver, integrator_statistics
   use friction_ode_watch, only: step_watch
   use friction_scene_report, only: job_reporter, new_job_watch
   use friction_ode_events, only: event_locator, event_falling
   use friction_law, only: sliding_law, max_law_states
   use friction_law_factory, only: make_law
   use friction_output_law_files, only: law_with_files
   use friction_machine_config, only: machine_config
   use friction_machine_model, only: mechanics, machine_smooth, machine_slip, machine_stick
   use friction_machine_band, only: machine_band, band_hold, band_cross, band_leave, band_exit, &
      & band_hold_end, max_switches
   implicit none
   private

   public :: machine_run, run_machine, machine_watch
   public :: event_stick_to_slip, event_slip_to_stick, event_slip_reversal, event_kind_names

   integer, parameter :: event_stick_to_slip = 1, event_slip_to_stick = 2, event_slip_reversal = 3
   character(len=*), parameter :: event_kind_names(3) = [character(len=13) :: 'stick_to_slip', 'slip_to_stick', &
      & 'reversal']

   type :: machine_run
      integer :: n = 0                        !! grid points
      real(wp), allocatable :: t(:), x(:), v(:), force(:), states(:, :)
      integer, allocatable :: stick(:)
      integer :: n_states = 0
      !> the law's states' names and units (z; theta; z1 ... zN of the GMS law's elements)
      character(len=16), allocatable :: state_names(:), state_units(:)
      integer :: n_events = 0
      real(wp), allocatable :: event_t(:), event_x(:), event_v(:)
      integer, allocatable :: event_kind(:)
      real(wp) :: stick_time = 0.0_wp         !! s in exact stick (set-valued laws)
      type(integrator_statistics) :: stats
   contains
      procedure :: add_event
   end type machine_run

contains

   subroutine add_event(self, t, kind, x, v)
      class(machine_run), intent(inout) :: self
      real(wp), intent(in) :: t, x, v
      integer, intent(in) :: kind
      real(wp), allocatable :: rt(:), rx(:), rv(:)
      integer, allocatable :: rk(:)
      integer :: n

      n = self%n_events
      if (n == size(self%event_t)) then
         allocate (rt(2 * n + 16), rx(2 * n + 16), rv(2 * n + 16), rk(2 * n + 16))
         rt(1:n) = self%event_t(1:n)
         rx(1:n) = self%event_x(1:n)
         rv(1:n) = self%event_v(1:n)
         rk(1:n) = self%event_kind(1:n)
         call move_alloc(rt, self%event_t)
         call move_alloc(rx, self%event_x)
         call move_alloc(rv, self%event_v)
         call move_alloc(rk, self%event_kind)
      end if
      n = n + 1
      self%event_t(n) = t
      self%event_x(n) = x
      self%event_v(n) = v
      self%event_kind(n) = kind
      self%n_events = n
   end subroutine add_event

   !> A watch over the machine's work from now on: max_wall_time, and the
   !> stop requests of `reporter` if given.
   function machine_watch(c, what, reporter) result(watch)
      type(machine_config), intent(in) :: c
      character(len=*), intent(in) :: what
      class(job_reporter), intent(in), optional :: reporter
      class(step_watch), allocatable :: watch

      allocate (watch, source=new_job_watch('machine, '//trim(c%law%model)//' law: '//what, 't', &
         & c%solver%max_wall_time, reporter))
   end function machine_watch

   !> The whole run of checked settings c.  The integration asks `watch`
   !> every few steps and at every output point (by default a watch of
   !> max_wall_time alone): a stop request or the limit ends the run there
   !> with an error, and nothing of it is kept.
   subroutine run_machine(c, run, error, watch)
      type(machine_config), intent(in) :: c
      type(machine_run), intent(out) :: run
      type(error_type), allocatable, intent(out) :: error
      class(step_watch), intent(inout), optional :: watch
      class(sliding_law), allocatable :: law
      class(step_watch), allocatable :: own
      type(mechanics) :: m
      integer :: n, k

      call make_law(law_with_files(c%law), law, error)
      if (allocated(error)) return
      call m%from_config(c)
      n = c%grid_size()
      run%n = n
      run%n_states = law%state_count()
      allocate (run%t(n), run%x(n), run%v(n), run%force(n), run%states(max(run%n_states, 1), n), run%stick(n))
      allocate (run%event_t(16), run%event_x(16), run%event_v(16), run%event_kind(16))
      run%states = 0.0_wp
      run%stick = 0
      allocate (run%state_names(run%n_states), run%state_units(run%n_states))
      do k = 1, run%n_states
         run%state_names(k) = law%state_name(k)
         run%state_units(k) = law%state_unit(k)
      end do
      if (present(watch)) then
         call integrate(watch)
      else
         allocate (own, source=machine_watch(c, 'the run'))
         call integrate(own)
      end if

   contains

      subroutine integrate(watch)
         class(step_watch), intent(inout) :: watch
         real(wp) :: width, limit

         call law%band(width, limit)
         if (law%set_valued()) then
            call run_switched(c, law, m, run, watch, error)
         else if (width > 0.0_wp) then
            call run_band(c, law, m, run, watch, error)
         else
            call run_smooth(c, law, m, run, watch, error)
         end if
      end subroutine integrate
   end subroutine run_machine

   subroutine run_smooth(c, law, m, run, watch, error)
      type(machine_config), intent(in) :: c
      class(sliding_law), intent(in) :: law
      type(mechanics), intent(in) :: m
      type(machine_run), intent(inout) :: run
      class(step_watch), intent(inout) :: watch
      type(error_type), allocatable, intent(out) :: error
      type(machine_smooth), target :: system
      type(ode_solver) :: solver
      real(wp) :: y(2 + max_law_states), t, z(max_law_states), h
      integer :: i, k, ns

      ns = law%state_count()
      system%m = m
      allocate (system%law, source=law)
      system%n_states = ns
      if (ns > 0) call law%state_scale(system%scale(1:ns))
      h = c%first_step()
      call solver%init(system, c%solver, h, error)
      if (allocated(error)) return
      call solver%set_time_label('t', ' s')
      z = 0.0_wp
      if (ns > 0 .and. c%steady_start) call law%steady_state(c%v0 - m%belt, m%normal, z(1:ns))
      y(1) = c%x0
      y(2) = c%v0
      y(3:2 + ns) = z(1:ns) / system%scale(1:ns)
      t = c%t_start
      if (c%dense_output .and. solver%has_dense_output()) then
         call free_steps()
         if (allocated(error)) return
      else
         do i = 1, run%n
            if (i > 1) then
               call solver%advance(t, c%grid_time(i), y(1:2 + ns), error, watch)
               if (allocated(error)) then
                  call label(c, error)
                  return
               end if
               ! (Also here: a trip of a few steps never reaches the solver's look.)
               call watch%check(t, error)
               if (allocated(error)) return
            end if
            call record(i, y)
         end do
      end if
      run%stats = solver%statistics()

   contains

      !> Steps of the error control's own size to the last output time, the
      !> output points within each step from its continuous extension: the
      !> grid no longer pins the steps (one Jacobian per output point).
      subroutine free_steps()
         real(wp) :: t_last, t_grid, yi(2 + max_law_states)
         integer(i8) :: steps
         !> Steps between two looks of the watch (as the solver's advance).
         integer, parameter :: watch_steps = 16

         t_last = c%grid_time(run%n)
         call record(1, y)
         i = 2
         steps = 0
         do while (i <= run%n)
            call solver%step(t, t_last, y(1:2 + ns), error)
            if (allocated(error)) then
               call label(c, error)
               return
            end if
            steps = steps + 1
            if (steps > c%solver%max_steps) then
               call fatal_error(error, trim(c%solver%method)//': more than max_steps steps at ' &
                  & //solver%time_at(t), error_numerical)
               call label(c, error)
               return
            end if
            do while (i <= run%n)
               t_grid = c%grid_time(i)
               if (t_grid > t) exit
               if (t_grid == t) then
                  call record(i, y)
               else
                  call solver%dense_output(t_grid, yi(1:2 + ns), error)
                  if (allocated(error)) return
                  call record(i, yi)
               end if
               i = i + 1
            end do
            if (mod(steps, int(watch_steps, i8)) == 0 .or. i > run%n) then
               call watch%check(t, error)
               if (allocated(error)) return
            end if
         end do
      end subroutine free_steps

      !> Output point i from the state yy at the grid time.
      subroutine record(i, yy)
         integer, intent(in) :: i
         real(wp), intent(in) :: yy(:)

         z(1:ns) = yy(3:2 + ns) * system%scale(1:ns)
         run%t(i) = c%grid_time(i)
         run%x(i) = yy(1)
         run%v(i) = yy(2)
         run%force(i) = law%force(yy(2) - m%belt, z(1:ns), m%normal, m%applied(run%t(i), yy(1), yy(2)))
         do k = 1, ns
            run%states(k, i) = z(k)
         end do
         if (abs(yy(2) - m%belt) <= c%stick_velocity) run%stick(i) = 1
      end subroutine record
   end subroutine run_smooth

   !> Exact stick and slip for a set-valued law.
   subroutine run_switched(c, law, m, run, watch, error)
      type(machine_config), intent(in) :: c
      class(sliding_law), intent(in) :: law
      type(mechanics), intent(in) :: m
      type(machine_run), intent(inout) :: run
      class(step_watch), intent(inout) :: watch
      type(error_type), allocatable, intent(out) :: error
      type(machine_slip), target :: slip
      type(machine_stick), target :: stick
      type(event_locator) :: slipping, sticking
      real(wp) :: y(2), t, limit, a, h, none(0), t_grid
      logical :: in_stick
      integer :: i, which

      limit = law%static_force(m%normal)
      slip%m = m
      allocate (slip%law, source=law)
      stick%m = m
      stick%limit = limit
      h = c%first_step()
      call slipping%init(slip, c%solver, [event_falling], [.true.], c%event_tolerance, h, error, 't', ' s')
      if (allocated(error)) return
      call sticking%init(stick, c%solver, [event_falling, event_falling], [.true., .true.], c%event_tolerance, h, &
         & error, 't', ' s')
      if (allocated(error)) return
      t = c%t_start
      y = [c%x0, c%v0]
      a = m%applied(t, y(1), y(2))
      in_stick = y(2) == m%belt .and. abs(a) <= limit
      if (in_stick) then
         call sticking%restart(t, y, h)
      else if (y(2) /= m%belt) then
         call start_slip(sign(1.0_wp, y(2) - m%belt))
      else
         call start_slip(sign(1.0_wp, a))
      end if
      call record(1)
      do i = 2, run%n
         t_grid = c%grid_time(i)
         do while (t < t_grid)
            if (in_stick) then
               block
                  real(wp) :: t0
                  t0 = t
                  call sticking%advance(t, t_grid, y, error, watch)
                  run%stick_time = run%stick_time + (t - t0)
               end block
               if (allocated(error)) exit
               y(2) = m%belt   ! exact in stick
               if (sticking%n_hits == 0) cycle
               which = sticking%hits(sticking%n_hits)%which
               ! The applied force reached +limit (1) or -limit (2): slip that way.
               in_stick = .false.
               call start_slip(merge(1.0_wp, -1.0_wp, which == 1))
               call run%add_event(t, event_stick_to_slip, y(1), y(2))
            else
               call slipping%advance(t, t_grid, y, error, watch)
               if (allocated(error)) exit
               if (slipping%n_hits == 0) cycle
               a = m%applied(t, y(1), m%belt)
               if (abs(a) <= limit) then
                  in_stick = .true.
                  y(2) = m%belt   ! exact: the event left w within the tolerance of 0
                  call sticking%restart(t, y, h)
                  call run%add_event(t, event_slip_to_stick, y(1), y(2))
               else
                  call start_slip(sign(1.0_wp, a))
                  call run%add_event(t, event_slip_reversal, y(1), y(2))
               end if
            end if
         end do
         if (allocated(error)) then
            call label(c, error)
            return
         end if
         call watch%check(t, error)
         if (allocated(error)) return
         call record(i)
      end do
      run%stats = slipping%statistics()
      call run%stats%add(sticking%statistics())
   contains
      subroutine start_slip(s)
         real(wp), intent(in) :: s

         slip%direction = s
         call slipping%restart(t, y, h)
      end subroutine start_slip

      subroutine record(i)
         integer, intent(in) :: i
         real(wp) :: applied

         run%t(i) = t
         run%x(i) = y(1)
         run%v(i) = y(2)
         applied = m%applied(t, y(1), y(2))
         if (in_stick) then
            run%force(i) = max(-limit, min(limit, applied))
            run%stick(i) = 1
         else
            run%force(i) = law%slip_force(y(2) - m%belt, none, m%normal, slip%direction)
         end if
      end subroutine record
   end subroutine run_switched

   !> A law with a zero-velocity band (Karnopp's): the band's edges and the
   !> ends of its holds located (band.f90, as the orbit's map runs them), the
   !> events as the brake's band run records them: into a hold at an edge
   !> slip_to_stick, into the band without a hold (crossing it) reversal, out
   !> of a hold stick_to_slip.  The output counts the band as stick, and
   !> stick_time is the time in it.
   subroutine run_band(c, law, m, run, watch, error)
      type(machine_config), intent(in) :: c
      class(sliding_law), intent(in) :: law
      type(mechanics), intent(in) :: m
      type(machine_run), intent(inout) :: run
      class(step_watch), intent(inout) :: watch
      type(error_type), allocatable, intent(out) :: error
      type(machine_band), target :: stepper
      real(wp) :: z(max_law_states), t_grid
      integer :: i, k, ns, outcome, switches

      call stepper%start_from(c, law, c%t_start, .false., error)
      if (allocated(error)) return
      ns = stepper%band%frame%base%n_states
      call record(1, stepper%y)
      if (c%dense_output .and. stepper%locator%has_dense_output()) then
         call free_steps()
      else
         do i = 2, run%n
            t_grid = c%grid_time(i)
            switches = 0
            do while (stepper%t < t_grid)
               call stepper%advance(t_grid, outcome, error, watch)
               if (allocated(error)) exit
               call take(outcome)
               if (allocated(error)) exit
            end do
            if (allocated(error)) then
               call label(c, error)
               return
            end if
            call watch%check(stepper%t, error)
            if (allocated(error)) return
            call record(i, stepper%y)
         end do
      end if
      if (allocated(error)) return
      run%stick_time = stepper%band_time
      run%stats = stepper%statistics()

   contains

      !> Steps of the error control's own size to the last output time, the
      !> output points within each from its continuous extension (as
      !> run_smooth's): the grid no longer pins the steps.
      subroutine free_steps()
         real(wp), allocatable :: times(:), states(:, :)
         integer :: filled, j

         times = [(c%grid_time(j), j = 2, run%n)]
         allocate (states(size(stepper%y), size(times)))
         i = 1
         switches = 0
         do while (i <= size(times))
            call stepper%advance(times(size(times)), outcome, error, watch, .true., times(i:), states(:, i:), filled)
            if (allocated(error)) then
               call label(c, error)
               return
            end if
            do j = i, i + filled - 1
               call record(j + 1, states(:, j))
            end do
            if (filled > 0) switches = 0
            i = i + filled
            call take(outcome)
            if (allocated(error)) return
         end do
         call watch%check(stepper%t, error)
      end subroutine free_steps

      !> The event of an advance into the table; the edges' switches counted.
      subroutine take(outcome)
         integer, intent(in) :: outcome

         select case (outcome)
         case (band_hold)
            call add(event_slip_to_stick)
         case (band_cross)
            call add(event_slip_reversal)
         case (band_leave, band_hold_end)
            call add(event_stick_to_slip)
         end select
         if (any(outcome == [band_hold, band_cross, band_leave, band_exit, band_hold_end])) switches = switches + 1
         if (switches > max_switches) then
            call fatal_error(error, 'more than '//itoa(max_switches)//' switches at the band''s edges ' &
               & //'before t = '//rtoa(stepper%t)//' s: the block slides along an edge', error_numerical)
            call label(c, error)
         end if
      end subroutine take

      subroutine add(kind)
         integer, intent(in) :: kind

         call run%add_event(stepper%t, kind, stepper%y(1) + m%load * stepper%t, stepper%y(2))
      end subroutine add

      !> Output point i from the state y at its grid time.
      subroutine record(i, y)
         integer, intent(in) :: i
         real(wp), intent(in) :: y(:)
         real(wp) :: x

         z(1:ns) = y(3:2 + ns) * stepper%band%frame%base%scale(1:ns)
         run%t(i) = c%grid_time(i)
         x = y(1) + m%load * run%t(i)
         run%x(i) = x
         run%v(i) = y(2)
         run%force(i) = law%force(y(2) - m%belt, z(1:ns), m%normal, m%applied(run%t(i), x, y(2)))
         do k = 1, ns
            run%states(k, i) = z(k)
         end do
         if (abs(y(2) - m%belt) < stepper%band%half_width) run%stick(i) = 1
      end subroutine record
   end subroutine run_band

   !> The law's name before an integrator's message (a watch's names it already).
   subroutine label(c, error)
      type(machine_config), intent(in) :: c
      type(error_type), intent(inout) :: error

      if (index(error%message, 'machine, ') /= 1) error%message = 'machine, '//trim(c%law%model)//' law: ' &
         & //error%message
   end subroutine label

end module friction_machine_run
