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

   public :: surface_potential, spice_form

   !> A potential as a SPICE netlist writes it (afm/netlist.f90): comment
   !> lines, its constants (.param name = value) and dV/dx, dV/dy as
   !> behavioural expressions of the tip's nodes V(xt) and V(yt), in Å and
   !> eV.  A potential without one says why in `why` ('' when it has one).
   type :: spice_form
      character(len=100), allocatable :: comment(:)
      character(len=8), allocatable :: names(:)
      real(wp), allocatable :: values(:)
      character(len=:), allocatable :: gradient_x, gradient_y
      character(len=:), allocatable :: why
   end type spice_form

   type, abstract :: surface_potential
   contains
      procedure(energy_interface), deferred :: energy
      procedure(gradient_interface), deferred :: gradient
      procedure(hessian_interface), deferred :: hessian
      procedure(dimensions_interface), deferred :: dimensions
      procedure :: spice
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

contains

   !> The potential's SPICE form; a potential without a closed form has none.
   pure subroutine spice(self, form)
      class(surface_potential), intent(in) :: self
      type(spice_form), intent(out) :: form

      allocate (form%comment(0), form%names(0), form%values(0))
      form%gradient_x = ''
      form%gradient_y = ''
      form%why = 'it has no closed form for a behavioural source'
   end subroutine spice

end module friction_surface_potential
