!> The checks a configuration makes of its own values, and the message a
!> failed one gives: where the value was set (a file and line, a sweep
!> point, or nothing for the C API), the group, the variable, the value and
!> the reason.  Every configuration type checks itself through a checker,
!> so the namelist, the sweep and the C API reject the same values with the
!> same words.  A value that is allowed but looks like a slip (a number in
!> another unit) gives a warning in the same words instead, kept beside the
!> error for the caller to pass on.
module friction_checks
   use friction_kinds, only: wp
   use friction_error, only: error_type, fatal_error, error_input
   use friction_strings, only: itoa, rtoa
   implicit none
   private

   public :: config_checker

   !> Where a variable was last set.
   type :: origin_entry
      character(len=32) :: group = ''
      character(len=32) :: name = ''
      character(len=:), allocatable :: where   !! 'file.nml:3', 'sweep point 2', or '' (set in memory)
   end type origin_entry

   !> The first rejected value (later ones are not reported: one message),
   !> and every warning in the order given.
   type :: config_checker
      type(error_type), allocatable :: error
      type(origin_entry), allocatable :: origins(:)
      character(len=1024), allocatable :: warnings(:)
   contains
      procedure :: set_origin
      procedure :: origin
      procedure :: is_set
      procedure :: failed
      procedure :: reject
      procedure, private :: set_partner
      procedure :: warn
      procedure :: positive
      procedure :: nonnegative
      procedure :: finite
   end type config_checker

contains

   !> Record where group.name was set (the latest wins).
   subroutine set_origin(self, group, name, where)
      class(config_checker), intent(inout) :: self
      character(len=*), intent(in) :: group, name, where
      type(origin_entry), allocatable :: more(:)
      integer :: k

      if (.not. allocated(self%origins)) allocate (self%origins(0))
      do k = 1, size(self%origins)
         if (self%origins(k)%group == group .and. self%origins(k)%name == name) then
            self%origins(k)%where = where
            return
         end if
      end do
      ! (Element by element: gfortran's array constructors mishandle
      ! deferred-length character components.)
      allocate (more(size(self%origins) + 1))
      do k = 1, size(self%origins)
         more(k)%group = self%origins(k)%group
         more(k)%name = self%origins(k)%name
         call move_alloc(self%origins(k)%where, more(k)%where)
      end do
      more(k)%group = group
      more(k)%name = name
      more(k)%where = where
      call move_alloc(more, self%origins)
   end subroutine set_origin

   !> Where group.name was set: '(default)' when nowhere.
   function origin(self, group, name) result(text)
      class(config_checker), intent(in) :: self
      character(len=*), intent(in) :: group, name
      character(len=:), allocatable :: text
      integer :: k

      text = '(default)'
      if (.not. allocated(self%origins)) return
      do k = 1, size(self%origins)
         if (self%origins(k)%group == group .and. self%origins(k)%name == name) then
            text = self%origins(k)%where
            return
         end if
      end do
   end function origin

   logical function is_set(self, group, name)
      class(config_checker), intent(in) :: self
      character(len=*), intent(in) :: group, name

      is_set = self%origin(group, name) /= '(default)'
   end function is_set

   logical function failed(self)
      class(config_checker), intent(in) :: self

      failed = allocated(self%error)
   end function failed

   !> A bad value: where it was set, group, variable (with its array index
   !> when given), value and reason.  Only the first is kept.
   !> `against` lists the variables ('group.name') the value was checked
   !> against.  A value left at its default that conflicts with one of them
   !> set in the input leads with that one's line, which is where the user
   !> has something to change:
   !> 'run.nml:3: &machine: t_end, with the default &analysis: window_start = 100: reason'.
   subroutine reject(self, group, name, value, reason, index, against)
      class(config_checker), intent(inout) :: self
      character(len=*), intent(in) :: group, name, value, reason
      integer, intent(in), optional :: index
      character(len=*), intent(in), optional :: against(:)
      character(len=:), allocatable :: shown, where, lead

      if (allocated(self%error)) return
      shown = name
      if (present(index)) shown = name//'('//itoa(index)//')'
      where = self%origin(group, name)
      lead = ''
      if (where == '(default)' .and. present(against)) lead = self%set_partner(against)
      if (len(lead) > 0) then
         call fatal_error(self%error, lead//', with the default &'//group//': '//shown//' = '//value//': ' &
            & //reason, error_input)
         return
      end if
      if (len(where) > 0) where = where//': '
      call fatal_error(self%error, where//'&'//group//': '//shown//' = '//value//': '//reason, error_input)
   end subroutine reject

   !> The first of `against` ('group.name') set in the input, as
   !> 'where: &group: name' (no 'where: ' when set in memory); '' when none is.
   function set_partner(self, against) result(text)
      class(config_checker), intent(in) :: self
      character(len=*), intent(in) :: against(:)
      character(len=:), allocatable :: text
      character(len=len(against)) :: group, name
      integer :: k, dot

      text = ''
      do k = 1, size(against)
         dot = index(against(k), '.')
         if (dot < 2) cycle
         group = against(k)(:dot - 1)
         name = against(k)(dot + 1:)
         if (.not. self%is_set(trim(group), trim(name))) cycle
         text = self%origin(trim(group), trim(name))
         if (len(text) > 0) text = text//': '
         text = text//'&'//trim(group)//': '//trim(name)
         return
      end do
   end function set_partner

   !> A value that is allowed but implausible: the same words as `reject`
   !> (where it was set, group, variable, value, reason), kept in `warnings`.
   subroutine warn(self, group, name, value, reason, index)
      class(config_checker), intent(inout) :: self
      character(len=*), intent(in) :: group, name, value, reason
      integer, intent(in), optional :: index
      character(len=:), allocatable :: shown, where

      if (.not. allocated(self%warnings)) allocate (self%warnings(0))
      shown = name
      if (present(index)) shown = name//'('//itoa(index)//')'
      where = self%origin(group, name)
      if (len(where) > 0) where = where//': '
      self%warnings = [character(len=1024) :: self%warnings, where//'&'//group//': '//shown//' = '//value//': ' &
         & //reason]
   end subroutine warn

   subroutine positive(self, group, name, value, unit_text)
      class(config_checker), intent(inout) :: self
      character(len=*), intent(in) :: group, name, unit_text
      real(wp), intent(in) :: value

      if (.not. (value > 0.0_wp)) call self%reject(group, name, rtoa(value), 'must be > 0 ('//unit_text//')')
   end subroutine positive

   subroutine nonnegative(self, group, name, value, unit_text)
      class(config_checker), intent(inout) :: self
      character(len=*), intent(in) :: group, name, unit_text
      real(wp), intent(in) :: value

      if (.not. (value >= 0.0_wp)) call self%reject(group, name, rtoa(value), 'must be >= 0 ('//unit_text//')')
   end subroutine nonnegative

   subroutine finite(self, group, name, value)
      class(config_checker), intent(inout) :: self
      character(len=*), intent(in) :: group, name
      real(wp), intent(in) :: value

      if (.not. (abs(value) <= huge(value))) call self%reject(group, name, rtoa(value), 'must be a finite number')
   end subroutine finite

end module friction_checks
