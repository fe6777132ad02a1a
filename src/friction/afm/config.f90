!> Settings of a friction-force-map scene, in the units of the namelist
!> (see README: input reference), and the conversion to the internal model.
module friction_afm_config
   use friction_kinds, only: wp, kg_to_internal, n_per_m_to_internal, ns_per_m_to_internal, &
      & deg_to_rad
   use friction_error, only: error_type, fatal_error, error_input
   use friction_ode_solver, only: solver_settings
   use friction_surface_potential, only: surface_potential
   use friction_surface_naf, only: new_naf_potential
   use friction_surface_hopg, only: new_hopg_potential
   use friction_afm_tip, only: afm_tip
   implicit none
   private

   public :: afm_config, potential_names, new_potential, new_tip

   character(len=*), parameter :: potential_names(2) = [character(len=4) :: 'naf', 'hopg']

   type :: afm_config
      ! &surface
      character(len=16) :: potential = 'naf'  !! 'naf' (Eq. 1) or 'hopg' (Eq. 2)
      real(wp) :: v0 = 1.0_wp          !! potential amplitude, eV
      real(wp) :: ax = 4.62_wp         !! NaF period along x, Å
      real(wp) :: ay = 4.62_wp         !! NaF period along y, Å
      real(wp) :: a = 2.46_wp          !! HOPG lattice constant, Å
      ! &tip
      real(wp) :: mass = 1.0e-8_wp     !! kg
      real(wp) :: kx = 10.0_wp         !! N/m
      real(wp) :: ky = 10.0_wp         !! N/m
      real(wp) :: cx = 1.0e-3_wp       !! N s/m
      real(wp) :: cy = 1.0e-3_wp       !! N s/m
      ! &scan
      real(wp) :: velocity = 400.0_wp  !! support speed, Å/s
      real(wp) :: length = 20.0_wp     !! along the scan direction, Å
      real(wp) :: width = 20.0_wp      !! across, Å
      real(wp) :: angle = 0.0_wp       !! scan direction from the lattice x axis, degrees
      real(wp) :: origin_x = 0.0_wp    !! first point of the first line, Å (lattice frame)
      real(wp) :: origin_y = 0.0_wp
      real(wp) :: lead_in = 0.0_wp     !! support travel before the first sample, Å
      integer :: nx = 128              !! sample points per line
      integer :: ny = 128              !! lines
      logical :: retrace = .true.      !! scan every line back as well
      ! &integrator
      type(solver_settings) :: solver
   contains
      procedure :: scan_direction
      procedure :: across_direction
   end type afm_config

contains

   !> Unit vector along the scan, lattice frame.
   pure function scan_direction(self) result(u)
      class(afm_config), intent(in) :: self
      real(wp) :: u(3)

      u = [cos(self%angle * deg_to_rad), sin(self%angle * deg_to_rad), 0.0_wp]
   end function scan_direction

   !> Unit vector across the scan (the scan direction turned by +90°).
   pure function across_direction(self) result(n)
      class(afm_config), intent(in) :: self
      real(wp) :: n(3)

      n = [-sin(self%angle * deg_to_rad), cos(self%angle * deg_to_rad), 0.0_wp]
   end function across_direction

   !> The surface potential the settings name.
   subroutine new_potential(config, potential, error)
      type(afm_config), intent(in) :: config
      class(surface_potential), allocatable, intent(out) :: potential
      type(error_type), allocatable, intent(out) :: error

      select case (trim(config%potential))
      case ('naf')
         allocate (potential, source=new_naf_potential(config%v0, config%ax, config%ay))
      case ('hopg')
         allocate (potential, source=new_hopg_potential(config%v0, config%a))
      case default
         call fatal_error(error, "unknown potential '"//trim(config%potential)//"'", error_input)
      end select
   end subroutine new_potential

   !> The tip model in internal units; the support path is set per trip.
   subroutine new_tip(config, tip, error)
      type(afm_config), intent(in) :: config
      type(afm_tip), intent(out) :: tip
      type(error_type), allocatable, intent(out) :: error

      call new_potential(config, tip%potential, error)
      if (allocated(error)) return
      tip%ndim = tip%potential%dimensions()
      tip%mass = config%mass * kg_to_internal
      tip%spring = [config%kx, config%ky, 0.0_wp] * n_per_m_to_internal
      tip%damping = [config%cx, config%cy, 0.0_wp] * ns_per_m_to_internal
   end subroutine new_tip

end module friction_afm_config
