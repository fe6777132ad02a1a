!> What every friction model of the brake is to a run: an integrator that
!> starts from a state, advances to a time through its events, and says
!> whether the block sticks.  The models (switched.f90, regularized.f90)
!> extend it; only brake_run's factory (simulate.f90) names them.
module friction_brake_integrator
   use friction_kinds, only: wp
   use friction_error, only: error_type, fatal_error, error_numerical
   use friction_strings, only: rtoa
   use friction_ode_solver, only: integrator_statistics
   use friction_ode_events, only: event_locator, event_falling, event_rising
   use friction_brake_config, only: brake_config
   use friction_brake_record, only: brake_event_table, event_stick_to_slip, event_slip_to_stick
   implicit none
   private

   public :: brake_integrator

   type, abstract :: brake_integrator
      real(wp) :: t = 0.0_wp                !! time reached, τ
      real(wp) :: y(4) = 0.0_wp             !! state there as integrated: x, x' - v_origin, y, y' (`state`: x')
      !> What y(2) is measured from: 0 (the block's velocity x') for the brake's
      !> own models and a set-valued law; v'_dr for a law's flow, whose y(2) is
      !> the slip rate v_rel, which creeps far below the spacing of v'_dr's doubles.
      real(wp) :: v_origin = 0.0_wp
      real(wp) :: stick_time = -1.0_wp      !! time spent in stick, when the model tracks it exactly; else < 0
      type(event_locator) :: locator
      !> Set before start: integrate the tangent matrix phi beside the state
      !> (the Lyapunov spectrum, docs/physics.md); phi = I at the start, of
      !> the dimension of the whole state: x, x', y, y' and a friction law's
      !> internal states (`states`, as the model integrates them).
      logical :: tangent = .false.
      real(wp), allocatable :: phi(:, :)
      real(wp), allocatable :: states(:)    !! the tangent run's law states (none for the brake's own models)
      real(wp), allocatable :: packed(:)    !! (y, states, Φ) as the locator steps them (allocated with Φ)
      integer :: lost = 0                   !! directions mapped to 0 (stick) since reset_tangent
   contains
      !> Start at (t0, y0) with the settings of `config`; the event table is cleared.
      procedure(start_interface), deferred :: start
      !> Advance to t_target; events go into the table.  On error, t is the time reached.
      procedure(advance_interface), deferred :: advance_to
      !> Whether the block sticks to the belt now.
      procedure(sticking_interface), deferred :: is_sticking
      procedure :: statistics
      !> The state (x, x', y, y') of y as integrated, and of any such vector (a located event's).
      procedure :: state
      procedure :: physical
      !> A friction law's internal states beyond (x, x', y, y'), as the model
      !> integrates them: how many, their values now, and setting them (after
      !> start, in place of the steady ones: Benettin's perturbed run).
      procedure :: state_count
      procedure :: get_states
      procedure :: set_states
      procedure :: reset_tangent
      procedure :: start_tangent
      procedure :: locator_advance
      procedure :: locator_restart
      procedure :: record_band_hits
   end type brake_integrator

   abstract interface
      subroutine start_interface(self, config, t0, y0, events, error)
         import :: brake_integrator, brake_config, wp, brake_event_table, error_type
         class(brake_integrator), target, intent(inout) :: self
         type(brake_config), intent(in) :: config
         real(wp), intent(in) :: t0, y0(4)
         type(brake_event_table), intent(inout) :: events
         type(error_type), allocatable, intent(out) :: error
      end subroutine start_interface

      subroutine advance_interface(self, t_target, events, error)
         import :: brake_integrator, wp, brake_event_table, error_type
         class(brake_integrator), intent(inout) :: self
         real(wp), intent(in) :: t_target
         type(brake_event_table), intent(inout) :: events
         type(error_type), allocatable, intent(out) :: error
      end subroutine advance_interface

      logical function sticking_interface(self)
         import :: brake_integrator
         class(brake_integrator), intent(in) :: self
      end function sticking_interface
   end interface

contains

   !> The stepper's cost counters.
   function statistics(self) result(stats)
      class(brake_integrator), intent(in) :: self
      type(integrator_statistics) :: stats

      stats = self%locator%statistics()
   end function statistics

   !> The state now, (x, x', y, y').
   pure function state(self) result(z)
      class(brake_integrator), intent(in) :: self
      real(wp) :: z(4)

      z = self%physical(self%y)
   end function state

   !> (x, x', y, y') of a vector in the integrated coordinates: unchanged,
   !> bit for bit, when v_origin = 0.
   pure function physical(self, y) result(z)
      class(brake_integrator), intent(in) :: self
      real(wp), intent(in) :: y(4)
      real(wp) :: z(4)

      z = y
      if (self%v_origin /= 0.0_wp) z(2) = y(2) + self%v_origin
   end function physical

   !> No states: the brake's own models.
   pure integer function state_count(self)
      class(brake_integrator), intent(in) :: self

      state_count = 0
   end function state_count

   !> The states now (none here).
   subroutine get_states(self, states)
      class(brake_integrator), intent(in) :: self
      real(wp), intent(out) :: states(:)
   end subroutine get_states

   !> Continue from these states (none here: nothing to do).
   subroutine set_states(self, states)
      class(brake_integrator), intent(inout) :: self
      real(wp), intent(in) :: states(:)
   end subroutine set_states

   !> Φ = I at the start of a run with the tangent, for the four variables
   !> and `states` law states (0 if absent; self%states holds their values).
   subroutine start_tangent(self, states)
      class(brake_integrator), intent(inout) :: self
      integer, intent(in), optional :: states
      integer :: i, n

      n = 4
      if (present(states)) n = 4 + states
      if (allocated(self%phi)) deallocate (self%phi)
      if (allocated(self%packed)) deallocate (self%packed)
      allocate (self%phi(n, n), self%packed(n + n * n))
      if (allocated(self%states)) then
         if (size(self%states) /= n - 4) deallocate (self%states)
      end if
      if (.not. allocated(self%states)) allocate (self%states(n - 4), source=0.0_wp)
      self%phi = 0.0_wp
      do i = 1, n
         self%phi(i, i) = 1.0_wp
      end do
      self%lost = 0
   end subroutine start_tangent

   !> (y, states, Φ by columns) into self%packed.
   subroutine pack_state(self)
      class(brake_integrator), intent(inout) :: self
      integer :: n

      n = size(self%phi, 1)
      self%packed(1:4) = self%y
      self%packed(5:n) = self%states
      self%packed(n + 1:) = reshape(self%phi, [n * n])
   end subroutine pack_state

   !> The locator's advance of (t, y), with the law's states and Φ beside y
   !> when the tangent is on.
   subroutine locator_advance(self, t_target, error)
      class(brake_integrator), intent(inout) :: self
      real(wp), intent(in) :: t_target
      type(error_type), allocatable, intent(out) :: error
      integer :: n

      if (self%tangent) then
         n = size(self%phi, 1)
         call pack_state(self)
         call self%locator%advance(self%t, t_target, self%packed, error)
         self%y = self%packed(1:4)
         self%states = self%packed(5:n)
         self%phi = reshape(self%packed(n + 1:), [n, n])
      else
         call self%locator%advance(self%t, t_target, self%y, error)
      end if
   end subroutine locator_advance

   !> The locator's restart at (t, y), with the law's states and Φ when the tangent is on.
   subroutine locator_restart(self, h_start)
      class(brake_integrator), intent(inout) :: self
      real(wp), intent(in) :: h_start

      if (self%tangent) then
         call pack_state(self)
         call self%locator%restart(self%t, self%packed, h_start)
      else
         call self%locator%restart(self%t, self%y, h_start)
      end if
   end subroutine locator_restart

   !> Replace the tangent matrix (after a QR step) and forget lost directions.
   subroutine reset_tangent(self, phi)
      class(brake_integrator), intent(inout) :: self
      real(wp), intent(in) :: phi(:, :)

      self%phi = phi
      self%lost = 0
      ! The stepper's copies of the state are stale: start it again here (in
      ! stick harmless: a slip restarts it anyway), at the step it had reached.
      call self%locator_restart(0.0_wp)
   end subroutine reset_tangent

   !> The hits of the last locator advance of a model whose stick is the
   !> creep band |v_rel| < v_s (events N' = 0, v_rel - v_s, v_rel + v_s):
   !> a lift-off is an error (`model` prefixes it), a band crossing an event
   !> (its state as x').
   subroutine record_band_hits(self, events, model, error)
      class(brake_integrator), intent(in) :: self
      type(brake_event_table), intent(inout) :: events
      character(len=*), intent(in) :: model
      type(error_type), allocatable, intent(out) :: error
      integer :: i

      do i = 1, self%locator%n_hits
         associate (hit => self%locator%hits(i))
            select case (hit%which)
            case (1)
               call fatal_error(error, model//"N' reached 0 at τ = "//rtoa(hit%t) &
                  & //': the pad lifts off the belt, outside Eq. 10', error_numerical)
               return
            case (2)   ! v_rel - v_s: falling enters the band from above
               call events%add(hit%t, merge(event_slip_to_stick, event_stick_to_slip, &
                  & hit%direction == event_falling), self%physical(hit%y(1:4)))
            case default   ! v_rel + v_s: rising enters the band from below
               call events%add(hit%t, merge(event_slip_to_stick, event_stick_to_slip, &
                  & hit%direction == event_rising), self%physical(hit%y(1:4)))
            end select
         end associate
      end do
   end subroutine record_band_hits

end module friction_brake_integrator
