!> A block pushed by a force ramp over a surface with a friction law (the
!> LuGre paper's experiments of pre-sliding and break-away), integrated by
!> the library's ODE bridge: m x'' = u(t) - F(v, z), u = min(rate t, u_max),
!> state (x, v, z).  The test's own mechanism, so the laws are checked
!> before any scene uses them.
module law_test_systems
   use friction_kinds, only: wp
   use friction_ode_system, only: ode_system
   use friction_law, only: sliding_law
   implicit none
   private
   public :: pushed_block

   type, extends(ode_system) :: pushed_block
      class(sliding_law), allocatable :: law
      real(wp) :: mass = 1.0_wp, normal = 1.0_wp, rate = 1.0_wp, u_max = huge(1.0_wp)
   contains
      procedure :: dimension
      procedure :: rhs
      procedure :: jacobian
      procedure :: applied
   end type pushed_block

contains

   pure integer function dimension(self) result(n)
      class(pushed_block), intent(in) :: self
      n = 2 + self%law%state_count()
   end function dimension

   pure real(wp) function applied(self, t)
      class(pushed_block), intent(in) :: self
      real(wp), intent(in) :: t
      applied = min(self%rate * t, self%u_max)
   end function applied

   pure subroutine rhs(self, t, y, dydt)
      class(pushed_block), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in), contiguous :: y(:)
      real(wp), intent(out), contiguous :: dydt(:)
      integer :: n

      n = size(y)
      dydt(1) = y(2)
      dydt(2) = (self%applied(t) - self%law%force(y(2), y(3:n), self%normal, self%applied(t))) / self%mass
      if (n > 2) call self%law%state_rate(y(2), y(3:n), self%normal, dydt(3:n))
   end subroutine rhs

   pure subroutine jacobian(self, t, y, dfdy, dfdt)
      class(pushed_block), intent(in) :: self
      real(wp), intent(in) :: t, y(:)
      real(wp), intent(out) :: dfdy(:, :), dfdt(:)
      real(wp) :: dfdv, dfdz(size(y) - 2), dfda, dgdv(size(y) - 2), dgdz(size(y) - 2, size(y) - 2)
      integer :: n

      n = size(y)
      call self%law%partials(y(2), y(3:n), self%normal, self%applied(t), dfdv, dfdz, dfda, dgdv, dgdz)
      dfdy = 0.0_wp
      dfdy(1, 2) = 1.0_wp
      dfdy(2, 2) = -dfdv / self%mass
      dfdy(2, 3:n) = -dfdz / self%mass
      dfdy(3:n, 2) = dgdv
      dfdy(3:n, 3:n) = dgdz
      dfdt = 0.0_wp
      if (self%rate * t < self%u_max) dfdt(2) = self%rate * (1.0_wp - dfda) / self%mass
   end subroutine jacobian

end module law_test_systems
