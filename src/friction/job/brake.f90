!> The brake job: one trajectory.  Rank 0 integrates it; with verify on, the
!> check run goes to rank 1 when there is one (concurrently), else rank 0
!> runs it after the main run.  The results are broadcast (a few MB at most)
!> so that every rank takes part in the collective writes with the same
!> data; the file does not depend on the number of ranks.
module friction_job_brake
   use mpi_f08
   use friction_kinds, only: wp, i8
   use friction_error, only: error_type, fatal_error, error_numerical
   use friction_strings, only: itoa
   use friction_version, only: version_string
   use friction_ode_solver, only: integrator_statistics
   use friction_brake_config, only: brake_config
   use friction_brake_simulate, only: brake_run, compare_runs
   use friction_brake_output, only: brake_run_summary, brake_check_summary, write_brake_file
   use friction_brake_diagnostics, only: brake_diagnostics, diagnose_brake
   use friction_scene_report, only: job_reporter
   use friction_scene_context, only: job_context, agree_on_error, temporary_name, publish, ranks_text
   implicit none
   private

   public :: run_brake_job, integrate_brake

contains

   subroutine run_brake_job(job, settings, reporter, summary, error)
      type(job_context), intent(in) :: job
      type(brake_config), intent(in) :: settings
      class(job_reporter), intent(inout) :: reporter
      character(len=:), allocatable, intent(out) :: summary
      type(error_type), allocatable, intent(out) :: error
      type(brake_run), target :: main_run, check_run
      type(brake_config) :: check_config
      type(brake_run_summary) :: record
      type(brake_check_summary) :: check
      type(brake_diagnostics) :: diagnostics
      type(error_type), allocatable :: check_error
      logical :: analysing
      integer :: check_rank
      real(wp) :: wall, stick_time
      integer(i8) :: counts(4)
      character(len=:), allocatable :: temporary
      character(len=240) :: line
      character(len=12) :: seconds

      check%enabled = settings%check%enabled
      check_rank = merge(1, 0, job%nranks > 1)
      if (job%rank == 0) call integrate_brake(main_run, settings, reporter, error)
      if (check%enabled) then
         check_config = settings%check_settings()
         if (job%rank == check_rank) then
            if (check_rank == 0) then
               call integrate_brake(check_run, check_config, reporter, check_error)
            else
               block
                  type(job_reporter) :: silent
                  call integrate_brake(check_run, check_config, silent, check_error)
               end block
            end if
         end if
         if (allocated(check_error) .and. .not. allocated(error)) then
            call move_alloc(check_error, error)
            error%message = 'verify run: '//error%message
         end if
      end if
      call agree_on_error(job, error)
      if (allocated(error)) return

      call share_brake_run(job, main_run, 0, settings%grid_size(), counts, record%compute_time, stick_time)
      record%stats = integrator_statistics(counts(1), counts(2), counts(3), counts(4))
      record%stick_time = stick_time
      if (check%enabled) then
         call share_brake_run(job, check_run, check_rank, settings%grid_size(), counts, check%compute_time, &
            & stick_time)
         check%stats = integrator_statistics(counts(1), counts(2), counts(3), counts(4))
         check%config = check_config
         check%comparison = compare_runs(main_run, check_run)
         associate (d => check%comparison, c => check_config%solver)
            if (job%rank == 0) then
               write (line, '(a, es8.2, a, es8.2, a, es8.2, a, i0, a, i0)') 'verify: '//trim(c%method) &
                  & //' at rtol ', c%rtol, ', atol ', c%atol, ': max |dx| = ', d%max_difference(1), &
                  & ' m over the grid; events ', d%events, ' vs ', d%check_events
               call reporter%note(trim(line))
            end if
            if (settings%check%max_difference > 0.0_wp .and. &
               & .not. (d%max_difference(1) <= settings%check%max_difference)) then
               write (line, '(a, es8.2, a, es8.2, a)') 'verify failed: the check run differs by ', &
                  & d%max_difference(1), ' m in x, more than check_limit = ', settings%check%max_difference, &
                  & ' m (README: Girling brake, which steppers need verify)'
               call fatal_error(error, trim(line), error_numerical)
               return
            end if
         end associate
      end if

      ! The diagnostics are deterministic functions of the shared run (and, for
      ! Benettin, of the settings): every rank computes the same numbers, so
      ! the file does not depend on the number of ranks.
      associate (a => settings%analysis)
         analysing = a%spectrum .or. a%poincare .or. a%lyapunov .or. a%rosenstein
      end associate
      if (analysing) then
         call diagnose_brake(settings, main_run%trajectory, main_run%events, diagnostics, error)
         if (allocated(error)) return
      end if

      wall = MPI_Wtime() - job%t_start
      call MPI_Allreduce(MPI_IN_PLACE, wall, 1, MPI_DOUBLE_PRECISION, MPI_MAX, job%comm)
      record%input_text = job%input_text
      record%version = version_string
      record%nranks = job%nranks
      record%wall_time = wall

      temporary = temporary_name(job)
      if (analysing) then
         call write_brake_file(temporary, job%comm, settings, main_run%trajectory, main_run%events, &
            & record, check, error, diagnostics)
      else
         call write_brake_file(temporary, job%comm, settings, main_run%trajectory, main_run%events, &
            & record, check, error)
      end if
      call publish(job, temporary, error)
      if (allocated(error)) return
      write (seconds, '(f12.3)') wall
      write (line, '(a, i0, a, f0.1, a, i0, a)') ' model, ', main_run%n, ' points to τ = ', &
         & settings%grid_time(main_run%n), ', ', main_run%events%n, ' events, '
      summary = trim(settings%model)//trim(line)//' '//trim(adjustl(seconds))//' s '//ranks_text(job%nranks)
   end subroutine run_brake_job

   !> One brake run, in pieces so that long runs can report progress in τ.
   subroutine integrate_brake(run, settings, reporter, error)
      type(brake_run), target, intent(inout) :: run
      type(brake_config), intent(in) :: settings
      class(job_reporter), intent(inout) :: reporter
      type(error_type), allocatable, intent(out) :: error
      integer :: piece, last

      call run%init(settings, error)
      if (allocated(error)) return
      piece = max(1, run%n / 200)
      do last = piece, run%n + piece - 1, piece
         call run%run_until(min(last, run%n), error)
         if (allocated(error)) return
         call reporter%progress(run%time_reached() - settings%t_start, settings%t_end - settings%t_start, &
            & 'tau', .false.)
      end do
      call reporter%progress(run%time_reached() - settings%t_start, settings%t_end - settings%t_start, &
         & 'tau', .true.)
   end subroutine integrate_brake

   !> Give every rank root's trajectory, events and counters.
   subroutine share_brake_run(job, run, root, n, counts, compute_time, stick_time)
      type(job_context), intent(in) :: job
      type(brake_run), intent(inout) :: run
      integer, intent(in) :: root, n
      integer(i8), intent(out) :: counts(4)
      real(wp), intent(out) :: compute_time, stick_time
      type(integrator_statistics) :: stats
      integer :: n_events
      real(wp) :: times(2)

      if (job%rank == root) then
         stats = run%statistics()
         counts = [stats%steps, stats%failed_steps, stats%rhs_evaluations, stats%jacobian_evaluations]
         times = [run%compute_time, run%stick_time()]
         n_events = run%events%n
      else
         call run%trajectory%allocate_points(n)
         run%n = n
         run%done = n
      end if
      call MPI_Bcast(counts, 4, MPI_INTEGER8, root, job%comm)
      call MPI_Bcast(times, 2, MPI_DOUBLE_PRECISION, root, job%comm)
      call MPI_Bcast(n_events, 1, MPI_INTEGER, root, job%comm)
      compute_time = times(1)
      stick_time = times(2)
      call MPI_Bcast(run%trajectory%t, n, MPI_DOUBLE_PRECISION, root, job%comm)
      call MPI_Bcast(run%trajectory%x, n, MPI_DOUBLE_PRECISION, root, job%comm)
      call MPI_Bcast(run%trajectory%v, n, MPI_DOUBLE_PRECISION, root, job%comm)
      call MPI_Bcast(run%trajectory%y, n, MPI_DOUBLE_PRECISION, root, job%comm)
      call MPI_Bcast(run%trajectory%w, n, MPI_DOUBLE_PRECISION, root, job%comm)
      call MPI_Bcast(run%trajectory%stick, n, MPI_INTEGER, root, job%comm)
      if (job%rank /= root) then
         run%events%n = n_events
         if (allocated(run%events%t)) deallocate (run%events%t, run%events%kind, run%events%state)
         allocate (run%events%t(max(1, n_events)), run%events%kind(max(1, n_events)), &
            & run%events%state(4, max(1, n_events)))
      end if
      if (n_events > 0) then
         call MPI_Bcast(run%events%t, n_events, MPI_DOUBLE_PRECISION, root, job%comm)
         call MPI_Bcast(run%events%kind, n_events, MPI_INTEGER, root, job%comm)
         call MPI_Bcast(run%events%state, 4 * n_events, MPI_DOUBLE_PRECISION, root, job%comm)
      end if
   end subroutine share_brake_run

end module friction_job_brake
