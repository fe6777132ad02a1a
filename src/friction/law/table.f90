!> A tabulated law F(v), read from a text file of two columns, the sliding
!> velocity v (m/s, > 0, strictly increasing) and the friction force F (N,
!> >= 0), one row a line; blank lines and lines starting with '#' are
!> skipped.  Between the rows F is the monotone cubic (friction_law_pchip)
!> in ln v; the force is that times `scale` (a table for one contact used
!> for many).  Outside the rows:
!> - below the first velocity F stays at the first row's force, which is
!>   also the largest force the contact holds in stick (the law is
!>   set-valued at v = 0, with exact stick);
!> - above the last, `extrapolation = 'constant'` keeps the last force and
!>   'logarithmic' continues along the end slope dF/d(ln v), as thermally
!>   activated friction does.
!> F is odd in v.  A table computed at the atomic scale (the microscope
!> scene's friction against velocity) used at the machine scale: the rows
!> may also come from a microscope sweep's HDF5 file, through the reading
!> routine the settings carry (law/table_reader.f90).
module friction_law_table
   use friction_kinds, only: wp
   use friction_error, only: error_type, fatal_error, error_input
   use friction_strings, only: rtoa, itoa
   use friction_files, only: open_for_reading, read_text_line
   use friction_checks, only: config_checker
   use friction_law, only: sliding_law, exact_stick_force
   use friction_law_settings, only: law_group
   use friction_law_pchip, only: pchip_curve
   use friction_law_table_reader, only: table_read
   implicit none
   private

   public :: table_law, read_table

   !> The most rows a table may have (a bound on the memory a file asks for).
   integer, parameter :: max_rows = 1000000

   type, extends(sliding_law) :: table_law
      type(pchip_curve) :: curve   !! F against ln v, set by prepare
   contains
      procedure :: check
      procedure :: prepare
      procedure :: force
      procedure :: partials
      procedure :: set_valued
      procedure :: static_force
      procedure :: slip_force
      procedure :: table_force
      procedure :: table_slope
   end type table_law

contains

   !> The rows of `path`, or '' and a problem naming the file and line; a
   !> file the reader takes (a sweep's HDF5 file) by the reader.
   subroutine read_table(path, v, f, problem, reader)
      character(len=*), intent(in) :: path
      real(wp), allocatable, intent(out) :: v(:), f(:)
      character(len=:), allocatable, intent(out) :: problem
      procedure(table_read), optional :: reader
      logical :: handled
      type(error_type), allocatable :: error
      character(len=:), allocatable :: line, bad
      character(len=256) :: message
      real(wp), allocatable :: grown(:, :)
      real(wp) :: row(2)
      real(wp), allocatable :: rows(:, :)
      integer :: unit, stat, number, n, extra
      character(len=1) :: probe

      if (present(reader)) then
         call reader(trim(path), v, f, problem, handled)
         if (handled) return
      end if
      problem = ''
      if (allocated(v)) deallocate (v)
      if (allocated(f)) deallocate (f)
      allocate (v(0), f(0))
      call open_for_reading(trim(path), unit, error)
      if (allocated(error)) then
         problem = error%message
         return
      end if
      allocate (rows(2, 64))
      n = 0
      number = 0
      do
         call read_text_line(unit, line, stat, message, bad)
         if (stat < 0) exit
         number = number + 1
         if (stat > 0) then
            problem = trim(path)//':'//itoa(number)//': '//trim(message)
            exit
         end if
         if (len(bad) > 0) then
            problem = trim(path)//':'//itoa(number)//': '//bad
            exit
         end if
         line = adjustl(line)
         if (len_trim(line) == 0) cycle
         if (line(1:1) == '#') cycle
         read (line, *, iostat=stat) row
         if (stat == 0) then
            ! A third column would be read as nothing: refuse it.
            read (line, *, iostat=extra) row, probe
            if (extra == 0) stat = 1
         end if
         if (stat /= 0) then
            problem = trim(path)//':'//itoa(number)//': expected two numbers, v (m/s) and F (N): '//trim(line)
            exit
         end if
         if (.not. all(abs(row) <= huge(1.0_wp))) then
            problem = trim(path)//':'//itoa(number)//': not a finite number (NaN or infinity): '//trim(line)
            exit
         end if
         if (.not. (row(1) > 0.0_wp)) then
            problem = trim(path)//':'//itoa(number)//': velocity '//rtoa(row(1)) &
               & //' must be > 0 (the table is interpolated in ln v)'
            exit
         end if
         if (row(2) < 0.0_wp) then
            problem = trim(path)//':'//itoa(number)//': force '//rtoa(row(2))//' must be >= 0 (it resists the motion)'
            exit
         end if
         if (n > 0) then
            if (.not. (row(1) > rows(1, n))) then
               problem = trim(path)//':'//itoa(number)//': velocity '//rtoa(row(1)) &
                  & //' is not above the previous row''s '//rtoa(rows(1, n))//' (velocities must increase)'
               exit
            end if
         end if
         if (n == max_rows) then
            problem = trim(path)//':'//itoa(number)//': more than '//itoa(max_rows)//' rows'
            exit
         end if
         if (n == size(rows, 2)) then
            allocate (grown(2, 2 * n))
            grown(:, 1:n) = rows(:, 1:n)
            call move_alloc(grown, rows)
         end if
         n = n + 1
         rows(:, n) = row
      end do
      close (unit)
      if (len(problem) > 0) return
      if (n < 2) then
         problem = trim(path)//': '//itoa(n)//' rows; a table needs at least 2'
         return
      end if
      v = rows(1, 1:n)
      f = rows(2, 1:n)
   end subroutine read_table

   subroutine check(self, c)
      class(table_law), intent(in) :: self
      type(config_checker), intent(inout) :: c
      real(wp), allocatable :: v(:), f(:)
      character(len=:), allocatable :: problem

      call c%positive(law_group, 'scale', self%p%scale, 'the number of contacts the table''s force is for')
      call c%finite(law_group, 'scale', self%p%scale)
      if (self%p%extrapolation /= 'constant' .and. self%p%extrapolation /= 'logarithmic') &
         & call c%reject(law_group, 'extrapolation', "'"//trim(self%p%extrapolation)//"'", &
         & "unknown extrapolation (known: 'constant', 'logarithmic')")
      if (c%failed()) return
      if (len_trim(self%p%table_file) == 0) then
         call c%reject(law_group, 'table_file', "''", 'the tabulated law needs a file of v (m/s), F (N) rows', &
            & against=[law_group//'.model'])
         return
      end if
      if (associated(self%p%reader)) then
         call read_table(self%p%table_file, v, f, problem, self%p%reader)
      else
         call read_table(self%p%table_file, v, f, problem)
      end if
      if (len(problem) > 0) call c%reject(law_group, 'table_file', "'"//trim(self%p%table_file)//"'", problem)
   end subroutine check

   subroutine prepare(self, error)
      class(table_law), intent(inout) :: self
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: v(:), f(:)
      character(len=:), allocatable :: problem

      if (associated(self%p%reader)) then
         call read_table(self%p%table_file, v, f, problem, self%p%reader)
      else
         call read_table(self%p%table_file, v, f, problem)
      end if
      if (len(problem) > 0) then
         call fatal_error(error, '&'//law_group//': table_file: '//problem, error_input)
         return
      end if
      call self%curve%build(log(v), f)
   end subroutine prepare

   !> The table's force at speed u >= 0, with its extrapolation, unscaled.
   pure real(wp) function table_force(self, u)
      class(table_law), intent(in) :: self
      real(wp), intent(in) :: u
      integer :: n

      n = size(self%curve%x)
      if (u <= 0.0_wp) then
         table_force = self%curve%y(1)
         return
      end if
      associate (t => log(u))
         if (t <= self%curve%x(1)) then
            table_force = self%curve%y(1)
         else if (t >= self%curve%x(n)) then
            table_force = self%curve%y(n)
            if (self%p%extrapolation == 'logarithmic') table_force = table_force + self%curve%d(n) * (t - self%curve%x(n))
         else
            table_force = self%curve%value(t)
         end if
      end associate
   end function table_force

   !> d(table_force)/du.
   pure real(wp) function table_slope(self, u)
      class(table_law), intent(in) :: self
      real(wp), intent(in) :: u
      integer :: n

      n = size(self%curve%x)
      table_slope = 0.0_wp
      if (u <= 0.0_wp) return
      associate (t => log(u))
         if (t <= self%curve%x(1)) return
         if (t >= self%curve%x(n)) then
            if (self%p%extrapolation == 'logarithmic') table_slope = self%curve%d(n) / u
         else
            table_slope = self%curve%slope(t) / u
         end if
      end associate
   end function table_slope

   pure real(wp) function force(self, v, z, normal, applied)
      class(table_law), intent(in) :: self
      real(wp), intent(in) :: v, normal, applied
      real(wp), intent(in) :: z(:)

      force = exact_stick_force(self, v, z, normal, applied)
   end function force

   pure subroutine partials(self, v, z, normal, applied, dfdv, dfdz, dfda, dgdv, dgdz)
      class(table_law), intent(in) :: self
      real(wp), intent(in) :: v, normal, applied
      real(wp), intent(in) :: z(:)
      real(wp), intent(out) :: dfdv, dfdz(:), dfda, dgdv(:), dgdz(:, :)

      dfdv = self%p%scale * self%table_slope(abs(v))
      dfda = 0.0_wp
      if (v == 0.0_wp .and. abs(applied) < self%static_force(normal)) dfda = 1.0_wp
   end subroutine partials

   pure logical function set_valued(self)
      class(table_law), intent(in) :: self

      set_valued = .true.
   end function set_valued

   pure real(wp) function static_force(self, normal)
      class(table_law), intent(in) :: self
      real(wp), intent(in) :: normal

      static_force = self%p%scale * self%curve%y(1)
   end function static_force

   pure real(wp) function slip_force(self, v, z, normal, s)
      class(table_law), intent(in) :: self
      real(wp), intent(in) :: v, normal, s
      real(wp), intent(in) :: z(:)

      slip_force = s * self%p%scale * self%table_force(abs(v))
   end function slip_force

end module friction_law_table
