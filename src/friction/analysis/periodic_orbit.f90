!> Periodic orbits by Newton shooting on a Poincaré section (docs/physics.md,
!> periodic orbits and their stability).  A section map P takes a point s of
!> the section, in the section's own coordinates, to the next point where
!> the orbit through it comes back, with the return time T(s) and the
!> Jacobian DP(s) (the monodromy matrix over the return, saltation matrices
!> included for a nonsmooth flow, projected along the flow onto the
!> section).  A periodic orbit is a fixed point P(s) = s; Newton solves
!> (DP - I) δ = -(P(s) - s), halving δ while the residual does not drop.
!> The multipliers of the orbit are the eigenvalues of DP at the fixed
!> point, plus the trivial 1 along the flow (and 0 for each direction a
!> nonsmooth flow forgets, which the caller adds).
!>
!> Not finding an orbit (no return, no convergence within the iterations,
!> a step that cannot reduce the residual) is a result, `found = .false.`
!> with the reason, not an error: errors are failures of the integration.
!>
!> `hyperplane_map` is the section map of a smooth ode_system through the
!> hyperplane y_k = c crossed upwards, the section coordinates being the
!> other n - 1 components.
module friction_analysis_periodic_orbit
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_negative_inf, ieee_quiet_nan, ieee_is_nan
   use friction_kinds, only: wp
   use friction_error, only: error_type, fatal_error, error_input
   use friction_ode_system, only: ode_system
   use friction_ode_events, only: event_locator, event_rising, event_falling, event_either
   use friction_ode_forwarding, only: forwarding_system
   use friction_ode_solver, only: solver_settings, ode_solver
   use friction_ode_watch, only: step_watch
   use friction_analysis_lyapunov_spectrum, only: tangent_system, pack_tangent, unpack_tangent
   implicit none
   private

   public :: section_map, orbit_settings, periodic_orbit, find_periodic_orbit, section_multipliers
   public :: floquet_multipliers, floquet_exponents, hyperplane_map, stroboscopic_map, small_eigenvalues
   public :: bifurcation_period_doubling, bifurcation_fold, bifurcation_neimark_sacker, crossing_kind
   public :: halving_walk, branch_values, modulus_crossing, general_eigenvalues

   !> Largest section dimension whose multipliers have closed forms (the
   !> brake's section is 2-dimensional, a forced oscillator with one law
   !> state's stroboscopic section 3); larger ones go to LAPACK's dgeev.
   integer, parameter :: max_closed_form = 3

   interface
      !> LAPACK's eigenvalues (and optionally eigenvectors) of a real general matrix.
      subroutine dgeev(jobvl, jobvr, n, a, lda, wr, wi, vl, ldvl, vr, ldvr, work, lwork, info)
         import :: wp
         character(len=1), intent(in) :: jobvl, jobvr
         integer, intent(in) :: n, lda, ldvl, ldvr, lwork
         real(wp), intent(inout) :: a(lda, *)
         real(wp), intent(out) :: wr(*), wi(*), vl(ldvl, *), vr(ldvr, *), work(*)
         integer, intent(out) :: info
      end subroutine dgeev
   end interface

   !> Where a multiplier of a section map leaves (or enters) the unit circle.
   integer, parameter :: bifurcation_period_doubling = 1  !! a real multiplier through -1
   integer, parameter :: bifurcation_fold = 2             !! a real multiplier through +1
   integer, parameter :: bifurcation_neimark_sacker = 3   !! a complex pair through |μ| = 1

   !> A return map of a section, in section coordinates.
   type, abstract :: section_map
   contains
      !> The section's dimension.
      procedure(map_dimension_interface), deferred :: dimension
      !> image = P(s), jacobian = DP(s), period = T(s); returned = .false.
      !> (and `reason`) when no return was found.
      procedure(map_evaluate_interface), deferred :: evaluate
   end type section_map

   abstract interface
      pure integer function map_dimension_interface(self)
         import :: section_map
         class(section_map), intent(in) :: self
      end function map_dimension_interface

      subroutine map_evaluate_interface(self, s, image, jacobian, period, returned, reason, error)
         import :: section_map, wp, error_type
         class(section_map), intent(inout) :: self
         real(wp), intent(in) :: s(:)
         real(wp), intent(out) :: image(:), jacobian(:, :), period
         logical, intent(out) :: returned
         character(len=:), allocatable, intent(out) :: reason
         type(error_type), allocatable, intent(out) :: error
      end subroutine map_evaluate_interface
   end interface

   !> A walk in a continuation variable from `from` to `to`: the whole step
   !> first, halved (at most 5 times) while no orbit is found, the rest of
   !> the way from each value reached; done at the orbit at `to` or the
   !> sixth failure.  The caller tries `trial` and records whether it found
   !> an orbit there (a state, not a callback: no closure, no trampoline).
   type :: halving_walk
      real(wp) :: trial = 0.0_wp   !! the value to try next
      logical :: done = .false.
      real(wp), private :: from = 0.0_wp, to = 0.0_wp, at = 0.0_wp, step = 0.0_wp
      integer, private :: halvings = 0
   contains
      procedure :: start => walk_start
      procedure :: record => walk_record
   end type halving_walk

   type :: orbit_settings
      real(wp) :: tolerance = 1.0e-9_wp   !! max |P(s) - s| accepted, in the section's units
      integer :: max_iterations = 20      !! Newton steps
      integer :: max_halvings = 10        !! step halvings per Newton step
   end type orbit_settings

   type :: periodic_orbit
      logical :: found = .false.
      real(wp) :: period = 0.0_wp
      real(wp), allocatable :: point(:)          !! section coordinates of the fixed point (or the last iterate)
      real(wp), allocatable :: jacobian(:, :)    !! DP there
      complex(wp), allocatable :: multipliers(:) !! eigenvalues of DP, by decreasing modulus
      integer :: iterations = 0                  !! Newton steps taken
      real(wp) :: residual = huge(1.0_wp)        !! max |P(s) - s| at the last iterate
      character(len=:), allocatable :: reason    !! why not found ('' when found)
   end type periodic_orbit

   !> A smooth system with the hyperplane y_k = c as its event, the
   !> hyperplanes y_j = c_j where its field has a kink (events 2, 3, ...) and
   !> the section's rearming level (the last, when rearms).  Otherwise the
   !> base, its relative component included: a creeping slip rate's error is
   !> held relative to itself in the map as in the run (without it rodas4
   !> crawled through the rate-and-state creep in millions of steps, its
   !> stages carrying v_rel across 0 within an atol above it).
   type, extends(forwarding_system) :: hyperplane_system
      integer :: coordinate = 1
      real(wp) :: level = 0.0_wp
      integer, allocatable :: kink_coordinate(:)
      real(wp), allocatable :: kink_level(:)
      logical :: rearms = .false.
      real(wp) :: rearm_level = 0.0_wp
   contains
      procedure :: event_count => hyperplane_event_count
      procedure :: event_values => hyperplane_event_values
   end type hyperplane_system

   !> The return map of y_k = c crossed upwards (y_k' > 0) for a smooth system;
   !> returns later than max_return count as none.
   !> The period map of a system periodic in time with `period` (a forced
   !> oscillator), from t0 to t0 + period: P(s) = y(t0 + T), DP = Φ(t0 + T),
   !> the whole state being the section's coordinates.
   type, extends(section_map) :: stroboscopic_map
      type(tangent_system), allocatable :: extended
      type(solver_settings) :: solver
      real(wp) :: t0 = 0.0_wp
      real(wp) :: period = 1.0_wp
      class(step_watch), pointer :: watch => null()   !! asked between steps when associated
   contains
      procedure :: setup => stroboscopic_setup
      procedure :: dimension => stroboscopic_dimension
      procedure :: evaluate => stroboscopic_evaluate
   end type stroboscopic_map

   type, extends(section_map) :: hyperplane_map
      type(tangent_system), allocatable :: extended
      type(solver_settings) :: solver
      integer :: coordinate = 1
      real(wp) :: level = 0.0_wp
      real(wp) :: max_return = 1000.0_wp
      real(wp) :: event_tolerance = 1.0e-12_wp
      logical :: falling = .false.   !! the section crossed downwards (y_k' < 0) instead
      integer :: kinks = 0           !! kinks of the field located (events 2 to 1 + kinks)
      !> A crossing returns only after y_k has crossed rearm_level the other way
      !> (the last event): a flow grazing the section is no return.
      logical :: rearms = .false.
      real(wp) :: rearm_level = 0.0_wp
      !> The first step of an evaluation when solver%h_start is unset: the
      !> scene's rule, which its map may set before each evaluation (the
      !> brake's at the section point, brake/orbit.f90).
      real(wp) :: first_step = 1.0e-3_wp
      class(step_watch), pointer :: watch => null()   !! asked between steps when associated
   contains
      procedure :: setup => hyperplane_setup
      procedure :: dimension => hyperplane_map_dimension
      procedure :: evaluate => hyperplane_evaluate
   end type hyperplane_map

contains

   !> Newton from `guess` (section coordinates) to a fixed point of `map`.
   subroutine find_periodic_orbit(map, guess, settings, orbit, error)
      class(section_map), intent(inout) :: map
      real(wp), intent(in) :: guess(:)
      type(orbit_settings), intent(in) :: settings
      type(periodic_orbit), intent(out) :: orbit
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: s(size(guess)), image(size(guess)), jac(size(guess), size(guess)), step(size(guess))
      real(wp) :: trial(size(guess)), trial_image(size(guess)), trial_jac(size(guess), size(guess))
      real(wp) :: period, trial_period, residual, trial_residual, scale
      logical :: returned, solved
      character(len=:), allocatable :: reason
      integer :: n, halving

      n = map%dimension()
      if (size(guess) /= n .or. n < 1) then
         call fatal_error(error, 'periodic orbit: the section must have a dimension and the guess as many', &
            & error_input)
         return
      end if
      s = guess
      orbit%point = s
      orbit%reason = ''
      call map%evaluate(s, image, jac, period, returned, reason, error)
      if (allocated(error)) return
      if (.not. returned) then
         orbit%reason = reason
         return
      end if
      residual = maxval(abs(image - s))
      do
         orbit%point = s
         orbit%jacobian = jac
         orbit%period = period
         orbit%residual = residual
         if (residual <= settings%tolerance) exit
         if (orbit%iterations >= settings%max_iterations) then
            orbit%reason = 'no convergence in orbit_max_iterations Newton steps'
            return
         end if
         call solve_shifted(jac, -(image - s), step, solved)
         if (.not. solved) then
            orbit%reason = 'a multiplier equals 1: DP - I is singular'
            return
         end if
         ! Coordinates off by more than the tolerance that the step cannot move (it is below their rounding): DP
         ! is far larger than the map's slope there, and no halving helps; say so before evaluating more returns.
         if (all(abs(image - s) <= settings%tolerance .or. abs(step) <= 4 * epsilon(1.0_wp) * abs(s))) then
            orbit%reason = 'the Newton step is below the rounding of the point where it is off: the section ' &
               & //'map''s Jacobian is far larger than its slope there'
            return
         end if
         orbit%iterations = orbit%iterations + 1
         scale = 1.0_wp
         do halving = 0, settings%max_halvings
            trial = s + scale * step
            call map%evaluate(trial, trial_image, trial_jac, trial_period, returned, reason, error)
            if (allocated(error)) return
            if (returned) then
               trial_residual = maxval(abs(trial_image - trial))
               if (trial_residual < residual) exit
            end if
            scale = scale / 2
         end do
         if (.not. (returned .and. trial_residual < residual)) then
            orbit%reason = 'no Newton step reduces the residual'
            if (.not. returned) orbit%reason = orbit%reason//' ('//reason//')'
            return
         end if
         s = trial
         image = trial_image
         jac = trial_jac
         period = trial_period
         residual = trial_residual
      end do
      orbit%multipliers = section_multipliers(orbit%jacobian)
      if (n > max_closed_form .and. any(ieee_is_nan(real(orbit%multipliers)))) then
         orbit%reason = 'the multipliers of the map''s Jacobian could not be computed (LAPACK dgeev failed)'
         deallocate (orbit%multipliers)
         return
      end if
      orbit%found = .true.
   end subroutine find_periodic_orbit

   !> (J - I) x = b: closed forms for n <= 2, Gaussian elimination with partial pivoting beyond.
   pure subroutine solve_shifted(jac, b, x, solved)
      real(wp), intent(in) :: jac(:, :), b(:)
      real(wp), intent(out) :: x(:)
      logical, intent(out) :: solved
      real(wp) :: a(size(b), size(b)), det
      integer :: i

      a = jac
      do i = 1, size(b)
         a(i, i) = a(i, i) - 1.0_wp
      end do
      solved = .false.
      x = 0.0_wp
      select case (size(b))
      case (1)
         if (a(1, 1) == 0.0_wp) return
         x(1) = b(1) / a(1, 1)
      case (2)
         det = a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1)
         if (det == 0.0_wp) return
         x(1) = (a(2, 2) * b(1) - a(1, 2) * b(2)) / det
         x(2) = (a(1, 1) * b(2) - a(2, 1) * b(1)) / det
      case default
         call eliminate(a, b, x, solved)
         if (.not. solved) return
      end select
      solved = all(abs(x) < huge(1.0_wp))
   end subroutine solve_shifted

   !> a x = b by Gaussian elimination with partial pivoting; solved = .false.
   !> for an exactly singular a.
   pure subroutine eliminate(a_in, b_in, x, solved)
      real(wp), intent(in) :: a_in(:, :), b_in(:)
      real(wp), intent(out) :: x(:)
      logical, intent(out) :: solved
      real(wp) :: a(size(b_in), size(b_in)), b(size(b_in)), row(size(b_in)), swap, factor
      integer :: n, i, j, p

      a = a_in
      b = b_in
      n = size(b)
      x = 0.0_wp
      solved = .false.
      do j = 1, n
         p = j - 1 + maxloc(abs(a(j:n, j)), 1)
         if (a(p, j) == 0.0_wp) return
         if (p /= j) then
            row = a(j, :)
            a(j, :) = a(p, :)
            a(p, :) = row
            swap = b(j)
            b(j) = b(p)
            b(p) = swap
         end if
         do i = j + 1, n
            factor = a(i, j) / a(j, j)
            a(i, j:n) = a(i, j:n) - factor * a(j, j:n)
            b(i) = b(i) - factor * b(j)
         end do
      end do
      do i = n, 1, -1
         x(i) = (b(i) - dot_product(a(i, i + 1:n), x(i + 1:n))) / a(i, i)
      end do
      solved = .true.
   end subroutine eliminate

   !> The kind of bifurcation where `critical`, the multiplier of a section
   !> map that crosses the unit circle, leaves it: complex, Neimark–Sacker;
   !> real negative, period doubling; real positive, fold.
   pure integer function crossing_kind(critical)
      complex(wp), intent(in) :: critical

      if (aimag(critical) /= 0.0_wp) then
         crossing_kind = bifurcation_neimark_sacker
      else if (real(critical) < 0.0_wp) then
         crossing_kind = bifurcation_period_doubling
      else
         crossing_kind = bifurcation_fold
      end if
   end function crossing_kind

   !> The walk from `from` to `to`, its first trial the whole step.
   pure subroutine walk_start(self, from, to)
      class(halving_walk), intent(inout) :: self
      real(wp), intent(in) :: from, to

      self%done = .false.
      self%from = from
      self%to = to
      self%at = from
      self%step = to - from
      self%halvings = 0
      call next_trial(self)
   end subroutine walk_start

   !> Whether an orbit was found at the trial: on from it, or a halved step.
   pure subroutine walk_record(self, found)
      class(halving_walk), intent(inout) :: self
      logical, intent(in) :: found

      if (found) then
         if (self%trial == self%to) then
            self%done = .true.
            return
         end if
         self%at = self%trial
         self%step = self%to - self%at
      else
         self%halvings = self%halvings + 1
         if (self%halvings > 5) then
            self%done = .true.
            return
         end if
         self%step = self%step / 2
      end if
      call next_trial(self)
   end subroutine walk_record

   pure subroutine next_trial(walk)
      type(halving_walk), intent(inout) :: walk

      walk%trial = walk%at + walk%step
      if (abs(walk%to - walk%trial) <= 1.0e-12_wp * abs(walk%to - walk%from)) walk%trial = walk%to
   end subroutine next_trial

   !> n values of a branch's parameter evenly from start to last (exactly).
   pure function branch_values(start, last, n) result(values)
      real(wp), intent(in) :: start, last
      integer, intent(in) :: n
      real(wp) :: values(n)
      integer :: k

      do k = 1, n
         values(k) = start + (last - start) * real(k - 1, wp) / real(n - 1, wp)
      end do
      values(n) = last
   end function branch_values

   !> Whether the largest |μ| of a section map, m0 at the value p0 and m1 at
   !> p1, crosses 1 between them: the kind from the critical multiplier
   !> (critical0 at p0, critical1 at p1) on the outer side, the value by
   !> linear interpolation of |μ| - 1.
   pure subroutine modulus_crossing(p0, p1, m0, m1, critical0, critical1, crossed, kind, at)
      real(wp), intent(in) :: p0, p1, m0, m1
      complex(wp), intent(in) :: critical0, critical1
      logical, intent(out) :: crossed
      integer, intent(out) :: kind
      real(wp), intent(out) :: at

      kind = 0
      at = 0.0_wp
      crossed = (m0 - 1.0_wp) * (m1 - 1.0_wp) < 0.0_wp
      if (.not. crossed) return
      kind = crossing_kind(merge(critical1, critical0, m1 > 1.0_wp))
      at = p0 + (1.0_wp - m0) / (m1 - m0) * (p1 - p0)
   end subroutine modulus_crossing

   !> Eigenvalues of a real n x n matrix, n <= 3, by decreasing modulus (a
   !> complex pair: positive imaginary part first): section_multipliers for
   !> n <= 2, and for n = 3 a real root of the characteristic cubic (the
   !> trigonometric or Cardano form, polished by Newton) and the quadratic
   !> left, whose product is det/root.
   pure function small_eigenvalues(a) result(mu)
      real(wp), intent(in) :: a(:, :)
      complex(wp), allocatable :: mu(:)
      real(wp) :: c2, c1, c0, q, r, disc, root, theta, p, dp, sum_rest, product_rest, d
      real(wp) :: pair(2, 2)
      complex(wp) :: rest(2), swap
      integer :: k, i, j

      if (size(a, 1) <= 2) then
         mu = pair_roots(a)
         return
      end if
      ! λ³ + c2 λ² + c1 λ + c0
      c2 = -(a(1, 1) + a(2, 2) + a(3, 3))
      c1 = a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1) + a(1, 1) * a(3, 3) - a(1, 3) * a(3, 1) &
         & + a(2, 2) * a(3, 3) - a(2, 3) * a(3, 2)
      c0 = -(a(1, 1) * (a(2, 2) * a(3, 3) - a(2, 3) * a(3, 2)) - a(1, 2) * (a(2, 1) * a(3, 3) - a(2, 3) * a(3, 1)) &
         & + a(1, 3) * (a(2, 1) * a(3, 2) - a(2, 2) * a(3, 1)))
      q = (c2**2 - 3.0_wp * c1) / 9.0_wp
      r = (2.0_wp * c2**3 - 9.0_wp * c2 * c1 + 27.0_wp * c0) / 54.0_wp
      disc = r**2 - q**3
      if (disc < 0.0_wp) then
         ! Three real roots: the one of largest modulus, by the trigonometric form.
         theta = acos(max(-1.0_wp, min(1.0_wp, r / sqrt(q**3))))
         root = -2.0_wp * sqrt(q) * cos(theta / 3.0_wp) - c2 / 3.0_wp
         do k = 1, 2
            d = -2.0_wp * sqrt(q) * cos((theta + 2.0_wp * k * acos(-1.0_wp)) / 3.0_wp) - c2 / 3.0_wp
            if (abs(d) > abs(root)) root = d
         end do
      else
         d = -sign(1.0_wp, r) * (abs(r) + sqrt(disc))**(1.0_wp / 3.0_wp)
         root = d - c2 / 3.0_wp
         if (d /= 0.0_wp) root = d + q / d - c2 / 3.0_wp
      end if
      do k = 1, 3
         p = ((root + c2) * root + c1) * root + c0
         dp = (3.0_wp * root + 2.0_wp * c2) * root + c1
         if (dp == 0.0_wp) exit
         root = root - p / dp
      end do
      sum_rest = -c2 - root
      if (root /= 0.0_wp) then
         product_rest = -c0 / root
      else
         product_rest = c1
      end if
      ! The pair as the 2 x 2 matrix with that trace and determinant.
      pair = reshape([sum_rest, -product_rest, 1.0_wp, 0.0_wp], [2, 2])
      rest = pair_roots(pair)
      if (aimag(rest(1)) /= 0.0_wp) then
         ! A complex pair stays together, the real root before or after it.
         if (abs(root) >= abs(rest(1))) then
            mu = [cmplx(root, 0.0_wp, wp), rest]
         else
            mu = [rest, cmplx(root, 0.0_wp, wp)]
         end if
      else
         mu = [cmplx(root, 0.0_wp, wp), rest]
         do i = 1, 2
            do j = 1, 3 - i
               if (abs(mu(j + 1)) > abs(mu(j))) then
                  swap = mu(j)
                  mu(j) = mu(j + 1)
                  mu(j + 1) = swap
               end if
            end do
         end do
      end if
   end function small_eigenvalues

   !> Eigenvalues of a section Jacobian, by decreasing modulus (a complex
   !> pair: positive imaginary part first): the closed forms up to 3 x 3
   !> (the results every earlier file holds, to the last bit), LAPACK's
   !> dgeev beyond; NaN for all of them when dgeev fails to converge.
   function section_multipliers(jac) result(mu)
      real(wp), intent(in) :: jac(:, :)
      complex(wp), allocatable :: mu(:)

      if (size(jac, 1) <= max_closed_form) then
         mu = small_eigenvalues(jac)
      else
         mu = general_eigenvalues(jac)
      end if
   end function section_multipliers

   !> Eigenvalues of a real n x n matrix by LAPACK's dgeev (balancing, then
   !> the Hessenberg QR algorithm), by decreasing modulus, a complex pair
   !> with its positive imaginary part first; NaN when QR does not converge.
   function general_eigenvalues(a) result(mu)
      real(wp), intent(in) :: a(:, :)
      complex(wp), allocatable :: mu(:)
      real(wp) :: work_a(size(a, 1), size(a, 1)), wr(size(a, 1)), wi(size(a, 1)), left(1, 1), right(1, 1)
      real(wp) :: work(max(1, 4 * size(a, 1)))
      complex(wp) :: swap
      integer :: n, info, i, j

      n = size(a, 1)
      allocate (mu(n))
      if (n == 0) return
      work_a = a
      call dgeev('N', 'N', n, work_a, n, wr, wi, left, 1, right, 1, work, size(work), info)
      if (info /= 0) then
         mu = cmplx(ieee_value(1.0_wp, ieee_quiet_nan), ieee_value(1.0_wp, ieee_quiet_nan), wp)
         return
      end if
      mu = cmplx(wr, wi, wp)
      ! Insertion sort: stable, so dgeev's pairs (positive imaginary part first) stay in order.
      do i = 2, n
         swap = mu(i)
         j = i - 1
         do while (j >= 1)
            if (.not. (abs(swap) > abs(mu(j)) .or. (abs(swap) == abs(mu(j)) .and. aimag(swap) > aimag(mu(j))))) exit
            mu(j + 1) = mu(j)
            j = j - 1
         end do
         mu(j + 1) = swap
      end do
   end function general_eigenvalues

   !> The closed form for n = 1, 2.
   pure function pair_roots(jac) result(mu)
      real(wp), intent(in) :: jac(:, :)
      complex(wp), allocatable :: mu(:)
      real(wp) :: half_trace, det, disc, root
      complex(wp) :: swap

      allocate (mu(size(jac, 1)))
      select case (size(jac, 1))
      case (1)
         mu(1) = cmplx(jac(1, 1), 0.0_wp, wp)
      case (2)
         half_trace = (jac(1, 1) + jac(2, 2)) / 2
         det = jac(1, 1) * jac(2, 2) - jac(1, 2) * jac(2, 1)
         disc = half_trace**2 - det
         if (disc >= 0.0_wp) then
            ! The larger root without cancellation, the other from the product.
            root = half_trace + sign(sqrt(disc), half_trace)
            mu(1) = cmplx(root, 0.0_wp, wp)
            mu(2) = cmplx(0.0_wp, 0.0_wp, wp)
            if (root /= 0.0_wp) mu(2) = cmplx(det / root, 0.0_wp, wp)
            if (abs(mu(2)) > abs(mu(1))) then
               swap = mu(1)
               mu(1) = mu(2)
               mu(2) = swap
            end if
         else
            mu(1) = cmplx(half_trace, sqrt(-disc), wp)
            mu(2) = conjg(mu(1))
         end if
      end select
   end function pair_roots

   !> All Floquet multipliers of an orbit: the trivial 1 (along the flow),
   !> those of the section map, and `lost` zeros for directions the flow
   !> maps to zero exactly (the brake's velocity in stick).
   pure function floquet_multipliers(orbit, lost) result(mu)
      type(periodic_orbit), intent(in) :: orbit
      integer, intent(in) :: lost
      complex(wp) :: mu(1 + size(orbit%multipliers) + lost)

      mu = cmplx(0.0_wp, 0.0_wp, wp)
      mu(1) = cmplx(1.0_wp, 0.0_wp, wp)
      mu(2:1 + size(orbit%multipliers)) = orbit%multipliers
   end function floquet_multipliers

   !> Floquet exponents ln|μ| / T; -inf for μ = 0 exactly (as the Lyapunov
   !> spectrum reports a lost direction).
   function floquet_exponents(mu, period) result(lambda)
      complex(wp), intent(in) :: mu(:)
      real(wp), intent(in) :: period
      real(wp) :: lambda(size(mu))
      integer :: i

      do i = 1, size(mu)
         if (abs(mu(i)) > 0.0_wp) then
            lambda(i) = log(abs(mu(i))) / period
         else
            lambda(i) = ieee_value(1.0_wp, ieee_negative_inf)
         end if
      end do
   end function floquet_exponents

   pure function hyperplane_event_count(self) result(m)
      class(hyperplane_system), intent(in) :: self
      integer :: m

      m = 1
      if (allocated(self%kink_coordinate)) m = 1 + size(self%kink_coordinate)
      if (self%rearms) m = m + 1
   end function hyperplane_event_count

   pure subroutine hyperplane_event_values(self, t, y, g)
      class(hyperplane_system), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: y(:)
      real(wp), intent(out) :: g(:)

      integer :: i

      g(1) = y(self%coordinate) - self%level
      do i = 2, size(g) - merge(1, 0, self%rearms)
         g(i) = y(self%kink_coordinate(i - 1)) - self%kink_level(i - 1)
      end do
      if (self%rearms) g(size(g)) = y(self%coordinate) - self%rearm_level
   end subroutine hyperplane_event_values

   !> The section y_k = c of an autonomous system, crossed upwards (or, with
   !> falling = .true., downwards).  Kinks y_j = c_j of the field (kink_coordinate,
   !> kink_level): located and the integration restarted there, so that no
   !> step straddles one (a step over a kink leaves the tangent equations an
   !> error of first order in the tolerance).  With rearm_level, a crossing
   !> counts only after y_k has crossed that level the other way since the
   !> start or the last crossing: a trajectory that grazes the section (leaves
   !> it and comes straight back) does not return there.
   subroutine hyperplane_setup(self, system, solver, coordinate, level, max_return, event_tolerance, falling, &
      & kink_coordinate, kink_level, rearm_level)
      class(hyperplane_map), intent(inout) :: self
      class(ode_system), intent(in) :: system
      type(solver_settings), intent(in) :: solver
      integer, intent(in) :: coordinate
      real(wp), intent(in) :: level, max_return, event_tolerance
      logical, intent(in), optional :: falling
      integer, intent(in), optional :: kink_coordinate(:)
      real(wp), intent(in), optional :: kink_level(:)
      real(wp), intent(in), optional :: rearm_level
      type(hyperplane_system) :: plane

      allocate (plane%base, source=system)
      plane%coordinate = coordinate
      plane%level = level
      self%kinks = 0
      if (present(kink_coordinate) .and. present(kink_level)) then
         plane%kink_coordinate = kink_coordinate
         plane%kink_level = kink_level
         self%kinks = size(kink_coordinate)
      end if
      self%rearms = present(rearm_level)
      plane%rearms = self%rearms
      if (self%rearms) then
         self%rearm_level = rearm_level
         plane%rearm_level = rearm_level
      end if
      if (allocated(self%extended)) deallocate (self%extended)
      allocate (self%extended)
      allocate (self%extended%base, source=plane)
      self%solver = solver
      self%coordinate = coordinate
      self%level = level
      self%max_return = max_return
      self%event_tolerance = event_tolerance
      self%falling = .false.
      if (present(falling)) self%falling = falling
   end subroutine hyperplane_setup

   pure integer function hyperplane_map_dimension(self)
      class(hyperplane_map), intent(in) :: self

      hyperplane_map_dimension = self%extended%base%dimension() - 1
   end function hyperplane_map_dimension

   !> From the section point s (y_k = c) with Φ = I to the next upward
   !> crossing; DP = the other rows and columns of (I - f nᵀ/(nᵀ f)) Φ(T),
   !> n = e_k: the monodromy matrix projected along the flow onto the section.
   subroutine hyperplane_evaluate(self, s, image, jacobian, period, returned, reason, error)
      class(hyperplane_map), intent(inout) :: self
      real(wp), intent(in) :: s(:)
      real(wp), intent(out) :: image(:), jacobian(:, :), period
      logical, intent(out) :: returned
      character(len=:), allocatable, intent(out) :: reason
      type(error_type), allocatable, intent(out) :: error
      type(event_locator) :: locator
      real(wp) :: y(size(s) + 1), phi(size(s) + 1, size(s) + 1), f(size(s) + 1), z((size(s) + 1) * (size(s) + 2))
      real(wp) :: row(size(s) + 1)
      real(wp) :: t, h
      integer :: n, i, k, m
      integer, allocatable :: others(:)
      logical :: crossed, armed

      n = size(s) + 1
      k = self%coordinate
      others = pack([(i, i=1, n)], [(i, i=1, n)] /= k)
      y(others) = s
      y(k) = self%level
      phi = 0.0_wp
      do i = 1, n
         phi(i, i) = 1.0_wp
      end do
      image = s
      jacobian = 0.0_wp
      period = 0.0_wp
      returned = .false.
      reason = ''
      h = self%solver%h_start
      if (.not. (h > 0.0_wp)) h = self%first_step
      m = 1 + self%kinks
      if (self%rearms) then
         call locator%init(self%extended, self%solver, [merge(event_falling, event_rising, self%falling), &
            & spread(event_either, 1, m - 1), merge(event_rising, event_falling, self%falling)], &
            & [spread(.true., 1, m), .false.], self%event_tolerance, h, error)
      else
         call locator%init(self%extended, self%solver, [merge(event_falling, event_rising, self%falling), &
            & spread(event_either, 1, m - 1)], spread(.true., 1, m), self%event_tolerance, h, error)
      end if
      if (allocated(error)) return
      t = 0.0_wp
      z = pack_tangent(y, phi)
      call locator%restart(t, z, h)
      crossed = .false.
      armed = .not. self%rearms
      do while (t < self%max_return)
         if (associated(self%watch)) then
            call locator%advance(t, self%max_return, z, error, self%watch)
         else
            call locator%advance(t, self%max_return, z, error)
         end if
         if (allocated(error)) return
         if (self%rearms .and. locator%n_hits > 0) then
            if (any(locator%hits(1:locator%n_hits)%which == m + 1)) armed = .true.
         end if
         if (locator%n_hits > 0) then
            if (locator%hits(locator%n_hits)%terminal) then
               ! A function exactly 0 at a restart crosses at once (ode/events.f90):
               ! that first hit, within a few event tolerances, is the start itself.
               ! A kink: on from its far side with a fresh step.
               crossed = locator%hits(locator%n_hits)%which == 1 .and. t > 1.0e3_wp * self%event_tolerance &
                  & .and. armed
               if (crossed) exit
               ! (a crossing before the rearming level: the flow grazed the section)
               if (locator%hits(locator%n_hits)%which == 1 .and. t > 1.0e3_wp * self%event_tolerance) &
                  & armed = .not. self%rearms
               call locator%restart(t, z, 0.0_wp)
               locator%n_hits = 0
            end if
         end if
      end do
      if (.not. crossed) then
         reason = 'no return to the section within the longest return time'
         return
      end if
      call unpack_tangent(z, y, phi)
      call self%extended%base%rhs(t, y, f)
      ! Row k as it was before the loop zeroes it: the rows after k need it too.
      row = phi(k, :)
      do i = 1, n
         phi(i, :) = phi(i, :) - f(i) * row / f(k)
      end do
      image = y(others)
      jacobian = phi(others, others)
      period = t
      returned = .true.
   end subroutine hyperplane_evaluate

   !> The period map of `system` from t0 over `period`.
   subroutine stroboscopic_setup(self, system, solver, t0, period)
      class(stroboscopic_map), intent(inout) :: self
      class(ode_system), intent(in) :: system
      type(solver_settings), intent(in) :: solver
      real(wp), intent(in) :: t0, period

      if (allocated(self%extended)) deallocate (self%extended)
      allocate (self%extended)
      allocate (self%extended%base, source=system)
      self%solver = solver
      self%t0 = t0
      self%period = period
   end subroutine stroboscopic_setup

   pure integer function stroboscopic_dimension(self)
      class(stroboscopic_map), intent(in) :: self

      stroboscopic_dimension = self%extended%base%dimension()
   end function stroboscopic_dimension

   subroutine stroboscopic_evaluate(self, s, image, jacobian, period, returned, reason, error)
      class(stroboscopic_map), intent(inout) :: self
      real(wp), intent(in) :: s(:)
      real(wp), intent(out) :: image(:), jacobian(:, :), period
      logical, intent(out) :: returned
      character(len=:), allocatable, intent(out) :: reason
      type(error_type), allocatable, intent(out) :: error
      type(ode_solver) :: solver
      real(wp) :: phi(size(s), size(s)), z(size(s) * (size(s) + 1)), t, h, y(size(s))
      integer :: i

      image = s
      jacobian = 0.0_wp
      period = self%period
      returned = .false.
      reason = ''
      phi = 0.0_wp
      do i = 1, size(s)
         phi(i, i) = 1.0_wp
      end do
      h = self%solver%h_start
      if (.not. (h > 0.0_wp)) h = 1.0e-6_wp * self%period
      call solver%init(self%extended, self%solver, h, error)
      if (allocated(error)) return
      t = self%t0
      z = pack_tangent(s, phi)
      if (associated(self%watch)) then
         call solver%advance(t, self%t0 + self%period, z, error, self%watch)
      else
         call solver%advance(t, self%t0 + self%period, z, error)
      end if
      if (allocated(error)) return
      call unpack_tangent(z, y, phi)
      image = y
      jacobian = phi
      returned = .true.
   end subroutine stroboscopic_evaluate

end module friction_analysis_periodic_orbit
