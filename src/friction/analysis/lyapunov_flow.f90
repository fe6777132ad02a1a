!> Maximum Lyapunov exponent from the equations (Benettin et al. 1980): a
!> reference and a perturbed trajectory at distance d0, integrated side by
!> side; every renormalisation interval the log growth of their distance is
!> summed and the perturbed one is pulled back to d0 along the separation.
!> The running estimate after each interval is kept so convergence shows.
!> Scenes whose trajectories are not one smooth ODE (the switched brake)
!> drive the same accumulator (`benettin_accumulator`) with their own runs.
module friction_analysis_lyapunov_flow
   use friction_kinds, only: wp
   use friction_error, only: error_type, fatal_error, error_input
   use friction_ode_system, only: ode_system
   use friction_ode_solver, only: ode_solver, solver_settings
   use friction_ode_watch, only: step_watch
   implicit none
   private

   public :: benettin_settings, benettin_accumulator, benettin_exponent

   type :: benettin_settings
      real(wp) :: transient = 100.0_wp     !! time integrated before measuring
      real(wp) :: duration = 1000.0_wp     !! time over which growth is summed
      real(wp) :: renormalise = 1.0_wp     !! interval between renormalisations
      real(wp) :: d0 = 1.0e-8_wp           !! initial and renormalised distance
   end type benettin_settings

   !> Sums of log growth and the running estimate.
   type :: benettin_accumulator
      real(wp) :: d0 = 1.0e-8_wp
      real(wp) :: log_growth = 0.0_wp
      real(wp) :: elapsed = 0.0_wp
      integer :: n = 0
      real(wp), allocatable :: time(:)       !! measuring time at each renormalisation
      real(wp), allocatable :: estimate(:)   !! running exponent there
   contains
      procedure :: start
      procedure :: renormalise
      procedure :: current => current_exponent
   end type benettin_accumulator

contains

   pure subroutine start(self, d0, capacity)
      class(benettin_accumulator), intent(inout) :: self
      real(wp), intent(in) :: d0
      integer, intent(in) :: capacity

      self%d0 = d0
      self%log_growth = 0.0_wp
      self%elapsed = 0.0_wp
      self%n = 0
      if (allocated(self%time)) deallocate (self%time, self%estimate)
      allocate (self%time(max(capacity, 1)), self%estimate(max(capacity, 1)))
   end subroutine start

   !> Record growth over interval and return the perturbed state pulled back
   !> to distance d0 from the reference.
   pure subroutine renormalise(self, reference, perturbed, interval)
      class(benettin_accumulator), intent(inout) :: self
      real(wp), intent(in) :: reference(:)
      real(wp), intent(inout) :: perturbed(:)
      real(wp), intent(in) :: interval
      real(wp) :: d

      d = norm2(perturbed - reference)
      if (d > 0.0_wp) then
         self%log_growth = self%log_growth + log(d / self%d0)
         perturbed = reference + (perturbed - reference) * (self%d0 / d)
      end if
      self%elapsed = self%elapsed + interval
      if (self%n < size(self%time)) then
         self%n = self%n + 1
         self%time(self%n) = self%elapsed
         self%estimate(self%n) = self%log_growth / self%elapsed
      end if
   end subroutine renormalise

   pure real(wp) function current_exponent(self) result(exponent)
      class(benettin_accumulator), intent(in) :: self

      exponent = 0.0_wp
      if (self%elapsed > 0.0_wp) exponent = self%log_growth / self%elapsed
   end function current_exponent

   !> The exponent of a smooth system from y0 at t0; the perturbation starts
   !> along (1, 1, ..., 1)/√n after the transient.  A watch, if given, is
   !> asked inside every integration and after every interval: its error
   !> (a stop request, a wall-clock limit) ends the estimate there.
   subroutine benettin_exponent(system, solver, y0, t0, settings, result, error, watch)
      class(ode_system), target, intent(in) :: system
      type(solver_settings), intent(in) :: solver
      real(wp), intent(in) :: y0(:), t0
      type(benettin_settings), intent(in) :: settings
      type(benettin_accumulator), intent(out) :: result
      type(error_type), allocatable, intent(out) :: error
      class(step_watch), intent(inout), optional :: watch
      type(ode_solver) :: first, second
      real(wp) :: t, t1, t2, reference(size(y0)), perturbed(size(y0)), h
      integer :: k, intervals

      if (.not. (settings%renormalise > 0.0_wp .and. settings%duration >= settings%renormalise &
         & .and. settings%d0 > 0.0_wp .and. settings%transient >= 0.0_wp)) then
         call fatal_error(error, 'Benettin: need renormalise > 0, duration >= renormalise, d0 > 0, ' &
            & //'transient >= 0', error_input)
         return
      end if
      h = solver%h_start
      if (.not. (h > 0.0_wp)) h = 1.0e-3_wp
      call first%init(system, solver, h, error)
      if (allocated(error)) return
      call second%init(system, solver, h, error)
      if (allocated(error)) return
      reference = y0
      t = t0
      if (settings%transient > 0.0_wp) then
         call first%advance(t, t0 + settings%transient, reference, error, watch)
         if (allocated(error)) return
      end if
      perturbed = reference + settings%d0 / sqrt(real(size(y0), wp))
      intervals = nint(settings%duration / settings%renormalise)
      call result%start(settings%d0, intervals)
      call first%restart(h)
      do k = 1, intervals
         t1 = t
         t2 = t
         call first%advance(t1, t + settings%renormalise, reference, error, watch)
         if (allocated(error)) return
         call second%restart(h)
         call second%advance(t2, t + settings%renormalise, perturbed, error, watch)
         if (allocated(error)) return
         t = t + settings%renormalise
         call result%renormalise(reference, perturbed, settings%renormalise)
         if (present(watch)) then
            call watch%check(t, error)
            if (allocated(error)) return
         end if
      end do
      call first%destroy()
      call second%destroy()
   end subroutine benettin_exponent

end module friction_analysis_lyapunov_flow
