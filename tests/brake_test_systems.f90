!> The crank in stick as an ODE of its own, for an oracle independent of the
!> closed form: ξ y'' + κ y = x(τ), x = x0 + v'_dr (τ - τ0), state (y, y').
module brake_test_systems
   use friction_kinds, only: wp
   use friction_error, only: error_type
   use friction_ode_system, only: ode_system
   use friction_ode_solver, only: ode_solver, solver_settings
   use friction_brake_params, only: brake_parameters
   implicit none
   private
   public :: crank_in_stick, stick_end_oracle

   type, extends(ode_system) :: crank_in_stick
      real(wp) :: xi = 0.412_wp, kappa = 1.5_wp, x0 = 0.0_wp, v_dr = 0.0_wp, t0 = 0.0_wp
   contains
      procedure :: dimension
      procedure :: rhs
      procedure :: jacobian
   end type crank_in_stick

contains

   pure integer function dimension(self) result(n)
      class(crank_in_stick), intent(in) :: self
      n = 2
   end function dimension

   pure subroutine rhs(self, t, y, dydt)
      class(crank_in_stick), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in), contiguous :: y(:)
      real(wp), intent(out), contiguous :: dydt(:)
      dydt(1) = y(2)
      dydt(2) = (self%x0 + self%v_dr * (t - self%t0) - self%kappa * y(1)) / self%xi
   end subroutine rhs

   pure subroutine jacobian(self, t, y, dfdy, dfdt)
      class(crank_in_stick), intent(in) :: self
      real(wp), intent(in) :: t, y(:)
      real(wp), intent(out) :: dfdy(:, :), dfdt(:)
      dfdy = reshape([0.0_wp, -self%kappa / self%xi, 1.0_wp, 0.0_wp], [2, 2])
      dfdt = [0.0_wp, self%v_dr / self%xi]
   end subroutine jacobian

   !> Where the integrated stick ODE from (t0, y0) first reaches the static
   !> limit: sample 200 points up to t_guess (and as far again), then
   !> bisect to 1e-11.  Each trial integrates afresh from t0.
   subroutine stick_end_oracle(p, t0, y0, t_guess, t_end, message)
      type(brake_parameters), intent(in) :: p
      real(wp), intent(in) :: t0, y0(4), t_guess
      real(wp), intent(out) :: t_end
      character(len=:), allocatable, intent(inout) :: message
      real(wp) :: a, b, m
      integer :: i

      a = t0
      b = t0
      do i = 1, 400
         b = t0 + i * (t_guess - t0) / 200
         if (limit_margin(p, t0, y0, b, message) < 0.0_wp) exit
         a = b
      end do
      do while (b - a > 1.0e-11_wp)
         m = 0.5_wp * (a + b)
         if (limit_margin(p, t0, y0, m, message) < 0.0_wp) then
            b = m
         else
            a = m
         end if
      end do
      t_end = b
   end subroutine stick_end_oracle

   !> μs N' - |2x - y| at time t of a stick from (t0, y0), the crank integrated
   !> by GSL rk8pd at 1e-13.
   real(wp) function limit_margin(p, t0, y0, t, message)
      type(brake_parameters), intent(in) :: p
      real(wp), intent(in) :: t0, y0(4), t
      character(len=:), allocatable, intent(inout) :: message
      type(crank_in_stick), target :: crank
      type(ode_solver) :: solver
      type(solver_settings) :: settings
      type(error_type), allocatable :: error
      real(wp) :: s, y(2), x

      crank%xi = p%xi
      crank%kappa = p%kappa
      crank%x0 = y0(1)
      crank%v_dr = p%v_dr
      crank%t0 = t0
      settings%method = 'rk8pd'
      settings%rtol = 1.0e-13_wp
      settings%atol = 1.0e-15_wp
      call solver%init(crank, settings, 1.0e-3_wp, error)
      s = t0
      y = y0(3:4)
      if (t > t0) call solver%advance(s, t, y, error)
      if (allocated(error)) message = error%message
      x = y0(1) + p%v_dr * (t - t0)
      limit_margin = p%mu_s * ((1.0_wp - p%kappa) * y(1) + p%g_prime) - abs(2.0_wp * x - y(1))
   end function limit_margin

end module brake_test_systems
