!> The tip–surface interaction as an abstract type: energy, analytic gradient
!> and Hessian at a tip position r(3) in Å (energies in eV).
!>
!> Two-dimensional potentials (NaF, HOPG) ignore r(3) and return zero for its
!> derivatives; a three-dimensional one (the Lennard-Jones lattice sum) extends
!> the same type, so the equations of motion need not know which it is.
module friction_surface_potential
   use friction_kinds, only: wp
   implicit none
   private

   public :: surface_potential

   type, abstract :: surface_potential
   contains
      procedure(energy_interface), deferred :: energy
      procedure(gradient_interface), deferred :: gradient
      procedure(hessian_interface), deferred :: hessian
      procedure(dimensions_interface), deferred :: dimensions
   end type surface_potential

   abstract interface
      !> Potential energy V(r) in eV.
      pure function energy_interface(self, r) result(v)
         import :: surface_potential, wp
         class(surface_potential), intent(in) :: self
         real(wp), intent(in) :: r(3)
         real(wp) :: v
      end function energy_interface

      !> Gradient dV/dr in eV/Å.
      pure subroutine gradient_interface(self, r, g)
         import :: surface_potential, wp
         class(surface_potential), intent(in) :: self
         real(wp), intent(in) :: r(3)
         real(wp), intent(out) :: g(3)
      end subroutine gradient_interface

      !> Hessian d2V/dr_i dr_j in eV/Å², symmetric.
      pure subroutine hessian_interface(self, r, h)
         import :: surface_potential, wp
         class(surface_potential), intent(in) :: self
         real(wp), intent(in) :: r(3)
         real(wp), intent(out) :: h(3, 3)
      end subroutine hessian_interface

      !> Number of coordinates the potential depends on (2 or 3).
      pure function dimensions_interface(self) result(n)
         import :: surface_potential
         class(surface_potential), intent(in) :: self
         integer :: n
      end function dimensions_interface
   end interface

end module friction_surface_potential
