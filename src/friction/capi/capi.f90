!> The C API (include/friction.h), version 2: handles over the kernel.
!>
!> A configuration handle is a job's configuration (&job, the scene's
!> groups, &sweep) made with its scene's defaults and changed by namelist
!> files or by name ("tip.kx"), through the same description of the
!> variables (core/parameters.f90) and the same checks (the scene's own)
!> as the program's input.  Computations on the calling process (a scan
!> line, a whole scene into a result handle) run the scene's own compute,
!> without MPI; jobs run the program's job routine.
!>
!> Every call returns a status (0 on success, else one of the friction_error
!> codes) and, when the caller passes an error handle, fills it with the
!> status and a message.  No module variables: all state lives in the
!> caller's handles or in the call's locals, so threads may work at once on
!> different handles.
!>
!> The functions live in one module per subject, all of them public here:
!> the text of C strings and buffers (text.f90), the handles, their table
!> and the error handle (handles.f90), configurations (config.f90),
!> computations and results (compute.f90), jobs (jobs.f90) and their
!> reporter (reporter.f90), friction laws (law.f90); this module adds the
!> version.
module friction_capi
   use, intrinsic :: iso_c_binding, only: c_ptr, c_int, c_size_t
   use friction_error, only: error_input
   use friction_version, only: version_string
   use friction_capi_text, only: copy_text
   use friction_capi_handles, only: capi_result, friction_error_new, friction_error_free, friction_error_status, &
      & friction_error_message, friction_config_new, friction_config_free, friction_result_free
   use friction_capi_config, only: friction_config_read, friction_config_set, friction_config_set_real, &
      & friction_config_get, friction_config_text, friction_config_names, friction_config_check, &
      & friction_config_warnings
   use friction_capi_compute, only: friction_afm_line, friction_afm_line_progress, friction_compute, &
      & friction_compute_progress, friction_result_get, friction_result_shape, friction_result_names
   use friction_capi_jobs, only: friction_run_job, friction_run_config
   use friction_capi_law, only: friction_law_new, friction_law_free, friction_law_set, friction_law_set_real, &
      & friction_law_get, friction_law_check, friction_law_state_count, friction_law_history
   implicit none
   private

   public :: friction_version_c, friction_api_version, friction_error_new, friction_error_free, &
      & friction_error_status, friction_error_message
   public :: friction_config_new, friction_config_free, friction_config_read, friction_config_set, &
      & friction_config_set_real, friction_config_get, friction_config_text, friction_config_names, &
      & friction_config_check, friction_config_warnings
   public :: friction_afm_line, friction_afm_line_progress, friction_compute, friction_compute_progress, &
      & friction_result_get, friction_result_shape, friction_result_names, friction_result_free
   public :: friction_run_job, friction_run_config
   public :: friction_law_new, friction_law_free, friction_law_set, friction_law_set_real, friction_law_get, &
      & friction_law_check, friction_law_state_count, friction_law_history
   public :: capi_result

   !> FRICTION_API_VERSION of include/friction.h.
   integer(c_int), parameter :: api_version = 2

contains

   !> int friction_version(char *buf, size_t len)
   integer(c_int) function friction_version_c(buf, len) bind(c, name='friction_version') result(status)
      type(c_ptr), value :: buf
      integer(c_size_t), value :: len

      status = 0
      if (.not. copy_text(version_string, buf, len)) status = error_input
   end function friction_version_c

   !> int friction_api_version(void)
   integer(c_int) function friction_api_version() bind(c, name='friction_api_version') result(version)
      version = api_version
   end function friction_api_version

end module friction_capi
