!> The AFM job: scan this rank's lines (dealt round-robin), then write the
!> file together under a temporary name and publish it.
module friction_job_afm
   use mpi_f08
   use friction_kinds, only: wp, i8
   use friction_error, only: error_type
   use friction_strings, only: itoa
   use friction_version, only: version_string
   use friction_ode_solver, only: integrator_statistics
   use friction_surface_potential, only: surface_potential
   use friction_afm_config, only: afm_config, new_potential, species_count
   use friction_afm_scan, only: afm_scanner, trip_record, n_quantities, q_fx, q_fy, q_f_along
   use friction_afm_output, only: write_afm_file, afm_surface_record
   use friction_afm_validity, only: afm_model_warnings, quasistatic_friction_warning
   use friction_output_summary, only: run_summary
   use friction_scene_report, only: job_reporter
   use friction_scene_context, only: job_context, agree_on_error, temporary_name, publish, ranks_text, share_of
   implicit none
   private

   public :: run_afm_job, afm_friction

contains

   !> Compute and write the map of `c`; `summary` says what was written.
   subroutine run_afm_job(job, c, reporter, summary, error)
      type(job_context), intent(in) :: job
      type(afm_config), intent(in) :: c
      class(job_reporter), intent(inout) :: reporter
      character(len=:), allocatable, intent(out) :: summary
      type(error_type), allocatable, intent(out) :: error
      type(afm_scanner), target :: scanner
      class(surface_potential), allocatable :: potential
      type(afm_surface_record) :: surface
      type(trip_record) :: trip
      real(wp), allocatable :: trace(:, :, :), retrace(:, :, :)
      type(run_summary) :: record
      type(integrator_statistics) :: stats
      integer(i8) :: counts(4)
      integer :: first, count, j
      real(wp) :: wall
      character(len=:), allocatable :: temporary, warnings
      character(len=12) :: seconds
      integer :: start, end

      ! The surface first, identically on every rank: a bad net or defect is
      ! bad input, reported before any work.
      call new_potential(c, potential, error, surface%net, surface%cutoff)
      if (allocated(error)) return
      ! A reduced tip model outside where it holds (README: Reduced models (AFM)):
      ! one note per reason.
      if (job%rank == 0) then
         warnings = afm_model_warnings(c, potential)
         start = 1
         do while (start <= len(warnings))
            end = index(warnings(start:), new_line('a'))
            end = merge(len(warnings), start + end - 2, end == 0)
            call reporter%note('warning: '//warnings(start:end))
            start = end + 2
         end do
      end if
      surface%species_names = c%species(1:species_count(c))
      call share_of(c%ny, job%nranks, job%rank, first, count)
      allocate (trace(c%nx, count, n_quantities))
      allocate (retrace(c%nx, merge(count, 0, c%retrace), n_quantities))
      call scanner%init(c, potential, error)
      surface%contact_height = scanner%contact_height
      surface%support_height = scanner%support_height
      do j = 1, count
         if (allocated(error)) exit
         call scanner%run_trip(first + (j - 1) * job%nranks, .true., trip, error)
         if (allocated(error)) exit
         trace(:, j, :) = trip%values
         if (c%retrace) then
            call scanner%run_trip(first + (j - 1) * job%nranks, .false., trip, error)
            if (allocated(error)) exit
            retrace(:, j, :) = trip%values
         end if
         ! Rank 0's share is as large as any other and spread over the whole
         ! map, so its fraction done is the map's fraction done.
         if (job%rank == 0) call reporter%progress(real(lines_done(j), wp), real(c%ny, wp), 'lines', .false.)
      end do
      if (job%rank == 0 .and. .not. allocated(error)) &
         & call reporter%progress(real(lines_done(count), wp), real(c%ny, wp), 'lines', .true.)

      ! A failure on any rank stops all of them here, before anything is written.
      call agree_on_error(job, error)
      if (allocated(error)) return
      if (c%model == 'quasistatic') call check_friction()

      stats = scanner%statistics()
      counts = [stats%steps, stats%failed_steps, stats%rhs_evaluations, stats%jacobian_evaluations]
      call MPI_Allreduce(MPI_IN_PLACE, counts, 4, MPI_INTEGER8, MPI_SUM, job%comm)
      stats = integrator_statistics(counts(1), counts(2), counts(3), counts(4))
      wall = MPI_Wtime() - job%t_start
      call MPI_Allreduce(MPI_IN_PLACE, wall, 1, MPI_DOUBLE_PRECISION, MPI_MAX, job%comm)
      ! (Component by component: gfortran's structure constructor mis-sizes a
      ! deferred-length component copied from another derived type's.)
      record%input_text = job%input_text
      record%version = version_string
      record%nranks = job%nranks
      record%wall_time = wall
      record%stats = stats

      temporary = temporary_name(job)
      if (scanner%tip%ndim == 3) then
         call write_afm_file(temporary, job%comm, c, first, job%nranks, trace, retrace, record, error, surface)
      else
         call write_afm_file(temporary, job%comm, c, first, job%nranks, trace, retrace, record, error)
      end if
      call publish(job, temporary, error)
      if (allocated(error)) return
      write (seconds, '(f12.2)') wall
      summary = itoa(c%ny)//' lines x '//itoa(c%nx)//' points, '//trim(adjustl(seconds))//' s ' &
         & //ranks_text(job%nranks)

   contains

      !> The quasistatic map's mean friction against the drag it leaves out.
      subroutine check_friction()
         real(wp) :: sums(2)
         character(len=:), allocatable :: warning

         sums = [sum(trace(:, :, q_f_along)), real(size(trace(:, :, q_f_along)), wp)]
         if (c%retrace) sums(1) = 0.5_wp * (sums(1) - sum(retrace(:, :, q_f_along)))
         call MPI_Allreduce(MPI_IN_PLACE, sums, 2, MPI_DOUBLE_PRECISION, MPI_SUM, job%comm)
         warning = quasistatic_friction_warning(c, sums(1) / max(1.0_wp, sums(2)))
         if (job%rank == 0 .and. len(warning) > 0) call reporter%note('warning: '//warning)
      end subroutine check_friction

      integer function lines_done(done)
         integer, intent(in) :: done

         lines_done = min(c%ny, int(real(done, wp) / max(1, count) * c%ny))
      end function lines_done

   end subroutine run_afm_job

   !> The whole map of `c` on this process, reduced to the numbers a
   !> parameter scan charts: the mean friction (half the width of the
   !> friction loop, the mean of (trace - retrace) f_along / 2 over the map;
   !> the mean trace f_along without retrace) and the maximum lateral force
   !> |(fx, fy)| over all samples, both nN.  Holds one trip at a time.
   subroutine afm_friction(c, mean_friction, max_force, error)
      type(afm_config), intent(in) :: c
      real(wp), intent(out) :: mean_friction, max_force
      type(error_type), allocatable, intent(out) :: error
      type(afm_scanner), target :: scanner
      class(surface_potential), allocatable :: potential
      type(trip_record) :: trip
      real(wp) :: total
      integer :: j

      mean_friction = 0.0_wp
      max_force = 0.0_wp
      call new_potential(c, potential, error)
      if (allocated(error)) return
      call scanner%init(c, potential, error)
      if (allocated(error)) return
      total = 0.0_wp
      do j = 0, c%ny - 1
         call scanner%run_trip(j, .true., trip, error)
         if (allocated(error)) return
         total = total + sum(trip%values(:, q_f_along))
         max_force = max(max_force, maxval(hypot(trip%values(:, q_fx), trip%values(:, q_fy))))
         if (c%retrace) then
            call scanner%run_trip(j, .false., trip, error)
            if (allocated(error)) return
            total = total - sum(trip%values(:, q_f_along))
            max_force = max(max_force, maxval(hypot(trip%values(:, q_fx), trip%values(:, q_fy))))
         end if
      end do
      mean_friction = total / (real(c%nx, wp) * c%ny * merge(2, 1, c%retrace))
   end subroutine afm_friction

end module friction_job_afm
