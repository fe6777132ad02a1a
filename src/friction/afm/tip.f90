!> The microscope tip on its springs, Eq. 4: for each direction i
!>   m r_i'' = k_i (r_M,i - r_i) - dV/dr_i - c_i r_i',
!> with the support r_M(t) = r_M(0) + v_M t.  The state is y = (u, r') with
!> u = r - r_M the tip's displacement from the support, of `ndim` components
!> (2 for the analytic potentials, 3 for a lattice sum).  Integrating u
!> rather than r makes the error control independent of where the scan lies
!> on the surface, and the absolute tolerance (Å) bounds the lateral force
!> error directly: |δF| <= k |δu|.  Internal units (friction_kinds): Å, eV, s.
!>
!> Reduced models (docs/physics.md, reduced tip models): `model_overdamped` drops the
!> inertia, c_i r_i' = k_i (r_M,i - r_i) - dV/dr_i, state y = u only;
!> `model_quasistatic` follows the equilibrium (friction_afm_deterministic_trip) and uses
!> the same first-order system, at a fixed support, only to relax the tip
!> into a new minimum after a jump.
module friction_afm_tip
   use friction_kinds, only: wp
   use friction_error, only: error_type, fatal_error, error_input
   use friction_strings, only: rtoa
   use friction_ode_system, only: ode_system
   use friction_surface_potential, only: surface_potential
   implicit none
   private

   public :: afm_tip, model_inertial, model_overdamped, model_quasistatic, find_height

   integer, parameter :: model_inertial = 1, model_overdamped = 2, model_quasistatic = 3

   type, extends(ode_system) :: afm_tip
      class(surface_potential), allocatable :: potential
      integer :: ndim = 2                  !! moving coordinates
      integer :: model = model_inertial    !! model_inertial: state (u, r'); else state u
      real(wp) :: mass = 0.0_wp            !! eV s²/Å²
      real(wp) :: spring(3) = 0.0_wp       !! k_x, k_y, k_z in eV/Å²
      real(wp) :: damping(3) = 0.0_wp      !! c_x, c_y, c_z in eV s/Å²
      real(wp) :: support_start(3) = 0.0_wp     !! r_M(0), Å
      real(wp) :: support_velocity(3) = 0.0_wp  !! v_M, Å/s
   contains
      procedure :: dimension
      procedure :: rhs
      procedure :: jacobian
      procedure :: support
      procedure :: lateral_force
      procedure :: tip_position
   end type afm_tip

contains

   pure function dimension(self) result(n)
      class(afm_tip), intent(in) :: self
      integer :: n

      n = merge(2 * self%ndim, self%ndim, self%model == model_inertial)
   end function dimension

   !> Support position r_M(t) in Å.
   pure function support(self, t) result(r)
      class(afm_tip), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp) :: r(3)

      r = self%support_start + self%support_velocity * t
   end function support

   !> The spring force k (r_M - r_t) = -k u on the tip in eV/Å: what the
   !> microscope measures as lateral force.
   pure function lateral_force(self, y) result(f)
      class(afm_tip), intent(in) :: self
      real(wp), intent(in) :: y(:)
      real(wp) :: f(3)
      integer :: nd

      nd = self%ndim
      f = 0.0_wp
      f(1:nd) = -self%spring(1:nd) * y(1:nd)
   end function lateral_force

   !> Tip position r = r_M(t) + u in Å.
   pure function tip_position(self, t, y) result(r)
      class(afm_tip), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: y(:)
      real(wp) :: r(3)
      integer :: nd

      nd = self%ndim
      r = self%support(t)
      r(1:nd) = r(1:nd) + y(1:nd)
   end function tip_position

   !> Eq. 4 in (u, r'): u' = r' - v_M, m r'' = -k u - dV/dr - c r'; or,
   !> without inertia, u' = (-k u - dV/dr) / c - v_M.
   !> The hot path: scalar loops, no array-valued calls.
   pure subroutine rhs(self, t, y, dydt)
      class(afm_tip), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in), contiguous :: y(:)
      real(wp), intent(out), contiguous :: dydt(:)
      real(wp) :: r(3), g(3), inverse_mass
      integer :: nd, i

      nd = self%ndim
      if (nd == 2) then
         ! One vector store: the surfaces load (x, y) as one vector, which
         ! two scalar stores could not forward from the store buffer.
         r = [self%support_start(1:2) + self%support_velocity(1:2) * t + y(1:2), 0.0_wp]
      else
         do i = 1, 3
            r(i) = self%support_start(i) + self%support_velocity(i) * t + y(i)
         end do
      end if
      call self%potential%gradient(r, g)
      if (self%model /= model_inertial) then
         do i = 1, nd
            dydt(i) = (-self%spring(i) * y(i) - g(i)) / self%damping(i) - self%support_velocity(i)
         end do
         return
      end if
      inverse_mass = 1.0_wp / self%mass
      do i = 1, nd
         dydt(i) = y(nd + i) - self%support_velocity(i)
         dydt(nd + i) = (-self%spring(i) * y(i) - g(i) - self%damping(i) * y(nd + i)) * inverse_mass
      end do
   end subroutine rhs

   !> Analytic Jacobian: the potential's Hessian H enters the velocity rows,
   !> and through r = r_M(t) + u also the explicit time dependence.
   pure subroutine jacobian(self, t, y, dfdy, dfdt)
      class(afm_tip), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: y(:)
      real(wp), intent(out) :: dfdy(:, :)
      real(wp), intent(out) :: dfdt(:)
      real(wp) :: h(3, 3)
      integer :: nd, i

      nd = self%ndim
      call self%potential%hessian(self%tip_position(t, y), h)
      dfdy = 0.0_wp
      dfdt = 0.0_wp
      if (self%model /= model_inertial) then
         do i = 1, nd
            dfdy(i, 1:nd) = -h(i, 1:nd) / self%damping(i)
            dfdy(i, i) = dfdy(i, i) - self%spring(i) / self%damping(i)
            dfdt(i) = -dot_product(h(i, 1:nd), self%support_velocity(1:nd)) / self%damping(i)
         end do
         return
      end if
      do i = 1, nd
         dfdy(i, nd + i) = 1.0_wp
         dfdy(nd + i, 1:nd) = -h(i, 1:nd) / self%mass
         dfdy(nd + i, i) = dfdy(nd + i, i) - self%spring(i) / self%mass
         dfdy(nd + i, nd + i) = -self%damping(i) / self%mass
         dfdt(nd + i) = -dot_product(h(i, 1:nd), self%support_velocity(1:nd)) / self%mass
      end do
   end subroutine jacobian


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

end module friction_afm_tip
