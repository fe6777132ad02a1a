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
!> --help, --version, --netlist and usage errors never start MPI.
program friction_main
   use friction_app_terminal_reporter, only: terminal_reporter
   use friction_app_cli, only: run_program
   implicit none

   type(terminal_reporter) :: reporter

   call run_program(reporter)
end program friction_main
