!> A set-valued law's run with exact stick and slip (Coulomb, Stribeck, the
!> table; docs/chaos.md, "The machine"), as run.f90's, with the tangent
!> matrix Φ beside the state when asked: the slip's variational equations,
!> the saltation matrix at every switch, and in stick the velocity pinned to
!> the belt, which forgets δv.  The Lyapunov spectrum and Benettin's
!> exponent of such a law run it (lyapunov.f90).
module friction_machine_switching
   use friction_kinds, only: wp
   use friction_error, only: error_type
   use friction_ode_events, only: event_locator, event_falling
   use friction_ode_watch, only: step_watch
   use friction_analysis_lyapunov_spectrum, only: tangent_system, generic_frame, pack_tangent, unpack_tangent
   use friction_law, only: sliding_law
   use friction_machine_config, only: machine_config
   use friction_machine_model, only: mechanics, machine_slip, machine_stick
   implicit none
   private

   public :: machine_switching

   !> A set-valued law's run with exact stick and slip, as run.f90's, with
   !> the tangent Φ beside the state when asked (the spectrum), or without
   !> it (Benettin's two runs).
   type :: machine_switching
      type(mechanics) :: m
      real(wp) :: limit = 0.0_wp, h = 0.0_wp, direction = 1.0_wp
      type(machine_slip) :: slip                    !! the slip alone
      type(tangent_system) :: slipping_system      !! the slip (its base) with its tangent
      type(machine_stick) :: stick
      type(event_locator) :: slipping, sticking
      logical :: tangent = .false., in_stick = .false.
      real(wp) :: t = 0.0_wp, y(2) = 0.0_wp, phi(2, 2) = 0.0_wp
      integer :: lost = 0                           !! directions stick mapped to 0 since the last reset
   contains
      procedure :: start => switching_start
      procedure :: advance_to => switching_advance
      procedure :: reset => switching_reset
      procedure, private :: pin => switching_pin
      procedure, private :: set_direction => switching_set_direction
      procedure, private :: restart_slip => switching_restart_slip
      procedure, private :: slip_field => switching_slip_field
      procedure, private :: saltation => switching_saltation
   end type machine_switching

contains

   !> Start at (t0, y0) as run.f90 does: stick where v = belt_velocity within
   !> the static limit, else slip (in the direction of w, or of the applied
   !> force); with `tangent`, Φ from the generic frame beside the state.
   subroutine switching_start(self, c, law, t0, y0, tangent, error)
      class(machine_switching), target, intent(inout) :: self
      type(machine_config), intent(in) :: c
      class(sliding_law), intent(in) :: law
      real(wp), intent(in) :: t0, y0(2)
      logical, intent(in) :: tangent
      type(error_type), allocatable, intent(out) :: error
      type(machine_slip) :: slip
      real(wp) :: a

      call self%m%from_config(c)
      self%limit = law%static_force(self%m%normal)
      self%tangent = tangent
      slip%m = self%m
      allocate (slip%law, source=law)
      if (allocated(self%slipping_system%base)) deallocate (self%slipping_system%base)
      allocate (self%slipping_system%base, source=slip)
      self%slip = slip
      self%stick%m = self%m
      self%stick%limit = self%limit
      self%h = c%solver%h_start
      if (.not. (self%h > 0.0_wp)) self%h = 1.0e-6_wp * c%dt_out
      if (tangent) then
         call self%slipping%init(self%slipping_system, c%solver, [event_falling], [.true.], c%event_tolerance, &
            & self%h, error, 't', ' s')
      else
         call self%slipping%init(self%slip, c%solver, [event_falling], [.true.], c%event_tolerance, self%h, error, &
            & 't', ' s')
      end if
      if (allocated(error)) return
      call self%sticking%init(self%stick, c%solver, [event_falling, event_falling], [.true., .true.], &
         & c%event_tolerance, self%h, error, 't', ' s')
      if (allocated(error)) return
      self%t = t0
      self%y = y0
      self%phi = generic_frame(2)
      self%lost = 0
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

   !> Through any number of stick and slip phases to t_target.  In slip Φ
   !> follows the slip's variational equations; in stick v is the belt's, so
   !> δv is set to 0 (the direction lost) and δx is carried unchanged
   !> (x' = belt_velocity does not depend on the state).  At each switch
   !> through the surface h(t, y) = 0 from the field f⁻ into f⁺,
   !> Φ ← (I + (f⁺ - f⁻) ∇hᵀ / (∇h·f⁻ + ∂h/∂t)) Φ (docs/chaos.md).
   subroutine switching_advance(self, t_target, error, watch)
      class(machine_switching), intent(inout) :: self
      real(wp), intent(in) :: t_target
      type(error_type), allocatable, intent(out) :: error
      class(step_watch), intent(inout) :: watch
      real(wp) :: zz(6), sigma, f_minus(2), a
      integer :: which

      associate (t => self%t, y => self%y, phi => self%phi, m => self%m)
         do while (t < t_target)
            if (self%in_stick) then
               call self%pin()
               call self%sticking%advance(t, t_target, y, error, watch)
               if (allocated(error)) return
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
               ! h = s (v - belt): the slip in direction s ends.
               f_minus = self%slip_field()
               sigma = self%direction
               a = m%applied(t, y(1), m%belt)
               if (abs(a) <= self%limit) then
                  self%in_stick = .true.
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

   !> In stick: δv is forgotten.
   subroutine switching_pin(self)
      class(machine_switching), intent(inout) :: self

      if (self%tangent .and. any(self%phi(2, :) /= 0.0_wp)) then
         self%phi(2, :) = 0.0_wp
         self%lost = 1
      end if
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
      real(wp), intent(in) :: q(2, 2)

      self%phi = q
      self%lost = 0
      if (self%in_stick) then
         call self%sticking%restart(self%t, self%y, 0.0_wp)
      else
         call self%restart_slip(0.0_wp)
      end if
   end subroutine switching_reset

end module friction_machine_switching
