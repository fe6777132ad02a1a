!> A one-dimensional row: a periodic potential along the lattice x axis only,
!> V = -V0 cos(2πx/a), flat across it.  The 1-D Prandtl–Tomlinson surface of
!> the literature (V0 its amplitude, 2 V0 its peak-to-peak corrugation), for
!> every tip model and the thermal ones: the tip moves in x and y, the y
!> spring alone holding it across.  NaF's Eq. 1 on its row of minima (y = 0)
!> is this potential exactly.
module friction_surface_row
   use friction_kinds, only: wp, pi
   use friction_surface_potential, only: surface_potential, spice_form
   implicit none
   private

   public :: row_potential, new_row_potential

   type, extends(surface_potential) :: row_potential
      real(wp) :: v0 = 0.0_wp  !! amplitude, eV
      real(wp) :: q = 0.0_wp   !! wave number 2π/a, 1/Å
   contains
      procedure :: energy
      procedure :: gradient
      procedure :: hessian
      procedure :: dimensions
      procedure :: spice
   end type row_potential

contains

   !> The row of amplitude v0 (eV) and period a (Å) along x.
   pure function new_row_potential(v0, a) result(self)
      real(wp), intent(in) :: v0, a
      type(row_potential) :: self

      self%v0 = v0
      self%q = 2.0_wp * pi / a
   end function new_row_potential

   pure function energy(self, r) result(v)
      class(row_potential), intent(in) :: self
      real(wp), intent(in) :: r(3)
      real(wp) :: v

      v = -self%v0 * cos(self%q * r(1))
   end function energy

   pure subroutine gradient(self, r, g)
      class(row_potential), intent(in) :: self
      real(wp), intent(in) :: r(3)
      real(wp), intent(out) :: g(3)

      g = [self%v0 * self%q * sin(self%q * r(1)), 0.0_wp, 0.0_wp]
   end subroutine gradient

   pure subroutine hessian(self, r, h)
      class(row_potential), intent(in) :: self
      real(wp), intent(in) :: r(3)
      real(wp), intent(out) :: h(3, 3)

      h = 0.0_wp
      h(1, 1) = self%v0 * self%q**2 * cos(self%q * r(1))
   end subroutine hessian

   pure function dimensions(self) result(n)
      class(row_potential), intent(in) :: self
      integer :: n

      n = 2
   end function dimensions

   !> The row, flat across: no force in y.
   pure subroutine spice(self, form)
      class(row_potential), intent(in) :: self
      type(spice_form), intent(out) :: form

      form%comment = [character(len=100) :: 'Surface: a one-dimensional row, V = -v0 cos(qx x), qx = 2 pi/ax.']
      form%names = [character(len=8) :: 'v0', 'qx']
      form%values = [self%v0, self%q]
      form%gradient_x = 'v0*qx*sin(qx*V(xt))'
      form%gradient_y = '0'
      form%why = ''
   end subroutine spice

end module friction_surface_row
