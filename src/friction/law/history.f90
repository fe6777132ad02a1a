!> A law on its own, driven along a prescribed history of the sliding
!> velocity or of the displacement: the friction force (and the internal
!> states) at the history's times, the hysteresis loops and velocity steps
!> laws are calibrated against (docs/laws.md).
!>
!> - Velocity history: v is linear between the samples; F(t_i) uses v(t_i).
!> - Displacement history: x is linear between the samples, so v is constant
!>   on each interval, (x_i+1 - x_i)/(t_i+1 - t_i); F(t_i+1) uses the velocity
!>   of the interval that ends there, F(t_1) that of the first interval.
!> The states are integrated interval by interval (a restart at each sample,
!> where v or its slope jumps), in units of the law's state scale so that
!> one absolute tolerance fits every law.  The rest of the mechanism applies
!> no force: a set-valued law at v = 0 gives F = 0, the middle of its set.
module friction_law_history
   use friction_kinds, only: wp
   use friction_error, only: error_type, fatal_error, error_input
   use friction_strings, only: itoa
   use friction_ode_system, only: ode_system
   use friction_ode_solver, only: ode_solver, solver_settings
   use friction_law, only: sliding_law, max_law_states
   implicit none
   private

   public :: law_history, history_velocity, history_displacement, history_solver_defaults

   integer, parameter :: history_velocity = 0, history_displacement = 1

   !> Rodas4 (stiff: LuGre's σ0 = 1e5 N/m makes the bristle's time scale
   !> 1e-8 s at 1 m/s), tolerances in the scaled states.
   type(solver_settings), parameter :: history_solver_defaults = solver_settings(method='rodas4', &
      & rtol=1.0e-9_wp, atol=1.0e-11_wp)

   !> The law's states over one interval, v linear in t, in scaled units.
   type, extends(ode_system) :: state_system
      class(sliding_law), allocatable :: law
      integer :: n = 0
      real(wp) :: normal = 0.0_wp
      real(wp) :: t0 = 0.0_wp, v0 = 0.0_wp, dvdt = 0.0_wp
      real(wp) :: scale(max_law_states) = 1.0_wp
   contains
      procedure :: dimension
      procedure :: rhs
      procedure :: jacobian
   end type state_system

contains

   pure function dimension(self) result(n)
      class(state_system), intent(in) :: self
      integer :: n

      n = self%n
   end function dimension

   pure subroutine rhs(self, t, y, dydt)
      class(state_system), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in), contiguous :: y(:)
      real(wp), intent(out), contiguous :: dydt(:)

      call self%law%state_rate(self%v0 + self%dvdt * (t - self%t0), y * self%scale(1:self%n), self%normal, dydt)
      dydt = dydt / self%scale(1:self%n)
   end subroutine rhs

   pure subroutine jacobian(self, t, y, dfdy, dfdt)
      class(state_system), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: y(:)
      real(wp), intent(out) :: dfdy(:, :)
      real(wp), intent(out) :: dfdt(:)
      real(wp) :: dfdv, dfdz(self%n), dfda, dgdv(self%n), dgdz(self%n, self%n)
      integer :: i, j

      call self%law%partials(self%v0 + self%dvdt * (t - self%t0), y * self%scale(1:self%n), self%normal, 0.0_wp, &
         & dfdv, dfdz, dfda, dgdv, dgdz)
      do j = 1, self%n
         do i = 1, self%n
            dfdy(i, j) = dgdz(i, j) * self%scale(j) / self%scale(i)
         end do
      end do
      dfdt = dgdv * self%dvdt / self%scale(1:self%n)
   end subroutine jacobian

   !> F(t_i) (N) and the states z(:, i) along the history u (velocities in
   !> m/s or displacements in m, as `kind` says) at the times t (s,
   !> strictly increasing); the states start at z0, or at steady sliding
   !> with the first velocity.  A prepared law (friction_law_factory's
   !> make_law).
   subroutine law_history(law, normal, t, u, kind, settings, force, states, error, z0)
      class(sliding_law), intent(in) :: law
      real(wp), intent(in) :: normal, t(:), u(:)
      integer, intent(in) :: kind
      type(solver_settings), intent(in) :: settings
      real(wp), intent(out) :: force(:), states(:, :)
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(in), optional :: z0(:)
      type(state_system), target :: system
      type(ode_solver) :: solver
      real(wp), allocatable :: v(:)
      real(wp) :: z(max_law_states), w(max_law_states), time, h
      integer :: n, m, i

      n = size(t)
      m = law%state_count()
      if (size(u) /= n .or. size(force) < n .or. size(states, 1) < m .or. (m > 0 .and. size(states, 2) < n)) then
         call fatal_error(error, 'law history: the arrays'' lengths differ from the '//itoa(n)//' times', error_input)
         return
      end if
      if (kind == history_displacement .and. n < 2) then
         call fatal_error(error, 'law history: a displacement history needs at least 2 samples', error_input)
         return
      end if
      if (n == 0) return
      if (.not. all(abs(t) <= huge(t)) .or. .not. all(abs(u) <= huge(u))) then
         call fatal_error(error, 'law history: times and values must be finite numbers', error_input)
         return
      end if
      if (n > 1) then
         if (.not. all(t(2:n) > t(1:n - 1))) then
            call fatal_error(error, 'law history: the times must increase strictly', error_input)
            return
         end if
      end if
      ! The velocity at each sample (and on each interval, below).
      allocate (v(n))
      if (kind == history_displacement) then
         v(2:n) = (u(2:n) - u(1:n - 1)) / (t(2:n) - t(1:n - 1))
         v(1) = v(2)
      else
         v = u
      end if
      z = 0.0_wp
      if (m > 0) then
         if (present(z0)) then
            if (size(z0) /= m) then
               call fatal_error(error, 'law history: '//itoa(size(z0))//' initial states for a law of '//itoa(m), &
                  & error_input)
               return
            end if
            z(1:m) = z0
         else
            call law%steady_state(v(1), normal, z(1:m))
         end if
         allocate (system%law, source=law)
         system%n = m
         system%normal = normal
         call law%state_scale(system%scale(1:m))
         h = settings%h_start
         if (.not. (h > 0.0_wp)) h = 1.0e-6_wp * (t(min(n, 2)) - t(1) + merge(1.0_wp, 0.0_wp, n == 1))
         call solver%init(system, settings, h, error)
         if (allocated(error)) return
         states(1:m, 1) = z(1:m)
      end if
      force(1) = law%force(v(1), z(1:m), normal, 0.0_wp)
      do i = 1, n - 1
         if (m > 0) then
            system%t0 = t(i)
            if (kind == history_displacement) then
               system%v0 = v(i + 1)
               system%dvdt = 0.0_wp
            else
               system%v0 = v(i)
               system%dvdt = (v(i + 1) - v(i)) / (t(i + 1) - t(i))
            end if
            if (i > 1) then
               h = solver%step_size()
               if (.not. (h > 0.0_wp) .or. h > t(i + 1) - t(i)) h = t(i + 1) - t(i)
               call solver%restart(h, error)
               if (allocated(error)) return
            end if
            time = t(i)
            w(1:m) = z(1:m) / system%scale(1:m)
            call solver%advance(time, t(i + 1), w(1:m), error)
            if (allocated(error)) then
               error%message = 'law history, interval '//itoa(i)//': '//error%message
               return
            end if
            z(1:m) = w(1:m) * system%scale(1:m)
            states(1:m, i + 1) = z(1:m)
         end if
         force(i + 1) = law%force(v(i + 1), z(1:m), normal, 0.0_wp)
      end do
   end subroutine law_history

end module friction_law_history
