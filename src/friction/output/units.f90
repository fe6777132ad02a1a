!> Units as the files write them (docs/output.md#units): UDUNITS strings that
!> pint parses too.  The brake's time τ is dimensionless, so a unit given in
!> τ ('tau', 'm/tau', 'tau/m', '1/tau') is written as its value at τ = 1 in
!> `units` ('1', 'm', '1/m', '1') and as given in `units_tau` beside it.
module friction_output_units
   implicit none
   private

   public :: plain_unit, mentions_tau

contains

   !> Whether unit has the factor tau (in its numerator or denominator).
   pure logical function mentions_tau(unit)
      character(len=*), intent(in) :: unit
      character(len=:), allocatable :: top, bottom, rest
      logical :: above, below

      call split(unit, top, bottom)
      call drop_tau(top, rest, above)
      call drop_tau(bottom, rest, below)
      mentions_tau = above .or. below
   end function mentions_tau

   !> unit with every factor tau set to 1: 'm/tau' is 'm', 'tau' is '1',
   !> 'tau/m' is '1/m'; a unit without tau as it is.
   pure function plain_unit(unit) result(plain)
      character(len=*), intent(in) :: unit
      character(len=:), allocatable :: plain
      character(len=:), allocatable :: whole_top, whole_bottom, top, bottom
      logical :: above, below

      call split(unit, whole_top, whole_bottom)
      call drop_tau(whole_top, top, above)
      call drop_tau(whole_bottom, bottom, below)
      if (.not. (above .or. below)) then
         plain = trim(unit)
         return
      end if
      if (len(top) == 0) top = '1'
      plain = top
      if (len(bottom) > 0) plain = top//'/'//bottom
   end function plain_unit

   !> The numerator and denominator of unit (at its first '/'; '' when none).
   pure subroutine split(unit, top, bottom)
      character(len=*), intent(in) :: unit
      character(len=:), allocatable, intent(out) :: top, bottom
      integer :: slash

      slash = index(unit, '/')
      if (slash == 0) then
         top = trim(adjustl(unit))
         bottom = ''
      else
         top = trim(adjustl(unit(:slash - 1)))
         bottom = trim(adjustl(unit(slash + 1:)))
      end if
   end subroutine split

   !> The blank-separated factors of a product other than tau, joined by
   !> blanks, and whether there was a tau.
   pure subroutine drop_tau(product, rest, found)
      character(len=*), intent(in) :: product
      character(len=:), allocatable, intent(out) :: rest
      logical, intent(out) :: found
      character(len=:), allocatable :: kept
      integer :: start, finish, n

      kept = ''
      found = .false.
      n = len_trim(product)
      start = 1
      do while (start <= n)
         if (product(start:start) == ' ') then
            start = start + 1
            cycle
         end if
         finish = index(product(start:n)//' ', ' ') + start - 2
         if (product(start:finish) == 'tau') then
            found = .true.
         else
            if (len(kept) > 0) kept = kept//' '
            kept = kept//product(start:finish)
         end if
         start = finish + 1
      end do
      rest = kept
   end subroutine drop_tau

end module friction_output_units
