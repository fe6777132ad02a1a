!> The overdamped tip at T = 0 against the slow limit it follows: where
!> the support hardly moves during a slip, the tip must land where the
!> quasistatic model's minimum lands, and an integration error that lets
!> it slip elsewhere (or earlier) is caught here, sample by sample.
module friction_afm_slow_limit
   use friction_kinds, only: wp
   use friction_error, only: error_type, fatal_error, error_numerical
   use friction_afm_tip, only: afm_tip, model_overdamped
   use friction_afm_quasistatic, only: newton_equilibrium, force_imbalance, continuation_step, landing_distance, &
      & equilibrium_tangent
   use friction_symmetric, only: symmetric_eigen
   use friction_strings, only: rtoa, fixed_text
   implicit none
   private

   public :: in_slow_limit, check_overdamped_slip, following_excess, bias_factor

   !> The overdamped tip's slips are checked where the support travels at
   !> most slow_travel Å in the tip's slowest spring relaxation time c_i/k_i
   !> (then it lags its minimum by about that much, and lands where the
   !> descent at a fixed support lands: the slow limit), and from samples
   !> within check_lag Å of their minimum; two minima are the same within
   !> same_minimum Å (below any well spacing of NaF or HOPG); the descent's
   !> step, Å.
   real(wp), parameter :: slow_travel = 2.5e-3_wp, check_lag = 0.05_wp, same_minimum = 0.25_wp
   real(wp), parameter :: descent_step = 0.01_wp
   !> How many times the time the slip takes from the fold (the passage
   !> through the fold's bottleneck and the relaxation into the new well,
   !> integrated by slip_duration) a tip may take to land.
   real(wp), parameter :: late_factor = 3.0_wp
   !> Where the tip follows its minimum, an integration that puts it farther
   !> from its lag than this many times its tolerances' bound (atol + rtol
   !> |u|, per component) is biased (docs/physics.md, reduced tip models):
   !> measured 4.3 to 21 for rk4imp and 2.8 to 8.4 for msbdf at their
   !> default tolerances on NaF, HOPG and the stiff row at 1 and 10 Å/s,
   !> at most 1.9 for rkf45, rk2, rk8pd, rk2imp, rodas4 and 'auto'.
   real(wp), parameter :: bias_factor = 4.0_wp

contains

   !> Whether the tip is the overdamped one in its slow limit at the support
   !> speed `velocity`, Å/s: its slips are then checked.
   pure logical function in_slow_limit(tip, velocity)
      type(afm_tip), intent(in) :: tip
      real(wp), intent(in) :: velocity
      integer :: nd

      nd = tip%ndim
      in_slow_limit = tip%model == model_overdamped .and. all(tip%spring(1:nd) > 0.0_wp)
      if (in_slow_limit) in_slow_limit = velocity * maxval(tip%damping(1:nd) / tip%spring(1:nd)) <= slow_travel
   end function in_slow_limit

   !> How far the overdamped tip at (t, u) is from where it follows its
   !> minimum of the total energy, in units of the tolerances' bound atol +
   !> rtol |u| per component (tolerances = [rtol, atol], Å): the minimum m
   !> (Newton's method from u) plus the lag the flow gives the tip while m
   !> moves at dm/dt, J (u - m) = -C (dm/dt + v_M) (J = K + H at m: the
   !> linearised c u' = -grad E).  `valid` only where the tip is within
   !> check_lag of m and that lag is itself within the bound (away from
   !> folds, where the linearisation holds).
   subroutine following_excess(tip, t, u, tolerances, excess, valid)
      type(afm_tip), intent(in) :: tip
      real(wp), intent(in) :: t, u(:), tolerances(2)
      real(wp), intent(out) :: excess
      logical, intent(out) :: valid
      real(wp) :: m(size(u)), dmdt(size(u)), hess(3, 3), jac(size(u), size(u)), values(size(u))
      real(wp) :: vectors(size(u), size(u)), lag(size(u)), bound(size(u))
      integer :: i, n

      n = size(u)
      excess = 0.0_wp
      call newton_equilibrium(tip, t, u, m, valid)
      if (valid) valid = norm2(m - u) <= check_lag
      if (valid) call equilibrium_tangent(tip, t, m, dmdt, valid)
      if (.not. valid) return
      call tip%potential%hessian(tip%tip_position(t, m), hess)
      jac = hess(1:n, 1:n)
      do i = 1, n
         jac(i, i) = jac(i, i) + tip%spring(i)
      end do
      call symmetric_eigen(jac, values, vectors)
      valid = all(values > 0.0_wp)
      if (.not. valid) return
      lag = matmul(vectors, matmul(transpose(vectors), -tip%damping(1:n) * (dmdt + tip%support_velocity(1:n))) &
         & / values)
      bound = tolerances(2) + tolerances(1) * abs(u)
      valid = all(abs(lag) <= bound)
      if (valid) excess = maxval(abs(u - m - lag) / bound)
   end subroutine following_excess

   !> The overdamped tip at T = 0 from the sample (t0, u0) to the next, (t1,
   !> u1), against the slow limit it follows: an error when it slipped
   !> where that limit does not.  The overdamped tip lags behind its
   !> minimum of the total energy E, on the side away from the saddle ahead
   !> (at the minimum u' = -v_M, while the minimum moves forward), so it
   !> cannot leave the minimum before the minimum ends at its fold; and
   !> where the support hardly moves during a slip (slow_travel) it lands
   !> where the descent at the support of the fold lands.  So: the minimum
   !> of the tip at t0 is followed to t1 as the quasistatic model follows
   !> it (continuation; at a fold, a push along the motion and the descent
   !> of the overdamped flow, c u' = -grad E, at that support), and the tip
   !> at t1 must be in that minimum.  An explicit pair at its stability
   !> limit on a stiff tip lets the stiff component grow unseen until the
   !> tip leaves a minimum that still exists; a stepper that steps over a
   !> slip can land a site too far.  No claim (no error) where the tip is
   !> mid-slip or lags at t0, or a descent does not settle.  The message
   !> says what went wrong; the caller says where.
   subroutine check_overdamped_slip(tip, t0, u0, t1, u1, pending, error)
      type(afm_tip), intent(in) :: tip
      real(wp), intent(in) :: t0, u0(:), t1, u1(:)
      !> the support time by which the tip must have landed from a fold it
      !> had not yet landed from at t0 (negative: none); on return, at t1
      real(wp), intent(inout) :: pending
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: m(size(u0)), w(size(u0)), t, h, speed, deadline, ghost(size(u0))
      logical :: ok, folded, at_fold
      integer :: steps, n

      n = size(u0)
      speed = norm2(tip%support_velocity(1:n))
      if (.not. (speed > 0.0_wp)) return
      call newton_equilibrium(tip, t0, u0, m, ok)
      if (ok) ok = norm2(m - u0) <= check_lag
      if (.not. ok) then
         ! Mid-slip (no claim), or still on its way from a fold: the slow
         ! limit is then where the descent from here lands.
         if (pending < 0.0_wp) return
         m = u0
         call descend(t0, m, ok)
         if (.not. ok) then
            pending = -1.0_wp
            return
         end if
      else
         pending = -1.0_wp
      end if
      t = t0
      h = t1 - t0
      folded = pending >= 0.0_wp
      deadline = merge(pending, huge(1.0_wp), folded)
      pending = -1.0_wp
      steps = 0
      do while (t < t1)
         steps = steps + 1
         if (steps > 100000) return
         call continuation_step(tip, t, t1, h, speed, m, at_fold, ghost)
         if (at_fold) then
            call descend(t, m, ok)
            if (.not. ok) return
            if (.not. folded) deadline = t + late_factor * slip_duration(t, ghost, m)
            folded = .true.
            h = t1 - t
         end if
      end do
      w = u1
      call descend(t1, w, ok)
      if (.not. ok) return
      if (norm2(w - m) <= same_minimum) then
         if (folded .and. norm2(u1 - m) > check_lag) then
            if (t1 > deadline) then
               call fatal_error(error, 'the tip had not slipped '//fixed_text(speed * (t1 - deadline), 4) &
                  & //' Å of support travel after it should have landed from the fold of its minimum of the ' &
                  & //'total energy ('//rtoa(late_factor)//' times the time the slip takes)', error_numerical)
            else
               pending = deadline
            end if
         end if
         return
      end if
      if (folded) then
         call fatal_error(error, 'the tip slipped into the minimum at '//fixed_text(norm2(w - m), 3) &
            & //' Å from the one its slow limit reaches (a site skipped or a wrong landing)', error_numerical)
      else
         call fatal_error(error, 'the tip slipped out of its minimum of the total energy while that minimum ' &
            & //'still existed (it can slip only where its minimum ends)', error_numerical)
      end if

   contains

      !> The time the overdamped tip takes from the ghost of its minimum at
      !> the fold (support time tf) to within check_lag of the minimum it
      !> lands in (near `landing`), the support moving: explicit Euler on
      !> the tip's own equation at a tenth of its stability limit (the
      !> curvature of V from its Hessian at every step); huge when it does
      !> not land within 1e6 steps (no claim).
      real(wp) function slip_duration(tf, start, landing) result(duration)
         real(wp), intent(in) :: tf, start(:), landing(:)
         real(wp) :: u(size(start)), dudt(size(start)), hess(3, 3), minimum(size(start)), tt, dt
         integer :: step
         logical :: settled

         u = start
         tt = tf
         duration = huge(1.0_wp)
         do step = 1, 1000000
            call tip%potential%hessian(tip%tip_position(tt, u), hess)
            dt = 0.1_wp * minval(tip%damping(1:n)) / (maxval(tip%spring(1:n)) + norm2(hess(1:n, 1:n)))
            call tip%rhs(tt, u, dudt)
            u = u + dt * dudt
            tt = tt + dt
            if (mod(step, 64) == 0 .and. norm2(u - landing) <= same_minimum) then
               call newton_equilibrium(tip, tt, u, minimum, settled)
               if (settled .and. norm2(minimum - u) <= check_lag) then
                  duration = tt - tf
                  return
               end if
            end if
         end do
      end function slip_duration

      !> u down the overdamped flow c u' = -grad E at the support of time
      !> ts (normalised steps of descent_step: the flow's path, not its
      !> time), into the minimum Newton's method then confirms.
      subroutine descend(ts, u, settled)
         real(wp), intent(in) :: ts
         real(wp), intent(inout) :: u(:)
         logical, intent(out) :: settled
         real(wp) :: g(size(u)), d(size(u)), minimum(size(u))
         integer :: iter

         do iter = 0, 20000
            if (mod(iter, 8) == 0) then
               call newton_equilibrium(tip, ts, u, minimum, settled)
               if (settled) settled = norm2(minimum - u) <= landing_distance
               if (settled) then
                  u = minimum
                  return
               end if
            end if
            g = force_imbalance(tip, ts, u)
            d = -g / tip%damping(1:size(u))
            if (.not. (norm2(d) > 0.0_wp)) exit
            u = u + descent_step * d / norm2(d)
         end do
         settled = .false.
      end subroutine descend

   end subroutine check_overdamped_slip

end module friction_afm_slow_limit
