!> friction: friction-force maps of a microscope tip over a crystal surface,
!> the stick-slip of a Girling brake, and parameter sweeps of both.
!>
!>   mpirun -n N friction [options] FILE.nml [MORE.nml ...]
!>
!> The only place that prints and sets the exit code.  The job itself is the
!> library's run_job (src/friction/job/); this program parses the command
!> line, shows the job's progress and notes on stderr, and turns its error
!> into a message and an exit code.
!>
!> MPI is started only for a job launched by an MPI launcher (mpirun, srun,
!> mpiexec: see launched()) or with FRICTION_MPI=1; any other run is serial,
!> through the same job code, without MPI_Init and its start-up time.
!> --help, --version, --netlist and usage errors never start MPI.  The same
!> code makes two programs (docs/layout.md, The two programs): friction,
!> serial, which loads no MPI library and hands a launched job to the
!> parallel program friction-mpi beside it (hand_over), and friction-mpi.
module friction_app_cli
   use, intrinsic :: iso_c_binding, only: c_int, c_char, c_null_char
   use, intrinsic :: iso_fortran_env, only: error_unit, output_unit
   use friction_parallel, only: communicator, serial_comm, world_comm, parallel_built, start_parallel, &
      & finish_parallel, parallel_library
   use friction_error, only: error_type, error_input, error_io, error_interrupted, fatal_error
   use friction_version, only: version_string, revision_string, compiler_string, hdf5_version_string, &
      & gsl_version_string, fftw_version_string, cpu_target_string, table_kernels_string
   use friction_job, only: run_job, write_netlist, resolve_input, default_output
   use friction_clock, only: wall_seconds
   use friction_app_terminal_reporter, only: terminal_reporter, say, write_fd
   implicit none
   private

   public :: run_program

   interface
      !> The C library's exit: a status code without the runtime's backtrace.
      subroutine c_exit(status) bind(c, name='exit')
         import :: c_int
         integer(c_int), value :: status
      end subroutine c_exit
      subroutine friction_ignore_write_signals() bind(c)
      end subroutine friction_ignore_write_signals
      !> Run `name` from this program's directory in this process, with the
      !> same arguments (app/hand_over.c); returns only if it could not, with
      !> the path tried and why in `message` (NUL-terminated).
      subroutine friction_hand_over(name, message, length) bind(c)
         import :: c_int, c_char
         character(kind=c_char), intent(in) :: name(*)
         character(kind=c_char), intent(out) :: message(*)
         integer(c_int), value :: length
      end subroutine friction_hand_over
   end interface

   integer, parameter :: exit_usage = 2, exit_input = 3, exit_numerical = 4, exit_io = 5, exit_interrupted = 6, &
      & exit_no_parallel = 7

   !> The program that runs launched jobs, installed beside this one.
   character(len=*), parameter :: parallel_program = 'friction-mpi'

   type :: options
      character(len=:), allocatable :: output
      character(len=:), allocatable :: netlist   !! --netlist FILE: write the network model, do not integrate
      logical :: force = .false.
      logical :: quiet = .false.
      logical :: resume = .false.
      logical :: print_input = .false.           !! --print-input: print the resolved input, run nothing
      !> As long as the longest argument, so none is cut short (a --set of a
      !> long list of sweep values is as long as it needs to be).
      character(len=:), allocatable :: files(:) !! files(1:nfiles), the input files in order
      character(len=:), allocatable :: sets(:)  !! sets(1:nsets), --set group.variable=value, in order
      integer :: nfiles = 0, nsets = 0
   end type options

contains

   !> The whole program, talking to the user through `reporter` (the
   !> terminal's, or a test's that extends it); ends the process with the
   !> exit code.
   subroutine run_program(reporter)
      class(terminal_reporter), intent(inout) :: reporter
      type(options) :: opts
      type(error_type), allocatable :: error
      character(len=:), allocatable :: summary, text
      integer :: rank, code, stat
      character(len=:), allocatable :: message
      logical :: mpi_started
      type(communicator) :: comm

      mpi_started = .false.
      reporter%t_start = wall_seconds()
      ! A closed stderr or stdout and a file-size limit fail the write instead
      ! of killing the program (app/signals.c).
      call friction_ignore_write_signals()
      ! Until MPI starts (if it does), the launcher's rank says who prints.
      rank = launcher_rank()

      code = parse_arguments(opts)
      if (code >= 0) call finish(code)
      reporter%quiet = opts%quiet
      comm = serial_comm()
      if (opts%print_input) then
         ! One process prints the resolved input, without MPI.
         if (rank /= 0) call finish(0)
         call resolve_input(opts%files(1:opts%nfiles), comm, reporter, text, error, opts%sets(1:opts%nsets))
         if (.not. allocated(error)) then
            ! Through the C library: gfortran's write and flush report success on /dev/full.
            call write_fd(1, text, message)
            if (len(message) > 0) call fatal_error(error, 'cannot write the input to standard output (' &
               & //message//')', error_io)
         end if
         opts%output = ''
      else if (allocated(opts%netlist)) then
         ! One process writes the netlist, without MPI: the others of a launch have nothing to do.
         if (rank /= 0) call finish(0)
         call write_netlist(opts%files(1:opts%nfiles), opts%netlist, opts%force, comm, reporter, summary, error, &
            & opts%sets(1:opts%nsets))
         opts%output = opts%netlist
      else
         if (launched() .or. forced_mpi()) then
            if (.not. parallel_built()) call hand_over()
            call start_parallel(.false., stat)
            mpi_started = .true.
            comm = world_comm()
            rank = comm%rank()
         end if
         call warn_lone_tasks(comm)
         if (.not. allocated(opts%output)) opts%output = default_output(opts%files(1))
         call run_job(opts%files(1:opts%nfiles), opts%output, opts%force, opts%resume, comm, reporter, summary, &
            & error, overrides=opts%sets(1:opts%nsets))
      end if
      ! An interrupted sweep has written its file: say what it holds, then why it stopped.
      if (rank == 0 .and. .not. opts%quiet .and. allocated(summary)) &
         & call say(reporter, 'friction: wrote '//opts%output//' ('//summary//')')
      if (allocated(error)) then
         ! Every rank holds the same error (the library agrees on one): rank 0 says it.
         if (rank == 0) then
            if (error%stat == error_interrupted) then
               call say(reporter, 'friction: '//error%message)
            else
               call say(reporter, 'friction: error: '//error%message)
            end if
         end if
         call finish(exit_code(error))
      end if
      call finish(0)

   contains

      !> The serial program under a launcher (or FRICTION_MPI=1): the parallel
      !> program beside it runs the job, in this process, with the same
      !> arguments.  Without it, every rank stops with exit code 7 (rank 0 says why).
      subroutine hand_over()
         character(kind=c_char) :: buffer(4096)
         character(len=:), allocatable :: why
         integer :: k

         call friction_hand_over(parallel_program//c_null_char, buffer, int(size(buffer), c_int))
         why = ''
         do k = 1, size(buffer)
            if (buffer(k) == c_null_char) exit
            why = why//buffer(k)
         end do
         if (rank == 0) call say(reporter, 'friction: error: this program is serial, and a launcher started it ' &
            & //'(or FRICTION_MPI=1 asked for MPI); the parallel program that runs such jobs cannot be started: ' &
            & //why//'; install '//parallel_program//' beside friction (it is built and installed with it), ' &
            & //'or run without a launcher')
         call finish(exit_no_parallel)
      end subroutine hand_over


      !> Whether an MPI launcher started this process: Open MPI's mpirun
      !> (OMPI_COMM_WORLD_SIZE, OMPI_UNIVERSE_SIZE), any PMIx launcher (PMIX_RANK:
      !> Open MPI 5, srun --mpi=pmix), or a PMI one (PMI_RANK, PMI_SIZE: MPICH's
      !> mpiexec, srun --mpi=pmi2).  Without one, a run is serial.
      logical function launched()
         character(len=*), parameter :: names(5) = [character(len=20) :: 'OMPI_COMM_WORLD_SIZE', &
            & 'OMPI_UNIVERSE_SIZE', 'PMIX_RANK', 'PMI_RANK', 'PMI_SIZE']
         integer :: k, length, stat

         launched = .false.
         do k = 1, size(names)
            call get_environment_variable(trim(names(k)), length=length, status=stat)
            if (stat == 0) launched = .true.
         end do
      end function launched

      !> Slurm started this step with several tasks (SLURM_STEP_NUM_TASKS > 1)
      !> but they are not one MPI job here (no MPI launch reached the process, or
      !> MPI_Init made each a job of one: a plain srun where the site's MPI needs
      !> --mpi=pmix): each task would compute the whole job alone and write the
      !> same output.  Task 0 says so; the run goes on as asked.
      subroutine warn_lone_tasks(comm)
         type(communicator), intent(in) :: comm
         character(len=32) :: text
         integer :: tasks, ranks, length, stat

         call get_environment_variable('SLURM_STEP_NUM_TASKS', text, length, stat)
         if (stat /= 0 .or. length == 0) return
         read (text, *, iostat=stat) tasks
         if (stat /= 0 .or. tasks <= 1) return
         ranks = comm%size()
         if (ranks > 1 .or. launcher_rank() /= 0) return
         write (error_unit, '(a,i0,a)') 'friction: warning: Slurm started ', tasks, ' tasks, but they are not one '// &
            & 'MPI job: each runs the whole job alone and writes the same output. Launch with srun --mpi=pmix '// &
            & '(srun --mpi=list shows what the site has) or mpirun; scripts/friction.slurm chooses (docs/cli.md)'
      end subroutine warn_lone_tasks

      !> FRICTION_MPI=1: start MPI even without a launcher (a singleton run,
      !> as `mpirun -n 1` would; docs/cli.md).
      logical function forced_mpi()
         character(len=8) :: text
         integer :: stat

         call get_environment_variable('FRICTION_MPI', text, status=stat)
         forced_mpi = stat == 0 .and. trim(text) == '1'
      end function forced_mpi

      !> This process's rank as its launcher set it (0 without a launcher), so
      !> that under mpirun only rank 0 prints help, version and usage errors.
      integer function launcher_rank() result(r)
         character(len=*), parameter :: names(4) = [character(len=21) :: 'OMPI_COMM_WORLD_RANK', 'PMIX_RANK', &
            & 'PMI_RANK', 'SLURM_PROCID']
         character(len=32) :: text
         integer :: k, length, stat

         r = 0
         do k = 1, size(names)
            call get_environment_variable(trim(names(k)), text, length, stat)
            if (stat /= 0 .or. length == 0) cycle
            read (text, *, iostat=stat) r
            if (stat /= 0) r = 0
            return
         end do
      end function launcher_rank

      !> The command line's arguments with bundled short options split, as
      !> getopt does: -fq is -f -q, and -fqo FILE is -f -q -o FILE.  An
      !> argument is split only where an option is expected (not the value of
      !> -o, --output, --netlist or --set).  Returns -1, or the exit code of a
      !> bundle that puts -o before other letters.
      integer function split_arguments(argv, n) result(code)
         character(len=:), allocatable, intent(out) :: argv(:)
         integer, intent(out) :: n
         character(len=:), allocatable :: arg
         integer :: i, k, count, width, length
         logical :: value_next

         code = -1
         count = command_argument_count()
         width = 2
         n = 0
         do i = 1, count
            call get_command_argument(i, length=length)
            width = max(width, length)
            n = n + max(1, length - 1)
         end do
         allocate (character(len=width) :: arg, argv(max(n, 1)))
         n = 0
         value_next = .false.
         do i = 1, count
            call get_command_argument(i, arg)
            if (.not. value_next .and. is_bundle(arg)) then
               do k = 2, len_trim(arg)
                  if (arg(k:k) == 'o' .and. k < len_trim(arg)) then
                     code = usage_error('in '//trim(arg)//', -o must come last (it takes the file name after it)')
                     return
                  end if
                  n = n + 1
                  argv(n) = '-'//arg(k:k)
               end do
               value_next = arg(len_trim(arg):len_trim(arg)) == 'o'
            else
               n = n + 1
               argv(n) = arg
               value_next = .not. value_next .and. any(trim(arg) == [character(len=9) :: '-o', '--output', &
                  & '--netlist', '--set'])
            end if
         end do
      end function split_arguments

      !> A bundle of short options: a dash and two or more letters (-fq).
      logical function is_bundle(arg)
         character(len=*), intent(in) :: arg
         integer :: k

         is_bundle = len_trim(arg) > 2 .and. arg(1:1) == '-' .and. arg(2:2) /= '-'
         do k = 2, len_trim(arg)
            if (.not. is_bundle) return
            is_bundle = verify(arg(k:k), 'abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ') == 0
         end do
      end function is_bundle

      !> Arguments; returns -1 to go on, else the exit code to finish with.
      integer function parse_arguments(opts) result(code)
         type(options), intent(inout) :: opts
         character(len=:), allocatable :: arg, argv(:)
         integer :: i, n

         code = split_arguments(argv, n)
         if (code >= 0) return
         allocate (character(len=len(argv)) :: arg)
         allocate (character(len=len(argv)) :: opts%files(n), opts%sets(n))
         i = 0
         do while (i < n)
            i = i + 1
            arg = argv(i)
            select case (trim(arg))
            case ('-h', '--help')
               if (rank == 0) call print_help()
               code = 0
               return
            case ('-V', '--version')
               stat = 0
               if (rank == 0) call print_version(stat)
               if (stat /= 0) reporter%lost = .true.
               code = 0
               return
            case ('-o', '--output')
               if (i == n) then
                  code = usage_error('option '//trim(arg)//' needs a file name')
                  return
               end if
               i = i + 1
               arg = argv(i)
               if (len_trim(arg) == 0) then
                  code = usage_error('option -o needs a file name, not an empty one')
                  return
               end if
               opts%output = trim(arg)
            case ('--netlist')
               if (i == n) then
                  code = usage_error('option --netlist needs a file name (the SPICE netlist to write)')
                  return
               end if
               i = i + 1
               arg = argv(i)
               if (len_trim(arg) == 0 .or. arg(1:1) == '-') then
                  code = usage_error('option --netlist needs a file name (the SPICE netlist to write), not "' &
                     & //trim(arg)//'"')
                  return
               end if
               opts%netlist = trim(arg)
            case ('--set')
               if (i == n) then
                  code = usage_error('option --set needs group.variable=value')
                  return
               end if
               i = i + 1
               arg = argv(i)
               if (index(arg, '=') == 0) then
                  code = usage_error('option --set needs group.variable=value (e.g. --set tip.kx=12.5), not "' &
                     & //trim(arg)//'"')
                  return
               end if
               opts%nsets = opts%nsets + 1
               opts%sets(opts%nsets) = arg
            case ('--print-input')
               opts%print_input = .true.
            case ('-f', '--force')
               opts%force = .true.
            case ('-q', '--quiet')
               opts%quiet = .true.
            case ('--resume')
               opts%resume = .true.
            case default
               if (arg(1:1) == '-') then
                  code = usage_error('unknown option '//trim(arg))
                  return
               end if
               opts%nfiles = opts%nfiles + 1
               opts%files(opts%nfiles) = arg
            end select
         end do
         if (opts%nfiles == 0) code = usage_error('no input file given')
         if (code < 0 .and. opts%print_input .and. (allocated(opts%output) .or. allocated(opts%netlist) .or. &
            & opts%resume)) code = usage_error('--print-input writes nothing: it takes no -o, --netlist or --resume')
      end function parse_arguments

      integer function usage_error(message) result(code)
         character(len=*), intent(in) :: message

         if (rank == 0) call say(reporter, 'friction: '//message// &
            & new_line('a')//'usage: friction [options] FILE.nml [MORE.nml ...]  (friction --help)')
         code = exit_usage
      end function usage_error

      subroutine print_help()
         write (output_unit, '(a)', iostat=stat) &
            & 'usage: [mpirun -n N] friction [options] FILE.nml [MORE.nml ...]', &
            & '', &
            & 'Friction-force maps of a microscope tip dragged over a crystal surface', &
            & '(NaF, HOPG): the tip''s equations of motion integrated with GSL odeiv2,', &
            & 'scan lines shared among MPI ranks, results in one HDF5 file.', &
            & 'With &job scene = ''brake'': the stick-slip of a Girling brake (one', &
            & 'trajectory; inputs/brake.nml; groups &brake &brake_dimensional &verify &analysis).', &
            & 'With a &sweep group: a parameter sweep of either scene over the MPI ranks, one or two', &
            & 'variables (inputs/brake_sweep.nml, inputs/afm_sweep.nml; docs/sweeps.md).', &
            & 'Without mpirun (or srun) the run is serial and does not start MPI; FRICTION_MPI=1', &
            & 'starts it anyway (docs/cli.md).', &
            & '', &
            & 'Input files are namelist files read in order; a later file overrides', &
            & 'earlier values variable by variable, and --set values override the files.', &
            & 'Groups: &job &surface &tip &scan &integrator &verify &thermal (see docs/input.md).', &
            & 'A group of another scene is ignored with a warning when &job names the scene,', &
            & 'and is an error when the scene is the default (afm): &job is missing.', &
            & '', &
            & 'options:', &
            & '  -o, --output FILE  output file (default: first input''s name with .h5,', &
            & '                     in the current directory)', &
            & '  -f, --force        overwrite an existing output file', &
            & '  -q, --quiet        no progress or summary on stderr', &
            & '      --set GROUP.VARIABLE=VALUE', &
            & '                     set one variable after the files (repeatable, in order;', &
            & '                     checked as a file''s: e.g. --set tip.kx=12.5,', &
            & '                     --set "integrator.method=''rk8pd''", --set surface.sigma(2)=3.4)', &
            & '      --print-input  print the resolved input (files and --set applied,', &
            & '                     defaults filled) as a namelist that reads back to the', &
            & '                     same run, each variable''s unit a comment after it, and', &
            & '                     exit without computing or writing', &
            & '      --resume       reuse the sweep points or map lines an interrupted run', &
            & '                     completed (its checkpoints beside the output); a sweep''s', &
            & '                     output is overwritten', &
            & '      --netlist FILE write the scene as a SPICE netlist for ngspice (the paper''s', &
            & '                     network model) and exit without integrating: the brake', &
            & '                     (arctan law), or line 0 (trace) of a NaF or HOPG map;', &
            & '                     ngspice -b FILE writes FILE.data (docs/netlist.md)', &
            & '  -h, --help         this help', &
            & '  -V, --version      the version, the compiler, MPI, HDF5, GSL and FFTW it was', &
            & '                     built with, the source revision and the kernels chosen', &
            & 'Short options bundle: -fq is -f -q; -fo FILE is -f -o FILE.', &
            & '', &
            & 'exit codes: 0 done, 2 usage, 3 bad input, 4 integration failed, 5 output failed', &
            & '            (a full disk, ulimit -f, or stderr or stdout closed: 2>&1 | head),', &
            & '            6 interrupted (a sweep''s file written with the points done, a map''s', &
            & '            lines done checkpointed, --resume; a brake trajectory: nothing written),', &
            & '            7 launched, but the parallel program friction-mpi is missing beside friction'
         if (stat /= 0) reporter%lost = .true.
      end subroutine print_help

      !> The version's first line as before (scripts read it), then what the
      !> program was built with and what it chooses on this processor.  MPI's
      !> is the library's own (the serial program has none).
      subroutine print_version(stat)
         integer, intent(out) :: stat
         character(len=:), allocatable :: cpu

         cpu = cpu_target_string
         if (len(cpu) == 0) cpu = 'the compiler''s default'
         write (output_unit, '(a)', iostat=stat) 'friction '//version_string, &
            & '  revision     '//revision_string, &
            & '  compiler     '//compiler_string//' (processor level: '//cpu//')', &
            & '  MPI          '//parallel_library(), &
            & '  HDF5         '//hdf5_version_string//trim(merge(' (parallel)', ' (serial)  ', parallel_built())), &
            & '  GSL          '//gsl_version_string, &
            & '  FFTW         '//fftw_version_string, &
            & '  kernels      the surface table''s: '//table_kernels_string()
      end subroutine print_version

      integer function exit_code(error)
         type(error_type), intent(in) :: error

         select case (error%stat)
         case (error_input)
            exit_code = exit_input
         case (error_io)
            exit_code = exit_io
         case (error_interrupted)
            exit_code = exit_interrupted
            ! Stopped because stderr was lost (a closed pipe): an I/O error.
            if (reporter%lost) exit_code = exit_io
         case default
            exit_code = exit_numerical
         end select
      end function exit_code

      !> Flush first: what the run said must reach stderr even if finalizing fails.
      subroutine finish(code)
         integer, intent(in) :: code
         integer :: status

         flush (error_unit, iostat=stat)
         flush (output_unit, iostat=stat)
         if (mpi_started) call finish_parallel()
         flush (error_unit, iostat=stat)
         flush (output_unit, iostat=stat)
         status = code
         ! A run whose stderr was lost (its notes and summary unsaid) ends with
         ! the I/O error's code, even when its file was written.
         if (reporter%lost .and. (status == 0 .or. status == exit_interrupted)) status = exit_io
         call c_exit(int(status, c_int))
      end subroutine finish

   end subroutine run_program

end module friction_app_cli
