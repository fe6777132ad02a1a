!> The machine's whole Lyapunov spectrum (&analysis lyapunov_spectrum;
!> docs/chaos.md, "The machine").  The orbit and its tangent matrix Φ go
!> side by side and the logs of Φ's QR factors are summed every
!> renormalisation interval (analysis/lyapunov_spectrum.f90).  Also Benettin's exponent of a
!> set-valued law, two switching runs without Φ (the smooth laws' is the
!> analysis layer's, diagnostics.f90).
!>
!> - A law that is one ODE (arctan, Dahl, LuGre, elasto-plastic,
!>   rate and state): the variational equations Φ' = J Φ with J from the
!>   law's analytic partial derivatives (model.f90's Jacobian), solved over
!>   each of the orbit's steps by exponentials and factored within the step
!>   (analysis/tangent_magnus.f90): a stiff law's fast directions keep their
!>   exact rates however long the steps.
!> - A set-valued law (Coulomb, Stribeck, the table) with exact stick: the
!>   slip's variational equations, the saltation matrix at every switch, and
!>   in stick the velocity pinned to the belt, which forgets δv: one direction
!>   is lost (its exponent -inf) once the run has stuck.
!> - A law with a zero-velocity band (Karnopp's): the band's run (band.f90)
!>   with its edges and the ends of its holds located, a saltation at each
!>   jump of the force, δv forgotten in a hold; Benettin's exponent of such a
!>   law is two such runs without Φ.
module friction_machine_lyapunov
   use friction_kinds, only: wp, i8
   use friction_error, only: error_type, fatal_error, error_input, error_numerical
   use friction_ode_system, only: ode_system
   use friction_ode_solver, only: ode_solver
   use friction_ode_watch, only: step_watch
   use friction_output_h5, only: h5_file
   use friction_analysis_lyapunov_spectrum, only: tangent_settings, spectrum_accumulator, kaplan_yorke, &
      & generic_frame
   use friction_analysis_tangent_magnus, only: orbit_step, tangent_over_step, magnus_tangent_step
   use friction_ode_events, only: event_system, event_locator, event_either
   use friction_strings, only: rtoa
   use friction_analysis_lyapunov_flow, only: benettin_settings, benettin_accumulator
   use friction_law, only: sliding_law, max_law_states
   use friction_law_factory, only: make_law
   use friction_output_law_files, only: law_with_files
   use friction_machine_config, only: machine_config
   use friction_machine_model, only: machine_smooth
   use friction_law_kinked, only: kinked_system
   use friction_machine_switching, only: machine_switching
   use friction_machine_band, only: machine_band
   use friction_machine_piecewise, only: piecewise_run
   implicit none
   private

   public :: machine_spectrum, machine_lyapunov_spectrum, smooth_start, write_machine_spectrum, piecewise_benettin, &
      & has_band

   !> The spectrum and what it was computed over.
   type :: machine_spectrum
      type(tangent_settings) :: settings
      type(spectrum_accumulator) :: qr
      real(wp), allocatable :: exponents(:)   !! largest first; -inf for the direction stick forgets
      real(wp) :: kaplan_yorke = 0.0_wp
      logical :: has_divergence = .false.     !! a law that is one ODE
      real(wp) :: divergence = 0.0_wp         !! 1/s: the time average of tr J over the same span
   end type machine_spectrum

   !> The orbit and one value more, D' = tr J(y): for the exact flow
   !> ∫ tr J dt = ln det Φ, which the exponents sum to (Liouville).  D is
   !> integrated by the stepper, beside the orbit but not measured by its
   !> error control, a quadrature independent of how Φ is carried: the
   !> check the file carries (docs/chaos.md).
   type, extends(ode_system) :: divergence_system
      class(ode_system), allocatable :: base
   contains
      procedure :: dimension => divergence_dimension
      procedure :: controlled_dimension => divergence_controlled_dimension
      procedure :: relative_component => divergence_relative_component
      procedure :: rhs => divergence_rhs
      procedure :: jacobian => divergence_jacobian
   end type divergence_system

contains

   pure function divergence_dimension(self) result(n)
      class(divergence_system), intent(in) :: self
      integer :: n

      n = self%base%dimension() + 1
   end function divergence_dimension

   pure function divergence_controlled_dimension(self) result(n)
      class(divergence_system), intent(in) :: self
      integer :: n

      n = self%base%dimension()
   end function divergence_controlled_dimension

   !> The base's (its components come first).
   pure subroutine divergence_relative_component(self, index, reference, floor)
      class(divergence_system), intent(in) :: self
      integer, intent(out) :: index
      real(wp), intent(out) :: reference, floor

      call self%base%relative_component(index, reference, floor)
   end subroutine divergence_relative_component

   pure subroutine divergence_rhs(self, t, y, dydt)
      class(divergence_system), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in), contiguous :: y(:)
      real(wp), intent(out), contiguous :: dydt(:)
      real(wp) :: jac(size(y) - 1, size(y) - 1), d0(size(y) - 1)
      integer :: n, i

      n = size(y) - 1
      call self%base%rhs(t, y(1:n), dydt(1:n))
      call self%base%jacobian(t, y(1:n), jac, d0)
      dydt(n + 1) = 0.0_wp
      do i = 1, n
         dydt(n + 1) = dydt(n + 1) + jac(i, i)
      end do
   end subroutine divergence_rhs

   !> The orbit's, and D's row ∂ tr J/∂y from central differences of the
   !> analytic J: a Rosenbrock stepper's D is of low order without it (docs/chaos.md).
   pure subroutine divergence_jacobian(self, t, y, dfdy, dfdt)
      class(divergence_system), intent(in) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: y(:)
      real(wp), intent(out) :: dfdy(:, :)
      real(wp), intent(out) :: dfdt(:)
      real(wp) :: jp(size(y) - 1, size(y) - 1), jm(size(y) - 1, size(y) - 1), d0(size(y) - 1), yp(size(y) - 1), dy
      integer :: n, k, i

      n = size(y) - 1
      dfdy = 0.0_wp
      dfdt = 0.0_wp
      call self%base%jacobian(t, y(1:n), dfdy(1:n, 1:n), dfdt(1:n))
      do k = 1, n
         dy = 1.0e-6_wp * max(1.0_wp, abs(y(k)))
         yp = y(1:n)
         yp(k) = y(k) + dy
         call self%base%jacobian(t, yp, jp, d0)
         yp(k) = y(k) - dy
         call self%base%jacobian(t, yp, jm, d0)
         do i = 1, n
            dfdy(n + 1, k) = dfdy(n + 1, k) + (jp(i, i) - jm(i, i)) / (2.0_wp * dy)
         end do
      end do
   end subroutine divergence_jacobian

   !> The ODE of a law that is one ODE, and its initial state (x0, v0, the
   !> states in steady sliding at v0 - belt_velocity or 0, over their scales).
   subroutine smooth_start(c, law, system, y0)
      type(machine_config), intent(in) :: c
      class(sliding_law), intent(in) :: law
      type(machine_smooth), intent(out) :: system
      real(wp), allocatable, intent(out) :: y0(:)
      real(wp) :: z(max_law_states)
      integer :: ns

      ns = law%state_count()
      call system%m%from_config(c)
      allocate (system%law, source=law)
      system%n_states = ns
      if (ns > 0) call law%state_scale(system%scale(1:ns))
      z = 0.0_wp
      if (ns > 0 .and. c%steady_start) call law%steady_state(c%v0 - c%belt_velocity, c%normal, z(1:ns))
      allocate (y0(2 + ns))
      y0(1:2) = [c%x0, c%v0]
      y0(3:2 + ns) = z(1:ns) / system%scale(1:ns)
   end subroutine smooth_start

   !> The spectrum of checked settings c from the start of the run: the
   !> transient, then a QR step every renormalisation interval.  `watch` is
   !> asked inside the integrations and after every interval.
   subroutine machine_lyapunov_spectrum(c, result, error, watch)
      type(machine_config), intent(in) :: c
      type(machine_spectrum), intent(out) :: result
      type(error_type), allocatable, intent(out) :: error
      class(step_watch), intent(inout) :: watch
      class(sliding_law), allocatable :: law

      associate (a => c%analysis, s => result%settings)
         s%transient = a%lyapunov_spectrum_transient
         s%duration = a%lyapunov_spectrum_duration
         if (s%duration == 0.0_wp) s%duration = c%t_end - c%t_start - s%transient
         s%renormalise = a%lyapunov_spectrum_renormalise
         if (.not. (s%renormalise > 0.0_wp .and. s%duration >= s%renormalise .and. s%transient >= 0.0_wp)) then
            call fatal_error(error, '&analysis: the Lyapunov spectrum needs lyapunov_spectrum_renormalise > 0, ' &
               & //'a duration of at least one interval after lyapunov_spectrum_transient', error_input)
            return
         end if
      end associate
      call make_law(law_with_files(c%law), law, error)
      if (allocated(error)) return
      if (law%set_valued() .or. has_band(law)) then
         call piecewise_spectrum(c, law, result%settings, result%qr, error, watch)
      else
         result%has_divergence = .true.
         call smooth_spectrum(c, law, result%settings, result%qr, result%divergence, error, watch)
      end if
      if (allocated(error)) return
      result%exponents = result%qr%exponents()
      result%kaplan_yorke = kaplan_yorke(result%exponents)
   end subroutine machine_lyapunov_spectrum

   !> A law that is one ODE: the orbit alone over the transient, then the
   !> orbit with D stepped one accepted step at a time, and Φ from the generic
   !> frame carried over each step by exponentials (analysis/tangent_magnus.f90),
   !> factored after every part of a step: the logs are summed over each
   !> renormalisation interval.
   subroutine smooth_spectrum(c, law, s, qr, divergence, error, watch)
      type(machine_config), intent(in) :: c
      class(sliding_law), intent(in) :: law
      type(tangent_settings), intent(in) :: s
      type(spectrum_accumulator), intent(out) :: qr
      real(wp), intent(out) :: divergence
      type(error_type), allocatable, intent(out) :: error
      class(step_watch), intent(inout) :: watch
      type(machine_smooth) :: system
      type(divergence_system), target :: extended
      type(ode_solver) :: orbit
      real(wp), allocatable :: y(:), phi(:, :), z(:), y_a(:), f_a(:), logs(:)
      real(wp) :: t, h, t0, t_a, t_target
      integer(i8) :: steps
      integer :: n, k, intervals, depth

      divergence = 0.0_wp
      call smooth_start(c, law, system, y)
      n = size(y)
      allocate (extended%base, source=system)
      h = c%first_step()
      t = c%t_start
      t0 = c%t_start + s%transient
      if (s%transient > 0.0_wp) then
         call orbit%init(extended%base, c%solver, h, error)
         if (allocated(error)) return
         call orbit%advance(t, t0, y, error, watch)
         call orbit%destroy()
         if (allocated(error)) return
      end if
      phi = generic_frame(n)
      if (law%kink_count() > 0) then
         call kinked_spectrum(error)
         return
      end if
      call orbit%init(extended, c%solver, h, error)
      if (allocated(error)) return
      intervals = int(s%duration / s%renormalise + 1.0e-9_wp)
      call qr%start(n, intervals)
      allocate (z(n + 1), y_a(n), f_a(n), logs(n))
      z(1:n) = y
      z(n + 1) = 0.0_wp
      call system%rhs(t, y, f_a)
      depth = 0
      do k = 1, intervals
         t_target = t0 + k * s%renormalise
         logs = 0.0_wp
         steps = 0
         do while (t < t_target)
            call orbit_step(orbit, c%solver%method, c%solver%max_steps, t, t_target, z, t_a, y_a, steps, error)
            if (allocated(error)) exit
            call tangent_over_step(system, orbit, t_a, y_a, f_a, t, z(1:n), phi, logs, depth, error)
            if (allocated(error)) exit
            ! (The watch every 16 steps, as the solver's own trips ask it, and
            ! after every step whose exponentials took thousands of parts.)
            if (mod(steps, 16_i8) == 0 .or. depth >= 12) then
               call watch%check(t, error)
               if (allocated(error)) exit
            end if
         end do
         if (allocated(error)) exit
         call qr%add_logs(logs, s%renormalise, 0)
         call watch%check(t, error)
         if (allocated(error)) exit
      end do
      call orbit%destroy()
      if (qr%elapsed > 0.0_wp) divergence = z(n + 1) / qr%elapsed

   contains

      !> The same with the law's kinks located (docs/chaos.md, "The tangent of a
      !> stiff law"): each ends a step, and past one the stepper restarts with a
      !> step of event_tolerance.
      subroutine kinked_spectrum(error)
         type(error_type), allocatable, intent(out) :: error
         type(kinked_system), target :: kinked
         type(divergence_system) :: flow
         type(event_locator) :: locator
         real(wp) :: f_b(n)
         integer :: m
         logical :: ok

         allocate (flow%base, source=system)
         allocate (kinked%base, source=flow)
         allocate (kinked%model, source=system)
         m = kinked%event_count()
         call locator%init(kinked, c%solver, spread(event_either, 1, m), spread(.true., 1, m), c%event_tolerance, &
            & h, error)
         if (allocated(error)) return
         intervals = int(s%duration / s%renormalise + 1.0e-9_wp)
         call qr%start(n, intervals)
         allocate (z(n + 1), y_a(n), f_a(n), logs(n))
         z(1:n) = y
         z(n + 1) = 0.0_wp
         call locator%restart(t, z, h)
         call system%rhs(t, y, f_a)
         depth = 0
         do k = 1, intervals
            t_target = t0 + k * s%renormalise
            logs = 0.0_wp
            steps = 0
            do while (t < t_target)
               t_a = t
               y_a = z(1:n)
               call locator%advance(t, t_target, z, error, watch, single=.true.)
               if (allocated(error)) return
               steps = steps + 1
               if (steps > c%solver%max_steps) then
                  call fatal_error(error, trim(c%solver%method)//': more than max_steps steps in one ' &
                     & //'renormalisation interval near t = '//rtoa(t)//' s', error_numerical)
                  return
               end if
               call system%rhs(t, z(1:n), f_b)
               if (t > t_a) then
                  call magnus_tangent_step(system, t_a, y_a, f_a, t, z(1:n), f_b, phi, logs, depth, ok)
                  if (.not. ok) then
                     call fatal_error(error, 'Lyapunov spectrum: the Jacobian is NaN or Inf, or too stiff for ' &
                        & //'the step ending near t = '//rtoa(t)//' s (an exponential of the tangent in more ' &
                        & //'than 2^24 parts)', error_numerical)
                     return
                  end if
               end if
               f_a = f_b
               if (locator%n_hits > 0) then
                  if (locator%hits(locator%n_hits)%terminal) call locator%restart(t, z, c%event_tolerance)
               end if
               if (mod(steps, 16_i8) == 0 .or. depth >= 12) then
                  call watch%check(t, error)
                  if (allocated(error)) return
               end if
            end do
            call qr%add_logs(logs, s%renormalise, 0)
            call watch%check(t, error)
            if (allocated(error)) return
         end do
         if (qr%elapsed > 0.0_wp) divergence = z(n + 1) / qr%elapsed
      end subroutine kinked_spectrum

   end subroutine smooth_spectrum

   !> A set-valued law's or a band law's spectrum: its run through switches
   !> with Φ (saltations at the switches, δv forgotten in stick or a hold); the
   !> transient in renormalisation intervals too, so that Φ stays bounded.
   subroutine piecewise_spectrum(c, law, s, qr, error, watch)
      type(machine_config), intent(in) :: c
      class(sliding_law), intent(in) :: law
      type(tangent_settings), intent(in) :: s
      type(spectrum_accumulator), intent(out) :: qr
      type(error_type), allocatable, intent(out) :: error
      class(step_watch), intent(inout) :: watch
      class(piecewise_run), allocatable, target :: run
      real(wp), allocatable :: phi(:, :)
      real(wp) :: t0
      integer :: k, intervals, n

      call allocate_run(law, run)
      call run%start_from(c, law, c%t_start, .true., error)
      if (allocated(error)) return
      n = size(run%y)
      t0 = c%t_start + s%transient
      do while (run%t < t0)
         call run%advance_to(min(run%t + s%renormalise, t0), error, watch)
         if (allocated(error)) return
         call run%reset(generic_frame(n))
         call watch%check(run%t, error)
         if (allocated(error)) return
      end do
      intervals = int(s%duration / s%renormalise + 1.0e-9_wp)
      call qr%start(n, intervals)
      do k = 1, intervals
         call run%advance_to(t0 + k * s%renormalise, error, watch)
         if (allocated(error)) return
         phi = run%phi
         call qr%renormalise(phi, s%renormalise, run%lost)
         call run%reset(phi)
         call watch%check(run%t, error)
         if (allocated(error)) return
      end do
   end subroutine piecewise_spectrum

   !> Benettin's exponent of a set-valued law or a band law (as the brake's
   !> switched model does it): a reference and a perturbed run through the
   !> law's switches in lockstep; after each interval the perturbed one
   !> restarts from the reference plus the separation scaled back to d0.
   !> Held (in stick, or in the band) the first perturbation is off v, so
   !> that both runs start in the same phase.
   subroutine piecewise_benettin(c, law, b, result, error, watch)
      type(machine_config), intent(in) :: c
      class(sliding_law), intent(in) :: law
      type(benettin_settings), intent(in) :: b
      type(benettin_accumulator), intent(out) :: result
      type(error_type), allocatable, intent(out) :: error
      class(step_watch), intent(inout) :: watch
      class(piecewise_run), allocatable, target :: reference, perturbed
      real(wp), allocatable :: direction(:), separated(:)
      real(wp) :: t
      integer :: k, intervals

      if (.not. benettin_valid(b, error)) return
      call allocate_run(law, reference)
      call allocate_run(law, perturbed)
      call reference%start_from(c, law, c%t_start, .false., error)
      if (allocated(error)) return
      t = c%t_start + b%transient
      call reference%advance_to(t, error, watch)
      if (allocated(error)) return
      allocate (direction(size(reference%y)), source=1.0_wp)
      if (reference%is_held()) direction(2) = 0.0_wp
      separated = reference%y + b%d0 * direction / norm2(direction)
      intervals = int(b%duration / b%renormalise + 1.0e-9_wp)
      call result%start(b%d0, intervals)
      do k = 1, intervals
         call perturbed%start_from(c, law, t, .false., error, separated)
         if (allocated(error)) return
         t = c%t_start + b%transient + k * b%renormalise
         call reference%advance_to(t, error, watch)
         if (allocated(error)) return
         call perturbed%advance_to(t, error, watch)
         if (allocated(error)) return
         separated = perturbed%y
         call result%renormalise(reference%y, separated, b%renormalise)
         call watch%check(t, error)
         if (allocated(error)) return
      end do
   end subroutine piecewise_benettin

   !> A run of the law's kind: exact stick and slip for a set-valued law, else the band's.
   subroutine allocate_run(law, run)
      class(sliding_law), intent(in) :: law
      class(piecewise_run), allocatable, intent(out) :: run

      if (law%set_valued()) then
         allocate (machine_switching :: run)
      else
         allocate (machine_band :: run)
      end if
   end subroutine allocate_run

   !> Whether the law has a zero-velocity band (Karnopp's).
   logical function has_band(law)
      class(sliding_law), intent(in) :: law
      real(wp) :: width, limit

      call law%band(width, limit)
      has_band = width > 0.0_wp
   end function has_band

   !> Whether Benettin's settings make sense, else the error.
   logical function benettin_valid(b, error)
      type(benettin_settings), intent(in) :: b
      type(error_type), allocatable, intent(out) :: error

      benettin_valid = b%renormalise > 0.0_wp .and. b%duration >= b%renormalise .and. b%d0 > 0.0_wp &
         & .and. b%transient >= 0.0_wp
      if (.not. benettin_valid) call fatal_error(error, '&analysis: Benettin needs lyapunov_renormalise > 0, ' &
         & //'a duration of at least one interval after lyapunov_transient, lyapunov_d0 > 0', error_input)
   end function benettin_valid

   !> /machine/lyapunov's spectrum (docs/output.md); the group exists.
   subroutine write_machine_spectrum(file, group, d)
      type(h5_file), intent(inout) :: file
      character(len=*), intent(in) :: group
      type(machine_spectrum), intent(in) :: d

      call file%write_vector(group//'/exponents', d%exponents, '1/s')
      call file%write_vector(group//'/exponents_time', d%qr%time(1:d%qr%count), 's')
      call file%write_matrix(group//'/exponents_history', d%qr%history(:, 1:d%qr%count), '1/s')
      call file%write_attribute_real(group, 'kaplan_yorke_dimension', d%kaplan_yorke, '1')
      call file%write_attribute_integer(group, 'spectrum_lost_directions', int(d%qr%lost, i8))
      call file%write_attribute_real(group, 'spectrum_transient', d%settings%transient, 's')
      call file%write_attribute_real(group, 'spectrum_duration', d%settings%duration, 's')
      call file%write_attribute_real(group, 'spectrum_renormalise', d%settings%renormalise, 's')
      if (d%has_divergence) call file%write_attribute_real(group, 'spectrum_divergence', d%divergence, '1/s')
   end subroutine write_machine_spectrum

end module friction_machine_lyapunov
