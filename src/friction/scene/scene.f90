!> A scene: what the program computes (a friction-force map, the brake, and
!> whatever comes next), as one type the job, the sweep, the netlist and the
!> C API call without knowing which scene it is.  A scene owns its namelist
!> groups (it visits its variables and checks its values), runs on a
!> communicator, writes its part of the output file, reduces itself to a
!> sweep point's named results, and describes itself as a SPICE netlist.
!> Only the factory (job/factory.f90) knows the concrete types.
module friction_scene
   use friction_kinds, only: wp, i8
   use friction_error, only: error_type, fatal_error, error_input
   use friction_parameters, only: configurable, parameter_visitor
   use friction_checks, only: config_checker
   use friction_scene_report, only: job_reporter
   use friction_scene_context, only: job_context
   use friction_surface_potential, only: surface_potential
   use friction_scene_sink, only: result_sink
   implicit none
   private

   public :: scene, point_result, point_memory, result_sink

   !> One named result of a sweep point (docs/sweeps.md).
   type :: point_result
      character(len=24) :: name = ''
      character(len=16) :: unit = ''
      logical :: whole = .false.   !! written as integers (counts)
   end type point_result

   !> What one process keeps from a sweep point for its next points: set-up
   !> that costs much and that the swept variables may leave as it was.  A
   !> scene fills it and decides when it still holds (`surface_key`: the
   !> settings it was made from, compared as text).  The AFM scene keeps its
   !> surface, whose table takes longer to build than a short scan takes to
   !> run (docs/sweeps.md, What a point keeps).
   type :: point_memory
      character(len=:), allocatable :: surface_key
      class(surface_potential), allocatable :: surface
   end type point_memory

   type, abstract, extends(configurable) :: scene
   contains
      !> The scene's name in &job scene = '...'.
      procedure(name_interface), deferred :: name
      !> The namelist groups it reads, in the order of the echo.
      procedure(groups_interface), deferred :: groups
      !> Check every value (the first bad one goes to the checker).
      procedure(check_interface), deferred :: check
      !> The stepper that runs (after 'auto' is resolved), for the file's root.
      procedure(name_interface), deferred :: method
      !> Compute, collectively over the job's communicator; every rank
      !> returns the same error or none.
      procedure(run_interface), deferred :: run
      !> Write the computed results to a new file `path` (collective).
      procedure(write_interface), deferred :: write_output
      !> What was computed, in one line, after a run.
      procedure(summary_interface), deferred :: summary
      !> The results a sweep point reduces to, and the name and unit of its
      !> variable-length series ('' when it has none).
      procedure(results_interface), deferred :: point_results
      procedure(series_interface), deferred :: point_series
      !> One sweep point on this process alone, into `sink` as compute's
      !> arrays go: each of point_results as a 1 x 1 array, and the series
      !> (point_series) as one column; nothing on an error.  `memory` is what
      !> the process kept from its earlier points (point_memory); a scene may
      !> ask `reporter` (the job's, if given) for stop requests inside the
      !> point, ending it with an error of stat error_interrupted.
      procedure(point_interface), deferred :: run_point
      !> Give `sink` a point's results, in the order of point_results, and
      !> its series: what run_point does once the point is computed.
      procedure, non_overridable :: put_point
      !> The whole scene on this process, into named arrays in `sink` (the
      !> arrays the output file holds, as the C API returns them), with
      !> progress and stop requests through `reporter`; `memory` as for
      !> run_point.  Needs checked settings.
      procedure(compute_interface), deferred :: compute
      !> One line of a scene made of lines, trace (`forward`) or retrace, on
      !> this process: its named arrays in `sink`, each of at most `capacity`
      !> values (a line longer than that is an input error, found before any
      !> computation); `reporter`, if given, is polled for a stop request
      !> within the line and told when it is done.  By default an error: the
      !> scene has no lines.
      procedure :: compute_line
      !> The scene as a SPICE netlist for ngspice; a refusal names where the
      !> variable that rules it out was set (`origins`, the input's, if given).
      procedure(netlist_interface), deferred :: netlist
      !> '' or a warning that the settings, though valid, make a result
      !> unreliable; cheap, from the settings alone.  The job says it before
      !> a run, and a sweep once for all its points.  None by default.
      procedure :: settings_warning
      !> Whether the settings ask for &verify's second integration, which a
      !> job runs and a sweep or the C API's friction_compute cannot.  No by
      !> default.
      procedure :: verifies
   end type scene

   abstract interface
      function name_interface(self) result(name)
         import :: scene
         class(scene), intent(in) :: self
         character(len=:), allocatable :: name
      end function name_interface

      subroutine groups_interface(self, names)
         import :: scene
         class(scene), intent(in) :: self
         character(len=32), allocatable, intent(out) :: names(:)
      end subroutine groups_interface

      subroutine check_interface(self, checker)
         import :: scene, config_checker
         class(scene), intent(in) :: self
         type(config_checker), intent(inout) :: checker
      end subroutine check_interface

      subroutine run_interface(self, job, reporter, error)
         import :: scene, job_context, job_reporter, error_type
         class(scene), intent(inout) :: self
         type(job_context), intent(in) :: job
         class(job_reporter), intent(inout) :: reporter
         type(error_type), allocatable, intent(out) :: error
      end subroutine run_interface

      subroutine write_interface(self, path, job, error)
         import :: scene, job_context, error_type
         class(scene), intent(inout) :: self
         character(len=*), intent(in) :: path
         type(job_context), intent(in) :: job
         type(error_type), allocatable, intent(out) :: error
      end subroutine write_interface

      function summary_interface(self, job) result(text)
         import :: scene, job_context
         class(scene), intent(in) :: self
         type(job_context), intent(in) :: job
         character(len=:), allocatable :: text
      end function summary_interface

      function results_interface(self) result(results)
         import :: scene, point_result
         class(scene), intent(in) :: self
         type(point_result), allocatable :: results(:)
      end function results_interface

      subroutine series_interface(self, name, unit)
         import :: scene
         class(scene), intent(in) :: self
         character(len=:), allocatable, intent(out) :: name, unit
      end subroutine series_interface

      subroutine point_interface(self, sink, memory, error, reporter)
         import :: scene, result_sink, error_type, point_memory, job_reporter
         class(scene), intent(inout) :: self
         class(result_sink), intent(inout) :: sink
         type(point_memory), intent(inout) :: memory
         type(error_type), allocatable, intent(out) :: error
         class(job_reporter), intent(inout), optional :: reporter
      end subroutine point_interface

      subroutine compute_interface(self, sink, memory, reporter, error)
         import :: scene, result_sink, point_memory, job_reporter, error_type
         class(scene), intent(inout) :: self
         class(result_sink), intent(inout) :: sink
         type(point_memory), intent(inout) :: memory
         class(job_reporter), intent(inout) :: reporter
         type(error_type), allocatable, intent(out) :: error
      end subroutine compute_interface

      subroutine netlist_interface(self, data_file, version, text, note, error, origins)
         import :: scene, error_type, config_checker
         class(scene), intent(in) :: self
         character(len=*), intent(in) :: data_file, version
         character(len=:), allocatable, intent(out) :: text, note
         type(error_type), allocatable, intent(out) :: error
         type(config_checker), intent(in), optional :: origins
      end subroutine netlist_interface
   end interface

contains

   subroutine put_point(self, sink, results, series)
      class(scene), intent(in) :: self
      class(result_sink), intent(inout) :: sink
      real(wp), intent(in) :: results(:), series(:)
      type(point_result), allocatable :: names(:)
      character(len=:), allocatable :: series_name, series_unit
      integer :: j

      names = self%point_results()
      do j = 1, size(names)
         call sink%add(trim(names(j)%name), 1, 1, results(j:j))
      end do
      call self%point_series(series_name, series_unit)
      if (len(series_name) > 0) call sink%add(series_name, size(series), 1, series)
   end subroutine put_point

   subroutine compute_line(self, line, forward, capacity, sink, memory, error, reporter)
      class(scene), intent(inout) :: self
      integer, intent(in) :: line
      logical, intent(in) :: forward
      integer(i8), intent(in) :: capacity
      class(result_sink), intent(inout) :: sink
      type(point_memory), intent(inout) :: memory
      type(error_type), allocatable, intent(out) :: error
      class(job_reporter), intent(inout), optional :: reporter

      call fatal_error(error, "scene '"//self%name()//"' is not made of scan lines: compute it whole", error_input)
   end subroutine compute_line

   function settings_warning(self) result(text)
      class(scene), intent(in) :: self
      character(len=:), allocatable :: text

      text = ''
   end function settings_warning

   logical function verifies(self)
      class(scene), intent(in) :: self

      verifies = .false.
   end function verifies

end module friction_scene
