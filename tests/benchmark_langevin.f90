!> Time per Langevin step of the 2D NaF tip (inputs/naf.nml: V0 = 1 eV,
!> a = 4.62 Å, m = 1e-8 kg, k = 10 N/m, c = 1e-3 N s/m) at 300 K with the
!> support at 400 Å/s and the default step, against the 100 ns target; and
!> its parts (one surface gradient, one Gaussian variate).  Median of
!> repeats, CPU time of this process (on a shared machine the wall clock
!> also counts other people's work; both are printed).
!>
!>   benchmark_langevin [repeats [steps]]     (defaults 7 and 2000000)
program benchmark_langevin
   use friction_kinds, only: wp, i8, kg_to_internal, n_per_m_to_internal, ns_per_m_to_internal
   use friction_error, only: error_type
   use friction_random, only: random_stream
   use friction_surface_naf, only: new_naf_potential
   use friction_surface_potential, only: surface_potential
   use friction_afm_tip, only: afm_tip, model_inertial, model_overdamped
   use friction_afm_langevin, only: langevin_integrator, langevin_state, langevin_time_step, largest_curvature
   implicit none

   real(wp), parameter :: target_ns = 100.0_wp
   integer :: repeats, steps, model
   character(len=32) :: arg
   real(wp), allocatable :: cpu(:), wall(:)
   type(afm_tip) :: tip
   type(langevin_integrator) :: integrator
   type(langevin_state) :: state
   type(random_stream) :: stream
   type(error_type), allocatable :: error
   real(wp) :: curvature, dt, limit, sink, g(3), r(3)
   integer :: k, i

   repeats = 7
   steps = 2000000
   if (command_argument_count() >= 1) then
      call get_command_argument(1, arg)
      read (arg, *) repeats
   end if
   if (command_argument_count() >= 2) then
      call get_command_argument(2, arg)
      read (arg, *) steps
   end if
   allocate (cpu(repeats), wall(repeats))

   write (*, '(a, i0, a, i0, a)') 'Langevin step, 2D NaF tip (inputs/naf.nml), 300 K, 400 A/s; median of ', &
      & repeats, ' repeats of ', steps, ' steps'
   write (*, '(a)') 'case                                   ns/step (cpu)   ns/step (wall)   target'
   do model = model_inertial, model_overdamped
      tip%ndim = 2
      tip%model = model
      tip%mass = 1.0e-8_wp * kg_to_internal
      tip%spring(1:2) = 10.0_wp * n_per_m_to_internal
      tip%damping(1:2) = 1.0e-3_wp * ns_per_m_to_internal
      tip%support_velocity(1:2) = [400.0_wp, 0.0_wp]
      if (allocated(tip%potential)) deallocate (tip%potential)
      allocate (tip%potential, source=new_naf_potential(1.0_wp, 4.62_wp, 4.62_wp))
      curvature = largest_curvature(tip%potential, [0.0_wp, 0.0_wp], [4.62_wp, 4.62_wp], 32)
      call langevin_time_step(tip, curvature, dt, limit, error)
      if (.not. allocated(error)) call integrator%init(tip, 300.0_wp, dt, error, curvature=curvature)
      if (.not. allocated(error)) call stream%init(1_i8, 0, 0, 0, error)
      if (allocated(error)) error stop error%message
      call integrator%start(stream, 0.0_wp, [0.0_wp, 0.0_wp], state)
      call integrator%advance(tip, stream, state, steps / 10, error)   ! warm-up
      do k = 1, repeats
         call timed(cpu(k), wall(k))
      end do
      if (model == model_inertial) then
         call report('BAOAB (inertial), h = '//trim(sci(dt)), median(cpu) / steps * 1.0e9_wp, &
            & median(wall) / steps * 1.0e9_wp, .true.)
      else
         call report('LM (overdamped), h = '//trim(sci(dt)), median(cpu) / steps * 1.0e9_wp, &
            & median(wall) / steps * 1.0e9_wp, .true.)
      end if
   end do

   ! The parts: one gradient of the surface, one Gaussian variate.
   sink = 0.0_wp
   do k = 1, repeats
      call part_timing(1, cpu(k), wall(k))
   end do
   call report('  NaF gradient', median(cpu) / steps * 1.0e9_wp, median(wall) / steps * 1.0e9_wp, .false.)
   do k = 1, repeats
      call part_timing(2, cpu(k), wall(k))
   end do
   call report('  Gaussian variate', median(cpu) / steps * 1.0e9_wp, median(wall) / steps * 1.0e9_wp, .false.)
   if (sink == 12345.0_wp) write (*, *) sink
   call stream%free()

contains

   subroutine timed(cpu_seconds, wall_seconds)
      real(wp), intent(out) :: cpu_seconds, wall_seconds
      real(wp) :: c0, c1
      integer(i8) :: w0, w1, rate

      call system_clock(w0, rate)
      call cpu_time(c0)
      call integrator%advance(tip, stream, state, steps, error)
      call cpu_time(c1)
      call system_clock(w1)
      if (allocated(error)) error stop error%message
      cpu_seconds = c1 - c0
      wall_seconds = real(w1 - w0, wp) / rate
   end subroutine timed

   subroutine part_timing(part, cpu_seconds, wall_seconds)
      integer, intent(in) :: part
      real(wp), intent(out) :: cpu_seconds, wall_seconds
      real(wp) :: c0, c1
      integer(i8) :: w0, w1, rate

      call system_clock(w0, rate)
      call cpu_time(c0)
      if (part == 1) then
         do i = 1, steps
            r = [1.0e-6_wp * i, 0.8_wp, 0.0_wp]
            call tip%potential%gradient(r, g)
            sink = sink + g(1)
         end do
      else
         do i = 1, steps
            sink = sink + stream%gaussian()
         end do
      end if
      call cpu_time(c1)
      call system_clock(w1)
      cpu_seconds = c1 - c0
      wall_seconds = real(w1 - w0, wp) / rate
   end subroutine part_timing

   subroutine report(label, ns_cpu, ns_wall, against_target)
      character(len=*), intent(in) :: label
      real(wp), intent(in) :: ns_cpu, ns_wall
      logical, intent(in) :: against_target

      if (against_target) then
         write (*, '(a, t40, f10.1, f17.1, a, f4.0, a, a)') label, ns_cpu, ns_wall, '   <= ', target_ns, ' ns: ', &
            & trim(merge('met   ', 'MISSED', ns_cpu <= target_ns))
      else
         write (*, '(a, t40, f10.1, f17.1)') label, ns_cpu, ns_wall
      end if
   end subroutine report

   real(wp) function median(x)
      real(wp), intent(in) :: x(:)
      real(wp) :: y(size(x)), swap
      integer :: a, b, n

      y = x
      n = size(y)
      do a = 2, n
         b = a
         do while (b > 1)
            if (y(b - 1) <= y(b)) exit
            swap = y(b - 1)
            y(b - 1) = y(b)
            y(b) = swap
            b = b - 1
         end do
      end do
      if (mod(n, 2) == 1) then
         median = y((n + 1) / 2)
      else
         median = 0.5_wp * (y(n / 2) + y(n / 2 + 1))
      end if
   end function median

   character(len=16) function sci(x)
      real(wp), intent(in) :: x
      write (sci, '(es9.2, a)') x, ' s'
      sci = adjustl(sci)
   end function sci

end program benchmark_langevin
