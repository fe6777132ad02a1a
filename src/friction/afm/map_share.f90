!> One rank's share of a friction-force map while it runs: its lines
!> (dealt round-robin: first, first + nranks, ...), each computed or taken
!> from the checkpoint an interrupted run left, the finished ones written
!> to checkpoints beside the output for --resume, and at a temperature
!> their standard errors and slips.
module friction_afm_map_share
   use friction_parallel, only: gather_all, gather_all_varying
   use friction_kinds, only: wp
   use friction_error, only: error_type, fatal_error, error_input
   use friction_files, only: available_memory, remove_file
   use friction_strings, only: itoa, bytes_text, text_hash
   use friction_clock, only: wall_seconds
   use friction_scene_context, only: job_context, share_of
   use friction_afm_config, only: afm_config
   use friction_afm_trip, only: line_record, slip_list, n_quantities
   use friction_afm_line_checkpoint, only: line_checkpoint_name, save_line, load_line, publish_checkpoints, &
      & discard_checkpoints
   implicit none
   private

   public :: map_share, n_slip_items

   !> A slip's items: line, realization, trip, support, force, jump, jump_across.
   integer, parameter :: n_slip_items = 9

   type :: map_share
      type(afm_config) :: config               !! the settings that run
      integer :: first = 0, count = 0          !! this rank's first line (0-based) and its number of lines
      integer :: nranks = 1
      logical :: thermal = .false.             !! at a temperature: standard errors and slips kept
      !> Line j of this rank is trace(:, j, :): (nx, lines, quantities).
      real(wp), allocatable :: trace(:, :, :), retrace(:, :, :)
      !> At a temperature: standard errors over the realizations of the
      !> samples and of each line's friction.
      real(wp), allocatable :: trace_sem(:, :, :), retrace_sem(:, :, :)
      real(wp), allocatable :: friction_sem(:)
      !> This rank's slips: line, realization, trip, support (Å), force (nN),
      !> jump along and across (Å).
      real(wp), allocatable :: slips(:, :)
      !> The integrator's counts of each line (steps, failed steps, right-hand
      !> sides, Jacobians), computed now or loaded.
      real(wp), allocatable :: line_counts(:, :)
      logical, allocatable :: loaded(:)        !! line j came from its checkpoint
      integer :: computed = 0                  !! lines computed in this run
      integer :: saved = 0                     !! lines 1 to saved are checkpointed (or loaded)
      real(wp) :: last_saved = 0.0_wp          !! wall time of the last save
      character(len=:), allocatable :: output, input_hash
   contains
      procedure :: init
      procedure :: global_line
      procedure :: store
      procedure :: resume_line
      procedure :: save_lines
      procedure :: save_due
      procedure :: gather_slips
      procedure :: lines_done
      procedure :: remove_checkpoints
   end type map_share

contains

   !> This rank's share of the map `config` for the job: its lines, and
   !> their arrays, or an error stating the memory they need when this
   !> machine has not that much available.
   subroutine init(self, config, job, thermal, error)
      class(map_share), intent(inout) :: self
      type(afm_config), intent(in) :: config
      type(job_context), intent(in) :: job
      logical, intent(in) :: thermal
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: needed, available
      integer :: stat

      self%config = config
      self%nranks = job%nranks
      self%output = job%output
      self%input_hash = text_hash(job%input_text)
      self%thermal = thermal
      call share_of(config%ny, job%nranks, job%rank, self%first, self%count)
      if (allocated(self%trace)) deallocate (self%trace)
      if (allocated(self%retrace)) deallocate (self%retrace)
      needed = 8.0_wp * real(config%nx, wp) * real(self%count, wp) * n_quantities &
         & * merge(2.0_wp, 1.0_wp, config%retrace)
      available = available_memory()
      if (available > 0.0_wp .and. needed > available) then
         call fatal_error(error, 'the map needs '//bytes_text(needed)//' of memory on each rank (' &
            & //itoa(config%nx)//' points x '//itoa(self%count)//' lines x '//itoa(n_quantities) &
            & //' quantities x 8 bytes'//trim(merge(' x 2 trips', '          ', config%retrace)) &
            & //'), more than the '//bytes_text(available)//' this machine has available: use fewer ' &
            & //'points (&scan nx, ny) or more ranks on more machines', error_input)
         return
      end if
      allocate (self%trace(config%nx, self%count, n_quantities), stat=stat)
      if (stat == 0) allocate (self%retrace(config%nx, merge(self%count, 0, config%retrace), n_quantities), &
         & stat=stat)
      if (stat /= 0) then
         call fatal_error(error, 'the map needs '//bytes_text(needed)//' of memory on each ' &
            & //'rank, which could not be allocated: use fewer points (&scan nx, ny) or more ranks', error_input)
         return
      end if
      if (allocated(self%trace_sem)) deallocate (self%trace_sem)
      if (allocated(self%retrace_sem)) deallocate (self%retrace_sem)
      if (allocated(self%friction_sem)) deallocate (self%friction_sem)
      if (allocated(self%slips)) deallocate (self%slips)
      allocate (self%slips(n_slip_items, 0))
      if (thermal) then
         allocate (self%trace_sem(config%nx, self%count, n_quantities))
         allocate (self%retrace_sem(config%nx, merge(self%count, 0, config%retrace), n_quantities))
         allocate (self%friction_sem(self%count))
      end if
      if (allocated(self%line_counts)) deallocate (self%line_counts)
      if (allocated(self%loaded)) deallocate (self%loaded)
      allocate (self%line_counts(4, self%count), source=0.0_wp)
      allocate (self%loaded(self%count), source=.false.)
      self%computed = 0
      self%saved = 0
      self%last_saved = wall_seconds()
   end subroutine init

   !> The map's line (0-based) that is line j of this rank.
   pure integer function global_line(self, j)
      class(map_share), intent(in) :: self
      integer, intent(in) :: j

      global_line = self%first + (j - 1) * self%nranks
   end function global_line

   !> Line j of this rank as computed, with the integrator's counts it took.
   subroutine store(self, j, line, counts)
      class(map_share), intent(inout) :: self
      integer, intent(in) :: j
      type(line_record), intent(in) :: line
      real(wp), intent(in) :: counts(4)

      self%line_counts(:, j) = counts
      self%computed = self%computed + 1
      self%trace(:, j, :) = line%trace
      if (self%config%retrace) self%retrace(:, j, :) = line%retrace
      if (self%thermal) then
         self%trace_sem(:, j, :) = line%trace_sem
         if (self%config%retrace) self%retrace_sem(:, j, :) = line%retrace_sem
         self%friction_sem(j) = line%friction_sem
         call keep_slips(self, self%global_line(j), line%slips)
      end if
   end subroutine store

   !> Line j of this rank from its checkpoint, when there is one for this
   !> input (then loaded(j)); one that exists but cannot serve is an error.
   subroutine resume_line(self, j, error)
      class(map_share), intent(inout) :: self
      integer, intent(in) :: j
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: slips(:, :), trace(:, :), retrace(:, :), trace_sem(:, :), retrace_sem(:, :)
      character(len=:), allocatable :: problem
      real(wp) :: friction_sem
      integer :: g

      g = self%global_line(j)
      call line_arrays(self, j, trace, retrace, trace_sem, retrace_sem)
      call load_line(line_checkpoint_name(self%output, g), self%input_hash, g, trace, retrace, trace_sem, &
         & retrace_sem, friction_sem, slips, self%line_counts(:, j), self%loaded(j), problem)
      if (len(problem) > 0) then
         call fatal_error(error, problem//'; --resume reuses only the checkpoints of the same input: remove ' &
            & //'it, or run without --resume', error_input)
         return
      end if
      if (.not. self%loaded(j)) return
      self%trace(:, j, :) = trace
      if (self%config%retrace) self%retrace(:, j, :) = retrace
      if (self%thermal) then
         self%trace_sem(:, j, :) = trace_sem
         if (self%config%retrace) self%retrace_sem(:, j, :) = retrace_sem
         self%friction_sem(j) = friction_sem
         self%slips = reshape([self%slips, slips], [n_slip_items, size(self%slips, 2) + size(slips, 2)])
      end if
   end subroutine resume_line

   !> Whether the checkpoint interval has passed since the last save.
   logical function save_due(self)
      class(map_share), intent(in) :: self

      save_due = wall_seconds() - self%last_saved >= self%config%checkpoint_interval
   end function save_due

   !> Checkpoints of this rank's lines after `saved` up to `last` that were
   !> computed in this run.
   subroutine save_lines(self, last, error)
      class(map_share), intent(inout) :: self
      integer, intent(in) :: last
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: trace(:, :), retrace(:, :), trace_sem(:, :), retrace_sem(:, :)
      real(wp) :: friction_sem
      character(len=:), allocatable :: names(:), problem
      integer :: j, g, k, n

      allocate (character(len=len(line_checkpoint_name(self%output, self%config%ny))) :: &
         & names(max(0, last - self%saved)))
      n = 0
      do j = self%saved + 1, last
         if (self%loaded(j)) cycle
         g = self%global_line(j)
         call line_arrays(self, j, trace, retrace, trace_sem, retrace_sem)
         friction_sem = 0.0_wp
         if (self%thermal) friction_sem = self%friction_sem(j)
         names(n + 1) = line_checkpoint_name(self%output, g)
         call save_line(trim(names(n + 1)), self%input_hash, g, trace, retrace, trace_sem, &
            & retrace_sem, friction_sem, self%slips(:, pack([(k, k=1, size(self%slips, 2))], &
            & nint(self%slips(1, :)) == g)), self%line_counts(:, j), problem)
         if (len(problem) > 0) then
            call discard_checkpoints(names(1:n))
            call fatal_error(error, problem)
            return
         end if
         n = n + 1
      end do
      ! One sync for the lines of this save, then their names.
      call publish_checkpoints(names(1:n), problem)
      if (len(problem) > 0) then
         call fatal_error(error, problem)
         return
      end if
      self%saved = max(self%saved, last)
      self%last_saved = wall_seconds()
   end subroutine save_lines

   !> Line j's samples as save_line and load_line take them: (nx,
   !> quantities) each, of no rows for what the map does not have.
   subroutine line_arrays(self, j, trace, retrace, trace_sem, retrace_sem)
      class(map_share), intent(in) :: self
      integer, intent(in) :: j
      real(wp), allocatable, intent(out) :: trace(:, :), retrace(:, :), trace_sem(:, :), retrace_sem(:, :)

      trace = self%trace(:, j, :)
      allocate (retrace(0, 0), trace_sem(0, 0), retrace_sem(0, 0))
      if (self%config%retrace) retrace = self%retrace(:, j, :)
      if (self%thermal) trace_sem = self%trace_sem(:, j, :)
      if (self%thermal .and. self%config%retrace) retrace_sem = self%retrace_sem(:, j, :)
   end subroutine line_arrays

   !> A line's slips onto this rank's list.
   subroutine keep_slips(self, global_line, slips)
      class(map_share), intent(inout) :: self
      integer, intent(in) :: global_line
      type(slip_list), intent(in) :: slips
      real(wp), allocatable :: more(:, :)
      integer :: k, n

      n = size(self%slips, 2)
      allocate (more(n_slip_items, n + slips%n))
      more(:, 1:n) = self%slips
      do k = 1, slips%n
         more(:, n + k) = [real(global_line, wp), real(slips%realization(k), wp), real(slips%trip(k), wp), &
            & slips%support(k), slips%force(k), slips%jump(k), slips%jump_across(k), slips%barrier(k), &
            & slips%prefactor(k)]
      end do
      call move_alloc(more, self%slips)
   end subroutine keep_slips

   !> Every rank's slips on every rank, in the order of the lines (each
   !> rank's list is in its lines' order; the lines are dealt round-robin).
   !> Collective; this rank's list is handed over.
   subroutine gather_slips(self, job, slips)
      class(map_share), intent(inout) :: self
      type(job_context), intent(in) :: job
      real(wp), allocatable, intent(out) :: slips(:, :)
      integer :: counts(job%nranks), displacements(job%nranks), cursor(job%nranks), n, r, line, k, at
      real(wp), allocatable :: everything(:, :)

      n = size(self%slips, 2)
      if (.not. job%parallel()) then
         call move_alloc(self%slips, slips)
         return
      end if
      call gather_all(job%comm, n, counts)
      displacements(1) = 0
      do r = 2, job%nranks
         displacements(r) = displacements(r - 1) + counts(r - 1)
      end do
      allocate (everything(n_slip_items, sum(counts)))
      call gather_all_varying(job%comm, self%slips, counts, displacements, everything)
      allocate (slips(n_slip_items, sum(counts)))
      cursor = displacements
      at = 0
      do line = 0, self%config%ny - 1
         r = mod(line, job%nranks) + 1
         do k = cursor(r) + 1, displacements(r) + counts(r)
            if (nint(everything(1, k)) /= line) exit
            at = at + 1
            slips(:, at) = everything(:, k)
            cursor(r) = k
         end do
      end do
   end subroutine gather_slips

   !> The map's lines done when this rank has done `done` of its own: rank
   !> 0's share is as large as any other and spread over the whole map.
   integer function lines_done(self, done)
      class(map_share), intent(in) :: self
      integer, intent(in) :: done

      lines_done = min(self%config%ny, int(real(done, wp) / max(1, self%count) * self%config%ny))
   end function lines_done

   !> A complete map: the checkpoints of this rank's lines have served.
   subroutine remove_checkpoints(self)
      class(map_share), intent(in) :: self
      integer :: j

      do j = 1, self%count
         call remove_file(line_checkpoint_name(self%output, self%global_line(j)))
      end do
   end subroutine remove_checkpoints

end module friction_afm_map_share
