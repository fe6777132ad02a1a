!> Event location on top of GSL odeiv2, which has none.
!>
!> An `event_system` is an ODE system with event functions g_k(t, y); an
!> event is a zero crossing of one of them in a chosen direction.  The
!> `event_locator` advances step by step with a GSL driver, watches the sign
!> of every g_k after each accepted step and, when one has crossed, finds
!> the crossing time to an absolute time tolerance: a first guess from the
!> step's cubic Hermite interpolant, then secants, with bisection as the
!> fallback (see locate).  Every trial time c of the root finder is reached
!> by integrating again from the start of the step to c with a second
!> driver (the probe), at the same tolerances: the event state is then an
!> integrated state, exact to the integrator's accuracy, not an
!> interpolant's (GSL's steppers offer no common dense output).  The probe
!> leaves the main driver untouched, so after a non-terminal event
!> (a Poincaré section, a diagnostic threshold) the integration goes on
!> exactly as without it, multistep history included.
!>
!> A function can cross zero and come back within one step, so that its
!> values at the step's ends agree in sign (a large step of an implicit or
!> extrapolation method over a short dip).  After every step the locator
!> therefore also follows g_k along the step's cubic Hermite interpolant
!> (the right-hand side at both ends: one extra evaluation per step, the
!> start's being the previous end's): the values and slopes of g_k at the
!> step's ends define a cubic, exact when g_k is linear in the state, whose
!> extrema show a dip; a probe confirms it.  A dip shallower than the
!> interpolant's error, O(h⁴), can still go unseen; the integration
!> tolerance bounds that.
!>
!> A crossing is a strict change of sign: a zero is no information (a
!> function that touches zero and turns back has not crossed).  The located
!> time is the end of the final bracket on the far side of the crossing: g_k
!> there has, strictly, the sign it has after the event, so a caller that
!> switches models at the event never starts the new one on the wrong side,
!> and a restart there does not see the same event again.  A function that
!> is exactly zero at a restart counts as being on the near side of its
!> crossing (+ for falling, - for rising events); one that then moves to the
!> far side crosses at once.
!>
!> Guards: a step budget over all steps since init (max_steps), the
!> driver's smallest step (h_min) and a wall-clock limit (max_wall_time),
!> each a numerical error naming the stepper, the time reached and the
!> reason.
module friction_ode_events
   use friction_kinds, only: wp, i8
   use friction_error, only: error_type, fatal_error, error_numerical, error_internal
   use friction_strings, only: itoa, rtoa
   use friction_ode_system, only: ode_system
   use friction_ode_solver, only: ode_solver, solver_settings, integrator_statistics
   use friction_ode_watch, only: step_watch
   implicit none
   private

   public :: event_system, event_locator, event_hit
   public :: event_rising, event_falling, event_either

   !> Directions of a crossing: g goes from - to + (rising), + to - (falling).
   integer, parameter :: event_rising = 1, event_falling = -1, event_either = 0


   !> An ODE system with event functions.
   type, abstract, extends(ode_system) :: event_system
   contains
      procedure(event_count_interface), deferred :: event_count
      procedure(event_values_interface), deferred :: event_values
   end type event_system

   abstract interface
      !> Number of event functions.
      pure function event_count_interface(self) result(n)
         import :: event_system
         class(event_system), intent(in) :: self
         integer :: n
      end function event_count_interface

      !> g(k) = g_k(t, y) for every event function k.
      pure subroutine event_values_interface(self, t, y, g)
         import :: event_system, wp
         class(event_system), intent(in) :: self
         real(wp), intent(in) :: t
         real(wp), intent(in) :: y(:)
         real(wp), intent(out) :: g(:)
      end subroutine event_values_interface
   end interface

   !> One located event.
   type :: event_hit
      integer :: which = 0          !! the event function that crossed zero
      integer :: direction = 0      !! event_rising or event_falling
      logical :: terminal = .false. !! the integration stopped here
      real(wp) :: t = 0.0_wp        !! crossing time, far side, within the tolerance
      real(wp), allocatable :: y(:) !! the state at t (dimension() entries, allocated by init)
   end type event_hit

   !> Step-by-step integration with event location.  The system must
   !> outlive the locator and stay where it is (the GSL drivers point at it).
   type :: event_locator
      private
      class(event_system), pointer :: system => null()
      type(ode_solver) :: main
      type(ode_solver) :: probe
      integer :: n = 0                     !! state dimension
      integer :: m = 0                     !! number of event functions
      integer, allocatable :: direction(:)
      logical, allocatable :: terminal(:)
      integer, allocatable :: last_sign(:) !! sign of g_k on the near side; 0 unknown
      real(wp), allocatable :: g(:)        !! g at the current point
      real(wp), allocatable :: f(:)        !! the right-hand side at the current point
      !> advance's room, allocated by init (none at each step): the step's
      !> start and its field, a trial state; g at the start, at a trial and
      !> the slopes of g at the step's ends
      real(wp), allocatable :: y0(:), f0(:), yc(:), g0(:), gc(:), slope0(:), slope1(:)
      logical :: f_valid = .false.         !! f is up to date (not after a restart)
      real(wp) :: tolerance = 1.0e-10_wp   !! absolute, in the system's time
      real(wp) :: h_first = 1.0e-6_wp      !! first step when nothing better is known
      real(wp) :: h_min = 0.0_wp           !! smallest step of the main integration
      integer(i8) :: max_steps = 0
      integer(i8) :: steps = 0             !! accepted main steps since init
      integer(i8) :: located = 0           !! events located since init
      integer(i8) :: probes = 0            !! probe integrations since init
      integer(i8) :: extra_rhs = 0         !! right-hand sides for interpolants
      real(wp) :: max_wall_time = 0.0_wp
      integer(i8) :: clock_start = 0, clock_rate = 1
      character(len=16) :: method = ''
      character(len=8) :: time_name = 't', time_unit = ' s'
      logical :: ready = .false.
      !> Events of the last advance, in time order; a terminal one is last.
      !> (Up to two per function and step: out across zero and back.)
      type(event_hit), allocatable, public :: hits(:)
      integer, public :: n_hits = 0
   contains
      procedure :: init
      procedure :: restart
      procedure :: advance
      procedure :: statistics
      procedure :: steps_taken
      procedure :: events_located
      procedure :: probes_taken
      procedure :: elapsed
      procedure :: has_dense_output
      procedure :: dense_output
      procedure, private :: locate
   end type event_locator

contains

   !> Whether the main stepper has a continuous extension (dense_output).
   logical function has_dense_output(self)
      class(event_locator), intent(in) :: self

      has_dense_output = self%main%has_dense_output()
   end function has_dense_output

   !> The state at t within the main stepper's last step, from its
   !> continuous extension: after an advance, any t since the start of that
   !> step up to the time reached (a located event's too: the step that found
   !> it spans it), until the next restart.
   subroutine dense_output(self, t, y, error)
      class(event_locator), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(out) :: y(:)
      type(error_type), allocatable, intent(out) :: error

      call self%main%dense_output(t, y, error)
   end subroutine dense_output

   !> Bind to a system.  direction(k) is event_rising, event_falling or
   !> event_either; terminal(k) stops the integration at event k.
   !> time_tolerance bounds the error of located times.  h_first is the
   !> first step when settings%h_start is 0 and a restart asks to continue
   !> before any step was taken.  time_name and time_unit label times in
   !> messages ('τ', '' for a nondimensional time).
   subroutine init(self, system, settings, direction, terminal, time_tolerance, h_first, error, &
      & time_name, time_unit)
      class(event_locator), intent(inout) :: self
      class(event_system), target, intent(in) :: system
      type(solver_settings), intent(in) :: settings
      integer, intent(in) :: direction(:)
      logical, intent(in) :: terminal(:)
      real(wp), intent(in) :: time_tolerance, h_first
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in), optional :: time_name, time_unit
      type(solver_settings) :: probe_settings
      integer :: k

      self%system => system
      self%n = system%dimension()
      self%m = system%event_count()
      if (size(direction) /= self%m .or. size(terminal) /= self%m) then
         call fatal_error(error, 'event locator: inconsistent event settings', error_internal)
         return
      end if
      if (.not. (time_tolerance > 0.0_wp)) then
         call fatal_error(error, 'event locator: the time tolerance must be > 0', error_internal)
         return
      end if
      self%direction = direction
      self%terminal = terminal
      self%tolerance = time_tolerance
      self%max_steps = settings%max_steps
      self%max_wall_time = settings%max_wall_time
      self%h_min = settings%h_min
      self%method = settings%method
      if (present(time_name)) self%time_name = time_name
      if (present(time_unit)) self%time_unit = time_unit
      self%h_first = h_first
      if (settings%h_start > 0.0_wp) self%h_first = settings%h_start
      ! GSL refuses an h_min above the current step (the solver reports that).
      self%h_first = max(self%h_first, settings%h_min)
      if (.not. (self%h_first > 0.0_wp)) then
         call fatal_error(error, 'event locator: the first step must be > 0', error_internal)
         return
      end if
      call self%main%init(system, settings, self%h_first, error)
      if (allocated(error)) return
      ! The probe re-integrates parts of accepted steps, which may be as short
      ! as the root finder needs: h_min guards the main integration only.
      probe_settings = settings
      probe_settings%h_min = 0.0_wp
      call self%probe%init(system, probe_settings, self%h_first, error)
      if (allocated(error)) return
      call self%main%set_time_label(trim(self%time_name), trim(self%time_unit))
      call self%probe%set_time_label(trim(self%time_name), trim(self%time_unit))
      if (allocated(self%hits)) deallocate (self%hits)
      allocate (self%hits(max(1, 2 * self%m)))
      do k = 1, size(self%hits)
         allocate (self%hits(k)%y(self%n))
         self%hits(k)%y = 0.0_wp
      end do
      if (allocated(self%g)) deallocate (self%last_sign, self%g, self%f, self%y0, self%f0, self%yc, self%g0, &
         & self%gc, self%slope0, self%slope1)
      allocate (self%last_sign(self%m), self%g(self%m), self%f(self%n), self%y0(self%n), self%f0(self%n), &
         & self%yc(self%n), self%g0(self%m), self%gc(self%m), self%slope0(self%m), self%slope1(self%m))
      self%f = 0.0_wp
      self%steps = 0
      self%located = 0
      self%probes = 0
      self%extra_rhs = 0
      self%n_hits = 0
      call system_clock(self%clock_start, self%clock_rate)
      self%ready = .false.
   end subroutine init

   !> Start from (t, y): a new initial condition or changed system
   !> parameters.  h_start > 0 is the first step; h_start <= 0 keeps the
   !> step size the driver would have tried next (continuation).
   subroutine restart(self, t, y, h_start)
      class(event_locator), intent(inout) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: y(:)
      real(wp), intent(in) :: h_start
      real(wp) :: h
      integer :: k

      h = h_start
      if (.not. (h > 0.0_wp) .and. self%steps > 0) h = self%main%step_size()
      if (.not. (h > 0.0_wp)) h = self%h_first
      h = max(h, self%h_min)
      call self%main%restart(h)
      call self%system%event_values(t, y(1:self%n), self%g)
      do k = 1, self%m
         self%last_sign(k) = near_sign(self%g(k), self%direction(k))
      end do
      self%n_hits = 0
      self%f_valid = .false.
      self%ready = .true.
   end subroutine restart

   !> Advance (t, y) towards t1 step by step.  Returns at t1, or after the
   !> first step in which events happened: those are in hits(1:n_hits) in
   !> time order.  If one of them is terminal it is the last, and (t, y) is
   !> its state: call restart before going on.  Otherwise (t, y) is the end
   !> of that step and advance may simply be called again.  A watch, if
   !> given, is asked every 16 steps (with the wall-clock limit): its error
   !> ends the advance there.  `single`: return after one accepted step even
   !> without events (a caller that carries something over each step).
   subroutine advance(self, t, t1, y, error, watch, single)
      class(event_locator), intent(inout) :: self
      real(wp), intent(inout) :: t
      real(wp), intent(in) :: t1
      real(wp), intent(inout) :: y(:)
      type(error_type), allocatable, intent(out) :: error
      class(step_watch), intent(inout), optional :: watch
      logical, intent(in), optional :: single
      logical :: one

      self%n_hits = 0
      if (.not. self%ready) then
         call fatal_error(error, 'event locator: advance before restart', error_internal)
         return
      end if
      one = .false.
      if (present(single)) one = single
      call advance_steps(self, t, t1, y, error, watch, self%n, self%m, self%y0, self%f0, self%yc, self%f, &
         & self%g0, self%gc, self%slope0, self%slope1, one)
   end subroutine advance

   !> advance's steps, with the locator's room (allocated by init: nothing
   !> is allocated at a step) as arrays of their own, not touched through
   !> self here: the step's start y0 and its field f0, a trial state yc, the
   !> field f at the current point; g at the step's start g0 and at a trial
   !> gc, and its slopes at the step's ends.  (Explicit shapes: the hot loop
   !> indexes them without reloading the components' descriptors.)
   subroutine advance_steps(self, t, t1, y, error, watch, n, m, y0, f0, yc, f, g0, gc, slope0, slope1, one)
      class(event_locator), intent(inout) :: self
      real(wp), intent(inout) :: t
      real(wp), intent(in) :: t1
      real(wp), intent(inout) :: y(:)
      type(error_type), allocatable, intent(out) :: error
      class(step_watch), intent(inout), optional :: watch
      integer, intent(in) :: n, m
      logical, intent(in) :: one
      real(wp), intent(inout) :: y0(n), f0(n), yc(n), f(n), g0(m), gc(m), slope0(m), slope1(m)
      real(wp) :: t0, tc, theta, h
      integer :: k, nfound, i, j, first_terminal, near
      real(wp), parameter :: nudge = 1.0e-3_wp

      do while (t < t1)
         t0 = t
         y0(1:n) = y(1:n)
         g0(1:m) = self%g
         if (.not. self%f_valid) then
            call self%system%rhs(t0, y0(1:n), f)
            self%extra_rhs = self%extra_rhs + 1
         end if
         f0(1:n) = f
         call self%main%step(t, t1, y(1:n), error)
         if (allocated(error)) return
         self%steps = self%steps + 1
         if (self%max_steps > 0 .and. self%steps > self%max_steps) then
            call fatal_error(error, trim(self%method)//': more than max_steps = '//itoa(self%max_steps) &
               & //' steps at '//self%main%time_at(t)//' (the step budget of the whole run)', &
               & error_numerical)
            return
         end if
         ! (The clock every 16 steps: reading it at every step is dear.)
         if (self%max_wall_time > 0.0_wp .and. mod(self%steps, 16_i8) == 0) then
            if (self%elapsed() > self%max_wall_time) then
               call fatal_error(error, trim(self%method)//': max_wall_time = '//rtoa(self%max_wall_time) &
                  & //' s reached at '//self%main%time_at(t)//' after '//itoa(self%steps)//' steps', &
                  & error_numerical)
               return
            end if
         end if
         if (present(watch) .and. mod(self%steps, 16_i8) == 0) then
            call watch%check(t, error)
            if (allocated(error)) return
         end if
         call self%system%rhs(t, y(1:n), f)
         self%extra_rhs = self%extra_rhs + 1
         self%f_valid = .true.
         call self%system%event_values(t, y(1:n), self%g)
         nfound = 0
         h = t - t0
         ! Slopes dg/dθ at both ends, by differences along the step's Hermite
         ! interpolant (θ = (t - t0)/h): with g at the ends they define a
         ! cubic in θ for each g_k, exact when g_k is linear in the state.
         if (self%m > 0) then
            call hermite(nudge, h, y0(1:n), f0(1:n), y(1:n), f, yc(1:n))
            call self%system%event_values(t0 + nudge * h, yc(1:n), gc(1:m))
            slope0(1:m) = (gc(1:m) - g0(1:m)) / nudge
            call hermite(1.0_wp - nudge, h, y0(1:n), f0(1:n), y(1:n), f, &
               & yc(1:n))
            call self%system%event_values(t - nudge * h, yc(1:n), gc(1:m))
            slope1(1:m) = (self%g - gc(1:m)) / nudge
         end if
         do k = 1, self%m
            near = self%last_sign(k)
            if (crossed(near, self%g(k), self%direction(k))) then
               nfound = nfound + 1
               call self%locate(k, t0, y0(1:n), g0(k), t, y(1:n), -near, &
                  & self%hits(nfound)%t, self%hits(nfound)%y(1:n), error)
               call describe(self%hits(nfound), k, -near)
               if (allocated(error)) return
               cycle
            end if
            if (near == 0) cycle
            ! No change of sign between the ends, but g may have dipped across
            ! zero and back inside the step: look at the extrema of its cubic,
            ! and confirm a dip with a probe.
            theta = dip(g0(k), self%g(k), slope0(k), slope1(k), near)
            if (theta < 0.0_wp) cycle
            tc = t0
            yc(1:n) = y0(1:n)
            call self%probe%restart(theta * h)
            call self%probe%advance(tc, t0 + theta * h, yc(1:n), error)
            self%probes = self%probes + 1
            if (allocated(error)) return
            call self%system%event_values(tc, yc(1:n), gc(1:m))
            if (gc(k) == 0.0_wp .or. (gc(k) > 0.0_wp .eqv. near > 0)) cycle   ! the interpolant erred
            ! Out across zero ...
            if (crossed(near, gc(k), self%direction(k))) then
               nfound = nfound + 1
               call self%locate(k, t0, y0(1:n), g0(k), tc, yc(1:n), -near, &
                  & self%hits(nfound)%t, self%hits(nfound)%y(1:n), error)
               call describe(self%hits(nfound), k, -near)
               if (allocated(error)) return
            end if
            ! ... and back, if that direction counts.
            if (crossed(-near, self%g(k), self%direction(k))) then
               nfound = nfound + 1
               call self%locate(k, tc, yc(1:n), gc(k), t, y(1:n), near, &
                  & self%hits(nfound)%t, self%hits(nfound)%y(1:n), error)
               call describe(self%hits(nfound), k, near)
               if (allocated(error)) return
            end if
         end do
         do k = 1, self%m
            if (self%g(k) /= 0.0_wp) self%last_sign(k) = int(sign(1.0_wp, self%g(k)))
         end do
         if (nfound == 0) then
            if (one) return
            cycle
         end if
         do i = 1, nfound
            self%hits(i)%terminal = self%terminal(self%hits(i)%which)
         end do
         ! Time order (few events per step: insertion sort by exchanges,
         ! which move the states' arrays instead of copying them).
         do i = 2, nfound
            j = i
            do while (j > 1)
               if (self%hits(j - 1)%t <= self%hits(j)%t) exit
               call exchange(self%hits(j - 1), self%hits(j))
               j = j - 1
            end do
         end do
         first_terminal = 0
         do i = 1, nfound
            if (self%hits(i)%terminal) then
               first_terminal = i
               exit
            end if
         end do
         if (first_terminal > 0) then
            nfound = first_terminal
            t = self%hits(nfound)%t
            y(1:n) = self%hits(nfound)%y(1:n)
            self%ready = .false.
         end if
         self%n_hits = nfound
         self%located = self%located + nfound
         return
      end do
   end subroutine advance_steps

   !> Swap two hits (their states by moving the allocations).
   subroutine exchange(a, b)
      type(event_hit), intent(inout) :: a, b
      real(wp), allocatable :: y(:)
      integer :: which, direction
      logical :: terminal
      real(wp) :: t

      which = a%which
      direction = a%direction
      terminal = a%terminal
      t = a%t
      a%which = b%which
      a%direction = b%direction
      a%terminal = b%terminal
      a%t = b%t
      b%which = which
      b%direction = direction
      b%terminal = terminal
      b%t = t
      call move_alloc(a%y, y)
      call move_alloc(b%y, a%y)
      call move_alloc(y, b%y)
   end subroutine exchange

   !> Record which function crossed and in which direction.
   subroutine describe(hit, k, direction)
      type(event_hit), intent(inout) :: hit
      integer, intent(in) :: k, direction

      hit%which = k
      hit%direction = direction
   end subroutine describe

   !> Where the cubic p on [0, 1] with p(0) = g0, p(1) = g1, p'(0) = d0,
   !> p'(1) = d1 reaches furthest to the side opposite near, if it crosses
   !> zero there; -1 if it stays on the near side.  (Both ends are on the
   !> near side.)
   pure real(wp) function dip(g0, g1, d0, d1, near) result(theta)
      real(wp), intent(in) :: g0, g1, d0, d1
      integer, intent(in) :: near
      real(wp) :: a, b, c, disc, roots(2), p, best, q
      integer :: i

      ! p = g0 + d0 θ + c2 θ² + c3 θ³ with the Hermite coefficients.
      a = 3.0_wp * (2.0_wp * (g0 - g1) + d0 + d1)           ! p' = a θ² + b θ + c
      b = 2.0_wp * (3.0_wp * (g1 - g0) - 2.0_wp * d0 - d1)
      c = d0
      theta = -1.0_wp
      roots = -1.0_wp
      if (abs(a) > 1.0e-14_wp * (abs(b) + abs(c))) then
         disc = b * b - 4.0_wp * a * c
         if (disc < 0.0_wp) return
         q = -0.5_wp * (b + sign(sqrt(disc), b))
         roots(1) = q / a
         if (q /= 0.0_wp) roots(2) = c / q
      else if (b /= 0.0_wp) then
         roots(1) = -c / b
      end if
      best = 0.0_wp
      do i = 1, 2
         if (.not. (roots(i) > 0.0_wp .and. roots(i) < 1.0_wp)) cycle
         q = roots(i)
         p = g0 + q * (d0 + q * (b / 2.0_wp + q * a / 3.0_wp))
         ! Far side: sign opposite near; keep the furthest.
         if (p * near < best) then
            best = p * near
            theta = q
         end if
      end do
   end function dip

   !> The cubic Hermite interpolant at θ in [0, 1] of a step of length h
   !> from (y0, f0) to (y1, f1): error O(h⁴).
   !> (A subroutine, not a function: a function's result of this size
   !> would be allocated on the heap at every call.)
   pure subroutine hermite(theta, h, y0, f0, y1, f1, y)
      real(wp), intent(in) :: theta, h, y0(:), f0(:), y1(:), f1(:)
      real(wp), intent(out) :: y(:)

      y = (2.0_wp * theta**3 - 3.0_wp * theta**2 + 1.0_wp) * y0 &
         & + (theta**3 - 2.0_wp * theta**2 + theta) * h * f0 &
         & + (-2.0_wp * theta**3 + 3.0_wp * theta**2) * y1 &
         & + (theta**3 - theta**2) * h * f1
   end subroutine hermite

   !> The crossing of g_k in [ta, tb], where g_k(ta) = ga is on the near side
   !> and g_k(tb) on the far side, whose sign is far.  Returns the far end of
   !> a bracket no wider than the tolerance, and its state.
   !>
   !> Every trial time c is reached by a probe integration from (ta, ya), so
   !> g_k(c) is exact to the integrator's tolerance.  The first trial is the
   !> zero of g_k along the cubic Hermite interpolant of the step (two extra
   !> right-hand sides, error O(h⁴)); the next ones are secants through the
   !> last two trials, kept half a tolerance inside the bracket so that a
   !> good guess closes it from both sides at once.  Bisection takes over if
   !> that stalls.  Typically three or four probes per event.
   subroutine locate(self, k, ta, ya, ga, tb, yb, far, t_event, y_event, error)
      class(event_locator), intent(inout) :: self
      integer, intent(in) :: k, far
      real(wp), intent(in) :: ta, ya(:), ga, tb, yb(:)
      real(wp), intent(out) :: t_event, y_event(:)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: a, b, c, gc_k, tc, yc(self%n), gc(self%m), fa(self%n), fb(self%n)
      real(wp) :: t_prev, g_prev, t_last, g_last, half
      integer :: iteration
      integer, parameter :: max_iterations = 200, secant_iterations = 8

      call self%system%rhs(ta, ya, fa)
      call self%system%rhs(tb, yb, fb)
      self%extra_rhs = self%extra_rhs + 2
      a = ta
      b = tb
      y_event = yb
      call self%system%event_values(tb, yb, gc)
      t_prev = ta
      g_prev = ga
      t_last = tb
      g_last = gc(k)
      half = 0.5_wp * self%tolerance
      do iteration = 1, max_iterations
         if (b - a <= self%tolerance .or. b - a <= 4.0_wp * spacing(max(abs(a), abs(b)))) exit
         if (iteration == 1) then
            c = interpolant_zero(self, k, ta, ya, fa, tb, yb, fb, ga, g_last, far)
         else if (iteration <= secant_iterations .and. g_last /= g_prev) then
            c = t_last - g_last * (t_last - t_prev) / (g_last - g_prev)
         else
            c = 0.5_wp * (a + b)
         end if
         if (.not. (c == c)) c = 0.5_wp * (a + b)
         if (b - a > 2.0_wp * self%tolerance) then
            c = min(max(c, a + half), b - half)
         else
            c = 0.5_wp * (a + b)
         end if
         tc = ta
         yc = ya
         call self%probe%restart(c - ta)
         call self%probe%advance(tc, c, yc, error)
         self%probes = self%probes + 1
         if (allocated(error)) then
            error%message = error%message//' (locating an event)'
            return
         end if
         call self%system%event_values(c, yc, gc)
         gc_k = gc(k)
         if (on_far_side(gc_k, far)) then
            b = c
            y_event = yc
         else
            a = c
         end if
         t_prev = t_last
         g_prev = g_last
         t_last = c
         g_last = gc_k
      end do
      t_event = b
   end subroutine locate

   !> Zero of g_k along the cubic Hermite interpolant of the step, by
   !> Illinois iterations (event functions only, no integration).
   function interpolant_zero(self, k, ta, ya, fa, tb, yb, fb, ga, gb, far) result(t)
      class(event_locator), intent(in) :: self
      integer, intent(in) :: k, far
      real(wp), intent(in) :: ta, ya(:), fa(:), tb, yb(:), fb(:), ga, gb
      real(wp) :: t
      real(wp) :: a, b, ya_(self%n), g(self%m), va, vb, vc, h, theta
      integer :: iteration, side

      h = tb - ta
      a = ta
      b = tb
      va = ga
      vb = gb
      side = 0
      t = b
      do iteration = 1, 100
         if (b - a <= 1.0e-3_wp * self%tolerance .or. b - a <= 4.0_wp * spacing(max(abs(a), abs(b)))) exit
         if (vb /= va) then
            t = b - vb * (b - a) / (vb - va)
         else
            t = 0.5_wp * (a + b)
         end if
         if (.not. (t > a .and. t < b)) t = 0.5_wp * (a + b)
         theta = (t - ta) / h
         call hermite(theta, h, ya, fa, yb, fb, ya_)
         call self%system%event_values(t, ya_, g)
         vc = g(k)
         if (on_far_side(vc, far)) then
            b = t
            vb = vc
            if (side == 1) va = 0.5_wp * va
            side = 1
         else
            a = t
            va = vc
            if (side == -1) vb = 0.5_wp * vb
            side = -1
         end if
      end do
      t = b
   end function interpolant_zero

   !> Whether g is strictly on the far side of a crossing (sign far).
   pure logical function on_far_side(g, far)
      real(wp), intent(in) :: g
      integer, intent(in) :: far

      on_far_side = g /= 0.0_wp .and. (g > 0.0_wp .eqv. far > 0)
   end function on_far_side

   !> The sign g counts as before an event of the direction: its own sign,
   !> or for g = 0 the near side of the crossing (0 for either direction).
   pure integer function near_sign(g, direction)
      real(wp), intent(in) :: g
      integer, intent(in) :: direction

      if (g > 0.0_wp) then
         near_sign = 1
      else if (g < 0.0_wp) then
         near_sign = -1
      else
         near_sign = -direction
      end if
   end function near_sign

   !> A crossing in the allowed direction from the last known sign to g.
   pure logical function crossed(last_sign, g, direction)
      integer, intent(in) :: last_sign, direction
      real(wp), intent(in) :: g

      crossed = .false.
      if (last_sign == 1 .and. g < 0.0_wp) crossed = direction /= event_rising
      if (last_sign == -1 .and. g > 0.0_wp) crossed = direction /= event_falling
   end function crossed

   !> Integrator counters of both drivers.
   function statistics(self) result(stats)
      class(event_locator), intent(in) :: self
      type(integrator_statistics) :: stats

      stats = self%main%statistics()
      call stats%add(self%probe%statistics())
      stats%rhs_evaluations = stats%rhs_evaluations + self%extra_rhs
   end function statistics

   pure function steps_taken(self) result(n)
      class(event_locator), intent(in) :: self
      integer(i8) :: n

      n = self%steps
   end function steps_taken

   pure function events_located(self) result(n)
      class(event_locator), intent(in) :: self
      integer(i8) :: n

      n = self%located
   end function events_located

   !> Probe integrations (root-finder trials) since init: the cost of location.
   pure function probes_taken(self) result(n)
      class(event_locator), intent(in) :: self
      integer(i8) :: n

      n = self%probes
   end function probes_taken

   !> Wall-clock seconds since init.
   function elapsed(self) result(seconds)
      class(event_locator), intent(in) :: self
      real(wp) :: seconds
      integer(i8) :: now

      call system_clock(now)
      seconds = real(now - self%clock_start, wp) / real(self%clock_rate, wp)
   end function elapsed

end module friction_ode_events
