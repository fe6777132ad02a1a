!> The brake with a law whose force jumps at the edges of a zero-velocity
!> band (Karnopp's: |v_rel| < Δv holds the springs' pull A = -(2x - y) up
!> to F_s; docs/chaos.md, "Karnopp's band on the brake"), integrated with the
!> band's edges and the ends of its hold as located events, and the tangent
!> Φ carried through a saltation at each jump.  The brake's run of such a
!> law (its trajectory, events, Poincaré maps and Benettin's two runs:
!> simulate.f90's factory), its periodic orbits (orbit.f90) and its Lyapunov
!> spectrum (diagnostics.f90) all run it.
!>
!> - an edge crossed: Φ ← (I + (f⁺ - f⁻) e_vᵀ / f⁻_v) Φ, f⁻ and f⁺ the fields
!>   on the two sides at the crossing.  Entering, the block is put at the
!>   closest velocity inside the edge (the band's limit of no depth: the
!>   exact flow holds it on the edge; where the step left it would set when
!>   it drifts out again).  Into a hold f⁺_v = 0: δv is forgotten, the
!>   direction the spectrum reports as lost (-inf), as exact stick's;
!> - a hold at the edge the pull pushes towards ends where σA reaches the
!>   hold's limit F_h = max(F_s, F_e), F_e the force just outside the edge:
!>   the block leaves at once, Φ through the saltation from the hold's field
!>   into the outside one across h = F_h - σA (the brake's slip onset:
!>   event_stick_to_slip); pushing inwards, or from inside the band, it is a
!>   kink of the clipped force, no jump.  With F_e > F_s a pull σA between
!>   the two drives the block out of the band and the slip force back in:
!>   it slides along the edge (Filippov's sliding mode), v' = 0 with the
!>   friction equal to the pull, a hold entered from either side, ending
!>   where σA = F_e with the force continuous (the saltation the identity
!>   but for the velocity's last bit).
!>
!> A run that switches at the edges more than max_switches times within one
!> advance ends with an error.
!>
!> The state is the law's flow's, (x, v_rel, y, w): the band and its edges
!> are in the slip rate v_rel itself, centred on 0.
module friction_brake_band
   use friction_kinds, only: wp
   use friction_error, only: error_type, fatal_error, error_numerical
   use friction_strings, only: rtoa, itoa
   use friction_ode_events, only: event_system, event_falling, event_rising, event_either
   use friction_law, only: sliding_law, in_band, band_edge_velocity, band_hold_limit, sliding_at_edge
   use friction_law_factory, only: make_law, new_law
   use friction_output_law_files, only: law_with_files
   use friction_analysis_lyapunov_spectrum, only: tangent_system
   use friction_brake_config, only: brake_config
   use friction_brake_integrator, only: brake_integrator
   use friction_brake_law_model, only: brake_law_flow
   use friction_brake_switched, only: saltation
   use friction_brake_record, only: brake_event_table, event_stick_to_slip, event_slip_to_stick, &
      & event_slip_reversal
   implicit none
   private

   public :: brake_band_flow, band_integrator, band_law

   !> Switches at the band's edges within one advance beyond which the edges are taken to chatter.
   integer, parameter :: max_switches = 1000000

   !> Eq. 10 with a band law (the law's flow, no states) and its events: 1 N'
   !> (falling through 0: the pad lifts off), 2 and 3 the edges w ∓ Δv, 4 and
   !> 5 the pull at ±F_s (F_s ∓ A), in the law's units as the law compares them.
   type, extends(event_system) :: brake_band_flow
      type(brake_law_flow) :: flow
      real(wp) :: half_width = 0.0_wp   !! Δv in the law's units
      real(wp) :: limit = 0.0_wp        !! F_s in the law's units
      real(wp) :: hold_limit = 0.0_wp   !! the largest pull a hold at an edge keeps (band_hold_limit), law's units
      real(wp) :: held_at = 0.0_wp      !! the sign of the edge held at (0: none): v' = 0 in its sliding mode
   contains
      procedure :: dimension => band_dimension
      procedure :: rhs => band_rhs
      procedure :: jacobian => band_jacobian
      procedure :: event_count => band_event_count
      procedure :: event_values => band_event_values
      procedure :: inside
      procedure :: edge_velocity
      procedure :: sliding
   end type brake_band_flow

   type, extends(brake_integrator) :: band_integrator
      type(brake_band_flow), allocatable :: band
      type(tangent_system), allocatable :: extended   !! the band's flow with its tangent (when tangent)
      real(wp) :: h_start = 1.0e-3_wp
      logical :: held = .false.   !! held in the band since it was entered: leaving it is a slip onset
      real(wp) :: hold_edge = 0.0_wp   !! the sign of the edge the block holds at (0: inside, or not held)
   contains
      procedure :: start => band_start
      procedure :: advance_to => band_advance_to
      procedure :: is_sticking => band_sticking
      procedure :: start_leaving
      procedure :: advance_to_hold_end
      procedure :: field
   end type band_integrator

contains

   !> Whether the brake's friction is a law of &law with a band whose force
   !> jumps at its edges (Karnopp's): run through its switches
   !> (the brake's run, its orbit and its spectrum).
   logical function band_law(config)
      type(brake_config), intent(in) :: config
      class(sliding_law), allocatable :: law
      real(wp) :: half_width, limit

      band_law = config%uses_law()
      if (.not. band_law) return
      call new_law(config%law, law)
      call law%band(half_width, limit)
      band_law = half_width > 0.0_wp
   end function band_law

   ! ---- the flow and its events ----

   pure function band_dimension(self) result(n)
      class(brake_band_flow), intent(in) :: self
      integer :: n

      n = 4
   end function band_dimension

   pure subroutine band_rhs(self, t, y, dydt)
      class(brake_band_flow), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in), contiguous :: y(:)
      real(wp), intent(out), contiguous :: dydt(:)

      call self%flow%rhs(t, y, dydt)
      ! A hold is exact: the law's clip of the pull, scaled to its units and back, may leave a rounding.
      if (self%inside(y(2))) then
         if (abs(-(2.0_wp * y(1) - y(3)) * self%flow%units%force) <= self%limit) dydt(2) = 0.0_wp
      end if
      if (self%sliding(y)) dydt(2) = 0.0_wp
   end subroutine band_rhs

   !> Whether the state is in the sliding mode of the hold at an edge (the
   !> pull outwards beyond F_s): its field's v' is 0, not the law's.
   pure logical function sliding(self, y)
      class(brake_band_flow), intent(in) :: self
      real(wp), intent(in) :: y(:)

      sliding = .false.
      ! (A band without a sliding mode keeps the law's field: the steps past a hold's end at F_s, as before.)
      if (self%held_at /= 0.0_wp .and. self%hold_limit > self%limit) sliding = sliding_at_edge(self%held_at, &
         & -(2.0_wp * y(1) - y(3)) * self%flow%units%force, self%limit)
   end function sliding

   pure subroutine band_jacobian(self, t, y, dfdy, dfdt)
      class(brake_band_flow), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: y(:)
      real(wp), intent(out) :: dfdy(:, :)
      real(wp), intent(out) :: dfdt(:)

      call self%flow%jacobian(t, y, dfdy, dfdt)
      if (self%sliding(y)) then
         dfdy(2, :) = 0.0_wp
         dfdt(2) = 0.0_wp
      end if
   end subroutine band_jacobian

   pure function band_event_count(self) result(n)
      class(brake_band_flow), intent(in) :: self
      integer :: n

      n = 5
   end function band_event_count

   pure subroutine band_event_values(self, t, y, g)
      class(brake_band_flow), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: y(:)
      real(wp), intent(out) :: g(:)
      real(wp) :: w, a

      associate (p => self%flow%params, u => self%flow%units)
         ! The law's own arguments, so that each sign is the law's test of the band (|w| < Δv, clip at F_s).
         w = y(2) * u%velocity
         a = -(2.0_wp * y(1) - y(3)) * u%force
         g(1) = (1.0_wp - p%kappa) * y(3) + p%g_prime
         g(2) = w - self%half_width
         g(3) = w + self%half_width
         g(4) = merge(self%hold_limit, self%limit, self%held_at == 1.0_wp) - a
         g(5) = merge(self%hold_limit, self%limit, self%held_at == -1.0_wp) + a
      end associate
   end subroutine band_event_values

   !> Whether the slip rate v_rel is inside the band, as the law decides.
   pure logical function inside(self, v_rel)
      class(brake_band_flow), intent(in) :: self
      real(wp), intent(in) :: v_rel

      inside = in_band(v_rel, 0.0_wp, self%half_width, self%flow%units%velocity)
   end function inside

   !> The slip rate closest to the edge of sign s on its inner side (the
   !> law's band) or its outer side.
   pure real(wp) function edge_velocity(self, s, inner) result(v_rel)
      class(brake_band_flow), intent(in) :: self
      real(wp), intent(in) :: s
      logical, intent(in) :: inner

      v_rel = band_edge_velocity(0.0_wp, self%half_width, self%flow%units%velocity, s, inner)
   end function edge_velocity

   ! ---- the integrator ----

   !> Start at (t0, y0) of the configuration (a band law of &law): the law
   !> made at the first start (an integrator runs one configuration, as the
   !> law model's), the locator on the band's flow (with Φ = I beside it when
   !> tangent).
   subroutine band_start(self, config, t0, y0, events, error)
      class(band_integrator), target, intent(inout) :: self
      type(brake_config), intent(in) :: config
      real(wp), intent(in) :: t0, y0(4)
      type(brake_event_table), intent(inout) :: events
      type(error_type), allocatable, intent(out) :: error
      integer :: directions(5)

      if (.not. allocated(self%band)) then
         allocate (self%band)
         call make_law(law_with_files(config%law), self%band%flow%law, error)
         if (allocated(error)) return
         self%band%flow%params = config%params
         call config%law_units(self%band%flow%units%force, self%band%flow%units%velocity, &
            & self%band%flow%units%time)
         self%band%flow%n_states = 0
         call self%band%flow%law%band(self%band%half_width, self%band%limit)
         ! (Karnopp's F_s and g(Δv) + σ2 Δv do not depend on the load.)
         self%band%hold_limit = band_hold_limit(self%band%flow%law, 1.0_wp)
      end if
      self%h_start = config%solver%h_start
      if (.not. (self%h_start > 0.0_wp)) self%h_start = 1.0e-3_wp
      self%t = t0
      ! The flow's coordinate is v_rel (law_model.f90); the input's state is x'.
      self%v_origin = config%params%v_dr
      self%y = [y0(1), y0(2) - config%params%v_dr, y0(3), y0(4)]
      self%held = self%band%inside(self%y(2))
      self%hold_edge = 0.0_wp
      self%band%held_at = 0.0_wp
      ! Exact: the time in the band, between its located edges.
      self%stick_time = 0.0_wp
      call events%clear()
      directions = [event_falling, event_either, event_either, event_either, event_either]
      if (self%tangent) then
         if (allocated(self%extended)) deallocate (self%extended)
         allocate (self%extended)
         allocate (self%extended%base, source=self%band)
         call self%locator%init(self%extended, config%solver, directions, spread(.true., 1, 5), &
            & config%event_tolerance, self%h_start, error, time_name='τ', time_unit='')
         if (allocated(error)) return
         call self%start_tangent()
      else
         call self%locator%init(self%band, config%solver, directions, spread(.true., 1, 5), &
            & config%event_tolerance, self%h_start, error, time_name='τ', time_unit='')
         if (allocated(error)) return
      end if
      call self%locator_restart(self%h_start)
   end subroutine band_start

   !> Start at the instant a hold at the edge ends: y0's slip rate replaced by
   !> the closest one outside the edge of sign s, the block leaving that way
   !> (a point of the section, brake/orbit.f90).
   subroutine start_leaving(self, config, t0, y0, s, events, error)
      class(band_integrator), target, intent(inout) :: self
      type(brake_config), intent(in) :: config
      real(wp), intent(in) :: t0, y0(4), s
      type(brake_event_table), intent(inout) :: events
      type(error_type), allocatable, intent(out) :: error

      call self%start(config, t0, y0, events, error)
      if (allocated(error)) return
      self%y(2) = self%band%edge_velocity(s, .false.)
      self%held = .false.
      call set_hold(self, 0.0_wp)
      call self%locator_restart(self%h_start)
   end subroutine start_leaving

   !> The edge the block holds at (0: none), in the run and in its flows.
   subroutine set_hold(self, s)
      type(band_integrator), intent(inout) :: self
      real(wp), intent(in) :: s

      self%hold_edge = s
      self%band%held_at = s
      if (allocated(self%extended)) then
         select type (base => self%extended%base)
         type is (brake_band_flow)
            base%held_at = s
         end select
      end if
   end subroutine set_hold

   logical function band_sticking(self)
      class(band_integrator), intent(in) :: self

      band_sticking = self%band%inside(self%y(2))
   end function band_sticking

   !> The band's field at the current state.
   function field(self) result(f)
      class(band_integrator), intent(in) :: self
      real(wp) :: f(4)

      call self%band%rhs(self%t, self%y, f)
   end function field

   subroutine band_advance_to(self, t_target, events, error)
      class(band_integrator), intent(inout) :: self
      real(wp), intent(in) :: t_target
      type(brake_event_table), intent(inout) :: events
      type(error_type), allocatable, intent(out) :: error

      call advance_band(self, t_target, events, error)
   end subroutine band_advance_to

   !> Advance to the next end of a hold at an edge (found), stopped just
   !> after it (outside, Φ through the saltation), or to t_limit (not found).
   subroutine advance_to_hold_end(self, t_limit, events, found, error)
      class(band_integrator), intent(inout) :: self
      real(wp), intent(in) :: t_limit
      type(brake_event_table), intent(inout) :: events
      logical, intent(out) :: found
      type(error_type), allocatable, intent(out) :: error

      call advance_band(self, t_limit, events, error, found)
   end subroutine advance_to_hold_end

   !> Through the band's switches to t_target (module comment); with
   !> hold_end present, up to the first end of a hold at an edge.
   subroutine advance_band(self, t_target, events, error, hold_end)
      type(band_integrator), intent(inout) :: self
      real(wp), intent(in) :: t_target
      type(brake_event_table), intent(inout) :: events
      type(error_type), allocatable, intent(out) :: error
      logical, intent(out), optional :: hold_end
      real(wp) :: near(4), f_minus(4), f_plus(4), row(4), s, sigma, t_before, pull
      integer :: which, direction, switches
      logical :: entering, left, was_inside, onto

      if (present(hold_end)) hold_end = .false.
      switches = 0
      associate (b => self%band, y => self%y)
         do while (self%t < t_target)
            t_before = self%t
            was_inside = b%inside(y(2))
            call self%locator_advance(t_target, error)
            ! (Between two of the band's events the block is inside it throughout or outside.)
            if (was_inside) self%stick_time = self%stick_time + (self%t - t_before)
            if (allocated(error)) exit
            if (self%locator%n_hits == 0) cycle
            which = self%locator%hits(self%locator%n_hits)%which
            direction = self%locator%hits(self%locator%n_hits)%direction
            left = .false.
            select case (which)
            case (1)
               call fatal_error(error, "N' reached 0 at τ = "//rtoa(self%t) &
                  & //': the pad lifts off the belt, outside Eq. 10', error_numerical)
               exit
            case (2, 3)
               switches = switches + 1
               if (switches > max_switches) then
                  call fatal_error(error, 'more than '//itoa(max_switches)//' switches at the band''s edges ' &
                     & //'before τ = '//rtoa(self%t)//': the block slides along an edge', error_numerical)
                  exit
               end if
               s = merge(1.0_wp, -1.0_wp, which == 2)
               ! The located state is on the far side: inside when the band was entered.
               entering = b%inside(y(2))
               if (.not. entering .and. self%hold_edge == s) then
                  ! Out of a hold at this edge before the pull's event was located: the hold's end.
                  call leave_hold(s)
               else
                  near = y
                  near(2) = b%edge_velocity(s, .not. entering)
                  if (entering) y(2) = b%edge_velocity(s, .true.)
                  call b%rhs(self%t, near, f_minus)
                  ! Pulled outwards beyond F_s but within the hold's limit: held on the edge (the sliding
                  ! mode), entering from outside or driven onto it from inside (then put just inside).
                  pull = -(2.0_wp * y(1) - y(3)) * b%flow%units%force
                  onto = .not. entering .and. sliding_at_edge(s, pull, b%limit) .and. s * pull < b%hold_limit
                  if (onto) y(2) = near(2)
                  if ((entering .or. onto) .and. sliding_at_edge(s, pull, b%limit) .and. s * pull <= b%hold_limit) &
                     & call set_hold(self, s)
                  call b%rhs(self%t, y, f_plus)
                  if (self%tangent .and. f_minus(2) /= 0.0_wp) then
                     row = self%phi(2, :)
                     call saltation(self%phi, f_minus, f_plus, [0.0_wp, 1.0_wp, 0.0_wp, 0.0_wp])
                     ! The velocity's row scales by f⁺_v/f⁻_v: 0 exactly into a hold.
                     self%phi(2, :) = row * (f_plus(2) / f_minus(2))
                     if (f_plus(2) == 0.0_wp) self%lost = 1
                  end if
                  call set_hold(self, 0.0_wp)
                  if (onto .and. self%held) then
                     ! A hold inside the band carried onto the edge: it goes on there, no event.
                     call set_hold(self, s)
                  else if ((entering .or. onto) .and. f_plus(2) == 0.0_wp) then
                     self%held = .true.
                     call set_hold(self, s)
                     call events%add(self%t, event_slip_to_stick, self%state())
                  else if (entering) then
                     self%held = .false.
                     call events%add(self%t, event_slip_reversal, self%state())
                  else if (self%held) then
                     ! A hold inside the band that drifted out.
                     self%held = .false.
                     call events%add(self%t, event_stick_to_slip, self%state())
                  end if
               end if
            case (4, 5)
               ! σ the sign of the pull at the limit: F_s - σA falls through 0 as the pull grows past F_s.
               sigma = merge(1.0_wp, -1.0_wp, which == 4)
               if (direction == event_falling .and. self%hold_edge == sigma) then
                  ! (Tested before the band: the step that reaches the event may have moved v past the
                  ! edge by a few units of its last place, from the pull just past F_s at its last stage.)
                  call leave_hold(sigma)
               else if (.not. b%inside(y(2))) then
                  ! (Outside the band the pull's limit changes nothing.)
               else if (direction == event_rising) then
                  ! |A| fell back within F_s inside the band: the block holds where it is.
                  self%held = .true.
               else
                  ! Pushed inwards, or from inside: the block drifts into the band (a kink, no jump).
                  call set_hold(self, 0.0_wp)
               end if
            end select
            call self%locator_restart(0.0_wp)
            if (left .and. present(hold_end)) then
               hold_end = .true.
               exit
            end if
         end do
      end associate
      if (allocated(error)) error%message = error%message//" (&brake model = 'law', &law model = '" &
         & //trim(self%band%flow%law%p%model)//"')"

   contains

      !> The hold at the edge σ that the pull pushes towards ends: the block
      !> leaves at once, through the saltation from the hold's field into the
      !> outside one across h = F_s - σA, ∇h = σ (2, 0, -1, 0).
      subroutine leave_hold(sigma)
         real(wp), intent(in) :: sigma

         associate (p => self%band%flow%params, y => self%y)
            f_minus = [y(2) + p%v_dr, 0.0_wp, y(4), (y(1) - p%kappa * y(3)) / p%xi]
            call set_hold(self, 0.0_wp)
            y(2) = self%band%edge_velocity(sigma, .false.)
            call self%band%rhs(self%t, y, f_plus)
            if (self%tangent) call saltation(self%phi, f_minus, f_plus, [2.0_wp * sigma, 0.0_wp, -sigma, 0.0_wp])
         end associate
         self%held = .false.
         left = .true.
         call events%add(self%t, event_stick_to_slip, self%state())
      end subroutine leave_hold

   end subroutine advance_band

end module friction_brake_band
