!> &verify for a map: this rank's lines integrated again on the same
!> surface with the check's stepper settings, and the largest difference of
!> each force component over every rank's samples of both trips; beyond
!> check_limit the run fails (nothing written).
module friction_afm_map_verify
   use friction_parallel, only: reduce_all, op_sum, op_max
   use friction_kinds, only: wp
   use friction_error, only: error_type, fatal_error, error_interrupted, error_numerical
   use friction_strings, only: etoa
   use friction_ode_solver, only: integrator_statistics
   use friction_ode_settings, only: verify_solver
   use friction_surface_potential, only: surface_potential
   use friction_scene_report, only: job_reporter
   use friction_scene_context, only: job_context, agree_on_error
   use friction_afm_config, only: afm_config
   use friction_afm_scan, only: afm_scanner
   use friction_afm_trip, only: line_record, q_fx, q_fy, q_fz
   use friction_afm_output, only: afm_verify_record
   use friction_afm_map_share, only: map_share
   use friction_afm_line_checkpoint, only: line_checkpoint_name
   implicit none
   private

   public :: verify_map

contains

   !> The check of `map` (its lines done): `potential` is the surface the
   !> map ran on, handed over so a table is not built again; `record` gets
   !> the check's settings and differences.  Collective.  A stop request
   !> checkpoints every line of the map, so --resume then runs the check alone.
   subroutine verify_map(map, potential, three_d, job, reporter, record, error)
      type(map_share), intent(inout) :: map
      class(surface_potential), allocatable, intent(inout) :: potential
      logical, intent(in) :: three_d
      type(job_context), intent(in) :: job
      class(job_reporter), intent(inout) :: reporter
      type(afm_verify_record), intent(inout) :: record
      type(error_type), allocatable, intent(out) :: error
      type(afm_scanner), target :: checker
      type(afm_config) :: check_config
      type(line_record) :: again
      type(integrator_statistics) :: check_stats
      integer :: j, q, stopped
      integer, parameter :: forces(3) = [q_fx, q_fy, q_fz]

      associate (c => map%config)
         check_config = c
         check_config%verify%enabled = .false.
         check_config%solver = verify_solver(c%verify, c%solver)
         record%enabled = .true.
         record%method = check_config%solver%method
         record%rtol = check_config%solver%rtol
         record%atol = check_config%solver%atol
         call checker%init_owning(check_config, potential, error)
         stopped = 0
         do j = 1, map%count
            if (allocated(error)) exit
            ! (The check's lines count after the map's.)
            if (reporter%stop_after(map%computed + j - 1)) then
               stopped = 1
               exit
            end if
            call checker%run_line(map%global_line(j), again, error)
            if (allocated(error)) exit
            do q = 1, merge(3, 2, three_d)
               record%max_difference(q) = max(record%max_difference(q), &
                  & maxval(abs(again%trace(:, forces(q)) - map%trace(:, j, forces(q)))))
               if (c%retrace) record%max_difference(q) = max(record%max_difference(q), &
                  & maxval(abs(again%retrace(:, forces(q)) - map%retrace(:, j, forces(q)))))
            end do
            if (job%rank == 0) call reporter%progress(real(map%lines_done(j), wp), real(c%ny, wp), &
               & 'lines (verify)', j == map%count)
         end do
         if (allocated(error)) error%message = 'verify run: '//error%message
         call agree_on_error(job, error)
         if (allocated(error)) return
         call reduce_all(job%comm, stopped, op_max)
         if (stopped /= 0) then
            call map%save_lines(map%count, error)
            if (.not. allocated(error)) call fatal_error(error, 'map interrupted in its &verify run: no file ' &
               & //'written; the map''s lines are checkpointed beside the output (' &
               & //line_checkpoint_name(job%output, 0)//' ...): run again with --resume to run only the check', &
               & error_interrupted)
            call agree_on_error(job, error)
            return
         end if
         check_stats = checker%statistics()
         record%rhs_evaluations = check_stats%rhs_evaluations
         if (job%parallel()) then
            call reduce_all(job%comm, record%max_difference, op_max)
            call reduce_all(job%comm, record%rhs_evaluations, op_sum)
         end if
         if (job%rank == 0) then
            call reporter%note('verify: '//trim(record%method)//' at rtol '//etoa(record%rtol, 2)//', atol ' &
               & //etoa(record%atol, 2)//': max |dF| = '//etoa(maxval(record%max_difference), 2)//' nN over the map')
         end if
         if (c%verify%max_difference > 0.0_wp .and. .not. (maxval(record%max_difference) <= c%verify%max_difference)) &
            & then
            call fatal_error(error, 'verify failed: the check run''s forces differ by ' &
               & //etoa(maxval(record%max_difference), 2)//' nN, more than check_limit = ' &
               & //etoa(c%verify%max_difference, 2)//' nN (docs/speed.md, which steppers need verify)', &
               & error_numerical)
         end if
      end associate
   end subroutine verify_map

end module friction_afm_map_verify
