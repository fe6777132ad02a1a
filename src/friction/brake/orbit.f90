!> Periodic orbits of the switched brake and their Floquet multipliers
!> (docs/physics.md, periodic orbits): Newton shooting on the stick-to-slip
!> section (analysis/periodic_orbit.f90).
!>
!> Section.  A slip starts when the elastic force reaches the static limit,
!> 2x - y = σ μs N'(y) with σ = ±1, at v = v'_dr.  Given σ, the points of
!> the section are (y, w): x = (y + σ μs N'(y))/2 and v = v'_dr follow.
!> The return map P(y, w) starts a slip there (direction -σ), integrates
!> through any number of slips, slip reversals and sticks with the tangent
!> matrix Φ (saltation matrices at every switching, the exact stick flow)
!> and stops at the next stick-to-slip event, located by the event
!> machinery.  DP = the (y, w) rows of (I - f nᵀ/(nᵀ f)) Φ B: Φ projected
!> along the flow f onto the section (normal n), B the section's tangent
!> vectors ∂(x, v, y, w)/∂(y, w).  A return at the other limit (σ changes)
!> is no return of this section.
!>
!> Multipliers.  The orbit's four: the trivial 1 along the flow, the two of
!> DP, and 0 exactly -- the stick forgets the block's velocity, the
!> direction the Lyapunov spectrum reports with exponent -inf.
module friction_brake_orbit
   use friction_kinds, only: wp
   use friction_error, only: error_type
   use friction_brake_config, only: brake_config
   use friction_brake_params, only: brake_parameters
   use friction_brake_record, only: brake_event_table, event_stick_to_slip
   use friction_brake_switched, only: switched_integrator, brake_slip
   use friction_analysis_periodic_orbit, only: section_map, orbit_settings, periodic_orbit, &
      & find_periodic_orbit, floquet_multipliers, floquet_exponents
   implicit none
   private

   public :: brake_section_map, brake_orbit, brake_periodic_orbit, section_state, section_limit

   !> The return map of the stick-to-slip section at the limit σ.
   type, extends(section_map) :: brake_section_map
      type(brake_config) :: config
      real(wp) :: limit = 1.0_wp          !! σ
      real(wp) :: max_return = 1.0e4_wp   !! τ; no slip onset by then: no return
      logical :: tangent = .true.         !! .false.: P alone (jacobian = 0)
   contains
      procedure :: dimension => brake_map_dimension
      procedure :: evaluate => brake_map_evaluate
   end type brake_section_map

   !> A brake run's periodic orbit (/brake/orbit, docs/output.md).
   type :: brake_orbit
      type(periodic_orbit) :: orbit
      real(wp) :: limit = 1.0_wp              !! σ of the section
      real(wp) :: guess_time = 0.0_wp         !! τ of the run's slip onset Newton started from
      real(wp) :: state(4) = 0.0_wp           !! the orbit's slip onset (x, v, y, w)
      complex(wp) :: multipliers(4) = (0.0_wp, 0.0_wp)  !! 1, those of DP (by modulus), 0
      real(wp) :: exponents(4) = 0.0_wp       !! ln|μ|/T; -inf for the stick's 0
   end type brake_orbit

contains

   !> The section's state at (y, w) = s for the limit σ.
   pure function section_state(p, limit, s) result(z)
      type(brake_parameters), intent(in) :: p
      real(wp), intent(in) :: limit, s(2)
      real(wp) :: z(4)

      z = [(s(1) + limit * p%mu_s * p%normal_force(s(1))) / 2, p%v_dr, s(1), s(2)]
   end function section_state

   !> σ of a slip onset: the sign of the elastic force 2x - y there.
   pure real(wp) function section_limit(p, z)
      type(brake_parameters), intent(in) :: p
      real(wp), intent(in) :: z(4)

      section_limit = sign(1.0_wp, p%elastic_force(z(1), z(3)))
   end function section_limit

   pure integer function brake_map_dimension(self)
      class(brake_section_map), intent(in) :: self

      brake_map_dimension = 2
   end function brake_map_dimension

   subroutine brake_map_evaluate(self, s, image, jacobian, period, returned, reason, error)
      class(brake_section_map), intent(inout) :: self
      real(wp), intent(in) :: s(:)
      real(wp), intent(out) :: image(:), jacobian(:, :), period
      logical, intent(out) :: returned
      character(len=:), allocatable, intent(out) :: reason
      type(error_type), allocatable, intent(out) :: error
      type(switched_integrator), target :: run
      type(brake_event_table) :: events
      type(brake_slip) :: slip
      real(wp) :: normal(4), f(4), b(4, 2), projected(4, 2)
      integer :: i

      image = s
      jacobian = 0.0_wp
      period = 0.0_wp
      returned = .false.
      reason = ''
      associate (p => self%config%params, sigma => self%limit)
         run%tangent = self%tangent
         call run%start_slipping(self%config, 0.0_wp, section_state(p, sigma, s), -sigma, events, error)
         if (allocated(error)) return
         call run%advance_to_slip_onset(self%max_return, events, returned, error)
         if (allocated(error)) then
            ! A trial point of Newton's whose orbit leaves Eq. 10 (the pad lifts
            ! off) or defeats the stepper returns nowhere: a result of the search.
            returned = .false.
            reason = error%message
            deallocate (error)
            return
         end if
         if (.not. returned) then
            reason = 'no slip onset within the longest return time'
            return
         end if
         if (section_limit(p, run%y) /= sigma) then
            returned = .false.
            reason = 'the slip starts at the other static limit'
            return
         end if
         period = run%t
         image = run%y(3:4)
         if (.not. self%tangent) return
         ! h = μs N' - σ (2x - y) (switched.f90, stick_exit_saltation).
         normal = [-2.0_wp * sigma, 0.0_wp, p%mu_s * (1.0_wp - p%kappa) + sigma, 0.0_wp]
         slip%params = p
         slip%direction = -sigma
         call slip%rhs(run%t, run%y, f)
         b = 0.0_wp
         b(:, 1) = [(1.0_wp + sigma * p%mu_s * (1.0_wp - p%kappa)) / 2, 0.0_wp, 1.0_wp, 0.0_wp]
         b(4, 2) = 1.0_wp
         projected = matmul(run%phi, b)
         do i = 1, 2
            projected(:, i) = projected(:, i) - f * dot_product(normal, projected(:, i)) / dot_product(normal, f)
         end do
         jacobian = projected(3:4, :)
      end associate
   end subroutine brake_map_evaluate

   !> The periodic orbit through the run's first slip onset at or after
   !> t_start + transient (the guess), Newton on its section.  No slip onset
   !> there, or no convergence: found = .false. with the reason.
   subroutine brake_periodic_orbit(config, events, transient, settings, result, error)
      type(brake_config), intent(in) :: config
      type(brake_event_table), intent(in) :: events
      real(wp), intent(in) :: transient
      type(orbit_settings), intent(in) :: settings
      type(brake_orbit), intent(out) :: result
      type(error_type), allocatable, intent(out) :: error
      integer :: j

      do j = 1, events%n
         if (events%kind(j) == event_stick_to_slip .and. events%t(j) >= config%t_start + transient) exit
      end do
      if (j > events%n) then
         result%orbit%reason = 'no slip onset after orbit_transient'
         return
      end if
      result%guess_time = events%t(j)
      result%limit = section_limit(config%params, events%state(:, j))
      call continue_orbit(config, result%limit, events%state(3:4, j), settings, result, error)
   end subroutine brake_periodic_orbit

   !> Newton from the section point (y, w) = guess at the limit σ.
   subroutine continue_orbit(config, limit, guess, settings, result, error)
      type(brake_config), intent(in) :: config
      real(wp), intent(in) :: limit, guess(2)
      type(orbit_settings), intent(in) :: settings
      type(brake_orbit), intent(inout) :: result
      type(error_type), allocatable, intent(out) :: error
      type(brake_section_map) :: map

      map%config = config
      map%limit = limit
      map%max_return = config%t_end - config%t_start
      result%limit = limit
      call find_periodic_orbit(map, guess, settings, result%orbit, error)
      if (allocated(error)) return
      result%state = section_state(config%params, limit, result%orbit%point)
      if (.not. result%orbit%found) return
      result%multipliers = floquet_multipliers(result%orbit, 1)
      result%exponents = floquet_exponents(result%multipliers, result%orbit%period)
   end subroutine continue_orbit

end module friction_brake_orbit
