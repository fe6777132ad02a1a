!> The &law group: which friction law and every law's parameters, in SI
!> units (docs/laws.md).  One flat group, so that a file may set the name
!> and the parameters in any order and a sweep may vary any of them; the
!> factory (factory.f90) builds the law the name says, and each law checks
!> and uses only its own parameters.  Names shared by several laws mean the
!> same thing in each (fc the Coulomb level, sigma2 the viscous slope ...).
module friction_law_settings
   use friction_kinds, only: wp
   use friction_parameters, only: parameter_visitor
   use friction_law_table_reader, only: table_read
   implicit none
   private

   public :: law_settings, law_group, law_path_length, max_gms_elements

   !> The namelist group the parameters are read from.
   character(len=*), parameter :: law_group = 'law'
   integer, parameter :: law_path_length = 4096
   !> The most elements of the Generalized Maxwell-Slip law (each one state).
   integer, parameter :: max_gms_elements = 8

   type :: law_settings
      character(len=16) :: model = 'coulomb'   !! the law's name (friction_law_factory's law_names)
      ! Coefficient laws: the force is a coefficient times the normal load.
      real(wp) :: mu = 0.3_wp           !! kinetic friction coefficient (coulomb, arctan)
      real(wp) :: mu_s = 0.4_wp         !! static friction coefficient (coulomb)
      real(wp) :: epsilon = 1.0e6_wp    !! steepness of the arctan law, s/m (Eq. 10's ε)
      real(wp) :: delta = 0.1_wp        !! velocity weakening of the arctan law, s/m (Eq. 10's δ)
      ! Force laws: the levels are forces (N) at the mechanism's normal load.
      ! Defaults: the LuGre paper's Table I.
      real(wp) :: fc = 1.0_wp           !! Coulomb level F_c, N
      real(wp) :: fs = 1.5_wp           !! static (stiction) level F_s, N
      real(wp) :: vs = 1.0e-3_wp        !! Stribeck velocity v_s, m/s
      real(wp) :: exponent = 2.0_wp     !! Stribeck exponent δ: exp(-|v/v_s|^δ)
      real(wp) :: sigma0 = 1.0e5_wp     !! bristle (contact) stiffness σ0, N/m
      real(wp) :: sigma1 = 316.22776601683793_wp  !! bristle damping σ1, N s/m (√1e5)
      real(wp) :: sigma2 = 0.0_wp       !! viscous coefficient σ2, N s/m
      real(wp) :: alpha = 1.0_wp        !! Dahl exponent α
      real(wp) :: z_ba = 5.0e-6_wp      !! elasto-plastic break-away displacement, m
      real(wp) :: dv = 1.0e-4_wp        !! Karnopp's zero-velocity band half-width, m/s
      ! Rate and state (Dieterich-Ruina), coefficients times the normal load.
      real(wp) :: mu0 = 0.6_wp          !! steady coefficient at v0
      real(wp) :: a = 0.010_wp          !! direct effect
      real(wp) :: b = 0.015_wp          !! evolution effect
      real(wp) :: dc = 1.0e-5_wp        !! characteristic slip distance D_c, m
      real(wp) :: v0 = 1.0e-6_wp        !! reference velocity, m/s
      character(len=8) :: evolution = 'aging'   !! 'aging' or 'slip'
      ! Generalized Maxwell-Slip: elements in parallel, each a spring that
      ! saturates at its share of the Stribeck curve.  The defaults' stiffnesses
      ! add up to Table I's sigma0.
      integer :: elements = 4           !! number of elements N (1 to max_gms_elements)
      real(wp) :: element_stiffness(max_gms_elements) = [4.0e4_wp, 3.0e4_wp, 2.0e4_wp, 1.0e4_wp, &
         & 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp]   !! k_i, N/m
      real(wp) :: element_weight(max_gms_elements) = [0.1_wp, 0.2_wp, 0.3_wp, 0.4_wp, &
         & 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp]   !! w_i, the share of the Stribeck curve (they add up to 1)
      real(wp) :: attraction = 20.0_wp  !! C, N/s: how fast a slipping element's force approaches its limit
      ! Tabulated F(v)
      character(len=law_path_length) :: table_file = ''   !! two columns: v (m/s), F (N)
      real(wp) :: scale = 1.0_wp        !! the table's force times this (number of contacts)
      character(len=12) :: extrapolation = 'constant'   !! above the last velocity: 'constant' or 'logarithmic'
      !> Reads table files other than text (a microscope sweep's HDF5 file),
      !> given by the layer that has the means; none: text only.  (A
      !> procedure pointer: settings are copied freely, a pointer to a module
      !> routine with them.)
      procedure(table_read), pointer, nopass :: reader => null()
   contains
      procedure :: visit
   end type law_settings

contains

   !> The variables of &law, each once, with its unit.
   subroutine visit(self, v)
      class(law_settings), intent(inout) :: self
      type(parameter_visitor), intent(inout) :: v

      call v%begin_group(law_group)
      call v%item('model', self%model, fold=.true.)
      call v%item('mu', self%mu, '1')
      call v%item('mu_s', self%mu_s, '1')
      call v%item('epsilon', self%epsilon, 's/m')
      call v%item('delta', self%delta, 's/m')
      call v%item('fc', self%fc, 'N')
      call v%item('fs', self%fs, 'N')
      call v%item('vs', self%vs, 'm/s')
      call v%item('exponent', self%exponent, '1')
      call v%item('sigma0', self%sigma0, 'N/m')
      call v%item('sigma1', self%sigma1, 'N s/m')
      call v%item('sigma2', self%sigma2, 'N s/m')
      call v%item('alpha', self%alpha, '1')
      call v%item('z_ba', self%z_ba, 'm')
      call v%item('dv', self%dv, 'm/s')
      call v%item('mu0', self%mu0, '1')
      call v%item('a', self%a, '1')
      call v%item('b', self%b, '1')
      call v%item('dc', self%dc, 'm')
      call v%item('v0', self%v0, 'm/s')
      call v%item('evolution', self%evolution, fold=.true.)
      call v%item('elements', self%elements)
      call v%item('element_stiffness', self%element_stiffness, 'N/m', fill=0.0_wp)
      call v%item('element_weight', self%element_weight, '1', fill=0.0_wp)
      call v%item('attraction', self%attraction, 'N/s')
      call v%item('table_file', self%table_file, path=.true.)
      call v%item('scale', self%scale, '1')
      call v%item('extrapolation', self%extrapolation, fold=.true.)
      call v%end_group()
   end subroutine visit

end module friction_law_settings
