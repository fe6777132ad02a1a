!> Unit conversions at the boundary, against values computed independently
!> from SI definitions.
program test_units
   use friction_kinds, only: wp, ev_per_angstrom_to_nn, kg_to_internal, n_per_m_to_internal, &
      & ns_per_m_to_internal, pi
   use testing, only: test_suite, check_close
   implicit none
   type(test_suite) :: suite

   suite%name = 'units'
   call suite%add('force', force)
   call suite%add('spring', spring)
   call suite%add('mass', mass)
   call suite%add('tomlinson_parameters', tomlinson_parameters)
   call suite%run_all()

contains

   subroutine force(failure)
      character(len=:), allocatable, intent(out) :: failure
      ! 1 eV/Å = 1.602176634e-19 J / 1e-10 m = 1.602176634e-9 N (exact since SI 2019).
      call check_close(failure, ev_per_angstrom_to_nn, 1.602176634_wp, 1.0e-15_wp, '1 eV/Å in nN')
   end subroutine force

   subroutine spring(failure)
      character(len=:), allocatable, intent(out) :: failure
      ! docs/physics.md (Units): 1 N/m = 0.06241509 eV/Å² (to its 7 digits); damping shares the factor.
      call check_close(failure, n_per_m_to_internal, 0.06241509_wp, 5.0e-9_wp, '1 N/m in eV/Å²')
      call check_close(failure, ns_per_m_to_internal, n_per_m_to_internal, 0.0_wp, '1 N s/m in eV s/Å²')
      ! k in eV/Å² times 1 Å² is an energy; back in J it must be k in N/m times 1e-20 m².
      call check_close(failure, 10.0_wp * n_per_m_to_internal * 1.602176634e-19_wp, 10.0_wp * 1.0e-20_wp, &
         & 1.0e-33_wp, '10 N/m round trip')
   end subroutine spring

   subroutine mass(failure)
      character(len=:), allocatable, intent(out) :: failure
      ! 1 kg = 1 J s²/m² = 0.06241509 eV s²/Å²
      call check_close(failure, kg_to_internal, 0.06241509_wp, 5.0e-9_wp, '1 kg in eV s²/Å²')
   end subroutine mass

   !> docs/physics.md (Prandtl–Tomlinson) quotes the parameter η = 4π²U0/(k a²):
   !> NaF along a row ≈ 2.96, HOPG along a row ≈ 4.18 (its two digits).
   subroutine tomlinson_parameters(failure)
      character(len=:), allocatable, intent(out) :: failure
      real(wp) :: eta

      eta = 4.0_wp * pi**2 * 1.0_wp / (10.0_wp * n_per_m_to_internal * 4.62_wp**2)
      call check_close(failure, eta, 2.96_wp, 0.005_wp, 'η of NaF')
      eta = 4.0_wp * pi**2 * (2.0_wp * 0.5_wp) / (25.0_wp * n_per_m_to_internal * 2.46_wp**2)
      call check_close(failure, eta, 4.18_wp, 0.005_wp, 'η of HOPG')
   end subroutine tomlinson_parameters

end program test_units
