!> Where a scene puts the named arrays it computes in memory (scene's
!> compute and compute_line): the C API's result handle is one sink, and a
!> caller that wants only some arrays is another.  The scene names each
!> array and gives its shape; the sink decides what to keep.
module friction_scene_sink
   use friction_kinds, only: wp
   implicit none
   private

   public :: result_sink, named_array, array_sink

   type, abstract :: result_sink
   contains
      !> Take the array `name` of rows x columns values, row-major (a series
      !> is one column).
      procedure(add_interface), deferred :: add
   end type result_sink

   abstract interface
      subroutine add_interface(self, name, rows, columns, values)
         import :: result_sink, wp
         class(result_sink), intent(inout) :: self
         character(len=*), intent(in) :: name
         integer, intent(in) :: rows, columns
         real(wp), intent(in) :: values(:)
      end subroutine add_interface
   end interface

   !> One named array of rows x columns values, row-major.
   type :: named_array
      character(len=32) :: name = ''
      integer :: rows = 0, columns = 1
      real(wp), allocatable :: values(:)
   end type named_array

   !> A sink that keeps every array it is given, in order.
   type, extends(result_sink) :: array_sink
      type(named_array), allocatable :: items(:)
   contains
      procedure :: add => array_sink_add
      procedure :: find => array_sink_find
   end type array_sink

contains

   subroutine array_sink_add(self, name, rows, columns, values)
      class(array_sink), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer, intent(in) :: rows, columns
      real(wp), intent(in) :: values(:)
      type(named_array), allocatable :: items(:)
      integer :: k, n

      n = 0
      if (allocated(self%items)) n = size(self%items)
      allocate (items(n + 1))
      do k = 1, n
         items(k)%name = self%items(k)%name
         items(k)%rows = self%items(k)%rows
         items(k)%columns = self%items(k)%columns
         call move_alloc(self%items(k)%values, items(k)%values)
      end do
      items(n + 1)%name = name
      items(n + 1)%rows = rows
      items(n + 1)%columns = columns
      items(n + 1)%values = values
      call move_alloc(items, self%items)
   end subroutine array_sink_add

   !> The index of the array `name`; 0 when there is none.
   integer function array_sink_find(self, name) result(found)
      class(array_sink), intent(in) :: self
      character(len=*), intent(in) :: name
      integer :: k

      found = 0
      if (.not. allocated(self%items)) return
      do k = 1, size(self%items)
         if (self%items(k)%name == name) then
            found = k
            return
         end if
      end do
   end function array_sink_find

end module friction_scene_sink
