!> A job's configuration: &job (which scene), the scene's own groups, and
!> &sweep; read from namelist files (later files override earlier values
!> variable by variable) and checked by the configurations themselves.
module friction_job_config
   use friction_kinds, only: wp, i8
   use friction_strings, only: itoa, rtoa, join, quoted, lower
   use friction_error, only: error_type, fatal_error, error_input
   use friction_parameters, only: configurable, parameter_visitor, parameter_info, list_parameters, &
      & parameters_text, split_name, parameter_finding, implausible_values, parameter_table
   use friction_checks, only: config_checker
   use friction_plausibility, only: unit_plausibility
   use friction_input_reader, only: namelist_source, scan_files, apply_files, override_source, source_place, last_text
   use friction_scene, only: scene
   use friction_job_factory, only: scene_names, new_scene
   implicit none
   private

   public :: job_config, sweep_settings, read_input, check_job, all_parameters, job_text, &
      & parameter_groups, not_in_scene, warn_units

   !> &sweep: one or two numeric variables of the scene ('group.name'), each
   !> over a list, a linspace or a logspace; the points are the grid of the
   !> two, the second varying fastest (docs/sweeps.md).  No cap on the
   !> points: a list holds as many values as the input gives, and a spaced
   !> range's values are computed when asked for (`value`), so nothing here
   !> grows with the number of points but the lists the input itself holds.
   !> Point counts are default integers: at most huge(1) = 2147483647
   !> points (a 1e6-point atlas is far below).
   type :: sweep_settings
      ! As the input gives them
      character(len=64) :: variables(2) = ''       !! 'group.name', e.g. 'brake.v_dr_prime'
      character(len=8) :: spacings(2) = 'list'     !! 'list', 'linear' or 'log'
      real(wp), allocatable :: listed1(:), listed2(:)   !! sweep_values, sweep_values2 (huge: not given)
      real(wp) :: from(2) = 0.0_wp, to(2) = 0.0_wp
      integer :: count(2) = 0
      character(len=8) :: schedule = 'dynamic'     !! 'dynamic' (on demand) or 'static' (contiguous blocks)
      ! Derived by check_job
      integer :: n_variables = 0
      logical :: integer_valued(2) = .false.       !! an integer variable (values are whole numbers)
      integer :: shape(2) = 1                      !! values per variable (1 for an absent second)
   contains
      procedure :: enabled => sweep_enabled
      procedure :: visit => sweep_visit
      procedure :: points => sweep_points
      procedure :: value => sweep_value
      procedure :: point_value => sweep_point_value
   end type sweep_settings

   !> Everything a run needs from its input files.
   type, extends(configurable) :: job_config
      character(len=16) :: scene_name = 'afm'
      class(scene), allocatable :: scene
      type(sweep_settings) :: sweep
   contains
      procedure :: visit => job_visit
   end type job_config

contains

   logical function sweep_enabled(self)
      class(sweep_settings), intent(in) :: self

      sweep_enabled = len_trim(self%variables(1)) > 0
   end function sweep_enabled

   subroutine sweep_visit(self, v)
      class(sweep_settings), intent(inout) :: self
      type(parameter_visitor), intent(inout) :: v

      call v%begin_group('sweep')
      call v%item('sweep_variable', self%variables(1), fold=.true.)
      call v%real_list('sweep_values', self%listed1, fill=huge(1.0_wp))
      call v%item('sweep_from', self%from(1))
      call v%item('sweep_to', self%to(1))
      call v%item('sweep_count', self%count(1))
      call v%item('sweep_spacing', self%spacings(1), fold=.true.)
      call v%item('sweep_variable2', self%variables(2), fold=.true.)
      call v%real_list('sweep_values2', self%listed2, fill=huge(1.0_wp))
      call v%item('sweep_from2', self%from(2))
      call v%item('sweep_to2', self%to(2))
      call v%item('sweep_count2', self%count(2))
      call v%item('sweep_spacing2', self%spacings(2), fold=.true.)
      call v%item('sweep_schedule', self%schedule, fold=.true.)
      call v%end_group()
   end subroutine sweep_visit

   !> The number of points (after check_job).
   integer function sweep_points(self)
      class(sweep_settings), intent(in) :: self

      sweep_points = self%shape(1) * self%shape(2)
   end function sweep_points

   !> Value k of variable a: the k-th listed value, or the k-th of the
   !> linspace or logspace, computed here (rounded for an integer variable).
   real(wp) function sweep_value(self, a, k) result(x)
      class(sweep_settings), intent(in) :: self
      integer, intent(in) :: a, k

      select case (trim(self%spacings(a)))
      case ('list')
         if (a == 1) then
            x = self%listed1(k)
         else
            x = self%listed2(k)
         end if
         return
      case ('linear')
         if (self%count(a) == 1) then
            x = self%from(a)
         else
            x = self%from(a) + (self%to(a) - self%from(a)) * (k - 1) / (self%count(a) - 1)
            ! Ends of opposite sign near the largest double: to - from overflows.
            if (abs(self%to(a) - self%from(a)) > huge(x)) x = self%from(a) * (real(self%count(a) - k, wp) &
               & / (self%count(a) - 1)) + self%to(a) * (real(k - 1, wp) / (self%count(a) - 1))
         end if
      case default
         if (self%count(a) == 1) then
            x = self%from(a)
         else
            x = sign(exp(log(abs(self%from(a))) + (log(abs(self%to(a))) - log(abs(self%from(a)))) * (k - 1) &
               & / (self%count(a) - 1)), self%from(a))
         end if
      end select
      if (self%integer_valued(a)) x = anint(x)
   end function sweep_value

   !> Point i's value of variable a (the second variable varies fastest).
   real(wp) function sweep_point_value(self, a, i) result(x)
      class(sweep_settings), intent(in) :: self
      integer, intent(in) :: a, i

      if (a == 1) then
         x = self%value(1, (i - 1) / self%shape(2) + 1)
      else
         x = self%value(2, mod(i - 1, self%shape(2)) + 1)
      end if
   end function sweep_point_value

   !> &job, the scene's groups, &sweep.
   subroutine job_visit(self, v)
      class(job_config), intent(inout) :: self
      type(parameter_visitor), intent(inout) :: v

      call v%begin_group('job')
      call v%item('scene', self%scene_name, fold=.true.)
      call v%end_group()
      if (allocated(self%scene)) call self%scene%visit(v)
      call self%sweep%visit(v)
   end subroutine job_visit

   !> Every variable of every scene's job (the names a file may use);
   !> `table`, if given, holds their names at their positions in the list.
   function all_parameters(table) result(list)
      type(parameter_table), intent(out), optional, target :: table
      type(parameter_info), allocatable :: list(:), more(:), grown(:)
      type(job_config) :: probe
      type(parameter_table), target :: own
      type(parameter_table), pointer :: seen
      integer :: k, m, n, position
      logical :: added

      ! (Grown by doubling: appending one at a time copied the whole list each
      ! time, a third of a short run's reading of its input; the variables
      ! scenes share are found by the table, not by a search of the list.)
      seen => own
      if (present(table)) seen => table
      allocate (list(256))
      n = 0
      do k = 1, size(scene_names)
         call new_scene(scene_names(k), probe%scene)
         more = list_parameters(probe)
         do m = 1, size(more)
            call seen%add(more(m)%group, more(m)%name, position, added)
            if (.not. added) cycle
            if (n == size(list)) then
               allocate (grown(2 * n))
               grown(1:n) = list(1:n)
               call move_alloc(grown, list)
            end if
            n = n + 1
            list(n) = more(m)
         end do
         deallocate (probe%scene)
      end do
      list = list(1:n)
   end function all_parameters

   !> The groups of a list of variables, in order of first appearance.
   function parameter_groups(list) result(groups)
      type(parameter_info), intent(in) :: list(:)
      character(len=32), allocatable :: groups(:)
      integer :: k

      allocate (groups(0))
      do k = 1, size(list)
         if (.not. any(groups == list(k)%group)) groups = [character(len=32) :: groups, list(k)%group]
      end do
   end function parameter_groups

   !> Read and check the files in order, then the command-line `overrides`
   !> ('group.variable=value', each read as a file of one assignment), into
   !> config; input_text is the resolved input as namelist text that reads
   !> back to the same run.  A file's group of another scene is ignored with
   !> a warning in `notes` if the input names the scene (&job scene), and is
   !> an error if the scene is the default one: the input then most likely
   !> forgot its &job (docs/cli.md, Groups of another scene).  With `units`,
   !> input_text has each variable's unit as a comment (--print-input).
   subroutine read_input(paths, config, input_text, error, overrides, notes, units, origins)
      character(len=*), intent(in) :: paths(:)
      type(job_config), intent(out) :: config
      character(len=:), allocatable, intent(out) :: input_text
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in), optional :: overrides(:)
      character(len=1024), allocatable, intent(out), optional :: notes(:)
      logical, intent(in), optional :: units
      type(config_checker), intent(out), optional :: origins
      type(namelist_source), allocatable :: sources(:), files(:)
      type(parameter_info), allocatable :: universe(:)
      type(parameter_table) :: names
      type(config_checker) :: checker
      character(len=32), allocatable :: groups(:)
      integer :: k, n_over

      if (present(notes)) allocate (notes(0))
      universe = all_parameters(names)
      groups = parameter_groups(universe)
      call scan_files(paths, groups, files, error)
      if (allocated(error)) return
      n_over = 0
      if (present(overrides)) n_over = size(overrides)
      allocate (sources(size(files) + n_over))
      sources(1:size(files)) = files
      do k = 1, n_over
         call override_source(overrides(k), groups, sources(size(files) + k), error)
         if (allocated(error)) return
      end do
      ! &job and &sweep first (every assignment of every file is checked here),
      ! then the scene they name.
      call apply_files(sources, universe, config, checker, error, names)
      if (allocated(error)) return
      call new_scene(config%scene_name, config%scene)
      if (.not. allocated(config%scene)) then
         call checker%reject('job', 'scene', "'"//trim(config%scene_name)//"'", 'unknown scene (known: ' &
            & //quoted(scene_names)//')')
         call move_alloc(checker%error, error)
         return
      end if
      call check_other_scenes(config, sources, len(last_text(sources, 'job', 'scene')) > 0, error, notes)
      if (allocated(error)) return
      call apply_files(sources, universe, config, checker, error, names)
      if (allocated(error)) return
      call check_job(config, checker)
      if (checker%failed()) then
         call move_alloc(checker%error, error)
         return
      end if
      call warn_units(config, checker)
      if (present(notes) .and. allocated(checker%warnings)) then
         do k = 1, size(checker%warnings)
            notes = [character(len=1024) :: notes, 'warning: '//trim(checker%warnings(k))]
         end do
      end if
      input_text = job_text(config, units)
      if (present(origins)) origins = checker
   end subroutine read_input

   !> The warnings of a checked configuration's values that look like numbers
   !> in another unit than their variable's: those the input set
   !> (warn_implausible) and those a sweep sets (warn_implausible_sweep).
   subroutine warn_units(config, checker)
      type(job_config), intent(inout) :: config
      type(config_checker), intent(inout) :: checker

      call warn_implausible(config, checker)
      call warn_implausible_sweep(config, checker)
   end subroutine warn_units

   !> Warnings for the values the input gives that look like numbers in
   !> another unit than their variable's (friction_plausibility), each naming
   !> where it was set; defaults are not the input's slips.
   subroutine warn_implausible(config, checker)
      type(job_config), intent(inout) :: config
      type(config_checker), intent(inout) :: checker
      type(parameter_finding), allocatable :: findings(:)
      integer :: k

      findings = implausible_values(config)
      do k = 1, size(findings)
         associate (f => findings(k))
            if (.not. checker%is_set(trim(f%group), trim(f%name))) cycle
            if (f%index > 0) then
               call checker%warn(trim(f%group), trim(f%name), trim(f%value), trim(f%reason), f%index)
            else
               call checker%warn(trim(f%group), trim(f%name), trim(f%value), trim(f%reason))
            end if
         end associate
      end do
   end subroutine warn_implausible

   !> Warnings for the values a sweep sets that look like numbers in another
   !> unit than the swept variable's (friction_plausibility): one per swept
   !> variable, where its sweep_variable was set, with how many of its values
   !> do, their range and the first one's reason.
   subroutine warn_implausible_sweep(config, checker)
      type(job_config), intent(in) :: config
      type(config_checker), intent(inout) :: checker
      type(parameter_info), allocatable :: list(:)
      class(scene), allocatable :: copy
      character(len=:), allocatable :: group, name, unit, reason, first, suffix
      real(wp) :: x, low, high
      integer :: a, k, m, flagged, n, stride, examined
      character(len=:), allocatable :: counted
      ! More values than this are sampled evenly (the ends included): a sweep of
      ! 2**31 points must reach its room check, not spend minutes here.
      integer, parameter :: most_examined = 100000

      if (.not. config%sweep%enabled()) return
      allocate (copy, source=config%scene)
      list = list_parameters(copy)
      do a = 1, config%sweep%n_variables
         call split_name(config%sweep%variables(a), group, name)
         unit = ''
         do m = 1, size(list)
            if (list(m)%group == group .and. list(m)%name == name .and. list(m)%kind == 'r') unit = trim(list(m)%unit)
         end do
         if (len(unit) == 0) cycle
         flagged = 0
         first = ''
         low = huge(1.0_wp)
         high = -huge(1.0_wp)
         n = config%sweep%shape(a)
         stride = max(1, n / most_examined)
         examined = 0
         do k = 1, n, stride
            call examine(k)
         end do
         if (mod(n - 1, stride) /= 0) call examine(n)
         if (flagged == 0) cycle
         counted = ' of its '//itoa(n)//' values'
         if (examined < n) counted = ' of '//itoa(examined)//' of its '//itoa(n)//' values (one in ' &
            & //itoa(stride)//' and the last)'
         suffix = merge('  ', '2 ', a == 1)
         call checker%warn('sweep', 'sweep_variable'//trim(suffix), "'"//trim(config%sweep%variables(a))//"'", &
            & itoa(flagged)//counted//', from '//rtoa(low)//' to ' &
            & //rtoa(high)//', look like another unit than '//unit//'; the first: '//first)
      end do

   contains

      subroutine examine(k)
         integer, intent(in) :: k

         examined = examined + 1
         x = config%sweep%value(a, k)
         reason = unit_plausibility(unit, x)
         if (len(reason) == 0) return
         flagged = flagged + 1
         if (flagged == 1) first = reason
         low = min(low, x)
         high = max(high, x)
      end subroutine examine
   end subroutine warn_implausible_sweep

   !> Groups of the sources that are not part of the job's scene: in an
   !> override (--set), an error with the C API's message; in a file, a
   !> warning in `notes` when `explicit` (the input names its scene), else an
   !> error naming the scene the group belongs to.
   subroutine check_other_scenes(config, sources, explicit, error, notes)
      type(job_config), intent(inout) :: config
      type(namelist_source), intent(in) :: sources(:)
      logical, intent(in) :: explicit
      type(error_type), allocatable, intent(out) :: error
      character(len=1024), allocatable, intent(inout), optional :: notes(:)
      character(len=32), allocatable :: own(:)
      character(len=:), allocatable :: where, owners, theirs
      integer :: f, k

      own = parameter_groups(list_parameters(config))
      do f = 1, size(sources)
         associate (s => sources(f))
            if (s%override) then
               if (any(own == s%mentions(1)%group)) cycle
               call fatal_error(error, s%path//': '//not_in_scene(config, s%mentions(1)%group), error_input)
               return
            end if
            do k = 1, size(s%groups)
               if (any(own == s%groups(k))) cycle
               where = source_place(s, s%group_lines(k))//': '
               owners = scenes_with(s%groups(k))
               if (explicit) then
                  theirs = ''
                  if (len(owners) > 0) theirs = ' (a group of scene '//owners//')'
                  if (present(notes)) notes = [character(len=1024) :: notes, 'warning: '//where// &
                     & not_in_scene(config, s%groups(k))//'; ignored'//theirs]
               else
                  call fatal_error(error, where//'group &'//trim(s%groups(k))//' belongs to scene '//owners// &
                     & ", but no &job scene is given and the default scene is '"//trim(config%scene_name)// &
                     & "': add &job scene = "//owners//' / (or remove the group)', error_input)
                  return
               end if
            end do
         end associate
      end do
   end subroutine check_other_scenes

   !> What is wrong with a group outside the job's scene (the program's and
   !> the C API's words).
   function not_in_scene(config, group) result(text)
      type(job_config), intent(inout) :: config
      character(len=*), intent(in) :: group
      character(len=:), allocatable :: text

      text = 'group &'//trim(group)//" is not part of scene '"//trim(config%scene_name)//"' (its groups: " &
         & //join(parameter_groups(list_parameters(config)), ' ', '&')//')'
   end function not_in_scene

   !> The scenes whose jobs have `group`, quoted ('brake'; '' if none).
   function scenes_with(group) result(text)
      character(len=*), intent(in) :: group
      character(len=:), allocatable :: text
      type(job_config) :: probe
      integer :: k

      text = ''
      do k = 1, size(scene_names)
         call new_scene(scene_names(k), probe%scene)
         if (any(parameter_groups(list_parameters(probe)) == group)) then
            if (len(text) > 0) text = text//' or '
            text = text//"'"//trim(scene_names(k))//"'"
         end if
         deallocate (probe%scene)
      end do
   end function scenes_with

   !> The groups the job reads as namelist text; with `units`, each
   !> variable's unit as a comment after it (--print-input).
   function job_text(config, units) result(text)
      type(job_config), intent(inout) :: config
      logical, intent(in), optional :: units
      character(len=:), allocatable :: text
      character(len=32), allocatable :: groups(:), own(:)

      call config%scene%groups(own)
      allocate (groups(size(own) + 1))
      groups(1) = 'job'
      groups(2:) = own
      if (config%sweep%enabled()) groups = [character(len=32) :: groups, 'sweep']
      text = parameters_text(config, groups, units)
   end function job_text

   !> The scene's checks, then the sweep's: one or two known numeric
   !> variables of the scene's groups, and their points.
   subroutine check_job(config, c)
      type(job_config), intent(inout) :: config
      type(config_checker), intent(inout) :: c
      type(parameter_info), allocatable :: mine(:), universe(:)
      integer :: counts(2)

      call config%scene%check(c)
      if (c%failed() .or. .not. config%sweep%enabled()) return
      associate (s => config%sweep)
         s%n_variables = merge(2, 1, len_trim(s%variables(2)) > 0)
         if (s%schedule /= 'dynamic' .and. s%schedule /= 'static') call c%reject('sweep', 'sweep_schedule', &
            & "'"//trim(s%schedule)//"'", "unknown schedule (known: 'dynamic', 'static')")
         mine = list_parameters(config%scene)
         universe = all_parameters()
         counts = 1
         call sweep_axis(1, '', counts(1))
         if (s%n_variables == 2) then
            if (s%variables(2) == s%variables(1)) call c%reject('sweep', 'sweep_variable2', &
               & "'"//trim(s%variables(2))//"'", 'is sweep_variable already')
            call sweep_axis(2, '2', counts(2))
         end if
         if (c%failed()) return
         ! The only limit on the points: a default integer counts them.
         if (int(counts(1), i8) * counts(2) > huge(1)) then
            call c%reject('sweep', 'sweep_count2', itoa(counts(2)), 'the grid of '//itoa(counts(1))//' x ' &
               & //itoa(counts(2))//' points exceeds '//itoa(huge(1))//' points')
            return
         end if
         s%shape = counts
         ! &verify checks one run against a second: a sweep reduces each point
         ! to a few numbers and runs no check, so asking for one (or sweeping
         ! its settings) would be ignored without a word.
         if (config%scene%verifies()) call c%reject('verify', 'check', '.true.', &
            & "is not run for a sweep's points: verify a point with a plain run of its values " &
            & //"(&sweep sweep_variable = '')")
      end associate

   contains

      !> One swept variable (`suffix` '' or '2' names its namelist variables):
      !> a numeric variable of a group of this scene, and its values.
      subroutine sweep_axis(a, suffix, n)
         integer, intent(in) :: a
         character(len=*), intent(in) :: suffix
         integer, intent(out) :: n
         character(len=:), allocatable :: group, name, shown
         real(wp), allocatable :: listed(:)
         real(wp) :: x, previous
         integer :: k, found
         logical :: whole
         character(len=32) :: partners(3)

         n = 0
         ! A value of this axis left at its default is refused against the axis's spacing and variable
         ! (2:3), sweep_to also against sweep_from.  (Element by element: see analysis_settings' partners.)
         partners(1) = 'sweep.sweep_from'//suffix
         partners(2) = 'sweep.sweep_spacing'//suffix
         partners(3) = 'sweep.sweep_variable'//suffix
         associate (s => config%sweep)
            shown = "'"//trim(s%variables(a))//"'"
            call split_name(s%variables(a), group, name)
            if (index(s%variables(a), '.') == 0 .or. group == 'job' .or. group == 'sweep' &
               & .or. .not. any(universe%group == group)) then
               call c%reject('sweep', 'sweep_variable'//suffix, shown, &
                  & "name a variable as 'group.name' of a scene group (e.g. 'brake.v_dr_prime')")
               return
            end if
            if (.not. any(mine%group == group)) then
               call c%reject('sweep', 'sweep_variable'//suffix, shown, 'group &'//group//' is not part of scene ' &
                  & //"'"//trim(config%scene_name)//"'")
               return
            end if
            if (group == 'verify') then
               call c%reject('sweep', 'sweep_variable'//suffix, shown, "&verify is not run for a sweep's points")
               return
            end if
            found = 0
            do k = 1, size(mine)
               if (mine(k)%group == group .and. mine(k)%name == name) found = k
            end do
            if (found == 0) then
               call c%reject('sweep', 'sweep_variable'//suffix, shown, 'no variable '//name// &
                  & ' in &'//group//' (known: '//join(pack(mine%name, mine%group == group))//')')
               return
            end if
            if ((mine(found)%kind /= 'r' .and. mine(found)%kind /= 'i') .or. mine(found)%size /= 1) then
               call c%reject('sweep', 'sweep_variable'//suffix, shown, &
                  & 'only numeric (real or integer) variables can be swept')
               return
            end if
            whole = mine(found)%kind == 'i'
            s%integer_valued(a) = whole
            select case (trim(s%spacings(a)))
            case ('list')
               if (a == 1) then
                  if (.not. allocated(s%listed1)) allocate (s%listed1(0))
                  listed = s%listed1
               else
                  if (.not. allocated(s%listed2)) allocate (s%listed2(0))
                  listed = s%listed2
               end if
               ! The values given, up to the first never given (a list is
               ! read whole; huge marks an element skipped with a null value).
               n = size(listed)
               do k = 1, size(listed)
                  if (listed(k) == huge(1.0_wp)) then
                     n = k - 1
                     exit
                  end if
               end do
               ! A gap would drop the values after it without a word.
               if (any(listed(n + 1:) /= huge(1.0_wp))) call c%reject('sweep', 'sweep_values'//suffix, '(none)', &
                  & 'not given (a null value or a gap), but a later element is: give every value up to the last', &
                  & index=n + 1)
               if (n == 0) call c%reject('sweep', 'sweep_values'//suffix, '(none)', "give at least one value for " &
                  & //"sweep_spacing"//suffix//" = 'list'", against=partners(2:3))
               if (a == 1) then
                  s%listed1 = listed(1:n)
               else
                  s%listed2 = listed(1:n)
               end if
            case ('linear', 'log')
               if (s%count(a) < 1) then
                  call c%reject('sweep', 'sweep_count'//suffix, itoa(s%count(a)), 'must be at least 1', &
                     & against=partners(2:3))
                  return
               end if
               call c%finite('sweep', 'sweep_from'//suffix, s%from(a))
               call c%finite('sweep', 'sweep_to'//suffix, s%to(a))
               ! A logarithmic range keeps one sign: both ends above zero, or
               ! both below (a belt that runs backwards: v_dr_prime < 0).
               if (s%spacings(a) == 'log' .and. .not. c%failed()) then
                  if (s%from(a) == 0.0_wp) then
                     call c%reject('sweep', 'sweep_from'//suffix, rtoa(s%from(a)), &
                        & "must not be 0 for sweep_spacing"//suffix//" = 'log'", against=partners(2:3))
                  else if (.not. (s%to(a) * sign(1.0_wp, s%from(a)) > 0.0_wp)) then
                     call c%reject('sweep', 'sweep_to'//suffix, rtoa(s%to(a)), "must be nonzero and of the sign " &
                        & //"of sweep_from"//suffix//" = "//rtoa(s%from(a))//" for sweep_spacing"//suffix//" = 'log'", &
                        & against=partners)
                  end if
               end if
               if (c%failed()) return
               n = s%count(a)
               ! An integer variable takes whole values: a spaced range is
               ! rounded (sweep_value) and must not repeat a value (monotonic:
               ! a repeat is next to its twin).
               if (whole) then
                  previous = s%value(a, 1)
                  do k = 2, n
                     x = s%value(a, k)
                     if (x == previous) then
                        call c%reject('sweep', 'sweep_count'//suffix, itoa(n), 'integer variable '//name &
                           & //' takes whole values: '//itoa(n)//' points from '//rtoa(s%from(a))//' to ' &
                           & //rtoa(s%to(a))//' repeat '//rtoa(x))
                        return
                     end if
                     previous = x
                  end do
               end if
            case default
               call c%reject('sweep', 'sweep_spacing'//suffix, "'"//trim(s%spacings(a))//"'", &
                  & "unknown spacing (known: 'list', 'linear', 'log')")
            end select
            if (whole .and. n > 0) then
               do k = 1, n
                  x = s%value(a, k)
                  if (x /= anint(x) .or. abs(x) > 2.0_wp**30) then
                     call c%reject('sweep', 'sweep_values'//suffix, rtoa(x), 'integer variable '//name// &
                        & ' takes whole values')
                     return
                  end if
               end do
            end if
         end associate
      end subroutine sweep_axis

   end subroutine check_job

end module friction_job_config
