!> Working precision and the unit conversions at the input/output boundary.
!>
!> Internal units: length in angstrom (Å), energy in electronvolt (eV), time in
!> second (s).  Derived: force eV/Å, mass eV s²/Å², spring constant eV/Å²,
!> damping eV s/Å².  Namelists use SI for the tip (kg, N/m, N s/m) and the
!> microscope's units for the rest (Å, Å/s, eV, degrees); HDF5 forces are nN.
module friction_kinds
   use, intrinsic :: iso_fortran_env, only: real64, int64
   implicit none
   private

   public :: wp, i8
   public :: pi, ev_per_angstrom_to_nn, kg_to_internal, n_per_m_to_internal, &
      & ns_per_m_to_internal, deg_to_rad

   integer, parameter :: wp = real64 !! working precision
   integer, parameter :: i8 = int64  !! counters that may pass 2**31

   real(wp), parameter :: pi = 3.14159265358979323846264338327950288_wp

   !> Elementary charge in C: 1 eV = 1.602176634e-19 J exactly (SI 2019).
   real(wp), parameter :: elementary_charge = 1.602176634e-19_wp

   !> 1 eV/Å = 1.602176634e-19 J / 1e-10 m = 1.602176634 nN
   real(wp), parameter :: ev_per_angstrom_to_nn = elementary_charge / 1.0e-10_wp * 1.0e9_wp

   !> 1 kg = 1 J s²/m² = (1/e) eV s² / (1e20 Å²)
   real(wp), parameter :: kg_to_internal = 1.0_wp / elementary_charge / 1.0e20_wp

   !> 1 N/m = 1 J/m² = (1/e) eV / (1e20 Å²)
   real(wp), parameter :: n_per_m_to_internal = 1.0_wp / elementary_charge / 1.0e20_wp

   !> 1 N s/m = 1 J s/m² = (1/e) eV s / (1e20 Å²)
   real(wp), parameter :: ns_per_m_to_internal = 1.0_wp / elementary_charge / 1.0e20_wp

   real(wp), parameter :: deg_to_rad = pi / 180.0_wp

end module friction_kinds
