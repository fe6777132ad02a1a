!> The whole Lyapunov spectrum from the tangent (variational) equations
!> (docs/physics.md, chaos diagnostics): the orbit y' = f(y) and n tangent
!> vectors Φ' = J(y) Φ integrated side by side; every renormalisation
!> interval Φ is factored Φ = Q R by modified Gram–Schmidt, log |R_ii| is
!> summed and Φ is replaced by Q.  The sums over the elapsed time converge
!> to the exponents λ_1 >= ... >= λ_n.
!>
!> Directions a nonsmooth flow maps to zero exactly (the brake in stick
!> forgets the velocity of the block) are `lost`: the caller says how many
!> per interval, their columns are completed to an orthonormal basis and
!> their exponents reported as -inf.
!>
!> `tangent_system` wraps any ode_system (and its events, if it has any) as
!> the extended system z = (y, Φ) of dimension n + n², Φ stored by columns.
module friction_analysis_lyapunov_spectrum
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_negative_inf
   use friction_kinds, only: wp
   use friction_error, only: error_type, fatal_error, error_input
   use friction_ode_system, only: ode_system
   use friction_ode_events, only: event_system
   use friction_ode_forwarding, only: forwarding_system
   use friction_ode_solver, only: ode_solver, solver_settings
   implicit none
   private

   public :: tangent_system, tangent_settings, spectrum_accumulator, tangent_spectrum, kaplan_yorke
   public :: orthonormalise, pack_tangent, unpack_tangent, generic_frame, tangent_field

   !> The orbit and its tangent matrix as one system (events: those of the
   !> base; its relative component the base's, whose components come first).
   type, extends(forwarding_system) :: tangent_system
   contains
      procedure :: dimension => tangent_dimension
      procedure :: controlled_dimension => tangent_controlled_dimension
      procedure :: rhs => tangent_rhs
      procedure :: jacobian => tangent_jacobian
      procedure :: event_count => tangent_event_count
      procedure :: event_values => tangent_event_values
   end type tangent_system

   type :: tangent_settings
      real(wp) :: transient = 100.0_wp     !! time integrated before measuring
      real(wp) :: duration = 1000.0_wp     !! time over which the logs are summed
      real(wp) :: renormalise = 1.0_wp     !! interval between QR factorisations
   end type tangent_settings

   !> Sums of log |R_ii| and the running estimates.
   type :: spectrum_accumulator
      integer :: n = 0
      integer :: lost = 0                   !! directions mapped to zero (exponent -inf)
      real(wp), allocatable :: log_sum(:)
      real(wp) :: elapsed = 0.0_wp
      integer :: count = 0
      real(wp), allocatable :: time(:)       !! measuring time at each renormalisation
      real(wp), allocatable :: history(:, :) !! (n, count): running exponents, QR column order
   contains
      procedure :: start => accumulator_start
      procedure :: renormalise => accumulator_renormalise
      procedure :: add_logs => accumulator_add_logs
      procedure :: exponents => accumulator_exponents
   end type spectrum_accumulator

contains

   pure function tangent_dimension(self) result(n)
      class(tangent_system), intent(in) :: self
      integer :: n

      n = self%base%dimension()
      n = n + n * n
   end function tangent_dimension

   !> The step-size control measures the orbit only: the tangent equations
   !> are linear along it with the orbit's own time scales, so the orbit's
   !> steps integrate them as accurately, and letting their (growing,
   !> renormalised) columns vote cost 1.46 times the steps of the plain run
   !> on the brake (docs/speed.md, Lyapunov spectrum).
   pure function tangent_controlled_dimension(self) result(n)
      class(tangent_system), intent(in) :: self
      integer :: n

      n = self%base%dimension()
   end function tangent_controlled_dimension

   !> (f(y), J(y) Φ), Φ by columns.
   pure subroutine tangent_rhs(self, t, y, dydt)
      class(tangent_system), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in), contiguous :: y(:)
      real(wp), intent(out), contiguous :: dydt(:)

      call tangent_field(self, t, y, dydt)
   end subroutine tangent_rhs

   !> The tangent system's right-hand side (f(y), J(y) Φ) into dydt(1:n + n²),
   !> and tr J(y) if asked (the flow's divergence), from one Jacobian.  No
   !> room of its own, whatever n (this is the hot loop, and a pure procedure
   !> has no workspace to keep): J is written where J Φ goes and replaced by
   !> it row by row, the row in hand kept where f goes, which comes last.
   pure subroutine tangent_field(self, t, y, dydt, trace)
      class(tangent_system), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in), contiguous :: y(:)
      real(wp), intent(out), contiguous :: dydt(:)
      real(wp), intent(out), optional :: trace
      integer :: n

      n = self%base%dimension()
      call jacobian_times_frame(self%base, t, y, n, dydt(1:n), dydt(n + 1:n + n * n), trace)
      call self%base%rhs(t, y(1:n), dydt(1:n))
   end subroutine tangent_field

   !> jphi = J(y) Φ (Φ = y(n + 1:) by columns), with `row` as room; tr J if asked.
   pure subroutine jacobian_times_frame(base, t, y, n, row, jphi, trace)
      class(ode_system), intent(in) :: base
      real(wp), intent(in) :: t
      real(wp), intent(in) :: y(:)
      integer, intent(in) :: n
      real(wp), intent(out) :: row(n), jphi(n, n)
      real(wp), intent(out), optional :: trace
      real(wp) :: sum
      integer :: i, j, k, c

      call base%jacobian(t, y(1:n), jphi, row)
      if (present(trace)) then
         trace = 0.0_wp
         do i = 1, n
            trace = trace + jphi(i, i)
         end do
      end if
      ! Row i of J Φ needs row i of J only: keep that row, overwrite it.
      do i = 1, n
         row = jphi(i, :)
         do j = 1, n
            c = n + (j - 1) * n
            sum = 0.0_wp
            do k = 1, n
               sum = sum + row(k) * y(c + k)
            end do
            jphi(i, j) = sum
         end do
      end do
   end subroutine jacobian_times_frame

   !> Jacobian of (f, J Φ) for the implicit steppers: J on the diagonal
   !> blocks, and ∂(J Φ)/∂y from central differences of the analytic J
   !> (the orbit does not depend on Φ, so the upper right block is 0).  No
   !> room of its own (an implicit stepper asks for it every step, and an
   !> allocation a call cost more than the small J's): J at y+h and y-h go
   !> where the upper right block's zeros go, the perturbed y and the
   !> unused ∂f/∂t where dfdt's zeros go, both zeroed at the end; n = 1,
   !> whose blocks have no such room, in a few numbers on the stack.
   pure subroutine tangent_jacobian(self, t, y, dfdy, dfdt)
      class(tangent_system), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: y(:)
      real(wp), intent(out) :: dfdy(:, :)
      real(wp), intent(out) :: dfdt(:)
      real(wp) :: one(1, 3), one_y(1), h, sum, reference, floor
      integer :: n, i, j, k, l, relative

      n = self%base%dimension()
      call self%base%relative_component(relative, reference, floor)
      dfdy = 0.0_wp
      dfdt = 0.0_wp
      call self%base%jacobian(t, y(1:n), dfdy(1:n, 1:n), dfdt(1:n))
      ! (Loops, here and below: sections of one array on both sides would be copied through a temporary.)
      do j = 1, n
         do k = 1, n
            do i = 1, n
               dfdy(n + (j - 1) * n + i, n + (j - 1) * n + k) = dfdy(i, k)
            end do
         end do
      end do
      if (n == 1) then
         h = 1.0e-6_wp * max(1.0_wp, abs(y(1)))
         one_y = y(1) + h
         call self%base%jacobian(t, one_y, one(:, 1:1), one(1, 3:3))
         one_y = y(1) - h
         call self%base%jacobian(t, one_y, one(:, 2:2), one(1, 3:3))
         dfdy(2, 1) = (one(1, 1) - one(1, 2)) / (2.0_wp * h) * y(2)
         return
      end if
      associate (jp => dfdy(1:n, n + 1:2 * n), jm => dfdy(1:n, 2 * n + 1:3 * n), yp => dfdt(n + 1:2 * n), &
         & d0 => dfdt(2 * n + 1:3 * n))
         do k = 1, n
            h = 1.0e-6_wp * max(1.0_wp, abs(y(k)))
            ! A slip rate the law takes the logarithm of is stepped relative to itself: 1e-6 across a creep of
            ! 1e-13 put J's 1/v_rel at v_rel ~ 0 into this block, and Φ's stages overflowed at any step above 1e-7.
            if (k == relative) h = 1.0e-6_wp * max(abs(y(k) - reference), floor)
            yp = y(1:n)
            yp(k) = y(k) + h
            call self%base%jacobian(t, yp, jp, d0)
            yp(k) = y(k) - h
            call self%base%jacobian(t, yp, jm, d0)
            do l = 1, n
               do i = 1, n
                  jp(i, l) = (jp(i, l) - jm(i, l)) / (2.0_wp * h)
               end do
            end do
            ! Column k of the lower left block: ∂J/∂y_k times each of Φ's columns (y holds Φ by columns).
            do j = 1, n
               do i = 1, n
                  sum = 0.0_wp
                  do l = 1, n
                     sum = sum + jp(i, l) * y(n + (j - 1) * n + l)
                  end do
                  dfdy(n + (j - 1) * n + i, k) = sum
               end do
            end do
         end do
         jp = 0.0_wp
         jm = 0.0_wp
         yp = 0.0_wp
         d0 = 0.0_wp
      end associate
   end subroutine tangent_jacobian

   pure function tangent_event_count(self) result(m)
      class(tangent_system), intent(in) :: self
      integer :: m

      m = 0
      select type (b => self%base)
      class is (event_system)
         m = b%event_count()
      end select
   end function tangent_event_count

   pure subroutine tangent_event_values(self, t, y, g)
      class(tangent_system), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: y(:)
      real(wp), intent(out) :: g(:)

      select type (b => self%base)
      class is (event_system)
         call b%event_values(t, y(1:b%dimension()), g)
      end select
   end subroutine tangent_event_values

   !> z = (y, Φ) with Φ by columns.
   pure function pack_tangent(y, phi) result(z)
      real(wp), intent(in) :: y(:), phi(:, :)
      real(wp) :: z(size(y) + size(phi))

      z(1:size(y)) = y
      z(size(y) + 1:) = reshape(phi, [size(phi)])
   end function pack_tangent

   pure subroutine unpack_tangent(z, y, phi)
      real(wp), intent(in) :: z(:)
      real(wp), intent(out) :: y(:), phi(:, :)

      y = z(1:size(y))
      phi = reshape(z(size(y) + 1:size(y) + size(phi)), shape(phi))
   end subroutine unpack_tangent

   !> Modified Gram–Schmidt with one reorthogonalisation: Φ = Q R, Φ replaced
   !> by Q and r(i) = R_ii.  The last `lost` columns (directions the flow
   !> mapped to zero) are not factored but completed to an orthonormal basis
   !> from the unit vectors, r = 0 there.
   pure subroutine orthonormalise(phi, r, lost)
      real(wp), intent(inout) :: phi(:, :)
      real(wp), intent(out) :: r(:)
      integer, intent(in) :: lost
      real(wp) :: v(size(phi, 1)), best(size(phi, 1)), norm_best
      integer :: n, i, j, k, pass

      n = size(phi, 2)
      r = 0.0_wp
      do k = 1, n
         if (k <= n - lost) then
            v = phi(:, k)
            do pass = 1, 2
               do i = 1, k - 1
                  v = v - dot_product(phi(:, i), v) * phi(:, i)
               end do
            end do
            r(k) = norm2(v)
            if (r(k) > 0.0_wp) then
               phi(:, k) = v / r(k)
               cycle
            end if
         end if
         ! Complete the basis: the unit vector with the largest part outside it.
         norm_best = -1.0_wp
         do j = 1, size(phi, 1)
            v = 0.0_wp
            v(j) = 1.0_wp
            do pass = 1, 2
               do i = 1, k - 1
                  v = v - dot_product(phi(:, i), v) * phi(:, i)
               end do
            end do
            if (norm2(v) > norm_best) then
               norm_best = norm2(v)
               best = v
            end if
         end do
         phi(:, k) = best / norm_best
      end do
   end subroutine orthonormalise

   !> A fixed orthonormal frame in general position (the QR of I + the Hilbert
   !> matrix) to start the tangent vectors from: no vector along a coordinate
   !> axis, so a direction a nonsmooth flow maps to zero (the brake's velocity
   !> in stick) is not one of the first n - lost and shows up in the last column.
   pure function generic_frame(n) result(q)
      integer, intent(in) :: n
      real(wp) :: q(n, n)
      real(wp) :: r(n)
      integer :: i, j

      do j = 1, n
         do i = 1, n
            q(i, j) = 1.0_wp / real(i + j - 1, wp)
         end do
         q(j, j) = q(j, j) + 1.0_wp
      end do
      call orthonormalise(q, r, 0)
   end function generic_frame

   pure subroutine accumulator_start(self, n, capacity)
      class(spectrum_accumulator), intent(inout) :: self
      integer, intent(in) :: n, capacity

      self%n = n
      self%lost = 0
      self%elapsed = 0.0_wp
      self%count = 0
      if (allocated(self%log_sum)) deallocate (self%log_sum, self%time, self%history)
      allocate (self%log_sum(n), self%time(max(capacity, 1)), self%history(n, max(capacity, 1)))
      self%log_sum = 0.0_wp
   end subroutine accumulator_start

   !> Factor Φ after an interval in which `lost` directions were mapped to
   !> zero; Φ becomes Q.
   subroutine accumulator_renormalise(self, phi, interval, lost)
      class(spectrum_accumulator), intent(inout) :: self
      real(wp), intent(inout) :: phi(:, :)
      real(wp), intent(in) :: interval
      integer, intent(in) :: lost
      real(wp) :: r(self%n)
      integer :: i

      call orthonormalise(phi, r, lost)
      do i = 1, self%n - lost
         r(i) = log(r(i))
      end do
      call self%add_logs(r, interval, lost)
   end subroutine accumulator_renormalise

   !> An interval's sums of log |R_ii| by a caller that factored Φ itself
   !> (more than once in the interval: machine/lyapunov.f90's stiff tangent).
   subroutine accumulator_add_logs(self, logs, interval, lost)
      class(spectrum_accumulator), intent(inout) :: self
      real(wp), intent(in) :: logs(:)
      real(wp), intent(in) :: interval
      integer, intent(in) :: lost

      self%lost = max(self%lost, lost)
      self%log_sum(1:self%n - lost) = self%log_sum(1:self%n - lost) + logs(1:self%n - lost)
      self%elapsed = self%elapsed + interval
      if (self%count < size(self%time)) then
         self%count = self%count + 1
         self%time(self%count) = self%elapsed
         self%history(:, self%count) = running(self)
      end if
   end subroutine accumulator_add_logs

   !> The running estimates in QR column order, -inf for lost directions.
   function running(self) result(lambda)
      type(spectrum_accumulator), intent(in) :: self
      real(wp) :: lambda(self%n)

      lambda = 0.0_wp
      if (self%elapsed > 0.0_wp) lambda = self%log_sum / self%elapsed
      if (self%lost > 0) lambda(self%n - self%lost + 1:) = ieee_value(1.0_wp, ieee_negative_inf)
   end function running

   !> The exponents, largest first.
   function accumulator_exponents(self) result(lambda)
      class(spectrum_accumulator), intent(in) :: self
      real(wp) :: lambda(self%n)
      real(wp) :: swap
      integer :: i, j

      lambda = running(self)
      do i = 2, self%n
         do j = i, 2, -1
            if (.not. (lambda(j) > lambda(j - 1))) exit
            swap = lambda(j)
            lambda(j) = lambda(j - 1)
            lambda(j - 1) = swap
         end do
      end do
   end function accumulator_exponents

   !> Kaplan–Yorke dimension j + (λ_1 + ... + λ_j)/|λ_{j+1}| of exponents
   !> sorted largest first, j the largest with a nonnegative partial sum
   !> (0 if λ_1 < 0, n if the whole sum is nonnegative).  A -inf λ_{j+1}
   !> adds nothing: D = j.
   pure real(wp) function kaplan_yorke(lambda) result(d)
      real(wp), intent(in) :: lambda(:)
      real(wp) :: partial
      integer :: j

      d = 0.0_wp
      partial = 0.0_wp
      do j = 1, size(lambda)
         if (partial + lambda(j) < 0.0_wp) then
            if (j > 1) d = (j - 1) + partial / abs(lambda(j))
            return
         end if
         partial = partial + lambda(j)
      end do
      d = size(lambda)
   end function kaplan_yorke

   !> The spectrum of a smooth system from y0 at t0: the orbit alone over the
   !> transient, then orbit and tangent from the generic frame.
   subroutine tangent_spectrum(system, solver, y0, t0, settings, result, error)
      class(ode_system), intent(in) :: system
      type(solver_settings), intent(in) :: solver
      real(wp), intent(in) :: y0(:), t0
      type(tangent_settings), intent(in) :: settings
      type(spectrum_accumulator), intent(out) :: result
      type(error_type), allocatable, intent(out) :: error
      type(tangent_system), target :: extended
      type(ode_solver) :: orbit, tangent
      real(wp) :: t, y(size(y0)), phi(size(y0), size(y0)), z(size(y0) * (size(y0) + 1)), h
      integer :: n, k, intervals

      if (.not. (settings%renormalise > 0.0_wp .and. settings%duration >= settings%renormalise &
         & .and. settings%transient >= 0.0_wp)) then
         call fatal_error(error, 'Lyapunov spectrum: need renormalise > 0, duration >= renormalise, ' &
            & //'transient >= 0', error_input)
         return
      end if
      n = size(y0)
      allocate (extended%base, source=system)
      h = solver%h_start
      if (.not. (h > 0.0_wp)) h = 1.0e-3_wp
      y = y0
      t = t0
      if (settings%transient > 0.0_wp) then
         call orbit%init(extended%base, solver, h, error)
         if (allocated(error)) return
         call orbit%advance(t, t0 + settings%transient, y, error)
         call orbit%destroy()
         if (allocated(error)) return
      end if
      phi = generic_frame(n)
      call tangent%init(extended, solver, h, error)
      if (allocated(error)) return
      intervals = nint(settings%duration / settings%renormalise)
      call result%start(n, intervals)
      do k = 1, intervals
         z = pack_tangent(y, phi)
         call tangent%advance(t, t0 + settings%transient + k * settings%renormalise, z, error)
         if (allocated(error)) exit
         call unpack_tangent(z, y, phi)
         call result%renormalise(phi, settings%renormalise, 0)
         ! Φ changed under the stepper: restart it (steppers with memory), at the step it had reached.
         call tangent%restart(tangent%step_size())
      end do
      call tangent%destroy()
   end subroutine tangent_spectrum

end module friction_analysis_lyapunov_spectrum
