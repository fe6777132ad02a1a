!> Surface potentials: analytic gradient and Hessian against centred finite
!> differences at random points, and the lattice periodicity.
program test_potentials
   use friction_kinds, only: wp, pi
   use friction_surface_potential, only: surface_potential
   use friction_surface_naf, only: new_naf_potential
   use friction_surface_hopg, only: new_hopg_potential
   use testing, only: test_suite, check, check_close
   implicit none
   type(test_suite) :: suite

   suite%name = 'potentials'
   call suite%add('naf_gradient', naf_gradient)
   call suite%add('hopg_gradient', hopg_gradient)
   call suite%add('naf_periodicity', naf_periodicity)
   call suite%add('hopg_periodicity', hopg_periodicity)
   call suite%add('naf_values', naf_values)
   call suite%add('hopg_values', hopg_values)
   ! Random test points, the same on every run.
   call random_init(repeatable=.true., image_distinct=.false.)
   call suite%run_all()

contains

   !> Centred differences with step h = 1e-4 Å have truncation error
   !> ~ h² V'''/6 ≈ 1e-9 of the gradient scale V0 q for q ~ 2.6/Å, and
   !> round-off ~ 1e-16 V0/h ≈ 1e-12: both far below the 1e-6 relative
   !> tolerance the issue asks, so a wrong sign or factor cannot pass.
   subroutine check_derivatives(failure, potential, scale, label)
      character(len=:), allocatable, intent(inout) :: failure
      class(surface_potential), intent(in) :: potential
      real(wp), intent(in) :: scale   !! typical wave number, 1/Å
      character(len=*), intent(in) :: label
      real(wp), parameter :: h = 1.0e-4_wp
      real(wp) :: r(3), e(3), g(3), gp(3), gm(3), hess(3, 3), fd
      real(wp) :: vscale
      integer :: trial, i, j
      character(len=80) :: what

      vscale = abs(potential%energy([0.0_wp, 0.0_wp, 0.0_wp]))
      do trial = 1, 200
         call random_number(r)
         r = (r - 0.5_wp) * 40.0_wp
         call potential%gradient(r, g)
         call potential%hessian(r, hess)
         do i = 1, 3
            e = 0.0_wp
            e(i) = h
            fd = (potential%energy(r + e) - potential%energy(r - e)) / (2.0_wp * h)
            write (what, '(a, " dV/dr", i0, " at trial ", i0)') label, i, trial
            call check_close(failure, g(i), fd, 1.0e-6_wp * vscale * scale, trim(what))
            call potential%gradient(r + e, gp)
            call potential%gradient(r - e, gm)
            do j = 1, 3
               fd = (gp(j) - gm(j)) / (2.0_wp * h)
               write (what, '(a, " d2V/dr", i0, "dr", i0, " at trial ", i0)') label, j, i, trial
               call check_close(failure, hess(j, i), fd, 1.0e-6_wp * vscale * scale**2, trim(what))
            end do
         end do
      end do
   end subroutine check_derivatives

   subroutine naf_gradient(failure)
      character(len=:), allocatable, intent(out) :: failure

      call check_derivatives(failure, new_naf_potential(1.0_wp, 4.62_wp, 4.62_wp), 2.0_wp * pi / 4.62_wp, 'NaF')
      call check_derivatives(failure, new_naf_potential(0.3_wp, 3.0_wp, 5.5_wp), 2.0_wp * pi / 3.0_wp, &
         & 'NaF ax /= ay')
   end subroutine naf_gradient

   subroutine hopg_gradient(failure)
      character(len=:), allocatable, intent(out) :: failure

      ! |V(0)| = 3 V0: the scale check uses it; the y terms reach 2 q_y ≈ 2.95/Å.
      call check_derivatives(failure, new_hopg_potential(0.5_wp, 2.46_wp), 2.0_wp * pi / 2.46_wp, 'HOPG')
   end subroutine hopg_gradient

   subroutine check_period(failure, potential, shift, label)
      character(len=:), allocatable, intent(inout) :: failure
      class(surface_potential), intent(in) :: potential
      real(wp), intent(in) :: shift(3)
      character(len=*), intent(in) :: label
      real(wp) :: r(3), g1(3), g2(3)
      integer :: trial

      do trial = 1, 100
         call random_number(r)
         r = (r - 0.5_wp) * 40.0_wp
         ! 1e-12 eV: a few ulps of the cosines at arguments up to ~50.
         call check_close(failure, potential%energy(r + shift), potential%energy(r), 1.0e-12_wp, &
            & label//': V(r + period) = V(r)')
         call potential%gradient(r, g1)
         call potential%gradient(r + shift, g2)
         call check(failure, maxval(abs(g1 - g2)) < 1.0e-11_wp, label//': gradient periodic')
      end do
   end subroutine check_period

   subroutine naf_periodicity(failure)
      character(len=:), allocatable, intent(out) :: failure
      associate (p => new_naf_potential(1.0_wp, 4.62_wp, 3.1_wp))
         call check_period(failure, p, [4.62_wp, 0.0_wp, 0.0_wp], 'NaF (ax, 0)')
         call check_period(failure, p, [0.0_wp, 3.1_wp, 0.0_wp], 'NaF (0, ay)')
         call check_period(failure, p, [0.0_wp, 0.0_wp, 1.7_wp], 'NaF z-independent')
         ! Half a period is not a symmetry: V changes sign of its x cosine.
         call check(failure, abs(p%energy([0.0_wp, 0.0_wp, 0.0_wp]) - p%energy([2.31_wp, 0.0_wp, 0.0_wp])) &
            & > 1.0_wp, 'NaF (ax/2, 0) must not be a period')
      end associate
   end subroutine naf_periodicity

   subroutine hopg_periodicity(failure)
      character(len=:), allocatable, intent(out) :: failure
      real(wp), parameter :: a = 2.46_wp

      associate (p => new_hopg_potential(0.5_wp, a))
         call check_period(failure, p, [a, 0.0_wp, 0.0_wp], 'HOPG (a, 0)')
         call check_period(failure, p, [a / 2, a * sqrt(3.0_wp) / 2, 0.0_wp], 'HOPG (a/2, a√3/2)')
         call check_period(failure, p, [-a / 2, a * sqrt(3.0_wp) / 2, 0.0_wp], 'HOPG (-a/2, a√3/2)')
         call check(failure, abs(p%energy([0.0_wp, 0.0_wp, 0.0_wp]) - p%energy([a / 2, 0.0_wp, 0.0_wp])) &
            & > 1.0_wp, 'HOPG (a/2, 0) must not be a period')
      end associate
   end subroutine hopg_periodicity

   !> Values at special points, straight from Eq. 1.
   subroutine naf_values(failure)
      character(len=:), allocatable, intent(out) :: failure

      associate (p => new_naf_potential(1.0_wp, 4.62_wp, 4.62_wp))
         call check_close(failure, p%energy([0.0_wp, 0.0_wp, 0.0_wp]), -1.0_wp, 1.0e-15_wp, 'V(0, 0)')
         call check_close(failure, p%energy([2.31_wp, 0.0_wp, 0.0_wp]), 1.0_wp, 1.0e-15_wp, 'V(ax/2, 0)')
         call check_close(failure, p%energy([1.155_wp, 0.0_wp, 0.0_wp]), 0.0_wp, 1.0e-15_wp, 'V(ax/4, 0)')
      end associate
   end subroutine naf_values

   !> Eq. 2 at the minimum (0, 0): -3 V0; at the saddle (a/2, 0): -V0 [-2 + 1] = V0.
   subroutine hopg_values(failure)
      character(len=:), allocatable, intent(out) :: failure

      associate (p => new_hopg_potential(0.5_wp, 2.46_wp))
         call check_close(failure, p%energy([0.0_wp, 0.0_wp, 0.0_wp]), -1.5_wp, 1.0e-15_wp, 'V(0, 0)')
         call check_close(failure, p%energy([1.23_wp, 0.0_wp, 0.0_wp]), 0.5_wp, 1.0e-15_wp, 'V(a/2, 0)')
      end associate
   end subroutine hopg_values

end program test_potentials
