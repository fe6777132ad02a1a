!> The machine's equations of motion as ODE systems (docs/laws.md,
!> "Mechanisms").  State (x, v, ẑ): the block's displacement (m) and
!> velocity (m/s) and the law's states in units of their scale (ẑ = z/scale,
!> so that one absolute tolerance fits them all).
!>
!> - machine_smooth: a law that is single-valued (arctan, Karnopp, Dahl,
!>   LuGre, elasto-plastic, rate and state), one ODE with the law's states
!>   (Karnopp's run with its band's edges located: band.f90).
!> - machine_slip, machine_stick: a set-valued law (Coulomb, Stribeck, the
!>   table) with exact stick.  In slip the law's slip force with the sign s
!>   of the sliding velocity w = v - belt_velocity held fixed; the slip ends
!>   when s w falls through 0 (event 1); a periodic orbit's section, v
!>   rising through a level, is event 2 when asked.  In stick v = belt_velocity exactly,
!>   and the stick ends when the applied force A reaches the static limit,
!>   F_s - A (event 1) or F_s + A (event 2) falling through 0.
module friction_machine_model
   use friction_kinds, only: wp, pi
   use friction_ode_events, only: event_system
   use friction_law, only: sliding_law, max_law_states
   use friction_law_kinked, only: law_flow
   use friction_machine_config, only: machine_config
   implicit none
   private

   public :: mechanics, machine_smooth, machine_slip, machine_stick

   !> The mechanism's parameters and the support's motion.
   type :: mechanics
      real(wp) :: mass = 1.0_wp, stiffness = 0.0_wp, damping = 0.0_wp, normal = 0.0_wp
      real(wp) :: belt = 0.0_wp, load = 0.0_wp, amplitude = 0.0_wp, omega = 0.0_wp
   contains
      procedure :: from_config
      procedure :: support
      procedure :: support_velocity
      procedure :: support_acceleration
      procedure :: applied
      procedure :: applied_rate
   end type mechanics

   !> (The law, its states' count and scales: law_flow's.)
   type, extends(law_flow) :: machine_smooth
      type(mechanics) :: m
   contains
      procedure :: dimension => smooth_dimension
      procedure :: rhs => smooth_rhs
      procedure :: jacobian => smooth_jacobian
      procedure :: relative_component => smooth_relative_component
      procedure :: event_count => smooth_event_count
      procedure :: event_values => smooth_event_values
      procedure :: law_arguments => smooth_law_arguments
   end type machine_smooth

   type, extends(event_system) :: machine_slip
      type(mechanics) :: m
      class(sliding_law), allocatable :: law
      real(wp) :: direction = 1.0_wp
      logical :: sectioned = .false.        !! event 2: v - section_level rising (a periodic orbit's section)
      real(wp) :: section_level = 0.0_wp    !! m/s
   contains
      procedure :: dimension => two
      procedure :: rhs => slip_rhs
      procedure :: jacobian => slip_jacobian
      procedure :: event_count => slip_event_count
      procedure :: event_values => slip_event_values
   end type machine_slip

   type, extends(event_system) :: machine_stick
      type(mechanics) :: m
      real(wp) :: limit = 0.0_wp   !! the static limit F_s (N)
   contains
      procedure :: dimension => stick_dimension
      procedure :: rhs => stick_rhs
      procedure :: jacobian => stick_jacobian
      procedure :: event_count => stick_event_count
      procedure :: event_values => stick_event_values
   end type machine_stick

contains

   subroutine from_config(self, c)
      class(mechanics), intent(out) :: self
      type(machine_config), intent(in) :: c

      self%mass = c%mass
      self%stiffness = c%stiffness
      self%damping = c%damping
      self%normal = c%normal
      self%belt = c%belt_velocity
      self%load = c%load_velocity
      self%amplitude = c%support_amplitude
      self%omega = 2.0_wp * pi * c%support_frequency
   end subroutine from_config

   pure real(wp) function support(self, t)
      class(mechanics), intent(in) :: self
      real(wp), intent(in) :: t

      support = self%load * t + self%amplitude * sin(self%omega * t)
   end function support

   pure real(wp) function support_velocity(self, t)
      class(mechanics), intent(in) :: self
      real(wp), intent(in) :: t

      support_velocity = self%load + self%amplitude * self%omega * cos(self%omega * t)
   end function support_velocity

   pure real(wp) function support_acceleration(self, t)
      class(mechanics), intent(in) :: self
      real(wp), intent(in) :: t

      support_acceleration = -self%amplitude * self%omega**2 * sin(self%omega * t)
   end function support_acceleration

   !> A = -k (x - u) - c (v - u'): every force on the block but friction.
   pure real(wp) function applied(self, t, x, v)
      class(mechanics), intent(in) :: self
      real(wp), intent(in) :: t, x, v

      applied = -self%stiffness * (x - self%support(t)) - self%damping * (v - self%support_velocity(t))
   end function applied

   !> ∂A/∂t at fixed x, v.
   pure real(wp) function applied_rate(self, t)
      class(mechanics), intent(in) :: self
      real(wp), intent(in) :: t

      applied_rate = self%stiffness * self%support_velocity(t) + self%damping * self%support_acceleration(t)
   end function applied_rate

   ! ---- smooth laws ----

   pure function smooth_dimension(self) result(n)
      class(machine_smooth), intent(in) :: self
      integer :: n

      n = 2 + self%n_states
   end function smooth_dimension

   pure subroutine smooth_rhs(self, t, y, dydt)
      class(machine_smooth), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in), contiguous :: y(:)
      real(wp), intent(out), contiguous :: dydt(:)
      real(wp) :: a, z(max_law_states), rate(max_law_states)
      integer :: n

      n = self%n_states
      z(1:n) = y(3:2 + n) * self%scale(1:n)
      a = self%m%applied(t, y(1), y(2))
      dydt(1) = y(2)
      dydt(2) = (a - self%law%force(y(2) - self%m%belt, z(1:n), self%m%normal, a)) / self%m%mass
      if (n > 0) then
         call self%law%state_rate(y(2) - self%m%belt, z(1:n), self%m%normal, rate(1:n))
         dydt(3:2 + n) = rate(1:n) / self%scale(1:n)
      end if
   end subroutine smooth_rhs

   pure subroutine smooth_jacobian(self, t, y, dfdy, dfdt)
      class(machine_smooth), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: y(:)
      real(wp), intent(out) :: dfdy(:, :)
      real(wp), intent(out) :: dfdt(:)
      real(wp) :: a, z(max_law_states), dfdv, dfdz(max_law_states), dfda, dgdv(max_law_states), &
         & dgdz(max_law_states, max_law_states)
      integer :: n, i, j

      n = self%n_states
      z(1:n) = y(3:2 + n) * self%scale(1:n)
      a = self%m%applied(t, y(1), y(2))
      call self%law%partials(y(2) - self%m%belt, z(1:n), self%m%normal, a, dfdv, dfdz(1:n), dfda, dgdv(1:n), &
         & dgdz(1:n, 1:n))
      dfdy = 0.0_wp
      dfdt = 0.0_wp
      dfdy(1, 2) = 1.0_wp
      ! v' = (A - F(w, z, A))/m with ∂A/∂x = -k, ∂A/∂v = -c.
      dfdy(2, 1) = -self%m%stiffness * (1.0_wp - dfda) / self%m%mass
      dfdy(2, 2) = (-self%m%damping * (1.0_wp - dfda) - dfdv) / self%m%mass
      dfdt(2) = (1.0_wp - dfda) * self%m%applied_rate(t) / self%m%mass
      do j = 1, n
         dfdy(2, 2 + j) = -dfdz(j) * self%scale(j) / self%m%mass
         dfdy(2 + j, 2) = dgdv(j) / self%scale(j)
         do i = 1, n
            dfdy(2 + i, 2 + j) = dgdz(i, j) * self%scale(j) / self%scale(i)
         end do
      end do
   end subroutine smooth_jacobian

   !> The slip rate v - belt (component 2) when the law's force goes with its
   !> logarithm (rate and state).
   pure subroutine smooth_relative_component(self, index, reference, floor)
      class(machine_smooth), intent(in) :: self
      integer, intent(out) :: index
      real(wp), intent(out) :: reference, floor

      floor = self%law%log_slip_floor()
      reference = self%m%belt
      index = merge(2, 0, floor > 0.0_wp)
   end subroutine smooth_relative_component

   pure function smooth_event_count(self) result(n)
      class(machine_smooth), intent(in) :: self
      integer :: n

      n = 0
   end function smooth_event_count

   pure subroutine smooth_event_values(self, t, y, g)
      class(machine_smooth), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: y(:)
      real(wp), intent(out) :: g(:)
   end subroutine smooth_event_values

   !> The law's arguments at y: the slip rate v - belt, the states, the normal load.
   pure subroutine smooth_law_arguments(self, y, v, z, normal)
      class(machine_smooth), intent(in) :: self
      real(wp), intent(in) :: y(:)
      real(wp), intent(out) :: v, z(:), normal

      v = y(2) - self%m%belt
      z = y(3:2 + self%n_states) * self%scale(1:self%n_states)
      normal = self%m%normal
   end subroutine smooth_law_arguments

   ! ---- set-valued laws: slip ----

   pure function two(self) result(n)
      class(machine_slip), intent(in) :: self
      integer :: n

      n = 2
   end function two

   pure subroutine slip_rhs(self, t, y, dydt)
      class(machine_slip), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in), contiguous :: y(:)
      real(wp), intent(out), contiguous :: dydt(:)
      real(wp) :: none(0)

      dydt(1) = y(2)
      dydt(2) = (self%m%applied(t, y(1), y(2)) - self%law%slip_force(y(2) - self%m%belt, none, self%m%normal, &
         & self%direction)) / self%m%mass
   end subroutine slip_rhs

   pure subroutine slip_jacobian(self, t, y, dfdy, dfdt)
      class(machine_slip), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: y(:)
      real(wp), intent(out) :: dfdy(:, :)
      real(wp), intent(out) :: dfdt(:)
      real(wp) :: none(0), dfdz(0), dgdv(0), dgdz(0, 0), dfdv, dfda, w, h

      w = y(2) - self%m%belt
      ! The slip force's slope: the law's partial derivative away from v = 0
      ! (there the set-valued law's force is the clipped applied force).
      if (w /= 0.0_wp) then
         call self%law%partials(w, none, self%m%normal, 0.0_wp, dfdv, dfdz, dfda, dgdv, dgdz)
      else
         h = 1.0e-9_wp
         dfdv = (self%law%slip_force(h, none, self%m%normal, self%direction) &
            & - self%law%slip_force(-h, none, self%m%normal, self%direction)) / (2.0_wp * h)
      end if
      dfdy = 0.0_wp
      dfdy(1, 2) = 1.0_wp
      dfdy(2, 1) = -self%m%stiffness / self%m%mass
      dfdy(2, 2) = (-self%m%damping - dfdv) / self%m%mass
      dfdt = [0.0_wp, self%m%applied_rate(t) / self%m%mass]
   end subroutine slip_jacobian

   pure function slip_event_count(self) result(n)
      class(machine_slip), intent(in) :: self
      integer :: n

      n = merge(2, 1, self%sectioned)
   end function slip_event_count

   pure subroutine slip_event_values(self, t, y, g)
      class(machine_slip), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: y(:)
      real(wp), intent(out) :: g(:)

      g(1) = self%direction * (y(2) - self%m%belt)
      if (self%sectioned) g(2) = y(2) - self%section_level
   end subroutine slip_event_values

   ! ---- set-valued laws: stick ----

   pure function stick_dimension(self) result(n)
      class(machine_stick), intent(in) :: self
      integer :: n

      n = 2
   end function stick_dimension

   pure subroutine stick_rhs(self, t, y, dydt)
      class(machine_stick), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in), contiguous :: y(:)
      real(wp), intent(out), contiguous :: dydt(:)

      dydt(1) = self%m%belt
      dydt(2) = 0.0_wp
   end subroutine stick_rhs

   pure subroutine stick_jacobian(self, t, y, dfdy, dfdt)
      class(machine_stick), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: y(:)
      real(wp), intent(out) :: dfdy(:, :)
      real(wp), intent(out) :: dfdt(:)

      dfdy = 0.0_wp
      dfdt = 0.0_wp
   end subroutine stick_jacobian

   pure function stick_event_count(self) result(n)
      class(machine_stick), intent(in) :: self
      integer :: n

      n = 2
   end function stick_event_count

   pure subroutine stick_event_values(self, t, y, g)
      class(machine_stick), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: y(:)
      real(wp), intent(out) :: g(:)
      real(wp) :: a

      a = self%m%applied(t, y(1), self%m%belt)
      g(1) = self%limit - a
      g(2) = self%limit + a
   end subroutine stick_event_values

end module friction_machine_model
