!> The library for Fortran programs: one `use friction` gives what a caller
!> needs to run jobs and scenes without files.
!>
!>     use friction
!>     type(job_config) :: config
!>     call read_input(['inputs/naf.nml'], config, text, error)
!>     call set_parameter_number(config, 'tip', 'kx', 5.0d0, problem)
!>
!> The modules behind it (docs/layout.md) stay available for finer use.
module friction
   use friction_kinds, only: wp, i8
   use friction_error, only: error_type, error_input, error_numerical, error_io, error_internal, &
      & error_interrupted
   use friction_version, only: version_string, revision_string
   use friction_parameters, only: configurable, parameter_info, list_parameters, set_parameter, &
      & set_parameter_number, get_parameter, parameters_text
   use friction_checks, only: config_checker
   use friction_scene_report, only: job_reporter
   use friction_scene, only: scene, point_result
   use friction_afm_config, only: afm_config
   use friction_afm_scene, only: afm_scene
   use friction_brake_config, only: brake_config
   use friction_brake_scene, only: brake_scene
   use friction_job_factory, only: scene_names, new_scene
   use friction_job_config, only: job_config, read_input, check_job, job_text
   use friction_job, only: run_job, write_netlist, default_output
   implicit none
   public
end module friction
