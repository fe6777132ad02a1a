!> The C API's jobs: whole jobs, from namelist files or from a
!> configuration handle, run by the program's job routine to an HDF5 file,
!> one at a time in the process (job_lock.c), on MPI_COMM_WORLD or serially.
module friction_capi_jobs
   use, intrinsic :: iso_c_binding, only: c_ptr, c_int, c_associated, c_f_pointer, c_funptr, c_f_procpointer
   use friction_parallel, only: communicator, serial_comm, world_comm, start_parallel, parallel_started, &
      & parallel_finished
   use friction_error, only: error_type, fatal_error, error_input
   use friction_strings, only: itoa
   use friction_job, only: run_job, run_job_config
   use friction_capi_text, only: c_string
   use friction_capi_handles, only: capi_config, report, config_of
   use friction_capi_config, only: forked_message
   use friction_capi_reporter, only: callback_reporter
   implicit none
   private

   public :: friction_run_job, friction_run_config

   !> friction_run_job / friction_run_config flags.
   integer(c_int), parameter :: job_force = 1, job_resume = 2, job_init_mpi = 4

   interface
      !> One job at a time in the process (job_lock.c): 0 once the calling
      !> thread may run its job, 1 if it is running one already, 2 in a
      !> process forked while its parent ran one.
      function friction_job_begin() bind(c, name='friction_job_begin') result(busy)
         import :: c_int
         integer(c_int) :: busy
      end function friction_job_begin

      subroutine friction_job_end() bind(c, name='friction_job_end')
      end subroutine friction_job_end
   end interface

contains

   !> The flags' checks and the job's communicator: MPI_COMM_WORLD when the
   !> caller initialised MPI, or when it passes FRICTION_JOB_INIT_MPI (MPI is
   !> initialised here); otherwise one not attached, a serial job on this process
   !> that makes no MPI call.
   subroutine prepare_job(flags, comm, error)
      integer(c_int), intent(in) :: flags
      type(communicator), intent(out) :: comm
      type(error_type), allocatable, intent(inout) :: error
      integer :: ierror

      comm = serial_comm()
      if (allocated(error)) return
      if (iand(flags, not(job_force + job_resume + job_init_mpi)) /= 0) then
         call fatal_error(error, 'flags = '//itoa(int(flags))//': unknown bits (known: FRICTION_JOB_FORCE, ' &
            & //'FRICTION_JOB_RESUME, FRICTION_JOB_INIT_MPI)', error_input)
         return
      end if
      if (parallel_finished()) then
         call fatal_error(error, 'MPI has been finalized: a job needs MPI (call it before MPI_Finalize)', &
            & error_input)
         return
      end if
      if (.not. parallel_started()) then
         if (iand(flags, job_init_mpi) == 0) return   ! serial, without MPI
         call start_parallel(.true., ierror)
         if (ierror /= 0) then
            call fatal_error(error, 'MPI_Init_thread failed (error '//itoa(ierror)//')', error_input)
            return
         end if
      end if
      comm = world_comm()
   end subroutine prepare_job

   !> int friction_run_job(const char *const *files, int nfiles, const char *output, int flags,
   !>                      friction_report_fn report, void *user, friction_error *err)
   integer(c_int) function friction_run_job(files, nfiles, output, flags, report_fn, user, handle) &
      & bind(c, name='friction_run_job_body') result(status)
      type(c_ptr), value :: files, output, user, handle
      integer(c_int), value :: nfiles, flags
      type(c_funptr), value :: report_fn
      type(error_type), allocatable :: error
      type(c_ptr), pointer :: names(:)
      character(len=4096), allocatable :: paths(:)
      character(len=:), allocatable :: summary, path
      type(callback_reporter) :: reporter
      type(communicator) :: comm
      integer :: k

      allocate (paths(0))
      if (.not. c_associated(files) .and. nfiles /= 0) then
         call fatal_error(error, 'files is a null pointer', error_input)
      else if (nfiles < 1) then
         call fatal_error(error, 'nfiles = '//itoa(int(nfiles))//': give at least one namelist file', error_input)
      else if (.not. c_associated(output)) then
         call fatal_error(error, 'output is a null pointer', error_input)
      else
         call c_f_pointer(files, names, [nfiles])
         deallocate (paths)
         allocate (paths(nfiles))
         do k = 1, nfiles
            if (.not. c_associated(names(k))) then
               call fatal_error(error, 'files['//itoa(k - 1)//'] is a null pointer', error_input)
               exit
            end if
            path = c_string(names(k))
            if (len(path) > len(paths)) then
               call fatal_error(error, 'files['//itoa(k - 1)//'] is longer than '//itoa(len(paths)) &
                  & //' characters', error_input)
               exit
            end if
            paths(k) = path
         end do
      end if
      if (.not. allocated(error)) call begin_job(error)
      if (allocated(error)) then
         status = report(handle, error)
         return
      end if
      call prepare_job(flags, comm, error)
      if (.not. allocated(error)) then
         reporter%user = user
         if (c_associated(report_fn)) call c_f_procpointer(report_fn, reporter%call)
         call run_job(paths, c_string(output), iand(flags, job_force) /= 0, iand(flags, job_resume) /= 0, &
            & comm, reporter, summary, error)
      end if
      call friction_job_end()
      status = report(handle, error)
   end function friction_run_job

   !> int friction_run_config(const friction_config *cfg, const char *output, int flags,
   !>                         friction_report_fn report, void *user, friction_error *err)
   integer(c_int) function friction_run_config(cfg, output, flags, report_fn, user, handle) &
      & bind(c, name='friction_run_config_body') result(status)
      type(c_ptr), value :: cfg, output, user, handle
      integer(c_int), value :: flags
      type(c_funptr), value :: report_fn
      type(capi_config), pointer :: config
      type(error_type), allocatable :: error
      character(len=:), allocatable :: summary
      type(callback_reporter) :: reporter
      type(communicator) :: comm

      if (config_of(cfg, config, error)) then
         if (.not. c_associated(output)) call fatal_error(error, 'output is a null pointer', error_input)
      end if
      if (.not. allocated(error)) call begin_job(error)
      if (allocated(error)) then
         status = report(handle, error)
         return
      end if
      call prepare_job(flags, comm, error)
      if (.not. allocated(error)) then
         reporter%user = user
         if (c_associated(report_fn)) call c_f_procpointer(report_fn, reporter%call)
         call run_job_config(config%job, c_string(output), iand(flags, job_force) /= 0, &
            & iand(flags, job_resume) /= 0, comm, reporter, summary, error, config%origins, config%files)
      end if
      call friction_job_end()
      status = report(handle, error)
   end function friction_run_config

   !> Wait until no other thread runs a job (job_lock.c); refused on a thread
   !> that runs one already (a report callback starting a job).  On success
   !> the caller ends with friction_job_end.
   subroutine begin_job(error)
      type(error_type), allocatable, intent(out) :: error

      select case (friction_job_begin())
      case (1)
         call fatal_error(error, 'a job is already running on this thread (a job cannot be started from its ' &
            & //'own report callback)', error_input)
      case (2)
         call fatal_error(error, forked_message, error_input)
      end select
   end subroutine begin_job

end module friction_capi_jobs
