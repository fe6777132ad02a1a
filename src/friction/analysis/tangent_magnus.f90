!> The tangent matrix Φ carried over one accepted step of an orbit by matrix
!> exponentials (docs/chaos.md, "How the tangent is propagated"), for the
!> whole Lyapunov spectrum of a stiff flow.
!>
!> Over the step [t_a, t_b] of length h, the fourth-order commutator-free
!> Magnus method
!>     Φ ← exp(h (β A1 + α A2)) exp(h (α A1 + β A2)) Φ,
!> α = 1/4 + √3/6, β = 1/4 - √3/6, A_i = J(t_i, y(t_i)) at the Gauss points
!> t_i = t_a + (1/2 ∓ √3/6) h, the states there from the cubic Hermite
!> interpolant of the step's ends.  An exponential damps a fast direction
!> at exactly its rate however long the step (a stiff stepper's stability
!> function does not), and det exp(X) = exp(tr X).
!>
!> A column that an exponential shrinks by e^-40 against another is lost to
!> rounding next to it, so each exponential is applied in parts
!> exp(X / 2^j), halved until R's diagonal spans at most e^18 in each, and
!> Φ is factored Φ = Q R after every part: Φ stays orthonormal between
!> steps, and the logs of R's diagonal are summed into the caller's `logs`.
!> The parts follow the stiffness met: about (λ_max - λ_min) h / 18 of them.
!>
!> With `closed` the last column is left out of that count: its log is
!> tr X less the others' (det exp(X) = e^tr X, Φ orthonormal before each
!> part) and its direction the complement of the others, so a single
!> direction contracting faster than any number of parts resolves (a creep
!> slip rate relaxing at 1e8 per τ over a step of τ) costs the parts the
!> other directions need.  X is then scaled into the Padé's range however
!> large (at most 2^max_closed_scaling).
module friction_analysis_tangent_magnus
   use friction_kinds, only: wp, i8
   use friction_error, only: error_type, fatal_error, error_numerical
   use friction_ode_system, only: ode_system
   use friction_ode_solver, only: ode_solver
   implicit none
   private

   public :: magnus_tangent_step, orbit_step, tangent_over_step, jacobian_trace, simpson_trace, step_state

   !> A part may shrink a column to e^-part_spread of another: the
   !> factorisation then loses at most e^18 ulp = 1.5e-8 of the small one,
   !> 1e-9 of its log.
   real(wp), parameter :: part_spread = 18.0_wp
   !> ||X||_1 at most 2^max_parts / 2 (beyond, J is not a number worth trusting).
   integer, parameter :: max_parts = 60
   !> ||X||_1 at most 2^max_closed_scaling / 2 when the last column is closed by the trace.
   integer, parameter :: max_closed_scaling = 1000
   !> At most 2^max_level parts to an exponential (seconds of work): a step
   !> that needs more ends the spectrum with an error instead of stalling.
   integer, parameter :: max_level = 24
   !> A monodromy's (`upper`) exponential is cut into at most 2^lost_level
   !> parts: a direction that still shrinks past e^-part_spread of the largest
   !> within one of them (faster than e^(-18 · 1024) over one exponential, the
   !> GMS elements held at their limits) is lost, its multiplier 0 exactly.
   integer, parameter :: lost_level = 10
   !> The Gauss points of a step at 1/2 ∓ gauss_offset of it.
   real(wp), parameter :: gauss_offset = sqrt(3.0_wp) / 6.0_wp
   !> The log of a lost direction's R factor.
   real(wp), parameter :: lost_log = -huge(1.0_wp)

   !> Padé (6, 6) of exp(X) is exact to 2e-17 for ||X||_1 <= 1/2 (the
   !> remainder (6!)² / (12! 13!) ||X||^13); larger X is scaled into it.
   real(wp), parameter :: pade_norm = 0.5_wp
   real(wp), parameter :: pade(0:6) = [1.0_wp, 1.0_wp / 2.0_wp, 5.0_wp / 44.0_wp, 1.0_wp / 66.0_wp, &
      & 1.0_wp / 792.0_wp, 1.0_wp / 15840.0_wp, 1.0_wp / 665280.0_wp]

contains

   !> One accepted step of `orbit` from (t, z) towards t_target, its start
   !> kept in t_a and y_a (z's first size(y_a) values) and counted in `steps`:
   !> an error when the interval has taken more than max_steps steps (a step
   !> without progress is the solver's).  For the scenes' spectrum loops
   !> (machine/lyapunov.f90, brake/diagnostics.f90).
   subroutine orbit_step(orbit, method, max_steps, t, t_target, z, t_a, y_a, steps, error)
      type(ode_solver), intent(inout) :: orbit
      character(len=*), intent(in) :: method
      integer(i8), intent(in) :: max_steps
      real(wp), intent(inout) :: t
      real(wp), intent(in) :: t_target
      real(wp), intent(inout) :: z(:)
      real(wp), intent(out) :: t_a
      real(wp), intent(out) :: y_a(:)
      integer(i8), intent(inout) :: steps
      type(error_type), allocatable, intent(out) :: error

      t_a = t
      y_a = z(1:size(y_a))
      call orbit%step(t, t_target, z, error)
      if (allocated(error)) return
      steps = steps + 1
      if (steps > max_steps) then
         call fatal_error(error, trim(method)//': more than max_steps steps in one ' &
            & //'renormalisation interval at '//orbit%time_at(t), error_numerical)
      end if
   end subroutine orbit_step

   !> Φ over the step orbit_step just took, from (t_a, y_a) with the field
   !> f_a to (t, y): the field there into f_a for the next step, an error
   !> naming the step where magnus_tangent_step cannot go on.
   subroutine tangent_over_step(system, orbit, t_a, y_a, f_a, t, y, phi, logs, depth, error, closed)
      class(ode_system), intent(in) :: system
      type(ode_solver), intent(in) :: orbit
      real(wp), intent(in) :: t_a, t
      real(wp), intent(in) :: y_a(:), y(:)
      real(wp), intent(inout) :: f_a(:)
      real(wp), intent(inout) :: phi(:, :)
      real(wp), intent(inout) :: logs(:)
      integer, intent(inout) :: depth
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: closed   !! closed_tangent_step's, the last column closed by the trace
      real(wp) :: f_b(size(y)), y_1(size(y)), y_2(size(y)), h
      logical :: ok, by_trace

      call system%rhs(t, y, f_b)
      by_trace = .false.
      if (present(closed)) by_trace = closed
      if (by_trace) then
         h = t - t_a
         call step_state(orbit, 0.5_wp - gauss_offset, t_a, h, y_a, f_a, y, f_b, y_1)
         call step_state(orbit, 0.5_wp + gauss_offset, t_a, h, y_a, f_a, y, f_b, y_2)
         call closed_tangent_step(system, t_a, y_1, y_2, t, phi, logs, depth, ok)
      else
         call magnus_tangent_step(system, t_a, y_a, f_a, t, y, f_b, phi, logs, depth, ok)
      end if
      if (.not. ok) then
         call fatal_error(error, 'Lyapunov spectrum: the Jacobian is NaN or Inf, or too stiff for ' &
            & //'the step ending at '//orbit%time_at(t)//' (an exponential of the tangent in more ' &
            & //'than 2^24 parts)', error_numerical)
         return
      end if
      f_a = f_b
   end subroutine tangent_over_step

   !> The state at t_a + θh within the orbit's last step: its stepper's
   !> continuous extension where it has one (rodas4's, of order 3), else the
   !> cubic Hermite interpolant of the step's ends.  (A creeping slip rate's
   !> field is the difference of two nearly equal forces, its rounding far
   !> above the rate itself: the Hermite interpolant, which takes the field
   !> at the ends, puts the rate off by orders of magnitude within the step;
   !> the stepper's stages are solved through the Jacobian and do not.)
   subroutine step_state(orbit, theta, t_a, h, y_a, f_a, y_b, f_b, y)
      type(ode_solver), intent(in) :: orbit
      real(wp), intent(in) :: theta, t_a, h, y_a(:), f_a(:), y_b(:), f_b(:)
      real(wp), intent(out) :: y(:)
      type(error_type), allocatable :: error

      if (orbit%has_dense_output()) then
         call orbit%dense_output(t_a + theta * h, y, error)
         if (.not. allocated(error)) return
      end if
      call hermite(theta, h, y_a, f_a, y_b, f_b, y)
   end subroutine step_state

   !> Φ over the step from t_a to t_b with the last column closed by the
   !> trace (apply_exponential, closed), the Jacobians A_i at the Gauss points from
   !> the states y_1, y_2 there: Φ ← exp(h A2 / 2) exp(h A1 / 2) Φ, second
   !> order in the commutator [A1, A2] (the fourth-order method's weights
   !> include a negative one, -0.039: where a creeping slip rate's stiffness,
   !> which goes with its inverse, changes by more than 14 times within a
   !> step, its exponential grows that direction at 1e9 per τ), each factor
   !> contracting wherever J does, and the trace's sum h (tr A1 + tr A2)/2
   !> still the Gauss rule's, of fourth order.
   pure subroutine closed_tangent_step(system, t_a, y_1, y_2, t_b, phi, logs, depth, ok)
      class(ode_system), intent(in) :: system
      real(wp), intent(in) :: t_a, t_b, y_1(:), y_2(:)
      real(wp), intent(inout) :: phi(:, :), logs(:)
      integer, intent(inout) :: depth
      logical, intent(out) :: ok
      real(wp) :: a1(size(y_1), size(y_1)), a2(size(y_1), size(y_1)), dfdt(size(y_1)), h

      h = t_b - t_a
      call system%jacobian(t_a + (0.5_wp - gauss_offset) * h, y_1, a1, dfdt)
      call system%jacobian(t_a + (0.5_wp + gauss_offset) * h, y_2, a2, dfdt)
      call apply_exponential(0.5_wp * h * a1, phi, logs, depth, ok, closed=.true.)
      if (.not. ok) return
      call apply_exponential(0.5_wp * h * a2, phi, logs, depth, ok, closed=.true.)
   end subroutine closed_tangent_step

   !> Φ (orthonormal) over the accepted step from (t_a, y_a), with the field
   !> f_a there, to (t_b, y_b) with f_b: Φ orthonormal again, the logs of the
   !> step's R factors added to logs(:).  `ok` false (Φ and logs undefined):
   !> the Jacobian was NaN or Inf, h J beyond 2^max_parts in norm, or an
   !> exponential needing more than 2^max_level parts.
   !> `depth`: the parts' level j to try first (0 at the start), kept from
   !> step to step: the stiffness met changes slowly.
   !> `upper` (a monodromy matrix, not a spectrum): the whole product R of the
   !> R factors is kept, R = diag(exp(logs)) upper, `upper` unit upper
   !> triangular (rows scaled by R's diagonal: bounded while the columns keep
   !> the order of their growth, as they do from a generic frame), so that
   !> Φ(t) Φ(t_0)⁻¹ = Q R Φ(t_0)ᵀ with its smallest parts resolved.
   pure subroutine magnus_tangent_step(system, t_a, y_a, f_a, t_b, y_b, f_b, phi, logs, depth, ok, upper)
      class(ode_system), intent(in) :: system
      real(wp), intent(in) :: t_a, t_b
      real(wp), intent(in) :: y_a(:), f_a(:), y_b(:), f_b(:)
      real(wp), intent(inout) :: phi(:, :)
      real(wp), intent(inout) :: logs(:)
      integer, intent(inout) :: depth
      logical, intent(out) :: ok
      real(wp), intent(inout), optional :: upper(:, :)
      real(wp), parameter :: offset = sqrt(3.0_wp) / 6.0_wp
      real(wp), parameter :: alpha = 0.25_wp + offset, beta = 0.25_wp - offset
      real(wp) :: a1(size(y_a), size(y_a)), a2(size(y_a), size(y_a)), y(size(y_a)), dfdt(size(y_a)), h

      h = t_b - t_a
      call hermite(0.5_wp - offset, h, y_a, f_a, y_b, f_b, y)
      call system%jacobian(t_a + (0.5_wp - offset) * h, y, a1, dfdt)
      call hermite(0.5_wp + offset, h, y_a, f_a, y_b, f_b, y)
      call system%jacobian(t_a + (0.5_wp + offset) * h, y, a2, dfdt)
      call apply_exponential(h * (alpha * a1 + beta * a2), phi, logs, depth, ok, upper)
      if (.not. ok) return
      call apply_exponential(h * (beta * a1 + alpha * a2), phi, logs, depth, ok, upper)
   end subroutine magnus_tangent_step

   !> Φ ← exp(X) Φ in parts exp(X / 2^j), Φ = Q R after each (Φ ← Q, logs +=
   !> log R_ii).  A part is taken whole when R's diagonal spans at most
   !> e^part_spread, else as two parts of half the size (at ||X / 2^j||_1 <= 1/2
   !> it spans at most e).  The first parts are tried at level `depth`, which
   !> becomes the finest level taken, or one coarser when every part spanned
   !> less than e^(part_spread / 2).  `closed`: the last column is closed by
   !> the trace, the parts judged by the other columns' span alone, the last
   !> column's log tr X less the others' logs, its direction their complement.
   pure subroutine apply_exponential(x, phi, logs, depth, ok, upper, closed)
      real(wp), intent(in) :: x(:, :)
      real(wp), intent(inout) :: phi(:, :)
      real(wp), intent(inout) :: logs(:)
      integer, intent(inout) :: depth
      logical, intent(out) :: ok
      real(wp), intent(inout), optional :: upper(:, :)
      logical, intent(in), optional :: closed
      real(wp), allocatable :: levels(:, :, :)
      real(wp) :: norm, product(size(logs)), widest, before(size(logs)), trace
      integer :: scaling, j, first, k, finest, n
      logical :: closing

      closing = .false.
      if (present(closed)) closing = closed
      n = size(x, 1)
      norm = maxval(sum(abs(x), dim=1))
      ok = all(abs(x) <= huge(x)) .and. norm <= pade_norm * 2.0_wp**merge(max_closed_scaling, max_parts, closing)
      if (.not. ok) return
      scaling = 0
      if (norm > pade_norm) scaling = ceiling(log(norm / pade_norm) / log(2.0_wp))
      ! levels(:, :, j) = exp(X / 2^j), from the Padé at the finest level up by squaring.
      allocate (levels(n, n, 0:scaling))
      levels(:, :, scaling) = pade_exponential(x / 2.0_wp**scaling)
      do j = scaling - 1, 0, -1
         levels(:, :, j) = matmul(levels(:, :, j + 1), levels(:, :, j + 1))
      end do
      trace = 0.0_wp
      do j = 1, n
         trace = trace + x(j, j)
      end do
      before = logs
      first = min(max(depth, 0), scaling)
      finest = first
      widest = 1.0_wp
      product = 1.0_wp
      do k = 1, 2**first
         call apply_part(levels, first, scaling, closing, phi, logs, product, finest, widest, upper)
         ok = finest <= max_level
         if (.not. ok) return
      end do
      logs = logs + log(product)
      if (closing) logs(n) = before(n) + trace - sum(logs(1:n - 1) - before(1:n - 1))
      depth = finest
      if (finest == first .and. widest <= exp(0.5_wp * part_spread)) depth = max(first - 1, 0)
   end subroutine apply_exponential

   !> exp(X / 2^level) applied to Φ, whole or as two halves (recursively).
   !> R's diagonals are multiplied into `product` (logs are dear: one a part
   !> would be a third of the part's cost), which goes into logs before it
   !> leaves [1e-100, 1e100]; `finest` and `widest` record the finest level
   !> taken and the largest span of R's diagonal (finest > max_level: a part
   !> beyond max_level was needed, and nothing more is done).  `closed`: a
   !> part is judged by the first n - 1 entries of R's diagonal; the last
   !> column becomes the others' complement, its R left out (1).
   pure recursive subroutine apply_part(levels, level, last, closed, phi, logs, product, finest, widest, upper)
      real(wp), intent(in) :: levels(:, :, 0:)
      integer, intent(in) :: level, last
      logical, intent(in) :: closed
      real(wp), intent(inout) :: phi(:, :)
      real(wp), intent(inout) :: logs(:), product(:), widest
      integer, intent(inout) :: finest
      real(wp), intent(inout), optional :: upper(:, :)
      real(wp) :: trial(size(phi, 1), size(phi, 2)), r(size(phi, 2))
      integer :: n, m, i, j, k
      logical :: fits

      if (finest > max_level) return
      n = size(phi, 1)
      do j = 1, n
         do i = 1, n
            trial(i, j) = 0.0_wp
         end do
         do k = 1, n
            do i = 1, n
               trial(i, j) = trial(i, j) + levels(i, k, level) * phi(k, j)
            end do
         end do
      end do
      if (present(upper)) then
         call monodromy_part(levels, level, last, phi, logs, finest, widest, upper, trial)
         return
      end if
      call factor(trial, r)
      m = merge(n - 1, n, closed)
      ! (A part that underflowed or overflowed a column is never taken whole.)
      fits = all(r(1:m) > 0.0_wp .and. r(1:m) <= huge(r))
      if (fits .and. m > 0) fits = minval(r(1:m)) >= exp(-part_spread) * maxval(r(1:m))
      if (level == last .or. fits) then
         if (closed) call complete(trial, n)
         phi = trial
         finest = max(finest, level)
         if (.not. closed .or. (m > 0 .and. fits)) widest = max(widest, maxval(r(1:m)) / minval(r(1:m)))
         if (closed) r(n) = 1.0_wp
         if (any(product < 1.0e-100_wp .or. product > 1.0e100_wp .or. r < 1.0e-100_wp .or. r > 1.0e100_wp)) then
            logs = logs + log(product) + log(r)
            product = 1.0_wp
         else
            product = product * r
         end if
      else if (level == max_level) then
         finest = max_level + 1
      else
         call apply_part(levels, level + 1, last, closed, phi, logs, product, finest, widest, upper)
         call apply_part(levels, level + 1, last, closed, phi, logs, product, finest, widest, upper)
      end if
   end subroutine apply_part

   !> apply_part's for a monodromy matrix: `trial` = the part applied to Φ,
   !> factored with all of R kept in `upper` and `logs`; the lost directions
   !> (logs at lost_log) left out of the span the part is judged by.
   pure recursive subroutine monodromy_part(levels, level, last, phi, logs, finest, widest, upper, applied)
      real(wp), intent(in) :: levels(:, :, 0:), applied(:, :)
      integer, intent(in) :: level, last
      real(wp), intent(inout) :: phi(:, :), logs(:), widest, upper(:, :)
      integer, intent(inout) :: finest
      real(wp) :: r(size(phi, 2)), whole(size(phi, 2), size(phi, 2)), top, trial(size(phi, 1), size(phi, 2))
      logical :: kept(size(phi, 2)), fits

      trial = applied
      call factor(trial, r, whole)
      kept = logs > lost_log
      top = maxval(r, mask=kept)
      fits = all(.not. kept .or. (r > 0.0_wp .and. r <= huge(r))) .and. top <= huge(r)
      if (fits) fits = minval(r, mask=kept) >= exp(-part_spread) * top
      if (level == last .or. level >= lost_level .or. fits) then
         phi = trial
         finest = max(finest, level)
         if (fits) widest = max(widest, top / minval(r, mask=kept))
         call accumulate(whole, r, logs, upper, kept .and. .not. (r >= exp(-part_spread) * top))
      else
         call monodromy_part(levels, level + 1, last, phi, logs, finest, widest, upper, &
            & matmul(levels(:, :, level + 1), phi))
         call monodromy_part(levels, level + 1, last, phi, logs, finest, widest, upper, &
            & matmul(levels(:, :, level + 1), phi))
      end if
   end subroutine monodromy_part

   !> Φ = Q R by modified Gram–Schmidt with one reorthogonalisation, as
   !> analysis/lyapunov_spectrum.f90's orthonormalise without its lost
   !> directions (Φ is regular here), in loops: it is the parts' inner loop.
   pure subroutine factor(phi, r, whole)
      real(wp), intent(inout) :: phi(:, :)
      real(wp), intent(out) :: r(:)
      real(wp), intent(out), optional :: whole(:, :)   !! all of R (the monodromy's)
      real(wp) :: d
      integer :: n, i, k, pass, l

      n = size(phi, 1)
      if (present(whole)) whole = 0.0_wp
      do k = 1, n
         do pass = 1, 2
            do i = 1, k - 1
               d = 0.0_wp
               do l = 1, n
                  d = d + phi(l, i) * phi(l, k)
               end do
               do l = 1, n
                  phi(l, k) = phi(l, k) - d * phi(l, i)
               end do
               if (present(whole)) whole(i, k) = whole(i, k) + d
            end do
         end do
         d = 0.0_wp
         do l = 1, n
            d = d + phi(l, k)**2
         end do
         r(k) = sqrt(d)
         if (r(k) > 0.0_wp) phi(:, k) = phi(:, k) / r(k)
         if (present(whole)) then
            whole(k, k) = r(k)
            ! A column shrunk to nothing (a lost direction): the basis completed by a unit vector instead.
            if (.not. (r(k) >= tiny(1.0_wp))) call complete(phi, k)
         end if
      end do
   end subroutine factor

   !> Column k of Φ: the unit vector orthogonal to columns 1 to k - 1 with
   !> the largest residual among the axes, orthogonalised twice.
   pure subroutine complete(phi, k)
      real(wp), intent(inout) :: phi(:, :)
      integer, intent(in) :: k
      real(wp) :: v(size(phi, 1)), best(size(phi, 1)), d
      integer :: axis, i, pass

      best = 0.0_wp
      do axis = 1, size(phi, 1)
         v = 0.0_wp
         v(axis) = 1.0_wp
         do pass = 1, 2
            do i = 1, k - 1
               d = dot_product(phi(:, i), v)
               v = v - d * phi(:, i)
            end do
         end do
         if (norm2(v) > norm2(best)) best = v
      end do
      phi(:, k) = best / norm2(best)
   end subroutine complete

   !> R ← R_part R with R = diag(exp(logs)) U: U ← (diag(exp(-logs)) V
   !> diag(exp(logs))) U, V = diag(r)⁻¹ R_part, then logs += log r.  (A column
   !> growing past an earlier one by e^700 is capped there: U would overflow.)
   pure subroutine accumulate(whole, r, logs, upper, lost)
      real(wp), intent(in) :: whole(:, :), r(:)
      real(wp), intent(inout) :: logs(:), upper(:, :)
      logical, intent(in) :: lost(:)   !! directions lost in this part
      real(wp) :: w(size(r), size(r))
      integer :: n, i, j

      n = size(r)
      w = 0.0_wp
      do j = 1, n
         w(j, j) = 1.0_wp
         do i = 1, j - 1
            ! (A lost row's R is rounding: it stays e_i.)
            if (logs(i) > lost_log .and. .not. lost(i)) &
               & w(i, j) = whole(i, j) / r(i) * exp(min(logs(j) - logs(i), 700.0_wp))
         end do
      end do
      upper = matmul(w, upper)
      do i = 1, n
         if (lost(i)) then
            logs(i) = lost_log
            upper(i, :) = 0.0_wp
            upper(i, i) = 1.0_wp
         else if (logs(i) > lost_log) then
            logs(i) = logs(i) + log(r(i))
         end if
      end do
   end subroutine accumulate

   !> D(X)^-1 N(X), N and D the Padé (6, 6) polynomials of exp (||X||_1 <= 1/2:
   !> D is then within 0.3 of I and needs no pivoting to speak of).
   pure function pade_exponential(x) result(e)
      real(wp), intent(in) :: x(:, :)
      real(wp) :: e(size(x, 1), size(x, 2))
      real(wp) :: power(size(x, 1), size(x, 2)), num(size(x, 1), size(x, 2)), den(size(x, 1), size(x, 2))
      integer :: n, i, k

      n = size(x, 1)
      num = 0.0_wp
      den = 0.0_wp
      do i = 1, n
         num(i, i) = 1.0_wp
         den(i, i) = 1.0_wp
      end do
      power = num
      do k = 1, 6
         power = matmul(power, x)
         num = num + pade(k) * power
         den = den + (-1.0_wp)**k * pade(k) * power
      end do
      e = solve(den, num)
   end function pade_exponential

   !> A^-1 B by Gaussian elimination with partial pivoting (A small, regular).
   pure function solve(a, b) result(x)
      real(wp), intent(in) :: a(:, :), b(:, :)
      real(wp) :: x(size(b, 1), size(b, 2))
      real(wp) :: lu(size(a, 1), size(a, 2)), row(size(b, 2)), lrow(size(a, 2)), factor
      integer :: n, i, k, p

      n = size(a, 1)
      lu = a
      x = b
      do k = 1, n
         p = k - 1 + maxloc(abs(lu(k:n, k)), dim=1)
         if (p /= k) then
            lrow = lu(k, :)
            lu(k, :) = lu(p, :)
            lu(p, :) = lrow
            row = x(k, :)
            x(k, :) = x(p, :)
            x(p, :) = row
         end if
         do i = k + 1, n
            factor = lu(i, k) / lu(k, k)
            lu(i, k + 1:n) = lu(i, k + 1:n) - factor * lu(k, k + 1:n)
            x(i, :) = x(i, :) - factor * x(k, :)
         end do
      end do
      do k = n, 1, -1
         x(k, :) = (x(k, :) - matmul(lu(k, k + 1:n), x(k + 1:n, :))) / lu(k, k)
      end do
   end function solve

   !> tr J(t, y) of `system`.
   pure real(wp) function jacobian_trace(system, t, y) result(trace)
      class(ode_system), intent(in) :: system
      real(wp), intent(in) :: t, y(:)
      real(wp) :: jac(size(y), size(y)), dfdt(size(y))
      integer :: i

      call system%jacobian(t, y, jac, dfdt)
      trace = 0.0_wp
      do i = 1, size(y)
         trace = trace + jac(i, i)
      end do
   end function jacobian_trace

   !> ∫ tr J dt over the accepted step from (t_a, y_a) with the field f_a to
   !> (t_b, y_b) with f_b by Simpson's rule: tr J at the step's ends (trace_a
   !> given, trace_b returned for the next step) and at the midpoint of the
   !> step's cubic Hermite interpolant.  The flow's divergence apart from the
   !> exponentials' Gauss points, which the exponents' sum is the quadrature
   !> on: the sum rule's check (docs/chaos.md, the brake with a law).
   !> `middle`: the state at the midpoint given (step_state's), in place of
   !> the interpolant's.
   pure subroutine simpson_trace(system, t_a, y_a, f_a, t_b, y_b, f_b, trace_a, trace_b, integral, middle)
      class(ode_system), intent(in) :: system
      real(wp), intent(in) :: t_a, t_b, trace_a
      real(wp), intent(in) :: y_a(:), f_a(:), y_b(:), f_b(:)
      real(wp), intent(out) :: trace_b, integral
      real(wp), intent(in), optional :: middle(:)
      real(wp) :: y(size(y_a)), h

      h = t_b - t_a
      if (present(middle)) then
         y = middle
      else
         call hermite(0.5_wp, h, y_a, f_a, y_b, f_b, y)
      end if
      trace_b = jacobian_trace(system, t_b, y_b)
      integral = h / 6.0_wp * (trace_a + 4.0_wp * jacobian_trace(system, t_a + 0.5_wp * h, y) + trace_b)
   end subroutine simpson_trace

   !> The cubic Hermite interpolant of the step at θ = (t - t_a)/h.
   pure subroutine hermite(theta, h, y_a, f_a, y_b, f_b, y)
      real(wp), intent(in) :: theta, h, y_a(:), f_a(:), y_b(:), f_b(:)
      real(wp), intent(out) :: y(:)
      real(wp) :: s

      s = 1.0_wp - theta
      y = s * s * (1.0_wp + 2.0_wp * theta) * y_a + theta * theta * (3.0_wp - 2.0_wp * theta) * y_b &
         & + h * theta * s * (s * f_a - theta * f_b)
   end subroutine hermite

end module friction_analysis_tangent_magnus
