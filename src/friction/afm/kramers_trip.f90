!> The thermal reduced model's trips (&thermal model = 'kramers'): the tip
!> sits in a minimum of its total energy E (surface and springs) and leaves
!> it over one of the first-order saddles ahead (see start_exits), each at
!> its Kramers–Langer rate r_s(t), whose prefactor is the tip model's:
!> Kramers' moderate-to-strong friction rate for the inertial tip,
!> Smoluchowski's for the overdamped one.  As the support moves the
!> barriers fall and the rates grow.  Every exit has its own clock: it
!> fires when its ∫ r_s dt reaches an exponential variate of its own
!> (hazard_advance); the first to fire is the jump (competing independent
!> clocks: the total rate is Σ r_s, and an exit is taken with probability
!> r_s/Σ r_s).  An exit also fires, at once, where its barrier has fallen
!> below barrier_floor k_B T or the minimum has vanished at a fold: there
!> the rate formula stops holding, and escape takes of the order of the
!> inverse attempt frequency, during which a slow support does not move.
!> The tip lands in the minimum past the saddle (jump_landing).  Jumps
!> back, over the saddles behind, are exits like the others.
!>
!> The exits are searched after every jump.  Where no saddle is found (the
!> search gives up on barriers of ~1 eV on NaF, e^-40 at 300 K) the minimum
!> is followed for search_distance of support travel with no jump and
!> searched again, with new variates (exponential clocks have no memory, so
!> a new start is exact); if the minimum vanished meanwhile, the tip's
!> descent into the next one is the jump, as in the quasistatic model.  A
!> saddle lost while its barrier is still high (it merges with another
!> stationary point) starts a new search there.  A sample records the tip
!> in its minimum: the force -k u_min is the mean over the well's thermal
!> spread up to O(k_B T) anharmonic terms.  Slips: every jump, with the
!> support where it happened, the force before it, the move of the
!> minimum, and the barrier and rate prefactor of the exit taken.
module friction_afm_kramers_trip
   use friction_kinds, only: wp, i8, pi
   use friction_error, only: error_type, fatal_error, error_numerical, error_interrupted
   use friction_random, only: random_stream
   use friction_afm_config, only: afm_config
   use friction_afm_tip, only: afm_tip
   use friction_afm_langevin, only: boltzmann
   use friction_afm_kramers, only: find_minimum, hazard_path, hazard_start, hazard_advance, jump_landing, &
      & hazard_running, hazard_low_barrier, hazard_paused, kmc_barrier_floor
   use friction_afm_quasistatic, only: landing_distance
   use friction_afm_trip, only: trip_record, trip_path, slip_list, start_trip, slip_distance
   use friction_afm_guard, only: trip_guard
   use friction_strings, only: rtoa, itoa
   implicit none
   private

   public :: kramers_trip

   !> The exits searched from a minimum: along the support's motion and
   !> against it, each also turned by ±exit_angle, rad (40°, between the
   !> motion and the diagonal saddles of a square lattice); the support
   !> travel between two searches, Å (a tenth of NaF's shortest well
   !> spacing); the barrier, in k_B T, below which an exit fires at once:
   !> friction_afm_kramers' kmc_barrier_floor (1 k_B T, down to which the
   !> Kramers rate of a cubic barrier holds within 10 %).
   integer, parameter :: n_exits = 6
   real(wp), parameter :: exit_angle = 40.0_wp * pi / 180.0_wp, search_distance = 0.1_wp
   real(wp), parameter :: barrier_floor = kmc_barrier_floor
   !> Searches allowed between two samples before the trip is reported as stuck.
   integer, parameter :: max_searches = 100000

   !> The thermal reduced model's trips of one tip.
   type :: kramers_trip
      integer(i8) :: steps = 0   !! steps along the paths of all trips so far
   contains
      procedure :: run
      procedure :: escape_hazards
      procedure :: trip_cost
   end type kramers_trip

contains

   !> The trip `path` (start_trip has set the tip's support on it) with the
   !> random stream of its realization into `record`; its slips appended
   !> to `slips` when given.
   subroutine run(self, tip, config, guard, path, record, error, slips, jump_hazards)
      class(kramers_trip), intent(inout) :: self
      type(afm_tip), intent(inout) :: tip
      type(afm_config), intent(in) :: config
      type(trip_guard), intent(inout) :: guard
      type(trip_path), intent(in) :: path
      type(trip_record), intent(inout) :: record
      type(error_type), allocatable, intent(out) :: error
      type(slip_list), intent(inout), optional :: slips
      !> A probe (see escape_hazards): no clock fires, every jump comes at
      !> the floor or a fold, and for each the hazard ∫ r dt all exits
      !> accumulated since the previous jump is listed here.
      real(wp), allocatable, intent(out), optional :: jump_hazards(:)
      type(random_stream) :: stream
      type(hazard_path) :: exits(n_exits)
      real(wp) :: targets(n_exits), u_cur(3), u_next(3), t_cur, t_end, temperature, carried
      logical :: active(n_exits), probing
      integer :: nd

      nd = tip%ndim
      temperature = config%thermal%temperature
      probing = present(jump_hazards)
      carried = 0.0_wp
      if (probing) allocate (jump_hazards(0))
      call record%reserve(config%nx, error)
      if (.not. allocated(error)) call path%noise(config, stream, error)
      if (.not. allocated(error)) call samples()
      call stream%free()

   contains

      !> The trip's samples from its stream.
      subroutine samples()
         !> support time of the last search; of the next, when an exit was dropped
         real(wp) :: t_search, t_research, u_before(3), t_sample, t_event, t_first
         logical :: need_search
         integer(i8) :: now
         integer :: i, k, status, searches, p, first

         ! From the support, into the minimum it relaxes to.
         u_cur = 0.0_wp
         u_next = 0.0_wp
         t_cur = 0.0_wp
         call find_minimum(tip, t_cur, u_next(1:nd), u_cur(1:nd), error)
         need_search = .true.
         t_search = t_cur
         t_research = huge(1.0_wp)
         do k = 1, config%nx
            i = path%sample(config, k)
            t_sample = path%sample_time(config, i)
            searches = 0
            do while (.not. allocated(error))
               if (.not. (t_cur < t_sample)) exit
               if (need_search) then
                  searches = searches + 1
                  if (searches > max_searches) then
                     call fatal_error(error, 'kramers: more than '//itoa(max_searches)//' searches for exits ' &
                        & //'between two samples at t = '//rtoa(t_cur)//' s', error_numerical)
                     exit
                  end if
                  call start_exits()
                  t_search = t_cur
                  t_research = huge(1.0_wp)
                  need_search = .not. any(active)
                  if (need_search) then
                     t_end = min(t_sample, t_cur + search_distance / config%velocity)
                     if (t_sample - t_end <= 1.0e-9_wp * (t_end - t_cur)) t_end = t_sample
                     call follow_minimum()
                     cycle
                  end if
               end if
               call guard%check('kramers', t_cur, error)
               if (allocated(error)) exit
               if (.not. any(active)) then
                  ! Every exit dropped (below): the minimum alone up to the next search.
                  t_end = min(t_sample, max(t_research, t_cur))
                  u_before = u_cur
                  call follow_minimum()
                  if (allocated(error)) exit
                  need_search = t_cur < t_sample .or. t_research <= t_sample &
                     & .or. norm2(u_cur(1:nd) - u_before(1:nd)) > slip_distance
                  cycle
               end if
               if (t_research <= t_cur) then
                  need_search = .true.
                  cycle
               end if
               ! Every clock on to the sample (or the search due) or to the first event so far.
               t_first = min(t_sample, t_research)
               first = 0
               do p = 1, n_exits
                  if (.not. active(p)) cycle
                  do
                     call system_clock(now)
                     call hazard_advance(tip, exits(p), t_first, targets(p), status, t_event, error, &
                        & barrier_floor=barrier_floor, pause_at=guard%next_look(now))
                     self%steps = self%steps + exits(p)%steps
                     exits(p)%steps = 0
                     if (allocated(error) .or. status /= hazard_paused) exit
                     call guard%check('kramers', exits(p)%t, error)
                     if (allocated(error)) exit
                  end do
                  if (allocated(error)) exit
                  if (status == hazard_running) cycle
                  if (status == hazard_low_barrier .and. exits(p)%barrier > 1.001_wp * barrier_floor &
                     & * boltzmann * temperature .and. .not. (exits(p)%t > t_search)) then
                     ! A saddle lost where it was found: at its own fold, where it
                     ! merges with the minimum beyond it (a search from here finds
                     ! it again, lost again at once).  Dropped; the exits are
                     ! searched again search_distance of support travel on.
                     active(p) = .false.
                     t_research = min(t_research, t_search + search_distance / config%velocity)
                     cycle
                  end if
                  first = p
                  t_first = t_event
                  ! A saddle lost, not overcome: a new search from there.
                  if (status == hazard_low_barrier .and. exits(p)%barrier > 1.001_wp * barrier_floor &
                     & * boltzmann * temperature) first = -p
               end do
               if (allocated(error)) exit
               if (first == 0 .and. .not. any(active)) cycle
               if (first > 0) then
                  if (probing) call note_jump(sum(exits%hazard, mask=active))
                  call jump(exits(first), t_first)
                  need_search = .true.
               else if (first < 0) then
                  if (probing) carried = carried + sum(exits%hazard, mask=active)
                  t_cur = exits(-first)%t
                  u_cur = exits(-first)%u_min
                  need_search = .true.
               else
                  t_cur = t_first
                  u_cur = exits(findloc(active, .true., 1))%u_min
                  if (t_first < t_sample) need_search = .true.
               end if
            end do
            if (.not. allocated(error)) call guard%check('kramers', t_cur, error)
            if (allocated(error)) then
               error%message = error%message//path%where(config, t_cur)
               return
            end if
            call record%put(i, tip, config, path, t_sample, u_cur, 0, error)
            if (allocated(error)) return
         end do
      end subroutine samples

      !> The exits from the minimum u_cur at support time t_cur: the saddles
      !> found from it along the support's motion and against it, each also
      !> turned by ±exit_angle in the scan plane (on a line of symmetry the
      !> saddle ahead is a pair, and the search along the motion alone stops
      !> on the ridge between them; off it the pair's barriers differ),
      !> without repeats; each with its clock's variate, drawn in order.
      !> The exits behind are the back jumps, which bring the mean force to
      !> zero as v -> 0 (detailed balance between neighbouring wells).
      subroutine start_exits()
         type(error_type), allocatable :: search_error
         real(wp) :: d(3), normal(3)
         integer :: q, m, found

         active = .false.
         found = 0
         normal = [-path%motion(2), path%motion(1), 0.0_wp]
         do q = 1, n_exits
            ! Ahead (1-3) and behind (4-6).
            d = merge(1.0_wp, -1.0_wp, q <= 3) * path%motion
            if (mod(q, 3) == 2) d = d + tan(exit_angle) * normal
            if (mod(q, 3) == 0) d = d - tan(exit_angle) * normal
            call hazard_start(tip, temperature, t_cur, u_cur(1:nd), exits(found + 1), search_error, &
               & direction=d(1:nd))
            if (allocated(search_error)) then
               deallocate (search_error)
               cycle
            end if
            if (any([(norm2(exits(m)%u_saddle(1:nd) - exits(found + 1)%u_saddle(1:nd)) <= &
               & landing_distance, m = 1, found)])) cycle
            found = found + 1
            active(found) = .true.
         end do
         ! (A probe draws the variates too, so that its stream is the trip's.)
         do q = 1, found
            targets(q) = stream%exponential()
            if (probing) targets(q) = huge(1.0_wp)
         end do
      end subroutine start_exits

      !> No exit found: the minimum followed from t_cur to t_end; a jump if
      !> it vanished meanwhile (the descent lands elsewhere).
      subroutine follow_minimum()
         call find_minimum(tip, t_end, u_cur(1:nd), u_next(1:nd), error)
         if (allocated(error)) return
         if (norm2(u_next(1:nd) - u_cur(1:nd)) > slip_distance) then
            call add_slip(t_end, u_cur, u_next)
            if (probing) call note_jump(0.0_wp)
         end if
         u_cur = u_next
         t_cur = t_end
      end subroutine follow_minimum

      !> A probe's jump after `hazard` on the exits since the last search.
      subroutine note_jump(hazard)
         real(wp), intent(in) :: hazard

         jump_hazards = [jump_hazards, carried + hazard]
         carried = 0.0_wp
      end subroutine note_jump

      !> The jump at support time te from the exit's minimum over its saddle.
      subroutine jump(taken, te)
         type(hazard_path), intent(in) :: taken
         real(wp), intent(in) :: te

         call jump_landing(tip, te, taken%u_min(1:nd), taken%u_saddle(1:nd), u_next(1:nd), error)
         if (allocated(error)) return
         ! (The prefactor from ln r = ln prefactor - ΔE/k_B T at the jump.)
         call add_slip(te, taken%u_min, u_next, taken%barrier, &
            & exp(taken%log_rate + taken%barrier / (boltzmann * temperature)))
         u_cur = u_next
         t_cur = te
      end subroutine jump

      !> A slip at support time te from the minimum `before` to `after`, over
      !> the barrier (eV) with the prefactor (1/s) of the exit taken (none: 0,
      !> the minimum vanished at a fold).
      subroutine add_slip(te, before, after, barrier, prefactor)
         real(wp), intent(in) :: te, before(3), after(3)
         real(wp), intent(in), optional :: barrier, prefactor

         if (present(slips)) call slips%add_jump(path, path%position(config, te), path%spring_force(tip, before), &
            & after - before, barrier, prefactor)
      end subroutine add_slip

   end subroutine run

   !> Where the thermal reduced model holds (friction_afm_validity): line
   !> 0's trace with clocks that never fire, so that every jump comes where
   !> an exit's barrier reaches the floor (or at a fold).  For each jump,
   !> the hazard H = ∫ Σ r dt its exits accumulated before it: at this
   !> velocity the model forces that jump at the floor with probability
   !> exp(-H) (no clock fired before), and H scales as 1/v (the path of the
   !> minimum and the saddles does not depend on v).
   subroutine escape_hazards(self, tip, config, guard, hazards, error)
      class(kramers_trip), intent(inout) :: self
      type(afm_tip), intent(inout) :: tip
      type(afm_config), intent(in) :: config
      type(trip_guard), intent(inout) :: guard
      real(wp), allocatable, intent(out) :: hazards(:)
      type(error_type), allocatable, intent(out) :: error
      type(trip_record) :: record

      call self%run(tip, config, guard, start_trip(config, tip, 0, .true., 0), record, error, jump_hazards=hazards)
   end subroutine escape_hazards

   !> The computing time of one trip, s, estimated from a sample: line 0's
   !> trace (realization 0) over the support travel `travel` Å (the lead-in
   !> and one period of the surface along the scan: the jumps, where the
   !> time goes, come once per period), its time scaled to the whole trip.
   !> Where the jumps back and forth (the thermolubric regime, their number
   !> growing as 1/(v c)) make the sample longer than `budget` s of wall
   !> time, it ends there and the estimate, scaled from the travel covered,
   !> is a lower bound (`lower`): the part of a period before its slip costs
   !> least.  0 when the sample fails.
   function trip_cost(self, tip, config, guard, travel, budget, lower) result(cost)
      class(kramers_trip), intent(inout) :: self
      type(afm_tip), intent(inout) :: tip
      type(afm_config), intent(in) :: config
      type(trip_guard), intent(inout) :: guard
      real(wp), intent(in) :: travel, budget
      logical, intent(out) :: lower
      real(wp) :: cost
      type(trip_record) :: record
      type(error_type), allocatable :: error
      integer(i8) :: start, finish
      real(wp) :: trip

      cost = 0.0_wp
      lower = .false.
      trip = (config%length + config%lead_in) / config%velocity
      call system_clock(start)
      guard%sample_end = start + int(budget * guard%clock_rate, i8)
      guard%sample_stop = min(travel / config%velocity, trip)
      guard%reached = 0.0_wp
      call self%run(tip, config, guard, start_trip(config, tip, 0, .true., 0), record, error)
      guard%sample_end = 0
      call system_clock(finish)
      cost = real(finish - start, wp) / guard%clock_rate
      if (.not. allocated(error)) return
      if (error%stat /= error_interrupted .or. .not. (guard%reached > 0.0_wp)) then
         cost = 0.0_wp
         return
      end if
      lower = guard%reached < guard%sample_stop
      cost = cost * trip / guard%reached
   end function trip_cost

end module friction_afm_kramers_trip
