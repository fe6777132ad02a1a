!> The machine with a law whose force jumps at the edges of a zero-velocity
!> band (Karnopp's: |w| < Δv holds the applied force A up to F_s; docs/chaos.md,
!> "Karnopp's band"), run with the band's edges and the ends of its holds as
!> located events and, when asked, the tangent Φ carried through a saltation
!> at each jump.  The run (run.f90), Benettin's two runs and the spectrum
!> (lyapunov.f90) and the orbit's return map (orbit.f90) all step it.
!>
!> Coordinates: the load point's frame, e = x - load_velocity t (e = x on the
!> belt), as the orbit's section takes them.
!>
!> - an edge w = ±Δv crossed: the saltation across h = w ∓ Δv, f⁻ and f⁺ the
!>   fields on the two sides.  Entering, the block is put at the closest
!>   velocity inside the edge (the band's limit of no depth: where the step
!>   left it, a located time's distance inside, would set when a hold there
!>   ends); with |A| <= F_s it holds there (v' = 0 exactly, f⁺_v = 0: δv
!>   forgotten, the direction the spectrum reports as lost);
!> - a hold at an edge ends where |A| reaches the hold's limit pushing
!>   outwards, F_h = max(F_s, F_e) with F_e the force just outside the edge:
!>   the block leaves at once, through the saltation from the hold's field
!>   into the outside one across h = F_h - σA (∂h/∂t of a moving support
!>   included).  With F_e > F_s, a pull σA between the two drives the block
!>   out of the band and the slip force back in: the block slides along the
!>   edge (Filippov's sliding mode), v' = 0 with the friction equal to the
!>   pull, a hold like the band's own, entered from either side; it ends
!>   where σA = F_e, the force continuous there (the saltation the identity
!>   but for the states' rounding).
!>   The hold is known by the edge it was entered at, not by v: the step that
!>   reaches the force's event may move v by units of its last place, out
!>   past the edge, so that the edge's event may even come first.  Pushing
!>   inwards, or from a hold inside the band, it is a kink of the clipped
!>   force, no jump.
module friction_machine_band
   use friction_kinds, only: wp
   use friction_error, only: error_type, fatal_error, error_numerical
   use friction_strings, only: rtoa, itoa
   use friction_ode_system, only: ode_system
   use friction_ode_solver, only: solver_settings, integrator_statistics
   use friction_ode_events, only: event_system, event_locator, event_either, event_rising
   use friction_ode_watch, only: step_watch
   use friction_analysis_lyapunov_spectrum, only: tangent_system, pack_tangent, unpack_tangent
   use friction_law, only: sliding_law, max_law_states, band_edge_velocity, band_hold_limit, sliding_at_edge
   use friction_machine_config, only: machine_config
   use friction_machine_model, only: mechanics, machine_smooth
   use friction_machine_piecewise, only: piecewise_run
   implicit none
   private

   public :: load_frame, band_frame, machine_band, band_frame_of, band_start_state
   public :: max_switches
   public :: band_none, band_hold, band_cross, band_leave, band_exit, band_hold_end, band_pull, band_at_section

   !> What one advance of machine_band ended at: t_target (none); the band
   !> entered into a hold at an edge (hold) or not held, to cross it (cross);
   !> the band left after a hold in it (leave) or after crossing it (exit); a
   !> hold at an edge ended, the block out at once (hold_end); the applied
   !> force at ±F_s without a jump (pull); the section v = load_velocity (section).
   integer, parameter :: band_none = 0, band_hold = 1, band_cross = 2, band_leave = 3, band_exit = 4, &
      & band_hold_end = 5, band_pull = 6, band_at_section = 7

   !> Switches at the band's edges within one advance_to (or one output
   !> interval of the run) beyond which the edges are taken to chatter.
   integer, parameter :: max_switches = 1000000

   !> The machine in the load point's frame: y = (e, v, ẑ), e = x - load t.
   type, extends(ode_system) :: load_frame
      type(machine_smooth) :: base
   contains
      procedure :: dimension => frame_dimension
      procedure :: relative_component => frame_relative_component
      procedure :: rhs => frame_rhs
      procedure :: jacobian => frame_jacobian
   end type load_frame

   !> The load point's frame with the events of a law's band |w| < Δv
   !> (Karnopp's): its edges w = ±Δv (1, 2), the applied force at ±F_s (3,
   !> 4: where a hold in the band ends; located so that no step straddles the
   !> kink of the clipped force), at ±hold_limit instead outwards from a hold
   !> at an edge, and, when sectioned, v = load_velocity (5).
   type, extends(event_system) :: band_frame
      type(load_frame) :: frame
      real(wp) :: half_width = 0.0_wp, limit = 0.0_wp
      real(wp) :: hold_limit = 0.0_wp   !! the largest pull a hold at an edge keeps (band_hold_limit)
      real(wp) :: held_at = 0.0_wp      !! the sign of the edge held at (0: none): v' = 0 in its sliding mode
      logical :: sectioned = .false.
   contains
      procedure :: set_limits => band_set_limits
      procedure :: dimension => band_dimension
      procedure :: rhs => band_rhs
      procedure :: jacobian => band_jacobian
      procedure :: event_count => band_event_count
      procedure :: event_values => band_event_values
   end type band_frame

   !> A run through the band's switches (module comment), with Φ beside the
   !> state when `tangent`.  Declare it `target`: its locator points at its frame.
   type, extends(piecewise_run) :: machine_band
      type(band_frame), allocatable :: band
      type(tangent_system), allocatable :: extended   !! the band's frame with its tangent (when tangent)
      type(event_locator) :: locator
      logical :: tangent = .false.
      !> In a hold at an edge Φ is set to 0: without a moving support what is left is a shift in time
      !> (an autonomous section map's choice).
      logical :: project_in_hold = .false.
      real(wp) :: hold_edge = 0.0_wp   !! the sign of the edge the block holds at (0: none)
      logical :: held = .false.        !! held in the band since it was entered: leaving it is a slip onset
      real(wp) :: band_time = 0.0_wp   !! s inside the band since the start
   contains
      procedure :: start => band_start
      procedure :: start_from => band_start_from
      procedure :: advance => band_advance
      procedure :: advance_to => band_advance_to
      procedure :: reset => band_reset
      procedure :: inside => band_inside
      procedure :: is_held => band_inside
      procedure :: statistics => band_statistics
   end type machine_band

contains

   ! ---- the load point's frame ----

   pure integer function frame_dimension(self)
      class(load_frame), intent(in) :: self

      frame_dimension = self%base%dimension()
   end function frame_dimension

   !> The base's (y(2) is v in this frame too).
   pure subroutine frame_relative_component(self, index, reference, floor)
      class(load_frame), intent(in) :: self
      integer, intent(out) :: index
      real(wp), intent(out) :: reference, floor

      call self%base%relative_component(index, reference, floor)
   end subroutine frame_relative_component

   pure subroutine frame_rhs(self, t, y, dydt)
      class(load_frame), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in), contiguous :: y(:)
      real(wp), intent(out), contiguous :: dydt(:)
      real(wp) :: moved(size(y))

      moved = y
      moved(1) = y(1) + self%base%m%load * t
      call self%base%rhs(t, moved, dydt)
      dydt(1) = y(2) - self%base%m%load
   end subroutine frame_rhs

   pure subroutine frame_jacobian(self, t, y, dfdy, dfdt)
      class(load_frame), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: y(:)
      real(wp), intent(out) :: dfdy(:, :)
      real(wp), intent(out) :: dfdt(:)
      real(wp) :: moved(size(y))

      moved = y
      moved(1) = y(1) + self%base%m%load * t
      call self%base%jacobian(t, moved, dfdy, dfdt)
      ! d/dt at fixed e moves x with the load point.
      dfdt = dfdt + dfdy(:, 1) * self%base%m%load
      dfdt(1) = 0.0_wp
   end subroutine frame_jacobian

   ! ---- the band's events ----

   pure integer function band_dimension(self)
      class(band_frame), intent(in) :: self

      band_dimension = self%frame%dimension()
   end function band_dimension

   !> The band's half-width, its limit and a hold's limit, from the frame's law.
   subroutine band_set_limits(self)
      class(band_frame), intent(inout) :: self

      call self%frame%base%law%band(self%half_width, self%limit)
      self%hold_limit = band_hold_limit(self%frame%base%law, self%frame%base%m%normal)
   end subroutine band_set_limits

   !> Whether the state is in the sliding mode of the hold at an edge (the
   !> pull outwards beyond F_s): its field's v' is 0, not the law's.
   pure logical function sliding(self, t, y)
      class(band_frame), intent(in) :: self
      real(wp), intent(in) :: t, y(:)

      sliding = .false.
      ! (A band without a sliding mode keeps the law's field: the steps past a hold's end at F_s, as before.)
      if (self%held_at == 0.0_wp .or. .not. self%hold_limit > self%limit) return
      associate (m => self%frame%base%m)
         sliding = sliding_at_edge(self%held_at, m%applied(t, y(1) + m%load * t, y(2)), self%limit)
      end associate
   end function sliding

   pure subroutine band_rhs(self, t, y, dydt)
      class(band_frame), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in), contiguous :: y(:)
      real(wp), intent(out), contiguous :: dydt(:)

      call self%frame%rhs(t, y, dydt)
      if (sliding(self, t, y)) dydt(2) = 0.0_wp
   end subroutine band_rhs

   pure subroutine band_jacobian(self, t, y, dfdy, dfdt)
      class(band_frame), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: y(:)
      real(wp), intent(out) :: dfdy(:, :)
      real(wp), intent(out) :: dfdt(:)

      call self%frame%jacobian(t, y, dfdy, dfdt)
      if (sliding(self, t, y)) then
         dfdy(2, :) = 0.0_wp
         dfdt(2) = 0.0_wp
      end if
   end subroutine band_jacobian

   pure integer function band_event_count(self)
      class(band_frame), intent(in) :: self

      band_event_count = merge(5, 4, self%sectioned)
   end function band_event_count

   pure subroutine band_event_values(self, t, y, g)
      class(band_frame), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: y(:)
      real(wp), intent(out) :: g(:)
      real(wp) :: w, a

      associate (m => self%frame%base%m)
         w = y(2) - m%belt
         a = m%applied(t, y(1) + m%load * t, y(2))
         g(1) = w - self%half_width
         g(2) = w + self%half_width
         g(3) = merge(self%hold_limit, self%limit, self%held_at == 1.0_wp) - a
         g(4) = merge(self%hold_limit, self%limit, self%held_at == -1.0_wp) + a
         if (self%sectioned) g(5) = y(2) - m%load
      end associate
   end subroutine band_event_values

   ! ---- the run ----

   !> The band's frame of checked settings c and their band law (no section event).
   subroutine band_frame_of(c, law, band)
      type(machine_config), intent(in) :: c
      class(sliding_law), intent(in) :: law
      type(band_frame), intent(out) :: band
      integer :: ns

      ns = law%state_count()
      call band%frame%base%m%from_config(c)
      allocate (band%frame%base%law, source=law)
      band%frame%base%n_states = ns
      if (ns > 0) call law%state_scale(band%frame%base%scale(1:ns))
      call band%set_limits()
   end subroutine band_frame_of

   !> The settings' initial state in the band's frame: e = x0 - load_velocity
   !> t_start, v0, the law's states in steady sliding at v0 - belt_velocity
   !> (with steady_start) or 0, over their scales.
   function band_start_state(c, band) result(y0)
      type(machine_config), intent(in) :: c
      type(band_frame), intent(in) :: band
      real(wp), allocatable :: y0(:)
      real(wp) :: z(max_law_states)
      integer :: ns

      ns = band%frame%base%n_states
      z = 0.0_wp
      if (ns > 0 .and. c%steady_start) call band%frame%base%law%steady_state(c%v0 - c%belt_velocity, c%normal, &
         & z(1:ns))
      y0 = [c%x0 - c%load_velocity * c%t_start, c%v0, z(1:ns) / band%frame%base%scale(1:ns)]
   end function band_start_state

   !> Start at (t0, y0) in the frame of `band` (copied), Φ = I beside it when
   !> `tangent`.  A block at the closest velocity inside an edge with |A| <=
   !> F_s starts in a hold at that edge (a strobe point may be in one).
   subroutine band_start(self, band, solver, event_tolerance, h, t0, y0, tangent, error)
      class(machine_band), target, intent(inout) :: self
      type(band_frame), intent(in) :: band
      type(solver_settings), intent(in) :: solver
      real(wp), intent(in) :: event_tolerance, h, t0, y0(:)
      logical, intent(in) :: tangent
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: directions(:)
      integer :: i, n
      real(wp) :: w, a

      if (allocated(self%band)) deallocate (self%band)
      allocate (self%band, source=band)
      self%tangent = tangent
      directions = [event_either, event_either, event_either, event_either]
      if (band%sectioned) directions = [directions, event_rising]
      if (tangent) then
         if (allocated(self%extended)) deallocate (self%extended)
         allocate (self%extended)
         allocate (self%extended%base, source=band)
         call self%locator%init(self%extended, solver, directions, spread(.true., 1, size(directions)), &
            & event_tolerance, h, error, 't', ' s')
      else
         call self%locator%init(self%band, solver, directions, spread(.true., 1, size(directions)), &
            & event_tolerance, h, error, 't', ' s')
      end if
      if (allocated(error)) return
      n = size(y0)
      self%t = t0
      self%y = y0
      if (allocated(self%phi)) deallocate (self%phi)
      allocate (self%phi(n, n))
      self%phi = 0.0_wp
      do i = 1, n
         self%phi(i, i) = 1.0_wp
      end do
      self%lost = 0
      self%band_time = 0.0_wp
      self%hold_edge = 0.0_wp
      associate (m => band%frame%base%m, width => band%half_width)
         w = y0(2) - m%belt
         a = m%applied(t0, y0(1) + m%load * t0, y0(2))
         if (abs(w) < width .and. abs(a) <= band%limit) then
            if (y0(2) == band_edge_velocity(m%belt, width, 1.0_wp, sign(1.0_wp, w), .true.)) &
               & self%hold_edge = sign(1.0_wp, w)
         else if (abs(w) < width .and. sign(1.0_wp, w) * a <= band%hold_limit) then
            ! In the sliding mode at an edge.
            if (y0(2) == band_edge_velocity(m%belt, width, 1.0_wp, sign(1.0_wp, w), .true.)) &
               & self%hold_edge = sign(1.0_wp, w)
         end if
      end associate
      call set_hold(self, self%hold_edge)
      self%held = self%inside()
      call restart(self, h)
   end subroutine band_start

   !> Start at t0 from y0, else from the settings' initial state (band_start_state), in the band's frame of
   !> checked settings c and their band law, with their solver and a first step of h_start, else 1e-6 dt_out.
   subroutine band_start_from(self, c, law, t0, tangent, error, y0)
      class(machine_band), target, intent(inout) :: self
      type(machine_config), intent(in) :: c
      class(sliding_law), intent(in) :: law
      real(wp), intent(in) :: t0
      logical, intent(in) :: tangent
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(in), optional :: y0(:)
      type(band_frame) :: band
      real(wp) :: h

      call band_frame_of(c, law, band)
      h = c%first_step()
      if (present(y0)) then
         call self%start(band, c%solver, c%event_tolerance, h, t0, y0, tangent, error)
      else
         call self%start(band, c%solver, c%event_tolerance, h, t0, band_start_state(c, band), tangent, error)
      end if
   end subroutine band_start_from

   !> Φ from here on (the spectrum's renormalisation); the lost count cleared.
   subroutine band_reset(self, q)
      class(machine_band), intent(inout) :: self
      real(wp), intent(in) :: q(:, :)

      self%phi = q
      self%lost = 0
      call restart(self, 0.0_wp)
   end subroutine band_reset

   logical function band_inside(self)
      class(machine_band), intent(in) :: self

      band_inside = abs(self%y(2) - self%band%frame%base%m%belt) < self%band%half_width
   end function band_inside

   function band_statistics(self) result(stats)
      class(machine_band), intent(in) :: self
      type(integrator_statistics) :: stats

      stats = self%locator%statistics()
   end function band_statistics

   !> The edge the block holds at (0: none), in the run and in its flows.
   subroutine set_hold(self, s)
      type(machine_band), intent(inout) :: self
      real(wp), intent(in) :: s

      self%hold_edge = s
      self%band%held_at = s
      if (allocated(self%extended)) then
         select type (base => self%extended%base)
         type is (band_frame)
            base%held_at = s
         end select
      end if
   end subroutine set_hold

   subroutine restart(self, h)
      type(machine_band), intent(inout) :: self
      real(wp), intent(in) :: h

      if (self%tangent) then
         call self%locator%restart(self%t, pack_tangent(self%y, self%phi), h)
      else
         call self%locator%restart(self%t, self%y, h)
      end if
   end subroutine restart

   !> Advance towards t_target up to the first of the band's events, which is
   !> taken (module comment): `outcome` says which it was (band_none at t_target).
   !> With `single`, after one accepted step even without an event; with
   !> `times` (increasing; not with the tangent), the states at the first
   !> `filled` of them, those up to the time reached, into `states` from the
   !> stepper's continuous extension (before the event is taken).
   subroutine band_advance(self, t_target, outcome, error, watch, single, times, states, filled)
      class(machine_band), intent(inout) :: self
      real(wp), intent(in) :: t_target
      integer, intent(out) :: outcome
      type(error_type), allocatable, intent(out) :: error
      class(step_watch), intent(inout), optional :: watch
      logical, intent(in), optional :: single
      real(wp), intent(in), optional :: times(:)
      real(wp), intent(inout), optional :: states(:, :)
      integer, intent(out), optional :: filled
      real(wp), allocatable :: z(:), near(:), f_minus(:), f_plus(:), normal(:), row(:)
      real(wp) :: t_before, w, edge, sigma, a, rate, rate_t
      integer :: n, i, which, direction
      logical :: was_inside, entering, onto

      outcome = band_none
      n = size(self%y)
      t_before = self%t
      was_inside = self%inside()
      if (self%tangent) then
         z = pack_tangent(self%y, self%phi)
         call self%locator%advance(self%t, t_target, z, error, watch, single)
         call unpack_tangent(z, self%y, self%phi)
      else
         call self%locator%advance(self%t, t_target, self%y, error, watch, single)
      end if
      ! (Between two of the band's events the block is inside it throughout or outside.)
      if (was_inside) self%band_time = self%band_time + (self%t - t_before)
      if (allocated(error)) return
      if (present(filled)) then
         filled = 0
         do while (filled < size(times))
            if (times(filled + 1) > self%t) exit
            filled = filled + 1
            if (times(filled) == self%t) then
               states(:, filled) = self%y
            else
               call self%locator%dense_output(times(filled), states(:, filled), error)
               if (allocated(error)) return
            end if
         end do
      end if
      if (self%locator%n_hits == 0) return
      which = self%locator%hits(self%locator%n_hits)%which
      direction = self%locator%hits(self%locator%n_hits)%direction
      allocate (f_minus(n), f_plus(n), normal(n), row(n))
      associate (b => self%band, m => self%band%frame%base%m, width => self%band%half_width, &
         & limit => self%band%limit)
         w = self%y(2) - m%belt
         ! Out past the edge of a hold before the force's event was located: that is the hold's end.
         if ((which == 1 .or. which == 2) .and. self%hold_edge == merge(1.0_wp, -1.0_wp, which == 1) &
            & .and. .not. abs(w) < width) which = which + 2
         select case (which)
         case (5)
            outcome = band_at_section
         case (1, 2)
            edge = merge(width, -width, which == 1)
            ! The located state is on the far side: inside when the band was entered.
            entering = abs(w) < width
            near = self%y
            if (entering) then
               ! Just inside, deterministically.
               self%y(2) = band_edge_velocity(m%belt, width, 1.0_wp, sign(1.0_wp, edge), .true.)
               near(2) = band_edge_velocity(m%belt, width, 1.0_wp, sign(1.0_wp, edge), .false.)
            else
               near(2) = band_edge_velocity(m%belt, width, 1.0_wp, sign(1.0_wp, edge), .true.)
            end if
            call b%rhs(self%t, near, f_minus)
            ! Pulled outwards beyond F_s but within the hold's limit: held on the edge (the sliding mode),
            ! entering from outside or driven onto it from inside (then put just inside, as entering).
            a = m%applied(self%t, self%y(1) + m%load * self%t, self%y(2))
            onto = .not. entering .and. sliding_at_edge(sign(1.0_wp, edge), a, limit) &
               & .and. sign(1.0_wp, edge) * a < b%hold_limit
            if (onto) self%y(2) = near(2)
            if ((entering .or. onto) .and. sliding_at_edge(sign(1.0_wp, edge), a, limit) &
               & .and. sign(1.0_wp, edge) * a <= b%hold_limit) call set_hold(self, sign(1.0_wp, edge))
            call b%rhs(self%t, self%y, f_plus)
            if (self%tangent .and. f_minus(2) /= 0.0_wp) then
               ! Φ across h = w - edge (∇h = e_v): row v scales by f⁺_v/f⁻_v (0 exactly into a hold).
               row = self%phi(2, :)
               do i = 1, n
                  if (i /= 2) self%phi(i, :) = self%phi(i, :) + (f_plus(i) - f_minus(i)) * row / f_minus(2)
               end do
               self%phi(2, :) = row * (f_plus(2) / f_minus(2))
               if (f_plus(2) == 0.0_wp) self%lost = 1
            end if
            call set_hold(self, merge(sign(1.0_wp, edge), 0.0_wp, f_plus(2) == 0.0_wp .and. (entering .or. onto)))
            ! A hold's flow is one-dimensional: without a support's motion what is left of Φ is a shift in time.
            if (self%tangent .and. self%project_in_hold .and. self%hold_edge /= 0.0_wp) self%phi = 0.0_wp
            if (onto .and. self%held) then
               ! A hold inside the band carried onto the edge: it goes on there, no event.
               outcome = band_pull
            else if ((entering .or. onto) .and. f_plus(2) == 0.0_wp) then
               self%held = .true.
               outcome = band_hold
            else if (entering) then
               self%held = .false.
               outcome = band_cross
            else if (self%held) then
               ! A hold inside the band that drifted out.
               self%held = .false.
               outcome = band_leave
            else
               outcome = band_exit
            end if
         case (3, 4)
            sigma = merge(1.0_wp, -1.0_wp, which == 3)
            a = m%applied(self%t, self%y(1) + m%load * self%t, self%y(2))
            outcome = band_pull
            ! A hold at the edge the force pushes towards ends: out at once (else a kink, nothing to do).
            if (self%hold_edge == sigma .and. (sigma * a >= b%hold_limit .or. .not. abs(w) < width)) then
               f_minus = 0.0_wp
               f_minus(1) = self%y(2) - m%load   ! the hold's field: e' = v - load_velocity, v' = 0, the states'
               if (n > 2) then
                  call b%rhs(self%t, self%y, f_plus)
                  f_minus(3:n) = f_plus(3:n)
               end if
               call set_hold(self, 0.0_wp)
               self%y(2) = band_edge_velocity(m%belt, width, 1.0_wp, sigma, .false.)
               call b%rhs(self%t, self%y, f_plus)
               if (self%tangent) then
                  ! h = F_s - σ A(t, e + load t, v): ∇h = σ (k, c, 0...), ∂h/∂t at fixed e.
                  normal = 0.0_wp
                  normal(1) = sigma * m%stiffness
                  normal(2) = sigma * m%damping
                  rate_t = -sigma * (m%applied_rate(self%t) - m%stiffness * m%load)
                  rate = dot_product(normal, f_minus) + rate_t
                  if (rate /= 0.0_wp) then
                     row = matmul(normal, self%phi) / rate
                     do i = 1, n
                        self%phi(i, :) = self%phi(i, :) + (f_plus(i) - f_minus(i)) * row
                     end do
                  end if
               end if
               self%held = .false.
               outcome = band_hold_end
            else if (abs(w) < width .and. direction == event_rising) then
               ! |A| fell back within F_s inside the band: the block holds where it is.
               self%held = .true.
            end if
            ! Ended, or pushed inwards into the band: no longer held at an edge.
            call set_hold(self, 0.0_wp)
         end select
      end associate
      call restart(self, 0.0_wp)
   end subroutine band_advance

   !> Through the band's switches to t_target, whatever they are (the
   !> spectrum's and Benettin's intervals); more than max_switches of them is
   !> an error: the block slides along an edge.
   subroutine band_advance_to(self, t_target, error, watch)
      class(machine_band), intent(inout) :: self
      real(wp), intent(in) :: t_target
      type(error_type), allocatable, intent(out) :: error
      class(step_watch), intent(inout), optional :: watch
      integer :: outcome, switches

      switches = 0
      do while (self%t < t_target)
         call self%advance(t_target, outcome, error, watch)
         if (allocated(error)) return
         if (outcome /= band_none .and. outcome /= band_pull) switches = switches + 1
         if (switches > max_switches) then
            call fatal_error(error, 'more than '//itoa(max_switches)//' switches at the band''s edges ' &
               & //'before t = '//rtoa(self%t)//' s: the block slides along an edge', error_numerical)
            return
         end if
      end do
   end subroutine band_advance_to

end module friction_machine_band
