!> Highly oriented pyrolytic graphite under a scanning force microscope tip
!> (Hölscher et al.), Eq. 2:
!> V = -V0 [2 cos(2πx/a) cos(2πy/(a√3)) + cos(4πy/(a√3))].
!> Periodic under (a, 0) and (a/2, a√3/2): a hexagonal lattice.
module friction_surface_hopg
   use friction_kinds, only: wp, pi
   use friction_surface_potential, only: surface_potential, spice_form
   use friction_special, only: sin_cos
   implicit none
   private

   public :: hopg_potential, new_hopg_potential

   type, extends(surface_potential) :: hopg_potential
      real(wp) :: v0 = 0.0_wp  !! amplitude, eV
      real(wp) :: qx = 0.0_wp  !! 2π/a, 1/Å
      real(wp) :: qy = 0.0_wp  !! 2π/(a√3), 1/Å
   contains
      procedure :: energy
      procedure :: gradient
      procedure :: hessian
      procedure :: dimensions
      procedure :: spice
   end type hopg_potential

contains

   !> The potential for amplitude v0 (eV) and lattice constant a (Å).
   pure function new_hopg_potential(v0, a) result(self)
      real(wp), intent(in) :: v0, a
      type(hopg_potential) :: self

      self%v0 = v0
      self%qx = 2.0_wp * pi / a
      self%qy = 2.0_wp * pi / (a * sqrt(3.0_wp))
   end function new_hopg_potential

   pure function energy(self, r) result(v)
      class(hopg_potential), intent(in) :: self
      real(wp), intent(in) :: r(3)
      real(wp) :: v

      v = -self%v0 * (2.0_wp * cos(self%qx * r(1)) * cos(self%qy * r(2)) &
         & + cos(2.0_wp * self%qy * r(2)))
   end function energy

   pure subroutine gradient(self, r, g)
      class(hopg_potential), intent(in) :: self
      real(wp), intent(in) :: r(3)
      real(wp), intent(out) :: g(3)
      real(wp) :: sx, cx, sy, cy, phase_sin(2), phase_cos(2)

      call sin_cos([self%qx * r(1), self%qy * r(2)], phase_sin, phase_cos)
      sx = phase_sin(1); cx = phase_cos(1)
      sy = phase_sin(2); cy = phase_cos(2)
      g(1) = 2.0_wp * self%v0 * self%qx * sx * cy
      ! sin(2 qy y) = 2 sy cy
      g(2) = 2.0_wp * self%v0 * self%qy * (cx * sy + 2.0_wp * sy * cy)
      g(3) = 0.0_wp
   end subroutine gradient

   pure subroutine hessian(self, r, h)
      class(hopg_potential), intent(in) :: self
      real(wp), intent(in) :: r(3)
      real(wp), intent(out) :: h(3, 3)
      real(wp) :: sx, cx, sy, cy, phase_sin(2), phase_cos(2)

      call sin_cos([self%qx * r(1), self%qy * r(2)], phase_sin, phase_cos)
      sx = phase_sin(1); cx = phase_cos(1)
      sy = phase_sin(2); cy = phase_cos(2)
      h = 0.0_wp
      h(1, 1) = 2.0_wp * self%v0 * self%qx**2 * cx * cy
      ! cos(2 qy y) = cy² - sy²
      h(2, 2) = 2.0_wp * self%v0 * self%qy**2 * (cx * cy + 2.0_wp * (cy**2 - sy**2))
      h(1, 2) = -2.0_wp * self%v0 * self%qx * self%qy * sx * sy
      h(2, 1) = h(1, 2)
   end subroutine hessian

   pure function dimensions(self) result(n)
      class(hopg_potential), intent(in) :: self
      integer :: n

      n = 2
   end function dimensions

   !> Eq. 2 with the netlist's names for its constants.
   pure subroutine spice(self, form)
      class(hopg_potential), intent(in) :: self
      type(spice_form), intent(out) :: form

      form%comment = [character(len=100) :: 'Surface: HOPG, Eq. 2: V = -v0 [2 cos(qx x) cos(qy y) + cos(2 qy y)],', &
         & 'qx = 2 pi/a, qy = 2 pi/(a sqrt 3).']
      form%names = [character(len=8) :: 'v0', 'qx', 'qy']
      form%values = [self%v0, self%qx, self%qy]
      form%gradient_x = '2*v0*qx*sin(qx*V(xt))*cos(qy*V(yt))'
      form%gradient_y = '2*v0*qy*(cos(qx*V(xt))*sin(qy*V(yt)) + sin(2*qy*V(yt)))'
      form%why = ''
   end subroutine spice

end module friction_surface_hopg
