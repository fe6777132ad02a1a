!> What a brake run records: the trajectory on the output grid and the
!> table of stick/slip events.
module friction_brake_record
   use friction_kinds, only: wp
   implicit none
   private

   public :: brake_trajectory, brake_event_table
   public :: event_stick_to_slip, event_slip_to_stick, event_slip_reversal, event_kind_names

   !> Event kinds (the integer codes of /brake/events/kind).
   integer, parameter :: event_stick_to_slip = 1  !! the elastic force reached μs N' (switched);
                                                  !! |v_rel| rose above stick_velocity (regularized)
   integer, parameter :: event_slip_to_stick = 2  !! v_rel reached 0 within the static limit (switched);
                                                  !! |v_rel| fell below stick_velocity (regularized)
   integer, parameter :: event_slip_reversal = 3  !! v_rel reached 0 beyond the static limit: slip on
                                                  !! the other way (switched only)
   character(len=*), parameter :: event_kind_names(3) = [character(len=13) :: &
      & 'stick_to_slip', 'slip_to_stick', 'slip_reversal']

   !> Samples t_i of the grid with the state and the stick flag.
   type :: brake_trajectory
      real(wp), allocatable :: t(:), x(:), v(:), y(:), w(:)
      integer, allocatable :: stick(:)   !! 1 in stick, 0 in slip
   contains
      procedure :: allocate_points
   end type brake_trajectory

   !> Events in time order: time, kind and the state (x, v, y, w) just after.
   type :: brake_event_table
      integer :: n = 0
      real(wp), allocatable :: t(:)
      integer, allocatable :: kind(:)
      real(wp), allocatable :: state(:, :)   !! (4, n)
   contains
      procedure :: add
      procedure :: clear
   end type brake_event_table

contains

   subroutine allocate_points(self, n)
      class(brake_trajectory), intent(inout) :: self
      integer, intent(in) :: n

      if (allocated(self%t)) deallocate (self%t, self%x, self%v, self%y, self%w, self%stick)
      allocate (self%t(n), self%x(n), self%v(n), self%y(n), self%w(n), self%stick(n))
      self%t = 0.0_wp
      self%x = 0.0_wp
      self%v = 0.0_wp
      self%y = 0.0_wp
      self%w = 0.0_wp
      self%stick = 0
   end subroutine allocate_points

   pure subroutine clear(self)
      class(brake_event_table), intent(inout) :: self

      self%n = 0
   end subroutine clear

   !> Append an event; storage grows geometrically.
   pure subroutine add(self, t, kind, state)
      class(brake_event_table), intent(inout) :: self
      real(wp), intent(in) :: t
      integer, intent(in) :: kind
      real(wp), intent(in) :: state(4)
      real(wp), allocatable :: t_new(:), state_new(:, :)
      integer, allocatable :: kind_new(:)
      integer :: capacity

      if (.not. allocated(self%t)) then
         allocate (self%t(64), self%kind(64), self%state(4, 64))
      else if (self%n == size(self%t)) then
         capacity = 2 * size(self%t)
         allocate (t_new(capacity), kind_new(capacity), state_new(4, capacity))
         t_new(1:self%n) = self%t(1:self%n)
         kind_new(1:self%n) = self%kind(1:self%n)
         state_new(:, 1:self%n) = self%state(:, 1:self%n)
         call move_alloc(t_new, self%t)
         call move_alloc(kind_new, self%kind)
         call move_alloc(state_new, self%state)
      end if
      self%n = self%n + 1
      self%t(self%n) = t
      self%kind(self%n) = kind
      self%state(:, self%n) = state
   end subroutine add

end module friction_brake_record
