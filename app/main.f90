!> friction: friction-force maps of a microscope tip over a crystal surface.
!>
!>   mpirun -n N friction [options] FILE.nml [MORE.nml ...]
!>
!> The only place that prints and sets the exit code.  Scan lines are dealt
!> round-robin to the MPI ranks; the file is written collectively under a
!> temporary name and renamed when complete.
program friction_main
   use, intrinsic :: iso_c_binding, only: c_int
   use, intrinsic :: iso_fortran_env, only: error_unit, output_unit
   use mpi_f08
   use friction_kinds, only: wp, i8
   use friction_error, only: error_type, fatal_error, error_input, error_io
   use friction_version, only: version_string
   use friction_strings, only: itoa
   use friction_io_input, only: job_config, read_input
   use friction_io_files, only: file_exists, rename_file, remove_file
   use friction_ode_solver, only: integrator_statistics
   use friction_afm_scan, only: afm_scanner, trip_record, share_of, n_quantities
   use friction_afm_output, only: afm_run_summary, write_afm_file, afm_surface_record
   use friction_afm_config, only: new_potential, species_count
   use friction_surface_potential, only: surface_potential
   implicit none

   interface
      function friction_stderr_is_terminal() result(yes) bind(c)
         import :: c_int
         integer(c_int) :: yes
      end function friction_stderr_is_terminal
      function friction_process_id() result(pid) bind(c)
         import :: c_int
         integer(c_int) :: pid
      end function friction_process_id
      !> The C library's exit: a status code without the runtime's backtrace.
      subroutine c_exit(status) bind(c, name='exit')
         import :: c_int
         integer(c_int), value :: status
      end subroutine c_exit
   end interface

   integer, parameter :: exit_usage = 2, exit_input = 3, exit_numerical = 4, exit_io = 5

   type :: options
      character(len=:), allocatable :: output
      logical :: force = .false.
      logical :: quiet = .false.
      character(len=4096), allocatable :: files(:)
   end type options

   type(options) :: opts
   type(job_config) :: config
   character(len=:), allocatable :: input_text
   type(error_type), allocatable :: error
   integer :: rank, nranks, code
   real(wp) :: t_start

   call MPI_Init()
   t_start = MPI_Wtime()
   call MPI_Comm_rank(MPI_COMM_WORLD, rank)
   call MPI_Comm_size(MPI_COMM_WORLD, nranks)

   code = parse_arguments(opts)
   if (code >= 0) call finish(code)

   call read_input(opts%files, config, input_text, error)
   if (allocated(error)) call fail(error)
   if (.not. allocated(opts%output)) opts%output = default_output(opts%files(1))
   if (file_exists(opts%output) .and. .not. opts%force) then
      call fatal_error(error, opts%output//': the output file exists; use --force to overwrite it', &
         & error_input)
      call fail(error)
   end if
   ! Find out now, not after the computation, whether the output can be written.
   if (rank == 0) call check_writable(opts%output, error)
   code = merge(1, 0, allocated(error))
   call MPI_Bcast(code, 1, MPI_INTEGER, 0, MPI_COMM_WORLD)
   if (code /= 0) then
      if (rank == 0) call report(error)
      call finish(exit_io)
   end if

   call run_afm()
   call finish(0)

contains

   !> Scan this rank's lines, then write the file together.
   subroutine run_afm()
      type(afm_scanner), target :: scanner
      class(surface_potential), allocatable :: potential
      type(afm_surface_record) :: surface
      type(trip_record) :: trip
      real(wp), allocatable :: trace(:, :, :), retrace(:, :, :)
      type(afm_run_summary) :: summary
      type(integrator_statistics) :: stats
      integer(i8) :: counts(4)
      integer :: first, count, j, failed_rank
      real(wp) :: wall
      character(len=:), allocatable :: temporary
      character(len=12) :: seconds
      integer :: pid

      associate (c => config%afm)
         ! The surface first, identically on every rank: a bad net or defect is
         ! bad input, reported before any work.
         call new_potential(c, potential, error, surface%net, surface%cutoff)
         if (allocated(error)) call fail(error)
         surface%species_names = c%species(1:species_count(c))
         call share_of(c%ny, nranks, rank, first, count)
         allocate (trace(c%nx, count, n_quantities))
         allocate (retrace(c%nx, merge(count, 0, c%retrace), n_quantities))
         call scanner%init(c, potential, error)
         surface%contact_height = scanner%contact_height
         surface%support_height = scanner%support_height
         do j = 1, count
            if (allocated(error)) exit
            call scanner%run_trip(first + (j - 1) * nranks, .true., trip, error)
            if (allocated(error)) exit
            trace(:, j, :) = trip%values
            if (c%retrace) then
               call scanner%run_trip(first + (j - 1) * nranks, .false., trip, error)
               if (allocated(error)) exit
               retrace(:, j, :) = trip%values
            end if
            if (rank == 0) call show_progress(j, count, c%ny, .false.)
         end do
         if (rank == 0) call show_progress(count, count, c%ny, .true.)
      end associate

      ! A failure on any rank stops all of them here, before anything is written.
      failed_rank = merge(rank, nranks, allocated(error))
      call MPI_Allreduce(MPI_IN_PLACE, failed_rank, 1, MPI_INTEGER, MPI_MIN, MPI_COMM_WORLD)
      if (failed_rank < nranks) then
         code = exit_numerical
         if (rank == failed_rank) then
            call report(error)
            code = exit_code(error)
         end if
         call MPI_Bcast(code, 1, MPI_INTEGER, failed_rank, MPI_COMM_WORLD)
         call finish(code)
      end if

      stats = scanner%statistics()
      counts = [stats%steps, stats%failed_steps, stats%rhs_evaluations, stats%jacobian_evaluations]
      call MPI_Allreduce(MPI_IN_PLACE, counts, 4, MPI_INTEGER8, MPI_SUM, MPI_COMM_WORLD)
      stats = integrator_statistics(counts(1), counts(2), counts(3), counts(4))
      wall = MPI_Wtime() - t_start
      call MPI_Allreduce(MPI_IN_PLACE, wall, 1, MPI_DOUBLE_PRECISION, MPI_MAX, MPI_COMM_WORLD)
      summary = afm_run_summary(input_text, version_string, nranks, wall, stats)

      pid = friction_process_id()
      call MPI_Bcast(pid, 1, MPI_INTEGER, 0, MPI_COMM_WORLD)
      temporary = opts%output//'.tmp-'//itoa(pid)
      if (scanner%tip%ndim == 3) then
         call write_afm_file(temporary, MPI_COMM_WORLD, config%afm, first, nranks, trace, retrace, summary, &
            & error, surface)
      else
         call write_afm_file(temporary, MPI_COMM_WORLD, config%afm, first, nranks, trace, retrace, summary, &
            & error)
      end if
      code = merge(1, 0, allocated(error))
      call MPI_Allreduce(MPI_IN_PLACE, code, 1, MPI_INTEGER, MPI_MAX, MPI_COMM_WORLD)
      if (rank == 0) then
         if (code == 0) then
            call rename_file(temporary, opts%output, error)
         else if (.not. allocated(error)) then
            call fatal_error(error, temporary//': writing failed on another rank', error_io)
         end if
         if (allocated(error)) then
            call remove_file(temporary)
            call report(error)
         else if (.not. opts%quiet) then
            write (seconds, '(f12.2)') wall
            write (error_unit, '(a)') 'friction: wrote '//opts%output//' ('//itoa(config%afm%ny) &
               & //' lines x '//itoa(config%afm%nx)//' points, '//trim(adjustl(seconds))//' s on ' &
               & //itoa(nranks)//trim(merge(' rank) ', ' ranks)', nranks == 1))
         end if
      end if
      code = merge(1, 0, allocated(error))
      call MPI_Bcast(code, 1, MPI_INTEGER, 0, MPI_COMM_WORLD)
      if (code /= 0) call finish(exit_io)
   end subroutine run_afm

   !> Rank 0's progress: its share is as large as any other and spread over
   !> the whole map, so its fraction done is the map's fraction done.
   subroutine show_progress(done, share, total, last)
      integer, intent(in) :: done, share, total
      logical, intent(in) :: last
      real(wp), save :: shown = -1.0_wp
      integer, save :: shown_done = -1
      real(wp) :: now, elapsed, remaining, interval
      integer :: lines
      logical :: tty

      if (opts%quiet) return
      tty = friction_stderr_is_terminal() /= 0
      now = MPI_Wtime()
      ! Under mpirun stderr is a pipe even at a terminal: plain lines there,
      ! spaced further apart as the run goes on so a long batch log stays short.
      interval = 0.5_wp
      if (.not. tty) interval = max(2.0_wp, 0.1_wp * (now - t_start))
      if (.not. last .and. now - max(shown, t_start) < interval) return
      if (last .and. (shown < 0.0_wp .or. done == shown_done)) return   ! nothing new to say
      shown = now
      shown_done = done
      elapsed = now - t_start
      lines = min(total, int(real(done, wp) / max(1, share) * total))
      remaining = 0.0_wp
      if (done > 0) remaining = elapsed * real(share - done, wp) / done
      if (tty) then
         write (error_unit, '(a, i0, a, i0, a, f0.1, a, f0.1, a)', advance='no') achar(13)// &
            & 'friction: ', lines, ' of ', total, ' lines, ', elapsed, ' s elapsed, ', remaining, &
            & ' s remaining   '
         if (last) write (error_unit, '(a)') ''
      else
         write (error_unit, '(a, i0, a, i0, a, f0.1, a, f0.1, a)') 'friction: ', lines, ' of ', total, &
            & ' lines, ', elapsed, ' s elapsed, ', remaining, ' s remaining'
      end if
      flush (error_unit)
   end subroutine show_progress

   !> Arguments; returns -1 to go on, else the exit code to finish with.
   integer function parse_arguments(opts) result(code)
      type(options), intent(inout) :: opts
      character(len=4096) :: arg
      integer :: i, n

      code = -1
      allocate (opts%files(0))
      n = command_argument_count()
      i = 0
      do while (i < n)
         i = i + 1
         call get_command_argument(i, arg)
         select case (trim(arg))
         case ('-h', '--help')
            if (rank == 0) call print_help()
            code = 0
            return
         case ('-V', '--version')
            if (rank == 0) write (output_unit, '(a)') 'friction '//version_string
            code = 0
            return
         case ('-o', '--output')
            if (i == n) then
               code = usage_error('option '//trim(arg)//' needs a file name')
               return
            end if
            i = i + 1
            call get_command_argument(i, arg)
            opts%output = trim(arg)
         case ('-f', '--force')
            opts%force = .true.
         case ('-q', '--quiet')
            opts%quiet = .true.
         case default
            if (arg(1:1) == '-') then
               code = usage_error('unknown option '//trim(arg))
               return
            end if
            opts%files = [opts%files, arg]
         end select
      end do
      if (size(opts%files) == 0) code = usage_error('no input file given')
   end function parse_arguments

   integer function usage_error(message) result(code)
      character(len=*), intent(in) :: message

      if (rank == 0) write (error_unit, '(a)') 'friction: '//message// &
         & new_line('a')//'usage: friction [options] FILE.nml [MORE.nml ...]  (friction --help)'
      code = exit_usage
   end function usage_error

   subroutine print_help()
      write (output_unit, '(a)') &
         & 'usage: [mpirun -n N] friction [options] FILE.nml [MORE.nml ...]', &
         & '', &
         & 'Friction-force maps of a microscope tip dragged over a crystal surface', &
         & '(NaF, HOPG): the tip''s equations of motion integrated with GSL odeiv2,', &
         & 'scan lines shared among MPI ranks, results in one HDF5 file.', &
         & '', &
         & 'Input files are namelist files read in order; a later file overrides', &
         & 'earlier values variable by variable.  Groups: &job &surface &tip &scan', &
         & '&integrator (see README.md, input reference).', &
         & '', &
         & 'options:', &
         & '  -o, --output FILE  output file (default: first input''s name with .h5,', &
         & '                     in the current directory)', &
         & '  -f, --force        overwrite an existing output file', &
         & '  -q, --quiet        no progress or summary on stderr', &
         & '  -h, --help         this help', &
         & '  -V, --version      the version', &
         & '', &
         & 'exit codes: 0 done, 2 usage, 3 bad input, 4 integration failed, 5 output failed'
   end subroutine print_help

   !> Create and remove a probe file beside the output.
   subroutine check_writable(path, error)
      character(len=*), intent(in) :: path
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: probe
      character(len=256) :: message
      integer :: unit, stat

      probe = path//'.tmp-'//itoa(friction_process_id())
      open (newunit=unit, file=probe, status='new', action='write', iostat=stat, iomsg=message)
      if (stat /= 0) then
         call fatal_error(error, path//': cannot write the output here ('//trim(message)//')', error_io)
         return
      end if
      close (unit, status='delete')
   end subroutine check_writable

   !> inputs/hopg.nml -> hopg.h5
   function default_output(path) result(name)
      character(len=*), intent(in) :: path
      character(len=:), allocatable :: name
      integer :: slash, dot

      slash = index(path, '/', back=.true.)
      name = trim(path(slash + 1:))
      dot = index(name, '.', back=.true.)
      if (dot > 1) name = name(1:dot - 1)
      name = name//'.h5'
   end function default_output

   subroutine report(error)
      type(error_type), intent(in) :: error

      write (error_unit, '(a)') 'friction: error: '//error%message
      flush (error_unit)
   end subroutine report

   !> Report an error met identically on every rank (input), then stop.
   subroutine fail(error)
      type(error_type), intent(in) :: error

      if (rank == 0) call report(error)
      call finish(exit_code(error))
   end subroutine fail

   integer function exit_code(error)
      type(error_type), intent(in) :: error

      select case (error%stat)
      case (error_input)
         exit_code = exit_input
      case (error_io)
         exit_code = exit_io
      case default
         exit_code = exit_numerical
      end select
   end function exit_code

   subroutine finish(code)
      integer, intent(in) :: code

      call MPI_Finalize()
      flush (error_unit)
      flush (output_unit)
      call c_exit(int(code, c_int))
   end subroutine finish

end program friction_main
