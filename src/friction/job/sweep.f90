!> Parameter sweeps over the MPI ranks (docs/sweeps.md).  Each point is a
!> copy of the job's scene with the swept variables set in memory and
!> checked by the scene's own checks (sweep_point.f90); an invalid or
!> failing point is recorded as failed with its reason and the sweep goes
!> on.  Each point is computed alone and deterministically: the results do
!> not depend on which rank took it or on the number of ranks.
!>
!> The run is four parts, each a type of its own module: the scheduler
!> hands out points (sweep_schedule.f90), the transport carries each
!> finished point to rank 0 at once (sweep_transport.f90), rank 0 keeps
!> them in batches in the checkpoint OUTPUT.ckpt (sweep_checkpoint.f90),
!> and the writer copies the checkpoint into the output in point order at
!> the end (sweep_output.f90).  Memory per rank does not grow with the
!> number of points: no rank holds an array over all points.
module friction_job_sweep
   use friction_parallel, only: broadcast, reduce_all, gather_to_root, op_sum, op_max, op_min
   use friction_kinds, only: wp
   use friction_error, only: error_type, fatal_error, error_interrupted, error_input, error_numerical
   use friction_strings, only: itoa, text_hash, bytes_text
   use friction_version, only: version_string
   use friction_ode_solver, only: integrator_statistics
   use friction_scene, only: point_result, point_memory
   use friction_job_config, only: job_config
   use friction_files, only: remove_file, file_exists, free_bytes, min_free_bytes, full_text
   use friction_scene_report, only: job_reporter
   use friction_scene_context, only: job_context, temporary_name, publish, ranks_text, agree_on_error, job_wall_time
   use friction_job_sweep_point, only: finished_point, point_names, compute_point, point_warning
   use friction_job_sweep_schedule, only: sweep_scheduler
   use friction_job_sweep_transport, only: point_transport
   use friction_job_sweep_checkpoint, only: sweep_checkpoint
   use friction_job_sweep_output, only: sweep_writer
   implicit none
   private

   public :: run_sweep_job

contains

   !> Run the sweep of `config`; a stop request (the reporter's stop_after)
   !> ends it early (the file then marks the points not done as pending and
   !> the error says so, with stat error_interrupted).
   subroutine run_sweep_job(job, config, reporter, summary, error)
      type(job_context), intent(in) :: job
      type(job_config), intent(in) :: config
      class(job_reporter), intent(inout) :: reporter
      character(len=:), allocatable, intent(out) :: summary
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: temporary, todo_path, warning
      !> points of this run whose settings the scene warns about, and the first of them
      integer :: warned, first_warned
      type(point_result), allocatable :: names(:)
      type(sweep_scheduler) :: scheduler
      type(point_transport) :: transport
      type(sweep_checkpoint) :: ckpt
      type(sweep_writer) :: writer
      type(finished_point) :: mine, theirs
      type(point_memory) :: kept   !! what this rank's points leave for its next ones
      integer :: n, n_work, i, flag, last_taken, counts(3)
      real(wp) :: wall
      character(len=12) :: seconds
      logical :: interrupted, all_failed, use_todo, arrived, stopped_inside

      names = point_names(config)
      n = config%sweep%points()
      call ckpt%init(job%output//'.ckpt', text_hash(job%input_text), n, size(names))
      todo_path = job%output//'.ckpt-todo'
      n_work = n
      use_todo = .false.
      ! --resume: the checkpoint must be of this very input and whole, or
      ! nothing is computed (README: Parameter sweeps).  Rank 0 lists the
      ! points still to do in a file every rank reads.
      if (job%rank == 0) call check_room(job, config, n, size(names), error)
      if (job%rank == 0 .and. .not. allocated(error)) then
         if (job%resume .and. file_exists(ckpt%path)) then
            call ckpt%resume(todo_path, n_work, error)
            use_todo = .not. allocated(error)
         else
            call remove_file(ckpt%path)   ! another run's, which this one does not resume
         end if
      end if
      call agree_on_error(job, error)
      if (allocated(error)) return
      if (job%parallel()) then
         call broadcast(job%comm, n_work, 0)
         call broadcast(job%comm, use_todo, 0)
      end if
      if (use_todo) then
         call scheduler%start(job, config%sweep%schedule == 'dynamic', n_work, todo_path, error)
      else
         call scheduler%start(job, config%sweep%schedule == 'dynamic', n_work, '', error)
      end if
      if (allocated(error)) return
      if (job%rank == 0) call ckpt%start_batch()

      warned = 0
      first_warned = huge(1)
      interrupted = .false.
      last_taken = 0
      do
         ! Between points: a stop request ends the sweep here, the point in hand done.
         if (reporter%stop_after(last_taken)) then
            interrupted = .true.
            exit
         end if
         call scheduler%next(i)
         if (i == 0) exit
         last_taken = i
         ! (A stop after the point before this one, which another rank may have taken.)
         if (i > 1) then
            if (reporter%stop_after(i - 1)) then
               interrupted = .true.
               exit
            end if
         end if
         call compute_point(config, i, size(names), kept, mine, warning, reporter, stopped_inside)
         ! A stop request inside the point: it stays pending (a resume computes it).
         if (stopped_inside) then
            interrupted = .true.
            exit
         end if
         if (len(warning) > 0) then
            warned = warned + 1
            first_warned = min(first_warned, i)
         end if
         if (job%rank == 0) then
            call ckpt%keep(mine)
            call take_points(.false.)
            call reporter%progress(real(ckpt%taken(), wp), real(n_work, wp), 'points', .false.)
         else
            call transport%send(job, mine)
         end if
      end do
      ! This rank has finished: it says so (and whether it was interrupted),
      ! and rank 0 takes every point still on its way.
      if (job%rank /= 0) then
         call transport%finish(job, interrupted)
      else
         call take_points(.true.)
         call ckpt%close(error)
      end if
      call scheduler%finish()
      flag = merge(1, 0, interrupted)
      call reduce_all(job%comm, flag, op_max)
      interrupted = flag /= 0
      ! One warning for the whole sweep, not one a point: how many points
      ! the scene warned about, and the first one's words.
      if (job%parallel()) then
         call reduce_all(job%comm, warned, op_sum)
         call reduce_all(job%comm, first_warned, op_min)
      end if
      if (job%rank == 0 .and. warned > 0) then
         warning = point_warning(config, first_warned)
         call reporter%note('warning: '//itoa(warned)//' of the sweep points computed in this run, the first ' &
            & //'point '//itoa(first_warned)//': '//warning)
      end if

      ! Peak resident memory of every rank, for the benchmark (docs/sweeps.md).
      allocate (writer%memory(job%nranks))
      wall = job_wall_time(job)
      call gather_to_root(job%comm, peak_memory_kb(), writer%memory)
      ! (Component by component: gfortran's structure constructor mis-sizes a
      ! deferred-length component copied from another derived type's.)
      writer%record%input_text = job%input_text
      writer%record%version = version_string
      writer%record%nranks = job%nranks
      writer%record%wall_time = wall
      writer%record%stats = integrator_statistics(0, 0, 0, 0)
      writer%interrupted = interrupted
      writer%parallel = job%parallel()
      temporary = temporary_name(job)
      counts = 0
      writer%first_reason = ''
      if (job%rank == 0 .and. .not. allocated(error)) then
         call writer%describe(config)
         call writer%write(temporary, ckpt, error)
         counts = writer%counts
      end if
      call broadcast(job%comm, counts, 0)
      ! A stop request after the last point stopped nothing: the sweep is complete.
      interrupted = interrupted .and. counts(1) + counts(2) < n
      call publish(job, temporary, error)
      if (job%rank == 0 .and. use_todo) call remove_file(todo_path)
      if (allocated(error)) return
      write (seconds, '(f12.2)') wall
      summary = itoa(counts(1) + counts(2))//' of '//itoa(n)//' sweep points done, '//itoa(counts(2)) &
         & //' failed, '//itoa(counts(3))//' computed in this run, '//trim(adjustl(seconds))//' s ' &
         & //ranks_text(job%nranks)
      if (interrupted) then
         call fatal_error(error, 'sweep interrupted; the file marks the points not done as pending ' &
            & //'(status 0): run again with --resume to compute only those', error_interrupted)
         return
      end if
      ! Complete: the checkpoint has served.
      if (job%rank == 0) call remove_file(ckpt%path)
      ! A sweep of which no point succeeded has no result to show: the file
      ! holds every point's reason, and the exit says it failed (rank 0 holds
      ! point 1's reason; its message is the one every rank returns).
      all_failed = n > 0 .and. counts(2) == n
      if (all_failed) then
         associate (first_reason => writer%first_reason)
            if (len(first_reason) > 0) first_reason = ': point 1: '//first_reason
            call fatal_error(error, 'every one of the '//itoa(n)//' sweep points failed; the file holds each ' &
               & //'point''s reason (/sweep/reason)'//first_reason, error_numerical)
         end associate
         call agree_on_error(job, error)
      end if

   contains

      !> Rank 0: keep the points the other ranks have sent; with `wait`,
      !> until every other rank has said it finished.
      subroutine take_points(wait)
         logical, intent(in) :: wait

         do
            call transport%receive(job, wait, theirs, arrived)
            if (.not. arrived) exit
            call ckpt%keep(theirs)
         end do
      end subroutine take_points

   end subroutine run_sweep_job

   !> A sweep whose file and checkpoint cannot fit on the output's disk is
   !> refused before computing, for the file holds a row for every point,
   !> pending ones too, and a full disk would lose what was computed.  Each
   !> point takes 8 bytes a column: the results, the sweep's own columns
   !> (about 8) in the file, and as many in the checkpoint.
   subroutine check_room(job, config, n, n_results, error)
      type(job_context), intent(in) :: job
      type(job_config), intent(in) :: config
      integer, intent(in) :: n, n_results
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: needed, free
      character(len=:), allocatable :: counts

      needed = 8.0_wp * real(n, wp) * (2 * n_results + 16)
      free = free_bytes(job%output)
      if (free < 0.0_wp .or. needed + min_free_bytes <= free) return
      counts = 'sweep_count = '//itoa(config%sweep%shape(1))
      if (config%sweep%n_variables == 2) counts = counts//', sweep_count2 = '//itoa(config%sweep%shape(2))
      call fatal_error(error, '&sweep: '//counts//': '//itoa(n)//' points need about '//bytes_text(needed) &
         & //' on disk for the sweep''s file and its checkpoint, but beside '//job%output//' ' &
         & //full_text(job%output, free)//'): sweep fewer points, or write the output where there is room', &
         & error_input)
   end subroutine check_room

   !> This process's peak resident set (VmHWM of /proc/self/status) in kB;
   !> 0 where there is no such file.
   integer function peak_memory_kb() result(kb)
      integer :: unit, stat
      character(len=256) :: line

      kb = 0
      open (newunit=unit, file='/proc/self/status', status='old', action='read', iostat=stat)
      if (stat /= 0) return
      do
         read (unit, '(a)', iostat=stat) line
         if (stat /= 0) exit
         if (line(1:6) == 'VmHWM:') then
            read (line(7:), *, iostat=stat) kb
            if (stat /= 0) kb = 0
            exit
         end if
      end do
      close (unit)
   end function peak_memory_kb

end module friction_job_sweep
