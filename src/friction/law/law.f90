!> A friction law as one abstract type (docs/laws.md): the force a sliding
!> contact resists with, from the sliding velocity v (m/s), the normal load
!> (N), the law's internal states z (a bristle's deflection, a contact's
!> age) and, where the law is set-valued at v = 0, the force the rest of the
!> mechanism applies.  The states' derivatives join a mechanism's equations
!> of motion.  Only the factory (factory.f90) names the concrete laws.
!>
!> Sign convention: F resists the motion, it has the sign of v, and the body
!> obeys m a = applied - F.
module friction_law
   use friction_kinds, only: wp
   use friction_error, only: error_type
   use friction_checks, only: config_checker
   use friction_law_settings, only: law_settings, max_gms_elements
   implicit none
   private

   public :: sliding_law, max_law_states, difference_partials, exact_stick_force
   public :: in_band, band_edge_velocity, band_hold_limit, sliding_at_edge

   !> The most internal states a law has (the ODE bridge's room): the
   !> Generalized Maxwell-Slip law's elements.
   integer, parameter :: max_law_states = max_gms_elements

   type, abstract :: sliding_law
      type(law_settings) :: p   !! the &law parameters the law was made from
   contains
      !> Every parameter the law uses, the first bad one to the checker.
      procedure(check_interface), deferred :: check
      !> F(v, z, N, applied): the force that resists the motion.
      procedure(force_interface), deferred :: force
      !> How many internal states; their rates, names and units.
      procedure :: state_count
      procedure :: state_rate
      procedure :: state_name
      procedure :: state_unit
      !> A typical size of each state (the integrators' error scale).
      procedure :: state_scale
      !> The states of steady sliding at v.
      procedure :: steady_state
      !> The slip rate down to which the force goes with its logarithm (rate
      !> and state), 0 for a law whose force does not: the integrators then
      !> hold the slip rate's error below a fixed fraction of the slip rate
      !> itself down to this floor, whatever the absolute tolerance.
      procedure :: log_slip_floor
      !> The partial derivatives of F and of the states' rates (the implicit
      !> steppers' Jacobian and the tangent equations); by default from
      !> central differences, which a law overrides with its exact ones.
      procedure :: partials => difference_partials
      !> Set-valued at v = 0 (exact stick): the largest force the contact
      !> holds in stick, and the force during a slip in direction s = ±1,
      !> smooth through v = 0 so that an integrator may step a little past
      !> the end of the slip.
      procedure :: set_valued
      procedure :: static_force
      procedure :: slip_force
      !> A band |v| < half_width where the contact holds the applied force up
      !> to `limit` and at whose edges the force jumps (Karnopp's); half_width
      !> 0 for a law without one.
      procedure :: band
      !> Functions of (v, z) whose zeros are where the law's partial
      !> derivatives jump (GMS's switch bands), none by default: a tangent
      !> carried over a step must not straddle one.
      procedure :: kink_count
      procedure :: kinks
      !> What the law needs before it computes (a table read from its file).
      procedure :: prepare
   end type sliding_law

   abstract interface
      subroutine check_interface(self, c)
         import :: sliding_law, config_checker
         class(sliding_law), intent(in) :: self
         type(config_checker), intent(inout) :: c
      end subroutine check_interface

      pure real(wp) function force_interface(self, v, z, normal, applied)
         import :: sliding_law, wp
         class(sliding_law), intent(in) :: self
         real(wp), intent(in) :: v, normal, applied
         real(wp), intent(in) :: z(:)
      end function force_interface
   end interface

contains

   pure integer function state_count(self)
      class(sliding_law), intent(in) :: self

      state_count = 0
   end function state_count

   pure subroutine state_rate(self, v, z, normal, rate)
      class(sliding_law), intent(in) :: self
      real(wp), intent(in) :: v, normal
      real(wp), intent(in) :: z(:)
      real(wp), intent(out) :: rate(:)

      rate = 0.0_wp
   end subroutine state_rate

   function state_name(self, i) result(name)
      class(sliding_law), intent(in) :: self
      integer, intent(in) :: i
      character(len=:), allocatable :: name

      name = 'z'
   end function state_name

   function state_unit(self, i) result(unit)
      class(sliding_law), intent(in) :: self
      integer, intent(in) :: i
      character(len=:), allocatable :: unit

      unit = 'm'
   end function state_unit

   pure subroutine state_scale(self, scale)
      class(sliding_law), intent(in) :: self
      real(wp), intent(out) :: scale(:)

      scale = 1.0_wp
   end subroutine state_scale

   pure subroutine steady_state(self, v, normal, z)
      class(sliding_law), intent(in) :: self
      real(wp), intent(in) :: v, normal
      real(wp), intent(out) :: z(:)

      z = 0.0_wp
   end subroutine steady_state

   pure real(wp) function log_slip_floor(self)
      class(sliding_law), intent(in) :: self

      log_slip_floor = 0.0_wp
   end function log_slip_floor

   !> ∂F/∂v, ∂F/∂z, ∂F/∂applied, ∂ż/∂v, ∂ż/∂z (dgdz(i, j) = ∂ż_i/∂z_j).
   !> Central differences with steps of 1e-6 of the variable's size (or of
   !> the state's scale, and of the velocity's largest of |v| and 1e-6 m/s):
   !> errors of order 1e-12 relative for smooth laws.  Public, so that a law
   !> extending one with analytic partials can fall back on these.
   pure subroutine difference_partials(self, v, z, normal, applied, dfdv, dfdz, dfda, dgdv, dgdz)
      class(sliding_law), intent(in) :: self
      real(wp), intent(in) :: v, normal, applied
      real(wp), intent(in) :: z(:)
      real(wp), intent(out) :: dfdv, dfdz(:), dfda, dgdv(:), dgdz(:, :)
      real(wp) :: h, zp(size(z)), zm(size(z)), rp(size(z)), rm(size(z)), scale(size(z))
      integer :: j

      h = 1.0e-6_wp * max(abs(v), 1.0e-6_wp)
      dfdv = (self%force(v + h, z, normal, applied) - self%force(v - h, z, normal, applied)) / (2.0_wp * h)
      call self%state_rate(v + h, z, normal, rp)
      call self%state_rate(v - h, z, normal, rm)
      dgdv = (rp - rm) / (2.0_wp * h)
      h = 1.0e-6_wp * max(abs(applied), 1.0e-6_wp)
      dfda = (self%force(v, z, normal, applied + h) - self%force(v, z, normal, applied - h)) / (2.0_wp * h)
      call self%state_scale(scale)
      do j = 1, size(z)
         h = 1.0e-6_wp * max(abs(z(j)), scale(j))
         zp = z
         zm = z
         zp(j) = z(j) + h
         zm(j) = z(j) - h
         dfdz(j) = (self%force(v, zp, normal, applied) - self%force(v, zm, normal, applied)) / (2.0_wp * h)
         call self%state_rate(v, zp, normal, rp)
         call self%state_rate(v, zm, normal, rm)
         dgdz(:, j) = (rp - rm) / (2.0_wp * h)
      end do
   end subroutine difference_partials

   pure logical function set_valued(self)
      class(sliding_law), intent(in) :: self

      set_valued = .false.
   end function set_valued

   !> The force of a set-valued law with exact stick: at rest the applied
   !> force, up to the static limit; sliding, the slip force.
   pure real(wp) function exact_stick_force(self, v, z, normal, applied) result(force)
      class(sliding_law), intent(in) :: self
      real(wp), intent(in) :: v, normal, applied
      real(wp), intent(in) :: z(:)
      real(wp) :: limit

      if (v == 0.0_wp) then
         limit = self%static_force(normal)
         force = max(-limit, min(limit, applied))
      else
         force = self%slip_force(v, z, normal, sign(1.0_wp, v))
      end if
   end function exact_stick_force

   pure real(wp) function static_force(self, normal)
      class(sliding_law), intent(in) :: self
      real(wp), intent(in) :: normal

      static_force = huge(1.0_wp)
   end function static_force

   pure subroutine band(self, half_width, limit)
      class(sliding_law), intent(in) :: self
      real(wp), intent(out) :: half_width, limit

      half_width = 0.0_wp
      limit = 0.0_wp
   end subroutine band

   pure integer function kink_count(self)
      class(sliding_law), intent(in) :: self

      kink_count = 0
   end function kink_count

   pure subroutine kinks(self, v, z, normal, g)
      class(sliding_law), intent(in) :: self
      real(wp), intent(in) :: v, normal
      real(wp), intent(in) :: z(:)
      real(wp), intent(out) :: g(:)
   end subroutine kinks

   !> The largest pull a hold at a band law's edge keeps: its own limit F_s,
   !> or the force just outside the edge when that is larger.  The pull
   !> between the two drives the block out of the band and the slip force
   !> outside pushes it back: Filippov's convex combination of the two
   !> fields keeps it on the edge with the friction equal to the pull, a
   !> hold like any other (a sliding mode; docs/laws.md, Karnopp).  0 for a
   !> law without a band.
   pure real(wp) function band_hold_limit(law, normal) result(hold)
      class(sliding_law), intent(in) :: law
      real(wp), intent(in) :: normal
      real(wp) :: half_width, limit, none(0)

      call law%band(half_width, limit)
      hold = 0.0_wp
      if (half_width > 0.0_wp) hold = max(limit, abs(law%force(half_width, none, normal, 0.0_wp)))
   end function band_hold_limit

   !> Whether a pull held at the band's edge of sign s is the sliding mode's
   !> (beyond the band's own limit, outwards): the friction is then the pull
   !> by Filippov's rule, not the band's clip of it.
   pure logical function sliding_at_edge(s, pull, limit)
      real(wp), intent(in) :: s, pull, limit

      sliding_at_edge = s * pull > limit
   end function sliding_at_edge

   !> Whether a mechanism's velocity v is inside a band law's band about the
   !> surface's velocity `centre`, as the law decides it: |(v - centre) scale|
   !> < half_width, with `scale` the law's velocity unit per the mechanism's
   !> (1 when both are SI).
   pure logical function in_band(v, centre, half_width, scale)
      real(wp), intent(in) :: v, centre, half_width, scale

      in_band = abs((v - centre) * scale) < half_width
   end function in_band

   !> The mechanism's velocity closest to the band's edge of sign s, on its
   !> inner side (in_band) or its outer side: where a block entering the band
   !> is put, and where it leaves from at the end of a hold, the same to the
   !> last bit on every pass (docs/chaos.md, "Karnopp's band").
   pure real(wp) function band_edge_velocity(centre, half_width, scale, s, inner) result(v)
      real(wp), intent(in) :: centre, half_width, scale, s
      logical, intent(in) :: inner
      integer :: k

      v = centre + s * half_width / scale
      ! By units of v's last place, which reach the edge in a step or two unless v is far below the
      ! centre's size: an edge at v = 0 (a belt at ±half_width) has subnormal units, and 2^60 steps of
      ! them moved v - centre by less than its own unit (a hang).  After 64, units of the larger.
      k = 0
      if (inner) then
         do while (.not. in_band(v, centre, half_width, scale))
            k = k + 1
            if (k <= 64) then
               v = nearest(v, -s)
            else
               v = v - s * spacing(max(abs(v), abs(centre)))
            end if
         end do
      else
         do while (in_band(v, centre, half_width, scale))
            k = k + 1
            if (k <= 64) then
               v = nearest(v, s)
            else
               v = v + s * spacing(max(abs(v), abs(centre)))
            end if
         end do
      end if
   end function band_edge_velocity

   pure real(wp) function slip_force(self, v, z, normal, s)
      class(sliding_law), intent(in) :: self
      real(wp), intent(in) :: v, normal, s
      real(wp), intent(in) :: z(:)

      slip_force = self%force(v, z, normal, 0.0_wp)
   end function slip_force

   subroutine prepare(self, error)
      class(sliding_law), intent(inout) :: self
      type(error_type), allocatable, intent(out) :: error
   end subroutine prepare

end module friction_law
