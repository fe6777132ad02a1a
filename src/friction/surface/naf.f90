!> NaF(001) under a friction force microscope tip (Hölscher et al.), Eq. 1:
!> V = -V0 cos(2πx/ax) cos(2πy/ay).
module friction_surface_naf
   use friction_kinds, only: wp, pi
   use friction_surface_potential, only: surface_potential, spice_form
   use friction_special, only: sin_cos
   implicit none
   private

   public :: naf_potential, new_naf_potential

   type, extends(surface_potential) :: naf_potential
      real(wp) :: v0 = 0.0_wp  !! amplitude, eV
      real(wp) :: qx = 0.0_wp  !! wave number 2π/ax, 1/Å
      real(wp) :: qy = 0.0_wp  !! wave number 2π/ay, 1/Å
   contains
      procedure :: energy
      procedure :: gradient
      procedure :: hessian
      procedure :: dimensions
      procedure :: spice
   end type naf_potential

contains

   !> The potential for amplitude v0 (eV) and periods ax, ay (Å).
   pure function new_naf_potential(v0, ax, ay) result(self)
      real(wp), intent(in) :: v0, ax, ay
      type(naf_potential) :: self

      self%v0 = v0
      self%qx = 2.0_wp * pi / ax
      self%qy = 2.0_wp * pi / ay
   end function new_naf_potential

   pure function energy(self, r) result(v)
      class(naf_potential), intent(in) :: self
      real(wp), intent(in) :: r(3)
      real(wp) :: v

      v = -self%v0 * cos(self%qx * r(1)) * cos(self%qy * r(2))
   end function energy

   pure subroutine gradient(self, r, g)
      class(naf_potential), intent(in) :: self
      real(wp), intent(in) :: r(3)
      real(wp), intent(out) :: g(3)
      real(wp) :: sx, cx, sy, cy, phase_sin(2), phase_cos(2)

      call sin_cos([self%qx * r(1), self%qy * r(2)], phase_sin, phase_cos)
      sx = phase_sin(1); cx = phase_cos(1)
      sy = phase_sin(2); cy = phase_cos(2)
      g(1) = self%v0 * self%qx * sx * cy
      g(2) = self%v0 * self%qy * cx * sy
      g(3) = 0.0_wp
   end subroutine gradient

   pure subroutine hessian(self, r, h)
      class(naf_potential), intent(in) :: self
      real(wp), intent(in) :: r(3)
      real(wp), intent(out) :: h(3, 3)
      real(wp) :: sx, cx, sy, cy, phase_sin(2), phase_cos(2)

      call sin_cos([self%qx * r(1), self%qy * r(2)], phase_sin, phase_cos)
      sx = phase_sin(1); cx = phase_cos(1)
      sy = phase_sin(2); cy = phase_cos(2)
      h = 0.0_wp
      h(1, 1) = self%v0 * self%qx**2 * cx * cy
      h(2, 2) = self%v0 * self%qy**2 * cx * cy
      h(1, 2) = -self%v0 * self%qx * self%qy * sx * sy
      h(2, 1) = h(1, 2)
   end subroutine hessian

   pure function dimensions(self) result(n)
      class(naf_potential), intent(in) :: self
      integer :: n

      n = 2
   end function dimensions

   !> Eq. 1 with the netlist's names for its constants.
   pure subroutine spice(self, form)
      class(naf_potential), intent(in) :: self
      type(spice_form), intent(out) :: form

      form%comment = [character(len=100) :: &
         & 'Surface: NaF(001), Eq. 1: V = -v0 cos(qx x) cos(qy y), qx = 2 pi/ax, qy = 2 pi/ay.']
      form%names = [character(len=8) :: 'v0', 'qx', 'qy']
      form%values = [self%v0, self%qx, self%qy]
      form%gradient_x = 'v0*qx*sin(qx*V(xt))*cos(qy*V(yt))'
      form%gradient_y = 'v0*qy*cos(qx*V(xt))*sin(qy*V(yt))'
      form%why = ''
   end subroutine spice

end module friction_surface_naf
