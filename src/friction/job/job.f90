!> A whole job from namelist files (or a configuration made in memory) to
!> an output file: what the command line runs, and what the C API's
!> friction_run_job (friction_run_config) runs.  Collective over `comm`;
!> every rank returns the same error or none.  Progress and notes go to the
!> caller's reporter (rank 0 only); nothing is printed.
module friction_job
   use mpi_f08
   use friction_kinds, only: wp
   use friction_error, only: error_type, fatal_error, error_input
   use friction_job_config, only: job_config, read_input, check_job, job_text
   use friction_checks, only: config_checker
   use friction_version, only: version_string
   use friction_files, only: file_exists, write_text_file
   use friction_scene_report, only: job_reporter
   use friction_scene_context, only: job_context, agree_on_error, check_writable, default_output, temporary_name, &
      & publish
   use friction_job_sweep, only: run_sweep_job
   implicit none
   private

   public :: run_job, run_job_config, write_netlist, job_reporter, default_output

contains

   !> Read `files` (later files override earlier ones variable by variable),
   !> run the scene or sweep they describe and write `output` (under a
   !> temporary name, renamed when complete).  An existing output is an error
   !> unless `force`, or `resume` for a sweep (which reuses the checkpoints an
   !> interrupted run left beside it).  `summary` says what was written.
   subroutine run_job(files, output, force, resume, comm, reporter, summary, error, stop_after)
      character(len=*), intent(in) :: files(:)
      character(len=*), intent(in) :: output
      logical, intent(in) :: force, resume
      !> A test hook: > 0 stops a sweep after that point as a stop request would.
      integer, intent(in), optional :: stop_after
      type(MPI_Comm), intent(in) :: comm
      class(job_reporter), intent(inout) :: reporter
      character(len=:), allocatable, intent(out) :: summary
      type(error_type), allocatable, intent(out) :: error
      type(job_context) :: job
      type(job_config) :: config

      call start_job(comm, output, resume, job)
      if (present(stop_after)) job%stop_after = stop_after
      allocate (job%files(size(files)))
      job%files = files
      if (size(files) == 0) then
         call fatal_error(error, 'no input file given', error_input)
         return
      end if
      if (len_trim(output) == 0) then
         call fatal_error(error, 'no output file given', error_input)
         return
      end if
      ! Every rank reads the input: an error in it is the same everywhere.
      call read_input(files, config, job%input_text, error)
      if (allocated(error)) return
      call run_configured(job, config, force, reporter, summary, error)
   end subroutine run_job

   !> The job of a configuration made in memory (the C API's
   !> friction_run_config) rather than read from files: checked as the
   !> files' would be (`origins`, if given, says where values were set, for
   !> the messages), echoed into the file as its namelist text, then run as
   !> run_job runs it.  Collective over `comm`; `config` is not changed.
   subroutine run_job_config(config, output, force, resume, comm, reporter, summary, error, origins)
      type(job_config), intent(in) :: config
      character(len=*), intent(in) :: output
      logical, intent(in) :: force, resume
      type(MPI_Comm), intent(in) :: comm
      class(job_reporter), intent(inout) :: reporter
      character(len=:), allocatable, intent(out) :: summary
      type(error_type), allocatable, intent(out) :: error
      type(config_checker), intent(in), optional :: origins
      type(job_context) :: job
      type(job_config) :: work
      type(config_checker) :: checker

      call start_job(comm, output, resume, job)
      allocate (job%files(0))
      if (len_trim(output) == 0) then
         call fatal_error(error, 'no output file given', error_input)
         return
      end if
      if (.not. allocated(config%scene)) then
         call fatal_error(error, 'the configuration has no scene', error_input)
         return
      end if
      work = config
      if (present(origins)) checker = origins
      call check_job(work, checker)
      if (checker%failed()) then
         call move_alloc(checker%error, error)
         return
      end if
      job%input_text = job_text(work)
      call run_configured(job, work, force, reporter, summary, error)
   end subroutine run_job_config

   !> A job's context on `comm`, its clock started.
   subroutine start_job(comm, output, resume, job)
      type(MPI_Comm), intent(in) :: comm
      character(len=*), intent(in) :: output
      logical, intent(in) :: resume
      type(job_context), intent(out) :: job

      job%t_start = MPI_Wtime()
      job%comm = comm
      call MPI_Comm_rank(comm, job%rank)
      call MPI_Comm_size(comm, job%nranks)
      job%output = output
      job%resume = resume
   end subroutine start_job

   !> The common body of run_job and run_job_config: a checked
   !> configuration, its echo in job%input_text, run and written.
   subroutine run_configured(job, config, force, reporter, summary, error)
      type(job_context), intent(inout) :: job
      type(job_config), intent(inout) :: config
      logical, intent(in) :: force
      class(job_reporter), intent(inout) :: reporter
      character(len=:), allocatable, intent(out) :: summary
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: temporary

      if (file_exists(job%output) .and. .not. (force .or. (job%resume .and. config%sweep%enabled()))) then
         call fatal_error(error, job%output//': the output file exists; use --force to overwrite it', error_input)
         return
      end if
      ! Find out now, not after the computation, whether the output can be written.
      if (job%rank == 0) call check_writable(job%output, error)
      call agree_on_error(job, error)
      if (allocated(error)) return

      if (config%sweep%enabled()) then
         call run_sweep_job(job, config, reporter, summary, error)
         return
      end if
      call config%scene%run(job, reporter, error)
      if (allocated(error)) return
      temporary = temporary_name(job)
      call config%scene%write_output(temporary, job, error)
      call publish(job, temporary, error)
      if (allocated(error)) return
      summary = config%scene%summary(job)
   end subroutine run_configured

   !> The scene of `files` as a SPICE netlist for ngspice (the paper's
   !> network model, docs/netlist.md) in `path`, its waveforms going to
   !> the same name with .data; nothing is integrated.  Rank 0 writes; every
   !> rank returns the same error or none.  `summary` says what was written.
   subroutine write_netlist(files, path, force, comm, reporter, summary, error)
      character(len=*), intent(in) :: files(:)
      character(len=*), intent(in) :: path
      logical, intent(in) :: force
      type(MPI_Comm), intent(in) :: comm
      class(job_reporter), intent(inout) :: reporter
      character(len=:), allocatable, intent(out) :: summary
      type(error_type), allocatable, intent(out) :: error
      type(job_context) :: job
      type(job_config) :: config
      character(len=:), allocatable :: text, note, data_file
      integer :: dot

      job%comm = comm
      call MPI_Comm_rank(comm, job%rank)
      call MPI_Comm_size(comm, job%nranks)
      call read_input(files, config, job%input_text, error)
      if (allocated(error)) return
      dot = index(path, '.', back=.true.)
      if (dot > index(path, '/', back=.true.) + 1) then
         data_file = path(1:dot - 1)//'.data'
      else
         data_file = path//'.data'
      end if
      if (config%sweep%enabled()) then
         call fatal_error(error, '--netlist writes one scene: a &sweep group is not supported '// &
            & '(write one point with an override file instead)', error_input)
         return
      end if
      call config%scene%netlist(data_file, version_string, text, note, error)
      if (allocated(error)) return
      if (file_exists(path) .and. .not. force) then
         call fatal_error(error, path//': the netlist file exists; use --force to overwrite it', error_input)
         return
      end if
      if (job%rank == 0) call write_text_file(path, text, error)
      call agree_on_error(job, error)
      if (allocated(error)) return
      if (job%rank == 0 .and. len(note) > 0) call reporter%note('note: '//note)
      summary = 'run: ngspice -b '//path//'; waveforms to '//data_file
   end subroutine write_netlist

end module friction_job
