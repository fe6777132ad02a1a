!> The return map of a smooth (stiff) flow with its Jacobian carried by
!> exponentials (docs/chaos.md, "Orbits and continuation of the machine"):
!> the orbit alone is stepped by the solver (the section y_k = c crossed
!> upwards located by the event locator, or a stroboscopic period), and the
!> tangent over each accepted step by analysis/tangent_magnus.f90's
!> commutator-free Magnus method, factored within the step.  The variational
!> equations then never ride on the stiff stepper, and the whole product of
!> the R factors is kept, R = diag(exp(L)) U: the monodromy matrix
!> M = Q R Gᵀ (G the generic starting frame) with its smallest parts in L.
!>
!> Newton gets DP in doubles (the parts below the smallest double are 0
!> there, as they are in any DP); `log_multipliers` gives the multipliers
!> of the last evaluation as complex logs, ln|μ| + i arg μ, resolved however
!> small: the eigenvalues of the graded matrix D B, D = diag(exp(L)),
!> B = U Gᵀ Q (similar to M), cluster by cluster where L falls by more than
!> e^36 from one to the next (the rest's Schur complement then moves the
!> eigenvalues by e^-36 of themselves at most), each cluster scaled into
!> doubles for LAPACK.
module friction_analysis_magnus_section
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_negative_inf, ieee_is_finite
   use friction_kinds, only: wp, i8
   use friction_error, only: error_type, fatal_error, error_numerical
   use friction_strings, only: rtoa
   use friction_ode_system, only: ode_system
   use friction_ode_solver, only: solver_settings, ode_solver
   use friction_ode_events, only: event_system, event_locator, event_rising, event_falling, event_either
   use friction_ode_forwarding, only: forwarding_system
   use friction_ode_watch, only: step_watch
   use friction_analysis_lyapunov_spectrum, only: generic_frame
   use friction_analysis_tangent_magnus, only: magnus_tangent_step
   use friction_analysis_periodic_orbit, only: section_map, general_eigenvalues
   implicit none
   private

   public :: magnus_map

   !> Consecutive log-moduli further apart than this split the clusters (e^-36 < ε/2).
   real(wp), parameter :: cluster_gap = 36.0_wp

   !> The flow with its section y_k = c as event 1 (none when forced) and,
   !> when the flow is an event system, its events after it: the kinks of its
   !> Jacobian, where a step of the tangent must end; the section's rearming
   !> level y_k = r the last, when it rearms.  The locator steps it with no
   !> relative component, as it always has (the base's, which the hyperplane
   !> map keeps, would change this map's steps: not measured here).
   type, extends(forwarding_system) :: plane_system
      integer :: coordinate = 1
      real(wp) :: level = 0.0_wp
      logical :: forced = .false.
      integer :: kinks = 0
      logical :: rearms = .false.
      real(wp) :: rearm_level = 0.0_wp
   contains
      procedure :: relative_component => plane_relative_component
      procedure :: event_count => plane_event_count
      procedure :: event_values => plane_event_values
   end type plane_system

   !> The section y_k = c crossed upwards of an autonomous flow (forced =
   !> .false.; its coordinates the other n - 1 components, as hyperplane_map)
   !> or the period map from t0 over `period` (forced; all n), with the
   !> factors of the last evaluation's monodromy matrix.
   type, extends(section_map) :: magnus_map
      type(plane_system), allocatable :: plane
      type(solver_settings) :: solver
      logical :: forced = .false.
      real(wp) :: t0 = 0.0_wp, period = 1.0_wp, max_return = 1000.0_wp, event_tolerance = 1.0e-12_wp
      class(step_watch), pointer :: watch => null()   !! asked between steps when associated
      !> The last evaluation: M = q diag(exp(logs)) upper frameᵀ, its return time.
      real(wp), allocatable :: q(:, :), logs(:), upper(:, :), frame(:, :)
      real(wp) :: last_period = 0.0_wp
      logical :: evaluated = .false.
      !> A start where the flow crosses y_k = c downwards (or not at all) is outside the map's domain and
      !> refused, unless entering: then its image is the flow's next upward crossing (a guess moved onto it).
      logical :: entering = .false.
      !> The section crossed downwards instead (y_k' < 0: every "upward" above reads "downward").
      logical :: falling = .false.
   contains
      procedure :: setup => magnus_setup
      procedure :: dimension => magnus_dimension
      procedure :: evaluate => magnus_evaluate
      procedure :: log_multipliers => magnus_log_multipliers
      procedure :: enter => magnus_enter
   end type magnus_map

contains

   pure subroutine plane_relative_component(self, index, reference, floor)
      class(plane_system), intent(in) :: self
      integer, intent(out) :: index
      real(wp), intent(out) :: reference, floor

      index = 0
      reference = 0.0_wp
      floor = 0.0_wp
   end subroutine plane_relative_component

   pure integer function plane_event_count(self)
      class(plane_system), intent(in) :: self

      plane_event_count = 1 + self%kinks + merge(1, 0, self%rearms)
   end function plane_event_count

   pure subroutine plane_event_values(self, t, y, g)
      class(plane_system), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: y(:)
      real(wp), intent(out) :: g(:)

      g(1) = 1.0_wp
      if (.not. self%forced) g(1) = y(self%coordinate) - self%level
      if (self%kinks > 0) then
         select type (base => self%base)
         class is (event_system)
            call base%event_values(t, y, g(2:1 + self%kinks))
         end select
      end if
      if (self%rearms) g(2 + self%kinks) = y(self%coordinate) - self%rearm_level
   end subroutine plane_event_values

   !> The map of `system`: forced, from t0 over `period`; else the section
   !> y_coordinate = level crossed upwards, returns after max_return none.
   !> A system with events has them located as kinks of its Jacobian: each
   !> ends a step of the orbit, so that no exponential of the tangent reads J
   !> across one (docs/chaos.md, "The tangent of a stiff law").  With
   !> `falling`, the section crossed downwards; with rearm_level, a crossing
   !> counts only after y_k has crossed that level the other way since the
   !> start or the last crossing (a flow grazing the section does not return
   !> there), as hyperplane_map's.
   subroutine magnus_setup(self, system, solver, forced, t0, period, coordinate, level, max_return, event_tolerance, &
      & falling, rearm_level)
      class(magnus_map), intent(inout) :: self
      class(ode_system), intent(in) :: system
      type(solver_settings), intent(in) :: solver
      logical, intent(in) :: forced
      real(wp), intent(in) :: t0, period, level, max_return, event_tolerance
      integer, intent(in) :: coordinate
      logical, intent(in), optional :: falling
      real(wp), intent(in), optional :: rearm_level

      if (allocated(self%plane)) deallocate (self%plane)
      allocate (self%plane)
      allocate (self%plane%base, source=system)
      self%plane%coordinate = coordinate
      self%plane%level = level
      self%plane%forced = forced
      self%plane%kinks = 0
      select type (system)
      class is (event_system)
         self%plane%kinks = system%event_count()
      end select
      self%falling = .false.
      if (present(falling)) self%falling = falling
      self%plane%rearms = present(rearm_level)
      if (present(rearm_level)) self%plane%rearm_level = rearm_level
      self%solver = solver
      self%forced = forced
      self%t0 = t0
      self%period = period
      self%max_return = max_return
      self%event_tolerance = event_tolerance
      self%evaluated = .false.
   end subroutine magnus_setup

   pure integer function magnus_dimension(self)
      class(magnus_map), intent(in) :: self

      magnus_dimension = self%plane%base%dimension() - merge(0, 1, self%forced)
   end function magnus_dimension

   !> From s with the generic frame G to the return: the orbit step by step,
   !> Φ over each step by exponentials, DP from M = Φ(T) Gᵀ (projected along
   !> the flow onto the section when autonomous, as hyperplane_map).
   subroutine magnus_evaluate(self, s, image, jacobian, period, returned, reason, error)
      class(magnus_map), intent(inout) :: self
      real(wp), intent(in) :: s(:)
      real(wp), intent(out) :: image(:), jacobian(:, :), period
      logical, intent(out) :: returned
      character(len=:), allocatable, intent(out) :: reason
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: y(:), y_a(:), f_a(:), f_b(:), monodromy(:, :), row(:)
      real(wp) :: t, t_a, t_end, h
      integer :: n, i, k, depth
      integer(i8) :: steps
      integer, allocatable :: others(:)
      logical :: ok, done

      n = self%plane%base%dimension()
      k = self%plane%coordinate
      image = s
      jacobian = 0.0_wp
      period = 0.0_wp
      returned = .false.
      reason = ''
      self%evaluated = .false.
      others = pack([(i, i=1, n)], [(i, i=1, n)] /= k)
      if (self%forced) then
         y = s
      else
         allocate (y(n))
         y(others) = s
         y(k) = self%plane%level
      end if
      allocate (y_a(n), f_a(n), f_b(n))
      self%frame = generic_frame(n)
      self%q = self%frame
      self%logs = spread(0.0_wp, 1, n)
      self%upper = identity(n)
      depth = 0
      steps = 0
      t = self%t0
      call self%plane%rhs(t, y, f_a)
      h = self%solver%h_start
      if (self%forced) then
         if (.not. (h > 0.0_wp)) h = 1.0e-6_wp * self%period
         t_end = self%t0 + self%period
         if (self%plane%kinks > 0) then
            call returning(done, error)
         else
            call periodic(error)
         end if
         if (allocated(error)) return
      else
         ! Off the upward side the next upward crossing is a short loop near the section's fold (where the flow
         ! is tangent to it), not a return round the orbit: Newton would converge on the fold.
         if (.not. (merge(-f_a(k), f_a(k), self%falling) > 0.0_wp) .and. .not. self%entering) then
            reason = 'the flow crosses the section '//trim(merge('upwards  ', 'downwards', self%falling)) &
               & //' at this point (outside the section''s '//trim(merge('downward', 'upward  ', self%falling)) &
               & //' side)'
            return
         end if
         if (.not. (h > 0.0_wp)) h = 1.0e-3_wp
         t_end = self%t0 + self%max_return
         call returning(done, error)
         if (allocated(error)) return
         if (.not. done) then
            reason = 'no return to the section within the longest return time'
            return
         end if
      end if
      monodromy = monodromy_double(self)
      if (.not. all(ieee_is_finite(monodromy))) then
         ! A Jacobian past the largest double leaves Newton nothing to solve with; say why at once.
         reason = 'the section map''s Jacobian overflows (a direction grows by e^'//rtoa(maxval(self%logs)) &
            & //' over the return: the tangent through a switch of the law sharper than the orbit''s steps)'
         return
      end if
      if (self%forced) then
         image = y
         jacobian = monodromy
         period = self%period
      else
         call self%plane%rhs(t, y, f_b)
         ! Row k as it was before the loop zeroes it: the rows after k need it too.
         row = monodromy(k, :)
         do i = 1, n
            monodromy(i, :) = monodromy(i, :) - f_b(i) * row / f_b(k)
         end do
         image = y(others)
         jacobian = monodromy(others, others)
         period = t - self%t0
      end if
      self%last_period = period
      self%evaluated = .true.
      returned = .true.

   contains

      !> Φ over the accepted step from (t_a, y_a) to (t, y), f_a to the end's field.
      subroutine carry(error)
         type(error_type), allocatable, intent(out) :: error

         call self%plane%rhs(t, y, f_b)
         if (t > t_a) then
            call magnus_tangent_step(self%plane%base, t_a, y_a, f_a, t, y, f_b, self%q, self%logs, depth, ok, &
               & self%upper)
            if (.not. ok) then
               call fatal_error(error, 'periodic orbit: the Jacobian is NaN or Inf, or too stiff for the step ' &
                  & //'of the section map ending near t = '//rtoa(t)//' s (an exponential of the ' &
                  & //'tangent in more than 2^24 parts)', error_numerical)
               return
            end if
         end if
         f_a = f_b
         steps = steps + 1
         if (associated(self%watch) .and. (mod(steps, 16_i8) == 0 .or. depth >= 12)) call self%watch%check(t, error)
      end subroutine carry

      subroutine periodic(error)
         type(error_type), allocatable, intent(out) :: error
         type(ode_solver) :: orbit

         call orbit%init(self%plane%base, self%solver, h, error)
         if (allocated(error)) return
         do while (t < t_end)
            t_a = t
            y_a = y
            call orbit%step(t, t_end, y, error)
            if (allocated(error)) exit
            if (self%solver%max_steps > 0 .and. steps >= self%solver%max_steps) then
               call fatal_error(error, trim(self%solver%method)//': more than max_steps steps in one period ' &
                  & //'of the section map at '//orbit%time_at(t), error_numerical)
               exit
            end if
            call carry(error)
            if (allocated(error)) exit
         end do
         call orbit%destroy()
      end subroutine periodic

      !> To the section's return (or, forced, to t_end), every kink a stop.
      subroutine returning(done, error)
         logical, intent(out) :: done
         type(error_type), allocatable, intent(out) :: error
         type(event_locator) :: locator
         logical :: armed

         done = .false.
         if (self%plane%rearms) then
            call locator%init(self%plane, self%solver, [merge(event_falling, event_rising, self%falling), &
               & spread(event_either, 1, self%plane%kinks), merge(event_rising, event_falling, self%falling)], &
               & [spread(.true., 1, 1 + self%plane%kinks), .false.], self%event_tolerance, h, error)
         else
            call locator%init(self%plane, self%solver, [merge(event_falling, event_rising, self%falling), &
               & spread(event_either, 1, self%plane%kinks)], spread(.true., 1, 1 + self%plane%kinks), &
               & self%event_tolerance, h, error)
         end if
         if (allocated(error)) return
         armed = .not. self%plane%rearms
         call locator%restart(t, y, h)
         do while (t < t_end)
            t_a = t
            y_a = y
            if (associated(self%watch)) then
               call locator%advance(t, t_end, y, error, self%watch, single=.true.)
            else
               call locator%advance(t, t_end, y, error, single=.true.)
            end if
            if (allocated(error)) return
            call carry(error)
            if (allocated(error)) return
            if (self%plane%rearms .and. locator%n_hits > 0) then
               if (any(locator%hits(1:locator%n_hits)%which == 2 + self%plane%kinks)) armed = .true.
            end if
            if (locator%n_hits > 0) then
               if (locator%hits(locator%n_hits)%terminal) then
                  ! A function exactly 0 at a restart crosses at once (ode/events.f90): that is the start itself.
                  ! A kink: on from its far side with a fresh step.  (A crossing before the rearming level:
                  ! the flow grazed the section.)
                  if (locator%hits(locator%n_hits)%which == 1 .and. &
                     & t - self%t0 > 1.0e3_wp * self%event_tolerance) then
                     done = armed
                     if (done) return
                     armed = .not. self%plane%rearms
                  end if
                  if (locator%hits(locator%n_hits)%which > 1) then
                     ! Past a kink with a step the size of the located time's error: a stepper that keeps its
                     ! long step there damps the fast growth of a band it enters (an L-stable method damps
                     ! h λ >> 1 either way) and sits on the band's edge, the tangent growing at every step.
                     call locator%restart(t, y, self%event_tolerance)
                  else
                     call locator%restart(t, y, 0.0_wp)
                  end if
               end if
            end if
         end do
         done = self%forced
      end subroutine returning

   end subroutine magnus_evaluate

   !> A guess s of the autonomous section moved onto its upward side: where
   !> the flow crosses there downwards, to the flow's next upward crossing;
   !> entered = .false. (with the reason) when it has none.
   subroutine magnus_enter(self, s, entered, reason, error)
      class(magnus_map), intent(inout) :: self
      real(wp), intent(inout) :: s(:)
      logical, intent(out) :: entered
      character(len=:), allocatable, intent(out) :: reason
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: image(size(s)), jacobian(size(s), size(s)), period, y(self%plane%base%dimension())
      real(wp) :: f(self%plane%base%dimension())
      integer :: i, k

      entered = .true.
      reason = ''
      if (self%forced) return
      k = self%plane%coordinate
      y(pack([(i, i=1, size(y))], [(i, i=1, size(y))] /= k)) = s
      y(k) = self%plane%level
      call self%plane%rhs(self%t0, y, f)
      if (merge(-f(k), f(k), self%falling) > 0.0_wp) return
      self%entering = .true.
      call self%evaluate(s, image, jacobian, period, entered, reason, error)
      self%entering = .false.
      if (entered .and. .not. allocated(error)) s = image
   end subroutine magnus_enter

   !> M = Q diag(exp(L)) U Gᵀ in doubles (what underflows is 0).
   function monodromy_double(self) result(m)
      class(magnus_map), intent(in) :: self
      real(wp) :: m(size(self%logs), size(self%logs))
      real(wp) :: r(size(self%logs), size(self%logs))
      integer :: i

      do i = 1, size(self%logs)
         r(i, :) = exp(self%logs(i)) * self%upper(i, :)
      end do
      m = matmul(self%q, matmul(r, transpose(self%frame)))
   end function monodromy_double

   !> The last evaluation's multipliers as ln|μ| + i arg μ, by decreasing
   !> modulus (a complex pair: positive argument first); autonomous, the
   !> trivial one along the flow (the closest to 1) left out.  NaN when
   !> LAPACK fails or a cluster's leading block is singular.
   function magnus_log_multipliers(self) result(logs)
      class(magnus_map), intent(in) :: self
      complex(wp), allocatable :: logs(:)
      real(wp), allocatable :: b(:, :), l(:), c(:, :), x(:, :)
      complex(wp), allocatable :: mu(:), all_logs(:)
      complex(wp) :: swap
      integer, allocatable :: order(:)
      integer :: n, i, j, first, last, trivial
      real(wp) :: nan
      logical :: solved

      n = size(self%logs)
      nan = ieee_value(1.0_wp, ieee_quiet_nan)
      ! B = U Gᵀ Q: M = Q (D B) Qᵀ.  Permuted so that L decreases (a similarity of D B).
      b = matmul(self%upper, matmul(transpose(self%frame), self%q))
      order = sort_decreasing(self%logs)
      l = self%logs(order)
      b = b(order, order)
      allocate (all_logs(0))
      first = 1
      do while (first <= n)
         last = first
         do while (last < n)
            if (l(last) - l(last + 1) > cluster_gap) exit
            last = last + 1
         end do
         if (l(first) <= -huge(1.0_wp)) then
            ! Lost directions (shrunk beyond e^(-18 · 1024) within one exponential): multipliers 0 exactly.
            all_logs = [all_logs, spread(cmplx(ieee_value(1.0_wp, ieee_negative_inf), 0.0_wp, wp), 1, n - first + 1)]
            exit
         end if
         allocate (c(last - first + 1, last - first + 1))
         do i = first, last
            c(i - first + 1, :) = exp(l(i) - l(first)) * b(i, first:last)
         end do
         mu = general_eigenvalues(c)
         do i = 1, size(mu)
            if (abs(mu(i)) > 0.0_wp) then
               all_logs = [all_logs, cmplx(log(abs(mu(i))) + l(first), atan2(aimag(mu(i)), real(mu(i))), wp)]
            else
               all_logs = [all_logs, cmplx(nan, nan, wp)]
            end if
         end do
         if (last < n) then
            ! The rest's Schur complement: B22 - B21 B11⁻¹ B12.
            call solve(b(first:last, first:last), b(first:last, last + 1:n), x, solved)
            if (.not. solved) then
               all_logs = [all_logs, spread(cmplx(nan, nan, wp), 1, n - last)]
               exit
            end if
            b(last + 1:n, last + 1:n) = b(last + 1:n, last + 1:n) - matmul(b(last + 1:n, first:last), x)
         end if
         deallocate (c)
         first = last + 1
      end do
      if (.not. self%forced) then
         trivial = minloc(abs(all_logs), dim=1)
         all_logs = [all_logs(1:trivial - 1), all_logs(trivial + 1:)]
      end if
      ! By decreasing modulus, a pair's positive argument first (insertion sort, stable).
      do i = 2, size(all_logs)
         swap = all_logs(i)
         j = i - 1
         do while (j >= 1)
            if (.not. (real(swap) > real(all_logs(j)) .or. (real(swap) == real(all_logs(j)) &
               & .and. aimag(swap) > aimag(all_logs(j))))) exit
            all_logs(j + 1) = all_logs(j)
            j = j - 1
         end do
         all_logs(j + 1) = swap
      end do
      logs = all_logs
   end function magnus_log_multipliers

   !> Indices of v by decreasing value (stable).
   pure function sort_decreasing(v) result(order)
      real(wp), intent(in) :: v(:)
      integer :: order(size(v))
      integer :: i, j, swap

      order = [(i, i=1, size(v))]
      do i = 2, size(v)
         swap = order(i)
         j = i - 1
         do while (j >= 1)
            if (.not. (v(swap) > v(order(j)))) exit
            order(j + 1) = order(j)
            j = j - 1
         end do
         order(j + 1) = swap
      end do
   end function sort_decreasing

   !> A⁻¹ B by Gaussian elimination with partial pivoting; solved = .false. for a singular A.
   pure subroutine solve(a_in, b_in, x, solved)
      real(wp), intent(in) :: a_in(:, :), b_in(:, :)
      real(wp), allocatable, intent(out) :: x(:, :)
      logical, intent(out) :: solved
      real(wp) :: a(size(a_in, 1), size(a_in, 2)), row(size(a_in, 2)), brow(size(b_in, 2)), factor
      integer :: n, i, k, p

      n = size(a_in, 1)
      a = a_in
      x = b_in
      solved = .false.
      do k = 1, n
         p = k - 1 + maxloc(abs(a(k:n, k)), dim=1)
         if (a(p, k) == 0.0_wp) return
         if (p /= k) then
            row = a(k, :)
            a(k, :) = a(p, :)
            a(p, :) = row
            brow = x(k, :)
            x(k, :) = x(p, :)
            x(p, :) = brow
         end if
         do i = k + 1, n
            factor = a(i, k) / a(k, k)
            a(i, k + 1:n) = a(i, k + 1:n) - factor * a(k, k + 1:n)
            x(i, :) = x(i, :) - factor * x(k, :)
         end do
      end do
      do k = n, 1, -1
         x(k, :) = (x(k, :) - matmul(a(k, k + 1:n), x(k + 1:n, :))) / a(k, k)
      end do
      solved = all(abs(x) <= huge(1.0_wp))
   end subroutine solve

   pure function identity(n) result(a)
      integer, intent(in) :: n
      real(wp) :: a(n, n)
      integer :: i

      a = 0.0_wp
      do i = 1, n
         a(i, i) = 1.0_wp
      end do
   end function identity

end module friction_analysis_magnus_section
