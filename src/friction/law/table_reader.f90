!> Where a tabulated law's rows may come from besides its text file: a
!> reading routine that a higher layer puts in the law's settings (the
!> output layer's reads the friction-velocity curve of a microscope sweep's
!> HDF5 file, output/law_files.f90).  The law layer knows no HDF5.
module friction_law_table_reader
   use friction_kinds, only: wp
   implicit none
   private

   public :: table_read

   abstract interface
      !> The rows (v in m/s increasing, F in N) of `path` if the routine
      !> takes the file (handled), else handled = .false. and nothing read;
      !> problem is '' or what is wrong with a file it takes.
      subroutine table_read(path, v, f, problem, handled)
         import :: wp
         character(len=*), intent(in) :: path
         real(wp), allocatable, intent(out) :: v(:), f(:)
         character(len=:), allocatable, intent(out) :: problem
         logical, intent(out) :: handled
      end subroutine table_read
   end interface

end module friction_law_table_reader
