!> The trips at T = 0: the tip's equations of motion integrated by the ODE
!> solver (inertial and overdamped tips), or the quasistatic tip followed
!> along its minimum of the total energy.
!>
!> The reduced models (docs/physics.md, reduced tip models): the overdamped tip is
!> integrated like the full one (friction_afm_tip), its slips checked
!> against the slow limit it follows (friction_afm_slow_limit); the
!> quasistatic tip is followed from sample to sample along its minimum
!> (friction_afm_quasistatic), starts in the minimum it relaxes into from
!> the support, and jumps to the next minimum where its own disappears
!> (see follow).
module friction_afm_deterministic_trip
   use friction_kinds, only: wp, pi
   use friction_error, only: error_type, fatal_error, error_numerical
   use friction_ode_solver, only: ode_solver
   use friction_afm_config, only: afm_config
   use friction_afm_tip, only: afm_tip, model_inertial, model_quasistatic
   use friction_afm_quasistatic, only: newton_equilibrium, continuation_step, landing_distance
   use friction_afm_slow_limit, only: in_slow_limit, check_overdamped_slip
   use friction_afm_trip, only: trip_record, trip_path, start_height, support_at
   use friction_afm_guard, only: trip_guard
   use friction_strings, only: rtoa, fixed_text
   implicit none
   private

   public :: deterministic_trip

   !> Relaxation stretches (of 10 relaxation times) before the quasistatic
   !> tip is given up as finding no minimum.
   integer, parameter :: max_stretches = 100000

   !> The trips at T = 0 of one tip: its solver and the solver's first step.
   type :: deterministic_trip
      type(ode_solver) :: solver
      real(wp) :: h_start = 0.0_wp
   contains
      procedure :: init
      procedure :: run
      procedure, private :: follow
      procedure, private :: relax
   end type deterministic_trip

contains

   !> The solver of `tip`, which must stay where it is while the solver
   !> lives; its first step a small fraction of the fastest time scale in
   !> sight (without inertia: the relaxation time c/k) unless the
   !> &integrator group gives one.
   subroutine init(self, tip, config, error)
      class(deterministic_trip), intent(inout) :: self
      type(afm_tip), intent(in), target :: tip
      type(afm_config), intent(in) :: config
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: period

      period = config%length / real(config%nx - 1, wp) / config%velocity
      if (maxval(tip%spring) > 0.0_wp) then
         if (tip%model == model_inertial) then
            period = min(period, 2.0_wp * pi * sqrt(tip%mass / maxval(tip%spring)))
         else
            period = min(period, minval(tip%damping(1:tip%ndim)) / maxval(tip%spring))
         end if
      end if
      self%h_start = config%solver%h_start
      ! (An h_min above the automatic first step raises it, as for the brake.)
      if (self%h_start <= 0.0_wp) self%h_start = max(1.0e-3_wp * period, config%solver%h_min)
      call self%solver%init(tip, config%solver, self%h_start, error)
   end subroutine init

   !> The trip `path` (start_trip has set the tip's support on it) into
   !> `record`: the tip starts at the support and at rest, in z at its
   !> static equilibrium under the support (paper §3.1: z differs).
   subroutine run(self, tip, config, guard, path, record, error)
      class(deterministic_trip), intent(inout) :: self
      type(afm_tip), intent(inout) :: tip
      type(afm_config), intent(in) :: config
      type(trip_guard), intent(inout) :: guard
      type(trip_path), intent(in) :: path
      type(trip_record), intent(inout) :: record
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: y(6), t, t_sample, u_z, t_last, u_last(3), pending
      integer :: i, k, nd, jumps, i_last
      logical :: checking

      nd = tip%ndim
      y = 0.0_wp
      if (nd == 3) then
         call start_height(tip, config, path, u_z, error)
         if (allocated(error)) return
         y(3) = u_z
      end if
      t = 0.0_wp
      jumps = 0
      checking = in_slow_limit(tip, config%velocity)
      t_last = -1.0_wp
      pending = -1.0_wp
      u_last = 0.0_wp
      i_last = 0
      call self%solver%restart(self%h_start)
      if (tip%model == model_quasistatic) call self%relax(tip, t, y(1:nd), error)
      if (allocated(error)) then
         error%message = error%message//path%where(config, t)
         return
      end if
      call record%reserve(config%nx, error)
      if (allocated(error)) return
      do k = 1, config%nx
         i = path%sample(config, k)
         t_sample = path%sample_time(config, i)
         if (tip%model == model_quasistatic) then
            if (t_sample > t) call self%follow(tip, t, t_sample, y(1:nd), jumps, error)
         else
            if (t_sample > t) call self%solver%advance(t, t_sample, y(1:tip%dimension()), error)
         end if
         if (.not. allocated(error)) call guard%check(trim(config%solver%method), t, error)
         if (checking .and. t_last >= 0.0_wp .and. .not. allocated(error)) then
            call check_overdamped_slip(tip, t_last, u_last(1:nd), t, y(1:nd), pending, error)
            if (allocated(error)) error%message = 'overdamped tip at T = 0, between the samples at support ' &
               & //fixed_text(support_at(config, i_last - 1), 4)//' and '//fixed_text(support_at(config, i - 1), 4) &
               & //' Å: '//error%message//': an integration error of '//trim(config%solver%method)//' at rtol = ' &
               & //rtoa(config%solver%rtol)//', atol = '//rtoa(config%solver%atol)//" (&integrator): tighten " &
               & //"them, or use method = 'rodas4' or 'auto' (docs/physics.md, reduced tip models)"
         end if
         if (allocated(error)) then
            error%message = error%message//path%where(config, t)
            return
         end if
         t_last = t
         u_last(1:nd) = y(1:nd)
         i_last = i
         call record%put(i, tip, config, path, t, y, jumps, error)
         if (allocated(error)) return
         jumps = 0
      end do
   end subroutine run

   !> The quasistatic tip from support time t to t1 (the next sample), u its
   !> displacement from the support (ndim components), jumps counted.
   !>
   !> Why this algorithm: the quasistatic model is the v -> 0 limit of the
   !> full one, in which the tip sits in a minimum of the total energy E
   !> while sticking and slips, faster than the support moves, when that
   !> minimum ends at a fold (saddle-node).  So the tip is followed along
   !> its minimum by continuation (continuation_step: a tangent predictor
   !> and Newton's method as corrector, steps that cannot leave the well);
   !> at a fold the tip, pushed off the ghost of its minimum along its
   !> motion, is relaxed into the minimum it falls into at the support
   !> position just past the fold (relax), and the jump is counted.  Where
   !> the minimum moves smoothly one predictor-corrector step (2-3 Newton
   !> iterations) covers a whole sample interval: that is what the model
   !> saves against integrating the motion.
   subroutine follow(self, tip, t, t1, u, jumps, error)
      class(deterministic_trip), intent(inout) :: self
      type(afm_tip), intent(inout) :: tip
      real(wp), intent(inout) :: t
      real(wp), intent(in) :: t1
      real(wp), intent(inout) :: u(:)
      integer, intent(inout) :: jumps
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: h, speed, ghost(size(u))
      logical :: folded
      integer :: steps

      speed = norm2(tip%support_velocity)
      h = t1 - t
      steps = 0
      do while (t < t1)
         steps = steps + 1
         if (steps > 1000000) then
            call fatal_error(error, 'quasistatic: more than 1e6 continuation steps between two samples at t = ' &
               & //rtoa(t)//' s', error_numerical)
            return
         end if
         call continuation_step(tip, t, t1, h, speed, u, folded, ghost)
         if (folded) then
            call self%relax(tip, t, u, error)
            if (allocated(error)) return
            jumps = jumps + 1
            h = t1 - t
         end if
      end do
   end subroutine follow

   !> Relax the quasistatic tip, support held at its position of time t,
   !> into a minimum of E: the first-order motion c u' = -(k u + dV/dr)
   !> (friction_afm_tip with model_quasistatic) in stretches of ten
   !> relaxation times, until Newton's method from the state converges, with
   !> J positive definite, to a minimum within landing_distance.
   subroutine relax(self, tip, t, u, error)
      class(deterministic_trip), intent(inout) :: self
      type(afm_tip), intent(inout) :: tip
      real(wp), intent(in) :: t
      real(wp), intent(inout) :: u(:)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: saved_start(3), saved_velocity(3), tau, s, minimum(size(u))
      logical :: ok
      integer :: k, nd

      nd = size(u)
      saved_start = tip%support_start
      saved_velocity = tip%support_velocity
      tip%support_start = tip%support(t)
      tip%support_velocity = 0.0_wp
      tau = maxval(tip%damping(1:nd) / max(tip%spring(1:nd), 1.0e-3_wp * maxval(tip%spring(1:nd)), &
         & tiny(1.0_wp)))
      call self%solver%restart(min(self%h_start, 1.0e-3_wp * tau))
      s = 0.0_wp
      ok = .false.
      do k = 1, max_stretches
         call newton_equilibrium(tip, 0.0_wp, u, minimum, ok)
         if (ok) ok = norm2(minimum - u) <= landing_distance
         if (ok) exit
         call self%solver%advance(s, s + 10.0_wp * tau, u, error)
         if (allocated(error)) exit
      end do
      if (.not. allocated(error) .and. .not. ok) call fatal_error(error, 'quasistatic: the tip found no ' &
         & //'minimum in '//rtoa(10.0_wp * max_stretches * tau)//' s of relaxation', error_numerical)
      if (allocated(error)) then
         error%message = error%message//' (relaxing the quasistatic tip into a minimum; t counts from ' &
            & //'the start of the relaxation)'
      else
         u = minimum
      end if
      tip%support_start = saved_start
      tip%support_velocity = saved_velocity
   end subroutine relax

end module friction_afm_deterministic_trip
