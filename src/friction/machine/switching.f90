!> A set-valued law's run with exact stick and slip (Coulomb, Stribeck, the
!> table; docs/chaos.md, "The machine"), as run.f90's, with the tangent
!> matrix Φ beside the state when asked: the slip's variational equations,
!> the saltation matrix at every switch, and in stick the velocity pinned to
!> the belt, which forgets δv.  The Lyapunov spectrum and Benettin's
!> exponent of such a law run it (lyapunov.f90), and so does the return map
!> of its periodic orbits (switching_section, for orbit.f90).
module friction_machine_switching
   use friction_kinds, only: wp
   use friction_error, only: error_type
   use friction_ode_events, only: event_locator, event_falling, event_rising
   use friction_ode_watch, only: step_watch
   use friction_analysis_lyapunov_spectrum, only: tangent_system, generic_frame, pack_tangent, unpack_tangent
   use friction_analysis_periodic_orbit, only: section_map
   use friction_law, only: sliding_law
   use friction_machine_config, only: machine_config
   use friction_machine_model, only: mechanics, machine_slip, machine_stick
   use friction_machine_piecewise, only: piecewise_run
   implicit none
   private

   public :: machine_switching, switching_section

   !> A set-valued law's run with exact stick and slip, as run.f90's, with
   !> the tangent Φ beside the state when asked (the spectrum), or without
   !> it (Benettin's two runs).
   type, extends(piecewise_run) :: machine_switching
      type(mechanics) :: m
      real(wp) :: limit = 0.0_wp, h = 0.0_wp, direction = 1.0_wp
      type(machine_slip) :: slip                    !! the slip alone
      type(tangent_system) :: slipping_system      !! the slip (its base) with its tangent
      type(machine_stick) :: stick
      type(event_locator) :: slipping, sticking
      logical :: tangent = .false., in_stick = .false.
      !> In stick Φ is projected along the flow in the load point's frame (an autonomous section map's choice).
      logical :: project_in_stick = .false.
      logical :: at_section = .false.               !! the last advance stopped where v rose through the section
      integer :: sticks = 0                         !! stick phases entered since the start
      real(wp) :: stick_time = 0.0_wp               !! s in stick since the start
   contains
      procedure :: start => switching_start
      procedure :: start_from => switching_start_from
      procedure :: advance_to => switching_advance
      procedure :: reset => switching_reset
      procedure :: is_held => switching_held
      procedure :: slip_field => switching_slip_field
      procedure, private :: pin => switching_pin
      procedure, private :: set_direction => switching_set_direction
      procedure, private :: restart_slip => switching_restart_slip
      procedure, private :: saltation => switching_saltation
   end type machine_switching

   !> The return map of a set-valued law's machine in the load point's frame,
   !> e = x - load_velocity t (docs/chaos.md, "Orbits and continuation of the
   !> machine"): without a moving support the section v = load_velocity
   !> crossed upwards in slip, its coordinate e; with one the stroboscopic
   !> section, (e, v) at t0 and t0 + period.  DP is Φ of the switching run
   !> (saltation matrices at every switch, δv forgotten in stick), projected
   !> along the flow onto the section when autonomous.
   type, extends(section_map) :: switching_section
      type(machine_config) :: config
      class(sliding_law), allocatable :: law
      logical :: forced = .false.
      real(wp) :: t0 = 0.0_wp, period = 0.0_wp   !! s: the strobe (forced)
      real(wp) :: max_return = 0.0_wp            !! s: no return by then is none (autonomous)
      integer :: sticks = 0                      !! stick phases entered over the last return
      real(wp) :: stick_time = 0.0_wp            !! s in stick over the last return
      logical :: stuck = .false.                 !! the last return was in stick at some time (its start included)
      class(step_watch), pointer :: watch => null()   !! asked inside the integrations when associated
   contains
      procedure :: setup => section_setup
      procedure :: dimension => section_dimension
      procedure :: evaluate => section_evaluate
   end type switching_section

contains

   !> Start at (t0, y0) as run.f90 does: stick where v = belt_velocity within
   !> the static limit, else slip (in the direction of w, or of the applied
   !> force); with `tangent`, Φ from the generic frame beside the state; with
   !> `section_level`, an advance stops where v rises through it in slip.
   subroutine switching_start(self, c, law, t0, y0, tangent, error, section_level)
      class(machine_switching), target, intent(inout) :: self
      type(machine_config), intent(in) :: c
      class(sliding_law), intent(in) :: law
      real(wp), intent(in) :: t0, y0(2)
      logical, intent(in) :: tangent
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(in), optional :: section_level
      type(machine_slip) :: slip
      real(wp) :: a
      integer, allocatable :: directions(:)

      call self%m%from_config(c)
      self%limit = law%static_force(self%m%normal)
      self%tangent = tangent
      slip%m = self%m
      allocate (slip%law, source=law)
      directions = [event_falling]
      if (present(section_level)) then
         slip%sectioned = .true.
         slip%section_level = section_level
         directions = [event_falling, event_rising]
      end if
      if (allocated(self%slipping_system%base)) deallocate (self%slipping_system%base)
      allocate (self%slipping_system%base, source=slip)
      self%slip = slip
      self%stick%m = self%m
      self%stick%limit = self%limit
      self%h = c%first_step()
      if (tangent) then
         call self%slipping%init(self%slipping_system, c%solver, directions, spread(.true., 1, size(directions)), &
            & c%event_tolerance, self%h, error, 't', ' s')
      else
         call self%slipping%init(self%slip, c%solver, directions, spread(.true., 1, size(directions)), &
            & c%event_tolerance, self%h, error, 't', ' s')
      end if
      if (allocated(error)) return
      call self%sticking%init(self%stick, c%solver, [event_falling, event_falling], [.true., .true.], &
         & c%event_tolerance, self%h, error, 't', ' s')
      if (allocated(error)) return
      self%t = t0
      self%y = y0
      self%phi = generic_frame(2)
      self%lost = 0
      self%sticks = 0
      self%stick_time = 0.0_wp
      self%at_section = .false.
      a = self%m%applied(t0, y0(1), y0(2))
      self%in_stick = y0(2) == self%m%belt .and. abs(a) <= self%limit
      if (self%in_stick) then
         call self%sticking%restart(t0, y0, self%h)
      else if (y0(2) /= self%m%belt) then
         call self%set_direction(sign(1.0_wp, y0(2) - self%m%belt))
         call self%restart_slip()
      else
         call self%set_direction(sign(1.0_wp, a))
         call self%restart_slip()
      end if
   end subroutine switching_start

   !> Start at t0 from y0, else from the settings' (x0, v0).
   subroutine switching_start_from(self, c, law, t0, tangent, error, y0)
      class(machine_switching), target, intent(inout) :: self
      type(machine_config), intent(in) :: c
      class(sliding_law), intent(in) :: law
      real(wp), intent(in) :: t0
      logical, intent(in) :: tangent
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(in), optional :: y0(:)

      if (present(y0)) then
         call self%start(c, law, t0, y0, tangent, error)
      else
         call self%start(c, law, t0, [c%x0, c%v0], tangent, error)
      end if
   end subroutine switching_start_from

   logical function switching_held(self)
      class(machine_switching), intent(in) :: self

      switching_held = self%in_stick
   end function switching_held

   !> Through any number of stick and slip phases to t_target.  In slip Φ
   !> follows the slip's variational equations; in stick v is the belt's, so
   !> δv is set to 0 (the direction lost) and δx is carried unchanged
   !> (x' = belt_velocity does not depend on the state).  At each switch
   !> through the surface h(t, y) = 0 from the field f⁻ into f⁺,
   !> Φ ← (I + (f⁺ - f⁻) ∇hᵀ / (∇h·f⁻ + ∂h/∂t)) Φ (docs/chaos.md).  A run
   !> started with a section level stops early where v rises through it
   !> (`at_section`).
   subroutine switching_advance(self, t_target, error, watch)
      class(machine_switching), intent(inout) :: self
      real(wp), intent(in) :: t_target
      type(error_type), allocatable, intent(out) :: error
      class(step_watch), intent(inout), optional :: watch
      real(wp) :: zz(6), sigma, f_minus(2), a, t_before
      integer :: which

      self%at_section = .false.
      associate (t => self%t, y => self%y, phi => self%phi, m => self%m)
         do while (t < t_target)
            if (self%in_stick) then
               call self%pin()
               t_before = t
               call self%sticking%advance(t, t_target, y, error, watch)
               if (allocated(error)) return
               self%stick_time = self%stick_time + (t - t_before)
               y(2) = m%belt   ! exact in stick
               if (self%sticking%n_hits == 0) cycle
               which = self%sticking%hits(self%sticking%n_hits)%which
               ! The applied force reached σ limit: h = limit - σ A(t, x, belt), slip that way.
               sigma = merge(1.0_wp, -1.0_wp, which == 1)
               self%in_stick = .false.
               call self%set_direction(sigma)
               call self%saltation([m%belt, 0.0_wp], self%slip_field(), [sigma * m%stiffness, 0.0_wp], &
                  & -sigma * m%applied_rate(t))
               call self%restart_slip()
            else
               if (self%tangent) then
                  zz = pack_tangent(y, phi)
                  call self%slipping%advance(t, t_target, zz, error, watch)
                  call unpack_tangent(zz, y, phi)
               else
                  call self%slipping%advance(t, t_target, y, error, watch)
               end if
               if (allocated(error)) return
               if (self%slipping%n_hits == 0) cycle
               if (self%slipping%hits(self%slipping%n_hits)%which == 2) then
                  ! The section: the slip goes on from here at the next advance.
                  self%at_section = .true.
                  call self%restart_slip(0.0_wp)
                  return
               end if
               ! h = s (v - belt): the slip in direction s ends.
               f_minus = self%slip_field()
               sigma = self%direction
               a = m%applied(t, y(1), m%belt)
               if (abs(a) <= self%limit) then
                  self%in_stick = .true.
                  self%sticks = self%sticks + 1
                  call self%saltation(f_minus, [m%belt, 0.0_wp], [0.0_wp, sigma], 0.0_wp)
                  y(2) = m%belt   ! exact: the event left w within the tolerance of 0
                  call self%sticking%restart(t, y, self%h)
               else
                  call self%set_direction(sign(1.0_wp, a))
                  call self%saltation(f_minus, self%slip_field(), [0.0_wp, sigma], 0.0_wp)
                  call self%restart_slip()
               end if
            end if
         end do
      end associate
   end subroutine switching_advance

   !> In stick: δv is forgotten.  With project_in_stick all of Φ: in the load
   !> point's frame the stick's flow is one-dimensional, (belt - load, 0), so
   !> the (δx, 0) left is a shift in time along the orbit, which an autonomous
   !> section map's projection along the flow removes at the return anyway
   !> (the linearised flow, saltations included, carries the field into the
   !> field); removed here it is exactly 0, not the return's rtol.
   subroutine switching_pin(self)
      class(machine_switching), intent(inout) :: self

      if (self%tangent .and. any(self%phi(2, :) /= 0.0_wp)) then
         self%phi(2, :) = 0.0_wp
         self%lost = 1
      end if
      if (self%tangent .and. self%project_in_stick .and. self%m%belt /= self%m%load) self%phi = 0.0_wp
   end subroutine switching_pin

   subroutine switching_set_direction(self, sigma)
      class(machine_switching), intent(inout) :: self
      real(wp), intent(in) :: sigma

      self%direction = sigma
      self%slip%direction = sigma
      select type (b => self%slipping_system%base)
      type is (machine_slip)
         b%direction = sigma
      end select
   end subroutine switching_set_direction

   !> The slip's locator restarted here (with Φ when the tangent is on); h <= 0
   !> keeps the step it had reached.
   subroutine switching_restart_slip(self, h)
      class(machine_switching), intent(inout) :: self
      real(wp), intent(in), optional :: h

      real(wp) :: first

      first = self%h
      if (present(h)) first = h
      if (self%tangent) then
         call self%slipping%restart(self%t, pack_tangent(self%y, self%phi), first)
      else
         call self%slipping%restart(self%t, self%y, first)
      end if
   end subroutine switching_restart_slip

   !> The slip's field at (t, y) in the current direction.
   function switching_slip_field(self) result(f)
      class(machine_switching), intent(in) :: self
      real(wp) :: f(2)

      call self%slip%rhs(self%t, self%y, f)
   end function switching_slip_field

   !> Φ across h = 0 (gradient `normal`, time derivative `rate_t`) from f⁻ into f⁺.
   !> A grazing crossing (∇h·f⁻ + ∂h/∂t = 0, measure zero) leaves Φ as it is.
   subroutine switching_saltation(self, f_minus, f_plus, normal, rate_t)
      class(machine_switching), intent(inout) :: self
      real(wp), intent(in) :: f_minus(2), f_plus(2), normal(2), rate_t
      real(wp) :: rate, row(2)
      integer :: i

      if (.not. self%tangent) return
      rate = dot_product(normal, f_minus) + rate_t
      if (rate == 0.0_wp) return
      row = matmul(normal, self%phi) / rate
      do i = 1, 2
         self%phi(i, :) = self%phi(i, :) + (f_plus(i) - f_minus(i)) * row
      end do
   end subroutine switching_saltation

   !> Φ replaced (a QR step): the steppers' copies are stale.
   subroutine switching_reset(self, q)
      class(machine_switching), intent(inout) :: self
      real(wp), intent(in) :: q(:, :)

      self%phi = q
      self%lost = 0
      if (self%in_stick) then
         call self%sticking%restart(self%t, self%y, 0.0_wp)
      else
         call self%restart_slip(0.0_wp)
      end if
   end subroutine switching_reset

   ! ---- the return map of a periodic orbit ----

   !> The map of checked settings c (a set-valued law): stroboscopic from t0
   !> over `period` when forced, else v = load_velocity upwards, returns after
   !> `max_return` counting as none.
   subroutine section_setup(self, c, law, forced, t0, period, max_return)
      class(switching_section), intent(inout) :: self
      type(machine_config), intent(in) :: c
      class(sliding_law), intent(in) :: law
      logical, intent(in) :: forced
      real(wp), intent(in) :: t0, period, max_return

      self%config = c
      if (allocated(self%law)) deallocate (self%law)
      allocate (self%law, source=law)
      self%forced = forced
      self%t0 = t0
      self%period = period
      self%max_return = max_return
   end subroutine section_setup

   pure integer function section_dimension(self)
      class(switching_section), intent(in) :: self

      section_dimension = merge(2, 1, self%forced)
   end function section_dimension

   !> From the section point s with Φ = I to the next return.  Forced: P(s)
   !> = (e, v) at t0 + period, DP = Φ.  Autonomous: from (e, load_velocity)
   !> in slip to the next upward crossing of v = load_velocity (the start's
   !> own crossing within 1000 event tolerances skipped), DP the e entry of
   !> (I - f nᵀ/(nᵀ f)) Φ with n = e_v and f the field in the load point's
   !> frame, (v - load_velocity, v').
   subroutine section_evaluate(self, s, image, jacobian, period, returned, reason, error)
      class(switching_section), intent(inout) :: self
      real(wp), intent(in) :: s(:)
      real(wp), intent(out) :: image(:), jacobian(:, :), period
      logical, intent(out) :: returned
      character(len=:), allocatable, intent(out) :: reason
      type(error_type), allocatable, intent(out) :: error
      type(machine_switching), target :: run
      real(wp), parameter :: identity(2, 2) = reshape([1.0_wp, 0.0_wp, 0.0_wp, 1.0_wp], [2, 2])
      real(wp) :: load, f(2), t_end

      image = s
      jacobian = 0.0_wp
      period = 0.0_wp
      returned = .false.
      reason = ''
      self%sticks = 0
      self%stick_time = 0.0_wp
      self%stuck = .false.
      load = self%config%load_velocity
      if (self%forced) then
         call run%start(self%config, self%law, self%t0, [s(1) + load * self%t0, s(2)], .true., error)
         if (allocated(error)) return
         self%stuck = run%in_stick
         call run%reset(identity)
         t_end = self%t0 + self%period
         call advance(t_end)
         if (allocated(error)) return
         image = [run%y(1) - load * t_end, run%y(2)]
         jacobian = run%phi
         period = self%period
      else
         call run%start(self%config, self%law, self%t0, [s(1) + load * self%t0, load], .true., error, &
            & section_level=load)
         if (allocated(error)) return
         run%project_in_stick = .true.
         call run%reset(identity)
         t_end = self%t0 + self%max_return
         do
            call advance(t_end)
            if (allocated(error)) return
            if (.not. run%at_section) then
               reason = 'no return to the section v = load_velocity within t_end - t_start'
               return
            end if
            ! A function exactly 0 at the start crosses at once (ode/events.f90): that is the start itself.
            if (run%t - self%t0 > 1.0e3_wp * self%config%event_tolerance) exit
         end do
         f = run%slip_field()
         f(1) = f(1) - load
         image = [run%y(1) - load * run%t]
         jacobian(1, 1) = run%phi(1, 1) - f(1) * run%phi(2, 1) / f(2)
         period = run%t - self%t0
      end if
      self%sticks = run%sticks
      self%stick_time = run%stick_time
      self%stuck = self%stuck .or. run%sticks > 0
      returned = .true.

   contains

      subroutine advance(t_target)
         real(wp), intent(in) :: t_target

         if (associated(self%watch)) then
            call run%advance_to(t_target, error, self%watch)
         else
            call run%advance_to(t_target, error)
         end if
      end subroutine advance

   end subroutine section_evaluate

end module friction_machine_switching
