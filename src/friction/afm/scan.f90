!> Scan geometry and the integration of one trip of the support.
!>
!> Line j (0-based) runs along the scan direction at the offset
!> t_j = j * width / (ny - 1) across it (the direction turned by +90°) from the origin.
!> Sample i sits at s_i = i * length / (nx - 1) along the line.  A trace trip
!> moves the support from s = -lead_in to s = length; a retrace trip from
!> s = length + lead_in back to 0; samples are stored by i either way, so
!> trace and retrace share the support_x axis.  Each trip starts with the tip
!> at the support and at rest (paper §3.1, §5.1).
module friction_afm_scan
   use friction_kinds, only: wp, i8, pi, ev_per_angstrom_to_nn
   use friction_error, only: error_type, fatal_error, error_input, error_numerical
   use friction_ode_solver, only: ode_solver, integrator_statistics
   use friction_afm_config, only: afm_config, new_tip
   use friction_afm_tip, only: afm_tip
   use friction_surface_potential, only: surface_potential
   use friction_strings, only: rtoa
   implicit none
   private

   public :: afm_scanner, trip_record, quantity_names, quantity_units, n_quantities, quantity_count
   public :: q_fx, q_fy, q_f_along, q_f_across, q_tip_x, q_tip_y, q_fz, q_tip_z
   public :: support_along, support_across, share_of

   integer, parameter :: n_quantities = 8
   integer, parameter :: q_fx = 1, q_fy = 2, q_f_along = 3, q_f_across = 4, q_tip_x = 5, q_tip_y = 6, &
      & q_fz = 7, q_tip_z = 8
   !> HDF5 dataset names and units of the recorded quantities; the last two
   !> only for a tip that moves in z.
   character(len=*), parameter :: quantity_names(n_quantities) = [character(len=8) :: &
      & 'fx', 'fy', 'f_along', 'f_across', 'tip_x', 'tip_y', 'fz', 'tip_z']
   character(len=*), parameter :: quantity_units(n_quantities) = [character(len=8) :: &
      & 'nN', 'nN', 'nN', 'nN', 'angstrom', 'angstrom', 'nN', 'angstrom']

   !> One trip's samples: values(i, q) for sample i and quantity q (output units).
   type :: trip_record
      real(wp), allocatable :: values(:, :)
   end type trip_record

   !> Integrates trips of one scene; owns one tip model and its solver.
   type :: afm_scanner
      type(afm_config) :: config
      type(afm_tip), allocatable :: tip
      type(ode_solver) :: solver
      real(wp) :: h_start = 0.0_wp
      integer(i8) :: clock_start = 0, clock_rate = 1   !! wall clock at init, for max_wall_time
      real(wp) :: contact_height = 0.0_wp   !! z0: free tip's equilibrium height at the origin, Å (3D)
      real(wp) :: support_height = 0.0_wp   !! z_M = z0 + support_z, Å (3D)
   contains
      procedure :: init
      procedure :: run_trip
      procedure :: statistics
   end type afm_scanner

contains

   !> Quantities recorded for a tip moving in ndim dimensions.
   pure integer function quantity_count(ndim)
      integer, intent(in) :: ndim

      quantity_count = merge(n_quantities, q_tip_y, ndim == 3)
   end function quantity_count

   !> Support positions along the line, Å.
   pure function support_along(config) result(s)
      type(afm_config), intent(in) :: config
      real(wp) :: s(config%nx)
      integer :: i

      s = [(config%length * real(i, wp) / real(config%nx - 1, wp), i = 0, config%nx - 1)]
   end function support_along

   !> Offsets of the lines across the scan, Å.
   pure function support_across(config) result(t)
      type(afm_config), intent(in) :: config
      real(wp) :: t(config%ny)
      integer :: j

      if (config%ny == 1) then
         t = 0.0_wp
      else
         t = [(config%width * real(j, wp) / real(config%ny - 1, wp), j = 0, config%ny - 1)]
      end if
   end function support_across

   !> A rank's share of n items, dealt round-robin: items first, first +
   !> nranks, ... (0-based), count of them.  Neighbouring lines cost alike
   !> (they cross the same rows of atoms), so dealing them out in turn
   !> balances uneven maps better than contiguous blocks (HOPG at 7°, rk8pd
   !> 1e-11: blocks left one rank idle 40 % of the run).  Each rank still
   !> writes one regular, strided hyperslab.
   pure subroutine share_of(n, nranks, rank, first, count)
      integer, intent(in) :: n, nranks, rank
      integer, intent(out) :: first, count

      first = rank
      count = max(0, (n - rank + nranks - 1) / nranks)
   end subroutine share_of

   subroutine init(self, config, potential, error)
      class(afm_scanner), intent(inout) :: self
      type(afm_config), intent(in) :: config
      class(surface_potential), intent(in) :: potential
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: sample_time, period

      self%config = config
      call system_clock(self%clock_start, self%clock_rate)
      if (allocated(self%tip)) deallocate (self%tip)
      allocate (self%tip)
      call new_tip(config, potential, self%tip)
      if (self%tip%ndim == 3) then
         ! The support's height is set from the contact of the free tip at the
         ! scan origin: z_M = z0 + support_z (support_z < 0 presses the tip).
         call find_height(self%tip, [config%origin_x, config%origin_y, 0.0_wp], 0.0_wp, &
            & self%contact_height, error)
         if (allocated(error)) return
         self%support_height = self%contact_height + config%support_z
      end if
      ! First step: a small fraction of the fastest time scale in sight.
      sample_time = config%length / real(config%nx - 1, wp) / config%velocity
      period = sample_time
      if (maxval(self%tip%spring) > 0.0_wp) &
         & period = min(period, 2.0_wp * pi * sqrt(self%tip%mass / maxval(self%tip%spring)))
      self%h_start = config%solver%h_start
      if (self%h_start <= 0.0_wp) self%h_start = 1.0e-3_wp * period
      call self%solver%init(self%tip, config%solver, self%h_start, error)
   end subroutine init

   !> One trip along line j (0-based): trace when forward, else retrace.
   subroutine run_trip(self, j, forward, record, error)
      class(afm_scanner), intent(inout) :: self
      integer, intent(in) :: j
      logical, intent(in) :: forward
      type(trip_record), intent(inout) :: record
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: along(3), across(3), line_start(3), s(self%config%nx), offset(self%config%ny)
      real(wp) :: y(6), t, t_sample, s_start, force(3), tip_r(3), z_start
      integer(i8) :: now
      integer :: i, k, nx, nd
      character(len=96) :: where

      associate (c => self%config, tip => self%tip)
         nx = c%nx
         nd = tip%ndim
         along = c%scan_direction()
         across = c%across_direction()
         s = support_along(c)
         offset = support_across(c)
         line_start = [c%origin_x, c%origin_y, 0.0_wp] + offset(j + 1) * across
         if (forward) then
            s_start = -c%lead_in
            tip%support_velocity = c%velocity * along
         else
            s_start = c%length + c%lead_in
            tip%support_velocity = -c%velocity * along
         end if
         tip%support_start = line_start + s_start * along
         ! At the support and at rest: r - r_M = 0, r' = 0; in z at the
         ! static equilibrium under the support (paper §3.1: z differs).
         y = 0.0_wp
         if (nd == 3) then
            tip%support_start(3) = self%support_height
            call find_height(tip, tip%support_start, tip%spring(3), z_start, error)
            if (allocated(error)) return
            y(3) = z_start - self%support_height
         end if
         t = 0.0_wp
         call self%solver%restart(self%h_start)
         if (.not. allocated(record%values)) allocate (record%values(nx, n_quantities))
         do k = 1, nx
            i = merge(k, nx + 1 - k, forward)
            t_sample = abs(s(i) - s_start) / c%velocity
            if (t_sample > t) call self%solver%advance(t, t_sample, y(1:2 * nd), error)
            if (.not. allocated(error) .and. c%solver%max_wall_time > 0.0_wp) then
               call system_clock(now)
               if (real(now - self%clock_start, wp) / self%clock_rate > c%solver%max_wall_time) &
                  & call fatal_error(error, trim(c%solver%method)//': max_wall_time = ' &
                  & //rtoa(c%solver%max_wall_time)//' s reached at t = '//rtoa(t)//' s', error_numerical)
            end if
            if (allocated(error)) then
               write (where, '(a, i0, a, f0.4, a)') ' (line ', j, trim(merge(' trace  ', ' retrace', forward)) &
                  & //', support at ', c%velocity * t, ' Å into the trip)'
               error%message = error%message//trim(where)
               return
            end if
            force = tip%lateral_force(y) * ev_per_angstrom_to_nn
            tip_r = tip%tip_position(t, y)
            record%values(i, q_fx) = force(1)
            record%values(i, q_fy) = force(2)
            record%values(i, q_f_along) = dot_product(force, along)
            record%values(i, q_f_across) = dot_product(force, across)
            record%values(i, q_tip_x) = tip_r(1)
            record%values(i, q_tip_y) = tip_r(2)
            record%values(i, q_fz) = force(3)
            record%values(i, q_tip_z) = tip_r(3)
         end do
      end associate
   end subroutine run_trip

   !> The height z at which the tip above (x, y) = at(1:2) is in equilibrium
   !> between the surface and a z spring of constant `spring` (eV/Å²) held
   !> at z_M = at(3): the root of g(z) = spring (z - z_M) + dV/dz.  Searched
   !> downward from 20 Å above the support or the contact, so it is the
   !> equilibrium a tip brought in from above reaches; refined by bisection
   !> to 1e-12 Å.  spring = 0 gives the free tip's contact height.
   subroutine find_height(tip, at, spring, z, error)
      type(afm_tip), intent(in) :: tip
      real(wp), intent(in) :: at(3), spring
      real(wp), intent(out) :: z
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: upper, lower, middle
      integer :: k

      upper = max(at(3), 0.0_wp) + 20.0_wp
      lower = upper
      do k = 1, 4000
         lower = upper - 0.05_wp
         if (force_balance(lower) < 0.0_wp) exit
         upper = lower
      end do
      if (force_balance(lower) >= 0.0_wp) then
         call fatal_error(error, 'no contact height found: the tip is not repelled anywhere above (' &
            & //rtoa(at(1))//', '//rtoa(at(2))//') Å; is the scan over the net?', error_input)
         return
      end if
      do k = 1, 200
         middle = 0.5_wp * (lower + upper)
         if (upper - lower < 1.0e-12_wp) exit
         if (force_balance(middle) < 0.0_wp) then
            lower = middle
         else
            upper = middle
         end if
      end do
      z = 0.5_wp * (lower + upper)

   contains

      real(wp) function force_balance(height)
         real(wp), intent(in) :: height
         real(wp) :: g(3)

         call tip%potential%gradient([at(1), at(2), height], g)
         force_balance = spring * (height - at(3)) + g(3)
      end function force_balance

   end subroutine find_height

   !> Integrator counters of all trips so far.
   function statistics(self) result(stats)
      class(afm_scanner), intent(in) :: self
      type(integrator_statistics) :: stats

      stats = self%solver%statistics()
   end function statistics

end module friction_afm_scan
