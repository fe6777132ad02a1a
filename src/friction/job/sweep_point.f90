!> One sweep point (docs/sweeps.md): a copy of the job's scene with the
!> swept variables set in memory and checked by the scene's own checks, run
!> on this process through the abstract scene, and what it leaves: the
!> finished point the transport carries to rank 0 and the checkpoint keeps.
!> An invalid or failing point is a failed point with its reason, not an
!> error of the sweep.
module friction_job_sweep_point
   use friction_kinds, only: wp
   use friction_clock, only: wall_seconds
   use friction_error, only: error_type, fatal_error, error_input, error_interrupted
   use friction_strings, only: itoa, one_line
   use friction_ode_solver, only: step_type_index
   use friction_parameters, only: set_parameter_number, split_name
   use friction_checks, only: config_checker
   use friction_scene, only: scene, point_result, point_memory, result_sink
   use friction_scene_report, only: job_reporter
   use friction_job_config, only: job_config
   implicit none
   private

   public :: finished_point, point_names, compute_point, point_warning
   public :: status_pending, status_done, status_failed, method_result

   !> A point's status in the checkpoint and the file.
   integer, parameter :: status_pending = 0, status_done = 1, status_failed = 2

   !> The result the sweep adds after the scene's own: the stepper point i ran,
   !> carried as its step type's index (0: none, the point failed its check)
   !> and written as its name, /sweep/method.  A point resolves method =
   !> 'auto' for its own values, so a sweep over a tip's damping, epsilon' or
   !> a tolerance can run different steppers at different points.
   character(len=*), parameter :: method_result = 'method'

   !> A computed point as it travels to rank 0: header = point (0: the
   !> sending rank has finished; then header(2) says whether it was
   !> interrupted), status, number of results, series length, reason length.
   type :: finished_point
      integer :: header(5) = 0
      real(wp), allocatable :: numbers(:)   !! results, cost, series
      character(len=:), allocatable :: reason
   end type finished_point

   !> Where a point's scene puts its results (run_point): each named result
   !> in its place among the scene's point_results, the series whole.
   type, extends(result_sink) :: point_sink
      type(point_result), allocatable :: names(:)
      character(len=:), allocatable :: series_name
      real(wp), allocatable :: results(:), series(:)
   contains
      procedure :: add => point_sink_add
   end type point_sink

contains

   !> The results every point of the job's sweep reduces to: the scene's,
   !> then method_result.
   function point_names(config) result(names)
      type(job_config), intent(in) :: config
      type(point_result), allocatable :: names(:)

      names = [config%scene%point_results(), point_result(method_result, '', .false.)]
   end function point_names

   !> Compute point i with what this rank's earlier points left in `kept`
   !> (point_memory): `point` is done or failed (with its reason), its cost
   !> the wall time it took.  `warning`: the scene's settings_warning for the
   !> point ('' for none, or when its check failed).  The scene may ask
   !> `reporter` for a stop request inside the point: `interrupted` then says
   !> the point was left unfinished (neither done nor failed: pending).
   subroutine compute_point(config, i, n_results, kept, point, warning, reporter, interrupted)
      type(job_config), intent(in) :: config
      integer, intent(in) :: i, n_results
      type(point_memory), intent(inout) :: kept
      type(finished_point), intent(out) :: point
      character(len=:), allocatable, intent(out) :: warning
      class(job_reporter), intent(inout), optional :: reporter
      logical, intent(out), optional :: interrupted
      type(error_type), allocatable :: error
      real(wp), allocatable :: results(:), series(:)
      real(wp) :: t0, cost

      allocate (results(n_results))
      t0 = wall_seconds()
      call run_point(config, i, results, series, kept, warning, error, reporter)
      if (present(interrupted)) then
         interrupted = .false.
         if (allocated(error)) interrupted = error%stat == error_interrupted
      end if
      if (.not. allocated(series)) allocate (series(0))
      cost = wall_seconds() - t0
      point%header = [i, status_done, n_results, size(series), 0]
      point%reason = ''
      if (allocated(error)) then
         point%header(2) = status_failed
         point%reason = one_line(trim(error%message))
         results(:size(results) - 1) = 0.0_wp   ! (the stepper it ran stays)
         deallocate (series)
         allocate (series(0))
      end if
      point%header(4) = size(series)
      point%header(5) = len(point%reason)
      point%numbers = [results, cost, series]
   end subroutine compute_point

   !> Point i's scene run on this process: `results` holds the scene's point
   !> results, then the index of the stepper it ran (method_result).
   subroutine run_point(config, i, results, series, kept, warning, error, reporter)
      type(job_config), intent(in) :: config
      integer, intent(in) :: i
      real(wp), intent(out) :: results(:)
      real(wp), allocatable, intent(out) :: series(:)
      type(point_memory), intent(inout) :: kept
      character(len=:), allocatable, intent(out) :: warning
      type(error_type), allocatable, intent(out) :: error
      class(job_reporter), intent(inout), optional :: reporter
      class(scene), allocatable :: point
      type(point_sink) :: sink
      character(len=:), allocatable :: unit

      results = 0.0_wp
      warning = ''
      allocate (series(0))
      call point_scene(config, i, point, error)
      if (allocated(error)) return
      warning = point%settings_warning()
      results(size(results)) = real(step_type_index(point%method()), wp)
      sink%names = point%point_results()
      call point%point_series(sink%series_name, unit)
      allocate (sink%results(size(sink%names)), source=0.0_wp)
      allocate (sink%series(0))
      call point%run_point(sink, kept, error, reporter)
      results(:size(results) - 1) = sink%results
      call move_alloc(sink%series, series)
   end subroutine run_point

   subroutine point_sink_add(self, name, rows, columns, values)
      class(point_sink), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer, intent(in) :: rows, columns
      real(wp), intent(in) :: values(:)
      integer :: j

      if (len(self%series_name) > 0 .and. name == self%series_name) then
         self%series = values
         return
      end if
      do j = 1, size(self%names)
         if (self%names(j)%name == name .and. size(values) > 0) self%results(j) = values(1)
      end do
   end subroutine point_sink_add

   !> The scene's warning about point i's settings ('' for none or a point
   !> that fails its check).
   function point_warning(config, i) result(text)
      type(job_config), intent(in) :: config
      integer, intent(in) :: i
      character(len=:), allocatable :: text
      class(scene), allocatable :: point
      type(error_type), allocatable :: error

      text = ''
      call point_scene(config, i, point, error)
      if (.not. allocated(error)) text = point%settings_warning()
   end function point_warning

   !> Point i's scene: a copy with the swept variables set in memory,
   !> checked as the input is.
   subroutine point_scene(config, i, point, error)
      type(job_config), intent(in) :: config
      integer, intent(in) :: i
      class(scene), allocatable, intent(out) :: point
      type(error_type), allocatable, intent(out) :: error
      type(config_checker) :: checker
      character(len=:), allocatable :: group, name, problem
      integer :: v

      allocate (point, source=config%scene)
      do v = 1, config%sweep%n_variables
         call split_name(config%sweep%variables(v), group, name)
         call set_parameter_number(point, group, name, config%sweep%point_value(v, i), problem)
         if (len(problem) > 0) then
            call fatal_error(error, 'sweep point '//itoa(i)//': &'//group//': '//name//': '//problem, error_input)
            return
         end if
         call checker%set_origin(group, name, 'sweep point '//itoa(i))
      end do
      call point%check(checker)
      if (checker%failed()) call move_alloc(checker%error, error)
   end subroutine point_scene

end module friction_job_sweep_point
