!> A whole job from namelist files (or a configuration made in memory) to
!> an output file: what the command line runs, and what the C API's
!> friction_run_job (friction_run_config) runs.  Collective over `comm`;
!> every rank returns the same error or none.  Progress and notes go to the
!> caller's reporter (rank 0 only); nothing is printed.
module friction_job
   use friction_parallel, only: communicator, broadcast, reduce_all, op_max
   use friction_kinds, only: wp
   use friction_clock, only: wall_seconds
   use friction_error, only: error_type, fatal_error, error_input
   use friction_job_config, only: job_config, read_input, check_job, job_text
   use friction_checks, only: config_checker
   use friction_version, only: version_string
   use friction_files, only: file_exists, write_text_file, output_problem, same_file, path_kind, kind_regular
   use friction_strings, only: text_hash
   use friction_scene_report, only: job_reporter
   use friction_scene_context, only: job_context, agree_on_error, check_writable, default_output, temporary_name, &
      & publish
   use friction_job_sweep, only: run_sweep_job
   implicit none
   private

   public :: run_job, run_job_config, write_netlist, resolve_input, job_reporter, default_output

contains

   !> Read `files` (later files override earlier ones variable by variable),
   !> run the scene or sweep they describe and write `output` (under a
   !> temporary name, renamed when complete).  An existing output is an error
   !> unless `force`, or `resume` for a sweep (which reuses the checkpoints an
   !> interrupted run left beside it).  `summary` says what was written.
   !> `overrides` ('group.variable=value') apply after the files, in order.
   subroutine run_job(files, output, force, resume, comm, reporter, summary, error, overrides)
      character(len=*), intent(in) :: files(:)
      character(len=*), intent(in) :: output
      logical, intent(in) :: force, resume
      character(len=*), intent(in), optional :: overrides(:)
      type(communicator), intent(in) :: comm
      class(job_reporter), intent(inout) :: reporter
      character(len=:), allocatable, intent(out) :: summary
      type(error_type), allocatable, intent(out) :: error
      type(job_context) :: job
      type(job_config) :: config

      call start_job(comm, output, resume, job)
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

      ! Every rank reads the input.  An error in a file is the same everywhere,
      ! but not when a rank cannot read what another read (a pipe reaches
      ! rank 0 only): the ranks agree on an error and on the text they read.
      call read_job_input(job, files, overrides, reporter, config, error)
      if (allocated(error)) return
      call check_same_input(job, error)
      if (allocated(error)) return
      call run_configured(job, config, force, reporter, summary, error)
   end subroutine run_job

   !> The job of a configuration made in memory (the C API's
   !> friction_run_config) rather than read from files: checked as the
   !> files' would be (`origins`, if given, says where values were set, for
   !> the messages), echoed into the file as its namelist text, then run as
   !> run_job runs it.  Collective over `comm`; `config` is not changed.
   subroutine run_job_config(config, output, force, resume, comm, reporter, summary, error, origins, files)
      type(job_config), intent(in) :: config
      character(len=*), intent(in) :: output
      logical, intent(in) :: force, resume
      type(communicator), intent(in) :: comm
      class(job_reporter), intent(inout) :: reporter
      character(len=:), allocatable, intent(out) :: summary
      type(error_type), allocatable, intent(out) :: error
      type(config_checker), intent(in), optional :: origins
      !> the files the configuration was read from (the output must be none of them)
      character(len=*), intent(in), optional :: files(:)
      type(job_context) :: job
      type(job_config) :: work
      type(config_checker) :: checker

      call start_job(comm, output, resume, job)
      allocate (job%files(0))
      if (present(files)) job%files = files
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

   !> The resolved input of `files` and `overrides` (all applied, defaults
   !> filled, checked) as the namelist text a run echoes into its output,
   !> which reads back to the same run, each variable's unit a comment after
   !> it; nothing is computed or written.
   !> Collective over `comm`; warnings go to the reporter.
   subroutine resolve_input(files, comm, reporter, text, error, overrides)
      character(len=*), intent(in) :: files(:)
      type(communicator), intent(in) :: comm
      class(job_reporter), intent(inout) :: reporter
      character(len=:), allocatable, intent(out) :: text
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in), optional :: overrides(:)
      type(job_context) :: job
      type(job_config) :: config

      call set_comm(comm, job)
      call read_job_input(job, files, overrides, reporter, config, error, units=.true.)
      if (allocated(error)) return
      text = job%input_text
   end subroutine resolve_input

   !> Read the input into `config` and `job%input_text` on every rank, the
   !> ranks agreeing on an error; rank 0 passes the reader's warnings on.
   !> With `units`, the text has each variable's unit as a comment.
   subroutine read_job_input(job, files, overrides, reporter, config, error, units, origins)
      type(job_context), intent(inout) :: job
      character(len=*), intent(in) :: files(:)
      character(len=*), intent(in), optional :: overrides(:)
      class(job_reporter), intent(inout) :: reporter
      type(job_config), intent(out) :: config
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: units
      type(config_checker), intent(out), optional :: origins
      character(len=1024), allocatable :: notes(:)
      integer :: k

      call read_input(files, config, job%input_text, error, overrides, notes, units, origins)
      call name_unread_pipe(job, files, error)
      call agree_on_error(job, error)
      if (allocated(error)) return
      if (job%rank == 0) then
         do k = 1, size(notes)
            call reporter%note(trim(notes(k)))
         end do
      end if
   end subroutine read_job_input

   !> A job's context on `comm`, its clock started.
   subroutine start_job(comm, output, resume, job)
      type(communicator), intent(in) :: comm
      character(len=*), intent(in) :: output
      logical, intent(in) :: resume
      type(job_context), intent(out) :: job

      job%t_start = wall_seconds()
      call set_comm(comm, job)
      job%output = output
      job%resume = resume
   end subroutine start_job

   !> The job's communicator, rank and size; one not attached: serial, MPI not started.
   subroutine set_comm(comm, job)
      type(communicator), intent(in) :: comm
      type(job_context), intent(inout) :: job

      job%comm = comm
      job%rank = 0
      job%nranks = 1
      if (.not. job%parallel()) return
      job%rank = comm%rank()
      job%nranks = comm%size()
   end subroutine set_comm

   !> The common body of run_job and run_job_config: a checked
   !> configuration, its echo in job%input_text, run and written.
   subroutine run_configured(job, config, force, reporter, summary, error)
      type(job_context), intent(inout) :: job
      type(job_config), intent(inout) :: config
      logical, intent(in) :: force
      class(job_reporter), intent(inout) :: reporter
      character(len=:), allocatable, intent(out) :: summary
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: temporary, warning

      job%replace = force .or. (job%resume .and. config%sweep%enabled())
      ! Find out now, not after the computation, whether the output can be written.
      if (job%rank == 0) call check_output(job, error)
      if (job%rank == 0 .and. .not. allocated(error)) call check_writable(job%output, error)
      call agree_on_error(job, error)
      if (allocated(error)) return

      if (config%sweep%enabled()) then
         call run_sweep_job(job, config, reporter, summary, error)
         return
      end if
      ! (A sweep says its points' warnings once, at its end.)
      if (job%rank == 0) then
         warning = config%scene%settings_warning()
         if (len(warning) > 0) call reporter%note('warning: '//warning)
      end if
      call config%scene%run(job, reporter, error)
      if (allocated(error)) return
      temporary = temporary_name(job)
      call config%scene%write_output(temporary, job, error)
      call publish(job, temporary, error)
      if (allocated(error)) return
      summary = config%scene%summary(job)
   end subroutine run_configured

   !> A rank other than 0 that cannot read an input file that is not a
   !> regular one, while rank 0 could: a pipe given to a job of many ranks
   !> reaches rank 0 alone (the others see /dev/null as /dev/stdin, and were
   !> told to 'give a regular file or a pipe').  The error says so instead.
   subroutine name_unread_pipe(job, files, error)
      type(job_context), intent(in) :: job
      character(len=*), intent(in) :: files(:)
      type(error_type), allocatable, intent(inout) :: error
      integer :: rank0_failed, k

      if (.not. job%parallel()) return
      rank0_failed = merge(1, 0, allocated(error))
      call broadcast(job%comm, rank0_failed, 0)
      if (job%rank == 0 .or. rank0_failed /= 0 .or. .not. allocated(error)) return
      do k = 1, size(files)
         if (path_kind(trim(files(k)), follow=.true.) /= kind_regular) then
            call fatal_error(error, trim(files(k))//': not a regular file (a pipe or a device?): rank 0 read ' &
               & //'it, but on more than one rank every rank reads the input itself, and a pipe reaches rank 0 ' &
               & //'alone; give a regular file, or run on one rank', error_input)
            return
         end if
      end do
   end subroutine name_unread_pipe

   !> Every rank must have read the same input: compare the hash of each
   !> rank's resolved input with rank 0's.  When they differ, name an input
   !> that is not a regular file (a pipe, /dev/stdin), the usual cause.
   subroutine check_same_input(job, error)
      type(job_context), intent(in) :: job
      type(error_type), allocatable, intent(out) :: error
      character(len=16) :: hash
      integer :: differs, k, culprit

      if (.not. job%parallel()) return
      hash = text_hash(job%input_text)
      call broadcast(job%comm, hash, 0)
      differs = merge(1, 0, hash /= text_hash(job%input_text))
      call reduce_all(job%comm, differs, op_max)
      if (differs == 0) return
      culprit = 0
      do k = 1, size(job%files)
         if (path_kind(trim(job%files(k)), follow=.true.) /= kind_regular) then
            culprit = k
            exit
         end if
      end do
      if (culprit > 0) then
         call fatal_error(error, trim(job%files(culprit))//': not a regular file (a pipe or a device?): on ' &
            & //'more than one rank every rank reads the input itself, and they read different text; give ' &
            & //'a regular file, or run on one rank', error_input)
      else
         call fatal_error(error, 'the ranks read different input (did a file change while it was read?)', &
            & error_input)
      end if
   end subroutine check_same_input

   !> The output must be writable without harm: not a link, device or
   !> directory; an existing regular file only with `replace`; and never one
   !> of the job's input files (a namelist file, or a file a namelist names
   !> such as an XYZ net).
   subroutine check_output(job, error)
      type(job_context), intent(in) :: job
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: problem, named
      integer :: k, from

      problem = output_problem(job%output, job%replace)
      if (len(problem) > 0) then
         call fatal_error(error, job%output//': '//problem, error_input)
         return
      end if
      do k = 1, size(job%files)
         if (same_file(job%output, trim(job%files(k)))) then
            call fatal_error(error, job%output//': the output is the input file '//trim(job%files(k)) &
               & //'; name another output (-o FILE)', error_input)
            return
         end if
      end do
      ! Quoted values of the resolved input that name files.
      from = 0
      do
         k = index(job%input_text(from + 1:), "'")
         if (k == 0) exit
         from = from + k
         k = index(job%input_text(from + 1:), "'")
         if (k == 0) exit
         named = job%input_text(from + 1:from + k - 1)
         from = from + k
         if (len(named) == 0) cycle
         if (same_file(job%output, named)) then
            call fatal_error(error, job%output//': the output is the input file '//named &
               & //'; name another output (-o FILE)', error_input)
            return
         end if
      end do
   end subroutine check_output

   !> The scene of `files` as a SPICE netlist for ngspice (the paper's
   !> network model, docs/netlist.md) in `path`, its waveforms going to
   !> the same name with .data; nothing is integrated.  Rank 0 writes; every
   !> rank returns the same error or none.  `summary` says what was written.
   subroutine write_netlist(files, path, force, comm, reporter, summary, error, overrides)
      character(len=*), intent(in) :: files(:)
      character(len=*), intent(in), optional :: overrides(:)
      character(len=*), intent(in) :: path
      logical, intent(in) :: force
      type(communicator), intent(in) :: comm
      class(job_reporter), intent(inout) :: reporter
      character(len=:), allocatable, intent(out) :: summary
      type(error_type), allocatable, intent(out) :: error
      type(job_context) :: job
      type(job_config) :: config
      type(config_checker) :: origins
      character(len=:), allocatable :: text, note, data_file, problem
      integer :: dot, k

      call set_comm(comm, job)
      call read_job_input(job, files, overrides, reporter, config, error, origins=origins)
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
      call config%scene%netlist(data_file, version_string, text, note, error, origins)
      if (allocated(error)) return
      if (file_exists(path) .and. .not. force) then
         call fatal_error(error, path//': the netlist file exists; use --force to overwrite it', error_input)
         return
      end if
      if (job%rank == 0) then
         problem = output_problem(path, force)
         if (len(problem) > 0) call fatal_error(error, path//': '//problem, error_input)
         do k = 1, size(files)
            if (.not. allocated(error) .and. same_file(path, trim(files(k)))) call fatal_error(error, &
               & path//': the netlist is the input file '//trim(files(k))//'; name another file', error_input)
         end do
         if (.not. allocated(error)) call write_text_file(path, text, error, replace=force)
      end if
      call agree_on_error(job, error)
      if (allocated(error)) return
      if (job%rank == 0 .and. len(note) > 0) call reporter%note('note: '//note)
      summary = 'run: ngspice -b '//path//'; waveforms to '//data_file
   end subroutine write_netlist

end module friction_job
