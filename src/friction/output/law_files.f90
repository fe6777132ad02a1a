!> The tabulated law's rows from the microscope: a sweep of `scan.velocity`
!> (an HDF5 file `friction` wrote, such as a sweep of
!> inputs/naf_thermal_velocity.nml) is a friction-velocity curve, its
!> /sweep/values the support's velocities and /sweep/mean_friction the mean
!> friction of each point (docs/laws.md, "Tabulated F(v)").  The points
!> that are done (status 1) become the rows, in SI units from the columns'
!> own units, by increasing velocity; &law scale multiplies the force (the
!> number of contacts).  The file is opened for reading only.
module friction_output_law_files
   use friction_kinds, only: wp, i8
   use friction_error, only: error_type
   use friction_strings, only: itoa, rtoa
   use friction_law_settings, only: law_settings
   use friction_output_h5_table, only: h5_table
   implicit none
   private

   public :: read_sweep_curve, law_with_files

contains

   !> The settings p with the means to read a table from a sweep's file.
   function law_with_files(p) result(q)
      type(law_settings), intent(in) :: p
      type(law_settings) :: q

      q = p
      q%reader => read_sweep_curve
   end function law_with_files

   !> Whether the file at path starts with HDF5's signature.
   logical function is_hdf5(path)
      character(len=*), intent(in) :: path
      character(len=8) :: head
      integer :: unit, stat

      is_hdf5 = .false.
      open (newunit=unit, file=path, access='stream', form='unformatted', action='read', status='old', iostat=stat)
      if (stat /= 0) return
      read (unit, iostat=stat) head
      close (unit)
      is_hdf5 = stat == 0 .and. head == achar(137)//'HDF'//achar(13)//achar(10)//achar(26)//achar(10)
   end function is_hdf5

   !> The rows of a sweep's file at path (law/table_reader.f90's table_read).
   subroutine read_sweep_curve(path, v, f, problem, handled)
      character(len=*), intent(in) :: path
      real(wp), allocatable, intent(out) :: v(:), f(:)
      character(len=:), allocatable, intent(out) :: problem
      logical, intent(out) :: handled
      type(h5_table) :: file
      type(error_type), allocatable :: error, closing
      real(wp), allocatable :: velocity(:), friction(:)
      integer, allocatable :: status(:), order(:)
      character(len=:), allocatable :: variable, v_units, f_units
      real(wp) :: v_factor, f_factor
      integer(i8) :: n
      integer :: k, j, m

      problem = ''
      allocate (v(0), f(0))
      handled = is_hdf5(path)
      if (.not. handled) return
      call file%open(path, error, read_only=.true.)
      if (allocated(error)) then
         problem = error%message
         return
      end if
      n = file%length('sweep/values')
      if (n < 0 .or. file%length('sweep/mean_friction') /= n .or. file%length('sweep/status') /= n) then
         problem = path//': not a sweep of the microscope (no /sweep/values, /sweep/mean_friction and ' &
            & //'/sweep/status of one length)'
      else if (file%length('sweep/values2') >= 0) then
         problem = path//': a sweep of two variables; the table needs one, scan.velocity'
      end if
      if (len(problem) == 0) then
         allocate (velocity(n), friction(n), status(n))
         call file%get('sweep/values', 0_i8, velocity)
         call file%get('sweep/mean_friction', 0_i8, friction)
         call file%get('sweep/status', 0_i8, status)
         variable = file%text('sweep/values', 'variable')
         v_units = file%text('sweep/values', 'units')
         f_units = file%text('sweep/mean_friction', 'units')
      end if
      call file%close(closing)
      if (len(problem) > 0) return
      if (allocated(closing)) then
         problem = closing%message
         return
      end if
      if (trim(variable) /= 'scan.velocity') then
         problem = path//": a sweep of '"//trim(variable)//"'; the table needs one of scan.velocity"
         return
      end if
      ! The units the microscope writes, and SI.
      select case (trim(v_units))
      case ('angstrom/s')
         v_factor = 1.0e-10_wp
      case ('m/s')
         v_factor = 1.0_wp
      case default
         problem = path//": /sweep/values in '"//trim(v_units)//"' (known: 'angstrom/s', 'm/s')"
         return
      end select
      select case (trim(f_units))
      case ('nN')
         f_factor = 1.0e-9_wp
      case ('N')
         f_factor = 1.0_wp
      case default
         problem = path//": /sweep/mean_friction in '"//trim(f_units)//"' (known: 'nN', 'N')"
         return
      end select
      ! The points done, by increasing velocity (a sweep's list may be in any order).
      order = pack([(k, k = 1, int(n))], status == 1)
      m = size(order)
      do k = 2, m
         j = k
         do while (j > 1)
            if (.not. (velocity(order(j)) < velocity(order(j - 1)))) exit
            order(j - 1:j) = order([j, j - 1])
            j = j - 1
         end do
      end do
      if (m < 2) then
         problem = path//': '//itoa(m)//' points done; a table needs at least 2'
         return
      end if
      v = velocity(order) * v_factor
      f = friction(order) * f_factor
      do k = 1, m
         if (.not. (abs(v(k)) <= huge(1.0_wp) .and. abs(f(k)) <= huge(1.0_wp))) then
            problem = path//': point '//itoa(order(k))//': not a finite number'
         else if (.not. (v(k) > 0.0_wp)) then
            problem = path//': point '//itoa(order(k))//': velocity '//rtoa(velocity(order(k)))//' must be > 0'
         else if (.not. (f(k) >= 0.0_wp)) then
            problem = path//': point '//itoa(order(k))//': friction '//rtoa(friction(order(k)))//' must be >= 0'
         else if (k > 1) then
            if (.not. (v(k) > v(k - 1))) problem = path//': points '//itoa(order(k - 1))//' and ' &
               & //itoa(order(k))//' have the same velocity '//rtoa(velocity(order(k)))
         end if
         if (len(problem) > 0) return
      end do
   end subroutine read_sweep_curve

end module friction_output_law_files
