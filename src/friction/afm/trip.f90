!> What a trip of the support records and where it goes, for every trip
!> kind alike.
!>
!> Line j (0-based) runs along the scan direction at the offset
!> t_j = j * width / (ny - 1) across it (the direction turned by +90°) from the origin.
!> Sample i sits at s_i = i * length / (nx - 1) along the line.  A trace trip
!> moves the support from s = -lead_in to s = length; a retrace trip from
!> s = length + lead_in back to 0; samples are stored by i either way, so
!> trace and retrace share the support_x axis.  Each trip starts with the tip
!> at the support and at rest (paper §3.1, §5.1).
!>
!> Here: the quantities a sample records and their fill from the tip's
!> state (trip_record), the support's path of one trip (trip_path), the
!> slips seen at a temperature (slip_list), a line over its realizations
!> (line_record), and the contact checks of a tip over a lattice sum.
module friction_afm_trip
   use friction_kinds, only: wp, ev_per_angstrom_to_nn
   use friction_error, only: error_type, fatal_error, error_input
   use friction_afm_config, only: afm_config
   use friction_afm_tip, only: afm_tip, find_height
   use friction_surface_lennard_jones, only: lj_potential
   use friction_strings, only: rtoa, itoa, bytes_text, fixed_text
   use friction_files, only: available_memory
   use friction_random, only: random_stream
   implicit none
   private

   public :: trip_record, trip_path, slip_list, line_record, start_trip, start_height, below_net
   public :: quantity_names, quantity_units, n_quantities, quantity_count
   public :: q_fx, q_fy, q_f_along, q_f_across, q_tip_x, q_tip_y, q_fz, q_tip_z, q_jumps
   public :: support_along, support_across, support_at, line_offset, slip_distance

   integer, parameter :: n_quantities = 9
   integer, parameter :: q_fx = 1, q_fy = 2, q_f_along = 3, q_f_across = 4, q_tip_x = 5, q_tip_y = 6, &
      & q_fz = 7, q_tip_z = 8, q_jumps = 9
   !> HDF5 dataset names and units of the recorded quantities; fz and tip_z
   !> only for a tip that moves in z; jumps (those of the quasistatic tip
   !> since the previous sample) only for the quasistatic model.
   character(len=*), parameter :: quantity_names(n_quantities) = [character(len=8) :: &
      & 'fx', 'fy', 'f_along', 'f_across', 'tip_x', 'tip_y', 'fz', 'tip_z', 'jumps']
   character(len=*), parameter :: quantity_units(n_quantities) = [character(len=8) :: &
      & 'nN', 'nN', 'nN', 'nN', 'angstrom', 'angstrom', 'nN', 'angstrom', '1']
   !> The jump of the tip's minimum that is a slip at a temperature, Å (below
   !> any well spacing of NaF or HOPG, above any drift of a minimum between
   !> two looks at it).
   real(wp), parameter :: slip_distance = 0.5_wp

   !> One trip's samples: values(i, q) for sample i and quantity q (output units).
   type :: trip_record
      real(wp), allocatable :: values(:, :)
   contains
      procedure :: reserve
      procedure :: put
   end type trip_record

   !> One trip of the support: line (0-based), trace when forward, the
   !> realization (0-based; -1 for the one deterministic trip at T = 0),
   !> where the support starts along the line, Å, the unit vectors along and
   !> across the scan and of the support's motion, and the support's height
   !> z_M (3D tip), Å.
   type :: trip_path
      integer :: line = 0
      logical :: forward = .true.
      integer :: realization = -1
      real(wp) :: s_start = 0.0_wp
      real(wp) :: along(3) = 0.0_wp, across(3) = 0.0_wp
      real(wp) :: motion(3) = 0.0_wp   !! the support's direction of motion
      real(wp) :: support_height = 0.0_wp
   contains
      procedure :: sample
      procedure :: sample_time
      procedure :: position
      procedure :: spring_force
      procedure :: noise
      procedure :: trip
      procedure :: label
      procedure :: where
   end type trip_path

   !> Slips in the order they happened: realization (0-based), trip (0
   !> trace, 1 retrace), support position along the line (Å, as
   !> support_along), force along the scan before the slip (nN), jump of
   !> the minimum along the support's motion and across the scan (Å); for
   !> the thermal reduced model the barrier (eV) and the rate's prefactor
   !> (1/s) of the exit taken (0 for a Langevin slip, and for a jump where
   !> the minimum vanished at a fold: no saddle, no rate).
   type :: slip_list
      integer :: n = 0
      integer, allocatable :: realization(:), trip(:)
      real(wp), allocatable :: support(:), force(:), jump(:), jump_across(:), barrier(:), prefactor(:)
   contains
      procedure :: clear => slips_clear
      procedure :: add => slips_add
      procedure :: add_jump
   end type slip_list

   !> One line over all realizations (afm_scanner's run_line): per trip the
   !> mean of every sample, values(i, q) as trip_record's, and its standard
   !> error over the realizations (NaN for one realization; 0 at T = 0, where
   !> there is one deterministic trip); the line's friction (half the
   !> difference of the mean force along on trace and retrace) and its
   !> standard error; the slips at a temperature.
   type :: line_record
      real(wp), allocatable :: trace(:, :), retrace(:, :)
      real(wp), allocatable :: trace_sem(:, :), retrace_sem(:, :)
      real(wp) :: friction = 0.0_wp, friction_sem = 0.0_wp
      type(slip_list) :: slips
   end type line_record

contains

   !> Quantities recorded for a tip moving in ndim dimensions (jumps apart).
   pure integer function quantity_count(ndim)
      integer, intent(in) :: ndim

      quantity_count = merge(q_tip_z, q_tip_y, ndim == 3)
   end function quantity_count

   !> Support position of sample i (0-based) along the line, Å.
   pure real(wp) function support_at(config, i) result(s)
      type(afm_config), intent(in) :: config
      integer, intent(in) :: i

      s = config%length * real(i, wp) / real(config%nx - 1, wp)
   end function support_at

   !> Offset of line j (0-based) across the scan, Å.
   pure real(wp) function line_offset(config, j) result(t)
      type(afm_config), intent(in) :: config
      integer, intent(in) :: j

      t = 0.0_wp
      if (config%ny > 1) t = config%width * real(j, wp) / real(config%ny - 1, wp)
   end function line_offset

   !> Support positions along the line, Å.
   pure function support_along(config) result(s)
      type(afm_config), intent(in) :: config
      real(wp), allocatable :: s(:)
      integer :: i

      allocate (s(config%nx))
      do i = 1, config%nx
         s(i) = support_at(config, i - 1)
      end do
   end function support_along

   !> Offsets of the lines across the scan, Å.
   pure function support_across(config) result(t)
      type(afm_config), intent(in) :: config
      real(wp), allocatable :: t(:)
      integer :: j

      allocate (t(config%ny))
      do j = 1, config%ny
         t(j) = line_offset(config, j - 1)
      end do
   end function support_across

   !> The path of a trip along line j (0-based), trace when forward, with
   !> the tip's support set on it: from the start of the trip at the
   !> scan's speed.  `realization` at a temperature; `support_height` for a
   !> 3D tip (start_height).
   function start_trip(config, tip, j, forward, realization, support_height) result(path)
      type(afm_config), intent(in) :: config
      type(afm_tip), intent(inout) :: tip
      integer, intent(in) :: j
      logical, intent(in) :: forward
      integer, intent(in), optional :: realization
      real(wp), intent(in), optional :: support_height
      type(trip_path) :: path
      real(wp) :: line_start(3)

      path%line = j
      path%forward = forward
      if (present(realization)) path%realization = realization
      if (present(support_height)) path%support_height = support_height
      path%along = config%scan_direction()
      path%across = config%across_direction()
      line_start = [config%origin_x, config%origin_y, 0.0_wp] + line_offset(config, j) * path%across
      if (forward) then
         path%s_start = -config%lead_in
         tip%support_velocity = config%velocity * path%along
      else
         path%s_start = config%length + config%lead_in
         tip%support_velocity = -config%velocity * path%along
      end if
      tip%support_start = line_start + path%s_start * path%along
      path%motion = tip%support_velocity / config%velocity
   end function start_trip

   !> The index i (1-based) of the trip's k-th sample: samples are stored
   !> by their place on the line, whichever way the support goes.
   pure integer function sample(self, config, k) result(i)
      class(trip_path), intent(in) :: self
      type(afm_config), intent(in) :: config
      integer, intent(in) :: k

      i = merge(k, config%nx + 1 - k, self%forward)
   end function sample

   !> The support time of sample i (1-based), s.
   pure real(wp) function sample_time(self, config, i) result(t)
      class(trip_path), intent(in) :: self
      type(afm_config), intent(in) :: config
      integer, intent(in) :: i

      t = abs(support_at(config, i - 1) - self%s_start) / config%velocity
   end function sample_time

   !> The support's position along the line at support time t, Å (as support_along).
   pure real(wp) function position(self, config, t) result(s)
      class(trip_path), intent(in) :: self
      type(afm_config), intent(in) :: config
      real(wp), intent(in) :: t

      s = merge(self%s_start + config%velocity * t, self%s_start - config%velocity * t, self%forward)
   end function position

   !> The spring's force along the scan on the tip at displacement u, nN.
   pure real(wp) function spring_force(self, tip, u) result(force)
      class(trip_path), intent(in) :: self
      type(afm_tip), intent(in) :: tip
      real(wp), intent(in) :: u(:)
      integer :: nd

      nd = tip%ndim
      force = -dot_product(tip%spring(1:nd) * u(1:nd), self%along(1:nd)) * ev_per_angstrom_to_nn
   end function spring_force

   !> The trip's noise at a temperature: the random stream of (seed, line,
   !> trip, realization), so that a trip's samples depend on nothing else
   !> (not on the ranks nor on the order of the lines).
   subroutine noise(self, config, stream, error)
      class(trip_path), intent(in) :: self
      type(afm_config), intent(in) :: config
      type(random_stream), intent(inout) :: stream
      type(error_type), allocatable, intent(out) :: error

      call stream%init(config%thermal%seed, self%line, self%trip(), self%realization, error)
   end subroutine noise

   !> The trip's number in its random stream and its slips: 0 trace, 1 retrace.
   pure integer function trip(self)
      class(trip_path), intent(in) :: self

      trip = merge(0, 1, self%forward)
   end function trip

   !> ' (line j trace' or retrace, and the realization at a temperature.
   function label(self) result(text)
      class(trip_path), intent(in) :: self
      character(len=:), allocatable :: text

      text = ' (line '//itoa(self%line)//trim(merge(' trace  ', ' retrace', self%forward))
      if (self%realization >= 0) text = text//', realization '//itoa(self%realization)
   end function label

   !> Where in the trip an error happened, for its message: the label and
   !> the support's travel at support time t.
   function where(self, config, t) result(text)
      class(trip_path), intent(in) :: self
      type(afm_config), intent(in) :: config
      real(wp), intent(in) :: t
      character(len=:), allocatable :: text

      text = self%label()//', support at '//fixed_text(config%velocity * t, 4)//' Å into the trip)'
   end function where

   !> The record of nx samples, unless it has one already; an error stating
   !> the memory it needs when this machine has not that much available.
   subroutine reserve(self, nx, error)
      class(trip_record), intent(inout) :: self
      integer, intent(in) :: nx
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: needed, available
      integer :: stat

      if (allocated(self%values)) return
      needed = 8.0_wp * real(nx, wp) * n_quantities
      available = available_memory()
      stat = 0
      if (.not. (available > 0.0_wp .and. needed > available)) allocate (self%values(nx, n_quantities), stat=stat)
      if (stat /= 0 .or. (available > 0.0_wp .and. needed > available)) call fatal_error(error, &
         & 'one scan line of '//itoa(nx)//' points needs '//bytes_text(needed)//' of memory, more than this ' &
         & //'machine has available ('//bytes_text(max(available, 0.0_wp))//'): use fewer points (&scan nx)', &
         & error_input)
   end subroutine reserve

   !> Sample i of the trip `path`: the spring's force on the tip and the
   !> tip's position at support time t with displacement u, and the jumps
   !> since the previous sample.  An error when a 3D tip is below the layer
   !> of atoms.
   subroutine put(self, i, tip, config, path, t, u, jumps, error)
      class(trip_record), intent(inout) :: self
      integer, intent(in) :: i
      type(afm_tip), intent(in) :: tip
      type(afm_config), intent(in) :: config
      type(trip_path), intent(in) :: path
      real(wp), intent(in) :: t, u(:)
      integer, intent(in) :: jumps
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: force(3), tip_r(3)

      force = tip%lateral_force(u) * ev_per_angstrom_to_nn
      tip_r = tip%tip_position(t, u)
      self%values(i, q_fx) = force(1)
      self%values(i, q_fy) = force(2)
      self%values(i, q_f_along) = dot_product(force, path%along)
      self%values(i, q_f_across) = dot_product(force, path%across)
      self%values(i, q_tip_x) = tip_r(1)
      self%values(i, q_tip_y) = tip_r(2)
      self%values(i, q_fz) = force(3)
      self%values(i, q_tip_z) = tip_r(3)
      self%values(i, q_jumps) = real(jumps, wp)
      if (tip%ndim /= 3) return
      ! (The message is built only when it is needed: a sample must not format numbers.)
      if (below_net(tip, tip_r)) call fatal_error(error, 'the tip went below the layer of atoms at (' &
         & //rtoa(tip_r(1))//', '//rtoa(tip_r(2))//', '//rtoa(tip_r(3))//') Å'//path%label() &
         & //'): off the edge of the net, or pressed through it by the load (support_z = ' &
         & //rtoa(config%support_z)//' Å); scan over the net, or raise support_z', error_input)
   end subroutine put

   !> The tip's start in z (3D tip) on the trip's line, the support's path
   !> set: the support at its height, the tip at its static equilibrium
   !> under it; returns u_z = z - z_M.  An error when the load presses the
   !> tip into the layer of atoms.
   subroutine start_height(tip, config, path, u_z, error)
      type(afm_tip), intent(inout) :: tip
      type(afm_config), intent(in) :: config
      type(trip_path), intent(in) :: path
      real(wp), intent(out) :: u_z
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: z_start

      u_z = 0.0_wp
      tip%support_start(3) = path%support_height
      call find_height(tip, tip%support_start, tip%spring(3), z_start, error)
      if (allocated(error)) return
      if (below_net(tip, [tip%support_start(1:2), z_start])) call fatal_error(error, 'at the start of line ' &
         & //itoa(path%line)//' the load presses the tip into the layer of atoms (support_z = ' &
         & //rtoa(config%support_z)//' Å from the contact height, kz = '//rtoa(config%kz) &
         & //' N/m): raise support_z', error_input)
      if (allocated(error)) return
      u_z = z_start - path%support_height
   end subroutine start_height

   !> For a tip over a lattice sum: whether the tip at `r` is not above the
   !> atoms under it, i.e. less than half the smallest σ above the highest
   !> atom within 2 σ_max laterally (the caller's error, bad input).  A root
   !> of the force balance in the plane of the atoms (a sparse net, tiny σ or
   !> a) or a tip pushed through the layer is not a contact.
   logical function below_net(tip, r)
      type(afm_tip), intent(in) :: tip
      real(wp), intent(in) :: r(3)
      real(wp) :: top, sigma_min

      below_net = .false.
      select type (p => tip%potential)
      type is (lj_potential)
         call p%highest_near(r(1:2), 2.0_wp * maxval(p%sigma), top, sigma_min)
         if (top > -huge(1.0_wp) .and. .not. (r(3) > top + 0.5_wp * sigma_min)) below_net = .true.
         if (top == -huge(1.0_wp) .and. r(3) < 0.5_wp * sigma_min + minval(p%atoms%position(3, :))) &
            & below_net = .true.
      end select
   end function below_net

   subroutine slips_clear(self)
      class(slip_list), intent(inout) :: self

      self%n = 0
   end subroutine slips_clear

   !> A slip on the trip `path` with the support at `support` (Å along the
   !> line) and the force along the scan `force` (nN) before it: the
   !> minimum's move `jump` (Å) resolved along the support's motion and
   !> across the scan.
   subroutine add_jump(self, path, support, force, jump, barrier, prefactor)
      class(slip_list), intent(inout) :: self
      type(trip_path), intent(in) :: path
      real(wp), intent(in) :: support, force, jump(3)
      !> the reduced model's barrier (eV) and prefactor (1/s) of the exit taken
      real(wp), intent(in), optional :: barrier, prefactor

      call self%add(path%realization, path%trip(), support, force, dot_product(jump, path%motion), &
         & dot_product(jump, path%across), barrier, prefactor)
   end subroutine add_jump

   subroutine slips_add(self, realization, trip, support, force, jump, jump_across, barrier, prefactor)
      class(slip_list), intent(inout) :: self
      integer, intent(in) :: realization, trip
      real(wp), intent(in) :: support, force, jump, jump_across
      real(wp), intent(in), optional :: barrier, prefactor
      integer :: room

      if (.not. allocated(self%realization)) then
         allocate (self%realization(16), self%trip(16), self%support(16), self%force(16), self%jump(16), &
            & self%jump_across(16), self%barrier(16), self%prefactor(16))
      end if
      if (self%n == size(self%realization)) then
         ! Twice the room, the entries kept.
         room = size(self%realization)
         self%realization = [self%realization, spread(0, 1, room)]
         self%trip = [self%trip, spread(0, 1, room)]
         self%support = [self%support, spread(0.0_wp, 1, room)]
         self%force = [self%force, spread(0.0_wp, 1, room)]
         self%jump = [self%jump, spread(0.0_wp, 1, room)]
         self%jump_across = [self%jump_across, spread(0.0_wp, 1, room)]
         self%barrier = [self%barrier, spread(0.0_wp, 1, room)]
         self%prefactor = [self%prefactor, spread(0.0_wp, 1, room)]
      end if
      self%n = self%n + 1
      self%realization(self%n) = realization
      self%trip(self%n) = trip
      self%support(self%n) = support
      self%force(self%n) = force
      self%jump(self%n) = jump
      self%jump_across(self%n) = jump_across
      self%barrier(self%n) = 0.0_wp
      self%prefactor(self%n) = 0.0_wp
      if (present(barrier)) self%barrier(self%n) = barrier
      if (present(prefactor)) self%prefactor(self%n) = prefactor
   end subroutine slips_add

end module friction_afm_trip
